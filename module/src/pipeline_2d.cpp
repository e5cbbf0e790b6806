// SPDX-License-Identifier: AGPL-3.0-or-later
// The 2D pipeline (paper Sections 3.1-3.3 and 4.2; docs/design.md §2.1–2.5 in 2D):
// check input -> one constrained Delaunay triangulation -> inside/outside by winding ->
// models (touching / overlapping polygons merged) -> neighbourhood graph -> Kruskal
// dendrogram (shared with 3D) -> per level: sculpt, polygons, measures and baselines.
#include "free_space_2d.h"
#include "parallel_for.h"
#include "polygon_check_2d.h"
#include "sculpt_2d.h"
#include "steiner_2d.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/dendrogram.h>
#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <future>
#include <numeric>
#include <string>
#include <thread>
#include <tuple>

namespace aggrelod {

double circularity(double area, double perimeter) {
    return perimeter > 0 ? 4 * M_PI * area / (perimeter * perimeter) : 0;
}

Measures2D normalizedMeasures(const Measures2D& m, const Measures2D& o) {
    Measures2D r;
    r.area = o.area > 0 ? m.area / o.area : 0;
    r.perimeter = o.perimeter > 0 ? m.perimeter / o.perimeter : 0;
    r.circularity = o.circularity > 0 ? m.circularity / o.circularity : 0;
    return r;
}

namespace {
using namespace detail;
using Clock = std::chrono::steady_clock;

/// Input vertices as one array, with the ring structure needed to orient constraints.
struct InputVertices {
    std::vector<double> points;            // 2 * n
    std::vector<uint32_t> part;            // per vertex
    std::vector<uint32_t> ringStart, ringSize;  // per vertex: its ring's first vertex and size
    std::vector<std::pair<size_t, size_t>> segments;
    std::vector<char> shared;              // per vertex: another input vertex lies at the same place (setShared)
    std::vector<char> partTouches;         // per part: its boundary meets another part's
    // Uniform grid of the ring segments (segment i starts at vertex i), for finding the input
    // segments under a triangulation edge; segments spanning many cells go to `longSegments`.
    double gridX0 = 0, gridY0 = 0, gridCell = 1;
    long long gridNx = 1, gridNy = 1;
    std::vector<std::pair<long long, uint32_t>> gridEntries;  // (cell, segment), sorted
    std::vector<uint32_t> longSegments;

    size_t next(size_t v) const { return ringStart[v] + (v - ringStart[v] + 1) % ringSize[v]; }
    long long cellX(double px) const {
        return std::clamp<long long>(static_cast<long long>((px - gridX0) / gridCell), 0, gridNx - 1);
    }
    long long cellY(double py) const {
        return std::clamp<long long>(static_cast<long long>((py - gridY0) / gridCell), 0, gridNy - 1);
    }
    size_t prev(size_t v) const { return ringStart[v] + (v - ringStart[v] + ringSize[v] - 1) % ringSize[v]; }
    double x(size_t v) const { return points[2 * v]; }
    double y(size_t v) const { return points[2 * v + 1]; }
};

void buildSegmentGrid(InputVertices& in) {
    const size_t n = in.part.size();
    if (n == 0) return;
    double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY, sumLen = 0;
    for (size_t i = 0; i < n; ++i) {
        minX = std::min(minX, in.x(i));
        maxX = std::max(maxX, in.x(i));
        minY = std::min(minY, in.y(i));
        maxY = std::max(maxY, in.y(i));
        sumLen += std::hypot(in.x(in.next(i)) - in.x(i), in.y(in.next(i)) - in.y(i));
    }
    const double span = std::max(maxX - minX, maxY - minY);
    double cell = std::max(2 * sumLen / static_cast<double>(n), span / 4096);
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
    in.gridX0 = minX;
    in.gridY0 = minY;
    in.gridCell = cell;
    in.gridNx = std::max<long long>(1, std::min<long long>(static_cast<long long>((maxX - minX) / cell) + 1, 1 << 20));
    in.gridNy = std::max<long long>(1, std::min<long long>(static_cast<long long>((maxY - minY) / cell) + 1, 1 << 20));
    in.gridEntries.clear();
    in.longSegments.clear();
    for (size_t i = 0; i < n; ++i) {
        const size_t j = in.next(i);
        const long long x0 = in.cellX(std::min(in.x(i), in.x(j))), x1 = in.cellX(std::max(in.x(i), in.x(j)));
        const long long y0 = in.cellY(std::min(in.y(i), in.y(j))), y1 = in.cellY(std::max(in.y(i), in.y(j)));
        if ((x1 - x0 + 1) * (y1 - y0 + 1) > 64) {
            in.longSegments.push_back(static_cast<uint32_t>(i));
            continue;
        }
        for (long long cy = y0; cy <= y1; ++cy)
            for (long long cx = x0; cx <= x1; ++cx) in.gridEntries.emplace_back(cy * in.gridNx + cx, static_cast<uint32_t>(i));
    }
    sortGridEntries(in.gridEntries, static_cast<size_t>(in.gridNx * in.gridNy));
}

// Winding number of all input rings around (px, py) (exteriors counter-clockwise, holes
// clockwise): the number of polygons containing the point. Linear in the vertex count; only
// for the rare faces the flood cannot reach.
int windingNumberAt(const InputVertices& in, double px, double py) {
    int w = 0;
    for (size_t a = 0; a < in.part.size(); ++a) {
        const size_t b = in.next(a);
        const double ay = in.y(a), by = in.y(b);
        const double side = (in.x(b) - in.x(a)) * (py - ay) - (px - in.x(a)) * (by - ay);
        if (ay <= py && by > py && side > 0) ++w;
        else if (ay > py && by <= py && side < 0) --w;
    }
    return w;
}

// Change of the winding count when crossing the triangulation edge u->v from its left side
// (the face) to its right: -1 per input ring running u->v (its interior is on the left),
// +1 per ring running v->u.
int windingChange(const InputVertices& in, const Triangulation2D& tri, int u, int v,
                  std::vector<std::tuple<size_t, int>>& found) {
    const double ux = tri.points[2 * u], uy = tri.points[2 * u + 1];
    const double vx = tri.points[2 * v], vy = tri.points[2 * v + 1];
    found.clear();  // (segment start vertex, sign)
    // Fast path: the edge is a whole input segment of a polygon whose boundary meets no other
    // (else another ring may run along the same edge, e.g. a shared border).
    const int iu = tri.vertexInput[u], iv = tri.vertexInput[v];
    if (iu >= 0 && iv >= 0 && !in.shared[iu] && !in.shared[iv] && !in.partTouches[in.part[iu]]) {
        if (in.next(static_cast<size_t>(iu)) == static_cast<size_t>(iv)) return -1;
        if (in.prev(static_cast<size_t>(iu)) == static_cast<size_t>(iv)) return +1;
    }
    // Every input segment under the edge's midpoint, collinear with it: -1 for a ring running
    // u->v (its interior is on the left, where the face is), +1 for one running v->u.
    const double mx = 0.5 * (ux + vx), my = 0.5 * (uy + vy);
    const double ex = vx - ux, ey = vy - uy;
    auto test = [&](uint32_t s) {
        const size_t a = s, b = in.next(s);
        const double dx = in.x(b) - in.x(a), dy = in.y(b) - in.y(a);
        const double len2 = dx * dx + dy * dy;
        const double px = mx - in.x(a), py = my - in.y(a);
        const double along = px * dx + py * dy;
        if (!(along > 0 && along < len2)) return;
        if (std::fabs(dx * py - dy * px) > 1e-9 * len2) return;  // midpoint off the segment
        if (std::fabs(dx * ey - dy * ex) > 1e-9 * std::sqrt(len2 * (ex * ex + ey * ey))) return;  // not along it
        found.emplace_back(s, dx * ex + dy * ey > 0 ? -1 : +1);
    };
    const long long key = in.cellY(my) * in.gridNx + in.cellX(mx);
    auto it = std::lower_bound(in.gridEntries.begin(), in.gridEntries.end(), std::make_pair(key, uint32_t{0}));
    for (; it != in.gridEntries.end() && it->first == key; ++it) test(it->second);
    for (uint32_t s : in.longSegments) test(s);
    int change = 0;
    for (auto& f : found) change += std::get<1>(f);
    return change;
}

std::string joinNames(const std::vector<Feature2D>& features, const std::vector<uint32_t>& ids) {
    std::string s;
    const size_t shown = std::min<size_t>(ids.size(), 6);
    for (size_t i = 0; i < shown; ++i) s += (i ? ", " : "") + features[ids[i]].name;
    if (ids.size() > shown) s += " and " + std::to_string(ids.size() - shown) + " more";
    return s;
}

double pointSegmentDistance(const double* p, const double* a, const double* b) {
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

/// Which model each part belongs to, and which parts touch others.
struct FreeSpaceModels {
    std::vector<int> partModel;
    std::vector<char> partTouches;  // touches or overlaps a part of another feature
};

/// Stage 3 on a triangulation of `in`: per face the winding number of the input rings (the
/// number of polygons containing it), by a flood from the outside of the hull that counts
/// the rings along each constrained edge it crosses.
std::vector<int> windingNumbers(const InputVertices& in, const Triangulation2D& tri, int threadCount) {
    const size_t faceCount = tri.faceCount();
    // 3. Inside / outside by winding count, flooding from the outside of the hull.
    std::vector<int> winding(faceCount, INT32_MIN);
    std::vector<std::tuple<size_t, int>> found;
    std::vector<int> queue;  // first in, first out: each face enters once
    queue.reserve(faceCount);
    size_t queueHead = 0;
    for (size_t f = 0; f < faceCount; ++f)
        for (int j = 0; j < 3; ++j)
            if (tri.neighbors[3 * f + j] < 0 && winding[f] == INT32_MIN) {
                const int u = tri.faces[3 * f + (j + 1) % 3], v = tri.faces[3 * f + (j + 2) % 3];
                winding[f] = tri.constrained[3 * f + j] ? -windingChange(in, tri, u, v, found) : 0;
                queue.push_back(static_cast<int>(f));
            }
    // A constrained edge between two Steiner points a rounding error apart (crossings of
    // nearly coincident rings) has no reliable direction: the flood does not cross it, and a
    // face reached only that way is counted directly (rings around its centroid).
    const double tiny = 1e-7 * in.gridCell;
    // Likewise a sliver face (area a rounding error) between two copies of one constraint
    // (coincident rings crossed by another ring give two nearly equal Steiner points): the
    // flood neither enters nor leaves it, since each copy would count the rings again.
    std::vector<char> sliver(faceCount, 0);
    const size_t faceBlocks = std::clamp<size_t>(faceCount / 8192, 1, 64);
    parallelFor(faceBlocks, threadCount, [&](size_t block) {
        for (size_t f = faceCount * block / faceBlocks; f < faceCount * (block + 1) / faceBlocks; ++f) {
            const int* v = &tri.faces[3 * f];
            auto P = [&](int k) { return &tri.points[2 * static_cast<size_t>(v[k])]; };
            const double area2 = std::fabs((P(1)[0] - P(0)[0]) * (P(2)[1] - P(0)[1]) - (P(2)[0] - P(0)[0]) * (P(1)[1] - P(0)[1]));
            double longest2 = 0;  // squared
            for (int k = 0; k < 3; ++k) {
                const double dx = P((k + 1) % 3)[0] - P(k)[0], dy = P((k + 1) % 3)[1] - P(k)[1];
                longest2 = std::max(longest2, dx * dx + dy * dy);
            }
            sliver[f] = area2 <= 1e-12 * longest2;
        }
    });
    auto unreliable = [&](int f, int j) {
        const int u = tri.faces[3 * f + (j + 1) % 3], v = tri.faces[3 * f + (j + 2) % 3];
        const int n = tri.neighbors[3 * f + j];
        if (!tri.constrained[3 * f + j]) return false;
        if (sliver[f] || (n >= 0 && sliver[n])) return true;
        return tri.vertexInput[u] < 0 && tri.vertexInput[v] < 0 &&
               std::hypot(tri.points[2 * v] - tri.points[2 * u], tri.points[2 * v + 1] - tri.points[2 * u + 1]) <= tiny;
    };
    while (queueHead < queue.size()) {
        const int f = queue[queueHead++];
        for (int j = 0; j < 3; ++j) {
            const int n = tri.neighbors[3 * f + j];
            if (n < 0 || winding[n] != INT32_MIN || unreliable(f, j)) continue;
            int w = winding[f];
            if (tri.constrained[3 * f + j])
                w += windingChange(in, tri, tri.faces[3 * f + (j + 1) % 3], tri.faces[3 * f + (j + 2) % 3], found);
            winding[n] = w;
            queue.push_back(n);
        }
    }
    for (size_t f = 0; f < faceCount; ++f) {
        if (winding[f] != INT32_MIN) continue;
        double cx = 0, cy = 0;
        for (int k = 0; k < 3; ++k) {
            cx += tri.points[2 * tri.faces[3 * f + k]] / 3;
            cy += tri.points[2 * tri.faces[3 * f + k] + 1] / 3;
        }
        winding[f] = windingNumberAt(in, cx, cy);
    }
    return winding;
}

/// Stages 4-5 on the triangulation in space.tri, given its windingNumbers(): models, voids, model pairs.
/// graphOnly: only what the dendrogram and the Steiner points need (models, pairs with their
/// shortest connection, edge lengths); no voids, per-pair length statistics, edge pairs or
/// model points (the pass before the Steiner points, whose result is replaced).
/// withModelPoints: fill space.modelPoints (read only by the convex hulls).
void buildFreeSpace(const InputVertices& in, const CheckedPolygons& checked, const std::vector<int>& winding,
                    FreeSpace2D& space, FreeSpaceModels& models, bool graphOnly, int threadCount,
                    bool withModelPoints = false) {
    const Triangulation2D& tri = space.tri;
    const size_t faceCount = tri.faceCount(), vertexCount = tri.vertexCount();
    const size_t faceBlocks = std::clamp<size_t>(faceCount / 8192, 1, 64);
    // Part of each vertex and of each interior face (parallel blocks, each writing its own slots).
    auto forBlocks = [&](size_t count, auto&& body) { parallelForEach(count, threadCount, body); };
    std::vector<int> vertexPart(vertexCount, -1);
    forBlocks(vertexCount, [&](size_t v) {
        if (tri.vertexInput[v] >= 0) vertexPart[v] = static_cast<int>(in.part[tri.vertexInput[v]]);
    });
    // The part of each interior face: a face beside a ring edge that has it on its left (the
    // ring's interior side) is in that ring's part; the others take the part of the face
    // they share an unconstrained edge with (the same region: no ring between them). So a
    // polygon nested inside another's interior leaves the faces between the two rings to the
    // outer one, and the two meet face to face (joined into one model below).
    std::vector<int> facePart(faceCount, -1);
    std::vector<uint8_t> faceRingEdges(faceCount, 0);  // per interior face: whole ring segments on its edges
    std::vector<char> unowned(faceBlocks, 0);  // per block: an interior face left without a part
    parallelFor(faceBlocks, threadCount, [&](size_t block) {
        for (size_t f = faceCount * block / faceBlocks; f < faceCount * (block + 1) / faceBlocks; ++f) {
            if (winding[f] < 1) continue;
            for (int j = 0; j < 3; ++j) {
                if (!tri.constrained[3 * f + j]) continue;
                const int iu = tri.vertexInput[tri.faces[3 * f + (j + 1) % 3]], iv = tri.vertexInput[tri.faces[3 * f + (j + 2) % 3]];
                if (iu < 0 || iv < 0 || in.next(static_cast<size_t>(iu)) != static_cast<size_t>(iv)) continue;
                ++faceRingEdges[f];  // the ring runs iu -> iv, f on its left
                if (facePart[f] < 0) facePart[f] = static_cast<int>(in.part[iu]);
            }
            if (facePart[f] < 0) unowned[block] = 1;
        }
    });
    if (std::count(unowned.begin(), unowned.end(), 1) > 0) {
        std::vector<int> queue;
        for (size_t f = 0; f < faceCount; ++f)
            if (facePart[f] >= 0) queue.push_back(static_cast<int>(f));
        for (size_t head = 0; head < queue.size(); ++head) {  // across unconstrained edges only
            const int f = queue[head];
            for (int j = 0; j < 3; ++j) {
                const int n = tri.neighbors[3 * f + j];
                if (n < 0 || tri.constrained[3 * f + j] || winding[n] < 1 || facePart[n] >= 0) continue;
                facePart[n] = facePart[f];
                queue.push_back(n);
            }
        }
        // Left over (a region whose every ring edge ends at a crossing vertex): the part of a
        // corner, or of any interior neighbour.
        for (size_t f = 0; f < faceCount; ++f)
            for (int k = 0; k < 3 && winding[f] >= 1 && facePart[f] < 0; ++k) facePart[f] = vertexPart[tri.faces[3 * f + k]];
        for (bool changed = true; changed;) {
            changed = false;
            for (size_t f = 0; f < faceCount; ++f) {
                if (winding[f] < 1 || facePart[f] >= 0) continue;
                for (int j = 0; j < 3; ++j) {
                    const int n = tri.neighbors[3 * f + j];
                    if (n >= 0 && winding[n] >= 1 && facePart[n] >= 0) {
                        facePart[f] = facePart[n];
                        changed = true;
                        break;
                    }
                }
            }
        }
    }

    // 4. Models: parts of one feature, touching or overlapping parts, parts nested in others.
    const uint32_t partCount = static_cast<uint32_t>(checked.parts.size());
    DisjointSets parts(partCount);
    for (uint32_t p = 1; p < partCount; ++p)
        if (checked.partFeature[p] == checked.partFeature[p - 1]) parts.unite(p, p - 1);
    std::vector<char>& partTouches = models.partTouches;
    partTouches.assign(partCount, 0);
    auto join = [&](uint32_t a, uint32_t b) {
        if (checked.partFeature[a] != checked.partFeature[b]) partTouches[a] = partTouches[b] = 1;
        parts.unite(a, b);
    };
    for (auto [a, b] : checked.touchingParts) join(a, b);
    // Interior faces of two parts side by side (found in parallel, joined in block order; the
    // models do not depend on the order).
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> adjacentParts(faceBlocks);
    parallelFor(faceBlocks, threadCount, [&](size_t block) {
        for (size_t f = faceCount * block / faceBlocks; f < faceCount * (block + 1) / faceBlocks; ++f)
            for (int j = 0; j < 3; ++j) {
                const int n = tri.neighbors[3 * f + j];
                if (n < 0 || facePart[f] < 0 || facePart[n] < 0 || facePart[f] == facePart[n]) continue;
                adjacentParts[block].emplace_back(facePart[f], facePart[n]);
            }
    });
    for (const auto& list : adjacentParts)
        for (auto [a, b] : list) join(a, b);
    std::vector<int>& partModel = models.partModel;
    std::vector<int> modelOfRoot(partCount, -1);
    partModel.assign(partCount, -1);
    for (uint32_t p = 0; p < partCount; ++p) {
        const uint32_t r = parts.find(p);
        if (modelOfRoot[r] < 0) modelOfRoot[r] = static_cast<int>(space.modelCount++);
        partModel[p] = modelOfRoot[r];
    }
    space.vertexModel.assign(vertexCount, -1);
    forBlocks(vertexCount, [&](size_t v) {
        if (vertexPart[v] >= 0) space.vertexModel[v] = partModel[vertexPart[v]];
    });
    space.faceModel.assign(faceCount, -1);
    forBlocks(faceCount, [&](size_t f) {
        if (winding[f] >= 1) space.faceModel[f] = facePart[f] >= 0 ? partModel[facePart[f]] : 0;
    });
    if (!graphOnly) {  // read by every level
        space.cornerModel.resize(3 * faceCount);
        forBlocks(3 * faceCount, [&](size_t c) { space.cornerModel[c] = space.vertexModel[tri.faces[c]]; });
    }
    if (withModelPoints) space.modelPoints.resize(space.modelCount);
    for (size_t v = 0; v < in.part.size() && withModelPoints; ++v) {
        auto& pts = space.modelPoints[partModel[in.part[v]]];
        pts.push_back(in.x(v));
        pts.push_back(in.y(v));
    }
    if (!graphOnly) {
        // The models whose boundary is exactly their rings: none of their parts touches,
        // overlaps or lies inside another part (the triangulation would split or hide a ring
        // edge there), and no ring vertex is shared. Their polygons, ring by ring of `in`
        // (each part's exterior, then its holes), as the extraction would trace them.
        std::vector<char> modelPlain(space.modelCount, 1);
        for (auto [a, b] : checked.touchingParts) modelPlain[partModel[a]] = modelPlain[partModel[b]] = 0;
        for (const auto& list : adjacentParts)
            for (auto [a, b] : list) modelPlain[partModel[a]] = modelPlain[partModel[b]] = 0;
        for (size_t v = 0; v < in.part.size(); ++v)
            if (v >= in.shared.size() || in.shared[v]) modelPlain[partModel[in.part[v]]] = 0;
        for (size_t f = 0; f < faceCount; ++f)  // inside two polygons: nested or overlapping parts
            if (winding[f] >= 2 && space.faceModel[f] >= 0) modelPlain[space.faceModel[f]] = 0;
        // And every ring segment is still one constrained edge, with the model's face on its
        // left (a vertex of another of its rings on it, e.g. a hole touching the exterior,
        // splits it): the faces' whole ring segments, per model, against its segments.
        std::vector<size_t> intactSegments(space.modelCount, 0), ringSegments(space.modelCount, 0);
        for (size_t f = 0; f < faceCount; ++f)
            if (space.faceModel[f] >= 0) intactSegments[space.faceModel[f]] += faceRingEdges[f];
        for (size_t v = 0; v < in.part.size(); ++v) ++ringSegments[partModel[in.part[v]]];
        for (size_t m = 0; m < space.modelCount; ++m)
            if (intactSegments[m] != ringSegments[m]) modelPlain[m] = 0;
        space.modelPolygons.assign(space.modelCount, {});
        for (size_t v = 0; v < in.part.size(); v += in.ringSize[v]) {
            const uint32_t p = in.part[v];
            const int m = partModel[p];
            if (!modelPlain[m]) continue;
            std::vector<double> ring(in.points.begin() + 2 * v, in.points.begin() + 2 * (v + in.ringSize[v]));
            if (v == 0 || in.part[v - 1] != p) space.modelPolygons[m].push_back(Polygon2D{std::move(ring), {}});
            else space.modelPolygons[m].back().holes.push_back(std::move(ring));
        }
    }

    // Voids: free faces not reachable from the hull through free faces (input holes, or
    // gaps enclosed by touching polygons) and owned by one model only: never filled.
    // Without holes and touching polygons the free space is connected: no voids.
    space.faceVoid.assign(faceCount, 0);
    bool voidsPossible = !checked.touchingParts.empty();
    for (const Polygon2D& poly : checked.parts) voidsPossible = voidsPossible || !poly.holes.empty();
    if (!graphOnly && voidsPossible) {
        std::vector<char> reached(faceCount, 0);
        std::vector<int> stack;
        for (size_t f = 0; f < faceCount; ++f)
            if (space.faceModel[f] < 0)
                for (int j = 0; j < 3; ++j)
                    if (tri.neighbors[3 * f + j] < 0 && !reached[f]) {
                        reached[f] = 1;
                        stack.push_back(static_cast<int>(f));
                    }
        while (!stack.empty()) {
            const int f = stack.back();
            stack.pop_back();
            for (int j = 0; j < 3; ++j) {
                const int n = tri.neighbors[3 * f + j];
                if (n >= 0 && !reached[n] && space.faceModel[n] < 0) {
                    reached[n] = 1;
                    stack.push_back(n);
                }
            }
        }
        for (size_t f = 0; f < faceCount; ++f) {
            if (space.faceModel[f] >= 0 || reached[f]) continue;
            int model = -1;
            bool single = true;
            for (int k = 0; k < 3; ++k) {
                const int m = space.vertexModel[tri.faces[3 * f + k]];
                if (m < 0) continue;
                if (model < 0) model = m;
                else if (m != model) single = false;
            }
            space.faceVoid[f] = single ? 1 : 0;
        }
    }

    // 5. Neighbourhood graph: per model pair the free edges joining them; weight = the
    // shortest connection seen in a free triangle (edge, or vertex to a model's boundary edge).
    space.faceArea.resize(faceCount);
    space.edgeLength.resize(3 * faceCount);
    space.faceLongest.resize(faceCount);
    if (!graphOnly) space.edgePair.assign(3 * faceCount, kSameModelEdge2D);
    struct PairEntry {  // 40 bytes: the grouping below moves many of them
        uint32_t a, b;
        double distance;    // of the connection; for an edge entry, the edge length
        int face;
        int connection[3];  // see ModelPair2D::connection
        int8_t edge;        // the face's edge for an edge entry, -1 for a distance-only entry
        bool counted;       // an edge entry counted in the pair's lengths (each undirected edge once)
    };
    auto P = [&](int v) { return &tri.points[2 * static_cast<size_t>(v)]; };
    // The entries of free face f: each edge joining two models, and each vertex facing another
    // model's boundary edge. Calls edge(a, b, j, u, w, counted) and vertex(a, b, k, j1, j2).
    auto visitEntries = [&](size_t f, auto&& edge, auto&& vertex) {
        const int* v = &tri.faces[3 * f];
        for (int j = 0; j < 3; ++j) {
            const int u = v[(j + 1) % 3], w = v[(j + 2) % 3];
            const int mu = space.vertexModel[u], mw = space.vertexModel[w];
            if (mu < 0 || mw < 0 || mu == mw) continue;
            const int n = tri.neighbors[3 * f + j];
            // Count each undirected edge once (from its smaller free face, or its only one).
            const bool counted = n < 0 || space.faceModel[n] >= 0 || static_cast<int>(f) < n;
            edge(static_cast<uint32_t>(std::min(mu, mw)), static_cast<uint32_t>(std::max(mu, mw)), j, u, w, counted);
        }
        for (int k = 0; k < 3; ++k) {
            const int j1 = (k + 1) % 3, j2 = (k + 2) % 3;
            const int mk = space.vertexModel[v[k]], m1 = space.vertexModel[v[j1]], m2 = space.vertexModel[v[j2]];
            if (mk < 0 || m1 < 0 || m1 != m2 || mk == m1 || !tri.constrained[3 * f + k]) continue;
            vertex(static_cast<uint32_t>(std::min(mk, m1)), static_cast<uint32_t>(std::max(mk, m1)), k, j1, j2);
        }
    };
    // Entries grouped by model a in face order, written straight into place: faces go in a
    // fixed number of contiguous chunks; pass 1 measures every face and counts its entries
    // per a, pass 2 writes them (same order for any chunk or thread count). Then a stable
    // sort on b per model: each pair's entries form one run, and its shortest connection is
    // the least entry of the run by (distance, face, edge, connection).
    const size_t threads = threadCount > 0 ? static_cast<size_t>(threadCount)
                                           : std::max<size_t>(1, std::thread::hardware_concurrency());
    const size_t chunks = std::min({faceBlocks, 2 * threads, size_t{16}});  // chunks x models counters
    std::vector<std::vector<uint32_t>> chunkPlace(chunks, std::vector<uint32_t>(space.modelCount, 0));
    auto chunkFaces = [&](size_t c) { return std::make_pair(faceCount * c / chunks, faceCount * (c + 1) / chunks); };
    parallelFor(chunks, threadCount, [&](size_t c) {
        std::vector<uint32_t>& count = chunkPlace[c];
        const auto [first, last] = chunkFaces(c);
        for (size_t f = first; f < last; ++f) {
            const int* v = &tri.faces[3 * f];
            space.faceArea[f] = 0.5 * ((P(v[1])[0] - P(v[0])[0]) * (P(v[2])[1] - P(v[0])[1]) -
                                       (P(v[2])[0] - P(v[0])[0]) * (P(v[1])[1] - P(v[0])[1]));
            double longest = 0;
            for (int j = 0; j < 3; ++j) {
                const int u = v[(j + 1) % 3], w = v[(j + 2) % 3];
                const double dx = P(w)[0] - P(u)[0], dy = P(w)[1] - P(u)[1];
                const double length = std::sqrt(dx * dx + dy * dy);  // not hypot: 5x slower, no overflow risk here
                space.edgeLength[3 * f + j] = length;
                longest = std::max(longest, length);
            }
            space.faceLongest[f] = longest;
            if (space.faceModel[f] >= 0) continue;
            visitEntries(f, [&](uint32_t a, uint32_t, int, int, int, bool) { ++count[a]; },
                         [&](uint32_t a, uint32_t, int, int, int) { ++count[a]; });
        }
    });
    std::vector<uint32_t> start(space.modelCount + 1, 0);
    for (size_t m = 0; m < space.modelCount; ++m) {
        uint32_t place = start[m];
        for (size_t c = 0; c < chunks; ++c) {
            const uint32_t count = chunkPlace[c][m];
            chunkPlace[c][m] = place;
            place += count;
        }
        start[m + 1] = place;
    }
    std::vector<PairEntry> entries(start[space.modelCount]);
    parallelFor(chunks, threadCount, [&](size_t c) {
        std::vector<uint32_t>& place = chunkPlace[c];
        const auto [first, last] = chunkFaces(c);
        for (size_t f = first; f < last; ++f) {
            if (space.faceModel[f] >= 0) continue;
            const int* v = &tri.faces[3 * f];
            visitEntries(
                f,
                [&](uint32_t a, uint32_t b, int j, int u, int w, bool counted) {
                    entries[place[a]++] = {a, b, space.edgeLength[3 * f + j], static_cast<int>(f), {u, w, -1},
                                           static_cast<int8_t>(j), counted};
                },
                [&](uint32_t a, uint32_t b, int k, int j1, int j2) {
                    entries[place[a]++] = {a, b, pointSegmentDistance(P(v[k]), P(v[j1]), P(v[j2])), static_cast<int>(f),
                                           {v[k], v[j1], v[j2]}, -1, false};
                });
        }
    });
    std::vector<std::vector<uint32_t>>().swap(chunkPlace);
    const size_t modelBlocks = std::clamp<size_t>(space.modelCount / 1024, 1, 64);
    auto blockModels = [&](size_t block) {
        return std::make_pair(space.modelCount * block / modelBlocks, space.modelCount * (block + 1) / modelBlocks);
    };
    parallelFor(modelBlocks, threadCount, [&](size_t block) {
        const auto [firstModel, lastModel] = blockModels(block);
        for (size_t m = firstModel; m < lastModel; ++m) {
            const auto first = entries.begin() + start[m], last = entries.begin() + start[m + 1];
            if (last - first <= 32) {  // the usual case: an insertion sort (stable)
                for (auto i = first + (first != last); i < last; ++i)
                    for (auto j = i; j > first && (j - 1)->b > j->b; --j) std::iter_swap(j - 1, j);
            } else {
                std::stable_sort(first, last, [](const PairEntry& x, const PairEntry& y) { return x.b < y.b; });
            }
        }
    });
    // Pairs by blocks of models (contiguous runs of entries): the blocks count their pairs and
    // lengths first, then each fills its own slots of the (a, b)-ordered lists.
    auto less = [](const PairEntry& x, const PairEntry& y) {
        return std::tie(x.distance, x.face, x.edge, x.connection[0], x.connection[1], x.connection[2]) <
               std::tie(y.distance, y.face, y.edge, y.connection[0], y.connection[1], y.connection[2]);
    };
    auto runEnd = [&](size_t i, size_t end) {
        size_t e = i;
        while (e < end && entries[e].a == entries[i].a && entries[e].b == entries[i].b) ++e;
        return e;
    };
    std::vector<size_t> blockPairs(modelBlocks + 1, 0), blockLengths(modelBlocks + 1, 0);
    parallelFor(modelBlocks, threadCount, [&](size_t block) {
        const auto [firstModel, lastModel] = blockModels(block);
        const size_t end = start[lastModel];
        for (size_t i = start[firstModel]; i < end; i = runEnd(i, end)) ++blockPairs[block + 1];
        for (size_t i = start[firstModel]; i < end; ++i) blockLengths[block + 1] += entries[i].counted;
    });
    for (size_t block = 0; block < modelBlocks; ++block) {
        blockPairs[block + 1] += blockPairs[block];
        blockLengths[block + 1] += blockLengths[block];
    }
    const size_t pairCount = blockPairs[modelBlocks];
    space.pairs.resize(pairCount);
    if (!graphOnly) {
        space.pairLengths.resize(blockLengths[modelBlocks]);
        space.pairPrefixSum.resize(blockLengths[modelBlocks] + pairCount);
        space.pairPrefixSumSquares.resize(blockLengths[modelBlocks] + pairCount);
    }
    parallelFor(modelBlocks, threadCount, [&](size_t block) {
        const auto [firstModel, lastModel] = blockModels(block);
        const size_t end = start[lastModel];
        size_t pairIndex = blockPairs[block], lengthAt = blockLengths[block];
        for (size_t i = start[firstModel], e; i < end; i = e, ++pairIndex) {
            e = runEnd(i, end);
            size_t best = i;
            for (size_t k = i + 1; k < e; ++k)
                if (less(entries[k], entries[best])) best = k;
            ModelPair2D& pair = space.pairs[pairIndex];
            pair.a = entries[i].a;
            pair.b = entries[i].b;
            pair.minDistance = entries[best].distance;
            pair.bestFace[0] = entries[best].face;
            std::copy(entries[best].connection, entries[best].connection + 3, pair.connection);
            // The second face: the smallest other face holding a connection as short.
            for (size_t k = i; k < e; ++k)
                if (entries[k].distance == pair.minDistance && entries[k].face != pair.bestFace[0] &&
                    (pair.bestFace[1] < 0 || entries[k].face < pair.bestFace[1]))
                    pair.bestFace[1] = entries[k].face;
            if (graphOnly) continue;
            pair.firstLength = static_cast<uint32_t>(lengthAt);
            for (size_t k = i; k < e; ++k)
                if (entries[k].counted) space.pairLengths[lengthAt++] = entries[k].distance;
            pair.lengthCount = static_cast<uint32_t>(lengthAt - pair.firstLength);
            double* lengths = space.pairLengths.data() + pair.firstLength;
            std::sort(lengths, lengths + pair.lengthCount);
            pair.firstPrefix = static_cast<uint32_t>(pair.firstLength + pairIndex);
            double* sum = space.pairPrefixSum.data() + pair.firstPrefix;
            double* sumSquares = space.pairPrefixSumSquares.data() + pair.firstPrefix;
            sum[0] = sumSquares[0] = 0;
            for (size_t k = 0; k < pair.lengthCount; ++k) {
                sum[k + 1] = sum[k] + lengths[k];
                sumSquares[k + 1] = sumSquares[k] + lengths[k] * lengths[k];
            }
            // Each free edge's pair (every (face, edge) is in one entry at most: distinct slots).
            for (size_t k = i; k < e; ++k)
                if (entries[k].edge >= 0)
                    space.edgePair[3 * static_cast<size_t>(entries[k].face) + entries[k].edge] = static_cast<int>(pairIndex);
        }
    });
    if (!graphOnly) {
        forBlocks(faceCount, [&](size_t f) {
            for (int j = 0; j < 3; ++j) {
                const int u = tri.faces[3 * f + (j + 1) % 3], w = tri.faces[3 * f + (j + 2) % 3];
                if (space.vertexModel[u] < 0 || space.vertexModel[w] < 0) space.edgePair[3 * f + j] = kUnpairedEdge2D;
            }
        });
    }
}

std::vector<GraphEdge> graphEdges(const FreeSpace2D& space) {
    std::vector<GraphEdge> graph;
    graph.reserve(space.pairs.size());
    for (const ModelPair2D& p : space.pairs) graph.push_back(GraphEdge{p.a, p.b, p.minDistance});
    return graph;
}

/// in.partTouches from checked.touchingParts.
void markTouchingParts(InputVertices& in, const CheckedPolygons& checked) {
    in.partTouches.assign(checked.parts.size(), 0);
    for (auto [a, b] : checked.touchingParts) in.partTouches[a] = in.partTouches[b] = 1;
}

/// in.shared from the triangulation of `in`: input points sharing a vertex lie at the same place.
void setShared(InputVertices& in, const Triangulation2D& tri) {
    std::vector<uint8_t> count(tri.vertexCount(), 0);
    for (int v : tri.inputVertex) count[v] = static_cast<uint8_t>(std::min(count[v] + 1, 2));
    in.shared.resize(in.part.size());
    for (size_t i = 0; i < in.shared.size(); ++i) in.shared[i] = count[tri.inputVertex[i]] > 1;
}

/// Steiner points on the ring segments, flat: the segment starting at original input vertex s
/// gets an extra (collinear) vertex at each parameter of t[first[s], first[s] + count[s]),
/// ascending, in (0, 1).
struct SegmentSplits {
    std::vector<uint32_t> first, count;
    std::vector<double> t;
    size_t size(size_t s) const { return s < count.size() ? count[s] : 0; }
    const double* at(size_t s) const { return t.data() + first[s]; }
};

/// Input vertices of the checked polygons (in.shared is set by setShared), with the Steiner
/// points of `splits` (optional) after their segment's start.
InputVertices inputVertices(const CheckedPolygons& checked, const SegmentSplits* splits, bool withGrid = true) {
    InputVertices in;
    size_t original = 0;
    for (uint32_t p = 0; p < checked.parts.size(); ++p) {
        const Polygon2D& poly = checked.parts[p];
        for (int h = -1; h < static_cast<int>(poly.holes.size()); ++h) {
            const std::vector<double>& ring = h < 0 ? poly.exterior : poly.holes[h];
            const uint32_t start = static_cast<uint32_t>(in.part.size()), n = static_cast<uint32_t>(ring.size() / 2);
            for (uint32_t i = 0; i < n; ++i, ++original) {
                const uint32_t j = (i + 1) % n;
                in.points.push_back(ring[2 * i]);
                in.points.push_back(ring[2 * i + 1]);
                in.part.push_back(p);
                for (size_t k = 0, count = splits ? splits->size(original) : 0; k < count; ++k) {
                    const double t = splits->at(original)[k];
                    in.points.push_back(ring[2 * i] + t * (ring[2 * j] - ring[2 * i]));
                    in.points.push_back(ring[2 * i + 1] + t * (ring[2 * j + 1] - ring[2 * i + 1]));
                    in.part.push_back(p);
                }
            }
            const uint32_t size = static_cast<uint32_t>(in.part.size()) - start;
            for (uint32_t i = 0; i < size; ++i) {
                in.ringStart.push_back(start);
                in.ringSize.push_back(size);
                in.segments.emplace_back(start + i, start + (i + 1) % size);
            }
        }
    }
    markTouchingParts(in, checked);
    if (withGrid) buildSegmentGrid(in);
    return in;
}

/// Steiner points for the shortest connection of every merge (docs/design.md §2.4 step 4): where a
/// connection ends at a vertex, its boundary edges longer than 3 d get a point at distance d
/// (d = the connection's length); where it ends inside an edge, the edge gets the foot point
/// and points d to either side. mergePair: per merge, its index in space.pairs. Only called
/// on the unsplit input.
SegmentSplits connectionSplits(const InputVertices& in, const FreeSpace2D& space, const std::vector<Merge>& merges,
                               const std::vector<uint32_t>& mergePair) {
    std::vector<std::pair<uint32_t, double>> found;  // (segment, parameter)
    found.reserve(2 * merges.size());
    const Triangulation2D& tri = space.tri;
    auto addAt = [&](size_t segmentStart, double t) { found.emplace_back(static_cast<uint32_t>(segmentStart), t); };
    auto segmentLength = [&](size_t s) { return std::hypot(in.x(in.next(s)) - in.x(s), in.y(in.next(s)) - in.y(s)); };
    // Split both boundary edges at vertex v (input vertex) at distance d from it.
    auto splitAroundVertex = [&](size_t v, double d) {
        const size_t prev = in.prev(v);
        const double lOut = segmentLength(v), lIn = segmentLength(prev);
        if (lOut > 3 * d) addAt(v, d / lOut);
        if (lIn > 3 * d) addAt(prev, 1 - d / lIn);
    };
    for (size_t k = 0; k < merges.size(); ++k) {
        const ModelPair2D& pair = space.pairs[mergePair[k]];
        const double d = pair.minDistance;
        if (!(d > 0)) continue;
        const int* c = pair.connection;
        const int iv0 = tri.vertexInput[c[0]];
        if (iv0 < 0) continue;
        splitAroundVertex(static_cast<size_t>(iv0), d);
        if (c[2] < 0) {  // vertex to vertex
            const int iv1 = tri.vertexInput[c[1]];
            if (iv1 >= 0) splitAroundVertex(static_cast<size_t>(iv1), d);
            continue;
        }
        // Vertex to the edge (c[1], c[2]): find the input segment holding it.
        const int e0 = tri.vertexInput[c[1]], e1 = tri.vertexInput[c[2]];
        if (e0 < 0 || e1 < 0) continue;
        size_t s;
        if (in.next(static_cast<size_t>(e0)) == static_cast<size_t>(e1)) s = static_cast<size_t>(e0);
        else if (in.next(static_cast<size_t>(e1)) == static_cast<size_t>(e0)) s = static_cast<size_t>(e1);
        else continue;  // a part of a longer segment: leave it
        const size_t e = in.next(s);
        const double dx = in.x(e) - in.x(s), dy = in.y(e) - in.y(s);
        const double len = std::hypot(dx, dy);
        const double t = ((in.x(iv0) - in.x(s)) * dx + (in.y(iv0) - in.y(s)) * dy) / (len * len);
        const double margin = 0.5 * d / len;
        for (double u : {t - d / len, t, t + d / len})
            if (u > margin && u < 1 - margin) addAt(s, u);
    }
    // By segment (counting sort), each segment's parameters ascending without near-duplicates
    // (two connections at one place).
    SegmentSplits splits;
    const size_t segmentCount = in.part.size();
    splits.first.assign(segmentCount + 1, 0);
    splits.count.assign(segmentCount, 0);
    for (const auto& [segment, t] : found) ++splits.first[segment + 1];
    for (size_t v = 0; v < segmentCount; ++v) splits.first[v + 1] += splits.first[v];
    splits.t.resize(found.size());
    for (const auto& [segment, t] : found) splits.t[splits.first[segment] + splits.count[segment]++] = t;
    for (size_t v = 0; v < segmentCount; ++v) {
        if (splits.count[v] < 2) continue;
        double* list = splits.t.data() + splits.first[v];
        std::sort(list, list + splits.count[v]);
        uint32_t kept = 1;
        for (uint32_t i = 1; i < splits.count[v]; ++i)
            if (list[i] - list[kept - 1] > 1e-6) list[kept++] = list[i];
        splits.count[v] = kept;
    }
    return splits;
}

}  // namespace

std::vector<std::vector<Polygon2D>> acceptedPolygons2D(const std::vector<Feature2D>& features,
                                                       std::vector<Diagnostic>& diagnostics) {
    CheckedPolygons checked;
    checkPolygons(features, checked, diagnostics);
    std::vector<std::vector<Polygon2D>> out(features.size());
    for (size_t p = 0; p < checked.parts.size(); ++p) out[checked.partFeature[p]].push_back(std::move(checked.parts[p]));
    return out;
}

bool buildHierarchy2D(const std::vector<Feature2D>& features, const Settings2D& settings, Hierarchy2D& out) {
    out = Hierarchy2D{};
    out.featureModel.assign(features.size(), -1);
    auto progress = [&](const char* stage, double fraction) {
        if (settings.progress) settings.progress(stage, fraction);
    };
    auto stageStart = Clock::now();
    auto endStage = [&](const char* name) {
        const auto now = Clock::now();
        out.timings.emplace_back(name, std::chrono::duration<double>(now - stageStart).count());
        stageStart = now;
    };
    auto fail = [&](const std::string& message) {
        out.diagnostics.push_back({Diagnostic::Severity::Error, "", message});
        return false;
    };
    if (std::string problem; !validThresholds(settings.deltas, problem)) return fail(problem);

    // 1. Input checks, in two steps: the rings are cleaned and oriented first; the contact
    // checks (self-intersections, crossings, touching polygons) then run on another thread
    // while CGAL triangulates the cleaned rings, followed there by the segment grid of the
    // free-space pass (they touch different members of `in`). When the contact checks drop a
    // polygon they cancel that triangulation, which is then made again without it.
    progress("checking input", 0);
    CheckedPolygons checked;
    PolygonCheckProgress checkProgress;
    cleanPolygons(features, checked, out.diagnostics, checkProgress);
    const size_t cleanedParts = checked.parts.size();
    InputVertices in = inputVertices(checked, nullptr, /*withGrid=*/false);
    std::vector<Diagnostic> contactDiagnostics;
    std::atomic<bool> partsDropped{false};
    auto checkContacts = [&] {
        checkPolygonContacts(features, checked, contactDiagnostics, checkProgress);
        if (checked.parts.size() != cleanedParts) {  // `in` is made again below
            partsDropped = true;
            return;
        }
        markTouchingParts(in, checked);
        buildSegmentGrid(in);
    };
    std::future<void> contactsLater;
    if (settings.threadCount != 1 && cleanedParts > 0) contactsLater = std::async(std::launch::async, checkContacts);
    else checkContacts();
    endStage("check input");

    const bool needHulls = settings.computeBaselines || settings.shape == Shape2D::ConvexHull;
    // 2.-5. Triangulation, free space, models and graph; then once more with Steiner points
    // on long boundary edges at the shortest connections of the dendrogram (docs/design.md §2.4
    // step 4), so that joined models get a narrow bridge of small triangles.
    progress("triangulating", 0);
    FreeSpace2D space;
    FreeSpaceModels models;
    std::string error;
    ConstrainedTriangulation2D triangulation;
    bool triangulated = cleanedParts > 0 && !partsDropped &&
                        triangulation.build(in.points, in.segments, space.tri, error, settings.threadCount, &partsDropped);
    if (contactsLater.valid()) contactsLater.get();
    out.diagnostics.insert(out.diagnostics.end(), contactDiagnostics.begin(), contactDiagnostics.end());
    if (checked.parts.empty()) return fail("no usable polygon in the input");
    if (checked.parts.size() != cleanedParts) {  // a polygon was dropped: triangulate without it
        in = inputVertices(checked, nullptr);
        triangulated = triangulation.build(in.points, in.segments, space.tri, error, settings.threadCount);
    }
    if (!triangulated) return fail(error);
    for (const Polygon2D& poly : checked.parts) {
        out.originals.area += ringSignedArea(poly.exterior);
        out.originals.perimeter += ringLength(poly.exterior);
        for (const auto& hole : poly.holes) {
            out.originals.area += ringSignedArea(hole);
            out.originals.perimeter += ringLength(hole);
        }
    }
    out.originals.circularity = circularity(out.originals.area, out.originals.perimeter);
    setShared(in, space.tri);
    endStage("triangulate");
    std::vector<int> winding = windingNumbers(in, space.tri, settings.threadCount);
    buildFreeSpace(in, checked, winding, space, models, /*graphOnly=*/true, settings.threadCount);
    // Unconstrained edges of free triangles (hull edges included), before Steiner points:
    // the edges GEOS's ConcaveHullOfPolygons takes for its length ratio.
    out.freeEdgeMin = INFINITY;
    for (size_t f = 0; f < space.tri.faceCount(); ++f)
        for (int j = 0; j < 3; ++j) {
            if (space.faceModel[f] >= 0 || space.tri.constrained[3 * f + j]) continue;
            out.freeEdgeMin = std::min(out.freeEdgeMin, space.edgeLength[3 * f + j]);
            out.freeEdgeMax = std::max(out.freeEdgeMax, space.edgeLength[3 * f + j]);
        }
    if (!std::isfinite(out.freeEdgeMin)) out.freeEdgeMin = 0;
    std::vector<uint32_t> mergePair;  // per merge: its index in space.pairs
    out.merges = kruskalMerges(space.modelCount, graphEdges(space), &mergePair);
    endStage("free space and graph");
    SegmentSplits splits = connectionSplits(in, space, out.merges, mergePair);
    std::vector<ConstraintSplit> requests;
    std::vector<size_t> requestSegment;
    for (size_t v = 0; v < in.part.size(); ++v) {
        if (splits.size(v) == 0) continue;
        ConstraintSplit r;
        r.from = v;
        r.to = in.next(v);
        r.points.reserve(2 * splits.size(v));
        for (size_t k = 0; k < splits.size(v); ++k) {  // the same arithmetic as inputVertices()
            const double t = splits.at(v)[k];
            r.points.push_back(in.x(v) + t * (in.x(r.to) - in.x(v)));
            r.points.push_back(in.y(v) + t * (in.y(r.to) - in.y(v)));
        }
        requests.push_back(std::move(r));
        requestSegment.push_back(v);
    }
    if (!requests.empty()) {
        // The new vertices go into the exported triangulation, each splitting its constrained
        // edge; a segment that cannot be split that way keeps fewer (or no) new vertices.
        // The input with the new vertices is prepared on another thread meanwhile.
        Triangulation2D tri = std::move(space.tri);
        space = FreeSpace2D{};
        InputVertices split;
        std::future<InputVertices> splitLater;
        if (settings.threadCount != 1)
            splitLater = std::async(std::launch::async, [&] { return inputVertices(checked, &splits, /*withGrid=*/false); });
        std::vector<uint32_t> appliedCount;
        std::vector<int> firstVertex;
        bool inserted = true;
        try {
            insertSplitPoints2D(tri, requests, appliedCount, firstVertex, &winding);
        } catch (const std::exception& e) {
            inserted = false;
            error = std::string("2D triangulation failed while adding points: ") + e.what();
        }
        split = splitLater.valid() ? splitLater.get() : inputVertices(checked, &splits, /*withGrid=*/false);
        if (!inserted) return fail(error);
        bool allApplied = true;
        for (size_t k = 0; k < requests.size(); ++k)
            if (appliedCount[k] < splits.size(requestSegment[k])) {
                splits.count[requestSegment[k]] = appliedCount[k];
                allApplied = false;
            }
        // The new input numbering: every original vertex followed by its segment's new points.
        const size_t originalCount = in.part.size();
        std::vector<size_t> newInputIndex(originalCount);
        for (size_t v = 0, next = 0; v < originalCount; ++v) {
            newInputIndex[v] = next;
            next += 1 + splits.size(v);
        }
        std::vector<long long> splitFirstIndex(requests.size(), -1);
        for (size_t k = 0; k < requests.size(); ++k)
            if (appliedCount[k] > 0) splitFirstIndex[k] = static_cast<long long>(newInputIndex[requestSegment[k]] + 1);
        in = allApplied ? std::move(split) : inputVertices(checked, &splits, /*withGrid=*/false);
        renumberAfterSplits2D(tri, newInputIndex, splitFirstIndex, appliedCount, firstVertex, in.part.size());
        space.tri = std::move(tri);
        setShared(in, space.tri);
        endStage("triangulate with Steiner points");
        buildFreeSpace(in, checked, winding, space, models, /*graphOnly=*/false, settings.threadCount, needHulls);
        out.merges = kruskalMerges(space.modelCount, graphEdges(space), &mergePair);
        endStage("free space and graph again");
    } else {
        Triangulation2D tri = std::move(space.tri);
        space = FreeSpace2D{};
        space.tri = std::move(tri);  // no Steiner point: complete the graph-only pass
        buildFreeSpace(in, checked, winding, space, models, /*graphOnly=*/false, settings.threadCount, needHulls);
        endStage("free space and graph again");
    }
    out.vertexCount = space.tri.vertexCount();
    out.triangleCount = space.tri.faceCount();
    out.modelCount = space.modelCount;
    for (uint32_t p = 0; p < checked.parts.size(); ++p) out.featureModel[checked.partFeature[p]] = models.partModel[p];
    {
        std::vector<std::vector<uint32_t>> modelFeatures(space.modelCount);
        std::vector<char> modelTouches(space.modelCount, 0);
        for (uint32_t p = 0; p < checked.parts.size(); ++p) {
            auto& list = modelFeatures[models.partModel[p]];
            if (list.empty() || list.back() != checked.partFeature[p]) list.push_back(checked.partFeature[p]);
            if (models.partTouches[p]) modelTouches[models.partModel[p]] = 1;
        }
        for (size_t m = 0; m < space.modelCount; ++m)
            if (modelTouches[m] && modelFeatures[m].size() > 1)
                out.diagnostics.push_back({Diagnostic::Severity::Note, joinNames(features, modelFeatures[m]),
                                           "these " + std::to_string(modelFeatures[m].size()) +
                                               " features touch or overlap; merged into one model"});
    }
    endStage("models");

    // 6. Levels.
    std::vector<double> deltas = settings.deltas;
    std::sort(deltas.begin(), deltas.end());
    deltas.erase(std::unique(deltas.begin(), deltas.end()), deltas.end());
    if (deltas.empty()) deltas = automaticDeltas(out.merges, settings.automaticLevelCount);
    if (deltas.empty()) deltas.push_back(0);  // a single model: one level, the originals
    const AggregateFunction primary = settings.customFunction ? settings.customFunction
                                                              : makeAggregateFunction(settings.function);
    const AggregateFunction constant = makeAggregateFunction(AggregateFunctionKind::Constant);
    const AggregateFunction adaptive = makeAggregateFunction(AggregateFunctionKind::Adaptive);
    const ConnectionFans2D fans = settings.shape == Shape2D::Sculpted || settings.computeBaselines
                                      ? computeConnectionFans2D(space, mergePair, settings.threadCount)
                                      : ConnectionFans2D{};
    // F of every pair at every level: a custom function (user code) on the calling thread, the
    // built-in ones inside the parallel level loop below.
    const size_t levelCount = deltas.size();
    std::vector<EdgeLimits2D> primaryLimits(levelCount), constantLimits(levelCount), adaptiveLimits(levelCount);
    const bool limitsInLevels = !settings.customFunction;
    for (size_t li = 0; li < levelCount && !limitsInLevels; ++li) {
        if (settings.shape == Shape2D::Sculpted) primaryLimits[li] = computeEdgeLimits2D(space, deltas[li], primary);
        if (settings.computeBaselines) {
            constantLimits[li] = computeEdgeLimits2D(space, deltas[li], constant);
            adaptiveLimits[li] = computeEdgeLimits2D(space, deltas[li], adaptive);
        }
    }
    // Levels are independent: sculpted in parallel, each writing only its own slot.
    out.levels.resize(levelCount);
    auto buildLevel = [&](size_t li) {
        if (limitsInLevels) {
            if (settings.shape == Shape2D::Sculpted) primaryLimits[li] = computeEdgeLimits2D(space, deltas[li], primary);
            if (settings.computeBaselines) {
                constantLimits[li] = computeEdgeLimits2D(space, deltas[li], constant);
                adaptiveLimits[li] = computeEdgeLimits2D(space, deltas[li], adaptive);
            }
        }
        Level2D& level = out.levels[li];
        std::vector<int> label;
        level.delta = deltas[li];
        size_t groupCount = 0;
        const std::vector<uint32_t> modelGroup = groupsAtThreshold(space.modelCount, out.merges, level.delta, &groupCount);
        size_t joined = 0;  // the merges of this level: the first ones (ascending height)
        while (joined < out.merges.size() && out.merges[joined].height < level.delta) ++joined;
        level.aggregates.resize(groupCount);
        // Sources and hulls of every group.
        for (size_t f = 0; f < features.size(); ++f)
            if (out.featureModel[f] >= 0)
                level.aggregates[modelGroup[out.featureModel[f]]].sourceFeatures.push_back(static_cast<uint32_t>(f));
        std::vector<std::vector<double>> hulls;
        if (needHulls) {
            std::vector<std::vector<double>> groupPoints(groupCount);
            for (size_t m = 0; m < space.modelCount; ++m) {
                auto& gp = groupPoints[modelGroup[m]];
                gp.insert(gp.end(), space.modelPoints[m].begin(), space.modelPoints[m].end());
            }
            hulls.resize(groupCount);
            for (size_t g = 0; g < groupCount; ++g) {
                hulls[g] = convexHull2D(std::move(groupPoints[g]));
                level.hull.area += ringSignedArea(hulls[g]);
                level.hull.perimeter += ringLength(hulls[g]);
            }
            level.hull.circularity = circularity(level.hull.area, level.hull.perimeter);
        }
        if (settings.shape == Shape2D::ConvexHull) {
            for (size_t g = 0; g < groupCount; ++g) {
                Aggregate2D& agg = level.aggregates[g];
                agg.polygons.push_back(Polygon2D{hulls[g], {}});
                agg.measures.area = ringSignedArea(hulls[g]);
                agg.measures.perimeter = ringLength(hulls[g]);
                agg.measures.circularity = circularity(agg.measures.area, agg.measures.perimeter);
            }
        } else {
            sculptLevel2D(space, modelGroup, primaryLimits[li], fans, joined, label);
            std::vector<int> groupModel(groupCount, -1);  // its model when it has one only
            std::vector<uint32_t> groupSize(groupCount, 0);
            for (size_t m = 0; m < space.modelCount; ++m)
                if (groupSize[modelGroup[m]]++ == 0) groupModel[modelGroup[m]] = static_cast<int>(m);
            for (size_t g = 0; g < groupCount; ++g)
                if (groupSize[g] != 1) groupModel[g] = -1;
            extractPolygons2D(space, label, groupCount, level.aggregates, &groupModel);
        }
        for (const Aggregate2D& agg : level.aggregates) {
            level.measures.area += agg.measures.area;
            level.measures.perimeter += agg.measures.perimeter;
        }
        level.measures.circularity = circularity(level.measures.area, level.measures.perimeter);
        if (settings.computeBaselines) {
            sculptLevel2D(space, modelGroup, constantLimits[li], fans, joined, label);
            level.constant = measureLabels2D(space, label);
            sculptLevel2D(space, modelGroup, adaptiveLimits[li], fans, joined, label);
            level.adaptive = measureLabels2D(space, label);
        }
    };
    progress("sculpting levels", 0);
    parallelFor(levelCount, settings.threadCount, buildLevel, [&](size_t done) {
        progress("sculpting levels", static_cast<double>(done) / static_cast<double>(levelCount));
    });
    progress("sculpting levels", 1);
    endStage("sculpt levels");
    return true;
}

}  // namespace aggrelod
