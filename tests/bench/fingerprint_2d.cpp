// SPDX-License-Identifier: AGPL-3.0-or-later
// Developer check for speed work on the 2D pipeline: prints one hash per case of everything
// buildHierarchy2D returns (every level's polygons, sources, measures and baselines, the
// dendrogram, models, diagnostics, triangulation size), timings excepted. Two builds that
// print the same lines give byte-identical outputs on these inputs. Cases: the five paper
// environments (adaptive, constant, hull), jittered square grids, the real data sets of
// ../shared/data/2d and 300 random overlapping / touching / holed polygon sets, with 1 and
// 2 threads. Usage: fingerprint_2d [random seeds=300] [--each (a line per random set)]
#include "geo_io.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

using namespace aggrelod;

namespace {

struct Hash {
    uint64_t h = 1469598103934665603ull;
    void bytes(const void* p, size_t n) {
        const unsigned char* c = static_cast<const unsigned char*>(p);
        for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
    }
    void d(double x) { bytes(&x, sizeof x); }
    void u(uint64_t x) { bytes(&x, sizeof x); }
    void s(const std::string& x) { u(x.size()), bytes(x.data(), x.size()); }
    void ring(const std::vector<double>& r) {
        u(r.size());
        for (double x : r) d(x);
    }
    void measures(const Measures2D& m) { d(m.area), d(m.perimeter), d(m.circularity); }
};

uint64_t fingerprint(const Hierarchy2D& h, bool ok) {
    Hash x;
    x.u(ok);
    x.u(h.levels.size());
    for (const Level2D& l : h.levels) {
        x.d(l.delta);
        x.measures(l.measures), x.measures(l.constant), x.measures(l.adaptive), x.measures(l.hull);
        x.u(l.aggregates.size());
        for (const Aggregate2D& a : l.aggregates) {
            x.measures(a.measures);
            for (uint32_t s : a.sourceFeatures) x.u(s);
            x.u(a.polygons.size());
            for (const Polygon2D& p : a.polygons) {
                x.ring(p.exterior);
                x.u(p.holes.size());
                for (const auto& hole : p.holes) x.ring(hole);
            }
        }
    }
    for (int m : h.featureModel) x.u(static_cast<uint64_t>(m));
    x.u(h.modelCount);
    for (const Merge& m : h.merges) x.u(m.modelA), x.u(m.modelB), x.d(m.height);
    x.measures(h.originals);
    for (const Diagnostic& d : h.diagnostics) x.u(static_cast<uint64_t>(d.severity)), x.s(d.object), x.s(d.message);
    x.u(h.vertexCount), x.u(h.triangleCount), x.d(h.freeEdgeMin), x.d(h.freeEdgeMax);
    return x.h;
}

void run(const std::string& name, const std::vector<Feature2D>& features, Settings2D settings, bool bothThreadCounts = true) {
    for (int threads : {1, 2}) {
        if (threads == 1 && !bothThreadCounts) continue;
        settings.threadCount = threads;
        Hierarchy2D h;
        const bool ok = buildHierarchy2D(features, settings, h);
        std::printf("%-40s threads %d  %016llx  (%zu triangles, %zu levels)\n", name.c_str(), threads,
                    static_cast<unsigned long long>(fingerprint(h, ok)), h.triangleCount, h.levels.size());
    }
}

}  // namespace

int main(int argc, char** argv) {
    const uint32_t randomSeeds = argc > 1 ? static_cast<uint32_t>(std::atoi(argv[1])) : 300;
    const bool eachSeed = argc > 2 && std::strcmp(argv[2], "--each") == 0;  // one line per random set
    const std::pair<AggregateFunctionKind, const char*> functions[] = {{AggregateFunctionKind::Adaptive, "adaptive"},
                                                                       {AggregateFunctionKind::Constant, "constant"}};
    for (samples::Environment2D env : samples::allEnvironments2D()) {
        const std::vector<Feature2D> features = samples::makeEnvironment2D(env, 1);
        for (const auto& [kind, fname] : functions) {
            Settings2D s;
            s.function = kind;
            run(samples::environmentName(env) + " " + fname, features, s);
        }
        Settings2D hull;
        hull.shape = Shape2D::ConvexHull;
        run(samples::environmentName(env) + " hull", features, hull);
    }
    for (int n : {1000, 10000}) {
        Settings2D s;
        s.function = AggregateFunctionKind::Constant;
        s.computeBaselines = false;
        for (double k : {0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0, 8.0}) s.deltas.push_back(k * 0.45);
        run("grid " + std::to_string(n) + " bench", samples::makeSquareGrid(n, 1.0, 0.5, 0.2, 1), s);
        Settings2D a;
        run("grid " + std::to_string(n) + " adaptive", samples::makeSquareGrid(n, 1.0, 0.5, 0.2, 1), a, n <= 1000);
    }
    for (const char* file : {"land50m_islands", "naturalearth_lowres", "nc_counties", "london_boroughs", "olinda_tracts"}) {
        io::GeoReadResult data;
        std::string error;
        if (!io::readPolygonFile(std::string(AGGRELOD_SHARED_DATA) + "/2d/" + file + ".wkt", data, error)) {
            std::printf("%s: %s\n", file, error.c_str());
            continue;
        }
        for (const auto& [kind, fname] : functions) {
            Settings2D s;
            s.function = kind;
            run(std::string(file) + " " + fname, data.features, s);
        }
        Settings2D zero;
        zero.deltas = {0, 0.5};
        run(std::string(file) + " delta 0, 0.5", data.features, zero, false);
    }
    Hash all;
    for (uint32_t seed = 1; seed <= randomSeeds; ++seed) {
        Settings2D s;
        s.automaticLevelCount = 3;
        s.function = seed % 2 ? AggregateFunctionKind::Constant : AggregateFunctionKind::Adaptive;
        s.threadCount = 1 + seed % 2;
        Hierarchy2D h;
        const bool ok = buildHierarchy2D(samples::makeRandomOverlappingPolygons(seed), s, h);
        all.u(fingerprint(h, ok));
        if (eachSeed)
            std::printf("random polygons seed %u  %016llx\n", seed, static_cast<unsigned long long>(fingerprint(h, ok)));
    }
    std::printf("%-40s           %016llx\n", ("random polygons x" + std::to_string(randomSeeds)).c_str(),
                static_cast<unsigned long long>(all.h));
    return 0;
}
