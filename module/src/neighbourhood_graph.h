// SPDX-License-Identifier: AGPL-3.0-or-later
// The neighbourhood graph shared by 2D and 3D (paper Section 3.2; docs/design.md §2.2): one
// vertex per model, one edge per model pair joined by free-space triangulation edges, and per
// pair the lengths of those edges with the statistics the aggregate function reads (the mean
// and spread of the lengths shorter than δ, paper Section 3.3). The dimension-specific graph
// builders (neighbourhood_graph_2d.cpp, neighbourhood_graph_3d.cpp) fill these structures.
#pragma once

#include <aggrelod/dendrogram.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <tuple>
#include <utility>
#include <vector>

namespace aggrelod::detail {

/// Per free-space triangulation edge, its pair index, or one of these.
constexpr int kSameModelEdge = -1;  ///< both ends on one model (in 3D also: on Steiner points only)
constexpr int kUnpairedEdge = -2;   ///< an end is a Steiner point (2D), or two models with no pair (3D)

/// One edge of the neighbourhood graph: a model pair and where its free-space edge lengths lie.
struct GraphPair {
    uint32_t a = 0, b = 0;       ///< models, a < b
    uint32_t firstLength = 0;    ///< PairEdgeLengths::lengths[firstLength, + lengthCount)
    uint32_t lengthCount = 0;    ///< free-space triangulation edges joining a and b
    uint32_t firstPrefix = 0;    ///< PairEdgeLengths::prefixSum(Squares)[firstPrefix, + lengthCount + 1)
};

/// Mean and population standard deviation of some of a pair's edge lengths (world units).
struct EdgeLengthStatistics {
    uint32_t count = 0;  ///< edges counted
    double mean = 0;     ///< 0 when count is 0
    double sigma = 0;    ///< 0 when count is 0
};

/// Every pair's free-space edge lengths, ascending within the pair, with running sums so that
/// the statistics of the edges shorter than any δ take one binary search.
struct PairEdgeLengths {
    std::vector<double> lengths;           ///< per pair: lengthCount values, ascending
    std::vector<double> prefixSum;         ///< per pair: lengthCount + 1 running sums, from 0
    std::vector<double> prefixSumSquares;  ///< per pair: the same for the squared lengths

    void clear() {
        lengths.clear();
        prefixSum.clear();
        prefixSumSquares.clear();
    }

    /// Appends the pair's lengths (`count` values at `sorted`, ascending) and its running sums,
    /// and sets p.firstLength, p.lengthCount and p.firstPrefix. For pairs made one by one.
    void append(GraphPair& p, const double* sorted, size_t count) {
        p.firstLength = static_cast<uint32_t>(lengths.size());
        p.lengthCount = static_cast<uint32_t>(count);
        p.firstPrefix = static_cast<uint32_t>(prefixSum.size());
        lengths.insert(lengths.end(), sorted, sorted + count);
        prefixSum.resize(prefixSum.size() + count + 1);
        prefixSumSquares.resize(prefixSumSquares.size() + count + 1);
        fillRunningSums(p);
    }

    /// Writes the running sums of p, whose lengths already lie sorted in `lengths` and whose
    /// slots in the sums exist. For pairs filled in parallel, each in its own slots.
    void fillRunningSums(const GraphPair& p) {
        const double* run = lengths.data() + p.firstLength;
        double* sum = prefixSum.data() + p.firstPrefix;
        double* sumSquares = prefixSumSquares.data() + p.firstPrefix;
        sum[0] = sumSquares[0] = 0;
        for (size_t k = 0; k < p.lengthCount; ++k) {
            sum[k + 1] = sum[k] + run[k];
            sumSquares[k + 1] = sumSquares[k] + run[k] * run[k];
        }
    }

    /// Statistics of p's edges shorter than `limit` (world units).
    EdgeLengthStatistics below(const GraphPair& p, double limit) const {
        const double* run = lengths.data() + p.firstLength;
        return first(p, static_cast<size_t>(std::lower_bound(run, run + p.lengthCount, limit) - run));
    }

    /// Statistics of all of p's edges.
    EdgeLengthStatistics all(const GraphPair& p) const { return first(p, p.lengthCount); }

private:
    EdgeLengthStatistics first(const GraphPair& p, size_t count) const {
        EdgeLengthStatistics s;
        s.count = static_cast<uint32_t>(count);
        if (count == 0) return s;
        const double n = static_cast<double>(count);
        s.mean = prefixSum[p.firstPrefix + count] / n;
        s.sigma = std::sqrt(std::max(0.0, prefixSumSquares[p.firstPrefix + count] / n - s.mean * s.mean));
        return s;
    }
};

/// Index of the pair (a, b), in either order, in `pairs` sorted by (a, b); -1 when absent.
template <class Pair>
int findPair(const std::vector<Pair>& pairs, uint32_t a, uint32_t b) {
    if (a > b) std::swap(a, b);
    auto it = std::lower_bound(pairs.begin(), pairs.end(), std::make_pair(a, b),
                               [](const Pair& p, const std::pair<uint32_t, uint32_t>& key) {
                                   return std::tie(p.a, p.b) < std::tie(key.first, key.second);
                               });
    if (it == pairs.end() || it->a != a || it->b != b) return -1;
    return static_cast<int>(it - pairs.begin());
}

/// The graph as the dendrogram reads it: one edge per pair, weighed by weightOf(pair).
template <class Pair, class WeightOf>
std::vector<GraphEdge> graphEdges(const std::vector<Pair>& pairs, WeightOf weightOf) {
    std::vector<GraphEdge> graph;
    graph.reserve(pairs.size());
    for (const Pair& p : pairs) graph.push_back(GraphEdge{p.a, p.b, weightOf(p)});
    return graph;
}

}  // namespace aggrelod::detail
