// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod_make_sample: writes one of the generated sample scenes as a GLB file.
//
//   aggrelod_make_sample NAME -o FILE.glb [--seed N] [options]
//
// NAME: two_cubes [--gap G] | slabs | spheres15 | chess [--board] | forest | village | random [--objects N]
// [--triangles T] | world [--objects N] (samples/include/aggrelod/world.h, streamed to the file).
// Exit status: 0 written, 1 could not write, 2 bad command line.
#include <aggrelod/samples.h>
#include <aggrelod/world.h>

#include "scene_io.h"

#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

namespace {

const char* const kUsage =
    "usage: aggrelod_make_sample NAME -o FILE.glb [--seed N] [options]\n"
    "  NAME       two_cubes | slabs | spheres15 | chess | forest | village | random | world\n"
    "  --seed N   random seed (spheres15, chess, forest, village, random, world; default 1)\n"
    "  --gap G    two_cubes: gap between the cubes (default 0.5)\n"
    "  --board    chess: also write the board, 0.05 below the pieces (default: pieces only)\n"
    "  --objects N    random: object count (default 1000); world: 1-65536 (default 4000)\n"
    "  --triangles T  random: approximate total triangle count (default 150000)\n";

int usage(const std::string& message) {
    if (!message.empty()) std::fprintf(stderr, "aggrelod_make_sample: %s\n", message.c_str());
    std::fputs(kUsage, stderr);
    return 2;
}

bool parseNumber(const std::string& text, double& value) {
    char* end = nullptr;
    value = std::strtod(text.c_str(), &end);
    return !text.empty() && end && *end == '\0';
}

bool parseInteger(const std::string& text, long long min, long long max, long long& value) {
    char* end = nullptr;
    value = std::strtoll(text.c_str(), &end, 10);
    return !text.empty() && end && *end == '\0' && value >= min && value <= max;
}

}  // namespace

int main(int argc, char** argv) {
    std::string name, output;
    long long seed = 1, objects = -1, triangles = 150000;
    double gap = 0.5;
    bool board = false;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&](std::string& out) {
            if (i + 1 >= argc) return false;
            out = argv[++i];
            return true;
        };
        std::string text;
        if (arg == "-h" || arg == "--help") {
            std::fputs(kUsage, stdout);
            return 0;
        } else if (arg == "-o" || arg == "--output") {
            if (!value(output)) return usage("-o needs a file name");
        } else if (arg == "--seed") {
            if (!value(text) || !parseInteger(text, 0, 4294967295LL, seed))
                return usage("--seed needs an integer in [0, 4294967295]");
        } else if (arg == "--gap") {
            if (!value(text) || !parseNumber(text, gap) || !(gap > 0))
                return usage("--gap needs a number > 0");
        } else if (arg == "--objects") {
            if (!value(text) || !parseInteger(text, 1, 10000000, objects))
                return usage("--objects needs an integer >= 1");
        } else if (arg == "--triangles") {
            if (!value(text) || !parseInteger(text, 1, 1000000000, triangles))
                return usage("--triangles needs an integer >= 1");
        } else if (arg == "--board") {
            board = true;
        } else if (!arg.empty() && arg[0] == '-') {
            return usage("unknown option " + arg);
        } else if (name.empty()) {
            name = arg;
        } else {
            return usage("more than one scene name");
        }
    }
    if (name.empty()) return usage("no scene name");
    if (output.empty()) return usage("no output file (-o FILE.glb)");

    if (name == "world") {
        aggrelod::samples::WorldSettings world;
        world.seed = uint32_t(seed);
        world.objectCount = objects < 0 ? 4000 : uint64_t(objects);
        if (world.objectCount > aggrelod::samples::kMaxWorldObjects)
            return usage("world: --objects must be at most " + std::to_string(aggrelod::samples::kMaxWorldObjects));
        aggrelod::samples::WorldSummary summary;
        std::string error;
        if (!aggrelod::samples::writeWorldGlb(world, output, &summary, error)) {
            std::fprintf(stderr, "aggrelod_make_sample: cannot write %s: %s\n", output.c_str(), error.c_str());
            return 1;
        }
        std::printf("world: %llu objects, %llu triangles, %llu blocks, %.0f m across -> %s\n",
                    static_cast<unsigned long long>(summary.objects), static_cast<unsigned long long>(summary.triangles),
                    static_cast<unsigned long long>(summary.blocks), summary.extent, output.c_str());
        return 0;
    }
    if (objects < 0) objects = 1000;
    std::vector<aggrelod::InputObject> scene;
    try {
        namespace s = aggrelod::samples;
        if (name == "two_cubes") scene = s::makeTwoCubes(gap);
        else if (name == "slabs") scene = s::makeOffsetSlabs();
        else if (name == "spheres15") scene = s::makeSpheres15(uint32_t(seed));
        else if (name == "chess") scene = s::makeChessBoard(uint32_t(seed), board);
        else if (name == "forest") scene = s::makeForest(uint32_t(seed));
        else if (name == "village") scene = s::makeVillage(uint32_t(seed));
        else if (name == "random") scene = s::makeRandomScene(int(objects), int(triangles), uint32_t(seed));
        else return usage("unknown scene '" + name + "'");
    } catch (const std::exception& e) {
        std::fprintf(stderr, "aggrelod_make_sample: %s\n", e.what());
        return 1;
    }
    size_t triangleCount = 0;
    for (const auto& o : scene) triangleCount += o.indices.size() / 3;

    std::string error;
    if (!aggrelod::io::writeObjectsGlb(scene, output, error)) {
        std::fprintf(stderr, "aggrelod_make_sample: cannot write %s: %s\n", output.c_str(), error.c_str());
        return 1;
    }
    std::printf("%s: %zu objects, %zu triangles -> %s\n", name.c_str(), scene.size(), triangleCount,
                output.c_str());
    return 0;
}
