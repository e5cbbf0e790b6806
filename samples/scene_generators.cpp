// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod samples: deterministic scene generators (see samples.h for the contracts).
#include <aggrelod/samples.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

namespace aggrelod::samples {

namespace {

constexpr double kPi = 3.14159265358979323846;

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
double distance(const Vec3& a, const Vec3& b) { return norm(sub(a, b)); }

Vec3 vertex(const InputObject& o, uint32_t i) {
    return {o.positions[3 * size_t(i)], o.positions[3 * size_t(i) + 1],
            o.positions[3 * size_t(i) + 2]};
}

uint32_t addVertex(InputObject& o, double x, double y, double z) {
    const uint32_t index = uint32_t(o.positions.size() / 3);
    o.positions.push_back(x);
    o.positions.push_back(y);
    o.positions.push_back(z);
    return index;
}

void addTriangle(InputObject& o, uint32_t a, uint32_t b, uint32_t c) {
    o.indices.push_back(a);
    o.indices.push_back(b);
    o.indices.push_back(c);
}

// Grid coordinate i of n between lo and hi, exact at both ends so that shared box edges
// produce bit-identical positions.
double gridCoordinate(double lo, double hi, int i, int n) {
    if (i == 0) return lo;
    if (i == n) return hi;
    return lo + (hi - lo) * double(i) / double(n);
}

// Surface of revolution; the caps are fans around (0, bottomApexZ) and (0, topApexZ) on the
// axis (equal to the first / last profile height for flat caps, or the poles of a sphere).
InputObject lathe(const std::string& name, const Vec3& c,
                  const std::vector<std::pair<double, double>>& profile, int segments,
                  double bottomApexZ, double topApexZ) {
    if (segments < 3 || profile.empty())
        throw std::invalid_argument("lathe '" + name + "': needs >= 3 segments and a profile");
    for (const auto& p : profile)
        if (!(p.first > 0))
            throw std::invalid_argument("lathe '" + name + "': profile radius must be > 0");
    InputObject o;
    o.name = name;
    const size_t rings = profile.size();
    std::vector<double> cosines(static_cast<size_t>(segments)), sines(static_cast<size_t>(segments));
    for (int j = 0; j < segments; ++j) {
        const double angle = 2.0 * kPi * double(j) / double(segments);
        cosines[size_t(j)] = j == 0 ? 1.0 : std::cos(angle);
        sines[size_t(j)] = j == 0 ? 0.0 : std::sin(angle);
    }
    for (size_t i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j)
            addVertex(o, c[0] + profile[i].first * cosines[size_t(j)],
                      c[1] + profile[i].first * sines[size_t(j)], c[2] + profile[i].second);
    const uint32_t bottom = addVertex(o, c[0], c[1], c[2] + bottomApexZ);
    const uint32_t top = addVertex(o, c[0], c[1], c[2] + topApexZ);
    auto v = [&](size_t ring, int j) { return uint32_t(ring * size_t(segments) + size_t(j % segments)); };
    for (size_t i = 0; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            addTriangle(o, v(i, j), v(i, j + 1), v(i + 1, j + 1));
            addTriangle(o, v(i, j), v(i + 1, j + 1), v(i + 1, j));
        }
    for (int j = 0; j < segments; ++j) {
        addTriangle(o, bottom, v(0, j + 1), v(0, j));
        addTriangle(o, top, v(rings - 1, j), v(rings - 1, j + 1));
    }
    return o;
}

std::vector<std::pair<double, double>> scaledProfile(
    const std::vector<std::pair<double, double>>& profile, double scale) {
    std::vector<std::pair<double, double>> out;
    out.reserve(profile.size());
    for (const auto& p : profile) out.emplace_back(p.first * scale, p.second * scale);
    return out;
}

// Appends the points of a circular arc (centre (0, zc), radius r) from angle a0 to a1
// (radians, measured from the +radius direction towards +z), `count` points after a0.
void appendArc(std::vector<std::pair<double, double>>& profile, double zc, double r, double a0,
               double a1, int count) {
    for (int k = 1; k <= count; ++k) {
        const double a = a0 + (a1 - a0) * double(k) / double(count);
        profile.emplace_back(r * std::cos(a), zc + r * std::sin(a));
    }
}

// --- chess pieces: profiles of unit size (base on z = 0, base radius <= 0.38) ---------------
std::vector<std::pair<double, double>> pawnProfile() {
    std::vector<std::pair<double, double>> p = {
        {0.30, 0.00}, {0.30, 0.08}, {0.22, 0.12}, {0.12, 0.30}, {0.09, 0.45}, {0.17, 0.50},
        {0.09, 0.55}};
    p.emplace_back(0.14 * std::cos(-0.7), 0.66 + 0.14 * std::sin(-0.7));
    appendArc(p, 0.66, 0.14, -0.7, 1.35, 6);
    return p;
}
std::vector<std::pair<double, double>> rookProfile() {
    return {{0.36, 0.00}, {0.36, 0.10}, {0.28, 0.16}, {0.22, 0.25}, {0.20, 0.60},
            {0.28, 0.66}, {0.28, 0.85}, {0.20, 0.85}, {0.20, 0.78}};
}
std::vector<std::pair<double, double>> bishopProfile() {
    return {{0.34, 0.00}, {0.34, 0.09}, {0.24, 0.14}, {0.14, 0.35}, {0.10, 0.60},
            {0.18, 0.64}, {0.10, 0.68}, {0.15, 0.75}, {0.16, 0.82}, {0.13, 0.92},
            {0.07, 1.00}, {0.03, 1.05}};
}
std::vector<std::pair<double, double>> queenProfile() {
    return {{0.37, 0.00}, {0.37, 0.10}, {0.27, 0.16}, {0.16, 0.40}, {0.12, 0.75},
            {0.21, 0.80}, {0.13, 0.85}, {0.17, 1.00}, {0.21, 1.10}, {0.15, 1.12},
            {0.08, 1.18}, {0.04, 1.22}};
}
std::vector<std::pair<double, double>> kingProfile() {
    return {{0.38, 0.00}, {0.38, 0.10}, {0.28, 0.16}, {0.17, 0.45}, {0.13, 0.85},
            {0.22, 0.90}, {0.14, 0.95}, {0.18, 1.12}, {0.20, 1.20}, {0.08, 1.26},
            {0.06, 1.40}, {0.03, 1.42}};
}
// Knight silhouette (u forward, v up), counter-clockwise, base on v = 0. Extruded 0.30 deep:
// its footprint stays within 0.372 of the square's centre at any heading (unit scale).
std::vector<std::pair<double, double>> knightOutline() {
    return {{-0.32, 0.00}, {0.32, 0.00}, {0.32, 0.10}, {0.18, 0.16}, {0.22, 0.40},
            {0.30, 0.55}, {0.34, 0.66}, {0.30, 0.74}, {0.10, 0.84}, {0.02, 0.95},
            {-0.06, 0.86}, {-0.18, 0.74}, {-0.22, 0.50}, {-0.20, 0.16}, {-0.32, 0.10}};
}

// Ear clipping of a simple counter-clockwise polygon: triangles as index triples.
std::vector<std::array<size_t, 3>> earClip(const std::vector<std::pair<double, double>>& poly) {
    auto crossAt = [&](size_t a, size_t b, size_t c) {
        return (poly[b].first - poly[a].first) * (poly[c].second - poly[a].second) -
               (poly[b].second - poly[a].second) * (poly[c].first - poly[a].first);
    };
    std::vector<size_t> remaining(poly.size());
    for (size_t i = 0; i < poly.size(); ++i) remaining[i] = i;
    std::vector<std::array<size_t, 3>> triangles;
    while (remaining.size() > 3) {
        bool clipped = false;
        const size_t n = remaining.size();
        for (size_t k = 0; k < n && !clipped; ++k) {
            const size_t a = remaining[(k + n - 1) % n], b = remaining[k], c = remaining[(k + 1) % n];
            if (crossAt(a, b, c) <= 0) continue;  // reflex or collinear corner
            bool empty = true;
            for (size_t m : remaining) {
                if (m == a || m == b || m == c) continue;
                if (crossAt(a, b, m) >= 0 && crossAt(b, c, m) >= 0 && crossAt(c, a, m) >= 0) {
                    empty = false;
                    break;
                }
            }
            if (!empty) continue;
            triangles.push_back({a, b, c});
            remaining.erase(remaining.begin() + std::ptrdiff_t(k));
            clipped = true;
        }
        if (!clipped) throw std::invalid_argument("earClip: polygon is not simple and CCW");
    }
    triangles.push_back({remaining[0], remaining[1], remaining[2]});
    return triangles;
}

void renumber(std::vector<InputObject>& objects) {
    for (size_t i = 0; i < objects.size(); ++i) objects[i].id = uint32_t(i);
}

std::string twoDigits(int i) {
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "%02d", i);
    return buffer;
}

}  // namespace

// --- Random -------------------------------------------------------------------------------

double Random::uniform01() {
    // genrand_res53: 27 + 26 random bits -> a double in [0, 1) with 53-bit resolution.
    const uint32_t a = uint32_t(engine_()) >> 5;
    const uint32_t b = uint32_t(engine_()) >> 6;
    return (double(a) * 67108864.0 + double(b)) * (1.0 / 9007199254740992.0);
}

int Random::uniformInt(int lo, int hi) {
    const double span = double(hi) - double(lo) + 1.0;
    const int value = lo + int(std::floor(uniform01() * span));
    return std::min(value, hi);
}

double Random::logUniform(double lo, double hi) {
    return lo * std::exp(uniform01() * std::log(hi / lo));
}

Vec3 Random::direction() {
    for (;;) {
        const Vec3 d = {uniform(-1, 1), uniform(-1, 1), uniform(-1, 1)};
        const double n = norm(d);
        if (n > 1e-3 && n <= 1.0) return {d[0] / n, d[1] / n, d[2] / n};
    }
}

// --- mesh helpers ---------------------------------------------------------------------------

InputObject makeBox(const std::string& name, const Vec3& lo, const Vec3& hi, double maxEdge) {
    for (int a = 0; a < 3; ++a)
        if (!(lo[size_t(a)] < hi[size_t(a)]))
            throw std::invalid_argument("makeBox '" + name + "': lo must be < hi on every axis");
    int cells[3];
    for (int a = 0; a < 3; ++a) {
        const double extent = hi[size_t(a)] - lo[size_t(a)];
        cells[a] = maxEdge > 0 ? std::max(1, int(std::ceil(extent / maxEdge - 1e-9))) : 1;
    }
    InputObject o;
    o.name = name;
    std::map<std::array<int, 3>, uint32_t> welded;  // integer grid coordinates -> vertex
    auto gridVertex = [&](const std::array<int, 3>& g) {
        auto it = welded.find(g);
        if (it != welded.end()) return it->second;
        const uint32_t index = addVertex(o, gridCoordinate(lo[0], hi[0], g[0], cells[0]),
                                         gridCoordinate(lo[1], hi[1], g[1], cells[1]),
                                         gridCoordinate(lo[2], hi[2], g[2], cells[2]));
        welded.emplace(g, index);
        return index;
    };
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;  // e_u x e_v = e_axis
        for (int side = 0; side < 2; ++side) {
            for (int i = 0; i < cells[u]; ++i)
                for (int j = 0; j < cells[v]; ++j) {
                    std::array<int, 3> g00{}, g10{}, g11{}, g01{};
                    for (auto* g : {&g00, &g10, &g11, &g01}) (*g)[size_t(axis)] = side ? cells[axis] : 0;
                    g00[size_t(u)] = i;     g00[size_t(v)] = j;
                    g10[size_t(u)] = i + 1; g10[size_t(v)] = j;
                    g11[size_t(u)] = i + 1; g11[size_t(v)] = j + 1;
                    g01[size_t(u)] = i;     g01[size_t(v)] = j + 1;
                    const uint32_t p00 = gridVertex(g00), p10 = gridVertex(g10),
                                   p11 = gridVertex(g11), p01 = gridVertex(g01);
                    if (side) {  // outward normal +axis
                        addTriangle(o, p00, p10, p11);
                        addTriangle(o, p00, p11, p01);
                    } else {     // outward normal -axis
                        addTriangle(o, p00, p11, p10);
                        addTriangle(o, p00, p01, p11);
                    }
                }
        }
    }
    return o;
}

InputObject makeUvSphere(const std::string& name, const Vec3& center, double radius,
                         int segments, int rings) {
    if (rings < 2 || !(radius > 0))
        throw std::invalid_argument("makeUvSphere '" + name + "': needs rings >= 2, radius > 0");
    std::vector<std::pair<double, double>> profile;
    for (int i = 1; i < rings; ++i) {
        const double latitude = -kPi / 2 + kPi * double(i) / double(rings);
        profile.emplace_back(radius * std::cos(latitude), radius * std::sin(latitude));
    }
    return lathe(name, center, profile, segments, -radius, radius);
}

InputObject makeCylinder(const std::string& name, const Vec3& baseCenter, double radius,
                         double height, int segments, int heightSegments) {
    if (heightSegments < 1 || !(height > 0))
        throw std::invalid_argument("makeCylinder '" + name + "': needs height > 0");
    std::vector<std::pair<double, double>> profile;
    for (int i = 0; i <= heightSegments; ++i)
        profile.emplace_back(radius, gridCoordinate(0, height, i, heightSegments));
    return lathe(name, baseCenter, profile, segments, 0, height);
}

InputObject makeLathe(const std::string& name, const Vec3& baseCenter,
                      const std::vector<std::pair<double, double>>& profile, int segments) {
    if (profile.empty()) throw std::invalid_argument("makeLathe '" + name + "': empty profile");
    return lathe(name, baseCenter, profile, segments, profile.front().second,
                 profile.back().second);
}

InputObject makeExtrusion(const std::string& name,
                          const std::vector<std::pair<double, double>>& outline, double depth,
                          double yaw, const Vec3& offset) {
    if (outline.size() < 3 || !(depth > 0))
        throw std::invalid_argument("makeExtrusion '" + name + "': needs 3 points, depth > 0");
    InputObject o;
    o.name = name;
    const uint32_t n = uint32_t(outline.size());
    // Vertices: k on the y = -depth/2 face, n + k on the y = +depth/2 face; (u, v) -> (x, z).
    for (int face = 0; face < 2; ++face)
        for (const auto& p : outline) addVertex(o, p.first, face ? depth / 2 : -depth / 2, p.second);
    // A counter-clockwise (u, v) triangle has normal e_x x e_z = -e_y.
    for (const auto& t : earClip(outline)) {
        addTriangle(o, uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2]));              // -y cap
        addTriangle(o, n + uint32_t(t[0]), n + uint32_t(t[2]), n + uint32_t(t[1]));  // +y cap
    }
    for (uint32_t k = 0; k < n; ++k) {
        const uint32_t a = k, b = (k + 1) % n, c = n + b, d = n + a;
        addTriangle(o, a, c, b);
        addTriangle(o, a, d, c);
    }
    rotateZAndTranslate(o, yaw, offset);
    return o;
}

void rotateZAndTranslate(InputObject& object, double yaw, const Vec3& offset) {
    const double c = yaw == 0 ? 1.0 : std::cos(yaw), s = yaw == 0 ? 0.0 : std::sin(yaw);
    for (size_t i = 0; i + 2 < object.positions.size(); i += 3) {
        const double x = object.positions[i], y = object.positions[i + 1];
        object.positions[i] = c * x - s * y + offset[0];
        object.positions[i + 1] = s * x + c * y + offset[1];
        object.positions[i + 2] += offset[2];
    }
}

// --- scenes ---------------------------------------------------------------------------------

std::vector<InputObject> makeTwoCubes(double gap) {
    if (!(gap > 0)) throw std::invalid_argument("makeTwoCubes: gap must be > 0");
    std::vector<InputObject> objects;
    objects.push_back(makeBox("cubeA", {0, 0, 0}, {1, 1, 1}));
    objects.push_back(makeBox("cubeB", {1 + gap, 0, 0}, {2 + gap, 1, 1}));
    renumber(objects);
    return objects;
}

std::vector<InputObject> makeOffsetSlabs() {
    std::vector<InputObject> objects;
    objects.push_back(makeBox("slabLower", {0, 0, 0}, {40, 40, 1}, 8));
    objects.push_back(makeBox("slabUpper", {4, 4, 2}, {44, 44, 3}, 8));
    renumber(objects);
    return objects;
}

std::vector<InputObject> makeSpheres15(uint32_t seed) {
    constexpr int kCount = 15;
    constexpr double kRadius = 1.0;
    Random rng(seed);
    for (int attempt = 0; attempt < 1000; ++attempt) {
        // Partition 15 spheres into 4-6 clusters of at least one sphere each.
        const int clusterCount = rng.uniformInt(4, 6);
        std::vector<int> clusterOf(kCount);
        for (int i = 0; i < kCount; ++i)
            clusterOf[size_t(i)] = i < clusterCount ? i : rng.uniformInt(0, clusterCount - 1);
        std::stable_sort(clusterOf.begin(), clusterOf.end());
        std::vector<Vec3> centers;
        bool failed = false;
        for (int i = 0; i < kCount && !failed; ++i) {
            const int cluster = clusterOf[size_t(i)];
            const bool firstOfCluster = i == 0 || clusterOf[size_t(i) - 1] != cluster;
            bool placed = false;
            for (int tries = 0; tries < 500 && !placed; ++tries) {
                Vec3 candidate = {0, 0, 0};
                if (i > 0) {
                    std::vector<int> anchors;
                    for (int k = 0; k < i; ++k)
                        if ((clusterOf[size_t(k)] == cluster) != firstOfCluster) anchors.push_back(k);
                    const int anchor = anchors[size_t(rng.uniformInt(0, int(anchors.size()) - 1))];
                    // Links between clusters are stratified over [1.3, 3.7] so that the
                    // clusters join at different deltas.
                    const double slot = (3.7 - 1.3) / double(clusterCount - 1);
                    const double gap = firstOfCluster
                                           ? 1.3 + slot * (double(cluster - 1) + rng.uniform(0.1, 0.9))
                                           : rng.uniform(0.25, 1.0);
                    Vec3 d = rng.direction();
                    d[2] *= 0.5;  // a rather flat layout, as in the paper's figure
                    const double n = norm(d);
                    for (auto& x : d) x /= n;
                    for (int a = 0; a < 3; ++a)
                        candidate[size_t(a)] = centers[size_t(anchor)][size_t(a)] + d[size_t(a)] * (2 * kRadius + gap);
                }
                placed = true;
                for (int k = 0; k < i && placed; ++k) {
                    const double gap = distance(candidate, centers[size_t(k)]) - 2 * kRadius;
                    const double minimum = clusterOf[size_t(k)] == cluster ? 0.2 : 1.2;
                    if (gap < minimum) placed = false;
                }
                if (placed) centers.push_back(candidate);
            }
            failed = !placed;
        }
        if (failed) continue;
        // Accept the layout only when the paper's deltas (1, 1.5, 2, 3, 4) give at least
        // three different groupings (single linkage on the ideal sphere gaps).
        std::vector<int> groupCounts;
        for (double delta : {1.0, 1.5, 2.0, 3.0, 4.0}) {
            std::vector<int> group(kCount);
            for (int i = 0; i < kCount; ++i) group[size_t(i)] = i;
            for (bool changed = true; changed;) {
                changed = false;
                for (int i = 0; i < kCount; ++i)
                    for (int k = 0; k < kCount; ++k)
                        if (distance(centers[size_t(i)], centers[size_t(k)]) - 2 * kRadius < delta &&
                            group[size_t(k)] < group[size_t(i)]) {
                            group[size_t(i)] = group[size_t(k)];
                            changed = true;
                        }
            }
            std::sort(group.begin(), group.end());
            groupCounts.push_back(int(std::unique(group.begin(), group.end()) - group.begin()));
        }
        std::sort(groupCounts.begin(), groupCounts.end());
        if (std::unique(groupCounts.begin(), groupCounts.end()) - groupCounts.begin() < 3) continue;
        std::vector<InputObject> objects;
        for (int i = 0; i < kCount; ++i)
            objects.push_back(makeUvSphere("sphere" + twoDigits(i), centers[size_t(i)], kRadius, 20, 11));
        renumber(objects);
        return objects;
    }
    throw std::runtime_error("makeSpheres15: could not place the spheres");
}

std::vector<InputObject> makeChessBoard(uint32_t seed, bool withBoard) {
    Random rng(seed);
    enum Kind { Pawn, Rook, Knight, Bishop, Queen, King, KindCount };
    static const char* const kKindNames[KindCount] = {"pawn", "rook", "knight", "bishop", "queen", "king"};
    static const int kWeights[KindCount] = {8, 2, 2, 2, 1, 1};
    const int pieceCount = rng.uniformInt(16, 32);
    std::vector<int> squares(64);
    for (int i = 0; i < 64; ++i) squares[size_t(i)] = i;
    for (int i = 63; i > 0; --i) std::swap(squares[size_t(i)], squares[size_t(rng.uniformInt(0, i))]);
    std::vector<InputObject> objects;
    if (withBoard) objects.push_back(makeBox("board", {0, 0, -0.25}, {8, 8, -0.05}, 1.0));
    constexpr int kSegments = 24;
    for (int p = 0; p < pieceCount; ++p) {
        Kind kind;
        if (p < KindCount) {
            kind = Kind(p);  // one of each kind first: a heterogeneous scene for every seed
        } else {
            int r = rng.uniformInt(0, 15);
            int k = 0;
            while (r >= kWeights[k]) r -= kWeights[k++];
            kind = Kind(k);
        }
        const bool white = rng.uniform01() < 0.5;
        const double scale = rng.uniform(0.8, 1.1);
        const int square = squares[size_t(p)];
        const int file = square % 8, rank = square / 8;
        const Vec3 base = {file + 0.5, rank + 0.5, 0.0};
        std::string name = std::string(white ? "w_" : "b_") + kKindNames[kind] + "_" +
                           char('a' + file) + char('1' + rank);
        switch (kind) {
            case Pawn: objects.push_back(makeLathe(name, base, scaledProfile(pawnProfile(), scale), kSegments)); break;
            case Rook: objects.push_back(makeLathe(name, base, scaledProfile(rookProfile(), scale), kSegments)); break;
            case Bishop: objects.push_back(makeLathe(name, base, scaledProfile(bishopProfile(), scale), kSegments)); break;
            case Queen: objects.push_back(makeLathe(name, base, scaledProfile(queenProfile(), scale), kSegments)); break;
            case King: objects.push_back(makeLathe(name, base, scaledProfile(kingProfile(), scale), kSegments)); break;
            case Knight: {
                const double yaw = rng.uniform(0, 2 * kPi);
                objects.push_back(makeExtrusion(name, scaledProfile(knightOutline(), scale), 0.30 * scale, yaw, base));
                break;
            }
            default: break;
        }
    }
    renumber(objects);
    return objects;
}

std::vector<InputObject> makeRandomScene(int objectCount, int approxTotalTriangles, uint32_t seed) {
    if (objectCount < 1) throw std::invalid_argument("makeRandomScene: objectCount must be >= 1");
    Random rng(seed);
    const double budget = std::max(12.0, double(approxTotalTriangles) / double(objectCount));
    const double extent = 2.5 * std::cbrt(double(objectCount)) + 4.0;  // half-size of the seeding box
    std::vector<Vec3> centers;
    std::vector<double> radii;
    std::vector<InputObject> objects;
    centers.reserve(size_t(objectCount));
    for (int i = 0; i < objectCount; ++i) {
        const double radius = rng.logUniform(0.5, 2.0);
        // Placement: next to an earlier object at a log-uniform gap (clusters), or a new seed.
        Vec3 center{};
        bool placed = false;
        for (int tries = 0; tries < 200 && !placed; ++tries) {
            if (i == 0 || rng.uniform01() < 0.08) {
                center = {rng.uniform(-extent, extent), rng.uniform(-extent, extent),
                          rng.uniform(-extent / 3, extent / 3)};
            } else {
                const size_t anchor = size_t(rng.uniformInt(0, i - 1));
                const double gap = rng.logUniform(0.05, 3.0);
                const Vec3 d = rng.direction();
                for (int a = 0; a < 3; ++a)
                    center[size_t(a)] = centers[anchor][size_t(a)] + d[size_t(a)] * (radius + radii[anchor] + gap);
            }
            placed = true;
            for (size_t k = 0; k < centers.size() && placed; ++k)
                if (distance(center, centers[k]) < radius + radii[k] + 0.02) placed = false;
        }
        if (!placed) {  // fall back: beyond everything placed so far along +x
            double maxX = 0;
            for (size_t k = 0; k < centers.size(); ++k) maxX = std::max(maxX, centers[k][0] + radii[k]);
            center = {maxX + radius + 0.5, 0, 0};
        }
        centers.push_back(center);
        radii.push_back(radius);

        char nameBuffer[32];
        std::snprintf(nameBuffer, sizeof nameBuffer, "obj%04d", i);
        const std::string name = nameBuffer;
        const int shape = rng.uniformInt(0, 3);
        InputObject o;
        if (shape == 0) {  // sphere: 2 * segments * (rings - 1) triangles
            const int bands = std::max(2, int(std::lround(std::sqrt(budget / 4.0))));
            const int segments = std::max(4, int(std::lround(budget / (2.0 * bands))));
            o = makeUvSphere(name, center, radius, segments, bands + 1);
        } else if (shape == 1) {  // box with half-diagonal = radius, random heading
            Vec3 dims = {rng.uniform(0.3, 1.0), rng.uniform(0.3, 1.0), rng.uniform(0.3, 1.0)};
            const double s = radius / (0.5 * norm(dims));
            for (auto& x : dims) x *= s;
            const double area = dims[0] * dims[1] + dims[1] * dims[2] + dims[2] * dims[0];
            const double maxEdge = std::sqrt(4.0 * area / budget);
            o = makeBox(name, {-dims[0] / 2, -dims[1] / 2, -dims[2] / 2},
                        {dims[0] / 2, dims[1] / 2, dims[2] / 2}, maxEdge);
            rotateZAndTranslate(o, rng.uniform(0, 2 * kPi), center);
        } else if (shape == 2) {  // cylinder: sqrt(r^2 + (h/2)^2) = radius
            const double angle = rng.uniform(0.3, 1.2);
            const double r = radius * std::cos(angle), h = 2 * radius * std::sin(angle);
            const int heightSegments = rng.uniformInt(1, 3);
            const int segments = std::max(6, int(std::lround(budget / (2.0 * (heightSegments + 1)))));
            o = makeCylinder(name, {center[0], center[1], center[2] - h / 2}, r, h, segments, heightSegments);
        } else {  // lathe (vase-like): radii <= rMax, heights in [0, h]
            const double angle = rng.uniform(0.5, 1.2);
            const double rMax = radius * std::cos(angle), h = 2 * radius * std::sin(angle);
            const int points = rng.uniformInt(5, 9);
            std::vector<std::pair<double, double>> profile;
            for (int k = 0; k < points; ++k)
                profile.emplace_back(rMax * rng.uniform(0.35, 1.0), h * double(k) / double(points - 1));
            const int segments = std::max(6, int(std::lround(budget / (2.0 * points))));
            o = makeLathe(name, {center[0], center[1], center[2] - h / 2}, profile, segments);
        }
        objects.push_back(std::move(o));
    }
    renumber(objects);
    return objects;
}

// --- checks ---------------------------------------------------------------------------------

double signedVolume(const InputObject& object) {
    double volume = 0;
    for (size_t t = 0; t + 2 < object.indices.size(); t += 3) {
        const Vec3 a = vertex(object, object.indices[t]), b = vertex(object, object.indices[t + 1]),
                   c = vertex(object, object.indices[t + 2]);
        volume += dot(a, cross(b, c));
    }
    return volume / 6.0;
}

std::string checkClosedMesh(const InputObject& object) {
    const std::string who = "object '" + object.name + "': ";
    if (object.positions.size() % 3 != 0) return who + "positions not a multiple of 3";
    if (object.indices.empty() || object.indices.size() % 3 != 0)
        return who + "indices empty or not a multiple of 3";
    const size_t vertexCount = object.positions.size() / 3;
    for (double x : object.positions)
        if (!std::isfinite(x)) return who + "non-finite coordinate";
    // Welded: no two vertices share a position.
    std::vector<std::tuple<double, double, double, size_t>> sorted;
    for (size_t i = 0; i < vertexCount; ++i)
        sorted.emplace_back(object.positions[3 * i], object.positions[3 * i + 1], object.positions[3 * i + 2], i);
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 1; i < sorted.size(); ++i)
        if (std::get<0>(sorted[i]) == std::get<0>(sorted[i - 1]) &&
            std::get<1>(sorted[i]) == std::get<1>(sorted[i - 1]) &&
            std::get<2>(sorted[i]) == std::get<2>(sorted[i - 1]))
            return who + "vertices " + std::to_string(std::get<3>(sorted[i - 1])) + " and " +
                   std::to_string(std::get<3>(sorted[i])) + " share a position (not welded)";
    // Scale for the degeneracy test.
    Vec3 lo = vertex(object, 0), hi = lo;
    for (size_t i = 0; i < vertexCount; ++i) {
        const Vec3 p = vertex(object, uint32_t(i));
        for (int a = 0; a < 3; ++a) {
            lo[size_t(a)] = std::min(lo[size_t(a)], p[size_t(a)]);
            hi[size_t(a)] = std::max(hi[size_t(a)], p[size_t(a)]);
        }
    }
    const double diagonal = distance(lo, hi);
    std::map<std::pair<uint32_t, uint32_t>, int> directed;
    for (size_t t = 0; t < object.indices.size(); t += 3) {
        const uint32_t i[3] = {object.indices[t], object.indices[t + 1], object.indices[t + 2]};
        for (uint32_t k : i)
            if (k >= vertexCount) return who + "index " + std::to_string(k) + " out of range";
        if (i[0] == i[1] || i[1] == i[2] || i[0] == i[2])
            return who + "triangle " + std::to_string(t / 3) + " repeats a vertex";
        const Vec3 n = cross(sub(vertex(object, i[1]), vertex(object, i[0])),
                             sub(vertex(object, i[2]), vertex(object, i[0])));
        if (norm(n) <= 1e-12 * diagonal * diagonal)
            return who + "triangle " + std::to_string(t / 3) + " is degenerate";
        for (int e = 0; e < 3; ++e) ++directed[{i[e], i[(e + 1) % 3]}];
    }
    for (const auto& [edge, count] : directed) {
        if (count != 1)
            return who + "directed edge " + std::to_string(edge.first) + "-" + std::to_string(edge.second) +
                   " used " + std::to_string(count) + " times (non-manifold or inconsistent orientation)";
        if (!directed.count({edge.second, edge.first}))
            return who + "edge " + std::to_string(edge.first) + "-" + std::to_string(edge.second) +
                   " has one triangle only (open mesh)";
    }
    return {};
}

std::pair<Vec3, double> boundingSphere(const InputObject& object) {
    if (object.positions.size() < 3) return {{0, 0, 0}, 0};
    Vec3 lo = vertex(object, 0), hi = lo;
    const size_t vertexCount = object.positions.size() / 3;
    for (size_t i = 0; i < vertexCount; ++i) {
        const Vec3 p = vertex(object, uint32_t(i));
        for (int a = 0; a < 3; ++a) {
            lo[size_t(a)] = std::min(lo[size_t(a)], p[size_t(a)]);
            hi[size_t(a)] = std::max(hi[size_t(a)], p[size_t(a)]);
        }
    }
    const Vec3 center = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
    double radius = 0;
    for (size_t i = 0; i < vertexCount; ++i) radius = std::max(radius, distance(center, vertex(object, uint32_t(i))));
    return {center, radius};
}

}  // namespace aggrelod::samples
