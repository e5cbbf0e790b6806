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

// Sorts by (weight, a, b). Edges that already come in (a, b) order (the 2D graph's pairs do)
// with non-negative weights take a stable LSD radix sort on the weight's bits (for such
// doubles the bit patterns order as the values): a few linear passes instead of a
// comparison sort of the whole graph.
void sortByWeightThenIds(std::vector<GraphEdge>& edges) {
    auto byIds = [](const GraphEdge& x, const GraphEdge& y) { return std::tie(x.a, x.b) < std::tie(y.a, y.b); };
    bool radix = edges.size() > 256 && std::is_sorted(edges.begin(), edges.end(), byIds);
    for (size_t i = 0; i < edges.size() && radix; ++i)
        radix = edges[i].weight >= 0 && !std::signbit(edges[i].weight) && std::isfinite(edges[i].weight);
    if (!radix) {
        std::sort(edges.begin(), edges.end(), [](const GraphEdge& x, const GraphEdge& y) {
            return std::tie(x.weight, x.a, x.b) < std::tie(y.weight, y.a, y.b);
        });
        return;
    }
    detail::radixSortStable(edges, [](const GraphEdge& e) {
        uint64_t bits;
        std::memcpy(&bits, &e.weight, sizeof bits);
        return bits;
    });
}

}  // namespace

std::vector<Merge> kruskalMerges(size_t modelCount, std::vector<GraphEdge> edges) {
    for (GraphEdge& e : edges)
        if (e.a > e.b) std::swap(e.a, e.b);
    sortByWeightThenIds(edges);
    DisjointSets sets(modelCount);
    std::vector<Merge> merges;
    for (const GraphEdge& e : edges) {
        if (e.a >= modelCount || e.b >= modelCount || e.a == e.b) continue;
        uint32_t ra = sets.find(e.a), rb = sets.find(e.b);
        if (ra == rb) continue;
        sets.parent[std::max(ra, rb)] = std::min(ra, rb);
        merges.push_back(Merge{e.weight, e.a, e.b});
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
