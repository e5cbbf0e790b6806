// SPDX-License-Identifier: AGPL-3.0-or-later
// The input rings as one vertex array (see input_vertices_2d.h).
#include "input_vertices_2d.h"

#include "radix_sort.h"

#include <cmath>

namespace aggrelod::detail {

void buildSegmentGrid(InputVertices& in) {
    const size_t n = in.part.size();
    if (n == 0) return;
    double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY, sumLen = 0;
    for (size_t i = 0; i < n; ++i) {
        minX = std::min(minX, in.x(i));
        maxX = std::max(maxX, in.x(i));
        minY = std::min(minY, in.y(i));
        maxY = std::max(maxY, in.y(i));
        sumLen += std::hypot(in.x(in.next(i)) - in.x(i), in.y(in.next(i)) - in.y(i));
    }
    const double span = std::max(maxX - minX, maxY - minY);
    double cell = std::max(2 * sumLen / static_cast<double>(n), span / 4096);
    if (!(cell > 0) || !std::isfinite(cell)) cell = 1;
    in.gridX0 = minX;
    in.gridY0 = minY;
    in.gridCell = cell;
    in.gridNx = std::max<long long>(1, std::min<long long>(static_cast<long long>((maxX - minX) / cell) + 1, 1 << 20));
    in.gridNy = std::max<long long>(1, std::min<long long>(static_cast<long long>((maxY - minY) / cell) + 1, 1 << 20));
    in.gridEntries.clear();
    in.longSegments.clear();
    for (size_t i = 0; i < n; ++i) {
        const size_t j = in.next(i);
        const long long x0 = in.cellX(std::min(in.x(i), in.x(j))), x1 = in.cellX(std::max(in.x(i), in.x(j)));
        const long long y0 = in.cellY(std::min(in.y(i), in.y(j))), y1 = in.cellY(std::max(in.y(i), in.y(j)));
        if ((x1 - x0 + 1) * (y1 - y0 + 1) > 64) {
            in.longSegments.push_back(static_cast<uint32_t>(i));
            continue;
        }
        for (long long cy = y0; cy <= y1; ++cy)
            for (long long cx = x0; cx <= x1; ++cx) in.gridEntries.emplace_back(cy * in.gridNx + cx, static_cast<uint32_t>(i));
    }
    sortGridEntries(in.gridEntries, static_cast<size_t>(in.gridNx * in.gridNy));
}

void markTouchingParts(InputVertices& in, const CheckedPolygons& checked) {
    in.partTouches.assign(checked.parts.size(), 0);
    for (auto [a, b] : checked.touchingParts) in.partTouches[a] = in.partTouches[b] = 1;
}

void setShared(InputVertices& in, const Triangulation2D& tri) {
    std::vector<uint8_t> count(tri.vertexCount(), 0);
    for (int v : tri.inputVertex) count[v] = static_cast<uint8_t>(std::min(count[v] + 1, 2));
    in.shared.resize(in.part.size());
    for (size_t i = 0; i < in.shared.size(); ++i) in.shared[i] = count[tri.inputVertex[i]] > 1;
}

InputVertices inputVertices(const CheckedPolygons& checked, const SegmentSplits* splits, bool withGrid) {
    InputVertices in;
    size_t original = 0;
    for (uint32_t p = 0; p < checked.parts.size(); ++p) {
        const Polygon2D& poly = checked.parts[p];
        for (int h = -1; h < static_cast<int>(poly.holes.size()); ++h) {
            const std::vector<double>& ring = h < 0 ? poly.exterior : poly.holes[h];
            const uint32_t start = static_cast<uint32_t>(in.part.size()), n = static_cast<uint32_t>(ring.size() / 2);
            for (uint32_t i = 0; i < n; ++i, ++original) {
                const uint32_t j = (i + 1) % n;
                in.points.push_back(ring[2 * i]);
                in.points.push_back(ring[2 * i + 1]);
                in.part.push_back(p);
                for (size_t k = 0, count = splits ? splits->size(original) : 0; k < count; ++k) {
                    const double t = splits->at(original)[k];
                    in.points.push_back(ring[2 * i] + t * (ring[2 * j] - ring[2 * i]));
                    in.points.push_back(ring[2 * i + 1] + t * (ring[2 * j + 1] - ring[2 * i + 1]));
                    in.part.push_back(p);
                }
            }
            const uint32_t size = static_cast<uint32_t>(in.part.size()) - start;
            for (uint32_t i = 0; i < size; ++i) {
                in.ringStart.push_back(start);
                in.ringSize.push_back(size);
                in.segments.emplace_back(start + i, start + (i + 1) % size);
            }
        }
    }
    markTouchingParts(in, checked);
    if (withGrid) buildSegmentGrid(in);
    return in;
}

}  // namespace aggrelod::detail
