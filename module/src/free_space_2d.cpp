// SPDX-License-Identifier: AGPL-3.0-or-later
// Free-space ownership in 2D (paper Section 3.1; docs/design.md §2.1): which faces of the one
// constrained Delaunay triangulation lie inside the polygons (winding numbers), which input
// part owns each vertex and interior face, and the voids no level fills.
#include "baker_2d.h"

#include "parallel_for.h"

#include <climits>
#include <cmath>
#include <tuple>

namespace aggrelod::detail {
namespace {

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

}  // namespace

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

FaceParts assignFaceParts(const InputVertices& in, const Triangulation2D& tri, const std::vector<int>& winding,
                          int threadCount) {
    const size_t faceCount = tri.faceCount(), vertexCount = tri.vertexCount();
    const size_t faceBlocks = faceBlockCount(faceCount);
    FaceParts parts;
    // Part of each vertex and of each interior face (parallel blocks, each writing its own slots).
    std::vector<int>& vertexPart = parts.vertexPart;
    vertexPart.assign(vertexCount, -1);
    parallelForEach(vertexCount, threadCount, [&](size_t v) {
        if (tri.vertexInput[v] >= 0) vertexPart[v] = static_cast<int>(in.part[tri.vertexInput[v]]);
    });
    // The part of each interior face: a face beside a ring edge that has it on its left (the
    // ring's interior side) is in that ring's part; the others take the part of the face
    // they share an unconstrained edge with (the same region: no ring between them). So a
    // polygon nested inside another's interior leaves the faces between the two rings to the
    // outer one, and the two meet face to face (joined into one model below).
    std::vector<int>& facePart = parts.facePart;
    facePart.assign(faceCount, -1);
    std::vector<uint8_t>& faceRingEdges = parts.faceRingEdges;
    faceRingEdges.assign(faceCount, 0);
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
    return parts;
}

void markVoids(const CheckedPolygons& checked, FreeSpace2D& space, bool graphOnly) {
    const Triangulation2D& tri = space.tri;
    const size_t faceCount = tri.faceCount();
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
}

void buildFreeSpace(const InputVertices& in, const CheckedPolygons& checked, const std::vector<int>& winding,
                    FreeSpace2D& space, FreeSpaceModels& models, bool graphOnly, int threadCount,
                    bool withModelPoints) {
    const FaceParts faces = assignFaceParts(in, space.tri, winding, threadCount);
    buildModels2D(in, checked, winding, faces, space, models, graphOnly, withModelPoints, threadCount);
    markVoids(checked, space, graphOnly);
    buildNeighbourhoodGraph2D(space, graphOnly, threadCount);
}

}  // namespace aggrelod::detail
