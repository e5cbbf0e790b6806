// SPDX-License-Identifier: AGPL-3.0-or-later
// Connection refinement in 2D (docs/design.md §2.4 step 4): where a merge's shortest
// connection ends at a long boundary edge, Steiner points on that edge give joined models a
// narrow bridge of small triangles instead of one long sliver. The points go into the
// existing triangulation (steiner_2d.cpp); the free space and graph are then built again.
#include "baker_2d.h"

#include "steiner_2d.h"

#include <cmath>
#include <exception>
#include <future>

namespace aggrelod::detail {
namespace {

/// Steiner points for the shortest connection of every merge (docs/design.md §2.4 step 4): where a
/// connection ends at a vertex, its boundary edges longer than 3 d get a point at distance d
/// (d = the connection's length); where it ends inside an edge, the edge gets the foot point
/// and points d to either side. mergePair: per merge, its index in space.pairs. Only called
/// on the unsplit input.
SegmentSplits connectionSplits(const InputVertices& in, const FreeSpace2D& space, const std::vector<Merge>& merges,
                               const std::vector<uint32_t>& mergePair) {
    std::vector<std::pair<uint32_t, double>> found;  // (segment, parameter)
    found.reserve(2 * merges.size());
    const Triangulation2D& tri = space.tri;
    auto addAt = [&](size_t segmentStart, double t) { found.emplace_back(static_cast<uint32_t>(segmentStart), t); };
    auto segmentLength = [&](size_t s) { return std::hypot(in.x(in.next(s)) - in.x(s), in.y(in.next(s)) - in.y(s)); };
    // Split both boundary edges at vertex v (input vertex) at distance d from it.
    auto splitAroundVertex = [&](size_t v, double d) {
        const size_t prev = in.prev(v);
        const double lOut = segmentLength(v), lIn = segmentLength(prev);
        if (lOut > 3 * d) addAt(v, d / lOut);
        if (lIn > 3 * d) addAt(prev, 1 - d / lIn);
    };
    for (size_t k = 0; k < merges.size(); ++k) {
        const ModelPair2D& pair = space.pairs[mergePair[k]];
        const double d = pair.minDistance;
        if (!(d > 0)) continue;
        const int* c = pair.connection;
        const int iv0 = tri.vertexInput[c[0]];
        if (iv0 < 0) continue;
        splitAroundVertex(static_cast<size_t>(iv0), d);
        if (c[2] < 0) {  // vertex to vertex
            const int iv1 = tri.vertexInput[c[1]];
            if (iv1 >= 0) splitAroundVertex(static_cast<size_t>(iv1), d);
            continue;
        }
        // Vertex to the edge (c[1], c[2]): find the input segment holding it.
        const int e0 = tri.vertexInput[c[1]], e1 = tri.vertexInput[c[2]];
        if (e0 < 0 || e1 < 0) continue;
        size_t s;
        if (in.next(static_cast<size_t>(e0)) == static_cast<size_t>(e1)) s = static_cast<size_t>(e0);
        else if (in.next(static_cast<size_t>(e1)) == static_cast<size_t>(e0)) s = static_cast<size_t>(e1);
        else continue;  // a part of a longer segment: leave it
        const size_t e = in.next(s);
        const double dx = in.x(e) - in.x(s), dy = in.y(e) - in.y(s);
        const double len = std::hypot(dx, dy);
        const double t = ((in.x(iv0) - in.x(s)) * dx + (in.y(iv0) - in.y(s)) * dy) / (len * len);
        const double margin = 0.5 * d / len;
        for (double u : {t - d / len, t, t + d / len})
            if (u > margin && u < 1 - margin) addAt(s, u);
    }
    // By segment (counting sort), each segment's parameters ascending without near-duplicates
    // (two connections at one place).
    SegmentSplits splits;
    const size_t segmentCount = in.part.size();
    splits.first.assign(segmentCount + 1, 0);
    splits.count.assign(segmentCount, 0);
    for (const auto& [segment, t] : found) ++splits.first[segment + 1];
    for (size_t v = 0; v < segmentCount; ++v) splits.first[v + 1] += splits.first[v];
    splits.t.resize(found.size());
    for (const auto& [segment, t] : found) splits.t[splits.first[segment] + splits.count[segment]++] = t;
    for (size_t v = 0; v < segmentCount; ++v) {
        if (splits.count[v] < 2) continue;
        double* list = splits.t.data() + splits.first[v];
        std::sort(list, list + splits.count[v]);
        uint32_t kept = 1;
        for (uint32_t i = 1; i < splits.count[v]; ++i)
            if (list[i] - list[kept - 1] > 1e-6) list[kept++] = list[i];
        splits.count[v] = kept;
    }
    return splits;
}

}  // namespace

bool refineConnections2D(const CheckedPolygons& checked, InputVertices& in, std::vector<int>& winding,
                         FreeSpace2D& space, FreeSpaceModels& models, std::vector<uint32_t>& mergePair,
                         bool needHulls, int threadCount, StageTimer& timer, Hierarchy2D& out, std::string& error) {
    SegmentSplits splits = connectionSplits(in, space, out.merges, mergePair);
    std::vector<ConstraintSplit> requests;
    std::vector<size_t> requestSegment;
    for (size_t v = 0; v < in.part.size(); ++v) {
        if (splits.size(v) == 0) continue;
        ConstraintSplit r;
        r.from = v;
        r.to = in.next(v);
        r.points.reserve(2 * splits.size(v));
        for (size_t k = 0; k < splits.size(v); ++k) {  // the same arithmetic as inputVertices()
            const double t = splits.at(v)[k];
            r.points.push_back(in.x(v) + t * (in.x(r.to) - in.x(v)));
            r.points.push_back(in.y(v) + t * (in.y(r.to) - in.y(v)));
        }
        requests.push_back(std::move(r));
        requestSegment.push_back(v);
    }
    if (!requests.empty()) {
        timer.begin("triangulate with Steiner points");
        // The new vertices go into the exported triangulation, each splitting its constrained
        // edge; a segment that cannot be split that way keeps fewer (or no) new vertices.
        // The input with the new vertices is prepared on another thread meanwhile.
        Triangulation2D tri = std::move(space.tri);
        space = FreeSpace2D{};
        InputVertices split;
        std::future<InputVertices> splitLater;
        if (threadCount != 1)
            splitLater = std::async(std::launch::async, [&] { return inputVertices(checked, &splits, /*withGrid=*/false); });
        std::vector<uint32_t> appliedCount;
        std::vector<int> firstVertex;
        bool inserted = true;
        try {
            insertSplitPoints2D(tri, requests, appliedCount, firstVertex, &winding);
        } catch (const std::exception& e) {
            inserted = false;
            error = std::string("2D triangulation failed while adding points: ") + e.what();
        }
        split = splitLater.valid() ? splitLater.get() : inputVertices(checked, &splits, /*withGrid=*/false);
        if (!inserted) return false;
        bool allApplied = true;
        for (size_t k = 0; k < requests.size(); ++k)
            if (appliedCount[k] < splits.size(requestSegment[k])) {
                splits.count[requestSegment[k]] = appliedCount[k];
                allApplied = false;
            }
        // The new input numbering: every original vertex followed by its segment's new points.
        const size_t originalCount = in.part.size();
        std::vector<size_t> newInputIndex(originalCount);
        for (size_t v = 0, next = 0; v < originalCount; ++v) {
            newInputIndex[v] = next;
            next += 1 + splits.size(v);
        }
        std::vector<long long> splitFirstIndex(requests.size(), -1);
        for (size_t k = 0; k < requests.size(); ++k)
            if (appliedCount[k] > 0) splitFirstIndex[k] = static_cast<long long>(newInputIndex[requestSegment[k]] + 1);
        in = allApplied ? std::move(split) : inputVertices(checked, &splits, /*withGrid=*/false);
        renumberAfterSplits2D(tri, newInputIndex, splitFirstIndex, appliedCount, firstVertex, in.part.size());
        space.tri = std::move(tri);
        setShared(in, space.tri);
        timer.begin("free space and graph again");
        buildFreeSpace(in, checked, winding, space, models, /*graphOnly=*/false, threadCount, needHulls);
        out.merges = kruskalMerges(space.modelCount, weighedGraph(space), &mergePair);
    } else {
        timer.begin("free space and graph again");
        Triangulation2D tri = std::move(space.tri);
        space = FreeSpace2D{};
        space.tri = std::move(tri);  // no Steiner point: complete the graph-only pass
        buildFreeSpace(in, checked, winding, space, models, /*graphOnly=*/false, threadCount, needHulls);
    }
    return true;
}

}  // namespace aggrelod::detail
