// SPDX-License-Identifier: AGPL-3.0-or-later
// 2D aggregation (paper Sections 3-4 in 2D): the acceptance properties on the five
// generated environments and on real data, with GEOS as the independent referee.
#include "geos_support.h"
#include "test_support.h"

#include "geo_io.h"

#include <aggrelod/aggregate2d.h>
#include <aggrelod/environments2d.h>
#include <aggrelod/samples.h>

#include <cmath>

#include <gtest/gtest.h>

using namespace aggrelod;
using namespace aggrelod::testing;

namespace {

/// The input polygons that are valid on their own (invalid ones are dropped by the reader
/// with a diagnostic; GEOS and our check agree on which, see RealIslandsAndCountries).
std::vector<Polygon2D> inputPolygons(const std::vector<Feature2D>& features, const Hierarchy2D& h) {
    std::vector<Polygon2D> out;
    for (size_t f = 0; f < features.size(); ++f)
        if (h.featureModel[f] >= 0)
            for (const Polygon2D& p : features[f].polygons)
                if (geosValidity({p}) == "Valid Geometry") out.push_back(p);
    return out;
}

std::vector<Polygon2D> levelPolygons(const Level2D& level) {
    std::vector<Polygon2D> out;
    for (const Aggregate2D& a : level.aggregates) out.insert(out.end(), a.polygons.begin(), a.polygons.end());
    return out;
}

/// Every aggregate OGC-valid (GEOS), the level contains its inputs, group count never rises.
void expectValidAndContaining(const std::vector<Feature2D>& features, const Hierarchy2D& h, const std::string& label) {
    const std::vector<Polygon2D> inputs = inputPolygons(features, h);
    const double inputArea = geosUnionArea(inputs);
    ASSERT_GT(inputArea, 0) << label;
    size_t previousGroups = SIZE_MAX;
    for (size_t l = 0; l < h.levels.size(); ++l) {
        const Level2D& level = h.levels[l];
        const std::string where = label + " level " + std::to_string(l) + " delta " + std::to_string(level.delta);
        EXPECT_LE(level.aggregates.size(), previousGroups) << where << ": group count rose";
        previousGroups = level.aggregates.size();
        size_t invalid = 0;
        for (size_t g = 0; g < level.aggregates.size(); ++g) {
            const Aggregate2D& a = level.aggregates[g];
            EXPECT_FALSE(a.polygons.empty()) << where << ": aggregate " << g << " has no polygon";
            for (const Polygon2D& p : a.polygons) {
                EXPECT_GT(p.exterior.size(), 5u);
                for (const auto& hole : p.holes) EXPECT_GT(hole.size(), 5u);
            }
            const std::string validity = geosValidity(a.polygons);
            if (validity != "Valid Geometry" && invalid++ < 5)
                ADD_FAILURE() << where << ": aggregate " << g << " is not OGC-valid: " << validity;
        }
        EXPECT_EQ(invalid, 0u) << where;
        const double uncovered = geosUncoveredArea(inputs, levelPolygons(level));
        EXPECT_LE(uncovered, 1e-9 * inputArea) << where << ": output does not contain its inputs";
        EXPECT_GE(level.measures.area, inputArea * (1 - 1e-9)) << where;
    }
}

/// Normalised area adaptive <= constant <= hull at every level.
void expectAreaOrder(const Hierarchy2D& h, const std::string& label) {
    for (size_t l = 0; l < h.levels.size(); ++l) {
        const Level2D& level = h.levels[l];
        const double tol = 1e-9 * h.originals.area;
        EXPECT_LE(level.adaptive.area, level.constant.area + tol) << label << " level " << l;
        EXPECT_LE(level.constant.area, level.hull.area + tol) << label << " level " << l;
        EXPECT_GE(level.adaptive.area, h.originals.area * (1 - 1e-9)) << label << " level " << l;
    }
}

std::vector<Feature2D> readShared(const std::string& name) {
    io::GeoReadResult r;
    std::string error;
    EXPECT_TRUE(io::readPolygonFile(sharedData("2d/" + name).string(), r, error)) << error;
    return r.features;
}

}  // namespace

TEST(Aggregate2D, EnvironmentsAreValidContainingAndOrdered) {
    for (samples::Environment2D env : samples::allEnvironments2D()) {
        const std::string name = samples::environmentName(env);
        const std::vector<Feature2D> features = samples::makeEnvironment2D(env, 1);
        ASSERT_GT(features.size(), 10u) << name;
        Settings2D settings;
        settings.automaticLevelCount = 6;
        Hierarchy2D h;
        ASSERT_TRUE(buildHierarchy2D(features, settings, h)) << name;
        for (const Diagnostic& d : h.diagnostics)
            EXPECT_NE(d.severity, Diagnostic::Severity::Error) << name << ": " << d.object << ": " << d.message;
        // Generated polygons never touch: one model per feature.
        EXPECT_EQ(h.modelCount, features.size()) << name;
        EXPECT_GE(h.levels.size(), 4u) << name;
        EXPECT_EQ(h.levels.back().aggregates.size(), 1u) << name << ": the last automatic level joins everything";
        expectValidAndContaining(features, h, name);
        expectAreaOrder(h, name);
        // Constant function output too.
        settings.function = AggregateFunctionKind::Constant;
        Hierarchy2D hc;
        ASSERT_TRUE(buildHierarchy2D(features, settings, hc)) << name;
        expectValidAndContaining(features, hc, name + " constant");
        for (size_t l = 0; l < h.levels.size(); ++l)
            EXPECT_NEAR(hc.levels[l].measures.area, h.levels[l].constant.area, 1e-9 * h.originals.area) << name;
    }
}

TEST(Aggregate2D, GroupsFollowTheDendrogram) {
    const std::vector<Feature2D> features = samples::makeEnvironment2D(samples::Environment2D::Scatter, 3);
    Settings2D settings;
    settings.deltas = {0, 2, 4, 8, 16, 1000};
    Hierarchy2D h;
    ASSERT_TRUE(buildHierarchy2D(features, settings, h));
    ASSERT_EQ(h.levels.size(), 6u);
    EXPECT_EQ(h.levels[0].aggregates.size(), features.size()) << "delta 0 joins nothing";
    for (size_t l = 0; l < h.levels.size(); ++l) {
        size_t joined = 0;
        for (const Merge& m : h.merges) joined += m.height < h.levels[l].delta;
        EXPECT_EQ(h.levels[l].aggregates.size(), features.size() - joined) << "level " << l;
    }
    // At delta 0 the output is the input exactly (no fill anywhere).
    EXPECT_NEAR(h.levels[0].measures.area, h.originals.area, 1e-9 * h.originals.area);
    EXPECT_NEAR(h.levels[0].measures.perimeter, h.originals.perimeter, 1e-9 * h.originals.perimeter);
    // Joined models come out connected: one polygon, or polygons touching at points where
    // the only connection is a vertex (the two are then separate polygons, still valid).
    for (const Level2D& level : h.levels)
        for (const Aggregate2D& a : level.aggregates)
            EXPECT_TRUE(geosConnected(a.polygons)) << "delta " << level.delta << ": aggregate of "
                                                   << a.sourceFeatures.size() << " features falls apart";
}

TEST(Aggregate2D, HolesTouchingPartsAndDeterminism) {
    // A ring-shaped building (square with a square hole) with a small block inside the hole,
    // and two blocks that touch the ring at a vertex.
    std::vector<Feature2D> features(5);
    features[0].name = "ring";
    features[0].polygons = {Polygon2D{{0, 0, 10, 0, 10, 10, 0, 10}, {{3, 3, 3, 7, 7, 7, 7, 3}}}};
    features[1].name = "inner";
    features[1].polygons = {Polygon2D{{4.5, 4.5, 5.5, 4.5, 5.5, 5.5, 4.5, 5.5}, {}}};
    features[2].name = "corner";
    features[2].polygons = {Polygon2D{{10, 10, 12, 10, 12, 12, 10, 12}, {}}};
    features[3].name = "far";
    features[3].polygons = {Polygon2D{{20, 0, 22, 0, 22, 2, 20, 2}, {}}};
    features[4].name = "notched";  // a hole touching its exterior at one vertex (OGC-valid)
    features[4].polygons = {Polygon2D{{30, 0, 34, 0, 34, 4, 30, 4}, {{32, 0, 31, 1, 33, 1}}}};
    for (uint32_t i = 0; i < 5; ++i) features[i].id = i;
    Settings2D settings;
    settings.deltas = {0, 1, 2, 9};
    Hierarchy2D h;
    ASSERT_TRUE(buildHierarchy2D(features, settings, h));
    EXPECT_EQ(h.modelCount, 4u) << "ring and corner touch: one model";
    bool noted = false;
    for (const Diagnostic& d : h.diagnostics) noted |= d.message.find("touch or overlap") != std::string::npos;
    EXPECT_TRUE(noted);
    expectValidAndContaining(features, h, "holes");
    // Delta 0: the hole stays a hole (with the inner block as its own aggregate).
    ASSERT_EQ(h.levels[0].aggregates.size(), 4u);
    const Aggregate2D& ring = h.levels[0].aggregates[0];
    size_t holes = 0;
    for (const Polygon2D& p : ring.polygons) holes += p.holes.size();
    EXPECT_EQ(holes, 1u);
    // Delta 2 joins the inner block (1.5 away) with the ring: still valid (checked above).
    EXPECT_EQ(h.levels[2].aggregates.size(), 3u);
    // The touching hole is kept at delta 0.
    size_t notchHoles = 0;
    for (const Polygon2D& p : h.levels[0].aggregates[3].polygons) notchHoles += p.holes.size();
    EXPECT_EQ(notchHoles, 1u);
    // Same input, same output, byte for byte.
    Hierarchy2D again;
    ASSERT_TRUE(buildHierarchy2D(features, settings, again));
    EXPECT_EQ(io::formatLevelsGeoJson(h, features), io::formatLevelsGeoJson(again, features));
}

TEST(Aggregate2D, RealIslandsAndCountries) {
    for (const std::string& file : {std::string("land50m_islands.wkt"), std::string("naturalearth_lowres.wkt")}) {
        const std::vector<Feature2D> features = readShared(file);
        ASSERT_GT(features.size(), 100u) << file;
        Settings2D settings;
        settings.deltas = {0.05, 0.5, 3};
        Hierarchy2D h;
        ASSERT_TRUE(buildHierarchy2D(features, settings, h)) << file;
        expectValidAndContaining(features, h, file);
        expectAreaOrder(h, file);
        // Polygons our check drops are exactly those GEOS finds invalid.
        size_t dropped = 0, invalid = 0;
        for (const Diagnostic& d : h.diagnostics)
            dropped += (d.message.find("dropped") != std::string::npos && d.message.find("hole dropped") == std::string::npos) ||
                       d.message.find("skipped") != std::string::npos;
        for (const Feature2D& f : features)
            for (const Polygon2D& p : f.polygons) invalid += geosValidity({p}) != "Valid Geometry";
        EXPECT_EQ(dropped, invalid) << file;
    }
}

TEST(Aggregate2D, SharedBordersMergeAtDeltaZero) {
    const std::vector<Feature2D> features = readShared("nc_counties.wkt");
    ASSERT_EQ(features.size(), 100u);
    Settings2D settings;
    settings.deltas = {0};
    Hierarchy2D h;
    ASSERT_TRUE(buildHierarchy2D(features, settings, h));
    for (const Diagnostic& d : h.diagnostics)
        EXPECT_NE(d.severity, Diagnostic::Severity::Error) << d.object << ": " << d.message;
    for (size_t f = 0; f < features.size(); ++f) EXPECT_GE(h.featureModel[f], 0) << features[f].name;
    // Neighbouring counties share borders: they are one model, hence one group at delta 0.
    EXPECT_LT(h.modelCount, 10u);
    ASSERT_EQ(h.levels.size(), 1u);
    EXPECT_EQ(h.levels[0].aggregates.size(), h.modelCount);
    expectValidAndContaining(features, h, "nc_counties");
    // Nothing added: the output is the union of the counties.
    const double unionArea = geosUnionArea(inputPolygons(features, h));
    EXPECT_NEAR(h.levels[0].measures.area, unionArea, 1e-9 * unionArea);
    EXPECT_LT(h.levels[0].measures.perimeter, 0.5 * h.originals.perimeter) << "inner borders are gone";
}

// A polygon inside another's interior, without touching it, is one model with it (README:
// nested polygons are merged), whichever comes first in the input and however the faces
// between the two rings are numbered; the level shows the outer polygon once.
TEST(Aggregate2D, NestedPolygonJoinsTheModelAroundIt) {
    auto square = [](const std::string& name, uint32_t id, double x0, double y0, double side) {
        Feature2D f;
        f.name = name;
        f.id = id;
        f.polygons.push_back(Polygon2D{{x0, y0, x0 + side, y0, x0 + side, y0 + side, x0, y0 + side}, {}});
        return f;
    };
    const std::vector<Feature2D> features = {square("inner", 0, 4, 4, 2), square("outer", 1, 0, 0, 10),
                                             square("far", 2, 30, 0, 3)};
    Settings2D settings;
    settings.deltas = {0.5};
    Hierarchy2D h;
    ASSERT_TRUE(buildHierarchy2D(features, settings, h));
    EXPECT_EQ(h.featureModel[0], h.featureModel[1]);
    EXPECT_NE(h.featureModel[0], h.featureModel[2]);
    ASSERT_EQ(h.levels.size(), 1u);
    ASSERT_EQ(h.levels[0].aggregates.size(), 2u);
    const Aggregate2D& both = h.levels[0].aggregates[0];
    EXPECT_EQ(both.sourceFeatures, (std::vector<uint32_t>{0, 1}));
    EXPECT_NEAR(both.measures.area, 100.0, 1e-9);
    EXPECT_EQ(geosValidity(both.polygons), "Valid Geometry");
}

// A hole touching its exterior at a vertex splits the exterior edge there: the output is
// traced (the exterior keeps that vertex), not copied from the input rings.
TEST(Aggregate2D, HoleTouchingItsExteriorKeepsTheTouchingVertex) {
    Feature2D notched;
    notched.name = "notched";
    notched.polygons.push_back(Polygon2D{{0, 0, 4, 0, 4, 4, 0, 4}, {{2, 0, 1, 1, 3, 1}}});
    Feature2D far;
    far.name = "far";
    far.id = 1;
    far.polygons.push_back(Polygon2D{{20, 0, 22, 0, 22, 2, 20, 2}, {}});
    Settings2D settings;
    settings.deltas = {0.1};
    Hierarchy2D h;
    ASSERT_TRUE(buildHierarchy2D({notched, far}, settings, h));
    ASSERT_EQ(h.levels[0].aggregates.size(), 2u);
    const Aggregate2D& a = h.levels[0].aggregates[0];
    EXPECT_EQ(geosValidity(a.polygons), "Valid Geometry");
    EXPECT_NEAR(a.measures.area, 15.0, 1e-12);
    bool touching = false;
    for (const Polygon2D& p : a.polygons)
        for (size_t i = 0; i + 1 < p.exterior.size(); i += 2) touching = touching || (p.exterior[i] == 2 && p.exterior[i + 1] == 0);
    EXPECT_TRUE(touching) << "the exterior ring passes through the vertex the hole touches";
}

// With more than one thread the contact checks run beside a first triangulation of all
// cleaned rings; a self-intersecting polygon they drop cancels it and the triangulation is
// made again without that polygon: the result must equal the one-thread run, which checks
// first.
TEST(Aggregate2D, DroppedPolygonGivesTheSameResultForAnyThreadCount) {
    std::vector<Feature2D> features = samples::makeSquareGrid(3000, 1.0, 0.5, 0.2, 3);
    Feature2D bowtie;
    bowtie.name = "bowtie";
    bowtie.id = static_cast<uint32_t>(features.size());
    bowtie.polygons.push_back(Polygon2D{{10.2, -3, 12.2, -1, 12.2, -3, 10.2, -2}, {}});  // AB crosses CD
    features.insert(features.begin() + 1500, bowtie);
    std::string first;
    for (int threads : {1, 2}) {
        Settings2D settings;
        settings.automaticLevelCount = 4;
        settings.threadCount = threads;
        Hierarchy2D h;
        ASSERT_TRUE(buildHierarchy2D(features, settings, h));
        EXPECT_EQ(h.featureModel[1500], -1) << "the self-intersecting polygon is left out";
        bool reported = false;
        for (const Diagnostic& d : h.diagnostics) reported = reported || (d.object == "bowtie" && d.message.find("self-intersecting") != std::string::npos);
        EXPECT_TRUE(reported);
        const std::string text = io::formatLevelsGeoJson(h, features);
        if (first.empty()) first = text;
        else EXPECT_EQ(text, first) << threads << " threads";
    }
}

TEST(Aggregate2D, SameResultForAnyThreadCount) {
    const std::vector<Feature2D> features = samples::makeEnvironment2D(samples::Environment2D::Forest, 2);
    std::string first;
    for (int threads : {1, 2, 5}) {
        Settings2D settings;
        settings.automaticLevelCount = 6;
        settings.threadCount = threads;
        Hierarchy2D h;
        ASSERT_TRUE(buildHierarchy2D(features, settings, h));
        std::string text = io::formatLevelsGeoJson(h, features);
        for (const Level2D& l : h.levels) {
            char buf[128];
            std::snprintf(buf, sizeof buf, "%.17g %.17g %.17g\n", l.constant.area, l.adaptive.area, l.hull.area);
            text += buf;
        }
        if (first.empty()) first = text;
        else EXPECT_EQ(text, first) << threads << " threads";
    }
}

// Random overlapping, touching (rounded vertices), holed and multi-part polygons: every level
// valid and containing its valid inputs. (Found the winding bugs of crossing and coincident
// rings; 4000 seeds passed when this was written, 120 run here.)
TEST(Aggregate2D, RandomOverlappingPolygonsStayValidAndContaining) {
    for (uint32_t seed = 1; seed <= 120; ++seed) {
        const std::vector<Feature2D> features = samples::makeRandomOverlappingPolygons(seed);
        Settings2D settings;
        settings.automaticLevelCount = 3;
        settings.function = seed % 2 ? AggregateFunctionKind::Constant : AggregateFunctionKind::Adaptive;
        Hierarchy2D h;
        if (!buildHierarchy2D(features, settings, h)) continue;  // every feature rejected
        const std::vector<Polygon2D> inputs = inputPolygons(features, h);
        if (inputs.empty()) continue;
        const double area = geosUnionArea(inputs);
        for (size_t l = 0; l < h.levels.size(); ++l) {
            for (const Aggregate2D& a : h.levels[l].aggregates)
                ASSERT_EQ(geosValidity(a.polygons), "Valid Geometry") << "seed " << seed << " level " << l;
            ASSERT_LE(geosUncoveredArea(inputs, levelPolygons(h.levels[l])), 1e-7 * area) << "seed " << seed << " level " << l;
        }
    }
}
