// SPDX-License-Identifier: MIT
// Exact distances between points, segments and triangles in 3D (double arithmetic), for the
// sphere and capsule overlap queries of the collision world (an agent of radius r at a point,
// or swept along a segment). Closest point on a triangle after Ericson, "Real-Time Collision
// Detection", 5.1.5; segment-segment after 5.1.9. Standard library only.
#pragma once

#include <algorithm>
#include <cmath>

namespace aggrelod::runtime::distance {

struct V3 {
    double x, y, z;
};
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double length2(V3 a) { return dot(a, a); }

/// Closest point to p on triangle abc (degenerate triangles allowed).
inline V3 closestOnTriangle(V3 p, V3 a, V3 b, V3 c) {
    const V3 ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const V3 bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double den = d1 - d3;
        return den > 0 ? a + (d1 / den) * ab : a;
    }
    const V3 cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double den = d2 - d6;
        return den > 0 ? a + (d2 / den) * ac : a;
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double den = (d4 - d3) + (d5 - d6);
        return den > 0 ? b + ((d4 - d3) / den) * (c - b) : b;
    }
    const double sum = va + vb + vc;
    if (!(std::fabs(sum) > 0)) return a;  // degenerate: fall back to a vertex
    const double v = vb / sum, w = vc / sum;
    return a + v * ab + w * ac;
}

inline double pointTriangleDistance2(V3 p, V3 a, V3 b, V3 c) { return length2(p - closestOnTriangle(p, a, b, c)); }

/// Squared distance between segments p1q1 and p2q2.
inline double segmentSegmentDistance2(V3 p1, V3 q1, V3 p2, V3 q2) {
    const V3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    double s = 0, t = 0;
    if (a <= 0 && e <= 0) return length2(r);
    if (a <= 0) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = dot(d1, r);
        if (e <= 0) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = dot(d1, d2), denom = a * e - b * b;
            s = denom > 0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0) {
                t = 0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1) {
                t = 1;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    return length2((p1 + s * d1) - (p2 + t * d2));
}

/// True when segment pq crosses or touches triangle abc.
inline bool segmentHitsTriangle(V3 p, V3 q, V3 a, V3 b, V3 c) {
    const V3 n = cross(b - a, c - a);
    const double dp = dot(n, p - a), dq = dot(n, q - a);
    if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0)) return false;
    if (dp == dq) return false;  // parallel (coplanar cases are covered by the edge distances)
    const double t = dp / (dp - dq);
    const V3 x = p + t * (q - p);
    const V3 c1 = cross(b - a, x - a), c2 = cross(c - b, x - b), c3 = cross(a - c, x - c);
    const double s1 = dot(c1, n), s2 = dot(c2, n), s3 = dot(c3, n);
    return (s1 >= 0 && s2 >= 0 && s3 >= 0) || (s1 <= 0 && s2 <= 0 && s3 <= 0);
}

/// Squared distance between segment pq and triangle abc (0 when they meet): the minimum is
/// reached at an end of the segment against the triangle or at the segment against an edge.
inline double segmentTriangleDistance2(V3 p, V3 q, V3 a, V3 b, V3 c) {
    if (segmentHitsTriangle(p, q, a, b, c)) return 0;
    double d = std::min(pointTriangleDistance2(p, a, b, c), pointTriangleDistance2(q, a, b, c));
    d = std::min(d, segmentSegmentDistance2(p, q, a, b));
    d = std::min(d, segmentSegmentDistance2(p, q, b, c));
    d = std::min(d, segmentSegmentDistance2(p, q, c, a));
    return d;
}

}  // namespace aggrelod::runtime::distance
