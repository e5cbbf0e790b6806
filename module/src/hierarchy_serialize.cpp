// SPDX-License-Identifier: AGPL-3.0-or-later
// Hierarchy3D to bytes and back for the tiled bake's cache (docs/design.md §2.8).
#include "hierarchy_serialize.h"

#include <cstring>
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
        if (method > uint8_t(SolidifyMethod::Union)) return false;
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

}  // namespace aggrelod::detail
