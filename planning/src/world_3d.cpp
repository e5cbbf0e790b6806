// SPDX-License-Identifier: AGPL-3.0-or-later
// The 3D planning world (paper Sections 4.3 and 4.4): a ball agent against one level of a baked
// runtime file, through the runtime's Embree collision world (one per level). A state is free
// when no triangle of the level lies within the radius (sphere query) and its centre is not
// inside a solid (the first surface a ray meets is seen from its back: meshes are closed and
// outward); a motion is free when the capsule it sweeps meets no triangle.
#include <aggrelod/collision.h>
#include <aggrelod/planning.h>
#include <aggrelod/runtime_file.h>

#include <cmath>
#include <stdexcept>

namespace aggrelod::planning {
namespace {

class World3D final : public PlanningWorld {
public:
    World3D(const runtime::RuntimeFile& file, double radius) : radius_(radius) {
        if (!(radius > 0)) throw std::invalid_argument("the agent radius must be > 0");
        std::vector<uint32_t> fileLevels = runtime::levelsOf(file);
        levelIds_.push_back(runtime::kLeafLevel);
        levelIds_.insert(levelIds_.end(), fileLevels.begin(), fileLevels.end());
        for (uint32_t id : levelIds_) {
            auto world = std::make_unique<runtime::CollisionWorld>(file, 2);
            world->useLevel(id);
            if (!world->ok()) throw std::runtime_error("Embree: " + world->error());
            worlds_.push_back(std::move(world));
            double delta = 0;
            if (id != runtime::kLeafLevel)
                for (const runtime::NodeRecord& n : file.nodes())
                    if (n.level == id) delta = std::max(delta, double(n.delta));
            deltas_.push_back(delta);
        }
        lo_ = {INFINITY, INFINITY, INFINITY};
        hi_ = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t r : file.roots()) {
            const runtime::NodeRecord& n = file.node(r);
            for (int k = 0; k < 3; ++k) {
                lo_[size_t(k)] = std::min(lo_[size_t(k)], double(n.boundsMin[k]));
                hi_[size_t(k)] = std::max(hi_[size_t(k)], double(n.boundsMax[k]));
            }
        }
    }

    int dimension() const override { return 3; }
    int levelCount() const override { return int(worlds_.size()); }
    double levelDelta(int level) const override { return deltas_[size_t(level)]; }
    int levelNumber(int level) const override { return level == 0 ? -1 : int(levelIds_[size_t(level)]); }
    Point boundsMin() const override { return lo_; }
    Point boundsMax() const override { return hi_; }
    double radius() const override { return radius_; }

    bool stateFree(int level, const Point& p) const override {
        for (int k = 0; k < 3; ++k)
            if (!(p[size_t(k)] >= lo_[size_t(k)] && p[size_t(k)] <= hi_[size_t(k)])) return false;
        const runtime::CollisionWorld& w = *worlds_[size_t(level)];
        const float c[3] = {float(p[0]), float(p[1]), float(p[2])};
        if (w.sphereTouches(c, float(radius_))) return false;
        // Inside test: a direction off the axes, so rays do not run along the faces of boxes.
        static const float kDir[3] = {0.8017837f, 0.5345225f, 0.2672612f};
        runtime::CollisionHit hit;
        if (!w.raycast(c, kDir, INFINITY, hit)) return true;
        return hit.normal[0] * kDir[0] + hit.normal[1] * kDir[1] + hit.normal[2] * kDir[2] <= 0;
    }

    bool motionFree(int level, const Point& a, const Point& b) const override {
        const float fa[3] = {float(a[0]), float(a[1]), float(a[2])};
        const float fb[3] = {float(b[0]), float(b[1]), float(b[2])};
        return !worlds_[size_t(level)]->capsuleTouches(fa, fb, float(radius_));
    }

private:
    double radius_;
    std::vector<uint32_t> levelIds_;
    std::vector<std::unique_ptr<runtime::CollisionWorld>> worlds_;
    std::vector<double> deltas_;
    Point lo_{}, hi_{};
};

}  // namespace

std::unique_ptr<PlanningWorld> makeWorld3D(const runtime::RuntimeFile& file, double radius) {
    return std::make_unique<World3D>(file, radius);
}

}  // namespace aggrelod::planning
