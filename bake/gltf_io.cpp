// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: glTF in and out. The only translation unit that includes tiny_gltf.h
// (Debian ships tinygltf's implementation compiled in libtinygltf.so, so no
// TINYGLTF_IMPLEMENTATION here).
//
// Reading: geometry and base colours. Images are never decoded (a loader callback that
// accepts anything); of the materials only baseColorFactor is read (times the mean COLOR_0
// of each triangle's corners when present; base colour textures are ignored with a note);
// unknown extensions are ignored; every accessor and
// buffer view is range-checked here before a byte is read, and a bad object is
// skipped with a diagnostic so that the rest of the scene can still be baked.
#include "runtime_export.h"
#include "scene_io.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <new>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace aggrelod::io {
namespace {

using Severity = Diagnostic::Severity;

// Limits on hostile structure (documented in docs/command-line.md, "Limits").
/// JSON nesting deeper than this is refused: tinygltf's parser recurses once per level.
constexpr size_t kMaxJsonDepth = 100;
/// Nodes in one file.
constexpr size_t kMaxNodes = 1000000;
/// Mesh nodes reached by the traversal (instances of meshes).
constexpr size_t kMaxMeshInstances = 200000;
/// Triangles in world space after instancing.
constexpr size_t kMaxWorldTriangles = 50000000;
/// Largest magnitude of a world coordinate. Far below where squares and cubes of
/// coordinates (areas, volumes, ray distances) leave double or float range.
constexpr double kMaxCoordinate = 1e15;
/// Depth of the node hierarchy.
constexpr size_t kMaxNodeDepth = 1000;


// ---------------------------------------------------------------------------
// Small double-precision 4x4 matrix (column-major, as glTF).

struct Mat4 {
    double m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
};

Mat4 multiply(const Mat4& a, const Mat4& b) {
    Mat4 r;
    for (int col = 0; col < 4; ++col) {
        for (int row = 0; row < 4; ++row) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a.m[k * 4 + row] * b.m[col * 4 + k];
            r.m[col * 4 + row] = s;
        }
    }
    return r;
}

double determinant3(const Mat4& a) {
    const double* m = a.m;
    // Upper-left 3x3, element (row, col) = m[col * 4 + row].
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/// Local transform of a node: `matrix` if given, else T * R * S.
Mat4 localTransform(const tinygltf::Node& node, std::string& problem) {
    Mat4 r;
    if (!node.matrix.empty()) {
        if (node.matrix.size() == 16) {
            for (int i = 0; i < 16; ++i) r.m[i] = node.matrix[size_t(i)];
            return r;
        }
        problem = "matrix has " + std::to_string(node.matrix.size()) +
                  " numbers instead of 16; identity used";
        return r;
    }
    double t[3] = {0, 0, 0}, s[3] = {1, 1, 1}, q[4] = {0, 0, 0, 1};
    if (node.translation.size() == 3) {
        for (int i = 0; i < 3; ++i) t[i] = node.translation[size_t(i)];
    } else if (!node.translation.empty()) {
        problem = "translation does not have 3 numbers; ignored";
    }
    if (node.scale.size() == 3) {
        for (int i = 0; i < 3; ++i) s[i] = node.scale[size_t(i)];
    } else if (!node.scale.empty()) {
        problem = "scale does not have 3 numbers; ignored";
    }
    if (node.rotation.size() == 4) {
        for (int i = 0; i < 4; ++i) q[i] = node.rotation[size_t(i)];
        const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
        if (n > 0 && std::isfinite(n)) {
            for (double& c : q) c /= n;
        }
    } else if (!node.rotation.empty()) {
        problem = "rotation does not have 4 numbers; ignored";
    }
    const double x = q[0], y = q[1], z = q[2], w = q[3];
    const double R[3][3] = {
        {1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
        {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
        {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)},
    };
    for (int col = 0; col < 3; ++col) {
        for (int row = 0; row < 3; ++row) r.m[col * 4 + row] = R[row][col] * s[col];
        r.m[col * 4 + 3] = 0;
    }
    r.m[12] = t[0];
    r.m[13] = t[1];
    r.m[14] = t[2];
    r.m[15] = 1;
    return r;
}

// ---------------------------------------------------------------------------
// Accessor reading with full range checks.

int componentSize(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
        case TINYGLTF_COMPONENT_TYPE_SHORT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
        case TINYGLTF_COMPONENT_TYPE_INT:
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return 4;
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return 8;
        default: return 0;
    }
}

const char* componentName(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
        default: return "unknown";
    }
}

/// One component at `p` converted to double (normalized integers mapped as the spec says).
double readComponent(const unsigned char* p, int componentType, bool normalized) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: {
            int8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? std::max(double(v) / 127.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
            uint8_t v;
            std::memcpy(&v, p, 1);
            return normalized ? double(v) / 255.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_SHORT: {
            int16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? std::max(double(v) / 32767.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
            uint16_t v;
            std::memcpy(&v, p, 2);
            return normalized ? double(v) / 65535.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_INT: {
            int32_t v;
            std::memcpy(&v, p, 4);
            return normalized ? std::max(double(v) / 2147483647.0, -1.0) : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
            uint32_t v;
            std::memcpy(&v, p, 4);
            return normalized ? double(v) / 4294967295.0 : double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_FLOAT: {
            float v;
            std::memcpy(&v, p, 4);
            return double(v);
        }
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: {
            double v;
            std::memcpy(&v, p, 8);
            return v;
        }
        default: return 0;
    }
}

/// a * b + c without overflow, or false.
bool mulAdd(uint64_t a, uint64_t b, uint64_t c, uint64_t& out) {
    uint64_t prod;
    if (__builtin_mul_overflow(a, b, &prod)) return false;
    return !__builtin_add_overflow(prod, c, &out);
}

/// Bytes of buffer view `viewIndex`, checked against its buffer. Returns nullptr with `why`.
const unsigned char* viewBytes(const tinygltf::Model& model, int viewIndex, size_t& length,
                               size_t& stride, std::string& why) {
    if (viewIndex < 0 || size_t(viewIndex) >= model.bufferViews.size()) {
        why = "bufferView " + std::to_string(viewIndex) + " does not exist (" +
              std::to_string(model.bufferViews.size()) + " buffer views)";
        return nullptr;
    }
    const tinygltf::BufferView& view = model.bufferViews[size_t(viewIndex)];
    if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
        why = "bufferView " + std::to_string(viewIndex) + " refers to buffer " +
              std::to_string(view.buffer) + ", which does not exist";
        return nullptr;
    }
    const tinygltf::Buffer& buffer = model.buffers[size_t(view.buffer)];
    uint64_t end;
    if (!mulAdd(1, view.byteOffset, view.byteLength, end) || end > buffer.data.size()) {
        why = "bufferView " + std::to_string(viewIndex) + " (offset " +
              std::to_string(view.byteOffset) + ", length " + std::to_string(view.byteLength) +
              ") lies outside buffer " + std::to_string(view.buffer) + " of " +
              std::to_string(buffer.data.size()) + " bytes (truncated file?)";
        return nullptr;
    }
    length = view.byteLength;
    stride = view.byteStride;
    return buffer.data.data() + view.byteOffset;
}

/// Reads accessor `index` into doubles (count * components values). `indices`: a SCALAR
/// index accessor (unsigned integer types only); `colours`: a VEC3 or VEC4 COLOR_n accessor
/// (components = 3 or 4); otherwise a VEC3 position accessor.
bool readAccessor(const tinygltf::Model& model, int index, bool indices,
                  std::vector<double>& out, std::string& why, bool colours = false) {
    if (index < 0 || size_t(index) >= model.accessors.size()) {
        why = "accessor " + std::to_string(index) + " does not exist (" +
              std::to_string(model.accessors.size()) + " accessors)";
        return false;
    }
    const tinygltf::Accessor& acc = model.accessors[size_t(index)];
    const std::string name = "accessor " + std::to_string(index);
    const int components = indices ? 1 : (colours && acc.type == TINYGLTF_TYPE_VEC4 ? 4 : 3);
    if (colours && acc.type != TINYGLTF_TYPE_VEC3 && acc.type != TINYGLTF_TYPE_VEC4) {
        why = name + " of colours is neither VEC3 nor VEC4";
        return false;
    }
    if (indices && acc.type != TINYGLTF_TYPE_SCALAR) {
        why = name + " of indices is not SCALAR";
        return false;
    }
    if (!indices && !colours && acc.type != TINYGLTF_TYPE_VEC3) {
        why = name + " of positions is not VEC3";
        return false;
    }
    const int csize = componentSize(acc.componentType);
    if (csize == 0) {
        why = name + " has invalid componentType " + std::to_string(acc.componentType);
        return false;
    }
    if (indices && acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
        acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        why = name + " of indices has component type " + componentName(acc.componentType) +
              " (must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT)";
        return false;
    }
    const size_t count = acc.count;
    if (count > size_t(std::numeric_limits<uint32_t>::max())) {
        why = name + " has too many elements (" + std::to_string(count) + ")";
        return false;
    }
    const size_t elementSize = size_t(csize) * size_t(components);

    if (acc.bufferView < 0) {
        // Nothing bounds the count by the file's size here: an accessor without data may not
        // be larger than all the file's buffers together (a tiny file must not ask for GBs).
        uint64_t bufferBytes = 0;
        for (const tinygltf::Buffer& b : model.buffers) bufferBytes += b.data.size();
        if (count > (size_t(1) << 28) || uint64_t(count) * elementSize > std::max<uint64_t>(bufferBytes, 4096)) {
            why = name + " has no bufferView and " + std::to_string(count) + " elements (" +
                  std::to_string(uint64_t(count) * elementSize) + " bytes), more than the file's buffers hold (" +
                  std::to_string(bufferBytes) + " bytes); refused";
            return false;
        }
        if (!acc.sparse.isSparse) {
            // Spec: without a buffer view the accessor is all zeros. Geometry compressed by
            // an extension (Draco, meshopt) also looks like this; the caller reports that.
            why = name + " has no bufferView (all zeros)";
            return false;
        }
        out.assign(count * size_t(components), 0.0);
    } else {
        size_t length = 0, stride = 0;
        const unsigned char* base = viewBytes(model, acc.bufferView, length, stride, why);
        if (!base) {
            why = name + ": " + why;
            return false;
        }
        if (stride == 0) stride = elementSize;
        if (stride < elementSize) {
            why = name + ": bufferView " + std::to_string(acc.bufferView) + " byteStride " +
                  std::to_string(stride) + " is smaller than one element (" +
                  std::to_string(elementSize) + " bytes)";
            return false;
        }
        if (count > 0) {
            uint64_t end;
            if (!mulAdd(count - 1, stride, uint64_t(acc.byteOffset) + elementSize, end) ||
                acc.byteOffset > length || end > length) {
                why = name + " (" + std::to_string(count) + " elements, offset " +
                      std::to_string(acc.byteOffset) + ", stride " + std::to_string(stride) +
                      ") does not fit in bufferView " + std::to_string(acc.bufferView) + " of " +
                      std::to_string(length) + " bytes";
                return false;
            }
        }
        out.resize(count * size_t(components));
        for (size_t i = 0; i < count; ++i) {
            const unsigned char* e = base + acc.byteOffset + i * stride;
            for (int c = 0; c < components; ++c) {
                out[i * size_t(components) + size_t(c)] =
                    readComponent(e + size_t(c) * size_t(csize), acc.componentType, acc.normalized);
            }
        }
    }

    if (acc.sparse.isSparse) {
        const auto& sp = acc.sparse;
        if (sp.count < 0 || size_t(sp.count) > count) {
            why = name + ": sparse count " + std::to_string(sp.count) + " is out of range";
            return false;
        }
        const int icType = sp.indices.componentType;
        if (icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            icType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
            why = name + ": sparse indices have invalid component type";
            return false;
        }
        const size_t icSize = size_t(componentSize(icType));
        size_t ilen = 0, istride = 0, vlen = 0, vstride = 0;
        const unsigned char* ib = viewBytes(model, sp.indices.bufferView, ilen, istride, why);
        if (!ib) {
            why = name + ": sparse indices: " + why;
            return false;
        }
        const unsigned char* vb = viewBytes(model, sp.values.bufferView, vlen, vstride, why);
        if (!vb) {
            why = name + ": sparse values: " + why;
            return false;
        }
        const size_t n = size_t(sp.count);
        if (sp.indices.byteOffset < 0 || sp.values.byteOffset < 0 ||
            size_t(sp.indices.byteOffset) + n * icSize > ilen ||
            size_t(sp.values.byteOffset) + n * elementSize > vlen) {
            why = name + ": sparse data does not fit in its buffer views";
            return false;
        }
        for (size_t k = 0; k < n; ++k) {
            const double target =
                readComponent(ib + size_t(sp.indices.byteOffset) + k * icSize, icType, false);
            if (target >= double(count)) {
                why = name + ": sparse index " + std::to_string(uint64_t(target)) +
                      " is out of range (count " + std::to_string(count) + ")";
                return false;
            }
            const size_t t = size_t(target);
            const unsigned char* e = vb + size_t(sp.values.byteOffset) + k * elementSize;
            for (int c = 0; c < components; ++c) {
                out[t * size_t(components) + size_t(c)] =
                    readComponent(e + size_t(c) * size_t(csize), acc.componentType, acc.normalized);
            }
        }
    }
    return true;
}

// ---------------------------------------------------------------------------
// Scene reading.

/// Extensions that change geometry and that aggrelod cannot decode.
bool isUnsupportedGeometryExtension(const std::string& ext) {
    return ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression" ||
           ext == "EXT_mesh_gpu_instancing";
}

/// Extensions that change geometry and that aggrelod reads.
bool isSupportedGeometryExtension(const std::string& ext) {
    return ext == "KHR_mesh_quantization";
}

/// Image loader that accepts any image without decoding it: only geometry is read.
bool acceptImageWithoutDecoding(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                                const unsigned char*, int, void*) {
    return true;
}

const char* modeName(int mode) {
    switch (mode) {
        case TINYGLTF_MODE_POINTS: return "POINTS";
        case TINYGLTF_MODE_LINE: return "LINES";
        case TINYGLTF_MODE_LINE_LOOP: return "LINE_LOOP";
        case TINYGLTF_MODE_LINE_STRIP: return "LINE_STRIP";
        case TINYGLTF_MODE_TRIANGLES: return "TRIANGLES";
        case TINYGLTF_MODE_TRIANGLE_STRIP: return "TRIANGLE_STRIP";
        case TINYGLTF_MODE_TRIANGLE_FAN: return "TRIANGLE_FAN";
        default: return "unknown";
    }
}

/// A node's name; an unnamed node is called after its mesh and its index path
/// ("Wheel@0/3/1": position in the scene's root list, then child positions), which stays the
/// same however the file is re-exported, as long as the hierarchy does. `path` is empty
/// before the traversal reached the node (then the node index is used).
std::string displayName(const tinygltf::Model& model, int node, const std::string& path = std::string()) {
    const tinygltf::Node& n = model.nodes[size_t(node)];
    if (!n.name.empty()) return n.name;
    std::string base = "node";
    if (n.mesh >= 0 && size_t(n.mesh) < model.meshes.size())
        base = model.meshes[size_t(n.mesh)].name.empty() ? "mesh" + std::to_string(n.mesh) : model.meshes[size_t(n.mesh)].name;
    return base + (path.empty() ? std::to_string(node) : path);
}

/// An object being assembled from one or more mesh nodes.
struct ObjectBuilder {
    std::string name;        ///< before de-duplication
    int topNode = -1;
    bool hadMesh = false;    ///< at least one node with a mesh contributed
    bool failed = false;     ///< a data error: the object is skipped
    std::vector<double> positions;
    std::vector<uint32_t> indices;
    std::vector<float> colors;  ///< linear RGBA per triangle (InputObject::triangleColors)
};

class SceneReader {
public:
    SceneReader(const tinygltf::Model& model, const SceneReadOptions& options,
                std::vector<Diagnostic>& diagnostics)
        : model_(model), options_(options), diags_(diagnostics) {}

    bool run(std::vector<InputObject>& objects, std::string& error);
    /// After run: per object, the glTF node that opened it (its mesh node, or the top of
    /// its subtree).
    const std::vector<int>& objectNodes() const { return objectNodes_; }

private:
    void note(Severity severity, const std::string& object, const std::string& message) {
        diags_.push_back(Diagnostic{severity, object, message});
    }
    bool matches(std::string text) const {
        // libstdc++'s regex matcher recurses per character: a crafted, very long name could
        // overflow the stack, so only the first 1024 characters of a name are matched.
        if (text.size() > 1024) text.resize(1024);
        return std::regex_search(text, regex_);
    }
    /// The node with its subtree is left out: its name or index path matches.
    bool excluded(int node) const {
        return hasRegex_ && (matches(name(node)) || matches(path(node)));
    }
    /// Only the node's own mesh is left out (see SceneReadOptions::excludeRegex).
    bool meshExcluded(int node) const {
        const tinygltf::Node& n = model_.nodes[size_t(node)];
        if (!hasRegex_ || n.mesh < 0) return false;
        const std::string meshName = size_t(n.mesh) < model_.meshes.size() ? model_.meshes[size_t(n.mesh)].name : std::string();
        return matches(name(node) + "/mesh") || matches(path(node) + "/mesh") ||
               (!meshName.empty() && matches("mesh:" + meshName));
    }
    std::string name(int node) const { return displayName(model_, node, path(node)); }
    /// Index path "@0/3/1" of a node the traversal reached (empty before), built from the
    /// parent links on demand: storing every path would cost depth x nodes.
    std::string path(int node) const {
        if (pathParent_[size_t(node)] == kUnreached) return std::string();
        std::vector<uint32_t> parts;
        for (int n = node;; n = pathParent_[size_t(n)]) {
            parts.push_back(pathPosition_[size_t(n)]);
            if (pathParent_[size_t(n)] < 0) break;
        }
        std::string text = "@" + std::to_string(parts.back());
        for (size_t i = parts.size() - 1; i-- > 0;) text += "/" + std::to_string(parts[i]);
        return text;
    }
    void addMeshOfNode(int node, const Mat4& world, ObjectBuilder& object);
    bool addPrimitive(int node, int meshIndex, int primIndex, const Mat4& world, bool flip,
                      ObjectBuilder& object);
    void fail(ObjectBuilder& object, int node, const std::string& why) {
        if (!object.failed) {
            note(Severity::Warning, object.name,
                 why + " (node " + std::to_string(node) + " '" + name(node) +
                     "'); object skipped");
        }
        object.failed = true;
    }

    const tinygltf::Model& model_;
    const SceneReadOptions& options_;
    std::vector<Diagnostic>& diags_;
    std::regex regex_;
    bool hasRegex_ = false;
    static constexpr int kUnreached = -2;
    std::vector<int> pathParent_;          ///< per node: parent in the traversal, -1 for a root
    std::vector<uint32_t> pathPosition_;   ///< per node: position among its parent's children (or roots)
    size_t meshInstances_ = 0;             ///< mesh nodes read (kMaxMeshInstances)
    size_t worldTriangles_ = 0;            ///< triangles read (kMaxWorldTriangles)
    size_t worldVertices_ = 0;             ///< vertices read (3 kMaxWorldTriangles)
    std::string fatal_;                    ///< input refused as a whole (limits, coordinate range)
    std::vector<std::string> nonTriangle_;  ///< "node 'name' mesh m primitive p: mode", listed in one note
    bool notedTexture_ = false;  ///< the texture note is given once per file
    std::vector<int> objectNodes_;  ///< per object: the node that opened it
};

bool SceneReader::addPrimitive(int node, int meshIndex, int primIndex, const Mat4& world,
                               bool flip, ObjectBuilder& object) {
    const tinygltf::Primitive& prim = model_.meshes[size_t(meshIndex)].primitives[size_t(primIndex)];
    const std::string where = "mesh " + std::to_string(meshIndex) + " primitive " +
                              std::to_string(primIndex);
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
        mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        const bool known = mode >= TINYGLTF_MODE_POINTS && mode <= TINYGLTF_MODE_LINE_STRIP;
        if (!known) {
            note(Severity::Warning, object.name,
                 "node " + std::to_string(node) + " '" + name(node) + "' " + where + ": mode " + std::to_string(mode) +
                     " is not a glTF primitive mode; primitive skipped");
        } else {
            nonTriangle_.push_back("'" + name(node) + "' " + where + " (" + modeName(mode) + ")");
        }
        return true;
    }
    const auto pos = prim.attributes.find("POSITION");
    if (pos == prim.attributes.end()) {
        note(Severity::Warning, object.name,
             "node " + std::to_string(node) + " '" + name(node) + "' " + where +
                 ": no POSITION attribute; primitive skipped");
        return true;
    }
    for (const auto& ext : prim.extensions) {
        if (isUnsupportedGeometryExtension(ext.first) &&
            pos->second >= 0 && size_t(pos->second) < model_.accessors.size() &&
            model_.accessors[size_t(pos->second)].bufferView < 0 &&
            !model_.accessors[size_t(pos->second)].sparse.isSparse) {
            fail(object, node, where + " is compressed with " + ext.first +
                                   ", which aggrelod cannot decode");
            return false;
        }
    }

    std::vector<double> p;
    std::string why;
    if (!readAccessor(model_, pos->second, false, p, why)) {
        fail(object, node, where + ": POSITION: " + why);
        return false;
    }
    const size_t vertexCount = p.size() / 3;
    worldVertices_ += vertexCount;
    if (worldVertices_ > 3 * kMaxWorldTriangles) {
        fatal_ = "more than " + std::to_string(3 * kMaxWorldTriangles) + " vertices in the scene after instancing, at node " +
                 std::to_string(node) + " '" + name(node) + "'; refused (limit of aggrelod)";
        return false;
    }
    std::vector<double> idx;
    if (prim.indices >= 0) {
        if (!readAccessor(model_, prim.indices, true, idx, why)) {
            fail(object, node, where + ": indices: " + why);
            return false;
        }
        for (double v : idx) {
            if (v >= double(vertexCount)) {
                fail(object, node,
                     where + ": index out of range: index " + std::to_string(uint64_t(v)) +
                         " >= vertex count " + std::to_string(vertexCount));
                return false;
            }
        }
    } else {
        idx.resize(vertexCount);
        for (size_t i = 0; i < vertexCount; ++i) idx[i] = double(i);
    }

    // Corner triples in the primitive's own vertex numbering.
    std::vector<uint32_t> tri;
    const size_t n = idx.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0) {
            note(Severity::Warning, object.name,
                 "node " + std::to_string(node) + " '" + name(node) + "' " + where +
                     ": " + std::to_string(n) + " indices is not a multiple of 3; last " +
                     std::to_string(n % 3) + " ignored");
        }
        tri.reserve(n - n % 3);
        for (size_t i = 0; i + 2 < n; i += 3) {
            tri.push_back(uint32_t(idx[i]));
            tri.push_back(uint32_t(idx[i + 1]));
            tri.push_back(uint32_t(idx[i + 2]));
        }
    } else {
        // Strips and fans: the degenerate triangles a strip uses as joints are dropped.
        for (size_t i = 0; i + 2 < n; ++i) {
            uint32_t a, b, c;
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                a = uint32_t(idx[i]);
                b = uint32_t(idx[i + 1 + (i % 2)]);
                c = uint32_t(idx[i + 2 - (i % 2)]);
            } else {
                a = uint32_t(idx[i + 1]);
                b = uint32_t(idx[i + 2]);
                c = uint32_t(idx[0]);
            }
            if (a == b || b == c || a == c) continue;
            tri.push_back(a);
            tri.push_back(b);
            tri.push_back(c);
        }
    }
    if (tri.empty()) return true;
    worldTriangles_ += tri.size() / 3;
    if (worldTriangles_ > kMaxWorldTriangles) {
        fatal_ = "more than " + std::to_string(kMaxWorldTriangles) + " triangles in the scene after instancing, at node " +
                 std::to_string(node) + " '" + name(node) + "'; refused (limit of aggrelod)";
        return false;
    }

    // Base colour of each triangle: the material's baseColorFactor (white without a
    // material), times the mean COLOR_0 of its corners when the primitive has vertex colours.
    double factor[4] = {1, 1, 1, 1};
    if (prim.material >= 0 && size_t(prim.material) < model_.materials.size()) {
        const tinygltf::Material& material = model_.materials[size_t(prim.material)];
        const std::vector<double>& f = material.pbrMetallicRoughness.baseColorFactor;
        if (f.size() == 4 && std::all_of(f.begin(), f.end(), [](double x) { return std::isfinite(x); }))
            for (int c = 0; c < 4; ++c) factor[c] = std::min(1.0, std::max(0.0, f[size_t(c)]));
        if (material.pbrMetallicRoughness.baseColorTexture.index >= 0 && !notedTexture_) {
            notedTexture_ = true;
            note(Severity::Note, object.name,
                 "material " + std::to_string(prim.material) + " '" + material.name +
                     "' has a base colour texture; textures are not read, proxies take its baseColorFactor");
        }
    } else if (prim.material >= 0) {
        note(Severity::Warning, object.name,
             "node " + std::to_string(node) + " '" + name(node) + "' " + where + ": material " +
                 std::to_string(prim.material) + " does not exist; white is used");
    }
    std::vector<double> vertexColours;
    int colourComponents = 0;
    const auto col = prim.attributes.find("COLOR_0");
    if (col != prim.attributes.end()) {
        why.clear();
        if (!readAccessor(model_, col->second, false, vertexColours, why, true) ||
            (vertexColours.size() != 3 * vertexCount && vertexColours.size() != 4 * vertexCount)) {
            note(Severity::Warning, object.name,
                 "node " + std::to_string(node) + " '" + name(node) + "' " + where +
                     ": COLOR_0 unusable (" + (why.empty() ? "count differs from POSITION" : why) +
                     "); the material colour is used");
            vertexColours.clear();
        } else {
            colourComponents = int(vertexColours.size() / vertexCount);
        }
    }
    const size_t firstTriangle = object.indices.size() / 3;
    object.colors.resize(4 * firstTriangle, 1.0f);  // earlier primitives without colour data
    for (size_t t = 0; t < tri.size(); t += 3) {
        for (int c = 0; c < 4; ++c) {
            double v = factor[c];
            if (colourComponents > 0) {
                double mean = 1;
                if (c < colourComponents) {
                    mean = 0;
                    for (int k = 0; k < 3; ++k) mean += vertexColours[size_t(colourComponents) * tri[t + size_t(k)] + size_t(c)];
                    mean /= 3;
                }
                v *= std::isfinite(mean) ? std::min(1.0, std::max(0.0, mean)) : 1.0;
            }
            object.colors.push_back(float(v));
        }
    }

    const size_t base = object.positions.size() / 3;
    if (base + vertexCount > size_t(std::numeric_limits<uint32_t>::max())) {
        fail(object, node, "more than 2^32 vertices");
        return false;
    }
    object.positions.reserve(object.positions.size() + p.size());
    const double* m = world.m;
    for (size_t v = 0; v < vertexCount; ++v) {
        const double x = p[3 * v], y = p[3 * v + 1], z = p[3 * v + 2];
        const double w[3] = {m[0] * x + m[4] * y + m[8] * z + m[12], m[1] * x + m[5] * y + m[9] * z + m[13],
                             m[2] * x + m[6] * y + m[10] * z + m[14]};
        // A non-finite coordinate in the data is reported per object later (NaN, inf); a
        // finite one that the node transforms (or the data itself) make too large is refused.
        if (std::isfinite(x) && std::isfinite(y) && std::isfinite(z)) {
            for (int c = 0; c < 3; ++c) {
                if (!(std::fabs(w[c]) <= kMaxCoordinate)) {
                    char text[64];
                    std::snprintf(text, sizeof text, "%.6g", w[c]);
                    fatal_ = "node " + std::to_string(node) + " '" + name(node) + "' " + where + ": vertex " +
                             std::to_string(v) + " lies at world coordinate " + text +
                             " (coordinates and transforms must keep every |coordinate| <= 1e15); refused";
                    return false;
                }
            }
        }
        object.positions.insert(object.positions.end(), w, w + 3);
    }
    object.indices.reserve(object.indices.size() + tri.size());
    for (size_t t = 0; t < tri.size(); t += 3) {
        object.indices.push_back(uint32_t(base) + tri[t]);
        object.indices.push_back(uint32_t(base) + tri[t + (flip ? 2 : 1)]);
        object.indices.push_back(uint32_t(base) + tri[t + (flip ? 1 : 2)]);
    }
    return true;
}

void SceneReader::addMeshOfNode(int node, const Mat4& world, ObjectBuilder& object) {
    const tinygltf::Node& n = model_.nodes[size_t(node)];
    if (n.mesh < 0) return;
    object.hadMesh = true;
    if (++meshInstances_ > kMaxMeshInstances) {
        fatal_ = "more than " + std::to_string(kMaxMeshInstances) + " mesh nodes (instances) in the scene, at node " +
                 std::to_string(node) + " '" + name(node) + "'; refused (limit of aggrelod)";
        return;
    }
    if (object.failed) return;
    if (size_t(n.mesh) >= model_.meshes.size()) {
        fail(object, node, "mesh " + std::to_string(n.mesh) + " does not exist (" +
                               std::to_string(model_.meshes.size()) + " meshes)");
        return;
    }
    if (n.skin >= 0 && options_.includeAnimated) {
        note(Severity::Note, object.name,
             "node " + std::to_string(node) + " '" + name(node) + "' is skinned; its bind pose is used");
    }
    const bool flip = determinant3(world) < 0;
    const tinygltf::Mesh& mesh = model_.meshes[size_t(n.mesh)];
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        if (!addPrimitive(node, n.mesh, int(p), world, flip, object)) return;
    }
}

bool SceneReader::run(std::vector<InputObject>& objects, std::string& error) {
    if (!options_.excludeRegex.empty()) {
        try {
            regex_ = std::regex(options_.excludeRegex, std::regex::ECMAScript);
            hasRegex_ = true;
        } catch (const std::regex_error& e) {
            error = "invalid --exclude regular expression '" + options_.excludeRegex +
                    "': " + e.what();
            return false;
        }
    }

    // File-level extension checks.
    for (const std::string& ext : model_.extensionsRequired) {
        if (isUnsupportedGeometryExtension(ext)) {
            note(Severity::Warning, "",
                 "the file requires extension " + ext +
                     ", which aggrelod cannot decode; geometry that uses it is skipped");
        } else if (!isSupportedGeometryExtension(ext)) {
            note(Severity::Note, "",
                 "the file requires extension " + ext +
                     "; ignored, since aggrelod reads geometry only");
        }
    }
    for (const std::string& ext : model_.extensionsUsed) {
        if (ext == "EXT_mesh_gpu_instancing" &&
            std::find(model_.extensionsRequired.begin(), model_.extensionsRequired.end(), ext) ==
                model_.extensionsRequired.end()) {
            note(Severity::Warning, "",
                 "the file uses EXT_mesh_gpu_instancing, which aggrelod does not read: "
                 "only one instance of each instanced mesh is taken");
        }
    }

    // Roots of the scene to read.
    std::vector<int> roots;
    const int nodeCount = int(std::min(model_.nodes.size(), size_t(std::numeric_limits<int>::max())));
    if (!model_.scenes.empty() && options_.allScenes) {
        // Every scene in order, each root once (a node may be a root of several scenes).
        std::vector<char> taken(size_t(nodeCount), 0);
        for (size_t s = 0; s < model_.scenes.size(); ++s)
            for (int r : model_.scenes[s].nodes) {
                if (r < 0 || r >= nodeCount) {
                    note(Severity::Warning, "",
                         "scene " + std::to_string(s) + " refers to node " + std::to_string(r) +
                             ", which does not exist; ignored");
                    continue;
                }
                if (!taken[size_t(r)]) roots.push_back(r);
                taken[size_t(r)] = 1;
            }
    } else if (!model_.scenes.empty()) {
        int scene = model_.defaultScene;
        if (scene < 0 || size_t(scene) >= model_.scenes.size()) {
            if (scene >= 0) {
                note(Severity::Warning, "",
                     "default scene " + std::to_string(scene) + " does not exist; scene 0 used");
            }
            scene = 0;
        }
        if (model_.scenes.size() > 1) {
            note(Severity::Note, "",
                 "the file has " + std::to_string(model_.scenes.size()) + " scenes; only scene " +
                     std::to_string(scene) + " is read");
        }
        for (int r : model_.scenes[size_t(scene)].nodes) {
            if (r < 0 || r >= nodeCount) {
                note(Severity::Warning, "",
                     "scene " + std::to_string(scene) + " refers to node " + std::to_string(r) +
                         ", which does not exist; ignored");
                continue;
            }
            roots.push_back(r);
        }
    } else {
        std::vector<char> isChild(size_t(nodeCount), 0);
        for (const auto& n : model_.nodes) {
            for (int c : n.children) {
                if (c >= 0 && c < nodeCount) isChild[size_t(c)] = 1;
            }
        }
        for (int i = 0; i < nodeCount; ++i) {
            if (!isChild[size_t(i)]) roots.push_back(i);
        }
        note(Severity::Note, "",
             "the file has no scene; all " + std::to_string(roots.size()) + " root nodes are read");
    }

    // Depth-first traversal with an explicit stack (no recursion: a crafted file may nest
    // nodes very deeply). Each node is visited at most once, even if the file (invalidly)
    // gives it several parents or a cycle.
    std::vector<ObjectBuilder> builders;
    std::vector<char> visited(size_t(nodeCount), 0);
    std::vector<std::string> excludedNames, excludedMeshes, animatedNames, cameraNames, lightNames;
    pathParent_.assign(size_t(nodeCount), kUnreached);
    pathPosition_.assign(size_t(nodeCount), 0);
    // Nodes an animation moves (their subtrees move with them).
    std::vector<char> animated(size_t(nodeCount), 0);
    for (const tinygltf::Animation& a : model_.animations)
        for (const tinygltf::AnimationChannel& c : a.channels)
            if (c.target_node >= 0 && c.target_node < nodeCount) animated[size_t(c.target_node)] = 1;
    // Depth whose nodes open one object gathering their subtree (-1: every mesh node is one).
    const int groupDepth = options_.objectDepth >= 0 ? options_.objectDepth
                           : options_.objectUnit == ObjectUnit::Subtree ? 1
                                                                       : -1;
    struct Item {
        int node;
        Mat4 parent;
        int group;  ///< builder index of the enclosing subtree object, -1 if none
        int depth;  ///< 0 for a scene root
        int parentNode;  ///< -1 for a scene root
        uint32_t position;  ///< among the parent's children (or the roots)
    };
    std::vector<Item> stack;
    for (size_t r = roots.size(); r-- > 0;) stack.push_back(Item{roots[r], Mat4{}, -1, 0, -1, uint32_t(r)});

    while (!stack.empty() && fatal_.empty()) {
        const Item item = stack.back();
        stack.pop_back();
        const int node = item.node;
        if (visited[size_t(node)]) {
            note(Severity::Warning, name(node),
                 "node " + std::to_string(node) +
                     " is reached more than once (invalid glTF: several parents or a cycle); "
                     "read only the first time");
            continue;
        }
        visited[size_t(node)] = 1;
        pathParent_[size_t(node)] = item.parentNode;
        pathPosition_[size_t(node)] = item.position;
        if (item.depth >= int(kMaxNodeDepth)) {
            fatal_ = "node " + std::to_string(node) + " '" + name(node) + "' lies deeper than " +
                     std::to_string(kMaxNodeDepth) + " levels in the node hierarchy; refused (limit of aggrelod)";
            break;
        }
        if (excluded(node)) {
            excludedNames.push_back(name(node));
            continue;
        }
        const tinygltf::Node& n = model_.nodes[size_t(node)];
        if (n.camera >= 0) cameraNames.push_back(name(node));
        if (n.extensions.count("KHR_lights_punctual")) lightNames.push_back(name(node));
        if (animated[size_t(node)] && !options_.includeAnimated) {
            animatedNames.push_back(name(node) + " (animated, with its subtree)");
            continue;
        }
        // A mesh left out on its own: by --exclude, or skinned (it deforms).
        bool useMesh = n.mesh >= 0;
        if (useMesh && meshExcluded(node)) {
            excludedMeshes.push_back(name(node));
            useMesh = false;
        } else if (useMesh && n.skin >= 0 && !options_.includeAnimated) {
            animatedNames.push_back(name(node) + " (skinned mesh)");
            useMesh = false;
        }
        std::string problem;
        const Mat4 world = multiply(item.parent, localTransform(n, problem));
        if (!problem.empty()) {
            note(Severity::Warning, name(node),
                 "node " + std::to_string(node) + ": " + problem);
        }

        int group = item.group;
        if (groupDepth < 0 || item.depth < groupDepth) {
            // A node above the assembly depth: its own mesh is an object by itself.
            if (useMesh) {
                builders.push_back(ObjectBuilder{});
                builders.back().name = name(node);
                builders.back().topNode = node;
                addMeshOfNode(node, world, builders.back());
            }
            group = -1;
        } else {
            // At the assembly depth a node opens an object gathering every mesh below it.
            if (item.depth == groupDepth) {
                builders.push_back(ObjectBuilder{});
                builders.back().name = name(node);
                builders.back().topNode = node;
                group = int(builders.size()) - 1;
            }
            if (useMesh) addMeshOfNode(node, world, builders[size_t(group)]);
        }

        for (auto c = n.children.rbegin(); c != n.children.rend(); ++c) {
            if (*c < 0 || *c >= nodeCount) {
                note(Severity::Warning, name(node),
                     "node " + std::to_string(node) + " has child " + std::to_string(*c) +
                         ", which does not exist; ignored");
                continue;
            }
            const size_t position = size_t(n.children.rend() - c) - 1;
            stack.push_back(Item{*c, world, group, item.depth + 1, node, uint32_t(position)});
        }
    }
    if (!fatal_.empty()) {
        error = fatal_;
        return false;
    }

    // One note per kind, each listing the nodes.
    const auto listNote = [&](const std::vector<std::string>& names, const std::string& what) {
        if (names.empty()) return;
        std::string list;
        const size_t shown = std::min<size_t>(names.size(), 20);
        for (size_t i = 0; i < shown; ++i) list += (i ? ", " : "") + names[i];
        if (names.size() > shown) list += ", ... (" + std::to_string(names.size()) + ")";
        note(Severity::Note, "", what + ": " + list);
    };
    listNote(animatedNames, "left out as animated or skinned (--include-animated bakes their rest pose)");
    listNote(excludedMeshes, "--exclude dropped the own mesh of these nodes, keeping their children");
    listNote(cameraNames, "cameras (not geometry; ignored)");
    listNote(lightNames, "lights (not geometry; ignored)");
    listNote(nonTriangle_, "primitives that are not triangles (points or lines; skipped)");

    if (hasRegex_) {
        std::string list;
        const size_t shown = std::min<size_t>(excludedNames.size(), 20);
        for (size_t i = 0; i < shown; ++i) list += (i ? ", " : "") + excludedNames[i];
        if (excludedNames.size() > shown) list += ", ...";
        note(Severity::Note, "",
             excludedNames.empty() && excludedMeshes.empty()
                 ? "--exclude '" + options_.excludeRegex + "' matched no node"
                 : excludedNames.empty()
                 ? "--exclude '" + options_.excludeRegex + "' matched no whole node"
                 : "excluded " + std::to_string(excludedNames.size()) + " node(s) matching '" +
                       options_.excludeRegex + "' with their subtrees: " + list);
    }

    // Keep the objects with triangles, in order of appearance; make names unique.
    std::vector<ObjectBuilder*> kept;
    for (ObjectBuilder& b : builders) {
        if (b.failed || !b.hadMesh) continue;
        if (b.indices.empty()) {
            note(Severity::Note, b.name,
                 "node " + std::to_string(b.topNode) + " has no triangles; not an object");
            continue;
        }
        kept.push_back(&b);
    }
    std::set<std::string> taken;
    for (const ObjectBuilder* b : kept) taken.insert(b->name);
    std::set<std::string> used;
    std::map<std::string, int> nextSuffix;  // per repeated name: the next "#k" to try (linear, not quadratic)
    objects.clear();
    objects.reserve(kept.size());
    objectNodes_.clear();
    for (ObjectBuilder* b : kept) {
        objectNodes_.push_back(b->topNode);
        std::string name = b->name;
        if (used.count(name)) {
            int& start = nextSuffix.emplace(b->name, 2).first->second;
            for (int& k = start;; ++k) {
                std::string candidate = b->name + "#" + std::to_string(k);
                if (!taken.count(candidate) && !used.count(candidate)) {
                    name = candidate;
                    break;
                }
            }
        }
        used.insert(name);
        InputObject obj;
        obj.name = std::move(name);
        obj.id = uint32_t(objects.size());
        obj.positions = std::move(b->positions);
        obj.indices = std::move(b->indices);
        // Triangle colours only when some triangle is not white (white is the default).
        b->colors.resize(4 * (obj.indices.size() / 3), 1.0f);
        if (std::any_of(b->colors.begin(), b->colors.end(), [](float c) { return c != 1.0f; }))
            obj.triangleColors = std::move(b->colors);
        objects.push_back(std::move(obj));
    }
    return true;
}

bool readWholeFile(const std::string& path, std::vector<unsigned char>& bytes, std::string& error) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        error = "is a directory, not a glTF file";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error = std::string("cannot open: ") + std::strerror(errno);
        return false;
    }
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) {
        error = "cannot read";
        return false;
    }
    if (uint64_t(size) >= uint64_t(std::numeric_limits<uint32_t>::max())) {
        error = "file is 4 GB or larger, which glTF loading does not support";
        return false;
    }
    in.seekg(0, std::ios::beg);
    // A few zero bytes past the end, so that nothing can read outside the allocation.
    bytes.assign(size_t(size) + 16, 0);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
        error = "read error";
        return false;
    }
    bytes.resize(size_t(size));
    return true;
}

uint32_t readLe32(const unsigned char* p) {
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}

/// Stricter GLB header check than tinygltf's; returns the declared total length.
bool checkGlbHeader(const std::vector<unsigned char>& b, uint32_t& length, std::string& error) {
    const size_t size = b.size();
    if (size < 20) {
        error = "truncated GLB: " + std::to_string(size) + " bytes, shorter than a GLB header";
        return false;
    }
    const uint32_t version = readLe32(&b[4]);
    length = readLe32(&b[8]);
    const uint32_t jsonLength = readLe32(&b[12]);
    const uint32_t jsonType = readLe32(&b[16]);
    if (version != 2) {
        error = "unsupported GLB version " + std::to_string(version) + " (only glTF 2.0 is read)";
        return false;
    }
    if (length > size) {
        error = "truncated GLB: header says " + std::to_string(length) + " bytes, file has " +
                std::to_string(size);
        return false;
    }
    if (jsonType != 0x4E4F534Au) {
        error = "invalid GLB: first chunk is not JSON";
        return false;
    }
    const uint64_t jsonEnd = 20ull + jsonLength;
    if (jsonLength == 0 || jsonEnd > length) {
        error = "truncated GLB: JSON chunk of " + std::to_string(jsonLength) +
                " bytes does not fit in " + std::to_string(length) + " bytes";
        return false;
    }
    if (jsonEnd < length) {
        if (jsonEnd + 8 > length) {
            error = "invalid GLB: incomplete chunk header after the JSON chunk";
            return false;
        }
        const uint32_t binLength = readLe32(&b[size_t(jsonEnd)]);
        const uint32_t binType = readLe32(&b[size_t(jsonEnd) + 4]);
        if (binType == 0x004E4942u && jsonEnd + 8 + binLength > length) {
            error = "truncated GLB: BIN chunk of " + std::to_string(binLength) +
                    " bytes does not fit in " + std::to_string(length) + " bytes";
            return false;
        }
    }
    return true;
}

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

/// One line, at most a few hundred characters (tinygltf may quote a whole data URI).
std::string tidyMessage(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
    for (char& c : s) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    const size_t maxLength = 300;
    if (s.size() > maxLength) s = s.substr(0, maxLength) + "...";
    return s;
}

// ---------------------------------------------------------------------------
// Limits and confinement: hostile structure is refused before tinygltf spends memory or
// stack on it (see docs/command-line.md, "Limits").

/// What a linear pass over the JSON text finds before the real parse.
struct JsonSummary {
    size_t nodeCount = 0;
    /// byteLength of every buffer whose uri names an external file, in buffer order
    /// (the order in which tinygltf loads them).
    std::vector<uint64_t> externalBufferLengths;
};

/// One pass over JSON text without recursion: refuses nesting deeper than kMaxJsonDepth and
/// more than kMaxNodes nodes, and collects the declared sizes of external buffers. Syntax
/// errors are left for tinygltf to report.
bool scanJson(const unsigned char* s, size_t n, JsonSummary& out, std::string& error) {
    struct Frame {
        bool object;
        bool expectKey;
        std::string key;     ///< current key (objects of depth <= 3 only)
        std::string uri;     ///< buffers[i].uri
        bool hasLength = false;
        uint64_t length = 0;
    };
    std::vector<Frame> stack;
    const auto inBufferElement = [&] {
        return stack.size() == 3 && stack[0].object && stack[0].key == "buffers" && !stack[1].object &&
               stack[2].object;
    };
    size_t i = 0;
    while (i < n) {
        const unsigned char c = s[i];
        if (c == '{' || c == '[') {
            if (stack.size() >= kMaxJsonDepth) {
                error = "JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels (at byte " +
                        std::to_string(i) + "); refused";
                return false;
            }
            if (stack.size() == 2 && stack[0].object && stack[0].key == "nodes" && !stack[1].object) {
                if (++out.nodeCount > kMaxNodes) {
                    error = "more than " + std::to_string(kMaxNodes) + " nodes; refused (limit of aggrelod)";
                    return false;
                }
            }
            stack.push_back(Frame{c == '{', c == '{', std::string(), std::string()});
            ++i;
        } else if (c == '}' || c == ']') {
            if (!stack.empty()) {
                if (inBufferElement() && stack[2].hasLength && !stack[2].uri.empty() &&
                    stack[2].uri.compare(0, 5, "data:") != 0)
                    out.externalBufferLengths.push_back(stack[2].length);
                stack.pop_back();
            }
            ++i;
        } else if (c == '"') {
            const size_t start = ++i;
            while (i < n && s[i] != '"') i += s[i] == '\\' ? 2 : 1;
            const size_t end = std::min(i, n);
            ++i;
            if (stack.empty()) continue;
            Frame& f = stack.back();
            if (f.object && f.expectKey) {
                if (stack.size() <= 3) f.key.assign(reinterpret_cast<const char*>(s + start), end - start);
            } else if (inBufferElement() && f.key == "uri") {
                f.uri.assign(reinterpret_cast<const char*>(s + start), std::min<size_t>(end - start, 16));
            }
        } else if (c == ':') {
            if (!stack.empty()) stack.back().expectKey = false;
            ++i;
        } else if (c == ',') {
            if (!stack.empty() && stack.back().object) stack.back().expectKey = true;
            ++i;
        } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
            ++i;
        } else {
            const size_t start = i;
            while (i < n && s[i] != ',' && s[i] != '}' && s[i] != ']' && s[i] != ' ' && s[i] != '\n' &&
                   s[i] != '\r' && s[i] != '\t')
                ++i;
            if (inBufferElement() && stack[2].key == "byteLength") {
                const std::string number(reinterpret_cast<const char*>(s + start), i - start);
                char* endp = nullptr;
                const double v = std::strtod(number.c_str(), &endp);
                if (endp && *endp == '\0' && v >= 0 && v < 1.8e19) {
                    stack[2].hasLength = true;
                    stack[2].length = uint64_t(v);
                }
            }
        }
    }
    return true;
}

/// Largest external file read (as the main file: glTF loading stays below 4 GiB).
constexpr uint64_t kMaxExternalFileBytes = uint64_t(std::numeric_limits<uint32_t>::max()) - 1;

/// File access handed to tinygltf: external files must be regular files inside the input's
/// folder (unless allowed), of exactly their buffer's declared size, checked before reading;
/// external images are never read (only geometry is baked).
struct ExternalFiles {
    std::filesystem::path folder;  ///< canonical folder of the input, ends with a separator
    bool allowOutside = false;
    std::vector<uint64_t> bufferLengths;  ///< JsonSummary::externalBufferLengths
    size_t calls = 0;
    size_t imagesSkipped = 0;
    std::string refusal;  ///< why a buffer's file was refused: the error, instead of tinygltf's
    std::vector<std::string> read;  ///< canonical paths of the buffer files read
};

const char* const kImageNotRead = "external image not read (only geometry is baked)";

bool externalFileExists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::exists(std::filesystem::symlink_status(path, ec));
}

std::string expandNothing(const std::string& path, void*) { return path; }

bool writeNothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is not used";
    return false;
}

bool readExternalFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    ExternalFiles& files = *static_cast<ExternalFiles*>(user);
    const size_t call = files.calls++;
    if (call >= files.bufferLengths.size()) {
        ++files.imagesSkipped;
        if (err) *err += kImageNotRead;
        return false;
    }
    const auto refuse = [&](const std::string& why) {
        if (err) *err += why;
        if (files.refusal.empty()) files.refusal = "external buffer file " + path + ": " + why;
        return false;
    };
    std::error_code ec;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
    if (ec) return refuse("cannot resolve: " + ec.message());
    if (!files.allowOutside) {
        const std::string folder = files.folder.string(), file = canonical.string();
        if (file.compare(0, folder.size(), folder) != 0)
            return refuse("refused: the uri leads outside the input's folder (--allow-external-uris allows it): " +
                          file + " is not under " + folder);
    }
    // The descriptor is checked, not the name, so that what is checked is what is read.
    const int fd = ::open(canonical.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) return refuse(std::string("cannot open: ") + std::strerror(errno));
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) return refuse(std::string("cannot stat: ") + std::strerror(errno));
    if (S_ISDIR(st.st_mode)) return refuse("refused: the uri names a directory, not a file");
    if (!S_ISREG(st.st_mode)) return refuse("refused: the uri names a device, pipe or socket, not a regular file");
    const uint64_t size = uint64_t(st.st_size);
    const uint64_t declared = files.bufferLengths[call];
    if (size > kMaxExternalFileBytes) return refuse("refused: file of " + std::to_string(size) + " bytes is 4 GiB or larger");
    if (size != declared)
        return refuse("refused: file has " + std::to_string(size) + " bytes, its buffer declares byteLength " +
                      std::to_string(declared));
    out->resize(size_t(size));
    size_t done = 0;
    while (done < size) {
        const ssize_t got = ::pread(fd, out->data() + done, size_t(size) - done, off_t(done));
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) return refuse(std::string("read error: ") + (got < 0 ? std::strerror(errno) : "file shrank"));
        done += size_t(got);
    }
    files.read.push_back(canonical.string());
    return true;
}

bool loadModel(const std::string& path, tinygltf::Model& model, std::vector<Diagnostic>& diags,
               std::string& error, bool allowExternalUris = false, std::vector<std::string>* externalFiles = nullptr) {
    std::vector<unsigned char> bytes;
    if (!readWholeFile(path, bytes, error)) return false;
    const bool magicGlb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    const std::string ext = lowerExtension(path);
    if (ext == ".glb" && !magicGlb) {
        error = bytes.size() < 4 ? "truncated GLB: " + std::to_string(bytes.size()) + " bytes"
                                 : "not a GLB file (no 'glTF' magic bytes)";
        return false;
    }
    std::string baseDir = std::filesystem::path(path).parent_path().string();
    if (baseDir.empty()) baseDir = ".";

    uint32_t glbLength = 0;
    if (magicGlb && !checkGlbHeader(bytes, glbLength, error)) return false;
    JsonSummary summary;
    if (!scanJson(bytes.data() + (magicGlb ? 20 : 0), magicGlb ? size_t(readLe32(&bytes[12])) : bytes.size(),
                  summary, error))
        return false;
    ExternalFiles files;
    std::error_code ec;
    files.folder = std::filesystem::weakly_canonical(std::filesystem::absolute(baseDir, ec), ec);
    if (ec) {
        error = "cannot resolve the input's folder: " + ec.message();
        return false;
    }
    files.folder /= "";  // trailing separator: "/in" must not admit "/inside"
    files.allowOutside = allowExternalUris;
    files.bufferLengths = summary.externalBufferLengths;

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&acceptImageWithoutDecoding, nullptr);
    loader.SetFsCallbacks(tinygltf::FsCallbacks{&externalFileExists, &expandNothing, &readExternalFile,
                                                &writeNothing, &files});
    std::string err, warn;
    bool ok = false;
    try {
        if (magicGlb) {
            ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), glbLength, baseDir);
        } else {
            if (bytes.empty()) {
                error = "empty file";
                return false;
            }
            ok = loader.LoadASCIIFromString(&model, &err, &warn,
                                            reinterpret_cast<const char*>(bytes.data()),
                                            unsigned(bytes.size()), baseDir);
        }
    } catch (const std::bad_alloc&) {
        error = "out of memory while parsing";
        return false;
    } catch (const std::exception& e) {
        error = std::string("invalid glTF: ") + e.what();
        return false;
    } catch (...) {
        error = "invalid glTF (the glTF parser failed)";
        return false;
    }
    if (!ok && !files.refusal.empty()) {
        error = files.refusal;
        return false;
    }
    if (!ok) {
        err = tidyMessage(err);
        error = "invalid glTF: " + (err.empty() ? std::string("the glTF parser failed") : err);
        return false;
    }
    if (!err.empty()) {
        diags.push_back(Diagnostic{Severity::Warning, "", "glTF loader: " + tidyMessage(err)});
    }
    // tinygltf's warnings are about images and other non-geometry data: kept as notes.
    std::istringstream lines(warn);
    std::string line;
    while (std::getline(lines, line)) {
        // External images are left unread on purpose: one note below instead of two lines each.
        if (line.find(kImageNotRead) != std::string::npos || line.find("Failed to load external 'uri' for image[") != std::string::npos)
            continue;
        line = tidyMessage(line);
        if (!line.empty()) diags.push_back(Diagnostic{Severity::Note, "", "glTF loader: " + line});
    }
    if (files.imagesSkipped)
        diags.push_back(Diagnostic{Severity::Note, "",
                                   std::to_string(files.imagesSkipped) +
                                       " external image file(s) not read: only geometry is baked"});
    if (externalFiles) *externalFiles = files.read;
    return true;
}

// ---------------------------------------------------------------------------
// Writing.

/// Builds one GLB model; meshes share one buffer, one buffer view per accessor.
class GlbBuilder {
public:
    GlbBuilder() {
        model_.asset.version = "2.0";
        model_.asset.generator = "aggrelod";
    }

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
        const bool coloured = faceColors && faceColors->size() == 4 * (indicesIn.size() / 3) &&
                              indicesIn.size() % 3 == 0;
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
        RenderMesh render;
        if (renderAttributes) {
            if (!buildRenderMesh(positions, indices, coloured ? *faceColors : std::vector<float>(), render))
                throw std::runtime_error(name + ": a triangle index is out of range");
        } else {
            render.positions = std::move(positions);
            render.indices = std::move(indices);
        }
        const size_t vertexCount = render.positions.size() / 3;
        std::vector<float> colours(4 * vertexCount, 1.0f);
        if (coloured)
            for (size_t c = 0; c < render.indices.size(); ++c)
                std::copy_n(&(*faceColors)[4 * (c / 3)], 4, &colours[4 * size_t(render.indices[c])]);

        // min/max (required for POSITION) over the finite values of each component.
        double lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
        bool any[3] = {false, false, false};
        for (size_t v = 0; v < vertexCount; ++v) {
            for (size_t c = 0; c < 3; ++c) {
                const float f = render.positions[3 * v + c];
                if (!std::isfinite(f)) continue;
                const double x = double(f);
                if (!any[c] || x < lo[c]) lo[c] = x;
                if (!any[c] || x > hi[c]) hi[c] = x;
                any[c] = true;
            }
        }

        tinygltf::Primitive prim;
        {
            tinygltf::Accessor pos;
            pos.bufferView = addView(render.positions.data(), render.positions.size() * sizeof(float),
                                     TINYGLTF_TARGET_ARRAY_BUFFER);
            pos.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
            pos.type = TINYGLTF_TYPE_VEC3;
            pos.count = vertexCount;
            pos.minValues.assign(lo, lo + 3);
            pos.maxValues.assign(hi, hi + 3);
            model_.accessors.push_back(std::move(pos));
            prim.attributes["POSITION"] = int(model_.accessors.size()) - 1;
        }
        if (renderAttributes) {
            tinygltf::Accessor normal;
            normal.bufferView = addView(render.normals.data(), render.normals.size() * sizeof(float),
                                        TINYGLTF_TARGET_ARRAY_BUFFER);
            normal.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
            normal.type = TINYGLTF_TYPE_VEC3;
            normal.count = vertexCount;
            model_.accessors.push_back(std::move(normal));
            prim.attributes["NORMAL"] = int(model_.accessors.size()) - 1;
        }
        if (renderAttributes || coloured) {
            tinygltf::Accessor col;
            col.bufferView = addView(colours.data(), colours.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
            col.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
            col.type = TINYGLTF_TYPE_VEC4;
            col.count = vertexCount;
            model_.accessors.push_back(std::move(col));
            prim.attributes["COLOR_0"] = int(model_.accessors.size()) - 1;
        }
        {
            tinygltf::Accessor idx;
            idx.bufferView = addView(render.indices.data(), render.indices.size() * sizeof(uint32_t),
                                     TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
            idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
            idx.type = TINYGLTF_TYPE_SCALAR;
            idx.count = render.indices.size();
            model_.accessors.push_back(std::move(idx));
            prim.indices = int(model_.accessors.size()) - 1;
        }
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        prim.material = material;
        tinygltf::Mesh mesh;
        mesh.name = name;
        mesh.primitives.push_back(std::move(prim));
        model_.meshes.push_back(std::move(mesh));
        return int(model_.meshes.size()) - 1;
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
        tinygltf::Primitive prim;
        tinygltf::Accessor pos;
        pos.bufferView = addView(positions.data(), positions.size() * sizeof(float), TINYGLTF_TARGET_ARRAY_BUFFER);
        pos.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
        pos.type = TINYGLTF_TYPE_VEC3;
        pos.count = vertexCount;
        pos.minValues.assign(lo, lo + 3);
        pos.maxValues.assign(hi, hi + 3);
        model_.accessors.push_back(std::move(pos));
        prim.attributes["POSITION"] = int(model_.accessors.size()) - 1;
        tinygltf::Accessor idx;
        idx.bufferView = addView(indices.data(), indices.size() * sizeof(uint32_t), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        idx.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        idx.type = TINYGLTF_TYPE_SCALAR;
        idx.count = indices.size();
        model_.accessors.push_back(std::move(idx));
        prim.indices = int(model_.accessors.size()) - 1;
        prim.mode = TINYGLTF_MODE_TRIANGLES;
        tinygltf::Mesh mesh;
        mesh.name = name;
        mesh.primitives.push_back(std::move(prim));
        model_.meshes.push_back(std::move(mesh));
        return int(model_.meshes.size()) - 1;
    }

    int addNode(tinygltf::Node node) {
        model_.nodes.push_back(std::move(node));
        return int(model_.nodes.size()) - 1;
    }

    tinygltf::Model& model() { return model_; }

    bool write(const std::string& path, const std::vector<int>& sceneRoots, std::string& error) {
        return writeScenes(path, {{std::string(), sceneRoots}}, error);
    }

    /// Writes the model with these scenes (name, root nodes); the first is the default scene.
    bool writeScenes(const std::string& path, const std::vector<std::pair<std::string, std::vector<int>>>& scenes,
                     std::string& error) {
        for (const auto& [name, roots] : scenes) {
            tinygltf::Scene scene;
            scene.name = name;
            scene.nodes = roots;
            model_.scenes.push_back(std::move(scene));
        }
        model_.defaultScene = 0;
        if (!bin_.empty()) {
            tinygltf::Buffer buffer;
            buffer.data = std::move(bin_);
            model_.buffers.push_back(std::move(buffer));
        }
        std::ofstream out(path, std::ios::binary | std::ios::trunc);
        if (!out) {
            error = path + ": cannot create: " + std::strerror(errno);
            return false;
        }
        tinygltf::TinyGLTF writer;
        bool ok = false;
        try {
            ok = writer.WriteGltfSceneToStream(&model_, out, false, true);
        } catch (const std::exception& e) {
            error = path + ": cannot write glTF: " + e.what();
            return false;
        }
        out.close();
        if (!ok || !out) {
            error = path + ": write error (disk full?)";
            return false;
        }
        return true;
    }

private:
    int addView(const void* data, size_t bytes, int target) {
        while (bin_.size() % 4) bin_.push_back(0);
        tinygltf::BufferView view;
        view.buffer = 0;
        view.byteOffset = bin_.size();
        view.byteLength = bytes;
        view.target = target;
        const auto* b = static_cast<const unsigned char*>(data);
        bin_.insert(bin_.end(), b, b + bytes);
        model_.bufferViews.push_back(std::move(view));
        return int(model_.bufferViews.size()) - 1;
    }

    tinygltf::Model model_;
    std::vector<unsigned char> bin_;
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

bool readGltfScene(const std::string& path, const SceneReadOptions& options,
                   SceneReadResult& out, std::string& error) {
    out.objects.clear();
    out.diagnostics.clear();
    error.clear();
    try {
        tinygltf::Model model;
        out.externalFiles.clear();
        if (!loadModel(path, model, out.diagnostics, error, options.allowExternalUris, &out.externalFiles)) {
            error = path + ": " + error;
            return false;
        }
        SceneReader reader(model, options, out.diagnostics);
        if (!reader.run(out.objects, error)) {
            error = path + ": " + error;
            return false;
        }
        return true;
    } catch (const std::bad_alloc&) {
        error = path + ": out of memory while reading the scene";
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
    }
    out.objects.clear();
    return false;
}

bool readLevelsGlb(const std::string& path, std::vector<LevelsGlbNode>& out, std::string& error) {
    out.clear();
    error.clear();
    try {
        tinygltf::Model model;
        std::vector<Diagnostic> diagnostics;
        if (!loadModel(path, model, diagnostics, error)) {
            error = path + ": " + error;
            return false;
        }
        // Geometry through the scene reader (one object per mesh node, world space, checked
        // accessors); the extras of the node with the same (unique) name give level and group.
        SceneReadOptions options;
        options.objectUnit = ObjectUnit::Node;
        options.allScenes = true;  // one scene per level
        std::vector<InputObject> objects;
        SceneReader reader(model, options, diagnostics);
        if (!reader.run(objects, error)) {
            error = path + ": " + error;
            return false;
        }
        std::map<std::string, int> nodeByName;
        for (size_t i = 0; i < model.nodes.size(); ++i)
            if (model.nodes[i].mesh >= 0) nodeByName.emplace(displayName(model, int(i)), int(i));
        auto number = [](const tinygltf::Value& extras, const char* key, double& value) {
            if (!extras.IsObject() || !extras.Has(key)) return false;
            const tinygltf::Value& v = extras.Get(key);
            if (!v.IsNumber()) return false;
            value = v.GetNumberAsDouble();
            return std::isfinite(value);
        };
        for (InputObject& object : objects) {
            const auto found = nodeByName.find(object.name);
            if (found == nodeByName.end()) {
                error = path + ": node '" + object.name + "' has a duplicate name: not a levels.glb of aggrelod";
                return false;
            }
            const tinygltf::Value& extras = model.nodes[size_t(found->second)].extras;
            if (extras.IsObject() && extras.Has("support")) continue;  // a support surface passed through
            double level = 0, group = 0, delta = 0;
            if (!number(extras, "level", level) || level < 0 || level > 1e6 || level != std::floor(level)) {
                error = path + ": node '" + object.name +
                        "' has no integer extras.level: not a levels.glb written by aggrelod bake";
                return false;
            }
            number(extras, "group", group);
            number(extras, "delta", delta);
            LevelsGlbNode node;
            node.name = object.name;
            node.level = uint32_t(level);
            node.group = group >= 0 && group < 4e9 ? uint32_t(group) : 0;
            node.delta = delta;
            node.sourceCount = extras.IsObject() && extras.Has("sources") && extras.Get("sources").IsArray()
                                   ? uint32_t(extras.Get("sources").ArrayLen())
                                   : 0;
            node.positions = std::move(object.positions);
            node.indices = std::move(object.indices);
            out.push_back(std::move(node));
        }
        if (out.empty()) {
            error = path + ": no mesh nodes: not a levels.glb written by aggrelod bake";
            return false;
        }
        return true;
    } catch (const std::bad_alloc&) {
        error = path + ": out of memory while reading the levels";
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
    }
    out.clear();
    return false;
}

bool readProxiesGlb(const std::string& path, std::vector<ProxiesGlbNode>& out, std::string& error) {
    out.clear();
    error.clear();
    try {
        tinygltf::Model model;
        std::vector<Diagnostic> diagnostics;
        if (!loadModel(path, model, diagnostics, error)) {
            error = path + ": " + error;
            return false;
        }
        const size_t count = model.nodes.size();
        out.resize(count);
        auto integer = [](const tinygltf::Value& object, const char* key, int& value) {
            if (!object.IsObject() || !object.Has(key) || !object.Get(key).IsNumber()) return;
            const double v = object.Get(key).GetNumberAsDouble();
            if (v >= -1 && v < 2147483647.0 && v == std::floor(v)) value = int(v);
        };
        for (size_t i = 0; i < count; ++i) {
            const tinygltf::Node& n = model.nodes[i];
            ProxiesGlbNode& p = out[i];
            p.name = n.name;
            p.gltfNode = int(i);
            integer(n.extras, "node", p.node);
            integer(n.extras, "lod", p.lod);
            integer(n.extras, "children_of", p.childrenOf);
            p.leaf = n.extras.IsObject() && n.extras.Has("leaf");
            if (n.extras.IsObject() && n.extras.Has("MSFT_screencoverage") && n.extras.Get("MSFT_screencoverage").IsArray()) {
                const tinygltf::Value& a = n.extras.Get("MSFT_screencoverage");
                for (size_t k = 0; k < a.ArrayLen(); ++k)
                    if (a.Get(int(k)).IsNumber()) p.screenCoverage.push_back(a.Get(int(k)).GetNumberAsDouble());
            }
            const auto lod = n.extensions.find("MSFT_lod");
            if (lod != n.extensions.end() && lod->second.IsObject() && lod->second.Has("ids") && lod->second.Get("ids").IsArray()) {
                const tinygltf::Value& a = lod->second.Get("ids");
                for (size_t k = 0; k < a.ArrayLen(); ++k)
                    if (a.Get(int(k)).IsNumber()) p.lodIds.push_back(int(a.Get(int(k)).GetNumberAsDouble()));
            }
            for (int c : n.children)
                if (c >= 0 && size_t(c) < count) p.children.push_back(c);
            if (n.mesh >= 0 && size_t(n.mesh) < model.meshes.size()) {
                p.hasNormals = p.hasColors = !model.meshes[size_t(n.mesh)].primitives.empty();
                for (const tinygltf::Primitive& prim : model.meshes[size_t(n.mesh)].primitives) {
                    p.hasNormals = p.hasNormals && prim.attributes.count("NORMAL");
                    p.hasColors = p.hasColors && prim.attributes.count("COLOR_0");
                }
            }
        }
        // Nodes reached from the default scene.
        if (!model.scenes.empty()) {
            const size_t scene = model.defaultScene >= 0 && size_t(model.defaultScene) < model.scenes.size() ? size_t(model.defaultScene) : 0;
            std::vector<int> stack(model.scenes[scene].nodes.begin(), model.scenes[scene].nodes.end());
            while (!stack.empty()) {
                const int n = stack.back();
                stack.pop_back();
                if (n < 0 || size_t(n) >= count || out[size_t(n)].inDefaultScene) continue;
                out[size_t(n)].inDefaultScene = true;
                for (int c : out[size_t(n)].children) stack.push_back(c);
            }
        }
        // Geometry, world space, through the checked scene reader over every scene.
        SceneReadOptions options;
        options.objectUnit = ObjectUnit::Node;
        options.allScenes = true;
        std::vector<InputObject> objects;
        SceneReader reader(model, options, diagnostics);
        if (!reader.run(objects, error)) {
            error = path + ": " + error;
            return false;
        }
        for (size_t o = 0; o < objects.size(); ++o) {
            const int n = reader.objectNodes()[o];
            if (n < 0 || size_t(n) >= count) continue;
            out[size_t(n)].positions = std::move(objects[o].positions);
            out[size_t(n)].indices = std::move(objects[o].indices);
            out[size_t(n)].triangleColors = std::move(objects[o].triangleColors);
        }
        return true;
    } catch (const std::bad_alloc&) {
        error = path + ": out of memory while reading the proxies";
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
    }
    out.clear();
    return false;
}

bool writeObjectsGlb(const std::vector<InputObject>& objects, const std::string& path,
                     std::string& error) {
    try {
        GlbBuilder glb;
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
                    const std::string& path, std::string& error, const HierarchyNodes* nodes) {
    if (nodes && (nodes->nodeOfAggregate.size() != hierarchy.levels.size() || nodes->objectCount != objects.size())) {
        error = path + ": the hierarchy nodes do not belong to this hierarchy";
        return false;
    }
    try {
        GlbBuilder glb;
        tinygltf::Model& model = glb.model();
        std::vector<int> roots;
        const size_t levelCount = hierarchy.levels.size();
        bool anyColours = false;
        for (const Level& level : hierarchy.levels)
            for (const Aggregate& agg : level.aggregates) anyColours = anyColours || !agg.faceColors.empty();
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
                const Aggregate& agg = level.aggregates[g];
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
                node.mesh = glb.addMesh(name, agg.positions, agg.indices, materialIndex, &agg.faceColors);
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
                    extras["proxy_triangles"] = intValue(hn.indices.size() / 3);
                }
                node.extras = tinygltf::Value(std::move(extras));
                children.push_back(glb.addNode(std::move(node)));
            }
            model.nodes[size_t(levelIndex)].children = std::move(children);
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
            }
            model.nodes[size_t(supportIndex)].children = std::move(children);
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
            setMsftLod(model, model.nodes[size_t(roots[0])], ids, radius, errors, nodes != nullptr);
        }
        return glb.writeScenes(path, scenes, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

bool writeProxiesGlb(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     const std::string& path, std::string& error) {
    if (nodes.objectCount != objects.size() || nodes.nodes.size() < objects.size()) {
        error = path + ": the hierarchy nodes do not belong to these objects";
        return false;
    }
    try {
        GlbBuilder glb;
        tinygltf::Model& model = glb.model();
        int levelCount = 0;
        bool anyColours = false;
        for (const HierarchyNode& n : nodes.nodes) {
            levelCount = std::max(levelCount, n.lastLevel + 1);
            anyColours = anyColours || !n.faceColors.empty();
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
                                     : std::max(nodes.nodes[aggregateBelow(nodes, uint32_t(i))].firstLevel, 0);
            const std::vector<double> positions(n.positions.begin(), n.positions.end());
            node.mesh = glb.addMesh(name, positions, n.indices, material, &n.faceColors);
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
            else model.nodes[size_t(p.parentLod0)].children.push_back(lod0);
            std::vector<int> ids;
            std::vector<double> errors;
            size_t lod = 1;
            for (size_t c = chain.size() - (b.leaf ? 1 : 0); c-- > 0;) {
                const uint32_t i = chain[c];
                const int standIn = meshNode(i, stem + "_LOD" + std::to_string(lod), lod);
                ++lod;
                ids.push_back(standIn);
                errors.push_back(nodes.nodes[i].geometricError);
                standInRoots.push_back(standIn);
            }
            setMsftLod(model, model.nodes[size_t(lod0)], ids, nodes.nodes[p.top].sphereRadius, errors, true);
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
        GlbBuilder glb;
        tinygltf::Model& model = glb.model();
        tinygltf::Value::Array omiShapes;
        // Static colliders: no motion. Each collider node carries its own mesh and names it as
        // KHR geometry (geometry.node = itself), and the same mesh as an OMI_physics_shape.
        auto colliderNode = [&](const std::string& name, const std::vector<float>& positions,
                                const std::vector<uint32_t>& indices, bool convex, tinygltf::Value::Object extras) {
            tinygltf::Node node;
            node.name = name;
            node.mesh = glb.addPlainMesh(name, positions, indices);
            const int index = int(model.nodes.size());
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
            if (n.indices.empty()) continue;
            const std::string stem = n.leaf ? objects[i].name : "node" + std::to_string(i);
            trimeshOf[i] = colliderNode(stem + "_collider", n.positions, n.indices, false, commonExtras(i));
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
            model.nodes[size_t(groupIndex)].children = std::move(children);
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
        GlbBuilder glb;
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
        if (model.meshes.empty()) model.materials.clear();  // nothing drawn: no unused material
        return glb.write(path, std::vector<int>{root}, error);
    } catch (const std::exception& e) {
        error = path + ": " + e.what();
        return false;
    }
}

}  // namespace aggrelod::io
