// SPDX-License-Identifier: MIT
// Collision queries with Embree 3 (docs/design.md §3): the only file that includes Embree.
// Pitfalls handled here (docs/design.md §6): ray mask 0xFFFFFFFF (a zeroed ray never hits),
// tnear/tfar/flags/geomID set explicitly, an error callback on the device, vertex buffers
// allocated by Embree (rtcSetNewGeometryBuffer pads them for its 16-byte SIMD loads),
// occlusion reported by rtcOccluded1 setting tfar to -inf.
#include <aggrelod/collision.h>
#include <aggrelod/selection.h>

#include "triangle_distance.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>

namespace aggrelod::runtime {

namespace {
/// Embree asserts (and aborts the process) on ray coordinates beyond about 1.8e18 and on
/// non-finite ones: such rays are refused here (no hit).
bool rayInRange(const float o[3], const float d[3], float maxDistance) {
    constexpr float kLimit = 1e18f;
    for (int k = 0; k < 3; ++k)
        if (!(std::fabs(o[k]) <= kLimit) || !(std::fabs(d[k]) <= kLimit)) return false;
    return maxDistance >= 0;  // +inf allowed, NaN not
}

/// Whether bundle `node` of level k stands for its level-k aggregate: that aggregate gave way
/// to the bundles of a group above (the bundle's parent is neither a bundle of level k nor an
/// aggregate of level k). A root bundle (the bundles of a bake's several roots) stands for
/// none.
bool bundleStandsForItsAggregate(const RuntimeFile& file, uint32_t node) {
    const uint32_t level = file.node(node).level;
    const uint32_t parent = file.node(node).parent;
    if (parent == kNoIndex) return false;
    const uint32_t above = file.node(parent).level;
    return !(above == level || above == (level & ~kBundleLevelFlag));
}
}  // namespace

void cutAtLevel(const RuntimeFile& file, uint32_t level, std::vector<uint32_t>& out) {
    out.clear();
    // Leaves are finest, then the per-object LODs, then level 0: rank(leaf) = -2,
    // rank(object LOD) = -1, rank(aggregate) = its level. A bake puts every object in a
    // level-0 aggregate, above its per-object LOD chain; should a chain hang directly below
    // a coarser aggregate, a cut at k >= 0 still passes through it to the leaf.
    auto rankOf = [](uint32_t l) -> int64_t {
        return l == kLeafLevel ? -2 : l == kObjectLodLevel ? -1 : int64_t(l);
    };
    const int64_t wanted = rankOf(level);
    auto rank = [&](uint32_t node) -> int64_t {
        if (file.isLeaf(node)) return -2;
        if (file.isObjectLod(node)) return wanted == -1 ? -1 : std::numeric_limits<int64_t>::max();
        if (file.isBundle(node) && bundleStandsForItsAggregate(file, node))
            return rankOf(file.node(node).level & ~kBundleLevelFlag);
        if (file.isCoarser(node) || file.isBundle(node)) return std::numeric_limits<int64_t>::max();  // passed through
        return rankOf(file.node(node).level);
    };
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
    for (uint32_t i = 0; i < file.nodeCount(); ++i) {
        if (file.isBundle(i) && bundleStandsForItsAggregate(file, i)) levels.push_back(file.node(i).level & ~kBundleLevelFlag);
        if (!file.isLeaf(i) && !file.isObjectLod(i) && !file.isCoarser(i) && !file.isBundle(i))
            levels.push_back(file.node(i).level);
    }
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    return levels;
}

struct CollisionWorld::Impl {
    const RuntimeFile& file;
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    RTCGeometry geometry = nullptr;       // all triangles of the cut, merged
    std::vector<uint32_t> cut;            // nodes, increasing
    // A hit is mapped back with two lookups (each likely a cache miss on big scenes):
    struct TriangleRef {
        uint32_t slot;   // position of the node in `cut`
        uint32_t local;  // triangle within the node's mesh
    };
    struct SlotInfo {
        const uint32_t* objects;
        uint32_t objectCount;
        uint32_t node;
    };
    std::vector<TriangleRef> triangleRefs;  // per merged triangle
    std::vector<SlotInfo> slots;            // per cut node
    std::unique_ptr<Selector> distanceSelector;
    mutable std::mutex errorMutex;
    std::string lastError;
    bool failed = false;
    bool committed = false;  // queries before the first cut find nothing
    const float* vertexData = nullptr;    // merged mesh (Embree's buffers), for distance queries
    const uint32_t* indexData = nullptr;

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
        // Watertight ray/triangle tests: in the fast default mode a ray through the shared
        // edge or corner of two triangles can miss both and pass through a closed proxy,
        // which breaks the promise that nothing reaches an original without touching it.
        if (scene) rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    }
    ~Impl() {
        if (geometry) rtcReleaseGeometry(geometry);
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }

    // One Embree geometry holding every triangle of the cut: Embree rebuilds the scene BVH on
    // each commit anyway, so per-node geometries bought nothing but bookkeeping.
    void setCut(std::vector<uint32_t> nodes) {
        if (!scene) return;
        std::sort(nodes.begin(), nodes.end());
        nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
        while (!nodes.empty() && nodes.back() >= file.nodeCount()) nodes.pop_back();
        if (geometry) {
            rtcDetachGeometry(scene, 0);
            rtcReleaseGeometry(geometry);
            geometry = nullptr;
        }
        cut = std::move(nodes);
        triangleRefs.clear();
        slots.clear();
        vertexData = nullptr;
        indexData = nullptr;
        size_t vertexTotal = 0;
        for (uint32_t slot = 0; slot < cut.size(); ++slot) {
            const uint32_t n = cut[slot];
            const Span<uint32_t> objects = file.sources(n);
            slots.push_back({objects.data, uint32_t(objects.size), n});
            vertexTotal += file.vertices(n).size / 3;
            const uint32_t triangles = uint32_t(file.triangles(n).size / 3);
            for (uint32_t t = 0; t < triangles; ++t) triangleRefs.push_back({slot, t});
        }
        const size_t triangleTotal = triangleRefs.size();
        if (triangleTotal > 0) {
            geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
            auto* vb = geometry ? static_cast<float*>(rtcSetNewGeometryBuffer(
                                      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), vertexTotal))
                                : nullptr;
            auto* ib = geometry ? static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
                                      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), triangleTotal))
                                : nullptr;
            if (!vb || !ib) {
                if (geometry) rtcReleaseGeometry(geometry);
                geometry = nullptr;
            } else {
                size_t v = 0, t = 0;
                for (uint32_t n : cut) {
                    const Span<float> verts = file.vertices(n);
                    const Span<uint32_t> tris = file.triangles(n);
                    std::memcpy(vb + 3 * v, verts.data, verts.size * sizeof(float));
                    for (size_t k = 0; k < tris.size; ++k) ib[t + k] = tris[k] + uint32_t(v);
                    v += verts.size / 3;
                    t += tris.size;
                }
                rtcCommitGeometry(geometry);
                rtcAttachGeometryByID(scene, geometry, 0);
                vertexData = vb;
                indexData = ib;
            }
        }
        rtcCommitScene(scene);
        committed = true;
    }

    bool intersect(const float o[3], const float d[3], float maxDistance, CollisionHit& hit) const {
        if (!scene || failed || !committed) return false;
        if (!rayInRange(o, d, maxDistance)) return false;
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
        const TriangleRef ref = triangleRefs[rh.hit.primID];
        const SlotInfo& info = slots[ref.slot];
        hit.distance = rh.ray.tfar;
        hit.node = info.node;
        hit.triangle = ref.local;
        hit.objects = {info.objects, info.objectCount};
        // Embree's unnormalised geometric normal points to the side from which the triangle's
        // vertices run counter-clockwise (checked by RuntimeCollision.*): outward for our meshes.
        const float n[3] = {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z};
        const float nl = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int k = 0; k < 3; ++k) hit.normal[k] = nl > 0 ? n[k] / nl : 0.0f;
        return true;
    }

    // Sphere / capsule overlap: an Embree point query around the shape's bounding sphere visits
    // every triangle whose box meets it; the callback measures the exact distance and, on the
    // first triangle within reach, shrinks the query to nothing so the traversal ends.
    struct TouchQuery {
        const Impl* self;
        distance::V3 a, b;  // segment (a == b for a sphere)
        double radius2;
        bool found;
    };
    static bool touchCallback(RTCPointQueryFunctionArguments* args) {
        auto* q = static_cast<TouchQuery*>(args->userPtr);
        if (q->found) return false;
        const uint32_t* t = q->self->indexData + 3 * size_t(args->primID);
        auto vertex = [&](uint32_t i) {
            const float* v = q->self->vertexData + 3 * size_t(i);
            return distance::V3{v[0], v[1], v[2]};
        };
        const distance::V3 a = vertex(t[0]), b = vertex(t[1]), c = vertex(t[2]);
        const double d2 = distance::segmentTriangleDistance2(q->a, q->b, a, b, c);
        if (d2 <= q->radius2) {
            q->found = true;
            args->query->radius = 0.0f;
            return true;
        }
        return false;
    }
    bool touches(const float a[3], const float b[3], float radius) const {
        if (!scene || failed || !committed || !vertexData || !(radius >= 0)) return false;
        TouchQuery q{this, {a[0], a[1], a[2]}, {b[0], b[1], b[2]}, double(radius) * double(radius), false};
        const double half = 0.5 * std::sqrt(distance::length2(q.b - q.a));
        RTCPointQuery query;
        query.x = float(0.5 * (q.a.x + q.b.x));
        query.y = float(0.5 * (q.a.y + q.b.y));
        query.z = float(0.5 * (q.a.z + q.b.z));
        query.time = 0.0f;
        // Float rounding of the centre is covered by a relative margin on the reach.
        const double reach = half + radius;
        query.radius = float(reach * (1.0 + 1e-5) + 1e-6);
        RTCPointQueryContext context;
        rtcInitPointQueryContext(&context);
        rtcPointQuery(scene, &query, &context, &Impl::touchCallback, &q);
        return q.found;
    }

    bool occluded(const float o[3], const float d[3], float maxDistance) const {
        if (!scene || failed || !committed) return false;
        if (!rayInRange(o, d, maxDistance)) return false;
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
bool CollisionWorld::sphereTouches(const float center[3], float radius) const {
    return impl_->touches(center, center, radius);
}
bool CollisionWorld::capsuleTouches(const float a[3], const float b[3], float radius) const {
    return impl_->touches(a, b, radius);
}

}  // namespace aggrelod::runtime
