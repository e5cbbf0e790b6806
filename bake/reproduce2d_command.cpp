// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod reproduce2d: the paper's 2D evaluation (Section 4: Fig. 4, Fig. 6 b-d, Eq. 3)
// rerun on seeded analogues of its five environments. For each environment, 4 thresholds
// between the smallest and largest neighbour distance (the paper picks them at random in
// that range): just above the merges at 1/5, 2/5, 3/5 and 4/5 of the dendrogram; measures of constant (Eq. 1), adaptive (Eq. 2) and convex
// hull at the same groups, normalised to the originals. Files are deterministic; run
// times go to the terminal only.
#include "commands_2d.h"
#include "geo_io.h"
#include "geo_picture.h"
#include "terminal.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace aggrelod::cli {
namespace {

std::string fixed(double v, int digits = 4) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

}  // namespace

int runReproduce2D(const Reproduce2DOptions& o) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(o.outDir, ec);
    if (ec || !fs::is_directory(o.outDir)) {
        std::fprintf(stderr, "aggrelod: error: %s: cannot create the output directory\n", o.outDir.c_str());
        return 2;
    }
    std::string md =
        "| environment | polygons | vertices | level | delta | groups | area constant | area adaptive | area hull | "
        "perimeter constant | perimeter adaptive | perimeter hull | circularity constant | circularity adaptive | "
        "circularity hull |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    std::string csv =
        "environment,polygons,vertices,level,delta,groups,area_constant,area_adaptive,area_hull,perimeter_constant,"
        "perimeter_adaptive,perimeter_hull,circularity_constant,circularity_adaptive,circularity_hull\n";
    io::BarChart chart;
    chart.metricNames = {"circularity (normalised)", "area (normalised)", "perimeter (normalised)"};
    chart.seriesNames = {"constant", "adaptive", "hull"};
    chart.values.resize(3);
    std::vector<std::vector<std::string>> timeRows{{"environment", "polygons", "vertices", "seconds (all 4 levels)"}};
    std::string error;
    for (samples::Environment2D env : samples::allEnvironments2D()) {
        const std::string name = samples::environmentName(env);
        const std::vector<Feature2D> features = samples::makeEnvironment2D(env, o.seed);
        size_t vertices = 0;
        for (const Feature2D& f : features)
            for (const Polygon2D& p : f.polygons) vertices += p.exterior.size() / 2;
        // Neighbour distances: the dendrogram heights.
        Settings2D probe;
        probe.deltas = {0};
        probe.computeBaselines = false;
        Hierarchy2D first;
        if (!buildHierarchy2D(features, probe, first) || first.merges.empty()) {
            std::fprintf(stderr, "aggrelod: error: environment %s: aggregation failed\n", name.c_str());
            return 3;
        }
        // Thresholds between neighbour distances: just above the merges at 1/5 .. 4/5 of the
        // dendrogram (every level changes the grouping; the extremes would join almost nothing
        // or everything).
        Settings2D settings;
        const size_t mergeCount = first.merges.size();
        for (int i = 1; i <= 4; ++i) {
            const size_t k = std::min(mergeCount - 1, static_cast<size_t>(i * mergeCount / 5));
            const double h = first.merges[k].height;
            const double next = k + 1 < mergeCount ? first.merges[k + 1].height : h * 1.1;
            settings.deltas.push_back(h + 0.5 * (next - h));
        }
        const auto start = std::chrono::steady_clock::now();
        Hierarchy2D adaptive;
        if (!buildHierarchy2D(features, settings, adaptive)) return 3;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        timeRows.push_back({name, std::to_string(features.size()), std::to_string(vertices), formatNumber(seconds)});
        settings.function = AggregateFunctionKind::Constant;
        settings.computeBaselines = false;
        Hierarchy2D constant;
        if (!buildHierarchy2D(features, settings, constant)) return 3;
        for (size_t l = 0; l < adaptive.levels.size(); ++l) {
            const Level2D& level = adaptive.levels[l];
            const Measures2D c = normalizedMeasures(level.constant, adaptive.originals);
            const Measures2D a = normalizedMeasures(level.adaptive, adaptive.originals);
            const Measures2D h = normalizedMeasures(level.hull, adaptive.originals);
            const std::vector<std::string> cells{name, std::to_string(features.size()), std::to_string(vertices),
                                                 std::to_string(l + 1), fixed(level.delta, 3),
                                                 std::to_string(level.aggregates.size()), fixed(c.area), fixed(a.area),
                                                 fixed(h.area), fixed(c.perimeter), fixed(a.perimeter), fixed(h.perimeter),
                                                 fixed(c.circularity), fixed(a.circularity), fixed(h.circularity)};
            md += "|";
            for (const std::string& cell : cells) md += " " + cell + " |";
            md += "\n";
            for (size_t i = 0; i < cells.size(); ++i) csv += (i ? "," : "") + cells[i];
            csv += "\n";
            chart.rowLabels.push_back(name.substr(0, 3) + std::to_string(l + 1));
            chart.values[0].push_back({c.circularity, a.circularity, h.circularity});
            chart.values[1].push_back({c.area, a.area, h.area});
            chart.values[2].push_back({c.perimeter, a.perimeter, h.perimeter});
        }
        // Fig. 4 analogue: original | constant | adaptive at the third threshold.
        const size_t shown = std::min<size_t>(2, adaptive.levels.size() - 1);
        const std::string d = "d=" + formatNumber(adaptive.levels[shown].delta);
        std::vector<io::PicturePanel> panels{{&features, nullptr, name + " original"},
                                             {&features, &constant.levels[shown].aggregates, "constant " + d},
                                             {&features, &adaptive.levels[shown].aggregates, "adaptive " + d}};
        const std::string png = (fs::path(o.outDir) / ("fig4-" + name + ".png")).string();
        if (!io::writePng(panels, 520, png, error)) {
            std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
            return 2;
        }
        if (!o.quiet) std::fprintf(stderr, "%s: %zu polygons, %.3f s\n", name.c_str(), features.size(), seconds);
    }
    md = "# Paper Fig. 6 (b-d) reproduced: measures normalised to the originals\n\n"
         "Constant = Eq. 1 (alpha-shape like), adaptive = Eq. 2, hull = convex hull of each group; all at the same "
         "groups. Circularity = 4 pi A / P^2 of the totals (Eq. 3).\n\n" + md;
    const fs::path dir(o.outDir);
    if (!io::writeTextFile((dir / "table.md").string(), md, error) ||
        !io::writeTextFile((dir / "table.csv").string(), csv, error) ||
        !io::writeBarChartPng(chart, (dir / "fig6.png").string(), error)) {
        std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
        return 2;
    }
    if (!o.quiet) {
        std::fputs(formatTable(timeRows).c_str(), stdout);
        std::printf("wrote %s/table.md, table.csv, fig6.png and fig4-<environment>.png\n", o.outDir.c_str());
    }
    return 0;
}

}  // namespace aggrelod::cli
