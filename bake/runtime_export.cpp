// aggrelod bake: hierarchy nodes -> runtime BuildParams -> scene.aglod (DESIGN section 4).
#include "runtime_export.h"

#include <cstdio>
#include <limits>

namespace aggrelod::io {

uint64_t settingsHash(const std::string& text) {
    uint64_t h = 14695981039346656037ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

bool fillBuildParams(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     uint64_t hash, const std::string& toolVersion, runtime::BuildParams& params,
                     std::string& error) {
    params = runtime::BuildParams{};
    params.settingsHash = hash;
    params.toolVersion = toolVersion;
    for (const InputObject& o : objects) params.objectNames.push_back(o.name);
    size_t totalChildren = 0, totalSources = 0, totalPositions = 0, totalIndices = 0;
    for (const HierarchyNode& n : nodes.nodes) {
        totalChildren += n.children.size();
        totalSources += n.sources.size();
        totalPositions += n.positions.size();
        totalIndices += n.indices.size();
    }
    const size_t limit = std::numeric_limits<uint32_t>::max() - 1;
    if (nodes.nodes.size() > limit || totalChildren > limit || totalSources > limit || totalPositions / 3 > limit ||
        totalIndices > limit) {
        error = "the hierarchy is too large for the runtime file (more than 2^32 nodes, vertices or indices)";
        return false;
    }
    params.nodes.reserve(nodes.nodes.size());
    params.childIndices.reserve(totalChildren);
    params.sourceObjects.reserve(totalSources);
    params.positions.reserve(totalPositions);
    params.indices.reserve(totalIndices);
    for (const HierarchyNode& n : nodes.nodes) {
        runtime::BuildNode b;
        b.parent = n.parent == kNoNode ? runtime::kNoIndex : n.parent;
        b.firstChild = static_cast<uint32_t>(params.childIndices.size());
        b.childCount = static_cast<uint32_t>(n.children.size());
        params.childIndices.insert(params.childIndices.end(), n.children.begin(), n.children.end());
        b.firstSource = static_cast<uint32_t>(params.sourceObjects.size());
        b.sourceCount = static_cast<uint32_t>(n.sources.size());
        params.sourceObjects.insert(params.sourceObjects.end(), n.sources.begin(), n.sources.end());
        b.firstVertex = static_cast<uint32_t>(params.positions.size() / 3);
        b.vertexCount = static_cast<uint32_t>(n.positions.size() / 3);
        params.positions.insert(params.positions.end(), n.positions.begin(), n.positions.end());
        b.firstIndex = static_cast<uint32_t>(params.indices.size());
        b.indexCount = static_cast<uint32_t>(n.indices.size());
        params.indices.insert(params.indices.end(), n.indices.begin(), n.indices.end());
        b.level = n.leaf ? runtime::kLeafLevel : static_cast<uint32_t>(n.firstLevel);
        b.delta = static_cast<float>(n.delta);
        // Float-representable by construction (hierarchy_nodes.h): the casts are exact.
        b.geometricError = static_cast<float>(n.geometricError);
        for (int k = 0; k < 3; ++k) {
            b.boundsMin[k] = static_cast<float>(n.boundsMin[k]);
            b.boundsMax[k] = static_cast<float>(n.boundsMax[k]);
            b.sphereCenter[k] = static_cast<float>(n.sphereCenter[k]);
        }
        b.sphereRadius = static_cast<float>(n.sphereRadius);
        params.nodes.push_back(b);
    }
    return true;
}

bool writeRuntimeScene(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       uint64_t hash, const std::string& toolVersion, const std::string& path,
                       std::string& error) {
    runtime::BuildParams params;
    if (!fillBuildParams(nodes, objects, hash, toolVersion, params, error)) {
        error = path + ": " + error;
        return false;
    }
    std::vector<uint8_t> bytes;
    if (!runtime::writeRuntimeFile(params, bytes, error)) {
        error = path + ": " + error;
        return false;
    }
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) {
        error = path + ": cannot open for writing";
        return false;
    }
    const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const bool closed = std::fclose(f) == 0;
    if (!ok || !closed) {
        error = path + ": write failed (disk full?)";
        return false;
    }
    return true;
}

}  // namespace aggrelod::io
