// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: writing glTF: the sample scenes (writeObjectsGlb), levels.glb, proxies.glb,
// collision.glb and the 3D Tiles contents, all through one GLB builder (tinygltf's model types;
// the JSON and the binary chunk written here).
#include "runtime_export.h"
#include "scene_io.h"

#include <aggrelod/tiled_bake_3d.h>

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <charconv>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <utility>


namespace aggrelod::io {
namespace {

using Severity = Diagnostic::Severity;

// ---------------------------------------------------------------------------
// Writing.

/// A mesh of one triangle primitive as GlbBuilder writes it (accessor indices, -1 for none).
struct MeshRecord {
    std::string name;
    int material = -1;
    int position = -1, normal = -1, color = -1, indices = -1;
};

struct AccessorRecord {
    int bufferView = -1;
    int componentType = 0;
    int type = 0;
    uint64_t count = 0;
    bool bounded = false;  ///< min and max written (VEC3)
    double min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
};

struct ViewRecord {
    uint64_t byteOffset = 0;
    uint64_t byteLength = 0;
    int target = 0;
};

/// JSON text of the glTF properties aggrelod's writers set (see GlbBuilder), in a fixed key
/// order: the same model gives the same bytes.
class JsonWriter {
public:
    std::string text;
    /// Where drain() moves the text so far (null: it all stays in `text`).
    std::FILE* sink = nullptr;
    uint64_t drained = 0;  ///< bytes moved to `sink`
    bool sinkFailed = false;

    /// Moves the text to `sink` once it exceeds a block (always with `all`), so that a large
    /// document never lies in memory whole.
    void drain(bool all = false) {
        if (!sink || (!all && text.size() < (size_t(1) << 20))) return;
        if (std::fwrite(text.data(), 1, text.size(), sink) != text.size()) sinkFailed = true;
        drained += text.size();
        text.clear();
    }
    /// A complete JSON value written before (another JsonWriter's text).
    void raw(const std::string& json) {
        comma();
        text += json;
    }

    void string(const std::string& s) {
        text += '"';
        for (size_t i = 0; i < s.size();) {
            const unsigned char c = static_cast<unsigned char>(s[i]);
            const size_t length = utf8Length(s, i);
            if (length == 0) {  // not UTF-8: U+FFFD
                text += "\xEF\xBF\xBD";
                ++i;
                continue;
            }
            if (c == '"' || c == '\\') {
                text += '\\';
                text += char(c);
            } else if (c == '\n') {
                text += "\\n";
            } else if (c == '\t') {
                text += "\\t";
            } else if (c == '\r') {
                text += "\\r";
            } else if (c < 0x20) {
                char escaped[8];
                std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(c));
                text += escaped;
            } else {
                text.append(s, i, length);
            }
            i += length;
        }
        text += '"';
    }
    void number(double x) {
        if (!std::isfinite(x)) {
            text += "null";
            return;
        }
        char buffer[32];
        const auto end = std::to_chars(buffer, buffer + sizeof buffer, x).ptr;  // shortest round trip
        text.append(buffer, end);
        // A whole number keeps a fraction, so that readers see a real, as written.
        if (std::find_if(buffer, end, [](char c) { return c == '.' || c == 'e'; }) == end) text += ".0";
    }
    void integer(int64_t x) { text += std::to_string(x); }
    /// An object member's key; its value follows.
    void key(const std::string& name) {
        comma();
        string(name);
        text += ':';
        fresh_ = true;
    }
    void open(char c) {
        comma();
        text += c;
        fresh_ = true;
    }
    void close(char c) {
        text += c;
        fresh_ = false;
    }
    void value(const tinygltf::Value& v) {
        switch (v.Type()) {
        case tinygltf::BOOL_TYPE: literal(v.Get<bool>() ? "true" : "false"); break;
        case tinygltf::INT_TYPE: field(int64_t(v.Get<int>())); break;
        case tinygltf::REAL_TYPE: field(v.Get<double>()); break;
        case tinygltf::STRING_TYPE: field(v.Get<std::string>()); break;
        case tinygltf::ARRAY_TYPE:
            open('[');
            for (const tinygltf::Value& e : v.Get<tinygltf::Value::Array>()) value(e);
            close(']');
            break;
        case tinygltf::OBJECT_TYPE:
            open('{');
            for (const auto& [k, e] : v.Get<tinygltf::Value::Object>()) {
                key(k);
                value(e);
            }
            close('}');
            break;
        default: literal("null"); break;  // null; binary values are never set
        }
    }
    void literal(const char* s) {
        comma();
        text += s;
    }
    void field(int64_t x) {
        comma();
        integer(x);
    }
    void field(double x) {
        comma();
        number(x);
    }
    void field(const std::string& s) {
        comma();
        string(s);
    }
    template <typename T>
    void member(const char* name, const T& x) {
        key(name);
        field(x);
    }
    template <typename T>
    void numbers(const char* name, const std::vector<T>& xs) {
        key(name);
        open('[');
        for (T x : xs) {
            if constexpr (std::is_integral_v<T>) field(int64_t(x));
            else field(double(x));
        }
        close(']');
    }
    void strings(const char* name, const std::vector<std::string>& xs) {
        key(name);
        open('[');
        for (const std::string& x : xs) field(x);
        close(']');
    }
    void extensions(const tinygltf::ExtensionMap& map) {
        if (map.empty()) return;
        key("extensions");
        open('{');
        for (const auto& [k, v] : map) {
            key(k);
            value(v);
        }
        close('}');
    }
    void extras(const tinygltf::Value& v) {
        if (v.Type() == tinygltf::NULL_TYPE) return;
        key("extras");
        value(v);
    }

private:
    bool fresh_ = true;  ///< just after '[', '{' or a key: the next item takes no comma
    void comma() {
        if (!fresh_) text += ',';
        fresh_ = false;
    }
    /// Bytes of the UTF-8 sequence starting at s[i], 0 when it is not one.
    static size_t utf8Length(const std::string& s, size_t i) {
        const unsigned char c = static_cast<unsigned char>(s[i]);
        const size_t n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
        if (n == 0 || i + n > s.size()) return 0;
        for (size_t k = 1; k < n; ++k)
            if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return 0;
        return n;
    }
};

const char* accessorTypeName(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: throw std::runtime_error("accessor of unknown type " + std::to_string(type));
    }
}

/// One glTF node's JSON object; `frozenExtras`: its extras as JSON text, or null (or empty)
/// to write node.extras.
void nodeJson(const tinygltf::Node& node, const std::string* frozenExtras, JsonWriter& w) {
    w.open('{');
    if (!node.name.empty()) w.member("name", node.name);
    if (node.mesh >= 0) w.member("mesh", int64_t(node.mesh));
    if (!node.children.empty()) w.numbers("children", node.children);
    if (!node.matrix.empty()) w.numbers("matrix", node.matrix);
    if (!node.translation.empty()) w.numbers("translation", node.translation);
    if (!node.rotation.empty()) w.numbers("rotation", node.rotation);
    if (!node.scale.empty()) w.numbers("scale", node.scale);
    w.extensions(node.extensions);
    if (frozenExtras && !frozenExtras->empty()) {
        w.key("extras");
        w.raw(*frozenExtras);
    } else {
        w.extras(node.extras);
    }
    w.close('}');
}

/// A node of a GlbBuilder: live (tinygltf's, still changing), or frozen as JSON text (its
/// extras only, or the whole node: a fraction of tinygltf's node and value tree, for the
/// hundreds of thousands of nodes of a large hierarchy).
struct NodeSlot {
    std::unique_ptr<tinygltf::Node> live;  ///< null once the whole node is frozen
    std::string frozen;                    ///< the extras' JSON (live node) or the whole node's
};

/// Writes the glTF JSON of `model` (its nodes: `nodes`) with one buffer of `binaryBytes` (none
/// when 0) through `w` (drained as it goes).
void modelJson(const tinygltf::Model& model, const std::vector<NodeSlot>& nodes, const std::vector<MeshRecord>& meshes,
               const std::vector<AccessorRecord>& accessors, const std::vector<ViewRecord>& views,
               uint64_t binaryBytes, JsonWriter& w) {
    w.open('{');
    w.key("asset");
    w.open('{');
    if (!model.asset.generator.empty()) w.member("generator", model.asset.generator);
    w.member("version", model.asset.version);
    w.close('}');
    if (!model.extensionsUsed.empty()) w.strings("extensionsUsed", model.extensionsUsed);
    if (!model.extensionsRequired.empty()) w.strings("extensionsRequired", model.extensionsRequired);
    w.extensions(model.extensions);
    w.extras(model.extras);
    if (model.defaultScene >= 0) w.member("scene", int64_t(model.defaultScene));
    w.key("scenes");
    w.open('[');
    for (const tinygltf::Scene& scene : model.scenes) {
        w.open('{');
        if (!scene.name.empty()) w.member("name", scene.name);
        if (!scene.nodes.empty()) w.numbers("nodes", scene.nodes);
        w.close('}');
    }
    w.close(']');
    if (!nodes.empty()) {
        w.key("nodes");
        w.open('[');
        for (const NodeSlot& slot : nodes) {
            if (slot.live) nodeJson(*slot.live, &slot.frozen, w);
            else w.raw(slot.frozen);
            w.drain();
        }
        w.close(']');
    }
    if (!meshes.empty()) {
        w.key("meshes");
        w.open('[');
        for (const MeshRecord& mesh : meshes) {
            w.open('{');
            if (!mesh.name.empty()) w.member("name", mesh.name);
            w.key("primitives");
            w.open('[');
            w.open('{');
            w.key("attributes");
            w.open('{');
            if (mesh.color >= 0) w.member("COLOR_0", int64_t(mesh.color));
            if (mesh.normal >= 0) w.member("NORMAL", int64_t(mesh.normal));
            if (mesh.position >= 0) w.member("POSITION", int64_t(mesh.position));
            w.close('}');
            if (mesh.indices >= 0) w.member("indices", int64_t(mesh.indices));
            if (mesh.material >= 0) w.member("material", int64_t(mesh.material));
            w.member("mode", int64_t(TINYGLTF_MODE_TRIANGLES));
            w.close('}');
            w.close(']');
            w.close('}');
            w.drain();
        }
        w.close(']');
    }
    if (!model.materials.empty()) {
        w.key("materials");
        w.open('[');
        for (const tinygltf::Material& m : model.materials) {
            w.open('{');
            if (!m.name.empty()) w.member("name", m.name);
            w.key("pbrMetallicRoughness");
            w.open('{');
            // glTF's defaults are left out.
            const auto& pbr = m.pbrMetallicRoughness;
            if (pbr.baseColorFactor != std::vector<double>{1.0, 1.0, 1.0, 1.0})
                w.numbers("baseColorFactor", pbr.baseColorFactor);
            if (pbr.metallicFactor != 1.0) w.member("metallicFactor", pbr.metallicFactor);
            if (pbr.roughnessFactor != 1.0) w.member("roughnessFactor", pbr.roughnessFactor);
            w.close('}');
            if (m.doubleSided) {
                w.key("doubleSided");
                w.literal("true");
            }
            if (!m.alphaMode.empty() && m.alphaMode != "OPAQUE") w.member("alphaMode", m.alphaMode);
            w.extensions(m.extensions);
            w.extras(m.extras);
            w.close('}');
        }
        w.close(']');
    }
    if (!accessors.empty()) {
        w.key("accessors");
        w.open('[');
        for (const AccessorRecord& a : accessors) {
            w.open('{');
            w.member("bufferView", int64_t(a.bufferView));
            w.member("componentType", int64_t(a.componentType));
            w.member("count", int64_t(a.count));
            w.member("type", std::string(accessorTypeName(a.type)));
            if (a.bounded) {
                w.numbers("min", std::vector<double>(a.min, a.min + 3));
                w.numbers("max", std::vector<double>(a.max, a.max + 3));
            }
            w.close('}');
            w.drain();
        }
        w.close(']');
    }
    if (!views.empty()) {
        w.key("bufferViews");
        w.open('[');
        for (const ViewRecord& v : views) {
            w.open('{');
            w.member("buffer", int64_t(0));
            if (v.byteOffset > 0) w.member("byteOffset", int64_t(v.byteOffset));
            w.member("byteLength", int64_t(v.byteLength));
            if (v.target > 0) w.member("target", int64_t(v.target));
            w.close('}');
            w.drain();
        }
        w.close(']');
    }
    if (binaryBytes > 0) {
        w.key("buffers");
        w.open('[');
        w.open('{');
        w.member("byteLength", int64_t(binaryBytes));
        w.close('}');
        w.close(']');
    }
    w.close('}');
    w.drain(true);
}

/// Builds one GLB model; meshes share one buffer, one buffer view per accessor.
class GlbBuilder {
public:
    /// `path`: the file write() will make; the binary chunk is gathered beside it meanwhile.
    explicit GlbBuilder(const std::string& path) : spill_(path + ".binary-part"), jsonSpill_(path + ".json-part") {
        model_.asset.version = "2.0";
        model_.asset.generator = "aggrelod";
    }
    GlbBuilder(const GlbBuilder&) = delete;
    GlbBuilder& operator=(const GlbBuilder&) = delete;

    /// Adds a mesh with one triangle primitive; returns its index, or -1 when there is
    /// nothing to draw. Positions are converted to float32. The primitive always has NORMAL
    /// (per-vertex, angle-weighted, split at creases of more than kCreaseAngleDegrees and at
    /// colour changes: buildRenderMesh, as in scene.aglod) and COLOR_0 (float VEC4, linear:
    /// `faceColors`, 4 per triangle, or white without them). Throws std::runtime_error for an
    /// index out of range.
    /// With `renderAttributes` false (input scenes written by the samples) the vertices stay
    /// as given, apart from the colour split, with COLOR_0 only when coloured and no NORMAL.
    int addMesh(const std::string& name, const std::vector<double>& positionsIn,
                const std::vector<uint32_t>& indicesIn, int material,
                const std::vector<float>* faceColors = nullptr, bool renderAttributes = true) {
        if (positionsIn.empty() || indicesIn.empty()) return -1;
        flushDeferred();
        return appendMesh(prepareMesh(name, positionsIn, indicesIn, material, faceColors, renderAttributes));
    }

    /// addMesh, with the mesh's attributes computed later, many meshes at once on the
    /// builder's threads (setThreads): the same file as addMesh in the same order. Takes the
    /// positions; `indicesIn` and `faceColors` must stay alive until the next addMesh, flush
    /// or write. Returns the index the mesh will have, or -1 when there is nothing to draw.
    int addMeshDeferred(const std::string& name, std::vector<double>&& positionsIn, const std::vector<uint32_t>& indicesIn,
                        int material, const std::vector<float>* faceColors = nullptr) {
        if (positionsIn.empty() || indicesIn.empty()) return -1;
        deferred_.push_back({name, std::move(positionsIn), &indicesIn, material, faceColors, {}, {}});
        const int index = int(meshes_.size() + deferred_.size()) - 1;
        // A bounded batch: the prepared meshes of one batch are all that is held at once.
        if (deferred_.size() >= 64 * threadCount()) flushDeferred();
        return index;
    }
    /// The same, taking the indices and face colours too (a mesh read back for this call).
    int addMeshDeferred(const std::string& name, std::vector<double>&& positionsIn, std::vector<uint32_t>&& indicesIn,
                        int material, std::vector<float>&& faceColors) {
        if (positionsIn.empty() || indicesIn.empty()) return -1;
        deferred_.push_back({name, std::move(positionsIn), nullptr, material, nullptr, std::move(indicesIn),
                             std::move(faceColors)});
        const int index = int(meshes_.size() + deferred_.size()) - 1;
        if (deferred_.size() >= 64 * threadCount()) flushDeferred();
        return index;
    }

    /// Threads for the deferred meshes (0: all cores).
    void setThreads(int threads) { threads_ = threads; }

    /// Computes and appends the deferred meshes, in the order they were added.
    void flushDeferred() {
        if (deferred_.empty()) return;
        std::vector<PreparedMesh> prepared(deferred_.size());
        std::vector<std::exception_ptr> failed(deferred_.size());
        std::atomic<size_t> next{0};
        auto work = [&] {
            for (size_t k = next++; k < deferred_.size(); k = next++) {
                const DeferredMesh& d = deferred_[k];
                try {
                    prepared[k] = prepareMesh(d.name, d.positions, d.indices ? *d.indices : d.ownedIndices, d.material,
                                              d.faceColors ? d.faceColors : &d.ownedFaceColors, true);
                } catch (...) {
                    failed[k] = std::current_exception();
                }
            }
        };
        std::vector<std::thread> pool;
        for (size_t t = 1; t < std::min(threadCount(), deferred_.size()); ++t) pool.emplace_back(work);
        work();
        for (std::thread& t : pool) t.join();
        deferred_.clear();
        for (size_t k = 0; k < prepared.size(); ++k) {
            if (failed[k]) std::rethrow_exception(failed[k]);
            appendMesh(std::move(prepared[k]));
        }
    }

    /// Adds a mesh of float positions without normals or colours (collision geometry): POSITION
    /// and indices only, vertices as given. Returns its index, -1 when empty.
    int addPlainMesh(const std::string& name, const std::vector<float>& positions, const std::vector<uint32_t>& indices) {
        if (positions.empty() || indices.empty()) return -1;
        const size_t vertexCount = positions.size() / 3;
        for (uint32_t i : indices)
            if (i >= vertexCount) throw std::runtime_error(name + ": index out of range");
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
        for (size_t v = 0; v < vertexCount; ++v)
            for (size_t c = 0; c < 3; ++c) {
                const double x = double(positions[3 * v + c]);
                if (v == 0 || x < lo[c]) lo[c] = x;
                if (v == 0 || x > hi[c]) hi[c] = x;
            }
        MeshRecord mesh;
        mesh.name = name;
        mesh.position = addAccessor(positions.data(), positions.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER,
                                    TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, vertexCount, lo, hi);
        mesh.indices = addAccessor(indices.data(), indices.size() * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER,
                                   TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, indices.size());
        meshes_.push_back(std::move(mesh));
        return int(meshes_.size()) - 1;
    }

    size_t meshCount() const { return meshes_.size() + deferred_.size(); }

    int addNode(tinygltf::Node node) {
        nodes_.push_back({std::make_unique<tinygltf::Node>(std::move(node)), {}});
        return int(nodes_.size()) - 1;
    }
    int nodeCount() const { return int(nodes_.size()); }
    /// Node `index`, to change it; not once frozen whole (freezeNode).
    tinygltf::Node& node(int index) {
        NodeSlot& slot = nodes_.at(size_t(index));
        if (!slot.live) throw std::logic_error("glTF node " + std::to_string(index) + " is already written");
        return *slot.live;
    }

    /// Node `index`'s extras will not change any more: kept as their JSON text from now on, a
    /// fraction of tinygltf's value tree (a large hierarchy lists every object of every node).
    void freezeExtras(int index) {
        tinygltf::Value& extras = node(index).extras;
        if (extras.Type() == tinygltf::NULL_TYPE) return;
        JsonWriter w;
        w.value(extras);
        std::string& frozen = nodes_[size_t(index)].frozen;
        frozen = std::move(w.text);
        frozen.shrink_to_fit();
        extras = tinygltf::Value();
    }
    /// Node `index` will not change any more: kept as its JSON text only.
    void freezeNode(int index) {
        NodeSlot& slot = nodes_.at(size_t(index));
        if (!slot.live) return;
        JsonWriter w;
        nodeJson(*slot.live, &slot.frozen, w);
        slot.frozen = std::move(w.text);
        slot.frozen.shrink_to_fit();
        slot.live.reset();
    }
    /// Room for `meshes` meshes of the usual four accessors each (no growth by copying).
    void reserveMeshes(size_t meshes) {
        meshes_.reserve(meshes);
        accessors_.reserve(4 * meshes);
        views_.reserve(4 * meshes);
    }

    tinygltf::Model& model() { return model_; }

    bool write(const std::string& path, const std::vector<int>& sceneRoots, std::string& error) {
        return writeScenes(path, {{std::string(), sceneRoots}}, error);
    }

    /// Writes the model with these scenes (name, root nodes); the first is the default scene.
    bool writeScenes(const std::string& path, const std::vector<std::pair<std::string, std::vector<int>>>& scenes,
                     std::string& error) {
        try {
            flushDeferred();
        } catch (const std::exception& e) {
            error = path + ": " + e.what();
            return false;
        }
        for (const auto& [name, roots] : scenes) {
            tinygltf::Scene scene;
            scene.name = name;
            scene.nodes = roots;
            model_.scenes.push_back(std::move(scene));
        }
        model_.defaultScene = 0;
        // The JSON written here from the model, the binary chunk straight from the views:
        // tinygltf would build a JSON document of the whole model and copy the buffer once
        // more, several times the file in memory for a large hierarchy. The JSON goes to a
        // file beside the output as it is written (it has to come first, with its length).
        JsonWriter json;
        json.sink = jsonSpill_.open();
        try {
            modelJson(model_, nodes_, meshes_, accessors_, views_, binSize_, json);
        } catch (const std::exception& e) {
            error = path + ": cannot write glTF: " + e.what();
            return false;
        }
        const uint64_t jsonSize = json.drained + json.text.size();
        if (json.sink && (json.sinkFailed || std::fflush(json.sink) != 0 || std::fseek(json.sink, 0, SEEK_SET) != 0)) {
            error = path + ": cannot write glTF: temporary file: " + std::strerror(errno);
            return false;
        }
        const auto padded = [](uint64_t n) { return (n + 3) / 4 * 4; };
        const uint64_t total = 12 + 8 + padded(jsonSize) + (binSize_ ? 8 + padded(binSize_) : 0);
        if (total > std::numeric_limits<uint32_t>::max()) {
            error = path + ": " + std::to_string(total) + " bytes: beyond the 4 GiB a GLB file can hold";
            return false;
        }
        if (binSize_ > 0 && spill_.file &&
            (spillFailed_ || std::fflush(spill_.file) != 0 || std::fseek(spill_.file, 0, SEEK_SET) != 0)) {
            error = path + ": cannot write glTF: temporary file: " + std::strerror(errno);
            return false;
        }
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        if (!out) {
            error = path + ": cannot create: " + std::strerror(errno);
            return false;
        }
        const auto word = [&](uint32_t v) {  // little endian, as GLB wants
            const unsigned char b[4] = {uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)};
            out.write(reinterpret_cast<const char*>(b), 4);
        };
        // `bytes` from a temporary file to the output; false when it ends early.
        std::vector<char> block(size_t(1) << 20);
        const auto copy = [&](std::FILE* from, uint64_t bytes) {
            for (uint64_t left = bytes; left > 0;) {
                const size_t n = std::fread(block.data(), 1, size_t(std::min<uint64_t>(left, block.size())), from);
                if (n == 0) {
                    error = path + ": cannot write glTF: temporary file ended early";
                    return false;
                }
                out.write(block.data(), std::streamsize(n));
                left -= n;
            }
            return true;
        };
        out.write("glTF", 4);
        word(2);
        word(uint32_t(total));
        word(uint32_t(padded(jsonSize)));
        word(0x4E4F534Au);  // "JSON"
        if (json.sink && !copy(json.sink, json.drained)) return false;
        json.text.resize(json.text.size() + size_t(padded(jsonSize) - jsonSize), ' ');
        out.write(json.text.data(), std::streamsize(json.text.size()));
        if (binSize_) {
            word(uint32_t(padded(binSize_)));
            word(0x004E4942u);  // "BIN\0"
            if (!spill_.file) out.write(reinterpret_cast<const char*>(inMemory_.data()), std::streamsize(inMemory_.size()));
            if (spill_.file && !copy(spill_.file, binSize_)) return false;
            const char zeros[4] = {0, 0, 0, 0};
            out.write(zeros, std::streamsize(padded(binSize_) - binSize_));
        }
        out.close();
        if (!out) {
            error = path + ": write error (disk full?)";
            return false;
        }
        return true;
    }

private:
    /// A mesh's vertices, normals, colours and bounds, ready to be appended.
    struct PreparedMesh {
        std::string name;
        int material = -1;
        bool renderAttributes = true, coloured = false;
        RenderMesh render;
        std::vector<float> colours;
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    };
    struct DeferredMesh {
        std::string name;
        std::vector<double> positions;
        const std::vector<uint32_t>* indices;  ///< null: ownedIndices
        int material;
        const std::vector<float>* faceColors;  ///< null: ownedFaceColors (empty: white)
        std::vector<uint32_t> ownedIndices;
        std::vector<float> ownedFaceColors;
    };

    size_t threadCount() const {
        return threads_ > 0 ? size_t(threads_) : std::max<size_t>(1, std::thread::hardware_concurrency());
    }

    /// The part of addMesh that depends on the mesh alone (no shared state: any thread).
    static PreparedMesh prepareMesh(const std::string& name, const std::vector<double>& positionsIn,
                                    const std::vector<uint32_t>& indicesIn, int material,
                                    const std::vector<float>* faceColors, bool renderAttributes) {
        PreparedMesh out;
        out.name = name;
        out.material = material;
        out.renderAttributes = renderAttributes;
        const bool coloured = faceColors && faceColors->size() == 4 * (indicesIn.size() / 3) &&
                              indicesIn.size() % 3 == 0;
        out.coloured = coloured;
        // A vertex shared by faces of different colours (exact float values) is split first, one
        // copy per colour, so that every output vertex carries the exact colour of its faces.
        std::vector<float> positions;
        std::vector<uint32_t> indices;
        if (coloured) {
            // New vertex per (vertex, colour) pair, numbered in order of first use.
            std::map<std::pair<uint32_t, std::array<float, 4>>, uint32_t> copies;
            indices.reserve(indicesIn.size());
            for (size_t i = 0; i < indicesIn.size(); ++i) {
                if (indicesIn[i] >= positionsIn.size() / 3) throw std::runtime_error(name + ": index out of range");
                const float* c = &(*faceColors)[4 * (i / 3)];
                const std::array<float, 4> colour = {c[0], c[1], c[2], c[3]};
                const auto key = std::make_pair(indicesIn[i], colour);
                auto it = copies.find(key);
                if (it == copies.end()) {
                    it = copies.emplace(key, uint32_t(positions.size() / 3)).first;
                    for (int k = 0; k < 3; ++k) positions.push_back(float(positionsIn[3 * size_t(indicesIn[i]) + k]));
                }
                indices.push_back(it->second);
            }
        } else {
            positions.reserve(positionsIn.size());
            for (double x : positionsIn) positions.push_back(float(x));
            indices = indicesIn;
        }
        RenderMesh& render = out.render;
        if (renderAttributes) {
            if (!buildRenderMesh(positions, indices, coloured ? *faceColors : std::vector<float>(), render))
                throw std::runtime_error(name + ": a triangle index is out of range");
        } else {
            render.positions = std::move(positions);
            render.indices = std::move(indices);
        }
        const size_t vertexCount = render.positions.size() / 3;
        out.colours.assign(4 * vertexCount, 1.0f);
        if (coloured)
            for (size_t c = 0; c < render.indices.size(); ++c)
                std::copy_n(&(*faceColors)[4 * (c / 3)], 4, &out.colours[4 * size_t(render.indices[c])]);

        // min/max (required for POSITION) over the finite values of each component.
        bool any[3] = {false, false, false};
        for (size_t v = 0; v < vertexCount; ++v) {
            for (size_t c = 0; c < 3; ++c) {
                const float f = render.positions[3 * v + c];
                if (!std::isfinite(f)) continue;
                const double x = double(f);
                if (!any[c] || x < out.lo[c]) out.lo[c] = x;
                if (!any[c] || x > out.hi[c]) out.hi[c] = x;
                any[c] = true;
            }
        }
        return out;
    }

    /// Appends a prepared mesh's accessors and record; returns its index.
    int appendMesh(PreparedMesh&& prepared) {
        const RenderMesh& render = prepared.render;
        const size_t vertexCount = render.positions.size() / 3;
        MeshRecord mesh;
        mesh.name = std::move(prepared.name);
        mesh.material = prepared.material;
        mesh.position = addAccessor(render.positions.data(), render.positions.size() * sizeof(float),
                                    TINYGLTF_TARGET_ARRAY_BUFFER, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                    vertexCount, prepared.lo, prepared.hi);
        if (prepared.renderAttributes)
            mesh.normal = addAccessor(render.normals.data(), render.normals.size() * sizeof(float),
                                      TINYGLTF_TARGET_ARRAY_BUFFER, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                                      vertexCount);
        if (prepared.renderAttributes || prepared.coloured)
            mesh.color = addAccessor(prepared.colours.data(), prepared.colours.size() * sizeof(float),
                                     TINYGLTF_TARGET_ARRAY_BUFFER, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4,
                                     vertexCount);
        mesh.indices = addAccessor(render.indices.data(), render.indices.size() * sizeof(uint32_t),
                                   TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                                   TINYGLTF_TYPE_SCALAR, render.indices.size());
        meshes_.push_back(std::move(mesh));
        return int(meshes_.size()) - 1;
    }

    std::vector<DeferredMesh> deferred_;
    int threads_ = 1;

    int addView(const void* data, size_t bytes, int target) {
        ViewRecord view;
        view.byteOffset = (binSize_ + 3) / 4 * 4;
        view.byteLength = bytes;
        view.target = target;
        // The binary chunk goes to a file beside the output as it grows (written out after the
        // JSON, which has to come first): the builder holds the model's description only.
        // Where that file cannot be made, the chunk stays in memory.
        if (!spill_.file && inMemory_.empty() && binSize_ == 0) spill_.open();
        const auto* b = static_cast<const unsigned char*>(data);
        if (!spill_.file) {
            inMemory_.resize(size_t(view.byteOffset), 0);
            inMemory_.insert(inMemory_.end(), b, b + bytes);
        } else {
            const char zeros[4] = {0, 0, 0, 0};
            if (std::fwrite(zeros, 1, size_t(view.byteOffset - binSize_), spill_.file) != view.byteOffset - binSize_ ||
                std::fwrite(b, 1, bytes, spill_.file) != bytes)
                spillFailed_ = true;
        }
        binSize_ = view.byteOffset + bytes;
        views_.push_back(view);
        return int(views_.size()) - 1;
    }

    /// A buffer view of `bytes` and its accessor; lo/hi: min/max of a VEC3, or null.
    int addAccessor(const void* data, size_t bytes, int target, int componentType, int type, uint64_t count,
                    const double* lo = nullptr, const double* hi = nullptr) {
        AccessorRecord a;
        a.bufferView = addView(data, bytes, target);
        a.componentType = componentType;
        a.type = type;
        a.count = count;
        a.bounded = lo && hi;
        if (a.bounded)
            for (int c = 0; c < 3; ++c) {
                a.min[c] = lo[c];
                a.max[c] = hi[c];
            }
        accessors_.push_back(a);
        return int(accessors_.size()) - 1;
    }

    /// A file beside the output for what has to wait until the output's start is known;
    /// removed with the builder.
    struct TemporaryFile {
        std::string path;
        std::FILE* file = nullptr;
        explicit TemporaryFile(std::string where) : path(std::move(where)) {}
        /// Creates it (read and write); null where it cannot be made.
        std::FILE* open() {
            file = std::fopen(path.c_str(), "w+b");
            return file;
        }
        TemporaryFile(const TemporaryFile&) = delete;
        TemporaryFile& operator=(const TemporaryFile&) = delete;
        ~TemporaryFile() {
            if (!file) return;
            std::fclose(file);
            std::remove(path.c_str());
        }
    };

    // Meshes, accessors and buffer views are only ever made here: kept in records of their own,
    // a fraction of tinygltf's (a large hierarchy has hundreds of thousands of them).
    tinygltf::Model model_;  ///< everything else: materials, extensions
    std::vector<NodeSlot> nodes_;
    std::vector<MeshRecord> meshes_;
    std::vector<AccessorRecord> accessors_;
    std::vector<ViewRecord> views_;
    TemporaryFile spill_;      ///< the binary chunk so far
    TemporaryFile jsonSpill_;  ///< the JSON chunk while it is written
    std::vector<unsigned char> inMemory_;         ///< the same without a temporary file
    bool spillFailed_ = false;
    uint64_t binSize_ = 0;      ///< bytes of the binary chunk before its final padding
};

tinygltf::Value intValue(uint64_t v) {
    if (v <= uint64_t(std::numeric_limits<int>::max())) return tinygltf::Value(int(v));
    return tinygltf::Value(double(v));
}

/// Distinct, deterministic colour per level: from warm (fine levels) to cool (coarse).
std::vector<double> levelColour(size_t level, size_t levelCount) {
    const double t = levelCount > 1 ? double(level) / double(levelCount - 1) : 0.0;
    const double hue = (1.0 - t) * 30.0 + t * 220.0;  // degrees
    const double s = 0.55, v = 0.9;
    const double c = v * s, h = hue / 60.0;
    const double x = c * (1 - std::fabs(std::fmod(h, 2.0) - 1));
    double r = 0, g = 0, b = 0;
    if (h < 1) { r = c; g = x; }
    else if (h < 2) { r = x; g = c; }
    else if (h < 3) { g = c; b = x; }
    else if (h < 4) { g = x; b = c; }
    else if (h < 5) { r = x; b = c; }
    else { r = c; b = x; }
    const double m = v - c;
    return {r + m, g + m, b + m, 1.0};
}

// MSFT_lod switching hints (MSFT_screencoverage): the fraction of the viewport height covered
// by a node's bounding sphere when its screen-space error reaches kCoverageTau pixels, at
// kCoverageViewport pixels and a vertical field of view of kCoverageFovY (the defaults of
// the runtime's examples). Engines scale these with their own LOD bias.
constexpr double kCoverageTau = 1.0;          // pixels
constexpr double kCoverageViewport = 1080.0;  // pixels
constexpr double kCoverageFovY = 60.0;        // degrees

/// Screen coverage (0..1) of a sphere of `radius` seen from the distance d at which a stand-in
/// of geometric error `error` projects to kCoverageTau: d - radius = error * H / (2 tau tan(fov/2))
/// (the runtime's rule, distance to the sphere), coverage = radius / (d tan(fov/2)). 1 for an
/// error of 0 (the stand-in is as good as the finer level).
double screenCoverage(double radius, double error) {
    if (!(error > 0) || !(radius > 0)) return 1.0;
    const double t = std::tan(kCoverageFovY * 3.14159265358979323846 / 360.0);
    const double d = error * kCoverageViewport / (2.0 * kCoverageTau * t) + radius;
    return std::clamp(radius / (d * t), 0.0, 1.0);
}

/// Radius of a sphere containing every root's bounding sphere (centred on their box).
double enclosingRadius(const HierarchyNodes& nodes) {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (uint32_t r : nodes.roots)
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], nodes.nodes[r].sphereCenter[k] - nodes.nodes[r].sphereRadius);
            hi[k] = std::max(hi[k], nodes.nodes[r].sphereCenter[k] + nodes.nodes[r].sphereRadius);
        }
    double radius = 0;
    for (uint32_t r : nodes.roots) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) {
            const double c = 0.5 * (lo[k] + hi[k]) - nodes.nodes[r].sphereCenter[k];
            d2 += c * c;
        }
        radius = std::max(radius, std::sqrt(d2) + nodes.nodes[r].sphereRadius);
    }
    return std::isfinite(radius) ? radius : 0.0;
}

/// Puts MSFT_lod {ids} on `node` (the finest level) and, when `withCoverage`, extras
/// MSFT_screencoverage: one value per level (ids.size() + 1), the coverage below which that
/// level gives way to the next, from screenCoverage(radius, error of the next); the last is 0
/// (never culled). `coarserErrors[k]`: stored error of stand-in ids[k]. Non-increasing.
void setMsftLod(tinygltf::Model& model, tinygltf::Node& node, const std::vector<int>& ids, double radius,
                const std::vector<double>& coarserErrors, bool withCoverage) {
    if (ids.empty()) return;
    tinygltf::Value::Array idValues;
    for (int id : ids) idValues.push_back(tinygltf::Value(id));
    tinygltf::Value::Object lod;
    lod["ids"] = tinygltf::Value(std::move(idValues));
    node.extensions["MSFT_lod"] = tinygltf::Value(std::move(lod));
    if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), "MSFT_lod") == model.extensionsUsed.end())
        model.extensionsUsed.push_back("MSFT_lod");
    if (!withCoverage || coarserErrors.size() != ids.size()) return;
    tinygltf::Value::Array coverage;
    double previous = 1.0;
    for (double e : coarserErrors) {
        previous = std::min(previous, screenCoverage(radius, e));
        coverage.push_back(tinygltf::Value(previous));
    }
    coverage.push_back(tinygltf::Value(0.0));
    tinygltf::Value::Object extras = node.extras.IsObject() ? node.extras.Get<tinygltf::Value::Object>() : tinygltf::Value::Object{};
    extras["MSFT_screencoverage"] = tinygltf::Value(std::move(coverage));
    node.extras = tinygltf::Value(std::move(extras));
}

}  // namespace

bool writeObjectsGlb(const std::vector<InputObject>& objects, const std::string& path,
                     std::string& error) {
    try {
        GlbBuilder glb(path);
        std::vector<int> roots;
        std::map<std::vector<double>, int> materialOfColour;
        for (const InputObject& o : objects) {
            if (o.positions.size() % 3 != 0 || o.indices.size() % 3 != 0) {
                error = path + ": object '" + o.name +
                        "': positions or indices size is not a multiple of 3";
                return false;
            }
            tinygltf::Node node;
            node.name = o.name;
            // Colours: one material when the object has one colour, else COLOR_0.
            const bool coloured = !o.triangleColors.empty() && o.triangleColors.size() == 4 * (o.indices.size() / 3);
            bool uniform = coloured;
            for (size_t i = 4; uniform && i < o.triangleColors.size(); ++i)
                uniform = o.triangleColors[i] == o.triangleColors[i % 4];
            int material = -1;
            if (uniform) {
                const std::vector<double> colour(o.triangleColors.begin(), o.triangleColors.begin() + 4);
                auto it = materialOfColour.find(colour);
                if (it == materialOfColour.end()) {
                    tinygltf::Material m;
                    m.name = "colour" + std::to_string(materialOfColour.size());
                    m.pbrMetallicRoughness.baseColorFactor = colour;
                    m.pbrMetallicRoughness.metallicFactor = 0.0;
                    m.pbrMetallicRoughness.roughnessFactor = 0.8;
                    glb.model().materials.push_back(std::move(m));
                    it = materialOfColour.emplace(colour, int(glb.model().materials.size()) - 1).first;
                }
                material = it->second;
            }
            node.mesh = glb.addMesh(o.name, o.positions, o.indices, material,
                                    coloured && !uniform ? &o.triangleColors : nullptr, false);
            tinygltf::Value::Object extras;
            extras["id"] = intValue(o.id);
            node.extras = tinygltf::Value(std::move(extras));
            roots.push_back(glb.addNode(std::move(node)));
        }
        return glb.write(path, roots, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

bool writeLevelsGlb(const Hierarchy3D& hierarchy, const std::vector<InputObject>& objects,
                    const std::string& path, std::string& error, const HierarchyNodes* nodes, int threadCount,
                    const TileCache* meshCache) {
    if (nodes && (nodes->nodeOfAggregate.size() != hierarchy.levels.size() || nodes->objectCount != objects.size())) {
        error = path + ": the hierarchy nodes do not belong to this hierarchy";
        return false;
    }
    try {
        GlbBuilder glb(path);
        glb.setThreads(threadCount);
        tinygltf::Model& model = glb.model();
        std::vector<int> roots;
        const size_t levelCount = hierarchy.levels.size();
        bool anyColours = false;
        for (const Level& level : hierarchy.levels)
            for (const Aggregate& agg : level.aggregates)
                anyColours = anyColours || !agg.faceColors.empty() || (agg.meshInCache && agg.meshInCache->hasFaceColors);
        // Meshes left in the tile cache, read back a run of aggregates at a time (the meshes
        // added from a run are made before the next run replaces it).
        constexpr size_t kMeshRun = 4096;
        std::vector<Aggregate> meshRun;
        std::vector<uint32_t> meshAt;  // g - run start -> index in meshRun (UINT32_MAX: in memory)
        for (size_t k = 0; k < levelCount; ++k) {
            const Level& level = hierarchy.levels[k];
            const std::string levelName = "level" + std::to_string(k);

            tinygltf::Material material;
            material.name = levelName;
            // With colours the faces carry them (COLOR_0 times a white base colour); without,
            // each level gets a distinct tint.
            material.pbrMetallicRoughness.baseColorFactor =
                anyColours ? std::vector<double>{1, 1, 1, 1} : levelColour(k, levelCount);
            material.pbrMetallicRoughness.metallicFactor = 0.0;
            material.pbrMetallicRoughness.roughnessFactor = 0.8;
            model.materials.push_back(std::move(material));
            const int materialIndex = int(model.materials.size()) - 1;

            tinygltf::Node levelNode;
            levelNode.name = "levels_LOD" + std::to_string(k);
            tinygltf::Value::Object levelExtras;
            levelExtras["level"] = intValue(k);
            levelExtras["lod"] = intValue(k);
            levelExtras["delta"] = tinygltf::Value(level.delta);
            levelNode.extras = tinygltf::Value(std::move(levelExtras));
            const int levelIndex = glb.addNode(std::move(levelNode));
            roots.push_back(levelIndex);

            std::vector<int> children;
            for (size_t g = 0; g < level.aggregates.size(); ++g) {
                if (g % kMeshRun == 0) {
                    glb.flushDeferred();
                    std::vector<const Aggregate*> lean;
                    meshAt.assign(std::min(kMeshRun, level.aggregates.size() - g), UINT32_MAX);
                    for (size_t j = g; j < g + meshAt.size(); ++j) {
                        const Aggregate& a = level.aggregates[j];
                        if (!meshLeftInCache(a)) continue;
                        meshAt[j - g] = static_cast<uint32_t>(lean.size());
                        lean.push_back(&a);
                    }
                    if (!lean.empty()) {
                        std::string why;
                        if (!meshCache || !readAggregateMeshes(*meshCache, lean, meshRun, threadCount, why)) {
                            error = path + ": " + (meshCache ? why : "aggregate meshes left in a tile cache but no cache given");
                            return false;
                        }
                    }
                }
                const uint32_t at = meshAt[g % kMeshRun];
                const Aggregate& agg = at == UINT32_MAX ? level.aggregates[g] : meshRun[at];
                const std::string name = levelName + "_group" + std::to_string(g);
                if (agg.positions.size() % 3 != 0 || agg.indices.size() % 3 != 0) {
                    error = path + ": " + name + ": positions or indices size is not a multiple of 3";
                    return false;
                }
                tinygltf::Value::Array sources, sourceIds;
                for (uint32_t s : agg.sourceObjects) {
                    if (s >= objects.size()) {
                        error = path + ": " + name + " refers to object " + std::to_string(s) +
                                " but there are " + std::to_string(objects.size()) + " objects";
                        return false;
                    }
                    sources.push_back(tinygltf::Value(objects[s].name));
                    sourceIds.push_back(intValue(objects[s].id));
                }
                tinygltf::Node node;
                node.name = name;
                node.mesh = glb.addMeshDeferred(name, std::vector<double>(agg.positions), agg.indices, materialIndex,
                                                &agg.faceColors);
                tinygltf::Value::Object extras;
                extras["level"] = intValue(k);
                extras["group"] = intValue(g);
                extras["delta"] = tinygltf::Value(level.delta);
                extras["sources"] = tinygltf::Value(std::move(sources));
                extras["source_ids"] = tinygltf::Value(std::move(sourceIds));
                extras["components"] = tinygltf::Value(agg.componentCount);
                extras["volume"] = tinygltf::Value(agg.measures.volume);
                extras["volume_original"] = tinygltf::Value(agg.volumeOriginal);
                // Where the faces on the objects come from: their own faces, or the watertight
                // solid that stood in for objects that were not closed solids.
                extras["surface"] = tinygltf::Value(std::string(agg.surface == Aggregate::Surface::Original     ? "original"
                                                                : agg.surface == Aggregate::Surface::Solidified ? "solidified"
                                                                                                                : "mixed"));
                if (nodes) {
                    if (g >= nodes->nodeOfAggregate[k].size()) {
                        error = path + ": " + name + " has no hierarchy node";
                        return false;
                    }
                    const uint32_t nodeIndex = nodes->nodeOfAggregate[k][g];
                    const HierarchyNode& hn = nodes->nodes[nodeIndex];
                    tinygltf::Value::Array children;
                    for (uint32_t c : hn.children) children.push_back(intValue(c));
                    extras["node"] = intValue(nodeIndex);
                    extras["parent"] = hn.parent == kNoNode ? tinygltf::Value(-1) : intValue(hn.parent);
                    extras["children"] = tinygltf::Value(std::move(children));
                    extras["first_level"] = tinygltf::Value(hn.firstLevel);
                    extras["last_level"] = tinygltf::Value(hn.lastLevel);
                    extras["geometric_error"] = tinygltf::Value(hn.geometricError);
                    tinygltf::Value::Object proxyError;
                    proxyError["proxy_to_originals"] = tinygltf::Value(hn.error.proxyToOriginals);
                    proxyError["originals_to_proxy"] = tinygltf::Value(hn.error.originalsToProxy);
                    proxyError["proxy_to_originals_found"] = tinygltf::Value(hn.error.proxyToOriginalsLower);
                    proxyError["originals_to_proxy_found"] = tinygltf::Value(hn.error.originalsToProxyLower);
                    proxyError["tolerance"] = tinygltf::Value(hn.error.tolerance);
                    proxyError["bound"] = tinygltf::Value(hn.error.bound());
                    extras["proxy_error"] = tinygltf::Value(std::move(proxyError));
                    extras["proxy_triangles"] = intValue(nodeTriangleCount(hn));
                }
                node.extras = tinygltf::Value(std::move(extras));
                children.push_back(glb.addNode(std::move(node)));
                glb.freezeNode(children.back());  // complete: a mesh node without children
            }
            glb.node(levelIndex).children = std::move(children);
        }
        // Support surfaces pass through unchanged, flagged, under their own root node.
        if (!hierarchy.supportObjects.empty()) {
            tinygltf::Material material;
            material.name = "support";
            material.pbrMetallicRoughness.baseColorFactor = {0.5, 0.5, 0.5, 1};
            material.pbrMetallicRoughness.metallicFactor = 0.0;
            material.pbrMetallicRoughness.roughnessFactor = 0.9;
            model.materials.push_back(std::move(material));
            const int materialIndex = int(model.materials.size()) - 1;
            tinygltf::Node supportNode;
            supportNode.name = "support";
            tinygltf::Value::Object supportExtras;
            supportExtras["support"] = tinygltf::Value(true);
            supportNode.extras = tinygltf::Value(std::move(supportExtras));
            const int supportIndex = glb.addNode(std::move(supportNode));
            roots.push_back(supportIndex);
            std::vector<int> children;
            for (uint32_t s : hierarchy.supportObjects) {
                if (s >= objects.size()) {
                    error = path + ": support object " + std::to_string(s) + " does not exist";
                    return false;
                }
                const InputObject& o = objects[s];
                const std::string name = "support_" + o.name;
                tinygltf::Node node;
                node.name = name;
                node.mesh = glb.addMesh(name, o.positions, o.indices, materialIndex, &o.triangleColors);
                tinygltf::Value::Object extras;
                extras["support"] = tinygltf::Value(true);
                extras["sources"] = tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(o.name)});
                extras["source_ids"] = tinygltf::Value(tinygltf::Value::Array{intValue(o.id)});
                if (nodes && s < nodes->objectCount) extras["node"] = intValue(s);
                node.extras = tinygltf::Value(std::move(extras));
                children.push_back(glb.addNode(std::move(node)));
                glb.freezeNode(children.back());  // complete: a mesh node without children
            }
            glb.node(supportIndex).children = std::move(children);
        }
        // One scene per level (the first, finest, is the default scene), each with the support
        // surfaces; the finest level's root lists the coarser ones as MSFT_lod stand-ins.
        const int supportRoot = hierarchy.supportObjects.empty() ? -1 : roots.back();
        std::vector<std::pair<std::string, std::vector<int>>> scenes;
        for (size_t k = 0; k < levelCount; ++k) {
            std::vector<int> sceneRoots{roots[k]};
            if (supportRoot >= 0) sceneRoots.push_back(supportRoot);
            scenes.emplace_back("level" + std::to_string(k), std::move(sceneRoots));
        }
        if (levelCount == 0) scenes.emplace_back("levels", roots);
        if (levelCount > 1) {
            std::vector<int> ids(roots.begin() + 1, roots.begin() + std::ptrdiff_t(levelCount));
            std::vector<double> errors;  // per coarser level: the largest stored error of its nodes
            double radius = 0;
            if (nodes) {
                radius = enclosingRadius(*nodes);
                for (size_t k = 1; k < levelCount; ++k) {
                    double e = 0;
                    for (uint32_t n : nodes->nodeOfAggregate[k]) e = std::max(e, nodes->nodes[n].geometricError);
                    errors.push_back(e);
                }
            }
            setMsftLod(model, glb.node(roots[0]), ids, radius, errors, nodes != nullptr);
        }
        return glb.writeScenes(path, scenes, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

bool writeProxiesGlb(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     const std::string& path, std::string& error, int threadCount) {
    if (nodes.objectCount != objects.size() || nodes.nodes.size() < objects.size()) {
        error = path + ": the hierarchy nodes do not belong to these objects";
        return false;
    }
    try {
        GlbBuilder glb(path);
        glb.setThreads(threadCount);
        glb.reserveMeshes(nodes.nodes.size());
        tinygltf::Model& model = glb.model();
        int levelCount = 0;
        bool anyColours = false;
        for (const HierarchyNode& n : nodes.nodes) {
            levelCount = std::max({levelCount, n.lastLevel + 1, n.bundleLevel + 1});  // the roots' bundles: a level above
            anyColours = anyColours || !n.faceColors.empty() || n.meshPlace.hasFaceColors;
        }
        for (int k = 0; k < levelCount; ++k) {
            tinygltf::Material material;
            material.name = "level" + std::to_string(k);
            material.pbrMetallicRoughness.baseColorFactor =
                anyColours ? std::vector<double>{1, 1, 1, 1} : levelColour(size_t(k), size_t(levelCount));
            material.pbrMetallicRoughness.metallicFactor = 0.0;
            material.pbrMetallicRoughness.roughnessFactor = 0.8;
            model.materials.push_back(std::move(material));
        }
        const int originalMaterial = int(model.materials.size());
        {
            tinygltf::Material material;
            material.name = "original";
            material.pbrMetallicRoughness.baseColorFactor =
                anyColours ? std::vector<double>{1, 1, 1, 1} : std::vector<double>{0.7, 0.7, 0.7, 1};
            material.pbrMetallicRoughness.metallicFactor = 0.0;
            material.pbrMetallicRoughness.roughnessFactor = 0.8;
            model.materials.push_back(std::move(material));
        }
        for (size_t i = 0; i < nodes.nodes.size(); ++i)
            for (uint32_t c : nodes.nodes[i].children)
                if (c >= nodes.nodes.size() || nodes.nodes[c].parent != i) {
                    error = path + ": node " + std::to_string(i) + " has a bad child " + std::to_string(c);
                    return false;
                }

        // The extras of hierarchy node i, with its place `lod` in its LOD group.
        auto extrasOf = [&](size_t i, size_t lod) {
            const HierarchyNode& n = nodes.nodes[i];
            tinygltf::Value::Object extras;
            tinygltf::Value::Array sources, sourceIds;
            for (uint32_t o : n.sources) {
                if (o >= objects.size())
                    throw std::runtime_error("node " + std::to_string(i) + " refers to object " + std::to_string(o));
                sources.push_back(tinygltf::Value(objects[o].name));
                sourceIds.push_back(intValue(objects[o].id));
            }
            extras["node"] = intValue(i);
            extras["lod"] = intValue(lod);
            extras["sources"] = tinygltf::Value(std::move(sources));
            extras["source_ids"] = tinygltf::Value(std::move(sourceIds));
            extras["geometric_error"] = tinygltf::Value(n.geometricError);
            tinygltf::Value::Array sphere;
            for (int k = 0; k < 3; ++k) sphere.push_back(tinygltf::Value(n.sphereCenter[k]));
            sphere.push_back(tinygltf::Value(n.sphereRadius));
            extras["bounding_sphere"] = tinygltf::Value(std::move(sphere));
            if (n.leaf) {
                extras["leaf"] = tinygltf::Value(true);
            } else if (n.objectLod >= 1) {
                extras["object_lod"] = intValue(size_t(n.objectLod));
            } else if (n.coarserStep >= 1) {
                extras["coarser_step"] = intValue(size_t(n.coarserStep));
                extras["aggregate_level"] = tinygltf::Value(std::max(nodes.nodes[aggregateBelow(nodes, uint32_t(i))].firstLevel, 0));
                extras["delta"] = tinygltf::Value(n.delta);
            } else if (n.bundleStep >= 1) {
                extras["bundle_step"] = intValue(size_t(n.bundleStep));
                extras["aggregate_level"] = tinygltf::Value(std::max(n.bundleLevel, 0));
                extras["delta"] = tinygltf::Value(n.delta);
            } else {
                extras["level"] = tinygltf::Value(n.firstLevel);
                extras["last_level"] = tinygltf::Value(n.lastLevel);
                extras["delta"] = tinygltf::Value(n.delta);
            }
            if (!n.leaf) {
                extras["proxy_error_bound"] = tinygltf::Value(n.error.bound());
                extras["proxy_error_budget"] = tinygltf::Value(n.budget);
                extras["exact_triangles"] = intValue(n.exactTriangleCount);
            }
            return extras;
        };
        // A glTF node with hierarchy node i's mesh (proxy; a leaf: the original object).
        auto meshNode = [&](size_t i, const std::string& name, size_t lod) {
            const HierarchyNode& n = nodes.nodes[i];
            tinygltf::Node node;
            node.name = name;
            const int material = n.leaf || n.objectLod >= 1
                                     ? (n.leaf ? originalMaterial : 0)
                                     : n.bundleStep >= 1 ? std::max(n.bundleLevel, 0)
                                                         : std::max(nodes.nodes[aggregateBelow(nodes, uint32_t(i))].firstLevel, 0);
            if (n.meshPlace.kind == NodeMeshPlace::Kind::InNode) {
                node.mesh = glb.addMeshDeferred(name, std::vector<double>(n.positions.begin(), n.positions.end()),
                                                n.indices, material, &n.faceColors);
            } else {  // spilled out of memory (spillNodeMeshes): read back for this mesh alone
                NodeMesh mesh;
                std::string readError;
                if (!readNodeMesh(nodes, objects, uint32_t(i), mesh, readError)) throw std::runtime_error(readError);
                node.mesh = glb.addMeshDeferred(name, std::vector<double>(mesh.positions.begin(), mesh.positions.end()),
                                                std::move(mesh.indices), material, std::move(mesh.faceColors));
            }
            node.extras = tinygltf::Value(extrasOf(i, lod));
            return glb.addNode(std::move(node));
        };

        // LOD groups: one per root and per child of a node with several children (its "top").
        // From the top, single children lead down to the group's bottom: a leaf, or a node with
        // several children. Finest first, the group's levels are LOD0 = the original (leaf
        // bottom) or a node holding the child groups' LOD0 nodes (otherwise), then the stand-ins:
        // the bottom's own proxy (when it is not a leaf) and every node up the chain to the top.
        // LOD0 nodes form the default scene; stand-ins are roots of the second scene and listed
        // by MSFT_lod on their LOD0 node.
        std::vector<int> finestRoots, standInRoots;
        struct Pending {
            uint32_t top;
            int parentLod0;  ///< glTF node receiving this group's LOD0 as a child, -1 for a root
        };
        std::vector<Pending> stack;
        for (size_t r = nodes.roots.size(); r-- > 0;) stack.push_back({nodes.roots[r], -1});
        size_t visitedTops = 0;
        while (!stack.empty()) {
            const Pending p = stack.back();
            stack.pop_back();
            if (++visitedTops > nodes.nodes.size()) throw std::runtime_error("the node tree has a cycle");
            std::vector<uint32_t> chain{p.top};  // top first
            while (nodes.nodes[chain.back()].children.size() == 1) {
                chain.push_back(nodes.nodes[chain.back()].children[0]);
                if (chain.size() > nodes.nodes.size()) throw std::runtime_error("the node tree has a cycle");
            }
            const uint32_t bottom = chain.back();
            const HierarchyNode& b = nodes.nodes[bottom];
            const std::string stem = b.leaf ? objects[bottom].name : "node" + std::to_string(bottom);
            int lod0 = -1;
            if (b.leaf) {
                lod0 = meshNode(bottom, stem + "_LOD0", 0);
            } else {
                tinygltf::Node group;
                group.name = stem + "_LOD0";
                tinygltf::Value::Object extras;
                extras["lod"] = tinygltf::Value(0);
                extras["children_of"] = intValue(bottom);
                group.extras = tinygltf::Value(std::move(extras));
                lod0 = glb.addNode(std::move(group));
                for (size_t c = b.children.size(); c-- > 0;) stack.push_back({b.children[c], lod0});
            }
            if (p.parentLod0 < 0) finestRoots.push_back(lod0);
            else glb.node(p.parentLod0).children.push_back(lod0);
            std::vector<int> ids;
            std::vector<double> errors;
            size_t lod = 1;
            for (size_t c = chain.size() - (b.leaf ? 1 : 0); c-- > 0;) {
                const uint32_t i = chain[c];
                const int standIn = meshNode(i, stem + "_LOD" + std::to_string(lod), lod);
                glb.freezeNode(standIn);  // complete: a stand-in has no children
                ++lod;
                ids.push_back(standIn);
                errors.push_back(nodes.nodes[i].geometricError);
                standInRoots.push_back(standIn);
            }
            setMsftLod(model, glb.node(lod0), ids, nodes.nodes[p.top].sphereRadius, errors, true);
            // A leaf's LOD0 is complete; a group's gets its child groups' LOD0 nodes later.
            if (b.leaf) glb.freezeNode(lod0);
            else glb.freezeExtras(lod0);
        }
        // Children were pushed in reverse onto the stack, so they arrive in order; the LOD0
        // nodes of a group's children are appended in that order.
        std::vector<std::pair<std::string, std::vector<int>>> scenes{{"finest", finestRoots}};
        if (!standInRoots.empty()) scenes.emplace_back("coarser_stand_ins", standInRoots);
        return glb.writeScenes(path, scenes, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

bool writeCollisionGlb(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       const std::vector<NodeCollisionShapes>& shapes, const std::vector<CollisionCut>& cuts,
                       const std::string& path, std::string& error) {
    if (nodes.objectCount != objects.size() || nodes.nodes.size() < objects.size() || shapes.size() != nodes.nodes.size()) {
        error = path + ": the collision shapes do not belong to these hierarchy nodes";
        return false;
    }
    try {
        GlbBuilder glb(path);
        tinygltf::Model& model = glb.model();
        tinygltf::Value::Array omiShapes;
        // Static colliders: no motion. Each collider node carries its own mesh and names it as
        // KHR geometry (geometry.node = itself), and the same mesh as an OMI_physics_shape.
        auto colliderNode = [&](const std::string& name, const std::vector<float>& positions,
                                const std::vector<uint32_t>& indices, bool convex, tinygltf::Value::Object extras) {
            tinygltf::Node node;
            node.name = name;
            node.mesh = glb.addPlainMesh(name, positions, indices);
            const int index = glb.nodeCount();
            tinygltf::Value::Object geometry;
            geometry["node"] = tinygltf::Value(index);
            geometry["convexHull"] = tinygltf::Value(convex);
            tinygltf::Value::Object collider;
            collider["geometry"] = tinygltf::Value(std::move(geometry));
            tinygltf::Value::Object khr;
            khr["collider"] = tinygltf::Value(std::move(collider));
            node.extensions["KHR_physics_rigid_bodies"] = tinygltf::Value(std::move(khr));
            tinygltf::Value::Object shapeMesh;
            shapeMesh["mesh"] = tinygltf::Value(node.mesh);
            tinygltf::Value::Object shape;
            const std::string type = convex ? "convex" : "trimesh";
            shape["type"] = tinygltf::Value(type);
            shape[type] = tinygltf::Value(std::move(shapeMesh));
            omiShapes.push_back(tinygltf::Value(std::move(shape)));
            tinygltf::Value::Object omiCollider;
            omiCollider["shape"] = tinygltf::Value(int(omiShapes.size()) - 1);
            tinygltf::Value::Object omi;
            omi["collider"] = tinygltf::Value(std::move(omiCollider));
            node.extensions["OMI_physics_body"] = tinygltf::Value(std::move(omi));
            extras["shape"] = tinygltf::Value(convex ? std::string("convex") : std::string("trimesh"));
            node.extras = tinygltf::Value(std::move(extras));
            return glb.addNode(std::move(node));
        };
        auto commonExtras = [&](size_t i) {
            const HierarchyNode& n = nodes.nodes[i];
            tinygltf::Value::Object extras;
            extras["node"] = intValue(i);
            extras["geometric_error"] = tinygltf::Value(n.geometricError);
            tinygltf::Value::Array sourceIds;
            for (uint32_t o : n.sources) {
                if (o >= objects.size())
                    throw std::runtime_error("node " + std::to_string(i) + " refers to object " + std::to_string(o));
                sourceIds.push_back(intValue(objects[o].id));
            }
            extras["source_ids"] = tinygltf::Value(std::move(sourceIds));
            if (n.leaf) extras["leaf"] = tinygltf::Value(true);
            return extras;
        };
        std::vector<int> trimeshOf(nodes.nodes.size(), -1), convexOf(nodes.nodes.size(), -1);
        for (size_t i = 0; i < nodes.nodes.size(); ++i) {
            const HierarchyNode& n = nodes.nodes[i];
            if (nodeTriangleCount(n) == 0) continue;
            const std::string stem = n.leaf ? objects[i].name : "node" + std::to_string(i);
            NodeMesh storage;  // a mesh out of memory (spillNodeMeshes) comes back here
            const NodeMeshView mesh = viewNodeMesh(nodes, objects, uint32_t(i), storage);
            trimeshOf[i] = colliderNode(stem + "_collider", mesh.positions, mesh.indices, false, commonExtras(i));
            const NodeCollisionShapes& c = shapes[i];
            if (c.convexParts.empty()) continue;
            tinygltf::Node group;
            group.name = stem + "_convex";
            tinygltf::Value::Object extras = commonExtras(i);
            extras["shape"] = tinygltf::Value(std::string("convex_decomposition"));
            extras["convex_error"] = tinygltf::Value(c.convexError);
            extras["allowance"] = tinygltf::Value(c.allowance);
            extras["parts"] = intValue(c.convexParts.size());
            group.extras = tinygltf::Value(std::move(extras));
            const int groupIndex = glb.addNode(std::move(group));
            std::vector<int> children;
            for (size_t j = 0; j < c.convexParts.size(); ++j) {
                tinygltf::Value::Object partExtras = commonExtras(i);
                partExtras["part"] = intValue(j);
                partExtras["error_bound"] = tinygltf::Value(c.convexParts[j].errorBound);
                children.push_back(colliderNode(stem + "_convex" + std::to_string(j), c.convexParts[j].positions,
                                                c.convexParts[j].indices, true, std::move(partExtras)));
            }
            glb.node(groupIndex).children = std::move(children);
            convexOf[i] = groupIndex;
        }
        // Scenes: per cut its trimesh colliders, then the same cut with convex decompositions
        // where a node has one; last every node's shapes (overlapping: for tools).
        std::vector<std::pair<std::string, std::vector<int>>> scenes;
        for (const CollisionCut& cut : cuts) {
            std::vector<int> trimesh, convex;
            for (uint32_t i : cut.nodes) {
                if (i >= nodes.nodes.size() || trimeshOf[i] < 0) continue;
                trimesh.push_back(trimeshOf[i]);
                convex.push_back(convexOf[i] >= 0 ? convexOf[i] : trimeshOf[i]);
            }
            scenes.emplace_back(cut.name, std::move(trimesh));
            scenes.emplace_back(cut.name + "_convex", std::move(convex));
        }
        std::vector<int> all;
        for (size_t i = 0; i < nodes.nodes.size(); ++i) {
            if (trimeshOf[i] >= 0) all.push_back(trimeshOf[i]);
            if (convexOf[i] >= 0) all.push_back(convexOf[i]);
        }
        scenes.emplace_back("all_nodes", std::move(all));
        tinygltf::Value::Object omiShape;
        omiShape["shapes"] = tinygltf::Value(std::move(omiShapes));
        model.extensions["OMI_physics_shape"] = tinygltf::Value(std::move(omiShape));
        model.extensionsUsed = {"KHR_physics_rigid_bodies", "OMI_physics_body", "OMI_physics_shape"};
        return glb.writeScenes(path, scenes, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

std::vector<double> levelBaseColour(size_t level, size_t levelCount) { return levelColour(level, levelCount); }

bool writeTileGlb(const TileMesh& tile, const std::string& path, std::string& error) {
    if (tile.positions.size() % 3 != 0 || tile.indices.size() % 3 != 0) {
        error = path + ": " + tile.name + ": positions or indices size is not a multiple of 3";
        return false;
    }
    const size_t vertexCount = tile.positions.size() / 3;
    for (uint32_t i : tile.indices) {
        if (i >= vertexCount) {
            error = path + ": " + tile.name + ": index " + std::to_string(i) + " out of range (" +
                    std::to_string(vertexCount) + " vertices)";
            return false;
        }
    }
    try {
        GlbBuilder glb(path);
        tinygltf::Model& model = glb.model();
        tinygltf::Material material;
        material.name = tile.name;
        material.pbrMetallicRoughness.baseColorFactor.assign(tile.baseColor, tile.baseColor + 4);
        material.pbrMetallicRoughness.metallicFactor = 0.0;
        material.pbrMetallicRoughness.roughnessFactor = 0.8;
        model.materials.push_back(std::move(material));

        tinygltf::Node node;
        node.name = tile.name;
        const std::vector<double> positions(tile.positions.begin(), tile.positions.end());
        node.mesh = glb.addMesh(tile.name, positions, tile.indices, 0);
        tinygltf::Value::Object extras;
        extras["node"] = intValue(tile.node);
        extras["geometric_error"] = tinygltf::Value(tile.geometricError);
        tinygltf::Value::Array sourceIds;
        for (uint64_t id : tile.sourceIds) sourceIds.push_back(intValue(id));
        extras["source_ids"] = tinygltf::Value(std::move(sourceIds));
        node.extras = tinygltf::Value(std::move(extras));
        const int root = glb.addNode(std::move(node));
        if (glb.meshCount() == 0) model.materials.clear();  // nothing drawn: no unused material
        return glb.write(path, std::vector<int>{root}, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}


}  // namespace aggrelod::io
