// SPDX-License-Identifier: MIT
// Checks one headless run of samples/viewer (aglod_viewer) against the benchmark's numbers:
//
//   check_viewer_run VIEWER_OUT_DIR BENCH.csv
//
// VIEWER_OUT_DIR holds what aglod_viewer --out wrote (frames.csv, screenshots.csv, near.png,
// far.png, with --compare-originals also the missing/extra shares); BENCH.csv is the output of
// `bench_lod_budget --cut-for scene.aglod --cameras VIEWER_OUT_DIR/frames.csv`, the cut the
// benchmark's rule selects for each of the viewer's cameras. It checks
//  - per frame: the viewer's draw calls, triangles, cut nodes, proxies, originals and culled
//    nodes equal the benchmark's; the GPU counted the triangles it was given
//    (GL_PRIMITIVES_GENERATED); the nodes resident on the GPU are the cut, every cut node was
//    resident, and every upload / release came from the cut's entered / left changes;
//  - the path: the near frame draws originals, the far frame proxies, fewer originals and
//    fewer triangles, and frustum culling left something out on the way;
//  - the screenshots, decoded from the PNG files: near shows the scene on >= 5 % of the
//    picture, far on >= 2 % of the scene's projected bounding circle (and >= 50 pixels); the
//    pixels are lit (a spread of brightness) and coloured (saturated); with the originals drawn
//    for comparison, the cut leaves at most 1 % (near) / 5 % (far) of their pixels uncovered,
//    and the cut lit by the file's normals looks like the cut lit by its triangles' own normals
//    (mean brightness difference <= 7 levels near, <= 12 far: wrong normals give 12 to 40).
// Prints every check; exit status 0 when all pass, 1 otherwise.
#include <stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Row = std::map<std::string, std::string>;

std::vector<std::string> split(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream ss(s);
    for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
    return out;
}

bool readCsv(const std::string& path, std::vector<Row>& rows) {
    std::ifstream in(path);
    std::string line;
    if (!in || !std::getline(in, line)) return false;
    const std::vector<std::string> header = split(line);
    while (std::getline(in, line)) {
        if (line.empty()) continue;
        const std::vector<std::string> cells = split(line);
        if (cells.size() != header.size()) return false;
        Row r;
        for (size_t i = 0; i < header.size(); ++i) r[header[i]] = cells[i];
        rows.push_back(r);
    }
    return true;
}

int failures = 0, passes = 0;

void check(bool ok, const std::string& what) {
    std::printf("%s  %s\n", ok ? "PASS" : "FAIL", what.c_str());
    (ok ? passes : failures)++;
}

std::string fmt(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char* f, ...) {
    char buffer[512];
    va_list args;
    va_start(args, f);
    std::vsnprintf(buffer, sizeof buffer, f, args);
    va_end(args);
    return buffer;
}

long long num(const Row& r, const char* key) {
    const auto it = r.find(key);
    return it == r.end() ? -1 : std::atoll(it->second.c_str());
}
double real(const Row& r, const char* key) {
    const auto it = r.find(key);
    return it == r.end() ? NAN : std::atof(it->second.c_str());
}

/// The screenshot checks on one PNG.
void checkScreenshot(const std::string& dir, const Row& shot, bool far) {
    const std::string name = shot.at("file");
    int w = 0, h = 0, channels = 0;
    unsigned char* img = stbi_load((dir + "/" + name).c_str(), &w, &h, &channels, 3);
    check(img != nullptr, fmt("%s decodes as PNG", name.c_str()));
    if (!img) return;
    check(w == num(shot, "width") && h == num(shot, "height"), fmt("%s is %dx%d as rendered", name.c_str(), w, h));
    const int bg[3] = {int(num(shot, "background_r")), int(num(shot, "background_g")), int(num(shot, "background_b"))};
    const double cx = real(shot, "sphere_x_px"), cy = real(shot, "sphere_y_px"), radius = real(shot, "sphere_radius_px");
    size_t covered = 0, inDisc = 0, discArea = 0;
    std::vector<int> luma;
    std::set<int> colours;
    double saturation = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const unsigned char* p = img + 3 * (size_t(y) * size_t(w) + size_t(x));
            const bool inside = std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= radius;
            discArea += inside;
            if (p[0] == bg[0] && p[1] == bg[1] && p[2] == bg[2]) continue;
            ++covered;
            inDisc += inside;
            luma.push_back((299 * p[0] + 587 * p[1] + 114 * p[2]) / 1000);
            colours.insert((p[0] << 16) | (p[1] << 8) | p[2]);
            saturation += std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]});
        }
    stbi_image_free(img);
    const double share = double(covered) / (double(w) * double(h));
    if (!far) {
        check(share >= 0.05, fmt("%s: the scene covers %.2f %% of the picture (>= 5 %%)", name.c_str(), 100 * share));
    } else {
        const double discShare = discArea ? double(inDisc) / double(discArea) : 0;
        check(inDisc >= 50 && discShare >= 0.02,
              fmt("%s: the scene covers %zu pixels, %.1f %% of its bounding circle of radius %.1f px (>= 50 px, >= 2 %%)",
                  name.c_str(), inDisc, 100 * discShare, radius));
    }
    if (luma.empty()) return;
    std::sort(luma.begin(), luma.end());
    const int lo = luma[luma.size() / 20], hi = luma[luma.size() - 1 - luma.size() / 20];
    check(hi - lo >= 20 && colours.size() >= 16,
          fmt("%s: lit (brightness 5th-95th percentile %d..%d, >= 20 apart; %zu distinct colours, >= 16)",
              name.c_str(), lo, hi, colours.size()));
    const double meanSaturation = saturation / double(luma.size());
    check(meanSaturation >= 20, fmt("%s: coloured (mean max-min channel spread %.1f, >= 20)", name.c_str(), meanSaturation));
    const double missing = real(shot, "missing_share");
    if (missing >= 0) {
        const double limit = far ? 0.05 : 0.01;
        check(missing <= limit, fmt("%s: the cut leaves %.3f %% of the originals' pixels uncovered (<= %.0f %%); %.2f %% of "
                                    "its pixels lie outside them",
                                    name.c_str(), 100 * missing, 100 * limit, 100 * real(shot, "extra_share")));
    }
    const double shading = real(shot, "shading_difference");
    if (shading >= 0) {
        // Lit by the file's normals against lit by the triangles' own: measured 3.5 (near) and
        // 7.9 (far) levels with the normals right; normals read from the wrong place or
        // flipped gave 12 to 40.
        const double limit = far ? 12 : 7;
        check(shading <= limit, fmt("%s: normals: smooth and faceted shading differ by %.2f brightness levels (<= %.0f)",
                                    name.c_str(), shading, limit));
    }
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: check_viewer_run VIEWER_OUT_DIR BENCH.csv\n");
        return 2;
    }
    const std::string dir = argv[1];
    std::vector<Row> frames, bench, shots;
    check(readCsv(dir + "/frames.csv", frames) && !frames.empty(), "the viewer wrote frames.csv");
    check(readCsv(argv[2], bench) && !bench.empty(), "bench_lod_budget --cut-for wrote its cuts");
    check(readCsv(dir + "/screenshots.csv", shots) && shots.size() == 2, "the viewer wrote two screenshots (near, far)");
    if (failures) return 1;
    check(frames.size() == bench.size() && frames.size() >= 2,
          fmt("%zu viewer frames, %zu benchmark cameras (equal, >= 2)", frames.size(), bench.size()));

    // Per frame, against the benchmark and the viewer's own GPU and streaming bookkeeping.
    const char* same[] = {"cut_nodes", "proxies", "originals", "culled", "draw_calls", "triangles"};
    size_t equalFrames = 0, gpuFrames = 0, residentFrames = 0, streamFrames = 0, culledFrames = 0;
    long long draws = 0, triangles = 0;
    for (size_t i = 0; i < std::min(frames.size(), bench.size()); ++i) {
        const Row &v = frames[i], &b = bench[i];
        bool equal = v.at("frame") == b.at("frame");
        for (const char* key : same) equal = equal && num(v, key) == num(b, key);
        if (!equal) {
            std::printf("  frame %s: viewer", v.at("frame").c_str());
            for (const char* key : same) std::printf(" %s %lld", key, num(v, key));
            std::printf("\n  frame %s: bench ", b.at("frame").c_str());
            for (const char* key : same) std::printf(" %s %lld", key, num(b, key));
            std::printf("\n");
        }
        equalFrames += equal;
        gpuFrames += num(v, "gpu_primitives") == num(v, "triangles");
        residentFrames += num(v, "resident") == num(v, "cut_nodes") && num(v, "missing") == 0;
        streamFrames += num(v, "uploads") == num(v, "entered") && num(v, "frees") == num(v, "left");
        culledFrames += num(v, "culled") > 0;
        draws += num(v, "draw_calls");
        triangles += num(v, "triangles");
    }
    const size_t n = frames.size();
    check(equalFrames == n, fmt("draw calls, triangles, cut, proxies, originals and culled nodes equal the benchmark's "
                                "in %zu of %zu frames (%lld draw calls, %lld triangles in all)",
                                equalFrames, n, draws, triangles));
    check(gpuFrames == n, fmt("the GPU counted the triangles submitted in %zu of %zu frames", gpuFrames, n));
    check(residentFrames == n, fmt("resident buffers = the cut, none missing, in %zu of %zu frames", residentFrames, n));
    check(streamFrames == n, fmt("uploads = entered and releases = left in %zu of %zu frames", streamFrames, n));
    const Row &first = frames.front(), &last = frames.back();
    check(num(first, "originals") > 0, fmt("near frame draws %lld originals (> 0)", num(first, "originals")));
    check(num(last, "originals") < num(first, "originals") && num(last, "proxies") > 0,
          fmt("far frame draws proxies and fewer originals than near (%lld proxies, %lld originals)", num(last, "proxies"),
              num(last, "originals")));
    check(num(last, "triangles") < num(first, "triangles"),
          fmt("far frame draws fewer triangles than near (%lld < %lld)", num(last, "triangles"), num(first, "triangles")));
    check(culledFrames > 0, fmt("frustum culling left nodes out in %zu frames (> 0)", culledFrames));

    for (const Row& shot : shots) checkScreenshot(dir, shot, shot.at("file").find("far") == 0);

    std::printf("check_viewer_run: %d passed, %d failed\n", passes, failures);
    if (failures == 0) std::printf("viewer test: PASSED\n");
    return failures ? 1 : 0;
}
