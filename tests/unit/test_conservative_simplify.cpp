// SPDX-License-Identifier: AGPL-3.0-or-later
// Conservative (progressive-hull) simplification: the output is closed, edge-manifold,
// encloses its input and really is coarser (module/src/conservative_simplify.cpp).
#include "conservative_simplify.h"
#include "mesh_distance.h"
#include "nearest_point_above_planes.h"
#include "solidify.h"
#include "mesh_checks.h"
#include "test_support.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <optional>
#include <random>
#include <set>

namespace aggrelod::testing {
namespace {

InputObject asObject(const std::vector<double>& positions, const std::vector<uint32_t>& indices) {
    InputObject o;
    o.name = "simplified";
    o.positions = positions;
    o.indices = indices;
    return o;
}

/// Vertices and triangle centroids of `inner` neither inside `outer` (winding number) nor on
/// its surface (within 1e-9 of the mesh's size: a point on an edge or corner has a winding
/// number below one half).
size_t pointsOutside(const InputObject& inner, const std::vector<double>& outer, const std::vector<uint32_t>& outerIdx) {
    detail::TriangleBvh bvh;
    bvh.build(outer.data(), outer.size() / 3, outerIdx.data(), outerIdx.size() / 3);
    double lo[3], hi[3];
    bvh.bounds(lo, hi);
    const double onSurface = 1e-9 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                              (hi[2] - lo[2]) * (hi[2] - lo[2]));
    size_t outside = 0;
    auto check = [&](const double* q) {
        if (windingNumber(outer, outerIdx, q) < 0.5 && detail::closestPoint(bvh, q).distance > onSurface) ++outside;
    };
    for (size_t v = 0; v < inner.positions.size(); v += 3) check(&inner.positions[v]);
    for (size_t t = 0; t < inner.indices.size(); t += 3) {
        double c[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) c[d] += inner.positions[3 * inner.indices[t + k] + d] / 3;
        check(c);
    }
    return outside;
}

void expectValidEnclosure(const InputObject& input, const std::vector<double>& pos, const std::vector<uint32_t>& idx) {
    const ClosedCheck closed = checkClosedAfterWeld(asObject(pos, idx));
    EXPECT_EQ(closed.problem, "");
    EXPECT_EQ(closed.edgesUsedMoreThanTwice, 0u);
    EXPECT_EQ(closed.components, checkClosedAfterWeld(input).components);
    EXPECT_GE(signedVolumeOf(asObject(pos, idx)), signedVolumeOf(input) * (1 - 1e-9));
    EXPECT_EQ(pointsOutside(input, pos, idx), 0u);
    EXPECT_FALSE(detail::meshSelfIntersects(pos, idx));
}

// The nearest point of an intersection of half-spaces, against every candidate an active set
// of at most three planes gives (the projection onto one plane, one line, one point), keeping
// the nearest feasible one: the same point, or both find the region empty. The narrow wedges
// are where alternating projections (the method before) had not arrived after 48 passes.
using detail::cross;
using detail::dot;
using detail::length;
using detail::Vec3;

std::optional<Vec3> nearestByActiveSets(const std::vector<detail::HalfSpace>& s, Vec3 c) {
    const double slack = 1e-9;
    const auto feasible = [&](Vec3 x) {
        for (const auto& h : s)
            if (dot(h.normal, x) - h.offset < -slack) return false;
        return true;
    };
    std::optional<Vec3> best;
    const auto offer = [&](Vec3 x) {
        if (feasible(x) && (!best || length(x - c) < length(*best - c))) best = x;
    };
    offer(c);
    const size_t n = s.size();
    for (size_t i = 0; i < n; ++i) {
        offer(c - (dot(s[i].normal, c) - s[i].offset) * s[i].normal);
        for (size_t j = i + 1; j < n; ++j) {
            // Nearest point to c on the line where planes i and j meet: c + alpha n_i + beta n_j.
            const double g = dot(s[i].normal, s[j].normal);
            const double det = 1 - g * g;
            if (det < 1e-12) continue;
            const double ri = s[i].offset - dot(s[i].normal, c), rj = s[j].offset - dot(s[j].normal, c);
            const double alpha = (ri - g * rj) / det, beta = (rj - g * ri) / det;
            offer(c + alpha * s[i].normal + beta * s[j].normal);
            for (size_t k = j + 1; k < n; ++k) {
                const Vec3 a = s[i].normal, b = s[j].normal, d = s[k].normal;
                const double volume = dot(a, cross(b, d));
                if (std::fabs(volume) < 1e-9) continue;
                offer((s[i].offset * cross(b, d) + s[j].offset * cross(d, a) + s[k].offset * cross(a, b)) / volume);
            }
        }
    }
    return best;
}

TEST(NearestPointAbovePlanes, MatchesTheBestActiveSet) {
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1, 1);
    const auto randomUnit = [&] {
        for (;;) {
            const Vec3 v{unit(rng), unit(rng), unit(rng)};
            if (length(v) > 0.1 && length(v) <= 1) return (1 / length(v)) * v;
        }
    };
    size_t feasibleCases = 0, emptyCases = 0, wedges = 0, coplanarCases = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        const size_t count = 1 + trial % 14;
        std::vector<detail::HalfSpace> spaces(count);
        const bool wedge = trial % 4 == 0;
        const Vec3 axis = randomUnit();
        for (auto& h : spaces) {
            // Wedges: normals within a few degrees of one axis, the region a thin cone or slab.
            if (wedge) {
                const Vec3 jitter = randomUnit();
                h.normal = axis + 0.05 * jitter;
                h.normal = (1 / length(h.normal)) * h.normal;
            } else {
                h.normal = randomUnit();
            }
            h.offset = unit(rng);
        }
        // Coplanar planes, as the faces of a flat region give: a copy of the first one (its
        // offset off by rounding), and the point on it.
        const bool coplanar = trial % 4 == 1 && count >= 3;
        if (coplanar) {
            spaces[count - 1] = spaces[0];
            spaces[count - 1].offset = std::nextafter(spaces[0].offset, trial % 8 == 1 ? 2.0 : -2.0);
            ++coplanarCases;
        }
        if (wedge && count >= 2) {  // two planes almost facing each other: a thin slab, or none
            spaces[1].normal = -1.0 * spaces[0].normal + 0.01 * randomUnit();
            spaces[1].normal = (1 / length(spaces[1].normal)) * spaces[1].normal;
            spaces[1].offset = -spaces[0].offset - 0.02 * std::fabs(unit(rng));
            ++wedges;
        }
        Vec3 c{2 * unit(rng), 2 * unit(rng), 2 * unit(rng)};
        if (coplanar) c = c - (dot(spaces[0].normal, c) - spaces[0].offset) * spaces[0].normal;
        Vec3 ours;
        const bool found = detail::nearestPointAbovePlanes(spaces.data(), spaces.size(), c, ours);
        const std::optional<Vec3> expected = nearestByActiveSets(spaces, c);
        ASSERT_EQ(found, expected.has_value()) << "trial " << trial;
        if (!found) {
            ++emptyCases;
            continue;
        }
        ++feasibleCases;
        for (const auto& h : spaces) ASSERT_GE(dot(h.normal, ours) - h.offset, -1e-9) << "trial " << trial;
        const double scale = 1 + length(*expected - c);  // thin wedges can put it far away
        EXPECT_NEAR(length(ours - c), length(*expected - c), 1e-9 * scale) << "trial " << trial;
        EXPECT_LT(length(ours - *expected), 1e-6 * scale) << "trial " << trial;
    }
    std::printf("%zu feasible, %zu empty, %zu trials with a thin slab\n", feasibleCases, emptyCases, wedges);
    EXPECT_GT(feasibleCases, 1000u);
    EXPECT_GT(emptyCases, 100u);
    EXPECT_GT(wedges, 500u);
    EXPECT_GT(coplanarCases, 500u);
}

TEST(ConservativeSimplify, GriddedBoxBecomesTwelveTriangles) {
    const InputObject box = samples::makeBox("box", {0, 0, 0}, {2, 1, 1}, 0.1);
    std::vector<double> pos;
    std::vector<uint32_t> idx;
    detail::simplifyConservative(box.positions, box.indices, 1e-3, 0, pos, idx);
    EXPECT_EQ(idx.size() / 3, 12u);
    expectValidEnclosure(box, pos, idx);
    EXPECT_NEAR(signedVolumeOf(asObject(pos, idx)), 2.0, 1e-9);  // flat faces cost nothing
}

TEST(ConservativeSimplify, SphereEnclosedWithinTheErrorEstimate) {
    const InputObject sphere = samples::makeUvSphere("sphere", {1, 2, 3}, 1.0, 64, 32);
    std::vector<double> pos;
    std::vector<uint32_t> idx;
    const auto result = detail::simplifyConservative(sphere.positions, sphere.indices, 0.02, 0, pos, idx);
    EXPECT_LT(idx.size(), sphere.indices.size() / 4);
    EXPECT_LE(result.errorEstimate, 0.02);
    expectValidEnclosure(sphere, pos, idx);
    // The estimate bounds the push-out: no vertex farther from the sphere than it.
    for (size_t v = 0; v < pos.size(); v += 3) {
        const double r = std::sqrt((pos[v] - 1) * (pos[v] - 1) + (pos[v + 1] - 2) * (pos[v + 1] - 2) + (pos[v + 2] - 3) * (pos[v + 2] - 3));
        EXPECT_LE(r, 1.0 + 0.02 + 1e-9);
    }
}

TEST(ConservativeSimplify, ConcaveLatheStaysAValidEnclosure) {
    // A chess-piece-like profile: necks and overhangs where pushing out could fold.
    const InputObject lathe = samples::makeLathe(
        "piece", {0, 0, 0}, {{0.5, 0}, {0.5, 0.1}, {0.2, 0.3}, {0.15, 0.6}, {0.35, 0.7}, {0.1, 0.9}, {0.25, 1.1}, {0.05, 1.3}},
        48);
    for (double maxError : {0.005, 0.02, 0.08}) {
        std::vector<double> pos;
        std::vector<uint32_t> idx;
        detail::simplifyConservative(lathe.positions, lathe.indices, maxError, 0, pos, idx);
        SCOPED_TRACE(maxError);
        EXPECT_LT(idx.size(), lathe.indices.size());
        expectValidEnclosure(lathe, pos, idx);
    }
}

TEST(ConservativeSimplify, SeriesSnapshotsAreNestedAndCoarsening) {
    const InputObject sphere = samples::makeUvSphere("sphere", {0, 0, 0}, 1.0, 48, 24);
    std::vector<detail::ConservativeSnapshot> snapshots;
    detail::simplifyConservativeSeries(sphere.positions, sphere.indices, {0.005, 0.01, 0.04, 0.16}, 0, snapshots);
    ASSERT_EQ(snapshots.size(), 4u);
    for (size_t i = 0; i < snapshots.size(); ++i) {
        SCOPED_TRACE(i);
        const InputObject finer = i == 0 ? sphere : asObject(snapshots[i - 1].positions, snapshots[i - 1].indices);
        EXPECT_LT(snapshots[i].indices.size(), finer.indices.size());
        expectValidEnclosure(finer, snapshots[i].positions, snapshots[i].indices);
        // Same as a single run to that error.
        std::vector<double> pos;
        std::vector<uint32_t> idx;
        detail::simplifyConservative(sphere.positions, sphere.indices, std::vector<double>{0.005, 0.01, 0.04, 0.16}[i], 0, pos, idx);
        EXPECT_EQ(pos, snapshots[i].positions);
        EXPECT_EQ(idx, snapshots[i].indices);
    }
}

// An alpha wrap has thousands of nearly coplanar triangles on every flat side of what it
// wraps. Collapsing them cheapest first would end in fans around single vertices, and every
// collapse near a fan costs in proportion to it; no vertex the simplifier moves gets more
// than 24 neighbours, and the result still encloses the wrap.
TEST(ConservativeSimplify, FlatSidesOfAWrapDoNotBecomeFans) {
    InputObject openBox = samples::makeBox("box", {0, 0, 0}, {1, 1, 1});
    openBox.indices.resize(openBox.indices.size() - 3);  // one triangle missing: open
    std::vector<double> wrap;
    std::vector<uint32_t> wrapIdx;
    std::string error;
    ASSERT_TRUE(detail::alphaWrap(openBox.positions, openBox.indices, 0.05, 0.01, wrap, wrapIdx, error)) << error;
    ASSERT_GT(wrapIdx.size() / 3, 5000u);
    std::vector<double> pos;
    std::vector<uint32_t> idx;
    detail::simplifyConservative(wrap, wrapIdx, 0.005, 0, pos, idx);
    EXPECT_LT(idx.size(), wrapIdx.size() / 3);
    std::vector<std::set<uint32_t>> neighbours(pos.size() / 3);
    for (size_t t = 0; t < idx.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            neighbours[idx[t + k]].insert(idx[t + (k + 1) % 3]);
            neighbours[idx[t + (k + 1) % 3]].insert(idx[t + k]);
        }
    size_t most = 0;
    for (const auto& n : neighbours) most = std::max(most, n.size());
    EXPECT_LE(most, 24u);
    expectValidEnclosure(asObject(wrap, wrapIdx), pos, idx);
}

// Flat regions: a position placed exactly on their planes could fold a face onto its
// neighbour (a fin enclosing nothing, which a ray along it meets twice at one point). No
// output has such a pair, on boxes of flat faces and on the alpha wrap of one.
TEST(ConservativeSimplify, NoTwoFacesFoldOntoEachOther) {
    std::vector<std::pair<std::string, InputObject>> shapes;
    shapes.emplace_back("gridded box", samples::makeBox("box", {0, 0, 0}, {2, 1, 0.5}, 0.1));
    shapes.emplace_back("sphere", samples::makeUvSphere("sphere", {0, 0, 0}, 1.0, 32, 16));
    InputObject openBox = samples::makeBox("box", {0, 0, 0}, {1, 1, 1});
    openBox.indices.resize(openBox.indices.size() - 3);
    InputObject wrap;
    std::string error;
    ASSERT_TRUE(detail::alphaWrap(openBox.positions, openBox.indices, 0.05, 0.01, wrap.positions, wrap.indices, error)) << error;
    shapes.emplace_back("alpha wrap", wrap);
    size_t outputs = 0;
    for (const auto& [name, shape] : shapes)
        for (double maxError : {0.002, 0.01, 0.05, 0.2}) {
            std::vector<double> pos;
            std::vector<uint32_t> idx;
            detail::simplifyConservative(shape.positions, shape.indices, maxError, 0, pos, idx);
            const std::vector<float> floats(pos.begin(), pos.end());
            EXPECT_EQ(foldedEdgeCount(floats, idx), 0u) << name << " at " << maxError;
            ++outputs;
        }
    EXPECT_EQ(outputs, 12u);
}

TEST(ConservativeSimplify, ZeroErrorKeepsTheMesh) {
    const InputObject sphere = samples::makeUvSphere("sphere", {0, 0, 0}, 1.0, 12, 6);
    std::vector<double> pos;
    std::vector<uint32_t> idx;
    detail::simplifyConservative(sphere.positions, sphere.indices, 0, 0, pos, idx);
    EXPECT_EQ(idx.size(), sphere.indices.size());
}

TEST(ConservativeSimplify, SelfIntersectionFoundBetweenOverlappingShells) {
    InputObject a = samples::makeBox("a", {0, 0, 0}, {1, 1, 1});
    const InputObject b = samples::makeBox("b", {0.5, 0.5, 0.5}, {1.5, 1.5, 1.5});
    EXPECT_FALSE(detail::meshSelfIntersects(a.positions, a.indices));
    const uint32_t base = static_cast<uint32_t>(a.positions.size() / 3);
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    for (uint32_t i : b.indices) a.indices.push_back(base + i);
    EXPECT_TRUE(detail::meshSelfIntersects(a.positions, a.indices));
    // Two shells apart do not intersect.
    InputObject c = samples::makeBox("c", {0, 0, 0}, {1, 1, 1});
    const InputObject d = samples::makeBox("d", {2, 0, 0}, {3, 1, 1});
    const uint32_t base2 = static_cast<uint32_t>(c.positions.size() / 3);
    c.positions.insert(c.positions.end(), d.positions.begin(), d.positions.end());
    for (uint32_t i : d.indices) c.indices.push_back(base2 + i);
    EXPECT_FALSE(detail::meshSelfIntersects(c.positions, c.indices));
}

}  // namespace
}  // namespace aggrelod::testing
