// SPDX-License-Identifier: AGPL-3.0-or-later
// Shape measures of the aggregates (paper Section 4.1, Eq. 3 and its 3D counterpart): the
// compactness of a level's shapes, 1 for one disc (circularity) or one sphere (sphericity),
// and the measures of a level relative to the originals'.
#include <aggrelod/aggregate2d.h>
#include <aggrelod/aggregate3d.h>

#include <algorithm>
#include <cmath>

namespace aggrelod {

double circularity(double area, double perimeter) {
    return perimeter > 0 ? 4 * M_PI * area / (perimeter * perimeter) : 0;
}

double sphericity(double volume, double area) {
    return area > 0 ? std::cbrt(M_PI) * std::pow(6.0 * std::max(volume, 0.0), 2.0 / 3.0) / area : 0.0;
}

Measures2D normalizedMeasures(const Measures2D& m, const Measures2D& o) {
    Measures2D r;
    r.area = o.area > 0 ? m.area / o.area : 0;
    r.perimeter = o.perimeter > 0 ? m.perimeter / o.perimeter : 0;
    r.circularity = o.circularity > 0 ? m.circularity / o.circularity : 0;
    return r;
}

}  // namespace aggrelod
