// SPDX-License-Identifier: MIT
// Level selection by screen-space error (docs/design.md §3): the cut of the hierarchy to draw,
// with hysteresis, incremental from the previous frame, allocation-free per frame.
//
// Incremental pass, for each node N of the previous cut:
// - if N's parent P no longer stays refined (its error fell under the coarsen threshold),
//   climb while the grandparent does not stay refined either; the highest such ancestor A
//   replaces all its previous descendants (emitted once, thanks to a per-frame stamp);
// - else if N exceeds tau, descend from N with the rule (only nodes that change are visited);
// - else N stays.
// Because errors and spheres nest, sse never grows going down a path, so a parent that stays
// refined implies every ancestor does: the climb stops at the first refined parent, and the
// result equals the walk from the roots (selectFull) for the same previous state.
//
// Leases make the steady state cost O(changes) instead of O(cut): a node's decision is
// "camera inside the sphere of radius error*reach + radius around its centre", and its
// parent's the same with the coarsen reach. Neither can change before the camera has moved
// by the distance to the nearer of those two sphere boundaries (minus a rounding margin).
// Each cut node gets that distance as a lease against an odometer (total camera path);
// a frame pops the expired leases from a min-heap and handles only those nodes with the pass
// above. The cut, proxy and original lists are kept with swap-removal. A change of tau, fov,
// viewport height or coarsen ratio re-runs the O(cut) pass and grants every lease anew.
#include <aggrelod/selection.h>

#include <aggrelod/runtime.h>

#include <algorithm>
#include <cmath>

namespace aggrelod::runtime {

Selector::Selector(const RuntimeFile& file) : file_(&file) {
    const uint32_t n = file.nodeCount();
    sourceObjects_ = file.allSourceObjects().data;
    hot_.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
        const NodeRecord& r = file.node(i);
        hot_[i] = {{r.sphereCenter[0], r.sphereCenter[1], r.sphereCenter[2]}, r.sphereRadius, r.geometricError,
                   r.parent, r.firstSource, r.childCount == 0 ? r.sourceCount : 0u};
    }
    // The incremental pass and the leases rely on sse never growing down a path. The file
    // guarantees nesting up to kNestingSlack; close that slack here, children before parents
    // (reverse preorder), by growing a parent's sphere and error just enough (plus
    // kSphereMargin relative, so float evaluation of the test cannot break the order either).
    {
        std::vector<uint32_t> order;
        order.reserve(n);
        std::vector<uint32_t> stack(file.roots().begin(), file.roots().end());
        while (!stack.empty()) {
            const uint32_t x = stack.back();
            stack.pop_back();
            order.push_back(x);
            for (uint32_t c : file.children(x)) stack.push_back(c);
        }
        for (size_t i = order.size(); i-- > 0;) {
            const uint32_t x = order[i];
            Hot& parent = hot_[x];
            for (uint32_t c : file.children(x)) {
                const Hot& child = hot_[c];
                double d2 = 0;
                for (int k = 0; k < 3; ++k) {
                    const double d = double(parent.center[k]) - child.center[k];
                    d2 += d * d;
                }
                const double needed = (std::sqrt(d2) + child.radius) * (1.0 + kSphereMargin);
                if (needed > parent.radius) parent.radius = static_cast<float>(needed);
                parent.error = std::max(parent.error, child.error);
            }
        }
    }
    state_.assign(n, State{0, 0, 0, 0});
    targetStamp_.assign(n, 0);
    target_.assign(n, kNoIndex);
    cut_.resize(n);
    nextCut_.resize(n);
    stack_.resize(n);
    newlyRefined_.resize(n);
    proxies_.resize(n);
    originals_.resize(file.objectCount());
    posInCut_.assign(n, kNoIndex);
    posInProxies_.assign(n, kNoIndex);
    posInOriginals_.assign(file.objectCount(), kNoIndex);
    leaseSerial_.assign(n, 0);
    heap_.reserve(2 * size_t(n) + 16);
    inView_.assign(n, 0);
    entered_.resize(n);
    left_.resize(n);
    touched_.resize(n);
    touchStamp_.assign(n, 0);
    setDrawCosts(nullptr, kDefaultTrianglesPerDrawCall);
}

void Selector::setDrawCosts(const uint32_t* originalTriangles, float trianglesPerDrawCall) {
    const RuntimeFile& file = *file_;
    const uint32_t n = file.nodeCount();
    const double perDraw = trianglesPerDrawCall > 0 && std::isfinite(trianglesPerDrawCall) ? trianglesPerDrawCall : 0.0;
    // Preorder from the roots; the cheapest cover of a node's objects, children before
    // parents: min(own cost, sum over the children). A leaf costs its originals (unknown:
    // infinite, so it is never preferred).
    std::vector<uint32_t> order;
    order.reserve(n);
    std::vector<uint32_t>& stack = stack_;  // free outside a selection
    uint32_t top = 0;
    for (uint32_t root : file.roots()) stack[top++] = root;
    while (top > 0) {
        const uint32_t x = stack[--top];
        order.push_back(x);
        for (uint32_t c : file.children(x)) stack[top++] = c;
    }
    std::vector<double> cheapest(n, 0.0);
    skipped_.assign(n, 0);
    skippedCount_ = 0;
    for (size_t i = order.size(); i-- > 0;) {
        const uint32_t x = order[i];
        const NodeRecord& r = file.node(x);
        if (r.childCount == 0) {
            double own = originalTriangles ? perDraw : INFINITY;
            if (originalTriangles)
                for (uint32_t o : file.sources(x)) own += originalTriangles[o] + (o == file.sources(x)[0] ? 0.0 : perDraw);
            cheapest[x] = own;
            continue;
        }
        const double own = double(r.indexCount / 3) + perDraw;
        double below = 0;
        for (uint32_t c : file.children(x)) below += cheapest[c];
        if (below < own) {
            skipped_[x] = 1;
            ++skippedCount_;
        }
        cheapest[x] = std::min(own, below);
    }
    // The climb of the incremental pass goes from a node to the nearest ancestor that can be
    // drawn: skipped nodes are always refined, so they never stop it.
    for (const uint32_t x : order) {  // parents before children
        uint32_t up = file.node(x).parent;
        while (up != kNoIndex && skipped_[up]) up = file.node(up).parent;
        hot_[x].parent = up;
    }
    reset();
}

void Selector::reset() {
    dropIndex();
    for (State& st : state_) st.refined = 0;
    nextSize_ = proxyCount_ = originalCount_ = 0;
    for (uint32_t root : file_->roots()) emit(root);
    endFrame(0);
}

Selector::Frame Selector::makeFrame(const float p[3], float k, float tau, float coarsenRatio) {
    // Guard against nonsense settings rather than dividing by zero.
    if (!(tau > 1e-12f)) tau = 1e-12f;
    if (!(coarsenRatio > 1e-3f)) coarsenRatio = 1e-3f;
    if (coarsenRatio > 1.0f) coarsenRatio = 1.0f;
    Frame f{{p[0], p[1], p[2]}, k / tau, k / (tau * coarsenRatio)};
    return f;
}

float Selector::screenSpaceErrorOf(uint32_t node, const Camera& camera) const {
    const Hot& b = hot_[node];
    double d2 = 0;
    for (int k = 0; k < 3; ++k) {
        const double d = double(camera.position[k]) - b.center[k];
        d2 += d * d;
    }
    return static_cast<float>(screenSpaceError(b.error, std::sqrt(d2) - b.radius, camera.fovY,
                                               camera.viewportHeight));
}

// sse > tau  <=>  error * k / tau > d  <=>  |p - c| < error * reach + radius (no sqrt, no divide).
inline bool Selector::exceeds(uint32_t node, float reach) const {
    const Hot& b = hot_[node];
    if (!(b.error > 0.0f)) return false;
    const float dx = frameP_[0] - b.center[0], dy = frameP_[1] - b.center[1], dz = frameP_[2] - b.center[2];
    const float r = b.error * reach + b.radius;
    return dx * dx + dy * dy + dz * dz < r * r;
}

inline bool Selector::refine(uint32_t node, const Frame& f) {
    State& st = state_[node];
    if (st.decidedStamp == frame_) return st.decision != 0;
    ++stats_.errorTests;
    const bool yes = hot_[node].leafSources == 0 &&
                     (skipped_[node] || exceeds(node, f.reachRefine) || (st.refined && exceeds(node, f.reachCoarsen)));
    st.decidedStamp = frame_;
    st.decision = yes;
    return yes;
}

inline void Selector::emit(uint32_t node) {
    nextCut_[nextSize_++] = node;
    const Hot& h = hot_[node];
    if (h.leafSources != 0) {
        for (uint32_t k = 0; k < h.leafSources; ++k) originals_[originalCount_++] = sourceObjects_[h.firstSource + k];
    } else {
        proxies_[proxyCount_++] = node;
    }
}

void Selector::descend(uint32_t start, const Frame& f) {
    uint32_t top = 0;
    stack_[top++] = start;
    while (top > 0) {
        const uint32_t x = stack_[--top];
        if (refine(x, f)) {
            state_[x].refined = 1;
            ++stats_.refined;
            const Span<uint32_t> kids = file_->children(x);
            for (size_t i = kids.size; i-- > 0;) stack_[top++] = kids[i];
        } else {
            emit(x);
        }
    }
}

void Selector::beginFrame(const Frame& f) {
    if (++frame_ == 0) {  // stamp wrap-around after 2^32 frames
        for (State& st : state_) st.decidedStamp = st.emittedStamp = 0;
        std::fill(targetStamp_.begin(), targetStamp_.end(), 0);
        std::fill(touchStamp_.begin(), touchStamp_.end(), 0);
        frame_ = 1;
    }
    for (int k = 0; k < 3; ++k) frameP_[k] = f.p[k];
    stats_ = {};
}

// nextCut_[0, nextSize_) is the new cover, its last `culled` entries culled.
void Selector::endFrame(uint32_t culled) {
    diffRebuilt(cut_.data(), cutSize_ - culledCount_, nextCut_.data(), nextSize_ - culled);
    std::swap(cut_, nextCut_);
    cutSize_ = nextSize_;
    culledCount_ = culled;
}

void Selector::diffRebuilt(const uint32_t* oldDrawn, uint32_t oldCount, const uint32_t* newDrawn, uint32_t newCount) {
    enteredCount_ = leftCount_ = 0;
    for (uint32_t i = 0; i < newCount; ++i) {
        const uint32_t x = newDrawn[i];
        if (!inView_[x]) entered_[enteredCount_++] = x;
        inView_[x] = 2;  // in both cuts or entered
    }
    for (uint32_t i = 0; i < oldCount; ++i) {
        const uint32_t x = oldDrawn[i];
        if (inView_[x] == 1) {
            left_[leftCount_++] = x;
            inView_[x] = 0;
        }
    }
    for (uint32_t i = 0; i < newCount; ++i) inView_[newDrawn[i]] = 1;
}

inline void Selector::touch(uint32_t node) {
    if (touchStamp_[node] == frame_) return;
    touchStamp_[node] = frame_;
    touched_[touchedCount_++] = node;
}

void Selector::diffTouched() {
    enteredCount_ = leftCount_ = 0;
    for (uint32_t i = 0; i < touchedCount_; ++i) {
        const uint32_t x = touched_[i];
        const uint8_t now = posInCut_[x] != kNoIndex;
        if (now && !inView_[x]) entered_[enteredCount_++] = x;
        if (!now && inView_[x]) left_[leftCount_++] = x;
        inView_[x] = now;
    }
    touchedCount_ = 0;
}

void Selector::runIncremental(const Frame& f) {
    dropIndex();
    beginFrame(f);
    nextSize_ = proxyCount_ = originalCount_ = 0;
    for (uint32_t i = 0; i < cutSize_; ++i) {
        const uint32_t n = cut_[i];
        const uint32_t parent = hot_[n].parent;
        if (parent != kNoIndex && !refine(parent, f)) {
            uint32_t top;
            if (targetStamp_[parent] == frame_) {
                top = target_[parent];  // a sibling already climbed from here
            } else {
                top = parent;
                for (uint32_t g = hot_[top].parent; g != kNoIndex && !refine(g, f); g = hot_[g].parent) top = g;
                targetStamp_[parent] = frame_;
                target_[parent] = top;
                for (uint32_t x = parent;; x = hot_[x].parent) {
                    state_[x].refined = 0;
                    if (x == top) break;
                }
            }
            if (state_[top].emittedStamp != frame_) {
                state_[top].emittedStamp = frame_;
                ++stats_.coarsened;
                emit(top);
            }
        } else if (hot_[n].leafSources == 0 && refine(n, f)) {
            descend(n, f);
        } else {
            emit(n);
        }
    }
    endFrame(0);
}

void Selector::runFull(const Frame& f, bool cull) {
    dropIndex();
    beginFrame(f);
    nextSize_ = proxyCount_ = originalCount_ = 0;
    // Culled nodes are put at the end of nextCut_ (the cover never exceeds its size).
    const uint32_t capacity = static_cast<uint32_t>(nextCut_.size());
    uint32_t top = 0, refinedCount = 0, culled = 0;
    const Span<uint32_t> roots = file_->roots();
    for (size_t i = roots.size; i-- > 0;) stack_[top++] = roots[i];
    while (top > 0) {
        const uint32_t x = stack_[--top];
        if (cull && outsideFrustum(x)) {
            nextCut_[capacity - 1 - culled++] = x;
        } else if (refine(x, f)) {
            newlyRefined_[refinedCount++] = x;
            const Span<uint32_t> kids = file_->children(x);
            for (size_t i = kids.size; i-- > 0;) stack_[top++] = kids[i];
        } else {
            emit(x);
        }
    }
    // Refined flags now describe the new cut: clear the old ancestors, mark the new ones.
    for (uint32_t i = 0; i < cutSize_; ++i)
        for (uint32_t x = hot_[cut_[i]].parent; x != kNoIndex && state_[x].refined; x = hot_[x].parent)
            state_[x].refined = 0;
    for (uint32_t i = 0; i < refinedCount; ++i) state_[newlyRefined_[i]].refined = 1;
    stats_.refined = refinedCount;
    stats_.culled = culled;
    // The culled nodes follow the drawn ones (in walk order); the copy runs forwards to a
    // start that is not after the source's, so the ranges may overlap.
    std::reverse(nextCut_.begin() + (capacity - culled), nextCut_.end());
    std::copy(nextCut_.begin() + (capacity - culled), nextCut_.end(), nextCut_.begin() + nextSize_);
    nextSize_ += culled;
    endFrame(culled);
}

bool Selector::setFrustum(const ViewCamera& c) {
    planeCount_ = 0;
    const double f0[3] = {c.forward[0], c.forward[1], c.forward[2]}, u0[3] = {c.up[0], c.up[1], c.up[2]};
    const double fl = std::sqrt(f0[0] * f0[0] + f0[1] * f0[1] + f0[2] * f0[2]);
    if (!(fl > 0) || !std::isfinite(fl) || !(c.aspect > 0) || !std::isfinite(c.aspect) || !(c.fovY > 0) ||
        !(c.fovY < 3.14159265f))
        return false;
    const double f[3] = {f0[0] / fl, f0[1] / fl, f0[2] / fl};
    double r[3] = {f[1] * u0[2] - f[2] * u0[1], f[2] * u0[0] - f[0] * u0[2], f[0] * u0[1] - f[1] * u0[0]};
    const double rl = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
    if (!(rl > 1e-12 * std::sqrt(u0[0] * u0[0] + u0[1] * u0[1] + u0[2] * u0[2])) || !std::isfinite(rl)) return false;
    for (double& x : r) x /= rl;
    const double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]};
    const double tanY = std::tan(0.5 * double(c.fovY)), tanX = tanY * double(c.aspect);
    // Side planes through the eye: inside when |q.r| <= (q.f) tanX and |q.u| <= (q.f) tanY
    // (q = p - eye), i.e. q.(f tan -/+ axis) >= 0, normalised.
    double normals[6][3];
    double offsets[6];
    int count = 0;
    const double sx = 1.0 / std::sqrt(tanX * tanX + 1.0), sy = 1.0 / std::sqrt(tanY * tanY + 1.0);
    for (int sign : {-1, 1}) {
        for (int k = 0; k < 3; ++k) normals[count][k] = (f[k] * tanX + sign * r[k]) * sx;
        ++count;
        for (int k = 0; k < 3; ++k) normals[count][k] = (f[k] * tanY + sign * u[k]) * sy;
        ++count;
    }
    for (int p = 0; p < count; ++p) offsets[p] = 0;
    // Near: q.f >= near; far: q.f <= far.
    const double nearD = std::max(0.0, double(c.nearDistance));
    for (int k = 0; k < 3; ++k) normals[count][k] = f[k];
    offsets[count++] = -nearD;
    if (std::isfinite(c.farDistance)) {
        for (int k = 0; k < 3; ++k) normals[count][k] = -f[k];
        offsets[count++] = double(c.farDistance);
    }
    for (int p = 0; p < count; ++p) {
        const double d = offsets[p] - (normals[p][0] * c.position[0] + normals[p][1] * c.position[1] +
                                       normals[p][2] * c.position[2]);
        if (!std::isfinite(d)) return false;
        for (int k = 0; k < 3; ++k) planes_[p][k] = float(normals[p][k]);
        planes_[p][3] = float(d);
    }
    planeCount_ = count;
    return true;
}

// Outside when the whole sphere is on the outer side of one plane; the float evaluation gets
// a relative margin so that rounding never culls a sphere that touches the frustum.
inline bool Selector::outsideFrustum(uint32_t node) const {
    const Hot& h = hot_[node];
    for (int p = 0; p < planeCount_; ++p) {
        const float* q = planes_[p];
        const float s = q[0] * h.center[0] + q[1] * h.center[1] + q[2] * h.center[2] + q[3];
        const float scale = std::fabs(q[0] * h.center[0]) + std::fabs(q[1] * h.center[1]) +
                            std::fabs(q[2] * h.center[2]) + std::fabs(q[3]) + h.radius;
        if (s < -h.radius - 1e-5f * scale) return true;
    }
    return false;
}

static float projectionScale(const Camera& camera) {
    // k = viewportHeight / (2 tan(fovY / 2)): sse = error * k / d.
    return camera.viewportHeight / (2.0f * std::tan(camera.fovY * 0.5f));
}

void Selector::select(const Camera& camera, const SelectionSettings& settings) {
    selectLeased(makeFrame(camera.position, projectionScale(camera), settings.pixelTolerance,
                           settings.coarsenRatio));
}

void Selector::selectFull(const Camera& camera, const SelectionSettings& settings) {
    runFull(makeFrame(camera.position, projectionScale(camera), settings.pixelTolerance,
                      settings.coarsenRatio),
            false);
}

void Selector::select(const ViewCamera& camera, const SelectionSettings& settings) {
    const bool cull = setFrustum(camera);
    runFull(makeFrame(camera.position, projectionScale(camera), settings.pixelTolerance, settings.coarsenRatio),
            cull);
}

void Selector::selectByDistance(const float point[3], float maxErrorPerDistance, float coarsenRatio) {
    selectLeased(makeFrame(point, 1.0f, maxErrorPerDistance, coarsenRatio));
}

// ---- leases -------------------------------------------------------------------------------

void Selector::selectLeased(const Frame& f) {
    if (leasesValid_ && f.reachRefine == leaseReach_[0] && f.reachCoarsen == leaseReach_[1]) {
        runLeased(f);
        return;
    }
    runIncremental(f);
    indexCut(f);
}

// Forgets positions and leases of the current cut (before a pass that rebuilds the lists).
void Selector::dropIndex() {
    if (!leasesValid_) return;
    for (uint32_t i = 0; i < cutSize_; ++i) {
        const uint32_t x = cut_[i];
        posInCut_[x] = posInProxies_[x] = kNoIndex;
        ++leaseSerial_[x];
        const Hot& h = hot_[x];
        for (uint32_t k = 0; k < h.leafSources; ++k) posInOriginals_[sourceObjects_[h.firstSource + k]] = kNoIndex;
    }
    heap_.clear();
    leasesValid_ = false;
}

void Selector::indexCut(const Frame& f) {
    for (uint32_t i = 0; i < cutSize_; ++i) posInCut_[cut_[i]] = i;
    for (uint32_t i = 0; i < proxyCount_; ++i) posInProxies_[proxies_[i]] = i;
    for (uint32_t i = 0; i < originalCount_; ++i) posInOriginals_[originals_[i]] = i;
    heap_.clear();
    for (int k = 0; k < 3; ++k) leaseP_[k] = f.p[k];
    for (uint32_t i = 0; i < cutSize_; ++i) grantLease(cut_[i], f);
    leaseReach_[0] = f.reachRefine;
    leaseReach_[1] = f.reachCoarsen;
    leasesValid_ = true;
}

// Distance from the camera to the boundary of the sphere "decision changes here", minus a
// margin for float rounding of the test in exceeds().
inline float Selector::slack(uint32_t node, float reach, const Frame& f) const {
    const Hot& h = hot_[node];
    const float dx = f.p[0] - h.center[0], dy = f.p[1] - h.center[1], dz = f.p[2] - h.center[2];
    const float d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const float r = h.error * reach + h.radius;
    return std::fabs(d - r) - 1e-5f * (d + r);
}

void Selector::grantLease(uint32_t node, const Frame& f) {
    const Hot& h = hot_[node];
    float s = INFINITY;
    if (h.leafSources == 0 && h.error > 0.0f && !skipped_[node]) s = slack(node, f.reachRefine, f);
    if (h.parent != kNoIndex) s = std::min(s, slack(h.parent, f.reachCoarsen, f));
    const uint32_t serial = ++leaseSerial_[node];
    if (s == INFINITY) return;  // nothing can change this node's state
    if (heap_.size() == heap_.capacity() || heap_.size() > 2 * size_t(cutSize_) + 64) {
        // Drop stale entries (nodes that left the cut or got a newer lease): the valid ones
        // are at most one per cut node, so this always frees room, and keeping the heap
        // within twice the cut keeps its sifts in cache. Amortised by the pushes it undoes.
        size_t kept = 0;
        for (const Lease& l : heap_)
            if (posInCut_[l.node] != kNoIndex && leaseSerial_[l.node] == l.serial) heap_[kept++] = l;
        heap_.resize(kept);
        std::make_heap(heap_.begin(), heap_.end(), [](const Lease& a, const Lease& b) { return a.expiry > b.expiry; });
    }
    heap_.push_back({odometer_ + double(std::max(s, 0.0f)), node, serial});
    std::push_heap(heap_.begin(), heap_.end(), [](const Lease& a, const Lease& b) { return a.expiry > b.expiry; });
}

void Selector::insertNode(uint32_t node, const Frame& f) {
    touch(node);
    posInCut_[node] = cutSize_;
    cut_[cutSize_++] = node;
    const Hot& h = hot_[node];
    if (h.leafSources != 0) {
        for (uint32_t k = 0; k < h.leafSources; ++k) {
            const uint32_t o = sourceObjects_[h.firstSource + k];
            posInOriginals_[o] = originalCount_;
            originals_[originalCount_++] = o;
        }
    } else {
        posInProxies_[node] = proxyCount_;
        proxies_[proxyCount_++] = node;
    }
    grantLease(node, f);
}

void Selector::removeNode(uint32_t node) {
    touch(node);
    const uint32_t i = posInCut_[node];
    const uint32_t last = cut_[--cutSize_];
    cut_[i] = last;
    posInCut_[last] = i;
    posInCut_[node] = kNoIndex;
    ++leaseSerial_[node];
    const Hot& h = hot_[node];
    if (h.leafSources != 0) {
        for (uint32_t k = 0; k < h.leafSources; ++k) {
            const uint32_t o = sourceObjects_[h.firstSource + k];
            const uint32_t j = posInOriginals_[o];
            const uint32_t lastObject = originals_[--originalCount_];
            originals_[j] = lastObject;
            posInOriginals_[lastObject] = j;
            posInOriginals_[o] = kNoIndex;
        }
    } else {
        const uint32_t j = posInProxies_[node];
        const uint32_t lastProxy = proxies_[--proxyCount_];
        proxies_[j] = lastProxy;
        posInProxies_[lastProxy] = j;
        posInProxies_[node] = kNoIndex;
    }
}

void Selector::handleExpired(uint32_t n, const Frame& f) {
    const uint32_t parent = hot_[n].parent;
    if (parent != kNoIndex && !refine(parent, f)) {
        uint32_t top = parent;
        for (uint32_t g = hot_[top].parent; g != kNoIndex && !refine(g, f); g = hot_[g].parent) top = g;
        // Everything of the cut under `top` goes: walk down through the refined nodes (each
        // of them is an ancestor of cut nodes, since the cut covers every path once).
        uint32_t sp = 0;
        stack_[sp++] = top;
        while (sp > 0) {
            const uint32_t x = stack_[--sp];
            if (posInCut_[x] != kNoIndex) {
                removeNode(x);
            } else {
                state_[x].refined = 0;
                const Span<uint32_t> kids = file_->children(x);
                for (size_t i = 0; i < kids.size; ++i) stack_[sp++] = kids[i];
            }
        }
        ++stats_.coarsened;
        insertNode(top, f);
    } else if (hot_[n].leafSources == 0 && refine(n, f)) {
        removeNode(n);
        uint32_t sp = 0;
        stack_[sp++] = n;
        while (sp > 0) {
            const uint32_t x = stack_[--sp];
            if (refine(x, f)) {
                state_[x].refined = 1;
                ++stats_.refined;
                const Span<uint32_t> kids = file_->children(x);
                for (size_t i = 0; i < kids.size; ++i) stack_[sp++] = kids[i];
            } else {
                insertNode(x, f);
            }
        }
    } else {
        grantLease(n, f);
    }
}

void Selector::runLeased(const Frame& f) {
    beginFrame(f);
    const double dx = double(f.p[0]) - leaseP_[0], dy = double(f.p[1]) - leaseP_[1], dz = double(f.p[2]) - leaseP_[2];
    odometer_ += std::sqrt(dx * dx + dy * dy + dz * dz);
    for (int k = 0; k < 3; ++k) leaseP_[k] = f.p[k];
    const auto later = [](const Lease& a, const Lease& b) { return a.expiry > b.expiry; };
    // Leases granted during this frame expire at >= odometer_: they are not popped again now.
    while (!heap_.empty() && heap_.front().expiry < odometer_) {
        const Lease l = heap_.front();
        std::pop_heap(heap_.begin(), heap_.end(), later);
        heap_.pop_back();
        if (leaseSerial_[l.node] != l.serial || posInCut_[l.node] == kNoIndex) continue;  // stale
        ++stats_.leasesExpired;
        handleExpired(l.node, f);
    }
    diffTouched();
}

}  // namespace aggrelod::runtime
