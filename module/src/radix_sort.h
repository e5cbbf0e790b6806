// SPDX-License-Identifier: AGPL-3.0-or-later
// Linear-time sorts on small integer keys, instead of comparison sorts of large flat arrays:
// a stable LSD radix sort (the 2D pipeline, the dendrogram) and a counting sort into buckets
// (edges by their first vertex or their group, in the 2D and 3D pipelines and sculpting).
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

/// Counting sort into buckets: `out` receives `items` grouped by key(item) (an integer in
/// [0, bucketCount)), each bucket in input order (stable); `start` receives bucketCount + 1
/// offsets, bucket b being out[start[b], start[b + 1]). Both outputs are resized (their
/// storage is reused); O(items + buckets).
template <class T, class KeyFn>
void countingSortByBucket(const std::vector<T>& items, size_t bucketCount, KeyFn key, std::vector<uint32_t>& start,
                          std::vector<T>& out) {
    start.assign(bucketCount + 1, 0);
    for (const T& item : items) ++start[size_t(key(item)) + 1];
    for (size_t b = 0; b < bucketCount; ++b) start[b + 1] += start[b];
    out.resize(items.size());
    std::vector<uint32_t> at(start.begin(), start.end() - 1);
    for (const T& item : items) out[at[size_t(key(item))]++] = item;
}

}  // namespace aggrelod::detail
