// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: ray-cast renders of the baked levels (`aggrelod render`). Each pixel casts
// rays through the runtime collision world (Embree, wrapped in runtime/src/collision_embree.cpp)
// over the cut of one level; the hit node picks a colour from a fixed palette (originals grey)
// and its normal a Lambert shade under a headlight. Works on a runtime file (.aglod) or on a
// levels.glb, which is turned into an in-memory runtime file (one leaf per mesh node).
#pragma once

#include <aggrelod/runtime_file.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace aggrelod::render {

/// A pinhole camera. World units.
struct Camera {
    float eye[3] = {0, 0, 0};
    float target[3] = {0, 0, -1};
    float up[3] = {0, 1, 0};    ///< the image's up direction (need not be unit length)
    float fovYDegrees = 25.0f;  ///< vertical field of view
};

/// Which world axis is up: glTF says y, but many scenes (the samples too) are built z-up.
enum class UpAxis { Auto, Y, Z };

/// RGB pixels, rows top-down, width * height * 3 bytes.
struct RgbImage {
    int width = 0, height = 0;
    std::vector<unsigned char> pixels;
};

/// One picture the scene offers: the originals or one level.
/// Panel level of "what the runtime draws from N scene diameters away": kDrawnAtLevel + N.
constexpr uint32_t kDrawnAtLevel = 0xFF80u;
/// The distances (scene diameters from the centre) of the drawn-cut panels of a .aglod.
constexpr uint32_t kDrawnAtDistances[] = {4, 16};

struct Panel {
    std::string label;            ///< e.g. "LEVEL 2  DELTA 0.5" or "ORIGINALS"
    /// runtime::kLeafLevel for the originals, kObjectLodLevel for the per-object LODs,
    /// kDrawnAtLevel + N for the cut drawn from N scene diameters
    uint32_t level = 0;
    std::vector<uint32_t> nodes;  ///< the cut: runtime-file nodes drawn
};

/// A scene ready to render: the runtime file (mapped .aglod, or built from a levels.glb),
/// the panels and the colour of every node.
class RenderScene {
public:
    RenderScene();
    ~RenderScene();
    RenderScene(const RenderScene&) = delete;
    RenderScene& operator=(const RenderScene&) = delete;

    /// Opens a .aglod (panels: the originals, the coarsest per-object LODs when the file has
    /// any, every aggregate level, then the cut the runtime's selection draws for a camera at
    /// kDrawnAtDistances scene diameters from the centre, 1080 px high, 60 degree field of
    /// view, tau 1 px: proxies of any kind, coarser versions included) or a levels.glb (panels:
    /// every level). False with a message naming the file and the problem.
    bool open(const std::string& path, std::string& error);

    const runtime::RuntimeFile& file() const { return file_; }
    const std::vector<Panel>& panels() const { return panels_; }
    /// Index into panels() of `level` (runtime::kLeafLevel: the originals); -1 if absent.
    int panelOfLevel(uint32_t level) const;
    /// "originals, 0, 1, ..." for messages.
    std::string levelList() const;
    /// Colour of a node: grey for an original object, else a palette colour fixed by the node.
    const unsigned char* colourOf(uint32_t node) const { return &colours_[size_t(node) * 3]; }
    /// Axis-aligned bounds of the first panel's nodes (the originals of a .aglod, the finest
    /// level of a levels.glb), world units.
    void bounds(float lo[3], float hi[3]) const;

private:
    runtime::RuntimeFile file_;
    std::unique_ptr<unsigned char[]> storage_;  ///< aligned bytes of a file built in memory
    std::vector<Panel> panels_;
    std::vector<unsigned char> colours_;  ///< 3 per node
};

/// The up axis of `requested`; Auto picks, of y and z, the one along which the scene is
/// thinner (a town, a forest or a board is flatter than it is wide).
UpAxis resolveUpAxis(const RenderScene& scene, UpAxis requested);

/// The default view: from the front-right, 30 degrees above the ground plane of `up`
/// (Y or Z), fitting the scene's box.
Camera defaultCamera(const RenderScene& scene, int width, int height, UpAxis up);

/// Grey of the original objects and the background colour (RGB).
extern const unsigned char kOriginalGrey[3];
extern const unsigned char kBackground[3];

/// Renders one panel at width x height pixels (2 x 2 rays per pixel), with `threads` threads
/// (0: 2). The same inputs give the same pixels for any thread count.
bool renderPanel(const RenderScene& scene, size_t panel, const Camera& camera, int width, int height,
                 unsigned threads, RgbImage& out, std::string& error);

/// Lays panels out in a grid of `columns` columns (0: up to 4), each with its label above it.
RgbImage composeSheet(const std::vector<RgbImage>& panels, const std::vector<std::string>& labels,
                      int columns);

}  // namespace aggrelod::render
