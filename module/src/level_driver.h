// SPDX-License-Identifier: AGPL-3.0-or-later
// What the 2D and 3D level drivers share (paper Algorithm 1, the loop over thresholds;
// docs/design.md §2.3 and §2.5): the thresholds of the levels and a pool of scratch buffers
// for levels sculpted in parallel. The checks on explicit thresholds are validThresholds()
// (dendrogram.h); stage timing is stage_timer.h.
#pragma once

#include <algorithm>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace aggrelod::detail {

/// The thresholds of the levels, ascending without repeats (world units): the explicit ones,
/// or when there are none those `automatic()` returns, or when that is empty too the single
/// threshold 0 (one level: every model alone). *fellBack (optional) tells the last case.
template <class Automatic>
std::vector<double> levelThresholds(const std::vector<double>& explicitDeltas, Automatic automatic,
                                    bool* fellBack = nullptr) {
    std::vector<double> deltas = explicitDeltas;
    if (deltas.empty()) deltas = automatic();
    if (fellBack) *fellBack = deltas.empty();
    if (deltas.empty()) deltas.push_back(0.0);
    std::sort(deltas.begin(), deltas.end());
    deltas.erase(std::unique(deltas.begin(), deltas.end()), deltas.end());
    return deltas;
}

/// Buffers reused from one level to the next on whichever thread runs it: at most one set
/// per thread is ever made. Thread-safe; the buffers' contents are the user's to reset.
template <class Scratch>
class ScratchPool {
public:
    std::unique_ptr<Scratch> take() {
        std::lock_guard<std::mutex> lock(mutex_);
        if (free_.empty()) return std::make_unique<Scratch>();
        std::unique_ptr<Scratch> s = std::move(free_.back());
        free_.pop_back();
        return s;
    }
    void giveBack(std::unique_ptr<Scratch> s) {
        std::lock_guard<std::mutex> lock(mutex_);
        free_.push_back(std::move(s));
    }

private:
    std::mutex mutex_;
    std::vector<std::unique_ptr<Scratch>> free_;
};

}  // namespace aggrelod::detail
