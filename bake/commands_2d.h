// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: the 2D subcommands (aggregate2d, reproduce2d). Options are declared in
// main.cpp (the only CLI11 user); the work is done here.
#pragma once

#include <string>
#include <vector>

namespace aggrelod::cli {

struct Aggregate2DOptions {
    std::string input;                  ///< .wkt, .geojson or .json
    std::string output;                 ///< .geojson
    std::vector<double> deltas;         ///< explicit thresholds; empty = automatic
    int levels = 8;
    std::string function = "adaptive";  ///< adaptive | constant | hull
    std::string linksPath, svgPath, pngPath, statsPath;
    int threads = 0;                    ///< threads for sculpting levels (0: all cores)
    bool quiet = false;
};
/// Returns the process exit code (0 ok, 1 usage, 2 file problem, 3 aggregation failed).
int runAggregate2D(Aggregate2DOptions options);

struct Reproduce2DOptions {
    std::string outDir;
    unsigned seed = 1;
    bool quiet = false;
};
int runReproduce2D(const Reproduce2DOptions& options);

}  // namespace aggrelod::cli
