// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: reading glTF scenes (readGltfScene) and reading back the bake's own
// levels.glb and proxies.glb. Geometry and base colours only. Images are never decoded;
// of the materials only baseColorFactor is read (times the mean COLOR_0 of each triangle's
// corners when present; base colour textures are ignored with a note); unknown extensions
// are ignored; every accessor and buffer view is range-checked here before a byte is read,
// and a bad object is skipped with a diagnostic so that the rest of the scene can still be
// baked. Loading and the limits on hostile files: gltf_load.cpp.
#include "gltf_load.h"
#include "scene_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <limits>
#include <map>
#include <new>
#include <regex>
#include <set>
#include <utility>


namespace aggrelod::io {
namespace {

using Severity = Diagnostic::Severity;
using namespace gltf;


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
    object.colors.reserve(object.colors.size() + 4 * (tri.size() / 3));  // no doubling slack kept for the bake
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

}  // namespace aggrelod::io
