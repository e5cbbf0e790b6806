// SPDX-License-Identifier: AGPL-3.0-or-later
// What the drawn cut costs against the alternatives a user has (docs/design.md §2.6, "the yardstick"):
// for a 1920 x 1080 viewport, 60 degree vertical field of view and tau = 1 px, cameras on a
// circle around the scene's bounding-sphere centre at 1, 2, 4, 8 and 16 scene diameters
// (8 azimuths, fixed elevation, looking at the centre, about the scene's up axis), the
// triangles and draw calls of
//  (a) the originals: every object at full detail, one draw call each;
//  (b) per-object LOD: each object simplified alone with meshoptimizer (a chain of target
//      errors sqrt(2) apart), each level's error measured as ours (measureProxyError, the
//      certified two-sided Hausdorff distance), the level with the fewest triangles whose
//      error projects to <= tau at the object's bounding sphere; one draw call per object;
//  (b') conservative per-object LOD: the same choice among each object's enclosing versions
//      (enclosingVersions: what the bake's per-object chains are cut from, not cut), each of
//      which contains its object as the cut's proxies do; one draw call per object;
//  (c) aggrelod's cut: Selector::selectFull at tau, no hysteresis, with the originals'
//      triangle counts given (Selector::setDrawCosts, default cost per draw call); proxy
//      triangles plus the originals drawn as leaves, one draw call per proxy node and per leaf.
// Figures are means per camera over the 8 azimuths. Then the goals (PASS / FAIL) and the
// proxies stage's share of the bake. Generated scenes are rounded to float first, as in the
// GLB that aggrelod_make_sample writes. A benchmark: nothing is asserted; apart from the
// timings the output is deterministic.
//
// Usage: bench_lod_budget [--scenes random,forest,village,truck_town] [--seed 1]
//          [--objects 400] [--triangles 200000] [--levels 8] [--threads 2] [--elevation 25]
//          [--data DIR (holds 3d/truck_town/town_model.gltf)] [--breakdown (the cut by node kind)]
//          [--bundles N (ProxySettings::bundleCount; 0: none, as before bundles; default: the bake's)]
//          [--draw-call-cost T (triangles one draw call is worth to the selector, setDrawCosts; default 16)]
//        bench_lod_budget --cut-for FILE.aglod --cameras FRAMES.csv   (the cut per given camera,
//          see lod_budget_cut_for.h)
#include "acceptance_scenes.h"
#include "runtime_export.h"

#include "parallel_for.h"

#include "lod_budget_cut_for.h"

#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include <meshoptimizer.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

using namespace aggrelod;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr float kViewportHeight = 1080.0f;
constexpr double kFovY = 60.0 * kPi / 180.0;
constexpr float kTau = 1.0f;
constexpr int kAzimuths = 8;
const int kDistances[] = {1, 2, 4, 8, 16};  // scene diameters from the centre

struct Options {
    std::vector<std::string> scenes = {"random", "forest", "village", "truck_town"};
    uint32_t seed = 1;
    int objects = 400, triangles = 200000, levels = 8, threads = 2;
    int bundles = -1;  ///< -1: the bake's default
    float drawCallCost = runtime::Selector::kDefaultTrianglesPerDrawCall;  ///< --draw-call-cost
    double elevationDegrees = 25;
    bool breakdown = false;
    std::string data = AGGRELOD_SHARED_DATA;
};

/// One level of an object's per-object LOD chain.
struct ChainLevel {
    size_t triangles = 0;
    double error = 0;  ///< certified two-sided distance to the object, world units
    bool closed = true;
};

struct Chain {
    std::vector<ChainLevel> levels;  ///< [0] = the object itself (error 0)
};

/// Every undirected edge used exactly twice, once in each direction.
bool closedMesh(const std::vector<uint32_t>& indices) {
    std::map<std::pair<uint32_t, uint32_t>, int> uses;  // directed edge -> count
    for (size_t t = 0; t < indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) ++uses[{indices[t + k], indices[t + (k + 1) % 3]}];
    for (const auto& [edge, count] : uses) {
        if (count != 1) return false;
        const auto back = uses.find({edge.second, edge.first});
        if (back == uses.end() || back->second != 1) return false;
    }
    return !indices.empty();
}

/// The per-object LOD chain of `object`: meshopt_simplify at absolute target errors
/// radius * 2^(-j/2), j = 0, 1, ... down to `finest`, coarsest first, identical results kept
/// once. Vertices are
/// welded by position first (glTF art repeats them at seams, which would otherwise lock the
/// seams). A closed result is measured as our proxies are (inside-ness by ray parity); an open
/// one gets no inside credit: its originals -> proxy distance is that of the original surface
/// to the proxy surface (measureProxyError with the roles swapped: its proxy -> originals
/// direction is a surface-to-surface bound that needs no closed mesh).
Chain buildChain(const InputObject& object, double radius, double finest) {
    Chain chain;
    const size_t vertexCount = object.positions.size() / 3;
    chain.levels.push_back({object.indices.size() / 3, 0.0, true});
    if (object.indices.empty()) return chain;
    const std::vector<float> positions(object.positions.begin(), object.positions.end());
    std::vector<uint32_t> remap(vertexCount);
    const size_t welded = meshopt_generateVertexRemap(remap.data(), object.indices.data(), object.indices.size(),
                                                      positions.data(), vertexCount, 3 * sizeof(float));
    std::vector<uint32_t> indices(object.indices.size());
    meshopt_remapIndexBuffer(indices.data(), object.indices.data(), object.indices.size(), remap.data());
    std::vector<float> weldedPositions(3 * welded);
    meshopt_remapVertexBuffer(weldedPositions.data(), positions.data(), vertexCount, 3 * sizeof(float), remap.data());
    const float scale = meshopt_simplifyScale(weldedPositions.data(), welded, 3 * sizeof(float));
    std::vector<float> originalFloat(weldedPositions);
    InputObject weldedObject;  // the same surface, welded, for the swapped measurement
    weldedObject.positions.assign(weldedPositions.begin(), weldedPositions.end());
    weldedObject.indices = indices;
    std::vector<ChainLevel> coarseToFine;
    size_t previousCount = 0;
    for (int j = 0;; ++j) {
        const double target = radius * std::pow(2.0, -0.5 * j);
        if (target < finest) break;
        std::vector<uint32_t> out(indices.size());
        const size_t count = meshopt_simplify(out.data(), indices.data(), indices.size(), weldedPositions.data(), welded,
                                              3 * sizeof(float), 0, float(target / scale), 0, nullptr);
        out.resize(count);
        if (count == 0 || count == previousCount || count >= indices.size()) {
            previousCount = count;
            continue;
        }
        previousCount = count;
        // Compact vertices: the error measurement walks every proxy vertex.
        std::vector<uint32_t> compact(welded, ~0u);
        std::vector<float> p;
        for (uint32_t& i : out) {
            if (compact[i] == ~0u) {
                compact[i] = uint32_t(p.size() / 3);
                p.insert(p.end(), &weldedPositions[3 * size_t(i)], &weldedPositions[3 * size_t(i)] + 3);
            }
            i = compact[i];
        }
        ChainLevel level;
        level.triangles = count / 3;
        level.closed = closedMesh(out);
        const double tolerance = 0.05 * target;
        const ProxyError e = measureProxyError(p, out, {&object}, tolerance, 20000);
        if (level.closed) {
            level.error = e.bound();
        } else {
            InputObject proxy;
            proxy.positions.assign(p.begin(), p.end());
            proxy.indices = out;
            const ProxyError swapped = measureProxyError(originalFloat, indices, {&proxy}, tolerance, 20000);
            level.error = std::max(e.proxyToOriginals, swapped.proxyToOriginals);
        }
        coarseToFine.push_back(level);
    }
    chain.levels.insert(chain.levels.end(), coarseToFine.rbegin(), coarseToFine.rend());
    return chain;
}

struct Cost {
    double triangles = 0, drawCalls = 0;
};

struct Row {
    int distance = 0;
    Cost originals, perObject, enclosingPerObject, cut;
    double cutProxies = 0, cutLeaves = 0;
    // --breakdown: the cut's triangles by node kind, beside (b)'s triangles for the same objects.
    // [0] leaves, [1] per-object LOD, [2] one-object aggregates, [3] aggregates of several
    // objects, [4] coarser versions.
    double kindNodes[5] = {}, kindTriangles[5] = {}, kindPerObject[5] = {};
    std::map<uint32_t, double> excess;  ///< --breakdown: (c) - (b) triangles per drawn node (leaf: ~object)
};

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

/// Proxy error and budget per level, relative to the level's delta: what the cut can select.
void printNodeErrors(const testing::Baked& b) {
    // -3: bundles, -2: per-object LOD nodes, -1: coarser versions of aggregates
    std::map<int, std::vector<const HierarchyNode*>> byLevel;
    for (const HierarchyNode& n : b.nodes.nodes)
        if (!n.leaf)
            byLevel[n.bundleStep >= 1 ? -3 : n.objectLod >= 1 ? -2 : n.coarserStep >= 1 ? -1 : n.firstLevel].push_back(&n);
    std::printf("| level | delta | nodes | budget / delta (median) | certified error / delta (median, max) | over budget | proxy triangles | exact triangles |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const auto& [level, nodes] : byLevel) {
        std::vector<double> budget, error;
        size_t over = 0, triangles = 0, exact = 0;
        for (const HierarchyNode* n : nodes) {
            const double delta = n->delta > 0 ? n->delta : 1;
            budget.push_back(n->budget / delta);
            error.push_back(n->error.bound() / delta);
            if (n->error.bound() > n->budget) ++over;
            triangles += n->indices.size() / 3;
            exact += n->exactTriangleCount;
        }
        char name[32];
        std::snprintf(name, sizeof name,
                      level == -3 ? "bundles" : level == -2 ? "object LOD" : level == -1 ? "coarser versions" : "%d", level);
        std::printf("| %s | %.4g | %zu | %.3f | %.3f, %.3f | %zu | %zu | %zu |\n", name, level == -2 ? 0.0 : nodes[0]->delta,
                    nodes.size(), median(budget), median(error), *std::max_element(error.begin(), error.end()), over,
                    triangles, exact);
    }
}

bool runScene(const Options& o, const std::string& name) {
    testing::SceneRequest request;
    request.name = name;
    request.seed = o.seed;
    request.randomObjects = o.objects;
    request.randomTriangles = o.triangles;
    request.sharedDataDir = o.data;
    testing::SceneInput input = testing::loadScene(request);
    if (!input.problem.empty()) {
        std::printf("\n## %s: skipped (%s)\n", name.c_str(), input.problem.c_str());
        return input.problem.rfind("absent: ", 0) == 0;
    }
    // A generated scene as a user bakes it: from the GLB aggrelod_make_sample writes, whose
    // positions are floats. (In doubles its flat faces are exactly flat, where the enclosing
    // simplifier finds many more touching faces and takes several times longer; see
    // docs/proxies.md.)
    if (name != "truck_town")
        for (InputObject& obj : input.objects)
            for (double& x : obj.positions) x = double(static_cast<float>(x));
    const std::vector<InputObject>& objects = input.objects;
    size_t totalTriangles = 0;
    for (const InputObject& obj : objects) totalTriangles += obj.indices.size() / 3;
    const testing::SceneSphere sphere = testing::sceneSphere(objects);
    std::printf("\n## %s: %zu objects, %zu triangles, bounding sphere radius %.4g, up axis %c, %d levels%s\n",
                input.label.c_str(), objects.size(), totalTriangles, sphere.radius, "xyz"[input.upAxis], o.levels,
                input.constantFunction ? ", constant function" : "");

    const testing::Baked b = testing::bakeScene(input, o.levels, o.threads, o.bundles);
    if (!b.ok) {
        std::printf("bake FAILED: %s\n", b.problem.c_str());
        return false;
    }
    runtime::BuildArrays params;
    std::string error;
    std::vector<uint8_t> bytes;
    runtime::RuntimeFile file;
    if (!exportHierarchy(b.nodes, objects, 0, "bench", params, error) ||
        !runtime::writeRuntimeFile(params, bytes, error) ||
        runtime::RuntimeFile::openMemory(bytes.data(), bytes.size(), file, error) != runtime::FileStatus::Ok) {
        std::printf("runtime file FAILED: %s\n", error.c_str());
        return false;
    }
    size_t innerNodes = 0;
    for (const HierarchyNode& n : b.nodes.nodes) innerNodes += n.leaf ? 0 : 1;
    std::printf("bake: %zu levels, %zu inner nodes, %zu roots\n", b.hierarchy.levels.size(), innerNodes, b.nodes.roots.size());

    // Per-object chains, once; the runtime's leaf spheres are the objects' bounding spheres.
    std::vector<float> leafCenter(3 * objects.size()), leafRadius(objects.size());
    for (uint32_t i = 0; i < file.nodeCount(); ++i)
        if (file.isLeaf(i)) {
            const runtime::NodeRecord& n = file.node(i);
            const uint32_t object = file.sources(i)[0];
            std::copy(n.sphereCenter, n.sphereCenter + 3, &leafCenter[3 * object]);
            leafRadius[object] = n.sphereRadius;
        }
    // No camera comes closer to an object than the scene radius (the nearest is 1 diameter
    // from the centre), where 1 px is radius / k. A level's measured error can be a few times
    // below meshoptimizer's target, so targets go on to 1/16 of that; finer ones would not be
    // drawn, and measuring them dominates the run.
    const double k = kViewportHeight / (2.0 * std::tan(kFovY / 2));  // sse = error * k / d
    const double finest = sphere.radius / (16 * k);
    const auto chainStart = std::chrono::steady_clock::now();
    std::vector<Chain> chains(objects.size());
    detail::parallelFor(objects.size(), o.threads,
                        [&](size_t i) { chains[i] = buildChain(objects[i], leafRadius[i], finest); });
    const double chainSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - chainStart).count();
    size_t chainLevels = 0, openLevels = 0;
    for (const Chain& c : chains)
        for (size_t l = 1; l < c.levels.size(); ++l) {
            ++chainLevels;
            openLevels += c.levels[l].closed ? 0 : 1;
        }
    std::printf("per-object LOD: %zu simplified levels (%.1f per object), %zu of them not closed (no inside credit); "
                "targets down to %.3g; chains built and measured in %.2f s\n",
                chainLevels, double(chainLevels) / double(objects.size()), openLevels, finest, chainSeconds);
    // (b'): every object's enclosing versions, as the bake makes them (an open object's from
    // the solid standing in for it alone, a support surface's from a thin solid made for it);
    // objects left out are drawn as they are, as in the cut.
    std::vector<const SolidReport*> standIn(objects.size(), nullptr);
    for (const SolidReport& r : b.hierarchy.solids)
        if (r.objects.size() == 1 && r.objects.front() < objects.size()) standIn[r.objects.front()] = &r;
    std::vector<char> asGiven(objects.size(), 0), support(objects.size(), 0);
    for (uint32_t i : b.hierarchy.supportObjects) support[i] = 1;
    for (uint32_t i : b.hierarchy.leftOutObjects) asGiven[i] = 1;
    std::vector<std::vector<ChainLevel>> enclosing(objects.size());
    ProxySettings versionSettings;
    detail::parallelFor(objects.size(), o.threads, [&](size_t i) {
        if (asGiven[i]) return;
        for (const HierarchyNode& v : enclosingVersions(objects[i], standIn[i], versionSettings, support[i] != 0))
            enclosing[i].push_back({v.indices.size() / 3, v.error.bound(), true});
    });

    // Cameras.
    int a1 = 0, a2 = 1;  // horizontal axes
    if (input.upAxis == 1) a1 = 2, a2 = 0;
    const double elevation = o.elevationDegrees * kPi / 180.0;
    runtime::Selector selector(file);
    std::vector<uint32_t> originalTriangles(objects.size());
    for (size_t i = 0; i < objects.size(); ++i) originalTriangles[i] = uint32_t(objects[i].indices.size() / 3);
    selector.setDrawCosts(originalTriangles.data(), o.drawCallCost);
    runtime::SelectionSettings settings;
    settings.pixelTolerance = kTau;
    settings.coarsenRatio = 1.0f;
    std::vector<Row> rows;
    for (int distance : kDistances) {
        Row row;
        row.distance = distance;
        for (int az = 0; az < kAzimuths; ++az) {
            const double phi = 2 * kPi * az / kAzimuths, radius = distance * 2 * sphere.radius;
            double eye[3] = {sphere.center[0], sphere.center[1], sphere.center[2]};
            eye[a1] += radius * std::cos(elevation) * std::cos(phi);
            eye[a2] += radius * std::cos(elevation) * std::sin(phi);
            eye[input.upAxis] += radius * std::sin(elevation);
            runtime::Camera camera;
            for (int c = 0; c < 3; ++c) camera.position[c] = float(eye[c]);
            camera.fovY = float(kFovY);
            camera.viewportHeight = kViewportHeight;
            std::vector<double> perObjectChoice(objects.size(), 0.0);
            for (size_t i = 0; i < objects.size(); ++i) {
                const size_t t = objects[i].indices.size() / 3;
                row.originals.triangles += double(t);
                row.originals.drawCalls += t ? 1 : 0;
                double d2 = 0;
                for (int c = 0; c < 3; ++c) d2 += (eye[c] - leafCenter[3 * i + c]) * (eye[c] - leafCenter[3 * i + c]);
                const double d = std::max(std::sqrt(d2) - leafRadius[i], 1e-6);
                size_t best = t;
                for (const ChainLevel& level : chains[i].levels)
                    if (level.error * k / d <= kTau) best = std::min(best, level.triangles);
                row.perObject.triangles += double(best);
                row.perObject.drawCalls += t ? 1 : 0;
                perObjectChoice[i] = double(best);
                size_t enclosed = t;
                for (const ChainLevel& level : enclosing[i])
                    if (level.error * k / d <= kTau) enclosed = std::min(enclosed, level.triangles);
                row.enclosingPerObject.triangles += double(enclosed);
                row.enclosingPerObject.drawCalls += t ? 1 : 0;
            }
            selector.reset();
            selector.selectFull(camera, settings);
            for (uint32_t n : selector.proxyNodes()) row.cut.triangles += double(file.triangles(n).size / 3);
            for (uint32_t obj : selector.originalObjects()) row.cut.triangles += double(objects[obj].indices.size() / 3);
            row.cutProxies += double(selector.proxyNodes().size);
            row.cutLeaves += double(selector.originalObjects().size);
            for (uint32_t n : selector.proxyNodes()) {
                const runtime::NodeRecord& r = file.node(n);
                const int kind = r.level == runtime::kObjectLodLevel ? 1
                                 : r.level == runtime::kCoarserLevel ? 4
                                 : r.sourceCount == 1               ? 2
                                                                    : 3;
                row.kindNodes[kind] += 1;
                row.kindTriangles[kind] += double(file.triangles(n).size / 3);
                double b = 0;
                for (uint32_t obj : file.sources(n)) b += perObjectChoice[obj];
                row.kindPerObject[kind] += b;
                row.excess[n] += double(file.triangles(n).size / 3) - b;
            }
            for (uint32_t obj : selector.originalObjects()) {
                row.kindNodes[0] += 1;
                row.kindTriangles[0] += double(objects[obj].indices.size() / 3);
                row.kindPerObject[0] += perObjectChoice[obj];
                row.excess[~obj] += double(objects[obj].indices.size() / 3) - perObjectChoice[obj];
            }
        }
        for (Cost* c : {&row.originals, &row.perObject, &row.enclosingPerObject, &row.cut}) {
            c->triangles /= kAzimuths;
            c->drawCalls /= kAzimuths;
        }
        row.cutProxies /= kAzimuths;
        row.cutLeaves /= kAzimuths;
        row.cut.drawCalls = row.cutProxies + row.cutLeaves;
        for (int kind = 0; kind < 5; ++kind) {
            row.kindNodes[kind] /= kAzimuths;
            row.kindTriangles[kind] /= kAzimuths;
            row.kindPerObject[kind] /= kAzimuths;
        }
        rows.push_back(row);
    }
    std::printf("\nmeans per camera over %d azimuths, elevation %.0f deg, %d x %d px, fov 60 deg, tau %.0f px:\n",
                kAzimuths, o.elevationDegrees, 1920, int(kViewportHeight), double(kTau));
    std::printf("| distance (diameters) | (a) triangles | (a) draws | (b) triangles | (b) draws | (b') triangles | "
                "(c) triangles | (c) draws (proxies + leaves) | (c)/(b) triangles | (c)/(b') triangles | (c)/(a) draws |\n");
    std::printf("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const Row& r : rows)
        std::printf("| %d | %.0f | %.0f | %.1f | %.0f | %.1f | %.1f | %.1f (%.1f + %.1f) | %.2f | %.2f | %.3f |\n", r.distance,
                    r.originals.triangles, r.originals.drawCalls, r.perObject.triangles, r.perObject.drawCalls,
                    r.enclosingPerObject.triangles, r.cut.triangles, r.cut.drawCalls, r.cutProxies, r.cutLeaves,
                    r.cut.triangles / r.perObject.triangles, r.cut.triangles / r.enclosingPerObject.triangles,
                    r.cut.drawCalls / r.originals.drawCalls);
    if (o.breakdown) {
        std::printf("\nthe cut by node kind: nodes, (c) triangles / (b) triangles of the same objects:\n");
        std::printf("| distance | leaves | per-object LOD | one-object aggregates | aggregates | coarser versions |\n");
        std::printf("|---:|---:|---:|---:|---:|---:|\n");
        for (const Row& r : rows) {
            std::printf("| %d |", r.distance);
            for (int kind = 0; kind < 5; ++kind)
                std::printf(" %.1f: %.0f / %.0f |", r.kindNodes[kind], r.kindTriangles[kind], r.kindPerObject[kind]);
            std::printf("\n");
        }
        std::printf("\nnodes costing the most triangles over (b) for the same objects (mean per camera):\n");
        const char* kindName[] = {"original", "per-object LOD", "aggregate", "coarser version"};
        for (const Row& r : rows) {
            std::vector<std::pair<double, uint32_t>> worst;
            for (const auto& [node, e] : r.excess) worst.push_back({-e, node});
            std::sort(worst.begin(), worst.end());
            std::printf("%d diameters:", r.distance);
            for (size_t j = 0; j < std::min<size_t>(worst.size(), 4); ++j) {
                const uint32_t node = worst[j].second;
                const bool leaf = node > file.nodeCount();
                const uint32_t first = leaf ? ~node : file.sources(node)[0];
                const uint32_t level = leaf ? 0 : file.node(node).level;
                const int kind = leaf ? 0 : level == runtime::kObjectLodLevel ? 1 : level == runtime::kCoarserLevel ? 3 : 2;
                std::printf(" %s %s (%u objects, %zu triangles, error %.3g) +%.0f;", kindName[kind],
                            objects[first].name.c_str(), leaf ? 1u : file.node(node).sourceCount,
                            leaf ? objects[first].indices.size() / 3 : file.triangles(node).size / 3,
                            leaf ? 0.0 : double(file.node(node).geometricError), -worst[j].first / kAzimuths);
            }
            std::printf("\n");
        }
    }
    int pass = 0, fail = 0;
    auto goal = [&](bool ok, const std::string& text) {
        std::printf("%s  %s\n", ok ? "PASS" : "FAIL", text.c_str());
        (ok ? pass : fail)++;
    };
    for (const Row& r : rows) {
        const double ratio = r.cut.triangles / r.perObject.triangles;
        char text[160];
        const double limit = r.distance <= 2 ? 1.1 : 1.0;
        std::snprintf(text, sizeof text, "%s triangles (c) <= %.1f x (b) at %d diameters: %.2f", input.label.c_str(), limit,
                      r.distance, ratio);
        goal(ratio <= limit, text);
        if (r.distance == 16) {
            std::snprintf(text, sizeof text, "%s triangles (c) <= (b) / 3 at 16 diameters: %.2f (<= 0.33)",
                          input.label.c_str(), ratio);
            goal(3 * r.cut.triangles <= r.perObject.triangles, text);
            std::snprintf(text, sizeof text, "%s draw calls (c) <= (a) / 10 at 16 diameters: %.1f of %.0f (%.3f)",
                          input.label.c_str(), r.cut.drawCalls, r.originals.drawCalls,
                          r.cut.drawCalls / r.originals.drawCalls);
            goal(10 * r.cut.drawCalls <= r.originals.drawCalls, text);
        }
    }
    std::printf("goals: %d PASS, %d FAIL\n", pass, fail);

    std::printf("\nnode errors per level (budget and certified error relative to the level's delta):\n");
    printNodeErrors(b);

    const double bakeSeconds = b.hierarchySeconds + b.proxySeconds;
    std::printf("\nbake stages (timings vary run to run):\n| stage | seconds | share of bake |\n|---|---:|---:|\n");
    for (const auto& [stage, seconds] : b.hierarchy.timings)
        std::printf("| %s | %.3f | %.1f %% |\n", stage.c_str(), seconds, 100.0 * seconds / bakeSeconds);
    std::printf("| **proxies** (buildHierarchyNodes) | %.3f | **%.1f %%** |\n", b.proxySeconds,
                100.0 * b.proxySeconds / bakeSeconds);
    std::printf("| whole bake | %.3f | 100 %% |\n", bakeSeconds);
    return true;
}

std::vector<std::string> split(const std::string& list) {
    std::vector<std::string> out;
    std::stringstream s(list);
    for (std::string item; std::getline(s, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    Options o;
    std::string cutFor, cameras;  // --cut-for / --cameras (lod_budget_cut_for.h)
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--breakdown") {
            o.breakdown = true;
            continue;
        }
        const char* value = i + 1 < argc ? argv[i + 1] : nullptr;
        if (!value) {
            std::fprintf(stderr, "%s: missing value\n", arg.c_str());
            return 2;
        }
        ++i;
        if (arg == "--scenes") o.scenes = split(value);
        else if (arg == "--seed") o.seed = uint32_t(std::atoi(value));
        else if (arg == "--objects") o.objects = std::atoi(value);
        else if (arg == "--triangles") o.triangles = std::atoi(value);
        else if (arg == "--levels") o.levels = std::atoi(value);
        else if (arg == "--threads") o.threads = std::atoi(value);
        else if (arg == "--bundles") o.bundles = std::atoi(value);
        else if (arg == "--draw-call-cost") o.drawCallCost = float(std::atof(value));
        else if (arg == "--elevation") o.elevationDegrees = std::atof(value);
        else if (arg == "--data") o.data = value;
        else if (arg == "--cut-for") cutFor = value;
        else if (arg == "--cameras") cameras = value;
        else {
            std::fprintf(stderr, "unknown option %s (see the comment at the top of bench_lod_budget.cpp)\n", arg.c_str());
            return 2;
        }
    }
    if (!cutFor.empty()) return lod_budget::printCutsForCameras(cutFor, cameras);
    std::printf("bench_lod_budget: seed %u; random scene = samples::makeRandomScene(%d objects, %d triangles, seed) "
                "(= aggrelod_make_sample random --objects %d --triangles %d --seed %u), generated scenes rounded to float as in "
                "their GLB; %d levels; threads %d\n",
                o.seed, o.objects, o.triangles, o.objects, o.triangles, o.seed, o.levels, o.threads);
    bool ok = true;
    for (const std::string& scene : o.scenes) ok = runScene(o, scene) && ok;
    return ok ? 0 : 1;
}
