// Kruskal dendrogram and level thresholds (DESIGN 2.3; paper Algorithm 1, Section 3.2).
#include <aggrelod/dendrogram.h>

#include "radix_sort.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <tuple>

namespace aggrelod {
namespace {
struct DisjointSets {
    std::vector<uint32_t> parent;
    explicit DisjointSets(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    uint32_t find(uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
};

struct RankedEdge {
    GraphEdge edge;
    uint32_t index;  // in the caller's list
};

// Sorts by (weight, a, b, index). Edges that already come in (a, b) order (the 2D graph's
// pairs do) with finite non-negative weights take a stable LSD radix sort on the weight: a
// few linear passes instead of a comparison sort of the whole graph.
void sortByWeightThenIds(std::vector<RankedEdge>& edges) {
    auto byIds = [](const RankedEdge& x, const RankedEdge& y) {
        return std::tie(x.edge.a, x.edge.b, x.index) < std::tie(y.edge.a, y.edge.b, y.index);
    };
    bool radix = edges.size() > 256 && std::is_sorted(edges.begin(), edges.end(), byIds);
    for (size_t i = 0; i < edges.size() && radix; ++i) {
        const double w = edges[i].edge.weight;
        radix = w >= 0 && !std::signbit(w) && std::isfinite(w);
    }
    if (!radix) {
        std::sort(edges.begin(), edges.end(), [](const RankedEdge& x, const RankedEdge& y) {
            return std::tie(x.edge.weight, x.edge.a, x.edge.b, x.index) < std::tie(y.edge.weight, y.edge.a, y.edge.b, y.index);
        });
        return;
    }
    // Three passes on the weight rounded to float (monotone for these doubles), then the few
    // runs of equal floats sorted stably on the double itself.
    detail::radixSortStable(
        edges,
        [](const RankedEdge& e) {
            const float rounded = static_cast<float>(e.edge.weight);
            uint32_t bits;
            std::memcpy(&bits, &rounded, sizeof bits);
            return static_cast<uint64_t>(bits);
        },
        32);
    auto rounded = [&](size_t i) { return static_cast<float>(edges[i].edge.weight); };
    for (size_t i = 0; i < edges.size();) {
        size_t end = i + 1;
        while (end < edges.size() && rounded(end) == rounded(i)) ++end;
        if (end - i > 1)
            std::stable_sort(edges.begin() + i, edges.begin() + end,
                             [](const RankedEdge& x, const RankedEdge& y) { return x.edge.weight < y.edge.weight; });
        i = end;
    }
}

}  // namespace

std::vector<Merge> kruskalMerges(size_t modelCount, const std::vector<GraphEdge>& edges, std::vector<uint32_t>* mergeEdge) {
    std::vector<RankedEdge> ranked(edges.size());
    for (size_t i = 0; i < edges.size(); ++i) {
        ranked[i] = {edges[i], static_cast<uint32_t>(i)};
        if (ranked[i].edge.a > ranked[i].edge.b) std::swap(ranked[i].edge.a, ranked[i].edge.b);
    }
    sortByWeightThenIds(ranked);
    DisjointSets sets(modelCount);
    std::vector<Merge> merges;
    if (mergeEdge) mergeEdge->clear();
    for (const RankedEdge& r : ranked) {
        const GraphEdge& e = r.edge;
        if (e.a >= modelCount || e.b >= modelCount || e.a == e.b) continue;
        uint32_t ra = sets.find(e.a), rb = sets.find(e.b);
        if (ra == rb) continue;
        sets.parent[std::max(ra, rb)] = std::min(ra, rb);
        merges.push_back(Merge{e.weight, e.a, e.b});
        if (mergeEdge) mergeEdge->push_back(r.index);
    }
    return merges;
}

std::vector<uint32_t> groupsAtThreshold(size_t modelCount, const std::vector<Merge>& merges, double delta,
                                        size_t* groupCount) {
    DisjointSets sets(modelCount);
    for (const Merge& m : merges) {
        if (!(m.height < delta)) break;  // merges are ascending
        uint32_t ra = sets.find(m.modelA), rb = sets.find(m.modelB);
        if (ra != rb) sets.parent[std::max(ra, rb)] = std::min(ra, rb);
    }
    // Roots are the smallest member (parent always points to the smaller index).
    std::vector<uint32_t> group(modelCount, UINT32_MAX);
    std::vector<uint32_t> rootGroup(modelCount, UINT32_MAX);
    uint32_t next = 0;
    for (size_t m = 0; m < modelCount; ++m) {
        uint32_t r = sets.find(static_cast<uint32_t>(m));
        if (rootGroup[r] == UINT32_MAX) rootGroup[r] = next++;
        group[m] = rootGroup[r];
    }
    if (groupCount) *groupCount = next;
    return group;
}

std::vector<double> automaticDeltas(const std::vector<Merge>& merges, int levelCount) {
    std::vector<double> heights;
    for (const Merge& m : merges) heights.push_back(m.height);
    std::sort(heights.begin(), heights.end());
    heights.erase(std::unique(heights.begin(), heights.end()), heights.end());
    std::vector<double> deltas;
    if (heights.empty() || levelCount <= 0) return deltas;
    // Just above a height h: halfway to the next distinct height (or 10 % above the last).
    auto above = [&](size_t i) {
        double h = heights[i];
        double next = i + 1 < heights.size() ? heights[i + 1] : (h > 0 ? h * 1.1 : 1e-12);
        return h + 0.5 * (next - h);
    };
    const double lo = std::max(heights.front(), heights.back() * 1e-9);
    const double hi = heights.back();
    std::vector<size_t> chosen;
    for (int i = 0; i < levelCount; ++i) {
        double target = levelCount == 1 ? hi : lo * std::pow(hi / lo, static_cast<double>(i) / (levelCount - 1));
        size_t idx = static_cast<size_t>(std::lower_bound(heights.begin(), heights.end(), target * (1 - 1e-12)) - heights.begin());
        if (idx >= heights.size()) idx = heights.size() - 1;
        if (!chosen.empty() && idx <= chosen.back()) {
            if (chosen.back() + 1 >= heights.size()) continue;
            idx = chosen.back() + 1;  // keep levels distinct while heights remain
        }
        chosen.push_back(idx);
    }
    if (chosen.empty() || chosen.back() != heights.size() - 1) chosen.push_back(heights.size() - 1);
    for (size_t i : chosen) deltas.push_back(above(i));
    deltas.erase(std::unique(deltas.begin(), deltas.end()), deltas.end());
    return deltas;
}

}  // namespace aggrelod
