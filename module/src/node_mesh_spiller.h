// SPDX-License-Identifier: AGPL-3.0-or-later
// Writing hierarchy nodes' meshes to a spill file (node_mesh_spill.cpp): shared by
// spillNodeMeshes and the proxies stage, which moves the meshes out as soon as its tree is
// put together (ProxySettings::meshSpillPath).
#pragma once

#include <aggrelod/hierarchy_nodes.h>

#include <cstdio>
#include <memory>
#include <string>

namespace aggrelod::detail {

/// The place of a leaf's mesh that is its object's (NodeMeshPlace::Kind::Object): the
/// object's counts, coloured where it has per-triangle colours.
NodeMeshPlace objectMeshPlace(const InputObject& object);

/// The mesh of a node that is not in nodes.nodes (a version kept aside), in the node or in
/// nodes.meshFile (read back into `storage`). Throws std::runtime_error when it cannot be read.
NodeMeshView viewDetachedNodeMesh(const HierarchyNodes& nodes, const HierarchyNode& n, NodeMesh& storage);

class NodeMeshSpiller {
public:
    /// A new spill file at `path` (removed when the last holder of file() goes).
    bool open(const std::string& path, std::string& error);
    /// Appends node n's mesh (index `node`, for messages) and gives its place; n is unchanged.
    /// write, spill and finish may be called from several threads at once (the places then
    /// follow the order of the calls; nothing but this file's readers sees them).
    bool write(const HierarchyNode& n, uint32_t node, NodeMeshPlace& place, std::string& error);
    /// write, then n's vectors emptied and its place set (an empty mesh, or one already out,
    /// stays as it is).
    bool spill(HierarchyNode& n, uint32_t node, std::string& error);
    /// Flushes what was written, so that readers see it.
    bool finish(std::string& error);
    std::shared_ptr<const NodeMeshFile> file() const { return file_; }

private:
    std::shared_ptr<NodeMeshFile> file_;
    std::FILE* raw_ = nullptr;
    uint64_t offset_ = 0;
};

}  // namespace aggrelod::detail
