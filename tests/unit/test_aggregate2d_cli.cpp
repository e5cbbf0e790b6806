// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod aggregate2d from the command line: outputs, determinism and bad input (every
// problem named with its feature and line; never a crash). Runs the ASan build when present.
#include "geos_support.h"
#include "test_support.h"

#include "geo_io.h"

#include <gtest/gtest.h>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

std::string cli() {
#ifdef AGGRELOD_CLI_ASAN
    return AGGRELOD_CLI_ASAN;
#else
    return AGGRELOD_CLI;
#endif
}

struct Case {
    std::string name, file, text;
    int exitCode;
    std::vector<std::string> expected;  // all must appear in stderr
};

RunResult runOn(const fs::path& dir, const std::string& file, const std::string& text,
                const std::vector<std::string>& extra = {}) {
    ::setenv("ASAN_OPTIONS", "detect_leaks=0:abort_on_error=0:exitcode=86", 1);
    ::setenv("UBSAN_OPTIONS", "halt_on_error=1:print_stacktrace=1:exitcode=86", 1);
    writeFile(dir / file, text);
    std::vector<std::string> args{cli(), "aggregate2d", (dir / file).string(), "-o", (dir / "out.geojson").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    return runProgram(args, dir);
}

const std::string kGoodSquare = "POLYGON((0 0, 1 0, 1 1, 0 1, 0 0))\n";

}  // namespace

TEST(Aggregate2DCli, BadInputIsNamedWithFeatureAndLine) {
    const fs::path dir = freshTestDir(currentTestName());
    const std::vector<Case> cases = {
        {"self-intersecting", "a.wkt", kGoodSquare + "POLYGON((3 0, 5 2, 5 0, 3 1, 3 0))\n", 0,
         {"line 2", "self-intersecting ring"}},
        {"unclosed", "b.wkt", kGoodSquare + "\nPOLYGON((3 0, 4 0, 4 1, 3 1))\n", 0, {"line 3", "unclosed ring"}},
        {"empty wkt", "c.wkt", kGoodSquare + "POLYGON EMPTY\n", 0, {"line 2", "empty geometry"}},
        {"nan", "d.wkt", kGoodSquare + "POLYGON((3 0, nan 0, 4 1, 3 0))\n", 0, {"line 2", "not a finite number"}},
        {"unsupported wkt", "e.wkt", kGoodSquare + "POINT(1 2)\n", 0, {"line 2", "unsupported geometry type 'POINT'"}},
        {"malformed wkt", "f.wkt", kGoodSquare + "POLYGON((3 0, 4 0, 4 1 3 0)\n", 0, {"line 2", "malformed WKT"}},
        {"overlap", "g.wkt", kGoodSquare + "POLYGON((0.5 0.5, 2 0.5, 2 2, 0.5 2, 0.5 0.5))\n", 0,
         {"line 1, line 2", "touch or overlap; merged into one model"}},
        {"malformed json", "h.geojson", "{\"type\": \"FeatureCollection\",\n \"features\": [\n {\"type\": \"Feature\",, }]}", 2,
         {"malformed JSON", "line 3"}},
        {"unsupported json", "i.geojson",
         "{\"type\": \"FeatureCollection\", \"features\": [\n"
         "{\"type\": \"Feature\", \"properties\": {\"name\": \"well\"}, \"geometry\": {\"type\": \"Point\", \"coordinates\": [1, 2]}},\n"
         "{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0],[1,1],[0,0]]]}}\n]}",
         0, {"feature 1 \"well\" (line 2)", "unsupported geometry type 'Point'"}},
        {"empty json", "j.geojson",
         "{\"type\": \"FeatureCollection\", \"features\": [\n"
         "{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0],[1,1],[0,0]]]}},\n"
         "{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"MultiPolygon\", \"coordinates\": []}}\n]}",
         0, {"feature 2 (line 3)", "empty geometry"}},
        {"nan json", "m.geojson",
         "{\"type\": \"FeatureCollection\", \"features\": [\n"
         "{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0],[1,1],[0,0]]]}},\n"
         "{\"type\": \"Feature\", \"properties\": {\"name\": \"NaN Infinity\"}, \"geometry\": {\"type\": \"Polygon\", "
         "\"coordinates\": [[[3,0],[NaN,0],[4,Infinity],[3,0]]]}}\n]}",
         0, {"feature 2 \"NaN Infinity\" (line 3)", "not a finite number"}},
        {"latin-1 json", "n.geojson",
         "{\"type\": \"FeatureCollection\", \"features\": [\n"
         "{\"type\": \"Feature\", \"properties\": {\"name\": \"Caf\xe9\"}, \"geometry\": {\"type\": \"Point\", \"coordinates\": [1, 2]}},\n"
         "{\"type\": \"Feature\", \"properties\": {}, \"geometry\": {\"type\": \"Polygon\", \"coordinates\": [[[0,0],[1,0],[1,1],[0,0]]]}}\n]}",
         0, {"feature 1 \"Caf\xc3\xa9\" (line 2)", "unsupported geometry type 'Point'"}},
        {"nothing usable", "k.wkt", "POLYGON((3 0, 5 2, 5 0, 3 1, 3 0))\n", 3, {"line 1", "self-intersecting"}},
        {"missing file", "l.txt", "", 2, {"cannot open"}},
    };
    for (const Case& c : cases) {
        RunResult r;
        if (c.name == "missing file") {
            r = runProgram({cli(), "aggregate2d", (dir / "nope.wkt").string(), "-o", (dir / "o.geojson").string()}, dir);
        } else {
            r = runOn(dir, c.file, c.text);
        }
        ASSERT_TRUE(r.exited) << c.name << "\n" << r.describe();
        EXPECT_EQ(r.exitCode, c.exitCode) << c.name << "\n" << r.describe();
        for (const std::string& e : c.expected)
            EXPECT_NE(r.err.find(e), std::string::npos) << c.name << ": expected '" << e << "'\n" << r.describe();
    }
}

TEST(Aggregate2DCli, WritesLevelsLinksPicturesAndStatsDeterministically) {
    const fs::path dir = freshTestDir(currentTestName());
    std::string wkt;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 4; ++j) {
            const double x = i * 3.0 + (j % 2) * 0.7, y = j * 2.5;
            char line[200];
            std::snprintf(line, sizeof line, "POLYGON((%g %g, %g %g, %g %g, %g %g, %g %g))\n", x, y, x + 2, y, x + 2, y + 1.5,
                          x, y + 1.5, x, y);
            wkt += line;
        }
    const std::vector<std::string> extra{"--delta", "0.5,1.2,3", "--links", (dir / "links.csv").string(), "--svg",
                                         (dir / "p.svg").string(), "--png", (dir / "p.png").string(), "--stats",
                                         (dir / "stats.json").string(), "--quiet"};
    RunResult r = runOn(dir, "in.wkt", wkt, extra);
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_EQ(r.out, "") << "--quiet prints nothing";
    const std::string first = readFile(dir / "out.geojson");
    const std::string links = readFile(dir / "links.csv");
    // Read the output back: 3 levels, every aggregate valid and the sources cover all inputs.
    io::GeoReadResult back;
    std::string error;
    ASSERT_TRUE(io::readPolygonText(first, "geojson", back, error)) << error;
    EXPECT_TRUE(back.diagnostics.empty());
    for (const Feature2D& f : back.features) EXPECT_EQ(geosValidity(f.polygons), "Valid Geometry") << f.name;
    EXPECT_NE(first.find("\"level\": 2"), std::string::npos);
    // Link table: header + 20 inputs x 3 levels.
    EXPECT_EQ(std::count(links.begin(), links.end(), '\n'), 61);
    EXPECT_EQ(links.rfind("input_id,level,delta,output_id\n", 0), 0u);
    EXPECT_GT(fs::file_size(dir / "p.png"), 1000u);
    EXPECT_NE(readFile(dir / "p.svg").find("<path"), std::string::npos);
    EXPECT_NE(readFile(dir / "stats.json").find("\"normalized_circularity\""), std::string::npos);
    // Run again: byte-identical outputs.
    r = runOn(dir, "in.wkt", wkt, extra);
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_EQ(readFile(dir / "out.geojson"), first);
    EXPECT_EQ(readFile(dir / "links.csv"), links);
    // hull and constant functions run too.
    for (const std::string fn : {"hull", "constant"}) {
        r = runOn(dir, "in.wkt", wkt, {"--function", fn, "--levels", "3", "-q"});
        EXPECT_EQ(r.exitCode, 0) << fn << "\n" << r.describe();
    }
}

TEST(Aggregate2DCli, Reproduce2DWritesTablesAndFiguresDeterministically) {
    const fs::path dir = freshTestDir(currentTestName());
    RunResult r = runProgram({AGGRELOD_CLI, "reproduce2d", "-o", (dir / "a").string(), "-q"}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    const std::string csv = readFile(dir / "a" / "table.csv");
    // Header + 5 environments x 4 levels.
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 21) << csv;
    for (const std::string env : {"tree", "scatter", "room", "colony", "forest"}) {
        EXPECT_NE(csv.find(env + ","), std::string::npos) << env;
        EXPECT_GT(fs::file_size(dir / "a" / ("fig4-" + env + ".png")), 5000u) << env;
    }
    EXPECT_GT(fs::file_size(dir / "a" / "fig6.png"), 5000u);
    // Every row: area adaptive <= constant <= hull (columns 7, 8, 9 of the CSV).
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
        std::vector<double> v;
        std::istringstream cells(line);
        std::string cell;
        while (std::getline(cells, cell, ',')) v.push_back(std::atof(cell.c_str()));
        ASSERT_GE(v.size(), 15u) << line;
        EXPECT_LE(v[7], v[6] + 1e-4) << line;
        EXPECT_LE(v[6], v[8] + 1e-4) << line;
    }
    r = runProgram({AGGRELOD_CLI, "reproduce2d", "-o", (dir / "b").string(), "-q"}, dir);
    ASSERT_EQ(r.exitCode, 0) << r.describe();
    EXPECT_EQ(readFile(dir / "b" / "table.csv"), csv);
    EXPECT_EQ(readFile(dir / "b" / "table.md"), readFile(dir / "a" / "table.md"));
    EXPECT_EQ(readFile(dir / "b" / "fig6.png"), readFile(dir / "a" / "fig6.png"));
}
