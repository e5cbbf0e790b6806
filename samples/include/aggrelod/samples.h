// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod samples: deterministic scene generators for demos, tests and benchmarks.
//
// Every generator returns closed triangle meshes in world space: every undirected edge is
// used by exactly two triangles, once in each direction (consistent orientation, counter-
// clockwise seen from outside, so the signed volume is positive), vertices are welded (no two
// vertices of one object share a position) and no triangle is degenerate. Objects never
// overlap one another; the gaps between them are documented per generator.
//
// Determinism: random choices come from std::mt19937 (whose raw output the C++ standard
// fixes) turned into doubles by our own code, never by std::uniform_real_distribution (whose
// output differs between standard libraries). The same arguments give the same meshes.
//
// Units: all lengths are in scene units (metres when written to glTF).
#pragma once

#include <aggrelod/aggregate3d.h>

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod::samples {

using Vec3 = std::array<double, 3>;

/// Portable random numbers: std::mt19937 with an explicit seed, doubles built from its raw
/// 32-bit outputs (53 random bits per double), so every standard library gives the same values.
class Random {
public:
    explicit Random(uint32_t seed) : engine_(seed) {}
    /// Uniform in [0, 1).
    double uniform01();
    /// Uniform in [lo, hi).
    double uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
    /// Uniform integer in [lo, hi] (inclusive); requires lo <= hi.
    int uniformInt(int lo, int hi);
    /// Log-uniform in [lo, hi), lo > 0: as many values in [1, 2) as in [2, 4).
    double logUniform(double lo, double hi);
    /// Uniform direction on the unit sphere.
    Vec3 direction();

private:
    std::mt19937 engine_;
};

// ---------------------------------------------------------------------------------------
// Mesh helpers. Each returns one closed, outward-oriented, welded object with the given name
// (id 0: the scene generators number the objects 0, 1, 2, ... in order).
// ---------------------------------------------------------------------------------------

/// Axis-aligned box [lo, hi] (lo < hi on every axis). Each face is a regular grid of
/// ceil(extent / maxEdge) cells per axis (at least 1), each cell split into two triangles.
/// maxEdge <= 0 means one cell per face (12 triangles).
InputObject makeBox(const std::string& name, const Vec3& lo, const Vec3& hi, double maxEdge = 0);

/// UV sphere: `segments` (>= 3) meridians, `rings` (>= 2) latitude bands, one vertex at each
/// pole. Vertices lie on the sphere (the mesh is inscribed). 2 * segments * (rings - 1)
/// triangles.
InputObject makeUvSphere(const std::string& name, const Vec3& center, double radius,
                         int segments, int rings);

/// Closed cylinder along +z from `baseCenter` up to baseCenter + height: `segments` (>= 3)
/// around, `heightSegments` (>= 1) bands along the side, caps as fans around a centre vertex.
/// 2 * segments * (heightSegments + 1) triangles.
InputObject makeCylinder(const std::string& name, const Vec3& baseCenter, double radius,
                         double height, int segments, int heightSegments = 1);

/// Surface of revolution about the vertical axis through `baseCenter`. `profile` lists
/// (radius, height) pairs from bottom to top, radius > 0, consecutive pairs distinct, and the
/// polyline must not cross itself or the axis. The bottom and top are closed by flat fans
/// around centre vertices on the axis. 2 * segments * profile.size() triangles.
InputObject makeLathe(const std::string& name, const Vec3& baseCenter,
                      const std::vector<std::pair<double, double>>& profile, int segments);

/// Prism: the simple polygon `outline` ((u, v) pairs, counter-clockwise, no three consecutive
/// points collinear) in the vertical plane, extruded by `depth` (> 0). u runs along +x, v
/// along +z, the extrusion along +y; the prism spans y in [-depth/2, depth/2]. The caps are
/// triangulated by ear clipping. Then rotated by `yaw` radians about +z and moved to `offset`.
InputObject makeExtrusion(const std::string& name,
                          const std::vector<std::pair<double, double>>& outline, double depth,
                          double yaw, const Vec3& offset);

/// Rotates the object by `yaw` radians about the +z axis through the origin, then translates
/// it by `offset`. Keeps it closed and outward (a rigid motion).
void rotateZAndTranslate(InputObject& object, double yaw, const Vec3& offset);

// ---------------------------------------------------------------------------------------
// Scenes.
// ---------------------------------------------------------------------------------------

/// Unit cubes [0,1]^3 ("cubeA") and [1+gap, 2+gap] x [0,1] x [0,1] ("cubeB"); gap > 0.
/// 12 triangles each.
std::vector<InputObject> makeTwoCubes(double gap);

/// Two parallel 40 x 40 x 1 slabs, "slabLower" = [0,40] x [0,40] x [0,1] and "slabUpper" =
/// [4,44] x [4,44] x [2,3]: the facing faces are exactly 1 apart over a 36 x 36 overlap, but
/// every face is a grid with spacing 8 and the upper grid is shifted by (4, 4), so no vertex
/// of one slab is closer than sqrt(4^2 + 4^2 + 1) ~ 5.74 to a vertex of the other. A
/// triangulation of the gap has no edge shorter than that: the hard case for keeping joined
/// models connected (docs/design.md §2.4 item 4).
std::vector<InputObject> makeOffsetSlabs();

/// 15 equal spheres of radius 1 (UV spheres, 20 x 11, 400 triangles each), as in the paper's
/// Fig. 9: 4 to 6 seeded clusters; inside a cluster each sphere sits 0.25-1.0 from another
/// one and >= 0.2 from all; each further cluster is linked to an earlier one by a gap
/// stratified over 1.3-3.7 and stays >= 1.2 from the other clusters (gaps between the ideal
/// spheres; the inscribed meshes are slightly farther apart). A layout is kept only when the
/// paper's deltas 1, 1.5, 2, 3, 4 give at least three different groupings (single linkage).
/// Names "sphere00" .. "sphere14".
std::vector<InputObject> makeSpheres15(uint32_t seed);

/// Chess pieces (paper Fig. 8): 16-32 pieces (seeded) on distinct squares of an 8 x 8 board of
/// unit squares spanning [0,8] x [0,8] at z = 0; each piece stands on z = 0 inside its square
/// (base radius <= 0.42, so neighbouring pieces are >= 0.16 apart). Shapes: pawn, rook,
/// bishop, queen, king (lathes) and knight (extruded silhouette), with seeded size factors
/// 0.8-1.1 and knight headings. Names like "w_pawn_e2" (colour, kind, square).
/// withBoard = false (default): pieces only; the board would touch every piece and join
/// everything at the first level. withBoard = true: a "board" box [0,8] x [0,8] x [-0.25,
/// -0.05] is added first, 0.05 below the pieces (exclude it with --exclude '^board$').
std::vector<InputObject> makeChessBoard(uint32_t seed, bool withBoard = false);

/// Benchmark scene: `objectCount` (>= 1) spheres, boxes, cylinders and lathe shapes with
/// heterogeneous sizes (bounding radius 0.5-2), roughly `approxTotalTriangles` triangles in
/// all. Objects are placed in clusters: most are put next to an earlier object at a
/// log-uniform gap in [0.05, 3] between bounding spheres, some start new clusters; no two
/// bounding spheres come closer than 0.02, so objects never overlap. Names "obj0000", ...
std::vector<InputObject> makeRandomScene(int objectCount, int approxTotalTriangles,
                                         uint32_t seed);

/// Forest (samples/outdoor_scenes.cpp): 36 x 36 ground (z = 0, z up), 5-7 dense clumps of
/// 6-12 trees (neighbouring canopies 0.1-0.8 apart), about 18 scattered trees (>= 1.5 from any
/// other) and two clearings. A tree is two objects: "treeNNN_trunk" (cylinder, 32 triangles) and,
/// 0.05 above it, "treeNNN_canopy": a sphere (broadleaf, 144 triangles) or a cone (conifer, 72
/// triangles). Every part of a tree lies inside the vertical cylinder of its canopy radius
/// (0.8-1.5) around its axis; those cylinders are >= 0.1 apart, so no two objects overlap.
std::vector<InputObject> makeForest(uint32_t seed);

/// Village (samples/outdoor_scenes.cpp): two rows of houses along a street (the x axis, z up),
/// tight terraces (0.6-1.2 apart) mixed with open plots (3-8 apart). Objects: "houseNNN" (walls
/// and pitched roof in one prism, 4-6.5 x 4-6), "fenceNNN" (pickets on a rail, 0.06 thick, in
/// front of some houses), "barrelNNN" (bulged lathe, 0.76 across, 1-4 by a side wall). All
/// ground rectangles are axis-aligned and >= 0.05 apart (houses >= 0.3), so no overlaps.
std::vector<InputObject> makeVillage(uint32_t seed);

// ---------------------------------------------------------------------------------------
// Checks (used by the tests and by aggrelod_make_sample before writing).
// ---------------------------------------------------------------------------------------

/// Signed volume of a closed mesh (positive when outward-oriented), units^3.
double signedVolume(const InputObject& object);

/// Empty string when the object is closed (every undirected edge used by exactly two
/// triangles, once per direction), welded, and has no degenerate or repeated-index triangle
/// and no index out of range; otherwise a description of the first problem found.
std::string checkClosedMesh(const InputObject& object);

/// Centre (midpoint of the bounding box) and radius of a sphere containing the object.
std::pair<Vec3, double> boundingSphere(const InputObject& object);

}  // namespace aggrelod::samples
