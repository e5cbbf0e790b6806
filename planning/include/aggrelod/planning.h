// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod planning: motion planning for a round agent (a disc in 2D, a ball in 3D) with the
// aggregation hierarchy, paper Section 4.3 and Fig. 7, on OMPL.
//
// A PlanningWorld answers "is a state free" and "is a straight motion free" against one level
// of a hierarchy. Level 0 is always the original objects; levels 1..levelCount()-1 are the
// aggregate levels, coarser with each index. Every level's obstacles contain the originals
// (each aggregate contains its objects), so a state or motion free at any level is free for
// the originals: a path found at any level is a path for the originals.
//
// plan() runs OMPL's LazyPRM (Bohlin and Kavraki's lazy probabilistic roadmap, the stock
// ompl::geometric::LazyPRM) with one of three strategies:
//   - Originals: on level 0 only;
//   - FixedLevel: on one level only;
//   - Hierarchy (Section 4.3): on the coarsest level where start and goal are free first; when
//     that level's roadmap has not solved the query after `levelSamples` new roadmap vertices,
//     the next finer level is used with the same roadmap (every vertex and edge found free so
//     far is kept without a new check; vertices and edges found blocked were dropped), and new
//     vertices are sampled only where free space opened up (states blocked at the coarser level
//     used before and free at this one), until solved, out of time, or level 0 ran out of time.
//
// Units: coordinates, radius and lengths in scene units; times in seconds. 2D states use
// x, y (z is 0 and ignored). Determinism: the same world, request and seed give the same
// roadmap and path (one thread; OMPL's random numbers seeded from the request).
// Dependencies: OMPL (inside src/planner_ompl.cpp only) and the runtime's Embree collision
// world (3D); never TetGen or CGAL.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace aggrelod::runtime {
class RuntimeFile;
}

namespace aggrelod::planning {

using Point = std::array<double, 3>;  ///< x, y, z (z = 0 in 2D)

/// Obstacles at the levels of a hierarchy, for an agent of a fixed radius.
class PlanningWorld {
public:
    virtual ~PlanningWorld() = default;
    /// 2 or 3.
    virtual int dimension() const = 0;
    /// Number of levels, >= 1 (level 0 = originals).
    virtual int levelCount() const = 0;
    /// Threshold delta of a level (0 for the originals), scene units.
    virtual double levelDelta(int level) const = 0;
    /// The aggregate level number in the hierarchy file of a world level (-1 for level 0).
    virtual int levelNumber(int level) const = 0;
    /// Box the agent's centre must stay in, scene units (z ignored in 2D).
    virtual Point boundsMin() const = 0;
    virtual Point boundsMax() const = 0;
    /// Agent radius, scene units, > 0.
    virtual double radius() const = 0;
    /// True when the agent centred at p is inside the bounds, touches no obstacle surface of
    /// this level and is not inside an obstacle.
    virtual bool stateFree(int level, const Point& p) const = 0;
    /// True when the agent moving on the straight segment a-b touches no obstacle of this
    /// level (exact: the swept disc / capsule against every edge / triangle). Assumes a is free.
    virtual bool motionFree(int level, const Point& a, const Point& b) const = 0;
};

/// A polygon with holes: rings of x y pairs (2 * n doubles each, open, either orientation).
struct PlanPolygon {
    std::vector<std::vector<double>> rings;  ///< rings[0] the exterior, the others holes
};

/// 2D world: level 0 = `originals`, level k = levels[k - 1] (ascending delta). Obstacles are
/// indexed in a uniform grid of edges, with winding numbers at cell centres for the inside test.
/// Throws std::invalid_argument when radius <= 0 or there are no originals.
std::unique_ptr<PlanningWorld> makeWorld2D(const std::vector<PlanPolygon>& originals,
                                           const std::vector<std::vector<PlanPolygon>>& levels,
                                           const std::vector<double>& deltas, double radius);

/// 3D world on a runtime file (kept alive by the caller): level 0 = the original objects,
/// level k = the k-th aggregate level of the file (ascending), each an Embree collision world;
/// the bounds are the scene box. Throws std::invalid_argument when radius <= 0, and
/// std::runtime_error when Embree fails.
std::unique_ptr<PlanningWorld> makeWorld3D(const runtime::RuntimeFile& file, double radius);

enum class Strategy { Hierarchy, Originals, FixedLevel };

struct PlanRequest {
    Point start{}, goal{};
    Strategy strategy = Strategy::Hierarchy;
    int fixedLevel = 0;         ///< world level for FixedLevel
    double timeLimit = 10;      ///< seconds for the whole query
    uint32_t seed = 1;          ///< OMPL random numbers
    int levelSamples = 500;     ///< Hierarchy: new roadmap vertices tried per level before descending
};

/// Why plan() returned what it returned.
enum class PlanStatus { Solved, NotFound, InvalidStart, InvalidGoal, BadRequest };

struct PlanResult {
    PlanStatus status = PlanStatus::BadRequest;
    std::string message;              ///< for anything but Solved / NotFound
    std::vector<Point> path;          ///< start ... goal, roadmap vertices in between
    std::vector<int> levelsUsed;      ///< world levels planned on, in order
    double seconds = 0;               ///< wall time of the query
    uint64_t stateChecks = 0;         ///< stateFree calls (sampler and planner)
    uint64_t motionChecks = 0;        ///< motionFree calls
    size_t roadmapVertices = 0;       ///< at the end
    size_t roadmapEdges = 0;
    double pathLength = 0;            ///< scene units (0 when not solved)
    /// The final roadmap for pictures: vertices with the world level at which each was added,
    /// edges as vertex index pairs with the level at which each was added.
    std::vector<Point> vertices;
    std::vector<int> vertexLevel;
    std::vector<std::array<uint32_t, 2>> edges;
    std::vector<int> edgeLevel;
    bool solved() const { return status == PlanStatus::Solved; }
    uint64_t collisionChecks() const { return stateChecks + motionChecks; }
};

/// Plans one query. Never throws for bad requests (status BadRequest / InvalidStart /
/// InvalidGoal with a message: start or goal outside the bounds or touching an obstacle at
/// level 0, a FixedLevel outside the world, a time limit <= 0).
PlanResult plan(const PlanningWorld& world, const PlanRequest& request);

/// "hierarchy", "originals", "level:K".
std::string strategyName(Strategy strategy, int fixedLevel);

}  // namespace aggrelod::planning
