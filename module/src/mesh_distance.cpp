// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): exact minimum distance between triangle meshes with a BVH.
// See mesh_distance.h for what is implemented (Ericson, "Real-Time Collision Detection",
// 2005: 5.1.2, 5.1.5, 5.1.9, 5.3.4, 6.3.x), units (world units) and array sizes.
#include "mesh_distance.h"
#include "vec3.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <stdexcept>
#include <string>
#if defined(__SSE2__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 2)
#include <emmintrin.h>
#define AGGRELOD_MD_SSE 1
#endif

namespace aggrelod::detail {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- small vector helpers --------------------------------------------------------------

inline Vec3 load(const double* p) { return Vec3{p[0], p[1], p[2]}; }
inline void store(const Vec3& v, double* out) {
    if (out) {
        out[0] = v.x;
        out[1] = v.y;
        out[2] = v.z;
    }
}
inline double dist2(const Vec3& a, const Vec3& b) {
    Vec3 d = a - b;
    return dot(d, d);
}
inline double clamp01(double v) { return v < 0 ? 0 : (v > 1 ? 1 : v); }

// lo = min(lo, a), hi = max(hi, b) on 4 floats (build records; exact, order-independent).
inline void growBox4(float* lo, float* hi, const float* a, const float* b) {
#ifdef AGGRELOD_MD_SSE
    _mm_storeu_ps(lo, _mm_min_ps(_mm_loadu_ps(lo), _mm_loadu_ps(a)));
    _mm_storeu_ps(hi, _mm_max_ps(_mm_loadu_ps(hi), _mm_loadu_ps(b)));
#else
    for (int k = 0; k < 4; ++k) {
        lo[k] = std::min(lo[k], a[k]);
        hi[k] = std::max(hi[k], b[k]);
    }
#endif
}

// ---- primitives (squared distances, closest points) ------------------------------------

// Ericson 5.1.2: closest point on segment a-b to p. Never divides by zero.
inline Vec3 closestOnSegment(const Vec3& p, const Vec3& a, const Vec3& b) {
    Vec3 ab = b - a;
    double t = dot(p - a, ab);
    if (t <= 0) return a;
    double len2 = dot(ab, ab);
    if (t >= len2) return b;  // also catches len2 == 0 (then t <= 0 above anyway)
    return a + ab * (t / len2);
}

// Point-triangle, Ericson 5.1.5 (barycentric coordinates of the projection from signed
// sub-triangle areas). The projection is returned when it lies inside the triangle;
// otherwise (or when the triangle has zero area) the closest point is on an edge, and the
// three edges are tried (5.1.2) - this keeps repeated or collinear vertices exact and NaN-free.
inline double pointTriangle2(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                             const Vec3& n, Vec3& out) {
    if (dot(n, n) > 0) {
        Vec3 pa = a - p, pb = b - p, pc = c - p;
        double ua = dot(n, cross(pb, pc));
        double ub = dot(n, cross(pc, pa));
        double uc = dot(n, cross(pa, pb));
        if (ua >= 0 && ub >= 0 && uc >= 0) {
            double sum = ua + ub + uc;
            if (sum > 0) {
                double v = ub / sum, w = uc / sum;
                out = a + (b - a) * v + (c - a) * w;
                return dist2(p, out);
            }
        }
    }
    Vec3 q = closestOnSegment(p, a, b);
    double best = dist2(p, q);
    out = q;
    q = closestOnSegment(p, b, c);
    double d = dist2(p, q);
    if (d < best) {
        best = d;
        out = q;
    }
    q = closestOnSegment(p, c, a);
    d = dist2(p, q);
    if (d < best) {
        best = d;
        out = q;
    }
    return best;
}

// Segment-segment, Ericson 5.1.9 with exact-zero tests for degenerate segments and s = 0 for
// parallel ones (every s then has an optimal t; the clamping below makes the pair optimal).
inline double segmentSegment2(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2,
                              Vec3& c1, Vec3& c2, double& s, double& t, double& denomOut,
                              double& aOut, double& eOut) {
    Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    denomOut = 0;
    aOut = a;
    eOut = e;
    if (a == 0 && e == 0) {
        s = t = 0;
    } else if (a == 0) {
        s = 0;
        t = clamp01(f / e);
    } else {
        double c = dot(d1, r);
        if (e == 0) {
            t = 0;
            s = clamp01(-c / a);
        } else {
            double b = dot(d1, d2);
            double denom = a * e - b * b;
            denomOut = denom;
            s = denom > 0 ? clamp01((b * f - c * e) / denom) : 0.0;
            double tnom = b * s + f;
            if (tnom < 0) {
                t = 0;
                s = clamp01(-c / a);
            } else if (tnom > e) {
                t = 1;
                s = clamp01((b - c) / a);
            } else {
                t = tnom / e;
            }
        }
    }
    c1 = p1 + d1 * s;
    c2 = p2 + d2 * t;
    return dist2(c1, c2);
}

// Does segment p-q cross triangle (t0,t1,t2) with normal n (unnormalized)? Ericson 5.3.4:
// p, q on opposite sides of (or on) the plane, and the line pq passes inside the triangle
// (scalar triple products of one sign). Segments lying in the plane are left to the
// coplanar test. On success x = crossing point.
inline bool segmentCrossesTriangle(const Vec3& p, const Vec3& q, const Vec3& t0,
                                   const Vec3& t1, const Vec3& t2, const Vec3& n, Vec3& x) {
    double sp = dot(n, p - t0), sq = dot(n, q - t0);
    if ((sp > 0 && sq > 0) || (sp < 0 && sq < 0)) return false;
    if (sp == 0 && sq == 0) return false;  // in the plane, or degenerate triangle (n = 0)
    // In the plane up to rounding (as nearPlane): the signs below would be noise and would
    // see a crossing wherever the segment's line passes near the triangle in its plane.
    const double L2 = std::max({dist2(p, q), dist2(t0, t1), dist2(t1, t2), dist2(t2, t0)});
    const double tolerance2 = 1e-24 * dot(n, n) * L2;
    if (sp * sp <= tolerance2 && sq * sq <= tolerance2) return false;
    Vec3 d = q - p;
    Vec3 a = t0 - p, b = t1 - p, c = t2 - p;
    double o0 = dot(d, cross(a, b)), o1 = dot(d, cross(b, c)), o2 = dot(d, cross(c, a));
    bool allPos = o0 >= 0 && o1 >= 0 && o2 >= 0;
    bool allNeg = o0 <= 0 && o1 <= 0 && o2 <= 0;
    if (!allPos && !allNeg) return false;
    if (o0 == 0 && o1 == 0 && o2 == 0) return false;
    x = p + d * (sp / (sp - sq));  // sp - sq != 0: not both zero and not of one sign
    return true;
}

// 2D separating-axis overlap test (closed triangles) of the projections that drop `axis`.
inline bool overlap2D(const Vec3 A[3], const Vec3 B[3], int axis) {
    int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    double P[6][2];
    for (int i = 0; i < 3; ++i) {
        const double* ca = &A[i].x;
        const double* cb = &B[i].x;
        P[i][0] = ca[u];
        P[i][1] = ca[v];
        P[3 + i][0] = cb[u];
        P[3 + i][1] = cb[v];
    }
    for (int tri = 0; tri < 2; ++tri) {
        for (int i = 0; i < 3; ++i) {
            const double* e0 = P[tri * 3 + i];
            const double* e1 = P[tri * 3 + (i + 1) % 3];
            double ax = -(e1[1] - e0[1]), ay = e1[0] - e0[0];
            if (ax == 0 && ay == 0) continue;
            double minA = kInf, maxA = -kInf, minB = kInf, maxB = -kInf;
            for (int k = 0; k < 3; ++k) {
                double pa = ax * P[k][0] + ay * P[k][1];
                double pb = ax * P[3 + k][0] + ay * P[3 + k][1];
                minA = std::min(minA, pa);
                maxA = std::max(maxA, pa);
                minB = std::min(minB, pb);
                maxB = std::max(maxB, pb);
            }
            if (maxA < minB || maxB < minA) return false;
        }
    }
    return true;
}

inline int dominantAxis(const Vec3& n) {
    double ax = std::fabs(n.x), ay = std::fabs(n.y), az = std::fabs(n.z);
    if (ax >= ay && ax >= az) return 0;
    return ay >= az ? 1 : 2;
}

// Are all three points of P within tol * sqrt(L2) of the plane through t0 with normal n?
inline bool nearPlane(const Vec3 P[3], const Vec3& t0, const Vec3& n, double L2) {
    double nn = dot(n, n);
    if (!(nn > 0)) return false;
    constexpr double kTol2 = 1e-24;  // (1e-12)^2, relative to the longest edge
    for (int i = 0; i < 3; ++i) {
        double s = dot(n, P[i] - t0);
        if (s * s > kTol2 * nn * L2) return false;
    }
    return true;
}

// Triangle-triangle squared distance. Returns 0 with outA = outB when the closed triangles
// intersect (edge crossing, coplanar overlap) or touch.
double triangleTriangle2(const Vec3 A[3], const Vec3 B[3], Vec3& outA, Vec3& outB) {
    Vec3 nA = cross(A[1] - A[0], A[2] - A[0]);
    Vec3 nB = cross(B[1] - B[0], B[2] - B[0]);
    double L2 = 0;
    for (int i = 0; i < 3; ++i) {
        L2 = std::max(L2, dist2(A[i], A[(i + 1) % 3]));
        L2 = std::max(L2, dist2(B[i], B[(i + 1) % 3]));
    }
    int coplanarAxis = -1;  // >= 0: both in one plane (up to rounding), the axis to drop
    if (nearPlane(A, B[0], nB, L2))
        coplanarAxis = dominantAxis(nB);
    else if (nearPlane(B, A[0], nA, L2))
        coplanarAxis = dominantAxis(nA);

    // 1. An edge of one triangle crossing the other. Not for coplanar triangles: there the
    // signs of the side and orientation tests are rounding noise, and would see crossings
    // between triangles that lie apart in their common plane.
    Vec3 x;
    for (int i = 0; i < 3 && coplanarAxis < 0; ++i) {
        if (segmentCrossesTriangle(A[i], A[(i + 1) % 3], B[0], B[1], B[2], nB, x) ||
            segmentCrossesTriangle(B[i], B[(i + 1) % 3], A[0], A[1], A[2], nA, x)) {
            outA = outB = x;
            return 0;
        }
    }

    // 2. Minimum over the 6 vertex-face and 9 edge-edge pairs (first minimum kept).
    double best = kInf;
    Vec3 q;
    for (int i = 0; i < 3; ++i) {
        double d = pointTriangle2(A[i], B[0], B[1], B[2], nB, q);
        if (d < best) {
            best = d;
            outA = A[i];
            outB = q;
        }
    }
    for (int i = 0; i < 3; ++i) {
        double d = pointTriangle2(B[i], A[0], A[1], A[2], nA, q);
        if (d < best) {
            best = d;
            outA = q;
            outB = B[i];
        }
    }
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            Vec3 c1, c2;
            double s, t, denom, a, e;
            double d = segmentSegment2(A[i], A[(i + 1) % 3], B[j], B[(j + 1) % 3], c1, c2, s, t,
                                       denom, a, e);
            if (d < best) {
                best = d;
                outA = c1;
                outB = c2;
            }
        }
    }
    if (best == 0) {
        outB = outA;
        return 0;
    }

    // 3. Coplanar overlap (crossings inside the common plane are not seen by step 1).
    if (coplanarAxis >= 0 && overlap2D(A, B, coplanarAxis)) {
        outB = outA;
        return 0;
    }
    return best;
}

// ---- boxes -------------------------------------------------------------------------------

inline double boxBoxDist2(const double* alo, const double* ahi, const double* blo,
                          const double* bhi) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
        double g = std::max(alo[k] - bhi[k], blo[k] - ahi[k]);
        if (g > 0) d2 += g * g;
    }
    return d2;
}

inline double pointBoxDist2(const double* p, const double* lo, const double* hi) {
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
        double g = std::max(lo[k] - p[k], p[k] - hi[k]);
        if (g > 0) d2 += g * g;
    }
    return d2;
}

inline void triangleBox(const double* c, double lo[3], double hi[3]) {
    for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(c[k], std::min(c[3 + k], c[6 + k]));
        hi[k] = std::max(c[k], std::max(c[3 + k], c[6 + k]));
    }
}

inline double halfArea(const double* lo, const double* hi) {
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    return dx * dy + dy * dz + dz * dx;
}

// Pruning slack: a computed triangle distance can undercut the box lower bound by rounding
// of order eps * |coordinates|; boxes within best + slack are still visited so that the
// result equals the brute-force minimum (with its tie rule) bit for bit.
inline double pruneBound2(double best, double slack) {
    double r = best + slack;
    return r * r;
}

// Separating-axis lower bound (a cheap reject before the full triangle-triangle distance):
// the gap between the two triangles' projections on any axis n is at most their distance
// times |n|. Axes: both normals and the centroid difference. True when the gap on one of
// them exceeds sqrt(bound2), so the pair cannot reach the pruning bound; bound2 holds the
// same slack as the box test, which covers the rounding of these few dot products, so a
// pair that could win (or tie) is never rejected and results stay bit for bit the same.
inline bool separatedBeyond(const Vec3 A[3], const Vec3 B[3], double bound2) {
    const Vec3 axes[3] = {cross(A[1] - A[0], A[2] - A[0]), cross(B[1] - B[0], B[2] - B[0]),
                          (B[0] + B[1] + B[2]) - (A[0] + A[1] + A[2])};
    for (const Vec3& n : axes) {
        const double a0 = dot(n, A[0]), a1 = dot(n, A[1]), a2 = dot(n, A[2]);
        const double b0 = dot(n, B[0]), b1 = dot(n, B[1]), b2 = dot(n, B[2]);
        const double gap = std::max(std::min({b0, b1, b2}) - std::max({a0, a1, a2}),
                                    std::min({a0, a1, a2}) - std::max({b0, b1, b2}));
        if (gap > 0 && gap * gap > bound2 * dot(n, n)) return true;
    }
    return false;
}

inline bool pairLess(uint32_t a0, uint32_t b0, uint32_t a1, uint32_t b1) {
    return a0 < a1 || (a0 == a1 && b0 < b1);
}

constexpr uint32_t kLeafSize = 4;
constexpr int kBins = 16;

}  // namespace

// ---- BVH build ---------------------------------------------------------------------------

void TriangleBvh::build(const double* positions, size_t vertexCount, const uint32_t* indices,
                        size_t triangleCount) {
    nodes_.clear();
    corners_.clear();
    triangleIndex_.clear();
    maxAbs_ = 0;
    if (triangleCount == 0) return;
    if (triangleCount >= size_t(0x7fffffff))
        throw std::invalid_argument("TriangleBvh: too many triangles");
    if (!positions || !indices) throw std::invalid_argument("TriangleBvh: null array");
    for (size_t i = 0; i < 3 * triangleCount; ++i)
        if (indices[i] >= vertexCount)
            throw std::invalid_argument("TriangleBvh: triangle " + std::to_string(i / 3) +
                                        " has vertex index " + std::to_string(indices[i]) +
                                        " >= vertex count " + std::to_string(vertexCount));

    const size_t nt = triangleCount;
    // Exact root box; its centre is the origin of the float records below.
    double rootLo[3] = {kInf, kInf, kInf}, rootHi[3] = {-kInf, -kInf, -kInf};
    for (size_t i = 0; i < 3 * nt; ++i) {
        const double* v = positions + 3 * size_t(indices[i]);
        if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])))
            throw std::invalid_argument("TriangleBvh: vertex " + std::to_string(indices[i]) +
                                        " has a non-finite coordinate");
        for (int k = 0; k < 3; ++k) {
            rootLo[k] = std::min(rootLo[k], v[k]);
            rootHi[k] = std::max(rootHi[k], v[k]);
        }
    }
    double centre[3];
    for (int k = 0; k < 3; ++k) {
        centre[k] = 0.5 * (rootLo[k] + rootHi[k]);
        maxAbs_ = std::max(maxAbs_, std::max(std::fabs(rootLo[k]), std::fabs(rootHi[k])));
    }
    auto toFloat = [&](double v, int k) {
        double r = v - centre[k];
        return float(std::min(std::max(r, -1e37), 1e37));  // finite, in float range
    };

    // Build records in float, relative to the centre: they only choose the splits (SAH
    // estimates, partition); the node boxes are recomputed exactly in double at the end.
    struct Prim {
        float lo[4], hi[4], c[4];  // [3] is padding (0): min/max run as 4-wide vector ops
        uint32_t index;
    };
    std::vector<Prim> prims(nt);
    float rootClo[3] = {FLT_MAX, FLT_MAX, FLT_MAX}, rootChi[3] = {-FLT_MAX, -FLT_MAX, -FLT_MAX};
    for (size_t t = 0; t < nt; ++t) {
        const double* v0 = positions + 3 * size_t(indices[3 * t]);
        const double* v1 = positions + 3 * size_t(indices[3 * t + 1]);
        const double* v2 = positions + 3 * size_t(indices[3 * t + 2]);
        Prim& p = prims[t];
        for (int k = 0; k < 3; ++k) {
            p.lo[k] = toFloat(std::min(v0[k], std::min(v1[k], v2[k])), k);
            p.hi[k] = toFloat(std::max(v0[k], std::max(v1[k], v2[k])), k);
            p.c[k] = toFloat((v0[k] + v1[k] + v2[k]) * (1.0 / 3.0), k);
            rootClo[k] = std::min(rootClo[k], p.c[k]);
            rootChi[k] = std::max(rootChi[k], p.c[k]);
        }
        p.lo[3] = p.hi[3] = p.c[3] = 0;
        p.index = uint32_t(t);
    }

    nodes_.reserve(nt);
    nodes_.push_back(Node{});
    struct Work {
        uint32_t node, begin, end;
        float clo[4], chi[4];  // centroid bounds of the range ([3] unused)
    };
    std::vector<Work> stack;
    stack.push_back({0, 0, uint32_t(nt), {rootClo[0], rootClo[1], rootClo[2], 0},
                     {rootChi[0], rootChi[1], rootChi[2], 0}});

    struct Bin {
        float lo[4], hi[4];
        uint32_t count;
    };
    Bin bins[3][kBins];
    double rightArea[kBins];
    uint32_t rightCount[kBins];
    auto binOf = [](float c, float cmin, float scale, int nb) {
        float f = std::max(0.0f, (c - cmin) * scale);  // NaN -> 0
        return int(std::min(float(nb - 1), f));
    };
    auto area = [](const float* lo, const float* hi) {
        double dx = double(hi[0]) - lo[0], dy = double(hi[1]) - lo[1], dz = double(hi[2]) - lo[2];
        return dx * dy + dy * dz + dz * dx;
    };

    while (!stack.empty()) {
        const Work w = stack.back();
        stack.pop_back();
        const uint32_t count = w.end - w.begin;
        if (count <= kLeafSize) {
            nodes_[w.node].first = w.begin;
            nodes_[w.node].count = count;
            continue;
        }

        // Binned SAH over centroids, three axes binned in one pass (Wald 2007); the first
        // minimum (lowest axis, lowest split) wins, so the choice is deterministic.
        const int nb = count >= 64 ? kBins : kBins / 2;  // fewer bins for small nodes
        float scale[3];
        bool active[3];
        for (int axis = 0; axis < 3; ++axis) {
            float extent = w.chi[axis] - w.clo[axis];
            active[axis] = extent > 0 && extent <= FLT_MAX;
            scale[axis] = active[axis] ? float(nb) / extent : 0.0f;
            for (int i = 0; i < nb; ++i) {
                Bin& b = bins[axis][i];
                b.count = 0;
                for (int k = 0; k < 4; ++k) {
                    b.lo[k] = FLT_MAX;
                    b.hi[k] = -FLT_MAX;
                }
            }
        }
        auto addToBin = [&](const Prim& p, int axis) {
            Bin& b = bins[axis][binOf(p.c[axis], w.clo[axis], scale[axis], nb)];
            ++b.count;
            growBox4(b.lo, b.hi, p.lo, p.hi);
        };
        for (uint32_t i = w.begin; i < w.end; ++i)
            for (int axis = 0; axis < 3; ++axis) addToBin(prims[i], axis);
        int bestAxis = -1, bestSplit = -1;
        double bestCost = kInf;
        for (int axis = 0; axis < 3; ++axis) {
            if (!active[axis]) continue;
            const Bin* bs = bins[axis];
            float rlo[4] = {FLT_MAX, FLT_MAX, FLT_MAX, FLT_MAX};
            float rhi[4] = {-FLT_MAX, -FLT_MAX, -FLT_MAX, -FLT_MAX};
            uint32_t rc = 0;
            for (int i = nb - 1; i > 0; --i) {
                rc += bs[i].count;
                growBox4(rlo, rhi, bs[i].lo, bs[i].hi);
                rightCount[i] = rc;
                rightArea[i] = rc ? area(rlo, rhi) : 0;
            }
            float llo[4] = {FLT_MAX, FLT_MAX, FLT_MAX, FLT_MAX};
            float lhi[4] = {-FLT_MAX, -FLT_MAX, -FLT_MAX, -FLT_MAX};
            uint32_t lc = 0;
            for (int i = 0; i < nb - 1; ++i) {
                lc += bs[i].count;
                growBox4(llo, lhi, bs[i].lo, bs[i].hi);
                if (lc == 0 || rightCount[i + 1] == 0) continue;
                double cost = lc * area(llo, lhi) + rightCount[i + 1] * rightArea[i + 1];
                if (cost < bestCost) {
                    bestCost = cost;
                    bestAxis = axis;
                    bestSplit = i;
                }
            }
        }

        // Partition (two-pointer, deterministic), gathering each side's centroid bounds.
        Work L{0, w.begin, 0, {FLT_MAX, FLT_MAX, FLT_MAX, 0}, {-FLT_MAX, -FLT_MAX, -FLT_MAX, 0}};
        Work R{0, 0, w.end, {FLT_MAX, FLT_MAX, FLT_MAX, 0}, {-FLT_MAX, -FLT_MAX, -FLT_MAX, 0}};
        auto grow = [](Work& s, const Prim& p) { growBox4(s.clo, s.chi, p.c, p.c); };
        uint32_t mid = w.begin;
        if (bestAxis >= 0) {
            const int axis = bestAxis;
            const float cmin = w.clo[axis], sc = scale[axis];
            auto left = [&](const Prim& p) { return binOf(p.c[axis], cmin, sc, nb) <= bestSplit; };
            uint32_t i = w.begin, j = w.end;
            for (;;) {
                while (i < j && left(prims[i])) grow(L, prims[i++]);
                while (i < j && !left(prims[j - 1])) grow(R, prims[--j]);
                if (i >= j) break;
                std::swap(prims[i], prims[j - 1]);
                grow(L, prims[i++]);
                grow(R, prims[--j]);
            }
            mid = i;
        }
        if (mid <= w.begin || mid >= w.end) {
            // No usable split (all centroids coincide): halve by position (deterministic).
            mid = w.begin + count / 2;
            for (int k = 0; k < 3; ++k) {
                L.clo[k] = R.clo[k] = w.clo[k];
                L.chi[k] = R.chi[k] = w.chi[k];
            }
        }

        const uint32_t first = uint32_t(nodes_.size());
        nodes_[w.node].first = first;
        nodes_[w.node].count = 0;
        nodes_.push_back(Node{});
        nodes_.push_back(Node{});
        L.node = first;
        L.end = mid;
        R.node = first + 1;
        R.begin = mid;
        stack.push_back(R);
        stack.push_back(L);
    }

    corners_.resize(nt * 9);
    triangleIndex_.resize(nt);
    for (size_t s = 0; s < nt; ++s) {
        triangleIndex_[s] = prims[s].index;
        const uint32_t* tri = indices + 3 * size_t(prims[s].index);
        for (size_t c = 0; c < 3; ++c)
            for (size_t k = 0; k < 3; ++k) corners_[9 * s + 3 * c + k] = positions[3 * size_t(tri[c]) + k];
    }
    // Exact node boxes, bottom-up (children always follow their parent in the array).
    for (size_t n = nodes_.size(); n-- > 0;) {
        Node& node = nodes_[n];
        if (node.count) {
            for (int k = 0; k < 3; ++k) {
                node.lo[k] = kInf;
                node.hi[k] = -kInf;
            }
            for (uint32_t s = node.first; s < node.first + node.count; ++s) {
                double lo[3], hi[3];
                triangleBox(&corners_[9 * size_t(s)], lo, hi);
                for (int k = 0; k < 3; ++k) {
                    node.lo[k] = std::min(node.lo[k], lo[k]);
                    node.hi[k] = std::max(node.hi[k], hi[k]);
                }
            }
        } else {
            const Node& a = nodes_[node.first];
            const Node& b = nodes_[node.first + 1];
            for (int k = 0; k < 3; ++k) {
                node.lo[k] = std::min(a.lo[k], b.lo[k]);
                node.hi[k] = std::max(a.hi[k], b.hi[k]);
            }
        }
    }
}

void TriangleBvh::bounds(double lo[3], double hi[3]) const {
    for (int k = 0; k < 3; ++k) {
        lo[k] = nodes_.empty() ? kInf : nodes_[0].lo[k];
        hi[k] = nodes_.empty() ? -kInf : nodes_[0].hi[k];
    }
}

// ---- public primitives ---------------------------------------------------------------------

double pointTriangleDistance(const double* p, const double* a, const double* b, const double* c,
                             double out[3]) {
    Vec3 A = load(a), B = load(b), C = load(c), q;
    double d2 = pointTriangle2(load(p), A, B, C, cross(B - A, C - A), q);
    store(q, out);
    return std::sqrt(d2);
}

double segmentSegmentDistance(const double* p1, const double* q1, const double* p2,
                              const double* q2, double out1[3], double out2[3], double* sOut,
                              double* tOut) {
    Vec3 P1 = load(p1), Q1 = load(q1), P2 = load(p2), Q2 = load(q2), c1, c2;
    double s, t, denom, a, e;
    double d2 = segmentSegment2(P1, Q1, P2, Q2, c1, c2, s, t, denom, a, e);
    // Nearly parallel segments: the line-line solution is ill-conditioned; the minimum is then
    // attained (to rounding) at an endpoint, so also try the four endpoint-segment pairs.
    if (a > 0 && e > 0 && denom <= 1e-10 * a * e) {
        const Vec3* ends[4] = {&P1, &Q1, &P2, &Q2};
        for (int i = 0; i < 4; ++i) {
            bool first = i < 2;
            Vec3 q = first ? closestOnSegment(*ends[i], P2, Q2) : closestOnSegment(*ends[i], P1, Q1);
            double d = dist2(*ends[i], q);
            if (d < d2) {
                d2 = d;
                if (first) {
                    c1 = *ends[i];
                    c2 = q;
                    s = i == 0 ? 0 : 1;
                    Vec3 r = q - P2;
                    t = clamp01(dot(r, Q2 - P2) / e);
                } else {
                    c1 = q;
                    c2 = *ends[i];
                    t = i == 2 ? 0 : 1;
                    Vec3 r = q - P1;
                    s = clamp01(dot(r, Q1 - P1) / a);
                }
            }
        }
    }
    store(c1, out1);
    store(c2, out2);
    if (sOut) *sOut = s;
    if (tOut) *tOut = t;
    return std::sqrt(d2);
}

double triangleTriangleDistance(const double* a0, const double* a1, const double* a2,
                                const double* b0, const double* b1, const double* b2,
                                double outA[3], double outB[3], bool* intersecting) {
    const Vec3 A[3] = {load(a0), load(a1), load(a2)};
    const Vec3 B[3] = {load(b0), load(b1), load(b2)};
    Vec3 pa, pb;
    double d = std::sqrt(triangleTriangle2(A, B, pa, pb));
    store(pa, outA);
    store(pb, outB);
    if (intersecting) *intersecting = d == 0;
    return d;
}

// ---- queries -----------------------------------------------------------------------------

ClosestPair meshDistance(const TriangleBvh& a, const TriangleBvh& b, double maxDistance,
                         double stopBelow) {
    ClosestPair result;
    if (a.triangleCount() == 0 || b.triangleCount() == 0 || !(maxDistance >= 0)) return result;
    const std::vector<TriangleBvh::Node>& na = a.nodes();
    const std::vector<TriangleBvh::Node>& nb = b.nodes();
    const double slack = 64 * DBL_EPSILON * std::max(a.maxAbsCoordinate(), b.maxAbsCoordinate());

    double best = maxDistance;
    bool have = false;
    double bound2 = pruneBound2(best, slack);

    struct Item {
        uint32_t a, b;
        double d2;
    };
    std::vector<Item> stack;
    stack.reserve(128);
    stack.push_back({0, 0, boxBoxDist2(na[0].lo, na[0].hi, nb[0].lo, nb[0].hi)});

    double boxA[4][6], boxB[4][6];
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        if (it.d2 > bound2) continue;
        const TriangleBvh::Node& A = na[it.a];
        const TriangleBvh::Node& B = nb[it.b];
        if (A.count && B.count) {
            for (uint32_t i = 0; i < A.count; ++i) triangleBox(a.slotCorners(A.first + i), boxA[i], boxA[i] + 3);
            for (uint32_t j = 0; j < B.count; ++j) triangleBox(b.slotCorners(B.first + j), boxB[j], boxB[j] + 3);
            for (uint32_t i = 0; i < A.count; ++i) {
                const uint32_t ta = a.slotTriangle(A.first + i);
                const double* ca = a.slotCorners(A.first + i);
                const Vec3 TA[3] = {load(ca), load(ca + 3), load(ca + 6)};
                for (uint32_t j = 0; j < B.count; ++j) {
                    if (boxBoxDist2(boxA[i], boxA[i] + 3, boxB[j], boxB[j] + 3) > bound2) continue;
                    const uint32_t tb = b.slotTriangle(B.first + j);
                    if (have && best == 0 && !pairLess(ta, tb, result.triangleA, result.triangleB))
                        continue;  // nothing beats 0, and the tie rule prefers the current pair
                    const double* cb = b.slotCorners(B.first + j);
                    const Vec3 TB[3] = {load(cb), load(cb + 3), load(cb + 6)};
                    if (separatedBeyond(TA, TB, bound2)) continue;
                    Vec3 pa, pb;
                    double d = std::sqrt(triangleTriangle2(TA, TB, pa, pb));
                    bool take = d < best ||
                                (d == best && (!have || pairLess(ta, tb, result.triangleA, result.triangleB)));
                    if (!take) continue;
                    have = true;
                    best = d;
                    bound2 = pruneBound2(best, slack);
                    result.distance = d;
                    store(pa, result.pointA);
                    store(pb, result.pointB);
                    result.triangleA = ta;
                    result.triangleB = tb;
                    result.intersecting = d == 0;
                    if (stopBelow > 0 && d <= stopBelow) return result;
                }
            }
            continue;
        }
        // Descend the larger box (Ericson 6.3.1); a leaf is never split.
        bool splitA = B.count != 0 || (A.count == 0 && halfArea(A.lo, A.hi) >= halfArea(B.lo, B.hi));
        Item c0, c1;
        if (splitA) {
            c0 = {A.first, it.b, boxBoxDist2(na[A.first].lo, na[A.first].hi, B.lo, B.hi)};
            c1 = {A.first + 1, it.b, boxBoxDist2(na[A.first + 1].lo, na[A.first + 1].hi, B.lo, B.hi)};
        } else {
            c0 = {it.a, B.first, boxBoxDist2(A.lo, A.hi, nb[B.first].lo, nb[B.first].hi)};
            c1 = {it.a, B.first + 1, boxBoxDist2(A.lo, A.hi, nb[B.first + 1].lo, nb[B.first + 1].hi)};
        }
        // Nearer pair on top of the stack (visited first); ties: first child first.
        if (c1.d2 < c0.d2) std::swap(c0, c1);
        if (c1.d2 <= bound2) stack.push_back(c1);
        if (c0.d2 <= bound2) stack.push_back(c0);
    }
    return result;
}

ClosestPoint closestPoint(const TriangleBvh& bvh, const double p[3], double maxDistance) {
    ClosestPoint result;
    if (bvh.triangleCount() == 0 || !(maxDistance >= 0)) return result;
    const std::vector<TriangleBvh::Node>& nodes = bvh.nodes();
    double pAbs = std::max(std::fabs(p[0]), std::max(std::fabs(p[1]), std::fabs(p[2])));
    const double slack = 64 * DBL_EPSILON * std::max(bvh.maxAbsCoordinate(), pAbs);
    const Vec3 P = load(p);

    double best = maxDistance;
    bool have = false;
    double bound2 = pruneBound2(best, slack);

    struct Item {
        uint32_t node;
        double d2;
    };
    // Reused per thread: this query runs millions of times (proxy errors), an allocation each
    // time would cost as much as the search.
    static thread_local std::vector<Item> stack;
    stack.clear();
    stack.push_back({0, pointBoxDist2(p, nodes[0].lo, nodes[0].hi)});
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        if (it.d2 > bound2) continue;
        const TriangleBvh::Node& N = nodes[it.node];
        if (N.count) {
            for (uint32_t i = 0; i < N.count; ++i) {
                const double* c = bvh.slotCorners(N.first + i);
                double lo[3], hi[3];
                triangleBox(c, lo, hi);
                if (pointBoxDist2(p, lo, hi) > bound2) continue;
                const uint32_t tri = bvh.slotTriangle(N.first + i);
                if (have && best == 0 && tri > result.triangle) continue;
                Vec3 A = load(c), B = load(c + 3), C = load(c + 6), q;
                double d = std::sqrt(pointTriangle2(P, A, B, C, cross(B - A, C - A), q));
                if (d < best || (d == best && (!have || tri < result.triangle))) {
                    have = true;
                    best = d;
                    bound2 = pruneBound2(best, slack);
                    result.distance = d;
                    store(q, result.point);
                    result.triangle = tri;
                }
            }
            continue;
        }
        Item c0{N.first, pointBoxDist2(p, nodes[N.first].lo, nodes[N.first].hi)};
        Item c1{N.first + 1, pointBoxDist2(p, nodes[N.first + 1].lo, nodes[N.first + 1].hi)};
        if (c1.d2 < c0.d2) std::swap(c0, c1);
        if (c1.d2 <= bound2) stack.push_back(c1);
        if (c0.d2 <= bound2) stack.push_back(c0);
    }
    return result;
}

bool anyWithin(const TriangleBvh& bvh, const double p[3], double distance) {
    if (bvh.triangleCount() == 0 || !(distance >= 0)) return false;
    const std::vector<TriangleBvh::Node>& nodes = bvh.nodes();
    const double pAbs = std::max(std::fabs(p[0]), std::max(std::fabs(p[1]), std::fabs(p[2])));
    // The same conservative pruning as closestPoint: no triangle it would find is skipped.
    const double bound2 = pruneBound2(distance, 64 * DBL_EPSILON * std::max(bvh.maxAbsCoordinate(), pAbs));
    const Vec3 P = load(p);
    static thread_local std::vector<uint32_t> stack;
    stack.clear();
    if (pointBoxDist2(p, nodes[0].lo, nodes[0].hi) <= bound2) stack.push_back(0);
    while (!stack.empty()) {
        const TriangleBvh::Node& N = nodes[stack.back()];
        stack.pop_back();
        if (N.count) {
            for (uint32_t i = 0; i < N.count; ++i) {
                const double* c = bvh.slotCorners(N.first + i);
                double lo[3], hi[3];
                triangleBox(c, lo, hi);
                if (pointBoxDist2(p, lo, hi) > bound2) continue;
                Vec3 A = load(c), B = load(c + 3), C = load(c + 6), q;
                if (std::sqrt(pointTriangle2(P, A, B, C, cross(B - A, C - A), q)) <= distance) return true;
            }
            continue;
        }
        // Nearer child on top: a yes is found sooner.
        const double d0 = pointBoxDist2(p, nodes[N.first].lo, nodes[N.first].hi);
        const double d1 = pointBoxDist2(p, nodes[N.first + 1].lo, nodes[N.first + 1].hi);
        const uint32_t nearer = d0 <= d1 ? N.first : N.first + 1, farther = nearer == N.first ? N.first + 1 : N.first;
        if (std::max(d0, d1) <= bound2) stack.push_back(farther);
        if (std::min(d0, d1) <= bound2) stack.push_back(nearer);
    }
    return false;
}

}  // namespace aggrelod::detail
