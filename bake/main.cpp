// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod: the command-line tool. The only translation unit that includes CLI11.
//
// Exit codes: 0 success, 1 usage error, 2 input or output file problem,
// 3 baking failed (nothing written), 4 internal error.
//
// Each subcommand has an options struct, an add<Name>Command() that declares its
// options, and a run<Name>() that does the work; add new subcommands the same way.
#include "runtime_export.h"
#include "commands_2d.h"
#include "commands_render.h"
#include "output_set.h"
#ifdef AGGRELOD_HAVE_PLANNING
#include "commands_plan.h"
#endif
#include "scene_io.h"
#include "terminal.h"
#include "tile_cache.h"
#include "tiles_export.h"

#include <aggrelod/collision.h>
#include <aggrelod/collision_shapes.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/tiled_bake_3d.h>

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <system_error>
#include <vector>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <dirent.h>
#include <fcntl.h>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sys/stat.h>
#include <unistd.h>

#ifndef AGGRELOD_VERSION
#define AGGRELOD_VERSION "unknown"
#endif

namespace {

using namespace aggrelod;
namespace fs = std::filesystem;

enum ExitCode { kOk = 0, kUsage = 1, kFileError = 2, kBakeFailed = 3, kInternal = 4 };

void printError(const std::string& message) {
    std::fprintf(stderr, "aggrelod: error: %s\n", message.c_str());
}

/// Hands the pages of freed memory back to the system between the bake's stages. glibc keeps
/// them (in every thread's arena), while the next stage's large blocks come from new pages:
/// without this, the peak is what every stage ever held, not what one holds.
void releaseFreedMemory() {
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

// ---------------------------------------------------------------------------
// The output set of a bake (OutputSet, its manifest and the clean-up of killed bakes): output_set.cpp.

/// Two paths naming the same file (or the same place, when one does not exist yet).
bool samePlace(const fs::path& a, const fs::path& b) {
    std::error_code ec1, ec2;
    if (fs::exists(a, ec1) && fs::exists(b, ec2)) {
        std::error_code ec;
        if (fs::equivalent(a, b, ec)) return true;
    }
    std::error_code ec;
    const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec1);
    const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec2);
    return !ec1 && !ec2 && ca == cb;
}

/// `inner` lies inside the folder `outer`.
bool inside(const fs::path& inner, const fs::path& outer) {
    std::error_code ec, ec1, ec2;
    const std::string ci = fs::weakly_canonical(fs::absolute(inner, ec), ec1).string();
    const std::string co = (fs::weakly_canonical(fs::absolute(outer, ec), ec2) / "").string();
    return !ec1 && !ec2 && ci.compare(0, co.size(), co) == 0;
}

// ---------------------------------------------------------------------------
// bake

struct BakeOptions {
    std::string scene;
    std::string outDir;
    std::vector<double> deltas;
    int levels = 8;
    std::string function = "adaptive";  ///< adaptive | constant
    std::string distance = "exact";     ///< exact | cdt
    std::string exclude;
    std::string objectUnit = "node";    ///< node | subtree
    std::string statsPath;
    double touchTolerance = -1;
    int threads = 0;
    double proxyError = 0.25;
    int bundles = 16;
    bool tiles = false;
    bool collision = false;
    bool constantBaseline = false;
    bool quiet = false;
    std::string solidify = "wrap";      ///< wrap | hull | off
    double wrapOffset = -1;             ///< < 0: automatic
    std::string support = "auto";       ///< auto | none | a regex on object names
    int objectDepth = -1;               ///< >= 0: each node at this depth, with its subtree, is one object
    bool includeAnimated = false;
    bool allowExternalUris = false;
    std::string tileSize;               ///< empty: untiled; "auto" or a length: tiled bake
    std::string tileCache;              ///< folder of the tiled bake's pieces (incremental rebake)
    std::string tileTask;               ///< one piece only: plan, graph:N, cell:N, parent:J:ROW:COLUMN
};

/// The settings that shape the outputs, as canonical text (hashed into scene.aglod so that an
/// engine can tell a stale bake). Thread count and verbosity are left out: they change nothing.
std::string settingsText(const BakeOptions& o) {
    char buffer[64];
    std::string text = "aggrelod-bake;function=" + o.function + ";distance=" + o.distance + ";levels=" +
                       std::to_string(o.levels) + ";object=" + o.objectUnit + ";exclude=" + o.exclude + ";deltas=";
    for (double d : o.deltas) {
        std::snprintf(buffer, sizeof buffer, "%.17g,", d);
        text += buffer;
    }
    std::snprintf(buffer, sizeof buffer, ";touch=%.17g;proxy=%.17g", o.touchTolerance, o.proxyError);
    text += buffer;
    std::snprintf(buffer, sizeof buffer, ";wrapoffset=%.17g;depth=%d;animated=%d", o.wrapOffset, o.objectDepth,
                  o.includeAnimated ? 1 : 0);
    text += ";solidify=" + o.solidify + ";support=" + o.support + buffer;
    if (!o.tileSize.empty()) text += ";tile=" + o.tileSize;  // only when tiled: untiled hashes stay as they were
    text += ";bundles=" + std::to_string(o.bundles);
    return text;
}

CLI::App* addBakeCommand(CLI::App& app, BakeOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "bake", "Bake a glTF scene (.glb or .gltf) into a level-of-detail hierarchy of aggregates");
    cmd->add_option("scene", o.scene, "Input scene, .glb or .gltf")->required();
    cmd->add_option("-o,--output", o.outDir,
                    "Output directory (created if missing); receives levels.glb, proxies.glb and scene.aglod (the runtime file)")
        ->required();
    CLI::Option* delta =
        cmd->add_option("--delta", o.deltas,
                        "Explicit thresholds, comma-separated, in scene units (e.g. 0.5,1,2)")
            ->delimiter(',')
            ->allow_extra_args(false);
    CLI::Option* levels =
        cmd->add_option("--levels", o.levels, "Number of automatic levels (default 8)")
            ->check(CLI::Range(1, 1000));
    delta->excludes(levels);
    cmd->add_option("--function", o.function, "Aggregate function: adaptive (default) or constant")
        ->transform(CLI::IsMember({"adaptive", "constant"}, CLI::ignore_case));
    cmd->add_option("--distance", o.distance,
                    "Distance between objects: exact (default, mesh to mesh) or cdt "
                    "(shortest triangulation edge, as in the paper)")
        ->transform(CLI::IsMember({"exact", "cdt"}, CLI::ignore_case));
    cmd->add_option("--exclude", o.exclude,
                    "Leave out nodes (with their subtree) whose name or index path ('@0/3/1': root "
                    "position, then child positions) matches this ECMAScript regex, e.g. 'Ground|Sky'; "
                    "'mesh:NAME', or a name or path followed by '/mesh' (e.g. '^Terrain/mesh$'), drops "
                    "only that node's own mesh and keeps its children");
    cmd->add_option("--object", o.objectUnit,
                    "What one object is: node (default: each node with a mesh) or subtree "
                    "(each child of a scene root, with all meshes below it)")
        ->transform(CLI::IsMember({"node", "subtree"}, CLI::ignore_case));
    cmd->add_option("--object-depth", o.objectDepth,
                    "Each node at this depth below the scene roots (0 = the roots), with every mesh below it, is "
                    "one object; shallower meshes stay objects of their own (overrides --object)")
        ->check(CLI::Range(0, 1000));
    cmd->add_option("--solidify", o.solidify,
                    "What stands in for objects that are not closed solids (open, non-manifold, self-intersecting, "
                    "touching): wrap (default: the exact union of touching closed solids, open sheets thickened into a shell, else a tight "
                    "watertight alpha wrap), hull (convex hull) or off (left out)")
        ->transform(CLI::IsMember({"wrap", "hull", "off"}, CLI::ignore_case));
    cmd->add_option("--wrap-offset", o.wrapOffset,
                    "Distance of the wrap (or the shell's surface) from the original surface, in scene units (default: "
                    "automatic, see docs/real-art.md)")
        ->check(CLI::PositiveNumber);
    cmd->add_option("--support", o.support,
                    "Support surfaces (ground, terrain, sky, roads, room shell) kept out of aggregation and passed "
                    "through: auto (default, documented rule), none, or an ECMAScript regex on object names");
    cmd->add_flag("--include-animated", o.includeAnimated,
                  "Bake animated and skinned nodes at their rest pose (default: left out and listed)");
    cmd->add_flag("--allow-external-uris", o.allowExternalUris,
                  "Let buffer uris name files outside the input's folder (refused by default)");
    cmd->add_option("--tile-size", o.tileSize,
                    "Tiled bake for large worlds: cells of this side (scene units) baked one at a time for the levels "
                    "up to an eighth of it, a quadtree of parent cells above; 'auto' tiles worlds of over 4,000 "
                    "objects into cells of about 2,000 (default: one piece; see docs/command-line.md)")
        ->check([](const std::string& v) -> std::string {
            if (v == "auto") return {};
            char* end = nullptr;
            const double d = std::strtod(v.c_str(), &end);
            if (end == v.c_str() || *end != '\0' || !(d > 0) || !std::isfinite(d)) return "expects 'auto' or a length > 0";
            return {};
        });
    cmd->add_option("--tile-cache", o.tileCache,
                    "Keep the result of every piece of a tiled bake in this folder and read it back when the "
                    "piece's input did not change: a rebake redoes only the cells that changed and their parents "
                    "(needs --tile-size)");
    cmd->add_option("--tile-task", o.tileTask,
                    "Bake one piece of a tiled bake into --tile-cache and write no outputs: plan (print the pieces "
                    "as JSON), graph:N, cell:N, parent:J:ROW:COLUMN, or proxies:PHASE:PART:PARTS (share PART of "
                    "PARTS of the proxies' phase 1 or 2, after every other piece); what aggrelod-farm runs on its "
                    "workers");
    cmd->add_option("--stats", o.statsPath, "Write the figures of every level and stage to this JSON file");
    cmd->add_flag("--constant-baseline", o.constantBaseline,
                  "Also measure the constant function (paper Eq. 1) at the same groups: volume_constant and "
                  "added_volume_constant in the stats (one more carving per level; off by default)");
    cmd->add_option("--touch-tolerance", o.touchTolerance,
                    "Objects closer than this are one model (default: 1e-6 x scene diagonal)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--threads", o.threads, "Threads for the parallel stages (default 0: all cores); output is identical for any count")
        ->check(CLI::Range(0, 1024));
    cmd->add_option("--proxy-error", o.proxyError,
                    "Room each level's proxies get above their exact aggregate's certified error, as a "
                    "fraction of the level's delta (default 0.25; 0 keeps the exact aggregates)")
        ->check(CLI::Range(0.0, 10.0));
    cmd->add_option("--bundles", o.bundles,
                    "Most bundles below each group: its children's versions merged into one mesh, so that a distant "
                    "group is one draw call (default 16; 0: none)")
        ->check(CLI::Range(0, 64));
    cmd->add_flag("--tiles", o.tiles,
                  "Also write OUTDIR/tiles/: a 3D Tiles 1.1 tileset (tileset.json, one GLB per hierarchy node) "
                  "for CesiumJS or 3DTilesRendererJS");
    cmd->add_flag("--collision", o.collision,
                  "Also write OUTDIR/collision.glb: static collision shapes per hierarchy node for physics engines "
                  "(KHR_physics_rigid_bodies and OMI_physics_body/OMI_physics_shape: triangle meshes of the proxies and, "
                  "where it fits the node's error, a convex hull per shell; one scene per level)");
    cmd->add_flag("-q,--quiet", o.quiet, "No progress, notes, warnings or table (errors only)");
    return cmd;
}

/// Writes the 3D Tiles tileset into the fresh folder `dir`.
bool writeTilesInto(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, const fs::path& dir,
                    io::TilesetSummary& summary, std::string& error) {
    std::error_code ec;
    fs::create_directory(dir, ec);
    if (ec) {
        error = dir.string() + ": cannot create: " + ec.message();
        return false;
    }
    return io::writeTileset(nodes, objects, dir.string(), summary, error);
}

struct CollisionSummary {
    size_t colliders = 0, convexNodes = 0, convexParts = 0, scenes = 0;
    double largestConvexError = 0;
};

/// Writes collision.glb: its scenes are the cuts of the runtime file just written (every
/// aggregate level, the per-object LODs when there are any, the originals), taken with the
/// runtime's own cutAtLevel.
bool writeCollisionInto(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                        const std::vector<NodeCollisionShapes>& shapes, const fs::path& runtimeFile, const fs::path& path,
                        CollisionSummary& summary, std::string& error) {
    runtime::RuntimeFile file;
    std::string message;
    const runtime::FileStatus status = runtime::RuntimeFile::openFile(runtimeFile.string(), file, message);
    if (status != runtime::FileStatus::Ok) {
        error = runtimeFile.string() + ": " + runtime::toString(status) + ": " + message;
        return false;
    }
    // The aggregate levels first, finest first (the default scene is the first), then the
    // per-object LODs and the originals.
    std::vector<io::CollisionCut> cuts;
    for (uint32_t level : runtime::levelsOf(file)) {
        cuts.push_back({"level" + std::to_string(level), {}});
        runtime::cutAtLevel(file, level, cuts.back().nodes);
    }
    bool anyObjectLod = false;
    for (uint32_t i = 0; i < file.nodeCount(); ++i) anyObjectLod = anyObjectLod || file.isObjectLod(i);
    if (anyObjectLod) {
        cuts.push_back({"object_lods", {}});
        runtime::cutAtLevel(file, runtime::kObjectLodLevel, cuts.back().nodes);
    }
    cuts.push_back({"originals", {}});
    runtime::cutAtLevel(file, runtime::kLeafLevel, cuts.back().nodes);
    if (!io::writeCollisionGlb(nodes, objects, shapes, cuts, path.string(), error)) return false;
    summary.scenes = 2 * cuts.size() + 1;
    for (size_t i = 0; i < nodes.nodes.size(); ++i) {
        if (nodeTriangleCount(nodes.nodes[i]) == 0) continue;
        ++summary.colliders;
        if (shapes[i].convexParts.empty()) continue;
        ++summary.convexNodes;
        summary.convexParts += shapes[i].convexParts.size();
        summary.largestConvexError = std::max(summary.largestConvexError, shapes[i].convexError);
    }
    return true;
}

int runBake(BakeOptions o) {
    for (double d : o.deltas) {
        if (!std::isfinite(d) || d < 0) {
            printError("--delta: every threshold must be a finite number >= 0");
            return kUsage;
        }
    }
    if (!std::isfinite(o.touchTolerance) || (o.touchTolerance < 0 && o.touchTolerance != -1)) {
        printError("--touch-tolerance: must be a finite number >= 0");
        return kUsage;
    }
    if ((!o.tileCache.empty() || !o.tileTask.empty()) && o.tileSize.empty()) {
        printError(std::string(o.tileCache.empty() ? "--tile-task" : "--tile-cache") + " needs --tile-size");
        return kUsage;
    }
    if (!o.tileTask.empty() && o.tileTask != "plan" && o.tileCache.empty()) {
        printError("--tile-task " + o.tileTask + " needs --tile-cache (the folder its result goes to)");
        return kUsage;
    }
    std::sort(o.deltas.begin(), o.deltas.end());
    o.deltas.erase(std::unique(o.deltas.begin(), o.deltas.end()), o.deltas.end());
    if (!o.exclude.empty()) {
        try {
            std::regex check(o.exclude, std::regex::ECMAScript);
        } catch (const std::regex_error& e) {
            printError("--exclude: invalid regular expression '" + o.exclude + "': " + e.what());
            return kUsage;
        }
    }

    const bool supportRegex = o.support != "auto" && o.support != "none";
    std::regex support;
    if (supportRegex) {
        try {
            support = std::regex(o.support, std::regex::ECMAScript);
        } catch (const std::regex_error& e) {
            printError("--support: invalid regular expression '" + o.support + "': " + e.what());
            return kUsage;
        }
    }

    // No output may overwrite the input or another output: checked before anything is read.
    {
        const fs::path outDir(o.outDir);
        std::vector<std::pair<std::string, fs::path>> outputs = {
            {"levels.glb", outDir / "levels.glb"}, {"proxies.glb", outDir / "proxies.glb"}, {"scene.aglod", outDir / "scene.aglod"},
            {io::kSetManifestName, outDir / io::kSetManifestName}};
        if (o.collision) outputs.emplace_back("collision.glb", outDir / "collision.glb");
        if (!o.statsPath.empty()) outputs.emplace_back("--stats", fs::path(o.statsPath));
        for (size_t i = 0; i < outputs.size(); ++i) {
            if (samePlace(outputs[i].second, o.scene)) {
                printError("output " + outputs[i].second.string() + " (" + outputs[i].first + ") is the input " +
                           o.scene + ": it would be overwritten; choose another output");
                return kUsage;
            }
            for (size_t j = 0; j < i; ++j)
                if (samePlace(outputs[i].second, outputs[j].second)) {
                    printError("outputs " + outputs[j].first + " and " + outputs[i].first + " are the same file " +
                               outputs[i].second.string());
                    return kUsage;
                }
        }
        if (o.tiles && (inside(o.scene, outDir / "tiles") ||
                        (!o.statsPath.empty() && inside(fs::path(o.statsPath), outDir / "tiles")))) {
            printError(outDir.string() + "/tiles is replaced whole by --tiles: the input and --stats must lie outside it");
            return kUsage;
        }
    }

    // A bake into this OUTDIR killed while moving its outputs: its old set comes back first.
    {
        std::error_code ec;
        if (fs::is_directory(o.outDir, ec)) io::removeStaleTemporaries(o.outDir);
    }

    // Read.
    io::SceneReadOptions readOptions;
    readOptions.excludeRegex = o.exclude;
    readOptions.objectUnit = o.objectUnit == "subtree" ? io::ObjectUnit::Subtree : io::ObjectUnit::Node;
    readOptions.objectDepth = o.objectDepth;
    readOptions.includeAnimated = o.includeAnimated;
    readOptions.allowExternalUris = o.allowExternalUris;
    io::SceneReadResult scene;
    std::string error;
    if (!io::readGltfScene(o.scene, readOptions, scene, error)) {
        printError(error);
        return kFileError;
    }
    // Nor an external buffer file of the input (known once the input is parsed).
    for (const std::string& buffer : scene.externalFiles) {
        const fs::path outDir(o.outDir);
        for (const fs::path& output : {outDir / "levels.glb", outDir / "proxies.glb", outDir / "scene.aglod",
                                       outDir / io::kSetManifestName, fs::path(o.statsPath),
                                       o.collision ? outDir / "collision.glb" : fs::path()}) {
            if (output.empty() || !samePlace(output, buffer)) continue;
            printError("output " + output.string() + " is the buffer file " + buffer + " of the input " + o.scene +
                       ": it would be overwritten; choose another output");
            return kUsage;
        }
        if (o.tiles && inside(buffer, outDir / "tiles")) {
            printError(outDir.string() + "/tiles is replaced whole by --tiles: the input's buffer file " + buffer +
                       " must lie outside it");
            return kUsage;
        }
    }
    cli::printDiagnostics(scene.diagnostics, o.quiet);
    if (scene.objects.empty()) {
        printError(o.scene + ": no objects to aggregate (all excluded or none with triangles)");
        return kFileError;
    }

    // A tiled bake's cache and piece (--tile-cache, --tile-task).
    TiledBakeOptions tiling;
    TileCache tileCache;
    ProxyShare proxyShare;
    if (!o.tileSize.empty()) tiling.tileSize = o.tileSize == "auto" ? 0.0 : std::strtod(o.tileSize.c_str(), nullptr);
    if (!o.tileCache.empty()) {
        tileCache = io::folderTileCache(o.tileCache);
        tiling.cache = &tileCache;
    }
    // One piece, or a comma-separated list of graph, cell and parent pieces (one read of the
    // scene for all of them: aggrelod-farm hands a worker a batch).
    std::vector<TileTask> tileTasks;
    if (!o.tileTask.empty()) {
        const auto parseTask = [&](const std::string& text, TileTask& t) {
            unsigned long a = 0, b = 0, c = 0;
            char tail = 0;
            if (text == "plan") {
                t.kind = TileTask::Kind::Plan;
            } else if (std::sscanf(text.c_str(), "graph:%lu%c", &a, &tail) == 1 && a <= UINT32_MAX) {
                t.kind = TileTask::Kind::Graph;
                t.cell = static_cast<uint32_t>(a);
            } else if (std::sscanf(text.c_str(), "cell:%lu%c", &a, &tail) == 1 && a <= UINT32_MAX) {
                t.kind = TileTask::Kind::Cell;
                t.cell = static_cast<uint32_t>(a);
            } else if (std::sscanf(text.c_str(), "parent:%lu:%lu:%lu%c", &a, &b, &c, &tail) == 3 && a >= 1 && a <= 64 &&
                       b <= UINT32_MAX && c <= UINT32_MAX) {
                t.kind = TileTask::Kind::Parent;
                t.level = static_cast<int>(a);
                t.row = static_cast<uint32_t>(b);
                t.column = static_cast<uint32_t>(c);
            } else if (std::sscanf(text.c_str(), "proxies:%lu:%lu:%lu%c", &a, &b, &c, &tail) == 3 && (a == 1 || a == 2) &&
                       c >= 1 && c <= UINT32_MAX && b < c) {
                t.kind = TileTask::Kind::Assemble;  // the whole hierarchy from the cache, then the share
                tiling.leanMeshes = true;           // which reads again the meshes of its own items only
                proxyShare.phase = static_cast<int>(a);
                proxyShare.part = static_cast<uint32_t>(b);
                proxyShare.parts = static_cast<uint32_t>(c);
            } else {
                return false;
            }
            return true;
        };
        bool valid = true;
        for (size_t start = 0; valid;) {
            const size_t comma = o.tileTask.find(',', start);
            TileTask t;
            valid = parseTask(o.tileTask.substr(start, comma == std::string::npos ? std::string::npos : comma - start), t);
            tileTasks.push_back(t);
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        if (valid && tileTasks.size() > 1)
            for (const TileTask& t : tileTasks)
                valid = valid && (t.kind == TileTask::Kind::Graph || t.kind == TileTask::Kind::Cell || t.kind == TileTask::Kind::Parent);
        if (!valid || tileTasks.size() > (size_t(1) << 20)) {
            printError("--tile-task " + o.tileTask +
                       ": expects plan, graph:N, cell:N, parent:J:ROW:COLUMN or proxies:PHASE:PART:PARTS "
                       "(PHASE 1 or 2, PART below PARTS), or a comma-separated list of graph, cell and parent pieces");
            return kUsage;
        }
        tiling.task = tileTasks.front();
        // The world's layout (support surfaces, grid, clusters) once for the whole list.
        if (tileTasks.size() > 1) tiling.layout = newTiledLayout();
    }
    // Bake.
    cli::ProgressLine progress(!o.quiet && cli::stderrIsTerminal());
    Settings3D settings;
    settings.deltas = o.deltas;
    settings.automaticLevelCount = o.levels;
    settings.function = o.function == "constant" ? AggregateFunctionKind::Constant
                                                 : AggregateFunctionKind::Adaptive;
    settings.distance = o.distance == "cdt" ? DistanceMode::Cdt : DistanceMode::Exact;
    settings.touchTolerance = o.touchTolerance;
    settings.threadCount = o.threads;
    settings.computeConstantBaseline = o.constantBaseline;
    settings.solidify = o.solidify == "hull" ? SolidifyMethod::Hull
                        : o.solidify == "off" ? SolidifyMethod::Off
                                              : SolidifyMethod::Wrap;
    settings.wrapOffset = o.wrapOffset;
    settings.support = o.support == "none" ? SupportDetection::None
                       : supportRegex      ? SupportDetection::Given
                                           : SupportDetection::Automatic;
    if (supportRegex) {
        for (uint32_t i = 0; i < scene.objects.size(); ++i) {
            std::string name = scene.objects[i].name;
            if (name.size() > 1024) name.resize(1024);  // as --exclude: bounded regex recursion
            if (std::regex_search(name, support)) settings.supportObjects.push_back(i);
        }
        if (settings.supportObjects.empty() && !o.quiet)
            std::fprintf(stderr, "note: --support '%s' matched no object\n", o.support.c_str());
    }
    settings.progress = [&progress](const char* stage, double fraction) {
        progress.update(stage, fraction);
    };
    // Proxies, their errors and the node tree for the runtime (docs/design.md §2.6); with a
    // tile cache, each of their work items is kept there too.
    ProxySettings proxySettings;
    proxySettings.simplifyFraction = o.proxyError;
    proxySettings.bundleCount = o.bundles;
    proxySettings.threadCount = o.threads;
    proxySettings.progress = settings.progress;
    proxySettings.cache = tiling.cache;
    proxySettings.leavesByReference = true;  // the originals are held once, in scene.objects
    Hierarchy3D hierarchy;
    TiledBakeReport tiled;
    if (!o.tileTask.empty()) {  // pieces: into the cache, no outputs
        bool done = true;
        std::string shareError;
        size_t made = 0, loaded = 0;
        const bool proxies = tiling.task.kind == TileTask::Kind::Assemble;
        for (const TileTask& task : tileTasks) {
            tiling.task = task;
            Hierarchy3D piece;
            done = buildTiledHierarchy3D(scene.objects, settings, tiling, piece, &tiled);
            if (done && proxies) {
                releaseFreedMemory();
                done = buildProxyShare(piece, scene.objects, proxySettings, proxyShare, shareError, &made, &loaded);
            } else {
                made += tiled.graphsBaked + tiled.cellsBaked + tiled.parentsBaked;
                loaded += tiled.graphsLoaded + tiled.cellsLoaded + tiled.parentsLoaded;
            }
            for (Diagnostic& d : piece.diagnostics) {  // once each, however many pieces say it
                const bool said = std::any_of(hierarchy.diagnostics.begin(), hierarchy.diagnostics.end(), [&](const Diagnostic& e) {
                    return e.severity == d.severity && e.object == d.object && e.message == d.message;
                });
                if (!said) hierarchy.diagnostics.push_back(std::move(d));
            }
            if (!done) break;
        }
        progress.finish();
        cli::printDiagnostics(hierarchy.diagnostics, o.quiet);
        if (!done) {
            printError(o.scene + ": tile task " + o.tileTask + " failed" + (shareError.empty() ? "" : ": " + shareError));
            return kBakeFailed;
        }
        if (tiling.task.kind == TileTask::Kind::Plan) {
            std::printf("%s\n", io::tilePlanJson(tiled).c_str());
        } else if (!o.quiet) {
            std::printf("tile task %s: %zu %s, %zu read from the cache\n", o.tileTask.c_str(), made,
                        proxies ? "proxy items made" : "pieces baked", loaded);
        }
        std::fflush(stdout);
        return kOk;
    }
    // A tiled bake whose pieces are all in the cache holds the hierarchy without its exact
    // meshes (they stay in the cache; the bounds and levels.glb read them back a run at a
    // time); otherwise it bakes what is missing and holds everything.
    bool lean = false;
    if (!o.tileSize.empty() && tiling.cache && !settings.customFunction) {
        TiledBakeOptions assemble = tiling;
        assemble.task.kind = TileTask::Kind::Assemble;
        assemble.leanMeshes = true;
        TiledBakeReport report;
        lean = buildTiledHierarchy3D(scene.objects, settings, assemble, hierarchy, &report);
        if (lean) tiled = report;
    }
    const bool ok = lean || (o.tileSize.empty() ? buildHierarchy3D(scene.objects, settings, hierarchy)
                                                : buildTiledHierarchy3D(scene.objects, settings, tiling, hierarchy, &tiled));
    // Write: the whole set into a fresh temporary folder, then switched in (OutputSet). Begun
    // before the proxies, whose meshes wait in it from the moment each is done with; declared
    // before the nodes, which close their spill file first.
    const fs::path outDir(o.outDir);
    std::optional<io::OutputSet> set;
    HierarchyNodes nodes;
    std::string nodeError;
    bool nodesOk = false;
    releaseFreedMemory();
    bool createdOutDir = false;
    std::error_code ec;
    // A bake that fails from here leaves OUTDIR as it found it (an OUTDIR it made: removed
    // when empty).
    const auto abandonOutputs = [&] {
        nodes = HierarchyNodes{};  // closes the spill file inside the set's folder
        set.reset();
        if (createdOutDir) fs::remove(outDir, ec);
    };
    if (ok) {
        createdOutDir = !fs::exists(outDir, ec);
        fs::create_directories(outDir, ec);
        if (ec || !fs::is_directory(outDir)) {
            printError(o.outDir + ": cannot create the output directory" + (ec ? ": " + ec.message() : std::string()));
            return kFileError;
        }
        set.emplace();
        if (!set->begin(outDir, error)) {
            abandonOutputs();
            printError(error);
            return kFileError;
        }
        proxySettings.meshSpillPath = set->scratchFile("node-meshes.spill").string();
        proxySettings.releaseFreedMemory = releaseFreedMemory;
    }
    if (ok) {
        const auto start = std::chrono::steady_clock::now();
        nodesOk = buildHierarchyNodes(hierarchy, scene.objects, proxySettings, nodes, nodeError);
        hierarchy.timings.emplace_back("proxies", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::vector<NodeCollisionShapes> collisionShapes;
    if (ok && nodesOk && o.collision) {
        // Convex decompositions where they fit each node's error (collision_shapes.h).
        progress.update("collision", 0.0);
        CollisionShapeSettings collisionSettings;
        collisionSettings.threadCount = o.threads;
        const auto start = std::chrono::steady_clock::now();
        nodesOk = buildCollisionShapes(nodes, scene.objects, collisionSettings, collisionShapes, nodeError);
        hierarchy.timings.emplace_back("collision", std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    progress.finish();
    releaseFreedMemory();
    cli::printDiagnostics(hierarchy.diagnostics, o.quiet);
    if (!ok) {
        printError(o.scene + ": baking failed; nothing was written");
        return kBakeFailed;
    }
    if (!nodesOk) {
        abandonOutputs();
        printError(o.scene + ": building the runtime hierarchy failed: " + nodeError + "; nothing was written");
        return kInternal;
    }

    const fs::path levelsPath = outDir / "levels.glb";
    const fs::path proxiesPath = outDir / "proxies.glb";
    const fs::path runtimePath = outDir / "scene.aglod";
    const fs::path statsPath = o.statsPath.empty() ? fs::path() : fs::path(o.statsPath);
    const auto fail = [&](const std::string& message) {
        printError(message);
        abandonOutputs();
        return kFileError;
    };
    if (!statsPath.empty() && statsPath.has_parent_path()) fs::create_directories(statsPath.parent_path(), ec);
    fs::path levelsTmp, proxiesTmp, runtimeTmp, statsTmp, collisionTmp;
    const fs::path collisionPath = outDir / "collision.glb";
    if (!set->addFile(levelsPath, levelsTmp, error) || !set->addFile(proxiesPath, proxiesTmp, error) ||
        !set->addFile(runtimePath, runtimeTmp, error) || (!statsPath.empty() && !set->addFile(statsPath, statsTmp, error)) ||
        (o.collision && !set->addFile(collisionPath, collisionTmp, error)))
        return fail(error);
    // The nodes' meshes wait on disk (ProxySettings::meshSpillPath) while the files are written,
    // each read back when written (a leaf's is its object's).
    if (!io::writeLevelsGlb(hierarchy, scene.objects, levelsTmp.string(), error, &nodes, o.threads, tiling.cache))
        return fail(error);
    // The exact aggregates' meshes are in levels.glb now and nothing after needs them (the
    // statistics keep counts): on a large world they are the largest part of what is held.
    for (Level& level : hierarchy.levels)
        for (Aggregate& a : level.aggregates) {
            std::vector<double>().swap(a.positions);
            std::vector<uint32_t>().swap(a.indices);
            std::vector<float>().swap(a.faceColors);
        }
    releaseFreedMemory();
    if (!io::writeProxiesGlb(nodes, scene.objects, proxiesTmp.string(), error, o.threads)) return fail(error);
    releaseFreedMemory();
    if (!io::writeRuntimeScene(nodes, scene.objects, io::settingsHash(settingsText(o)), AGGRELOD_VERSION,
                               runtimeTmp.string(), error, o.threads))
        return fail(error);
    CollisionSummary collision;
    if (o.collision && !writeCollisionInto(nodes, scene.objects, collisionShapes, runtimeTmp, collisionTmp, collision, error))
        return fail(error);
    io::TilesetSummary tiles;
    if (o.tiles && !writeTilesInto(nodes, scene.objects, set->folderTemporary(outDir / "tiles"), tiles, error))
        return fail(error);
    if (!statsPath.empty() &&
        !io::writeStatsJson(hierarchy, scene.objects, scene.diagnostics, statsTmp.string(), error, &nodes))
        return fail(error);
    if (!set->commit(error)) return fail(error);

    if (!o.quiet) {
        std::printf("%zu objects, %zu models, %zu triangles; originals: volume %s, sphericity %s\n",
                    scene.objects.size(), hierarchy.modelCount, hierarchy.inputTriangleCount,
                    cli::formatNumber(hierarchy.originals.volume).c_str(),
                    cli::formatNumber(hierarchy.originals.sphericity).c_str());
        std::fputs(cli::formatLevelTable(hierarchy).c_str(), stdout);
        if (tiled.tiled)
            std::printf("tiles: %zu cells and %zu parent cells baked, %zu and %zu read from %s; proxies: %zu items made, "
                        "%zu read\n",
                        tiled.cellsBaked, tiled.parentsBaked, tiled.cellsLoaded, tiled.parentsLoaded,
                        o.tileCache.empty() ? "a cache (none given)" : o.tileCache.c_str(), nodes.proxyItemsMade,
                        nodes.proxyItemsLoaded);
        size_t proxyTriangles = 0, exactTriangles = 0;
        for (size_t i = nodes.objectCount; i < nodes.nodes.size(); ++i) {
            proxyTriangles += nodeTriangleCount(nodes.nodes[i]);
            exactTriangles += nodes.nodes[i].exactTriangleCount;
        }
        std::printf("runtime hierarchy: %zu nodes (%zu aggregates, %zu roots); proxies %zu triangles "
                    "(exact aggregates %zu)\n",
                    nodes.nodes.size(), nodes.nodes.size() - nodes.objectCount, nodes.roots.size(), proxyTriangles,
                    exactTriangles);
        std::printf("wrote %s, %s, %s%s%s\n", levelsPath.string().c_str(), proxiesPath.string().c_str(),
                    runtimePath.string().c_str(),
                    statsPath.empty() ? "" : " and ", statsPath.string().c_str());
        if (o.collision) {
            std::printf("wrote %s: %zu colliders (triangle meshes), %zu nodes with a convex decomposition (%zu hulls, "
                        "largest certified hull error %s), %zu scenes\n",
                        collisionPath.string().c_str(), collision.colliders, collision.convexNodes, collision.convexParts,
                        cli::formatNumber(collision.largestConvexError).c_str(), collision.scenes);
        }
        if (o.tiles) {
            std::printf("wrote %s: %zu tiles (%zu GLB contents), tileset geometric error %s\n",
                        (outDir / "tiles" / "tileset.json").string().c_str(), tiles.tileCount, tiles.contentCount,
                        cli::formatNumber(tiles.geometricError).c_str());
        }
        std::fflush(stdout);
    }
    return kOk;
}

// ---------------------------------------------------------------------------
// inspect

struct InspectOptions {
    std::string file;
    bool noLeaves = false;
    int maxSources = 8;
};

CLI::App* addInspectCommand(CLI::App& app, InspectOptions& o) {
    CLI::App* cmd = app.add_subcommand("inspect", "Print the node tree of a runtime file (.aglod)");
    cmd->add_option("file", o.file, "Runtime file written by `aggrelod bake` (OUTDIR/scene.aglod)")->required();
    cmd->add_flag("--no-leaves", o.noLeaves, "Do not print the original objects (the leaves)");
    cmd->add_option("--max-sources", o.maxSources, "Object names printed per node (default 8; 0: all)")
        ->check(CLI::NonNegativeNumber);
    return cmd;
}

/// One node's line, indented by its depth (capped, so that a very deep tree cannot print
/// quadratic output; deeper lines say their depth).
void printInspectLine(const runtime::RuntimeFile& file, uint32_t index, size_t depth, const InspectOptions& o) {
    const runtime::NodeRecord& n = file.node(index);
    const bool leaf = n.level == runtime::kLeafLevel;
    if (leaf && o.noLeaves) return;
    constexpr size_t kMaxIndent = 32;
    std::string indent(2 * std::min(depth, kMaxIndent), ' ');
    if (depth > kMaxIndent) indent += "(depth " + std::to_string(depth) + ") ";
    const auto sources = file.sources(index);
    if (leaf) {
        std::printf("%sobject %u '%.*s'  triangles %u  sphere r %s\n", indent.c_str(), sources.empty() ? 0u : sources[0],
                    sources.empty() ? 0 : int(file.objectName(sources[0]).size()),
                    sources.empty() ? "" : file.objectName(sources[0]).data(), n.indexCount / 3,
                    cli::formatNumber(n.sphereRadius).c_str());
    } else {
        // A per-object LOD (a simplified version of one object) has no level of its own.
        const std::string level = n.level == runtime::kObjectLodLevel ? std::string("object LOD")
                                  : n.level == runtime::kCoarserLevel
                                      ? "coarser version  delta " + cli::formatNumber(n.delta)
                                  : runtime::isBundleLevel(n.level)
                                      ? "bundle of level " + std::to_string(n.level & 0xFFFFu) + "  delta " +
                                            cli::formatNumber(n.delta)
                                      : "level " + std::to_string(n.level) + "  delta " + cli::formatNumber(n.delta);
        std::printf("%snode %u  %s  error %s  triangles %u  box [%s %s %s]..[%s %s %s]  sphere r %s  "
                    "%u objects:",
                    indent.c_str(), index, level.c_str(),
                    cli::formatNumber(n.geometricError).c_str(), n.indexCount / 3,
                    cli::formatNumber(n.boundsMin[0]).c_str(), cli::formatNumber(n.boundsMin[1]).c_str(),
                    cli::formatNumber(n.boundsMin[2]).c_str(), cli::formatNumber(n.boundsMax[0]).c_str(),
                    cli::formatNumber(n.boundsMax[1]).c_str(), cli::formatNumber(n.boundsMax[2]).c_str(),
                    cli::formatNumber(n.sphereRadius).c_str(), unsigned(sources.size));
        size_t shown = 0;
        for (uint32_t s : sources) {
            if (o.maxSources > 0 && shown == size_t(o.maxSources)) {
                std::printf(" ...");
                break;
            }
            const std::string_view name = file.objectName(s);
            std::printf(" %.*s", int(name.size()), name.data());
            ++shown;
        }
        std::printf("\n");
    }
}

/// Every node below `root`, depth first, children in file order, with an explicit stack (a
/// valid file may nest hundreds of thousands of levels deep).
void printInspectTree(const runtime::RuntimeFile& file, uint32_t root, const InspectOptions& o) {
    std::vector<std::pair<uint32_t, size_t>> stack = {{root, 0}};
    while (!stack.empty()) {
        const auto [index, depth] = stack.back();
        stack.pop_back();
        printInspectLine(file, index, depth, o);
        const auto children = file.children(index);
        for (size_t c = children.size; c-- > 0;) stack.emplace_back(children[c], depth + 1);
    }
}

int runInspect(const InspectOptions& o) {
    runtime::RuntimeFile file;
    std::string message;
    const runtime::FileStatus status = runtime::RuntimeFile::openFile(o.file, file, message);
    if (status != runtime::FileStatus::Ok) {
        printError(o.file + ": " + runtime::toString(status) + (message.empty() ? "" : ": " + message));
        return kFileError;
    }
    uint32_t aggregates = 0, leaves = 0, objectLods = 0, bundles = 0;
    uint64_t proxyTriangles = 0, leafTriangles = 0, objectLodTriangles = 0, bundleTriangles = 0;
    for (const runtime::NodeRecord& n : file.nodes()) {
        if (n.level == runtime::kLeafLevel) {
            ++leaves;
            leafTriangles += n.indexCount / 3;
        } else if (n.level == runtime::kObjectLodLevel) {
            ++objectLods;
            objectLodTriangles += n.indexCount / 3;
        } else if (runtime::isBundleLevel(n.level)) {
            ++bundles;
            bundleTriangles += n.indexCount / 3;
        } else {
            ++aggregates;
            proxyTriangles += n.indexCount / 3;
        }
    }
    std::printf("%s: format %u.%u, tool %.*s, settings hash %016llx, %zu bytes\n", o.file.c_str(),
                unsigned(file.versionMajor()), unsigned(file.versionMinor()), int(file.toolVersion().size()),
                file.toolVersion().data(), static_cast<unsigned long long>(file.settingsHash()), file.byteSize());
    std::printf("%u nodes: %u aggregates (%llu proxy triangles), %u per-object LODs (%llu triangles), "
                "%u bundles (%llu triangles), %u original objects (%llu triangles); %zu roots, depth %u\n",
                file.nodeCount(), aggregates, static_cast<unsigned long long>(proxyTriangles), objectLods,
                static_cast<unsigned long long>(objectLodTriangles), bundles,
                static_cast<unsigned long long>(bundleTriangles), leaves,
                static_cast<unsigned long long>(leafTriangles), file.roots().size, file.depth());
    for (uint32_t r : file.roots()) printInspectTree(file, r, o);
    // The set the file belongs to, when a bake's manifest lies beside it and names it.
    const fs::path dir = fs::path(o.file).parent_path().empty() ? fs::path(".") : fs::path(o.file).parent_path();
    std::error_code ec;
    if (fs::exists(fs::symlink_status(dir / io::kSetManifestName, ec))) {
        const io::SetCheck set = io::checkOutputSet(dir);
        bool named = false;
        for (const auto& f : set.files) named = named || f.first == fs::path(o.file).filename().string();
        if (set.status != io::SetCheck::Status::Complete)
            std::fprintf(stderr, "warning: %s: the files beside it are not one complete set: %s\n", o.file.c_str(),
                         set.problem.c_str());
        else if (!named)
            std::printf("set: %s does not name this file\n", (dir / io::kSetManifestName).string().c_str());
        else if (set.moved)
            std::fprintf(stderr, "warning: %s: a bake is replacing its set (or was killed doing so): the complete "
                                 "set is the one %s names\n", o.file.c_str(), (dir / io::kSetManifestName).string().c_str());
        else
            std::printf("set: complete, %zu files match %s\n", set.files.size(),
                        (dir / io::kSetManifestName).string().c_str());
    }
    std::fflush(stdout);
    return kOk;
}

// ---------------------------------------------------------------------------
// aggregate2d, reproduce2d (work in aggregate2d_command.cpp / reproduce2d_command.cpp)

CLI::App* addAggregate2DCommand(CLI::App& app, cli::Aggregate2DOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "aggregate2d", "Aggregate 2D polygons (WKT or GeoJSON) into levels; writes GeoJSON (coordinates are taken as "
                       "plain planar numbers, degrees included)");
    cmd->add_option("input", o.input, "Input polygons: .wkt (one POLYGON/MULTIPOLYGON per line) or .geojson")
        ->required();
    cmd->add_option("-o,--output", o.output, "Output GeoJSON: one feature per aggregate per level")->required();
    CLI::Option* delta = cmd->add_option("--delta", o.deltas, "Explicit thresholds, comma-separated, in input units")
                             ->delimiter(',')
                             ->allow_extra_args(false);
    CLI::Option* levels =
        cmd->add_option("--levels", o.levels, "Number of automatic levels (default 8)")->check(CLI::Range(1, 1000));
    delta->excludes(levels);
    cmd->add_option("--function", o.function,
                    "Aggregate shape: adaptive (default, paper Eq. 2), constant (Eq. 1) or hull (convex hull per group)")
        ->transform(CLI::IsMember({"adaptive", "constant", "hull"}, CLI::ignore_case));
    cmd->add_option("--links", o.linksPath, "Write the input id -> output id table per level (CSV)");
    cmd->add_option("--svg", o.svgPath, "Write an SVG picture (originals filled, aggregates outlined)");
    cmd->add_option("--png", o.pngPath, "Write a PNG picture (originals filled, aggregates outlined)");
    cmd->add_option("--stats", o.statsPath, "Write the measures of every level to this JSON file");
    cmd->add_option("--threads", o.threads, "Threads (default 0: all cores); output is identical for any count")
        ->check(CLI::Range(0, 1024));
    cmd->add_flag("-q,--quiet", o.quiet, "No progress, notes, warnings or table (errors only)");
    return cmd;
}

CLI::App* addReproduce2DCommand(CLI::App& app, cli::Reproduce2DOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "reproduce2d", "Rerun the paper's 2D evaluation on its five environments: table.md, table.csv, "
                       "fig4-<env>.png, fig6.png");
    cmd->add_option("-o,--output", o.outDir, "Output directory (created if missing)")->required();
    cmd->add_option("--seed", o.seed, "Seed of the environment generators (default 1)");
    cmd->add_flag("-q,--quiet", o.quiet, "No progress or table (errors only)");
    return cmd;
}

// ---------------------------------------------------------------------------
// render (work in render_command.cpp)

CLI::App* addRenderCommand(CLI::App& app, cli::RenderOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "render", "Ray-cast a PNG of one level (or, with --sheet, of every level side by side) of a baked .aglod or "
                  "levels.glb: one colour per aggregate, originals grey");
    cmd->add_option("file", o.input, "OUTDIR/scene.aglod or OUTDIR/levels.glb written by `aggrelod bake`")->required();
    cmd->add_option("-o,--output", o.output, "Output PNG")->required();
    CLI::Option* level = cmd->add_option(
        "--level", o.level, "Level to draw: a level number, 'originals', 'object-lods' or 'drawn-at-N' (.aglod: what "
                            "the runtime draws from N = 4 or 16 scene diameters; default: originals for .aglod, the "
                            "first level for levels.glb)");
    CLI::Option* sheet = cmd->add_flag("--sheet", o.sheet, "Draw every level (and the originals) side by side, labelled");
    level->excludes(sheet);
    cmd->add_option("--camera", o.camera,
                    "Camera x,y,z,tx,ty,tz[,fovDegrees]: eye and target (world units) and vertical field of view "
                    "(default 25); default: a 3/4 view from the front-right fitting the scene")
        ->delimiter(',')
        ->allow_extra_args(false);
    cmd->add_option("--up", o.up, "Up axis of the scene: y (glTF), z (the samples) or auto (default: the thinner of y and z)")
        ->transform(CLI::IsMember({"auto", "y", "z"}, CLI::ignore_case));
    cmd->add_option("--size", o.size, "Image size WIDTHxHEIGHT in pixels (default 640x480; with --sheet 400x300 per panel)");
    cmd->add_option("--columns", o.columns, "Panels per row of the sheet (default: up to 4)")->check(CLI::Range(0, 64));
    cmd->add_option("--threads", o.threads, "Ray-casting threads (default 0: 2); output is identical for any count")
        ->check(CLI::Range(0, 64));
    cmd->add_flag("-q,--quiet", o.quiet, "Print nothing but errors");
    return cmd;
}

// ---------------------------------------------------------------------------
// plan, reproduce-planning (work in plan_command.cpp / reproduce_planning_command.cpp)

#ifdef AGGRELOD_HAVE_PLANNING
CLI::App* addPlanCommand(CLI::App& app, cli::PlanOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "plan", "Plan a collision-free path for a round agent with the aggregation hierarchy (OMPL LazyPRM, coarse to "
                "fine); exit 0 solved, 3 no path within the time limit");
    cmd->add_option("baked", o.input,
                    "OUTDIR/scene.aglod (3D), the GeoJSON written by aggregate2d (with --originals), or 2D polygons "
                    "(.wkt, .geojson, .json; aggregated here, see --levels)")
        ->required();
    cmd->add_option("--originals", o.originalsPath,
                    "aggregate2d GeoJSON: the polygons aggregate2d read (required; the original obstacles)");
    cmd->add_option("--links", o.linksPath,
                    "aggregate2d GeoJSON: its link table (aggregate2d --links); checked row by row against the GeoJSON");
    cmd->add_option("--from", o.from, "Start x,y (2D) or x,y,z (3D), scene units")->delimiter(',')->required();
    cmd->add_option("--to", o.to, "Goal x,y (2D) or x,y,z (3D), scene units")->delimiter(',')->required();
    cmd->add_option("--radius", o.radius, "Agent radius (disc in 2D, ball in 3D), scene units, > 0")->required();
    cmd->add_option("--strategy", o.strategy,
                    "hierarchy (default: coarsest level first, then finer), originals, or level:K (one level only)");
    cmd->add_option("--time-limit", o.timeLimit, "Seconds for the query (default 10)");
    cmd->add_option("--seed", o.seed, "Seed of OMPL's random numbers (default 1); same seed, same roadmap and path");
    cmd->add_option("--level-samples", o.levelSamples,
                    "Hierarchy: new roadmap vertices per level before descending (default 500)")
        ->check(CLI::Range(1, 100000000));
    CLI::Option* delta = cmd->add_option("--delta", o.deltas, "2D polygons: explicit thresholds, comma-separated")
                             ->delimiter(',')
                             ->allow_extra_args(false);
    CLI::Option* levels =
        cmd->add_option("--levels", o.levels, "2D polygons: number of automatic levels (default 6)")->check(CLI::Range(1, 1000));
    delta->excludes(levels);
    CLI::Option* png = cmd->add_option("--png", o.pngPath, "Write a Fig. 7-style picture (roadmap per level, path) as PNG");
    CLI::Option* svg = cmd->add_option("--svg", o.svgPath, "Write the picture as SVG");
    png->excludes(svg);
    cmd->add_option("--stats", o.statsPath, "Write {solved, path, levels_used, seconds, collision_checks, ...} as JSON");
    cmd->add_flag("-q,--quiet", o.quiet, "Print nothing but errors");
    return cmd;
}

CLI::App* addReproducePlanningCommand(CLI::App& app, cli::ReproducePlanningOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "reproduce-planning", "Rerun the paper's motion-planning experiment (Section 4.3) on the five 2D environments and "
                              "three 3D scenes: planning.md, planning.csv, fig7-<env>.png");
    cmd->add_option("-o,--output", o.outDir, "Output directory (created if missing; 3D bakes are kept in scenes/)")
        ->required();
    cmd->add_option("--queries", o.queries, "Random start / goal pairs per environment (default 100)")
        ->check(CLI::Range(1, 100000));
    cmd->add_option("--time-limit", o.timeLimit, "Seconds per query and strategy (default 2)");
    cmd->add_option("--seed", o.seed, "Seed of the scenes, queries and planners (default 1)");
    cmd->add_option("--only", o.only,
                    "Comma-separated environments (tree, scatter, room, colony, forest, forest3d, village3d, random1000)");
    cmd->add_flag("-q,--quiet", o.quiet, "No progress or table (errors only)");
    return cmd;
}
#endif

// ---------------------------------------------------------------------------

int run(int argc, char** argv) {
    CLI::App app{"aggrelod: aggregate separate objects into a level-of-detail hierarchy"};
    app.set_version_flag("--version", std::string("aggrelod ") + AGGRELOD_VERSION);
    app.require_subcommand(1);

    BakeOptions bake;
    CLI::App* bakeCommand = addBakeCommand(app, bake);
    InspectOptions inspect;
    CLI::App* inspectCommand = addInspectCommand(app, inspect);
    cli::Aggregate2DOptions aggregate2d;
    CLI::App* aggregate2dCommand = addAggregate2DCommand(app, aggregate2d);
    cli::Reproduce2DOptions reproduce2d;
    CLI::App* reproduce2dCommand = addReproduce2DCommand(app, reproduce2d);
    cli::RenderOptions render;
    CLI::App* renderCommand = addRenderCommand(app, render);
#ifdef AGGRELOD_HAVE_PLANNING
    cli::PlanOptions plan;
    CLI::App* planCommand = addPlanCommand(app, plan);
    cli::ReproducePlanningOptions reproducePlanning;
    CLI::App* reproducePlanningCommand = addReproducePlanningCommand(app, reproducePlanning);
#endif

    if (argc <= 1) {
        std::fputs(app.help().c_str(), stderr);
        return kUsage;
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);  // prints help, version or the error
        return code == 0 ? kOk : kUsage;
    }
    if (bakeCommand->parsed()) return runBake(bake);
    if (inspectCommand->parsed()) return runInspect(inspect);
    if (aggregate2dCommand->parsed()) return cli::runAggregate2D(aggregate2d);
    if (reproduce2dCommand->parsed()) return cli::runReproduce2D(reproduce2d);
    if (renderCommand->parsed()) return cli::runRender(render);
#ifdef AGGRELOD_HAVE_PLANNING
    if (planCommand->parsed()) return cli::runPlan(plan);
    if (reproducePlanningCommand->parsed()) return cli::runReproducePlanning(reproducePlanning);
#endif
    return kUsage;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "aggrelod: internal error: %s\n", e.what());
    } catch (...) {
        std::fprintf(stderr, "aggrelod: internal error\n");
    }
    return kInternal;
}
