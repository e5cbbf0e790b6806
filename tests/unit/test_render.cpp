// SPDX-License-Identifier: AGPL-3.0-or-later
// Tests of `aggrelod render` and bake/render.h: ray-cast images of the baked levels of the
// 15-spheres sample (deterministic bytes, size, objects where they project, colours per
// group, grey originals, one sheet panel per level) and its errors on bad input.
#include "render.h"
#include "scene_io.h"

#include "test_support.h"

#include <aggrelod/collision.h>

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

namespace {

using aggrelod::testing::readFile;
using aggrelod::testing::runProgram;
using aggrelod::testing::writeFile;
namespace fs = std::filesystem;
namespace render = aggrelod::render;
namespace runtime = aggrelod::runtime;

/// The 15-spheres sample baked once per test process (about a second). CTest runs every
/// test in its own process, in parallel: each process has its own directory, removed at exit.
struct BakedSample {
    fs::path dir;
    BakedSample() {
        dir = aggrelod::testing::freshTestDir("RenderFixture." + std::to_string(::getpid()));
        const auto made = runProgram({AGGRELOD_MAKE_SAMPLE, "spheres15", "--seed", "1", "-o", (dir / "s.glb").string()}, dir);
        EXPECT_EQ(made.exitCode, 0) << made.describe();
        const auto baked = runProgram({AGGRELOD_CLI, "bake", (dir / "s.glb").string(), "-o", (dir / "out").string(), "--quiet"}, dir);
        EXPECT_EQ(baked.exitCode, 0) << baked.describe();
    }
    ~BakedSample() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};
const fs::path& bakedDir() {
    static const BakedSample sample;
    return sample.dir;
}
fs::path aglodPath() { return bakedDir() / "out" / "scene.aglod"; }
fs::path levelsPath() { return bakedDir() / "out" / "levels.glb"; }

/// Width and height from a PNG's IHDR chunk (big-endian at bytes 16 and 20).
std::pair<int, int> pngSize(const std::string& bytes) {
    if (bytes.size() < 24 || bytes.compare(1, 3, "PNG") != 0) return {-1, -1};
    auto be = [&](size_t at) {
        return int((unsigned char)bytes[at] << 24 | (unsigned char)bytes[at + 1] << 16 | (unsigned char)bytes[at + 2] << 8 |
                   (unsigned char)bytes[at + 3]);
    };
    return {be(16), be(20)};
}

bool isBackground(const unsigned char* p) {
    return p[0] == render::kBackground[0] && p[1] == render::kBackground[1] && p[2] == render::kBackground[2];
}
int saturation(const unsigned char* p) { return std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}); }

/// Pixel (column, row) where a world point projects with `camera` (same pinhole as the
/// renderer: vertical field of view, image centre on the target).
std::pair<double, double> project(const render::Camera& c, const float q[3], int w, int h) {
    double f[3], up[3] = {c.up[0], c.up[1], c.up[2]}, r[3], u[3], p[3];
    for (int k = 0; k < 3; ++k) f[k] = c.target[k] - c.eye[k], p[k] = q[k] - c.eye[k];
    auto norm = [](double* v) {
        const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (int k = 0; k < 3; ++k) v[k] /= l;
    };
    auto cross = [](const double* a, const double* b, double* o) {
        o[0] = a[1] * b[2] - a[2] * b[1], o[1] = a[2] * b[0] - a[0] * b[2], o[2] = a[0] * b[1] - a[1] * b[0];
    };
    norm(f);
    cross(f, up, r);
    norm(r);
    cross(r, f, u);
    const double depth = p[0] * f[0] + p[1] * f[1] + p[2] * f[2];
    const double t = std::tan(c.fovYDegrees * 0.5 * M_PI / 180.0);
    const double x = (p[0] * r[0] + p[1] * r[1] + p[2] * r[2]) / depth / (t * w / h);
    const double y = (p[0] * u[0] + p[1] * u[1] + p[2] * u[2]) / depth / t;
    return {(x + 1) * 0.5 * w, (1 - y) * 0.5 * h};
}

/// The AddressSanitizer build of the CLI when there is one: bad input must not read out of bounds.
std::string cliForBadInput() {
#ifdef AGGRELOD_CLI_ASAN
    return AGGRELOD_CLI_ASAN;
#else
    return AGGRELOD_CLI;
#endif
}

}  // namespace

TEST(Render, SameBytesTwiceAnyThreadCountAndRequestedSize) {
    const fs::path dir = aggrelod::testing::freshTestDir(aggrelod::testing::currentTestName());
    std::vector<std::string> images;
    for (const char* threads : {"1", "2", "1"}) {
        const fs::path out = dir / (std::string("l1_") + threads + "_" + std::to_string(images.size()) + ".png");
        const auto r = runProgram({AGGRELOD_CLI, "render", aglodPath().string(), "--level", "1", "--size", "200x150",
                                   "--threads", threads, "-o", out.string()},
                                  dir);
        ASSERT_EQ(r.exitCode, 0) << r.describe();
        images.push_back(readFile(out));
    }
    EXPECT_EQ(pngSize(images[0]), std::make_pair(200, 150));
    EXPECT_EQ(images[0], images[1]) << "1 and 2 threads differ";
    EXPECT_EQ(images[0], images[2]) << "two runs differ";
}

TEST(Render, OriginalsGreyWhereTheyProjectGroupsColoured) {
    render::RenderScene scene;
    std::string error;
    ASSERT_TRUE(scene.open(aglodPath().string(), error)) << error;
    const int w = 160, h = 120;
    const render::Camera camera = render::defaultCamera(scene, w, h, render::UpAxis::Auto);
    ASSERT_EQ(scene.panels().front().level, runtime::kLeafLevel);

    // Originals: every sphere centre projects onto a drawn pixel; every pixel is grey (or
    // the background, or an edge blend of the two); the corners show background.
    render::RgbImage originals;
    ASSERT_TRUE(render::renderPanel(scene, 0, camera, w, h, 2, originals, error)) << error;
    ASSERT_EQ(originals.pixels.size(), size_t(w * h * 3));
    size_t drawn = 0;
    for (size_t i = 0; i < originals.pixels.size(); i += 3) {
        const unsigned char* p = &originals.pixels[i];
        if (isBackground(p)) continue;
        ++drawn;
        EXPECT_LE(saturation(p), 3) << "pixel " << i / 3 << " of the originals is not grey";
    }
    EXPECT_GT(drawn, size_t(w * h / 20));
    for (uint32_t node : scene.panels().front().nodes) {
        const auto& n = scene.file().node(node);
        const auto [x, y] = project(camera, n.sphereCenter, w, h);
        ASSERT_TRUE(x >= 0 && x < w && y >= 0 && y < h) << "object " << node << " outside the default view";
        EXPECT_FALSE(isBackground(&originals.pixels[(size_t(y) * w + size_t(x)) * 3])) << "object " << node;
    }
    for (auto [x, y] : {std::pair{0, 0}, std::pair{w - 1, 0}, std::pair{0, h - 1}, std::pair{w - 1, h - 1}})
        EXPECT_TRUE(isBackground(&originals.pixels[(size_t(y) * w + size_t(x)) * 3]));

    // A level with several aggregates: different groups get different colours, and each
    // aggregate's colour shows up in the image.
    int groupedPanel = -1;
    for (size_t p = 1; p < scene.panels().size(); ++p) {
        int aggregates = 0;
        for (uint32_t node : scene.panels()[p].nodes) aggregates += scene.file().isLeaf(node) ? 0 : 1;
        if (aggregates >= 3) groupedPanel = int(p);
    }
    ASSERT_GE(groupedPanel, 1);
    render::RgbImage level;
    ASSERT_TRUE(render::renderPanel(scene, size_t(groupedPanel), camera, w, h, 2, level, error)) << error;
    std::set<std::array<int, 3>> baseColours;
    for (uint32_t node : scene.panels()[size_t(groupedPanel)].nodes) {
        const unsigned char* c = scene.colourOf(node);
        baseColours.insert({c[0], c[1], c[2]});
    }
    EXPECT_GE(baseColours.size(), 3u);
    // A pixel shaded from base colour c is c * s, s in [0.3, 1]: find which colours occur.
    std::set<std::array<int, 3>> seen;
    for (size_t i = 0; i < level.pixels.size(); i += 3) {
        const unsigned char* p = &level.pixels[i];
        for (const auto& c : baseColours) {
            const double s = double(p[0] + p[1] + p[2]) / double(c[0] + c[1] + c[2]);
            if (s < 0.29 || s > 1.01) continue;
            if (std::abs(p[0] - c[0] * s) <= 2 && std::abs(p[1] - c[1] * s) <= 2 && std::abs(p[2] - c[2] * s) <= 2)
                seen.insert(c);
        }
    }
    EXPECT_GE(seen.size(), 3u) << "distinct group colours visible on panel " << groupedPanel;
    size_t saturated = 0;
    for (size_t i = 0; i < level.pixels.size(); i += 3) saturated += saturation(&level.pixels[i]) > 30;
    EXPECT_GT(saturated, size_t(w * h / 40));
}

TEST(Render, SheetHasOnePanelPerLevel) {
    const fs::path dir = aggrelod::testing::freshTestDir(aggrelod::testing::currentTestName());
    runtime::RuntimeFile file;
    std::string message;
    ASSERT_EQ(runtime::RuntimeFile::openFile(aglodPath().string(), file, message), runtime::FileStatus::Ok) << message;
    const size_t levels = runtime::levelsOf(file).size();
    ASSERT_GE(levels, 3u);
    bool objectLods = false;
    for (uint32_t i = 0; i < file.nodeCount(); ++i) objectLods = objectLods || file.node(i).level == runtime::kObjectLodLevel;
    // levels.glb has every level of the bake; the runtime file only those with a group of
    // several objects (objects alone are stood in for by their per-object LOD chains).
    aggrelod::io::SceneReadResult glb;
    aggrelod::io::SceneReadOptions everyLevel;
    everyLevel.allScenes = true;  // one scene per level
    ASSERT_TRUE(aggrelod::io::readGltfScene(levelsPath().string(), everyLevel, glb, message)) << message;
    std::set<std::string> glbLevels;
    for (const aggrelod::InputObject& o : glb.objects) glbLevels.insert(o.name.substr(0, o.name.find('_')));

    // .aglod: the originals, the per-object LODs, every level and the cuts drawn from far
    // away; levels.glb: every level.
    struct Case { fs::path input; size_t panels; };
    const size_t drawnAt = std::size(render::kDrawnAtDistances);
    for (const Case& c : {Case{aglodPath(), levels + 1 + (objectLods ? 1 : 0) + drawnAt}, Case{levelsPath(), glbLevels.size()}}) {
        render::RenderScene scene;
        ASSERT_TRUE(scene.open(c.input.string(), message)) << message;
        EXPECT_EQ(scene.panels().size(), c.panels) << c.input;
        for (const render::Panel& p : scene.panels())  // every level's delta, also where bundles stand for it
            if (p.label.rfind("LEVEL ", 0) == 0 && p.level >= 1) EXPECT_NE(p.label.substr(p.label.size() - 7), "DELTA 0") << p.label;
        const fs::path out = dir / (c.input.stem().string() + ".png");
        const auto r = runProgram({AGGRELOD_CLI, "render", c.input.string(), "--sheet", "--size", "64x48", "--columns",
                                   "3", "-o", out.string()},
                                  dir);
        ASSERT_EQ(r.exitCode, 0) << r.describe();
        // Layout: 3 columns of 64 + 4 gaps of 4; rows of 48 + label (7 * 2 + 10) + gap 4.
        const int rows = int((c.panels + 2) / 3);
        EXPECT_EQ(pngSize(readFile(out)), std::make_pair(3 * 64 + 4 * 4, rows * (48 + 24) + (rows + 1) * 4)) << c.input;
        EXPECT_NE(r.out.find(std::to_string(c.panels) + " panels"), std::string::npos) << r.out;
    }
    // The drawn-cut panels are the runtime's selection: they cover every object once, and the
    // farther one draws no more triangles than the nearer one.
    render::RenderScene scene;
    ASSERT_TRUE(scene.open(aglodPath().string(), message)) << message;
    size_t previous = SIZE_MAX;
    for (uint32_t distance : render::kDrawnAtDistances) {
        const int panel = scene.panelOfLevel(render::kDrawnAtLevel + distance);
        ASSERT_GE(panel, 0) << distance;
        std::vector<int> covered(file.objectCount(), 0);
        size_t triangles = 0;
        for (uint32_t n : scene.panels()[size_t(panel)].nodes) {
            for (uint32_t o : file.sources(n)) ++covered[o];
            triangles += file.node(n).indexCount / 3;
        }
        for (uint32_t o = 0; o < file.objectCount(); ++o) EXPECT_EQ(covered[o], 1) << "object " << o;
        EXPECT_LE(triangles, previous) << distance << " diameters";
        previous = triangles;
    }

    // composeSheet puts each panel's pixels at its cell.
    render::RgbImage a{2, 2, std::vector<unsigned char>(12, 10)}, b{2, 2, std::vector<unsigned char>(12, 200)};
    const render::RgbImage sheet = render::composeSheet({a, b}, {"", ""}, 0);
    ASSERT_GT(sheet.width, 4);
    const int labelH = 7 * 2 + 10;
    EXPECT_EQ(sheet.pixels[(size_t(4 + labelH) * sheet.width + 4) * 3], 10);
    EXPECT_EQ(sheet.pixels[(size_t(4 + labelH) * sheet.width + 4 + 2 + 4) * 3], 200);
}

TEST(Render, BadInputClearMessageAndExitCode) {
    const fs::path dir = aggrelod::testing::freshTestDir(aggrelod::testing::currentTestName());
    const std::string out = (dir / "x.png").string();
    auto run = [&](std::vector<std::string> args) {
        args.insert(args.begin(), {cliForBadInput(), "render"});
        return runProgram(args, dir);
    };
    // Missing file.
    auto r = run({(dir / "missing.aglod").string(), "-o", out});
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_NE(r.err.find("missing.aglod"), std::string::npos) << r.err;
    // Corrupt .aglod: one byte changed in the middle.
    std::string bytes = readFile(aglodPath());
    bytes[bytes.size() / 2] = char(bytes[bytes.size() / 2] ^ 0x5A);
    writeFile(dir / "corrupt.aglod", bytes);
    r = run({(dir / "corrupt.aglod").string(), "-o", out});
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_NE(r.err.find("checksum"), std::string::npos) << r.err;
    // Truncated .aglod.
    writeFile(dir / "short.aglod", readFile(aglodPath()).substr(0, 100));
    r = run({(dir / "short.aglod").string(), "-o", out});
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_NE(r.err.find("short.aglod"), std::string::npos) << r.err;
    // Level out of range: names the level and lists the ones there are.
    r = run({aglodPath().string(), "--level", "99", "-o", out});
    EXPECT_EQ(r.exitCode, 1) << r.describe();
    EXPECT_NE(r.err.find("no level 99"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("(levels: originals, "), std::string::npos) << r.err;
    r = run({aglodPath().string(), "--level", "two", "-o", out});
    EXPECT_EQ(r.exitCode, 1) << r.describe();
    // A glTF that is not a levels.glb (the input scene).
    r = run({(bakedDir() / "s.glb").string(), "-o", out});
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_NE(r.err.find("not a levels.glb"), std::string::npos) << r.err;
    // Bad size and camera.
    r = run({aglodPath().string(), "--size", "100", "-o", out});
    EXPECT_EQ(r.exitCode, 1) << r.describe();
    EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
    r = run({aglodPath().string(), "--camera", "1,2,3", "-o", out});
    EXPECT_EQ(r.exitCode, 1) << r.describe();
    EXPECT_NE(r.err.find("--camera"), std::string::npos) << r.err;
    r = run({aglodPath().string(), "--camera", "1,1,1,1,1,1", "-o", out});
    EXPECT_EQ(r.exitCode, 1) << r.describe();
    EXPECT_NE(r.err.find("camera"), std::string::npos) << r.err;
    // Unwritable output.
    r = run({aglodPath().string(), "-o", (dir / "no_such_dir" / "x.png").string()});
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_FALSE(fs::exists(out));
}

TEST(Render, ExplicitCameraChangesTheView) {
    const fs::path dir = aggrelod::testing::freshTestDir(aggrelod::testing::currentTestName());
    const fs::path a = dir / "a.png", b = dir / "b.png";
    auto r = runProgram({AGGRELOD_CLI, "render", aglodPath().string(), "--size", "80x60", "-o", a.string()}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    // The default camera is printed; a far camera looking the same way draws the scene smaller.
    r = runProgram({AGGRELOD_CLI, "render", aglodPath().string(), "--size", "80x60", "--camera", "60,-60,40,0,3,-1,25",
                    "-o", b.string()},
                   dir);
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_NE(readFile(a), readFile(b));
    EXPECT_NE(r.out.find("Camera 60,-60,40,0,3,-1,25"), std::string::npos) << r.out;
}
