// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod reproduce-planning: the paper's motion-planning experiment (Section 4.3, Fig. 7) as a
// command. On the five 2D environments (aggregated here, 6 automatic levels) and on the 3D
// forest, village and a 1000-object random scene (baked with `aggrelod bake`, 8 automatic
// levels, without bundles: a group's bundle may stand for it at its level, and the planner
// wants the aggregates there), seeded random start / goal pairs free for the originals; each pair planned with the
// same OMPL LazyPRM on the originals, with the hierarchy, and at each fixed level. Writes
// planning.md, planning.csv and one Fig. 7-style picture per environment (the first query,
// hierarchy strategy). Table contents depend on timing (time-limited planning); the queries,
// roadmaps and paths of solved queries are deterministic.
#include "commands_plan.h"
#include "geo_io.h"
#include "scene_io.h"
#include "terminal.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/samples.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>

namespace aggrelod::cli {
namespace {

namespace fs = std::filesystem;

std::string fixed(double v, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

double quantile(std::vector<double> v, double q) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    const double pos = q * double(v.size() - 1);
    const size_t i = size_t(std::floor(pos));
    const double f = pos - double(i);
    return i + 1 < v.size() ? v[i] * (1 - f) + v[i + 1] * f : v[i];
}

std::string quoteShell(const std::string& s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

struct Environment {
    std::string name;
    bool is3D;
    double radius;
};

/// Random query ends free for the originals (std::mt19937, our own double conversion).
std::vector<std::pair<planning::Point, planning::Point>> makeQueries(const planning::PlanningWorld& w, int count,
                                                                     uint32_t seed) {
    std::mt19937 rng(seed);
    const planning::Point lo = w.boundsMin(), hi = w.boundsMax();
    auto sample = [&] {
        for (int attempt = 0; attempt < 1000000; ++attempt) {
            planning::Point p{0, 0, 0};
            for (int k = 0; k < w.dimension(); ++k)
                p[size_t(k)] = lo[size_t(k)] + (hi[size_t(k)] - lo[size_t(k)]) * (double(rng()) / 4294967296.0);
            if (w.stateFree(0, p)) return p;
        }
        return planning::Point{NAN, NAN, NAN};
    };
    std::vector<std::pair<planning::Point, planning::Point>> out;
    for (int i = 0; i < count; ++i) {
        const planning::Point a = sample();
        out.push_back({a, sample()});
    }
    return out;
}

struct Row {
    std::string strategy;
    int queries = 0, solved = 0;
    std::vector<double> seconds, lengthRatio, checks, vertices;
};

}  // namespace

int runReproducePlanning(const ReproducePlanningOptions& o) {
    std::error_code ec;
    fs::create_directories(o.outDir, ec);
    if (ec || !fs::is_directory(o.outDir)) {
        std::fprintf(stderr, "aggrelod: error: %s: cannot create the output directory\n", o.outDir.c_str());
        return 2;
    }
    std::vector<Environment> envs;
    for (samples::Environment2D e : samples::allEnvironments2D()) envs.push_back({samples::environmentName(e), false, 0});
    envs.push_back({"forest3d", true, 0.2});
    envs.push_back({"village3d", true, 0.2});
    envs.push_back({"random1000", true, 0.1});
    if (!o.only.empty()) {
        std::vector<Environment> kept;
        std::stringstream ss(o.only);
        std::string name;
        while (std::getline(ss, name, ','))
            for (const Environment& e : envs)
                if (e.name == name) kept.push_back(e);
        if (kept.empty()) {
            std::fprintf(stderr, "aggrelod: error: --only %s: no such environment\n", o.only.c_str());
            return 1;
        }
        envs = kept;
    }
    const bool progress = !o.quiet && stderrIsTerminal();
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);

    std::string md = "| environment | objects | levels | radius | strategy | queries | success | median s | p90 s | "
                     "median length / best | median checks | median roadmap vertices |\n"
                     "|---|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|\n";
    std::string csv = "environment,objects,levels,radius,strategy,queries,solved,success_rate,median_seconds,p90_seconds,"
                      "median_length_ratio,median_collision_checks,median_roadmap_vertices\n";
    std::string summary;
    for (const Environment& env : envs) {
        PlanScene scene;
        std::string error;
        size_t objects = 0;
        if (!env.is3D) {
            samples::Environment2D which{};
            for (samples::Environment2D e : samples::allEnvironments2D())
                if (samples::environmentName(e) == env.name) which = e;
            const std::vector<Feature2D> features = samples::makeEnvironment2D(which, o.seed);
            Settings2D settings;
            settings.automaticLevelCount = 6;
            settings.computeBaselines = false;
            Hierarchy2D h;
            if (!buildHierarchy2D(features, settings, h)) {
                std::fprintf(stderr, "aggrelod: error: %s: aggregation failed\n", env.name.c_str());
                return 3;
            }
            std::vector<planning::PlanPolygon> originals;
            double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (const Feature2D& f : features)
                for (const Polygon2D& p : f.polygons) {
                    planning::PlanPolygon q;
                    q.rings.push_back(p.exterior);
                    for (const auto& hole : p.holes) q.rings.push_back(hole);
                    for (size_t i = 0; i + 1 < p.exterior.size(); i += 2)
                        for (int k = 0; k < 2; ++k)
                            lo[k] = std::min(lo[k], p.exterior[i + size_t(k)]), hi[k] = std::max(hi[k], p.exterior[i + size_t(k)]);
                    originals.push_back(std::move(q));
                }
            objects = features.size();
            std::vector<std::vector<planning::PlanPolygon>> levels;
            std::vector<double> deltas;
            for (const Level2D& level : h.levels) {
                levels.emplace_back();
                deltas.push_back(level.delta);
                for (const Aggregate2D& a : level.aggregates)
                    for (const Polygon2D& p : a.polygons) {
                        planning::PlanPolygon q;
                        q.rings.push_back(p.exterior);
                        for (const auto& hole : p.holes) q.rings.push_back(hole);
                        levels.back().push_back(std::move(q));
                    }
            }
            // The agent: 0.2 % of the environment's larger side.
            const double radius = 0.002 * std::max(hi[0] - lo[0], hi[1] - lo[1]);
            if (!makePlanScene2D(std::move(originals), std::move(levels), deltas, radius, scene, error)) {
                std::fprintf(stderr, "aggrelod: error: %s: %s\n", env.name.c_str(), error.c_str());
                return 3;
            }
        } else {
            const fs::path dir = fs::path(o.outDir) / "scenes" / env.name;
            const fs::path aglod = dir / "scene.aglod";
            if (!fs::exists(aglod)) {
                fs::create_directories(dir, ec);
                std::vector<InputObject> objs;
                if (env.name == "forest3d") objs = samples::makeForest(o.seed);
                else if (env.name == "village3d") objs = samples::makeVillage(o.seed);
                else objs = samples::makeRandomScene(1000, 100000, o.seed);
                const fs::path glb = dir / "scene.glb";
                if (!io::writeObjectsGlb(objs, glb.string(), error)) {
                    std::fprintf(stderr, "aggrelod: error: %s: %s\n", glb.string().c_str(), error.c_str());
                    return 2;
                }
                if (!o.quiet) std::fprintf(stderr, "reproduce-planning: baking %s (%zu objects)\n", env.name.c_str(), objs.size());
                const std::string cmd = quoteShell(self.string()) + " bake " + quoteShell(glb.string()) + " -o " +
                                        quoteShell(dir.string()) + " --bundles 0 --quiet";
                if (std::system(cmd.c_str()) != 0 || !fs::exists(aglod)) {
                    std::fprintf(stderr, "aggrelod: error: %s: the bake failed\n", env.name.c_str());
                    return 3;
                }
            }
            if (!loadPlanScene(aglod.string(), env.radius, 0, {}, scene, error)) {
                std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
                return 2;
            }
            for (uint32_t n = 0; n < scene.file->nodeCount(); ++n) objects += scene.file->isLeaf(n) ? 1 : 0;
        }
        const planning::PlanningWorld& w = *scene.world;
        const auto queries = makeQueries(w, o.queries, o.seed * 7919u + uint32_t(env.name.size()));

        std::vector<std::pair<planning::Strategy, int>> strategies = {{planning::Strategy::Originals, 0},
                                                                      {planning::Strategy::Hierarchy, 0}};
        for (int l = 1; l < w.levelCount(); ++l) strategies.push_back({planning::Strategy::FixedLevel, l});
        std::vector<Row> rows(strategies.size());
        std::vector<std::vector<double>> lengths(strategies.size(), std::vector<double>(queries.size(), NAN));
        std::vector<std::vector<planning::PlanResult>> results(strategies.size());
        for (size_t qi = 0; qi < queries.size(); ++qi) {
            if (progress) std::fprintf(stderr, "\r[%s] query %zu/%zu ", env.name.c_str(), qi + 1, queries.size());
            for (size_t si = 0; si < strategies.size(); ++si) {
                planning::PlanRequest r;
                r.start = queries[qi].first;
                r.goal = queries[qi].second;
                r.strategy = strategies[si].first;
                r.fixedLevel = strategies[si].second;
                r.timeLimit = o.timeLimit;
                r.seed = o.seed + uint32_t(qi);
                planning::PlanResult res = planning::plan(w, r);
                Row& row = rows[si];
                row.strategy = planning::strategyName(r.strategy, r.strategy == planning::Strategy::FixedLevel
                                                                      ? w.levelNumber(r.fixedLevel)
                                                                      : 0);
                ++row.queries;  // a fixed level whose ends are not free counts as a failure
                if (res.solved()) {
                    ++row.solved;
                    row.seconds.push_back(res.seconds);
                    row.checks.push_back(double(res.collisionChecks()));
                    row.vertices.push_back(double(res.roadmapVertices));
                    lengths[si][qi] = res.pathLength;
                }
                if (qi == 0 && r.strategy == planning::Strategy::Hierarchy) results[si].push_back(std::move(res));
            }
        }
        if (progress) std::fprintf(stderr, "\n");
        for (size_t qi = 0; qi < queries.size(); ++qi) {
            double best = INFINITY;
            for (size_t si = 0; si < strategies.size(); ++si)
                if (lengths[si][qi] == lengths[si][qi]) best = std::min(best, lengths[si][qi]);
            for (size_t si = 0; si < strategies.size(); ++si)
                if (lengths[si][qi] == lengths[si][qi] && best > 0) rows[si].lengthRatio.push_back(lengths[si][qi] / best);
        }
        for (const Row& row : rows) {
            const double rate = row.queries ? double(row.solved) / row.queries : 0;
            auto cell = [](double v, int d) { return v == v ? fixed(v, d) : std::string("-"); };
            md += "| " + env.name + " | " + std::to_string(objects) + " | " + std::to_string(w.levelCount() - 1) + " | " +
                  fixed(w.radius(), 4) + " | " + row.strategy + " | " + std::to_string(row.queries) + " | " +
                  fixed(100 * rate, 0) + " % | " + cell(quantile(row.seconds, 0.5), 4) + " | " +
                  cell(quantile(row.seconds, 0.9), 4) + " | " + cell(quantile(row.lengthRatio, 0.5), 3) + " | " +
                  cell(quantile(row.checks, 0.5), 0) + " | " + cell(quantile(row.vertices, 0.5), 0) + " |\n";
            csv += env.name + "," + std::to_string(objects) + "," + std::to_string(w.levelCount() - 1) + "," +
                   fixed(w.radius(), 6) + "," + row.strategy + "," + std::to_string(row.queries) + "," +
                   std::to_string(row.solved) + "," + fixed(rate, 4) + "," + cell(quantile(row.seconds, 0.5), 6) + "," +
                   cell(quantile(row.seconds, 0.9), 6) + "," + cell(quantile(row.lengthRatio, 0.5), 4) + "," +
                   cell(quantile(row.checks, 0.5), 0) + "," + cell(quantile(row.vertices, 0.5), 0) + "\n";
        }
        // Hierarchy against originals.
        const Row& orig = rows[0];
        const Row& hier = rows[1];
        const double speedup = quantile(orig.seconds, 0.5) / quantile(hier.seconds, 0.5);
        summary += "| " + env.name + " | " + fixed(100.0 * orig.solved / std::max(1, orig.queries), 0) + " % | " +
                   fixed(100.0 * hier.solved / std::max(1, hier.queries), 0) + " % | " +
                   fixed(quantile(orig.seconds, 0.5), 4) + " | " + fixed(quantile(hier.seconds, 0.5), 4) + " | " +
                   (speedup == speedup ? fixed(speedup, 2) + "x" : std::string("-")) + " | " +
                   fixed(quantile(orig.checks, 0.5), 0) + " | " + fixed(quantile(hier.checks, 0.5), 0) + " |\n";
        for (size_t si = 0; si < strategies.size(); ++si)
            for (const planning::PlanResult& res : results[si]) {
                const fs::path png = fs::path(o.outDir) / ("fig7-" + env.name + ".png");
                if (!writePlanPicture(scene, res, png.string(), false, env.name, error))
                    std::fprintf(stderr, "aggrelod: warning: %s\n", error.c_str());
            }
        if (!o.quiet)
            std::fprintf(stderr, "reproduce-planning: %s: originals %d/%d solved, hierarchy %d/%d, median %.4f s vs %.4f s\n",
                         env.name.c_str(), orig.solved, orig.queries, hier.solved, hier.queries,
                         quantile(orig.seconds, 0.5), quantile(hier.seconds, 0.5));
    }
    const std::string header = "# Motion planning with the aggregation hierarchy\n\n`aggrelod reproduce-planning` with " +
                               std::to_string(o.queries) + " queries per environment, time limit " + fixed(o.timeLimit, 2) +
                               " s per query and strategy, seed " + std::to_string(o.seed) +
                               ". Planner: OMPL LazyPRM, one thread. Times are wall seconds to the first solution (solved "
                               "queries only).\n\n## Hierarchy against originals\n\n| environment | success originals | "
                               "success hierarchy | median s originals | median s hierarchy | speed-up (median) | median "
                               "checks originals | median checks hierarchy |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
    std::string error;
    if (!io::writeTextFile((fs::path(o.outDir) / "planning.md").string(),
                           header + summary + "\n## Every strategy\n\n" + md, error) ||
        !io::writeTextFile((fs::path(o.outDir) / "planning.csv").string(), csv, error)) {
        std::fprintf(stderr, "aggrelod: error: %s\n", error.c_str());
        return 2;
    }
    if (!o.quiet) std::printf("%s", (header + summary).c_str());
    return 0;
}

}  // namespace aggrelod::cli
