// SPDX-License-Identifier: AGPL-3.0-or-later
// Hierarchy nodes -> the runtime's flat contract (hierarchy_export.h, docs/design.md §4).
// Normals: angle-weighted face normals (Thuermer & Wuethrich, "Computing vertex normals from
// polygonal facets", JGT 3(1), 1998), split at creases.
#include <aggrelod/hierarchy_export.h>

#include <aggrelod/disjoint_sets.h>

#include "parallel_for.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <new>
#include <numeric>

namespace aggrelod {

namespace {

using Vec3 = std::array<double, 3>;
Vec3 sub(const float* a, const float* b) { return {double(a[0]) - b[0], double(a[1]) - b[1], double(a[2]) - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double length(const Vec3& a) { return std::sqrt(dot(a, a)); }

// Node `at`'s mesh into `storage` when it is out of memory; true (storage untouched) when in
// the node. False with `error` when it cannot be read back.
bool readIfSpilled(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, uint32_t at, NodeMesh& storage,
                   std::string& error) {
    return nodes.nodes[at].meshPlace.kind == NodeMeshPlace::Kind::InNode || readNodeMesh(nodes, objects, at, storage, error);
}

}  // namespace

bool buildRenderMesh(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                     const std::vector<float>& faceColors, RenderMesh& out) {
    out = RenderMesh{};
    const size_t vertexCount = positions.size() / 3, cornerCount = indices.size(), faceCount = cornerCount / 3;
    if (cornerCount % 3 != 0) return false;
    for (uint32_t v : indices)
        if (v >= vertexCount) return false;

    // Per face: unit normal (zero when degenerate) and encoded colour.
    std::vector<Vec3> faceNormal(faceCount);
    std::vector<std::array<uint8_t, 4>> faceColour(faceCount, {255, 255, 255, 255});
    const bool coloured = faceColors.size() == 4 * faceCount;
    for (size_t f = 0; f < faceCount; ++f) {
        const float* a = &positions[3 * size_t(indices[3 * f])];
        const float* b = &positions[3 * size_t(indices[3 * f + 1])];
        const float* c = &positions[3 * size_t(indices[3 * f + 2])];
        const Vec3 n = cross(sub(b, a), sub(c, a));
        const double l = length(n);
        faceNormal[f] = l > 0 && std::isfinite(l) ? Vec3{n[0] / l, n[1] / l, n[2] / l} : Vec3{0, 0, 0};
        if (coloured) runtime::encodeColorSrgb8(&faceColors[4 * f], faceColour[f].data());
    }

    // Corners of one vertex are joined across smooth edges shared by exactly two faces.
    // Edges sorted by (low vertex, high vertex, face): deterministic, no hashing. A counting
    // sort by the low vertex (corners in order), then each vertex's few edges by the high one.
    struct EdgeUse {
        uint32_t lo, hi, corner;  // corner = 3 * face + slot of the edge's start
    };
    std::vector<uint32_t> start(vertexCount + 1, 0);
    auto edgeOf = [&](uint32_t c) {
        const uint32_t a = indices[c], b = indices[c - c % 3 + (c + 1) % 3];
        return EdgeUse{std::min(a, b), std::max(a, b), c};
    };
    for (uint32_t c = 0; c < cornerCount; ++c) ++start[edgeOf(c).lo + 1];
    for (size_t v = 0; v < vertexCount; ++v) start[v + 1] += start[v];
    std::vector<EdgeUse> edges(cornerCount);
    {
        std::vector<uint32_t> next(start.begin(), start.end() - 1);
        for (uint32_t c = 0; c < cornerCount; ++c) {
            const EdgeUse e = edgeOf(c);
            edges[next[e.lo]++] = e;
        }
    }
    for (size_t v = 0; v < vertexCount; ++v) {  // stable: equal high vertices keep corner order
        if (start[v + 1] - start[v] > 32) {  // a fan's hub
            std::stable_sort(edges.begin() + start[v], edges.begin() + start[v + 1],
                             [](const EdgeUse& x, const EdgeUse& y) { return x.hi < y.hi; });
            continue;
        }
        for (uint32_t i = start[v] + 1; i < start[v + 1]; ++i)
            for (uint32_t j = i; j > start[v] && edges[j - 1].hi > edges[j].hi; --j) std::swap(edges[j - 1], edges[j]);
    }
    const double cosCrease = std::cos(kCreaseAngleDegrees * 3.14159265358979323846 / 180.0);
    DisjointSets group(cornerCount);  // the smallest corner of a group is its root
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
        if (j - i == 2) {
            const uint32_t c1 = edges[i].corner, c2 = edges[i + 1].corner;
            const uint32_t f1 = c1 / 3, f2 = c2 / 3;
            if (f1 != f2 && faceColour[f1] == faceColour[f2] && dot(faceNormal[f1], faceNormal[f2]) >= cosCrease) {
                // Both corners at each end of the edge: start and end of the edge in each face.
                const uint32_t e1 = c1 - c1 % 3 + (c1 + 1) % 3, e2 = c2 - c2 % 3 + (c2 + 1) % 3;
                const uint32_t a1 = indices[c1];
                group.unite(c1, indices[c2] == a1 ? c2 : e2);
                group.unite(e1, indices[c2] == a1 ? e2 : c2);
            }
        }
        i = j;
    }

    // Angle-weighted normal sums per group (accumulated at the group's root corner), and per
    // input vertex for groups made only of degenerate faces.
    std::vector<Vec3> sum(cornerCount, Vec3{0, 0, 0}), vertexSum(vertexCount, Vec3{0, 0, 0});
    for (uint32_t c = 0; c < cornerCount; ++c) {
        const uint32_t f = c / 3;
        const float* p = &positions[3 * size_t(indices[c])];
        const Vec3 u = sub(&positions[3 * size_t(indices[3 * f + (c + 1) % 3])], p);
        const Vec3 w = sub(&positions[3 * size_t(indices[3 * f + (c + 2) % 3])], p);
        const double lu = length(u), lw = length(w);
        if (!(lu > 0 && lw > 0) || faceNormal[f] == Vec3{0, 0, 0}) continue;
        const double angle = std::acos(std::clamp(dot(u, w) / (lu * lw), -1.0, 1.0));
        Vec3& s = sum[group.find(c)];
        Vec3& vs = vertexSum[indices[c]];
        for (int k = 0; k < 3; ++k) {
            s[k] += angle * faceNormal[f][k];
            vs[k] += angle * faceNormal[f][k];
        }
    }

    std::vector<uint32_t> outputOf(cornerCount, runtime::kNoIndex);
    out.indices.resize(cornerCount);
    for (uint32_t c = 0; c < cornerCount; ++c) {
        const uint32_t root = group.find(c);
        if (outputOf[root] == runtime::kNoIndex) {
            outputOf[root] = uint32_t(out.positions.size() / 3);
            const float* p = &positions[3 * size_t(indices[c])];
            out.positions.insert(out.positions.end(), p, p + 3);
            Vec3 n = sum[root];
            if (!(length(n) > 1e-12)) n = vertexSum[indices[c]];
            const double l = length(n);
            if (!(l > 1e-12) || !std::isfinite(l)) n = {0, 0, 1};
            else n = {n[0] / l, n[1] / l, n[2] / l};
            for (int k = 0; k < 3; ++k) out.normals.push_back(float(n[k]));
            const std::array<uint8_t, 4>& colour = faceColour[c / 3];
            out.colors.insert(out.colors.end(), colour.begin(), colour.end());
        }
        out.indices[c] = outputOf[root];
    }
    return true;
}

bool exportHierarchyNodes(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, int threadCount,
                          const NodeExportSink& emit, std::string& error) {
    size_t totalChildren = 0, totalSources = 0, totalIndices = 0;
    for (const HierarchyNode& n : nodes.nodes) {
        totalChildren += n.children.size();
        totalSources += n.sources.size();
        totalIndices += 3 * nodeTriangleCount(n);
    }
    // A render mesh has at most one vertex per triangle corner (buildRenderMesh splits, never adds).
    const size_t limit = std::numeric_limits<uint32_t>::max() - 1;
    if (nodes.nodes.size() > limit || totalChildren > limit || totalSources > limit || totalIndices > limit) {
        error = "the hierarchy is too large for the runtime file (more than 2^32 nodes, vertices or indices)";
        return false;
    }
    // The render meshes are made a batch at a time: only one batch of them is held. A batch
    // ends at 1024 nodes or 2^20 triangles, so that a run of large meshes (bundles) is not held
    // a thousand at a time.
    std::vector<RenderMesh> meshes;
    const size_t batchNodes = 1024, batchTriangles = size_t(1) << 20;
    size_t batchStart = 0, batchEnd = 0;
    for (size_t i = 0; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& n = nodes.nodes[i];
        if (i == batchEnd) {
            batchStart = i;
            size_t triangles = nodeTriangleCount(nodes.nodes[batchEnd++]);
            while (batchEnd < nodes.nodes.size() && batchEnd - batchStart < batchNodes &&
                   triangles + nodeTriangleCount(nodes.nodes[batchEnd]) <= batchTriangles)
                triangles += nodeTriangleCount(nodes.nodes[batchEnd++]);
            const size_t count = batchEnd - batchStart;
            meshes.assign(count, RenderMesh{});
            std::vector<std::string> failed(count);
            detail::parallelFor(count, threadCount, [&](size_t k) {
                const uint32_t at = static_cast<uint32_t>(i + k);
                NodeMesh storage;  // a mesh spilled out of memory (spillNodeMeshes) comes back here
                if (!readIfSpilled(nodes, objects, at, storage, failed[k])) return;
                const HierarchyNode& m = nodes.nodes[at];
                const bool inNode = m.meshPlace.kind == NodeMeshPlace::Kind::InNode;
                if (!buildRenderMesh(inNode ? m.positions : storage.positions, inNode ? m.indices : storage.indices,
                                     inNode ? m.faceColors : storage.faceColors, meshes[k]))
                    failed[k] = "node " + std::to_string(at) + ": a triangle index is out of range";
            });
            for (size_t k = 0; k < count; ++k)
                if (!failed[k].empty()) {
                    error = failed[k];
                    return false;
                }
        }
        RenderMesh& mesh = meshes[i - batchStart];
        runtime::NodeRecord b;
        b.parent = n.parent == kNoNode ? runtime::kNoIndex : n.parent;
        b.level = n.leaf ? runtime::kLeafLevel
                  : n.objectLod >= 1 ? runtime::kObjectLodLevel
                  : n.coarserStep >= 1 ? runtime::kCoarserLevel
                  : n.bundleStep >= 1  ? runtime::kBundleLevelFlag | static_cast<uint32_t>(n.bundleLevel)
                                       : static_cast<uint32_t>(n.firstLevel);
        b.delta = static_cast<float>(n.delta);
        // Float-representable by construction (hierarchy_nodes.h): the casts are exact.
        b.geometricError = static_cast<float>(n.geometricError);
        for (int k = 0; k < 3; ++k) {
            b.boundsMin[k] = static_cast<float>(n.boundsMin[k]);
            b.boundsMax[k] = static_cast<float>(n.boundsMax[k]);
            b.sphereCenter[k] = static_cast<float>(n.sphereCenter[k]);
        }
        b.sphereRadius = static_cast<float>(n.sphereRadius);
        if (!emit(i, b, mesh, error)) return false;
        mesh = RenderMesh{};  // keep the peak memory near one batch of meshes
    }
    return true;
}

bool exportHierarchy(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     uint64_t hash, const std::string& toolVersion, runtime::BuildArrays& params,
                     std::string& error, int threadCount) {
    params = runtime::BuildArrays{};
    params.settingsHash = hash;
    params.toolVersion = toolVersion;
    for (const InputObject& o : objects) params.objectNames.push_back(o.name);
    size_t totalChildren = 0, totalSources = 0, totalIndices = 0;
    for (const HierarchyNode& n : nodes.nodes) {
        totalChildren += n.children.size();
        totalSources += n.sources.size();
        totalIndices += 3 * nodeTriangleCount(n);
    }
    if (std::max({nodes.nodes.size(), totalChildren, totalSources, totalIndices}) < std::numeric_limits<uint32_t>::max()) {
        params.nodes.reserve(nodes.nodes.size());
        params.childIndices.reserve(totalChildren);
        params.sourceObjects.reserve(totalSources);
        params.indices.reserve(totalIndices);
        // The vertex arrays are reserved for that most (address space: only what is filled
        // takes memory), so they never grow by copying.
        try {
            params.positions.reserve(3 * totalIndices);
            params.normals.reserve(3 * totalIndices);
            params.colors.reserve(4 * totalIndices);
        } catch (const std::bad_alloc&) {  // no such address space: the arrays grow as they fill
            params.positions.shrink_to_fit();
            params.normals.shrink_to_fit();
            params.colors.shrink_to_fit();
        }
    }
    return exportHierarchyNodes(nodes, objects, threadCount, [&](size_t i, runtime::NodeRecord b, const RenderMesh& mesh,
                                                        std::string&) {
        const HierarchyNode& n = nodes.nodes[i];
        b.firstChild = static_cast<uint32_t>(params.childIndices.size());
        b.childCount = static_cast<uint32_t>(n.children.size());
        params.childIndices.insert(params.childIndices.end(), n.children.begin(), n.children.end());
        b.firstSource = static_cast<uint32_t>(params.sourceObjects.size());
        b.sourceCount = static_cast<uint32_t>(n.sources.size());
        params.sourceObjects.insert(params.sourceObjects.end(), n.sources.begin(), n.sources.end());
        b.firstVertex = static_cast<uint32_t>(params.positions.size() / 3);
        b.vertexCount = static_cast<uint32_t>(mesh.positions.size() / 3);
        params.positions.insert(params.positions.end(), mesh.positions.begin(), mesh.positions.end());
        params.normals.insert(params.normals.end(), mesh.normals.begin(), mesh.normals.end());
        params.colors.insert(params.colors.end(), mesh.colors.begin(), mesh.colors.end());
        b.firstIndex = static_cast<uint32_t>(params.indices.size());
        b.indexCount = static_cast<uint32_t>(mesh.indices.size());
        params.indices.insert(params.indices.end(), mesh.indices.begin(), mesh.indices.end());
        params.nodes.push_back(b);
        return true;
    }, error);
}

}  // namespace aggrelod
