// SPDX-License-Identifier: AGPL-3.0-or-later
// The neighbourhood graph in 2D (paper Section 3.2; docs/design.md §2.2): per model pair the
// free-space edges joining them, with their lengths for the statistics of the aggregate
// function (neighbourhood_graph.h), and the shortest connection that weighs the pair.
#include "baker_2d.h"

#include "parallel_for.h"

#include <cmath>
#include <thread>
#include <tuple>

namespace aggrelod::detail {
namespace {

double pointSegmentDistance(const double* p, const double* a, const double* b) {
    const double dx = b[0] - a[0], dy = b[1] - a[1];
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0 ? ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / len2 : 0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy));
}

}  // namespace

void buildNeighbourhoodGraph2D(FreeSpace2D& space, bool graphOnly, int threadCount) {
    const Triangulation2D& tri = space.tri;
    const size_t faceCount = tri.faceCount();
    const size_t faceBlocks = faceBlockCount(faceCount);
    // 5. Neighbourhood graph: per model pair the free edges joining them; weight = the
    // shortest connection seen in a free triangle (edge, or vertex to a model's boundary edge).
    space.faceArea.resize(faceCount);
    space.edgeLength.resize(3 * faceCount);
    space.faceLongest.resize(faceCount);
    if (!graphOnly) space.edgePair.assign(3 * faceCount, kSameModelEdge);
    struct PairEntry {  // 40 bytes: the grouping below moves many of them
        uint32_t a, b;
        double distance;    // of the connection; for an edge entry, the edge length
        int face;
        int connection[3];  // see ModelPair2D::connection
        int8_t edge;        // the face's edge for an edge entry, -1 for a distance-only entry
        bool counted;       // an edge entry counted in the pair's lengths (each undirected edge once)
    };
    auto P = [&](int v) { return &tri.points[2 * static_cast<size_t>(v)]; };
    // The entries of free face f: each edge joining two models, and each vertex facing another
    // model's boundary edge. Calls edge(a, b, j, u, w, counted) and vertex(a, b, k, j1, j2).
    auto visitEntries = [&](size_t f, auto&& edge, auto&& vertex) {
        const int* v = &tri.faces[3 * f];
        for (int j = 0; j < 3; ++j) {
            const int u = v[(j + 1) % 3], w = v[(j + 2) % 3];
            const int mu = space.vertexModel[u], mw = space.vertexModel[w];
            if (mu < 0 || mw < 0 || mu == mw) continue;
            const int n = tri.neighbors[3 * f + j];
            // Count each undirected edge once (from its smaller free face, or its only one).
            const bool counted = n < 0 || space.faceModel[n] >= 0 || static_cast<int>(f) < n;
            edge(static_cast<uint32_t>(std::min(mu, mw)), static_cast<uint32_t>(std::max(mu, mw)), j, u, w, counted);
        }
        for (int k = 0; k < 3; ++k) {
            const int j1 = (k + 1) % 3, j2 = (k + 2) % 3;
            const int mk = space.vertexModel[v[k]], m1 = space.vertexModel[v[j1]], m2 = space.vertexModel[v[j2]];
            if (mk < 0 || m1 < 0 || m1 != m2 || mk == m1 || !tri.constrained[3 * f + k]) continue;
            vertex(static_cast<uint32_t>(std::min(mk, m1)), static_cast<uint32_t>(std::max(mk, m1)), k, j1, j2);
        }
    };
    // Entries grouped by model a in face order, written straight into place: faces go in a
    // fixed number of contiguous chunks; pass 1 measures every face and counts its entries
    // per a, pass 2 writes them (same order for any chunk or thread count). Then a stable
    // sort on b per model: each pair's entries form one run, and its shortest connection is
    // the least entry of the run by (distance, face, edge, connection).
    const size_t threads = threadCount > 0 ? static_cast<size_t>(threadCount)
                                           : std::max<size_t>(1, std::thread::hardware_concurrency());
    const size_t chunks = std::min({faceBlocks, 2 * threads, size_t{16}});  // chunks x models counters
    std::vector<std::vector<uint32_t>> chunkPlace(chunks, std::vector<uint32_t>(space.modelCount, 0));
    auto chunkFaces = [&](size_t c) { return std::make_pair(faceCount * c / chunks, faceCount * (c + 1) / chunks); };
    parallelFor(chunks, threadCount, [&](size_t c) {
        std::vector<uint32_t>& count = chunkPlace[c];
        const auto [first, last] = chunkFaces(c);
        for (size_t f = first; f < last; ++f) {
            const int* v = &tri.faces[3 * f];
            space.faceArea[f] = 0.5 * ((P(v[1])[0] - P(v[0])[0]) * (P(v[2])[1] - P(v[0])[1]) -
                                       (P(v[2])[0] - P(v[0])[0]) * (P(v[1])[1] - P(v[0])[1]));
            double longest = 0;
            for (int j = 0; j < 3; ++j) {
                const int u = v[(j + 1) % 3], w = v[(j + 2) % 3];
                const double dx = P(w)[0] - P(u)[0], dy = P(w)[1] - P(u)[1];
                const double length = std::sqrt(dx * dx + dy * dy);  // not hypot: 5x slower, no overflow risk here
                space.edgeLength[3 * f + j] = length;
                longest = std::max(longest, length);
            }
            space.faceLongest[f] = longest;
            if (space.faceModel[f] >= 0) continue;
            visitEntries(f, [&](uint32_t a, uint32_t, int, int, int, bool) { ++count[a]; },
                         [&](uint32_t a, uint32_t, int, int, int) { ++count[a]; });
        }
    });
    std::vector<uint32_t> start(space.modelCount + 1, 0);
    for (size_t m = 0; m < space.modelCount; ++m) {
        uint32_t place = start[m];
        for (size_t c = 0; c < chunks; ++c) {
            const uint32_t count = chunkPlace[c][m];
            chunkPlace[c][m] = place;
            place += count;
        }
        start[m + 1] = place;
    }
    std::vector<PairEntry> entries(start[space.modelCount]);
    parallelFor(chunks, threadCount, [&](size_t c) {
        std::vector<uint32_t>& place = chunkPlace[c];
        const auto [first, last] = chunkFaces(c);
        for (size_t f = first; f < last; ++f) {
            if (space.faceModel[f] >= 0) continue;
            const int* v = &tri.faces[3 * f];
            visitEntries(
                f,
                [&](uint32_t a, uint32_t b, int j, int u, int w, bool counted) {
                    entries[place[a]++] = {a, b, space.edgeLength[3 * f + j], static_cast<int>(f), {u, w, -1},
                                           static_cast<int8_t>(j), counted};
                },
                [&](uint32_t a, uint32_t b, int k, int j1, int j2) {
                    entries[place[a]++] = {a, b, pointSegmentDistance(P(v[k]), P(v[j1]), P(v[j2])), static_cast<int>(f),
                                           {v[k], v[j1], v[j2]}, -1, false};
                });
        }
    });
    std::vector<std::vector<uint32_t>>().swap(chunkPlace);
    const size_t modelBlocks = std::clamp<size_t>(space.modelCount / 1024, 1, 64);
    auto blockModels = [&](size_t block) {
        return std::make_pair(space.modelCount * block / modelBlocks, space.modelCount * (block + 1) / modelBlocks);
    };
    parallelFor(modelBlocks, threadCount, [&](size_t block) {
        const auto [firstModel, lastModel] = blockModels(block);
        for (size_t m = firstModel; m < lastModel; ++m) {
            const auto first = entries.begin() + start[m], last = entries.begin() + start[m + 1];
            if (last - first <= 32) {  // the usual case: an insertion sort (stable)
                for (auto i = first + (first != last); i < last; ++i)
                    for (auto j = i; j > first && (j - 1)->b > j->b; --j) std::iter_swap(j - 1, j);
            } else {
                std::stable_sort(first, last, [](const PairEntry& x, const PairEntry& y) { return x.b < y.b; });
            }
        }
    });
    // Pairs by blocks of models (contiguous runs of entries): the blocks count their pairs and
    // lengths first, then each fills its own slots of the (a, b)-ordered lists.
    auto less = [](const PairEntry& x, const PairEntry& y) {
        return std::tie(x.distance, x.face, x.edge, x.connection[0], x.connection[1], x.connection[2]) <
               std::tie(y.distance, y.face, y.edge, y.connection[0], y.connection[1], y.connection[2]);
    };
    auto runEnd = [&](size_t i, size_t end) {
        size_t e = i;
        while (e < end && entries[e].a == entries[i].a && entries[e].b == entries[i].b) ++e;
        return e;
    };
    std::vector<size_t> blockPairs(modelBlocks + 1, 0), blockLengths(modelBlocks + 1, 0);
    parallelFor(modelBlocks, threadCount, [&](size_t block) {
        const auto [firstModel, lastModel] = blockModels(block);
        const size_t end = start[lastModel];
        for (size_t i = start[firstModel]; i < end; i = runEnd(i, end)) ++blockPairs[block + 1];
        for (size_t i = start[firstModel]; i < end; ++i) blockLengths[block + 1] += entries[i].counted;
    });
    for (size_t block = 0; block < modelBlocks; ++block) {
        blockPairs[block + 1] += blockPairs[block];
        blockLengths[block + 1] += blockLengths[block];
    }
    const size_t pairCount = blockPairs[modelBlocks];
    space.pairs.resize(pairCount);
    if (!graphOnly) {
        space.edgeLengths.lengths.resize(blockLengths[modelBlocks]);
        space.edgeLengths.prefixSum.resize(blockLengths[modelBlocks] + pairCount);
        space.edgeLengths.prefixSumSquares.resize(blockLengths[modelBlocks] + pairCount);
    }
    parallelFor(modelBlocks, threadCount, [&](size_t block) {
        const auto [firstModel, lastModel] = blockModels(block);
        const size_t end = start[lastModel];
        size_t pairIndex = blockPairs[block], lengthAt = blockLengths[block];
        for (size_t i = start[firstModel], e; i < end; i = e, ++pairIndex) {
            e = runEnd(i, end);
            size_t best = i;
            for (size_t k = i + 1; k < e; ++k)
                if (less(entries[k], entries[best])) best = k;
            ModelPair2D& pair = space.pairs[pairIndex];
            pair.a = entries[i].a;
            pair.b = entries[i].b;
            pair.minDistance = entries[best].distance;
            pair.bestFace[0] = entries[best].face;
            std::copy(entries[best].connection, entries[best].connection + 3, pair.connection);
            // The second face: the smallest other face holding a connection as short.
            for (size_t k = i; k < e; ++k)
                if (entries[k].distance == pair.minDistance && entries[k].face != pair.bestFace[0] &&
                    (pair.bestFace[1] < 0 || entries[k].face < pair.bestFace[1]))
                    pair.bestFace[1] = entries[k].face;
            if (graphOnly) continue;
            pair.firstLength = static_cast<uint32_t>(lengthAt);
            for (size_t k = i; k < e; ++k)
                if (entries[k].counted) space.edgeLengths.lengths[lengthAt++] = entries[k].distance;
            pair.lengthCount = static_cast<uint32_t>(lengthAt - pair.firstLength);
            double* lengths = space.edgeLengths.lengths.data() + pair.firstLength;
            std::sort(lengths, lengths + pair.lengthCount);
            pair.firstPrefix = static_cast<uint32_t>(pair.firstLength + pairIndex);
            space.edgeLengths.fillRunningSums(pair);
            // Each free edge's pair (every (face, edge) is in one entry at most: distinct slots).
            for (size_t k = i; k < e; ++k)
                if (entries[k].edge >= 0)
                    space.edgePair[3 * static_cast<size_t>(entries[k].face) + entries[k].edge] = static_cast<int>(pairIndex);
        }
    });
    if (!graphOnly) {
        parallelForEach(faceCount, threadCount, [&](size_t f) {
            for (int j = 0; j < 3; ++j) {
                const int u = tri.faces[3 * f + (j + 1) % 3], w = tri.faces[3 * f + (j + 2) % 3];
                if (space.vertexModel[u] < 0 || space.vertexModel[w] < 0) space.edgePair[3 * f + j] = kUnpairedEdge;
            }
        });
    }
}

std::vector<GraphEdge> weighedGraph(const FreeSpace2D& space) {
    return graphEdges(space.pairs, [](const ModelPair2D& p) { return p.minDistance; });
}

}  // namespace aggrelod::detail
