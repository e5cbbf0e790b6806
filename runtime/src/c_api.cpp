// SPDX-License-Identifier: MIT
// C API of the runtime (aggrelod_runtime.h): file and selection. Thin wrappers over
// RuntimeFile and Selector; no exception crosses the C boundary.
#include <aggrelod_runtime.h>

#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include "c_api_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <new>

using namespace aggrelod::runtime;

struct aglod_selector {
    Selector selector;
    explicit aglod_selector(const RuntimeFile& f) : selector(f) {}
};

namespace aggrelod::runtime::capi {
std::string& lastError() {
    thread_local std::string message;
    return message;
}
aglod_status failWith(aglod_status status, const std::string& message) {
    lastError() = message;
    return status;
}
}  // namespace aggrelod::runtime::capi

using aggrelod::runtime::capi::failWith;
using aggrelod::runtime::capi::inRange;

namespace {
// A per-vertex attribute of a node (`components` values per vertex) as a view into the file.
template <class T>
int nodeAttribute(const aglod_file* file, uint32_t node, aggrelod::runtime::Span<T> (RuntimeFile::*get)(uint32_t) const,
                         size_t components, const T** data, uint32_t* vertex_count) {
    if (data) *data = nullptr;
    if (vertex_count) *vertex_count = 0;
    if (!file || node >= file->file.nodeCount()) return 0;
    const aggrelod::runtime::Span<T> values = (file->file.*get)(node);
    if (data) *data = values.data;
    if (vertex_count) *vertex_count = static_cast<uint32_t>(values.size / components);
    return 1;
}
}  // namespace

extern "C" {

const char* aglod_status_string(aglod_status status) {
    switch (status) {
        case AGLOD_INVALID_ARGUMENT: return "invalid argument";
        case AGLOD_COLLISION_ERROR: return "collision error";
        default:
            if (status >= AGLOD_OK && status <= AGLOD_UNSUPPORTED_HOST) return toString(FileStatus(status));
            return "unknown status";
    }
}

const char* aglod_last_error(void) { return aggrelod::runtime::capi::lastError().c_str(); }

static aglod_status finishOpen(FileStatus status, const std::string& message, RuntimeFile&& file,
                               aglod_file** out) {
    if (status != FileStatus::Ok) return failWith(aglod_status(status), message);
    *out = new (std::nothrow) aglod_file{std::move(file)};
    if (!*out) return failWith(AGLOD_IO_ERROR, "out of memory");
    return AGLOD_OK;
}

aglod_status aglod_open_file(const char* path, aglod_file** out) {
    if (!out) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_open_file: out is NULL");
    *out = nullptr;
    if (!path) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_open_file: path is NULL");
    try {
        RuntimeFile file;
        std::string message;
        const FileStatus status = RuntimeFile::openFile(path, file, message);
        return finishOpen(status, message, std::move(file), out);
    } catch (const std::exception& e) {
        return failWith(AGLOD_IO_ERROR, e.what());
    }
}

aglod_status aglod_open_memory(const void* data, size_t size, aglod_file** out) {
    if (!out) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_open_memory: out is NULL");
    *out = nullptr;
    try {
        RuntimeFile file;
        std::string message;
        const FileStatus status = RuntimeFile::openMemory(data, size, file, message);
        return finishOpen(status, message, std::move(file), out);
    } catch (const std::exception& e) {
        return failWith(AGLOD_IO_ERROR, e.what());
    }
}

void aglod_close(aglod_file* file) { delete file; }

uint32_t aglod_node_count(const aglod_file* file) { return file ? file->file.nodeCount() : 0; }
uint32_t aglod_object_count(const aglod_file* file) { return file ? file->file.objectCount() : 0; }

uint32_t aglod_node_level(const aglod_file* file, uint32_t node) {
    if (!file || node >= file->file.nodeCount()) return AGLOD_NO_INDEX;
    return file->file.node(node).level;
}

float aglod_node_error(const aglod_file* file, uint32_t node) {
    if (!file || node >= file->file.nodeCount()) return -1.0f;
    return file->file.node(node).geometricError;
}

int aglod_node_bounds(const aglod_file* file, uint32_t node, float min[3], float max[3]) {
    if (!file || !min || !max || node >= file->file.nodeCount()) return 0;
    const NodeRecord& r = file->file.node(node);
    for (int k = 0; k < 3; ++k) {
        min[k] = r.boundsMin[k];
        max[k] = r.boundsMax[k];
    }
    return 1;
}

int aglod_node_mesh(const aglod_file* file, uint32_t node, const float** positions, uint32_t* vertex_count,
                    const uint32_t** indices, uint32_t* index_count) {
    if (positions) *positions = nullptr;
    if (vertex_count) *vertex_count = 0;
    if (indices) *indices = nullptr;
    if (index_count) *index_count = 0;
    if (!file || node >= file->file.nodeCount()) return 0;
    const aggrelod::runtime::Span<float> v = file->file.vertices(node);
    const aggrelod::runtime::Span<uint32_t> t = file->file.triangles(node);
    if (positions) *positions = v.data;
    if (vertex_count) *vertex_count = static_cast<uint32_t>(v.size / 3);
    if (indices) *indices = t.data;
    if (index_count) *index_count = static_cast<uint32_t>(t.size);
    return 1;
}

int aglod_node_normals(const aglod_file* file, uint32_t node, const float** normals, uint32_t* vertex_count) {
    return nodeAttribute(file, node, &RuntimeFile::normals, 3, normals, vertex_count);
}

int aglod_node_colors(const aglod_file* file, uint32_t node, const uint8_t** colors, uint32_t* vertex_count) {
    return nodeAttribute(file, node, &RuntimeFile::colors, 4, colors, vertex_count);
}

void aglod_color_to_linear(const uint8_t rgba[4], float linear[4]) {
    if (!rgba || !linear) return;
    decodeColorSrgb8(rgba, linear);
}

int aglod_scene_bounds(const aglod_file* file, float min[3], float max[3]) {
    if (!file || !min || !max) return 0;
    for (int k = 0; k < 3; ++k) {
        min[k] = 3.4e38f;
        max[k] = -3.4e38f;
    }
    // The originals' boxes: coarse versions near the roots may reach well beyond them.
    const RuntimeFile& f = file->file;
    for (uint32_t i = 0; i < f.nodeCount(); ++i) {
        if (!f.isLeaf(i)) continue;
        const NodeRecord& r = f.node(i);
        if (!(r.boundsMin[0] <= r.boundsMax[0] && r.boundsMin[1] <= r.boundsMax[1] && r.boundsMin[2] <= r.boundsMax[2]))
            continue;  // an object without geometry
        for (int k = 0; k < 3; ++k) {
            min[k] = std::min(min[k], r.boundsMin[k]);
            max[k] = std::max(max[k], r.boundsMax[k]);
        }
    }
    if (min[0] > max[0])  // no leaf with a box: the roots'
        for (uint32_t root : f.roots()) {
            const NodeRecord& r = f.node(root);
            for (int k = 0; k < 3; ++k) {
                min[k] = std::min(min[k], r.boundsMin[k]);
                max[k] = std::max(max[k], r.boundsMax[k]);
            }
        }
    return 1;
}

size_t aglod_object_name(const aglod_file* file, uint32_t object, char* buffer, size_t capacity) {
    if (!file || object >= file->file.objectCount()) return 0;
    const std::string_view name = file->file.objectName(object);
    if (buffer && capacity > 0) {
        const size_t n = std::min(name.size(), capacity - 1);
        std::memcpy(buffer, name.data(), n);
        buffer[n] = '\0';
    }
    return name.size();
}

aglod_selector* aglod_selector_create(const aglod_file* file) {
    if (!file) {
        failWith(AGLOD_INVALID_ARGUMENT, "aglod_selector_create: file is NULL");
        return nullptr;
    }
    try {
        return new aglod_selector(file->file);
    } catch (const std::exception& e) {
        failWith(AGLOD_IO_ERROR, e.what());
        return nullptr;
    }
}

void aglod_selector_destroy(aglod_selector* selector) { delete selector; }

aglod_status aglod_selector_set_draw_costs(aglod_selector* selector, const uint32_t* original_triangles,
                                           float triangles_per_draw_call) {
    if (!selector) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_selector_set_draw_costs: selector is NULL");
    if (!(triangles_per_draw_call >= 0.0f) || !std::isfinite(triangles_per_draw_call))
        return failWith(AGLOD_INVALID_ARGUMENT,
                        "aglod_selector_set_draw_costs: triangles_per_draw_call must be finite and >= 0");
    selector->selector.setDrawCosts(original_triangles, triangles_per_draw_call);
    return AGLOD_OK;
}

static bool validSelection(const char* function, const float position[3], float pixel_tolerance,
                           float coarsen_ratio, float fov_y, float viewport_height) {
    if (!inRange(position, 3)) {
        failWith(AGLOD_INVALID_ARGUMENT, std::string(function) + ": camera position must be finite, within 1e18");
        return false;
    }
    if (pixel_tolerance > 0 && std::isfinite(pixel_tolerance) && coarsen_ratio > 0 && coarsen_ratio <= 1 &&
        fov_y > 0 && fov_y < 3.14159f && viewport_height > 0 && std::isfinite(viewport_height))
        return true;
    failWith(AGLOD_INVALID_ARGUMENT, std::string(function) +
                                         ": need finite pixel_tolerance > 0, coarsen_ratio in (0,1], fov_y in (0,pi), "
                                         "finite viewport_height > 0");
    return false;
}

static void fillCut(const Selector& s, aglod_cut* out) {
    *out = {s.cut().data, uint32_t(s.cut().size), s.proxyNodes().data, uint32_t(s.proxyNodes().size),
            s.originalObjects().data, uint32_t(s.originalObjects().size)};
}

aglod_status aglod_select(aglod_selector* selector, const aglod_camera* camera, float pixel_tolerance,
                          float coarsen_ratio, aglod_cut* out) {
    if (!selector || !camera || !out) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_select: NULL argument");
    if (!validSelection("aglod_select", camera->position, pixel_tolerance, coarsen_ratio, camera->fov_y,
                        camera->viewport_height))
        return AGLOD_INVALID_ARGUMENT;
    Camera c;
    std::memcpy(c.position, camera->position, sizeof(c.position));
    c.fovY = camera->fov_y;
    c.viewportHeight = camera->viewport_height;
    selector->selector.select(c, SelectionSettings{pixel_tolerance, coarsen_ratio});
    fillCut(selector->selector, out);
    return AGLOD_OK;
}

aglod_status aglod_select_view(aglod_selector* selector, const aglod_view_camera* camera, float pixel_tolerance,
                               float coarsen_ratio, aglod_cut* out) {
    if (!selector || !camera || !out) return failWith(AGLOD_INVALID_ARGUMENT, "aglod_select_view: NULL argument");
    if (!validSelection("aglod_select_view", camera->position, pixel_tolerance, coarsen_ratio, camera->fov_y,
                        camera->viewport_height))
        return AGLOD_INVALID_ARGUMENT;
    const float* f = camera->forward;
    const float* u = camera->up;
    const double fl = std::sqrt(double(f[0]) * f[0] + double(f[1]) * f[1] + double(f[2]) * f[2]);
    const double ul = std::sqrt(double(u[0]) * u[0] + double(u[1]) * u[1] + double(u[2]) * u[2]);
    const double cx = double(f[1]) * u[2] - double(f[2]) * u[1], cy = double(f[2]) * u[0] - double(f[0]) * u[2],
                 cz = double(f[0]) * u[1] - double(f[1]) * u[0];
    const double sine = std::sqrt(cx * cx + cy * cy + cz * cz) / (fl * ul);
    const float far = camera->far_distance == 0.0f ? INFINITY : camera->far_distance;
    if (!inRange(f, 3) || !inRange(u, 3) || !(fl > 0) || !std::isfinite(fl) || !(ul > 0) || !std::isfinite(ul) ||
        !(sine > 1e-6) || !(camera->aspect > 0) || !std::isfinite(camera->aspect) ||
        !(camera->near_distance >= 0) || !std::isfinite(camera->near_distance) || !(far > camera->near_distance))
        return failWith(AGLOD_INVALID_ARGUMENT,
                        "aglod_select_view: need a finite non-zero forward, up not parallel to it, aspect > 0, "
                        "near_distance >= 0 and far_distance > near_distance (0 = none)");
    ViewCamera c;
    std::memcpy(c.position, camera->position, sizeof(c.position));
    c.fovY = camera->fov_y;
    c.viewportHeight = camera->viewport_height;
    std::memcpy(c.forward, camera->forward, sizeof(c.forward));
    std::memcpy(c.up, camera->up, sizeof(c.up));
    c.aspect = camera->aspect;
    c.nearDistance = camera->near_distance;
    c.farDistance = far;
    selector->selector.select(c, SelectionSettings{pixel_tolerance, coarsen_ratio});
    fillCut(selector->selector, out);
    return AGLOD_OK;
}

const uint32_t* aglod_culled_nodes(const aglod_selector* selector, uint32_t* count) {
    if (count) *count = 0;
    if (!selector || !count) return nullptr;
    const Span<uint32_t> culled = selector->selector.culledNodes();
    *count = uint32_t(culled.size);
    return culled.data;
}

int aglod_selector_changes(const aglod_selector* selector, aglod_cut_changes* out) {
    if (!selector || !out) return 0;
    const Selector& s = selector->selector;
    *out = {s.entered().data, uint32_t(s.entered().size), s.left().data, uint32_t(s.left().size)};
    return 1;
}

}  // extern "C"
