// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod samples: a seeded open world of any size for the huge-world benchmarks
// (samples/world.cpp): terrain, towns, forests, fields and roads, generated one block at a
// time and streamed to a GLB file without holding the world in memory.
//
// The world is a grid of blocks of kWorldBlockSize x kWorldBlockSize metres (z up, like every
// sample scene), ceil(sqrt(count / 24)) blocks per row (24 objects per block on average),
// filled row by row until the requested object count is reached: about a square.
// Each block is generated from its own random stream (the seed and the block's row and
// column), so a block's content does not depend on the others: the block at row r, column c is
// the same in every world that has it (the last block of a world may be cut short by the
// object count). Every block has
// - a terrain tile: a closed slab whose top follows a smooth height function (96 triangles),
//   0.05 m from its neighbours;
// - four road segments along its south edge (flat closed slabs, 11 m long, 60 triangles, each
//   0.05 m above the highest terrain under it);
// - by its kind (forest 40 %, town 30 %, field 30 %): trees (a trunk and canopy lathe, 196
//   triangles), houses (a hip-roofed lathe with four sides, 56 triangles) with barrels beside
//   them (a bulged lathe, 100 triangles), or rocks (a flattened sphere, 144 triangles) and hay
//   bales (a cylinder, 96 triangles).
// Objects never overlap or touch: every object stands 0.05 m above the highest terrain under
// its footprint, and footprints within a block are at least 0.3 m apart. All meshes are
// closed, welded and outward (samples.h). Determinism: as samples.h (std::mt19937 raw
// output, our own conversions); the same settings give the same bytes.
#pragma once

#include <aggrelod/aggregate3d.h>

#include <cstdint>
#include <functional>
#include <string>

namespace aggrelod::samples {

/// Edge length of one world block, metres.
constexpr double kWorldBlockSize = 48.0;

struct WorldSettings {
    uint32_t seed = 1;
    /// Objects in the world (terrain tiles and road segments included), 1 .. kMaxWorldObjects.
    uint64_t objectCount = 4000;
};

/// The largest world the generator makes (about 10 M triangles).
constexpr uint64_t kMaxWorldObjects = 65536;

struct WorldSummary {
    uint64_t objects = 0;
    uint64_t triangles = 0;
    uint64_t vertices = 0;
    uint64_t blocks = 0;
    double extent = 0;  ///< the longer side of the blocks' rectangle, metres
};

/// Generates the world block by block and calls `emit` once per object, in a fixed order
/// (objects numbered 0, 1, ... as their id; names "bRRRR_CCCC_kind_N" say the block's row and
/// column). Only one block is held at a time. Returns the summary. Throws
/// std::invalid_argument when objectCount is 0 or above kMaxWorldObjects.
WorldSummary generateWorld(const WorldSettings& settings, const std::function<void(InputObject&)>& emit);

/// Writes the world as a binary glTF 2.0 file: one node and mesh per object (float32
/// positions, uint32 indices, no normals), one material per colour, node extras {"id": N}.
/// The world is generated twice (sizes first, then the bytes) so that memory stays at one
/// block plus a few dozen bytes per object. False with a reason in `error` when the file
/// cannot be written. `summary` (optional) gets the counts.
bool writeWorldGlb(const WorldSettings& settings, const std::string& path, WorldSummary* summary, std::string& error);

}  // namespace aggrelod::samples
