// SPDX-License-Identifier: MIT
// Writes a synthetic `.aglod` file (city boxes, tests/runtime_support/synthetic_hierarchy.h)
// for the C sample test and the runtime benchmarks:
//   aglod_make_synthetic OUT.aglod [objects=1000] [seed=1] [branching=4]
#include <aggrelod/runtime_build.h>

#include "synthetic_hierarchy.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: aglod_make_synthetic OUT.aglod [objects] [seed] [branching]\n");
        return 2;
    }
    const uint32_t objects = argc > 2 ? uint32_t(std::strtoul(argv[2], nullptr, 10)) : 1000u;
    const uint32_t seed = argc > 3 ? uint32_t(std::strtoul(argv[3], nullptr, 10)) : 1u;
    const uint32_t branching = argc > 4 ? uint32_t(std::strtoul(argv[4], nullptr, 10)) : 4u;
    if (objects == 0 || branching < 2) {
        std::fprintf(stderr, "aglod_make_synthetic: need objects >= 1 and branching >= 2\n");
        return 2;
    }
    const aggrelod::runtime::BuildArrays params =
        aggrelod::testing::makeSyntheticHierarchy(objects, seed, branching);
    std::vector<uint8_t> bytes;
    std::string error;
    if (!aggrelod::runtime::writeRuntimeFile(params, bytes, error)) {
        std::fprintf(stderr, "aglod_make_synthetic: %s\n", error.c_str());
        return 1;
    }
    std::ofstream out(argv[1], std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    if (!out) {
        std::fprintf(stderr, "aglod_make_synthetic: cannot write %s\n", argv[1]);
        return 1;
    }
    std::printf("%s: %zu nodes, %u objects, %zu bytes\n", argv[1], params.nodes.size(), objects, bytes.size());
    return 0;
}
