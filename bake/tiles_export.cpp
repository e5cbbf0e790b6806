// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: 3D Tiles export (docs/design.md §4; runtime selection as in section 3).
// See tiles_export.h for the mapping and the axis convention. The GLB contents are written
// by writeTileGlb (gltf_write.cpp); this file writes the JSON (json.h).
#include "tiles_export.h"

#include "json.h"
#include "scene_io.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

namespace aggrelod::io {
namespace {

/// Axis-aligned box in glTF (y-up) world coordinates.
struct Box {
    double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};

/// The 3D Tiles "box" (12 numbers: centre, x half axis, y half axis, z half axis) of `b`
/// grown by `pad` on every side, taken from glTF y-up to 3D Tiles z-up: (x, y, z) -> (x, -z, y).
Json tilesBox(const Box& b, double pad) {
    double c[3], h[3];
    for (int k = 0; k < 3; ++k) {
        c[k] = 0.5 * (b.lo[k] + b.hi[k]);
        h[k] = 0.5 * (b.hi[k] - b.lo[k]) + pad;
    }
    const double values[12] = {c[0], -c[2], c[1],  //
                               h[0], 0,     0,     // glTF x stays x
                               0,    h[2],  0,     // glTF z becomes -y (a half axis: sign irrelevant)
                               0,    0,     h[1]};  // glTF y becomes z
    Json box = Json::array();
    for (double v : values) box.push_back(jsonNumber(v));
    return box;
}

class TilesetWriter {
public:
    TilesetWriter(const HierarchyNodes& nodes, const std::vector<InputObject>& objects)
        : nodes_(nodes), objects_(objects) {}

    bool run(std::string& json, TilesetSummary& summary, std::string& error) {
        if (nodes_.objectCount != objects_.size() || nodes_.nodes.size() < objects_.size()) {
            error = "the hierarchy nodes do not belong to these objects";
            return false;
        }
        for (size_t i = 0; i < nodes_.nodes.size(); ++i) {
            for (uint32_t c : nodes_.nodes[i].children) {
                if (c >= i) {  // children come before their parent: also rules out cycles
                    error = "hierarchy node " + std::to_string(i) + " has child " + std::to_string(c) +
                            " that does not come before it";
                    return false;
                }
            }
        }
        std::vector<uint32_t> roots;
        for (uint32_t r : nodes_.roots) {
            if (r >= nodes_.nodes.size()) {
                error = "hierarchy root " + std::to_string(r) + " does not exist";
                return false;
            }
            if (hasGeometry(r)) roots.push_back(r);  // objects left out of the bake get no tile
        }
        if (roots.empty()) {
            error = "the hierarchy has nothing to draw";
            return false;
        }
        Box scene = box(roots[0]);
        for (uint32_t r : roots) scene = unite(scene, box(r));
        double diagonal = 0;
        for (int k = 0; k < 3; ++k) diagonal += (scene.hi[k] - scene.lo[k]) * (scene.hi[k] - scene.lo[k]);
        diagonal = std::sqrt(diagonal);
        pad_ = diagonal > 0 ? 1e-6 * diagonal : 1e-6;
        double rootError = 0;
        for (uint32_t r : roots) rootError = std::max(rootError, nodes_.nodes[r].geometricError);
        // Without any tile drawn, the error is about the whole scene: its diagonal.
        summary.geometricError = std::max(diagonal, rootError);

        Json tileset;
        tileset["asset"] = {{"version", "1.1"}, {"generator", "aggrelod"}};
        tileset["geometricError"] = jsonNumber(summary.geometricError);
        if (roots.size() == 1) {
            tileset["root"] = tile(roots[0]);
        } else {
            // Several roots: a root without content standing for "nothing drawn".
            ++tileCount_;
            Json root;
            root["boundingVolume"] = {{"box", tilesBox(scene, pad_)}};
            root["geometricError"] = jsonNumber(summary.geometricError);
            root["refine"] = "REPLACE";
            root["children"] = Json::array();
            for (uint32_t r : roots) root["children"].push_back(tile(r));
            tileset["root"] = std::move(root);
        }
        json = jsonText(tileset);
        summary.tileCount = tileCount_;
        summary.contentCount = contentCount_;
        return true;
    }

    /// Nodes that have a tile with content, in the order of tileset.json.
    const std::vector<uint32_t>& contentNodes() const { return contentNodes_; }

private:
    bool hasGeometry(uint32_t n) const {
        const HierarchyNode& node = nodes_.nodes[n];
        return nodeTriangleCount(node) > 0 || !node.children.empty();
    }

    Box box(uint32_t n) const {
        const HierarchyNode& node = nodes_.nodes[n];
        Box b;
        for (int k = 0; k < 3; ++k) {
            b.lo[k] = node.boundsMin[k];
            b.hi[k] = node.boundsMax[k];
        }
        return b;
    }

    static Box unite(const Box& a, const Box& b) {
        Box r;
        for (int k = 0; k < 3; ++k) {
            r.lo[k] = std::min(a.lo[k], b.lo[k]);
            r.hi[k] = std::max(a.hi[k], b.hi[k]);
        }
        return r;
    }

    Json tile(uint32_t n) {
        const HierarchyNode& node = nodes_.nodes[n];
        ++tileCount_;
        Json t;
        t["boundingVolume"] = {{"box", tilesBox(box(n), pad_)}};
        t["geometricError"] = jsonNumber(node.leaf ? 0.0 : node.geometricError);
        t["refine"] = "REPLACE";
        if (nodeTriangleCount(node) > 0) {
            ++contentCount_;
            contentNodes_.push_back(n);
            t["content"] = {{"uri", "node" + std::to_string(n) + ".glb"}};
        }
        Json extras;
        extras["node"] = n;
        if (node.leaf) {
            extras["object"] = objects_[n].name;
            extras["id"] = objects_[n].id;
        } else if (node.objectLod >= 1) {
            // A simplified version of one object: no aggregate level of its own.
            extras["objectLod"] = node.objectLod;
            extras["objects"] = 1;
        } else if (node.coarserStep >= 1) {
            // A coarser version of the aggregate below it: no level of its own either.
            extras["coarserStep"] = node.coarserStep;
            extras["delta"] = jsonNumber(node.delta);
            extras["objects"] = node.sources.size();
        } else if (node.bundleStep >= 1) {
            // The aggregate's children's versions merged into one mesh: no level of its own.
            extras["bundleStep"] = node.bundleStep;
            extras["delta"] = jsonNumber(node.delta);
            extras["objects"] = node.sources.size();
        } else {
            extras["level"] = node.firstLevel;
            extras["lastLevel"] = node.lastLevel;
            extras["delta"] = jsonNumber(node.delta);
            extras["objects"] = node.sources.size();
        }
        t["extras"] = std::move(extras);
        Json children = Json::array();
        for (uint32_t c : node.children)
            if (hasGeometry(c)) children.push_back(tile(c));
        if (!children.empty()) t["children"] = std::move(children);
        return t;
    }

    const HierarchyNodes& nodes_;
    const std::vector<InputObject>& objects_;
    double pad_ = 0;
    size_t tileCount_ = 0, contentCount_ = 0;
    std::vector<uint32_t> contentNodes_;
};

}  // namespace

bool makeTilesetJson(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, std::string& json,
                     TilesetSummary& summary, std::string& error) {
    TilesetWriter writer(nodes, objects);
    return writer.run(json, summary, error);
}

bool writeTileset(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, const std::string& dir,
                  TilesetSummary& summary, std::string& error) {
    namespace fs = std::filesystem;
    TilesetWriter writer(nodes, objects);
    std::string json;
    if (!writer.run(json, summary, error)) {
        error = (fs::path(dir) / "tileset.json").string() + ": " + error;
        return false;
    }
    int levelCount = 0;
    for (const HierarchyNode& n : nodes.nodes) levelCount = std::max({levelCount, n.lastLevel + 1, n.bundleLevel + 1});
    for (uint32_t n : writer.contentNodes()) {
        const HierarchyNode& node = nodes.nodes[n];
        TileMesh tile;
        const bool objectLod = node.objectLod >= 1;
        // A coarser version takes the level (and tint) of the aggregate it simplifies, a bundle that
        // of the aggregate it was made for.
        const int level = std::max(node.bundleStep >= 1 ? node.bundleLevel : nodes.nodes[aggregateBelow(nodes, n)].firstLevel, 0);
        tile.name = node.leaf                ? "object_" + objects[n].name
                    : objectLod             ? "node" + std::to_string(n) + "_object_lod" + std::to_string(node.objectLod)
                    : node.coarserStep >= 1 ? "node" + std::to_string(n) + "_coarser" + std::to_string(node.coarserStep)
                    : node.bundleStep >= 1  ? "node" + std::to_string(n) + "_bundle" + std::to_string(node.bundleStep)
                                            : "node" + std::to_string(n) + "_level" + std::to_string(node.firstLevel);
        {
            NodeMesh mesh;  // wherever it is (in the node, its object, the spill file)
            if (!readNodeMesh(nodes, objects, n, mesh, error)) {
                error = (fs::path(dir) / ("node" + std::to_string(n) + ".glb")).string() + ": " + error;
                return false;
            }
            tile.positions = std::move(mesh.positions);
            tile.indices = std::move(mesh.indices);
        }
        if (!node.leaf) {
            // Per-object LODs are finer than level 0: they take its tint.
            const std::vector<double> colour =
                levelBaseColour(objectLod ? 0 : size_t(level), size_t(std::max(levelCount, 1)));
            std::copy(colour.begin(), colour.begin() + 4, tile.baseColor);
        }
        tile.node = n;
        tile.geometricError = node.leaf ? 0.0 : node.geometricError;
        for (uint32_t s : node.sources) {
            if (s >= objects.size()) {
                error = (fs::path(dir) / "tileset.json").string() + ": hierarchy node " + std::to_string(n) +
                        " refers to object " + std::to_string(s) + " of " + std::to_string(objects.size());
                return false;
            }
            tile.sourceIds.push_back(objects[s].id);
        }
        const std::string path = (fs::path(dir) / ("node" + std::to_string(n) + ".glb")).string();
        if (!writeTileGlb(tile, path, error)) return false;
    }
    const fs::path jsonPath = fs::path(dir) / "tileset.json";
    std::ofstream out(jsonPath, std::ios::binary | std::ios::trunc);
    if (!out) {
        error = jsonPath.string() + ": cannot create";
        return false;
    }
    out.write(json.data(), std::streamsize(json.size()));
    out.close();
    if (!out) {
        error = jsonPath.string() + ": write error (disk full?)";
        return false;
    }
    return true;
}

}  // namespace aggrelod::io
