// SPDX-License-Identifier: AGPL-3.0-or-later
// The 3D bake (paper Algorithm 1; docs/design.md §2), read top to bottom: prepare objects
// and models, triangulate the free space once, build the neighbourhood graph (refined once
// where connections are coarse), measure the solids, then shape and measure every level.
#include "baker_3d.h"

#include <aggrelod/dendrogram.h>

namespace aggrelod::detail {

bool Baker3D::run() {
    out_ = Hierarchy3D{};
    function_ = settings_.customFunction ? settings_.customFunction : makeAggregateFunction(settings_.function);
    if (!prepare()) {
        timer_.end();
        return false;
    }
    buildModels();
    if (settings_.distance == DistanceMode::Exact) prerefineClosePairs();
    if (!triangulate()) {
        timer_.end();
        return false;
    }
    out_.modelCount = models_.size();
    out_.objectModel.assign(objects_.size(), UINT32_MAX);
    for (size_t m = 0; m < models_.size(); ++m)
        for (uint32_t o : models_[m].objects) out_.objectModel[o] = static_cast<uint32_t>(m);
    for (uint32_t o = 0; o < objects_.size(); ++o)
        if (out_.objectModel[o] == UINT32_MAX && !support_[o]) out_.leftOutObjects.push_back(o);
    if (!modelsPrepared_) {
        timer_.begin("model hulls");
        prepareModels(settings_.threadCount);
    }
    buildGraph();
    if (settings_.distance == DistanceMode::Exact && refineCoarseConnections()) {
        if (!triangulate()) {
            timer_.end();
            return false;
        }
        buildGraph();
    }
    if (graphOnly_) {
        out_.merges = kruskalMerges(models_.size(), weighedGraph());
        timer_.end();
        return true;
    }
    measureSolids();
    buildLevels();
    timer_.end();
    return true;
}

}  // namespace aggrelod::detail

namespace aggrelod {

bool buildHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings, Hierarchy3D& out) {
    if (std::string problem; !validThresholds(settings.deltas, problem)) {
        out = Hierarchy3D{};  // nothing of an earlier result stays
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", problem});
        return false;
    }
    try {
        detail::Baker3D baker(objects, settings, out);
        return baker.run();
    } catch (const std::exception& e) {
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", std::string("internal error: ") + e.what()});
        return false;
    }
}

}  // namespace aggrelod
