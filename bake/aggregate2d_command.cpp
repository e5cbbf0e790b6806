// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod aggregate2d: polygons (WKT / GeoJSON) in, one GeoJSON of every level out, with
// optional link table, pictures and stats (paper Sections 3-4 in 2D; docs/design.md §4 "2D").
#include "commands_2d.h"
#include "geo_io.h"
#include "geo_picture.h"
#include "terminal.h"

#include <aggrelod/aggregate2d.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace aggrelod::cli {

int runAggregate2D(Aggregate2DOptions o) {
    for (double d : o.deltas)
        if (!std::isfinite(d) || d < 0) {
            std::fprintf(stderr, "aggrelod: error: --delta: every threshold must be a finite number >= 0\n");
            return 1;
        }
    std::sort(o.deltas.begin(), o.deltas.end());
    o.deltas.erase(std::unique(o.deltas.begin(), o.deltas.end()), o.deltas.end());

    io::GeoReadResult input;
    std::string error;
    if (!io::readPolygonFile(o.input, input, error)) {
        std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
        return 2;
    }
    printDiagnostics(input.diagnostics, o.quiet);
    if (input.features.empty()) {
        std::fprintf(stderr, "aggrelod: error: %s: no polygon to aggregate\n", o.input.c_str());
        return 2;
    }

    ProgressLine progress(!o.quiet && stderrIsTerminal());
    Settings2D settings;
    settings.deltas = o.deltas;
    settings.automaticLevelCount = o.levels;
    settings.function = o.function == "constant" ? AggregateFunctionKind::Constant : AggregateFunctionKind::Adaptive;
    settings.shape = o.function == "hull" ? Shape2D::ConvexHull : Shape2D::Sculpted;
    settings.threadCount = o.threads;
    settings.progress = [&progress](const char* stage, double fraction) { progress.update(stage, fraction); };
    Hierarchy2D hierarchy;
    const bool ok = buildHierarchy2D(input.features, settings, hierarchy);
    progress.finish();
    printDiagnostics(hierarchy.diagnostics, o.quiet);
    if (!ok) {
        std::fprintf(stderr, "aggrelod: error: %s: aggregation failed; nothing was written\n", o.input.c_str());
        return 3;
    }

    auto write = [&](const std::string& path, const std::string& text) {
        if (path.empty()) return true;
        if (!io::writeTextFile(path, text, error)) {
            std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
            return false;
        }
        return true;
    };
    if (!write(o.output, io::formatLevelsGeoJson(hierarchy, input.features))) return 2;
    if (!write(o.linksPath, io::formatLinksCsv(hierarchy, input.features))) return 2;
    if (!write(o.statsPath, io::formatStats2DJson(hierarchy, input.features))) return 2;
    // Pictures: the originals and every level side by side would be too wide; draw the
    // originals and the last three levels.
    if (!o.svgPath.empty() || !o.pngPath.empty()) {
        std::vector<io::PicturePanel> panels;
        panels.push_back({&input.features, nullptr, "original"});
        const size_t first = hierarchy.levels.size() > 3 ? hierarchy.levels.size() - 3 : 0;
        for (size_t l = first; l < hierarchy.levels.size(); ++l)
            panels.push_back({&input.features, &hierarchy.levels[l].aggregates,
                              "level " + std::to_string(l) + " d=" + formatNumber(hierarchy.levels[l].delta)});
        if (!write(o.svgPath, io::formatSvg(panels, 600))) return 2;
        if (!o.pngPath.empty() && !io::writePng(panels, 600, o.pngPath, error)) {
            std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
            return 2;
        }
    }

    if (!o.quiet) {
        std::printf("%zu features, %zu models, %zu triangles; originals: area %s, perimeter %s, circularity %s\n",
                    input.features.size(), hierarchy.modelCount, hierarchy.triangleCount,
                    formatNumber(hierarchy.originals.area).c_str(), formatNumber(hierarchy.originals.perimeter).c_str(),
                    formatNumber(hierarchy.originals.circularity).c_str());
        std::vector<std::vector<std::string>> rows{
            {"level", "delta", "groups", "area", "perimeter", "circularity", "area const", "area hull"}};
        for (size_t l = 0; l < hierarchy.levels.size(); ++l) {
            const Level2D& level = hierarchy.levels[l];
            const Measures2D n = normalizedMeasures(level.measures, hierarchy.originals);
            rows.push_back({std::to_string(l), formatNumber(level.delta), std::to_string(level.aggregates.size()),
                            formatNumber(n.area), formatNumber(n.perimeter), formatNumber(n.circularity),
                            formatNumber(normalizedMeasures(level.constant, hierarchy.originals).area),
                            formatNumber(normalizedMeasures(level.hull, hierarchy.originals).area)});
        }
        std::fputs("measures normalised to the originals:\n", stdout);
        std::fputs(formatTable(rows).c_str(), stdout);
        std::printf("wrote %s\n", o.output.c_str());
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace aggrelod::cli
