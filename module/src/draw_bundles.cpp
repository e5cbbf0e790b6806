// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: bundles (docs/design.md §2.6). Not from the paper: game HLOD systems merge
// the meshes of a cluster into one draw call for distant views (Unreal's HLOD, Simplygon's
// aggregation); here the merged parts are the group's own certified versions, so a bundle
// keeps every guarantee of its parts.
#include "draw_bundles.h"

#include "node_tree.h"
#include "surface_colors.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <utility>

namespace aggrelod::detail {
namespace {

/// A kept bundle that does not hold enough more children than the finer one kept before it
/// (see addDrawBundles) has at most this share of its triangles (as the per-object chains:
/// denser chains use up ProxySettings::bundleCount before the coarse end, where a distant
/// group is drawn).
constexpr size_t kWorthNumerator = 9, kWorthDenominator = 10;
/// Most thresholds tried for one group.
constexpr size_t kMaxThresholds = 256;

/// A member of a chain: a node (below the node count) or a bundle made here (the node count
/// plus its index in the list of all bundles planned).
using Member = uint32_t;

/// One child of a group: its chain from the top down to its end (an aggregate or a leaf, or
/// the finest bundle that holds every child of an aggregate whose children all joined its
/// bundles).
struct Chain {
    std::vector<Member> members;  ///< top first
    double end = INFINITY;        ///< the smallest error of a member other than a leaf
};

/// What a bundle draws for one chain: a member of the chain, or one version of each of the
/// chain's objects.
struct Piece {
    Member member = kNoNode;
    std::vector<const HierarchyNode*> versions;
    size_t triangles = 0;
};

struct Plan {
    uint32_t group = kNoNode;
    std::vector<Chain> chains;               ///< the bundled ones
    std::vector<uint32_t> joins;             ///< per chain: the finest bundle holding it
    std::vector<double> thresholds;          ///< of the bundles planned, finest first
    std::vector<std::vector<Piece>> pieces;  ///< per bundle planned, one per chain (empty before it joins)
    std::vector<ProxyError> errors;          ///< per bundle planned: the largest of its parts'
    std::vector<Member> newTops;             ///< per chain: its top below the bundle it joins
    uint32_t firstBundle = 0;                ///< index of its finest bundle in the list of all
    uint32_t kept = 0;                       ///< bundles left in the tree (the finest ones)
};

/// The bundle error of parts: the largest of their bounds, field by field. Nothing is measured
/// on a bundle as a whole (a distance found on a part may be shorter to another part's
/// objects): found 0, the whole bound as the gap.
void addPartError(ProxyError& into, const ProxyError& part) {
    into.proxyToOriginals = std::max(into.proxyToOriginals, part.proxyToOriginals);
    into.originalsToProxy = std::max(into.originalsToProxy, part.originalsToProxy);
    into.evaluationCount += part.evaluationCount;
    into.tolerance = 0;
    into.tolerance = into.bound();
}

/// The lightest version of `versions` whose error is at most t; null for none.
const HierarchyNode* lightestVersionWithin(const std::vector<HierarchyNode>& versions, double t) {
    const HierarchyNode* best = nullptr;
    for (const HierarchyNode& v : versions)
        if (v.error.bound() <= t && (!best || nodeTriangleCount(v) < nodeTriangleCount(*best))) best = &v;
    return best;
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

/// The bundles of a tree as they are planned: chains, pieces and errors of every group's.
class Planner {
public:
    Planner(const std::vector<HierarchyNode>& nodes, const std::vector<std::vector<HierarchyNode>>& versionsAbove)
        : nodes_(nodes), versionsAbove_(versionsAbove), count_(static_cast<uint32_t>(nodes.size())), eff_(count_, 0.0) {
        // Error of a node as the cut sees it: the largest on its subtree (children come first).
        for (uint32_t i = 0; i < count_; ++i) {
            eff_[i] = nodes[i].leaf ? 0.0 : nodes[i].error.bound();
            for (uint32_t c : nodes[i].children) eff_[i] = std::max(eff_[i], eff_[c]);
        }
    }

    bool isBundle(Member m) const { return m >= count_; }
    bool isLeaf(Member m) const { return !isBundle(m) && nodes_[m].leaf; }
    double eff(Member m) const { return isBundle(m) ? bundleEff_[m - count_] : eff_[m]; }
    size_t triangles(Member m) const { return isBundle(m) ? bundleTriangles_[m - count_] : nodeTriangleCount(nodes_[m]); }
    /// The plan and step of bundle member m.
    std::pair<uint32_t, uint32_t> bundleOf(Member m) const { return bundleAt_[m - count_]; }

    /// Chain from child c of a group down: through coarser versions, per-object LODs and
    /// aggregates of one child, then through the bundles of an aggregate whose children all
    /// joined its bundles (planned already: children come first), coarsest first.
    Chain chainFrom(uint32_t c, const std::vector<uint32_t>& planOf, const std::vector<Plan>& plans) const {
        Chain chain;
        for (uint32_t x = c;; x = nodes_[x].children.front()) {
            chain.members.push_back(x);
            if (!nodes_[x].leaf) chain.end = std::min(chain.end, eff_[x]);
            const HierarchyNode& n = nodes_[x];
            // An aggregate of several objects with one child holds the same objects as that
            // child (the next finer level's aggregate): the chain goes on through it.
            if (!n.leaf && (n.objectLod >= 1 || n.coarserStep >= 1 || n.sources.size() >= 2) && n.children.size() == 1)
                continue;
            if (planOf[x] != kNoNode && plans[planOf[x]].chains.size() == n.children.size()) {
                const Plan& q = plans[planOf[x]];
                // Down to the finest bundle that holds every child: those below hold some only.
                const uint32_t whole = *std::max_element(q.joins.begin(), q.joins.end());
                for (size_t j = q.thresholds.size(); j-- > whole;) {
                    const Member m = count_ + q.firstBundle + static_cast<uint32_t>(j);
                    chain.members.push_back(m);
                    chain.end = std::min(chain.end, eff(m));
                }
            }
            return chain;
        }
    }

    /// A chain's part at threshold t: its lightest member other than a leaf within t (ties: the
    /// one nearest the top), or its objects' lightest versions within t when every object has
    /// one and they have fewer triangles in all.
    Piece pieceWithin(const Chain& chain, double t) const {
        Piece piece;
        piece.triangles = SIZE_MAX;
        for (Member m : chain.members) {
            if (isLeaf(m) || !(eff(m) <= t)) continue;
            const size_t n = triangles(m);
            if (n < piece.triangles) piece.member = m, piece.triangles = n;
        }
        if (versionsAbove_.empty()) return piece;
        std::vector<const HierarchyNode*> versions;
        size_t sum = 0;
        for (uint32_t o : nodes_[chain.members.front()].sources) {
            const HierarchyNode* v = lightestVersionWithin(versionsAbove_[o], t);
            if (!v) return piece;
            versions.push_back(v);
            sum += nodeTriangleCount(*v);
        }
        if (sum < piece.triangles) {
            piece.member = kNoNode;
            piece.versions = std::move(versions);
            piece.triangles = sum;
        }
        return piece;
    }

    /// The error of a piece: the largest of its parts' (a bundle member's parts, recursively).
    ProxyError pieceError(const Piece& piece, const std::vector<Plan>& plans) const {
        ProxyError e;
        if (piece.member != kNoNode) {
            if (isBundle(piece.member)) {
                const auto [p, j] = bundleOf(piece.member);
                addPartError(e, plans[p].errors[j]);
            } else {
                addPartError(e, nodes_[piece.member].error);
            }
        }
        for (const HierarchyNode* v : piece.versions) addPartError(e, v->error);
        return e;
    }

    /// Registers the bundles of plans[p] (its pieces, errors, joins and new tops known).
    void addBundles(std::vector<Plan>& plans, uint32_t p) {
        Plan& plan = plans[p];
        plan.firstBundle = static_cast<uint32_t>(bundleAt_.size());
        plan.kept = static_cast<uint32_t>(plan.thresholds.size());
        double below = 0;  // the largest error below bundle j: the finer bundle's, its new tops'
        for (uint32_t j = 0; j < plan.thresholds.size(); ++j) {
            for (size_t c = 0; c < plan.chains.size(); ++c)
                if (plan.joins[c] == j) below = std::max(below, eff(plan.newTops[c]));
            below = std::max(below, plan.errors[j].bound());
            bundleEff_.push_back(below);
            size_t n = 0;
            for (const Piece& piece : plan.pieces[j]) n += piece.triangles;
            bundleTriangles_.push_back(n);
            bundleAt_.push_back({p, j});
        }
    }

private:
    const std::vector<HierarchyNode>& nodes_;
    const std::vector<std::vector<HierarchyNode>>& versionsAbove_;
    uint32_t count_;
    std::vector<double> eff_;
    std::vector<double> bundleEff_;
    std::vector<size_t> bundleTriangles_;
    std::vector<std::pair<uint32_t, uint32_t>> bundleAt_;
};

}  // namespace

bool addDrawBundles(HierarchyNodes& tree, const std::vector<InputObject>& objects, const ProxySettings& settings,
                    const std::vector<std::vector<HierarchyNode>>& versionsAbove, NodeMeshSpiller* spiller,
                    std::string& error) {
    if (settings.bundleCount <= 0) return true;
    std::vector<HierarchyNode>& nodes = tree.nodes;
    // A tree of several roots (support surfaces beside the hierarchy, groups the coarsest level
    // never joined) has its roots bundled too, so that the whole scene far away costs one draw
    // call: they are planned as the children of a group made for this (last: children come
    // first), the scene group, at the level above the coarsest. It has no mesh and leaves the
    // tree afterwards: its coarsest bundle becomes a root, the roots that join none stay roots.
    uint32_t sceneGroup = kNoNode;
    if (tree.roots.size() >= 2 && !tree.nodeOfAggregate.empty()) {
        HierarchyNode scene;  // its error, the largest of its roots', is set below (Planner::eff)
        scene.children = tree.roots;
        for (uint32_t r : tree.roots) {
            scene.sources.insert(scene.sources.end(), nodes[r].sources.begin(), nodes[r].sources.end());
            scene.exactTriangleCount += nodes[r].exactTriangleCount;
            scene.delta = std::max(scene.delta, nodes[r].delta);
        }
        std::sort(scene.sources.begin(), scene.sources.end());
        scene.firstLevel = scene.lastLevel = static_cast<int>(tree.nodeOfAggregate.size());
        sceneGroup = static_cast<uint32_t>(nodes.size());
        for (uint32_t r : tree.roots) nodes[r].parent = sceneGroup;
        nodes.push_back(std::move(scene));
    }
    // The scene group out again, where nothing was planned at all.
    const auto dropSceneGroup = [&] {
        if (sceneGroup == kNoNode) return;
        for (uint32_t r : nodes[sceneGroup].children) nodes[r].parent = kNoNode;
        nodes.pop_back();
    };
    const uint32_t count = static_cast<uint32_t>(nodes.size());
    Planner planner(nodes, versionsAbove);
    if (sceneGroup != kNoNode) nodes[sceneGroup].error.proxyToOriginals = planner.eff(sceneGroup);
    // Each object's box, for its groups' diagonals (a group's proxy may be out of memory).
    std::vector<std::array<double, 6>> objectBox(objects.size());
    for (size_t o = 0; o < objects.size(); ++o) {
        std::array<double, 6>& b = objectBox[o];
        b = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (size_t v = 0; v + 2 < objects[o].positions.size(); v += 3)
            for (int k = 0; k < 3; ++k)
                b[k] = std::min(b[k], objects[o].positions[v + k]), b[3 + k] = std::max(b[3 + k], objects[o].positions[v + k]);
    }

    // Plans, children first. A member above a chain's new top leaves the tree: a node
    // (absorbed, stood in for by the new top), or a bundle of a group whose chain this is
    // (that group keeps only its bundles up to the new top, and leaves the tree itself).
    std::vector<Plan> plans;
    std::vector<uint32_t> planOf(count, kNoNode);
    std::vector<char> absorbed(count, 0);
    std::vector<Member> standIn(count, kNoNode);
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
            chains.push_back(planner.chainFrom(c, planOf, plans));
            ends.push_back(chains.back().end);
        }
        double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (uint32_t o : group.sources)
            for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], objectBox[o][k]), hi[k] = std::max(hi[k], objectBox[o][3 + k]);
        double diagonal2 = 0;
        for (int k = 0; k < 3; ++k) diagonal2 += (hi[k] - lo[k]) * (hi[k] - lo[k]);
        // The finest bundle holds the chains ending at or below the floor (at least two); a
        // chain that ends higher (an aggregate with a wide fill) joins the first bundle whose
        // threshold reaches its end, and its child stays beside the finer bundles, drawn
        // apart, rather than holding every bundle above its error.
        std::sort(ends.begin(), ends.end());
        const double floor = std::max(settings.bundleMinErrorFraction * std::sqrt(diagonal2), ends[1]);
        const double top = group.error.bound();
        if (!(floor > 0 && floor < top)) continue;
        for (Chain& chain : chains)
            if (chain.end < top) plan.chains.push_back(std::move(chain));
        if (plan.chains.size() < 2) continue;
        const size_t finite = plan.chains.size();
        // Thresholds: where a bundled chain's lightest part changes, that is its members' and
        // its objects' versions' errors (at most kMaxThresholds of them, evenly spread, for a
        // group of many children).
        std::vector<double> candidates{floor};
        const auto candidate = [&](double e) {
            if (e > floor && e < top) candidates.push_back(e);
        };
        for (const Chain& chain : plan.chains) {
            for (Member m : chain.members)
                if (!planner.isLeaf(m)) candidate(planner.eff(m));
            if (versionsAbove.empty()) continue;
            for (uint32_t o : nodes[chain.members.front()].sources)
                for (const HierarchyNode& v : versionsAbove[o]) candidate(v.error.bound());
        }
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
        if (candidates.size() > kMaxThresholds) {
            std::vector<double> spread;
            for (size_t j = 0; j < kMaxThresholds; ++j) spread.push_back(candidates[j * candidates.size() / kMaxThresholds]);
            candidates = std::move(spread);
        }
        // A bundle is kept when it holds more chains than the last one kept (an eighth of them
        // more, or all: each join saves draw calls, but the bundles are few) or is lighter
        // enough.
        const size_t joinStep = std::max<size_t>(1, finite / 8);
        size_t lastTriangles = 0, lastJoined = 0;
        for (double t : candidates) {
            if (int(plan.thresholds.size()) >= settings.bundleCount) break;
            std::vector<Piece> pieces(plan.chains.size());
            size_t triangles = 0, joined = 0;
            for (size_t c = 0; c < plan.chains.size(); ++c) {
                if (!(plan.chains[c].end <= t)) continue;
                pieces[c] = planner.pieceWithin(plan.chains[c], t);
                triangles += pieces[c].triangles;
                ++joined;
            }
            if (joined < 2 || triangles > settings.bundleMaxTriangles) continue;
            const bool more = plan.thresholds.empty() || joined >= lastJoined + joinStep ||
                              (joined == finite && lastJoined < finite);
            if (!more && kWorthDenominator * triangles > kWorthNumerator * lastTriangles) continue;
            ProxyError e;
            for (const Piece& piece : pieces) addPartError(e, planner.pieceError(piece, plans));
            plan.thresholds.push_back(t);
            plan.pieces.push_back(std::move(pieces));
            plan.errors.push_back(e);
            lastTriangles = triangles;
            lastJoined = joined;
        }
        if (plan.thresholds.empty()) continue;
        // Each chain joins the finest bundle kept that reaches its end; those that join none stay
        // children of the group, beside the bundles (dropped from the plan, kept in order).
        size_t joining = 0;
        for (size_t c = 0; c < plan.chains.size(); ++c) {
            uint32_t j = 0;
            while (j < plan.thresholds.size() && !(plan.chains[c].end <= plan.thresholds[j])) ++j;
            if (j == plan.thresholds.size()) continue;
            if (joining != c) {  // (a vector moved onto itself would be emptied)
                plan.chains[joining] = std::move(plan.chains[c]);
                for (std::vector<Piece>& pieces : plan.pieces) pieces[joining] = std::move(pieces[c]);
            }
            plan.joins.push_back(j);
            ++joining;
        }
        plan.chains.resize(joining);
        for (std::vector<Piece>& pieces : plan.pieces) pieces.resize(joining);
        for (size_t c = 0; c < plan.chains.size(); ++c) {
            const Chain& chain = plan.chains[c];
            const double threshold = plan.thresholds[plan.joins[c]];
            size_t j = 0;  // the highest member within the threshold of the bundle it joins (one is: chain.end)
            while (!(planner.eff(chain.members[j]) <= threshold)) ++j;
            const Member newTop = chain.members[j];
            plan.newTops.push_back(newTop);
            for (size_t k = 0; k < j; ++k) {
                const Member m = chain.members[k];
                if (!planner.isBundle(m)) {
                    absorbed[m] = 1;
                    standIn[m] = newTop;
                } else {  // a bundle above the new top: its group keeps those below only
                    const auto [q, step] = planner.bundleOf(m);
                    plans[q].kept = std::min(plans[q].kept, step);
                }
            }
        }
        planOf[g] = static_cast<uint32_t>(plans.size());
        plans.push_back(std::move(plan));
        planner.addBundles(plans, planOf[g]);
    }
    if (plans.empty()) {
        dropSceneGroup();
        return true;
    }
    const size_t allBundles = plans.back().firstBundle + plans.back().thresholds.size();
    // Per new top: the bundle it joins (its parent), as an index in the list of all bundles.
    std::vector<uint32_t> bundleAbove(count + allBundles, kNoNode);
    for (uint32_t p = 0; p < plans.size(); ++p)
        for (size_t c = 0; c < plans[p].newTops.size(); ++c)
            bundleAbove[plans[p].newTops[c]] = plans[p].firstBundle + plans[p].joins[c];

    // Materializes a piece into bundle b: each node part's mesh, a bundle member's parts
    // recursively, each version.
    NodeMesh storage;
    std::function<bool(const Piece&)> pieceHasColors = [&](const Piece& piece) {
        for (const HierarchyNode* v : piece.versions)
            if (hasColors(*v)) return true;
        if (piece.member == kNoNode) return false;
        if (!planner.isBundle(piece.member)) return hasColors(nodes[piece.member]);
        const auto [q, j] = planner.bundleOf(piece.member);
        for (const Piece& sub : plans[q].pieces[j])
            if (pieceHasColors(sub)) return true;
        return false;
    };
    std::function<void(const Piece&, bool, HierarchyNode&)> appendPiece = [&](const Piece& piece, bool colored,
                                                                               HierarchyNode& b) {
        if (piece.member != kNoNode) {
            if (planner.isBundle(piece.member)) {
                const auto [q, j] = planner.bundleOf(piece.member);
                for (const Piece& sub : plans[q].pieces[j]) appendPiece(sub, colored, b);
            } else {
                appendMesh(viewNodeMesh(tree, objects, piece.member, storage), colored, b);
            }
        }
        for (const HierarchyNode* v : piece.versions) appendMesh(viewDetachedNodeMesh(tree, *v, storage), colored, b);
    };
    // The bundles left in the tree, made (and spilled) before the absorbed nodes go.
    std::vector<std::vector<HierarchyNode>> bundles(plans.size());
    try {
        for (size_t p = 0; p < plans.size(); ++p) {
            const Plan& plan = plans[p];
            const HierarchyNode& group = nodes[plan.group];
            for (size_t j = 0; j < plan.kept; ++j) {
                HierarchyNode b;
                b.bundleStep = static_cast<int>(j) + 1;
                b.bundleLevel = group.firstLevel;
                for (size_t c = 0; c < plan.chains.size(); ++c) {
                    if (plan.joins[c] > j) continue;
                    const HierarchyNode& chainTop = nodes[plan.chains[c].members.front()];
                    b.sources.insert(b.sources.end(), chainTop.sources.begin(), chainTop.sources.end());
                    b.exactTriangleCount += chainTop.exactTriangleCount;
                }
                std::sort(b.sources.begin(), b.sources.end());
                b.delta = group.delta;
                b.budget = plan.thresholds[j];
                b.error = plan.errors[j];
                bool colored = false;
                for (const Piece& piece : plan.pieces[j]) colored = colored || pieceHasColors(piece);
                for (const Piece& piece : plan.pieces[j]) appendPiece(piece, colored, b);
                if (spiller && !spiller->spill(b, plan.group, error)) return false;
                bundles[p].push_back(std::move(b));
            }
        }
    } catch (const std::runtime_error& e) {  // a spilled mesh that did not read back
        error = e.what();
        return false;
    }

    // Renumbered: each group's bundles left (finest first) just before it (its descendants,
    // the new tops below them included, come before it), also where the group itself goes.
    std::vector<uint32_t> newIndex(count, kNoNode), bundleIndex(allBundles, kNoNode);
    if (sceneGroup != kNoNode) absorbed[sceneGroup] = 1;  // its bundles, if any, stand for it
    uint32_t next = 0;
    for (uint32_t i = 0; i < count; ++i) {
        if (planOf[i] != kNoNode) {
            const Plan& plan = plans[planOf[i]];
            for (uint32_t j = 0; j < plan.kept; ++j) bundleIndex[plan.firstBundle + j] = next++;
        }
        if (!absorbed[i]) newIndex[i] = next++;
    }
    const auto indexOf = [&](Member m) { return planner.isBundle(m) ? bundleIndex[m - count] : newIndex[m]; };
    std::vector<HierarchyNode> out(next);
    std::vector<uint32_t> parentOf(next, kNoNode);
    for (uint32_t i = 0; i < count; ++i) {
        if (planOf[i] != kNoNode) {
            const Plan& plan = plans[planOf[i]];
            for (uint32_t j = 0; j < plan.kept; ++j) {
                const uint32_t at = bundleIndex[plan.firstBundle + j];
                out[at] = std::move(bundles[planOf[i]][j]);
                if (j + 1 < plan.kept) parentOf[at] = at + 1;
                else if (i == sceneGroup) parentOf[at] = kNoNode;
                else if (!absorbed[i]) parentOf[at] = newIndex[i];
                else parentOf[at] = bundleIndex[bundleAbove[count + plan.firstBundle + j]];
            }
        }
        if (absorbed[i]) continue;
        const uint32_t at = newIndex[i];
        if (bundleAbove[i] != kNoNode) parentOf[at] = bundleIndex[bundleAbove[i]];
        else if (nodes[i].parent != kNoNode) parentOf[at] = newIndex[nodes[i].parent];
        out[at] = std::move(nodes[i]);
    }
    linkByParents(out, parentOf, tree.roots);
    for (auto& level : tree.nodeOfAggregate)
        for (uint32_t& i : level) i = absorbed[i] ? indexOf(standIn[i]) : newIndex[i];
    nodes = std::move(out);
    return true;
}

}  // namespace aggrelod::detail
