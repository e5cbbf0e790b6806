// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod samples: the forest and the village (samples.h). Outdoor scenes of many small
// separate objects with varied spacing: dense clumps that merge at small thresholds,
// clearings and scattered objects that stay apart until large ones (the situation of the
// paper's Figs. 1 and 10). z is up; the ground is z = 0.
#include <aggrelod/samples.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace aggrelod::samples {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string numbered(const char* prefix, int i) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%s%03d", prefix, i);
    return buffer;
}

// Base colours (linear RGBA, as glTF's baseColorFactor), so bakes show proxies that carry
// the look of what they replace (issue 5, materials).
constexpr float kTrunk[4] = {0.20f, 0.09f, 0.03f, 1.0f};
constexpr float kLeaves[4] = {0.05f, 0.30f, 0.04f, 1.0f};
constexpr float kNeedles[4] = {0.02f, 0.16f, 0.06f, 1.0f};
constexpr float kWall[4] = {0.70f, 0.58f, 0.40f, 1.0f};
constexpr float kRoof[4] = {0.50f, 0.08f, 0.04f, 1.0f};
constexpr float kFence[4] = {0.45f, 0.32f, 0.18f, 1.0f};
constexpr float kBarrel[4] = {0.25f, 0.12f, 0.05f, 1.0f};

void paint(InputObject& o, const float colour[4]) {
    const size_t triangles = o.indices.size() / 3;
    o.triangleColors.resize(4 * triangles);
    for (size_t t = 0; t < triangles; ++t)
        for (int k = 0; k < 4; ++k) o.triangleColors[4 * t + k] = colour[k];
}

// Faces looking up (normal z > 0.2) take the roof colour, the others the wall colour.
void paintHouse(InputObject& o) {
    paint(o, kWall);
    for (size_t t = 0; t + 2 < o.indices.size(); t += 3) {
        const double* a = &o.positions[3 * size_t(o.indices[t])];
        const double* b = &o.positions[3 * size_t(o.indices[t + 1])];
        const double* c = &o.positions[3 * size_t(o.indices[t + 2])];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 0 && n[2] / len > 0.2)
            for (int k = 0; k < 4; ++k) o.triangleColors[4 * (t / 3) + k] = kRoof[k];
    }
}

void renumberObjects(std::vector<InputObject>& objects) {
    for (size_t i = 0; i < objects.size(); ++i) objects[i].id = uint32_t(i);
}

/// A tree's footprint: everything of the tree lies in the vertical cylinder of this radius.
struct Footprint {
    double x, y, radius;
};

bool fits(const std::vector<Footprint>& placed, const Footprint& f, double minGap) {
    for (const Footprint& p : placed)
        if (std::hypot(p.x - f.x, p.y - f.y) < p.radius + f.radius + minGap) return false;
    return true;
}

/// Axis-aligned rectangle on the ground (x0 < x1, y0 < y1).
struct Rect {
    double x0, y0, x1, y1;
};

bool rectsApart(const Rect& a, const Rect& b, double gap) {
    return a.x1 + gap <= b.x0 || b.x1 + gap <= a.x0 || a.y1 + gap <= b.y0 || b.y1 + gap <= a.y0;
}

bool rectFits(const std::vector<Rect>& placed, const Rect& r, double gap) {
    for (const Rect& p : placed)
        if (!rectsApart(p, r, gap)) return false;
    return true;
}

}  // namespace

std::vector<InputObject> makeForest(uint32_t seed) {
    Random random(seed);
    const double size = 36.0;  // the forest spans [0, size]^2
    struct Tree {
        Footprint footprint;
        bool conifer;
    };
    std::vector<Tree> trees;
    std::vector<Footprint> placed;
    auto newTree = [&](double x, double y) {
        Tree t;
        t.conifer = random.uniform01() < 0.45;
        t.footprint = {x, y, t.conifer ? random.uniform(0.9, 1.3) : random.uniform(0.8, 1.5)};
        return t;
    };
    // Two clearings: nothing grows there.
    const Footprint clearings[2] = {{random.uniform(9, 13), random.uniform(22, 27), 5.0},
                                    {random.uniform(23, 28), random.uniform(8, 12), 4.0}};
    auto inClearing = [&](double x, double y, double r) {
        for (const Footprint& c : clearings)
            if (std::hypot(x - c.x, y - c.y) < c.radius + r) return true;
        return false;
    };
    auto inside = [&](double x, double y, double r) { return x - r >= 0 && y - r >= 0 && x + r <= size && y + r <= size; };
    // Dense clumps: each tree grows 0.1-0.8 from a tree of its clump.
    const int clumps = random.uniformInt(5, 7);
    for (int c = 0; c < clumps; ++c) {
        const int clumpSize = random.uniformInt(6, 12);
        for (int attempt = 0; attempt < 40; ++attempt) {
            Tree first = newTree(random.uniform(3, size - 3), random.uniform(3, size - 3));
            const Footprint& f = first.footprint;
            if (inClearing(f.x, f.y, f.radius) || !fits(placed, f, 2.5)) continue;
            const size_t clumpStart = trees.size();
            trees.push_back(first);
            placed.push_back(f);
            for (int k = 1, tries = 0; k < clumpSize && tries < 400; ++tries) {
                const Footprint& parent = trees[clumpStart + size_t(random.uniformInt(0, int(trees.size() - clumpStart) - 1))].footprint;
                Tree t = newTree(0, 0);
                const double gap = random.logUniform(0.1, 0.8), angle = random.uniform(0, 2 * kPi);
                t.footprint.x = parent.x + (parent.radius + t.footprint.radius + gap) * std::cos(angle);
                t.footprint.y = parent.y + (parent.radius + t.footprint.radius + gap) * std::sin(angle);
                if (!inside(t.footprint.x, t.footprint.y, t.footprint.radius) ||
                    inClearing(t.footprint.x, t.footprint.y, t.footprint.radius) || !fits(placed, t.footprint, 0.1))
                    continue;
                trees.push_back(t);
                placed.push_back(t.footprint);
                ++k;
            }
            break;
        }
    }
    // Scattered trees: at least 1.5 from every other tree.
    for (int k = 0, tries = 0; k < 18 && tries < 2000; ++tries) {
        Tree t = newTree(random.uniform(1.5, size - 1.5), random.uniform(1.5, size - 1.5));
        if (inClearing(t.footprint.x, t.footprint.y, t.footprint.radius) || !fits(placed, t.footprint, 1.5)) continue;
        trees.push_back(t);
        placed.push_back(t.footprint);
        ++k;
    }

    // Geometry: a trunk (cylinder) and, 0.05 above it, a canopy (sphere or cone); every part
    // stays within the footprint radius of the tree's axis.
    std::vector<InputObject> objects;
    for (size_t i = 0; i < trees.size(); ++i) {
        const Tree& t = trees[i];
        const Footprint& f = t.footprint;
        const std::string name = numbered("tree", int(i));
        const double trunkRadius = random.uniform(0.12, 0.2);
        const double trunkHeight = t.conifer ? random.uniform(0.7, 1.2) : random.uniform(1.3, 2.2);
        objects.push_back(makeCylinder(name + "_trunk", {f.x, f.y, 0}, trunkRadius, trunkHeight, 8));
        paint(objects.back(), kTrunk);
        const double base = trunkHeight + 0.05;
        if (t.conifer) {
            const double height = random.uniform(2.2, 3.4) * f.radius;
            objects.push_back(makeLathe(name + "_canopy", {f.x, f.y, base},
                                        {{f.radius, 0}, {0.62 * f.radius, 0.45 * height}, {0.05, height}}, 12));
            paint(objects.back(), kNeedles);
        } else {
            objects.push_back(makeUvSphere(name + "_canopy", {f.x, f.y, base + f.radius}, f.radius, 12, 7));
            paint(objects.back(), kLeaves);
        }
    }
    renumberObjects(objects);
    return objects;
}

std::vector<InputObject> makeVillage(uint32_t seed) {
    Random random(seed);
    std::vector<InputObject> objects;
    std::vector<Rect> placed;  // ground rectangles of everything placed (all axis-aligned)
    int houses = 0, fences = 0, barrels = 0;

    // A barrel: a bulged lathe, 0.76 across, 0.9 high.
    auto addBarrel = [&](double x, double y) {
        const Rect r{x - 0.38, y - 0.38, x + 0.38, y + 0.38};
        if (!rectFits(placed, r, 0.05)) return false;
        placed.push_back(r);
        objects.push_back(makeLathe(numbered("barrel", barrels++), {x, y, 0},
                                    {{0.3, 0}, {0.35, 0.2}, {0.38, 0.45}, {0.35, 0.7}, {0.3, 0.9}}, 12));
        paint(objects.back(), kBarrel);
        return true;
    };
    // A fence segment along x: pickets with pointed tops on a bottom rail, 0.06 thick.
    auto addFence = [&](double x0, double y, double length) {
        const double pitch = 0.3, picketWidth = 0.12, thick = 0.06;
        const int pickets = std::max(2, int(std::floor((length - picketWidth) / pitch)) + 1);
        length = (pickets - 1) * pitch + picketWidth;
        const Rect r{x0, y - thick / 2, x0 + length, y + thick / 2};
        if (!rectFits(placed, r, 0.05)) return false;
        placed.push_back(r);
        std::vector<std::pair<double, double>> outline = {{0, 0}, {length, 0}};
        for (int i = pickets - 1; i >= 0; --i) {
            const double a = i * pitch, b = a + picketWidth;
            if (i != pickets - 1) outline.push_back({b, 0.3});
            outline.push_back({b, 0.9});
            outline.push_back({a + picketWidth / 2, 1.05});
            outline.push_back({a, 0.9});
            if (i != 0) outline.push_back({a, 0.3});
        }
        objects.push_back(makeExtrusion(numbered("fence", fences++), outline, thick, 0, {x0, y, 0}));
        paint(objects.back(), kFence);
        return true;
    };
    // A house: walls and a pitched roof in one prism (gable ends facing +-y), w along x,
    // d along y. Returns false when it does not fit.
    auto addHouse = [&](double x0, double y0, double w, double d) {
        const Rect r{x0, y0, x0 + w, y0 + d};
        if (!rectFits(placed, r, 0.3)) return false;
        placed.push_back(r);
        const double wall = random.uniform(2.3, 3.0), ridge = random.uniform(1.2, 2.0);
        // Eaves overhang the walls by 0.25 on both sides (still inside the rectangle).
        const double o = 0.25;
        const std::vector<std::pair<double, double>> outline = {
            {o, 0}, {w - o, 0}, {w - o, wall - 0.1}, {w, wall - 0.2}, {w, wall}, {w / 2, wall + ridge}, {0, wall},
            {0, wall - 0.2}, {o, wall - 0.1}};
        objects.push_back(makeExtrusion(numbered("house", houses++), outline, d, 0, {x0, y0 + d / 2, 0}));
        paintHouse(objects.back());
        return true;
    };

    // Two rows of houses facing a street along x (y = 0), with varied gaps: tight terraces
    // (0.6-1.2 apart) and open plots (3-8 apart).
    for (int row = 0; row < 2; ++row) {
        double x = random.uniform(0, 3);
        while (x < 70) {
            const double w = random.uniform(4.0, 6.5), d = random.uniform(4.0, 6.0);
            const double y0 = row == 0 ? 4.0 + random.uniform(0, 1.5) : -4.0 - random.uniform(0, 1.5) - d;
            if (addHouse(x, y0, w, d)) {
                // Front fence (on the street side) for some houses.
                if (random.uniform01() < 0.5) {
                    const double fy = row == 0 ? y0 - random.uniform(0.8, 1.6) : y0 + d + random.uniform(0.8, 1.6);
                    addFence(x - 0.2, fy, w + 0.4);
                }
                // A few barrels by the side wall, close to each other.
                if (random.uniform01() < 0.55) {
                    const int count = random.uniformInt(1, 4);
                    const double by = row == 0 ? y0 + 0.6 : y0 + d - 0.6;
                    double bx = x + w + random.uniform(0.35, 0.9) + 0.38;
                    for (int b = 0; b < count; ++b) {
                        addBarrel(bx, by + (b % 2) * 0.85 * (row == 0 ? 1 : -1));
                        if (b % 2 == 1) bx += 0.76 + random.uniform(0.08, 0.3);
                    }
                }
            }
            const bool terrace = random.uniform01() < 0.45;
            x += w + (terrace ? random.uniform(0.6, 1.2) : random.uniform(3.0, 8.0));
        }
    }
    renumberObjects(objects);
    return objects;
}

}  // namespace aggrelod::samples
