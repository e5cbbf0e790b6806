// SPDX-License-Identifier: AGPL-3.0-or-later
// Motion planning on the aggregation hierarchy (paper Section 4.3) with OMPL's LazyPRM: every
// returned path is re-checked against the original objects by an independent referee (dense
// samples along the path, and for each path segment its exact distance to every original edge
// or box found by ternary search on the convex distance function); a passage closed at the
// coarse levels is still found; an unsolvable query fails within its time limit; a seed gives
// the same roadmap and path twice; bad requests are refused with a message.
#include <aggrelod/aggregate2d.h>
#include <aggrelod/collision.h>
#include <aggrelod/environments2d.h>
#include <aggrelod/planning.h>
#include <aggrelod/runtime_file.h>

#include "planning_referee.h"
#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace aggrelod;
using planning::PlanRequest;
using planning::PlanResult;
using planning::Point;
using planning::Strategy;
using aggrelod::testing::convexMin;
using aggrelod::testing::violations2D;

namespace {

planning::PlanPolygon toPlan(const Polygon2D& p) {
    planning::PlanPolygon out;
    out.rings.push_back(p.exterior);
    for (const auto& h : p.holes) out.rings.push_back(h);
    return out;
}

struct World2DFixture {
    std::vector<planning::PlanPolygon> originals;
    std::vector<std::vector<planning::PlanPolygon>> levels;
    std::vector<double> deltas;
    std::unique_ptr<planning::PlanningWorld> world;

    World2DFixture(const std::vector<Feature2D>& features, const std::vector<double>& explicitDeltas, double radius,
                   int automaticLevels = 4) {
        Settings2D settings;
        settings.deltas = explicitDeltas;
        settings.automaticLevelCount = automaticLevels;
        settings.computeBaselines = false;
        settings.threadCount = 1;
        Hierarchy2D h;
        EXPECT_TRUE(buildHierarchy2D(features, settings, h));
        for (const Feature2D& f : features)
            for (const Polygon2D& p : f.polygons) originals.push_back(toPlan(p));
        for (const Level2D& level : h.levels) {
            levels.emplace_back();
            deltas.push_back(level.delta);
            for (const Aggregate2D& a : level.aggregates)
                for (const Polygon2D& p : a.polygons) levels.back().push_back(toPlan(p));
        }
        if (radius > 0) world = planning::makeWorld2D(originals, levels, deltas, radius);
    }
};

Feature2D rect(const std::string& name, double x0, double y0, double x1, double y1) {
    Feature2D f;
    f.name = name;
    f.polygons.push_back({{x0, y0, x1, y0, x1, y1, x0, y1}, {}});
    return f;
}

// Random free query ends (free for the originals), seeded.
std::vector<std::pair<Point, Point>> randomQueries(const planning::PlanningWorld& w, int count, uint32_t seed) {
    std::mt19937 rng(seed);
    const Point lo = w.boundsMin(), hi = w.boundsMax();
    auto sample = [&] {
        for (;;) {
            Point p{0, 0, 0};
            for (int k = 0; k < w.dimension(); ++k)
                p[size_t(k)] = lo[size_t(k)] + (hi[size_t(k)] - lo[size_t(k)]) * (double(rng()) / 4294967296.0);
            if (w.stateFree(0, p)) return p;
        }
    };
    std::vector<std::pair<Point, Point>> out;
    for (int i = 0; i < count; ++i) {
        const Point a = sample();
        out.push_back({a, sample()});
    }
    return out;
}

}  // namespace

TEST(Planning2D, EveryPathIsFreeForTheOriginals) {
    World2DFixture f(samples::makeEnvironment2D(samples::Environment2D::Scatter, 1), {}, 0.0, 4);
    // Radius: a fraction of the environment's size.
    const Point lo0 = planning::makeWorld2D(f.originals, {}, {}, 1.0)->boundsMin();
    const Point hi0 = planning::makeWorld2D(f.originals, {}, {}, 1.0)->boundsMax();
    const double radius = 0.004 * std::max(hi0[0] - lo0[0], hi0[1] - lo0[1]);
    auto world = planning::makeWorld2D(f.originals, f.levels, f.deltas, radius);
    ASSERT_EQ(world->levelCount(), int(f.levels.size()) + 1);
    int solved = 0, total = 0, bad = 0;
    const auto queries = randomQueries(*world, 6, 7);
    std::vector<std::pair<Strategy, int>> strategies = {{Strategy::Hierarchy, 0}, {Strategy::Originals, 0}};
    for (int l = 1; l < world->levelCount(); ++l) strategies.push_back({Strategy::FixedLevel, l});
    for (const auto& [strategy, level] : strategies)
        for (const auto& q : queries) {
            PlanRequest r;
            r.start = q.first;
            r.goal = q.second;
            r.strategy = strategy;
            r.fixedLevel = level;
            r.timeLimit = 0.5;
            const PlanResult res = planning::plan(*world, r);
            if (res.status == planning::PlanStatus::BadRequest) continue;  // ends not free at that level
            ++total;
            if (!res.solved()) continue;
            ++solved;
            ASSERT_GE(res.path.size(), 2u);
            EXPECT_EQ(res.path.front(), q.first);
            EXPECT_EQ(res.path.back(), q.second);
            bad += violations2D(f.originals, res.path, radius);
        }
    EXPECT_EQ(bad, 0);
    EXPECT_GE(solved, 12) << "of " << total;
}

TEST(Planning2D, PassageClosedAtCoarseLevelsIsFound) {
    // Two walls leave one gap of 1.0; delta 2 and 4 join them (the gap is filled), delta 0.5
    // does not. The corner posts keep start and goal outside the coarse aggregates.
    std::vector<Feature2D> features = {rect("wall low", 4, 0, 5, 4.5), rect("wall high", 4, 5.5, 5, 10),
                                       rect("post left", 0, 9.6, 0.4, 10), rect("post right", 9.6, 0, 10, 0.4)};
    World2DFixture f(features, {0.5, 2, 4}, 0.2);
    const planning::PlanningWorld& w = *f.world;
    ASSERT_EQ(w.levelCount(), 4);
    const Point gap{4.5, 5.0, 0};
    EXPECT_TRUE(w.stateFree(0, gap));
    EXPECT_TRUE(w.stateFree(1, gap));
    EXPECT_FALSE(w.stateFree(2, gap));
    EXPECT_FALSE(w.stateFree(3, gap));

    PlanRequest r;
    r.start = {1, 2, 0};
    r.goal = {9, 8, 0};
    r.timeLimit = 5;
    r.levelSamples = 200;
    const PlanResult h = planning::plan(w, r);
    ASSERT_TRUE(h.solved()) << h.message;
    ASSERT_GE(h.levelsUsed.size(), 2u);
    EXPECT_GE(h.levelsUsed.front(), 2);  // started where the gap is closed
    EXPECT_LE(h.levelsUsed.back(), 1);   // descended to where it is open
    EXPECT_EQ(violations2D(f.originals, h.path, 0.2), 0);
    // The path goes through the gap.
    bool throughGap = false;
    for (size_t i = 0; i + 1 < h.path.size(); ++i)
        if ((h.path[i][0] - 4.5) * (h.path[i + 1][0] - 4.5) <= 0) throughGap = true;
    EXPECT_TRUE(throughGap);
    // Vertices added at the finer level lie where the coarse level is blocked.
    int finer = 0, inOpened = 0;
    for (size_t i = 0; i < h.vertices.size(); ++i)
        if (h.vertexLevel[i] == h.levelsUsed.back() && h.vertices[i] != r.start && h.vertices[i] != r.goal) {
            ++finer;
            if (!w.stateFree(h.levelsUsed[h.levelsUsed.size() - 2], h.vertices[i])) ++inOpened;
        }
    EXPECT_GT(finer, 0);
    EXPECT_GE(inOpened, finer * 9 / 10);

    // At a coarse level alone the query has no solution.
    r.strategy = Strategy::FixedLevel;
    r.fixedLevel = 3;
    r.timeLimit = 0.3;
    const PlanResult coarse = planning::plan(w, r);
    EXPECT_EQ(coarse.status, planning::PlanStatus::NotFound);
}

TEST(Planning2D, UnsolvableQueryFailsWithinTheTimeLimit) {
    // The goal sits in the hole of a square ring.
    Feature2D ring;
    ring.name = "ring";
    ring.polygons.push_back({{0, 0, 10, 0, 10, 10, 0, 10}, {{3, 3, 3, 7, 7, 7, 7, 3}}});
    std::vector<Feature2D> features = {ring, rect("far", 14, 0, 15, 10)};
    World2DFixture f(features, {1, 6}, 0.2);
    PlanRequest r;
    r.start = {12, 5, 0};
    r.goal = {5, 5, 0};
    r.timeLimit = 0.4;
    const PlanResult res = planning::plan(*f.world, r);
    EXPECT_EQ(res.status, planning::PlanStatus::NotFound);
    EXPECT_LT(res.seconds, 0.4 + 0.3);
    EXPECT_GT(res.roadmapVertices, 10u);
}

TEST(Planning2D, SameSeedSameRoadmapAndPath) {
    World2DFixture f(samples::makeEnvironment2D(samples::Environment2D::Room, 1), {}, 0.0, 4);
    const Point lo = planning::makeWorld2D(f.originals, {}, {}, 1.0)->boundsMin();
    const Point hi = planning::makeWorld2D(f.originals, {}, {}, 1.0)->boundsMax();
    auto world = planning::makeWorld2D(f.originals, f.levels, f.deltas, 0.003 * (hi[0] - lo[0]));
    const auto q = randomQueries(*world, 1, 3)[0];
    PlanRequest r;
    r.start = q.first;
    r.goal = q.second;
    r.timeLimit = 5;
    r.seed = 42;
    const PlanResult a = planning::plan(*world, r), b = planning::plan(*world, r);
    ASSERT_TRUE(a.solved());
    EXPECT_EQ(a.path, b.path);
    EXPECT_EQ(a.vertices, b.vertices);
    EXPECT_EQ(a.edges, b.edges);
    EXPECT_EQ(a.levelsUsed, b.levelsUsed);
    EXPECT_EQ(a.collisionChecks(), b.collisionChecks());
    r.seed = 43;
    const PlanResult c = planning::plan(*world, r);
    EXPECT_NE(a.vertices, c.vertices);
}

TEST(Planning2D, BadRequestsAreRefused) {
    std::vector<Feature2D> features = {rect("a", 0, 0, 2, 2), rect("b", 4, 0, 6, 2)};
    World2DFixture f(features, {3}, 0.1);
    PlanRequest r;
    r.start = {1, 1, 0};  // inside a
    r.goal = {3, 1, 0};
    PlanResult res = planning::plan(*f.world, r);
    EXPECT_EQ(res.status, planning::PlanStatus::InvalidStart);
    EXPECT_NE(res.message.find("inside an obstacle"), std::string::npos) << res.message;
    r.start = {3, 1, 0};
    r.goal = {30, 1, 0};
    res = planning::plan(*f.world, r);
    EXPECT_EQ(res.status, planning::PlanStatus::InvalidGoal);
    EXPECT_NE(res.message.find("outside the scene"), std::string::npos) << res.message;
    r.goal = {3, 0.5, 0};
    r.strategy = Strategy::FixedLevel;
    r.fixedLevel = 7;
    EXPECT_EQ(planning::plan(*f.world, r).status, planning::PlanStatus::BadRequest);
    r.strategy = Strategy::Originals;
    r.timeLimit = 0;
    EXPECT_EQ(planning::plan(*f.world, r).status, planning::PlanStatus::BadRequest);
    EXPECT_THROW(planning::makeWorld2D(f.originals, f.levels, f.deltas, 0.0), std::invalid_argument);
    EXPECT_THROW(planning::makeWorld2D(f.originals, f.levels, f.deltas, -1.0), std::invalid_argument);
}

// ---- 3D ---------------------------------------------------------------------------------

namespace {

struct Box {
    double lo[3], hi[3];
};

double pointBoxDist(const double p[3], const Box& b) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
        const double d = std::max({b.lo[k] - p[k], 0.0, p[k] - b.hi[k]});
        s += d * d;
    }
    return std::sqrt(s);
}

int violations3D(const std::vector<Box>& boxes, const std::vector<Point>& path, double r) {
    int bad = 0;
    for (size_t i = 0; i + 1 < path.size(); ++i) {
        const Point a = path[i], b = path[i + 1];
        for (const Box& box : boxes) {
            const double d = convexMin([&](double t) {
                const double p[3] = {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])};
                return pointBoxDist(p, box);
            });
            if (d <= r * (1 - 1e-6)) ++bad;
        }
    }
    return bad;
}

struct City {
    std::vector<uint8_t> bytes;
    runtime::RuntimeFile file;
    std::vector<Box> boxes;
    City(uint32_t objects, uint32_t seed) {
        std::string error;
        EXPECT_TRUE(runtime::writeRuntimeFile(aggrelod::testing::makeSyntheticHierarchy(objects, seed, 3), bytes, error)) << error;
        EXPECT_EQ(runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error), runtime::FileStatus::Ok);
        for (uint32_t i = 0; i < file.nodeCount(); ++i)
            if (file.isLeaf(i)) {
                const runtime::NodeRecord& n = file.node(i);
                boxes.push_back({{n.boundsMin[0], n.boundsMin[1], n.boundsMin[2]}, {n.boundsMax[0], n.boundsMax[1], n.boundsMax[2]}});
            }
    }
};

}  // namespace

TEST(Planning3D, EveryPathIsFreeForTheOriginalsAndDeterministic) {
    City city(64, 5);
    auto world = planning::makeWorld3D(city.file, 0.5);
    ASSERT_GE(world->levelCount(), 3);
    // State checks agree with the boxes.
    std::mt19937 rng(1);
    const Point lo = world->boundsMin(), hi = world->boundsMax();
    int disagree = 0;
    for (int i = 0; i < 2000; ++i) {
        Point p;
        for (int k = 0; k < 3; ++k) p[size_t(k)] = lo[size_t(k)] + (hi[size_t(k)] - lo[size_t(k)]) * (double(rng()) / 4294967296.0);
        const double q[3] = {p[0], p[1], p[2]};
        bool blocked = false;
        for (const Box& b : city.boxes) blocked = blocked || pointBoxDist(q, b) <= 0.5;
        if (blocked == world->stateFree(0, p)) ++disagree;
    }
    EXPECT_EQ(disagree, 0);

    int solved = 0, bad = 0;
    for (const auto& q : randomQueries(*world, 8, 11))
        for (Strategy s : {Strategy::Hierarchy, Strategy::Originals}) {
            PlanRequest r;
            r.start = q.first;
            r.goal = q.second;
            r.strategy = s;
            r.timeLimit = 1;
            const PlanResult res = planning::plan(*world, r);
            if (!res.solved()) continue;
            ++solved;
            bad += violations3D(city.boxes, res.path, 0.5);
            if (s == Strategy::Hierarchy && solved <= 2) {
                const PlanResult again = planning::plan(*world, r);
                EXPECT_EQ(again.path, res.path);
                EXPECT_EQ(again.vertices, res.vertices);
                EXPECT_EQ(again.edges, res.edges);
            }
        }
    EXPECT_EQ(bad, 0);
    EXPECT_GE(solved, 12);
}

TEST(Planning3D, BadRequestsAreRefused) {
    City city(16, 2);
    EXPECT_THROW(planning::makeWorld3D(city.file, 0.0), std::invalid_argument);
    auto world = planning::makeWorld3D(city.file, 0.3);
    const Box& b = city.boxes[0];
    PlanRequest r;
    r.start = {0.5 * (b.lo[0] + b.hi[0]), 0.5 * (b.lo[1] + b.hi[1]), 0.5 * (b.lo[2] + b.hi[2])};
    r.goal = world->boundsMax();
    const PlanResult res = planning::plan(*world, r);
    EXPECT_EQ(res.status, planning::PlanStatus::InvalidStart);
    EXPECT_NE(res.message.find("inside an obstacle"), std::string::npos) << res.message;
}
