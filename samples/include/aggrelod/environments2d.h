// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod samples: seeded 2D test environments, analogues of the five scenes of the
// paper's evaluation (Fig. 4: Tree, Scatter, Room, Colony, Forest), and square grids for
// benchmarks. Polygons never overlap or touch; the same seed gives the same polygons
// (aggrelod::samples::Random). Units: plain planar units; the paper's deltas for each
// scene (0.8, 4, 20, 28, 40) fall between its smallest and largest neighbour distance.
#pragma once

#include <aggrelod/aggregate2d.h>

#include <cstdint>
#include <string>
#include <vector>

namespace aggrelod::samples {

enum class Environment2D { Tree, Scatter, Room, Colony, Forest };

/// All five, in the paper's order (by vertex count).
std::vector<Environment2D> allEnvironments2D();
/// "tree", "scatter", "room", "colony", "forest".
std::string environmentName(Environment2D env);

/// Features of one environment (names "tree 3" etc., ids 0..n-1).
std::vector<Feature2D> makeEnvironment2D(Environment2D env, uint32_t seed = 1);

/// count squares of side `size` on a square grid with `gap` between neighbours (row-major,
/// ceil(sqrt(count)) per row), each moved by up to +-jitter in x and y (seeded; jitter
/// < gap / 2 keeps them apart). Names "square i".
std::vector<Feature2D> makeSquareGrid(int count, double size = 1.0, double gap = 0.5, double jitter = 0,
                                      uint32_t seed = 1);

/// A random test set (seeded): 2-25 star-shaped polygons of 3-12 vertices, radius 1-8, in a
/// square of side 10-60, so they overlap and touch (30% of the vertices rounded to integers:
/// exact touches and shared edges); 20% have a square hole, 10% of the features a second,
/// overlapping part with the same hole. Names "random i", ids 0..n-1. Unlike the
/// environments, these polygons do overlap: they exercise the input checks and the winding.
std::vector<Feature2D> makeRandomOverlappingPolygons(uint32_t seed);

}  // namespace aggrelod::samples
