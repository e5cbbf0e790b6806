// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: hierarchy nodes -> the runtime contract (module) -> scene.aglod (docs/design.md §4).
#include "runtime_export.h"

#include <aggrelod/hierarchy_export.h>

#include <algorithm>
#include <cstdio>
#include <utility>

namespace aggrelod::io {

uint64_t settingsHash(const std::string& text) {
    uint64_t h = 14695981039346656037ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

bool writeRuntimeScene(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       uint64_t hash, const std::string& toolVersion, const std::string& path,
                       std::string& error, int threadCount) {
    // A node at a time: the vertex arrays of a large hierarchy wait in spill files, not beside
    // the nodes in memory.
    std::vector<std::string> names;
    names.reserve(objects.size());
    for (const InputObject& o : objects) names.push_back(o.name);
    runtime::RuntimeFileStreamWriter writer;
    const bool written =
        writer.open(path, std::move(names), hash, toolVersion, error) &&
        exportHierarchyNodes(nodes, objects, threadCount, [&](size_t i, const runtime::NodeRecord& record, const RenderMesh& mesh,
                                                     std::string& message) {
            const HierarchyNode& n = nodes.nodes[i];
            return writer.addNode(record, n.children.data(), n.children.size(), n.sources.data(), n.sources.size(),
                                  mesh.positions.data(), mesh.normals.data(), mesh.colors.data(),
                                  mesh.positions.size() / 3, mesh.indices.data(), mesh.indices.size(), message);
        }, error) &&
        writer.finish(error);
    if (!written && error.rfind(path, 0) != 0) error = path + ": " + error;
    return written;
}

}  // namespace aggrelod::io
