// SPDX-License-Identifier: AGPL-3.0-or-later
// The output set of a bake and its manifest (output_set.h).
//
// A commit, in this order (each step leaves one complete set for a reader of the manifest):
//  1. every temporary is synced; the new manifest is written into the temporary folder;
//  2. the journal lists every output (whether an old version existed, the name of its backup,
//     the final path), then each old version gets a backup in the temporary folder: a second
//     name (hard link; a copy across file systems; a tree of them for tiles/) - nothing in
//     OUTDIR has changed yet;
//  3. the old manifest, with each replaced file named at its backup ("at"), takes the place of
//     the manifest (one rename): the old set stays complete through the moves;
//  4. each new file is renamed into place (tiles/ first moved aside);
//  5. the new manifest takes the place of the manifest (one rename): the new set is switched
//     in; then "committed" ends the journal.
// A bake killed before step 5 is undone by the next bake into OUTDIR (removeStaleTemporaries):
// the backups go back to their names, then the old manifest; a bake killed after it is not.
// Commits and that clean-up hold an exclusive lock on OUTDIR (flock), so that two bakes into
// one OUTDIR do not interleave their moves.
#include "output_set.h"
#include "json.h"
#include "sha256.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

namespace aggrelod::io {
namespace {

namespace fs = std::filesystem;

/// Prefix of the temporary folders; the rest is "<pid>-<random>".
constexpr const char* kTempPrefix = ".aggrelod-tmp-";

/// The journal of a commit in its temporary folder: one line per output ("1" or "0" for
/// whether an old version existed, the name of its backup in the folder, the final path,
/// tab-separated), written and synced before any backup is made, then a line "committed"
/// after the new manifest took its place.
constexpr const char* kJournal = "journal";
/// In the temporary folder: the new manifest, and a second name of the old one.
constexpr const char* kNewManifest = "manifest";
constexpr const char* kOldManifest = "old-manifest";

// --- small file-system helpers ----------------------------------------------------------------

bool syncPath(const fs::path& p, std::string& error) {
    const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0 || ::fsync(fd) != 0) {
        error = p.string() + ": cannot sync: " + std::strerror(errno);
        if (fd >= 0) ::close(fd);
        return false;
    }
    ::close(fd);
    return true;
}

/// Syncs every file and folder of the tree `dir`, `dir` last.
bool syncTree(const fs::path& dir, std::string& error) {
    std::error_code ec;
    for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::file_status s = it->symlink_status(ec);
        if (ec) break;
        if ((fs::is_regular_file(s) || fs::is_directory(s)) && !syncPath(it->path(), error)) return false;
    }
    if (ec) {
        error = dir.string() + ": cannot list: " + ec.message();
        return false;
    }
    return syncPath(dir, error);
}

/// Creates an empty file that did not exist, never through a symbolic link.
bool createExclusive(const fs::path& p, std::string& error) {
    const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
        error = p.string() + ": cannot create: " + std::strerror(errno);
        return false;
    }
    ::close(fd);
    return true;
}

/// Writes `text` into the new file `p` (created exclusively) and syncs it.
bool writeNewFile(const fs::path& p, const std::string& text, std::string& error) {
    const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
        error = p.string() + ": cannot create: " + std::strerror(errno);
        return false;
    }
    size_t done = 0;
    while (done < text.size()) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        done += size_t(n);
    }
    const bool ok = done == text.size() && ::fsync(fd) == 0;
    if (!ok) error = p.string() + ": cannot write: " + std::strerror(errno);
    ::close(fd);
    return ok;
}

/// The content of a regular file (not through a symbolic link), or false.
bool readSmallFile(const fs::path& p, std::string& text) {
    const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) return false;
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size > (64 << 20)) {
        ::close(fd);
        return false;
    }
    text.clear();
    char buffer[65536];
    for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) != 0;) {
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            ::close(fd);
            return false;
        }
        text.append(buffer, size_t(n));
    }
    ::close(fd);
    return true;
}

/// A second name `to` for the file `from` (a hard link, or a copy where links do not work).
bool linkOrCopy(const fs::path& from, const fs::path& to) {
    if (::link(from.c_str(), to.c_str()) == 0) return true;
    std::error_code ec;
    return fs::copy_file(from, to, fs::copy_options::none, ec) && !ec;
}

/// A tree `to` of second names for the files of the tree `from` (folders made anew, symbolic
/// links copied as links, never followed).
bool linkTree(const fs::path& from, const fs::path& to) {
    std::error_code ec;
    if (!fs::create_directory(to, ec) || ec) return false;
    for (fs::recursive_directory_iterator it(from, ec), end; !ec && it != end; it.increment(ec)) {
        const fs::path target = to / fs::relative(it->path(), from, ec);
        if (ec) return false;
        const fs::file_status s = it->symlink_status(ec);
        if (fs::is_directory(s)) {
            if (!fs::create_directory(target, ec) || ec) return false;
        } else if (fs::is_symlink(s)) {
            fs::copy_symlink(it->path(), target, ec);
            if (ec) return false;
        } else if (fs::is_regular_file(s)) {
            if (!linkOrCopy(it->path(), target)) return false;
        }
    }
    return !ec;
}

/// An exclusive lock on the folder (released when the process ends, killed or not).
class FolderLock {
public:
    explicit FolderLock(const fs::path& dir) : fd_(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)) {
        if (fd_ >= 0)
            while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
            }
    }
    ~FolderLock() {
        if (fd_ >= 0) ::close(fd_);
    }
    FolderLock(const FolderLock&) = delete;
    FolderLock& operator=(const FolderLock&) = delete;

private:
    int fd_;
};

/// A relative path with '/' and no empty, "." or ".." component.
bool isPlainRelative(const std::string& p) {
    if (p.empty() || p.front() == '/' || p.back() == '/' || p.find('\0') != std::string::npos) return false;
    std::stringstream parts(p);
    for (std::string part; std::getline(parts, part, '/');)
        if (part.empty() || part == "." || part == "..") return false;
    return true;
}

// --- the manifest as JSON -----------------------------------------------------------------------

/// Reads the manifest from parsed JSON: "format", "version" 1 and "files"; other keys are
/// ignored. Every file's name (and "at") must be a plain path inside the folder.
bool manifestFromJson(const Json& j, SetManifest& manifest, std::string& error) {
    const auto fail = [&](const std::string& what) {
        error = what;
        manifest.files.clear();
        return false;
    };
    if (!j.is_object()) return fail("the manifest is not a JSON object");
    const auto format = j.find("format"), version = j.find("version"), files = j.find("files");
    if (format == j.end() || files == j.end()) return fail("no \"format\" or no \"files\"");
    if (*format != "aggrelod-set") return fail("\"format\" is not \"aggrelod-set\"");
    if (version != j.end()) {
        if (!version->is_number_unsigned()) return fail("\"version\" is not a non-negative integer");
        if (*version != 1) return fail("version " + version->dump() + ", this reader reads 1");
    }
    if (!files->is_array()) return fail("\"files\" is not an array");
    for (const Json& entry : *files) {
        if (!entry.is_object()) return fail("a file entry is not an object");
        const auto name = entry.find("name"), size = entry.find("size"), hash = entry.find("sha256"), at = entry.find("at");
        if (name == entry.end() || size == entry.end() || hash == entry.end())
            return fail("a file without \"name\", \"size\" or \"sha256\"");
        if (!name->is_string() || !hash->is_string() || (at != entry.end() && !at->is_string()))
            return fail("a file whose \"name\", \"sha256\" or \"at\" is not a string");
        if (!size->is_number_unsigned()) return fail("a file whose \"size\" is not a non-negative integer");
        SetManifestFile f;
        f.name = name->get<std::string>();
        f.size = size->get<uint64_t>();
        f.sha256 = hash->get<std::string>();
        if (at != entry.end()) f.at = at->get<std::string>();
        if (!isPlainRelative(f.name) || (!f.at.empty() && !isPlainRelative(f.at)))
            return fail("\"" + f.name + "\": not a path inside the folder");
        if (f.sha256.size() != 64 || f.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
            return fail("\"" + f.name + "\": \"sha256\" is not 64 lower-case hex digits");
        manifest.files.push_back(std::move(f));
    }
    return true;
}

// --- undoing a commit -------------------------------------------------------------------------

std::string manifestPath(const fs::path& outDir) { return (outDir / kSetManifestName).string(); }

/// Gives `final` the content of `backup` with one rename, keeping `backup` (a manifest may
/// name it): a second name made in the temporary folder, or beside `final` when that lies on
/// another file system.
void restoreFile(const fs::path& tempDir, const fs::path& backup, const fs::path& final, const std::string& tag) {
    std::error_code ec;
    const fs::path here = tempDir / ("restore-" + tag);
    fs::remove(here, ec);
    if (linkOrCopy(backup, here) && ::rename(here.c_str(), final.c_str()) == 0) return;
    fs::remove(here, ec);
    fs::path beside = final;
    beside += "." + tempDir.filename().string() + "-restore";
    fs::remove(beside, ec);
    if (linkOrCopy(backup, beside) && ::rename(beside.c_str(), final.c_str()) == 0) return;
    fs::remove(beside, ec);
}

/// Puts the old set back from the journal of the commit in `tempDir`, unless it reached the
/// new manifest (or `force`: the commit itself failed and rolls back).
void undoCommit(const fs::path& outDir, const fs::path& tempDir, bool force) {
    std::ifstream journal(tempDir / kJournal);
    if (!journal) return;  // never started: nothing in OUTDIR changed
    std::vector<std::array<std::string, 3>> moves;
    for (std::string line; std::getline(journal, line);) {
        if (line == "committed") return;  // the new set is complete
        const size_t a = line.find('\t'), b = line.find('\t', a == std::string::npos ? a : a + 1);
        if (a == std::string::npos || b == std::string::npos) break;  // cut short: written last
        moves.push_back({line.substr(0, a), line.substr(a + 1, b - a - 1), line.substr(b + 1)});
    }
    std::string published, written;
    if (!force && readSmallFile(outDir / kSetManifestName, published) &&
        readSmallFile(tempDir / kNewManifest, written) && published == written)
        return;  // killed after switching the manifest, before the journal's last line
    std::error_code ec;
    for (auto m = moves.rbegin(); m != moves.rend(); ++m) {
        const fs::path backup = tempDir / (*m)[1], final = (*m)[2];
        if ((*m)[0] != "1") {
            fs::remove_all(final, ec);  // no old version: what the bake moved there goes
            continue;
        }
        const fs::file_status s = fs::symlink_status(backup, ec);
        if (!fs::exists(s)) continue;  // no backup made yet: the old one was not touched
        if (fs::is_directory(s)) {
            const fs::path restore = tempDir / ("restore-" + (*m)[1]), aside = tempDir / ("undone-" + (*m)[1]);
            fs::remove_all(restore, ec);
            if (!linkTree(backup, restore)) continue;
            fs::remove_all(aside, ec);
            if (fs::exists(fs::symlink_status(final, ec)) && ::rename(final.c_str(), aside.c_str()) != 0)
                fs::remove_all(final, ec);
            ::rename(restore.c_str(), final.c_str());
        } else {
            restoreFile(tempDir, backup, final, (*m)[1]);
        }
    }
    // Then the manifest as it was (the old set is back at its names).
    const fs::path oldManifest = tempDir / kOldManifest, restore = tempDir / "restore-manifest";
    fs::remove(restore, ec);
    if (fs::exists(fs::symlink_status(oldManifest, ec)) && linkOrCopy(oldManifest, restore))
        ::rename(restore.c_str(), manifestPath(outDir).c_str());
    std::string ignored;
    syncPath(outDir, ignored);
}

/// The step counter of the fault-injection test (tests/unit/test_output_set.cpp): with
/// AGGRELOD_TEST_KILL_AFTER_COMMIT_STEP=K set, a commit kills its own process (SIGKILL) right
/// after its K-th step. Unset (or not a positive number), nothing happens.
class KillSwitch {
public:
    KillSwitch() {
        const char* v = std::getenv("AGGRELOD_TEST_KILL_AFTER_COMMIT_STEP");
        killAfter_ = v ? std::strtol(v, nullptr, 10) : 0;
    }
    void step() {
        if (killAfter_ > 0 && ++steps_ == killAfter_) ::raise(SIGKILL);
    }

private:
    long killAfter_ = 0, steps_ = 0;
};

}  // namespace

// --- public ---------------------------------------------------------------------------------

std::string sha256Hex(const void* data, size_t size) {
    Sha256 h;
    h.update(static_cast<const unsigned char*>(data), size);
    return h.hex();
}

bool sha256File(const fs::path& path, std::string& hex, uint64_t& size, std::string& error) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) {
        error = path.string() + ": cannot open: " + std::strerror(errno);
        return false;
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        error = path.string() + ": not a regular file";
        ::close(fd);
        return false;
    }
    Sha256 h;
    std::vector<unsigned char> buffer(1 << 20);
    size = 0;
    for (ssize_t n; (n = ::read(fd, buffer.data(), buffer.size())) != 0;) {
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            error = path.string() + ": cannot read: " + std::strerror(errno);
            ::close(fd);
            return false;
        }
        h.update(buffer.data(), size_t(n));
        size += uint64_t(n);
    }
    ::close(fd);
    hex = h.hex();
    return true;
}

std::string formatSetManifest(const SetManifest& manifest) {
    Json j;
    j["format"] = "aggrelod-set";
    j["version"] = 1;
    Json files = Json::array();
    for (const SetManifestFile& f : manifest.files) {
        Json entry;
        entry["name"] = f.name;
        entry["size"] = f.size;
        entry["sha256"] = f.sha256;
        if (!f.at.empty()) entry["at"] = f.at;
        files.push_back(std::move(entry));
    }
    j["files"] = std::move(files);
    return jsonText(j);
}

bool parseSetManifest(const std::string& text, SetManifest& manifest, std::string& error) {
    manifest.files.clear();
    Json j;
    if (!parseJson(text, j, error, 16)) return false;
    return manifestFromJson(j, manifest, error);
}

SetCheck checkOutputSet(const fs::path& outDir) {
    SetCheck check;
    std::string text;
    for (int attempt = 0; attempt < 5; ++attempt) {
        check = SetCheck();
        std::error_code ec;
        const fs::path path = outDir / kSetManifestName;
        if (!fs::exists(fs::symlink_status(path, ec))) return check;  // NoManifest
        check.status = SetCheck::Status::Incomplete;
        if (!readSmallFile(path, text)) {
            check.problem = path.string() + ": cannot read (not a regular file, or over 64 MiB)";
            return check;
        }
        SetManifest manifest;
        std::string error;
        if (!parseSetManifest(text, manifest, error)) {
            check.problem = path.string() + ": " + error;
            return check;
        }
        for (const SetManifestFile& f : manifest.files) {
            const fs::path file = outDir / (f.at.empty() ? f.name : f.at);
            std::string hex;
            uint64_t size = 0;
            if (!sha256File(file, hex, size, error)) {
                check.problem = f.name + ": " + error;
                break;
            }
            if (size != f.size || hex != f.sha256) {
                check.problem = f.name + ": " + (size != f.size ? std::to_string(size) + " bytes, the manifest says " +
                                                                      std::to_string(f.size)
                                                                : std::string("its SHA-256 differs from the manifest's"));
                break;
            }
            check.files.emplace_back(f.name, file);
            check.moved = check.moved || !f.at.empty();
        }
        if (check.problem.empty()) {
            check.status = SetCheck::Status::Complete;
            return check;
        }
        // A bake may have switched sets while the files were read: look again if so.
        std::string now;
        if (!readSmallFile(path, now) || now == text) return check;
    }
    return check;
}

void removeStaleTemporaries(const fs::path& outDir) {
    std::error_code ec;
    for (const char* legacy : {"levels.glb.tmp", "proxies.glb.tmp", "scene.aglod.tmp", "tiles.tmp", "tiles.old"})
        fs::remove_all(outDir / legacy, ec);  // a symbolic link is removed, not followed
    FolderLock lock(outDir);
    for (fs::directory_iterator it(outDir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.rfind(kTempPrefix, 0) != 0) continue;
        const long pid = std::strtol(name.c_str() + std::strlen(kTempPrefix), nullptr, 10);
        if (pid > 0 && (::kill(pid_t(pid), 0) == 0 || errno == EPERM)) continue;  // its bake still runs
        undoCommit(outDir, it->path(), false);
        std::error_code removeError;
        fs::remove_all(it->path(), removeError);
    }
}

OutputSet::~OutputSet() {
    std::error_code ec;
    for (const fs::path& p : outsideTemporaries_) fs::remove(p, ec);
    if (!tempDir_.empty()) fs::remove_all(tempDir_, ec);
}

bool OutputSet::begin(const fs::path& outDir, std::string& error) {
    outDir_ = outDir;
    removeStaleTemporaries(outDir);
    std::string pattern = (outDir / (kTempPrefix + std::to_string(::getpid()) + "-XXXXXX")).string();
    if (!::mkdtemp(pattern.data())) {
        error = outDir.string() + ": cannot create a temporary folder: " + std::strerror(errno);
        return false;
    }
    tempDir_ = pattern;
    return true;
}

bool OutputSet::addFile(const fs::path& final, fs::path& temporary, std::string& error) {
    const bool inOutDir = final.parent_path() == outDir_;
    if (inOutDir) {
        temporary = tempDir_ / final.filename();
    } else {
        // Elsewhere: beside its final place (a rename cannot cross file systems).
        temporary = final;
        temporary += "." + tempDir_.filename().string();
    }
    if (!createExclusive(temporary, error)) return false;
    if (!inOutDir) outsideTemporaries_.push_back(temporary);
    entries_.push_back({temporary, final, false});
    return true;
}

fs::path OutputSet::folderTemporary(const fs::path& final) {
    entries_.push_back({tempDir_ / final.filename(), final, true});
    return entries_.back().temporary;
}

bool OutputSet::commit(std::string& error) {
    // 1. Everything on disk, and the new manifest: every output inside OUTDIR, by its place.
    SetManifest manifest;
    std::vector<std::string> names(entries_.size());  // place in the set; empty: outside OUTDIR
    std::error_code ec;
    const fs::path outCanonical = fs::weakly_canonical(fs::absolute(outDir_, ec), ec);
    for (size_t k = 0; k < entries_.size(); ++k) {
        const Entry& e = entries_[k];
        if (!(e.folder ? syncTree(e.temporary, error) : syncPath(e.temporary, error))) return false;
        std::error_code ec1;  // the folder resolved, not the name (it may be a planted link)
        const fs::path parent = fs::weakly_canonical(fs::absolute(e.final, ec1).parent_path(), ec1);
        const fs::path rel = (parent / e.final.filename()).lexically_relative(outCanonical);
        if (!ec1 && isPlainRelative(rel.generic_string())) names[k] = rel.generic_string();
        if (names[k].empty()) continue;
        std::vector<std::pair<std::string, fs::path>> files;
        if (e.folder) {
            for (fs::recursive_directory_iterator it(e.temporary, ec), end; !ec && it != end; it.increment(ec))
                if (it->is_regular_file(ec))
                    files.emplace_back(names[k] + "/" + it->path().lexically_relative(e.temporary).generic_string(),
                                       it->path());
            std::sort(files.begin(), files.end());
        } else {
            files.emplace_back(names[k], e.temporary);
        }
        for (const auto& [name, path] : files) {
            SetManifestFile f;
            f.name = name;
            if (!sha256File(path, f.sha256, f.size, error)) return false;
            manifest.files.push_back(f);
        }
    }
    if (!writeNewFile(tempDir_ / kNewManifest, formatSetManifest(manifest), error) || !syncPath(tempDir_, error))
        return false;

    // Nothing can be replaced by a file of another kind (checked before anything changes).
    std::vector<bool> hadOld(entries_.size());
    for (size_t k = 0; k < entries_.size(); ++k) {
        const Entry& e = entries_[k];
        const fs::file_status s = fs::symlink_status(e.final, ec);
        hadOld[k] = fs::exists(s);
        if (hadOld[k] && fs::is_directory(s) != e.folder) {
            error = e.final.string() + ": cannot replace: it is " + (e.folder ? "not a folder" : "a folder");
            return false;
        }
    }

    FolderLock lock(outDir_);
    KillSwitch kill;
    const auto rollBack = [&](const std::string& message) {
        error = message;
        undoCommit(outDir_, tempDir_, true);
        return false;
    };

    // 2. The journal, then a backup of every old version.
    std::vector<std::string> backups(entries_.size());
    std::string lines;
    for (size_t k = 0; k < entries_.size(); ++k) {
        backups[k] = "old-" + std::to_string(k) + "-" + entries_[k].final.filename().string();
        lines += std::string(hadOld[k] ? "1" : "0") + "\t" + backups[k] + "\t" + fs::absolute(entries_[k].final, ec).string() + "\n";
    }
    if (!writeNewFile(tempDir_ / kJournal, lines, error)) return false;
    kill.step();
    SetManifest old;
    bool haveOld = false;
    {
        const fs::path path = outDir_ / kSetManifestName;
        if (fs::is_regular_file(fs::symlink_status(path, ec))) {
            if (!linkOrCopy(path, tempDir_ / kOldManifest))
                return rollBack(path.string() + ": cannot keep the old manifest: " + std::strerror(errno));
            kill.step();
            std::string text, ignored;
            haveOld = readSmallFile(tempDir_ / kOldManifest, text) && parseSetManifest(text, old, ignored);
        }
    }
    for (size_t k = 0; k < entries_.size(); ++k) {
        if (!hadOld[k]) continue;
        const Entry& e = entries_[k];
        const fs::path backup = tempDir_ / backups[k];
        if (!(e.folder ? linkTree(e.final, backup) : linkOrCopy(e.final, backup)))
            return rollBack(e.final.string() + ": cannot keep the old version: " + std::strerror(errno));
        kill.step();
    }

    // 3. The old manifest, naming the backups of the files about to be replaced.
    if (haveOld) {
        const std::string tempName = tempDir_.filename().string();
        for (SetManifestFile& f : old.files) {
            if (!f.at.empty()) continue;  // already elsewhere (a bake still running into OUTDIR)
            for (size_t k = 0; k < entries_.size(); ++k) {
                if (!hadOld[k] || names[k].empty()) continue;
                if (f.name == names[k] && !entries_[k].folder)
                    f.at = tempName + "/" + backups[k];
                else if (entries_[k].folder && f.name.rfind(names[k] + "/", 0) == 0)
                    f.at = tempName + "/" + backups[k] + f.name.substr(names[k].size());
            }
        }
        const fs::path redirect = tempDir_ / "redirect-manifest";
        if (!writeNewFile(redirect, formatSetManifest(old), error)) return rollBack(error);
        if (::rename(redirect.c_str(), manifestPath(outDir_).c_str()) != 0)
            return rollBack(manifestPath(outDir_) + ": cannot replace: " + std::strerror(errno));
        std::string ignored;
        syncPath(outDir_, ignored);
        kill.step();
    }

    // 4. The new files into place.
    for (size_t k = 0; k < entries_.size(); ++k) {
        const Entry& e = entries_[k];
        if (e.folder && hadOld[k]) {
            const fs::path aside = tempDir_ / ("replaced-" + std::to_string(k));
            if (::rename(e.final.c_str(), aside.c_str()) != 0)
                return rollBack(e.final.string() + ": cannot replace: " + std::strerror(errno));
            kill.step();
        }
        if (::rename(e.temporary.c_str(), e.final.c_str()) != 0)
            return rollBack(e.final.string() + ": cannot replace: " + std::strerror(errno));
        kill.step();
    }
    std::string ignored;
    syncPath(outDir_, ignored);
    for (size_t k = 0; k < entries_.size(); ++k)
        if (names[k].empty()) syncPath(entries_[k].final.parent_path().empty() ? "." : entries_[k].final.parent_path(), ignored);

    // 5. The new manifest: the new set is switched in.
    const fs::path publish = tempDir_ / "publish-manifest";
    if (!linkOrCopy(tempDir_ / kNewManifest, publish) || ::rename(publish.c_str(), manifestPath(outDir_).c_str()) != 0)
        return rollBack(manifestPath(outDir_) + ": cannot replace: " + std::strerror(errno));
    syncPath(outDir_, ignored);
    kill.step();
    const int journal = ::open((tempDir_ / kJournal).c_str(), O_WRONLY | O_APPEND | O_NOFOLLOW | O_CLOEXEC);
    if (journal >= 0) {
        if (::write(journal, "committed\n", 10) == 10) ::fdatasync(journal);
        ::close(journal);
    }
    kill.step();
    return true;
}

}  // namespace aggrelod::io
