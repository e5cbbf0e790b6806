// SPDX-License-Identifier: AGPL-3.0-or-later
// Kruskal dendrogram and level thresholds (docs/design.md §2.3; paper Algorithm 1, Section 3.2).
#include <aggrelod/dendrogram.h>
#include <aggrelod/disjoint_sets.h>

#include "radix_sort.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numeric>
#include <tuple>

namespace aggrelod {
namespace {
struct SortedEdge {
    uint32_t index, a, b;  // a < b
    uint32_t rounded;      // bits of the weight rounded to float (radix path)
};

// Edges by (weight, smaller id, larger id, index). Edges that already come in (smaller id,
// larger id) order (the 2D graph's pairs do) with finite non-negative weights take a stable
// LSD radix sort on the weight rounded to float (monotone for such doubles), a few linear
// passes instead of a comparison sort of the whole graph; the few runs of equal floats are
// then sorted stably on the double itself. The ids travel with the keys, so the merge loop
// reads the sorted list in order.
std::vector<SortedEdge> sortEdges(const std::vector<GraphEdge>& edges) {
    const size_t n = edges.size();
    std::vector<SortedEdge> sorted(n);
    for (size_t i = 0; i < n; ++i)
        sorted[i] = {static_cast<uint32_t>(i), std::min(edges[i].a, edges[i].b), std::max(edges[i].a, edges[i].b), 0};
    bool radix = n > 256;
    for (size_t i = 0; i < n && radix; ++i) {
        const double w = edges[i].weight;
        radix = w >= 0 && !std::signbit(w) && std::isfinite(w) &&
                (i == 0 || std::tie(sorted[i - 1].a, sorted[i - 1].b) <= std::tie(sorted[i].a, sorted[i].b));
    }
    if (!radix) {
        std::sort(sorted.begin(), sorted.end(), [&](const SortedEdge& x, const SortedEdge& y) {
            return std::tie(edges[x.index].weight, x.a, x.b, x.index) < std::tie(edges[y.index].weight, y.a, y.b, y.index);
        });
        return sorted;
    }
    for (SortedEdge& e : sorted) {
        const float r = static_cast<float>(edges[e.index].weight);
        std::memcpy(&e.rounded, &r, sizeof e.rounded);
    }
    detail::radixSortStable(sorted, [](const SortedEdge& e) { return static_cast<uint64_t>(e.rounded); }, 32);
    for (size_t i = 0; i < n;) {
        size_t end = i + 1;
        while (end < n && sorted[end].rounded == sorted[i].rounded) ++end;
        auto lighter = [&](const SortedEdge& x, const SortedEdge& y) { return edges[x.index].weight < edges[y.index].weight; };
        if (end - i > 16) std::stable_sort(sorted.begin() + i, sorted.begin() + end, lighter);
        else  // the usual case: two or three edges (an insertion sort, stable)
            for (size_t j = i + 1; j < end; ++j)
                for (size_t k = j; k > i && lighter(sorted[k], sorted[k - 1]); --k) std::swap(sorted[k], sorted[k - 1]);
        i = end;
    }
    return sorted;
}

}  // namespace

std::vector<Merge> kruskalMerges(size_t modelCount, const std::vector<GraphEdge>& edges, std::vector<uint32_t>* mergeEdge) {
    // Union by size (the partition is all that matters here): short trees, whatever the
    // order of the merges.
    DisjointSets sets(modelCount);
    std::vector<uint32_t> size(modelCount, 1);
    std::vector<Merge> merges;
    merges.reserve(modelCount > 0 ? modelCount - 1 : 0);
    if (mergeEdge) {
        mergeEdge->clear();
        mergeEdge->reserve(merges.capacity());
    }
    for (const SortedEdge& e : sortEdges(edges)) {
        if (e.b >= modelCount || e.a == e.b) continue;
        uint32_t ra = sets.find(e.a), rb = sets.find(e.b);
        if (ra == rb) continue;
        if (size[ra] < size[rb]) std::swap(ra, rb);
        sets.attach(rb, ra);
        size[ra] += size[rb];
        merges.push_back(Merge{edges[e.index].weight, e.a, e.b});
        if (mergeEdge) mergeEdge->push_back(e.index);
    }
    return merges;
}

std::vector<uint32_t> groupsAtThreshold(size_t modelCount, const std::vector<Merge>& merges, double delta,
                                        size_t* groupCount) {
    DisjointSets sets(modelCount);
    for (const Merge& m : merges) {
        if (!(m.height < delta)) break;  // merges are ascending
        sets.unite(m.modelA, m.modelB);
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

bool validThresholds(const std::vector<double>& deltas, std::string& problem) {
    for (double d : deltas)
        if (!std::isfinite(d) || d < 0) {
            problem = "every threshold delta must be a finite number >= 0";
            return false;
        }
    return true;
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
