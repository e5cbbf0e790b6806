// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the render subcommand. Options are declared in main.cpp (the only CLI11
// user); the work is done in render_command.cpp.
#pragma once

#include <string>
#include <vector>

namespace aggrelod::cli {

struct RenderOptions {
    std::string input;            ///< .aglod or levels.glb
    std::string output;           ///< .png
    std::string level;            ///< "originals" or a level number; empty: originals (.aglod) / first level (.glb)
    bool sheet = false;           ///< every level side by side
    std::vector<float> camera;    ///< empty, or x,y,z,tx,ty,tz[,fovYDegrees]
    std::string up = "auto";      ///< auto | y | z
    std::string size;             ///< "WxH"; empty: 640x480 (one level) or 400x300 per panel (sheet)
    int columns = 0;              ///< sheet columns (0: up to 4)
    int threads = 0;              ///< ray-casting threads (0: 2)
    bool quiet = false;
};
/// Returns the process exit code (0 ok, 1 usage, 2 file problem, 4 render failed).
int runRender(const RenderOptions& options);

}  // namespace aggrelod::cli
