// SPDX-License-Identifier: MIT
// Read-only memory mapping of a whole file (POSIX mmap, Windows MapViewOfFile; the only place
// that calls them).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace aggrelod::runtime {

class MappedFile {
public:
    MappedFile() = default;
    ~MappedFile();
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;

    /// Maps `path`; false with a message naming the file and the system error otherwise.
    /// An empty file maps to data() == nullptr, size() == 0.
    bool open(const std::string& path, std::string& message);
    const uint8_t* data() const { return static_cast<const uint8_t*>(address_); }
    size_t size() const { return size_; }
    /// Lets the system drop the resident pages wholly inside [begin, begin + bytes) of the
    /// mapping (they are read from the file again if used): a large file validated once does
    /// not stay resident as a whole. A hint; does nothing where not supported.
    void release(const void* begin, size_t bytes) const;

private:
    void* address_ = nullptr;
    size_t size_ = 0;
};

}  // namespace aggrelod::runtime
