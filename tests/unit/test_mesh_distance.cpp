// SPDX-License-Identifier: AGPL-3.0-or-later
// Unit tests for mesh_distance (exact triangle-mesh minimum distance with a BVH).
// Known-answer cases on cubes and triangles, degenerate inputs, and comparisons of the BVH
// queries against brute force over all triangle pairs on random meshes (fixed seeds).
#include "mesh_distance.h"
#include "mesh_preparation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

using namespace aggrelod::detail;

namespace {

const double kInf = std::numeric_limits<double>::infinity();

struct Mesh {
    std::vector<double> pos;
    std::vector<uint32_t> idx;
    size_t vertexCount() const { return pos.size() / 3; }
    size_t triangleCount() const { return idx.size() / 3; }
    const double* corner(size_t t, int c) const { return &pos[3 * size_t(idx[3 * t + c])]; }
};

using Mat3 = std::array<double, 9>;

Mat3 identity() { return {1, 0, 0, 0, 1, 0, 0, 0, 1}; }

Mat3 axisAngle(double ax, double ay, double az, double angle) {
    double n = std::sqrt(ax * ax + ay * ay + az * az);
    ax /= n, ay /= n, az /= n;
    double c = std::cos(angle), s = std::sin(angle), t = 1 - c;
    return {t * ax * ax + c,      t * ax * ay - s * az, t * ax * az + s * ay,
            t * ax * ay + s * az, t * ay * ay + c,      t * ay * az - s * ax,
            t * ax * az - s * ay, t * ay * az + s * ax, t * az * az + c};
}

Mat3 mul(const Mat3& a, const Mat3& b) {
    Mat3 r{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) r[3 * i + j] += a[3 * i + k] * b[3 * k + j];
    return r;
}

// Cube of edge `side` centred at c, rotated by R about its centre. 12 outward triangles.
Mesh cube(double cx, double cy, double cz, double side = 1.0, const Mat3& R = identity()) {
    Mesh m;
    double h = side / 2;
    for (int i = 0; i < 8; ++i) {
        double l[3] = {(i & 1) ? h : -h, (i & 2) ? h : -h, (i & 4) ? h : -h};
        double c[3] = {cx, cy, cz};
        for (int r = 0; r < 3; ++r)
            m.pos.push_back(c[r] + R[3 * r] * l[0] + R[3 * r + 1] * l[1] + R[3 * r + 2] * l[2]);
    }
    m.idx = {0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4,
             2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6, 2, 1, 3, 7, 1, 7, 5};
    return m;
}

TriangleBvh bvhOf(const Mesh& m) {
    TriangleBvh b;
    b.build(m.pos.data(), m.vertexCount(), m.idx.data(), m.triangleCount());
    return b;
}

ClosestPair bruteForce(const Mesh& a, const Mesh& b) {
    ClosestPair r;
    bool have = false;
    for (size_t i = 0; i < a.triangleCount(); ++i)
        for (size_t j = 0; j < b.triangleCount(); ++j) {
            double pa[3], pb[3];
            bool inter = false;
            double d = triangleTriangleDistance(a.corner(i, 0), a.corner(i, 1), a.corner(i, 2),
                                                b.corner(j, 0), b.corner(j, 1), b.corner(j, 2),
                                                pa, pb, &inter);
            if (!have || d < r.distance) {  // strict: the lowest (i, j) pair wins ties
                have = true;
                r.distance = d;
                std::memcpy(r.pointA, pa, sizeof pa);
                std::memcpy(r.pointB, pb, sizeof pb);
                r.triangleA = uint32_t(i);
                r.triangleB = uint32_t(j);
                r.intersecting = inter;
            }
        }
    return r;
}

ClosestPoint bruteForcePoint(const Mesh& m, const double p[3]) {
    ClosestPoint r;
    for (size_t t = 0; t < m.triangleCount(); ++t) {
        double q[3];
        double d = pointTriangleDistance(p, m.corner(t, 0), m.corner(t, 1), m.corner(t, 2), q);
        if (d < r.distance) {
            r.distance = d;
            std::memcpy(r.point, q, sizeof q);
            r.triangle = uint32_t(t);
        }
    }
    return r;
}

double dist(const double* a, const double* b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
}

bool finite3(const double* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }

void expectPair(const ClosestPair& r, double expected, double tol = 1e-12) {
    EXPECT_NEAR(r.distance, expected, tol);
    EXPECT_NEAR(dist(r.pointA, r.pointB), r.distance, 1e-12);
    EXPECT_EQ(r.intersecting, r.distance == 0);
}

}  // namespace

// ---- primitives -----------------------------------------------------------------------------

TEST(MeshDistancePrimitives, PointTriangleRegions) {
    const double a[3] = {0, 0, 0}, b[3] = {4, 0, 0}, c[3] = {0, 4, 0};
    double q[3];
    const double interior[3] = {1, 1, 2.5};
    EXPECT_DOUBLE_EQ(pointTriangleDistance(interior, a, b, c, q), 2.5);
    EXPECT_DOUBLE_EQ(q[0], 1);
    EXPECT_DOUBLE_EQ(q[1], 1);
    EXPECT_DOUBLE_EQ(q[2], 0);
    const double vertexRegion[3] = {-3, -4, 0};
    EXPECT_DOUBLE_EQ(pointTriangleDistance(vertexRegion, a, b, c, q), 5);
    const double edgeRegion[3] = {2, -3, 4};  // closest (2,0,0)
    EXPECT_DOUBLE_EQ(pointTriangleDistance(edgeRegion, a, b, c, q), 5);
    EXPECT_DOUBLE_EQ(q[0], 2);
    const double hypotenuse[3] = {3, 3, 0};  // closest (2,2,0)
    EXPECT_NEAR(pointTriangleDistance(hypotenuse, a, b, c, q), std::sqrt(2.0), 1e-15);
}

TEST(MeshDistancePrimitives, PointTriangleDegenerate) {
    double q[3];
    const double p[3] = {1.5, 1, 0};
    // Collinear (zero area): closest point on the segment (0,0,0)-(2,0,0).
    const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {2, 0, 0};
    EXPECT_DOUBLE_EQ(pointTriangleDistance(p, a, b, c, q), 1);
    EXPECT_DOUBLE_EQ(q[0], 1.5);
    // Repeated vertex a == b: a segment a-c.
    EXPECT_DOUBLE_EQ(pointTriangleDistance(p, a, a, c, q), 1);
    EXPECT_DOUBLE_EQ(q[0], 1.5);
    EXPECT_DOUBLE_EQ(pointTriangleDistance(p, c, a, a, q), 1);
    // All three vertices equal: a point.
    EXPECT_DOUBLE_EQ(pointTriangleDistance(p, c, c, c, q), std::sqrt(0.25 + 1));
    EXPECT_TRUE(finite3(q));
}

TEST(MeshDistancePrimitives, PointTriangleAgainstSampling) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int iter = 0; iter < 200; ++iter) {
        double a[3], b[3], c[3], p[3];
        for (int k = 0; k < 3; ++k) a[k] = u(rng), b[k] = u(rng), c[k] = u(rng), p[k] = 2 * u(rng);
        double q[3];
        double d = pointTriangleDistance(p, a, b, c, q);
        ASSERT_TRUE(std::isfinite(d));
        EXPECT_NEAR(dist(p, q), d, 1e-14);
        // q lies on the triangle: its distance to the triangle is ~0.
        double q2[3];
        EXPECT_LT(pointTriangleDistance(q, a, b, c, q2), 1e-14);
        // No sampled point of the triangle is closer.
        const int n = 40;
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                double s = double(i) / n, t = double(j) / n, x[3];
                for (int k = 0; k < 3; ++k) x[k] = a[k] + s * (b[k] - a[k]) + t * (c[k] - a[k]);
                ASSERT_GE(dist(p, x), d - 1e-13);
            }
    }
}

TEST(MeshDistancePrimitives, SegmentSegmentCases) {
    double c1[3], c2[3], s, t;
    // Skew, interior closest points.
    const double p1[3] = {-1, 0, 0}, q1[3] = {1, 0, 0}, p2[3] = {0, -1, 2}, q2[3] = {0, 1, 2};
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(p1, q1, p2, q2, c1, c2, &s, &t), 2);
    EXPECT_DOUBLE_EQ(s, 0.5);
    EXPECT_DOUBLE_EQ(t, 0.5);
    // Parallel, overlapping in projection.
    const double a0[3] = {0, 0, 0}, a1[3] = {2, 0, 0}, b0[3] = {1, 1, 0}, b1[3] = {3, 1, 0};
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(a0, a1, b0, b1, c1, c2), 1);
    // Parallel, anti-parallel direction.
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(a0, a1, b1, b0, c1, c2), 1);
    // Collinear, disjoint.
    const double d0[3] = {3, 0, 0}, d1[3] = {4, 0, 0};
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(a0, a1, d0, d1, c1, c2), 1);
    EXPECT_DOUBLE_EQ(c1[0], 2);
    EXPECT_DOUBLE_EQ(c2[0], 3);
    // Parallel, disjoint in projection: endpoints (2,0,0)-(3,1,0).
    const double e0[3] = {3, 1, 0}, e1[3] = {5, 1, 0};
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(a0, a1, e0, e1, c1, c2), std::sqrt(2.0));
    // Degenerate: point vs segment, point vs point.
    const double pt[3] = {1, 5, 0};
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(pt, pt, a0, a1, c1, c2), 5);
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(a0, a1, pt, pt, c1, c2), 5);
    EXPECT_DOUBLE_EQ(segmentSegmentDistance(pt, pt, a0, a0, c1, c2), std::sqrt(26.0));
    EXPECT_TRUE(finite3(c1) && finite3(c2));
    // Nearly parallel (angle 1e-9): the minimum is at an endpoint.
    const double f0[3] = {0, 1, 0}, f1[3] = {2, 1 + 2e-9, 0};
    EXPECT_NEAR(segmentSegmentDistance(a0, a1, f0, f1, c1, c2), 1, 1e-15);
}

TEST(MeshDistancePrimitives, SegmentSegmentAgainstSampling) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1);
    for (int iter = 0; iter < 300; ++iter) {
        double p1[3], q1[3], p2[3], q2[3];
        for (int k = 0; k < 3; ++k) p1[k] = u(rng), q1[k] = u(rng), p2[k] = u(rng), q2[k] = u(rng);
        if (iter % 3 == 0)  // parallel
            for (int k = 0; k < 3; ++k) q2[k] = p2[k] + 0.7 * (q1[k] - p1[k]);
        double c1[3], c2[3], s, t;
        double d = segmentSegmentDistance(p1, q1, p2, q2, c1, c2, &s, &t);
        EXPECT_NEAR(dist(c1, c2), d, 1e-14);
        EXPECT_GE(s, 0);
        EXPECT_LE(s, 1);
        const int n = 400;
        double sampled = kInf;
        for (int i = 0; i <= n; ++i) {
            double x[3];
            for (int k = 0; k < 3; ++k) x[k] = p1[k] + (q1[k] - p1[k]) * i / n;
            double y[3], yd[3];
            // Exact distance from x to segment 2 (a degenerate triangle).
            sampled = std::min(sampled, pointTriangleDistance(x, p2, q2, q2, yd));
            (void)y;
        }
        EXPECT_LE(d, sampled + 1e-14);
        EXPECT_GE(d, sampled - 2.0 * dist(p1, q1) / n);  // sampling step bound
    }
}

TEST(MeshDistancePrimitives, TriangleTriangleKnownCases) {
    double pa[3], pb[3];
    bool inter = false;
    // Coarse pair, closest point on A in the interior of A's face (vertex of B above it).
    const double a0[3] = {0, 0, 0}, a1[3] = {10, 0, 0}, a2[3] = {0, 10, 0};
    const double b0[3] = {3, 3, 0.5}, b1[3] = {9, 8, 7}, b2[3] = {-4, 8, 6};
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(a0, a1, a2, b0, b1, b2, pa, pb, &inter), 0.5);
    EXPECT_FALSE(inter);
    EXPECT_DOUBLE_EQ(pa[0], 3);
    EXPECT_DOUBLE_EQ(pa[1], 3);
    EXPECT_DOUBLE_EQ(pa[2], 0);
    // And the symmetric role: closest point on the second triangle is interior.
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(b0, b1, b2, a0, a1, a2, pa, pb, &inter), 0.5);
    EXPECT_DOUBLE_EQ(pb[0], 3);
    EXPECT_DOUBLE_EQ(pb[1], 3);

    // Parallel faces overlapping in projection: distance = plane gap.
    const double c0[3] = {1, 1, 0.25}, c1[3] = {5, 1, 0.25}, c2[3] = {1, 5, 0.25};
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(a0, a1, a2, c0, c1, c2, pa, pb, &inter), 0.25);

    // Edge of B piercing A's interior (no vertex or edge of either is near the other).
    const double d0[3] = {2, 2, -1}, d1[3] = {2, 2, 1}, d2[3] = {30, 30, 0};
    EXPECT_EQ(triangleTriangleDistance(a0, a1, a2, d0, d1, d2, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    EXPECT_DOUBLE_EQ(pa[0], 2);
    EXPECT_DOUBLE_EQ(pa[2], 0);
    EXPECT_EQ(pa[0], pb[0]);

    // Coplanar overlap without any vertex inside the other (star of David).
    const double s0[3] = {0, 0, 0}, s1[3] = {6, 0, 0}, s2[3] = {3, 5, 0};
    const double t0[3] = {0, 3.5, 0}, t1[3] = {3, -1.5, 0}, t2[3] = {6, 3.5, 0};
    EXPECT_EQ(triangleTriangleDistance(s0, s1, s2, t0, t1, t2, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    // Coplanar, one inside the other.
    const double u0[3] = {1, 1, 0}, u1[3] = {2, 1, 0}, u2[3] = {1, 2, 0};
    EXPECT_EQ(triangleTriangleDistance(a0, a1, a2, u0, u1, u2, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    // Coplanar, disjoint: 2D distance.
    const double v0[3] = {11, 0, 0}, v1[3] = {12, 0, 0}, v2[3] = {11, 1, 0};
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(a0, a1, a2, v0, v1, v2, pa, pb, &inter), 1);
    EXPECT_FALSE(inter);
}

TEST(MeshDistancePrimitives, TriangleTriangleRotatedCoplanarOverlap) {
    // The same star of David, rotated and moved off the axes: coordinates are no longer
    // exactly coplanar, the pair must still be reported as intersecting.
    Mat3 R = mul(axisAngle(1, 2, 3, 0.7), axisAngle(-2, 0.5, 1, 1.9));
    double P[6][3] = {{0, 0, 0}, {6, 0, 0}, {3, 5, 0}, {0, 3.5, 0}, {3, -1.5, 0}, {6, 3.5, 0}};
    double Q[6][3];
    for (int i = 0; i < 6; ++i)
        for (int r = 0; r < 3; ++r)
            Q[i][r] = 0.123 + R[3 * r] * P[i][0] + R[3 * r + 1] * P[i][1] + R[3 * r + 2] * P[i][2];
    double pa[3], pb[3];
    bool inter = false;
    EXPECT_EQ(triangleTriangleDistance(Q[0], Q[1], Q[2], Q[3], Q[4], Q[5], pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    EXPECT_EQ(triangleTriangleDistance(Q[3], Q[4], Q[5], Q[0], Q[1], Q[2], pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
}

// Pairs from the side and top faces of a rotated generated box (a mesh that does not cross
// itself): an edge of one triangle lies in the plane of the other, on the line of its edge,
// and the rounding noise of the side tests used to count that as a crossing.
TEST(MeshDistancePrimitives, TriangleTriangleEdgeInTheOtherPlaneIsNoCrossing) {
    const double side[9] = {12.39478509518012, -6.2757406528578841, 4.3551169703244552,
                            12.186235661723968, -6.1722718991705534, 4.3551169703244552,
                            12.186235661723968, -6.1722718991705534, 4.5893663581302215};
    const double top[9] = {11.977686228267817, -6.0688031454832236, 4.5893663581302215,
                           11.769136794811665, -5.965334391795893, 4.5893663581302215,
                           11.664184656698058, -6.1768737035551355, 4.5893663581302215};
    double pa[3], pb[3];
    bool inter = true;
    const double d = triangleTriangleDistance(side, side + 3, side + 6, top, top + 3, top + 6, pa, pb, &inter);
    EXPECT_FALSE(inter);
    EXPECT_NEAR(d, 0.232806, 1e-6);
    inter = true;
    EXPECT_NEAR(triangleTriangleDistance(top, top + 3, top + 6, side, side + 3, side + 6, pa, pb, &inter), d, 1e-12);
    EXPECT_FALSE(inter);
    // Two triangles of one vertical face, apart in their common plane.
    const double low[9] = {13.24986546348652, -3.0300803290803318, 1.543487077459887,
                           13.244200621978434, -2.7160081806265213, 1.543487077459887,
                           13.244200621978434, -2.7160081806265213, 1.8473885164430843};
    const double high[9] = {13.24986546348652, -3.0300803290803318, 2.4551913944094794,
                            13.244200621978434, -2.7160081806265213, 2.7590928333926765,
                            13.24986546348652, -3.0300803290803318, 2.7590928333926765};
    inter = true;
    // At least their gap in z apart.
    EXPECT_GT(triangleTriangleDistance(low, low + 3, low + 6, high, high + 3, high + 6, pa, pb, &inter),
              2.4551913944094794 - 1.8473885164430843);
    EXPECT_FALSE(inter);
}

TEST(MeshDistancePrimitives, TriangleTriangleDegenerate) {
    double pa[3], pb[3];
    bool inter = false;
    const double a0[3] = {0, 0, 0}, a1[3] = {4, 0, 0}, a2[3] = {0, 4, 0};
    // Zero-area triangle (segment) piercing A.
    const double s0[3] = {1, 1, -1}, s1[3] = {1, 1, 1};
    EXPECT_EQ(triangleTriangleDistance(a0, a1, a2, s0, s1, s1, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    EXPECT_EQ(triangleTriangleDistance(s0, s1, s0, a0, a1, a2, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    // Zero-area triangle above A.
    const double h0[3] = {1, 1, 2}, h1[3] = {1, 1, 3};
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(a0, a1, a2, h0, h1, h1, pa, pb, &inter), 2);
    // Point triangle inside A, and above A.
    const double in[3] = {1, 1, 0}, above[3] = {1, 1, 0.5};
    EXPECT_EQ(triangleTriangleDistance(a0, a1, a2, in, in, in, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(a0, a1, a2, above, above, above, pa, pb, &inter), 0.5);
    // Two segments crossing, two points.
    const double x0[3] = {-1, 0, 0}, x1[3] = {1, 0, 0}, y0[3] = {0, -1, 0}, y1[3] = {0, 1, 0};
    EXPECT_EQ(triangleTriangleDistance(x0, x1, x1, y0, y1, y0, pa, pb, &inter), 0);
    EXPECT_TRUE(inter);
    const double z0[3] = {0, -1, 3}, z1[3] = {0, 1, 3};
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(x0, x1, x0, z0, z1, z1, pa, pb, &inter), 3);
    EXPECT_DOUBLE_EQ(triangleTriangleDistance(x0, x0, x0, z0, z0, z0, pa, pb, &inter),
                     std::sqrt(1.0 + 1.0 + 9.0));
    EXPECT_TRUE(finite3(pa) && finite3(pb));
}

TEST(MeshDistancePrimitives, TriangleTriangleAgainstSampling) {
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1, 1);
    int intersecting = 0;
    for (int iter = 0; iter < 300; ++iter) {
        double T[6][3];
        for (int i = 0; i < 6; ++i)
            for (int k = 0; k < 3; ++k) T[i][k] = u(rng) + (i >= 3 && k == 0 ? 0.8 : 0.0);
        double pa[3], pb[3];
        bool inter = false;
        double d = triangleTriangleDistance(T[0], T[1], T[2], T[3], T[4], T[5], pa, pb, &inter);
        ASSERT_TRUE(std::isfinite(d));
        EXPECT_NEAR(dist(pa, pb), d, 1e-14);
        double tmp[3];
        EXPECT_LT(pointTriangleDistance(pa, T[0], T[1], T[2], tmp), 1e-13);
        EXPECT_LT(pointTriangleDistance(pb, T[3], T[4], T[5], tmp), 1e-13);
        intersecting += inter;
        // Sample A densely; exact distance of each sample to B bounds d from above.
        const int n = 60;
        double sampled = kInf;
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                double s = double(i) / n, t = double(j) / n, x[3];
                for (int k = 0; k < 3; ++k) x[k] = T[0][k] + s * (T[1][k] - T[0][k]) + t * (T[2][k] - T[0][k]);
                sampled = std::min(sampled, pointTriangleDistance(x, T[3], T[4], T[5], tmp));
            }
        EXPECT_LE(d, sampled + 1e-13) << iter;
        if (!inter) {
            // Separated triangles: sampled minimum converges to d (step ~ 2/n).
            EXPECT_GE(d, sampled - 0.1) << iter;
        }
    }
    EXPECT_GT(intersecting, 10);  // the set does exercise the intersection path
}

// ---- cubes ------------------------------------------------------------------------------

TEST(MeshDistance, CubesFaceFace) {
    Mesh a = cube(0, 0, 0), b = cube(1.25, 0.3, -0.2);  // gap 0.25 along x
    TriangleBvh ba = bvhOf(a), bb = bvhOf(b);
    ClosestPair r = meshDistance(ba, bb);
    expectPair(r, 0.25, 0);
    EXPECT_FALSE(r.intersecting);
    EXPECT_DOUBLE_EQ(r.pointA[0], 0.5);
    EXPECT_DOUBLE_EQ(r.pointB[0], 0.75);
    ClosestPair bf = bruteForce(a, b);
    EXPECT_EQ(r.triangleA, bf.triangleA);
    EXPECT_EQ(r.triangleB, bf.triangleB);
}

TEST(MeshDistance, CubesEdgeEdgeSkew) {
    // A: top edge along x at z = sqrt(2)/2; B: bottom edge along y at z = cz - sqrt(2)/2.
    const double pi = std::acos(-1.0), gap = 0.3, h = std::sqrt(2.0) / 2;
    Mesh a = cube(0, 0, 0, 1, axisAngle(1, 0, 0, pi / 4));
    Mesh b = cube(0, 0, 2 * h + gap, 1, axisAngle(0, 1, 0, pi / 4));
    ClosestPair r = meshDistance(bvhOf(a), bvhOf(b));
    expectPair(r, gap, 1e-14);
    EXPECT_NEAR(r.pointA[0], 0, 1e-14);
    EXPECT_NEAR(r.pointA[1], 0, 1e-14);
    EXPECT_NEAR(r.pointA[2], h, 1e-14);
    EXPECT_NEAR(r.pointB[2], h + gap, 1e-14);
}

TEST(MeshDistance, CubesVertexFace) {
    // B stands on a vertex: its main diagonal is vertical, lowest vertex sqrt(3)/2 below centre.
    const double gap = 0.125, s3 = std::sqrt(3.0);
    // Rotate (1,1,1)/sqrt3 onto (0,0,1): axis (1,1,1) x (0,0,1) = (1,-1,0), angle acos(1/sqrt3).
    Mat3 R = axisAngle(1, -1, 0, std::acos(1 / s3));
    Mesh a = cube(0, 0, 0), b = cube(0, 0, 0.5 + gap + s3 / 2, 1, R);
    ClosestPair r = meshDistance(bvhOf(a), bvhOf(b));
    expectPair(r, gap, 1e-14);
    EXPECT_NEAR(r.pointA[0], 0, 1e-14);
    EXPECT_NEAR(r.pointA[1], 0, 1e-14);
    EXPECT_NEAR(r.pointA[2], 0.5, 1e-14);
    EXPECT_NEAR(r.pointB[2], 0.5 + gap, 1e-14);
}

TEST(MeshDistance, RotatedCubeVsCube) {
    // B rotated by theta about z: its vertical edge nearest to A is at x = cx - (cos + sin)/2.
    const double theta = 0.4, cx = 2.0;
    Mesh a = cube(0, 0, 0), b = cube(cx, 0.1, 0.05, 1, axisAngle(0, 0, 1, theta));
    ClosestPair r = meshDistance(bvhOf(a), bvhOf(b));
    double expected = cx - 0.5 - (std::cos(theta) + std::sin(theta)) / 2;
    expectPair(r, expected, 1e-14);
    ClosestPair bf = bruteForce(a, b);
    EXPECT_EQ(r.distance, bf.distance);
    EXPECT_EQ(r.triangleA, bf.triangleA);
    EXPECT_EQ(r.triangleB, bf.triangleB);
    // Generic rotation: against brute force.
    Mesh c = cube(0.3, 1.6, -0.4, 0.8, mul(axisAngle(1, 2, 3, 0.9), axisAngle(3, -1, 0.2, 2.1)));
    ClosestPair rc = meshDistance(bvhOf(a), bvhOf(c));
    ClosestPair bc = bruteForce(a, c);
    EXPECT_GT(rc.distance, 0);
    EXPECT_EQ(rc.distance, bc.distance);
}

TEST(MeshDistance, IntersectingAndTouchingCubes) {
    Mesh a = cube(0, 0, 0);
    ClosestPair r = meshDistance(bvhOf(a), bvhOf(cube(0.5, 0.3, 0.2)));
    EXPECT_EQ(r.distance, 0);
    EXPECT_TRUE(r.intersecting);
    EXPECT_EQ(r.pointA[0], r.pointB[0]);
    // Rotated intersecting cube.
    r = meshDistance(bvhOf(a), bvhOf(cube(0.9, 0.1, 0, 1, axisAngle(1, 1, 0, 0.6))));
    EXPECT_EQ(r.distance, 0);
    EXPECT_TRUE(r.intersecting);
    // Face-to-face contact (gap exactly 0) counts as intersecting.
    r = meshDistance(bvhOf(a), bvhOf(cube(1, 0.25, 0.5)));
    EXPECT_EQ(r.distance, 0);
    EXPECT_TRUE(r.intersecting);
    // Identical cubes.
    r = meshDistance(bvhOf(a), bvhOf(a));
    EXPECT_EQ(r.distance, 0);
    EXPECT_EQ(r.triangleA, 0u);
    EXPECT_EQ(r.triangleB, 0u);
}

TEST(MeshDistance, CoarseTrianglesInteriorClosestPoints) {
    // One big triangle each: closest point on A is deep inside A's face, on B deep inside
    // B's face would need parallel faces, so use parallel faces offset in the plane.
    Mesh a, b;
    a.pos = {0, 0, 0, 100, 0, 0, 0, 100, 0};
    a.idx = {0, 1, 2};
    b.pos = {20, 20, 3, 60, 25, 3, 25, 60, 3};
    b.idx = {0, 1, 2};
    ClosestPair r = meshDistance(bvhOf(a), bvhOf(b));
    expectPair(r, 3, 0);
    // Tilted B touching down with one vertex at an interior point of A.
    b.pos = {30, 35, 0.75, 80, 20, 40, 10, 70, 50};
    r = meshDistance(bvhOf(a), bvhOf(b));
    expectPair(r, 0.75, 0);
    EXPECT_EQ(r.pointA[0], 30);
    EXPECT_EQ(r.pointA[1], 35);
    EXPECT_EQ(r.pointA[2], 0);
}

TEST(MeshDistance, MaxDistanceAndStopBelow) {
    Mesh a = cube(0, 0, 0), b = cube(2.5, 0, 0);  // gap 1.5
    TriangleBvh ba = bvhOf(a), bb = bvhOf(b);
    ClosestPair r = meshDistance(ba, bb, 1.0);
    EXPECT_EQ(r.distance, kInf);
    EXPECT_EQ(r.triangleA, ~0u);
    EXPECT_EQ(r.triangleB, ~0u);
    EXPECT_FALSE(r.intersecting);
    r = meshDistance(ba, bb, 1.5);  // inclusive
    EXPECT_EQ(r.distance, 1.5);
    r = meshDistance(ba, bb, 10.0);
    EXPECT_EQ(r.distance, 1.5);
    r = meshDistance(ba, bb, kInf, 100.0);  // early exit: some pair within 100
    EXPECT_LE(r.distance, 100.0);
    EXPECT_GE(r.distance, 1.5);
    double pa[3], pb[3];
    const Mesh& ma = a;
    const Mesh& mb = b;
    double d = triangleTriangleDistance(ma.corner(r.triangleA, 0), ma.corner(r.triangleA, 1),
                                        ma.corner(r.triangleA, 2), mb.corner(r.triangleB, 0),
                                        mb.corner(r.triangleB, 1), mb.corner(r.triangleB, 2), pa, pb,
                                        nullptr);
    EXPECT_EQ(d, r.distance);
    // Empty meshes.
    TriangleBvh empty;
    empty.build(nullptr, 0, nullptr, 0);
    EXPECT_EQ(meshDistance(empty, bb).distance, kInf);
    EXPECT_EQ(closestPoint(empty, pa).triangle, ~0u);
    EXPECT_FALSE(anyWithin(empty, pa, kInf));
    double lo[3], hi[3];
    empty.bounds(lo, hi);
    EXPECT_EQ(lo[0], kInf);
    EXPECT_EQ(hi[0], -kInf);
}

TEST(MeshDistance, BadIndicesThrow) {
    Mesh a = cube(0, 0, 0);
    a.idx[5] = 8;
    TriangleBvh b;
    EXPECT_THROW(b.build(a.pos.data(), a.vertexCount(), a.idx.data(), a.triangleCount()),
                 std::invalid_argument);
    Mesh c = cube(0, 0, 0);
    c.pos[4] = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(b.build(c.pos.data(), c.vertexCount(), c.idx.data(), c.triangleCount()),
                 std::invalid_argument);
    c.pos[4] = kInf;
    EXPECT_THROW(b.build(c.pos.data(), c.vertexCount(), c.idx.data(), c.triangleCount()),
                 std::invalid_argument);
}

// ---- random meshes vs brute force --------------------------------------------------------

namespace {

// Random triangle soup: clustered small triangles (so the BVH has structure), some long
// slivers, and degenerate ones (repeated vertex, collinear, single point).
Mesh randomMesh(std::mt19937& rng, int triangles, double scale, const double offset[3]) {
    std::uniform_real_distribution<double> u(0, 1);
    Mesh m;
    for (int t = 0; t < triangles; ++t) {
        double c[3], v[3][3];
        for (int k = 0; k < 3; ++k) c[k] = u(rng);
        double size = u(rng) < 0.2 ? 0.8 : 0.15;
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) v[i][k] = c[k] + size * (u(rng) - 0.5);
        uint32_t kind = rng() % 20;
        if (kind == 0) std::memcpy(v[1], v[0], sizeof v[0]);                   // repeated vertex
        if (kind == 1)
            for (int k = 0; k < 3; ++k) v[2][k] = 0.5 * (v[0][k] + v[1][k]);  // collinear
        if (kind == 2) std::memcpy(v[1], v[0], sizeof v[0]), std::memcpy(v[2], v[0], sizeof v[0]);
        for (int i = 0; i < 3; ++i) {
            m.idx.push_back(uint32_t(m.pos.size() / 3));
            for (int k = 0; k < 3; ++k) m.pos.push_back(offset[k] + scale * v[i][k]);
        }
    }
    // A shared-vertex fan, too (indexed mesh, not only a soup).
    uint32_t base = uint32_t(m.pos.size() / 3);
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 3; ++k) m.pos.push_back(offset[k] + scale * u(rng));
    for (uint32_t i = 1; i + 1 < 6; ++i) m.idx.insert(m.idx.end(), {base, base + i, base + i + 1});
    return m;
}

}  // namespace

TEST(MeshDistance, RandomMeshesMatchBruteForce) {
    int intersecting = 0;
    for (uint32_t seed = 1; seed <= 200; ++seed) {
        std::mt19937 rng(seed);
        std::uniform_real_distribution<double> u(0, 1);
        // Some seeds far from the origin and at other scales (rounding-slack pruning).
        double scale = seed % 7 == 0 ? 1e-3 : (seed % 11 == 0 ? 250.0 : 1.0);
        double origin = seed % 5 == 0 ? 1000.0 : 0.0;
        double offA[3] = {origin, origin, origin};
        double offB[3];
        for (int k = 0; k < 3; ++k) offB[k] = origin + scale * 2.5 * u(rng) * (k == 0 ? 1 : 0.4);
        Mesh a = randomMesh(rng, 5 + int(rng() % 60), scale, offA);
        Mesh b = randomMesh(rng, 5 + int(rng() % 60), scale, offB);
        TriangleBvh ba = bvhOf(a), bb = bvhOf(b);
        ClosestPair r = meshDistance(ba, bb);
        ClosestPair bf = bruteForce(a, b);
        ASSERT_TRUE(std::isfinite(r.distance)) << seed;
        EXPECT_NEAR(r.distance, bf.distance, 1e-12 * bf.distance) << seed;
        // Stronger: identical result, including the tie rule and the points.
        EXPECT_EQ(r.distance, bf.distance) << seed;
        EXPECT_EQ(r.triangleA, bf.triangleA) << seed;
        EXPECT_EQ(r.triangleB, bf.triangleB) << seed;
        EXPECT_EQ(std::memcmp(r.pointA, bf.pointA, sizeof r.pointA), 0) << seed;
        EXPECT_EQ(r.intersecting, bf.intersecting) << seed;
        intersecting += r.intersecting;

        // Swapped arguments: same distance up to rounding (features are evaluated in another
        // order, so the bits may differ).
        EXPECT_NEAR(meshDistance(bb, ba).distance, r.distance, 1e-13 * (r.distance + scale)) << seed;
        // maxDistance below the minimum prunes everything; above it changes nothing.
        if (bf.distance > 0) {
            EXPECT_EQ(meshDistance(ba, bb, bf.distance * 0.999).distance, kInf);
        }
        ClosestPair rm = meshDistance(ba, bb, bf.distance * 1.5 + 1e-300);
        EXPECT_EQ(rm.distance, r.distance);
        EXPECT_EQ(rm.triangleA, r.triangleA);
        // Early exit returns a genuine pair within the bound.
        double stop = bf.distance + scale * 0.5;
        ClosestPair re = meshDistance(ba, bb, kInf, stop);
        EXPECT_LE(re.distance, stop);
        double pa[3], pb[3];
        EXPECT_EQ(triangleTriangleDistance(a.corner(re.triangleA, 0), a.corner(re.triangleA, 1),
                                           a.corner(re.triangleA, 2), b.corner(re.triangleB, 0),
                                           b.corner(re.triangleB, 1), b.corner(re.triangleB, 2), pa, pb,
                                           nullptr),
                  re.distance);

        // Closest point from random query points vs brute force.
        for (int q = 0; q < 20; ++q) {
            double p[3];
            for (int k = 0; k < 3; ++k) p[k] = origin + scale * (3 * u(rng) - 1);
            ClosestPoint cp = closestPoint(ba, p);
            ClosestPoint bp = bruteForcePoint(a, p);
            EXPECT_NEAR(cp.distance, bp.distance, 1e-12 * bp.distance) << seed;
            EXPECT_EQ(cp.distance, bp.distance) << seed;
            EXPECT_EQ(cp.triangle, bp.triangle) << seed;
            EXPECT_EQ(std::memcmp(cp.point, bp.point, sizeof cp.point), 0) << seed;
            ClosestPoint cm = closestPoint(ba, p, bp.distance * 0.999);
            if (bp.distance > 0) {
                EXPECT_EQ(cm.triangle, ~0u);
            }
            // Yes exactly at the closest distance and above it, no just below it.
            EXPECT_TRUE(anyWithin(ba, p, bp.distance)) << seed;
            EXPECT_TRUE(anyWithin(ba, p, bp.distance * 1.5 + 1e-3)) << seed;
            if (bp.distance > 0) {
                EXPECT_FALSE(anyWithin(ba, p, std::nextafter(bp.distance, 0.0))) << seed;
            }
        }
    }
    EXPECT_GT(intersecting, 20);
    EXPECT_LT(intersecting, 180);
}

TEST(MeshDistance, LargerRandomMeshesMatchBruteForce) {
    // Deeper trees (~100 leaves each), separated, touching-close and interpenetrating.
    const double gaps[4] = {2.6, 2.2, 0.9, 0.5};
    int separated = 0, intersecting = 0;
    for (uint32_t seed = 0; seed < 4; ++seed) {
        std::mt19937 rng(1000 + seed);
        double offA[3] = {0, 0, 0}, offB[3] = {gaps[seed], 0.1, -0.05};
        Mesh a = randomMesh(rng, 400, 1.0, offA), b = randomMesh(rng, 400, 1.0, offB);
        ClosestPair r = meshDistance(bvhOf(a), bvhOf(b));
        ClosestPair bf = bruteForce(a, b);
        EXPECT_EQ(r.distance, bf.distance) << seed;
        EXPECT_EQ(r.triangleA, bf.triangleA) << seed;
        EXPECT_EQ(r.triangleB, bf.triangleB) << seed;
        EXPECT_EQ(r.intersecting, bf.intersecting) << seed;
        (r.intersecting ? intersecting : separated) += 1;
    }
    EXPECT_GE(separated, 1);
    EXPECT_GE(intersecting, 1);
}

TEST(MeshDistance, BvhStructureAndDeterminism) {
    std::mt19937 rng(99);
    double off[3] = {0, 0, 0};
    Mesh m = randomMesh(rng, 3000, 1.0, off);
    TriangleBvh b1 = bvhOf(m), b2 = bvhOf(m);
    ASSERT_EQ(b1.triangleCount(), m.triangleCount());
    const auto& nodes = b1.nodes();
    std::vector<int> seen(m.triangleCount(), 0);
    for (size_t i = 0; i < nodes.size(); ++i) {
        const auto& n = nodes[i];
        if (n.count) {
            EXPECT_LE(n.count, 4u);
            for (uint32_t s = n.first; s < n.first + n.count; ++s) {
                ++seen[b1.slotTriangle(s)];
                const double* c = b1.slotCorners(s);
                for (int v = 0; v < 3; ++v)
                    for (int k = 0; k < 3; ++k) {
                        EXPECT_GE(c[3 * v + k], n.lo[k]);
                        EXPECT_LE(c[3 * v + k], n.hi[k]);
                    }
            }
        } else {
            for (uint32_t ch = n.first; ch < n.first + 2; ++ch)
                for (int k = 0; k < 3; ++k) {
                    EXPECT_GE(nodes[ch].lo[k], n.lo[k]);
                    EXPECT_LE(nodes[ch].hi[k], n.hi[k]);
                }
        }
    }
    for (int s : seen) EXPECT_EQ(s, 1);
    ASSERT_EQ(b1.nodes().size(), b2.nodes().size());
    EXPECT_EQ(std::memcmp(b1.nodes().data(), b2.nodes().data(),
                          b1.nodes().size() * sizeof(TriangleBvh::Node)),
              0);
    double lo[3], hi[3];
    b1.bounds(lo, hi);
    EXPECT_EQ(lo[0], nodes[0].lo[0]);
    EXPECT_EQ(hi[2], nodes[0].hi[2]);

    // Same query twice -> same bits.
    double off2[3] = {0.9, 0.2, 0.1};
    Mesh m2 = randomMesh(rng, 2000, 1.0, off2);
    TriangleBvh c = bvhOf(m2);
    ClosestPair r1 = meshDistance(b1, c), r2 = meshDistance(b2, c);
    EXPECT_EQ(std::memcmp(&r1.distance, &r2.distance, sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(r1.pointA, r2.pointA, sizeof r1.pointA), 0);
    EXPECT_EQ(r1.triangleA, r2.triangleA);
    EXPECT_EQ(r1.triangleB, r2.triangleB);
}

TEST(MeshDistance, AllCentroidsEqual) {
    // Many triangles sharing one centroid (SAH cannot split): still leaves <= 4, correct.
    Mesh m;
    for (int i = 0; i < 37; ++i) {
        double a = 0.1 * i;
        double v[3][3] = {{std::cos(a), std::sin(a), 0}, {-std::cos(a), -std::sin(a), 0}, {0, 0, 1}};
        for (int k = 0; k < 3; ++k) v[1][k] = -v[0][k];
        for (int c = 0; c < 3; ++c) {
            m.idx.push_back(uint32_t(m.pos.size() / 3));
            for (int k = 0; k < 3; ++k) m.pos.push_back(v[c][k]);
        }
    }
    TriangleBvh b = bvhOf(m);
    for (const auto& n : b.nodes())
        if (n.count) {
            EXPECT_LE(n.count, 4u);
        }
    const double p[3] = {0.2, 0.1, 2};
    ClosestPoint cp = closestPoint(b, p);
    ClosestPoint bp = bruteForcePoint(m, p);
    EXPECT_EQ(cp.distance, bp.distance);
    EXPECT_EQ(cp.triangle, bp.triangle);
}

// selfIntersects (its grid of cells and the triangles too large for it)
// against every pair tested directly, on soups of many sizes: sheets of small triangles with
// a few large ones, mixed sizes, random soups that cross and ones that barely do not.
TEST(SelfIntersects, MatchesEveryPairTested) {
    auto bruteForce = [](const std::vector<double>& p, const std::vector<uint32_t>& t) {
        for (size_t a = 0; a < t.size() / 3; ++a)
            for (size_t b = a + 1; b < t.size() / 3; ++b) {
                bool shares = false;
                for (int x = 0; x < 3; ++x)
                    for (int y = 0; y < 3; ++y) shares = shares || t[3 * a + x] == t[3 * b + y];
                if (shares) continue;
                bool hit = false;
                triangleTriangleDistance(&p[3 * t[3 * a]], &p[3 * t[3 * a + 1]], &p[3 * t[3 * a + 2]], &p[3 * t[3 * b]],
                                         &p[3 * t[3 * b + 1]], &p[3 * t[3 * b + 2]], nullptr, nullptr, &hit);
                if (hit) return true;
            }
        return false;
    };
    std::mt19937 random(7);
    std::uniform_real_distribution<double> unit(0, 1);
    size_t crossing = 0, apart = 0;
    for (int round = 0; round < 300; ++round) {
        std::vector<double> p;
        std::vector<uint32_t> t;
        const int kind = round % 3;
        // 0: a flat grid of small triangles plus a few large ones above or through it;
        // 1: random triangles of mixed sizes; 2: large triangles of every orientation.
        if (kind == 0) {
            const int n = 6 + round % 9;
            for (int j = 0; j <= n; ++j)
                for (int i = 0; i <= n; ++i) p.insert(p.end(), {double(i) / n, double(j) / n, 0.0});
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) {
                    const uint32_t v = uint32_t(j * (n + 1) + i);
                    t.insert(t.end(), {v, v + 1, v + uint32_t(n) + 2, v, v + uint32_t(n) + 2, v + uint32_t(n) + 1});
                }
        }
        const int count = kind == 0 ? 1 + round % 3 : kind == 1 ? 40 : 30;
        for (int k = 0; k < count; ++k) {
            const double size = kind == 1 ? (k % 5 == 0 ? 0.5 : 0.03) : kind == 2 ? 0.6 : 0.8;
            const double c[3] = {unit(random), unit(random), kind == 0 ? 0.02 + 0.3 * unit(random) - (round % 4 == 0 ? 0.2 : 0) : unit(random)};
            const double depth = kind == 2 ? 1.0 : 0.2;
            const uint32_t base = uint32_t(p.size() / 3);
            for (int v = 0; v < 3; ++v)
                p.insert(p.end(), {c[0] + size * (unit(random) - 0.5), c[1] + size * (unit(random) - 0.5), c[2] + size * depth * (unit(random) - 0.5)});
            t.insert(t.end(), {base, base + 1, base + 2});
        }
        const bool expected = bruteForce(p, t);
        EXPECT_EQ(selfIntersects(p, t), expected) << "round " << round;
        (expected ? crossing : apart) += 1;
    }
    EXPECT_GT(crossing, 30u);
    EXPECT_GT(apart, 30u);
}
