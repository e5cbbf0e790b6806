// SPDX-License-Identifier: AGPL-3.0-or-later
// aggrelod bake: loading a glTF file (gltf_load.h): whole-file read, GLB chunk checks, a
// linear pre-scan of the JSON for hostile structure, external files confined to the input's
// folder, then tinygltf's parse.
#include "gltf_load.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>
#include <utility>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace aggrelod::io::gltf {
namespace {

using Severity = Diagnostic::Severity;

/// Image loader that accepts any image without decoding it: only geometry is read.
bool acceptImageWithoutDecoding(tinygltf::Image*, const int, std::string*, std::string*, int, int,
                                const unsigned char*, int, void*) {
    return true;
}

bool readWholeFile(const std::string& path, std::vector<unsigned char>& bytes, std::string& error) {
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        error = "is a directory, not a glTF file";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        error = std::string("cannot open: ") + std::strerror(errno);
        return false;
    }
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0) {
        error = "cannot read";
        return false;
    }
    if (uint64_t(size) >= uint64_t(std::numeric_limits<uint32_t>::max())) {
        error = "file is 4 GB or larger, which glTF loading does not support";
        return false;
    }
    in.seekg(0, std::ios::beg);
    // A few zero bytes past the end, so that nothing can read outside the allocation.
    bytes.assign(size_t(size) + 16, 0);
    if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
        error = "read error";
        return false;
    }
    bytes.resize(size_t(size));
    return true;
}

uint32_t readLe32(const unsigned char* p) {
    return uint32_t(p[0]) | (uint32_t(p[1]) << 8) | (uint32_t(p[2]) << 16) | (uint32_t(p[3]) << 24);
}

/// Stricter GLB header check than tinygltf's; returns the declared total length.
bool checkGlbHeader(const std::vector<unsigned char>& b, uint32_t& length, std::string& error) {
    const size_t size = b.size();
    if (size < 20) {
        error = "truncated GLB: " + std::to_string(size) + " bytes, shorter than a GLB header";
        return false;
    }
    const uint32_t version = readLe32(&b[4]);
    length = readLe32(&b[8]);
    const uint32_t jsonLength = readLe32(&b[12]);
    const uint32_t jsonType = readLe32(&b[16]);
    if (version != 2) {
        error = "unsupported GLB version " + std::to_string(version) + " (only glTF 2.0 is read)";
        return false;
    }
    if (length > size) {
        error = "truncated GLB: header says " + std::to_string(length) + " bytes, file has " +
                std::to_string(size);
        return false;
    }
    if (jsonType != 0x4E4F534Au) {
        error = "invalid GLB: first chunk is not JSON";
        return false;
    }
    const uint64_t jsonEnd = 20ull + jsonLength;
    if (jsonLength == 0 || jsonEnd > length) {
        error = "truncated GLB: JSON chunk of " + std::to_string(jsonLength) +
                " bytes does not fit in " + std::to_string(length) + " bytes";
        return false;
    }
    if (jsonEnd < length) {
        if (jsonEnd + 8 > length) {
            error = "invalid GLB: incomplete chunk header after the JSON chunk";
            return false;
        }
        const uint32_t binLength = readLe32(&b[size_t(jsonEnd)]);
        const uint32_t binType = readLe32(&b[size_t(jsonEnd) + 4]);
        if (binType == 0x004E4942u && jsonEnd + 8 + binLength > length) {
            error = "truncated GLB: BIN chunk of " + std::to_string(binLength) +
                    " bytes does not fit in " + std::to_string(length) + " bytes";
            return false;
        }
    }
    return true;
}

std::string lowerExtension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

/// One line, at most a few hundred characters (tinygltf may quote a whole data URI).
std::string tidyMessage(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
    for (char& c : s) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    const size_t maxLength = 300;
    if (s.size() > maxLength) s = s.substr(0, maxLength) + "...";
    return s;
}

// ---------------------------------------------------------------------------
// Limits and confinement: hostile structure is refused before tinygltf spends memory or
// stack on it (see docs/command-line.md, "Limits").

/// What a linear pass over the JSON text finds before the real parse.
struct JsonSummary {
    size_t nodeCount = 0;
    /// byteLength of every buffer whose uri names an external file, in buffer order
    /// (the order in which tinygltf loads them).
    std::vector<uint64_t> externalBufferLengths;
};

/// One pass over JSON text without recursion: refuses nesting deeper than kMaxJsonDepth and
/// more than kMaxNodes nodes, and collects the declared sizes of external buffers. Syntax
/// errors are left for tinygltf to report.
bool scanJson(const unsigned char* s, size_t n, JsonSummary& out, std::string& error) {
    struct Frame {
        bool object;
        bool expectKey;
        std::string key;     ///< current key (objects of depth <= 3 only)
        std::string uri;     ///< buffers[i].uri
        bool hasLength = false;
        uint64_t length = 0;
    };
    std::vector<Frame> stack;
    const auto inBufferElement = [&] {
        return stack.size() == 3 && stack[0].object && stack[0].key == "buffers" && !stack[1].object &&
               stack[2].object;
    };
    size_t i = 0;
    while (i < n) {
        const unsigned char c = s[i];
        if (c == '{' || c == '[') {
            if (stack.size() >= kMaxJsonDepth) {
                error = "JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels (at byte " +
                        std::to_string(i) + "); refused";
                return false;
            }
            if (stack.size() == 2 && stack[0].object && stack[0].key == "nodes" && !stack[1].object) {
                if (++out.nodeCount > kMaxNodes) {
                    error = "more than " + std::to_string(kMaxNodes) + " nodes; refused (limit of aggrelod)";
                    return false;
                }
            }
            stack.push_back(Frame{c == '{', c == '{', std::string(), std::string()});
            ++i;
        } else if (c == '}' || c == ']') {
            if (!stack.empty()) {
                if (inBufferElement() && stack[2].hasLength && !stack[2].uri.empty() &&
                    stack[2].uri.compare(0, 5, "data:") != 0)
                    out.externalBufferLengths.push_back(stack[2].length);
                stack.pop_back();
            }
            ++i;
        } else if (c == '"') {
            const size_t start = ++i;
            while (i < n && s[i] != '"') i += s[i] == '\\' ? 2 : 1;
            const size_t end = std::min(i, n);
            ++i;
            if (stack.empty()) continue;
            Frame& f = stack.back();
            if (f.object && f.expectKey) {
                if (stack.size() <= 3) f.key.assign(reinterpret_cast<const char*>(s + start), end - start);
            } else if (inBufferElement() && f.key == "uri") {
                f.uri.assign(reinterpret_cast<const char*>(s + start), std::min<size_t>(end - start, 16));
            }
        } else if (c == ':') {
            if (!stack.empty()) stack.back().expectKey = false;
            ++i;
        } else if (c == ',') {
            if (!stack.empty() && stack.back().object) stack.back().expectKey = true;
            ++i;
        } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r') {
            ++i;
        } else {
            const size_t start = i;
            while (i < n && s[i] != ',' && s[i] != '}' && s[i] != ']' && s[i] != ' ' && s[i] != '\n' &&
                   s[i] != '\r' && s[i] != '\t')
                ++i;
            if (inBufferElement() && stack[2].key == "byteLength") {
                const std::string number(reinterpret_cast<const char*>(s + start), i - start);
                char* endp = nullptr;
                const double v = std::strtod(number.c_str(), &endp);
                if (endp && *endp == '\0' && v >= 0 && v < 1.8e19) {
                    stack[2].hasLength = true;
                    stack[2].length = uint64_t(v);
                }
            }
        }
    }
    return true;
}

/// Largest external file read (as the main file: glTF loading stays below 4 GiB).
constexpr uint64_t kMaxExternalFileBytes = uint64_t(std::numeric_limits<uint32_t>::max()) - 1;

/// File access handed to tinygltf: external files must be regular files inside the input's
/// folder (unless allowed), of exactly their buffer's declared size, checked before reading;
/// external images are never read (only geometry is baked).
struct ExternalFiles {
    std::filesystem::path folder;  ///< canonical folder of the input, ends with a separator
    bool allowOutside = false;
    std::vector<uint64_t> bufferLengths;  ///< JsonSummary::externalBufferLengths
    size_t calls = 0;
    size_t imagesSkipped = 0;
    std::string refusal;  ///< why a buffer's file was refused: the error, instead of tinygltf's
    std::vector<std::string> read;  ///< canonical paths of the buffer files read
};

const char* const kImageNotRead = "external image not read (only geometry is baked)";

bool externalFileExists(const std::string& path, void*) {
    std::error_code ec;
    return std::filesystem::exists(std::filesystem::symlink_status(path, ec));
}

std::string expandNothing(const std::string& path, void*) { return path; }

bool writeNothing(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "writing is not used";
    return false;
}

bool readExternalFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    ExternalFiles& files = *static_cast<ExternalFiles*>(user);
    const size_t call = files.calls++;
    if (call >= files.bufferLengths.size()) {
        ++files.imagesSkipped;
        if (err) *err += kImageNotRead;
        return false;
    }
    const auto refuse = [&](const std::string& why) {
        if (err) *err += why;
        if (files.refusal.empty()) files.refusal = "external buffer file " + path + ": " + why;
        return false;
    };
    std::error_code ec;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(path, ec);
    if (ec) return refuse("cannot resolve: " + ec.message());
    if (!files.allowOutside) {
        const std::string folder = files.folder.string(), file = canonical.string();
        if (file.compare(0, folder.size(), folder) != 0)
            return refuse("refused: the uri leads outside the input's folder (--allow-external-uris allows it): " +
                          file + " is not under " + folder);
    }
    // The descriptor is checked, not the name, so that what is checked is what is read.
    const int fd = ::open(canonical.c_str(), O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK);
    if (fd < 0) return refuse(std::string("cannot open: ") + std::strerror(errno));
    struct FdCloser {
        int fd;
        ~FdCloser() { ::close(fd); }
    } closer{fd};
    struct stat st {};
    if (::fstat(fd, &st) != 0) return refuse(std::string("cannot stat: ") + std::strerror(errno));
    if (S_ISDIR(st.st_mode)) return refuse("refused: the uri names a directory, not a file");
    if (!S_ISREG(st.st_mode)) return refuse("refused: the uri names a device, pipe or socket, not a regular file");
    const uint64_t size = uint64_t(st.st_size);
    const uint64_t declared = files.bufferLengths[call];
    if (size > kMaxExternalFileBytes) return refuse("refused: file of " + std::to_string(size) + " bytes is 4 GiB or larger");
    if (size != declared)
        return refuse("refused: file has " + std::to_string(size) + " bytes, its buffer declares byteLength " +
                      std::to_string(declared));
    out->resize(size_t(size));
    size_t done = 0;
    while (done < size) {
        const ssize_t got = ::pread(fd, out->data() + done, size_t(size) - done, off_t(done));
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) return refuse(std::string("read error: ") + (got < 0 ? std::strerror(errno) : "file shrank"));
        done += size_t(got);
    }
    files.read.push_back(canonical.string());
    return true;
}

}  // namespace

bool loadModel(const std::string& path, tinygltf::Model& model, std::vector<Diagnostic>& diags,
               std::string& error, bool allowExternalUris, std::vector<std::string>* externalFiles) {
    std::vector<unsigned char> bytes;
    if (!readWholeFile(path, bytes, error)) return false;
    const bool magicGlb = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
    const std::string ext = lowerExtension(path);
    if (ext == ".glb" && !magicGlb) {
        error = bytes.size() < 4 ? "truncated GLB: " + std::to_string(bytes.size()) + " bytes"
                                 : "not a GLB file (no 'glTF' magic bytes)";
        return false;
    }
    std::string baseDir = std::filesystem::path(path).parent_path().string();
    if (baseDir.empty()) baseDir = ".";

    uint32_t glbLength = 0;
    if (magicGlb && !checkGlbHeader(bytes, glbLength, error)) return false;
    JsonSummary summary;
    if (!scanJson(bytes.data() + (magicGlb ? 20 : 0), magicGlb ? size_t(readLe32(&bytes[12])) : bytes.size(),
                  summary, error))
        return false;
    ExternalFiles files;
    std::error_code ec;
    files.folder = std::filesystem::weakly_canonical(std::filesystem::absolute(baseDir, ec), ec);
    if (ec) {
        error = "cannot resolve the input's folder: " + ec.message();
        return false;
    }
    files.folder /= "";  // trailing separator: "/in" must not admit "/inside"
    files.allowOutside = allowExternalUris;
    files.bufferLengths = summary.externalBufferLengths;

    tinygltf::TinyGLTF loader;
    loader.SetImageLoader(&acceptImageWithoutDecoding, nullptr);
    loader.SetFsCallbacks(tinygltf::FsCallbacks{&externalFileExists, &expandNothing, &readExternalFile,
                                                &writeNothing, &files});
    std::string err, warn;
    bool ok = false;
    try {
        if (magicGlb) {
            ok = loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), glbLength, baseDir);
        } else {
            if (bytes.empty()) {
                error = "empty file";
                return false;
            }
            ok = loader.LoadASCIIFromString(&model, &err, &warn,
                                            reinterpret_cast<const char*>(bytes.data()),
                                            unsigned(bytes.size()), baseDir);
        }
    } catch (const std::bad_alloc&) {
        error = "out of memory while parsing";
        return false;
    } catch (const std::exception& e) {
        error = std::string("invalid glTF: ") + e.what();
        return false;
    } catch (...) {
        error = "invalid glTF (the glTF parser failed)";
        return false;
    }
    if (!ok && !files.refusal.empty()) {
        error = files.refusal;
        return false;
    }
    if (!ok) {
        err = tidyMessage(err);
        error = "invalid glTF: " + (err.empty() ? std::string("the glTF parser failed") : err);
        return false;
    }
    if (!err.empty()) {
        diags.push_back(Diagnostic{Severity::Warning, "", "glTF loader: " + tidyMessage(err)});
    }
    // tinygltf's warnings are about images and other non-geometry data: kept as notes.
    std::istringstream lines(warn);
    std::string line;
    while (std::getline(lines, line)) {
        // External images are left unread on purpose: one note below instead of two lines each.
        if (line.find(kImageNotRead) != std::string::npos || line.find("Failed to load external 'uri' for image[") != std::string::npos)
            continue;
        line = tidyMessage(line);
        if (!line.empty()) diags.push_back(Diagnostic{Severity::Note, "", "glTF loader: " + line});
    }
    if (files.imagesSkipped)
        diags.push_back(Diagnostic{Severity::Note, "",
                                   std::to_string(files.imagesSkipped) +
                                       " external image file(s) not read: only geometry is baked"});
    if (externalFiles) *externalFiles = files.read;
    return true;
}

}  // namespace aggrelod::io::gltf
