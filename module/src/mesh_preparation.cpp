// SPDX-License-Identifier: AGPL-3.0-or-later
// Input clean-up (docs/design.md §2 and §5): exact weld, degenerate removal, finiteness check,
// closedness / manifoldness / orientation analysis, inside-out repair per shell.
#include "mesh_preparation.h"

#include "mesh_distance.h"

#include <aggrelod/disjoint_sets.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <string>
#include <tuple>

namespace aggrelod::detail {
namespace {

void addDiagnostic(std::vector<Diagnostic>& out, Diagnostic::Severity severity, const std::string& object,
                   const std::string& message) {
    out.push_back(Diagnostic{severity, object, message});
}

double triangleArea(const double* a, const double* b, const double* c) {
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    return 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
}

}  // namespace

void meshVolumeArea(const std::vector<double>& positions, const std::vector<uint32_t>& triangles,
                    double& volume, double& area) {
    volume = 0;
    area = 0;
    for (size_t t = 0; t + 2 < triangles.size(); t += 3) {
        const double* a = &positions[3 * triangles[t]];
        const double* b = &positions[3 * triangles[t + 1]];
        const double* c = &positions[3 * triangles[t + 2]];
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                   a[2] * (b[0] * c[1] - b[1] * c[0])) / 6.0;
        area += triangleArea(a, b, c);
    }
}

double windingNumber(const std::vector<double>& p, const std::vector<uint32_t>& t, const double* q) {
    double total = 0;
    for (size_t i = 0; i + 2 < t.size(); i += 3) {
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = p[3 * t[i] + k] - q[k];
            b[k] = p[3 * t[i + 1] + k] - q[k];
            c[k] = p[3 * t[i + 2] + k] - q[k];
        }
        const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        const double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                           a[2] * (b[0] * c[1] - b[1] * c[0]);
        const double ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        const double bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
        const double ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
        total += 2.0 * std::atan2(det, la * lb * lc + ab * lc + bc * la + ca * lb);
    }
    return total / (4.0 * M_PI);
}

bool selfIntersects(const std::vector<double>& positions, const std::vector<uint32_t>& triangles) {
    const size_t m = triangles.size() / 3;
    if (m < 2) return false;
    std::vector<std::array<double, 6>> box(m);
    double all[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    double extentSum = 0;
    for (size_t t = 0; t < m; ++t) {
        for (int k = 0; k < 3; ++k) {
            box[t][k] = INFINITY;
            box[t][3 + k] = -INFINITY;
        }
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 3; ++k) {
                const double v = positions[3 * triangles[3 * t + c] + k];
                box[t][k] = std::min(box[t][k], v);
                box[t][3 + k] = std::max(box[t][3 + k], v);
            }
        for (int k = 0; k < 3; ++k) {
            all[k] = std::min(all[k], box[t][k]);
            all[3 + k] = std::max(all[3 + k], box[t][3 + k]);
        }
        extentSum += std::max({box[t][3] - box[t][0], box[t][4] - box[t][1], box[t][5] - box[t][2]});
    }
    // The pairs tested: boxes that overlap, triangles that share no vertex. Found in a uniform
    // grid of cells twice the mean triangle size (each pair in the first cell both boxes
    // touch), a sweep along x within each cell; the few triangles that would span more than
    // 27 cells are tested against every other by box. A single sweep along x over a flat sheet lying across
    // x would compare each triangle with a whole column of the sheet.
    auto test = [&](uint32_t a, uint32_t b) {
        if (box[b][0] > box[a][3] || box[a][0] > box[b][3] || box[b][1] > box[a][4] || box[a][1] > box[b][4] ||
            box[b][2] > box[a][5] || box[a][2] > box[b][5])
            return false;
        const uint32_t* ta = &triangles[3 * a];
        const uint32_t* tb = &triangles[3 * b];
        for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y)
                if (ta[x] == tb[y]) return false;
        bool intersecting = false;
        triangleTriangleDistance(&positions[3 * ta[0]], &positions[3 * ta[1]], &positions[3 * ta[2]], &positions[3 * tb[0]],
                                 &positions[3 * tb[1]], &positions[3 * tb[2]], nullptr, nullptr, &intersecting);
        return intersecting;
    };
    const double cell = std::max(2 * extentSum / double(m),
                                 1e-9 * std::max({all[3] - all[0], all[4] - all[1], all[5] - all[2], 1e-300}));
    uint64_t dims[3];
    for (int k = 0; k < 3; ++k) dims[k] = std::min<uint64_t>(uint64_t((all[3 + k] - all[k]) / cell) + 1, uint64_t(1) << 20);
    auto cellOf = [&](double v, int k) {
        return std::min<uint64_t>(uint64_t(std::max(0.0, (v - all[k]) / cell)), dims[k] - 1);
    };
    constexpr uint64_t kMaxCellsPerTriangle = 27;
    std::vector<std::pair<uint64_t, uint32_t>> entries;  // (cell key, triangle)
    std::vector<uint32_t> large;
    std::vector<std::array<uint64_t, 6>> range(m);
    for (uint32_t t = 0; t < m; ++t) {
        for (int k = 0; k < 3; ++k) {
            range[t][k] = cellOf(box[t][k], k);
            range[t][3 + k] = cellOf(box[t][3 + k], k);
        }
        const uint64_t count = (range[t][3] - range[t][0] + 1) * (range[t][4] - range[t][1] + 1) * (range[t][5] - range[t][2] + 1);
        if (count > kMaxCellsPerTriangle) {
            large.push_back(t);
            continue;
        }
        for (uint64_t z = range[t][2]; z <= range[t][5]; ++z)
            for (uint64_t y = range[t][1]; y <= range[t][4]; ++y)
                for (uint64_t x = range[t][0]; x <= range[t][3]; ++x) entries.emplace_back(x + dims[0] * (y + dims[1] * z), t);
    }
    std::vector<char> isLarge(m, 0);
    for (uint32_t t : large) isLarge[t] = 1;
    for (uint32_t a : large)
        for (uint32_t b = 0; b < m; ++b)
            if (b != a && (!isLarge[b] || b > a) && test(a, b)) return true;
    std::sort(entries.begin(), entries.end());
    std::vector<uint32_t> run;
    for (size_t i = 0; i < entries.size();) {
        size_t j = i;
        while (j < entries.size() && entries[j].first == entries[i].first) ++j;
        if (j - i >= 2) {
            const uint64_t key = entries[i].first;
            run.clear();
            for (size_t k = i; k < j; ++k) run.push_back(entries[k].second);
            std::sort(run.begin(), run.end(), [&](uint32_t a, uint32_t b) { return std::make_pair(box[a][0], a) < std::make_pair(box[b][0], b); });
            for (size_t p = 0; p < run.size(); ++p) {
                const uint32_t a = run[p];
                for (size_t q = p + 1; q < run.size(); ++q) {
                    const uint32_t b = run[q];
                    if (box[b][0] > box[a][3]) break;
                    // Only in the first cell both ranges share: each pair once.
                    const uint64_t first = std::max(range[a][0], range[b][0]) +
                                           dims[0] * (std::max(range[a][1], range[b][1]) + dims[1] * std::max(range[a][2], range[b][2]));
                    if (first == key && test(a, b)) return true;
                }
            }
        }
        i = j;
    }
    return false;
}

PreparedObject checkedSurface(const std::vector<double>& positions, const std::vector<uint32_t>& triangles) {
    InputObject surface;
    surface.positions = positions;
    surface.indices = triangles;
    PreparedObject check;
    std::vector<Diagnostic> ignored;
    prepareObject(surface, 0.0, check, ignored);
    return check;
}

void prepareObject(const InputObject& object, double areaEpsilon, PreparedObject& out,
                   std::vector<Diagnostic>& diagnostics) {
    out = PreparedObject{};
    const std::string& name = object.name;
    const size_t vertexCount = object.positions.size() / 3;
    if (object.positions.size() % 3 != 0) {
        addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                      "position array length is not a multiple of 3; object skipped");
        return;
    }
    if (object.indices.size() % 3 != 0) {
        addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                      "index array length is not a multiple of 3; object skipped");
        return;
    }
    for (size_t i = 0; i < object.indices.size(); ++i) {
        if (object.indices[i] >= vertexCount) {
            addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                          "index out of range: triangle " + std::to_string(i / 3) + " uses vertex " +
                              std::to_string(object.indices[i]) + " of " + std::to_string(vertexCount) +
                              "; object skipped");
            return;
        }
    }
    for (size_t i = 0; i < object.positions.size(); ++i) {
        if (!std::isfinite(object.positions[i])) {
            addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                          std::string("coordinate is not finite (") + (std::isnan(object.positions[i]) ? "NaN" : "inf") +
                              ") at vertex " + std::to_string(i / 3) + "; object skipped");
            return;
        }
    }
    if (object.indices.empty()) {
        addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name, "has no triangles; object skipped");
        return;
    }

    // Exact weld: sort vertices by position, merge equal ones (deterministic, no hashing).
    std::vector<uint32_t> order(vertexCount);
    std::iota(order.begin(), order.end(), 0u);
    auto pos = [&](uint32_t v) {
        return std::make_tuple(object.positions[3 * v], object.positions[3 * v + 1], object.positions[3 * v + 2]);
    };
    std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) { return pos(a) < pos(b); });
    std::vector<uint32_t> remap(vertexCount, 0);
    std::vector<uint32_t> firstUse;  // welded vertex -> representative input vertex
    for (size_t i = 0; i < order.size(); ++i) {
        if (i == 0 || pos(order[i]) != pos(order[i - 1])) firstUse.push_back(order[i]);
        remap[order[i]] = static_cast<uint32_t>(firstUse.size() - 1);
    }
    // Renumber welded vertices in order of first appearance in the index list (stable output).
    std::vector<uint32_t> newIndex(firstUse.size(), UINT32_MAX);
    uint32_t next = 0;
    size_t degenerate = 0;
    for (size_t t = 0; t < object.indices.size(); t += 3) {
        uint32_t a = remap[object.indices[t]], b = remap[object.indices[t + 1]], c = remap[object.indices[t + 2]];
        const double* pa = &object.positions[3 * firstUse[a]];
        const double* pb = &object.positions[3 * firstUse[b]];
        const double* pc = &object.positions[3 * firstUse[c]];
        if (a == b || b == c || a == c || triangleArea(pa, pb, pc) <= areaEpsilon) {
            ++degenerate;
            continue;
        }
        for (uint32_t w : {a, b, c}) {
            if (newIndex[w] == UINT32_MAX) {
                newIndex[w] = next++;
                const double* p = &object.positions[3 * firstUse[w]];
                out.positions.insert(out.positions.end(), p, p + 3);
            }
            out.triangles.push_back(newIndex[w]);
        }
    }
    if (degenerate > 0) {
        addDiagnostic(diagnostics, Diagnostic::Severity::Note, name,
                      "dropped " + std::to_string(degenerate) + " degenerate triangle(s)");
    }
    if (out.triangles.empty()) {
        addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                      "has no non-degenerate triangles; object skipped");
        return;
    }
    out.usable = true;
    const size_t n = out.positions.size() / 3;
    for (int k = 0; k < 3; ++k) {
        out.bounds[k] = INFINITY;
        out.bounds[3 + k] = -INFINITY;
    }
    for (size_t v = 0; v < n; ++v)
        for (int k = 0; k < 3; ++k) {
            out.bounds[k] = std::min(out.bounds[k], out.positions[3 * v + k]);
            out.bounds[3 + k] = std::max(out.bounds[3 + k], out.positions[3 * v + k]);
        }

    // Edge analysis: directed edges sorted by (min, max, direction).
    const size_t triCount = out.triangles.size() / 3;
    struct HalfEdge {
        uint32_t lo, hi, tri;
        bool forward;  // lo -> hi
    };
    std::vector<HalfEdge> edges;
    edges.reserve(out.triangles.size());
    for (size_t t = 0; t < triCount; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = out.triangles[3 * t + k], b = out.triangles[3 * t + (k + 1) % 3];
            edges.push_back({std::min(a, b), std::max(a, b), static_cast<uint32_t>(t), a < b});
        }
    std::sort(edges.begin(), edges.end(), [](const HalfEdge& x, const HalfEdge& y) {
        return std::tie(x.lo, x.hi, x.tri) < std::tie(y.lo, y.hi, y.tri);
    });
    size_t boundaryEdges = 0, nonManifoldEdges = 0, misoriented = 0;
    DisjointSets shells(triCount);
    std::vector<std::array<uint32_t, 2>> manifoldPairs;  // triangle pairs sharing a 2-use edge
    std::vector<bool> sameDirection;
    for (size_t i = 0; i < edges.size();) {
        size_t j = i;
        while (j < edges.size() && edges[j].lo == edges[i].lo && edges[j].hi == edges[i].hi) ++j;
        const size_t uses = j - i;
        if (uses == 1) ++boundaryEdges;
        else if (uses > 2) ++nonManifoldEdges;
        else {
            shells.unite(edges[i].tri, edges[i + 1].tri);
            manifoldPairs.push_back({edges[i].tri, edges[i + 1].tri});
            sameDirection.push_back(edges[i].forward == edges[i + 1].forward);
            if (edges[i].forward == edges[i + 1].forward) ++misoriented;
        }
        i = j;
    }
    out.closed = boundaryEdges == 0 && nonManifoldEdges == 0;
    if (boundaryEdges > 0)
        addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                      "open mesh: " + std::to_string(boundaryEdges) + " boundary edge(s)");
    if (nonManifoldEdges > 0)
        addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name,
                      "non-manifold mesh: " + std::to_string(nonManifoldEdges) + " edge(s) used by more than two triangles");

    if (out.closed && misoriented > 0) {
        // Try to make orientation consistent per shell by propagation (BFS over triangle pairs).
        std::vector<std::vector<std::pair<uint32_t, bool>>> adjacency(triCount);
        for (size_t e = 0; e < manifoldPairs.size(); ++e) {
            adjacency[manifoldPairs[e][0]].push_back({manifoldPairs[e][1], sameDirection[e]});
            adjacency[manifoldPairs[e][1]].push_back({manifoldPairs[e][0], sameDirection[e]});
        }
        std::vector<int> flip(triCount, -1);
        bool orientable = true;
        for (size_t seed = 0; seed < triCount && orientable; ++seed) {
            if (flip[seed] >= 0) continue;
            flip[seed] = 0;
            std::vector<uint32_t> stack{static_cast<uint32_t>(seed)};
            while (!stack.empty() && orientable) {
                uint32_t t = stack.back();
                stack.pop_back();
                for (auto [u, same] : adjacency[t]) {
                    int want = flip[t] ^ (same ? 1 : 0);
                    if (flip[u] < 0) {
                        flip[u] = want;
                        stack.push_back(u);
                    } else if (flip[u] != want) {
                        orientable = false;
                        break;
                    }
                }
            }
        }
        if (orientable) {
            for (size_t t = 0; t < triCount; ++t)
                if (flip[t] == 1) std::swap(out.triangles[3 * t + 1], out.triangles[3 * t + 2]);
            misoriented = 0;
            addDiagnostic(diagnostics, Diagnostic::Severity::Note, name,
                          "inconsistent triangle orientation repaired");
        } else {
            addDiagnostic(diagnostics, Diagnostic::Severity::Warning, name, "mesh is not orientable");
        }
    }
    out.consistent = out.closed && misoriented == 0;

    if (out.consistent) {
        // Orient every shell outward: a shell with negative signed volume is inside-out.
        std::vector<double> shellVolume(triCount, 0.0);
        for (size_t t = 0; t < triCount; ++t) {
            const double* a = &out.positions[3 * out.triangles[3 * t]];
            const double* b = &out.positions[3 * out.triangles[3 * t + 1]];
            const double* c = &out.positions[3 * out.triangles[3 * t + 2]];
            // relative to the object's min corner for accuracy
            double ra[3], rb[3], rc[3];
            for (int k = 0; k < 3; ++k) {
                ra[k] = a[k] - out.bounds[k];
                rb[k] = b[k] - out.bounds[k];
                rc[k] = c[k] - out.bounds[k];
            }
            shellVolume[shells.find(static_cast<uint32_t>(t))] +=
                (ra[0] * (rb[1] * rc[2] - rb[2] * rc[1]) - ra[1] * (rb[0] * rc[2] - rb[2] * rc[0]) +
                 ra[2] * (rb[0] * rc[1] - rb[1] * rc[0])) / 6.0;
        }
        size_t flipped = 0;
        for (size_t t = 0; t < triCount; ++t) {
            if (shellVolume[shells.find(static_cast<uint32_t>(t))] < 0) {
                std::swap(out.triangles[3 * t + 1], out.triangles[3 * t + 2]);
                ++flipped;
            }
        }
        if (flipped > 0)
            addDiagnostic(diagnostics, Diagnostic::Severity::Note, name,
                          "inside-out mesh: " + std::to_string(flipped) + " triangle(s) flipped to face outward");
    }
    meshVolumeArea(out.positions, out.triangles, out.volume, out.area);
    if (!out.consistent) out.volume = std::fabs(out.volume);
}

}  // namespace aggrelod::detail
