// aggrelod runtime: which nodes to draw this frame (DESIGN section 3), by the screen-space
// error rule of 3D Tiles / CesiumJS, with hysteresis, incremental from the previous frame's
// cut, without allocating per frame. Standard library only.
#pragma once

#include <aggrelod/runtime_file.h>

#include <cstdint>
#include <vector>

namespace aggrelod::runtime {

/// A perspective camera, as far as level selection needs it.
struct Camera {
    float position[3] = {0, 0, 0};  ///< world units
    float fovY = 1.0f;              ///< vertical field of view, radians, in (0, pi)
    float viewportHeight = 1080.0f; ///< pixels
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
/// nest (the file guarantees it up to a 1e-5 relative slack, which the selector closes by
/// growing a parent's sphere/error by that much), so sse never grows going down and the nodes
/// drawn form a cut: every original object is covered exactly once.
class Selector {
public:
    explicit Selector(const RuntimeFile& file);

    /// Forgets the previous frame: the next selection starts from the roots, nothing refined.
    void reset();

    /// Incremental selection: starts from the previous cut, refines or coarsens only where
    /// the errors crossed a threshold. Same result as selectFull() for the same state.
    void select(const Camera& camera, const SelectionSettings& settings);
    /// Reference selection: walks from the roots. Same rule and state as select().
    void selectFull(const Camera& camera, const SelectionSettings& settings);

    /// Collision cut around a query point (DESIGN section 3): a node is used when its error is
    /// at most maxErrorPerDistance * (distance from `point` to its bounding sphere), i.e.
    /// finer close to the querying agent. Incremental like select(). Units: world / world.
    void selectByDistance(const float point[3], float maxErrorPerDistance, float coarsenRatio = 0.75f);

    /// The cut: node indices (size <= nodeCount). Inner nodes and leaves mixed; order unspecified.
    Span<uint32_t> cut() const { return {cut_.data(), cutSize_}; }
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
    void endFrame();
    void runIncremental(const Frame& f);
    void runFull(const Frame& f);
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
    uint32_t frame_ = 0;
    SelectionStats stats_;
};

}  // namespace aggrelod::runtime
