// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the hierarchy nodes as a 3D Tiles 1.1 tileset (docs/design.md §4), so that
// CesiumJS or 3DTilesRendererJS can stream the hierarchy: OUTDIR/tiles/tileset.json and one
// GLB per tile.
//
// Mapping:
// - every hierarchy node is one tile: aggregates carry their simplified proxy, leaves the
//   original object; geometricError = the node's stored error (world units: the error made
//   when this tile is drawn and its children are not; 0 for leaves); refine REPLACE.
// - one root tile: the hierarchy's root when there is one, otherwise a tile without content
//   whose children are the roots. Objects the bake left out (no geometry) get no tile.
// - the tileset's geometricError (the error made when nothing is drawn) is the diagonal of
//   the scene's box, or the root's error if larger.
//
// Axes: tile contents are glTF, y-up, in the input scene's world coordinates (units as the
// input). 3D Tiles is z-up and applies the standard glTF y-up to z-up rotation to every glTF
// content (+90 degrees about x: glTF (x, y, z) is tileset (x, -z, y)). So the bounding boxes
// in tileset.json are the nodes' axis-aligned boxes taken through that rotation, and no tile
// has a transform. A y-up viewer (three.js) turns the tileset by -90 degrees about x to see
// the scene in its original coordinates (samples/web does).
//
// Boxes are the nodes' boxes grown by 1e-6 of the scene diagonal on every side (the same for
// all, so nesting is kept), so that a flat object never gives a degenerate box.
// Determinism: the same nodes give byte-identical files.
#pragma once

#include <aggrelod/aggregate3d.h>
#include <aggrelod/hierarchy_nodes.h>

#include <cstddef>
#include <string>
#include <vector>

namespace aggrelod::io {

struct TilesetSummary {
    size_t tileCount = 0;     ///< tiles in tileset.json (with a content-less root, if any)
    size_t contentCount = 0;  ///< GLB files written
    double geometricError = 0;  ///< the tileset's, world units
};

/// Text of tileset.json for `nodes` (contents named node<i>.glb, i = node index).
/// Returns false with a message when the nodes do not belong to `objects`.
bool makeTilesetJson(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, std::string& json,
                     TilesetSummary& summary, std::string& error);

/// Writes `dir`/tileset.json and `dir`/node<i>.glb (one per tile with geometry; `dir` must
/// exist). Returns false with a message naming the file on any problem.
bool writeTileset(const HierarchyNodes& nodes, const std::vector<InputObject>& objects, const std::string& dir,
                  TilesetSummary& summary, std::string& error);

}  // namespace aggrelod::io
