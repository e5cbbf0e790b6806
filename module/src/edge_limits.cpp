// SPDX-License-Identifier: AGPL-3.0-or-later
// Edge limits (paper Section 3.3; docs/design.md §2.4 step 3): see edge_limits.h.
#include "edge_limits.h"

#include <cmath>

namespace aggrelod::detail {
namespace {

/// F at `delta` for an edge of no pair: sameModel tells which kind (AggregateFunctionInput).
double limitWithoutPair(const AggregateFunction& function, double delta, bool sameModel) {
    AggregateFunctionInput in;
    in.delta = delta;
    in.sameModel = sameModel;
    return function(in);
}

/// limits.pair for every pair, and limits.smallest. minDistanceOf(pair): the distance F reads.
template <class Pair, class MinDistanceOf>
void fillPairLimits(EdgeLimits& limits, const std::vector<Pair>& pairs, const PairEdgeLengths& lengths,
                    const AggregateFunction& function, MinDistanceOf minDistanceOf) {
    limits.pair.resize(pairs.size());
    for (size_t p = 0; p < pairs.size(); ++p) {
        AggregateFunctionInput in;
        in.delta = limits.delta;
        in.minDistance = minDistanceOf(pairs[p]);
        // sigma over the joining edges shorter than delta (see aggregate_function.cpp).
        const EdgeLengthStatistics shorter = lengths.below(pairs[p], limits.delta);
        in.meanEdgeLength = shorter.mean;
        in.sigma = shorter.sigma;
        in.sigmaAllEdges = lengths.all(pairs[p]).sigma;
        limits.pair[p] = function(in);
    }
    // (A NaN limit never carves, so it is left out.)
    limits.smallest = INFINITY;
    auto least = [&](double limit) {
        if (limit < limits.smallest) limits.smallest = limit;
    };
    least(limits.sameModel);
    least(limits.unpaired);
    for (double limit : limits.pair) least(limit);
}

}  // namespace

EdgeLimits computeEdgeLimits(const FreeSpace2D& space, double delta, const AggregateFunction& function) {
    EdgeLimits limits;
    limits.delta = delta;
    limits.sameModel = limitWithoutPair(function, delta, true);
    limits.unpaired = limits.sameModel;  // a Steiner end lies on no model: as within one
    fillPairLimits(limits, space.pairs, space.edgeLengths, function,
                   [](const ModelPair2D& pair) { return pair.minDistance; });
    return limits;
}

EdgeLimits computeEdgeLimits(const FreeSpace& space, double delta, const AggregateFunction& function,
                             DistanceMode distance) {
    EdgeLimits limits;
    limits.delta = delta;
    limits.sameModel = limitWithoutPair(function, delta, true);
    limits.unpaired = limitWithoutPair(function, delta, false);
    fillPairLimits(limits, space.pairs, space.edgeLengths, function, [distance](const ModelPair& pair) {
        return distance == DistanceMode::Exact ? pair.exactDistance : pair.shortestEdge;
    });
    return limits;
}

}  // namespace aggrelod::detail
