// SPDX-License-Identifier: AGPL-3.0-or-later
// Objects to models (docs/design.md §2.0): clean each object, group the ones that touch
// into models (the vertices of the neighbourhood graph), solidify the ones that are not
// valid closed solids, and per model the BVH and convex hull the later stages read.
#include "baker_3d.h"
#include "convex_hull.h"
#include "surface_colors.h"
#include "parallel_for.h"

#include <aggrelod/disjoint_sets.h>

namespace aggrelod::detail {

bool Baker3D::prepare() {
    timer_.begin("prepare");
    out_.diagnostics.clear();
    diagonal_ = finiteDiagonal(objects_);  // scene size, for relative tolerances
    tolerance_ = settings_.touchTolerance >= 0 ? settings_.touchTolerance : 1e-6 * diagonal_;
    const double areaEpsilon = 1e-14 * diagonal_ * diagonal_;
    for (const InputObject& o : objects_)
        if (!o.triangleColors.empty() && !hasTriangleColors(o))
            diag(out_, Diagnostic::Severity::Warning, o.name,
                 "triangleColors has " + std::to_string(o.triangleColors.size()) + " values, expected 4 per triangle (" +
                     std::to_string(4 * (o.indices.size() / 3)) + "); the object counts as white");
    prepared_.resize(objects_.size());
    size_t usable = 0;
    for (size_t i = 0; i < objects_.size(); ++i) {
        prepareObject(objects_[i], areaEpsilon, prepared_[i], out_.diagnostics);
        if (prepared_[i].usable) {
            ++usable;
            out_.inputTriangleCount += prepared_[i].triangles.size() / 3;
            out_.originals.volume += prepared_[i].volume;
            out_.originals.area += prepared_[i].area;
        }
        timer_.report(double(i + 1) / objects_.size());
    }
    out_.originals = measuresOf(out_.originals.volume, out_.originals.area);
    if (usable == 0) {
        diag(out_, Diagnostic::Severity::Error, "", objects_.empty() ? "the scene has no objects" : "no usable object in the scene");
        return false;
    }
    for (double d : settings_.deltas)
        if (d > 0) smallestDelta_ = std::min(smallestDelta_, d);
    detectSupport();
    if (usable == out_.supportObjects.size()) {
        diag(out_, Diagnostic::Severity::Error, "", "every usable object is a support surface: nothing to aggregate");
        return false;
    }
    return true;
}

void Baker3D::buildModels() {
    timer_.begin("models");
    const size_t n = objects_.size();
    objectBvh_.assign(n, TriangleBvh{});
    std::vector<TriangleBvh>& bvh = objectBvh_;
    parallelFor(n, settings_.threadCount, [&](size_t i) {
        if (prepared_[i].usable)
            bvh[i].build(prepared_[i].positions.data(), prepared_[i].positions.size() / 3, prepared_[i].triangles.data(),
                         prepared_[i].triangles.size() / 3);
    });
    std::vector<uint32_t> usable;
    for (uint32_t i = 0; i < n; ++i)
        if (prepared_[i].usable && !support_[i]) usable.push_back(i);
    auto pairs = overlappingPairs(usable.size(), [&](uint32_t k) { return prepared_[usable[k]].bounds; }, tolerance_);
    DisjointSets sets(n);
    for (size_t p = 0; p < pairs.size(); ++p) {
        uint32_t i = usable[pairs[p].first], j = usable[pairs[p].second];
        if (i > j) std::swap(i, j);
        ClosestPair cp = meshDistance(bvh[i], bvh[j], tolerance_, tolerance_);
        if (cp.distance <= tolerance_) {
            sets.unite(i, j);
            diag(out_, Diagnostic::Severity::Note, objects_[i].name + ", " + objects_[j].name,
                 cp.intersecting ? "objects intersect; aggregated as one model from the start"
                                 : "objects touch (distance " + fmt(cp.distance) + " <= tolerance " + fmt(tolerance_) +
                                       "); aggregated as one model from the start");
        }
        if (p % 64 == 0) timer_.report(double(p) / std::max<size_t>(pairs.size(), 1));
    }
    std::map<uint32_t, size_t> modelOfRoot;
    for (uint32_t i : usable) {
        uint32_t r = sets.find(i);
        auto it = modelOfRoot.find(r);
        if (it == modelOfRoot.end()) {
            it = modelOfRoot.emplace(r, models_.size()).first;
            models_.emplace_back();
        }
        models_[it->second].objects.push_back(i);
    }
    // A closed surface that crosses itself would fail the triangulation (and TetGen's own
    // search for the crossing facets is slow): find those first.
    std::vector<char> crossing(models_.size(), 0);
    parallelFor(models_.size(), settings_.threadCount, [&](size_t i) {
        const Model& m = models_[i];
        if (m.objects.size() == 1 && prepared_[m.objects[0]].validSolid())
            crossing[i] = selfIntersects(prepared_[m.objects[0]].positions, prepared_[m.objects[0]].triangles);
    });
    std::vector<size_t> toSolidify;
    std::vector<std::string> why;
    for (size_t i = 0; i < models_.size(); ++i) {
        Model& m = models_[i];
        for (uint32_t o : m.objects) m.volumeOriginal += prepared_[o].volume;
        if (crossing[i]) {
            toSolidify.push_back(i);
            why.push_back("self-intersecting surface");
        } else if (m.objects.size() == 1 && prepared_[m.objects[0]].validSolid()) {
            m.positions = prepared_[m.objects[0]].positions;
            m.triangles = prepared_[m.objects[0]].triangles;
        } else {
            toSolidify.push_back(i);
            why.push_back(m.objects.size() == 1 ? "not a closed, consistently oriented solid"
                                                : "touching or intersecting objects form one model");
        }
    }
    solidifyNestedLast(toSolidify, why);
}

// Objects' bounding box (of their original surfaces).
void Baker3D::objectsBounds(const std::vector<uint32_t>& objects, double box[6]) const {
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    for (uint32_t o : objects)
        for (int k = 0; k < 3; ++k) {
            box[k] = std::min(box[k], prepared_[o].bounds[k]);
            box[3 + k] = std::max(box[3 + k], prepared_[o].bounds[3 + k]);
        }
}

// Per model: BVH of its surface (for exact distances) and convex hull (for the baseline).
void Baker3D::prepareModels(int threadCount) {
    parallelFor(models_.size(), threadCount, [&](size_t m) {
        Model& model = models_[m];
        model.bvh.build(model.positions.data(), model.positions.size() / 3, model.triangles.data(), model.triangles.size() / 3);
        if (!settings_.computeHullBaseline) return;
        if (!model.standIn()) {
            model.hullVolume = convexHullVolume(model.positions, &model.hullPoints);
            return;
        }
        // The baseline is the hull of the originals, not of their (slightly larger) solid.
        std::vector<double> points;
        for (uint32_t o : model.objects) points.insert(points.end(), prepared_[o].positions.begin(), prepared_[o].positions.end());
        model.hullVolume = convexHullVolume(points, &model.hullPoints);
    });
    modelsPrepared_ = true;
}

}  // namespace aggrelod::detail
