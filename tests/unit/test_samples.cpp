// SPDX-License-Identifier: AGPL-3.0-or-later
// Checks of the sample scene generators (samples/): closed, outward, welded meshes, no
// overlaps, the documented gaps, and determinism.
#include <aggrelod/samples.h>

#include "mesh_preparation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <functional>
#include <random>
#include <cmath>
#include <numeric>
#include <set>
#include <string>
#include <vector>

namespace {

using aggrelod::InputObject;
namespace s = aggrelod::samples;
constexpr double kPi = 3.14159265358979323846;

struct Box3 {
    double lo[3], hi[3];
};

Box3 boundsOf(const InputObject& o) {
    Box3 b{{1e300, 1e300, 1e300}, {-1e300, -1e300, -1e300}};
    for (size_t i = 0; i < o.positions.size(); ++i) {
        b.lo[i % 3] = std::min(b.lo[i % 3], o.positions[i]);
        b.hi[i % 3] = std::max(b.hi[i % 3], o.positions[i]);
    }
    return b;
}

bool boxesDisjoint(const Box3& a, const Box3& b) {
    for (int k = 0; k < 3; ++k)
        if (a.hi[k] < b.lo[k] || b.hi[k] < a.lo[k]) return true;
    return false;
}

double dist(const s::Vec3& a, const s::Vec3& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
}

size_t triangleCount(const std::vector<InputObject>& scene) {
    size_t n = 0;
    for (const auto& o : scene) n += o.indices.size() / 3;
    return n;
}

// Every object closed, welded, non-degenerate, positive volume; ids 0..n-1; unique names.
void expectValidScene(const std::vector<InputObject>& scene, const std::string& label) {
    std::set<std::string> names;
    for (size_t i = 0; i < scene.size(); ++i) {
        const auto& o = scene[i];
        EXPECT_EQ(s::checkClosedMesh(o), "") << label;
        EXPECT_GT(s::signedVolume(o), 0.0) << label << " object " << o.name;
        EXPECT_EQ(o.id, i) << label;
        EXPECT_FALSE(o.name.empty()) << label;
        EXPECT_TRUE(names.insert(o.name).second) << label << ": duplicate name " << o.name;
    }
}

// No two objects overlap: their bounding boxes or their bounding spheres are disjoint.
void expectNoOverlap(const std::vector<InputObject>& scene, const std::string& label) {
    std::vector<Box3> boxes;
    std::vector<std::pair<s::Vec3, double>> spheres;
    for (const auto& o : scene) {
        boxes.push_back(boundsOf(o));
        spheres.push_back(s::boundingSphere(o));
    }
    int failures = 0;
    for (size_t i = 0; i < scene.size(); ++i)
        for (size_t j = i + 1; j < scene.size(); ++j) {
            const bool separated =
                boxesDisjoint(boxes[i], boxes[j]) ||
                dist(spheres[i].first, spheres[j].first) > spheres[i].second + spheres[j].second;
            if (!separated && ++failures <= 5)
                ADD_FAILURE() << label << ": " << scene[i].name << " and " << scene[j].name
                              << " may overlap";
        }
    EXPECT_EQ(failures, 0) << label;
}

// Number of groups when spheres (radius 1) closer than delta are joined (single linkage).
int sphereGroups(const std::vector<InputObject>& scene, double delta) {
    std::vector<int> parent(scene.size());
    std::iota(parent.begin(), parent.end(), 0);
    std::function<int(int)> find = [&](int x) { return parent[size_t(x)] == x ? x : parent[size_t(x)] = find(parent[size_t(x)]); };
    int groups = int(scene.size());
    for (size_t i = 0; i < scene.size(); ++i)
        for (size_t j = i + 1; j < scene.size(); ++j) {
            const double gap = dist(s::boundingSphere(scene[i]).first, s::boundingSphere(scene[j]).first) - 2.0;
            if (gap < delta) {
                const int a = find(int(i)), b = find(int(j));
                if (a != b) {
                    parent[size_t(a)] = b;
                    --groups;
                }
            }
        }
    return groups;
}

bool sameScene(const std::vector<InputObject>& a, const std::vector<InputObject>& b) {
    if (a.size() != b.size()) return false;
    for (size_t i = 0; i < a.size(); ++i)
        if (a[i].name != b[i].name || a[i].positions != b[i].positions || a[i].indices != b[i].indices)
            return false;
    return true;
}

}  // namespace

TEST(SamplesRandom, MatchesTheStandardMersenneTwister) {
    // std::mt19937 is fixed by the standard (its 10000th output from the default seed is
    // 4123659995), and uniform01 uses only its raw output: golden values hold everywhere.
    std::mt19937 reference;
    reference.discard(9999);
    EXPECT_EQ(reference(), 4123659995u);
    s::Random rng(5489u);
    const double first = rng.uniform01();
    std::mt19937 raw(5489u);
    const uint32_t a = raw() >> 5, b = raw() >> 6;
    EXPECT_EQ(first, (a * 67108864.0 + b) / 9007199254740992.0);
    s::Random r1(42), r2(42);
    for (int i = 0; i < 1000; ++i) {
        const double x = r1.uniform01();
        EXPECT_EQ(x, r2.uniform01());
        EXPECT_GE(x, 0.0);
        EXPECT_LT(x, 1.0);
        const int k = r1.uniformInt(-3, 3);
        EXPECT_EQ(k, r2.uniformInt(-3, 3));
        EXPECT_GE(k, -3);
        EXPECT_LE(k, 3);
    }
}

TEST(SamplesHelpers, BoxIsClosedWithExactVolume) {
    for (double maxEdge : {0.0, 0.7, 2.0, 8.0}) {
        const auto box = s::makeBox("b", {-1, 2, 3}, {4, 5, 3.5}, maxEdge);
        EXPECT_EQ(s::checkClosedMesh(box), "") << maxEdge;
        EXPECT_NEAR(s::signedVolume(box), 5.0 * 3.0 * 0.5, 1e-9) << maxEdge;
    }
    EXPECT_EQ(s::makeBox("b", {0, 0, 0}, {1, 1, 1}).indices.size(), 36u);
    const auto grid = s::makeBox("g", {0, 0, 0}, {40, 40, 1}, 8);  // 5 x 5, 5 x 1, 5 x 1 cells
    EXPECT_EQ(grid.indices.size() / 3, size_t(2 * 2 * (25 + 5 + 5)));
}

TEST(SamplesHelpers, SphereCylinderLatheExtrusion) {
    const auto sphere = s::makeUvSphere("s", {1, 2, 3}, 2.0, 20, 11);
    EXPECT_EQ(s::checkClosedMesh(sphere), "");
    EXPECT_EQ(sphere.indices.size() / 3, 400u);
    const double ideal = 4.0 / 3.0 * kPi * 8.0;
    EXPECT_LT(s::signedVolume(sphere), ideal);       // inscribed
    EXPECT_GT(s::signedVolume(sphere), 0.95 * ideal);

    const int segments = 16;
    const auto cylinder = s::makeCylinder("c", {0, 0, -1}, 0.5, 2.0, segments, 3);
    EXPECT_EQ(s::checkClosedMesh(cylinder), "");
    EXPECT_EQ(cylinder.indices.size() / 3, size_t(2 * segments * 4));
    const double polygonArea = 0.5 * segments * 0.25 * std::sin(2 * kPi / segments);
    EXPECT_NEAR(s::signedVolume(cylinder), polygonArea * 2.0, 1e-9);

    const auto lathe = s::makeLathe("l", {0, 0, 0}, {{0.3, 0}, {0.3, 0.1}, {0.1, 0.5}, {0.2, 0.6}, {0.05, 0.8}}, 12);
    EXPECT_EQ(s::checkClosedMesh(lathe), "");
    EXPECT_EQ(lathe.indices.size() / 3, size_t(2 * 12 * 5));
    EXPECT_GT(s::signedVolume(lathe), 0.0);

    // An L-shaped (non-convex) outline: volume = area * depth, whatever the heading.
    const std::vector<std::pair<double, double>> outline = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 3}, {0, 3}};
    for (double yaw : {0.0, 0.7, 3.0}) {
        const auto prism = s::makeExtrusion("e", outline, 0.5, yaw, {10, -4, 2});
        EXPECT_EQ(s::checkClosedMesh(prism), "");
        EXPECT_NEAR(s::signedVolume(prism), 4.0 * 0.5, 1e-9);
    }
}

TEST(SamplesHelpers, CheckClosedMeshFindsProblems) {
    auto open = s::makeBox("open", {0, 0, 0}, {1, 1, 1});
    open.indices.resize(open.indices.size() - 3);
    EXPECT_NE(s::checkClosedMesh(open).find("open"), std::string::npos) << s::checkClosedMesh(open);
    auto flipped = s::makeBox("flipped", {0, 0, 0}, {1, 1, 1});
    std::swap(flipped.indices[0], flipped.indices[1]);
    EXPECT_NE(s::checkClosedMesh(flipped), "");
    auto inside = s::makeBox("inside", {0, 0, 0}, {1, 1, 1});
    for (size_t t = 0; t < inside.indices.size(); t += 3) std::swap(inside.indices[t], inside.indices[t + 1]);
    EXPECT_EQ(s::checkClosedMesh(inside), "");  // closed, but inside out:
    EXPECT_LT(s::signedVolume(inside), 0.0);
    auto range = s::makeBox("range", {0, 0, 0}, {1, 1, 1});
    range.indices[4] = 99;
    EXPECT_NE(s::checkClosedMesh(range).find("out of range"), std::string::npos);
}

TEST(SamplesScenes, TwoCubes) {
    const auto scene = s::makeTwoCubes(0.25);
    ASSERT_EQ(scene.size(), 2u);
    EXPECT_EQ(scene[0].name, "cubeA");
    EXPECT_EQ(scene[1].name, "cubeB");
    expectValidScene(scene, "two_cubes");
    const Box3 a = boundsOf(scene[0]), b = boundsOf(scene[1]);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(a.lo[k], 0.0);
        EXPECT_EQ(a.hi[k], 1.0);
    }
    EXPECT_EQ(b.lo[0], 1.25);
    EXPECT_EQ(b.hi[0], 2.25);
    EXPECT_NEAR(s::signedVolume(scene[0]), 1.0, 1e-12);
}

TEST(SamplesScenes, OffsetSlabsGapOneButVerticesFarApart) {
    const auto scene = s::makeOffsetSlabs();
    ASSERT_EQ(scene.size(), 2u);
    expectValidScene(scene, "slabs");
    expectNoOverlap(scene, "slabs");
    const Box3 lower = boundsOf(scene[0]), upper = boundsOf(scene[1]);
    EXPECT_EQ(upper.lo[2] - lower.hi[2], 1.0);  // parallel faces exactly 1 apart
    // ... over a large overlap in x and y.
    EXPECT_GE(std::min(lower.hi[0], upper.hi[0]) - std::max(lower.lo[0], upper.lo[0]), 30.0);
    EXPECT_GE(std::min(lower.hi[1], upper.hi[1]) - std::max(lower.lo[1], upper.lo[1]), 30.0);
    double closest = 1e300;
    for (size_t i = 0; i < scene[0].positions.size(); i += 3)
        for (size_t j = 0; j < scene[1].positions.size(); j += 3) {
            const s::Vec3 p = {scene[0].positions[i], scene[0].positions[i + 1], scene[0].positions[i + 2]};
            const s::Vec3 q = {scene[1].positions[j], scene[1].positions[j + 1], scene[1].positions[j + 2]};
            closest = std::min(closest, dist(p, q));
        }
    EXPECT_GT(closest, 4.0);
    EXPECT_NEAR(closest, std::sqrt(33.0), 1e-12);
}

TEST(SamplesScenes, Spheres15HaveDistinctLevels) {
    for (uint32_t seed = 1; seed <= 20; ++seed) {
        const auto scene = s::makeSpheres15(seed);
        const std::string label = "spheres15 seed " + std::to_string(seed);
        ASSERT_EQ(scene.size(), 15u) << label;
        expectValidScene(scene, label);
        expectNoOverlap(scene, label);
        for (const auto& o : scene) {
            EXPECT_GE(o.indices.size() / 3, 300u);
            EXPECT_LE(o.indices.size() / 3, 500u);
        }
        // No two spheres closer than 0.2; the paper's deltas 1, 1.5, 2, 3, 4 give several
        // different groupings.
        EXPECT_EQ(sphereGroups(scene, 0.2), 15) << label;
        std::set<int> counts;
        for (double delta : {1.0, 1.5, 2.0, 3.0, 4.0}) counts.insert(sphereGroups(scene, delta));
        EXPECT_GE(counts.size(), 3u) << label;
        EXPECT_LT(sphereGroups(scene, 1.0), 15) << label;
        EXPECT_LT(sphereGroups(scene, 4.0), sphereGroups(scene, 1.0)) << label;
    }
}

TEST(SamplesScenes, ChessBoard) {
    for (uint32_t seed = 1; seed <= 10; ++seed) {
        const std::string label = "chess seed " + std::to_string(seed);
        const auto pieces = s::makeChessBoard(seed);
        ASSERT_GE(pieces.size(), 16u) << label;
        ASSERT_LE(pieces.size(), 32u) << label;
        expectValidScene(pieces, label);
        expectNoOverlap(pieces, label);
        for (const char* kind : {"pawn", "rook", "knight", "bishop", "queen", "king"})
            EXPECT_TRUE(std::any_of(pieces.begin(), pieces.end(), [&](const InputObject& o) {
                return o.name.find(std::string("_") + kind + "_") != std::string::npos;
            })) << label << " has no " << kind;
        for (const auto& o : pieces) {
            const Box3 b = boundsOf(o);
            EXPECT_EQ(b.lo[2], 0.0) << o.name;  // standing on the board plane
            // Inside its own square, 0.08 from its edges: neighbours are >= 0.16 apart.
            const double cx = std::floor((b.lo[0] + b.hi[0]) / 2), cy = std::floor((b.lo[1] + b.hi[1]) / 2);
            EXPECT_GE(b.lo[0], cx + 0.08) << o.name;
            EXPECT_LE(b.hi[0], cx + 0.92) << o.name;
            EXPECT_GE(b.lo[1], cy + 0.08) << o.name;
            EXPECT_LE(b.hi[1], cy + 0.92) << o.name;
        }
        const auto withBoard = s::makeChessBoard(seed, true);
        ASSERT_EQ(withBoard.size(), pieces.size() + 1) << label;
        EXPECT_EQ(withBoard[0].name, "board");
        expectValidScene(withBoard, label + " with board");
        expectNoOverlap(withBoard, label + " with board");
        EXPECT_NEAR(boundsOf(withBoard[1]).lo[2] - boundsOf(withBoard[0]).hi[2], 0.05, 1e-12);
        for (size_t i = 0; i < pieces.size(); ++i) EXPECT_EQ(withBoard[i + 1].positions, pieces[i].positions);
    }
}

TEST(SamplesScenes, RandomSceneForBenchmarks) {
    const auto small = s::makeRandomScene(50, 5000, 7);
    ASSERT_EQ(small.size(), 50u);
    expectValidScene(small, "random 50");
    expectNoOverlap(small, "random 50");

    const auto scene = s::makeRandomScene(1000, 150000, 1);
    ASSERT_EQ(scene.size(), 1000u);
    expectValidScene(scene, "random 1000");
    expectNoOverlap(scene, "random 1000");
    const double triangles = double(triangleCount(scene));
    EXPECT_GT(triangles, 0.75 * 150000);
    EXPECT_LT(triangles, 1.25 * 150000);
    // Heterogeneous: all four kinds of shape occur (by triangle count signature is fragile,
    // so look at the bounding-sphere radii spread instead).
    double rMin = 1e300, rMax = 0;
    for (const auto& o : scene) {
        const double r = s::boundingSphere(o).second;
        rMin = std::min(rMin, r);
        rMax = std::max(rMax, r);
    }
    EXPECT_GT(rMax / rMin, 2.5);
}

// The bake sees the generated objects as the valid solids they are: none is taken for one
// that crosses itself (rotated boxes have faces whose edges lie on the lines of others, the
// case where the side tests of the triangle-pair check are rounding noise), so none is
// wrapped.
TEST(SamplesScenes, RandomSceneObjectsDoNotCrossThemselves) {
    const auto scene = s::makeRandomScene(400, 200000, 1);
    size_t crossing = 0;
    for (const auto& o : scene) {
        aggrelod::detail::PreparedObject prepared;
        std::vector<aggrelod::Diagnostic> diagnostics;
        aggrelod::detail::prepareObject(o, 0.0, prepared, diagnostics);
        EXPECT_TRUE(prepared.validSolid()) << o.name;
        if (aggrelod::detail::selfIntersects(prepared.positions, prepared.triangles)) ++crossing;
    }
    EXPECT_EQ(crossing, 0u);
}

TEST(SamplesScenes, Deterministic) {
    EXPECT_TRUE(sameScene(s::makeSpheres15(3), s::makeSpheres15(3)));
    EXPECT_FALSE(sameScene(s::makeSpheres15(3), s::makeSpheres15(4)));
    EXPECT_TRUE(sameScene(s::makeChessBoard(3), s::makeChessBoard(3)));
    EXPECT_FALSE(sameScene(s::makeChessBoard(3), s::makeChessBoard(4)));
    EXPECT_TRUE(sameScene(s::makeRandomScene(100, 10000, 9), s::makeRandomScene(100, 10000, 9)));
    EXPECT_FALSE(sameScene(s::makeRandomScene(100, 10000, 9), s::makeRandomScene(100, 10000, 10)));
    EXPECT_TRUE(sameScene(s::makeOffsetSlabs(), s::makeOffsetSlabs()));
}

namespace {

// No two objects overlap, proved by one of: disjoint boxes, disjoint bounding spheres, or
// disjoint vertical cylinders (circle around the box's xy centre containing every vertex).
void expectApartInBoxSphereOrColumn(const std::vector<InputObject>& scene, const std::string& label) {
    struct Column { double x, y, r; };
    std::vector<Box3> boxes;
    std::vector<std::pair<s::Vec3, double>> spheres;
    std::vector<Column> columns;
    for (const auto& o : scene) {
        boxes.push_back(boundsOf(o));
        spheres.push_back(s::boundingSphere(o));
        Column c{0.5 * (boxes.back().lo[0] + boxes.back().hi[0]), 0.5 * (boxes.back().lo[1] + boxes.back().hi[1]), 0};
        for (size_t i = 0; i + 2 < o.positions.size(); i += 3)
            c.r = std::max(c.r, std::hypot(o.positions[i] - c.x, o.positions[i + 1] - c.y));
        columns.push_back(c);
    }
    int failures = 0;
    for (size_t i = 0; i < scene.size(); ++i)
        for (size_t j = i + 1; j < scene.size(); ++j) {
            const bool separated =
                boxesDisjoint(boxes[i], boxes[j]) ||
                dist(spheres[i].first, spheres[j].first) > spheres[i].second + spheres[j].second ||
                std::hypot(columns[i].x - columns[j].x, columns[i].y - columns[j].y) > columns[i].r + columns[j].r;
            if (!separated && ++failures <= 5)
                ADD_FAILURE() << label << ": " << scene[i].name << " and " << scene[j].name << " may overlap";
        }
    EXPECT_EQ(failures, 0) << label;
}

size_t countPrefix(const std::vector<InputObject>& scene, const std::string& prefix, const std::string& suffix = "") {
    size_t n = 0;
    for (const auto& o : scene)
        if (o.name.rfind(prefix, 0) == 0 && o.name.size() >= suffix.size() &&
            o.name.compare(o.name.size() - suffix.size(), suffix.size(), suffix) == 0)
            ++n;
    return n;
}

// Smallest and largest gap between an object and its nearest other object, over all objects,
// measured between vertical columns (a lower bound of the true gap): varied spacing means
// some objects nearly touch and some stand far from every other one.
std::pair<double, double> nearestColumnGapRange(const std::vector<InputObject>& scene, const std::string& suffix) {
    std::vector<std::array<double, 3>> c;
    for (const auto& o : scene) {
        if (o.name.size() < suffix.size() || o.name.compare(o.name.size() - suffix.size(), suffix.size(), suffix) != 0) continue;
        const Box3 b = boundsOf(o);
        std::array<double, 3> col{0.5 * (b.lo[0] + b.hi[0]), 0.5 * (b.lo[1] + b.hi[1]), 0};
        for (size_t i = 0; i + 2 < o.positions.size(); i += 3)
            col[2] = std::max(col[2], std::hypot(o.positions[i] - col[0], o.positions[i + 1] - col[1]));
        c.push_back(col);
    }
    double lo = 1e300, hi = 0;
    for (size_t i = 0; i < c.size(); ++i) {
        double nearest = 1e300;
        for (size_t j = 0; j < c.size(); ++j)
            if (i != j) nearest = std::min(nearest, std::hypot(c[i][0] - c[j][0], c[i][1] - c[j][1]) - c[i][2] - c[j][2]);
        lo = std::min(lo, nearest);
        hi = std::max(hi, nearest);
    }
    return {lo, hi};
}

}  // namespace

TEST(SamplesScenes, ForestTrunksCanopiesVariedSpacing) {
    const auto forest = s::makeForest(1);
    expectValidScene(forest, "forest");
    expectApartInBoxSphereOrColumn(forest, "forest");
    const size_t trunks = countPrefix(forest, "tree", "_trunk"), canopies = countPrefix(forest, "tree", "_canopy");
    EXPECT_EQ(trunks, canopies);
    EXPECT_EQ(trunks + canopies, forest.size());
    EXPECT_GE(trunks, 40u);
    // Moderate size: bakes in seconds.
    EXPECT_GE(triangleCount(forest), 4000u);
    EXPECT_LE(triangleCount(forest), 20000u);
    // Every canopy stands 0.05 above its trunk (the tree's two objects nearly touch).
    for (size_t i = 0; i + 1 < forest.size(); i += 2) {
        EXPECT_NEAR(boundsOf(forest[i + 1]).lo[2] - boundsOf(forest[i]).hi[2], 0.05, 1e-9) << forest[i].name;
    }
    // Varied spacing: canopies in clumps nearly touch, scattered ones stand >= 1.5 apart.
    const auto gaps = nearestColumnGapRange(forest, "_canopy");
    EXPECT_LT(gaps.first, 0.3);
    EXPECT_GT(gaps.second, 1.5);
}

TEST(SamplesScenes, VillageHousesFencesBarrels) {
    const auto village = s::makeVillage(1);
    expectValidScene(village, "village");
    expectNoOverlap(village, "village");  // every object has its own axis-aligned ground rectangle
    const size_t houses = countPrefix(village, "house"), fences = countPrefix(village, "fence"),
                 barrels = countPrefix(village, "barrel");
    EXPECT_EQ(houses + fences + barrels, village.size());
    EXPECT_GE(houses, 12u);
    EXPECT_GE(fences, 3u);
    EXPECT_GE(barrels, 4u);
    EXPECT_GE(triangleCount(village), 2000u);
    EXPECT_LE(triangleCount(village), 20000u);
    // Pitched roofs: a house is taller at its ridge (the middle) than at its walls.
    for (const auto& o : village) {
        if (o.name.rfind("house", 0) != 0) continue;
        const Box3 b = boundsOf(o);
        double wallTop = 0;
        for (size_t i = 0; i + 2 < o.positions.size(); i += 3)
            if (std::fabs(o.positions[i] - b.lo[0]) < 1e-9) wallTop = std::max(wallTop, o.positions[i + 2]);
        EXPECT_GT(b.hi[2], wallTop + 1.0) << o.name;
    }
    // Varied spacing: terraced houses 0.6-1.2 apart, open plots 3-8 apart.
    std::vector<Box3> houseBoxes;
    for (const auto& o : village)
        if (o.name.rfind("house", 0) == 0) houseBoxes.push_back(boundsOf(o));
    double smallest = 1e300, largest = 0;
    for (size_t i = 0; i < houseBoxes.size(); ++i) {
        double nearest = 1e300;
        for (size_t j = 0; j < houseBoxes.size(); ++j) {
            if (i == j) continue;
            const double dx = std::max({0.0, houseBoxes[j].lo[0] - houseBoxes[i].hi[0], houseBoxes[i].lo[0] - houseBoxes[j].hi[0]});
            const double dy = std::max({0.0, houseBoxes[j].lo[1] - houseBoxes[i].hi[1], houseBoxes[i].lo[1] - houseBoxes[j].hi[1]});
            nearest = std::min(nearest, std::hypot(dx, dy));
        }
        smallest = std::min(smallest, nearest);
        largest = std::max(largest, nearest);
    }
    EXPECT_LT(smallest, 1.3);
    EXPECT_GT(largest, 2.9);
}

TEST(SamplesScenes, ForestAndVillageDeterministic) {
    EXPECT_TRUE(sameScene(s::makeForest(7), s::makeForest(7)));
    EXPECT_TRUE(sameScene(s::makeVillage(7), s::makeVillage(7)));
    EXPECT_FALSE(sameScene(s::makeForest(7), s::makeForest(8)));
    EXPECT_FALSE(sameScene(s::makeVillage(7), s::makeVillage(8)));
    for (uint32_t seed : {2u, 3u, 4u}) {
        expectValidScene(s::makeForest(seed), "forest seed " + std::to_string(seed));
        expectApartInBoxSphereOrColumn(s::makeForest(seed), "forest seed " + std::to_string(seed));
        expectValidScene(s::makeVillage(seed), "village seed " + std::to_string(seed));
        expectNoOverlap(s::makeVillage(seed), "village seed " + std::to_string(seed));
    }
}
