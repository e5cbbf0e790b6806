// SPDX-License-Identifier: AGPL-3.0-or-later
// A Hierarchy3D as bytes and back, for the tiled bake's cache of cell and parent results
// (docs/design.md §2.8). Little-endian, versioned; the reader checks every count against the
// bytes left, so a truncated or corrupted entry is refused (the cell is then baked again),
// never read out of bounds. Also the content hash that names cache entries. Internal.
#pragma once

#include <aggrelod/aggregate3d.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::detail {

/// Appends the whole of `h` (levels, models, merges, solids, diagnostics, timings, counts).
void serializeHierarchy(const Hierarchy3D& h, std::vector<uint8_t>& bytes);

/// Reads what serializeHierarchy wrote; false (and `h` reset) for anything else.
bool deserializeHierarchy(const std::vector<uint8_t>& bytes, Hierarchy3D& h);

/// 128-bit content hash (two independent 64-bit FNV-1a lanes), fed piece by piece; hex() is
/// 32 lowercase hex digits. Equal feeds give equal hashes on every platform.
class ContentHash {
public:
    void bytes(const void* data, size_t size);
    template <class T>
    void values(const std::vector<T>& v) {
        u64(v.size());
        bytes(v.data(), v.size() * sizeof(T));
    }
    void u64(uint64_t v) { bytes(&v, sizeof v); }
    void f64(double v) { bytes(&v, sizeof v); }
    void text(const std::string& s) {
        u64(s.size());
        bytes(s.data(), s.size());
    }
    std::string hex() const;

private:
    uint64_t a_ = 0xcbf29ce484222325ull, b_ = 0x84222325cbf29ce4ull;
};

}  // namespace aggrelod::detail
