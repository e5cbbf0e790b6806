// SPDX-License-Identifier: AGPL-3.0-or-later
// Hierarchy nodes' meshes out of memory (hierarchy_nodes.h, spillNodeMeshes): a leaf's mesh is
// its object's, every other mesh waits in one spill file that writers read a node at a time.
#include <aggrelod/hierarchy_nodes.h>

#include "node_mesh_spiller.h"
#include "surface_colors.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <stdexcept>

namespace aggrelod {

/// The spill file: written once by spillNodeMeshes, then read back under a lock (one
/// std::FILE, portable; reads come from the page cache and are short beside what the
/// writers do with a mesh).
class NodeMeshFile {
public:
    NodeMeshFile(std::FILE* file, std::string path) : file_(file), path_(std::move(path)) {}
    ~NodeMeshFile() {
        std::fclose(file_);
        std::remove(path_.c_str());
    }
    NodeMeshFile(const NodeMeshFile&) = delete;
    NodeMeshFile& operator=(const NodeMeshFile&) = delete;

    const std::string& path() const { return path_; }

    /// Reads and appends share one stream: NodeMeshSpiller::write holds this lock too.
    std::mutex& lock() const { return mutex_; }

    bool read(uint64_t offset, void* a, size_t aBytes, void* b, size_t bBytes, void* c, size_t cBytes) const {
        std::lock_guard<std::mutex> lock(mutex_);
#if defined(_WIN32)
        if (_fseeki64(file_, static_cast<long long>(offset), SEEK_SET) != 0) return false;
#else
        if (fseeko(file_, static_cast<off_t>(offset), SEEK_SET) != 0) return false;
#endif
        return std::fread(a, 1, aBytes, file_) == aBytes && std::fread(b, 1, bBytes, file_) == bBytes &&
               std::fread(c, 1, cBytes, file_) == cBytes;
    }

private:
    std::FILE* file_;
    std::string path_;
    mutable std::mutex mutex_;
};

size_t nodeTriangleCount(const HierarchyNode& n) {
    return n.meshPlace.kind == NodeMeshPlace::Kind::InNode ? n.indices.size() / 3 : n.meshPlace.triangleCount;
}

namespace detail {

NodeMeshPlace objectMeshPlace(const InputObject& object) {
    NodeMeshPlace place;
    place.kind = NodeMeshPlace::Kind::Object;
    place.vertexCount = uint32_t(object.positions.size() / 3);
    place.triangleCount = uint32_t(object.indices.size() / 3);
    place.hasFaceColors = hasTriangleColors(object);
    return place;
}

bool NodeMeshSpiller::open(const std::string& path, std::string& error) {
    // A new file only ("x"): a spill file still in use by other nodes is never overwritten.
    std::FILE* file = std::fopen(path.c_str(), "w+bx");
    if (!file) {
        error = path + (std::ifstream(path).good() ? ": already exists" : ": cannot open for writing");
        return false;
    }
    file_ = std::make_shared<NodeMeshFile>(file, path);  // closes and removes it with its last user
    raw_ = file;
    offset_ = 0;
    return true;
}

bool NodeMeshSpiller::write(const HierarchyNode& n, uint32_t node, NodeMeshPlace& place, std::string& error) {
    if (n.positions.size() / 3 > UINT32_MAX || n.indices.size() / 3 > UINT32_MAX) {
        error = "node " + std::to_string(node) + ": a mesh too large to spill";
        return false;
    }
    if (!n.faceColors.empty() && n.faceColors.size() != 4 * (n.indices.size() / 3)) {
        error = "node " + std::to_string(node) + ": " + std::to_string(n.faceColors.size()) +
                " face colour values for " + std::to_string(n.indices.size() / 3) + " triangles";
        return false;
    }
    // Several threads may spill at once (the proxies stage spills each item as it is made):
    // the place is taken and written under the file's lock.
    std::lock_guard<std::mutex> lock(file_->lock());
    place = NodeMeshPlace{};
    place.kind = NodeMeshPlace::Kind::File;
    place.offset = offset_;
    place.vertexCount = uint32_t(n.positions.size() / 3);
    place.triangleCount = uint32_t(n.indices.size() / 3);
    place.hasFaceColors = !n.faceColors.empty();
    const size_t bytes[3] = {4 * n.positions.size(), 4 * n.indices.size(), 4 * n.faceColors.size()};
    const void* data[3] = {n.positions.data(), n.indices.data(), n.faceColors.data()};
    // At the end again: meshes may have been read back in between (the same stream).
#ifdef _WIN32
    if (_fseeki64(raw_, static_cast<long long>(offset_), SEEK_SET) != 0) {
#else
    if (fseeko(raw_, static_cast<off_t>(offset_), SEEK_SET) != 0) {
#endif
        error = file_->path() + ": cannot seek to its end";
        return false;
    }
    for (int k = 0; k < 3; ++k)
        if (bytes[k] && std::fwrite(data[k], 1, bytes[k], raw_) != bytes[k]) {
            error = file_->path() + ": write failed (disk full?)";
            return false;
        }
    offset_ += bytes[0] + bytes[1] + bytes[2];
    return true;
}

bool NodeMeshSpiller::spill(HierarchyNode& n, uint32_t node, std::string& error) {
    if (n.meshPlace.kind != NodeMeshPlace::Kind::InNode || n.indices.empty()) return true;
    NodeMeshPlace place;
    if (!write(n, node, place, error)) return false;
    n.meshPlace = place;
    std::vector<float>().swap(n.positions);
    std::vector<uint32_t>().swap(n.indices);
    std::vector<float>().swap(n.faceColors);
    return true;
}

bool NodeMeshSpiller::finish(std::string& error) {
    std::lock_guard<std::mutex> lock(file_->lock());
    if (std::fflush(raw_) != 0) {
        error = file_->path() + ": write failed (disk full?)";
        return false;
    }
    return true;
}

}  // namespace detail

bool spillNodeMeshes(HierarchyNodes& nodes, const std::vector<InputObject>& objects, const std::string& path,
                     std::string& error) {
    const bool anyInNode = std::any_of(nodes.nodes.begin(), nodes.nodes.end(), [](const HierarchyNode& n) {
        return n.meshPlace.kind == NodeMeshPlace::Kind::InNode && !n.indices.empty();
    });
    if (!anyInNode) return true;  // nothing to move (the spill file of the build, if any, stays)
    if (nodes.meshFile) {
        error = "the nodes' meshes are partly in a spill file already";
        return false;
    }
    detail::NodeMeshSpiller spiller;
    if (!spiller.open(path, error)) return false;
    // Places first, the nodes changed only once the whole file is written.
    std::vector<NodeMeshPlace> places(nodes.nodes.size());
    for (size_t i = 0; i < nodes.nodes.size(); ++i) {
        const HierarchyNode& n = nodes.nodes[i];
        NodeMeshPlace& place = places[i];
        place = n.meshPlace;
        if (n.meshPlace.kind != NodeMeshPlace::Kind::InNode || n.indices.empty()) continue;
        const InputObject* object = n.leaf && i < objects.size() ? &objects[i] : nullptr;
        // A leaf holds a copy of its object (hierarchy_nodes.cpp); anything else goes to the file.
        const auto sameCopy = [&] {
            for (size_t k = 0; k < n.positions.size(); ++k)
                if (n.positions[k] != static_cast<float>(object->positions[k])) return false;
            return true;
        };
        const bool coloured = !n.faceColors.empty();
        if (object && n.positions.size() == object->positions.size() && n.indices == object->indices && sameCopy() &&
            (coloured ? detail::hasTriangleColors(*object) && n.faceColors == object->triangleColors
                      : !detail::hasTriangleColors(*object))) {
            place = detail::objectMeshPlace(*object);
            continue;
        }
        if (!spiller.write(n, uint32_t(i), place, error)) return false;
    }
    if (!spiller.finish(error)) return false;
    for (size_t i = 0; i < nodes.nodes.size(); ++i) {
        HierarchyNode& n = nodes.nodes[i];
        if (places[i].kind == NodeMeshPlace::Kind::InNode) continue;
        n.meshPlace = places[i];
        std::vector<float>().swap(n.positions);
        std::vector<uint32_t>().swap(n.indices);
        std::vector<float>().swap(n.faceColors);
    }
    nodes.meshFile = spiller.file();
    return true;
}

namespace {

/// A mesh at `place` in nodes.meshFile (`name` for messages).
bool readFromSpillFile(const HierarchyNodes& nodes, const NodeMeshPlace& place, const std::string& name, NodeMesh& out,
                       std::string& error) {
    if (!nodes.meshFile) {
        error = name + ": its mesh was spilled, but the spill file is gone";
        return false;
    }
    out.positions.resize(3 * size_t(place.vertexCount));
    out.indices.resize(3 * size_t(place.triangleCount));
    out.faceColors.resize(place.hasFaceColors ? 4 * size_t(place.triangleCount) : 0);
    if (!nodes.meshFile->read(place.offset, out.positions.data(), 4 * out.positions.size(), out.indices.data(),
                              4 * out.indices.size(), out.faceColors.data(), 4 * out.faceColors.size())) {
        error = nodes.meshFile->path() + ": " + name + "'s mesh cannot be read back";
        out = NodeMesh{};
        return false;
    }
    for (uint32_t v : out.indices)
        if (v >= place.vertexCount) {
            error = nodes.meshFile->path() + ": " + name + "'s mesh read back is damaged";
            out = NodeMesh{};
            return false;
        }
    return true;
}

}  // namespace

bool readNodeMesh(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, uint32_t node, NodeMesh& out,
                  std::string& error) {
    out = NodeMesh{};
    if (node >= nodes.nodes.size()) {
        error = "node " + std::to_string(node) + " is out of range";
        return false;
    }
    const HierarchyNode& n = nodes.nodes[node];
    const NodeMeshPlace& place = n.meshPlace;
    switch (place.kind) {
        case NodeMeshPlace::Kind::InNode:
            out.positions = n.positions;
            out.indices = n.indices;
            out.faceColors = n.faceColors;
            return true;
        case NodeMeshPlace::Kind::Object: {
            if (node >= objects.size() || objects[node].positions.size() != 3 * size_t(place.vertexCount) ||
                objects[node].indices.size() != 3 * size_t(place.triangleCount)) {
                error = "node " + std::to_string(node) + ": its object is not the one its mesh was spilled from";
                return false;
            }
            const InputObject& o = objects[node];
            out.positions.assign(o.positions.begin(), o.positions.end());
            out.indices = o.indices;
            if (place.hasFaceColors) out.faceColors = o.triangleColors;
            return true;
        }
        case NodeMeshPlace::Kind::File:
            return readFromSpillFile(nodes, place, "node " + std::to_string(node), out, error);
    }
    error = "node " + std::to_string(node) + ": unknown mesh place";
    return false;
}

NodeMeshView viewNodeMesh(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, uint32_t node,
                          NodeMesh& storage) {
    if (node < nodes.nodes.size() && nodes.nodes[node].meshPlace.kind == NodeMeshPlace::Kind::InNode) {
        const HierarchyNode& n = nodes.nodes[node];
        return {n.positions, n.indices, n.faceColors};
    }
    std::string error;
    if (!readNodeMesh(nodes, objects, node, storage, error)) throw std::runtime_error(error);
    return {storage.positions, storage.indices, storage.faceColors};
}

namespace detail {

NodeMeshView viewDetachedNodeMesh(const HierarchyNodes& nodes, const HierarchyNode& n, NodeMesh& storage) {
    if (n.meshPlace.kind == NodeMeshPlace::Kind::InNode) return {n.positions, n.indices, n.faceColors};
    std::string error = "a mesh kept out of the tree refers to an object";
    if (n.meshPlace.kind != NodeMeshPlace::Kind::File ||
        !readFromSpillFile(nodes, n.meshPlace, "a mesh kept out of the tree", storage, error))
        throw std::runtime_error(error);
    return {storage.positions, storage.indices, storage.faceColors};
}

}  // namespace detail

}  // namespace aggrelod
