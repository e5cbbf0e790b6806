// SPDX-License-Identifier: AGPL-3.0-or-later
// Few-faced enclosing polytopes of a convex hull (module/src/bounding_polytope.cpp): each one
// is a closed, outward convex mesh that contains the hull, its stated distance to the hull is
// the true one, and the series reaches down to a tetrahedron.
#include "bounding_polytope.h"
#include "convex_hull.h"
#include "mesh_distance.h"
#include "test_support.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <map>
#include <random>

namespace aggrelod::testing {
namespace {

/// Every directed edge once and its reverse once, and a positive volume.
bool closedOutward(const std::vector<double>& positions, const std::vector<uint32_t>& triangles) {
    return edgeManifoldProblem(triangles).empty() && signedVolume(positions, triangles) > 0;
}

/// Checks every polytope of the series of `points`' convex hull; returns the fewest triangles
/// of one within maxDistance of the hull (0 when none).
size_t checkSeries(const std::vector<double>& points, double maxDistance) {
    std::vector<double> hull;
    std::vector<uint32_t> hullTriangles;
    EXPECT_TRUE(detail::convexHull3(points, hull, hullTriangles));
    detail::TriangleBvh bvh;
    bvh.build(hull.data(), hull.size() / 3, hullTriangles.data(), hullTriangles.size() / 3);
    const auto series = detail::boundingPolytopes(hull, hullTriangles, 24, 0.0);
    EXPECT_FALSE(series.empty());
    size_t fewest = 0;
    bool tetrahedron = false;
    for (const detail::BoundingPolytope& p : series) {
        std::vector<double> positions;
        std::vector<uint32_t> triangles;
        // Contains every input point strictly (boundingPolytopeMesh checks it), closed, outward.
        EXPECT_TRUE(detail::boundingPolytopeMesh(p, points, positions, triangles));
        EXPECT_TRUE(closedOutward(positions, triangles));
        EXPECT_LE(positions.size() / 3, 24u);
        tetrahedron |= triangles.size() == 12;
        // The stated distance is the largest over the polytope: its vertices reach it, and
        // no sampled surface point lies farther.
        double atVertices = 0;
        for (size_t v = 0; v < positions.size(); v += 3)
            atVertices = std::max(atVertices, detail::closestPoint(bvh, &positions[v]).distance);
        EXPECT_NEAR(atVertices, p.distanceToHull, 1e-9 + 1e-6 * p.distanceToHull);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> u(0, 1);
        for (size_t t = 0; t < triangles.size(); t += 3)
            for (int s = 0; s < 8; ++s) {
                double a = u(rng), b = u(rng);
                if (a + b > 1) a = 1 - a, b = 1 - b;
                double q[3];
                for (int k = 0; k < 3; ++k)
                    q[k] = positions[3 * triangles[t] + k] + a * (positions[3 * triangles[t + 1] + k] - positions[3 * triangles[t] + k]) +
                           b * (positions[3 * triangles[t + 2] + k] - positions[3 * triangles[t] + k]);
                EXPECT_LE(detail::closestPoint(bvh, q).distance, p.distanceToHull * (1 + 1e-9) + 1e-12);
            }
        if (p.distanceToHull <= maxDistance && (fewest == 0 || triangles.size() / 3 < fewest)) fewest = triangles.size() / 3;
    }
    EXPECT_TRUE(tetrahedron) << "the coarsest polytope is a tetrahedron";
    return fewest;
}

TEST(BoundingPolytope, SphereGetsFewFacedEnclosures) {
    const InputObject sphere = samples::makeUvSphere("sphere", {1, 2, 3}, 1.0, 48, 24);
    // The circumscribed octahedron: 8 triangles, sqrt(3) - 1 = 0.73 radii away (the cube needs
    // 12); within a quarter of the radius, 24 vertices (44 triangles; the circumscribed
    // icosahedron would need 20, but only a perfect sphere keeps its corners from splitting).
    EXPECT_LE(checkSeries(sphere.positions, 0.75), 8u);
    const size_t fine = checkSeries(sphere.positions, 0.26);
    EXPECT_GT(fine, 0u);
    EXPECT_LE(fine, 44u);
}

TEST(BoundingPolytope, RandomPointCloudsOfManySeeds) {
    for (uint32_t seed = 1; seed <= 12; ++seed) {
        std::mt19937 rng(seed);
        std::normal_distribution<double> g;
        std::vector<double> points;
        const double stretch[3] = {1.0 + 4.0 * (seed % 3), 1.0, 0.2 + 0.3 * (seed % 4)};
        for (int i = 0; i < 200; ++i)
            for (int k = 0; k < 3; ++k) points.push_back(100.0 * seed + stretch[k] * g(rng));
        SCOPED_TRACE("seed " + std::to_string(seed));
        checkSeries(points, 1e9);
    }
}

TEST(BoundingPolytope, DegenerateInputGivesNone) {
    const std::vector<double> flat = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
    EXPECT_TRUE(detail::boundingPolytopes(flat, {0, 1, 2, 1, 3, 2}, 24, 0.0).empty());
    EXPECT_TRUE(detail::boundingPolytopes({}, {}, 24, 0.0).empty());
}

}  // namespace
}  // namespace aggrelod::testing
