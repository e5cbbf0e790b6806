// SPDX-License-Identifier: MIT
// C API of the optional collision part (aggrelod_runtime.h, aglod_collision_* and
// aglod_raycast): thin wrappers over CollisionWorld.
#include <aggrelod_runtime.h>

#include <aggrelod/collision.h>

#include "c_api_internal.h"

#include <cmath>
#include <new>
#include <string>

using namespace aggrelod::runtime;
using aggrelod::runtime::capi::failWith;
using aggrelod::runtime::capi::inRange;

namespace {
/// A ray Embree can take: finite origin and direction within 1e18, a direction of non-zero
/// length, max_distance >= 0 (infinity allowed). Sets the last error otherwise.
bool validRay(const char* function, const float origin[3], const float direction[3], float max_distance) {
    if (!inRange(origin, 3) || !inRange(direction, 3)) {
        failWith(AGLOD_INVALID_ARGUMENT, std::string(function) + ": origin and direction must be finite, within 1e18");
        return false;
    }
    if (direction[0] == 0 && direction[1] == 0 && direction[2] == 0) {
        failWith(AGLOD_INVALID_ARGUMENT, std::string(function) + ": direction is zero");
        return false;
    }
    if (!(max_distance >= 0)) {
        failWith(AGLOD_INVALID_ARGUMENT, std::string(function) + ": max_distance must be >= 0 (or infinity)");
        return false;
    }
    return true;
}
}  // namespace

struct aglod_collision {
    CollisionWorld world;
    explicit aglod_collision(const RuntimeFile& f) : world(f, 0) {}
};

extern "C" {

aglod_collision* aglod_collision_create(const aglod_file* file) {
    if (!file) {
        failWith(AGLOD_INVALID_ARGUMENT, "aglod_collision_create: file is NULL");
        return nullptr;
    }
    try {
        auto* c = new aglod_collision(file->file);
        c->world.useLevel(kLeafLevel);
        if (!c->world.ok()) {
            failWith(AGLOD_COLLISION_ERROR, c->world.error());
            delete c;
            return nullptr;
        }
        return c;
    } catch (const std::exception& e) {
        failWith(AGLOD_COLLISION_ERROR, e.what());
        return nullptr;
    }
}

void aglod_collision_destroy(aglod_collision* collision) { delete collision; }

aglod_status aglod_collision_use_level(aglod_collision* collision, uint32_t level) {
    if (!collision) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_collision_use_level: NULL collision");
    try {
        collision->world.useLevel(level);
    } catch (const std::exception& e) {
        return failWith(AGLOD_COLLISION_ERROR, e.what());
    }
    return collision->world.ok() ? AGLOD_OK : failWith(AGLOD_COLLISION_ERROR, collision->world.error());
}

aglod_status aglod_collision_use_distance_cut(aglod_collision* collision, const float point[3],
                                              float max_error_per_distance) {
    if (!collision || !point || !(max_error_per_distance > 0) || !std::isfinite(max_error_per_distance))
        return failWith(AGLOD_INVALID_ARGUMENT,
                        "aglod_collision_use_distance_cut: NULL argument or ratio not finite and > 0");
    if (!inRange(point, 3))
        return failWith(AGLOD_INVALID_ARGUMENT, "aglod_collision_use_distance_cut: point must be finite, within 1e18");
    try {
        collision->world.useDistanceCut(point, max_error_per_distance);
    } catch (const std::exception& e) {
        return failWith(AGLOD_COLLISION_ERROR, e.what());
    }
    return collision->world.ok() ? AGLOD_OK : failWith(AGLOD_COLLISION_ERROR, collision->world.error());
}

int aglod_raycast(const aglod_collision* collision, const float origin[3], const float direction[3],
                  float max_distance, aglod_hit* hit) {
    if (!collision || !origin || !direction || !hit) {
        failWith(AGLOD_INVALID_ARGUMENT, "aglod_raycast: NULL argument");
        return 0;
    }
    if (!validRay("aglod_raycast", origin, direction, max_distance)) return 0;
    CollisionHit h;
    if (!collision->world.raycast(origin, direction, max_distance, h)) return 0;
    hit->distance = h.distance;
    for (int k = 0; k < 3; ++k) hit->normal[k] = h.normal[k];
    hit->node = h.node;
    hit->triangle = h.triangle;
    hit->objects = h.objects.data;
    hit->object_count = uint32_t(h.objects.size);
    return 1;
}

int aglod_occluded(const aglod_collision* collision, const float origin[3], const float direction[3],
                   float max_distance) {
    if (!collision || !origin || !direction) {
        failWith(AGLOD_INVALID_ARGUMENT, "aglod_occluded: NULL argument");
        return 0;
    }
    if (!validRay("aglod_occluded", origin, direction, max_distance)) return 0;
    return collision->world.occluded(origin, direction, max_distance) ? 1 : 0;
}

}  // extern "C"
