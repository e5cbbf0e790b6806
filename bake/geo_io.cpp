// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: WKT and GeoJSON readers and writers, link table and 2D stats JSON.
// JSON is read through json.h; numbers are written shortest round-trip, locale-independent.
#include "geo_io.h"
#include "json.h"

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

/// The member `key` of an object, or null (also when v is not an object).
const Json* member(const Json& v, const char* key) {
    if (!v.is_object()) return nullptr;
    const auto it = v.find(key);
    return it == v.end() ? nullptr : &*it;
}

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

/// A coordinate: a number, or NaN for null (what NaN and Infinity literals were read as,
/// see readableJson), which the geometry check then names.
bool coordinate(const Json& v, double& out) {
    if (v.is_number()) out = v.get<double>();
    else if (v.is_null()) out = NAN;
    else return false;
    return true;
}

bool readPosition(const Json& p, std::vector<double>& ring, std::string& problem) {
    double x = 0, y = 0;
    if (!p.is_array() || p.size() < 2 || !coordinate(p[0], x) || !coordinate(p[1], y)) {
        problem = "a position is not an array of at least 2 numbers";
        return false;
    }
    ring.push_back(x);
    ring.push_back(y);
    return true;
}

/// Length of the valid UTF-8 sequence at text[i] (1 to 4), or 0 when the bytes there are not one.
size_t utf8Length(const std::string& text, size_t i) {
    const auto byte = [&](size_t k) { return k < text.size() ? static_cast<unsigned char>(text[k]) : 0u; };
    const unsigned c = byte(i);
    const auto cont = [&](size_t k) { return (byte(k) & 0xC0u) == 0x80u; };
    if (c < 0x80) return 1;
    if (c >= 0xC2 && c <= 0xDF) return cont(i + 1) ? 2 : 0;
    if (c >= 0xE0 && c <= 0xEF) {
        const unsigned d = byte(i + 1);
        if ((c == 0xE0 && d < 0xA0) || (c == 0xED && d > 0x9F)) return 0;  // overlong, surrogate
        return cont(i + 1) && cont(i + 2) ? 3 : 0;
    }
    if (c >= 0xF0 && c <= 0xF4) {
        const unsigned d = byte(i + 1);
        if ((c == 0xF0 && d < 0x90) || (c == 0xF4 && d > 0x8F)) return 0;
        return cont(i + 1) && cont(i + 2) && cont(i + 3) ? 4 : 0;
    }
    return 0;
}

/// Text that nlohmann's strict parser reads, from what GeoJSON writers put out:
/// - JSON has no NaN or infinity, but some writers (Python's json module among them) put the
///   literals NaN, Infinity and -Infinity where a number is not finite. Outside strings they
///   become null, so that the file parses and the feature holding them is named and skipped
///   by the geometry check instead of the whole file being refused;
/// - inside strings, a byte that does not start valid UTF-8 (a Latin-1 export, say) is taken
///   as the Latin-1 character it is, instead of refusing the file.
/// Lines do not change; columns after a replacement shift by its length difference.
std::string readableJson(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    const auto boundary = [&](size_t i) { return i >= text.size() || !std::isalnum(static_cast<unsigned char>(text[i])); };
    bool inString = false;
    for (size_t i = 0; i < text.size();) {
        const char c = text[i];
        if (inString) {
            const size_t n = utf8Length(text, i);
            if (n == 0) {  // Latin-1 byte 0x80-0xFF as U+0080-U+00FF
                const unsigned b = static_cast<unsigned char>(c);
                out += char(0xC0 | (b >> 6));
                out += char(0x80 | (b & 0x3F));
                ++i;
                continue;
            }
            if (c == '\\' && i + 1 < text.size()) {
                out.append(text, i, 2);
                i += 2;
                continue;
            }
            if (c == '"') inString = false;
            out.append(text, i, n);
            i += n;
            continue;
        }
        if (c == '"') {
            inString = true;
            out += c;
            ++i;
            continue;
        }
        const bool start = i == 0 || boundary(i - 1);
        bool replaced = false;
        for (const char* word : {"-Infinity", "Infinity", "NaN"}) {
            const size_t n = std::strlen(word);
            if (start && text.compare(i, n, word) == 0 && boundary(i + n)) {
                out += "null";
                i += n;
                replaced = true;
                break;
            }
        }
        if (!replaced) out += text[i++];
    }
    return out;
}

bool readPolygonCoordinates(const Json& rings, Polygon2D& poly, size_t index, size_t count, std::string& problem) {
    if (!rings.is_array()) {
        problem = "polygon coordinates are not an array of rings";
        return false;
    }
    if (rings.empty()) {
        problem = "empty geometry (polygon without rings)";
        return false;
    }
    for (size_t r = 0; r < rings.size(); ++r) {
        const Json& ringValue = rings[r];
        if (!ringValue.is_array()) {
            problem = ringName(index, count, r) + ": not an array of positions";
            return false;
        }
        std::vector<double> ring;
        for (const Json& p : ringValue)
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

void readGeoJsonFeature(const Json* geometry, const std::string& name, uint32_t id, GeoReadResult& out) {
    auto problemOf = [&](Diagnostic::Severity severity, const std::string& message) {
        out.diagnostics.push_back({severity, name, message});
    };
    if (!geometry || geometry->is_null()) {
        problemOf(Diagnostic::Severity::Error, "empty geometry (null); feature skipped");
        return;
    }
    const Json* type = member(*geometry, "type");
    const Json* coords = member(*geometry, "coordinates");
    const std::string t = type && type->is_string() ? type->get<std::string>() : "";
    if (t != "Polygon" && t != "MultiPolygon") {
        problemOf(Diagnostic::Severity::Warning,
                  "unsupported geometry type '" + (t.empty() ? std::string("(none)") : t) +
                      "' (only Polygon and MultiPolygon are aggregated); feature skipped");
        return;
    }
    if (!coords || !coords->is_array() || coords->empty()) {
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
        for (size_t i = 0; i < coords->size(); ++i) {
            Polygon2D poly;
            if (!readPolygonCoordinates((*coords)[i], poly, i, coords->size(), problem)) {
                problemOf(Diagnostic::Severity::Error, problem + "; feature skipped");
                return;
            }
            feature.polygons.push_back(std::move(poly));
        }
    }
    out.features.push_back(std::move(feature));
}

bool readGeoJson(const std::string& text, GeoReadResult& out, std::string& error) {
    Json root;
    JsonLines lines;
    lines.arrayKey = "features";
    if (!parseJson(readableJson(text), root, error, 256, &lines)) {
        error = "malformed JSON: " + error;
        return false;
    }
    const Json* type = member(root, "type");
    if (!type || !type->is_string()) {
        error = "not GeoJSON: the top level is not an object with a \"type\"";
        return false;
    }
    const auto lineOf = [&](size_t index) {
        const int line = index < lines.elementLines.size() ? lines.elementLines[index] : 0;
        return line > 0 ? " (line " + std::to_string(line) + ")" : std::string();
    };
    auto featureName = [&](size_t index, const Json& f) {
        std::string name = "feature " + std::to_string(index + 1);
        const Json* props = member(f, "properties");
        const Json* label = props ? member(*props, "name") : nullptr;
        if (!label && props) label = member(*props, "NAME");
        if (label && label->is_string()) name += " \"" + label->get<std::string>() + "\"";
        return name + (&f == &root ? " (line " + std::to_string(lines.rootLine) + ")" : lineOf(index));
    };
    const std::string kind = type->get<std::string>();
    if (kind == "FeatureCollection") {
        const Json* features = member(root, "features");
        if (!features || !features->is_array()) {
            error = "GeoJSON FeatureCollection without a \"features\" array";
            return false;
        }
        for (size_t i = 0; i < features->size(); ++i) {
            const Json& f = (*features)[i];
            if (!f.is_object()) {
                out.diagnostics.push_back({Diagnostic::Severity::Error, featureName(i, f), "not a GeoJSON Feature object; skipped"});
                continue;
            }
            readGeoJsonFeature(member(f, "geometry"), featureName(i, f), static_cast<uint32_t>(i), out);
        }
    } else if (kind == "Feature") {
        readGeoJsonFeature(member(root, "geometry"), featureName(0, root), 0, out);
    } else {
        readGeoJsonFeature(&root, "geometry (line " + std::to_string(lines.rootLine) + ")", 0, out);
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
bool asIndex(const Json* v, int64_t limit, int64_t& out) {
    if (!v || !v->is_number()) return false;
    const double number = v->get<double>();
    if (!std::isfinite(number) || number < 0 || number >= double(limit) || number != std::floor(number)) return false;
    out = static_cast<int64_t>(number);
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
    Json root;
    JsonLines lines;
    lines.arrayKey = "features";
    if (!parseJson(text, root, error, 256, &lines)) {
        error = "malformed JSON: " + error;
        return false;
    }
    const Json* type = member(root, "type");
    if (!type || !type->is_string()) {
        error = "not GeoJSON: the top level is not an object with a \"type\"";
        return false;
    }
    const Json* features = member(root, "features");
    if (*type != "FeatureCollection" || !features || !features->is_array()) return true;
    static const char* const kKeys[] = {"level", "delta", "aggregate", "sources"};
    auto propertiesOf = [](const Json& f) -> const Json* {
        const Json* p = member(f, "properties");
        return p && p->is_object() ? p : nullptr;
    };
    // Plain polygons may well carry one of these names (a building's "level"): only a feature
    // with all four marks the file as aggregate2d's output.
    size_t marked = 0;
    for (const Json& f : *features)
        if (const Json* p = propertiesOf(f))
            if (std::all_of(std::begin(kKeys), std::end(kKeys), [&](const char* key) { return member(*p, key) != nullptr; }))
                ++marked;
    if (marked == 0) return true;
    isLevels = true;
    const std::string notOutput = ": not the GeoJSON of `aggrelod aggregate2d` (each of its features has the properties "
                                  "level, delta, aggregate and sources)";
    for (size_t i = 0; i < features->size(); ++i) {
        const Json& f = (*features)[i];
        const int line = i < lines.elementLines.size() ? lines.elementLines[i] : 0;
        const std::string name = "feature " + std::to_string(i + 1) + (line > 0 ? " at line " + std::to_string(line) : "");
        const Json* p = propertiesOf(f);
        if (!p) {
            error = name + " has no properties" + notOutput;
            return false;
        }
        for (const char* key : kKeys)
            if (!member(*p, key)) {
                error = name + " has no \"" + key + "\" property" + notOutput;
                return false;
            }
        LevelAggregateRecord r;
        r.name = name;
        int64_t value = 0;
        if (!asIndex(member(*p, "level"), 1 << 20, value)) {
            error = name + ": \"level\" is not a level number (an integer >= 0)" + notOutput;
            return false;
        }
        r.level = int(value);
        if (!asIndex(member(*p, "aggregate"), int64_t(1) << 31, value)) {
            error = name + ": \"aggregate\" is not an aggregate index (an integer >= 0)" + notOutput;
            return false;
        }
        r.aggregate = int(value);
        const Json* delta = member(*p, "delta");
        if (!delta->is_number() || !std::isfinite(delta->get<double>()) || delta->get<double>() < 0) {
            error = name + ": \"delta\" is not a finite number >= 0" + notOutput;
            return false;
        }
        r.delta = delta->get<double>();
        const Json* sources = member(*p, "sources");
        if (!sources->is_array() || sources->empty()) {
            error = name + ": \"sources\" is not a non-empty array of input feature ids" + notOutput;
            return false;
        }
        for (const Json& s : *sources) {
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
        readGeoJsonFeature(member(f, "geometry"), name, 0, one);
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
    const auto measures = [&](const Measures2D& m) {
        const Measures2D n = normalizedMeasures(m, h.originals);
        Json j;
        j["area"] = jsonNumber(m.area);
        j["perimeter"] = jsonNumber(m.perimeter);
        j["circularity"] = jsonNumber(m.circularity);
        j["normalized_area"] = jsonNumber(n.area);
        j["normalized_perimeter"] = jsonNumber(n.perimeter);
        j["normalized_circularity"] = jsonNumber(n.circularity);
        return j;
    };
    Json w;
    w["features"] = features.size();
    w["models"] = h.modelCount;
    w["triangulation"] = {{"vertices", h.vertexCount}, {"triangles", h.triangleCount}};
    w["originals"] = {{"area", jsonNumber(h.originals.area)},
                      {"perimeter", jsonNumber(h.originals.perimeter)},
                      {"circularity", jsonNumber(h.originals.circularity)}};
    Json levels = Json::array();
    for (size_t l = 0; l < h.levels.size(); ++l) {
        const Level2D& level = h.levels[l];
        Json j;
        j["level"] = l;
        j["delta"] = jsonNumber(level.delta);
        j["groups"] = level.aggregates.size();
        j["output"] = measures(level.measures);
        j["constant"] = measures(level.constant);
        j["adaptive"] = measures(level.adaptive);
        j["hull"] = measures(level.hull);
        levels.push_back(std::move(j));
    }
    w["levels"] = std::move(levels);
    Json diagnostics = Json::array();
    for (const Diagnostic& d : h.diagnostics)
        diagnostics.push_back({{"severity", d.severity == Diagnostic::Severity::Error     ? "error"
                                            : d.severity == Diagnostic::Severity::Warning ? "warning"
                                                                                          : "note"},
                               {"object", d.object},
                               {"message", d.message}});
    w["diagnostics"] = std::move(diagnostics);
    Json timings = Json::object();
    for (const auto& t : h.timings) timings[t.first] = jsonNumber(t.second);
    w["timings"] = std::move(timings);
    return jsonText(w);
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
