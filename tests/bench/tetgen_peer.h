// SPDX-License-Identifier: AGPL-3.0-or-later
// The peer of the issue-2 benchmarks: TetGen alone on a scene's surfaces, with the switches
// the bake uses (pczQn), timed in this process or in a fresh one. Shared by bench_bake and
// bench_tetgen_child so both compare against exactly the same TetGen call.
//
// The fresh-process run re-executes the calling benchmark with
// `--tetgen-alone OBJECTS TRIANGLES SEED`; each benchmark's main() starts with
// `if (runTetgenAloneIfAsked(argc, argv)) return 0;`.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/samples.h>

#include <tetgen.h>

#include <sys/resource.h>
#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

namespace aggrelod::bench {

/// CPU seconds of a clock (CLOCK_THREAD_CPUTIME_ID, CLOCK_PROCESS_CPUTIME_ID).
inline double cpuSeconds(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/// CPU seconds (user + system) of this process's children that have been waited for.
inline double childrenCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

/// One TetGen-alone run: wall and CPU seconds of the tetrahedralize() call (-1 on failure)
/// and the number of tetrahedra it made.
struct TetgenPeerRun {
    double wall = -1, cpu = -1;
    int tets = 0;
};

/// TetGen alone in this process on every object's triangles (one facet per triangle, the
/// object's number + 1 as marker), as the bake's backend gives them to TetGen.
inline TetgenPeerRun tetgenAlone(const std::vector<InputObject>& objects) {
    tetgenio in, out;
    size_t points = 0, faces = 0;
    for (const InputObject& o : objects) {
        points += o.positions.size() / 3;
        faces += o.indices.size() / 3;
    }
    in.numberofpoints = static_cast<int>(points);
    in.pointlist = new REAL[3 * points];
    in.numberoffacets = static_cast<int>(faces);
    in.facetlist = new tetgenio::facet[faces];
    in.facetmarkerlist = new int[faces];
    size_t p = 0, f = 0;
    for (size_t m = 0; m < objects.size(); ++m) {
        const InputObject& o = objects[m];
        const size_t base = p;
        std::memcpy(in.pointlist + 3 * p, o.positions.data(), o.positions.size() * sizeof(double));
        p += o.positions.size() / 3;
        for (size_t t = 0; t < o.indices.size(); t += 3, ++f) {
            tetgenio::facet& facet = in.facetlist[f];
            tetgenio::init(&facet);
            facet.numberofpolygons = 1;
            facet.polygonlist = new tetgenio::polygon[1];
            tetgenio::init(&facet.polygonlist[0]);
            facet.polygonlist[0].numberofvertices = 3;
            facet.polygonlist[0].vertexlist = new int[3];
            for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = static_cast<int>(base + o.indices[t + k]);
            in.facetmarkerlist[f] = static_cast<int>(m) + 1;
        }
    }
    char switches[] = "pczQn";
    TetgenPeerRun run;
    const auto start = std::chrono::steady_clock::now();
    const double cpuStart = cpuSeconds(CLOCK_THREAD_CPUTIME_ID);
    tetrahedralize(switches, &in, &out);
    run.cpu = cpuSeconds(CLOCK_THREAD_CPUTIME_ID) - cpuStart;
    run.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.tets = out.numberoftetrahedra;
    return run;
}

/// TetGen alone in a fresh process (cold memory, every page faulted in: as the `tetgen`
/// program or the bake's child process meets it), on samples::makeRandomScene(objects,
/// triangles, seed): re-executes this program with --tetgen-alone.
inline TetgenPeerRun tetgenAloneFreshProcess(int objects, int triangles, uint32_t seed) {
    char command[512];
    std::snprintf(command, sizeof command, "/proc/%d/exe --tetgen-alone %d %d %u", static_cast<int>(getpid()), objects,
                  triangles, seed);
    TetgenPeerRun run;
    if (FILE* pipe = popen(command, "r")) {
        if (std::fscanf(pipe, "%lf %lf %d", &run.wall, &run.cpu, &run.tets) != 3) run = TetgenPeerRun{};
        pclose(pipe);
    }
    return run;
}

/// The fresh process's side: with `--tetgen-alone OBJECTS TRIANGLES SEED`, times TetGen alone
/// on that scene, prints "wall cpu tets" and returns true (the caller then exits).
inline bool runTetgenAloneIfAsked(int argc, char** argv) {
    if (argc != 5 || std::strcmp(argv[1], "--tetgen-alone") != 0) return false;
    const TetgenPeerRun run = tetgenAlone(
        samples::makeRandomScene(std::atoi(argv[2]), std::atoi(argv[3]), static_cast<uint32_t>(std::atoi(argv[4]))));
    std::printf("%.6f %.6f %d\n", run.wall, run.cpu, run.tets);
    return true;
}

}  // namespace aggrelod::bench
