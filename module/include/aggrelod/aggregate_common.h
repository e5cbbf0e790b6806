// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: types shared by the 2D and 3D pipelines (diagnostics, aggregate
// functions, progress, dendrogram merges). Included by aggregate2d.h and aggregate3d.h.
#pragma once

#include <cstdint>
#include <functional>
#include <string>

namespace aggrelod {

/// A problem found in the input or while baking. Never fatal unless severity is Error.
struct Diagnostic {
    enum class Severity { Note, Warning, Error };
    Severity severity = Severity::Warning;
    std::string object;   ///< object name(s) concerned; empty for scene-wide problems
    std::string message;  ///< what is wrong and what was done about it
};

/// Which aggregate function sculpts the fill (docs/design.md §2.4, paper Eqs. 1 and 2).
enum class AggregateFunctionKind {
    Adaptive,  ///< F = 0.5 * (min(m1,m2) + sigma(m1,m2) + delta)
    Constant   ///< F = delta
};

/// Inputs of an aggregate function for one exposed edge whose endpoints lie on models m1, m2.
struct AggregateFunctionInput {
    double delta = 0;            ///< level threshold
    double minDistance = 0;      ///< minimum distance between m1 and m2 (0 when m1 == m2)
    double sigma = 0;            ///< std deviation of the free-space edge lengths joining m1, m2 that are shorter than delta
    double meanEdgeLength = 0;   ///< mean of those lengths
    double sigmaAllEdges = 0;    ///< std deviation of all free-space edge lengths joining m1, m2
    bool sameModel = false;      ///< m1 == m2
};
/// Pluggable aggregate function: returns the longest exposed edge length kept (world units).
/// Called from the calling thread only, once per model pair and level.
using AggregateFunction = std::function<double(const AggregateFunctionInput&)>;

/// Built-in functions. Constant: paper Eq. 1. Adaptive: paper Eq. 2 (sigma documented in README).
AggregateFunction makeAggregateFunction(AggregateFunctionKind kind);

/// Progress report: stage name and fraction done in [0, 1]. Called from the baking thread.
using ProgressCallback = std::function<void(const char* stage, double fraction)>;

/// One Kruskal merge of the dendrogram.
struct Merge {
    double height = 0;          ///< graph edge weight (distance) that caused the merge
    uint32_t modelA = 0, modelB = 0;
};

}  // namespace aggrelod
