// SPDX-License-Identifier: MIT
// Screen-space error rule of docs/design.md §3 (the 3D Tiles / CesiumJS formula).
#include <aggrelod/runtime.h>

#include <algorithm>
#include <cmath>

namespace aggrelod::runtime {

double screenSpaceError(double geometricError, double distance, double fovY,
                        double viewportHeight) {
    // Clamp: a camera inside the bounding sphere sees an unbounded error.
    const double d = std::max(distance, 1e-6);
    return geometricError * viewportHeight / (2.0 * d * std::tan(fovY * 0.5));
}

}  // namespace aggrelod::runtime
