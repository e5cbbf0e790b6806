// SPDX-License-Identifier: AGPL-3.0-or-later
// libFuzzer target: the WKT and GeoJSON readers (readPolygonText), both on every input.
#include "geo_io.h"

#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    for (const char* format : {"wkt", "geojson"}) {
        aggrelod::io::GeoReadResult result;
        std::string error;
        aggrelod::io::readPolygonText(text, format, result, error);
    }
    return 0;
}
