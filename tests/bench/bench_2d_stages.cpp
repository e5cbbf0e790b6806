// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: where the 2D pipeline's time goes (issue 3), on the jittered square grids of
// bench_geos (unit squares, gaps 0.5 +- 0.2, constant function, 8 levels 0.25..8 x 0.45, no
// baselines: the same settings as bench_geos). Prints, per grid size, the median over the
// runs of every stage of Hierarchy2D::timings and of the whole buildHierarchy2D call.
// Usage: bench_2d_stages [runs=9] [threads=0] [sizes...=10000 40000]
#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

using namespace aggrelod;

int main(int argc, char** argv) {
    const int runs = argc > 1 ? std::max(1, std::atoi(argv[1])) : 9;
    const int threads = argc > 2 ? std::atoi(argv[2]) : 0;
    std::vector<int> sizes;
    for (int i = 3; i < argc; ++i) sizes.push_back(std::atoi(argv[i]));
    if (sizes.empty()) sizes = {10000, 40000};
    auto median = [](std::vector<double> v) {
        std::sort(v.begin(), v.end());
        return v.empty() ? 0.0 : v[v.size() / 2];
    };
    std::printf("median of %d runs, threads %d (0 = all cores), milliseconds\n\n", runs, threads);
    for (int n : sizes) {
        const std::vector<Feature2D> features = samples::makeSquareGrid(n, 1.0, 0.5, 0.2, 1);
        Settings2D settings;
        settings.function = AggregateFunctionKind::Constant;
        settings.computeBaselines = false;
        settings.threadCount = threads;
        for (double k : {0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0, 8.0}) settings.deltas.push_back(k * 0.45);
        std::vector<std::string> order;
        std::map<std::string, std::vector<double>> stage;
        std::vector<double> total;
        size_t triangles = 0;
        for (int r = 0; r < runs; ++r) {
            Hierarchy2D h;
            const auto t0 = std::chrono::steady_clock::now();
            if (!buildHierarchy2D(features, settings, h)) {
                std::printf("grid %d: failed\n", n);
                return 1;
            }
            total.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            triangles = h.triangleCount;
            for (const auto& [name, seconds] : h.timings) {
                if (!stage.count(name)) order.push_back(name);
                stage[name].push_back(seconds);
            }
        }
        std::printf("grid %d squares, %zu triangles\n| stage | ms |\n|---|---:|\n", n, triangles);
        for (const std::string& name : order) std::printf("| %s | %.1f |\n", name.c_str(), 1e3 * median(stage[name]));
        std::printf("| **total (buildHierarchy2D)** | **%.1f** |\n\n", 1e3 * median(total));
    }
    return 0;
}
