// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod samples: the open-world generator and its streaming GLB writer (world.h).
// A GLB is a 12-byte header, a JSON chunk and a binary chunk (glTF 2.0 specification,
// section 4.4 "Binary glTF Layout"); the JSON comes first but describes the binary chunk, so
// the world is generated twice: once for the sizes and bounds the JSON needs, once for the
// bytes, which go straight to the file.
#include <aggrelod/samples.h>
#include <aggrelod/world.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace aggrelod::samples {
namespace {

constexpr double kPi = 3.14159265358979323846;
/// Clearance between objects and the terrain, and between terrain tiles (metres).
constexpr double kClearance = 0.05;
/// Least distance between two footprints in one block (metres).
constexpr double kFootprintGap = 0.3;
constexpr double kTileDepth = 4.0;      ///< terrain slab bottom, metres below z = 0
constexpr double kTerrainCell = 12.0;   ///< largest edge of the terrain grid, metres
constexpr double kRoadWidth = 4.0;      ///< the road strip along a block's south edge
constexpr double kRoadMargin = 6.0;     ///< south strip of a block kept for the road
/// Mean objects per block, for the layout of the grid (measured over many blocks).
constexpr double kMeanObjectsPerBlock = 24.0;

// Base colours (linear RGBA, as glTF's baseColorFactor).
constexpr std::array<float, 4> kGrass{0.16f, 0.30f, 0.08f, 1.0f}, kRoad{0.18f, 0.17f, 0.16f, 1.0f},
    kLeaves{0.05f, 0.30f, 0.04f, 1.0f}, kNeedles{0.02f, 0.16f, 0.06f, 1.0f}, kWall{0.70f, 0.58f, 0.40f, 1.0f},
    kBarrel{0.25f, 0.12f, 0.05f, 1.0f}, kRock{0.35f, 0.34f, 0.32f, 1.0f}, kHay{0.62f, 0.52f, 0.20f, 1.0f};

/// Smooth rolling hills, metres: between about 0.3 and 7.7.
double terrainHeight(double x, double y) {
    return 4.0 + 2.5 * std::sin(x / 41.0) * std::cos(y / 57.0) + 1.2 * std::sin((x + 0.7 * y) / 23.0);
}

/// The random stream of one block: a 64-bit mix (splitmix64's finaliser) of the seed and the
/// block's row and column, so that a block is the same in every world that has it.
uint32_t blockSeed(uint32_t seed, uint64_t row, uint64_t column) {
    const uint64_t cell = (row << 32) | (column & 0xFFFFFFFFull);
    uint64_t z = (uint64_t(seed) << 32) ^ (cell * 0x9E3779B97F4A7C15ull) ^ 0xD1B54A32D192ED03ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return uint32_t(z ^ (z >> 31));
}

void paint(InputObject& o, const std::array<float, 4>& colour) {
    o.triangleColors.resize(4 * (o.indices.size() / 3));
    for (size_t t = 0; t < o.indices.size() / 3; ++t) std::copy(colour.begin(), colour.end(), &o.triangleColors[4 * t]);
}

struct Footprint {
    double x, y, radius;
};

/// One block of the world: its terrain tile, and where its objects may stand.
class Block {
public:
    Block(uint32_t seed, uint64_t index, uint64_t columns)
        : random_(blockSeed(seed, index / columns, index % columns)), row_(index / columns), column_(index % columns) {
        x0_ = double(column_) * kWorldBlockSize;
        y0_ = double(row_) * kWorldBlockSize;
        char prefix[32];
        std::snprintf(prefix, sizeof prefix, "b%04llu_%04llu_", static_cast<unsigned long long>(row_),
                      static_cast<unsigned long long>(column_));
        prefix_ = prefix;
    }

    /// The block's objects, in order: terrain, roads, then its kind's content.
    std::vector<InputObject> objects() {
        std::vector<InputObject> out;
        out.push_back(terrainTile());
        for (int k = 0; k < 4; ++k) out.push_back(roadSegment(k));
        const double kind = random_.uniform01();
        if (kind < 0.4) addForest(out);
        else if (kind < 0.7) addTown(out);
        else addField(out);
        return out;
    }

private:
    double tileLo(int axis) const { return (axis == 0 ? x0_ : y0_) + kClearance / 2; }
    double tileHi(int axis) const { return (axis == 0 ? x0_ : y0_) + kWorldBlockSize - kClearance / 2; }
    int tileCells() const { return std::max(1, int(std::ceil((kWorldBlockSize - kClearance) / kTerrainCell - 1e-9))); }
    double tileGrid(int axis, int i) const {
        const double lo = tileLo(axis), hi = tileHi(axis);
        return i == tileCells() ? hi : lo + (hi - lo) * double(i) / double(tileCells());
    }

    /// Highest terrain over the box [xa, xb] x [ya, yb]: the top of the tile is flat between
    /// its grid corners, so the highest corner of every cell the box meets bounds it.
    double terrainMax(double xa, double ya, double xb, double yb) const {
        const int n = tileCells();
        const auto cellOf = [&](int axis, double v) {
            const double t = (v - tileLo(axis)) / (tileHi(axis) - tileLo(axis)) * n;
            return std::clamp(int(std::floor(t)), 0, n - 1);
        };
        double top = -INFINITY;
        for (int i = cellOf(0, xa); i <= cellOf(0, xb) + 1 && i <= n; ++i)
            for (int j = cellOf(1, ya); j <= cellOf(1, yb) + 1 && j <= n; ++j)
                top = std::max(top, terrainHeight(tileGrid(0, i), tileGrid(1, j)));
        return top;
    }
    double standHeight(const Footprint& f) const {
        return terrainMax(f.x - f.radius, f.y - f.radius, f.x + f.radius, f.y + f.radius) + kClearance;
    }

    InputObject terrainTile() {
        InputObject tile = makeBox(prefix_ + "terrain", {tileLo(0), tileLo(1), -kTileDepth}, {tileHi(0), tileHi(1), 0.0},
                                   kTerrainCell);
        for (size_t v = 0; v + 2 < tile.positions.size(); v += 3)
            if (tile.positions[v + 2] == 0.0) tile.positions[v + 2] = terrainHeight(tile.positions[v], tile.positions[v + 1]);
        paint(tile, kGrass);
        return tile;
    }

    InputObject roadSegment(int k) {
        const double xa = x0_ + 12.0 * k + 0.5, xb = x0_ + 12.0 * (k + 1) - 0.5;
        const double ya = y0_ + 1.0, yb = ya + kRoadWidth;
        const double z = terrainMax(xa, ya, xb, yb) + kClearance;
        InputObject road = makeBox(prefix_ + "road_" + std::to_string(k), {xa, ya, z}, {xb, yb, z + 0.3}, 3.0);
        paint(road, kRoad);
        return road;
    }

    /// A free spot of the given radius inside the block (south strip excluded), or false
    /// after a fixed number of tries.
    bool place(double radius, Footprint& out) {
        for (int attempt = 0; attempt < 40; ++attempt) {
            const Footprint f{random_.uniform(x0_ + 1 + radius, x0_ + kWorldBlockSize - 1 - radius),
                              random_.uniform(y0_ + kRoadMargin + radius, y0_ + kWorldBlockSize - 1 - radius), radius};
            if (fits(f)) {
                placed_.push_back(f);
                out = f;
                return true;
            }
        }
        return false;
    }
    bool fits(const Footprint& f) const {
        if (f.x - f.radius < x0_ + 1 || f.x + f.radius > x0_ + kWorldBlockSize - 1 || f.y - f.radius < y0_ + kRoadMargin ||
            f.y + f.radius > y0_ + kWorldBlockSize - 1)
            return false;
        for (const Footprint& p : placed_)
            if (std::hypot(p.x - f.x, p.y - f.y) < p.radius + f.radius + kFootprintGap) return false;
        return true;
    }
    std::string name(const char* kind) { return prefix_ + kind + "_" + std::to_string(counter_++); }

    void addForest(std::vector<InputObject>& out) {
        const int trees = random_.uniformInt(18, 30);
        for (int t = 0; t < trees; ++t) {
            const double r = random_.uniform(1.5, 3.0);
            Footprint f;
            if (!place(r, f)) break;
            const double trunk = 0.12 * r, h = random_.uniform(1.2, 2.5);
            std::vector<std::pair<double, double>> profile;
            const bool conifer = random_.uniform01() < 0.4;
            if (conifer)
                profile = {{trunk, 0}, {trunk, h}, {r, h + 0.05 * r}, {0.55 * r, h + 1.0 * r}, {0.75 * r, h + 1.05 * r},
                           {0.3 * r, h + 2.0 * r}, {0.08 * r, h + 2.6 * r}};
            else
                profile = {{trunk, 0}, {trunk, h}, {0.7 * r, h + 0.1 * r}, {r, h + 0.6 * r}, {0.85 * r, h + 1.2 * r},
                           {0.5 * r, h + 1.6 * r}, {0.15 * r, h + 1.85 * r}};
            InputObject tree = makeLathe(name("tree"), {f.x, f.y, standHeight(f)}, profile, 14);
            paint(tree, conifer ? kNeedles : kLeaves);
            out.push_back(std::move(tree));
        }
    }

    void addTown(std::vector<InputObject>& out) {
        // Houses on a 3 x 3 grid of plots, each with up to two barrels by it.
        const double plotW = (kWorldBlockSize - 2) / 3, plotH = (kWorldBlockSize - kRoadMargin - 1) / 3;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
                if (random_.uniform01() < 0.2) continue;  // an empty plot
                const double R = random_.uniform(3.0, 4.5), reach = 1.08 * R;
                const Footprint f{x0_ + 1 + plotW * (i + 0.5) + random_.uniform(-1, 1),
                                  y0_ + kRoadMargin + plotH * (j + 0.5) + random_.uniform(-1, 1), reach};
                if (!fits(f)) continue;
                placed_.push_back(f);
                const double wall = random_.uniform(2.6, 3.4);
                InputObject house = makeLathe(name("house"), {0, 0, 0},
                                              {{R, 0}, {R, wall / 3}, {R, 2 * wall / 3}, {R, wall}, {reach, wall + 0.05},
                                               {0.6 * R, wall + 0.4 * R}, {0.2 * R, wall + 0.7 * R}},
                                              4);
                rotateZAndTranslate(house, random_.uniform(0, kPi / 2), {f.x, f.y, standHeight(f)});
                paint(house, kWall);
                out.push_back(std::move(house));
                const int barrels = random_.uniformInt(0, 2);
                for (int b = 0; b < barrels; ++b) {
                    const double angle = random_.uniform(0, 2 * kPi), d = reach + kFootprintGap + 0.4 + random_.uniform(0, 1);
                    const Footprint g{f.x + d * std::cos(angle), f.y + d * std::sin(angle), 0.4};
                    if (!fits(g)) continue;
                    placed_.push_back(g);
                    InputObject barrel = makeLathe(name("barrel"), {g.x, g.y, standHeight(g)},
                                                   {{0.32, 0}, {0.38, 0.25}, {0.4, 0.5}, {0.38, 0.75}, {0.32, 1.0}}, 10);
                    paint(barrel, kBarrel);
                    out.push_back(std::move(barrel));
                }
            }
    }

    void addField(std::vector<InputObject>& out) {
        const int items = random_.uniformInt(12, 22);
        for (int k = 0; k < items; ++k) {
            if (random_.uniform01() < 0.6) {
                const double r = random_.uniform(0.4, 1.5);
                Footprint f;
                if (!place(r, f)) break;
                // A flattened sphere: 0.6 of its radius high, resting above the ground.
                InputObject rock = makeUvSphere(name("rock"), {0, 0, 0}, r, 12, 7);
                for (size_t v = 0; v + 2 < rock.positions.size(); v += 3) rock.positions[v + 2] *= 0.6;
                rotateZAndTranslate(rock, random_.uniform(0, kPi), {f.x, f.y, standHeight(f) + 0.6 * r});
                paint(rock, kRock);
                out.push_back(std::move(rock));
            } else {
                Footprint f;
                if (!place(0.8, f)) break;
                InputObject bale = makeCylinder(name("hay"), {f.x, f.y, standHeight(f)}, 0.8, 1.2, 16, 2);
                paint(bale, kHay);
                out.push_back(std::move(bale));
            }
        }
    }

    Random random_;
    uint64_t row_, column_;
    double x0_ = 0, y0_ = 0;
    std::string prefix_;
    std::vector<Footprint> placed_;
    int counter_ = 0;
};

uint64_t gridColumns(uint64_t objectCount) {
    return std::max<uint64_t>(1, uint64_t(std::ceil(std::sqrt(double(objectCount) / kMeanObjectsPerBlock))));
}

// --- the streaming GLB writer ------------------------------------------------------------------

/// What the JSON needs of one object (pass one).
struct ObjectEntry {
    std::string name;
    uint32_t vertices = 0, indices = 0, material = 0, id = 0;
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
};

/// A float as the shortest decimal text that reads back as the same float.
std::string floatText(float v) {
    char buffer[32];
    for (int digits = 6; digits <= 9; ++digits) {
        std::snprintf(buffer, sizeof buffer, "%.*g", digits, double(v));
        if (std::strtof(buffer, nullptr) == v) break;
    }
    return buffer;
}

class GlbFile {
public:
    explicit GlbFile(const std::string& path) : file_(std::fopen(path.c_str(), "wb")) {}
    ~GlbFile() {
        if (file_) std::fclose(file_);
    }
    bool ok() const { return file_ && !failed_; }
    void write(const void* data, size_t size) {
        if (file_ && size && std::fwrite(data, 1, size, file_) != size) failed_ = true;
    }
    void write(const std::string& text) { write(text.data(), text.size()); }
    void le32(uint32_t v) {
        const unsigned char b[4] = {uint8_t(v), uint8_t(v >> 8), uint8_t(v >> 16), uint8_t(v >> 24)};
        write(b, 4);
    }
    bool seekStart() { return file_ && std::fseek(file_, 0, SEEK_SET) == 0; }
    bool close() {
        if (!file_) return false;
        const bool closed = std::fclose(file_) == 0;
        file_ = nullptr;
        return closed && !failed_;
    }

private:
    std::FILE* file_;
    bool failed_ = false;
};

}  // namespace

WorldSummary generateWorld(const WorldSettings& settings, const std::function<void(InputObject&)>& emit) {
    if (settings.objectCount == 0 || settings.objectCount > kMaxWorldObjects)
        throw std::invalid_argument("world: the object count must be in 1.." + std::to_string(kMaxWorldObjects));
    WorldSummary summary;
    const uint64_t columns = gridColumns(settings.objectCount);
    // Rows of `columns` blocks, filled until the count is reached; the last rows may be short
    // or, when blocks hold fewer objects than the mean, one more than the columns.
    for (uint64_t block = 0; summary.objects < settings.objectCount; ++block) {
        Block b(settings.seed, block, columns);
        ++summary.blocks;
        for (InputObject& o : b.objects()) {
            if (summary.objects == settings.objectCount) break;
            o.id = uint32_t(summary.objects++);
            summary.triangles += o.indices.size() / 3;
            summary.vertices += o.positions.size() / 3;
            emit(o);
        }
    }
    const uint64_t rows = (summary.blocks + columns - 1) / columns;
    summary.extent = double(std::max(rows, columns)) * kWorldBlockSize;
    return summary;
}

bool writeWorldGlb(const WorldSettings& settings, const std::string& path, WorldSummary* summaryOut, std::string& error) {
    // Pass one: sizes, bounds and materials.
    std::vector<ObjectEntry> entries;
    std::vector<std::array<float, 4>> materials;
    std::map<std::array<float, 4>, uint32_t> materialOf;
    WorldSummary summary;
    try {
        entries.reserve(size_t(std::min<uint64_t>(settings.objectCount, kMaxWorldObjects)));
        summary = generateWorld(settings, [&](InputObject& o) {
            ObjectEntry e;
            e.name = o.name;
            e.id = o.id;
            e.vertices = uint32_t(o.positions.size() / 3);
            e.indices = uint32_t(o.indices.size());
            for (int k = 0; k < 3; ++k) {
                e.lo[k] = INFINITY;
                e.hi[k] = -INFINITY;
            }
            for (size_t v = 0; v + 2 < o.positions.size(); v += 3)
                for (int k = 0; k < 3; ++k) {
                    const float c = float(o.positions[v + size_t(k)]);
                    e.lo[k] = std::min(e.lo[k], c);
                    e.hi[k] = std::max(e.hi[k], c);
                }
            std::array<float, 4> colour{1, 1, 1, 1};
            if (o.triangleColors.size() >= 4) std::copy(o.triangleColors.begin(), o.triangleColors.begin() + 4, colour.begin());
            auto it = materialOf.find(colour);
            if (it == materialOf.end()) {
                it = materialOf.emplace(colour, uint32_t(materials.size())).first;
                materials.push_back(colour);
            }
            e.material = it->second;
            entries.push_back(std::move(e));
        });
    } catch (const std::exception& e) {
        error = e.what();
        return false;
    }
    uint64_t binLength = 0;
    for (const ObjectEntry& e : entries) binLength += 12ull * e.vertices + 4ull * e.indices;

    GlbFile glb(path);
    if (!glb.ok()) {
        error = path + ": cannot create: " + std::strerror(errno);
        return false;
    }
    glb.write(std::string(20, '\0'));  // header and JSON chunk header, filled in at the end
    // The JSON, written in pieces of a few objects at a time.
    std::string json = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"aggrelod_make_sample world\"},\"scene\":0,"
                       "\"scenes\":[{\"nodes\":[";
    uint64_t jsonLength = 0;
    const auto flush = [&](bool force) {
        if (!force && json.size() < (1u << 16)) return;
        jsonLength += json.size();
        glb.write(json);
        json.clear();
    };
    for (size_t i = 0; i < entries.size(); ++i) {
        json += (i ? "," : "") + std::to_string(i);
        flush(false);
    }
    json += "]}],\"nodes\":[";
    for (size_t i = 0; i < entries.size(); ++i) {
        json += std::string(i ? "," : "") + "{\"name\":\"" + entries[i].name + "\",\"mesh\":" + std::to_string(i) +
                ",\"extras\":{\"id\":" + std::to_string(entries[i].id) + "}}";
        flush(false);
    }
    json += "],\"meshes\":[";
    for (size_t i = 0; i < entries.size(); ++i) {
        json += std::string(i ? "," : "") + "{\"name\":\"" + entries[i].name + "\",\"primitives\":[{\"attributes\":{\"POSITION\":" +
                std::to_string(2 * i) + "},\"indices\":" + std::to_string(2 * i + 1) +
                ",\"material\":" + std::to_string(entries[i].material) + ",\"mode\":4}]}";
        flush(false);
    }
    json += "],\"accessors\":[";
    for (size_t i = 0; i < entries.size(); ++i) {
        const ObjectEntry& e = entries[i];
        json += std::string(i ? "," : "") + "{\"bufferView\":" + std::to_string(2 * i) +
                ",\"componentType\":5126,\"count\":" + std::to_string(e.vertices) + ",\"type\":\"VEC3\",\"min\":[" +
                floatText(e.lo[0]) + "," + floatText(e.lo[1]) + "," + floatText(e.lo[2]) + "],\"max\":[" +
                floatText(e.hi[0]) + "," + floatText(e.hi[1]) + "," + floatText(e.hi[2]) + "]},{\"bufferView\":" +
                std::to_string(2 * i + 1) + ",\"componentType\":5125,\"count\":" + std::to_string(e.indices) +
                ",\"type\":\"SCALAR\"}";
        flush(false);
    }
    json += "],\"bufferViews\":[";
    uint64_t offset = 0;
    for (size_t i = 0; i < entries.size(); ++i) {
        const uint64_t positions = 12ull * entries[i].vertices, indices = 4ull * entries[i].indices;
        json += std::string(i ? "," : "") + "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
                ",\"byteLength\":" + std::to_string(positions) + ",\"target\":34962},{\"buffer\":0,\"byteOffset\":" +
                std::to_string(offset + positions) + ",\"byteLength\":" + std::to_string(indices) + ",\"target\":34963}";
        offset += positions + indices;
        flush(false);
    }
    json += "],\"materials\":[";
    for (size_t m = 0; m < materials.size(); ++m)
        json += std::string(m ? "," : "") + "{\"name\":\"colour" + std::to_string(m) +
                "\",\"pbrMetallicRoughness\":{\"baseColorFactor\":[" + floatText(materials[m][0]) + "," +
                floatText(materials[m][1]) + "," + floatText(materials[m][2]) + "," + floatText(materials[m][3]) +
                "],\"metallicFactor\":0,\"roughnessFactor\":0.8}}";
    json += "],\"buffers\":[{\"byteLength\":" + std::to_string(binLength) + "}]}";
    json += std::string((4 - (jsonLength + json.size()) % 4) % 4, ' ');  // chunks are 4-byte aligned
    flush(true);
    const uint64_t total = 12 + 8 + jsonLength + 8 + binLength;
    // A file cut short is not left behind under the name asked for.
    const auto failWith = [&](const std::string& why) {
        glb.close();
        std::remove(path.c_str());
        error = why;
        return false;
    };
    if (total > UINT32_MAX)
        return failWith(path + ": the world needs " + std::to_string(total) + " bytes, more than a GLB can hold (4 GiB)");
    glb.le32(uint32_t(binLength));
    glb.write("BIN\0", 4);
    // Pass two: the bytes, object by object (float32 positions, then uint32 indices).
    std::vector<unsigned char> bytes;
    try {
        generateWorld(settings, [&](InputObject& o) {
            bytes.clear();
            const auto put32 = [&](uint32_t v) {
                for (int k = 0; k < 4; ++k) bytes.push_back(uint8_t(v >> (8 * k)));
            };
            for (double c : o.positions) {
                const float f = float(c);
                uint32_t bits;
                std::memcpy(&bits, &f, 4);
                put32(bits);
            }
            for (uint32_t i : o.indices) put32(i);
            glb.write(bytes.data(), bytes.size());
        });
    } catch (const std::exception& e) {
        return failWith(e.what());
    }
    if (!glb.seekStart()) return failWith(path + ": cannot seek");
    glb.write("glTF", 4);
    glb.le32(2);
    glb.le32(uint32_t(total));
    glb.le32(uint32_t(jsonLength));
    glb.write("JSON", 4);
    if (!glb.close()) {
        std::remove(path.c_str());
        error = path + ": write error (disk full?)";
        return false;
    }
    if (summaryOut) *summaryOut = summary;
    return true;
}

}  // namespace aggrelod::samples
