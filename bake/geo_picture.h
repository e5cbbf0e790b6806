// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: pictures of 2D levels (SVG, PNG) and the bar charts of reproduce2d; part of
// the aggrelod_render library with the 3D renders (render.h) and the bitmap font (raster.h).
#pragma once

#include <aggrelod/aggregate2d.h>

#include <string>
#include <vector>

namespace aggrelod::io {

/// What to draw in a picture panel.
struct PicturePanel {
    const std::vector<Feature2D>* originals = nullptr;  ///< filled in one colour
    const std::vector<Aggregate2D>* aggregates = nullptr;  ///< outlined (may be null)
    std::string title;
};

/// SVG of one or more panels side by side (same scale).
std::string formatSvg(const std::vector<PicturePanel>& panels, int panelWidth);

/// PNG (stb_image_write) of one or more panels side by side, each panelWidth pixels wide.
bool writePng(const std::vector<PicturePanel>& panels, int panelWidth, const std::string& path, std::string& error);

/// A simple chart for reproduce2d: groups of bars (one group per row label, one bar per
/// series), one chart per metric, stacked vertically. values[metric][row][series].
struct BarChart {
    std::vector<std::string> metricNames;
    std::vector<std::string> rowLabels;
    std::vector<std::string> seriesNames;
    std::vector<std::vector<std::vector<double>>> values;
};
bool writeBarChartPng(const BarChart& chart, const std::string& path, std::string& error);

}  // namespace aggrelod::io
