/* SPDX-License-Identifier: MIT */
/* Package consumer, C API (runtime only): opens FILE.aglod and selects from far and near.
 *   select_c FILE.aglod   (the file written by write_and_select)
 * Exit status 0 only when the cuts are the expected ones. */
#include <aggrelod_runtime.h>

#include <stdio.h>

int main(int argc, char** argv) {
    aglod_file* file = NULL;
    aglod_selector* selector = NULL;
    aglod_cut cut;
    int ok = 1;
    if (argc != 2) {
        fprintf(stderr, "usage: select_c FILE.aglod\n");
        return 2;
    }
    if (aglod_open_file(argv[1], &file) != AGLOD_OK) {
        fprintf(stderr, "select_c: %s\n", aglod_last_error());
        return 1;
    }
    selector = aglod_selector_create(file);
    if (selector == NULL) {
        fprintf(stderr, "select_c: %s\n", aglod_last_error());
        aglod_close(file);
        return 1;
    }
    {
        aglod_camera far_camera = {{2.0f, 0.5f, 1e5f}, 1.0f, 1080.0f};
        aglod_camera near_camera = {{2.0f, 0.5f, 5.0f}, 1.0f, 1080.0f};
        ok &= aglod_select(selector, &far_camera, 1.0f, 0.75f, &cut) == AGLOD_OK;
        printf("far : %u proxies, %u originals\n", cut.proxy_count, cut.original_count);
        ok &= cut.proxy_count == 1 && cut.original_count == 0;
        ok &= aglod_select(selector, &near_camera, 1.0f, 0.75f, &cut) == AGLOD_OK;
        printf("near: %u proxies, %u originals\n", cut.proxy_count, cut.original_count);
        ok &= cut.proxy_count == 0 && cut.original_count == 2;
    }
    /* A file that is not a runtime file is refused with a status, not a crash. */
    {
        aglod_file* bad = NULL;
        const aglod_status status = aglod_open_file(argv[0], &bad);
        printf("opening the executable itself: %s\n", aglod_status_string(status));
        ok &= status != AGLOD_OK && bad == NULL;
    }
    aglod_selector_destroy(selector);
    aglod_close(file);
    printf("select_c: %s\n", ok ? "PASSED" : "FAILED");
    return ok ? 0 : 1;
}
