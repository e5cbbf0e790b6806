// TetGen wrapper (see tetgen_backend.h). Implements DESIGN 2.1, 3D: constrained Delaunay
// tetrahedralization of the free space, switches "pczQn", no hole points.
#include "tetgen_backend.h"

#include <tetgen.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

namespace aggrelod::detail {
namespace {

// ---- a tiny byte stream over a pipe ------------------------------------------------
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

struct ByteReader {
    std::vector<char> bytes;
    size_t at = 0;
    bool ok = true;
    template <class T>
    bool readArray(std::vector<T>& out) {
        uint64_t n = 0;
        if (!take(&n, sizeof n)) return false;
        if (n > (bytes.size() - at) / sizeof(T)) return ok = false;
        out.resize(n);
        return n == 0 || take(out.data(), n * sizeof(T));
    }
    bool take(void* dst, size_t size) {
        if (bytes.size() - at < size) return ok = false;
        std::memcpy(dst, bytes.data() + at, size);
        at += size;
        return true;
    }
};

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

// Fills a tetgenio with the PLC. The arrays are owned by tetgenio (freed with delete[]).
void fillTetgenInput(const PlcInput& plc, tetgenio& in) {
    in.firstnumber = 0;
    in.numberofpoints = static_cast<int>(plc.points.size() / 3);
    in.pointlist = new REAL[plc.points.size()];
    std::memcpy(in.pointlist, plc.points.data(), plc.points.size() * sizeof(double));
    const int faceCount = static_cast<int>(plc.triangles.size() / 3);
    in.numberoffacets = faceCount;
    in.facetlist = new tetgenio::facet[faceCount];
    in.facetmarkerlist = new int[faceCount];
    for (int f = 0; f < faceCount; ++f) {
        tetgenio::facet& facet = in.facetlist[f];
        tetgenio::init(&facet);
        facet.numberofpolygons = 1;
        facet.polygonlist = new tetgenio::polygon[1];
        tetgenio::init(&facet.polygonlist[0]);
        facet.polygonlist[0].numberofvertices = 3;
        facet.polygonlist[0].vertexlist = new int[3];
        for (int k = 0; k < 3; ++k) facet.polygonlist[0].vertexlist[k] = plc.triangles[3 * f + k];
        in.facetmarkerlist[f] = plc.triangleMarkers[f];
    }
}

// Runs `work` in a child process; it writes its result (starting with an int code) to fd.
template <class Work>
TetgenOutcome runIsolated(Work work, ByteReader& reader) {
    int fds[2];
    if (::pipe(fds) != 0) return {TetgenStatus::InternalError, std::string("pipe: ") + std::strerror(errno)};
    std::fflush(nullptr);
    pid_t pid = ::fork();
    if (pid < 0) {
        ::close(fds[0]);
        ::close(fds[1]);
        return {TetgenStatus::InternalError, std::string("fork: ") + std::strerror(errno)};
    }
    if (pid == 0) {
        ::close(fds[0]);
        int devnull = ::open("/dev/null", O_WRONLY);
        if (devnull >= 0) ::dup2(devnull, STDOUT_FILENO);  // TetGen prints to stdout
        int code = 2;
        try {
            code = work(fds[1]);
        } catch (int c) {
            code = c;
            int32_t c32 = code;
            writeAll(fds[1], &c32, sizeof c32);
        } catch (...) {
            int32_t c32 = 2;
            writeAll(fds[1], &c32, sizeof c32);
        }
        ::close(fds[1]);
        ::_exit(0);
    }
    ::close(fds[1]);
    char buffer[1 << 16];
    for (;;) {
        ssize_t n = ::read(fds[0], buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        reader.bytes.insert(reader.bytes.end(), buffer, buffer + n);
    }
    ::close(fds[0]);
    int wstatus = 0;
    while (::waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
    }
    int32_t code = -1;
    if (!reader.take(&code, sizeof code)) {
        std::string why = "TetGen stopped without a result";
        if (WIFSIGNALED(wstatus)) why += std::string(" (signal ") + std::to_string(WTERMSIG(wstatus)) + ": " + strsignal(WTERMSIG(wstatus)) + ")";
        return {TetgenStatus::Crashed, why};
    }
    if (code != 0) {
        return {statusFromCode(code), "TetGen reported error code " + std::to_string(code)};
    }
    return {};
}

}  // namespace

const char* tetgenStatusName(TetgenStatus status) {
    switch (status) {
        case TetgenStatus::Ok: return "ok";
        case TetgenStatus::SelfIntersection: return "input facets intersect";
        case TetgenStatus::InputError: return "invalid input";
        case TetgenStatus::ToleranceError: return "points or facets too close for TetGen's tolerance";
        case TetgenStatus::OutOfMemory: return "out of memory";
        case TetgenStatus::InternalError: return "internal error";
        case TetgenStatus::Crashed: return "triangulator crashed";
    }
    return "unknown";
}

TetgenOutcome tetrahedralizePlc(const PlcInput& input, TetMesh& out, const char* extraSwitches) {
    ByteReader reader;
    TetgenOutcome outcome = runIsolated(
        [&](int fd) -> int {
            tetgenio in, result;
            fillTetgenInput(input, in);
            if (const char* dump = std::getenv("AGGRELOD_DUMP_PLC")) {  // debugging aid
                in.save_nodes(const_cast<char*>(dump));
                in.save_poly(const_cast<char*>(dump));
            }
            std::string switches = std::string("pczQn") + (extraSwitches ? extraSwitches : "");
            tetrahedralize(&switches[0], &in, &result);
            int32_t ok = 0;
            writeAll(fd, &ok, sizeof ok);
            writeArray(fd, result.pointlist, static_cast<size_t>(result.numberofpoints) * 3);
            writeArray(fd, result.tetrahedronlist, static_cast<size_t>(result.numberoftetrahedra) * 4);
            writeArray(fd, result.neighborlist, result.neighborlist ? static_cast<size_t>(result.numberoftetrahedra) * 4 : 0);
            std::vector<double> regions(static_cast<size_t>(result.numberoftetrahedra), -1.0);
            if (result.numberoftetrahedronattributes > 0) {
                for (int t = 0; t < result.numberoftetrahedra; ++t)
                    regions[t] = result.tetrahedronattributelist[t * result.numberoftetrahedronattributes];
            }
            writeArray(fd, regions.data(), regions.size());
            writeArray(fd, result.trifacelist, static_cast<size_t>(result.numberoftrifaces) * 3);
            writeArray(fd, result.trifacemarkerlist, result.trifacemarkerlist ? static_cast<size_t>(result.numberoftrifaces) : 0);
            return 0;
        },
        reader);
    if (outcome.status != TetgenStatus::Ok) return outcome;
    if (!(reader.readArray(out.points) && reader.readArray(out.tets) && reader.readArray(out.neighbors) &&
          reader.readArray(out.regions) && reader.readArray(out.boundaryFaces) &&
          reader.readArray(out.boundaryMarkers))) {
        return {TetgenStatus::InternalError, "TetGen result was cut short"};
    }
    if (out.neighbors.size() != out.tets.size()) return {TetgenStatus::InternalError, "TetGen gave no neighbours"};
    if (out.boundaryMarkers.size() != out.boundaryFaces.size() / 3) out.boundaryMarkers.assign(out.boundaryFaces.size() / 3, 0);
    return outcome;
}

TetgenOutcome findIntersectingFacets(const PlcInput& input, std::vector<int>& intersectingMarkers) {
    ByteReader reader;
    TetgenOutcome outcome = runIsolated(
        [&](int fd) -> int {
            tetgenio in, result;
            fillTetgenInput(input, in);
            char switches[] = "pdzQ";
            tetrahedralize(switches, &in, &result);
            int32_t ok = 0;
            writeAll(fd, &ok, sizeof ok);
            writeArray(fd, result.trifacemarkerlist, result.trifacemarkerlist ? static_cast<size_t>(result.numberoftrifaces) : 0);
            return 0;
        },
        reader);
    if (outcome.status != TetgenStatus::Ok) return outcome;
    std::vector<int> markers;
    if (!reader.readArray(markers)) return {TetgenStatus::InternalError, "TetGen result was cut short"};
    std::sort(markers.begin(), markers.end());
    markers.erase(std::unique(markers.begin(), markers.end()), markers.end());
    intersectingMarkers = markers;
    return outcome;
}

}  // namespace aggrelod::detail
