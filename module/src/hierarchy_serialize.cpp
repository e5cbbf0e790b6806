// SPDX-License-Identifier: AGPL-3.0-or-later
// Hierarchy3D to bytes and back for the tiled bake's cache (docs/design.md §2.8).
#include "hierarchy_serialize.h"

#include "parallel_for.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <memory>
#include <type_traits>

namespace aggrelod::detail {
namespace {

constexpr char kMagic[8] = {'A', 'G', 'L', 'O', 'D', 'H', '3', '1'};

void write(ByteWriter& w, const SolidMeasures& m) {
    w.pod(m.volume);
    w.pod(m.area);
    w.pod(m.sphericity);
}
void read(ByteReader& r, SolidMeasures& m) {
    m.volume = r.pod<double>();
    m.area = r.pod<double>();
    m.sphericity = r.pod<double>();
}

}  // namespace

void serializeHierarchy(const Hierarchy3D& h, std::vector<uint8_t>& bytes) {
    ByteWriter w(bytes);
    for (char c : kMagic) w.pod(c);
    w.pod(uint64_t(h.levels.size()));
    for (const Level& l : h.levels) {
        w.pod(l.delta);
        w.pod(uint64_t(l.aggregates.size()));
        for (const Aggregate& a : l.aggregates) {
            w.array(a.positions);
            w.array(a.indices);
            w.array(a.sourceObjects);
            w.array(a.faceColors);
            w.pod(int64_t(a.componentCount));
            write(w, a.measures);
            w.pod(a.volumeOriginal);
            w.pod(a.volumeHull);
            w.pod(uint8_t(a.surface));
        }
        write(w, l.measures);
        w.pod(l.volumeOriginal);
        w.pod(l.volumeHull);
        w.pod(l.volumeConstant);
        w.pod(uint8_t(l.hasVolumeConstant));
        w.pod(uint64_t(l.triangleCount));
    }
    w.array(h.objectModel);
    w.pod(uint64_t(h.modelCount));
    w.array(h.merges);
    write(w, h.originals);
    w.pod(uint64_t(h.diagnostics.size()));
    for (const Diagnostic& d : h.diagnostics) {
        w.pod(uint8_t(d.severity));
        w.text(d.object);
        w.text(d.message);
    }
    w.pod(uint64_t(h.timings.size()));
    for (const auto& [stage, seconds] : h.timings) {
        w.text(stage);
        w.pod(seconds);
    }
    w.pod(uint64_t(h.tetrahedronCount));
    w.pod(uint64_t(h.inputTriangleCount));
    w.pod(uint64_t(h.solids.size()));
    for (const SolidReport& s : h.solids) {
        w.array(s.objects);
        w.pod(uint8_t(s.method));
        w.text(s.reason);
        for (double v : {s.alpha, s.offset, s.volumeOriginal, s.volumeSolid, s.distanceSolidToOriginal,
                         s.distanceOriginalToSolid, s.hullDistance, s.bboxDiagonal, s.seconds})
            w.pod(v);
        w.pod(uint8_t(s.closedManifold));
        w.array(s.positions);
        w.array(s.triangles);
    }
    w.array(h.supportObjects);
    w.array(h.leftOutObjects);
}

bool deserializeLevel(const std::vector<uint8_t>& bytes, uint32_t wanted, std::vector<Aggregate>& aggregates) {
    aggregates.clear();
    ByteReader r(bytes);
    for (char c : kMagic)
        if (r.pod<char>() != c) return false;
    const size_t levels = r.count(73);
    if (wanted >= levels) return false;
    for (size_t k = 0; k <= wanted && r.ok(); ++k) {
        r.pod<double>();  // delta
        const size_t count = r.count(4 * 8 + 8 + 3 * 8 + 2 * 8 + 1);
        if (k == wanted) aggregates.resize(count);
        for (size_t g = 0; g < count && r.ok(); ++g) {
            if (k == wanted) {
                Aggregate& a = aggregates[g];
                r.array(a.positions);
                r.array(a.indices);
                r.array(a.sourceObjects);
                r.array(a.faceColors);
            } else {
                r.skipArray(sizeof(double));
                r.skipArray(sizeof(uint32_t));
                r.skipArray(sizeof(uint32_t));
                r.skipArray(sizeof(float));
            }
            r.pod<int64_t>();  // componentCount, measures, volumes, surface: kept in memory
            for (int i = 0; i < 5; ++i) r.pod<double>();
            r.pod<uint8_t>();
        }
        if (k == wanted) break;
        for (int i = 0; i < 6; ++i) r.pod<double>();  // measures, volumes
        r.pod<uint8_t>();
        r.pod<uint64_t>();
    }
    if (!r.ok()) aggregates.clear();
    return r.ok();
}

bool deserializeHierarchy(const std::vector<uint8_t>& bytes, Hierarchy3D& h) {
    h = Hierarchy3D{};
    ByteReader r(bytes);
    for (char c : kMagic)
        if (r.pod<char>() != c) return false;
    // Smallest encoded sizes bound every count: a level is at least 8 + 8 + 3*8 + 3*8 + 1 + 8 bytes.
    h.levels.resize(r.count(73));
    for (Level& l : h.levels) {
        l.delta = r.pod<double>();
        l.aggregates.resize(r.count(4 * 8 + 8 + 3 * 8 + 2 * 8 + 1));
        for (Aggregate& a : l.aggregates) {
            r.array(a.positions);
            r.array(a.indices);
            r.array(a.sourceObjects);
            r.array(a.faceColors);
            a.componentCount = static_cast<int>(r.pod<int64_t>());
            read(r, a.measures);
            a.volumeOriginal = r.pod<double>();
            a.volumeHull = r.pod<double>();
            const uint8_t surface = r.pod<uint8_t>();
            if (surface > uint8_t(Aggregate::Surface::Mixed)) return false;
            a.surface = Aggregate::Surface(surface);
        }
        read(r, l.measures);
        l.volumeOriginal = r.pod<double>();
        l.volumeHull = r.pod<double>();
        l.volumeConstant = r.pod<double>();
        l.hasVolumeConstant = r.pod<uint8_t>() != 0;
        l.triangleCount = static_cast<size_t>(r.pod<uint64_t>());
    }
    r.array(h.objectModel);
    h.modelCount = static_cast<size_t>(r.pod<uint64_t>());
    r.array(h.merges);
    read(r, h.originals);
    h.diagnostics.resize(r.count(1 + 8 + 8));
    for (Diagnostic& d : h.diagnostics) {
        const uint8_t severity = r.pod<uint8_t>();
        if (severity > uint8_t(Diagnostic::Severity::Error)) return false;
        d.severity = Diagnostic::Severity(severity);
        d.object = r.text();
        d.message = r.text();
    }
    h.timings.resize(r.count(8 + 8));
    for (auto& [stage, seconds] : h.timings) {
        stage = r.text();
        seconds = r.pod<double>();
    }
    h.tetrahedronCount = static_cast<size_t>(r.pod<uint64_t>());
    h.inputTriangleCount = static_cast<size_t>(r.pod<uint64_t>());
    h.solids.resize(r.count(8 + 1 + 8 + 9 * 8 + 1 + 8 + 8));
    for (SolidReport& s : h.solids) {
        r.array(s.objects);
        const uint8_t method = r.pod<uint8_t>();
        if (method > uint8_t(SolidifyMethod::Shell)) return false;
        s.method = SolidifyMethod(method);
        s.reason = r.text();
        for (double* v : {&s.alpha, &s.offset, &s.volumeOriginal, &s.volumeSolid, &s.distanceSolidToOriginal,
                          &s.distanceOriginalToSolid, &s.hullDistance, &s.bboxDiagonal, &s.seconds})
            *v = r.pod<double>();
        s.closedManifold = r.pod<uint8_t>() != 0;
        r.array(s.positions);
        r.array(s.triangles);
    }
    r.array(h.supportObjects);
    r.array(h.leftOutObjects);
    if (!r.ok() || !r.atEnd()) {
        h = Hierarchy3D{};
        return false;
    }
    return true;
}

void ContentHash::bytes(const void* data, size_t size) {
    const auto* p = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < size; ++i) {
        a_ = (a_ ^ p[i]) * 0x100000001b3ull;
        b_ = (b_ ^ uint8_t(p[i] + 0x5a)) * 0x00000100000001b3ull + 0x9e3779b97f4a7c15ull;
    }
}

std::string ContentHash::hex() const {
    static const char digits[] = "0123456789abcdef";
    std::string s(32, '0');
    for (int i = 0; i < 16; ++i) {
        s[15 - i] = digits[(a_ >> (4 * i)) & 15];
        s[31 - i] = digits[(b_ >> (4 * i)) & 15];
    }
    return s;
}

void leaveMeshInCache(Aggregate& a, const std::string& piece, uint32_t level, uint32_t index, bool keepForNow) {
    if (!a.meshInCache) {
        auto ref = std::make_shared<AggregateMeshRef>();
        ref->piece = piece;
        ref->level = level;
        ref->index = index;
        ref->vertexCount = a.positions.size() / 3;
        ref->triangleCount = a.indices.size() / 3;
        ref->hasFaceColors = !a.faceColors.empty();
        ref->meshHash = aggregateMeshHash(a);
        aggregateVertexSetHash(a, ref->vertexSetHash);
        a.meshInCache = std::move(ref);
    }
    if (!keepForNow) dropMeshInCache(a);
}

void dropMeshInCache(Aggregate& a) {
    if (!a.meshInCache) return;
    std::vector<double>().swap(a.positions);
    std::vector<uint32_t>().swap(a.indices);
    std::vector<float>().swap(a.faceColors);
}

bool reloadMeshes(const TileCache& cache, const std::vector<const Aggregate*>& lean, const std::vector<Aggregate*>& into,
                  int threads, std::string& error) {
    // (piece, level) -> the j it holds: each piece read once per level asked, that level only.
    std::map<std::pair<std::string, uint32_t>, std::vector<size_t>> byPiece;
    for (size_t j = 0; j < lean.size(); ++j) {
        if (!lean[j]->meshInCache) {
            error = "an aggregate to read again was not left in the cache";
            return false;
        }
        byPiece[{lean[j]->meshInCache->piece, lean[j]->meshInCache->level}].push_back(j);
    }
    std::vector<const std::vector<size_t>*> pieces;
    for (const auto& [key, js] : byPiece) pieces.push_back(&js);
    std::vector<char> failed(pieces.size(), 0);
    parallelFor(pieces.size(), threads, [&](size_t p) {
        const AggregateMeshRef& first = *lean[pieces[p]->front()]->meshInCache;
        std::vector<uint8_t> bytes;
        std::vector<Aggregate> level;
        if (!cache.load || !cache.load(first.piece, bytes) || !deserializeLevel(bytes, first.level, level)) {
            failed[p] = 1;
            return;
        }
        std::vector<uint8_t>().swap(bytes);
        for (size_t j : *pieces[p]) {
            const AggregateMeshRef& ref = *lean[j]->meshInCache;
            if (ref.index >= level.size()) {
                failed[p] = 1;
                return;
            }
            Aggregate& from = level[ref.index];
            const bool wellFormed =
                from.positions.size() % 3 == 0 && from.indices.size() % 3 == 0 &&
                (from.faceColors.empty() || from.faceColors.size() == 4 * (from.indices.size() / 3)) &&
                std::all_of(from.indices.begin(), from.indices.end(), [&](uint32_t v) { return v < from.positions.size() / 3; });
            if (!wellFormed || from.positions.size() / 3 != ref.vertexCount || from.indices.size() / 3 != ref.triangleCount ||
                aggregateMeshHash(from) != ref.meshHash) {
                failed[p] = 1;
                return;
            }
            Aggregate& a = *into[j];
            a = *lean[j];
            a.positions = from.positions;  // copies: an aggregate may be asked for twice
            a.indices = from.indices;
            a.faceColors = from.faceColors;
        }
    });
    for (size_t p = 0; p < pieces.size(); ++p)
        if (failed[p]) {
            error = "the tile cache entry " + lean[pieces[p]->front()]->meshInCache->piece +
                    " is missing or no longer holds the aggregates assembled from it";
            return false;
        }
    return true;
}

}  // namespace aggrelod::detail

namespace aggrelod {

std::string aggregateMeshHash(const Aggregate& a) {
    if (meshLeftInCache(a)) return a.meshInCache->meshHash;
    detail::ContentHash h;
    h.text("aggregate mesh");
    h.values(a.positions);
    h.values(a.indices);
    return h.hex();
}

void aggregateVertexSetHash(const Aggregate& a, uint64_t hash[2]) {
    if (meshLeftInCache(a)) {
        hash[0] = a.meshInCache->vertexSetHash[0];
        hash[1] = a.meshInCache->vertexSetHash[1];
        return;
    }
    // Sums of a strong mix of each vertex (order-free): two independent 64-bit lanes.
    const auto mix = [](uint64_t x) {
        x ^= x >> 30;
        x *= 0xbf58476d1ce4e5b9ull;
        x ^= x >> 27;
        x *= 0x94d049bb133111ebull;
        x ^= x >> 31;
        return x;
    };
    uint64_t s0 = 0, s1 = 0;
    for (size_t i = 0; i + 2 < a.positions.size(); i += 3) {
        uint64_t h0 = 0x9e3779b97f4a7c15ull, h1 = 0xc2b2ae3d27d4eb4full;
        for (int k = 0; k < 3; ++k) {
            const double x = a.positions[i + k] + 0.0;  // -0 as +0
            uint64_t bits;
            std::memcpy(&bits, &x, sizeof bits);
            h0 = mix(h0 ^ bits);
            h1 = mix(h1 + bits * 0x2545f4914f6cdd1dull);
        }
        s0 += h0;
        s1 += mix(h1 ^ 0x5851f42d4c957f2dull);
    }
    hash[0] = s0;
    hash[1] = s1;
}

}  // namespace aggrelod
