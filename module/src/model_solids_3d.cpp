// SPDX-License-Identifier: AGPL-3.0-or-later
// Solids for the models that are not valid closed solids (docs/design.md §2.0): the exact
// union of touching solids, an alpha wrap (CGAL Alpha_wrap_3, in solidify.cpp) or a convex
// hull; nested models wrapped last; stand-ins that reach into others merged; and the sampled
// two-sided distance of every solid to its originals.
#include "baker_3d.h"
#include "convex_hull.h"
#include "parallel_for.h"
#include "solidify.h"
#include "surface_shell.h"

#include <aggrelod/disjoint_sets.h>

#include <array>
#include <cfloat>

namespace aggrelod::detail {

namespace {

// Sample i of a surface (p, t) for the sampled distances: its vertices, then its triangles'
// centroids (c: 3 doubles).
void surfaceSample(const std::vector<double>& p, const std::vector<uint32_t>& t, size_t i, double* c) {
    const size_t vertices = p.size() / 3;
    if (i < vertices) {
        for (int k = 0; k < 3; ++k) c[k] = p[3 * i + k];
        return;
    }
    const uint32_t* f = &t[3 * (i - vertices)];
    for (int k = 0; k < 3; ++k) c[k] = (p[3 * f[0] + k] + p[3 * f[1] + k] + p[3 * f[2] + k]) / 3.0;
}

// Largest distance from the samples of (p, t) to the surface in `target`: a sampled
// one-sided Hausdorff distance, not certified (a point between samples may lie a little
// farther). A sample with some triangle within the largest distance so far cannot raise it
// and is skipped by a quick yes-or-no query (the result is the same as measuring every
// sample); on `threads` threads in blocks, each with its own largest so far.
double sampledDistance(const std::vector<double>& p, const std::vector<uint32_t>& t, const TriangleBvh& target,
                       int threads = 1) {
    const size_t samples = p.size() / 3 + t.size() / 3;
    const size_t blocks = threads > 1 ? std::min<size_t>(4 * size_t(threads), samples / 256 + 1) : 1;
    std::vector<double> worst(blocks, 0.0);
    parallelFor(blocks, threads, [&](size_t b) {
        double largest = 0;
        bool any = false;
        for (size_t i = samples * b / blocks; i < samples * (b + 1) / blocks; ++i) {
            double c[3];
            surfaceSample(p, t, i, c);
            if (any && anyWithin(target, c, largest)) continue;
            largest = std::max(largest, closestPoint(target, c).distance);
            any = true;
        }
        worst[b] = largest;
    });
    return *std::max_element(worst.begin(), worst.end());
}

// The share of the triangles' edges (each counted once per triangle) longer than `length`.
double edgesLongerThan(const std::vector<double>& p, const std::vector<uint32_t>& t, double length) {
    if (t.empty()) return 0;
    size_t longer = 0;
    for (size_t i = 0; i + 2 < t.size(); i += 3)
        for (int e = 0; e < 3; ++e) {
            const double* a = &p[3 * t[i + e]];
            const double* b = &p[3 * t[i + (e + 1) % 3]];
            const double d2 = (a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) + (a[2] - b[2]) * (a[2] - b[2]);
            longer += d2 > length * length;
        }
    return double(longer) / double(t.size());
}

// Whether sampledDistance(p, t, target) <= tolerance, stopping at the first sample farther.
bool sampledWithin(const std::vector<double>& p, const std::vector<uint32_t>& t, const TriangleBvh& target,
                   double tolerance) {
    for (size_t i = 0; i < p.size() / 3 + t.size() / 3; ++i) {
        double c[3];
        surfaceSample(p, t, i, c);
        if (!anyWithin(target, c, tolerance)) return false;
    }
    return true;
}

}  // namespace

// Sampled distances between each solid and its originals, both ways, and the same for the
// convex hull of the originals (for comparison): vertices and triangle centroids of one
// surface, closest point on the other (BVH). Not certified: a point between samples may lie
// a little farther.
void Baker3D::measureSolids() {
    std::vector<size_t> which;
    for (size_t m = 0; m < models_.size(); ++m)
        if (models_[m].standIn() && !models_[m].objects.empty()) which.push_back(m);
    if (which.empty()) return;
    timer_.begin("solid measures");
    // Fewer solids than threads (an engine wrapped whole): each measure uses its share of them.
    const int threads = settings_.threadCount > 0 ? settings_.threadCount : int(std::max(1u, std::thread::hardware_concurrency()));
    const int inner = std::max(1, threads / int(which.size()));
    const auto sampled = [inner](const std::vector<double>& p, const std::vector<uint32_t>& t, const TriangleBvh& target) {
        return sampledDistance(p, t, target, inner);
    };
    std::vector<SolidReport> reports(which.size());
    parallelFor(which.size(), settings_.threadCount, [&](size_t k) {
        const Model& m = models_[which[k]];
        SolidReport& r = reports[k];
        r.objects = m.objects;
        r.method = m.kind == Model::Kind::Union ? SolidifyMethod::Union
                   : m.kind == Model::Kind::Shell ? SolidifyMethod::Shell
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
        meshVolumeArea(m.positions, m.triangles, r.volumeSolid, area);
        TriangleBvh original;
        original.build(pts.data(), pts.size() / 3, tris.data(), tris.size() / 3);
        r.distanceSolidToOriginal = sampled(m.positions, m.triangles, original);
        r.distanceOriginalToSolid = sampled(pts, tris, m.bvh);
        // Closed and edge-manifold as a fresh check of the triangulator's input.
        r.closedManifold = checkedSurface(m.positions, m.triangles).validSolid();
        if (settings_.computeHullBaseline && r.method != SolidifyMethod::Hull) {
            std::vector<double> hp;
            std::vector<uint32_t> ht;
            if (convexHull3(pts, hp, ht)) {
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

// Objects that are valid solids alone but touch or cross each other: their exact union as
// the model's surface when it is one closed, edge-manifold shell that does not cross itself
// after rounding (the tightest solid: its surface lies on theirs). False leaves m unchanged.
bool Baker3D::uniteClosedParts(Model& m) const {
    // The union is one shell only if the parts hang together by surfaces that meet or by one
    // lying inside another; parts that only come near each other (spheres resting on each
    // other) give several shells whatever the corefinement does, and it is the costly step:
    // find that out first.
    {
        DisjointSets joined(m.objects.size());
        size_t pieces = m.objects.size();
        for (size_t a = 0; a < m.objects.size() && pieces > 1; ++a)
            for (size_t b = a + 1; b < m.objects.size() && pieces > 1; ++b) {
                const PreparedObject& pa = prepared_[m.objects[a]];
                const PreparedObject& pb = prepared_[m.objects[b]];
                if (!boxesOverlap(pa.bounds, pb.bounds, 0) || joined.find(a) == joined.find(b)) continue;
                bool together = meshDistance(objectBvh_[m.objects[a]], objectBvh_[m.objects[b]], 0.0, DBL_MIN).intersecting;
                if (!together) together = windingNumber(pb.positions, pb.triangles, &pa.positions[0]) > 0.5 ||
                                          windingNumber(pa.positions, pa.triangles, &pb.positions[0]) > 0.5;
                if (together && joined.unite(a, b)) --pieces;
            }
        if (pieces > 1) return false;
    }
    std::vector<const std::vector<double>*> positions;
    std::vector<const std::vector<uint32_t>*> triangles;
    for (uint32_t o : m.objects) {
        positions.push_back(&prepared_[o].positions);
        triangles.push_back(&prepared_[o].triangles);
    }
    std::vector<double> p;
    std::vector<uint32_t> t;
    std::string error;
    if (!exactUnion(positions, triangles, p, t, error)) return false;
    InputObject united;
    united.positions = std::move(p);
    united.indices = std::move(t);
    PreparedObject check;
    std::vector<Diagnostic> ignored;
    prepareObject(united, 0.0, check, ignored);
    if (!check.validSolid() || check.positions.size() != united.positions.size() ||
        check.triangles.size() != united.indices.size() || selfIntersects(check.positions, check.triangles))
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
double Baker3D::nearestGap(const Model& m, double limit) const {
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
            const ClosestPair cp = meshDistance(objectBvh_[o], objectBvh_[other], best);
            if (cp.distance < best) best = cp.distance;
        }
    }
    return best;
}

void Baker3D::solidifyModels(const std::vector<size_t>& which, const std::vector<std::string>& why) {
    if (which.empty()) return;
    const std::string stage = timer_.stage();  // resumed afterwards: solidifying is timed on its own
    timer_.begin("solidify");
    standInsChanged_ = true;
    modelsPrepared_ = false;
    distanceCache_.clear();
    std::vector<std::string> failure(which.size());
    std::vector<char> flat(which.size(), 0);
    std::vector<char> fellBack(which.size(), 0);
    std::vector<std::string> shellWhy(which.size());  // why a model of open surfaces was not thickened
    // Largest first (by input triangles): the two threads then finish together.
    std::vector<size_t> order(which.size()), load(which.size(), 0);
    std::iota(order.begin(), order.end(), size_t(0));
    for (size_t k = 0; k < which.size(); ++k)
        for (uint32_t o : models_[which[k]].objects) load[k] += prepared_[o].triangles.size();
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return load[a] > load[b]; });
    parallelFor(which.size(), settings_.threadCount, [&](size_t i) {
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
            // Models of open surfaces first try a larger alpha, kept when its sampled two-sided
            // distance to the originals is within 2 % of the diagonal (a failed try is a wasted
            // wrap). How much larger depends on the detail the larger ball would bridge: a
            // surface of large faces (three quarters of its edges longer than a third more
            // than alpha) has none, and tries a third more at about half the cost; a detailed
            // surface (windows, frames, eaves: edges shorter than alpha) tries a tenth more,
            // at 0.83 of the cost, where a third more fails more often than not. Assemblies
            // with closed parts are not tried: their hidden inner surfaces lie deep inside any
            // wrap, so the test could not pass.
            const bool allOpen = std::none_of(m.objects.begin(), m.objects.end(), [&](uint32_t o) { return prepared_[o].validSolid(); });
            // Open sheets (walls, floors, panels) are thickened first: the tightest solid and
            // the cheapest, when the surface allows it (no detail finer than the offset, no fold
            // sharper than 60 degrees, one fan of faces at every vertex, openings wider than
            // alpha: a wrap fills a nearly closed mesh where a shell would be a hollow skin).
            // Half the offset each side, so that no point of the shell lies farther than the
            // offset from the surface, as for a wrap.
            if (allOpen && size > 0) {
                if (thickenSurface(pts, tris, offset / 2, offset, alpha, m.positions, m.triangles, shellWhy[k])) {
                    PreparedObject check = checkedSurface(m.positions, m.triangles);
                    if (check.validSolid() && check.positions.size() == m.positions.size()) {
                        m.positions = std::move(check.positions);
                        m.triangles = std::move(check.triangles);
                        m.kind = Model::Kind::Shell;
                        m.alpha = 0;
                        m.offset = offset / 2;
                        return;
                    }
                    shellWhy[k] = "the shell is not a closed, consistently oriented solid";
                }
                m.positions.clear();
                m.triangles.clear();
            }
            std::vector<double> alphas;
            if (allOpen) alphas.push_back(alpha * (edgesLongerThan(pts, tris, alpha * 4.0 / 3.0) >= 0.75 ? 4.0 / 3.0 : 1.1));
            alphas.push_back(alpha);
            std::string error;
            TriangleBvh original;
            if (alphas.size() > 1) original.build(pts.data(), pts.size() / 3, tris.data(), tris.size() / 3);
            for (size_t a = 0; a < alphas.size() && size > 0; ++a) {
                const bool last = a + 1 == alphas.size();
                std::string attempt;
                if (!alphaWrap(pts, tris, alphas[a], offset, m.positions, m.triangles, attempt)) {
                    if (last) error = attempt;
                    continue;
                }
                // The wrap must be a valid solid piece of the triangulation's input.
                PreparedObject check = checkedSurface(m.positions, m.triangles);
                if (!check.validSolid() || check.positions.size() != m.positions.size()) {
                    if (last) error = "the wrap is not a closed, consistently oriented solid";
                    continue;
                }
                if (!last) {
                    TriangleBvh wrap;
                    wrap.build(check.positions.data(), check.positions.size() / 3, check.triangles.data(), check.triangles.size() / 3);
                    const double tolerance = 0.02 * size;
                    if (!sampledWithin(check.positions, check.triangles, original, tolerance) ||
                        !sampledWithin(pts, tris, wrap, tolerance))
                        continue;
                }
                m.positions = std::move(check.positions);
                m.triangles = std::move(check.triangles);
                m.kind = Model::Kind::Wrap;
                m.alpha = alphas[a];
                m.offset = offset;
                return;
            }
            failure[k] = error;
            m.positions.clear();
            m.triangles.clear();
            fellBack[k] = 1;
        }
        if (settings_.solidify == SolidifyMethod::Off) return;
        m.alpha = m.offset = 0;
        m.kind = Model::Kind::Hull;
        if (!convexHull3(pts, m.positions, m.triangles)) flat[k] = 1;
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
        else if (m.kind == Model::Kind::Shell)
            diag(out_, Diagnostic::Severity::Note, names,
                 why[k] + "; solidified by thickening its surface by " + fmt(m.offset) +
                     " on both sides for the triangulation");
        else if (m.kind == Model::Kind::Wrap)
            diag(out_, Diagnostic::Severity::Note, names,
                 why[k] + "; solidified by an alpha wrap (alpha " + fmt(m.alpha) + ", offset " + fmt(m.offset) +
                     ") for the triangulation" +
                     (shellWhy[k].empty() ? std::string() : " (not thickened: " + shellWhy[k] + ")"));
        else
            diag(out_, Diagnostic::Severity::Warning, names,
                 why[k] + (fellBack[k] ? "; alpha wrap failed (" + failure[k] + ")" : std::string()) +
                     "; stood in for by its convex hull in the triangulation");
    }
    if (!stage.empty() && stage != "solidify") timer_.begin(stage);
}

// A model to be wrapped whose box lies inside the box of another one (a spring in an engine)
// is often swallowed by that one's wrap, which then has to be wrapped again with it: its own
// wrap would be wasted. So the outer models are wrapped first; a nested model whose original
// surfaces all lie inside one of those wraps, apart from it, joins that model and keeps its
// wrap (a closed solid containing both); the others are wrapped after.
void Baker3D::solidifyNestedLast(const std::vector<size_t>& which, const std::vector<std::string>& why) {
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
    parallelFor(nested.size(), settings_.threadCount, [&](size_t k) {
        const Model& inner = models_[nested[k]];
        double b[6];
        objectsBounds(inner.objects, b);
        for (size_t f : first) {
            const Model& outer = models_[f];
            if (outer.kind == Model::Kind::Original || outer.kind == Model::Kind::Hull || outer.objects.empty()) continue;
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
                if (meshDistance(objectBvh_[o], wrapBvh, tolerance_, tolerance_).distance <= tolerance_) {
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
             nestedWhy[k] + "; inside the solid of " + objectNames(objects_, outer.objects) +
                 ": joins that model, whose solid stands for both");
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
bool Baker3D::resolveStandInOverlaps() {
    bool changed = false;
    standInsChanged_ = false;
    for (int round = 0; round < 64; ++round) {
        models_.erase(std::remove_if(models_.begin(), models_.end(), [](const Model& m) { return m.objects.empty(); }),
                      models_.end());
        parallelFor(models_.size(), settings_.threadCount, [&](size_t i) {
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
            bool joins = meshDistance(a.bvh, b.bvh, tolerance_, tolerance_).distance <= tolerance_;
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

}  // namespace aggrelod::detail
