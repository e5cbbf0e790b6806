// SPDX-License-Identifier: AGPL-3.0-or-later
// Open surfaces thickened into closed shells (module/src/surface_shell.cpp): closed,
// edge-manifold, outward, containing the surface with every face at least the offset inside,
// within twice the offset of it; and refused, with the reason, where that cannot hold.
#include "surface_shell.h"
#include "mesh_distance.h"
#include "mesh_preparation.h"
#include "mesh_checks.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>

namespace aggrelod::testing {
namespace {

struct Surface {
    std::vector<double> positions;
    std::vector<uint32_t> triangles;
    uint32_t add(double x, double y, double z) {
        positions.insert(positions.end(), {x, y, z});
        return uint32_t(positions.size() / 3 - 1);
    }
    void quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d) { triangles.insert(triangles.end(), {a, b, c, a, c, d}); }
};

// A box without its top face: five faces, the open rim at z = h. Its own vertices per face
// (as exporters write them), so the shell's weld is exercised too.
Surface openBox(double w, double d, double h) {
    Surface s;
    auto face = [&](std::array<double, 3> a, std::array<double, 3> b, std::array<double, 3> c, std::array<double, 3> e) {
        s.quad(s.add(a[0], a[1], a[2]), s.add(b[0], b[1], b[2]), s.add(c[0], c[1], c[2]), s.add(e[0], e[1], e[2]));
    };
    face({0, 0, 0}, {0, d, 0}, {w, d, 0}, {w, 0, 0});  // bottom, facing -z
    face({0, 0, 0}, {w, 0, 0}, {w, 0, h}, {0, 0, h});  // facing -y
    face({w, 0, 0}, {w, d, 0}, {w, d, h}, {w, 0, h});  // facing +x
    face({w, d, 0}, {0, d, 0}, {0, d, h}, {w, d, h});  // facing +y
    face({0, d, 0}, {0, 0, 0}, {0, 0, h}, {0, d, h});  // facing -x
    return s;
}

// A rolling height field on an n x n grid over [0, 1]^2: a terrain patch, a sheet of cloth.
Surface heightField(int n, unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> phase(0, 6.283), amplitude(0.02, 0.08);
    const double p1 = phase(random), p2 = phase(random), a = amplitude(random);
    Surface s;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const double x = double(i) / n, y = double(j) / n;
            s.add(x, y, a * std::sin(5 * x + p1) * std::cos(4 * y + p2));
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const uint32_t v = uint32_t(j * (n + 1) + i);
            s.quad(v, v + 1, v + uint32_t(n) + 2, v + uint32_t(n) + 1);
        }
    return s;
}

// Everything the shell promises, checked independently of how it was made.
void expectShellAround(const Surface& s, double offset, const std::vector<double>& shellPositions,
                       const std::vector<uint32_t>& shellTriangles, const std::string& name) {
    InputObject shell;
    shell.positions = shellPositions;
    shell.indices = shellTriangles;
    const ClosedCheck closed = checkClosedAfterWeld(shell);
    EXPECT_EQ(closed.problem, "") << name;
    EXPECT_EQ(closed.edgesUsedMoreThanTwice, 0u) << name;
    EXPECT_EQ(closed.components, 1) << name;
    EXPECT_GT(signedVolumeOf(shell), 0.0) << name;
    detail::TriangleBvh shellBvh, sheetsBvh, surfaceBvh;
    shellBvh.build(shellPositions.data(), shellPositions.size() / 3, shellTriangles.data(), shellTriangles.size() / 3);
    // The two sheets: the first two faces per face of the surface (the strips follow).
    sheetsBvh.build(shellPositions.data(), shellPositions.size() / 3, shellTriangles.data(), 2 * (s.triangles.size() / 3));
    surfaceBvh.build(s.positions.data(), s.positions.size() / 3, s.triangles.data(), s.triangles.size() / 3);
    // Points on every face (corners, edge midpoints, centroid, points near the corners): inside
    // the shell or on it, and at least half the offset from both sheets.
    size_t inside = 0;
    for (size_t t = 0; t + 2 < s.triangles.size(); t += 3) {
        const double* a = &s.positions[3 * s.triangles[t]];
        const double* b = &s.positions[3 * s.triangles[t + 1]];
        const double* c = &s.positions[3 * s.triangles[t + 2]];
        const double weights[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0.5, 0.5, 0}, {0, 0.5, 0.5}, {0.5, 0, 0.5},
                                     {1.0 / 3, 1.0 / 3, 1.0 / 3}, {0.9, 0.05, 0.05}, {0.05, 0.9, 0.05}, {0.05, 0.05, 0.9}};
        for (const auto& w : weights) {
            double q[3];
            for (int k = 0; k < 3; ++k) q[k] = w[0] * a[k] + w[1] * b[k] + w[2] * c[k];
            if (detail::closestPoint(shellBvh, q).distance <= 1e-12) continue;  // on a boundary strip
            EXPECT_GT(windingNumber(shellPositions, shellTriangles, q), 0.5) << name << " face " << t / 3;
            EXPECT_GE(detail::closestPoint(sheetsBvh, q).distance, 0.5 * offset * (1 - 1e-9)) << name << " face " << t / 3;
            ++inside;
        }
    }
    EXPECT_GT(inside, s.triangles.size() / 3) << name;
    // The shell's surface within twice the offset of the surface (its vertices and centroids).
    for (size_t i = 0; i < shellPositions.size() / 3 + shellTriangles.size() / 3; ++i) {
        double q[3];
        if (i < shellPositions.size() / 3) {
            for (int k = 0; k < 3; ++k) q[k] = shellPositions[3 * i + k];
        } else {
            const uint32_t* f = &shellTriangles[3 * (i - shellPositions.size() / 3)];
            for (int k = 0; k < 3; ++k)
                q[k] = (shellPositions[3 * f[0] + k] + shellPositions[3 * f[1] + k] + shellPositions[3 * f[2] + k]) / 3;
        }
        EXPECT_LE(detail::closestPoint(surfaceBvh, q).distance, 2 * offset * (1 + 1e-9)) << name << " sample " << i;
    }
}

TEST(SurfaceShell, OpenBoxBecomesAClosedShellAroundIt) {
    const Surface box = openBox(2, 1, 1.5);
    const double offset = 0.04;
    std::vector<double> p;
    std::vector<uint32_t> t;
    std::string why;
    ASSERT_TRUE(detail::thickenSurface(box.positions, box.triangles, offset, 2 * offset, 0.0, p, t, why)) << why;
    expectShellAround(box, offset, p, t, "open box");
    // 10 faces per sheet, 4 per edge of the open rim (4 edges after the weld).
    EXPECT_EQ(t.size() / 3, 2 * 10 + 4 * 4u);
    // Its volume is the area times twice the offset, give or take the corners.
    double volume, area;
    detail::meshVolumeArea(p, t, volume, area);
    const double surfaceArea = 2 * 1 + 2 * (2 * 1.5) + 2 * (1 * 1.5);
    EXPECT_NEAR(volume, surfaceArea * 2 * offset, 0.1 * surfaceArea * 2 * offset);
}

// Height fields with a few faces turned over (as exported surfaces often have): the faces are
// oriented alike first, and the shell holds for every seed.
TEST(SurfaceShell, HeightFieldsWithFacesTurnedOver) {
    for (unsigned seed = 1; seed <= 8; ++seed) {
        Surface s = heightField(12, seed);
        std::mt19937 random(seed);
        for (size_t f = 0; f < s.triangles.size() / 3; ++f)
            if (random() % 7 == 0) std::swap(s.triangles[3 * f + 1], s.triangles[3 * f + 2]);
        const double offset = 0.01;
        std::vector<double> p;
        std::vector<uint32_t> t;
        std::string why;
        ASSERT_TRUE(detail::thickenSurface(s.positions, s.triangles, offset, 2 * offset, 0.0, p, t, why)) << why << " seed " << seed;
        expectShellAround(s, offset, p, t, "height field seed " + std::to_string(seed));
    }
}

// A small open box in the cavity of a large one: two shells, neither inside the other (the
// cavity is outside the large box's skin), so both are kept.
TEST(SurfaceShell, PiecesInACavityAreSeparateShells) {
    Surface s = openBox(4, 4, 4);
    const Surface small = openBox(1, 1, 1);
    const uint32_t base = uint32_t(s.positions.size() / 3);
    for (size_t i = 0; i < small.positions.size(); i += 3) s.add(small.positions[i] + 1.5, small.positions[i + 1] + 1.5, small.positions[i + 2] + 1);
    for (uint32_t v : small.triangles) s.triangles.push_back(base + v);
    std::vector<double> p;
    std::vector<uint32_t> t;
    std::string why;
    ASSERT_TRUE(detail::thickenSurface(s.positions, s.triangles, 0.05, 0.1, 0.0, p, t, why)) << why;
    InputObject shell;
    shell.positions = p;
    shell.indices = t;
    const ClosedCheck closed = checkClosedAfterWeld(shell);
    EXPECT_EQ(closed.problem, "");
    EXPECT_EQ(closed.components, 2);
    const double q[3] = {2, 2, 1.5};  // the small box's inside: in the cavity of both
    EXPECT_LT(windingNumber(p, t, q), 0.5);
}

TEST(SurfaceShell, RefusesWhatItCannotThicken) {
    std::vector<double> p;
    std::vector<uint32_t> t;
    std::string why;
    auto refused = [&](const Surface& s, double offset, const std::string& reason, double smallestOpening = 0) {
        EXPECT_FALSE(detail::thickenSurface(s.positions, s.triangles, offset, 2 * offset, smallestOpening, p, t, why)) << reason;
        EXPECT_NE(why.find(reason), std::string::npos) << why;
        EXPECT_TRUE(p.empty() && t.empty()) << reason;
    };
    {  // a closed box: its shell would be two nested sheets (a hollow solid)
        Surface box = openBox(1, 1, 1);
        box.quad(box.add(0, 0, 1), box.add(1, 0, 1), box.add(1, 1, 1), box.add(0, 1, 1));
        refused(box, 0.02, "closed");
    }
    {  // a fin: three faces on one edge
        Surface s;
        const uint32_t a = s.add(0, 0, 0), b = s.add(0, 1, 0);
        s.triangles.insert(s.triangles.end(), {a, b, s.add(1, 0.5, 0), b, a, s.add(-1, 0.5, 0), a, b, s.add(0, 0.5, 1)});
        refused(s, 0.02, "more than two faces");
    }
    {  // a Moebius strip
        Surface s;
        const int n = 24;
        for (int i = 0; i < n; ++i) {
            const double u = 2 * M_PI * i / n;
            for (double v : {-0.3, 0.3})
                s.add((1 + v * std::cos(u / 2)) * std::cos(u), (1 + v * std::cos(u / 2)) * std::sin(u), v * std::sin(u / 2));
        }
        for (uint32_t i = 0; i < uint32_t(n); ++i) {
            const uint32_t j = (i + 1) % n;
            // The last quad joins the strip's ends the other way round: the half twist.
            if (j == 0) s.quad(2 * i, 1, 0, 2 * i + 1);
            else s.quad(2 * i, 2 * j, 2 * j + 1, 2 * i + 1);
        }
        refused(s, 0.01, "oriented alike");
    }
    {  // two sheets nearer than twice the offset (the two leaves of a thin panel, apart)
        Surface s = heightField(4, 3);
        const Surface second = heightField(4, 3);
        const uint32_t base = uint32_t(s.positions.size() / 3);
        for (size_t i = 0; i < second.positions.size(); i += 3) s.add(second.positions[i], second.positions[i + 1], second.positions[i + 2] + 0.03);
        for (uint32_t v : second.triangles) s.triangles.push_back(base + v);
        refused(s, 0.02, "cross");
    }
    {  // a fold of 20 degrees: no displacement within twice the offset keeps both faces away
        Surface s;
        const double a = 20 * M_PI / 180;
        const uint32_t o = s.add(0, 0, 0), e = s.add(0, 1, 0);
        s.triangles.insert(s.triangles.end(), {o, e, s.add(1, 0, 0), e, o, s.add(std::cos(a), 0, std::sin(a))});
        refused(s, 0.02, "too sharp");
    }
    {  // two triangles meeting at one vertex only (a bow tie)
        Surface s;
        const uint32_t c = s.add(0, 0, 0);
        s.triangles.insert(s.triangles.end(), {c, s.add(1, 0, 0), s.add(1, 1, 0), c, s.add(-1, 0, 0), s.add(-1, -1, 0)});
        refused(s, 0.02, "two fans");
    }
    {  // a face whose corners lie on one line
        Surface s;
        const uint32_t a = s.add(0, 0, 0), b = s.add(1, 0, 0), c = s.add(2, 0, 0), d = s.add(1, 1, 0);
        s.triangles.insert(s.triangles.end(), {a, b, c, a, c, d});
        refused(s, 0.02, "no area");
    }
    {  // a closed box with one triangle missing: a wrap fills it, a shell would be a hollow skin
        Surface box = openBox(1, 1, 1);
        const uint32_t a = box.add(0, 0, 1), b = box.add(1, 0, 1), c = box.add(1, 1, 1), d = box.add(0, 1, 1);
        box.triangles.insert(box.triangles.end(), {a, b, c});
        (void)d;
        refused(box, 0.02, "nearly closed", 2.0);
        EXPECT_TRUE(detail::thickenSurface(box.positions, box.triangles, 0.02, 0.04, 1.0, p, t, why)) << why;
    }
    {  // faces of one part bent towards the sheets of another (each vertex's own faces keep the
       // offset; the faces across do not)
        Surface s;
        for (const auto& v : std::vector<std::array<double, 3>>{{0, 0, 0}, {0.755, 0.059, -0.063}, {-0.136, 0.222, 0.130},
                                                              {-0.450, -0.735, -0.580}, {0.756, -0.059, 0.102}})
            s.add(v[0], v[1], v[2]);
        s.triangles = {0, 1, 2, 0, 2, 3, 0, 3, 4};
        refused(s, 0.1843, "nearer it than half the offset");
    }
}

}  // namespace
}  // namespace aggrelod::testing
