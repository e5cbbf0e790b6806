// SPDX-License-Identifier: AGPL-3.0-or-later
// The independent referee of the planning tests: a returned 2D path against the original
// polygons, by dense samples along the path (every r / 8, inside a polygon) and, for each path
// segment, its exact distance to every original edge (ternary search on the convex distance).
#pragma once

#include <aggrelod/planning.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace aggrelod::testing {

struct Seg2 {
    double ax, ay, bx, by;
};

inline double pointSegDist(double px, double py, const Seg2& s) {
    const double dx = s.bx - s.ax, dy = s.by - s.ay, l2 = dx * dx + dy * dy;
    double t = l2 > 0 ? ((px - s.ax) * dx + (py - s.ay) * dy) / l2 : 0;
    t = std::max(0.0, std::min(1.0, t));
    return std::hypot(s.ax + t * dx - px, s.ay + t * dy - py);
}

// Minimum over t of a convex function on [0, 1] (ternary search).
template <class F>
inline double convexMin(F f) {
    double lo = 0, hi = 1;
    for (int i = 0; i < 100; ++i) {
        const double m1 = lo + (hi - lo) / 3, m2 = hi - (hi - lo) / 3;
        if (f(m1) < f(m2))
            hi = m2;
        else
            lo = m1;
    }
    return std::min({f(0.0), f(1.0), f(0.5 * (lo + hi))});
}

inline bool insideRing(const std::vector<double>& ring, double x, double y) {
    bool in = false;
    const size_t n = ring.size() / 2;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const double xi = ring[2 * i], yi = ring[2 * i + 1], xj = ring[2 * j], yj = ring[2 * j + 1];
        if ((yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi) in = !in;
    }
    return in;
}

inline bool insidePolygon(const planning::PlanPolygon& p, double x, double y) {
    if (!insideRing(p.rings[0], x, y)) return false;
    for (size_t h = 1; h < p.rings.size(); ++h)
        if (insideRing(p.rings[h], x, y)) return false;
    return true;
}

/// Violations of a path against 2D originals: segments closer than r to an edge, and dense
/// samples (every r / 8) inside a polygon.
inline int violations2D(const std::vector<planning::PlanPolygon>& originals, const std::vector<planning::Point>& path, double r) {
    std::vector<Seg2> edges;
    for (const auto& p : originals)
        for (const auto& ring : p.rings)
            for (size_t i = 0, n = ring.size() / 2; i < n; ++i)
                edges.push_back({ring[2 * i], ring[2 * i + 1], ring[2 * ((i + 1) % n)], ring[2 * ((i + 1) % n) + 1]});
    int bad = 0;
    for (size_t i = 0; i + 1 < path.size(); ++i) {
        const planning::Point a = path[i], b = path[i + 1];
        for (const Seg2& e : edges) {
            const double d = convexMin([&](double t) {
                return pointSegDist(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), e);
            });
            if (d <= r * (1 - 1e-9)) ++bad;
        }
        const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
        const int steps = std::max(1, int(std::ceil(len / (r / 8))));
        for (int s = 0; s <= steps; ++s) {
            const double t = double(s) / steps, x = a[0] + t * (b[0] - a[0]), y = a[1] + t * (b[1] - a[1]);
            for (const auto& p : originals)
                if (insidePolygon(p, x, y)) ++bad;
        }
    }
    return bad;
}

}  // namespace aggrelod::testing
