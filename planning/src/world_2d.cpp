// SPDX-License-Identifier: AGPL-3.0-or-later
// The 2D planning world (paper Section 4.3, in the plane): a disc agent against the polygons of
// one level. Obstacle edges are indexed in a uniform grid shared by all levels; each level also
// stores the winding number of its polygons at every cell centre (a scanline per row), so that
// "is p inside a polygon" costs only the edges of p's cell: the winding number at p is the one
// at the centre plus the signed crossings of the short segment from the centre to p.
#include <aggrelod/planning.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace aggrelod::planning {
namespace {

struct Edge {
    double ax, ay, bx, by;  // oriented: interior on the left (exteriors CCW, holes CW)
};

double orient(double ax, double ay, double bx, double by, double px, double py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

double pointSegmentDistance2(double px, double py, const Edge& e) {
    const double dx = e.bx - e.ax, dy = e.by - e.ay;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((px - e.ax) * dx + (py - e.ay) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const double qx = e.ax + t * dx - px, qy = e.ay + t * dy - py;
    return qx * qx + qy * qy;
}

bool segmentsCross(double ax, double ay, double bx, double by, const Edge& e) {
    const double d1 = orient(e.ax, e.ay, e.bx, e.by, ax, ay), d2 = orient(e.ax, e.ay, e.bx, e.by, bx, by);
    const double d3 = orient(ax, ay, bx, by, e.ax, e.ay), d4 = orient(ax, ay, bx, by, e.bx, e.by);
    return ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0;
}

// Squared distance between segment a-b and an edge (0 when they cross).
double segmentSegmentDistance2(double ax, double ay, double bx, double by, const Edge& e) {
    if (segmentsCross(ax, ay, bx, by, e)) return 0;
    const Edge s{ax, ay, bx, by};
    return std::min(std::min(pointSegmentDistance2(ax, ay, e), pointSegmentDistance2(bx, by, e)),
                    std::min(pointSegmentDistance2(e.ax, e.ay, s), pointSegmentDistance2(e.bx, e.by, s)));
}

double signedArea(const std::vector<double>& ring) {
    const size_t n = ring.size() / 2;
    double a = 0;
    for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        a += ring[2 * i] * ring[2 * j + 1] - ring[2 * j] * ring[2 * i + 1];
    }
    return 0.5 * a;
}

void appendEdges(const std::vector<PlanPolygon>& polygons, std::vector<Edge>& out) {
    for (const PlanPolygon& polygon : polygons) {
        for (size_t r = 0; r < polygon.rings.size(); ++r) {
            const std::vector<double>& ring = polygon.rings[r];
            const size_t n = ring.size() / 2;
            if (n < 3) continue;
            const bool ccw = signedArea(ring) > 0;
            const bool wantCcw = r == 0;
            for (size_t i = 0; i < n; ++i) {
                const size_t j = (i + 1) % n;
                Edge e{ring[2 * i], ring[2 * i + 1], ring[2 * j], ring[2 * j + 1]};
                if (ccw != wantCcw) e = {e.bx, e.by, e.ax, e.ay};
                if (e.ax == e.bx && e.ay == e.by) continue;
                out.push_back(e);
            }
        }
    }
}

class World2D final : public PlanningWorld {
public:
    World2D(const std::vector<PlanPolygon>& originals, const std::vector<std::vector<PlanPolygon>>& levels,
            const std::vector<double>& deltas, double radius)
        : radius_(radius), deltas_(deltas) {
        if (!(radius > 0)) throw std::invalid_argument("the agent radius must be > 0");
        std::vector<std::vector<Edge>> edges(levels.size() + 1);
        appendEdges(originals, edges[0]);
        if (edges[0].empty()) throw std::invalid_argument("no original polygons to plan around");
        for (size_t k = 0; k < levels.size(); ++k) appendEdges(levels[k], edges[k + 1]);
        deltas_.insert(deltas_.begin(), 0.0);
        deltas_.resize(edges.size(), 0.0);
        lo_ = {INFINITY, INFINITY, 0};
        hi_ = {-INFINITY, -INFINITY, 0};
        for (const Edge& e : edges[0]) {
            lo_[0] = std::min({lo_[0], e.ax, e.bx});
            lo_[1] = std::min({lo_[1], e.ay, e.by});
            hi_[0] = std::max({hi_[0], e.ax, e.bx});
            hi_[1] = std::max({hi_[1], e.ay, e.by});
        }
        // The grid spans every level's edges (aggregates stay inside the originals' hull, but
        // be safe), with about one cell per original edge.
        gridLo_[0] = lo_[0], gridLo_[1] = lo_[1];
        double gridHi[2] = {hi_[0], hi_[1]};
        for (const auto& level : edges)
            for (const Edge& e : level) {
                gridLo_[0] = std::min({gridLo_[0], e.ax, e.bx});
                gridLo_[1] = std::min({gridLo_[1], e.ay, e.by});
                gridHi[0] = std::max({gridHi[0], e.ax, e.bx});
                gridHi[1] = std::max({gridHi[1], e.ay, e.by});
            }
        const double w = std::max(gridHi[0] - gridLo_[0], 1e-9), h = std::max(gridHi[1] - gridLo_[1], 1e-9);
        const double cells = std::clamp(double(edges[0].size()), 64.0, double(1 << 20));
        cell_ = std::sqrt(w * h / cells);
        cell_ = std::max(cell_, std::max(w, h) / 4096.0);
        nx_ = std::max(1, int(std::ceil(w / cell_)));
        ny_ = std::max(1, int(std::ceil(h / cell_)));
        for (auto& level : edges) levels_.push_back(buildLevel(std::move(level)));
    }

    int dimension() const override { return 2; }
    int levelCount() const override { return int(levels_.size()); }
    double levelDelta(int level) const override { return deltas_[size_t(level)]; }
    int levelNumber(int level) const override { return level - 1; }
    Point boundsMin() const override { return lo_; }
    Point boundsMax() const override { return hi_; }
    double radius() const override { return radius_; }

    bool stateFree(int level, const Point& p) const override {
        if (!(p[0] >= lo_[0] && p[0] <= hi_[0] && p[1] >= lo_[1] && p[1] <= hi_[1])) return false;
        const Level& L = levels_[size_t(level)];
        const double r2 = radius_ * radius_;
        int x0, y0, x1, y1;
        cellRange(p[0] - radius_, p[1] - radius_, p[0] + radius_, p[1] + radius_, x0, y0, x1, y1);
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x)
                for (uint32_t i = L.start[cellIndex(x, y)]; i < L.start[cellIndex(x, y) + 1]; ++i)
                    if (pointSegmentDistance2(p[0], p[1], L.edges[L.items[i]]) <= r2) return false;
        return winding(L, p[0], p[1]) == 0;
    }

    bool motionFree(int level, const Point& a, const Point& b) const override {
        const Level& L = levels_[size_t(level)];
        const double r2 = radius_ * radius_;
        int x0, y0, x1, y1;
        cellRange(std::min(a[0], b[0]) - radius_, std::min(a[1], b[1]) - radius_, std::max(a[0], b[0]) + radius_,
                  std::max(a[1], b[1]) + radius_, x0, y0, x1, y1);
        // Cells far from the segment (more than radius + half a cell diagonal) hold no edge
        // within reach; skip them.
        const Edge s{a[0], a[1], b[0], b[1]};
        const double reach = radius_ + 0.7072 * cell_;
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x) {
                const double cx = gridLo_[0] + (x + 0.5) * cell_, cy = gridLo_[1] + (y + 0.5) * cell_;
                if (pointSegmentDistance2(cx, cy, s) > reach * reach) continue;
                for (uint32_t i = L.start[cellIndex(x, y)]; i < L.start[cellIndex(x, y) + 1]; ++i)
                    if (segmentSegmentDistance2(a[0], a[1], b[0], b[1], L.edges[L.items[i]]) <= r2) return false;
            }
        return true;
    }

private:
    struct Level {
        std::vector<Edge> edges;
        std::vector<uint32_t> start;  // per cell, into items (CSR), nx*ny + 1
        std::vector<uint32_t> items;  // edge indices
        std::vector<int> centreWinding;  // per cell
    };

    size_t cellIndex(int x, int y) const { return size_t(y) * size_t(nx_) + size_t(x); }

    void cellRange(double minX, double minY, double maxX, double maxY, int& x0, int& y0, int& x1, int& y1) const {
        auto clampCell = [](double v, int n) { return int(std::clamp(std::floor(v), 0.0, double(n - 1))); };
        x0 = clampCell((minX - gridLo_[0]) / cell_, nx_);
        x1 = clampCell((maxX - gridLo_[0]) / cell_, nx_);
        y0 = clampCell((minY - gridLo_[1]) / cell_, ny_);
        y1 = clampCell((maxY - gridLo_[1]) / cell_, ny_);
    }

    Level buildLevel(std::vector<Edge> edges) const {
        Level L;
        L.edges = std::move(edges);
        const size_t cells = size_t(nx_) * size_t(ny_);
        std::vector<uint32_t> count(cells + 1, 0);
        auto forCells = [&](const Edge& e, auto&& f) {
            int x0, y0, x1, y1;
            cellRange(std::min(e.ax, e.bx), std::min(e.ay, e.by), std::max(e.ax, e.bx), std::max(e.ay, e.by), x0, y0, x1, y1);
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    // Keep only cells the edge can meet (its distance to the cell centre at most
                    // half the cell diagonal).
                    const double cx = gridLo_[0] + (x + 0.5) * cell_, cy = gridLo_[1] + (y + 0.5) * cell_;
                    if (pointSegmentDistance2(cx, cy, e) <= 0.5001 * cell_ * cell_) f(cellIndex(x, y));
                }
        };
        for (const Edge& e : L.edges) forCells(e, [&](size_t c) { ++count[c + 1]; });
        for (size_t c = 0; c < cells; ++c) count[c + 1] += count[c];
        L.start = count;
        L.items.resize(count[cells]);
        std::vector<uint32_t> fill(count.begin(), count.end() - 1);
        for (uint32_t i = 0; i < L.edges.size(); ++i) forCells(L.edges[i], [&](size_t c) { L.items[fill[c]++] = i; });
        // Winding numbers at the cell centres, one scanline per row: an edge crossing the row's
        // centre line (half-open in y) counts +1 going up, -1 going down, for the centres to
        // its left.
        L.centreWinding.assign(cells, 0);
        std::vector<std::vector<std::pair<double, int>>> rows(static_cast<size_t>(ny_));
        for (const Edge& e : L.edges) {
            if (e.ay == e.by) continue;
            const double ylo = std::min(e.ay, e.by), yhi = std::max(e.ay, e.by);
            const int r0 = std::max(0, int(std::ceil((ylo - gridLo_[1]) / cell_ - 0.5)) - 1);
            const int r1 = std::min(ny_ - 1, int(std::floor((yhi - gridLo_[1]) / cell_ - 0.5)) + 1);
            for (int r = r0; r <= r1; ++r) {
                const double y = gridLo_[1] + (r + 0.5) * cell_;
                if (!(y >= ylo && y < yhi)) continue;
                const double t = (y - e.ay) / (e.by - e.ay);
                rows[size_t(r)].push_back({e.ax + t * (e.bx - e.ax), e.by > e.ay ? 1 : -1});
            }
        }
        for (int r = 0; r < ny_; ++r) {
            auto& crossings = rows[size_t(r)];
            std::sort(crossings.begin(), crossings.end());
            int w = 0;
            size_t k = crossings.size();
            for (int x = nx_ - 1; x >= 0; --x) {
                const double cx = gridLo_[0] + (x + 0.5) * cell_;
                while (k > 0 && crossings[k - 1].first > cx) w += crossings[--k].second;
                L.centreWinding[cellIndex(x, r)] = w;
            }
        }
        return L;
    }

    // Winding number of the level's polygons at p (p inside the grid).
    int winding(const Level& L, double px, double py) const {
        int x0, y0, x1, y1;
        cellRange(px, py, px, py, x0, y0, x1, y1);
        const size_t c = cellIndex(x0, y0);
        const double cx = gridLo_[0] + (x0 + 0.5) * cell_, cy = gridLo_[1] + (y0 + 0.5) * cell_;
        int w = L.centreWinding[c];
        // Walking from the centre to p: entering an edge's left side (the interior) adds one.
        for (uint32_t i = L.start[c]; i < L.start[c + 1]; ++i) {
            const Edge& e = L.edges[L.items[i]];
            if (!segmentsCross(cx, cy, px, py, e)) continue;
            w += orient(e.ax, e.ay, e.bx, e.by, px, py) > 0 ? 1 : -1;
        }
        return w;
    }

    double radius_;
    std::vector<double> deltas_;
    Point lo_{}, hi_{};
    double gridLo_[2] = {0, 0};
    double cell_ = 1;
    int nx_ = 1, ny_ = 1;
    std::vector<Level> levels_;
};

}  // namespace

std::unique_ptr<PlanningWorld> makeWorld2D(const std::vector<PlanPolygon>& originals,
                                           const std::vector<std::vector<PlanPolygon>>& levels,
                                           const std::vector<double>& deltas, double radius) {
    return std::make_unique<World2D>(originals, levels, deltas, radius);
}

}  // namespace aggrelod::planning
