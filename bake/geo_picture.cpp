// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: pictures of 2D levels (SVG text, PNG through stb_image_write) and the bar
// charts of reproduce2d. A scanline polygon filler (even-odd per feature), line drawing and
// a 5x7 bitmap font: enough for clear figures without a graphics dependency.
#include "geo_picture.h"
#include "raster.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_STATIC
#include <stb_image_write.h>

namespace aggrelod::io {
namespace {

struct Rgb { unsigned char r, g, b; };
constexpr Rgb kWhite{255, 255, 255}, kOriginal{52, 101, 164}, kAggregateFill{252, 220, 180},
    kOutline{204, 40, 30}, kText{20, 20, 20}, kGrid{210, 210, 210};

class Image {
public:
    Image(int w, int h) : w_(w), h_(h), px_(static_cast<size_t>(w) * h * 3, 255) {}
    int width() const { return w_; }
    int height() const { return h_; }
    void set(int x, int y, Rgb c) {
        if (x < 0 || y < 0 || x >= w_ || y >= h_) return;
        unsigned char* p = &px_[(static_cast<size_t>(y) * w_ + x) * 3];
        p[0] = c.r; p[1] = c.g; p[2] = c.b;
    }
    void rect(int x0, int y0, int x1, int y1, Rgb c) {
        for (int y = std::max(0, y0); y < std::min(h_, y1); ++y)
            for (int x = std::max(0, x0); x < std::min(w_, x1); ++x) set(x, y, c);
    }
    void line(double x0, double y0, double x1, double y1, Rgb c, int thick = 1) {
        const double len = std::max(std::fabs(x1 - x0), std::fabs(y1 - y0));
        const int steps = static_cast<int>(std::ceil(len)) + 1;
        for (int i = 0; i <= steps; ++i) {
            const double t = static_cast<double>(i) / steps;
            const int x = static_cast<int>(std::floor(x0 + t * (x1 - x0)));
            const int y = static_cast<int>(std::floor(y0 + t * (y1 - y0)));
            for (int dy = 0; dy < thick; ++dy)
                for (int dx = 0; dx < thick; ++dx) set(x + dx - thick / 2, y + dy - thick / 2, c);
        }
    }
    /// Fills the rings (pixel coordinates, open rings) with the even-odd rule.
    void fill(const std::vector<std::vector<double>>& rings, Rgb c) {
        double minY = INFINITY, maxY = -INFINITY;
        for (const auto& r : rings)
            for (size_t i = 1; i < r.size(); i += 2) { minY = std::min(minY, r[i]); maxY = std::max(maxY, r[i]); }
        if (!(minY <= maxY)) return;
        std::vector<double> xs;
        for (int y = std::max(0, static_cast<int>(std::floor(minY))); y <= std::min(h_ - 1, static_cast<int>(std::ceil(maxY))); ++y) {
            const double sy = y + 0.5;
            xs.clear();
            for (const auto& r : rings) {
                const size_t n = r.size() / 2;
                for (size_t i = 0, j = n - 1; i < n; j = i++) {
                    const double yi = r[2 * i + 1], yj = r[2 * j + 1];
                    if ((yi > sy) != (yj > sy)) xs.push_back(r[2 * i] + (sy - yi) * (r[2 * j] - r[2 * i]) / (yj - yi));
                }
            }
            std::sort(xs.begin(), xs.end());
            for (size_t k = 0; k + 1 < xs.size(); k += 2) {
                const int x0 = std::max(0, static_cast<int>(std::ceil(xs[k] - 0.5)));
                const int x1 = std::min(w_ - 1, static_cast<int>(std::floor(xs[k + 1] - 0.5)));
                for (int x = x0; x <= x1; ++x) set(x, y, c);
            }
        }
    }
    void text(int x, int y, const std::string& s, Rgb c, int scale = 2);
    std::vector<unsigned char>& pixels() { return px_; }
    bool save(const std::string& path) const {
        return stbi_write_png(path.c_str(), w_, h_, 3, px_.data(), w_ * 3) != 0;
    }

private:
    int w_, h_;
    std::vector<unsigned char> px_;
};

// 5x7 font, column bytes (bit 0 = top row).
struct Glyph { char c; unsigned char col[5]; };
constexpr Glyph kFont[] = {
    {' ', {0, 0, 0, 0, 0}}, {'!', {0, 0, 0x5F, 0, 0}}, {'(', {0, 0x1C, 0x22, 0x41, 0}}, {')', {0, 0x41, 0x22, 0x1C, 0}},
    {'+', {8, 8, 0x3E, 8, 8}}, {',', {0, 0x50, 0x30, 0, 0}}, {'-', {8, 8, 8, 8, 8}}, {'.', {0, 0x60, 0x60, 0, 0}},
    {'/', {0x20, 0x10, 8, 4, 2}}, {'0', {0x3E, 0x51, 0x49, 0x45, 0x3E}}, {'1', {0, 0x42, 0x7F, 0x40, 0}},
    {'2', {0x42, 0x61, 0x51, 0x49, 0x46}}, {'3', {0x21, 0x41, 0x45, 0x4B, 0x31}}, {'4', {0x18, 0x14, 0x12, 0x7F, 0x10}},
    {'5', {0x27, 0x45, 0x45, 0x45, 0x39}}, {'6', {0x3C, 0x4A, 0x49, 0x49, 0x30}}, {'7', {1, 0x71, 9, 5, 3}},
    {'8', {0x36, 0x49, 0x49, 0x49, 0x36}}, {'9', {6, 0x49, 0x49, 0x29, 0x1E}}, {':', {0, 0x36, 0x36, 0, 0}},
    {'=', {0x14, 0x14, 0x14, 0x14, 0x14}}, {'A', {0x7E, 0x11, 0x11, 0x11, 0x7E}}, {'B', {0x7F, 0x49, 0x49, 0x49, 0x36}},
    {'C', {0x3E, 0x41, 0x41, 0x41, 0x22}}, {'D', {0x7F, 0x41, 0x41, 0x22, 0x1C}}, {'E', {0x7F, 0x49, 0x49, 0x49, 0x41}},
    {'F', {0x7F, 9, 9, 1, 1}}, {'G', {0x3E, 0x41, 0x41, 0x51, 0x32}}, {'H', {0x7F, 8, 8, 8, 0x7F}},
    {'I', {0, 0x41, 0x7F, 0x41, 0}}, {'J', {0x20, 0x40, 0x41, 0x3F, 1}}, {'K', {0x7F, 8, 0x14, 0x22, 0x41}},
    {'L', {0x7F, 0x40, 0x40, 0x40, 0x40}}, {'M', {0x7F, 2, 4, 2, 0x7F}}, {'N', {0x7F, 4, 8, 0x10, 0x7F}},
    {'O', {0x3E, 0x41, 0x41, 0x41, 0x3E}}, {'P', {0x7F, 9, 9, 9, 6}}, {'Q', {0x3E, 0x41, 0x51, 0x21, 0x5E}},
    {'R', {0x7F, 9, 0x19, 0x29, 0x46}}, {'S', {0x46, 0x49, 0x49, 0x49, 0x31}}, {'T', {1, 1, 0x7F, 1, 1}},
    {'U', {0x3F, 0x40, 0x40, 0x40, 0x3F}}, {'V', {0x1F, 0x20, 0x40, 0x20, 0x1F}}, {'W', {0x7F, 0x20, 0x18, 0x20, 0x7F}},
    {'X', {0x63, 0x14, 8, 0x14, 0x63}}, {'Y', {3, 4, 0x78, 4, 3}}, {'Z', {0x61, 0x51, 0x49, 0x45, 0x43}},
    {'_', {0x40, 0x40, 0x40, 0x40, 0x40}},
};

void Image::text(int x, int y, const std::string& s, Rgb c, int scale) {
    for (char ch : s) {
        const char u = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
        for (const Glyph& g : kFont) {
            if (g.c != u) continue;
            for (int col = 0; col < 5; ++col)
                for (int row = 0; row < 7; ++row)
                    if (g.col[col] & (1u << row)) rect(x + col * scale, y + row * scale, x + (col + 1) * scale, y + (row + 1) * scale, c);
        }
        x += 6 * scale;
    }
}

struct Bounds { double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY; };

void grow(Bounds& b, const std::vector<double>& ring) {
    for (size_t i = 0; i + 1 < ring.size(); i += 2) {
        b.minX = std::min(b.minX, ring[i]); b.maxX = std::max(b.maxX, ring[i]);
        b.minY = std::min(b.minY, ring[i + 1]); b.maxY = std::max(b.maxY, ring[i + 1]);
    }
}

Bounds panelBounds(const std::vector<PicturePanel>& panels) {
    Bounds b;
    for (const PicturePanel& p : panels) {
        if (p.originals)
            for (const Feature2D& f : *p.originals)
                for (const Polygon2D& poly : f.polygons) grow(b, poly.exterior);
        if (p.aggregates)
            for (const Aggregate2D& a : *p.aggregates)
                for (const Polygon2D& poly : a.polygons) grow(b, poly.exterior);
    }
    if (!(b.minX <= b.maxX)) b = Bounds{0, 0, 1, 1};
    if (b.maxX == b.minX) b.maxX += 1;
    if (b.maxY == b.minY) b.maxY += 1;
    return b;
}

constexpr int kMargin = 12, kTitleHeight = 30;

struct Transform {
    double scale, ox, oy;
    int offsetX, offsetY, height;
    double x(double wx) const { return offsetX + kMargin + (wx - ox) * scale; }
    double y(double wy) const { return offsetY + kTitleHeight + kMargin + (height - (wy - oy) * scale); }
};

std::vector<double> toPixels(const std::vector<double>& ring, const Transform& t) {
    std::vector<double> out(ring.size());
    for (size_t i = 0; i + 1 < ring.size(); i += 2) { out[i] = t.x(ring[i]); out[i + 1] = t.y(ring[i + 1]); }
    return out;
}

}  // namespace

std::string formatSvg(const std::vector<PicturePanel>& panels, int panelWidth) {
    const Bounds b = panelBounds(panels);
    const double scale = (panelWidth - 2 * kMargin) / (b.maxX - b.minX);
    const int drawH = static_cast<int>(std::ceil((b.maxY - b.minY) * scale));
    const int height = drawH + 2 * kMargin + kTitleHeight;
    std::string out;
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" viewBox=\"0 0 %d %d\">\n"
                  "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                  panelWidth * static_cast<int>(panels.size()), height, panelWidth * static_cast<int>(panels.size()), height);
    out += buf;
    auto path = [&](const Polygon2D& poly, const Transform& t) {
        std::string d;
        auto ring = [&](const std::vector<double>& r) {
            const std::vector<double> p = toPixels(r, t);
            for (size_t i = 0; i + 1 < p.size(); i += 2) {
                std::snprintf(buf, sizeof buf, "%c%.2f %.2f", i ? 'L' : 'M', p[i], p[i + 1]);
                d += buf;
            }
            d += 'Z';
        };
        ring(poly.exterior);
        for (const auto& h : poly.holes) ring(h);
        return d;
    };
    for (size_t k = 0; k < panels.size(); ++k) {
        const Transform t{scale, b.minX, b.minY, static_cast<int>(k) * panelWidth, 0, drawH};
        std::snprintf(buf, sizeof buf, "<text x=\"%d\" y=\"20\" font-family=\"sans-serif\" font-size=\"16\">",
                      static_cast<int>(k) * panelWidth + kMargin);
        out += buf + panels[k].title + "</text>\n";
        if (panels[k].aggregates)
            for (const Aggregate2D& a : *panels[k].aggregates)
                for (const Polygon2D& poly : a.polygons)
                    out += "<path fill=\"#fcdcb4\" fill-rule=\"evenodd\" stroke=\"none\" d=\"" + path(poly, t) + "\"/>\n";
        if (panels[k].originals)
            for (const Feature2D& f : *panels[k].originals)
                for (const Polygon2D& poly : f.polygons)
                    out += "<path fill=\"#3465a4\" fill-rule=\"evenodd\" stroke=\"none\" d=\"" + path(poly, t) + "\"/>\n";
        if (panels[k].aggregates)
            for (const Aggregate2D& a : *panels[k].aggregates)
                for (const Polygon2D& poly : a.polygons)
                    out += "<path fill=\"none\" stroke=\"#cc281e\" stroke-width=\"1.2\" d=\"" + path(poly, t) + "\"/>\n";
    }
    out += "</svg>\n";
    return out;
}

bool writePng(const std::vector<PicturePanel>& panels, int panelWidth, const std::string& path, std::string& error) {
    const Bounds b = panelBounds(panels);
    double scale = (panelWidth - 2 * kMargin) / (b.maxX - b.minX);
    int drawH = static_cast<int>(std::ceil((b.maxY - b.minY) * scale));
    if (drawH > 4 * panelWidth) {  // very tall scenes: fit the height instead
        scale *= 4.0 * panelWidth / drawH;
        drawH = 4 * panelWidth;
    }
    Image img(panelWidth * static_cast<int>(panels.size()), drawH + 2 * kMargin + kTitleHeight);
    for (size_t k = 0; k < panels.size(); ++k) {
        const Transform t{scale, b.minX, b.minY, static_cast<int>(k) * panelWidth, 0, drawH};
        img.text(t.offsetX + kMargin, 8, panels[k].title, kText, 2);
        if (panels[k].aggregates)
            for (const Aggregate2D& a : *panels[k].aggregates)
                for (const Polygon2D& poly : a.polygons) {
                    std::vector<std::vector<double>> rings{toPixels(poly.exterior, t)};
                    for (const auto& h : poly.holes) rings.push_back(toPixels(h, t));
                    img.fill(rings, kAggregateFill);
                }
        if (panels[k].originals)
            for (const Feature2D& f : *panels[k].originals) {
                std::vector<std::vector<double>> rings;
                for (const Polygon2D& poly : f.polygons) {
                    rings.push_back(toPixels(poly.exterior, t));
                    for (const auto& h : poly.holes) rings.push_back(toPixels(h, t));
                }
                img.fill(rings, kOriginal);
            }
        if (panels[k].aggregates)
            for (const Aggregate2D& a : *panels[k].aggregates)
                for (const Polygon2D& poly : a.polygons) {
                    auto ringLines = [&](const std::vector<double>& r) {
                        const std::vector<double> p = toPixels(r, t);
                        const size_t n = p.size() / 2;
                        for (size_t i = 0; i < n; ++i) {
                            const size_t j = (i + 1) % n;
                            img.line(p[2 * i], p[2 * i + 1], p[2 * j], p[2 * j + 1], kOutline, 2);
                        }
                    };
                    ringLines(poly.exterior);
                    for (const auto& h : poly.holes) ringLines(h);
                }
        if (k > 0) img.rect(t.offsetX, 0, t.offsetX + 1, img.height(), kGrid);
    }
    if (!img.save(path)) {
        error = path + ": cannot write PNG";
        return false;
    }
    return true;
}

bool writeBarChartPng(const BarChart& chart, const std::string& path, std::string& error) {
    const Rgb seriesColours[] = {{204, 40, 30}, {52, 101, 164}, {115, 210, 22}, {245, 121, 0}, {117, 80, 123}};
    const int rows = static_cast<int>(chart.rowLabels.size());
    const int series = static_cast<int>(chart.seriesNames.size());
    const int barW = 7, groupGap = 8, left = 80, panelH = 260, top = 40, labelH = 70;
    const int groupW = series * barW + groupGap;
    const int width = left + rows * groupW + 20;
    const int metrics = static_cast<int>(chart.metricNames.size());
    Image img(width, top + metrics * (panelH + labelH) + 10);
    // Legend.
    int lx = left;
    for (int s = 0; s < series; ++s) {
        img.rect(lx, 12, lx + 14, 26, seriesColours[s % 5]);
        img.text(lx + 20, 12, chart.seriesNames[s], kText, 2);
        lx += 40 + 12 * static_cast<int>(chart.seriesNames[s].size());
    }
    for (int m = 0; m < metrics; ++m) {
        const int y0 = top + m * (panelH + labelH);
        double maxV = 0;
        for (const auto& row : chart.values[m])
            for (double v : row)
                if (std::isfinite(v)) maxV = std::max(maxV, v);
        if (maxV <= 0) maxV = 1;
        // Nice axis step.
        const double rawStep = maxV / 5;
        const double mag = std::pow(10.0, std::floor(std::log10(rawStep)));
        double step = mag;
        for (double f : {1.0, 2.0, 5.0, 10.0})
            if (f * mag >= rawStep) { step = f * mag; break; }
        const double top_v = std::ceil(maxV / step) * step;
        auto yOf = [&](double v) { return y0 + 20 + (panelH - 20) * (1 - v / top_v); };
        for (double v = 0; v <= top_v + 1e-9; v += step) {
            const int y = static_cast<int>(yOf(v));
            img.rect(left, y, width - 20, y + 1, kGrid);
            char buf[32];
            std::snprintf(buf, sizeof buf, "%.3g", v);
            img.text(4, y - 7, buf, kText, 2);
        }
        img.text(left, y0 + 2, chart.metricNames[m], kText, 2);
        for (int r = 0; r < rows; ++r) {
            const int gx = left + r * groupW + groupGap / 2;
            for (int s = 0; s < series; ++s) {
                const double v = chart.values[m][r][s];
                if (!std::isfinite(v)) continue;
                img.rect(gx + s * barW, static_cast<int>(yOf(v)), gx + (s + 1) * barW - 1, static_cast<int>(yOf(0)),
                         seriesColours[s % 5]);
            }
            // Row label, vertical-ish: written in small text under the group, one char per line.
            const std::string& label = chart.rowLabels[r];
            for (size_t c = 0; c < label.size() && c < 8; ++c)
                img.text(gx + 2, static_cast<int>(yOf(0)) + 4 + static_cast<int>(c) * 8, std::string(1, label[c]), kText, 1);
        }
        img.rect(left, static_cast<int>(yOf(0)), width - 20, static_cast<int>(yOf(0)) + 1, kText);
    }
    if (!img.save(path)) {
        error = path + ": cannot write PNG";
        return false;
    }
    return true;
}

// ---------------------------------------------------------------------------
// Raster helpers for other pictures (raster.h): the same font and PNG writer.

void drawText(std::vector<unsigned char>& rgb, int width, int height, int x, int y,
              const std::string& text, const unsigned char colour[3], int scale) {
    if (width <= 0 || height <= 0 || rgb.size() != static_cast<size_t>(width) * height * 3) return;
    Image image(width, height);
    image.pixels().swap(rgb);
    image.text(x, y, text, Rgb{colour[0], colour[1], colour[2]}, scale);
    image.pixels().swap(rgb);
}

int textWidth(const std::string& text, int scale) { return static_cast<int>(text.size()) * 6 * scale; }

bool writeRgbPng(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb,
                 std::string& error) {
    if (width <= 0 || height <= 0 || rgb.size() != static_cast<size_t>(width) * height * 3) {
        error = path + ": image size does not match its pixels";
        return false;
    }
    if (stbi_write_png(path.c_str(), width, height, 3, rgb.data(), width * 3) == 0) {
        error = path + ": cannot write the PNG file";
        return false;
    }
    return true;
}

}  // namespace aggrelod::io
