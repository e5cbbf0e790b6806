// SPDX-License-Identifier: AGPL-3.0-or-later
// The state of one 3D bake, shared by its stage files (docs/design.md §2): the objects as
// prepared, the models (vertices of the neighbourhood graph), the one free-space
// triangulation, and the small helpers the stages have in common. Internal to the module.
#pragma once

#include "free_space.h"
#include "mesh_distance.h"
#include "mesh_preparation.h"
#include "stage_timer.h"

#include <aggrelod/aggregate3d.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod::detail {

/// The cleaned meshes of `objects` as one triangle soup (positions 3 per vertex, triangles 3
/// per triangle, each object's indices shifted by the vertices before it).
inline void concatenateMeshes(const std::vector<PreparedObject>& prepared, const std::vector<uint32_t>& objects,
                       std::vector<double>& positions, std::vector<uint32_t>& triangles) {
    positions.clear();
    triangles.clear();
    for (uint32_t o : objects) {
        const uint32_t base = static_cast<uint32_t>(positions.size() / 3);
        positions.insert(positions.end(), prepared[o].positions.begin(), prepared[o].positions.end());
        for (uint32_t i : prepared[o].triangles) triangles.push_back(base + i);
    }
}

inline std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

inline void diag(Hierarchy3D& out, Diagnostic::Severity s, const std::string& object, const std::string& message) {
    out.diagnostics.push_back(Diagnostic{s, object, message});
}

inline std::string objectNames(const std::vector<InputObject>& objects, const std::vector<uint32_t>& ids, size_t limit = 6) {
    std::string s;
    for (size_t i = 0; i < ids.size() && i < limit; ++i) s += (i ? ", " : "") + objects[ids[i]].name;
    if (ids.size() > limit) s += ", ... (" + std::to_string(ids.size()) + " objects)";
    return s;
}

inline void computeBounds(const std::vector<double>& p, double b[6]) {
    for (int k = 0; k < 3; ++k) {
        b[k] = INFINITY;
        b[3 + k] = -INFINITY;
    }
    for (size_t i = 0; i + 2 < p.size(); i += 3)
        for (int k = 0; k < 3; ++k) {
            b[k] = std::min(b[k], p[i + k]);
            b[3 + k] = std::max(b[3 + k], p[i + k]);
        }
}

/// Diagonal of the box of every finite coordinate of `objects` (0 when none): the scene size
/// the relative tolerances are taken from.
inline double finiteDiagonal(const std::vector<InputObject>& objects) {
    double b[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const InputObject& o : objects)
        for (size_t i = 0; i + 2 < o.positions.size(); i += 3) {
            if (!std::isfinite(o.positions[i]) || !std::isfinite(o.positions[i + 1]) || !std::isfinite(o.positions[i + 2])) continue;
            for (int k = 0; k < 3; ++k) {
                b[k] = std::min(b[k], o.positions[i + k]);
                b[3 + k] = std::max(b[3 + k], o.positions[i + k]);
            }
        }
    return b[0] <= b[3] ? std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2])) : 0.0;
}

inline bool boxesOverlap(const double* a, const double* b, double pad) {
    for (int k = 0; k < 3; ++k)
        if (a[k] > b[3 + k] + pad || b[k] > a[3 + k] + pad) return false;
    return true;
}

// Candidate pairs whose boxes overlap after padding, sorted (i < j), by sweep on x.
template <class BoxOf>
std::vector<std::pair<uint32_t, uint32_t>> overlappingPairs(size_t n, BoxOf boxOf, double pad) {
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return std::make_pair(boxOf(a)[0], a) < std::make_pair(boxOf(b)[0], b);
    });
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (size_t i = 0; i < n; ++i) {
        const double* a = boxOf(order[i]);
        for (size_t j = i + 1; j < n; ++j) {
            const double* b = boxOf(order[j]);
            if (b[0] > a[3] + pad) break;
            if (boxesOverlap(a, b, pad)) pairs.emplace_back(std::min(order[i], order[j]), std::max(order[i], order[j]));
        }
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
}

inline bool pointInsideConvex(const std::vector<double>& hp, const std::vector<uint32_t>& ht, const double* q) {
    for (size_t t = 0; t + 2 < ht.size(); t += 3) {
        const double* a = &hp[3 * ht[t]];
        const double* b = &hp[3 * ht[t + 1]];
        const double* c = &hp[3 * ht[t + 2]];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        if (n[0] * (q[0] - a[0]) + n[1] * (q[1] - a[1]) + n[2] * (q[2] - a[2]) > 0) return false;
    }
    return true;
}

inline SolidMeasures measuresOf(double volume, double area) {
    SolidMeasures m;
    m.volume = volume;
    m.area = area;
    m.sphericity = sphericity(volume, area);
    return m;
}

/// Per object, 1 when it is a support surface by the rule of Settings3D::support (see
/// supportSpanFraction). bounds[i]: object i's box (min xyz, max xyz), nullptr when the
/// object is unusable (never a support surface).
std::vector<char> findSupportSurfaces(const std::vector<const double*>& bounds, const Settings3D& settings);

/// A vertex of the neighbourhood graph: one object, or objects that touch.
struct Model {
    std::vector<uint32_t> objects;    ///< ascending input indices
    /// What the surface given to the triangulator is: the objects' own faces, or a solid
    /// standing in for them (docs/design.md §2.0).
    enum class Kind { Original, Union, Shell, Wrap, Hull } kind = Kind::Original;
    bool standIn() const { return kind != Kind::Original; }
    std::string reason;               ///< why it is solidified
    double alpha = 0, offset = 0;     ///< wrap parameters
    double seconds = 0;               ///< time its solid took (one thread)
    std::vector<double> positions;    ///< the surface given to the triangulator
    std::vector<uint32_t> triangles;
    TriangleBvh bvh;
    double bounds[6];
    double volumeOriginal = 0;
    std::vector<double> hullPoints;   ///< convex hull vertices (for the hull baseline)
    double hullVolume = 0;            ///< their hull's volume
};

/// One 3D bake: the stages of docs/design.md §2 as steps over shared state. Each step
/// lives in the file of its stage (see the file list in docs/design.md §4).
class Baker3D {
public:
    Baker3D(const std::vector<InputObject>& objects, const Settings3D& settings, Hierarchy3D& out)
        : objects_(objects), settings_(settings), out_(out), timer_(out.timings, settings.progress) {}

    bool run();
    /// run() stops once the neighbourhood graph is built: out.merges holds its dendrogram
    /// and out.levels stays empty (the tiled bake's first pass, for automatic thresholds).
    void stopAfterGraph() { graphOnly_ = true; }

private:
    bool graphOnly_ = false;
    const std::vector<InputObject>& objects_;
    const Settings3D& settings_;
    Hierarchy3D& out_;
    StageTimer timer_;
    std::vector<PreparedObject> prepared_;
    std::vector<Model> models_;
    double diagonal_ = 0;
    double tolerance_ = 0;
    FreeSpace space_;
    AggregateFunction function_;

    bool prepare();
    void buildModels();
    /// Replaces the surfaces of models_[which[k]] by solids (SolidifyMethod), in parallel;
    /// diagnostics in `which` order. A model that cannot be solidified loses its objects.
    void solidifyModels(const std::vector<size_t>& which, const std::vector<std::string>& why);
    void makeStandIn(size_t model, const std::string& why) { solidifyModels({model}, {why}); }
    /// solidifyModels, the models nested in another's box last (see the definition).
    void solidifyNestedLast(const std::vector<size_t>& which, const std::vector<std::string>& why);
    void objectsBounds(const std::vector<uint32_t>& objects, double box[6]) const;
    double nearestGap(const Model& m, double limit) const;
    bool uniteClosedParts(Model& m) const;
    void detectSupport();
    void measureSolids();
    std::vector<TriangleBvh> objectBvh_;  ///< per prepared object (built in buildModels)
    std::vector<char> support_;           ///< per object: a support surface
    double smallestDelta_ = INFINITY;     ///< smallest positive explicit delta
    bool resolveStandInOverlaps();
    bool standInsChanged_ = true;  ///< a stand-in was made since the last resolveStandInOverlaps()
    bool triangulate();
    void analyseFreeSpace(const std::vector<int>& pointModel);
    void buildGraph();
    /// The graph's weights in 3D: each pair's exact or cdt distance (Settings3D::distance).
    std::vector<GraphEdge> weighedGraph() const {
        return graphEdges(space_.pairs, [](const ModelPair& p) { return p.weight; });
    }
    bool refineCoarseConnections();
    void prepareModels(int threadCount);
    bool modelsPrepared_ = false;  ///< BVHs and hulls match the models' current surfaces
    /// Exact distances measured before triangulating (prerefine), by (first object of a,
    /// first object of b). Their triangle numbers are not used: points are inserted right
    /// after. Whether a pair is cached never changes the result: meshDistance gives the same
    /// closest pair with or without its distance bound.
    std::map<std::pair<uint32_t, uint32_t>, ClosestPair> distanceCache_;
    std::vector<std::pair<uint32_t, uint32_t>> nearestPairsByBox(size_t neighbours) const;
    void prerefineClosePairs();
    struct Insertion {
        uint32_t model, triangle;
        double point[3];
    };
    /// nearVertex: what to do with a point close to a triangle corner: skip it (the corner
    /// is close already) or insert it inside the triangle all the same.
    enum class NearVertex { Skip, Insert };
    size_t insertSurfacePoints(std::vector<Insertion>& insertions, NearVertex nearVertex);
    void buildLevels();
    std::vector<double> visibleDeltas() const;
};

}  // namespace aggrelod::detail
