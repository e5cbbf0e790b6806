// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): an open surface thickened into a thin closed solid (a shell),
// the cheapest tight solid for walls, floors and panels modelled as open sheets
// (docs/real-art.md, "Solidify").
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// Thickens an open, edge-manifold, orientable surface by `offset` on both sides into one
/// closed solid: each vertex v moves to v + d and v - d, where d is the displacement nearest
/// to `offset` times its mean normal with every face around v at least `offset` away along
/// that face's normal (Seidel's projection, nearest_point_above_planes.h); the two sheets
/// are joined along the surface's boundary by strips through the boundary itself. So every
/// face of the surface lies inside, at least `offset` from both sheets, and the boundary
/// lies on the strips: the solid contains the surface. Its surface lies within
/// `maxDisplacement` of it.
///
/// positions: 3 * n doubles (world units), triangles: 3 * m indices < n; vertices at exactly
/// the same position are one vertex. offset > 0 and maxDisplacement >= offset (world units).
/// Output: outPositions 3 * n', outTriangles 3 * m', closed, edge-manifold, outward, free of
/// self-intersections (checked): the outer sheet's faces first, one per face of the surface
/// (after the weld drops faces with two corners at one position), then the inner sheet's, then
/// four per boundary edge. Deterministic.
/// Returns false with the reason in `why`, leaving the outputs empty, when the surface has a
/// closed piece, an edge of more than two faces, a vertex where two fans meet, faces that
/// cannot be oriented alike, a vertex whose faces allow no displacement within
/// `maxDisplacement` (a fold sharper than about 2 asin(offset / maxDisplacement)), or when the
/// sheets would cross each other (detail finer than twice the offset).
bool thickenSurface(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double offset,
                    double maxDisplacement, std::vector<double>& outPositions, std::vector<uint32_t>& outTriangles,
                    std::string& why);

}  // namespace aggrelod::detail
