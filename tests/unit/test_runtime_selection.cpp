// SPDX-License-Identifier: MIT
// Level selection (docs/design.md §3): valid cuts for 1000 random cameras, the
// screen-space-error rule, incremental == full, hysteresis against flicker, and the
// collision cut by distance. On synthetic hierarchies (tests/runtime_support).
#include <aggrelod/runtime.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

using namespace aggrelod::runtime;
using aggrelod::testing::makeSyntheticHierarchy;

namespace {

struct OpenedHierarchy {
    std::vector<uint8_t> bytes;
    RuntimeFile file;
    explicit OpenedHierarchy(const BuildArrays& p) {
        std::string error;
        EXPECT_TRUE(writeRuntimeFile(p, bytes, error)) << error;
        EXPECT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error), FileStatus::Ok) << error;
    }
};

// Every object covered exactly once by the cut, and the proxies/originals lists agree with it.
void expectExactCover(const RuntimeFile& file, const Selector& selector) {
    std::vector<int> cover(file.objectCount(), 0);
    size_t leaves = 0, inner = 0;
    for (uint32_t node : selector.cut()) {
        for (uint32_t o : file.sources(node)) ++cover[o];
        file.isLeaf(node) ? ++leaves : ++inner;
    }
    for (uint32_t o = 0; o < file.objectCount(); ++o) ASSERT_EQ(cover[o], 1) << "object " << o;
    EXPECT_EQ(selector.proxyNodes().size, inner);
    size_t originals = 0;
    for (uint32_t node : selector.cut())
        if (file.isLeaf(node)) originals += file.sources(node).size;
    EXPECT_EQ(selector.originalObjects().size, originals);
    for (uint32_t node : selector.proxyNodes()) EXPECT_FALSE(file.isLeaf(node));
}

std::vector<uint32_t> sortedCut(const Selector& s) {
    std::vector<uint32_t> v(s.cut().begin(), s.cut().end());
    std::sort(v.begin(), v.end());
    return v;
}

Camera randomCamera(std::mt19937& rng, const RuntimeFile& file) {
    // Around the scene centre, in a random direction, at a log-uniform distance from inside
    // the scene to far away (so that every level gets drawn by some camera).
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (uint32_t r : file.roots())
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], file.node(r).boundsMin[k]);
            hi[k] = std::max(hi[k], file.node(r).boundsMax[k]);
        }
    std::normal_distribution<float> gauss;
    float dir[3] = {gauss(rng), gauss(rng), gauss(rng)};
    const float len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]) + 1e-9f;
    const float distance = std::exp(std::uniform_real_distribution<float>(0.0f, std::log(1e5f))(rng));
    Camera c;
    for (int k = 0; k < 3; ++k) c.position[k] = 0.5f * (lo[k] + hi[k]) + dir[k] / len * distance;
    c.fovY = std::uniform_real_distribution<float>(0.3f, 1.6f)(rng);
    c.viewportHeight = std::uniform_real_distribution<float>(200.0f, 2200.0f)(rng);
    return c;
}

}  // namespace

TEST(RuntimeSelection, ValidCutAndRuleFor1000RandomCameras) {
    OpenedHierarchy h(makeSyntheticHierarchy(700, 11, 4, 3));
    const RuntimeFile& file = h.file;
    Selector incremental(file), full(file);
    std::mt19937 rng(99);
    SelectionSettings noHysteresis;
    noHysteresis.coarsenRatio = 1.0f;
    size_t cutSizes = 0, distinctMixes = 0, intermediate = 0;
    for (int i = 0; i < 1000; ++i) {
        const Camera cam = randomCamera(rng, file);
        noHysteresis.pixelTolerance = std::uniform_real_distribution<float>(0.5f, 8.0f)(rng);
        incremental.select(cam, noHysteresis);
        full.selectFull(cam, noHysteresis);
        expectExactCover(file, incremental);
        expectExactCover(file, full);
        ASSERT_EQ(sortedCut(incremental), sortedCut(full)) << "camera " << i;
        // The rule of docs/design.md §3, checked with the reference formula.
        const float tau = noHysteresis.pixelTolerance;
        for (uint32_t node : full.cut()) {
            const NodeRecord& r = file.node(node);
            if (!file.isLeaf(node)) {
                EXPECT_LE(full.screenSpaceErrorOf(node, cam), tau * 1.0001f) << node;
            }
            if (r.parent != kNoIndex && !full.skipsNode(r.parent)) {
                EXPECT_GT(full.screenSpaceErrorOf(r.parent, cam), tau * 0.9999f) << node;
            }
        }
        cutSizes += full.cut().size;
        if (full.cut().size > file.roots().size && full.cut().size < file.objectCount()) ++intermediate;
        if (full.proxyNodes().size > 0 && full.originalObjects().size > 0) ++distinctMixes;
    }
    // The cameras really exercise the hierarchy: mixed cuts of proxies and originals.
    EXPECT_GT(distinctMixes, 50u);
    EXPECT_GT(intermediate, 150u);  // measured 203 of 1000
    EXPECT_GT(cutSizes, 1000u);
}

TEST(RuntimeSelection, ScreenSpaceErrorMatchesTheFormula) {
    OpenedHierarchy h(makeSyntheticHierarchy(50, 2));
    Selector s(h.file);
    Camera cam;
    cam.position[0] = -100; cam.position[1] = 20; cam.position[2] = 30;
    cam.fovY = 0.9f;
    cam.viewportHeight = 720;
    const uint32_t root = h.file.roots()[0];
    const NodeRecord& r = h.file.node(root);
    const double d = std::sqrt(std::pow(-100.0 - r.sphereCenter[0], 2) + std::pow(20.0 - r.sphereCenter[1], 2) +
                               std::pow(30.0 - r.sphereCenter[2], 2)) - r.sphereRadius;
    const double expected = r.geometricError * 720.0 / (2.0 * d * std::tan(0.45));
    EXPECT_NEAR(s.screenSpaceErrorOf(root, cam), expected, 1e-4 * expected);
    EXPECT_NEAR(screenSpaceError(r.geometricError, d, 0.9, 720), expected, 1e-9 * expected);
}

TEST(RuntimeSelection, IncrementalEqualsFullAlongAFlightWithHysteresis) {
    OpenedHierarchy h(makeSyntheticHierarchy(2000, 5, 2));
    Selector incremental(h.file), full(h.file);
    SelectionSettings settings;
    settings.pixelTolerance = 2.0f;
    settings.coarsenRatio = 0.7f;
    Camera cam;
    cam.fovY = 1.0f;
    cam.viewportHeight = 1080;
    std::mt19937 rng(3);
    float p[3] = {-50, 40, -50};
    float v[3] = {3, 0, 2.5f};
    size_t changes = 0;
    std::vector<uint32_t> previous;
    for (int frame = 0; frame < 600; ++frame) {
        for (int k = 0; k < 3; ++k) {
            v[k] += std::normal_distribution<float>(0.0f, 0.4f)(rng);
            p[k] += v[k];
        }
        p[1] = std::max(2.0f, p[1]);
        if (frame % 150 == 149) p[0] = p[2] = 600;  // teleport: big coarsening and refining
        std::copy(p, p + 3, cam.position);
        incremental.select(cam, settings);
        full.selectFull(cam, settings);
        const std::vector<uint32_t> a = sortedCut(incremental);
        ASSERT_EQ(a, sortedCut(full)) << "frame " << frame;
        expectExactCover(h.file, incremental);
        if (a != previous) ++changes;
        previous = a;
    }
    EXPECT_GT(changes, 20u);  // the flight does change the cut
}

TEST(RuntimeSelection, HysteresisStopsFlickerOfAnOscillatingCamera) {
    OpenedHierarchy h(makeSyntheticHierarchy(400, 8));
    // Find a camera distance along a line at which the cut flickers without hysteresis.
    auto countChanges = [&](float x0, float ratio, int& secondHalf) {
        Selector s(h.file);
        SelectionSettings settings;
        settings.coarsenRatio = ratio;
        Camera cam;
        cam.fovY = 1.0f;
        cam.viewportHeight = 1000;
        std::vector<uint32_t> previous;
        int changes = 0;
        secondHalf = 0;
        for (int frame = 0; frame < 200; ++frame) {
            cam.position[0] = x0 * (1.0f + 0.004f * std::sin(0.7f * float(frame)));  // +-0.4 %
            cam.position[1] = 30;
            cam.position[2] = 100;
            s.select(cam, settings);
            const std::vector<uint32_t> cut = sortedCut(s);
            if (frame > 0 && cut != previous) {
                ++changes;
                if (frame >= 100) ++secondHalf;
            }
            previous = cut;
        }
        return changes;
    };
    int tested = 0;
    for (float x0 = -200; x0 > -20000; x0 *= 1.07f) {
        int withoutLate = 0, withLate = 0;
        countChanges(x0, 1.0f, withoutLate);
        if (withoutLate < 10) continue;
        ++tested;
        countChanges(x0, 0.8f, withLate);
        EXPECT_EQ(withLate, 0) << "x0 " << x0 << " flickers " << withoutLate << " times without hysteresis";
    }
    EXPECT_GT(tested, 3);  // the scenario exists at several distances
}

TEST(RuntimeSelection, CollisionCutIsFinerNearTheQueryPoint) {
    OpenedHierarchy h(makeSyntheticHierarchy(900, 4));
    Selector s(h.file);
    const float point[3] = {150, 5, 150};
    const float ratio = 0.5f;
    s.selectByDistance(point, ratio, 1.0f);
    expectExactCover(h.file, s);
    size_t leavesNear = 0;
    for (uint32_t node : s.cut()) {
        const NodeRecord& r = h.file.node(node);
        const double d = std::sqrt(std::pow(point[0] - r.sphereCenter[0], 2) + std::pow(point[1] - r.sphereCenter[1], 2) +
                                   std::pow(point[2] - r.sphereCenter[2], 2)) - r.sphereRadius;
        if (!h.file.isLeaf(node)) {
            EXPECT_LE(r.geometricError, ratio * std::max(d, 1e-6) * 1.0001) << node;
        }
        if (h.file.isLeaf(node) && d < 20) ++leavesNear;
    }
    EXPECT_GT(leavesNear, 0u);
    EXPECT_LT(s.cut().size, h.file.objectCount());  // coarser far away
}

TEST(RuntimeSelection, LeasedSelectionStaysExactAcrossSettingChangesAndMixedCalls) {
    // The same selector is driven by select() (leases), selectFull() and reset(), with tau
    // changing from time to time; a second selector recomputes every frame with selectFull
    // from the same previous cut. Both must agree at every frame.
    OpenedHierarchy h(makeSyntheticHierarchy(1500, 12, 3, 2, 0.05f));
    Selector mixed(h.file), reference(h.file);
    SelectionSettings settings;
    Camera cam;
    cam.fovY = 0.8f;
    cam.viewportHeight = 900;
    std::mt19937 rng(17);
    float p[3] = {0, 20, 0};
    for (int frame = 0; frame < 800; ++frame) {
        p[0] = 400.0f * std::cos(0.01f * frame) + 150;
        p[2] = 300.0f * std::sin(0.013f * frame) + 150;
        p[1] = 15.0f + 10.0f * std::sin(0.05f * frame);
        std::copy(p, p + 3, cam.position);
        if (frame % 97 == 0) settings.pixelTolerance = std::uniform_real_distribution<float>(0.5f, 3.0f)(rng);
        if (frame % 211 == 0) {
            mixed.reset();
            reference.reset();
        }
        if (frame % 53 == 0) mixed.selectFull(cam, settings);
        else mixed.select(cam, settings);
        reference.selectFull(cam, settings);
        ASSERT_EQ(sortedCut(mixed), sortedCut(reference)) << "frame " << frame;
        expectExactCover(h.file, mixed);
    }
}

TEST(RuntimeSelection, ExactWithSpheresThatNestOnlyWithinTheFileSlack) {
    // Parent spheres shrunk to just below the children's extent (inside the reader's slack),
    // all inner errors equal, and cameras placed alternately at a node's centre and just
    // inside its refine sphere on the side away from its parent's centre (where the file's
    // raw sse is larger for the child than for the parent: near-tie decisions). Incremental
    // and full selection must agree at every frame, with an exact cover.
    BuildArrays p = makeSyntheticHierarchy(600, 21, 2, 1, 0.02f);
    for (size_t i = 0; i < p.nodes.size(); ++i) {  // children come first (post-order)
        NodeRecord& node = p.nodes[i];
        if (node.childCount == 0) continue;
        node.geometricError = 1.0f;
        double reach = 0;
        for (uint32_t k = 0; k < node.childCount; ++k) {
            const NodeRecord& c = p.nodes[p.childIndices[node.firstChild + k]];
            double d2 = 0;
            for (int a = 0; a < 3; ++a) d2 += std::pow(double(c.sphereCenter[a]) - node.sphereCenter[a], 2);
            reach = std::max(reach, std::sqrt(d2) + c.sphereRadius);
        }
        // The reader's slack is 1e-5 * (1 + max(radius, |centre coordinates|)): use half of it.
        double scale = reach;
        for (int a = 0; a < 3; ++a) scale = std::max(scale, std::fabs(double(node.sphereCenter[a])));
        node.sphereRadius = float(reach - 0.5e-5 * (scale + 1.0));
    }
    OpenedHierarchy h(p);
    ASSERT_TRUE(h.file.isOpen());
    Selector incremental(h.file), full(h.file);
    SelectionSettings settings;
    settings.coarsenRatio = 1.0f;  // both thresholds on the same boundary
    Camera cam;
    const double k = cam.viewportHeight / (2.0 * std::tan(cam.fovY * 0.5));
    std::mt19937 rng(4);
    std::vector<uint32_t> innerWithParent;
    for (uint32_t i = 0; i < h.file.nodeCount(); ++i)
        if (!h.file.isLeaf(i) && h.file.node(i).parent != kNoIndex) innerWithParent.push_back(i);
    size_t changes = 0;
    std::vector<uint32_t> previous;
    uint32_t c = innerWithParent[0];
    for (int frame = 0; frame < 3000; ++frame) {
        if (frame % 2 == 0) {
            // First at the centre of a random node: its region gets refined.
            c = innerWithParent[rng() % innerWithParent.size()];
            for (int a = 0; a < 3; ++a) cam.position[a] = h.file.node(c).sphereCenter[a];
        } else {
            // Then just inside its refine sphere, on the side away from its parent's centre.
            const NodeRecord& child = h.file.node(c);
            const NodeRecord& parent = h.file.node(child.parent);
            double u[3], len = 0;
            for (int a = 0; a < 3; ++a) {
                u[a] = double(child.sphereCenter[a]) - parent.sphereCenter[a];
                len += u[a] * u[a];
            }
            len = std::sqrt(len);
            if (len < 1e-9) {
                u[0] = 1;
                len = 1;
            }
            const double reach = child.geometricError * k / settings.pixelTolerance + child.sphereRadius;
            double scale = parent.sphereRadius;
            for (int a = 0; a < 3; ++a) scale = std::max(scale, std::fabs(double(parent.sphereCenter[a])));
            const double inside = reach - 0.2e-5 * (scale + 1.0);
            for (int a = 0; a < 3; ++a) cam.position[a] = float(child.sphereCenter[a] + u[a] / len * inside);
        }
        incremental.select(cam, settings);
        full.selectFull(cam, settings);
        const std::vector<uint32_t> cut = sortedCut(full);
        ASSERT_EQ(sortedCut(incremental), cut) << "frame " << frame;
        changes += cut != previous;
        previous = cut;
    }
    expectExactCover(h.file, incremental);
    EXPECT_GT(changes, 100u);
}

namespace {

// Signed distances of a point to the planes of the view frustum of `c`, in double: inside
// when every value is >= 0. Independent of the selector's float planes.
std::vector<double> frustumDistances(const ViewCamera& c, const float p[3]) {
    double f[3] = {c.forward[0], c.forward[1], c.forward[2]};
    const double fl = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    for (double& x : f) x /= fl;
    double r[3] = {f[1] * c.up[2] - f[2] * c.up[1], f[2] * c.up[0] - f[0] * c.up[2], f[0] * c.up[1] - f[1] * c.up[0]};
    const double rl = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    for (double& x : r) x /= rl;
    const double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    double q[3];
    for (int k = 0; k < 3; ++k) q[k] = double(p[k]) - c.position[k];
    const double x = q[0] * r[0] + q[1] * r[1] + q[2] * r[2], y = q[0] * u[0] + q[1] * u[1] + q[2] * u[2],
                 z = q[0] * f[0] + q[1] * f[1] + q[2] * f[2];
    const double ty = std::tan(0.5 * c.fovY), tx = ty * c.aspect;
    // Distance to the plane x = z tx is (z tx - x) / sqrt(tx^2 + 1), and so on.
    std::vector<double> d = {(z * tx - x) / std::sqrt(tx * tx + 1), (z * tx + x) / std::sqrt(tx * tx + 1),
                             (z * ty - y) / std::sqrt(ty * ty + 1), (z * ty + y) / std::sqrt(ty * ty + 1),
                             z - c.nearDistance};
    if (std::isfinite(c.farDistance)) d.push_back(c.farDistance - z);
    return d;
}

// -1: the node's sphere lies outside one plane by more than a float-rounding slack; +1: it
// is that much inside every plane's outer side; 0: in between (too close to call).
int sphereVersusFrustum(const ViewCamera& c, const NodeRecord& r) {
    double scale = r.sphereRadius + 1.0;
    for (int k = 0; k < 3; ++k) scale += std::fabs(double(r.sphereCenter[k])) + std::fabs(double(c.position[k]));
    const double slack = 1e-4 * scale;
    bool clearlyInside = true;
    for (double d : frustumDistances(c, r.sphereCenter)) {
        if (d < -r.sphereRadius - slack) return -1;
        if (d < -r.sphereRadius + slack) clearlyInside = false;
    }
    return clearlyInside ? 1 : 0;
}

ViewCamera randomViewCamera(std::mt19937& rng) {
    // Inside or near the city (about 400 x 400 world units), looking mostly sideways.
    std::uniform_real_distribution<float> u(0, 1);
    ViewCamera c;
    c.position[0] = -100 + 600 * u(rng);
    c.position[1] = 2 + 60 * u(rng);
    c.position[2] = -100 + 600 * u(rng);
    const float yaw = 6.2831853f * u(rng), pitch = -0.6f + 0.8f * u(rng);
    c.forward[0] = std::cos(yaw) * std::cos(pitch);
    c.forward[1] = std::sin(pitch);
    c.forward[2] = std::sin(yaw) * std::cos(pitch);
    const float scale = 0.1f + 10 * u(rng);  // forward need not be unit
    for (float& x : c.forward) x *= scale;
    c.up[0] = 0.2f * (u(rng) - 0.5f);
    c.up[1] = 1;
    c.up[2] = 0.2f * (u(rng) - 0.5f);
    c.fovY = 0.4f + 1.2f * u(rng);
    c.aspect = 0.5f + 2.0f * u(rng);
    c.viewportHeight = 1080;
    c.nearDistance = u(rng) < 0.5f ? 0.0f : 5 * u(rng);
    c.farDistance = u(rng) < 0.5f ? INFINITY : 100 + 400 * u(rng);
    return c;
}

std::vector<uint32_t> sorted(Span<uint32_t> s) {
    std::vector<uint32_t> v(s.begin(), s.end());
    std::sort(v.begin(), v.end());
    return v;
}

}  // namespace

TEST(RuntimeSelection, FrustumCullingNeitherRefinesNorDrawsNodesOutsideTheView) {
    OpenedHierarchy h(makeSyntheticHierarchy(1500, 31, 4, 1, 0.05f));
    const RuntimeFile& file = h.file;
    Selector culling(file), plain(file);
    SelectionSettings noHysteresis;
    noHysteresis.coarsenRatio = 1.0f;
    std::mt19937 rng(41);
    size_t framesWithBoth = 0, culledTotal = 0;
    for (int frame = 0; frame < 300; ++frame) {
        const ViewCamera cam = randomViewCamera(rng);
        noHysteresis.pixelTolerance = std::uniform_real_distribution<float>(0.5f, 4.0f)(rng);
        culling.select(cam, noHysteresis);
        EXPECT_EQ(culling.stats().culled, culling.culledNodes().size);
        // Drawn and culled nodes together cover every object once; the draw lists hold only
        // the drawn nodes.
        std::vector<int> cover(file.objectCount(), 0);
        size_t inner = 0, originals = 0;
        for (uint32_t n : culling.cut()) {
            for (uint32_t o : file.sources(n)) ++cover[o];
            file.isLeaf(n) ? originals += file.sources(n).size : ++inner;
        }
        for (uint32_t n : culling.culledNodes())
            for (uint32_t o : file.sources(n)) ++cover[o];
        for (uint32_t o = 0; o < file.objectCount(); ++o) ASSERT_EQ(cover[o], 1) << "frame " << frame << " object " << o;
        EXPECT_EQ(culling.proxyNodes().size, inner);
        EXPECT_EQ(culling.originalObjects().size, originals);
        for (uint32_t n : culling.culledNodes()) EXPECT_NE(sphereVersusFrustum(cam, file.node(n)), 1) << n;
        for (uint32_t n : culling.cut()) EXPECT_NE(sphereVersusFrustum(cam, file.node(n)), -1) << n;
        // The parent of every drawn or culled node was refined: visible and over tau.
        const float tau = noHysteresis.pixelTolerance;
        for (Span<uint32_t> list : {culling.cut(), culling.culledNodes()})
            for (uint32_t n : list) {
                const uint32_t parent = file.node(n).parent;
                if (parent == kNoIndex) continue;
                EXPECT_NE(sphereVersusFrustum(cam, file.node(parent)), -1) << "parent of " << n;
                EXPECT_GT(culling.screenSpaceErrorOf(parent, cam), tau * 0.9999f) << "parent of " << n;
            }
        for (uint32_t n : culling.cut())
            if (!file.isLeaf(n)) EXPECT_LE(culling.screenSpaceErrorOf(n, cam), tau * 1.0001f) << n;
        // No hysteresis: the result does not depend on the history.
        Selector fresh(file);
        fresh.select(cam, noHysteresis);
        EXPECT_EQ(sorted(fresh.cut()), sorted(culling.cut())) << "frame " << frame;
        EXPECT_EQ(sorted(fresh.culledNodes()), sorted(culling.culledNodes())) << "frame " << frame;
        // The old call, given the same camera as a Camera, culls nothing and is unchanged.
        plain.select(static_cast<const Camera&>(cam), noHysteresis);
        EXPECT_TRUE(plain.culledNodes().empty());
        expectExactCover(file, plain);
        framesWithBoth += !culling.cut().empty() && !culling.culledNodes().empty();
        culledTotal += culling.culledNodes().size;
        // Drawn nodes are never finer than without culling: culled parts are not refined.
        if (frame % 10 == 0) {
            culling.select(static_cast<const Camera&>(cam), noHysteresis);
            EXPECT_TRUE(culling.culledNodes().empty());
            EXPECT_EQ(sortedCut(culling), sortedCut(plain));
        }
    }
    EXPECT_GT(framesWithBoth, 100u);
    EXPECT_GT(culledTotal, 1000u);

    // Looking away from the whole city: nothing drawn, the roots culled. Looking at it from
    // far away: nothing culled, same cut as without culling.
    ViewCamera away;
    away.position[0] = -500; away.position[1] = 50; away.position[2] = 200;
    away.forward[0] = -1; away.forward[1] = 0; away.forward[2] = 0;
    culling.select(away, noHysteresis);
    EXPECT_TRUE(culling.cut().empty());
    EXPECT_EQ(sorted(culling.culledNodes()), sorted(file.roots()));
    EXPECT_TRUE(culling.proxyNodes().empty());
    EXPECT_TRUE(culling.originalObjects().empty());
    ViewCamera overview = away;
    overview.forward[0] = 1;
    overview.position[0] = -3000;
    culling.select(overview, noHysteresis);
    plain.select(static_cast<const Camera&>(overview), noHysteresis);
    EXPECT_TRUE(culling.culledNodes().empty());
    EXPECT_EQ(sortedCut(culling), sortedCut(plain));
    // A degenerate orientation culls nothing rather than guessing.
    ViewCamera degenerate = away;
    degenerate.forward[0] = 0;
    culling.select(degenerate, noHysteresis);
    EXPECT_TRUE(culling.culledNodes().empty());
    expectExactCover(file, culling);
    degenerate = away;
    degenerate.up[0] = -1; degenerate.up[1] = 0;  // parallel to forward
    culling.select(degenerate, noHysteresis);
    EXPECT_TRUE(culling.culledNodes().empty());
}

TEST(RuntimeSelection, CutChangesListExactlyWhatEnteredAndLeft) {
    OpenedHierarchy h(makeSyntheticHierarchy(1200, 32, 3, 2, 0.05f));
    const RuntimeFile& file = h.file;
    Selector s(file);
    // Construction: everything entered from an empty cut.
    EXPECT_EQ(sorted(s.entered()), sorted(file.roots()));
    EXPECT_TRUE(s.left().empty());
    std::vector<uint32_t> previous = sortedCut(s);
    SelectionSettings settings;
    settings.coarsenRatio = 0.7f;
    std::mt19937 rng(43);
    size_t leasedChanges = 0, steadyFrames = 0;
    for (int frame = 0; frame < 900; ++frame) {
        const float t = 0.01f * frame;
        ViewCamera cam;
        cam.position[0] = 200 + 350 * std::cos(t);
        cam.position[1] = 20 + 15 * std::sin(3 * t);
        cam.position[2] = 200 + 250 * std::sin(1.3f * t);
        cam.forward[0] = -std::sin(2 * t); cam.forward[1] = -0.1f; cam.forward[2] = std::cos(2 * t);
        cam.fovY = 0.9f;
        cam.viewportHeight = 1000;
        const int kind = frame % 150 == 149 ? 4 : (frame / 50) % 4;  // runs of each kind, a reset now and then
        const bool hold = frame % 7 == 3;  // camera did not move since the previous frame
        if (hold) std::copy(cam.position, cam.position + 3, cam.position);
        switch (kind) {
            case 0: s.select(static_cast<const Camera&>(cam), settings); break;
            case 1: s.select(cam, settings); break;
            case 2: s.selectFull(static_cast<const Camera&>(cam), settings); break;
            case 3: s.selectByDistance(cam.position, 0.02f); break;
            default: s.reset(); break;
        }
        const std::vector<uint32_t> now = sortedCut(s);
        std::vector<uint32_t> entered, left;
        std::set_difference(now.begin(), now.end(), previous.begin(), previous.end(), std::back_inserter(entered));
        std::set_difference(previous.begin(), previous.end(), now.begin(), now.end(), std::back_inserter(left));
        ASSERT_EQ(sorted(s.entered()), entered) << "frame " << frame << " kind " << kind;
        ASSERT_EQ(sorted(s.left()), left) << "frame " << frame << " kind " << kind;
        if (kind == 0 && !entered.empty()) ++leasedChanges;
        previous = now;
        // The same call again from the same place changes nothing.
        if (hold && kind != 4) {
            if (kind == 0) s.select(static_cast<const Camera&>(cam), settings);
            else if (kind == 1) s.select(cam, settings);
            else if (kind == 2) s.selectFull(static_cast<const Camera&>(cam), settings);
            else s.selectByDistance(cam.position, 0.02f);
            EXPECT_TRUE(s.entered().empty()) << "frame " << frame;
            EXPECT_TRUE(s.left().empty()) << "frame " << frame;
            ASSERT_EQ(sortedCut(s), previous);
            ++steadyFrames;
        }
    }
    EXPECT_GT(leasedChanges, 10u);  // measured 16
    EXPECT_GT(steadyFrames, 100u);
}
