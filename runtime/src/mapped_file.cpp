// POSIX mmap of a runtime file, so that the reader uses the bytes in place (DESIGN section 4):
// opening costs the validation pass, not a copy.
#include "mapped_file.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

namespace aggrelod::runtime {

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

}  // namespace aggrelod::runtime
