// SPDX-License-Identifier: AGPL-3.0-or-later
// Seeded analogues of the paper's five 2D environments (paper Section 4, Fig. 4) and square
// grids. Each generator places simple polygons and rejects any that would come closer than
// a minimum gap to one already placed (bounding-circle test), so no two polygons touch.
#include <aggrelod/environments2d.h>
#include <aggrelod/samples.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace aggrelod::samples {
namespace {

struct Placed {
    double x, y, r;
};

bool fits(const std::vector<Placed>& placed, double x, double y, double r, double gap) {
    for (const Placed& p : placed)
        if (std::hypot(p.x - x, p.y - y) < p.r + r + gap) return false;
    return true;
}

Feature2D feature(const std::string& kind, size_t index, std::vector<double> ring) {
    Feature2D f;
    f.name = kind + " " + std::to_string(index + 1);
    f.id = static_cast<uint32_t>(index);
    f.polygons.push_back(Polygon2D{std::move(ring), {}});
    return f;
}

/// Star-shaped blob: n vertices at radius r * (1 +- jitter) around (cx, cy).
std::vector<double> blob(Random& rnd, double cx, double cy, double r, int n, double jitter) {
    std::vector<double> ring;
    const double phase = rnd.uniform(0, 2 * M_PI);
    for (int i = 0; i < n; ++i) {
        const double a = phase + 2 * M_PI * i / n;
        const double rr = r * (1 - jitter * rnd.uniform01());
        ring.push_back(cx + rr * std::cos(a));
        ring.push_back(cy + rr * std::sin(a));
    }
    return ring;
}

/// Rectangle centred at (cx, cy), half sizes hx, hy, rotated by angle.
std::vector<double> box(double cx, double cy, double hx, double hy, double angle = 0) {
    const double c = std::cos(angle), s = std::sin(angle);
    std::vector<double> ring;
    const double corners[4][2] = {{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}};
    for (auto& k : corners) {
        ring.push_back(cx + c * k[0] - s * k[1]);
        ring.push_back(cy + s * k[0] + c * k[1]);
    }
    return ring;
}

// Tree: a fractal tree whose trunk and branches are separate tapered quads (gaps at the
// forks) with leaf blobs at the twig ends; extent about 40 units, gaps from 0.2 up.
// A branch (with its subtree) that would come within 0.2 of anything placed is left out.
bool branchFits(const std::vector<Placed>& placed, double x, double y, double ex, double ey, double width,
                std::vector<Placed>& circles) {
    circles.clear();
    const double len = std::hypot(ex - x, ey - y);
    const int n = std::max(2, static_cast<int>(std::ceil(len / std::max(width, 0.2))) + 1);
    for (int i = 0; i < n; ++i) {
        const double t = static_cast<double>(i) / (n - 1);
        circles.push_back({x + t * (ex - x), y + t * (ey - y), width / 2 + 0.05});
    }
    for (const Placed& c : circles)
        if (!fits(placed, c.x, c.y, c.r, 0.2)) return false;
    return true;
}

void tree(Random& rnd, std::vector<Feature2D>& out, std::vector<Placed>& placed, double x, double y, double angle,
          double length, double width, int depth) {
    const double ex = x + length * std::cos(angle), ey = y + length * std::sin(angle);
    const double nx = -std::sin(angle) * width / 2, ny = std::cos(angle) * width / 2;
    const double taper = 0.7;
    std::vector<Placed> circles;
    if (!branchFits(placed, x, y, ex, ey, width, circles)) return;
    placed.insert(placed.end(), circles.begin(), circles.end());
    out.push_back(feature("branch", out.size(),
                          {x + nx, y + ny, x - nx, y - ny, ex - nx * taper, ey - ny * taper, ex + nx * taper,
                           ey + ny * taper}));
    if (depth == 0) {
        const double r = rnd.uniform(0.8, 1.4);
        const double cx = ex + (r + 0.5) * std::cos(angle), cy = ey + (r + 0.5) * std::sin(angle);
        if (fits(placed, cx, cy, r, 0.3)) {
            out.push_back(feature("leaf", out.size(), blob(rnd, cx, cy, r, 7, 0.3)));
            placed.push_back({cx, cy, r});
        }
        return;
    }
    const int children = depth > 3 ? 2 : rnd.uniformInt(2, 3);
    const double childWidth = width * taper;
    const double minAngle = children == 2 ? 0.9 : 0.5;  // between sibling directions
    // Children start far enough from the fork that siblings keep a gap of 0.3.
    const double startGap = (childWidth / 2 + 0.15) / std::sin(minAngle / 2) + 0.3;
    for (int c = 0; c < children; ++c) {
        const double spread = children == 2 ? (c == 0 ? -0.45 : 0.45) : (c - 1) * 0.5;
        const double a = angle + spread;
        tree(rnd, out, placed, ex + startGap * std::cos(a), ey + startGap * std::sin(a), a + rnd.uniform(-0.05, 0.05),
             length * rnd.uniform(0.68, 0.8), childWidth, depth - 1);
    }
}

std::vector<Feature2D> makeTree(Random& rnd) {
    std::vector<Feature2D> out;
    std::vector<Placed> placed;
    tree(rnd, out, placed, 0, 0, M_PI / 2, 10, 1.6, 5);
    return out;
}

// Scatter: 70 random convex-ish blobs of radius 1-4 in a 100 x 100 square, at least 1 apart.
std::vector<Feature2D> makeScatter(Random& rnd) {
    std::vector<Feature2D> out;
    std::vector<Placed> placed;
    for (int tries = 0; tries < 5000 && out.size() < 70; ++tries) {
        const double r = rnd.uniform(1, 4), x = rnd.uniform(0, 100), y = rnd.uniform(0, 100);
        if (!fits(placed, x, y, r, 1.0)) continue;
        placed.push_back({x, y, r});
        out.push_back(feature("object", out.size(), blob(rnd, x, y, r, rnd.uniformInt(5, 9), 0.35)));
    }
    return out;
}

// Room: a floor plan of 3 x 3 rooms (walls are separate thin rectangles broken by door
// gaps of 12-16 units) with furniture rectangles inside each room; 300 x 300 units.
std::vector<Feature2D> makeRoom(Random& rnd) {
    std::vector<Feature2D> out;
    const double cell = 100, wall = 3;
    auto addWall = [&](double x0, double y0, double x1, double y1) {
        out.push_back(feature("wall", out.size(), {x0, y0, x1, y0, x1, y1, x0, y1}));
    };
    // Horizontal walls (y = k * cell) and vertical walls (x = k * cell), each segment between
    // corners split by a door unless on the outside.
    for (int k = 0; k <= 3; ++k)
        for (int c = 0; c < 3; ++c) {
            const double a = c * cell + wall, b = (c + 1) * cell - wall;  // corners keep a gap of `wall`
            const bool outside = k == 0 || k == 3;
            const double door = outside && rnd.uniform01() < 0.7 ? 0 : rnd.uniform(12, 16);
            const double mid = rnd.uniform(a + 20, b - 20 - door);
            for (int orient = 0; orient < 2; ++orient) {
                const double p = k * cell;
                auto seg = [&](double s0, double s1) {
                    if (s1 - s0 < 1) return;
                    if (orient == 0) addWall(s0, p - wall / 2, s1, p + wall / 2);
                    else addWall(p - wall / 2, s0, p + wall / 2, s1);
                };
                if (door > 0) {
                    seg(a, mid);
                    seg(mid + door, b);
                } else {
                    seg(a, b);
                }
            }
        }
    // Corner posts.
    for (int i = 0; i <= 3; ++i)
        for (int j = 0; j <= 3; ++j) {
            const double x = i * cell, y = j * cell;
            out.push_back(feature("post", out.size(), box(x, y, wall / 2 + 0.2, wall / 2 + 0.2)));
        }
    // Furniture: 3-5 pieces per room, at least 6 units from the walls and each other.
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            std::vector<Placed> placed;
            const int pieces = rnd.uniformInt(3, 5);
            for (int tries = 0; tries < 200 && static_cast<int>(placed.size()) < pieces; ++tries) {
                const double hx = rnd.uniform(4, 14), hy = rnd.uniform(4, 10);
                const double r = std::hypot(hx, hy);
                const double x = rnd.uniform(i * cell + 8 + r, (i + 1) * cell - 8 - r);
                const double y = rnd.uniform(j * cell + 8 + r, (j + 1) * cell - 8 - r);
                if (!fits(placed, x, y, r, 6)) continue;
                placed.push_back({x, y, r});
                out.push_back(feature("furniture", out.size(), box(x, y, hx, hy, rnd.uniform01() < 0.5 ? 0 : M_PI / 2)));
            }
        }
    return out;
}

// Colony: 6 villages of 12-25 small rotated houses (some L-shaped) around village centres,
// houses 4-10 units apart inside a village, villages 60-150 apart; 500 x 500 units.
std::vector<Feature2D> makeColony(Random& rnd) {
    std::vector<Feature2D> out;
    std::vector<Placed> placed, centres;
    for (int tries = 0; tries < 1000 && centres.size() < 6; ++tries) {
        const double x = rnd.uniform(60, 440), y = rnd.uniform(60, 440);
        if (fits(centres, x, y, 40, 40)) centres.push_back({x, y, 40});
    }
    for (const Placed& c : centres) {
        const int houses = rnd.uniformInt(12, 25);
        int made = 0;
        for (int tries = 0; tries < 2000 && made < houses; ++tries) {
            const double hx = rnd.uniform(4, 8), hy = rnd.uniform(3, 6), r = std::hypot(hx, hy);
            const double a = rnd.uniform(0, 2 * M_PI), d = 55 * std::sqrt(rnd.uniform01());
            const double x = c.x + d * std::cos(a), y = c.y + d * std::sin(a);
            if (!fits(placed, x, y, r, rnd.uniform(4, 10))) continue;
            placed.push_back({x, y, r});
            const double angle = rnd.uniform(0, M_PI);
            std::vector<double> ring;
            if (rnd.uniform01() < 0.4) {  // L-shaped house
                const double co = std::cos(angle), si = std::sin(angle);
                const double pts[6][2] = {{-hx, -hy}, {hx, -hy}, {hx, 0}, {0, 0}, {0, hy}, {-hx, hy}};
                for (auto& p : pts) {
                    ring.push_back(x + co * p[0] - si * p[1]);
                    ring.push_back(y + si * p[0] + co * p[1]);
                }
            } else {
                ring = box(x, y, hx, hy, angle);
            }
            out.push_back(feature("house", out.size(), std::move(ring)));
            ++made;
        }
    }
    return out;
}

// Forest: 400 tree crowns (irregular 10-16-gons, radius 5-20, log-uniform) spread over
// 1000 x 1000 units with clearings; crowns at least 2 apart.
std::vector<Feature2D> makeForest(Random& rnd) {
    std::vector<Feature2D> out;
    std::vector<Placed> placed;
    std::vector<Placed> clearings;
    for (int i = 0; i < 4; ++i) clearings.push_back({rnd.uniform(150, 850), rnd.uniform(150, 850), rnd.uniform(60, 120)});
    for (int tries = 0; tries < 20000 && out.size() < 400; ++tries) {
        const double r = rnd.logUniform(5, 20), x = rnd.uniform(0, 1000), y = rnd.uniform(0, 1000);
        bool inClearing = false;
        for (const Placed& c : clearings) inClearing |= std::hypot(c.x - x, c.y - y) < c.r;
        if (inClearing || !fits(placed, x, y, r, 2)) continue;
        placed.push_back({x, y, r});
        out.push_back(feature("crown", out.size(), blob(rnd, x, y, r, rnd.uniformInt(10, 16), 0.3)));
    }
    return out;
}

}  // namespace

std::vector<Environment2D> allEnvironments2D() {
    return {Environment2D::Tree, Environment2D::Scatter, Environment2D::Room, Environment2D::Colony, Environment2D::Forest};
}

std::string environmentName(Environment2D env) {
    switch (env) {
        case Environment2D::Tree: return "tree";
        case Environment2D::Scatter: return "scatter";
        case Environment2D::Room: return "room";
        case Environment2D::Colony: return "colony";
        case Environment2D::Forest: return "forest";
    }
    return "unknown";
}

std::vector<Feature2D> makeEnvironment2D(Environment2D env, uint32_t seed) {
    Random rnd(seed * 7919u + static_cast<uint32_t>(env));
    switch (env) {
        case Environment2D::Tree: return makeTree(rnd);
        case Environment2D::Scatter: return makeScatter(rnd);
        case Environment2D::Room: return makeRoom(rnd);
        case Environment2D::Colony: return makeColony(rnd);
        case Environment2D::Forest: return makeForest(rnd);
    }
    return {};
}

std::vector<Feature2D> makeSquareGrid(int count, double size, double gap, double jitter, uint32_t seed) {
    std::vector<Feature2D> out;
    Random rnd(seed);
    const int perRow = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(std::max(count, 1)))));
    for (int i = 0; i < count; ++i) {
        const double x = (i % perRow) * (size + gap) + (jitter > 0 ? rnd.uniform(-jitter, jitter) : 0.0);
        const double y = (i / perRow) * (size + gap) + (jitter > 0 ? rnd.uniform(-jitter, jitter) : 0.0);
        out.push_back(feature("square", static_cast<size_t>(i), {x, y, x + size, y, x + size, y + size, x, y + size}));
    }
    return out;
}

std::vector<Feature2D> makeRandomOverlappingPolygons(uint32_t seed) {
    Random rnd(seed);
    std::vector<Feature2D> features;
    const int n = rnd.uniformInt(2, 25);
    const double span = rnd.uniform(10, 60);
    for (int i = 0; i < n; ++i) {
        Feature2D f;
        f.name = "random " + std::to_string(i);
        f.id = static_cast<uint32_t>(i);
        const double cx = rnd.uniform(0, span), cy = rnd.uniform(0, span), r = rnd.uniform(1, 8);
        const int k = rnd.uniformInt(3, 12);
        Polygon2D p;
        for (int j = 0; j < k; ++j) {
            const double a = 2 * M_PI * j / k, rr = r * rnd.uniform(0.4, 1.0);
            double x = cx + rr * std::cos(a), y = cy + rr * std::sin(a);
            if (rnd.uniform01() < 0.3) {  // integer vertices: exact touches and shared edges
                x = std::round(x);
                y = std::round(y);
            }
            p.exterior.push_back(x);
            p.exterior.push_back(y);
        }
        if (rnd.uniform01() < 0.2) {
            std::vector<double> hole;
            for (int j = 0; j < 4; ++j) {
                hole.push_back(cx + 0.2 * r * std::cos(-M_PI / 2 * j));
                hole.push_back(cy + 0.2 * r * std::sin(-M_PI / 2 * j));
            }
            p.holes.push_back(hole);
        }
        f.polygons.push_back(p);
        if (rnd.uniform01() < 0.1) {  // an overlapping second part with the same hole
            Polygon2D q = p;
            for (size_t t = 0; t < q.exterior.size(); t += 2) q.exterior[t] += rnd.uniform(-3, 3);
            f.polygons.push_back(q);
        }
        features.push_back(std::move(f));
    }
    return features;
}

}  // namespace aggrelod::samples
