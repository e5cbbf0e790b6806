// SPDX-License-Identifier: AGPL-3.0-or-later
// The tests' one set of mesh checks: closedness after welding, edge-manifoldness, shells,
// signed volume and the generalized winding number (an inside test independent of ray
// casting; for rays see ray_scene.h). Positions are xyz per vertex, indices 3 per triangle.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <numeric>
#include <string>
#include <vector>

namespace aggrelod::testing {

/// Signed volume of an indexed mesh (positive for an outward-oriented closed mesh).
template <class Real>
double signedVolume(const std::vector<Real>& pos, const std::vector<uint32_t>& idx) {
    double v = 0;
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
        const Real* a = &pos[3 * size_t(idx[t])];
        const Real* b = &pos[3 * size_t(idx[t + 1])];
        const Real* c = &pos[3 * size_t(idx[t + 2])];
        v += double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
             double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
             double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0]);
    }
    return v / 6.0;
}

/// Empty when every undirected index edge is used by exactly two triangles, once in each
/// direction (closed, edge-manifold, consistently oriented) and no triangle repeats a corner;
/// else what the first offending edge or triangle does.
inline std::string edgeManifoldProblem(const std::vector<uint32_t>& indices) {
    if (indices.empty()) return "no triangles";
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = indices[t + size_t(k)], b = indices[t + size_t(k + 1) % 3];
            if (a == b) return "triangle " + std::to_string(t / 3) + " repeats corner " + std::to_string(a);
            ++directed[{a, b}];
        }
    for (const auto& [edge, uses] : directed) {
        const auto back = directed.find({edge.second, edge.first});
        const int backUses = back == directed.end() ? 0 : back->second;
        if (uses != 1 || backUses != 1)
            return "index edge " + std::to_string(edge.first) + "-" + std::to_string(edge.second) + " used " +
                   std::to_string(uses) + " + " + std::to_string(backUses) + " times in the two directions";
    }
    return {};
}

/// Index edges whose two triangles fold onto each other: normals within about 2.6 degrees
/// of opposite (a fin that encloses nothing; a ray along it meets both faces at one point).
/// positions: 3 * n floats; indices as edgeManifoldProblem's (pairs used other than once in
/// each direction are not counted here).
inline size_t foldedEdgeCount(const std::vector<float>& positions, const std::vector<uint32_t>& indices) {
    const auto normal = [&](size_t t) {
        double c[3][3];
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d) c[k][d] = positions[3 * size_t(indices[3 * t + size_t(k)]) + size_t(d)];
        const double u[3] = {c[1][0] - c[0][0], c[1][1] - c[0][1], c[1][2] - c[0][2]};
        const double v[3] = {c[2][0] - c[0][0], c[2][1] - c[0][1], c[2][2] - c[0][2]};
        return std::array<double, 3>{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    };
    std::map<std::pair<uint32_t, uint32_t>, size_t> directed;
    for (size_t t = 0; 3 * t + 2 < indices.size(); ++t)
        for (int k = 0; k < 3; ++k) directed[{indices[3 * t + size_t(k)], indices[3 * t + size_t(k + 1) % 3]}] = t;
    size_t folded = 0;
    for (const auto& [edge, t] : directed) {
        if (edge.first > edge.second) continue;  // each undirected edge once
        const auto back = directed.find({edge.second, edge.first});
        if (back == directed.end()) continue;
        const auto m = normal(t), n = normal(back->second);
        const double dot = m[0] * n[0] + m[1] * n[1] + m[2] * n[2];
        const double lm = std::sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
        const double ln = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (dot < -0.999 * lm * ln) ++folded;
    }
    return folded;
}

/// The index triples of each edge-connected shell of an indexed mesh (triangles sharing an
/// undirected index edge), in order of their first triangle.
inline std::vector<std::vector<uint32_t>> shellsOf(const std::vector<uint32_t>& indices) {
    const size_t triangles = indices.size() / 3;
    DisjointSets sets(triangles);
    std::map<std::pair<uint32_t, uint32_t>, uint32_t> firstUse;
    for (size_t t = 0; t < triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = indices[3 * t + size_t(k)], b = indices[3 * t + size_t(k + 1) % 3];
            const auto [it, fresh] = firstUse.emplace(std::make_pair(std::min(a, b), std::max(a, b)), uint32_t(t));
            if (!fresh) sets.unite(uint32_t(t), it->second);
        }
    std::map<uint32_t, size_t> shellOfRoot;
    std::vector<std::vector<uint32_t>> out;
    for (size_t t = 0; t < triangles; ++t) {
        const auto [it, fresh] = shellOfRoot.emplace(sets.find(uint32_t(t)), out.size());
        if (fresh) out.emplace_back();
        out[it->second].insert(out[it->second].end(), indices.begin() + 3 * t, indices.begin() + 3 * t + 3);
    }
    return out;
}

/// Edge-connected shells of an indexed mesh (triangles sharing an undirected index edge).
inline int shellCount(const std::vector<uint32_t>& indices) { return int(shellsOf(indices).size()); }

/// The indices with vertices of bit-identical positions merged (glTF art repeats vertices at
/// seams): each index replaced by the first vertex at its position.
template <class Real>
std::vector<uint32_t> weldedIndices(const std::vector<Real>& pos, const std::vector<uint32_t>& idx) {
    std::map<std::array<double, 3>, uint32_t> ids;
    std::vector<uint32_t> weld(pos.size() / 3);
    for (size_t i = 0; i < weld.size(); ++i)
        weld[i] = ids.emplace(std::array<double, 3>{double(pos[3 * i]), double(pos[3 * i + 1]), double(pos[3 * i + 2])},
                              uint32_t(ids.size()))
                      .first->second;
    std::vector<uint32_t> welded;
    welded.reserve(idx.size());
    for (uint32_t i : idx) welded.push_back(weld[i]);
    return welded;
}

/// Result of checking a triangle soup for closedness after welding equal positions.
struct ClosedCheck {
    std::string problem;            ///< empty when closed and consistently oriented
    size_t weldedVertices = 0;
    size_t edges = 0;               ///< undirected, after welding
    size_t edgesUsedMoreThanTwice = 0; ///< non-manifold after welding (e.g. shells touching along an edge)
    int components = 0;             ///< connected pieces (through shared welded vertices)
};

/// Welds vertices with bit-identical positions, then checks that every undirected edge is
/// used by triangles as often in one direction as in the other (and at least once each way):
/// the surface is closed and consistently oriented.
inline ClosedCheck checkClosedAfterWeld(const InputObject& o) {
    ClosedCheck c;
    const size_t n = o.positions.size() / 3;
    std::map<std::array<double, 3>, uint32_t> ids;
    std::vector<uint32_t> weld(n);
    for (size_t i = 0; i < n; ++i) {
        const std::array<double, 3> p = {o.positions[3 * i], o.positions[3 * i + 1], o.positions[3 * i + 2]};
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
            c.problem = "non-finite vertex " + std::to_string(i);
            return c;
        }
        weld[i] = ids.emplace(p, uint32_t(ids.size())).first->second;
    }
    c.weldedVertices = ids.size();
    if (o.indices.empty() || o.indices.size() % 3 != 0) {
        c.problem = "no triangles or index count not a multiple of 3";
        return c;
    }
    DisjointSets sets(ids.size());
    std::map<std::pair<uint32_t, uint32_t>, std::array<int, 2>> edges;  // (lo, hi) -> uses lo->hi, hi->lo
    for (size_t t = 0; t < o.indices.size(); t += 3) {
        uint32_t v[3];
        for (int k = 0; k < 3; ++k) {
            if (o.indices[t + size_t(k)] >= n) {
                c.problem = "index out of range in triangle " + std::to_string(t / 3);
                return c;
            }
            v[k] = weld[o.indices[t + size_t(k)]];
        }
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) {
            c.problem = "triangle " + std::to_string(t / 3) + " has two corners at one position";
            return c;
        }
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = v[k], b = v[(k + 1) % 3];
            auto& uses = edges[{std::min(a, b), std::max(a, b)}];
            ++uses[a < b ? 0 : 1];
            sets.unite(a, b);
        }
    }
    c.edges = edges.size();
    for (const auto& [edge, uses] : edges) {
        if (uses[0] != uses[1]) {
            c.problem = "edge between vertices " + std::to_string(edge.first) + " and " + std::to_string(edge.second) +
                        " used " + std::to_string(uses[0]) + " + " + std::to_string(uses[1]) +
                        " times in the two directions (open or inconsistently oriented)";
            return c;
        }
        if (uses[0] + uses[1] > 2) ++c.edgesUsedMoreThanTwice;
    }
    std::vector<bool> used(ids.size(), false);
    for (uint32_t i : o.indices) used[weld[i]] = true;
    for (uint32_t i = 0; i < ids.size(); ++i)
        if (used[i] && sets.find(i) == i) ++c.components;
    return c;
}

/// Signed volume of an object (positive for an outward-oriented closed mesh).
inline double signedVolumeOf(const InputObject& o) { return signedVolume(o.positions, o.indices); }

/// Generalized winding number of a closed mesh at q (about 1 inside, 0 outside): an inside
/// test independent of ray casting. pos: xyz per vertex; idx: 3 per triangle.
template <class Real>
double windingNumber(const std::vector<Real>& pos, const std::vector<uint32_t>& idx, const double* q) {
    double total = 0;
    for (size_t t = 0; t + 2 < idx.size(); t += 3) {
        double r[3][3], len[3];
        for (int k = 0; k < 3; ++k) {
            for (int d = 0; d < 3; ++d) r[k][d] = double(pos[3 * size_t(idx[t + k]) + d]) - q[d];
            len[k] = std::sqrt(r[k][0] * r[k][0] + r[k][1] * r[k][1] + r[k][2] * r[k][2]);
        }
        const double det = r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1]) - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0]) +
                           r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0]);
        auto dot = [&](int i, int j) { return r[i][0] * r[j][0] + r[i][1] * r[j][1] + r[i][2] * r[j][2]; };
        const double den = len[0] * len[1] * len[2] + dot(0, 1) * len[2] + dot(1, 2) * len[0] + dot(2, 0) * len[1];
        total += 2 * std::atan2(det, den);
    }
    return total / (4 * 3.14159265358979323846);
}

}  // namespace aggrelod::testing
