// SPDX-License-Identifier: AGPL-3.0-or-later
// Sculpting in 2D (docs/design.md §2.4; paper Section 3.3 "Aggregated Approximation") and the
// extraction of polygons with holes from the kept triangles.
//
// Step 1: a free triangle takes the single group of its owned vertices; triangles of two or
// more groups, of none, and input holes (faceVoid) are removed.
// Step 2: a kept free triangle with an exposed edge (on the hull or facing a triangle outside
// its group) is removed when such an edge is longer than F(m1, m2). Removal is monotone, so
// a stack gives the same result as any order (linear time).
// Step 4: for every pair joined at this level, the triangle holding their shortest connection
// and a fan of triangles to an edge of each model are never removed, so joined models come
// out as one polygon (edge-connected) where the fan's faces are no longer than delta;
// otherwise they touch at a point and come out as two polygons of one MultiPolygon.
#include "sculpt_2d.h"

#include "carve.h"
#include "parallel_for.h"
#include "polygon_check_2d.h"
#include "radix_sort.h"

#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace aggrelod::detail {
namespace {

struct Sculptor2D {
    const FreeSpace2D& space;
    const std::vector<uint32_t>& modelGroup;
    const EdgeLimits& limits;
    std::vector<int>& label;
    std::vector<char> isProtected;

    const Triangulation2D& tri() const { return space.tri; }
    int groupOfModel(int m) const { return m < 0 ? -1 : static_cast<int>(modelGroup[m]); }

    void initialLabels() {
        const size_t faceCount = tri().faceCount();
        label.assign(faceCount, -1);
        isProtected.assign(faceCount, 0);
        for (size_t f = 0; f < faceCount; ++f) {
            if (space.faceModel[f] >= 0) {
                label[f] = groupOfModel(space.faceModel[f]);
                continue;
            }
            if (space.faceVoid[f]) continue;
            int group = -1;
            bool mixed = false;
            for (int k = 0; k < 3; ++k) {
                const int g = groupOfModel(space.cornerModel[3 * f + k]);
                if (g < 0) continue;
                if (group < 0) group = g;
                else if (g != group) mixed = true;
            }
            label[f] = mixed ? -1 : group;
        }
    }

    bool isKeptFree(int f, int group) const { return f >= 0 && space.faceModel[f] < 0 && label[f] == group; }

    double limitOf(int pairIndex) const {
        if (pairIndex >= 0) return limits.pair[pairIndex];
        return pairIndex == kSameModelEdge ? limits.sameModel : limits.unpaired;
    }

    // The fan of least total area among the slot's walks whose faces are all kept in the
    // group and no longer than delta (the one hugging the corner, not a sliver along a side;
    // a fan through a long face would fill far more than the connection).
    void protectFan(const ConnectionFans2D& fans, size_t slot, int group) {
        uint32_t best = UINT32_MAX;
        double bestArea = INFINITY;
        for (uint32_t c = fans.slotBegin[slot]; c < fans.slotBegin[slot + 1]; ++c) {
            bool usable = !(fans.pathLongest[c] > limits.delta);
            for (uint32_t i = fans.pathBegin[c]; i < fans.pathBegin[c + 1] && usable; ++i)
                usable = label[fans.faces[i]] == group;
            if (usable && (best == UINT32_MAX || fans.pathArea[c] < bestArea)) {
                best = c;
                bestArea = fans.pathArea[c];
            }
        }
        if (best == UINT32_MAX) return;
        for (uint32_t i = fans.pathBegin[best]; i < fans.pathBegin[best + 1]; ++i) isProtected[fans.faces[i]] = 1;
    }

    // The merge at position p of fans.order.
    void protectConnection(const ConnectionFans2D& fans, size_t p) {
        const ModelPair2D& pair = space.pairs[fans.pair[fans.order[p]]];
        const int group = groupOfModel(static_cast<int>(pair.a));
        if (group < 0 || group != groupOfModel(static_cast<int>(pair.b))) return;
        for (int i = 0; i < 2; ++i) {
            const int f = pair.bestFace[i];
            if (!isKeptFree(f, group)) continue;
            isProtected[f] = 1;
            protectFan(fans, 4 * p + 2 * i, group);
            protectFan(fans, 4 * p + 2 * i + 1, group);
            return;
        }
    }

    // True when face f (kept) has an exposed edge longer than its limit.
    bool mustCarve(int f) const {
        const int group = label[f];
        for (int j = 0; j < 3; ++j) {
            const int n = tri().neighbors[3 * f + j];
            if (n >= 0 && label[n] == group) continue;
            const size_t e = 3 * static_cast<size_t>(f) + j;
            if (space.edgeLength[e] > limitOf(space.edgePair[e])) return true;
        }
        return false;
    }

    // Only a face with an edge longer than the level's smallest limit can ever be carved: the
    // others are left off the stack (carving is monotone, so this changes nothing).
    bool mayCarve(int f) const { return space.faceLongest[f] > limits.smallest; }

    // Step 2 (carve.h).
    void carve() {
        const int faceCount = static_cast<int>(tri().faceCount());
        carveFromOutside<3>(
            label,
            [&](auto&& push) {
                for (int f = 0; f < faceCount; ++f) push(f);
            },
            [&](int f, int j) { return tri().neighbors[3 * f + j]; },
            [&](int f) {
                return space.faceModel[f] < 0 && label[f] >= 0 && !isProtected[f] && mayCarve(f) && mustCarve(f);
            });
    }
};

struct HalfEdge {
    int group, from, to, face;
};

}  // namespace

ConnectionFans2D computeConnectionFans2D(const FreeSpace2D& space, const std::vector<uint32_t>& mergePair, int threadCount) {
    const Triangulation2D& tri = space.tri;
    // The merges by their first best face (key: face << 32 | merge).
    std::vector<uint64_t> keyed(mergePair.size());
    for (size_t k = 0; k < mergePair.size(); ++k)
        keyed[k] = static_cast<uint64_t>(static_cast<uint32_t>(space.pairs[mergePair[k]].bestFace[0])) << 32 | k;
    std::sort(keyed.begin(), keyed.end());
    std::vector<uint32_t> order(keyed.size());
    for (size_t p = 0; p < keyed.size(); ++p) order[p] = static_cast<uint32_t>(keyed[p]);
    const size_t count = order.size();
    // Blocks of merges on all threads, each filling its own arrays; joined in block order.
    const size_t blockCount = std::clamp<size_t>(count / 512, 1, 64);
    std::vector<ConnectionFans2D> blocks(blockCount);
    parallelFor(blockCount, threadCount, [&](size_t block) {
        ConnectionFans2D& out = blocks[block];
        std::vector<int> path;
        const size_t first = count * block / blockCount, last = count * (block + 1) / blockCount;
        for (size_t p = first; p < last; ++p) {
            const ModelPair2D& pair = space.pairs[mergePair[order[p]]];
            for (int slot = 0; slot < 4; ++slot) {
                out.slotBegin.push_back(static_cast<uint32_t>(out.pathArea.size()));
                const int f = pair.bestFace[slot / 2];
                const int model = static_cast<int>(slot % 2 == 0 ? pair.a : pair.b);
                if (f < 0 || space.faceModel[f] >= 0) continue;
                bool sharesEdge = false;  // f already shares an edge with the model: no fan
                for (int j = 0; j < 3; ++j) {
                    const int n = tri.neighbors[3 * f + j];
                    if (n >= 0 && space.faceModel[n] == model) sharesEdge = true;
                }
                if (sharesEdge) continue;
                // Walks around each vertex of the model, both ways, to a face of its interior;
                // the level-dependent tests (kept in the group, no longer than delta) are left
                // to protectFan.
                for (int kf = 0; kf < 3; ++kf) {
                    const int v = tri.faces[3 * f + kf];
                    if (space.vertexModel[v] != model) continue;
                    for (int side = 1; side <= 2; ++side) {
                        path.clear();
                        int cur = f;
                        for (int steps = 0; steps < 256; ++steps) {
                            int kv = 0;
                            while (tri.faces[3 * cur + kv] != v) ++kv;
                            const int n = tri.neighbors[3 * cur + (kv + side) % 3];
                            if (n < 0) break;
                            if (space.faceModel[n] == model) {
                                double area = 0, longest = 0;
                                for (int p : path) {
                                    area += space.faceArea[p];
                                    longest = std::max(longest, space.faceLongest[p]);
                                }
                                out.pathLongest.push_back(longest);
                                out.pathBegin.push_back(static_cast<uint32_t>(out.faces.size()));
                                out.faces.insert(out.faces.end(), path.begin(), path.end());
                                out.pathArea.push_back(area);
                                break;
                            }
                            if (space.faceModel[n] >= 0 || n == f) break;
                            path.push_back(n);
                            cur = n;
                        }
                    }
                }
            }
        }
    });
    ConnectionFans2D fans;
    fans.pair = mergePair;
    fans.order = std::move(order);
    fans.slotBegin.reserve(4 * count + 1);
    for (const ConnectionFans2D& b : blocks) {
        const uint32_t candidateOffset = static_cast<uint32_t>(fans.pathArea.size());
        const uint32_t faceOffset = static_cast<uint32_t>(fans.faces.size());
        for (uint32_t s : b.slotBegin) fans.slotBegin.push_back(s + candidateOffset);
        for (uint32_t p : b.pathBegin) fans.pathBegin.push_back(p + faceOffset);
        fans.pathArea.insert(fans.pathArea.end(), b.pathArea.begin(), b.pathArea.end());
        fans.pathLongest.insert(fans.pathLongest.end(), b.pathLongest.begin(), b.pathLongest.end());
        fans.faces.insert(fans.faces.end(), b.faces.begin(), b.faces.end());
    }
    fans.slotBegin.push_back(static_cast<uint32_t>(fans.pathArea.size()));
    fans.pathBegin.push_back(static_cast<uint32_t>(fans.faces.size()));
    return fans;
}

void sculptLevel2D(const FreeSpace2D& space, const std::vector<uint32_t>& modelGroup, const EdgeLimits& limits,
                   const ConnectionFans2D& fans, size_t joinedMerges, std::vector<int>& faceLabel) {
    Sculptor2D s{space, modelGroup, limits, faceLabel, {}};
    s.initialLabels();
    // The level's merges are the first joinedMerges; visited in face order (each protection
    // only reads labels, so the order does not matter).
    for (size_t p = 0; p < fans.order.size(); ++p)
        if (fans.order[p] < joinedMerges) s.protectConnection(fans, p);
    s.carve();
}

Measures2D measureLabels2D(const FreeSpace2D& space, const std::vector<int>& faceLabel) {
    Measures2D m;
    const Triangulation2D& tri = space.tri;
    for (size_t f = 0; f < tri.faceCount(); ++f) {
        if (faceLabel[f] < 0) continue;
        m.area += space.faceArea[f];
        for (int j = 0; j < 3; ++j) {
            const int n = tri.neighbors[3 * f + j];
            if (n < 0 || faceLabel[n] != faceLabel[f]) m.perimeter += space.edgeLength[3 * f + j];
        }
    }
    m.circularity = circularity(m.area, m.perimeter);
    return m;
}

void extractPolygons2D(const FreeSpace2D& space, const std::vector<int>& faceLabel, size_t groupCount,
                       std::vector<Aggregate2D>& aggregates, const std::vector<int>* groupModel) {
    const Triangulation2D& tri = space.tri;
    const size_t faceCount = tri.faceCount();
    aggregates.resize(groupCount);
    // Groups that are one model with nothing kept around it: that model's own polygons (at
    // fine levels, most groups), copied instead of traced.
    std::vector<char> copied(groupCount, 0);
    if (groupModel && !space.modelPolygons.empty()) {
        std::vector<char> filled(groupCount, 0);
        for (size_t f = 0; f < faceCount; ++f)
            if (space.faceModel[f] < 0 && faceLabel[f] >= 0) filled[faceLabel[f]] = 1;
        for (size_t g = 0; g < groupCount; ++g) {
            const int m = (*groupModel)[g];
            if (m < 0 || filled[g] || space.modelPolygons[m].empty()) continue;
            copied[g] = 1;
            aggregates[g].polygons = space.modelPolygons[m];
        }
    }
    // Boundary half-edges, the kept face on their left.
    std::vector<HalfEdge> edges;
    edges.reserve(faceCount);
    for (size_t f = 0; f < faceCount; ++f) {
        const int g = faceLabel[f];
        if (g < 0 || copied[g]) continue;
        for (int j = 0; j < 3; ++j) {
            const int n = tri.neighbors[3 * f + j];
            if (n >= 0 && faceLabel[n] == g) continue;
            edges.push_back({g, tri.faces[3 * f + (j + 1) % 3], tri.faces[3 * f + (j + 2) % 3], static_cast<int>(f)});
        }
    }
    // Sorted by (group, from, to): a counting sort on the group, then small sorts per group.
    {
        std::vector<uint32_t> start;
        std::vector<HalfEdge> bucketed;
        countingSortByBucket(edges, groupCount, [](const HalfEdge& e) { return e.group; }, start, bucketed);
        auto less = [](const HalfEdge& a, const HalfEdge& b) { return a.from != b.from ? a.from < b.from : a.to < b.to; };
        for (size_t g = 0; g < groupCount; ++g) {
            const auto first = bucketed.begin() + start[g], last = bucketed.begin() + start[g + 1];
            if (last - first > 32) {
                std::sort(first, last, less);
                continue;
            }
            for (auto i = first + (first != last); i < last; ++i)  // the usual case: a few edges
                for (auto j = i; j > first && less(*j, *(j - 1)); --j) std::iter_swap(j - 1, j);
        }
        edges = std::move(bucketed);
    }
    // Face components (edge-connected kept faces of one group): holes join the exterior of
    // theirs. Built only when a level has a hole.
    DisjointSets components;
    auto componentOf = [&](int face) {
        if (components.size() == 0) {
            components.reset(faceCount);
            for (size_t f = 0; f < faceCount; ++f) {
                if (faceLabel[f] < 0) continue;
                for (int j = 0; j < 3; ++j) {
                    const int n = tri.neighbors[3 * f + j];
                    if (n < 0 || faceLabel[n] != faceLabel[f]) continue;
                    components.unite(static_cast<uint32_t>(f), static_cast<uint32_t>(n));
                }
            }
        }
        return components.find(static_cast<uint32_t>(face));
    };
    auto px = [&](int v) { return tri.points[2 * static_cast<size_t>(v)]; };
    auto py = [&](int v) { return tri.points[2 * static_cast<size_t>(v) + 1]; };
    std::vector<char> used(edges.size(), 0);
    struct Loop {
        std::vector<double> ring;
        double area;
        int face;  // a face on the loop's left: its component
    };
    std::vector<Loop> loops;
    size_t groupBegin = 0;
    std::vector<size_t> trace, stack, polygonComponent, exteriorLoop;
    std::vector<size_t> stackPos(tri.vertexCount(), SIZE_MAX);  // per vertex: its place on the stack
    std::vector<size_t> firstOut(tri.vertexCount(), SIZE_MAX);   // per vertex: its first edge in the current group
    while (groupBegin < edges.size()) {
        const int g = edges[groupBegin].group;
        size_t groupEnd = groupBegin;
        while (groupEnd < edges.size() && edges[groupEnd].group == g) ++groupEnd;
        for (size_t i = groupBegin; i < groupEnd; ++i)
            if (i == groupBegin || edges[i].from != edges[i - 1].from) firstOut[static_cast<size_t>(edges[i].from)] = i;
        loops.clear();
        // The group's edges leaving v: a run of the sorted edges (empty when there is none;
        // firstOut entries left from earlier groups lie before this group's range).
        auto outgoing = [&](int v) {
            const size_t lo = firstOut[static_cast<size_t>(v)];
            if (lo < groupBegin || lo >= groupEnd || edges[lo].from != v) return std::make_pair(groupEnd, groupEnd);
            size_t hi = lo + 1;
            while (hi < groupEnd && edges[hi].from == v) ++hi;
            return std::make_pair(lo, hi);
        };
        for (size_t start = groupBegin; start < groupEnd; ++start) {
            if (used[start]) continue;
            // Trace: at each vertex take the first outgoing edge clockwise from the way back.
            trace.clear();
            size_t cur = start;
            for (size_t guard = 0; guard <= groupEnd - groupBegin; ++guard) {
                used[cur] = 1;
                trace.push_back(cur);
                const HalfEdge& e = edges[cur];
                auto [lo, hi] = outgoing(e.to);
                if (hi - lo == 1) {  // the usual case: a single way on
                    if (lo == start || !used[lo]) {
                        if (lo == start) break;
                        cur = lo;
                        continue;
                    }
                    break;
                }
                const double backAngle = std::atan2(py(e.from) - py(e.to), px(e.from) - px(e.to));
                size_t next = SIZE_MAX;
                double bestTurn = INFINITY;
                for (size_t c = lo; c < hi; ++c) {
                    if (used[c] && c != start) continue;
                    const double a = std::atan2(py(edges[c].to) - py(e.to), px(edges[c].to) - px(e.to));
                    double turn = backAngle - a;  // clockwise angle from the way back
                    while (turn <= 0) turn += 2 * M_PI;
                    while (turn > 2 * M_PI) turn -= 2 * M_PI;
                    if (turn < bestTurn) {
                        bestTurn = turn;
                        next = c;
                    }
                }
                if (next == SIZE_MAX || next == start) break;
                cur = next;
            }
            // Split at repeated vertices so every ring is simple.
            stack.clear();
            auto emit = [&](size_t fromIndex) {
                Loop loop;
                loop.ring.reserve(2 * (stack.size() - fromIndex));
                for (size_t i = fromIndex; i < stack.size(); ++i) {
                    loop.ring.push_back(px(edges[stack[i]].from));
                    loop.ring.push_back(py(edges[stack[i]].from));
                }
                loop.area = ringSignedArea(loop.ring);
                loop.face = edges[stack[fromIndex]].face;
                for (size_t i = fromIndex; i < stack.size(); ++i) stackPos[edges[stack[i]].from] = SIZE_MAX;
                stack.resize(fromIndex);
                if (loop.ring.size() >= 6 && loop.area != 0) loops.push_back(std::move(loop));
            };
            for (size_t h : trace) {
                if (stackPos[edges[h].from] != SIZE_MAX) emit(stackPos[edges[h].from]);
                stackPos[edges[h].from] = stack.size();
                stack.push_back(h);
            }
            if (!stack.empty()) emit(0);
        }
        // Exteriors (counter-clockwise) and holes (clockwise), holes to the exterior of their component.
        Aggregate2D& agg = aggregates[g];
        polygonComponent.clear();
        exteriorLoop.clear();
        for (size_t i = 0; i < loops.size(); ++i) {
            if (loops[i].area <= 0) continue;
            exteriorLoop.push_back(i);
            agg.polygons.push_back(Polygon2D{std::move(loops[i].ring), {}});
            polygonComponent.push_back(SIZE_MAX);  // filled when a hole needs it
        }
        for (size_t i = 0; i < loops.size(); ++i) {
            if (loops[i].area > 0) continue;
            size_t best = SIZE_MAX;
            double bestArea = INFINITY;
            const double mx = 0.5 * (loops[i].ring[0] + loops[i].ring[2]);
            const double my = 0.5 * (loops[i].ring[1] + loops[i].ring[3]);
            const uint32_t holeComponent = componentOf(loops[i].face);
            for (size_t p = 0; p < agg.polygons.size(); ++p) {
                if (polygonComponent[p] == SIZE_MAX) polygonComponent[p] = componentOf(loops[exteriorLoop[p]].face);
                if (polygonComponent[p] != holeComponent) continue;
                const std::vector<double>& ring = agg.polygons[p].exterior;
                const double a = ringSignedArea(ring);
                if (a >= bestArea) continue;
                // Point in ring (the hole edge midpoint is never on another ring's edge).
                bool inside = false;
                const size_t n = ring.size() / 2;
                for (size_t s = 0, t = n - 1; s < n; t = s++) {
                    const double xi = ring[2 * s], yi = ring[2 * s + 1], xj = ring[2 * t], yj = ring[2 * t + 1];
                    if ((yi > my) != (yj > my) && mx < (xj - xi) * (my - yi) / (yj - yi) + xi) inside = !inside;
                }
                if (inside) {
                    best = p;
                    bestArea = a;
                }
            }
            if (best != SIZE_MAX) agg.polygons[best].holes.push_back(std::move(loops[i].ring));
        }
        groupBegin = groupEnd;
    }
    for (Aggregate2D& agg : aggregates) {
        Measures2D m;
        for (const Polygon2D& p : agg.polygons) {
            m.area += ringSignedArea(p.exterior);
            m.perimeter += ringLength(p.exterior);
            for (const auto& h : p.holes) {
                m.area += ringSignedArea(h);
                m.perimeter += ringLength(h);
            }
        }
        m.circularity = circularity(m.area, m.perimeter);
        agg.measures = m;
    }
}

std::vector<double> convexHull2D(std::vector<double> points) {
    const size_t n = points.size() / 2;
    std::vector<std::pair<double, double>> p(n);
    for (size_t i = 0; i < n; ++i) p[i] = {points[2 * i], points[2 * i + 1]};
    std::sort(p.begin(), p.end());
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) {
        std::vector<double> out;
        for (auto& q : p) { out.push_back(q.first); out.push_back(q.second); }
        return out;
    }
    auto cross = [](const std::pair<double, double>& o, const std::pair<double, double>& a,
                    const std::pair<double, double>& b) {
        return (a.first - o.first) * (b.second - o.second) - (a.second - o.second) * (b.first - o.first);
    };
    std::vector<std::pair<double, double>> h(2 * p.size());
    size_t k = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
        while (k >= t && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    h.resize(k - 1);
    std::vector<double> out;
    out.reserve(2 * h.size());
    for (auto& q : h) { out.push_back(q.first); out.push_back(q.second); }
    return out;
}

}  // namespace aggrelod::detail
