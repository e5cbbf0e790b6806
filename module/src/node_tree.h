// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): a node tree's links made again from each node's parent.
#pragma once

#include <aggrelod/hierarchy_nodes.h>

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Sets every node's parent to parentOf[i] (kNoNode for a root) and its children to the nodes
/// naming it, ascending; roots gets the parentless nodes, ascending. parentOf.size() ==
/// nodes.size().
inline void linkByParents(std::vector<HierarchyNode>& nodes, const std::vector<uint32_t>& parentOf,
                          std::vector<uint32_t>& roots) {
    roots.clear();
    for (size_t i = 0; i < nodes.size(); ++i) {
        nodes[i].children.clear();
        nodes[i].parent = parentOf[i];
    }
    for (uint32_t i = 0; i < nodes.size(); ++i) {  // ascending, so children lists come out sorted
        if (parentOf[i] == kNoNode) roots.push_back(i);
        else nodes[parentOf[i]].children.push_back(i);
    }
}

}  // namespace aggrelod::detail
