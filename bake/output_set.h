// SPDX-License-Identifier: AGPL-3.0-or-later
// The output set of `aggrelod bake` (levels.glb, proxies.glb, scene.aglod, tiles/, a --stats
// file) and its manifest OUTDIR/aggrelod-set.json, written last, which names the size and the
// SHA-256 of every file of the set. A reader that goes through the manifest never sees a mixed
// set: while a bake moves its files into place (or after one was killed while doing so) the
// manifest names the previous set's files, kept in the bake's temporary folder; the new set
// is switched in by one rename of the manifest. See docs/outputs.md, "The output set and its manifest".
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace aggrelod::io {

/// The manifest's file name in OUTDIR.
constexpr const char* kSetManifestName = "aggrelod-set.json";

struct SetManifestFile {
    std::string name;    ///< place in the set, relative to OUTDIR with '/' ("levels.glb", "tiles/tileset.json")
    uint64_t size = 0;   ///< bytes
    std::string sha256;  ///< 64 lower-case hex digits
    std::string at;      ///< where its bytes are, relative to OUTDIR, when not at `name` (a commit in progress)
};

struct SetManifest {
    std::vector<SetManifestFile> files;
};

std::string formatSetManifest(const SetManifest& manifest);
bool parseSetManifest(const std::string& text, SetManifest& manifest, std::string& error);

/// SHA-256 of a file's bytes as 64 hex digits, and its size.
bool sha256File(const std::filesystem::path& path, std::string& hex, uint64_t& size, std::string& error);
std::string sha256Hex(const void* data, size_t size);

/// What a reader finds in OUTDIR.
struct SetCheck {
    enum class Status {
        Complete,    ///< every file the manifest names is there with its size and hash
        NoManifest,  ///< no OUTDIR/aggrelod-set.json (not a bake's output, or one of an older version)
        Incomplete,  ///< the manifest does not parse, or a file it names is missing or differs
    } status = Status::NoManifest;
    std::string problem;  ///< for Incomplete
    /// For Complete: each file of the set (manifest name) and where to read it.
    std::vector<std::pair<std::string, std::filesystem::path>> files;
    /// For Complete: some file of the set is not at its name (a bake is replacing the set, or
    /// was killed while doing so; the files at the names may be a mix until the next bake).
    bool moved = false;
};

/// Reads OUTDIR's manifest and checks every file it names (size and SHA-256). When the check
/// fails while the manifest changed under it (a bake switched sets meanwhile) it starts again.
SetCheck checkOutputSet(const std::filesystem::path& outDir);

/// Removes the temporary folders of bakes into OUTDIR that are no longer running (killed, or
/// the machine stopped), after undoing a commit they were killed in, and the fixed-name
/// temporaries of older versions.
void removeStaleTemporaries(const std::filesystem::path& outDir);

/// The files of one bake: each written into a fresh private folder inside OUTDIR (created
/// exclusively, so nothing can be planted in it), synced, then committed.
class OutputSet {
public:
    OutputSet() = default;
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;
    ~OutputSet();

    /// Removes stale temporaries, then creates the private folder.
    bool begin(const std::filesystem::path& outDir, std::string& error);

    /// A new empty temporary for `final` (OUTDIR/name, or a file elsewhere such as --stats).
    bool addFile(const std::filesystem::path& final, std::filesystem::path& temporary, std::string& error);

    /// A folder (the 3D Tiles tileset), written whole into the returned path by the caller.
    std::filesystem::path folderTemporary(const std::filesystem::path& final);

    /// A file of the bake's own in the private folder (scratch: never committed, removed with
    /// the folder). begin() first.
    std::filesystem::path scratchFile(const std::string& name) const { return tempDir_ / name; }

    /// Syncs every temporary, writes the new manifest, keeps the old files reachable and points
    /// the manifest at them, moves the new files into place, then switches the manifest to the
    /// new set with one rename. On a failure the set as it was is put back.
    bool commit(std::string& error);

private:
    struct Entry {
        std::filesystem::path temporary, final;
        bool folder;
    };
    std::filesystem::path outDir_, tempDir_;
    std::vector<Entry> entries_;
    std::vector<std::filesystem::path> outsideTemporaries_;
};

}  // namespace aggrelod::io
