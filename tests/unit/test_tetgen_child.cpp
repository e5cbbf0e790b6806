// SPDX-License-Identifier: AGPL-3.0-or-later
// The TetGen child process: it runs in the helper executable aggrelod-tetgen (started with
// posix_spawn, so it inherits no lock of the bake); a hung child (blocked, gaining no CPU time, as on a lock held at
// fork time) is stopped by the watchdog and retried once, then reported; a child never
// outlives the process that started it.
#include "tetgen_backend.h"
#include "test_support.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdlib>
#include <thread>

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace aggrelod;

namespace {

detail::PlcInput twoCubes() {
    detail::PlcInput plc;
    int marker = 1;
    for (double x0 : {0.0, 3.0}) {
        const InputObject box = samples::makeBox("box", {x0, 0, 0}, {x0 + 1, 1, 1});
        const int base = int(plc.points.size() / 3);
        plc.points.insert(plc.points.end(), box.positions.begin(), box.positions.end());
        for (uint32_t i : box.indices) plc.triangles.push_back(base + int(i));
        plc.triangleMarkers.insert(plc.triangleMarkers.end(), box.indices.size() / 3, marker++);
    }
    return plc;
}

/// Sets AGGRELOD_TEST_TETGEN_HANGS for one scope.
struct HangingChildren {
    explicit HangingChildren(int n) { ::setenv("AGGRELOD_TEST_TETGEN_HANGS", std::to_string(n).c_str(), 1); }
    ~HangingChildren() { ::unsetenv("AGGRELOD_TEST_TETGEN_HANGS"); }
};

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

TEST(TetgenChild, AHungChildIsStoppedAndTriedOnceMore) {
    detail::PlcInput plc = twoCubes();
    plc.hangSeconds = 1;
    HangingChildren hang(1);
    detail::TetMesh mesh;
    const auto start = std::chrono::steady_clock::now();
    const detail::TetgenOutcome outcome = detail::tetrahedralizePlc(plc, mesh);
    const double seconds = secondsSince(start);
    EXPECT_EQ(outcome.status, detail::TetgenStatus::Ok) << outcome.message;
    EXPECT_GT(mesh.tetCount(), 0u);
    EXPECT_GE(seconds, 1.0);
    EXPECT_LT(seconds, 20.0);
}

TEST(TetgenChild, AChildThatHangsTwiceIsReportedNotWaitedFor) {
    detail::PlcInput plc = twoCubes();
    plc.hangSeconds = 1;
    HangingChildren hang(2);
    detail::TetMesh mesh;
    const auto start = std::chrono::steady_clock::now();
    const detail::TetgenOutcome outcome = detail::tetrahedralizePlc(plc, mesh);
    const double seconds = secondsSince(start);
    EXPECT_EQ(outcome.status, detail::TetgenStatus::Hung) << outcome.message;
    EXPECT_NE(outcome.message.find("no progress"), std::string::npos) << outcome.message;
    EXPECT_EQ(mesh.tetCount(), 0u);
    EXPECT_LT(seconds, 20.0);
}

TEST(TetgenChild, TheChildDiesWithItsParent) {
    // This process adopts orphans (subreaper), so a TetGen child that outlived its parent
    // would show up here as a child of ours.
    ASSERT_EQ(::prctl(PR_SET_CHILD_SUBREAPER, 1), 0);
    const pid_t parent = ::fork();
    ASSERT_GE(parent, 0);
    if (parent == 0) {
        // The "bake": its TetGen child blocks, and the watchdog would wait for a long time.
        detail::PlcInput plc = twoCubes();
        plc.hangSeconds = 600;
        ::setenv("AGGRELOD_TEST_TETGEN_HANGS", "2", 1);
        detail::TetMesh mesh;
        detail::tetrahedralizePlc(plc, mesh);
        ::_exit(0);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(700));  // the TetGen child is running
    ASSERT_EQ(::kill(parent, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(parent, &status, 0), parent);
    // Within one second no process of the "bake" may be left.
    const auto start = std::chrono::steady_clock::now();
    bool childrenLeft = true;
    while (secondsSince(start) < 1.0) {
        const pid_t p = ::waitpid(-1, &status, WNOHANG);
        if (p < 0 && errno == ECHILD) {
            childrenLeft = false;
            break;
        }
        if (p == 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    ::prctl(PR_SET_CHILD_SUBREAPER, 0);
    EXPECT_FALSE(childrenLeft) << "a TetGen child outlived its parent by more than 1 s";
}

TEST(TetgenChild, TheBakeRunsTetgenInTheHelperExecutable) {
    const aggrelod::testing::fs::path dir = aggrelod::testing::freshTestDir(aggrelod::testing::currentTestName());
    aggrelod::testing::writeFile(dir / "in.glb", aggrelod::testing::makeGlb({aggrelod::testing::rawMeshOf(samples::makeBox("a", {0, 0, 0}, {1, 1, 1})),
                                                         aggrelod::testing::rawMeshOf(samples::makeBox("b", {3, 0, 0}, {4, 1, 1}))}));
    // A "helper" that ends at once without a result: the bake must notice, so it used it.
    ::setenv("AGGRELOD_TETGEN_HELPER", "/bin/true", 1);
    const aggrelod::testing::RunResult broken =
        aggrelod::testing::runProgram({AGGRELOD_CLI, "bake", (dir / "in.glb").string(), "-o", (dir / "out").string()}, dir);
    ::unsetenv("AGGRELOD_TETGEN_HELPER");
    EXPECT_EQ(broken.exitCode, 3) << broken.describe();  // baking failed (docs/command-line.md)
    EXPECT_NE(broken.err.find("TetGen stopped without a result"), std::string::npos) << broken.describe();
    // The real helper (found in the build tree) bakes.
    const aggrelod::testing::RunResult r =
        aggrelod::testing::runProgram({AGGRELOD_CLI, "bake", (dir / "in.glb").string(), "-o", (dir / "out").string()}, dir);
    EXPECT_EQ(r.exitCode, 0) << r.describe();
    // Run by hand, it refuses: it only talks to the bake.
    const aggrelod::testing::RunResult alone = aggrelod::testing::runProgram({AGGRELOD_TETGEN_HELPER_BIN}, dir);
    EXPECT_EQ(alone.exitCode, 2) << alone.describe();
    EXPECT_NE(alone.err.find("started by aggrelod"), std::string::npos) << alone.describe();
}

TEST(TetgenChild, WithoutTheHelperAForkedChildDoesTheWork) {
    ::setenv("AGGRELOD_TETGEN_HELPER", "", 1);  // none: the forked child
    detail::PlcInput plc = twoCubes();
    detail::TetMesh mesh;
    const detail::TetgenOutcome outcome = detail::tetrahedralizePlc(plc, mesh);
    ::unsetenv("AGGRELOD_TETGEN_HELPER");
    EXPECT_EQ(outcome.status, detail::TetgenStatus::Ok) << outcome.message;
    EXPECT_GT(mesh.tetCount(), 0u);
}
