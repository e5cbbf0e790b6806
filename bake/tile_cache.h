// SPDX-License-Identifier: AGPL-3.0-or-later
// The tiled bake's cache as a folder of files (docs/command-line.md, --tile-cache): one file
// per piece, named by its content key, written to a temporary name and renamed, so that
// processes sharing the folder (aggrelod-farm's workers) never see half an entry.
#pragma once

#include <aggrelod/tiled_bake_3d.h>

#include <string>

namespace aggrelod::io {

/// A TileCache over folder `dir` (created when missing). Entries are `dir/KEY.piece`.
TileCache folderTileCache(const std::string& dir);

/// The pieces of a tiled bake (TileTask::Kind::Plan's report) as one line of JSON:
/// {"tiled": bool, "graphs": bool, "cells": [N...], "parents": [[J, ROW, COLUMN]...]}.
std::string tilePlanJson(const TiledBakeReport& plan);

}  // namespace aggrelod::io
