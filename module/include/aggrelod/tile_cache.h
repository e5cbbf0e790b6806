// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: where a bake keeps the results of its pieces between runs and between
// processes (the tiled bake's cells and parent cells, tiled_bake_3d.h; the proxies stage's
// work items, hierarchy_nodes.h).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace aggrelod {

/// A key (32 hex digits) names a piece's whole input: its objects (meshes, colours, and for
/// the tiled bake's pieces names and ids) and the settings that shape it, so a piece whose
/// input did not change is read back instead of baked (incremental rebake), and a stale entry
/// is never used. An entry that does not read back is refused and its piece made again.
/// The tiled bake calls both functions from the calling thread only; the proxies stage
/// (ProxySettings::cache) calls them from several threads at once, for different keys or, for
/// two pieces with the same input, the same key with the same bytes.
struct TileCache {
    /// Fills `bytes` with the entry `key`; false when there is none.
    std::function<bool(const std::string& key, std::vector<uint8_t>& bytes)> load;
    /// Keeps `bytes` as entry `key`; false when it could not (the bake goes on, with a warning).
    std::function<bool(const std::string& key, const std::vector<uint8_t>& bytes)> store;
};

}  // namespace aggrelod
