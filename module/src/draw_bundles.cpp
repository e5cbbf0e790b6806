// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: bundles (docs/design.md §2.6). Not from the paper: game HLOD systems merge
// the meshes of a cluster into one draw call for distant views (Unreal's HLOD, Simplygon's
// aggregation); here the merged parts are the group's own certified versions, so a bundle
// keeps every guarantee of its parts.
#include "draw_bundles.h"

#include "surface_colors.h"

#include <algorithm>
#include <cmath>

namespace aggrelod::detail {
namespace {

/// A kept bundle is lighter than the finer one kept before it by at least this share, as a
/// chain version must be to be worth a node.
constexpr size_t kWorthNumerator = 19, kWorthDenominator = 20;

double ownError(const HierarchyNode& n) { return n.leaf ? 0.0 : n.error.bound(); }

size_t triangleCount(const HierarchyNode& n, const std::vector<InputObject>& objects, uint32_t index) {
    if (n.leaf && n.meshPlace.kind == NodeMeshPlace::Kind::Object) return objects[index].indices.size() / 3;
    return n.indices.size() / 3;
}

/// One child of a group: its chain from the top down to its base (an aggregate or a leaf).
struct Chain {
    std::vector<uint32_t> members;  ///< top first, base last
};

struct Plan {
    uint32_t group = kNoNode;
    std::vector<Chain> chains;
    std::vector<double> thresholds;              ///< of the bundles kept, finest first
    std::vector<std::vector<uint32_t>> pieces;   ///< per bundle kept, one node per chain
    std::vector<uint32_t> newTops;               ///< per chain: its top below the finest bundle
};

/// The lightest member of `chain` whose error (eff) is at most t; the base qualifies for
/// every t >= its error. Ties: the one nearest the top.
uint32_t lightestWithin(const Chain& chain, double t, const std::vector<double>& eff,
                        const std::vector<HierarchyNode>& nodes, const std::vector<InputObject>& objects) {
    uint32_t best = kNoNode;
    size_t bestTriangles = SIZE_MAX;
    for (uint32_t m : chain.members) {
        if (!(eff[m] <= t)) continue;
        const size_t tri = triangleCount(nodes[m], objects, m);
        if (tri < bestTriangles) best = m, bestTriangles = tri;
    }
    return best;
}

/// Appends node m's mesh (a leaf's may be its object's) to `out`; colours white where m has
/// none, when `colored`.
void appendMesh(const HierarchyNode& m, uint32_t index, const std::vector<InputObject>& objects, bool colored,
                HierarchyNode& out) {
    const bool byObject = m.leaf && m.meshPlace.kind == NodeMeshPlace::Kind::Object;
    const InputObject& object = objects[byObject ? index : 0];
    const uint32_t base = static_cast<uint32_t>(out.positions.size() / 3);
    if (byObject) {
        out.positions.insert(out.positions.end(), object.positions.begin(), object.positions.end());
        for (uint32_t i : object.indices) out.indices.push_back(base + i);
    } else {
        out.positions.insert(out.positions.end(), m.positions.begin(), m.positions.end());
        for (uint32_t i : m.indices) out.indices.push_back(base + i);
    }
    if (!colored) return;
    const size_t triangles = (byObject ? object.indices.size() : m.indices.size()) / 3;
    const std::vector<float>* colors = byObject ? (hasTriangleColors(object) ? &object.triangleColors : nullptr)
                                                : (m.faceColors.size() == 4 * triangles ? &m.faceColors : nullptr);
    if (colors) out.faceColors.insert(out.faceColors.end(), colors->begin(), colors->end());
    else out.faceColors.insert(out.faceColors.end(), 4 * triangles, 1.0f);
}

bool hasColors(const HierarchyNode& m, uint32_t index, const std::vector<InputObject>& objects) {
    if (m.leaf && m.meshPlace.kind == NodeMeshPlace::Kind::Object) return hasTriangleColors(objects[index]);
    return !m.faceColors.empty();
}

}  // namespace

void addDrawBundles(std::vector<HierarchyNode>& nodes, std::vector<uint32_t>& roots,
                    std::vector<std::vector<uint32_t>>& nodeOfAggregate, const std::vector<InputObject>& objects,
                    const ProxySettings& settings) {
    if (settings.bundleCount <= 0) return;
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

    std::vector<Plan> plans;
    std::vector<uint32_t> planOf(count, kNoNode);
    for (uint32_t g = 0; g < count; ++g) {
        const HierarchyNode& group = nodes[g];
        if (group.leaf || group.objectLod != 0 || group.coarserStep != 0 || group.sources.size() < 2 ||
            group.children.size() < 2 || group.positions.empty())
            continue;
        Plan plan;
        plan.group = g;
        std::vector<Chain> chains;
        std::vector<double> ends;  // the error of each chain's end, ascending
        for (uint32_t c : group.children) {
            Chain chain;
            uint32_t x = c;
            while (isVersion(nodes[x])) {
                chain.members.push_back(x);
                x = nodes[x].children.front();
            }
            chain.members.push_back(x);
            ends.push_back(eff[x]);
            chains.push_back(std::move(chain));
        }
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        for (size_t v = 0; v + 2 < group.positions.size(); v += 3)
            for (int k = 0; k < 3; ++k)
                lo[k] = std::min(lo[k], group.positions[v + k]), hi[k] = std::max(hi[k], group.positions[v + k]);
        double diagonal2 = 0;
        for (int k = 0; k < 3; ++k) diagonal2 += double(hi[k] - lo[k]) * double(hi[k] - lo[k]);
        // The floor: the fraction of the diagonal. The chains ending at or below it go into the
        // bundles; a child whose chain ends higher (an aggregate with a wide fill) stays a child
        // of the group beside them, drawn apart, rather than holding every bundle above its
        // error. Where fewer than two chains end that low, the floor rises to the highest end.
        std::sort(ends.begin(), ends.end());
        double floor = settings.bundleMinErrorFraction * std::sqrt(diagonal2);
        if (!(ends[1] <= floor)) floor = ends.back();
        const double top = ownError(group);
        if (!(floor < top)) continue;
        for (Chain& chain : chains)
            if (eff[chain.members.back()] <= floor) plan.chains.push_back(std::move(chain));
        std::vector<double> candidates{floor};
        for (const Chain& chain : plan.chains)
            for (uint32_t m : chain.members)
                if (eff[m] > floor && eff[m] < top) candidates.push_back(eff[m]);
        std::sort(candidates.begin(), candidates.end());
        candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
        size_t lastTriangles = 0;
        for (double t : candidates) {
            if (int(plan.thresholds.size()) >= settings.bundleCount) break;
            std::vector<uint32_t> pieces;
            size_t triangles = 0;
            for (const Chain& chain : plan.chains) {
                pieces.push_back(lightestWithin(chain, t, eff, nodes, objects));
                triangles += triangleCount(nodes[pieces.back()], objects, pieces.back());
            }
            if (triangles > settings.bundleMaxTriangles) continue;
            if (!plan.thresholds.empty() && kWorthDenominator * triangles > kWorthNumerator * lastTriangles) continue;
            plan.thresholds.push_back(t);
            plan.pieces.push_back(std::move(pieces));
            lastTriangles = triangles;
        }
        if (plan.thresholds.empty()) continue;
        for (const Chain& chain : plan.chains) {
            size_t j = 0;
            while (!(eff[chain.members[j]] <= plan.thresholds.front())) ++j;  // the base always qualifies
            plan.newTops.push_back(chain.members[j]);
        }
        planOf[g] = static_cast<uint32_t>(plans.size());
        plans.push_back(std::move(plan));
    }
    if (plans.empty()) return;

    // Chain nodes above a finest bundle's threshold leave the tree.
    // An aggregate of one object that gave way to the object's chain is stood for by the
    // chain's top (nodeOfAggregate): by its new top when that top goes.
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

    // The bundles' meshes, made before the absorbed nodes go.
    std::vector<std::vector<HierarchyNode>> bundles(plans.size());
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
            for (uint32_t m : plan.pieces[j]) colored = colored || hasColors(nodes[m], m, objects);
            for (uint32_t m : plan.pieces[j]) {
                appendMesh(nodes[m], m, objects, colored, b);
                if (nodes[m].leaf) continue;
                const ProxyError& e = nodes[m].error;
                b.error.proxyToOriginals = std::max(b.error.proxyToOriginals, e.proxyToOriginals);
                b.error.originalsToProxy = std::max(b.error.originalsToProxy, e.originalsToProxy);
                b.error.proxyToOriginalsLower = std::max(b.error.proxyToOriginalsLower, e.proxyToOriginalsLower);
                b.error.originalsToProxyLower = std::max(b.error.originalsToProxyLower, e.originalsToProxyLower);
                b.error.tolerance = std::max(b.error.tolerance, e.tolerance);
                b.error.evaluationCount += e.evaluationCount;
            }
            bundles[p].push_back(std::move(b));
        }
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
    roots.clear();
    for (uint32_t i = 0; i < next; ++i) {
        out[i].children.clear();
        out[i].parent = parentOf[i];
    }
    for (uint32_t i = 0; i < next; ++i) {  // ascending, so children lists come out sorted
        if (parentOf[i] == kNoNode) roots.push_back(i);
        else out[parentOf[i]].children.push_back(i);
    }
    for (auto& level : nodeOfAggregate)
        for (uint32_t& i : level) i = newIndex[absorbed[i] ? standIn[i] : i];
    nodes = std::move(out);
}

}  // namespace aggrelod::detail
