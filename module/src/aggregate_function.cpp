// SPDX-License-Identifier: AGPL-3.0-or-later
// Built-in aggregate functions (paper Section 3.3).
//   constant, Eq. 1:  F(m1, m2) = delta
//   adaptive, Eq. 2:  F(m1, m2) = 0.5 * (min(m1, m2) + sigma(m1, m2) + delta)
// sigma(m1, m2) is the population standard deviation of the lengths of the free-space
// triangulation edges joining m1 and m2 that are shorter than delta: the connections this
// level joins. (With all connections, sigma of two spheres spans their whole diameter and
// F exceeded delta: the adaptive shape came out fatter than the constant one; see README.)
// With this choice sigma <= (delta - min) / 2, so F <= delta.
// For an edge with both ends on one model, min = 0 and sigma = 0, so F = delta / 2:
// concavities of a single model are filled only when their mouth is under delta / 2.
#include <aggrelod/aggregate_common.h>

namespace aggrelod {

AggregateFunction makeAggregateFunction(AggregateFunctionKind kind) {
    if (kind == AggregateFunctionKind::Constant) {
        return [](const AggregateFunctionInput& in) { return in.delta; };
    }
    return [](const AggregateFunctionInput& in) {
        return 0.5 * (in.minDistance + in.sigma + in.delta);
    };
}

}  // namespace aggrelod
