// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: `aggrelod render` (commands_render.h): renders one level or a sheet of all
// levels of a .aglod or levels.glb to PNG.
#include "commands_render.h"

#include "raster.h"
#include "render.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace aggrelod::cli {
namespace {

enum ExitCode { kOk = 0, kUsage = 1, kFileError = 2, kRenderFailed = 4 };

void printError(const std::string& message) { std::fprintf(stderr, "aggrelod: error: %s\n", message.c_str()); }

bool parseSize(const std::string& text, int& width, int& height) {
    const size_t x = text.find_first_of("xX");
    if (x == std::string::npos) return false;
    char* end = nullptr;
    const long w = std::strtol(text.c_str(), &end, 10);
    if (end != text.c_str() + x) return false;
    const long h = std::strtol(text.c_str() + x + 1, &end, 10);
    if (*end != '\0' || x + 1 == text.size()) return false;
    if (w < 16 || h < 16 || w > 8192 || h > 8192) return false;
    width = int(w);
    height = int(h);
    return true;
}

}  // namespace

int runRender(const RenderOptions& o) {
    int width = o.sheet ? 400 : 640, height = o.sheet ? 300 : 480;
    if (!o.size.empty() && !parseSize(o.size, width, height)) {
        printError("--size '" + o.size + "': expected WIDTHxHEIGHT, each 16..8192 pixels (e.g. 640x480)");
        return kUsage;
    }
    if (!o.camera.empty() && o.camera.size() != 6 && o.camera.size() != 7) {
        printError("--camera: expected x,y,z,tx,ty,tz[,fovDegrees] (6 or 7 numbers), got " +
                   std::to_string(o.camera.size()));
        return kUsage;
    }
    if (o.sheet && !o.level.empty()) {
        printError("--sheet draws every level: do not give --level as well");
        return kUsage;
    }
    render::RenderScene scene;
    std::string error;
    if (!scene.open(o.input, error)) {
        printError(error);
        return kFileError;
    }

    std::vector<size_t> panels;
    if (o.sheet) {
        for (size_t i = 0; i < scene.panels().size(); ++i) panels.push_back(i);
    } else if (o.level.empty()) {
        panels.push_back(0);
    } else {
        uint32_t level = runtime::kLeafLevel;
        if (o.level == "object-lods") {
            level = runtime::kObjectLodLevel;
        } else if (o.level.rfind("drawn-at-", 0) == 0) {
            char* end = nullptr;
            const long n = std::strtol(o.level.c_str() + 9, &end, 10);
            level = *end == '\0' && n > 0 && n < 64 ? render::kDrawnAtLevel + uint32_t(n) : runtime::kLeafLevel - 1;
        } else if (o.level != "originals") {
            char* end = nullptr;
            const long k = std::strtol(o.level.c_str(), &end, 10);
            if (o.level.empty() || *end != '\0' || k < 0 || k >= long(runtime::kMaxAggregateLevel)) {
                printError("--level '" + o.level +
                           "': expected 'originals', 'object-lods', 'drawn-at-N' or a level number");
                return kUsage;
            }
            level = uint32_t(k);
        }
        const int panel = scene.panelOfLevel(level);
        if (panel < 0) {
            printError(o.input + ": has no level " + o.level + " (levels: " + scene.levelList() + ")");
            return kUsage;
        }
        panels.push_back(size_t(panel));
    }

    const render::UpAxis requestedUp = o.up == "y" ? render::UpAxis::Y : o.up == "z" ? render::UpAxis::Z : render::UpAxis::Auto;
    render::Camera camera = render::defaultCamera(scene, width, height, requestedUp);
    if (!o.camera.empty()) {
        for (int k = 0; k < 3; ++k) camera.eye[k] = o.camera[size_t(k)], camera.target[k] = o.camera[size_t(k) + 3];
        if (o.camera.size() == 7) camera.fovYDegrees = o.camera[6];
    }

    std::vector<render::RgbImage> images;
    std::vector<std::string> labels;
    for (size_t p : panels) {
        render::RgbImage image;
        if (!render::renderPanel(scene, p, camera, width, height, unsigned(o.threads), image, error)) {
            printError(o.input + ": " + error);
            return error.rfind("Embree", 0) == 0 ? kRenderFailed : kUsage;
        }
        images.push_back(std::move(image));
        labels.push_back(scene.panels()[p].label);
    }
    const render::RgbImage result = o.sheet ? render::composeSheet(images, labels, o.columns) : images.front();
    if (!io::writeRgbPng(o.output, result.width, result.height, result.pixels, error)) {
        printError(error);
        return kFileError;
    }
    if (!o.quiet) {
        std::printf("Camera %g,%g,%g,%g,%g,%g,%g\n", camera.eye[0], camera.eye[1], camera.eye[2], camera.target[0],
                    camera.target[1], camera.target[2], camera.fovYDegrees);
        std::printf("Wrote %s (%dx%d, %s)\n", o.output.c_str(), result.width, result.height,
                    o.sheet ? (std::to_string(images.size()) + " panels: " + scene.levelList()).c_str()
                            : labels.front().c_str());
    }
    return kOk;
}

}  // namespace aggrelod::cli
