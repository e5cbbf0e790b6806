// SPDX-License-Identifier: AGPL-3.0-or-later
// libFuzzer target: the glTF import (GLB or .gltf text) through readGltfScene, as the bake
// reads a file. The input is written to a private folder; its uris may name files there only.
#include "scene_io.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace {
std::string scratchFolder() {
    static std::string folder = [] {
        char pattern[] = "/tmp/aggrelod-fuzz-gltf-XXXXXX";
        const char* made = ::mkdtemp(pattern);
        return std::string(made ? made : "/tmp");
    }();
    return folder;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const bool glb = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
    const std::string path = scratchFolder() + (glb ? "/scene.glb" : "/scene.gltf");
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) return 0;
    std::fwrite(data, 1, size, f);
    std::fclose(f);
    aggrelod::io::SceneReadOptions options;
    options.objectUnit = (size % 2) ? aggrelod::io::ObjectUnit::Subtree : aggrelod::io::ObjectUnit::Node;
    aggrelod::io::SceneReadResult result;
    std::string error;
    aggrelod::io::readGltfScene(path, options, result, error);
    std::vector<aggrelod::io::LevelsGlbNode> levels;
    aggrelod::io::readLevelsGlb(path, levels, error);
    return 0;
}
