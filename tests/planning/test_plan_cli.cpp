// SPDX-License-Identifier: AGPL-3.0-or-later
// `aggrelod plan` end to end: 2D polygons (aggregated in the command), the output of
// `aggrelod aggregate2d` (levels GeoJSON, link table, the polygons it read) and a 3D runtime
// file; exit 0 with the stats JSON when solved, 3 when no path exists, a clear message and a
// non-zero exit for bad input (start in an obstacle or outside, radius <= 0, wrong file kind,
// a link table of another run, an aggregate that does not contain its originals).
#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>
#include <aggrelod/planning.h>
#include <aggrelod/runtime_file.h>

#include "planning_referee.h"
#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
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

// ---- aggregate2d output ---------------------------------------------------------------

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

void appendRing(std::string& s, const std::vector<double>& ring) {
    s += "(";
    for (size_t i = 0; i <= ring.size() / 2; ++i) {
        const size_t k = i % (ring.size() / 2);
        s += (i ? ", " : "") + num(ring[2 * k]) + " " + num(ring[2 * k + 1]);
    }
    s += ")";
}

/// One POLYGON / MULTIPOLYGON line per feature.
std::string writeWkt(const std::vector<aggrelod::Feature2D>& features, const std::string& path) {
    std::string s;
    for (const aggrelod::Feature2D& f : features) {
        s += f.polygons.size() == 1 ? "POLYGON(" : "MULTIPOLYGON(";
        for (size_t p = 0; p < f.polygons.size(); ++p) {
            if (f.polygons.size() > 1) s += p ? ", (" : "(";
            appendRing(s, f.polygons[p].exterior);
            for (const auto& h : f.polygons[p].holes) {
                s += ", ";
                appendRing(s, h);
            }
            if (f.polygons.size() > 1) s += ")";
        }
        s += ")\n";
    }
    std::ofstream(path) << s;
    return path;
}

struct Stats {
    bool solved = false;
    std::string levelsUsed;
    std::vector<aggrelod::planning::Point> path;
};

/// The fields of the --stats JSON these tests compare.
Stats readStats(const std::string& file) {
    const std::string json = readFile(file);
    Stats st;
    st.solved = json.find("\"solved\": true") != std::string::npos;
    const size_t lu = json.find("\"levels_used\": [");
    if (lu != std::string::npos) st.levelsUsed = json.substr(lu + 16, json.find(']', lu) - lu - 16);
    size_t at = json.find("\"path\": [");
    if (at == std::string::npos) return st;
    const char* c = json.c_str() + at + 9;
    for (;;) {
        while (*c == ' ' || *c == ',') ++c;
        if (*c != '[') break;
        char* end = nullptr;
        const double x = std::strtod(c + 1, &end);
        c = end;
        while (*c == ' ' || *c == ',') ++c;
        const double y = std::strtod(c, &end);
        c = end;
        st.path.push_back({x, y, 0});
        while (*c && *c != ']') ++c;
        if (*c) ++c;
    }
    return st;
}

std::vector<aggrelod::planning::PlanPolygon> planPolygons(const std::vector<aggrelod::Feature2D>& features) {
    std::vector<aggrelod::planning::PlanPolygon> out;
    for (const aggrelod::Feature2D& f : features)
        for (const aggrelod::Polygon2D& p : f.polygons) {
            out.emplace_back();
            out.back().rings.push_back(p.exterior);
            for (const auto& h : p.holes) out.back().rings.push_back(h);
        }
    return out;
}

std::string pointArg(const aggrelod::planning::Point& p) { return num(p[0]) + "," + num(p[1]); }

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

// aggregate2d's output planned on as it is: solved, every path free for the originals (the
// referee of test_planning.cpp), and the same levels, roadmap and path as planning on the raw
// polygons aggregated in the command with the same thresholds (the same aggregation, read
// back exactly: aggregate2d writes shortest round-trip numbers).
TEST(PlanCli, TwoDAggregate2DOutputPlansLikeTheRawPolygons) {
    using namespace aggrelod;
    const std::vector<Feature2D> room = samples::makeEnvironment2D(samples::Environment2D::Room, 1);
    const std::string wkt = writeWkt(room, tmp("room.wkt"));
    const std::string levels = tmp("room_levels.geojson"), links = tmp("room_links.csv");
    const std::string deltas = "1.5,6,14";
    CliRun r = run("aggregate2d " + wkt + " -o " + levels + " --links " + links + " --delta " + deltas + " -q");
    ASSERT_EQ(r.code, 0) << r.output;

    const std::vector<planning::PlanPolygon> originals = planPolygons(room);
    auto box = planning::makeWorld2D(originals, {}, {}, 1.0);
    const double radius = 0.002 * std::max(box->boundsMax()[0] - box->boundsMin()[0], box->boundsMax()[1] - box->boundsMin()[1]);
    auto world0 = planning::makeWorld2D(originals, {}, {}, radius);
    std::mt19937 rng(11);
    auto freePoint = [&] {
        for (;;) {
            const planning::Point lo = world0->boundsMin(), hi = world0->boundsMax();
            const planning::Point p{lo[0] + (hi[0] - lo[0]) * (double(rng()) / 4294967296.0),
                                    lo[1] + (hi[1] - lo[1]) * (double(rng()) / 4294967296.0), 0};
            if (world0->stateFree(0, p)) return p;
        }
    };
    int solved = 0, descended = 0, violations = 0;
    for (int q = 0; q < 4; ++q) {
        const planning::Point a = freePoint(), b = freePoint();
        const std::string query = " --from " + pointArg(a) + " --to " + pointArg(b) + " --radius " + num(radius) +
                                  " --time-limit 10 --seed " + std::to_string(q + 1);
        const std::string geoStats = tmp("room_geo_" + std::to_string(q) + ".json");
        const std::string rawStats = tmp("room_raw_" + std::to_string(q) + ".json");
        const CliRun geo = run("plan " + levels + " --originals " + wkt + " --links " + links + query + " --stats " + geoStats);
        const CliRun raw = run("plan " + wkt + " --delta " + deltas + query + " --stats " + rawStats);
        EXPECT_EQ(geo.code, 0) << geo.output;
        EXPECT_EQ(raw.code, 0) << raw.output;
        EXPECT_NE(geo.output.find("aggregate2d output, 3 levels over 85 input features"), std::string::npos) << geo.output;
        EXPECT_NE(geo.output.find("all match"), std::string::npos) << geo.output;
        const Stats g = readStats(geoStats), w = readStats(rawStats);
        ASSERT_TRUE(g.solved) << geo.output;
        ++solved;
        EXPECT_EQ(g.levelsUsed, w.levelsUsed) << "query " << q;
        EXPECT_EQ(g.path, w.path) << "query " << q;
        ASSERT_GE(g.path.size(), 2u);
        EXPECT_EQ(g.path.front(), a);
        EXPECT_EQ(g.path.back(), b);
        violations += aggrelod::testing::violations2D(originals, g.path, radius);
        if (g.levelsUsed.find(',') != std::string::npos) ++descended;
        std::printf("query %d: levels_used [%s], %zu path points\n", q, g.levelsUsed.c_str(), g.path.size());
    }
    EXPECT_EQ(solved, 4);
    EXPECT_EQ(violations, 0);
    EXPECT_GE(descended, 1) << "no query needed a finer level";
}

// Input that is not aggregate2d's output, or does not belong together, is refused (exit 2)
// with a message naming the file, the line and what does not match.
TEST(PlanCli, TwoDAggregate2DMismatchesAreRefused) {
    using namespace aggrelod;
    const std::vector<Feature2D> room = samples::makeEnvironment2D(samples::Environment2D::Room, 1);
    const std::string wkt = writeWkt(room, tmp("mm_room.wkt"));
    const std::string levels = tmp("mm_levels.geojson"), links = tmp("mm_links.csv");
    const std::string otherLevels = tmp("mm_other.geojson"), otherLinks = tmp("mm_other_links.csv");
    ASSERT_EQ(run("aggregate2d " + wkt + " -o " + levels + " --links " + links + " --delta 1.5,6,12 -q").code, 0);
    ASSERT_EQ(run("aggregate2d " + wkt + " -o " + otherLevels + " --links " + otherLinks + " --delta 1.5,9 -q").code, 0);
    const std::string query = " --from 1,1 --to 2,2 --radius 0.2";
    // The link table of another run (other thresholds).
    CliRun r = run("plan " + levels + " --originals " + wkt + " --links " + otherLinks + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("the link table does not belong to " + levels), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(otherLinks + " line "), std::string::npos) << r.output;
    // A row pointing at another aggregate.
    {
        std::string table = readFile(links);
        const size_t row = table.find('\n', table.find("\n") + 1);  // end of the first data row
        const size_t comma = table.rfind(',', row);
        table.replace(comma + 1, row - comma - 1, "7");
        std::ofstream(tmp("mm_bad_links.csv")) << table;
    }
    r = run("plan " + levels + " --originals " + wkt + " --links " + tmp("mm_bad_links.csv") + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("mm_bad_links.csv line 2: input feature 0 in aggregate 7 of level 0"), std::string::npos) << r.output;
    // A link table missing rows.
    {
        std::string table = readFile(links);
        std::ofstream(tmp("mm_short_links.csv")) << table.substr(0, table.size() / 2).substr(0, table.substr(0, table.size() / 2).rfind('\n') + 1);
    }
    r = run("plan " + levels + " --originals " + wkt + " --links " + tmp("mm_short_links.csv") + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("no row for input feature"), std::string::npos) << r.output;
    // Not a link table.
    r = run("plan " + levels + " --originals " + wkt + " --links " + wkt + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("expected the header \"input_id,level,delta,output_id\""), std::string::npos) << r.output;
    // aggregate2d's GeoJSON without the originals.
    r = run("plan " + levels + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("--originals"), std::string::npos) << r.output;
    // Originals of another environment.
    const std::string scatter = writeWkt(samples::makeEnvironment2D(samples::Environment2D::Scatter, 1), tmp("mm_scatter.wkt"));
    r = run("plan " + levels + " --originals " + scatter + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("mm_levels.geojson: aggregate "), std::string::npos) << r.output;
    // A GeoJSON of plain polygons is not aggregate2d output ...
    {
        std::ofstream(tmp("mm_plain.geojson"))
            << "{\"type\": \"FeatureCollection\", \"features\": [{\"type\": \"Feature\", \"properties\": {\"name\": \"a\"}, "
               "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0],[1,1],[0,1],[0,0]]]}}]}\n";
    }
    r = run("plan " + tmp("mm_plain.geojson") + " --originals " + wkt + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("not the GeoJSON of `aggrelod aggregate2d`"), std::string::npos) << r.output;
    // Plain polygons with a property of one of its names stay plain polygons.
    {
        std::ofstream(tmp("mm_plain_level.geojson"))
            << "{\"type\": \"FeatureCollection\", \"features\": [\n{\"type\": \"Feature\", \"properties\": {\"level\": 2}, "
               "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0],[1,1],[0,1],[0,0]]]}},\n"
               "{\"type\": \"Feature\", \"properties\": {\"level\": 3}, "
               "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[3,0],[4,0],[4,1],[3,1],[3,0]]]}}]}\n";
    }
    r = run("plan " + tmp("mm_plain_level.geojson") + " --from 2,0.2 --to 2,0.8 --radius 0.1 --delta 0.5");
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("polygons aggregated here"), std::string::npos) << r.output;
    // ... nor one whose features lack some of its properties.
    {
        std::string text = readFile(levels);
        const size_t at = text.find("\"aggregate\": 1, ");
        text.erase(at, 16);
        std::ofstream(tmp("mm_mixed.geojson")) << text;
    }
    r = run("plan " + tmp("mm_mixed.geojson") + " --originals " + wkt + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("has no \"aggregate\" property: not the GeoJSON of `aggrelod aggregate2d`"), std::string::npos)
        << r.output;
    // Thresholds cannot be chosen for fixed levels.
    r = run("plan " + levels + " --originals " + wkt + query + " --delta 3");
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("--delta apply only to plain polygons"), std::string::npos) << r.output;
}

// Every aggregate must contain its originals: an edited aggregate is refused, naming it, whether
// an original's vertex sticks out, the aggregate's boundary cuts into an original, or the
// aggregate has the original as its hole (no vertex on the wrong side; the uncovered area).
TEST(PlanCli, TwoDAggregateNotContainingItsOriginalsIsRefused) {
    const std::string originals = tmp("cont.wkt");
    std::ofstream(originals) << "POLYGON((0 0, 4 0, 4 4, 0 4, 0 0))\nPOLYGON((10 0, 14 0, 14 4, 10 4, 10 0))\n";
    auto levelsFile = [&](const std::string& name, const std::string& level0a, const std::string& level1) {
        const std::string path = tmp(name);
        std::ofstream(path)
            << "{\"type\": \"FeatureCollection\", \"features\": [\n"
               "{\"type\": \"Feature\", \"properties\": {\"level\": 0, \"delta\": 1, \"aggregate\": 0, \"sources\": [0]}, "
               "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": " + level0a + "}},\n"
               "{\"type\": \"Feature\", \"properties\": {\"level\": 0, \"delta\": 1, \"aggregate\": 1, \"sources\": [1]}, "
               "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[10,0],[14,0],[14,4],[10,4],[10,0]]]}},\n"
               "{\"type\": \"Feature\", \"properties\": {\"level\": 1, \"delta\": 7, \"aggregate\": 0, \"sources\": [0, 1]}, "
               "\"geometry\": {\"type\": \"Polygon\", \"coordinates\": " + level1 + "}}\n]}\n";
        return path;
    };
    const std::string square = "[[[0,0],[4,0],[4,4],[0,4],[0,0]]]";
    const std::string query = " --from 7,1 --to 7,3 --radius 0.2 --time-limit 2";
    CliRun r = run("plan " + levelsFile("cont_good.geojson", square, "[[[0,0],[14,0],[14,4],[0,4],[0,0]]]") + " --originals " +
                   originals + query);
    EXPECT_EQ(r.code, 0) << r.output;
    // Level 1 stops short of the second square's right side.
    r = run("plan " + levelsFile("cont_short.geojson", square, "[[[0,0],[13.5,0],[13.5,4],[0,4],[0,0]]]") + " --originals " +
            originals + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("aggregate 0 of level 1 (" + tmp("cont_short.geojson") + " feature 3 at line 4) does not contain "
                            "input feature 1 (" + originals + " line 2): its vertex (14, 0) lies outside the aggregate"),
              std::string::npos)
        << r.output;
    // Level 1 has a notch reaching into the first square.
    r = run("plan " + levelsFile("cont_notch.geojson", square, "[[[0,0],[14,0],[14,4],[3,4],[2,2],[1,4],[0,4],[0,0]]]") +
            " --originals " + originals + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("does not contain input feature 0"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("the aggregate's vertex (2, 2) lies inside it"), std::string::npos) << r.output;
    // Level 0's first aggregate is a frame around the square: every vertex on the other's boundary.
    r = run("plan " + levelsFile("cont_frame.geojson", "[[[-1,-1],[5,-1],[5,5],[-1,5],[-1,-1]],[[0,0],[0,4],[4,4],[4,0],[0,0]]]",
                                 "[[[-1,-1],[14,-1],[14,5],[-1,5],[-1,-1]]]") +
            " --originals " + originals + query);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("aggregate 0 of level 0"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("an area of 16 of it (of 16) lies outside the aggregate"), std::string::npos) << r.output;
}

// A polygon aggregate2d drops (a self-intersecting part of a multipolygon, with a warning) is in
// no aggregate, so it is no obstacle either: the plan says so and plans on what aggregate2d kept,
// the same as on the raw polygons.
TEST(PlanCli, TwoDPolygonsAggregate2DDropsAreNoObstacles) {
    const std::string wkt = tmp("drop.wkt");
    std::ofstream(wkt) << "MULTIPOLYGON(((0 0, 2 0, 2 2, 0 2, 0 0)), ((6 0, 9 2, 9 0, 6 3, 6 0)))\n"
                          "POLYGON((0 6, 2 6, 2 8, 0 8, 0 6))\nPOLYGON((10 0, 11 0, 11 1, 10 1, 10 0))\n";
    const std::string levels = tmp("drop_levels.geojson"), links = tmp("drop_links.csv");
    CliRun r = run("aggregate2d " + wkt + " -o " + levels + " --links " + links + " --delta 1,5");
    ASSERT_EQ(r.code, 0) << r.output;
    ASSERT_NE(r.output.find("self-intersecting"), std::string::npos) << r.output;
    const std::string query = " --from 4,4 --to 6.5,1.2 --radius 0.1 --time-limit 5";  // goal in the dropped bow tie
    r = run("plan " + levels + " --originals " + wkt + " --links " + links + query + " --stats " + tmp("drop_geo.json"));
    EXPECT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("note: " + wkt + " line 1: polygon 2"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("self-intersecting"), std::string::npos) << r.output;
    const CliRun raw = run("plan " + wkt + " --delta 1,5" + query + " --stats " + tmp("drop_raw.json"));
    EXPECT_EQ(raw.code, 0) << raw.output;
    const Stats g = readStats(tmp("drop_geo.json")), w = readStats(tmp("drop_raw.json"));
    EXPECT_TRUE(g.solved);
    EXPECT_EQ(g.levelsUsed, w.levelsUsed);
    EXPECT_EQ(g.path, w.path);
}
