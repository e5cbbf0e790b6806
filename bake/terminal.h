// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: terminal output helpers shared by the subcommands (progress line,
// diagnostics, tables). No CLI11 here.
#pragma once

#include <aggrelod/aggregate3d.h>

#include <cstdio>
#include <mutex>
#include <string>
#include <vector>

namespace aggrelod::cli {

/// True when stderr is a terminal.
bool stderrIsTerminal();

/// One-line progress display on stderr: "\r[stage] 42%". Prints only when enabled
/// (callers pass `!quiet && stderrIsTerminal()`); redraws only when the stage or the
/// whole percentage changes. Thread-safe.
class ProgressLine {
public:
    explicit ProgressLine(bool enabled) : enabled_(enabled) {}
    ~ProgressLine() { finish(); }
    ProgressLine(const ProgressLine&) = delete;
    ProgressLine& operator=(const ProgressLine&) = delete;

    void update(const char* stage, double fraction);
    /// Ends the line with a newline if anything was drawn.
    void finish();

private:
    bool enabled_;
    std::mutex mutex_;
    std::string stage_;
    int percent_ = -1;
    size_t width_ = 0;
    bool drawn_ = false;
};

/// "note: object: message" (or without "object: " when empty).
std::string formatDiagnostic(const Diagnostic& d);

/// Prints diagnostics to stderr: errors always, notes and warnings unless quiet.
void printDiagnostics(const std::vector<Diagnostic>& diagnostics, bool quiet);

/// Right-aligned text table; the first row is the header.
std::string formatTable(const std::vector<std::vector<std::string>>& rows);

/// Level table: level, delta, groups, triangles, volume, added vol, hull added, sphericity.
std::string formatLevelTable(const Hierarchy3D& hierarchy);

/// "%.6g" without locale surprises; "nan"/"inf" as such.
std::string formatNumber(double v);

}  // namespace aggrelod::cli
