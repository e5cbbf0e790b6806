// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: loading a glTF file for the readers (gltf_read.cpp): the limits on hostile
// structure, the confinement of external files to the input's folder, and tinygltf's parse.
// Internal to bake/; includes tiny_gltf.h (declarations only: Debian ships tinygltf's
// implementation compiled in libtinygltf.so, so no TINYGLTF_IMPLEMENTATION anywhere).
#pragma once

#include "scene_io.h"

#include <tiny_gltf.h>

#include <cstddef>
#include <string>
#include <vector>

namespace aggrelod::io::gltf {

using Severity = Diagnostic::Severity;

// Limits on hostile structure (documented in docs/command-line.md, "Limits").
/// JSON nesting deeper than this is refused: tinygltf's parser recurses once per level.
constexpr size_t kMaxJsonDepth = 100;
/// Nodes in one file.
constexpr size_t kMaxNodes = 1000000;
/// Mesh nodes reached by the traversal (instances of meshes).
constexpr size_t kMaxMeshInstances = 200000;
/// Triangles in world space after instancing.
constexpr size_t kMaxWorldTriangles = 50000000;
/// Largest magnitude of a world coordinate. Far below where squares and cubes of
/// coordinates (areas, volumes, ray distances) leave double or float range.
constexpr double kMaxCoordinate = 1e15;
/// Depth of the node hierarchy.
constexpr size_t kMaxNodeDepth = 1000;

/// Reads `path` (.gltf or .glb) into `model` after the checks of docs/command-line.md
/// ("Limits"): the whole file is read at once, a GLB's chunks are checked, the JSON is scanned
/// for depth and node count before tinygltf parses it, and external buffers are read only
/// from inside the file's folder (and only with allowExternalUris; their paths are appended
/// to externalFiles). tinygltf's warnings become notes in `diags`. False with a reason in
/// `error` (without the path).
bool loadModel(const std::string& path, tinygltf::Model& model, std::vector<Diagnostic>& diags,
               std::string& error, bool allowExternalUris = false, std::vector<std::string>* externalFiles = nullptr);

}  // namespace aggrelod::io::gltf
