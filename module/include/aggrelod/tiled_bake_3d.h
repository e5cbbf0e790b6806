// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod module: the tiled 3D bake for worlds too large for one triangulation
// (docs/design.md §2.8; grid-cell HLOD as in Unreal's World Partition).
//
// The world is cut into square cells of side S along the scene's two longest axes. Each
// cell is baked alone (buildHierarchy3D on its objects) for the levels with delta <= S / 8;
// levels above are built by baking alpha wraps of the cells' coarsest aggregates as objects
// in the parent cells of a quadtree (parent cell of quadtree level j: 2^j x 2^j cells; wrap
// alpha delta / 8, offset delta / 64, so distances there are between wraps). The result is
// one Hierarchy3D, as buildHierarchy3D gives, for buildHierarchyNodes and every writer.
//
// Cell rule: objects whose boxes come within S / 8 of each other (chains included) form a
// cluster, and a cluster goes whole to the cell holding the box centre of its first object,
// so no neighbour closer than a cell level's delta is cut off by a border. A cluster wider
// than S along either axis is split instead: each of its objects goes to the cell of its own
// box centre (TiledBakeReport counts them; groups there may differ from an untiled bake).
// Support surfaces are found once on the whole world (Settings3D::support) and passed through.
//
// Units: world units. Determinism: cells and parent cells are baked one after another in a
// fixed order (row-major cell index), so the result depends on the objects and settings only,
// bit-identical for every thread count.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/tile_cache.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod {

/// What the tiled bake did (also said in a Note diagnostic).
struct TiledBakeReport {
    double tileSize = 0;            ///< S, world units (the automatic choice when 0 was asked)
    double cellTopDelta = 0;        ///< S / 8: cells bake the levels with delta up to this
    size_t columns = 0, rows = 0;   ///< cells along the scene's longest and second axis
    size_t cellCount = 0;           ///< cells baked (those holding objects)
    size_t largestCellObjects = 0;  ///< objects in the fullest cell
    size_t cellTriangleCount = 0;   ///< triangles of the objects in cells (those aggregated)
    int quadtreeDepth = 0;          ///< parent levels of cells above the cells
    size_t parentBakeCount = 0;     ///< parent cells baked (those with two inputs or more)
    size_t clusterCount = 0;
    size_t splitClusterCount = 0;   ///< clusters wider than S, split by object centre
    size_t splitClusterObjects = 0; ///< objects in them
    bool tiled = false;             ///< false: the world fits one cell and was baked untiled
    bool automaticDeltas = false;   ///< thresholds by the automatic rule (a graph pass per cell)
    /// Pieces baked in this run and pieces read from the cache (TiledBakeOptions::cache).
    size_t graphsBaked = 0, graphsLoaded = 0, cellsBaked = 0, cellsLoaded = 0, parentsBaked = 0, parentsLoaded = 0;
    /// TileTask::Kind::Plan only: the cells holding objects (row-major index, ascending), and
    /// per quadtree level j (index j; 0 unused) its parent cells (row, column) that may be baked.
    std::vector<uint32_t> cells;
    std::vector<std::vector<std::pair<uint32_t, uint32_t>>> parents;
};

/// One piece of a tiled bake, so that pieces can run in separate processes (aggrelod-farm).
/// A piece reads what it depends on from the cache and fails, naming it, when it is missing:
/// graphs (automatic thresholds only) before cells, cells before parents, quadtree level j
/// before j + 1. Everything bakes what the cache lacks and returns the whole hierarchy.
struct TileTask {
    enum class Kind {
        Everything,  ///< the whole bake (default)
        Plan,        ///< nothing baked: TiledBakeReport::cells and ::parents list the pieces
        Graph,       ///< the neighbourhood graph of cell `cell` (automatic thresholds)
        Cell,        ///< the levels of cell `cell`
        Parent,      ///< the levels of parent cell (row, column) of quadtree level `level`
        Assemble     ///< the whole hierarchy from the cache, baking nothing (fails naming a missing piece)
    } kind = Kind::Everything;
    uint32_t cell = 0;
    int level = 0;
    uint32_t row = 0, column = 0;
};

/// What a tiled bake works out from the whole world before any piece: support surfaces, the
/// grid, the clusters and each object's cell. Opaque; see TiledBakeOptions::layout.
struct TiledLayout;

/// An empty layout for TiledBakeOptions::layout.
std::shared_ptr<TiledLayout> newTiledLayout();

struct TiledBakeOptions {
    double tileSize = 0;              ///< S (world units), or 0 for the automatic choice
    const TileCache* cache = nullptr; ///< optional; not used with Settings3D::customFunction
    TileTask task;                    ///< a piece only (the result then holds no levels)
    /// Optional, for several pieces of one bake in one process (a list of --tile-task pieces):
    /// the first run keeps the world's layout here and later runs reuse it instead of working it
    /// out again from every object (about a quarter of a second per piece at 65,536 objects). A
    /// run on other objects (another address or count), settings or tile size works it out anew
    /// and keeps that; objects changed in place need a fresh layout (newTiledLayout).
    std::shared_ptr<TiledLayout> layout;
    /// TileTask::Kind::Assemble only: leave every aggregate's mesh in the cache
    /// (Aggregate::meshInCache), so that the whole hierarchy is held without its meshes. Such
    /// a hierarchy goes only where that cache is given too: buildProxyShare and
    /// buildHierarchyNodes (ProxySettings::cache) read back the meshes they need, as does
    /// readAggregateMeshes. A world that fits one tile has no pieces: refused with an Error.
    bool leanMeshes = false;
};

/// Objects per cell the automatic tile size aims at (tileSize == 0).
constexpr size_t kAutomaticTileObjects = 2000;

/// Bakes `objects` tiled. tileSize: S in world units (> 0), or 0 for the automatic choice:
/// untiled up to 2 x kAutomaticTileObjects aggregated objects, else the S that puts about
/// kAutomaticTileObjects objects in a cell of the world's footprint. A world that fits one
/// cell is baked by buildHierarchy3D (same result). Explicit settings.deltas need at least one
/// delta <= S / 8 (cells must have a level). Automatic deltas: a first pass builds each cell's
/// neighbourhood graph; the automatic rule (Settings3D::automaticLevelCount) runs on all their
/// merges up to S / 8, and every quadtree level adds one level at delta = S / 8 * 2^j.
/// Returns false with an Error diagnostic as buildHierarchy3D does. Never throws for bad input.
bool buildTiledHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings, double tileSize,
                           Hierarchy3D& out, TiledBakeReport* report = nullptr);

/// The same with a cache and, optionally, one piece only (TileTask).
bool buildTiledHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings,
                           const TiledBakeOptions& options, Hierarchy3D& out, TiledBakeReport* report = nullptr);

/// Reads back from `cache` the meshes a lean assembly left there (TiledBakeOptions::leanMeshes):
/// out[j] is *lean[j] with its positions, indices and faceColors (out resized to lean.size()).
/// Each piece is read once per level asked; runs on up to `threads` threads (0: all cores).
/// False with `error` naming a piece that is missing or no longer holds a mesh with the hash kept.
bool readAggregateMeshes(const TileCache& cache, const std::vector<const Aggregate*>& lean, std::vector<Aggregate>& out,
                         int threads, std::string& error);

}  // namespace aggrelod
