// SPDX-License-Identifier: AGPL-3.0-or-later
// CGAL wrapper: 2D constrained Delaunay triangulation (docs/design.md §2.1; paper Section 3.1).
// All points and constraints go in as one batch, the way CGAL's insert_constraints() does it
// (spatially sorted insertion: about 40x faster than inserting polygon by polygon, see
// docs/design.md §6), written out here to keep each input point's vertex. Inside/outside marking is
// done by the caller (CGAL 5.5 has no mark_domain_in_triangulation). Also CGAL's two exact
// predicates, for the Steiner points that steiner_2d.cpp inserts into the export.
#include "cdt_2d.h"

#include "parallel_for.h"
#include "radix_sort.h"
#include "steiner_2d.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <array>
#include <cmath>
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
using Dt = CGAL::Delaunay_triangulation_2<Kernel, Tds>;  // same data structure, for the points alone
using Point = Kernel::Point_2;
}  // namespace

struct ConstrainedTriangulation2D::Impl {
    Cdt cdt;
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

// Position of the cell (x, y) along the Hilbert curve through a 2^16 x 2^16 grid: the classic
// xy -> d conversion (one quadrant per bit from the top; in the lower quadrants the rest is
// mirrored and / or transposed), without branches.
uint64_t hilbertIndex(uint32_t x, uint32_t y) {
    uint64_t d = 0;
    for (int bit = 15; bit >= 0; --bit) {
        const uint32_t rx = (x >> bit) & 1, ry = (y >> bit) & 1;
        d |= static_cast<uint64_t>((3 * rx) ^ ry) << (2 * bit);
        const uint32_t mirror = (0u - (rx & (ry ^ 1))) & 0xffff;  // rx = 1, ry = 0
        x ^= mirror;
        y ^= mirror;
        const uint32_t transpose = (0u - (ry ^ 1)) & (x ^ y);  // ry = 0
        x ^= transpose;
        y ^= transpose;
    }
    return d;
}

// Insertion order: the points along a Hilbert curve over their bounding square (equal cells in
// index order), so each insertion starts its walk next to the previous vertex. The
// triangulation does not depend on the order (CGAL's flips use a symbolic perturbation), only
// its speed does; a radix sort of the curve positions costs far less than CGAL's spatial_sort.
std::vector<uint32_t> hilbertOrder(const std::vector<double>& points) {
    const size_t n = points.size() / 2;
    double minX = INFINITY, minY = INFINITY, maxX = -INFINITY, maxY = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        minX = std::min(minX, points[2 * i]), maxX = std::max(maxX, points[2 * i]);
        minY = std::min(minY, points[2 * i + 1]), maxY = std::max(maxY, points[2 * i + 1]);
    }
    const double span = std::max(maxX - minX, maxY - minY);
    const double scale = span > 0 && std::isfinite(span) ? 65535.0 / span : 0;
    auto cell = [&](double v, double lo) { return static_cast<uint32_t>(std::clamp((v - lo) * scale, 0.0, 65535.0)); };
    // Biased randomized rounds (BRIO, as CGAL's spatial_sort): a point joins an earlier round
    // with probability 1/4 per round, from a hash of its index (deterministic); rounds go in
    // from the smallest, each along the curve.
    struct Keyed {
        uint64_t key;  // round << 32 | curve position
        uint32_t point;
    };
    std::vector<Keyed> keyed(n);
    for (size_t i = 0; i < n; ++i) {
        uint64_t h = i + 0x9e3779b97f4a7c15ull;  // splitmix64
        h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ull;
        h = (h ^ (h >> 27)) * 0x94d049bb133111ebull;
        h ^= h >> 31;
        uint64_t earlier = 0;
        while (earlier < 8 && ((h >> (62 - 2 * earlier)) & 3) == 3) ++earlier;
        keyed[i] = {(8 - earlier) << 32 | hilbertIndex(cell(points[2 * i], minX), cell(points[2 * i + 1], minY)),
                    static_cast<uint32_t>(i)};
    }
    radixSortStable(keyed, [](const Keyed& k) { return k.key; }, 36);
    std::vector<uint32_t> order(n);
    for (size_t i = 0; i < n; ++i) order[i] = keyed[i].point;
    return order;
}

}  // namespace

namespace {

// Flat export. Vertices are numbered in the order of their input point (info().input, the
// smallest input index at the vertex's place; Steiner points after, in CGAL's order, which is
// deterministic for a given input); faces then get the canonical order of
// canonicalizeFaces2D (by sorted vertex triple, smallest corner first). Neither depends on
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
    // Faces in CGAL's storage order first (infinite faces are -1), in parallel blocks each
    // writing its own slots; then the canonical order.
    std::vector<Cdt::Face_handle> handles;
    handles.reserve(cdt.number_of_faces());
    for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
        f->info() = static_cast<int>(handles.size());
        handles.push_back(f);
    }
    {
        auto first = cdt.incident_faces(cdt.infinite_vertex()), f = first;
        if (f != nullptr) do f->info() = -1; while (++f != first);
    }
    const size_t faceCount = handles.size();
    out.faces.resize(3 * faceCount);
    out.neighbors.resize(3 * faceCount);
    out.constrained.resize(3 * faceCount);
    parallelForEach(faceCount, threadCount, [&](size_t i) {
        const Cdt::Face_handle f = handles[i];
        for (int k = 0; k < 3; ++k) {
            out.faces[3 * i + k] = f->vertex(k)->info().index;
            out.neighbors[3 * i + k] = f->neighbor(k)->info();
            out.constrained[3 * i + k] = f->is_constrained(k) ? 1 : 0;
        }
    });
    canonicalizeFaces2D(out, threadCount);
}

}  // namespace

bool ConstrainedTriangulation2D::build(const std::vector<double>& points,
                                       const std::vector<std::pair<size_t, size_t>>& segments, Triangulation2D& out,
                                       std::string& error, int threadCount, const std::atomic<bool>* cancel) {
    const size_t n = points.size() / 2;
    try {
        Cdt& cdt = impl_->cdt;
        cdt.clear();
        std::vector<Point> pts;
        pts.reserve(n);
        for (size_t i = 0; i < n; ++i) pts.emplace_back(points[2 * i], points[2 * i + 1]);
        // CGAL's insert_constraints(points, segments) (Triangulation_2/insert_constraints.h),
        // step by step to keep the vertex of every input point: spatially sorted insertion
        // (hilbertOrder), then the constraints between the vertices.
        const std::vector<uint32_t> order = hilbertOrder(points);
        std::vector<Cdt::Vertex_handle> handle(n);  // per input point
        // The points go into a plain Delaunay triangulation on the same data structure (about
        // a quarter faster than the constrained one's insertion, with the same flips and
        // symbolic perturbation, so the same triangulation), which then becomes the
        // constrained triangulation's before the constraints go in.
        Dt delaunay;
        Dt::Face_handle hint;
        auto cancelled = [&] { return cancel && cancel->load(std::memory_order_relaxed); };
        for (size_t k = 0; k < order.size(); ++k) {
            if (k % 4096 == 0 && cancelled()) {
                error.clear();
                return false;
            }
            const uint32_t i = order[k];
            const Dt::Vertex_handle v = delaunay.insert(pts[i], hint);
            handle[i] = v;
            hint = v->face();
            // Duplicate points share one vertex: it carries the smallest of their indices.
            if (v->info().input < 0 || static_cast<int>(i) < v->info().input) v->info().input = static_cast<int>(i);
        }
        static_cast<CGAL::Triangulation_2<Kernel, Tds>&>(cdt).swap(delaunay);
        if (cancelled()) {
            error.clear();
            return false;
        }
        for (const auto& [a, b] : segments)
            if (handle[a] != handle[b]) insertConstraint(cdt, handle[a], handle[b]);
        exportTriangulation(cdt, handle, out, threadCount);
    } catch (const std::exception& e) {
        error = std::string("2D triangulation failed: ") + e.what();
        return false;
    }
    return true;
}

int exactOrientation2D(const double* a, const double* b, const double* c) {
    return static_cast<int>(CGAL::orientation(Point(a[0], a[1]), Point(b[0], b[1]), Point(c[0], c[1])));
}

// Triangulation_2::side_of_oriented_circle(p0, p1, p2, p, perturb = true) of CGAL 5.5, the
// test of every Delaunay flip CGAL's constrained Delaunay triangulation makes.
int exactPerturbedSideOfCircle2D(const double* a, const double* b, const double* c, const double* d) {
    const Point p0(a[0], a[1]), p1(b[0], b[1]), p2(c[0], c[1]), p(d[0], d[1]);
    const CGAL::Oriented_side side = Kernel().side_of_oriented_circle_2_object()(p0, p1, p2, p);
    if (side != CGAL::ON_ORIENTED_BOUNDARY) return static_cast<int>(side);
    // Symbolic perturbation: the points in lexicographic order, the leading monomials decide.
    const Point* points[4] = {&p0, &p1, &p2, &p};
    std::sort(points, points + 4, [](const Point* u, const Point* v) { return CGAL::compare_xy(*u, *v) == CGAL::SMALLER; });
    for (int i = 3; i > 0; --i) {
        if (points[i] == &p) return -1;
        CGAL::Orientation o;
        if (points[i] == &p2 && (o = CGAL::orientation(p0, p1, p)) != CGAL::COLLINEAR) return static_cast<int>(o);
        if (points[i] == &p1 && (o = CGAL::orientation(p0, p, p2)) != CGAL::COLLINEAR) return static_cast<int>(o);
        if (points[i] == &p0 && (o = CGAL::orientation(p, p1, p2)) != CGAL::COLLINEAR) return static_cast<int>(o);
    }
    return -1;
}

}  // namespace aggrelod::detail
