// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: Euclidean projection onto an intersection of half-spaces (Seidel 1991,
// incremental, applied to the nearest point). See nearest_point_above_planes.h.
#include "nearest_point_above_planes.h"

#include <algorithm>
#include <cmath>

namespace aggrelod::detail {

bool nearestPointAbovePlanes(const HalfSpace* spaces, size_t count, Vec3 c, Vec3& out) {
    const double tiny = 1e-12;
    Vec3 x = c;
    for (size_t i = 0; i < count; ++i) {
        const HalfSpace& si = spaces[i];
        if (dot(si.normal, x) - si.offset >= 0) continue;
        // The optimum lies on plane i: y = origin + u e1 + v e2, with origin the projection of
        // c onto the plane, so that |y - c|^2 = |origin - c|^2 + u^2 + v^2.
        const Vec3 origin = c - (dot(si.normal, c) - si.offset) * si.normal;
        const Vec3 helper = std::fabs(si.normal.x) < 0.6 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
        Vec3 e1 = cross(si.normal, helper);
        e1 = (1 / length(e1)) * e1;
        const Vec3 e2 = cross(si.normal, e1);
        // Minimise u^2 + v^2 subject to a_j u + b_j v >= r_j for the half-spaces before i.
        double u = 0, v = 0;
        for (size_t j = 0; j < i; ++j) {
            const HalfSpace& sj = spaces[j];
            const double aj = dot(sj.normal, e1), bj = dot(sj.normal, e2);
            const double rj = sj.offset - dot(sj.normal, origin);
            if (aj * u + bj * v - rj >= 0) continue;
            const double aa = aj * aj + bj * bj;
            if (!(aa > tiny * tiny)) {  // parallel to plane i: the same plane (to rounding) or facing away
                if (rj > tiny * (1 + std::fabs(sj.offset))) return false;
                continue;
            }
            // The optimum lies on the line a_j u + b_j v = r_j: base + t (-b_j, a_j) / |(a_j, b_j)|,
            // t within the interval the half-spaces before j leave.
            const double la = std::sqrt(aa);
            const double baseU = aj * rj / aa, baseV = bj * rj / aa;
            const double du = -bj / la, dv = aj / la;
            double lo = -INFINITY, hi = INFINITY;
            for (size_t l = 0; l < j; ++l) {
                const HalfSpace& sl = spaces[l];
                const double al = dot(sl.normal, e1), bl = dot(sl.normal, e2);
                const double rl = sl.offset - dot(sl.normal, origin) - (al * baseU + bl * baseV);
                const double slope = al * du + bl * dv;
                if (slope > tiny) lo = std::max(lo, rl / slope);
                else if (slope < -tiny) hi = std::min(hi, rl / slope);
                else if (rl > tiny * (1 + std::fabs(sl.offset))) return false;  // parallel, facing away
            }
            if (lo > hi) {
                if (lo - hi > tiny * (1 + std::fabs(lo) + std::fabs(hi))) return false;
                lo = hi = 0.5 * (lo + hi);  // closed by rounding only
            }
            const double t = std::min(std::max(0.0, lo), hi);
            u = baseU + t * du;
            v = baseV + t * dv;
        }
        x = origin + u * e1 + v * e2;
    }
    out = x;
    return true;
}

}  // namespace aggrelod::detail
