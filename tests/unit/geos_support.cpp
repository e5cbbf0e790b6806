// SPDX-License-Identifier: AGPL-3.0-or-later
// GEOS C API wrapper for the tests (the only test file that includes geos_c.h).
#include "geos_support.h"

#include <geos_c.h>

#include <stdexcept>

namespace aggrelod::testing {
namespace {

struct Context {
    GEOSContextHandle_t h = GEOS_init_r();
    ~Context() { GEOS_finish_r(h); }
};

GEOSGeometry* ring(GEOSContextHandle_t h, const std::vector<double>& xy) {
    const unsigned n = static_cast<unsigned>(xy.size() / 2);
    GEOSCoordSequence* seq = GEOSCoordSeq_create_r(h, n + 1, 2);
    for (unsigned i = 0; i <= n; ++i) {
        const unsigned k = i % n;
        GEOSCoordSeq_setXY_r(h, seq, i, xy[2 * k], xy[2 * k + 1]);
    }
    return GEOSGeom_createLinearRing_r(h, seq);
}

GEOSGeometry* multiPolygon(GEOSContextHandle_t h, const std::vector<Polygon2D>& polygons) {
    std::vector<GEOSGeometry*> parts;
    for (const Polygon2D& p : polygons) {
        std::vector<GEOSGeometry*> holes;
        for (const auto& hole : p.holes) holes.push_back(ring(h, hole));
        parts.push_back(GEOSGeom_createPolygon_r(h, ring(h, p.exterior), holes.data(), static_cast<unsigned>(holes.size())));
    }
    return GEOSGeom_createCollection_r(h, GEOS_MULTIPOLYGON, parts.data(), static_cast<unsigned>(parts.size()));
}

/// Union of the polygons, each made valid on its own (inputs may touch or overlap).
GEOSGeometry* validUnion(GEOSContextHandle_t h, const std::vector<Polygon2D>& polygons) {
    std::vector<GEOSGeometry*> parts;
    for (const Polygon2D& p : polygons) {
        GEOSGeometry* one = multiPolygon(h, {p});
        GEOSGeometry* valid = GEOSMakeValid_r(h, one);
        GEOSGeom_destroy_r(h, one);
        if (!valid) throw std::runtime_error("GEOSMakeValid failed");
        parts.push_back(valid);
    }
    GEOSGeometry* collection =
        GEOSGeom_createCollection_r(h, GEOS_GEOMETRYCOLLECTION, parts.data(), static_cast<unsigned>(parts.size()));
    GEOSGeometry* u = GEOSUnaryUnion_r(h, collection);
    GEOSGeom_destroy_r(h, collection);
    if (!u) throw std::runtime_error("GEOSUnaryUnion failed");
    return u;
}

}  // namespace

std::string geosValidity(const std::vector<Polygon2D>& polygons) {
    Context c;
    GEOSGeometry* g = multiPolygon(c.h, polygons);
    char* reason = GEOSisValidReason_r(c.h, g);
    std::string r = reason ? reason : "GEOSisValidReason failed";
    GEOSFree_r(c.h, reason);
    GEOSGeom_destroy_r(c.h, g);
    return r;
}

double geosUncoveredArea(const std::vector<Polygon2D>& inner, const std::vector<Polygon2D>& outer) {
    Context c;
    GEOSGeometry* a = validUnion(c.h, inner);
    GEOSGeometry* b = validUnion(c.h, outer);
    GEOSGeometry* d = GEOSDifference_r(c.h, a, b);
    double area = -1;
    if (d) GEOSArea_r(c.h, d, &area);
    GEOSGeom_destroy_r(c.h, a);
    GEOSGeom_destroy_r(c.h, b);
    if (d) GEOSGeom_destroy_r(c.h, d);
    return area;
}

bool geosConnected(const std::vector<Polygon2D>& polygons) {
    Context c;
    std::vector<GEOSGeometry*> g;
    for (const Polygon2D& p : polygons) g.push_back(multiPolygon(c.h, {p}));
    std::vector<int> component(g.size());
    for (size_t i = 0; i < g.size(); ++i) component[i] = static_cast<int>(i);
    auto root = [&](int x) { while (component[x] != x) x = component[x]; return x; };
    for (size_t i = 0; i < g.size(); ++i)
        for (size_t j = i + 1; j < g.size(); ++j)
            if (root(static_cast<int>(i)) != root(static_cast<int>(j)) && GEOSIntersects_r(c.h, g[i], g[j]) == 1)
                component[root(static_cast<int>(j))] = root(static_cast<int>(i));
    bool connected = true;
    for (size_t i = 0; i < g.size(); ++i) connected &= root(static_cast<int>(i)) == root(0);
    for (GEOSGeometry* x : g) GEOSGeom_destroy_r(c.h, x);
    return connected;
}

double geosUnionArea(const std::vector<Polygon2D>& polygons) {
    Context c;
    GEOSGeometry* u = validUnion(c.h, polygons);
    double area = -1;
    GEOSArea_r(c.h, u, &area);
    GEOSGeom_destroy_r(c.h, u);
    return area;
}

}  // namespace aggrelod::testing
