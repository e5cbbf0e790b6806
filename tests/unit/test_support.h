// SPDX-License-Identifier: AGPL-3.0-or-later
// Helpers shared by the integration tests: running the CLI, temporary directories, shared
// test data, hand-made GLB files and the glTF validator (mesh checks: mesh_checks.h).
// Header-only (tests/unit/*.cpp are globbed into one executable).
#pragma once

#include <aggrelod/aggregate3d.h>

#include "mesh_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace aggrelod::testing {

namespace fs = std::filesystem;

#ifdef AGGRELOD_SHARED_DATA
inline fs::path sharedDataDir() { return fs::path(AGGRELOD_SHARED_DATA); }
#else
inline fs::path sharedDataDir() { return fs::path("../shared/data"); }
#endif

/// Path of a file under ../shared/data (may not exist: check and GTEST_SKIP()).
inline fs::path sharedData(const std::string& relative) { return sharedDataDir() / relative; }

/// A fresh, empty directory for one test under the build tree.
inline fs::path freshTestDir(const std::string& name) {
#ifdef AGGRELOD_TEST_TMP
    fs::path dir = fs::path(AGGRELOD_TEST_TMP) / name;
#else
    fs::path dir = fs::temp_directory_path() / ("aggrelod_test_" + name);
#endif
    std::error_code ec;
    fs::remove_all(dir, ec);
    fs::create_directories(dir);
    return dir;
}

/// "Suite.Name" of the running test, usable as a directory name.
inline std::string currentTestName() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "." + info->name();
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_') c = '_';
    return name;
}

inline std::string readFile(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

inline void writeFile(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

inline bool containsAny(const std::string& haystack, const std::vector<std::string>& needles) {
    for (const auto& n : needles)
        if (haystack.find(n) != std::string::npos) return true;
    return false;
}

/// Result of running a program.
struct RunResult {
    bool started = false;
    bool exited = false;   ///< ended by exit(): exitCode is meaningful
    int exitCode = -1;
    bool signaled = false; ///< killed by a signal
    int signal = 0;
    std::string out, err;  ///< what it printed
    std::string command;   ///< for messages

    std::string describe() const {
        std::ostringstream s;
        s << "command: " << command << "\n";
        if (signaled) s << "killed by signal " << signal << "\n";
        else s << "exit status " << exitCode << "\n";
        s << "--- stdout ---\n" << out << "--- stderr ---\n" << err;
        return s.str();
    }
};

/// Runs argv[0] with arguments (no shell), stdout and stderr captured through files in
/// `workDir`; waits for it. The environment is this process's.
inline RunResult runProgram(const std::vector<std::string>& argv, const fs::path& workDir) {
    RunResult r;
    for (const auto& a : argv) r.command += (r.command.empty() ? "" : " ") + ("'" + a + "'");
    const fs::path outPath = workDir / "run.stdout", errPath = workDir / "run.stderr";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, outPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 2, errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = 0;
    const int rc = posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) {
        r.err = std::string("cannot start: ") + std::strerror(rc);
        return r;
    }
    r.started = true;
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    if (WIFEXITED(status)) {
        r.exited = true;
        r.exitCode = WEXITSTATUS(status);
    } else if (WIFSIGNALED(status)) {
        r.signaled = true;
        r.signal = WTERMSIG(status);
    }
    r.out = readFile(outPath);
    r.err = readFile(errPath);
    return r;
}

// --- mesh checks on read-back outputs ---------------------------------------------------

// --- hand-made GLB files (for malformed input) ----------------------------------------------

/// One mesh node of a hand-made GLB: float32 positions, uint32 indices, written as given
/// (NaN, out-of-range indices and open meshes included).
struct RawMesh {
    std::string name;
    std::vector<float> positions;    ///< xyz triples
    std::vector<uint32_t> indices;   ///< triangle corners
};

inline RawMesh rawMeshOf(const InputObject& o) {
    RawMesh m;
    m.name = o.name;
    for (double x : o.positions) m.positions.push_back(float(x));
    m.indices = o.indices;
    return m;
}

/// A GLB (glTF 2.0 binary) with one node per mesh under one scene. Accessor min/max are
/// computed over the finite coordinates only (JSON has no NaN).
inline std::string makeGlb(const std::vector<RawMesh>& meshes) {
    std::string bin;
    std::ostringstream nodes, meshJson, accessors, views;
    auto num = [](double v) {
        std::ostringstream s;
        s.precision(9);
        s << v;
        return s.str();
    };
    for (size_t m = 0; m < meshes.size(); ++m) {
        const RawMesh& mesh = meshes[m];
        const size_t posOffset = bin.size();
        bin.append(reinterpret_cast<const char*>(mesh.positions.data()), mesh.positions.size() * sizeof(float));
        const size_t idxOffset = bin.size();
        bin.append(reinterpret_cast<const char*>(mesh.indices.data()), mesh.indices.size() * sizeof(uint32_t));
        double lo[3] = {1e30, 1e30, 1e30}, hi[3] = {-1e30, -1e30, -1e30};
        for (size_t i = 0; i < mesh.positions.size(); ++i)
            if (std::isfinite(mesh.positions[i])) {
                lo[i % 3] = std::min(lo[i % 3], double(mesh.positions[i]));
                hi[i % 3] = std::max(hi[i % 3], double(mesh.positions[i]));
            }
        const std::string sep = m ? "," : "";
        nodes << sep << "{\"name\":\"" << mesh.name << "\",\"mesh\":" << m << "}";
        meshJson << sep << "{\"name\":\"" << mesh.name << "\",\"primitives\":[{\"attributes\":{\"POSITION\":"
                 << 2 * m << "},\"indices\":" << 2 * m + 1 << ",\"mode\":4}]}";
        accessors << sep << "{\"bufferView\":" << 2 * m << ",\"componentType\":5126,\"count\":"
                  << mesh.positions.size() / 3 << ",\"type\":\"VEC3\",\"min\":[" << num(lo[0]) << ","
                  << num(lo[1]) << "," << num(lo[2]) << "],\"max\":[" << num(hi[0]) << "," << num(hi[1])
                  << "," << num(hi[2]) << "]},{\"bufferView\":" << 2 * m + 1
                  << ",\"componentType\":5125,\"count\":" << mesh.indices.size() << ",\"type\":\"SCALAR\"}";
        views << sep << "{\"buffer\":0,\"byteOffset\":" << posOffset << ",\"byteLength\":"
              << mesh.positions.size() * sizeof(float) << ",\"target\":34962},{\"buffer\":0,\"byteOffset\":"
              << idxOffset << ",\"byteLength\":" << mesh.indices.size() * sizeof(uint32_t)
              << ",\"target\":34963}";
    }
    std::ostringstream json;
    json << "{\"asset\":{\"version\":\"2.0\",\"generator\":\"aggrelod tests\"},\"scene\":0,\"scenes\":[{\"nodes\":[";
    for (size_t m = 0; m < meshes.size(); ++m) json << (m ? "," : "") << m;
    json << "]}]";
    if (!meshes.empty()) {
        json << ",\"nodes\":[" << nodes.str() << "],\"meshes\":[" << meshJson.str() << "],\"accessors\":["
             << accessors.str() << "],\"bufferViews\":[" << views.str() << "],\"buffers\":[{\"byteLength\":"
             << bin.size() << "}]";
    }
    json << "}";
    std::string jsonChunk = json.str();
    while (jsonChunk.size() % 4) jsonChunk += ' ';
    while (bin.size() % 4) bin += '\0';
    auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
    std::string glb = "glTF" + u32(2);
    const bool hasBin = !bin.empty();
    const uint32_t total = uint32_t(12 + 8 + jsonChunk.size() + (hasBin ? 8 + bin.size() : 0));
    glb += u32(total);
    glb += u32(uint32_t(jsonChunk.size())) + u32(0x4E4F534A) + jsonChunk;  // "JSON"
    if (hasBin) glb += u32(uint32_t(bin.size())) + u32(0x004E4942) + bin;  // "BIN\0"
    return glb;
}

// --- the Khronos glTF validator -------------------------------------------------------------

/// Empty when node and tests/validator/node_modules/gltf-validator are there; else why not.
inline std::string validatorMissing() {
#if defined(AGGRELOD_NODE) && defined(AGGRELOD_VALIDATOR_JS)
    const fs::path script = AGGRELOD_VALIDATOR_JS;
    if (std::string(AGGRELOD_NODE).empty())
        return "node not found when configuring: cannot run the glTF validator "
               "(run .ci/install-deps.sh, then re-run cmake)";
    if (!fs::exists(script.parent_path() / "node_modules" / "gltf-validator"))
        return "gltf-validator is not installed in " + (script.parent_path() / "node_modules").string() +
               " (run .ci/install-deps.sh)";
    return {};
#else
    return "built without AGGRELOD_NODE / AGGRELOD_VALIDATOR_JS";
#endif
}

/// Runs tests/validator/validate.js on `files` (exit status 0: no errors, 1: errors).
inline RunResult runValidator(const std::vector<fs::path>& files, const fs::path& workDir) {
#if defined(AGGRELOD_NODE) && defined(AGGRELOD_VALIDATOR_JS)
    std::vector<std::string> argv = {AGGRELOD_NODE, AGGRELOD_VALIDATOR_JS};
    for (const auto& f : files) argv.push_back(f.string());
    return runProgram(argv, workDir);
#else
    (void)files;
    (void)workDir;
    return RunResult{};
#endif
}

/// The one test that fails when node or the validator are missing; the others skip their
/// validation and point there, so a missing tool is one failure, not one per test.
constexpr const char* kValidatorCheck = "CliSamples.ValidatorHarnessCatchesErrors";

/// Skips the calling test when the validator is missing (see kValidatorCheck).
#define AGGRELOD_REQUIRE_VALIDATOR()                                                              \
    do {                                                                                          \
        const std::string missing_ = ::aggrelod::testing::validatorMissing();                     \
        if (!missing_.empty())                                                                    \
            GTEST_SKIP() << "glTF validator missing (reported by "                                \
                         << ::aggrelod::testing::kValidatorCheck << "): " << missing_;           \
    } while (0)

/// Validates `files`; adds a test failure when the validator reports errors. When node or the
/// validator are missing the test is marked skipped (kValidatorCheck fails for it; CI installs
/// them with .ci/install-deps.sh). Returns true when it ran and reported no errors.
inline bool validateGltf(const std::vector<fs::path>& files, const fs::path& workDir) {
    const std::string missing = validatorMissing();
    if (!missing.empty()) {
        const std::string message =
            "glTF validator missing (reported by " + std::string(kValidatorCheck) + "): " + missing;
        GTEST_MESSAGE_AT_(__FILE__, __LINE__, message.c_str(), ::testing::TestPartResult::kSkip);
        return false;
    }
    const RunResult r = runValidator(files, workDir);
    if (!r.exited || r.exitCode != 0) {
        ADD_FAILURE() << "glTF validator reports errors\n" << r.describe();
        return false;
    }
    return true;
}

}  // namespace aggrelod::testing
