// SPDX-License-Identifier: AGPL-3.0-or-later
// aggregate2d's output read back (levels GeoJSON, link table, the input polygons) and checked:
// the levels are a hierarchy of the inputs, the link table matches, and every aggregate
// contains its sources, so that what is free at a level is free for the originals.
#include "geo_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

namespace aggrelod::io {
namespace {

// ---------------------------------------------------------------------------------------
// Containment of one union of polygons in another, up to a tolerance

struct Edge {
    double ax, ay, bx, by;
    int set;      // 0 inner, 1 outer
    int polygon;  // index within its set
    int dir;      // +1 going down (entering from the left when exteriors are CCW), -1 going up, 0 flat
};

double orient(double ax, double ay, double bx, double by, double px, double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

double pointSegmentDistance(double px, double py, const Edge& e) {
    const double dx = e.bx - e.ax, dy = e.by - e.ay, len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((px - e.ax) * dx + (py - e.ay) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(e.ax + t * dx - px, e.ay + t * dy - py);
}

double ringArea(const std::vector<double>& ring) {
    const size_t n = ring.size() / 2;
    double a = 0;
    for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        a += ring[2 * i] * ring[2 * j + 1] - ring[2 * j] * ring[2 * i + 1];
    }
    return 0.5 * a;
}

/// Edges of one set, rings oriented exterior CCW and holes CW (as the signed areas say), so the
/// count of enclosing polygons rises by `dir` when a horizontal line crosses an edge to the right.
void addEdges(const std::vector<const Polygon2D*>& polygons, int set, std::vector<Edge>& out, double& perimeter) {
    for (size_t p = 0; p < polygons.size(); ++p) {
        for (size_t r = 0; r <= polygons[p]->holes.size(); ++r) {
            const std::vector<double>& ring = r == 0 ? polygons[p]->exterior : polygons[p]->holes[r - 1];
            const size_t n = ring.size() / 2;
            if (n < 2) continue;
            const bool flip = (ringArea(ring) > 0) != (r == 0);
            for (size_t i = 0; i < n; ++i) {
                const size_t j = (i + 1) % n;
                Edge e{ring[2 * i], ring[2 * i + 1], ring[2 * j], ring[2 * j + 1], set, int(p), 0};
                if (flip) e = {e.bx, e.by, e.ax, e.ay, set, int(p), 0};
                if (e.ax == e.bx && e.ay == e.by) continue;
                e.dir = e.by < e.ay ? 1 : e.by > e.ay ? -1 : 0;
                perimeter += std::hypot(e.bx - e.ax, e.by - e.ay);
                out.push_back(e);
            }
        }
    }
}

/// Uniform grid of edge bounding boxes.
class EdgeGrid {
public:
    EdgeGrid(const std::vector<Edge>& edges) : edges_(edges) {
        x0_ = y0_ = 1e300;
        double x1 = -1e300, y1 = -1e300;
        for (const Edge& e : edges) {
            x0_ = std::min({x0_, e.ax, e.bx}), y0_ = std::min({y0_, e.ay, e.by});
            x1 = std::max({x1, e.ax, e.bx}), y1 = std::max({y1, e.ay, e.by});
        }
        const double w = std::max(x1 - x0_, 1e-300), h = std::max(y1 - y0_, 1e-300);
        const double cells = std::clamp(double(edges.size()), 1.0, 1e6);
        const double side = std::sqrt(w * h / cells);
        nx_ = std::clamp(int(std::ceil(w / std::max(side, 1e-300))), 1, 2048);
        ny_ = std::clamp(int(std::ceil(h / std::max(side, 1e-300))), 1, 2048);
        cw_ = w / nx_, ch_ = h / ny_;
        cells_.resize(size_t(nx_) * size_t(ny_));
        for (size_t i = 0; i < edges.size(); ++i) {
            const Edge& e = edges[i];
            const int cx0 = col(std::min(e.ax, e.bx)), cx1 = col(std::max(e.ax, e.bx));
            const int cy0 = row(std::min(e.ay, e.by)), cy1 = row(std::max(e.ay, e.by));
            for (int cy = cy0; cy <= cy1; ++cy)
                for (int cx = cx0; cx <= cx1; ++cx) cells_[size_t(cy) * size_t(nx_) + size_t(cx)].push_back(uint32_t(i));
        }
        stamp_.assign(edges.size(), 0);
    }
    int col(double x) const { return std::clamp(int((x - x0_) / cw_), 0, nx_ - 1); }
    int row(double y) const { return std::clamp(int((y - y0_) / ch_), 0, ny_ - 1); }
    const std::vector<std::vector<uint32_t>>& cells() const { return cells_; }

    /// Distance from p to the nearest edge of `set`, if below `limit`; else `limit`.
    double nearest(double px, double py, int set, double limit) {
        ++tick_;
        double best = limit;
        for (int cy = row(py - limit); cy <= row(py + limit); ++cy)
            for (int cx = col(px - limit); cx <= col(px + limit); ++cx)
                for (uint32_t i : cells_[size_t(cy) * size_t(nx_) + size_t(cx)]) {
                    if (stamp_[i] == tick_ || edges_[i].set != set) continue;
                    stamp_[i] = tick_;
                    best = std::min(best, pointSegmentDistance(px, py, edges_[i]));
                }
        return best;
    }

    /// True when p is inside some polygon of `set` (crossings of the ray to +x, per polygon
    /// even-odd; a point on an edge may go either way).
    bool inside(double px, double py, int set, size_t polygonCount) {
        ++tick_;
        std::vector<char> parity(polygonCount, 0);
        const int cy = row(py);
        for (int cx = col(px); cx < nx_; ++cx)
            for (uint32_t i : cells_[size_t(cy) * size_t(nx_) + size_t(cx)]) {
                const Edge& e = edges_[i];
                if (stamp_[i] == tick_ || e.set != set) continue;
                stamp_[i] = tick_;
                if ((e.ay > py) != (e.by > py) && px < (e.bx - e.ax) * (py - e.ay) / (e.by - e.ay) + e.ax)
                    parity[size_t(e.polygon)] ^= 1;
            }
        return std::find(parity.begin(), parity.end(), 1) != parity.end();
    }

private:
    const std::vector<Edge>& edges_;
    double x0_, y0_, cw_, ch_;
    int nx_, ny_;
    std::vector<std::vector<uint32_t>> cells_;
    std::vector<uint32_t> stamp_;
    uint32_t tick_ = 0;
};

std::string point(double x, double y) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.10g, %.10g)", x, y);
    return buf;
}

std::string number(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

}  // namespace

Containment2D checkContainment2D(const std::vector<const Polygon2D*>& inner, const std::vector<const Polygon2D*>& outer,
                                 double tolerance) {
    Containment2D c;
    std::vector<Edge> edges;
    double innerPerimeter = 0, outerPerimeter = 0;
    addEdges(inner, 0, edges, innerPerimeter);
    addEdges(outer, 1, edges, outerPerimeter);
    if (edges.empty()) return c;
    EdgeGrid grid(edges);

    // 1. Vertices on the wrong side: an inner vertex outside every outer polygon, or an outer
    //    vertex inside an inner polygon (a boundary of the outer set inside the inner one means
    //    uncovered inner points beside it), farther than the tolerance from the other boundary.
    for (const Edge& e : edges) {
        const int other = 1 - e.set;
        const bool wrong = e.set == 0 ? !grid.inside(e.ax, e.ay, 1, outer.size()) : grid.inside(e.ax, e.ay, 0, inner.size());
        if (!wrong) continue;
        const double d = grid.nearest(e.ax, e.ay, other, tolerance * 2);
        if (d > tolerance) {
            c.contained = false;
            c.why = e.set == 0 ? "its vertex " + point(e.ax, e.ay) + " lies outside the aggregate"
                               : "the aggregate's vertex " + point(e.ax, e.ay) + " lies inside it";
            c.why += d >= tolerance * 2 ? "" : " by " + number(d);
            break;
        }
    }

    // 2. Uncovered area, exactly: between consecutive event heights (vertices and edge
    //    crossings) no two edges change order, so the uncovered length of a horizontal line is
    //    linear in y and its value at the slab's middle times the slab's height is the slab's area.
    std::vector<double> ys;
    ys.reserve(edges.size() * 2);
    for (const Edge& e : edges) ys.push_back(e.ay);
    for (const auto& cell : grid.cells())
        for (size_t a = 0; a < cell.size(); ++a)
            for (size_t b = a + 1; b < cell.size(); ++b) {
                const Edge& e = edges[cell[a]];
                const Edge& f = edges[cell[b]];
                if (std::max(e.ax, e.bx) < std::min(f.ax, f.bx) || std::max(f.ax, f.bx) < std::min(e.ax, e.bx) ||
                    std::max(e.ay, e.by) < std::min(f.ay, f.by) || std::max(f.ay, f.by) < std::min(e.ay, e.by))
                    continue;
                const double d1 = orient(e.ax, e.ay, e.bx, e.by, f.ax, f.ay), d2 = orient(e.ax, e.ay, e.bx, e.by, f.bx, f.by);
                const double d3 = orient(f.ax, f.ay, f.bx, f.by, e.ax, e.ay), d4 = orient(f.ax, f.ay, f.bx, f.by, e.bx, e.by);
                if (!((d1 < 0 && d2 > 0) || (d1 > 0 && d2 < 0)) || !((d3 < 0 && d4 > 0) || (d3 > 0 && d4 < 0))) continue;
                const double t = d3 / (d3 - d4);
                ys.push_back(e.ay + t * (e.by - e.ay));
            }
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    std::vector<uint32_t> order(edges.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = uint32_t(i);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return std::min(edges[a].ay, edges[a].by) < std::min(edges[b].ay, edges[b].by);
    });
    std::vector<uint32_t> active;
    struct Crossing {
        double x;
        int set, dir;
    };
    std::vector<Crossing> xs;
    size_t next = 0;
    double worstLength = 0, worstY = 0, worstX = 0;
    for (size_t k = 0; k + 1 < ys.size(); ++k) {
        const double y0 = ys[k], y1 = ys[k + 1], ym = 0.5 * (y0 + y1);
        if (!(ym > y0 && ym < y1)) continue;
        while (next < order.size() && std::min(edges[order[next]].ay, edges[order[next]].by) < ym) active.push_back(order[next++]);
        active.erase(std::remove_if(active.begin(), active.end(),
                                    [&](uint32_t i) { return std::max(edges[i].ay, edges[i].by) < ym; }),
                     active.end());
        xs.clear();
        for (uint32_t i : active) {
            const Edge& e = edges[i];
            if ((e.ay > ym) == (e.by > ym)) continue;
            xs.push_back({e.ax + (ym - e.ay) * (e.bx - e.ax) / (e.by - e.ay), e.set, e.dir});
        }
        std::sort(xs.begin(), xs.end(), [](const Crossing& a, const Crossing& b) { return a.x < b.x; });
        int in = 0, out = 0;
        double uncovered = 0, covered = 0, firstX = 0;
        for (size_t i = 0; i + 1 < xs.size(); ++i) {
            (xs[i].set == 0 ? in : out) += xs[i].dir;
            const double len = xs[i + 1].x - xs[i].x;
            if (in > 0) covered += len;
            if (in > 0 && out <= 0) {
                if (uncovered == 0) firstX = 0.5 * (xs[i].x + xs[i + 1].x);
                uncovered += len;
            }
        }
        c.innerArea += covered * (y1 - y0);
        c.uncoveredArea += uncovered * (y1 - y0);
        if (uncovered * (y1 - y0) > worstLength) worstLength = uncovered * (y1 - y0), worstY = ym, worstX = firstX;
    }
    const double allowed = tolerance * innerPerimeter;
    if (c.contained && c.uncoveredArea > allowed) {
        c.contained = false;
        c.why = "an area of " + number(c.uncoveredArea) + " of it (of " + number(c.innerArea) +
                ") lies outside the aggregate, e.g. at " + point(worstX, worstY);
    }
    return c;
}

bool checkAggregate2DOutput(std::vector<LevelAggregateRecord> records, const std::string& levelsPath,
                            const std::string& originalsPath, const std::string& linksPath, Aggregate2DOutput& out,
                            std::string& error) {
    out = Aggregate2DOutput{};
    const std::string& L = levelsPath;
    auto aggregateName = [&](const LevelAggregateRecord& r) {
        return "aggregate " + std::to_string(r.aggregate) + " of level " + std::to_string(r.level) + " (" + L + " " + r.name + ")";
    };

    // Levels 0..n-1, one delta each, ascending; aggregate indices unique in a level.
    int levelCount = 0;
    for (const LevelAggregateRecord& r : records) levelCount = std::max(levelCount, r.level + 1);
    out.levels.resize(size_t(levelCount));
    std::vector<bool> seen(size_t(levelCount), false);
    std::vector<std::set<int>> indices(static_cast<size_t>(levelCount));
    for (LevelAggregateRecord& r : records) {
        Aggregate2DOutput::Level& level = out.levels[size_t(r.level)];
        if (!seen[size_t(r.level)]) {
            seen[size_t(r.level)] = true;
            level.delta = r.delta;
        } else if (r.delta != level.delta) {
            error = L + ": " + r.name + " gives level " + std::to_string(r.level) + " delta " + number(r.delta) +
                    ", an earlier feature " + number(level.delta) + "; not the GeoJSON of `aggrelod aggregate2d`";
            return false;
        }
        if (!indices[size_t(r.level)].insert(r.aggregate).second) {
            error = L + ": " + r.name + ": level " + std::to_string(r.level) + " has a second aggregate " +
                    std::to_string(r.aggregate) + "; not the GeoJSON of `aggrelod aggregate2d`";
            return false;
        }
        level.aggregates.push_back(std::move(r));
    }
    for (int l = 0; l < levelCount; ++l) {
        if (!seen[size_t(l)]) {
            error = L + ": no aggregate of level " + std::to_string(l) + " (levels run 0.." + std::to_string(levelCount - 1) +
                    "); not the GeoJSON of `aggrelod aggregate2d`";
            return false;
        }
        if (l > 0 && out.levels[size_t(l)].delta < out.levels[size_t(l - 1)].delta) {
            error = L + ": level " + std::to_string(l) + " has delta " + number(out.levels[size_t(l)].delta) +
                    ", below level " + std::to_string(l - 1) + "'s " + number(out.levels[size_t(l - 1)].delta) +
                    "; not the GeoJSON of `aggrelod aggregate2d`";
            return false;
        }
    }

    // Every level covers the same input features, each once.
    std::map<uint32_t, const LevelAggregateRecord*> level0;
    for (const LevelAggregateRecord& r : out.levels[0].aggregates)
        for (uint32_t s : r.sources)
            if (!level0.emplace(s, &r).second) {
                error = L + ": input feature " + std::to_string(s) + " is in two aggregates of level 0 (" + level0[s]->name +
                        " and " + r.name + "); not the GeoJSON of `aggrelod aggregate2d`";
                return false;
            }
    for (int l = 1; l < levelCount; ++l) {
        std::map<uint32_t, const LevelAggregateRecord*> here;
        for (const LevelAggregateRecord& r : out.levels[size_t(l)].aggregates)
            for (uint32_t s : r.sources) {
                if (!here.emplace(s, &r).second) {
                    error = L + ": input feature " + std::to_string(s) + " is in two aggregates of level " + std::to_string(l) +
                            " (" + here[s]->name + " and " + r.name + "); not the GeoJSON of `aggrelod aggregate2d`";
                    return false;
                }
                if (!level0.count(s)) {
                    error = L + ": " + aggregateName(r) + " covers input feature " + std::to_string(s) +
                            ", which no aggregate of level 0 covers; not the GeoJSON of `aggrelod aggregate2d`";
                    return false;
                }
            }
        if (here.size() != level0.size())
            for (const auto& [s, r] : level0)
                if (!here.count(s)) {
                    error = L + ": no aggregate of level " + std::to_string(l) + " covers input feature " + std::to_string(s) +
                            " (level 0: " + r->name + "); not the GeoJSON of `aggrelod aggregate2d`";
                    return false;
                }
    }

    // The originals: the polygons aggregate2d read.
    GeoReadResult input;
    if (!readPolygonFile(originalsPath, input, error)) return false;
    std::map<uint32_t, size_t> byId;
    for (size_t i = 0; i < input.features.size(); ++i) byId[input.features[i].id] = i;
    for (const auto& [s, r] : level0)
        if (!byId.count(s)) {
            error = L + ": " + aggregateName(*r) + " lists input feature " + std::to_string(s) + ", which " + originalsPath +
                    " does not have (" + std::to_string(input.features.size()) +
                    " usable features); give the file `aggrelod aggregate2d` read";
            return false;
        }
    // Only the polygons aggregate2d accepts are part of the hierarchy (it drops invalid ones
    // with a warning): the same checks, without aggregating.
    std::vector<Diagnostic> checks;
    std::vector<std::vector<Polygon2D>> accepted = acceptedPolygons2D(input.features, checks);
    for (const auto& [s, r] : level0)
        if (accepted[byId[s]].empty()) {
            error = L + ": " + aggregateName(*r) + " lists input feature " + std::to_string(s) + " (" + originalsPath + " " +
                    input.features[byId[s]].name + "), which aggregate2d's input checks reject; give the file "
                    "`aggrelod aggregate2d` read";
            return false;
        }
    std::vector<char> used(input.features.size(), 0);
    for (const auto& [s, r] : level0) used[byId[s]] = 1;
    for (size_t i = 0; i < input.features.size(); ++i) {
        if (used[i]) {
            input.features[i].polygons = std::move(accepted[i]);
            out.originals.push_back(input.features[i]);
        } else if (!accepted[i].empty()) {
            error = originalsPath + " " + input.features[i].name + " (input feature " + std::to_string(input.features[i].id) +
                    ") is a valid polygon, but no aggregate of " + L + " covers it; give the file `aggrelod aggregate2d` "
                    "read with the GeoJSON it wrote";
            return false;
        } else {
            input.features[i].polygons.clear();
        }
    }
    size_t dropped = 0;
    for (const Diagnostic& d : checks) {
        if (d.severity == Diagnostic::Severity::Note) continue;
        if (++dropped <= 3) out.notes.push_back(originalsPath + " " + d.object + ": " + d.message + " (as in aggregate2d; planning uses the polygons it keeps)");
    }
    if (dropped > 3)
        out.notes.push_back(originalsPath + ": " + std::to_string(dropped - 3) + " more input problems (aggregate2d lists them all)");

    // Each aggregate contains its sources.
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (const Feature2D& f : out.originals)
        for (const Polygon2D& p : f.polygons)
            for (size_t i = 0; i + 1 < p.exterior.size(); i += 2)
                for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], p.exterior[i + k]), hi[k] = std::max(hi[k], p.exterior[i + k]);
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], 1e-300});
    const double tolerance = 1e-9 * extent;
    for (const Aggregate2DOutput::Level& level : out.levels)
        for (const LevelAggregateRecord& r : level.aggregates) {
            std::vector<const Polygon2D*> inner, outer;
            for (const Polygon2D& p : r.polygons) outer.push_back(&p);
            for (uint32_t s : r.sources)
                for (const Polygon2D& p : input.features[byId[s]].polygons) inner.push_back(&p);
            const Containment2D all = checkContainment2D(inner, outer, tolerance);
            if (all.contained) continue;
            // Name the source that is not contained (the first one, alone).
            for (uint32_t s : r.sources) {
                const Feature2D& f = input.features[byId[s]];
                std::vector<const Polygon2D*> one;
                for (const Polygon2D& p : f.polygons) one.push_back(&p);
                const Containment2D c = checkContainment2D(one, outer, tolerance);
                if (c.contained) continue;
                error = L + ": " + aggregateName(r) + " does not contain input feature " + std::to_string(s) + " (" +
                        originalsPath + " " + f.name + "): " + c.why +
                        "; refused, since a path planned on this level could then hit the original";
                return false;
            }
            error = L + ": " + aggregateName(r) + " does not contain the union of its sources: " + all.why +
                    "; refused, since a path planned on this level could then hit an original";
            return false;
        }

    // The link table: one row per source of every aggregate, nothing else.
    if (!linksPath.empty()) {
        std::vector<LinkRow> rows;
        if (!readLinksCsvFile(linksPath, rows, error)) return false;
        std::map<std::pair<int, int>, const LevelAggregateRecord*> aggregates;
        for (const Aggregate2DOutput::Level& level : out.levels)
            for (const LevelAggregateRecord& r : level.aggregates) aggregates[{r.level, r.aggregate}] = &r;
        std::set<std::pair<int, uint32_t>> rowSeen;
        const std::string mismatch = "; the link table does not belong to " + L;
        for (const LinkRow& row : rows) {
            const std::string where = linksPath + " line " + std::to_string(row.line) + ": ";
            if (row.level >= levelCount) {
                error = where + "level " + std::to_string(row.level) + ", but " + L + " has levels 0.." +
                        std::to_string(levelCount - 1) + mismatch;
                return false;
            }
            const auto it = aggregates.find({row.level, row.output});
            if (it == aggregates.end()) {
                error = where + "aggregate " + std::to_string(row.output) + " of level " + std::to_string(row.level) +
                        ", which " + L + " does not have" + mismatch;
                return false;
            }
            const LevelAggregateRecord& r = *it->second;
            if (row.delta != r.delta && std::fabs(row.delta - r.delta) > 1e-12 * std::max(1.0, std::fabs(r.delta))) {
                error = where + "delta " + number(row.delta) + " for level " + std::to_string(row.level) + ", but " + L +
                        " has delta " + number(r.delta) + mismatch;
                return false;
            }
            if (std::find(r.sources.begin(), r.sources.end(), row.input) == r.sources.end()) {
                std::string there = "in no aggregate of that level";
                for (const LevelAggregateRecord& other : out.levels[size_t(row.level)].aggregates)
                    if (std::find(other.sources.begin(), other.sources.end(), row.input) != other.sources.end())
                        there = "in " + aggregateName(other);
                error = where + "input feature " + std::to_string(row.input) + " in aggregate " + std::to_string(row.output) +
                        " of level " + std::to_string(row.level) + ", but " + L + " has it " + there + mismatch;
                return false;
            }
            if (!rowSeen.insert({row.level, row.input}).second) {
                error = where + "a second row for input feature " + std::to_string(row.input) + " at level " +
                        std::to_string(row.level) + mismatch;
                return false;
            }
        }
        for (const auto& [key, r] : aggregates)
            for (uint32_t s : r->sources)
                if (!rowSeen.count({key.first, s})) {
                    error = linksPath + ": no row for input feature " + std::to_string(s) + " at level " +
                            std::to_string(key.first) + " (" + aggregateName(*r) + ")" + mismatch;
                    return false;
                }
        out.linkRows = rows.size();
    }
    return true;
}

}  // namespace aggrelod::io
