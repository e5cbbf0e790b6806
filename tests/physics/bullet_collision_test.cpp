// SPDX-License-Identifier: AGPL-3.0-or-later
// collision.glb in a real physics engine: Bullet 3 (Debian libbullet-dev).
//
// Two sample scenes are baked with `aggrelod bake --collision`; collision.glb passes the
// Khronos validator, is read back with tinygltf (the colliders of each scene through
// KHR_physics_rigid_bodies, checked against OMI_physics_body / OMI_physics_shape) and every
// scene (each cut, as triangle meshes and with convex decompositions) is loaded into Bullet as
// static bodies: btBvhTriangleMeshShape for triangle meshes, btConvexHullShape for convex
// parts. Then, per scene:
//  a) rays (btCollisionWorld::rayTest) and swept spheres (convexSweepTest) agree with the
//     runtime's Embree answers on the same cut (CollisionWorld::raycast, sphereTouches,
//     capsuleTouches): triangle meshes give the same hit (node and distance, float
//     rounding); convex parts are hit no later than the proxies and within the node's error
//     of them;
//  b) spheres dropped from above the scene onto every object (Bullet rigid bodies, 1/240 s
//     steps) never pass through a collider: the centre of a sphere never crosses a collision
//     surface (triangle meshes: the runtime's segment query on the same triangles; convex
//     parts: the segment clipped by the hull's planes).
#include "test_support.h"

#include <aggrelod/collision.h>
#include <aggrelod/runtime_file.h>

#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>
#include <tiny_gltf.h>

#include <chrono>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <set>

namespace {

using namespace aggrelod;
using namespace aggrelod::testing;
namespace rt = aggrelod::runtime;

// ---------------------------------------------------------------------------------------
// Reading collision.glb

struct Collider {
    uint32_t node = 0;   ///< hierarchy node (extras.node)
    bool convex = false; ///< KHR geometry.convexHull
    std::vector<float> positions;
    std::vector<uint32_t> indices;
};

struct ColliderScene {
    std::string name;  ///< "level2", "level2_convex", ...
    std::vector<Collider> colliders;
};

struct CollisionFile {
    std::vector<ColliderScene> scenes;
    int defaultScene = -1;
    std::vector<std::string> extensionsUsed;
    std::string problem;  ///< empty when read and consistent
};

const unsigned char* accessorData(const tinygltf::Model& m, int index, int type, size_t elementSize, size_t& count,
                                  size_t& stride, std::string& why) {
    if (index < 0 || size_t(index) >= m.accessors.size()) {
        why = "accessor " + std::to_string(index) + " missing";
        return nullptr;
    }
    const tinygltf::Accessor& a = m.accessors[size_t(index)];
    if (a.type != type || a.sparse.isSparse || a.bufferView < 0 || size_t(a.bufferView) >= m.bufferViews.size()) {
        why = "accessor " + std::to_string(index) + " has an unexpected layout";
        return nullptr;
    }
    const tinygltf::BufferView& v = m.bufferViews[size_t(a.bufferView)];
    if (v.buffer < 0 || size_t(v.buffer) >= m.buffers.size()) {
        why = "buffer view without buffer";
        return nullptr;
    }
    stride = v.byteStride ? v.byteStride : elementSize;
    count = a.count;
    const size_t end = a.byteOffset + (count ? (count - 1) * stride + elementSize : 0);
    if (end > v.byteLength || v.byteOffset + v.byteLength > m.buffers[size_t(v.buffer)].data.size()) {
        why = "accessor " + std::to_string(index) + " outside its buffer";
        return nullptr;
    }
    return m.buffers[size_t(v.buffer)].data.data() + v.byteOffset + a.byteOffset;
}

bool readMesh(const tinygltf::Model& m, int meshIndex, Collider& c, std::string& why) {
    if (meshIndex < 0 || size_t(meshIndex) >= m.meshes.size() || m.meshes[size_t(meshIndex)].primitives.size() != 1) {
        why = "mesh " + std::to_string(meshIndex) + " missing or not one primitive";
        return false;
    }
    const tinygltf::Primitive& p = m.meshes[size_t(meshIndex)].primitives[0];
    if (p.mode != TINYGLTF_MODE_TRIANGLES || !p.attributes.count("POSITION")) {
        why = "mesh " + std::to_string(meshIndex) + " is not a triangle mesh with positions";
        return false;
    }
    size_t count = 0, stride = 0;
    const unsigned char* pos = accessorData(m, p.attributes.at("POSITION"), TINYGLTF_TYPE_VEC3, 12, count, stride, why);
    if (!pos || m.accessors[size_t(p.attributes.at("POSITION"))].componentType != TINYGLTF_COMPONENT_TYPE_FLOAT) return false;
    c.positions.resize(3 * count);
    for (size_t i = 0; i < count; ++i) std::memcpy(&c.positions[3 * i], pos + i * stride, 12);
    const int ct = p.indices >= 0 ? m.accessors[size_t(p.indices)].componentType : -1;
    if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        why = "mesh " + std::to_string(meshIndex) + ": indices are not uint32";
        return false;
    }
    size_t indexCount = 0, indexStride = 0;
    const unsigned char* idx = accessorData(m, p.indices, TINYGLTF_TYPE_SCALAR, 4, indexCount, indexStride, why);
    if (!idx) return false;
    c.indices.resize(indexCount);
    for (size_t i = 0; i < indexCount; ++i) {
        std::memcpy(&c.indices[i], idx + i * indexStride, 4);
        if (c.indices[i] >= count) {
            why = "mesh " + std::to_string(meshIndex) + ": index out of range";
            return false;
        }
    }
    return indexCount % 3 == 0 && indexCount > 0;
}

int intAt(const tinygltf::Value& object, const char* key) {
    return object.IsObject() && object.Has(key) && object.Get(key).IsNumber() ? int(object.Get(key).GetNumberAsDouble()) : -1;
}

CollisionFile readCollisionGlb(const fs::path& path) {
    CollisionFile f;
    tinygltf::Model m;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    if (!loader.LoadBinaryFromFile(&m, &err, &warn, path.string())) {
        f.problem = "tinygltf cannot read " + path.string() + ": " + err;
        return f;
    }
    f.extensionsUsed = m.extensionsUsed;
    f.defaultScene = m.defaultScene;
    // OMI_physics_shape: document-level shapes.
    std::vector<std::pair<std::string, int>> omiShapes;  // (type, mesh)
    const auto omi = m.extensions.find("OMI_physics_shape");
    if (omi == m.extensions.end() || !omi->second.Has("shapes")) {
        f.problem = "no document-level OMI_physics_shape shapes";
        return f;
    }
    const tinygltf::Value& shapes = omi->second.Get("shapes");
    for (size_t i = 0; i < shapes.ArrayLen(); ++i) {
        const tinygltf::Value& s = shapes.Get(int(i));
        const std::string type = s.Has("type") ? s.Get("type").Get<std::string>() : std::string();
        omiShapes.emplace_back(type, s.Has(type) ? intAt(s.Get(type), "mesh") : -1);
    }
    for (const tinygltf::Scene& scene : m.scenes) {
        ColliderScene cs;
        cs.name = scene.name;
        std::vector<int> stack(scene.nodes.rbegin(), scene.nodes.rend());
        while (!stack.empty()) {
            const int n = stack.back();
            stack.pop_back();
            if (n < 0 || size_t(n) >= m.nodes.size()) {
                f.problem = "scene " + scene.name + " refers to a missing node";
                return f;
            }
            const tinygltf::Node& node = m.nodes[size_t(n)];
            for (auto c = node.children.rbegin(); c != node.children.rend(); ++c) stack.push_back(*c);
            const auto khr = node.extensions.find("KHR_physics_rigid_bodies");
            if (khr == node.extensions.end()) continue;
            if (khr->second.Has("motion")) {
                f.problem = node.name + ": has motion (colliders must be static)";
                return f;
            }
            const tinygltf::Value& geometry = khr->second.Get("collider").Get("geometry");
            const int geometryNode = intAt(geometry, "node");
            if (geometryNode < 0 || size_t(geometryNode) >= m.nodes.size()) {
                f.problem = node.name + ": KHR collider geometry names no node";
                return f;
            }
            Collider c;
            c.node = uint32_t(intAt(node.extras, "node"));
            c.convex = geometry.Has("convexHull") && geometry.Get("convexHull").Get<bool>();
            const int meshIndex = m.nodes[size_t(geometryNode)].mesh;
            std::string why;
            if (!readMesh(m, meshIndex, c, why)) {
                f.problem = node.name + ": " + why;
                return f;
            }
            // The OMI description of the same collider: the same mesh, the same kind of shape.
            const auto body = node.extensions.find("OMI_physics_body");
            const int shape = body == node.extensions.end() ? -1 : intAt(body->second.Get("collider"), "shape");
            if (shape < 0 || size_t(shape) >= omiShapes.size() || omiShapes[size_t(shape)].second != meshIndex ||
                omiShapes[size_t(shape)].first != (c.convex ? "convex" : "trimesh")) {
                f.problem = node.name + ": OMI_physics_body / OMI_physics_shape disagree with KHR_physics_rigid_bodies";
                return f;
            }
            cs.colliders.push_back(std::move(c));
        }
        f.scenes.push_back(std::move(cs));
    }
    return f;
}

// ---------------------------------------------------------------------------------------
// Baking and Bullet worlds

struct Baked {
    std::string label;
    fs::path dir;
    rt::RuntimeFile file;
    CollisionFile collision;
    std::string problem;
};

std::unique_ptr<Baked> bake(const std::string& sample, const std::string& label) {
    auto b = std::make_unique<Baked>();
    b->label = label;
    b->dir = freshTestDir("bullet_" + label);
    const fs::path input = b->dir / (label + ".glb");
    RunResult r = runProgram({AGGRELOD_MAKE_SAMPLE, sample, "--seed", "1", "-o", input.string()}, b->dir);
    if (!(r.exited && r.exitCode == 0)) {
        b->problem = r.describe();
        return b;
    }
    r = runProgram({AGGRELOD_CLI, "bake", input.string(), "-o", (b->dir / "out").string(), "--levels", "4", "--collision",
                    "--threads", "2", "--quiet"},
                   b->dir);
    if (!(r.exited && r.exitCode == 0)) {
        b->problem = r.describe();
        return b;
    }
    std::string message;
    if (rt::RuntimeFile::openFile((b->dir / "out" / "scene.aglod").string(), b->file, message) != rt::FileStatus::Ok) {
        b->problem = "scene.aglod: " + message;
        return b;
    }
    b->collision = readCollisionGlb(b->dir / "out" / "collision.glb");
    b->problem = b->collision.problem;
    return b;
}

/// The runtime cut a scene of collision.glb stands for.
bool cutOfScene(const rt::RuntimeFile& file, const std::string& sceneName, std::vector<uint32_t>& cut) {
    std::string name = sceneName;
    if (name.size() > 7 && name.compare(name.size() - 7, 7, "_convex") == 0) name.resize(name.size() - 7);
    uint32_t level = 0;
    if (name == "originals") level = rt::kLeafLevel;
    else if (name == "object_lods") level = rt::kObjectLodLevel;
    else if (name.rfind("level", 0) == 0) level = uint32_t(std::stoul(name.substr(5)));
    else return false;
    rt::cutAtLevel(file, level, cut);
    return true;
}

/// A static Bullet body per collider; margins 0 (shapes exactly as in the file).
struct BulletScene {
    std::unique_ptr<btDefaultCollisionConfiguration> config = std::make_unique<btDefaultCollisionConfiguration>();
    std::unique_ptr<btCollisionDispatcher> dispatcher = std::make_unique<btCollisionDispatcher>(config.get());
    std::unique_ptr<btDbvtBroadphase> broadphase = std::make_unique<btDbvtBroadphase>();
    std::unique_ptr<btSequentialImpulseConstraintSolver> solver = std::make_unique<btSequentialImpulseConstraintSolver>();
    std::unique_ptr<btDiscreteDynamicsWorld> world;
    std::vector<std::unique_ptr<btTriangleMesh>> meshes;
    std::vector<std::unique_ptr<btCollisionShape>> shapes;
    std::vector<std::unique_ptr<btRigidBody>> bodies;
    std::vector<std::unique_ptr<btDefaultMotionState>> motions;

    static constexpr int kStaticGroup = 1, kSphereGroup = 2;

    /// Bullet's convex algorithms (GJK) need a margin above 0: with margin 0 its ray test was
    /// seen to report hits far outside a tetrahedron. The hull grows by it (conservatively).
    double hullMargin = 0;

    BulletScene(const ColliderScene& scene, double margin) : hullMargin(margin) {
        world = std::make_unique<btDiscreteDynamicsWorld>(dispatcher.get(), broadphase.get(), solver.get(), config.get());
        for (const Collider& c : scene.colliders) {
            btCollisionShape* shape = nullptr;
            if (c.convex) {
                auto hull = std::make_unique<btConvexHullShape>(c.positions.data(), int(c.positions.size() / 3), int(3 * sizeof(float)));
                hull->setMargin(btScalar(hullMargin));
                shape = hull.get();
                shapes.push_back(std::move(hull));
            } else {
                auto mesh = std::make_unique<btTriangleMesh>(true, false);
                for (size_t t = 0; t + 2 < c.indices.size(); t += 3) {
                    btVector3 v[3];
                    for (int k = 0; k < 3; ++k) {
                        const float* p = &c.positions[3 * size_t(c.indices[t + k])];
                        v[k] = btVector3(p[0], p[1], p[2]);
                    }
                    mesh->addTriangle(v[0], v[1], v[2], false);
                }
                auto trimesh = std::make_unique<btBvhTriangleMeshShape>(mesh.get(), true);
                shape = trimesh.get();
                meshes.push_back(std::move(mesh));
                shapes.push_back(std::move(trimesh));
            }
            addStatic(shape, int(c.node));
        }
    }
    void addStatic(btCollisionShape* shape, int userIndex) {
        btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape);
        auto body = std::make_unique<btRigidBody>(info);
        body->setUserIndex(userIndex);
        world->addRigidBody(body.get(), kStaticGroup, kSphereGroup);
        bodies.push_back(std::move(body));
    }
    ~BulletScene() {
        for (auto& b : bodies) world->removeRigidBody(b.get());
    }
};

/// Half-spaces of a convex hull (outward unit normal n, offset d: inside when n.x <= d).
struct Hull {
    std::vector<std::array<double, 4>> planes;
};

Hull hullPlanes(const Collider& c) {
    Hull h;
    for (size_t t = 0; t + 2 < c.indices.size(); t += 3) {
        double p[3][3];
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) p[k][d] = c.positions[3 * size_t(c.indices[t + k]) + d];
        const double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
        const double v[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(l > 0)) continue;
        for (double& x : n) x /= l;
        h.planes.push_back({n[0], n[1], n[2], n[0] * p[0][0] + n[1] * p[0][1] + n[2] * p[0][2]});
    }
    return h;
}

/// Whether the segment a-b meets the inside of the hull shrunk by `slack` (Cyrus-Beck clipping).
bool segmentEntersHull(const Hull& h, const btVector3& a, const btVector3& b, double slack) {
    double t0 = 0, t1 = 1;
    for (const auto& q : h.planes) {
        const double da = q[0] * a.x() + q[1] * a.y() + q[2] * a.z() - q[3] + slack;
        const double db = q[0] * b.x() + q[1] * b.y() + q[2] * b.z() - q[3] + slack;
        if (da > 0 && db > 0) return false;
        if (da > 0) t0 = std::max(t0, da / (da - db));
        else if (db > 0) t1 = std::min(t1, da / (da - db));
        if (t0 > t1) return false;
    }
    return true;
}

/// Closest distance from p to the triangles of runtime node `node`.
double distanceToNode(const rt::RuntimeFile& file, uint32_t node, const btVector3& p) {
    const auto v = file.vertices(node);
    const auto t = file.triangles(node);
    double best = INFINITY;
    for (size_t i = 0; i + 2 < t.size; i += 3) {
        const btVector3 a(v[3 * t[i]], v[3 * t[i] + 1], v[3 * t[i] + 2]);
        const btVector3 b(v[3 * t[i + 1]], v[3 * t[i + 1] + 1], v[3 * t[i + 1] + 2]);
        const btVector3 c(v[3 * t[i + 2]], v[3 * t[i + 2] + 1], v[3 * t[i + 2] + 2]);
        // Closest point on triangle (Ericson, Real-Time Collision Detection 5.1.5), in double.
        const double ab[3] = {b.x() - a.x(), b.y() - a.y(), b.z() - a.z()}, ac[3] = {c.x() - a.x(), c.y() - a.y(), c.z() - a.z()};
        const double ap[3] = {p.x() - a.x(), p.y() - a.y(), p.z() - a.z()};
        auto dot = [](const double* x, const double* y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
        const double d1 = dot(ab, ap), d2 = dot(ac, ap);
        double q[3];
        auto at = [&](double s, double w) {
            for (int k = 0; k < 3; ++k) q[k] = (k == 0 ? a.x() : k == 1 ? a.y() : a.z()) + s * ab[k] + w * ac[k];
        };
        const double bp[3] = {p.x() - b.x(), p.y() - b.y(), p.z() - b.z()}, cp[3] = {p.x() - c.x(), p.y() - c.y(), p.z() - c.z()};
        const double d3 = dot(ab, bp), d4 = dot(ac, bp), d5 = dot(ab, cp), d6 = dot(ac, cp);
        const double vc = d1 * d4 - d3 * d2, vb = d5 * d2 - d1 * d6, va = d3 * d6 - d5 * d4;
        if (d1 <= 0 && d2 <= 0) at(0, 0);
        else if (d3 >= 0 && d4 <= d3) at(1, 0);
        else if (vc <= 0 && d1 >= 0 && d3 <= 0) at(d1 / (d1 - d3), 0);
        else if (d6 >= 0 && d5 <= d6) at(0, 1);
        else if (vb <= 0 && d2 >= 0 && d6 <= 0) at(0, d2 / (d2 - d6));
        else if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
            const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
            at(1 - w, w);
        } else {
            const double denom = 1 / (va + vb + vc);
            at(vb * denom, vc * denom);
        }
        const double dx = q[0] - p.x(), dy = q[1] - p.y(), dz = q[2] - p.z();
        best = std::min(best, std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    return best;
}

/// Distance from p to the nearest triangle edge of `node`'s mesh (world units).
double distanceToNodeEdges(const rt::RuntimeFile& file, uint32_t node, const btVector3& p) {
    const auto v = file.vertices(node);
    const auto t = file.triangles(node);
    double best = INFINITY;
    for (size_t i = 0; i + 2 < t.size; i += 3)
        for (int k = 0; k < 3; ++k) {
            const uint32_t i0 = t[i + size_t(k)], i1 = t[i + size_t((k + 1) % 3)];
            const double a[3] = {v[3 * i0], v[3 * i0 + 1], v[3 * i0 + 2]}, c[3] = {v[3 * i1], v[3 * i1 + 1], v[3 * i1 + 2]};
            const double q[3] = {p.x(), p.y(), p.z()};
            double ac2 = 0, aq = 0;
            for (int d = 0; d < 3; ++d) ac2 += (c[d] - a[d]) * (c[d] - a[d]), aq += (q[d] - a[d]) * (c[d] - a[d]);
            const double u = std::clamp(aq / std::max(ac2, 1e-300), 0.0, 1.0);
            double d2 = 0;
            for (int d = 0; d < 3; ++d) d2 += (a[d] + u * (c[d] - a[d]) - q[d]) * (a[d] + u * (c[d] - a[d]) - q[d]);
            best = std::min(best, std::sqrt(d2));
        }
    return best;
}

/// Bullet's collision margin of the convex hulls, as a fraction of the scene's radius.
constexpr double kHullMarginFraction = 2e-5;

struct SceneBox {
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    double center[3] = {0, 0, 0}, radius = 0;
    int up = 2;  ///< the box's shortest axis (z for the samples)
};

SceneBox sceneBox(const rt::RuntimeFile& file) {
    SceneBox s;
    for (uint32_t r : file.roots())
        for (int k = 0; k < 3; ++k) {
            s.lo[k] = std::min(s.lo[k], double(file.node(r).boundsMin[k]));
            s.hi[k] = std::max(s.hi[k], double(file.node(r).boundsMax[k]));
        }
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
        s.center[k] = 0.5 * (s.lo[k] + s.hi[k]);
        d2 += (s.hi[k] - s.lo[k]) * (s.hi[k] - s.lo[k]);
    }
    s.radius = 0.5 * std::sqrt(d2);
    for (int k = 0; k < 3; ++k)
        if (s.hi[k] - s.lo[k] < s.hi[s.up] - s.lo[s.up]) s.up = k;
    return s;
}

btVector3 vec(const double* p) { return btVector3(btScalar(p[0]), btScalar(p[1]), btScalar(p[2])); }

struct Figures {
    size_t scenes = 0, colliders = 0, convexColliders = 0;
    size_t rays = 0, rayHits = 0, sweeps = 0, sweepHits = 0;
    size_t drops = 0, dropsTouching = 0, tunnelled = 0, steps = 0;
    double radius = 0;  ///< of the scene's bounding box (world units)
    size_t grazing = 0;  ///< triangle-mesh rays hit at different distances (through an edge), same point within eps
    size_t edgeOnly = 0;  ///< of those, rays through an edge that one of Bullet and the runtime counts as a miss
    double largestRayGap = 0, largestSweepGap = 0;  ///< triangle meshes: |Bullet - runtime|, world units
    double largestConvexEarly = 0;  ///< convex: how much earlier than the proxies Bullet's rays hit
    double largestConvexOff = 0;    ///< convex: largest (distance of Bullet's hit to the node's proxy - node's error)
};

/// a) rays and sweeps of one scene against the runtime's answers on its cut.
void compareQueries(const Baked& b, const ColliderScene& scene, BulletScene& bullet, rt::CollisionWorld& world,
                    const SceneBox& box, std::mt19937& rng, Figures& fig) {
    const bool convexScene = scene.name.size() > 7 && scene.name.compare(scene.name.size() - 7, 7, "_convex") == 0;
    const double eps = 1e-4 * box.radius;
    std::uniform_real_distribution<double> uni(0, 1);
    auto randomPointInBox = [&]() {
        double p[3];
        for (int k = 0; k < 3; ++k) p[k] = box.lo[k] + uni(rng) * (box.hi[k] - box.lo[k]);
        return vec(p);
    };
    auto randomOrigin = [&]() {
        double d[3], l = 0;
        do {
            l = 0;
            for (int k = 0; k < 3; ++k) {
                d[k] = 2 * uni(rng) - 1;
                l += d[k] * d[k];
            }
        } while (l > 1 || l < 1e-6);
        l = std::sqrt(l);
        double p[3];
        for (int k = 0; k < 3; ++k) p[k] = box.center[k] + 1.5 * box.radius * d[k] / l;
        return vec(p);
    };
    // Most rays and sweeps aim at a point on a collider of the scene, the rest anywhere in the box.
    auto randomTarget = [&]() {
        if (scene.colliders.empty() || uni(rng) < 0.2) return randomPointInBox();
        const Collider& c = scene.colliders[size_t(uni(rng) * scene.colliders.size()) % scene.colliders.size()];
        const size_t t = 3 * (size_t(uni(rng) * (c.indices.size() / 3)) % (c.indices.size() / 3));
        double w[3] = {uni(rng), uni(rng), 0};
        if (w[0] + w[1] > 1) w[0] = 1 - w[0], w[1] = 1 - w[1];
        w[2] = 1 - w[0] - w[1];
        double p[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) p[d] += w[k] * c.positions[3 * size_t(c.indices[t + k]) + d];
        return vec(p);
    };
    auto errorOf = [&](int node) { return node >= 0 && uint32_t(node) < b.file.nodeCount() ? double(b.file.node(uint32_t(node)).geometricError) : 0.0; };
    const int rayCount = 400, sweepCount = 150;
    for (int i = 0; i < rayCount; ++i) {
        const btVector3 from = randomOrigin(), target = randomTarget();
        const btVector3 dir = (target - from).normalized();
        const double length = 1.25 * (target - from).length();
        // Bullet's ray test against a convex shape (btSubsimplexConvexCast) stops within about
        // 1e-4 of the ray's length; triangle meshes are exact up to float rounding.
        const double rayEps = convexScene ? eps + 3e-4 * length + bullet.hullMargin : eps;
        const btVector3 to = from + dir * btScalar(length);
        btCollisionWorld::ClosestRayResultCallback cb(from, to);
        cb.m_collisionFilterGroup = BulletScene::kSphereGroup;
        cb.m_collisionFilterMask = BulletScene::kStaticGroup;
        bullet.world->rayTest(from, to, cb);
        const float o[3] = {from.x(), from.y(), from.z()}, d[3] = {dir.x(), dir.y(), dir.z()};
        rt::CollisionHit hit;
        const bool runtimeHit = world.raycast(o, d, float(length), hit);
        ++fig.rays;
        fig.rayHits += cb.hasHit();
        const double tBullet = cb.hasHit() ? cb.m_closestHitFraction * length : INFINITY;
        const int bulletNode = cb.hasHit() ? cb.m_collisionObject->getUserIndex() : -1;
        if (!convexScene) {
            if (cb.hasHit() != runtimeHit) {
                // One of them passes by where the other one hits: a ray through an edge, as
                // below, when the hit lies on an edge of its node's mesh (within eps).
                const double edge = cb.hasHit()
                                        ? distanceToNodeEdges(b.file, uint32_t(bulletNode), from + (to - from) * cb.m_closestHitFraction)
                                        : distanceToNodeEdges(b.file, hit.node, from + dir * hit.distance);
                EXPECT_LE(edge, eps) << b.label << " " << scene.name << " ray " << i << ": "
                                     << (cb.hasHit() ? "Bullet" : "the runtime") << " alone hits, " << edge
                                     << " from an edge of its node";
                ++fig.grazing;
                ++fig.edgeOnly;
                continue;
            }
            if (!runtimeHit) continue;
            const double along = std::fabs(tBullet - hit.distance);
            const btVector3 pb = from + (to - from) * cb.m_closestHitFraction;
            double gap = along;
            if (along > eps) {
                // Not the same distance: a ray through an edge, which Bullet's lenient edge test
                // (a tolerance relative to the triangle's size) counts as a hit where Embree's
                // watertight test passes by, or the other way round. The same hit when the ray
                // comes within eps of the surface at the earlier point: Bullet's hit point lies
                // on its node's triangles, or Embree's on an edge of its triangle.
                if (tBullet < hit.distance) {
                    gap = distanceToNode(b.file, uint32_t(bulletNode), pb);
                } else {
                    const btVector3 pr = from + dir * hit.distance;
                    const auto v = b.file.vertices(hit.node);
                    const auto t = b.file.triangles(hit.node);
                    gap = INFINITY;
                    for (int k = 0; k < 3; ++k) {
                        const uint32_t i0 = t[3 * size_t(hit.triangle) + size_t(k)], i1 = t[3 * size_t(hit.triangle) + size_t((k + 1) % 3)];
                        const btVector3 a(v[3 * i0], v[3 * i0 + 1], v[3 * i0 + 2]), c(v[3 * i1], v[3 * i1 + 1], v[3 * i1 + 2]);
                        const btScalar u = std::clamp((pr - a).dot(c - a) / std::max((c - a).length2(), btScalar(1e-30)), btScalar(0), btScalar(1));
                        gap = std::min(gap, double((a + (c - a) * u - pr).length()));
                    }
                }
                ++fig.grazing;
            }
            fig.largestRayGap = std::max(fig.largestRayGap, gap);
            EXPECT_LE(gap, eps) << b.label << " " << scene.name << " ray " << i << ": Bullet " << tBullet << " runtime "
                                << hit.distance << " (node " << hit.node << " triangle " << hit.triangle << ", cos "
                                << (dir.x() * hit.normal[0] + dir.y() * hit.normal[1] + dir.z() * hit.normal[2])
                                << "; Bullet normal " << cb.m_hitNormalWorld.x() << " " << cb.m_hitNormalWorld.y() << " "
                                << cb.m_hitNormalWorld.z() << ")";
            if (along <= eps) {
                EXPECT_EQ(uint32_t(bulletNode), hit.node) << b.label << " " << scene.name << " ray " << i;
            }
        } else {
            // Hulls contain the proxies: hit no later; the hit lies within the node's error of it.
            if (runtimeHit) {
                ASSERT_TRUE(cb.hasHit()) << b.label << " " << scene.name << " ray " << i << ": the proxies are hit, the hulls not";
                EXPECT_LE(tBullet, hit.distance + rayEps) << b.label << " " << scene.name << " ray " << i;
                fig.largestConvexEarly = std::max(fig.largestConvexEarly, double(hit.distance) - tBullet);
            }
            if (cb.hasHit()) {
                const double d = distanceToNode(b.file, uint32_t(bulletNode), from + (to - from) * cb.m_closestHitFraction);
                fig.largestConvexOff = std::max(fig.largestConvexOff, d - errorOf(bulletNode));
                EXPECT_LE(d, errorOf(bulletNode) + rayEps)
                    << b.label << " " << scene.name << " ray " << i << ": hull hit " << d << " from node " << bulletNode;
            }
        }
    }
    for (int i = 0; i < sweepCount; ++i) {
        const btVector3 from = randomOrigin(), target = randomTarget();
        const btVector3 to = from + (target - from) * 1.25;
        const double r = box.radius * (0.005 + 0.045 * uni(rng));
        btSphereShape sphere(static_cast<btScalar>(r));
        btCollisionWorld::ClosestConvexResultCallback cb(from, to);
        cb.m_collisionFilterGroup = BulletScene::kSphereGroup;
        cb.m_collisionFilterMask = BulletScene::kStaticGroup;
        btTransform a, c;
        a.setIdentity();
        c.setIdentity();
        a.setOrigin(from);
        c.setOrigin(to);
        bullet.world->convexSweepTest(&sphere, a, c, cb, 0);
        ++fig.sweeps;
        const float af[3] = {from.x(), from.y(), from.z()};
        auto point = [&](double f) { return from + (to - from) * btScalar(f); };
        auto capsuleTo = [&](double f, double radius) {
            const btVector3 p = point(f);
            const float bf[3] = {p.x(), p.y(), p.z()};
            return world.capsuleTouches(af, bf, float(std::max(radius, 0.0)));
        };
        const double length = (to - from).length();
        if (!cb.hasHit()) {
            // Nothing in the way: the runtime's cut is not touched either (up to rounding).
            EXPECT_FALSE(capsuleTo(1, r - eps)) << b.label << " " << scene.name << " sweep " << i << ": runtime touches, Bullet not";
            continue;
        }
        ++fig.sweepHits;
        const double f = cb.m_closestHitFraction;
        const int node = cb.m_hitCollisionObject->getUserIndex();
        const btVector3 p = point(f);
        const float pf[3] = {p.x(), p.y(), p.z()};
        // No contact before Bullet's (the runtime's surfaces are inside Bullet's shapes) ...
        if (f * length > 2 * eps) {
            const double before = std::max(0.0, f - 2 * eps / length);
            EXPECT_FALSE(capsuleTo(before, r - eps)) << b.label << " " << scene.name << " sweep " << i << ": runtime touches earlier";
        }
        // ... and at Bullet's contact the sphere touches the cut (convex: within the node's error).
        const double slack = convexScene ? errorOf(node) + bullet.hullMargin : 0.0;
        EXPECT_TRUE(world.sphereTouches(pf, float(r + slack + eps)))
            << b.label << " " << scene.name << " sweep " << i << ": Bullet's contact is not near the cut";
        if (!convexScene) {
            // Distance of the contact sphere to the cut's triangles, from the runtime: bisect on radius.
            double lo = 0, hi = r + eps;
            for (int k = 0; k < 30; ++k) {
                const double mid = 0.5 * (lo + hi);
                (world.sphereTouches(pf, float(mid)) ? hi : lo) = mid;
            }
            fig.largestSweepGap = std::max(fig.largestSweepGap, std::fabs(hi - r));
        }
    }
}

/// b) spheres dropped from above the scene onto every object of the scene's cut.
void dropSpheres(const Baked& b, const ColliderScene& scene, BulletScene& bullet, rt::CollisionWorld& world,
                 const std::vector<uint32_t>& cut, const SceneBox& box, int perObject, std::mt19937& rng, Figures& fig) {
    const bool convexScene = scene.name.size() > 7 && scene.name.compare(scene.name.size() - 7, 7, "_convex") == 0;
    std::vector<Hull> hulls;
    if (convexScene)
        for (const Collider& c : scene.colliders)
            if (c.convex) hulls.push_back(hullPlanes(c));
    // Triangle-mesh colliders of a convex scene (nodes without a decomposition) are checked
    // with the runtime on those nodes only.
    std::vector<uint32_t> meshNodes;
    for (const Collider& c : scene.colliders)
        if (!c.convex) meshNodes.push_back(c.node);
    world.useCut(meshNodes.data(), meshNodes.size());
    const int up = box.up;
    btVector3 gravity(0, 0, 0);
    gravity[up] = btScalar(-9.81);
    bullet.world->setGravity(gravity);
    // A ground below everything, so that spheres rolling off come to rest.
    btVector3 normal(0, 0, 0);
    normal[up] = 1;
    btStaticPlaneShape ground(normal, btScalar(box.lo[up] - 0.05 * box.radius));
    bullet.addStatic(&ground, -1);

    struct Drop {
        std::unique_ptr<btSphereShape> shape;
        std::unique_ptr<btRigidBody> body;
        btVector3 last;
        bool touched = false;
    };
    std::vector<Drop> drops;
    std::uniform_real_distribution<double> uni(0, 1);
    std::set<uint32_t> objects;
    for (uint32_t n : cut)
        for (uint32_t o : b.file.sources(n)) objects.insert(o);
    for (uint32_t o : objects) {
        const rt::NodeRecord& leaf = b.file.node(o);  // leaf i = object i
        if (b.file.triangles(o).size == 0) continue;
        double extent = INFINITY;
        for (int k = 0; k < 3; ++k) extent = std::min(extent, double(leaf.boundsMax[k] - leaf.boundsMin[k]));
        const double r = std::clamp(0.2 * extent, 0.002 * box.radius, 0.05 * box.radius);
        for (int j = 0; j < perObject; ++j) {
            double p[3];
            for (int k = 0; k < 3; ++k) {
                const double mid = 0.5 * (leaf.boundsMin[k] + leaf.boundsMax[k]), half = 0.5 * (leaf.boundsMax[k] - leaf.boundsMin[k]);
                p[k] = mid + (2 * uni(rng) - 1) * 0.6 * half;
            }
            p[up] = box.hi[up] + 2 * r + 0.02 * box.radius * uni(rng);  // above every collider
            Drop d;
            d.shape = std::make_unique<btSphereShape>(btScalar(r));
            btVector3 inertia(0, 0, 0);
            d.shape->calculateLocalInertia(1, inertia);
            btTransform t;
            t.setIdentity();
            t.setOrigin(vec(p));
            btRigidBody::btRigidBodyConstructionInfo info(1, nullptr, d.shape.get(), inertia);
            info.m_startWorldTransform = t;
            d.body = std::make_unique<btRigidBody>(info);
            d.body->setUserIndex(-2);
            d.body->setActivationState(DISABLE_DEACTIVATION);
            bullet.world->addRigidBody(d.body.get(), BulletScene::kSphereGroup, BulletScene::kStaticGroup);
            d.last = t.getOrigin();
            drops.push_back(std::move(d));
        }
    }
    fig.drops += drops.size();
    const double dt = 1.0 / 240.0;
    // Time to fall from the top of the scene to the ground, and some to settle.
    const double fall = std::sqrt(2 * (box.hi[up] - box.lo[up] + 0.2 * box.radius) / 9.81);
    const int steps = int(std::ceil((fall + 0.5) / dt));
    for (int s = 0; s < steps; ++s) {
        bullet.world->stepSimulation(btScalar(dt), 1, btScalar(dt));
        ++fig.steps;
        for (int m = 0; m < bullet.dispatcher->getNumManifolds(); ++m) {
            const btPersistentManifold* manifold = bullet.dispatcher->getManifoldByIndexInternal(m);
            if (manifold->getNumContacts() == 0) continue;
            const btCollisionObject* b0 = manifold->getBody0();
            const btCollisionObject* b1 = manifold->getBody1();
            const btCollisionObject* sphere = b0->getUserIndex() == -2 ? b0 : b1;
            const btCollisionObject* other = sphere == b0 ? b1 : b0;
            if (other->getUserIndex() < 0) continue;  // the ground
            for (Drop& d : drops)
                if (d.body.get() == sphere) d.touched = true;
        }
        for (size_t i = 0; i < drops.size(); ++i) {
            Drop& d = drops[i];
            const btVector3 now = d.body->getCenterOfMassPosition();
            bool crossed = false;
            if (!meshNodes.empty()) {
                const float a[3] = {d.last.x(), d.last.y(), d.last.z()}, c[3] = {now.x(), now.y(), now.z()};
                rt::CollisionHit hit;
                crossed = world.segment(a, c, hit);
            }
            for (size_t h = 0; h < hulls.size() && !crossed; ++h)
                crossed = segmentEntersHull(hulls[h], d.last, now, 1e-6 * box.radius);
            if (crossed) {
                ++fig.tunnelled;
                ADD_FAILURE() << b.label << " " << scene.name << ": sphere " << i << " (radius " << d.shape->getRadius()
                              << ") passed into a collider at step " << s << ", from (" << d.last.x() << ", " << d.last.y()
                              << ", " << d.last.z() << ") to (" << now.x() << ", " << now.y() << ", " << now.z() << ")";
                bullet.world->removeRigidBody(d.body.get());  // report it once
                d.last = btVector3(btScalar(INFINITY), 0, 0);
            } else {
                d.last = now;
            }
        }
        std::vector<Drop> alive;
        for (Drop& d : drops)
            if (std::isfinite(d.last.x())) alive.push_back(std::move(d));
            else fig.dropsTouching += d.touched;
        drops = std::move(alive);
    }
    for (Drop& d : drops) {
        fig.dropsTouching += d.touched;
        bullet.world->removeRigidBody(d.body.get());
    }
    bullet.world->removeRigidBody(bullet.bodies.back().get());
    bullet.bodies.pop_back();
}

Figures runScene(Baked& b, int dropsPerObject, uint32_t seed) {
    Figures fig;
    const SceneBox box = sceneBox(b.file);
    fig.radius = box.radius;
    rt::CollisionWorld world(b.file, 2);
    EXPECT_TRUE(world.ok()) << world.error();
    std::mt19937 rng(seed);
    for (const ColliderScene& scene : b.collision.scenes) {
        if (scene.name == "all_nodes") continue;
        std::vector<uint32_t> cut;
        if (!cutOfScene(b.file, scene.name, cut)) {
            ADD_FAILURE() << b.label << ": scene '" << scene.name << "' names no cut";
            continue;
        }
        // The scene holds the runtime's cut: one collider (or convex group) per node with triangles.
        std::set<uint32_t> inScene, inCut;
        for (const Collider& c : scene.colliders) inScene.insert(c.node);
        for (uint32_t n : cut)
            if (b.file.triangles(n).size > 0) inCut.insert(n);
        EXPECT_EQ(inScene, inCut) << b.label << ": scene '" << scene.name << "' is not the runtime's cut";
        ++fig.scenes;
        fig.colliders += scene.colliders.size();
        for (const Collider& c : scene.colliders) fig.convexColliders += c.convex;
        BulletScene bullet(scene, kHullMarginFraction * box.radius);
        world.useCut(cut.data(), cut.size());
        compareQueries(b, scene, bullet, world, box, rng, fig);
        dropSpheres(b, scene, bullet, world, cut, box, dropsPerObject, rng, fig);
    }
    return fig;
}

void report(const std::string& label, const Figures& f, double seconds) {
    std::printf("%s: %zu scenes, %zu colliders (%zu convex); %zu rays (%zu hit), %zu sphere sweeps (%zu hit): "
                "triangle meshes agree with the runtime to %.3g (rays; %zu through an edge, %zu of them hit by one only) and %.3g (sweeps); convex hulls hit up to %.3g "
                "earlier than the proxies, at most %.3g beyond the node's error from its proxy; %zu spheres dropped (%zu "
                "touched a collider), %zu passed into one, %zu steps of 1/240 s; scene radius %.4g; %.1f s\n",
                label.c_str(), f.scenes, f.colliders, f.convexColliders, f.rays, f.rayHits, f.sweeps, f.sweepHits,
                f.largestRayGap, f.grazing, f.edgeOnly, f.largestSweepGap, f.largestConvexEarly, f.largestConvexOff, f.drops, f.dropsTouching,
                f.tunnelled, f.steps, f.radius, seconds);
    std::fflush(stdout);
}

TEST(BulletCollision, CollisionGlbInBullet) {
    const auto start = std::chrono::steady_clock::now();
    struct Case {
        const char* sample;
        int dropsPerObject;
    };
    size_t drops = 0, touching = 0, tunnelled = 0, convexColliders = 0, rays = 0, sweeps = 0;
    for (const Case& c : {Case{"spheres15", 8}, Case{"village", 3}}) {
        const auto sceneStart = std::chrono::steady_clock::now();
        auto b = bake(c.sample, c.sample);
        ASSERT_TRUE(b->problem.empty()) << c.sample << ": " << b->problem;
        // Valid glTF with the physics extensions (reported as unknown: info, not errors).
        validateGltf({b->dir / "out" / "collision.glb"}, b->dir);
        const RunResult v = runValidator({b->dir / "out" / "collision.glb"}, b->dir);
        std::printf("%s", v.out.c_str());
        const std::vector<std::string>& used = b->collision.extensionsUsed;
        for (const char* ext : {"KHR_physics_rigid_bodies", "OMI_physics_body", "OMI_physics_shape"})
            EXPECT_NE(std::find(used.begin(), used.end(), ext), used.end()) << ext << " not in extensionsUsed";
        ASSERT_GE(b->collision.scenes.size(), 3u);
        EXPECT_EQ(b->collision.defaultScene, 0);
        const Figures f = runScene(*b, c.dropsPerObject, 20240601u);
        report(c.sample, f, std::chrono::duration<double>(std::chrono::steady_clock::now() - sceneStart).count());
        EXPECT_GT(f.convexColliders, 0u) << c.sample << ": no convex decomposition was tested";
        EXPECT_GT(f.rayHits, f.rays / 4) << c.sample << ": too few rays hit anything for the comparison to mean much";
        EXPECT_GT(f.sweepHits, f.sweeps / 4);
        drops += f.drops;
        touching += f.dropsTouching;
        tunnelled += f.tunnelled;
        convexColliders += f.convexColliders;
        rays += f.rays;
        sweeps += f.sweeps;
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("total: %zu rays, %zu sweeps, %zu drops (%zu touched a collider), %zu passed through; %.1f s\n", rays, sweeps,
                drops, touching, tunnelled, seconds);
    EXPECT_GE(drops, 1000u);
    EXPECT_EQ(tunnelled, 0u);
    EXPECT_GE(touching, drops * 8 / 10) << "most spheres must land on a collider, not only on the ground";
}

}  // namespace
