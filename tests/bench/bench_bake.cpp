// Benchmark of the whole 3D bake versus TetGen alone on the same input (issue 2):
// a generated scene of ~1000 objects / ~150k triangles, 8 levels. TetGen's constrained
// tetrahedralization is the floor of this design, so the figure that matters is the ratio
// bake / TetGen, measured in the same run (absolute seconds on shared machines are noisy).
//
// Usage: bench_bake [objects=1000] [triangles=150000] [levels=8] [seed=1] [threads=0 (all)]
#include <aggrelod/aggregate3d.h>
#include <aggrelod/samples.h>

#include <tetgen.h>

#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

using namespace aggrelod;

namespace {
double cpuSeconds(clockid_t clock) {
    timespec ts{};
    clock_gettime(clock, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double childrenCpuSeconds() {
    rusage usage{};
    getrusage(RUSAGE_CHILDREN, &usage);
    return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec + 1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double tetgenAloneSeconds(const std::vector<InputObject>& objects, int& tetCount, double& cpu) {
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
    auto start = std::chrono::steady_clock::now();
    const double cpuStart = cpuSeconds(CLOCK_THREAD_CPUTIME_ID);
    tetrahedralize(switches, &in, &out);
    cpu = cpuSeconds(CLOCK_THREAD_CPUTIME_ID) - cpuStart;
    tetCount = out.numberoftetrahedra;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}
}  // namespace

int main(int argc, char** argv) {
    const int objectCount = argc > 1 ? std::atoi(argv[1]) : 1000;
    const int triangles = argc > 2 ? std::atoi(argv[2]) : 150000;
    const int levels = argc > 3 ? std::atoi(argv[3]) : 8;
    const uint32_t seed = argc > 4 ? static_cast<uint32_t>(std::atoi(argv[4])) : 1u;
    const int threads = argc > 5 ? std::atoi(argv[5]) : 0;
    const bool constantBaseline = argc > 6 ? std::atoi(argv[6]) != 0 : true;
    std::vector<InputObject> objects = samples::makeRandomScene(objectCount, triangles, seed);
    size_t tris = 0;
    for (const InputObject& o : objects) tris += o.indices.size() / 3;

    int tets = 0;
    double tetgenCpu = 0;
    const double tetgenSeconds = tetgenAloneSeconds(objects, tets, tetgenCpu);

    Settings3D settings;
    settings.automaticLevelCount = levels;
    settings.threadCount = threads;
    settings.computeConstantBaseline = constantBaseline;
    Hierarchy3D h;
    auto start = std::chrono::steady_clock::now();
    const double childCpuStart = childrenCpuSeconds(), processCpuStart = cpuSeconds(CLOCK_PROCESS_CPUTIME_ID);
    const bool ok = buildHierarchy3D(objects, settings, h);
    const double childCpu = childrenCpuSeconds() - childCpuStart;
    const double processCpu = cpuSeconds(CLOCK_PROCESS_CPUTIME_ID) - processCpuStart;
    const double bakeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    std::printf("scene: %zu objects, %zu triangles, seed %u, threads %d (0 = all); bake %s, %zu levels, %zu tets (TetGen alone: %d tets)\n",
                objects.size(), tris, seed, threads, ok ? "ok" : "FAILED", h.levels.size(), h.tetrahedronCount, tets);
    std::printf("| stage | seconds | share of bake |\n|---|---:|---:|\n");
    for (const auto& [stage, seconds] : h.timings)
        std::printf("| %s | %.3f | %.1f %% |\n", stage.c_str(), seconds, 100.0 * seconds / bakeSeconds);
    std::printf("| **whole bake** | %.3f | 100 %% |\n", bakeSeconds);
    std::printf("| TetGen alone (pczQn, in-process, same input) | %.3f | |\n", tetgenSeconds);
    std::printf("\nratio whole bake / TetGen alone: %.2fx (goal <= 1.5x)\n", bakeSeconds / tetgenSeconds);
    // CPU seconds are less sensitive than wall time to other load on a shared machine.
    std::printf("CPU seconds: TetGen alone %.3f; bake: TetGen child %.3f, this process %.3f (all threads)\n",
                tetgenCpu, childCpu, processCpu);
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
