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

// Edge indices by (weight, smaller id, larger id, index). Edges that already come in
// (smaller id, larger id) order (the 2D graph's pairs do) with finite non-negative weights
// take a stable LSD radix sort of (weight rounded to float, index) keys, three linear passes
// instead of a comparison sort of the whole graph; float rounding is monotone for such
// doubles, and the few runs of equal floats are then sorted stably on the double itself.
std::vector<uint32_t> edgeOrder(const std::vector<GraphEdge>& edges) {
    const size_t n = edges.size();
    auto lo = [&](size_t i) { return std::min(edges[i].a, edges[i].b); };
    auto hi = [&](size_t i) { return std::max(edges[i].a, edges[i].b); };
    bool radix = n > 256;
    for (size_t i = 0; i < n && radix; ++i) {
        const double w = edges[i].weight;
        radix = w >= 0 && !std::signbit(w) && std::isfinite(w) &&
                (i == 0 || std::make_pair(lo(i - 1), hi(i - 1)) <= std::make_pair(lo(i), hi(i)));
    }
    std::vector<uint32_t> order(n);
    if (!radix) {
        std::iota(order.begin(), order.end(), 0u);
        std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) {
            return std::make_tuple(edges[x].weight, lo(x), hi(x), x) < std::make_tuple(edges[y].weight, lo(y), hi(y), y);
        });
        return order;
    }
    auto rounded = [&](size_t i) { return static_cast<float>(edges[i].weight); };
    std::vector<uint64_t> keyed(n);  // float bits << 32 | index
    for (size_t i = 0; i < n; ++i) {
        const float r = rounded(i);
        uint32_t bits;
        std::memcpy(&bits, &r, sizeof bits);
        keyed[i] = static_cast<uint64_t>(bits) << 32 | i;
    }
    detail::radixSortStable(keyed, [](uint64_t k) { return k >> 32; }, 32);
    for (size_t i = 0; i < n; ++i) order[i] = static_cast<uint32_t>(keyed[i]);
    for (size_t i = 0; i < n;) {
        size_t end = i + 1;
        while (end < n && (keyed[end] >> 32) == (keyed[i] >> 32)) ++end;
        if (end - i > 1)
            std::stable_sort(order.begin() + i, order.begin() + end,
                             [&](uint32_t x, uint32_t y) { return edges[x].weight < edges[y].weight; });
        i = end;
    }
    return order;
}

}  // namespace

std::vector<Merge> kruskalMerges(size_t modelCount, const std::vector<GraphEdge>& edges, std::vector<uint32_t>* mergeEdge) {
    DisjointSets sets(modelCount);
    std::vector<Merge> merges;
    if (mergeEdge) mergeEdge->clear();
    const std::vector<uint32_t> order = edgeOrder(edges);
    for (const uint32_t i : order) {
        const uint32_t a = std::min(edges[i].a, edges[i].b), b = std::max(edges[i].a, edges[i].b);
        if (b >= modelCount || a == b) continue;
        uint32_t ra = sets.find(a), rb = sets.find(b);
        if (ra == rb) continue;
        sets.parent[std::max(ra, rb)] = std::min(ra, rb);
        merges.push_back(Merge{edges[i].weight, a, b});
        if (mergeEdge) mergeEdge->push_back(i);
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
