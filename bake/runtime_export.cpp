// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: hierarchy nodes -> the runtime contract (module) -> scene.aglod (docs/design.md §4).
#include "runtime_export.h"

#include <aggrelod/hierarchy_export.h>

#include <algorithm>
#include <cstdio>

namespace aggrelod::io {

uint64_t settingsHash(const std::string& text) {
    uint64_t h = 14695981039346656037ull;
    for (unsigned char c : text) {
        h ^= c;
        h *= 1099511628211ull;
    }
    return h;
}

bool writeRuntimeScene(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       uint64_t hash, const std::string& toolVersion, const std::string& path,
                       std::string& error) {
    runtime::BuildArrays arrays;
    if (!exportHierarchy(nodes, objects, hash, toolVersion, arrays, error)) {
        error = path + ": " + error;
        return false;
    }
    std::vector<uint8_t> bytes;
    if (!runtime::writeRuntimeFile(arrays.params(), bytes, error)) {
        error = path + ": " + error;
        return false;
    }
    std::FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) {
        error = path + ": cannot open for writing";
        return false;
    }
    const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const bool closed = std::fclose(f) == 0;
    if (!ok || !closed) {
        error = path + ": write failed (disk full?)";
        return false;
    }
    return true;
}

}  // namespace aggrelod::io
