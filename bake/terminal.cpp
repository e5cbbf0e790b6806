// SPDX-License-Identifier: AGPL-3.0-or-later
#include "terminal.h"

#include <algorithm>
#include <cmath>
#include <unistd.h>

namespace aggrelod::cli {

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

void ProgressLine::update(const char* stage, double fraction) {
    if (!enabled_) return;
    std::lock_guard<std::mutex> lock(mutex_);
    if (!(fraction >= 0)) fraction = 0;  // also NaN
    if (fraction > 1) fraction = 1;
    const int percent = int(std::floor(fraction * 100.0));
    const std::string name = stage ? stage : "";
    if (drawn_ && percent == percent_ && name == stage_) return;
    stage_ = name;
    percent_ = percent;
    std::string line = "[" + stage_ + "] " + std::to_string(percent) + "%";
    const size_t width = line.size();
    if (width < width_) line.append(width_ - width, ' ');  // erase a longer previous line
    width_ = width;
    std::fprintf(stderr, "\r%s", line.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressLine::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!drawn_) return;
    std::fputc('\n', stderr);
    std::fflush(stderr);
    drawn_ = false;
    width_ = 0;
    percent_ = -1;
}

std::string formatDiagnostic(const Diagnostic& d) {
    const char* kind = d.severity == Diagnostic::Severity::Error     ? "error"
                       : d.severity == Diagnostic::Severity::Warning ? "warning"
                                                                     : "note";
    std::string s = kind;
    s += ": ";
    if (!d.object.empty()) s += d.object + ": ";
    s += d.message;
    return s;
}

void printDiagnostics(const std::vector<Diagnostic>& diagnostics, bool quiet) {
    for (const Diagnostic& d : diagnostics) {
        if (quiet && d.severity != Diagnostic::Severity::Error) continue;
        std::fprintf(stderr, "%s\n", formatDiagnostic(d).c_str());
    }
}

std::string formatNumber(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v == 0 ? 0.0 : v);
    return buf;
}

std::string formatTable(const std::vector<std::vector<std::string>>& rows) {
    std::vector<size_t> widths;
    for (const auto& row : rows) {
        if (widths.size() < row.size()) widths.resize(row.size(), 0);
        for (size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
    }
    std::string out;
    for (const auto& row : rows) {
        for (size_t c = 0; c < row.size(); ++c) {
            if (c) out += "  ";
            out.append(widths[c] - row[c].size(), ' ');
            out += row[c];
        }
        out += '\n';
    }
    return out;
}

std::string formatLevelTable(const Hierarchy3D& h) {
    std::vector<std::vector<std::string>> rows;
    rows.push_back({"level", "delta", "groups", "triangles", "volume", "added vol", "hull added",
                    "sphericity"});
    for (size_t k = 0; k < h.levels.size(); ++k) {
        const Level& l = h.levels[k];
        rows.push_back({std::to_string(k), formatNumber(l.delta), std::to_string(l.aggregates.size()),
                        std::to_string(l.triangleCount), formatNumber(l.measures.volume),
                        formatNumber(l.measures.volume - l.volumeOriginal),
                        formatNumber(l.volumeHull - l.volumeOriginal),
                        formatNumber(l.measures.sphericity)});
    }
    return formatTable(rows);
}

}  // namespace aggrelod::cli
