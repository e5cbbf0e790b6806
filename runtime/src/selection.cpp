// Level selection by screen-space error (DESIGN section 3): the cut of the hierarchy to draw,
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
#include <aggrelod/selection.h>

#include <aggrelod/runtime.h>

#include <algorithm>
#include <cmath>

namespace aggrelod::runtime {

Selector::Selector(const RuntimeFile& file) : file_(&file) {
    const uint32_t n = file.nodeCount();
    bounds_.resize(n);
    childless_.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
        const NodeRecord& r = file.node(i);
        bounds_[i] = {{r.sphereCenter[0], r.sphereCenter[1], r.sphereCenter[2]},
                      r.sphereRadius, r.geometricError, r.parent};
        childless_[i] = r.childCount == 0;
    }
    refined_.assign(n, 0);
    decidedStamp_.assign(n, 0);
    decision_.assign(n, 0);
    emittedStamp_.assign(n, 0);
    targetStamp_.assign(n, 0);
    target_.assign(n, kNoIndex);
    cut_.resize(n);
    nextCut_.resize(n);
    stack_.resize(n);
    newlyRefined_.resize(n);
    proxies_.resize(n);
    originals_.resize(file.objectCount());
    reset();
}

void Selector::reset() {
    std::fill(refined_.begin(), refined_.end(), 0);
    nextSize_ = proxyCount_ = originalCount_ = 0;
    for (uint32_t root : file_->roots()) emit(root);
    std::swap(cut_, nextCut_);
    cutSize_ = nextSize_;
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
    const Bound& b = bounds_[node];
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
    const Bound& b = bounds_[node];
    if (!(b.error > 0.0f)) return false;
    const float dx = frameP_[0] - b.center[0], dy = frameP_[1] - b.center[1], dz = frameP_[2] - b.center[2];
    const float r = b.error * reach + b.radius;
    return dx * dx + dy * dy + dz * dz < r * r;
}

inline bool Selector::refine(uint32_t node, const Frame& f) {
    if (decidedStamp_[node] == frame_) return decision_[node] != 0;
    ++stats_.errorTests;
    const bool yes = !childless_[node] &&
                     (exceeds(node, f.reachRefine) || (refined_[node] && exceeds(node, f.reachCoarsen)));
    decidedStamp_[node] = frame_;
    decision_[node] = yes;
    return yes;
}

inline void Selector::emit(uint32_t node) {
    nextCut_[nextSize_++] = node;
    if (childless_[node]) {
        for (uint32_t o : file_->sources(node)) originals_[originalCount_++] = o;
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
            refined_[x] = 1;
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
        std::fill(decidedStamp_.begin(), decidedStamp_.end(), 0);
        std::fill(emittedStamp_.begin(), emittedStamp_.end(), 0);
        std::fill(targetStamp_.begin(), targetStamp_.end(), 0);
        frame_ = 1;
    }
    for (int k = 0; k < 3; ++k) frameP_[k] = f.p[k];
    stats_ = {};
    nextSize_ = proxyCount_ = originalCount_ = 0;
}

void Selector::endFrame() {
    std::swap(cut_, nextCut_);
    cutSize_ = nextSize_;
}

void Selector::runIncremental(const Frame& f) {
    beginFrame(f);
    for (uint32_t i = 0; i < cutSize_; ++i) {
        const uint32_t n = cut_[i];
        const uint32_t parent = bounds_[n].parent;
        if (parent != kNoIndex && !refine(parent, f)) {
            uint32_t top;
            if (targetStamp_[parent] == frame_) {
                top = target_[parent];  // a sibling already climbed from here
            } else {
                top = parent;
                for (uint32_t g = bounds_[top].parent; g != kNoIndex && !refine(g, f); g = bounds_[g].parent) top = g;
                targetStamp_[parent] = frame_;
                target_[parent] = top;
                for (uint32_t x = parent;; x = bounds_[x].parent) {
                    refined_[x] = 0;
                    if (x == top) break;
                }
            }
            if (emittedStamp_[top] != frame_) {
                emittedStamp_[top] = frame_;
                ++stats_.coarsened;
                emit(top);
            }
        } else if (refine(n, f)) {
            descend(n, f);
        } else {
            emit(n);
        }
    }
    endFrame();
}

void Selector::runFull(const Frame& f) {
    beginFrame(f);
    uint32_t top = 0, refinedCount = 0;
    const Span<uint32_t> roots = file_->roots();
    for (size_t i = roots.size; i-- > 0;) stack_[top++] = roots[i];
    while (top > 0) {
        const uint32_t x = stack_[--top];
        if (refine(x, f)) {
            newlyRefined_[refinedCount++] = x;
            const Span<uint32_t> kids = file_->children(x);
            for (size_t i = kids.size; i-- > 0;) stack_[top++] = kids[i];
        } else {
            emit(x);
        }
    }
    // Refined flags now describe the new cut: clear the old ancestors, mark the new ones.
    for (uint32_t i = 0; i < cutSize_; ++i)
        for (uint32_t x = bounds_[cut_[i]].parent; x != kNoIndex && refined_[x]; x = bounds_[x].parent)
            refined_[x] = 0;
    for (uint32_t i = 0; i < refinedCount; ++i) refined_[newlyRefined_[i]] = 1;
    stats_.refined = refinedCount;
    endFrame();
}

static float projectionScale(const Camera& camera) {
    // k = viewportHeight / (2 tan(fovY / 2)): sse = error * k / d.
    return camera.viewportHeight / (2.0f * std::tan(camera.fovY * 0.5f));
}

void Selector::select(const Camera& camera, const SelectionSettings& settings) {
    runIncremental(makeFrame(camera.position, projectionScale(camera), settings.pixelTolerance,
                             settings.coarsenRatio));
}

void Selector::selectFull(const Camera& camera, const SelectionSettings& settings) {
    runFull(makeFrame(camera.position, projectionScale(camera), settings.pixelTolerance,
                      settings.coarsenRatio));
}

void Selector::selectByDistance(const float point[3], float maxErrorPerDistance, float coarsenRatio) {
    runIncremental(makeFrame(point, 1.0f, maxErrorPerDistance, coarsenRatio));
}

}  // namespace aggrelod::runtime
