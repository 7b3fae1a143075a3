/* test_living.c - volumes and settings that change while rendering, on the CPU backend: a read
   of the image before any frame exists says so (HD_ERROR_NO_FRAME). */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

/* A 24^3 blob with a dense core, one light, a 32x32 image. */
#define N 24
#define W 32
static float vox[N * N * N];
static const float tf3[12] = {0, 0, 0, 0, 1.0f, 0.6f, 0.4f, 0.3f, 1, 1, 1, 1};

static float blob(int x, int y, int z, float cx)
{
    float dx = x - cx, dy = y - 11.5f, dz = z - 11.5f;
    float r = sqrtf(dx * dx + dy * dy + dz * dz);
    return r < 9 ? (r < 4 ? 1.0f : 0.5f) : 0.0f;
}

static void make_desc(hd_desc *d, hd_test_log *log)
{
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) vox[(z * N + y) * N + x] = blob(x, y, z, 11.5f);
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_F32;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = N;
    d->volume.data = vox;
    d->transfer_function.rgba = tf3;
    d->transfer_function.count = 3;
    d->camera.width = d->camera.height = W;
    d->params.extinction = 40.0f;
    if (log) d->logger = hd_test_logger(log);
}

/* No frame yet: after hd_create, after a change of the camera's size and after a change that
   restarts the image, each read says HD_ERROR_NO_FRAME with one log line and leaves dst as it
   was; a render makes the reads succeed again. */
static void test_no_frame(void)
{
    hd_desc d;
    hd_test_log log;
    hd_context ctx;
    hd_camera cam;
    float *f = (float *)malloc((size_t)64 * 48 * 4 * sizeof(float));
    uint8_t *b = (uint8_t *)malloc((size_t)64 * 48 * 4);
    make_desc(&d, &log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    f[0] = 7.0f;
    b[0] = 7;
    CHECK(hd_read_image_f32(ctx, f, (size_t)W * W * 4) == HD_ERROR_NO_FRAME && log.errors == 1 && strstr(log.last, "no frame"));
    CHECK(hd_read_image_rgba8(ctx, b, (size_t)W * W * 4) == HD_ERROR_NO_FRAME && log.errors == 2);
    CHECK(f[0] == 7.0f && b[0] == 7);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, f, (size_t)W * W * 4) == HD_SUCCESS && log.errors == 2);
    CHECK(hd_read_image_rgba8(ctx, b, (size_t)W * W * 4) == HD_SUCCESS);
    /* a new size: nothing to read until a frame at it is made */
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    cam = d.camera;
    cam.width = 64;
    cam.height = 48;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    f[0] = 7.0f;
    CHECK(hd_read_image_f32(ctx, f, (size_t)64 * 48 * 4) == HD_ERROR_NO_FRAME && log.errors == 3 && strstr(log.last, "64x48"));
    CHECK(hd_read_image_rgba8(ctx, b, (size_t)64 * 48 * 4) == HD_ERROR_NO_FRAME && log.errors == 4);
    CHECK(f[0] == 7.0f);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, f, (size_t)64 * 48 * 4) == HD_SUCCESS && log.errors == 4);
    /* a light iteration without a frame (hd_refine) keeps the frames the image holds */
    CHECK(hd_refine(ctx, 3) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, f, (size_t)64 * 48 * 4) == HD_SUCCESS && log.errors == 4);
    /* a camera move restarts the image: the cleared image is not a frame either */
    cam.eye[0] += 0.5f;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    CHECK(hd_read_image_rgba8(ctx, b, (size_t)64 * 48 * 4) == HD_ERROR_NO_FRAME && log.errors == 5);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_read_image_rgba8(ctx, b, (size_t)64 * 48 * 4) == HD_SUCCESS && log.errors == 5);
    /* the path tracers too */
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    d.params.method = HD_METHOD_PT_SS;
    CHECK(hd_set_params(ctx, &d.params) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, f, (size_t)64 * 48 * 4) == HD_ERROR_NO_FRAME && log.errors == 6);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, f, (size_t)64 * 48 * 4) == HD_SUCCESS && log.errors == 6);
    hd_destroy(ctx);
    free(f);
    free(b);
}

const hd_test_case hd_tests_living[] = {
    {"living_no_frame", test_no_frame},
};
const int hd_tests_living_count = sizeof hd_tests_living / sizeof hd_tests_living[0];
