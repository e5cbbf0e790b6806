// SPDX-License-Identifier: MIT
// Package consumer, C++ API: writes a two-box scene with aggrelod::runtime::writeRuntimeFile,
// maps it with RuntimeFile::openFile and checks what a Selector draws from far and near.
//   write_and_select OUT.aglod
// Exit status 0 only when everything matches.
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>
#include <aggrelod/selection.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

using namespace aggrelod::runtime;

namespace {

int failures = 0;

void check(bool ok, const char* what) {
    std::printf("%s: %s\n", ok ? "ok  " : "FAIL", what);
    if (!ok) ++failures;
}

// A closed box mesh, 4 vertices per face (own normal per face), outward winding.
void appendBox(BuildArrays& p, NodeRecord& node, const float lo[3], const float hi[3]) {
    static const int corners[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                      {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    static const float normals[6][3] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
    node.firstVertex = static_cast<uint32_t>(p.positions.size() / 3);
    node.vertexCount = 24;
    node.firstIndex = static_cast<uint32_t>(p.indices.size());
    node.indexCount = 36;
    for (int f = 0; f < 6; ++f) {
        const uint32_t base = static_cast<uint32_t>(p.positions.size() / 3) - node.firstVertex;
        for (int i = 0; i < 4; ++i) {
            const int v = corners[f][i];
            p.positions.push_back((v & 1) ? hi[0] : lo[0]);
            p.positions.push_back((v & 2) ? hi[1] : lo[1]);
            p.positions.push_back((v & 4) ? hi[2] : lo[2]);
            p.normals.insert(p.normals.end(), normals[f], normals[f] + 3);
            const float linear[4] = {0.8f, 0.3f, 0.1f, 1.0f};
            uint8_t rgba[4];
            encodeColorSrgb8(linear, rgba);
            p.colors.insert(p.colors.end(), rgba, rgba + 4);
        }
        const uint32_t quad[6] = {base, base + 1, base + 2, base, base + 2, base + 3};
        p.indices.insert(p.indices.end(), quad, quad + 6);
    }
    for (int k = 0; k < 3; ++k) {
        node.boundsMin[k] = lo[k];
        node.boundsMax[k] = hi[k];
        node.sphereCenter[k] = 0.5f * (lo[k] + hi[k]);
    }
    const float dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    node.sphereRadius = 0.5f * std::sqrt(dx * dx + dy * dy + dz * dz) * 1.001f;
}

// Two unit boxes 3 apart on x (objects "left" and "right") under one aggregate whose proxy is
// their common bounding box.
BuildArrays twoBoxScene() {
    BuildArrays p;
    p.objectNames = {"left", "right"};
    const float lo[2][3] = {{0, 0, 0}, {3, 0, 0}}, hi[2][3] = {{1, 1, 1}, {4, 1, 1}};
    for (uint32_t o = 0; o < 2; ++o) {
        NodeRecord leaf;
        leaf.parent = 2;
        leaf.level = kLeafLevel;
        leaf.firstSource = static_cast<uint32_t>(p.sourceObjects.size());
        leaf.sourceCount = 1;
        p.sourceObjects.push_back(o);
        appendBox(p, leaf, lo[o], hi[o]);
        p.nodes.push_back(leaf);
    }
    NodeRecord root;
    root.level = 0;
    root.delta = 1.0f;
    root.firstChild = 0;
    root.childCount = 2;
    p.childIndices = {0, 1};
    root.firstSource = static_cast<uint32_t>(p.sourceObjects.size());
    root.sourceCount = 2;
    p.sourceObjects.push_back(0);
    p.sourceObjects.push_back(1);
    const float rlo[3] = {0, 0, 0}, rhi[3] = {4, 1, 1};
    appendBox(p, root, rlo, rhi);
    root.sphereRadius = 2.5f;  // encloses the children's spheres (1.5 + 0.87 from its centre)
    root.geometricError = 1.5f;  // the gap between the boxes is filled by the proxy
    p.nodes.push_back(root);
    p.settingsHash = 42;
    p.toolVersion = "consumer";
    return p;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: write_and_select OUT.aglod\n");
        return 2;
    }
    std::vector<uint8_t> bytes;
    std::string error;
    const bool written = writeRuntimeFile(twoBoxScene(), bytes, error);
    check(written, ("writeRuntimeFile " + error).c_str());
    if (!written) return 1;
    {
        std::ofstream out(argv[1], std::ios::binary);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        check(static_cast<bool>(out), "file written");
    }

    RuntimeFile file;
    std::string message;
    const FileStatus status = RuntimeFile::openFile(argv[1], file, message);
    check(status == FileStatus::Ok, ("openFile " + message).c_str());
    if (status != FileStatus::Ok) return 1;
    check(file.nodeCount() == 3 && file.objectCount() == 2, "3 nodes over 2 objects");
    check(file.objectName(1) == "right", "object 1 is \"right\"");

    Selector selector(file);
    SelectionSettings settings;  // 1 px, hysteresis 0.75
    Camera far;
    far.position[0] = 2.0f;
    far.position[1] = 0.5f;
    far.position[2] = 1e5f;
    selector.select(far, settings);
    check(selector.proxyNodes().size == 1 && selector.proxyNodes()[0] == 2 && selector.originalObjects().size == 0,
          "far camera draws the proxy of the root");
    Camera near = far;
    near.position[2] = 5.0f;
    selector.select(near, settings);
    check(selector.proxyNodes().size == 0 && selector.originalObjects().size == 2,
          "near camera draws both original objects");
    std::printf("write_and_select: %s\n", failures == 0 ? "PASSED" : "FAILED");
    return failures == 0 ? 0 : 1;
}
