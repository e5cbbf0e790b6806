// SPDX-License-Identifier: AGPL-3.0-or-later
// Input clean-up and validation of one object (docs/design.md §2, "Bad input"): weld, drop
// degenerate triangles, reject NaN/inf, detect open, non-manifold and inside-out meshes.
#pragma once

#include <aggrelod/aggregate3d.h>

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

struct PreparedObject {
    std::vector<double> positions;    ///< 3 * n, welded (exactly equal positions merged)
    std::vector<uint32_t> triangles;  ///< 3 * m, non-degenerate, oriented outward when possible
    bool usable = false;      ///< has at least one triangle and only finite coordinates
    bool closed = false;      ///< every edge used by exactly two triangles
    bool consistent = false;  ///< every edge used once in each direction (orientable, oriented)
    double volume = 0;        ///< enclosed volume when closed and consistent, units^3
    double area = 0;          ///< units^2
    double bounds[6] = {0, 0, 0, 0, 0, 0};  ///< min xyz, max xyz
    /// A valid piece of the triangulation's input: closed, edge-manifold, consistently oriented.
    bool validSolid() const { return usable && closed && consistent && volume > 0; }
};

/// Cleans one object. Problems go to `diagnostics`, each naming the object.
/// `areaEpsilon`: triangles with area below it are dropped as degenerate (units^2).
void prepareObject(const InputObject& object, double areaEpsilon, PreparedObject& out,
                   std::vector<Diagnostic>& diagnostics);

/// A mesh as the triangulator's input check sees it (prepareObject, no area threshold, no
/// diagnostics): cleaned, and whether it is a valid closed, edge-manifold solid.
PreparedObject checkedSurface(const std::vector<double>& positions, const std::vector<uint32_t>& triangles);

/// Whether two triangles of the mesh that share no vertex intersect or touch (exact
/// triangle-triangle test of mesh_distance.h on the pairs whose boxes overlap, found in a
/// uniform grid of cells about twice the mean triangle size). Triangles sharing a vertex are
/// not tested: a fold there is not seen. positions 3 * n, triangles 3 * m. O(m log m + pairs
/// in a cell) when triangle sizes are alike; memory O(m) (at most 27 cells per triangle).
bool selfIntersects(const std::vector<double>& positions, const std::vector<uint32_t>& triangles);

/// Generalized winding number of a closed surface around q (Jacobson et al. 2013; solid
/// angles by Van Oosterom and Strackee 1983): about 1 inside, 0 outside, robust to small
/// defects. p: 3 * n doubles, t: 3 * m indices, q: 3 doubles (world units). O(m).
double windingNumber(const std::vector<double>& p, const std::vector<uint32_t>& t, const double* q);

/// Signed volume (divergence theorem) and area of a triangle mesh.
void meshVolumeArea(const std::vector<double>& positions, const std::vector<uint32_t>& triangles,
                    double& volume, double& area);

}  // namespace aggrelod::detail
