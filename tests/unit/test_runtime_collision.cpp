// SPDX-License-Identifier: MIT
// Collision queries with Embree (docs/design.md §3) against cuts of a synthetic hierarchy:
// hits equal a brute-force ray/triangle search, coarser levels are conservative (their box
// proxies contain the originals), segment and occlusion agree with the ray query, and a hit
// names the original objects of its node.
#include <aggrelod/runtime_file.h>

#if __has_include(<aggrelod/collision.h>)
#include <aggrelod/collision.h>
#endif
#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#ifdef AGGRELOD_HAVE_COLLISION
using namespace aggrelod::runtime;
using aggrelod::testing::makeSyntheticHierarchy;

namespace {

struct BruteHit {
    double t = INFINITY;
    uint32_t node = kNoIndex;
};

// Moller-Trumbore in double over every triangle of the cut.
BruteHit bruteForce(const RuntimeFile& file, const std::vector<uint32_t>& cut, const double o[3],
                    const double d[3], double maxT) {
    BruteHit best;
    for (uint32_t node : cut) {
        const Span<float> v = file.vertices(node);
        const Span<uint32_t> t = file.triangles(node);
        for (size_t i = 0; i < t.size; i += 3) {
            const float* a = &v[3 * t[i]];
            const float* b = &v[3 * t[i + 1]];
            const float* c = &v[3 * t[i + 2]];
            const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
            const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
            const double p[3] = {d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]};
            const double det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
            if (std::fabs(det) < 1e-12) continue;
            const double s[3] = {o[0] - a[0], o[1] - a[1], o[2] - a[2]};
            const double u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
            if (u < 0 || u > 1) continue;
            const double q[3] = {s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]};
            const double w = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
            if (w < 0 || u + w > 1) continue;
            const double tt = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
            if (tt >= 0 && tt <= maxT && tt < best.t) best = {tt, node};
        }
    }
    return best;
}

struct Fixture {
    std::vector<uint8_t> bytes;
    RuntimeFile file;
    explicit Fixture(uint32_t objects, uint32_t seed) {
        std::string error;
        EXPECT_TRUE(writeRuntimeFile(makeSyntheticHierarchy(objects, seed, 3), bytes, error)) << error;
        EXPECT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error), FileStatus::Ok) << error;
    }
};

// Rays from outside the scene box towards random points inside it.
void randomRay(std::mt19937& rng, const RuntimeFile& file, double o[3], double d[3]) {
    const NodeRecord& root = file.node(file.roots()[0]);
    std::uniform_real_distribution<double> u(0, 1);
    double target[3];
    for (int k = 0; k < 3; ++k) target[k] = root.boundsMin[k] + u(rng) * (root.boundsMax[k] - root.boundsMin[k]);
    double dir[3] = {u(rng) - 0.5, u(rng) * 0.6 - 0.1, u(rng) - 0.5};
    const double len = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    const double far = 2.0 * root.sphereRadius + 10.0;
    for (int k = 0; k < 3; ++k) {
        d[k] = -dir[k] / len;
        o[k] = target[k] + dir[k] / len * far;
    }
}

}  // namespace

TEST(RuntimeCollision, RaycastAtEveryLevelMatchesBruteForce) {
    Fixture f(150, 21);
    CollisionWorld world(f.file, 1);
    ASSERT_TRUE(world.ok()) << world.error();
    std::vector<uint32_t> levels = levelsOf(f.file);
    levels.push_back(kLeafLevel);
    ASSERT_GE(levels.size(), 4u);
    std::mt19937 rng(5);
    for (uint32_t level : levels) {
        world.useLevel(level);
        std::vector<uint32_t> cut;
        cutAtLevel(f.file, level, cut);
        ASSERT_EQ(world.currentCut(), cut);
        int hits = 0, mismatches = 0;
        for (int i = 0; i < 500; ++i) {
            double o[3], d[3];
            randomRay(rng, f.file, o, d);
            const float of[3] = {float(o[0]), float(o[1]), float(o[2])};
            const float df[3] = {float(d[0]), float(d[1]), float(d[2])};
            CollisionHit hit;
            const bool got = world.raycast(of, df, 1e6f, hit);
            const double od[3] = {of[0], of[1], of[2]}, dd[3] = {df[0], df[1], df[2]};
            const double dl = std::sqrt(dd[0] * dd[0] + dd[1] * dd[1] + dd[2] * dd[2]);
            const double du[3] = {dd[0] / dl, dd[1] / dl, dd[2] / dl};
            const BruteHit ref = bruteForce(f.file, cut, od, du, 1e6);
            if (got != (ref.node != kNoIndex)) {
                ++mismatches;
                continue;
            }
            if (!got) continue;
            ++hits;
            EXPECT_NEAR(hit.distance, ref.t, 1e-3 * (1 + ref.t));
            const double nlen = std::sqrt(hit.normal[0] * hit.normal[0] + hit.normal[1] * hit.normal[1] + hit.normal[2] * hit.normal[2]);
            EXPECT_NEAR(nlen, 1.0, 1e-5);
            // Outward box faces seen from outside face the ray.
            EXPECT_LT(hit.normal[0] * du[0] + hit.normal[1] * du[1] + hit.normal[2] * du[2], 0.0);
            ASSERT_EQ(hit.objects.size, f.file.sources(hit.node).size);
            EXPECT_EQ(hit.objects.data, f.file.sources(hit.node).data);
        }
        EXPECT_LE(mismatches, 1) << "level " << level;  // grazing edge hits may differ
        EXPECT_GT(hits, 100) << "level " << level;
    }
}

TEST(RuntimeCollision, CoarserLevelsAreHitNoLaterThanTheOriginals) {
    Fixture f(300, 22);
    CollisionWorld originals(f.file, 1), level(f.file, 1);
    originals.useLevel(kLeafLevel);
    std::mt19937 rng(6);
    for (uint32_t l : levelsOf(f.file)) {
        level.useLevel(l);
        int compared = 0, violations = 0;
        for (int i = 0; i < 2000; ++i) {
            double o[3], d[3];
            randomRay(rng, f.file, o, d);
            const float of[3] = {float(o[0]), float(o[1]), float(o[2])};
            const float df[3] = {float(d[0]), float(d[1]), float(d[2])};
            CollisionHit a, b;
            if (!originals.raycast(of, df, 1e6f, a)) continue;
            ++compared;
            if (!level.raycast(of, df, 1e6f, b) || b.distance > a.distance + 1e-3f) ++violations;
        }
        EXPECT_EQ(violations, 0) << "level " << l;
        EXPECT_GT(compared, 500) << "level " << l;
    }
}

TEST(RuntimeCollision, SegmentAndOcclusionAgreeWithTheRay) {
    Fixture f(120, 23);
    CollisionWorld world(f.file, 1);
    const float point[3] = {30, 5, 30};
    world.useDistanceCut(point, 0.3f);
    // The distance cut covers every object exactly once.
    std::vector<int> cover(f.file.objectCount(), 0);
    for (uint32_t n : world.currentCut())
        for (uint32_t o : f.file.sources(n)) ++cover[o];
    for (int c : cover) ASSERT_EQ(c, 1);
    std::mt19937 rng(7);
    int hits = 0;
    for (int i = 0; i < 1000; ++i) {
        double o[3], d[3];
        randomRay(rng, f.file, o, d);
        const float of[3] = {float(o[0]), float(o[1]), float(o[2])};
        const float df[3] = {float(d[0]), float(d[1]), float(d[2])};
        const float reach = std::uniform_real_distribution<float>(10.0f, 400.0f)(rng);
        CollisionHit ray, seg;
        const bool hitRay = world.raycast(of, df, reach, ray);
        EXPECT_EQ(world.occluded(of, df, reach), hitRay);
        const float end[3] = {of[0] + df[0] * reach, of[1] + df[1] * reach, of[2] + df[2] * reach};
        const bool hitSeg = world.segment(of, end, seg);
        EXPECT_EQ(hitSeg, hitRay);
        if (hitRay && hitSeg) {
            ++hits;
            EXPECT_NEAR(seg.distance, ray.distance, 1e-3f * (1 + ray.distance));
            EXPECT_EQ(seg.node, ray.node);
        }
    }
    EXPECT_GT(hits, 100);
    // Degenerate queries are refused without a hit, never a crash.
    const float zero[3] = {0, 0, 0}, o[3] = {0, 0, 0};
    CollisionHit hit;
    EXPECT_FALSE(world.raycast(o, zero, 10.0f, hit));
    EXPECT_FALSE(world.occluded(o, zero, 10.0f));
}
TEST(RuntimeCollision, CutAtLevelRanksPerObjectLodsBetweenLeavesAndLevelZero) {
    // The same hierarchy with and without a chain of two per-object LODs above every leaf.
    std::vector<uint8_t> plainBytes, chainBytes;
    std::string error;
    ASSERT_TRUE(writeRuntimeFile(makeSyntheticHierarchy(120, 23, 3), plainBytes, error)) << error;
    ASSERT_TRUE(writeRuntimeFile(makeSyntheticHierarchy(120, 23, 3, 1, 1.0f, 2), chainBytes, error)) << error;
    RuntimeFile plain, chain;
    ASSERT_EQ(RuntimeFile::openMemory(plainBytes.data(), plainBytes.size(), plain, error), FileStatus::Ok) << error;
    ASSERT_EQ(RuntimeFile::openMemory(chainBytes.data(), chainBytes.size(), chain, error), FileStatus::Ok) << error;
    ASSERT_EQ(chain.nodeCount(), plain.nodeCount() + 2 * 120);

    // The per-object LODs are not a level.
    EXPECT_EQ(levelsOf(chain), levelsOf(plain));
    ASSERT_GE(levelsOf(chain).size(), 3u);
    // A level k >= 0 gives the same cut as without the chains: no per-object LOD, the leaves
    // where no aggregate of level <= k exists.
    for (uint32_t k : levelsOf(chain)) {
        std::vector<uint32_t> a, b;
        cutAtLevel(plain, k, a);
        cutAtLevel(chain, k, b);
        ASSERT_EQ(a.size(), b.size()) << "level " << k;
        size_t leavesA = 0, leavesB = 0;
        for (uint32_t n : a) leavesA += plain.isLeaf(n);
        for (uint32_t n : b) {
            EXPECT_FALSE(chain.isObjectLod(n)) << "level " << k << " node " << n;
            leavesB += chain.isLeaf(n);
            if (!chain.isLeaf(n)) {
                EXPECT_LE(chain.node(n).level, k);
            }
        }
        EXPECT_EQ(leavesA, leavesB) << "level " << k;
    }
    // kLeafLevel still gives the originals; kObjectLodLevel the top of every chain.
    std::vector<uint32_t> originals, lods;
    cutAtLevel(chain, kLeafLevel, originals);
    cutAtLevel(chain, kObjectLodLevel, lods);
    ASSERT_EQ(originals.size(), 120u);
    ASSERT_EQ(lods.size(), 120u);
    for (uint32_t n : originals) EXPECT_TRUE(chain.isLeaf(n));
    for (uint32_t n : lods) {
        EXPECT_TRUE(chain.isObjectLod(n));
        EXPECT_FALSE(chain.isObjectLod(chain.node(n).parent));
    }
    // Collision against the per-object LODs works like any other cut.
    CollisionWorld world(chain, 1);
    ASSERT_TRUE(world.ok()) << world.error();
    world.useLevel(kObjectLodLevel);
    EXPECT_EQ(world.currentCut(), lods);
}

// Bundles are not a level: levelsOf leaves them out and a cut at a level passes through them.
// A bundle below its own aggregate is passed through by a cut at a level; a bundle whose
// aggregate gave way to the bundles of a group above stands for that aggregate at its level.
TEST(RuntimeCollision, CutAtLevelPassesThroughBundles) {
    const BuildArrays p = makeSyntheticHierarchy(200, 7);
    std::string error;
    std::vector<uint8_t> plainBytes;
    ASSERT_TRUE(writeRuntimeFile(p, plainBytes, error)) << error;
    RuntimeFile plain;
    ASSERT_EQ(RuntimeFile::openMemory(plainBytes.data(), plainBytes.size(), plain, error), FileStatus::Ok) << error;
    const auto rankOf = [](uint32_t level) { return level == kLeafLevel ? -4 : 2 * int64_t(level); };
    // Nodes that can be a bundle of level k (every child ranks below 2k - 1), k = the node's
    // parent's level (a bundle below its aggregate) or the node's own (standing for it).
    const auto relabel = [&](bool ownLevel, BuildArrays& q) {
        size_t count = 0;
        for (uint32_t i = static_cast<uint32_t>(q.nodes.size()); i-- > 0;) {  // parents first
            NodeRecord& n = q.nodes[i];
            if (n.level == kLeafLevel || n.level >= kMaxAggregateLevel || n.parent == kNoIndex) continue;
            const uint32_t k = ownLevel ? n.level : p.nodes[n.parent].level;
            if (k == 0 || k >= kMaxAggregateLevel) continue;
            bool fits = true;
            for (uint32_t c = n.firstChild; c < n.firstChild + n.childCount; ++c)
                fits = fits && rankOf(p.nodes[p.childIndices[c]].level) < 2 * int64_t(k) - 1;
            if (!fits || (!ownLevel && isBundleLevel(q.nodes[n.parent].level))) continue;
            n.level = kBundleLevelFlag | k;
            ++count;
        }
        return count;
    };
    for (bool ownLevel : {false, true}) {
        BuildArrays q = p;
        ASSERT_GT(relabel(ownLevel, q), 0u);
        std::vector<uint8_t> bytes;
        ASSERT_TRUE(writeRuntimeFile(q, bytes, error)) << error;
        RuntimeFile bundles;
        ASSERT_EQ(RuntimeFile::openMemory(bytes.data(), bytes.size(), bundles, error), FileStatus::Ok) << error;
        if (ownLevel) EXPECT_EQ(levelsOf(bundles), levelsOf(plain));  // each level stood for
        for (uint32_t k : levelsOf(bundles)) EXPECT_FALSE(isBundleLevel(k));
        for (uint32_t k : levelsOf(plain)) {
            std::vector<uint32_t> cut, plainCut;
            cutAtLevel(bundles, k, cut);
            cutAtLevel(plain, k, plainCut);
            if (ownLevel) EXPECT_EQ(cut, plainCut) << "level " << k;  // the bundles stand where their aggregates stood
            size_t covered = 0;
            for (uint32_t n : cut) {
                if (!ownLevel) EXPECT_FALSE(bundles.isBundle(n)) << "level " << k << " node " << n;
                covered += bundles.sources(n).size;
            }
            EXPECT_EQ(covered, bundles.objectCount()) << "level " << k;
        }
    }
}

TEST(RuntimeCollision, RaysThroughSharedEdgesAndCornersDoNotSlipThrough) {
    // Each ray enters a leaf box exactly through one of its corners or through a point of an
    // edge, where two or more triangles meet, and goes on towards a point inside the box: a
    // watertight intersector hits one of those triangles. Embree's fast mode tests each
    // triangle on its own in float and can miss both sides of a shared edge, letting a
    // collision query pass through a closed proxy.
    Fixture f(150, 24);
    CollisionWorld world(f.file, 1);
    ASSERT_TRUE(world.ok()) << world.error();
    world.useLevel(kLeafLevel);
    std::mt19937 rng(8);
    std::uniform_real_distribution<double> unit(0, 1);
    size_t rays = 0, slipped = 0;
    for (uint32_t n : world.currentCut()) {
        const Span<float> v = f.file.vertices(n);
        const Span<uint32_t> t = f.file.triangles(n);
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t i = 0; i < v.size; ++i) {
            lo[i % 3] = std::min(lo[i % 3], double(v[i]));
            hi[i % 3] = std::max(hi[i % 3], double(v[i]));
        }
        for (size_t i = 0; i < t.size; ++i) {
            // Corner i of its triangle, then a point on the edge to the next corner.
            const float* a = &v[3 * t[i]];
            const float* b = &v[3 * t[i - i % 3 + (i + 1) % 3]];
            for (int kind = 0; kind < 2; ++kind) {
                const double s = kind == 0 ? 0.0 : unit(rng);
                // Entry point on the surface; inner point in the middle half of the (convex) box.
                double entry[3], inner[3], d[3], len = 0;
                for (int k = 0; k < 3; ++k) {
                    entry[k] = a[k] + s * (double(b[k]) - a[k]);
                    inner[k] = lo[k] + (0.25 + 0.5 * unit(rng)) * (hi[k] - lo[k]);
                    d[k] = inner[k] - entry[k];
                    len += d[k] * d[k];
                }
                len = std::sqrt(len);
                float o[3], df[3];
                for (int k = 0; k < 3; ++k) {
                    df[k] = float(d[k] / len);
                    o[k] = float(entry[k] - 20.0 * d[k] / len);
                }
                // Hit before the entry point (another box in the way) or at it: fine. None, or
                // only later (the far side of the box): the ray slipped through.
                CollisionHit hit;
                ++rays;
                if (!world.raycast(o, df, 1e6f, hit) || hit.distance > 20.0f + 1e-3f) ++slipped;
            }
        }
    }
    EXPECT_GT(rays, 10000u);
    EXPECT_EQ(slipped, 0u) << slipped << " of " << rays << " rays entering through an edge or corner passed it";
}
#else
TEST(RuntimeCollision, NotBuilt) { GTEST_SKIP() << "Embree 3 not found: aggrelod_runtime_collision not built"; }
#endif
