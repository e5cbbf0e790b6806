// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): bundles, the drawn versions of a group's children merged into
// one mesh so that a distant group costs one draw call (docs/design.md §2.6).
#pragma once

#include <aggrelod/hierarchy_nodes.h>

#include "node_mesh_spiller.h"

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// Adds bundles (HierarchyNode::bundleStep) below every aggregate of several objects of a
/// node tree as buildHierarchyNodes puts it together: leaves first (node i = object i), then
/// every node after its children; meshes anywhere (in the node, its object, nodes.meshFile).
/// Errors are the nodes' own (error.bound()); bounds and geometric errors are computed
/// afterwards.
///
/// For an aggregate G of several objects with children c_1..c_k, each the top of a chain of
/// single children (coarser versions, per-object LODs, aggregates of several objects with one
/// child: the same objects' aggregate one level finer) ending at a leaf or at an aggregate; an
/// aggregate whose children all joined its bundles (planned first: children come first)
/// continues the chain through its own bundles, coarsest first, down to the finest that holds
/// every child. A chain's end is the smallest error (the largest on the chain from a member
/// down) of its members other than a leaf (an original is never a part: it need not be
/// closed). The floor t_0 is the larger of settings.bundleMinErrorFraction * the diagonal of
/// G's objects' box and the second smallest end; only the chains ending below G's own error
/// can join. On thresholds from t_0 up to G's own error
/// (the chains' members' errors, at most 256 of them evenly spread), bundle B(t) merges, for
/// every chain ending at or below t, its lightest member other than a leaf whose error is at
/// most t (a bundle member: its parts). The bundles kept are the finest one and each coarser
/// one that holds more chains than the last kept (an eighth of the chains that can join
/// more, at least one, or all of them) or has at most 9/10 of its triangles, at most settings.bundleCount, each of at most
/// settings.bundleMaxTriangles triangles. They hang as a chain below G, finest lowest; a
/// chain hangs below the finest bundle holding it (the bundle it joins), the chains that
/// join none beside the bundles, below G. The chain members above the threshold of the
/// bundle a chain joins leave the tree (the bundles stand for them): nodes, and also a child
/// aggregate with its bundles above that threshold, so that its finer bundles hang below the
/// bundle of G it joins. Those members are drawn only where one pixel is at least the floor,
/// so at least bundleMinErrorFraction of G's size, where one error over the bundled children
/// costs about what one per child would.
///
/// A bundled chain's part may instead be its objects' own versions: versionsAbove[o] (empty, or
/// one list per object, each version certified against object o alone, its mesh in the node or
/// in nodes.meshFile) holds the versions of object o above its per-object LOD chain; at threshold t, where every object of a chain has
/// one within t, the lightest of each together are the chain's part when they have fewer
/// triangles than its lightest node within t (a group's versions keep the fill between its
/// objects, the objects' do not), and their errors are thresholds too.
///
/// A tree of several roots (support surfaces beside the hierarchy, groups the coarsest level
/// never joined) has its roots bundled the same way, as the children of a scene group made for
/// this at the level above the coarsest (bundleLevel = nodeOfAggregate.size(), error the
/// largest of its roots'): the scene group has no mesh and is not kept; its coarsest bundle is
/// a root, and the roots that join no bundle stay roots. So the whole scene far away costs one
/// draw call too.
///
/// A bundle's certified error is the largest of its parts' (each certified against its own
/// objects, so the bound holds for all of them); its parts may overlap (a union of closed
/// shells: closed and edge-manifold, not free of self-intersections). Its sources are the
/// objects of the chains it holds. nodeOfAggregate and roots are renumbered (an entry on a
/// removed chain node moves to the highest member left of that chain); aggregates keep their
/// order. With `spiller`, each bundle's mesh goes to it as soon as it is made. Deterministic.
/// False with `error` when a mesh cannot be read back or spilled.
bool addDrawBundles(HierarchyNodes& nodes, const std::vector<InputObject>& objects, const ProxySettings& settings,
                    const std::vector<std::vector<HierarchyNode>>& versionsAbove, NodeMeshSpiller* spiller,
                    std::string& error);

}  // namespace aggrelod::detail
