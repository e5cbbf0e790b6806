// SPDX-License-Identifier: AGPL-3.0-or-later
// Connection refinement (docs/design.md §2.4 step 4): where coarse surface triangles leave
// no short free-space edge between two neighbours, their closest points become surface
// vertices so the triangulation gets gap-spanning edges near the true distance.
#include "baker_3d.h"
#include "parallel_for.h"

#include <aggrelod/dendrogram.h>

#include <array>

namespace aggrelod::detail {

// Before the one triangulation: each model's nearest neighbours (by box distance) are
// measured exactly; where the closest points lie far from the surface vertices (coarse
// triangles), they are inserted as vertices, so the triangulation gets gap-spanning edges
// close to the true distance without a second TetGen run (docs/design.md §2.4 step 4).
void Baker3D::prerefineClosePairs() {
    timer_.begin("prerefine");
    resolveStandInOverlaps();
    if (models_.size() < 2) return;
    const std::vector<std::pair<uint32_t, uint32_t>> candidates = nearestPairsByBox(6);
    std::vector<Insertion> insertions;
    auto nearestVertexDistance = [&](const Model& m, uint32_t tri, const double* p) {
        double best = INFINITY;
        for (int k = 0; k < 3; ++k) {
            const double* v = &m.positions[3 * m.triangles[3 * tri + k]];
            best = std::min(best, std::sqrt((v[0] - p[0]) * (v[0] - p[0]) + (v[1] - p[1]) * (v[1] - p[1]) + (v[2] - p[2]) * (v[2] - p[2])));
        }
        return best;
    };
    // Measure every candidate on its own slot, then gather in candidate order.
    std::vector<std::array<Insertion, 2>> found(candidates.size());
    std::vector<std::array<bool, 2>> use(candidates.size(), {false, false});
    std::vector<ClosestPair> measured(candidates.size());
    parallelFor(candidates.size(), settings_.threadCount, [&](size_t c) {
        const auto [i, j] = candidates[c];
        ClosestPair cp = meshDistance(models_[i].bvh, models_[j].bvh);
        measured[c] = cp;
        if (cp.triangleA == ~0u || cp.triangleB == ~0u || !(cp.distance > tolerance_)) return;
        const double ra = nearestVertexDistance(models_[i], cp.triangleA, cp.pointA);
        const double rb = nearestVertexDistance(models_[j], cp.triangleB, cp.pointB);
        if (ra + rb <= 0.5 * cp.distance) return;  // a short edge exists already
        found[c][0] = Insertion{i, cp.triangleA, {cp.pointA[0], cp.pointA[1], cp.pointA[2]}};
        found[c][1] = Insertion{j, cp.triangleB, {cp.pointB[0], cp.pointB[1], cp.pointB[2]}};
        use[c] = {ra > 0.1 * cp.distance, rb > 0.1 * cp.distance};
    }, [&](size_t done) {
        if (done % 64 == 0) timer_.report(double(done) / candidates.size());
    });
    for (size_t c = 0; c < candidates.size(); ++c) {
        for (int k = 0; k < 2; ++k)
            if (use[c][k]) insertions.push_back(found[c][k]);
        const auto [i, j] = candidates[c];
        distanceCache_[{models_[i].objects[0], models_[j].objects[0]}] = measured[c];
    }
    insertSurfacePoints(insertions, NearVertex::Skip);
}

// Splits surface triangles at the given points. A point well inside its triangle splits it
// 1 -> 3; a point near an edge splits that edge (the triangle and its neighbour across the
// edge, 2 -> 4, the new vertex on the edge), because a 1 -> 3 split there makes thin sliver
// triangles that slow the triangulation's exact predicates down; a point near a corner is
// skipped or, with NearVertex::Insert, moved inside (no degenerate triangle). Surfaces stay
// closed, manifold and outward. Returns how many points were inserted.
size_t Baker3D::insertSurfacePoints(std::vector<Insertion>& insertions, NearVertex nearVertex) {
    modelsPrepared_ = false;  // surfaces change (not their shape: distances stay valid)
    std::stable_sort(insertions.begin(), insertions.end(), [](const Insertion& x, const Insertion& y) {
        return std::tie(x.model, x.triangle) < std::tie(y.model, y.triangle);
    });
    constexpr double kNearEdge = 0.1;  // smallest barycentric coordinate below this: near an edge
    size_t inserted = 0;
    for (size_t i = 0; i < insertions.size();) {
        size_t j = i;
        while (j < insertions.size() && insertions[j].model == insertions[i].model) ++j;
        Model& model = models_[insertions[i].model];
        const uint32_t originalCount = static_cast<uint32_t>(model.triangles.size() / 3);
        // children[t]: current triangles covering original triangle t; origin[t]: the original
        // triangle a current triangle comes from (new triangles only, index - originalCount).
        std::map<uint32_t, std::vector<uint32_t>> children;
        std::vector<uint32_t> origin;
        auto addChild = [&](uint32_t parent, uint32_t child) {
            const uint32_t root = parent < originalCount ? parent : origin[parent - originalCount];
            auto& list = children[root];
            if (list.empty()) list.push_back(root);
            list.push_back(child);
            origin.push_back(root);
        };
        // Directed edge (from, to) -> triangles holding it, for finding the neighbour across an
        // edge; built on the first edge split (lookups only, never iterated).
        std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> edges;
        bool edgesBuilt = false;
        auto edgeKey = [](uint32_t from, uint32_t to) { return std::make_pair(from, to); };
        auto setTriangle = [&](uint32_t t, uint32_t x, uint32_t y, uint32_t z) {
            if (edgesBuilt && 3 * static_cast<size_t>(t) + 2 < model.triangles.size()) {
                const uint32_t* old = &model.triangles[3 * t];
                for (int e = 0; e < 3; ++e) {
                    auto& list = edges[edgeKey(old[e], old[(e + 1) % 3])];
                    list.erase(std::remove(list.begin(), list.end(), t), list.end());
                }
            }
            if (3 * static_cast<size_t>(t) + 2 >= model.triangles.size()) model.triangles.resize(3 * static_cast<size_t>(t) + 3);
            model.triangles[3 * t] = x;
            model.triangles[3 * t + 1] = y;
            model.triangles[3 * t + 2] = z;
            if (edgesBuilt) {
                const uint32_t v[3] = {x, y, z};
                for (int e = 0; e < 3; ++e) edges[edgeKey(v[e], v[(e + 1) % 3])].push_back(t);
            }
        };
        for (size_t k = i; k < j; ++k) {
            const Insertion& ins = insertions[k];
            if (ins.triangle >= originalCount) continue;
            auto& list = children[ins.triangle];
            if (list.empty()) list.push_back(ins.triangle);
            // Locate the child with the largest smallest barycentric coordinate.
            int bestChild = -1;
            double bestMin = -INFINITY, bary[3] = {0, 0, 0};
            for (size_t c = 0; c < list.size(); ++c) {
                const uint32_t* tri = &model.triangles[3 * list[c]];
                const double* A = &model.positions[3 * tri[0]];
                const double* B = &model.positions[3 * tri[1]];
                const double* C = &model.positions[3 * tri[2]];
                double v0[3], v1[3], v2[3];
                for (int d = 0; d < 3; ++d) {
                    v0[d] = B[d] - A[d];
                    v1[d] = C[d] - A[d];
                    v2[d] = ins.point[d] - A[d];
                }
                double d00 = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2];
                double d01 = v0[0] * v1[0] + v0[1] * v1[1] + v0[2] * v1[2];
                double d11 = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2];
                double d20 = v2[0] * v0[0] + v2[1] * v0[1] + v2[2] * v0[2];
                double d21 = v2[0] * v1[0] + v2[1] * v1[1] + v2[2] * v1[2];
                double den = d00 * d11 - d01 * d01;
                if (!(den > 0)) continue;
                double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den, u = 1 - v - w;
                double mn = std::min(u, std::min(v, w));
                if (mn > bestMin) {
                    bestMin = mn;
                    bestChild = static_cast<int>(c);
                    bary[0] = u;
                    bary[1] = v;
                    bary[2] = w;
                }
            }
            if (bestChild < 0) continue;
            const uint32_t t = list[bestChild];
            const uint32_t corner[3] = {model.triangles[3 * t], model.triangles[3 * t + 1], model.triangles[3 * t + 2]};
            const uint32_t nv = static_cast<uint32_t>(model.positions.size() / 3);
            const uint32_t t1 = static_cast<uint32_t>(model.triangles.size() / 3);
            // Near an edge (one small coordinate) or a corner (two).
            int smallest = 0;
            for (int e = 1; e < 3; ++e)
                if (bary[e] < bary[smallest]) smallest = e;
            const int p = (smallest + 1) % 3, q = (smallest + 2) % 3;  // the edge corner[p] -> corner[q]
            const bool nearEdge = bary[smallest] < kNearEdge;
            const bool nearCorner = nearEdge && std::min(bary[p], bary[q]) < kNearEdge;
            if (nearCorner && nearVertex == NearVertex::Skip) continue;
            if (nearEdge && !nearCorner) {
                if (!edgesBuilt) {
                    for (uint32_t f = 0; 3 * static_cast<size_t>(f) + 2 < model.triangles.size(); ++f)
                        for (int e = 0; e < 3; ++e)
                            edges[edgeKey(model.triangles[3 * f + e], model.triangles[3 * f + (e + 1) % 3])].push_back(f);
                    edgesBuilt = true;
                }
                const uint32_t a = corner[p], b = corner[q], c = corner[smallest];
                const auto forward = edges.find(edgeKey(a, b));
                const auto backward = edges.find(edgeKey(b, a));
                // Only on a manifold edge (one triangle each way); otherwise split 1 -> 3 below.
                if (forward != edges.end() && forward->second.size() == 1 && backward != edges.end() && backward->second.size() == 1 &&
                    backward->second[0] != t) {
                    const uint32_t t2 = backward->second[0];
                    const uint32_t* n2 = &model.triangles[3 * t2];
                    uint32_t d = n2[0];
                    for (int e = 0; e < 3; ++e)
                        if (n2[e] != a && n2[e] != b) d = n2[e];
                    // The point projected on the edge, kept away from the corners.
                    const double s = std::min(std::max(bary[q] / (bary[p] + bary[q]), kNearEdge), 1 - kNearEdge);
                    for (int dim = 0; dim < 3; ++dim)
                        model.positions.push_back((1 - s) * model.positions[3 * a + dim] + s * model.positions[3 * b + dim]);
                    // (a, b, c) -> (a, nv, c) + (nv, b, c); neighbour (b, a, d) -> (b, nv, d) + (nv, a, d).
                    setTriangle(t, a, nv, c);
                    setTriangle(t1, nv, b, c);
                    addChild(t, t1);
                    setTriangle(t2, b, nv, d);
                    setTriangle(t1 + 1, nv, a, d);
                    addChild(t2, t1 + 1);
                    ++inserted;
                    continue;
                }
            }
            // Keep the new vertex strictly inside (no sliver, no degenerate triangle).
            const double floorBary = 0.02;
            double sum = 0;
            for (double& w : bary) {
                w = std::max(w, floorBary);
                sum += w;
            }
            for (double& w : bary) w /= sum;
            const uint32_t a = corner[0], b = corner[1], c = corner[2];
            for (int d = 0; d < 3; ++d)
                model.positions.push_back(bary[0] * model.positions[3 * a + d] + bary[1] * model.positions[3 * b + d] +
                                          bary[2] * model.positions[3 * c + d]);
            setTriangle(t, a, b, nv);
            setTriangle(t1, b, c, nv);
            addChild(t, t1);
            setTriangle(t1 + 1, c, a, nv);
            addChild(t, t1 + 1);
            ++inserted;
        }
        i = j;
    }
    return inserted;
}

// Pairs (i < j, sorted, unique) of each model with its `neighbours` nearest models by box
// distance.
std::vector<std::pair<uint32_t, uint32_t>> Baker3D::nearestPairsByBox(size_t neighbours) const {
    const size_t n = models_.size();
    std::vector<std::pair<uint32_t, uint32_t>> candidates;
    std::vector<std::pair<double, uint32_t>> near;
    for (uint32_t i = 0; i < n; ++i) {
        near.clear();
        for (uint32_t j = 0; j < n; ++j) {
            if (j == i) continue;
            double d2 = 0;
            for (int k = 0; k < 3; ++k) {
                double gap = std::max({0.0, models_[j].bounds[k] - models_[i].bounds[3 + k], models_[i].bounds[k] - models_[j].bounds[3 + k]});
                d2 += gap * gap;
            }
            near.emplace_back(d2, j);
        }
        const size_t keep = std::min(neighbours, near.size());
        std::partial_sort(near.begin(), near.begin() + keep, near.end());
        for (size_t k = 0; k < keep; ++k) candidates.emplace_back(std::min(i, near[k].second), std::max(i, near[k].second));
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    return candidates;
}

// docs/design.md §2.4 step 4: where large input triangles leave no short triangulation edge between
// two models the dendrogram joins (shortest edge much longer than the exact distance),
// insert the closest points into both surfaces as Steiner vertices and triangulate again,
// so that gap-spanning edges approach the true distance. One extra pass, only when needed.
bool Baker3D::refineCoarseConnections() {
    std::vector<Merge> merges = kruskalMerges(models_.size(), weighedGraph());
    std::vector<Insertion> insertions;
    for (const Merge& m : merges) {
        int idx = findPair(space_.pairs, m.modelA, m.modelB);
        if (idx < 0) continue;
        const ModelPair& p = space_.pairs[idx];
        if (p.closestTriangleA == ~0u || p.closestTriangleB == ~0u) continue;
        if (!(p.shortestEdge > 1.5 * p.exactDistance + tolerance_)) continue;
        Insertion a{p.a, p.closestTriangleA, {p.closestA[0], p.closestA[1], p.closestA[2]}};
        Insertion b{p.b, p.closestTriangleB, {p.closestB[0], p.closestB[1], p.closestB[2]}};
        insertions.push_back(a);
        insertions.push_back(b);
    }
    if (insertions.empty()) return false;
    timer_.begin("refine");
    const size_t inserted = insertSurfacePoints(insertions, NearVertex::Insert);
    diag(out_, Diagnostic::Severity::Note, "",
         "refined " + std::to_string(inserted) + " surface point(s) where the triangulation had no short connection "
         "between joined models; triangulating again");
    return inserted > 0;
}

}  // namespace aggrelod::detail
