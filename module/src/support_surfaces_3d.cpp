// SPDX-License-Identifier: AGPL-3.0-or-later
// Support surfaces (docs/design.md §2.0): ground, terrain, sky dome, road network and room
// shell are found by a rule on their extent and contacts and kept out of aggregation.
#include "baker_3d.h"

namespace aggrelod::detail {

// Support surfaces (docs/design.md §2.0): ground, terrain, sky dome, road network, room shell. The
// rule (Settings3D::supportSpanFraction): an object that spans most of the scene in two
// axes and whose box meets the boxes of a large share of the other objects carries or
// encloses them; aggregating it would join everything into one blob at the finest level.
std::vector<char> findSupportSurfaces(const std::vector<const double*>& bounds, const Settings3D& settings) {
    const size_t n = bounds.size();
    std::vector<char> support(n, 0);
    std::vector<uint32_t> usable;
    for (uint32_t i = 0; i < n; ++i)
        if (bounds[i]) usable.push_back(i);
    if (settings.support == SupportDetection::Given) {
        for (uint32_t i : settings.supportObjects)
            if (i < n && bounds[i]) support[i] = 1;
    } else if (settings.support == SupportDetection::Automatic) {
        // Peeled in rounds: a huge outer ground hides the town's own ground and roads,
        // which span the box of what is left once it is set aside.
        for (int round = 0; round < 3; ++round) {
            std::vector<uint32_t> rest;
            for (uint32_t i : usable)
                if (!support[i]) rest.push_back(i);
            if (rest.size() < 3) break;
            double scene[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
            for (uint32_t i : rest)
                for (int k = 0; k < 3; ++k) {
                    scene[k] = std::min(scene[k], bounds[i][k]);
                    scene[3 + k] = std::max(scene[3 + k], bounds[i][3 + k]);
                }
            // The scene's two longest axes (ties: lower axis first).
            int axes[3] = {0, 1, 2};
            std::stable_sort(axes, axes + 3, [&](int x, int y) { return scene[3 + x] - scene[x] > scene[3 + y] - scene[y]; });
            const double pad = 0.01 * std::sqrt((scene[3] - scene[0]) * (scene[3] - scene[0]) + (scene[4] - scene[1]) * (scene[4] - scene[1]) +
                                                (scene[5] - scene[2]) * (scene[5] - scene[2]));
            auto pairs = overlappingPairs(rest.size(), [&](uint32_t k) { return bounds[rest[k]]; }, pad);
            std::vector<size_t> meets(rest.size(), 0);
            for (auto [x, y] : pairs) {
                ++meets[x];
                ++meets[y];
            }
            const double others = double(rest.size() - 1);
            std::vector<uint32_t> found;
            for (size_t k = 0; k < rest.size(); ++k) {
                const double* b = bounds[rest[k]];
                bool wide = true;
                for (int j = 0; j < 2; ++j) {
                    const int d = axes[j];
                    wide = wide && b[3 + d] - b[d] >= settings.supportSpanFraction * (scene[3 + d] - scene[d]);
                }
                if (wide && meets[k] >= 2 && double(meets[k]) >= settings.supportShareFraction * others) found.push_back(rest[k]);
            }
            // At least two objects must be left to aggregate.
            if (found.empty() || rest.size() - found.size() < 2) break;
            for (uint32_t i : found) support[i] = 1;
        }
    }
    return support;
}

void Baker3D::detectSupport() {
    const size_t n = objects_.size();
    std::vector<const double*> bounds(n, nullptr);
    for (uint32_t i = 0; i < n; ++i)
        if (prepared_[i].usable) bounds[i] = prepared_[i].bounds;
    support_ = findSupportSurfaces(bounds, settings_);
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < n; ++i)
        if (support_[i]) ids.push_back(i);
    out_.supportObjects = ids;
    if (!ids.empty())
        diag(out_, Diagnostic::Severity::Warning, objectNames(objects_, ids, 20),
             std::string(settings_.support == SupportDetection::Given ? "support surfaces as asked"
                                                                      : "support surfaces (span the scene and meet most objects)") +
                 ": kept out of aggregation and passed through unchanged (--support none aggregates them)");
}

}  // namespace aggrelod::detail
