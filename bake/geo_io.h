// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: 2D polygon files in and out (WKT, GeoJSON, link table CSV, stats JSON);
// the pictures are in geo_picture.h. module/ sees plain polygons; only this code knows formats.
// Coordinates are taken as plain planar numbers (degrees are not projected).
#pragma once

#include <aggrelod/aggregate2d.h>

#include <string>
#include <vector>

namespace aggrelod::io {

struct GeoReadResult {
    std::vector<Feature2D> features;      ///< id = feature ordinal in the file (0-based), name says where it is
    std::vector<Diagnostic> diagnostics;  ///< skipped features: unsupported types, unclosed or empty rings, bad WKT lines
};

/// Reads a .wkt file (one POLYGON or MULTIPOLYGON per line; blank lines and lines starting
/// with '#' ignored) or a .geojson / .json file (FeatureCollection, Feature or geometry;
/// Polygon and MultiPolygon kept, other types reported and skipped). Features with problems
/// are skipped with a diagnostic naming the feature and its line. Returns false with `error`
/// only when the file cannot be read or parsed at all (e.g. malformed JSON, with line and column).
bool readPolygonFile(const std::string& path, GeoReadResult& out, std::string& error);
/// Same, from text; `format` is "wkt" or "geojson".
bool readPolygonText(const std::string& text, const std::string& format, GeoReadResult& out, std::string& error);

/// GeoJSON FeatureCollection: one feature per aggregate per level with properties
/// {level, delta, aggregate, sources: [input ids], area, perimeter}; Polygon or MultiPolygon,
/// closed rings, exterior CCW, holes CW. Deterministic (shortest round-trip numbers).
std::string formatLevelsGeoJson(const Hierarchy2D& hierarchy, const std::vector<Feature2D>& features);

/// Link table (like ArcGIS Aggregate Polygons out_table): "input_id,level,delta,output_id",
/// one row per accepted input feature per level; output_id is the aggregate index in its level.
std::string formatLinksCsv(const Hierarchy2D& hierarchy, const std::vector<Feature2D>& features);

/// One aggregate read back from the GeoJSON of `formatLevelsGeoJson` (aggregate2d's output).
struct LevelAggregateRecord {
    int level = 0;                    ///< "level" property (0 = finest aggregate level)
    double delta = 0;                 ///< "delta" property
    int aggregate = 0;                ///< "aggregate" property: index in its level
    std::vector<uint32_t> sources;    ///< "sources" property: input feature ids (ordinals in the input file)
    std::vector<Polygon2D> polygons;  ///< the geometry (Polygon or MultiPolygon)
    std::string name;                 ///< "feature 5 (line 7)", for messages
};

/// Reads aggregate2d's levels GeoJSON. `isLevels` is false (and true is returned, `out`
/// empty) when no feature carries all four properties level, delta, aggregate and sources:
/// then the text is plain polygons. Returns false with `error` when the text is not GeoJSON,
/// or when some feature carries them and the file is not such output (a feature without them,
/// a malformed property, a geometry that is not a valid Polygon / MultiPolygon).
bool readLevelsGeoJsonText(const std::string& text, std::vector<LevelAggregateRecord>& out, bool& isLevels,
                           std::string& error);
/// Same, from a file (messages start with the path).
bool readLevelsGeoJsonFile(const std::string& path, std::vector<LevelAggregateRecord>& out, bool& isLevels,
                           std::string& error);

/// One row of the link table of `formatLinksCsv`.
struct LinkRow {
    uint32_t input = 0;  ///< input feature id
    int level = 0;
    double delta = 0;
    int output = 0;      ///< aggregate index in its level
    int line = 0;        ///< line in the file (1 = header)
};
/// Reads a link table "input_id,level,delta,output_id" (header first). Returns false with
/// `error` (naming the line) when it is not one.
bool readLinksCsvText(const std::string& text, std::vector<LinkRow>& out, std::string& error);
bool readLinksCsvFile(const std::string& path, std::vector<LinkRow>& out, std::string& error);

/// aggregate2d's output read back and checked against its input polygons.
struct Aggregate2DOutput {
    struct Level {
        double delta = 0;
        std::vector<LevelAggregateRecord> aggregates;  ///< in file order (ascending aggregate index)
    };
    std::vector<Level> levels;            ///< level 0, 1, ... of the file (ascending delta)
    std::vector<Feature2D> originals;     ///< the input features the aggregates cover, in file order, with the
                                          ///< polygons aggregate2d accepts (acceptedPolygons2D)
    std::vector<std::string> notes;       ///< input polygons aggregate2d drops (invalid): not in the hierarchy
    size_t linkRows = 0;                  ///< rows of the link table checked (0 without one)
};

/// Checks aggregate2d's levels (read by readLevelsGeoJsonFile from `levelsPath`) against the
/// polygons it read (`originalsPath`, .wkt / .geojson / .json) and, when `linksPath` is not
/// empty, its link table: levels numbered 0..n-1 with one delta each, ascending; every level
/// covers the same input features, each by exactly one aggregate; these are exactly the input
/// features with polygons aggregate2d accepts (its input checks, acceptedPolygons2D); each aggregate contains the polygons of its sources (up to 1e-9 of the scene's
/// size: uncovered area at most that of a strip that wide along their boundary, and no vertex of
/// one that far on the wrong side of the other); the link table has exactly one row per source
/// of every aggregate, with its level, delta and aggregate index. Returns false with a message
/// naming the file, the aggregate (level, index, feature and line) or the link table line.
bool checkAggregate2DOutput(std::vector<LevelAggregateRecord> records, const std::string& levelsPath,
                            const std::string& originalsPath, const std::string& linksPath, Aggregate2DOutput& out,
                            std::string& error);

/// Containment of `inner` (union of polygons, may overlap) in `outer` (union of polygons),
/// up to `tolerance` (a length): see checkAggregate2DOutput.
struct Containment2D {
    bool contained = true;
    double uncoveredArea = 0;  ///< area of inner outside outer
    double innerArea = 0;      ///< area of the union of inner
    std::string why;           ///< when not contained: what was found, with coordinates
};
Containment2D checkContainment2D(const std::vector<const Polygon2D*>& inner, const std::vector<const Polygon2D*>& outer,
                                 double tolerance);

/// Stats JSON: originals, per level the measures (chosen shape, constant, adaptive, hull; raw
/// and normalised), group counts, diagnostics; timings last.
std::string formatStats2DJson(const Hierarchy2D& hierarchy, const std::vector<Feature2D>& features);

/// Writes text to a file (via a temporary file renamed over the target).
bool writeTextFile(const std::string& path, const std::string& text, std::string& error);

}  // namespace aggrelod::io
