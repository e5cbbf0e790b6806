// SPDX-License-Identifier: AGPL-3.0-or-later
// Solidification of objects that are not valid closed solids (docs/design.md §2.0 "Solidify"):
// the exact union of touching closed parts (CGAL corefinement), and CGAL 3D Alpha Wrapping
// (Portaneri, Rouxel-Labbé, Hemmer, Cohen-Steiner, Alliez, "Alpha Wrapping with an Offset",
// ACM TOG 41(4), 2022), CGAL 5.5 `alpha_wrap_3`, GPL-3+:
// bake side only. This header keeps CGAL out of its users; solidify.cpp is the one
// translation unit that includes it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// How the wrap queries its input.
/// - Cgal: CGAL's own queries on its AABB tree.
/// - QuickPredicates: whether a ball or a tetrahedron meets the input answered in double
///   precision where that decides with room to spare, CGAL's exact queries otherwise; closest
///   points and the offset surface's crossings by CGAL. The same wrap as Cgal, bit for bit.
/// - Quick (default): QuickPredicates, and the closest points and crossings (the Steiner
///   points, CGAL's own search along a segment) computed on this library's BVH. The same
///   algorithm and guarantees (closed, manifold, containing, vertices at the offset to within
///   CGAL's 1 %), about a quarter faster on large inputs; Steiner points differ from Cgal's
///   by rounding, so the wrap is not Cgal's bit for bit.
enum class WrapOracle { Quick, QuickPredicates, Cgal };

/// Wraps a triangle soup (open, non-manifold, self-intersecting, several pieces: anything)
/// into a closed, edge-manifold, intersection-free, outward-oriented triangle mesh that
/// strictly contains it.
/// positions: 3 * n doubles (world units), triangles: 3 * m indices < n.
/// alpha: the smallest cavity or tunnel the wrap may enter (world units, > 0); offset: how
/// far the wrap's vertices lie from the input (world units, > 0). Cost grows as either one
/// shrinks. Output: outPositions 3 * n', outTriangles 3 * m'. Deterministic (same input and
/// `oracle`, same bytes). Returns false with a reason in `error` (never throws).
bool alphaWrap(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double alpha,
               double offset, std::vector<double>& outPositions, std::vector<uint32_t>& outTriangles,
               std::string& error, WrapOracle oracle = WrapOracle::Quick);

/// The exact boolean union of closed parts (CGAL corefinement in exact arithmetic, rounded to
/// doubles at the end): for objects that are valid solids on their own but touch or cross
/// each other, the tightest solid there is (its surface lies on theirs).
/// positions[i], triangles[i]: part i, as alphaWrap's input; each must be closed,
/// edge-manifold, free of self-intersections and bound a volume. Output as alphaWrap's, in a
/// canonical order: vertices sorted by coordinates, each triangle starting at its smallest
/// index, triangles sorted (the corefinement's own order follows memory addresses, so it
/// differs between runs and thread counts). Returns false with a reason in
/// `error` (never throws) when a part is not such a solid or the union is not a manifold
/// surface (parts meeting along an edge or at a point). The rounding of new vertices can
/// leave the output crossing itself: the caller checks it.
bool exactUnion(const std::vector<const std::vector<double>*>& positions,
                const std::vector<const std::vector<uint32_t>*>& triangles, std::vector<double>& outPositions,
                std::vector<uint32_t>& outTriangles, std::string& error);

}  // namespace aggrelod::detail
