// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: collision shapes per hierarchy node for physics engines.
//
// Every node with geometry collides as its own triangle mesh (the proxy; a leaf: the
// original object). Beside it, a node gets a convex decomposition when one exists within the
// node's error: one convex hull per shell (connected part) of its mesh. A shell lies inside
// its hull, and the proxy contains its originals, so the hulls contain the originals as well
// (conservative). Each hull's distance to the originals (hull surface -> nearest original
// surface) is measured with the certified bound of measureProxyError; the decomposition is
// kept only when every hull's bound is at most the node's stored geometric error plus a
// rounding allowance, so that the node's error stays true for it. The hulls of one node may
// overlap one another.
//
// Units: world units throughout. Deterministic: the same nodes and settings give the same
// shapes for every thread count.
#pragma once

#include <aggrelod/hierarchy_nodes.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod {

struct CollisionShapeSettings {
    /// Nodes whose mesh has more shells than this get no convex decomposition ("small
    /// nodes" only: a few convex parts). 0: no node gets one.
    size_t maxShells = 16;
    /// Hulls with more vertices than this are not used (engines limit convex hull sizes;
    /// Bullet recommends well under 100). 0: no limit.
    size_t maxHullVertices = 255;
    /// Allowance above the node's stored geometric error for the hulls' certified bound, as a
    /// fraction of the diagonal of the node's box: covers the rounding of the measurement
    /// (a leaf has error 0, so a convex original needs it to pass).
    double roundingFraction = 1e-6;
    /// Refinement limit of the error measurement (see ProxySettings).
    size_t maxRefinementsPerDirection = 20000;
    int threadCount = 0;  ///< 0 = hardware concurrency; results identical for every count
};

/// One convex part: the convex hull of one shell of a node's mesh (closed, outward).
/// Its vertices are vertices of the node's mesh (bit-identical floats).
struct ConvexPart {
    std::vector<float> positions;  ///< 3 * vertexCount, world units
    std::vector<uint32_t> indices; ///< 3 * triangleCount, outward
    /// Certified upper bound of the distance from any point of the hull's surface to the
    /// nearest surface of the node's originals, world units.
    double errorBound = 0;
};

struct NodeCollisionShapes {
    /// The convex decomposition; empty when the node has none (then `reason` says why).
    std::vector<ConvexPart> convexParts;
    /// max errorBound over the parts (0 when there are none), world units.
    double convexError = 0;
    /// What the parts were held to: the node's geometric error plus the rounding allowance.
    double allowance = 0;
    size_t shellCount = 0;  ///< connected parts of the node's mesh (vertices welded by position)
    std::string reason;     ///< empty when convexParts is filled
};

/// Collision shapes of every node of `nodes` (out[i] for nodes.nodes[i]), baked from
/// `objects` (the same array as for buildHierarchyNodes). Returns false with `error` when
/// the two do not match. Never throws for such input.
bool buildCollisionShapes(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                          const CollisionShapeSettings& settings, std::vector<NodeCollisionShapes>& out,
                          std::string& error);

}  // namespace aggrelod
