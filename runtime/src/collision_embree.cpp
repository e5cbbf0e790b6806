// Collision queries with Embree 3 (DESIGN section 3): the only file that includes Embree.
// Pitfalls handled here (NOTES-deps): ray mask 0xFFFFFFFF (a zeroed ray never hits),
// tnear/tfar/flags/geomID set explicitly, an error callback on the device, vertex buffers
// allocated by Embree (rtcSetNewGeometryBuffer pads them for its 16-byte SIMD loads),
// occlusion reported by rtcOccluded1 setting tfar to -inf.
#include <aggrelod/collision.h>
#include <aggrelod/selection.h>

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

namespace aggrelod::runtime {

void cutAtLevel(const RuntimeFile& file, uint32_t level, std::vector<uint32_t>& out) {
    out.clear();
    // Leaves are finer than level 0: rank(leaf) = -1, rank(inner) = its level.
    auto rank = [&](uint32_t node) -> int64_t {
        return file.isLeaf(node) ? -1 : int64_t(file.node(node).level);
    };
    const int64_t wanted = level == kLeafLevel ? -1 : int64_t(level);
    std::vector<uint32_t> stack(file.roots().begin(), file.roots().end());
    while (!stack.empty()) {
        const uint32_t x = stack.back();
        stack.pop_back();
        if (rank(x) <= wanted || file.isLeaf(x)) {
            out.push_back(x);
        } else {
            for (uint32_t c : file.children(x)) stack.push_back(c);
        }
    }
    std::sort(out.begin(), out.end());
}

std::vector<uint32_t> levelsOf(const RuntimeFile& file) {
    std::vector<uint32_t> levels;
    for (uint32_t i = 0; i < file.nodeCount(); ++i)
        if (!file.isLeaf(i)) levels.push_back(file.node(i).level);
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    return levels;
}

struct CollisionWorld::Impl {
    const RuntimeFile& file;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::vector<RTCGeometry> geometries;  // per node, created on first use
    std::vector<uint8_t> enabled;
    std::vector<uint32_t> cut;
    std::unique_ptr<Selector> distanceSelector;
    mutable std::mutex errorMutex;
    std::string lastError;
    bool failed = false;

    static void onError(void* user, RTCError code, const char* text) {
        auto* self = static_cast<Impl*>(user);
        std::lock_guard<std::mutex> lock(self->errorMutex);
        self->lastError = "Embree error " + std::to_string(int(code)) + ": " + (text ? text : "");
        self->failed = true;
    }

    Impl(const RuntimeFile& f, unsigned threads) : file(f) {
        const std::string config = threads ? "threads=" + std::to_string(threads) : std::string();
        device = rtcNewDevice(config.empty() ? nullptr : config.c_str());
        if (!device) {
            failed = true;
            lastError = "Embree device creation failed (error " + std::to_string(int(rtcGetDeviceError(nullptr))) + ")";
            return;
        }
        rtcSetDeviceErrorFunction(device, &Impl::onError, this);
        scene = rtcNewScene(device);
        geometries.assign(file.nodeCount(), nullptr);
        enabled.assign(file.nodeCount(), 0);
        if (scene) rtcCommitScene(scene);
    }
    ~Impl() {
        for (RTCGeometry g : geometries)
            if (g) rtcReleaseGeometry(g);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    // Copies a node's mesh into Embree-owned (padded) buffers; nullptr for an empty mesh.
    RTCGeometry makeGeometry(uint32_t node) {
        const Span<float> v = file.vertices(node);
        const Span<uint32_t> t = file.triangles(node);
        if (t.size == 0 || v.size == 0) return nullptr;
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        if (!g) return nullptr;
        auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), v.size / 3));
        auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                  3 * sizeof(uint32_t), t.size / 3));
        if (!vb || !ib) {
            rtcReleaseGeometry(g);
            return nullptr;
        }
        std::memcpy(vb, v.data, v.size * sizeof(float));
        std::memcpy(ib, t.data, t.size * sizeof(uint32_t));
        rtcCommitGeometry(g);
        rtcAttachGeometryByID(scene, g, node);  // geomID == node index
        rtcDisableGeometry(g);
        return g;
    }

    void setCut(std::vector<uint32_t> nodes) {
        if (!scene) return;
        std::sort(nodes.begin(), nodes.end());
        nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
        while (!nodes.empty() && nodes.back() >= file.nodeCount()) nodes.pop_back();
        for (uint32_t n : cut)
            if (geometries[n] && !std::binary_search(nodes.begin(), nodes.end(), n)) {
                rtcDisableGeometry(geometries[n]);
                enabled[n] = 0;
            }
        for (uint32_t n : nodes) {
            if (!geometries[n]) geometries[n] = makeGeometry(n);
            if (geometries[n] && !enabled[n]) {
                rtcEnableGeometry(geometries[n]);
                enabled[n] = 1;
            }
        }
        cut = std::move(nodes);
        rtcCommitScene(scene);
    }

    bool intersect(const float o[3], const float d[3], float maxDistance, CollisionHit& hit) const {
        if (!scene || failed) return false;
        const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0) || !(maxDistance >= 0)) return false;
        RTCRayHit rh;
        rh.ray.org_x = o[0]; rh.ray.org_y = o[1]; rh.ray.org_z = o[2];
        rh.ray.dir_x = d[0] / len; rh.ray.dir_y = d[1] / len; rh.ray.dir_z = d[2] / len;
        rh.ray.tnear = 0.0f;
        rh.ray.tfar = maxDistance;
        rh.ray.time = 0.0f;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcIntersect1(scene, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
        hit.distance = rh.ray.tfar;
        hit.node = rh.hit.geomID;
        hit.triangle = rh.hit.primID;
        hit.objects = file.sources(hit.node);
        // Normal from the stored triangle (outward by winding), not Embree's Ng convention.
        const Span<float> v = file.vertices(hit.node);
        const Span<uint32_t> t = file.triangles(hit.node);
        const float* a = &v[3 * t[3 * hit.triangle]];
        const float* b = &v[3 * t[3 * hit.triangle + 1]];
        const float* c = &v[3 * t[3 * hit.triangle + 2]];
        const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
        const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                             e1[0] * e2[1] - e1[1] * e2[0]};
        const double nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k) hit.normal[k] = nl > 0 ? float(n[k] / nl) : 0.0f;
        return true;
    }

    bool occluded(const float o[3], const float d[3], float maxDistance) const {
        if (!scene || failed) return false;
        const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(len > 0) || !(maxDistance >= 0)) return false;
        RTCRay ray;
        ray.org_x = o[0]; ray.org_y = o[1]; ray.org_z = o[2];
        ray.dir_x = d[0] / len; ray.dir_y = d[1] / len; ray.dir_z = d[2] / len;
        ray.tnear = 0.0f;
        ray.tfar = maxDistance;
        ray.time = 0.0f;
        ray.mask = 0xFFFFFFFFu;
        ray.id = 0;
        ray.flags = 0;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcOccluded1(scene, &context, &ray);
        return ray.tfar == -std::numeric_limits<float>::infinity();
    }
};

CollisionWorld::CollisionWorld(const RuntimeFile& file, unsigned buildThreads)
    : impl_(std::make_unique<Impl>(file, buildThreads)) {}
CollisionWorld::~CollisionWorld() = default;

bool CollisionWorld::ok() const { return !impl_->failed; }
std::string CollisionWorld::error() const {
    std::lock_guard<std::mutex> lock(impl_->errorMutex);
    return impl_->lastError;
}

void CollisionWorld::useCut(const uint32_t* nodes, size_t count) {
    impl_->setCut(std::vector<uint32_t>(nodes, nodes + count));
}
void CollisionWorld::useLevel(uint32_t level) {
    std::vector<uint32_t> nodes;
    cutAtLevel(impl_->file, level, nodes);
    impl_->setCut(std::move(nodes));
}
void CollisionWorld::useDistanceCut(const float point[3], float maxErrorPerDistance) {
    if (!impl_->distanceSelector) impl_->distanceSelector = std::make_unique<Selector>(impl_->file);
    impl_->distanceSelector->selectByDistance(point, maxErrorPerDistance);
    const Span<uint32_t> cut = impl_->distanceSelector->cut();
    impl_->setCut(std::vector<uint32_t>(cut.begin(), cut.end()));
}
const std::vector<uint32_t>& CollisionWorld::currentCut() const { return impl_->cut; }

bool CollisionWorld::raycast(const float origin[3], const float direction[3], float maxDistance,
                             CollisionHit& hit) const {
    return impl_->intersect(origin, direction, maxDistance, hit);
}
bool CollisionWorld::segment(const float a[3], const float b[3], CollisionHit& hit) const {
    const float d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    return impl_->intersect(a, d, std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), hit);
}
bool CollisionWorld::occluded(const float origin[3], const float direction[3], float maxDistance) const {
    return impl_->occluded(origin, direction, maxDistance);
}

}  // namespace aggrelod::runtime
