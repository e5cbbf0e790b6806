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

/// How the wrap asks whether a ball or a tetrahedron meets the input: CGAL's own exact
/// queries on its AABB tree, or quick double-precision answers that fall back to those
/// whenever rounding could matter (the same wrap, bit for bit, in a fraction of the time).
enum class WrapOracle { Quick, Cgal };

/// Wraps a triangle soup (open, non-manifold, self-intersecting, several pieces: anything)
/// into a closed, edge-manifold, intersection-free, outward-oriented triangle mesh that
/// strictly contains it.
/// positions: 3 * n doubles (world units), triangles: 3 * m indices < n.
/// alpha: the smallest cavity or tunnel the wrap may enter (world units, > 0); offset: how
/// far the wrap's vertices lie from the input (world units, > 0). Cost grows as either one
/// shrinks. Output: outPositions 3 * n', outTriangles 3 * m'. Deterministic (same input, same
/// bytes, whichever `oracle`). Returns false with a reason in `error` (never throws).
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
