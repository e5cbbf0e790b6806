// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark: aggrelod 2D (constant function, paper Eq. 1) against GEOS 3.11
// ConcaveHullOfPolygons, the strongest open peer, at the same edge-length threshold.
//
// GEOS takes a length ratio r, not a length: L = r * (max - min) + min over the
// unconstrained edges of ITS triangulation (GEOS computeTargetEdgeLength; its C API takes the ratio, whatever its doc comment says). That
// triangulation has a frame around the input (the envelope grown by 4 diagonals on each
// side) whose corners change which long edges exist near the convex hull, so min / max are
// not those of aggrelod's triangulation. geosEdgeRange() rebuilds GEOS's triangulation (a
// constrained Delaunay triangulation is unique up to co-circular ties) and reads min / max
// the way GEOS does, so that L = delta exactly; the table prints L. aggrelod builds ALL its levels (8 thresholds); GEOS builds one. Figures: seconds,
// added area (relative to the originals), validity (GEOSisValid), and the longest boundary
// edge of the output that does not lie on an input boundary versus delta.
// GEOS time grows about with the square of the polygon count: it is skipped above 10k.
#include "cdt_2d.h"  // aggrelod's CGAL wrapper, for GEOS's edge-length range
#include "geo_io.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>

#include <geos_c.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <sys/wait.h>
#include <unistd.h>

using namespace aggrelod;

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

GEOSContextHandle_t H;
constexpr int kRuns = 9;                         // aggrelod runs per figure (median)
constexpr int kGeosRuns = 3;                     // GEOS runs per figure (median; its time varies by ~20%)
constexpr int kScalingPairs = 9;                 // alternating 10k / 40k runs for the scaling figure

std::string lastGeosError;

void recordGeosError(const char* fmt, ...) {
    char buf[512];
    va_list args;
    va_start(args, fmt);
    std::vsnprintf(buf, sizeof buf, fmt, args);
    va_end(args);
    lastGeosError = buf;
}

GEOSGeometry* ring(const std::vector<double>& xy) {
    const unsigned n = static_cast<unsigned>(xy.size() / 2);
    GEOSCoordSequence* seq = GEOSCoordSeq_create_r(H, n + 1, 2);
    for (unsigned i = 0; i <= n; ++i) GEOSCoordSeq_setXY_r(H, seq, i, xy[2 * (i % n)], xy[2 * (i % n) + 1]);
    return GEOSGeom_createLinearRing_r(H, seq);
}

GEOSGeometry* multiPolygon(const std::vector<Polygon2D>& polys) {
    std::vector<GEOSGeometry*> parts;
    for (const Polygon2D& p : polys) {
        std::vector<GEOSGeometry*> holes;
        for (const auto& h : p.holes) holes.push_back(ring(h));
        parts.push_back(GEOSGeom_createPolygon_r(H, ring(p.exterior), holes.data(), static_cast<unsigned>(holes.size())));
    }
    return GEOSGeom_createCollection_r(H, GEOS_MULTIPOLYGON, parts.data(), static_cast<unsigned>(parts.size()));
}

std::vector<double> ringOf(const GEOSGeometry* r) {
    const GEOSCoordSequence* seq = GEOSGeom_getCoordSeq_r(H, r);
    unsigned n = 0;
    GEOSCoordSeq_getSize_r(H, seq, &n);
    std::vector<double> xy;
    for (unsigned i = 0; i + 1 < n; ++i) {  // drop the closing position
        double x, y;
        GEOSCoordSeq_getXY_r(H, seq, i, &x, &y);
        xy.push_back(x);
        xy.push_back(y);
    }
    return xy;
}

std::vector<Polygon2D> polygonsOf(const GEOSGeometry* g) {
    std::vector<Polygon2D> out;
    const int n = GEOSGetNumGeometries_r(H, g);
    for (int i = 0; i < n; ++i) {
        const GEOSGeometry* p = GEOSGetGeometryN_r(H, g, i);
        if (GEOSGeomTypeId_r(H, p) != GEOS_POLYGON) continue;
        Polygon2D poly;
        poly.exterior = ringOf(GEOSGetExteriorRing_r(H, p));
        for (int k = 0; k < GEOSGetNumInteriorRings_r(H, p); ++k) poly.holes.push_back(ringOf(GEOSGetInteriorRingN_r(H, p, k)));
        out.push_back(std::move(poly));
    }
    return out;
}

/// Longest output ring edge whose midpoint is not on an input boundary.
double longestFreeEdge(const std::vector<Polygon2D>& output, const GEOSPreparedGeometry* inputBoundary, double tol) {
    double longest = 0;
    auto scan = [&](const std::vector<double>& r) {
        const size_t n = r.size() / 2;
        for (size_t i = 0; i < n; ++i) {
            const size_t j = (i + 1) % n;
            const double len = std::hypot(r[2 * j] - r[2 * i], r[2 * j + 1] - r[2 * i + 1]);
            if (len <= longest) continue;
            GEOSGeometry* mid = GEOSGeom_createPointFromXY_r(H, 0.5 * (r[2 * i] + r[2 * j]), 0.5 * (r[2 * i + 1] + r[2 * j + 1]));
            double d = 0;
            GEOSPreparedDistance_r(H, inputBoundary, mid, &d);
            GEOSGeom_destroy_r(H, mid);
            if (d > tol) longest = len;
        }
    };
    for (const Polygon2D& p : output) {
        scan(p.exterior);
        for (const auto& h : p.holes) scan(h);
    }
    return longest;
}

/// Shortest and longest edge GEOS's computeTargetEdgeLength() sees for `shells` (x y rings,
/// unclosed): triangulate the frame polygon (envelope grown by FRAME_EXPAND_FACTOR = 4
/// diagonals) with the shells as holes; over the triangles outside the shells with no frame
/// corner, every edge with a triangle on both sides.
std::pair<double, double> geosEdgeRange(const std::vector<std::vector<double>>& shells) {
    std::vector<double> points;
    std::vector<std::pair<size_t, size_t>> segments;
    double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY;
    for (const auto& r : shells) {
        const size_t first = points.size() / 2, n = r.size() / 2;
        for (size_t i = 0; i < n; ++i) {
            minX = std::min(minX, r[2 * i]), maxX = std::max(maxX, r[2 * i]);
            minY = std::min(minY, r[2 * i + 1]), maxY = std::max(maxY, r[2 * i + 1]);
            segments.emplace_back(first + i, first + (i + 1) % n);
        }
        points.insert(points.end(), r.begin(), r.end());
    }
    const size_t frameFirst = points.size() / 2;
    const double grow = 4 * std::hypot(maxX - minX, maxY - minY);
    for (double c : {minX - grow, minY - grow, maxX + grow, minY - grow, maxX + grow, maxY + grow, minX - grow, maxY + grow})
        points.push_back(c);
    for (size_t i = 0; i < 4; ++i) segments.emplace_back(frameFirst + i, frameFirst + (i + 1) % 4);
    detail::Triangulation2D tri;
    detail::ConstrainedTriangulation2D cdt;
    std::string error;
    if (!cdt.build(points, segments, tri, error)) return {0, 0};
    // Outside the shells: flood from the hull (the frame), crossing a constraint flips sides.
    const size_t faces = tri.faceCount();
    std::vector<int> side(faces, -1), queue;
    for (size_t f = 0; f < faces; ++f)
        for (int j = 0; j < 3; ++j)
            if (tri.neighbors[3 * f + j] < 0 && side[f] < 0) side[f] = 0, queue.push_back(static_cast<int>(f));
    for (size_t head = 0; head < queue.size(); ++head) {
        const int f = queue[head];
        for (int j = 0; j < 3; ++j) {
            const int n = tri.neighbors[3 * f + j];
            if (n < 0 || side[n] >= 0) continue;
            side[n] = side[f] ^ (tri.constrained[3 * f + j] ? 1 : 0);
            queue.push_back(n);
        }
    }
    double lo = INFINITY, hi = -INFINITY;
    for (size_t f = 0; f < faces; ++f) {
        if (side[f] != 0) continue;
        const int* v = &tri.faces[3 * f];
        bool frame = false;
        for (int k = 0; k < 3; ++k) frame |= tri.vertexInput[v[k]] >= static_cast<int>(frameFirst);
        if (frame) continue;
        for (int j = 0; j < 3; ++j) {
            if (tri.constrained[3 * f + j] || tri.neighbors[3 * f + j] < 0) continue;
            const int a = v[(j + 1) % 3], b = v[(j + 2) % 3];
            const double len = std::hypot(tri.points[2 * b] - tri.points[2 * a], tri.points[2 * b + 1] - tri.points[2 * a + 1]);
            lo = std::min(lo, len), hi = std::max(hi, len);
        }
    }
    return {lo, hi};
}

double totalArea(const std::vector<Polygon2D>& polys) {
    GEOSGeometry* g = multiPolygon(polys);
    double a = 0;
    GEOSArea_r(H, g, &a);
    GEOSGeom_destroy_r(H, g);
    return a;
}

/// One GEOS run, measured in a child process.
struct GeosRun {
    double seconds = 0;
    bool ok = false, valid = false;
    double addedArea = 0, longestFreeEdge = 0;  // of the output (withMeasures only)
    char error[256] = "";
};

/// Forks; the child times GEOSConcaveHullOfPolygons_r on its copy of `input`, measures the
/// output when asked (untimed), writes the result to a pipe and exits.
GeosRun geosInChild(const GEOSGeometry* input, double ratio, double inputArea, const GEOSPreparedGeometry* inputBoundary,
                    double tol, bool withMeasures) {
    GeosRun result;
    int fds[2];
    if (pipe(fds) != 0) {
        std::snprintf(result.error, sizeof result.error, "pipe failed");
        return result;
    }
    std::fflush(stdout);
    const pid_t pid = fork();
    if (pid == 0) {
        close(fds[0]);
        GeosRun child;
        const auto t0 = Clock::now();
        GEOSGeometry* hull = GEOSConcaveHullOfPolygons_r(H, input, ratio, 1, 1);
        child.seconds = secondsSince(t0);
        child.ok = hull != nullptr;
        if (!hull) std::snprintf(child.error, sizeof child.error, "%s", lastGeosError.c_str());
        if (hull && withMeasures) {
            double a = 0;
            GEOSArea_r(H, hull, &a);
            child.addedArea = (a - inputArea) / inputArea;
            child.valid = GEOSisValid_r(H, hull) == 1;
            child.longestFreeEdge = longestFreeEdge(polygonsOf(hull), inputBoundary, tol);
        }
        const ssize_t written = write(fds[1], &child, sizeof child);
        _exit(written == static_cast<ssize_t>(sizeof child) ? 0 : 1);
    }
    close(fds[1]);
    const ssize_t got = pid > 0 ? read(fds[0], &result, sizeof result) : -1;
    close(fds[0]);
    while (pid > 0 && waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
    if (got != static_cast<ssize_t>(sizeof result)) {
        result = GeosRun{};
        std::snprintf(result.error, sizeof result.error, "GEOS child process gave no result");
    }
    return result;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

Settings2D eightLevels(double delta) {
    Settings2D settings;
    settings.function = AggregateFunctionKind::Constant;
    settings.computeBaselines = false;
    for (double k : {0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 4.0, 8.0}) settings.deltas.push_back(k * delta);
    return settings;
}

double timedBuild(const std::vector<Feature2D>& features, const Settings2D& settings, Hierarchy2D& h, bool& ok) {
    h = Hierarchy2D{};
    const auto t0 = Clock::now();
    ok = buildHierarchy2D(features, settings, h);
    return secondsSince(t0);
}

void runCase(const std::string& name, const std::vector<Feature2D>& features, double delta, bool runGeos) {
    const Settings2D settings = eightLevels(delta);
    // A first, untimed run gives the polygons aggrelod accepted (land data has a few invalid
    // ones) and the checks below.
    Hierarchy2D h;
    bool ok = true;
    timedBuild(features, settings, h, ok);
    if (!ok) {
        std::printf("| %s | aggrelod failed |\n", name.c_str());
        return;
    }
    std::vector<Polygon2D> inputsUsed;
    for (size_t f = 0; f < features.size(); ++f)
        if (h.featureModel[f] >= 0)
            for (const Polygon2D& p : features[f].polygons) {
                GEOSGeometry* g = multiPolygon({p});
                if (GEOSisValid_r(H, g) == 1) inputsUsed.push_back(p);
                GEOSGeom_destroy_r(H, g);
            }
    const double inputArea = totalArea(inputsUsed);
    GEOSGeometry* inputGeom = multiPolygon(inputsUsed);
    // GEOS needs a valid MultiPolygon: touching inputs (land data) are unioned first (not
    // timed; the grids are already valid).
    GEOSGeometry* geosInput = nullptr;
    double geosLength = NAN, ratio = 0;  // GEOS's edge-length threshold L and its length ratio
    if (runGeos) {
        geosInput = GEOSisValid_r(H, inputGeom) == 1 ? GEOSGeom_clone_r(H, inputGeom) : GEOSUnaryUnion_r(H, inputGeom);
        std::vector<std::vector<double>> shells;
        if (geosInput)
            for (const Polygon2D& p : polygonsOf(geosInput)) shells.push_back(p.exterior);
        const auto [edgeMin, edgeMax] = geosEdgeRange(shells);
        ratio = std::clamp((delta - edgeMin) / (edgeMax - edgeMin), 0.0, 1.0);
        geosLength = ratio * (edgeMax - edgeMin) + edgeMin;  // GEOS's own formula
    }
    // Input boundaries, for "edge on an input boundary".
    GEOSGeometry* boundary = GEOSBoundary_r(H, inputGeom);
    const GEOSPreparedGeometry* prepared = GEOSPrepare_r(H, boundary);
    const double tol = 1e-9 * std::max(1.0, h.freeEdgeMax);
    // Timed runs, interleaved so that both peers see the same spells of the shared machine:
    // kGeosRuns rounds of kRuns / kGeosRuns aggrelod runs and one GEOS run (aggrelod alone when
    // GEOS is skipped). Each GEOS run is a child process of its own, so that its heap (it
    // allocates and frees far more than aggrelod) leaves this process's heap as it was.
    std::vector<double> runs, geosRuns;
    GeosRun geosResult;
    for (int round = 0; round < kGeosRuns; ++round) {
        for (int r = 0; r < kRuns / kGeosRuns; ++r) runs.push_back(timedBuild(features, settings, h, ok));
        if (!geosInput || (round > 0 && !geosResult.ok)) continue;  // a failure does not get faster by repeating it
        geosResult = geosInChild(geosInput, ratio, inputArea, prepared, tol, round + 1 == kGeosRuns);
        geosRuns.push_back(geosResult.seconds);
    }
    const double ours = median(runs);
    // aggrelod: the compared level alone.
    Settings2D one = settings;
    one.deltas = {delta};
    std::vector<double> oneRuns;
    for (int r = 0; r < kRuns; ++r) {
        Hierarchy2D h1;
        oneRuns.push_back(timedBuild(features, one, h1, ok));
    }
    const double oursOne = median(oneRuns);

    const Level2D* level = nullptr;
    for (const Level2D& l : h.levels)
        if (l.delta == delta) level = &l;
    std::vector<Polygon2D> oursOut;
    size_t oursInvalid = 0;
    for (const Aggregate2D& a : level->aggregates) {
        oursOut.insert(oursOut.end(), a.polygons.begin(), a.polygons.end());
        GEOSGeometry* g = multiPolygon(a.polygons);
        oursInvalid += GEOSisValid_r(H, g) != 1;
        GEOSGeom_destroy_r(H, g);
    }
    const double oursLongest = longestFreeEdge(oursOut, prepared, tol);
    const double oursAdded = (level->measures.area - inputArea) / inputArea;

    std::string geosTime = "skipped", geosAdded = "-", geosValid = "-", geosLongest = "-", speedup = "-";
    if (runGeos) {
        const double geos = median(geosRuns);
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.3f", geos);
        geosTime = buf;
        std::snprintf(buf, sizeof buf, "%.1fx", geos / ours);
        speedup = buf;
        if (geosResult.ok) {
            std::snprintf(buf, sizeof buf, "%.4f", geosResult.addedArea);
            geosAdded = buf;
            geosValid = geosResult.valid ? "valid" : "INVALID";
            std::snprintf(buf, sizeof buf, "%.4g", geosResult.longestFreeEdge);
            geosLongest = buf;
        } else {
            geosValid = std::string("failed: ") + geosResult.error;
        }
        if (geosInput) GEOSGeom_destroy_r(H, geosInput);
    }
    std::printf("| %s | %zu | %.4g | %.3f | %.3f | %.4f | %s | %.4g | %.4g | %s | %s | %s | %s | %s |\n", name.c_str(),
                features.size(), delta, ours, oursOne, oursAdded, oursInvalid == 0 ? "valid" : (std::to_string(oursInvalid) + " INVALID").c_str(),
                oursLongest, geosLength, geosTime.c_str(), geosAdded.c_str(), geosValid.c_str(), geosLongest.c_str(), speedup.c_str());
    std::fflush(stdout);
    GEOSPreparedGeom_destroy_r(H, prepared);
    GEOSGeom_destroy_r(H, boundary);
    GEOSGeom_destroy_r(H, inputGeom);
}

// time(40k squares) / time(10k squares), all 8 levels: runs of the two alternate, so that a
// slower spell of the shared machine weighs on both; ratio of the medians, and the range of
// the per-pair ratios.
void scaling() {
    const std::vector<Feature2D> small = samples::makeSquareGrid(10000, 1.0, 0.5, 0.2, 1);
    const std::vector<Feature2D> large = samples::makeSquareGrid(40000, 1.0, 0.5, 0.2, 1);
    const Settings2D settings = eightLevels(0.45);
    std::vector<double> smallRuns, largeRuns, pairRatios;
    Hierarchy2D h;
    bool ok = true;
    for (int r = 0; r < kScalingPairs; ++r) {
        smallRuns.push_back(timedBuild(small, settings, h, ok));
        largeRuns.push_back(timedBuild(large, settings, h, ok));
        pairRatios.push_back(largeRuns.back() / smallRuns.back());
    }
    std::sort(pairRatios.begin(), pairRatios.end());
    std::printf("\naggrelod 8 levels: 40k / 10k squares = %.2fx (goal <= 5x; %d alternating pairs, medians %.3f s / %.3f s, "
                "per-pair %.2f-%.2fx)\n",
                median(largeRuns) / median(smallRuns), kScalingPairs, median(largeRuns), median(smallRuns), pairRatios.front(),
                pairRatios.back());
}

}  // namespace

int main(int argc, char** argv) {
    H = GEOS_init_r();
    GEOSContext_setErrorHandler_r(H, recordGeosError);
    const int geosLimit = argc > 1 ? std::atoi(argv[1]) : 10000;
    std::printf("GEOS %s; aggrelod builds 8 levels (0.25..8 x delta), GEOS one; GEOS skipped above %d polygons\n"
                "Timed: buildHierarchy2D (input checks, triangulation, graph, dendrogram, sculpting and polygons of\n"
                "every level with their area / perimeter; no baselines) versus GEOSConcaveHullOfPolygons_r; input\n"
                "conversion and validity checks are not timed. aggrelod: median of %d runs; GEOS: median of %d runs,\n"
                "one after every third aggrelod run.\n\n",
                GEOSversion(), geosLimit, kRuns, kGeosRuns);
    std::printf("| case | polygons | delta | aggrelod s (8 levels) | aggrelod s (1 level) | aggrelod added area | aggrelod valid | aggrelod longest free edge | "
                "GEOS L | GEOS s (1 level) | GEOS added area | GEOS valid | GEOS longest free edge | GEOS / aggrelod time |\n"
                "|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---|---:|---:|\n");
    // Unit squares, gaps 0.5 +- 0.4 (jittered grid), delta 0.45.
    for (int n : {1000, 4000, 10000, 40000})
        runCase("grid " + std::to_string(n / 1000) + "k", samples::makeSquareGrid(n, 1.0, 0.5, 0.2, 1), 0.45, n <= geosLimit);
    io::GeoReadResult land;
    std::string error;
    const std::string path = std::string(AGGRELOD_SHARED_DATA) + "/2d/land50m_islands.wkt";
    if (io::readPolygonFile(path, land, error)) runCase("land50m_islands", land.features, 0.5, true);
    else std::printf("%s\n", error.c_str());
    scaling();
    GEOS_finish_r(H);
    return 0;
}
