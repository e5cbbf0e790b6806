/* SPDX-License-Identifier: MIT */
/* Package consumer, C API with the collision part (Embree 3): rays against the originals and
 * against the root's proxy of the two-box file written by write_and_select.
 *   raycast_c FILE.aglod
 * Exit status 0 only when every ray hits where it must. */
#include <aggrelod_runtime.h>

#include <math.h>
#include <stdio.h>

static int expect_hit(const aglod_collision* world, const float origin[3], const float direction[3],
                      float distance, uint32_t node, const char* what) {
    aglod_hit hit;
    const int got = aglod_raycast(world, origin, direction, 1e30f, &hit);
    const int ok = got && fabsf(hit.distance - distance) < 1e-4f && hit.node == node;
    if (got)
        printf("%s: %s, hit node %u at %.4f\n", ok ? "ok  " : "FAIL", what, hit.node, hit.distance);
    else
        printf("FAIL: %s, no hit\n", what);
    return ok;
}

int main(int argc, char** argv) {
    aglod_file* file = NULL;
    aglod_collision* world = NULL;
    int ok = 1;
    /* Down the gap between the boxes (x = 2): misses both originals, hits the proxy's top. */
    const float gap[3] = {2.0f, 10.0f, 0.5f};
    const float onto_left[3] = {0.5f, 10.0f, 0.5f};
    const float down[3] = {0.0f, -1.0f, 0.0f};
    aglod_hit hit;
    if (argc != 2) {
        fprintf(stderr, "usage: raycast_c FILE.aglod\n");
        return 2;
    }
    if (aglod_open_file(argv[1], &file) != AGLOD_OK) {
        fprintf(stderr, "raycast_c: %s\n", aglod_last_error());
        return 1;
    }
    world = aglod_collision_create(file);
    if (world == NULL) {
        fprintf(stderr, "raycast_c: %s\n", aglod_last_error());
        aglod_close(file);
        return 1;
    }
    ok &= expect_hit(world, onto_left, down, 9.0f, 0, "originals: ray onto the left box");
    {
        const int missed = !aglod_raycast(world, gap, down, 1e30f, &hit);
        printf("%s: originals: ray down the gap misses\n", missed ? "ok  " : "FAIL");
        ok &= missed;
    }
    ok &= aglod_collision_use_level(world, 0) == AGLOD_OK;
    ok &= expect_hit(world, gap, down, 9.0f, 2, "level 0: ray down the gap hits the proxy");
    aglod_collision_destroy(world);
    aglod_close(file);
    printf("raycast_c: %s\n", ok ? "PASSED" : "FAILED");
    return ok ? 0 : 1;
}
