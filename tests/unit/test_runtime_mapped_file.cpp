// SPDX-License-Identifier: MIT
// RuntimeFile::openFile on the file system (runtime/src/mapped_file.cpp: POSIX mmap, Windows
// MapViewOfFile): UTF-8 paths outside ASCII, directories refused with the path in the message,
// and what happens when a new bake replaces a file that is open. Also built for Windows and
// run under wine (tests/windows).
#include <aggrelod/runtime_build.h>
#include <aggrelod/runtime_file.h>

#include "synthetic_hierarchy.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

using namespace aggrelod::runtime;
using aggrelod::testing::makeSyntheticHierarchy;
namespace fs = std::filesystem;

namespace {

std::vector<uint8_t> bytesOf(const BuildArrays& p) {
    std::vector<uint8_t> bytes;
    std::string error;
    EXPECT_TRUE(writeRuntimeFile(p, bytes, error)) << error;
    return bytes;
}

void writeFile(const fs::path& path, const std::vector<uint8_t>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(static_cast<bool>(out)) << path.string();
}

// A fresh folder under the test temporaries.
fs::path freshDir(const std::string& name) {
    const fs::path dir = fs::path(AGGRELOD_TEST_TMP) / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

}  // namespace

TEST(RuntimeMappedFile, OpensUtf8PathOutsideAscii) {
    const fs::path dir = freshDir("mapped_utf8");
    // "größe-✓.aglod" in UTF-8, the encoding of every path the API takes.
    const std::string name = "gr\xc3\xb6\xc3\x9f" "e-\xe2\x9c\x93.aglod";
    const std::string utf8Path = dir.u8string() + "/" + name;
    const std::vector<uint8_t> bytes = bytesOf(makeSyntheticHierarchy(30, 5));
    writeFile(fs::u8path(utf8Path), bytes);
    ASSERT_TRUE(fs::exists(fs::u8path(utf8Path)));
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openFile(utf8Path, file, message), FileStatus::Ok) << message;
    EXPECT_EQ(file.byteSize(), bytes.size());
    EXPECT_EQ(file.objectName(7), "box7");
}

TEST(RuntimeMappedFile, DirectoryIsRefusedWithItsPath) {
    const fs::path dir = freshDir("mapped_directory");
    RuntimeFile file;
    std::string message;
    EXPECT_EQ(RuntimeFile::openFile(dir.string(), file, message), FileStatus::IoError);
    EXPECT_NE(message.find("mapped_directory"), std::string::npos) << message;
    EXPECT_FALSE(file.isOpen());
}

// POSIX: a bake may move a new file over one that a game has open; the game keeps reading the
// old bytes until it reopens. Windows refuses to replace (or delete) a file while a view of it
// is mapped: the move fails, the open file stays intact, and the move succeeds once it is closed.
TEST(RuntimeMappedFile, ReplacingAnOpenFile) {
    const fs::path dir = freshDir("mapped_replace");
    const fs::path path = dir / "scene.aglod", next = dir / "scene.aglod.new";
    writeFile(path, bytesOf(makeSyntheticHierarchy(40, 1)));
    RuntimeFile file;
    std::string message;
    ASSERT_EQ(RuntimeFile::openFile(path.string(), file, message), FileStatus::Ok) << message;
    const uint32_t nodes = file.nodeCount();

    // A bake writes the new file beside the old one and moves it into place.
    writeFile(next, bytesOf(makeSyntheticHierarchy(90, 2)));
    std::error_code error;
    fs::rename(next, path, error);
#if defined(_WIN32)
    EXPECT_TRUE(error) << "Windows replaced a file that has a mapped view";
#else
    ASSERT_FALSE(error) << "replacing a mapped file: " << error.message();
#endif
    EXPECT_EQ(file.nodeCount(), nodes);  // the mapping still holds the old bytes
    EXPECT_EQ(file.objectCount(), 40u);
    EXPECT_EQ(file.objectName(39), "box39");
#if defined(_WIN32)
    file = RuntimeFile();  // close: unmaps
    fs::rename(next, path, error);
    ASSERT_FALSE(error) << "replacing a closed file: " << error.message();
#endif
    RuntimeFile fresh;
    ASSERT_EQ(RuntimeFile::openFile(path.string(), fresh, message), FileStatus::Ok) << message;
    EXPECT_EQ(fresh.objectCount(), 90u);
}
