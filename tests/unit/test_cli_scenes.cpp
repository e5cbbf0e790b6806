// SPDX-License-Identifier: AGPL-3.0-or-later
// Integration tests of the `aggrelod bake` command line:
//  a) real scenes from ../shared/data bake, every output mesh is closed, and the output
//     passes the Khronos glTF validator;
//  b) bad input (run under AddressSanitizer and UBSan): a clear message and a clean exit status,
//     never a crash;
//  c) determinism: two bakes of one scene give byte-identical outputs;
//  plus the sample scenes (generated here) baked end to end.
#include "scene_io.h"
#include "test_support.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <set>
#include <string>
#include <vector>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

std::string cliPath() { return AGGRELOD_CLI; }

// The AddressSanitizer build of the CLI when it was built (AGGRELOD_ASAN=ON), else the
// plain one. ASan is told to exit with a recognisable status instead of aborting.
std::string asanCliPath() {
#ifdef AGGRELOD_CLI_ASAN
    return AGGRELOD_CLI_ASAN;
#else
    return AGGRELOD_CLI;
#endif
}
constexpr int kAsanExitCode = 86;

void setAsanOptions() {
    ::setenv("ASAN_OPTIONS",
             ("detect_leaks=0:abort_on_error=0:exitcode=" + std::to_string(kAsanExitCode)).c_str(), 1);
    // The sanitizer CLI has UndefinedBehaviorSanitizer too: a report ends the run the same way.
    ::setenv("UBSAN_OPTIONS", ("halt_on_error=1:print_stacktrace=1:exitcode=" + std::to_string(kAsanExitCode)).c_str(), 1);
}

/// Reads the aggregates of OUTDIR/levels.glb back (one object per aggregate node). Support
/// surfaces are passed through as given (open, like the ground they are) and are not
/// aggregates: every other mesh node must be one.
std::vector<InputObject> readLevels(const fs::path& levelsGlb) {
    std::vector<io::LevelsGlbNode> nodes;
    std::string error;
    EXPECT_TRUE(io::readLevelsGlb(levelsGlb.string(), nodes, error)) << levelsGlb << ": " << error;
    io::SceneReadResult scene;
    io::SceneReadOptions everyLevel;
    everyLevel.allScenes = true;  // one scene per level
    EXPECT_TRUE(io::readGltfScene(levelsGlb.string(), everyLevel, scene, error)) << levelsGlb << ": " << error;
    size_t support = 0;
    for (const auto& o : scene.objects) support += o.name.rfind("support_", 0) == 0;
    EXPECT_EQ(scene.objects.size(), nodes.size() + support) << levelsGlb << ": mesh nodes that are neither aggregates nor support surfaces";
    std::vector<InputObject> objects(nodes.size());
    for (size_t i = 0; i < nodes.size(); ++i) {
        objects[i].name = nodes[i].name;
        objects[i].positions = nodes[i].positions;
        objects[i].indices = nodes[i].indices;
    }
    return objects;
}

/// Every aggregate in levels.glb is a closed, consistently and outward-oriented surface.
void expectAllClosed(const std::vector<InputObject>& objects, const std::string& label) {
    EXPECT_FALSE(objects.empty()) << label << ": levels.glb has no mesh";
    size_t nonManifoldEdges = 0;
    for (const auto& o : objects) {
        const ClosedCheck c = checkClosedAfterWeld(o);
        EXPECT_EQ(c.problem, "") << label << ": aggregate '" << o.name << "' is not closed";
        EXPECT_GT(signedVolumeOf(o), 0.0) << label << ": aggregate '" << o.name << "' is inside out";
        nonManifoldEdges += c.edgesUsedMoreThanTwice;
    }
    if (nonManifoldEdges)  // shells of one aggregate touching along an edge (split, then welded here)
        std::printf("%s: %zu edges shared by more than two triangles after welding positions\n",
                    label.c_str(), nonManifoldEdges);
}

/// Bakes `scene` into `outDir` with the plain CLI; expects success.
RunResult bake(const fs::path& scene, const fs::path& outDir, std::vector<std::string> extra) {
    std::vector<std::string> argv = {cliPath(), "bake", scene.string(), "-o", outDir.string()};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return runProgram(argv, outDir.parent_path());
}

/// a) A real scene bakes, its output is closed and valid glTF.
void bakeRealScene(const std::string& relative, const std::vector<std::string>& extra) {
    const fs::path scene = sharedData(relative);
    if (!fs::exists(scene)) {
        GTEST_SKIP() << scene << " is absent: the real test scenes live in ../shared/data "
                                 "next to the repository";
    }
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<std::string> args = {"--levels", "4", "--stats", (dir / "out" / "stats.json").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = bake(scene, dir / "out", args);
    ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
    const fs::path levels = dir / "out" / "levels.glb";
    ASSERT_TRUE(fs::exists(levels)) << r.describe();
    EXPECT_TRUE(fs::exists(dir / "out" / "stats.json"));
    expectAllClosed(readLevels(levels), relative);
    validateGltf({levels}, dir);
}

/// b) The bad-input contract: exit status `expected` (docs/command-line.md), no signal, no
/// ASan report.
void expectCleanExit(const RunResult& r, int expected) {
    ASSERT_TRUE(r.started) << r.describe();
    EXPECT_FALSE(r.signaled) << "crashed\n" << r.describe();
    EXPECT_EQ(r.err.find("ERROR: AddressSanitizer"), std::string::npos) << r.describe();
    EXPECT_EQ(r.err.find("runtime error:"), std::string::npos) << "undefined behaviour\n" << r.describe();
    EXPECT_NE(r.exitCode, kAsanExitCode) << "sanitizer error\n" << r.describe();
    EXPECT_TRUE(r.exited) << r.describe();
    EXPECT_EQ(r.exitCode, expected) << r.describe();
}

RunResult bakeBadInput(const fs::path& scene, const fs::path& dir) {
    setAsanOptions();
    // --tiles: the 3D Tiles writer sees every bad input too, under ASan.
    return runProgram({asanCliPath(), "bake", scene.string(), "-o", (dir / "out").string(), "--levels", "3", "--tiles"},
                      dir);
}

RawMesh cube(const std::string& name, double x0, double y0, double z0, double size = 1.0) {
    return rawMeshOf(samples::makeBox(name, {x0, y0, z0}, {x0 + size, y0 + size, z0 + size}));
}

std::string withoutTimings(const std::string& statsJson) {
    const size_t at = statsJson.find("\"timings\"");
    return at == std::string::npos ? statsJson : statsJson.substr(0, at);
}

}  // namespace

// ---------------------------------------------------------------------------------------
// a) real scenes
// ---------------------------------------------------------------------------------------

TEST(CliRealScenes, DeccerCubes) { bakeRealScene("3d/deccer-cubes/SM_Deccer_Cubes.glb", {}); }
TEST(CliRealScenes, DeccerCubesWithRotation) {
    bakeRealScene("3d/deccer-cubes/SM_Deccer_Cubes_With_Rotation.glb", {});
}
TEST(CliRealScenes, OrientationTest) { bakeRealScene("3d/OrientationTest/OrientationTest.glb", {}); }
TEST(CliRealScenes, TruckTownWithoutGround) {
    // Node names checked in town_model.gltf: the three ground meshes.
    bakeRealScene("3d/truck_town/town_model.gltf", {"--exclude", "^(OuterGroundMesh|GrassMesh|RoadMesh)$"});
}
TEST(CliRealScenes, CollisionWorld) { bakeRealScene("3d/collision-world/collision-world.glb", {}); }
TEST(CliRealScenes, TwoCylinderEngine) { bakeRealScene("3d/2CylinderEngine/2CylinderEngine.glb", {}); }

// ---------------------------------------------------------------------------------------
// b) bad input, under AddressSanitizer
// ---------------------------------------------------------------------------------------

TEST(CliBadInput, NanCoordinate) {
    const fs::path dir = freshTestDir(currentTestName());
    RawMesh bad = cube("nanCube", 3, 0, 0);
    bad.positions[4] = std::numeric_limits<float>::quiet_NaN();
    writeFile(dir / "in.glb", makeGlb({cube("goodCubeA", 0, 0, 0), bad, cube("goodCubeB", 0, 3, 0)}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 0);
    const std::string err = lower(r.err);
    EXPECT_TRUE(containsAny(err, {"nan", "not finite", "non-finite"})) << r.describe();
    EXPECT_NE(err.find("nancube"), std::string::npos) << "message must name the object\n" << r.describe();
}

TEST(CliBadInput, InfiniteCoordinate) {
    const fs::path dir = freshTestDir(currentTestName());
    RawMesh bad = cube("infCube", 3, 0, 0);
    bad.positions[0] = std::numeric_limits<float>::infinity();
    writeFile(dir / "in.glb", makeGlb({cube("goodCubeA", 0, 0, 0), bad, cube("goodCubeB", 0, 3, 0)}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 0);
    const std::string err = lower(r.err);
    EXPECT_TRUE(containsAny(err, {"inf", "not finite", "non-finite"})) << r.describe();
    EXPECT_NE(err.find("infcube"), std::string::npos) << r.describe();
}

TEST(CliBadInput, OpenMeshIsReportedAndBakeGoesOn) {
    const fs::path dir = freshTestDir(currentTestName());
    RawMesh open = cube("openCube", 2, 0, 0);
    open.indices.resize(open.indices.size() - 6);  // one face (two triangles) missing
    writeFile(dir / "in.glb", makeGlb({cube("closedCube", 0, 0, 0), open}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 0);
    const std::string err = lower(r.err);
    EXPECT_TRUE(containsAny(err, {"open", "boundary", "not closed"})) << r.describe();
    EXPECT_NE(err.find("opencube"), std::string::npos) << r.describe();
    EXPECT_TRUE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(CliBadInput, IntersectingObjectsAreReportedAndBakeGoesOn) {
    const fs::path dir = freshTestDir(currentTestName());
    // cubeB pierces cubeA (no coplanar faces); farCube keeps the scene more than one model.
    writeFile(dir / "in.glb", makeGlb({cube("cubeA", 0, 0, 0), cube("cubeB", 0.5, 0.3, 0.2),
                                       cube("farCube", 4, 0, 0)}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 0);
    const std::string err = lower(r.err);
    EXPECT_TRUE(containsAny(err, {"intersect", "overlap"})) << r.describe();
    EXPECT_TRUE(containsAny(err, {"cubea", "cubeb"})) << r.describe();
    EXPECT_TRUE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(CliBadInput, SingleObject) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", makeGlb({cube("lonelyCube", 0, 0, 0)}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 0);
    EXPECT_TRUE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(CliBadInput, EmptyScene) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", makeGlb({}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 2);
    EXPECT_TRUE(containsAny(lower(r.err), {"no object", "no objects", "empty"})) << r.describe();
    EXPECT_FALSE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(CliBadInput, IndexOutOfRange) {
    const fs::path dir = freshTestDir(currentTestName());
    RawMesh bad = cube("badIndexCube", 2, 0, 0);
    bad.indices[7] = 99;  // the cube has 8 vertices
    writeFile(dir / "in.glb", makeGlb({cube("cubeA", 0, 0, 0), bad, cube("cubeC", 0, 2, 0)}));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 0);
    const std::string err = lower(r.err);
    EXPECT_NE(err.find("index"), std::string::npos) << r.describe();
    EXPECT_NE(err.find("99"), std::string::npos) << r.describe();
    EXPECT_NE(err.find("badindexcube"), std::string::npos) << r.describe();
}

TEST(CliBadInput, TruncatedGlb) {
    const fs::path dir = freshTestDir(currentTestName());
    const std::string whole = makeGlb({cube("cubeA", 0, 0, 0), cube("cubeB", 2, 0, 0)});
    ASSERT_GT(whole.size(), 100u);
    writeFile(dir / "in.glb", whole.substr(0, 100));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 2);
    EXPECT_TRUE(containsAny(lower(r.err), {"truncated", "invalid glb", "invalid gltf"})) << r.describe();
    EXPECT_FALSE(fs::exists(dir / "out" / "levels.glb"));
}

TEST(CliBadInput, TruncatedRealScene) {
    const fs::path dir = freshTestDir(currentTestName());
    const fs::path real = sharedData("3d/deccer-cubes/SM_Deccer_Cubes.glb");
    if (!fs::exists(real)) GTEST_SKIP() << real << " is absent (../shared/data)";
    writeFile(dir / "in.glb", readFile(real).substr(0, 100));
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 2);
    EXPECT_TRUE(containsAny(lower(r.err), {"truncated", "invalid glb", "invalid gltf"})) << r.describe();
}

TEST(CliBadInput, MissingFile) {
    const fs::path dir = freshTestDir(currentTestName());
    const RunResult r = bakeBadInput(dir / "does_not_exist.glb", dir);
    expectCleanExit(r, 2);
    EXPECT_TRUE(containsAny(lower(r.err), {"no such file", "cannot open", "does not exist"})) << r.describe();
    EXPECT_NE(r.err.find("does_not_exist.glb"), std::string::npos) << "message must name the file\n" << r.describe();
}

TEST(CliBadInput, NotAGltfFile) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", "this is not a glTF file at all, just some text\n");
    const RunResult r = bakeBadInput(dir / "in.glb", dir);
    expectCleanExit(r, 2);
    EXPECT_FALSE(r.err.empty()) << r.describe();
}

// ---------------------------------------------------------------------------------------
// c) determinism, and the sample scenes end to end
// ---------------------------------------------------------------------------------------

TEST(CliDeterminism, Spheres15TwiceGiveIdenticalOutputs) {
    const fs::path dir = freshTestDir(currentTestName());
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(samples::makeSpheres15(1), (dir / "spheres15.glb").string(), error)) << error;
    for (const char* run : {"a", "b"}) {
        const RunResult r = bake(dir / "spheres15.glb", dir / run,
                                 {"--quiet", "--stats", (dir / run / "stats.json").string()});
        ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
    }
    const std::string levelsA = readFile(dir / "a" / "levels.glb"), levelsB = readFile(dir / "b" / "levels.glb");
    ASSERT_FALSE(levelsA.empty());
    EXPECT_TRUE(levelsA == levelsB) << "levels.glb differs between two identical bakes";
    const std::string statsA = readFile(dir / "a" / "stats.json"), statsB = readFile(dir / "b" / "stats.json");
    ASSERT_FALSE(statsA.empty());
    EXPECT_NE(statsA.find("\"timings\""), std::string::npos) << "stats.json has no \"timings\" object";
    EXPECT_EQ(withoutTimings(statsA), withoutTimings(statsB));
    expectAllClosed(readLevels(dir / "a" / "levels.glb"), "spheres15");
    validateGltf({dir / "a" / "levels.glb"}, dir);
}

// Determinism across thread counts, on a real scene whose open meshes are stood in for by
// convex hulls (hull facets with coplanar vertices must be triangulated canonically).
TEST(CliDeterminism, TruckTownSameBytesForOneAndTwoThreads) {
    const fs::path scene = sharedData("3d/truck_town/town_model.gltf");
    if (!fs::exists(scene)) GTEST_SKIP() << "missing " << scene;
    const fs::path dir = freshTestDir(currentTestName());
    for (const char* threads : {"1", "2"}) {
        const fs::path out = dir / (std::string("t") + threads);
        const RunResult r = bake(scene, out,
                                 {"--quiet", "--levels", "4", "--threads", threads, "--exclude",
                                  "^(OuterGroundMesh|GrassMesh|RoadMesh)$", "--stats", (out / "stats.json").string()});
        ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
    }
    EXPECT_TRUE(readFile(dir / "t1" / "levels.glb") == readFile(dir / "t2" / "levels.glb"))
        << "levels.glb depends on the thread count";
    EXPECT_EQ(withoutTimings(readFile(dir / "t1" / "stats.json")), withoutTimings(readFile(dir / "t2" / "stats.json")));
}

TEST(CliSamples, SampleGlbRoundTripAndValidator) {
    const fs::path dir = freshTestDir(currentTestName());
    const auto scene = samples::makeChessBoard(2, true);
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(scene, (dir / "chess.glb").string(), error)) << error;
    io::SceneReadResult back;
    ASSERT_TRUE(io::readGltfScene((dir / "chess.glb").string(), {}, back, error)) << error;
    ASSERT_EQ(back.objects.size(), scene.size());
    for (size_t i = 0; i < scene.size(); ++i) {
        EXPECT_EQ(back.objects[i].name, scene[i].name);
        EXPECT_EQ(back.objects[i].indices.size(), scene[i].indices.size());
        EXPECT_EQ(checkClosedAfterWeld(back.objects[i]).problem, "") << scene[i].name;
        EXPECT_NEAR(signedVolumeOf(back.objects[i]), samples::signedVolume(scene[i]),
                    1e-4 * std::abs(samples::signedVolume(scene[i])) + 1e-6);
    }
    validateGltf({dir / "chess.glb"}, dir);
}

// The one test that fails when the validator is missing (kValidatorCheck): the others skip.
TEST(CliSamples, ValidatorHarnessCatchesErrors) {
    const std::string missing = validatorMissing();
    ASSERT_TRUE(missing.empty()) << missing;
    const fs::path dir = freshTestDir(currentTestName());
    RawMesh bad = cube("badIndexCube", 0, 0, 0);
    bad.indices[7] = 99;
    writeFile(dir / "bad.glb", makeGlb({bad}));
    writeFile(dir / "good.glb", makeGlb({cube("cubeA", 0, 0, 0)}));
    const RunResult good = runValidator({dir / "good.glb"}, dir);
    EXPECT_TRUE(good.exited && good.exitCode == 0) << good.describe();
    EXPECT_NE(good.out.find("numErrors=0"), std::string::npos) << good.describe();
    const RunResult r = runValidator({dir / "good.glb", dir / "bad.glb"}, dir);
    EXPECT_TRUE(r.exited && r.exitCode == 1) << r.describe();
    EXPECT_NE(r.out.find("ACCESSOR_INDEX_OOB"), std::string::npos) << r.describe();
}

#ifdef AGGRELOD_MAKE_SAMPLE
TEST(CliSamples, MakeSampleToolWritesValidGlb) {
    const fs::path dir = freshTestDir(currentTestName());
    std::vector<fs::path> files;
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"two_cubes", "--gap", "0.25"}, {"slabs"}, {"spheres15", "--seed", "3"},
          {"chess", "--board"}, {"random", "--objects", "40", "--triangles", "4000"}, {"forest"}, {"village"}}) {
        std::vector<std::string> argv = {AGGRELOD_MAKE_SAMPLE};
        argv.insert(argv.end(), args.begin(), args.end());
        const fs::path out = dir / (args[0] + ".glb");
        argv.insert(argv.end(), {"-o", out.string()});
        const RunResult r = runProgram(argv, dir);
        ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
        files.push_back(out);
    }
    validateGltf(files, dir);
    const RunResult usage = runProgram({AGGRELOD_MAKE_SAMPLE, "no_such_scene", "-o", (dir / "x.glb").string()}, dir);
    EXPECT_TRUE(usage.exited && usage.exitCode == 2) << usage.describe();
}
#endif

namespace {

// Bakes a generated scene at two explicit deltas and checks that, at the larger one, the
// objects become one connected, closed solid that contains them (volume at least theirs).
void expectJoinedAtLargeDelta(const std::vector<InputObject>& scene, const std::string& deltas,
                              const std::string& label) {
    const fs::path dir = freshTestDir(currentTestName());
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(scene, (dir / "in.glb").string(), error)) << error;
    const RunResult r = bake(dir / "in.glb", dir / "out", {"--delta", deltas});
    ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
    const auto objects = readLevels(dir / "out" / "levels.glb");
    expectAllClosed(objects, label);
    double inputVolume = 0, lo = 1e300, hi = -1e300;
    for (const auto& o : scene) {
        inputVolume += samples::signedVolume(o);
        for (size_t i = 0; i < o.positions.size(); i += 3) {
            lo = std::min(lo, o.positions[i]);
            hi = std::max(hi, o.positions[i]);
        }
    }
    int joined = 0;
    for (const auto& o : objects) {
        double olo = 1e300, ohi = -1e300;
        for (size_t i = 0; i < o.positions.size(); i += 3) {
            olo = std::min(olo, o.positions[i]);
            ohi = std::max(ohi, o.positions[i]);
        }
        if (olo <= lo + 1e-6 && ohi >= hi - 1e-6) {  // spans every input object in x
            ++joined;
            const ClosedCheck c = checkClosedAfterWeld(o);
            EXPECT_EQ(c.components, 1) << label << ": the joined aggregate is not connected";
            EXPECT_GE(signedVolumeOf(o), inputVolume * (1 - 1e-6)) << label;
        }
    }
    EXPECT_EQ(joined, 1) << label << ": expected exactly one aggregate holding every object";
    validateGltf({dir / "out" / "levels.glb"}, dir);
}

}  // namespace

TEST(CliSamples, TwoCubesJoinAboveTheGap) { expectJoinedAtLargeDelta(samples::makeTwoCubes(0.5), "0.25,1", "two_cubes"); }
TEST(CliSamples, OffsetSlabsJoinIntoOneSolid) { expectJoinedAtLargeDelta(samples::makeOffsetSlabs(), "0.5,2", "slabs"); }

TEST(CliSamples, ChessBakes) {
    const fs::path dir = freshTestDir(currentTestName());
    std::string error;
    ASSERT_TRUE(io::writeObjectsGlb(samples::makeChessBoard(1), (dir / "chess.glb").string(), error)) << error;
    const RunResult r = bake(dir / "chess.glb", dir / "out", {"--levels", "4", "--function", "constant"});
    ASSERT_TRUE(r.exited && r.exitCode == 0) << r.describe();
    expectAllClosed(readLevels(dir / "out" / "levels.glb"), "chess");
    validateGltf({dir / "out" / "levels.glb"}, dir);
}
