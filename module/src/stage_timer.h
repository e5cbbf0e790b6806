// SPDX-License-Identifier: AGPL-3.0-or-later
// Stage timing and progress, shared by the 2D and 3D level drivers (docs/design.md §2.5):
// every stage's wall time goes to the result's `timings` in run order, and the caller's
// progress callback hears 0 when a stage begins, fractions while it runs and 1 when it ends.
#pragma once

#include <aggrelod/aggregate_common.h>

#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace aggrelod::detail {

class StageTimer {
public:
    using Timings = std::vector<std::pair<std::string, double>>;

    /// `timings` and `progress` must outlive the timer; `progress` may be empty.
    StageTimer(Timings& timings, const ProgressCallback& progress) : timings_(timings), progress_(progress) {}

    /// Ends the running stage (if any) and starts `stage`.
    void begin(const std::string& stage) {
        end();
        name_ = stage;
        start_ = Clock::now();
        report(0.0);
    }
    /// Progress of the running stage, fraction in [0, 1]; nothing when no stage runs.
    void report(double fraction) const {
        if (progress_ && !name_.empty()) progress_(name_.c_str(), fraction);
    }
    /// The running stage's name; empty when none runs.
    const std::string& stage() const { return name_; }
    /// Records the running stage's time; nothing when no stage runs.
    void end() {
        if (name_.empty()) return;
        report(1.0);
        timings_.emplace_back(name_, std::chrono::duration<double>(Clock::now() - start_).count());
        name_.clear();
    }

private:
    using Clock = std::chrono::steady_clock;
    Timings& timings_;
    const ProgressCallback& progress_;
    Clock::time_point start_ = Clock::now();
    std::string name_;
};

}  // namespace aggrelod::detail
