// SPDX-License-Identifier: AGPL-3.0-or-later
// Disjoint sets (union-find, Tarjan 1975) with path halving: the one copy the module and the
// bake use for shells, welded corners, touching models, groups of a level and coplanar facets.
// Standard library only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace aggrelod {

/// Elements 0 .. size()-1, each first in a set of its own.
/// unite() keeps the smaller of the two roots, so every set's root is its smallest element
/// whatever the order of the merges: labels taken from roots are deterministic.
/// attach() links one root below another for callers that balance by their own rule (union
/// by size); after it a root is no longer the set's smallest element.
class DisjointSets {
public:
    explicit DisjointSets(size_t count = 0) { reset(count); }

    /// Back to `count` singletons (keeps the storage).
    void reset(size_t count) {
        parent_.resize(count);
        std::iota(parent_.begin(), parent_.end(), uint32_t(0));
    }
    size_t size() const { return parent_.size(); }

    /// Root of x's set (x < size()).
    uint32_t find(uint32_t x) {
        while (parent_[x] != x) x = parent_[x] = parent_[parent_[x]];
        return x;
    }
    /// Joins the sets of a and b; true when they were apart.
    bool unite(uint32_t a, uint32_t b) {
        a = find(a);
        b = find(b);
        if (a == b) return false;
        if (b < a) parent_[a] = b;
        else parent_[b] = a;
        return true;
    }
    /// Makes root `child` a member of root `root`'s set (both roots, different).
    void attach(uint32_t child, uint32_t root) { parent_[child] = root; }

private:
    std::vector<uint32_t> parent_;
};

}  // namespace aggrelod
