// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: hierarchy nodes -> the runtime contract (module) -> scene.aglod (docs/design.md §4).
#include "runtime_export.h"

#include <aggrelod/hierarchy_export.h>

#include <algorithm>
#include <cstdio>
#include <utility>

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
                       std::string& error, int threadCount) {
    runtime::BuildArrays arrays;
    if (!exportHierarchy(nodes, objects, hash, toolVersion, arrays, error, threadCount)) {
        error = path + ": " + error;
        return false;
    }
    // Straight to the file: the arrays and a whole image of the file would be twice the
    // hierarchy in memory.
    if (!runtime::writeRuntimeFile(std::move(arrays), path, error)) {
        if (error.rfind(path, 0) != 0) error = path + ": " + error;
        return false;
    }
    return true;
}

}  // namespace aggrelod::io
