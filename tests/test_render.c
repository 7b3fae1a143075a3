/* test_render.c - the per-frame API on the CPU backend: hd_refine refines the light without
   projecting, the convergence estimate falls as the light converges, hd_render stops all light
   work once it has, a camera move costs one projection, setters restart the light, bad input. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

/* A 20^3 blob with a dense core, one light, a 32x32 image. */
#define N 20
#define W 32
static uint8_t vox[N * N * N];
static const float tf3[12] = {0, 0, 0, 0, 1.0f, 0.6f, 0.4f, 0.3f, 1, 1, 1, 1};

static void make_desc(hd_desc *d, hd_test_log *log)
{
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                float dx = x - 9.5f, dy = y - 9.5f, dz = z - 9.5f;
                float r = sqrtf(dx * dx + dy * dy + dz * dz);
                vox[(z * N + y) * N + x] = (uint8_t)(r < 8 ? (r < 4 ? 255 : 128) : 0);
            }
    memset(d, 0, sizeof *d);
    /* the paper's grid and boundary (hd_params_preset): these cases are not about the defaults */
    d->params.illumination_downsample = 1;
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = N;
    d->volume.data = vox;
    d->transfer_function.rgba = tf3;
    d->transfer_function.count = 3;
    d->camera.width = d->camera.height = W;
    d->params.extinction = 40.0f;
    if (log) d->logger = hd_test_logger(log);
}

static void read_light(hd_context ctx, float *e, float *p)
{
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, (size_t)N * N * N) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, p, (size_t)N * N * N) == HD_SUCCESS);
}

/* The light of hd_refine(n) is bit for bit that of hd_iterate(n), and it projects nothing. */
static void test_refine_is_iterate_without_frames(void)
{
    size_t n = (size_t)N * N * N;
    float *e0 = (float *)malloc(n * 4), *p0 = (float *)malloc(n * 4), *e1 = (float *)malloc(n * 4), *p1 = (float *)malloc(n * 4);
    hd_desc d;
    hd_context a, b;
    hd_stats s;
    make_desc(&d, NULL);
    CHECK(hd_create(&d, &a) == HD_SUCCESS);
    CHECK(hd_create(&d, &b) == HD_SUCCESS);
    CHECK(hd_iterate(a, 6) == HD_SUCCESS);
    CHECK(hd_refine(b, 6) == HD_SUCCESS);
    read_light(a, e0, p0);
    read_light(b, e1, p1);
    CHECK(memcmp(e0, e1, n * 4) == 0 && memcmp(p0, p1, n * 4) == 0);
    CHECK(hd_get_stats(b, &s) == HD_SUCCESS && s.iterations == 6 && s.frames == 0 && s.seconds_projection == 0.0);
    CHECK(s.seconds_direct > 0.0 && s.seconds_diffusion > 0.0);
    hd_destroy(a);
    hd_destroy(b);
    free(e0); free(p0); free(e1); free(p1);
}

/* The estimate starts at 1 and falls as the light converges, for HD and for CD. */
static void test_light_error_falls(void)
{
    hd_method methods[2] = {HD_METHOD_HD, HD_METHOD_CD};
    int m;
    for (m = 0; m < 2; ++m) {
        hd_desc d;
        hd_context ctx;
        hd_stats s;
        double e4, e64;
        make_desc(&d, NULL);
        d.params.method = methods[m];
        CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.light_error == 1.0 && !s.light_converged);
        CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.light_error == 1.0);
        CHECK(hd_refine(ctx, 3) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
        e4 = s.light_error;
        CHECK(hd_refine(ctx, 60) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
        e64 = s.light_error;
        CHECK_MSG(e4 > 0.0 && e64 < 0.5 * e4, "%s: error %g after 4, %g after 64 iterations",
                  hd_method_name(methods[m]), e4, e64);
        hd_destroy(ctx);
    }
}

/* On a grid with more medium voxels than the estimate reads (it measures a lattice of z slices
   there), the estimate stays close to the same formula over every voxel, computed here from
   hd_read_illumination. */
static void test_light_error_sampled(void)
{
    enum { X = 72, Y = 72, Z = 40, K = 10 };
    size_t n = (size_t)X * Y * Z, i;
    uint8_t *v = (uint8_t *)malloc(n);
    float *e = (float *)calloc(n, 4), *p = (float *)calloc(n, 4), *e1 = (float *)malloc(n * 4), *p1 = (float *)malloc(n * 4);
    double dp_prev = 0.0, worst = 1.0;
    hd_desc d;
    hd_context ctx;
    hd_stats s;
    int k;
    for (i = 0; i < n; ++i) v[i] = (uint8_t)(96 + (i * 2654435761u >> 27)); /* medium everywhere, uneven */
    make_desc(&d, NULL);
    d.volume.dims[0] = X; d.volume.dims[1] = Y; d.volume.dims[2] = Z;
    d.volume.data = v;
    d.params.extinction = 10.0f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    for (k = 1; k <= K; ++k) {
        double de = 0.0, dp = 0.0, ls = 0.0, q, err, ratio;
        CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e1, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, p1, n) == HD_SUCCESS);
        for (i = 0; i < n; ++i) {
            de += (double)(e1[i] - e[i]) * (e1[i] - e[i]);
            dp += (double)(p1[i] - p[i]) * (p1[i] - p[i]);
            ls += ((double)e1[i] + p1[i]) * ((double)e1[i] + p1[i]);
        }
        memcpy(e, e1, n * 4);
        memcpy(p, p1, n * 4);
        dp = sqrt(dp);
        q = dp_prev > 0.0 ? dp / dp_prev : 0.0;
        q = q > 0.9 ? 0.9 : q;
        dp_prev = dp;
        err = (sqrt((double)k * de) + dp * q / (1.0 - q)) / sqrt(ls);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
        if (k < 3) continue; /* the first estimate is 1 by definition */
        ratio = s.light_error / err;
        if (fabs(log(ratio)) > fabs(log(worst))) worst = ratio;
        CHECK_MSG(ratio > 0.75 && ratio < 1.33, "iteration %d: estimate %g, over every voxel %g", k, s.light_error, err);
    }
    printf("  sampled light_error against every voxel's: worst ratio %.3f over iterations 3..%d\n", worst, K);
    hd_destroy(ctx);
    free(v); free(e); free(p); free(e1); free(p1);
}

/* A per-frame loop: light work until the light converges, then projections only, then nothing
   once the frame window is full; a camera move costs one projection and keeps the light. */
static void test_render_loop(void)
{
    size_t n = (size_t)N * N * N;
    float *e0 = (float *)malloc(n * 4), *p0 = (float *)malloc(n * 4), *e1 = (float *)malloc(n * 4), *p1 = (float *)malloc(n * 4);
    float *img0 = (float *)malloc(W * W * 16), *img1 = (float *)malloc(W * W * 16);
    hd_desc d;
    hd_context ctx;
    hd_stats s, c;
    hd_camera cam;
    int i;
    double sum = 0.0;
    make_desc(&d, NULL);
    d.params.light_tolerance = 0.05f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    for (i = 0; i < 2000; ++i) {
        CHECK(hd_render(ctx) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
        if (s.light_converged) break;
        CHECK(s.iterations == (uint64_t)i + 1); /* one light iteration per call, budget 0 */
    }
    CHECK_MSG(s.light_converged && s.light_error < 0.05, "not converged after %d calls (error %g)", i, s.light_error);
    CHECK(s.frames == 1); /* the image restarted with the converged light */
    read_light(ctx, e0, p0);
    for (i = 0; i < 20; ++i) CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &c) == HD_SUCCESS);
    CHECK(c.iterations == s.iterations && c.seconds_direct == s.seconds_direct && c.seconds_diffusion == s.seconds_diffusion);
    CHECK(c.frames == 8 && c.light_converged); /* frame_window frames, then nothing */
    CHECK(c.seconds_projection > s.seconds_projection);
    read_light(ctx, e1, p1);
    CHECK(memcmp(e0, e1, n * 4) == 0 && memcmp(p0, p1, n * 4) == 0);
    CHECK(hd_read_image_f32(ctx, img0, W * W * 4) == HD_SUCCESS);
    /* the image is done: more calls leave it and the timers alone */
    s = c;
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &c) == HD_SUCCESS && c.seconds_projection == s.seconds_projection && c.frames == 8);

    cam = d.camera;
    cam.eye[0] = 2.0f; cam.eye[1] = 0.7f; cam.eye[2] = 1.2f;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &c) == HD_SUCCESS);
    CHECK(c.frames == 1 && c.iterations == s.iterations && c.light_converged);
    CHECK(c.seconds_direct == s.seconds_direct && c.seconds_diffusion == s.seconds_diffusion);
    CHECK(hd_read_image_f32(ctx, img1, W * W * 4) == HD_SUCCESS);
    for (i = 0; i < W * W * 4; ++i) sum += fabsf(img1[i] - img0[i]);
    CHECK(sum > 0.0); /* a new view */

    /* a setter that changes the light restarts the refinement (from the light held: warm) */
    {
        hd_light l;
        memset(&l, 0, sizeof l);
        l.direction[0] = 1.0f;
        CHECK(hd_set_lights(ctx, &l, 1) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &c) == HD_SUCCESS && !c.light_converged && c.light_error == 1.0);
        CHECK(hd_render(ctx) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &c) == HD_SUCCESS && c.iterations == s.iterations + 1 && c.frames == 1 && !c.light_converged);
        CHECK(c.seconds_direct > s.seconds_direct);
    }
    hd_destroy(ctx);
    free(e0); free(p0); free(e1); free(p1); free(img0); free(img1);
}

/* A frame projects the light as it is now: the CPU backend's summed light grid (E + phi, kept
   for the projection) follows hd_refine. Context a projects, refines on and projects again; b
   refines as far at once: the same light and frame index, so the same image bit for bit. */
static void test_render_follows_light(void)
{
    float *ia = (float *)malloc(W * W * 16), *ib = (float *)malloc(W * W * 16), *i0 = (float *)malloc(W * W * 16);
    hd_desc d;
    hd_context a, b;
    hd_stats s;
    make_desc(&d, NULL);
    d.params.light_tolerance = 1e6f; /* converged within 3 iterations: hd_render only projects */
    CHECK(hd_create(&d, &a) == HD_SUCCESS);
    CHECK(hd_create(&d, &b) == HD_SUCCESS);
    CHECK(hd_refine(a, 3) == HD_SUCCESS);
    CHECK(hd_render(a) == HD_SUCCESS);
    CHECK(hd_read_image_f32(a, i0, W * W * 4) == HD_SUCCESS);
    CHECK(hd_refine(a, 3) == HD_SUCCESS);
    CHECK(hd_set_camera(a, &d.camera) == HD_SUCCESS); /* restart the image */
    CHECK(hd_render(a) == HD_SUCCESS);
    CHECK(hd_get_stats(a, &s) == HD_SUCCESS);
    CHECK_MSG(s.iterations == 6 && s.frames == 1, "a: %llu iterations, %llu frames", (unsigned long long)s.iterations,
              (unsigned long long)s.frames);
    CHECK(hd_refine(b, 6) == HD_SUCCESS);
    CHECK(hd_render(b) == HD_SUCCESS);
    CHECK(hd_get_stats(b, &s) == HD_SUCCESS);
    CHECK_MSG(s.iterations == 6 && s.frames == 1, "b: %llu iterations, %llu frames", (unsigned long long)s.iterations,
              (unsigned long long)s.frames);
    CHECK(hd_read_image_f32(a, ia, W * W * 4) == HD_SUCCESS);
    CHECK(hd_read_image_f32(b, ib, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(ia, i0, W * W * 16) != 0); /* the test has power: the light changed the image */
    CHECK_MSG(memcmp(ia, ib, W * W * 16) == 0, "the frame after hd_refine projected the old light");
    hd_destroy(a);
    hd_destroy(b);
    free(ia); free(ib); free(i0);
}

/* render_budget: one call may run several light iterations; the path tracers add paths. */
static void test_render_budget(void)
{
    hd_desc d;
    hd_context ctx;
    hd_stats s;
    make_desc(&d, NULL);
    d.params.render_budget = 10.0f;
    d.params.light_tolerance = 0.05f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
    CHECK_MSG(s.light_converged && s.iterations > 2 && s.frames == 1, "one call with a 10 s budget: %llu iterations, converged %d",
              (unsigned long long)s.iterations, s.light_converged);
    hd_destroy(ctx);

    make_desc(&d, NULL);
    d.params.method = HD_METHOD_PT_MS;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS && hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 2 && s.frames == 2 && s.light_error == 0.0);
    hd_destroy(ctx);
}

/* Bad input: each a specific hd_result and one logged line; nothing changes. */
static void test_render_bad_input(void)
{
    hd_test_log log;
    hd_desc d;
    hd_context ctx, stale;
    hd_params p;
    hd_stats s;
    float bad[3] = {-1.0f, NAN, INFINITY};
    int i;
    for (i = 0; i < 3; ++i) {
        make_desc(&d, &log);
        d.params.light_tolerance = bad[i];
        CHECK(hd_create(&d, &ctx) == HD_ERROR_INVALID_PARAMETER && log.errors == 1 && strstr(log.last, "light_tolerance"));
        make_desc(&d, &log);
        d.params.render_budget = bad[i];
        CHECK(hd_create(&d, &ctx) == HD_ERROR_INVALID_PARAMETER && log.errors == 1 && strstr(log.last, "render_budget"));
    }
    make_desc(&d, &log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    CHECK(p.light_tolerance == 0.1f && p.render_budget == 0.0f); /* the defaults */
    p.light_tolerance = NAN;
    CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_PARAMETER && log.errors == 1);
    p.light_tolerance = 0.05f;
    p.render_budget = -1.0f;
    CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_PARAMETER && log.errors == 2);
    CHECK(hd_refine(ctx, 0) == HD_ERROR_INVALID_PARAMETER && log.errors == 3);
    CHECK(hd_refine(ctx, -5) == HD_ERROR_INVALID_PARAMETER && log.errors == 4);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 0 && s.frames == 0);
    /* before any light: a render does the first light iteration itself */
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 1 && s.frames == 1);
    p.method = HD_METHOD_PT_SS;
    p.render_budget = 0.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 1) == HD_ERROR_UNSUPPORTED && log.errors == 5 && strstr(log.last, "PT_SS"));
    stale = ctx;
    hd_destroy(ctx);
    CHECK(hd_refine(stale, 1) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_render(stale) == HD_ERROR_INVALID_HANDLE);
}

/* render_scale 2: the frame is the projection at half the size (the same rays as a context of
   that size: same field of view, pixel index and frame), upsampled bilinearly to the camera's
   size; the image read back has the full size. The test's own bilinear upsample of the half-size
   context's image must match the library's within rounding. */
static void test_render_scale_upsample(void)
{
    enum { H = W / 2 };
    float *full = (float *)malloc(W * W * 16), *half = (float *)malloc(H * H * 16), *plain = (float *)malloc(W * W * 16);
    hd_desc d, dh;
    hd_context a, b, c;
    hd_stats s;
    double worst = 0.0, diff = 0.0;
    int x, y, k, f;
    make_desc(&d, NULL);
    d.params.light_tolerance = 1e6f; /* converged within 3 iterations: hd_render only projects */
    dh = d;
    dh.camera.width = dh.camera.height = H;
    d.params.render_scale = 2;
    CHECK(hd_create(&d, &a) == HD_SUCCESS);
    CHECK(hd_create(&dh, &b) == HD_SUCCESS);
    d.params.render_scale = 0; /* the default: full frames */
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_refine(a, 3) == HD_SUCCESS && hd_refine(b, 3) == HD_SUCCESS && hd_refine(c, 3) == HD_SUCCESS);
    for (f = 0; f < 3; ++f) /* three jittered frames into each running mean */
        CHECK(hd_render(a) == HD_SUCCESS && hd_render(b) == HD_SUCCESS && hd_render(c) == HD_SUCCESS);
    CHECK(hd_get_stats(a, &s) == HD_SUCCESS && s.frames == 3 && s.render_scale == 2);
    CHECK(s.image_bytes == (size_t)(W * W + H * H) * 16 + (size_t)W * W * 4); /* the image, the half-size frame, the depth plane */
    CHECK(hd_read_image_f32(a, full, W * W * 4) == HD_SUCCESS);
    CHECK(hd_read_image_f32(b, half, H * H * 4) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, plain, W * W * 4) == HD_SUCCESS);
    CHECK(hd_get_stats(c, &s) == HD_SUCCESS && s.render_scale == 1);
    for (y = 0; y < W; ++y)
        for (x = 0; x < W; ++x) {
            float fx = (x + 0.5f) * 0.5f - 0.5f, fy = (y + 0.5f) * 0.5f - 0.5f;
            int x0, y0, x1, y1;
            fx = fx < 0.0f ? 0.0f : (fx > H - 1 ? (float)(H - 1) : fx);
            fy = fy < 0.0f ? 0.0f : (fy > H - 1 ? (float)(H - 1) : fy);
            x0 = (int)fx; y0 = (int)fy;
            x1 = x0 + 1 < H ? x0 + 1 : H - 1; y1 = y0 + 1 < H ? y0 + 1 : H - 1;
            for (k = 0; k < 4; ++k) {
                float t = half[(y0 * H + x0) * 4 + k] + (fx - x0) * (half[(y0 * H + x1) * 4 + k] - half[(y0 * H + x0) * 4 + k]);
                float u = half[(y1 * H + x0) * 4 + k] + (fx - x0) * (half[(y1 * H + x1) * 4 + k] - half[(y1 * H + x0) * 4 + k]);
                double e = fabs((double)(t + (fy - y0) * (u - t)) - full[(y * W + x) * 4 + k]);
                if (e > worst) worst = e;
                diff += fabs((double)plain[(y * W + x) * 4 + k] - full[(y * W + x) * 4 + k]);
            }
        }
    CHECK_MSG(worst < 1e-6, "the scale-2 frame differs from the half-size projection upsampled by %g", worst);
    CHECK(diff > 0.0); /* and it is not the full-resolution frame */
    hd_destroy(a);
    hd_destroy(b);
    hd_destroy(c);
    free(full); free(half); free(plain);
}

/* HD_RENDER_SCALE_AUTO: a new image starts at 1/4, then 1/2, then full frames accumulate to
   frame_window; a camera move starts coarse again; with a budget the full frame fits in, the
   first frame is already full. No light work once converged. */
static void test_render_scale_auto(void)
{
    static const int want_scale[12] = {4, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
    static const int want_frames[12] = {1, 1, 1, 2, 3, 4, 5, 6, 7, 8, 8, 8};
    hd_desc d;
    hd_context ctx;
    hd_stats s, s0;
    hd_camera cam;
    hd_params p;
    int i;
    make_desc(&d, NULL);
    d.params.light_tolerance = 1e6f;
    d.params.render_scale = HD_RENDER_SCALE_AUTO;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 3) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s0) == HD_SUCCESS && s0.light_converged);
    for (i = 0; i < 12; ++i) {
        CHECK(hd_render(ctx) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
        CHECK_MSG(s.render_scale == want_scale[i] && s.frames == (uint64_t)want_frames[i],
                  "call %d: scale %d, %llu frames; want %d, %d", i, s.render_scale, (unsigned long long)s.frames,
                  want_scale[i], want_frames[i]);
    }
    CHECK(s.seconds_direct == s0.seconds_direct && s.seconds_diffusion == s0.seconds_diffusion);
    cam = d.camera;
    cam.eye[0] = 2.0f; cam.eye[1] = 0.7f; cam.eye[2] = 1.2f;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.render_scale == 4 && s.frames == 1);
    /* a budget far above the measured frame time: full frames from the first */
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    CHECK(p.render_scale == HD_RENDER_SCALE_AUTO);
    p.render_budget = 10.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    cam.eye[0] = -2.0f; /* another view */
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK_MSG(hd_get_stats(ctx, &s) == HD_SUCCESS && s.render_scale == 1 && s.frames == 1, "with a budget: scale %d, %llu frames",
              s.render_scale, (unsigned long long)s.frames);
    /* a fixed scale: every frame at it; changing it restarts the image */
    p.render_scale = 4;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS && hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.render_scale == 4 && s.frames == 2);
    /* the path tracers ignore it (no budget: one path per call) */
    p.method = HD_METHOD_PT_MS;
    p.render_budget = 0.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.render_scale == 1 && s.frames == 1);
    hd_destroy(ctx);
}

/* HD_RENDER_SCALE_AUTO's cost model, fed frame times through the hooks in tests/hd_impl_cpu.c
   (no frame runs, so the choices are exact). The times follow t = a + b * pixels with a fixed
   part a = 20 ms (per-call overhead, the upsample pass) and b * (512 * 512) = 80 ms: full frames
   100 ms, scale 2 40 ms, scale 4 25 ms, scale 8 21.25 ms. The old rule (the last frame's time
   times the ratio of pixels) overestimates a full frame from a reduced one and underestimates a
   reduced one from a full one; the model fits both. */
hd_result hdt_frame_cost(hd_context h, int scale, double seconds);
int hdt_first_scale(hd_context h);

/* A frame's share of render_budget while the light has not converged (as in these contexts,
   which run no light): half of it, the rest is the light's. */
#define FRAME_BUDGET(share) (2.0f * (share))

/* A 512^2 context with HD_RENDER_SCALE_AUTO whose frames may take `budget` seconds. */
static hd_result make_auto_ctx(float budget, hd_context *ctx)
{
    hd_desc d;
    make_desc(&d, NULL);
    d.camera.width = d.camera.height = 512;
    d.params.render_scale = HD_RENDER_SCALE_AUTO;
    d.params.render_budget = FRAME_BUDGET(budget);
    return hd_create(&d, ctx);
}

static void test_render_scale_auto_cost(void)
{
    hd_desc d;
    hd_context ctx;
    hd_params p;
    CHECK(make_auto_ctx(0.11f, &ctx) == HD_SUCCESS);
    CHECK(hdt_first_scale(ctx) == 4); /* nothing measured yet */
    /* one scale measured: time proportional to pixels (25 ms * 16 = 400 ms, 25 * 4 = 100 ms) */
    CHECK(hdt_frame_cost(ctx, 4, 0.025) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 2, "one scale-4 frame, budget 110 ms: scale %d, want 2", hdt_first_scale(ctx));
    /* a new view's 1/4 and 1/2 frames: a full frame (100 ms) fits 110 ms (the old rule: 160 ms) */
    CHECK(hdt_frame_cost(ctx, 2, 0.040) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 1, "scale 4 and 2 measured, budget 110 ms: scale %d, want 1", hdt_first_scale(ctx));
    /* and after a full frame, a budget of 30 ms: scale 2 (40 ms) does not fit, scale 4 does (the old
       rule: 100 / 4 = 25 ms, scale 2, over budget) */
    CHECK(hdt_frame_cost(ctx, 1, 0.100) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    p.render_budget = FRAME_BUDGET(0.030f);
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 4, "scales 4, 2, 1 measured, budget 30 ms: scale %d, want 4", hdt_first_scale(ctx));
    /* 22 ms fits scale 8 (21.25 ms) first; below the fixed part nothing fits: the coarsest, 16 */
    p.render_budget = FRAME_BUDGET(0.022f);
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 8, "budget 22 ms: scale %d, want 8", hdt_first_scale(ctx));
    p.render_budget = FRAME_BUDGET(0.010f);
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS && hdt_first_scale(ctx) == 16);
    /* the per-pixel part follows the newest frame: a view twice as dear per pixel (full frames of
       180 ms, two of them: the estimate moves halfway per frame, 100 -> 140 -> 160 ms) fits a
       budget of 110 ms at scale 2 (about 50 ms predicted), no longer at 1 */
    CHECK(hdt_frame_cost(ctx, 1, 0.180) == HD_SUCCESS && hdt_frame_cost(ctx, 1, 0.180) == HD_SUCCESS);
    p.render_budget = FRAME_BUDGET(0.11f);
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 2, "a dearer view, budget 110 ms: scale %d, want 2", hdt_first_scale(ctx));
    /* no budget: 4, whatever was measured */
    p.render_budget = 0.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS && hdt_first_scale(ctx) == 4);
    hd_destroy(ctx);
    /* the newest frame a scale-8 one of 15 ms, below the fixed part (a faster view, or noise):
       every prediction scales down with it (full frames about 81 ms, scale 2 about 31 ms), so a
       budget of 50 ms gets scale 2, not full frames (as if all were fixed cost) nor scale 8 (the
       old rule: 15 ms * 64 for a full frame) */
    CHECK(make_auto_ctx(0.05f, &ctx) == HD_SUCCESS);
    CHECK(hdt_frame_cost(ctx, 4, 0.025) == HD_SUCCESS && hdt_frame_cost(ctx, 2, 0.040) == HD_SUCCESS);
    CHECK(hdt_frame_cost(ctx, 1, 0.100) == HD_SUCCESS && hdt_frame_cost(ctx, 8, 0.015) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 2, "a fast scale-8 frame last, budget 50 ms: scale %d, want 2", hdt_first_scale(ctx));
    hd_destroy(ctx);
}

/* A scale the frames stop visiting goes stale: scales 4, 2 and 1 measured under 3x the load
   (75, 120, 300 ms), then 40 frames alternating between scales 4 and 2 at the normal cost (25 and
   40 ms; a drag that never rests for full frames). The line through the fresh scales alone puts a
   full frame at 100 ms, inside a budget of 120 ms; with the stale full frame in the fit it came
   out at about 160 ms and AUTO stayed at scale 2. With fewer than two fresh scales every measured
   one counts: 40 frames of scale 4 alone keep the stale line's shape (a full frame over budget). */
static void test_render_scale_auto_stale(void)
{
    hd_context ctx;
    int i;
    CHECK(make_auto_ctx(0.12f, &ctx) == HD_SUCCESS);
    CHECK(hdt_frame_cost(ctx, 4, 0.075) == HD_SUCCESS && hdt_frame_cost(ctx, 2, 0.120) == HD_SUCCESS);
    CHECK(hdt_frame_cost(ctx, 1, 0.300) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) > 1, "under load, budget 120 ms: scale %d, want a reduced one", hdt_first_scale(ctx));
    for (i = 0; i < 40; ++i) CHECK(hdt_frame_cost(ctx, i % 2 ? 2 : 4, i % 2 ? 0.040 : 0.025) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 1, "the full frame's estimate stale, budget 120 ms: scale %d, want 1",
              hdt_first_scale(ctx));
    hd_destroy(ctx);
    CHECK(make_auto_ctx(0.12f, &ctx) == HD_SUCCESS);
    CHECK(hdt_frame_cost(ctx, 4, 0.075) == HD_SUCCESS && hdt_frame_cost(ctx, 2, 0.120) == HD_SUCCESS);
    CHECK(hdt_frame_cost(ctx, 1, 0.300) == HD_SUCCESS);
    for (i = 0; i < 40; ++i) CHECK(hdt_frame_cost(ctx, 4, 0.025) == HD_SUCCESS);
    CHECK_MSG(hdt_first_scale(ctx) == 2, "one fresh scale, budget 120 ms: scale %d, want 2", hdt_first_scale(ctx));
    hd_destroy(ctx);
}

/* The image buffer holds the reduced frames' region only once a scale > 1 is used: full frames
   cost the w x h image and its depth plane alone (hd_stats.image_bytes says what is held). A new camera size keeps
   the region while the parameters may still ask for reduced frames. When the region cannot be
   allocated, the frame fails with HD_ERROR_OUT_OF_MEMORY and one log line, and the context goes
   on rendering full frames. */
static void test_render_scale_image_room(void)
{
    enum { H = W / 2, W2 = 2 * W };
    const size_t full = (size_t)W * W * 16, room = (size_t)H * H * 16, held = full + (size_t)W * W * 4;
    float *img = (float *)malloc(full), *before = (float *)malloc(full);
    hd_test_alloc al;
    hd_test_log log;
    hd_desc d;
    hd_context ctx;
    hd_stats s;
    hd_params p;
    hd_camera cam;
    make_desc(&d, &log);
    d.params.light_tolerance = 1e6f; /* converged within 3 iterations: hd_render only projects */
    hd_test_allocator(&d, &al);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 3) == HD_SUCCESS && hd_render(ctx) == HD_SUCCESS);
    CHECK_MSG(hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == held, "scale 1: %zu image bytes, want %zu", s.image_bytes, held);
    /* the region cannot be had: the frame fails, logged once; full frames go on */
    CHECK(hd_read_image_f32(ctx, before, full / 4) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    p.render_scale = 2;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    al.fail_at = al.calls + 1;
    CHECK(hd_render(ctx) == HD_ERROR_OUT_OF_MEMORY && log.errors == 1 && log.last_code == HD_ERROR_OUT_OF_MEMORY && al.failed == 1);
    CHECK_MSG(strstr(log.last, "reduced") != NULL, "log: %s", log.last);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == held && s.frames == 0);
    p.render_scale = 1;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS && hd_read_image_f32(ctx, img, full / 4) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.frames == 1 && s.render_scale == 1 && s.image_bytes == held);
    CHECK(memcmp(img, before, full) == 0); /* the same first frame of the same view and light */
    /* reduced frames: the region comes with the first one */
    p.render_scale = HD_RENDER_SCALE_AUTO;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK_MSG(hd_get_stats(ctx, &s) == HD_SUCCESS && s.render_scale == 4 && s.image_bytes == held + room, "auto: scale %d, %zu bytes",
              s.render_scale, s.image_bytes);
    /* a new size keeps it while reduced frames may come, and drops it at render_scale 1 */
    cam = d.camera;
    cam.width = cam.height = W2;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == (size_t)(W2 * W2 + W * W) * 16 + (size_t)W2 * W2 * 4);
    CHECK(hd_render(ctx) == HD_SUCCESS && hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == (size_t)(W2 * W2 + W * W) * 16 + (size_t)W2 * W2 * 4);
    p.render_scale = 1;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    cam.width = cam.height = W;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS && hd_get_stats(ctx, &s) == HD_SUCCESS && s.image_bytes == held);
    CHECK(log.errors == 1);
    hd_destroy(ctx);
    CHECK(al.live == 0);
    free(img);
    free(before);
}

/* render_scale outside 1..16 and HD_RENDER_SCALE_AUTO: HD_ERROR_INVALID_PARAMETER, one line. */
static void test_render_scale_bad_input(void)
{
    static const int bad[5] = {17, -2, 1000, -1000000, 0x7fffffff};
    hd_test_log log;
    hd_desc d;
    hd_context ctx;
    hd_params p;
    int i;
    for (i = 0; i < 5; ++i) {
        make_desc(&d, &log);
        d.params.render_scale = bad[i];
        CHECK_MSG(hd_create(&d, &ctx) == HD_ERROR_INVALID_PARAMETER && log.errors == 1 && strstr(log.last, "render_scale"),
                  "render_scale %d", bad[i]);
    }
    make_desc(&d, &log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS && d.params.render_scale == 1); /* 0 -> 1 */
    p = d.params;
    for (i = 0; i < 5; ++i) {
        p.render_scale = bad[i];
        CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_PARAMETER && log.errors == i + 1 && strstr(log.last, "render_scale"));
    }
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS && d.params.render_scale == 1); /* unchanged */
    p.render_scale = 16;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS && log.errors == 5);
    CHECK(hd_render(ctx) == HD_SUCCESS); /* a 2 x 2 frame of a 32 x 32 image */
    hd_destroy(ctx);
}


/* Converges ctx's light and fills its image (hd_render until frame_window frames are in). */
static void render_until_done(hd_context ctx)
{
    hd_stats s;
    int i;
    for (i = 0; i < 2000; ++i) {
        CHECK(hd_render(ctx) == HD_SUCCESS);
        CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS);
        if (s.light_converged && s.frames >= 8) break;
    }
    CHECK_MSG(s.light_converged && s.frames == 8 && s.refine_paths == 0, "converged %d, %llu frames", s.light_converged,
              (unsigned long long)s.frames);
}

/* HD_REST_REFINE: the same HD frames as HOLD until the view rests, then one refinement pass per
   call (no light work) that changes the image; a camera move shows HD's frame at once, bit for
   bit the one a HOLD context projects; a setter of the refinement restarts the image. */
static void test_render_refine_rest(void)
{
    float *a = (float *)malloc(W * W * 16), *b = (float *)malloc(W * W * 16);
    hd_desc d;
    hd_context hold, ref;
    hd_stats s, c;
    hd_camera cam;
    hd_params p;
    double diff = 0.0;
    int i;
    make_desc(&d, NULL);
    d.params.light_tolerance = 0.05f;
    CHECK(hd_create(&d, &hold) == HD_SUCCESS);
    d.params.rest = HD_REST_REFINE;
    CHECK(hd_create(&d, &ref) == HD_SUCCESS);
    render_until_done(hold);
    render_until_done(ref);
    CHECK(hd_read_image_f32(hold, a, W * W * 4) == HD_SUCCESS && hd_read_image_f32(ref, b, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(a, b, W * W * 16) == 0); /* HD's frames, unchanged by the setting */
    CHECK(hd_get_stats(ref, &s) == HD_SUCCESS);
    for (i = 0; i < 5; ++i) CHECK(hd_render(ref) == HD_SUCCESS);
    CHECK(hd_get_stats(ref, &c) == HD_SUCCESS);
    CHECK(c.refine_paths == 5 && c.frames == 8 && c.iterations == s.iterations && c.seconds_direct == s.seconds_direct);
    CHECK(hd_read_image_f32(ref, b, W * W * 4) == HD_SUCCESS);
    for (i = 0; i < W * W * 4; ++i) diff += fabs((double)a[i] - b[i]);
    CHECK(diff > 0.0);
    CHECK(hd_render(hold) == HD_SUCCESS && hd_get_stats(hold, &c) == HD_SUCCESS && c.refine_paths == 0); /* HOLD rests */

    cam = d.camera;
    cam.eye[0] = 2.0f; cam.eye[1] = 0.7f; cam.eye[2] = 1.2f;
    CHECK(hd_set_camera(hold, &cam) == HD_SUCCESS && hd_set_camera(ref, &cam) == HD_SUCCESS);
    CHECK(hd_render(hold) == HD_SUCCESS && hd_render(ref) == HD_SUCCESS);
    CHECK(hd_get_stats(ref, &c) == HD_SUCCESS && c.refine_paths == 0 && c.frames == 1);
    CHECK(hd_read_image_f32(hold, a, W * W * 4) == HD_SUCCESS && hd_read_image_f32(ref, b, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(a, b, W * W * 16) == 0); /* HD's frame at once, no paths */

    for (i = 0; i < 12; ++i) CHECK(hd_render(ref) == HD_SUCCESS);
    CHECK(hd_get_stats(ref, &c) == HD_SUCCESS && c.refine_paths == 5);
    CHECK(hd_query_desc(ref, &d) == HD_SUCCESS);
    p = d.params;
    CHECK(p.rest == HD_REST_REFINE && p.refine_bounces == -1); /* the default filled in */
    p.refine_bounces = 3;
    CHECK(hd_set_params(ref, &p) == HD_SUCCESS && hd_render(ref) == HD_SUCCESS);
    CHECK(hd_get_stats(ref, &c) == HD_SUCCESS && c.refine_paths == 0 && c.frames == 1);
    hd_destroy(hold);
    hd_destroy(ref);
    free(a);
    free(b);
}

/* RMS over the RGB of two linear images. */
static double rms_rgb(const float *x, const float *y)
{
    double s = 0.0;
    int i;
    for (i = 0; i < W * W; ++i) {
        int c;
        for (c = 0; c < 3; ++c) s += ((double)x[4 * i + c] - y[4 * i + c]) * ((double)x[4 * i + c] - y[4 * i + c]);
    }
    return sqrt(s / (3.0 * W * W));
}

/* Two PT_MS images of d's scene, n paths each, seeds 11 and 12, into pa and pb: their RMS
   difference (returned) is the noise a refined image is held to. d keeps its other fields. */
static double pt_ms_pair(hd_desc *d, int n, float *pa, float *pb)
{
    hd_context ctx;
    int k;
    d->params.method = HD_METHOD_PT_MS;
    for (k = 0; k < 2; ++k) {
        d->params.seed = 11u + (uint32_t)k;
        CHECK(hd_create(d, &ctx) == HD_SUCCESS);
        CHECK(hd_iterate(ctx, n) == HD_SUCCESS);
        CHECK(hd_read_image_f32(ctx, k ? pb : pa, W * W * 4) == HD_SUCCESS);
        hd_destroy(ctx);
    }
    return rms_rgb(pa, pb);
}

/* refine_bounces -1: the refinement's paths are PT_MS's, so their mean (the image less HD's
   prior share, HD__REFINE_PRIOR = 8 paths' worth) agrees with PT_MS's within the noise: its RMS
   difference from one PT_MS image is about that of a second PT_MS image of another seed. Read
   at vertex 1 instead (HD's light at the first collision), the same test sees HD's bias on this
   scene: the check can fail. */
static void test_render_refine_unbiased(void)
{
    const int n = 192;
    float *h = (float *)malloc(W * W * 16), *r = (float *)malloc(W * W * 16);
    float *pa = (float *)malloc(W * W * 16), *pb = (float *)malloc(W * W * 16);
    double noise, err = 0.0, err1 = 0.0, ma = 0.0, mr = 0.0;
    hd_desc d;
    hd_context ctx;
    int i, k;
    make_desc(&d, NULL);
    d.params.light_tolerance = 0.05f;
    d.params.max_bounces = 8;
    noise = pt_ms_pair(&d, n, pa, pb);
    d.params.method = HD_METHOD_HD;
    d.params.seed = 0;
    d.params.rest = HD_REST_REFINE;
    for (k = 0; k < 2; ++k) {
        d.params.refine_bounces = k ? 1 : -1;
        CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
        render_until_done(ctx);
        CHECK(hd_read_image_f32(ctx, h, W * W * 4) == HD_SUCCESS);
        for (i = 0; i < n; ++i) CHECK(hd_render(ctx) == HD_SUCCESS);
        CHECK(hd_read_image_f32(ctx, r, W * W * 4) == HD_SUCCESS);
        hd_destroy(ctx);
        for (i = 0; i < W * W * 4; ++i) r[i] = (float)(((8.0 + n) * r[i] - 8.0 * h[i]) / n);
        if (k) {
            err1 = rms_rgb(r, pa);
        } else {
            err = rms_rgb(r, pa);
            for (i = 0; i < W * W; ++i) { ma += pa[4 * i]; mr += r[4 * i]; }
        }
    }
    fprintf(stderr, "  refine k=-1 RMS %g, k=1 RMS %g, PT_MS seeds %g; mean %g vs %g\n", err, err1, noise, mr, ma);
    CHECK_MSG(err < 1.25 * noise, "refinement paths vs PT_MS: RMS %g, PT_MS seeds apart %g", err, noise);
    CHECK_MSG(fabs(mr - ma) < 0.02 * ma, "mean radiance %g against PT_MS's %g", mr, ma);
    CHECK_MSG(err1 > 1.25 * noise, "paths reading HD's light at vertex 1: RMS %g, noise %g", err1, noise);
    free(h); free(r); free(pa); free(pb);
}

/* HD_REST_BLEND: HD's frames as HOLD's until the view rests, then one pass of paths per call that
   changes the image (finite, not negative); hd_iterate during the rest projects into HD's frame
   (the one HOLD holds), not into the blend, and a camera move shows HD's frame at once: both bit
   for bit HOLD's. */
static void test_render_blend_rest(void)
{
    float *a = (float *)malloc(W * W * 16), *b = (float *)malloc(W * W * 16);
    hd_desc d;
    hd_context hold, bl;
    hd_stats s, c;
    hd_camera cam;
    double diff = 0.0;
    int i, finite = 1;
    make_desc(&d, NULL);
    d.params.light_tolerance = 0.05f;
    CHECK(hd_create(&d, &hold) == HD_SUCCESS);
    d.params.rest = HD_REST_BLEND;
    CHECK(hd_create(&d, &bl) == HD_SUCCESS);
    render_until_done(hold);
    render_until_done(bl);
    CHECK(hd_read_image_f32(hold, a, W * W * 4) == HD_SUCCESS && hd_read_image_f32(bl, b, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(a, b, W * W * 16) == 0);
    CHECK(hd_get_stats(bl, &s) == HD_SUCCESS);
    for (i = 0; i < 6; ++i) CHECK(hd_render(bl) == HD_SUCCESS);
    CHECK(hd_get_stats(bl, &c) == HD_SUCCESS);
    CHECK(c.refine_paths == 6 && c.frames == 8 && c.iterations == s.iterations);
    CHECK(hd_read_image_f32(bl, b, W * W * 4) == HD_SUCCESS);
    for (i = 0; i < W * W * 4; ++i) {
        diff += fabs((double)a[i] - b[i]);
        finite &= isfinite(b[i]) && b[i] >= 0.0f;
    }
    CHECK(diff > 0.0 && finite);

    CHECK(hd_iterate(hold, 1) == HD_SUCCESS && hd_iterate(bl, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(bl, &c) == HD_SUCCESS && c.refine_paths == 0);
    CHECK(hd_read_image_f32(hold, a, W * W * 4) == HD_SUCCESS && hd_read_image_f32(bl, b, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(a, b, W * W * 16) == 0); /* the frame went into HD's image, not the blend */

    for (i = 0; i < 12; ++i) CHECK(hd_render(hold) == HD_SUCCESS && hd_render(bl) == HD_SUCCESS); /* the same light work */
    CHECK(hd_get_stats(bl, &c) == HD_SUCCESS && c.refine_paths > 0);
    cam = d.camera;
    cam.eye[0] = 2.0f; cam.eye[1] = 0.7f; cam.eye[2] = 1.2f;
    CHECK(hd_set_camera(hold, &cam) == HD_SUCCESS && hd_set_camera(bl, &cam) == HD_SUCCESS);
    CHECK(hd_render(hold) == HD_SUCCESS && hd_render(bl) == HD_SUCCESS);
    CHECK(hd_get_stats(bl, &c) == HD_SUCCESS && c.refine_paths == 0 && c.frames == 1);
    CHECK(hd_read_image_f32(hold, a, W * W * 4) == HD_SUCCESS && hd_read_image_f32(bl, b, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(a, b, W * W * 16) == 0); /* HD's frame at once */
    hd_destroy(hold);
    hd_destroy(bl);
    free(a);
    free(b);
}

/* HD_REST_BLEND with many paths tends to PT_MS: after n passes its RMS difference from one PT_MS
   image is below that of a second PT_MS image of another seed and its mean is PT_MS's within 2 %.
   HD's frame alone fails the same RMS bound on this scene (its bias), so the check can fail. */
static void test_render_blend_unbiased(void)
{
    const int n = 192;
    float *h = (float *)malloc(W * W * 16), *r = (float *)malloc(W * W * 16);
    float *pa = (float *)malloc(W * W * 16), *pb = (float *)malloc(W * W * 16);
    double noise, err, errh, ma = 0.0, mr = 0.0;
    hd_desc d;
    hd_context ctx;
    int i;
    make_desc(&d, NULL);
    d.params.light_tolerance = 0.05f;
    d.params.max_bounces = 8;
    noise = pt_ms_pair(&d, n, pa, pb);
    d.params.method = HD_METHOD_HD;
    d.params.seed = 0;
    d.params.rest = HD_REST_BLEND;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    render_until_done(ctx);
    CHECK(hd_read_image_f32(ctx, h, W * W * 4) == HD_SUCCESS);
    for (i = 0; i < n; ++i) CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, r, W * W * 4) == HD_SUCCESS);
    hd_destroy(ctx);
    err = rms_rgb(r, pa);
    errh = rms_rgb(h, pa);
    for (i = 0; i < W * W; ++i) { ma += pa[4 * i]; mr += r[4 * i]; }
    fprintf(stderr, "  blend RMS %g, HD RMS %g, PT_MS seeds %g; mean %g vs %g\n", err, errh, noise, mr, ma);
    CHECK_MSG(err < noise, "blend vs PT_MS: RMS %g, PT_MS seeds apart %g", err, noise);
    CHECK_MSG(fabs(mr - ma) < 0.02 * ma, "mean radiance %g against PT_MS's %g", mr, ma);
    CHECK_MSG(errh > noise, "HD's frame vs PT_MS: RMS %g, noise %g", errh, noise);
    free(h); free(r); free(pa); free(pb);
}

/* Bad values of rest and refine_bounces: refused with one log line each, nothing changed. */
static void test_render_refine_bad_input(void)
{
    static const int bad_k[] = {-2, 100001, INT32_MIN};
    static const int bad_rest[] = {HD_REST_COUNT, -1};
    hd_test_log log;
    hd_desc d;
    hd_context ctx;
    hd_params p;
    int i;
    memset(&log, 0, sizeof log);
    make_desc(&d, &log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    for (i = 0; i < 3; ++i) {
        p.refine_bounces = bad_k[i];
        CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_PARAMETER && log.errors == i + 1 && strstr(log.last, "refine_bounces"));
    }
    p.refine_bounces = 2;
    for (i = 0; i < 2; ++i) {
        p.rest = (hd_rest)bad_rest[i];
        CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_ENUM && log.errors == 4 + i && strstr(log.last, "params.rest"));
    }
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS && d.params.rest == HD_REST_HOLD && d.params.refine_bounces == -1);
    make_desc(&d, &log); /* a fresh log */
    d.params.refine_bounces = -2;
    {
        hd_context c2;
        hd_result r = hd_create(&d, &c2);
        CHECK_MSG(r == HD_ERROR_INVALID_PARAMETER && log.errors == 1, "%s, %d errors", hd_result_string(r), log.errors);
    }
    hd_destroy(ctx);
}

const hd_test_case hd_tests_render[] = {
    {"render_refine_is_iterate_without_frames", test_refine_is_iterate_without_frames},
    {"render_light_error_falls", test_light_error_falls},
    {"render_light_error_sampled", test_light_error_sampled},
    {"render_loop", test_render_loop},
    {"render_budget", test_render_budget},
    {"render_follows_light", test_render_follows_light},
    {"render_bad_input", test_render_bad_input},
    {"render_scale_upsample", test_render_scale_upsample},
    {"render_scale_auto", test_render_scale_auto},
    {"render_scale_auto_cost", test_render_scale_auto_cost},
    {"render_scale_auto_stale", test_render_scale_auto_stale},
    {"render_scale_image_room", test_render_scale_image_room},
    {"render_scale_bad_input", test_render_scale_bad_input},
    {"render_refine_rest", test_render_refine_rest},
    {"render_refine_unbiased", test_render_refine_unbiased},
    {"render_refine_bad_input", test_render_refine_bad_input},
    {"render_blend_rest", test_render_blend_rest},
    {"render_blend_unbiased", test_render_blend_unbiased},
};
const int hd_tests_render_count = sizeof hd_tests_render / sizeof hd_tests_render[0];
