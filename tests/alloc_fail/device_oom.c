/* device_oom.c - device allocation failure on a GPU backend, provoked by a device memory limit
   the caller sets in the environment (PoCL: POCL_MEMORY_LIMIT=1, in GiB): a volume whose grids
   need more than the limit must give HD_ERROR_OUT_OF_DEVICE_MEMORY with a log line, from
   hd_create or from the first hd_iterate, and the context (if created) must still destroy
   cleanly (LSan / the allocator hook count the rest). */
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

const hd_test_case hd_tests_device_oom[] = {
    {"device_oom_512_cubed", test_device_oom_512},
};
const int hd_tests_device_oom_count = sizeof hd_tests_device_oom / sizeof hd_tests_device_oom[0];
