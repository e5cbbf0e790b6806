// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: ray-cast renders of the levels (render.h). Not an algorithm of the paper: a
// viewer for its Figs. 9-10 style level sheets. Rays go through the runtime CollisionWorld
// (Embree lives only in runtime/src/collision_embree.cpp).
#include "render.h"

#include "raster.h"
#include "runtime_export.h"
#include "scene_io.h"

#include <aggrelod/collision.h>
#include <aggrelod/selection.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <thread>

namespace aggrelod::render {

const unsigned char kOriginalGrey[3] = {150, 150, 150};
const unsigned char kBackground[3] = {246, 246, 243};

namespace {

using runtime::kLeafLevel;

// Twelve well-separated colours (Tableau-like); a node's colour is fixed by its index, so a
// node keeps its colour on every level where it is drawn. None of them is grey.
constexpr unsigned char kPalette[][3] = {
    {31, 119, 180}, {255, 127, 14}, {44, 160, 44}, {214, 39, 40},  {148, 103, 189}, {140, 86, 75},
    {227, 119, 194}, {188, 189, 34}, {23, 190, 207}, {174, 199, 232}, {255, 187, 120}, {152, 223, 138},
};
constexpr size_t kPaletteSize = sizeof(kPalette) / sizeof(kPalette[0]);

std::string formatDelta(double d) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", d);
    return buf;
}

std::string lowerExtension(const std::string& path) {
    std::string e = std::filesystem::path(path).extension().string();
    for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
    return e;
}

/// A levels.glb as a runtime file: every mesh node one root leaf standing for one "object".
bool buildParamsFromLevels(const std::vector<io::LevelsGlbNode>& nodes, runtime::BuildArrays& params,
                           std::string& error) {
    for (size_t i = 0; i < nodes.size(); ++i) {
        const io::LevelsGlbNode& n = nodes[i];
        runtime::NodeRecord b;
        b.firstSource = uint32_t(params.sourceObjects.size());
        b.sourceCount = 1;
        params.sourceObjects.push_back(uint32_t(i));
        b.level = runtime::kLeafLevel;
        float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
        std::vector<float> positions(n.positions.size());
        for (size_t k = 0; k < n.positions.size(); ++k) {
            const float v = float(n.positions[k]);
            if (!std::isfinite(v)) {
                error = "node '" + n.name + "' has a non-finite coordinate";
                return false;
            }
            positions[k] = v;
            lo[k % 3] = std::min(lo[k % 3], v);
            hi[k % 3] = std::max(hi[k % 3], v);
        }
        RenderMesh mesh;  // the writer wants normals; the panels colour by group
        if (!buildRenderMesh(positions, n.indices, {}, mesh)) {
            error = "node '" + n.name + "' has a triangle index out of range";
            return false;
        }
        b.firstVertex = uint32_t(params.positions.size() / 3);
        b.vertexCount = uint32_t(mesh.positions.size() / 3);
        b.firstIndex = uint32_t(params.indices.size());
        b.indexCount = uint32_t(mesh.indices.size());
        params.positions.insert(params.positions.end(), mesh.positions.begin(), mesh.positions.end());
        params.normals.insert(params.normals.end(), mesh.normals.begin(), mesh.normals.end());
        params.colors.insert(params.colors.end(), mesh.colors.begin(), mesh.colors.end());
        if (n.positions.empty()) std::fill(lo, lo + 3, 0.0f), std::fill(hi, hi + 3, 0.0f);
        float r2 = 0;
        for (int k = 0; k < 3; ++k) {
            b.boundsMin[k] = lo[k];
            b.boundsMax[k] = hi[k];
            b.sphereCenter[k] = 0.5f * (lo[k] + hi[k]);
            r2 += 0.25f * (hi[k] - lo[k]) * (hi[k] - lo[k]);
        }
        b.sphereRadius = std::sqrt(r2) * 1.0001f;
        params.indices.insert(params.indices.end(), mesh.indices.begin(), mesh.indices.end());
        params.nodes.push_back(b);
        params.objectNames.push_back(n.name);
    }
    return true;
}

struct Vec {
    float x, y, z;
};
Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator*(Vec a, float s) { return {a.x * s, a.y * s, a.z * s}; }
float dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec cross(Vec a, Vec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec normalize(Vec a) {
    const float l = std::sqrt(dot(a, a));
    return l > 0 ? a * (1.0f / l) : a;
}

}  // namespace

RenderScene::RenderScene() = default;
RenderScene::~RenderScene() = default;

bool RenderScene::open(const std::string& path, std::string& error) {
    panels_.clear();
    colours_.clear();
    const std::string ext = lowerExtension(path);
    std::vector<io::LevelsGlbNode> glbNodes;
    if (ext == ".glb" || ext == ".gltf") {
        if (!io::readLevelsGlb(path, glbNodes, error)) return false;
        runtime::BuildArrays params;
        params.toolVersion = "render";
        if (!buildParamsFromLevels(glbNodes, params, error)) {
            error = path + ": " + error;
            return false;
        }
        std::vector<uint8_t> bytes;
        if (!runtime::writeRuntimeFile(params.params(), bytes, error)) {
            error = path + ": " + error;
            return false;
        }
        storage_.reset(new unsigned char[bytes.size() + 16]);
        unsigned char* aligned = storage_.get();
        while (reinterpret_cast<uintptr_t>(aligned) % 16 != 0) ++aligned;
        std::memcpy(aligned, bytes.data(), bytes.size());
        std::string message;
        const runtime::FileStatus status = runtime::RuntimeFile::openMemory(aligned, bytes.size(), file_, message);
        if (status != runtime::FileStatus::Ok) {
            error = path + ": " + runtime::toString(status) + (message.empty() ? "" : ": " + message);
            return false;
        }
        // Panels: one per level, in increasing level; colours by group (singletons grey).
        std::vector<uint32_t> levels;
        for (const auto& n : glbNodes) levels.push_back(n.level);
        std::sort(levels.begin(), levels.end());
        levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
        for (uint32_t level : levels) {
            Panel panel;
            panel.level = level;
            double delta = 0;
            for (uint32_t i = 0; i < glbNodes.size(); ++i)
                if (glbNodes[i].level == level) {
                    panel.nodes.push_back(i);
                    delta = glbNodes[i].delta;
                }
            panel.label = "LEVEL " + std::to_string(level) + "  DELTA " + formatDelta(delta);
            panels_.push_back(std::move(panel));
        }
        colours_.resize(glbNodes.size() * 3);
        for (size_t i = 0; i < glbNodes.size(); ++i) {
            const unsigned char* c = glbNodes[i].sourceCount == 1 ? kOriginalGrey : kPalette[glbNodes[i].group % kPaletteSize];
            std::copy(c, c + 3, &colours_[i * 3]);
        }
        return true;
    }

    std::string message;
    const runtime::FileStatus status = runtime::RuntimeFile::openFile(path, file_, message);
    if (status != runtime::FileStatus::Ok) {
        error = path + ": " + runtime::toString(status) + (message.empty() ? "" : ": " + message) +
                (ext == ".aglod" ? "" : " (render reads a .aglod runtime file or a levels.glb)");
        return false;
    }
    Panel originals;
    originals.level = kLeafLevel;
    originals.label = "ORIGINALS";
    runtime::cutAtLevel(file_, kLeafLevel, originals.nodes);
    panels_.push_back(std::move(originals));
    bool anyObjectLod = false;
    for (uint32_t i = 0; i < file_.nodeCount(); ++i) anyObjectLod = anyObjectLod || file_.isObjectLod(i);
    if (anyObjectLod) {
        // The coarsest simplified version of every object, before any aggregation.
        Panel objectLods;
        objectLods.level = runtime::kObjectLodLevel;
        objectLods.label = "OBJECT LODS";
        runtime::cutAtLevel(file_, runtime::kObjectLodLevel, objectLods.nodes);
        panels_.push_back(std::move(objectLods));
    }
    for (uint32_t level : runtime::levelsOf(file_)) {
        Panel panel;
        panel.level = level;
        runtime::cutAtLevel(file_, level, panel.nodes);
        double delta = 0;
        for (uint32_t n : panel.nodes) {
            // The level's aggregates, or bundles standing for those that gave way (the cut
            // passes through every other bundle).
            const uint32_t l = file_.node(n).level;
            if (!file_.isLeaf(n) && (l == level || (runtime::isBundleLevel(l) && (l & ~runtime::kBundleLevelFlag) == level)))
                delta = file_.node(n).delta;
        }
        panel.label = "LEVEL " + std::to_string(level) + "  DELTA " + formatDelta(delta);
        panels_.push_back(std::move(panel));
    }
    // What the runtime draws from far away, seen up close: a camera on the diagonal at N
    // scene diameters from the centre of the originals' box.
    float lo[3], hi[3];
    bounds(lo, hi);
    const float diameter = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                     (hi[2] - lo[2]) * (hi[2] - lo[2]));
    runtime::Selector selector(file_);
    runtime::SelectionSettings settings;
    settings.pixelTolerance = 1.0f;
    settings.coarsenRatio = 1.0f;
    for (uint32_t distance : kDrawnAtDistances) {
        runtime::Camera camera;
        for (int k = 0; k < 3; ++k)
            camera.position[k] = 0.5f * (lo[k] + hi[k]) + float(distance) * diameter / std::sqrt(3.0f);
        camera.fovY = float(3.14159265358979323846 / 3);
        camera.viewportHeight = 1080.0f;
        selector.reset();
        selector.selectFull(camera, settings);
        Panel panel;
        panel.level = kDrawnAtLevel + distance;
        panel.nodes.assign(selector.cut().begin(), selector.cut().end());
        std::sort(panel.nodes.begin(), panel.nodes.end());
        size_t triangles = 0;
        for (uint32_t n : panel.nodes) triangles += file_.node(n).indexCount / 3;
        panel.label = "FROM " + std::to_string(distance) + " DIAM  " + std::to_string(triangles) + " TRI";
        panels_.push_back(std::move(panel));
    }
    colours_.resize(size_t(file_.nodeCount()) * 3);
    for (uint32_t i = 0; i < file_.nodeCount(); ++i) {
        const unsigned char* c = file_.isLeaf(i) ? kOriginalGrey : kPalette[i % kPaletteSize];
        std::copy(c, c + 3, &colours_[size_t(i) * 3]);
    }
    return true;
}

int RenderScene::panelOfLevel(uint32_t level) const {
    for (size_t i = 0; i < panels_.size(); ++i)
        if (panels_[i].level == level) return int(i);
    return -1;
}

std::string RenderScene::levelList() const {
    std::string s;
    for (const Panel& p : panels_) {
        if (!s.empty()) s += ", ";
        s += p.level == kLeafLevel                ? std::string("originals")
             : p.level == runtime::kObjectLodLevel ? std::string("object-lods")
             : p.level > kDrawnAtLevel             ? "drawn-at-" + std::to_string(p.level - kDrawnAtLevel)
                                                   : std::to_string(p.level);
    }
    return s;
}

void RenderScene::bounds(float lo[3], float hi[3]) const {
    for (int k = 0; k < 3; ++k) lo[k] = -1, hi[k] = 1;
    if (panels_.empty()) return;
    for (int k = 0; k < 3; ++k) lo[k] = INFINITY, hi[k] = -INFINITY;
    // The first panel (the originals, or the finest level of a levels.glb): coarse proxies
    // may bulge out, but the view should fit the objects themselves.
    for (uint32_t r : panels_.front().nodes) {
        const runtime::NodeRecord& n = file_.node(r);
        for (int k = 0; k < 3; ++k) {
            lo[k] = std::min(lo[k], n.boundsMin[k]);
            hi[k] = std::max(hi[k], n.boundsMax[k]);
        }
    }
    if (!(lo[0] <= hi[0])) {
        for (int k = 0; k < 3; ++k) lo[k] = -1, hi[k] = 1;
    }
}

UpAxis resolveUpAxis(const RenderScene& scene, UpAxis requested) {
    if (requested != UpAxis::Auto) return requested;
    float lo[3], hi[3];
    scene.bounds(lo, hi);
    return hi[2] - lo[2] <= hi[1] - lo[1] ? UpAxis::Z : UpAxis::Y;
}

Camera defaultCamera(const RenderScene& scene, int width, int height, UpAxis upAxis) {
    if (scene.panels().empty()) return Camera{};
    float lo[3], hi[3];
    scene.bounds(lo, hi);
    Vec centre{0.5f * (lo[0] + hi[0]), 0.5f * (lo[1] + hi[1]), 0.5f * (lo[2] + hi[2])};
    // Ground-plane axes (a to the right, b towards the viewer) and the up axis.
    const bool zUp = resolveUpAxis(scene, upAxis) == UpAxis::Z;
    const Vec worldUp = zUp ? Vec{0, 0, 1} : Vec{0, 1, 0};
    const Vec a{1, 0, 0}, b = zUp ? Vec{0, -1, 0} : Vec{0, 0, 1};
    // From the front-right, 30 degrees above the ground plane.
    const float azimuth = 0.6f, elevation = 0.52f;
    const Vec toEye = (a * std::sin(azimuth) + b * std::cos(azimuth)) * std::cos(elevation) + worldUp * std::sin(elevation);
    Camera camera;
    const float tanY = std::tan(camera.fovYDegrees * 0.5f * 3.14159265f / 180.0f);
    const float tanX = tanY * float(width) / float(std::max(1, height));
    const Vec forward = toEye * -1.0f;
    const Vec right = normalize(cross(forward, worldUp));
    const Vec up = cross(right, forward);
    // Smallest distance that keeps every vertex of the first panel inside the view (5 % margin);
    // then the target moves to the middle of what is seen, and the distance is fitted again.
    const runtime::RuntimeFile& file = scene.file();
    auto forEachVertex = [&](auto&& f) {
        for (uint32_t node : scene.panels().front().nodes) {
            const runtime::Span<float> v = file.vertices(node);
            for (size_t i = 0; i + 2 < v.size; i += 3) f(Vec{v[i], v[i + 1], v[i + 2]});
        }
    };
    auto fitDistance = [&](Vec c) {
        float d = 0;
        forEachVertex([&](Vec q) {
            const Vec p = q - c;
            const float depth = dot(p, forward);
            d = std::max(d, std::fabs(dot(p, right)) / (0.95f * tanX) - depth);
            d = std::max(d, std::fabs(dot(p, up)) / (0.95f * tanY) - depth);
        });
        return std::max(d, 1e-3f);
    };
    float distance = fitDistance(centre);
    {
        float x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
        forEachVertex([&](Vec q) {
            const Vec p = q - centre;
            const float depth = std::max(1e-6f, distance + dot(p, forward));
            x0 = std::min(x0, dot(p, right) / depth), x1 = std::max(x1, dot(p, right) / depth);
            y0 = std::min(y0, dot(p, up) / depth), y1 = std::max(y1, dot(p, up) / depth);
        });
        if (x0 <= x1 && y0 <= y1) centre = centre + right * (0.5f * (x0 + x1) * distance) + up * (0.5f * (y0 + y1) * distance);
        distance = fitDistance(centre);
    }
    distance = std::max(distance, 1e-3f);
    const Vec eye = centre + toEye * distance;
    camera.eye[0] = eye.x, camera.eye[1] = eye.y, camera.eye[2] = eye.z;
    camera.target[0] = centre.x, camera.target[1] = centre.y, camera.target[2] = centre.z;
    camera.up[0] = worldUp.x, camera.up[1] = worldUp.y, camera.up[2] = worldUp.z;
    return camera;
}

bool renderPanel(const RenderScene& scene, size_t panelIndex, const Camera& camera, int width, int height,
                 unsigned threads, RgbImage& out, std::string& error) {
    if (panelIndex >= scene.panels().size()) {
        error = "no panel " + std::to_string(panelIndex);
        return false;
    }
    if (width < 1 || height < 1 || width > 16384 || height > 16384) {
        error = "image size " + std::to_string(width) + "x" + std::to_string(height) + " is out of range (1..16384)";
        return false;
    }
    const Vec eye{camera.eye[0], camera.eye[1], camera.eye[2]};
    const Vec target{camera.target[0], camera.target[1], camera.target[2]};
    Vec forward = target - eye;
    if (!(dot(forward, forward) > 0) || !(camera.fovYDegrees > 0 && camera.fovYDegrees < 180)) {
        error = "bad camera: the eye must differ from the target and the field of view lie in (0, 180) degrees";
        return false;
    }
    forward = normalize(forward);
    Vec worldUp = normalize(Vec{camera.up[0], camera.up[1], camera.up[2]});
    if (!(dot(worldUp, worldUp) > 0)) worldUp = Vec{0, 1, 0};
    if (std::fabs(dot(forward, worldUp)) > 0.999f) {  // looking straight along up: any other up
        worldUp = std::fabs(forward.x) < 0.9f ? Vec{1, 0, 0} : Vec{0, 1, 0};
    }
    const Vec right = normalize(cross(forward, worldUp));
    const Vec up = cross(right, forward);
    const float tanY = std::tan(camera.fovYDegrees * 0.5f * 3.14159265f / 180.0f);
    const float tanX = tanY * float(width) / float(height);

    // One Embree build thread: the BVH, and so which of two coincident triangles is hit, is
    // then the same on every run.
    runtime::CollisionWorld world(scene.file(), 1);
    if (!world.ok()) {
        error = "Embree: " + world.error();
        return false;
    }
    const Panel& panel = scene.panels()[panelIndex];
    world.useCut(panel.nodes.data(), panel.nodes.size());
    if (!world.ok()) {
        error = "Embree: " + world.error();
        return false;
    }

    out.width = width;
    out.height = height;
    out.pixels.assign(size_t(width) * height * 3, 0);
    const float maxDistance = std::numeric_limits<float>::infinity();
    auto renderRows = [&](int first, int step) {
        const float o[3] = {eye.x, eye.y, eye.z};
        for (int y = first; y < height; y += step) {
            for (int x = 0; x < width; ++x) {
                float sum[3] = {0, 0, 0};
                for (int s = 0; s < 4; ++s) {  // 2 x 2 rays per pixel
                    const float px = (2.0f * (x + 0.25f + 0.5f * float(s & 1)) / float(width) - 1.0f) * tanX;
                    const float py = (1.0f - 2.0f * (y + 0.25f + 0.5f * float(s >> 1)) / float(height)) * tanY;
                    const Vec d = normalize(forward + right * px + up * py);
                    const float dir[3] = {d.x, d.y, d.z};
                    runtime::CollisionHit hit;
                    if (world.raycast(o, dir, maxDistance, hit) && hit.node < scene.file().nodeCount()) {
                        const Vec n{hit.normal[0], hit.normal[1], hit.normal[2]};
                        // Headlight Lambert (two-sided) plus ambient.
                        const float shade = 0.3f + 0.7f * std::fabs(dot(n, d));
                        const unsigned char* c = scene.colourOf(hit.node);
                        for (int k = 0; k < 3; ++k) sum[k] += float(c[k]) * shade;
                    } else {
                        for (int k = 0; k < 3; ++k) sum[k] += float(kBackground[k]);
                    }
                }
                unsigned char* p = &out.pixels[(size_t(y) * width + x) * 3];
                for (int k = 0; k < 3; ++k) p[k] = static_cast<unsigned char>(std::lround(std::min(255.0f, sum[k] * 0.25f)));
            }
        }
    };
    const unsigned count = std::max(1u, std::min(threads == 0 ? 2u : threads, 64u));
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < count; ++t) pool.emplace_back(renderRows, int(t), int(count));
    renderRows(0, int(count));
    for (std::thread& t : pool) t.join();
    if (!world.ok()) {
        error = "Embree: " + world.error();
        return false;
    }
    return true;
}

RgbImage composeSheet(const std::vector<RgbImage>& panels, const std::vector<std::string>& labels, int columns) {
    RgbImage sheet;
    if (panels.empty()) return sheet;
    const int n = int(panels.size());
    const int cols = columns > 0 ? std::min(columns, n) : std::min(n, 4);
    const int rows = (n + cols - 1) / cols;
    int cellW = 0, cellH = 0;
    for (const RgbImage& p : panels) cellW = std::max(cellW, p.width), cellH = std::max(cellH, p.height);
    const int scale = cellW >= 480 ? 3 : 2, labelH = 7 * scale + 10, gap = 4;
    sheet.width = cols * cellW + (cols + 1) * gap;
    sheet.height = rows * (cellH + labelH) + (rows + 1) * gap;
    sheet.pixels.assign(size_t(sheet.width) * sheet.height * 3, 255);
    const unsigned char textColour[3] = {20, 20, 20};
    for (int i = 0; i < n; ++i) {
        const int x0 = gap + (i % cols) * (cellW + gap);
        const int y0 = gap + (i / cols) * (cellH + labelH + gap);
        if (i < int(labels.size())) io::drawText(sheet.pixels, sheet.width, sheet.height, x0 + 4, y0 + 5, labels[size_t(i)], textColour, scale);
        const RgbImage& p = panels[size_t(i)];
        for (int y = 0; y < p.height; ++y)
            std::memcpy(&sheet.pixels[(size_t(y0 + labelH + y) * sheet.width + x0) * 3], &p.pixels[size_t(y) * p.width * 3],
                        size_t(p.width) * 3);
    }
    return sheet;
}

}  // namespace aggrelod::render
