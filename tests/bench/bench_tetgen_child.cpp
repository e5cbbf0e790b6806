// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of the TetGen backend's process isolation (issue 2): the same PLC (the generated
// scene's surfaces, no prerefine points) tetrahedralized by
//   fresh  - TetGen alone in a fresh process (this program re-executed: the peer of issue 2),
//   backend - detail::tetrahedralizePlc from this process (child process, result streamed back),
//   backend+busy - the same while a low-priority thread of this process keeps the other core
//                  busy (as the bake's overlap thread does),
//   fresh+busy   - TetGen alone in a fresh process while the same busy thread runs here.
// Before the runs this process can run one whole bake (argument heap=1) so that the child
// starts from a large, fragmented parent, as inside the bake.
// Modes alternate per run; medians of wall seconds and of TetGen's CPU seconds are printed.
//
// Usage: bench_tetgen_child [objects=1000] [triangles=150000] [seed=1] [runs=5] [heap=1]
#include "tetgen_backend.h"
#include "tetgen_peer.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/samples.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

using namespace aggrelod;
using bench::childrenCpuSeconds;

namespace {
detail::PlcInput makePlc(const std::vector<InputObject>& objects) {
    detail::PlcInput plc;
    for (size_t m = 0; m < objects.size(); ++m) {
        const int base = static_cast<int>(plc.points.size() / 3);
        plc.points.insert(plc.points.end(), objects[m].positions.begin(), objects[m].positions.end());
        for (uint32_t i : objects[m].indices) plc.triangles.push_back(base + static_cast<int>(i));
        plc.triangleMarkers.insert(plc.triangleMarkers.end(), objects[m].indices.size() / 3, static_cast<int>(m) + 1);
    }
    return plc;
}

// A low-priority thread doing memory-heavy work (like BVH builds and distance queries).
struct BusyThread {
    std::atomic<bool> stop{false};
    std::thread thread;
    void start() {
        stop = false;
        thread = std::thread([this] {
            setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
            std::vector<double> data(1 << 22);
            uint64_t x = 1;
            while (!stop) {
                for (int k = 0; k < 100000 && !stop; ++k) {
                    x = x * 6364136223846793005ull + 1442695040888963407ull;
                    data[(x >> 20) & (data.size() - 1)] += 1.0;
                }
            }
        });
    }
    void finish() {
        stop = true;
        thread.join();
    }
};

struct Sample {
    double wall = 0, cpu = 0;
};

Sample freshProcess(int objects, int triangles, uint32_t seed) {
    const bench::TetgenPeerRun run = bench::tetgenAloneFreshProcess(objects, triangles, seed);
    return {run.wall, run.cpu};
}

Sample backend(const detail::PlcInput& plc) {
    detail::TetMesh mesh;
    const double cpuStart = childrenCpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    detail::TetgenOutcome outcome = detail::tetrahedralizePlc(plc, mesh);
    Sample s;
    s.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // The backend reaps a child that delivered its result in the background; its CPU time
    // is counted once it is reaped.
    for (int wait = 0; wait < 50 && childrenCpuSeconds() == cpuStart; ++wait) usleep(20000);
    s.cpu = childrenCpuSeconds() - cpuStart;
    if (outcome.status != detail::TetgenStatus::Ok) s = {-1, -1};
    return s;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}
}  // namespace

int main(int argc, char** argv) {
    if (bench::runTetgenAloneIfAsked(argc, argv)) return 0;
    const int objectCount = argc > 1 ? std::atoi(argv[1]) : 1000;
    const int triangles = argc > 2 ? std::atoi(argv[2]) : 150000;
    const uint32_t seed = argc > 3 ? static_cast<uint32_t>(std::atoi(argv[3])) : 1u;
    const int runs = argc > 4 ? std::max(1, std::atoi(argv[4])) : 5;
    const bool heap = argc > 5 ? std::atoi(argv[5]) != 0 : true;
    const std::vector<InputObject> objects = samples::makeRandomScene(objectCount, triangles, seed);
    const detail::PlcInput plc = makePlc(objects);
    Hierarchy3D keep;  // kept alive: the parent stays large, as during a bake
    if (heap) {
        Settings3D settings;
        buildHierarchy3D(objects, settings, keep);
    }
    const char* names[] = {"fresh process", "backend (child)", "backend + busy thread", "fresh process + busy thread"};
    std::vector<std::vector<double>> wall(4), cpu(4);
    for (int r = 0; r < runs; ++r) {
        for (int mode = 0; mode < 4; ++mode) {
            BusyThread busy;
            if (mode >= 2) busy.start();
            const Sample s = mode == 0 || mode == 3 ? freshProcess(objectCount, triangles, seed) : backend(plc);
            if (mode >= 2) busy.finish();
            wall[mode].push_back(s.wall);
            cpu[mode].push_back(s.cpu);
        }
    }
    std::printf("scene: %d objects, %zu triangles, seed %u; %d runs, parent heap %s\n", objectCount, plc.triangles.size() / 3,
                seed, runs, heap ? "after one bake" : "small");
    std::printf("| mode | wall median (s) | CPU median (s) | wall runs |\n|---|---:|---:|---|\n");
    for (int mode = 0; mode < 4; ++mode) {
        std::printf("| %s | %.3f | %.3f |", names[mode], median(wall[mode]), median(cpu[mode]));
        for (double w : wall[mode]) std::printf(" %.2f", w);
        std::printf(" |\n");
    }
    return 0;
}
