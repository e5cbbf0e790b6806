// CGAL wrapper: 2D constrained Delaunay triangulation (DESIGN 2.1; paper Section 3.1).
// All constraints go in one insert_constraints() call (spatially sorted insertion: about
// 40x faster than inserting polygon by polygon, see NOTES-deps). Inside/outside marking is
// done by the caller (CGAL 5.5 has no mark_domain_in_triangulation).
#include "cdt_2d.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <exception>
#include <numeric>

namespace aggrelod::detail {
namespace {
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<int, Kernel>;
using FaceBase = CGAL::Triangulation_face_base_with_info_2<int, Kernel, CGAL::Constrained_triangulation_face_base_2<Kernel>>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Point = Kernel::Point_2;
}  // namespace

struct ConstrainedTriangulation2D::Impl {
    Cdt cdt;
    std::vector<Cdt::Vertex_handle> inputHandle;  // per build() input point
};

ConstrainedTriangulation2D::ConstrainedTriangulation2D() : impl_(new Impl) {}
ConstrainedTriangulation2D::~ConstrainedTriangulation2D() { delete impl_; }

namespace {

// Flat export. Vertices are numbered in the order of their input point (Steiner points
// after, in CGAL's order, which is deterministic for a given input); faces by their sorted
// vertex triple. Neither depends on CGAL's storage order.
void exportTriangulation(Cdt& cdt, const std::vector<double>& points, Triangulation2D& out,
                         const std::vector<size_t>* pointOrder, std::vector<Cdt::Vertex_handle>* inputHandle = nullptr) {
    out = Triangulation2D{};
    const size_t n = points.size() / 2;
    std::vector<size_t> ownOrder;
    if (!pointOrder || pointOrder->size() != n) {
        ownOrder.resize(n);
        std::iota(ownOrder.begin(), ownOrder.end(), size_t{0});
        std::sort(ownOrder.begin(), ownOrder.end(), [&](size_t a, size_t b) {
            if (points[2 * a] != points[2 * b]) return points[2 * a] < points[2 * b];
            if (points[2 * a + 1] != points[2 * b + 1]) return points[2 * a + 1] < points[2 * b + 1];
            return a < b;
        });
        pointOrder = &ownOrder;
    }
    // The sorted points as one contiguous array: binary searches without indirection.
    struct SortedPoint {
        double x, y;
        size_t index;
    };
    std::vector<SortedPoint> sorted;
    sorted.reserve(n);
    for (size_t i : *pointOrder) sorted.push_back({points[2 * i], points[2 * i + 1], i});
    std::vector<std::pair<long long, Cdt::Vertex_handle>> keyed;
    keyed.reserve(cdt.number_of_vertices());
    long long steinerKey = static_cast<long long>(n);
    for (auto v = cdt.finite_vertices_begin(); v != cdt.finite_vertices_end(); ++v) {
        const double x = v->point().x(), y = v->point().y();
        auto it = std::lower_bound(sorted.begin(), sorted.end(), 0, [&](const SortedPoint& a, int) {
            return a.x < x || (a.x == x && a.y < y);
        });
        if (it != sorted.end() && it->x == x && it->y == y) {
            keyed.emplace_back(static_cast<long long>(it->index), v);
            if (inputHandle)
                for (auto same = it; same != sorted.end() && same->x == x && same->y == y; ++same)
                    (*inputHandle)[same->index] = v;
        } else {
            keyed.emplace_back(steinerKey++, v);
        }
    }
    std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    out.points.reserve(2 * keyed.size());
    out.vertexInput.reserve(keyed.size());
    for (size_t i = 0; i < keyed.size(); ++i) {
        Cdt::Vertex_handle v = keyed[i].second;
        v->info() = static_cast<int>(i);
        out.points.push_back(v->point().x());
        out.points.push_back(v->point().y());
        out.vertexInput.push_back(keyed[i].first < static_cast<long long>(n) ? static_cast<int>(keyed[i].first) : -1);
    }
    // Faces by sorted vertex triple: a counting sort on the smallest vertex, then tiny sorts.
    std::vector<std::pair<std::array<int, 3>, Cdt::Face_handle>> unsortedFaces, faces;
    unsortedFaces.reserve(cdt.number_of_faces());
    std::vector<uint32_t> bucketStart(keyed.size() + 1, 0);
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        std::array<int, 3> key{f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info()};
        std::sort(key.begin(), key.end());
        ++bucketStart[key[0] + 1];
        unsortedFaces.emplace_back(key, f);
    }
    for (size_t v = 0; v < keyed.size(); ++v) bucketStart[v + 1] += bucketStart[v];
    faces.resize(unsortedFaces.size());
    {
        std::vector<uint32_t> fill(bucketStart.begin(), bucketStart.end() - 1);
        for (const auto& f : unsortedFaces) faces[fill[f.first[0]]++] = f;
    }
    for (size_t v = 0; v < keyed.size(); ++v)
        std::sort(faces.begin() + bucketStart[v], faces.begin() + bucketStart[v + 1],
                  [](const auto& a, const auto& b) { return a.first < b.first; });
    // Infinite faces (around the infinite vertex) are -1; every finite one gets its number.
    {
        auto first = cdt.incident_faces(cdt.infinite_vertex()), f = first;
        if (f != nullptr) do f->info() = -1; while (++f != first);
    }
    for (size_t i = 0; i < faces.size(); ++i) faces[i].second->info() = static_cast<int>(i);
    out.faces.resize(3 * faces.size());
    out.neighbors.resize(3 * faces.size());
    out.constrained.resize(3 * faces.size());
    // In CGAL's storage order (sequential reads), each face writing its own slots.
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        const size_t i = static_cast<size_t>(f->info());
        for (int k = 0; k < 3; ++k) {
            out.faces[3 * i + k] = f->vertex(k)->info();
            out.neighbors[3 * i + k] = f->neighbor(k)->info();
            out.constrained[3 * i + k] = f->is_constrained(k) ? 1 : 0;
        }
    }
}

}  // namespace

bool ConstrainedTriangulation2D::build(const std::vector<double>& points,
                                       const std::vector<std::pair<size_t, size_t>>& segments, Triangulation2D& out,
                                       std::string& error, const std::vector<size_t>* pointOrder) {
    const size_t n = points.size() / 2;
    try {
        impl_->cdt.clear();
        std::vector<Point> pts;
        pts.reserve(n);
        for (size_t i = 0; i < n; ++i) pts.emplace_back(points[2 * i], points[2 * i + 1]);
        impl_->cdt.insert_constraints(pts.begin(), pts.end(), segments.begin(), segments.end());
        impl_->inputHandle.assign(n, Cdt::Vertex_handle());
        exportTriangulation(impl_->cdt, points, out, pointOrder, &impl_->inputHandle);
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed: ") + e.what();
        return false;
    }
    return true;
}

bool ConstrainedTriangulation2D::splitConstraints(const std::vector<ConstraintSplit>& splits,
                                                  std::vector<char>& applied, const std::vector<double>& allPoints,
                                                  Triangulation2D& out, std::string& error,
                                                  const std::vector<size_t>* allPointOrder) {
    return insertSplits(splits, applied, error) && exportTo(allPoints, out, error, allPointOrder);
}

bool ConstrainedTriangulation2D::exportTo(const std::vector<double>& allPoints, Triangulation2D& out,
                                          std::string& error, const std::vector<size_t>* allPointOrder) {
    try {
        exportTriangulation(impl_->cdt, allPoints, out, allPointOrder);
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed while adding points: ") + e.what();
        return false;
    }
    return true;
}

bool ConstrainedTriangulation2D::insertSplits(const std::vector<ConstraintSplit>& splits, std::vector<char>& applied,
                                              std::string& error) {
    applied.assign(splits.size(), 0);
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
                cdt.insert_constraint(previous, v);
                previous = v;
            }
            cdt.insert_constraint(previous, vb);
            applied[k] = 1;
        }
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed while adding points: ") + e.what();
        return false;
    }
    return true;
}

}  // namespace aggrelod::detail
