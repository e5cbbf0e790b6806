// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: bundles (docs/design.md §2.6). Not from the paper: game HLOD systems merge
// the meshes of a cluster into one draw call for distant views (Unreal's HLOD, Simplygon's
// aggregation); here the merged parts are the group's own certified versions, so a bundle
// keeps every guarantee of its parts.
#include "draw_bundles.h"

#include "surface_colors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace aggrelod::detail {
namespace {

/// A kept bundle is lighter than the finer one kept before it by at least this share.
constexpr size_t kWorthNumerator = 19, kWorthDenominator = 20;
/// Most thresholds tried for one group.
constexpr size_t kMaxThresholds = 256;

double ownError(const HierarchyNode& n) { return n.leaf ? 0.0 : n.error.bound(); }

/// One child of a group: its chain from the top down to its end (an aggregate or a leaf).
struct Chain {
    std::vector<uint32_t> members;  ///< top first
    double end = INFINITY;          ///< the smallest error of a member other than a leaf
};

/// What a bundle draws for one chain: a node of the chain, or one version of each of the
/// chain's objects.
struct Piece {
    uint32_t node = kNoNode;
    std::vector<const HierarchyNode*> versions;
    size_t triangles = 0;
};

struct Plan {
    uint32_t group = kNoNode;
    std::vector<Chain> chains;               ///< the bundled ones
    std::vector<double> thresholds;          ///< of the bundles kept, finest first
    std::vector<std::vector<Piece>> pieces;  ///< per bundle kept, one per chain
    std::vector<uint32_t> newTops;           ///< per chain: its top below the finest bundle
};

/// The lightest member of `chain` other than a leaf whose error (eff) is at most t; kNoNode for
/// none. Ties: the one nearest the top.
uint32_t lightestWithin(const Chain& chain, double t, const std::vector<double>& eff,
                        const std::vector<HierarchyNode>& nodes) {
    uint32_t best = kNoNode;
    size_t bestTriangles = SIZE_MAX;
    for (uint32_t m : chain.members) {
        if (nodes[m].leaf || !(eff[m] <= t)) continue;
        const size_t triangles = nodeTriangleCount(nodes[m]);
        if (triangles < bestTriangles) best = m, bestTriangles = triangles;
    }
    return best;
}

/// The lightest version of `versions` whose error is at most t; null for none.
const HierarchyNode* lightestVersionWithin(const std::vector<HierarchyNode>& versions, double t) {
    const HierarchyNode* best = nullptr;
    for (const HierarchyNode& v : versions)
        if (v.error.bound() <= t && (!best || v.indices.size() < best->indices.size())) best = &v;
    return best;
}

/// A chain's part at threshold t: its lightest node within t, or its objects' lightest
/// versions within t when every object has one and they have fewer triangles in all.
Piece pieceWithin(const Chain& chain, double t, const std::vector<double>& eff, const std::vector<HierarchyNode>& nodes,
                  const std::vector<std::vector<HierarchyNode>>& versionsAbove) {
    Piece piece;
    piece.node = lightestWithin(chain, t, eff, nodes);
    piece.triangles = nodeTriangleCount(nodes[piece.node]);
    if (versionsAbove.empty()) return piece;
    std::vector<const HierarchyNode*> versions;
    size_t triangles = 0;
    for (uint32_t o : nodes[chain.members.back()].sources) {
        const HierarchyNode* v = lightestVersionWithin(versionsAbove[o], t);
        if (!v) return piece;
        versions.push_back(v);
        triangles += v->indices.size() / 3;
    }
    if (triangles < piece.triangles) {
        piece.node = kNoNode;
        piece.versions = std::move(versions);
        piece.triangles = triangles;
    }
    return piece;
}

/// Appends `mesh` (a node's, coloured or not) to `out`; white where it has no colours, when
/// `colored`.
void appendMesh(const NodeMeshView& mesh, bool colored, HierarchyNode& out) {
    const uint32_t base = static_cast<uint32_t>(out.positions.size() / 3);
    out.positions.insert(out.positions.end(), mesh.positions.begin(), mesh.positions.end());
    for (uint32_t i : mesh.indices) out.indices.push_back(base + i);
    if (!colored) return;
    const size_t triangles = mesh.indices.size() / 3;
    if (mesh.faceColors.size() == 4 * triangles) out.faceColors.insert(out.faceColors.end(), mesh.faceColors.begin(), mesh.faceColors.end());
    else out.faceColors.insert(out.faceColors.end(), 4 * triangles, 1.0f);
}

bool hasColors(const HierarchyNode& m) {
    return m.meshPlace.kind == NodeMeshPlace::Kind::InNode ? !m.faceColors.empty() : m.meshPlace.hasFaceColors;
}

}  // namespace

bool addDrawBundles(HierarchyNodes& tree, const std::vector<InputObject>& objects, const ProxySettings& settings,
                    const std::vector<std::vector<HierarchyNode>>& versionsAbove, NodeMeshSpiller* spiller,
                    std::string& error) {
    if (settings.bundleCount <= 0) return true;
    std::vector<HierarchyNode>& nodes = tree.nodes;
    const uint32_t count = static_cast<uint32_t>(nodes.size());
    // Error of a node as the cut sees it: the largest on its subtree (children come first).
    std::vector<double> eff(count, 0.0);
    for (uint32_t i = 0; i < count; ++i) {
        eff[i] = ownError(nodes[i]);
        for (uint32_t c : nodes[i].children) eff[i] = std::max(eff[i], eff[c]);
    }
    const auto isVersion = [&](const HierarchyNode& n) {
        return !n.leaf && (n.objectLod >= 1 || n.coarserStep >= 1) && n.children.size() == 1;
    };
    // Each object's box, for its groups' diagonals (a group's proxy may be out of memory).
    std::vector<std::array<double, 6>> objectBox(objects.size());
    for (size_t o = 0; o < objects.size(); ++o) {
        std::array<double, 6>& b = objectBox[o];
        b = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (size_t v = 0; v + 2 < objects[o].positions.size(); v += 3)
            for (int k = 0; k < 3; ++k)
                b[k] = std::min(b[k], objects[o].positions[v + k]), b[3 + k] = std::max(b[3 + k], objects[o].positions[v + k]);
    }

    std::vector<Plan> plans;
    std::vector<uint32_t> planOf(count, kNoNode);
    for (uint32_t g = 0; g < count; ++g) {
        const HierarchyNode& group = nodes[g];
        if (group.leaf || group.objectLod != 0 || group.coarserStep != 0 || group.sources.size() < 2 ||
            group.children.size() < 2)
            continue;
        Plan plan;
        plan.group = g;
        std::vector<Chain> chains;
        std::vector<double> ends;  // ascending, below
        for (uint32_t c : group.children) {
            Chain chain;
            for (uint32_t x = c;; x = nodes[x].children.front()) {
                chain.members.push_back(x);
                if (!nodes[x].leaf) chain.end = std::min(chain.end, eff[x]);
                if (!isVersion(nodes[x])) break;
            }
            ends.push_back(chain.end);
            chains.push_back(std::move(chain));
        }
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t o : group.sources)
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], objectBox[o][k]), hi[k] = std::max(hi[k], objectBox[o][3 + k]);
        double diagonal2 = 0;
        for (int k = 0; k < 3; ++k) diagonal2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        // The chains ending at or below the floor are bundled; a child whose chain ends higher
        // (an aggregate with a wide fill) stays a child of the group beside them, drawn apart,
        // rather than holding every bundle above its error.
        std::sort(ends.begin(), ends.end());
        double floor = settings.bundleMinErrorFraction * std::sqrt(diagonal2);
        if (!(ends[1] <= floor)) {
            floor = 0;
            for (double e : ends)
                if (std::isfinite(e)) floor = std::max(floor, e);
        }
        const double top = ownError(group);
        if (!(floor > 0 && floor < top)) continue;
        for (Chain& chain : chains)
            if (chain.end <= floor) plan.chains.push_back(std::move(chain));
        if (plan.chains.size() < 2) continue;
        // Thresholds: where a bundled chain's lightest node changes, that is its nodes' errors
        // (at most kMaxThresholds of them, evenly spread, for a group of many children).
        std::vector<double> candidates{floor};
        for (const Chain& chain : plan.chains) {
            for (uint32_t m : chain.members)
                if (!nodes[m].leaf && eff[m] > floor && eff[m] < top) candidates.push_back(eff[m]);
            if (versionsAbove.empty()) continue;
            for (uint32_t o : nodes[chain.members.back()].sources)
                for (const HierarchyNode& v : versionsAbove[o])
                    if (v.error.bound() > floor && v.error.bound() < top) candidates.push_back(v.error.bound());
        }
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
        if (candidates.size() > kMaxThresholds) {
            std::vector<double> spread;
            for (size_t j = 0; j < kMaxThresholds; ++j) spread.push_back(candidates[j * candidates.size() / kMaxThresholds]);
            candidates = std::move(spread);
        }
        size_t lastTriangles = 0;
        for (double t : candidates) {
            if (int(plan.thresholds.size()) >= settings.bundleCount) break;
            std::vector<Piece> pieces;
            size_t triangles = 0;
            for (const Chain& chain : plan.chains) {
                pieces.push_back(pieceWithin(chain, t, eff, nodes, versionsAbove));
                triangles += pieces.back().triangles;
            }
            if (triangles > settings.bundleMaxTriangles) continue;
            if (!plan.thresholds.empty() && kWorthDenominator * triangles > kWorthNumerator * lastTriangles) continue;
            plan.thresholds.push_back(t);
            plan.pieces.push_back(std::move(pieces));
            lastTriangles = triangles;
        }
        if (plan.thresholds.empty()) continue;
        for (const Chain& chain : plan.chains) {
            size_t j = 0;  // the highest member within the finest threshold (one is: chain.end <= floor)
            while (!(eff[chain.members[j]] <= plan.thresholds.front())) ++j;
            plan.newTops.push_back(chain.members[j]);
        }
        planOf[g] = static_cast<uint32_t>(plans.size());
        plans.push_back(std::move(plan));
    }
    if (plans.empty()) return true;

    // Chain nodes above a finest bundle's threshold leave the tree. An aggregate of one object
    // that gave way to the object's chain is stood for by the chain's top (nodeOfAggregate):
    // by its new top when that top goes.
    std::vector<char> absorbed(count, 0);
    std::vector<uint32_t> standIn(count, kNoNode);
    std::vector<uint32_t> bundleAbove(count, kNoNode);  // new top -> its group's plan
    for (uint32_t p = 0; p < plans.size(); ++p)
        for (size_t i = 0; i < plans[p].chains.size(); ++i) {
            for (uint32_t m : plans[p].chains[i].members) {
                if (m == plans[p].newTops[i]) break;
                absorbed[m] = 1;
                standIn[m] = plans[p].newTops[i];
            }
            bundleAbove[plans[p].newTops[i]] = p;
        }

    // The bundles' meshes, made (and spilled) before the absorbed nodes go.
    std::vector<std::vector<HierarchyNode>> bundles(plans.size());
    NodeMesh storage;
    try {
        for (size_t p = 0; p < plans.size(); ++p) {
            const Plan& plan = plans[p];
            const HierarchyNode& group = nodes[plan.group];
            for (size_t j = 0; j < plan.thresholds.size(); ++j) {
                HierarchyNode b;
                b.bundleStep = static_cast<int>(j) + 1;
                for (const Chain& chain : plan.chains) {
                    const HierarchyNode& end = nodes[chain.members.back()];
                    b.sources.insert(b.sources.end(), end.sources.begin(), end.sources.end());
                    b.exactTriangleCount += end.exactTriangleCount;
                }
                std::sort(b.sources.begin(), b.sources.end());
                b.delta = group.delta;
                b.budget = plan.thresholds[j];
                bool colored = false;
                for (const Piece& piece : plan.pieces[j]) {
                    if (piece.node != kNoNode) colored = colored || hasColors(nodes[piece.node]);
                    for (const HierarchyNode* v : piece.versions) colored = colored || !v->faceColors.empty();
                }
                const auto addPart = [&](const NodeMeshView& mesh, const ProxyError& e) {
                    appendMesh(mesh, colored, b);
                    b.error.proxyToOriginals = std::max(b.error.proxyToOriginals, e.proxyToOriginals);
                    b.error.originalsToProxy = std::max(b.error.originalsToProxy, e.originalsToProxy);
                    b.error.evaluationCount += e.evaluationCount;
                };
                for (const Piece& piece : plan.pieces[j]) {
                    if (piece.node != kNoNode) addPart(viewNodeMesh(tree, objects, piece.node, storage), nodes[piece.node].error);
                    for (const HierarchyNode* v : piece.versions)
                        addPart(NodeMeshView{v->positions, v->indices, v->faceColors}, v->error);
                }
                // Nothing is measured on the bundle as a whole (a distance found on a part may
                // be shorter to another part's objects): found 0, the whole bound as the gap.
                b.error.tolerance = b.error.bound();
                if (spiller && !spiller->spill(b, plan.group, error)) return false;
                bundles[p].push_back(std::move(b));
            }
        }
    } catch (const std::runtime_error& e) {  // a spilled mesh that did not read back
        error = e.what();
        return false;
    }

    // Renumbered: each group's bundles (finest first) just before it.
    std::vector<uint32_t> newIndex(count, kNoNode);
    uint32_t next = 0;
    for (uint32_t i = 0; i < count; ++i) {
        if (absorbed[i]) continue;
        if (planOf[i] != kNoNode) next += static_cast<uint32_t>(bundles[planOf[i]].size());
        newIndex[i] = next++;
    }
    std::vector<HierarchyNode> out(next);
    std::vector<uint32_t> parentOf(next, kNoNode);
    for (uint32_t i = 0; i < count; ++i) {
        if (absorbed[i]) continue;
        const uint32_t at = newIndex[i];
        if (bundleAbove[i] != kNoNode) {
            parentOf[at] = newIndex[plans[bundleAbove[i]].group] - static_cast<uint32_t>(bundles[bundleAbove[i]].size());
        } else if (nodes[i].parent != kNoNode) {
            parentOf[at] = newIndex[nodes[i].parent];
        }
        if (planOf[i] != kNoNode) {
            std::vector<HierarchyNode>& chain = bundles[planOf[i]];
            const uint32_t first = at - static_cast<uint32_t>(chain.size());
            for (size_t j = 0; j < chain.size(); ++j) {
                out[first + j] = std::move(chain[j]);
                parentOf[first + j] = first + static_cast<uint32_t>(j) + 1;  // the last one's: the group
            }
        }
        out[at] = std::move(nodes[i]);
    }
    tree.roots.clear();
    for (uint32_t i = 0; i < next; ++i) {
        out[i].children.clear();
        out[i].parent = parentOf[i];
    }
    for (uint32_t i = 0; i < next; ++i) {  // ascending, so children lists come out sorted
        if (parentOf[i] == kNoNode) tree.roots.push_back(i);
        else out[parentOf[i]].children.push_back(i);
    }
    for (auto& level : tree.nodeOfAggregate)
        for (uint32_t& i : level) i = newIndex[absorbed[i] ? standIn[i] : i];
    nodes = std::move(out);
    return true;
}

}  // namespace aggrelod::detail
