/* SPDX-License-Identifier: MIT */
/* aggrelod runtime, C API: open a baked `.aglod` file, select the nodes to draw for a camera,
 * cast rays against a cut (optional collision library). For engines written in C or bound
 * from other languages. Plain C99; every function is safe to call with NULL handles (it then
 * returns an error or does nothing).
 *
 * Link: aggrelod_runtime (open, select) and aggrelod_runtime_collision (the aglod_collision_*
 * and aglod_raycast functions; needs Embree 3).
 *
 * Memory: handles are created and destroyed by the pair functions below. Arrays returned in
 * aglod_cut / aglod_hit are views owned by the selector / file: valid until the next call on
 * the same selector, or until the file is closed. */
#ifndef AGGRELOD_RUNTIME_H
#define AGGRELOD_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Same values as aggrelod::runtime::FileStatus, plus AGLOD_INVALID_ARGUMENT. */
typedef enum aglod_status {
    AGLOD_OK = 0,
    AGLOD_IO_ERROR = 1,
    AGLOD_WRONG_MAGIC = 2,
    AGLOD_WRONG_VERSION = 3,
    AGLOD_TRUNCATED = 4,
    AGLOD_CHECKSUM_MISMATCH = 5,
    AGLOD_BAD_SECTION = 6,
    AGLOD_INDEX_OUT_OF_RANGE = 7,
    AGLOD_BAD_TREE = 8,
    AGLOD_BAD_VALUE = 9,
    AGLOD_MISALIGNED = 10,
    AGLOD_UNSUPPORTED_HOST = 11,
    AGLOD_INVALID_ARGUMENT = 100,
    AGLOD_COLLISION_ERROR = 101
} aglod_status;

typedef struct aglod_file aglod_file;
typedef struct aglod_selector aglod_selector;
typedef struct aglod_collision aglod_collision;

/* Marks leaves (original objects) in aglod_node_level, and "originals" in aglod_collision_use_level. */
#define AGLOD_LEAF_LEVEL 0xFFFFu
/* Marks per-object LOD nodes (a simplified version of one object, between its leaf and its
 * first aggregate) in aglod_node_level; in aglod_collision_use_level: the coarsest per-object
 * LOD of every object. */
#define AGLOD_OBJECT_LOD_LEVEL 0xFFFEu
/** Level of a coarser version of an aggregate (one child: that aggregate or a finer version). */
#define AGLOD_COARSER_LEVEL 0xFFFDu
/** Flag of a bundle's level, AGLOD_BUNDLE_LEVEL_FLAG | k (k: the level of the aggregate it was
 * made for; the number of levels for the bundles of a bake's several roots): that aggregate's
 * children's drawn versions merged into one mesh (one draw call). */
#define AGLOD_BUNDLE_LEVEL_FLAG 0x10000u
#define AGLOD_NO_INDEX 0xFFFFFFFFu

/* Short name of a status, e.g. "checksum mismatch". Never NULL. */
const char* aglod_status_string(aglod_status status);
/* Detailed message of the last failing call on this thread (e.g. "scene.aglod: node 12: child
 * 40 has parent 3"); "" when none. Valid until the next failing call on this thread. */
const char* aglod_last_error(void);

/* Maps `path` read-only and validates it; *out is NULL on failure. */
aglod_status aglod_open_file(const char* path, aglod_file** out);
/* Validates `size` bytes at `data` (16-byte aligned) and uses them in place: the caller keeps
 * them alive and unchanged until aglod_close. */
aglod_status aglod_open_memory(const void* data, size_t size, aglod_file** out);
void aglod_close(aglod_file* file);

uint32_t aglod_node_count(const aglod_file* file);
uint32_t aglod_object_count(const aglod_file* file);
/* Level of a node: 0, 1, ... for aggregates, AGLOD_LEAF_LEVEL for originals,
 * AGLOD_OBJECT_LOD_LEVEL for per-object LODs, AGLOD_COARSER_LEVEL for coarser versions of an
 * aggregate, AGLOD_BUNDLE_LEVEL_FLAG | k for bundles; AGLOD_NO_INDEX when out of range. */
uint32_t aglod_node_level(const aglod_file* file, uint32_t node);
/* Geometric error of a node, world units (-1 when out of range). */
float aglod_node_error(const aglod_file* file, uint32_t node);
/* Axis-aligned box of a node, world units; 0 when out of range, 1 otherwise. */
int aglod_node_bounds(const aglod_file* file, uint32_t node, float min[3], float max[3]);
/* Mesh of a node, as views into the file (valid until aglod_close): positions are 3 floats per
 * vertex in world units (vertex_count vertices), indices 3 per triangle (index_count
 * indices) relative to this node's first vertex. Proxies for inner nodes, the original
 * meshes for leaves. 0 when out of range (outputs then empty), 1 otherwise. */
int aglod_node_mesh(const aglod_file* file, uint32_t node, const float** positions, uint32_t* vertex_count,
                    const uint32_t** indices, uint32_t* index_count);
/* Per-vertex normals of a node's mesh, a view into the file: 3 floats per vertex (unit,
 * outward), *vertex_count vertices, in the order of aglod_node_mesh's positions. Vertices on
 * creases and colour boundaries are split in the file, so positions + normals + colours can
 * be uploaded as they are. 0 when out of range (outputs then empty), 1 otherwise. */
int aglod_node_normals(const aglod_file* file, uint32_t node, const float** normals, uint32_t* vertex_count);
/* Per-vertex base colours of a node's mesh, a view into the file: 4 bytes per vertex, RGB
 * sRGB-encoded and alpha linear (upload as an sRGB8_ALPHA8-like normalised attribute and
 * linearise in the shader, or use aglod_color_to_linear), *vertex_count vertices. White
 * (255, 255, 255, 255) where the scene had no colour. 0 when out of range, 1 otherwise. */
int aglod_node_colors(const aglod_file* file, uint32_t node, const uint8_t** colors, uint32_t* vertex_count);
/* The linear RGBA in [0, 1] (glTF COLOR_0 / baseColorFactor meaning) of 4 colour bytes. */
void aglod_color_to_linear(const uint8_t rgba[4], float linear[4]);
/* Box of the original objects (union of the leaves' boxes; the roots' when no leaf has one),
 * world units. 0 when file is NULL. */
int aglod_scene_bounds(const aglod_file* file, float min[3], float max[3]);
/* Name of an original object, NUL-terminated copy into buffer (capacity bytes); returns the
 * full length of the name (excluding NUL), or 0 when out of range. */
size_t aglod_object_name(const aglod_file* file, uint32_t object, char* buffer, size_t capacity);

typedef struct aglod_camera {
    float position[3];     /* world units */
    float fov_y;           /* vertical field of view, radians */
    float viewport_height; /* pixels */
} aglod_camera;

/* The nodes to draw. Views owned by the selector, valid until its next aglod_select. */
typedef struct aglod_cut {
    const uint32_t* nodes;     uint32_t node_count;     /* all nodes drawn (the cut, minus culled nodes) */
    const uint32_t* proxies;   uint32_t proxy_count;    /* inner nodes: draw their proxy mesh */
    const uint32_t* originals; uint32_t original_count; /* objects the engine draws itself */
} aglod_cut;

/* A camera with orientation, for selection with frustum culling (aglod_select_view). */
typedef struct aglod_view_camera {
    float position[3];     /* world units */
    float fov_y;           /* vertical field of view, radians, in (0, pi) */
    float viewport_height; /* pixels */
    float forward[3];      /* view direction, world space, any non-zero length */
    float up[3];           /* world space, not parallel to forward */
    float aspect;          /* viewport width / height, > 0 */
    float near_distance;   /* near plane, world units along forward, >= 0 */
    float far_distance;    /* far plane, world units along forward; 0 or infinity = none */
} aglod_view_camera;

/* The cut's changes made by the last selection call: nodes now drawn that were not before
 * (stream their meshes in) and nodes no longer drawn. Views owned by the selector, valid
 * until its next call. Creating the selector counts as a first call (entered = the roots). */
typedef struct aglod_cut_changes {
    const uint32_t* entered; uint32_t entered_count;
    const uint32_t* left;    uint32_t left_count;
} aglod_cut_changes;

/* One selector per view; allocates at creation only. NULL on failure. */
aglod_selector* aglod_selector_create(const aglod_file* file);
void aglod_selector_destroy(aglod_selector* selector);
/* Drawing costs: a node that costs more (triangles + triangles_per_draw_call) than the
 * cheapest cover of its objects by nodes below it is never drawn; the cut stays within the
 * pixel tolerance and draws no more triangles than without this, often fewer.
 * original_triangles: triangles the engine draws per original object (aglod_object_count
 * entries), or NULL when unknown (a leaf then never counts as cheaper). Resets the
 * selection (the next call starts from the roots). Without this call the selector behaves
 * as after (NULL, 16). AGLOD_INVALID_ARGUMENT for a NULL selector or a negative or
 * non-finite triangles_per_draw_call. */
aglod_status aglod_selector_set_draw_costs(aglod_selector* selector, const uint32_t* original_triangles,
                                           float triangles_per_draw_call);
/* Screen-space-error selection, incremental from the previous call (docs/design.md §3).
 * pixel_tolerance: tau in pixels (> 0); coarsen_ratio in (0, 1]: hysteresis (1 = none). */
aglod_status aglod_select(aglod_selector* selector, const aglod_camera* camera,
                          float pixel_tolerance, float coarsen_ratio, aglod_cut* out);
/* Same selection with frustum culling: a node whose bounding sphere lies outside the view
 * frustum is neither refined nor drawn; it is not in `out` (nodes, proxies, originals), so
 * the objects it stands for are simply not drawn; aglod_culled_nodes lists such nodes.
 * May be mixed with aglod_select on the same selector. AGLOD_INVALID_ARGUMENT for a zero or
 * non-finite forward, up parallel to forward, aspect <= 0, near < 0 or far <= near. */
aglod_status aglod_select_view(aglod_selector* selector, const aglod_view_camera* camera,
                               float pixel_tolerance, float coarsen_ratio, aglod_cut* out);
/* Nodes culled by the last aglod_select_view (none after aglod_select): *count of them,
 * a view owned by the selector, valid until its next call. NULL with *count 0 for NULL. */
const uint32_t* aglod_culled_nodes(const aglod_selector* selector, uint32_t* count);
/* Fills *out with the changes of the cut made by the last call; 0 for NULL arguments. */
int aglod_selector_changes(const aglod_selector* selector, aglod_cut_changes* out);

/* ---- collision (aggrelod_runtime_collision, Embree 3) ---- */

typedef struct aglod_hit {
    float distance;           /* from the ray origin, world units */
    float normal[3];          /* unit, outward by the triangle's winding */
    uint32_t node;            /* node whose mesh was hit */
    uint32_t triangle;        /* triangle in that mesh */
    const uint32_t* objects;  /* original objects the node stands for (view into the file) */
    uint32_t object_count;
} aglod_hit;

/* Starts with the originals (AGLOD_LEAF_LEVEL) as the cut. NULL on failure (see aglod_last_error). */
aglod_collision* aglod_collision_create(const aglod_file* file);
void aglod_collision_destroy(aglod_collision* collision);
/* Collide against one level (AGLOD_LEAF_LEVEL = the originals). */
aglod_status aglod_collision_use_level(aglod_collision* collision, uint32_t level);
/* Collide against a cut finer near `point`: node error <= max_error_per_distance * distance. */
aglod_status aglod_collision_use_distance_cut(aglod_collision* collision, const float point[3],
                                              float max_error_per_distance);
/* Closest hit along origin + t * direction, t in [0, max_distance]. 1 on a hit, 0 otherwise. */
int aglod_raycast(const aglod_collision* collision, const float origin[3], const float direction[3],
                  float max_distance, aglod_hit* hit);
/* 1 when anything lies on the ray within max_distance, 0 otherwise. */
int aglod_occluded(const aglod_collision* collision, const float origin[3], const float direction[3],
                   float max_distance);

#ifdef __cplusplus
}
#endif

#endif /* AGGRELOD_RUNTIME_H */
