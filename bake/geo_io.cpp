// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: WKT and GeoJSON readers and writers, link table and 2D stats JSON.
// A small hand-written JSON parser (with line/column in messages) keeps the bake free of
// another dependency; numbers are written shortest round-trip, locale-independent.
#include "geo_io.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

namespace aggrelod::io {
namespace {

// ---------------------------------------------------------------------------------------
// JSON

struct JsonValue {
    enum class Type { Null, Bool, Number, String, Array, Object } type = Type::Null;
    double number = 0;
    bool boolean = false;
    std::string string;
    std::vector<JsonValue> items;                            // Array
    std::vector<std::pair<std::string, JsonValue>> members;  // Object
    int line = 0;

    const JsonValue* get(const std::string& key) const {
        for (const auto& m : members)
            if (m.first == key) return &m.second;
        return nullptr;
    }
};

class JsonParser {
public:
    explicit JsonParser(const std::string& text) : s_(text) {}

    bool parse(JsonValue& out, std::string& error) {
        if (!value(out, 0)) {
            error = error_;
            return false;
        }
        skipSpace();
        if (pos_ != s_.size()) {
            fail("unexpected text after the JSON value");
            error = error_;
            return false;
        }
        return true;
    }

private:
    const std::string& s_;
    size_t pos_ = 0;
    int line_ = 1;
    size_t lineStart_ = 0;
    std::string error_;

    bool fail(const std::string& what) {
        if (error_.empty())
            error_ = "line " + std::to_string(line_) + ", column " + std::to_string(pos_ - lineStart_ + 1) + ": " + what;
        return false;
    }
    void skipSpace() {
        while (pos_ < s_.size()) {
            const char c = s_[pos_];
            if (c == '\n') {
                ++line_;
                lineStart_ = pos_ + 1;
            } else if (c != ' ' && c != '\t' && c != '\r') {
                break;
            }
            ++pos_;
        }
    }
    bool literal(const char* word) {
        const size_t n = std::strlen(word);
        if (s_.compare(pos_, n, word) != 0) return false;
        pos_ += n;
        return true;
    }
    bool value(JsonValue& v, int depth) {
        if (depth > 256) return fail("nesting too deep");
        skipSpace();
        if (pos_ >= s_.size()) return fail("unexpected end of file");
        v.line = line_;
        const char c = s_[pos_];
        if (c == '{') return object(v, depth);
        if (c == '[') return array(v, depth);
        if (c == '"') {
            v.type = JsonValue::Type::String;
            return string(v.string);
        }
        if (literal("true")) { v.type = JsonValue::Type::Bool; v.boolean = true; return true; }
        if (literal("false")) { v.type = JsonValue::Type::Bool; return true; }
        if (literal("null")) { v.type = JsonValue::Type::Null; return true; }
        // Non-standard NaN / Infinity (written by some tools) are accepted as numbers so the
        // geometry check can name the feature that holds them.
        if (literal("NaN")) { v.type = JsonValue::Type::Number; v.number = NAN; return true; }
        if (literal("Infinity")) { v.type = JsonValue::Type::Number; v.number = INFINITY; return true; }
        if (literal("-Infinity")) { v.type = JsonValue::Type::Number; v.number = -INFINITY; return true; }
        if (c == '-' || (c >= '0' && c <= '9')) {
            size_t end = pos_;
            while (end < s_.size() && (std::isdigit(static_cast<unsigned char>(s_[end])) || s_[end] == '-' ||
                                       s_[end] == '+' || s_[end] == '.' || s_[end] == 'e' || s_[end] == 'E'))
                ++end;
            const auto r = std::from_chars(s_.data() + pos_, s_.data() + end, v.number);
            if (r.ec != std::errc() || r.ptr != s_.data() + end) return fail("malformed number");
            v.type = JsonValue::Type::Number;
            pos_ = end;
            return true;
        }
        return fail(std::string("unexpected character '") + c + "'");
    }
    bool string(std::string& out) {
        ++pos_;  // opening quote
        while (pos_ < s_.size()) {
            const char c = s_[pos_++];
            if (c == '"') return true;
            if (c == '\n') return fail("line break inside a string");
            if (c != '\\') {
                out += c;
                continue;
            }
            if (pos_ >= s_.size()) break;
            const char e = s_[pos_++];
            switch (e) {
                case 'n': out += '\n'; break;
                case 't': out += '\t'; break;
                case 'r': out += '\r'; break;
                case 'b': out += '\b'; break;
                case 'f': out += '\f'; break;
                case 'u': {
                    if (pos_ + 4 > s_.size()) return fail("truncated \\u escape");
                    unsigned code = 0;
                    const auto r = std::from_chars(s_.data() + pos_, s_.data() + pos_ + 4, code, 16);
                    if (r.ec != std::errc()) return fail("malformed \\u escape");
                    pos_ += 4;
                    // UTF-8 (surrogate pairs kept as two code units; names only appear in messages)
                    if (code < 0x80) out += static_cast<char>(code);
                    else if (code < 0x800) { out += static_cast<char>(0xC0 | (code >> 6)); out += static_cast<char>(0x80 | (code & 0x3F)); }
                    else { out += static_cast<char>(0xE0 | (code >> 12)); out += static_cast<char>(0x80 | ((code >> 6) & 0x3F)); out += static_cast<char>(0x80 | (code & 0x3F)); }
                    break;
                }
                default: out += e;
            }
        }
        return fail("unterminated string");
    }
    bool array(JsonValue& v, int depth) {
        v.type = JsonValue::Type::Array;
        ++pos_;
        skipSpace();
        if (pos_ < s_.size() && s_[pos_] == ']') { ++pos_; return true; }
        while (true) {
            v.items.emplace_back();
            if (!value(v.items.back(), depth + 1)) return false;
            skipSpace();
            if (pos_ >= s_.size()) return fail("unexpected end of file inside an array");
            if (s_[pos_] == ',') { ++pos_; continue; }
            if (s_[pos_] == ']') { ++pos_; return true; }
            return fail("expected ',' or ']' in an array");
        }
    }
    bool object(JsonValue& v, int depth) {
        v.type = JsonValue::Type::Object;
        ++pos_;
        skipSpace();
        if (pos_ < s_.size() && s_[pos_] == '}') { ++pos_; return true; }
        while (true) {
            skipSpace();
            if (pos_ >= s_.size() || s_[pos_] != '"') return fail("expected a member name in quotes");
            std::string key;
            if (!string(key)) return false;
            skipSpace();
            if (pos_ >= s_.size() || s_[pos_] != ':') return fail("expected ':' after a member name");
            ++pos_;
            v.members.emplace_back(std::move(key), JsonValue{});
            if (!value(v.members.back().second, depth + 1)) return false;
            skipSpace();
            if (pos_ >= s_.size()) return fail("unexpected end of file inside an object");
            if (s_[pos_] == ',') { ++pos_; continue; }
            if (s_[pos_] == '}') { ++pos_; return true; }
            return fail("expected ',' or '}' in an object");
        }
    }
};

// ---------------------------------------------------------------------------------------
// Rings

/// Checks closure and drops the closing vertex; `problem` is set when unusable.
bool closeRing(std::vector<double>& ring, std::string& problem) {
    if (ring.empty()) {
        problem = "empty ring";
        return false;
    }
    const size_t n = ring.size() / 2;
    if (n < 4) {
        problem = "ring with " + std::to_string(n) + " positions (a closed ring needs at least 4)";
        return false;
    }
    const bool same = ring[0] == ring[2 * n - 2] && ring[1] == ring[2 * n - 1];
    const bool nan = std::isnan(ring[0]) || std::isnan(ring[1]);
    if (!same && !nan) {
        char buf[160];
        std::snprintf(buf, sizeof buf, "unclosed ring: first position (%.10g, %.10g) differs from last (%.10g, %.10g)",
                      ring[0], ring[1], ring[2 * n - 2], ring[2 * n - 1]);
        problem = buf;
        return false;
    }
    ring.resize(2 * n - 2);
    return true;
}

std::string ringName(size_t polygon, size_t polygonCount, size_t ring) {
    std::string s = polygonCount > 1 ? "polygon " + std::to_string(polygon + 1) + ", " : "";
    return s + (ring == 0 ? std::string("exterior ring") : "hole " + std::to_string(ring));
}

// ---------------------------------------------------------------------------------------
// GeoJSON reading

bool readPosition(const JsonValue& p, std::vector<double>& ring, std::string& problem) {
    if (p.type != JsonValue::Type::Array || p.items.size() < 2 || p.items[0].type != JsonValue::Type::Number ||
        p.items[1].type != JsonValue::Type::Number) {
        problem = "a position is not an array of at least 2 numbers (line " + std::to_string(p.line) + ")";
        return false;
    }
    ring.push_back(p.items[0].number);
    ring.push_back(p.items[1].number);
    return true;
}

bool readPolygonCoordinates(const JsonValue& rings, Polygon2D& poly, size_t index, size_t count, std::string& problem) {
    if (rings.type != JsonValue::Type::Array) {
        problem = "polygon coordinates are not an array of rings";
        return false;
    }
    if (rings.items.empty()) {
        problem = "empty geometry (polygon without rings)";
        return false;
    }
    for (size_t r = 0; r < rings.items.size(); ++r) {
        const JsonValue& ringValue = rings.items[r];
        if (ringValue.type != JsonValue::Type::Array) {
            problem = ringName(index, count, r) + ": not an array of positions";
            return false;
        }
        std::vector<double> ring;
        for (const JsonValue& p : ringValue.items)
            if (!readPosition(p, ring, problem)) {
                problem = ringName(index, count, r) + ": " + problem;
                return false;
            }
        std::string why;
        if (!closeRing(ring, why)) {
            problem = ringName(index, count, r) + ": " + why;
            return false;
        }
        if (r == 0) poly.exterior = std::move(ring);
        else poly.holes.push_back(std::move(ring));
    }
    return true;
}

void readGeoJsonFeature(const JsonValue* geometry, const std::string& name, uint32_t id, GeoReadResult& out) {
    auto problemOf = [&](Diagnostic::Severity severity, const std::string& message) {
        out.diagnostics.push_back({severity, name, message});
    };
    if (!geometry || geometry->type == JsonValue::Type::Null) {
        problemOf(Diagnostic::Severity::Error, "empty geometry (null); feature skipped");
        return;
    }
    const JsonValue* type = geometry->get("type");
    const JsonValue* coords = geometry->get("coordinates");
    const std::string t = type && type->type == JsonValue::Type::String ? type->string : "";
    if (t != "Polygon" && t != "MultiPolygon") {
        problemOf(Diagnostic::Severity::Warning,
                  "unsupported geometry type '" + (t.empty() ? std::string("(none)") : t) +
                      "' (only Polygon and MultiPolygon are aggregated); feature skipped");
        return;
    }
    if (!coords || coords->type != JsonValue::Type::Array || coords->items.empty()) {
        problemOf(Diagnostic::Severity::Error, "empty geometry (no coordinates); feature skipped");
        return;
    }
    Feature2D feature;
    feature.name = name;
    feature.id = id;
    std::string problem;
    if (t == "Polygon") {
        Polygon2D poly;
        if (!readPolygonCoordinates(*coords, poly, 0, 1, problem)) {
            problemOf(Diagnostic::Severity::Error, problem + "; feature skipped");
            return;
        }
        feature.polygons.push_back(std::move(poly));
    } else {
        for (size_t i = 0; i < coords->items.size(); ++i) {
            Polygon2D poly;
            if (!readPolygonCoordinates(coords->items[i], poly, i, coords->items.size(), problem)) {
                problemOf(Diagnostic::Severity::Error, problem + "; feature skipped");
                return;
            }
            feature.polygons.push_back(std::move(poly));
        }
    }
    out.features.push_back(std::move(feature));
}

bool readGeoJson(const std::string& text, GeoReadResult& out, std::string& error) {
    JsonValue root;
    JsonParser parser(text);
    if (!parser.parse(root, error)) {
        error = "malformed JSON: " + error;
        return false;
    }
    const JsonValue* type = root.get("type");
    if (root.type != JsonValue::Type::Object || !type || type->type != JsonValue::Type::String) {
        error = "not GeoJSON: the top level is not an object with a \"type\"";
        return false;
    }
    auto featureName = [](size_t index, const JsonValue& f) {
        std::string name = "feature " + std::to_string(index + 1);
        const JsonValue* props = f.get("properties");
        const JsonValue* label = props ? props->get("name") : nullptr;
        if (!label && props) label = props->get("NAME");
        if (label && label->type == JsonValue::Type::String) name += " \"" + label->string + "\"";
        return name + " (line " + std::to_string(f.line) + ")";
    };
    if (type->string == "FeatureCollection") {
        const JsonValue* features = root.get("features");
        if (!features || features->type != JsonValue::Type::Array) {
            error = "GeoJSON FeatureCollection without a \"features\" array";
            return false;
        }
        for (size_t i = 0; i < features->items.size(); ++i) {
            const JsonValue& f = features->items[i];
            if (f.type != JsonValue::Type::Object) {
                out.diagnostics.push_back({Diagnostic::Severity::Error, featureName(i, f), "not a GeoJSON Feature object; skipped"});
                continue;
            }
            readGeoJsonFeature(f.get("geometry"), featureName(i, f), static_cast<uint32_t>(i), out);
        }
    } else if (type->string == "Feature") {
        readGeoJsonFeature(root.get("geometry"), featureName(0, root), 0, out);
    } else {
        readGeoJsonFeature(&root, "geometry (line " + std::to_string(root.line) + ")", 0, out);
    }
    return true;
}

// ---------------------------------------------------------------------------------------
// WKT reading

class WktLine {
public:
    explicit WktLine(const std::string& s) : s_(s) {}
    void skipSpace() { while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_; }
    std::string word() {
        skipSpace();
        size_t b = pos_;
        while (pos_ < s_.size() && std::isalpha(static_cast<unsigned char>(s_[pos_]))) ++pos_;
        std::string w = s_.substr(b, pos_ - b);
        for (char& c : w) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        return w;
    }
    bool accept(char c) {
        skipSpace();
        if (pos_ < s_.size() && s_[pos_] == c) { ++pos_; return true; }
        return false;
    }
    bool expect(char c, std::string& problem) {
        if (accept(c)) return true;
        problem = std::string("expected '") + c + "' at column " + std::to_string(pos_ + 1);
        return false;
    }
    bool number(double& v, std::string& problem) {
        skipSpace();
        const char* begin = s_.c_str() + pos_;
        char* end = nullptr;
        v = std::strtod(begin, &end);  // accepts nan / inf: the geometry check names them
        if (end == begin) {
            problem = "expected a number at column " + std::to_string(pos_ + 1);
            return false;
        }
        pos_ += static_cast<size_t>(end - begin);
        return true;
    }
    bool atEnd() { skipSpace(); return pos_ >= s_.size(); }
    size_t column() const { return pos_ + 1; }

private:
    const std::string& s_;
    size_t pos_ = 0;
};

bool wktRing(WktLine& in, std::vector<double>& ring, std::string& problem) {
    if (!in.expect('(', problem)) return false;
    do {
        double x, y;
        if (!in.number(x, problem) || !in.number(y, problem)) return false;
        double z;
        std::string ignore;
        WktLine probe = in;
        if (probe.number(z, ignore)) in.number(z, ignore);  // Z ignored
        ring.push_back(x);
        ring.push_back(y);
    } while (in.accept(','));
    return in.expect(')', problem);
}

bool wktPolygon(WktLine& in, Polygon2D& poly, size_t index, size_t count, std::string& problem) {
    if (in.word() == "EMPTY") {
        problem = "empty geometry (EMPTY polygon)";
        return false;
    }
    if (!in.expect('(', problem)) return false;
    size_t r = 0;
    do {
        std::vector<double> ring;
        if (!wktRing(in, ring, problem)) return false;
        std::string why;
        if (!closeRing(ring, why)) {
            problem = ringName(index, count, r) + ": " + why;
            return false;
        }
        if (r == 0) poly.exterior = std::move(ring);
        else poly.holes.push_back(std::move(ring));
        ++r;
    } while (in.accept(','));
    return in.expect(')', problem);
}

bool readWkt(const std::string& text, GeoReadResult& out) {
    std::istringstream stream(text);
    std::string line;
    int lineNumber = 0;
    uint32_t ordinal = 0;
    while (std::getline(stream, line)) {
        ++lineNumber;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        WktLine in(line);
        if (in.atEnd()) continue;
        {
            WktLine probe(line);
            probe.skipSpace();
            if (line[line.find_first_not_of(" \t")] == '#') continue;
        }
        const std::string name = "line " + std::to_string(lineNumber);
        const uint32_t id = ordinal++;
        const std::string type = in.word();
        Feature2D feature;
        feature.name = name;
        feature.id = id;
        std::string problem;
        bool ok = true;
        if (type == "POLYGON") {
            Polygon2D poly;
            ok = wktPolygon(in, poly, 0, 1, problem);
            feature.polygons.push_back(std::move(poly));
        } else if (type == "MULTIPOLYGON") {
            WktLine probe = in;
            if (probe.word() == "EMPTY") {
                ok = false;
                problem = "empty geometry (MULTIPOLYGON EMPTY)";
            } else if ((ok = in.expect('(', problem))) {
                // Count the parts first for names: parse into a list.
                std::vector<Polygon2D> parts;
                do {
                    Polygon2D poly;
                    if (!(ok = wktPolygon(in, poly, parts.size(), 2, problem))) break;
                    parts.push_back(std::move(poly));
                } while (in.accept(','));
                if (ok) ok = in.expect(')', problem);
                feature.polygons = std::move(parts);
            }
        } else if (type.empty()) {
            ok = false;
            problem = "malformed WKT: expected a geometry type at column " + std::to_string(in.column());
        } else {
            out.diagnostics.push_back({Diagnostic::Severity::Warning, name,
                                       "unsupported geometry type '" + type +
                                           "' (only POLYGON and MULTIPOLYGON are aggregated); skipped"});
            continue;
        }
        if (ok && !in.atEnd()) {
            ok = false;
            problem = "unexpected text after the geometry at column " + std::to_string(in.column());
        }
        if (!ok) {
            if (problem.rfind("expected", 0) == 0) problem = "malformed WKT: " + problem;
            out.diagnostics.push_back({Diagnostic::Severity::Error, name, problem + "; skipped"});
            continue;
        }
        out.features.push_back(std::move(feature));
    }
    return true;
}

// ---------------------------------------------------------------------------------------
// Writing

void appendNumber(std::string& out, double v) {
    if (!std::isfinite(v)) {
        out += "null";
        return;
    }
    if (v == 0) v = 0;
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

void appendJsonString(std::string& out, const std::string& s) {
    out += '"';
    for (char c : s) {
        if (c == '"' || c == '\\') { out += '\\'; out += c; }
        else if (static_cast<unsigned char>(c) < 0x20) { char b[8]; std::snprintf(b, sizeof b, "\\u%04x", c); out += b; }
        else out += c;
    }
    out += '"';
}

void appendRing(std::string& out, const std::vector<double>& ring) {
    out += '[';
    const size_t n = ring.size() / 2;
    for (size_t i = 0; i <= n; ++i) {
        const size_t k = i % n;  // closed: first position repeated
        if (i) out += ',';
        out += '[';
        appendNumber(out, ring[2 * k]);
        out += ',';
        appendNumber(out, ring[2 * k + 1]);
        out += ']';
    }
    out += ']';
}

void appendPolygon(std::string& out, const Polygon2D& p) {
    out += '[';
    appendRing(out, p.exterior);
    for (const auto& h : p.holes) {
        out += ',';
        appendRing(out, h);
    }
    out += ']';
}

void appendMeasures(std::string& out, const char* key, const Measures2D& m, const Measures2D& originals, bool comma = true) {
    const Measures2D n = normalizedMeasures(m, originals);
    out += "    ";
    appendJsonString(out, key);
    out += ": {\"area\": ";
    appendNumber(out, m.area);
    out += ", \"perimeter\": ";
    appendNumber(out, m.perimeter);
    out += ", \"circularity\": ";
    appendNumber(out, m.circularity);
    out += ", \"normalized_area\": ";
    appendNumber(out, n.area);
    out += ", \"normalized_perimeter\": ";
    appendNumber(out, n.perimeter);
    out += ", \"normalized_circularity\": ";
    appendNumber(out, n.circularity);
    out += comma ? "},\n" : "}\n";
}

/// Largest magnitude of a coordinate: squares of coordinates (areas, distances) must stay
/// far inside double range, and their differences meaningful.
constexpr double kMaxCoordinate2D = 1e15;

/// A finite coordinate beyond kMaxCoordinate2D refuses the whole file (non-finite ones are
/// reported per feature by the geometry check).
bool checkCoordinateRange(const GeoReadResult& in, std::string& error) {
    for (const Feature2D& f : in.features) {
        for (const Polygon2D& p : f.polygons) {
            const auto ringOk = [&](const std::vector<double>& ring) {
                for (double v : ring) {
                    if (std::isfinite(v) && std::fabs(v) > kMaxCoordinate2D) {
                        char text[48];
                        std::snprintf(text, sizeof text, "%.6g", v);
                        error = f.name + ": coordinate " + text +
                                " is beyond the supported range (|coordinate| <= 1e15); refused";
                        return false;
                    }
                }
                return true;
            };
            if (!ringOk(p.exterior)) return false;
            for (const auto& hole : p.holes)
                if (!ringOk(hole)) return false;
        }
    }
    return true;
}

}  // namespace

bool readPolygonText(const std::string& text, const std::string& format, GeoReadResult& out, std::string& error) {
    out = GeoReadResult{};
    const bool ok = format == "wkt" ? readWkt(text, out) : readGeoJson(text, out, error);
    if (!ok) return false;
    if (!checkCoordinateRange(out, error)) {
        out = GeoReadResult{};
        return false;
    }
    return true;
}

bool readPolygonFile(const std::string& path, GeoReadResult& out, std::string& error) {
    std::ifstream file(path, std::ios::binary);
    if (!file) {
        error = path + ": cannot open";
        return false;
    }
    std::stringstream buffer;
    buffer << file.rdbuf();
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    std::string format;
    if (ext == ".wkt" || ext == ".txt") format = "wkt";
    else if (ext == ".geojson" || ext == ".json") format = "geojson";
    else {
        error = path + ": unknown extension '" + ext + "' (expected .wkt, .geojson or .json)";
        return false;
    }
    if (!readPolygonText(buffer.str(), format, out, error)) {
        error = path + ": " + error;
        return false;
    }
    return true;
}

namespace {

/// A JSON number that is a non-negative integer below 2^31.
bool asIndex(const JsonValue* v, int64_t limit, int64_t& out) {
    if (!v || v->type != JsonValue::Type::Number || !std::isfinite(v->number) || v->number < 0 ||
        v->number >= double(limit) || v->number != std::floor(v->number))
        return false;
    out = static_cast<int64_t>(v->number);
    return true;
}

std::string slurp(const std::string& path, bool& ok) {
    std::ifstream file(path, std::ios::binary);
    ok = bool(file);
    std::stringstream buffer;
    if (ok) buffer << file.rdbuf();
    return buffer.str();
}

}  // namespace

bool readLevelsGeoJsonText(const std::string& text, std::vector<LevelAggregateRecord>& out, bool& isLevels,
                           std::string& error) {
    out.clear();
    isLevels = false;
    JsonValue root;
    JsonParser parser(text);
    if (!parser.parse(root, error)) {
        error = "malformed JSON: " + error;
        return false;
    }
    const JsonValue* type = root.type == JsonValue::Type::Object ? root.get("type") : nullptr;
    if (!type || type->type != JsonValue::Type::String) {
        error = "not GeoJSON: the top level is not an object with a \"type\"";
        return false;
    }
    const JsonValue* features = root.get("features");
    if (type->string != "FeatureCollection" || !features || features->type != JsonValue::Type::Array) return true;
    static const char* const kKeys[] = {"level", "delta", "aggregate", "sources"};
    auto propertiesOf = [](const JsonValue& f) -> const JsonValue* {
        const JsonValue* p = f.type == JsonValue::Type::Object ? f.get("properties") : nullptr;
        return p && p->type == JsonValue::Type::Object ? p : nullptr;
    };
    // Plain polygons may well carry one of these names (a building's "level"): only a feature
    // with all four marks the file as aggregate2d's output.
    size_t marked = 0;
    for (const JsonValue& f : features->items)
        if (const JsonValue* p = propertiesOf(f))
            if (std::all_of(std::begin(kKeys), std::end(kKeys), [&](const char* key) { return p->get(key) != nullptr; }))
                ++marked;
    if (marked == 0) return true;
    isLevels = true;
    const std::string notOutput = ": not the GeoJSON of `aggrelod aggregate2d` (each of its features has the properties "
                                  "level, delta, aggregate and sources)";
    for (size_t i = 0; i < features->items.size(); ++i) {
        const JsonValue& f = features->items[i];
        const std::string name = "feature " + std::to_string(i + 1) + " at line " + std::to_string(f.line);
        const JsonValue* p = propertiesOf(f);
        if (!p) {
            error = name + " has no properties" + notOutput;
            return false;
        }
        for (const char* key : kKeys)
            if (!p->get(key)) {
                error = name + " has no \"" + key + "\" property" + notOutput;
                return false;
            }
        LevelAggregateRecord r;
        r.name = name;
        int64_t value = 0;
        if (!asIndex(p->get("level"), 1 << 20, value)) {
            error = name + ": \"level\" is not a level number (an integer >= 0)" + notOutput;
            return false;
        }
        r.level = int(value);
        if (!asIndex(p->get("aggregate"), int64_t(1) << 31, value)) {
            error = name + ": \"aggregate\" is not an aggregate index (an integer >= 0)" + notOutput;
            return false;
        }
        r.aggregate = int(value);
        const JsonValue* delta = p->get("delta");
        if (delta->type != JsonValue::Type::Number || !std::isfinite(delta->number) || delta->number < 0) {
            error = name + ": \"delta\" is not a finite number >= 0" + notOutput;
            return false;
        }
        r.delta = delta->number;
        const JsonValue* sources = p->get("sources");
        if (sources->type != JsonValue::Type::Array || sources->items.empty()) {
            error = name + ": \"sources\" is not a non-empty array of input feature ids" + notOutput;
            return false;
        }
        for (const JsonValue& s : sources->items) {
            if (!asIndex(&s, int64_t(1) << 32, value)) {
                error = name + ": \"sources\" holds something that is not an input feature id (an integer >= 0)" + notOutput;
                return false;
            }
            r.sources.push_back(static_cast<uint32_t>(value));
        }
        std::vector<uint32_t> sorted = r.sources;
        std::sort(sorted.begin(), sorted.end());
        if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) {
            error = name + ": \"sources\" lists an input feature twice";
            return false;
        }
        // The geometry, read as for plain polygons; here a problem refuses the file: a missing
        // aggregate would leave its originals uncovered.
        GeoReadResult one;
        readGeoJsonFeature(f.get("geometry"), name, 0, one);
        if (one.features.size() != 1) {
            error = name + ": " + (one.diagnostics.empty() ? std::string("no usable geometry") : one.diagnostics[0].message);
            const size_t skipped = error.rfind("; feature skipped");
            if (skipped != std::string::npos) error.erase(skipped);
            return false;
        }
        r.polygons = std::move(one.features[0].polygons);
        out.push_back(std::move(r));
    }
    if (out.empty()) {
        error = "no aggregates";
        return false;
    }
    return true;
}

bool readLevelsGeoJsonFile(const std::string& path, std::vector<LevelAggregateRecord>& out, bool& isLevels,
                           std::string& error) {
    bool ok = false;
    const std::string text = slurp(path, ok);
    if (!ok) {
        error = path + ": cannot open";
        return false;
    }
    if (!readLevelsGeoJsonText(text, out, isLevels, error)) {
        error = path + ": " + error;
        return false;
    }
    return true;
}

bool readLinksCsvText(const std::string& text, std::vector<LinkRow>& out, std::string& error) {
    out.clear();
    std::istringstream stream(text);
    std::string line;
    int lineNumber = 0;
    const std::string header = "input_id,level,delta,output_id";
    while (std::getline(stream, line)) {
        ++lineNumber;
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (lineNumber == 1) {
            if (line != header) {
                error = "line 1: expected the header \"" + header +
                        "\" (the link table of `aggrelod aggregate2d --links`), found \"" + line.substr(0, 80) + "\"";
                return false;
            }
            continue;
        }
        if (line.empty()) continue;
        std::vector<std::string> fields;
        size_t start = 0;
        for (;;) {
            const size_t comma = line.find(',', start);
            fields.push_back(line.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        const std::string where = "line " + std::to_string(lineNumber) + ": ";
        if (fields.size() != 4) {
            error = where + "expected 4 fields (input_id,level,delta,output_id), found " + std::to_string(fields.size());
            return false;
        }
        auto integer = [&](const std::string& field, int64_t limit, int64_t& v) {
            const auto r = std::from_chars(field.data(), field.data() + field.size(), v);
            return r.ec == std::errc() && r.ptr == field.data() + field.size() && v >= 0 && v < limit;
        };
        LinkRow row;
        row.line = lineNumber;
        int64_t v = 0;
        if (!integer(fields[0], int64_t(1) << 32, v)) {
            error = where + "input_id \"" + fields[0] + "\" is not an integer >= 0";
            return false;
        }
        row.input = static_cast<uint32_t>(v);
        if (!integer(fields[1], 1 << 20, v)) {
            error = where + "level \"" + fields[1] + "\" is not an integer >= 0";
            return false;
        }
        row.level = int(v);
        const auto r = std::from_chars(fields[2].data(), fields[2].data() + fields[2].size(), row.delta);
        if (r.ec != std::errc() || r.ptr != fields[2].data() + fields[2].size() || !std::isfinite(row.delta) || row.delta < 0) {
            error = where + "delta \"" + fields[2] + "\" is not a finite number >= 0";
            return false;
        }
        if (!integer(fields[3], int64_t(1) << 31, v)) {
            error = where + "output_id \"" + fields[3] + "\" is not an integer >= 0";
            return false;
        }
        row.output = int(v);
        out.push_back(row);
    }
    if (lineNumber == 0) {
        error = "empty file (expected the header \"" + header + "\")";
        return false;
    }
    return true;
}

bool readLinksCsvFile(const std::string& path, std::vector<LinkRow>& out, std::string& error) {
    bool ok = false;
    const std::string text = slurp(path, ok);
    if (!ok) {
        error = path + ": cannot open";
        return false;
    }
    if (!readLinksCsvText(text, out, error)) {
        error = path + ": " + error;
        return false;
    }
    return true;
}

std::string formatLevelsGeoJson(const Hierarchy2D& h, const std::vector<Feature2D>& features) {
    std::string out = "{\"type\": \"FeatureCollection\", \"features\": [\n";
    bool first = true;
    for (size_t l = 0; l < h.levels.size(); ++l) {
        const Level2D& level = h.levels[l];
        for (size_t g = 0; g < level.aggregates.size(); ++g) {
            const Aggregate2D& agg = level.aggregates[g];
            if (agg.polygons.empty()) continue;
            if (!first) out += ",\n";
            first = false;
            out += "{\"type\": \"Feature\", \"properties\": {\"level\": " + std::to_string(l) + ", \"delta\": ";
            appendNumber(out, level.delta);
            out += ", \"aggregate\": " + std::to_string(g) + ", \"sources\": [";
            for (size_t i = 0; i < agg.sourceFeatures.size(); ++i) {
                if (i) out += ", ";
                out += std::to_string(features[agg.sourceFeatures[i]].id);
            }
            out += "], \"area\": ";
            appendNumber(out, agg.measures.area);
            out += ", \"perimeter\": ";
            appendNumber(out, agg.measures.perimeter);
            out += "}, \"geometry\": {";
            if (agg.polygons.size() == 1) {
                out += "\"type\": \"Polygon\", \"coordinates\": ";
                appendPolygon(out, agg.polygons[0]);
            } else {
                out += "\"type\": \"MultiPolygon\", \"coordinates\": [";
                for (size_t p = 0; p < agg.polygons.size(); ++p) {
                    if (p) out += ',';
                    appendPolygon(out, agg.polygons[p]);
                }
                out += ']';
            }
            out += "}}";
        }
    }
    out += "\n]}\n";
    return out;
}

std::string formatLinksCsv(const Hierarchy2D& h, const std::vector<Feature2D>& features) {
    std::string out = "input_id,level,delta,output_id\n";
    // Per level: feature -> aggregate.
    for (size_t l = 0; l < h.levels.size(); ++l) {
        std::vector<long long> outputOf(features.size(), -1);
        for (size_t g = 0; g < h.levels[l].aggregates.size(); ++g)
            for (uint32_t f : h.levels[l].aggregates[g].sourceFeatures) outputOf[f] = static_cast<long long>(g);
        for (size_t f = 0; f < features.size(); ++f) {
            if (outputOf[f] < 0) continue;
            out += std::to_string(features[f].id) + "," + std::to_string(l) + ",";
            appendNumber(out, h.levels[l].delta);
            out += "," + std::to_string(outputOf[f]) + "\n";
        }
    }
    return out;
}

std::string formatStats2DJson(const Hierarchy2D& h, const std::vector<Feature2D>& features) {
    std::string out = "{\n  \"features\": " + std::to_string(features.size()) +
                      ",\n  \"models\": " + std::to_string(h.modelCount) +
                      ",\n  \"triangulation\": {\"vertices\": " + std::to_string(h.vertexCount) +
                      ", \"triangles\": " + std::to_string(h.triangleCount) + "},\n  \"originals\": {\"area\": ";
    appendNumber(out, h.originals.area);
    out += ", \"perimeter\": ";
    appendNumber(out, h.originals.perimeter);
    out += ", \"circularity\": ";
    appendNumber(out, h.originals.circularity);
    out += "},\n  \"levels\": [\n";
    for (size_t l = 0; l < h.levels.size(); ++l) {
        const Level2D& level = h.levels[l];
        out += "   {\"level\": " + std::to_string(l) + ", \"delta\": ";
        appendNumber(out, level.delta);
        out += ", \"groups\": " + std::to_string(level.aggregates.size()) + ",\n";
        appendMeasures(out, "output", level.measures, h.originals);
        appendMeasures(out, "constant", level.constant, h.originals);
        appendMeasures(out, "adaptive", level.adaptive, h.originals);
        appendMeasures(out, "hull", level.hull, h.originals, false);
        out += l + 1 < h.levels.size() ? "   },\n" : "   }\n";
    }
    out += "  ],\n  \"diagnostics\": [";
    for (size_t i = 0; i < h.diagnostics.size(); ++i) {
        const Diagnostic& d = h.diagnostics[i];
        out += i ? ",\n    " : "\n    ";
        out += "{\"severity\": ";
        appendJsonString(out, d.severity == Diagnostic::Severity::Error ? "error"
                              : d.severity == Diagnostic::Severity::Warning ? "warning" : "note");
        out += ", \"object\": ";
        appendJsonString(out, d.object);
        out += ", \"message\": ";
        appendJsonString(out, d.message);
        out += "}";
    }
    out += "\n  ],\n  \"timings\": {";
    for (size_t i = 0; i < h.timings.size(); ++i) {
        out += i ? ", " : "";
        appendJsonString(out, h.timings[i].first);
        out += ": ";
        appendNumber(out, h.timings[i].second);
    }
    out += "}\n}\n";
    return out;
}

bool writeTextFile(const std::string& path, const std::string& text, std::string& error) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    std::error_code ec;
    if (target.has_parent_path()) fs::create_directories(target.parent_path(), ec);
    const fs::path tmp = fs::path(path + ".tmp");
    {
        std::ofstream file(tmp, std::ios::binary | std::ios::trunc);
        if (!file) {
            error = path + ": cannot write";
            return false;
        }
        file.write(text.data(), static_cast<std::streamsize>(text.size()));
        if (!file) {
            error = path + ": write failed";
            fs::remove(tmp, ec);
            return false;
        }
    }
    fs::rename(tmp, target, ec);
    if (ec) {
        error = path + ": cannot replace: " + ec.message();
        fs::remove(tmp, ec);
        return false;
    }
    return true;
}

}  // namespace aggrelod::io
