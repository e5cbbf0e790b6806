// SPDX-License-Identifier: AGPL-3.0-or-later
// The tests' one ray caster (Embree 3): a scene of triangle meshes and instances of other
// scenes, first hit (distance, mesh, triangle), every hit along a ray, and an inside test by
// ray parity. Independent of the runtime's collision part, which the tests check against it.
#pragma once

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

namespace aggrelod::testing {

/// One Embree device; scenes made on it keep it alive (shared_ptr).
class RayDevice {
public:
    RayDevice() : device_(rtcNewDevice(nullptr)) {}
    ~RayDevice() { rtcReleaseDevice(device_); }
    RayDevice(const RayDevice&) = delete;
    RayDevice& operator=(const RayDevice&) = delete;
    RTCDevice handle() const { return device_; }

private:
    RTCDevice device_;
};

/// First hit of a ray: distance along the (not necessarily unit) direction, in multiples of
/// it; the mesh is the id addMesh/addInstance returned, the triangle its index in that mesh.
struct RayHit {
    static constexpr uint32_t kNone = 0xFFFFFFFFu;
    float t = INFINITY;
    uint32_t mesh = kNone;
    uint32_t triangle = kNone;
    bool hit() const { return mesh != kNone; }
};

class RayScene {
public:
    /// A scene on a device of its own.
    RayScene() : RayScene(std::make_shared<RayDevice>()) {}
    /// A scene on a shared device (many small scenes: one device).
    explicit RayScene(std::shared_ptr<RayDevice> device)
        : device_(std::move(device)), scene_(rtcNewScene(device_->handle())) {
        // Watertight intersection: without it a ray can slip through the shared edge of two
        // triangles of a closed mesh and report a hit on its far side.
        rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    }
    ~RayScene() { rtcReleaseScene(scene_); }
    RayScene(const RayScene&) = delete;
    RayScene& operator=(const RayScene&) = delete;

    /// Adds one mesh: positions 3 per vertex (world units), indices 3 per triangle. Returns its
    /// id, counted from 0 in the order of addMesh/addInstance calls; an empty mesh gets an id
    /// too and is never hit.
    template <typename Real>
    uint32_t addMesh(const Real* positions, size_t vertexCount, const uint32_t* indices, size_t triangleCount) {
        if (triangleCount == 0) return attach(nullptr);
        RTCGeometry g = rtcNewGeometry(device_->handle(), RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                              3 * sizeof(float), vertexCount));
        for (size_t i = 0; i < 3 * vertexCount; ++i) v[i] = float(positions[i]);
        auto* ix = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                  3 * sizeof(uint32_t), triangleCount));
        std::copy(indices, indices + 3 * triangleCount, ix);
        // Every-hit queries go through this filter; first-hit queries leave it at once.
        rtcSetGeometryIntersectFilterFunction(g, collectEveryHit);
        return attach(g);
    }
    template <typename Real>
    uint32_t addMesh(const std::vector<Real>& positions, const std::vector<uint32_t>& indices) {
        return addMesh(positions.data(), positions.size() / 3, indices.data(), indices.size() / 3);
    }

    /// Adds `part` (committed, on the same device, outliving this scene) with the identity
    /// transform; its hits report the instance's id and the triangle within the part's mesh.
    uint32_t addInstance(const RayScene& part) {
        RTCGeometry g = rtcNewGeometry(device_->handle(), RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, part.scene_);
        const float identity[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, identity);
        return attach(g);
    }

    void commit() { rtcCommitScene(scene_); }

    /// First hit along o + t d, t >= 0.
    RayHit first(const double o[3], const double d[3]) const {
        Context context;
        RTCRayHit rh = ray(o, d);
        rtcIntersect1(scene_, &context.base, &rh);
        RayHit h;
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return h;
        const unsigned top = rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
        h.t = rh.ray.tfar;
        h.mesh = top < meshOfGeometry_.size() ? meshOfGeometry_[top] : RayHit::kNone;
        h.triangle = rh.hit.primID;
        return h;
    }

    /// Every hit distance along o + t d, t >= 0, unsorted.
    void every(const double o[3], const double d[3], std::vector<float>& distances) const {
        Context context;
        context.hits = &distances;
        RTCRayHit rh = ray(o, d);
        rtcIntersect1(scene_, &context.base, &rh);
    }

    /// Inside a closed mesh by ray parity: majority over three fixed, oblique directions; hits
    /// at (nearly) equal distances (a ray through an edge) count once.
    bool insideByParity(const double p[3], double mergeDistance) const {
        static const double kDirections[3][3] = {
            {0.5383, 0.6221, 0.5686}, {-0.7071, 0.3162, -0.6325}, {0.2673, -0.8018, 0.5345}};
        int inside = 0;
        std::vector<float> hits;
        for (const auto& d : kDirections) {
            hits.clear();
            every(p, d, hits);
            std::sort(hits.begin(), hits.end());
            int crossings = 0;
            for (size_t i = 0; i < hits.size(); ++i)
                if (i == 0 || hits[i] - hits[i - 1] > mergeDistance) ++crossings;
            inside += crossings % 2;
        }
        return inside >= 2;
    }

private:
    struct Context {
        RTCIntersectContext base;             // first member: Embree hands this pointer to the filter
        std::vector<float>* hits = nullptr;   // non-null: collect every hit distance and go on
        Context() { rtcInitIntersectContext(&base); }
    };

    static void collectEveryHit(const RTCFilterFunctionNArguments* args) {
        const Context* context = reinterpret_cast<const Context*>(args->context);
        if (!context->hits) return;
        context->hits->push_back(RTCRayN_tfar(args->ray, args->N, 0));
        args->valid[0] = 0;
    }

    static RTCRayHit ray(const double o[3], const double d[3]) {
        RTCRayHit rh{};
        rh.ray.org_x = float(o[0]);
        rh.ray.org_y = float(o[1]);
        rh.ray.org_z = float(o[2]);
        rh.ray.dir_x = float(d[0]);
        rh.ray.dir_y = float(d[1]);
        rh.ray.dir_z = float(d[2]);
        rh.ray.tnear = 0;
        rh.ray.tfar = INFINITY;
        rh.ray.mask = 0xFFFFFFFFu;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        return rh;
    }

    uint32_t attach(RTCGeometry g) {
        const uint32_t id = meshes_++;
        if (!g) return id;
        rtcCommitGeometry(g);
        const unsigned geometry = rtcAttachGeometry(scene_, g);
        rtcReleaseGeometry(g);
        if (meshOfGeometry_.size() <= geometry) meshOfGeometry_.resize(geometry + 1, RayHit::kNone);
        meshOfGeometry_[geometry] = id;
        return id;
    }

    std::shared_ptr<RayDevice> device_;
    RTCScene scene_;
    uint32_t meshes_ = 0;
    std::vector<uint32_t> meshOfGeometry_;
};

}  // namespace aggrelod::testing
