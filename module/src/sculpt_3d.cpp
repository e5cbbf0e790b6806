// SPDX-License-Identifier: AGPL-3.0-or-later
// Sculpting (docs/design.md §2.4; paper Section 3.3 "Aggregated Approximation", 3D as Section 4.4)
// and surface extraction of the aggregates.
//
// Step 1 drops free tets whose owned vertices belong to several groups (or to none).
// Step 2 carves from the outside: a kept free tet with an exposed facet (on the hull or
// facing a tet outside its group's solid) is removed when an edge of such a facet is
// longer than F(m1, m2). Carving is monotone (removing a tet only exposes more), so the
// removed set does not depend on visiting order (a longest-edge-first queue would give that
// too; monotonicity already does, and a stack is linear instead of n log n).
// Step 4 keeps, for every pair joined at this level, a face-connected chain of tets from
// one model's surface to the other's along the shortest connection (A* over tet
// adjacency, Euclidean costs), so joined models always come out as one solid.
#include "sculpt_3d.h"

#include "carve.h"
#include "parallel_for.h"
#include "radix_sort.h"

#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <deque>
#include <iterator>
#include <cmath>
#include <numeric>
#include <queue>
#include <tuple>

namespace aggrelod::detail {
namespace {

// Corners of the face opposite corner j, ordered so the normal points out of a
// positively oriented tet.
constexpr int kFaceCorners[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

// Tet edges (corner pairs) in FreeSpace::tetEdgeLength order, and for each face (opposite
// corner j) the bit set of its three edges: those that do not touch corner j.
constexpr int kTetEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
constexpr unsigned kEdgesOfFace[4] = {0b111000, 0b100110, 0b010101, 0b001011};

double distance3(const double* a, const double* b) {
    const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

struct Sculptor {
    const FreeSpace& space;
    const LevelShapeRequest& request;
    std::vector<int>& label;
    const TetMesh& mesh;
    std::vector<char> isProtected;

    const EdgeLimits* limits;

    Sculptor(const FreeSpace& s, const LevelShapeRequest& r, std::vector<int>& l)
        : space(s), request(r), label(l), mesh(s.mesh), limits(r.limits) {}

    const double* point(int v) const { return &mesh.points[3 * static_cast<size_t>(v)]; }

    int groupOfModel(int m) const { return m < 0 ? -1 : static_cast<int>((*request.modelGroup)[m]); }

    // Tets that can take part in this level's shape, ascending: after step 1, the kept free
    // tets and the object tets with a face on their model's surface. Carving and the
    // clean-up's first pass only remove, so their full scans visit these instead of every
    // tet of the mesh (object interiors and the free space no group claims are most of it).
    std::vector<int> active;
    // Tets the clean-up added to a solid (not in `active`).
    std::vector<int> addedTets;

    // Step 1: object interiors take their model's group; a free tet takes the single group
    // of its owned vertices, or -1.
    void initialLabels() {
        const size_t tetCount = mesh.tetCount();
        label.assign(tetCount, -1);
        active.clear();
        for (size_t t = 0; t < tetCount; ++t) {
            if (space.tetModel[t] >= 0) {
                label[t] = groupOfModel(space.tetModel[t]);
                if (label[t] >= 0 && space.objectFaceMask[t]) active.push_back(static_cast<int>(t));
                continue;
            }
            int group = -1;
            bool mixed = false;
            for (int k = 0; k < 4; ++k) {
                int g = groupOfModel(space.vertexModel[mesh.tets[4 * t + k]]);
                if (g < 0) continue;
                if (group < 0) group = g;
                else if (g != group) mixed = true;
            }
            label[t] = mixed ? -1 : group;
            if (label[t] >= 0) active.push_back(static_cast<int>(t));
        }
    }

    // Faces of t that can lie on a surface: all four for a free tet, the model-surface
    // faces for an object tet.
    unsigned candidateFaces(size_t t) const { return space.tetModel[t] >= 0 ? space.objectFaceMask[t] : 0xFu; }

    bool isKeptFree(int t, int group) const { return t >= 0 && space.tetModel[t] < 0 && label[t] == group; }

    // Longest exposed edge of tet t longer than its limit (0 if none).
    double carvePriority(int t) const {
        const int group = label[t];
        // Bit e set: tet edge e lies on an exposed facet (edge e avoids corner j of facet j).
        unsigned exposedEdges = 0;
        for (int j = 0; j < 4; ++j) {
            int n = mesh.neighbors[4 * t + j];
            if (n >= 0 && label[n] == group) continue;  // facet not exposed
            exposedEdges |= kEdgesOfFace[j];
        }
        double worst = 0;
        for (int e = 0; e < 6; ++e) {
            if (!(exposedEdges & (1u << e))) continue;
            const double len = space.tetEdgeLength[6 * static_cast<size_t>(t) + e];
            if (len > worst && len > limitOfEdge(space.tetEdgePair[6 * static_cast<size_t>(t) + e])) worst = len;
        }
        return worst;
    }

    double limitOfEdge(int pairIndex) const {
        if (pairIndex >= 0) return limits->pair[pairIndex];
        return pairIndex == kSameModelEdge ? limits->sameModel : limits->unpaired;
    }

    // Step 4: face-connected chain of kept tets from model a's surface to model b's surface.
    void protectConnection(const ProtectedConnection& c) {
        const int group = groupOfModel(static_cast<int>(c.modelA));
        if (group < 0 || group != groupOfModel(static_cast<int>(c.modelB))) return;
        const size_t tetCount = mesh.tetCount();
        auto centroid = [&](int t, double out[3]) {
            out[0] = out[1] = out[2] = 0;
            for (int k = 0; k < 4; ++k)
                for (int d = 0; d < 3; ++d) out[d] += 0.25 * point(mesh.tets[4 * t + k])[d];
        };
        auto touchesModel = [&](int t, int model) {
            for (int j = 0; j < 4; ++j) {
                int n = mesh.neighbors[4 * t + j];
                if (n >= 0 && space.tetModel[n] == model) return true;
            }
            return false;
        };
        // Sources: kept free tets with a facet on a's surface, found by scanning the
        // interior tets of a (their free neighbours).
        using Entry = std::tuple<double, double, int>;  // f = g + h, g, tet
        std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
        std::vector<double>& best = scratchBest;
        std::vector<int>& from = scratchFrom;
        if (best.size() != tetCount) {
            best.assign(tetCount, INFINITY);
            from.assign(tetCount, -1);
        }
        std::vector<int>& touched = scratchTouched;
        touched.clear();
        // Only the few surface tets nearest the closest point start the search: the chain
        // has to leave a's surface there, and a large model has hundreds of surface tets.
        constexpr size_t kSources = 8;
        std::vector<Entry>& sources = scratchSources;
        sources.clear();
        for (int t : modelSurfaceTets(static_cast<int>(c.modelA))) {
            if (!isKeptFree(t, group)) continue;
            double cen[3];
            centroid(t, cen);
            const double g = distance3(cen, c.pointA);
            sources.emplace_back(g + distance3(cen, c.pointB), g, t);
        }
        const size_t keep = std::min(kSources, sources.size());
        std::partial_sort(sources.begin(), sources.begin() + keep, sources.end());
        for (size_t k = 0; k < keep; ++k) {
            const auto [f, g, t] = sources[k];
            if (best[t] == INFINITY) touched.push_back(t);
            best[t] = g;
            from[t] = -1;
            open.emplace(f, g, t);
        }
        int reached = -1;
        size_t expansions = 0;
        while (!open.empty()) {
            auto [f, g, t] = open.top();
            open.pop();
            if (g > best[t]) continue;
            if (touchesModel(t, static_cast<int>(c.modelB))) {
                reached = t;
                break;
            }
            if (++expansions > 4 * tetCount + 16) break;  // cannot happen; guards against a hang
            double ct[3];
            centroid(t, ct);
            for (int j = 0; j < 4; ++j) {
                int n = mesh.neighbors[4 * t + j];
                if (!isKeptFree(n, group)) continue;
                double cn[3];
                centroid(n, cn);
                double gn = g + distance3(ct, cn);
                if (gn < best[n]) {
                    if (best[n] == INFINITY) touched.push_back(n);
                    best[n] = gn;
                    from[n] = t;
                    open.emplace(gn + distance3(cn, c.pointB), gn, n);
                }
            }
        }
        for (int t = reached; t >= 0; t = from[t]) isProtected[t] = 1;
        for (int t : touched) {
            best[t] = INFINITY;
            from[t] = -1;
        }
    }

    std::vector<double> scratchBest;
    std::vector<std::tuple<double, double, int>> scratchSources;
    std::vector<int> scratchFrom, scratchTouched;
    const std::vector<int>& modelSurfaceTets(int model) const { return space.surfaceTetsOfModel[model]; }

    // Kept free tets that cannot reach an object of their group through faces of the
    // group's solid are removed (they would touch it only along an edge or at a vertex).
    // Floods start from kept free tets only and stop at the first object tet (or tet
    // already known to be anchored) of the group, so object interiors are never walked.
    std::vector<unsigned char> floodState;  // per tet, scratch: 0 unknown, 1 anchored / outer
    std::vector<int> floodMembers;
    // fullScan: every kept free tet starts a flood. Otherwise only the kept free neighbours
    // of tets removed since the last pass do: an island can only be cut off by a removal.
    bool removeIslands(bool fullScan) {
        const size_t tetCount = mesh.tetCount();
        floodState.assign(tetCount, 0);
        std::vector<int>& members = floodMembers;
        bool changed = false;
        auto floodFrom = [&](int s) {
            if (space.tetModel[s] >= 0 || label[s] < 0 || floodState[s]) return;
            const int g = label[s];
            members.clear();
            members.push_back(s);
            floodState[s] = 2;  // in the current flood
            bool anchored = false;
            for (size_t head = 0; head < members.size() && !anchored; ++head) {
                const int t = members[head];
                for (int j = 0; j < 4; ++j) {
                    const int n = mesh.neighbors[4 * t + j];
                    if (n < 0 || label[n] != g) continue;
                    if (space.tetModel[n] >= 0 || floodState[n] == 1) {
                        anchored = true;
                        break;
                    }
                    if (floodState[n] == 0) {
                        floodState[n] = 2;
                        members.push_back(n);
                    }
                }
            }
            for (int t : members) floodState[t] = 1;
            if (!anchored) {
                for (int t : members) setLabel(t, -1);
                changed = true;
            }
        };
        std::vector<int> removed;
        removed.swap(removedSinceIslands);
        if (fullScan) {
            for (int t : active) floodFrom(t);  // only removals so far: kept free tets are in it
        } else {
            for (int r : removed)
                for (int j = 0; j < 4; ++j) {
                    const int n = mesh.neighbors[4 * r + j];
                    if (n >= 0) floodFrom(n);
                }
        }
        return changed;
    }

    // Closed cavities: connected free space not exposed to the outside (hull) and bordered
    // by one group only is filled, so every aggregate is one shell without inner voids.
    // A cavity borders its group, so floods start only from free tets next to a solid, and
    // stop as soon as they meet the hull, a second group or space already known to be
    // outside: most of the free space is never walked.
    // fullScan as for removeIslands; otherwise floods start only at tets changed since the
    // last pass and their neighbours (a new cavity needs a removal or a fill next to it).
    bool fillVoids(bool fullScan) {
        const size_t tetCount = mesh.tetCount();
        floodState.assign(tetCount, 0);
        std::vector<int>& members = floodMembers;
        bool changed = false;
        auto floodFrom = [&](int s) {
            if (label[s] >= 0 || floodState[s]) return;
            members.clear();
            members.push_back(s);
            floodState[s] = 2;
            int border = -1;  // the single bordering group, -2 when several or the hull
            for (size_t head = 0; head < members.size() && border != -2; ++head) {
                const int t = members[head];
                for (int j = 0; j < 4; ++j) {
                    const int n = mesh.neighbors[4 * t + j];
                    if (n < 0) {
                        border = -2;
                        break;
                    }
                    if (label[n] < 0) {
                        if (floodState[n] == 1) {
                            border = -2;  // joins space already known to be outside
                            break;
                        }
                        if (floodState[n] == 0) {
                            floodState[n] = 2;
                            members.push_back(n);
                        }
                        continue;
                    }
                    if (border == -1) border = label[n];
                    else if (border != label[n]) {
                        border = -2;
                        break;
                    }
                }
            }
            if (border >= 0) {
                for (int t : members) setLabel(t, border);
                changed = true;
            } else {
                for (int t : members) floodState[t] = 1;
            }
        };
        std::vector<int> changedTets;
        changedTets.swap(changedSinceVoids);
        if (fullScan) {
            // Seeds next to every solid tet: those of `active` and those the edge repair
            // added. Which cavities get filled does not depend on the seed order (a cavity is
            // a connected component of unclaimed space, judged whole).
            auto seedAround = [&](int t) {
                if (label[t] < 0) return;
                const unsigned faces = candidateFaces(static_cast<size_t>(t));
                for (int j = 0; j < 4; ++j) {
                    if (!(faces & (1u << j))) continue;
                    const int n = mesh.neighbors[4 * t + j];
                    if (n >= 0) floodFrom(n);
                }
            };
            for (int t : active) seedAround(t);
            for (size_t k = 0; k < addedTets.size(); ++k) seedAround(addedTets[k]);
        } else {
            for (int t : changedTets) {
                floodFrom(t);
                for (int j = 0; j < 4; ++j) {
                    const int n = mesh.neighbors[4 * t + j];
                    if (n >= 0) floodFrom(n);
                }
            }
        }
        return changed;
    }

    // Tets around edge (u, v), starting from tet t0 which contains it. When the ring
    // reaches the hull it is open and holds the tets of both sides.
    bool edgeRing(int t0, int u, int v, std::vector<int>& ring) const {
        auto local = [&](int t, int w) {
            for (int k = 0; k < 4; ++k)
                if (mesh.tets[4 * t + k] == w) return k;
            return -1;
        };
        ring.clear();
        ring.push_back(t0);
        int others[2], k = 0;
        for (int c = 0; c < 4; ++c)
            if (c != local(t0, u) && c != local(t0, v)) others[k++] = c;
        for (int direction = 0; direction < 2; ++direction) {
            int t = t0;
            int cross = others[direction];
            for (int guard = 0; guard < 1024; ++guard) {
                int n = mesh.neighbors[4 * t + cross];
                if (n < 0) break;       // open ring: walk the other way too
                if (n == t0) return true;  // closed ring complete
                int lu = local(n, u), lv = local(n, v), entered = -1;
                for (int c = 0; c < 4; ++c)
                    if (mesh.neighbors[4 * n + c] == t && c != lu && c != lv) entered = c;
                if (lu < 0 || lv < 0 || entered < 0) return false;
                ring.push_back(n);
                t = n;
                cross = 6 - lu - lv - entered;
            }
        }
        return false;
    }

    // Edges where the group's solid meets itself only along the edge (more than two
    // surface faces): fill the gap tets when they are all unclaimed free space, else
    // remove the free unprotected solid tets around the edge.
    // Tets whose label changed during clean-up (the next round only looks near them).
    std::vector<int> changedTets;
    bool openedByRepair = false;  ///< the last repair removed solid tets (islands may follow)
    // Per tet: 1 once removed, 2 once added by the clean-up. The edge repair never undoes
    // what the clean-up did, so the rounds cannot cycle.
    std::vector<unsigned char> cleanUpHistory;
    std::vector<int> removedSinceIslands, changedSinceVoids;
    void setLabel(int t, int value) {
        label[t] = value;
        changedTets.push_back(t);
        changedSinceVoids.push_back(t);
        if (value < 0) removedSinceIslands.push_back(t);
        else if (!(cleanUpHistory.size() && (cleanUpHistory[t] & 2))) addedTets.push_back(t);
        if (cleanUpHistory.empty()) cleanUpHistory.assign(mesh.tetCount(), 0);
        cleanUpHistory[t] |= value < 0 ? 1 : 2;
    }
    bool wasAdded(int t) const { return !cleanUpHistory.empty() && (cleanUpHistory[t] & 2); }
    bool wasRemoved(int t) const { return !cleanUpHistory.empty() && (cleanUpHistory[t] & 1); }

    struct EdgeUse {
        int u, v, group, tet;
    };
    std::vector<EdgeUse> repairUses, repairByVertex;  // scratch of repairNonManifoldEdges
    std::vector<uint32_t> repairStart;

    bool repairNonManifoldEdges(bool fullScan) {
        std::vector<EdgeUse>& uses = repairUses;
        uses.clear();
        auto collectFaces = [&](int t) {
            const int g = label[t];
            if (g < 0) return;
            const unsigned faces = candidateFaces(static_cast<size_t>(t));
            for (int j = 0; j < 4; ++j) {
                if (!(faces & (1u << j))) continue;
                int n = mesh.neighbors[4 * t + j];
                if (n >= 0 && label[n] == g) continue;
                for (int e = 0; e < 3; ++e) {
                    int u = mesh.tets[4 * t + kFaceCorners[j][e]];
                    int v = mesh.tets[4 * t + kFaceCorners[j][(e + 1) % 3]];
                    uses.push_back({std::min(u, v), std::max(u, v), g, t});
                }
            }
        };
        if (fullScan) {
            for (int t : active) collectFaces(t);  // first pass: only removals so far
        } else {
            // Only edges near tets changed in the previous round; their fans are checked
            // whole below (ring runs), since the unchanged faces were not collected.
            std::vector<int> near;
            for (int t : changedTets) {
                near.push_back(t);
                for (int j = 0; j < 4; ++j)
                    if (mesh.neighbors[4 * t + j] >= 0) near.push_back(mesh.neighbors[4 * t + j]);
            }
            std::sort(near.begin(), near.end());
            near.erase(std::unique(near.begin(), near.end()), near.end());
            for (int t : near) collectFaces(t);
        }
        changedTets.clear();
        auto useLess = [](const EdgeUse& a, const EdgeUse& b) {
            return std::tie(a.group, a.u, a.v, a.tet) < std::tie(b.group, b.u, b.v, b.tet);
        };
        if (fullScan) {
            // Every surface edge: only those on more than two faces of a group are work.
            // Bucketed by the first vertex (counting sort), each small bucket sorted alone;
            // the few edges kept are then sorted as the work list expects. Same list as
            // sorting all uses, without sorting hundreds of thousands of them.
            const size_t pointCount = mesh.pointCount();
            std::vector<uint32_t>& start = repairStart;
            std::vector<EdgeUse>& byVertex = repairByVertex;
            countingSortByBucket(uses, pointCount, [](const EdgeUse& use) { return use.u; }, start, byVertex);
            uses.clear();
            for (size_t p = 0; p < pointCount; ++p) {
                EdgeUse* b = byVertex.data() + start[p];
                EdgeUse* e = byVertex.data() + start[p + 1];
                if (e - b < 3) continue;
                std::sort(b, e, useLess);
                for (EdgeUse* i = b; i != e;) {
                    EdgeUse* j = i;
                    while (j != e && j->group == i->group && j->v == i->v) ++j;
                    if (j - i > 2) uses.insert(uses.end(), i, j);
                    i = j;
                }
            }
        }
        std::sort(uses.begin(), uses.end(), useLess);
        // Work list of edges to examine, in a deterministic order: first the candidates,
        // then the edges of every tet a repair changed (a repair can make a neighbour edge
        // non-manifold), until none is left. The cap only guards against a cycle.
        std::deque<EdgeUse> work;
        for (size_t i = 0; i < uses.size();) {
            size_t j = i;
            while (j < uses.size() && uses[j].group == uses[i].group && uses[j].u == uses[i].u && uses[j].v == uses[i].v) ++j;
            if (!fullScan || j - i > 2) work.push_back(uses[i]);
            i = j;
        }
        size_t budget = 64 * work.size() + 4096;
        bool changed = false;
        std::vector<int> ring;
        std::vector<std::pair<size_t, size_t>> runs;  // [begin, end) in ring
        std::vector<int> touched;
        while (!work.empty() && budget-- > 0) {
            const EdgeUse edge = work.front();
            work.pop_front();
            const int g = edge.group;
            const bool closedRing = edgeRing(edge.tet, edge.u, edge.v, ring);
            // Runs of consecutive tets in or out of the solid around the edge; on a closed
            // ring the last run continues the first.
            runs.clear();
            for (size_t k = 0; k < ring.size();) {
                size_t e = k;
                const bool in = label[ring[k]] == g;
                while (e < ring.size() && (label[ring[e]] == g) == in) ++e;
                runs.emplace_back(k, e);
                k = e;
            }
            size_t solidRuns = 0;
            for (auto r : runs)
                if (label[ring[r.first]] == g) ++solidRuns;
            if (closedRing && runs.size() > 1 && label[ring[runs.front().first]] == g && label[ring[runs.back().first]] == g)
                --solidRuns;
            if (solidRuns < 2) continue;
            auto fillable = [&](std::pair<size_t, size_t> r) {
                for (size_t k = r.first; k < r.second; ++k)
                    if (space.tetModel[ring[k]] >= 0 || label[ring[k]] >= 0 || wasRemoved(ring[k])) return false;
                return true;
            };
            auto openable = [&](std::pair<size_t, size_t> r) {
                for (size_t k = r.first; k < r.second; ++k)
                    if (label[ring[k]] != g || space.tetModel[ring[k]] >= 0 || isProtected[ring[k]] || wasAdded(ring[k]))
                        return false;
                return true;
            };
            // Prefer opening a run of free fill (carving already judged such fill
            // marginal, and the solid only shrinks); fill a gap only where no run of the
            // solid can be opened (object interiors or protected connections).
            touched.clear();
            int newLabel = -1;
            for (auto r : runs)
                if (label[ring[r.first]] == g && openable(r)) {
                    for (size_t k = r.first; k < r.second; ++k) touched.push_back(ring[k]);
                    break;
                }
            if (touched.empty()) {
                newLabel = g;
                for (auto r : runs)
                    if (label[ring[r.first]] != g && fillable(r)) {
                        for (size_t k = r.first; k < r.second; ++k) touched.push_back(ring[k]);
                        break;
                    }
            }
            if (touched.empty()) continue;  // neither side can change: left as is
            changed = true;
            if (newLabel < 0) openedByRepair = true;
            for (int t : touched) setLabel(t, newLabel);
            for (int t : touched)
                for (const auto& e : kTetEdges) {
                    int u = mesh.tets[4 * t + e[0]], v = mesh.tets[4 * t + e[1]];
                    work.push_back({std::min(u, v), std::max(u, v), g, t});
                }
        }
        return changed;
    }

    // Step 2 (carve.h): only the active tets can be kept free ones.
    void carve() {
        carveFromOutside<4>(
            label,
            [&](auto&& push) {
                for (int t : active) push(t);
            },
            [&](int t, int j) { return mesh.neighbors[4 * t + j]; },
            [&](int t) { return space.tetModel[t] < 0 && label[t] >= 0 && !isProtected[t] && carvePriority(t) > 0; });
    }
};

}  // namespace

// The per-tet and per-edge buffers of one level, kept between levels on one thread.
struct SculptScratch::Buffers {
    std::vector<char> isProtected;
    std::vector<unsigned char> floodState, cleanUpHistory;
    std::vector<double> best;  // all +inf between uses
    std::vector<int> from;     // all -1 between uses
    std::vector<int> floodMembers, active, addedTets, changedTets, removedSinceIslands, changedSinceVoids;
    std::vector<Sculptor::EdgeUse> repairUses, repairByVertex;
    std::vector<uint32_t> repairStart;
    // extractSurfaces
    std::vector<int> faceIndexOf;  // all -1 between uses
    std::vector<std::pair<int, int>> allFaces, byGroup;
    std::vector<uint32_t> faceGroup;
    std::vector<uint64_t> edgeKeys;
    std::vector<int> edgeUse, twinEdge;
};

SculptScratch::SculptScratch() : buffers(std::make_unique<Buffers>()) {}
SculptScratch::~SculptScratch() = default;

namespace {
// Lends the scratch buffers to a Sculptor for its lifetime (swaps keep their capacity).
struct BorrowedBuffers {
    Sculptor& s;
    SculptScratch::Buffers* b;
    BorrowedBuffers(Sculptor& sculptor, SculptScratch* scratch) : s(sculptor), b(scratch ? scratch->buffers.get() : nullptr) {
        swapAll();
        // State that must start empty (the rest is assigned before use, or kept in its
        // neutral state between uses).
        s.cleanUpHistory.clear();
        s.addedTets.clear();
        s.changedTets.clear();
        s.removedSinceIslands.clear();
        s.changedSinceVoids.clear();
    }
    ~BorrowedBuffers() { swapAll(); }
    void swapAll() {
        if (!b) return;
        s.isProtected.swap(b->isProtected);
        s.floodState.swap(b->floodState);
        s.cleanUpHistory.swap(b->cleanUpHistory);
        s.scratchBest.swap(b->best);
        s.scratchFrom.swap(b->from);
        s.floodMembers.swap(b->floodMembers);
        s.active.swap(b->active);
        s.addedTets.swap(b->addedTets);
        s.changedTets.swap(b->changedTets);
        s.removedSinceIslands.swap(b->removedSinceIslands);
        s.changedSinceVoids.swap(b->changedSinceVoids);
        s.repairUses.swap(b->repairUses);
        s.repairByVertex.swap(b->repairByVertex);
        s.repairStart.swap(b->repairStart);
    }
};
}  // namespace

void precomputeTetEdges(FreeSpace& space, int threadCount) {
    const TetMesh& mesh = space.mesh;
    const size_t tetCount = mesh.tetCount();
    space.surfaceTetsOfModel.assign(space.modelCount, {});
    for (size_t t = 0; t < tetCount; ++t) {
        if (space.tetModel[t] >= 0) continue;
        for (int j = 0; j < 4; ++j) {
            int n = mesh.neighbors[4 * t + j];
            if (n >= 0 && space.tetModel[n] >= 0) {
                auto& list = space.surfaceTetsOfModel[space.tetModel[n]];
                if (list.empty() || list.back() != static_cast<int>(t)) list.push_back(static_cast<int>(t));
            }
        }
    }
    space.objectFaceMask.assign(tetCount, 0);
    for (size_t t = 0; t < tetCount; ++t) {
        if (space.tetModel[t] < 0) continue;
        for (int j = 0; j < 4; ++j) {
            const int n = mesh.neighbors[4 * t + j];
            if (n < 0 || space.tetModel[n] != space.tetModel[t]) space.objectFaceMask[t] |= static_cast<uint8_t>(1u << j);
        }
    }
    space.tetEdgeLength.resize(6 * tetCount);
    space.tetEdgePair.resize(6 * tetCount);
    // Blocks of tets on several threads; each tet writes only its own six slots.
    constexpr size_t kBlock = 16384;
    parallelFor((tetCount + kBlock - 1) / kBlock, threadCount, [&](size_t block) {
    const size_t end = std::min(tetCount, (block + 1) * kBlock);
    for (size_t t = block * kBlock; t < end; ++t)
        for (int e = 0; e < 6; ++e) {
            const int u = mesh.tets[4 * t + kTetEdges[e][0]], v = mesh.tets[4 * t + kTetEdges[e][1]];
            space.tetEdgeLength[6 * t + e] = distance3(&mesh.points[3 * static_cast<size_t>(u)], &mesh.points[3 * static_cast<size_t>(v)]);
            int mu = space.vertexModel[u], mv = space.vertexModel[v];
            if (mu < 0) mu = mv;
            if (mv < 0) mv = mu;
            int pair = kSameModelEdge;
            if (mu >= 0 && mu != mv) {
                pair = findPair(space.pairs, static_cast<uint32_t>(mu), static_cast<uint32_t>(mv));
                if (pair < 0) pair = kUnpairedEdge;
            }
            space.tetEdgePair[6 * t + e] = pair;
        }
    });
}

void sculptLevel(const FreeSpace& space, const LevelShapeRequest& request, std::vector<int>& tetLabel,
                 std::vector<int>* baselineLabel, std::vector<int>* surfaceTets, SculptScratch* scratch) {
    Sculptor sculptor(space, request, tetLabel);
    BorrowedBuffers borrowed(sculptor, scratch);
    sculptor.initialLabels();
    sculptor.isProtected.assign(space.mesh.tetCount(), 0);
    for (const ProtectedConnection& c : request.connections) sculptor.protectConnection(c);
    if (request.baselineLimits && baselineLabel) {
        // Same groups, same protected connections: only the carving limits differ.
        *baselineLabel = tetLabel;
        Sculptor baseline(space, request, *baselineLabel);
        baseline.active = sculptor.active;
        baseline.limits = request.baselineLimits;
        baseline.isProtected = sculptor.isProtected;
        baseline.carve();
    }
    sculptor.carve();
    // Clean-up for a manifold result: drop fill not face-connected to its group's objects,
    // and open or fill the tets around edges where a solid touches itself only along an
    // edge. Each round only changes free tets; a few rounds settle it.
    // Every tet that can hold a surface face: `active` and what the clean-up added.
    auto listSurfaceTets = [&] {
        if (!surfaceTets) return;
        std::vector<int>& list = *surfaceTets;
        list = sculptor.addedTets;
        std::sort(list.begin(), list.end());
        std::vector<int> merged;
        merged.reserve(sculptor.active.size() + list.size());
        std::set_union(sculptor.active.begin(), sculptor.active.end(), list.begin(), list.end(), std::back_inserter(merged));
        list.swap(merged);
    };
    if (!request.cleanUp) {
        listSurfaceTets();
        return;
    }
    // Islands appear only where tets are removed; voids are filled in the same round; the
    // edge repair follows its own changes. So another round is needed only when the repair
    // opened something (new islands are possible then).
    for (int round = 0; round < 8; ++round) {
        sculptor.removeIslands(round == 0);
        sculptor.openedByRepair = false;
        sculptor.repairNonManifoldEdges(round == 0);
        sculptor.fillVoids(round == 0);
        if (!sculptor.openedByRepair) break;
    }
    listSurfaceTets();
}

// ---- surface extraction ----------------------------------------------------------------

void extractSurfaces(const FreeSpace& space, const std::vector<int>& label, size_t groupCount,
                     std::vector<Aggregate>& aggregates, const std::vector<int>* surfaceTets, SculptScratch* scratch) {
    SculptScratch local;
    SculptScratch::Buffers& buffers = scratch ? *scratch->buffers : *local.buffers;
    const TetMesh& mesh = space.mesh;
    const size_t tetCount = mesh.tetCount();
    aggregates.resize(groupCount);
    // Surface faces: (tet, face) with the tet in a group's solid and the neighbour outside
    // it, gathered by group in one array (counting sort, tet order kept within a group).
    std::vector<std::pair<int, int>>& allFaces = buffers.allFaces;
    std::vector<uint32_t>& faceGroup = buffers.faceGroup;
    allFaces.clear();
    faceGroup.clear();
    auto collect = [&](size_t t) {
        const int g = label[t];
        if (g < 0) return;
        // Object interiors are skipped: only their model-surface faces can be on a surface.
        const unsigned candidates = space.tetModel[t] >= 0 ? space.objectFaceMask[t] : 0xFu;
        for (int j = 0; j < 4; ++j) {
            if (!(candidates & (1u << j))) continue;
            int n = mesh.neighbors[4 * t + j];
            if (n < 0 || label[n] != g) {
                allFaces.emplace_back(static_cast<int>(t), j);
                faceGroup.push_back(static_cast<uint32_t>(g));
            }
        }
    };
    if (surfaceTets) {
        for (int t : *surfaceTets) collect(static_cast<size_t>(t));
    } else {
        for (size_t t = 0; t < tetCount; ++t) collect(t);
    }
    std::vector<size_t> groupStart(groupCount + 1, 0);
    for (uint32_t g : faceGroup) ++groupStart[g + 1];
    for (size_t g = 0; g < groupCount; ++g) groupStart[g + 1] += groupStart[g];
    std::vector<std::pair<int, int>>& byGroup = buffers.byGroup;
    byGroup.resize(allFaces.size());
    {
        std::vector<size_t> at(groupStart.begin(), groupStart.end() - 1);
        for (size_t f = 0; f < allFaces.size(); ++f) byGroup[at[faceGroup[f]]++] = allFaces[f];
    }
    std::vector<int>& faceIndexOf = buffers.faceIndexOf;  // all -1 again after each group
    if (faceIndexOf.size() != 4 * tetCount) faceIndexOf.assign(4 * tetCount, -1);
    std::vector<int>& twinEdge = buffers.twinEdge;
    constexpr uint64_t kNoEdge = ~0ull;
    std::vector<uint64_t>& edgeKeys = buffers.edgeKeys;  // open addressing: directed edge (from << 32 | to)
    std::vector<int>& edgeUse = buffers.edgeUse;         // its face edge 3 * face + e, or -1 when used twice
    std::vector<uint32_t> outIndex;
    DisjointSets corners, shells;
    for (size_t g = 0; g < groupCount; ++g) {
        const std::pair<int, int>* list = byGroup.data() + groupStart[g];
        const size_t listSize = groupStart[g + 1] - groupStart[g];
        Aggregate& agg = aggregates[g];
        agg.positions.clear();
        agg.indices.clear();
        agg.componentCount = 0;
        if (listSize == 0) continue;
        for (size_t f = 0; f < listSize; ++f) faceIndexOf[4 * list[f].first + list[f].second] = static_cast<int>(f);
        auto vertexAt = [&](int t, int corner) { return mesh.tets[4 * t + corner]; };
        auto localCorner = [&](int t, int v) {
            for (int k = 0; k < 4; ++k)
                if (mesh.tets[4 * t + k] == v) return k;
            return -1;
        };
        corners.reset(3 * listSize);
        shells.reset(listSize);
        // Twin of each face edge, recorded for both sides. Where the group's surface uses the
        // edge once each way (a manifold edge: nearly all), the twin is the one face using it
        // the other way, looked up in a table of directed edges. Otherwise (the edge is on
        // more faces) it is found by rotating around the edge through the group's solid;
        // the rotation from the twin back through the same solid run ends at this face.
        twinEdge.assign(3 * listSize, -1);
        size_t slots = 16;
        while (slots < 2 * 3 * listSize) slots <<= 1;  // load factor <= 1/2: short probes
        const uint64_t mask = slots - 1;
        edgeKeys.assign(slots, kNoEdge);
        edgeUse.resize(slots);
        auto slotOf = [&](uint64_t key) {
            uint64_t h = (key * 0x9E3779B97F4A7C15ull) >> 20;
            while (true) {
                h &= mask;
                if (edgeKeys[h] == key || edgeKeys[h] == kNoEdge) return h;
                ++h;
            }
        };
        auto directedKey = [](int from, int to) { return (static_cast<uint64_t>(from) << 32) | static_cast<uint32_t>(to); };
        for (size_t f = 0; f < listSize; ++f) {
            const auto [t0, j0] = list[f];
            for (int e = 0; e < 3; ++e) {
                const uint64_t key = directedKey(vertexAt(t0, kFaceCorners[j0][e]), vertexAt(t0, kFaceCorners[j0][(e + 1) % 3]));
                const uint64_t h = slotOf(key);
                if (edgeKeys[h] == kNoEdge) {
                    edgeKeys[h] = key;
                    edgeUse[h] = static_cast<int>(3 * f + e);
                } else {
                    edgeUse[h] = -1;  // used twice this way: not manifold
                }
            }
        }
        for (size_t f = 0; f < listSize; ++f) {
            const auto [t0, j0] = list[f];
            for (int e = 0; e < 3; ++e) {
                if (twinEdge[3 * f + e] >= 0) continue;
                const int u = vertexAt(t0, kFaceCorners[j0][e]);
                const int v = vertexAt(t0, kFaceCorners[j0][(e + 1) % 3]);
                int twinFace = -1;
                const uint64_t back = slotOf(directedKey(v, u));
                if (edgeKeys[back] != kNoEdge && edgeUse[back] >= 0 && edgeUse[slotOf(directedKey(u, v))] >= 0)
                    twinFace = edgeUse[back] / 3;
                // Rotate around edge uv through the group's solid tets until leaving it.
                int t = t0;
                int lu = localCorner(t, u), lv = localCorner(t, v);
                int cross = 6 - lu - lv - j0;  // the other face of t containing uv
                for (int guard = 0; guard < 4096 && twinFace < 0; ++guard) {
                    int n = mesh.neighbors[4 * t + cross];
                    if (n < 0 || label[n] != static_cast<int>(g)) {
                        twinFace = faceIndexOf[4 * t + cross];
                        break;
                    }
                    // Enter n through the face shared with t.
                    int entered = -1;
                    for (int k = 0; k < 4; ++k)
                        if (mesh.neighbors[4 * n + k] == t) {
                            // the shared face must contain u and v
                            int a = localCorner(n, u), b = localCorner(n, v);
                            if (a >= 0 && b >= 0 && k != a && k != b) entered = k;
                        }
                    if (entered < 0) break;
                    t = n;
                    lu = localCorner(t, u);
                    lv = localCorner(t, v);
                    cross = 6 - lu - lv - entered;
                }
                if (twinFace < 0) continue;  // cannot happen on a valid mesh
                // In the twin face the edge runs v -> u: join the corners at u and at v.
                const auto [t1, j1] = list[twinFace];
                for (int e1 = 0; e1 < 3; ++e1) {
                    int c = vertexAt(t1, kFaceCorners[j1][e1]);
                    if (c == u) corners.unite(static_cast<uint32_t>(3 * f + e), static_cast<uint32_t>(3 * twinFace + e1));
                    if (c == v) {
                        corners.unite(static_cast<uint32_t>(3 * f + (e + 1) % 3), static_cast<uint32_t>(3 * twinFace + e1));
                        twinEdge[3 * static_cast<size_t>(twinFace) + e1] = static_cast<int>(3 * f + e);  // twin's edge v -> u
                    }
                }
                twinEdge[3 * f + e] = 3 * twinFace;
                shells.unite(static_cast<uint32_t>(f), static_cast<uint32_t>(twinFace));
            }
        }
        // One output vertex per corner class, numbered by first use.
        outIndex.assign(3 * listSize, UINT32_MAX);
        uint32_t next = 0;
        agg.indices.resize(3 * listSize);
        for (size_t f = 0; f < listSize; ++f) {
            const auto [t, j] = list[f];
            for (int e = 0; e < 3; ++e) {
                uint32_t root = corners.find(static_cast<uint32_t>(3 * f + e));
                if (outIndex[root] == UINT32_MAX) {
                    outIndex[root] = next++;
                    const double* p = &mesh.points[3 * static_cast<size_t>(vertexAt(t, kFaceCorners[j][e]))];
                    agg.positions.insert(agg.positions.end(), p, p + 3);
                }
                agg.indices[3 * f + e] = outIndex[root];
            }
        }
        int components = 0;
        for (size_t f = 0; f < listSize; ++f)
            if (shells.find(static_cast<uint32_t>(f)) == f) ++components;
        agg.componentCount = components;
        for (size_t f = 0; f < listSize; ++f) faceIndexOf[4 * list[f].first + list[f].second] = -1;
    }
}

}  // namespace aggrelod::detail
