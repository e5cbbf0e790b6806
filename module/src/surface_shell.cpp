// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: an open surface thickened into a closed shell (see surface_shell.h). The
// offset surfaces are the classic "solidify" of modelling tools; each vertex's displacement
// is the nearest one that keeps every face around it at the offset, so the faces, not only
// the vertices, keep their distance.
#include "surface_shell.h"

#include "mesh_distance.h"
#include "mesh_preparation.h"
#include "nearest_point_above_planes.h"

#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <tuple>

namespace aggrelod::detail {

namespace {

Vec3 vertexAt(const std::vector<double>& p, uint32_t i) { return Vec3{p[3 * i], p[3 * i + 1], p[3 * i + 2]}; }

bool fail(std::string& why, const char* reason) {
    why = reason;
    return false;
}

/// Diagonal of a box given as min xyz, max xyz.
double diagonal(const double* box) {
    return std::sqrt((box[3] - box[0]) * (box[3] - box[0]) + (box[4] - box[1]) * (box[4] - box[1]) +
                     (box[5] - box[2]) * (box[5] - box[2]));
}

void grow(double* box, const double* p) {
    for (int k = 0; k < 3; ++k) {
        box[k] = std::min(box[k], p[k]);
        box[3 + k] = std::max(box[3 + k], p[k]);
    }
}

}  // namespace

bool thickenSurface(const std::vector<double>& positions, const std::vector<uint32_t>& triangles, double offset,
                    double maxDisplacement, double smallestOpening, std::vector<double>& outPositions,
                    std::vector<uint32_t>& outTriangles, std::string& why) {
    outPositions.clear();
    outTriangles.clear();
    const size_t n = positions.size() / 3;
    if (!(offset > 0) || !(maxDisplacement >= offset) || triangles.empty()) return fail(why, "nothing to thicken");
    // Exact weld: the first of equal positions (in coordinate order) stands for all.
    std::vector<uint32_t> order(n), weld(n);
    std::iota(order.begin(), order.end(), 0u);
    auto point = [&](uint32_t i) { return std::make_tuple(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]); };
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return std::make_pair(point(a), a) < std::make_pair(point(b), b); });
    for (size_t k = 0; k < n; ++k) {
        const uint32_t i = order[k];
        weld[i] = k > 0 && point(i) == point(order[k - 1]) ? weld[order[k - 1]] : i;
    }
    std::vector<std::array<uint32_t, 3>> faces;
    faces.reserve(triangles.size() / 3);
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const std::array<uint32_t, 3> f = {weld[triangles[t]], weld[triangles[t + 1]], weld[triangles[t + 2]]};
        if (f[0] == f[1] || f[1] == f[2] || f[2] == f[0]) continue;
        faces.push_back(f);
    }
    const size_t m = faces.size();
    if (m == 0) return fail(why, "nothing to thicken");
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const auto& f : faces)
        for (uint32_t v : f) grow(box, &positions[3 * v]);
    const double size = diagonal(box);

    // Edges: (smaller vertex, larger vertex, face, corner the edge starts at), sorted.
    std::vector<std::tuple<uint32_t, uint32_t, uint32_t, uint8_t>> edges;
    edges.reserve(3 * m);
    for (uint32_t f = 0; f < m; ++f)
        for (uint8_t c = 0; c < 3; ++c) {
            const uint32_t a = faces[f][c], b = faces[f][(c + 1) % 3];
            edges.emplace_back(std::min(a, b), std::max(a, b), f, c);
        }
    std::sort(edges.begin(), edges.end());
    // For each face corner c: the face across the edge from corner c to c + 1 (or none).
    std::vector<std::array<uint32_t, 3>> across(m, {UINT32_MAX, UINT32_MAX, UINT32_MAX});
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && std::get<0>(edges[j]) == std::get<0>(edges[i]) && std::get<1>(edges[j]) == std::get<1>(edges[i])) ++j;
        if (j - i > 2) return fail(why, "an edge is shared by more than two faces");
        if (j - i == 2) {
            across[std::get<2>(edges[i])][std::get<3>(edges[i])] = std::get<2>(edges[i + 1]);
            across[std::get<2>(edges[i + 1])][std::get<3>(edges[i + 1])] = std::get<2>(edges[i]);
        }
        i = j;
    }
    // Orient the faces of each piece alike (breadth first from its first face); every piece
    // must have a boundary (a closed piece would give two nested sheets: a hollow solid).
    // A piece whose openings all fit in a ball of `smallestOpening` (a closed mesh with a face
    // missing) is nearly closed: thickened it would be a hollow skin, where a wrap fills it.
    std::vector<int8_t> flip(m, -1);
    std::vector<uint32_t> queue, pieceOf(m, 0);
    uint32_t pieces = 0;
    for (uint32_t seed = 0; seed < m; ++seed) {
        if (flip[seed] >= 0) continue;
        flip[seed] = 0;
        queue.assign(1, seed);
        bool open = false;
        double rim[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
        for (size_t q = 0; q < queue.size(); ++q) {
            const uint32_t f = queue[q];
            pieceOf[f] = pieces;
            for (int c = 0; c < 3; ++c) {
                const uint32_t g = across[f][c];
                if (g == UINT32_MAX) {
                    open = true;
                    grow(rim, &positions[3 * faces[f][c]]);
                    grow(rim, &positions[3 * faces[f][(c + 1) % 3]]);
                    continue;
                }
                // f as stored runs a -> b along this edge. Oriented alike, g runs b -> a: when
                // g as stored runs a -> b too, exactly one of the two is turned over.
                const uint32_t a = faces[f][c], b = faces[f][(c + 1) % 3];
                int gc = 0;
                while (!(faces[g][gc] == a || faces[g][gc] == b) || !(faces[g][(gc + 1) % 3] == a || faces[g][(gc + 1) % 3] == b)) ++gc;
                const bool gRunsAB = faces[g][gc] == a;
                const int want = gRunsAB ? 1 - flip[f] : flip[f];
                if (flip[g] < 0) {
                    flip[g] = int8_t(want);
                    queue.push_back(g);
                } else if (flip[g] != want) {
                    return fail(why, "its faces cannot be oriented alike");
                }
            }
        }
        if (!open) return fail(why, "a piece of it is closed");
        if (diagonal(rim) < smallestOpening) return fail(why, "a piece of it is nearly closed (its openings are small)");
        ++pieces;
    }
    for (uint32_t f = 0; f < m; ++f)
        if (flip[f]) {
            std::swap(faces[f][1], faces[f][2]);
            std::array<uint32_t, 3> a = across[f];
            across[f] = {a[2], a[1], a[0]};  // corner c's edge: (0,1)->(0,2) is old edge 2, (1,2)->(2,1) old 1, (2,0)->(1,0) old 0
        }
    // One fan of faces around every vertex: corners of a vertex joined across its edges.
    DisjointSets corners(3 * m);
    for (uint32_t f = 0; f < m; ++f)
        for (int c = 0; c < 3; ++c) {
            const uint32_t g = across[f][c];
            if (g == UINT32_MAX || g < f) continue;
            for (int side = 0; side < 2; ++side) {
                const uint32_t v = faces[f][(c + side) % 3];
                int gc = 0;
                while (faces[g][gc] != v) ++gc;
                corners.unite(3 * f + c + side - (c + side >= 3 ? 3 : 0), 3 * g + gc);
            }
        }
    std::vector<uint32_t> fan(n, UINT32_MAX);
    for (uint32_t f = 0; f < m; ++f)
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = faces[f][c], root = corners.find(3 * f + c);
            if (fan[v] == UINT32_MAX) fan[v] = root;
            else if (fan[v] != root) return fail(why, "two fans of faces meet at a vertex");
        }

    // Face normals (unit) and each vertex's faces, in face order.
    std::vector<Vec3> normal(m);
    std::vector<Vec3> meanNormal(n, Vec3{0, 0, 0});
    for (uint32_t f = 0; f < m; ++f) {
        const Vec3 a = vertexAt(positions, faces[f][0]), b = vertexAt(positions, faces[f][1]), c = vertexAt(positions, faces[f][2]);
        const Vec3 cr = cross(b - a, c - a);
        const double len = length(cr);
        if (!(len > 1e-14 * size * size)) return fail(why, "a face has no area");
        normal[f] = (1 / len) * cr;
        // Angle-weighted mean normal (Thürmer and Wüthrich 1998): independent of how a flat
        // region is cut into triangles.
        for (int k = 0; k < 3; ++k) {
            const Vec3 p = vertexAt(positions, faces[f][k]);
            const Vec3 u = vertexAt(positions, faces[f][(k + 1) % 3]) - p, w = vertexAt(positions, faces[f][(k + 2) % 3]) - p;
            const double angle = std::atan2(length(cross(u, w)), dot(u, w));
            meanNormal[faces[f][k]] += angle * normal[f];
        }
    }
    std::vector<uint32_t> start(n + 1, 0), around(3 * m);
    for (const auto& f : faces)
        for (uint32_t v : f) ++start[v + 1];
    for (size_t v = 0; v < n; ++v) start[v + 1] += start[v];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t f = 0; f < m; ++f)
            for (uint32_t v : faces[f]) around[fill[v]++] = f;
    }
    // Displacements: the nearest to offset * mean normal with every face around at the offset.
    std::vector<Vec3> shift(n, Vec3{0, 0, 0});
    std::vector<HalfSpace> spaces;
    for (uint32_t v = 0; v < n; ++v) {
        if (start[v] == start[v + 1]) continue;
        const double ml = length(meanNormal[v]);
        if (!(ml > 1e-9)) return fail(why, "a vertex has faces turned every way");
        spaces.clear();
        for (uint32_t k = start[v]; k < start[v + 1]; ++k) spaces.push_back(HalfSpace{normal[around[k]], offset});
        Vec3 d;
        if (!nearestPointAbovePlanes(spaces.data(), spaces.size(), (offset / ml) * meanNormal[v], d))
            return fail(why, "a fold too sharp to thicken");
        for (const HalfSpace& s : spaces)
            if (dot(s.normal, d) < 0.999 * offset) return fail(why, "a fold too sharp to thicken");
        if (length(d) > maxDisplacement) return fail(why, "a fold too sharp to thicken");
        shift[v] = d;
    }

    // Output: for each used vertex its outer and inner copies; boundary vertices also itself.
    std::vector<uint8_t> onBoundary(n, 0);
    for (uint32_t f = 0; f < m; ++f)
        for (int c = 0; c < 3; ++c)
            if (across[f][c] == UINT32_MAX) onBoundary[faces[f][c]] = onBoundary[faces[f][(c + 1) % 3]] = 1;
    std::vector<uint32_t> outer(n, UINT32_MAX), inner(n, UINT32_MAX), middle(n, UINT32_MAX);
    auto emit = [&](const Vec3& p) {
        outPositions.insert(outPositions.end(), {p.x, p.y, p.z});
        return uint32_t(outPositions.size() / 3 - 1);
    };
    for (uint32_t v = 0; v < n; ++v) {
        if (start[v] == start[v + 1]) continue;
        const Vec3 p = vertexAt(positions, v);
        outer[v] = emit(p + shift[v]);
        inner[v] = emit(p - shift[v]);
        if (onBoundary[v]) middle[v] = emit(p);
    }
    for (const auto& f : faces) outTriangles.insert(outTriangles.end(), {outer[f[0]], outer[f[1]], outer[f[2]]});
    for (const auto& f : faces) outTriangles.insert(outTriangles.end(), {inner[f[0]], inner[f[2]], inner[f[1]]});
    for (uint32_t f = 0; f < m; ++f)
        for (int c = 0; c < 3; ++c) {
            if (across[f][c] != UINT32_MAX) continue;
            const uint32_t a = faces[f][c], b = faces[f][(c + 1) % 3];
            outTriangles.insert(outTriangles.end(), {outer[b], outer[a], middle[a], outer[b], middle[a], middle[b],
                                                     middle[b], middle[a], inner[a], middle[b], inner[a], inner[b]});
        }
    auto refuse = [&](const char* reason) {
        outPositions.clear();
        outTriangles.clear();
        return fail(why, reason);
    };
    // Every sheet face keeps its side (a face turned over is a fold the check below may not
    // see, since it skips faces that share a vertex), and no two faces meet.
    for (uint32_t f = 0; f < 2 * m; ++f) {
        const uint32_t* t = &outTriangles[3 * f];
        const Vec3 a = vertexAt(outPositions, t[0]), b = vertexAt(outPositions, t[1]), c = vertexAt(outPositions, t[2]);
        const Vec3 n0 = f < m ? normal[f] : -normal[f - m];
        if (!(dot(cross(b - a, c - a), n0) > 0)) return refuse("a sheet folds over (detail finer than twice the offset)");
    }
    if (selfIntersects(outPositions, outTriangles)) return refuse("its two sheets would cross (detail finer than twice the offset)");
    // Each face keeps the offset from the sheet faces made from its own vertices; a face of
    // another part of the surface may come nearer. Half the offset from both sheets everywhere
    // is what the caller relies on.
    {
        std::vector<uint32_t> flat(3 * m);
        for (uint32_t f = 0; f < m; ++f) std::copy(faces[f].begin(), faces[f].end(), flat.begin() + 3 * f);
        TriangleBvh surface, sheets;
        surface.build(positions.data(), n, flat.data(), m);
        sheets.build(outPositions.data(), outPositions.size() / 3, outTriangles.data(), 2 * m);
        if (meshDistance(surface, sheets, 0.5 * offset, 0.5 * offset).distance < 0.5 * offset)
            return refuse("its sheets come nearer it than half the offset (detail finer than twice the offset)");
    }
    // Pieces apart (their shells do not cross, checked above) must not lie inside one another:
    // nested shells do not bound a solid. One vertex of each piece's shell against the shells
    // of the others (generalized winding number), within a fixed budget of work.
    if (pieces > 1) {
        if (double(pieces) * double(outTriangles.size() / 3) > 2e7) return refuse("too many separate pieces");
        // The piece of each output face: sheets in face order, then four per boundary edge.
        std::vector<uint32_t> pieceOfOutput(outTriangles.size() / 3);
        for (uint32_t f = 0; f < m; ++f) pieceOfOutput[f] = pieceOfOutput[m + f] = pieceOf[f];
        size_t strip = 2 * m;
        for (uint32_t f = 0; f < m; ++f)
            for (int c = 0; c < 3; ++c)
                if (across[f][c] == UINT32_MAX)
                    for (int k = 0; k < 4; ++k) pieceOfOutput[strip++] = pieceOf[f];
        std::vector<uint32_t> probe(pieces, UINT32_MAX), others;
        for (uint32_t f = 0; f < m; ++f)
            if (probe[pieceOf[f]] == UINT32_MAX) probe[pieceOf[f]] = outer[faces[f][0]];
        for (uint32_t piece = 0; piece < pieces; ++piece) {
            others.clear();
            for (size_t t = 0; t < pieceOfOutput.size(); ++t)
                if (pieceOfOutput[t] != piece) others.insert(others.end(), &outTriangles[3 * t], &outTriangles[3 * t] + 3);
            if (windingNumber(outPositions, others, &outPositions[3 * probe[piece]]) > 0.5)
                return refuse("a piece of it lies inside another's shell");
        }
    }
    return true;
}

}  // namespace aggrelod::detail
