// SPDX-License-Identifier: AGPL-3.0-or-later
// libFuzzer target: the glTF import (GLB or .gltf text) through readGltfScene, as the bake
// reads a file. The input is written to a private folder (under $TMPDIR, else /tmp, removed at
// exit); its uris may name files there only.
#include "scene_io.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <unistd.h>

namespace {
/// The private folder, made on first use; kept in a string that is never destroyed, so the
/// exit handler that removes the folder can still read it.
const std::string& scratchFolder();

void removeScratchFolder() {
    const std::string& folder = scratchFolder();
    std::remove((folder + "/scene.glb").c_str());
    std::remove((folder + "/scene.gltf").c_str());
    ::rmdir(folder.c_str());
}

const std::string& scratchFolder() {
    static const std::string* folder = [] {
        const char* base = std::getenv("TMPDIR");
        std::string pattern = std::string(base && *base ? base : "/tmp") + "/aggrelod-fuzz-gltf-XXXXXX";
        if (!::mkdtemp(pattern.data())) return new std::string();
        // libFuzzer ends through exit(): the folder and the two inputs go with the process.
        std::atexit(removeScratchFolder);
        return new std::string(pattern);
    }();
    return *folder;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const bool glb = size >= 4 && data[0] == 'g' && data[1] == 'l' && data[2] == 'T' && data[3] == 'F';
    if (scratchFolder().empty()) return 0;
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
