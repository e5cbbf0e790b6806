/* SPDX-License-Identifier: MIT */
/* hello_runtime: the smallest engine integration of the aggrelod runtime, in plain C.
 *
 *   hello_runtime FILE.aglod      (a file written by `aggrelod bake`)
 *
 * It opens the baked hierarchy, flies a camera from far away towards the scene, prints which
 * nodes a renderer would draw each frame (aggregate proxies far away, the original objects
 * close up) and what entered and left the cut (what an engine would stream), culls a view
 * that looks at half of the scene, reads a drawn mesh's normals and colours, then casts a ray
 * against the originals and against the coarsest level. */
#include <aggrelod_runtime.h>

#include <math.h>
#include <stdio.h>

static void print_cut(int frame, float distance, const aglod_file* file, const aglod_cut* cut,
                      const aglod_cut_changes* changes) {
    /* A renderer would draw the proxy mesh of each proxy node and its own meshes of the
     * original objects listed in cut->originals. Here we only count them per level
     * (per-object LODs, simplified single objects, coarser versions of aggregates and bundles
     * have no aggregate level of their own). */
    int coarsest = -1;
    for (uint32_t i = 0; i < cut->proxy_count; ++i) {
        const uint32_t level = aglod_node_level(file, cut->proxies[i]);
        if (level != AGLOD_OBJECT_LOD_LEVEL && level != AGLOD_COARSER_LEVEL && !(level & AGLOD_BUNDLE_LEVEL_FLAG) &&
            (int)level > coarsest)
            coarsest = (int)level;
    }
    printf("frame %2d  distance %9.1f  cut %5u nodes: %5u proxies (coarsest level %2d), %5u originals;"
           "  %u entered, %u left\n",
           frame, distance, cut->node_count, cut->proxy_count, coarsest, cut->original_count,
           changes->entered_count, changes->left_count);
}

static void print_hit(const char* what, const aglod_file* file, int hit, const aglod_hit* h) {
    char name[64];
    if (!hit) {
        printf("ray against %-14s: no hit\n", what);
        return;
    }
    aglod_object_name(file, h->objects[0], name, sizeof name);
    printf("ray against %-14s: hit at %.2f on node %u (level %u), normal (%.2f %.2f %.2f), "
           "stands for %u object(s), first \"%s\"\n",
           what, h->distance, h->node, aglod_node_level(file, h->node), h->normal[0], h->normal[1],
           h->normal[2], h->object_count, name);
}

int main(int argc, char** argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: hello_runtime FILE.aglod\n");
        return 2;
    }

    /* 1. Open: the file is memory-mapped and fully validated; a bad file gives a status and a
     *    message, never a crash. */
    aglod_file* file = NULL;
    aglod_status status = aglod_open_file(argv[1], &file);
    if (status != AGLOD_OK) {
        fprintf(stderr, "hello_runtime: %s (%s)\n", aglod_last_error(), aglod_status_string(status));
        return 1;
    }
    printf("%s: %u nodes over %u original objects\n", argv[1], aglod_node_count(file),
           aglod_object_count(file));

    float lo[3], hi[3], center[3], size = 0.0f;
    aglod_scene_bounds(file, lo, hi);
    for (int k = 0; k < 3; ++k) {
        center[k] = 0.5f * (lo[k] + hi[k]);
        if (hi[k] - lo[k] > size) size = hi[k] - lo[k];
    }

    /* 2. Select: one selector per view. Each call starts from the previous frame's cut and
     *    allocates nothing. tau = 1 pixel; coarsen_ratio 0.75 keeps the cut stable when the
     *    camera hovers near a threshold. */
    aglod_selector* selector = aglod_selector_create(file);
    aglod_camera camera = {{0, 0, 0}, 1.0f /* ~57 degrees */, 1080.0f};
    aglod_cut cut;
    aglod_cut_changes changes;
    for (int frame = 0; frame < 12; ++frame) {
        const float distance = 1000.0f * size * powf(0.5f, (float)frame); /* fly in */
        camera.position[0] = center[0] - distance * 0.6f;
        camera.position[1] = center[1] + distance * 0.5f;
        camera.position[2] = center[2] - distance * 0.6f;
        status = aglod_select(selector, &camera, 1.0f, 0.75f, &cut);
        if (status != AGLOD_OK) {
            fprintf(stderr, "hello_runtime: %s\n", aglod_last_error());
            break;
        }
        aglod_selector_changes(selector, &changes); /* stream in changes.entered, release changes.left */
        print_cut(frame, distance, file, &cut, &changes);
    }

    /* 2b. Frustum culling: looking from the last position at the scene's centre, 16:9. Nodes
     *     outside the view are neither refined nor drawn. The first drawn mesh's normals and
     *     colours come with its positions (one of each per vertex). */
    aglod_view_camera view = {{camera.position[0], camera.position[1], camera.position[2]}, 1.0f, 1080.0f,
                              {center[0] - camera.position[0], center[1] - camera.position[1],
                               center[2] - camera.position[2]},
                              {0, 1, 0}, 16.0f / 9.0f, 0.0f, 0.0f};
    aglod_cut view_cut;
    if (aglod_select_view(selector, &view, 1.0f, 0.75f, &view_cut) == AGLOD_OK) {
        uint32_t culled = 0;
        aglod_culled_nodes(selector, &culled);
        aglod_selector_changes(selector, &changes);
        printf("view towards the centre: %u nodes drawn, %u culled; %u entered, %u left\n", view_cut.node_count,
               culled, changes.entered_count, changes.left_count);
        if (view_cut.node_count > 0) {
            const float* normals = NULL;
            const uint8_t* colors = NULL;
            uint32_t vertices = 0;
            aglod_node_normals(file, view_cut.nodes[0], &normals, &vertices);
            aglod_node_colors(file, view_cut.nodes[0], &colors, &vertices);
            if (vertices > 0) {
                float linear[4];
                aglod_color_to_linear(colors, linear);
                printf("node %u: %u vertices, first normal (%.2f %.2f %.2f), colour (%.2f %.2f %.2f %.2f) linear\n",
                       view_cut.nodes[0], vertices, normals[0], normals[1], normals[2], linear[0], linear[1],
                       linear[2], linear[3]);
            }
        }
    } else {
        fprintf(stderr, "hello_runtime: %s\n", aglod_last_error());
    }

    /* 3. Collide: a ray from the last camera position towards the first node drawn, first against
     *    the original objects, then against the coarsest aggregate level (cheaper, and it
     *    tells which originals the hit proxy stands for). */
    aglod_collision* collision = aglod_collision_create(file);
    if (collision) {
        float nlo[3], nhi[3];
        aglod_node_bounds(file, cut.nodes[0], nlo, nhi);
        const float dir[3] = {0.5f * (nlo[0] + nhi[0]) - camera.position[0],
                              0.5f * (nlo[1] + nhi[1]) - camera.position[1],
                              0.5f * (nlo[2] + nhi[2]) - camera.position[2]};
        aglod_hit hit;
        int got = aglod_raycast(collision, camera.position, dir, 1e30f, &hit);
        print_hit("the originals", file, got, &hit);
        uint32_t coarsest = 0;
        for (uint32_t n = 0; n < aglod_node_count(file); ++n) {
            const uint32_t level = aglod_node_level(file, n);
            if (level != AGLOD_LEAF_LEVEL && level != AGLOD_OBJECT_LOD_LEVEL && level != AGLOD_COARSER_LEVEL &&
                !(level & AGLOD_BUNDLE_LEVEL_FLAG) && level > coarsest)
                coarsest = level;
        }
        if (aglod_collision_use_level(collision, coarsest) == AGLOD_OK) {
            got = aglod_raycast(collision, camera.position, dir, 1e30f, &hit);
            char what[32];
            snprintf(what, sizeof what, "level %u", coarsest);
            print_hit(what, file, got, &hit);
        }
        aglod_collision_destroy(collision);
    } else {
        fprintf(stderr, "hello_runtime: no collision: %s\n", aglod_last_error());
    }

    aglod_selector_destroy(selector);
    aglod_close(file);
    return 0;
}
