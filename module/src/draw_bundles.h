// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module (internal): bundles, the drawn versions of a group's children merged into
// one mesh so that a distant group costs one draw call (docs/design.md §2.6).
#pragma once

#include <aggrelod/hierarchy_nodes.h>

#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Adds bundles (HierarchyNode::bundleStep) below every aggregate of several objects of a
/// node tree as buildHierarchyNodes puts it together: leaves first (node i = object i), then
/// every node after its children, meshes in memory (a leaf's may be its object's,
/// NodeMeshPlace::Kind::Object). Errors are the nodes' own (error.bound()); bounds and
/// geometric errors are computed afterwards.
///
/// For an aggregate G of several objects with children c_1..c_k, each the top of a chain of
/// single children (coarser versions, per-object LODs) ending at a base (an aggregate or a
/// leaf) whose error (the largest below it) is the chain's end: the floor t_0 is
/// settings.bundleMinErrorFraction * G's diagonal, and the chains ending at or below it are
/// bundled (where fewer than two do, t_0 rises to the highest end and every chain is). From
/// t_0 up to G's own error, bundle B(t) merges, for every bundled chain, its lightest node
/// whose error is at most t. The bundles kept are the finest one and each coarser one with
/// at most 19/20 of the triangles of the last kept, at most settings.bundleCount, each of at
/// most settings.bundleMaxTriangles triangles. They hang as a chain below G, finest lowest,
/// the bundled children below the finest, the other children beside the chain; the chain
/// nodes above the finest bundle's threshold leave the tree (their meshes are in the
/// bundles). A bundle is drawn only where one pixel is at least bundleMinErrorFraction of G's
/// size, where one error over the bundled children costs about what one per child would.
///
/// A bundle's error is the largest of its parts' (each certified against its own objects, so
/// the bound holds for all of them); its budget is its threshold; its parts may overlap (a
/// union of closed shells: closed and edge-manifold, not free of self-intersections).
/// nodeOfAggregate and roots are renumbered; aggregates keep their order. Deterministic.
void addDrawBundles(std::vector<HierarchyNode>& nodes, std::vector<uint32_t>& roots,
                    std::vector<std::vector<uint32_t>>& nodeOfAggregate, const std::vector<InputObject>& objects,
                    const ProxySettings& settings);

}  // namespace aggrelod::detail
