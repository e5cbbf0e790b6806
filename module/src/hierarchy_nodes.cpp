// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: hierarchy nodes for real-time use (docs/design.md §2.5 and §2.6).
// Builds the tree (leaves = original objects, inner nodes = aggregates, unchanged aggregates
// collapsed across levels), simplifies every aggregate into an enclosing proxy within its
// error budget and gives each object a chain of enclosing simplifications (per-object LOD;
// conservative_simplify.cpp),
// measures its error (proxy_error.cpp), colours its faces after the nearest original surface
// (surface_colors.cpp), and makes bounds nested and errors monotone so that
// the runtime's screen-space rule (docs/design.md §3) always selects a clean cut.
#include "bounding_polytope.h"
#include "conservative_simplify.h"
#include "convex_hull.h"
#include "draw_bundles.h"
#include "node_tree.h"
#include "hierarchy_serialize.h"
#include "mesh_optimize.h"
#include "mesh_preparation.h"
#include "node_mesh_spiller.h"
#include "parallel_for.h"
#include "proxy_error.h"
#include "solidify.h"
#include "surface_colors.h"
#include "surface_shell.h"

#include <aggrelod/disjoint_sets.h>
#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/tiled_bake_3d.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>

namespace aggrelod {

namespace {

/// Relative growth of every bounding sphere radius; equal to aggrelod::runtime::kSphereMargin
/// (runtime_build.h), which the reader's nesting slack is measured against.
constexpr double kSphereMargin = 1e-6;

/// Smallest float >= x (as a double).
double floatUp(double x) {
    float f = static_cast<float>(x);
    if (double(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}
/// Largest float <= x (as a double).
double floatDown(double x) {
    float f = static_cast<float>(x);
    if (double(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    return f;
}

void growBox(double lo[3], double hi[3], const double p[3]) {
    for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], p[k]);
        hi[k] = std::max(hi[k], p[k]);
    }
}

double distance(const double a[3], const double b[3]) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]));
}

/// Fills box and sphere of `node` from its own vertices (`positions`: its float proxy or
/// original; for aggregates, also the exact double mesh) and its children, rounded to float
/// outwards.
void computeBounds(HierarchyNode& node, const std::vector<float>& positions, const std::vector<double>& exactPositions,
                   const std::vector<HierarchyNode>& nodes) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 2 < positions.size(); i += 3) {
        const double p[3] = {positions[i], positions[i + 1], positions[i + 2]};
        growBox(lo, hi, p);
    }
    for (size_t i = 0; i + 2 < exactPositions.size(); i += 3) growBox(lo, hi, &exactPositions[i]);
    for (uint32_t c : node.children) {
        growBox(lo, hi, nodes[c].boundsMin);
        growBox(lo, hi, nodes[c].boundsMax);
    }
    if (!(lo[0] <= hi[0])) {  // nothing at all (cannot happen for a validated hierarchy)
        for (int k = 0; k < 3; ++k) lo[k] = hi[k] = 0;
    }
    for (int k = 0; k < 3; ++k) {
        node.boundsMin[k] = floatDown(lo[k]);
        node.boundsMax[k] = floatUp(hi[k]);
        node.sphereCenter[k] = static_cast<float>(0.5 * (lo[k] + hi[k]));
    }
    double r = 0;
    for (size_t i = 0; i + 2 < positions.size(); i += 3) {
        const double p[3] = {positions[i], positions[i + 1], positions[i + 2]};
        r = std::max(r, distance(node.sphereCenter, p));
    }
    for (size_t i = 0; i + 2 < exactPositions.size(); i += 3) r = std::max(r, distance(node.sphereCenter, &exactPositions[i]));
    for (uint32_t c : node.children)
        r = std::max(r, distance(node.sphereCenter, nodes[c].sphereCenter) + nodes[c].sphereRadius);
    // A relative margin keeps the nesting true when a reader recomputes it in float: the
    // runtime file's kSphereMargin (runtime_build.h; the module does not include the runtime).
    node.sphereRadius = floatUp(r * (1 + kSphereMargin));
}

/// Vertex coordinates as sorted xyz triples.
std::vector<std::array<double, 3>> sortedVertices(const Aggregate& a) {
    std::vector<std::array<double, 3>> v(a.positions.size() / 3);
    for (size_t i = 0; i < v.size(); ++i) v[i] = {a.positions[3 * i], a.positions[3 * i + 1], a.positions[3 * i + 2]};
    std::sort(v.begin(), v.end());
    return v;
}

bool nearlyEqual(double x, double y) { return std::fabs(x - y) <= 1e-9 * std::max(std::fabs(x), std::fabs(y)); }

/// The same solid: same objects, same vertices, same volume and area. This tells apart real
/// changes of the fill and ignores a flat face (e.g. a planar quad of an object, filled by a
/// zero-volume sliver) split along its other diagonal at another level.
bool sameSolid(const Aggregate& a, const Aggregate& b) {
    if (a.meshInCache || b.meshInCache) {  // a lean hierarchy: by the hashes kept of the meshes
        const auto vertices = [](const Aggregate& x) { return x.meshInCache ? x.meshInCache->vertexCount : x.positions.size() / 3; };
        if (a.sourceObjects != b.sourceObjects || vertices(a) != vertices(b)) return false;
        if (aggregateMeshHash(a) == aggregateMeshHash(b)) return true;
        uint64_t ha[2], hb[2];
        aggregateVertexSetHash(a, ha);
        aggregateVertexSetHash(b, hb);
        return nearlyEqual(a.measures.volume, b.measures.volume) && nearlyEqual(a.measures.area, b.measures.area) &&
               ha[0] == hb[0] && ha[1] == hb[1];
    }
    if (a.sourceObjects != b.sourceObjects || a.positions.size() != b.positions.size()) return false;
    if (a.indices == b.indices && a.positions == b.positions) return true;
    return nearlyEqual(a.measures.volume, b.measures.volume) && nearlyEqual(a.measures.area, b.measures.area) &&
           sortedVertices(a) == sortedVertices(b);
}


/// Frees a node's proxy mesh (keeps its error and the rest): for a share, whose results are
/// in the cache.
void dropMesh(HierarchyNode& n) {
    std::vector<float>().swap(n.positions);
    std::vector<uint32_t>().swap(n.indices);
    std::vector<float>().swap(n.faceColors);
}

std::vector<float> toFloats(const std::vector<double>& v) { return std::vector<float>(v.begin(), v.end()); }

/// Largest distance a vertex moved when rounded to float (world units). Every point of the
/// float mesh's surface lies within it of the same point of the double mesh, so a double
/// enclosure of the originals stays one up to this slack.
double roundingSlack(const std::vector<double>& exact, const std::vector<float>& rounded) {
    double worst = 0;
    for (size_t i = 0; i + 2 < exact.size(); i += 3) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += (exact[i + k] - double(rounded[i + k])) * (exact[i + k] - double(rounded[i + k]));
        worst = std::max(worst, std::sqrt(d2));
    }
    return worst * (1 + 1e-12);
}

/// Certified error of an enclosure built in doubles and stored in floats: proxy -> originals
/// by branch and bound (given up once above giveUpAbove), originals -> proxy is the rounding
/// slack (the proxy encloses them by construction).
ProxyError measureEnclosure(const std::vector<double>& exact, const std::vector<float>& positions,
                            const std::vector<uint32_t>& indices,
                            const std::vector<const detail::PreparedOriginal*>& originals, double tolerance,
                            const ProxySettings& settings, double giveUpAbove,
                            detail::TriangleBoundCache* cache = nullptr) {
    detail::ProxyMeasureOptions options;
    options.enclosesOriginals = true;
    options.enclosureSlack = roundingSlack(exact, positions);
    options.giveUpAbove = giveUpAbove;
    options.cache = cache;
    return detail::measureProxyErrorPrepared(positions, indices, originals, tolerance,
                                             settings.maxRefinementsPerDirection, options);
}

/// Enclosing simplifications of one closed mesh at ascending push-out targets (world units):
/// one pass of the simplifier for the whole series; a snapshot that intersects itself is
/// made again on demand with the corners of the crossing faces pinned. Each repair round is a
/// whole simplification, and where the simplifier keeps crossing itself (a dense wrap of flat
/// faces) more rounds on other targets rarely help: a series makes at most kCleanRounds of
/// them in all, then gives up its intersecting snapshots (the callers fall back to finer
/// versions, the exact aggregate or the object itself). Benchmark scenes need none.
class EnclosureSeries {
public:
    EnclosureSeries(const std::vector<double>& positions, const std::vector<uint32_t>& indices,
                    std::vector<double> targets)
        : positions_(positions), indices_(indices), targets_(std::move(targets)), checked_(targets_.size(), 0) {
        detail::simplifyConservativeSeries(positions, indices, targets_, 0, snapshots_);
    }
    size_t size() const { return snapshots_.size(); }
    /// Triangles of snapshot i before any repair (a repair keeps more).
    size_t triangleCount(size_t i) const { return snapshots_[i].indices.size() / 3; }
    double target(size_t i) const { return targets_[i]; }
    /// Snapshot i without self-intersections, or null when pinning could not remove them.
    const detail::ConservativeSnapshot* clean(size_t i) {
        if (!checked_[i]) {
            checked_[i] = 1;
            if (detail::meshSelfIntersects(snapshots_[i].positions, snapshots_[i].indices)) {
                if (roundsLeft_ <= 0) {
                    checked_[i] = 2;
                    return nullptr;
                }
                detail::ConservativeSnapshot redone;
                int rounds = 0;
                checked_[i] = detail::simplifyConservativeClean(positions_, indices_, targets_[i], pinned_,
                                                                roundsLeft_, redone, &rounds) ? 1 : 2;
                roundsLeft_ -= rounds;
                snapshots_[i] = std::move(redone);
            }
        }
        return checked_[i] == 1 ? &snapshots_[i] : nullptr;
    }

private:
    /// Rounds of pinning crossing faces a series may make in all.
    static constexpr int kCleanRounds = 6;
    int roundsLeft_ = kCleanRounds;
    const std::vector<double>& positions_;
    const std::vector<uint32_t>& indices_;
    std::vector<double> targets_;
    std::vector<detail::ConservativeSnapshot> snapshots_;
    std::vector<char> checked_;  ///< 0 unchecked, 1 clean, 2 intersecting
    std::vector<char> pinned_;
};

/// Whether a triangle has two corners at one float position.
bool hasCollapsedTriangle(const std::vector<float>& positions, const std::vector<uint32_t>& indices) {
    const auto same = [&](uint32_t a, uint32_t b) {
        return positions[3 * a] == positions[3 * b] && positions[3 * a + 1] == positions[3 * b + 1] &&
               positions[3 * a + 2] == positions[3 * b + 2];
    };
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        if (same(indices[t], indices[t + 1]) || same(indices[t + 1], indices[t + 2]) || same(indices[t + 2], indices[t]))
            return true;
    return false;
}

/// Few-faced convex polytopes around a closed mesh's convex hull (bounding_polytope.h), each
/// built and measured once, on demand. A polytope within d of the hull lies within d plus the
/// hull's error of the originals; that error, estimated from below by the distance found at
/// the hull's faces' centroids, screens the candidates before they are measured. No polytope
/// does better than that distance (a point outside a hull face is no nearer the originals
/// behind it than the face's point below it).
class PolytopeSource {
public:
    PolytopeSource(const std::vector<double>& positions, const std::vector<const detail::PreparedOriginal*>& originals,
                   const ProxySettings& settings, double giveUpAbove, detail::TriangleBoundCache* cache)
        : originals_(originals), settings_(settings), cache_(cache) {
        if (settings.polytopeVertices < 4) return;
        std::vector<double> hullPositions;
        std::vector<uint32_t> hullIndices;
        if (!detail::convexHull3(positions, hullPositions, hullIndices)) return;
        for (size_t t = 0; t + 2 < hullIndices.size(); t += 3) {
            double c[3];
            for (int k = 0; k < 3; ++k)
                c[k] = (hullPositions[3 * hullIndices[t] + k] + hullPositions[3 * hullIndices[t + 1] + k] +
                        hullPositions[3 * hullIndices[t + 2] + k]) / 3.0;
            // A centroid with an original within the largest distance so far cannot raise it.
            if (t > 0 && std::any_of(originals.begin(), originals.end(), [&](const detail::PreparedOriginal* o) {
                    return detail::anyWithin(o->bvh, c, hullReach_);
                }))
                continue;
            double nearest = INFINITY;
            for (const detail::PreparedOriginal* o : originals)
                nearest = std::min(nearest, detail::closestPoint(o->bvh, c, nearest).distance);
            hullReach_ = std::max(hullReach_, nearest);
        }
        if (!(hullReach_ < giveUpAbove)) return;
        enclosed_ = positions;
        polytopes_ = detail::boundingPolytopes(hullPositions, hullIndices, size_t(settings.polytopeVertices), 0.0);
        measured_.resize(polytopes_.size());
    }

    /// The coarsest polytope whose certified error fits `budget`, with at most
    /// maxTriangles triangles; false when none does. n gets positions, indices and error.
    /// Callers ask for ascending budgets: each polytope's mesh is built and its error
    /// measured once (again only when an earlier measurement gave up below the new budget).
    bool coarsestWithin(double budget, size_t maxTriangles, double tolerance, HierarchyNode& n,
                        std::vector<double>* exact = nullptr) {
        int tried = 0;
        for (size_t i = 0; i < polytopes_.size(); ++i) {
            const detail::BoundingPolytope& p = polytopes_[i];
            if (2 * (p.vertices.size() / 3) > maxTriangles + 4) break;  // a triangulated polytope has 2V - 4 faces
            if (!(p.distanceToHull + hullReach_ <= budget)) continue;
            Measured& m = measured_[i];
            if (m.state == Measured::Unbuilt) {
                std::vector<double> positions;
                m.state = Measured::Unusable;
                if (!detail::boundingPolytopeMesh(p, enclosed_, positions, m.indices)) continue;
                m.positions = toFloats(positions);
                if (hasCollapsedTriangle(m.positions, m.indices)) continue;  // corners merged by float rounding
                m.exact = std::move(positions);
                m.state = Measured::Built;
            }
            if (m.state == Measured::Unusable || m.indices.size() / 3 > maxTriangles) continue;
            // Measured again only when an earlier measurement stopped at a distance found
            // over its budget but not over this one.
            if (m.state == Measured::Built || (m.state == Measured::GaveUp && !(m.error.proxyToOriginalsLower > budget))) {
                m.error = measureEnclosure(m.exact, m.positions, m.indices, originals_, tolerance, settings_, budget, cache_);
                m.state = m.error.proxyToOriginalsLower > budget ? Measured::GaveUp : Measured::Certified;
            }
            if (m.state == Measured::Certified && m.error.bound() <= budget) {
                n.positions = m.positions;
                n.indices = m.indices;
                n.error = m.error;
                if (exact) *exact = m.exact;
                return true;
            }
            if (++tried == 2) break;  // the bound by the triangle inequality was loose twice
        }
        return false;
    }

private:
    /// A polytope's mesh and certified error, made once.
    struct Measured {
        enum State { Unbuilt, Unusable, Built, Certified, GaveUp } state = Unbuilt;
        std::vector<double> exact;
        std::vector<float> positions;
        std::vector<uint32_t> indices;
        ProxyError error;  ///< Certified: final; GaveUp: stopped early, proxyToOriginalsLower is a distance found
    };
    const std::vector<const detail::PreparedOriginal*>& originals_;
    const ProxySettings& settings_;
    std::vector<double> enclosed_;
    std::vector<detail::BoundingPolytope> polytopes_;
    std::vector<Measured> measured_;
    detail::TriangleBoundCache* cache_;
    double hullReach_ = 0;  ///< a distance from the hull to the originals found at its faces' centroids
};

/// A proxy as built, in doubles, before vertex-cache ordering: what its coarser versions
/// are simplified from.
struct ExactProxy {
    std::vector<double> positions;
    std::vector<uint32_t> indices;
};

/// Push-out allowances tried for a proxy, as fractions of the room its budget leaves above
/// the exact aggregate's own error, coarsest first (the simplification's estimate is a
/// vertex-to-plane distance, not the certified one, so the largest can still miss).
constexpr double kRoomFractions[] = {1.0 / 4, 1.0 / 2, 1.0, 2.0, 4.0};

/// The proxy of an aggregate node (docs/design.md §2.6). Its budget is the exact aggregate's
/// own certified error (the fill between the originals: nothing that encloses the aggregate
/// does better) plus simplifyFraction * delta of room; the proxy is the coarsest
/// conservative simplification of the aggregate that does not intersect itself and whose
/// certified error fits the budget, else the exact aggregate.
void makeAggregateProxy(const Aggregate& agg, const std::vector<const detail::PreparedOriginal*>& originals,
                        const ProxySettings& settings, HierarchyNode& n, ExactProxy& exactProxy) {
    const double tolerance = settings.toleranceFraction * n.delta;
    n.positions = toFloats(agg.positions);
    n.indices = agg.indices;
    exactProxy = {agg.positions, agg.indices};
    detail::TriangleBoundCache cache;  // the aggregate's faces on its originals, and those the versions share
    for (const detail::PreparedOriginal* o : originals) cache.addOriginal(*o->object);
    n.error = measureEnclosure(agg.positions, n.positions, n.indices, originals, tolerance, settings, INFINITY, &cache);
    const double room = settings.simplifyFraction * n.delta;
    n.budget = n.error.bound() + room;
    if (!(room > 0)) return;
    std::vector<double> targets;
    for (double f : kRoomFractions) targets.push_back(f * room);
    EnclosureSeries series(agg.positions, agg.indices, targets);
    for (size_t i = series.size(); i-- > 0;) {
        const detail::ConservativeSnapshot* clean = series.clean(i);
        if (!clean) continue;
        const detail::ConservativeSnapshot& s = *clean;
        if (s.indices.size() >= agg.indices.size()) break;  // no coarser than the exact one
        std::vector<float> positions = toFloats(s.positions);
        const ProxyError e = measureEnclosure(s.positions, positions, s.indices, originals, tolerance, settings, n.budget, &cache);
        if (e.bound() <= n.budget) {
            n.positions = std::move(positions);
            n.indices = s.indices;
            n.error = e;
            exactProxy = {s.positions, s.indices};
            return;
        }
    }
}

/// A version is worth a node of its own when it has at most this share of the triangles of
/// the finer one it would replace (a cut drawing it saves at least the rest).
constexpr size_t kWorthNumerator = 9, kWorthDenominator = 10;
bool lighterEnough(size_t triangles, size_t finerTriangles) {
    return kWorthDenominator * triangles <= kWorthNumerator * finerTriangles;
}

/// Snapshot i of a chain's series when it is clean and lighter enough than finerTriangles
/// (else not worth a node), else null.
const detail::ConservativeSnapshot* lighterCleanSnapshot(EnclosureSeries& series, size_t i, size_t finerTriangles) {
    if (!lighterEnough(series.triangleCount(i), finerTriangles)) return nullptr;
    const detail::ConservativeSnapshot* clean = series.clean(i);
    if (!clean || !lighterEnough(clean->indices.size() / 3, finerTriangles)) return nullptr;
    return clean;
}

/// Connected pieces of a triangle mesh (triangles sharing a vertex are connected).
size_t shellCount(size_t vertexCount, const std::vector<uint32_t>& triangles) {
    DisjointSets sets(vertexCount);
    for (size_t t = 0; t + 2 < triangles.size(); t += 3)
        for (int k = 1; k < 3; ++k) sets.unite(triangles[t], triangles[t + k]);
    std::vector<char> used(vertexCount, 0);
    for (uint32_t v : triangles) used[v] = 1;
    size_t count = 0;
    for (uint32_t v = 0; v < vertexCount; ++v) count += used[v] && sets.find(v) == v;
    return count;
}

/// The lightest chain through candidate versions of one node, finest first: by ascending
/// certified error, a candidate is kept when it is lighter enough than the one kept before it
/// (the first: than finerTriangles, the node's own), at most maxCount of them.
/// A version with a larger error is selectable only from farther away, so of two errors the
/// chain keeps both when the coarser one is lighter enough to be worth a node.
std::vector<HierarchyNode> lightestChain(std::vector<HierarchyNode> candidates, size_t finerTriangles, int maxCount) {
    std::vector<size_t> order(candidates.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const double ea = candidates[a].error.bound(), eb = candidates[b].error.bound();
        return ea < eb || (ea == eb && candidates[a].indices.size() < candidates[b].indices.size());
    });
    std::vector<HierarchyNode> chain;
    for (size_t i : order) {
        if (int(chain.size()) >= maxCount) break;
        const size_t triangles = candidates[i].indices.size() / 3;
        if (!lighterEnough(triangles, finerTriangles)) continue;
        finerTriangles = triangles;
        chain.push_back(std::move(candidates[i]));
    }
    return chain;
}

/// Error targets of per-object LOD chains: a geometric series sqrt(2) apart, from this
/// fraction of the object's box diagonal up.
constexpr double kChainFinestFraction = 1.0 / 1024;
/// The same for a support surface. It spans at least half the scene, so from a camera one
/// scene radius from it one pixel (1080 px, 60 degrees) is 1/1000 to 1/2000 of its diagonal,
/// which a version made for a quarter of that (its budget is twice its target) fits.
constexpr double kSupportChainFinestFraction = 1.0 / 4096;
/// An object's versions are measured this many times further (ProxySettings::
/// maxRefinementsPerDirection) than other proxies: on a large object the bound stops far
/// above the distance found (truck_town's racetrack: 0.37 against 0.22), which refuses finer
/// versions and keeps the others from being drawn as near as they could be. A version is an
/// object's own, so the extra work is small (the 400-object scene's proxies stage: no change
/// measured).
constexpr size_t kVersionRefinementFactor = 10;
constexpr double kChainRatio = 1.4142135623730951;

/// One certified enclosing version of an object: the node as stored (float positions,
/// indices, error, budget) and its vertices in doubles (what unions are made from).
struct Version {
    HierarchyNode node;
    std::vector<double> exact;
};

/// Every certified enclosing version of one object, ascending by error (ties: fewer
/// triangles first): its per-object LOD chain is chosen from them (chainFromLadder), and the
/// coarser versions of the groups holding it are united from them (coarserChain).
struct VersionLadder {
    std::vector<Version> versions;
    size_t objectTriangles = 0;
    /// The version with the fewest triangles whose error is at most `error`; null for none.
    const Version* lightestWithin(double error) const {
        const Version* best = nullptr;
        for (const Version& v : versions)
            if (v.node.error.bound() <= error && (!best || v.node.indices.size() < best->node.indices.size())) best = &v;
        return best;
    }
};

/// Offset and smallest cavity of the solid made for a support surface's versions, as
/// fractions of its box diagonal: the bake's default for a model's wrap (docs/real-art.md).
constexpr double kSupportSolidOffsetFraction = 0.004;
constexpr double kSupportSolidAlphaFraction = 0.015;

/// A closed solid containing an open surface that has no solid from the bake (a support
/// surface, in no model): the surface thickened by half the offset on each side where it
/// allows it (surface_shell.h), else its alpha wrap (solidify.h). `reach`: how far the
/// solid's surface may lie from the object's (world units). False when neither gives a valid
/// closed solid. Deterministic.
bool supportSolid(const detail::PreparedObject& surface, double diagonal, std::vector<double>& positions,
                  std::vector<uint32_t>& triangles, double& reach) {
    const double offset = kSupportSolidOffsetFraction * diagonal;
    const double alpha = std::max(kSupportSolidAlphaFraction * diagonal, 2 * offset);
    // As the bake takes a model's solid: valid and closed as the triangulator would see it.
    const auto valid = [&] {
        detail::PreparedObject check = detail::checkedSurface(positions, triangles);
        if (!check.validSolid() || check.positions.size() != positions.size()) return false;
        positions = std::move(check.positions);
        triangles = std::move(check.triangles);
        return true;
    };
    std::string why;
    if (detail::thickenSurface(surface.positions, surface.triangles, offset / 2, offset, alpha, positions, triangles, why) &&
        valid()) {
        reach = offset;
        return true;
    }
    if (detail::alphaWrap(surface.positions, surface.triangles, alpha, offset, positions, triangles, why) && valid()) {
        reach = alpha;  // a wrap fills cavities narrower than alpha
        return true;
    }
    positions.clear();
    triangles.clear();
    return false;
}

/// Per-object versions (docs/design.md §2.6): conservative simplifications of one object at
/// error targets sqrt(2) apart, from a thousandth of its diagonal (a support surface's: a
/// four-thousandth) up to its diagonal, and for
/// an object of one shell the coarsest enclosing polytope of its convex hull that fits each
/// target. A candidate counts when it does not intersect itself and its certified error fits
/// its budget (twice its target). An object that is not a closed solid is simplified from
/// `standIn`, the watertight solid that contains it alone (its alpha wrap), when there is one:
/// whatever encloses that solid encloses the object, and errors are still certified against
/// the object itself. A support surface (`support`) without a stand-in is simplified from a
/// solid made for it here (supportSolid). Empty for any other such object.
VersionLadder objectLadder(const InputObject& object, const detail::PreparedOriginal& original,
                           const SolidReport* standIn, bool support, const ProxySettings& settings) {
    VersionLadder ladder;
    ladder.objectTriangles = object.indices.size() / 3;
    if (settings.objectLodCount <= 0) return ladder;
    detail::PreparedObject prepared;
    std::vector<Diagnostic> ignored;  // the bake reported the object's problems already
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 2 < object.positions.size(); i += 3) growBox(lo, hi, &object.positions[i]);
    const double diagonal = distance(lo, hi);
    if (!(diagonal > 0)) return ladder;
    detail::prepareObject(object, 1e-14 * diagonal * diagonal, prepared, ignored);
    const std::vector<double>* basePositions = &prepared.positions;
    const std::vector<uint32_t>* baseTriangles = &prepared.triangles;
    double finest = (support ? kSupportChainFinestFraction : kChainFinestFraction) * diagonal;
    std::vector<double> ownSolidPositions;
    std::vector<uint32_t> ownSolidTriangles;
    if (!prepared.validSolid() && standIn && standIn->closedManifold && !standIn->triangles.empty()) {
        basePositions = &standIn->positions;
        baseTriangles = &standIn->triangles;
        // No version can be closer to the object than its solid is.
        finest = std::max(finest, 0.5 * std::max(standIn->distanceSolidToOriginal, standIn->distanceOriginalToSolid));
    } else if (!prepared.validSolid()) {
        double reach = 0;
        if (!support || !prepared.usable || !supportSolid(prepared, diagonal, ownSolidPositions, ownSolidTriangles, reach))
            return ladder;
        basePositions = &ownSolidPositions;
        baseTriangles = &ownSolidTriangles;
        finest = std::max(finest, 0.5 * reach);
    }
    std::vector<double> targets;  // ascending
    for (double t = finest; t < diagonal; t *= kChainRatio) targets.push_back(t);
    if (targets.empty()) return ladder;
    EnclosureSeries series(*basePositions, *baseTriangles, targets);
    const std::vector<const detail::PreparedOriginal*> originals{&original};
    detail::TriangleBoundCache cache;  // the versions share many triangles, and with the object
    cache.addOriginal(object);
    std::unique_ptr<PolytopeSource> polytopes;
    if (shellCount(basePositions->size() / 3, *baseTriangles) == 1)
        polytopes = std::make_unique<PolytopeSource>(*basePositions, originals, settings, 2 * diagonal, &cache);
    const size_t objectTriangles = ladder.objectTriangles;
    ProxySettings versionSettings = settings;
    versionSettings.maxRefinementsPerDirection *= kVersionRefinementFactor;
    size_t lastTriangles = 0;
    for (size_t i = 0; i < series.size(); ++i) {
        const double budget = 2 * targets[i], tolerance = settings.toleranceFraction * targets[i];
        Version p;
        if (polytopes && polytopes->coarsestWithin(budget, kWorthNumerator * objectTriangles / kWorthDenominator, tolerance,
                                                   p.node, &p.exact)) {
            p.node.budget = budget;
            ladder.versions.push_back(std::move(p));
        }
        if (series.triangleCount(i) == lastTriangles) continue;  // stopped simplifying: the same mesh again
        const detail::ConservativeSnapshot* clean = lighterCleanSnapshot(series, i, objectTriangles);
        if (!clean) continue;
        lastTriangles = series.triangleCount(i);
        Version v;
        v.node.positions = toFloats(clean->positions);
        v.node.indices = clean->indices;
        v.node.error = measureEnclosure(clean->positions, v.node.positions, v.node.indices, originals, tolerance, versionSettings,
                                        budget, &cache);
        if (!(v.node.error.bound() <= budget)) continue;
        v.node.budget = budget;
        v.exact = clean->positions;
        ladder.versions.push_back(std::move(v));
    }
    std::stable_sort(ladder.versions.begin(), ladder.versions.end(), [](const Version& a, const Version& b) {
        const double ea = a.node.error.bound(), eb = b.node.error.bound();
        return ea < eb || (ea == eb && a.node.indices.size() < b.node.indices.size());
    });
    // A version with no fewer triangles than one of smaller error is never chosen (neither by
    // the lightest chain nor by lightestWithin): keep the others only.
    std::vector<Version> kept;
    for (Version& v : ladder.versions)
        if (kept.empty() || v.node.indices.size() < kept.back().node.indices.size()) kept.push_back(std::move(v));
    ladder.versions = std::move(kept);
    return ladder;
}

/// Per-object LOD (docs/design.md §2.6): the lightest chain (lightestChain) through the
/// object's versions whose error stays below `ceiling` (the error of the first aggregate above
/// it holding other objects; infinity for none). Returned finest first.
std::vector<HierarchyNode> chainFromLadder(const VersionLadder& ladder, uint32_t objectIndex, double ceiling,
                                           const ProxySettings& settings) {
    std::vector<HierarchyNode> candidates;
    for (const Version& v : ladder.versions)
        if (v.node.error.bound() < ceiling) candidates.push_back(v.node);
    std::vector<HierarchyNode> chain = lightestChain(std::move(candidates), ladder.objectTriangles, settings.objectLodCount);
    for (size_t j = 0; j < chain.size(); ++j) {
        chain[j].objectLod = static_cast<int>(j) + 1;
        chain[j].sources = {objectIndex};
        chain[j].exactTriangleCount = ladder.objectTriangles;
    }
    return chain;
}

/// An object's versions above its per-object LOD chain `chain` (finest first), for the bundles
/// of the groups holding it (draw_bundles.h): the lightest chain (lightestChain) through its
/// versions whose error is at least `ceiling` (the chain's) and below `reach` (the error of the
/// root above it). Ascending by error.
std::vector<HierarchyNode> versionsAboveChain(const VersionLadder& ladder, const std::vector<HierarchyNode>& chain,
                                              double ceiling, double reach, const ProxySettings& settings) {
    std::vector<HierarchyNode> candidates;
    for (const Version& v : ladder.versions) {
        const double e = v.node.error.bound();
        if (e >= ceiling && e < reach) candidates.push_back(v.node);
    }
    return lightestChain(std::move(candidates), chain.empty() ? ladder.objectTriangles : chain.back().indices.size() / 3,
                         settings.objectLodCount);
}

/// Most objects a group may hold for its coarser versions to be tried as unions of its
/// objects' versions (each union is a chain of exact boolean operations).
constexpr size_t kUnionMaxObjects = 48;

/// Coarser versions of an aggregate node (docs/design.md §2.6): enclosing simplifications of
/// its proxy at error targets sqrt(2) apart above the node's budget, up to below `ceiling`
/// (its parent's certified error; infinity for a root, then up to the aggregate's diagonal).
/// A level's proxy fits a budget near the fill's own error, the next level's error is that
/// of a wider fill; these versions fill the gap, so that at any distance the cut can draw a
/// version of the group whose error is near what the pixel tolerance allows. Each target is
/// tried on the proxy and, for a proxy of one shell, on its convex hull (both simplified in
/// one pass each) and as the coarsest enclosing polytope of that hull. A candidate counts
/// when it does not intersect itself, its certified error fits its budget (the node's error
/// plus twice its push-out allowance) and stays below the ceiling; the chain is the lightest
/// one through them (lightestChain). Finest first.
/// A group of at most kUnionMaxObjects objects whose every object has versions (`ladders`,
/// one per source object, null for none) is also tried as the exact union of its objects'
/// lightest versions within each budget: where the group's proxy keeps the detail of its fill,
/// its objects' coarse versions often overlap into a lighter solid of the same shells. Every
/// point of the union's surface lies on an object's version, so it is within that version's
/// error of the originals (certified again all the same).
std::vector<HierarchyNode> coarserChain(const HierarchyNode& node, const ExactProxy& proxy, size_t shells,
                                        const std::vector<const detail::PreparedOriginal*>& originals,
                                        const std::vector<const VersionLadder*>& ladders, double ceiling,
                                        const ProxySettings& settings) {
    const bool oneShell = shells == 1;
    std::vector<HierarchyNode> chain;
    if (settings.coarserCount <= 0 || proxy.indices.empty()) return chain;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i + 2 < proxy.positions.size(); i += 3) growBox(lo, hi, &proxy.positions[i]);
    const double diagonal = distance(lo, hi);
    const double own = node.error.bound(), base = std::max(own, node.budget);
    if (!(diagonal > 0) || !(base > 0)) return chain;
    const double top = std::min(ceiling, diagonal);
    std::vector<double> allowances;  // ascending push-outs above the proxy
    for (double t = base * kChainRatio; t < top; t *= kChainRatio) allowances.push_back(t - own);
    if (allowances.empty()) return chain;
    // Two sources of versions: the proxy simplified further, and (for a proxy of one shell)
    // its convex hull simplified. The hull starts coarser, but where edge collapses of the
    // proxy get stuck among concave edges, the hull's go on down to a tetrahedron.
    std::vector<std::unique_ptr<EnclosureSeries>> sources;
    sources.push_back(std::make_unique<EnclosureSeries>(proxy.positions, proxy.indices, allowances));
    ExactProxy hull;
    if (oneShell && detail::convexHull3(proxy.positions, hull.positions, hull.indices) &&
        hull.indices.size() < proxy.indices.size())
        sources.push_back(std::make_unique<EnclosureSeries>(hull.positions, hull.indices, allowances));
    detail::TriangleBoundCache cache;  // the versions of one source share many triangles
    std::unique_ptr<PolytopeSource> polytopes;
    if (oneShell)
        polytopes = std::make_unique<PolytopeSource>(proxy.positions, originals, settings, std::min(ceiling, own + 2 * top),
                                                     &cache);
    // Unions of the objects' versions: one per distinct choice of versions.
    const bool unite = ladders.size() >= 2 && ladders.size() <= kUnionMaxObjects &&
                       std::all_of(ladders.begin(), ladders.end(), [](const VersionLadder* l) { return l != nullptr; });
    std::vector<const Version*> lastChoice;
    const auto unionWithin = [&](double budget, double tolerance, HierarchyNode& u) {
        std::vector<const Version*> choice;
        for (const VersionLadder* l : ladders) {
            const Version* v = l->lightestWithin(budget);
            if (!v) return false;
            choice.push_back(v);
        }
        if (choice == lastChoice) return false;  // the same union as for the previous budget
        lastChoice = choice;
        std::vector<const std::vector<double>*> parts;
        std::vector<const std::vector<uint32_t>*> partIndices;
        size_t partTriangles = 0;
        for (const Version* v : choice) {
            parts.push_back(&v->exact);
            partIndices.push_back(&v->node.indices);
            partTriangles += v->node.indices.size() / 3;
        }
        if (!lighterEnough(partTriangles, proxy.indices.size() / 3)) return false;  // seams only add
        std::vector<double> positions;
        std::vector<uint32_t> indices;
        std::string ignored;
        if (!detail::exactUnion(parts, partIndices, positions, indices, ignored)) return false;
        if (!lighterEnough(indices.size() / 3, proxy.indices.size() / 3) ||
            shellCount(positions.size() / 3, indices) != shells || detail::meshSelfIntersects(positions, indices))
            return false;
        u.positions = toFloats(positions);
        u.indices = std::move(indices);
        if (hasCollapsedTriangle(u.positions, u.indices)) return false;
        u.error = measureEnclosure(positions, u.positions, u.indices, originals, tolerance, settings, budget, &cache);
        return u.error.bound() <= budget;
    };
    // Every version that fits its target's budget, from every source; then the lightest chain.
    std::vector<HierarchyNode> candidates;
    std::vector<size_t> lastTriangles(sources.size(), 0);
    for (size_t i = 0; i < allowances.size(); ++i) {
        const double budget = own + 2 * allowances[i], tolerance = settings.toleranceFraction * (own + allowances[i]);
        HierarchyNode p;
        if (polytopes && polytopes->coarsestWithin(std::min(budget, std::nextafter(ceiling, 0.0)),
                                                   kWorthNumerator * (proxy.indices.size() / 3) / kWorthDenominator, tolerance, p)) {
            p.budget = budget;
            candidates.push_back(std::move(p));
        }
        for (size_t k = 0; k < sources.size(); ++k) {
            EnclosureSeries& series = *sources[k];
            // A series that stopped simplifying repeats its snapshot: measured once.
            if (series.triangleCount(i) == lastTriangles[k]) continue;
            const detail::ConservativeSnapshot* clean = lighterCleanSnapshot(series, i, proxy.indices.size() / 3);
            if (!clean) continue;
            lastTriangles[k] = series.triangleCount(i);
            HierarchyNode n;
            n.positions = toFloats(clean->positions);
            n.indices = clean->indices;
            n.error = measureEnclosure(clean->positions, n.positions, n.indices, originals, tolerance, settings,
                                       std::min(budget, ceiling), &cache);
            if (!(n.error.bound() <= budget && n.error.bound() < ceiling)) continue;
            n.budget = budget;
            candidates.push_back(std::move(n));
        }
        if (unite) {
            HierarchyNode u;
            if (unionWithin(std::min(budget, std::nextafter(ceiling, 0.0)), tolerance, u)) {
                u.budget = budget;
                candidates.push_back(std::move(u));
            }
        }
    }
    chain = lightestChain(std::move(candidates), proxy.indices.size() / 3, settings.coarserCount);
    for (size_t j = 0; j < chain.size(); ++j) {
        HierarchyNode& c = chain[j];
        c.coarserStep = static_cast<int>(j) + 1;
        c.sources = node.sources;
        c.delta = node.delta;
        c.exactTriangleCount = node.exactTriangleCount;
    }
    return chain;
}

/// Whether a work item of the proxies stage is made (when the cache lacks it), only read from
/// the cache (made by an earlier phase), or left to another share.
enum class Work : char { Skip, Obtain, LoadOnly };

/// One kind of work item of the proxies stage, items [0, count): everything buildHierarchyNodes
/// needs to read it back, make it, keep it and name it.
struct WorkItems {
    std::function<Work(size_t)> work;
    std::function<std::string(size_t)> key;  ///< the cache key of the item's whole input
    std::function<bool(size_t, const std::vector<uint8_t>&)> read;
    std::function<void(size_t)> make;
    std::function<void(size_t, std::vector<uint8_t>&)> write;
    std::function<void(size_t, std::vector<char>&)> objects;  ///< marks the objects make(j) measures against
    /// Optional: the nodes whose aggregate's mesh make(j) reads (read again from the cache
    /// first when the hierarchy is lean, Aggregate::meshInCache).
    std::function<void(size_t, std::vector<uint32_t>&)> meshes;
    /// Optional: drops item j's result once it is in the cache, where nothing after needs it.
    std::function<void(size_t)> release;
    /// Optional: called once item j is read, or made and stored (after release), from the
    /// thread that did it: what follows from it alone is done at once (and its meshes leave
    /// memory) instead of once every item is there.
    std::function<void(size_t)> done;
    std::function<std::string(size_t)> name;
    /// Optional: a relative estimate of make(j)'s time. The items are made largest first, so
    /// that the last ones to finish are small ones (the results do not depend on the order).
    std::function<double(size_t)> cost;
};

/// Layout of the proxies' cache entries and of their keys: a new layout never reads old ones.
/// Change it too whenever what an item makes changes (any constant or step of this file or
/// of the simplifier, the error measure or the colours), so that no stale entry is read.
constexpr char kProxyItemTag[] = "aggrelod proxy item 4";

/// ProxySettings::cache: the keys of the proxies' work items (each a hash of everything the
/// item's result depends on) and what was made and read.
class ProxyMemo {
public:
    explicit ProxyMemo(const ProxySettings& s)
        : cache_(s.cache && s.cache->load && s.cache->store ? s.cache : nullptr) {
        settings_.text(kProxyItemTag);
        settings_.f64(s.simplifyFraction);
        settings_.u64(uint64_t(int64_t(s.objectLodCount)));
        settings_.u64(uint64_t(int64_t(s.coarserCount)));
        settings_.u64(uint64_t(int64_t(s.polytopeVertices)));
        settings_.f64(s.toleranceFraction);
        settings_.u64(s.maxRefinementsPerDirection);
    }
    bool on() const { return cache_ != nullptr; }
    bool load(const std::string& key, std::vector<uint8_t>& bytes) const { return cache_->load(key, bytes); }
    void store(const std::string& key, const std::vector<uint8_t>& bytes) {
        if (!cache_->store(key, bytes)) storeFailed = true;
    }
    /// What an object contributes to the results: its mesh and colours (not its name or id).
    std::string objectKey(const InputObject& o) const {
        detail::ContentHash h;
        h.values(o.positions);
        h.values(o.indices);
        h.values(o.triangleColors);
        return h.hex();
    }
    std::string aggregateKey(const Aggregate& a, const HierarchyNode& n, const std::vector<std::string>& objectKeys) const {
        detail::ContentHash h = start('a');
        h.f64(n.delta);
        h.text(aggregateMeshHash(a));  // a lean hierarchy keeps it without the mesh
        h.u64(n.sources.size());
        for (uint32_t o : n.sources) h.text(objectKeys[o]);
        return h.hex();
    }
    std::string ladderKey(const std::string& objectKey, const SolidReport* standIn, bool support) const {
        detail::ContentHash h = start('l');
        h.text(objectKey);
        h.u64(standIn != nullptr);
        if (support) h.text("support");  // versions from a solid made for the surface (supportSolid)
        if (standIn) {
            h.values(standIn->positions);
            h.values(standIn->triangles);
            h.u64(standIn->closedManifold);
            h.f64(standIn->distanceSolidToOriginal);
            h.f64(standIn->distanceOriginalToSolid);
        }
        return h.hex();
    }
    /// ladderKeys: "-" for an object without versions made.
    std::string coarserKey(const std::string& aggregateKey, size_t shells, double ceiling,
                           const std::vector<uint32_t>& sources, const std::vector<std::string>& ladderKeys) const {
        detail::ContentHash h = start('c');
        h.text(aggregateKey);
        h.u64(shells);
        h.f64(ceiling);
        for (uint32_t o : sources) h.text(ladderKeys[o]);
        return h.hex();
    }
    std::atomic<size_t> made{0}, loaded{0};
    std::atomic<bool> storeFailed{false};

private:
    detail::ContentHash start(char kind) const {
        detail::ContentHash h = settings_;
        h.bytes(&kind, 1);
        return h;
    }
    const TileCache* cache_;
    detail::ContentHash settings_;
};

void writeProxyNode(detail::ByteWriter& w, const HierarchyNode& n) {
    w.array(n.positions);
    w.array(n.indices);
    w.array(n.faceColors);
    w.pod(n.error);
    w.pod(n.budget);
}
void readProxyNode(detail::ByteReader& r, HierarchyNode& n) {
    r.array(n.positions);
    r.array(n.indices);
    r.array(n.faceColors);
    n.error = r.pod<ProxyError>();
    n.budget = r.pod<double>();
}
/// A read entry is used only when it is whole and its meshes index within themselves.
bool wellFormed(const detail::ByteReader& r, const HierarchyNode& n) {
    if (!r.ok() || !r.atEnd() || n.positions.size() % 3 || n.indices.size() % 3) return false;
    if (!n.faceColors.empty() && n.faceColors.size() != 4 * (n.indices.size() / 3)) return false;
    return std::all_of(n.indices.begin(), n.indices.end(), [&](uint32_t i) { return i < n.positions.size() / 3; });
}

void writeAggregateProxy(const HierarchyNode& n, const ExactProxy& exact, std::vector<uint8_t>& bytes) {
    detail::ByteWriter w(bytes);
    w.pod('a');
    writeProxyNode(w, n);
    w.array(exact.positions);
    w.array(exact.indices);
}
/// `exact`: null to read the entry without keeping its exact proxy (only coarser versions made
/// in this run need it: read again then).
bool readAggregateProxy(const std::vector<uint8_t>& bytes, HierarchyNode& n, ExactProxy* exact) {
    detail::ByteReader r(bytes);
    HierarchyNode read;
    ExactProxy readExact;
    if (r.pod<char>() != 'a') return false;
    readProxyNode(r, read);
    r.array(readExact.positions);
    r.array(readExact.indices);
    if (!wellFormed(r, read) || readExact.positions.size() % 3 || readExact.indices.size() % 3 ||
        !std::all_of(readExact.indices.begin(), readExact.indices.end(),
                     [&](uint32_t i) { return i < readExact.positions.size() / 3; }))
        return false;
    n.positions = std::move(read.positions);
    n.indices = std::move(read.indices);
    n.faceColors = std::move(read.faceColors);
    n.error = read.error;
    n.budget = read.budget;
    if (exact) *exact = std::move(readExact);
    return true;
}

void writeLadder(const VersionLadder& ladder, std::vector<uint8_t>& bytes) {
    detail::ByteWriter w(bytes);
    w.pod('l');
    w.pod(uint64_t(ladder.objectTriangles));
    w.pod(uint64_t(ladder.versions.size()));
    for (const Version& v : ladder.versions) {
        writeProxyNode(w, v.node);
        w.array(v.exact);
    }
}
/// whole: keep the versions' exact vertices too (only unions made in this run need them).
bool readLadder(const std::vector<uint8_t>& bytes, VersionLadder& ladder, bool whole) {
    detail::ByteReader r(bytes);
    VersionLadder read;
    if (r.pod<char>() != 'l') return false;
    read.objectTriangles = static_cast<size_t>(r.pod<uint64_t>());
    read.versions.resize(r.count(64));
    for (Version& v : read.versions) {
        readProxyNode(r, v.node);
        r.array(v.exact);
        if (!r.ok() || v.exact.size() != v.node.positions.size()) return false;
    }
    if (!r.ok() || !r.atEnd()) return false;
    for (const Version& v : read.versions)
        if (!wellFormed(r, v.node)) return false;
    if (!whole)
        for (Version& v : read.versions) std::vector<double>().swap(v.exact);
    ladder = std::move(read);
    return true;
}

void writeCoarser(const std::vector<HierarchyNode>& chain, std::vector<uint8_t>& bytes) {
    detail::ByteWriter w(bytes);
    w.pod('c');
    w.pod(uint64_t(chain.size()));
    for (const HierarchyNode& c : chain) writeProxyNode(w, c);
}
bool readCoarser(const std::vector<uint8_t>& bytes, std::vector<HierarchyNode>& chain) {
    detail::ByteReader r(bytes);
    std::vector<HierarchyNode> read;
    if (r.pod<char>() != 'c') return false;
    read.resize(r.count(64));
    for (HierarchyNode& c : read) readProxyNode(r, c);
    if (!r.ok() || !r.atEnd()) return false;
    for (const HierarchyNode& c : read)
        if (!wellFormed(r, c)) return false;
    chain = std::move(read);
    return true;
}

/// Bits of x's low 21 bits spread three apart (for a 63-bit Morton key).
uint64_t spreadBits(uint64_t x) {
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
}

/// The share (ProxyShare::part) of each work item of a phase: the items in Morton order of
/// their centres (`centres`, inside the box lo..hi), cut into `parts` runs of about equal
/// estimated work (`costs`: triangles to measure). Items near each other go to one share, so
/// a share measures against the originals of its part of the world only (it prepares their
/// search structures) rather than against nearly all of them. Deterministic: every share
/// computes the same assignment.
std::vector<uint32_t> assignShares(const std::vector<double>& costs, const std::vector<std::array<double, 3>>& centres,
                                   const double lo[3], const double hi[3], uint32_t parts) {
    std::vector<uint64_t> key(costs.size(), 0);
    for (size_t j = 0; j < costs.size(); ++j) {
        uint64_t code = 0;
        for (int k = 0; k < 3; ++k) {
            const double extent = hi[k] - lo[k];
            double t = extent > 0 ? (centres[j][k] - lo[k]) / extent : 0.0;
            t = std::isfinite(t) ? std::clamp(t, 0.0, 1.0) : 0.0;
            code |= spreadBits(static_cast<uint64_t>(t * double(0x1fffff))) << k;
        }
        key[j] = code;
    }
    std::vector<uint32_t> order(costs.size());
    for (uint32_t j = 0; j < order.size(); ++j) order[j] = j;
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return key[a] < key[b]; });
    double total = 0;
    for (double c : costs) total += c;
    std::vector<uint32_t> shareOf(costs.size(), 0);
    double before = 0;
    for (uint32_t j : order) {
        // By the middle of the item's work: a heavy item goes where most of it falls.
        const double middle = before + 0.5 * costs[j];
        shareOf[j] = total > 0 ? std::min(parts - 1, static_cast<uint32_t>(double(parts) * middle / total)) : 0;
        before += costs[j];
    }
    return shareOf;
}

/// Relative work of an object's versions per object triangle against an aggregate's proxy
/// per triangle measured (a ladder simplifies and certifies at some twenty targets).
constexpr double kLadderCostPerTriangle = 8.0;

/// An aggregate's mesh is well formed (sizes, indices in range); true for a lean one (checked
/// when read again).
bool checkMesh(const Aggregate& agg, const std::string& where, std::string& error) {
    if (meshLeftInCache(agg)) return true;
    if (agg.positions.size() % 3 || agg.indices.size() % 3) {
        error = where + ": positions or indices size is not a multiple of 3";
        return false;
    }
    for (uint32_t i : agg.indices)
        if (i >= agg.positions.size() / 3) {
            error = where + ": vertex index " + std::to_string(i) + " out of range";
            return false;
        }
    return true;
}

/// buildHierarchyNodes, or one share of its work (buildProxyShare) when `share` is given.
bool buildNodes(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects, const ProxySettings& settings,
                const ProxyShare* share, HierarchyNodes& out, std::string& error) {
    out = HierarchyNodes{};
    const size_t objectCount = objects.size();
    const size_t levelCount = hierarchy.levels.size();
    out.objectCount = objectCount;

    // groupOf[k][o]: the aggregate of level k holding object o. Checks the partition.
    std::vector<std::vector<uint32_t>> groupOf(levelCount, std::vector<uint32_t>(objectCount, kNoNode));
    for (size_t k = 0; k < levelCount; ++k) {
        const Level& level = hierarchy.levels[k];
        for (size_t g = 0; g < level.aggregates.size(); ++g) {
            const Aggregate& agg = level.aggregates[g];
            const std::string where = "level " + std::to_string(k) + " aggregate " + std::to_string(g);
            if (agg.sourceObjects.empty()) {
                error = where + " stands for no object";
                return false;
            }
            if (!checkMesh(agg, where, error)) return false;
            for (uint32_t o : agg.sourceObjects) {
                if (o >= objectCount) {
                    error = where + " refers to object " + std::to_string(o) + " but there are " +
                            std::to_string(objectCount) + " objects";
                    return false;
                }
                if (groupOf[k][o] != kNoNode) {
                    error = "object '" + objects[o].name + "' is in two aggregates of level " + std::to_string(k);
                    return false;
                }
                groupOf[k][o] = static_cast<uint32_t>(g);
            }
        }
        // An object the bake left out (e.g. a non-finite coordinate) is in no level; any
        // other object is in every level.
        for (size_t o = 0; o < objectCount; ++o)
            if ((groupOf[k][o] == kNoNode) != (groupOf[0][o] == kNoNode)) {
                error = "object '" + objects[o].name + "' is in an aggregate of level " +
                        std::to_string(groupOf[k][o] == kNoNode ? 0 : k) + " but in none of level " +
                        std::to_string(groupOf[k][o] == kNoNode ? k : 0);
                return false;
            }
        if (k > 0)  // groups only coarsen: one level-(k-1) group lies in one level-k group
            for (size_t o = 0; o < objectCount; ++o) {
                if (groupOf[k][o] == kNoNode) continue;
                const Aggregate& below = hierarchy.levels[k - 1].aggregates[groupOf[k - 1][o]];
                if (groupOf[k][below.sourceObjects.front()] != groupOf[k][o]) {
                    error = "level " + std::to_string(k) + " splits a group of level " + std::to_string(k - 1) +
                            " (object '" + objects[o].name + "')";
                    return false;
                }
            }
    }
    for (size_t o = 0; o < objectCount; ++o) {
        if (objects[o].positions.size() % 3 || objects[o].indices.size() % 3) {
            error = "object '" + objects[o].name + "': positions or indices size is not a multiple of 3";
            return false;
        }
        for (uint32_t i : objects[o].indices)
            if (i >= objects[o].positions.size() / 3) {
                error = "object '" + objects[o].name + "': vertex index " + std::to_string(i) + " out of range";
                return false;
            }
    }

    // Leaves: the original objects (a share makes no tree: only whether a leaf has geometry).
    std::vector<HierarchyNode>& nodes = out.nodes;
    nodes.resize(objectCount);
    std::vector<char> leafHasGeometry(objectCount, 0);
    std::vector<char> support(objectCount, 0);  // support surfaces: root leaves with versions of their own
    for (uint32_t o : hierarchy.supportObjects)
        if (o < objectCount) support[o] = 1;
    for (size_t o = 0; o < objectCount; ++o) {
        HierarchyNode& n = nodes[o];
        n.leaf = true;
        n.sources = {static_cast<uint32_t>(o)};
        n.exactTriangleCount = objects[o].indices.size() / 3;
        // Every object an engine can draw keeps its mesh, those in no level too (support
        // surfaces, flat or open objects left out): a root leaf, drawn from the runtime file
        // alone. An object with a non-finite coordinate keeps its leaf without geometry.
        leafHasGeometry[o] = std::all_of(objects[o].positions.begin(), objects[o].positions.end(),
                                         [](double x) { return std::isfinite(x); });
        if (leafHasGeometry[o] && !share && settings.leavesByReference) {
            n.meshPlace = detail::objectMeshPlace(objects[o]);
        } else if (leafHasGeometry[o] && !share) {
            n.positions.assign(objects[o].positions.begin(), objects[o].positions.end());
            n.indices = objects[o].indices;
            if (detail::hasTriangleColors(objects[o])) n.faceColors = objects[o].triangleColors;
        }
    }
    // Aggregates, level by level; an aggregate that is the same solid as the one holding the
    // same objects one level finer is the same node (its level range grows).
    out.nodeOfAggregate.resize(levelCount);
    for (size_t k = 0; k < levelCount; ++k) {
        const Level& level = hierarchy.levels[k];
        out.nodeOfAggregate[k].resize(level.aggregates.size());
        for (size_t g = 0; g < level.aggregates.size(); ++g) {
            const Aggregate& agg = level.aggregates[g];
            if (k > 0) {
                const uint32_t previous = groupOf[k - 1][agg.sourceObjects.front()];
                if (sameSolid(hierarchy.levels[k - 1].aggregates[previous], agg)) {
                    const uint32_t node = out.nodeOfAggregate[k - 1][previous];
                    nodes[node].lastLevel = static_cast<int>(k);
                    out.nodeOfAggregate[k][g] = node;
                    continue;
                }
            }
            HierarchyNode n;
            n.firstLevel = n.lastLevel = static_cast<int>(k);
            n.aggregateIndex = static_cast<uint32_t>(g);
            n.delta = level.delta;
            n.sources = agg.sourceObjects;
            n.exactTriangleCount = agg.meshInCache ? agg.meshInCache->triangleCount : agg.indices.size() / 3;
            out.nodeOfAggregate[k][g] = static_cast<uint32_t>(nodes.size());
            nodes.push_back(std::move(n));
        }
    }
    // Parents: the node holding the first object one level above the last level spanned.
    for (size_t i = 0; i < nodes.size(); ++i) {
        HierarchyNode& n = nodes[i];
        const size_t above = n.leaf ? 0 : size_t(n.lastLevel) + 1;
        if (above < levelCount && groupOf[above][n.sources.front()] != kNoNode) {
            n.parent = out.nodeOfAggregate[above][groupOf[above][n.sources.front()]];
            nodes[n.parent].children.push_back(static_cast<uint32_t>(i));
        } else {
            out.roots.push_back(static_cast<uint32_t>(i));
        }
    }

    // Proxies and their errors, in work items that each write their own slots: made here,
    // or read back from the cache (ProxyMemo) where their whole input is unchanged.
    ProxyMemo memo(settings);
    auto aggregateOf = [&](const HierarchyNode& n) -> const Aggregate& {
        return hierarchy.levels[size_t(n.firstLevel)].aggregates[n.aggregateIndex];
    };
    // A lean hierarchy's meshes, read again from the cache for the items that need them
    // (WorkItems::meshes), each dropped once its item is made.
    std::vector<std::unique_ptr<Aggregate>> reloaded(nodes.size());
    std::string reloadError;
    const auto needsReload = [&](uint32_t i) {
        return meshLeftInCache(aggregateOf(nodes[i]));
    };
    const auto reload = [&](const std::vector<uint32_t>& which) {
        std::vector<const Aggregate*> lean;
        std::vector<Aggregate*> into;
        for (uint32_t i : which) {
            reloaded[i] = std::make_unique<Aggregate>();
            lean.push_back(&aggregateOf(nodes[i]));
            into.push_back(reloaded[i].get());
        }
        if (!settings.cache) reloadError = "the hierarchy's meshes are in a tile cache, but no cache was given";
        return settings.cache && detail::reloadMeshes(*settings.cache, lean, into, settings.threadCount, reloadError);
    };
    // The aggregate of node i with its mesh (read again alone if it was not read for its item).
    const auto meshOf = [&](uint32_t i) -> const Aggregate& {
        if (!needsReload(i)) return aggregateOf(nodes[i]);
        if (!reloaded[i] && !reload({i})) throw std::runtime_error(reloadError);
        return *reloaded[i];
    };
    // One BVH per original object, shared by every node holding it at every level (an
    // object recurs at each level; merging the originals into one BVH per node would
    // rebuild the coarse nodes' BVHs over nearly every triangle of the scene). Built for the
    // objects of the items made only.
    std::vector<detail::PreparedOriginal> prepared(objectCount);
    std::vector<char> isPrepared(objectCount, 0);
    const auto originalsOf = [&](const HierarchyNode& n) {
        std::vector<const detail::PreparedOriginal*> originals;
        for (uint32_t o : n.sources) originals.push_back(&prepared[o]);
        return originals;
    };
    const auto objectsOf = [&](const HierarchyNode& n) {
        std::vector<const InputObject*> sourceObjects;
        for (uint32_t o : n.sources) sourceObjects.push_back(&objects[o]);
        return sourceObjects;
    };
    std::vector<std::string> objectKeys(memo.on() ? objectCount : 0);
    detail::parallelFor(objectKeys.size(), settings.threadCount, [&](size_t o) { objectKeys[o] = memo.objectKey(objects[o]); });
    // Runs the items [0, count) of one kind; false with `missing` naming the first item
    // that had to be read from the cache and was not there.
    std::string missing;
    const auto runItems = [&](size_t count, const WorkItems& items, double progressFrom, double progressTo) {
        std::vector<char> state(count, 0);  // 0: skipped or read back, 1: to make, 2: missing
        std::vector<std::string> keys(memo.on() ? count : 0);
        detail::parallelFor(count, settings.threadCount, [&](size_t j) {
            const Work w = items.work(j);
            if (w == Work::Skip) return;
            if (memo.on()) {
                keys[j] = items.key(j);
                std::vector<uint8_t> bytes;
                if (memo.load(keys[j], bytes) && items.read(j, bytes)) {
                    ++memo.loaded;
                    if (items.release) items.release(j);  // as for one made: nothing after needs it
                    if (items.done) items.done(j);
                    return;
                }
            }
            state[j] = w == Work::Obtain ? 1 : 2;
        });
        std::vector<uint32_t> toMake;
        std::vector<char> needed(objectCount, 0);
        for (size_t j = 0; j < count; ++j) {
            if (state[j] == 2) {
                missing = items.name(j) + " (entry " + keys[j] + ")";
                return false;
            }
            if (state[j] != 1) continue;
            toMake.push_back(static_cast<uint32_t>(j));
            items.objects(j, needed);
        }
        std::vector<uint32_t> unprepared;
        for (uint32_t o = 0; o < objectCount; ++o)
            if (needed[o] && !isPrepared[o]) unprepared.push_back(o);
        detail::parallelFor(unprepared.size(), settings.threadCount, [&](size_t j) {
            detail::prepareOriginal(objects[unprepared[j]], prepared[unprepared[j]]);
            isPrepared[unprepared[j]] = 1;
        });
        out.originalsPrepared += unprepared.size();
        if (items.meshes) {
            std::vector<uint32_t> meshNodes, lean;
            for (uint32_t j : toMake) items.meshes(j, meshNodes);
            std::sort(meshNodes.begin(), meshNodes.end());
            meshNodes.erase(std::unique(meshNodes.begin(), meshNodes.end()), meshNodes.end());
            for (uint32_t i : meshNodes)
                if (needsReload(i) && !reloaded[i]) lean.push_back(i);
            if (!lean.empty() && !reload(lean)) return false;
        }
        if (items.cost) {
            std::vector<double> costs(count, 0.0);
            for (uint32_t j : toMake) costs[j] = items.cost(j);
            std::stable_sort(toMake.begin(), toMake.end(), [&](uint32_t a, uint32_t b) { return costs[a] > costs[b]; });
        }
        detail::parallelFor(toMake.size(), settings.threadCount, [&](size_t m) {
            const uint32_t j = toMake[m];
            items.make(j);
            ++memo.made;
            if (memo.on()) {
                std::vector<uint8_t> bytes;
                items.write(j, bytes);
                memo.store(keys[j], bytes);
                if (items.release) items.release(j);
            }
            if (items.done) items.done(j);
        }, [&](size_t done) {
            if (settings.progress)
                settings.progress("proxies", progressFrom + (progressTo - progressFrom) * double(done) / double(toMake.size()));
        });
        return true;
    };
    // Where each object is, for a share to take the items of one part of the world.
    std::vector<std::array<double, 6>> objectBox(share ? objectCount : 0);
    double worldLo[3] = {INFINITY, INFINITY, INFINITY}, worldHi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t o = 0; o < objectBox.size(); ++o) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        if (leafHasGeometry[o])
            for (size_t i = 0; i + 2 < objects[o].positions.size(); i += 3) growBox(lo, hi, &objects[o].positions[i]);
        for (int k = 0; k < 3; ++k) objectBox[o][k] = lo[k], objectBox[o][3 + k] = hi[k];
        if (support[o]) continue;  // the world of the objects that are aggregated
        for (int k = 0; k < 3; ++k) worldLo[k] = std::min(worldLo[k], lo[k]), worldHi[k] = std::max(worldHi[k], hi[k]);
    }
    const auto centreOf = [&](const HierarchyNode& n) {
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t o : n.sources)
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], objectBox[o][k]), hi[k] = std::max(hi[k], objectBox[o][3 + k]);
        return std::array<double, 3>{0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
    };
    // Which items of a phase are this share's (assignShares); all of them without a share.
    std::vector<uint32_t> shareOf;
    const auto mine = [&](size_t j) { return !share || shareOf[j] == share->part ? Work::Obtain : Work::Skip; };
    // Estimated work of an aggregate's items: the triangles its proxies are measured over
    // (its own and its originals').
    const auto aggregateWork = [&](const HierarchyNode& n) {
        double t = double(n.exactTriangleCount);
        for (uint32_t o : n.sources) t += double(objects[o].indices.size() / 3);
        return t;
    };
    const auto hasLadder = [&](size_t o) { return (nodes[o].parent != kNoNode || support[o]) && leafHasGeometry[o]; };
    const auto finish = [&](bool ok) {
        if (!ok) error = !reloadError.empty() ? reloadError
                         : "the cache holds no result for " + missing + ": run the proxies' phase 1 first";
        // A share whose results are not kept did nothing; a whole bake just makes them again next time.
        else if (share && memo.storeFailed) error = "could not store a result in the cache";
        out.proxyItemsMade = memo.made;
        out.proxyItemsLoaded = memo.loaded;
        return ok && !(share && memo.storeFailed);
    };

    // Proxies of the aggregates that hold several objects first: their errors cap the
    // per-object LOD chains below them.
    std::vector<ExactProxy> exactProxies(nodes.size());
    std::vector<char> exactHeld(nodes.size(), 0);  // exactProxies[i] is there (made, not read lean)
    std::vector<std::string> nodeKeys(memo.on() ? nodes.size() : 0);
    const auto aggregateItems = [&](const std::vector<uint32_t>& which, const std::function<Work(size_t)>& work) {
        WorkItems items;
        items.work = work;
        items.key = [&, which](size_t j) {
            const uint32_t i = which[j];
            nodeKeys[i] = memo.aggregateKey(aggregateOf(nodes[i]), nodes[i], objectKeys);
            return nodeKeys[i];
        };
        items.read = [&, which](size_t j, const std::vector<uint8_t>& bytes) {
            HierarchyNode& n = nodes[which[j]];
            if (!readAggregateProxy(bytes, n, nullptr)) return false;
            // A share of phase 2 needs an aggregate's error only (its ceilings); the items it
            // makes read their aggregate's proxy again whole.
            if (share && share->phase == 2) dropMesh(n);
            return true;
        };
        items.make = [&, which](size_t j) {
            HierarchyNode& n = nodes[which[j]];
            makeAggregateProxy(meshOf(which[j]), originalsOf(n), settings, n, exactProxies[which[j]]);
            reloaded[which[j]].reset();
            exactHeld[which[j]] = 1;
            detail::nearestSurfaceColors(n.positions, n.indices, objectsOf(n), n.faceColors);
            detail::optimizeVertexCache(n.positions, n.indices, n.faceColors);
        };
        items.write = [&, which](size_t j, std::vector<uint8_t>& bytes) {
            writeAggregateProxy(nodes[which[j]], exactProxies[which[j]], bytes);
        };
        items.objects = [&, which](size_t j, std::vector<char>& needed) {
            for (uint32_t o : nodes[which[j]].sources) needed[o] = 1;
        };
        items.meshes = [&, which](size_t j, std::vector<uint32_t>& needed) { needed.push_back(which[j]); };
        items.name = [&, which](size_t j) {
            const HierarchyNode& n = nodes[which[j]];
            return "the proxy of level " + std::to_string(n.firstLevel) + " aggregate " + std::to_string(n.aggregateIndex);
        };
        items.cost = [&, which](size_t j) { return aggregateWork(nodes[which[j]]); };
        // A share of phase 1 ends with its results in the cache: it holds none of them.
        if (share && share->phase == 1)
            items.release = [&, which](size_t j) {
                dropMesh(nodes[which[j]]);
                exactProxies[which[j]] = ExactProxy{};
                exactHeld[which[j]] = 0;
            };
        return items;
    };
    std::vector<uint32_t> groupNodes, singleNodes;
    for (uint32_t i = static_cast<uint32_t>(objectCount); i < nodes.size(); ++i)
        (nodes[i].sources.size() > 1 ? groupNodes : singleNodes).push_back(i);
    const bool phaseOne = !share || share->phase == 1;
    if (share && phaseOne) {  // the groups' proxies, then the objects' versions
        std::vector<double> costs;
        std::vector<std::array<double, 3>> centres;
        for (uint32_t i : groupNodes) {
            costs.push_back(aggregateWork(nodes[i]));
            centres.push_back(centreOf(nodes[i]));
        }
        for (size_t o = 0; o < objectCount; ++o) {
            costs.push_back(hasLadder(o) ? kLadderCostPerTriangle * double(objects[o].indices.size() / 3) : 0.0);
            centres.push_back(centreOf(nodes[o]));
        }
        shareOf = assignShares(costs, centres, worldLo, worldHi, share->parts);
    }
    if (!runItems(groupNodes.size(), aggregateItems(groupNodes, phaseOne ? std::function<Work(size_t)>(mine) : [](size_t) { return Work::LoadOnly; }),
                  0.0, 0.5))
        return finish(false);

    // Every object's versions, up to its diagonal: its chain is cut at its first group's
    // error, and the groups holding it unite them into coarser versions.
    // The solid that stands in for an object alone (not for a model of several objects).
    std::vector<const SolidReport*> standInOf(objectCount, nullptr);
    for (const SolidReport& r : hierarchy.solids)
        if (r.objects.size() == 1 && r.objects.front() < objectCount) standInOf[r.objects.front()] = &r;
    std::vector<VersionLadder> ladders(objectCount);
    std::vector<char> ladderWhole(objectCount, 0);  // with the versions' exact vertices (made, not read lean)
    std::vector<char> chained(objectCount, 0);  // the object has a per-object LOD chain
    std::vector<uint32_t> firstGroup(objectCount, kNoNode);  // first ancestor with several objects
    for (size_t o = 0; o < objectCount; ++o) {
        uint32_t up = nodes[o].parent;
        while (up != kNoNode && nodes[up].sources.size() == 1) up = nodes[up].parent;
        firstGroup[o] = up;
    }
    // A support surface, in no group, is drawn no coarser than the coarsest level's
    // aggregates: its chain stops below their largest error.
    double coarsestLevelError = levelCount ? 0.0 : INFINITY;
    if (levelCount)
        for (uint32_t node : out.nodeOfAggregate[levelCount - 1])
            if (nodes[node].sources.size() > 1) coarsestLevelError = std::max(coarsestLevelError, nodes[node].error.bound());
    if (!(coarsestLevelError > 0)) coarsestLevelError = INFINITY;  // no group at the top
    const auto ceilingOfChain = [&](size_t o) {
        if (firstGroup[o] != kNoNode) return nodes[firstGroup[o]].error.bound();
        return support[o] ? coarsestLevelError : INFINITY;
    };
    // Per-object LOD chains. An object's chain stands in for the aggregates of that object
    // alone (the object with its concavities filled), up to its first aggregate with other
    // objects; those single-object aggregates stay only where the object has no chain.
    std::vector<std::vector<HierarchyNode>> chains(objectCount);
    // Each object's versions above its chain, up to its root's error, and its chain's coarsest:
    // the bundles of its groups may draw them instead of the groups' own versions
    // (draw_bundles.h).
    std::vector<std::vector<HierarchyNode>> versionsAbove(share || settings.bundleCount <= 0 ? 0 : objectCount);
    const auto reachOf = [&](size_t o) {
        uint32_t top = static_cast<uint32_t>(o);
        while (nodes[top].parent != kNoNode) top = nodes[top].parent;
        return top == o ? 0.0 : nodes[top].error.bound();
    };
    // Spilling, every mesh goes to the spill file as soon as nothing in this stage needs it
    // in memory any more (an object's chain and versions once made, an aggregate's proxy and
    // coarser versions once those are made or read): held until the end, the meshes of a
    // large world would be most of the stage's peak. The order of the places in the file
    // follows the threads; only this stage and the writers read them.
    const bool spilling = !settings.meshSpillPath.empty() && !share;
    detail::NodeMeshSpiller spiller;
    if (spilling && !spiller.open(settings.meshSpillPath, reloadError)) return finish(false);
    std::mutex spillErrorMutex;
    std::atomic<bool> spillFailed{false};
    const auto spillNow = [&](HierarchyNode& n, uint32_t node) {
        if (!spilling || spillFailed) return;
        std::string error;
        if (spiller.spill(n, node, error)) return;
        std::lock_guard<std::mutex> lock(spillErrorMutex);
        if (!spillFailed.exchange(true)) reloadError = error;
    };
    // An object's chain and versions from its ladder, as soon as the ladder is made or read:
    // the ladders of a large world are not all held at once.
    const auto finishObject = [&](size_t o) {
        if (ladders[o].versions.empty()) return;
        std::vector<HierarchyNode> chain = chainFromLadder(ladders[o], static_cast<uint32_t>(o), ceilingOfChain(o), settings);
        if (!versionsAbove.empty())
            versionsAbove[o] = versionsAboveChain(ladders[o], chain, ceilingOfChain(o), reachOf(o), settings);
        // A ladder read without its exact vertices has given all it can: coarser versions to
        // be made read it again whole, each for itself, so it need not be held beside its chain.
        if (!ladderWhole[o]) ladders[o] = VersionLadder{};
        chained[o] = !chain.empty();
        if (share) return;  // only whether there is a chain matters to a share
        chains[o] = std::move(chain);
        const detail::SurfaceColorSource colors({&objects[o]});
        const auto colorAndOrder = [&](std::vector<HierarchyNode>& list) {
            for (HierarchyNode& c : list) {
                colors.colorsOf(c.positions, c.indices, c.faceColors);
                detail::optimizeVertexCache(c.positions, c.indices, c.faceColors);
            }
        };
        colorAndOrder(chains[o]);
        if (!versionsAbove.empty()) {
            colorAndOrder(versionsAbove[o]);
            // The chain's coarsest version first: bundles may draw it too (coloured once, copied).
            if (!chains[o].empty()) versionsAbove[o].insert(versionsAbove[o].begin(), chains[o].back());
            for (HierarchyNode& v : versionsAbove[o]) spillNow(v, static_cast<uint32_t>(o));
        }
        for (HierarchyNode& c : chains[o]) spillNow(c, static_cast<uint32_t>(o));
    };
    std::vector<std::string> ladderKeys(memo.on() ? objectCount : 0, std::string("-"));
    {
        WorkItems items;
        items.work = [&](size_t o) {
            if (!hasLadder(o)) return Work::Skip;
            return phaseOne ? mine(groupNodes.size() + o) : Work::LoadOnly;
        };
        items.key = [&](size_t o) { return ladderKeys[o] = memo.ladderKey(objectKeys[o], standInOf[o], support[o]); };
        items.read = [&](size_t o, const std::vector<uint8_t>& bytes) { return readLadder(bytes, ladders[o], false); };
        items.make = [&](size_t o) {
            ladders[o] = objectLadder(objects[o], prepared[o], standInOf[o], support[o], settings);
            ladderWhole[o] = 1;
        };
        items.write = [&](size_t o, std::vector<uint8_t>& bytes) { writeLadder(ladders[o], bytes); };
        items.objects = [](size_t o, std::vector<char>& needed) { needed[o] = 1; };
        items.name = [&](size_t o) { return "the versions of object '" + objects[o].name + "'"; };
        items.cost = [&](size_t o) { return double(objects[o].indices.size() / 3); };
        // Phase 1 of a share only stores the ladders; otherwise each object's chain follows from
        // its ladder at once (the groups' errors, its ceiling, are known by now).
        if (share && share->phase == 1) items.release = [&](size_t o) { ladders[o] = VersionLadder{}; };
        else items.done = finishObject;
        if (!runItems(objectCount, items, 0.5, 0.75) || spillFailed) return finish(false);
    }
    if (share && share->phase == 1) return finish(true);

    std::vector<char> dropped(nodes.size(), 0);
    std::vector<uint32_t> keptSingles;
    for (uint32_t i : singleNodes) {
        if (chained[nodes[i].sources.front()]) dropped[i] = 1;
        else keptSingles.push_back(i);
    }
    // Coarser versions of every aggregate kept, capped by its parent's error. The parent of
    // a kept aggregate is kept: it holds more objects, or the same object, which then has no
    // chain either.
    std::vector<uint32_t> keptAggregates;
    for (uint32_t i = static_cast<uint32_t>(objectCount); i < nodes.size(); ++i)
        if (!dropped[i]) keptAggregates.push_back(i);
    // Phase 2's shares: an aggregate of several objects alone; the kept aggregates of one
    // object all together (each one's coarser versions are capped by the next one's error).
    std::vector<uint32_t> shareOfNode(share ? nodes.size() : 0, 0);
    if (share) {
        std::vector<double> costs;
        std::vector<std::array<double, 3>> centres;
        std::vector<uint32_t> unitOf(keptAggregates.size()), unitOfObject(objectCount, kNoNode);
        for (size_t j = 0; j < keptAggregates.size(); ++j) {
            const HierarchyNode& n = nodes[keptAggregates[j]];
            uint32_t& single = unitOfObject[n.sources.front()];
            if (n.sources.size() > 1 || single == kNoNode) costs.push_back(0.0), centres.push_back(centreOf(n));
            if (n.sources.size() == 1 && single == kNoNode) single = static_cast<uint32_t>(costs.size() - 1);
            unitOf[j] = n.sources.size() == 1 ? single : static_cast<uint32_t>(costs.size() - 1);
            costs[unitOf[j]] += aggregateWork(n);
        }
        const std::vector<uint32_t> unitShare = assignShares(costs, centres, worldLo, worldHi, share->parts);
        for (size_t j = 0; j < keptAggregates.size(); ++j) shareOfNode[keptAggregates[j]] = unitShare[unitOf[j]];
    }
    const auto mineInPhaseTwo = [&](uint32_t node) {
        return !share || shareOfNode[node] == share->part ? Work::Obtain : Work::Skip;
    };
    if (!runItems(keptSingles.size(), aggregateItems(keptSingles, [&](size_t j) { return mineInPhaseTwo(keptSingles[j]); }),
                  0.75, 0.85))
        return finish(false);
    std::vector<std::vector<HierarchyNode>> coarser(nodes.size());
    const auto ceilingOf = [&](const HierarchyNode& n) { return n.parent == kNoNode ? INFINITY : nodes[n.parent].error.bound(); };
    {
        WorkItems items;
        items.work = [&](size_t j) { return mineInPhaseTwo(keptAggregates[j]); };
        items.key = [&](size_t j) {
            const uint32_t i = keptAggregates[j];
            return memo.coarserKey(nodeKeys[i], aggregateOf(nodes[i]).componentCount, ceilingOf(nodes[i]), nodes[i].sources,
                                   ladderKeys);
        };
        // An aggregate's proxy and its coarser versions are done with once these are made or read.
        const auto spillAggregate = [&](uint32_t i) {
            spillNow(nodes[i], i);
            for (HierarchyNode& c : coarser[i]) spillNow(c, i);
        };
        items.read = [&](size_t j, const std::vector<uint8_t>& bytes) { return readCoarser(bytes, coarser[keptAggregates[j]]); };
        items.done = [&](size_t j) { spillAggregate(keptAggregates[j]); };
        items.make = [&](size_t j) {
            const uint32_t i = keptAggregates[j];
            const HierarchyNode& n = nodes[i];
            if (!exactHeld[i]) {
                // Read without its exact vertices: read again whole, one item at a time (or,
                // should the entry have gone meanwhile, made again: the same result).
                HierarchyNode again = n;
                std::vector<uint8_t> bytes;
                if (!(memo.on() && memo.load(nodeKeys[i], bytes) && readAggregateProxy(bytes, again, &exactProxies[i]))) {
                    makeAggregateProxy(meshOf(i), originalsOf(n), settings, again, exactProxies[i]);
                    reloaded[i].reset();
                }
            }
            // The versions of its objects, for a group small enough to be united from them
            // (coarserChain): a ladder read without its exact vertices is read again whole for
            // this item alone (or, should the entry have gone meanwhile, made again: the same).
            const bool unitable = n.sources.size() >= 2 && n.sources.size() <= kUnionMaxObjects;
            std::vector<VersionLadder> reread;
            reread.reserve(unitable ? n.sources.size() : 0);  // no reallocation: pointers into it are kept
            std::vector<const VersionLadder*> sourceLadders;
            for (uint32_t o : n.sources) {
                const VersionLadder* ladder = &ladders[o];
                if (unitable && !ladderWhole[o] && hasLadder(o)) {
                    VersionLadder& whole = reread.emplace_back();
                    std::vector<uint8_t> bytes;
                    if (!(memo.on() && memo.load(ladderKeys[o], bytes) && readLadder(bytes, whole, true)))
                        whole = objectLadder(objects[o], prepared[o], standInOf[o], support[o], settings);
                    ladder = &whole;
                }
                sourceLadders.push_back(ladder->versions.empty() ? nullptr : ladder);
            }
            coarser[i] = coarserChain(n, exactProxies[i], aggregateOf(n).componentCount, originalsOf(n), sourceLadders,
                                      ceilingOf(n), settings);
            exactProxies[i] = ExactProxy{};
            const detail::SurfaceColorSource colors(objectsOf(n));
            for (HierarchyNode& c : coarser[i]) {
                colors.colorsOf(c.positions, c.indices, c.faceColors);
                detail::optimizeVertexCache(c.positions, c.indices, c.faceColors);
            }
        };
        items.write = [&](size_t j, std::vector<uint8_t>& bytes) { writeCoarser(coarser[keptAggregates[j]], bytes); };
        items.objects = [&](size_t j, std::vector<char>& needed) {
            for (uint32_t o : nodes[keptAggregates[j]].sources) needed[o] = 1;
        };
        items.name = [&](size_t j) { return "the coarser versions of node " + std::to_string(keptAggregates[j]); };
        items.cost = [&](size_t j) { return aggregateWork(nodes[keptAggregates[j]]); };
        if (share) items.release = [&](size_t j) { coarser[keptAggregates[j]] = {}; };  // a share keeps nothing
        if (!runItems(keptAggregates.size(), items, 0.85, 1.0) || spillFailed) return finish(false);
    }
    // Nothing after measures against the originals or unites versions: what was held for that
    // goes before the tree is put together again (on a large world, a good part of the peak).
    std::vector<ExactProxy>().swap(exactProxies);
    std::vector<detail::PreparedOriginal>().swap(prepared);
    std::vector<VersionLadder>().swap(ladders);
    if (share) return finish(true);
    for (size_t i = objectCount; i < nodes.size(); ++i) {
        if (dropped[i]) continue;
        for (size_t j = 0; j < coarser[i].size(); ++j) {
            HierarchyNode& c = coarser[i][j];
            c.coarserStep = static_cast<int>(j) + 1;
            c.sources = nodes[i].sources;
            c.delta = nodes[i].delta;
            c.exactTriangleCount = nodes[i].exactTriangleCount;
        }
    }

    // Spilling, whatever is still in memory goes now (most meshes went when done with; a
    // leaf's copy gives way to its object): the tree is put together and its bounds computed
    // without them in memory (ProxySettings::meshSpillPath).
    if (spilling) {
        bool spilled = true;
        for (size_t o = 0; spilled && o < objectCount; ++o) {  // a leaf's copy is its object's
            HierarchyNode& n = nodes[o];
            if (n.meshPlace.kind != NodeMeshPlace::Kind::InNode || n.indices.empty()) continue;
            n.meshPlace = detail::objectMeshPlace(objects[o]);
            dropMesh(n);
        }
        for (size_t i = objectCount; spilled && i < nodes.size(); ++i) {
            if (dropped[i]) {
                dropMesh(nodes[i]);
                continue;
            }
            spilled = spiller.spill(nodes[i], static_cast<uint32_t>(i), reloadError);
            for (HierarchyNode& c : coarser[i]) spilled = spilled && spiller.spill(c, static_cast<uint32_t>(i), reloadError);
        }
        for (size_t o = 0; spilled && o < objectCount; ++o)
            for (HierarchyNode& c : chains[o]) spilled = spilled && spiller.spill(c, static_cast<uint32_t>(o), reloadError);
        if (!spilled || !spiller.finish(reloadError)) return finish(false);
        out.meshFile = spiller.file();
        if (settings.releaseFreedMemory) settings.releaseFreedMemory();
    }

    // The tree again: leaves, per-object chains (object by object, finest first), then each
    // aggregate kept followed by its coarser versions (finest first).
    {
        std::vector<uint32_t> newIndex(nodes.size(), kNoNode);
        uint32_t next = static_cast<uint32_t>(objectCount);
        std::vector<uint32_t> chainTop(objectCount);
        for (size_t o = 0; o < objectCount; ++o) {
            newIndex[o] = static_cast<uint32_t>(o);
            next += static_cast<uint32_t>(chains[o].size());
            chainTop[o] = chains[o].empty() ? static_cast<uint32_t>(o) : next - 1;
        }
        for (size_t i = objectCount; i < nodes.size(); ++i) {
            if (dropped[i]) {
                newIndex[i] = chainTop[nodes[i].sources.front()];
            } else {
                newIndex[i] = next++;
                next += static_cast<uint32_t>(coarser[i].size());
            }
        }
        // Nearest kept ancestor of old node i (kNoNode at the top).
        const auto keptParent = [&](uint32_t i) {
            uint32_t up = nodes[i].parent;
            while (up != kNoNode && dropped[up]) up = nodes[up].parent;
            return up == kNoNode ? kNoNode : newIndex[up];
        };
        std::vector<HierarchyNode> renumbered(next);
        std::vector<uint32_t> parentOf(next, kNoNode);
        // Hangs `chain` above new node `bottom` (its nodes numbered first..) and the chain's
        // top below `above`.
        const auto hang = [&](std::vector<HierarchyNode>& chain, uint32_t bottom, uint32_t first, uint32_t above) {
            uint32_t below = bottom;
            for (size_t j = 0; j < chain.size(); ++j) {
                const uint32_t at = first + static_cast<uint32_t>(j);
                parentOf[below] = at;
                renumbered[at] = std::move(chain[j]);
                below = at;
            }
            parentOf[below] = above;
            std::vector<HierarchyNode>().swap(chain);  // the moved-from shells too (a large world has many)
        };
        for (size_t o = 0; o < objectCount; ++o)
            hang(chains[o], static_cast<uint32_t>(o), chainTop[o] + 1 - static_cast<uint32_t>(chains[o].size()),
                 keptParent(static_cast<uint32_t>(o)));
        for (size_t i = objectCount; i < nodes.size(); ++i)
            if (!dropped[i]) hang(coarser[i], newIndex[i], newIndex[i] + 1, keptParent(static_cast<uint32_t>(i)));
        for (size_t i = 0; i < nodes.size(); ++i)
            if (i < objectCount || !dropped[i]) renumbered[newIndex[i]] = std::move(nodes[i]);
        detail::linkByParents(renumbered, parentOf, out.roots);
        for (auto& level : out.nodeOfAggregate)
            for (uint32_t& i : level) i = newIndex[i];
        nodes = std::move(renumbered);
    }

    // Bundles: the drawn versions of each group's children merged into one draw call (spilled
    // as they are made, where the other meshes are).
    if (!detail::addDrawBundles(out, objects, settings, versionsAbove, spilling ? &spiller : nullptr, reloadError))
        return finish(false);
    std::vector<std::vector<HierarchyNode>>().swap(versionsAbove);
    if (spilling) {
        if (!spiller.finish(reloadError)) return finish(false);
        if (settings.releaseFreedMemory) settings.releaseFreedMemory();
    }

    // Errors and bounds, children first (children have smaller indices than their parent).
    // The exact aggregates of a lean hierarchy are read again a run of nodes at a time, a run
    // ending at kBoundsRunNodes nodes or at kBoundsRunTriangles triangles read (the coarse
    // levels' aggregates span the world).
    const std::vector<double> none;
    constexpr size_t kBoundsRunNodes = 16384, kBoundsRunTriangles = size_t(1) << 20;
    std::vector<Aggregate> exactRun;
    std::vector<uint32_t> exactAt;  // node - run start -> index in exactRun (kNoNode: in memory)
    size_t runStart = 0;
    std::vector<float> leafPositions;  // a leaf that refers to its object: the float copy it would hold
    NodeMesh spilledMesh;              // a mesh in the spill file, read back
    for (size_t i = 0; i < nodes.size(); ++i) {
        HierarchyNode& n = nodes[i];
        const bool exactAggregate = !n.leaf && n.objectLod == 0 && n.coarserStep == 0 && n.bundleStep == 0;
        if (i == runStart + exactAt.size()) {
            runStart = i;
            exactRun.clear();
            exactRun.shrink_to_fit();
            std::vector<const Aggregate*> lean;
            exactAt.clear();
            size_t triangles = 0;
            for (size_t j = i; j < nodes.size() && j - i < kBoundsRunNodes && (j == i || triangles < kBoundsRunTriangles);
                 ++j) {
                exactAt.push_back(kNoNode);
                const HierarchyNode& m = nodes[j];
                if (m.leaf || m.objectLod > 0 || m.coarserStep > 0 || m.bundleStep > 0) continue;
                const Aggregate& a = aggregateOf(m);
                if (!meshLeftInCache(a)) continue;
                exactAt.back() = static_cast<uint32_t>(lean.size());
                lean.push_back(&a);
                triangles += a.meshInCache->triangleCount;
            }
            if (!lean.empty() && !settings.cache)
                reloadError = "the hierarchy's meshes are in a tile cache, but no cache was given";
            if (!lean.empty() && !(settings.cache && readAggregateMeshes(*settings.cache, lean, exactRun, settings.threadCount,
                                                                        reloadError)))
                return finish(false);
        }
        double e = n.leaf ? 0.0 : n.error.bound();
        for (uint32_t c : n.children) e = std::max(e, nodes[c].geometricError);
        n.geometricError = floatUp(e);
        const uint32_t at = exactAt[i - runStart];
        const bool leafByReference = n.leaf && n.meshPlace.kind == NodeMeshPlace::Kind::Object;
        const std::vector<double>& exact = n.leaf ? (n.positions.empty() && !leafByReference ? none : objects[i].positions)
                                           : !exactAggregate ? none
                                           : at != kNoNode  ? exactRun[at].positions
                                                            : aggregateOf(n).positions;
        const std::vector<float>* own = &n.positions;
        if (leafByReference) {
            leafPositions.assign(objects[i].positions.begin(), objects[i].positions.end());
            own = &leafPositions;
        } else if (n.meshPlace.kind == NodeMeshPlace::Kind::File) {  // spilled above
            if (!readNodeMesh(out, objects, static_cast<uint32_t>(i), spilledMesh, reloadError)) return finish(false);
            own = &spilledMesh.positions;
        }
        computeBounds(n, *own, exact, nodes);
    }
    return finish(true);
}

}  // namespace

bool buildHierarchyNodes(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                         const ProxySettings& settings, HierarchyNodes& out, std::string& error) {
    try {
        return buildNodes(hierarchy, objects, settings, nullptr, out, error);
    } catch (const std::runtime_error& e) {  // a lean hierarchy's mesh that did not read back
        error = e.what();
        return false;
    }
}

bool buildProxyShare(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                     const ProxySettings& settings, const ProxyShare& share, std::string& error, size_t* made,
                     size_t* loaded, size_t* prepared) {
    if (!(share.phase == 1 || share.phase == 2) || share.parts == 0 || share.part >= share.parts) {
        error = "proxy share " + std::to_string(share.phase) + ":" + std::to_string(share.part) + ":" +
                std::to_string(share.parts) + " is out of range (phase 1 or 2, part below parts)";
        return false;
    }
    if (!settings.cache || !settings.cache->load || !settings.cache->store) {
        error = "a share of the proxies needs a cache to keep its results";
        return false;
    }
    HierarchyNodes nodes;
    bool ok = false;
    try {
        ok = buildNodes(hierarchy, objects, settings, &share, nodes, error);
    } catch (const std::runtime_error& e) {  // a lean hierarchy's mesh that did not read back
        error = e.what();
    }
    if (made) *made = nodes.proxyItemsMade;
    if (loaded) *loaded = nodes.proxyItemsLoaded;
    if (prepared) *prepared = nodes.originalsPrepared;
    return ok;
}

std::vector<HierarchyNode> enclosingVersions(const InputObject& object, const SolidReport* standIn,
                                             const ProxySettings& settings, bool support) {
    detail::PreparedOriginal original;
    try {
        detail::prepareOriginal(object, original);
    } catch (const std::invalid_argument&) {  // a non-finite coordinate or an index out of range
        return {};
    }
    VersionLadder ladder = objectLadder(object, original, standIn, support, settings);
    std::vector<HierarchyNode> out;
    for (Version& v : ladder.versions) out.push_back(std::move(v.node));
    return out;
}

uint32_t aggregateBelow(const HierarchyNodes& nodes, uint32_t node) {
    // A scene bundle (the roots' bundles, draw_bundles.h) has no aggregate above: the root itself.
    while (nodes.nodes[node].bundleStep >= 1 && nodes.nodes[node].parent != kNoNode) node = nodes.nodes[node].parent;
    while (nodes.nodes[node].coarserStep >= 1) node = nodes.nodes[node].children.front();
    return node;
}

}  // namespace aggrelod
