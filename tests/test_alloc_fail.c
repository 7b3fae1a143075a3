/* test_alloc_fail.c - allocation failure, on the CPU backend in build/hdtest and on OpenCL in
   build/afgpu/alloc-fail-opencl (mk/alloc_fail_gpu.mk). A counting allocator hook fails the
   k-th allocation, for every k in a full cycle: create, iterate HD (at render scale 1, then 2),
   switch to CD and iterate, switch to PT_SS and iterate, read the image and illumination,
   destroy. Each run must return HD_ERROR_OUT_OF_MEMORY (with a log line) or succeed, never
   crash, and free every byte it took (live allocations are counted here; under `make asan` LSan
   checks the rest). */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

typedef struct af_log { int errors; hd_result last; } af_log;
static void af_log_fn(void *user, hd_log_level level, hd_result code, const char *msg,
                      const char *file, int line)
{
    af_log *l = (af_log *)user;
    (void)msg; (void)file; (void)line;
    if (level == HD_LOG_ERROR) { ++l->errors; l->last = code; }
}

#define AF_N 12
static uint8_t af_vol[AF_N * AF_N * AF_N];

/* One cycle; returns the first error (HD_SUCCESS if all went through). The context is always
   destroyed if it was created. */
static hd_result af_cycle(hd_test_alloc *st, af_log *log)
{
    hd_desc d;
    hd_context ctx;
    hd_params p;
    hd_result r;
    float img[16 * 16 * 4], ill[AF_N * AF_N * AF_N];
    int i;
    for (i = 0; i < AF_N * AF_N * AF_N; ++i) af_vol[i] = (uint8_t)((i * 37) & 255);
    memset(&d, 0, sizeof d);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = AF_N;
    d.volume.data = af_vol;
    d.camera.width = d.camera.height = 16;
    d.threads = 2;
    d.allocator.alloc = hd_test_alloc_fn;
    d.allocator.free = hd_test_free_fn;
    d.allocator.user_data = st;
    d.logger.func = af_log_fn;
    d.logger.user_data = log;
    r = hd_create(&d, &ctx);
    if (r != HD_SUCCESS) return r;
    r = hd_iterate(ctx, 2);
    if (r == HD_SUCCESS) r = hd_query_desc(ctx, &d);
    if (r == HD_SUCCESS) {
        p = d.params;
        p.render_scale = 2; /* the image buffer's reduced frames' region comes with this frame */
        r = hd_set_params(ctx, &p);
        if (r == HD_SUCCESS) r = hd_iterate(ctx, 1);
        p.render_scale = 1;
        p.method = HD_METHOD_CD;
        r = hd_set_params(ctx, &p);
        if (r == HD_SUCCESS) r = hd_iterate(ctx, 1);
        p.method = HD_METHOD_PT_SS;
        if (r == HD_SUCCESS) r = hd_set_params(ctx, &p);
        if (r == HD_SUCCESS) r = hd_iterate(ctx, 1);
        p.method = HD_METHOD_HD;
        p.solver = HD_SOLVER_JACOBI;
        if (r == HD_SUCCESS) r = hd_set_params(ctx, &p);
        if (r == HD_SUCCESS) r = hd_iterate(ctx, 1);
        /* multigrid where the backend has it (the others refuse it, which would log an error) */
        if (strcmp(hd_backend_name(), "cpu") == 0 || strcmp(hd_backend_name(), "opencl") == 0) {
            p.solver = HD_SOLVER_MULTIGRID;           /* its levels come with the first V-cycle */
            p.diffusion_sweeps = 1;
            if (r == HD_SUCCESS) r = hd_set_params(ctx, &p);
            if (r == HD_SUCCESS) r = hd_iterate(ctx, 1);
        }
    }
    if (r == HD_SUCCESS) r = hd_read_image_f32(ctx, img, sizeof img / sizeof img[0]);
    if (r == HD_SUCCESS)
        r = hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, ill, sizeof ill / sizeof ill[0]);
    if (hd_destroy(ctx) != HD_SUCCESS) CHECK_MSG(0, "destroy failed after %s", hd_result_string(r));
    return r;
}

static void test_alloc_fail_every_k(void)
{
    hd_test_alloc st;
    af_log log;
    long total, k, failures = 0;
    memset(&st, 0, sizeof st);
    memset(&log, 0, sizeof log);
    CHECK(af_cycle(&st, &log) == HD_SUCCESS);
    CHECK(st.live == 0 && log.errors == 0);
    total = st.calls;
    CHECK(total >= 5); /* else the hook is not used and the test proves nothing */
    for (k = 1; k <= total; ++k) {
        hd_result r;
        memset(&st, 0, sizeof st);
        memset(&log, 0, sizeof log);
        st.fail_at = k;
        r = af_cycle(&st, &log);
        CHECK_MSG(st.failed == 1, "k=%ld: the allocation was not reached", k);
        CHECK_MSG(r == HD_ERROR_OUT_OF_MEMORY || r == HD_SUCCESS, "k=%ld: %s", k,
                  hd_result_string(r));
        if (r != HD_SUCCESS) {
            ++failures;
            CHECK_MSG(log.errors >= 1 && log.last == r, "k=%ld: no log line for %s", k,
                      hd_result_string(r));
        }
        CHECK_MSG(st.live == 0, "k=%ld: %ld allocations leaked (%s)", k, st.live,
                  hd_result_string(r));
    }
    CHECK(failures >= 1);
    printf("  %s: %ld allocations per cycle, each failed once: %ld runs returned "
           "HD_ERROR_OUT_OF_MEMORY, none leaked\n", hd_backend_name(), total, failures);
}

const hd_test_case hd_tests_alloc_fail[] = {
    {"alloc_fail_every_k", test_alloc_fail_every_k},
};
const int hd_tests_alloc_fail_count = sizeof hd_tests_alloc_fail / sizeof hd_tests_alloc_fail[0];
