// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: 2D aggregation of disjoint polygons into a hierarchy of levels.
//
// Implements the paper's own 2D method (shared/paper, Sections 3.1-3.3, Eqs. 1-3):
// a constrained Delaunay triangulation of the free space between polygons gives a
// neighbourhood graph; Kruskal merges give a dendrogram (shared with 3D, dendrogram.h);
// at threshold delta the models closer than delta form one group whose free-space
// triangles are sculpted with an aggregate function into polygons with holes.
//
// Units: coordinates are plain planar numbers (degrees are treated as such); lengths in
// the same unit, areas in unit^2. Rings are stored open (the last vertex is not repeated)
// as x y pairs: a ring of n vertices is 2 * n doubles.
// Determinism: the same features (same order) and settings give bit-identical results.
#pragma once

#include <aggrelod/aggregate_common.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod {

/// A polygon with holes. Input rings may have either orientation; output exteriors are
/// counter-clockwise and holes clockwise (OGC / GeoJSON right-hand rule).
struct Polygon2D {
    std::vector<double> exterior;            ///< 2 * n, open ring, n >= 3
    std::vector<std::vector<double>> holes;  ///< each 2 * n, open rings
};

/// One input feature: a polygon or a multipolygon (all its parts form one object).
struct Feature2D {
    std::string name;                 ///< shown in every diagnostic, e.g. "line 12" or "feature 3 (line 40)"
    uint32_t id = 0;                  ///< caller's id, copied to outputs
    std::vector<Polygon2D> polygons;  ///< at least one
};

/// How the aggregate of a group is shaped.
enum class Shape2D {
    Sculpted,   ///< sculpted free-space triangles (the paper's method, with `function`)
    ConvexHull  ///< convex hull of the group (baseline)
};

struct Settings2D {
    std::vector<double> deltas;          ///< explicit thresholds (ascending, >= 0); empty = automatic
    int automaticLevelCount = 8;         ///< number of automatic levels when deltas is empty
    AggregateFunctionKind function = AggregateFunctionKind::Adaptive;
    AggregateFunction customFunction;    ///< overrides `function` when set
    Shape2D shape = Shape2D::Sculpted;
    bool computeBaselines = true;        ///< measure constant function and convex hulls at the same groups
    ProgressCallback progress;           ///< optional, called from the calling thread
    int threadCount = 0;                 ///< threads (contact checks, free-space passes, levels); 0 = hardware concurrency.
                                         ///< Results are identical for every thread count.
};

/// Figures of a set of polygons (paper Section 4.2).
struct Measures2D {
    double area = 0;         ///< unit^2
    double perimeter = 0;    ///< unit, exterior and hole rings
    double circularity = 0;  ///< 4 pi A / P^2 of the totals (paper Eq. 3); 1 for one disc
};

/// The aggregate of one group at one level: one or more polygons (a MultiPolygon).
/// Parts that would touch at a single point are separate polygons.
struct Aggregate2D {
    std::vector<Polygon2D> polygons;       ///< OGC-valid, exterior CCW, holes CW
    std::vector<uint32_t> sourceFeatures;  ///< indices into the input feature array, ascending
    Measures2D measures;
};

struct Level2D {
    double delta = 0;                     ///< threshold: models closer than delta are joined
    std::vector<Aggregate2D> aggregates;  ///< one per group, ordered by smallest source index
    Measures2D measures;                  ///< of all aggregates (the chosen shape)
    Measures2D constant;                  ///< constant function (Eq. 1) at the same groups (if computed)
    Measures2D adaptive;                  ///< adaptive function (Eq. 2) at the same groups (if computed)
    Measures2D hull;                      ///< convex hulls of the groups (if computed)
};

struct Hierarchy2D {
    std::vector<Level2D> levels;             ///< ascending delta
    std::vector<int> featureModel;           ///< per input feature: its model, -1 if rejected
    size_t modelCount = 0;
    std::vector<Merge> merges;               ///< dendrogram, ascending height
    Measures2D originals;                    ///< of all accepted input polygons
    std::vector<Diagnostic> diagnostics;     ///< every problem found, deterministic order
    std::vector<std::pair<std::string, double>> timings;  ///< stage -> seconds, run order
    size_t vertexCount = 0;                  ///< triangulation vertices
    size_t triangleCount = 0;                ///< triangulation faces
    double freeEdgeMin = 0, freeEdgeMax = 0; ///< shortest / longest unconstrained edge of a free-space triangle (before Steiner points)
};

/// Measures divided by the originals' (area, perimeter, circularity each normalised).
Measures2D normalizedMeasures(const Measures2D& m, const Measures2D& originals);

/// 4 pi A / P^2, 0 when P == 0.
double circularity(double area, double perimeter);

/// The polygons buildHierarchy2D aggregates, found without aggregating: the same input checks
/// (rings cleaned of repeated vertices and oriented, exterior CCW and holes CW; degenerate holes
/// dropped; polygons with a bad ring dropped), per input feature its accepted polygons in input
/// order (empty when the feature is rejected). Diagnostics as buildHierarchy2D's input checks
/// give them. No triangulation: near-linear time.
std::vector<std::vector<Polygon2D>> acceptedPolygons2D(const std::vector<Feature2D>& features,
                                                       std::vector<Diagnostic>& diagnostics);

/// Builds the whole hierarchy. Bad features (self-intersecting ring, NaN, fewer than 3
/// distinct vertices, zero area) get an Error diagnostic and are left out; touching or
/// overlapping polygons are merged into one model (Note). Returns false only when no
/// feature is usable or the triangulator fails. Never throws for bad input.
bool buildHierarchy2D(const std::vector<Feature2D>& features, const Settings2D& settings, Hierarchy2D& out);

}  // namespace aggrelod
