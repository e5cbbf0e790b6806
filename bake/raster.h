// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: small raster helpers shared by the 2D pictures and the 3D renders (both in
// the aggrelod_render library): the 5x7 bitmap font and PNG output (stb_image_write stays
// inside geo_picture.cpp).
#pragma once

#include <string>
#include <vector>

namespace aggrelod::io {

/// Draws `text` with the built-in 5x7 bitmap font (upper case, digits, a few signs; other
/// characters are blank) into `rgb` (width * height * 3 bytes, rows top-down). (x, y) is the
/// top-left corner in pixels; each font pixel becomes a scale x scale square. Clipped.
void drawText(std::vector<unsigned char>& rgb, int width, int height, int x, int y,
              const std::string& text, const unsigned char colour[3], int scale);

/// Width in pixels of `text` drawn with drawText at `scale`.
int textWidth(const std::string& text, int scale);

/// Writes an RGB image (width * height * 3 bytes, rows top-down) as PNG. Deterministic bytes.
bool writeRgbPng(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb,
                 std::string& error);

}  // namespace aggrelod::io
