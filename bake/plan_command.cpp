// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod plan: one motion-planning query on a hierarchy (paper Section 4.3, Fig. 7), 2D or 3D,
// with the stats JSON and the Fig. 7-style picture (roadmap coloured by level, path on top).
#include "commands_plan.h"
#include "geo_io.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/runtime_file.h>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace aggrelod::cli {

PlanScene::PlanScene() = default;
PlanScene::~PlanScene() = default;
PlanScene::PlanScene(PlanScene&&) noexcept = default;

namespace {

std::string lower(std::string s) {
    for (char& c : s) c = char(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

std::string num(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return buf;
}

planning::PlanPolygon toPlan(const Polygon2D& p) {
    planning::PlanPolygon out;
    out.rings.push_back(p.exterior);
    for (const auto& h : p.holes) out.rings.push_back(h);
    return out;
}

// ---- a tiny vector drawing, rendered to PNG (scanline fill, stamped lines) or SVG -----------

struct Rgb {
    uint8_t r, g, b;
};

struct Drawing {
    double minX = 0, minY = 0, maxX = 1, maxY = 1;
    struct Shape {
        std::vector<std::vector<double>> rings;  // x y pairs
        Rgb fill;
        bool filled;
        Rgb stroke;
        double strokePx;  // 0 = none
    };
    struct Line {
        double ax, ay, bx, by;
        Rgb color;
        double px;
    };
    std::vector<Shape> shapes;
    std::vector<Line> lines;
    std::vector<std::pair<std::string, Rgb>> legend;
    std::string title;
};

class Canvas {
public:
    Canvas(int w, int h) : w_(w), h_(h), px_(size_t(w) * size_t(h) * 3, 255) {}
    void set(int x, int y, Rgb c) {
        if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
        uint8_t* p = &px_[(size_t(y) * size_t(w_) + size_t(x)) * 3];
        p[0] = c.r, p[1] = c.g, p[2] = c.b;
    }
    // Even-odd fill of rings given in pixel coordinates.
    void fill(const std::vector<std::vector<double>>& rings, Rgb c) {
        double ymin = 1e300, ymax = -1e300;
        for (const auto& r : rings)
            for (size_t i = 1; i < r.size(); i += 2) ymin = std::min(ymin, r[i]), ymax = std::max(ymax, r[i]);
        const int y0 = std::max(0, int(std::floor(ymin))), y1 = std::min(h_ - 1, int(std::ceil(ymax)));
        std::vector<double> xs;
        for (int y = y0; y <= y1; ++y) {
            const double sy = y + 0.5;
            xs.clear();
            for (const auto& r : rings) {
                const size_t n = r.size() / 2;
                for (size_t i = 0, j = n - 1; i < n; j = i++) {
                    const double yi = r[2 * i + 1], yj = r[2 * j + 1];
                    if ((yi > sy) != (yj > sy)) xs.push_back(r[2 * i] + (sy - yi) / (yj - yi) * (r[2 * j] - r[2 * i]));
                }
            }
            std::sort(xs.begin(), xs.end());
            for (size_t k = 0; k + 1 < xs.size(); k += 2)
                for (int x = std::max(0, int(std::ceil(xs[k] - 0.5))); x <= std::min(w_ - 1, int(std::floor(xs[k + 1] - 0.5))); ++x)
                    set(x, y, c);
        }
    }
    void line(double ax, double ay, double bx, double by, Rgb c, double width) {
        const double len = std::hypot(bx - ax, by - ay);
        const int steps = std::max(1, int(std::ceil(len * 2)));
        const int r = std::max(0, int(std::floor(width / 2)));
        for (int s = 0; s <= steps; ++s) {
            const double t = double(s) / steps;
            const int x = int(std::lround(ax + t * (bx - ax))), y = int(std::lround(ay + t * (by - ay)));
            for (int dy = -r; dy <= r; ++dy)
                for (int dx = -r; dx <= r; ++dx)
                    if (dx * dx + dy * dy <= r * r + r) set(x + dx, y + dy, c);
        }
    }
    bool save(const std::string& path) const { return stbi_write_png(path.c_str(), w_, h_, 3, px_.data(), w_ * 3) != 0; }

private:
    int w_, h_;
    std::vector<uint8_t> px_;
};

const Rgb kLevelColors[] = {{214, 39, 40},  {31, 119, 180}, {44, 160, 44}, {148, 103, 189}, {255, 127, 14},
                            {23, 190, 207}, {140, 86, 75},  {227, 119, 194}, {188, 189, 34}, {127, 127, 127}};

Rgb levelColor(int level) { return kLevelColors[size_t(level) % (sizeof kLevelColors / sizeof kLevelColors[0])]; }

std::string levelLabel(const planning::PlanningWorld& w, int level) {
    if (level == 0) return "originals";
    char buf[80];
    std::snprintf(buf, sizeof buf, "level %d (delta %.3g)", w.levelNumber(level), w.levelDelta(level));
    return buf;
}

Drawing makeDrawing(const PlanScene& scene, const planning::PlanResult& result, const std::string& title) {
    const planning::PlanningWorld& w = *scene.world;
    Drawing d;
    d.title = title;
    const planning::Point lo = w.boundsMin(), hi = w.boundsMax();
    d.minX = lo[0], d.minY = lo[1], d.maxX = hi[0], d.maxY = hi[1];
    const int firstLevel = result.levelsUsed.empty() ? 0 : result.levelsUsed.front();
    if (scene.file) {
        // 3D: the originals from above, darker where higher.
        const runtime::RuntimeFile& f = *scene.file;
        const double z0 = lo[2], dz = std::max(1e-9, hi[2] - lo[2]);
        for (uint32_t n = 0; n < f.nodeCount(); ++n) {
            if (!f.isLeaf(n)) continue;
            const runtime::NodeRecord& rec = f.node(n);
            const uint8_t g = uint8_t(215 - 110 * std::clamp((double(rec.boundsMax[2]) - z0) / dz, 0.0, 1.0));
            const runtime::Span<float> v = f.vertices(n);
            const runtime::Span<uint32_t> t = f.triangles(n);
            for (size_t i = 0; i + 2 < t.size; i += 3) {
                std::vector<double> ring;
                for (int k = 0; k < 3; ++k) ring.push_back(v[3 * t[i + k]]), ring.push_back(v[3 * t[i + k] + 1]);
                d.shapes.push_back({{ring}, {g, g, g}, true, {0, 0, 0}, 0});
            }
        }
    } else {
        for (const auto& p : scene.originals2D) d.shapes.push_back({p.rings, {120, 120, 120}, true, {0, 0, 0}, 0});
        if (firstLevel > 0)
            for (const auto& p : scene.levels2D[size_t(firstLevel - 1)])
                d.shapes.push_back({p.rings, {0, 0, 0}, false, levelColor(firstLevel), 1.5});
    }
    // Roadmap edges, coarse levels first so that finer additions stay visible.
    std::vector<size_t> order(result.edges.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return result.edgeLevel[a] > result.edgeLevel[b]; });
    for (size_t i : order) {
        const planning::Point& a = result.vertices[result.edges[i][0]];
        const planning::Point& b = result.vertices[result.edges[i][1]];
        d.lines.push_back({a[0], a[1], b[0], b[1], levelColor(result.edgeLevel[i]), 1});
    }
    for (size_t i = 0; i + 1 < result.path.size(); ++i)
        d.lines.push_back({result.path[i][0], result.path[i][1], result.path[i + 1][0], result.path[i + 1][1], {0, 0, 0}, 4});
    for (int level : result.levelsUsed) d.legend.push_back({"roadmap at " + levelLabel(w, level), levelColor(level)});
    if (result.solved()) d.legend.push_back({"path", {0, 0, 0}});
    return d;
}

// Pixel transform: y up in the scene, down in the picture; a margin and a legend strip.
struct Frame {
    double scale, offX, offY;
    int width, height;
    double x(double v) const { return (v - offX) * scale + 10; }
    double y(double v) const { return height - 10 - (v - offY) * scale; }
};

Frame frameOf(const Drawing& d, int width, int legendRows) {
    Frame f;
    const double w = std::max(1e-9, d.maxX - d.minX), h = std::max(1e-9, d.maxY - d.minY);
    f.scale = (width - 20) / w;
    f.offX = d.minX;
    f.offY = d.minY;
    f.width = width;
    f.height = int(std::ceil(h * f.scale)) + 20;
    (void)legendRows;
    return f;
}

std::string svgColor(Rgb c) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c.r, c.g, c.b);
    return buf;
}

std::string formatSvg(const Drawing& d, int width) {
    const Frame f = frameOf(d, width, int(d.legend.size()));
    const int legendH = 18 * int(d.legend.size()) + 24;
    std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(width) + "\" height=\"" +
                    std::to_string(f.height + legendH) + "\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    char buf[160];
    for (const auto& shape : d.shapes) {
        s += "<path fill-rule=\"evenodd\" d=\"";
        for (const auto& ring : shape.rings) {
            for (size_t i = 0; i + 1 < ring.size(); i += 2) {
                std::snprintf(buf, sizeof buf, "%c%.2f %.2f ", i == 0 ? 'M' : 'L', f.x(ring[i]), f.y(ring[i + 1]));
                s += buf;
            }
            s += "Z ";
        }
        s += "\" fill=\"" + (shape.filled ? svgColor(shape.fill) : std::string("none")) + "\"";
        if (shape.strokePx > 0) s += " stroke=\"" + svgColor(shape.stroke) + "\" stroke-width=\"" + num(shape.strokePx) + "\"";
        s += "/>\n";
    }
    for (const auto& l : d.lines) {
        std::snprintf(buf, sizeof buf, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\" ", f.x(l.ax), f.y(l.ay), f.x(l.bx),
                      f.y(l.by));
        s += buf;
        s += "stroke=\"" + svgColor(l.color) + "\" stroke-width=\"" + num(l.px) + "\"/>\n";
    }
    int y = f.height + 16;
    s += "<text x=\"10\" y=\"" + std::to_string(y) + "\" font-family=\"sans-serif\" font-size=\"13\">" + d.title + "</text>\n";
    for (const auto& [label, c] : d.legend) {
        y += 18;
        s += "<rect x=\"10\" y=\"" + std::to_string(y - 10) + "\" width=\"24\" height=\"6\" fill=\"" + svgColor(c) + "\"/>";
        s += "<text x=\"40\" y=\"" + std::to_string(y) + "\" font-family=\"sans-serif\" font-size=\"12\">" + label + "</text>\n";
    }
    return s + "</svg>\n";
}

bool writePng(const Drawing& d, int width, const std::string& path) {
    const Frame f = frameOf(d, width, int(d.legend.size()));
    const int legendH = 14 * int(d.legend.size()) + 8;
    Canvas c(width, f.height + legendH);
    for (const auto& shape : d.shapes) {
        std::vector<std::vector<double>> rings;
        for (const auto& ring : shape.rings) {
            rings.emplace_back();
            for (size_t i = 0; i + 1 < ring.size(); i += 2) rings.back().push_back(f.x(ring[i])), rings.back().push_back(f.y(ring[i + 1]));
        }
        if (shape.filled) c.fill(rings, shape.fill);
        if (shape.strokePx > 0)
            for (const auto& r : rings)
                for (size_t i = 0, n = r.size() / 2; i < n; ++i)
                    c.line(r[2 * i], r[2 * i + 1], r[2 * ((i + 1) % n)], r[2 * ((i + 1) % n) + 1], shape.stroke, shape.strokePx);
    }
    for (const auto& l : d.lines) c.line(f.x(l.ax), f.y(l.ay), f.x(l.bx), f.y(l.by), l.color, l.px);
    // Legend: colour swatches only (no font); the order is that of the stats' levels_used, then the path.
    int y = f.height + 4;
    for (const auto& entry : d.legend) {
        for (int dy = 0; dy < 8; ++dy)
            for (int dx = 0; dx < 40; ++dx) c.set(10 + dx, y + dy, entry.second);
        y += 14;
    }
    return c.save(path);
}

}  // namespace

bool makePlanScene2D(std::vector<planning::PlanPolygon> originals, std::vector<std::vector<planning::PlanPolygon>> levels,
                     const std::vector<double>& deltas, double radius, PlanScene& out, std::string& error) {
    try {
        out.world = planning::makeWorld2D(originals, levels, deltas, radius);
    } catch (const std::exception& e) {
        error = e.what();
        return false;
    }
    out.originals2D = std::move(originals);
    out.levels2D = std::move(levels);
    return true;
}

bool loadPlanScene(const std::string& path, double radius, int levels, const std::vector<double>& deltas,
                   PlanScene& out, std::string& error, const std::string& originalsPath, const std::string& linksPath) {
    namespace fs = std::filesystem;
    if (!(radius > 0)) {
        error = "--radius must be > 0 (the agent radius in scene units)";
        return false;
    }
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
        error = path + ": no such file";
        return false;
    }
    const std::string ext = lower(fs::path(path).extension().string());
    if (ext == ".geojson" || ext == ".json") {
        // aggregate2d's output: the levels as they are, the originals from --originals.
        std::vector<io::LevelAggregateRecord> records;
        bool isLevels = false;
        if (!io::readLevelsGeoJsonFile(path, records, isLevels, error)) return false;
        if (isLevels) {
            if (originalsPath.empty()) {
                error = path + ": the GeoJSON of `aggrelod aggregate2d` holds the aggregate levels but not the original "
                               "polygons: give the file aggregate2d read with --originals FILE";
                return false;
            }
            if (levels > 0 || !deltas.empty()) {
                error = path + ": the levels of `aggrelod aggregate2d` output are fixed; --levels and --delta apply only "
                               "to plain polygons (use --strategy level:K to plan on one level)";
                return false;
            }
            io::Aggregate2DOutput input;
            if (!io::checkAggregate2DOutput(std::move(records), path, originalsPath, linksPath, input, error)) return false;
            std::vector<planning::PlanPolygon> originals;
            for (const Feature2D& f : input.originals)
                for (const Polygon2D& p : f.polygons) originals.push_back(toPlan(p));
            std::vector<std::vector<planning::PlanPolygon>> levelPolygons;
            std::vector<double> levelDeltas;
            for (const io::Aggregate2DOutput::Level& level : input.levels) {
                levelPolygons.emplace_back();
                levelDeltas.push_back(level.delta);
                for (const io::LevelAggregateRecord& a : level.aggregates)
                    for (const Polygon2D& p : a.polygons) levelPolygons.back().push_back(toPlan(p));
            }
            out.notes = input.notes;
            auto count = [](size_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); };
            out.description = "aggregate2d output, " + count(input.levels.size(), "level") + " over " +
                              count(input.originals.size(), "input feature") + " of " + originalsPath +
                              " (each aggregate contains its sources" +
                              (linksPath.empty() ? std::string()
                                                 : "; link table " + linksPath + ": " + count(input.linkRows, "row") + ", all match") +
                              ")";
            return makePlanScene2D(std::move(originals), std::move(levelPolygons), levelDeltas, radius, out, error);
        }
    }
    if (!originalsPath.empty() || !linksPath.empty()) {
        error = path + ": not the GeoJSON of `aggrelod aggregate2d` (no feature has its level, delta, aggregate and "
                       "sources properties); --originals and --links apply only to that";
        return false;
    }
    if (ext == ".wkt" || ext == ".geojson" || ext == ".json") {
        io::GeoReadResult input;
        if (!io::readPolygonFile(path, input, error)) {
            error = path + ": " + error;
            return false;
        }
        if (input.features.empty()) {
            error = path + ": no polygons";
            return false;
        }
        Settings2D settings;
        settings.deltas = deltas;
        settings.automaticLevelCount = levels > 0 ? levels : 6;
        settings.computeBaselines = false;
        Hierarchy2D h;
        if (!buildHierarchy2D(input.features, settings, h)) {
            error = path + ": the polygons could not be aggregated";
            return false;
        }
        // The obstacles are the polygons the hierarchy was built on: without those the input
        // checks drop (invalid polygons of a multipolygon), which no aggregate contains.
        std::vector<Diagnostic> checks;
        const std::vector<std::vector<Polygon2D>> accepted = acceptedPolygons2D(input.features, checks);
        std::vector<planning::PlanPolygon> originals;
        for (size_t i = 0; i < input.features.size(); ++i)
            if (h.featureModel[i] >= 0)
                for (const Polygon2D& p : accepted[i]) originals.push_back(toPlan(p));
        std::vector<std::vector<planning::PlanPolygon>> levelPolygons;
        std::vector<double> levelDeltas;
        for (const Level2D& level : h.levels) {
            levelPolygons.emplace_back();
            levelDeltas.push_back(level.delta);
            for (const Aggregate2D& a : level.aggregates)
                for (const Polygon2D& p : a.polygons) levelPolygons.back().push_back(toPlan(p));
        }
        out.description = "polygons aggregated here, " + std::to_string(levelPolygons.size()) + " levels";
        return makePlanScene2D(std::move(originals), std::move(levelPolygons), levelDeltas, radius, out, error);
    }
    auto file = std::make_unique<runtime::RuntimeFile>();
    std::string message;
    const runtime::FileStatus status = runtime::RuntimeFile::openFile(path, *file, message);
    if (status != runtime::FileStatus::Ok) {
        error = path + ": not a baked runtime file (" + std::string(runtime::toString(status)) +
                (message.empty() ? "" : ": " + message) +
                "); `aggrelod plan` reads OUTDIR/scene.aglod (3D), the GeoJSON of `aggrelod aggregate2d` (with "
                "--originals) or 2D polygons (.wkt, .geojson, .json)";
        return false;
    }
    try {
        out.world = planning::makeWorld3D(*file, radius);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
    out.file = std::move(file);
    return true;
}

bool writePlanPicture(const PlanScene& scene, const planning::PlanResult& result, const std::string& path, bool svg,
                      const std::string& title, std::string& error) {
    const Drawing d = makeDrawing(scene, result, title);
    if (svg) return io::writeTextFile(path, formatSvg(d, 800), error);
    if (!writePng(d, 800, path)) {
        error = path + ": cannot write the PNG";
        return false;
    }
    return true;
}

std::string formatPlanStatsJson(const PlanScene& scene, const planning::PlanResult& r, const planning::PlanRequest& request) {
    const planning::PlanningWorld& w = *scene.world;
    const int dim = w.dimension();
    std::string s = "{\n  \"solved\": " + std::string(r.solved() ? "true" : "false") + ",\n  \"path\": [";
    for (size_t i = 0; i < r.path.size(); ++i) {
        s += i ? ", [" : "[";
        for (int k = 0; k < dim; ++k) s += (k ? ", " : "") + num(r.path[i][size_t(k)]);
        s += "]";
    }
    s += "],\n  \"levels_used\": [";
    for (size_t i = 0; i < r.levelsUsed.size(); ++i) s += (i ? ", " : "") + std::to_string(w.levelNumber(r.levelsUsed[i]));
    s += "],\n  \"seconds\": " + num(r.seconds) + ",\n  \"collision_checks\": " + std::to_string(r.collisionChecks()) +
         ",\n  \"roadmap_vertices\": " + std::to_string(r.roadmapVertices) + ",\n  \"roadmap_edges\": " +
         std::to_string(r.roadmapEdges) + ",\n  \"state_checks\": " + std::to_string(r.stateChecks) +
         ",\n  \"motion_checks\": " + std::to_string(r.motionChecks) + ",\n  \"path_length\": " + num(r.pathLength) +
         ",\n  \"strategy\": \"" + planning::strategyName(request.strategy, request.strategy == planning::Strategy::FixedLevel ? w.levelNumber(request.fixedLevel) : 0) +
         "\",\n  \"radius\": " + num(w.radius()) + ",\n  \"time_limit\": " + num(request.timeLimit) +
         ",\n  \"seed\": " + std::to_string(request.seed) + ",\n  \"levels\": [";
    for (int l = 1; l < w.levelCount(); ++l)
        s += std::string(l > 1 ? ", " : "") + "{\"level\": " + std::to_string(w.levelNumber(l)) + ", \"delta\": " + num(w.levelDelta(l)) + "}";
    return s + "]\n}\n";
}

int runPlan(const PlanOptions& o) {
    auto fail = [](int code, const std::string& message) {
        std::fprintf(stderr, "aggrelod: error: %s\n", message.c_str());
        return code;
    };
    if (!(o.radius > 0)) return fail(1, "--radius must be > 0 (the agent radius in scene units)");
    if (!(o.timeLimit > 0)) return fail(1, "--time-limit must be > 0 seconds");
    planning::PlanRequest request;
    request.timeLimit = o.timeLimit;
    request.seed = o.seed;
    request.levelSamples = o.levelSamples;
    int fileLevel = -1;
    if (o.strategy == "hierarchy") {
        request.strategy = planning::Strategy::Hierarchy;
    } else if (o.strategy == "originals") {
        request.strategy = planning::Strategy::Originals;
    } else if (o.strategy.rfind("level:", 0) == 0) {
        request.strategy = planning::Strategy::FixedLevel;
        try {
            size_t used = 0;
            fileLevel = std::stoi(o.strategy.substr(6), &used);
            if (used != o.strategy.size() - 6 || fileLevel < 0) throw std::invalid_argument("");
        } catch (const std::exception&) {
            return fail(1, "--strategy " + o.strategy + ": K in level:K must be a level number (0, 1, ...)");
        }
    } else {
        return fail(1, "--strategy must be hierarchy, originals or level:K, not '" + o.strategy + "'");
    }

    PlanScene scene;
    std::string error;
    if (!loadPlanScene(o.input, o.radius, o.levels, o.deltas, scene, error, o.originalsPath, o.linksPath))
        return fail(2, error);
    if (!o.quiet)
        for (const std::string& note : scene.notes) std::fprintf(stderr, "aggrelod: note: %s\n", note.c_str());
    const int dim = scene.world->dimension();
    auto point = [&](const std::vector<double>& v, const char* name, planning::Point& p) {
        if (int(v.size()) != dim) {
            fail(1, std::string(name) + " needs " + (dim == 2 ? "x,y" : "x,y,z") + " for this " + (dim == 2 ? "2D" : "3D") +
                        " scene (got " + std::to_string(v.size()) + " numbers)");
            return false;
        }
        p = {v[0], v[1], dim == 3 ? v[2] : 0.0};
        return true;
    };
    if (!point(o.from, "--from", request.start) || !point(o.to, "--to", request.goal)) return 1;
    if (fileLevel >= 0) {
        request.fixedLevel = -1;
        for (int l = 1; l < scene.world->levelCount(); ++l)
            if (scene.world->levelNumber(l) == fileLevel) request.fixedLevel = l;
        if (request.fixedLevel < 0)
            return fail(1, "--strategy level:" + std::to_string(fileLevel) + ": the hierarchy has levels 0.." +
                               std::to_string(scene.world->levelCount() - 2));
    }

    const planning::PlanResult r = planning::plan(*scene.world, request);
    if (r.status == planning::PlanStatus::InvalidStart || r.status == planning::PlanStatus::InvalidGoal ||
        r.status == planning::PlanStatus::BadRequest)
        return fail(1, r.message);
    if (!o.statsPath.empty() && !io::writeTextFile(o.statsPath, formatPlanStatsJson(scene, r, request), error))
        return fail(2, error);
    const std::string title = planning::strategyName(request.strategy, fileLevel) + (r.solved() ? ": solved" : ": no path");
    if (!o.pngPath.empty() && !writePlanPicture(scene, r, o.pngPath, false, title, error)) return fail(2, error);
    if (!o.svgPath.empty() && !writePlanPicture(scene, r, o.svgPath, true, title, error)) return fail(2, error);
    if (!o.quiet) {
        std::string levels;
        for (int l : r.levelsUsed) levels += (levels.empty() ? "" : " -> ") + levelLabel(*scene.world, l);
        if (!scene.description.empty()) std::printf("%s: %s\n", o.input.c_str(), scene.description.c_str());
        std::printf("%s: %s in %.3f s; levels %s; %llu collision checks; roadmap %zu vertices, %zu edges",
                    o.input.c_str(), r.solved() ? "solved" : "no path found", r.seconds, levels.c_str(),
                    static_cast<unsigned long long>(r.collisionChecks()), r.roadmapVertices, r.roadmapEdges);
        if (r.solved()) std::printf("; path %zu points, length %.4g", r.path.size(), r.pathLength);
        std::printf("\n");
    }
    return r.solved() ? 0 : 3;
}

}  // namespace aggrelod::cli
