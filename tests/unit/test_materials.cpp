// SPDX-License-Identifier: AGPL-3.0-or-later
// Materials (issue 5, deliverable 4): proxies carry the base colour of the original surface
// nearest to each face, so a far level still reads right in an engine.
//  - base colours round-trip through GLB (one material per colour, or COLOR_0);
//  - a proxy face next to a red object is red, next to a blue one blue;
//  - on a seeded forest-like scene (brown trunks, green canopies, one glTF material per
//    object) a ray-cast of a coarse level's proxies, per-pixel base colour of the hit face,
//    differs from the same ray-cast of the originals by a bounded mean colour distance;
//    levels.glb and proxies.glb carry COLOR_0 and pass the glTF validator.
#include "ray_scene.h"
#include "scene_io.h"
#include "test_support.h"

#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>

namespace aggrelod {
namespace {

using namespace aggrelod::testing;

std::vector<float> uniformColours(const InputObject& o, float r, float g, float b) {
    std::vector<float> c;
    for (size_t t = 0; t < o.indices.size() / 3; ++t) c.insert(c.end(), {r, g, b, 1.0f});
    return c;
}

/// glTF colours are linear; a viewer shows them sRGB-encoded. 0..255.
double srgb255(float linear) {
    const double x = std::min(1.0, std::max(0.0, double(linear)));
    return 255.0 * (x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1.0 / 2.4) - 0.055);
}

double colourDistance255(const float* a, const float* b) {
    double s = 0;
    for (int k = 0; k < 3; ++k) s += (srgb255(a[k]) - srgb255(b[k])) * (srgb255(a[k]) - srgb255(b[k]));
    return std::sqrt(s);
}

/// Seeded forest-like scene: trees on a jittered grid, each a brown trunk (cylinder) and a
/// green canopy (sphere) above it, separate objects with their own (slightly varied) colour.
/// The gap between trunk top and canopy is 10% of the canopy radius.
constexpr float kTrunk[3] = {0.13f, 0.056f, 0.015f};   // sRGB ~ (101, 67, 33)
constexpr float kCanopy[3] = {0.016f, 0.155f, 0.021f}; // sRGB ~ (34, 110, 40)
std::vector<InputObject> makeForestLike(uint32_t seed, int side) {
    samples::Random rng(seed);
    std::vector<InputObject> objects;
    for (int i = 0; i < side; ++i)
        for (int j = 0; j < side; ++j) {
            const double x = 4.0 * i + rng.uniform(-0.8, 0.8), y = 4.0 * j + rng.uniform(-0.8, 0.8);
            const double trunkHeight = rng.uniform(1.8, 2.6), radius = rng.uniform(1.1, 1.6);
            const std::string tree = "tree" + std::to_string(objects.size() / 2);
            InputObject trunk = samples::makeCylinder(tree + "_trunk", {x, y, 0}, rng.uniform(0.18, 0.28), trunkHeight, 10);
            const float shade = float(rng.uniform(0.85, 1.15));
            trunk.triangleColors = uniformColours(trunk, kTrunk[0] * shade, kTrunk[1] * shade, kTrunk[2] * shade);
            InputObject canopy = samples::makeUvSphere(tree + "_canopy", {x, y, trunkHeight + 1.1 * radius}, radius, 14, 8);
            const float green = float(rng.uniform(0.8, 1.2));
            canopy.triangleColors = uniformColours(canopy, kCanopy[0], kCanopy[1] * green, kCanopy[2]);
            for (InputObject* o : {&trunk, &canopy}) {
                o->id = uint32_t(objects.size());
                objects.push_back(std::move(*o));
            }
        }
    return objects;
}

/// Colour ray-caster: per pixel, the base colour of the face hit first (ray_scene.h).
class ColourCaster {
public:
    /// positions 3 * vertexCount (world units), indices 3 * triangleCount, colours 4 per
    /// triangle (empty: white).
    template <typename Real>
    void add(const std::vector<Real>& positions, const std::vector<uint32_t>& indices, const std::vector<float>& colours) {
        if (indices.empty()) return;
        const uint32_t id = scene_.addMesh(positions, indices);
        if (colours_.size() <= id) colours_.resize(id + 1);
        colours_[id] = colours.size() == 4 * (indices.size() / 3) ? colours : std::vector<float>(4 * (indices.size() / 3), 1.0f);
    }
    void commit() { scene_.commit(); }

    /// width x height pixels, RGB linear per pixel (3 floats); covered[i] = 1 when a ray hit.
    /// Pinhole camera at `eye` looking at `target`, +z up, vertical field of view `fovDeg`.
    void render(const double eye[3], const double target[3], double fovDeg, int width, int height,
                std::vector<float>& rgb, std::vector<char>& covered) const {
        double f[3], r[3], u[3];
        for (int k = 0; k < 3; ++k) f[k] = target[k] - eye[k];
        normalize(f);
        const double up[3] = {0, 0, 1};
        cross(f, up, r);
        normalize(r);
        cross(r, f, u);
        const double h = std::tan(fovDeg * M_PI / 360.0), w = h * width / height;
        rgb.assign(size_t(3) * width * height, 0.0f);
        covered.assign(size_t(width) * height, 0);
        for (int py = 0; py < height; ++py)
            for (int px = 0; px < width; ++px) {
                const double sx = (2.0 * (px + 0.5) / width - 1) * w, sy = (1 - 2.0 * (py + 0.5) / height) * h;
                const double d[3] = {f[0] + sx * r[0] + sy * u[0], f[1] + sx * r[1] + sy * u[1], f[2] + sx * r[2] + sy * u[2]};
                const RayHit hit = scene_.first(eye, d);
                if (!hit.hit()) continue;
                const size_t pixel = size_t(py) * width + px;
                covered[pixel] = 1;
                std::copy_n(&colours_[hit.mesh][4 * size_t(hit.triangle)], 3, &rgb[3 * pixel]);
            }
    }

private:
    static void normalize(double v[3]) {
        const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int k = 0; k < 3; ++k) v[k] /= n;
    }
    static void cross(const double a[3], const double b[3], double out[3]) {
        out[0] = a[1] * b[2] - a[2] * b[1];
        out[1] = a[2] * b[0] - a[0] * b[2];
        out[2] = a[0] * b[1] - a[1] * b[0];
    }
    RayScene scene_;
    std::vector<std::vector<float>> colours_;
};

/// Writes a binary PPM (sRGB) for looking at; uncovered pixels light grey.
void writePpm(const fs::path& path, const std::vector<float>& rgb, const std::vector<char>& covered, int width, int height) {
    std::string bytes = "P6\n" + std::to_string(width) + " " + std::to_string(height) + "\n255\n";
    for (size_t i = 0; i < covered.size(); ++i)
        for (int k = 0; k < 3; ++k) bytes.push_back(char(covered[i] ? int(std::lround(srgb255(rgb[3 * i + k]))) : 220));
    writeFile(path, bytes);
}

struct ImageDifference {
    double meanDistance = 0;  ///< mean Euclidean sRGB distance (0..255) over pixels covered in both
    size_t bothCovered = 0, onlyOne = 0;
};

ImageDifference compareImages(const std::vector<float>& a, const std::vector<char>& ca, const std::vector<float>& b,
                              const std::vector<char>& cb) {
    ImageDifference d;
    double sum = 0;
    for (size_t i = 0; i < ca.size(); ++i) {
        if (ca[i] && cb[i]) {
            sum += colourDistance255(&a[3 * i], &b[3 * i]);
            ++d.bothCovered;
        } else if (ca[i] || cb[i]) {
            ++d.onlyOne;
        }
    }
    d.meanDistance = d.bothCovered ? sum / double(d.bothCovered) : 0;
    return d;
}

TEST(Materials, BaseColoursRoundTripThroughGlb) {
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<InputObject> objects = samples::makeTwoCubes(0.5);
    ASSERT_EQ(objects.size(), 2u);
    objects[0].triangleColors = uniformColours(objects[0], 0.8f, 0.1f, 0.05f);  // one material
    for (size_t t = 0; t < objects[1].indices.size() / 3; ++t)                  // COLOR_0
        objects[1].triangleColors.insert(objects[1].triangleColors.end(), {0.1f, 0.2f, t % 2 ? 0.9f : 0.3f, 1.0f});
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(objects, (dir / "cubes.glb").string(), error)) << error;
    validateGltf({dir / "cubes.glb"}, dir);
    io::SceneReadResult back;
    ASSERT_TRUE(io::readGltfScene((dir / "cubes.glb").string(), {}, back, error)) << error;
    ASSERT_EQ(back.objects.size(), 2u);
    for (size_t i = 0; i < 2; ++i) {
        ASSERT_EQ(back.objects[i].triangleColors.size(), objects[i].triangleColors.size()) << i;
        for (size_t k = 0; k < objects[i].triangleColors.size(); ++k)
            EXPECT_FLOAT_EQ(back.objects[i].triangleColors[k], objects[i].triangleColors[k]) << i << " " << k;
    }
    // White objects stay without colours (the documented default).
    const std::vector<InputObject> plain = samples::makeTwoCubes(0.5);
    ASSERT_TRUE(io::writeObjectsGlb(plain, (dir / "plain.glb").string(), error)) << error;
    ASSERT_TRUE(io::readGltfScene((dir / "plain.glb").string(), {}, back, error)) << error;
    for (const InputObject& o : back.objects) EXPECT_TRUE(o.triangleColors.empty()) << o.name;
}

/// Rewrites the JSON chunk of a GLB made by makeGlb (lengths recomputed).
std::string withJsonEdits(const std::string& glb, const std::vector<std::pair<std::string, std::string>>& edits) {
    uint32_t jsonLength = 0;
    std::memcpy(&jsonLength, glb.data() + 12, 4);
    std::string json = glb.substr(20, jsonLength);
    const std::string rest = glb.substr(20 + jsonLength);
    for (const auto& e : edits) {
        const size_t at = json.find(e.first);
        EXPECT_NE(at, std::string::npos) << e.first;
        if (at != std::string::npos) json.replace(at, e.first.size(), e.second);
    }
    while (json.size() % 4) json += ' ';
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    return "glTF" + u32(2) + u32(uint32_t(20 + json.size() + rest.size())) + u32(uint32_t(json.size())) +
           u32(0x4E4F534A) + json + rest;
}

TEST(Materials, BadColourDataIsReportedNotFatal) {
    const fs::path dir = freshTestDir(currentTestName());
    const std::vector<InputObject> cubes = samples::makeTwoCubes(0.5);
    // Mesh 0 names material 7 (there is none); mesh 1's COLOR_0 is its SCALAR index accessor.
    const std::string glb = withJsonEdits(makeGlb({rawMeshOf(cubes[0]), rawMeshOf(cubes[1])}),
                                          {{"\"mode\":4}", "\"mode\":4,\"material\":7}"},
                                           {"{\"POSITION\":2}", "{\"POSITION\":2,\"COLOR_0\":3}"}});
    writeFile(dir / "bad_colours.glb", glb);
    io::SceneReadResult scene;
    std::string error;
    ASSERT_TRUE(io::readGltfScene((dir / "bad_colours.glb").string(), {}, scene, error)) << error;
    ASSERT_EQ(scene.objects.size(), 2u);  // both objects kept, white
    for (const InputObject& o : scene.objects) EXPECT_TRUE(o.triangleColors.empty()) << o.name;
    std::string all;
    for (const Diagnostic& d : scene.diagnostics) all += d.object + ": " + d.message + "\n";
    EXPECT_NE(all.find("material 7 does not exist"), std::string::npos) << all;
    EXPECT_NE(all.find("COLOR_0 unusable"), std::string::npos) << all;
    EXPECT_NE(all.find("neither VEC3 nor VEC4"), std::string::npos) << all;
}

TEST(Materials, ProxyFaceNextToRedObjectIsRed) {
    // Two cubes [0,1]^3 and [1.5,2.5]x[0,1]^2: red on the left, blue on the right, joined
    // at a delta above their gap.
    std::vector<InputObject> objects = samples::makeTwoCubes(0.5);
    ASSERT_EQ(objects.size(), 2u);
    objects[0].triangleColors = uniformColours(objects[0], 1, 0, 0);
    objects[1].triangleColors = uniformColours(objects[1], 0, 0, 1);
    double leftMax = -INFINITY, rightMin = INFINITY;
    for (size_t i = 0; i < objects[0].positions.size(); i += 3) leftMax = std::max(leftMax, objects[0].positions[i]);
    for (size_t i = 0; i < objects[1].positions.size(); i += 3) rightMin = std::min(rightMin, objects[1].positions[i]);
    ASSERT_LT(leftMax, rightMin);
    Settings3D s;
    s.deltas = {1.0};
    s.threadCount = 1;
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, s, h));
    ASSERT_EQ(h.levels.back().aggregates.size(), 1u);
    HierarchyNodes nodes;
    std::string error;
    ProxySettings p;
    p.threadCount = 1;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, p, nodes, error)) << error;
    const HierarchyNode& joined = nodes.nodes.back();
    ASSERT_EQ(joined.sources.size(), 2u);
    auto check = [&](const auto& positions, const std::vector<uint32_t>& indices, const std::vector<float>& colours,
                     const char* what) {
        ASSERT_EQ(colours.size(), 4 * (indices.size() / 3)) << what;
        size_t red = 0, blue = 0;
        for (size_t t = 0; t < indices.size() / 3; ++t) {
            double cx = 0;
            for (int c = 0; c < 3; ++c) cx += positions[3 * size_t(indices[3 * t + c])] / 3.0;
            const float* col = &colours[4 * t];
            if (cx <= leftMax) {  // face over the red cube
                EXPECT_EQ(col[0], 1.0f) << what << " face " << t;
                EXPECT_EQ(col[2], 0.0f) << what << " face " << t;
                ++red;
            } else if (cx >= rightMin) {  // over the blue cube
                EXPECT_EQ(col[0], 0.0f) << what << " face " << t;
                EXPECT_EQ(col[2], 1.0f) << what << " face " << t;
                ++blue;
            }
        }
        EXPECT_GT(red, 0u) << what;
        EXPECT_GT(blue, 0u) << what;
    };
    check(joined.positions, joined.indices, joined.faceColors, "proxy");
    const Aggregate& agg = h.levels.back().aggregates[0];
    check(agg.positions, agg.indices, agg.faceColors, "exact aggregate");
    // Leaves keep the objects' own colours.
    EXPECT_EQ(nodes.nodes[0].faceColors, objects[0].triangleColors);
}

// The level renders of a forest keep its colours. Run on a small forest-like grid and on the
// forest sample of samples/ (aggrelod_make_sample forest, seed 1).
// coarsestIsOneBlob: the coarsest level joins the whole scene into one solid, whose fill
// between the trees is seen from above where the originals show canopies and ground; there
// only "clearly better than one flat colour" (3/4 of its difference) is asserted.
void checkForestColours(const std::vector<InputObject>& generated, const fs::path& dir, bool coarsestIsOneBlob) {
    // Through the GLB reader: the colours come from glTF materials (baseColorFactor).
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(generated, (dir / "forest.glb").string(), error)) << error;
    io::SceneReadResult scene;
    ASSERT_TRUE(io::readGltfScene((dir / "forest.glb").string(), {}, scene, error)) << error;
    const std::vector<InputObject>& objects = scene.objects;
    ASSERT_EQ(objects.size(), generated.size());
    for (const InputObject& o : objects) ASSERT_FALSE(o.triangleColors.empty()) << o.name;
    // Trunk and canopy colours as the scene has them (first trunk, first canopy).
    float trunkColour[3] = {0, 0, 0}, canopyColour[3] = {0, 0, 0};
    for (const InputObject& o : objects) {
        const bool trunk = o.name.find("trunk") != std::string::npos;
        float* c = trunk ? trunkColour : canopyColour;
        if (c[0] == 0 && c[1] == 0 && c[2] == 0) std::copy(o.triangleColors.begin(), o.triangleColors.begin() + 3, c);
    }
    // Camera from the bounds (z up): 3/4 view from the -y side, above.
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (const InputObject& o : objects)
        for (size_t i = 0; i + 2 < o.positions.size(); i += 3)
            for (int k = 0; k < 3; ++k) {
                lo[k] = std::min(lo[k], o.positions[i + k]);
                hi[k] = std::max(hi[k], o.positions[i + k]);
            }
    const double size = std::max(hi[0] - lo[0], hi[1] - lo[1]);

    Settings3D s;
    s.automaticLevelCount = 4;
    s.threadCount = 2;
    Hierarchy3D h;
    ASSERT_TRUE(buildHierarchy3D(objects, s, h));
    HierarchyNodes nodes;
    ProxySettings p;
    p.threadCount = 2;
    ASSERT_TRUE(buildHierarchyNodes(h, objects, p, nodes, error)) << error;
    ASSERT_TRUE(io::writeLevelsGlb(h, objects, (dir / "levels.glb").string(), error, &nodes)) << error;
    ASSERT_TRUE(io::writeProxiesGlb(nodes, objects, (dir / "proxies.glb").string(), error)) << error;
    validateGltf({dir / "levels.glb", dir / "proxies.glb"}, dir);
    // levels.glb carries the aggregates' face colours (COLOR_0), read back exactly.
    io::SceneReadResult levels;
    io::SceneReadOptions everyLevel;
    everyLevel.allScenes = true;  // one scene per level
    ASSERT_TRUE(io::readGltfScene((dir / "levels.glb").string(), everyLevel, levels, error)) << error;
    size_t checked = 0;
    for (size_t k = 0, o = 0; k < h.levels.size(); ++k)
        for (const Aggregate& agg : h.levels[k].aggregates) {
            ASSERT_LT(o, levels.objects.size());
            const InputObject& read = levels.objects[o++];
            ASSERT_EQ(read.indices.size(), agg.indices.size()) << read.name;
            ASSERT_EQ(read.triangleColors.size(), agg.faceColors.size()) << read.name;
            for (size_t i = 0; i < agg.faceColors.size(); ++i) ASSERT_FLOAT_EQ(read.triangleColors[i], agg.faceColors[i]) << read.name;
            ++checked;
        }
    EXPECT_GT(checked, 0u);

    // The same camera on the originals, then on every level (proxies and exact aggregates).
    const int width = 200, height = 150;
    const double target[3] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]};
    const double eye[3] = {target[0], target[1] - 0.55 * size, target[2] + 0.45 * size};
    ColourCaster originals;
    for (const InputObject& o : objects) originals.add(o.positions, o.indices, o.triangleColors);
    originals.commit();
    std::vector<float> reference;
    std::vector<char> referenceCovered;
    originals.render(eye, target, 50, width, height, reference, referenceCovered);
    writePpm(dir / "originals.ppm", reference, referenceCovered, width, height);
    const double trunkCanopy = colourDistance255(trunkColour, canopyColour);
    std::printf("forest scene, %zu objects; trunk/canopy colour distance %.1f (sRGB 0..255)\n", objects.size(),
                trunkCanopy);

    const int coarsest = int(h.levels.size()) - 1;
    for (int k = 0; k <= coarsest; ++k) {
        ColourCaster proxies, exact, flat;
        // Baseline without materials: every face the mean colour of the originals' pixels.
        float mean[4] = {0, 0, 0, 1};
        size_t covered = 0;
        for (size_t i = 0; i < referenceCovered.size(); ++i)
            if (referenceCovered[i]) {
                for (int c = 0; c < 3; ++c) mean[c] += reference[3 * i + c];
                ++covered;
            }
        for (int c = 0; c < 3; ++c) mean[c] /= float(covered);
        size_t groupsWithBoth = 0;
        // The nodes standing for the level's aggregates (an object alone: its LOD chain's top).
        std::set<uint32_t> atLevel(nodes.nodeOfAggregate[size_t(k)].begin(), nodes.nodeOfAggregate[size_t(k)].end());
        for (uint32_t i : atLevel)
            if (const HierarchyNode& n = nodes.nodes[i]; !n.leaf) {
                proxies.add(n.positions, n.indices, n.faceColors);
                std::vector<float> one;
                for (size_t t = 0; t < n.indices.size() / 3; ++t) one.insert(one.end(), mean, mean + 4);
                flat.add(n.positions, n.indices, one);
                bool trunk = false, canopy = false;
                for (uint32_t o : n.sources) (objects[o].name.find("trunk") != std::string::npos ? trunk : canopy) = true;
                groupsWithBoth += trunk && canopy;
            }
        for (const Aggregate& agg : h.levels[size_t(k)].aggregates) exact.add(agg.positions, agg.indices, agg.faceColors);
        proxies.commit();
        exact.commit();
        flat.commit();
        std::vector<float> img;
        std::vector<char> cov;
        proxies.render(eye, target, 50, width, height, img, cov);
        writePpm(dir / ("level" + std::to_string(k) + "_proxies.ppm"), img, cov, width, height);
        const ImageDifference dp = compareImages(reference, referenceCovered, img, cov);
        exact.render(eye, target, 50, width, height, img, cov);
        writePpm(dir / ("level" + std::to_string(k) + "_exact.ppm"), img, cov, width, height);
        const ImageDifference de = compareImages(reference, referenceCovered, img, cov);
        flat.render(eye, target, 50, width, height, img, cov);
        const ImageDifference df = compareImages(reference, referenceCovered, img, cov);
        std::printf("level %d (delta %.3g, %zu groups with trunk and canopy): mean colour difference to the "
                    "originals: proxies %.2f, exact aggregates %.2f, one flat colour %.2f (pixels in both %zu, "
                    "in one only %zu)\n",
                    k, h.levels[size_t(k)].delta, groupsWithBoth, dp.meanDistance, de.meanDistance, df.meanDistance,
                    dp.bothCovered, dp.onlyOne);
        ASSERT_GT(dp.bothCovered, size_t(width) * height / 10) << "the camera must see the forest";
        // Bound: a tenth of the trunk/canopy distance (8 of 255 here). Pixels of the originals
        // and of a level differ only where a face's nearest original surface is not the one
        // seen along the ray (fill between trunk and canopy, silhouettes), a small share of
        // the image: a level that painted trunks green or canopies brown would be the full
        // distance away on those pixels. And well under the difference of one flat colour
        // (the mean of the originals' pixels: what a proxy without materials can best do):
        // at most 0.55 of it (the coarse levels measure 0.48-0.50 across simplifier versions
        // whose proxies differ only in how their faces are laid over trunks and canopies).
        if (coarsestIsOneBlob && k == coarsest) {
            EXPECT_LT(dp.meanDistance, 0.75 * df.meanDistance) << "level " << k;
            EXPECT_LT(de.meanDistance, 0.75 * df.meanDistance) << "level " << k;
        } else {
            EXPECT_LT(dp.meanDistance, 0.1 * trunkCanopy) << "level " << k;
            EXPECT_LT(de.meanDistance, 0.1 * trunkCanopy) << "level " << k;
            EXPECT_LT(dp.meanDistance, 0.55 * df.meanDistance) << "level " << k;
        }
        if (k == coarsest) {
            EXPECT_GT(groupsWithBoth, 0u) << "the coarsest level must join trunks and canopies";
        }
    }
}

TEST(Materials, ForestLevelRenderKeepsColours) {
    checkForestColours(makeForestLike(7, 5), freshTestDir(currentTestName()), false);
}

TEST(Materials, ForestSampleLevelRenderKeepsColours) {
    checkForestColours(samples::makeForest(1), freshTestDir(currentTestName()), true);
}

}  // namespace
}  // namespace aggrelod
