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

/// Which distance weights the neighbourhood graph (DESIGN 2.2).
enum class DistanceMode {
    Exact,  ///< exact mesh-to-mesh minimum distance (default)
    Cdt     ///< shortest triangulation edge joining the models (the paper's choice)
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
};

/// Bakes the whole hierarchy.
/// Returns false (with an Error diagnostic in out.diagnostics) when baking cannot go on:
/// no usable object, or the triangulator failed beyond recovery. Never throws for bad input.
bool buildHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings,
                      Hierarchy3D& out);

}  // namespace aggrelod
