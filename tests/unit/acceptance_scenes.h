// SPDX-License-Identifier: AGPL-3.0-or-later
// The scenes of the proxy acceptance test and of bench_lod_budget, and an in-process bake of
// them through the module API (buildHierarchy3D + buildHierarchyNodes, as `aggrelod bake` does),
// with the stage timings. Header-only: included by a test (tests/unit) and a benchmark.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/samples.h>

#include "scene_io.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod::testing {

/// truck_town's ground, road and grass span the whole scene; the bake is run without them.
inline const char* truckTownGround() { return "^(OuterGroundMesh|GrassMesh|RoadMesh)$"; }

struct SceneRequest {
    std::string name;        ///< spheres15 | chess | forest | village | random | truck_town
    uint32_t seed = 1;       ///< samples' seed
    int randomObjects = 400;       ///< random: object count
    int randomTriangles = 200000;  ///< random: approximate total triangle count
    std::string sharedDataDir;     ///< folder holding 3d/truck_town/town_model.gltf
};

/// The input of a bake, as `aggrelod bake` would read it.
struct SceneInput {
    std::string label;
    std::vector<InputObject> objects;
    int upAxis = 2;               ///< 2 (z) for the samples, 1 (y) for glTF scenes
    bool constantFunction = false;  ///< chess is baked with the constant function, as in the CLI tests
    std::string problem;          ///< empty when loaded; starts with "absent: " when the data is missing
};

inline SceneInput loadScene(const SceneRequest& r) {
    SceneInput s;
    s.label = r.name;
    if (r.name == "spheres15") s.objects = samples::makeSpheres15(r.seed);
    else if (r.name == "chess") {
        s.objects = samples::makeChessBoard(r.seed);
        s.constantFunction = true;
    } else if (r.name == "forest") s.objects = samples::makeForest(r.seed);
    else if (r.name == "village") s.objects = samples::makeVillage(r.seed);
    else if (r.name == "random") {
        s.objects = samples::makeRandomScene(r.randomObjects, r.randomTriangles, r.seed);
        s.label = "random" + std::to_string(r.randomObjects);
    } else if (r.name == "truck_town") {
        const std::filesystem::path path = std::filesystem::path(r.sharedDataDir) / "3d/truck_town/town_model.gltf";
        if (!std::filesystem::exists(path)) {
            s.problem = "absent: " + path.string();
            return s;
        }
        io::SceneReadOptions options;
        options.excludeRegex = truckTownGround();
        io::SceneReadResult read;
        std::string error;
        if (!io::readGltfScene(path.string(), options, read, error)) s.problem = error;
        s.objects = std::move(read.objects);
        s.upAxis = 1;
    } else {
        s.problem = "unknown scene '" + r.name + "'";
    }
    return s;
}

/// Centre (middle of the box of every vertex) and radius (largest vertex distance from it).
struct SceneSphere {
    double center[3] = {0, 0, 0};
    double radius = 0;
    double diagonal = 0;  ///< of the box
};

inline SceneSphere sceneSphere(const std::vector<InputObject>& objects) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const InputObject& o : objects)
        for (size_t i = 0; i < o.positions.size(); i += 3)
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], o.positions[i + k]);
                hi[k] = std::max(hi[k], o.positions[i + k]);
            }
    SceneSphere s;
    for (int k = 0; k < 3; ++k) {
        s.center[k] = 0.5 * (lo[k] + hi[k]);
        s.diagonal += (hi[k] - lo[k]) * (hi[k] - lo[k]);
    }
    s.diagonal = std::sqrt(s.diagonal);
    for (const InputObject& o : objects)
        for (size_t i = 0; i < o.positions.size(); i += 3) {
            double d2 = 0;
            for (int k = 0; k < 3; ++k) d2 += (o.positions[i + k] - s.center[k]) * (o.positions[i + k] - s.center[k]);
            s.radius = std::max(s.radius, std::sqrt(d2));
        }
    return s;
}

struct Baked {
    Hierarchy3D hierarchy;
    HierarchyNodes nodes;
    double hierarchySeconds = 0;  ///< buildHierarchy3D (its stages are in hierarchy.timings)
    double proxySeconds = 0;      ///< buildHierarchyNodes: proxies, their errors, the node tree
    bool ok = false;
    std::string problem;
};

/// Bakes `input` with `levels` automatic levels (spheres15: the paper's deltas), proxies at
/// the default settings (bundles >= 0: that ProxySettings::bundleCount), `threads` threads
/// (results do not depend on it).
inline Baked bakeScene(const SceneInput& input, int levels, int threads, int bundles = -1) {
    Baked b;
    Settings3D settings;
    if (input.label == "spheres15") settings.deltas = {1, 1.5, 2, 3, 4};
    settings.automaticLevelCount = levels;
    settings.threadCount = threads;
    if (input.constantFunction) settings.function = AggregateFunctionKind::Constant;
    const auto start = std::chrono::steady_clock::now();
    if (!buildHierarchy3D(input.objects, settings, b.hierarchy)) {
        b.problem = "buildHierarchy3D failed";
        for (const Diagnostic& d : b.hierarchy.diagnostics) b.problem += "; " + d.message;
        return b;
    }
    const auto middle = std::chrono::steady_clock::now();
    ProxySettings proxies;
    proxies.threadCount = threads;
    if (bundles >= 0) proxies.bundleCount = bundles;
    std::string error;
    if (!buildHierarchyNodes(b.hierarchy, input.objects, proxies, b.nodes, error)) {
        b.problem = "buildHierarchyNodes failed: " + error;
        return b;
    }
    const auto end = std::chrono::steady_clock::now();
    b.hierarchySeconds = std::chrono::duration<double>(middle - start).count();
    b.proxySeconds = std::chrono::duration<double>(end - middle).count();
    b.ok = true;
    return b;
}

}  // namespace aggrelod::testing
