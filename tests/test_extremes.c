/* test_extremes.c - finite extremes (FLT_MAX, 3e38, 1e+-30, FLT_MIN, denormals, -0 and the
   documented bounds with the float next to them, inside and out) of every float the image
   depends on: hd_params (each float row of src/hd_params.h's table, test_float_coverage),
   hd_camera, hd_light, the volume's spacing and value range. Each goes through hd_create and
   through its setter. A row wants either its specific rejection code (one logged error, no
   handle, nothing hd_query_desc or hd_get_stats show changed) or a context on which every call
   succeeds with finite results: iterations, refinement and frames of every method with the image
   read back finite after each, every read-back. Rows with a visible consequence check it as
   well: a value range maps the voxels as the same volume normalised in double precision does,
   the RGBA8 image is the sRGB encoding of radiance * exposure, a ray that misses the volume shows
   the background, hd_render stays within its budget. Each row runs in a child process under an
   alarm, so a hang fails that row and the rest still run.
   Then NaN and Inf in every float field, every enum out of range (HD_ERROR_INVALID_ENUM), a
   destroyed context's logger, and a PT_MS setting that must restart the running mean. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <float.h>
#include <limits.h>
#include <signal.h>
#include <stdint.h>
#include <time.h>
#include <unistd.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <errno.h>

/* A 6^3 blob (dense core, lighter shell, empty corners), an 8x8 image: every row is milliseconds. */
#define XN 6
#define XW 8
#define XT_VOX (XN * XN * XN)
#define XT_ALARM 60       /* seconds a row may take in its child before it counts as hung */
#define XT_CALL_BOUND 5.0 /* seconds one hd_render call may take (a few: the sanitizer builds) */
#define XT_BOUNDED_ALARM 50 /* the same for a row of xt_check_bounded's three calls (budget <= 10 s) */

static uint8_t xt_u8[XT_VOX];
static uint16_t xt_u16[XT_VOX];
static float xt_f32[XT_VOX];
static float xt_tf_buf[16];
static hd_light xt_light_buf[3];
static hd_test_log xt_log;

static float xt_nan(void) { volatile float z = 0.0f; return z / z; }
static float xt_inf(void) { volatile float z = 0.0f; return 1.0f / z; }
static float xt_denorm(void) { volatile float f = FLT_MIN; return f / 4096.0f; }
static float xt_up(float v) { return nextafterf(v, FLT_MAX); }   /* the next float above v */
static float xt_down(float v) { return nextafterf(v, -FLT_MAX); } /* the next float below v */
static float xt_neg0(void) { volatile float z = 0.0f; return -z; }

static double xt_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* 2 in the core, 1 in the shell, 0 outside: the voxel classes the value-range rows map. */
static int xt_class(int x, int y, int z)
{
    float dx = (float)x - 2.5f, dy = (float)y - 2.5f, dz = (float)z - 2.5f;
    float r = sqrtf(dx * dx + dy * dy + dz * dz);
    return r < 1.5f ? 2 : r < 2.6f ? 1 : 0;
}

/* The base desc: U8 blob, 3-entry TF, one directional light, 8x8 camera, the paper's grid. */
static void xt_base(hd_desc *d)
{
    static const float tf[12] = {0, 0, 0, 0, 1.0f, 0.6f, 0.4f, 0.5f, 1, 1, 1, 1};
    int x, y, z;
    for (z = 0; z < XN; ++z)
        for (y = 0; y < XN; ++y)
            for (x = 0; x < XN; ++x) {
                int c = xt_class(x, y, z), i = (z * XN + y) * XN + x;
                xt_u8[i] = (uint8_t)(c == 2 ? 255 : c == 1 ? 128 : 0);
                xt_u16[i] = (uint16_t)(c == 2 ? 65535 : c == 1 ? 32768 : 0);
                xt_f32[i] = c == 2 ? 1.0f : c == 1 ? 0.5f : 0.0f;
            }
    memset(d, 0, sizeof *d);
    memcpy(xt_tf_buf, tf, sizeof tf);
    memset(xt_light_buf, 0, sizeof xt_light_buf);
    xt_light_buf[0].direction[0] = 0.3f;
    xt_light_buf[0].direction[1] = -0.4f;
    xt_light_buf[0].direction[2] = -1.0f;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = XN;
    d->volume.data = xt_u8;
    d->transfer_function.rgba = xt_tf_buf;
    d->transfer_function.count = 3;
    d->lights = xt_light_buf;
    d->light_count = 1;
    d->camera.width = d->camera.height = XW;
    d->params.extinction = 40.0f;
    d->params.illumination_downsample = 1;
    d->threads = 1;
    d->logger = hd_test_logger(&xt_log);
}

/* F32 voxels for value range {lo, hi}: the core at hi, the shell halfway (in double), the rest at
   lo; U16 and U8 keep their pattern. */
static void xt_range(hd_desc *d, hd_voxel_type type, float lo, float hi)
{
    int i;
    float mid = (float)(0.5 * (double)lo + 0.5 * (double)hi);
    d->volume.type = type;
    d->volume.data = type == HD_VOXEL_F32 ? (const void *)xt_f32 : type == HD_VOXEL_U16 ? (const void *)xt_u16 : (const void *)xt_u8;
    d->volume.value_range[0] = lo;
    d->volume.value_range[1] = hi;
    if (type == HD_VOXEL_F32)
        for (i = 0; i < XT_VOX; ++i) xt_f32[i] = xt_f32[i] == 1.0f ? hi : xt_f32[i] == 0.5f ? mid : lo;
}

/* ---- what a context that accepted its input must do ----------------------------------------- */
static int xt_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

static int xt_image_finite(hd_context c)
{
    float img[XW * XW * 4];
    hd_desc q;
    size_t n;
    if (hd_query_desc(c, &q) != HD_SUCCESS) return 0;
    n = (size_t)q.camera.width * (size_t)q.camera.height * 4;
    if (n > sizeof img / sizeof img[0]) return 0;
    return hd_read_image_f32(c, img, n) == HD_SUCCESS && xt_finite(img, n);
}

static const hd_method xt_methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};

/* Each method in turn: 2 iterations, a refinement (the path tracers: HD_ERROR_UNSUPPORTED),
   `frames` frames each followed by a finite read-back (an image that turns NaN after a few frames of its
   running mean fails here), then RGBA8, both illumination volumes (finite) and finite statistics;
   no error logged but the path tracers' refinement. */
static void xt_exercise(hd_context c, const char *name, int frames)
{
    static float ill[XT_VOX * 3];
    uint8_t px[XW * XW * 4];
    hd_desc q;
    hd_params p;
    hd_stats st;
    int m, k, unsupported = 0;
    xt_log.errors = 0;
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    p = q.params;
    for (m = 0; m < 4; ++m) {
        int pt = xt_methods[m] == HD_METHOD_PT_SS || xt_methods[m] == HD_METHOD_PT_MS;
        const char *mn = hd_method_name(xt_methods[m]);
        p.method = xt_methods[m];
        CHECK_MSG(hd_set_params(c, &p) == HD_SUCCESS, "%s: %s: set_params", name, mn);
        CHECK_MSG(hd_iterate(c, 2) == HD_SUCCESS, "%s: %s: iterate", name, mn);
        CHECK_MSG(xt_image_finite(c), "%s: %s: image after hd_iterate not finite", name, mn);
        CHECK_MSG(hd_refine(c, 1) == (pt ? HD_ERROR_UNSUPPORTED : HD_SUCCESS), "%s: %s: refine", name, mn);
        unsupported += pt;
        for (k = 0; k < frames; ++k) {
            CHECK_MSG(hd_render(c) == HD_SUCCESS, "%s: %s: render %d", name, mn, k + 1);
            CHECK_MSG(xt_image_finite(c), "%s: %s: image after hd_render %d not finite", name, mn, k + 1);
        }
        CHECK_MSG(hd_read_image_rgba8(c, px, sizeof px) == HD_SUCCESS, "%s: %s: rgba8", name, mn);
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS);
        if (!pt) {
            size_t n = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] *
                       (size_t)st.illumination_channels;
            CHECK_MSG(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, ill, n) == HD_SUCCESS && xt_finite(ill, n),
                      "%s: %s: direct light not finite", name, mn);
            CHECK_MSG(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, ill, n) == HD_SUCCESS && xt_finite(ill, n),
                      "%s: %s: scattered light not finite", name, mn);
        }
        CHECK_MSG(isfinite(st.light_error) && st.light_error >= 0.0, "%s: %s: light_error %g", name, mn, st.light_error);
    }
    CHECK_MSG(xt_log.errors == unsupported, "%s: %d errors logged (last: %s)", name, xt_log.errors, xt_log.last);
}

/* Value ranges: the first frame's alpha against that of the same voxels normalised in double to
   F32 {0, 1}. Alpha depends only on sigma_t along rays both contexts jitter alike, so the two
   agree up to the rounding of the normalisation; a range whose width overflows a float must not
   map every voxel to one coordinate. c is fresh (created from d, nothing run). */
static void xt_check_reference(hd_context c, const hd_desc *d, const char *name)
{
    static float ref[XT_VOX];
    float a[XW * XW * 4], b[XW * XW * 4];
    double lo = d->volume.value_range[0], hi = d->volume.value_range[1];
    hd_desc r = *d;
    hd_context rc;
    int i, bad = 0;
    if (lo == 0.0 && hi == 0.0) hi = d->volume.type == HD_VOXEL_U8 ? 255.0 : d->volume.type == HD_VOXEL_U16 ? 65535.0 : 1.0;
    for (i = 0; i < XT_VOX; ++i) {
        double v = d->volume.type == HD_VOXEL_U8 ? ((const uint8_t *)d->volume.data)[i]
                   : d->volume.type == HD_VOXEL_U16 ? ((const uint16_t *)d->volume.data)[i]
                                                    : ((const float *)d->volume.data)[i];
        double t = (v - lo) / (hi - lo);
        ref[i] = t != t ? 0.0f : t < 0.0 ? 0.0f : t > 1.0 ? 1.0f : (float)t;
    }
    r.volume.type = HD_VOXEL_F32;
    r.volume.data = ref;
    r.volume.value_range[0] = 0.0f;
    r.volume.value_range[1] = 1.0f;
    if (hd_create(&r, &rc) != HD_SUCCESS) { CHECK_MSG(0, "%s: reference context", name); return; }
    CHECK(hd_iterate(c, 1) == HD_SUCCESS && hd_iterate(rc, 1) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, a, sizeof a / sizeof a[0]) == HD_SUCCESS);
    CHECK(hd_read_image_f32(rc, b, sizeof b / sizeof b[0]) == HD_SUCCESS);
    for (i = 0; i < XW * XW; ++i)
        if (!(fabsf(a[4 * i + 3] - b[4 * i + 3]) <= 0.01f)) ++bad;
    CHECK_MSG(bad == 0, "%s: %d of %d pixels' alpha differ from the normalised volume's (pixel 27: %g, want %g)",
              name, bad, XW * XW, (double)a[4 * 27 + 3], (double)b[4 * 27 + 3]);
    hd_destroy(rc);
}

/* hd__srgb8's definition, in double: the byte of linear v. */
static int xt_srgb(double v)
{
    double s;
    if (!(v > 0.0)) return 0;
    if (v >= 1.0) return 255;
    s = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (int)(s * 255.0 + 0.5);
}

/* RGBA8 is the sRGB encoding of the float image times exposure (within one code), alpha as is. */
static void xt_check_exposure(hd_context c, const char *name)
{
    float f[XW * XW * 4];
    uint8_t b[XW * XW * 4];
    hd_desc q;
    int i, bad = 0;
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(hd_iterate(c, 2) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, f, sizeof f / sizeof f[0]) == HD_SUCCESS);
    CHECK(hd_read_image_rgba8(c, b, sizeof b) == HD_SUCCESS);
    for (i = 0; i < XW * XW * 4; ++i) {
        int want = i % 4 == 3 ? (f[i] <= 0.0f ? 0 : f[i] >= 1.0f ? 255 : (int)(f[i] * 255.0f + 0.5f))
                              : xt_srgb((double)f[i] * (double)q.params.exposure);
        if (abs((int)b[i] - want) > 1) ++bad;
    }
    CHECK_MSG(bad == 0, "%s: %d RGBA8 values are not the encoding of radiance * %g", name, bad, (double)q.params.exposure);
}

/* The corner pixels' rays miss the box: after some frames they show the background, alpha 0
   (a denormal background may be flushed to zero: the CPU backend computes with FTZ/DAZ). */
static void xt_check_background(hd_context c, const char *name)
{
    float f[XW * XW * 4];
    hd_desc q;
    int k, i, corner[2] = {0, XW * XW - 1};
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    for (k = 0; k < 3; ++k) CHECK(hd_render(c) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, f, sizeof f / sizeof f[0]) == HD_SUCCESS);
    for (k = 0; k < 2; ++k) {
        const float *px = f + 4 * corner[k];
        for (i = 0; i < 3; ++i)
            CHECK_MSG(fabs((double)px[i] - (double)q.params.background[i]) <= 1e-5 * (double)q.params.background[i] + FLT_MIN,
                      "%s: corner pixel %d channel %d is %g, the background %g", name, corner[k], i, (double)px[i],
                      (double)q.params.background[i]);
        CHECK_MSG(px[3] == 0.0f, "%s: corner pixel alpha %g", name, (double)px[3]);
    }
}

/* hd_render returns within its budget and XT_CALL_BOUND seconds; the image stays finite. */
static void xt_check_bounded(hd_context c, const char *name)
{
    hd_desc q;
    int k;
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    for (k = 0; k < 3; ++k) {
        double t0 = xt_now(), dt;
        hd_result r = hd_render(c);
        dt = xt_now() - t0;
        CHECK_MSG(r == HD_SUCCESS, "%s: render %d: %s", name, k + 1, hd_result_string(r));
        CHECK_MSG(dt <= (double)q.params.render_budget + XT_CALL_BOUND, "%s: render %d took %.1f s", name, k + 1, dt);
        CHECK_MSG(xt_image_finite(c), "%s: image after render %d not finite", name, k + 1);
    }
}

/* ---- what a rejected call must leave: everything hd_query_desc and hd_get_stats show ------------ */
typedef struct xt_snap {
    hd_params p;
    hd_camera cam;
    hd_light l[HD_MAX_LIGHTS];
    float tf[64];
    int nl, ntf;
    hd_stats st;
} xt_snap;

static void xt_snap_take(hd_context c, xt_snap *s)
{
    hd_desc q;
    memset(s, 0, sizeof *s);
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(hd_get_stats(c, &s->st) == HD_SUCCESS);
    s->st.seconds_direct = s->st.seconds_diffusion = s->st.seconds_projection = 0.0;
    s->p = q.params;
    s->cam = q.camera;
    s->nl = q.light_count;
    s->ntf = q.transfer_function.count;
    if (s->nl > 0 && s->nl <= HD_MAX_LIGHTS && q.lights) memcpy(s->l, q.lights, (size_t)s->nl * sizeof *s->l);
    if (s->ntf > 0 && s->ntf <= 16 && q.transfer_function.rgba) memcpy(s->tf, q.transfer_function.rgba, (size_t)s->ntf * 16);
}

static int xt_snap_same(hd_context c, const xt_snap *before)
{
    xt_snap now;
    xt_snap_take(c, &now);
    return memcmp(&now, before, sizeof now) == 0;
}

static void xt_create_rejected(const hd_desc *d, hd_result want, const char *name);

/* ---- rows: an edit of the base desc and what it must give ------------------------------------- */
enum {
    XT_REF = 2,        /* xt_check_reference */
    XT_EXPOSURE = 4,   /* xt_check_exposure */
    XT_BACKGROUND = 8, /* xt_check_background */
    XT_BOUNDED = 16,   /* xt_check_bounded instead of xt_exercise (each frame may take the budget) */
    XT_FEW = 32        /* one frame per method: each walk costs its 2^16 collisions */
};
typedef struct xt_row {
    const char *name;
    void (*edit)(hd_desc *d);
    hd_result want; /* HD_SUCCESS: accepted, and every call works (xt_exercise) */
    int flags;
} xt_row;

static void xt_expect_rejected(hd_result r, hd_result want, const char *name, const char *how)
{
    CHECK_MSG(r == want, "%s (%s): got %s, want %s", name, how, hd_result_string(r), hd_result_string(want));
    if (r != HD_SUCCESS)
        CHECK_MSG(xt_log.errors == 1 && xt_log.last_code == r, "%s (%s): %d errors logged, last code %s", name, how,
                  xt_log.errors, hd_result_string(xt_log.last_code));
}

static void xt_accepted(hd_context c, const xt_row *row, const hd_desc *d, int fresh)
{
    if ((row->flags & XT_REF) && fresh) xt_check_reference(c, d, row->name);
    if (row->flags & XT_EXPOSURE) xt_check_exposure(c, row->name);
    if (row->flags & XT_BACKGROUND) xt_check_background(c, row->name);
    if (row->flags & XT_BOUNDED) xt_check_bounded(c, row->name);
    else xt_exercise(c, row->name, (row->flags & XT_FEW) ? 1 : 10);
}

/* The row through hd_create, then through the setters of what it edits on a context made from the
   base desc (a volume edit has no setter). */
static void xt_row_body(const xt_row *row)
{
    static float tf0[16];
    static hd_light l0[3];
    hd_desc b, d;
    hd_context c;
    hd_result r, want = row->want;
    int ntf0, nl0;
    xt_base(&d);
    row->edit(&d);
    r = hd_create(&d, &c);
    xt_expect_rejected(r, want, row->name, "hd_create");
    if (r != HD_SUCCESS) CHECK_MSG(c.id == 0, "%s: a rejected hd_create gave a handle", row->name);
    if (r == HD_SUCCESS) {
        xt_accepted(c, row, &d, 1);
        CHECK(hd_destroy(c) == HD_SUCCESS);
    }
    /* the base, its TF and lights kept aside; then the edited desc again */
    xt_base(&b);
    memcpy(tf0, xt_tf_buf, sizeof tf0);
    memcpy(l0, xt_light_buf, sizeof l0);
    ntf0 = b.transfer_function.count;
    nl0 = b.light_count;
    xt_base(&d);
    row->edit(&d);
    if (memcmp(&d.volume, &b.volume, sizeof d.volume) != 0) return;
    b.transfer_function.rgba = tf0;
    b.lights = l0;
    if (hd_create(&b, &c) != HD_SUCCESS) { CHECK_MSG(0, "%s: base desc", row->name); return; }
    CHECK(hd_iterate(c, 1) == HD_SUCCESS);
    r = HD_SUCCESS;
    want = row->want;
#define XT_SETTER(changed, call, how) \
    if (r == HD_SUCCESS && (changed)) { \
        xt_snap s; \
        xt_snap_take(c, &s); \
        xt_log.errors = 0; \
        r = call; \
        if (r != HD_SUCCESS || want != HD_SUCCESS) { \
            xt_expect_rejected(r, want, row->name, how); \
            CHECK_MSG(xt_snap_same(c, &s), "%s (%s): a rejected call changed the context", row->name, how); \
        } \
    }
    XT_SETTER(d.transfer_function.count != ntf0 || memcmp(xt_tf_buf, tf0, sizeof tf0) != 0,
              hd_set_transfer_function(c, &d.transfer_function), "hd_set_transfer_function")
    XT_SETTER(d.light_count != nl0 || memcmp(xt_light_buf, l0, sizeof l0) != 0, hd_set_lights(c, d.lights, d.light_count),
              "hd_set_lights")
    XT_SETTER(memcmp(&d.camera, &b.camera, sizeof d.camera) != 0, hd_set_camera(c, &d.camera), "hd_set_camera")
    XT_SETTER(memcmp(&d.params, &b.params, sizeof d.params) != 0, hd_set_params(c, &d.params), "hd_set_params")
#undef XT_SETTER
    if (r == HD_SUCCESS && want != HD_SUCCESS) CHECK_MSG(0, "%s: no setter rejected it", row->name);
    if (r == HD_SUCCESS) xt_accepted(c, row, &d, 0);
    CHECK(hd_destroy(c) == HD_SUCCESS);
}

/* Each row in a child process under an alarm: a hang or a crash fails that row only. */
static void xt_run_rows(const xt_row *rows, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i) {
        pid_t pid;
        int status = 0;
        fflush(NULL);
        pid = fork();
        if (pid < 0) { CHECK_MSG(0, "fork failed"); return; }
        if (pid == 0) {
            hd_test_failures = 0;
            alarm((rows[i].flags & XT_BOUNDED) ? XT_BOUNDED_ALARM : XT_ALARM);
            xt_row_body(&rows[i]);
            fflush(NULL);
            _exit(hd_test_failures ? 1 : 0);
        }
        while (waitpid(pid, &status, 0) < 0)
            if (errno != EINTR) break;
        if (WIFSIGNALED(status))
            CHECK_MSG(0, "%s: %s", rows[i].name, WTERMSIG(status) == SIGALRM ? "did not finish within the alarm (hang)"
                                                                              : strsignal(WTERMSIG(status)));
        else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
            CHECK_MSG(0, "%s: failed (status %d)", rows[i].name, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    }
}
#define XT_ROWS(rows) xt_run_rows(rows, sizeof rows / sizeof rows[0])

/* An edit: one statement on d (the desc), L (its first light) or T (its TF entries). */
#define XT_EDIT(fn, stmt) \
    static void fn(hd_desc *d) \
    { \
        hd_light *L = xt_light_buf; \
        float *T = xt_tf_buf; \
        (void)L; (void)T; (void)d; \
        stmt; \
    }
#define XT_SET3(v, x) ((v)[0] = (v)[1] = (v)[2] = (x))
#define IP HD_ERROR_INVALID_PARAMETER
#define IL HD_ERROR_INVALID_LIGHT
#define IC HD_ERROR_INVALID_CAMERA

/* ---- value ranges: hi - lo may overflow (or lo > hi); the voxels must still map ---- */
XT_EDIT(vr_3e38, xt_range(d, HD_VOXEL_F32, -3e38f, 3e38f))
XT_EDIT(vr_max, xt_range(d, HD_VOXEL_F32, -FLT_MAX, FLT_MAX))
XT_EDIT(vr_0_max, xt_range(d, HD_VOXEL_F32, 0.0f, FLT_MAX))
XT_EDIT(vr_max_0, xt_range(d, HD_VOXEL_F32, -FLT_MAX, 0.0f))
XT_EDIT(vr_rev_max, xt_range(d, HD_VOXEL_F32, FLT_MAX, -FLT_MAX))
XT_EDIT(vr_rev_1e30, xt_range(d, HD_VOXEL_F32, 1e30f, -1e30f))
XT_EDIT(vr_neg_max, xt_range(d, HD_VOXEL_F32, -FLT_MAX, -3e38f))
XT_EDIT(vr_denorm, xt_range(d, HD_VOXEL_F32, 0.0f, xt_denorm()))
XT_EDIT(vr_min, xt_range(d, HD_VOXEL_F32, 0.0f, FLT_MIN))
XT_EDIT(vr_ulp, xt_range(d, HD_VOXEL_F32, 1.0f, xt_up(1.0f)))
XT_EDIT(vr_ulp_1e30, xt_range(d, HD_VOXEL_F32, 1e30f, xt_up(1e30f)))
XT_EDIT(vr_tiny, xt_range(d, HD_VOXEL_F32, -1e-30f, 1e-30f))
XT_EDIT(vr_neg0, xt_range(d, HD_VOXEL_F32, xt_neg0(), 0.0f))
XT_EDIT(vr_u16_3e38, xt_range(d, HD_VOXEL_U16, -3e38f, 3e38f))
XT_EDIT(vr_u16_rev, xt_range(d, HD_VOXEL_U16, 65535.0f, 0.0f))
XT_EDIT(vr_u8_max, xt_range(d, HD_VOXEL_U8, -FLT_MAX, FLT_MAX))
XT_EDIT(vr_u8_tiny, xt_range(d, HD_VOXEL_U8, 0.0f, 1e-30f))
XT_EDIT(vr_nan, xt_range(d, HD_VOXEL_F32, xt_nan(), 1.0f))
XT_EDIT(vr_inf, xt_range(d, HD_VOXEL_F32, 0.0f, xt_inf()))
XT_EDIT(vr_eq_max, xt_range(d, HD_VOXEL_F32, FLT_MAX, FLT_MAX))
XT_EDIT(vr_eq_denorm, xt_range(d, HD_VOXEL_U8, xt_denorm(), xt_denorm()))
static const xt_row xt_value_range_rows[] = {
    {"value range F32 {-3e38, 3e38}", vr_3e38, HD_SUCCESS, XT_REF},
    {"value range F32 {-FLT_MAX, FLT_MAX}", vr_max, HD_SUCCESS, XT_REF},
    {"value range F32 {0, FLT_MAX}", vr_0_max, HD_SUCCESS, XT_REF},
    {"value range F32 {-FLT_MAX, 0}", vr_max_0, HD_SUCCESS, XT_REF},
    {"value range F32 {FLT_MAX, -FLT_MAX}", vr_rev_max, HD_SUCCESS, XT_REF},
    {"value range F32 {1e30, -1e30}", vr_rev_1e30, HD_SUCCESS, XT_REF},
    {"value range F32 {-FLT_MAX, -3e38}", vr_neg_max, HD_SUCCESS, XT_REF},
    {"value range F32 {0, denormal}", vr_denorm, HD_SUCCESS, XT_REF},
    {"value range F32 {0, FLT_MIN}", vr_min, HD_SUCCESS, XT_REF},
    {"value range F32 {1, 1 + ulp}", vr_ulp, HD_SUCCESS, XT_REF},
    {"value range F32 {1e30, 1e30 + ulp}", vr_ulp_1e30, HD_SUCCESS, XT_REF},
    {"value range F32 {-1e-30, 1e-30}", vr_tiny, HD_SUCCESS, XT_REF},
    {"value range F32 {-0, 0} (the default)", vr_neg0, HD_SUCCESS, XT_REF},
    {"value range U16 {-3e38, 3e38}", vr_u16_3e38, HD_SUCCESS, XT_REF},
    {"value range U16 {65535, 0}", vr_u16_rev, HD_SUCCESS, XT_REF},
    {"value range U8 {-FLT_MAX, FLT_MAX}", vr_u8_max, HD_SUCCESS, XT_REF},
    {"value range U8 {0, 1e-30}", vr_u8_tiny, HD_SUCCESS, XT_REF},
    {"value range {NaN, 1}", vr_nan, IP, 0},
    {"value range {0, Inf}", vr_inf, IP, 0},
    {"value range {FLT_MAX, FLT_MAX}", vr_eq_max, IP, 0},
    {"value range {denormal, denormal}", vr_eq_denorm, IP, 0},
};

/* ---- spacing: finite, > 0, each >= the largest extent / HD_MAX_SPACING_RATIO (6 voxels a side) ---- */
/* 6 / 65536 = 3 * 2^-15 is a float: the thinnest axis' bound exactly */
#define XT_SP_THIN (6.0f / HD_MAX_SPACING_RATIO)
static float xt_sp_thick(void) /* the largest spacing the others (1) allow: 65536 / 6, rounded down */
{
    float s = (float)(HD_MAX_SPACING_RATIO / 6.0);
    return (double)s * 6.0 > (double)HD_MAX_SPACING_RATIO ? xt_down(s) : s;
}
XT_EDIT(sp_thin, d->volume.spacing[0] = d->volume.spacing[1] = 1.0f; d->volume.spacing[2] = XT_SP_THIN)
XT_EDIT(sp_thin_down, d->volume.spacing[0] = d->volume.spacing[1] = 1.0f; d->volume.spacing[2] = xt_down(XT_SP_THIN))
XT_EDIT(sp_thick, d->volume.spacing[0] = d->volume.spacing[2] = 1.0f; d->volume.spacing[1] = xt_sp_thick())
XT_EDIT(sp_thick_up, d->volume.spacing[0] = d->volume.spacing[2] = 1.0f; d->volume.spacing[1] = xt_up(xt_sp_thick()))
XT_EDIT(sp_max, XT_SET3(d->volume.spacing, FLT_MAX))
XT_EDIT(sp_max_thin, d->volume.spacing[0] = d->volume.spacing[1] = FLT_MAX; d->volume.spacing[2] = FLT_MAX / 8192.0f)
XT_EDIT(sp_denorm, XT_SET3(d->volume.spacing, xt_denorm()))
XT_EDIT(sp_min, XT_SET3(d->volume.spacing, FLT_MIN))
XT_EDIT(sp_neg0, XT_SET3(d->volume.spacing, xt_neg0()))
XT_EDIT(sp_one_zero, d->volume.spacing[0] = d->volume.spacing[1] = 1.0f)
XT_EDIT(sp_neg_denorm, d->volume.spacing[0] = d->volume.spacing[2] = 1.0f; d->volume.spacing[1] = -xt_denorm())
XT_EDIT(sp_mixed, d->volume.spacing[0] = 1e-30f; d->volume.spacing[1] = 1.0f; d->volume.spacing[2] = 1e30f)
static const xt_row xt_spacing_rows[] = {
    {"spacing {1, 1, 6/65536} (the thinnest axis)", sp_thin, HD_SUCCESS, 0},
    {"spacing {1, 1, 6/65536 - ulp}", sp_thin_down, HD_ERROR_INVALID_SPACING, 0},
    {"spacing {1, 65536/6, 1} (the thickest axis)", sp_thick, HD_SUCCESS, 0},
    {"spacing {1, 65536/6 + ulp, 1}", sp_thick_up, HD_ERROR_INVALID_SPACING, 0},
    {"spacing FLT_MAX x3", sp_max, HD_SUCCESS, 0},
    {"spacing {FLT_MAX, FLT_MAX, FLT_MAX / 8192}", sp_max_thin, HD_SUCCESS, 0},
    {"spacing denormal x3", sp_denorm, HD_SUCCESS, 0},
    {"spacing FLT_MIN x3", sp_min, HD_SUCCESS, 0},
    {"spacing -0 x3 (the default)", sp_neg0, HD_SUCCESS, 0},
    {"spacing {1, 1, 0}", sp_one_zero, HD_ERROR_INVALID_SPACING, 0},
    {"spacing {1, -denormal, 1}", sp_neg_denorm, HD_ERROR_INVALID_SPACING, 0},
    {"spacing {1e-30, 1, 1e30}", sp_mixed, HD_ERROR_INVALID_SPACING, 0},
};

/* ---- background: each component in [0, 1e6]; with reduced frames (render_scale) and short windows ---- */
XT_EDIT(bg_max, XT_SET3(d->params.background, FLT_MAX))
XT_EDIT(bg_max_r, d->params.background[0] = FLT_MAX)
XT_EDIT(bg_3e38, XT_SET3(d->params.background, 3e38f))
XT_EDIT(bg_1e30, XT_SET3(d->params.background, 1e30f))
XT_EDIT(bg_lim, XT_SET3(d->params.background, 1e6f))
XT_EDIT(bg_lim_r, d->params.background[0] = 1e6f)
XT_EDIT(bg_lim_down, XT_SET3(d->params.background, xt_down(1e6f)))
XT_EDIT(bg_lim_up, d->params.background[1] = xt_up(1e6f))
XT_EDIT(bg_denorm, XT_SET3(d->params.background, xt_denorm()))
XT_EDIT(bg_min, XT_SET3(d->params.background, FLT_MIN))
XT_EDIT(bg_neg0, XT_SET3(d->params.background, xt_neg0()))
XT_EDIT(bg_neg_denorm, d->params.background[1] = -xt_denorm())
XT_EDIT(bg_neg_max, d->params.background[2] = -FLT_MAX)
XT_EDIT(bg_lim_w1_s2, d->params.background[0] = 1e6f; d->params.frame_window = 1; d->params.render_scale = 2)
XT_EDIT(bg_lim_w1_s4, d->params.background[0] = 1e6f; d->params.frame_window = 1; d->params.render_scale = 4)
XT_EDIT(bg_lim_w1_s8, XT_SET3(d->params.background, 1e6f); d->params.frame_window = 1; d->params.render_scale = 8)
XT_EDIT(bg_lim_auto, d->params.background[0] = 1e6f; d->params.render_scale = HD_RENDER_SCALE_AUTO)
XT_EDIT(bg_lim_auto_w1, XT_SET3(d->params.background, 1e6f); d->params.frame_window = 1;
        d->params.render_scale = HD_RENDER_SCALE_AUTO)
XT_EDIT(bg_lim_w2_s2, XT_SET3(d->params.background, 1e6f); d->params.frame_window = 2; d->params.render_scale = 2)
XT_EDIT(bg_max_w1_s2, d->params.background[0] = FLT_MAX; d->params.frame_window = 1; d->params.render_scale = 2)
static const xt_row xt_background_rows[] = {
    {"background 1e6 x3 (the bound)", bg_lim, HD_SUCCESS, XT_BACKGROUND},
    {"background {1e6, 0, 0}", bg_lim_r, HD_SUCCESS, XT_BACKGROUND},
    {"background 1e6 - ulp x3", bg_lim_down, HD_SUCCESS, XT_BACKGROUND},
    {"background {0, 1e6 + ulp, 0}", bg_lim_up, IP, 0},
    {"background FLT_MAX x3", bg_max, IP, 0},
    {"background {FLT_MAX, 0, 0}", bg_max_r, IP, 0},
    {"background 3e38 x3", bg_3e38, IP, 0},
    {"background 1e30 x3", bg_1e30, IP, 0},
    {"background denormal x3", bg_denorm, HD_SUCCESS, XT_BACKGROUND},
    {"background FLT_MIN x3", bg_min, HD_SUCCESS, XT_BACKGROUND},
    {"background -0 x3", bg_neg0, HD_SUCCESS, XT_BACKGROUND},
    {"background {0, -denormal, 0}", bg_neg_denorm, IP, 0},
    {"background {0, 0, -FLT_MAX}", bg_neg_max, IP, 0},
    {"background 1e6, frame_window 1, render_scale 2", bg_lim_w1_s2, HD_SUCCESS, XT_BACKGROUND},
    {"background 1e6, frame_window 1, render_scale 4", bg_lim_w1_s4, HD_SUCCESS, XT_BACKGROUND},
    {"background 1e6 x3, frame_window 1, render_scale 8", bg_lim_w1_s8, HD_SUCCESS, XT_BACKGROUND},
    {"background 1e6, render_scale AUTO", bg_lim_auto, HD_SUCCESS, XT_BACKGROUND},
    {"background 1e6 x3, frame_window 1, render_scale AUTO", bg_lim_auto_w1, HD_SUCCESS, XT_BACKGROUND},
    {"background 1e6 x3, frame_window 2, render_scale 2", bg_lim_w2_s2, HD_SUCCESS, XT_BACKGROUND},
    {"background FLT_MAX, frame_window 1, render_scale 2", bg_max_w1_s2, IP, 0},
};

/* An 8^3 U16 volume of three values (a: 65, b: 65534, c: 65535) on which full-resolution frames
   of a FLT_MAX background turned non-finite before the background had a bound (found by
   tests/fuzz/fuzz_state.c). */
static const char xt_bg_volume[] =
    "abacbacaabacbacaabacbacbacaabacbacaabacbacbacaabacbacaabacbacbac"
    "aabacbacaabacbacaacaabacbacaabacbacaacaabacbacaabacbacaabaabacba"
    "caabacbacaabacbacbacaabacbacaabacbacbacaabacbacaabacbacbacaabacb"
    "acaabacbacbacaabacbacaabacbacaacaabacbacaabacbacaabaabacbacaabac"
    "bacaabaabacbacaabacbacaabacbacbacaabacbacaabacbacbacaabacbacaaba"
    "cbacbacaabacbacaabacbacaacaabacbacaabacbacaacaabacbacaabacbacaab"
    "aabacbacaabacbacaabaabacbacaabacbacaabacbacbacaabacbacaabacbacba"
    "caabacbacaabacbacbacaabacbacaabacbacaacaabacbacaabacbacaacaabacb";

/* The largest background over many frames: the fuzzer's volume at full resolution (a FLT_MAX
   background rejected by hd_create and hd_set_params, the context unchanged), then a sweep of
   volumes, image sizes, reduced scales and windows; every frame read back finite (the
   projection, the upsample and the running mean must not overflow). */
static void test_background_reduced(void)
{
    static const int sizes[3] = {8, 12, 16}, scales[4] = {2, 4, 8, HD_RENDER_SCALE_AUTO};
    static uint8_t alt[64], ramp[8];
    static float img[16 * 16 * 4];
    const float bmax = 1e6f;
    int v, w, s, win, bg, k, i, bad = 0;
    for (i = 0; i < 64; ++i) alt[i] = (uint8_t)(i % 2 ? 255 : 0);
    for (i = 0; i < 8; ++i) ramp[i] = (uint8_t)(i * 36);
    for (k = 0; k < 2; ++k) { /* the default light tolerance, then 1 */
        static uint16_t u16[512];
        hd_desc d;
        hd_context c;
        hd_params p;
        xt_snap sn;
        for (i = 0; i < 512; ++i) u16[i] = (uint16_t)(xt_bg_volume[i] == 'a' ? 65 : xt_bg_volume[i] == 'b' ? 65534 : 65535);
        memset(&d, 0, sizeof d);
        d.volume.type = HD_VOXEL_U16;
        d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = 8;
        d.volume.data = u16;
        d.camera.width = 16;
        d.camera.height = 14;
        d.threads = 1;
        d.logger = hd_test_logger(&xt_log);
        d.params.light_tolerance = k ? 1.0f : 0.0f;
        XT_SET3(d.params.background, FLT_MAX);
        xt_log.errors = 0;
        xt_create_rejected(&d, IP, "U16 8^3, background FLT_MAX x3");
        XT_SET3(d.params.background, bmax);
        if (hd_create(&d, &c) != HD_SUCCESS) { CHECK(0); continue; }
        for (v = 1; v <= 16; ++v) {
            CHECK(hd_render(c) == HD_SUCCESS);
            CHECK(hd_read_image_f32(c, img, 16 * 14 * 4) == HD_SUCCESS);
            if (!xt_finite(img, 16 * 14 * 4)) {
                CHECK_MSG(0, "U16 8^3, 16x14, light tolerance %s: frame %d of a 1e6 background not finite", k ? "1" : "default", v);
                break;
            }
            if (v == 8) { /* a FLT_MAX background mid-run: rejected, nothing changed */
                CHECK(hd_query_desc(c, &d) == HD_SUCCESS);
                p = d.params;
                p.background[k] = FLT_MAX;
                xt_snap_take(c, &sn);
                xt_log.errors = 0;
                xt_expect_rejected(hd_set_params(c, &p), IP, "U16 8^3, background FLT_MAX", "hd_set_params");
                CHECK_MSG(xt_snap_same(c, &sn), "U16 8^3: the rejected background changed the context");
            }
        }
        CHECK(hd_destroy(c) == HD_SUCCESS);
    }
    for (v = 0; v < 3; ++v)
        for (w = 0; w < 3; ++w)
            for (s = 0; s < 4; ++s)
                for (win = 0; win < 2; ++win)
                    for (bg = 0; bg < 2; ++bg) {
                        hd_desc d;
                        hd_context c;
                        size_t n = (size_t)sizes[w] * sizes[w] * 4;
                        xt_base(&d);
                        if (v > 0) {
                            d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = v == 1 ? 4 : 2;
                            d.volume.data = v == 1 ? alt : ramp;
                        }
                        d.camera.width = d.camera.height = sizes[w];
                        d.params.render_scale = scales[s];
                        d.params.frame_window = win;
                        d.params.background[0] = bmax;
                        if (bg) d.params.background[1] = d.params.background[2] = bmax;
                        if (hd_create(&d, &c) != HD_SUCCESS) { CHECK(0); continue; }
                        for (k = 1; k <= 12; ++k) {
                            CHECK(hd_render(c) == HD_SUCCESS);
                            CHECK(hd_read_image_f32(c, img, n) == HD_SUCCESS);
                            if (!xt_finite(img, n)) {
                                if (++bad <= 8)
                                    CHECK_MSG(0, "volume %d, %dx%d, render_scale %d, frame_window %d, background %s: "
                                              "frame %d not finite", v, sizes[w], sizes[w], scales[s], win,
                                              bg ? "1e6 x3" : "{1e6, 0, 0}", k);
                                break;
                            }
                        }
                        CHECK(hd_destroy(c) == HD_SUCCESS);
                    }
    CHECK_MSG(bad == 0, "%d of 144 configurations gave a non-finite image", bad);
}

/* ---- exposure: finite, >= 0 (0 -> 1); RGBA8 encodes radiance * exposure ---- */
XT_EDIT(ex_max, d->params.exposure = FLT_MAX)
XT_EDIT(ex_3e38, d->params.exposure = 3e38f)
XT_EDIT(ex_1e30, d->params.exposure = 1e30f)
XT_EDIT(ex_denorm, d->params.exposure = xt_denorm())
XT_EDIT(ex_1e_30, d->params.exposure = 1e-30f)
XT_EDIT(ex_min, d->params.exposure = FLT_MIN)
XT_EDIT(ex_neg0, d->params.exposure = xt_neg0())
XT_EDIT(ex_neg_denorm, d->params.exposure = -xt_denorm())
XT_EDIT(ex_neg_max, d->params.exposure = -FLT_MAX)
static const xt_row xt_exposure_rows[] = {
    {"exposure FLT_MAX", ex_max, HD_SUCCESS, XT_EXPOSURE},
    {"exposure 3e38", ex_3e38, HD_SUCCESS, XT_EXPOSURE},
    {"exposure 1e30", ex_1e30, HD_SUCCESS, XT_EXPOSURE},
    {"exposure denormal", ex_denorm, HD_SUCCESS, XT_EXPOSURE},
    {"exposure 1e-30", ex_1e_30, HD_SUCCESS, XT_EXPOSURE},
    {"exposure FLT_MIN", ex_min, HD_SUCCESS, XT_EXPOSURE},
    {"exposure -0 (the default)", ex_neg0, HD_SUCCESS, XT_EXPOSURE},
    {"exposure -denormal", ex_neg_denorm, IP, 0},
    {"exposure -FLT_MAX", ex_neg_max, IP, 0},
};

/* ---- the medium: extinction (0, 1e6], albedo (0, 1], anisotropy (-1, 1), step [0.01, 16] ---- */
/* extinction 1e6 makes every walk run to its 2^16-collision limit: a coarser grid, a 2x2 image */
#define XT_DENSE(stmt) d->params.illumination_downsample = 2; d->camera.width = d->camera.height = 2; stmt
XT_EDIT(mx_1e6, XT_DENSE(d->params.extinction = 1e6f))
XT_EDIT(mx_1e6_up, d->params.extinction = xt_up(1e6f))
XT_EDIT(mx_max, d->params.extinction = FLT_MAX)
XT_EDIT(mx_1e30, d->params.extinction = 1e30f)
XT_EDIT(mx_denorm, d->params.extinction = xt_denorm())
XT_EDIT(mx_1e_30, d->params.extinction = 1e-30f)
XT_EDIT(mx_min, d->params.extinction = FLT_MIN)
XT_EDIT(mx_neg0, d->params.extinction = xt_neg0())
XT_EDIT(mx_neg_denorm, d->params.extinction = -xt_denorm())
XT_EDIT(mx_1e6_albedo1, XT_DENSE(d->params.extinction = 1e6f; d->params.albedo = 1.0f; d->params.anisotropy = xt_down(1.0f)))
XT_EDIT(al_1, d->params.albedo = 1.0f)
XT_EDIT(al_1_up, d->params.albedo = xt_up(1.0f))
XT_EDIT(al_denorm, d->params.albedo = xt_denorm())
XT_EDIT(al_1e_30, d->params.albedo = 1e-30f)
XT_EDIT(al_neg0, d->params.albedo = xt_neg0())
XT_EDIT(al_neg_denorm, d->params.albedo = -xt_denorm())
XT_EDIT(al_max, d->params.albedo = FLT_MAX)
XT_EDIT(an_below1, d->params.anisotropy = xt_down(1.0f))
XT_EDIT(an_above_m1, d->params.anisotropy = xt_up(-1.0f))
XT_EDIT(an_1, d->params.anisotropy = 1.0f)
XT_EDIT(an_m1, d->params.anisotropy = -1.0f)
XT_EDIT(an_denorm, d->params.anisotropy = -xt_denorm())
XT_EDIT(an_max, d->params.anisotropy = FLT_MAX)
XT_EDIT(st_min, d->params.step = 0.01f)
XT_EDIT(st_min_down, d->params.step = xt_down(0.01f))
XT_EDIT(st_16, d->params.step = 16.0f)
XT_EDIT(st_16_up, d->params.step = xt_up(16.0f))
XT_EDIT(st_denorm, d->params.step = xt_denorm())
XT_EDIT(st_max, d->params.step = FLT_MAX)
XT_EDIT(st_neg0, d->params.step = xt_neg0())
XT_EDIT(st_neg, d->params.step = -0.01f)
/* majorant: 0 (the grid) or in [max sigma_t, 16 max sigma_t] and [0, 1e6]; the base's largest
   extinction is 40 (TF alpha 1 at the core) */
XT_EDIT(mj_at, d->params.majorant = 40.0f)
XT_EDIT(mj_below, d->params.majorant = 39.9f)
XT_EDIT(mj_slack, d->params.majorant = 640.0f)
XT_EDIT(mj_slack_up, d->params.majorant = 644.0f)
XT_EDIT(mj_lim, XT_DENSE(d->params.extinction = 1e6f; d->params.majorant = 1e6f))
XT_EDIT(mj_lim_up, d->params.extinction = 1e6f; d->params.majorant = xt_up(1e6f))
XT_EDIT(mj_max, d->params.majorant = FLT_MAX)
XT_EDIT(mj_denorm, d->params.majorant = xt_denorm())
XT_EDIT(mj_neg0, d->params.majorant = xt_neg0())
XT_EDIT(mj_neg_denorm, d->params.majorant = -xt_denorm())
static const xt_row xt_medium_rows[] = {
    {"majorant 40 (the largest extinction)", mj_at, HD_SUCCESS, 0},
    {"majorant 39.9 (below the largest extinction)", mj_below, IP, 0},
    {"majorant 640 (16x the largest extinction)", mj_slack, HD_SUCCESS, 0},
    {"majorant 644 (16.1x; the bound carries a rounding margin)", mj_slack_up, IP, 0},
    {"majorant 1e6, extinction 1e6", mj_lim, HD_SUCCESS, XT_FEW},
    {"majorant 1e6 + ulp, extinction 1e6", mj_lim_up, IP, 0},
    {"majorant FLT_MAX", mj_max, IP, 0},
    {"majorant denormal", mj_denorm, IP, 0},
    {"majorant -0 (the grid)", mj_neg0, HD_SUCCESS, 0},
    {"majorant -denormal", mj_neg_denorm, IP, 0},
    {"extinction 1e6", mx_1e6, HD_SUCCESS, XT_FEW},
    {"extinction 1e6 + ulp", mx_1e6_up, IP, 0},
    {"extinction FLT_MAX", mx_max, IP, 0},
    {"extinction 1e30", mx_1e30, IP, 0},
    {"extinction denormal", mx_denorm, HD_SUCCESS, 0},
    {"extinction 1e-30", mx_1e_30, HD_SUCCESS, 0},
    {"extinction FLT_MIN", mx_min, HD_SUCCESS, 0},
    {"extinction -0 (the default)", mx_neg0, HD_SUCCESS, 0},
    {"extinction -denormal", mx_neg_denorm, IP, 0},
    {"extinction 1e6, albedo 1, anisotropy 1 - ulp", mx_1e6_albedo1, HD_SUCCESS, XT_FEW},
    {"albedo 1", al_1, HD_SUCCESS, 0},
    {"albedo 1 + ulp", al_1_up, IP, 0},
    {"albedo denormal", al_denorm, HD_SUCCESS, 0},
    {"albedo 1e-30", al_1e_30, HD_SUCCESS, 0},
    {"albedo -0 (the default)", al_neg0, HD_SUCCESS, 0},
    {"albedo -denormal", al_neg_denorm, IP, 0},
    {"albedo FLT_MAX", al_max, IP, 0},
    {"anisotropy 1 - ulp", an_below1, HD_SUCCESS, 0},
    {"anisotropy -1 + ulp", an_above_m1, HD_SUCCESS, 0},
    {"anisotropy 1", an_1, IP, 0},
    {"anisotropy -1", an_m1, IP, 0},
    {"anisotropy -denormal", an_denorm, HD_SUCCESS, 0},
    {"anisotropy FLT_MAX", an_max, IP, 0},
    {"step 0.01", st_min, HD_SUCCESS, 0},
    {"step 0.01 - ulp", st_min_down, IP, 0},
    {"step 16", st_16, HD_SUCCESS, 0},
    {"step 16 + ulp", st_16_up, IP, 0},
    {"step denormal", st_denorm, IP, 0},
    {"step FLT_MAX", st_max, IP, 0},
    {"step -0 (the default)", st_neg0, HD_SUCCESS, 0},
    {"step -0.01", st_neg, IP, 0},
};

/* ---- lights: intensity, colour, point position (1/r^2 or none), direction ---- */
XT_EDIT(li_power, L->intensity = HD_MAX_LIGHT_POWER)
XT_EDIT(li_power_up, L->intensity = xt_up(HD_MAX_LIGHT_POWER))
XT_EDIT(li_max, L->intensity = FLT_MAX)
XT_EDIT(li_denorm, L->intensity = xt_denorm())
XT_EDIT(li_1e_30, L->intensity = 1e-30f)
XT_EDIT(li_neg0, L->intensity = xt_neg0())
XT_EDIT(li_neg_denorm, L->intensity = -xt_denorm())
XT_EDIT(lc_max_dim, XT_SET3(L->color, FLT_MAX); L->intensity = 1e-38f)
XT_EDIT(lc_max_red, L->color[0] = FLT_MAX; L->intensity = 1e-38f)
XT_EDIT(lc_denorm, L->color[0] = xt_denorm())
XT_EDIT(lc_max, L->color[1] = FLT_MAX)
XT_EDIT(lc_two, L->color[0] = FLT_MAX; L->intensity = 1e-38f; L[1] = L[0]; L[1].color[0] = 0.0f;
        L[1].color[2] = xt_denorm(); L[1].intensity = 1.0f; d->light_count = 2)
XT_EDIT(lc_two_power, L[1] = L[0]; L[1].color[1] = 0.5f; L->intensity = 0.5f * HD_MAX_LIGHT_POWER;
        L[1].intensity = 0.5f * HD_MAX_LIGHT_POWER; d->light_count = 2)
XT_EDIT(lp_far, L->type = HD_LIGHT_POINT; L->position[0] = HD_MAX_LIGHT_DISTANCE; L->inverse_square = 1)
XT_EDIT(lp_far_flat, L->type = HD_LIGHT_POINT; XT_SET3(L->position, -HD_MAX_LIGHT_DISTANCE))
XT_EDIT(lp_far_up, L->type = HD_LIGHT_POINT; L->position[1] = xt_up(HD_MAX_LIGHT_DISTANCE))
XT_EDIT(lp_max, L->type = HD_LIGHT_POINT; L->position[2] = -FLT_MAX)
XT_EDIT(lp_centre, L->type = HD_LIGHT_POINT; L->inverse_square = 1; L->intensity = HD_MAX_LIGHT_POWER)
XT_EDIT(lp_voxel, L->type = HD_LIGHT_POINT; L->inverse_square = 1; XT_SET3(L->position, 1.0f / 12.0f))
XT_EDIT(lp_denorm, L->type = HD_LIGHT_POINT; L->inverse_square = 1; L->position[0] = xt_denorm(); L->position[1] = xt_neg0())
XT_EDIT(lp_face, L->type = HD_LIGHT_POINT; L->inverse_square = 1; L->position[2] = 0.5f)
XT_EDIT(ld_max, L->direction[0] = FLT_MAX; L->direction[1] = FLT_MAX; L->direction[2] = -FLT_MAX)
XT_EDIT(ld_denorm, L->direction[0] = 0.0f; L->direction[1] = xt_denorm(); L->direction[2] = -xt_denorm())
XT_EDIT(ld_min, L->direction[0] = L->direction[1] = 0.0f; L->direction[2] = 1e-45f)
XT_EDIT(ld_zero, XT_SET3(L->direction, xt_neg0()))
XT_EDIT(ld_axis, L->direction[0] = 1.0f; L->direction[1] = L->direction[2] = 0.0f)
static const xt_row xt_light_rows[] = {
    {"light intensity HD_MAX_LIGHT_POWER", li_power, HD_SUCCESS, 0},
    {"light intensity HD_MAX_LIGHT_POWER + ulp", li_power_up, IL, 0},
    {"light intensity FLT_MAX", li_max, IL, 0},
    {"light intensity denormal", li_denorm, HD_SUCCESS, 0},
    {"light intensity 1e-30", li_1e_30, HD_SUCCESS, 0},
    {"light intensity -0 (the default)", li_neg0, HD_SUCCESS, 0},
    {"light intensity -denormal", li_neg_denorm, IL, 0},
    {"light colour FLT_MAX x3, intensity 1e-38", lc_max_dim, HD_SUCCESS, 0},
    {"light colour {FLT_MAX, 1, 1}, intensity 1e-38", lc_max_red, HD_SUCCESS, 0},
    {"light colour {denormal, 1, 1}", lc_denorm, HD_SUCCESS, 0},
    {"light colour {1, FLT_MAX, 1}", lc_max, IL, 0},
    {"two lights: colour FLT_MAX at 1e-38 and a denormal blue", lc_two, HD_SUCCESS, 0},
    {"two lights of different colours, summed power at the limit", lc_two_power, HD_SUCCESS, 0},
    {"point light at HD_MAX_LIGHT_DISTANCE, 1/r^2", lp_far, HD_SUCCESS, 0},
    {"point light at -HD_MAX_LIGHT_DISTANCE x3, no falloff", lp_far_flat, HD_SUCCESS, 0},
    {"point light at HD_MAX_LIGHT_DISTANCE + ulp", lp_far_up, IL, 0},
    {"point light at -FLT_MAX", lp_max, IL, 0},
    {"point light at the centre, 1/r^2, HD_MAX_LIGHT_POWER", lp_centre, HD_SUCCESS, 0},
    {"point light on a voxel centre, 1/r^2", lp_voxel, HD_SUCCESS, 0},
    {"point light at {denormal, -0, 0}, 1/r^2", lp_denorm, HD_SUCCESS, 0},
    {"point light on the box face, 1/r^2", lp_face, HD_SUCCESS, 0},
    {"light direction FLT_MAX", ld_max, HD_SUCCESS, 0},
    {"light direction denormal", ld_denorm, HD_SUCCESS, 0},
    {"light direction {0, 0, 1e-45}", ld_min, HD_SUCCESS, 0},
    {"light direction -0 x3", ld_zero, IL, 0},
    {"light direction along x (grazing the faces)", ld_axis, HD_SUCCESS, 0},
};

/* ---- camera: eye and target within HD_MAX_CAMERA_DISTANCE, fov in (0, 180), up ---- */
XT_EDIT(ce_far, d->camera.eye[2] = HD_MAX_CAMERA_DISTANCE)
XT_EDIT(ce_far_up, d->camera.eye[2] = xt_up(HD_MAX_CAMERA_DISTANCE))
XT_EDIT(ce_corners, XT_SET3(d->camera.eye, HD_MAX_CAMERA_DISTANCE); XT_SET3(d->camera.target, -HD_MAX_CAMERA_DISTANCE))
XT_EDIT(ce_below, d->camera.eye[2] = -HD_MAX_CAMERA_DISTANCE)
XT_EDIT(ce_inside, d->camera.eye[2] = 2e-6f)
XT_EDIT(ce_coincide, d->camera.eye[2] = 5e-7f)
XT_EDIT(ce_target_far, d->camera.eye[2] = 2.5f; d->camera.target[0] = -HD_MAX_CAMERA_DISTANCE)
XT_EDIT(ce_target_denorm, d->camera.eye[2] = 2.5f; d->camera.target[0] = xt_denorm())
XT_EDIT(cf_179, d->camera.fov_y = xt_down(180.0f))
XT_EDIT(cf_180, d->camera.fov_y = 180.0f)
XT_EDIT(cf_denorm, d->camera.fov_y = xt_denorm())
XT_EDIT(cf_1e_30, d->camera.fov_y = 1e-30f)
XT_EDIT(cf_max, d->camera.fov_y = FLT_MAX)
XT_EDIT(cf_neg0, d->camera.fov_y = xt_neg0())
XT_EDIT(cf_neg_denorm, d->camera.fov_y = -xt_denorm())
XT_EDIT(cu_max, d->camera.up[1] = FLT_MAX)
XT_EDIT(cu_max3, XT_SET3(d->camera.up, FLT_MAX))
XT_EDIT(cu_denorm, d->camera.up[1] = xt_denorm())
XT_EDIT(cs_1x1, d->camera.width = d->camera.height = 1)
XT_EDIT(cs_1x8, d->camera.width = 1)
static const xt_row xt_camera_rows[] = {
    {"camera eye at HD_MAX_CAMERA_DISTANCE", ce_far, HD_SUCCESS, 0},
    {"camera eye at HD_MAX_CAMERA_DISTANCE + ulp", ce_far_up, IC, 0},
    {"camera eye and target at opposite corners of the limit", ce_corners, HD_SUCCESS, 0},
    {"camera eye at -HD_MAX_CAMERA_DISTANCE", ce_below, HD_SUCCESS, 0},
    {"camera eye 2e-6 from the target (inside the medium)", ce_inside, HD_SUCCESS, 0},
    {"camera eye 5e-7 from the target", ce_coincide, IC, 0},
    {"camera target at -HD_MAX_CAMERA_DISTANCE", ce_target_far, HD_SUCCESS, 0},
    {"camera target at {denormal, 0, 0}", ce_target_denorm, HD_SUCCESS, 0},
    {"camera fov 180 - ulp", cf_179, HD_SUCCESS, 0},
    {"camera fov 180", cf_180, IC, 0},
    {"camera fov denormal", cf_denorm, HD_SUCCESS, 0},
    {"camera fov 1e-30", cf_1e_30, HD_SUCCESS, 0},
    {"camera fov FLT_MAX", cf_max, IC, 0},
    {"camera fov -0 (the default)", cf_neg0, HD_SUCCESS, 0},
    {"camera fov -denormal", cf_neg_denorm, IC, 0},
    {"camera up {0, FLT_MAX, 0}", cu_max, HD_SUCCESS, 0},
    {"camera up FLT_MAX x3", cu_max3, HD_SUCCESS, 0},
    {"camera up {0, denormal, 0}", cu_denorm, HD_SUCCESS, 0},
    {"camera 1x1", cs_1x1, HD_SUCCESS, 0},
    {"camera 1x8", cs_1x8, HD_SUCCESS, 0},
};

/* ---- the crop box: 0 <= min < max <= 1 per axis, max 0 -> 1 ---- */
XT_EDIT(cr_denorm, XT_SET3(d->params.crop_min, xt_denorm()); XT_SET3(d->params.crop_max, 2.0f * xt_denorm()))
XT_EDIT(cr_top, XT_SET3(d->params.crop_min, xt_down(1.0f)); XT_SET3(d->params.crop_max, 1.0f))
XT_EDIT(cr_ulp_mid, XT_SET3(d->params.crop_min, 0.5f); XT_SET3(d->params.crop_max, xt_up(0.5f)))
XT_EDIT(cr_neg0, XT_SET3(d->params.crop_min, xt_neg0()); XT_SET3(d->params.crop_max, xt_neg0()))
XT_EDIT(cr_max_denorm, d->params.crop_max[1] = xt_denorm())
XT_EDIT(cr_neg_denorm, d->params.crop_min[0] = -xt_denorm())
XT_EDIT(cr_max_up, d->params.crop_max[2] = xt_up(1.0f))
XT_EDIT(cr_equal, d->params.crop_min[1] = 0.5f; d->params.crop_max[1] = 0.5f)
XT_EDIT(cr_reversed, d->params.crop_min[0] = 0.75f; d->params.crop_max[0] = 0.25f)
XT_EDIT(cr_min_one, d->params.crop_min[2] = 1.0f)
XT_EDIT(cr_max_fltmax, d->params.crop_max[0] = -FLT_MAX)
static const xt_row xt_crop_rows[] = {
    {"crop box denormal wide at the low corner", cr_denorm, HD_SUCCESS, 0},
    {"crop box one ulp below the high faces", cr_top, HD_SUCCESS, 0},
    {"crop box one ulp wide in the middle", cr_ulp_mid, HD_SUCCESS, 0},
    {"crop box -0 corners (the default)", cr_neg0, HD_SUCCESS, 0},
    {"crop box max {1, denormal, 1}", cr_max_denorm, HD_SUCCESS, 0},
    {"crop min -denormal", cr_neg_denorm, IP, 0},
    {"crop max 1 + ulp", cr_max_up, IP, 0},
    {"crop min == max", cr_equal, IP, 0},
    {"crop min > max", cr_reversed, IP, 0},
    {"crop min 1 (max defaults to 1)", cr_min_one, IP, 0},
    {"crop max -FLT_MAX", cr_max_fltmax, IP, 0},
};

/* ---- light tolerance and render budget (finite, >= 0): every hd_render call stays bounded ---- */
XT_EDIT(lt_max, d->params.light_tolerance = FLT_MAX)
XT_EDIT(lt_1e30, d->params.light_tolerance = 1e30f)
XT_EDIT(lt_denorm, d->params.light_tolerance = xt_denorm())
XT_EDIT(lt_1e_30, d->params.light_tolerance = 1e-30f)
XT_EDIT(lt_neg0, d->params.light_tolerance = xt_neg0())
XT_EDIT(lt_neg_denorm, d->params.light_tolerance = -xt_denorm())
XT_EDIT(lt_neg_max, d->params.light_tolerance = -FLT_MAX)
XT_EDIT(rb_denorm, d->params.render_budget = xt_denorm())
XT_EDIT(rb_1e_30, d->params.render_budget = 1e-30f)
XT_EDIT(rb_ms, d->params.render_budget = 1e-3f; d->params.light_tolerance = 1e-30f)
XT_EDIT(rb_neg0, d->params.render_budget = xt_neg0())
XT_EDIT(rb_neg_denorm, d->params.render_budget = -xt_denorm())
XT_EDIT(rb_neg_max, d->params.render_budget = -FLT_MAX)
XT_EDIT(rb_lim, d->params.render_budget = 10.0f)
XT_EDIT(rb_lim_up, d->params.render_budget = xt_up(10.0f))
XT_EDIT(rb_1e30, d->params.render_budget = 1e30f; d->params.light_tolerance = 1e-30f)
XT_EDIT(rb_max, d->params.render_budget = FLT_MAX)
XT_EDIT(rb_hd_short, d->params.render_budget = 0.05f; d->params.light_tolerance = 1e-30f)
XT_EDIT(rb_cd_short, d->params.render_budget = 0.05f; d->params.light_tolerance = xt_denorm(); d->params.method = HD_METHOD_CD)
XT_EDIT(rb_ss_short, d->params.render_budget = 0.05f; d->params.method = HD_METHOD_PT_SS)
XT_EDIT(rb_ms_short, d->params.render_budget = 0.05f; d->params.method = HD_METHOD_PT_MS)
XT_EDIT(dt_one, d->params.depth_threshold = 1.0f)
XT_EDIT(dt_one_up, d->params.depth_threshold = xt_up(1.0f))
XT_EDIT(dt_denorm, d->params.depth_threshold = xt_denorm())
XT_EDIT(dt_neg0, d->params.depth_threshold = xt_neg0())
XT_EDIT(dt_neg_denorm, d->params.depth_threshold = -xt_denorm())
XT_EDIT(dt_max, d->params.depth_threshold = FLT_MAX)
static const xt_row xt_tolerance_rows[] = {
    {"light tolerance FLT_MAX", lt_max, HD_SUCCESS, 0},
    {"light tolerance 1e30", lt_1e30, HD_SUCCESS, 0},
    {"light tolerance denormal", lt_denorm, HD_SUCCESS, 0},
    {"light tolerance 1e-30", lt_1e_30, HD_SUCCESS, 0},
    {"light tolerance -0 (the default)", lt_neg0, HD_SUCCESS, 0},
    {"light tolerance -denormal", lt_neg_denorm, IP, 0},
    {"light tolerance -FLT_MAX", lt_neg_max, IP, 0},
    {"render budget denormal", rb_denorm, HD_SUCCESS, 0},
    {"render budget 1e-30", rb_1e_30, HD_SUCCESS, 0},
    {"render budget 1 ms, light tolerance 1e-30", rb_ms, HD_SUCCESS, 0},
    {"render budget -0 (the default)", rb_neg0, HD_SUCCESS, 0},
    {"render budget -denormal", rb_neg_denorm, IP, 0},
    {"render budget -FLT_MAX", rb_neg_max, IP, 0},
    {"depth threshold 1 (the bound)", dt_one, HD_SUCCESS, 0},
    {"depth threshold 1 + ulp", dt_one_up, IP, 0},
    {"depth threshold denormal", dt_denorm, HD_SUCCESS, 0},
    {"depth threshold -0 (the default)", dt_neg0, HD_SUCCESS, 0},
    {"depth threshold -denormal", dt_neg_denorm, IP, 0},
    {"depth threshold FLT_MAX", dt_max, IP, 0},
};
/* The budget's bound (10 s): above it rejected; at it, with light that converges, and with short
   budgets the light never meets, every hd_render call returns within its budget and a few seconds. */
static const xt_row xt_budget_rows[] = {
    {"HD, render budget 10 (the bound), default tolerance", rb_lim, HD_SUCCESS, XT_BOUNDED},
    {"render budget 10 + ulp", rb_lim_up, IP, 0},
    {"render budget 1e30, light tolerance 1e-30", rb_1e30, IP, 0},
    {"render budget FLT_MAX", rb_max, IP, 0},
    {"HD, render budget 0.05, light tolerance 1e-30", rb_hd_short, HD_SUCCESS, XT_BOUNDED},
    {"CD, render budget 0.05, light tolerance denormal", rb_cd_short, HD_SUCCESS, XT_BOUNDED},
    {"PT_SS, render budget 0.05", rb_ss_short, HD_SUCCESS, XT_BOUNDED},
    {"PT_MS, render budget 0.05", rb_ms_short, HD_SUCCESS, XT_BOUNDED},
};

static void test_value_range(void) { XT_ROWS(xt_value_range_rows); }
static void test_spacing(void) { XT_ROWS(xt_spacing_rows); }
static void test_background(void) { XT_ROWS(xt_background_rows); }
static void test_exposure(void) { XT_ROWS(xt_exposure_rows); }
static void test_medium(void) { XT_ROWS(xt_medium_rows); }
static void test_lights(void) { XT_ROWS(xt_light_rows); }
static void test_camera(void) { XT_ROWS(xt_camera_rows); }
static void test_crop(void) { XT_ROWS(xt_crop_rows); }
static void test_tolerance(void) { XT_ROWS(xt_tolerance_rows); }
static void test_budget_bounded(void) { XT_ROWS(xt_budget_rows); }

/* ---- NaN and Inf in every float field: its own code, one logged error, nothing changed ---- */
enum { XF_PARAMS, XF_CAMERA, XF_LIGHT, XF_POINT, XF_VOLUME, XF_TF };
typedef struct xt_field { const char *name; int part; size_t off; hd_result want; } xt_field;
#define XFP(f) {"params." #f, XF_PARAMS, offsetof(hd_params, f), IP}
#define XFC(f) {"camera." #f, XF_CAMERA, offsetof(hd_camera, f), IC}
#define XFL(f) {"directional light." #f, XF_LIGHT, offsetof(hd_light, f), IL}, \
               {"point light." #f, XF_POINT, offsetof(hd_light, f), IL}
static const xt_field xt_fields[] = {
    XFP(extinction), XFP(albedo), XFP(anisotropy), XFP(majorant), XFP(background[0]), XFP(background[1]),
    XFP(background[2]), XFP(step), XFP(exposure), XFP(light_tolerance), XFP(render_budget), XFP(depth_threshold), XFP(crop_min[0]),
    XFP(crop_min[1]), XFP(crop_min[2]), XFP(crop_max[0]), XFP(crop_max[1]), XFP(crop_max[2]),
    XFC(eye[0]), XFC(eye[1]), XFC(eye[2]), XFC(target[0]), XFC(target[1]), XFC(target[2]), XFC(up[0]),
    XFC(up[1]), XFC(up[2]), XFC(fov_y),
    XFL(direction[0]), XFL(direction[1]), XFL(direction[2]), XFL(position[0]), XFL(position[1]),
    XFL(position[2]), XFL(color[0]), XFL(color[1]), XFL(color[2]), XFL(intensity),
    {"volume.spacing[0]", XF_VOLUME, offsetof(hd_volume_desc, spacing[0]), HD_ERROR_INVALID_SPACING},
    {"volume.spacing[2]", XF_VOLUME, offsetof(hd_volume_desc, spacing[2]), HD_ERROR_INVALID_SPACING},
    {"volume.value_range[0]", XF_VOLUME, offsetof(hd_volume_desc, value_range[0]), IP},
    {"volume.value_range[1]", XF_VOLUME, offsetof(hd_volume_desc, value_range[1]), IP},
    {"transfer function entry 0 red", XF_TF, 0, HD_ERROR_INVALID_TRANSFER_FUNCTION},
    {"transfer function entry 1 alpha", XF_TF, 7, HD_ERROR_INVALID_TRANSFER_FUNCTION},
    {"transfer function entry 2 green", XF_TF, 9, HD_ERROR_INVALID_TRANSFER_FUNCTION},
};

static float xt_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* The field's float in desc d (its first light, its TF copy in xt_tf_buf). */
static float *xt_field_at(hd_desc *d, const xt_field *f)
{
    switch (f->part) {
    case XF_PARAMS: return (float *)(void *)((char *)&d->params + f->off);
    case XF_CAMERA: return (float *)(void *)((char *)&d->camera + f->off);
    case XF_LIGHT:
    case XF_POINT:
        xt_light_buf[0].type = f->part == XF_POINT ? HD_LIGHT_POINT : HD_LIGHT_DIRECTIONAL;
        return (float *)(void *)((char *)&xt_light_buf[0] + f->off);
    case XF_VOLUME:
        if (f->want == HD_ERROR_INVALID_SPACING) XT_SET3(d->volume.spacing, 1.0f);
        return (float *)(void *)((char *)&d->volume + f->off);
    default: return &xt_tf_buf[f->off];
    }
}

static void test_nan_inf_everywhere(void)
{
    const float values[5] = {xt_nan(), -xt_nan(), xt_inf(), -xt_inf(), xt_bits(0x7f800001u) /* signalling NaN */};
    static const char *vnames[5] = {"NaN", "-NaN", "+Inf", "-Inf", "sNaN"};
    size_t i;
    int k;
    for (i = 0; i < sizeof xt_fields / sizeof xt_fields[0]; ++i)
        for (k = 0; k < 5; ++k) {
            const xt_field *f = &xt_fields[i];
            hd_desc d;
            hd_context c;
            hd_result r;
            xt_snap s;
            char name[128];
            snprintf(name, sizeof name, "%s = %s", f->name, vnames[k]);
            /* hd_create */
            xt_base(&d);
            *xt_field_at(&d, f) = values[k];
            r = hd_create(&d, &c);
            xt_expect_rejected(r, f->want, name, "hd_create");
            if (r == HD_SUCCESS) hd_destroy(c);
            if (f->part == XF_VOLUME) continue;
            /* its setter, on a context that has run */
            xt_base(&d);
            if (f->part == XF_POINT) xt_light_buf[0].type = HD_LIGHT_POINT;
            if (hd_create(&d, &c) != HD_SUCCESS) { CHECK_MSG(0, "%s: base desc", name); continue; }
            CHECK(hd_iterate(c, 1) == HD_SUCCESS);
            xt_snap_take(c, &s);
            *xt_field_at(&d, f) = values[k];
            xt_log.errors = 0;
            r = f->part == XF_PARAMS ? hd_set_params(c, &d.params)
                : f->part == XF_CAMERA ? hd_set_camera(c, &d.camera)
                : f->part == XF_TF ? hd_set_transfer_function(c, &d.transfer_function)
                                   : hd_set_lights(c, d.lights, d.light_count);
            xt_expect_rejected(r, f->want, name, "setter");
            CHECK_MSG(xt_snap_same(c, &s), "%s: the rejected setter changed the context", name);
            CHECK_MSG(hd_iterate(c, 1) == HD_SUCCESS && xt_image_finite(c), "%s: the context no longer works", name);
            CHECK(hd_destroy(c) == HD_SUCCESS);
        }
}

/* hd_create(d) must fail with want (a context it makes anyway is destroyed). */
static void xt_create_rejected(const hd_desc *d, hd_result want, const char *name)
{
    hd_context c;
    hd_result r = hd_create(d, &c);
    xt_expect_rejected(r, want, name, "hd_create");
    if (r == HD_SUCCESS) hd_destroy(c);
}

/* ---- every enum out of range is HD_ERROR_INVALID_ENUM (hd_create and the setter alike) ---- */
typedef struct xt_enum { const char *name; size_t off; int count; } xt_enum;
static const xt_enum xt_param_enums[] = {
    {"params.method", offsetof(hd_params, method), HD_METHOD_COUNT},
    {"params.solver", offsetof(hd_params, solver), HD_SOLVER_COUNT},
    {"params.tracking", offsetof(hd_params, tracking), HD_TRACKING_COUNT},
    {"params.diffusion_boundary", offsetof(hd_params, diffusion_boundary), HD_BOUNDARY_COUNT},
    {"params.illumination_precision", offsetof(hd_params, illumination_precision), HD_PRECISION_COUNT},
    {"params.rest", offsetof(hd_params, rest), HD_REST_COUNT},
};

static void test_enums(void)
{
    size_t i;
    int k;
    for (k = 0; k < 4; ++k) {
        hd_desc d;
        hd_context c;
        xt_snap s;
        float buf[XT_VOX * 3];
        for (i = 0; i < sizeof xt_param_enums / sizeof xt_param_enums[0]; ++i) {
            const xt_enum *e = &xt_param_enums[i];
            int v = k == 0 ? e->count : k == 1 ? -1 : k == 2 ? INT_MAX : INT_MIN;
            char name[96];
            snprintf(name, sizeof name, "%s = %d", e->name, v);
            xt_base(&d);
            memcpy((char *)&d.params + e->off, &v, sizeof v);
            xt_create_rejected(&d, HD_ERROR_INVALID_ENUM, name);
            xt_base(&d);
            CHECK(hd_create(&d, &c) == HD_SUCCESS);
            xt_snap_take(c, &s);
            memcpy((char *)&d.params + e->off, &v, sizeof v);
            xt_log.errors = 0;
            xt_expect_rejected(hd_set_params(c, &d.params), HD_ERROR_INVALID_ENUM, name, "hd_set_params");
            CHECK_MSG(xt_snap_same(c, &s), "%s: the rejected setter changed the context", name);
            CHECK(hd_destroy(c) == HD_SUCCESS);
        }
        {
            int v = k == 0 ? HD_LIGHT_TYPE_COUNT : k == 1 ? -1 : k == 2 ? INT_MAX : INT_MIN;
            int t = k == 0 ? HD_VOXEL_COUNT : k == 1 ? HD_VOXEL_INVALID : k == 2 ? INT_MAX : INT_MIN;
            int w = k == 0 ? HD_ILLUMINATION_COUNT : k == 1 ? -1 : k == 2 ? INT_MAX : INT_MIN;
            int pr = k == 0 ? HD_PRESET_COUNT : k == 1 ? -1 : k == 2 ? INT_MAX : INT_MIN;
            int fm = k == 0 ? HD_FILE_FORMAT_COUNT : k == 1 ? -1 : k == 2 ? INT_MAX : INT_MIN;
            hd_params p;
            hd_load_options o;
            hd_volume_file vf;
            hd_logger lg;
            xt_base(&d);
            memcpy(&xt_light_buf[0].type, &v, sizeof v);
            xt_create_rejected(&d, HD_ERROR_INVALID_ENUM, "light type");
            xt_base(&d);
            memcpy(&d.volume.type, &t, sizeof t);
            xt_create_rejected(&d, HD_ERROR_INVALID_ENUM, "volume type");
            xt_base(&d);
            CHECK(hd_create(&d, &c) == HD_SUCCESS);
            CHECK(hd_iterate(c, 1) == HD_SUCCESS);
            xt_snap_take(c, &s);
            memcpy(&xt_light_buf[0].type, &v, sizeof v);
            xt_log.errors = 0;
            xt_expect_rejected(hd_set_lights(c, d.lights, 1), HD_ERROR_INVALID_ENUM, "light type", "hd_set_lights");
            xt_log.errors = 0;
            xt_expect_rejected(hd_read_illumination(c, (hd_illumination)w, buf, sizeof buf / sizeof buf[0]),
                               HD_ERROR_INVALID_ENUM, "illumination", "hd_read_illumination");
            CHECK_MSG(xt_snap_same(c, &s), "enum %d: a rejected call changed the context", k);
            CHECK(hd_destroy(c) == HD_SUCCESS);
            memset(&p, 0, sizeof p);
            lg = hd_test_logger(&xt_log);
            xt_expect_rejected(hd_params_preset((hd_preset)pr, &p, &lg), HD_ERROR_INVALID_ENUM, "preset", "hd_params_preset");
            memset(&o, 0, sizeof o);
            memcpy(&o.format, &fm, sizeof fm);
            lg = hd_test_logger(&xt_log);
            xt_expect_rejected(hd_volume_load_ex("data/head.nrrd", &o, &vf, &lg), HD_ERROR_INVALID_ENUM, "file format",
                               "hd_volume_load_ex");
        }
    }
}

/* ---- a destroyed context's logger is never called: its user data may be gone ---- */
static int xt_owner_gone, xt_calls_after;
static void xt_owner_log(void *user, hd_log_level level, hd_result code, const char *m, const char *f, int l)
{
    (void)level; (void)code; (void)m; (void)f; (void)l;
    if (*(const int *)user) ++xt_calls_after;
}

static void test_destroyed_logger(void)
{
    hd_desc d, q;
    hd_context c, other;
    hd_stats st;
    float f[XT_VOX * 3];
    uint8_t b[XW * XW * 4];
    hd_camera cam;
    int round, k;
    xt_base(&d);
    d.logger.func = xt_owner_log;
    d.logger.user_data = &xt_owner_gone;
    xt_owner_gone = 0;
    xt_calls_after = 0;
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_iterate(c, 1) == HD_SUCCESS);
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    cam = q.camera;
    CHECK(hd_destroy(c) == HD_SUCCESS);
    xt_owner_gone = 1; /* the caller freed what user_data pointed to */
    /* round 0: the slot empty; round 1: a new context (another logger) in it */
    for (round = 0; round < 2; ++round) {
        if (round == 1) {
            xt_base(&d);
            CHECK(hd_create(&d, &other) == HD_SUCCESS);
        }
        for (k = 0; k < 15; ++k) {
            hd_result r;
            switch (k) {
            case 0: r = hd_render(c); break;
            case 1: r = hd_iterate(c, 1); break;
            case 2: r = hd_refine(c, 1); break;
            case 3: r = hd_set_params(c, &q.params); break;
            case 4: r = hd_set_camera(c, &cam); break;
            case 5: r = hd_set_lights(c, xt_light_buf, 1); break;
            case 6: r = hd_set_transfer_function(c, &d.transfer_function); break;
            case 7: r = hd_read_image_rgba8(c, b, sizeof b); break;
            case 8: r = hd_read_image_f32(c, f, XW * XW * 4); break;
            case 9: r = hd_read_illumination(c, HD_ILLUMINATION_DIRECT, f, sizeof f / sizeof f[0]); break;
            case 10: r = hd_get_stats(c, &st); break;
            case 11: r = hd_query_desc(c, &q); break;
            case 12: r = hd_vulkan_record(c, NULL, 1); break;
            case 13: r = hd_gl_render_to_texture(c, 1); break;
            default: r = hd_destroy(c); break;
            }
            CHECK_MSG(r == HD_ERROR_INVALID_HANDLE, "round %d call %d: %s", round, k, hd_result_string(r));
            CHECK_MSG(xt_calls_after == 0, "round %d call %d: the destroyed context's logger was called", round, k);
            xt_calls_after = 0;
        }
    }
    CHECK(hd_destroy(other) == HD_SUCCESS);
}

/* ---- PT_MS: its image is its state, so whatever the image depends on restarts the mean ---- */
XT_EDIT(pm_bounces, d->params.max_bounces = 2)
XT_EDIT(pm_bounces1, d->params.max_bounces = 1)
XT_EDIT(pm_albedo, d->params.albedo = 0.5f)
XT_EDIT(pm_aniso, d->params.anisotropy = 0.5f)
XT_EDIT(pm_ext, d->params.extinction = 20.0f)
XT_EDIT(pm_seed, d->params.seed = 7)
XT_EDIT(pm_bg, d->params.background[1] = 0.25f)
XT_EDIT(pm_crop, d->params.crop_max[0] = 0.5f)
static void test_path_restart(void)
{
    static void (*const edits[])(hd_desc *) = {pm_bounces, pm_bounces1, pm_albedo, pm_aniso, pm_ext, pm_seed, pm_bg, pm_crop};
    static const char *names[] = {"max_bounces 2", "max_bounces 1", "albedo", "anisotropy", "extinction", "seed",
                                  "background", "crop box"};
    size_t i;
    for (i = 0; i < sizeof edits / sizeof edits[0]; ++i) {
        float a[XW * XW * 4], b[XW * XW * 4];
        hd_desc d;
        hd_context c, fresh;
        hd_stats st;
        xt_base(&d);
        d.params.method = HD_METHOD_PT_MS;
        CHECK(hd_create(&d, &c) == HD_SUCCESS);
        CHECK(hd_iterate(c, 3) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS && st.frames == 3);
        edits[i](&d);
        CHECK(hd_set_params(c, &d.params) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS);
        CHECK_MSG(st.frames == 0 && st.iterations == 0, "PT_MS, %s changed: %llu frames, %llu iterations kept", names[i],
                  (unsigned long long)st.frames, (unsigned long long)st.iterations);
        /* the restarted mean is the one a new context with the new setting makes */
        CHECK(hd_iterate(c, 1) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS && st.frames == 1);
        CHECK(hd_create(&d, &fresh) == HD_SUCCESS);
        CHECK(hd_iterate(fresh, 1) == HD_SUCCESS);
        CHECK(hd_read_image_f32(c, a, sizeof a / sizeof a[0]) == HD_SUCCESS);
        CHECK(hd_read_image_f32(fresh, b, sizeof b / sizeof b[0]) == HD_SUCCESS);
        CHECK_MSG(memcmp(a, b, sizeof a) == 0, "PT_MS, %s changed: the image is not that of a new context", names[i]);
        CHECK(hd_destroy(fresh) == HD_SUCCESS);
        CHECK(hd_destroy(c) == HD_SUCCESS);
    }
}

/* ---- every float of hd_params has rows: a new table row must be listed here, a float one with
   rows at its bounds (a row whose name holds the field's name, '_' read as ' ') and NaN/Inf ---- */
int hdt_param_rows(void);
const char *hdt_param_row(int i, size_t *offset, size_t *size, unsigned *invalidates);
static int xt_rows_name(const xt_row *rows, size_t n, const char *words)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (strstr(rows[i].name, words)) return 1;
    return 0;
}
#define XT_ROWS_NAME(rows, w) xt_rows_name(rows, sizeof rows / sizeof rows[0], w)
static void test_float_coverage(void)
{
    static const char *not_float[] = {"method", "solver", "diffusion_sweeps", "disable_diffusion", "tracking", "seed",
                                      "frame_window", "max_bounces", "illumination_downsample", "rgb_scattering",
                                      "diffusion_boundary", "illumination_precision", "render_scale", "light_window", "rest",
                                      "refine_bounces", "environment_background"};
    int i, rows = hdt_param_rows();
    CHECK(rows >= 24);
    for (i = 0; i < rows; ++i) {
        size_t off, size, k;
        unsigned inv;
        const char *name = hdt_param_row(i, &off, &size, &inv);
        char words[64], full[80];
        int listed = 0, covered;
        for (k = 0; k < sizeof not_float / sizeof not_float[0]; ++k) listed |= strcmp(name, not_float[k]) == 0;
        if (listed) continue;
        snprintf(words, sizeof words, "%s", name);
        for (k = 0; words[k]; ++k)
            if (words[k] == '_') words[k] = ' ';
        covered = XT_ROWS_NAME(xt_background_rows, words) || XT_ROWS_NAME(xt_exposure_rows, words) ||
                  XT_ROWS_NAME(xt_medium_rows, words) || XT_ROWS_NAME(xt_crop_rows, words) ||
                  XT_ROWS_NAME(xt_tolerance_rows, words) || XT_ROWS_NAME(xt_budget_rows, words);
        CHECK_MSG(covered, "params.%s: no row of test_extremes.c at its bounds (or list it as not a float)", name);
        snprintf(full, sizeof full, "params.%s", name);
        for (k = 0, covered = 0; k < sizeof xt_fields / sizeof xt_fields[0]; ++k)
            covered |= strncmp(xt_fields[k].name, full, strlen(full)) == 0;
        CHECK_MSG(covered, "params.%s: not in test_extremes.c's NaN and Inf fields", name);
    }
}

/* Names avoid the valgrind suites' filters (mk/reliability.mk, VG_SUITES). */
const hd_test_case hd_tests_extremes[] = {
    {"extremes: value range", test_value_range},
    {"extremes: spacing", test_spacing},
    {"extremes: background", test_background},
    {"extremes: background 1e6 over many frames", test_background_reduced},
    {"extremes: exposure", test_exposure},
    {"extremes: medium", test_medium},
    {"extremes: lights", test_lights},
    {"extremes: camera", test_camera},
    {"extremes: crop box", test_crop},
    {"extremes: light tolerance and budget", test_tolerance},
    {"extremes: render budget bounded", test_budget_bounded},
    {"extremes: NaN and Inf in every float", test_nan_inf_everywhere},
    {"extremes: every enum out of range", test_enums},
    {"extremes: destroyed context's logger", test_destroyed_logger},
    {"extremes: PT_MS settings restart the mean", test_path_restart},
    {"extremes: every float of hd_params has rows", test_float_coverage},
};
const int hd_tests_extremes_count = sizeof hd_tests_extremes / sizeof hd_tests_extremes[0];
