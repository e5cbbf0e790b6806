// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: geometric error of a proxy against the original objects (docs/design.md §2.5,
// "Geometric error of a proxy"): both one-sided Hausdorff distances, with certified upper
// bounds.
//
// Directions:
// - proxy -> originals: h(p) = distance from a proxy point to the nearest original surface
//   (closest-point BVH query, mesh_distance.h);
// - originals -> proxy: h(p) = distance from an original point to the proxy *solid*: 0 when
//   the point is inside the proxy (an original surface buried in the aggregate's fill is
//   covered by it, not missing), else the distance to the proxy surface. Inside = odd number
//   of crossings of a ray, majority of three rays in fixed directions.
//
// Branch and bound (in the spirit of Tang et al., "Interactive Hausdorff distance computation
// for general polygonal models", SIGGRAPH 2009). Regions are triangles of the measured mesh
// (and their subdivisions) or, for originals -> proxy, boxes of the nodes of each original
// object's BVH (built once per object, shared by every node and level holding it). At a
// triangle region's centroid c, h(c) is a lower bound of the maximum. Upper bounds of h over
// a region (ball of radius rho around c holding it), the smallest that applies:
//   - h(c) + rho, as h is 1-Lipschitz; for the solid, max(0, rho - d(c)) when c is inside
//     (the signed distance is 1-Lipschitz too), so 0 when the ball lies inside;
//   - max over the corners v of dist(v, T), T the target triangle nearest to c: the distance
//     to one triangle is convex, so its maximum over the region is at a corner, and the
//     distance to the whole target is at most the distance to T;
//   - where proxy and originals share a surface but not its triangulation (a region then
//     straddles target edges, and the bounds above stay as large as the region):
//     planarPatches/patchBound (a flat patch of target triangles that tiles a convex
//     polygon), edgePairBound (T and the triangle across one of its edges forming a convex
//     quad) and vertexFanBound (the closed ring of triangles around a vertex of T tiling a
//     convex polygon) -- each proof at the function;
//   - 0 for originals -> proxy when c is inside and the region does not meet the proxy
//     surface (a connected set not crossing the surface stays inside);
//   - for a box region: h(centre) + half its diagonal, the corners' distance to the triangle
//     nearest the centre, or 0 / max(0, rho - d) when the centre is inside. Boxes give no
//     lower bound (their points are not original points); a box is split into its two
//     children, a leaf into its triangles, so originals deep inside the proxy or well within
//     the tolerance are dismissed a box at a time instead of a triangle at a time.
// The region with the largest upper bound is split (triangles into four at the edge
// midpoints) until every upper bound is within `tolerance` of the best lower bound or the
// evaluation limit (seeds + maxRefinementsPerDirection) is reached; the result is the
// largest upper bound left: never below the true Hausdorff distance (up to double rounding;
// the flat-patch allowance is part of the bound, not an assumption).
#include "proxy_error.h"
#include "vec3.h"

#include <aggrelod/hierarchy_nodes.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <queue>
#include <stdexcept>

namespace aggrelod {

double ProxyError::bound() const { return std::max(proxyToOriginals, originalsToProxy); }

namespace {

using detail::TriangleBvh;

/// A triangle mesh in doubles (positions 3 * n, indices 3 * t).
struct Mesh {
    std::vector<double> positions;
    std::vector<uint32_t> indices;
    const double* corner(size_t t, int k) const { return &positions[3 * size_t(indices[3 * t + k])]; }
    size_t triangleCount() const { return indices.size() / 3; }
};

/// Number of triangles of `bvh` crossed by the ray p + t d, t > 0 (Moller-Trumbore).
size_t crossings(const TriangleBvh& bvh, const double p[3], const double d[3]) {
    const auto& nodes = bvh.nodes();
    if (nodes.empty()) return 0;
    double inv[3];
    for (int k = 0; k < 3; ++k) inv[k] = 1.0 / d[k];
    size_t count = 0;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const TriangleBvh::Node& N = nodes[stack[--top]];
        double tmin = 0, tmax = INFINITY;
        for (int k = 0; k < 3; ++k) {
            double t0 = (N.lo[k] - p[k]) * inv[k], t1 = (N.hi[k] - p[k]) * inv[k];
            if (t0 > t1) std::swap(t0, t1);
            tmin = std::max(tmin, t0);
            tmax = std::min(tmax, t1);
        }
        if (tmin > tmax * (1 + 1e-12) + 1e-300) continue;
        if (N.count == 0) {
            if (top + 2 > 128) continue;  // cannot happen for a SAH tree of < 2^60 triangles
            stack[top++] = N.first;
            stack[top++] = N.first + 1;
            continue;
        }
        for (uint32_t i = 0; i < N.count; ++i) {
            const double* c = bvh.slotCorners(N.first + i);
            double e1[3], e2[3], s[3], q[3], h[3];
            for (int k = 0; k < 3; ++k) {
                e1[k] = c[3 + k] - c[k];
                e2[k] = c[6 + k] - c[k];
                s[k] = p[k] - c[k];
            }
            h[0] = d[1] * e2[2] - d[2] * e2[1];
            h[1] = d[2] * e2[0] - d[0] * e2[2];
            h[2] = d[0] * e2[1] - d[1] * e2[0];
            const double det = e1[0] * h[0] + e1[1] * h[1] + e1[2] * h[2];
            if (det == 0) continue;
            const double u = (s[0] * h[0] + s[1] * h[1] + s[2] * h[2]) / det;
            if (u < 0 || u > 1) continue;
            q[0] = s[1] * e1[2] - s[2] * e1[1];
            q[1] = s[2] * e1[0] - s[0] * e1[2];
            q[2] = s[0] * e1[1] - s[1] * e1[0];
            const double v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
            if (v < 0 || u + v > 1) continue;
            const double t = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
            if (t > 0) ++count;
        }
    }
    return count;
}

bool insideSolid(const TriangleBvh& bvh, const double p[3]) {
    // Three fixed, unrelated directions (unlikely to be parallel to modelled faces).
    static const double kDirections[3][3] = {
        {0.5773502691896258, 0.5773502691896257, 0.5773502691896259},
        {-0.2672612419124244, 0.8017837257372732, -0.5345224838248488},
        {0.8164965809277261, -0.4082482904638631, -0.4082482904638629}};
    const bool first = crossings(bvh, p, kDirections[0]) % 2 == 1;
    const bool second = crossings(bvh, p, kDirections[1]) % 2 == 1;
    if (first == second) return first;  // already the majority
    return crossings(bvh, p, kDirections[2]) % 2 == 1;
}


/// A target surface for the bounds: triangles (positions, indices) and the triangle
/// across each edge (trianglesAcrossEdges).
struct TargetMesh {
    const double* positions = nullptr;
    const uint32_t* indices = nullptr;
    const uint32_t* across = nullptr;
    const detail::PlanarPatches* patches = nullptr;
    const double* corner(uint32_t t, int k) const { return positions + 3 * size_t(indices[3 * size_t(t) + size_t(k)]); }
};

/// Nearest target triangle to a point.
struct Nearest {
    double distance = INFINITY;
    const TargetMesh* mesh = nullptr;  ///< null when the target is empty
    uint32_t triangle = ~0u;
};

inline void sub(const double* a, const double* b, double* r) {
    for (int k = 0; k < 3; ++k) r[k] = a[k] - b[k];
}
inline void cross3(const double* a, const double* b, double* r) {
    r[0] = a[1] * b[2] - a[2] * b[1];
    r[1] = a[2] * b[0] - a[0] * b[2];
    r[2] = a[0] * b[1] - a[1] * b[0];
}
inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline bool samePoint(const double* a, const double* b) { return a[0] == b[0] && a[1] == b[1] && a[2] == b[2]; }

/// max over `points` (n xyz triples) of the distance to triangle t: the distance to one
/// triangle is convex, so this bounds it over their convex hull.
double cornerBound(const TargetMesh& m, uint32_t t, const double* points, int n) {
    double worst = 0, q[3];
    for (int v = 0; v < n; ++v)
        worst = std::max(worst, detail::pointTriangleDistance(points + 3 * v, m.corner(t, 0), m.corner(t, 1), m.corner(t, 2), q));
    return worst;
}

/// Upper bound over the convex hull of `points` of the distance to the union of triangle t
/// and a triangle across one of its edges, for regions straddling a shared edge (where the
/// one-triangle bound stays as large as the region): t = (P, Q, R) with edge PQ shared with
/// U = (Q, P, o). When R and o project onto t's plane on opposite sides of PQ and P, Q on
/// opposite sides of Ro (a convex quad), every point of K = hull(P, Q, R, o) is within
/// w = |height of o over t's plane| of t or U (its projection lies in the projection of t
/// or of U; heights differ by at most w). So dist(p, t u U) <= dist(p, K) + w, convex
/// in p up to the constant, and dist(p, K) <= the distance to the nearest face of K (the
/// four triangles of P, Q, R, o). Returns the smallest such bound over t's edges (inf when
/// no edge qualifies).
double edgePairBound(const TargetMesh& m, uint32_t t, const double* points, int n) {
    double best = INFINITY;
    if (!m.across) return best;
    for (int e = 0; e < 3; ++e) {
        const uint32_t u = m.across[3 * size_t(t) + size_t(e)];
        if (u == ~0u) continue;
        const double* P = m.corner(t, e);
        const double* Q = m.corner(t, (e + 1) % 3);
        const double* R = m.corner(t, (e + 2) % 3);
        const double* o = nullptr;
        for (int k = 0; k < 3 && !o; ++k) {
            const double* c = m.corner(u, k);
            if (!samePoint(c, P) && !samePoint(c, Q)) o = c;
        }
        if (!o) continue;
        double pq[3], pr[3], po[3], nrm[3], tmp[3];
        sub(Q, P, pq);
        sub(R, P, pr);
        sub(o, P, po);
        cross3(pq, pr, nrm);
        const double nn = std::sqrt(dot3(nrm, nrm));
        if (!(nn > 0)) continue;
        cross3(pq, po, tmp);
        if (!(dot3(nrm, tmp) < 0)) continue;  // o on R's side of PQ (or on it): not a convex quad
        double ro[3], rp[3], rq[3], c1[3], c2[3];
        sub(o, R, ro);
        sub(P, R, rp);
        sub(Q, R, rq);
        cross3(ro, rp, c1);
        cross3(ro, rq, c2);
        if (!(dot3(nrm, c1) * dot3(nrm, c2) < 0)) continue;  // P, Q not strictly on both sides of Ro
        const double w = std::fabs(dot3(nrm, po)) / nn;
        if (!(w < best)) continue;
        double worst = 0, q[3];
        for (int v = 0; v < n && worst + w < best; ++v) {
            const double* p = points + 3 * v;
            double d = detail::pointTriangleDistance(p, P, Q, R, q);
            d = std::min(d, detail::pointTriangleDistance(p, Q, P, o, q));
            d = std::min(d, detail::pointTriangleDistance(p, R, P, o, q));
            d = std::min(d, detail::pointTriangleDistance(p, R, Q, o, q));
            worst = std::max(worst, d);
        }
        best = std::min(best, worst + w);
    }
    return best;
}

/// Upper bound over the convex hull of `points` of the distance to the triangles around a
/// vertex V of triangle t, for regions covering a vertex where many triangles meet (the
/// edge-pair bound needs a region straddling one edge only). Walks the closed ring of
/// triangles around V (across the edge leaving V); with n the unit normal of t, when every
/// ring triangle projects onto t's plane with positive orientation, once around V, and the
/// outer ring polygon is convex, the projections of the ring triangles tile the convex
/// polygon C of the outer ring. A point p whose projection lies in C projects onto the
/// projection of some ring point s, so |p - s| = |height(p) - height(s)| <= max(|height(p) -
/// hmin|, |height(p) - hmax|) (heights over t's plane; hmin, hmax over the ring's vertices).
/// That is convex in p and C is convex, so when every point projects into C the largest value
/// at them bounds the whole hull. Returns the smallest bound over t's corners (inf if none).
double vertexFanBound(const TargetMesh& m, uint32_t t, const double* points, int n) {
    double best = INFINITY;
    if (!m.across) return best;
    double nrm[3], e1[3], e2[3];
    sub(m.corner(t, 1), m.corner(t, 0), e1);
    sub(m.corner(t, 2), m.corner(t, 0), e2);
    cross3(e1, e2, nrm);
    const double nn = std::sqrt(dot3(nrm, nrm));
    if (!(nn > 0)) return best;
    for (int k = 0; k < 3; ++k) nrm[k] /= nn;
    constexpr int kMaxRing = 64;
    const double* ring[kMaxRing];
    for (int corner = 0; corner < 3; ++corner) {
        const double* V = m.corner(t, corner);
        int count = 0;
        uint32_t c = t;
        int j = corner;
        bool closed = false;
        double angle = 0;
        while (count < kMaxRing) {
            const double* a = m.corner(c, (j + 1) % 3);
            const double* b = m.corner(c, (j + 2) % 3);
            double va[3], vb[3], x[3];
            sub(a, V, va);
            sub(b, V, vb);
            cross3(va, vb, x);
            const double orient = dot3(nrm, x);
            if (!(orient > 0)) break;  // folded or degenerate in projection
            angle += std::atan2(orient, dot3(va, vb) - dot3(nrm, va) * dot3(nrm, vb));
            ring[count++] = a;
            const uint32_t next = m.across[3 * size_t(c) + size_t(j)];  // across edge V -> a
            if (next == ~0u) break;
            if (next == t) {
                closed = true;
                break;
            }
            int jn = -1;
            for (int q = 0; q < 3; ++q)
                if (samePoint(m.corner(next, q), V)) jn = q;
            if (jn < 0 || !samePoint(m.corner(next, (jn + 2) % 3), a)) break;  // not consistently oriented
            c = next;
            j = jn;
        }
        if (!closed || count < 3 || std::fabs(angle - 2 * M_PI) > 1e-6) continue;
        std::reverse(ring, ring + count);  // the walk goes clockwise around V
        // Outer polygon convex (every turn to the left, seen along n).
        bool convex = true;
        for (int i = 0; i < count && convex; ++i) {
            double u[3], w[3], x[3];
            sub(ring[(i + 1) % count], ring[i], u);
            sub(ring[(i + 2) % count], ring[(i + 1) % count], w);
            cross3(u, w, x);
            convex = dot3(nrm, x) > 0;
        }
        if (!convex) continue;
        double hmin = 0, hmax = 0;  // V itself has height 0
        for (int i = 0; i < count; ++i) {
            double r[3];
            sub(ring[i], V, r);
            const double h = dot3(nrm, r);
            hmin = std::min(hmin, h);
            hmax = std::max(hmax, h);
        }
        double worst = 0;
        for (int v = 0; v < n && worst < best; ++v) {
            const double* p = points + 3 * v;
            for (int i = 0; i < count; ++i) {  // projection inside C
                double u[3], w[3], x[3];
                sub(ring[(i + 1) % count], ring[i], u);
                sub(p, ring[i], w);
                cross3(u, w, x);
                if (dot3(nrm, x) < 0) {
                    worst = INFINITY;
                    break;
                }
            }
            double r[3];
            sub(p, V, r);
            const double h = dot3(nrm, r);
            worst = std::max(worst, std::max(std::fabs(h - hmin), std::fabs(h - hmax)));
        }
        best = std::min(best, worst);
    }
    return best;
}

/// Upper bound over the convex hull of `points` of the distance to the planar patch of
/// triangle t (detail::PlanarPatches): when every point projects (along the patch normal)
/// into the patch polygon C, a point p has a patch point s with |proj(p) - proj(s)| <= slack
/// and heights within the patch's range, so |p - s| <= slack + max(|h(p) - hmin|, |h(p) -
/// hmax|), convex in p. Inf when t has no patch or a point projects outside C.
double patchBound(const TargetMesh& m, uint32_t t, const double* points, int n) {
    if (!m.patches) return INFINITY;
    const uint32_t id = m.patches->patchOf[t];
    if (id == ~0u) return INFINITY;
    const detail::PlanarPatches::Patch& P = m.patches->patches[id];
    const double* const* loop = m.patches->loops.data() + P.loopBegin;
    const uint32_t count = P.loopEnd - P.loopBegin;
    double worst = 0;
    for (int v = 0; v < n; ++v) {
        const double* p = points + 3 * v;
        for (uint32_t i = 0; i < count; ++i) {
            double u[3], w[3], x[3];
            sub(loop[(i + 1) % count], loop[i], u);
            sub(p, loop[i], w);
            cross3(u, w, x);
            if (dot3(P.normal, x) < 0) return INFINITY;
        }
        double r[3];
        sub(p, P.origin, r);
        const double h = dot3(P.normal, r);
        worst = std::max(worst, std::max(std::fabs(h - P.hmin), std::fabs(h - P.hmax)));
    }
    return worst + P.slack;
}

/// True when triangle `tri` (9 doubles) comes within `margin` of a triangle of `bvh`.
bool touchesMesh(const TriangleBvh& bvh, const double* tri, double margin) {
    const auto& nodes = bvh.nodes();
    if (nodes.empty()) return false;
    double lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(tri[k], std::min(tri[3 + k], tri[6 + k])) - margin;
        hi[k] = std::max(tri[k], std::max(tri[3 + k], tri[6 + k])) + margin;
    }
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const TriangleBvh::Node& N = nodes[stack[--top]];
        bool overlap = true;
        for (int k = 0; k < 3; ++k) overlap = overlap && N.lo[k] <= hi[k] && N.hi[k] >= lo[k];
        if (!overlap) continue;
        if (N.count == 0) {
            if (top + 2 > 128) return true;  // too deep to tell: assume it touches
            stack[top++] = N.first;
            stack[top++] = N.first + 1;
            continue;
        }
        for (uint32_t i = 0; i < N.count; ++i) {
            const double* c = bvh.slotCorners(N.first + i);
            if (detail::triangleTriangleDistance(tri, tri + 3, tri + 6, c, c + 3, c + 6, nullptr, nullptr, nullptr) <= margin)
                return true;
        }
    }
    return false;
}

/// The proxy as a target: its surface (closest point) and its solid (ray parity).
struct ProxyTarget {
    const TriangleBvh& bvh;
    TargetMesh mesh;
    /// `hint`: an upper bound of the distance (prunes the search); when rounding makes it
    /// miss, the search runs again without it.
    Nearest closest(const double p[3], double hint) const {
        detail::ClosestPoint cp = detail::closestPoint(bvh, p, hint);
        if (cp.triangle == ~0u && hint < INFINITY) cp = detail::closestPoint(bvh, p);
        Nearest r;
        r.distance = cp.distance;
        if (cp.triangle != ~0u) {
            r.mesh = &mesh;
            r.triangle = cp.triangle;
        }
        return r;
    }
    bool inside(const double p[3]) const { return insideSolid(bvh, p); }
    double convexCornerBound(const TargetMesh*, const double*, int) const { return INFINITY; }
    /// A region triangle that does not meet the surface lies on one side of it.
    bool touches(const double* tri) const { return touchesMesh(bvh, tri, 1e-9 * bvh.maxAbsCoordinate()); }
};

double pointBoxDistance(const double p[3], const double lo[3], const double hi[3]) {
    double s = 0;
    for (int k = 0; k < 3; ++k) {
        const double d = p[k] < lo[k] ? lo[k] - p[k] : (p[k] > hi[k] ? p[k] - hi[k] : 0.0);
        s += d * d;
    }
    return std::sqrt(s);
}

/// The original objects as a target: their surfaces, one prepared BVH per object (shared by
/// every node holding the object), under a small tree of the objects' boxes built per node.
/// Nearest child box first, boxes farther than the best distance so far pruned; the
/// traversal order is fixed, so ties are resolved the same way on every run.
struct OriginalsTarget {
    struct Node {
        double lo[3], hi[3];
        uint32_t first, count;  ///< leaf: objects order[first, first + count); inner: children first, first + 1
    };
    const std::vector<const detail::PreparedOriginal*>& objects;
    std::vector<std::array<double, 6>> boxes;  // lo, hi per object
    std::vector<TargetMesh> meshes;
    std::vector<Node> nodes;
    std::vector<uint32_t> order;

    explicit OriginalsTarget(const std::vector<const detail::PreparedOriginal*>& o)
        : objects(o), boxes(o.size()), meshes(o.size()) {
        for (size_t i = 0; i < o.size(); ++i) {
            o[i]->bvh.bounds(boxes[i].data(), boxes[i].data() + 3);
            meshes[i] = TargetMesh{o[i]->object->positions.data(), o[i]->object->indices.data(), o[i]->across.data(),
                                   &o[i]->patches};
            if (o[i]->bvh.triangleCount() > 0) order.push_back(uint32_t(i));
        }
        if (order.empty()) return;
        nodes.reserve(2 * order.size());
        nodes.push_back(Node{});
        build(0, 0, uint32_t(order.size()));
    }
    void build(uint32_t node, uint32_t begin, uint32_t end) {
        Node n;
        for (int k = 0; k < 3; ++k) {
            n.lo[k] = INFINITY;
            n.hi[k] = -INFINITY;
        }
        for (uint32_t i = begin; i < end; ++i)
            for (int k = 0; k < 3; ++k) {
                n.lo[k] = std::min(n.lo[k], boxes[order[i]][size_t(k)]);
                n.hi[k] = std::max(n.hi[k], boxes[order[i]][size_t(3 + k)]);
            }
        if (end - begin <= 4) {
            n.first = begin;
            n.count = end - begin;
            nodes[node] = n;
            return;
        }
        int axis = 0;
        for (int k = 1; k < 3; ++k)
            if (n.hi[k] - n.lo[k] > n.hi[axis] - n.lo[axis]) axis = k;
        auto centre = [&](uint32_t i) { return boxes[i][size_t(axis)] + boxes[i][size_t(3 + axis)]; };
        std::sort(order.begin() + begin, order.begin() + end, [&](uint32_t x, uint32_t y) {
            return centre(x) != centre(y) ? centre(x) < centre(y) : x < y;
        });
        const uint32_t mid = begin + (end - begin) / 2;
        n.first = uint32_t(nodes.size());
        n.count = 0;
        nodes[node] = n;
        nodes.push_back(Node{});
        nodes.push_back(Node{});
        build(n.first, begin, mid);
        build(n.first + 1, mid, end);
    }
    Nearest closest(const double p[3], double hint) const {
        Nearest r = closestWithin(p, hint);
        if (!r.mesh && hint < INFINITY) r = closestWithin(p, INFINITY);
        return r;
    }
    Nearest closestWithin(const double p[3], double maxDistance) const {
        Nearest r;
        r.distance = maxDistance;
        if (nodes.empty()) return r;
        struct Item {
            uint32_t node;
            double distance;
        };
        Item stack[64];
        int top = 0;
        stack[top++] = {0, pointBoxDistance(p, nodes[0].lo, nodes[0].hi)};
        while (top > 0) {
            const Item it = stack[--top];
            if (it.distance > r.distance) continue;
            const Node& N = nodes[it.node];
            if (N.count > 0) {
                for (uint32_t j = N.first; j < N.first + N.count; ++j) {
                    const uint32_t i = order[j];
                    if (pointBoxDistance(p, boxes[i].data(), boxes[i].data() + 3) > r.distance) continue;
                    const detail::ClosestPoint cp = detail::closestPoint(objects[i]->bvh, p, r.distance);
                    if (cp.triangle == ~0u || !(cp.distance < r.distance || (!r.mesh && cp.distance == r.distance))) continue;
                    r.distance = cp.distance;
                    r.mesh = &meshes[i];
                    r.triangle = cp.triangle;
                }
                continue;
            }
            Item a{N.first, pointBoxDistance(p, nodes[N.first].lo, nodes[N.first].hi)};
            Item b{N.first + 1, pointBoxDistance(p, nodes[N.first + 1].lo, nodes[N.first + 1].hi)};
            if (b.distance < a.distance) std::swap(a, b);
            // Median splits: depth <= 33 for < 2^32 objects, so the stack never overflows.
            if (top + 2 > 64) throw std::logic_error("OriginalsTarget: tree too deep");
            stack[top++] = b;
            stack[top++] = a;
        }
        return r;
    }
    bool inside(const double*) const { return false; }  // never asked: the originals are surfaces
    bool touches(const double*) const { return true; }
    /// For a region outside every original (an enclosure), when `mesh` is the surface of a
    /// convex solid K (PreparedOriginal::convexSolid): the largest distance from its n corners
    /// to K bounds the distance to K over the whole region (convex function), so to the
    /// originals. INFINITY for other objects.
    double convexCornerBound(const TargetMesh* mesh, const double* corners, int n) const {
        const size_t i = size_t(mesh - meshes.data());
        if (i >= objects.size() || !objects[i]->convexSolid) return INFINITY;
        double worst = 0;
        for (int v = 0; v < n; ++v) {
            // A corner with the surface within the largest distance so far cannot raise it.
            if (v > 0 && detail::anyWithin(objects[i]->bvh, corners + 3 * v, worst)) continue;
            worst = std::max(worst, detail::closestPoint(objects[i]->bvh, corners + 3 * v).distance);
        }
        return worst + 2 * objects[i]->convexSlack;
    }
};

/// One region of the branch and bound: a triangle (corners), or the box of a node of an
/// original object's BVH (everything below it, not yet split into triangles).
struct Region {
    std::array<double, 9> corners;  ///< triangle regions
    uint32_t object = ~0u;          ///< box regions: index in the originals ...
    uint32_t node = 0;              ///< ... and node of its BVH
    double upper;
    double surfaceUpper;  ///< upper bound of the distance to the target surface (search hint for the parts)
    uint64_t order;  ///< creation order: a full tie-break, so the refinement is deterministic
    uint32_t root = ~0u;  ///< triangle regions: the seed triangle it lies in
};
struct LowerUpperFirst {
    bool operator()(const Region& a, const Region& b) const {
        return a.upper != b.upper ? a.upper < b.upper : a.order > b.order;
    }
};

struct DirectionResult {
    double lower = 0, upper = 0;
    size_t evaluations = 0;
};

/// Max over a surface of h (distance to `target`'s surface, or to its solid when toSolid),
/// within `tolerance`. The surface is given as seed regions (evaluateTriangle /
/// evaluateBox); run() splits the region with the largest upper bound (a box into its two
/// children, a BVH leaf into its triangles, a triangle into four) until every upper bound
/// is within `tolerance` of the best lower bound or the evaluation limit is reached.
template <class Target>
class BranchAndBound {
public:
    /// outsideSlack >= 0: every region point lies outside the target's solids or within this
    /// distance of outside (an enclosure measured against its originals), which allows the
    /// convex-solid corner bound; < 0: unknown.
    BranchAndBound(const Target& target, bool toSolid, double tolerance,
                   const std::vector<const detail::PreparedOriginal*>* boxSources, double outsideSlack = -1)
        : target_(target), toSolid_(toSolid), tolerance_(tolerance), boxSources_(boxSources), outsideSlack_(outsideSlack) {}

    /// Triangle region: h at its centroid is a lower bound; upper bound in the file comment
    /// (plus edgePairBound where the one-triangle bound does not settle the region).
    void evaluateTriangle(const std::array<double, 9>& c, double hint = INFINITY, uint32_t root = ~0u) {
        ++r_.evaluations;
        double centroid[3], rho = 0;
        for (int k = 0; k < 3; ++k) centroid[k] = (c[k] + c[3 + k] + c[6 + k]) / 3;
        for (int v = 0; v < 3; ++v) {
            const double dx = c[3 * v] - centroid[0], dy = c[3 * v + 1] - centroid[1], dz = c[3 * v + 2] - centroid[2];
            rho = std::max(rho, std::sqrt(dx * dx + dy * dy + dz * dz));
        }
        const Nearest near = target_.closest(centroid, hint);
        const double d = near.distance;
        double upper = d + rho;
        if (near.mesh) upper = std::min(upper, cornerBound(*near.mesh, near.triangle, c.data(), 3));
        double surfaceUpper = upper;
        double h = d;
        if (toSolid_ && (d > r_.lower || upper > r_.lower + tolerance_) && target_.inside(centroid)) {
            h = 0;
            // The signed distance (minus d here) is 1-Lipschitz too: 0 when the ball lies
            // inside the solid.
            upper = std::min(upper, std::max(0.0, rho - d));
            // Inside at the centroid and not meeting the surface: inside throughout.
            if (upper > r_.lower + tolerance_ && !target_.touches(c.data())) upper = 0;
        }
        r_.lower = std::max(r_.lower, h);
        if (root < rootLower_.size()) rootLower_[root] = std::max(rootLower_[root], h);
        // Bounds of the distance to the surface, so of the distance to the solid as well.
        if (near.mesh && upper > r_.lower + tolerance_) {
            surfaceUpper = std::min(surfaceUpper, patchBound(*near.mesh, near.triangle, c.data(), 3));
            upper = std::min(upper, surfaceUpper);
        }
        if (near.mesh && upper > r_.lower + tolerance_) {
            surfaceUpper = std::min(surfaceUpper, edgePairBound(*near.mesh, near.triangle, c.data(), 3));
            upper = std::min(upper, surfaceUpper);
        }
        if (near.mesh && upper > r_.lower + tolerance_) {
            surfaceUpper = std::min(surfaceUpper, vertexFanBound(*near.mesh, near.triangle, c.data(), 3));
            upper = std::min(upper, surfaceUpper);
        }
        if (near.mesh && outsideSlack_ >= 0 && upper > r_.lower + tolerance_) {
            // Points within the slack inside a solid are within it of its surface.
            const double convex = std::max(target_.convexCornerBound(near.mesh, c.data(), 3), outsideSlack_);
            surfaceUpper = std::min(surfaceUpper, convex);
            upper = std::min(upper, surfaceUpper);
        }
        keepTriangle(c, upper, surfaceUpper, root);
    }

    /// Seeds are the triangles 0..count-1 of a mesh: per seed, the largest bound of its parts
    /// and the largest distance found in it are tracked (rootBounds).
    void trackSeeds(size_t count) {
        rootLower_.assign(count, 0.0);
        rootUpper_.assign(count, 0.0);
    }

    /// Seed triangle `root` whose bound and a distance found in it are known already (an
    /// earlier measurement of the same triangle against the same target): not evaluated.
    void seedKnown(const std::array<double, 9>& c, uint32_t root, double upper, double lower) {
        r_.lower = std::max(r_.lower, lower);
        rootLower_[root] = std::max(rootLower_[root], lower);
        keepTriangle(c, upper, upper, root);
    }

    /// After run(): per seed, a certified upper bound of h over it and the largest h found in it.
    void rootBounds(std::vector<double>& upper, std::vector<double>& lower) const {
        upper = rootUpper_;
        lower = rootLower_;
    }

    /// Box of node `node` of the BVH of (*boxSources)[object]: none of its points is an
    /// original point, so it gives no lower bound, only an upper bound over the ball around
    /// its centre holding it (radius = half its diagonal): h(centre) + radius; or the
    /// largest distance from its eight corners to the target triangle nearest the centre
    /// (convexity, as for triangles); or 0 when the centre is inside the solid and the ball
    /// misses its surface.
    void evaluateBox(uint32_t object, uint32_t node, double hint = INFINITY) {
        ++r_.evaluations;
        const TriangleBvh::Node& N = (*boxSources_)[object]->bvh.nodes()[node];
        double centre[3], rho2 = 0;
        for (int k = 0; k < 3; ++k) {
            centre[k] = 0.5 * (N.lo[k] + N.hi[k]);
            const double half = std::max(N.hi[k] - centre[k], centre[k] - N.lo[k]);
            rho2 += half * half;
        }
        const double rho = std::sqrt(rho2);
        const Nearest near = target_.closest(centre, hint);
        const double d = near.distance;
        double upper = d + rho;
        if (near.mesh && upper > r_.lower + tolerance_) {
            double corners[24];
            for (int i = 0; i < 8; ++i) {
                corners[3 * i] = (i & 1) ? N.hi[0] : N.lo[0];
                corners[3 * i + 1] = (i & 2) ? N.hi[1] : N.lo[1];
                corners[3 * i + 2] = (i & 4) ? N.hi[2] : N.lo[2];
            }
            upper = std::min(upper, cornerBound(*near.mesh, near.triangle, corners, 8));
        }
        const double surfaceUpper = upper;
        if (toSolid_ && upper > r_.lower + tolerance_ && target_.inside(centre))
            upper = std::min(upper, std::max(0.0, rho - d));  // signed distance -d at the centre
        Region g;
        g.object = object;
        g.node = node;
        g.upper = upper;
        g.surfaceUpper = surfaceUpper;
        keepOrDismiss(g);
    }

    /// Refines until the bound is within the tolerance of the distance found, the limit is
    /// spent, or the distance found exceeds giveUpAbove (the answer is then "over it").
    DirectionResult run(size_t evaluationLimit, double giveUpAbove = INFINITY) {
        while (!open_.empty() && open_.top().upper > r_.lower + tolerance_ && r_.evaluations + 4 <= evaluationLimit &&
               !(r_.lower > giveUpAbove)) {
            const Region g = open_.top();
            open_.pop();
            // Every part lies in the region: its distance to the surface is below the region's
            // bound (a margin for rounding; a miss only costs a second search).
            const double hint = g.surfaceUpper * (1 + 1e-9) + 1e-300;
            if (g.object != ~0u) {
                const TriangleBvh& bvh = (*boxSources_)[g.object]->bvh;
                const TriangleBvh::Node& N = bvh.nodes()[g.node];
                if (N.count == 0) {
                    evaluateBox(g.object, N.first, hint);
                    evaluateBox(g.object, N.first + 1, hint);
                } else {
                    for (uint32_t i = 0; i < N.count; ++i) {
                        std::array<double, 9> c;
                        std::copy(bvh.slotCorners(N.first + i), bvh.slotCorners(N.first + i) + 9, c.begin());
                        evaluateTriangle(c, hint);
                    }
                }
                continue;
            }
            const double* c = g.corners.data();
            double m[3][3];  // edge midpoints 01, 12, 20
            for (int k = 0; k < 3; ++k) {
                m[0][k] = 0.5 * (c[k] + c[3 + k]);
                m[1][k] = 0.5 * (c[3 + k] + c[6 + k]);
                m[2][k] = 0.5 * (c[6 + k] + c[k]);
            }
            auto tri = [](const double* p, const double* q, const double* s) {
                return std::array<double, 9>{p[0], p[1], p[2], q[0], q[1], q[2], s[0], s[1], s[2]};
            };
            evaluateTriangle(tri(c, m[0], m[2]), hint, g.root);
            evaluateTriangle(tri(m[0], c + 3, m[1]), hint, g.root);
            evaluateTriangle(tri(m[2], m[1], c + 6), hint, g.root);
            evaluateTriangle(tri(m[0], m[1], m[2]), hint, g.root);
        }
        // What is left open keeps its upper bound.
        while (!open_.empty()) {
            r_.upper = std::max(r_.upper, open_.top().upper);
            noteRootUpper(open_.top());
            open_.pop();
        }
        r_.upper = std::max(r_.upper, r_.lower);
        return r_;
    }

private:
    void keepTriangle(const std::array<double, 9>& c, double upper, double surfaceUpper, uint32_t root) {
        Region g;
        g.corners = c;
        g.upper = upper;
        g.surfaceUpper = surfaceUpper;
        g.root = root;
        keepOrDismiss(g);
    }
    void keepOrDismiss(Region& g) {
        g.order = order_++;
        if (g.upper > r_.lower + tolerance_) {
            open_.push(g);
        } else {
            r_.upper = std::max(r_.upper, g.upper);
            noteRootUpper(g);
        }
    }
    void noteRootUpper(const Region& g) {
        if (g.root != ~0u && g.root < rootUpper_.size()) rootUpper_[g.root] = std::max(rootUpper_[g.root], g.upper);
    }

    const Target& target_;
    bool toSolid_;
    double tolerance_;
    const std::vector<const detail::PreparedOriginal*>* boxSources_;
    double outsideSlack_;
    DirectionResult r_;
    std::priority_queue<Region, std::vector<Region>, LowerUpperFirst> open_;
    uint64_t order_ = 0;
    std::vector<double> rootLower_, rootUpper_;  ///< per seed triangle (trackSeeds)
};

}  // namespace

namespace detail {

std::vector<uint32_t> trianglesAcrossEdges(const double* positions, const uint32_t* indices, size_t triangleCount) {
    struct Edge {
        const double* a;  // lexicographically smaller end
        const double* b;
        uint32_t triangle;
    };
    auto less = [](const double* x, const double* y) {
        return x[0] != y[0] ? x[0] < y[0] : x[1] != y[1] ? x[1] < y[1] : x[2] < y[2];
    };
    std::vector<Edge> edges;
    edges.reserve(3 * triangleCount);
    for (size_t t = 0; t < triangleCount; ++t)
        for (int k = 0; k < 3; ++k) {
            const double* a = positions + 3 * size_t(indices[3 * t + size_t(k)]);
            const double* b = positions + 3 * size_t(indices[3 * t + size_t((k + 1) % 3)]);
            if (less(b, a)) std::swap(a, b);
            edges.push_back({a, b, uint32_t(t)});
        }
    // Full order (ends, then triangle): deterministic groups.
    auto key = [&](const Edge& x, const Edge& y) {
        if (less(x.a, y.a)) return true;
        if (less(y.a, x.a)) return false;
        if (less(x.b, y.b)) return true;
        if (less(y.b, x.b)) return false;
        return x.triangle < y.triangle;
    };
    std::vector<uint32_t> order(edges.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = uint32_t(i);
    std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
        return key(edges[x], edges[y]) || (!key(edges[y], edges[x]) && x < y);
    });
    std::vector<uint32_t> across(3 * triangleCount, ~0u);
    for (size_t begin = 0; begin < order.size();) {
        size_t end = begin + 1;
        const Edge& first = edges[order[begin]];
        while (end < order.size() && samePoint(edges[order[end]].a, first.a) && samePoint(edges[order[end]].b, first.b)) ++end;
        // Within the group, triangles ascend: the lowest other one is the first or the second.
        for (size_t i = begin; i < end; ++i) {
            const uint32_t self = edges[order[i]].triangle;
            for (size_t j = begin; j < end; ++j)
                if (edges[order[j]].triangle != self) {
                    across[order[i]] = edges[order[j]].triangle;
                    break;
                }
        }
        begin = end;
    }
    return across;
}

PlanarPatches planarPatches(const double* positions, const uint32_t* indices, const uint32_t* across,
                            size_t triangleCount) {
    PlanarPatches out;
    out.patchOf.assign(triangleCount, ~0u);
    if (triangleCount == 0) return out;
    auto corner = [&](size_t t, int k) { return positions + 3 * size_t(indices[3 * t + size_t(k)]); };
    // Flatness allowance: float rounding of the coordinates (inputs are often floats).
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY}, maxAbs = 0;
    for (size_t i = 0; i < 3 * triangleCount; ++i) {
        const double* v = positions + 3 * size_t(indices[i]);
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], v[k]);
            hi[k] = std::max(hi[k], v[k]);
            maxAbs = std::max(maxAbs, std::fabs(v[k]));
        }
    }
    const double diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    const double flatness = 1e-6 * (diagonal + maxAbs);
    std::vector<uint32_t> group(triangleCount, ~0u);
    std::vector<uint32_t> members;
    constexpr size_t kMaxBoundary = 256;
    for (size_t seed = 0; seed < triangleCount; ++seed) {
        if (group[seed] != ~0u) continue;
        group[seed] = uint32_t(seed);
        double e1[3], e2[3], nrm[3];
        sub(corner(seed, 1), corner(seed, 0), e1);
        sub(corner(seed, 2), corner(seed, 0), e2);
        cross3(e1, e2, nrm);
        const double nn = std::sqrt(dot3(nrm, nrm));
        if (!(nn > 0)) continue;
        for (int k = 0; k < 3; ++k) nrm[k] /= nn;
        const double* origin = corner(seed, 0);
        auto height = [&](const double* x) {
            double r[3];
            sub(x, origin, r);
            return dot3(nrm, r);
        };
        auto positive = [&](size_t t) {
            double a[3], b[3], x[3];
            sub(corner(t, 1), corner(t, 0), a);
            sub(corner(t, 2), corner(t, 0), b);
            cross3(a, b, x);
            return dot3(nrm, x) > 0;
        };
        // Grow across edges (breadth first, fixed order) while the triangles stay flat,
        // positively oriented and consistently connected (the edge reversed in the other).
        members.assign(1, uint32_t(seed));
        bool valid = positive(seed);
        for (size_t i = 0; i < members.size(); ++i) {
            const uint32_t c = members[i];
            for (int e = 0; e < 3; ++e) {
                const uint32_t u = across[3 * size_t(c) + size_t(e)];
                if (u == ~0u || group[u] != ~0u) continue;
                bool flat = true;
                for (int k = 0; k < 3; ++k) flat = flat && std::fabs(height(corner(u, k))) <= flatness;
                if (!flat || !positive(u)) continue;
                group[u] = uint32_t(seed);
                members.push_back(u);
            }
        }
        if (!valid || members.size() < 2) continue;
        // Boundary chain: edges whose triangle across is outside the patch; an inner edge
        // must be matched both ways (manifold, consistently oriented).
        std::vector<std::pair<const double*, const double*>> boundary;
        double hmin = 0, hmax = 0;
        for (uint32_t c : members) {
            for (int e = 0; e < 3 && valid; ++e) {
                const double* a = corner(c, e);
                const double* b = corner(c, (e + 1) % 3);
                hmin = std::min(hmin, height(a));
                hmax = std::max(hmax, height(a));
                const uint32_t u = across[3 * size_t(c) + size_t(e)];
                if (u != ~0u && group[u] == uint32_t(seed)) {
                    bool matched = false;
                    for (int f = 0; f < 3; ++f)
                        if (across[3 * size_t(u) + size_t(f)] == c && samePoint(corner(u, f), b) &&
                            samePoint(corner(u, (f + 1) % 3), a))
                            matched = true;
                    valid = matched;
                } else {
                    boundary.emplace_back(a, b);
                    valid = boundary.size() <= kMaxBoundary;
                }
            }
        }
        if (!valid || boundary.size() < 3) continue;
        // One closed loop through every boundary edge.
        std::vector<const double*> chain;
        std::vector<bool> used(boundary.size(), false);
        size_t at = 0;
        for (size_t step = 0; step < boundary.size() && valid; ++step) {
            used[at] = true;
            chain.push_back(boundary[at].first);
            const double* end = boundary[at].second;
            size_t next = boundary.size();
            for (size_t j = 0; j < boundary.size(); ++j)
                if (samePoint(boundary[j].first, end)) {
                    if (next != boundary.size()) valid = false;  // two ways on: not a simple loop
                    next = j;
                }
            if (next == boundary.size()) valid = false;
            else if (step + 1 < boundary.size()) valid = valid && !used[next];
            else valid = valid && next == 0;
            at = next;
        }
        if (!valid) continue;
        // Convex: no right turn beyond rounding; nearly straight corners dropped (the kept
        // polygon then lies within `slack` of the chain).
        const size_t k = chain.size();
        std::vector<bool> keep(k, true);
        for (size_t i = 0; i < k && valid; ++i) {
            double u[3], w[3], x[3];
            sub(chain[i], chain[(i + k - 1) % k], u);
            sub(chain[(i + 1) % k], chain[i], w);
            cross3(u, w, x);
            const double turn = dot3(nrm, x), scale = std::sqrt(dot3(u, u) * dot3(w, w));
            if (turn <= 1e-6 * scale) keep[i] = false;
            if (turn < -1e-6 * scale) valid = false;
        }
        std::vector<const double*> polygon;
        for (size_t i = 0; i < k; ++i)
            if (keep[i]) polygon.push_back(chain[i]);
        if (!valid || polygon.size() < 3) continue;
        double slack = 0, turning = 0;
        for (size_t i = 0, kept = 0; i < k; ++i) {
            if (keep[i]) {
                ++kept;
                continue;
            }
            // Dropped corner: its distance to the kept edge spanning it.
            const double* a = polygon[(kept + polygon.size() - 1) % polygon.size()];
            const double* b = polygon[kept % polygon.size()];
            double q[3];
            slack = std::max(slack, segmentSegmentDistance(chain[i], chain[i], a, b, q, q));
        }
        const size_t m = polygon.size();
        for (size_t i = 0; i < m && valid; ++i) {
            double u[3], w[3], x[3];
            sub(polygon[i], polygon[(i + m - 1) % m], u);
            sub(polygon[(i + 1) % m], polygon[i], w);
            cross3(u, w, x);
            const double turn = dot3(nrm, x);
            valid = turn > 0;
            turning += std::atan2(turn, dot3(u, w) - dot3(nrm, u) * dot3(nrm, w));
        }
        if (!valid || std::fabs(turning - 2 * M_PI) > 1e-6) continue;  // winds once
        PlanarPatches::Patch patch;
        for (int j = 0; j < 3; ++j) patch.normal[j] = nrm[j];
        patch.origin = origin;
        patch.hmin = hmin;
        patch.hmax = hmax;
        patch.slack = slack;
        patch.loopBegin = uint32_t(out.loops.size());
        out.loops.insert(out.loops.end(), polygon.begin(), polygon.end());
        patch.loopEnd = uint32_t(out.loops.size());
        for (uint32_t c : members) out.patchOf[c] = uint32_t(out.patches.size());
        out.patches.push_back(patch);
    }
    return out;
}

namespace {

/// Whether a triangle mesh (positions 3 * n, indices 3 * m, across as trianglesAcrossEdges)
/// bounds a convex solid: closed, one shell, positive volume, the corners of the triangle
/// across every edge on or behind the edge's triangle's plane, and at every vertex face
/// angles summing to at most 2 pi (no saddle), all within `slack` (world units: the float
/// rounding of flat faces split into many triangles). `violation` gets the largest distance
/// of a corner in front of such a plane (0 for an exactly convex mesh).
bool boundsConvexSolid(const std::vector<double>& positions, const std::vector<uint32_t>& indices,
                       const std::vector<uint32_t>& across, double slack, double& violation) {
    violation = 0;
    const size_t triangles = indices.size() / 3, vertices = positions.size() / 3;
    if (triangles < 4) return false;
    auto at = [&](uint32_t v) { return Vec3{positions[3 * size_t(v)], positions[3 * size_t(v) + 1], positions[3 * size_t(v) + 2]}; };
    std::vector<double> angleSum(vertices, 0.0);
    std::vector<uint32_t> shell(triangles);
    for (uint32_t t = 0; t < triangles; ++t) shell[t] = t;
    auto find = [&](uint32_t x) {
        while (shell[x] != x) x = shell[x] = shell[shell[x]];
        return x;
    };
    double volume = 0;
    for (size_t t = 0; t < triangles; ++t) {
        const uint32_t* tri = &indices[3 * t];
        const Vec3 a = at(tri[0]), b = at(tri[1]), c = at(tri[2]);
        const Vec3 n = glm::cross(b - a, c - a);
        const double len = glm::length(n);
        if (!(len > 0)) return false;
        const Vec3 unit = n / len;
        volume += glm::dot(a, glm::cross(b, c));
        const Vec3 corner[3] = {a, b, c};
        for (int k = 0; k < 3; ++k) {
            const uint32_t other = across[3 * t + size_t(k)];
            if (other == ~0u || other >= triangles) return false;
            const uint32_t r = find(uint32_t(t)), q = find(other);
            if (r != q) shell[std::max(r, q)] = std::min(r, q);
            // The other triangle's corner off this edge lies behind this plane.
            for (int j = 0; j < 3; ++j) {
                const Vec3 p = at(indices[3 * size_t(other) + size_t(j)]);
                const double ahead = glm::dot(unit, p - a);
                if (ahead > slack) return false;
                violation = std::max(violation, ahead);
            }
            const Vec3 u = corner[(k + 1) % 3] - corner[k], w = corner[(k + 2) % 3] - corner[k];
            const double lu = glm::length(u), lw = glm::length(w);
            if (!(lu > 0 && lw > 0)) return false;
            angleSum[tri[k]] += std::acos(std::clamp(glm::dot(u, w) / (lu * lw), -1.0, 1.0));
        }
    }
    if (!(volume > 0)) return false;
    for (uint32_t t = 1; t < triangles; ++t)
        if (find(t) != 0) return false;
    for (size_t v = 0; v < vertices; ++v)
        if (angleSum[v] > 2 * M_PI + 1e-6) return false;
    return true;
}

}  // namespace

void prepareOriginal(const InputObject& object, PreparedOriginal& out) {
    out.object = &object;
    const size_t triangles = object.indices.size() / 3;
    out.bvh.build(object.positions.data(), object.positions.size() / 3, object.indices.data(), triangles);
    out.across = trianglesAcrossEdges(object.positions.data(), object.indices.data(), triangles);
    out.patches = planarPatches(object.positions.data(), object.indices.data(), out.across.data(), triangles);
    double extent = 0;
    for (double x : object.positions) extent = std::max(extent, std::fabs(x));
    out.convexSolid = boundsConvexSolid(object.positions, object.indices, out.across, 1e-6 * extent, out.convexSlack);
}

void TriangleBoundCache::addOriginal(const InputObject& object) {
    const std::vector<double>& p = object.positions;
    for (size_t t = 0; t + 2 < object.indices.size(); t += 3) {
        float c[9];
        bool exact = true;
        for (int v = 0; v < 3 && exact; ++v)
            for (int k = 0; k < 3; ++k) {
                const size_t i = 3 * size_t(object.indices[t + size_t(v)]) + size_t(k);
                if (i >= p.size()) return;
                c[3 * v + k] = static_cast<float>(p[i]);
                exact = exact && double(c[3 * v + k]) == p[i];
            }
        if (exact) bounds[key(c, c + 3, c + 6)] = Bound{};
    }
}

ProxyError measureProxyErrorPrepared(const std::vector<float>& proxyPositions,
                                     const std::vector<uint32_t>& proxyIndices,
                                     const std::vector<const PreparedOriginal*>& originals, double tolerance,
                                     size_t maxRefinementsPerDirection) {
    return measureProxyErrorPrepared(proxyPositions, proxyIndices, originals, tolerance, maxRefinementsPerDirection,
                                     ProxyMeasureOptions{});
}

ProxyError measureProxyErrorPrepared(const std::vector<float>& proxyPositions,
                                     const std::vector<uint32_t>& proxyIndices,
                                     const std::vector<const PreparedOriginal*>& originals, double tolerance,
                                     size_t maxRefinementsPerDirection, const ProxyMeasureOptions& options) {
    ProxyError e;
    e.tolerance = tolerance;
    size_t originalTriangles = 0;
    for (const PreparedOriginal* o : originals) originalTriangles += o->object->indices.size() / 3;
    if (originalTriangles == 0) return e;
    if (proxyIndices.size() < 3) {
        // Nothing drawn in place of the originals: they vanish, an error as large as their
        // extent (the diagonal of their box), so the node is used only when all of it is
        // below the tolerance on screen.
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (const PreparedOriginal* o : originals)
            for (size_t i = 0; i + 2 < o->object->positions.size(); i += 3)
                for (int k = 0; k < 3; ++k) {
                    lo[k] = std::min(lo[k], o->object->positions[i + k]);
                    hi[k] = std::max(hi[k], o->object->positions[i + k]);
                }
        e.originalsToProxy = e.originalsToProxyLower =
            std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
        return e;
    }
    // An enclosure of one convex solid K: the distance to K is convex, so over each proxy
    // triangle it is largest at a corner, and it equals the distance to K's surface wherever
    // the proxy lies outside K (everywhere, up to the enclosure's slack). Exact: the largest
    // corner distance.
    if (options.enclosesOriginals && originals.size() == 1 && originals[0]->convexSolid) {
        double worst = 0;
        for (size_t v = 0; v + 2 < proxyPositions.size(); v += 3) {
            const double q[3] = {proxyPositions[v], proxyPositions[v + 1], proxyPositions[v + 2]};
            // A corner with K within the largest distance so far cannot raise it.
            if (v > 0 && anyWithin(originals[0]->bvh, q, worst)) continue;
            worst = std::max(worst, closestPoint(originals[0]->bvh, q).distance);
        }
        // A solid convex up to convexSlack lies within about that of a convex one: twice that margin.
        e.proxyToOriginals = std::max(worst + 2 * originals[0]->convexSlack, options.enclosureSlack) * (1 + 1e-12);
        e.proxyToOriginalsLower = worst;
        e.originalsToProxy = options.enclosureSlack;
        e.evaluationCount = proxyPositions.size() / 3;
        return e;
    }
    Mesh proxy;
    proxy.positions.assign(proxyPositions.begin(), proxyPositions.end());
    proxy.indices = proxyIndices;

    // proxy -> original surfaces: every proxy triangle is a seed; one whose bound an earlier
    // measurement against the same originals certified is taken from the cache.
    const OriginalsTarget originalsTarget(originals);
    BranchAndBound<OriginalsTarget> forward(originalsTarget, false, tolerance, nullptr,
                                            options.enclosesOriginals ? options.enclosureSlack : -1.0);
    TriangleBoundCache* cache = options.cache;
    std::vector<TriangleBoundCache::Key> keys;
    if (cache) {
        forward.trackSeeds(proxy.triangleCount());
        keys.resize(proxy.triangleCount());
    }
    for (size_t t = 0; t < proxy.triangleCount(); ++t) {
        std::array<double, 9> c;
        for (int v = 0; v < 3; ++v)
            for (int k = 0; k < 3; ++k) c[size_t(3 * v + k)] = proxy.corner(t, v)[k];
        if (!cache) {
            forward.evaluateTriangle(c);
            continue;
        }
        keys[t] = TriangleBoundCache::key(&proxyPositions[3 * size_t(proxyIndices[3 * t])],
                                          &proxyPositions[3 * size_t(proxyIndices[3 * t + 1])],
                                          &proxyPositions[3 * size_t(proxyIndices[3 * t + 2])]);
        const auto known = cache->bounds.find(keys[t]);
        if (known != cache->bounds.end()) forward.seedKnown(c, uint32_t(t), known->second.upper, known->second.lower);
        else forward.evaluateTriangle(c, INFINITY, uint32_t(t));
    }
    const DirectionResult f = forward.run(proxy.triangleCount() + maxRefinementsPerDirection, options.giveUpAbove);
    if (cache) {
        std::vector<double> upper, lower;
        forward.rootBounds(upper, lower);
        for (size_t t = 0; t < keys.size(); ++t) {
            TriangleBoundCache::Bound& b = cache->bounds[keys[t]];
            b.upper = upper[t];
            b.lower = lower[t];
        }
    }
    e.proxyToOriginals = f.upper;
    e.proxyToOriginalsLower = f.lower;
    if (options.enclosesOriginals || f.lower > options.giveUpAbove) {
        e.originalsToProxy = options.enclosesOriginals ? options.enclosureSlack : INFINITY;
        e.evaluationCount = f.evaluations;
        return e;
    }
    TriangleBvh proxyBvh;
    proxyBvh.build(proxy.positions.data(), proxy.positions.size() / 3, proxy.indices.data(), proxy.triangleCount());
    const std::vector<uint32_t> proxyAcross =
        trianglesAcrossEdges(proxy.positions.data(), proxy.indices.data(), proxy.triangleCount());

    // originals -> proxy solid: the root box of every object's BVH is a seed, so originals
    // deep inside the proxy or well within the tolerance are dismissed a box at a time.
    const detail::PlanarPatches proxyPatches =
        detail::planarPatches(proxy.positions.data(), proxy.indices.data(), proxyAcross.data(), proxy.triangleCount());
    const ProxyTarget proxyTarget{proxyBvh, TargetMesh{proxy.positions.data(), proxy.indices.data(), proxyAcross.data(),
                                                       &proxyPatches}};
    BranchAndBound<ProxyTarget> backward(proxyTarget, true, tolerance, &originals);
    for (size_t i = 0; i < originals.size(); ++i)
        if (originals[i]->bvh.triangleCount() > 0) backward.evaluateBox(uint32_t(i), 0);
    const DirectionResult b = backward.run(originalTriangles + maxRefinementsPerDirection);

    e.originalsToProxy = b.upper;
    e.originalsToProxyLower = b.lower;
    e.evaluationCount = f.evaluations + b.evaluations;
    return e;
}

}  // namespace detail

ProxyError measureProxyError(const std::vector<float>& proxyPositions,
                             const std::vector<uint32_t>& proxyIndices,
                             const std::vector<const InputObject*>& originals, double tolerance,
                             size_t maxRefinementsPerDirection) {
    std::vector<detail::PreparedOriginal> prepared(originals.size());
    std::vector<const detail::PreparedOriginal*> pointers;
    for (size_t i = 0; i < originals.size(); ++i) {
        detail::prepareOriginal(*originals[i], prepared[i]);
        pointers.push_back(&prepared[i]);
    }
    return detail::measureProxyErrorPrepared(proxyPositions, proxyIndices, pointers, tolerance,
                                             maxRefinementsPerDirection);
}

}  // namespace aggrelod
