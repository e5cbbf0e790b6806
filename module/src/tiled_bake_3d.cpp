// SPDX-License-Identifier: AGPL-3.0-or-later
// The tiled 3D bake (docs/design.md §2.8): cells of the world baked alone for the fine
// levels, a quadtree of parent cells aggregating their coarsest aggregates for the coarse
// ones, combined into one Hierarchy3D. The cell rule and the thresholds are in
// tiled_bake_3d.h.
#include "baker_3d.h"
#include "hierarchy_serialize.h"
#include "parallel_for.h"
#include "solidify.h"

#include <aggrelod/dendrogram.h>
#include <aggrelod/disjoint_sets.h>
#include <aggrelod/tiled_bake_3d.h>

#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <numeric>
#include <string>

namespace aggrelod {
namespace {

using detail::diag;
using detail::fmt;

/// Box (min xyz, max xyz) of the finite vertices an object's triangles use; false when none.
bool objectBox(const InputObject& o, double b[6]) {
    for (int k = 0; k < 3; ++k) {
        b[k] = INFINITY;
        b[3 + k] = -INFINITY;
    }
    bool any = false;
    const size_t vertexCount = o.positions.size() / 3;
    for (size_t t = 0; t + 2 < o.indices.size(); t += 3)
        for (int c = 0; c < 3; ++c) {
            const uint32_t v = o.indices[t + c];
            if (v >= vertexCount) continue;
            const double* p = &o.positions[3 * size_t(v)];
            if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) return false;
            for (int k = 0; k < 3; ++k) {
                b[k] = std::min(b[k], p[k]);
                b[3 + k] = std::max(b[3 + k], p[k]);
            }
            any = true;
        }
    return any;
}

/// Level totals from the aggregates (as buildLevels sums them).
void totalLevel(Level& level) {
    double volume = 0, area = 0;
    level.volumeOriginal = level.volumeHull = 0;
    level.triangleCount = 0;
    for (const Aggregate& a : level.aggregates) {
        volume += a.measures.volume;
        area += a.measures.area;
        level.volumeOriginal += a.volumeOriginal;
        level.volumeHull += a.volumeHull;
        level.triangleCount += a.meshInCache ? a.meshInCache->triangleCount : a.indices.size() / 3;
    }
    level.measures = detail::measuresOf(volume, area);
}

void addTimings(Hierarchy3D& out, const Hierarchy3D& part) {
    for (const auto& [stage, seconds] : part.timings) {
        auto it = std::find_if(out.timings.begin(), out.timings.end(), [&](const auto& t) { return t.first == stage; });
        if (it == out.timings.end()) out.timings.emplace_back(stage, seconds);
        else it->second += seconds;
    }
}

/// What a tiled bake works out from the whole world before any piece (TiledBaker::layOut).
struct WorldLayout {
    std::vector<std::array<double, 6>> boxes;
    std::vector<char> usable, support;
    int axes[2] = {0, 1};
    double origin[2] = {0, 0};
    double size = 0;
    double tolerance = 0;
    double diagonal = 0;                            ///< the whole scene's, as the untiled bake measures it
    std::vector<uint32_t> cellOf;                   ///< per object: its cell (row-major), aggregated objects only
    std::map<uint32_t, std::vector<uint32_t>> cells;  ///< cell -> its objects, ascending
    std::vector<uint32_t> unusable;                 ///< objects with no finite triangle
};

class TiledBaker {
public:
    TiledBaker(const std::vector<InputObject>& objects, const Settings3D& settings, const TiledBakeOptions& options,
               Hierarchy3D& out, TiledBakeReport& report)
        : objects_(objects), settings_(settings), options_(options), out_(out), report_(report) {}

    bool run(double tileSize);

private:
    const std::vector<InputObject>& objects_;
    const Settings3D& settings_;
    const TiledBakeOptions& options_;
    Hierarchy3D& out_;
    TiledBakeReport& report_;
    WorldLayout world_;                              ///< what layOut works out (or reuseLayout finds)
    bool keepOut_ = false;                           ///< the piece just baked is not to be cached

    void findSupport();
    void assignCells();
    /// Support surfaces, the grid and the cells; false when the world is to be baked untiled.
    bool layOut(double tileSize);
    /// The layout of options_.layout when it was made for these objects, settings and tile size.
    bool reuseLayout(double tileSize);
    void keepLayout(double tileSize) const;
    Settings3D cellSettings(const std::vector<double>& deltas) const;
    std::vector<InputObject> cellObjects(const std::vector<uint32_t>& ids) const;
    bool automaticCellDeltas(std::vector<double>& deltas);
    bool fail(const Hierarchy3D& part, const std::string& where);

    // Pieces (cell graphs, cells, parent cells) and the cache (TileCache, TileTask).
    using Kind = TileTask::Kind;
    bool caching() const { return options_.cache && options_.cache->load && options_.cache->store && !settings_.customFunction; }
    bool isTask(Kind k) const { return options_.task.kind == k; }
    /// Aggregates' meshes are left in the cache (TiledBakeOptions::leanMeshes).
    bool lean() const { return options_.leanMeshes && isTask(Kind::Assemble) && caching(); }
    /// Whether this run needs cell `cell` (its graph, its levels).
    bool needCell(uint32_t cell) const;
    std::string cellKey(char kind, const std::vector<uint32_t>& ids, const Settings3D& settings) const;
    /// The piece `key` from the cache, or baked by `bake` when `mayBake` (and then stored).
    bool obtain(const std::string& key, const std::string& name, bool mayBake,
                const std::function<bool(Hierarchy3D&)>& bake, Hierarchy3D& part, size_t& baked, size_t& loaded);
};

/// Layout and meaning of the pieces' cache entries: a new tag never reads old ones. Change it
/// whenever what a piece bakes can change for the same input (any stage of a cell's or a
/// parent's bake, the wraps of a parent's inputs included), so that no stale piece is read.
void hashSettings(detail::ContentHash& h, const Settings3D& s) {
    h.text("aggrelod tile piece 5");
    h.u64(uint64_t(s.function));
    h.u64(uint64_t(s.distance));
    h.f64(s.touchTolerance);
    h.u64(s.computeHullBaseline);
    h.u64(s.computeConstantBaseline);
    h.u64(uint64_t(s.solidify));
    h.f64(s.wrapOffset);
    h.u64(uint64_t(s.automaticLevelCount));
    h.values(s.deltas);
}

bool TiledBaker::needCell(uint32_t cell) const {
    const TileTask& t = options_.task;
    switch (t.kind) {
    case Kind::Everything:
    case Kind::Assemble: return true;
    case Kind::Plan: return false;
    case Kind::Graph:
    case Kind::Cell: return cell == t.cell;
    case Kind::Parent:
        return ((cell / report_.columns) >> t.level) == t.row && ((cell % report_.columns) >> t.level) == t.column;
    }
    return false;
}

std::string TiledBaker::cellKey(char kind, const std::vector<uint32_t>& ids, const Settings3D& settings) const {
    detail::ContentHash h;
    h.bytes(&kind, 1);
    hashSettings(h, settings);
    h.u64(ids.size());
    for (uint32_t i : ids) {
        const InputObject& o = objects_[i];
        h.text(o.name);
        h.u64(o.id);
        h.values(o.positions);
        h.values(o.indices);
        h.values(o.triangleColors);
    }
    return h.hex();
}

bool TiledBaker::obtain(const std::string& key, const std::string& name, bool mayBake,
                        const std::function<bool(Hierarchy3D&)>& bake, Hierarchy3D& part, size_t& baked, size_t& loaded) {
    if (caching()) {
        std::vector<uint8_t> bytes;
        if (options_.cache->load(key, bytes) && detail::deserializeHierarchy(bytes, part)) {
            part.timings.clear();  // not spent in this run
            ++loaded;
            return true;
        }
    }
    if (!mayBake) {
        diag(out_, Diagnostic::Severity::Error, "", "the tile cache holds no result for " + name + " (entry " + key +
                                                        "): bake that piece first");
        return false;
    }
    keepOut_ = false;
    if (!bake(part)) return fail(part, name);
    ++baked;
    if (caching() && !keepOut_) {
        std::vector<uint8_t> bytes;
        detail::serializeHierarchy(part, bytes);
        if (!options_.cache->store(key, bytes))
            diag(out_, Diagnostic::Severity::Warning, "", "could not store " + name + " in the tile cache");
    }
    return true;
}

void TiledBaker::findSupport() {
    const size_t n = objects_.size();
    world_.boxes.resize(n);
    world_.usable.assign(n, 0);
    std::vector<const double*> bounds(n, nullptr);
    for (size_t i = 0; i < n; ++i)
        if (objectBox(objects_[i], world_.boxes[i].data())) {
            world_.usable[i] = 1;
            bounds[i] = world_.boxes[i].data();
        } else {
            world_.unusable.push_back(static_cast<uint32_t>(i));
        }
    world_.support = detail::findSupportSurfaces(bounds, settings_);
}

void TiledBaker::assignCells() {
    std::vector<uint32_t> ids;
    for (uint32_t i = 0; i < objects_.size(); ++i)
        if (world_.usable[i] && !world_.support[i]) ids.push_back(i);
    world_.cellOf.assign(objects_.size(), UINT32_MAX);
    const auto cellAt = [&](const double* box) {
        size_t c[2];
        for (int j = 0; j < 2; ++j) {
            const double centre = 0.5 * (box[world_.axes[j]] + box[3 + world_.axes[j]]);
            const double f = std::floor((centre - world_.origin[j]) / world_.size);
            const size_t limit = j == 0 ? report_.columns : report_.rows;
            c[j] = f <= 0 ? 0 : std::min(limit - 1, static_cast<size_t>(f));
        }
        return static_cast<uint32_t>(c[1] * report_.columns + c[0]);
    };
    // Clusters: boxes within the cells' top delta of each other, chained.
    DisjointSets sets(ids.size());
    for (auto [a, b] : detail::overlappingPairs(ids.size(), [&](uint32_t k) { return world_.boxes[ids[k]].data(); },
                                                report_.cellTopDelta))
        sets.unite(a, b);
    std::map<uint32_t, std::vector<uint32_t>> clusters;  // root (smallest member) -> members, ascending
    for (uint32_t k = 0; k < ids.size(); ++k) clusters[sets.find(k)].push_back(k);
    report_.clusterCount = clusters.size();
    for (const auto& [root, members] : clusters) {
        double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
        for (uint32_t k : members)
            for (int j = 0; j < 2; ++j) {
                lo[j] = std::min(lo[j], world_.boxes[ids[k]][world_.axes[j]]);
                hi[j] = std::max(hi[j], world_.boxes[ids[k]][3 + world_.axes[j]]);
            }
        const bool split = hi[0] - lo[0] > world_.size || hi[1] - lo[1] > world_.size;
        if (split) {
            ++report_.splitClusterCount;
            report_.splitClusterObjects += members.size();
        }
        const uint32_t cell = cellAt(world_.boxes[ids[root]].data());
        for (uint32_t k : members) world_.cellOf[ids[k]] = split ? cellAt(world_.boxes[ids[k]].data()) : cell;
    }
    for (uint32_t i : ids) {
        world_.cells[world_.cellOf[i]].push_back(i);
        report_.cellTriangleCount += objects_[i].indices.size() / 3;
    }
    for (auto& [cell, members] : world_.cells) {
        std::sort(members.begin(), members.end());
        report_.largestCellObjects = std::max(report_.largestCellObjects, members.size());
    }
    report_.cellCount = world_.cells.size();
}

Settings3D TiledBaker::cellSettings(const std::vector<double>& deltas) const {
    Settings3D s = settings_;
    s.deltas = deltas;
    s.support = SupportDetection::None;
    s.supportObjects.clear();
    s.touchTolerance = world_.tolerance;  // the whole world's, not the cell's
    s.progress = nullptr;
    return s;
}

std::vector<InputObject> TiledBaker::cellObjects(const std::vector<uint32_t>& ids) const {
    std::vector<InputObject> cell;
    cell.reserve(ids.size());
    for (uint32_t i : ids) cell.push_back(objects_[i]);
    return cell;
}

bool TiledBaker::fail(const Hierarchy3D& part, const std::string& where) {
    for (Diagnostic d : part.diagnostics) {
        if (d.severity == Diagnostic::Severity::Error) d.message = where + ": " + d.message;
        out_.diagnostics.push_back(std::move(d));
    }
    return false;
}

// First pass for automatic thresholds: every cell's dendrogram, then the automatic rule
// (visibleDeltas of the untiled bake) on all their merges up to the cells' top delta.
bool TiledBaker::automaticCellDeltas(std::vector<double>& deltas) {
    std::vector<Merge> merges;
    size_t done = 0;
    for (const auto& [cell, ids] : world_.cells) {
        if (isTask(Kind::Graph) && cell != options_.task.cell) continue;  // the others are not this task's
        const Settings3D settings = cellSettings({});
        Hierarchy3D part;
        const auto bake = [&](Hierarchy3D& p) {
            const std::vector<InputObject> objects = cellObjects(ids);
            detail::Baker3D baker(objects, settings, p);
            baker.stopAfterGraph();
            if (!baker.run()) return false;
            p.diagnostics.clear();  // the cell's bake reports them again
            return true;
        };
        const bool mayBake = isTask(Kind::Everything) || isTask(Kind::Graph);
        if (!obtain(cellKey('g', ids, settings), "the graph of tile " + std::to_string(cell), mayBake, bake, part,
                    report_.graphsBaked, report_.graphsLoaded))
            return false;
        for (const Merge& m : part.merges)
            if (m.height <= report_.cellTopDelta) merges.push_back(m);
        addTimings(out_, part);
        if (settings_.progress) settings_.progress("tile graphs", double(++done) / double(world_.cells.size()));
    }
    if (isTask(Kind::Graph)) return true;
    std::sort(merges.begin(), merges.end(), [](const Merge& a, const Merge& b) { return a.height < b.height; });
    double box[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    for (const auto& [cell, ids] : world_.cells)
        for (uint32_t i : ids)
            for (int k = 0; k < 3; ++k) {
                box[k] = std::min(box[k], world_.boxes[i][k]);
                box[3 + k] = std::max(box[3 + k], world_.boxes[i][3 + k]);
            }
    const double diagonal = std::sqrt((box[3] - box[0]) * (box[3] - box[0]) + (box[4] - box[1]) * (box[4] - box[1]) +
                                      (box[5] - box[2]) * (box[5] - box[2]));
    std::vector<Merge> seen;
    for (const Merge& m : merges)
        if (m.height >= 1e-3 * diagonal) seen.push_back(m);
    if (seen.empty()) seen = merges;
    const int count = std::max(2, settings_.automaticLevelCount - report_.quadtreeDepth);
    deltas = automaticDeltas(seen, count - 1);
    if (!seen.empty() && seen.front().height > 0) deltas.insert(deltas.begin(), 0.5 * seen.front().height);
    for (double& d : deltas) d = std::min(d, report_.cellTopDelta);
    std::sort(deltas.begin(), deltas.end());
    deltas.erase(std::unique(deltas.begin(), deltas.end()), deltas.end());
    if (deltas.empty()) deltas.push_back(0.0);
    return true;
}

bool TiledBaker::layOut(double tileSize) {
    findSupport();
    world_.diagonal = detail::finiteDiagonal(objects_);  // as the untiled bake measures the scene
    world_.tolerance = settings_.touchTolerance >= 0 ? settings_.touchTolerance : 1e-6 * world_.diagonal;

    // The footprint of the aggregated objects and its two longest axes.
    double world[6] = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    size_t aggregated = 0;
    for (size_t i = 0; i < objects_.size(); ++i) {
        if (!world_.usable[i] || world_.support[i]) continue;
        ++aggregated;
        for (int k = 0; k < 3; ++k) {
            world[k] = std::min(world[k], world_.boxes[i][k]);
            world[3 + k] = std::max(world[3 + k], world_.boxes[i][3 + k]);
        }
    }
    if (aggregated == 0) return false;
    int axes[3] = {0, 1, 2};
    std::stable_sort(axes, axes + 3, [&](int x, int y) { return world[3 + x] - world[x] > world[3 + y] - world[y]; });
    world_.axes[0] = axes[0];
    world_.axes[1] = axes[1];
    const double extent[2] = {world[3 + world_.axes[0]] - world[world_.axes[0]], world[3 + world_.axes[1]] - world[world_.axes[1]]};
    if (tileSize <= 0) {
        if (aggregated <= 2 * kAutomaticTileObjects) return false;
        const double area = std::max(extent[0], 1e-300) * std::max(extent[1], extent[0] * 1e-3);
        tileSize = std::sqrt(area * double(kAutomaticTileObjects) / double(aggregated));
    }
    world_.size = tileSize;
    report_.tileSize = tileSize;
    report_.cellTopDelta = tileSize / 8;
    for (int j = 0; j < 2; ++j) world_.origin[j] = world[world_.axes[j]];
    const auto cellsAlong = [&](double e) {
        const double c = std::ceil(e / tileSize);
        return c < 1 ? size_t(1) : c > 65536 ? size_t(65536) : static_cast<size_t>(c);
    };
    report_.columns = cellsAlong(extent[0]);
    report_.rows = cellsAlong(extent[1]);
    if (report_.columns * report_.rows == 1) return false;
    report_.tiled = true;
    while ((size_t(1) << report_.quadtreeDepth) < std::max(report_.columns, report_.rows)) ++report_.quadtreeDepth;

    assignCells();
    if (!world_.unusable.empty()) {  // reported (and left out) by the first cell's bake
        std::vector<uint32_t>& first = world_.cells.begin()->second;
        first.insert(first.end(), world_.unusable.begin(), world_.unusable.end());
        std::sort(first.begin(), first.end());
    }
    return true;
}

std::string layoutKey(const Settings3D& settings) {
    detail::ContentHash h;
    hashSettings(h, settings);
    h.u64(uint64_t(settings.support));
    h.values(settings.supportObjects);
    return h.hex();
}

}  // namespace

struct TiledLayout {
    // What it was made for.
    const InputObject* objects = nullptr;
    size_t objectCount = 0;
    double tileSize = 0;
    std::string settings;  ///< layoutKey
    WorldLayout world;
    TiledBakeReport report;  ///< as layOut leaves it
};

std::shared_ptr<TiledLayout> newTiledLayout() { return std::make_shared<TiledLayout>(); }

namespace {

bool TiledBaker::reuseLayout(double tileSize) {
    const TiledLayout* kept = options_.layout.get();
    if (!kept || kept->objects != objects_.data() || kept->objectCount != objects_.size() || kept->tileSize != tileSize ||
        kept->settings != layoutKey(settings_))
        return false;
    world_ = kept->world;
    report_ = kept->report;
    return true;
}

void TiledBaker::keepLayout(double tileSize) const {
    TiledLayout* kept = options_.layout.get();
    if (!kept) return;
    *kept = TiledLayout{objects_.data(), objects_.size(), tileSize, layoutKey(settings_), world_, report_};
}

bool TiledBaker::run(double tileSize) {
    if (!reuseLayout(tileSize)) {
        if (!layOut(tileSize)) {
            if (lean()) {  // nothing in the cache to assemble: the caller bakes the world whole
                diag(out_, Diagnostic::Severity::Error, "", "the world fits one tile: there are no pieces to assemble");
                return false;
            }
            return buildHierarchy3D(objects_, settings_, out_);
        }
        keepLayout(tileSize);
    }

    // Thresholds: the cells' and those of each quadtree level j (delta <= S / 8 * 2^j).
    std::vector<double> cellDeltas;
    std::vector<std::vector<double>> parentDeltas(size_t(report_.quadtreeDepth) + 1);
    if (!settings_.deltas.empty()) {
        for (double d : settings_.deltas) {
            if (d <= report_.cellTopDelta) {
                cellDeltas.push_back(d);
                continue;
            }
            int j = 1;
            while (j < report_.quadtreeDepth && d > report_.cellTopDelta * std::ldexp(1.0, j)) ++j;
            parentDeltas[size_t(j)].push_back(d);
        }
        if (cellDeltas.empty()) {
            diag(out_, Diagnostic::Severity::Error, "",
                 "a tiled bake with tile size " + fmt(tileSize) + " needs a delta of at most " +
                     fmt(report_.cellTopDelta) + " (an eighth of the tile size) for the cells' levels");
            return false;
        }
    }
    report_.automaticDeltas = settings_.deltas.empty();
    if (isTask(Kind::Plan)) {  // the pieces, for running them apart (aggrelod-farm)
        report_.parents.assign(size_t(report_.quadtreeDepth) + 1, {});
        for (const auto& [cell, ids] : world_.cells) report_.cells.push_back(cell);
        for (int j = 1; j <= report_.quadtreeDepth; ++j) {
            if (!report_.automaticDeltas && parentDeltas[size_t(j)].empty()) continue;
            auto& list = report_.parents[size_t(j)];
            for (uint32_t cell : report_.cells)
                list.emplace_back((cell / report_.columns) >> j, (cell % report_.columns) >> j);
            std::sort(list.begin(), list.end());
            list.erase(std::unique(list.begin(), list.end()), list.end());
        }
        return true;
    }
    if (report_.automaticDeltas) {
        if (!automaticCellDeltas(cellDeltas)) return false;
        if (isTask(Kind::Graph)) return true;
        for (int j = 1; j <= report_.quadtreeDepth; ++j) parentDeltas[size_t(j)].push_back(report_.cellTopDelta * std::ldexp(1.0, j));
    } else if (isTask(Kind::Graph)) {
        return true;  // explicit thresholds: no graph pass
    }

    // Cells.
    std::vector<Level> levels(cellDeltas.size());
    for (size_t k = 0; k < levels.size(); ++k) levels[k].delta = cellDeltas[k];
    std::vector<SolidReport> solids;
    out_.objectModel.assign(objects_.size(), UINT32_MAX);
    std::vector<char> leftOut(objects_.size(), 0);
    size_t done = 0;
    bool hasConstant = true;
    for (const auto& [cell, ids] : world_.cells) {
        if (!needCell(cell)) continue;
        const Settings3D settings = cellSettings(cellDeltas);
        Hierarchy3D part;
        const auto bake = [&](Hierarchy3D& p) { return buildHierarchy3D(cellObjects(ids), settings, p); };
        const bool mayBake = isTask(Kind::Everything) || isTask(Kind::Cell);
        const std::string key = cellKey('c', ids, settings);
        if (!obtain(key, "tile " + std::to_string(cell), mayBake, bake, part, report_.cellsBaked, report_.cellsLoaded))
            return false;
        if (part.levels.size() != levels.size()) {
            diag(out_, Diagnostic::Severity::Error, "", "tile " + std::to_string(cell) + ": the bake made " +
                 std::to_string(part.levels.size()) + " levels where " + std::to_string(levels.size()) + " were asked");
            return false;
        }
        for (size_t k = 0; k < levels.size(); ++k) {
            hasConstant = hasConstant && part.levels[k].hasVolumeConstant;
            levels[k].volumeConstant += part.levels[k].volumeConstant;
            for (size_t g = 0; g < part.levels[k].aggregates.size(); ++g) {
                Aggregate& a = part.levels[k].aggregates[g];
                // The top level's meshes name the parent pieces: they go once those are read.
                if (lean()) detail::leaveMeshInCache(a, key, uint32_t(k), uint32_t(g), k + 1 == levels.size());
                for (uint32_t& o : a.sourceObjects) o = ids[o];
                levels[k].aggregates.push_back(std::move(a));
            }
        }
        for (size_t o = 0; o < ids.size(); ++o)
            if (part.objectModel[o] != UINT32_MAX) out_.objectModel[ids[o]] = static_cast<uint32_t>(out_.modelCount + part.objectModel[o]);
        for (Merge m : part.merges) {
            m.modelA += static_cast<uint32_t>(out_.modelCount);
            m.modelB += static_cast<uint32_t>(out_.modelCount);
            out_.merges.push_back(m);
        }
        out_.modelCount += part.modelCount;
        for (SolidReport& r : part.solids) {
            for (uint32_t& o : r.objects) o = ids[o];
            solids.push_back(std::move(r));
        }
        for (uint32_t o : part.leftOutObjects) leftOut[ids[o]] = 1;
        for (Diagnostic& d : part.diagnostics) out_.diagnostics.push_back(std::move(d));
        addTimings(out_, part);
        out_.tetrahedronCount += part.tetrahedronCount;
        out_.inputTriangleCount += part.inputTriangleCount;
        out_.originals.volume += part.originals.volume;
        out_.originals.area += part.originals.area;
        if (settings_.progress) settings_.progress("tiles", double(++done) / double(world_.cells.size()));
    }
    for (Level& level : levels) level.hasVolumeConstant = hasConstant;
    if (isTask(Kind::Cell)) return true;

    // Parent cells, quadtree level by level: the coarsest aggregates so far are their objects.
    const auto anchorColumnRow = [&](const Aggregate& a) {
        const uint32_t cell = world_.cellOf[a.sourceObjects.front()];
        return std::make_pair(cell % report_.columns, cell / report_.columns);
    };
    for (int j = 1; j <= report_.quadtreeDepth; ++j) {
        const std::vector<double>& deltas = parentDeltas[size_t(j)];
        if (deltas.empty()) continue;
        const Level& top = levels.back();
        std::map<std::pair<size_t, size_t>, std::vector<uint32_t>> parents;  // (row, column) -> top aggregates
        for (uint32_t g = 0; g < top.aggregates.size(); ++g) {
            const auto [column, row] = anchorColumnRow(top.aggregates[g]);
            parents[{row >> j, column >> j}].push_back(g);
        }
        std::vector<Level> added(deltas.size());
        for (size_t k = 0; k < added.size(); ++k) added[k].delta = deltas[k];
        done = 0;
        for (const auto& [where, inputs] : parents) {
            std::vector<char> passed(inputs.size(), inputs.size() < 2);
            if (inputs.size() >= 2) {
                // The inputs: the coarsest aggregates so far, each wrapped (CGAL alpha wrap) at a
                // scale of this level's delta. A wrap contains its aggregate, which contains
                // its originals; it is light and clean where the exact aggregate carries every
                // original face and the fine fill, which is what bounds a parent's
                // triangulation. The proxies stage certifies every error against the originals.
                const double alpha = deltas.front() / 8, offset = deltas.front() / 64;
                std::vector<InputObject> objects(inputs.size());
                for (size_t i = 0; i < inputs.size(); ++i) {
                    const Aggregate& a = top.aggregates[inputs[i]];
                    objects[i].name = "aggregate of " + objects_[a.sourceObjects.front()].name +
                                      (a.sourceObjects.size() > 1 ? " (+" + std::to_string(a.sourceObjects.size() - 1) + ")" : "");
                    objects[i].id = static_cast<uint32_t>(i);
                }
                const auto wrapInputs = [&] {  // only when the piece is baked: the key is of the aggregates
                    detail::parallelFor(inputs.size(), settings_.threadCount, [&](size_t i) {
                        const Aggregate& a = top.aggregates[inputs[i]];
                        std::string ignored;
                        if (!detail::alphaWrap(a.positions, a.indices, alpha, offset, objects[i].positions,
                                               objects[i].indices, ignored)) {
                            objects[i].positions = a.positions;  // the exact aggregate then
                            objects[i].indices = a.indices;
                            objects[i].triangleColors = a.faceColors;
                        }
                    });
                };
                Settings3D settings = cellSettings(deltas);
                Hierarchy3D part;
                const std::string name = "parent tile " + std::to_string(j) + ":" + std::to_string(where.first) + "," +
                                         std::to_string(where.second);
                const bool target = isTask(Kind::Parent) && j == options_.task.level && where.first == options_.task.row &&
                                    where.second == options_.task.column;
                detail::ContentHash key;
                key.bytes("p", 1);
                hashSettings(key, settings);
                for (size_t i = 0; i < inputs.size(); ++i) {
                    const Aggregate& a = top.aggregates[inputs[i]];
                    key.text(objects[i].name);
                    key.values(a.sourceObjects);
                    key.values(a.positions);
                    key.values(a.indices);
                    key.values(a.faceColors);
                }
                // Aggregates of neighbouring cells were shaped apart and may nearly touch, which
                // TetGen can refuse: then once more with those closer than a thousandth of the
                // level's delta as one model (they join at this level anyway), and if that fails
                // too the inputs pass through unchanged, with a warning.
                const auto bake = [&](Hierarchy3D& p) {
                    wrapInputs();
                    if (buildHierarchy3D(objects, settings, p)) return true;
                    Settings3D closer = settings;
                    closer.touchTolerance = std::max(world_.tolerance, 1e-3 * deltas.front());
                    std::vector<Diagnostic> first = p.diagnostics;
                    if (buildHierarchy3D(objects, closer, p)) return true;
                    p = Hierarchy3D{};
                    p.leftOutObjects.resize(objects.size());
                    std::iota(p.leftOutObjects.begin(), p.leftOutObjects.end(), 0u);
                    std::string why;
                    for (const Diagnostic& d : first)
                        if (d.severity == Diagnostic::Severity::Error) why = d.message;
                    diag(p, Diagnostic::Severity::Warning, "", name + " not aggregated (" + why + "): its " +
                                                                  std::to_string(objects.size()) + " inputs pass through");
                    keepOut_ = true;  // a later run tries again
                    return true;
                };
                if (!obtain(key.hex(), name, isTask(Kind::Everything) || target, bake, part, report_.parentsBaked,
                            report_.parentsLoaded))
                    return false;
                ++report_.parentBakeCount;
                if (target) return true;
                for (uint32_t o : part.leftOutObjects) passed[o] = 1;
                for (size_t k = 0; k < added.size() && k < part.levels.size(); ++k)
                    for (size_t g = 0; g < part.levels[k].aggregates.size(); ++g) {
                        Aggregate& a = part.levels[k].aggregates[g];
                        if (lean()) detail::leaveMeshInCache(a, key.hex(), uint32_t(k), uint32_t(g), true);
                        std::vector<uint32_t> sources;
                        double volumeOriginal = 0;
                        for (uint32_t i : a.sourceObjects) {
                            const Aggregate& below = top.aggregates[inputs[i]];
                            sources.insert(sources.end(), below.sourceObjects.begin(), below.sourceObjects.end());
                            volumeOriginal += below.volumeOriginal;
                        }
                        std::sort(sources.begin(), sources.end());
                        a.sourceObjects = std::move(sources);
                        a.volumeOriginal = volumeOriginal;
                        added[k].aggregates.push_back(std::move(a));
                    }
                for (Diagnostic& d : part.diagnostics)
                    if (d.severity != Diagnostic::Severity::Note) out_.diagnostics.push_back(std::move(d));
                addTimings(out_, part);
                out_.tetrahedronCount += part.tetrahedronCount;
            }
            for (size_t i = 0; i < inputs.size(); ++i)
                if (passed[i])
                    for (Level& level : added) level.aggregates.push_back(top.aggregates[inputs[i]]);
            if (settings_.progress)
                settings_.progress("parent tiles", (double(j - 1) + double(++done) / double(parents.size())) / report_.quadtreeDepth);
        }
        for (Level& level : added) {
            level.hasVolumeConstant = false;
            levels.push_back(std::move(level));
        }
        if (lean())  // all but the new top level, whose meshes name the next quadtree level's pieces
            for (size_t k = 0; k + 1 < levels.size(); ++k)
                for (Aggregate& a : levels[k].aggregates) detail::dropMeshInCache(a);
        if (isTask(Kind::Parent) && j == options_.task.level) return true;  // its target had one input: nothing to bake
    }

    for (Level& level : levels) {
        if (lean())
            for (Aggregate& a : level.aggregates) detail::dropMeshInCache(a);
        std::sort(level.aggregates.begin(), level.aggregates.end(),
                  [](const Aggregate& a, const Aggregate& b) { return a.sourceObjects.front() < b.sourceObjects.front(); });
        const double constant = level.volumeConstant;
        totalLevel(level);
        level.volumeConstant = level.hasVolumeConstant ? constant : 0;
    }
    out_.levels = std::move(levels);
    std::stable_sort(out_.merges.begin(), out_.merges.end(), [](const Merge& a, const Merge& b) { return a.height < b.height; });
    std::sort(solids.begin(), solids.end(), [](const SolidReport& a, const SolidReport& b) { return a.objects.front() < b.objects.front(); });
    out_.solids = std::move(solids);
    for (uint32_t i = 0; i < objects_.size(); ++i) {
        if (world_.support[i]) {  // counted in the originals as the untiled bake counts them
            detail::PreparedObject prepared;
            detail::prepareObject(objects_[i], 1e-14 * world_.diagonal * world_.diagonal, prepared, out_.diagnostics);
            out_.supportObjects.push_back(i);
            out_.inputTriangleCount += prepared.triangles.size() / 3;
            out_.originals.volume += prepared.volume;
            out_.originals.area += prepared.area;
        }
        if (leftOut[i]) out_.leftOutObjects.push_back(i);
    }
    out_.originals = detail::measuresOf(out_.originals.volume, out_.originals.area);
    if (!out_.supportObjects.empty())
        diag(out_, Diagnostic::Severity::Warning, detail::objectNames(objects_, out_.supportObjects, 20),
             std::string(settings_.support == SupportDetection::Given ? "support surfaces as asked"
                                                                      : "support surfaces (span the scene and meet most objects)") +
                 ": kept out of aggregation and passed through unchanged (--support none aggregates them)");
    std::string note = "tiled bake: tile size " + fmt(tileSize) + ", " + std::to_string(report_.columns) + " x " +
                       std::to_string(report_.rows) + " cells, " + std::to_string(report_.cellCount) +
                       " with objects (largest " + std::to_string(report_.largestCellObjects) + "), levels up to delta " +
                       fmt(report_.cellTopDelta) + " baked per cell, " + std::to_string(report_.parentBakeCount) +
                       " parent cells baked over " + std::to_string(report_.quadtreeDepth) + " quadtree levels";
    if (report_.splitClusterCount)
        note += "; " + std::to_string(report_.splitClusterCount) + " of " + std::to_string(report_.clusterCount) +
                " clusters wider than a tile were split at cell borders (" + std::to_string(report_.splitClusterObjects) +
                " objects): groups there may differ from an untiled bake";
    diag(out_, Diagnostic::Severity::Note, "", note);
    return true;
}

}  // namespace

bool buildTiledHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings, double tileSize,
                           Hierarchy3D& out, TiledBakeReport* report) {
    TiledBakeOptions options;
    options.tileSize = tileSize;
    return buildTiledHierarchy3D(objects, settings, options, out, report);
}

bool readAggregateMeshes(const TileCache& cache, const std::vector<const Aggregate*>& lean, std::vector<Aggregate>& out,
                         int threads, std::string& error) {
    out.assign(lean.size(), Aggregate{});
    std::vector<Aggregate*> into(lean.size());
    for (size_t j = 0; j < lean.size(); ++j) into[j] = &out[j];
    return detail::reloadMeshes(cache, lean, into, threads, error);
}

bool buildTiledHierarchy3D(const std::vector<InputObject>& objects, const Settings3D& settings,
                           const TiledBakeOptions& options, Hierarchy3D& out, TiledBakeReport* report) {
    const double tileSize = options.tileSize;
    out = Hierarchy3D{};
    TiledBakeReport local;
    TiledBakeReport& r = report ? *report : local;
    r = TiledBakeReport{};
    if (std::string problem; !validThresholds(settings.deltas, problem)) {
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", problem});
        return false;
    }
    if (!(tileSize >= 0) || !std::isfinite(tileSize)) {
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", "tile size " + fmt(tileSize) +
                                                                                  " is not a finite number >= 0"});
        return false;
    }
    try {
        TiledBaker baker(objects, settings, options, out, r);
        return baker.run(tileSize);
    } catch (const std::exception& e) {
        out.diagnostics.push_back(Diagnostic{Diagnostic::Severity::Error, "", std::string("internal error: ") + e.what()});
        return false;
    }
}

}  // namespace aggrelod
