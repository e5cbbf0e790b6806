// SPDX-License-Identifier: AGPL-3.0-or-later
// The bake's export to the runtime file (bake/runtime_export.cpp): render vertices split at
// creases and colour boundaries with positions kept bit for bit, angle-weighted smooth
// normals elsewhere, face colours sRGB-encoded per vertex, per-object LOD nodes at
// kObjectLodLevel, and the whole file read back with the same normals and colours.
#include "runtime_export.h"

#include <aggrelod/collision.h>
#include <aggrelod/runtime_file.h>

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

using namespace aggrelod;

namespace {

// A closed cube [lo, lo + size]^3 with 8 shared vertices, 12 outward triangles.
void cube(float lo, float size, std::vector<float>& p, std::vector<uint32_t>& t) {
    p.clear();
    for (int v = 0; v < 8; ++v)
        for (int k = 0; k < 3; ++k) p.push_back(lo + ((v >> k) & 1 ? size : 0.0f));
    t = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
}

// A subdivided octahedron pushed onto the unit sphere: every dihedral angle is small.
void sphere(int subdivisions, std::vector<float>& p, std::vector<uint32_t>& t) {
    std::vector<std::array<double, 3>> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    t = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    for (int s = 0; s < subdivisions; ++s) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto middle = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            std::array<double, 3> m;
            double l = 0;
            for (int k = 0; k < 3; ++k) l += (m[k] = v[a][k] + v[b][k]) * m[k];
            for (double& x : m) x /= std::sqrt(l);
            v.push_back(m);
            return mid[key] = uint32_t(v.size() - 1);
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < t.size(); i += 3) {
            const uint32_t a = t[i], b = t[i + 1], c = t[i + 2], ab = middle(a, b), bc = middle(b, c), ca = middle(c, a);
            next.insert(next.end(), {a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca});
        }
        t = next;
    }
    p.clear();
    for (const auto& x : v)
        for (double c : x) p.push_back(float(c));
}

void expectCornersKeepPositions(const std::vector<float>& p, const std::vector<uint32_t>& t, const RenderMesh& m) {
    ASSERT_EQ(m.indices.size(), t.size());
    for (size_t i = 0; i < t.size(); ++i)
        for (int k = 0; k < 3; ++k)
            ASSERT_EQ(std::memcmp(&m.positions[3 * size_t(m.indices[i]) + k], &p[3 * size_t(t[i]) + k], 4), 0) << i;
    ASSERT_EQ(m.normals.size(), m.positions.size());
    ASSERT_EQ(m.colors.size() / 4, m.positions.size() / 3);
    for (size_t v = 0; v < m.normals.size(); v += 3) {
        const double l = std::sqrt(double(m.normals[v]) * m.normals[v] + double(m.normals[v + 1]) * m.normals[v + 1] +
                                   double(m.normals[v + 2]) * m.normals[v + 2]);
        EXPECT_NEAR(l, 1.0, 1e-6);
    }
}

}  // namespace

TEST(RuntimeExport, CubeCornersAreSplitIntoFaceNormals) {
    std::vector<float> p;
    std::vector<uint32_t> t;
    cube(-1.0f, 2.0f, p, t);
    RenderMesh m;
    ASSERT_TRUE(buildRenderMesh(p, t, {}, m));
    expectCornersKeepPositions(p, t, m);
    EXPECT_EQ(m.positions.size() / 3, 24u);  // 90 degree edges: 3 copies of each corner
    for (size_t i = 0; i < t.size(); ++i) {
        // The normal of every corner is its face's (an axis), pointing away from the centre.
        const float* n = &m.normals[3 * size_t(m.indices[i])];
        const float* c = &p[3 * size_t(t[i])];
        int axes = 0;
        for (int k = 0; k < 3; ++k)
            if (std::fabs(n[k]) > 0.999f) {
                ++axes;
                EXPECT_GT(n[k] * c[k], 0.0f);
            }
        EXPECT_EQ(axes, 1) << "corner " << i;
    }
    for (uint8_t b : m.colors) EXPECT_EQ(b, 255);  // no colours: white
}

TEST(RuntimeExport, SmoothSurfaceKeepsSharedVerticesWithRadialNormals) {
    std::vector<float> p;
    std::vector<uint32_t> t;
    sphere(3, p, t);  // 512 triangles, dihedral angles well under the crease angle
    RenderMesh m;
    ASSERT_TRUE(buildRenderMesh(p, t, {}, m));
    expectCornersKeepPositions(p, t, m);
    EXPECT_EQ(m.positions.size(), p.size());
    for (size_t v = 0; v < m.positions.size(); v += 3) {
        double d = 0;
        for (int k = 0; k < 3; ++k) d += double(m.normals[v + k]) * m.positions[v + k];
        EXPECT_GT(d, 0.995) << "vertex " << v / 3;  // the normal of a point of the unit sphere is itself
    }
}

// A flat disc of 200 triangles around one hub (the hub's many edges take another sorting path):
// every corner at the hub is one output vertex, every rim vertex too, all facing +z. A second
// disc with a crease through the hub splits it in two.
TEST(RuntimeExport, FanHubIsOneVertexUnlessACreaseCrossesIt) {
    const int segments = 200;
    for (bool crease : {false, true}) {
        std::vector<float> p = {0, 0, 0};
        std::vector<uint32_t> t;
        for (int i = 0; i < segments; ++i) {
            const double a = 2 * M_PI * i / segments;
            // With a crease: the half with y < 0 folded down by 60 degrees about the x axis.
            const double y = std::sin(a), fold = crease && y < 0 ? M_PI / 3 : 0;
            p.insert(p.end(), {float(std::cos(a)), float(y * std::cos(fold)), float(y * std::sin(fold))});
        }
        for (int i = 0; i < segments; ++i) t.insert(t.end(), {0u, uint32_t(1 + i), uint32_t(1 + (i + 1) % segments)});
        RenderMesh m;
        ASSERT_TRUE(buildRenderMesh(p, t, {}, m));
        expectCornersKeepPositions(p, t, m);
        std::set<uint32_t> hub;
        for (size_t c = 0; c < t.size(); c += 3) hub.insert(m.indices[c]);
        if (!crease) {
            EXPECT_EQ(hub.size(), 1u);
            EXPECT_EQ(m.positions.size(), p.size());
            for (size_t v = 0; v < m.normals.size(); v += 3) EXPECT_NEAR(m.normals[v + 2], 1.0f, 1e-6f);
        } else {
            EXPECT_EQ(hub.size(), 2u);  // one copy per side of the crease
        }
    }
}

TEST(RuntimeExport, ColourBoundariesSplitEvenOnAFlatSurfaceAndColoursAreSrgb) {
    // A flat square of two triangles, one red one blue: the diagonal's two vertices split.
    const std::vector<float> p = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    const std::vector<uint32_t> t = {0, 1, 2, 0, 2, 3};
    const std::vector<float> colours = {1, 0, 0, 1, 0, 0, 0.5f, 1};
    RenderMesh m;
    ASSERT_TRUE(buildRenderMesh(p, t, colours, m));
    expectCornersKeepPositions(p, t, m);
    EXPECT_EQ(m.positions.size() / 3, 6u);
    for (size_t v = 0; v < m.normals.size(); v += 3) EXPECT_EQ(m.normals[v + 2], 1.0f);
    for (int corner = 0; corner < 6; ++corner) {
        const uint8_t* c = &m.colors[4 * size_t(m.indices[corner])];
        if (corner < 3) {
            EXPECT_EQ(c[0], 255); EXPECT_EQ(c[1], 0); EXPECT_EQ(c[2], 0); EXPECT_EQ(c[3], 255);
        } else {
            EXPECT_EQ(c[0], 0); EXPECT_EQ(c[1], 0); EXPECT_EQ(c[2], 188); EXPECT_EQ(c[3], 255);  // sRGB of linear 0.5
        }
    }
    // The same colour on both: the square stays 4 vertices with one normal.
    const std::vector<float> same = {0.2f, 0.4f, 0.6f, 1, 0.2f, 0.4f, 0.6f, 1};
    ASSERT_TRUE(buildRenderMesh(p, t, same, m));
    EXPECT_EQ(m.positions.size() / 3, 4u);
    // Bad input is refused, never read out of bounds.
    EXPECT_FALSE(buildRenderMesh(p, {0, 1, 7}, {}, m));
    EXPECT_FALSE(buildRenderMesh(p, {0, 1}, {}, m));
    EXPECT_TRUE(m.positions.empty());
}

TEST(RuntimeExport, CreaseAngleDecidesBetweenSmoothAndSplit) {
    // Two triangles hinged on the x axis, opened by an angle below or above the crease angle.
    for (double degrees : {kCreaseAngleDegrees - 5, kCreaseAngleDegrees + 5}) {
        const double a = degrees * 3.14159265358979 / 180;
        const std::vector<float> p = {0, 0, 0, 1, 0, 0, 0.5f, 1, 0, 0.5f, float(-std::cos(a)), float(std::sin(a))};
        const std::vector<uint32_t> t = {0, 1, 2, 1, 0, 3};
        RenderMesh m;
        ASSERT_TRUE(buildRenderMesh(p, t, {}, m));
        EXPECT_EQ(m.positions.size() / 3, degrees < kCreaseAngleDegrees ? 4u : 6u) << degrees;
    }
}

TEST(RuntimeExport, FileCarriesNormalsColoursAndPerObjectLodLevels) {
    // Object 0 (a coloured cube) under a two-step per-object LOD chain, object 1 a plain cube,
    // both under one level-0 aggregate, under a level-1 root.
    std::vector<InputObject> objects(2);
    objects[0].name = "red";
    objects[1].name = "plain";
    HierarchyNodes nodes;
    nodes.objectCount = 2;
    auto addNode = [&](float lo, float size, std::vector<uint32_t> children, std::vector<uint32_t> sources) {
        HierarchyNode n;
        cube(lo, size, n.positions, n.indices);
        n.children = children;
        n.sources = sources;
        for (int k = 0; k < 3; ++k) {
            n.boundsMin[k] = lo;
            n.boundsMax[k] = lo + size;
            n.sphereCenter[k] = lo + 0.5 * size;
        }
        n.sphereRadius = 0.87 * size;
        nodes.nodes.push_back(n);
        return uint32_t(nodes.nodes.size() - 1);
    };
    const uint32_t red = addNode(0, 1, {}, {0}), plain = addNode(3, 1, {}, {1});
    nodes.nodes[red].leaf = nodes.nodes[plain].leaf = true;
    nodes.nodes[red].faceColors.assign(4 * 12, 0.0f);
    for (int f = 0; f < 12; ++f) nodes.nodes[red].faceColors[4 * f] = nodes.nodes[red].faceColors[4 * f + 3] = 1.0f;
    uint32_t below = red;
    for (int j = 1; j <= 2; ++j) {
        const uint32_t lod = addNode(-0.01f * j, 1 + 0.02f * j, {below}, {0});
        HierarchyNode& n = nodes.nodes[lod];
        n.objectLod = j;
        n.geometricError = 0.01 * j;
        n.sphereRadius = nodes.nodes[below].sphereRadius + 0.02;
        n.faceColors = nodes.nodes[red].faceColors;
        nodes.nodes[below].parent = lod;
        below = lod;
    }
    const uint32_t group = addNode(-1, 6, {below, plain}, {0, 1});
    nodes.nodes[group].firstLevel = nodes.nodes[group].lastLevel = 0;
    nodes.nodes[group].geometricError = 0.5;
    nodes.nodes[group].sphereRadius = 6;
    const uint32_t root = addNode(-2, 8, {group}, {0, 1});
    nodes.nodes[root].firstLevel = nodes.nodes[root].lastLevel = 1;
    nodes.nodes[root].geometricError = 1;
    nodes.nodes[root].sphereRadius = 8;
    nodes.nodes[below].parent = nodes.nodes[plain].parent = group;
    nodes.nodes[group].parent = root;
    nodes.roots = {root};

    runtime::BuildArrays params;
    std::string error;
    ASSERT_TRUE(exportHierarchy(nodes, objects, 7, "test", params, error)) << error;
    std::vector<uint8_t> bytes;
    ASSERT_TRUE(runtime::writeRuntimeFile(params, bytes, error)) << error;
    runtime::RuntimeFile file;
    ASSERT_EQ(runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error), runtime::FileStatus::Ok) << error;
    EXPECT_EQ(file.versionMajor(), runtime::kFormatMajor);
    EXPECT_EQ(file.node(red).level, runtime::kLeafLevel);
    EXPECT_EQ(file.node(2).level, runtime::kObjectLodLevel);
    EXPECT_EQ(file.node(3).level, runtime::kObjectLodLevel);
    EXPECT_EQ(file.node(group).level, 0u);
    EXPECT_EQ(file.node(root).level, 1u);
    // Every node: 24 split vertices with the positions of its cube, normals and colours read
    // back as built; red where the node has red faces, white elsewhere.
    for (uint32_t i = 0; i < file.nodeCount(); ++i) {
        RenderMesh expected;
        ASSERT_TRUE(buildRenderMesh(nodes.nodes[i].positions, nodes.nodes[i].indices, nodes.nodes[i].faceColors, expected));
        const auto v = file.vertices(i), n = file.normals(i);
        const auto c = file.colors(i);
        ASSERT_EQ(v.size, 72u);
        ASSERT_EQ(n.size, 72u);
        ASSERT_EQ(c.size, 96u);
        EXPECT_EQ(std::memcmp(n.data, expected.normals.data(), 4 * n.size), 0) << i;
        EXPECT_EQ(std::memcmp(c.data, expected.colors.data(), c.size), 0) << i;
        const bool isRed = i == red || file.isObjectLod(i);
        EXPECT_EQ(c[1], isRed ? 0 : 255) << i;
        EXPECT_EQ(c[0], 255) << i;
        EXPECT_EQ(file.isObjectLod(i), i == 2 || i == 3);
    }
    // The per-object LODs are no level of their own; the level cuts skip them.
    EXPECT_EQ(runtime::levelsOf(file), (std::vector<uint32_t>{0, 1}));
    std::vector<uint32_t> cut;
    runtime::cutAtLevel(file, 0, cut);
    EXPECT_EQ(cut, (std::vector<uint32_t>{group}));
    runtime::cutAtLevel(file, runtime::kObjectLodLevel, cut);
    EXPECT_EQ(cut, (std::vector<uint32_t>{plain, 3}));
    runtime::cutAtLevel(file, runtime::kLeafLevel, cut);
    EXPECT_EQ(cut, (std::vector<uint32_t>{red, plain}));
    // Deterministic, also with the meshes built on several threads.
    runtime::BuildArrays again;
    ASSERT_TRUE(exportHierarchy(nodes, objects, 7, "test", again, error, 3));
    std::vector<uint8_t> bytesAgain;
    ASSERT_TRUE(runtime::writeRuntimeFile(again, bytesAgain, error));
    EXPECT_EQ(bytes, bytesAgain);

    // Written a node at a time (the bake's way, vertex arrays in spill files): the same bytes,
    // and nothing else left in the folder.
    const std::filesystem::path folder = std::filesystem::temp_directory_path() /
                                         ("aggrelod_stream_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                          "_" + std::to_string(reinterpret_cast<uintptr_t>(&nodes)));
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    const std::string path = (folder / "scene.aglod").string();
    ASSERT_TRUE(io::writeRuntimeScene(nodes, objects, 7, "test", path, error, 2)) << error;
    std::ifstream in(path, std::ios::binary);
    const std::vector<uint8_t> streamed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    in.close();
    EXPECT_EQ(streamed, bytes);
    auto entries = [&] {
        std::vector<std::string> names;
        for (const auto& e : std::filesystem::directory_iterator(folder)) names.push_back(e.path().filename().string());
        return names;
    };
    EXPECT_EQ(entries(), (std::vector<std::string>{"scene.aglod"}));
    // A hierarchy the reader refuses (a child whose parent is another node): an error naming
    // the file and the node, and neither the file nor a spill file left behind.
    nodes.nodes[plain].parent = root;
    std::filesystem::remove(path);
    EXPECT_FALSE(io::writeRuntimeScene(nodes, objects, 7, "test", path, error, 2));
    EXPECT_NE(error.find(path), std::string::npos) << error;
    EXPECT_NE(error.find("has parent"), std::string::npos) << error;
    EXPECT_TRUE(entries().empty());
    std::filesystem::remove_all(folder);
}
