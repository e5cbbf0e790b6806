// SPDX-License-Identifier: AGPL-3.0-or-later
// SHA-256 (FIPS 180-4) of a byte stream: the checksums of an output set's manifest.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace aggrelod::io {

/// Incremental SHA-256. Uses the x86 SHA extensions when the processor has them (checked once
/// at run time), the portable compression function otherwise; both give the same digest.
class Sha256 {
public:
    /// Which compression function to use: the fastest available, or the portable one (tests
    /// compare the two).
    enum class Path { Fastest, Portable };
    explicit Sha256(Path path = Path::Fastest);

    /// Appends `size` bytes at `data`.
    void update(const void* data, size_t size);
    /// The digest of everything appended, as 64 lower-case hex digits. Ends the stream.
    std::string hex();

    /// True when Path::Fastest uses the SHA extensions on this processor.
    static bool hardwareAvailable();

private:
    void compress(const unsigned char* blocks, size_t count);

    uint32_t state_[8] = {0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a,
                          0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19};
    unsigned char block_[64];
    size_t fill_ = 0;
    uint64_t length_ = 0;
    bool hardware_ = false;
};

}  // namespace aggrelod::io
