// SPDX-License-Identifier: AGPL-3.0-or-later
// What solidifying costs on the shared real scenes (docs/design.md §2.0, docs/real-art.md): per scene,
// as `aggrelod bake SCENE` with no options does it (default read options and settings, then
// the proxies), the seconds of the "solidify" and "solid measures" stages (making the solids,
// then measuring their distances for the report) against the whole bake, the peak resident
// memory during solidification (sampled at every progress report of that stage) against the
// bake's peak (getrusage; each scene runs in its own process), and per scene the solids' added volume and sampled Hausdorff
// distance (worst solid, in % of its own bounding-box diagonal). With --solids, one line per
// solid with its own time, and for each wrap the time of the same wrap (one thread) with the
// quick oracle the bake uses and with CGAL's own queries, and the triangles of both wraps
// (the quick oracle's Steiner points differ from CGAL's by rounding). A benchmark: nothing is
// asserted.
//
// Usage: bench_solidify [--threads 2] [--data DIR] [--solids] [SCENE.glb|gltf ...]
//   (default scenes: every real scene under DIR/3d)
#include "scene_io.h"
#include "solidify.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/hierarchy_nodes.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace aggrelod;

namespace {

double residentMiB() {
    FILE* f = std::fopen("/proc/self/statm", "r");
    if (!f) return 0;
    unsigned long size = 0, resident = 0;
    const int read = std::fscanf(f, "%lu %lu", &size, &resident);
    std::fclose(f);
    return read == 2 ? double(resident) * double(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0) : 0.0;
}

double peakMiB() {
    rusage u{};
    ::getrusage(RUSAGE_SELF, &u);
    return double(u.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

}  // namespace

int main(int argc, char** argv) {
    int threads = 2;
    bool perSolid = false;
    std::string data = AGGRELOD_SHARED_DATA;
    std::vector<std::string> scenes;
    for (int i = 1; i < argc; ++i) {
        if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::atoi(argv[++i]);
        else if (!std::strcmp(argv[i], "--data") && i + 1 < argc) data = argv[++i];
        else if (!std::strcmp(argv[i], "--solids")) perSolid = true;
        else scenes.push_back(argv[i]);
    }
    if (scenes.empty())
        for (const char* s : {"truck_town/town_model.gltf", "collision-world/collision-world.glb", "godot_occlusion_room/room.glb",
                              "2CylinderEngine/2CylinderEngine.glb", "deccer-cubes/SM_Deccer_Cubes.glb",
                              "deccer-cubes/SM_Deccer_Cubes_With_Rotation.glb", "OrientationTest/OrientationTest.glb",
                              "MetalRoughSpheresNoTextures/MetalRoughSpheresNoTextures.glb"})
            scenes.push_back(data + "/3d/" + s);

    std::printf("%-34s %7s %6s %8s %8s %6s %9s %9s %7s %10s %10s\n", "scene", "solids", "tris", "solidify", "measures", "bake",
                "share", "mem solid", "mem bake", "added vol", "hausdorff");
    std::printf("%-34s %7s %6s %8s %8s %6s %9s %9s %7s %10s %10s\n", "", "", "(k)", "s", "s", "s", "%", "MiB", "MiB", "% orig",
                "% diag");
    for (const std::string& path : scenes) {
        // Each scene in its own process: its peak memory is its own.
        std::fflush(stdout);
        const pid_t child = ::fork();
        if (child < 0) return 1;
        if (child > 0) {
            int status = 0;
            ::waitpid(child, &status, 0);
            continue;
        }
        io::SceneReadResult scene;
        std::string error;
        if (!io::readGltfScene(path, io::SceneReadOptions{}, scene, error)) {
            std::printf("%s: %s\n", path.c_str(), error.c_str());
            std::fflush(stdout);
            ::_exit(1);
        }
        size_t triangles = 0;
        for (const InputObject& o : scene.objects) triangles += o.indices.size() / 3;
        Settings3D settings;
        settings.threadCount = threads;
        double solidPeak = 0;
        settings.progress = [&](const char* stage, double) {
            if (!std::strcmp(stage, "solidify")) solidPeak = std::max(solidPeak, residentMiB());
        };
        Hierarchy3D h;
        const auto start = std::chrono::steady_clock::now();
        bool ok = buildHierarchy3D(scene.objects, settings, h);
        if (ok) {
            ProxySettings proxies;
            proxies.threadCount = threads;
            HierarchyNodes nodes;
            ok = buildHierarchyNodes(h, scene.objects, proxies, nodes, error);
        }
        const double bake = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        // Making the solids, then measuring them (the sampled distances of the report): the
        // share counts both.
        double solidify = 0, measures = 0;
        for (const auto& [stage, seconds] : h.timings) {
            if (stage == "solidify") solidify += seconds;
            if (stage == "solid measures") measures += seconds;
        }
        double original = 0, added = 0, worst = 0;
        for (const SolidReport& r : h.solids) {
            original += r.volumeOriginal;
            added += r.volumeSolid - r.volumeOriginal;
            if (r.bboxDiagonal > 0)
                worst = std::max(worst, std::max(r.distanceSolidToOriginal, r.distanceOriginalToSolid) / r.bboxDiagonal);
        }
        std::string name = path.substr(path.find_last_of('/') + 1);
        if (name.size() > 34) name.resize(34);
        std::printf("%-34s %7zu %6.1f %8.2f %8.2f %6.1f %9.1f %9.0f %7.0f %10.1f %10.2f%s\n", name.c_str(), h.solids.size(),
                    triangles / 1000.0, solidify, measures, bake, 100 * (solidify + measures) / bake, solidPeak, peakMiB(),
                    // flat originals (labels) have no volume to compare with: NaN
                    original > 1e-6 * std::fabs(added) ? 100 * added / original : NAN, 100 * worst, ok ? "" : "  (bake failed)");
        if (perSolid)
            for (const SolidReport& r : h.solids) {
                std::string names;
                for (uint32_t o : r.objects) names += (names.empty() ? "" : ",") + scene.objects[o].name;
                if (names.size() > 40) names.resize(40);
                std::printf("    %-40s %7.3f s  alpha %.4g offset %.4g  %6zu tris  hausdorff %.2f %% diag", names.c_str(),
                            r.seconds, r.alpha, r.offset, r.triangles.size() / 3,
                            100 * std::max(r.distanceSolidToOriginal, r.distanceOriginalToSolid) / r.bboxDiagonal);
                // The objects as read.
                std::vector<double> positions;
                std::vector<uint32_t> triangles;
                for (uint32_t o : r.objects) {
                    const uint32_t base = static_cast<uint32_t>(positions.size() / 3);
                    positions.insert(positions.end(), scene.objects[o].positions.begin(), scene.objects[o].positions.end());
                    for (uint32_t i : scene.objects[o].indices) triangles.push_back(base + i);
                }
                if (r.method == SolidifyMethod::Shell) {
                    // What a user would do instead: CGAL's alpha wrap, at the wrap path's alpha
                    // for surfaces of large faces (2 % of the diagonal) and the same reach.
                    std::vector<double> outPositions;
                    std::vector<uint32_t> outTriangles;
                    std::string ignored;
                    const auto begin = std::chrono::steady_clock::now();
                    detail::alphaWrap(positions, triangles, 0.02 * r.bboxDiagonal, 2 * r.offset, outPositions, outTriangles, ignored,
                                      detail::WrapOracle::Cgal);
                    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
                    std::printf("  shell; CGAL's alpha wrap (alpha 2 %% diag) %.3f s, %zu tris", seconds, outTriangles.size() / 3);
                }
                if (r.method == SolidifyMethod::Wrap) {
                    // The wrap, with either oracle.
                    double seconds[2] = {0, 0};
                    std::vector<double> outPositions[2];
                    std::vector<uint32_t> outTriangles[2];
                    for (int k = 0; k < 2; ++k) {
                        std::string ignored;
                        const auto begin = std::chrono::steady_clock::now();
                        detail::alphaWrap(positions, triangles, r.alpha, r.offset, outPositions[k], outTriangles[k], ignored,
                                          k == 0 ? detail::WrapOracle::Quick : detail::WrapOracle::Cgal);
                        seconds[k] = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
                    }
                    std::printf("  wrap %.2f s, with CGAL's queries %.2f s (%.1fx), %zu / %zu tris", seconds[0], seconds[1],
                                seconds[1] / seconds[0], outTriangles[0].size() / 3, outTriangles[1].size() / 3);
                }
                std::printf("\n");
            }
        std::fflush(stdout);
        ::_exit(0);
    }
    return 0;
}
