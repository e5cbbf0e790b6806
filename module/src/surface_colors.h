// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): proxies carry the look of what they replace.
// Each face of a proxy or aggregate takes the base colour of the original surface nearest to
// its centroid (one closest-point query per face on a BVH of the originals, mesh_distance.h).
// Not from the paper (which aggregates geometry only): an engine-facing addition so that a
// far level keeps the colours of the objects it stands for.
//
// Colours are linear RGBA, 4 floats per triangle (InputObject::triangleColors).
// Determinism: single-threaded per call; ties between equally near triangles go to the
// lowest (object order, triangle) index.
#pragma once

#include <aggrelod/aggregate3d.h>

#include "mesh_distance.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// True when `o` has one colour per triangle (4 * triangleCount floats).
bool hasTriangleColors(const InputObject& o);

/// Fills `faceColors` (4 * triangleCount) with the colour of the originals' triangle nearest
/// to each face centroid of the mesh (positions 3 * vertexCount, world units; indices
/// 3 * triangleCount). Leaves `faceColors` empty when no original has triangle colours.
/// Originals with non-finite coordinates are skipped; objects without (valid) colours count
/// as white.
void nearestSurfaceColors(const std::vector<double>& positions, const std::vector<uint32_t>& indices,
                          const std::vector<const InputObject*>& originals, std::vector<float>& faceColors);
void nearestSurfaceColors(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                          const std::vector<const InputObject*>& originals, std::vector<float>& faceColors);

/// The same, for several meshes standing for the same originals: the originals' surface and
/// colours are gathered once (a surface of one colour needs no search at all).
class SurfaceColorSource {
public:
    explicit SurfaceColorSource(const std::vector<const InputObject*>& originals);
    /// As nearestSurfaceColors with this source's originals. Real: float or double.
    template <typename Real>
    void colorsOf(const std::vector<Real>& positions, const std::vector<uint32_t>& indices,
                  std::vector<float>& faceColors) const;

private:
    bool coloured_ = false;  ///< some original has triangle colours
    bool uniform_ = false;   ///< every usable original triangle has the same colour
    std::vector<float> colors_;  ///< per soup triangle, RGBA
    TriangleBvh bvh_;            ///< of the soup (built only when the colours differ)
};

}  // namespace aggrelod::detail
