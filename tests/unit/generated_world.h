// SPDX-License-Identifier: AGPL-3.0-or-later
// The generated open world (samples/include/aggrelod/world.h) in memory, for the tests.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/world.h>

#include <cstdint>
#include <vector>

namespace aggrelod::testing {

/// The world of `count` objects and `seed`, objects in the generator's order.
inline std::vector<InputObject> generatedWorld(uint64_t count, uint32_t seed = 1) {
    std::vector<InputObject> objects;
    samples::WorldSettings settings;
    settings.objectCount = count;
    settings.seed = seed;
    samples::generateWorld(settings, [&](InputObject& o) { objects.push_back(o); });
    return objects;
}

}  // namespace aggrelod::testing
