// SPDX-License-Identifier: AGPL-3.0-or-later
// The 2D bake (paper Algorithm 1, Sections 3.1-3.3 and 4.2; docs/design.md §2 in 2D), read top
// to bottom: check the input, one constrained Delaunay triangulation, free space, models and
// neighbourhood graph, the Kruskal dendrogram (shared with 3D), Steiner points at the
// dendrogram's connections and the free space again, then every level.
#include "baker_2d.h"

#include <atomic>
#include <cmath>
#include <future>

namespace aggrelod {

namespace {
using namespace detail;

std::string joinNames(const std::vector<Feature2D>& features, const std::vector<uint32_t>& ids) {
    std::string s;
    const size_t shown = std::min<size_t>(ids.size(), 6);
    for (size_t i = 0; i < shown; ++i) s += (i ? ", " : "") + features[ids[i]].name;
    if (ids.size() > shown) s += " and " + std::to_string(ids.size() - shown) + " more";
    return s;
}

}  // namespace

std::vector<std::vector<Polygon2D>> acceptedPolygons2D(const std::vector<Feature2D>& features,
                                                       std::vector<Diagnostic>& diagnostics) {
    CheckedPolygons checked;
    checkPolygons(features, checked, diagnostics);
    std::vector<std::vector<Polygon2D>> out(features.size());
    for (size_t p = 0; p < checked.parts.size(); ++p) out[checked.partFeature[p]].push_back(std::move(checked.parts[p]));
    return out;
}

bool buildHierarchy2D(const std::vector<Feature2D>& features, const Settings2D& settings, Hierarchy2D& out) {
    out = Hierarchy2D{};
    out.featureModel.assign(features.size(), -1);
    StageTimer timer(out.timings, settings.progress);
    auto fail = [&](const std::string& message) {
        out.diagnostics.push_back({Diagnostic::Severity::Error, "", message});
        return false;
    };
    if (std::string problem; !validThresholds(settings.deltas, problem)) return fail(problem);

    // 1. Input checks, in two steps: the rings are cleaned and oriented first; the contact
    // checks (self-intersections, crossings, touching polygons) then run on another thread
    // while CGAL triangulates the cleaned rings, followed there by the segment grid of the
    // free-space pass (they touch different members of `in`). When the contact checks drop a
    // polygon they cancel that triangulation, which is then made again without it.
    timer.begin("check input");
    CheckedPolygons checked;
    PolygonCheckProgress checkProgress;
    cleanPolygons(features, checked, out.diagnostics, checkProgress);
    const size_t cleanedParts = checked.parts.size();
    InputVertices in = inputVertices(checked, nullptr, /*withGrid=*/false);
    std::vector<Diagnostic> contactDiagnostics;
    std::atomic<bool> partsDropped{false};
    auto checkContacts = [&] {
        checkPolygonContacts(features, checked, contactDiagnostics, checkProgress);
        if (checked.parts.size() != cleanedParts) {  // `in` is made again below
            partsDropped = true;
            return;
        }
        markTouchingParts(in, checked);
        buildSegmentGrid(in);
    };
    std::future<void> contactsLater;
    if (settings.threadCount != 1 && cleanedParts > 0) contactsLater = std::async(std::launch::async, checkContacts);
    else checkContacts();
    timer.begin("triangulate");

    const bool needHulls = settings.computeBaselines || settings.shape == Shape2D::ConvexHull;
    // 2.-5. Triangulation, free space, models and graph; then once more with Steiner points
    // on long boundary edges at the shortest connections of the dendrogram (docs/design.md §2.4
    // step 4), so that joined models get a narrow bridge of small triangles.
    FreeSpace2D space;
    FreeSpaceModels models;
    std::string error;
    ConstrainedTriangulation2D triangulation;
    bool triangulated = cleanedParts > 0 && !partsDropped &&
                        triangulation.build(in.points, in.segments, space.tri, error, settings.threadCount, &partsDropped);
    if (contactsLater.valid()) contactsLater.get();
    out.diagnostics.insert(out.diagnostics.end(), contactDiagnostics.begin(), contactDiagnostics.end());
    if (checked.parts.empty()) return fail("no usable polygon in the input");
    if (checked.parts.size() != cleanedParts) {  // a polygon was dropped: triangulate without it
        in = inputVertices(checked, nullptr);
        triangulated = triangulation.build(in.points, in.segments, space.tri, error, settings.threadCount);
    }
    if (!triangulated) return fail(error);
    for (const Polygon2D& poly : checked.parts) {
        out.originals.area += ringSignedArea(poly.exterior);
        out.originals.perimeter += ringLength(poly.exterior);
        for (const auto& hole : poly.holes) {
            out.originals.area += ringSignedArea(hole);
            out.originals.perimeter += ringLength(hole);
        }
    }
    out.originals.circularity = circularity(out.originals.area, out.originals.perimeter);
    setShared(in, space.tri);
    timer.begin("free space and graph");
    std::vector<int> winding = windingNumbers(in, space.tri, settings.threadCount);
    buildFreeSpace(in, checked, winding, space, models, /*graphOnly=*/true, settings.threadCount);
    // Unconstrained edges of free triangles (hull edges included), before Steiner points:
    // the edges GEOS's ConcaveHullOfPolygons takes for its length ratio.
    out.freeEdgeMin = INFINITY;
    for (size_t f = 0; f < space.tri.faceCount(); ++f)
        for (int j = 0; j < 3; ++j) {
            if (space.faceModel[f] >= 0 || space.tri.constrained[3 * f + j]) continue;
            out.freeEdgeMin = std::min(out.freeEdgeMin, space.edgeLength[3 * f + j]);
            out.freeEdgeMax = std::max(out.freeEdgeMax, space.edgeLength[3 * f + j]);
        }
    if (!std::isfinite(out.freeEdgeMin)) out.freeEdgeMin = 0;
    std::vector<uint32_t> mergePair;  // per merge: its index in space.pairs
    out.merges = kruskalMerges(space.modelCount, weighedGraph(space), &mergePair);
    if (!refineConnections2D(checked, in, winding, space, models, mergePair, needHulls, settings.threadCount, timer, out,
                             error))
        return fail(error);
    timer.begin("models");
    out.vertexCount = space.tri.vertexCount();
    out.triangleCount = space.tri.faceCount();
    out.modelCount = space.modelCount;
    for (uint32_t p = 0; p < checked.parts.size(); ++p) out.featureModel[checked.partFeature[p]] = models.partModel[p];
    {
        std::vector<std::vector<uint32_t>> modelFeatures(space.modelCount);
        std::vector<char> modelTouches(space.modelCount, 0);
        for (uint32_t p = 0; p < checked.parts.size(); ++p) {
            auto& list = modelFeatures[models.partModel[p]];
            if (list.empty() || list.back() != checked.partFeature[p]) list.push_back(checked.partFeature[p]);
            if (models.partTouches[p]) modelTouches[models.partModel[p]] = 1;
        }
        for (size_t m = 0; m < space.modelCount; ++m)
            if (modelTouches[m] && modelFeatures[m].size() > 1)
                out.diagnostics.push_back({Diagnostic::Severity::Note, joinNames(features, modelFeatures[m]),
                                           "these " + std::to_string(modelFeatures[m].size()) +
                                               " features touch or overlap; merged into one model"});
    }

    buildLevels2D(features, settings, space, mergePair, needHulls, timer, out);
    timer.end();
    return true;
}

}  // namespace aggrelod
