// SPDX-License-Identifier: AGPL-3.0-or-later
// TetGen wrapper (see tetgen_backend.h). Implements docs/design.md §2.1, 3D: constrained Delaunay
// tetrahedralization of the free space, switches "pczQn", no hole points.
#include "tetgen_backend.h"

#include <tetgen.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <new>
#include <system_error>
#include <thread>
#include <spawn.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

namespace aggrelod::detail {
namespace {

// ---- the child's result, streamed over a pipe -------------------------------------
// Each array goes as a 64-bit element count followed by the elements. The parent reads
// them straight into the destination vectors: no intermediate buffer, no second copy.
bool writeAll(int fd, const void* data, size_t size) {
    const char* p = static_cast<const char*>(data);
    bool socket = true;
    while (size > 0) {
        // To a socket with MSG_NOSIGNAL: a helper that died must give an error here, not
        // SIGPIPE the bake. A pipe (the forked child's) takes write().
        ssize_t n = socket ? ::send(fd, p, size, MSG_NOSIGNAL) : ::write(fd, p, size);
        if (n < 0 && socket && errno == ENOTSOCK) {
            socket = false;
            continue;
        }
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;
        p += n;
        size -= static_cast<size_t>(n);
    }
    return true;
}

template <class T>
bool writeArray(int fd, const T* data, size_t count) {
    uint64_t n = count;
    return writeAll(fd, &n, sizeof n) && (count == 0 || writeAll(fd, data, count * sizeof(T)));
}

bool readAll(int fd, void* data, size_t size) {
    char* p = static_cast<char*>(data);
    while (size > 0) {
        ssize_t n = ::read(fd, p, size);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return false;  // end of stream before the whole result: the child died
        p += n;
        size -= static_cast<size_t>(n);
    }
    return true;
}

template <class T>
bool readArray(int fd, std::vector<T>& out) {
    uint64_t n = 0;
    if (!readAll(fd, &n, sizeof n)) return false;
    if (n > (uint64_t(1) << 36) / sizeof(T)) return false;  // no mesh is 64 GiB: a garbled stream
    out.resize(static_cast<size_t>(n));
    return n == 0 || readAll(fd, out.data(), static_cast<size_t>(n) * sizeof(T));
}

TetgenStatus statusFromCode(int code) {
    switch (code) {
        case 0: return TetgenStatus::Ok;
        case 1: return TetgenStatus::OutOfMemory;
        case 3: return TetgenStatus::SelfIntersection;
        case 4:
        case 5: return TetgenStatus::ToleranceError;
        case 10: return TetgenStatus::InputError;
        default: return TetgenStatus::InternalError;
    }
}

// Points a tetgenio at the PLC, for the child process only: the point, vertex and marker
// arrays alias the PLC's vectors (the child's private copy-on-write view of them) and all
// polygons share one block, so no per-facet allocation. TetGen only reads its input. The
// tetgenio must never be destroyed (its destructor would delete[] the aliased arrays): the
// child leaks it and ends with _exit.
tetgenio& tetgenInputForChild(const PlcInput& plc) {
    tetgenio& in = *new tetgenio;
    in.firstnumber = 0;
    in.numberofpoints = static_cast<int>(plc.points.size() / 3);
    in.pointlist = const_cast<REAL*>(plc.points.data());
    const int faceCount = static_cast<int>(plc.triangles.size() / 3);
    in.numberoffacets = faceCount;
    in.facetlist = new tetgenio::facet[faceCount];
    in.facetmarkerlist = const_cast<int*>(plc.triangleMarkers.data());
    tetgenio::polygon* polygons = new tetgenio::polygon[faceCount];
    for (int f = 0; f < faceCount; ++f) {
        tetgenio::facet& facet = in.facetlist[f];
        tetgenio::init(&facet);
        facet.numberofpolygons = 1;
        facet.polygonlist = &polygons[f];
        tetgenio::init(&polygons[f]);
        polygons[f].numberofvertices = 3;
        polygons[f].vertexlist = const_cast<int*>(&plc.triangles[3 * static_cast<size_t>(f)]);
    }
    return in;
}

// Reaps a child that has delivered its whole result without waiting for it: its exit (the
// kernel freeing a few hundred MB) then overlaps with this process's next work.
void reapInBackground(pid_t pid) {
    int wstatus = 0;
    if (::waitpid(pid, &wstatus, WNOHANG) != 0) return;  // already gone (or not our child)
    auto reap = [pid] {
        int status = 0;
        while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
        }
    };
    try {
        std::thread(reap).detach();
    } catch (const std::system_error&) {
        reap();  // no thread to be had: wait here
    }
}

// Address space the process has mapped now (bytes), 0 when unknown. Read without allocating.
[[maybe_unused]] uint64_t mappedBytes() {
    int fd = ::open("/proc/self/statm", O_RDONLY | O_CLOEXEC);
    if (fd < 0) return 0;
    char text[64] = {};
    const ssize_t n = ::read(fd, text, sizeof text - 1);
    ::close(fd);
    if (n <= 0) return 0;
    return std::strtoull(text, nullptr, 10) * static_cast<uint64_t>(::sysconf(_SC_PAGESIZE));
}

// In the child: CPU time (SIGXCPU at the soft limit, SIGKILL at the hard one) and address
// space beyond what the fork inherited (allocations past it fail: TetGen reports out of
// memory). AddressSanitizer maps terabytes of shadow up front, so there only CPU is bounded.
void limitChild(double cpuSeconds, uint64_t memoryBytes) {
    const rlim_t seconds = static_cast<rlim_t>(std::ceil(std::max(1.0, cpuSeconds)));
    const rlimit cpu{seconds, seconds + 5};
    ::setrlimit(RLIMIT_CPU, &cpu);
#if !defined(__SANITIZE_ADDRESS__)
    if (memoryBytes > 0) {
        const uint64_t limit = mappedBytes() + memoryBytes;
        const rlimit as{static_cast<rlim_t>(limit), static_cast<rlim_t>(limit)};
        ::setrlimit(RLIMIT_AS, &as);
    }
#else
    (void)memoryBytes;
#endif
}

// CPU time (user + system, clock ticks) a process has used so far; -1 when it cannot be read.
long long cpuTicksOf(pid_t pid) {
    char path[64];
    std::snprintf(path, sizeof path, "/proc/%d/stat", int(pid));
    const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
    if (fd < 0) return -1;
    char text[1024] = {};
    const ssize_t n = ::read(fd, text, sizeof text - 1);
    ::close(fd);
    if (n <= 0) return -1;
    // Fields after the command name, which is in parentheses and may contain spaces.
    const char* p = std::strrchr(text, ')');
    if (!p) return -1;
    char state = 0;
    unsigned long long utime = 0, stime = 0;
    if (std::sscanf(p + 1, " %c %*d %*d %*d %*d %*d %*u %*u %*u %*u %*u %llu %llu", &state, &utime, &stime) != 3)
        return -1;
    if (state == 'Z' || state == 'X') return -1;  // exited: nothing left to watch
    return static_cast<long long>(utime + stime);
}

// Kills a child that stops gaining CPU time for `hangSeconds` (a deadlock: blocked threads
// use no CPU, so RLIMIT_CPU never fires and the parent would wait for ever).
class HangWatchdog {
public:
    HangWatchdog(pid_t pid, double hangSeconds) : pid_(pid), hangSeconds_(hangSeconds) {
        try {
            thread_ = std::thread([this] { watch(); });
        } catch (const std::system_error&) {
            // No thread to be had: the CPU limit still bounds a busy child.
        }
    }
    ~HangWatchdog() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            done_ = true;
        }
        wake_.notify_all();
        if (thread_.joinable()) thread_.join();
    }
    bool fired() const { return fired_.load(); }

private:
    void watch() {
        using Clock = std::chrono::steady_clock;
        long long lastTicks = cpuTicksOf(pid_);
        Clock::time_point lastProgress = Clock::now();
        std::unique_lock<std::mutex> lock(mutex_);
        while (!done_) {
            wake_.wait_for(lock, std::chrono::milliseconds(200));
            if (done_) break;
            const long long ticks = cpuTicksOf(pid_);
            if (ticks < 0) break;  // gone (or a zombie the parent is about to reap)
            if (ticks != lastTicks) {
                lastTicks = ticks;
                lastProgress = Clock::now();
            } else if (std::chrono::duration<double>(Clock::now() - lastProgress).count() >= hangSeconds_) {
                fired_ = true;
                ::kill(pid_, SIGKILL);
                break;
            }
        }
    }

    pid_t pid_;
    double hangSeconds_;
    std::mutex mutex_;
    std::condition_variable wake_;
    bool done_ = false;
    std::atomic<bool> fired_{false};
    std::thread thread_;
};

// Fault injection for the watchdog's test: the first N children block for ever.
bool childShouldHangForTest(int attempt) {
    const char* value = std::getenv("AGGRELOD_TEST_TETGEN_HANGS");
    return value && attempt < std::atoi(value);
}

// What a TetGen process computes; the same code runs in the helper executable and in a
// forked child.
enum class Job : uint32_t { Tetrahedralize = 0, FindIntersections = 1 };

// The work of the TetGen process: writes the result (an int32 code, 0 = ok, then the arrays)
// to `fd`. Never returns its memory: the process ends with _exit right after.
void doJob(Job job, const PlcInput& plc, const std::string& extraSwitches, int fd) {
    tetgenio& in = tetgenInputForChild(plc);
    tetgenio& result = *new tetgenio;
    if (job == Job::FindIntersections) {
        char switches[] = "pdzQ";
        tetrahedralize(switches, &in, &result);
        int32_t ok = 0;
        writeAll(fd, &ok, sizeof ok) &&
            writeArray(fd, result.trifacemarkerlist, result.trifacemarkerlist ? static_cast<size_t>(result.numberoftrifaces) : 0);
        return;
    }
    if (const char* dump = std::getenv("AGGRELOD_DUMP_PLC")) {  // debugging aid
        in.save_nodes(const_cast<char*>(dump));
        in.save_poly(const_cast<char*>(dump));
    }
    std::string switches = "pczQn" + extraSwitches;
    tetrahedralize(&switches[0], &in, &result);
    const size_t tetCount = static_cast<size_t>(result.numberoftetrahedra);
    std::vector<double> regions(tetCount, -1.0);
    if (result.numberoftetrahedronattributes > 0) {
        for (size_t t = 0; t < tetCount; ++t)
            regions[t] = result.tetrahedronattributelist[t * result.numberoftetrahedronattributes];
    }
    int32_t ok = 0;
    writeAll(fd, &ok, sizeof ok) && writeArray(fd, result.pointlist, static_cast<size_t>(result.numberofpoints) * 3) &&
        writeArray(fd, result.tetrahedronlist, tetCount * 4) &&
        writeArray(fd, result.neighborlist, result.neighborlist ? tetCount * 4 : 0) &&
        writeArray(fd, regions.data(), regions.size()) &&
        writeArray(fd, result.trifacelist, static_cast<size_t>(result.numberoftrifaces) * 3) &&
        writeArray(fd, result.trifacemarkerlist, result.trifacemarkerlist ? static_cast<size_t>(result.numberoftrifaces) : 0);
}

// doJob, its errors turned into the result code (TetGen throws an int, see tetgen_terminate.cpp).
void doJobReportingErrors(Job job, const PlcInput& plc, const std::string& extraSwitches, int fd) {
    try {
        doJob(job, plc, extraSwitches, fd);
    } catch (const std::bad_alloc&) {
        int32_t c32 = 1;
        writeAll(fd, &c32, sizeof c32);
    } catch (int c) {
        int32_t c32 = c;
        writeAll(fd, &c32, sizeof c32);
    } catch (...) {
        int32_t c32 = 2;
        writeAll(fd, &c32, sizeof c32);
    }
}

// ---- the helper executable --------------------------------------------------------
// A fresh process started with posix_spawn holds no lock of this one (a forked child of a
// multi-threaded process may inherit an allocator or stdio lock held by another thread and
// deadlock on it). The request goes over a socket: the budget, the job, the switches, the PLC.

constexpr uint32_t kRequestMagic = 0x47544741u;  // "AGTG"

bool sendRequest(int fd, Job job, const PlcInput& plc, const std::string& extraSwitches, double cpuSeconds,
                 uint64_t memoryBytes) {
    const uint32_t head[2] = {kRequestMagic, static_cast<uint32_t>(job)};
    return writeAll(fd, head, sizeof head) && writeAll(fd, &cpuSeconds, sizeof cpuSeconds) &&
           writeAll(fd, &memoryBytes, sizeof memoryBytes) && writeArray(fd, extraSwitches.data(), extraSwitches.size()) &&
           writeArray(fd, plc.points.data(), plc.points.size()) && writeArray(fd, plc.triangles.data(), plc.triangles.size()) &&
           writeArray(fd, plc.triangleMarkers.data(), plc.triangleMarkers.size());
}

// The helper: AGGRELOD_TETGEN_HELPER when set (empty: none, fork instead), else
// aggrelod-tetgen beside the running executable, else the one of the build tree.
const std::string& helperPath() {
    static const std::string path = [] {
        if (const char* given = std::getenv("AGGRELOD_TETGEN_HELPER")) return std::string(given);
        char exe[4096];
        const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (n > 0) {
            std::string beside(exe, static_cast<size_t>(n));
            beside = beside.substr(0, beside.find_last_of('/') + 1) + "aggrelod-tetgen";
            if (::access(beside.c_str(), X_OK) == 0) return beside;
        }
#ifdef AGGRELOD_TETGEN_HELPER_PATH
        if (::access(AGGRELOD_TETGEN_HELPER_PATH, X_OK) == 0) return std::string(AGGRELOD_TETGEN_HELPER_PATH);
#endif
        return std::string();
    }();
    return path;
}

// Starts the helper with its stdin on `requestFd`, fd 3 on `resultFd`, stdout on /dev/null.
pid_t spawnHelper(const std::string& helper, int requestFd, int resultFd, int attempt) {
    posix_spawn_file_actions_t actions;
    if (::posix_spawn_file_actions_init(&actions) != 0) return -1;
    ::posix_spawn_file_actions_adddup2(&actions, requestFd, STDIN_FILENO);
    ::posix_spawn_file_actions_adddup2(&actions, resultFd, 3);
    ::posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    const std::string parent = std::to_string(::getpid()), attemptText = std::to_string(attempt);
    const char* argv[] = {helper.c_str(), "--parent", parent.c_str(), "--attempt", attemptText.c_str(), nullptr};
    pid_t pid = -1;
    const int rc = ::posix_spawn(&pid, helper.c_str(), &actions, nullptr, const_cast<char* const*>(argv), environ);
    ::posix_spawn_file_actions_destroy(&actions);
    return rc == 0 ? pid : -1;
}

// Runs `job` in a separate process within the PLC's budget (the helper, or a forked child
// when there is none); `receive` reads the rest of an ok result in this process.
template <class Receive>
TetgenOutcome runIsolatedOnce(const PlcInput& plc, Job job, const std::string& extraSwitches, Receive& receive,
                              int attempt) {
    double cpuSeconds = plc.cpuSeconds;
    uint64_t memoryBytes = plc.memoryBytes;
    if (!(cpuSeconds > 0) || memoryBytes == 0) {
        double autoSeconds = 0;
        uint64_t autoBytes = 0;
        tetgenBudget(plc, autoSeconds, autoBytes);
        if (!(cpuSeconds > 0)) cpuSeconds = autoSeconds;
        if (memoryBytes == 0) memoryBytes = autoBytes;
    }
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) return {TetgenStatus::InternalError, std::string("pipe: ") + std::strerror(errno)};
    // A larger pipe buffer: the result (tens of MB) then crosses in fewer context switches.
    ::fcntl(fds[1], F_SETPIPE_SZ, 1 << 20);
    pid_t pid = -1;
    int requestFd = -1;
    const std::string& helper = helperPath();
    if (!helper.empty()) {
        int request[2];
        if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, request) == 0) {
            pid = spawnHelper(helper, request[1], fds[1], attempt);
            ::close(request[1]);
            if (pid > 0) requestFd = request[0];
            else ::close(request[0]);
        }
    }
    if (pid <= 0) {
        // No helper: a forked child (the watchdog below still catches a hang).
        std::fflush(nullptr);
        const pid_t parent = ::getpid();
        pid = ::fork();
        if (pid < 0) {
            ::close(fds[0]);
            ::close(fds[1]);
            return {TetgenStatus::InternalError, std::string("fork: ") + std::strerror(errno)};
        }
        if (pid == 0) {
            ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a parent that dies takes TetGen with it
            if (::getppid() != parent) ::_exit(0);  // the parent died before the line above
            ::close(fds[0]);
            int devnull = ::open("/dev/null", O_WRONLY);
            if (devnull >= 0) ::dup2(devnull, STDOUT_FILENO);  // TetGen prints to stdout
            limitChild(cpuSeconds, memoryBytes);
            if (childShouldHangForTest(attempt))
                for (;;) ::pause();
            doJobReportingErrors(job, plc, extraSwitches, fds[1]);
            ::close(fds[1]);
            ::_exit(0);  // no destructors, no atexit handlers of the parent's program
        }
    }
    ::close(fds[1]);
    int32_t code = -1;
    bool gotCode = false, complete = false, hung = false;
    {
        HangWatchdog watchdog(pid, plc.hangSeconds > 0 ? plc.hangSeconds : kDefaultHangSeconds);
        if (requestFd >= 0) {
            sendRequest(requestFd, job, plc, extraSwitches, cpuSeconds, memoryBytes);  // a failure shows below
            ::close(requestFd);
        }
        gotCode = readAll(fds[0], &code, sizeof code);
        complete = gotCode && code == 0 && receive(fds[0]);
        hung = watchdog.fired();
    }
    ::close(fds[0]);
    if (complete && !hung) {
        reapInBackground(pid);
        return {};
    }
    int wstatus = 0;
    rusage usage{};
    while (::wait4(pid, &wstatus, 0, &usage) < 0 && errno == EINTR) {
    }
    if (hung)
        return {TetgenStatus::Hung, "TetGen's process made no progress for " +
                                        std::to_string(static_cast<long long>(plc.hangSeconds > 0 ? plc.hangSeconds
                                                                                                   : kDefaultHangSeconds)) +
                                        " s (hung) and was stopped"};
    std::string signal;
    if (WIFSIGNALED(wstatus))
        signal = std::string(" (signal ") + std::to_string(WTERMSIG(wstatus)) + ": " + strsignal(WTERMSIG(wstatus)) + ")";
    const double used = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) + 1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    if (WIFSIGNALED(wstatus) && (WTERMSIG(wstatus) == SIGXCPU || (WTERMSIG(wstatus) == SIGKILL && used >= cpuSeconds)))
        return {TetgenStatus::OverBudget, "TetGen used up its budget of " + std::to_string(static_cast<long long>(std::ceil(cpuSeconds))) +
                                              " CPU seconds and was stopped (" + std::to_string(plc.triangles.size() / 3) +
                                              " input triangles)"};
    if (!gotCode) return {TetgenStatus::Crashed, "TetGen stopped without a result" + signal};
    if (code == 1)
        return {TetgenStatus::OutOfMemory, "TetGen ran out of memory (budget " + std::to_string(memoryBytes >> 20) + " MiB)"};
    if (code != 0) return {statusFromCode(code), "TetGen reported error code " + std::to_string(code)};
    return {TetgenStatus::Crashed, "TetGen's result was cut short" + signal};
}

// A hung process is most likely a fork-time lock race (no helper): transient, so one more
// is tried before the hang is reported.
template <class Receive>
TetgenOutcome runIsolated(const PlcInput& plc, Job job, const std::string& extraSwitches, Receive receive) {
    TetgenOutcome outcome = runIsolatedOnce(plc, job, extraSwitches, receive, 0);
    if (outcome.status == TetgenStatus::Hung) outcome = runIsolatedOnce(plc, job, extraSwitches, receive, 1);
    return outcome;
}

}  // namespace

void tetgenBudget(const PlcInput& input, double& cpuSeconds, uint64_t& memoryBytes) {
    cpuSeconds = 120.0 + 5e-4 * double(input.triangles.size() / 3);
    const long pages = ::sysconf(_SC_PHYS_PAGES);
    const long pageSize = ::sysconf(_SC_PAGESIZE);
    memoryBytes = pages > 0 && pageSize > 0 ? static_cast<uint64_t>(pages) * static_cast<uint64_t>(pageSize) / 2 : (uint64_t(8) << 30);
}

const char* tetgenStatusName(TetgenStatus status) {
    switch (status) {
        case TetgenStatus::Ok: return "ok";
        case TetgenStatus::SelfIntersection: return "input facets intersect";
        case TetgenStatus::InputError: return "invalid input";
        case TetgenStatus::ToleranceError: return "points or facets too close for TetGen's tolerance";
        case TetgenStatus::OutOfMemory: return "out of memory";
        case TetgenStatus::InternalError: return "internal error";
        case TetgenStatus::Crashed: return "triangulator crashed";
        case TetgenStatus::OverBudget: return "triangulator over its time budget";
        case TetgenStatus::Hung: return "triangulator hung";
    }
    return "unknown";
}

TetgenOutcome tetrahedralizePlc(const PlcInput& input, TetMesh& out, const char* extraSwitches) {
    TetgenOutcome outcome = runIsolated(input, Job::Tetrahedralize, extraSwitches ? extraSwitches : "", [&](int fd) {
        return readArray(fd, out.points) && readArray(fd, out.tets) && readArray(fd, out.neighbors) &&
               readArray(fd, out.regions) && readArray(fd, out.boundaryFaces) && readArray(fd, out.boundaryMarkers);
    });
    if (outcome.status != TetgenStatus::Ok) return outcome;
    if (out.neighbors.size() != out.tets.size()) return {TetgenStatus::InternalError, "TetGen gave no neighbours"};
    if (out.boundaryMarkers.size() != out.boundaryFaces.size() / 3) out.boundaryMarkers.assign(out.boundaryFaces.size() / 3, 0);
    return outcome;
}

TetgenOutcome findIntersectingFacets(const PlcInput& input, std::vector<int>& intersectingMarkers) {
    std::vector<int> markers;
    TetgenOutcome outcome = runIsolated(input, Job::FindIntersections, "", [&](int fd) { return readArray(fd, markers); });
    if (outcome.status != TetgenStatus::Ok) return outcome;
    std::sort(markers.begin(), markers.end());
    markers.erase(std::unique(markers.begin(), markers.end()), markers.end());
    intersectingMarkers = markers;
    return outcome;
}

int tetgenHelperMain(int argc, char** argv) {
    long parent = -1;
    int attempt = 0;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (std::strcmp(argv[i], "--parent") == 0) parent = std::strtol(argv[i + 1], nullptr, 10);
        if (std::strcmp(argv[i], "--attempt") == 0) attempt = std::atoi(argv[i + 1]);
    }
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a parent that dies takes TetGen with it
    if (parent > 0 && ::getppid() != pid_t(parent)) return 0;  // it died before the line above
    uint32_t head[2] = {0, 0};
    double cpuSeconds = 0;
    uint64_t memoryBytes = 0;
    std::vector<char> switches;
    PlcInput plc;
    if (!readAll(STDIN_FILENO, head, sizeof head) || head[0] != kRequestMagic || head[1] > 1 ||
        !readAll(STDIN_FILENO, &cpuSeconds, sizeof cpuSeconds) || !readAll(STDIN_FILENO, &memoryBytes, sizeof memoryBytes) ||
        !readArray(STDIN_FILENO, switches) || !readArray(STDIN_FILENO, plc.points) ||
        !readArray(STDIN_FILENO, plc.triangles) || !readArray(STDIN_FILENO, plc.triangleMarkers)) {
        std::fprintf(stderr, "aggrelod-tetgen: incomplete request (this program is started by aggrelod)\n");
        return 2;
    }
    limitChild(cpuSeconds, memoryBytes);
    if (childShouldHangForTest(attempt))
        for (;;) ::pause();
    doJobReportingErrors(static_cast<Job>(head[1]), plc, std::string(switches.begin(), switches.end()), 3);
    ::close(3);
    ::_exit(0);
}

}  // namespace aggrelod::detail
