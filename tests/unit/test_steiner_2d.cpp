// SPDX-License-Identifier: AGPL-3.0-or-later
// Steiner points inserted into the flat triangulation (module/src/steiner_2d.cpp) against
// CGAL: after insertSplitPoints2D + renumberAfterSplits2D the triangulation must be the one
// CGAL builds from scratch for all the points with the split segments as constraint chains
// (a constrained Delaunay triangulation with CGAL's perturbation is unique, and both are
// numbered canonically once the faces are put in canonical order), array for array.
#include "cdt_2d.h"
#include "steiner_2d.h"

#include <aggrelod/environments2d.h>
#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <utility>
#include <vector>

using namespace aggrelod;
using namespace aggrelod::detail;

namespace {

struct Rings {
    std::vector<double> points;
    std::vector<std::pair<size_t, size_t>> segments;  // segment i starts at point i
};

Rings ringsOf(const std::vector<Feature2D>& features) {
    Rings r;
    for (const Feature2D& f : features)
        for (const Polygon2D& p : f.polygons) {
            const size_t first = r.points.size() / 2, n = p.exterior.size() / 2;
            r.points.insert(r.points.end(), p.exterior.begin(), p.exterior.end());
            for (size_t i = 0; i < n; ++i) r.segments.emplace_back(first + i, first + (i + 1) % n);
        }
    return r;
}

struct Coverage {
    size_t applied = 0, onHullInside = 0, onHullOutside = 0, offLine = 0;
};

// Splits about one segment in three at 1-3 seeded parameters, inserts them and compares with
// CGAL's triangulation of everything.
void expectSameAsCgal(const std::string& name, const Rings& rings, uint32_t seed, Coverage& coverage) {
    SCOPED_TRACE(name);
    ConstrainedTriangulation2D cgal;
    Triangulation2D tri;
    std::string error;
    ASSERT_TRUE(cgal.build(rings.points, rings.segments, tri, error, 1)) << error;
    samples::Random rnd(seed);
    std::vector<ConstraintSplit> splits;
    for (const auto& [from, to] : rings.segments) {
        if (rnd.uniform01() > 0.35) continue;
        ConstraintSplit s;
        s.from = from;
        s.to = to;
        const int count = rnd.uniformInt(1, 3);
        for (int j = 0; j < count; ++j) {
            const double t = (j + rnd.uniform(0.2, 0.8)) / count;  // ascending
            s.points.push_back(rings.points[2 * from] + t * (rings.points[2 * to] - rings.points[2 * from]));
            s.points.push_back(rings.points[2 * from + 1] + t * (rings.points[2 * to + 1] - rings.points[2 * from + 1]));
        }
        splits.push_back(std::move(s));
    }
    // Which splits sit on the convex hull, and on which side of the segment (rounding) each point is.
    std::vector<char> onHull(splits.size(), 0);
    for (size_t f = 0; f < tri.faceCount(); ++f)
        for (int j = 0; j < 3; ++j)
            if (tri.neighbors[3 * f + j] < 0)
                for (size_t k = 0; k < splits.size(); ++k) {
                    const int a = tri.inputVertex[splits[k].from], b = tri.inputVertex[splits[k].to];
                    const int u = tri.faces[3 * f + (j + 1) % 3], w = tri.faces[3 * f + (j + 2) % 3];
                    if ((u == a && w == b) || (u == b && w == a)) onHull[k] = 1;
                }
    const std::vector<double> firstPoints = tri.points;
    std::vector<uint32_t> applied;
    std::vector<int> firstVertex;
    insertSplitPoints2D(tri, splits, applied, firstVertex);
    for (size_t k = 0; k < splits.size(); ++k) {
        coverage.applied += applied[k];
        for (uint32_t j = 0; j < applied[k]; ++j) {
            const double* p = &splits[k].points[2 * j];
            const int side = orientation2D(&rings.points[2 * splits[k].from], &rings.points[2 * splits[k].to], p);
            coverage.offLine += side != 0;
            if (onHull[k] && side > 0) ++coverage.onHullInside;
            if (onHull[k] && side < 0) ++coverage.onHullOutside;
        }
    }
    // The same input with the applied points after their segment's start, as the pipeline numbers it.
    Rings all;
    std::vector<size_t> newInputIndex(rings.points.size() / 2);
    std::vector<long long> splitFirstIndex(splits.size(), -1);
    std::vector<size_t> splitOfSegment(rings.segments.size(), SIZE_MAX);
    for (size_t k = 0; k < splits.size(); ++k) splitOfSegment[splits[k].from] = k;
    for (size_t i = 0; i < rings.points.size() / 2; ++i) {
        newInputIndex[i] = all.points.size() / 2;
        all.points.push_back(rings.points[2 * i]);
        all.points.push_back(rings.points[2 * i + 1]);
        const size_t k = splitOfSegment[i];
        if (k == SIZE_MAX) continue;
        if (applied[k] > 0) splitFirstIndex[k] = static_cast<long long>(all.points.size() / 2);
        for (uint32_t j = 0; j < applied[k]; ++j) {
            all.points.push_back(splits[k].points[2 * j]);
            all.points.push_back(splits[k].points[2 * j + 1]);
        }
    }
    for (const auto& [from, to] : rings.segments) {
        size_t previous = newInputIndex[from];
        const size_t k = splitOfSegment[from];
        for (uint32_t j = 0; k != SIZE_MAX && j < applied[k]; ++j) {
            all.segments.emplace_back(previous, static_cast<size_t>(splitFirstIndex[k]) + j);
            previous = static_cast<size_t>(splitFirstIndex[k]) + j;
        }
        all.segments.emplace_back(previous, newInputIndex[to]);
    }
    renumberAfterSplits2D(tri, newInputIndex, splitFirstIndex, applied, firstVertex, all.points.size() / 2);
    canonicalizeFaces2D(tri, 2);
    ConstrainedTriangulation2D fresh;
    Triangulation2D expected;
    ASSERT_TRUE(fresh.build(all.points, all.segments, expected, error, 1)) << error;
    EXPECT_EQ(tri.points, expected.points);
    EXPECT_EQ(tri.vertexInput, expected.vertexInput);
    EXPECT_EQ(tri.inputVertex, expected.inputVertex);
    EXPECT_EQ(tri.faces, expected.faces);
    EXPECT_EQ(tri.neighbors, expected.neighbors);
    EXPECT_EQ(tri.constrained, expected.constrained);
    EXPECT_GT(tri.vertexCount(), firstPoints.size() / 2);
}

}  // namespace

TEST(Steiner2D, SplitPointsGiveTheTriangulationCgalBuildsFromScratch) {
    Coverage coverage;
    for (uint32_t seed = 1; seed <= 6; ++seed)
        expectSameAsCgal("grid seed " + std::to_string(seed), ringsOf(samples::makeSquareGrid(300, 1.0, 0.5, 0.2, seed)), seed,
                         coverage);
    expectSameAsCgal("unjittered grid (collinear hull edges)", ringsOf(samples::makeSquareGrid(100, 1.0, 0.5, 0, 1)), 7, coverage);
    for (samples::Environment2D env : samples::allEnvironments2D())
        expectSameAsCgal(samples::environmentName(env), ringsOf(samples::makeEnvironment2D(env, 1)), 11, coverage);
    // The cases the insertion treats apart were all met: points a rounding error off their
    // segment, on hull edges inside the hull (CGAL keeps a flat face) and outside it.
    EXPECT_GT(coverage.applied, 1000u);
    EXPECT_GT(coverage.offLine, 100u);
    EXPECT_GT(coverage.onHullInside, 0u);
    EXPECT_GT(coverage.onHullOutside, 0u);
}

TEST(Steiner2D, PointOffItsSegmentIsRefusedAndChangesNothing) {
    // Two squares; the split asks for a point far off the bottom edge of the first one, so a
    // face would be inverted: nothing is inserted and the triangulation stays as it was.
    const Rings rings = ringsOf(samples::makeSquareGrid(2, 1.0, 0.5, 0, 1));
    ConstrainedTriangulation2D cgal;
    Triangulation2D tri;
    std::string error;
    ASSERT_TRUE(cgal.build(rings.points, rings.segments, tri, error, 1)) << error;
    const Triangulation2D before = tri;
    ConstraintSplit split;
    split.from = 0;  // (0, 0) -> (1, 0)
    split.to = 1;
    split.points = {0.5, -3.0};
    ConstraintSplit notAnEdge;  // (0, 0) -> (1, 1) is a diagonal, not a constrained edge
    notAnEdge.from = 0;
    notAnEdge.to = 2;
    notAnEdge.points = {0.5, 0.5};
    std::vector<uint32_t> applied;
    std::vector<int> firstVertex;
    insertSplitPoints2D(tri, {split, notAnEdge}, applied, firstVertex);
    EXPECT_EQ(applied, (std::vector<uint32_t>{0, 0}));
    EXPECT_EQ(tri.points, before.points);
    EXPECT_EQ(tri.faces, before.faces);
    EXPECT_EQ(tri.neighbors, before.neighbors);
    EXPECT_EQ(tri.constrained, before.constrained);
}

TEST(ConstrainedTriangulation2D, CancelledBuildStopsWithoutAMessage) {
    const Rings rings = ringsOf(samples::makeSquareGrid(500, 1.0, 0.5, 0.2, 1));
    ConstrainedTriangulation2D cgal;
    Triangulation2D tri;
    std::string error = "unchanged";
    const std::atomic<bool> cancel{true};
    EXPECT_FALSE(cgal.build(rings.points, rings.segments, tri, error, 1, &cancel));
    EXPECT_TRUE(error.empty());
    const std::atomic<bool> goOn{false};
    EXPECT_TRUE(cgal.build(rings.points, rings.segments, tri, error, 1, &goOn)) << error;
    EXPECT_GT(tri.faceCount(), 1000u);
}
