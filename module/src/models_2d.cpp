// SPDX-License-Identifier: AGPL-3.0-or-later
// Models in 2D (docs/design.md §2.1, stage 4): the vertices of the neighbourhood graph. The
// parts of one feature, parts that touch or overlap, and parts nested inside another part's
// interior form one model.
#include "baker_2d.h"

#include "parallel_for.h"

#include <aggrelod/disjoint_sets.h>

namespace aggrelod::detail {

void buildModels2D(const InputVertices& in, const CheckedPolygons& checked, const std::vector<int>& winding,
                   const FaceParts& faces, FreeSpace2D& space, FreeSpaceModels& models, bool graphOnly,
                   bool withModelPoints, int threadCount) {
    const Triangulation2D& tri = space.tri;
    const size_t faceCount = tri.faceCount(), vertexCount = tri.vertexCount();
    const size_t faceBlocks = faceBlockCount(faceCount);
    const std::vector<int>& vertexPart = faces.vertexPart;
    const std::vector<int>& facePart = faces.facePart;
    const std::vector<uint8_t>& faceRingEdges = faces.faceRingEdges;
    // 4. Models: parts of one feature, touching or overlapping parts, parts nested in others.
    const uint32_t partCount = static_cast<uint32_t>(checked.parts.size());
    DisjointSets parts(partCount);
    for (uint32_t p = 1; p < partCount; ++p)
        if (checked.partFeature[p] == checked.partFeature[p - 1]) parts.unite(p, p - 1);
    std::vector<char>& partTouches = models.partTouches;
    partTouches.assign(partCount, 0);
    auto join = [&](uint32_t a, uint32_t b) {
        if (checked.partFeature[a] != checked.partFeature[b]) partTouches[a] = partTouches[b] = 1;
        parts.unite(a, b);
    };
    for (auto [a, b] : checked.touchingParts) join(a, b);
    // Interior faces of two parts side by side (found in parallel, joined in block order; the
    // models do not depend on the order).
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> adjacentParts(faceBlocks);
    parallelFor(faceBlocks, threadCount, [&](size_t block) {
        for (size_t f = faceCount * block / faceBlocks; f < faceCount * (block + 1) / faceBlocks; ++f)
            for (int j = 0; j < 3; ++j) {
                const int n = tri.neighbors[3 * f + j];
                if (n < 0 || facePart[f] < 0 || facePart[n] < 0 || facePart[f] == facePart[n]) continue;
                adjacentParts[block].emplace_back(facePart[f], facePart[n]);
            }
    });
    for (const auto& list : adjacentParts)
        for (auto [a, b] : list) join(a, b);
    std::vector<int>& partModel = models.partModel;
    std::vector<int> modelOfRoot(partCount, -1);
    partModel.assign(partCount, -1);
    for (uint32_t p = 0; p < partCount; ++p) {
        const uint32_t r = parts.find(p);
        if (modelOfRoot[r] < 0) modelOfRoot[r] = static_cast<int>(space.modelCount++);
        partModel[p] = modelOfRoot[r];
    }
    space.vertexModel.assign(vertexCount, -1);
    parallelForEach(vertexCount, threadCount, [&](size_t v) {
        if (vertexPart[v] >= 0) space.vertexModel[v] = partModel[vertexPart[v]];
    });
    space.faceModel.assign(faceCount, -1);
    parallelForEach(faceCount, threadCount, [&](size_t f) {
        if (winding[f] >= 1) space.faceModel[f] = facePart[f] >= 0 ? partModel[facePart[f]] : 0;
    });
    if (!graphOnly) {  // read by every level
        space.cornerModel.resize(3 * faceCount);
        parallelForEach(3 * faceCount, threadCount, [&](size_t c) { space.cornerModel[c] = space.vertexModel[tri.faces[c]]; });
    }
    if (withModelPoints) space.modelPoints.resize(space.modelCount);
    for (size_t v = 0; v < in.part.size() && withModelPoints; ++v) {
        auto& pts = space.modelPoints[partModel[in.part[v]]];
        pts.push_back(in.x(v));
        pts.push_back(in.y(v));
    }
    if (!graphOnly) {
        // The models whose boundary is exactly their rings: none of their parts touches,
        // overlaps or lies inside another part (the triangulation would split or hide a ring
        // edge there), and no ring vertex is shared. Their polygons, ring by ring of `in`
        // (each part's exterior, then its holes), as the extraction would trace them.
        std::vector<char> modelPlain(space.modelCount, 1);
        for (auto [a, b] : checked.touchingParts) modelPlain[partModel[a]] = modelPlain[partModel[b]] = 0;
        for (const auto& list : adjacentParts)
            for (auto [a, b] : list) modelPlain[partModel[a]] = modelPlain[partModel[b]] = 0;
        for (size_t v = 0; v < in.part.size(); ++v)
            if (v >= in.shared.size() || in.shared[v]) modelPlain[partModel[in.part[v]]] = 0;
        for (size_t f = 0; f < faceCount; ++f)  // inside two polygons: nested or overlapping parts
            if (winding[f] >= 2 && space.faceModel[f] >= 0) modelPlain[space.faceModel[f]] = 0;
        // And every ring segment is still one constrained edge, with the model's face on its
        // left (a vertex of another of its rings on it, e.g. a hole touching the exterior,
        // splits it): the faces' whole ring segments, per model, against its segments.
        std::vector<size_t> intactSegments(space.modelCount, 0), ringSegments(space.modelCount, 0);
        for (size_t f = 0; f < faceCount; ++f)
            if (space.faceModel[f] >= 0) intactSegments[space.faceModel[f]] += faceRingEdges[f];
        for (size_t v = 0; v < in.part.size(); ++v) ++ringSegments[partModel[in.part[v]]];
        for (size_t m = 0; m < space.modelCount; ++m)
            if (intactSegments[m] != ringSegments[m]) modelPlain[m] = 0;
        space.modelPolygons.assign(space.modelCount, {});
        for (size_t v = 0; v < in.part.size(); v += in.ringSize[v]) {
            const uint32_t p = in.part[v];
            const int m = partModel[p];
            if (!modelPlain[m]) continue;
            std::vector<double> ring(in.points.begin() + 2 * v, in.points.begin() + 2 * (v + in.ringSize[v]));
            if (v == 0 || in.part[v - 1] != p) space.modelPolygons[m].push_back(Polygon2D{std::move(ring), {}});
            else space.modelPolygons[m].back().holes.push_back(std::move(ring));
        }
    }
}

}  // namespace aggrelod::detail
