// SPDX-License-Identifier: AGPL-3.0-or-later
// Deterministic parallel loop: body(i) for i in [0, count) on up to threadCount threads
// (0 = hardware concurrency). Every index must write only its own output slot, so results
// do not depend on the thread count. The first exception thrown is rethrown here.
// `onDone` (optional) runs on the calling thread only, after each index it ran itself,
// with the number of indices finished so far (for progress reports).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace aggrelod::detail {

inline void parallelFor(size_t count, int threadCount, const std::function<void(size_t)>& body,
                        const std::function<void(size_t)>& onDone = {}) {
    std::atomic<size_t> next{0}, done{0};
    std::mutex failureMutex;
    std::exception_ptr failure;
    auto worker = [&](bool caller) {
        for (size_t i = next++; i < count; i = next++) {
            try {
                body(i);
            } catch (...) {
                std::lock_guard<std::mutex> lock(failureMutex);
                if (!failure) failure = std::current_exception();
            }
            size_t finished = ++done;
            if (caller && onDone) onDone(finished);
        }
    };
    size_t threads = threadCount > 0 ? static_cast<size_t>(threadCount) : std::max(1u, std::thread::hardware_concurrency());
    threads = std::min(threads, count);
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) pool.emplace_back(worker, false);
    worker(true);
    for (std::thread& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
}

/// body(i) for i in [0, count), in contiguous blocks of about `grain` indices on up to
/// threadCount threads; every index must write only its own output slots (the same result
/// for any thread count).
template <class Body>
void parallelForEach(size_t count, int threadCount, Body&& body, size_t grain = 16384) {
    const size_t blocks = std::clamp<size_t>(count / grain, 1, 64);
    parallelFor(blocks, threadCount, [&](size_t block) {
        for (size_t i = count * block / blocks; i < count * (block + 1) / blocks; ++i) body(i);
    });
}

}  // namespace aggrelod::detail
