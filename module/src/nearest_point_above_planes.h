// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): the Euclidean projection of a point onto an intersection of
// half-spaces in 3D, for the conservative simplifier's vertex placement.
#pragma once

#include "vec3.h"

#include <cstddef>

namespace aggrelod::detail {

/// The half-space n . x >= offset (n: unit normal, world units).
struct HalfSpace {
    Vec3 normal;
    double offset = 0;
};

/// The point nearest to c (Euclidean distance) that lies in every half-space: the incremental
/// algorithm of Seidel ("Small-dimensional linear programming and convex hulls made easy",
/// Discrete & Computational Geometry 6, 1991), applied to the projection, whose objective is
/// strictly convex. Half-spaces are added in turn; when the optimum so far lies outside the
/// new one, the new optimum lies on its plane and is found by the same method one dimension
/// down over the ones before it. O(count) when few planes are violated, O(count^3) at worst.
/// spaces: `count` half-spaces; c and out: world units. out may be a hair outside a plane by
/// rounding (the caller steps out if it must). Returns false when the intersection is empty
/// (to rounding: parallel planes facing apart, or an interval on a line that closes).
/// Deterministic: the result depends on the order of `spaces`.
bool nearestPointAbovePlanes(const HalfSpace* spaces, size_t count, Vec3 c, Vec3& out);

}  // namespace aggrelod::detail
