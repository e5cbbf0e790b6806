// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the motion-planning subcommands (plan, reproduce-planning), paper Section 4.3.
// Options are declared in main.cpp (the only CLI11 user); the work is done in
// plan_command.cpp and reproduce_planning_command.cpp.
#pragma once

#include <aggrelod/planning.h>

#include <memory>
#include <string>
#include <vector>

namespace aggrelod::runtime {
class RuntimeFile;
}

namespace aggrelod::cli {

struct PlanOptions {
    std::string input;                 ///< scene.aglod (3D), aggregate2d's levels GeoJSON, or 2D polygons (.wkt, .geojson, .json)
    std::string originalsPath;         ///< aggregate2d GeoJSON: the polygons aggregate2d read (required)
    std::string linksPath;             ///< aggregate2d GeoJSON: its link table (optional; checked against it)
    std::vector<double> from, to;      ///< x,y or x,y,z
    double radius = 0;                 ///< agent radius, scene units, > 0
    std::string strategy = "hierarchy";  ///< hierarchy | originals | level:K
    double timeLimit = 10;             ///< seconds
    unsigned seed = 1;
    int levelSamples = 500;            ///< hierarchy: new roadmap vertices per level before descending
    int levels = 0;                    ///< 2D polygon input: automatic levels of the in-process aggregation (0: 6)
    std::vector<double> deltas;        ///< 2D polygon input: explicit thresholds
    std::string pngPath, svgPath, statsPath;
    bool quiet = false;
};
/// Exit code: 0 solved, 3 no path within the time limit, 1 bad request (start / goal outside
/// the scene or in an obstacle, radius <= 0, wrong number of coordinates, unknown strategy),
/// 2 file problem (unreadable, wrong kind).
int runPlan(const PlanOptions& options);

struct ReproducePlanningOptions {
    std::string outDir;
    int queries = 100;       ///< random start / goal pairs per environment
    double timeLimit = 2;    ///< seconds per query and strategy
    unsigned seed = 1;
    std::string only;        ///< comma-separated environment names; empty = all eight
    bool quiet = false;
};
int runReproducePlanning(const ReproducePlanningOptions& options);

// ---- shared by both commands (plan_command.cpp) ----------------------------------------

/// A loaded planning problem: the world plus what the picture needs.
struct PlanScene {
    std::unique_ptr<runtime::RuntimeFile> file;               ///< 3D only
    std::vector<planning::PlanPolygon> originals2D;           ///< 2D only
    std::vector<std::vector<planning::PlanPolygon>> levels2D; ///< 2D only, ascending delta
    std::unique_ptr<planning::PlanningWorld> world;
    std::string description;                                  ///< what was read, for the summary line
    std::vector<std::string> notes;                           ///< e.g. input features in no aggregate
    ~PlanScene();
    PlanScene();
    PlanScene(PlanScene&&) noexcept;
};

/// Reads `path` and builds the world for `radius`:
///  - .aglod: 3D runtime file;
///  - .geojson/.json written by `aggrelod aggregate2d`: its levels as they are, the originals
///    from `originalsPath` (required), checked (every aggregate contains its sources) and, when
///    `linksPath` is given, checked against its link table;
///  - other .wkt/.geojson/.json: 2D polygons aggregated here with `levels` automatic levels (0: 6)
///    or the explicit `deltas`.
/// Returns false with a message (wrong kind, unreadable, mismatched, not containing, radius <= 0).
bool loadPlanScene(const std::string& path, double radius, int levels, const std::vector<double>& deltas,
                   PlanScene& out, std::string& error, const std::string& originalsPath = "",
                   const std::string& linksPath = "");

/// Builds a world on 2D polygons already in memory.
bool makePlanScene2D(std::vector<planning::PlanPolygon> originals, std::vector<std::vector<planning::PlanPolygon>> levels,
                     const std::vector<double>& deltas, double radius, PlanScene& out, std::string& error);

/// Fig. 7-style picture: obstacles (2D: originals filled, the first level used outlined; 3D: the
/// originals seen from above), the roadmap coloured by the level each edge was added at, the
/// path on top. `svg` selects SVG text instead of PNG. Returns false with a message.
bool writePlanPicture(const PlanScene& scene, const planning::PlanResult& result, const std::string& path, bool svg,
                      const std::string& title, std::string& error);

/// The --stats JSON of one query.
std::string formatPlanStatsJson(const PlanScene& scene, const planning::PlanResult& result,
                                const planning::PlanRequest& request);

}  // namespace aggrelod::cli
