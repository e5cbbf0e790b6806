// SPDX-License-Identifier: MIT
// aggrelod runtime: which nodes to draw this frame (docs/design.md §3), by the screen-space
// error rule of 3D Tiles / CesiumJS, with hysteresis, incremental from the previous frame's
// cut, without allocating per frame. Standard library only.
#pragma once

#include <aggrelod/runtime_file.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace aggrelod::runtime {

/// A perspective camera, as far as level selection needs it.
struct Camera {
    float position[3] = {0, 0, 0};  ///< world units
    float fovY = 1.0f;              ///< vertical field of view, radians, in (0, pi)
    float viewportHeight = 1080.0f; ///< pixels
};

/// A perspective camera with its orientation, for selection with frustum culling. The base
/// Camera part means the same as in the calls without culling.
struct ViewCamera : Camera {
    float forward[3] = {0, 0, -1};  ///< view direction, world space; any non-zero length
    float up[3] = {0, 1, 0};        ///< world space, not parallel to forward (only its part
                                    ///<   orthogonal to forward is used)
    float aspect = 16.0f / 9.0f;    ///< viewport width / height, > 0
    float nearDistance = 0.0f;      ///< near plane, world units along forward, >= 0
    float farDistance = INFINITY;   ///< far plane, world units along forward; infinity = none
};

/// Pixel tolerance and hysteresis band.
struct SelectionSettings {
    /// tau, pixels (> 0): a drawn node is replaced by its children when its screen-space
    /// error exceeds tau.
    float pixelTolerance = 1.0f;
    /// In (0, 1]: refined nodes are collapsed back into their parent only when the parent's
    /// error falls to tau * coarsenRatio or below. Between the two thresholds the previous
    /// frame's choice stays, so a camera hovering at a boundary does not flicker. 1 = none.
    float coarsenRatio = 0.75f;
};

/// Counters of the last selection (for profiling).
struct SelectionStats {
    uint32_t errorTests = 0;  ///< nodes whose screen-space error was evaluated
    uint32_t refined = 0;     ///< nodes replaced by their children this frame
    uint32_t coarsened = 0;   ///< nodes that replaced their descendants this frame
    uint32_t leasesExpired = 0;  ///< cut nodes re-examined because the camera moved enough
    uint32_t culled = 0;      ///< nodes left out by the frustum (select with a ViewCamera)
};

/// Per-file selection state. Allocates once (O(nodes + objects)) at construction; select()
/// and selectFull() allocate nothing. The file must outlive the selector. Not thread-safe:
/// use one selector per view.
///
/// The rule, for every root-to-leaf path, is "draw the first node that is not refined", where
/// a node is refined when it has children and its screen-space error
///     sse = geometricError * viewportHeight / (2 * d * tan(fovY / 2))
/// (d = distance from the camera to its bounding sphere, clamped to >= 1e-6) exceeds tau, or
/// exceeds tau * coarsenRatio when it was refined in the previous frame. Errors and spheres
/// nest (the file guarantees it up to a kNestingSlack relative slack, which the selector closes by
/// growing a parent's sphere/error by that much), so sse never grows going down and the nodes
/// drawn form a cut: every original object is covered exactly once.
class Selector {
public:
    explicit Selector(const RuntimeFile& file);

    /// Forgets the previous frame: the next selection starts from the roots, nothing refined.
    void reset();

    /// Drawing costs, used to skip nodes that are never worth drawing. A node costs its
    /// triangles plus trianglesPerDrawCall; one that costs more than the cheapest cover of
    /// its objects by nodes below it is always refined. Every node below a node passes the
    /// screen-space rule whenever that node does (errors and spheres nest), so the cut stays
    /// within tau and draws no more than the rule alone would, often less.
    /// originalTriangles: the triangles the engine draws for each original object
    /// (file.objectCount() entries), or null when unknown (then a leaf never counts as
    /// cheaper than the node above it). trianglesPerDrawCall >= 0 (triangles; NaN counts as
    /// 0). O(nodes); resets the selection. The constructor applies
    /// setDrawCosts(nullptr, kDefaultTrianglesPerDrawCall).
    void setDrawCosts(const uint32_t* originalTriangles, float trianglesPerDrawCall);
    /// Default cost of one draw call in triangles: descending to save fewer triangles than
    /// this per extra draw call is not worth it.
    static constexpr float kDefaultTrianglesPerDrawCall = 16.0f;
    /// Nodes that setDrawCosts found never worth drawing (always refined).
    uint32_t skippedNodeCount() const { return skippedCount_; }
    /// Whether `node` (< nodeCount) is one of them.
    bool skipsNode(uint32_t node) const { return skipped_[node] != 0; }

    /// Incremental selection: starts from the previous cut, refines or coarsens only where
    /// the errors crossed a threshold. Same result as selectFull() for the same state.
    void select(const Camera& camera, const SelectionSettings& settings);
    /// Reference selection: walks from the roots. Same rule and state as select().
    void selectFull(const Camera& camera, const SelectionSettings& settings);

    /// Selection with frustum culling. The same rule as select(), except that a node whose
    /// bounding sphere lies entirely outside the view frustum (the four side planes given by
    /// fovY and aspect, the near plane and, when finite, the far plane) is culled: it is not
    /// refined and not drawn. It is neither in cut() nor in proxyNodes() / originalObjects(),
    /// but in culledNodes(), so cut() and culledNodes() together still cover every original
    /// object exactly once; the objects of a culled node are simply not drawn. Refinement
    /// state and hysteresis carry over between calls as with select(), and the calls may be
    /// mixed freely. Cost: a walk from the roots over the visible part of the hierarchy (no
    /// leases, since a turn of the camera changes what is culled). A camera with a zero or
    /// non-finite forward, an up parallel to forward, aspect <= 0 or a NaN plane culls nothing.
    void select(const ViewCamera& camera, const SelectionSettings& settings);

    /// Collision cut around a query point (docs/design.md §3): a node is used when its error is
    /// at most maxErrorPerDistance * (distance from `point` to its bounding sphere), i.e.
    /// finer close to the querying agent. Incremental like select(). Units: world / world.
    void selectByDistance(const float point[3], float maxErrorPerDistance, float coarsenRatio = 0.75f);

    /// The cut: the nodes drawn, node indices (size <= nodeCount). Inner nodes and leaves
    /// mixed; order unspecified. Without culling it covers every original object exactly once.
    Span<uint32_t> cut() const { return {cut_.data(), cutSize_ - culledCount_}; }
    /// Nodes of the last select(ViewCamera) left out by the frustum (not refined, not drawn);
    /// empty after the calls without culling. Order unspecified.
    Span<uint32_t> culledNodes() const { return {cut_.data() + (cutSize_ - culledCount_), culledCount_}; }
    /// Changes of cut() made by the last call that selects (select, selectFull,
    /// selectByDistance, reset; construction counts as one from an empty cut): the nodes now
    /// in cut() that were not before, and those no longer in it. An engine streams in the
    /// meshes of entered() and may release those of left(). Node indices, each at most once
    /// (sizes <= nodeCount); order unspecified; no allocation. Both are empty when the cut did
    /// not change.
    Span<uint32_t> entered() const { return {entered_.data(), enteredCount_}; }
    Span<uint32_t> left() const { return {left_.data(), leftCount_}; }
    /// Inner nodes of the cut: draw their proxy meshes.
    Span<uint32_t> proxyNodes() const { return {proxies_.data(), proxyCount_}; }
    /// Original objects covered by leaves of the cut: the engine draws these itself.
    Span<uint32_t> originalObjects() const { return {originals_.data(), originalCount_}; }
    const SelectionStats& stats() const { return stats_; }

    /// Screen-space error in pixels of `node` for `camera` (the same formula as the rule).
    float screenSpaceErrorOf(uint32_t node, const Camera& camera) const;

private:
    struct Hot {  // what the rule and the output read, 32 bytes per node
        float center[3];
        float radius;
        float error;
        uint32_t parent;
        uint32_t firstSource;
        uint32_t leafSources;  // sourceCount for a leaf, 0 for an inner node
    };
    struct State {  // per-node frame state, 12 bytes
        uint32_t decidedStamp;  // frame in which refine() was cached
        uint32_t emittedStamp;  // frame in which the node was emitted by a coarsening
        uint8_t decision;
        uint8_t refined;        // refined in the previous (then current) frame
    };
    struct Frame {  // per-call parameters of the rule
        float p[3];
        float reachRefine;   // k / tau: refine when d < error * reachRefine
        float reachCoarsen;  // k / (tau * coarsenRatio)
    };
    bool exceeds(uint32_t node, float reach) const;
    bool refine(uint32_t node, const Frame& f);          // with hysteresis, cached per frame
    void emit(uint32_t node);
    void descend(uint32_t node, const Frame& f);          // fresh rule below a refined node
    void beginFrame(const Frame& f);
    void endFrame(uint32_t culled);
    void runIncremental(const Frame& f);
    void runFull(const Frame& f, bool cull);
    void runCulled(const Frame& f);
    bool outsideFrustum(uint32_t node) const;
    bool setFrustum(const ViewCamera& camera);
    // Cut changes: from the old and the new drawn lists (passes that rebuild the cut), or from
    // the nodes inserted or removed in place (leased pass).
    void diffRebuilt(const uint32_t* oldDrawn, uint32_t oldCount, const uint32_t* newDrawn, uint32_t newCount);
    void touch(uint32_t node);
    void diffTouched();
    // Leases (see selection.cpp): per cut node, how far the camera may travel before its
    // decision (or its parent's) can change; only expired nodes are re-examined.
    struct Lease {
        double expiry;  // odometer value
        uint32_t node;
        uint32_t serial;
    };
    void selectLeased(const Frame& f);
    void runLeased(const Frame& f);
    void dropIndex();
    void indexCut(const Frame& f);
    void insertNode(uint32_t node, const Frame& f);
    void removeNode(uint32_t node);
    void grantLease(uint32_t node, const Frame& f);
    void handleExpired(uint32_t node, const Frame& f);
    float slack(uint32_t node, float reach, const Frame& f) const;
    static Frame makeFrame(const float p[3], float k, float tau, float coarsenRatio);

    const RuntimeFile* file_;
    const uint32_t* sourceObjects_ = nullptr;
    std::vector<Hot> hot_;
    std::vector<uint8_t> skipped_;  // never worth drawing: always refined (setDrawCosts)
    uint32_t skippedCount_ = 0;
    std::vector<State> state_;
    std::vector<uint32_t> targetStamp_, target_;  // per-frame memo of coarsening climbs
    float frameP_[3] = {0, 0, 0};
    std::vector<uint32_t> cut_, nextCut_, stack_, newlyRefined_, proxies_, originals_;
    std::vector<uint32_t> posInCut_, posInProxies_, posInOriginals_, leaseSerial_;
    std::vector<Lease> heap_;  // min-heap on expiry, capacity fixed at construction
    double odometer_ = 0;      // camera path length since construction, world units
    float leaseP_[3] = {0, 0, 0};
    float leaseReach_[2] = {-1, -1};
    bool leasesValid_ = false;
    uint32_t cutSize_ = 0, proxyCount_ = 0, originalCount_ = 0, nextSize_ = 0;
    uint32_t culledCount_ = 0;     // the last culledCount_ entries of the cut_ cover are culled
    float planes_[6][4] = {};      // frustum: inward unit normal n and d, inside when n.p + d >= 0
    int planeCount_ = 0;
    std::vector<uint8_t> inView_;  // 1 when the node is in cut() (as of the end of the last call)
    std::vector<uint32_t> entered_, left_, touched_, touchStamp_;
    uint32_t enteredCount_ = 0, leftCount_ = 0, touchedCount_ = 0;
    uint32_t frame_ = 0;
    SelectionStats stats_;
};

}  // namespace aggrelod::runtime
