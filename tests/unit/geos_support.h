// SPDX-License-Identifier: AGPL-3.0-or-later
// GEOS as an independent referee for the 2D tests (validity, containment, area).
// GEOS is used only in tests and benchmarks (peer, not dependency); all its calls are in
// geos_support.cpp.
#pragma once

#include <aggrelod/aggregate2d.h>

#include <string>
#include <vector>

namespace aggrelod::testing {

/// GEOSisValidReason of the polygons as one MultiPolygon: "Valid Geometry" when valid.
std::string geosValidity(const std::vector<Polygon2D>& polygons);

/// Area of (union of `inner`) minus (union of `outer`), both made valid first.
double geosUncoveredArea(const std::vector<Polygon2D>& inner, const std::vector<Polygon2D>& outer);

/// True when the polygons form one connected set (parts may touch at points).
bool geosConnected(const std::vector<Polygon2D>& polygons);

/// Area of the union of the polygons (made valid first).
double geosUnionArea(const std::vector<Polygon2D>& polygons);

}  // namespace aggrelod::testing
