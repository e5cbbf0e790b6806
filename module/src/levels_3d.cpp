// SPDX-License-Identifier: AGPL-3.0-or-later
// The level driver (paper Algorithm 1; docs/design.md §2.3 and §2.5): the dendrogram, the
// thresholds (explicit or automatic), then per level in parallel the sculpted aggregates
// (sculpt_3d.cpp), their sources, colours and measures, and the convex-hull baseline.
#include "baker_3d.h"
#include "convex_hull.h"
#include "level_driver.h"
#include "parallel_for.h"
#include "sculpt_3d.h"
#include "surface_colors.h"

#include <aggrelod/dendrogram.h>

#include <array>
#include <memory>

namespace aggrelod::detail {

// Automatic thresholds that change something one can see (docs/design.md §2.3). Merges closer than
// 0.1 % of the diagonal of the aggregated objects (support surfaces left out) look the same
// as touching at any distance where the scene is seen whole: the geometric series of levels
// starts at the first merge above that, and runs to the last merge. The finest level sits
// at half of that first visible merge, so it shows every model apart (except those nearer
// than that) before anything visible is joined.
std::vector<double> Baker3D::visibleDeltas() const {
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const Model& m : models_)
        for (uint32_t o : m.objects)
            for (int k = 0; k < 3; ++k) {
                box[k] = std::min(box[k], prepared_[o].bounds[k]);
                box[3 + k] = std::max(box[3 + k], prepared_[o].bounds[3 + k]);
            }
    const double diagonal = box[0] <= box[3] ? std::sqrt((box[3] - box[0]) * (box[3] - box[0]) + (box[4] - box[1]) * (box[4] - box[1]) +
                                                         (box[5] - box[2]) * (box[5] - box[2]))
                                             : 0.0;
    const double visible = 1e-3 * diagonal;
    std::vector<Merge> seen;
    for (const Merge& m : out_.merges)
        if (m.height >= visible) seen.push_back(m);
    if (seen.empty()) seen = out_.merges;
    const int count = settings_.automaticLevelCount;
    std::vector<double> deltas = automaticDeltas(seen, count > 1 ? count - 1 : count);
    if (count > 1 && !seen.empty() && seen.front().height > 0) deltas.insert(deltas.begin(), 0.5 * seen.front().height);
    return deltas;
}

void Baker3D::buildLevels() {
    timer_.begin("hierarchy");
    precomputeTetEdges(space_, settings_.threadCount);
    out_.merges = kruskalMerges(models_.size(), weighedGraph());
    bool nothingToAggregate = false;
    const std::vector<double> deltas = levelThresholds(settings_.deltas, [&] { return visibleDeltas(); }, &nothingToAggregate);
    if (nothingToAggregate)
        diag(out_, Diagnostic::Severity::Note, "",
             models_.size() == 1 ? "only one model: nothing to aggregate; the single level holds it alone"
                                 : "no two models are neighbours: nothing to aggregate");

    AggregateFunction constant = makeAggregateFunction(AggregateFunctionKind::Constant);
    const bool isConstant = !settings_.customFunction && settings_.function == AggregateFunctionKind::Constant;
    const bool measureConstant = !isConstant && settings_.computeConstantBaseline;
    timer_.begin("levels");

    // What each level needs, prepared here so the sculpting below touches only its own data.
    struct LevelWork {
        std::vector<uint32_t> modelGroup;
        size_t groupCount = 0;
        EdgeLimits limits, constantLimits;
        LevelShapeRequest request;
        std::vector<Aggregate> aggregates;
        double volumeConstant = 0;
        double totalVolume = 0, totalArea = 0;  ///< sums over the level's aggregates
        size_t triangleCount = 0;
    };
    std::vector<LevelWork> work(deltas.size());
    for (size_t li = 0; li < deltas.size(); ++li) {
        LevelWork& w = work[li];
        w.modelGroup = groupsAtThreshold(models_.size(), out_.merges, deltas[li], &w.groupCount);
        w.limits = computeEdgeLimits(space_, deltas[li], function_, settings_.distance);
        if (measureConstant) w.constantLimits = computeEdgeLimits(space_, deltas[li], constant, settings_.distance);
        w.request.modelGroup = &w.modelGroup;
        w.request.groupCount = w.groupCount;
        w.request.limits = &w.limits;
        for (const Merge& m : out_.merges) {
            if (!(m.height < deltas[li])) break;
            int p = findPair(space_.pairs, m.modelA, m.modelB);
            if (p < 0) continue;
            const ModelPair& pair = space_.pairs[p];
            ProtectedConnection c;
            c.modelA = pair.a;
            c.modelB = pair.b;
            const double* pa = pair.closestA;
            const double* pb = pair.closestB;
            if (settings_.distance == DistanceMode::Cdt) {
                pa = &space_.mesh.points[3 * pair.shortestEdgeVertexA];
                pb = &space_.mesh.points[3 * pair.shortestEdgeVertexB];
            }
            std::copy(pa, pa + 3, c.pointA);
            std::copy(pb, pb + 3, c.pointB);
            w.request.connections.push_back(c);
        }
    }

    // Hull baseline, level by level: starts from each model's own hull. A group's hull is
    // the hull of its sub-groups' hulls at the previous level (groups only coarsen): a group
    // unchanged since then keeps its hull, others are built from the few vertices of their
    // parts' hulls. It does not depend on the sculpting, so it runs as one more task beside
    // the levels (one chain, in level order), keeping both cores busy to the end.
    struct GroupHull {
        std::vector<double> vertices;
        double volume = 0;
    };
    std::vector<std::vector<double>> hullVolumes(deltas.size());  ///< per level, per group
    auto computeHullBaseline = [&] {
        std::vector<GroupHull> previousHulls(models_.size());
        std::vector<uint32_t> previousHullOfModel(models_.size());
        for (size_t m = 0; m < models_.size(); ++m) {
            previousHullOfModel[m] = static_cast<uint32_t>(m);
            previousHulls[m].vertices = models_[m].hullPoints;
            previousHulls[m].volume = models_[m].hullVolume;
        }
        for (size_t li = 0; li < deltas.size(); ++li) {
            const LevelWork& w = work[li];
            std::vector<GroupHull> hulls(w.groupCount);
            std::vector<std::vector<uint32_t>> parts(w.groupCount);
            for (size_t m = 0; m < models_.size(); ++m) parts[w.modelGroup[m]].push_back(previousHullOfModel[m]);
            for (size_t g = 0; g < w.groupCount; ++g) {
                std::vector<uint32_t>& p = parts[g];
                std::sort(p.begin(), p.end());
                p.erase(std::unique(p.begin(), p.end()), p.end());
                if (p.size() == 1) {
                    hulls[g] = previousHulls[p[0]];
                } else {
                    std::vector<double> points;
                    for (uint32_t part : p) points.insert(points.end(), previousHulls[part].vertices.begin(), previousHulls[part].vertices.end());
                    hulls[g].volume = convexHullVolume(points, &hulls[g].vertices);
                }
            }
            hullVolumes[li].resize(w.groupCount);
            for (size_t g = 0; g < w.groupCount; ++g) hullVolumes[li][g] = hulls[g].volume;
            for (size_t m = 0; m < models_.size(); ++m) previousHullOfModel[m] = w.modelGroup[m];
            previousHulls = std::move(hulls);
        }
    };

    // Levels are independent given the one triangulation: sculpt them on several threads;
    // each level writes only its own LevelWork. Coarse levels keep much more free space and
    // cost the most, so they are started first (the threads then finish together); the hull
    // baseline (when asked) runs as one task after the coarser half.
    // Buffers reused by the next level on whichever thread (at most one set per thread).
    ScratchPool<SculptScratch> scratchPool;
    std::vector<size_t> taskOrder;  // level index, or SIZE_MAX for the hull baseline
    for (size_t k = 0; k < work.size(); ++k) {
        if (settings_.computeHullBaseline && k == work.size() / 2) taskOrder.push_back(SIZE_MAX);
        taskOrder.push_back(work.size() - 1 - k);
    }
    parallelFor(
        taskOrder.size(), settings_.threadCount,
        [&](size_t task) {
            if (taskOrder[task] == SIZE_MAX) {
                computeHullBaseline();
                return;
            }
            const size_t li = taskOrder[task];
            LevelWork& w = work[li];
            std::unique_ptr<SculptScratch> scratch = scratchPool.take();
            std::vector<int>& label = scratch->label;
            std::vector<int>& constantLabel = scratch->baselineLabel;
            if (measureConstant) w.request.baselineLimits = &w.constantLimits;
            sculptLevel(space_, w.request, label, &constantLabel, &scratch->surfaceTets, scratch.get());
            extractSurfaces(space_, label, w.groupCount, w.aggregates, &scratch->surfaceTets, scratch.get());
            // Per-aggregate sources and measures, on the same thread (levels are independent).
            std::vector<std::array<size_t, 2>> kinds(w.aggregates.size(), {0, 0});  // original, solidified models
            for (size_t m = 0; m < models_.size(); ++m) {
                Aggregate& agg = w.aggregates[w.modelGroup[m]];
                agg.sourceObjects.insert(agg.sourceObjects.end(), models_[m].objects.begin(), models_[m].objects.end());
                agg.volumeOriginal += models_[m].volumeOriginal;
                ++kinds[w.modelGroup[m]][models_[m].standIn() ? 1 : 0];
            }
            for (size_t g = 0; g < w.aggregates.size(); ++g)
                w.aggregates[g].surface = kinds[g][1] == 0   ? Aggregate::Surface::Original
                                          : kinds[g][0] == 0 ? Aggregate::Surface::Solidified
                                                             : Aggregate::Surface::Mixed;
            for (Aggregate& agg : w.aggregates) {
                std::sort(agg.sourceObjects.begin(), agg.sourceObjects.end());
                std::vector<const InputObject*> sources;
                for (uint32_t o : agg.sourceObjects) sources.push_back(&objects_[o]);
                nearestSurfaceColors(agg.positions, agg.indices, sources, agg.faceColors);
                double v = 0, a = 0;
                meshVolumeArea(agg.positions, agg.indices, v, a);
                agg.measures = measuresOf(v, a);
                w.totalVolume += v;
                w.totalArea += a;
                w.triangleCount += agg.indices.size() / 3;
            }
            if (measureConstant)
                for (size_t t = 0; t < constantLabel.size(); ++t)
                    if (constantLabel[t] >= 0) w.volumeConstant += space_.tetVolume[t];
            scratchPool.giveBack(std::move(scratch));
        },
        [&](size_t done) { timer_.report(double(done) / taskOrder.size()); });

    timer_.begin("level measures");
    for (size_t li = 0; li < deltas.size(); ++li) {
        LevelWork& w = work[li];
        Level level;
        level.delta = deltas[li];
        std::vector<Aggregate>& aggregates = w.aggregates;
        const double totalVolume = w.totalVolume, totalArea = w.totalArea;
        level.triangleCount = w.triangleCount;
        level.measures = measuresOf(totalVolume, totalArea);
        level.volumeOriginal = out_.originals.volume;
        if (settings_.computeHullBaseline)
            for (size_t g = 0; g < w.groupCount; ++g) {
                aggregates[g].volumeHull = hullVolumes[li][g];
                level.volumeHull += hullVolumes[li][g];
            }
        level.volumeConstant = isConstant ? totalVolume : w.volumeConstant;
        level.hasVolumeConstant = isConstant || measureConstant;
        level.aggregates = std::move(aggregates);
        out_.levels.push_back(std::move(level));
        timer_.report(double(li + 1) / deltas.size());
    }
}

}  // namespace aggrelod::detail
