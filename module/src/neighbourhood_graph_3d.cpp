// SPDX-License-Identifier: AGPL-3.0-or-later
// The neighbourhood graph and its statistics (paper Section 3.2; docs/design.md §2.2): model
// pairs joined by free-space edges, their edge-length statistics, and the exact distance
// that weighs each pair.
#include "baker_3d.h"
#include "parallel_for.h"
#include "radix_sort.h"

namespace aggrelod::detail {

void Baker3D::buildGraph() {
    timer_.begin("graph");
    const TetMesh& mesh = space_.mesh;
    constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    std::vector<std::pair<int, int>> edges;
    for (size_t t = 0; t < mesh.tetCount(); ++t) {
        if (space_.tetModel[t] >= 0) continue;
        for (auto& e : kEdges) {
            int u = mesh.tets[4 * t + e[0]], v = mesh.tets[4 * t + e[1]];
            int mu = space_.vertexModel[u], mv = space_.vertexModel[v];
            if (mu < 0 || mv < 0 || mu == mv) continue;
            edges.emplace_back(std::min(u, v), std::max(u, v));
        }
    }
    // Sorted and unique, as std::sort + std::unique would give, but bucketed by the first
    // vertex first (counting sort): each edge appears in several tets, and the list is long.
    {
        const size_t pointCount = mesh.pointCount();
        std::vector<uint32_t> start;
        std::vector<std::pair<int, int>> byFirst;
        countingSortByBucket(edges, pointCount, [](const std::pair<int, int>& e) { return e.first; }, start, byFirst);
        edges.clear();
        for (size_t u = 0; u < pointCount; ++u) {
            const auto b = byFirst.begin() + start[u], e = byFirst.begin() + start[u + 1];
            std::sort(b, e);  // one first vertex: by the second
            for (auto v = b; v != e; ++v)
                if (v == b || v->second != (v - 1)->second) edges.push_back(*v);
        }
    }
    // Accumulate per model pair (u on a, v on b, a < b).
    struct Acc {
        uint32_t a, b;
        double length;
        int u, v;
    };
    std::vector<Acc> accs;
    accs.reserve(edges.size());
    for (auto [u, v] : edges) {
        int mu = space_.vertexModel[u], mv = space_.vertexModel[v];
        if (mu > mv) {
            std::swap(mu, mv);
            std::swap(u, v);
        }
        const double* p = &mesh.points[3 * u];
        const double* q = &mesh.points[3 * v];
        double len = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
        accs.push_back({static_cast<uint32_t>(mu), static_cast<uint32_t>(mv), len, u, v});
    }
    std::sort(accs.begin(), accs.end(), [](const Acc& x, const Acc& y) {
        return std::tie(x.a, x.b, x.length, x.u, x.v) < std::tie(y.a, y.b, y.length, y.u, y.v);
    });
    space_.pairs.clear();
    space_.edgeLengths.clear();
    std::vector<double> run;
    for (size_t i = 0; i < accs.size();) {
        size_t j = i;
        while (j < accs.size() && accs[j].a == accs[i].a && accs[j].b == accs[i].b) ++j;
        ModelPair p;
        p.a = accs[i].a;
        p.b = accs[i].b;
        p.shortestEdge = accs[i].length;  // sorted by length within the pair
        p.shortestEdgeVertexA = accs[i].u;
        p.shortestEdgeVertexB = accs[i].v;
        run.clear();
        for (size_t k = i; k < j; ++k) run.push_back(accs[k].length);
        space_.edgeLengths.append(p, run.data(), run.size());
        space_.pairs.push_back(p);
        i = j;
    }
    // Exact distances between neighbouring models (BVH closest pair).
    timer_.begin("distances");
    if (!modelsPrepared_) prepareModels(settings_.threadCount);
    const size_t pairCount = space_.pairs.size();
    parallelFor(pairCount, settings_.threadCount, [&](size_t i) {
        ModelPair& p = space_.pairs[i];
        const double* ua = &mesh.points[3 * p.shortestEdgeVertexA];
        const double* ub = &mesh.points[3 * p.shortestEdgeVertexB];
        std::copy(ua, ua + 3, p.closestA);
        std::copy(ub, ub + 3, p.closestB);
        p.exactDistance = p.shortestEdge;
        // Pairs measured before triangulating keep that result (same surfaces; their
        // triangle numbers changed with the inserted points, so those are not kept).
        auto cached = distanceCache_.find({models_[p.a].objects[0], models_[p.b].objects[0]});
        const bool fromCache = cached != distanceCache_.end();
        const ClosestPair cp =
            fromCache ? cached->second : meshDistance(models_[p.a].bvh, models_[p.b].bvh, p.shortestEdge);
        if (std::isfinite(cp.distance) && cp.distance <= p.shortestEdge) {
            p.exactDistance = cp.distance;
            std::copy(cp.pointA, cp.pointA + 3, p.closestA);
            std::copy(cp.pointB, cp.pointB + 3, p.closestB);
            if (!fromCache) {
                p.closestTriangleA = cp.triangleA;
                p.closestTriangleB = cp.triangleB;
            }
        }
        p.weight = settings_.distance == DistanceMode::Exact ? p.exactDistance : p.shortestEdge;
    }, [&](size_t done) {
        if (done % 64 == 0) timer_.report(double(done) / pairCount);
    });
}

}  // namespace aggrelod::detail
