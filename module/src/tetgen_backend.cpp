// TetGen wrapper (see tetgen_backend.h). Implements DESIGN 2.1, 3D: constrained Delaunay
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
#include <sys/prctl.h>
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
    while (size > 0) {
        ssize_t n = ::write(fd, p, size);
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
uint64_t mappedBytes() {
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

// Runs `work` in a child process within the PLC's budget; it writes its result (starting with
// an int32 code, 0 = ok) to the fd it gets. `receive` reads the rest of an ok result in this
// process.
template <class Work, class Receive>
TetgenOutcome runIsolatedOnce(const PlcInput& plc, Work& work, Receive& receive, int attempt) {
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
    std::fflush(nullptr);
    const pid_t parent = ::getpid();
    pid_t pid = ::fork();
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
        try {
            work(fds[1]);
        } catch (const std::bad_alloc&) {
            int32_t c32 = 1;
            writeAll(fds[1], &c32, sizeof c32);
        } catch (int c) {
            int32_t c32 = c;
            writeAll(fds[1], &c32, sizeof c32);
        } catch (...) {
            int32_t c32 = 2;
            writeAll(fds[1], &c32, sizeof c32);
        }
        ::close(fds[1]);
        ::_exit(0);  // no destructors, no atexit handlers of the parent's program
    }
    ::close(fds[1]);
    int32_t code = -1;
    bool gotCode = false, complete = false, hung = false;
    {
        HangWatchdog watchdog(pid, plc.hangSeconds > 0 ? plc.hangSeconds : kDefaultHangSeconds);
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

// A hung child is most likely a lock another thread held when it was forked: a transient
// race, so one more child is tried before the hang is reported.
template <class Work, class Receive>
TetgenOutcome runIsolated(const PlcInput& plc, Work work, Receive receive) {
    TetgenOutcome outcome = runIsolatedOnce(plc, work, receive, 0);
    if (outcome.status == TetgenStatus::Hung) outcome = runIsolatedOnce(plc, work, receive, 1);
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
    TetgenOutcome outcome = runIsolated(
        input,
        [&](int fd) {
            // Never freed: the child ends with _exit right after sending the result.
            tetgenio& in = tetgenInputForChild(input);
            tetgenio& result = *new tetgenio;
            if (const char* dump = std::getenv("AGGRELOD_DUMP_PLC")) {  // debugging aid
                in.save_nodes(const_cast<char*>(dump));
                in.save_poly(const_cast<char*>(dump));
            }
            std::string switches = std::string("pczQn") + (extraSwitches ? extraSwitches : "");
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
        },
        [&](int fd) {
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
    TetgenOutcome outcome = runIsolated(
        input,
        [&](int fd) {
            tetgenio& in = tetgenInputForChild(input);  // never freed: see tetrahedralizePlc
            tetgenio& result = *new tetgenio;
            char switches[] = "pdzQ";
            tetrahedralize(switches, &in, &result);
            int32_t ok = 0;
            writeAll(fd, &ok, sizeof ok) &&
                writeArray(fd, result.trifacemarkerlist, result.trifacemarkerlist ? static_cast<size_t>(result.numberoftrifaces) : 0);
        },
        [&](int fd) { return readArray(fd, markers); });
    if (outcome.status != TetgenStatus::Ok) return outcome;
    std::sort(markers.begin(), markers.end());
    markers.erase(std::unique(markers.begin(), markers.end()), markers.end());
    intersectingMarkers = markers;
    return outcome;
}

}  // namespace aggrelod::detail
