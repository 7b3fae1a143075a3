/* device_oom.c - device allocation failure on a GPU backend, provoked by a device memory limit
   the caller sets in the environment (PoCL: POCL_MEMORY_LIMIT=1, in GiB): a volume whose grids
   need more than the limit must give HD_ERROR_OUT_OF_DEVICE_MEMORY with a log line, from
   hd_create or from the first hd_iterate, and the context (if created) must still destroy
   cleanly (LSan / the allocator hook count the rest); an image whose reduced frames' region
   does not fit fails its first reduced frame the same way and renders full frames on. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

typedef struct oom_log { int errors; hd_result last; } oom_log;
static void oom_log_fn(void *user, hd_log_level level, hd_result code, const char *msg,
                       const char *file, int line)
{
    oom_log *l = (oom_log *)user;
    (void)file; (void)line;
    if (level == HD_LOG_ERROR) { ++l->errors; l->last = code; fprintf(stderr, "  log: %s\n", msg); }
}

/* n^3 f32 under a 1 GiB device limit: 512^3 (512 MiB) is above the device's largest single
   allocation (a quarter of its memory). Measured: PoCL 3.1 does not enforce the limit on the sum
   of buffers (400^3, 4 grids of 244 MiB = 977 MiB + image, created and iterated fine), so the
   single-allocation limit is the failure this test can provoke here. */
static void device_oom(int n)
{
    size_t nv = (size_t)n * n * n, i;
    float *vol = (float *)malloc(nv * sizeof(float));
    hd_desc d;
    hd_context ctx;
    hd_result r;
    oom_log log;
    CHECK(vol != NULL);
    if (!vol) return;
    for (i = 0; i < nv; ++i) vol[i] = (float)(i % 97) / 96.0f;
    memset(&d, 0, sizeof d);
    memset(&log, 0, sizeof log);
    d.volume.type = HD_VOXEL_F32;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = n;
    d.volume.data = vol;
    d.camera.width = d.camera.height = 8;
    d.logger.func = oom_log_fn;
    d.logger.user_data = &log;
    r = hd_create(&d, &ctx);
    if (r == HD_SUCCESS) {
        r = hd_iterate(ctx, 1);
        CHECK(hd_destroy(ctx) == HD_SUCCESS);
    }
    printf("  %s: %d^3 f32 under the device memory limit: %s\n", hd_backend_name(), n, hd_result_string(r));
    CHECK_MSG(r == HD_ERROR_OUT_OF_DEVICE_MEMORY, "got %s", hd_result_string(r));
    CHECK_MSG(log.errors >= 1 && log.last == r, "%d errors logged, the last %s", log.errors, hd_result_string(log.last));
    free(vol);
}

static void test_device_oom_512(void) { device_oom(512); }

/* The reduced frames' region of the image buffer is made by the first frame at a render scale
   > 1 (hd_k_upsample.h). A 3600x3400 image (245 MB: RGBA floats and the depth plane) fits the
   device's largest allocation under the 1 GiB limit (256 MiB), the image with that region
   (294 MB) does not: the
   scale-2 frame fails with HD_ERROR_OUT_OF_DEVICE_MEMORY and one log line, the image buffer held
   before stays, and full frames render on. */
static void test_device_oom_image_room(void)
{
    static unsigned char vol[8 * 8 * 8];
    hd_desc d;
    hd_context ctx;
    hd_params p;
    hd_stats s;
    hd_result r;
    oom_log log;
    size_t full = (size_t)3600 * 3400 * 20;
    memset(vol, 200, sizeof vol);
    memset(&d, 0, sizeof d);
    memset(&log, 0, sizeof log);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = 8;
    d.volume.data = vol;
    d.camera.width = 3600;
    d.camera.height = 3400;
    d.camera.eye[1] = 8.0f; /* far: the volume covers few pixels, the frame is cheap */
    d.camera.up[2] = 1.0f;
    d.params.illumination_downsample = 1;
    d.logger.func = oom_log_fn;
    d.logger.user_data = &log;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS && log.errors == 0);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == full);
    p = d.params;
    p.render_scale = 2;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    r = hd_iterate(ctx, 1);
    printf("  %s: a 3600x3400 image's scale-2 frame under the device memory limit: %s\n", hd_backend_name(), hd_result_string(r));
    CHECK_MSG(r == HD_ERROR_OUT_OF_DEVICE_MEMORY && log.errors == 1 && log.last == r, "got %s, %d errors logged", hd_result_string(r),
              log.errors);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == full);
    p.render_scale = 1;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS && hd_iterate(ctx, 1) == HD_SUCCESS && log.errors == 1);
    CHECK(hd_destroy(ctx) == HD_SUCCESS);
}

const hd_test_case hd_tests_device_oom[] = {
    {"device_oom_512_cubed", test_device_oom_512},
    {"device_oom_image_room", test_device_oom_image_room},
};
const int hd_tests_device_oom_count = sizeof hd_tests_device_oom / sizeof hd_tests_device_oom[0];
