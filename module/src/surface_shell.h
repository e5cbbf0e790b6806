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
/// are joined along the surface's boundary by strips through the boundary itself. The solid
/// contains the surface: its boundary lies on the strips, and every other point is at least
/// offset / 2 from both sheets (checked: a face of one part of the surface may come nearer
/// the sheets made for another part). Its surface lies within `maxDisplacement` of it.
///
/// positions: 3 * n doubles (world units), triangles: 3 * m indices < n; vertices at exactly
/// the same position are one vertex. offset > 0, maxDisplacement >= offset and
/// smallestOpening >= 0 (world units).
/// Output: outPositions 3 * n', outTriangles 3 * m', closed, edge-manifold, outward, free of
/// self-intersections (checked): the outer sheet's faces first, one per face of the surface
/// (after the weld drops faces with two corners at one position), then the inner sheet's, then
/// four per boundary edge. Deterministic.
/// Returns false with the reason in `why`, leaving the outputs empty, when the surface has a
/// closed piece, a piece whose boundary fits in a ball of diameter `smallestOpening` (nearly
/// closed: its shell would be a hollow skin), an edge of more than two faces, a vertex where
/// two fans meet, faces that cannot be oriented alike, a vertex whose faces allow no
/// displacement within `maxDisplacement` (a fold sharper than about
/// 2 asin(offset / maxDisplacement)), when the sheets would cross each other or come nearer
/// the surface than offset / 2 (detail finer than about twice the offset), or when one piece
/// would lie inside another's shell.
bool thickenSurface(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double offset,
                    double maxDisplacement, double smallestOpening, std::vector<double>& outPositions,
                    std::vector<uint32_t>& outTriangles, std::string& why);

}  // namespace aggrelod::detail
