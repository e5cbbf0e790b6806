// SPDX-License-Identifier: AGPL-3.0-or-later
// The 2D level driver (paper Algorithm 1 and Section 4.2; docs/design.md §2.3 and §2.5):
// thresholds (explicit or automatic), the aggregate function's edge limits, then every level
// in parallel: groups, sculpting (sculpt_2d.cpp), polygons, measures and the convex-hull,
// constant and adaptive baselines.
#include "baker_2d.h"

#include "convex_hull.h"
#include "level_driver.h"
#include "parallel_for.h"
#include "sculpt_2d.h"

namespace aggrelod::detail {

void buildLevels2D(const std::vector<Feature2D>& features, const Settings2D& settings, const FreeSpace2D& space,
                   const std::vector<uint32_t>& mergePair, bool needHulls, StageTimer& timer, Hierarchy2D& out) {
    timer.begin("sculpt levels");
    const std::vector<double> deltas =
        levelThresholds(settings.deltas, [&] { return automaticDeltas(out.merges, settings.automaticLevelCount); });
    const AggregateFunction primary = settings.customFunction ? settings.customFunction
                                                              : makeAggregateFunction(settings.function);
    const AggregateFunction constant = makeAggregateFunction(AggregateFunctionKind::Constant);
    const AggregateFunction adaptive = makeAggregateFunction(AggregateFunctionKind::Adaptive);
    const ConnectionFans2D fans = settings.shape == Shape2D::Sculpted || settings.computeBaselines
                                      ? computeConnectionFans2D(space, mergePair, settings.threadCount)
                                      : ConnectionFans2D{};
    // F of every pair at every level: a custom function (user code) on the calling thread, the
    // built-in ones inside the parallel level loop below.
    const size_t levelCount = deltas.size();
    std::vector<EdgeLimits> primaryLimits(levelCount), constantLimits(levelCount), adaptiveLimits(levelCount);
    const bool limitsInLevels = !settings.customFunction;
    for (size_t li = 0; li < levelCount && !limitsInLevels; ++li) {
        if (settings.shape == Shape2D::Sculpted) primaryLimits[li] = computeEdgeLimits(space, deltas[li], primary);
        if (settings.computeBaselines) {
            constantLimits[li] = computeEdgeLimits(space, deltas[li], constant);
            adaptiveLimits[li] = computeEdgeLimits(space, deltas[li], adaptive);
        }
    }
    // Levels are independent: sculpted in parallel, each writing only its own slot.
    out.levels.resize(levelCount);
    auto buildLevel = [&](size_t li) {
        if (limitsInLevels) {
            if (settings.shape == Shape2D::Sculpted) primaryLimits[li] = computeEdgeLimits(space, deltas[li], primary);
            if (settings.computeBaselines) {
                constantLimits[li] = computeEdgeLimits(space, deltas[li], constant);
                adaptiveLimits[li] = computeEdgeLimits(space, deltas[li], adaptive);
            }
        }
        Level2D& level = out.levels[li];
        std::vector<int> label;
        level.delta = deltas[li];
        size_t groupCount = 0;
        const std::vector<uint32_t> modelGroup = groupsAtThreshold(space.modelCount, out.merges, level.delta, &groupCount);
        size_t joined = 0;  // the merges of this level: the first ones (ascending height)
        while (joined < out.merges.size() && out.merges[joined].height < level.delta) ++joined;
        level.aggregates.resize(groupCount);
        // Sources and hulls of every group.
        for (size_t f = 0; f < features.size(); ++f)
            if (out.featureModel[f] >= 0)
                level.aggregates[modelGroup[out.featureModel[f]]].sourceFeatures.push_back(static_cast<uint32_t>(f));
        std::vector<std::vector<double>> hulls;
        if (needHulls) {
            std::vector<std::vector<double>> groupPoints(groupCount);
            for (size_t m = 0; m < space.modelCount; ++m) {
                auto& gp = groupPoints[modelGroup[m]];
                gp.insert(gp.end(), space.modelPoints[m].begin(), space.modelPoints[m].end());
            }
            hulls.resize(groupCount);
            for (size_t g = 0; g < groupCount; ++g) {
                hulls[g] = convexHull2D(std::move(groupPoints[g]));
                level.hull.area += ringSignedArea(hulls[g]);
                level.hull.perimeter += ringLength(hulls[g]);
            }
            level.hull.circularity = circularity(level.hull.area, level.hull.perimeter);
        }
        if (settings.shape == Shape2D::ConvexHull) {
            for (size_t g = 0; g < groupCount; ++g) {
                Aggregate2D& agg = level.aggregates[g];
                agg.polygons.push_back(Polygon2D{hulls[g], {}});
                agg.measures.area = ringSignedArea(hulls[g]);
                agg.measures.perimeter = ringLength(hulls[g]);
                agg.measures.circularity = circularity(agg.measures.area, agg.measures.perimeter);
            }
        } else {
            sculptLevel2D(space, modelGroup, primaryLimits[li], fans, joined, label);
            std::vector<int> groupModel(groupCount, -1);  // its model when it has one only
            std::vector<uint32_t> groupSize(groupCount, 0);
            for (size_t m = 0; m < space.modelCount; ++m)
                if (groupSize[modelGroup[m]]++ == 0) groupModel[modelGroup[m]] = static_cast<int>(m);
            for (size_t g = 0; g < groupCount; ++g)
                if (groupSize[g] != 1) groupModel[g] = -1;
            extractPolygons2D(space, label, groupCount, level.aggregates, &groupModel);
        }
        for (const Aggregate2D& agg : level.aggregates) {
            level.measures.area += agg.measures.area;
            level.measures.perimeter += agg.measures.perimeter;
        }
        level.measures.circularity = circularity(level.measures.area, level.measures.perimeter);
        if (settings.computeBaselines) {
            sculptLevel2D(space, modelGroup, constantLimits[li], fans, joined, label);
            level.constant = measureLabels2D(space, label);
            sculptLevel2D(space, modelGroup, adaptiveLimits[li], fans, joined, label);
            level.adaptive = measureLabels2D(space, label);
        }
    };
    parallelFor(levelCount, settings.threadCount, buildLevel,
                [&](size_t done) { timer.report(static_cast<double>(done) / static_cast<double>(levelCount)); });
}

}  // namespace aggrelod::detail
