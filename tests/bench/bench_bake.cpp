// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of the whole 3D bake versus TetGen alone on the same input (issue 2):
// a generated scene of ~1000 objects / ~150k triangles, 8 levels. TetGen's constrained
// tetrahedralization is the floor of this design, so the figure that matters is the ratio
// bake / TetGen, measured in the same run (absolute seconds on shared machines are noisy).
//
// TetGen is timed two ways: in a fresh process (as the `tetgen` program, or our bake's child
// process, meets it: cold memory, every page faulted in) - the peer the goal is judged
// against - and in this process after warm-up (its heap reused: the best case).
//
// The default bake measures the convex-hull baseline only; the constant-function baseline
// (Settings3D::computeConstantBaseline, CLI --constant-baseline) is opt-in. With the sixth
// argument 1 each run also bakes with it, and that bake is reported on its own line.
//
// Usage: bench_bake [objects=1000] [triangles=150000] [levels=8] [seed=1] [threads=0 (all)]
//                   [also bake with the constant baseline 1|0 = 1] [runs=3]
#include "tetgen_peer.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/samples.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

using namespace aggrelod;
using bench::childrenCpuSeconds;
using bench::cpuSeconds;

int main(int argc, char** argv) {
    if (bench::runTetgenAloneIfAsked(argc, argv)) return 0;
    const int objectCount = argc > 1 ? std::atoi(argv[1]) : 1000;
    const int triangles = argc > 2 ? std::atoi(argv[2]) : 150000;
    const int levels = argc > 3 ? std::atoi(argv[3]) : 8;
    const uint32_t seed = argc > 4 ? static_cast<uint32_t>(std::atoi(argv[4])) : 1u;
    const int threads = argc > 5 ? std::atoi(argv[5]) : 0;
    const bool alsoConstantBaseline = argc > 6 ? std::atoi(argv[6]) != 0 : true;
    std::vector<InputObject> objects = samples::makeRandomScene(objectCount, triangles, seed);
    size_t tris = 0;
    for (const InputObject& o : objects) tris += o.indices.size() / 3;

    // Runs alternate TetGen alone and the whole bake; the medians are compared, so a burst
    // of other load on a shared machine hits both sides alike and one outlier changes nothing.
    const int runs = argc > 7 ? std::max(1, std::atoi(argv[7])) : 3;
    Settings3D settings;
    settings.automaticLevelCount = levels;
    settings.threadCount = threads;
    settings.computeConstantBaseline = false;  // the default
    Settings3D withConstant = settings;
    withConstant.computeConstantBaseline = true;
    struct BakeRun {
        double seconds = 0, childCpu = 0, processCpu = 0;
        bool ok = false;
        Hierarchy3D h;
    };
    std::vector<BakeRun> bakes(runs), constantBakes(alsoConstantBaseline ? runs : 0);
    std::vector<std::pair<double, double>> alone(runs), fresh(runs);  // wall, cpu
    int tets = 0, freshTets = 0;
    for (int r = 0; r < runs; ++r) {
        const bench::TetgenPeerRun freshRun = bench::tetgenAloneFreshProcess(objectCount, triangles, seed);
        fresh[r] = {freshRun.wall, freshRun.cpu};
        freshTets = freshRun.tets;
        const bench::TetgenPeerRun aloneRun = bench::tetgenAlone(objects);
        alone[r] = {aloneRun.wall, aloneRun.cpu};
        tets = aloneRun.tets;
        BakeRun& b = bakes[r];
        auto start = std::chrono::steady_clock::now();
        const double childCpuStart = childrenCpuSeconds(), processCpuStart = cpuSeconds(CLOCK_PROCESS_CPUTIME_ID);
        b.ok = buildHierarchy3D(objects, settings, b.h);
        b.childCpu = childrenCpuSeconds() - childCpuStart;
        b.processCpu = cpuSeconds(CLOCK_PROCESS_CPUTIME_ID) - processCpuStart;
        b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (alsoConstantBaseline) {
            BakeRun& c = constantBakes[r];
            start = std::chrono::steady_clock::now();
            c.ok = buildHierarchy3D(objects, withConstant, c.h);
            c.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        }
    }
    std::printf("runs: %d (medians shown); in run order, whole bake seconds:", runs);
    for (const BakeRun& b : bakes) std::printf(" %.3f", b.seconds);
    if (alsoConstantBaseline) {
        std::printf("; with constant baseline:");
        for (const BakeRun& b : constantBakes) std::printf(" %.3f", b.seconds);
    }
    std::printf("; TetGen fresh process:");
    for (const auto& a : fresh) std::printf(" %.3f", a.first);
    std::printf("; TetGen in-process:");
    for (const auto& a : alone) std::printf(" %.3f", a.first);
    std::printf("\n");
    std::sort(fresh.begin(), fresh.end());
    std::sort(alone.begin(), alone.end());
    const double freshSeconds = fresh[runs / 2].first, freshCpu = fresh[runs / 2].second;
    std::sort(bakes.begin(), bakes.end(), [](const BakeRun& x, const BakeRun& y) { return x.seconds < y.seconds; });
    const double tetgenSeconds = alone[runs / 2].first, tetgenCpu = alone[runs / 2].second;
    const BakeRun& median = bakes[runs / 2];
    const Hierarchy3D& h = median.h;
    const bool ok = median.ok;
    const double bakeSeconds = median.seconds, childCpu = median.childCpu, processCpu = median.processCpu;

    std::printf("scene: %zu objects, %zu triangles, seed %u, threads %d (0 = all); bake %s, %zu levels, %zu tets (TetGen alone: %d tets)\n",
                objects.size(), tris, seed, threads, ok ? "ok" : "FAILED", h.levels.size(), h.tetrahedronCount, tets);
    std::printf("| stage | seconds | share of bake |\n|---|---:|---:|\n");
    for (const auto& [stage, seconds] : h.timings)
        std::printf("| %s | %.3f | %.1f %% |\n", stage.c_str(), seconds, 100.0 * seconds / bakeSeconds);
    std::printf("| **whole bake** | %.3f | 100 %% |\n", bakeSeconds);
    std::printf("| TetGen alone, fresh process (pczQn, same input) | %.3f | |\n", freshSeconds);
    std::printf("| TetGen alone, warm in-process (best case) | %.3f | |\n", tetgenSeconds);
    std::printf("\nratio whole bake (default: hull baseline) / TetGen alone (fresh process): %.2fx (goal <= 1.5x)\n",
                bakeSeconds / freshSeconds);
    std::printf("ratio whole bake / TetGen alone (warm, in-process): %.2fx\n", bakeSeconds / tetgenSeconds);
    if (alsoConstantBaseline) {
        std::sort(constantBakes.begin(), constantBakes.end(), [](const BakeRun& x, const BakeRun& y) { return x.seconds < y.seconds; });
        const BakeRun& c = constantBakes[runs / 2];
        double levelsSeconds = 0;
        for (const auto& [stage, seconds] : c.h.timings)
            if (stage == "levels") levelsSeconds = seconds;
        std::printf("bake with the constant baseline too (opt-in): %.3f s %s, levels stage %.3f s; ratio / TetGen alone "
                    "(fresh process): %.2fx\n",
                    c.seconds, c.ok ? "ok" : "FAILED", levelsSeconds, c.seconds / freshSeconds);
    }
    // CPU seconds are less sensitive than wall time to other load on a shared machine.
    std::printf("CPU seconds: TetGen alone fresh %.3f, warm %.3f; bake: TetGen child %.3f, this process %.3f (all threads)\n",
                freshCpu, tetgenCpu, childCpu, processCpu);
    if (freshTets != tets) std::printf("note: fresh-process TetGen made %d tets, in-process %d\n", freshTets, tets);
    // Output quality on the same run: aggregates whose surface uses a directed edge twice
    // (not edge-manifold) and aggregates with more than one shell.
    size_t aggregates = 0, nonManifold = 0, multiShell = 0;
    for (const Level& level : h.levels)
        for (const Aggregate& a : level.aggregates) {
            ++aggregates;
            std::vector<std::pair<uint32_t, uint32_t>> edges;
            for (size_t t = 0; t + 2 < a.indices.size(); t += 3)
                for (int k = 0; k < 3; ++k) edges.emplace_back(a.indices[t + k], a.indices[t + (k + 1) % 3]);
            std::sort(edges.begin(), edges.end());
            if (std::adjacent_find(edges.begin(), edges.end()) != edges.end()) ++nonManifold;
            if (a.componentCount > 1) ++multiShell;
        }
    std::printf("aggregates: %zu, not edge-manifold: %zu, more than one shell: %zu\n", aggregates, nonManifold, multiShell);
    return ok ? 0 : 1;
}
