// SPDX-License-Identifier: AGPL-3.0-or-later
// Coarse-to-fine roadmap planning on the aggregation hierarchy (paper Section 4.3, Fig. 7),
// with OMPL's LazyPRM. The only translation unit that includes OMPL (its headers pull Boost).
//
// One LazyPRM roadmap lives through the whole query. Its state validity checker, motion
// validator and state sampler read the level in use from a shared context, so descending a
// level keeps the roadmap as it is: vertices and edges LazyPRM has checked stay marked valid
// (free at a coarser level, hence free for the originals, whose obstacles every level
// contains), the unchecked ones are checked against the new level when a candidate path uses
// them, and what was found blocked had been removed. New vertices at a finer level come from
// the region that opened up: states blocked at the coarser level used before and free at this
// one (rejection sampling, bounded).
#include <aggrelod/planning.h>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/PlannerData.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/StateSampler.h>
#include <ompl/base/StateValidityChecker.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathGeometric.h>
#include <ompl/geometric/planners/prm/LazyPRM.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>

namespace aggrelod::planning {
namespace {

namespace ob = ompl::base;
namespace og = ompl::geometric;

/// Attempts of the opened-region sampler before it settles for a uniform sample.
constexpr int kOpenedSamplerAttempts = 1000;

struct Context {
    const PlanningWorld* world = nullptr;
    int dimension = 2;
    int level = 0;         ///< level checked against
    int coarser = -1;      ///< level used before (sampling region), -1 = none
    uint64_t stateChecks = 0;
    uint64_t motionChecks = 0;

    Point point(const ob::State* s) const {
        const auto* v = s->as<ob::RealVectorStateSpace::StateType>()->values;
        return {v[0], v[1], dimension == 3 ? v[2] : 0.0};
    }
    bool stateFree(int l, const Point& p) {
        ++stateChecks;
        return world->stateFree(l, p);
    }
};

class LevelValidityChecker final : public ob::StateValidityChecker {
public:
    LevelValidityChecker(const ob::SpaceInformationPtr& si, Context& c) : ob::StateValidityChecker(si), c_(c) {}
    bool isValid(const ob::State* s) const override { return c_.stateFree(c_.level, c_.point(s)); }

private:
    Context& c_;
};

class LevelMotionValidator final : public ob::MotionValidator {
public:
    LevelMotionValidator(const ob::SpaceInformationPtr& si, Context& c) : ob::MotionValidator(si), c_(c) {}
    bool checkMotion(const ob::State* a, const ob::State* b) const override {
        ++c_.motionChecks;
        const bool ok = c_.world->motionFree(c_.level, c_.point(a), c_.point(b));
        if (ok)
            ++valid_;
        else
            ++invalid_;
        return ok;
    }
    bool checkMotion(const ob::State* a, const ob::State* b, std::pair<ob::State*, double>& lastValid) const override {
        const bool ok = checkMotion(a, b);
        if (!ok) {
            if (lastValid.first) si_->copyState(lastValid.first, a);
            lastValid.second = 0;
        }
        return ok;
    }

private:
    Context& c_;
};

/// Uniform in the bounds on the first level; on a finer level, in the region that opened up.
class OpenedRegionSampler final : public ob::StateSampler {
public:
    OpenedRegionSampler(const ob::StateSpace* space, Context& c, uint32_t seed) : ob::StateSampler(space), c_(c) {
        rng_.setLocalSeed(seed);
    }
    void sampleUniform(ob::State* state) override {
        auto* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
        const Point lo = c_.world->boundsMin(), hi = c_.world->boundsMax();
        for (int attempt = 0;; ++attempt) {
            for (int k = 0; k < c_.dimension; ++k) v[k] = rng_.uniformReal(lo[size_t(k)], hi[size_t(k)]);
            if (c_.coarser < 0 || attempt + 1 >= kOpenedSamplerAttempts) return;
            const Point p = c_.point(state);
            if (!c_.stateFree(c_.coarser, p) && c_.stateFree(c_.level, p)) return;
        }
    }
    void sampleUniformNear(ob::State* state, const ob::State* near, double distance) override {
        auto* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
        const auto* n = near->as<ob::RealVectorStateSpace::StateType>()->values;
        const Point lo = c_.world->boundsMin(), hi = c_.world->boundsMax();
        for (int k = 0; k < c_.dimension; ++k)
            v[k] = std::clamp(rng_.uniformReal(n[k] - distance, n[k] + distance), lo[size_t(k)], hi[size_t(k)]);
    }
    void sampleGaussian(ob::State* state, const ob::State* mean, double stdDev) override {
        auto* v = state->as<ob::RealVectorStateSpace::StateType>()->values;
        const auto* m = mean->as<ob::RealVectorStateSpace::StateType>()->values;
        const Point lo = c_.world->boundsMin(), hi = c_.world->boundsMax();
        for (int k = 0; k < c_.dimension; ++k)
            v[k] = std::clamp(rng_.gaussian(m[k], stdDev), lo[size_t(k)], hi[size_t(k)]);
    }

private:
    Context& c_;
};

/// OMPL's process-wide seed, set once before the first planner exists (ompl::RNG::setSeed
/// refuses later changes). Each query's sampler is seeded from its request on top of it.
void seedOmplOnce(uint32_t seed) {
    static std::once_flag once;
    std::call_once(once, [seed] {
        ompl::msg::setLogLevel(ompl::msg::LOG_ERROR);
        ompl::RNG::setSeed(seed == 0 ? 1 : seed);
    });
}

double distance(const Point& a, const Point& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

}  // namespace

std::string strategyName(Strategy strategy, int fixedLevel) {
    switch (strategy) {
        case Strategy::Hierarchy: return "hierarchy";
        case Strategy::Originals: return "originals";
        case Strategy::FixedLevel: return "level:" + std::to_string(fixedLevel);
    }
    return "?";
}

PlanResult plan(const PlanningWorld& world, const PlanRequest& request) {
    using Clock = std::chrono::steady_clock;
    const Clock::time_point begin = Clock::now();
    PlanResult result;
    const int dim = world.dimension();
    auto bad = [&](PlanStatus status, const std::string& message) {
        result.status = status;
        result.message = message;
        result.seconds = std::chrono::duration<double>(Clock::now() - begin).count();
        return result;
    };
    if (!(request.timeLimit > 0)) return bad(PlanStatus::BadRequest, "the time limit must be > 0 seconds");
    if (request.strategy == Strategy::FixedLevel &&
        (request.fixedLevel < 0 || request.fixedLevel >= world.levelCount()))
        return bad(PlanStatus::BadRequest, "level " + std::to_string(request.fixedLevel) + " is not in the world (it has " +
                                               std::to_string(world.levelCount()) + " levels, 0 = originals)");

    Context ctx;
    ctx.world = &world;
    ctx.dimension = dim;
    auto describe = [&](const Point& p) {
        std::string s = std::to_string(p[0]) + "," + std::to_string(p[1]);
        if (dim == 3) s += "," + std::to_string(p[2]);
        return s;
    };
    auto inBounds = [&](const Point& p) {
        const Point lo = world.boundsMin(), hi = world.boundsMax();
        for (int k = 0; k < dim; ++k)
            if (!(p[size_t(k)] >= lo[size_t(k)] && p[size_t(k)] <= hi[size_t(k)])) return false;
        return true;
    };
    for (int end = 0; end < 2; ++end) {
        const Point& p = end == 0 ? request.start : request.goal;
        const PlanStatus status = end == 0 ? PlanStatus::InvalidStart : PlanStatus::InvalidGoal;
        const std::string name = end == 0 ? "start" : "goal";
        if (!inBounds(p)) return bad(status, name + " " + describe(p) + " is outside the scene bounds");
        if (!ctx.stateFree(0, p))
            return bad(status, name + " " + describe(p) + " is inside an obstacle or closer than the radius " +
                                   std::to_string(world.radius()) + " to one");
    }

    // The levels to plan on, coarse to fine.
    std::vector<int> order;
    if (request.strategy == Strategy::Originals) {
        order = {0};
    } else if (request.strategy == Strategy::FixedLevel) {
        if (!ctx.stateFree(request.fixedLevel, request.start) || !ctx.stateFree(request.fixedLevel, request.goal))
            return bad(PlanStatus::BadRequest, "start or goal is not free at level " + std::to_string(request.fixedLevel) +
                                                   " (inside or near an aggregate)");
        order = {request.fixedLevel};
    } else {
        for (int l = world.levelCount() - 1; l > 0; --l)
            if (ctx.stateFree(l, request.start) && ctx.stateFree(l, request.goal)) order.push_back(l);
        order.push_back(0);
    }

    seedOmplOnce(request.seed);
    auto space = std::make_shared<ob::RealVectorStateSpace>(unsigned(dim));
    ob::RealVectorBounds bounds{unsigned(dim)};
    const Point lo = world.boundsMin(), hi = world.boundsMax();
    for (int k = 0; k < dim; ++k) bounds.setLow(unsigned(k), lo[size_t(k)]), bounds.setHigh(unsigned(k), hi[size_t(k)]);
    space->setBounds(bounds);
    const uint32_t seed = request.seed;
    space->setStateSamplerAllocator(
        [&ctx, seed](const ob::StateSpace* s) { return std::make_shared<OpenedRegionSampler>(s, ctx, seed); });
    auto si = std::make_shared<ob::SpaceInformation>(space);
    si->setStateValidityChecker(std::make_shared<LevelValidityChecker>(si, ctx));
    si->setMotionValidator(std::make_shared<LevelMotionValidator>(si, ctx));
    si->setup();

    ob::ScopedState<ob::RealVectorStateSpace> start(space), goal(space);
    for (int k = 0; k < dim; ++k) start[unsigned(k)] = request.start[size_t(k)], goal[unsigned(k)] = request.goal[size_t(k)];
    auto pdef = std::make_shared<ob::ProblemDefinition>(si);
    pdef->setStartAndGoalStates(start, goal);

    auto planner = std::make_shared<og::LazyPRM>(si);
    planner->setProblemDefinition(pdef);

    // Vertex and edge of the roadmap -> level at which they first appeared (for pictures).
    std::map<Point, int> vertexLevel;
    std::map<std::pair<Point, Point>, int> edgeLevel;
    Clock::duration recordTime{};
    auto record = [&](int level) {
        struct Add {
            Clock::duration& total;
            Clock::time_point t0;
            ~Add() { total += Clock::now() - t0; }
        } add{recordTime, Clock::now()};
        ob::PlannerData data(si);
        planner->getPlannerData(data);
        for (unsigned i = 0; i < data.numVertices(); ++i) vertexLevel.emplace(ctx.point(data.getVertex(i).getState()), level);
        for (unsigned i = 0; i < data.numVertices(); ++i) {
            std::vector<unsigned> out;
            data.getEdges(i, out);
            const Point a = ctx.point(data.getVertex(i).getState());
            for (unsigned j : out) {
                const Point b = ctx.point(data.getVertex(j).getState());
                if (a < b) edgeLevel.emplace(std::make_pair(a, b), level);
            }
        }
    };

    const Clock::time_point deadline =
        begin + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(request.timeLimit));
    bool solved = false;
    for (size_t i = 0; i < order.size() && !solved; ++i) {
        ctx.level = order[i];
        ctx.coarser = i == 0 ? -1 : order[i - 1];
        result.levelsUsed.push_back(ctx.level);
        const bool last = i + 1 == order.size();
        const unsigned long cap = planner->milestoneCount() + (unsigned long)std::max(1, request.levelSamples);
        ob::PlannerTerminationCondition ptc([&] {
            return Clock::now() >= deadline || (!last && planner->milestoneCount() >= cap);
        });
        const ob::PlannerStatus status = planner->solve(ptc);
        record(ctx.level);
        solved = status == ob::PlannerStatus::EXACT_SOLUTION;
        if (Clock::now() >= deadline) break;
    }

    // Time to the answer, without the bookkeeping for pictures (record).
    result.seconds = std::chrono::duration<double>(Clock::now() - begin - recordTime).count();
    result.status = solved ? PlanStatus::Solved : PlanStatus::NotFound;
    if (solved) {
        const auto& path = static_cast<const og::PathGeometric&>(*pdef->getSolutionPath());
        for (size_t i = 0; i < path.getStateCount(); ++i) result.path.push_back(ctx.point(path.getState(i)));
        for (size_t i = 1; i < result.path.size(); ++i) result.pathLength += distance(result.path[i - 1], result.path[i]);
    }
    // The final roadmap, in a deterministic order (sorted by coordinates), each vertex and edge
    // tagged with the level at which it first appeared.
    {
        ob::PlannerData data(si);
        planner->getPlannerData(data);
        std::map<Point, unsigned> vertices;
        for (unsigned i = 0; i < data.numVertices(); ++i) vertices.emplace(ctx.point(data.getVertex(i).getState()), i);
        std::map<Point, uint32_t> index;
        for (const auto& [p, unused] : vertices) {
            (void)unused;
            index.emplace(p, uint32_t(result.vertices.size()));
            result.vertices.push_back(p);
            const auto it = vertexLevel.find(p);
            result.vertexLevel.push_back(it == vertexLevel.end() ? ctx.level : it->second);
        }
        std::map<std::pair<Point, Point>, int> edges;
        for (unsigned i = 0; i < data.numVertices(); ++i) {
            std::vector<unsigned> out;
            data.getEdges(i, out);
            const Point a = ctx.point(data.getVertex(i).getState());
            for (unsigned j : out) {
                const Point b = ctx.point(data.getVertex(j).getState());
                if (!(a < b)) continue;
                const auto it = edgeLevel.find({a, b});
                edges.emplace(std::make_pair(a, b), it == edgeLevel.end() ? ctx.level : it->second);
            }
        }
        for (const auto& [e, level] : edges) {
            result.edges.push_back({index[e.first], index[e.second]});
            result.edgeLevel.push_back(level);
        }
        result.roadmapVertices = result.vertices.size();
        result.roadmapEdges = result.edges.size();
    }
    result.stateChecks = ctx.stateChecks;
    result.motionChecks = ctx.motionChecks;
    return result;
}

}  // namespace aggrelod::planning
