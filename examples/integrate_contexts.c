/* integrate_contexts.c - two contexts at once (different volumes and methods, interleaved), then
   200 create/destroy cycles: every handle works while alive and is refused after hd_destroy
   (HD_ERROR_INVALID_HANDLE). Exits 1 on any failure. Built in C99 and C++17, with hybriddiff.h
   before (default) or after (-DINTEGRATE_HD_LAST) the system headers (mk/integrate.mk). */
#ifndef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#ifdef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#endif

#define CHECK(call) do { hd_result r_ = (call); if (r_ != HD_SUCCESS) { \
    fprintf(stderr, "%s:%d: %s: %s\n", __FILE__, __LINE__, #call, hd_result_string(r_)); return 1; } } while (0)

int main(void)
{
    enum { N = 16, W = 32 };
    static float a[N * N * N];
    static unsigned char b[N * N * N];
    static unsigned char px[W * W * 4];
    hd_desc desc = HD_DESC_INIT;
    hd_params params = HD_PARAMS_INIT;
    hd_light light = HD_LIGHT_INIT;
    hd_context c1, c2, old;
    hd_stats st;
    int i;

    for (i = 0; i < N * N * N; ++i) {
        a[i] = 0.5f + 0.5f * sinf(0.7f * (float)i); /* float voxels in [0, 1] */
        b[i] = (unsigned char)(i % 7 == 0 ? 255 : 40);
    }
    desc.volume.type = HD_VOXEL_F32;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = N;
    desc.volume.data = a;
    desc.camera.width = desc.camera.height = W;
    desc.threads = 1;
    desc.logger.func = hd_log_stderr;
    CHECK(hd_create(&desc, &c1));
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.data = b;
    light.type = HD_LIGHT_POINT;
    light.position[0] = 1.0f;
    light.inverse_square = 1;
    desc.lights = &light;
    desc.light_count = 1;
    desc.params.method = HD_METHOD_PT_SS;
    CHECK(hd_create(&desc, &c2));
    for (i = 0; i < 3; ++i) { /* interleaved */
        CHECK(hd_render(c1));
        CHECK(hd_render(c2));
    }
    CHECK(hd_query_desc(c1, &desc));
    params = desc.params;
    params.albedo = 0.5f;
    CHECK(hd_set_params(c1, &params));
    CHECK(hd_render(c1));
    CHECK(hd_get_stats(c2, &st));
    if (st.method != HD_METHOD_PT_SS || st.iterations != 3) { fprintf(stderr, "c2 stats wrong\n"); return 1; }
    CHECK(hd_read_image_rgba8(c2, px, sizeof px));
    CHECK(hd_destroy(c1));
    CHECK(hd_destroy(c2));

    memset(&desc, 0, sizeof desc);
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = 4;
    desc.volume.data = b;
    desc.camera.width = desc.camera.height = 8;
    desc.threads = 1;
    old = c1;
    for (i = 0; i < 200; ++i) {
        hd_context c;
        CHECK(hd_create(&desc, &c));
        CHECK(hd_iterate(c, 1));
        CHECK(hd_destroy(c));
        if (hd_iterate(c, 1) != HD_ERROR_INVALID_HANDLE) { fprintf(stderr, "stale handle accepted\n"); return 1; }
    }
    if (hd_destroy(old) != HD_ERROR_INVALID_HANDLE) { fprintf(stderr, "stale handle accepted\n"); return 1; }
    printf("integrate_contexts: 2 contexts interleaved, 200 create/destroy cycles\n");
    return 0;
}
