/* user.c - a translation unit of the program that does NOT define HYBRIDDIFF_IMPLEMENTATION:
   it sees the declarations only, and links against impl.c (or, in static.c, is the same unit as
   the implementation). Creates a tiny context, iterates once, reads the image back.
   Valid C99 and C++17: no designated initialisers, no compound literals. */
#include "hybriddiff.h"
#include <stdio.h>
#include <string.h>

#define N 8

int main(void)
{
    static uint8_t voxels[N * N * N];
    static uint8_t pixels[16 * 16 * 4];
    hd_desc desc;
    hd_context ctx;
    hd_stats stats;
    hd_result r;
    int i, lit = 0;
    for (i = 0; i < N * N * N; ++i) voxels[i] = (uint8_t)(i % 7 == 0 ? 255 : 64);
    memset(&desc, 0, sizeof desc);
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = N;
    desc.volume.data = voxels;
    desc.camera.width = desc.camera.height = 16;
    desc.threads = 1;
    desc.logger.func = hd_log_stderr;
    if ((r = hd_create(&desc, &ctx)) != HD_SUCCESS) {
        fprintf(stderr, "user: hd_create on %s: %s\n", hd_backend_name(), hd_result_string(r));
        return 1;
    }
    if ((r = hd_iterate(ctx, 1)) != HD_SUCCESS ||
        (r = hd_read_image_rgba8(ctx, pixels, sizeof pixels)) != HD_SUCCESS ||
        (r = hd_get_stats(ctx, &stats)) != HD_SUCCESS) {
        fprintf(stderr, "user: %s\n", hd_result_string(r));
        hd_destroy(ctx);
        return 1;
    }
    for (i = 0; i < 16 * 16; ++i) lit += pixels[i * 4 + 3] != 0;
    hd_destroy(ctx);
    if (stats.iterations != 1 || lit == 0) {
        fprintf(stderr, "user: %u iterations, %d covered pixels\n", (unsigned)stats.iterations, lit);
        return 1;
    }
    printf("user: %s backend, 1 iteration, %d of 256 pixels covered\n", hd_backend_name(), lit);
    return 0;
}
