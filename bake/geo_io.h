// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: 2D polygon files in and out (WKT, GeoJSON, link table CSV, stats JSON)
// and pictures (SVG, PNG). module/ sees plain polygons; only this code knows formats.
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

/// Stats JSON: originals, per level the measures (chosen shape, constant, adaptive, hull; raw
/// and normalised), group counts, diagnostics; timings last.
std::string formatStats2DJson(const Hierarchy2D& hierarchy, const std::vector<Feature2D>& features);

/// Writes text to a file (via a temporary file renamed over the target).
bool writeTextFile(const std::string& path, const std::string& text, std::string& error);

/// What to draw in a picture panel.
struct PicturePanel {
    const std::vector<Feature2D>* originals = nullptr;  ///< filled in one colour
    const std::vector<Aggregate2D>* aggregates = nullptr;  ///< outlined (may be null)
    std::string title;
};

/// SVG of one or more panels side by side (same scale).
std::string formatSvg(const std::vector<PicturePanel>& panels, int panelWidth);

/// PNG (stb_image_write) of one or more panels side by side, each panelWidth pixels wide.
bool writePng(const std::vector<PicturePanel>& panels, int panelWidth, const std::string& path, std::string& error);

/// A simple chart for reproduce2d: groups of bars (one group per row label, one bar per
/// series), one chart per metric, stacked vertically. values[metric][row][series].
struct BarChart {
    std::vector<std::string> metricNames;
    std::vector<std::string> rowLabels;
    std::vector<std::string> seriesNames;
    std::vector<std::vector<std::vector<double>>> values;
};
bool writeBarChartPng(const BarChart& chart, const std::string& path, std::string& error);

}  // namespace aggrelod::io
