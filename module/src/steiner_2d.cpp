// SPDX-License-Identifier: AGPL-3.0-or-later
// Steiner points on constrained edges of a flat constrained Delaunay triangulation, and the
// canonical numbering of its faces (docs/design.md §2.4 step 4; paper Section 3.1). Insertion is the
// textbook incremental one for a point on an edge (split the two faces, then Lawson flips
// across the edges opposite the new vertex; de Berg et al., Computational Geometry, 9.3),
// with CGAL's exact predicates (cdt_2d.h), so the result equals CGAL's own insertion.
#include "steiner_2d.h"

#include "parallel_for.h"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace aggrelod::detail {

void canonicalizeFaces2D(Triangulation2D& tri, int threadCount) {
    const size_t faceCount = tri.faceCount(), vertexCount = tri.vertexCount();
    // Per face: its smallest corner (the bucket) and the other two, sorted, as one number.
    std::vector<uint8_t> rotation(faceCount);  // corner that comes first: the smallest
    std::vector<uint32_t> smallest(faceCount);
    std::vector<uint64_t> rest(faceCount);
    parallelForEach(faceCount, threadCount, [&](size_t f) {
        const uint32_t c[3] = {static_cast<uint32_t>(tri.faces[3 * f]), static_cast<uint32_t>(tri.faces[3 * f + 1]),
                               static_cast<uint32_t>(tri.faces[3 * f + 2])};
        const int r = c[1] < c[0] ? (c[2] < c[1] ? 2 : 1) : (c[2] < c[0] ? 2 : 0);
        rotation[f] = static_cast<uint8_t>(r);
        smallest[f] = c[r];
        const uint32_t u = c[(r + 1) % 3], w = c[(r + 2) % 3];
        rest[f] = u < w ? static_cast<uint64_t>(u) << 32 | w : static_cast<uint64_t>(w) << 32 | u;
    });
    // Counting sort on the smallest corner, then insertion sorts of the (tiny) buckets.
    std::vector<uint32_t> bucketStart(vertexCount + 1, 0);
    for (size_t f = 0; f < faceCount; ++f) ++bucketStart[smallest[f] + 1];
    for (size_t v = 0; v < vertexCount; ++v) bucketStart[v + 1] += bucketStart[v];
    std::vector<uint32_t> sorted(faceCount);  // old face of each new position
    {
        std::vector<uint32_t> fill(bucketStart.begin(), bucketStart.end() - 1);
        for (size_t f = 0; f < faceCount; ++f) sorted[fill[smallest[f]]++] = static_cast<uint32_t>(f);
    }
    parallelForEach(
        vertexCount, threadCount,
        [&](size_t v) {
            uint32_t* first = sorted.data() + bucketStart[v];
            uint32_t* last = sorted.data() + bucketStart[v + 1];
            for (uint32_t* i = first + 1; i < last; ++i)
                for (uint32_t* j = i; j > first && rest[*(j - 1)] > rest[*j]; --j) std::swap(*(j - 1), *j);
        },
        8192);
    std::vector<int> newIndex(faceCount);
    parallelForEach(faceCount, threadCount, [&](size_t i) { newIndex[sorted[i]] = static_cast<int>(i); });
    std::vector<int> faces(3 * faceCount), neighbors(3 * faceCount);
    std::vector<char> constrained(3 * faceCount);
    // Old faces in order (sequential reads), each writing its new slots.
    parallelForEach(faceCount, threadCount, [&](size_t f) {
        const size_t i = static_cast<size_t>(newIndex[f]);
        for (int k = 0; k < 3; ++k) {
            const size_t from = 3 * f + (k + rotation[f]) % 3;
            faces[3 * i + k] = tri.faces[from];
            neighbors[3 * i + k] = tri.neighbors[from] < 0 ? -1 : newIndex[static_cast<size_t>(tri.neighbors[from])];
            constrained[3 * i + k] = tri.constrained[from];
        }
    });
    tri.faces = std::move(faces);
    tri.neighbors = std::move(neighbors);
    tri.constrained = std::move(constrained);
}

namespace {

/// The flat triangulation with a vertex -> incident face table, edited in place.
class SplitMesh {
public:
    SplitMesh(Triangulation2D& tri, std::vector<int>* faceWinding)
        : t_(tri), winding_(faceWinding), vertexFace_(tri.vertexCount(), -1) {
        for (size_t f = 0; f < tri.faceCount(); ++f)
            for (int k = 0; k < 3; ++k) vertexFace_[static_cast<size_t>(tri.faces[3 * f + k])] = static_cast<int>(f);
    }

    /// Inserts (x, y) on the constrained edge a-b; returns its vertex, or -1 when a-b is not a
    /// constrained edge, a face would be flat or inverted, or CGAL would triangulate around
    /// the point otherwise (nothing changed then).
    int splitConstrainedEdge(int a, int b, double x, double y) {
        int f = -1, i = -1;
        if (!findEdge(a, b, f, i) || !t_.constrained[3 * f + i]) return -1;
        const int c = corner(f, i), ex = corner(f, i + 1), ey = corner(f, i + 2);  // f = [c, ex, ey]
        const int g = neighbor(f, i);
        const double p[2] = {x, y};
        if (orientation2D(P(c), P(ex), p) <= 0 || orientation2D(P(c), p, P(ey)) <= 0) return -1;
        int j = -1, d = -1;
        int sliver = -1;  // convex hull only: the thin face CGAL keeps between the hull edge and the point
        const int side = orientation2D(P(ex), P(ey), p);  // 0 on the segment, > 0 on f's side
        if (g >= 0) {
            j = oppositeCorner(g, ex, ey);
            d = corner(g, j);  // g = [d, ey, ex]
            if (orientation2D(P(d), P(ey), p) <= 0 || orientation2D(P(d), p, P(ex)) <= 0) return -1;
            // A point a rounding error off the segment: the new edge to the far corner (d on
            // f's side, c on g's) must be Delaunay, else CGAL would keep ex-ey and a thin face
            // instead (leave the split out; practically never: needs a very flat neighbour).
            if (side > 0 && perturbedSideOfCircle2D(P(d), p, P(ex), P(ey)) > 0) return -1;
        } else {
            // Outside the hull edge: CGAL joins the point to every hull edge it sees; only a
            // rounding error off this edge, it must see no other (else leave the split out).
            if (side < 0 && (orientation2D(P(hullPredecessor(f, i)), P(ex), p) <= 0 ||
                             orientation2D(P(ey), P(hullSuccessor(f, i)), p) <= 0))
                return -1;
        }
        if (side < 0 && perturbedSideOfCircle2D(P(c), P(ex), p, P(ey)) > 0) return -1;  // as above, for c
        if (g < 0 && side > 0) sliver = newFace(0);  // inside the hull: CGAL keeps the hull edge and a thin face (outside the rings)
        const int v = static_cast<int>(t_.vertexCount());
        t_.points.push_back(x);
        t_.points.push_back(y);
        t_.vertexInput.push_back(-1);
        vertexFace_.push_back(f);
        // Old neighbours and constraints of the four outer edges.
        const int nX = neighbor(f, i + 1), nY = neighbor(f, i + 2);  // across (ey, c), (c, ex)
        const char cX = t_.constrained[3 * f + (i + 1) % 3], cY = t_.constrained[3 * f + (i + 2) % 3];
        const int f1 = f, f2 = newFace(windingOf(f));
        const int outside1 = g >= 0 ? newFace(windingOf(g)) : sliver, outside2 = g >= 0 ? g : sliver;  // faces across (ex, v), (v, ey)
        setFace(f1, {c, ex, v}, {outside1, f2, nY}, {1, 0, cY});
        setFace(f2, {c, v, ey}, {outside2, nX, f1}, {1, cX, 0});
        replaceNeighbor(nX, f, f2);
        if (g >= 0) {
            const int gY = neighbor(g, j + 1), gX = neighbor(g, j + 2);  // across (ex, d), (d, ey)
            const char cgY = t_.constrained[3 * g + (j + 1) % 3], cgX = t_.constrained[3 * g + (j + 2) % 3];
            const int g1 = g, g2 = outside1;
            setFace(g1, {d, ey, v}, {f2, g2, gX}, {1, 0, cgX});
            setFace(g2, {d, v, ex}, {f1, gY, g1}, {1, cgY, 0});
            replaceNeighbor(gY, g, g2);
            vertexFace_[static_cast<size_t>(d)] = g1;
        } else if (sliver >= 0) {
            setFace(sliver, {v, ex, ey}, {-1, f2, f1}, {0, 1, 1});
        }
        vertexFace_[static_cast<size_t>(c)] = f1;
        vertexFace_[static_cast<size_t>(ex)] = f1;
        vertexFace_[static_cast<size_t>(ey)] = f2;
        vertexFace_[static_cast<size_t>(v)] = f1;
        restoreDelaunay(v, {f1, f2, outside1, outside2});
        return v;
    }

private:
    Triangulation2D& t_;
    std::vector<int>* winding_;  // per face, or null
    std::vector<int> vertexFace_;
    std::vector<int> stack_;

    const double* P(int v) const { return &t_.points[2 * static_cast<size_t>(v)]; }
    int windingOf(int f) const { return winding_ ? (*winding_)[static_cast<size_t>(f)] : 0; }
    int corner(int f, int k) const { return t_.faces[3 * static_cast<size_t>(f) + k % 3]; }
    int neighbor(int f, int k) const { return t_.neighbors[3 * static_cast<size_t>(f) + k % 3]; }
    int cornerOf(int f, int v) const {
        for (int k = 0; k < 3; ++k)
            if (corner(f, k) == v) return k;
        throw std::logic_error("2D Steiner insertion: vertex not in face");
    }
    int oppositeCorner(int f, int a, int b) const {
        for (int k = 0; k < 3; ++k)
            if (corner(f, k) != a && corner(f, k) != b) return k;
        throw std::logic_error("2D Steiner insertion: degenerate face");
    }
    int newFace(int winding) {
        if (winding_) winding_->push_back(winding);
        t_.faces.insert(t_.faces.end(), 3, -1);
        t_.neighbors.insert(t_.neighbors.end(), 3, -1);
        t_.constrained.insert(t_.constrained.end(), 3, 0);
        return static_cast<int>(t_.faceCount() - 1);
    }
    void setFace(int f, std::array<int, 3> v, std::array<int, 3> n, std::array<char, 3> c) {
        for (int k = 0; k < 3; ++k) {
            t_.faces[3 * static_cast<size_t>(f) + k] = v[k];
            t_.neighbors[3 * static_cast<size_t>(f) + k] = n[k];
            t_.constrained[3 * static_cast<size_t>(f) + k] = c[k];
        }
    }
    void replaceNeighbor(int f, int from, int to) {
        if (f < 0) return;
        for (int k = 0; k < 3; ++k)
            if (t_.neighbors[3 * static_cast<size_t>(f) + k] == from) t_.neighbors[3 * static_cast<size_t>(f) + k] = to;
    }

    // Face and corner index opposite the edge a-b (either direction), turning about a.
    bool findEdge(int a, int b, int& face, int& index) const {
        const int start = vertexFace_[static_cast<size_t>(a)];
        if (start < 0) return false;
        for (int way = 0; way < 2; ++way) {
            int f = start;
            for (size_t guard = 0; guard < t_.faceCount(); ++guard) {
                const int k = cornerOf(f, a);
                if (corner(f, k + 1) == b) return face = f, index = (k + 2) % 3, true;
                if (corner(f, k + 2) == b) return face = f, index = (k + 1) % 3, true;
                f = neighbor(f, way == 0 ? k + 1 : k + 2);
                if (f < 0) break;       // the hull: turn the other way from the start
                if (f == start) return false;  // a full turn
            }
        }
        return false;
    }
    // The hull vertex before ex (edge opposite corner i of face f = [c, ex, ey] is on the hull).
    int hullPredecessor(int f, int i) const {
        int cur = f, v = corner(f, i + 1);
        for (size_t guard = 0; guard < t_.faceCount(); ++guard) {
            const int k = cornerOf(cur, v);
            const int n = neighbor(cur, k + 1);  // across (corner k + 2, v)
            if (n < 0) return corner(cur, k + 2);
            cur = n;
        }
        throw std::logic_error("2D Steiner insertion: no hull edge");
    }
    int hullSuccessor(int f, int i) const {
        int cur = f, v = corner(f, i + 2);
        for (size_t guard = 0; guard < t_.faceCount(); ++guard) {
            const int k = cornerOf(cur, v);
            const int n = neighbor(cur, k + 2);  // across (v, corner k + 1)
            if (n < 0) return corner(cur, k + 1);
            cur = n;
        }
        throw std::logic_error("2D Steiner insertion: no hull edge");
    }

    // Lawson flips across the edges opposite v (CGAL's is_flipable: not constrained, not on
    // the hull, v inside the neighbour's circle with the symbolic perturbation).
    void restoreDelaunay(int v, std::array<int, 4> faces) {
        stack_.clear();
        for (int f : faces)
            if (f >= 0) stack_.push_back(f);
        for (size_t flips = 0; !stack_.empty(); ++flips) {
            if (flips > 16 * t_.faceCount() + 1024) throw std::runtime_error("2D Steiner insertion: flips do not end");
            const int x = stack_.back();
            stack_.pop_back();
            const int kv = cornerOf(x, v);
            const int y = neighbor(x, kv);
            if (y < 0 || t_.constrained[3 * static_cast<size_t>(x) + kv]) continue;
            const int p = corner(x, kv + 1), q = corner(x, kv + 2);  // x = [v, p, q]
            const int m = oppositeCorner(y, p, q);
            const int e = corner(y, m);  // y = [e, q, p]
            if (perturbedSideOfCircle2D(P(corner(y, 0)), P(corner(y, 1)), P(corner(y, 2)), P(v)) <= 0) continue;
            const int nXp = neighbor(x, kv + 1), nXq = neighbor(x, kv + 2);  // across (q, v), (v, p)
            const int nYq = neighbor(y, m + 1), nYp = neighbor(y, m + 2);    // across (p, e), (e, q)
            const char cXp = t_.constrained[3 * static_cast<size_t>(x) + (kv + 1) % 3];
            const char cXq = t_.constrained[3 * static_cast<size_t>(x) + (kv + 2) % 3];
            const char cYq = t_.constrained[3 * static_cast<size_t>(y) + (m + 1) % 3];
            const char cYp = t_.constrained[3 * static_cast<size_t>(y) + (m + 2) % 3];
            setFace(x, {v, p, e}, {nYq, y, nXq}, {cYq, 0, cXq});
            setFace(y, {v, e, q}, {nYp, nXp, x}, {cYp, cXp, 0});
            replaceNeighbor(nYq, y, x);
            replaceNeighbor(nXp, x, y);
            vertexFace_[static_cast<size_t>(v)] = x;
            vertexFace_[static_cast<size_t>(p)] = x;
            vertexFace_[static_cast<size_t>(e)] = x;
            vertexFace_[static_cast<size_t>(q)] = y;
            stack_.push_back(x);
            stack_.push_back(y);
        }
    }
};

}  // namespace

void insertSplitPoints2D(Triangulation2D& tri, const std::vector<ConstraintSplit>& splits,
                         std::vector<uint32_t>& appliedCount, std::vector<int>& firstVertex,
                         std::vector<int>* faceWinding) {
    appliedCount.assign(splits.size(), 0);
    firstVertex.assign(splits.size(), -1);
    size_t newPoints = 0;
    for (const ConstraintSplit& s : splits) newPoints += s.points.size() / 2;
    tri.points.reserve(tri.points.size() + 2 * newPoints);
    tri.vertexInput.reserve(tri.vertexInput.size() + newPoints);
    tri.faces.reserve(tri.faces.size() + 3 * 3 * newPoints);
    tri.neighbors.reserve(tri.neighbors.size() + 3 * 3 * newPoints);
    tri.constrained.reserve(tri.constrained.size() + 3 * 3 * newPoints);
    if (faceWinding) faceWinding->reserve(faceWinding->size() + 3 * newPoints);
    SplitMesh mesh(tri, faceWinding);
    for (size_t k = 0; k < splits.size(); ++k) {
        const ConstraintSplit& split = splits[k];
        if (split.from >= tri.inputVertex.size() || split.to >= tri.inputVertex.size()) continue;
        int previous = tri.inputVertex[split.from];
        const int last = tri.inputVertex[split.to];
        if (previous == last) continue;
        for (size_t i = 0; i + 1 < split.points.size(); i += 2) {
            const int v = mesh.splitConstrainedEdge(previous, last, split.points[i], split.points[i + 1]);
            if (v < 0) break;
            if (firstVertex[k] < 0) firstVertex[k] = v;
            ++appliedCount[k];
            previous = v;
        }
    }
}

void renumberAfterSplits2D(Triangulation2D& tri, const std::vector<size_t>& newInputIndex,
                           const std::vector<long long>& splitFirstIndex, const std::vector<uint32_t>& appliedCount,
                           const std::vector<int>& firstVertex, size_t inputCount) {
    const size_t vertexCount = tri.vertexCount();
    // Smallest new input point of every vertex (-1: an intersection vertex).
    std::vector<long long> input(vertexCount, -1);
    for (size_t v = 0; v < vertexCount; ++v)
        if (tri.vertexInput[v] >= 0) input[v] = static_cast<long long>(newInputIndex[static_cast<size_t>(tri.vertexInput[v])]);
    for (size_t k = 0; k < appliedCount.size(); ++k)
        for (uint32_t j = 0; j < appliedCount[k]; ++j) {
            long long& in = input[static_cast<size_t>(firstVertex[k]) + j];
            const long long point = splitFirstIndex[k] + j;
            if (in < 0 || point < in) in = point;
        }
    std::vector<int> byInput(inputCount, -1), newVertex(vertexCount, -1);
    for (size_t v = 0; v < vertexCount; ++v)
        if (input[v] >= 0) byInput[static_cast<size_t>(input[v])] = static_cast<int>(v);
    std::vector<double> points;
    std::vector<int> vertexInput;
    points.reserve(2 * vertexCount);
    vertexInput.reserve(vertexCount);
    auto add = [&](size_t v, long long in) {
        newVertex[v] = static_cast<int>(vertexInput.size());
        points.push_back(tri.points[2 * v]);
        points.push_back(tri.points[2 * v + 1]);
        vertexInput.push_back(static_cast<int>(in));
    };
    for (size_t i = 0; i < inputCount; ++i)
        if (byInput[i] >= 0) add(static_cast<size_t>(byInput[i]), static_cast<long long>(i));
    for (size_t v = 0; v < vertexCount; ++v)
        if (input[v] < 0) add(v, -1);
    std::vector<int> inputVertex(inputCount, -1);
    for (size_t i = 0; i < newInputIndex.size(); ++i) inputVertex[newInputIndex[i]] = newVertex[static_cast<size_t>(tri.inputVertex[i])];
    for (size_t k = 0; k < appliedCount.size(); ++k)
        for (uint32_t j = 0; j < appliedCount[k]; ++j)
            inputVertex[static_cast<size_t>(splitFirstIndex[k]) + j] = newVertex[static_cast<size_t>(firstVertex[k]) + j];
    for (int& c : tri.faces) c = newVertex[static_cast<size_t>(c)];
    tri.points = std::move(points);
    tri.vertexInput = std::move(vertexInput);
    tri.inputVertex = std::move(inputVertex);
}

}  // namespace aggrelod::detail
