// SPDX-License-Identifier: AGPL-3.0-or-later
// Carving, shared by 2D and 3D (paper Section 3.3, step 2 of the sculpting; docs/design.md
// §2.4): a kept free element (triangle or tetrahedron) with an exposed edge longer than the
// aggregate function allows is removed, which exposes its neighbours in turn. Removal is
// monotone (an element that may be removed stays so until it is: removing an element only
// exposes more of its neighbours' edges), so the removed set is the same in any order and
// a plain stack finds it in linear time.
#pragma once

#include <vector>

namespace aggrelod::detail {

/// Carves `label` in place (set to -1 for a removed element).
/// kNeighbours: 3 for triangles, 4 for tetrahedra.
/// seeds(push): calls push(e) for every element that may be carvable now (any superset of them).
/// neighbourOf(e, j): element across side j of e, or -1.
/// carvable(e): e is free, kept (label >= 0), not protected, and has an exposed edge over its
/// limit, given the current labels.
template <int kNeighbours, class Seeds, class NeighbourOf, class Carvable>
void carveFromOutside(std::vector<int>& label, Seeds&& seeds, NeighbourOf&& neighbourOf, Carvable&& carvable) {
    std::vector<int> stack;
    seeds([&](int e) {
        if (carvable(e)) stack.push_back(e);
    });
    while (!stack.empty()) {
        const int e = stack.back();
        stack.pop_back();
        if (label[e] < 0) continue;  // already removed (pushed by two neighbours)
        const int group = label[e];
        label[e] = -1;
        for (int j = 0; j < kNeighbours; ++j) {
            const int n = neighbourOf(e, j);
            if (n >= 0 && label[n] == group && carvable(n)) stack.push_back(n);
        }
    }
}

}  // namespace aggrelod::detail
