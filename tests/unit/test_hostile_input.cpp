// SPDX-License-Identifier: AGPL-3.0-or-later
// Hostile input: files crafted to read outside their folder, exhaust memory or stack, or
// overflow arithmetic. Each is refused with a clean exit (< 128) and a message naming the
// problem, never a crash, a hang or an unbounded allocation. The CLI runs are under the
// sanitizer build when there is one.
#include "geo_io.h"
#include "scene_io.h"
#include "test_support.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

std::string sanitizedCli() {
#ifdef AGGRELOD_CLI_ASAN
    return AGGRELOD_CLI_ASAN;
#else
    return AGGRELOD_CLI;
#endif
}
constexpr int kSanitizerExitCode = 86;

void setSanitizerOptions() {
    const std::string code = std::to_string(kSanitizerExitCode);
    ::setenv("ASAN_OPTIONS", ("detect_leaks=0:abort_on_error=0:exitcode=" + code).c_str(), 1);
    ::setenv("UBSAN_OPTIONS", ("halt_on_error=1:print_stacktrace=1:exitcode=" + code).c_str(), 1);
}

void expectCleanExit(const RunResult& r, int expected) {
    ASSERT_TRUE(r.started) << r.describe();
    EXPECT_FALSE(r.signaled) << "crashed\n" << r.describe();
    EXPECT_EQ(r.err.find("ERROR: AddressSanitizer"), std::string::npos) << r.describe();
    EXPECT_EQ(r.err.find("runtime error:"), std::string::npos) << "undefined behaviour\n" << r.describe();
    EXPECT_NE(r.exitCode, kSanitizerExitCode) << "sanitizer report\n" << r.describe();
    EXPECT_TRUE(r.exited) << r.describe();
    EXPECT_EQ(r.exitCode, expected) << r.describe();
}

RunResult bakeWith(const std::string& cli, const fs::path& scene, const fs::path& dir,
                   std::vector<std::string> extra = {}) {
    setSanitizerOptions();
    std::vector<std::string> argv = {cli, "bake", scene.string(), "-o", (dir / "out").string(), "--levels", "2"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return runProgram(argv, dir);
}

RawMesh cube(const std::string& name, double x0) {
    return rawMeshOf(samples::makeBox(name, {x0, 0, 0}, {x0 + 1, 1, 1}));
}

/// A .gltf (JSON) whose geometry lives in one external buffer named `uri`: one node per
/// mesh. `nodeExtra` is spliced into the first node's JSON (e.g. ",\"scale\":[...]").
struct Gltf {
    std::string json;
    std::string bin;
};

Gltf makeGltf(const std::vector<RawMesh>& meshes, const std::string& uri, const std::string& nodeExtra = "") {
    Gltf g;
    std::ostringstream nodes, meshJson, accessors, views;
    for (size_t m = 0; m < meshes.size(); ++m) {
        const RawMesh& mesh = meshes[m];
        const size_t posOffset = g.bin.size();
        g.bin.append(reinterpret_cast<const char*>(mesh.positions.data()), mesh.positions.size() * sizeof(float));
        const size_t idxOffset = g.bin.size();
        g.bin.append(reinterpret_cast<const char*>(mesh.indices.data()), mesh.indices.size() * sizeof(uint32_t));
        const std::string sep = m ? "," : "";
        nodes << sep << "{\"name\":\"" << mesh.name << "\",\"mesh\":" << m << (m == 0 ? nodeExtra : "") << "}";
        meshJson << sep << "{\"primitives\":[{\"attributes\":{\"POSITION\":" << 2 * m << "},\"indices\":" << 2 * m + 1
                 << "}]}";
        accessors << sep << "{\"bufferView\":" << 2 * m << ",\"componentType\":5126,\"count\":"
                  << mesh.positions.size() / 3 << ",\"type\":\"VEC3\"},{\"bufferView\":" << 2 * m + 1
                  << ",\"componentType\":5125,\"count\":" << mesh.indices.size() << ",\"type\":\"SCALAR\"}";
        views << sep << "{\"buffer\":0,\"byteOffset\":" << posOffset << ",\"byteLength\":"
              << mesh.positions.size() * sizeof(float) << "},{\"buffer\":0,\"byteOffset\":" << idxOffset
              << ",\"byteLength\":" << mesh.indices.size() * sizeof(uint32_t) << "}";
    }
    std::ostringstream json;
    json << "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[";
    for (size_t m = 0; m < meshes.size(); ++m) json << (m ? "," : "") << m;
    json << "]}],\"nodes\":[" << nodes.str() << "],\"meshes\":[" << meshJson.str() << "],\"accessors\":["
         << accessors.str() << "],\"bufferViews\":[" << views.str() << "],\"buffers\":[{\"uri\":\"" << uri
         << "\",\"byteLength\":" << g.bin.size() << "}]}";
    g.json = json.str();
    return g;
}

std::vector<RawMesh> twoCubes() { return {cube("cubeA", 0), cube("cubeB", 3)}; }

}  // namespace

// ---------------------------------------------------------------------------------------
// External uris: confined to the input's folder
// ---------------------------------------------------------------------------------------

TEST(HostileGltf, BufferUriLeavingTheFolderIsRefused) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "in");
    const Gltf g = makeGltf(twoCubes(), "../outside.bin");
    writeFile(dir / "outside.bin", g.bin);  // a real, valid buffer: only the place is wrong
    writeFile(dir / "in" / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "in" / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("outside the input's folder"), std::string::npos) << r.describe();
    EXPECT_NE(r.err.find("--allow-external-uris"), std::string::npos) << r.describe();
    EXPECT_FALSE(fs::exists(dir / "out" / "levels.glb"));

    // The same file bakes when the user allows it.
    const RunResult allowed = bakeWith(AGGRELOD_CLI, dir / "in" / "scene.gltf", dir, {"--allow-external-uris"});
    EXPECT_EQ(allowed.exitCode, 0) << allowed.describe();
    EXPECT_TRUE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(HostileGltf, SystemFileUriIsNeverRead) {
    const fs::path dir = freshTestDir(currentTestName());
    Gltf g = makeGltf(twoCubes(), "../../../../../../../../../../etc/passwd");
    writeFile(dir / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("outside the input's folder"), std::string::npos) << r.describe();
}

TEST(HostileGltf, SymlinkLeavingTheFolderIsRefused) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "in");
    const Gltf g = makeGltf(twoCubes(), "data.bin");
    writeFile(dir / "outside.bin", g.bin);
    fs::create_symlink(dir / "outside.bin", dir / "in" / "data.bin");
    writeFile(dir / "in" / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "in" / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("outside the input's folder"), std::string::npos) << r.describe();
}

TEST(HostileGltf, BufferInASubfolderAndDataUrisStillWork) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "in" / "bin");
    const Gltf g = makeGltf(twoCubes(), "bin/data%20one.bin");  // percent-encoded, as uris are
    writeFile(dir / "in" / "bin" / "data one.bin", g.bin);
    writeFile(dir / "in" / "scene.gltf", g.json);
    const RunResult r = bakeWith(AGGRELOD_CLI, dir / "in" / "scene.gltf", dir);
    EXPECT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_TRUE(fs::exists(dir / "out" / "levels.glb"));

    // The same geometry in a data: uri (base64).
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string b64;
    for (size_t i = 0; i < g.bin.size(); i += 3) {
        uint32_t v = uint32_t(uint8_t(g.bin[i])) << 16;
        if (i + 1 < g.bin.size()) v |= uint32_t(uint8_t(g.bin[i + 1])) << 8;
        if (i + 2 < g.bin.size()) v |= uint32_t(uint8_t(g.bin[i + 2]));
        b64 += kAlphabet[(v >> 18) & 63];
        b64 += kAlphabet[(v >> 12) & 63];
        b64 += i + 1 < g.bin.size() ? kAlphabet[(v >> 6) & 63] : '=';
        b64 += i + 2 < g.bin.size() ? kAlphabet[v & 63] : '=';
    }
    const Gltf embedded = makeGltf(twoCubes(), "data:application/octet-stream;base64," + b64);
    writeFile(dir / "embedded.gltf", embedded.json);
    fs::remove_all(dir / "out");
    const RunResult e = bakeWith(AGGRELOD_CLI, dir / "embedded.gltf", dir);
    EXPECT_EQ(e.exitCode, 0) << e.describe();
    EXPECT_TRUE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(HostileGltf, AnOutputNamingAnInputBufferIsRefused) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "in" / "tiles");
    for (const std::string uri : {"data.bin", "scene.aglod", "tiles/data.bin"}) {
        const Gltf g = makeGltf(twoCubes(), uri);
        writeFile(dir / "in" / uri, g.bin);
        writeFile(dir / "in" / "scene.gltf", g.json);
        const std::vector<std::string> argv =
            uri == "data.bin" ? std::vector<std::string>{"--stats", (dir / "in" / "data.bin").string()}
                              : std::vector<std::string>{"--tiles"};
        // OUTDIR is the input's folder: its scene.aglod, or tiles/ with --tiles, would replace the buffer.
        setSanitizerOptions();
        std::vector<std::string> bake = {sanitizedCli(), "bake", (dir / "in" / "scene.gltf").string(), "-o",
                                         (dir / "in").string(), "--levels", "2"};
        bake.insert(bake.end(), argv.begin(), argv.end());
        const RunResult r = runProgram(bake, dir);
        expectCleanExit(r, 1);
        EXPECT_TRUE(r.err.find("is the buffer file") != std::string::npos ||
                    r.err.find("the input's buffer file") != std::string::npos)
            << uri << "\n" << r.describe();
        EXPECT_EQ(readFile(dir / "in" / uri), g.bin) << uri;
        EXPECT_FALSE(fs::exists(dir / "in" / "levels.glb")) << uri;
    }
}

TEST(HostileGltf, DirectoryUriIsRefused) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "sub");
    writeFile(dir / "scene.gltf", makeGltf(twoCubes(), "sub").json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("directory"), std::string::npos) << r.describe();
}

TEST(HostileGltf, ExternalFileSizeIsCheckedBeforeReading) {
    const fs::path dir = freshTestDir(currentTestName());
    const Gltf g = makeGltf(twoCubes(), "big.bin");
    writeFile(dir / "scene.gltf", g.json);
    // A sparse 5 GiB file: reading it whole would take 5 GiB of memory.
    {
        FILE* f = std::fopen((dir / "big.bin").c_str(), "wb");
        ASSERT_TRUE(f);
        ASSERT_EQ(::ftruncate(fileno(f), off_t(5) << 30), 0);
        std::fclose(f);
    }
    const auto start = std::chrono::steady_clock::now();
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("4 GiB or larger"), std::string::npos) << r.describe();
    EXPECT_LT(seconds, 30.0);

    // A smaller file of the wrong size is refused too, naming both sizes.
    writeFile(dir / "big.bin", g.bin + std::string(1000, '\0'));
    const RunResult wrong = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(wrong, 2);
    EXPECT_NE(wrong.err.find("declares byteLength " + std::to_string(g.bin.size())), std::string::npos)
        << wrong.describe();
}

// ---------------------------------------------------------------------------------------
// Structure that costs before it is read
// ---------------------------------------------------------------------------------------

TEST(HostileGltf, DeeplyNestedExtrasAreRefusedBeforeParsing) {
    const fs::path dir = freshTestDir(currentTestName());
    const Gltf g = makeGltf(twoCubes(), "data.bin", ",\"extras\":" + std::string(20000, '[') + std::string(20000, ']'));
    writeFile(dir / "data.bin", g.bin);
    writeFile(dir / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("nests deeper than"), std::string::npos) << r.describe();

    // Ordinary nesting (a few levels of extras) is read.
    const Gltf ok = makeGltf(twoCubes(), "data.bin", ",\"extras\":{\"a\":[[{\"b\":[1,2]}]]}");
    writeFile(dir / "ok.gltf", ok.json);
    const RunResult fine = bakeWith(AGGRELOD_CLI, dir / "ok.gltf", dir);
    EXPECT_EQ(fine.exitCode, 0) << fine.describe();
}

TEST(HostileGltf, HugeSparseAccessorIsRefusedBeforeAllocating) {
    const fs::path dir = freshTestDir(currentTestName());
    Gltf g = makeGltf(twoCubes(), "data.bin");
    // Accessor 0 (cubeA's positions) becomes 2^28 zeros plus one sparse value: nothing in the
    // file backs its 3 GiB of doubles.
    const size_t at = g.json.find("{\"bufferView\":0,\"componentType\":5126,");
    ASSERT_NE(at, std::string::npos) << g.json;
    g.json.replace(at, g.json.find('}', at) + 1 - at,
                   "{\"componentType\":5126,\"count\":268435456,\"type\":\"VEC3\",\"sparse\":{\"count\":1,"
                   "\"indices\":{\"bufferView\":1,\"componentType\":5125},\"values\":{\"bufferView\":0}}}");
    writeFile(dir / "data.bin", g.bin);
    writeFile(dir / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(r, 0);  // cubeA is left out, the other cube is baked
    EXPECT_NE(r.err.find("more than the file's buffers hold"), std::string::npos) << r.describe();
    EXPECT_NE(r.err.find("cubeA"), std::string::npos) << "message must name the object\n" << r.describe();
}

TEST(HostileGltf, HugeNodeScaleIsBadInput) {
    const fs::path dir = freshTestDir(currentTestName());
    const Gltf g = makeGltf(twoCubes(), "data.bin", ",\"scale\":[3.4e38,3.4e38,3.4e38]");
    writeFile(dir / "data.bin", g.bin);
    writeFile(dir / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("1e15"), std::string::npos) << r.describe();
    EXPECT_NE(r.err.find("cubeA"), std::string::npos) << r.describe();
}

TEST(HostileGltf, HugeCoordinateIsBadInput) {
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<RawMesh> meshes = twoCubes();
    meshes[1].positions[0] = 1e30f;
    const Gltf g = makeGltf(meshes, "data.bin");
    writeFile(dir / "data.bin", g.bin);
    writeFile(dir / "scene.gltf", g.json);
    const RunResult r = bakeWith(sanitizedCli(), dir / "scene.gltf", dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("cubeB"), std::string::npos) << r.describe();
    EXPECT_NE(r.err.find("1e+30"), std::string::npos) << r.describe();
}

namespace {

/// A .gltf of `nodes` nodes all instancing one cube, all named `name` (empty: unnamed),
/// either side by side (`chain` false) or each the child of the previous one.
std::string instancingGltf(size_t nodes, const std::string& name, bool chain, const std::string& binUri) {
    std::string json = "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[";
    if (chain) json += "0";
    else
        for (size_t i = 0; i < nodes; ++i) json += (i ? "," : "") + std::to_string(i);
    json += "]}],\"nodes\":[";
    for (size_t i = 0; i < nodes; ++i) {
        json += i ? "," : "";
        json += "{\"mesh\":0";
        if (!name.empty()) json += ",\"name\":\"" + name + "\"";
        if (chain && i + 1 < nodes) json += ",\"children\":[" + std::to_string(i + 1) + "]";
        json += ",\"translation\":[" + std::to_string(chain ? 2 : 2 * int(i % 1000)) + ",0," +
                std::to_string(chain ? 0 : 2 * int(i / 1000)) + "]}";
    }
    const RawMesh c = cube("c", 0);
    json += "],\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0},\"indices\":1}]}],"
            "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" +
            std::to_string(c.positions.size() / 3) +
            ",\"type\":\"VEC3\"},{\"bufferView\":1,\"componentType\":5125,\"count\":" +
            std::to_string(c.indices.size()) + ",\"type\":\"SCALAR\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":" +
            std::to_string(c.positions.size() * 4) + "},{\"buffer\":0,\"byteOffset\":" +
            std::to_string(c.positions.size() * 4) + ",\"byteLength\":" + std::to_string(c.indices.size() * 4) +
            "}],\"buffers\":[{\"uri\":\"" + binUri + "\",\"byteLength\":" +
            std::to_string(c.positions.size() * 4 + c.indices.size() * 4) + "}]}";
    return json;
}

void writeCubeBin(const fs::path& path) {
    const RawMesh c = cube("c", 0);
    std::string bin(reinterpret_cast<const char*>(c.positions.data()), c.positions.size() * 4);
    bin.append(reinterpret_cast<const char*>(c.indices.data()), c.indices.size() * 4);
    writeFile(path, bin);
}

}  // namespace

TEST(HostileGltf, ManyInstancesOfOneNameAreReadInLinearTime) {
    const fs::path dir = freshTestDir(currentTestName());
    writeCubeBin(dir / "cube.bin");
    writeFile(dir / "scene.gltf", instancingGltf(150000, "same", false, "cube.bin"));
    io::SceneReadResult scene;
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(io::readGltfScene((dir / "scene.gltf").string(), io::SceneReadOptions{}, scene, error)) << error;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ASSERT_EQ(scene.objects.size(), 150000u);
    std::set<std::string> names;
    for (const auto& o : scene.objects) names.insert(o.name);
    EXPECT_EQ(names.size(), scene.objects.size()) << "object names must be unique";
    EXPECT_EQ(scene.objects[1].name, "same#2");
    std::printf("150000 instances of one mesh read in %.2f s\n", seconds);
    EXPECT_LT(seconds, 60.0);
}

TEST(HostileGltf, TooManyInstancesAreRefusedWithALimit) {
    const fs::path dir = freshTestDir(currentTestName());
    writeCubeBin(dir / "cube.bin");
    writeFile(dir / "scene.gltf", instancingGltf(1000000, "", false, "cube.bin"));
    const auto start = std::chrono::steady_clock::now();
    const RunResult r = bakeWith(AGGRELOD_CLI, dir / "scene.gltf", dir);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("mesh nodes (instances)"), std::string::npos) << r.describe();
    std::printf("10^6 instances refused in %.2f s\n", seconds);
    EXPECT_LT(seconds, 120.0);

    // More nodes than the node limit: refused before the JSON is parsed.
    writeFile(dir / "more.gltf", instancingGltf(1000001, "n", false, "cube.bin"));
    const RunResult more = bakeWith(AGGRELOD_CLI, dir / "more.gltf", dir);
    expectCleanExit(more, 2);
    EXPECT_NE(more.err.find("more than 1000000 nodes"), std::string::npos) << more.describe();
}

TEST(HostileGltf, DeepNodeChainIsBoundedAndNamed) {
    const fs::path dir = freshTestDir(currentTestName());
    writeCubeBin(dir / "cube.bin");
    // 1000 levels: read; names of unnamed nodes carry their full index path.
    writeFile(dir / "ok.gltf", instancingGltf(1000, "", true, "cube.bin"));
    io::SceneReadResult scene;
    std::string error;
    ASSERT_TRUE(io::readGltfScene((dir / "ok.gltf").string(), io::SceneReadOptions{}, scene, error)) << error;
    ASSERT_EQ(scene.objects.size(), 1000u);
    std::string deepest = "mesh0@0";
    for (int i = 1; i < 1000; ++i) deepest += "/0";
    EXPECT_EQ(scene.objects.back().name, deepest);
    // 1001 levels: refused, naming the limit.
    writeFile(dir / "deep.gltf", instancingGltf(1001, "", true, "cube.bin"));
    EXPECT_FALSE(io::readGltfScene((dir / "deep.gltf").string(), io::SceneReadOptions{}, scene, error));
    EXPECT_NE(error.find("deeper than 1000 levels"), std::string::npos) << error;
}

// ---------------------------------------------------------------------------------------
// 2D coordinates
// ---------------------------------------------------------------------------------------

TEST(Hostile2D, HugeCoordinatesAreBadInput) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.wkt",
              "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))\n"
              "POLYGON ((2e200 0, 3e200 0, 3e200 1e200, 2e200 1e200, 2e200 0))\n");
    setSanitizerOptions();
    const RunResult r =
        runProgram({sanitizedCli(), "aggregate2d", (dir / "in.wkt").string(), "-o", (dir / "out.geojson").string(), "-q"}, dir);
    expectCleanExit(r, 2);
    EXPECT_NE(r.err.find("line 2"), std::string::npos) << r.describe();
    EXPECT_NE(r.err.find("supported range"), std::string::npos) << r.describe();

    writeFile(dir / "in.geojson",
              "{\"type\":\"Polygon\",\"coordinates\":[[[0,0],[1e160,0],[1e160,1e160],[0,1e160],[0,0]]]}");
    const RunResult g = runProgram(
        {sanitizedCli(), "aggregate2d", (dir / "in.geojson").string(), "-o", (dir / "out.geojson").string(), "-q"}, dir);
    expectCleanExit(g, 2);
    EXPECT_NE(g.err.find("supported range"), std::string::npos) << g.describe();
}
