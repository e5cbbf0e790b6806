// SPDX-License-Identifier: AGPL-3.0-or-later
// The 3D bake (docs/design.md §2): prepare objects, set support surfaces aside and solidify what is
// not a valid closed solid (docs/design.md §2.0), group touching objects into models, triangulate
// the free space once, build the neighbourhood graph and dendrogram, then shape and measure
// every level from that one triangulation.
#include "convex_hull.h"
#include "solidify.h"
#include "free_space.h"
#include "mesh_distance.h"
#include "mesh_preparation.h"
#include "parallel_for.h"
#include "radix_sort.h"
#include "surface_colors.h"
#include "sculpt_3d.h"
#include "tetgen_backend.h"

#include <aggrelod/aggregate3d.h>
#include <aggrelod/dendrogram.h>
#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <set>
#include <string>
#include <thread>
#include <tuple>

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace aggrelod {
namespace {

using detail::FreeSpace;
using detail::ModelPair;
using detail::PreparedObject;
using detail::TriangleBvh;

using Clock = std::chrono::steady_clock;

/// The cleaned meshes of `objects` as one triangle soup (positions 3 per vertex, triangles 3
/// per triangle, each object's indices shifted by the vertices before it).
void concatenateMeshes(const std::vector<PreparedObject>& prepared, const std::vector<uint32_t>& objects,
                       std::vector<double>& positions, std::vector<uint32_t>& triangles) {
    positions.clear();
    triangles.clear();
    for (uint32_t o : objects) {
        const uint32_t base = static_cast<uint32_t>(positions.size() / 3);
        positions.insert(positions.end(), prepared[o].positions.begin(), prepared[o].positions.end());
        for (uint32_t i : prepared[o].triangles) triangles.push_back(base + i);
    }
}

struct StageTimer {
    Hierarchy3D& out;
    const ProgressCallback& progress;
    Clock::time_point start = Clock::now();
    std::string name;
    StageTimer(Hierarchy3D& o, const ProgressCallback& p) : out(o), progress(p) {}
    void begin(const std::string& stage) {
        end();
        name = stage;
        start = Clock::now();
        report(0.0);
    }
    void report(double fraction) const {
        if (progress && !name.empty()) progress(name.c_str(), fraction);
    }
    void end() {
        if (name.empty()) return;
        report(1.0);
        out.timings.emplace_back(name, std::chrono::duration<double>(Clock::now() - start).count());
        name.clear();
    }
};

std::string fmt(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void diag(Hierarchy3D& out, Diagnostic::Severity s, const std::string& object, const std::string& message) {
    out.diagnostics.push_back(Diagnostic{s, object, message});
}

/// A vertex of the neighbourhood graph: one object, or objects that touch.
struct Model {
    std::vector<uint32_t> objects;    ///< ascending input indices
    /// What the surface given to the triangulator is: the objects' own faces, or a solid
    /// standing in for them (docs/design.md §2.0).
    enum class Kind { Original, Union, Wrap, Hull } kind = Kind::Original;
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

std::string objectNames(const std::vector<InputObject>& objects, const std::vector<uint32_t>& ids, size_t limit = 6) {
    std::string s;
    for (size_t i = 0; i < ids.size() && i < limit; ++i) s += (i ? ", " : "") + objects[ids[i]].name;
    if (ids.size() > limit) s += ", ... (" + std::to_string(ids.size()) + " objects)";
    return s;
}

void computeBounds(const std::vector<double>& p, double b[6]) {
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

bool boxesOverlap(const double* a, const double* b, double pad) {
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

bool pointInsideConvex(const std::vector<double>& hp, const std::vector<uint32_t>& ht, const double* q) {
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

SolidMeasures measuresOf(double volume, double area) {
    SolidMeasures m;
    m.volume = volume;
    m.area = area;
    m.sphericity = area > 0 ? std::cbrt(M_PI) * std::pow(6.0 * std::max(volume, 0.0), 2.0 / 3.0) / area : 0.0;
    return m;
}

// ---------------------------------------------------------------------------------------

class Baker {
public:
    Baker(const std::vector<InputObject>& objects, const Settings3D& settings, Hierarchy3D& out)
        : objects_(objects), settings_(settings), out_(out), timer_(out, settings.progress) {}

    bool run();

private:
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
    bool refineCoarseConnections();
    void prepareModels(int threadCount);
    bool modelsPrepared_ = false;  ///< BVHs and hulls match the models' current surfaces
    /// Exact distances measured before triangulating (prerefine), by (first object of a,
    /// first object of b). Their triangle numbers are not used: points are inserted right
    /// after. Whether a pair is cached never changes the result: meshDistance gives the same
    /// closest pair with or without its distance bound.
    std::map<std::pair<uint32_t, uint32_t>, detail::ClosestPair> distanceCache_;
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

bool Baker::prepare() {
    timer_.begin("prepare");
    out_.diagnostics.clear();
    // Scene size from finite coordinates, for relative tolerances.
    double b[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const InputObject& o : objects_)
        for (size_t i = 0; i + 2 < o.positions.size(); i += 3) {
            if (!std::isfinite(o.positions[i]) || !std::isfinite(o.positions[i + 1]) || !std::isfinite(o.positions[i + 2])) continue;
            for (int k = 0; k < 3; ++k) {
                b[k] = std::min(b[k], o.positions[i + k]);
                b[3 + k] = std::max(b[3 + k], o.positions[i + k]);
            }
        }
    diagonal_ = b[0] <= b[3] ? std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2])) : 0.0;
    tolerance_ = settings_.touchTolerance >= 0 ? settings_.touchTolerance : 1e-6 * diagonal_;
    const double areaEpsilon = 1e-14 * diagonal_ * diagonal_;
    for (const InputObject& o : objects_)
        if (!o.triangleColors.empty() && !detail::hasTriangleColors(o))
            diag(out_, Diagnostic::Severity::Warning, o.name,
                 "triangleColors has " + std::to_string(o.triangleColors.size()) + " values, expected 4 per triangle (" +
                     std::to_string(4 * (o.indices.size() / 3)) + "); the object counts as white");
    prepared_.resize(objects_.size());
    size_t usable = 0;
    for (size_t i = 0; i < objects_.size(); ++i) {
        detail::prepareObject(objects_[i], areaEpsilon, prepared_[i], out_.diagnostics);
        if (prepared_[i].usable) {
            ++usable;
            out_.inputTriangleCount += prepared_[i].triangles.size() / 3;
            out_.originals.volume += prepared_[i].volume;
            out_.originals.area += prepared_[i].area;
        }
        timer_.report(double(i + 1) / objects_.size());
    }
    out_.originals = measuresOf(out_.originals.volume, out_.originals.area);
    if (usable == 0) {
        diag(out_, Diagnostic::Severity::Error, "", objects_.empty() ? "the scene has no objects" : "no usable object in the scene");
        return false;
    }
    for (double d : settings_.deltas)
        if (d > 0) smallestDelta_ = std::min(smallestDelta_, d);
    detectSupport();
    if (usable == out_.supportObjects.size()) {
        diag(out_, Diagnostic::Severity::Error, "", "every usable object is a support surface: nothing to aggregate");
        return false;
    }
    return true;
}

// Support surfaces (docs/design.md §2.0): ground, terrain, sky dome, road network, room shell. The
// rule (Settings3D::supportSpanFraction): an object that spans most of the scene in two
// axes and whose box meets the boxes of a large share of the other objects carries or
// encloses them; aggregating it would join everything into one blob at the finest level.
void Baker::detectSupport() {
    const size_t n = objects_.size();
    support_.assign(n, 0);
    std::vector<uint32_t> usable;
    for (uint32_t i = 0; i < n; ++i)
        if (prepared_[i].usable) usable.push_back(i);
    if (settings_.support == SupportDetection::Given) {
        for (uint32_t i : settings_.supportObjects)
            if (i < n && prepared_[i].usable) support_[i] = 1;
    } else if (settings_.support == SupportDetection::Automatic) {
        // Peeled in rounds: a huge outer ground hides the town's own ground and roads,
        // which span the box of what is left once it is set aside.
        for (int round = 0; round < 3; ++round) {
            std::vector<uint32_t> rest;
            for (uint32_t i : usable)
                if (!support_[i]) rest.push_back(i);
            if (rest.size() < 3) break;
            double scene[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
            for (uint32_t i : rest)
                for (int k = 0; k < 3; ++k) {
                    scene[k] = std::min(scene[k], prepared_[i].bounds[k]);
                    scene[3 + k] = std::max(scene[3 + k], prepared_[i].bounds[3 + k]);
                }
            // The scene's two longest axes (ties: lower axis first).
            int axes[3] = {0, 1, 2};
            std::stable_sort(axes, axes + 3, [&](int x, int y) { return scene[3 + x] - scene[x] > scene[3 + y] - scene[y]; });
            const double pad = 0.01 * std::sqrt((scene[3] - scene[0]) * (scene[3] - scene[0]) + (scene[4] - scene[1]) * (scene[4] - scene[1]) +
                                                (scene[5] - scene[2]) * (scene[5] - scene[2]));
            auto pairs = overlappingPairs(rest.size(), [&](uint32_t k) { return prepared_[rest[k]].bounds; }, pad);
            std::vector<size_t> meets(rest.size(), 0);
            for (auto [x, y] : pairs) {
                ++meets[x];
                ++meets[y];
            }
            const double others = double(rest.size() - 1);
            std::vector<uint32_t> found;
            for (size_t k = 0; k < rest.size(); ++k) {
                const PreparedObject& p = prepared_[rest[k]];
                bool wide = true;
                for (int j = 0; j < 2; ++j) {
                    const int d = axes[j];
                    wide = wide && p.bounds[3 + d] - p.bounds[d] >= settings_.supportSpanFraction * (scene[3 + d] - scene[d]);
                }
                if (wide && meets[k] >= 2 && double(meets[k]) >= settings_.supportShareFraction * others) found.push_back(rest[k]);
            }
            // At least two objects must be left to aggregate.
            if (found.empty() || rest.size() - found.size() < 2) break;
            for (uint32_t i : found) support_[i] = 1;
        }
    }
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < n; ++i)
        if (support_[i]) ids.push_back(i);
    out_.supportObjects = ids;
    if (!ids.empty())
        diag(out_, Diagnostic::Severity::Warning, objectNames(objects_, ids, 20),
             std::string(settings_.support == SupportDetection::Given ? "support surfaces as asked"
                                                                      : "support surfaces (span the scene and meet most objects)") +
                 ": kept out of aggregation and passed through unchanged (--support none aggregates them)");
}

// Sampled distances between each solid and its originals, both ways, and the same for the
// convex hull of the originals (for comparison): vertices and triangle centroids of one
// surface, closest point on the other (BVH). Not certified: a point between samples may lie
// a little farther.
void Baker::measureSolids() {
    std::vector<size_t> which;
    for (size_t m = 0; m < models_.size(); ++m)
        if (models_[m].standIn() && !models_[m].objects.empty()) which.push_back(m);
    if (which.empty()) return;
    timer_.begin("solid measures");
    auto sampled = [](const std::vector<double>& p, const std::vector<uint32_t>& t, const TriangleBvh& target) {
        double worst = 0;
        for (size_t v = 0; v + 2 < p.size(); v += 3) worst = std::max(worst, detail::closestPoint(target, &p[v]).distance);
        for (size_t i = 0; i + 2 < t.size(); i += 3) {
            double c[3];
            for (int k = 0; k < 3; ++k) c[k] = (p[3 * t[i] + k] + p[3 * t[i + 1] + k] + p[3 * t[i + 2] + k]) / 3.0;
            worst = std::max(worst, detail::closestPoint(target, c).distance);
        }
        return worst;
    };
    std::vector<SolidReport> reports(which.size());
    detail::parallelFor(which.size(), settings_.threadCount, [&](size_t k) {
        const Model& m = models_[which[k]];
        SolidReport& r = reports[k];
        r.objects = m.objects;
        r.method = m.kind == Model::Kind::Union ? SolidifyMethod::Union
                   : m.kind == Model::Kind::Wrap ? SolidifyMethod::Wrap
                                                 : SolidifyMethod::Hull;
        r.reason = m.reason;
        r.alpha = m.alpha;
        r.offset = m.offset;
        r.seconds = m.seconds;
        std::vector<double> pts;
        std::vector<uint32_t> tris;
        concatenateMeshes(prepared_, m.objects, pts, tris);
        for (uint32_t o : m.objects) r.volumeOriginal += std::fabs(prepared_[o].volume);
        double b[6];
        computeBounds(pts, b);
        r.bboxDiagonal = std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2]));
        double area = 0;
        detail::meshVolumeArea(m.positions, m.triangles, r.volumeSolid, area);
        TriangleBvh original;
        original.build(pts.data(), pts.size() / 3, tris.data(), tris.size() / 3);
        r.distanceSolidToOriginal = sampled(m.positions, m.triangles, original);
        r.distanceOriginalToSolid = sampled(pts, tris, m.bvh);
        // Closed and edge-manifold as a fresh check of the triangulator's input.
        InputObject solid;
        solid.positions = m.positions;
        solid.indices = m.triangles;
        PreparedObject check;
        std::vector<Diagnostic> ignored;
        detail::prepareObject(solid, 0.0, check, ignored);
        r.closedManifold = check.validSolid();
        if (settings_.computeHullBaseline && r.method != SolidifyMethod::Hull) {
            std::vector<double> hp;
            std::vector<uint32_t> ht;
            if (detail::convexHull3(pts, hp, ht)) {
                TriangleBvh hull;
                hull.build(hp.data(), hp.size() / 3, ht.data(), ht.size() / 3);
                r.hullDistance = std::max(sampled(hp, ht, original), sampled(pts, tris, hull));
            }
        }
        r.positions = m.positions;
        r.triangles = m.triangles;
    }, [&](size_t done) { timer_.report(double(done) / which.size()); });
    std::sort(reports.begin(), reports.end(), [](const SolidReport& a, const SolidReport& b) { return a.objects < b.objects; });
    out_.solids = std::move(reports);
}

// Generalized winding number of a closed surface around q (Jacobson et al. 2013; solid
// angles by Van Oosterom and Strackee 1983): about 1 inside, 0 outside, robust to small
// defects. O(triangles).
double windingNumber(const std::vector<double>& p, const std::vector<uint32_t>& t, const double* q) {
    double total = 0;
    for (size_t i = 0; i + 2 < t.size(); i += 3) {
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = p[3 * t[i] + k] - q[k];
            b[k] = p[3 * t[i + 1] + k] - q[k];
            c[k] = p[3 * t[i + 2] + k] - q[k];
        }
        const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        const double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                           a[2] * (b[0] * c[1] - b[1] * c[0]);
        const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        const double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
        const double ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
        total += 2.0 * std::atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
    }
    return total / (4.0 * M_PI);
}

// Objects that are valid solids alone but touch or cross each other: their exact union as
// the model's surface when it is one closed, edge-manifold shell that does not cross itself
// after rounding (the tightest solid: its surface lies on theirs). False leaves m unchanged.
bool Baker::uniteClosedParts(Model& m) const {
    std::vector<const std::vector<double>*> positions;
    std::vector<const std::vector<uint32_t>*> triangles;
    for (uint32_t o : m.objects) {
        positions.push_back(&prepared_[o].positions);
        triangles.push_back(&prepared_[o].triangles);
    }
    std::vector<double> p;
    std::vector<uint32_t> t;
    std::string error;
    if (!detail::exactUnion(positions, triangles, p, t, error)) return false;
    InputObject united;
    united.positions = std::move(p);
    united.indices = std::move(t);
    PreparedObject check;
    std::vector<Diagnostic> ignored;
    detail::prepareObject(united, 0.0, check, ignored);
    if (!check.validSolid() || check.positions.size() != united.positions.size() ||
        check.triangles.size() != united.indices.size() || detail::selfIntersects(check.positions, check.triangles))
        return false;
    // One shell: parts that only come near each other stay for the wrap to join.
    DisjointSets shells(check.positions.size() / 3);
    size_t pieces = check.positions.size() / 3;
    for (size_t i = 0; i + 2 < check.triangles.size(); i += 3)
        for (int k = 1; k < 3; ++k) pieces -= shells.unite(check.triangles[i], check.triangles[i + k]) ? 1 : 0;
    if (pieces != 1) return false;
    m.positions = std::move(check.positions);
    m.triangles = std::move(check.triangles);
    m.kind = Model::Kind::Union;
    m.alpha = m.offset = 0;
    return true;
}

// Distance from the original surfaces of m's objects to the nearest other model's objects,
// looked for up to `limit` (returns `limit` when none is nearer). Support surfaces do not
// count: they are not in the triangulation, so a wrap may reach into the ground.
double Baker::nearestGap(const Model& m, double limit) const {
    double box[6];
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    for (uint32_t o : m.objects)
        for (int k = 0; k < 3; ++k) {
            box[k] = std::min(box[k], prepared_[o].bounds[k]);
            box[3 + k] = std::max(box[3 + k], prepared_[o].bounds[3 + k]);
        }
    double best = limit;
    for (uint32_t other = 0; other < prepared_.size(); ++other) {
        if (!prepared_[other].usable || support_[other] || std::binary_search(m.objects.begin(), m.objects.end(), other)) continue;
        if (!boxesOverlap(box, prepared_[other].bounds, best)) continue;
        for (uint32_t o : m.objects) {
            const detail::ClosestPair cp = detail::meshDistance(objectBvh_[o], objectBvh_[other], best);
            if (cp.distance < best) best = cp.distance;
        }
    }
    return best;
}

void Baker::solidifyModels(const std::vector<size_t>& which, const std::vector<std::string>& why) {
    if (which.empty()) return;
    const std::string stage = timer_.name;  // resumed afterwards: solidifying is timed on its own
    timer_.begin("solidify");
    standInsChanged_ = true;
    modelsPrepared_ = false;
    distanceCache_.clear();
    std::vector<std::string> failure(which.size());
    std::vector<char> flat(which.size(), 0);
    std::vector<char> fellBack(which.size(), 0);
    // Largest first (by input triangles): the two threads then finish together.
    std::vector<size_t> order(which.size()), load(which.size(), 0);
    std::iota(order.begin(), order.end(), size_t(0));
    for (size_t k = 0; k < which.size(); ++k)
        for (uint32_t o : models_[which[k]].objects) load[k] += prepared_[o].triangles.size();
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return load[a] > load[b]; });
    detail::parallelFor(which.size(), settings_.threadCount, [&](size_t i) {
        const size_t k = order[i];
        Model& m = models_[which[k]];
        const auto started = std::chrono::steady_clock::now();
        struct Clock {  // the solid's own time, however this lambda ends
            Model& m;
            std::chrono::steady_clock::time_point started;
            ~Clock() { m.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(); }
        } clock{m, started};
        m.reason = why[k];
        m.positions.clear();
        m.triangles.clear();
        std::vector<double> pts;
        std::vector<uint32_t> tris;
        concatenateMeshes(prepared_, m.objects, pts, tris);
        const bool closed = std::all_of(m.objects.begin(), m.objects.end(), [&](uint32_t o) { return prepared_[o].validSolid(); });
        if (settings_.solidify == SolidifyMethod::Wrap && closed && m.objects.size() > 1 && uniteClosedParts(m)) return;
        if (settings_.solidify == SolidifyMethod::Wrap) {
            double b[6];
            computeBounds(pts, b);
            const double size = std::sqrt((b[3] - b[0]) * (b[3] - b[0]) + (b[4] - b[1]) * (b[4] - b[1]) + (b[5] - b[2]) * (b[5] - b[2]));
            double offset = settings_.wrapOffset;
            if (!(offset > 0)) {
                // Tight enough to keep the shape, never reaching a neighbour (a quarter of the
                // gap each side leaves half of it free), never blurring the finest level.
                const double cap = std::min(0.004 * size, 0.25 * smallestDelta_);
                offset = std::min(cap, 0.25 * nearestGap(m, 4 * cap));
                offset = std::max(offset, 5e-4 * size);
            }
            // 1.5 % keeps every truck_town house within 2 % of its diagonal (two-sided); the
            // cost grows as 1 / alpha^2 (see docs/real-art.md). Closed objects that only cross
            // themselves or each other have their shape in their own faces: the wrap only has
            // to join them, and 3 % keeps it within about 0.6 % (truck_town's ramps) at a
            // quarter of the cost.
            const double alpha = std::max((closed ? 0.03 : 0.015) * size, 2 * offset);
            std::string error;
            if (size > 0 && detail::alphaWrap(pts, tris, alpha, offset, m.positions, m.triangles, error)) {
                // The wrap must be a valid solid piece of the triangulation's input.
                InputObject wrapped;
                wrapped.positions = m.positions;
                wrapped.indices = m.triangles;
                PreparedObject check;
                std::vector<Diagnostic> ignored;
                detail::prepareObject(wrapped, 0.0, check, ignored);
                if (check.validSolid() && check.positions.size() == m.positions.size()) {
                    m.positions = std::move(check.positions);
                    m.triangles = std::move(check.triangles);
                    m.kind = Model::Kind::Wrap;
                    m.alpha = alpha;
                    m.offset = offset;
                    return;
                }
                error = "the wrap is not a closed, consistently oriented solid";
            }
            failure[k] = error;
            m.positions.clear();
            m.triangles.clear();
            fellBack[k] = 1;
        }
        if (settings_.solidify == SolidifyMethod::Off) return;
        m.alpha = m.offset = 0;
        m.kind = Model::Kind::Hull;
        if (!detail::convexHull3(pts, m.positions, m.triangles)) flat[k] = 1;
    }, [&](size_t done) { timer_.report(double(done) / which.size()); });
    for (size_t k = 0; k < which.size(); ++k) {
        Model& m = models_[which[k]];
        const std::string names = objectNames(objects_, m.objects);
        if (settings_.solidify == SolidifyMethod::Off && m.positions.empty()) {
            diag(out_, Diagnostic::Severity::Warning, names,
                 why[k] + "; left out of aggregation (--solidify off) and passed through unchanged");
            m.objects.clear();
            continue;
        }
        if (flat[k]) {
            diag(out_, Diagnostic::Severity::Warning, names,
                 why[k] + (fellBack[k] ? "; could not be wrapped (" + failure[k] + ")" : std::string()) +
                     "; it is flat, has no convex hull with volume, and is left out");
            m.objects.clear();
            continue;
        }
        if (m.kind == Model::Kind::Union)
            diag(out_, Diagnostic::Severity::Note, names,
                 why[k] + "; solidified by their exact boolean union for the triangulation");
        else if (m.kind == Model::Kind::Wrap)
            diag(out_, Diagnostic::Severity::Note, names,
                 why[k] + "; solidified by an alpha wrap (alpha " + fmt(m.alpha) + ", offset " + fmt(m.offset) +
                     ") for the triangulation");
        else
            diag(out_, Diagnostic::Severity::Warning, names,
                 why[k] + (fellBack[k] ? "; alpha wrap failed (" + failure[k] + ")" : std::string()) +
                     "; stood in for by its convex hull in the triangulation");
    }
    if (!stage.empty() && stage != "solidify") timer_.begin(stage);
}

void Baker::buildModels() {
    timer_.begin("models");
    const size_t n = objects_.size();
    objectBvh_.assign(n, TriangleBvh{});
    std::vector<TriangleBvh>& bvh = objectBvh_;
    detail::parallelFor(n, settings_.threadCount, [&](size_t i) {
        if (prepared_[i].usable)
            bvh[i].build(prepared_[i].positions.data(), prepared_[i].positions.size() / 3, prepared_[i].triangles.data(),
                         prepared_[i].triangles.size() / 3);
    });
    std::vector<uint32_t> usable;
    for (uint32_t i = 0; i < n; ++i)
        if (prepared_[i].usable && !support_[i]) usable.push_back(i);
    auto pairs = overlappingPairs(usable.size(), [&](uint32_t k) { return prepared_[usable[k]].bounds; }, tolerance_);
    DisjointSets sets(n);
    for (size_t p = 0; p < pairs.size(); ++p) {
        uint32_t i = usable[pairs[p].first], j = usable[pairs[p].second];
        if (i > j) std::swap(i, j);
        detail::ClosestPair cp = detail::meshDistance(bvh[i], bvh[j], tolerance_, tolerance_);
        if (cp.distance <= tolerance_) {
            sets.unite(i, j);
            diag(out_, Diagnostic::Severity::Note, objects_[i].name + ", " + objects_[j].name,
                 cp.intersecting ? "objects intersect; aggregated as one model from the start"
                                 : "objects touch (distance " + fmt(cp.distance) + " <= tolerance " + fmt(tolerance_) +
                                       "); aggregated as one model from the start");
        }
        if (p % 64 == 0) timer_.report(double(p) / std::max<size_t>(pairs.size(), 1));
    }
    std::map<uint32_t, size_t> modelOfRoot;
    for (uint32_t i : usable) {
        uint32_t r = sets.find(i);
        auto it = modelOfRoot.find(r);
        if (it == modelOfRoot.end()) {
            it = modelOfRoot.emplace(r, models_.size()).first;
            models_.emplace_back();
        }
        models_[it->second].objects.push_back(i);
    }
    // A closed surface that crosses itself would fail the triangulation (and TetGen's own
    // search for the crossing facets is slow): find those first.
    std::vector<char> crossing(models_.size(), 0);
    detail::parallelFor(models_.size(), settings_.threadCount, [&](size_t i) {
        const Model& m = models_[i];
        if (m.objects.size() == 1 && prepared_[m.objects[0]].validSolid())
            crossing[i] = detail::selfIntersects(prepared_[m.objects[0]].positions, prepared_[m.objects[0]].triangles);
    });
    std::vector<size_t> toSolidify;
    std::vector<std::string> why;
    for (size_t i = 0; i < models_.size(); ++i) {
        Model& m = models_[i];
        for (uint32_t o : m.objects) m.volumeOriginal += prepared_[o].volume;
        if (crossing[i]) {
            toSolidify.push_back(i);
            why.push_back("self-intersecting surface");
        } else if (m.objects.size() == 1 && prepared_[m.objects[0]].validSolid()) {
            m.positions = prepared_[m.objects[0]].positions;
            m.triangles = prepared_[m.objects[0]].triangles;
        } else {
            toSolidify.push_back(i);
            why.push_back(m.objects.size() == 1 ? "not a closed, consistently oriented solid"
                                                : "touching or intersecting objects form one model");
        }
    }
    solidifyNestedLast(toSolidify, why);
}

// Objects' bounding box (of their original surfaces).
void Baker::objectsBounds(const std::vector<uint32_t>& objects, double box[6]) const {
    for (int k = 0; k < 3; ++k) {
        box[k] = INFINITY;
        box[3 + k] = -INFINITY;
    }
    for (uint32_t o : objects)
        for (int k = 0; k < 3; ++k) {
            box[k] = std::min(box[k], prepared_[o].bounds[k]);
            box[3 + k] = std::max(box[3 + k], prepared_[o].bounds[3 + k]);
        }
}

// A model to be wrapped whose box lies inside the box of another one (a spring in an engine)
// is often swallowed by that one's wrap, which then has to be wrapped again with it: its own
// wrap would be wasted. So the outer models are wrapped first; a nested model whose original
// surfaces all lie inside one of those wraps, apart from it, joins that model and keeps its
// wrap (a closed solid containing both); the others are wrapped after.
void Baker::solidifyNestedLast(const std::vector<size_t>& which, const std::vector<std::string>& why) {
    std::vector<std::array<double, 6>> box(which.size());
    for (size_t k = 0; k < which.size(); ++k) objectsBounds(models_[which[k]].objects, box[k].data());
    auto within = [](const std::array<double, 6>& inner, const std::array<double, 6>& outer) {
        for (int d = 0; d < 3; ++d)
            if (inner[d] < outer[d] || inner[3 + d] > outer[3 + d]) return false;
        return true;
    };
    std::vector<size_t> first, nested;
    std::vector<std::string> firstWhy, nestedWhy;
    for (size_t k = 0; k < which.size(); ++k) {
        bool inside = false;
        for (size_t j = 0; j < which.size() && !inside; ++j) inside = j != k && within(box[k], box[j]) && !within(box[j], box[k]);
        (inside ? nested : first).push_back(which[k]);
        (inside ? nestedWhy : firstWhy).push_back(why[k]);
    }
    solidifyModels(first, firstWhy);
    if (nested.empty()) return;
    // Each nested model against the wraps made above, in model order (deterministic).
    std::vector<size_t> host(nested.size(), SIZE_MAX);
    detail::parallelFor(nested.size(), settings_.threadCount, [&](size_t k) {
        const Model& inner = models_[nested[k]];
        double b[6];
        objectsBounds(inner.objects, b);
        for (size_t f : first) {
            const Model& outer = models_[f];
            if ((outer.kind != Model::Kind::Wrap && outer.kind != Model::Kind::Union) || outer.objects.empty()) continue;
            double ob[6];
            computeBounds(outer.positions, ob);
            bool boxInside = true;
            for (int d = 0; d < 3; ++d) boxInside = boxInside && b[d] > ob[d] && b[3 + d] < ob[3 + d];
            if (!boxInside) continue;
            TriangleBvh wrapBvh;
            wrapBvh.build(outer.positions.data(), outer.positions.size() / 3, outer.triangles.data(), outer.triangles.size() / 3);
            // Apart from the wrap's surface and with one point of every connected piece inside
            // it, the whole of each object is inside.
            bool inside = true;
            for (uint32_t o : inner.objects) {
                if (!inside) break;
                const PreparedObject& p = prepared_[o];
                if (detail::meshDistance(objectBvh_[o], wrapBvh, tolerance_, tolerance_).distance <= tolerance_) {
                    inside = false;
                    break;
                }
                std::vector<uint32_t> piece(p.positions.size() / 3);
                std::iota(piece.begin(), piece.end(), 0u);
                auto find = [&piece](uint32_t x) {
                    while (piece[x] != x) x = piece[x] = piece[piece[x]];
                    return x;
                };
                for (size_t t = 0; t + 2 < p.triangles.size(); t += 3)
                    for (int c = 1; c < 3; ++c) {
                        const uint32_t a = find(p.triangles[t]), z = find(p.triangles[t + c]);
                        if (a != z) piece[std::max(a, z)] = std::min(a, z);
                    }
                for (size_t t = 0; t + 2 < p.triangles.size() && inside; t += 3) {
                    const uint32_t v = p.triangles[t];
                    if (find(v) != v) continue;  // one vertex per piece: its smallest
                    inside = windingNumber(outer.positions, outer.triangles, &p.positions[3 * v]) > 0.5;
                }
            }
            if (inside) {
                host[k] = f;
                break;
            }
        }
    });
    std::vector<size_t> rest;
    std::vector<std::string> restWhy;
    for (size_t k = 0; k < nested.size(); ++k) {
        Model& inner = models_[nested[k]];
        if (host[k] == SIZE_MAX) {
            rest.push_back(nested[k]);
            restWhy.push_back(nestedWhy[k]);
            continue;
        }
        Model& outer = models_[host[k]];
        diag(out_, Diagnostic::Severity::Note, objectNames(objects_, inner.objects),
             nestedWhy[k] + "; inside the alpha wrap of " + objectNames(objects_, outer.objects) +
                 ": joins that model, whose wrap stands for both");
        outer.objects.insert(outer.objects.end(), inner.objects.begin(), inner.objects.end());
        std::sort(outer.objects.begin(), outer.objects.end());
        outer.volumeOriginal += inner.volumeOriginal;
        inner.objects.clear();
    }
    solidifyModels(rest, restWhy);
}

// A convex-hull stand-in may reach into another model: merge them (and re-hull) until no
// stand-in touches or contains another model.
// Also leaves every model's bounds and BVH up to date.
bool Baker::resolveStandInOverlaps() {
    bool changed = false;
    standInsChanged_ = false;
    for (int round = 0; round < 64; ++round) {
        models_.erase(std::remove_if(models_.begin(), models_.end(), [](const Model& m) { return m.objects.empty(); }),
                      models_.end());
        detail::parallelFor(models_.size(), settings_.threadCount, [&](size_t i) {
            Model& m = models_[i];
            computeBounds(m.positions, m.bounds);
            m.bvh.build(m.positions.data(), m.positions.size() / 3, m.triangles.data(), m.triangles.size() / 3);
        });
        auto pairs = overlappingPairs(models_.size(), [&](uint32_t k) { return models_[k].bounds; }, tolerance_);
        DisjointSets sets(models_.size());
        bool merged = false;
        for (auto [i, j] : pairs) {
            Model& a = models_[i];
            Model& b = models_[j];
            if (!a.standIn() && !b.standIn()) continue;
            bool joins = detail::meshDistance(a.bvh, b.bvh, tolerance_, tolerance_).distance <= tolerance_;
            // One inside the other (surfaces apart): a hull by its planes, any other closed
            // surface by its winding number.
            auto inside = [](const Model& outer, const double* q) {
                return outer.kind == Model::Kind::Hull ? pointInsideConvex(outer.positions, outer.triangles, q)
                                                       : windingNumber(outer.positions, outer.triangles, q) > 0.5;
            };
            if (!joins && boxesOverlap(a.bounds, b.bounds, 0) ) joins = inside(a, &b.positions[0]) || inside(b, &a.positions[0]);
            if (joins) merged |= sets.unite(i, j);
        }
        if (!merged) return changed;
        changed = true;
        modelsPrepared_ = false;
        distanceCache_.clear();
        std::vector<Model> next;
        std::map<uint32_t, size_t> at;
        for (uint32_t i = 0; i < models_.size(); ++i) {
            uint32_t r = sets.find(i);
            if (r == i) {
                at[i] = next.size();
                next.push_back(std::move(models_[i]));
            } else {
                Model& dst = next[at[r]];
                dst.objects.insert(dst.objects.end(), models_[i].objects.begin(), models_[i].objects.end());
                dst.volumeOriginal += models_[i].volumeOriginal;
                dst.kind = Model::Kind::Original;  // solidified again below
            }
        }
        std::vector<size_t> again;
        std::vector<std::string> why;
        for (size_t k = 0; k < next.size(); ++k) {
            Model& m = next[k];
            std::sort(m.objects.begin(), m.objects.end());
            if (!m.standIn() && m.objects.size() > 1) {
                again.push_back(k);
                why.push_back("a solidified stand-in reaches other objects; merged");
            }
        }
        models_ = std::move(next);
        solidifyModels(again, why);
    }
    return changed;
}

bool Baker::triangulate() {
    timer_.begin("tetrahedralize");
    for (int attempt = 0; attempt < 6; ++attempt) {
        if (standInsChanged_) resolveStandInOverlaps();
        // Model order: by smallest object index (deterministic).
        std::sort(models_.begin(), models_.end(), [](const Model& a, const Model& b) { return a.objects[0] < b.objects[0]; });
        detail::PlcInput plc;
        plc.cpuSeconds = settings_.triangulationSeconds;
        plc.memoryBytes = settings_.triangulationMemory;
        std::vector<int> pointModel;
        for (size_t m = 0; m < models_.size(); ++m) {
            const int base = static_cast<int>(plc.points.size() / 3);
            plc.points.insert(plc.points.end(), models_[m].positions.begin(), models_[m].positions.end());
            pointModel.insert(pointModel.end(), models_[m].positions.size() / 3, static_cast<int>(m));
            for (uint32_t idx : models_[m].triangles) plc.triangles.push_back(base + static_cast<int>(idx));
            plc.triangleMarkers.insert(plc.triangleMarkers.end(), models_[m].triangles.size() / 3, static_cast<int>(m) + 1);
        }
        space_ = FreeSpace{};
        // TetGen runs in a child process on one core; meanwhile this process builds the
        // models' BVHs and hulls (needed right after) on one thread. Each model's result
        // does not depend on the thread doing it, so output stays deterministic.
        // (It used to go on measuring likely neighbour pairs until TetGen was done; on this
        // 2-vCPU VM that slowed TetGen's child by more than it saved in the graph stage.)
        std::thread preparing;
        const bool overlap = !modelsPrepared_ && settings_.threadCount != 1;
        if (overlap)
            preparing = std::thread([this] {
#ifdef __linux__
                // Lowest priority for this thread only: on a busy machine TetGen goes first.
                setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
#endif
                prepareModels(1);
            });
        detail::TetgenOutcome outcome = detail::tetrahedralizePlc(plc, space_.mesh);
        if (preparing.joinable()) preparing.join();
        for (const char* fallback : {"Y", "M"}) {
            if (outcome.status != detail::TetgenStatus::Crashed && outcome.status != detail::TetgenStatus::InternalError) break;
            std::vector<int> markers;
            detail::TetgenOutcome found = detail::findIntersectingFacets(plc, markers);
            if (found.status != detail::TetgenStatus::Ok || !markers.empty()) break;  // repaired below
            space_ = FreeSpace{};
            detail::TetgenOutcome retry = detail::tetrahedralizePlc(plc, space_.mesh, fallback);
            if (retry.status == detail::TetgenStatus::Ok)
                diag(out_, Diagnostic::Severity::Note, "",
                     std::string("TetGen's boundary recovery failed (") + outcome.message + "); succeeded with switch " + fallback);
            outcome = retry;
        }
        if (outcome.status == detail::TetgenStatus::Ok) {
            timer_.begin("free space");
            space_.modelCount = models_.size();
            analyseFreeSpace(pointModel);
            return true;
        }
        // Intersecting input makes TetGen report code 3 or trip one of its assertions:
        // find the facets that intersect (switch d) and stand in for their models.
        if (outcome.status == detail::TetgenStatus::SelfIntersection || outcome.status == detail::TetgenStatus::Crashed ||
            outcome.status == detail::TetgenStatus::InternalError) {
            std::vector<int> markers;
            detail::TetgenOutcome found = detail::findIntersectingFacets(plc, markers);
            bool repaired = false;
            if (found.status == detail::TetgenStatus::Ok) {
                std::vector<size_t> which;
                for (int marker : markers) {
                    if (marker <= 0 || static_cast<size_t>(marker) > models_.size()) continue;
                    if (!models_[marker - 1].standIn()) which.push_back(static_cast<size_t>(marker - 1));
                }
                std::sort(which.begin(), which.end());
                which.erase(std::unique(which.begin(), which.end()), which.end());
                solidifyModels(which, std::vector<std::string>(which.size(), "self-intersecting surface"));
                repaired = !which.empty();
            }
            if (repaired) continue;
        }
        diag(out_, Diagnostic::Severity::Error, "",
             std::string("tetrahedralization failed: ") + detail::tetgenStatusName(outcome.status) + " (" + outcome.message + ")");
        return false;
    }
    diag(out_, Diagnostic::Severity::Error, "", "tetrahedralization failed after repeated repairs of intersecting input");
    return false;
}

void Baker::analyseFreeSpace(const std::vector<int>& pointModel) {
    detail::TetMesh& mesh = space_.mesh;
    const size_t tetCount = mesh.tetCount();
    // TetGen orients all tets alike; make them positive (the sculptor's face tables assume
    // it). Decide once from the total, never per tet: a sliver's rounded sign can lie.
    space_.tetVolume.assign(tetCount, 0.0);
    double signedTotal = 0;
    for (size_t t = 0; t < tetCount; ++t) {
        const double* a = &mesh.points[3 * mesh.tets[4 * t]];
        const double* b = &mesh.points[3 * mesh.tets[4 * t + 1]];
        const double* c = &mesh.points[3 * mesh.tets[4 * t + 2]];
        const double* d = &mesh.points[3 * mesh.tets[4 * t + 3]];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        double vol = ((u[1] * v[2] - u[2] * v[1]) * w[0] + (u[2] * v[0] - u[0] * v[2]) * w[1] + (u[0] * v[1] - u[1] * v[0]) * w[2]) / 6.0;
        signedTotal += vol;
        space_.tetVolume[t] = std::fabs(vol);
    }
    if (signedTotal < 0) {
        for (size_t t = 0; t < tetCount; ++t) {
            std::swap(mesh.tets[4 * t + 2], mesh.tets[4 * t + 3]);
            std::swap(mesh.neighbors[4 * t + 2], mesh.neighbors[4 * t + 3]);
        }
    }
    // Vertex owners: input points by construction; Steiner points on a model's surface
    // through the constrained faces they lie on.
    space_.vertexModel.assign(mesh.pointCount(), -1);
    for (size_t v = 0; v < pointModel.size() && v < mesh.pointCount(); ++v) space_.vertexModel[v] = pointModel[v];
    for (size_t f = 0; f < mesh.boundaryMarkers.size(); ++f) {
        int marker = mesh.boundaryMarkers[f];
        if (marker <= 0) continue;
        for (int k = 0; k < 3; ++k) {
            int v = mesh.boundaryFaces[3 * f + k];
            if (v >= 0 && static_cast<size_t>(v) < mesh.pointCount() && space_.vertexModel[v] < 0) space_.vertexModel[v] = marker - 1;
        }
    }
    // Interior tets: flood each enclosed region from a tet that faces free space through a
    // model's surface.
    space_.tetModel.assign(tetCount, -1);
    std::vector<int> stack;
    for (size_t t = 0; t < tetCount; ++t) {
        if (mesh.regions[t] == -1.0 || space_.tetModel[t] >= 0) continue;
        int model = -1;
        for (int j = 0; j < 4 && model < 0; ++j) {
            // the face opposite corner j: if all three corners belong to one model, it is on it
            int owners[3], k = 0;
            for (int c = 0; c < 4; ++c)
                if (c != j) owners[k++] = space_.vertexModel[mesh.tets[4 * t + c]];
            if (owners[0] >= 0 && owners[0] == owners[1] && owners[1] == owners[2]) {
                int n = mesh.neighbors[4 * t + j];
                if (n < 0 || mesh.regions[n] == -1.0) model = owners[0];
            }
        }
        if (model < 0) continue;
        stack.push_back(static_cast<int>(t));
        space_.tetModel[t] = model;
        while (!stack.empty()) {
            int s = stack.back();
            stack.pop_back();
            for (int j = 0; j < 4; ++j) {
                int n = mesh.neighbors[4 * s + j];
                if (n >= 0 && mesh.regions[n] != -1.0 && space_.tetModel[n] < 0 && mesh.regions[n] == mesh.regions[s]) {
                    space_.tetModel[n] = model;
                    stack.push_back(n);
                }
            }
        }
    }
    for (size_t t = 0; t < tetCount; ++t)
        if (mesh.regions[t] != -1.0 && space_.tetModel[t] < 0) {
            // An enclosed region no model surface faces (should not happen); treat as free.
            mesh.regions[t] = -1.0;
        }
    out_.tetrahedronCount = tetCount;
}

void Baker::buildGraph() {
    timer_.begin("graph");
    const detail::TetMesh& mesh = space_.mesh;
    constexpr int kEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
    std::vector<std::pair<int, int>> edges;
    for (size_t t = 0; t < mesh.tetCount(); ++t) {
        if (space_.tetModel[t] >= 0) continue;
        for (auto& e : kEdges) {
            int u = mesh.tets[4 * t + e[0]], v = mesh.tets[4 * t + e[1]];
            int mu = space_.vertexModel[u], mv = space_.vertexModel[v];
            if (mu < 0 || mv < 0 || mu == mv) continue;
            edges.emplace_back(std::min(u, v), std::max(u, v));
        }
    }
    // Sorted and unique, as std::sort + std::unique would give, but bucketed by the first
    // vertex first (counting sort): each edge appears in several tets, and the list is long.
    {
        const size_t pointCount = mesh.pointCount();
        std::vector<uint32_t> start;
        std::vector<std::pair<int, int>> byFirst;
        detail::countingSortByBucket(edges, pointCount, [](const std::pair<int, int>& e) { return e.first; }, start, byFirst);
        edges.clear();
        for (size_t u = 0; u < pointCount; ++u) {
            const auto b = byFirst.begin() + start[u], e = byFirst.begin() + start[u + 1];
            std::sort(b, e);  // one first vertex: by the second
            for (auto v = b; v != e; ++v)
                if (v == b || v->second != (v - 1)->second) edges.push_back(*v);
        }
    }
    // Accumulate per model pair (u on a, v on b, a < b).
    struct Acc {
        uint32_t a, b;
        double length;
        int u, v;
    };
    std::vector<Acc> accs;
    accs.reserve(edges.size());
    for (auto [u, v] : edges) {
        int mu = space_.vertexModel[u], mv = space_.vertexModel[v];
        if (mu > mv) {
            std::swap(mu, mv);
            std::swap(u, v);
        }
        const double* p = &mesh.points[3 * u];
        const double* q = &mesh.points[3 * v];
        double len = std::sqrt((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]));
        accs.push_back({static_cast<uint32_t>(mu), static_cast<uint32_t>(mv), len, u, v});
    }
    std::sort(accs.begin(), accs.end(), [](const Acc& x, const Acc& y) {
        return std::tie(x.a, x.b, x.length, x.u, x.v) < std::tie(y.a, y.b, y.length, y.u, y.v);
    });
    space_.pairs.clear();
    space_.lengths.clear();
    space_.lengthPrefix.clear();
    space_.lengthSqPrefix.clear();
    for (size_t i = 0; i < accs.size();) {
        size_t j = i;
        while (j < accs.size() && accs[j].a == accs[i].a && accs[j].b == accs[i].b) ++j;
        ModelPair p;
        p.a = accs[i].a;
        p.b = accs[i].b;
        p.edgeCount = static_cast<uint32_t>(j - i);
        p.shortestEdge = accs[i].length;  // sorted by length within the pair
        p.shortestEdgeVertexA = accs[i].u;
        p.shortestEdgeVertexB = accs[i].v;
        p.firstLength = static_cast<uint32_t>(space_.lengthPrefix.size());
        double run = 0, runSq = 0;
        for (size_t k = i; k < j; ++k) {
            run += accs[k].length;
            runSq += accs[k].length * accs[k].length;
            space_.lengths.push_back(accs[k].length);
            space_.lengthPrefix.push_back(run);
            space_.lengthSqPrefix.push_back(runSq);
        }
        space_.edgeStatsBelow(p, INFINITY, p.meanEdge, p.sigmaEdge);
        space_.pairs.push_back(p);
        i = j;
    }
    // Exact distances between neighbouring models (BVH closest pair).
    timer_.begin("distances");
    if (!modelsPrepared_) prepareModels(settings_.threadCount);
    const size_t pairCount = space_.pairs.size();
    detail::parallelFor(pairCount, settings_.threadCount, [&](size_t i) {
        ModelPair& p = space_.pairs[i];
        const double* ua = &mesh.points[3 * p.shortestEdgeVertexA];
        const double* ub = &mesh.points[3 * p.shortestEdgeVertexB];
        std::copy(ua, ua + 3, p.closestA);
        std::copy(ub, ub + 3, p.closestB);
        p.exactDistance = p.shortestEdge;
        // Pairs measured before triangulating keep that result (same surfaces; their
        // triangle numbers changed with the inserted points, so those are not kept).
        auto cached = distanceCache_.find({models_[p.a].objects[0], models_[p.b].objects[0]});
        const bool fromCache = cached != distanceCache_.end();
        const detail::ClosestPair cp =
            fromCache ? cached->second : detail::meshDistance(models_[p.a].bvh, models_[p.b].bvh, p.shortestEdge);
        if (std::isfinite(cp.distance) && cp.distance <= p.shortestEdge) {
            p.exactDistance = cp.distance;
            std::copy(cp.pointA, cp.pointA + 3, p.closestA);
            std::copy(cp.pointB, cp.pointB + 3, p.closestB);
            if (!fromCache) {
                p.closestTriangleA = cp.triangleA;
                p.closestTriangleB = cp.triangleB;
            }
        }
        p.weight = settings_.distance == DistanceMode::Exact ? p.exactDistance : p.shortestEdge;
    }, [&](size_t done) {
        if (done % 64 == 0) timer_.report(double(done) / pairCount);
    });
}

// Before the one triangulation: each model's nearest neighbours (by box distance) are
// measured exactly; where the closest points lie far from the surface vertices (coarse
// triangles), they are inserted as vertices, so the triangulation gets gap-spanning edges
// close to the true distance without a second TetGen run (docs/design.md §2.4 step 4).
void Baker::prerefineClosePairs() {
    timer_.begin("prerefine");
    resolveStandInOverlaps();
    if (models_.size() < 2) return;
    const std::vector<std::pair<uint32_t, uint32_t>> candidates = nearestPairsByBox(6);
    std::vector<Insertion> insertions;
    auto nearestVertexDistance = [&](const Model& m, uint32_t tri, const double* p) {
        double best = INFINITY;
        for (int k = 0; k < 3; ++k) {
            const double* v = &m.positions[3 * m.triangles[3 * tri + k]];
            best = std::min(best, std::sqrt((v[0] - p[0]) * (v[0] - p[0]) + (v[1] - p[1]) * (v[1] - p[1]) + (v[2] - p[2]) * (v[2] - p[2])));
        }
        return best;
    };
    // Measure every candidate on its own slot, then gather in candidate order.
    std::vector<std::array<Insertion, 2>> found(candidates.size());
    std::vector<std::array<bool, 2>> use(candidates.size(), {false, false});
    std::vector<detail::ClosestPair> measured(candidates.size());
    detail::parallelFor(candidates.size(), settings_.threadCount, [&](size_t c) {
        const auto [i, j] = candidates[c];
        detail::ClosestPair cp = detail::meshDistance(models_[i].bvh, models_[j].bvh);
        measured[c] = cp;
        if (cp.triangleA == ~0u || cp.triangleB == ~0u || !(cp.distance > tolerance_)) return;
        const double ra = nearestVertexDistance(models_[i], cp.triangleA, cp.pointA);
        const double rb = nearestVertexDistance(models_[j], cp.triangleB, cp.pointB);
        if (ra + rb <= 0.5 * cp.distance) return;  // a short edge exists already
        found[c][0] = Insertion{i, cp.triangleA, {cp.pointA[0], cp.pointA[1], cp.pointA[2]}};
        found[c][1] = Insertion{j, cp.triangleB, {cp.pointB[0], cp.pointB[1], cp.pointB[2]}};
        use[c] = {ra > 0.1 * cp.distance, rb > 0.1 * cp.distance};
    }, [&](size_t done) {
        if (done % 64 == 0) timer_.report(double(done) / candidates.size());
    });
    for (size_t c = 0; c < candidates.size(); ++c) {
        for (int k = 0; k < 2; ++k)
            if (use[c][k]) insertions.push_back(found[c][k]);
        const auto [i, j] = candidates[c];
        distanceCache_[{models_[i].objects[0], models_[j].objects[0]}] = measured[c];
    }
    insertSurfacePoints(insertions, NearVertex::Skip);
}

// Splits surface triangles at the given points. A point well inside its triangle splits it
// 1 -> 3; a point near an edge splits that edge (the triangle and its neighbour across the
// edge, 2 -> 4, the new vertex on the edge), because a 1 -> 3 split there makes thin sliver
// triangles that slow the triangulation's exact predicates down; a point near a corner is
// skipped or, with NearVertex::Insert, moved inside (no degenerate triangle). Surfaces stay
// closed, manifold and outward. Returns how many points were inserted.
size_t Baker::insertSurfacePoints(std::vector<Insertion>& insertions, NearVertex nearVertex) {
    modelsPrepared_ = false;  // surfaces change (not their shape: distances stay valid)
    std::stable_sort(insertions.begin(), insertions.end(), [](const Insertion& x, const Insertion& y) {
        return std::tie(x.model, x.triangle) < std::tie(y.model, y.triangle);
    });
    constexpr double kNearEdge = 0.1;  // smallest barycentric coordinate below this: near an edge
    size_t inserted = 0;
    for (size_t i = 0; i < insertions.size();) {
        size_t j = i;
        while (j < insertions.size() && insertions[j].model == insertions[i].model) ++j;
        Model& model = models_[insertions[i].model];
        const uint32_t originalCount = static_cast<uint32_t>(model.triangles.size() / 3);
        // children[t]: current triangles covering original triangle t; origin[t]: the original
        // triangle a current triangle comes from (new triangles only, index - originalCount).
        std::map<uint32_t, std::vector<uint32_t>> children;
        std::vector<uint32_t> origin;
        auto addChild = [&](uint32_t parent, uint32_t child) {
            const uint32_t root = parent < originalCount ? parent : origin[parent - originalCount];
            auto& list = children[root];
            if (list.empty()) list.push_back(root);
            list.push_back(child);
            origin.push_back(root);
        };
        // Directed edge (from, to) -> triangles holding it, for finding the neighbour across an
        // edge; built on the first edge split (lookups only, never iterated).
        std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> edges;
        bool edgesBuilt = false;
        auto edgeKey = [](uint32_t from, uint32_t to) { return std::make_pair(from, to); };
        auto setTriangle = [&](uint32_t t, uint32_t x, uint32_t y, uint32_t z) {
            if (edgesBuilt && 3 * static_cast<size_t>(t) + 2 < model.triangles.size()) {
                const uint32_t* old = &model.triangles[3 * t];
                for (int e = 0; e < 3; ++e) {
                    auto& list = edges[edgeKey(old[e], old[(e + 1) % 3])];
                    list.erase(std::remove(list.begin(), list.end(), t), list.end());
                }
            }
            if (3 * static_cast<size_t>(t) + 2 >= model.triangles.size()) model.triangles.resize(3 * static_cast<size_t>(t) + 3);
            model.triangles[3 * t] = x;
            model.triangles[3 * t + 1] = y;
            model.triangles[3 * t + 2] = z;
            if (edgesBuilt) {
                const uint32_t v[3] = {x, y, z};
                for (int e = 0; e < 3; ++e) edges[edgeKey(v[e], v[(e + 1) % 3])].push_back(t);
            }
        };
        for (size_t k = i; k < j; ++k) {
            const Insertion& ins = insertions[k];
            if (ins.triangle >= originalCount) continue;
            auto& list = children[ins.triangle];
            if (list.empty()) list.push_back(ins.triangle);
            // Locate the child with the largest smallest barycentric coordinate.
            int bestChild = -1;
            double bestMin = -INFINITY, bary[3] = {0, 0, 0};
            for (size_t c = 0; c < list.size(); ++c) {
                const uint32_t* tri = &model.triangles[3 * list[c]];
                const double* A = &model.positions[3 * tri[0]];
                const double* B = &model.positions[3 * tri[1]];
                const double* C = &model.positions[3 * tri[2]];
                double v0[3], v1[3], v2[3];
                for (int d = 0; d < 3; ++d) {
                    v0[d] = B[d] - A[d];
                    v1[d] = C[d] - A[d];
                    v2[d] = ins.point[d] - A[d];
                }
                double d00 = v0[0] * v0[0] + v0[1] * v0[1] + v0[2] * v0[2];
                double d01 = v0[0] * v1[0] + v0[1] * v1[1] + v0[2] * v1[2];
                double d11 = v1[0] * v1[0] + v1[1] * v1[1] + v1[2] * v1[2];
                double d20 = v2[0] * v0[0] + v2[1] * v0[1] + v2[2] * v0[2];
                double d21 = v2[0] * v1[0] + v2[1] * v1[1] + v2[2] * v1[2];
                double den = d00 * d11 - d01 * d01;
                if (!(den > 0)) continue;
                double v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den, u = 1 - v - w;
                double mn = std::min(u, std::min(v, w));
                if (mn > bestMin) {
                    bestMin = mn;
                    bestChild = static_cast<int>(c);
                    bary[0] = u;
                    bary[1] = v;
                    bary[2] = w;
                }
            }
            if (bestChild < 0) continue;
            const uint32_t t = list[bestChild];
            const uint32_t corner[3] = {model.triangles[3 * t], model.triangles[3 * t + 1], model.triangles[3 * t + 2]};
            const uint32_t nv = static_cast<uint32_t>(model.positions.size() / 3);
            const uint32_t t1 = static_cast<uint32_t>(model.triangles.size() / 3);
            // Near an edge (one small coordinate) or a corner (two).
            int smallest = 0;
            for (int e = 1; e < 3; ++e)
                if (bary[e] < bary[smallest]) smallest = e;
            const int p = (smallest + 1) % 3, q = (smallest + 2) % 3;  // the edge corner[p] -> corner[q]
            const bool nearEdge = bary[smallest] < kNearEdge;
            const bool nearCorner = nearEdge && std::min(bary[p], bary[q]) < kNearEdge;
            if (nearCorner && nearVertex == NearVertex::Skip) continue;
            if (nearEdge && !nearCorner) {
                if (!edgesBuilt) {
                    for (uint32_t f = 0; 3 * static_cast<size_t>(f) + 2 < model.triangles.size(); ++f)
                        for (int e = 0; e < 3; ++e)
                            edges[edgeKey(model.triangles[3 * f + e], model.triangles[3 * f + (e + 1) % 3])].push_back(f);
                    edgesBuilt = true;
                }
                const uint32_t a = corner[p], b = corner[q], c = corner[smallest];
                const auto forward = edges.find(edgeKey(a, b));
                const auto backward = edges.find(edgeKey(b, a));
                // Only on a manifold edge (one triangle each way); otherwise split 1 -> 3 below.
                if (forward != edges.end() && forward->second.size() == 1 && backward != edges.end() && backward->second.size() == 1 &&
                    backward->second[0] != t) {
                    const uint32_t t2 = backward->second[0];
                    const uint32_t* n2 = &model.triangles[3 * t2];
                    uint32_t d = n2[0];
                    for (int e = 0; e < 3; ++e)
                        if (n2[e] != a && n2[e] != b) d = n2[e];
                    // The point projected on the edge, kept away from the corners.
                    const double s = std::min(std::max(bary[q] / (bary[p] + bary[q]), kNearEdge), 1 - kNearEdge);
                    for (int dim = 0; dim < 3; ++dim)
                        model.positions.push_back((1 - s) * model.positions[3 * a + dim] + s * model.positions[3 * b + dim]);
                    // (a, b, c) -> (a, nv, c) + (nv, b, c); neighbour (b, a, d) -> (b, nv, d) + (nv, a, d).
                    setTriangle(t, a, nv, c);
                    setTriangle(t1, nv, b, c);
                    addChild(t, t1);
                    setTriangle(t2, b, nv, d);
                    setTriangle(t1 + 1, nv, a, d);
                    addChild(t2, t1 + 1);
                    ++inserted;
                    continue;
                }
            }
            // Keep the new vertex strictly inside (no sliver, no degenerate triangle).
            const double floorBary = 0.02;
            double sum = 0;
            for (double& w : bary) {
                w = std::max(w, floorBary);
                sum += w;
            }
            for (double& w : bary) w /= sum;
            const uint32_t a = corner[0], b = corner[1], c = corner[2];
            for (int d = 0; d < 3; ++d)
                model.positions.push_back(bary[0] * model.positions[3 * a + d] + bary[1] * model.positions[3 * b + d] +
                                          bary[2] * model.positions[3 * c + d]);
            setTriangle(t, a, b, nv);
            setTriangle(t1, b, c, nv);
            addChild(t, t1);
            setTriangle(t1 + 1, c, a, nv);
            addChild(t, t1 + 1);
            ++inserted;
        }
        i = j;
    }
    return inserted;
}

// Pairs (i < j, sorted, unique) of each model with its `neighbours` nearest models by box
// distance.
std::vector<std::pair<uint32_t, uint32_t>> Baker::nearestPairsByBox(size_t neighbours) const {
    const size_t n = models_.size();
    std::vector<std::pair<uint32_t, uint32_t>> candidates;
    std::vector<std::pair<double, uint32_t>> near;
    for (uint32_t i = 0; i < n; ++i) {
        near.clear();
        for (uint32_t j = 0; j < n; ++j) {
            if (j == i) continue;
            double d2 = 0;
            for (int k = 0; k < 3; ++k) {
                double gap = std::max({0.0, models_[j].bounds[k] - models_[i].bounds[3 + k], models_[i].bounds[k] - models_[j].bounds[3 + k]});
                d2 += gap * gap;
            }
            near.emplace_back(d2, j);
        }
        const size_t keep = std::min(neighbours, near.size());
        std::partial_sort(near.begin(), near.begin() + keep, near.end());
        for (size_t k = 0; k < keep; ++k) candidates.emplace_back(std::min(i, near[k].second), std::max(i, near[k].second));
    }
    std::sort(candidates.begin(), candidates.end());
    candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
    return candidates;
}

// Per model: BVH of its surface (for exact distances) and convex hull (for the baseline).
void Baker::prepareModels(int threadCount) {
    detail::parallelFor(models_.size(), threadCount, [&](size_t m) {
        Model& model = models_[m];
        model.bvh.build(model.positions.data(), model.positions.size() / 3, model.triangles.data(), model.triangles.size() / 3);
        if (!settings_.computeHullBaseline) return;
        if (!model.standIn()) {
            model.hullVolume = detail::convexHullVolume(model.positions, &model.hullPoints);
            return;
        }
        // The baseline is the hull of the originals, not of their (slightly larger) solid.
        std::vector<double> points;
        for (uint32_t o : model.objects) points.insert(points.end(), prepared_[o].positions.begin(), prepared_[o].positions.end());
        model.hullVolume = detail::convexHullVolume(points, &model.hullPoints);
    });
    modelsPrepared_ = true;
}

// docs/design.md §2.4 step 4: where large input triangles leave no short triangulation edge between
// two models the dendrogram joins (shortest edge much longer than the exact distance),
// insert the closest points into both surfaces as Steiner vertices and triangulate again,
// so that gap-spanning edges approach the true distance. One extra pass, only when needed.
bool Baker::refineCoarseConnections() {
    std::vector<GraphEdge> graph;
    for (const ModelPair& p : space_.pairs) graph.push_back(GraphEdge{p.a, p.b, p.weight});
    std::vector<Merge> merges = kruskalMerges(models_.size(), graph);
    std::vector<Insertion> insertions;
    for (const Merge& m : merges) {
        int idx = space_.findPair(m.modelA, m.modelB);
        if (idx < 0) continue;
        const ModelPair& p = space_.pairs[idx];
        if (p.closestTriangleA == ~0u || p.closestTriangleB == ~0u) continue;
        if (!(p.shortestEdge > 1.5 * p.exactDistance + tolerance_)) continue;
        Insertion a{p.a, p.closestTriangleA, {p.closestA[0], p.closestA[1], p.closestA[2]}};
        Insertion b{p.b, p.closestTriangleB, {p.closestB[0], p.closestB[1], p.closestB[2]}};
        insertions.push_back(a);
        insertions.push_back(b);
    }
    if (insertions.empty()) return false;
    timer_.begin("refine");
    const size_t inserted = insertSurfacePoints(insertions, NearVertex::Insert);
    diag(out_, Diagnostic::Severity::Note, "",
         "refined " + std::to_string(inserted) + " surface point(s) where the triangulation had no short connection "
         "between joined models; triangulating again");
    return inserted > 0;
}

// Automatic thresholds that change something one can see (docs/design.md §2.3). Merges closer than
// 0.1 % of the diagonal of the aggregated objects (support surfaces left out) look the same
// as touching at any distance where the scene is seen whole: the geometric series of levels
// starts at the first merge above that, and runs to the last merge. The finest level sits
// at half of that first visible merge, so it shows every model apart (except those nearer
// than that) before anything visible is joined.
std::vector<double> Baker::visibleDeltas() const {
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const Model& m : models_)
        for (uint32_t o : m.objects)
            for (int k = 0; k < 3; ++k) {
                box[k] = std::min(box[k], prepared_[o].bounds[k]);
                box[3 + k] = std::max(box[3 + k], prepared_[o].bounds[3 + k]);
            }
    const double diagonal = box[0] <= box[3] ? std::sqrt((box[3] - box[0]) * (box[3] - box[0]) + (box[4] - box[1]) * (box[4] - box[1]) +
                                                         (box[5] - box[2]) * (box[5] - box[2]))
                                             : 0.0;
    const double visible = 1e-3 * diagonal;
    std::vector<Merge> seen;
    for (const Merge& m : out_.merges)
        if (m.height >= visible) seen.push_back(m);
    if (seen.empty()) seen = out_.merges;
    const int count = settings_.automaticLevelCount;
    std::vector<double> deltas = automaticDeltas(seen, count > 1 ? count - 1 : count);
    if (count > 1 && !seen.empty() && seen.front().height > 0) deltas.insert(deltas.begin(), 0.5 * seen.front().height);
    return deltas;
}

void Baker::buildLevels() {
    timer_.begin("hierarchy");
    detail::precomputeTetEdges(space_, settings_.threadCount);
    std::vector<GraphEdge> graph;
    for (const ModelPair& p : space_.pairs) graph.push_back(GraphEdge{p.a, p.b, p.weight});
    out_.merges = kruskalMerges(models_.size(), graph);
    std::vector<double> deltas = settings_.deltas;
    if (deltas.empty()) {
        deltas = visibleDeltas();
        if (deltas.empty()) {
            deltas.push_back(0.0);
            diag(out_, Diagnostic::Severity::Note, "",
                 models_.size() == 1 ? "only one model: nothing to aggregate; the single level holds it alone"
                                     : "no two models are neighbours: nothing to aggregate");
        }
    }
    std::sort(deltas.begin(), deltas.end());
    deltas.erase(std::unique(deltas.begin(), deltas.end()), deltas.end());

    AggregateFunction constant = makeAggregateFunction(AggregateFunctionKind::Constant);
    const bool isConstant = !settings_.customFunction && settings_.function == AggregateFunctionKind::Constant;
    const bool measureConstant = !isConstant && settings_.computeConstantBaseline;
    timer_.begin("levels");

    // What each level needs, prepared here so the sculpting below touches only its own data.
    struct LevelWork {
        std::vector<uint32_t> modelGroup;
        size_t groupCount = 0;
        detail::EdgeLimits limits, constantLimits;
        detail::LevelShapeRequest request;
        std::vector<Aggregate> aggregates;
        double volumeConstant = 0;
        double totalVolume = 0, totalArea = 0;  ///< sums over the level's aggregates
        size_t triangleCount = 0;
    };
    std::vector<LevelWork> work(deltas.size());
    for (size_t li = 0; li < deltas.size(); ++li) {
        LevelWork& w = work[li];
        w.modelGroup = groupsAtThreshold(models_.size(), out_.merges, deltas[li], &w.groupCount);
        w.limits = detail::computeEdgeLimits(space_, deltas[li], function_, settings_.distance);
        if (measureConstant) w.constantLimits = detail::computeEdgeLimits(space_, deltas[li], constant, settings_.distance);
        w.request.modelGroup = &w.modelGroup;
        w.request.groupCount = w.groupCount;
        w.request.limits = &w.limits;
        for (const Merge& m : out_.merges) {
            if (!(m.height < deltas[li])) break;
            int p = space_.findPair(m.modelA, m.modelB);
            if (p < 0) continue;
            const ModelPair& pair = space_.pairs[p];
            detail::ProtectedConnection c;
            c.modelA = pair.a;
            c.modelB = pair.b;
            const double* pa = pair.closestA;
            const double* pb = pair.closestB;
            if (settings_.distance == DistanceMode::Cdt) {
                pa = &space_.mesh.points[3 * pair.shortestEdgeVertexA];
                pb = &space_.mesh.points[3 * pair.shortestEdgeVertexB];
            }
            std::copy(pa, pa + 3, c.pointA);
            std::copy(pb, pb + 3, c.pointB);
            w.request.connections.push_back(c);
        }
    }

    // Hull baseline, level by level: starts from each model's own hull. A group's hull is
    // the hull of its sub-groups' hulls at the previous level (groups only coarsen): a group
    // unchanged since then keeps its hull, others are built from the few vertices of their
    // parts' hulls. It does not depend on the sculpting, so it runs as one more task beside
    // the levels (one chain, in level order), keeping both cores busy to the end.
    struct GroupHull {
        std::vector<double> vertices;
        double volume = 0;
    };
    std::vector<std::vector<double>> hullVolumes(deltas.size());  ///< per level, per group
    auto computeHullBaseline = [&] {
        std::vector<GroupHull> previousHulls(models_.size());
        std::vector<uint32_t> previousHullOfModel(models_.size());
        for (size_t m = 0; m < models_.size(); ++m) {
            previousHullOfModel[m] = static_cast<uint32_t>(m);
            previousHulls[m].vertices = models_[m].hullPoints;
            previousHulls[m].volume = models_[m].hullVolume;
        }
        for (size_t li = 0; li < deltas.size(); ++li) {
            const LevelWork& w = work[li];
            std::vector<GroupHull> hulls(w.groupCount);
            std::vector<std::vector<uint32_t>> parts(w.groupCount);
            for (size_t m = 0; m < models_.size(); ++m) parts[w.modelGroup[m]].push_back(previousHullOfModel[m]);
            for (size_t g = 0; g < w.groupCount; ++g) {
                std::vector<uint32_t>& p = parts[g];
                std::sort(p.begin(), p.end());
                p.erase(std::unique(p.begin(), p.end()), p.end());
                if (p.size() == 1) {
                    hulls[g] = previousHulls[p[0]];
                } else {
                    std::vector<double> points;
                    for (uint32_t part : p) points.insert(points.end(), previousHulls[part].vertices.begin(), previousHulls[part].vertices.end());
                    hulls[g].volume = detail::convexHullVolume(points, &hulls[g].vertices);
                }
            }
            hullVolumes[li].resize(w.groupCount);
            for (size_t g = 0; g < w.groupCount; ++g) hullVolumes[li][g] = hulls[g].volume;
            for (size_t m = 0; m < models_.size(); ++m) previousHullOfModel[m] = w.modelGroup[m];
            previousHulls = std::move(hulls);
        }
    };

    // Levels are independent given the one triangulation: sculpt them on several threads;
    // each level writes only its own LevelWork. Coarse levels keep much more free space and
    // cost the most, so they are started first (the threads then finish together); the hull
    // baseline (when asked) runs as one task after the coarser half.
    // Buffers reused by the next level on whichever thread (at most one set per thread).
    std::vector<std::unique_ptr<detail::SculptScratch>> scratchPool;
    std::mutex scratchMutex;
    auto takeScratch = [&] {
        std::lock_guard<std::mutex> lock(scratchMutex);
        if (scratchPool.empty()) return std::make_unique<detail::SculptScratch>();
        std::unique_ptr<detail::SculptScratch> s = std::move(scratchPool.back());
        scratchPool.pop_back();
        return s;
    };
    auto giveBackScratch = [&](std::unique_ptr<detail::SculptScratch> s) {
        std::lock_guard<std::mutex> lock(scratchMutex);
        scratchPool.push_back(std::move(s));
    };
    std::vector<size_t> taskOrder;  // level index, or SIZE_MAX for the hull baseline
    for (size_t k = 0; k < work.size(); ++k) {
        if (settings_.computeHullBaseline && k == work.size() / 2) taskOrder.push_back(SIZE_MAX);
        taskOrder.push_back(work.size() - 1 - k);
    }
    detail::parallelFor(
        taskOrder.size(), settings_.threadCount,
        [&](size_t task) {
            if (taskOrder[task] == SIZE_MAX) {
                computeHullBaseline();
                return;
            }
            const size_t li = taskOrder[task];
            LevelWork& w = work[li];
            std::unique_ptr<detail::SculptScratch> scratch = takeScratch();
            std::vector<int>& label = scratch->label;
            std::vector<int>& constantLabel = scratch->baselineLabel;
            if (measureConstant) w.request.baselineLimits = &w.constantLimits;
            detail::sculptLevel(space_, w.request, label, &constantLabel, &scratch->surfaceTets, scratch.get());
            detail::extractSurfaces(space_, label, w.groupCount, w.aggregates, &scratch->surfaceTets, scratch.get());
            // Per-aggregate sources and measures, on the same thread (levels are independent).
            std::vector<std::array<size_t, 2>> kinds(w.aggregates.size(), {0, 0});  // original, solidified models
            for (size_t m = 0; m < models_.size(); ++m) {
                Aggregate& agg = w.aggregates[w.modelGroup[m]];
                agg.sourceObjects.insert(agg.sourceObjects.end(), models_[m].objects.begin(), models_[m].objects.end());
                agg.volumeOriginal += models_[m].volumeOriginal;
                ++kinds[w.modelGroup[m]][models_[m].standIn() ? 1 : 0];
            }
            for (size_t g = 0; g < w.aggregates.size(); ++g)
                w.aggregates[g].surface = kinds[g][1] == 0   ? Aggregate::Surface::Original
                                          : kinds[g][0] == 0 ? Aggregate::Surface::Solidified
                                                             : Aggregate::Surface::Mixed;
            for (Aggregate& agg : w.aggregates) {
                std::sort(agg.sourceObjects.begin(), agg.sourceObjects.end());
                std::vector<const InputObject*> sources;
                for (uint32_t o : agg.sourceObjects) sources.push_back(&objects_[o]);
                detail::nearestSurfaceColors(agg.positions, agg.indices, sources, agg.faceColors);
                double v = 0, a = 0;
                detail::meshVolumeArea(agg.positions, agg.indices, v, a);
                agg.measures = measuresOf(v, a);
                w.totalVolume += v;
                w.totalArea += a;
                w.triangleCount += agg.indices.size() / 3;
            }
            if (measureConstant)
                for (size_t t = 0; t < constantLabel.size(); ++t)
                    if (constantLabel[t] >= 0) w.volumeConstant += space_.tetVolume[t];
            giveBackScratch(std::move(scratch));
        },
        [&](size_t done) { timer_.report(double(done) / taskOrder.size()); });

    timer_.begin("level measures");
    for (size_t li = 0; li < deltas.size(); ++li) {
        LevelWork& w = work[li];
        Level level;
        level.delta = deltas[li];
        std::vector<Aggregate>& aggregates = w.aggregates;
        const double totalVolume = w.totalVolume, totalArea = w.totalArea;
        level.triangleCount = w.triangleCount;
        level.measures = measuresOf(totalVolume, totalArea);
        level.volumeOriginal = out_.originals.volume;
        if (settings_.computeHullBaseline)
            for (size_t g = 0; g < w.groupCount; ++g) {
                aggregates[g].volumeHull = hullVolumes[li][g];
                level.volumeHull += hullVolumes[li][g];
            }
        level.volumeConstant = isConstant ? totalVolume : w.volumeConstant;
        level.hasVolumeConstant = isConstant || measureConstant;
        level.aggregates = std::move(aggregates);
        out_.levels.push_back(std::move(level));
        timer_.report(double(li + 1) / deltas.size());
    }
}

bool Baker::run() {
    out_ = Hierarchy3D{};
    function_ = settings_.customFunction ? settings_.customFunction : makeAggregateFunction(settings_.function);
    if (!prepare()) {
        timer_.end();
        return false;
    }
    buildModels();
    if (settings_.distance == DistanceMode::Exact) prerefineClosePairs();
    if (!triangulate()) {
        timer_.end();
        return false;
    }
    out_.modelCount = models_.size();
    out_.objectModel.assign(objects_.size(), UINT32_MAX);
    for (size_t m = 0; m < models_.size(); ++m)
        for (uint32_t o : models_[m].objects) out_.objectModel[o] = static_cast<uint32_t>(m);
    for (uint32_t o = 0; o < objects_.size(); ++o)
        if (out_.objectModel[o] == UINT32_MAX && !support_[o]) out_.leftOutObjects.push_back(o);
    if (!modelsPrepared_) {
        timer_.begin("model hulls");
        prepareModels(settings_.threadCount);
    }
    buildGraph();
    if (settings_.distance == DistanceMode::Exact && refineCoarseConnections()) {
        if (!triangulate()) {
            timer_.end();
            return false;
        }
        buildGraph();
    }
    measureSolids();
    buildLevels();
    timer_.end();
    return true;
}

}  // namespace

bool buildHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings, Hierarchy3D& out) {
    if (std::string problem; !validThresholds(settings.deltas, problem)) {
        out = Hierarchy3D{};  // nothing of an earlier result stays
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", problem});
        return false;
    }
    try {
        Baker baker(objects, settings, out);
        return baker.run();
    } catch (const std::exception& e) {
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", std::string("internal error: ") + e.what()});
        return false;
    }
}

}  // namespace aggrelod
