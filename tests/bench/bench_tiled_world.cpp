// SPDX-License-Identifier: AGPL-3.0-or-later
// Tiled against untiled bake of one generated open world (docs/benchmarks.md, "Worlds"):
//   bench_tiled_world [objects=4000] [tile=96] [threads=2] [seed=1] [deltas=0.5,1,2,4,8,16,32,64]
// Each bake (hierarchy, then the node tree with its proxies) runs in a child process of its
// own, so its peak memory (ru_maxrss from wait4) is its own. Terrain tiles and roads are the
// support surfaces. Prints a Markdown table: seconds of the hierarchy and of the proxies,
// peak memory, nodes; then, per level, how many tiled groups differ from the untiled ones;
// and the checks of the tiled tree (every cut covers every object once: each node's sources
// are the disjoint union of its children's; every certified error within its budget).
#include "generated_world.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/tiled_bake_3d.h>
#include <aggrelod/world.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace aggrelod;

namespace {

struct Options {
    uint64_t objects = 4000;
    double tile = 96;
    int threads = 2;
    uint32_t seed = 1;
    std::vector<double> deltas{0.5, 1, 2, 4, 8, 16, 32, 64};
};

/// Bakes in this (child) process and writes the figures and the groups to `path`.
int bakeInChild(const Options& o, bool tiled, const std::string& path) {
    const std::vector<InputObject> objects = aggrelod::testing::generatedWorld(o.objects, o.seed);
    Settings3D settings;
    settings.deltas = o.deltas;
    settings.threadCount = o.threads;
    settings.support = SupportDetection::Given;
    for (uint32_t i = 0; i < objects.size(); ++i)
        if (objects[i].name.find("terrain") != std::string::npos || objects[i].name.find("road") != std::string::npos)
            settings.supportObjects.push_back(i);
    Hierarchy3D h;
    TiledBakeReport report;
    const auto t0 = std::chrono::steady_clock::now();
    const bool ok = tiled ? buildTiledHierarchy3D(objects, settings, o.tile, h, &report) : buildHierarchy3D(objects, settings, h);
    const auto t1 = std::chrono::steady_clock::now();
    if (!ok) {
        for (const Diagnostic& d : h.diagnostics) std::fprintf(stderr, "%s: %s\n", d.object.c_str(), d.message.c_str());
        return 1;
    }
    HierarchyNodes nodes;
    std::string error;
    ProxySettings proxies;
    proxies.threadCount = o.threads;
    if (!buildHierarchyNodes(h, objects, proxies, nodes, error)) {
        std::fprintf(stderr, "nodes: %s\n", error.c_str());
        return 1;
    }
    const auto t2 = std::chrono::steady_clock::now();
    size_t badUnion = 0, overBudget = 0;
    for (size_t i = nodes.objectCount; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& n = nodes.nodes[i];
        std::vector<uint32_t> u;
        for (uint32_t c : n.children) u.insert(u.end(), nodes.nodes[c].sources.begin(), nodes.nodes[c].sources.end());
        std::sort(u.begin(), u.end());
        badUnion += u != n.sources;
        overBudget += n.error.bound() > n.budget * (1 + 1e-9);
    }
    double tet = 0;
    for (const auto& [stage, seconds] : h.timings)
        if (stage == "tetrahedralize") tet += seconds;
    std::ofstream out(path);
    out.precision(17);
    out << std::chrono::duration<double>(t1 - t0).count() << ' ' << std::chrono::duration<double>(t2 - t1).count() << ' '
        << tet << ' ' << nodes.nodes.size() << ' ' << badUnion << ' ' << overBudget << ' ' << report.cellCount << ' '
        << report.largestCellObjects << ' ' << report.splitClusterCount << ' ' << report.clusterCount << ' '
        << h.levels.size() << '\n';
    for (const Level& level : h.levels) {
        out << level.delta << ' ' << level.aggregates.size() << '\n';
        for (const Aggregate& a : level.aggregates) {
            out << a.sourceObjects.size();
            for (uint32_t s : a.sourceObjects) out << ' ' << s;
            out << '\n';
        }
    }
    return out ? 0 : 1;
}

struct Result {
    double hierarchy = 0, proxies = 0, tetrahedralize = 0, peakMiB = 0;
    size_t nodes = 0, badUnion = 0, overBudget = 0, cells = 0, largestCell = 0, split = 0, clusters = 0;
    std::vector<double> deltas;
    std::vector<std::set<std::vector<uint32_t>>> groups;
};

bool run(const Options& o, bool tiled, Result& r) {
    const std::string path = "/tmp/bench_tiled_world_" + std::to_string(getpid()) + (tiled ? "_tiled" : "_untiled");
    std::fflush(stdout);
    const pid_t pid = fork();
    if (pid == 0) _exit(bakeInChild(o, tiled, path));
    int status = 0;
    struct rusage usage {};
    if (pid < 0 || wait4(pid, &status, 0, &usage) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0) return false;
    r.peakMiB = double(usage.ru_maxrss) / 1024.0;
    std::ifstream in(path);
    size_t levels = 0;
    in >> r.hierarchy >> r.proxies >> r.tetrahedralize >> r.nodes >> r.badUnion >> r.overBudget >> r.cells >> r.largestCell >>
        r.split >> r.clusters >> levels;
    for (size_t k = 0; k < levels; ++k) {
        double delta = 0;
        size_t count = 0;
        in >> delta >> count;
        r.deltas.push_back(delta);
        r.groups.emplace_back();
        for (size_t g = 0; g < count; ++g) {
            size_t n = 0;
            in >> n;
            std::vector<uint32_t> sources(n);
            for (uint32_t& s : sources) in >> s;
            r.groups.back().insert(std::move(sources));
        }
    }
    std::remove(path.c_str());
    return bool(in);
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    if (argc > 1) o.objects = std::strtoull(argv[1], nullptr, 10);
    if (argc > 2) o.tile = std::atof(argv[2]);
    if (argc > 3) o.threads = std::atoi(argv[3]);
    if (argc > 4) o.seed = static_cast<uint32_t>(std::strtoul(argv[4], nullptr, 10));
    if (argc > 5) {
        o.deltas.clear();
        std::stringstream list(argv[5]);
        for (std::string item; std::getline(list, item, ',');) o.deltas.push_back(std::atof(item.c_str()));
    }
    Result untiled, tiled;
    if (!run(o, false, untiled) || !run(o, true, tiled)) {
        std::fprintf(stderr, "bench_tiled_world: a bake failed\n");
        return 1;
    }
    std::printf("world of %llu objects (seed %u), tile %g (cells hold delta <= %g), %d threads\n\n",
                static_cast<unsigned long long>(o.objects), o.seed, o.tile, o.tile / 8, o.threads);
    std::printf("| bake | hierarchy s | of it tetrahedralize s | proxies s | total s | peak MiB | nodes | cells (largest) |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const auto& [name, r] : {std::make_pair("untiled", &untiled), std::make_pair("tiled", &tiled)})
        std::printf("| %s | %.1f | %.1f | %.1f | %.1f | %.0f | %zu | %zu (%zu) |\n", name, r->hierarchy, r->tetrahedralize,
                    r->proxies, r->hierarchy + r->proxies, r->peakMiB, r->nodes, r->cells, r->largestCell);
    std::printf("\n| level | delta | untiled groups | tiled groups | tiled groups not in the untiled bake |\n");
    std::printf("|---:|---:|---:|---:|---:|\n");
    for (size_t k = 0; k < std::min(untiled.groups.size(), tiled.groups.size()); ++k) {
        size_t differ = 0;
        for (const auto& g : tiled.groups[k]) differ += untiled.groups[k].count(g) ? 0 : 1;
        std::printf("| %zu | %g%s | %zu | %zu | %zu (%.1f %%) |\n", k, tiled.deltas[k], tiled.deltas[k] <= o.tile / 8 ? " (cell)" : "",
                    untiled.groups[k].size(), tiled.groups[k].size(), differ,
                    100.0 * double(differ) / double(std::max<size_t>(tiled.groups[k].size(), 1)));
    }
    std::printf("\nclusters wider than a tile, split: %zu of %zu\n", tiled.split, tiled.clusters);
    std::printf("tiled tree: %zu nodes whose sources are not the union of their children's, %zu over budget\n",
                tiled.badUnion, tiled.overBudget);
    return tiled.badUnion || tiled.overBudget ? 1 : 0;
}
