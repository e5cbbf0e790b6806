// aggrelod bake: the hierarchy nodes (module) turned into the runtime's flat BuildParams,
// and the bytes of OUTDIR/scene.aglod (DESIGN section 4).
#pragma once

#include <aggrelod/hierarchy_nodes.h>
#include <aggrelod/runtime_build.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::io {

/// 64-bit FNV-1a of `text` (the canonical text of the bake settings).
uint64_t settingsHash(const std::string& text);

/// Fills `params` from `nodes` (node i of the file = nodes.nodes[i]; leaves carry the
/// original object's triangles, aggregates their simplified proxy, as float world
/// coordinates). Returns false with a message when a count does not fit 32 bits.
bool fillBuildParams(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                     uint64_t settingsHash, const std::string& toolVersion,
                     runtime::BuildParams& params, std::string& error);

/// fillBuildParams + runtime::writeRuntimeFile + writing `path` (the caller renames it into
/// place). Deterministic: the same nodes give the same bytes.
bool writeRuntimeScene(const HierarchyNodes& nodes, const std::vector<InputObject>& objects,
                       uint64_t settingsHash, const std::string& toolVersion, const std::string& path,
                       std::string& error);

}  // namespace aggrelod::io
