// CGAL wrapper: 2D constrained Delaunay triangulation (DESIGN 2.1; paper Section 3.1).
// All points and constraints go in as one batch, the way CGAL's insert_constraints() does it
// (spatially sorted insertion: about 40x faster than inserting polygon by polygon, see
// NOTES-deps), written out here to keep each input point's vertex. Inside/outside marking is
// done by the caller (CGAL 5.5 has no mark_domain_in_triangulation).
#include "cdt_2d.h"

#include "parallel_for.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <array>
#include <exception>
#include <numeric>

namespace aggrelod::detail {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
/// Per vertex: the smallest input point index at its place (-1 for a crossing of
/// constraints), and its number in the last export.
struct VertexInfo {
    int input = -1;
    int index = -1;
};
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using FaceBase = CGAL::Triangulation_face_base_with_info_2<int, Kernel, CGAL::Constrained_triangulation_face_base_2<Kernel>>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Point = Kernel::Point_2;
}  // namespace

struct ConstrainedTriangulation2D::Impl {
    Cdt cdt;
    std::vector<Cdt::Vertex_handle> inputHandle;               // per build() input point
    std::vector<std::vector<Cdt::Vertex_handle>> splitHandle;  // per insertSplits() request: its new vertices
};

ConstrainedTriangulation2D::ConstrainedTriangulation2D() : impl_(new Impl) {}

namespace {

// cdt.insert_constraint(a, b), with a shortcut for the usual case where a-b is already an edge:
// it is marked as CGAL's mark_constraint() does (insert_constraint would find the same edge
// after collinearity tests and a heap-allocated stack).
void insertConstraint(Cdt& cdt, Cdt::Vertex_handle a, Cdt::Vertex_handle b) {
    Cdt::Face_handle face;
    int index = 0;
    if (cdt.dimension() == 2 && cdt.is_edge(a, b, face, index)) {
        face->set_constraint(index, true);
        face->neighbor(index)->set_constraint(cdt.mirror_index(face, index), true);
        return;
    }
    cdt.insert_constraint(a, b);
}

}  // namespace
ConstrainedTriangulation2D::~ConstrainedTriangulation2D() { delete impl_; }

namespace {

// Flat export. Vertices are numbered in the order of their input point (info().input, the
// smallest input index at the vertex's place; Steiner points after, in CGAL's order, which is
// deterministic for a given input); faces by their sorted vertex triple. Neither depends on
// CGAL's storage order.
void exportTriangulation(Cdt& cdt, const std::vector<Cdt::Vertex_handle>& inputVertex, Triangulation2D& out, int threadCount) {
    out = Triangulation2D{};
    const size_t inputCount = inputVertex.size();
    // Vertices by input index (a direct table: no search, no sort), Steiner points after.
    std::vector<Cdt::Vertex_handle> byInput(inputCount), steiner;
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
        const int input = v->info().input;
        if (input >= 0) byInput[static_cast<size_t>(input)] = v;
        else steiner.push_back(v);
    }
    const size_t vertexCount = cdt.number_of_vertices();
    out.points.reserve(2 * vertexCount);
    out.vertexInput.reserve(vertexCount);
    auto add = [&](Cdt::Vertex_handle v, int input) {
        v->info().index = static_cast<int>(out.vertexInput.size());
        out.points.push_back(v->point().x());
        out.points.push_back(v->point().y());
        out.vertexInput.push_back(input);
    };
    for (size_t i = 0; i < inputCount; ++i)
        if (byInput[i] != Cdt::Vertex_handle()) add(byInput[i], static_cast<int>(i));
    for (Cdt::Vertex_handle v : steiner) add(v, -1);
    out.inputVertex.resize(inputCount);
    for (size_t i = 0; i < inputCount; ++i) out.inputVertex[i] = inputVertex[i]->info().index;
    // Faces by sorted vertex triple: a counting sort on the smallest vertex, then tiny sorts.
    // Keys and sorts in parallel blocks (each writing its own slots; same result for any
    // thread count).
    std::vector<Cdt::Face_handle> handles;
    handles.reserve(cdt.number_of_faces());
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) handles.push_back(f);
    const size_t faceCount = handles.size();
    std::vector<std::array<int, 3>> keys(faceCount), corners(faceCount);  // sorted / CGAL's order
    const size_t blocks = std::clamp<size_t>(faceCount / 16384, 1, 64);
    parallelFor(blocks, threadCount, [&](size_t block) {
        for (size_t i = faceCount * block / blocks; i < faceCount * (block + 1) / blocks; ++i) {
            const Cdt::Face_handle f = handles[i];
            corners[i] = {f->vertex(0)->info().index, f->vertex(1)->info().index, f->vertex(2)->info().index};
            std::array<int, 3> key = corners[i];
            std::sort(key.begin(), key.end());
            keys[i] = key;
        }
    });
    std::vector<uint32_t> bucketStart(vertexCount + 1, 0);
    for (const auto& key : keys) ++bucketStart[key[0] + 1];
    for (size_t v = 0; v < vertexCount; ++v) bucketStart[v + 1] += bucketStart[v];
    std::vector<uint32_t> sorted(faceCount);  // storage positions, by key
    {
        std::vector<uint32_t> fill(bucketStart.begin(), bucketStart.end() - 1);
        for (size_t i = 0; i < faceCount; ++i) sorted[fill[keys[i][0]]++] = static_cast<uint32_t>(i);
    }
    const size_t vertexBlocks = std::clamp<size_t>(vertexCount / 8192, 1, 64);
    parallelFor(vertexBlocks, threadCount, [&](size_t block) {
        for (size_t v = vertexCount * block / vertexBlocks; v < vertexCount * (block + 1) / vertexBlocks; ++v)
            if (bucketStart[v + 1] - bucketStart[v] > 1)
                std::sort(sorted.begin() + bucketStart[v], sorted.begin() + bucketStart[v + 1],
                          [&](uint32_t a, uint32_t b) { return keys[a] < keys[b]; });
    });
    // Infinite faces (around the infinite vertex) are -1; every finite one gets its number.
    {
        auto first = cdt.incident_faces(cdt.infinite_vertex()), f = first;
        if (f != nullptr) do f->info() = -1; while (++f != first);
    }
    parallelFor(blocks, threadCount, [&](size_t block) {
        for (size_t i = faceCount * block / blocks; i < faceCount * (block + 1) / blocks; ++i)
            handles[sorted[i]]->info() = static_cast<int>(i);
    });
    out.faces.resize(3 * faceCount);
    out.neighbors.resize(3 * faceCount);
    out.constrained.resize(3 * faceCount);
    // In CGAL's storage order (sequential reads), each face writing its own slots.
    parallelFor(blocks, threadCount, [&](size_t block) {
        for (size_t h = faceCount * block / blocks; h < faceCount * (block + 1) / blocks; ++h) {
            const Cdt::Face_handle f = handles[h];
            const size_t i = static_cast<size_t>(f->info());
            for (int k = 0; k < 3; ++k) {
                out.faces[3 * i + k] = corners[h][k];
                out.neighbors[3 * i + k] = f->neighbor(k)->info();
                out.constrained[3 * i + k] = f->is_constrained(k) ? 1 : 0;
            }
        }
    });
}

}  // namespace

bool ConstrainedTriangulation2D::build(const std::vector<double>& points,
                                       const std::vector<std::pair<size_t, size_t>>& segments, Triangulation2D& out,
                                       std::string& error, int threadCount) {
    const size_t n = points.size() / 2;
    try {
        Cdt& cdt = impl_->cdt;
        cdt.clear();
        std::vector<Point> pts;
        pts.reserve(n);
        for (size_t i = 0; i < n; ++i) pts.emplace_back(points[2 * i], points[2 * i + 1]);
        // CGAL's insert_constraints(points, segments) (Triangulation_2/insert_constraints.h),
        // step by step to keep the vertex of every input point: spatially sorted insertion,
        // then the constraints between the vertices.
        std::vector<std::size_t> order(n);
        std::iota(order.begin(), order.end(), std::size_t{0});
        CGAL::Spatial_sort_traits_adapter_2<Kernel, CGAL::Pointer_property_map<Point>::const_type> sortTraits(
            CGAL::make_property_map(static_cast<const std::vector<Point>&>(pts)), cdt.geom_traits());
        CGAL::spatial_sort(order.begin(), order.end(), sortTraits);
        std::vector<Cdt::Vertex_handle>& handle = impl_->inputHandle;
        handle.assign(n, Cdt::Vertex_handle());
        Cdt::Face_handle hint;
        for (std::size_t i : order) {
            const Cdt::Vertex_handle v = cdt.insert(pts[i], hint);
            handle[i] = v;
            hint = v->face();
            // Duplicate points share one vertex: it carries the smallest of their indices.
            if (v->info().input < 0 || static_cast<int>(i) < v->info().input) v->info().input = static_cast<int>(i);
        }
        for (const auto& [a, b] : segments)
            if (handle[a] != handle[b]) insertConstraint(cdt, handle[a], handle[b]);
        impl_->splitHandle.clear();
        exportTriangulation(cdt, handle, out, threadCount);
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed: ") + e.what();
        return false;
    }
    return true;
}

bool ConstrainedTriangulation2D::exportTo(const std::vector<size_t>& newInputIndex, const std::vector<long long>& splitFirstIndex,
                                          size_t inputCount, Triangulation2D& out, std::string& error,
                                          int threadCount) {
    try {
        Cdt& cdt = impl_->cdt;
        for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v)
            if (v->info().input >= 0) v->info().input = static_cast<int>(newInputIndex[static_cast<size_t>(v->info().input)]);
        for (size_t k = 0; k < impl_->splitHandle.size() && k < splitFirstIndex.size(); ++k) {
            if (splitFirstIndex[k] < 0) continue;
            for (size_t j = 0; j < impl_->splitHandle[k].size(); ++j) {
                const Cdt::Vertex_handle v = impl_->splitHandle[k][j];
                const int input = static_cast<int>(splitFirstIndex[k] + static_cast<long long>(j));
                if (v->info().input < 0 || input < v->info().input) v->info().input = input;
            }
        }
        std::vector<Cdt::Vertex_handle> inputVertex(inputCount);
        for (size_t i = 0; i < impl_->inputHandle.size(); ++i) inputVertex.at(newInputIndex[i]) = impl_->inputHandle[i];
        for (size_t k = 0; k < impl_->splitHandle.size() && k < splitFirstIndex.size(); ++k)
            for (size_t j = 0; j < impl_->splitHandle[k].size() && splitFirstIndex[k] >= 0; ++j)
                inputVertex.at(static_cast<size_t>(splitFirstIndex[k]) + j) = impl_->splitHandle[k][j];
        impl_->splitHandle.clear();
        exportTriangulation(cdt, inputVertex, out, threadCount);
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed while adding points: ") + e.what();
        return false;
    }
    return true;
}

bool ConstrainedTriangulation2D::insertSplits(const std::vector<ConstraintSplit>& splits, std::vector<char>& applied,
                                              std::string& error) {
    applied.assign(splits.size(), 0);
    impl_->splitHandle.assign(splits.size(), {});
    try {
        Cdt& cdt = impl_->cdt;
        for (size_t k = 0; k < splits.size(); ++k) {
            const ConstraintSplit& split = splits[k];
            if (split.from >= impl_->inputHandle.size() || split.to >= impl_->inputHandle.size()) continue;
            const Cdt::Vertex_handle va = impl_->inputHandle[split.from], vb = impl_->inputHandle[split.to];
            Cdt::Face_handle face;
            int index = 0;
            // Only a segment that is still one constrained edge (not already split by another
            // ring's vertex on it) is split here; the caller leaves the others as they are.
            if (va == Cdt::Vertex_handle() || vb == Cdt::Vertex_handle() || !cdt.is_edge(va, vb, face, index) ||
                !face->is_constrained(index))
                continue;
            cdt.remove_constrained_edge(face, index);
            Cdt::Vertex_handle previous = va;
            for (size_t i = 0; i + 1 < split.points.size(); i += 2) {
                const Cdt::Vertex_handle v = cdt.insert(Point(split.points[i], split.points[i + 1]), va->face());
                impl_->splitHandle[k].push_back(v);
                insertConstraint(cdt, previous, v);
                previous = v;
            }
            insertConstraint(cdt, previous, vb);
            applied[k] = 1;
        }
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed while adding points: ") + e.what();
        return false;
    }
    return true;
}

}  // namespace aggrelod::detail
