// SPDX-License-Identifier: MIT
// Synthetic hierarchies for the runtime tests and benchmarks: N disjoint boxes on a jittered
// grid (a "city"), grouped by recursive median splits into a tree of the given branching.
// Inner nodes carry their bounding box as proxy mesh (it contains every child, so rays hit it
// no later than the originals), an error of half their box diagonal (monotone because boxes
// nest) and a bounding sphere enclosing the children's spheres. Nodes are stored children
// first (post-order), to exercise readers that must not assume parents come first.
#pragma once

#include <aggrelod/runtime_build.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace aggrelod::testing {

struct SyntheticBox {
    float lo[3], hi[3];
};

/// Appends a closed, outward 12-triangle box mesh to `p` (4 vertices per face, so each face
/// has its own normal, as the bake splits at creases), sets node's vertex/index ranges. The
/// faces get colour `rgba` (the file's encoded bytes), the top face a lighter one.
inline void appendBoxMesh(runtime::BuildArrays& p, runtime::NodeRecord& node, const float lo[3],
                          const float hi[3], const uint8_t rgba[4] = nullptr) {
    static const uint8_t kWhite[4] = {255, 255, 255, 255};
    if (!rgba) rgba = kWhite;
    node.firstVertex = static_cast<uint32_t>(p.positions.size() / 3);
    node.vertexCount = 24;
    node.firstIndex = static_cast<uint32_t>(p.indices.size());
    node.indexCount = 36;
    // Corner v of the box: bit 0 = x high, bit 1 = y high, bit 2 = z high. Each face lists its
    // corners counter-clockwise seen from outside.
    static const int kFaceCorners[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    static const float kFaceNormal[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
    for (int f = 0; f < 6; ++f) {
        const uint32_t base = static_cast<uint32_t>(p.positions.size() / 3) - node.firstVertex;
        for (int i = 0; i < 4; ++i) {
            const int v = kFaceCorners[f][i];
            p.positions.push_back((v & 1) ? hi[0] : lo[0]);
            p.positions.push_back((v & 2) ? hi[1] : lo[1]);
            p.positions.push_back((v & 4) ? hi[2] : lo[2]);
            p.normals.insert(p.normals.end(), kFaceNormal[f], kFaceNormal[f] + 3);
            for (int k = 0; k < 4; ++k)
                p.colors.push_back(f == 3 && k < 3 ? static_cast<uint8_t>(rgba[k] / 2 + 128) : rgba[k]);
        }
        const uint32_t quad[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
        p.indices.insert(p.indices.end(), quad, quad + 6);
    }
}

inline std::vector<SyntheticBox> makeCityBoxes(uint32_t count, uint32_t seed, float cell = 10.0f) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> size(1.0f, 0.35f * cell), jitter(0.0f, 1.0f),
        height(1.0f, 3.0f * cell);
    const uint32_t side = static_cast<uint32_t>(std::ceil(std::sqrt(double(count))));
    std::vector<SyntheticBox> boxes(count);
    for (uint32_t i = 0; i < count; ++i) {
        const float cx = (float(i % side) + 0.5f) * cell, cz = (float(i / side) + 0.5f) * cell;
        const float hx = size(rng), hz = size(rng), h = height(rng);
        const float ox = (jitter(rng) - 0.5f) * (cell - 2 * hx - 0.2f);
        const float oz = (jitter(rng) - 0.5f) * (cell - 2 * hz - 0.2f);
        boxes[i] = {{cx + ox - hx, 0.0f, cz + oz - hz}, {cx + ox + hx, h, cz + oz + hz}};
    }
    return boxes;
}

namespace detail {
struct HierarchyBuilder {
    runtime::BuildArrays& p;
    const std::vector<SyntheticBox>& boxes;
    uint32_t branching;
    float errorScale;
    uint32_t objectLodChain;

    // Builds the subtree over objects ids[first, last); returns its node index and height.
    std::pair<uint32_t, uint32_t> build(std::vector<uint32_t>& ids, size_t first, size_t last) {
        runtime::NodeRecord node;
        if (last - first == 1) {
            const uint32_t o = ids[first];
            const SyntheticBox& b = boxes[o];
            node.level = runtime::kLeafLevel;
            node.firstSource = static_cast<uint32_t>(p.sourceObjects.size());
            node.sourceCount = 1;
            p.sourceObjects.push_back(o);
            for (int k = 0; k < 3; ++k) {
                node.boundsMin[k] = b.lo[k];
                node.boundsMax[k] = b.hi[k];
            }
            finishSphereOfBox(node);
            const uint8_t colour[4] = {static_cast<uint8_t>(37 * o), static_cast<uint8_t>(91 * o + 40),
                                       static_cast<uint8_t>(13 * o + 200), 255};
            appendBoxMesh(p, node, b.lo, b.hi, colour);
            p.nodes.push_back(node);
            uint32_t below = static_cast<uint32_t>(p.nodes.size() - 1);
            // Per-object LOD chain: simplified versions of this one object (the same box here),
            // each a little coarser and with a slightly larger sphere than the node below.
            for (uint32_t j = 1; j <= objectLodChain; ++j) {
                runtime::NodeRecord lod = p.nodes[below];
                lod.level = runtime::kObjectLodLevel;
                lod.firstChild = static_cast<uint32_t>(p.childIndices.size());
                lod.childCount = 1;
                p.childIndices.push_back(below);
                lod.firstSource = static_cast<uint32_t>(p.sourceObjects.size());
                p.sourceObjects.push_back(o);
                lod.sphereRadius = float(double(lod.sphereRadius) * (1.0 + 1e-6) + 1e-4);
                lod.geometricError = errorScale * 0.02f * float(j) * (b.hi[1] - b.lo[1]);
                appendBoxMesh(p, lod, b.lo, b.hi, colour);
                const uint32_t self = static_cast<uint32_t>(p.nodes.size());
                p.nodes[below].parent = self;
                p.nodes.push_back(lod);
                below = self;
            }
            return {below, 0};
        }
        // Split along the longest axis of the centres, median first, full tie-break on id.
        float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
        for (size_t i = first; i < last; ++i)
            for (int k = 0; k < 3; ++k) {
                const float c = 0.5f * (boxes[ids[i]].lo[k] + boxes[ids[i]].hi[k]);
                lo[k] = std::min(lo[k], c);
                hi[k] = std::max(hi[k], c);
            }
        int axis = 0;
        for (int k = 1; k < 3; ++k)
            if (hi[k] - lo[k] > hi[axis] - lo[axis]) axis = k;
        std::sort(ids.begin() + first, ids.begin() + last, [&](uint32_t a, uint32_t b) {
            const float ca = boxes[a].lo[axis] + boxes[a].hi[axis];
            const float cb = boxes[b].lo[axis] + boxes[b].hi[axis];
            return ca != cb ? ca < cb : a < b;
        });
        const size_t parts = std::min<size_t>(branching, last - first);
        std::vector<uint32_t> kids;
        uint32_t height = 0;
        for (size_t k = 0; k < parts; ++k) {
            const size_t a = first + (last - first) * k / parts, b = first + (last - first) * (k + 1) / parts;
            auto [child, h] = build(ids, a, b);
            kids.push_back(child);
            height = std::max(height, h + 1);
        }
        node.level = height - 1;
        node.delta = float(height);
        node.firstChild = static_cast<uint32_t>(p.childIndices.size());
        node.childCount = static_cast<uint32_t>(kids.size());
        node.firstSource = static_cast<uint32_t>(p.sourceObjects.size());
        for (int k = 0; k < 3; ++k) {
            node.boundsMin[k] = 1e30f;
            node.boundsMax[k] = -1e30f;
        }
        for (uint32_t c : kids) {
            p.childIndices.push_back(c);
            const runtime::NodeRecord& cn = p.nodes[c];
            for (int k = 0; k < 3; ++k) {
                node.boundsMin[k] = std::min(node.boundsMin[k], cn.boundsMin[k]);
                node.boundsMax[k] = std::max(node.boundsMax[k], cn.boundsMax[k]);
            }
            for (uint32_t s = 0; s < cn.sourceCount; ++s)
                p.sourceObjects.push_back(p.sourceObjects[cn.firstSource + s]);
        }
        node.sourceCount = static_cast<uint32_t>(p.sourceObjects.size()) - node.firstSource;
        double radius = 0;
        for (int k = 0; k < 3; ++k) node.sphereCenter[k] = 0.5f * (node.boundsMin[k] + node.boundsMax[k]);
        double diag2 = 0;
        for (int k = 0; k < 3; ++k) diag2 += double(node.boundsMax[k] - node.boundsMin[k]) * (node.boundsMax[k] - node.boundsMin[k]);
        for (uint32_t c : kids) {
            const runtime::NodeRecord& cn = p.nodes[c];
            double d2 = 0;
            for (int k = 0; k < 3; ++k) d2 += double(cn.sphereCenter[k] - node.sphereCenter[k]) * (cn.sphereCenter[k] - node.sphereCenter[k]);
            radius = std::max(radius, std::sqrt(d2) + cn.sphereRadius);
        }
        node.sphereRadius = float(radius * (1.0 + 1e-6) + 1e-4);
        node.geometricError = float(errorScale * 0.5 * std::sqrt(diag2));
        for (uint32_t c : kids) node.geometricError = std::max(node.geometricError, p.nodes[c].geometricError);
        appendBoxMesh(p, node, node.boundsMin, node.boundsMax);
        const uint32_t self = static_cast<uint32_t>(p.nodes.size());
        for (uint32_t c : kids) p.nodes[c].parent = self;
        p.nodes.push_back(node);
        return {self, height};
    }

    static void finishSphereOfBox(runtime::NodeRecord& node) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) {
            node.sphereCenter[k] = 0.5f * (node.boundsMin[k] + node.boundsMax[k]);
            const double h = 0.5 * (double(node.boundsMax[k]) - node.boundsMin[k]);
            d2 += h * h;
        }
        node.sphereRadius = float(std::sqrt(d2) * (1.0 + 1e-6) + 1e-4);
    }
};
}  // namespace detail

/// A hierarchy over `objectCount` city boxes: about objectCount*b/(b-1) nodes. `roots` > 1
/// splits the objects into that many separate trees. An inner node's error is errorScale
/// times half its box diagonal (1 = the box proxy's true one-sided distance bound; smaller
/// values mimic proxies that hug their originals, as the bake's). `objectLodChain` > 0 puts
/// that many per-object LOD nodes (level kObjectLodLevel, one source, errors rising) between
/// every leaf and its aggregate.
inline runtime::BuildArrays makeSyntheticHierarchy(uint32_t objectCount, uint32_t seed,
                                                   uint32_t branching = 4, uint32_t roots = 1,
                                                   float errorScale = 1.0f, uint32_t objectLodChain = 0) {
    runtime::BuildArrays p;
    const std::vector<SyntheticBox> boxes = makeCityBoxes(objectCount, seed);
    for (uint32_t i = 0; i < objectCount; ++i) p.objectNames.push_back("box" + std::to_string(i));
    std::vector<uint32_t> ids(objectCount);
    std::iota(ids.begin(), ids.end(), 0u);
    detail::HierarchyBuilder builder{p, boxes, branching, errorScale, objectLodChain};
    roots = std::max(1u, std::min(roots, objectCount));
    for (uint32_t r = 0; r < roots; ++r)
        builder.build(ids, size_t(objectCount) * r / roots, size_t(objectCount) * (r + 1) / roots);
    p.settingsHash = 0x1234abcdull + seed;
    p.toolVersion = "0.1.0-test";
    return p;
}

}  // namespace aggrelod::testing
