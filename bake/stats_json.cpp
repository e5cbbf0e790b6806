// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the stats JSON file, with a small hand-written JSON writer
// (deterministic: shortest round-trip doubles, locale-independent; NaN/inf as null).
#include "scene_io.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod::io {
namespace {

/// Minimal streaming JSON writer with two-space indentation. The caller keeps the
/// structure valid; commas and indentation are handled here.
class JsonWriter {
public:
    explicit JsonWriter(std::string& out) : out_(out) {}

    void beginObject() { open('{'); }
    void endObject() { close('}'); }
    void beginArray() { open('['); }
    void endArray() { close(']'); }

    /// Arrays whose elements stay on one line (small records): `{"a": 1, "b": 2}`.
    void beginInlineObject() {
        value();
        out_ += '{';
        inlineDepth_++;
        first_ = true;
    }
    void endInlineObject() {
        out_ += '}';
        inlineDepth_--;
        first_ = false;
    }

    void key(const std::string& k) {
        separator();
        string(k);
        out_ += ": ";
        afterKey_ = true;
    }

    void number(double v) {
        value();
        if (!std::isfinite(v)) {
            out_ += "null";
            return;
        }
        if (v == 0) v = 0;  // no "-0"
        char buf[64];
        const auto r = std::to_chars(buf, buf + sizeof buf, v);
        out_.append(buf, r.ptr);
    }
    void integer(long long v) {
        value();
        out_ += std::to_string(v);
    }
    void unsignedInteger(unsigned long long v) {
        value();
        out_ += std::to_string(v);
    }
    void str(const std::string& s) {
        value();
        string(s);
    }

    // key + value shorthands
    void field(const std::string& k, double v) { key(k); number(v); }
    void fieldInt(const std::string& k, unsigned long long v) { key(k); unsignedInteger(v); }
    void fieldSigned(const std::string& k, long long v) { key(k); integer(v); }
    void fieldStr(const std::string& k, const std::string& v) { key(k); str(v); }

    void finish() { out_ += '\n'; }

private:
    void open(char c) {
        value();
        out_ += c;
        depth_++;
        first_ = true;
    }
    void close(char c) {
        depth_--;
        if (!first_) newline();
        out_ += c;
        first_ = false;
    }
    void newline() {
        out_ += '\n';
        out_.append(size_t(depth_) * 2, ' ');
    }
    void separator() {
        if (!first_) out_ += inlineDepth_ > 0 ? ", " : ",";
        if (inlineDepth_ == 0) newline();
        first_ = false;
    }
    /// Before a value: separator unless it follows a key.
    void value() {
        if (afterKey_) {
            afterKey_ = false;
            return;
        }
        if (depth_ == 0 && inlineDepth_ == 0 && out_.empty()) return;
        separator();
    }
    void string(const std::string& s) {
        out_ += '"';
        for (unsigned char c : s) {
            switch (c) {
                case '"': out_ += "\\\""; break;
                case '\\': out_ += "\\\\"; break;
                case '\b': out_ += "\\b"; break;
                case '\f': out_ += "\\f"; break;
                case '\n': out_ += "\\n"; break;
                case '\r': out_ += "\\r"; break;
                case '\t': out_ += "\\t"; break;
                default:
                    if (c < 0x20 || c == 0x7f) {
                        char buf[8];
                        std::snprintf(buf, sizeof buf, "\\u%04x", unsigned(c));
                        out_ += buf;
                    } else {
                        out_ += char(c);  // UTF-8 passes through
                    }
            }
        }
        out_ += '"';
    }

    std::string& out_;
    int depth_ = 0;
    int inlineDepth_ = 0;
    bool first_ = true;
    bool afterKey_ = false;
};

const char* severityName(Diagnostic::Severity s) {
    switch (s) {
        case Diagnostic::Severity::Note: return "note";
        case Diagnostic::Severity::Warning: return "warning";
        case Diagnostic::Severity::Error: return "error";
    }
    return "warning";
}

void writeMeasures(JsonWriter& w, const SolidMeasures& m) {
    w.beginInlineObject();
    w.field("volume", m.volume);
    w.field("area", m.area);
    w.field("sphericity", m.sphericity);
    w.endInlineObject();
}

void writeDiagnostic(JsonWriter& w, const Diagnostic& d) {
    w.beginInlineObject();
    w.fieldStr("severity", severityName(d.severity));
    w.fieldStr("object", d.object);
    w.fieldStr("message", d.message);
    w.endInlineObject();
}

/// Largest and median of `values` (0, 0 when empty).
std::pair<double, double> maxAndMedian(std::vector<double> values) {
    if (values.empty()) return {0, 0};
    std::sort(values.begin(), values.end());
    return {values.back(), values[values.size() / 2]};
}

/// The proxies of the nodes a cut of `nodes` would draw at one level (level -1: the
/// per-object LOD nodes, -2: the coarser versions of aggregates): their budgets, certified
/// errors and triangles.
void writeProxyFigures(JsonWriter& w, const HierarchyNodes& nodes, int level) {
    std::vector<double> budgets, errors;
    size_t triangles = 0, count = 0;
    for (const HierarchyNode& n : nodes.nodes) {
        if (n.leaf) continue;
        const bool wanted = level >= 0   ? n.objectLod == 0 && n.coarserStep == 0 && n.firstLevel <= level &&
                                               level <= n.lastLevel
                            : level == -1 ? n.objectLod >= 1
                                          : n.coarserStep >= 1;
        if (!wanted) continue;
        ++count;
        budgets.push_back(n.budget);
        errors.push_back(n.error.bound());
        triangles += n.indices.size() / 3;
    }
    const auto [budgetMax, budgetMedian] = maxAndMedian(budgets);
    const auto [errorMax, errorMedian] = maxAndMedian(errors);
    w.beginInlineObject();
    w.fieldInt("nodes", count);
    w.field("budget_max", budgetMax);
    w.field("budget_median", budgetMedian);
    w.field("error_max", errorMax);
    w.field("error_median", errorMedian);
    w.fieldInt("triangles", triangles);
    w.endInlineObject();
}

std::string statsJsonText(const Hierarchy3D& h, const std::vector<InputObject>& objects,
                          const std::vector<Diagnostic>& readDiagnostics, const HierarchyNodes* nodes) {
    std::string text;
    JsonWriter w(text);
    w.beginObject();
    w.fieldInt("objects", objects.size());
    w.fieldInt("models", h.modelCount);
    w.fieldInt("input_triangles", h.inputTriangleCount);
    w.fieldInt("tetrahedra", h.tetrahedronCount);
    w.key("originals");
    writeMeasures(w, h.originals);

    w.key("levels");
    w.beginArray();
    for (size_t k = 0; k < h.levels.size(); ++k) {
        const Level& l = h.levels[k];
        long long components = 0;
        for (const Aggregate& a : l.aggregates) components += a.componentCount;
        w.beginInlineObject();
        w.fieldInt("level", k);
        w.field("delta", l.delta);
        w.fieldInt("groups", l.aggregates.size());
        w.fieldInt("triangles", l.triangleCount);
        w.field("volume_original", l.volumeOriginal);
        w.field("volume_aggregate", l.measures.volume);
        w.field("volume_hull", l.volumeHull);
        if (l.hasVolumeConstant) w.field("volume_constant", l.volumeConstant);
        w.field("added_volume", l.measures.volume - l.volumeOriginal);
        w.field("added_volume_hull", l.volumeHull - l.volumeOriginal);
        if (l.hasVolumeConstant) w.field("added_volume_constant", l.volumeConstant - l.volumeOriginal);
        w.field("area", l.measures.area);
        w.field("sphericity", l.measures.sphericity);
        w.fieldSigned("components", components);
        if (nodes) {
            w.key("proxies");
            writeProxyFigures(w, *nodes, int(k));
        }
        w.endInlineObject();
    }
    w.endArray();
    if (nodes) {  // the per-object LOD nodes below the levels
        w.key("object_lods");
        writeProxyFigures(w, *nodes, -1);
        w.key("coarser_versions");  // between each aggregate and its parent
        writeProxyFigures(w, *nodes, -2);
    }

    // Solidified models (docs/design.md §2.0): distances sampled, not certified.
    w.key("solids");
    w.beginArray();
    for (const SolidReport& r : h.solids) {
        w.beginInlineObject();
        std::string names;
        for (size_t i = 0; i < r.objects.size(); ++i) names += (i ? ", " : "") + objects[r.objects[i]].name;
        w.fieldStr("objects", names);
        w.fieldStr("method", r.method == SolidifyMethod::Wrap    ? "alpha_wrap"
                            : r.method == SolidifyMethod::Union ? "boolean_union"
                                                                : "convex_hull");
        w.fieldStr("reason", r.reason);
        w.field("alpha", r.alpha);
        w.field("offset", r.offset);
        w.field("bbox_diagonal", r.bboxDiagonal);
        w.field("volume_original", r.volumeOriginal);
        w.field("volume_solid", r.volumeSolid);
        w.field("added_volume", r.volumeSolid - r.volumeOriginal);
        w.field("distance_solid_to_original", r.distanceSolidToOriginal);
        w.field("distance_original_to_solid", r.distanceOriginalToSolid);
        w.field("hausdorff", std::max(r.distanceSolidToOriginal, r.distanceOriginalToSolid));
        w.fieldStr("hausdorff_kind", "sampled");
        if (r.hullDistance > 0) w.field("hausdorff_convex_hull", r.hullDistance);
        w.fieldInt("triangles", r.triangles.size() / 3);
        w.fieldStr("closed_manifold", r.closedManifold ? "yes" : "no");
        w.endInlineObject();
    }
    w.endArray();
    const auto writeNames = [&](const char* key, const std::vector<uint32_t>& ids) {
        w.key(key);
        w.beginArray();
        for (uint32_t i : ids) w.str(objects[i].name);
        w.endArray();
    };
    writeNames("support_surfaces", h.supportObjects);
    writeNames("left_out", h.leftOutObjects);

    w.key("merges");
    w.beginArray();
    for (const Merge& m : h.merges) {
        w.beginInlineObject();
        w.field("height", m.height);
        w.fieldInt("a", m.modelA);
        w.fieldInt("b", m.modelB);
        w.endInlineObject();
    }
    w.endArray();

    w.key("warnings");
    w.beginArray();
    for (const Diagnostic& d : readDiagnostics) writeDiagnostic(w, d);
    for (const Diagnostic& d : h.diagnostics) writeDiagnostic(w, d);
    w.endArray();

    // Last, so that determinism checks can drop it.
    // A stage run more than once (e.g. triangulating again after a refinement) is summed,
    // so that every key appears once, in order of first appearance.
    std::vector<std::pair<std::string, double>> timings;
    for (const auto& t : h.timings) {
        auto it = std::find_if(timings.begin(), timings.end(),
                               [&](const auto& e) { return e.first == t.first; });
        if (it == timings.end()) {
            timings.push_back(t);
        } else {
            it->second += t.second;
        }
    }
    w.key("timings");
    w.beginObject();
    for (const auto& t : timings) w.field(t.first, t.second);
    w.endObject();
    w.endObject();
    w.finish();
    return text;
}

}  // namespace

bool writeStatsJson(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                    const std::vector<Diagnostic>& readDiagnostics, const std::string& path,
                    std::string& error, const HierarchyNodes* nodes) {
    try {
        const std::string text = statsJsonText(hierarchy, objects, readDiagnostics, nodes);
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        if (!out) {
            error = path + ": cannot create: " + std::strerror(errno);
            return false;
        }
        out.write(text.data(), std::streamsize(text.size()));
        out.close();
        if (!out) {
            error = path + ": write error (disk full?)";
            return false;
        }
        return true;
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

}  // namespace aggrelod::io
