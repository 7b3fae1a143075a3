/* test_living.c - volumes and settings that change while rendering, on the CPU backend: a read
   of the image before any frame exists says so (HD_ERROR_NO_FRAME); hd_update_volume keeps the
   core's volume state equal to a fresh context's, keeps E and phi as the warm start with E's mean
   re-weighted, converges to the fresh context's light, changes nothing for equal voxels, and
   refuses bad updates with the context unchanged. */
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

/* ---- hd_update_volume ------------------------------------------------------------------------ */
#include "hdt_volume_state.h"

static float vox2[N * N * N];
static uint8_t vox8[N * N * N], vox8b[N * N * N];

/* The new volume: inside the box [B0, B1) the blob moved 3 voxels along x, outside as before. */
enum { BX0 = 6, BX1 = 23, BY0 = 3, BY1 = 21, BZ0 = 2, BZ1 = 22 };
static void make_moved(void)
{
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                int in = x >= BX0 && x < BX1 && y >= BY0 && y < BY1 && z >= BZ0 && z < BZ1;
                size_t i = ((size_t)z * N + y) * N + x;
                vox2[i] = in ? blob(x, y, z, 14.5f) : vox[i];
                vox8[i] = (uint8_t)(vox[i] * 255.0f + 0.5f);
                vox8b[i] = (uint8_t)(vox2[i] * 255.0f + 0.5f);
            }
}

/* An update of the box [B0, B1) of a whole volume in memory (pitches of the whole volume). */
static hd_volume_update box_update(hd_voxel_type type, const void *whole)
{
    hd_volume_update u = HD_VOLUME_UPDATE_INIT;
    size_t es = type == HD_VOXEL_U8 ? 1 : 4;
    u.type = type;
    u.dims[0] = u.dims[1] = u.dims[2] = N;
    u.offset[0] = BX0; u.offset[1] = BY0; u.offset[2] = BZ0;
    u.size[0] = BX1 - BX0; u.size[1] = BY1 - BY0; u.size[2] = BZ1 - BZ0;
    u.row_pitch = N * es;
    u.slice_pitch = (size_t)N * N * es;
    u.data = (const char *)whole + (((size_t)BZ0 * N + BY0) * N + BX0) * es;
    return u;
}

/* Renders until the light has converged and the image is final (at most `most` calls); the
   number of calls, or -1. */
static int render_to_rest(hd_context c, int most)
{
    hd_stats st;
    int i;
    for (i = 1; i <= most; ++i) {
        uint64_t frames;
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS);
        frames = st.frames;
        CHECK(hd_render(c) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS);
        if (st.light_converged && st.frames == frames && frames > 0) return i;
    }
    return -1;
}

/* The core's volume state of a and b (after a read in a bracket, so both are prepared). */
static int same_volume_state(hd_context a, hd_context b)
{
    static float e[N * N * N];
    hdt_volume_state s, t;
    int ok;
    CHECK(hd_read_illumination(a, HD_ILLUMINATION_DIRECT, e, N * N * N) == HD_SUCCESS);
    CHECK(hd_read_illumination(b, HD_ILLUMINATION_DIRECT, e, N * N * N) == HD_SUCCESS);
    if (!hdt_volume_state_get(a, &s) || !hdt_volume_state_get(b, &t)) return 0;
    ok = s.nvox == t.nvox && s.ncell == t.ncell && s.gvox == t.gvox && s.max_sigma == t.max_sigma && s.dl_count == t.dl_count &&
         s.vol_bytes == t.vol_bytes && memcmp(s.vol, t.vol, s.vol_bytes) == 0 && memcmp(s.cell_range, t.cell_range, s.ncell * 2 * sizeof(float)) == 0 &&
         memcmp(s.majorant, t.majorant, s.ncell * sizeof(float)) == 0 && s.bits && t.bits &&
         memcmp(s.bits, t.bits, (s.gvox + 7) / 8) == 0 && !s.dl_idx == !t.dl_idx && !s.dl_brick == !t.dl_brick &&
         (!s.dl_idx || memcmp(s.dl_idx, t.dl_idx, s.dl_count * sizeof(uint32_t)) == 0) &&
         (!s.dl_brick || (s.dl_bricks == t.dl_bricks && memcmp(s.dl_brick, t.dl_brick, (s.dl_bricks + 1) * sizeof(uint32_t)) == 0));
    CHECK_MSG(ok, "vol %d, cell ranges %d, majorants %d, max_sigma %g/%g, mask %d, list %zu/%zu",
              s.vol_bytes == t.vol_bytes && memcmp(s.vol, t.vol, s.vol_bytes) == 0, memcmp(s.cell_range, t.cell_range, s.ncell * 2 * sizeof(float)) == 0,
              memcmp(s.majorant, t.majorant, s.ncell * sizeof(float)) == 0, (double)s.max_sigma, (double)t.max_sigma,
              s.bits && t.bits && memcmp(s.bits, t.bits, (s.gvox + 7) / 8) == 0, s.dl_count, t.dl_count);
    return ok;
}

static double rel_l2(const float *a, const float *b, size_t n)
{
    double d = 0.0, r = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        d += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
        r += (double)b[i] * b[i];
    }
    return r > 0.0 ? sqrt(d / r) : sqrt(d);
}

/* Equal voxels (the whole volume, and a box of it through pitches) change nothing: the light stays
   converged, the finished image is not touched, nothing is redone. */
static void test_update_same(void)
{
    hd_desc d;
    hd_test_log log;
    hd_context c;
    hd_stats a, b;
    hd_volume_update u = HD_VOLUME_UPDATE_INIT;
    static float img0[W * W * 4], img1[W * W * 4];
    make_desc(&d, &log);
    make_moved();
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(render_to_rest(c, 300) > 0);
    CHECK(hd_read_image_f32(c, img0, W * W * 4) == HD_SUCCESS);
    CHECK(hd_get_stats(c, &a) == HD_SUCCESS && a.light_converged);
    u.type = HD_VOXEL_F32;
    u.dims[0] = u.dims[1] = u.dims[2] = N;
    u.data = vox;
    CHECK(hd_update_volume(c, &u) == HD_SUCCESS);
    u = box_update(HD_VOXEL_F32, vox);
    CHECK(hd_update_volume(c, &u) == HD_SUCCESS);
    CHECK(hd_get_stats(c, &b) == HD_SUCCESS);
    CHECK_MSG(b.light_converged && b.iterations == a.iterations && b.frames == a.frames && b.light_error == a.light_error,
              "converged %d, iterations %llu -> %llu, frames %llu -> %llu", b.light_converged, (unsigned long long)a.iterations,
              (unsigned long long)b.iterations, (unsigned long long)a.frames, (unsigned long long)b.frames);
    CHECK(hd_render(c) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, img1, W * W * 4) == HD_SUCCESS);
    CHECK(memcmp(img0, img1, sizeof img0) == 0);
    CHECK(hd_get_stats(c, &b) == HD_SUCCESS && b.iterations == a.iterations && b.frames == a.frames && log.errors == 0);
    hd_destroy(c);
}

/* A box update (F32, and U8 through the same value map): the core's volume, majorants and
   direct-light mask equal a fresh context's with the new volume; E is kept as it was (warm
   start) and its mean holds at most light_window samples; the light's convergence estimate
   restarts and converges again; after as many iterations as the fresh context, the image agrees
   with the fresh one's within the estimator's noise. hd_reset then starts from zero. */
static void update_vs_fresh(hd_voxel_type type)
{
    hd_desc d, d2;
    hd_test_log log;
    hd_context c, f;
    hd_stats st;
    hd_volume_update u;
    hdt_volume_state vs;
    size_t gn;
    static float e0[N * N * N], e1[N * N * N], p0[N * N * N], p1[N * N * N], img0[W * W * 4], img1[W * W * 4];
    int renders, k;
    size_t i;
    double l2_img, l2_e, l2_phi;
    make_desc(&d, &log);
    make_moved();
    if (type == HD_VOXEL_U8) d.volume.data = vox8;
    d.volume.type = type;
    d.params.light_window = 8;
    d2 = d;
    d2.volume.data = type == HD_VOXEL_U8 ? (const void *)vox8b : (const void *)vox2;
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_create(&d2, &f) == HD_SUCCESS);
    CHECK(render_to_rest(c, 300) > 0);
    CHECK(hd_get_stats(c, &st) == HD_SUCCESS);
    gn = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2];
    CHECK(gn <= (size_t)N * N * N);
    CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e0, gn) == HD_SUCCESS);
    u = box_update(type, type == HD_VOXEL_U8 ? (const void *)vox8b : (const void *)vox2);
    CHECK(hd_update_volume(c, &u) == HD_SUCCESS);
    CHECK(hd_get_stats(c, &st) == HD_SUCCESS && !st.light_converged && st.light_error == 1.0);
    CHECK(same_volume_state(c, f));
    /* the warm start: E as it was, its mean capped at light_window samples */
    CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e1, gn) == HD_SUCCESS);
    CHECK(memcmp(e0, e1, gn * sizeof(float)) == 0);
    CHECK(hdt_volume_state_get(c, &vs) && vs.dl_n == 8);
    CHECK(hd_iterate(c, 1) == HD_SUCCESS && hdt_volume_state_get(c, &vs) && vs.dl_n == 9);
    CHECK(hd_get_stats(c, &st) == HD_SUCCESS && !st.light_converged);
    renders = render_to_rest(c, 300);
    CHECK_MSG(renders > 1, "converged again after %d renders", renders);
    /* both on to the same number of samples: the old light weighs 8 / 400 of E */
    for (k = 0; k < 2; ++k) {
        hd_context h = k ? f : c;
        hdt_volume_state hs;
        hd_desc q;
        CHECK(hd_query_desc(h, &q) == HD_SUCCESS);
        q.params.frame_window = 256; /* the images compared: means of 256 frames */
        CHECK(hd_set_params(h, &q.params) == HD_SUCCESS);
        CHECK(hdt_volume_state_get(h, &hs));
        CHECK(hd_iterate(h, (int)(400 - hs.dl_n)) == HD_SUCCESS);
        CHECK(hd_read_image_f32(h, k ? img1 : img0, W * W * 4) == HD_SUCCESS);
        CHECK(hd_read_illumination(h, HD_ILLUMINATION_DIRECT, k ? e1 : e0, gn) == HD_SUCCESS);
        CHECK(hd_read_illumination(h, HD_ILLUMINATION_SCATTERED, k ? p1 : p0, gn) == HD_SUCCESS);
    }
    /* E where it is read (the fresh context's mask; elsewhere the updated one keeps what it had) */
    CHECK(hdt_volume_state_get(f, &vs));
    for (i = 0; i < gn; ++i)
        if (!(vs.bits[i >> 3] >> (i & 7) & 1u)) e0[i] = e1[i] = 0.0f;
    l2_img = rel_l2(img0, img1, W * W * 4);
    l2_e = rel_l2(e0, e1, gn);
    l2_phi = rel_l2(p0, p1, gn);
    fprintf(stderr, "  %s box update, 400 samples: rel L2 against the fresh context: image %.2e, E %.2e, phi %.2e; converged again after %d renders\n",
            type == HD_VOXEL_U8 ? "U8" : "F32", l2_img, l2_e, l2_phi, renders);
    CHECK_MSG(l2_img < 1e-2 && l2_e < 2.5e-2 && l2_phi < 3e-2, "image %.3e, E %.3e, phi %.3e", l2_img, l2_e, l2_phi);
    /* a clean restart */
    CHECK(hd_reset(c) == HD_SUCCESS);
    CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e1, gn) == HD_SUCCESS);
    for (k = 0; k < (int)gn && e1[k] == 0.0f; ++k) {}
    CHECK(k == (int)gn && hdt_volume_state_get(c, &vs) && vs.dl_n == 0);
    CHECK(hd_get_stats(c, &st) == HD_SUCCESS && st.iterations == 0 && !st.light_converged);
    CHECK(log.errors == 0);
    hd_destroy(c);
    hd_destroy(f);
}
static void test_update_box_f32(void) { update_vs_fresh(HD_VOXEL_F32); }
static void test_update_box_u8(void) { update_vs_fresh(HD_VOXEL_U8); }

/* Each bad update its own result and one log line, the context unchanged: its voxels, its
   converged light and its finished image. The path tracers restart on a good one. */
static void test_update_bad(void)
{
    hd_desc d;
    hd_test_log log;
    hd_context c;
    hd_stats a, b;
    hd_volume_update u, good;
    hdt_volume_state vs;
    static float saved[N * N * N], bad[N * N * N];
    int errors = 0, i;
    make_desc(&d, &log);
    make_moved();
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(render_to_rest(c, 300) > 0);
    CHECK(hd_get_stats(c, &a) == HD_SUCCESS && a.light_converged);
    CHECK(hdt_volume_state_get(c, &vs));
    CHECK(vs.vol_bytes == sizeof saved);
    memcpy(saved, vs.vol, sizeof saved);
    good = box_update(HD_VOXEL_F32, vox2);
#define BAD(stmt, code) do { u = good; stmt; \
        CHECK_MSG(hd_update_volume(c, &u) == (code) && log.errors == ++errors && log.last_code == (code), "%s: %s", #stmt, log.last); \
    } while (0)
    CHECK(hd_update_volume(c, NULL) == HD_ERROR_NULL_POINTER && log.errors == ++errors);
    BAD(u.data = NULL, HD_ERROR_NULL_POINTER);
    BAD(u.type = HD_VOXEL_U16, HD_ERROR_VOLUME_MISMATCH);
    BAD(u.type = (hd_voxel_type)77, HD_ERROR_VOLUME_MISMATCH);
    BAD(u.dims[2] = N + 1, HD_ERROR_VOLUME_MISMATCH);
    BAD(u.dims[0] = 0, HD_ERROR_VOLUME_MISMATCH);
    BAD(u.offset[0] = -1, HD_ERROR_BOX_OUTSIDE_VOLUME);
    BAD(u.offset[1] = N - 2, HD_ERROR_BOX_OUTSIDE_VOLUME);
    BAD(u.size[2] = N, HD_ERROR_BOX_OUTSIDE_VOLUME);
    BAD(u.size[0] = 0, HD_ERROR_BOX_OUTSIDE_VOLUME);
    BAD(u.size[1] = -3, HD_ERROR_BOX_OUTSIDE_VOLUME);
    BAD(u.size[0] = u.size[1] = u.size[2] = 0, HD_ERROR_BOX_OUTSIDE_VOLUME); /* whole volume at an offset */
    BAD(u.offset[2] = 0x7fffffff, HD_ERROR_BOX_OUTSIDE_VOLUME);
    BAD(u.row_pitch = 4, HD_ERROR_INVALID_PARAMETER);
    BAD(u.slice_pitch = N * 4, HD_ERROR_INVALID_PARAMETER);
    memcpy(bad, vox2, sizeof bad);
    bad[((size_t)(BZ1 - 1) * N + BY1 - 1) * N + BX1 - 1] = NAN; /* the box's last voxel */
    BAD(u.data = bad + ((size_t)BZ0 * N + BY0) * N + BX0, HD_ERROR_INVALID_VOXELS);
    bad[((size_t)(BZ1 - 1) * N + BY1 - 1) * N + BX1 - 1] = vox2[((size_t)(BZ1 - 1) * N + BY1 - 1) * N + BX1 - 1];
    bad[((size_t)BZ0 * N + BY0) * N + BX0 + 3] = -INFINITY;
    BAD(u.data = bad + ((size_t)BZ0 * N + BY0) * N + BX0, HD_ERROR_INVALID_VOXELS);
#undef BAD
    CHECK(strstr(log.last, "inf") != NULL);
    CHECK(hdt_volume_state_get(c, &vs) && memcmp(saved, vs.vol, sizeof saved) == 0);
    CHECK(hd_get_stats(c, &b) == HD_SUCCESS && b.light_converged && b.iterations == a.iterations && b.frames == a.frames);
    CHECK(hd_render(c) == HD_SUCCESS && hd_get_stats(c, &b) == HD_SUCCESS && b.iterations == a.iterations && b.frames == a.frames);
    /* PT_MS: an update restarts its mean */
    d.params.method = HD_METHOD_PT_MS;
    CHECK(hd_set_params(c, &d.params) == HD_SUCCESS);
    CHECK(hd_iterate(c, 3) == HD_SUCCESS);
    CHECK(hd_update_volume(c, &good) == HD_SUCCESS);
    CHECK(hd_iterate(c, 1) == HD_SUCCESS && hd_get_stats(c, &b) == HD_SUCCESS && b.iterations == 1 && b.frames == 1);
    for (i = 0; i < 3; ++i) CHECK(hdt_volume_state_get(c, &vs) && ((const float *)vs.vol)[((size_t)(BZ0 + i) * N + BY0) * N + BX0] == vox2[((size_t)(BZ0 + i) * N + BY0) * N + BX0]);
    CHECK(log.errors == errors);
    hd_destroy(c);
}

/* ---- setters that keep what stays valid ------------------------------------------------------- */
/* A TF change of colour only (the same alphas): with grey scattering no light work at all (the
   light stays converged, no iteration runs, E and phi bit for bit), only the image restarts, in
   the new colour; the same TF again changes nothing; with RGB scattering phi is the warm start
   (E bit for bit). An alpha change keeps E and phi as the warm start, E's mean capped. */
static void test_tf_warm(void)
{
    hd_desc d;
    hd_test_log log;
    hd_context c;
    hd_stats a, b;
    hd_transfer_function tf;
    hdt_volume_state vs;
    static float e0[N * N * N], p0[N * N * N], e1[N * N * N], p1[N * N * N], img0[W * W * 4], img1[W * W * 4];
    float red[12], thin[12];
    int i, rgb;
    for (rgb = 0; rgb < 2; ++rgb) {
        make_desc(&d, &log);
        d.params.rgb_scattering = rgb;
        CHECK(hd_create(&d, &c) == HD_SUCCESS);
        CHECK(render_to_rest(c, 300) > 0);
        CHECK(hd_get_stats(c, &a) == HD_SUCCESS && a.light_converged);
        CHECK(hd_read_image_f32(c, img0, W * W * 4) == HD_SUCCESS);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e0, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, p0, (size_t)N * N * N) == HD_SUCCESS);
        /* the same TF: nothing */
        tf.rgba = tf3;
        tf.count = 3;
        CHECK(hd_set_transfer_function(c, &tf) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &b) == HD_SUCCESS && b.light_converged && b.frames == a.frames && b.iterations == a.iterations);
        /* colour only */
        memcpy(red, tf3, sizeof red);
        red[5] = 0.1f; red[6] = 0.1f; red[8] = 1.0f; red[9] = 0.2f;
        tf.rgba = red;
        CHECK(hd_set_transfer_function(c, &tf) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &b) == HD_SUCCESS && b.light_converged == !rgb && b.frames == 0 && b.iterations == a.iterations);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e1, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, p1, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(memcmp(e0, e1, sizeof e0) == 0 && memcmp(p0, p1, sizeof p0) == 0);
        for (i = 0; i < 4; ++i) CHECK(hd_render(c) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &b) == HD_SUCCESS);
        if (!rgb)
            CHECK_MSG(b.iterations == a.iterations && b.seconds_direct == a.seconds_direct && b.seconds_diffusion == a.seconds_diffusion &&
                          b.light_converged && b.frames == 4,
                      "colour only: iterations %llu -> %llu, frames %llu", (unsigned long long)a.iterations,
                      (unsigned long long)b.iterations, (unsigned long long)b.frames);
        else
            CHECK(b.iterations > a.iterations); /* phi re-solved */
        CHECK(hd_read_image_f32(c, img1, W * W * 4) == HD_SUCCESS);
        CHECK(rel_l2(img1, img0, W * W * 4) > 0.05);
        /* alpha: E and phi the warm start */
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e0, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, p0, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &a) == HD_SUCCESS);
        memcpy(thin, red, sizeof thin);
        thin[7] = 0.15f;
        tf.rgba = thin;
        CHECK(hd_set_transfer_function(c, &tf) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &b) == HD_SUCCESS && !b.light_converged && b.iterations == a.iterations && b.frames == 0);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e1, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, p1, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(memcmp(e0, e1, sizeof e0) == 0 && memcmp(p0, p1, sizeof p0) == 0);
        CHECK(hdt_volume_state_get(c, &vs) && vs.dl_n == 8);
        CHECK(render_to_rest(c, 300) > 0);
        CHECK(log.errors == 0);
        hd_destroy(c);
    }
}

/* render_budget splits a light iteration over hd_render calls: with a budget far below one
   iteration's time each call runs one piece (a range of the direct light's list or one sweep),
   hd_stats.light_progress rises within the iteration and iterations counts complete ones only;
   a camera move between the pieces keeps the iteration open. After the same number of complete
   iterations E, phi and light_error are bit for bit those of whole iterations (hd_refine), for
   HD with each solver and for CD. */
static void budget_split_case(const char *name, hd_method method, hd_solver solver)
{
    enum { ITER = 3 };
    hd_desc d;
    hd_context whole, split;
    hd_stats s, t;
    hd_camera cam;
    size_t n = (size_t)N * N * N;
    float *e0 = (float *)malloc(n * sizeof(float)), *p0 = (float *)malloc(n * sizeof(float));
    float *e1 = (float *)malloc(n * sizeof(float)), *p1 = (float *)malloc(n * sizeof(float));
    int calls = 0, parts = 0, direct = 0, rising = 1;
    double prev = 0.0;
    make_desc(&d, NULL);
    d.params.illumination_downsample = 1;
    d.params.method = method;
    d.params.solver = solver;
    d.params.light_tolerance = 1e-6f; /* nothing converges within ITER iterations */
    CHECK(hd_create(&d, &whole) == HD_SUCCESS);
    d.params.render_budget = 1e-6f;
    CHECK(hd_create(&d, &split) == HD_SUCCESS);
    CHECK(hd_refine(whole, ITER) == HD_SUCCESS);
    cam = d.camera;
    for (;;) {
        CHECK(hd_render(split) == HD_SUCCESS);
        CHECK(hd_get_stats(split, &s) == HD_SUCCESS);
        ++calls;
        if (s.light_progress > 0.0) {
            ++parts;
            direct += s.light_progress < 0.5; /* the direct stage in progress: its list split */
            if (s.light_progress < 1.0 && s.light_progress > prev) prev = s.light_progress;
            else rising = 0;
        } else {
            prev = 0.0;
        }
        /* a camera move restarts the image, not the light iteration in progress */
        cam.eye[0] += 0.01f;
        CHECK(hd_set_camera(split, &cam) == HD_SUCCESS);
        if ((s.iterations >= ITER && s.light_progress == 0.0) || calls > 10000) break;
    }
    CHECK_MSG(s.iterations == ITER && parts >= 2 * ITER && (direct >= ITER || method == HD_METHOD_CD) && rising,
              "%s: %llu iterations in %d calls, %d in between (%d in the direct stage), rising %d", name,
              (unsigned long long)s.iterations, calls, parts, direct, rising);
    CHECK(hd_get_stats(whole, &t) == HD_SUCCESS && t.iterations == ITER && t.light_progress == 0.0);
    CHECK_MSG(s.light_error == t.light_error, "%s: light_error %g split, %g whole", name, s.light_error, t.light_error);
    CHECK(hd_read_illumination(whole, HD_ILLUMINATION_DIRECT, e0, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(whole, HD_ILLUMINATION_SCATTERED, p0, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(split, HD_ILLUMINATION_DIRECT, e1, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(split, HD_ILLUMINATION_SCATTERED, p1, n) == HD_SUCCESS);
    CHECK_MSG(memcmp(e0, e1, n * sizeof(float)) == 0 && memcmp(p0, p1, n * sizeof(float)) == 0, "%s: split E, phi differ", name);
    /* hd_refine finishes a split iteration first: one more render opens one, a refine closes it */
    CHECK(hd_render(split) == HD_SUCCESS && hd_get_stats(split, &s) == HD_SUCCESS && s.light_progress > 0.0);
    CHECK(hd_refine(split, 1) == HD_SUCCESS && hd_refine(whole, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(split, &s) == HD_SUCCESS && s.iterations == ITER + 1 && s.light_progress == 0.0);
    CHECK(hd_read_illumination(whole, HD_ILLUMINATION_SCATTERED, p0, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(split, HD_ILLUMINATION_SCATTERED, p1, n) == HD_SUCCESS);
    CHECK_MSG(memcmp(p0, p1, n * sizeof(float)) == 0, "%s: phi after a finished split iteration differs", name);
    hd_destroy(whole);
    hd_destroy(split);
    free(e0); free(p0); free(e1); free(p1);
}

static void test_budget_split(void)
{
    budget_split_case("HD red-black", HD_METHOD_HD, HD_SOLVER_RED_BLACK);
    budget_split_case("HD Jacobi", HD_METHOD_HD, HD_SOLVER_JACOBI);
    budget_split_case("HD multigrid", HD_METHOD_HD, HD_SOLVER_MULTIGRID);
    budget_split_case("CD", HD_METHOD_CD, HD_SOLVER_RED_BLACK);
}

/* A change of the light's inputs (a warm TF change) ends a split iteration where it is; the
   next call starts the next one, and the light goes on converging. */
static void test_budget_split_setter(void)
{
    hd_desc d;
    hd_context ctx;
    hd_stats s;
    hd_params p;
    int i;
    make_desc(&d, NULL);
    d.params.illumination_downsample = 1;
    d.params.render_budget = 1e-6f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_render(ctx) == HD_SUCCESS && hd_get_stats(ctx, &s) == HD_SUCCESS && s.light_progress > 0.0 && s.iterations == 0);
    CHECK(hd_query_desc(ctx, &d) == HD_SUCCESS);
    p = d.params;
    p.extinction = 30.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &s) == HD_SUCCESS && s.light_progress == 0.0);
    for (i = 0; i < 2000 && !s.light_converged; ++i) CHECK(hd_render(ctx) == HD_SUCCESS && hd_get_stats(ctx, &s) == HD_SUCCESS);
    CHECK_MSG(s.light_converged && s.light_progress == 0.0, "after the change: converged %d in %d calls", s.light_converged, i);
    hd_destroy(ctx);
}


/* The direct light's mask equals its definition (hdt_direct_mask_check: dual cell by dual cell)
   on a 21x17x19 volume of plateaus, exact zeros and noise, F32 and U8, for TFs whose zero-alpha
   entries come singly, in runs, or not at all, with a crop box and a coarser grid; and again
   after a box update and a whole-volume update. */
int hdt_direct_mask_check(hd_context h, size_t *tracked);
enum { MX = 21, MY = 17, MZ = 19 };
static float mask_value(int x, int y, int z, int t)
{
    float dx = x - 9.0f - 2.0f * t, dy = y - 8.0f, dz = z - 9.5f, r = sqrtf(dx * dx + dy * dy + dz * dz);
    uint32_t h = (uint32_t)(x * 73856093 ^ y * 19349663 ^ z * 83492791 ^ t * 2654435761u);
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    if (r > 8.0f) return 0.0f;                     /* exact zeros */
    if (r < 3.0f) return 0.6f;                     /* a plateau */
    if (x > 14) return (float)(h & 255) / 255.0f;  /* noise */
    return 0.5f * (8.0f - r) / 5.0f + 0.01f * (float)(h & 3);
}
static void mask_case(const char *name, hd_voxel_type type, const float *tf, int count, int down, int crop)
{
    static float f[MX * MY * MZ];
    static uint8_t b[MX * MY * MZ];
    hd_desc d;
    hd_context c;
    hd_volume_update u = HD_VOLUME_UPDATE_INIT;
    size_t tracked = 0;
    int x, y, z, t;
    static float e[4 * MX * MY * MZ];
    for (t = 0; t < 3; ++t) {
        for (z = 0; z < MZ; ++z)
            for (y = 0; y < MY; ++y)
                for (x = 0; x < MX; ++x) {
                    size_t i = ((size_t)z * MY + y) * MX + x;
                    f[i] = mask_value(x, y, z, t);
                    b[i] = (uint8_t)(f[i] * 255.0f + 0.5f);
                }
        if (t == 0) {
            make_desc(&d, NULL);
            d.volume.type = type;
            d.volume.dims[0] = MX; d.volume.dims[1] = MY; d.volume.dims[2] = MZ;
            d.volume.data = type == HD_VOXEL_U8 ? (const void *)b : (const void *)f;
            d.transfer_function.rgba = tf;
            d.transfer_function.count = count;
            d.params.illumination_downsample = down;
            if (crop) {
                d.params.crop_min[0] = 0.2f; d.params.crop_min[1] = 0.0f; d.params.crop_min[2] = 0.31f;
                d.params.crop_max[0] = 0.77f; d.params.crop_max[1] = 0.6f; d.params.crop_max[2] = 1.0f;
            }
            CHECK(hd_create(&d, &c) == HD_SUCCESS);
        } else {
            u.type = type;
            u.dims[0] = MX; u.dims[1] = MY; u.dims[2] = MZ;
            if (t == 1) { /* the box x 4..12, y 2..15, z 6..18 */
                size_t es = type == HD_VOXEL_U8 ? 1 : 4;
                u.offset[0] = 4; u.offset[1] = 2; u.offset[2] = 6;
                u.size[0] = 9; u.size[1] = 14; u.size[2] = 13;
                u.row_pitch = MX * es;
                u.slice_pitch = (size_t)MX * MY * es;
                u.data = (type == HD_VOXEL_U8 ? (const char *)b : (const char *)f) + (((size_t)6 * MY + 2) * MX + 4) * es;
            } else {
                memset(u.offset, 0, sizeof u.offset);
                memset(u.size, 0, sizeof u.size);
                u.row_pitch = u.slice_pitch = 0;
                u.data = type == HD_VOXEL_U8 ? (const void *)b : (const void *)f;
            }
            CHECK(hd_update_volume(c, &u) == HD_SUCCESS);
        }
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e, 4 * MX * MY * MZ) == HD_SUCCESS); /* prepares */
        CHECK_MSG(hdt_direct_mask_check(c, &tracked), "%s, step %d: the mask differs from its definition (%zu tracked)", name, t, tracked);
        if (t == 0) CHECK_MSG(tracked > 0, "%s: nothing tracked", name);
    }
    hd_destroy(c);
}
static void test_mask_definition(void)
{
    static const float single[12] = {0, 0, 0, 0, 1, 1, 1, 0.4f, 1, 1, 1, 1};
    static const float runs[32] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 0.5f, 1, 1, 1, 0.2f, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1};
    static const float none[8] = {1, 1, 1, 0.3f, 1, 1, 1, 1};
    mask_case("single zero, F32", HD_VOXEL_F32, single, 3, 1, 0);
    mask_case("zero runs, F32", HD_VOXEL_F32, runs, 8, 1, 0);
    mask_case("zero runs, U8, crop", HD_VOXEL_U8, runs, 8, 1, 1);
    mask_case("zero runs, F32, grid / 2", HD_VOXEL_F32, runs, 8, 2, 0);
    mask_case("no zero, F32, crop, grid / 2", HD_VOXEL_F32, none, 2, 2, 1);
    mask_case("single zero, U8, grid / 2", HD_VOXEL_U8, single, 3, 2, 1);
}

const hd_test_case hd_tests_living[] = {
    {"living_mask_definition", test_mask_definition},
    {"living_budget_split", test_budget_split},
    {"living_budget_split_setter", test_budget_split_setter},
    {"living_tf_warm", test_tf_warm},
    {"living_no_frame", test_no_frame},
    {"living_update_same", test_update_same},
    {"living_update_box_f32", test_update_box_f32},
    {"living_update_box_u8", test_update_box_u8},
    {"living_update_bad", test_update_bad},
};
const int hd_tests_living_count = sizeof hd_tests_living / sizeof hd_tests_living[0];
