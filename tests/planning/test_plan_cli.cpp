// SPDX-License-Identifier: AGPL-3.0-or-later
// `aggrelod plan` end to end: 2D polygons (aggregated in the command) and a 3D runtime file;
// exit 0 with the stats JSON when solved, 3 when no path exists, a clear message and a
// non-zero exit for bad input (start in an obstacle or outside, radius <= 0, wrong file kind).
#include <aggrelod/runtime_file.h>

#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace {

struct CliRun {
    int code;
    std::string output;
};

CliRun run(const std::string& args) {
    const std::string cmd = std::string(AGGRELOD_CLI) + " " + args + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    std::string out;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    const int status = pclose(p);
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

std::string tmp(const std::string& name) { return std::string(AGGRELOD_TEST_TMP) + "/plan_cli_" + name; }

std::string readFile(const std::string& path) {
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::string wallsFile() {
    const std::string path = tmp("walls.wkt");
    std::ofstream(path) << "POLYGON((4 0, 5 0, 5 4.5, 4 4.5, 4 0))\n"
                           "POLYGON((4 5.5, 5 5.5, 5 10, 4 10, 4 5.5))\n"
                           "POLYGON((0 9.6, 0.4 9.6, 0.4 10, 0 10, 0 9.6))\n"
                           "POLYGON((9.6 0, 10 0, 10 0.4, 9.6 0.4, 9.6 0))\n"
                           "POLYGON((12 3, 16 3, 16 7, 12 7, 12 3),(13 4, 13 6, 15 6, 15 4, 13 4))\n";
    return path;
}

}  // namespace

TEST(PlanCli, TwoDSolvedWithStatsAndPicture) {
    const std::string walls = wallsFile();
    const CliRun r = run("plan " + walls + " --from 1,2 --to 9,8 --radius 0.2 --delta 0.5,2,4 --level-samples 200 --stats " +
                      tmp("walls.json") + " --png " + tmp("walls.png"));
    EXPECT_EQ(r.code, 0) << r.output;
    const std::string json = readFile(tmp("walls.json"));
    EXPECT_NE(json.find("\"solved\": true"), std::string::npos) << json;
    EXPECT_NE(json.find("\"path\": [[1, 2], "), std::string::npos) << json;
    EXPECT_NE(json.find("\"levels_used\": [2, 1, 0]"), std::string::npos) << json;
    EXPECT_NE(json.find("\"collision_checks\": "), std::string::npos);
    EXPECT_NE(json.find("\"roadmap_vertices\": "), std::string::npos);
    EXPECT_GT(readFile(tmp("walls.png")).size(), 1000u);
    // The same command twice gives the same stats apart from the time.
    const CliRun again = run("plan " + walls + " --from 1,2 --to 9,8 --radius 0.2 --delta 0.5,2,4 --level-samples 200 --stats " +
                          tmp("walls2.json") + " --svg " + tmp("walls.svg") + " --quiet");
    EXPECT_EQ(again.code, 0) << again.output;
    EXPECT_TRUE(again.output.empty()) << again.output;
    auto withoutSeconds = [](std::string s) { return s.erase(s.find("\"seconds\""), s.find('\n', s.find("\"seconds\"")) - s.find("\"seconds\"")); };
    EXPECT_EQ(withoutSeconds(json), withoutSeconds(readFile(tmp("walls2.json"))));
    EXPECT_NE(readFile(tmp("walls.svg")).find("<svg"), std::string::npos);
}

TEST(PlanCli, TwoDNoPathExitsThree) {
    const CliRun r = run("plan " + wallsFile() + " --from 1,2 --to 14,5 --radius 0.2 --delta 0.5,2 --time-limit 0.3");
    EXPECT_EQ(r.code, 3) << r.output;
    EXPECT_NE(r.output.find("no path found"), std::string::npos) << r.output;
}

TEST(PlanCli, BadInputIsRefusedWithAMessage) {
    const std::string walls = wallsFile();
    CliRun r = run("plan " + walls + " --from 4.5,2 --to 9,8 --radius 0.2");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("start 4.5"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("inside an obstacle"), std::string::npos) << r.output;
    r = run("plan " + walls + " --from 1,2 --to 90,8 --radius 0.2");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("outside the scene"), std::string::npos) << r.output;
    r = run("plan " + walls + " --from 1,2 --to 9,8 --radius 0");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("--radius must be > 0"), std::string::npos) << r.output;
    r = run("plan " + walls + " --from 1,2 --to 9,8 --radius -1");
    EXPECT_NE(r.code, 0);
    r = run("plan " + std::string(AGGRELOD_SOURCE_DIR) + "/CMakeLists.txt --from 1,2 --to 9,8 --radius 0.2");
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.output.find("not a baked runtime file"), std::string::npos) << r.output;
    r = run("plan " + walls + " --from 1,2,3 --to 9,8 --radius 0.2");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("needs x,y"), std::string::npos) << r.output;
    r = run("plan " + walls + " --from 1,2 --to 9,8 --radius 0.2 --strategy sideways");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("--strategy"), std::string::npos) << r.output;
}

TEST(PlanCli, ThreeDRuntimeFile) {
    std::vector<uint8_t> bytes;
    std::string error;
    ASSERT_TRUE(aggrelod::runtime::writeRuntimeFile(aggrelod::testing::makeSyntheticHierarchy(36, 3, 3), bytes, error));
    const std::string path = tmp("city.aglod");
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    aggrelod::runtime::RuntimeFile file;
    ASSERT_EQ(aggrelod::runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error),
              aggrelod::runtime::FileStatus::Ok);
    const aggrelod::runtime::NodeRecord& root = file.node(file.roots()[0]);
    // Above the boxes' tops the city is open: from one corner to the other.
    char from[128], to[128];
    const float top = root.boundsMax[1] - 0.5f;
    std::snprintf(from, sizeof from, "%g,%g,%g", root.boundsMin[0] + 0.1, double(top), root.boundsMin[2] + 0.1);
    std::snprintf(to, sizeof to, "%g,%g,%g", root.boundsMax[0] - 0.1, double(top), root.boundsMax[2] - 0.1);
    CliRun r = run("plan " + path + " --from " + from + " --to " + to + " --radius 0.05 --strategy originals --stats " +
                tmp("city.json") + " --png " + tmp("city.png"));
    // A corner may be inside a box; then the refusal must say so.
    if (r.code == 1) {
        EXPECT_NE(r.output.find("obstacle"), std::string::npos) << r.output;
    } else {
        EXPECT_EQ(r.code, 0) << r.output;
        EXPECT_NE(readFile(tmp("city.json")).find("\"solved\": true"), std::string::npos);
    }
    r = run("plan " + path + " --from 1,2 --to 3,4 --radius 0.5");
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.output.find("x,y,z"), std::string::npos) << r.output;
}
