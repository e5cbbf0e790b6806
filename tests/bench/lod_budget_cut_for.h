// SPDX-License-Identifier: AGPL-3.0-or-later
// bench_lod_budget --cut-for FILE.aglod --cameras FRAMES.csv: the cut the benchmark's rule
// selects for each of the given cameras, in a baked runtime file. The rule is that of the
// benchmark's (c) column (a fresh selection per camera, no hysteresis; triangles of the proxy
// nodes plus those of the originals drawn as leaves; one draw call per proxy node and per leaf),
// with the camera's frustum culling added (Selector::select(ViewCamera) after reset()), since
// a renderer's camera has a frustum, and no draw call for a node without triangles (as in the
// benchmark's column (a): e.g. a support surface such as a ground, which the file lists as an
// object without a mesh for the engine to draw itself). FRAMES.csv is what samples/viewer writes (columns frame,
// eye_*, forward_*, up_*, fov_y, aspect, viewport_height, near, far, tau, coarsen_ratio, by
// name, any order; coarsen_ratio must be 1). Prints one CSV row per camera:
//   frame,cut_nodes,proxies,originals,culled,draw_calls,triangles
// Returns the process exit status (0, or 1 on an unreadable file or camera list).
#pragma once

#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace lod_budget {

inline int printCutsForCameras(const std::string& aglodPath, const std::string& camerasPath) {
    using namespace aggrelod::runtime;
    RuntimeFile file;
    std::string error;
    if (RuntimeFile::openFile(aglodPath, file, error) != FileStatus::Ok) {
        std::fprintf(stderr, "bench_lod_budget: %s\n", error.c_str());
        return 1;
    }
    std::ifstream in(camerasPath);
    std::string line;
    if (camerasPath.empty() || !in || !std::getline(in, line)) {
        std::fprintf(stderr, "bench_lod_budget: --cut-for needs --cameras FRAMES.csv (got '%s')\n", camerasPath.c_str());
        return 1;
    }
    auto split = [](const std::string& s) {
        std::vector<std::string> out;
        std::stringstream ss(s);
        for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
        return out;
    };
    std::map<std::string, size_t> column;
    const std::vector<std::string> header = split(line);
    for (size_t i = 0; i < header.size(); ++i) column[header[i]] = i;
    const char* needed[] = {"frame", "eye_x", "eye_y", "eye_z", "forward_x", "forward_y", "forward_z", "up_x", "up_y",
                            "up_z", "fov_y", "aspect", "viewport_height", "near", "far", "tau", "coarsen_ratio"};
    for (const char* name : needed)
        if (!column.count(name)) {
            std::fprintf(stderr, "bench_lod_budget: %s: no column %s\n", camerasPath.c_str(), name);
            return 1;
        }
    // The originals' triangles, per object (the benchmark counts each drawn object's mesh): the
    // mesh of its leaf node.
    std::vector<size_t> objectTriangles(file.objectCount(), 0);
    for (uint32_t n = 0; n < file.nodeCount(); ++n)
        if (file.isLeaf(n)) {
            if (file.sources(n).size != 1) {
                std::fprintf(stderr, "bench_lod_budget: leaf %u stands for %zu objects, not 1\n", n,
                             size_t(file.sources(n).size));
                return 1;
            }
            objectTriangles[file.sources(n)[0]] = file.triangles(n).size / 3;
        }
    Selector selector(file);
    std::printf("frame,cut_nodes,proxies,originals,culled,draw_calls,triangles\n");
    int rows = 0;
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        const std::vector<std::string> cells = split(line);
        if (cells.size() < header.size()) {
            std::fprintf(stderr, "bench_lod_budget: %s: short row '%s'\n", camerasPath.c_str(), line.c_str());
            return 1;
        }
        auto value = [&](const char* name) { return std::strtof(cells[column[name]].c_str(), nullptr); };
        ViewCamera camera;
        const char* axes = "xyz";
        for (int k = 0; k < 3; ++k) {
            const std::string suffix(1, axes[k]);
            camera.position[k] = value(("eye_" + suffix).c_str());
            camera.forward[k] = value(("forward_" + suffix).c_str());
            camera.up[k] = value(("up_" + suffix).c_str());
        }
        camera.fovY = value("fov_y");
        camera.viewportHeight = value("viewport_height");
        camera.aspect = value("aspect");
        camera.nearDistance = value("near");
        camera.farDistance = value("far");
        SelectionSettings settings;
        settings.pixelTolerance = value("tau");
        settings.coarsenRatio = value("coarsen_ratio");
        if (settings.coarsenRatio != 1.0f) {
            std::fprintf(stderr, "bench_lod_budget: --cut-for compares fresh selections: coarsen_ratio must be 1\n");
            return 1;
        }
        selector.reset();
        selector.select(camera, settings);
        size_t triangles = 0, draws = 0;
        for (uint32_t n : selector.proxyNodes()) {
            triangles += file.triangles(n).size / 3;
            draws += file.triangles(n).size ? 1 : 0;
        }
        for (uint32_t obj : selector.originalObjects()) {
            triangles += objectTriangles[obj];
            draws += objectTriangles[obj] ? 1 : 0;
        }
        std::printf("%s,%zu,%zu,%zu,%zu,%zu,%zu\n", cells[column["frame"]].c_str(), size_t(selector.cut().size),
                    size_t(selector.proxyNodes().size), size_t(selector.originalObjects().size),
                    size_t(selector.culledNodes().size), draws, triangles);
        ++rows;
    }
    std::fprintf(stderr, "bench_lod_budget: %d cameras, %u nodes in %s\n", rows, file.nodeCount(), aglodPath.c_str());
    return rows > 0 ? 0 : 1;
}

}  // namespace lod_budget
