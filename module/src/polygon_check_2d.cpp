// SPDX-License-Identifier: AGPL-3.0-or-later
// Input checks for 2D polygons and detection of touching / overlapping polygons.
// Segment pairs are found with a uniform grid (each pair tested once, in the cell holding
// the lower-left corner of their boxes' overlap), so the check is near-linear.
#include "polygon_check_2d.h"

#include "radix_sort.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace aggrelod::detail {
namespace {

std::string formatPoint(double x, double y) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "(%.10g, %.10g)", x, y);
    return buf;
}

std::string ringLabel(size_t polygon, size_t polygonCount, int hole) {
    std::string s;
    if (polygonCount > 1) s += "polygon " + std::to_string(polygon + 1) + ", ";
    s += hole < 0 ? std::string("exterior ring") : "hole " + std::to_string(hole + 1);
    return s;
}

struct Segment {
    double ax, ay, bx, by;
    uint32_t part;      // index into CheckedPolygons::parts
    uint32_t ring;      // global ring index
    uint32_t index;     // segment index within its ring
    uint32_t ringSize;  // segments in the ring
};

double orient(double ax, double ay, double bx, double by, double cx, double cy) {
    const double d = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax);
    // Treat a result within rounding of zero as collinear (conservative: counts as touching).
    const double scale = (std::fabs(bx - ax) + std::fabs(by - ay)) * (std::fabs(cx - ax) + std::fabs(cy - ay));
    return std::fabs(d) <= 1e-14 * scale ? 0.0 : d;
}

bool onSegment(double ax, double ay, double bx, double by, double px, double py) {
    return std::min(ax, bx) <= px && px <= std::max(ax, bx) && std::min(ay, by) <= py && py <= std::max(ay, by);
}

enum class Contact { None, Touch, Cross, Overlap };

// How two segments meet; `where` receives a point of contact.
Contact contact(const Segment& s, const Segment& t, double& wx, double& wy) {
    const double o1 = orient(s.ax, s.ay, s.bx, s.by, t.ax, t.ay);
    const double o2 = orient(s.ax, s.ay, s.bx, s.by, t.bx, t.by);
    const double o3 = orient(t.ax, t.ay, t.bx, t.by, s.ax, s.ay);
    const double o4 = orient(t.ax, t.ay, t.bx, t.by, s.bx, s.by);
    if (o1 == 0 && o2 == 0) {
        // Collinear: overlap of positive length, a shared point, or nothing.
        const bool useX = std::fabs(s.bx - s.ax) >= std::fabs(s.by - s.ay);
        double s0 = useX ? s.ax : s.ay, s1 = useX ? s.bx : s.by;
        double t0 = useX ? t.ax : t.ay, t1 = useX ? t.bx : t.by;
        if (s0 > s1) std::swap(s0, s1);
        if (t0 > t1) std::swap(t0, t1);
        const double lo = std::max(s0, t0), hi = std::min(s1, t1);
        if (lo > hi) return Contact::None;
        wx = onSegment(s.ax, s.ay, s.bx, s.by, t.ax, t.ay) ? t.ax : s.ax;
        wy = onSegment(s.ax, s.ay, s.bx, s.by, t.ax, t.ay) ? t.ay : s.ay;
        return lo < hi ? Contact::Overlap : Contact::Touch;
    }
    if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0))) {
        const double t0 = o3 / (o3 - o4);
        wx = s.ax + t0 * (s.bx - s.ax);
        wy = s.ay + t0 * (s.by - s.ay);
        return Contact::Cross;
    }
    if (o1 == 0 && onSegment(s.ax, s.ay, s.bx, s.by, t.ax, t.ay)) { wx = t.ax; wy = t.ay; return Contact::Touch; }
    if (o2 == 0 && onSegment(s.ax, s.ay, s.bx, s.by, t.bx, t.by)) { wx = t.bx; wy = t.by; return Contact::Touch; }
    if (o3 == 0 && onSegment(t.ax, t.ay, t.bx, t.by, s.ax, s.ay)) { wx = s.ax; wy = s.ay; return Contact::Touch; }
    if (o4 == 0 && onSegment(t.ax, t.ay, t.bx, t.by, s.bx, s.by)) { wx = s.bx; wy = s.by; return Contact::Touch; }
    return Contact::None;
}

// Cleans one ring: checks finiteness, drops a closing duplicate and repeated vertices.
bool cleanRing(const std::vector<double>& in, std::vector<double>& out, std::string& problem) {
    out.clear();
    if (in.size() % 2 != 0) {
        problem = "odd number of coordinates";
        return false;
    }
    for (size_t i = 0; i < in.size(); i += 2) {
        if (!std::isfinite(in[i]) || !std::isfinite(in[i + 1])) {
            problem = "coordinate " + std::to_string(i / 2 + 1) + " is not a finite number (NaN or infinite)";
            return false;
        }
        if (out.size() >= 2 && out[out.size() - 2] == in[i] && out[out.size() - 1] == in[i + 1]) continue;
        out.push_back(in[i]);
        out.push_back(in[i + 1]);
    }
    while (out.size() >= 4 && out[0] == out[out.size() - 2] && out[1] == out[out.size() - 1]) out.resize(out.size() - 2);
    if (out.size() < 6) {
        problem = "fewer than 3 distinct vertices";
        return false;
    }
    if (ringSignedArea(out) == 0) {
        problem = "zero area (all vertices on one line)";
        return false;
    }
    return true;
}

void orientRing(std::vector<double>& ring, bool counterClockwise) {
    if ((ringSignedArea(ring) > 0) == counterClockwise) return;
    const size_t n = ring.size() / 2;
    for (size_t i = 0; i < n / 2; ++i) {
        std::swap(ring[2 * i], ring[2 * (n - 1 - i)]);
        std::swap(ring[2 * i + 1], ring[2 * (n - 1 - i) + 1]);
    }
}

bool pointInRing(const std::vector<double>& ring, double px, double py) {
    bool inside = false;
    const size_t n = ring.size() / 2;
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
        const double xi = ring[2 * i], yi = ring[2 * i + 1], xj = ring[2 * j], yj = ring[2 * j + 1];
        if ((yi > py) != (yj > py) && px < (xj - xi) * (py - yi) / (yj - yi) + xi) inside = !inside;
    }
    return inside;
}

}  // namespace

double ringSignedArea(const std::vector<double>& ring) {
    const size_t n = ring.size() / 2;
    if (n < 3) return 0;
    // Relative to the first vertex, for precision far from the origin.
    double sum = 0;
    const double x0 = ring[0], y0 = ring[1];
    for (size_t i = 1; i + 1 < n; ++i)
        sum += (ring[2 * i] - x0) * (ring[2 * i + 3] - y0) - (ring[2 * i + 2] - x0) * (ring[2 * i + 1] - y0);
    return 0.5 * sum;
}

void sortGridEntries(std::vector<std::pair<long long, uint32_t>>& entries, size_t cellCount) {
    if (cellCount > 4 * entries.size() + 4096) {
        std::sort(entries.begin(), entries.end());
        return;
    }
    std::vector<uint32_t> start;
    std::vector<std::pair<long long, uint32_t>> sorted;
    countingSortByBucket(entries, cellCount, [](const std::pair<long long, uint32_t>& e) { return e.first; }, start, sorted);
    entries = std::move(sorted);
}

double ringLength(const std::vector<double>& ring) {
    const size_t n = ring.size() / 2;
    double len = 0;
    for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        const double dx = ring[2 * j] - ring[2 * i], dy = ring[2 * j + 1] - ring[2 * i + 1];
        len += std::sqrt(dx * dx + dy * dy);
    }
    return len;
}

void cleanPolygons(const std::vector<Feature2D>& features, CheckedPolygons& out, std::vector<Diagnostic>& diagnostics,
                   PolygonCheckProgress& progress) {
    out = CheckedPolygons{};
    out.featureAccepted.assign(features.size(), 0);
    progress = PolygonCheckProgress{};
    // 1. Per ring: finite, >= 3 distinct vertices, non-zero area; orientation normalised.
    // A bad polygon of a multipolygon is dropped (warning); a feature left without polygons
    // is skipped (error). A degenerate hole is dropped (warning).
    std::vector<uint32_t>& partIndexInFeature = progress.partIndexInFeature;
    std::vector<std::string>& droppedParts = progress.droppedParts;  // first problem, for the error message
    droppedParts.assign(features.size(), {});
    auto warn = [&](size_t f, const std::string& message) {
        diagnostics.push_back({Diagnostic::Severity::Warning, features[f].name, message});
    };
    for (size_t f = 0; f < features.size(); ++f) {
        const Feature2D& feature = features[f];
        const size_t count = feature.polygons.size();
        for (size_t p = 0; p < count; ++p) {
            Polygon2D clean;
            std::string problem;
            if (!cleanRing(feature.polygons[p].exterior, clean.exterior, problem)) {
                const std::string message = ringLabel(p, count, -1) + ": " + problem;
                if (count > 1) warn(f, message + "; polygon " + std::to_string(p + 1) + " dropped");
                if (droppedParts[f].empty()) droppedParts[f] = message;
                continue;
            }
            orientRing(clean.exterior, true);
            bool ok = true;
            for (size_t h = 0; h < feature.polygons[p].holes.size(); ++h) {
                std::vector<double> ring;
                if (!cleanRing(feature.polygons[p].holes[h], ring, problem)) {
                    const std::string message = ringLabel(p, count, static_cast<int>(h)) + ": " + problem;
                    if (problem.find("finite") != std::string::npos) {  // NaN: the polygon is unusable
                        if (count > 1) warn(f, message + "; polygon " + std::to_string(p + 1) + " dropped");
                        if (droppedParts[f].empty()) droppedParts[f] = message;
                        ok = false;
                        break;
                    }
                    warn(f, message + "; hole dropped");
                    continue;
                }
                orientRing(ring, false);
                clean.holes.push_back(std::move(ring));
            }
            if (!ok) continue;
            out.parts.push_back(std::move(clean));
            out.partFeature.push_back(static_cast<uint32_t>(f));
            partIndexInFeature.push_back(static_cast<uint32_t>(p));
        }
    }
}

void checkPolygonContacts(const std::vector<Feature2D>& features, CheckedPolygons& out,
                          std::vector<Diagnostic>& diagnostics, PolygonCheckProgress& progress) {
    const std::vector<uint32_t>& partIndexInFeature = progress.partIndexInFeature;
    std::vector<std::string>& droppedParts = progress.droppedParts;
    auto warn = [&](size_t f, const std::string& message) {
        diagnostics.push_back({Diagnostic::Severity::Warning, features[f].name, message});
    };
    auto reject = [&](size_t f, const std::string& message) {
        diagnostics.push_back({Diagnostic::Severity::Error, features[f].name, message + "; feature skipped"});
    };
    // 2. Segments of every ring, into a grid.
    std::vector<Segment> segments;
    std::vector<std::pair<uint32_t, int>> ringOwner;  // global ring -> (part, hole index or -1)
    for (uint32_t p = 0; p < out.parts.size(); ++p) {
        const Polygon2D& poly = out.parts[p];
        for (int h = -1; h < static_cast<int>(poly.holes.size()); ++h) {
            const std::vector<double>& ring = h < 0 ? poly.exterior : poly.holes[h];
            const uint32_t n = static_cast<uint32_t>(ring.size() / 2);
            const uint32_t r = static_cast<uint32_t>(ringOwner.size());
            ringOwner.emplace_back(p, h);
            for (uint32_t i = 0; i < n; ++i) {
                const uint32_t j = (i + 1) % n;
                segments.push_back({ring[2 * i], ring[2 * i + 1], ring[2 * j], ring[2 * j + 1], p, r, i, n});
            }
        }
    }
    // 3. Contacts between segments. Problems per polygon are collected, the first one reported.
    std::vector<std::string> partProblem(out.parts.size());
    std::vector<std::pair<uint32_t, uint32_t>> touching;
    if (!segments.empty()) {
        double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY, sumLen = 0;
        for (const Segment& s : segments) {
            minX = std::min({minX, s.ax, s.bx});
            maxX = std::max({maxX, s.ax, s.bx});
            minY = std::min({minY, s.ay, s.by});
            maxY = std::max({maxY, s.ay, s.by});
            sumLen += std::hypot(s.bx - s.ax, s.by - s.ay);
        }
        // Cell about twice the mean segment length, at most ~4 cells per segment overall.
        double cell = 2 * sumLen / static_cast<double>(segments.size());
        const double spanX = maxX - minX, spanY = maxY - minY;
        const double minCell = std::sqrt(std::max(spanX * spanY, 1e-300) / (4.0 * static_cast<double>(segments.size())));
        cell = std::max({cell, minCell, 1e-300});
        const long long nx = std::min<long long>(static_cast<long long>(spanX / cell) + 1, 1 << 20);
        const long long ny = std::min<long long>(static_cast<long long>(spanY / cell) + 1, 1 << 20);
        auto cellOf = [&](double x, double y) {
            long long cx = std::clamp<long long>(static_cast<long long>((x - minX) / cell), 0, nx - 1);
            long long cy = std::clamp<long long>(static_cast<long long>((y - minY) / cell), 0, ny - 1);
            return std::pair<long long, long long>(cx, cy);
        };
        std::vector<std::pair<long long, uint32_t>> entries;  // (cell key, segment)
        entries.reserve(segments.size() * 2);
        for (uint32_t i = 0; i < segments.size(); ++i) {
            const Segment& s = segments[i];
            auto [x0, y0] = cellOf(std::min(s.ax, s.bx), std::min(s.ay, s.by));
            auto [x1, y1] = cellOf(std::max(s.ax, s.bx), std::max(s.ay, s.by));
            for (long long cy = y0; cy <= y1; ++cy)
                for (long long cx = x0; cx <= x1; ++cx) entries.emplace_back(cy * nx + cx, i);
        }
        sortGridEntries(entries, static_cast<size_t>(nx * ny));

        for (size_t b = 0; b < entries.size();) {
            size_t e = b;
            while (e < entries.size() && entries[e].first == entries[b].first) ++e;
            const long long key = entries[b].first;
            for (size_t i = b; i < e; ++i) {
                for (size_t j = i + 1; j < e; ++j) {
                    const Segment& s = segments[entries[i].second];
                    const Segment& t = segments[entries[j].second];
                    // Test the pair only in the cell of the lower-left corner of the boxes' overlap.
                    const double ox = std::max(std::min(s.ax, s.bx), std::min(t.ax, t.bx));
                    const double oy = std::max(std::min(s.ay, s.by), std::min(t.ay, t.by));
                    if (ox > std::min(std::max(s.ax, s.bx), std::max(t.ax, t.bx)) ||
                        oy > std::min(std::max(s.ay, s.by), std::max(t.ay, t.by)))
                        continue;
                    auto [cx, cy] = cellOf(ox, oy);
                    if (cy * nx + cx != key) continue;
                    const bool samePart = s.part == t.part;
                    if (samePart && !partProblem[s.part].empty()) continue;
                    double wx = 0, wy = 0;
                    const Contact c = contact(s, t, wx, wy);
                    if (c == Contact::None) continue;
                    if (!samePart) {
                        touching.emplace_back(std::min(s.part, t.part), std::max(s.part, t.part));
                        continue;
                    }
                    const uint32_t feature = out.partFeature[s.part];
                    auto label = [&](const Segment& g) {
                        const auto [part, hole] = ringOwner[g.ring];
                        return ringLabel(partIndexInFeature[part], features[feature].polygons.size(), hole);
                    };
                    if (s.ring == t.ring) {
                        const bool adjacent = (s.index + 1) % s.ringSize == t.index || (t.index + 1) % t.ringSize == s.index;
                        if (adjacent && c == Contact::Touch) continue;  // shared vertex
                        partProblem[s.part] = label(s) + ": self-intersecting ring " +
                                                  (c == Contact::Overlap && adjacent ? "(the ring turns back on itself) " : "") +
                                                  "at " + formatPoint(wx, wy);
                    } else if (c != Contact::Touch) {
                        partProblem[s.part] = label(s) + " and " + label(t) + " cross at " + formatPoint(wx, wy);
                    }
                }
            }
            b = e;
        }
    }

    // Holes must lie inside their exterior (checked at a hole edge midpoint; crossings are found above).
    for (uint32_t p = 0; p < out.parts.size(); ++p) {
        if (!partProblem[p].empty()) continue;
        const Polygon2D& poly = out.parts[p];
        for (size_t h = 0; h < poly.holes.size(); ++h) {
            const std::vector<double>& hole = poly.holes[h];
            const double mx = 0.5 * (hole[0] + hole[2]), my = 0.5 * (hole[1] + hole[3]);
            if (!pointInRing(poly.exterior, mx, my)) {
                partProblem[p] = ringLabel(partIndexInFeature[p], features[out.partFeature[p]].polygons.size(),
                                           static_cast<int>(h)) + " lies outside its exterior ring";
                break;
            }
        }
    }
    // Drop bad polygons; skip features left with none.
    std::vector<uint32_t> newIndex(out.parts.size(), UINT32_MAX);
    std::vector<Polygon2D> parts;
    std::vector<uint32_t> partFeature;
    std::vector<uint32_t> kept(features.size(), 0);
    for (uint32_t p = 0; p < out.parts.size(); ++p) {
        const uint32_t f = out.partFeature[p];
        if (!partProblem[p].empty()) {
            if (features[f].polygons.size() > 1)
                warn(f, partProblem[p] + "; polygon " + std::to_string(partIndexInFeature[p] + 1) + " dropped");
            if (droppedParts[f].empty()) droppedParts[f] = partProblem[p];
            continue;
        }
        newIndex[p] = static_cast<uint32_t>(parts.size());
        parts.push_back(std::move(out.parts[p]));
        partFeature.push_back(f);
        kept[f]++;
    }
    out.parts = std::move(parts);
    out.partFeature = std::move(partFeature);
    for (size_t f = 0; f < features.size(); ++f) {
        out.featureAccepted[f] = kept[f] > 0;
        if (kept[f] > 0) continue;
        if (features[f].polygons.empty()) reject(f, "empty geometry (no polygon)");
        else if (features[f].polygons.size() == 1) reject(f, droppedParts[f]);
        else reject(f, "no usable polygon left (first problem: " + droppedParts[f] + ")");
    }
    for (auto [a, b] : touching)
        if (newIndex[a] != UINT32_MAX && newIndex[b] != UINT32_MAX) out.touchingParts.emplace_back(newIndex[a], newIndex[b]);
    std::sort(out.touchingParts.begin(), out.touchingParts.end());
    out.touchingParts.erase(std::unique(out.touchingParts.begin(), out.touchingParts.end()), out.touchingParts.end());
}

void checkPolygons(const std::vector<Feature2D>& features, CheckedPolygons& out,
                   std::vector<Diagnostic>& diagnostics) {
    PolygonCheckProgress progress;
    cleanPolygons(features, out, diagnostics, progress);
    checkPolygonContacts(features, out, diagnostics, progress);
}

}  // namespace aggrelod::detail
