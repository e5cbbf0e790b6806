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

private:
    void* address_ = nullptr;
    size_t size_ = 0;
};

}  // namespace aggrelod::runtime
