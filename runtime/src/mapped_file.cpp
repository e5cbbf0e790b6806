// SPDX-License-Identifier: MIT
// Read-only memory mapping of a runtime file, so that the reader uses the bytes in place
// (docs/design.md §4): opening costs the validation pass, not a copy. POSIX mmap, or on
// Windows CreateFileMapping / MapViewOfFile.
#include "mapped_file.h"

#include <cerrno>
#include <cstring>
#include <limits>

#if defined(_WIN32)
#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#ifndef NOMINMAX
#define NOMINMAX
#endif
#include <windows.h>
#else
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#endif

namespace aggrelod::runtime {

#if defined(_WIN32)

namespace {

// The system's text for a Win32 error code, e.g. "The system cannot find the file specified."
std::string windowsErrorText(DWORD code) {
    char* buffer = nullptr;
    const DWORD length = FormatMessageA(
        FORMAT_MESSAGE_ALLOCATE_BUFFER | FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS,
        nullptr, code, 0, reinterpret_cast<LPSTR>(&buffer), 0, nullptr);
    std::string text = length > 0 && buffer != nullptr ? std::string(buffer, length) : std::string();
    if (buffer != nullptr) LocalFree(buffer);
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' ' || text.back() == '.'))
        text.pop_back();
    if (text.empty()) text = "error";
    return text + ", code " + std::to_string(code);
}

// Paths are UTF-8 (as everywhere in the API): convert to UTF-16 for the wide Win32 calls,
// so that names outside the ANSI code page open too.
bool utf8ToWide(const std::string& path, std::wstring& wide) {
    if (path.empty() || path.size() > static_cast<size_t>(std::numeric_limits<int>::max())) return false;
    const int n = MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path.data(), static_cast<int>(path.size()), nullptr, 0);
    if (n <= 0) return false;
    wide.assign(static_cast<size_t>(n), L'\0');
    return MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, path.data(), static_cast<int>(path.size()), &wide[0], n) == n;
}

}  // namespace

MappedFile::~MappedFile() {
    if (address_ != nullptr) UnmapViewOfFile(address_);
}

bool MappedFile::open(const std::string& path, std::string& message) {
    std::wstring wide;
    if (!utf8ToWide(path, wide)) {
        message = path + ": cannot open (not a valid UTF-8 path)";
        return false;
    }
    // Others may read the file while it is open, not write to it: the validated bytes must not
    // change under the reader. (Windows refuses to replace or delete a file while a view of it
    // is mapped, whatever the share mode: a bake can replace it only once it is closed.)
    const HANDLE file = CreateFileW(wide.c_str(), GENERIC_READ, FILE_SHARE_READ, nullptr,
                                    OPEN_EXISTING, FILE_ATTRIBUTE_NORMAL, nullptr);
    if (file == INVALID_HANDLE_VALUE) {
        message = path + ": cannot open (" + windowsErrorText(GetLastError()) + ")";
        return false;
    }
    BY_HANDLE_FILE_INFORMATION info{};
    if (GetFileType(file) != FILE_TYPE_DISK || !GetFileInformationByHandle(file, &info) ||
        (info.dwFileAttributes & FILE_ATTRIBUTE_DIRECTORY) != 0) {
        message = path + ": not a regular file";
        CloseHandle(file);
        return false;
    }
    const unsigned long long bytes =
        (static_cast<unsigned long long>(info.nFileSizeHigh) << 32) | info.nFileSizeLow;
    if (bytes > static_cast<unsigned long long>(std::numeric_limits<size_t>::max())) {
        message = path + ": too large to map";
        CloseHandle(file);
        return false;
    }
    size_ = static_cast<size_t>(bytes);
    if (size_ > 0) {  // a mapping of an empty file is an error on Windows: leave data() null
        const HANDLE mapping = CreateFileMappingW(file, nullptr, PAGE_READONLY, 0, 0, nullptr);
        if (mapping == nullptr) {
            message = path + ": cannot map (" + windowsErrorText(GetLastError()) + ")";
            size_ = 0;
            CloseHandle(file);
            return false;
        }
        void* address = MapViewOfFile(mapping, FILE_MAP_READ, 0, 0, 0);
        const DWORD mapError = GetLastError();
        CloseHandle(mapping);  // the view keeps the mapping and the file alive
        if (address == nullptr) {
            message = path + ": cannot map (" + windowsErrorText(mapError) + ")";
            size_ = 0;
            CloseHandle(file);
            return false;
        }
        address_ = address;
    }
    CloseHandle(file);
    return true;
}

void MappedFile::release(const void* begin, size_t bytes) const {
    // Unlocking pages that are not locked removes them from the working set.
    if (address_ != nullptr && bytes > 0) VirtualUnlock(const_cast<void*>(begin), bytes);
}

#else

void MappedFile::release(const void* begin, size_t bytes) const {
    if (address_ == nullptr || bytes == 0) return;
    const long pageSize = sysconf(_SC_PAGESIZE);
    if (pageSize <= 0) return;
    const uintptr_t page = static_cast<uintptr_t>(pageSize);
    const uintptr_t from = (reinterpret_cast<uintptr_t>(begin) + page - 1) / page * page;
    const uintptr_t to = (reinterpret_cast<uintptr_t>(begin) + bytes) / page * page;
    // A private read-only mapping never written to: dropped pages come back from the file.
    if (to > from) madvise(reinterpret_cast<void*>(from), to - from, MADV_DONTNEED);
}

MappedFile::~MappedFile() {
    if (address_ != nullptr) munmap(address_, size_);
}

bool MappedFile::open(const std::string& path, std::string& message) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        message = path + ": cannot open (" + std::strerror(errno) + ")";
        return false;
    }
    struct stat info {};
    if (fstat(fd, &info) != 0 || !S_ISREG(info.st_mode)) {
        message = path + ": not a regular file";
        ::close(fd);
        return false;
    }
    size_ = static_cast<size_t>(info.st_size);
    if (size_ > 0) {
        void* address = mmap(nullptr, size_, PROT_READ, MAP_PRIVATE, fd, 0);
        if (address == MAP_FAILED) {
            message = path + ": cannot map (" + std::strerror(errno) + ")";
            size_ = 0;
            ::close(fd);
            return false;
        }
        address_ = address;
    }
    ::close(fd);  // the mapping stays valid after close
    return true;
}

#endif

}  // namespace aggrelod::runtime
