// SPDX-License-Identifier: AGPL-3.0-or-later
// Free-space ownership (paper Section 3.1; docs/design.md §2.1): one constrained Delaunay
// tetrahedralization of the models (TetGen, in tetgen_backend.cpp) and, per vertex and tet,
// the model that owns it.
#include "baker_3d.h"
#include "parallel_for.h"
#include "radix_sort.h"
#include "tetgen_backend.h"

#include <thread>

#ifdef __linux__
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

namespace aggrelod::detail {

bool Baker3D::triangulate() {
    timer_.begin("tetrahedralize");
    for (int attempt = 0; attempt < 6; ++attempt) {
        if (standInsChanged_) resolveStandInOverlaps();
        // Model order: by smallest object index (deterministic).
        std::sort(models_.begin(), models_.end(), [](const Model& a, const Model& b) { return a.objects[0] < b.objects[0]; });
        PlcInput plc;
        plc.cpuSeconds = settings_.triangulationSeconds;
        plc.memoryBytes = settings_.triangulationMemory;
        std::vector<int> pointModel;
        for (size_t m = 0; m < models_.size(); ++m) {
            const int base = static_cast<int>(plc.points.size() / 3);
            plc.points.insert(plc.points.end(), models_[m].positions.begin(), models_[m].positions.end());
            pointModel.insert(pointModel.end(), models_[m].positions.size() / 3, static_cast<int>(m));
            for (uint32_t idx : models_[m].triangles) plc.triangles.push_back(base + static_cast<int>(idx));
            plc.triangleMarkers.insert(plc.triangleMarkers.end(), models_[m].triangles.size() / 3, static_cast<int>(m) + 1);
        }
        space_ = FreeSpace{};
        // TetGen runs in a child process on one core; meanwhile this process builds the
        // models' BVHs and hulls (needed right after) on one thread. Each model's result
        // does not depend on the thread doing it, so output stays deterministic.
        // (It used to go on measuring likely neighbour pairs until TetGen was done; on this
        // 2-vCPU VM that slowed TetGen's child by more than it saved in the graph stage.)
        std::thread preparing;
        const bool overlap = !modelsPrepared_ && settings_.threadCount != 1;
        if (overlap)
            preparing = std::thread([this] {
#ifdef __linux__
                // Lowest priority for this thread only: on a busy machine TetGen goes first.
                setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), 19);
#endif
                prepareModels(1);
            });
        TetgenOutcome outcome = tetrahedralizePlc(plc, space_.mesh);
        if (preparing.joinable()) preparing.join();
        for (const char* fallback : {"Y", "M"}) {
            if (outcome.status != TetgenStatus::Crashed && outcome.status != TetgenStatus::InternalError) break;
            std::vector<int> markers;
            TetgenOutcome found = findIntersectingFacets(plc, markers);
            if (found.status != TetgenStatus::Ok || !markers.empty()) break;  // repaired below
            space_ = FreeSpace{};
            TetgenOutcome retry = tetrahedralizePlc(plc, space_.mesh, fallback);
            if (retry.status == TetgenStatus::Ok)
                diag(out_, Diagnostic::Severity::Note, "",
                     std::string("TetGen's boundary recovery failed (") + outcome.message + "); succeeded with switch " + fallback);
            outcome = retry;
        }
        if (outcome.status == TetgenStatus::ToleranceError) {
            // Features below TetGen's relative tolerance (1e-8 of the box): once more with a
            // finer one. Large inputs of fine detail meet it, e.g. the tiled bake's parents.
            space_ = FreeSpace{};
            TetgenOutcome retry = tetrahedralizePlc(plc, space_.mesh, "T1e-12");
            if (retry.status == TetgenStatus::Ok)
                diag(out_, Diagnostic::Severity::Note, "",
                     "TetGen found features below its tolerance (" + outcome.message + "); succeeded with tolerance 1e-12");
            outcome = retry;
        }
        if (outcome.status == TetgenStatus::Ok) {
            timer_.begin("free space");
            space_.modelCount = models_.size();
            analyseFreeSpace(pointModel);
            return true;
        }
        // Intersecting input makes TetGen report code 3 or trip one of its assertions:
        // find the facets that intersect (switch d) and stand in for their models.
        if (outcome.status == TetgenStatus::SelfIntersection || outcome.status == TetgenStatus::Crashed ||
            outcome.status == TetgenStatus::InternalError) {
            std::vector<int> markers;
            TetgenOutcome found = findIntersectingFacets(plc, markers);
            bool repaired = false;
            if (found.status == TetgenStatus::Ok) {
                std::vector<size_t> which;
                for (int marker : markers) {
                    if (marker <= 0 || static_cast<size_t>(marker) > models_.size()) continue;
                    if (!models_[marker - 1].standIn()) which.push_back(static_cast<size_t>(marker - 1));
                }
                std::sort(which.begin(), which.end());
                which.erase(std::unique(which.begin(), which.end()), which.end());
                solidifyModels(which, std::vector<std::string>(which.size(), "self-intersecting surface"));
                repaired = !which.empty();
            }
            if (repaired) continue;
        }
        diag(out_, Diagnostic::Severity::Error, "",
             std::string("tetrahedralization failed: ") + tetgenStatusName(outcome.status) + " (" + outcome.message + ")");
        return false;
    }
    diag(out_, Diagnostic::Severity::Error, "", "tetrahedralization failed after repeated repairs of intersecting input");
    return false;
}

void Baker3D::analyseFreeSpace(const std::vector<int>& pointModel) {
    TetMesh& mesh = space_.mesh;
    const size_t tetCount = mesh.tetCount();
    // TetGen orients all tets alike; make them positive (the sculptor's face tables assume
    // it). Decide once from the total, never per tet: a sliver's rounded sign can lie.
    space_.tetVolume.assign(tetCount, 0.0);
    double signedTotal = 0;
    for (size_t t = 0; t < tetCount; ++t) {
        const double* a = &mesh.points[3 * mesh.tets[4 * t]];
        const double* b = &mesh.points[3 * mesh.tets[4 * t + 1]];
        const double* c = &mesh.points[3 * mesh.tets[4 * t + 2]];
        const double* d = &mesh.points[3 * mesh.tets[4 * t + 3]];
        const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
        const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
        const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
        double vol = ((u[1] * v[2] - u[2] * v[1]) * w[0] + (u[2] * v[0] - u[0] * v[2]) * w[1] + (u[0] * v[1] - u[1] * v[0]) * w[2]) / 6.0;
        signedTotal += vol;
        space_.tetVolume[t] = std::fabs(vol);
    }
    if (signedTotal < 0) {
        for (size_t t = 0; t < tetCount; ++t) {
            std::swap(mesh.tets[4 * t + 2], mesh.tets[4 * t + 3]);
            std::swap(mesh.neighbors[4 * t + 2], mesh.neighbors[4 * t + 3]);
        }
    }
    // Vertex owners: input points by construction; Steiner points on a model's surface
    // through the constrained faces they lie on.
    space_.vertexModel.assign(mesh.pointCount(), -1);
    for (size_t v = 0; v < pointModel.size() && v < mesh.pointCount(); ++v) space_.vertexModel[v] = pointModel[v];
    for (size_t f = 0; f < mesh.boundaryMarkers.size(); ++f) {
        int marker = mesh.boundaryMarkers[f];
        if (marker <= 0) continue;
        for (int k = 0; k < 3; ++k) {
            int v = mesh.boundaryFaces[3 * f + k];
            if (v >= 0 && static_cast<size_t>(v) < mesh.pointCount() && space_.vertexModel[v] < 0) space_.vertexModel[v] = marker - 1;
        }
    }
    // Interior tets: flood each enclosed region from a tet that faces free space through a
    // model's surface.
    space_.tetModel.assign(tetCount, -1);
    std::vector<int> stack;
    for (size_t t = 0; t < tetCount; ++t) {
        if (mesh.regions[t] == -1.0 || space_.tetModel[t] >= 0) continue;
        int model = -1;
        for (int j = 0; j < 4 && model < 0; ++j) {
            // the face opposite corner j: if all three corners belong to one model, it is on it
            int owners[3], k = 0;
            for (int c = 0; c < 4; ++c)
                if (c != j) owners[k++] = space_.vertexModel[mesh.tets[4 * t + c]];
            if (owners[0] >= 0 && owners[0] == owners[1] && owners[1] == owners[2]) {
                int n = mesh.neighbors[4 * t + j];
                if (n < 0 || mesh.regions[n] == -1.0) model = owners[0];
            }
        }
        if (model < 0) continue;
        stack.push_back(static_cast<int>(t));
        space_.tetModel[t] = model;
        while (!stack.empty()) {
            int s = stack.back();
            stack.pop_back();
            for (int j = 0; j < 4; ++j) {
                int n = mesh.neighbors[4 * s + j];
                if (n >= 0 && mesh.regions[n] != -1.0 && space_.tetModel[n] < 0 && mesh.regions[n] == mesh.regions[s]) {
                    space_.tetModel[n] = model;
                    stack.push_back(n);
                }
            }
        }
    }
    for (size_t t = 0; t < tetCount; ++t)
        if (mesh.regions[t] != -1.0 && space_.tetModel[t] < 0) {
            // An enclosed region no model surface faces (should not happen); treat as free.
            mesh.regions[t] = -1.0;
        }
    out_.tetrahedronCount = tetCount;
}

}  // namespace aggrelod::detail
