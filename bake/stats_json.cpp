// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the stats JSON file (json.h: keys in a fixed order, round-trip doubles,
// NaN/inf as null; deterministic).
#include "json.h"
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

const char* severityName(Diagnostic::Severity s) {
    switch (s) {
        case Diagnostic::Severity::Note: return "note";
        case Diagnostic::Severity::Warning: return "warning";
        case Diagnostic::Severity::Error: return "error";
    }
    return "warning";
}

Json measuresJson(const SolidMeasures& m) {
    Json j;
    j["volume"] = jsonNumber(m.volume);
    j["area"] = jsonNumber(m.area);
    j["sphericity"] = jsonNumber(m.sphericity);
    return j;
}

Json diagnosticJson(const Diagnostic& d) {
    Json j;
    j["severity"] = severityName(d.severity);
    j["object"] = d.object;
    j["message"] = d.message;
    return j;
}

/// Largest and median of `values` (0, 0 when empty).
std::pair<double, double> maxAndMedian(std::vector<double> values) {
    if (values.empty()) return {0, 0};
    std::sort(values.begin(), values.end());
    return {values.back(), values[values.size() / 2]};
}

/// The proxies of the nodes a cut of `nodes` would draw at one level (level -1: the
/// per-object LOD nodes, -2: the coarser versions of aggregates, -3: the bundles): their
/// budgets, certified errors and triangles.
Json proxyFiguresJson(const HierarchyNodes& nodes, int level) {
    std::vector<double> budgets, errors;
    size_t triangles = 0, count = 0;
    for (const HierarchyNode& n : nodes.nodes) {
        if (n.leaf) continue;
        const bool wanted = level >= 0   ? n.objectLod == 0 && n.coarserStep == 0 && n.bundleStep == 0 &&
                                               n.firstLevel <= level && level <= n.lastLevel
                            : level == -1 ? n.objectLod >= 1
                            : level == -2 ? n.coarserStep >= 1
                                          : n.bundleStep >= 1;
        if (!wanted) continue;
        ++count;
        budgets.push_back(n.budget);
        errors.push_back(n.error.bound());
        triangles += nodeTriangleCount(n);
    }
    const auto [budgetMax, budgetMedian] = maxAndMedian(budgets);
    const auto [errorMax, errorMedian] = maxAndMedian(errors);
    Json j;
    j["nodes"] = count;
    j["budget_max"] = jsonNumber(budgetMax);
    j["budget_median"] = jsonNumber(budgetMedian);
    j["error_max"] = jsonNumber(errorMax);
    j["error_median"] = jsonNumber(errorMedian);
    j["triangles"] = triangles;
    return j;
}

std::string statsJsonText(const Hierarchy3D& h, const std::vector<InputObject>& objects,
                          const std::vector<Diagnostic>& readDiagnostics, const HierarchyNodes* nodes) {
    Json w;
    w["objects"] = objects.size();
    w["models"] = h.modelCount;
    w["input_triangles"] = h.inputTriangleCount;
    w["tetrahedra"] = h.tetrahedronCount;
    w["originals"] = measuresJson(h.originals);

    Json& levels = w["levels"] = Json::array();
    for (size_t k = 0; k < h.levels.size(); ++k) {
        const Level& l = h.levels[k];
        long long components = 0;
        for (const Aggregate& a : l.aggregates) components += a.componentCount;
        Json j;
        j["level"] = k;
        j["delta"] = jsonNumber(l.delta);
        j["groups"] = l.aggregates.size();
        j["triangles"] = l.triangleCount;
        j["volume_original"] = jsonNumber(l.volumeOriginal);
        j["volume_aggregate"] = jsonNumber(l.measures.volume);
        j["volume_hull"] = jsonNumber(l.volumeHull);
        if (l.hasVolumeConstant) j["volume_constant"] = jsonNumber(l.volumeConstant);
        j["added_volume"] = jsonNumber(l.measures.volume - l.volumeOriginal);
        j["added_volume_hull"] = jsonNumber(l.volumeHull - l.volumeOriginal);
        if (l.hasVolumeConstant) j["added_volume_constant"] = jsonNumber(l.volumeConstant - l.volumeOriginal);
        j["area"] = jsonNumber(l.measures.area);
        j["sphericity"] = jsonNumber(l.measures.sphericity);
        j["components"] = components;
        if (nodes) j["proxies"] = proxyFiguresJson(*nodes, int(k));
        levels.push_back(std::move(j));
    }
    if (nodes) {
        w["object_lods"] = proxyFiguresJson(*nodes, -1);       // the per-object LOD nodes below the levels
        w["coarser_versions"] = proxyFiguresJson(*nodes, -2);  // between each aggregate and its parent
        w["bundles"] = proxyFiguresJson(*nodes, -3);           // between a group and its children
    }

    // Solidified models (docs/design.md §2.0): distances sampled, not certified.
    Json& solids = w["solids"] = Json::array();
    for (const SolidReport& r : h.solids) {
        Json j;
        std::string names;
        for (size_t i = 0; i < r.objects.size(); ++i) names += (i ? ", " : "") + objects[r.objects[i]].name;
        j["objects"] = names;
        j["method"] = r.method == SolidifyMethod::Wrap    ? "alpha_wrap"
                      : r.method == SolidifyMethod::Union ? "boolean_union"
                      : r.method == SolidifyMethod::Shell ? "shell"
                                                          : "convex_hull";
        j["reason"] = r.reason;
        j["alpha"] = jsonNumber(r.alpha);
        j["offset"] = jsonNumber(r.offset);
        j["bbox_diagonal"] = jsonNumber(r.bboxDiagonal);
        j["volume_original"] = jsonNumber(r.volumeOriginal);
        j["volume_solid"] = jsonNumber(r.volumeSolid);
        j["added_volume"] = jsonNumber(r.volumeSolid - r.volumeOriginal);
        j["distance_solid_to_original"] = jsonNumber(r.distanceSolidToOriginal);
        j["distance_original_to_solid"] = jsonNumber(r.distanceOriginalToSolid);
        j["hausdorff"] = jsonNumber(std::max(r.distanceSolidToOriginal, r.distanceOriginalToSolid));
        j["hausdorff_kind"] = "sampled";
        if (r.hullDistance > 0) j["hausdorff_convex_hull"] = jsonNumber(r.hullDistance);
        j["triangles"] = r.triangles.size() / 3;
        j["closed_manifold"] = r.closedManifold ? "yes" : "no";
        solids.push_back(std::move(j));
    }
    const auto names = [&](const std::vector<uint32_t>& ids) {
        Json list = Json::array();
        for (uint32_t i : ids) list.push_back(objects[i].name);
        return list;
    };
    w["support_surfaces"] = names(h.supportObjects);
    w["left_out"] = names(h.leftOutObjects);

    Json& merges = w["merges"] = Json::array();
    for (const Merge& m : h.merges) {
        Json j;
        j["height"] = jsonNumber(m.height);
        j["a"] = m.modelA;
        j["b"] = m.modelB;
        merges.push_back(std::move(j));
    }

    Json& warnings = w["warnings"] = Json::array();
    for (const Diagnostic& d : readDiagnostics) warnings.push_back(diagnosticJson(d));
    for (const Diagnostic& d : h.diagnostics) warnings.push_back(diagnosticJson(d));

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
    Json& times = w["timings"] = Json::object();
    for (const auto& t : timings) times[t.first] = jsonNumber(t.second);
    return jsonText(w);
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
