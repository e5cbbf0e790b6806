// SPDX-License-Identifier: AGPL-3.0-or-later
// Acceptance tests of the 3D core (issue "Foundation"): two cubes, offset slabs, and the
// paper's two 3D environments (15 spheres, chess board).
#include <aggrelod/aggregate3d.h>
#include <aggrelod/samples.h>

#include "mesh_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

using namespace aggrelod;

namespace {

// Every undirected edge used exactly twice, once in each direction (closed, edge-manifold,
// consistently oriented), and positive volume (outward).
::testing::AssertionResult isClosedManifoldOutward(const Aggregate& a) {
    const std::string problem = aggrelod::testing::edgeManifoldProblem(a.indices);
    if (!problem.empty()) return ::testing::AssertionFailure() << problem;
    if (!(a.measures.volume > 0)) return ::testing::AssertionFailure() << "volume " << a.measures.volume;
    return ::testing::AssertionSuccess();
}

double windingNumber(const Aggregate& a, const double* q) { return aggrelod::testing::windingNumber(a.positions, a.indices, q); }

// Distance from q to the nearest vertex-plane of the aggregate is hard; use: q is inside
// (winding >= 0.5) or lies on one of the aggregate's triangles (within eps).
bool insideOrOn(const Aggregate& a, const double* q, double eps) {
    if (windingNumber(a, q) > 0.49) return true;
    for (size_t t = 0; t < a.indices.size(); t += 3) {
        const double* A = &a.positions[3 * a.indices[t]];
        const double* B = &a.positions[3 * a.indices[t + 1]];
        const double* C = &a.positions[3 * a.indices[t + 2]];
        double u[3], v[3], w[3];
        for (int d = 0; d < 3; ++d) {
            u[d] = B[d] - A[d];
            v[d] = C[d] - A[d];
            w[d] = q[d] - A[d];
        }
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (nl == 0) continue;
        double h = (n[0] * w[0] + n[1] * w[1] + n[2] * w[2]) / nl;
        if (std::fabs(h) > eps) continue;
        // barycentric inside test
        double d00 = u[0] * u[0] + u[1] * u[1] + u[2] * u[2], d01 = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
        double d11 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        double d20 = w[0] * u[0] + w[1] * u[1] + w[2] * u[2], d21 = w[0] * v[0] + w[1] * v[1] + w[2] * v[2];
        double den = d00 * d11 - d01 * d01;
        double bv = (d11 * d20 - d01 * d21) / den, bw = (d00 * d21 - d01 * d20) / den;
        if (bv >= -1e-9 && bw >= -1e-9 && bv + bw <= 1 + 1e-9) return true;
    }
    return false;
}

void expectContainsOriginals(const Level& level, const std::vector<InputObject>& objects, double eps) {
    for (const Aggregate& a : level.aggregates)
        for (uint32_t o : a.sourceObjects)
            for (size_t v = 0; v < objects[o].positions.size(); v += 3)
                ASSERT_TRUE(insideOrOn(a, &objects[o].positions[v], eps))
                    << objects[o].name << " vertex " << v / 3 << " outside its aggregate at delta " << level.delta;
}

Hierarchy3D bake(const std::vector<InputObject>& objects, std::vector<double> deltas,
                 AggregateFunctionKind fn = AggregateFunctionKind::Adaptive, DistanceMode dist = DistanceMode::Exact) {
    Settings3D s;
    s.deltas = std::move(deltas);
    s.function = fn;
    s.distance = dist;
    Hierarchy3D h;
    EXPECT_TRUE(buildHierarchy3D(objects, s, h));
    return h;
}

}  // namespace

TEST(TwoCubes, StayApartBelowGap) {
    auto objects = samples::makeTwoCubes(0.5);
    Hierarchy3D h = bake(objects, {0.4});
    ASSERT_EQ(h.levels.size(), 1u);
    ASSERT_EQ(h.levels[0].aggregates.size(), 2u);
    for (const Aggregate& a : h.levels[0].aggregates) {
        EXPECT_TRUE(isClosedManifoldOutward(a));
        EXPECT_NEAR(a.measures.volume, 1.0, 1e-12);
    }
}

TEST(TwoCubes, ThresholdsThatAreNotFiniteAndNonNegativeAreRefused) {
    // The same check and message as in 2D, before any work: a NaN threshold would also break
    // the sort of the levels.
    const auto objects = samples::makeTwoCubes(0.5);
    for (double bad : {std::nan(""), -0.5, double(INFINITY)}) {
        Settings3D settings;
        settings.deltas = {0.4, bad};
        Hierarchy3D h;
        EXPECT_FALSE(buildHierarchy3D(objects, settings, h)) << bad;
        ASSERT_FALSE(h.diagnostics.empty()) << bad;
        EXPECT_EQ(h.diagnostics.back().message, "every threshold delta must be a finite number >= 0") << bad;
        EXPECT_TRUE(h.levels.empty()) << bad;
    }
}

TEST(TwoCubes, JoinAboveGapIntoOneClosedSolid) {
    for (auto fn : {AggregateFunctionKind::Adaptive, AggregateFunctionKind::Constant}) {
        auto objects = samples::makeTwoCubes(0.5);
        Hierarchy3D h = bake(objects, {0.6, 2.0}, fn);
        ASSERT_EQ(h.levels.size(), 2u);
        for (const Level& level : h.levels) {
            ASSERT_EQ(level.aggregates.size(), 1u);
            const Aggregate& a = level.aggregates[0];
            EXPECT_TRUE(isClosedManifoldOutward(a));
            EXPECT_EQ(a.componentCount, 1);
            EXPECT_EQ(a.sourceObjects, (std::vector<uint32_t>{0, 1}));
            expectContainsOriginals(level, objects, 1e-9);
            // The solid is the cubes plus a filling of the gap slab 1 <= x <= 1.5 only.
            for (size_t v = 0; v < a.positions.size(); v += 3) {
                EXPECT_GE(a.positions[v], -1e-12);
                EXPECT_LE(a.positions[v], 2.5 + 1e-12);
            }
            EXPECT_GT(a.measures.volume, 2.0);
            EXPECT_LE(a.measures.volume, 2.5 + 1e-12);
            EXPECT_NEAR(a.volumeOriginal, 2.0, 1e-12);
        }
        // At delta = 2 every gap edge (at most sqrt(1 + 1 + 0.25) = 1.5) is under F for the
        // constant function: the whole gap is filled, volume = cubes + gap = 2 + 0.5.
        if (fn == AggregateFunctionKind::Constant) {
            EXPECT_NEAR(h.levels[1].aggregates[0].measures.volume, 2.5, 1e-12);
        }
    }
}

TEST(OffsetSlabs, ExactDistanceJoinsIntoOneConnectedSolid) {
    auto objects = samples::makeOffsetSlabs();
    Hierarchy3D h = bake(objects, {2.0});
    ASSERT_EQ(h.levels.size(), 1u);
    ASSERT_EQ(h.levels[0].aggregates.size(), 1u);
    const Aggregate& a = h.levels[0].aggregates[0];
    EXPECT_TRUE(isClosedManifoldOutward(a));
    EXPECT_EQ(a.componentCount, 1) << "joined slabs must form one connected solid";
    expectContainsOriginals(h.levels[0], objects, 1e-9);
    // The connection is short: the added volume stays far below the whole gap (40 x 40 x 1).
    EXPECT_LT(a.measures.volume - a.volumeOriginal, 0.25 * 40 * 40 * 1);
}

TEST(OffsetSlabs, CdtDistanceSeesOnlyLongEdges) {
    // The paper's weight is the shortest triangulation edge: with vertices offset so no pair
    // is closer than 4, the slabs look 4 apart and stay two groups at delta = 2.
    auto objects = samples::makeOffsetSlabs();
    Hierarchy3D h = bake(objects, {2.0}, AggregateFunctionKind::Adaptive, DistanceMode::Cdt);
    ASSERT_EQ(h.levels.size(), 1u);
    EXPECT_EQ(h.levels[0].aggregates.size(), 2u);
}

namespace {
void checkPaperClaims(const std::vector<InputObject>& objects, const char* scene) {
    Settings3D s;
    s.automaticLevelCount = 8;
    s.computeConstantBaseline = true;  // the claim adaptive <= constant needs the constant figure
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, s, h));
    ASSERT_GE(h.levels.size(), 4u) << scene;
    size_t previousGroups = SIZE_MAX;
    double previousVolume = 0;
    for (const Level& level : h.levels) {
        SCOPED_TRACE(std::string(scene) + " delta " + std::to_string(level.delta));
        EXPECT_LE(level.aggregates.size(), previousGroups);
        EXPECT_GE(level.measures.volume, previousVolume * (1 - 1e-12));
        previousGroups = level.aggregates.size();
        previousVolume = level.measures.volume;
        const double added = level.measures.volume - level.volumeOriginal;
        ASSERT_TRUE(level.hasVolumeConstant);
        const double addedConstant = level.volumeConstant - level.volumeOriginal;
        const double addedHull = level.volumeHull - level.volumeOriginal;
        EXPECT_LE(added, addedConstant + 1e-9 * level.volumeOriginal) << "adaptive <= constant";
        EXPECT_LE(addedConstant, addedHull + 1e-9 * level.volumeOriginal) << "constant <= convex hull";
        for (const Aggregate& a : level.aggregates) {
            EXPECT_TRUE(isClosedManifoldOutward(a));
            EXPECT_EQ(a.componentCount, 1) << "joined models must form one solid";
        }
        expectContainsOriginals(level, objects, 1e-7);
    }
}
}  // namespace

TEST(PaperEnvironments, FifteenSpheres) { checkPaperClaims(samples::makeSpheres15(1), "spheres15"); }

TEST(PaperEnvironments, ChessBoard) { checkPaperClaims(samples::makeChessBoard(1), "chess"); }

TEST(Dendrogram, GroupCountNeverRisesAndLevelsAreDistinct) {
    auto objects = samples::makeSpheres15(7);
    Settings3D s;
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, s, h));
    for (size_t i = 1; i < h.levels.size(); ++i) {
        EXPECT_LT(h.levels[i].aggregates.size(), h.levels[i - 1].aggregates.size());
        EXPECT_GT(h.levels[i].delta, h.levels[i - 1].delta);
    }
    EXPECT_EQ(h.levels.back().aggregates.size(), 1u);
    for (size_t i = 1; i < h.merges.size(); ++i) EXPECT_GE(h.merges[i].height, h.merges[i - 1].height);
}

TEST(Determinism, SameResultForAnyThreadCount) {
    // An open box (a hull stand-in) among the spheres exercises the hull path too.
    auto objects = samples::makeSpheres15(3);
    InputObject open = samples::makeBox("openBox", {20, 0, 0}, {21, 1, 1});
    open.indices.resize(open.indices.size() - 3);
    objects.push_back(open);
    std::vector<Hierarchy3D> runs;
    for (int threads : {1, 2, 1}) {
        Settings3D s;
        s.threadCount = threads;
        s.computeConstantBaseline = true;
        runs.emplace_back();
        ASSERT_TRUE(buildHierarchy3D(objects, s, runs.back()));
    }
    for (size_t r = 1; r < runs.size(); ++r) {
        ASSERT_EQ(runs[r].levels.size(), runs[0].levels.size());
        for (size_t l = 0; l < runs[0].levels.size(); ++l) {
            const Level& a = runs[0].levels[l];
            const Level& b = runs[r].levels[l];
            EXPECT_EQ(a.delta, b.delta);
            EXPECT_EQ(a.volumeHull, b.volumeHull);
            EXPECT_EQ(a.volumeConstant, b.volumeConstant);
            ASSERT_EQ(a.aggregates.size(), b.aggregates.size());
            for (size_t g = 0; g < a.aggregates.size(); ++g) {
                EXPECT_EQ(a.aggregates[g].positions, b.aggregates[g].positions);
                EXPECT_EQ(a.aggregates[g].indices, b.aggregates[g].indices);
                EXPECT_EQ(a.aggregates[g].sourceObjects, b.aggregates[g].sourceObjects);
            }
        }
    }
}
