/* test_core.c - the public API on the CPU backend: determinism, what a change invalidates,
   memory independent of the light count, and bad input (each its own hd_result and a log line). */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

/* A logger that counts messages and keeps the last error. */
typedef struct test_log { int count; hd_result last; char text[1024]; } test_log;
static void test_log_fn(void *user, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    test_log *t = (test_log *)user;
    (void)file; (void)line;
    if (level != HD_LOG_ERROR) return;
    t->count++;
    t->last = code;
    snprintf(t->text, sizeof t->text, "%s", msg);
}

/* A 24^3 blob with a dense core, one light, a 48x48 image: small enough for many cases. */
#define N 24
static uint8_t blob[N * N * N];
static const float blob_tf[12] = {0, 0, 0, 0, 1.0f, 0.6f, 0.4f, 0.3f, 1, 1, 1, 1};

static void make_desc(hd_desc *d, test_log *log)
{
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                float dx = x - 11.5f, dy = y - 11.5f, dz = z - 11.5f;
                float r = sqrtf(dx * dx + dy * dy + dz * dz);
                blob[(z * N + y) * N + x] = (uint8_t)(r < 10 ? (r < 5 ? 255 : 128) : 0);
            }
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = N;
    d->volume.data = blob;
    d->transfer_function.rgba = blob_tf;
    d->transfer_function.count = 3;
    d->camera.width = d->camera.height = 48;
    d->params.extinction = 40.0f;
    /* the paper's grid and boundary: the cases are about the API, not the defaults (which
       core_create_defaults and core_params_preset check) */
    d->params.illumination_downsample = 1;
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
    if (log) {
        memset(log, 0, sizeof *log);
        d->logger.func = test_log_fn;
        d->logger.user_data = log;
    }
}

static void test_create_defaults(void)
{
    hd_desc d, q;
    hd_context ctx;
    hd_stats s;
    make_desc(&d, NULL);
    CHECK(hd_params_preset(HD_PRESET_DEFAULT, &d.params, NULL) == HD_SUCCESS);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &q) == HD_SUCCESS);
    CHECK(q.params.method == HD_METHOD_HD);
    CHECK(q.params.albedo == 0.9f && q.params.diffusion_sweeps == 4 && q.params.step == 0.5f);
    CHECK(q.params.illumination_downsample == 2 && q.params.diffusion_boundary == HD_BOUNDARY_SURFACE);
    CHECK(q.params.solver == HD_SOLVER_RED_BLACK);
    CHECK(q.light_count == 1 && q.lights[0].direction[2] == -1.0f && q.lights[0].intensity == 1.0f);
    CHECK(q.camera.fov_y == 40.0f && q.camera.eye[2] == 2.5f && q.camera.up[1] == 1.0f);
    CHECK(q.volume.spacing[0] == 1.0f && q.volume.value_range[1] == 255.0f);
    CHECK(q.volume.data == NULL); /* the caller's buffer is not kept */
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 0);
    CHECK(hd_iterate(ctx, 3) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 3 && s.frames == 3);
    CHECK(s.illumination_dims[0] == N / 2 && s.illumination_channels == 1);
    CHECK(hd_destroy(ctx) == HD_SUCCESS);
}

/* hd_params_preset: the paper's settings (full grid, box boundary, 4 red-black sweeps) give the
   image of a context with those fields spelled out, which differs from the defaults' image; the
   default preset restores the defaults; other fields are left alone; bad input is refused with
   its code and one log line. */
static void test_params_preset(void)
{
    hd_desc d, q;
    hd_context paper, spelled, dflt;
    hd_params p;
    test_log log;
    size_t i, n = 48 * 48 * 4, differ = 0;
    float *a = (float *)malloc(n * sizeof(float)), *b = (float *)malloc(n * sizeof(float));
    float *c = (float *)malloc(n * sizeof(float));
    make_desc(&d, &log);
    d.params.seed = 5;
    d.params.illumination_downsample = 0;
    d.params.diffusion_boundary = HD_BOUNDARY_DEFAULT;
    CHECK(hd_params_preset(HD_PRESET_PAPER, &d.params, &d.logger) == HD_SUCCESS);
    CHECK(d.params.illumination_downsample == 1 && d.params.diffusion_boundary == HD_BOUNDARY_BOX);
    CHECK(d.params.solver == HD_SOLVER_RED_BLACK && d.params.diffusion_sweeps == 4);
    CHECK(d.params.seed == 5 && d.params.extinction == 40.0f && d.params.method == HD_METHOD_DEFAULT);
    CHECK(hd_create(&d, &paper) == HD_SUCCESS);
    CHECK(hd_query_desc(paper, &q) == HD_SUCCESS);
    CHECK(q.params.illumination_downsample == 1 && q.params.diffusion_boundary == HD_BOUNDARY_BOX);
    make_desc(&d, NULL); /* the paper's grid and boundary, spelled out */
    d.params.seed = 5;
    d.params.solver = HD_SOLVER_RED_BLACK;
    d.params.diffusion_sweeps = 4;
    CHECK(hd_create(&d, &spelled) == HD_SUCCESS);
    p = d.params;
    CHECK(hd_params_preset(HD_PRESET_DEFAULT, &p, NULL) == HD_SUCCESS);
    CHECK(p.illumination_downsample == 0 && p.diffusion_boundary == HD_BOUNDARY_DEFAULT);
    CHECK(p.solver == HD_SOLVER_DEFAULT && p.diffusion_sweeps == 0 && p.seed == 5);
    d.params = p;
    CHECK(hd_create(&d, &dflt) == HD_SUCCESS);
    CHECK(hd_iterate(paper, 4) == HD_SUCCESS && hd_iterate(spelled, 4) == HD_SUCCESS && hd_iterate(dflt, 4) == HD_SUCCESS);
    CHECK(hd_read_image_f32(paper, a, n) == HD_SUCCESS && hd_read_image_f32(spelled, b, n) == HD_SUCCESS);
    CHECK(hd_read_image_f32(dflt, c, n) == HD_SUCCESS);
    CHECK(memcmp(a, b, n * sizeof(float)) == 0);
    for (i = 0; i < n; ++i) differ += a[i] != c[i];
    CHECK(differ > 0);
    make_desc(&d, &log);
    CHECK(hd_params_preset(HD_PRESET_COUNT, &p, &d.logger) == HD_ERROR_INVALID_ENUM);
    CHECK(log.count == 1 && log.last == HD_ERROR_INVALID_ENUM);
    CHECK(hd_params_preset((hd_preset)-1, &p, &d.logger) == HD_ERROR_INVALID_ENUM);
    CHECK(log.count == 2 && log.last == HD_ERROR_INVALID_ENUM);
    CHECK(hd_params_preset(HD_PRESET_PAPER, NULL, &d.logger) == HD_ERROR_NULL_POINTER);
    CHECK(log.count == 3 && log.last == HD_ERROR_NULL_POINTER);
    CHECK(p.seed == 5 && p.illumination_downsample == 0); /* a refused preset writes nothing */
    CHECK(hd_params_preset(HD_PRESET_PAPER, &p, NULL) == HD_SUCCESS && p.illumination_downsample == 1);
    hd_destroy(paper);
    hd_destroy(spelled);
    hd_destroy(dflt);
    free(a);
    free(b);
    free(c);
}

static float *render(int threads, uint32_t seed, int iters)
{
    hd_desc d;
    hd_context ctx;
    float *img = (float *)malloc(48 * 48 * 4 * sizeof(float));
    make_desc(&d, NULL);
    d.threads = threads;
    d.params.seed = seed;
    if (hd_create(&d, &ctx) != HD_SUCCESS) { free(img); return NULL; }
    hd_iterate(ctx, iters);
    hd_read_image_f32(ctx, img, 48 * 48 * 4);
    hd_destroy(ctx);
    return img;
}

/* The same seed gives the same bits for 1 and 2 threads; another seed does not. */
static void test_determinism(void)
{
    float *a = render(1, 7, 6), *b = render(2, 7, 6), *c = render(2, 7, 6), *e = render(2, 8, 6);
    CHECK(a && b && c && e);
    if (a && b && c && e) {
        size_t bytes = 48 * 48 * 4 * sizeof(float), i;
        double sum = 0;
        CHECK(memcmp(a, b, bytes) == 0);
        CHECK(memcmp(b, c, bytes) == 0);
        CHECK(memcmp(b, e, bytes) != 0);
        for (i = 0; i < 48 * 48 * 4; ++i) sum += a[i];
        CHECK(sum > 1.0); /* not a black image */
    }
    free(a); free(b); free(c); free(e);
}

static void read_both(hd_context ctx, float *E, float *phi, size_t n)
{
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, E, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, phi, n) == HD_SUCCESS);
}

/* Moving the camera keeps E and phi bit for bit and the iteration count; only the image restarts. */
static void test_camera_keeps_illumination(void)
{
    hd_desc d;
    hd_context ctx;
    hd_camera cam;
    hd_stats s;
    size_t n = (size_t)N * N * N;
    float *E0 = (float *)malloc(n * 4), *P0 = (float *)malloc(n * 4), *E1 = (float *)malloc(n * 4), *P1 = (float *)malloc(n * 4);
    double esum = 0, psum = 0;
    size_t i;
    make_desc(&d, NULL);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 5) == HD_SUCCESS);
    read_both(ctx, E0, P0, n);
    cam = d.camera;
    cam.eye[0] = 2.0f; cam.eye[1] = 0.5f; cam.eye[2] = 1.0f;
    CHECK(hd_set_camera(ctx, &cam) == HD_SUCCESS);
    read_both(ctx, E1, P1, n);
    CHECK(memcmp(E0, E1, n * 4) == 0);
    CHECK(memcmp(P0, P1, n * 4) == 0);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 5 && s.frames == 0);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 6 && s.frames == 1);
    for (i = 0; i < n; ++i) { esum += E0[i]; psum += P0[i]; }
    CHECK(esum > 0.0 && psum > 0.0);
    hd_destroy(ctx);
    free(E0); free(P0); free(E1); free(P1);
}

/* Each setter resets exactly what depends on it. */
static void test_invalidation(void)
{
    hd_desc d;
    hd_context ctx;
    hd_params p;
    hd_stats s;
    hd_light l[2];
    hd_transfer_function tf;
    size_t n = (size_t)N * N * N;
    float *E0 = (float *)malloc(n * 4), *P0 = (float *)malloc(n * 4), *E1 = (float *)malloc(n * 4), *P1 = (float *)malloc(n * 4);
    make_desc(&d, NULL);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 4) == HD_SUCCESS);
    read_both(ctx, E0, P0, n);
    /* albedo: the image restarts, E is kept and phi is the warm start of the new solution */
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    p.albedo = 0.5f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    read_both(ctx, E1, P1, n);
    CHECK(memcmp(E0, E1, n * 4) == 0 && memcmp(P0, P1, n * 4) == 0 && P0[n / 2 + N / 2] != 0.0f);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 4 && s.frames == 0 && s.light_error == 1.0);
    /* the diffusion boundary: phi and the image restart, E is kept */
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
    read_both(ctx, E0, P0, n);
    p.diffusion_boundary = HD_BOUNDARY_SURFACE;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    read_both(ctx, E1, P1, n);
    CHECK(memcmp(E0, E1, n * 4) == 0);
    CHECK(P1[n / 2 + N / 2] == 0.0f && P0[n / 2 + N / 2] != 0.0f);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 6 && s.frames == 0);
    /* solver, sweeps and exposure change nothing */
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
    read_both(ctx, E0, P0, n);
    p.solver = HD_SOLVER_JACOBI; p.diffusion_sweeps = 9; p.exposure = 2.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    read_both(ctx, E1, P1, n);
    CHECK(memcmp(E0, E1, n * 4) == 0 && memcmp(P0, P1, n * 4) == 0);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 8 && s.frames == 2);
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS); /* Jacobi runs from the kept phi */
    /* lights of another colour: three channels, new grids, E restarts */
    memset(l, 0, sizeof l);
    l[0].direction[0] = 1.0f;
    l[1].type = HD_LIGHT_POINT; l[1].position[1] = 1.0f; l[1].color[0] = 1.0f; l[1].color[1] = 0.5f;
    CHECK(hd_set_lights(ctx, l, 2) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 0 && s.illumination_channels == 3);
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
    /* TF alpha: sigma_t anew, E and phi the warm start (tests/test_living.c), the image restarts;
       hd_reset restarts from zero */
    tf.rgba = blob_tf; tf.count = 2;
    CHECK(hd_set_transfer_function(ctx, &tf) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 2 && s.frames == 0 && s.light_error == 1.0);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
    CHECK(hd_reset(ctx) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.iterations == 0 && s.frames == 0);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
    hd_destroy(ctx);
    free(E0); free(P0); free(E1); free(P1);
}

/* HD keeps one E and one phi for all lights: its memory does not depend on the light count. */
static void test_memory_independent_of_lights(void)
{
    hd_desc d;
    hd_context a, b;
    hd_light l[16];
    hd_stats sa, sb;
    int i;
    make_desc(&d, NULL);
    CHECK(hd_create(&d, &a) == HD_SUCCESS);
    memset(l, 0, sizeof l);
    for (i = 0; i < 16; ++i) { l[i].direction[0] = cosf((float)i); l[i].direction[1] = sinf((float)i); l[i].direction[2] = -0.5f; }
    d.lights = l;
    d.light_count = 16;
    CHECK(hd_create(&d, &b) == HD_SUCCESS);
    CHECK(hd_iterate(a, 2) == HD_SUCCESS && hd_iterate(b, 2) == HD_SUCCESS);
    CHECK(hd_get_stats(a, &sa) == HD_SUCCESS && hd_get_stats(b, &sb) == HD_SUCCESS);
    CHECK(sa.method_bytes == sb.method_bytes);
    /* sigma_t + E + phi + the projection's E + phi, 4 bytes each, and the direct light's mask */
    CHECK(sa.method_bytes == (size_t)N * N * N * 16 + hd_test_mask_bytes(&sa));
    hd_destroy(a);
    hd_destroy(b);
}

/* A coarser illumination grid: dims / 2 rounded up (24 -> 12, 8x fewer voxels and bytes), the
   image stays close to the full-resolution one (measured: relative L2 of the radiance 8.4% on
   this 24^3 blob of radius 10, whose 12^3 grid is very coarse; bound 15%), and switching back
   restores the full grid. */
static void test_illumination_downsample(void)
{
    hd_desc d;
    hd_context full, coarse;
    hd_stats sf, sc;
    hd_params p;
    size_t i, n = 48 * 48 * 4;
    float *a = (float *)malloc(n * sizeof(float)), *b = (float *)malloc(n * sizeof(float));
    double num = 0, den = 0;
    make_desc(&d, NULL);
    d.params.seed = 3;
    CHECK(hd_create(&d, &full) == HD_SUCCESS);
    d.params.illumination_downsample = 2;
    CHECK(hd_create(&d, &coarse) == HD_SUCCESS);
    CHECK(hd_iterate(full, 24) == HD_SUCCESS && hd_iterate(coarse, 24) == HD_SUCCESS);
    CHECK(hd_get_stats(full, &sf) == HD_SUCCESS && hd_get_stats(coarse, &sc) == HD_SUCCESS);
    CHECK(sc.illumination_dims[0] == 12 && sc.illumination_dims[1] == 12 && sc.illumination_dims[2] == 12);
    CHECK(sf.method_bytes - hd_test_mask_bytes(&sf) == 8 * (sc.method_bytes - hd_test_mask_bytes(&sc)));
    CHECK(hd_read_image_f32(full, a, n) == HD_SUCCESS && hd_read_image_f32(coarse, b, n) == HD_SUCCESS);
    for (i = 0; i < n; ++i) {
        if (i % 4 == 3) continue; /* opacity does not depend on the grid */
        num += (double)(a[i] - b[i]) * (a[i] - b[i]);
        den += (double)a[i] * a[i];
    }
    printf("  illumination downsample 2: %zu -> %zu bytes, image rel. L2 %.4f\n", sf.method_bytes,
           sc.method_bytes, sqrt(num / den));
    CHECK(den > 0 && sqrt(num / den) < 0.15);
    CHECK(hd_query_desc(coarse, &d) == HD_SUCCESS);
    p = d.params;
    p.illumination_downsample = 1;
    CHECK(hd_set_params(coarse, &p) == HD_SUCCESS);
    CHECK(hd_get_stats(coarse, &sc) == HD_SUCCESS && sc.illumination_dims[0] == N && sc.iterations == 0);
    CHECK(hd_iterate(coarse, 1) == HD_SUCCESS);
    p.illumination_downsample = 9;
    CHECK(hd_set_params(coarse, &p) == HD_ERROR_INVALID_PARAMETER);
    hd_destroy(full);
    hd_destroy(coarse);
    free(a);
    free(b);
}

/* RGB scattering: with a TF colour of (1, 0.5, 0.25), the red channel scatters exactly as the
   grey diffusion does (same bits: albedo * 1), green and blue lose more light at every
   scattering, so phi_r > phi_g > phi_b; E is the same in every channel (white light) and equal
   to the grey E. State: sigma_t + 3 colours + 3 E + 3 phi = 40 bytes per voxel. */
static void test_rgb_scattering(void)
{
    static const float tf[12] = {1, 0.5f, 0.25f, 0, 1, 0.5f, 0.25f, 0.3f, 1, 0.5f, 0.25f, 1};
    hd_desc d;
    hd_context grey, rgb;
    hd_stats sg, sr;
    size_t n = (size_t)N * N * N, i;
    float *Eg = (float *)malloc(n * 4), *Pg = (float *)malloc(n * 4);
    float *Er = (float *)malloc(n * 12), *Pr = (float *)malloc(n * 12);
    double sum[3] = {0, 0, 0};
    make_desc(&d, NULL);
    d.transfer_function.rgba = tf;
    CHECK(hd_create(&d, &grey) == HD_SUCCESS);
    d.params.rgb_scattering = 1;
    CHECK(hd_create(&d, &rgb) == HD_SUCCESS);
    CHECK(hd_iterate(grey, 6) == HD_SUCCESS && hd_iterate(rgb, 6) == HD_SUCCESS);
    CHECK(hd_get_stats(grey, &sg) == HD_SUCCESS && hd_get_stats(rgb, &sr) == HD_SUCCESS);
    CHECK(sg.illumination_channels == 1 && sr.illumination_channels == 3);
    /* RGB: sigma_t with its colour (4 channels), E, phi and the projection's E + phi (3 each);
       the direct light's mask, one for all channels */
    CHECK(sr.method_bytes == n * 52 + hd_test_mask_bytes(&sr) && sg.method_bytes == n * 16 + hd_test_mask_bytes(&sg));
    CHECK(hd_read_illumination(grey, HD_ILLUMINATION_DIRECT, Eg, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(grey, HD_ILLUMINATION_SCATTERED, Pg, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(rgb, HD_ILLUMINATION_DIRECT, Er, 3 * n) == HD_SUCCESS);
    CHECK(hd_read_illumination(rgb, HD_ILLUMINATION_SCATTERED, Pr, 3 * n) == HD_SUCCESS);
    for (i = 0; i < 3; ++i) CHECK_MSG(memcmp(Eg, Er + i * n, n * 4) == 0, "E channel %zu", i);
    CHECK(memcmp(Pg, Pr, n * 4) == 0); /* red: colour 1, the grey solution bit for bit */
    for (i = 0; i < 3 * n; ++i) sum[i / n] += Pr[i];
    printf("  RGB scattering, TF colour (1, 0.5, 0.25): sum of phi r %.4g g %.4g b %.4g\n", sum[0], sum[1], sum[2]);
    CHECK(sum[0] > sum[1] && sum[1] > sum[2] && sum[2] > 0.0);
    hd_destroy(grey);
    hd_destroy(rgb);
    free(Eg); free(Pg); free(Er); free(Pr);
}

/* ---- bad input: each case its own code, and a logged message -------------------------------- */
typedef struct bad_case { const char *name; hd_result expect; void (*mutate)(hd_desc *d); } bad_case;
static float nan_f(void) { volatile float z = 0.0f; return z / z; }
static void m_zero_dim(hd_desc *d) { d->volume.dims[1] = 0; }
static void m_huge_dim(hd_desc *d) { d->volume.dims[0] = 1 << 20; }
static void m_negative_dim(hd_desc *d) { d->volume.dims[2] = -5; }
static void m_overflow(hd_desc *d) { d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = 8000; }
static void m_null_data(hd_desc *d) { d->volume.data = NULL; }
static void m_bad_type(hd_desc *d) { d->volume.type = (hd_voxel_type)99; }
static void m_nan_spacing(hd_desc *d) { d->volume.spacing[0] = nan_f(); d->volume.spacing[1] = d->volume.spacing[2] = 1; }
static void m_neg_spacing(hd_desc *d) { d->volume.spacing[0] = d->volume.spacing[1] = 1; d->volume.spacing[2] = -1; }
static void m_nan_extinction(hd_desc *d) { d->params.extinction = nan_f(); }
static void m_neg_albedo(hd_desc *d) { d->params.albedo = -0.5f; }
static void m_big_albedo(hd_desc *d) { d->params.albedo = 1.5f; }
static void m_bad_g(hd_desc *d) { d->params.anisotropy = 1.0f; }
static void m_neg_sweeps(hd_desc *d) { d->params.diffusion_sweeps = -1; }
static void m_low_majorant(hd_desc *d) { d->params.majorant = 1.0f; }
static void m_bad_method(hd_desc *d) { d->params.method = (hd_method)42; }
static void m_bad_downsample(hd_desc *d) { d->params.illumination_downsample = -2; }
static void m_big_downsample(hd_desc *d) { d->params.illumination_downsample = 9; }
static void m_bad_rgb(hd_desc *d) { d->params.rgb_scattering = 2; }
static void m_bad_boundary(hd_desc *d) { d->params.diffusion_boundary = (hd_boundary)7; }
static const float tf_nan[8] = {0, 0, 0, 0, 1, 1, 1, 1};
static float tf_bad[8];
static void m_tf_nan(hd_desc *d) { memcpy(tf_bad, tf_nan, sizeof tf_bad); tf_bad[7] = nan_f(); d->transfer_function.rgba = tf_bad; d->transfer_function.count = 2; }
static void m_tf_neg(hd_desc *d) { memcpy(tf_bad, tf_nan, sizeof tf_bad); tf_bad[1] = -1; d->transfer_function.rgba = tf_bad; d->transfer_function.count = 2; }
static void m_tf_one(hd_desc *d) { d->transfer_function.count = 1; }
static void m_tf_null(hd_desc *d) { d->transfer_function.rgba = NULL; d->transfer_function.count = 4; }
static void m_cam_same(hd_desc *d) { d->camera.eye[0] = d->camera.target[0] = 1.0f; }
static void m_cam_up(hd_desc *d) { d->camera.eye[1] = 2.0f; d->camera.up[1] = 1.0f; }
static void m_cam_fov(hd_desc *d) { d->camera.fov_y = 180.0f; }
static void m_cam_nan(hd_desc *d) { d->camera.eye[0] = nan_f(); }
static void m_cam_size(hd_desc *d) { d->camera.width = -3; }
static hd_light bad_light;
static void m_no_lights(hd_desc *d) { d->lights = &bad_light; d->light_count = 0; }
static void m_many_lights(hd_desc *d) { d->lights = &bad_light; d->light_count = HD_MAX_LIGHTS + 1; }
static void m_zero_dir(hd_desc *d) { memset(&bad_light, 0, sizeof bad_light); d->lights = &bad_light; d->light_count = 1; }
static void m_neg_intensity(hd_desc *d) { memset(&bad_light, 0, sizeof bad_light); bad_light.direction[0] = 1; bad_light.intensity = -1; d->lights = &bad_light; d->light_count = 1; }
static void m_null_lights(hd_desc *d) { d->lights = NULL; d->light_count = 2; }
static void free_cb(void *ptr, void *user) { (void)user; free(ptr); }
static void m_half_allocator(hd_desc *d) { d->allocator.alloc = NULL; d->allocator.free = free_cb; }

static const bad_case bad_cases[] = {
    {"zero dimension", HD_ERROR_INVALID_DIMENSIONS, m_zero_dim},
    {"huge dimension", HD_ERROR_INVALID_DIMENSIONS, m_huge_dim},
    {"negative dimension", HD_ERROR_INVALID_DIMENSIONS, m_negative_dim},
    {"dims x type overflow", HD_ERROR_SIZE_OVERFLOW, m_overflow},
    {"NULL data", HD_ERROR_NULL_POINTER, m_null_data},
    {"voxel type enum", HD_ERROR_INVALID_ENUM, m_bad_type},
    {"NaN spacing", HD_ERROR_INVALID_SPACING, m_nan_spacing},
    {"negative spacing", HD_ERROR_INVALID_SPACING, m_neg_spacing},
    {"NaN extinction", HD_ERROR_INVALID_PARAMETER, m_nan_extinction},
    {"negative albedo", HD_ERROR_INVALID_PARAMETER, m_neg_albedo},
    {"albedo > 1", HD_ERROR_INVALID_PARAMETER, m_big_albedo},
    {"anisotropy 1", HD_ERROR_INVALID_PARAMETER, m_bad_g},
    {"negative sweeps", HD_ERROR_INVALID_PARAMETER, m_neg_sweeps},
    {"majorant below extinction", HD_ERROR_INVALID_PARAMETER, m_low_majorant},
    {"method enum", HD_ERROR_INVALID_ENUM, m_bad_method},
    {"negative illumination_downsample", HD_ERROR_INVALID_PARAMETER, m_bad_downsample},
    {"illumination_downsample 9", HD_ERROR_INVALID_PARAMETER, m_big_downsample},
    {"rgb_scattering 2", HD_ERROR_INVALID_PARAMETER, m_bad_rgb},
    {"diffusion_boundary 7", HD_ERROR_INVALID_ENUM, m_bad_boundary},
    {"NaN TF entry", HD_ERROR_INVALID_TRANSFER_FUNCTION, m_tf_nan},
    {"negative TF entry", HD_ERROR_INVALID_TRANSFER_FUNCTION, m_tf_neg},
    {"one TF entry", HD_ERROR_INVALID_TRANSFER_FUNCTION, m_tf_one},
    {"NULL TF", HD_ERROR_NULL_POINTER, m_tf_null},
    {"eye == target", HD_ERROR_INVALID_CAMERA, m_cam_same},
    {"up parallel to view", HD_ERROR_INVALID_CAMERA, m_cam_up},
    {"fov 180", HD_ERROR_INVALID_CAMERA, m_cam_fov},
    {"NaN eye", HD_ERROR_INVALID_CAMERA, m_cam_nan},
    {"negative image size", HD_ERROR_INVALID_DIMENSIONS, m_cam_size},
    {"zero lights", HD_ERROR_NO_LIGHTS, m_no_lights},
    {"too many lights", HD_ERROR_TOO_MANY_LIGHTS, m_many_lights},
    {"zero light direction", HD_ERROR_INVALID_LIGHT, m_zero_dir},
    {"negative intensity", HD_ERROR_INVALID_LIGHT, m_neg_intensity},
    {"NULL lights", HD_ERROR_NULL_POINTER, m_null_lights},
    {"half an allocator", HD_ERROR_NULL_POINTER, m_half_allocator},
};

static void test_bad_desc(void)
{
    size_t i;
    for (i = 0; i < sizeof bad_cases / sizeof bad_cases[0]; ++i) {
        hd_desc d;
        test_log log;
        hd_context ctx;
        hd_result r;
        make_desc(&d, &log);
        bad_cases[i].mutate(&d);
        ctx.id = 12345;
        r = hd_create(&d, &ctx);
        CHECK_MSG(r == bad_cases[i].expect, "%s: got %s", bad_cases[i].name, hd_result_string(r));
        CHECK_MSG(log.count == 1 && log.last == r, "%s: %d messages logged", bad_cases[i].name, log.count);
        CHECK_MSG(ctx.id == 0, "%s: handle not cleared", bad_cases[i].name);
    }
    CHECK(hd_create(NULL, NULL) == HD_ERROR_NULL_POINTER);
}

/* The setters and readers reject bad arguments the same way and leave the context usable. */
static void test_bad_calls(void)
{
    hd_desc d;
    test_log log;
    hd_context ctx, stale;
    hd_camera cam;
    hd_params p;
    hd_transfer_function tf;
    float small[4];
    uint8_t px[4];
    make_desc(&d, &log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    cam = d.camera; cam.eye[0] = cam.target[0] = 0.3f; cam.eye[1] = cam.target[1] = 0; cam.eye[2] = cam.target[2] = 0;
    CHECK(hd_set_camera(ctx, &cam) == HD_ERROR_INVALID_CAMERA);
    CHECK(hd_set_camera(ctx, NULL) == HD_ERROR_NULL_POINTER);
    CHECK(hd_set_lights(ctx, d.lights, 0) == HD_ERROR_NO_LIGHTS);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params; p.extinction = -1.0f;
    CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_PARAMETER);
    p = d.params; p.tracking = (hd_tracking)7;
    CHECK(hd_set_params(ctx, &p) == HD_ERROR_INVALID_ENUM);
    tf.rgba = blob_tf; tf.count = 0;
    CHECK(hd_set_transfer_function(ctx, &tf) == HD_ERROR_INVALID_TRANSFER_FUNCTION);
    CHECK(hd_iterate(ctx, 0) == HD_ERROR_INVALID_PARAMETER);
    CHECK(hd_iterate(ctx, -4) == HD_ERROR_INVALID_PARAMETER);
    CHECK(hd_read_image_f32(ctx, small, 4) == HD_ERROR_BUFFER_TOO_SMALL);
    CHECK(hd_read_image_rgba8(ctx, px, 4) == HD_ERROR_BUFFER_TOO_SMALL);
    CHECK(hd_read_image_rgba8(ctx, NULL, 1u << 20) == HD_ERROR_NULL_POINTER);
    CHECK(hd_read_illumination(ctx, (hd_illumination)5, small, 4) == HD_ERROR_INVALID_ENUM);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, small, 4) == HD_ERROR_BUFFER_TOO_SMALL);
    CHECK(hd_get_stats(ctx, NULL) == HD_ERROR_NULL_POINTER);
    CHECK(log.count == 14); /* one per rejected call above */
    /* still usable after all that */
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
    stale = ctx;
    CHECK(hd_destroy(ctx) == HD_SUCCESS);
    log.count = 0;
    CHECK(hd_iterate(stale, 1) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_destroy(stale) == HD_ERROR_INVALID_HANDLE);
    CHECK(log.count == 0); /* a destroyed context's logger is never called again */
    stale.id = 0;
    CHECK(hd_iterate(stale, 1) == HD_ERROR_INVALID_HANDLE);
    stale.id = 0xffffffffu;
    CHECK(hd_get_stats(stale, NULL) == HD_ERROR_INVALID_HANDLE);
}

/* The sRGB encoding of hd_read_image_rgba8, written out: 0 for v <= 0 (and NaN), 255 from 1. */
static uint8_t srgb8_ref(float v)
{
    float s;
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)(s * 255.0f + 0.5f);
}

/* hd_read_image_rgba8 is the sRGB encoding of hd_read_image_f32 * exposure, byte for byte, at
   exposures from 2^-14 to 2^6 in steps of 2^(1/20): the image's values then pass through every
   code, both branches of the encoding and many values next to each code's boundary. */
static void test_rgba8_encoding(void)
{
    hd_desc d;
    hd_context ctx;
    float img[48 * 48 * 4];
    uint8_t px[48 * 48 * 4];
    long bad = 0, checked = 0;
    int k, i, c;
    make_desc(&d, NULL);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 4) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, img, sizeof img / sizeof img[0]) == HD_SUCCESS);
    for (k = 0; k <= 400; ++k) {
        float e = (float)pow(2.0, -14.0 + k / 20.0);
        d.params.exposure = e;
        CHECK(hd_set_params(ctx, &d.params) == HD_SUCCESS);
        CHECK(hd_read_image_rgba8(ctx, px, sizeof px) == HD_SUCCESS);
        for (i = 0; i < 48 * 48; ++i)
            for (c = 0; c < 3; ++c) {
                uint8_t want = srgb8_ref(img[4 * i + c] * e);
                checked += img[4 * i + c] * e > 0.0f && img[4 * i + c] * e < 1.0f;
                if (px[4 * i + c] != want && bad++ < 5)
                    fprintf(stderr, "  exposure %g, pixel %d channel %d: %d, want %d (value %.9g)\n", (double)e, i, c,
                            px[4 * i + c], want, (double)(img[4 * i + c] * e));
            }
    }
    CHECK(bad == 0);
    CHECK(checked > 100000); /* the sweep reached the encoding's curve, not only 0 and 255 */
    hd_destroy(ctx);
}

const hd_test_case hd_tests_core[] = {
    {"core_rgba8_encoding", test_rgba8_encoding},
    {"core_create_defaults", test_create_defaults},
    {"core_params_preset", test_params_preset},
    {"core_determinism_threads_seed", test_determinism},
    {"core_camera_keeps_illumination", test_camera_keeps_illumination},
    {"core_invalidation", test_invalidation},
    {"core_memory_independent_of_lights", test_memory_independent_of_lights},
    {"core_illumination_downsample", test_illumination_downsample},
    {"core_rgb_scattering", test_rgb_scattering},
    {"core_bad_desc", test_bad_desc},
    {"core_bad_calls", test_bad_calls},
};
const int hd_tests_core_count = sizeof hd_tests_core / sizeof hd_tests_core[0];
