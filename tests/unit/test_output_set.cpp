// SPDX-License-Identifier: AGPL-3.0-or-later
// The output set of `aggrelod bake`: outputs never overwrite the input or each other, nothing
// planted in OUTDIR is followed, a failing move puts the old set back, stale temporaries are
// removed, and a bake killed at any moment leaves the complete old or the complete new set
// (as a reader of OUTDIR/aggrelod-set.json sees it, without another bake) with no process of
// it left running.
#include "test_support.h"

#include "output_set.h"
#include "sha256.h"

#include <aggrelod/samples.h>

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <map>
#include <random>
#include <spawn.h>
#include <string>
#include <thread>
#include <vector>

#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

RawMesh cube(const std::string& name, double x0) {
    return rawMeshOf(samples::makeBox(name, {x0, 0, 0}, {x0 + 1, 1, 1}));
}

std::string threeCubes() { return makeGlb({cube("a", 0), cube("b", 1.5), cube("c", 5)}); }

RunResult bake(const fs::path& scene, const fs::path& out, const fs::path& dir, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {AGGRELOD_CLI, "bake", scene.string(), "-o", out.string(), "-q"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return runProgram(argv, dir);
}

const std::vector<std::string> kSet = {"levels.glb", "proxies.glb", "scene.aglod"};

std::vector<std::string> readSet(const fs::path& out) {
    std::vector<std::string> files;
    for (const auto& name : kSet) files.push_back(fs::exists(out / name) ? readFile(out / name) : std::string("<missing>"));
    return files;
}

/// The set a reader of OUTDIR/aggrelod-set.json sees: each file of it by name with its bytes
/// (the stats file, whose timings differ from bake to bake, by its name only); `status` says
/// whether the manifest is there and every file matches it.
struct SeenSet {
    io::SetCheck check;
    std::map<std::string, std::string> files;
};

SeenSet readThroughManifest(const fs::path& out) {
    SeenSet seen;
    seen.check = io::checkOutputSet(out);
    for (const auto& [name, path] : seen.check.files)
        seen.files[name] = name == "stats.json" ? std::string("<stats>") : readFile(path);
    return seen;
}

std::vector<std::string> leftTemporaries(const fs::path& out) {
    std::vector<std::string> left;
    for (const auto& e : fs::directory_iterator(out))
        if (e.path().filename().string().rfind(".aggrelod-tmp-", 0) == 0) left.push_back(e.path().filename().string());
    return left;
}

}  // namespace

TEST(OutputSet, AnInputNamedLikeAnOutputIsNotOverwritten) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "out");
    const std::string input = threeCubes();
    writeFile(dir / "out" / "levels.glb", input);
    const RunResult r = bake(dir / "out" / "levels.glb", dir / "out", dir);
    EXPECT_EQ(r.exitCode, 1) << r.describe();
    EXPECT_NE(r.err.find("would be overwritten"), std::string::npos) << r.describe();
    EXPECT_EQ(readFile(dir / "out" / "levels.glb"), input);

    writeFile(dir / "in.glb", input);
    const RunResult stats = bake(dir / "in.glb", dir / "out2", dir, {"--stats", (dir / "in.glb").string()});
    EXPECT_EQ(stats.exitCode, 1) << stats.describe();
    EXPECT_NE(stats.err.find("(--stats) is the input"), std::string::npos) << stats.describe();
    EXPECT_NE(stats.err.find("would be overwritten"), std::string::npos) << stats.describe();
    EXPECT_EQ(readFile(dir / "in.glb"), input);
    const RunResult same = bake(dir / "in.glb", dir / "out2", dir, {"--stats", (dir / "out2" / "scene.aglod").string()});
    EXPECT_EQ(same.exitCode, 1) << same.describe();
    EXPECT_NE(same.err.find("are the same file"), std::string::npos) << same.describe();
}

TEST(OutputSet, APlantedSymlinkIsNotFollowed) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "out");
    writeFile(dir / "victim.txt", "precious");
    for (const char* name : {"levels.glb.tmp", "proxies.glb.tmp", "scene.aglod.tmp"})
        fs::create_symlink(dir / "victim.txt", dir / "out" / name);
    writeFile(dir / "in.glb", threeCubes());
    const RunResult r = bake(dir / "in.glb", dir / "out", dir);
    EXPECT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_EQ(readFile(dir / "victim.txt"), "precious");
    EXPECT_FALSE(fs::is_symlink(dir / "out" / "levels.glb"));
    EXPECT_TRUE(fs::is_regular_file(dir / "out" / "levels.glb"));
}

TEST(OutputSet, AFailingMovePutsTheOldSetBack) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", threeCubes());
    ASSERT_EQ(bake(dir / "in.glb", dir / "out", dir, {"--levels", "2"}).exitCode, 0);
    const std::vector<std::string> old = readSet(dir / "out");
    // scene.aglod, moved last, cannot be replaced: a non-empty folder took its place.
    fs::remove(dir / "out" / "scene.aglod");
    fs::create_directories(dir / "out" / "scene.aglod" / "x");
    const RunResult r = bake(dir / "in.glb", dir / "out", dir, {"--levels", "3"});
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_NE(r.err.find("cannot replace"), std::string::npos) << r.describe();
    EXPECT_TRUE(readFile(dir / "out" / "levels.glb") == old[0]) << "levels.glb is not the old one";
    EXPECT_TRUE(readFile(dir / "out" / "proxies.glb") == old[1]) << "proxies.glb is not the old one";
    EXPECT_TRUE(fs::is_directory(dir / "out" / "scene.aglod" / "x"));
    for (const auto& e : fs::directory_iterator(dir / "out"))
        EXPECT_EQ(e.path().filename().string().rfind(".aggrelod-tmp-", 0), std::string::npos) << e.path();
}

TEST(OutputSet, StaleTemporariesAreRemoved) {
    const fs::path dir = freshTestDir(currentTestName());
    fs::create_directories(dir / "out" / ".aggrelod-tmp-999999999-dead01");  // no such process
    writeFile(dir / "out" / ".aggrelod-tmp-999999999-dead01" / "levels.glb", "half written");
    writeFile(dir / "out" / "tiles.tmp", "old temporary");
    const fs::path live = dir / "out" / (".aggrelod-tmp-" + std::to_string(::getpid()) + "-alive1");
    fs::create_directories(live);  // a bake that still runs (this process): left alone
    writeFile(dir / "in.glb", threeCubes());
    const RunResult r = bake(dir / "in.glb", dir / "out", dir);
    EXPECT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_FALSE(fs::exists(dir / "out" / ".aggrelod-tmp-999999999-dead01"));
    EXPECT_FALSE(fs::exists(dir / "out" / "tiles.tmp"));
    EXPECT_TRUE(fs::exists(live));
}

TEST(OutputSet, AMoveInterruptedByAKillIsUndoneByTheNextBake) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", threeCubes());
    ASSERT_EQ(bake(dir / "in.glb", dir / "out", dir, {"--levels", "2"}).exitCode, 0);
    ASSERT_EQ(bake(dir / "in.glb", dir / "new", dir, {"--levels", "3"}).exitCode, 0);
    const std::vector<std::string> oldSet = readSet(dir / "out");
    // The state a bake leaves when killed right after moving levels.glb into place: the old
    // levels.glb as its backup, the rest still in the temporary folder, the journal.
    const fs::path temp = dir / "out" / ".aggrelod-tmp-999999999-killed";
    fs::create_directories(temp);
    fs::create_hard_link(dir / "out" / "levels.glb", temp / "old-0-levels.glb");
    fs::remove(dir / "out" / "levels.glb");  // a new file in its place, as rename does (the link keeps the old)
    fs::copy_file(dir / "new" / "levels.glb", dir / "out" / "levels.glb");
    fs::copy_file(dir / "new" / "proxies.glb", temp / "proxies.glb");
    fs::copy_file(dir / "new" / "scene.aglod", temp / "scene.aglod");
    writeFile(temp / "journal", "1\told-0-levels.glb\t" + fs::absolute(dir / "out" / "levels.glb").string() + "\n");
    ASSERT_FALSE(readSet(dir / "out") == oldSet);  // mixed
    // The next bake, even one that fails on its input, first puts the old set back.
    const RunResult r = bake(dir / "missing.glb", dir / "out", dir);
    EXPECT_EQ(r.exitCode, 2) << r.describe();
    EXPECT_TRUE(readSet(dir / "out") == oldSet) << "the old set is not back";
    EXPECT_FALSE(fs::exists(temp));

    // A journal that reached "committed": the new set stays.
    const std::vector<std::string> newSet = readSet(dir / "new");
    for (const auto& name : kSet) fs::copy_file(dir / "new" / name, dir / "out" / name, fs::copy_options::overwrite_existing);
    fs::create_directories(temp);
    writeFile(temp / "old-0-levels.glb", oldSet[0]);
    writeFile(temp / "journal", "1\told-0-levels.glb\t" + fs::absolute(dir / "out" / "levels.glb").string() + "\ncommitted\n");
    EXPECT_EQ(bake(dir / "missing.glb", dir / "out", dir).exitCode, 2);
    EXPECT_TRUE(readSet(dir / "out") == newSet) << "a committed set was undone";
    EXPECT_FALSE(fs::exists(temp));
}

TEST(OutputSet, ABakeKilledAtAnyMomentLeavesTheOldOrTheNewSet) {
    const fs::path dir = freshTestDir(currentTestName());
    // Enough objects for the bake to take a while (kill times spread over all its stages).
    std::vector<RawMesh> cubes;
    for (int i = 0; i < 30; ++i) cubes.push_back(cube("c" + std::to_string(i), 1.7 * i + 0.1 * (i % 3)));
    writeFile(dir / "in.glb", makeGlb(cubes));
    // The two sets: --levels 2 (old) and --levels 3 (new), each baked once to compare with.
    ASSERT_EQ(bake(dir / "in.glb", dir / "old", dir, {"--levels", "2"}).exitCode, 0);
    const auto start = std::chrono::steady_clock::now();
    ASSERT_EQ(bake(dir / "in.glb", dir / "new", dir, {"--levels", "3"}).exitCode, 0);
    const double duration = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::vector<std::string> oldSet = readSet(dir / "old"), newSet = readSet(dir / "new");
    ASSERT_FALSE(oldSet[0] == newSet[0]);

    ASSERT_EQ(::prctl(PR_SET_CHILD_SUBREAPER, 1), 0);  // orphans of the bake become ours
    std::mt19937 random(18);
    std::uniform_real_distribution<double> at(0.0, 1.3 * duration);
    int oldSeen = 0, newSeen = 0;
    for (int run = 0; run < 10; ++run) {
        fs::remove_all(dir / "out");
        fs::create_directories(dir / "out");
        for (const auto& name : kSet) fs::copy_file(dir / "old" / name, dir / "out" / name);
        const std::string in = (dir / "in.glb").string(), out = (dir / "out").string();
        std::vector<std::string> argv = {AGGRELOD_CLI, "bake", in, "-o", out, "-q", "--levels", "3"};
        std::vector<char*> args;
        for (auto& a : argv) args.push_back(a.data());
        args.push_back(nullptr);
        pid_t pid = 0;
        ASSERT_EQ(posix_spawn(&pid, args[0], nullptr, nullptr, args.data(), environ), 0);
        const double killAt = at(random);
        std::this_thread::sleep_for(std::chrono::duration<double>(killAt));
        ::kill(pid, SIGKILL);
        int status = 0;
        ::waitpid(pid, &status, 0);
        // One second later no process of the bake is left (a TetGen child dies with it).
        std::this_thread::sleep_for(std::chrono::seconds(1));
        int leftovers = 0;  // still running (dead ones, reaped here, are fine)
        for (pid_t p;;) {
            p = ::waitpid(-1, &status, WNOHANG);
            if (p > 0) continue;
            if (p == 0) ++leftovers;
            break;
        }
        EXPECT_EQ(leftovers, 0) << "run " << run << ": a process of the bake outlived it (killed at " << killAt << " s)";
        const std::vector<std::string> now = readSet(dir / "out");
        if (now == oldSet) ++oldSeen;
        else if (now == newSet) ++newSeen;
        else ADD_FAILURE() << "run " << run << ", killed at " << killAt << " s: a mixed or damaged output set";
    }
    ::prctl(PR_SET_CHILD_SUBREAPER, 0);
    std::printf("bake %.2f s; killed 10 times: old set %d, new set %d\n", duration, oldSeen, newSeen);
}

TEST(OutputSet, ManifestNamesEveryFileOfTheSet) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", threeCubes());
    const RunResult r = bake(dir / "in.glb", dir / "out", dir,
                             {"--levels", "2", "--tiles", "--collision", "--stats", (dir / "out" / "stats.json").string()});
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    const SeenSet seen = readThroughManifest(dir / "out");
    ASSERT_EQ(seen.check.status, io::SetCheck::Status::Complete) << seen.check.problem;
    EXPECT_FALSE(seen.check.moved);
    for (const char* name : {"levels.glb", "proxies.glb", "scene.aglod", "collision.glb", "stats.json", "tiles/tileset.json"})
        EXPECT_EQ(seen.files.count(name), 1u) << name;
    size_t tiles = 0;
    for (const auto& [name, bytes] : seen.files) {
        if (name.rfind("tiles/", 0) == 0) ++tiles;
        if (name != "stats.json") {
            EXPECT_EQ(bytes, readFile(dir / "out" / name)) << name;
        }
    }
    size_t tilesOnDisk = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir / "out" / "tiles")) tilesOnDisk += e.is_regular_file();
    EXPECT_EQ(tiles, tilesOnDisk);

    // inspect tells a complete set from a damaged one.
    const RunResult ok = runProgram({AGGRELOD_CLI, "inspect", (dir / "out" / "scene.aglod").string()}, dir);
    EXPECT_EQ(ok.exitCode, 0) << ok.describe();
    EXPECT_NE(ok.out.find("set: complete"), std::string::npos) << ok.describe();
    std::string levels = readFile(dir / "out" / "levels.glb");
    levels[levels.size() / 2] ^= 1;
    writeFile(dir / "out" / "levels.glb", levels);
    EXPECT_EQ(io::checkOutputSet(dir / "out").status, io::SetCheck::Status::Incomplete);
    const RunResult damaged = runProgram({AGGRELOD_CLI, "inspect", (dir / "out" / "scene.aglod").string()}, dir);
    EXPECT_EQ(damaged.exitCode, 0) << damaged.describe();
    EXPECT_NE(damaged.err.find("not one complete set: levels.glb: its SHA-256 differs"), std::string::npos)
        << damaged.describe();

    // The manifest reader refuses paths out of the folder and malformed text.
    io::SetManifest m;
    std::string error;
    const std::string hash(64, 'a');
    EXPECT_FALSE(io::parseSetManifest(R"({"format": "aggrelod-set", "version": 1, "files": [{"name": "../x", "size": 1, "sha256": ")" + hash + "\"}]}", m, error));
    EXPECT_FALSE(io::parseSetManifest(R"({"format": "aggrelod-set", "version": 1, "files": [{"name": "x", "size": 1, "sha256": ")" + hash + R"(", "at": "/etc/passwd"}]})", m, error));
    EXPECT_FALSE(io::parseSetManifest(R"({"format": "aggrelod-set", "files": [)", m, error));
    ASSERT_TRUE(io::parseSetManifest(R"({"format": "aggrelod-set", "version": 1, "extra": [1, {"a": null}], "files": [{"name": "a b", "size": 3, "sha256": ")" + hash + "\"}]}", m, error)) << error;
    ASSERT_EQ(m.files.size(), 1u);
    EXPECT_EQ(m.files[0].name, "a b");
    EXPECT_EQ(io::sha256Hex("abc", 3), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    EXPECT_EQ(io::sha256Hex("", 0), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
    const std::string million(1000000, 'a');
    EXPECT_EQ(io::sha256Hex(million.data(), million.size()), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// The hardware path (x86 SHA extensions, where the processor has them) and the portable one give
// the same digests, for every length around the block and padding boundaries and whatever
// pieces the stream comes in.
TEST(OutputSet, Sha256HardwareAndPortablePathsAgree) {
    std::printf("SHA extensions on this processor: %s\n", io::Sha256::hardwareAvailable() ? "yes" : "no");
    std::vector<unsigned char> data(4096 + 200);
    uint32_t x = 12345;
    for (unsigned char& b : data) b = static_cast<unsigned char>((x = x * 1664525u + 1013904223u) >> 24);
    auto digest = [&](io::Sha256::Path path, size_t length, size_t piece) {
        io::Sha256 h(path);
        for (size_t at = 0; at < length; at += piece) h.update(data.data() + at, std::min(piece, length - at));
        return h.hex();
    };
    for (size_t length = 0; length <= data.size(); length += length < 300 ? 1 : 97) {
        const std::string portable = digest(io::Sha256::Path::Portable, length, data.size());
        EXPECT_EQ(digest(io::Sha256::Path::Fastest, length, data.size()), portable) << length;
        EXPECT_EQ(digest(io::Sha256::Path::Fastest, length, 1), portable) << length;
        EXPECT_EQ(digest(io::Sha256::Path::Fastest, length, 63), portable) << length;
        EXPECT_EQ(digest(io::Sha256::Path::Portable, length, 65), portable) << length;
    }
    // A known digest through both paths (FIPS 180-4 example, two blocks).
    const char* two = "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq";
    for (auto path : {io::Sha256::Path::Fastest, io::Sha256::Path::Portable}) {
        io::Sha256 h(path);
        h.update(two, std::strlen(two));
        EXPECT_EQ(h.hex(), "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
    }
}

// Fault injection: AGGRELOD_TEST_KILL_AFTER_COMMIT_STEP=K makes the bake kill itself (SIGKILL)
// right after the K-th step of its commit (the journal, each backup, each rename, each switch
// of the manifest; bake/output_set.cpp); without it the variable does nothing. For every K up
// to the first that the bake outlives, a reader of the manifest must find, without another
// bake, the complete old set or the complete new set; then the next bake into OUTDIR (one that
// fails on its input) must leave that set at its names with no temporary folder.
TEST(OutputSet, AKillAfterEveryStepOfTheCommitLeavesTheOldOrTheNewSet) {
    const fs::path dir = freshTestDir(currentTestName());
    writeFile(dir / "in.glb", threeCubes());
    const std::string statsInside = "--stats=" + (dir / "out" / "stats.json").string();
    struct Scenario {
        std::string name;
        std::vector<std::string> oldOptions;  // empty: no old set (a fresh OUTDIR)
        std::vector<std::string> newOptions;
    };
    const std::vector<Scenario> scenarios = {
        {"tiles, collision and stats", {"--levels", "2", "--tiles", "--collision", statsInside},
         {"--levels", "3", "--tiles", "--collision", statsInside}},
        {"fresh OUTDIR", {}, {"--levels", "3", "--tiles"}},
        {"tiles added, stats elsewhere", {"--levels", "2"}, {"--levels", "3", "--tiles", "--stats", (dir / "stats.json").string()}},
    };
    for (const Scenario& sc : scenarios) {
        SCOPED_TRACE(sc.name);
        // The reference sets, each baked once into a folder of its own and read back through
        // their manifests (a set copied elsewhere stays complete: its names are relative).
        const auto reference = [&](const std::vector<std::string>& options, const fs::path& folder) {
            fs::remove_all(dir / "out");
            if (options.empty()) return std::map<std::string, std::string>();
            const RunResult r = bake(dir / "in.glb", dir / "out", dir, options);
            EXPECT_EQ(r.exitCode, 0) << r.describe();
            fs::remove_all(folder);
            fs::rename(dir / "out", folder);
            const SeenSet seen = readThroughManifest(folder);
            EXPECT_EQ(seen.check.status, io::SetCheck::Status::Complete) << seen.check.problem;
            return seen.files;
        };
        const std::map<std::string, std::string> oldSet = reference(sc.oldOptions, dir / "old");
        const std::map<std::string, std::string> newSet = reference(sc.newOptions, dir / "new");
        ASSERT_FALSE(oldSet == newSet);
        const bool noOld = sc.oldOptions.empty();

        int oldSeen = 0, newSeen = 0, steps = 0;
        for (int k = 1;; ++k) {
            ASSERT_LT(k, 200) << "the commit never ends";
            fs::remove_all(dir / "out");
            if (noOld) fs::create_directories(dir / "out");
            else fs::copy(dir / "old", dir / "out", fs::copy_options::recursive);
            ::setenv("AGGRELOD_TEST_KILL_AFTER_COMMIT_STEP", std::to_string(k).c_str(), 1);
            const RunResult r = bake(dir / "in.glb", dir / "out", dir, sc.newOptions);
            ::unsetenv("AGGRELOD_TEST_KILL_AFTER_COMMIT_STEP");
            if (r.exited && r.exitCode == 0) break;  // K is past the last step
            ASSERT_TRUE(r.signaled && r.signal == SIGKILL) << "step " << k << ": " << r.describe();
            ++steps;

            // The reader, before anything else touches OUTDIR.
            const SeenSet seen = readThroughManifest(dir / "out");
            if (noOld && seen.check.status == io::SetCheck::Status::NoManifest) {
                ++oldSeen;  // no set yet: the old (empty) one
            } else {
                ASSERT_EQ(seen.check.status, io::SetCheck::Status::Complete)
                    << "killed after step " << k << ": " << seen.check.problem;
                if (seen.files == oldSet) ++oldSeen;
                else if (seen.files == newSet) ++newSeen;
                else ADD_FAILURE() << "killed after step " << k << ": the manifest names a set neither old nor new";
            }

            // The next bake (failing on its input) puts that set back at its names.
            const bool sawNew = seen.check.status == io::SetCheck::Status::Complete && seen.files == newSet;
            const RunResult next = bake(dir / "missing.glb", dir / "out", dir);
            EXPECT_EQ(next.exitCode, 2) << next.describe();
            const SeenSet after = readThroughManifest(dir / "out");
            EXPECT_TRUE(leftTemporaries(dir / "out").empty()) << "step " << k << ": " << leftTemporaries(dir / "out")[0];
            if (!sawNew && noOld) {
                EXPECT_EQ(after.check.status, io::SetCheck::Status::NoManifest) << "step " << k;
                for (const char* name : {"levels.glb", "proxies.glb", "scene.aglod", "tiles"})
                    EXPECT_FALSE(fs::exists(dir / "out" / name)) << "step " << k << ": " << name << " left over";
                continue;
            }
            ASSERT_EQ(after.check.status, io::SetCheck::Status::Complete) << "step " << k << ": " << after.check.problem;
            EXPECT_FALSE(after.check.moved) << "step " << k;
            EXPECT_TRUE(after.files == (sawNew ? newSet : oldSet)) << "step " << k << ": the next bake changed the set";
            for (const auto& [name, path] : after.check.files) EXPECT_EQ(path, dir / "out" / name) << "step " << k;
        }
        std::printf("%s: killed after each of %d commit steps: old set %d, new set %d\n", sc.name.c_str(), steps,
                    oldSeen, newSeen);
        EXPECT_GE(steps, 5);
        EXPECT_GE(oldSeen, 1);
        EXPECT_GE(newSeen, 1);
    }
}
