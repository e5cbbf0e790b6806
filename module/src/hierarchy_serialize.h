// SPDX-License-Identifier: AGPL-3.0-or-later
// A Hierarchy3D as bytes and back, for the tiled bake's cache of cell and parent results
// (docs/design.md §2.8). Little-endian, versioned; the reader checks every count against the
// bytes left, so a truncated or corrupted entry is refused (the cell is then baked again),
// never read out of bounds. Also the content hash that names cache entries. Internal.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/tile_cache.h>

#include <cstdint>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

namespace aggrelod::detail {

/// Appends little-endian values and length-prefixed arrays to a byte vector.
class ByteWriter {
public:
    explicit ByteWriter(std::vector<uint8_t>& out) : out_(out) {}
    template <class T>
    void pod(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        const auto* p = reinterpret_cast<const uint8_t*>(&v);
        out_.insert(out_.end(), p, p + sizeof v);
    }
    template <class T>
    void array(const std::vector<T>& v) {
        pod(uint64_t(v.size()));
        const auto* p = reinterpret_cast<const uint8_t*>(v.data());
        out_.insert(out_.end(), p, p + v.size() * sizeof(T));
    }
    void text(const std::string& s) {
        pod(uint64_t(s.size()));
        out_.insert(out_.end(), s.begin(), s.end());
    }

private:
    std::vector<uint8_t>& out_;
};

/// Reads what ByteWriter wrote; every count is checked against the bytes left, and after the
/// first failure every read gives zeros and ok() stays false.
class ByteReader {
public:
    explicit ByteReader(const std::vector<uint8_t>& in) : in_(in) {}
    bool ok() const { return ok_; }
    bool atEnd() const { return at_ == in_.size(); }
    template <class T>
    T pod() {
        T v{};
        if (!take(sizeof v)) return v;
        std::memcpy(&v, in_.data() + at_ - sizeof v, sizeof v);
        return v;
    }
    /// A count of items of `itemBytes` each that must fit in the bytes left.
    size_t count(size_t itemBytes) {
        const uint64_t n = pod<uint64_t>();
        if (!ok_ || (itemBytes && n > (in_.size() - at_) / itemBytes)) {
            ok_ = false;
            return 0;
        }
        return static_cast<size_t>(n);
    }
    template <class T>
    void array(std::vector<T>& v) {
        const size_t n = count(sizeof(T));
        v.resize(n);
        if (n && take(n * sizeof(T))) std::memcpy(v.data(), in_.data() + at_ - n * sizeof(T), n * sizeof(T));
    }
    /// Skips an array that ByteWriter::array wrote of items of `itemBytes` each.
    void skipArray(size_t itemBytes) {
        const size_t n = count(itemBytes);
        take(n * itemBytes);
    }
    std::string text() {
        const size_t n = count(1);
        if (!take(n)) return {};
        return std::string(reinterpret_cast<const char*>(in_.data() + at_ - n), n);
    }

private:
    bool take(size_t n) {
        if (!ok_ || n > in_.size() - at_) {
            ok_ = false;
            return false;
        }
        at_ += n;
        return true;
    }
    const std::vector<uint8_t>& in_;
    size_t at_ = 0;
    bool ok_ = true;
};


/// Appends the whole of `h` (levels, models, merges, solids, diagnostics, timings, counts).
void serializeHierarchy(const Hierarchy3D& h, std::vector<uint8_t>& bytes);

/// Reads what serializeHierarchy wrote; false (and `h` reset) for anything else.
bool deserializeHierarchy(const std::vector<uint8_t>& bytes, Hierarchy3D& h);

/// The meshes, sources and colours of the aggregates of level `level` only of what
/// serializeHierarchy wrote (the rest of each aggregate left at its defaults); the levels
/// before it are skipped, those after it not read. False (and `aggregates` empty) when the
/// bytes end early or there is no such level.
bool deserializeLevel(const std::vector<uint8_t>& bytes, uint32_t level, std::vector<Aggregate>& aggregates);

/// Leaves `a`'s mesh in the tile cache entry `piece` (where it is aggregate `index` of level
/// `level`): sets a.meshInCache (hashes and counts of the mesh) unless set, then frees the
/// mesh unless `keepForNow` (dropMeshInCache frees it later).
void leaveMeshInCache(Aggregate& a, const std::string& piece, uint32_t level, uint32_t index, bool keepForNow = false);

/// Frees the mesh of an aggregate whose mesh is in the cache (meshInCache set); else nothing.
void dropMeshInCache(Aggregate& a);

/// Reads the meshes of lean aggregates (Aggregate::meshInCache) back from `cache`, each piece
/// once: for every j, the mesh of *lean[j] into *into[j] (positions, indices, faceColors; the
/// rest copied from *lean[j]). Runs on up to `threads` threads. False naming the first piece
/// that is missing, does not read back, or no longer holds a well-formed mesh (sizes, indices
/// in range) with the hash kept.
bool reloadMeshes(const TileCache& cache, const std::vector<const Aggregate*>& lean, const std::vector<Aggregate*>& into,
                  int threads, std::string& error);

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
