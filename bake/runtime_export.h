// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the bytes of OUTDIR/scene.aglod, from the hierarchy nodes through the
// module's export (aggrelod/hierarchy_export.h) and the runtime's writer (docs/design.md §4).
#pragma once

#include <aggrelod/hierarchy_export.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::io {

/// 64-bit FNV-1a of `text` (the canonical text of the bake settings).
uint64_t settingsHash(const std::string& text);

/// exportHierarchyNodes into a runtime::RuntimeFileStreamWriter: writes `path` (the caller
/// renames it into place) a node at a time, its vertex arrays never all in memory. Meshes
/// built on up to `threadCount` threads (0: all cores). Deterministic: the same nodes give the
/// same bytes as runtime::writeRuntimeFile of exportHierarchy's arrays, for any thread count.
bool writeRuntimeScene(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       uint64_t settingsHash, const std::string& toolVersion, const std::string& path,
                       std::string& error, int threadCount = 1);

}  // namespace aggrelod::io
