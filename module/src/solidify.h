// SPDX-License-Identifier: AGPL-3.0-or-later
// Solidification of objects that are not valid closed solids (DESIGN 2.0 "Solidify"):
// CGAL 3D Alpha Wrapping (Portaneri, Rouxel-Labbé, Hemmer, Cohen-Steiner, Alliez,
// "Alpha Wrapping with an Offset", ACM TOG 41(4), 2022), CGAL 5.5 `alpha_wrap_3`, GPL-3+:
// bake side only. This header keeps CGAL out of its users; solidify.cpp is the one
// translation unit that includes it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// Wraps a triangle soup (open, non-manifold, self-intersecting, several pieces: anything)
/// into a closed, edge-manifold, intersection-free, outward-oriented triangle mesh that
/// strictly contains it.
/// positions: 3 * n doubles (world units), triangles: 3 * m indices < n.
/// alpha: the smallest cavity or tunnel the wrap may enter (world units, > 0); offset: how
/// far the wrap's vertices lie from the input (world units, > 0). Cost grows as either one
/// shrinks. Output: outPositions 3 * n', outTriangles 3 * m'. Deterministic (same input, same
/// bytes). Returns false with a reason in `error` (never throws).
bool alphaWrap(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double alpha,
               double offset, std::vector<double>& outPositions, std::vector<uint32_t>& outTriangles,
               std::string& error);

}  // namespace aggrelod::detail
