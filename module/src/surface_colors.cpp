// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: proxy face colours from the nearest original surface (surface_colors.h).
// An engine-facing addition, not a section of the paper.
#include "surface_colors.h"

#include <algorithm>
#include <cmath>

namespace aggrelod::detail {

bool hasTriangleColors(const InputObject& o) {
    return !o.triangleColors.empty() && o.triangleColors.size() == 4 * (o.indices.size() / 3);
}

SurfaceColorSource::SurfaceColorSource(const std::vector<const InputObject*>& originals) {
    coloured_ = std::any_of(originals.begin(), originals.end(), [](const InputObject* o) { return hasTriangleColors(*o); });
    if (!coloured_) return;
    // One triangle soup of every usable original, with its colours in the same order.
    std::vector<double> soupPositions;
    std::vector<uint32_t> soupIndices;
    for (const InputObject* o : originals) {
        const bool finite = std::all_of(o->positions.begin(), o->positions.end(), [](double x) { return std::isfinite(x); });
        const size_t vertexCount = o->positions.size() / 3;
        if (!finite || o->positions.size() % 3 || o->indices.size() % 3) continue;
        if (std::any_of(o->indices.begin(), o->indices.end(), [&](uint32_t i) { return i >= vertexCount; })) continue;
        const uint32_t base = static_cast<uint32_t>(soupPositions.size() / 3);
        soupPositions.insert(soupPositions.end(), o->positions.begin(), o->positions.end());
        for (uint32_t i : o->indices) soupIndices.push_back(base + i);
        if (hasTriangleColors(*o))
            colors_.insert(colors_.end(), o->triangleColors.begin(), o->triangleColors.end());
        else
            colors_.resize(colors_.size() + 4 * (o->indices.size() / 3), 1.0f);
    }
    if (soupIndices.empty()) return;
    // One colour for the whole surface (an object of one material, or a group of such objects
    // of one colour): every face takes it, as the vote would give; no search needed.
    uniform_ = true;
    for (size_t i = 4; i < colors_.size() && uniform_; i += 4) uniform_ = std::equal(&colors_[i], &colors_[i] + 4, &colors_[0]);
    if (!uniform_) bvh_.build(soupPositions.data(), soupPositions.size() / 3, soupIndices.data(), soupIndices.size() / 3);
}

template <typename Real>
void SurfaceColorSource::colorsOf(const std::vector<Real>& positions, const std::vector<uint32_t>& indices,
                                  std::vector<float>& faceColors) const {
    faceColors.clear();
    if (!coloured_) return;
    const size_t faceCount = indices.size() / 3;
    faceColors.assign(4 * faceCount, 1.0f);
    if (colors_.empty()) return;
    if (uniform_) {
        for (size_t f = 0; f < faceCount; ++f) {
            bool finite = true;  // a face with a non-finite corner stays white, as below
            for (int c = 0; c < 3; ++c)
                for (int k = 0; k < 3; ++k) finite = finite && std::isfinite(double(positions[3 * size_t(indices[3 * f + c]) + k]));
            if (finite) std::copy_n(&colors_[0], 4, &faceColors[4 * f]);
        }
        return;
    }
    // Seven points spread over the face (its centroid first); the colour most of them are
    // nearest to wins, so a large coarse face takes the colour of most of the surface it
    // stands for rather than of whatever lies under its centroid.
    constexpr double kSamples[7][3] = {{1.0 / 3, 1.0 / 3, 1.0 / 3},   {2.0 / 3, 1.0 / 6, 1.0 / 6},
                                       {1.0 / 6, 2.0 / 3, 1.0 / 6},   {1.0 / 6, 1.0 / 6, 2.0 / 3},
                                       {1.0 / 6, 5.0 / 12, 5.0 / 12}, {5.0 / 12, 1.0 / 6, 5.0 / 12},
                                       {5.0 / 12, 5.0 / 12, 1.0 / 6}};
    for (size_t f = 0; f < faceCount; ++f) {
        uint32_t nearestTriangle[7];
        int found = 0;
        for (const auto& w : kSamples) {
            double p[3] = {0, 0, 0};
            for (int c = 0; c < 3; ++c)
                for (int k = 0; k < 3; ++k) p[k] += w[c] * double(positions[3 * size_t(indices[3 * f + c]) + k]);
            const ClosestPoint nearest = closestPoint(bvh_, p);
            if (nearest.triangle != ~0u) nearestTriangle[found++] = nearest.triangle;
        }
        if (found == 0) continue;  // non-finite face: stays white
        auto colorOf = [&](int i) { return &colors_[4 * size_t(nearestTriangle[i])]; };
        int best = 0, bestVotes = 0;
        for (int i = 0; i < found; ++i) {
            int votes = 0;
            for (int j = 0; j < found; ++j) votes += std::equal(colorOf(i), colorOf(i) + 4, colorOf(j));
            if (votes > bestVotes) best = i, bestVotes = votes;
        }
        std::copy_n(colorOf(best), 4, &faceColors[4 * f]);
    }
}

template void SurfaceColorSource::colorsOf(const std::vector<double>&, const std::vector<uint32_t>&, std::vector<float>&) const;
template void SurfaceColorSource::colorsOf(const std::vector<float>&, const std::vector<uint32_t>&, std::vector<float>&) const;

void nearestSurfaceColors(const std::vector<double>& positions, const std::vector<uint32_t>& indices,
                          const std::vector<const InputObject*>& originals, std::vector<float>& faceColors) {
    SurfaceColorSource(originals).colorsOf(positions, indices, faceColors);
}

void nearestSurfaceColors(const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                          const std::vector<const InputObject*>& originals, std::vector<float>& faceColors) {
    SurfaceColorSource(originals).colorsOf(positions, indices, faceColors);
}

}  // namespace aggrelod::detail
