// SPDX-License-Identifier: AGPL-3.0-or-later
// The tiled bake's cache as a folder of files (tile_cache.h).
#include "tile_cache.h"

#include "json.h"

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <system_error>

#include <unistd.h>

namespace aggrelod::io {

namespace fs = std::filesystem;

TileCache folderTileCache(const std::string& dir) {
    TileCache cache;
    cache.load = [dir](const std::string& key, std::vector<uint8_t>& bytes) {
        const fs::path path = fs::path(dir) / (key + ".piece");
        std::error_code ec;
        const uintmax_t size = fs::file_size(path, ec);
        if (ec || size > (uintmax_t(1) << 40)) return false;
        std::ifstream in(path, std::ios::binary);
        bytes.resize(static_cast<size_t>(size));
        return bool(in.read(reinterpret_cast<char*>(bytes.data()), std::streamsize(bytes.size())));
    };
    cache.store = [dir](const std::string& key, const std::vector<uint8_t>& bytes) {
        std::error_code ec;
        fs::create_directories(dir, ec);
        const fs::path path = fs::path(dir) / (key + ".piece");
        // Unique per process and call: threads of one bake may store at once (tile_cache.h).
        static std::atomic<uint64_t> stores{0};
        const fs::path temporary =
            fs::path(dir) / (key + ".piece." + std::to_string(getpid()) + "." + std::to_string(stores++) + ".tmp");
        {
            std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
            out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
            out.close();  // a full disk may show only here: never rename a short file into place
            if (!out) {
                std::error_code ignored;
                fs::remove(temporary, ignored);
                return false;
            }
        }
        fs::rename(temporary, path, ec);
        if (!ec) return true;
        std::error_code ignored;
        fs::remove(temporary, ignored);
        return false;
    };
    return cache;
}

std::string tilePlanJson(const TiledBakeReport& plan) {
    Json parents = Json::array();
    for (size_t j = 0; j < plan.parents.size(); ++j)
        for (const auto& [row, column] : plan.parents[j]) parents.push_back({j, row, column});
    Json j;
    j["tiled"] = plan.tiled;
    j["graphs"] = plan.automaticDeltas;
    j["cells"] = plan.cells;
    j["parents"] = std::move(parents);
    j["triangles"] = plan.cellTriangleCount;
    return j.dump();
}

}  // namespace aggrelod::io
