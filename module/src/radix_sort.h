// SPDX-License-Identifier: AGPL-3.0-or-later
// Stable LSD radix sort on an unsigned integer key: linear passes of 11-bit digits instead of
// a comparison sort, for the large flat arrays of the 2D pipeline and the dendrogram.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace aggrelod::detail {

/// Sorts `items` by key(item) (uint64_t, only its low keyBits bits are read), stably: equal
/// keys keep their order. Passes where every item has the same digit are skipped.
template <class T, class KeyFn>
void radixSortStable(std::vector<T>& items, KeyFn key, int keyBits = 64) {
    const size_t n = items.size();
    if (n < 2) return;
    std::vector<T> buffer(n);
    std::vector<uint64_t> keys(n), keyBuffer(n);
    for (size_t i = 0; i < n; ++i) keys[i] = key(items[i]);
    std::vector<uint32_t> count(2049);
    for (int shift = 0; shift < keyBits; shift += 11) {
        std::fill(count.begin(), count.end(), 0u);
        for (uint64_t k : keys) ++count[((k >> shift) & 2047) + 1];
        if (*std::max_element(count.begin(), count.end()) == n) continue;  // one digit everywhere
        for (size_t d = 0; d < 2048; ++d) count[d + 1] += count[d];
        for (size_t i = 0; i < n; ++i) {
            const uint32_t at = count[(keys[i] >> shift) & 2047]++;
            buffer[at] = std::move(items[i]);
            keyBuffer[at] = keys[i];
        }
        items.swap(buffer);
        keys.swap(keyBuffer);
    }
}

}  // namespace aggrelod::detail
