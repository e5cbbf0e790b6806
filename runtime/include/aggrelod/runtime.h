// SPDX-License-Identifier: MIT
// aggrelod runtime: what a game engine links (standard library only; MIT-compatible).
// Level selection by screen-space error, as in 3D Tiles / CesiumJS (docs/design.md §3).
#pragma once

#include <cstdint>

namespace aggrelod::runtime {

/// Version of the runtime library (the baked file carries its own format version).
constexpr uint32_t kVersionMajor = 0;
constexpr uint32_t kVersionMinor = 1;

/// Screen-space error in pixels of a node drawn instead of its children.
/// geometricError: world units; distance: camera to bounding sphere, world units (clamped
/// to a small positive value); fovY: vertical field of view in radians; viewportHeight: pixels.
double screenSpaceError(double geometricError, double distance, double fovY,
                        double viewportHeight);

}  // namespace aggrelod::runtime
