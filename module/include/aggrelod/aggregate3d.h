// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: 3D aggregation of disjoint objects into a level-of-detail hierarchy.
//
// Implements "distance aggregation" (paper in shared/paper, Sections 3 and 4.4):
// a constrained Delaunay tetrahedralization of the free space between objects gives a
// neighbourhood graph; Kruskal merges give a dendrogram; at threshold delta the models
// closer than delta form one group whose free-space tetrahedra are sculpted with an
// aggregate function (constant = Eq. 1, adaptive = Eq. 2) into one watertight solid.
//
// Units: every length is in the input's world units (glTF: metres); volumes in units^3.
// Arrays: positions are xyz triples (size 3 * vertexCount), indices are triangle
// corner triples (size 3 * triangleCount), counter-clockwise seen from outside.
// Determinism: the same objects (same order) and settings give bit-identical results.
#pragma once

#include <aggrelod/aggregate_common.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace aggrelod {

/// One input object: a closed, outward-oriented triangle mesh in world space.
struct InputObject {
    std::string name;                ///< shown in every diagnostic about this object
    uint32_t id = 0;                 ///< caller's id, copied to outputs (sources)
    std::vector<double> positions;   ///< 3 * vertexCount, world units
    std::vector<uint32_t> indices;   ///< 3 * triangleCount
    /// Base colour of each triangle, linear RGBA in [0, 1] (glTF baseColorFactor meaning),
    /// 4 * triangleCount floats. Empty = every triangle white (1, 1, 1, 1), glTF's default.
    /// Proxies take the colour of the nearest original surface (see Aggregate::faceColors);
    /// any other size is ignored with a warning.
    std::vector<float> triangleColors;
};

/// Which distance weights the neighbourhood graph (docs/design.md §2.2).
enum class DistanceMode {
    Exact,  ///< exact mesh-to-mesh minimum distance (default)
    Cdt     ///< shortest triangulation edge joining the models (the paper's choice)
};

/// What stands in, in the triangulation, for an object or model that is not a valid closed
/// solid (open, non-manifold, self-intersecting, or several touching objects; docs/design.md §2.0).
enum class SolidifyMethod {
    Wrap,  ///< a tight watertight wrap containing it (CGAL alpha wrap; default)
    Hull,  ///< its convex hull
    Off,   ///< nothing: such objects are left out of aggregation (passed through as support)
    /// (reported in SolidReport only) the exact boolean union of objects that are closed
    /// solids alone but touch or cross each other; Wrap tries it first for them.
    Union,
    /// (reported in SolidReport only) an open surface thickened by the offset on both sides
    /// into a thin closed shell; Wrap tries it first for models made only of open surfaces.
    Shell
};

/// How support surfaces (ground, terrain, sky dome, road network, room shell) are found.
enum class SupportDetection {
    Automatic,  ///< the documented rule (see Settings3D::supportSpanFraction)
    None,       ///< no object is a support surface
    Given       ///< exactly Settings3D::supportObjects
};

struct Settings3D {
    std::vector<double> deltas;       ///< explicit thresholds (world units, ascending); empty = automatic
    int automaticLevelCount = 8;      ///< number of automatic levels when deltas is empty
    AggregateFunctionKind function = AggregateFunctionKind::Adaptive;
    AggregateFunction customFunction; ///< overrides `function` when set
    DistanceMode distance = DistanceMode::Exact;
    double touchTolerance = -1;       ///< objects closer than this are one model; < 0: 1e-6 * scene diagonal
    bool computeHullBaseline = true;  ///< convex hull of each group as a baseline measure
    /// Also carve every level with the constant function (paper Eq. 1) at the same groups and
    /// protected connections, for Level::volumeConstant. Off by default: it is a comparison
    /// figure only (the hull baseline is the one reported by default) and costs about a tenth
    /// of the levels stage.
    bool computeConstantBaseline = false;
    SolidifyMethod solidify = SolidifyMethod::Wrap;
    /// Offset of the wrap from the original surface (world units); < 0: automatic, the
    /// smallest of 0.4 % of the model's bounding-box diagonal, a quarter of its gap to the
    /// nearest other model (support surfaces not counted) and a quarter of the smallest
    /// positive explicit delta, but at least 0.05 % of that diagonal. Alpha (smallest cavity
    /// the wrap enters) is 1.5 % of the diagonal (3 % when every object of the model is a
    /// closed solid that only crosses itself or touches others), and at least 2 x offset.
    double wrapOffset = -1;
    SupportDetection support = SupportDetection::Automatic;
    std::vector<uint32_t> supportObjects; ///< input indices, for SupportDetection::Given
    /// Automatic rule: an object is a support surface when its bounding box spans at least
    /// this fraction of the scene box along the scene box's two longest axes AND its box
    /// (padded by 1 % of the scene diagonal) overlaps the boxes of at least
    /// supportShareFraction of the other objects (and of at least 2). Applied in up to three
    /// rounds, each on the objects left by the previous one (a huge outer ground hides the
    /// town's own ground); a round that would leave fewer than 2 objects finds nothing.
    double supportSpanFraction = 0.5;
    double supportShareFraction = 0.3;
    /// Budget of each tetrahedralization (it runs in a child process): CPU seconds and bytes
    /// of memory; 0 = automatic (120 s + 0.5 ms per input triangle; half the physical memory).
    /// Over budget, the bake stops with an error saying so instead of waiting.
    double triangulationSeconds = 0;
    uint64_t triangulationMemory = 0;
    ProgressCallback progress;        ///< optional; called from the calling thread only
    int threadCount = 0;              ///< threads for sculpting levels; 0 = hardware concurrency.
                                      ///< Results are identical for every thread count.
};

/// Figures of a set of closed meshes.
struct SolidMeasures {
    double volume = 0;       ///< units^3
    double area = 0;         ///< units^2
    double sphericity = 0;   ///< pi^(1/3) (6V)^(2/3) / A of the total V and A; 1 for one sphere
};

/// pi^(1/3) (6 V)^(2/3) / A for a volume V (units^3, negative counts as 0) and area A
/// (units^2); 0 when A == 0. The 3D counterpart of circularity().
double sphericity(double volume, double area);

/// Where a lean assembly of a tiled bake (TiledBakeOptions::leanMeshes) left an aggregate's
/// mesh: in a tile cache entry, to be read again by the work that needs it (the proxies of a
/// share of the world), with what stands in for the mesh meanwhile.
struct AggregateMeshRef {
    std::string piece;                   ///< the tile cache key of the piece holding the aggregate
    uint32_t level = 0, index = 0;       ///< its level and place in that piece's Hierarchy3D
    size_t vertexCount = 0, triangleCount = 0;
    bool hasFaceColors = false;          ///< faceColors was not empty
    std::string meshHash;                ///< aggregateMeshHash() of the mesh
    uint64_t vertexSetHash[2] = {0, 0};  ///< aggregateVertexSetHash() of the mesh
};

/// One aggregate: the watertight proxy of one group of models at one level.
struct Aggregate {
    std::vector<double> positions;       ///< 3 * vertexCount
    std::vector<uint32_t> indices;       ///< 3 * triangleCount, closed, edge-manifold, outward
    std::vector<uint32_t> sourceObjects; ///< indices into the input object array, ascending
    /// Per triangle, linear RGBA (4 * triangleCount): the base colour of the source objects'
    /// surface nearest to the triangle's centroid. Empty when no source object has colours
    /// (every face white).
    std::vector<float> faceColors;
    int componentCount = 0;              ///< connected shells in this aggregate
    SolidMeasures measures;
    double volumeOriginal = 0;           ///< sum of the source objects' volumes
    double volumeHull = 0;               ///< convex hull of the group (0 when not computed)
    /// Whose surface the aggregate's faces come from where they lie on an object: the
    /// original faces (every source model a valid solid), a solidified stand-in's (every
    /// source model solidified), or both.
    enum class Surface { Original, Solidified, Mixed };
    Surface surface = Surface::Original;
    /// Set only by a lean assembly: positions, indices and faceColors are then empty and stay
    /// in the tile cache (AggregateMeshRef); everything else is here.
    std::shared_ptr<const AggregateMeshRef> meshInCache;
};

/// The aggregate's mesh is in the tile cache and not here (meshInCache set, no positions or
/// indices held): what needs it reads it back (readAggregateMeshes).
inline bool meshLeftInCache(const Aggregate& a) { return a.meshInCache && a.positions.empty() && a.indices.empty(); }

/// A content hash (32 hex digits) of an aggregate's positions and indices; the one kept in
/// meshInCache when the mesh was left there.
std::string aggregateMeshHash(const Aggregate& a);

/// A hash of an aggregate's vertices as a set with repeats (their order and the triangles do
/// not count; -0 and +0 are the same): equal for aggregates whose sorted vertex lists are equal.
/// The one kept in meshInCache when the mesh was left there.
void aggregateVertexSetHash(const Aggregate& a, uint64_t hash[2]);

/// One solidified model (docs/design.md §2.0): what stood in for its objects in the triangulation.
struct SolidReport {
    std::vector<uint32_t> objects;   ///< input indices, ascending
    SolidifyMethod method = SolidifyMethod::Wrap;
    std::string reason;              ///< why the objects were not a valid solid
    double alpha = 0, offset = 0;    ///< wrap parameters (world units; 0 for a hull)
    double volumeOriginal = 0;       ///< |enclosed volume| of the objects (open ones: of their faces as given)
    double volumeSolid = 0;          ///< units^3
    /// Sampled (not certified) distances, world units: from every vertex and triangle
    /// centroid of one surface to the other surface (closest point, BVH).
    double distanceSolidToOriginal = 0;
    double distanceOriginalToSolid = 0;
    /// The same two-sided figure, max of both directions, for the convex hull of the objects
    /// (for comparison; 0 when not measured or for Hull itself).
    double hullDistance = 0;
    double bboxDiagonal = 0;         ///< of the objects, world units
    double seconds = 0;              ///< time to build the solid (one thread)
    bool closedManifold = false;     ///< closed, edge-manifold, consistently outward oriented
    std::vector<double> positions;   ///< the solid, 3 * vertexCount
    std::vector<uint32_t> triangles; ///< 3 * triangleCount, outward
};

struct Level {
    double delta = 0;                 ///< threshold: models closer than delta are joined
    std::vector<Aggregate> aggregates; ///< one per group, ordered by smallest source index
    SolidMeasures measures;           ///< of all aggregates together
    double volumeOriginal = 0;        ///< of all objects
    double volumeHull = 0;            ///< sum of the groups' convex hull volumes
    double volumeConstant = 0;        ///< total volume with the constant function (baseline); 0 when not measured
    bool hasVolumeConstant = false;   ///< volumeConstant was measured (Settings3D::computeConstantBaseline,
                                      ///< or the constant function itself is the one baked)
    size_t triangleCount = 0;
};

struct Hierarchy3D {
    std::vector<Level> levels;               ///< ascending delta
    std::vector<uint32_t> objectModel;       ///< per input object: its model (touching objects share one)
    size_t modelCount = 0;
    std::vector<Merge> merges;               ///< dendrogram, ascending height
    SolidMeasures originals;                 ///< of all input objects
    std::vector<Diagnostic> diagnostics;     ///< every problem found, in a deterministic order
    std::vector<std::pair<std::string, double>> timings; ///< stage name -> seconds, in run order
    size_t tetrahedronCount = 0;
    size_t inputTriangleCount = 0;
    std::vector<SolidReport> solids;         ///< every solidified model, by smallest object index
    /// Support surfaces (ascending input indices): kept out of aggregation, in no level;
    /// the outputs pass them through unchanged.
    std::vector<uint32_t> supportObjects;
    /// Objects in no level for another reason (unusable, flat, or left out by SolidifyMethod::Off).
    std::vector<uint32_t> leftOutObjects;
};

/// The 3D result types under the names of their 2D counterparts (Measures2D, Aggregate2D,
/// Level2D); the same types.
using Measures3D = SolidMeasures;
using Aggregate3D = Aggregate;
using Level3D = Level;

/// Bakes the whole hierarchy.
/// Returns false (with an Error diagnostic in out.diagnostics) when baking cannot go on:
/// no usable object, or the triangulator failed beyond recovery. Never throws for bad input.
bool buildHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings,
                      Hierarchy3D& out);

}  // namespace aggrelod
