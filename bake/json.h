// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: JSON for the files the bake reads and writes (GeoJSON input, the output-set
// manifest, the stats files), through nlohmann::json (Debian nlohmann-json3-dev). The one
// place that names the library, so that it can be swapped. Determinism: keys keep the order
// they were set in; numbers are written so that they read back as the same double.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace aggrelod::io {

/// A JSON value whose object keys keep their insertion order.
using Json = nlohmann::ordered_json;

/// The JSON number for v: an integer when v is a whole number of magnitude below 2^53 (so
/// 3.0 is written "3"), null when v is not finite, 0 for -0.
Json jsonNumber(double v);

/// Two-space indented text of j with a final newline (UTF-8 passes through).
std::string jsonText(const Json& j);

/// Where parsed objects began in the text, for messages that point at a line: the top-level
/// value, and each element of the top-level object's array member `arrayKey` (e.g. the
/// "features" of a GeoJSON FeatureCollection), in order. Lines count from 1; 0 for an
/// element that is not an object.
struct JsonLines {
    std::string arrayKey;
    int rootLine = 0;
    std::vector<int> elementLines;
};

/// Parses text into out. False with "line L, column C: what" in error on malformed JSON or
/// nesting deeper than maxDepth (objects and arrays). `lines`, when given, gets where the
/// objects it asks for began.
bool parseJson(const std::string& text, Json& out, std::string& error, int maxDepth = 256, JsonLines* lines = nullptr);

}  // namespace aggrelod::io
