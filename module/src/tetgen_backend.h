// SPDX-License-Identifier: AGPL-3.0-or-later
// The one place that calls TetGen 1.5 (AGPL-3+). Swap this file to change triangulator.
//
// TetGen runs in a forked child process: the Debian build keeps its assert()s and
// its error path double-frees (docs/design.md §6), so a bad input must not be able to
// take the baking process down. Results come back through a pipe.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// Piecewise linear complex: triangles of every model surface.
struct PlcInput {
    std::vector<double> points;         ///< 3 * pointCount
    std::vector<int> triangles;         ///< 3 * triangleCount, indices into points
    std::vector<int> triangleMarkers;   ///< per triangle: model index + 1 (> 0)
    /// Budget of the TetGen child: CPU seconds and bytes of address space; 0 = automatic
    /// (tetgenBudget). A child over budget is stopped and reported, never waited for.
    double cpuSeconds = 0;
    uint64_t memoryBytes = 0;
    /// Watchdog: a child that gains no CPU time for this many seconds is hung (e.g. on a lock
    /// another thread held at fork time, which no CPU limit catches): it is killed and started
    /// once more, then reported as TetgenStatus::Hung. 0 = kDefaultHangSeconds.
    double hangSeconds = 0;
};

/// Seconds without CPU progress after which a TetGen child counts as hung.
constexpr double kDefaultHangSeconds = 60.0;

/// main() of the helper executable aggrelod-tetgen, which runs TetGen for
/// tetrahedralizePlc / findIntersectingFacets: started with posix_spawn, a fresh process
/// holds no lock of the bake (a forked child can inherit one, held by another thread, and
/// deadlock). It is looked up as AGGRELOD_TETGEN_HELPER (set but empty: none), beside the
/// running executable, then in the build tree; without one a forked child does the work.
int tetgenHelperMain(int argc, char** argv);

/// The budget a PLC gets when it names none: 120 s + 0.5 ms per input triangle of CPU (about
/// 20x what TetGen needs on well-spaced input), and half the machine's physical memory.
void tetgenBudget(const PlcInput& input, double& cpuSeconds, uint64_t& memoryBytes);

/// Tetrahedral mesh of the convex hull of the input.
struct TetMesh {
    std::vector<double> points;         ///< 3 * pointCount; input points first, in input order
    std::vector<int> tets;              ///< 4 * tetCount
    std::vector<int> neighbors;         ///< 4 * tetCount; neighbor j is across the face opposite corner j; -1 = hull
    std::vector<double> regions;        ///< per tet: -1 in free space, > 0 inside a closed surface
    std::vector<int> boundaryFaces;     ///< 3 * faceCount: constrained faces (object surfaces, hull)
    std::vector<int> boundaryMarkers;   ///< per face: marker of the input facet (0 = hull)
    size_t tetCount() const { return tets.size() / 4; }
    size_t pointCount() const { return points.size() / 3; }
};

enum class TetgenStatus {
    Ok,
    SelfIntersection,  ///< input facets intersect (TetGen code 3)
    InputError,        ///< code 10, or bad PLC
    ToleranceError,    ///< codes 4/5: points or facets too close for TetGen's tolerance
    OutOfMemory,       ///< code 1
    InternalError,     ///< code 2, or anything else TetGen reported
    Crashed,           ///< the child process died (assert, signal)
    OverBudget,        ///< the child used up its CPU time budget and was stopped
    Hung               ///< the child made no progress (twice) and was stopped
};

struct TetgenOutcome {
    TetgenStatus status = TetgenStatus::Ok;
    std::string message;
};

/// Constrained Delaunay tetrahedralization of the PLC, keeping its convex hull
/// (switches "pczQn", no hole points: free space is region -1). `extraSwitches` are
/// appended (the fallbacks "Y", "M" help where TetGen's boundary recovery trips).
TetgenOutcome tetrahedralizePlc(const PlcInput& input, TetMesh& out, const char* extraSwitches = "");

/// Finds intersecting input triangles (TetGen switch d). `intersectingMarkers` gets the
/// sorted, unique markers of every triangle involved in an intersection.
TetgenOutcome findIntersectingFacets(const PlcInput& input, std::vector<int>& intersectingMarkers);

const char* tetgenStatusName(TetgenStatus status);

}  // namespace aggrelod::detail
