/* fuzz_state.c - libFuzzer target: the public API as a state machine (mk/reliability.mk:
   make fuzz-smoke-state, fuzz-long-state; seeds in regressions/state/).
   The bytes become a sequence of up to FZ_OPS calls on up to two live contexts and the handles
   of destroyed ones: hd_create (a volume of each voxel type, at most 8^3, value ranges at the
   float limit; a camera of at most 16x16), every setter with the current settings edited in one
   to three fields (valid, boundary, finite-extreme and invalid values: FLT_MAX, 3e38, 1e+-30,
   denormals, -0, NaN, Inf, enums out of range), hd_params_preset, hd_iterate, hd_refine,
   hd_render (up to 12 frames; one where a render budget is set), every read-back, hd_get_stats, hd_query_desc, the other backends'
   calls, destroy, calls on destroyed, zero and forged handles. After every call:
   - the result is one the documented rules allow for that input (fz_*_want below: e.g. an enum
     out of range is HD_ERROR_INVALID_ENUM, a NaN parameter HD_ERROR_INVALID_PARAMETER), and a
     valid input succeeds;
   - a rejected call logged exactly one error with its code, allocated nothing and changed
     nothing hd_query_desc and hd_get_stats show (timings apart); a call on a destroyed handle
     is HD_ERROR_INVALID_HANDLE and calls no destroyed context's logger or allocator;
   - an accepted setter stored its input with the documented defaults filled in, and restarted
     what the documented invalidation rules say depends on it (hybriddiff.h, the setters; the
     path tracers' image is their state) and nothing when it changed only solver, sweeps,
     tracking, exposure, light tolerance or render budget;
   - every image and illumination volume read back is finite (alpha in [0, 1], E >= 0), RGBA8
     is the sRGB encoding of radiance * exposure, hd_refine and an hd_render that added no frame
     leave the image as it was, a read changes nothing, and a new HD or CD context's first frame
     has the alpha of the same voxels normalised in double (a value range whose width overflows
     must still map them);
   - a destroyed context freed everything it allocated, and no call took more than
     FZ_CALL_SECONDS (libFuzzer's -timeout catches one that never returns).
   A failure prints what broke and aborts, which keeps the input. HD_FZ_TRACE=1 in the
   environment prints every call as C, for a reproducer. Work per input stays small: valid
   values that only cost time (extinction above 2000, majorants above 4000, 10^5 sweeps or
   bounces, n = 2^31 iterations) are not drawn, valid render budgets above FZ_BUDGET_FAST are
   drawn as FZ_BUDGET_FAST (those above the 10 s bound as they are: rejected), and an input's
   calls stop after FZ_INPUT_SECONDS. */
#include "hybriddiff.h" /* the implementation: tests/fuzz/hd_impl_fuzz.c */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define FZ_DIM 8            /* volume side */
#define FZ_IMG 16           /* image side */
#define FZ_TF 8             /* transfer function entries */
#define FZ_OPS 48           /* calls per input after the first hd_create */
#define FZ_CTX 2            /* live contexts */
#define FZ_STALE 4          /* destroyed handles kept */
#define FZ_OWNERS (FZ_CTX + 2) /* live contexts, one being created, a reference */
#define FZ_CALL_SECONDS 5.0 /* the longest any one call may take (sanitizer build, loaded machine) */
#define FZ_INPUT_SECONDS 8.0 /* an input's calls stop after this long (-timeout stays for a hang) */
#define FZ_BUDGET_FAST 0.001f /* valid render budgets above this are drawn as this */
#define FZ_BUDGET_MAX 10.0f   /* params.render_budget's bound (hybriddiff.h) */
#define FZ_BACKGROUND_MAX 1e6f /* params.background's bound per component */

/* ---- the bytes ---------------------------------------------------------------------------- */
static const uint8_t *fz_p;
static size_t fz_n, fz_at;
static uint8_t fz_u8(void) { return fz_at < fz_n ? fz_p[fz_at++] : 0; }
static int fz_more(void) { return fz_at < fz_n; }

static float fz_bits(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* Any float: mostly finite extremes and boundaries, some NaN and Inf, sometimes raw bits. */
static float fz_float(void)
{
    static const float table[] = {
        0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 2.0f, 0.25f, 3.0f, 16.0f, 100.0f, 0.01f, 1e-30f, -1e-30f, 1e30f,
        -1e30f, FLT_MIN, -FLT_MIN, FLT_MIN / 4096.0f, -FLT_MIN / 4096.0f, 1e-45f, FLT_MAX, -FLT_MAX, 3e38f,
        -3e38f, 1e-6f, 1e6f, -1e6f, 1e15f, 1e4f, 65536.0f, 0.999999f, 1.0000001f, 16.000002f, 0.0099999f,
        1e-3f, 179.99998f, 180.0f, 40.0f, 1e-4f, 0.1f, 1e15f * 1.0000001f, 1e4f * 1.0000001f};
    uint8_t b = fz_u8();
    if (b < 232) return table[b % (sizeof table / sizeof table[0])];
    if (b < 236) return NAN;
    if (b < 238) return -NAN;
    if (b < 242) return INFINITY;
    if (b < 246) return -INFINITY;
    if (b < 248) return fz_bits(0x7f800001u); /* signalling NaN */
    return fz_bits((uint32_t)fz_u8() | (uint32_t)fz_u8() << 8 | (uint32_t)fz_u8() << 16 | (uint32_t)fz_u8() << 24);
}

/* A float for a field: mostly one of its usual values, else any float. */
static float fz_pick(const float *usual, int n)
{
    uint8_t b = fz_u8();
    return b < 150 ? usual[b % n] : fz_float();
}
#define FZ_PICK(...) fz_pick((const float[]){__VA_ARGS__}, (int)(sizeof((const float[]){__VA_ARGS__}) / sizeof(float)))

/* An int: mostly one of its usual values, else an edge. */
static int fz_int(const int *usual, int n)
{
    static const int edge[] = {-1, -2, INT_MAX, INT_MIN, 3, 9, 100000, 100001, 16385};
    uint8_t b = fz_u8();
    return b < 200 ? usual[b % n] : edge[b % (sizeof edge / sizeof edge[0])];
}
#define FZ_INT(...) fz_int((const int[]){__VA_ARGS__}, (int)(sizeof((const int[]){__VA_ARGS__}) / sizeof(int)))

/* An enum value: mostly in range, else COUNT, -1, INT_MAX or INT_MIN. */
static int fz_enum(int count)
{
    uint8_t b = fz_u8();
    if (b < 220) return b % count;
    return b < 230 ? count : b < 240 ? -1 : b < 248 ? INT_MAX : INT_MIN;
}

static int fz_finite(float v) { return v == v && v - v == 0.0f; }
static int fz_finite3(const float v[3]) { return fz_finite(v[0]) && fz_finite(v[1]) && fz_finite(v[2]); }

/* ---- failure and trace ---------------------------------------------------------------------- */
static int fz_trace;
static int fz_step;
static const char *fz_call = "hd_create";

static void fz_fail(const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "fuzz_state: call %d (%s): ", fz_step, fz_call);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    abort();
}

static void fz_tr(const char *fmt, ...)
{
    va_list ap;
    if (!fz_trace) return;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
}

/* A float as C source. */
static const char *fz_cf(float v, char *buf)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    if (v != v) snprintf(buf, 40, "fz_bits(0x%08xu)", (unsigned)u);
    else if (v == INFINITY) snprintf(buf, 40, "INFINITY");
    else if (v == -INFINITY) snprintf(buf, 40, "-INFINITY");
    else if (v == 0.0f) snprintf(buf, 40, u ? "-0.0f" : "0.0f");
    else {
        snprintf(buf, 40, "%.9g", (double)v);
        strcat(buf, strpbrk(buf, ".en") ? "f" : ".0f");
    }
    return buf;
}

static void fz_tr_f(const char *what, const float *v, int n)
{
    int i;
    char b[40];
    for (i = 0; i < n; ++i)
        if (v[i] != 0.0f || signbit(v[i]) || v[i] != v[i]) {
            if (n > 1) fz_tr("    %s[%d] = %s;\n", what, i, fz_cf(v[i], b));
            else fz_tr("    %s = %s;\n", what, fz_cf(v[i], b));
        }
}
static void fz_tr_i(const char *what, int v) { if (v) fz_tr("    %s = %d;\n", what, v); }

static void fz_tr_params(const char *p, const hd_params *q)
{
    char w[64];
#define FZ_TRF(f, n) snprintf(w, sizeof w, "%s." #f, p), fz_tr_f(w, (const float *)&q->f, n)
#define FZ_TRI(f) snprintf(w, sizeof w, "%s." #f, p), fz_tr_i(w, (int)q->f)
    fz_tr("    memset(&%s, 0, sizeof %s);\n", p, p);
    FZ_TRI(method); FZ_TRF(extinction, 1); FZ_TRF(albedo, 1); FZ_TRF(anisotropy, 1); FZ_TRF(majorant, 1);
    FZ_TRI(diffusion_sweeps); FZ_TRI(disable_diffusion); FZ_TRI(solver); FZ_TRI(tracking); FZ_TRI(seed);
    FZ_TRF(background, 3); FZ_TRF(step, 1); FZ_TRI(frame_window); FZ_TRF(exposure, 1); FZ_TRI(max_bounces);
    FZ_TRI(illumination_downsample); FZ_TRI(rgb_scattering); FZ_TRI(diffusion_boundary);
    FZ_TRI(illumination_precision); FZ_TRF(light_tolerance, 1); FZ_TRF(render_budget, 1); FZ_TRF(crop_min, 3);
    FZ_TRF(crop_max, 3); FZ_TRI(render_scale); FZ_TRF(depth_threshold, 1);
    FZ_TRI(environment_background);
#undef FZ_TRF
#undef FZ_TRI
}

static void fz_tr_camera(const char *p, const hd_camera *c)
{
    char w[64];
    fz_tr("    memset(&%s, 0, sizeof %s);\n", p, p);
    snprintf(w, sizeof w, "%s.eye", p); fz_tr_f(w, c->eye, 3);
    snprintf(w, sizeof w, "%s.target", p); fz_tr_f(w, c->target, 3);
    snprintf(w, sizeof w, "%s.up", p); fz_tr_f(w, c->up, 3);
    snprintf(w, sizeof w, "%s.fov_y", p); fz_tr_f(w, &c->fov_y, 1);
    snprintf(w, sizeof w, "%s.width", p); fz_tr_i(w, c->width);
    snprintf(w, sizeof w, "%s.height", p); fz_tr_i(w, c->height);
}

static void fz_tr_lights(const hd_light *l, int n)
{
    char w[64];
    int i;
    if (!l) return;
    fz_tr("    memset(lights, 0, sizeof lights);\n");
    for (i = 0; i < n && i < 4; ++i) {
        snprintf(w, sizeof w, "lights[%d].type", i); fz_tr_i(w, (int)l[i].type);
        snprintf(w, sizeof w, "lights[%d].direction", i); fz_tr_f(w, l[i].direction, 3);
        snprintf(w, sizeof w, "lights[%d].position", i); fz_tr_f(w, l[i].position, 3);
        snprintf(w, sizeof w, "lights[%d].color", i); fz_tr_f(w, l[i].color, 3);
        snprintf(w, sizeof w, "lights[%d].intensity", i); fz_tr_f(w, &l[i].intensity, 1);
        snprintf(w, sizeof w, "lights[%d].inverse_square", i); fz_tr_i(w, l[i].inverse_square);
        snprintf(w, sizeof w, "lights[%d].edge1", i); fz_tr_f(w, l[i].edge1, 3);
        snprintf(w, sizeof w, "lights[%d].edge2", i); fz_tr_f(w, l[i].edge2, 3);
        snprintf(w, sizeof w, "lights[%d].radius", i); fz_tr_f(w, &l[i].radius, 1);
    }
}

static void fz_tr_tf(const hd_transfer_function *t)
{
    char w[64];
    int i;
    if (!t->rgba) return;
    for (i = 0; i < 4 * t->count && i < 4 * FZ_TF; ++i) {
        snprintf(w, sizeof w, "tf[%d]", i);
        fz_tr("    %s = %s;\n", w, fz_cf(t->rgba[i], w + 32));
    }
}

static double fz_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* ---- owners: each context's logger and allocator user data, freed when it is destroyed ------- */
typedef struct fz_owner {
    int errors, other;
    hd_result code;
    long calls, live;
} fz_owner;
static fz_owner *fz_owners[FZ_OWNERS]; /* live: the contexts', one being created, a reference */

static int fz_owner_live(const void *u)
{
    int i;
    for (i = 0; i < FZ_OWNERS; ++i)
        if (u && fz_owners[i] == u) return 1;
    return 0;
}

static void fz_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    fz_owner *o = (fz_owner *)u;
    (void)file; (void)line;
    if (!fz_owner_live(u)) fz_fail("a destroyed context's logger was called (%s: %s)", hd_result_string(code), msg ? msg : "");
    if (!msg || !msg[0]) fz_fail("a log message is empty");
    if (level == HD_LOG_ERROR) { ++o->errors; o->code = code; }
    else ++o->other;
    fz_tr("    /* log %d: %s: %s */\n", (int)level, hd_result_string(code), msg);
}

static void *fz_alloc(size_t size, void *u)
{
    fz_owner *o = (fz_owner *)u;
    void *p;
    if (!fz_owner_live(u)) fz_fail("a destroyed context's allocator was called");
    ++o->calls;
    p = malloc(size ? size : 1);
    if (p) ++o->live;
    return p;
}

static void fz_free(void *ptr, void *u)
{
    fz_owner *o = (fz_owner *)u;
    if (!fz_owner_live(u)) fz_fail("a destroyed context's free was called");
    if (ptr) --o->live;
    free(ptr);
}

static fz_owner *fz_owner_new(void)
{
    int i;
    fz_owner *o = (fz_owner *)calloc(1, sizeof *o);
    if (!o) abort();
    for (i = 0; i < FZ_OWNERS; ++i)
        if (!fz_owners[i]) { fz_owners[i] = o; return o; }
    abort();
}

static void fz_owner_free(fz_owner *o)
{
    int i;
    for (i = 0; i < FZ_OWNERS; ++i)
        if (fz_owners[i] == o) fz_owners[i] = NULL;
    free(o);
}

/* ---- allowed results ------------------------------------------------------------------------- */
typedef uint64_t fz_set;
#define FZ_R(r) ((fz_set)1 << (r))
#define FZ_OK FZ_R(HD_SUCCESS)
#define IP HD_ERROR_INVALID_PARAMETER
#define IE HD_ERROR_INVALID_ENUM

static int fz_bad_enum(int v, int count) { return v < 0 || v >= count; }

/* hd_params with the documented defaults (hybriddiff.h, hd_params) filled in. */
static void fz_params_defaults(hd_params *p)
{
    int i;
    if (p->method == HD_METHOD_DEFAULT) p->method = HD_METHOD_HD;
    if (p->extinction == 0.0f) p->extinction = 100.0f;
    if (p->albedo == 0.0f) p->albedo = 0.9f;
    if (p->solver == HD_SOLVER_DEFAULT) p->solver = HD_SOLVER_RED_BLACK; /* AUTO: the volumes here are far below 4 M voxels */
    if (p->diffusion_sweeps == 0) p->diffusion_sweeps = p->solver == HD_SOLVER_MULTIGRID ? 1 : 4;
    if (p->tracking == HD_TRACKING_DEFAULT) p->tracking = HD_TRACKING_RATIO;
    if (p->step == 0.0f) p->step = 0.5f;
    if (p->frame_window == 0) p->frame_window = 8;
    if (p->exposure == 0.0f) p->exposure = 1.0f;
    if (p->max_bounces == 0) p->max_bounces = 64;
    if (p->illumination_downsample == 0) p->illumination_downsample = 2;
    if (p->diffusion_boundary == HD_BOUNDARY_DEFAULT) p->diffusion_boundary = HD_BOUNDARY_SURFACE;
    if (p->light_tolerance == 0.0f) p->light_tolerance = 0.1f;
    if (p->render_scale == 0) p->render_scale = 1;
    if (p->light_window == 0) p->light_window = 8;
    if (p->depth_threshold == 0.0f) p->depth_threshold = 0.5f;
    if (p->refine_bounces == 0) p->refine_bounces = -1;
    if (p->rest == HD_REST_DEFAULT) p->rest = HD_REST_HOLD;
    for (i = 0; i < 3; ++i)
        if (p->crop_max[i] == 0.0f) p->crop_max[i] = 1.0f;
    /* a float whose default is 0 is stored as +0 (src/hd_params.h: a zero field gets its default) */
    if (p->anisotropy == 0.0f) p->anisotropy = 0.0f;
    if (p->majorant == 0.0f) p->majorant = 0.0f;
    if (p->render_budget == 0.0f) p->render_budget = 0.0f;
    for (i = 0; i < 3; ++i) {
        if (p->background[i] == 0.0f) p->background[i] = 0.0f;
        if (p->crop_min[i] == 0.0f) p->crop_min[i] = 0.0f;
    }
}

/* What hd_set_params (and hd_create's params) may return for *p (defaults filled in). */
static fz_set fz_params_want(const hd_params *p)
{
    fz_set bad = 0;
    int i;
    if (fz_bad_enum((int)p->method, HD_METHOD_COUNT) || fz_bad_enum((int)p->solver, HD_SOLVER_COUNT) ||
        fz_bad_enum((int)p->tracking, HD_TRACKING_COUNT) || fz_bad_enum((int)p->diffusion_boundary, HD_BOUNDARY_COUNT) ||
        fz_bad_enum((int)p->illumination_precision, HD_PRECISION_COUNT))
        bad |= FZ_R(IE);
    if (!fz_finite(p->extinction) || p->extinction < 0.0f || p->extinction > 1e6f) bad |= FZ_R(IP);
    if (!fz_finite(p->albedo) || p->albedo < 0.0f || p->albedo > 1.0f) bad |= FZ_R(IP);
    if (!fz_finite(p->anisotropy) || !(p->anisotropy > -1.0f && p->anisotropy < 1.0f)) bad |= FZ_R(IP);
    if (!fz_finite(p->majorant) || p->majorant < 0.0f || p->majorant > 1e6f) bad |= FZ_R(IP);
    if (p->diffusion_sweeps < 0 || p->diffusion_sweeps > 100000) bad |= FZ_R(IP);
    if (p->disable_diffusion != 0 && p->disable_diffusion != 1) bad |= FZ_R(IP);
    for (i = 0; i < 3; ++i)
        if (!fz_finite(p->background[i]) || !(p->background[i] >= 0.0f && p->background[i] <= FZ_BACKGROUND_MAX)) bad |= FZ_R(IP);
    if (!fz_finite(p->step) || !(p->step >= 0.01f && p->step <= 16.0f)) bad |= FZ_R(IP);
    if (p->frame_window < 0) bad |= FZ_R(IP);
    if (!fz_finite(p->exposure) || p->exposure < 0.0f) bad |= FZ_R(IP);
    if (p->max_bounces < 0 || p->max_bounces > 100000) bad |= FZ_R(IP);
    if (p->illumination_downsample < 1 || p->illumination_downsample > 8) bad |= FZ_R(IP);
    if (p->rgb_scattering != 0 && p->rgb_scattering != 1) bad |= FZ_R(IP);
    if (p->environment_background != 0 && p->environment_background != 1) bad |= FZ_R(IP);
    if (!fz_finite(p->light_tolerance) || p->light_tolerance < 0.0f) bad |= FZ_R(IP);
    if (!fz_finite(p->render_budget) || !(p->render_budget >= 0.0f && p->render_budget <= FZ_BUDGET_MAX)) bad |= FZ_R(IP);
    if (p->render_scale != HD_RENDER_SCALE_AUTO && (p->render_scale < 1 || p->render_scale > 8)) bad |= FZ_R(IP);
    if (p->light_window < 1 || p->light_window > 1000000) bad |= FZ_R(IP);
    if (!fz_finite(p->depth_threshold) || !(p->depth_threshold >= 0.0f && p->depth_threshold <= 1.0f)) bad |= FZ_R(IP);
    if (fz_bad_enum((int)p->rest, HD_REST_COUNT)) bad |= FZ_R(IE);
    if (p->refine_bounces < -1 || p->refine_bounces > 100000) bad |= FZ_R(IP);
    for (i = 0; i < 3; ++i)
        if (!fz_finite(p->crop_min[i]) || !fz_finite(p->crop_max[i]) || !(p->crop_min[i] >= 0.0f) ||
            !(p->crop_max[i] <= 1.0f) || !(p->crop_min[i] < p->crop_max[i]))
            bad |= FZ_R(IP);
    if (p->illumination_precision == HD_PRECISION_FLOAT16 && p->solver == HD_SOLVER_MULTIGRID) bad |= FZ_R(HD_ERROR_UNSUPPORTED);
    if (bad) return bad;
    /* a global majorant is checked against the TF's largest extinction */
    return FZ_OK | (p->majorant > 0.0f ? FZ_R(IP) : 0);
}

static void fz_camera_defaults(hd_camera *c)
{
    int i, zero = 1;
    for (i = 0; i < 3; ++i) zero &= c->eye[i] == 0.0f && c->target[i] == 0.0f;
    if (zero) c->eye[2] = 2.5f;
    if (c->up[0] == 0.0f && c->up[1] == 0.0f && c->up[2] == 0.0f) c->up[1] = 1.0f;
    if (c->fov_y == 0.0f) c->fov_y = 40.0f;
    if (c->width == 0) c->width = 512;
    if (c->height == 0) c->height = 512;
}

static fz_set fz_camera_want(const hd_camera *c)
{
    double f[3], fl = 0.0, cr[3], cl;
    fz_set bad = 0;
    int i;
    if (!fz_finite3(c->eye) || !fz_finite3(c->target) || !fz_finite3(c->up) || !fz_finite(c->fov_y))
        return FZ_R(HD_ERROR_INVALID_CAMERA) | (c->width < 1 || c->height < 1 || c->width > HD_MAX_IMAGE_DIM || c->height > HD_MAX_IMAGE_DIM ? FZ_R(HD_ERROR_INVALID_DIMENSIONS) : 0);
    for (i = 0; i < 3; ++i)
        if (fabsf(c->eye[i]) > HD_MAX_CAMERA_DISTANCE || fabsf(c->target[i]) > HD_MAX_CAMERA_DISTANCE) bad |= FZ_R(HD_ERROR_INVALID_CAMERA);
    if (!(c->fov_y > 0.0f && c->fov_y < 180.0f)) bad |= FZ_R(HD_ERROR_INVALID_CAMERA);
    if (c->width < 1 || c->height < 1 || c->width > HD_MAX_IMAGE_DIM || c->height > HD_MAX_IMAGE_DIM)
        bad |= FZ_R(HD_ERROR_INVALID_DIMENSIONS);
    if (bad) return bad;
    /* degenerate: eye on the target, up along the view (near either limit: either answer) */
    {
        double um = 0.0, u[3], ul = 0.0;
        for (i = 0; i < 3; ++i) {
            if (fabs((double)c->up[i]) > um) um = fabs((double)c->up[i]);
            f[i] = (double)c->target[i] - (double)c->eye[i];
            fl += f[i] * f[i];
        }
        fl = sqrt(fl);
        if (fl < 0.5e-6) return FZ_R(HD_ERROR_INVALID_CAMERA);
        for (i = 0; i < 3; ++i) { u[i] = (double)c->up[i] / um; ul += u[i] * u[i]; }
        ul = sqrt(ul);
        cr[0] = f[1] * u[2] - f[2] * u[1];
        cr[1] = f[2] * u[0] - f[0] * u[2];
        cr[2] = f[0] * u[1] - f[1] * u[0];
        cl = sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]) / (fl * ul);
    }
    if (fl < 2e-6 || cl < 1e-3) return FZ_OK | FZ_R(HD_ERROR_INVALID_CAMERA);
    return FZ_OK;
}

static void fz_light_defaults(hd_light *l)
{
    if (l->color[0] == 0.0f && l->color[1] == 0.0f && l->color[2] == 0.0f) l->color[0] = l->color[1] = l->color[2] = 1.0f;
    if (l->intensity == 0.0f) l->intensity = 1.0f;
}

/* An area light's shape breaks a rule (hybriddiff.h, hd_light): a NaN or infinite edge or
   radius; a quad's edge beyond HD_MAX_LIGHT_DISTANCE, zero or parallel to the other; a disk's or
   sphere's radius outside (0, HD_MAX_LIGHT_DISTANCE], a disk's zero normal. */
static int fz_area_bad(const hd_light *l)
{
    double a[3], b[3], c[3], la, lb;
    int k;
    if (!fz_finite3(l->edge1) || !fz_finite3(l->edge2) || !fz_finite(l->radius)) return 1;
    if (l->type == HD_LIGHT_QUAD) {
        for (k = 0; k < 3; ++k)
            if (fabsf(l->edge1[k]) > HD_MAX_LIGHT_DISTANCE || fabsf(l->edge2[k]) > HD_MAX_LIGHT_DISTANCE) return 1;
        for (k = 0; k < 3; ++k) { a[k] = l->edge1[k]; b[k] = l->edge2[k]; }
        la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        if (!(la > 0.0) || !(lb > 0.0)) return 1;
        c[0] = a[1] * b[2] - a[2] * b[1]; c[1] = a[2] * b[0] - a[0] * b[2]; c[2] = a[0] * b[1] - a[1] * b[0];
        return !((c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) / (la * la * lb * lb) > 1e-8);
    }
    if (!(l->radius > 0.0f) || l->radius > HD_MAX_LIGHT_DISTANCE) return 1;
    return l->type == HD_LIGHT_DISK && l->direction[0] == 0.0f && l->direction[1] == 0.0f && l->direction[2] == 0.0f;
}

/* Whether lights l[0..n) hold an area light (which method CD refuses). */
static int fz_has_area(const hd_light *l, int n)
{
    int i;
    for (i = 0; l && i < n; ++i)
        if (l[i].type >= HD_LIGHT_QUAD && l[i].type < HD_LIGHT_TYPE_COUNT) return 1;
    return 0;
}

/* hd_set_lights (hybriddiff.h, hd_light and the limits above it): the codes of the first light
   that breaks a rule (the power limit counts the lights up to it). */
static fz_set fz_lights_want(const hd_light *l, int n)
{
    double power = 0.0;
    int i;
    if (n <= 0) return FZ_R(HD_ERROR_NO_LIGHTS);
    if (n > HD_MAX_LIGHTS) return FZ_R(HD_ERROR_TOO_MANY_LIGHTS);
    if (!l) return FZ_R(HD_ERROR_NULL_POINTER);
    for (i = 0; i < n; ++i) {
        fz_set bad = 0;
        double cmax;
        if (fz_bad_enum((int)l[i].type, HD_LIGHT_TYPE_COUNT)) bad |= FZ_R(IE);
        if (!fz_finite3(l[i].direction) || !fz_finite3(l[i].position) || !fz_finite3(l[i].color) || !fz_finite(l[i].intensity) ||
            l[i].color[0] < 0.0f || l[i].color[1] < 0.0f || l[i].color[2] < 0.0f || l[i].intensity < 0.0f) {
            bad |= FZ_R(HD_ERROR_INVALID_LIGHT);
            return bad;
        }
        if (l[i].type == HD_LIGHT_DIRECTIONAL && l[i].direction[0] == 0.0f && l[i].direction[1] == 0.0f && l[i].direction[2] == 0.0f)
            bad |= FZ_R(HD_ERROR_INVALID_LIGHT);
        if (l[i].type >= HD_LIGHT_QUAD && l[i].type < HD_LIGHT_TYPE_COUNT && fz_area_bad(&l[i])) {
            bad |= FZ_R(HD_ERROR_INVALID_LIGHT);
            return bad;
        }
        if (l[i].type != HD_LIGHT_DIRECTIONAL && (fabsf(l[i].position[0]) > HD_MAX_LIGHT_DISTANCE ||
                                            fabsf(l[i].position[1]) > HD_MAX_LIGHT_DISTANCE ||
                                            fabsf(l[i].position[2]) > HD_MAX_LIGHT_DISTANCE))
            bad |= FZ_R(HD_ERROR_INVALID_LIGHT);
        cmax = l[i].color[0] > l[i].color[1] ? l[i].color[0] : l[i].color[1];
        if (l[i].color[2] > cmax) cmax = l[i].color[2];
        power += (l[i].intensity == 0.0f ? 1.0 : (double)l[i].intensity) * (cmax == 0.0 ? 1.0 : cmax);
        if (!(power <= (double)HD_MAX_LIGHT_POWER)) bad |= FZ_R(HD_ERROR_INVALID_LIGHT);
        if (bad) return bad;
    }
    return FZ_OK;
}

static fz_set fz_tf_want(const hd_transfer_function *t)
{
    int i;
    if (!t->rgba && t->count == 0) return FZ_OK;
    if (t->count < 2 || t->count > (1 << 20)) return FZ_R(HD_ERROR_INVALID_TRANSFER_FUNCTION);
    if (!t->rgba) return FZ_R(HD_ERROR_NULL_POINTER);
    for (i = 0; i < 4 * t->count; ++i)
        if (!fz_finite(t->rgba[i]) || t->rgba[i] < 0.0f || t->rgba[i] > 1.0f) return FZ_R(HD_ERROR_INVALID_TRANSFER_FUNCTION);
    return FZ_OK;
}

static fz_set fz_volume_want(const hd_volume_desc *v)
{
    fz_set bad = 0;
    double ext[3], emax = 0.0;
    int i, zero;
    if (fz_bad_enum((int)v->type, HD_VOXEL_COUNT) || v->type == HD_VOXEL_INVALID) bad |= FZ_R(IE);
    for (i = 0; i < 3; ++i)
        if (v->dims[i] < 1 || v->dims[i] > HD_MAX_DIM) bad |= FZ_R(HD_ERROR_INVALID_DIMENSIONS);
    if (!v->data) bad |= FZ_R(HD_ERROR_NULL_POINTER);
    zero = v->spacing[0] == 0.0f && v->spacing[1] == 0.0f && v->spacing[2] == 0.0f;
    if (!zero) {
        int ok = 1;
        for (i = 0; i < 3; ++i)
            if (!fz_finite(v->spacing[i]) || !(v->spacing[i] > 0.0f)) ok = 0;
        if (ok && !(bad & FZ_R(HD_ERROR_INVALID_DIMENSIONS))) {
            for (i = 0; i < 3; ++i) {
                ext[i] = (double)v->dims[i] * (double)v->spacing[i];
                if (ext[i] > emax) emax = ext[i];
            }
            for (i = 0; i < 3; ++i)
                if (!((double)v->spacing[i] / emax * (double)HD_MAX_SPACING_RATIO >= 1.0) || !((float)(ext[i] / emax) > 0.0f)) ok = 0;
        }
        if (!ok) bad |= FZ_R(HD_ERROR_INVALID_SPACING);
    }
    if (!fz_finite(v->value_range[0]) || !fz_finite(v->value_range[1]) ||
        (v->value_range[0] == v->value_range[1] && v->value_range[0] != 0.0f))
        bad |= FZ_R(IP);
    return bad ? bad : FZ_OK;
}

/* ---- what hd_query_desc and hd_get_stats show ---------------------------------------------- */
typedef struct fz_snap {
    int type, dims[3], nl, ntf, threads;
    float spacing[3], range[2];
    hd_params p;
    hd_camera cam;
    hd_light l[HD_MAX_LIGHTS];
    float tf[4 * FZ_TF];
    hd_stats st; /* timings zeroed */
} fz_snap;

static void fz_snap_take(hd_context h, fz_snap *s)
{
    hd_desc q;
    hd_result r;
    memset(s, 0, sizeof *s);
    if ((r = hd_query_desc(h, &q)) != HD_SUCCESS) fz_fail("hd_query_desc on a live context: %s", hd_result_string(r));
    if ((r = hd_get_stats(h, &s->st)) != HD_SUCCESS) fz_fail("hd_get_stats on a live context: %s", hd_result_string(r));
    s->st.seconds_direct = s->st.seconds_diffusion = s->st.seconds_projection = 0.0;
    s->type = (int)q.volume.type;
    memcpy(s->dims, q.volume.dims, sizeof s->dims);
    memcpy(s->spacing, q.volume.spacing, sizeof s->spacing);
    memcpy(s->range, q.volume.value_range, sizeof s->range);
    s->p = q.params;
    s->cam = q.camera;
    s->nl = q.light_count;
    s->ntf = q.transfer_function.count;
    s->threads = q.threads;
    if (s->nl < 1 || s->nl > HD_MAX_LIGHTS || !q.lights) fz_fail("hd_query_desc: %d lights at %p", s->nl, (const void *)q.lights);
    if (s->ntf < 2 || s->ntf > FZ_TF || !q.transfer_function.rgba)
        fz_fail("hd_query_desc: a %d-entry transfer function at %p", s->ntf, (const void *)q.transfer_function.rgba);
    memcpy(s->l, q.lights, (size_t)s->nl * sizeof *s->l);
    memcpy(s->tf, q.transfer_function.rgba, (size_t)s->ntf * 4 * sizeof(float));
}

/* The first difference between two snapshots, or NULL. */
static const char *fz_snap_diff(const fz_snap *a, const fz_snap *b)
{
    if (a->type != b->type || memcmp(a->dims, b->dims, sizeof a->dims) || memcmp(a->spacing, b->spacing, sizeof a->spacing) ||
        memcmp(a->range, b->range, sizeof a->range) || a->threads != b->threads)
        return "the volume";
    if (memcmp(&a->p, &b->p, sizeof a->p)) return "the params";
    if (memcmp(&a->cam, &b->cam, sizeof a->cam)) return "the camera";
    if (a->nl != b->nl || memcmp(a->l, b->l, sizeof a->l)) return "the lights";
    if (a->ntf != b->ntf || memcmp(a->tf, b->tf, sizeof a->tf)) return "the transfer function";
    if (a->st.iterations != b->st.iterations) return "stats.iterations";
    if (a->st.frames != b->st.frames) return "stats.frames";
    if (memcmp(&a->st, &b->st, sizeof a->st)) return "the stats";
    return NULL;
}

/* ---- contexts ---------------------------------------------------------------------------------- */
typedef struct fz_ctx { hd_context h; fz_owner *o; int live; } fz_ctx;
static fz_ctx fz_c[FZ_CTX];
static hd_context fz_stale[FZ_STALE];
static int fz_nstale;

static float fz_img[FZ_IMG * FZ_IMG * 4], fz_img2[FZ_IMG * FZ_IMG * 4];
static float fz_ill[FZ_DIM * FZ_DIM * FZ_DIM * 3];
static uint8_t fz_px[FZ_IMG * FZ_IMG * 4];

static int fz_pt(hd_method m) { return m == HD_METHOD_PT_SS || m == HD_METHOD_PT_MS; }

/* The image: finite, alpha in [0, 1]. */
static void fz_check_image(hd_context h, const char *when)
{
    fz_snap s;
    size_t n, i;
    hd_result r;
    fz_snap_take(h, &s);
    n = (size_t)s.cam.width * (size_t)s.cam.height * 4;
    if (n > sizeof fz_img / sizeof fz_img[0]) fz_fail("camera %dx%d", s.cam.width, s.cam.height);
    r = hd_read_image_f32(h, fz_img, n);
    if (r == HD_ERROR_NO_FRAME && s.st.frames == 0) return; /* nothing projected since the image was reset */
    if (r != HD_SUCCESS) fz_fail("%s: hd_read_image_f32: %s", when, hd_result_string(r));
    for (i = 0; i < n; ++i) {
        if (!fz_finite(fz_img[i])) fz_fail("%s: image value %zu (pixel %zu, channel %zu) is %g", when, i, i / 4, i % 4, (double)fz_img[i]);
        if (i % 4 == 3 && !(fz_img[i] >= -1e-5f && fz_img[i] <= 1.00001f)) fz_fail("%s: pixel %zu alpha %g", when, i / 4, (double)fz_img[i]);
    }
}

/* Both illumination volumes (HD, CD): finite, E >= 0. */
static void fz_check_light(hd_context h, const char *when)
{
    fz_snap s;
    size_t n, i;
    int w;
    fz_snap_take(h, &s);
    if (fz_pt(s.p.method)) return;
    n = (size_t)s.st.illumination_dims[0] * s.st.illumination_dims[1] * s.st.illumination_dims[2] * (size_t)s.st.illumination_channels;
    if (n > sizeof fz_ill / sizeof fz_ill[0]) fz_fail("%s: illumination of %zu floats", when, n);
    for (w = 0; w < 2; ++w) {
        hd_result r = hd_read_illumination(h, (hd_illumination)w, fz_ill, n);
        if (r != HD_SUCCESS) fz_fail("%s: hd_read_illumination(%d): %s", when, w, hd_result_string(r));
        for (i = 0; i < n; ++i)
            if (!fz_finite(fz_ill[i]) || (w == 0 && fz_ill[i] < 0.0f))
                fz_fail("%s: illumination %d value %zu is %g", when, w, i, (double)fz_ill[i]);
    }
}

/* hd__srgb8's definition, in double. */
static int fz_srgb(double v)
{
    double s;
    if (!(v > 0.0)) return 0;
    if (v >= 1.0) return 255;
    s = v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
    return (int)(s * 255.0 + 0.5);
}

/* ---- generators -------------------------------------------------------------------------------- */
#define FZ_PARAM_FIELDS 26
/* Field k of *p from the bytes. Valid values that only cost time are not drawn (the header). */
static void fz_param_field(hd_params *p, int k)
{
    int i = fz_u8() % 3;
    float v;
    switch (k) {
    case 0: p->method = (hd_method)fz_enum(HD_METHOD_COUNT); break;
    case 1:
        v = FZ_PICK(0.0f, 40.0f, 100.0f, 1.0f, 0.5f, 500.0f, 2000.0f);
        p->extinction = fz_finite(v) && v > 2000.0f && v <= 1e6f ? 2000.0f : v;
        break;
    case 2: p->albedo = FZ_PICK(0.0f, 0.9f, 0.5f, 1.0f, 0.1f); break;
    case 3: p->anisotropy = FZ_PICK(0.0f, 0.5f, -0.5f, 0.9f, -0.9f); break;
    case 4:
        v = FZ_PICK(0.0f, 0.0f, 100.0f, 1600.0f, 50.0f, 4000.0f);
        p->majorant = fz_finite(v) && v > 4000.0f && v <= 1e6f ? 4000.0f : v;
        break;
    case 5: p->diffusion_sweeps = FZ_INT(0, 1, 2, 4, 8); if (p->diffusion_sweeps > 16 && p->diffusion_sweeps <= 100000) p->diffusion_sweeps = 16; break;
    case 6: p->disable_diffusion = FZ_INT(0, 0, 1); break;
    case 7: p->solver = (hd_solver)fz_enum(HD_SOLVER_COUNT); break;
    case 8: p->tracking = (hd_tracking)fz_enum(HD_TRACKING_COUNT); break;
    case 9: p->seed = fz_u8(); break;
    case 10: p->background[i] = FZ_PICK(0.0f, 0.1f, 1.0f, 0.5f, 1e6f, 999999.94f, 1000000.06f, FLT_MAX, 3e38f, 1e30f); break;
    case 11: p->background[0] = p->background[1] = p->background[2] = FZ_PICK(0.0f, 0.1f, 1.0f, 1e6f, FLT_MAX); break;
    case 12: p->step = FZ_PICK(0.0f, 0.5f, 0.25f, 1.0f, 0.01f, 16.0f, 4.0f); break;
    case 13: p->frame_window = FZ_INT(0, 1, 2, 8); break;
    case 14: p->exposure = FZ_PICK(0.0f, 1.0f, 2.0f, 0.5f, FLT_MAX, 1e-30f); break;
    case 15: p->max_bounces = FZ_INT(0, 1, 2, 8); if (p->max_bounces > 64 && p->max_bounces <= 100000) p->max_bounces = 64; break;
    case 16: p->illumination_downsample = FZ_INT(0, 1, 2, 3, 8); break;
    case 17: p->rgb_scattering = FZ_INT(0, 0, 1); break;
    case 18: p->diffusion_boundary = (hd_boundary)fz_enum(HD_BOUNDARY_COUNT); break;
    case 19: p->illumination_precision = (hd_precision)fz_enum(HD_PRECISION_COUNT); break;
    case 20: p->light_tolerance = FZ_PICK(0.0f, 0.1f, 0.01f, 1.0f, 1e-30f); break;
    case 21:
        v = FZ_PICK(0.0f, 0.0f, 1e-4f, 1e-3f, 10.0f, 10.000001f, 1e30f);
        p->render_budget = fz_finite(v) && v > FZ_BUDGET_FAST && v <= FZ_BUDGET_MAX ? FZ_BUDGET_FAST : v;
        break;
    case 22: p->crop_min[i] = FZ_PICK(0.0f, 0.25f, 0.5f); break;
    case 23: p->crop_max[i] = FZ_PICK(0.0f, 1.0f, 0.75f, 0.5f); break;
    case 24: p->render_scale = FZ_INT(0, 1, 2, 4, 8, HD_RENDER_SCALE_AUTO); break;
    default:
        p->crop_min[i] = FZ_PICK(0.0f, 0.25f, 0.5f);
        p->crop_max[i] = FZ_PICK(0.0f, 1.0f, 0.75f, 0.5f);
        break;
    }
}

static void fz_gen_params(hd_params *p)
{
    int k;
    memset(p, 0, sizeof *p);
    for (k = 0; k < FZ_PARAM_FIELDS; ++k)
        if (fz_u8() & 1) fz_param_field(p, k);
}

/* A vector: one of the usual ones (index u), else each component any float. */
static void fz_vec(float v[3], const float (*usual)[3], int n)
{
    uint8_t b = fz_u8();
    if (b < 170) memcpy(v, usual[b % n], 3 * sizeof(float));
    else if (b < 220) v[b % 3] = fz_float();
    else { v[0] = fz_float(); v[1] = fz_float(); v[2] = fz_float(); }
}

static int fz_side(void)
{
    uint8_t b = fz_u8();
    return b < 240 ? 1 + b % FZ_IMG : b < 244 ? -1 : b < 248 ? HD_MAX_IMAGE_DIM + 1 : b < 252 ? INT_MAX : INT_MIN;
}

static void fz_camera_field(hd_camera *c, int k)
{
    static const float eyes[][3] = {{0, 0, 0}, {0, 0, 2.5f}, {2, 1, 1.5f}, {0, 0, 0.1f}, {0, -3, 0}, {0.3f, 0.2f, -2}};
    static const float targets[][3] = {{0, 0, 0}, {0, 0, 0}, {0.1f, 0, 0}, {0, 0, -0.5f}};
    static const float ups[][3] = {{0, 0, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, 1}};
    switch (k) {
    case 0: fz_vec(c->eye, eyes, 6); break;
    case 1: fz_vec(c->target, targets, 4); break;
    case 2: fz_vec(c->up, ups, 4); break;
    case 3: c->fov_y = FZ_PICK(0.0f, 40.0f, 90.0f, 10.0f, 170.0f); break;
    case 4: c->width = fz_side(); break;
    default: c->height = fz_side(); break;
    }
}

static void fz_gen_camera(hd_camera *c)
{
    int k;
    memset(c, 0, sizeof *c);
    for (k = 0; k < 4; ++k)
        if (fz_u8() & 1) fz_camera_field(c, k);
    c->width = fz_side();
    c->height = fz_side();
}

static void fz_light_field(hd_light *l, int k)
{
    static const float dirs[][3] = {{0, 0, -1}, {1, 0, 0}, {0.3f, -0.4f, -1}, {0, 1, 0}};
    static const float pos[][3] = {{0, 0, 2}, {1, 1, 1}, {0, 0, 0}, {0.5f, 0, 0}, {0, 0, -0.25f}};
    static const float cols[][3] = {{0, 0, 0}, {1, 1, 1}, {1, 0.5f, 0.2f}, {0, 0, 1}};
    switch (k) {
    case 0: l->type = (hd_light_type)fz_enum(HD_LIGHT_TYPE_COUNT); break;
    case 1: fz_vec(l->direction, dirs, 4); break;
    case 2: fz_vec(l->position, pos, 5); break;
    case 3: fz_vec(l->color, cols, 4); break;
    case 4: l->intensity = FZ_PICK(0.0f, 1.0f, 10.0f, 0.5f, 1e6f); break;
    case 5: l->inverse_square = fz_u8() & 1; break;
    case 6: fz_vec(l->edge1, dirs, 4); break;
    case 7: fz_vec(l->edge2, pos, 5); break;
    default: l->radius = FZ_PICK(0.0f, 0.25f, 1.0f, -1.0f, 2e15f); break;
    }
}

static void fz_gen_light(hd_light *l)
{
    int k;
    memset(l, 0, sizeof *l);
    l->direction[2] = -1.0f;
    for (k = 0; k < 9; ++k)
        if (fz_u8() & 1) fz_light_field(l, k);
}

/* Lights into l[4] (count *n, or NULL with *n > 0). */
static const hd_light *fz_gen_lights(hd_light *l, int *n)
{
    uint8_t b = fz_u8();
    int i;
    *n = 1 + b % 3;
    for (i = 0; i < *n; ++i) fz_gen_light(&l[i]);
    if (b >= 240) *n = b < 244 ? 0 : b < 248 ? -1 : b < 252 ? HD_MAX_LIGHTS + 1 : 2;
    return b >= 252 ? NULL : l;
}

static float fz_tf_buf[4 * FZ_TF];
static void fz_gen_tf(hd_transfer_function *t)
{
    uint8_t b = fz_u8();
    int i;
    t->rgba = NULL;
    t->count = 0;
    if (b < 60) return; /* the default ramp */
    t->count = 2 + b % (FZ_TF - 1);
    for (i = 0; i < 4 * t->count; ++i) fz_tf_buf[i] = fz_u8() < 230 ? (float)fz_u8() / 255.0f : fz_float();
    t->rgba = fz_tf_buf;
    if (b >= 240) {
        t->count = b < 244 ? 1 : b < 247 ? -1 : b < 250 ? (1 << 20) + 1 : 3;
        if (b >= 250) t->rgba = NULL;
    }
}

/* The volume at hd_create: voxels of each type and pattern, spacing, value range. */
static uint8_t fz_vox[FZ_DIM * FZ_DIM * FZ_DIM * 4];
static void fz_gen_volume(hd_volume_desc *v)
{
    static const float spacings[][3] = {{1, 1, 1}, {0.5f, 1, 2}, {1, 1, 100}, {1e-30f, 1e-30f, 1e-30f}, {1e30f, 1e30f, 1e30f},
                                        {FLT_MAX, FLT_MAX, FLT_MAX}, {FLT_MIN / 4096, FLT_MIN / 4096, FLT_MIN / 4096},
                                        {1e-30f, 1, 1}, {-1, 1, 1}, {0, 1, 1}, {1, 1, 1000}, {3e38f, 1e36f, 3e38f}};
    static const float ranges[][2] = {{0, 1}, {0, 255}, {-3e38f, 3e38f}, {-FLT_MAX, FLT_MAX}, {0, FLT_MAX}, {FLT_MAX, -FLT_MAX},
                                      {0, FLT_MIN / 4096}, {1, 1.0000001f}, {-1e-30f, 1e-30f}, {1, 1}, {255, 0}, {-1e30f, 0}};
    uint8_t b;
    int i, n = 1, pat, x, y, z;
    float lo, hi, mid, palette[4], pick, unit;
    unsigned hash;
    memset(v, 0, sizeof *v);
    b = fz_u8();
    v->type = (hd_voxel_type)(b < 240 ? 1 + b % 4 : b < 246 ? 0 : b < 250 ? HD_VOXEL_COUNT : -1);
    for (i = 0; i < 3; ++i) {
        b = fz_u8();
        v->dims[i] = b < 248 ? 1 + b % FZ_DIM : b < 251 ? 0 : b < 254 ? -1 : HD_MAX_DIM + 1;
    }
    b = fz_u8();
    if (b >= 150) {
        if (b < 240) memcpy(v->spacing, spacings[b % 12], sizeof v->spacing);
        else { v->spacing[0] = fz_float(); v->spacing[1] = fz_float(); v->spacing[2] = fz_float(); }
        /* a valid spacing far from uniform makes every ray march long: kept to 1:1000 */
        if (fz_finite3(v->spacing) && v->spacing[0] > 0.0f && v->spacing[1] > 0.0f && v->spacing[2] > 0.0f) {
            float mx = v->spacing[0], mn = v->spacing[0];
            for (i = 1; i < 3; ++i) { mx = v->spacing[i] > mx ? v->spacing[i] : mx; mn = v->spacing[i] < mn ? v->spacing[i] : mn; }
            if ((double)mx / (double)mn > 1000.0 && (double)mx / (double)mn < 65536.0 / FZ_DIM) v->spacing[0] = v->spacing[1] = v->spacing[2] = 1.0f;
        }
    }
    b = fz_u8();
    if (b >= 110) {
        if (b < 240) memcpy(v->value_range, ranges[b % 12], sizeof v->value_range);
        else { v->value_range[0] = fz_float(); v->value_range[1] = fz_float(); }
    }
    v->data = fz_vox;
    for (i = 0; i < 3; ++i) n *= v->dims[i] >= 1 && v->dims[i] <= FZ_DIM ? v->dims[i] : 1;
    memset(fz_vox, 0, sizeof fz_vox);
    lo = v->value_range[0];
    hi = v->value_range[1];
    if (lo == 0.0f && hi == 0.0f) {
        lo = v->type == HD_VOXEL_I16 ? -32768.0f : 0.0f;
        hi = v->type == HD_VOXEL_U8 ? 255.0f : v->type == HD_VOXEL_U16 ? 65535.0f : v->type == HD_VOXEL_I16 ? 32767.0f : 1.0f;
    }
    mid = (float)(0.5 * (double)lo + 0.5 * (double)hi);
    pat = fz_u8() % 6;
    /* patterns 4 and 5 draw from a palette of 4 values by a hash of the voxel index */
    for (i = 0; i < 4; ++i) palette[i] = pat == 4 ? fz_float() : (float)fz_u8() / 255.0f;
    hash = fz_u8() | 1u;
    for (z = 0, i = 0; z < FZ_DIM; ++z)
        for (y = 0; y < FZ_DIM; ++y)
            for (x = 0; x < FZ_DIM && i < n; ++x) {
                int nx = v->dims[0] >= 1 && v->dims[0] <= FZ_DIM ? v->dims[0] : 1;
                int ny = v->dims[1] >= 1 && v->dims[1] <= FZ_DIM ? v->dims[1] : 1;
                int cls; /* 0 low, 1 middle, 2 high, 3 from the bytes */
                float fx, fy, fz, r;
                if (x >= nx || y >= ny) continue;
                fx = (float)x - 0.5f * (float)(nx - 1); fy = (float)y - 0.5f * (float)(ny - 1); fz = (float)z - 3.5f;
                r = sqrtf(fx * fx + fy * fy + fz * fz);
                cls = pat == 0 ? 2 : pat == 1 ? (r < 1.5f ? 2 : r < 3.0f ? 1 : 0) : pat == 2 ? (x * 3 / nx) : pat == 3 ? (i & 1) * 2 : 3;
                pick = palette[((unsigned)i * hash * 2654435761u) >> 30];
                unit = pick >= 0.0f && pick <= 1.0f ? pick : pick > 1.0f ? 1.0f : 0.0f; /* NaN: 0 */
                if (v->type == HD_VOXEL_F32) {
                    float f = cls == 0 ? lo : cls == 1 ? mid : cls == 2 ? hi : pat == 4 ? pick : (float)((double)pick * ((double)hi - lo) + lo);
                    memcpy(fz_vox + 4 * i, &f, 4);
                } else if (v->type == HD_VOXEL_U16) {
                    uint16_t u = (uint16_t)(cls == 0 ? 0 : cls == 1 ? 32768 : cls == 2 ? 65535 : (int)(unit * 65535.0f));
                    memcpy(fz_vox + 2 * i, &u, 2);
                } else if (v->type == HD_VOXEL_I16) {
                    int16_t u = (int16_t)(cls == 0 ? -32768 : cls == 1 ? 0 : cls == 2 ? 32767 : (int)(unit * 65535.0f) - 32768);
                    memcpy(fz_vox + 2 * i, &u, 2);
                } else {
                    fz_vox[i] = (uint8_t)(cls == 0 ? 0 : cls == 1 ? 128 : cls == 2 ? 255 : (int)(unit * 255.0f));
                }
                ++i;
            }
    if (fz_u8() >= 252) v->data = NULL;
}

/* ---- one call: before, the call, after ----------------------------------------------------- */
#define FZ_NAME(name, text) #name,
static const char *const fz_names[] = {HD__RESULT_LIST(FZ_NAME)};
#undef FZ_NAME
static const char *fz_name(hd_result r) { return (int)r >= 0 && (int)r < (int)HD_RESULT_COUNT ? fz_names[r] : "(out of range)"; }

static const char *fz_set_names(fz_set s)
{
    static char buf[1024];
    int r;
    buf[0] = 0;
    for (r = 0; r < (int)HD_RESULT_COUNT; ++r)
        if (s & FZ_R(r)) {
            strncat(buf, fz_names[r], sizeof buf - strlen(buf) - 2);
            strncat(buf, " ", sizeof buf - strlen(buf) - 1);
        }
    return buf;
}

typedef struct fz_pre {
    fz_snap s, os;
    int ci, other;
    long calls, ocalls;
    double t0;
} fz_pre;

static void fz_begin(int ci, fz_pre *pre, const char *call)
{
    fz_call = call;
    ++fz_step;
    pre->ci = ci;
    pre->other = -1;
    if (ci >= 0) {
        fz_snap_take(fz_c[ci].h, &pre->s);
        fz_c[ci].o->errors = 0;
        fz_c[ci].o->code = HD_SUCCESS;
        pre->calls = fz_c[ci].o->calls;
    }
    if (fz_c[ci < 0 ? 0 : 1 - ci].live) {
        pre->other = ci < 0 ? 0 : 1 - ci;
        fz_snap_take(fz_c[pre->other].h, &pre->os);
        fz_c[pre->other].o->errors = 0;
        pre->ocalls = fz_c[pre->other].o->calls;
    }
    pre->t0 = fz_now();
}

static void fz_same(hd_context h, const fz_snap *before, const char *why)
{
    fz_snap now;
    const char *d;
    fz_snap_take(h, &now);
    if ((d = fz_snap_diff(before, &now)) != NULL) fz_fail("%s changed %s", why, d);
}

/* After the call: its time, an allowed result, a rejected call's rules, the other context as it was. */
static void fz_end(const fz_pre *pre, hd_result r, fz_set allowed)
{
    double dt = fz_now() - pre->t0;
    fz_tr("    /* call %d -> %s */\n", fz_step, fz_name(r));
    if (dt > FZ_CALL_SECONDS) fz_fail("took %.2f s", dt);
    if ((int)r < 0 || (int)r >= (int)HD_RESULT_COUNT) fz_fail("result %d is not an hd_result", (int)r);
    if (!(allowed & FZ_R(r))) fz_fail("returned %s; the rules allow %s", fz_name(r), fz_set_names(allowed));
    if (pre->ci >= 0) {
        const fz_owner *o = fz_c[pre->ci].o;
        if (r != HD_SUCCESS) {
            if (o->errors != 1 || o->code != r)
                fz_fail("rejected with %s, logged %d errors (the last %s)", fz_name(r), o->errors, fz_name(o->code));
            /* HD_ERROR_NO_FRAME is found after the call brought the device state up to date
               (src/hd_readback.h), which may allocate the image of a new camera size */
            if (o->calls != pre->calls && r != HD_ERROR_NO_FRAME)
                fz_fail("rejected with %s after %ld allocations", fz_name(r), o->calls - pre->calls);
            fz_same(fz_c[pre->ci].h, &pre->s, "a rejected call");
        } else if (o->errors) {
            fz_fail("succeeded but logged %d errors (the last %s)", o->errors, fz_name(o->code));
        }
    }
    if (pre->other >= 0) {
        const fz_owner *o = fz_c[pre->other].o;
        if (o->errors || o->calls != pre->ocalls) fz_fail("the other context logged %d errors, allocated %ld times", o->errors, o->calls - pre->ocalls);
        fz_same(fz_c[pre->other].h, &pre->os, "a call on another context");
    }
}

/* A setter's documented invalidation (hybriddiff.h, above hd_set_transfer_function): a, b before
   and after hd_set_params. The path tracers' image is their state: what resets it restarts them.
   A value that changed restarts what depends on it; one whose bits alone changed (-0 for 0) may. */
#define FZ_NE(f) (p->f != o->f)
#define FZ_BITS(f) (memcmp(&p->f, &o->f, sizeof p->f) != 0)
static void fz_check_params_restart(const fz_snap *a, const fz_snap *b)
{
    const hd_params *o = &a->p, *p = &b->p;
    hd_params t = *o;
    int i, crop = 0, bg = 0, light, light_bits, warm, phi, phi_bits, image, pt = fz_pt(p->method);
    for (i = 0; i < 3; ++i) {
        crop |= FZ_NE(crop_min[i]) || FZ_NE(crop_max[i]);
        bg |= FZ_NE(background[i]);
    }
    /* reset: E, phi zeroed; warm: kept as the new light's start (extinction; albedo, anisotropy) */
    light = FZ_NE(majorant) || FZ_NE(seed) || crop || FZ_NE(illumination_downsample) || FZ_NE(rgb_scattering) ||
            FZ_NE(illumination_precision);
    warm = FZ_NE(extinction) || FZ_NE(albedo) || FZ_NE(anisotropy);
    light_bits = FZ_BITS(extinction) || FZ_BITS(majorant) || FZ_BITS(crop_min) || FZ_BITS(crop_max) || light;
    phi = FZ_NE(disable_diffusion) || FZ_NE(diffusion_boundary);
    phi_bits = FZ_BITS(albedo) || FZ_BITS(anisotropy) || phi || warm;
    image = FZ_NE(step) || FZ_NE(frame_window) || FZ_NE(render_scale) || FZ_NE(depth_threshold) || FZ_NE(rest) ||
            FZ_NE(refine_bounces) || FZ_NE(environment_background) || bg;
    /* "solver, sweeps, tracking, exposure, light_tolerance, render_budget, light_window -> nothing" */
    t.solver = p->solver;
    t.diffusion_sweeps = p->diffusion_sweeps;
    t.tracking = p->tracking;
    t.exposure = p->exposure;
    t.light_tolerance = p->light_tolerance;
    t.render_budget = p->render_budget;
    t.light_window = p->light_window;
    if (p->method != o->method) {
        if (b->st.iterations || b->st.frames) fz_fail("a new method kept %llu iterations, %llu frames",
                                                      (unsigned long long)b->st.iterations, (unsigned long long)b->st.frames);
        return;
    }
    if (memcmp(&t, p, sizeof t) == 0) {
        if (b->st.iterations != a->st.iterations || b->st.frames != a->st.frames)
            fz_fail("solver/sweeps/tracking/exposure/tolerance/budget changed %llu iterations, %llu frames to %llu, %llu",
                    (unsigned long long)a->st.iterations, (unsigned long long)a->st.frames,
                    (unsigned long long)b->st.iterations, (unsigned long long)b->st.frames);
        return;
    }
    if (pt) {
        int dep = light || warm || phi || image || (p->method == HD_METHOD_PT_MS && p->max_bounces != o->max_bounces);
        if (dep && (b->st.iterations || b->st.frames))
            fz_fail("%s: a change its image depends on kept %llu iterations, %llu frames (max_bounces %d -> %d)",
                    hd_method_name(p->method), (unsigned long long)b->st.iterations, (unsigned long long)b->st.frames,
                    o->max_bounces, p->max_bounces);
        return;
    }
    if (light && (b->st.iterations || b->st.frames))
        fz_fail("a change of what E depends on kept %llu iterations, %llu frames", (unsigned long long)b->st.iterations,
                (unsigned long long)b->st.frames);
    if ((warm || phi || image) && b->st.frames) fz_fail("a change the image depends on kept %llu frames", (unsigned long long)b->st.frames);
    if (warm && !light && b->st.iterations != a->st.iterations)
        fz_fail("a warm change (extinction, albedo, anisotropy) did not keep E: %llu -> %llu iterations",
                (unsigned long long)a->st.iterations, (unsigned long long)b->st.iterations);
    if (!light_bits && !phi_bits && image && (b->st.iterations != a->st.iterations || b->st.light_converged != a->st.light_converged))
        fz_fail("an image-only change touched the light: %llu -> %llu iterations", (unsigned long long)a->st.iterations,
                (unsigned long long)b->st.iterations);
}
#undef FZ_NE
#undef FZ_BITS

/* ---- the calls ---------------------------------------------------------------------------------- */
static void fz_op_params(int ci, int fresh)
{
    hd_params p, filled;
    fz_pre pre;
    fz_snap now;
    fz_set allowed;
    hd_result r;
    int k, null = fz_u8() >= 250;
    fz_snap_take(fz_c[ci].h, &pre.s);
    if (fresh) fz_gen_params(&p);
    else {
        p = pre.s.p;
        for (k = fz_u8() % 3; k >= 0; --k) fz_param_field(&p, fz_u8() % FZ_PARAM_FIELDS);
    }
    filled = p;
    fz_params_defaults(&filled);
    allowed = null ? FZ_R(HD_ERROR_NULL_POINTER) : fz_params_want(&filled);
    if (!null && filled.method == HD_METHOD_CD && fz_has_area(pre.s.l, pre.s.nl)) allowed = (allowed & ~FZ_OK) | FZ_R(HD_ERROR_UNSUPPORTED);
    if (!null) fz_tr_params("p", &p);
    fz_tr("    r = hd_set_params(c%d, %s);\n", ci, null ? "NULL" : "&p");
    fz_begin(ci, &pre, "hd_set_params");
    r = hd_set_params(fz_c[ci].h, null ? NULL : &p);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_snap_take(fz_c[ci].h, &now);
    if (memcmp(&now.p, &filled, sizeof filled)) fz_fail("hd_query_desc's params are not the ones set, defaults filled in");
    fz_check_params_restart(&pre.s, &now);
}

static int fz_camera_changed(const hd_camera *a, const hd_camera *b)
{
    int i, d = a->fov_y != b->fov_y || a->width != b->width || a->height != b->height;
    for (i = 0; i < 3; ++i) d |= a->eye[i] != b->eye[i] || a->target[i] != b->target[i] || a->up[i] != b->up[i];
    return d;
}

static void fz_op_camera(int ci)
{
    hd_camera c, filled;
    fz_pre pre;
    fz_snap now;
    fz_set allowed;
    hd_result r;
    uint8_t b = fz_u8();
    int null = b >= 250, k;
    fz_snap_take(fz_c[ci].h, &pre.s);
    if (b < 40) fz_gen_camera(&c);
    else {
        c = pre.s.cam;
        for (k = fz_u8() % 2; k >= 0; --k) fz_camera_field(&c, fz_u8() % 6);
    }
    filled = c;
    fz_camera_defaults(&filled);
    allowed = null ? FZ_R(HD_ERROR_NULL_POINTER) : fz_camera_want(&filled);
    /* 0 -> 512 is valid but 1024 times the pixels: not drawn */
    if (!null && (c.width == 0 || c.height == 0)) return;
    if (!null) fz_tr_camera("cam", &c);
    fz_tr("    r = hd_set_camera(c%d, %s);\n", ci, null ? "NULL" : "&cam");
    fz_begin(ci, &pre, "hd_set_camera");
    r = hd_set_camera(fz_c[ci].h, null ? NULL : &c);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_snap_take(fz_c[ci].h, &now);
    if (memcmp(&now.cam, &filled, sizeof filled)) fz_fail("hd_query_desc's camera is not the one set, defaults filled in");
    if (fz_camera_changed(&pre.s.cam, &filled)) {
        if (now.st.frames) fz_fail("a new camera kept %llu frames", (unsigned long long)now.st.frames);
        if (!fz_pt(now.p.method) && now.st.iterations != pre.s.st.iterations)
            fz_fail("a camera move changed the light's iterations %llu -> %llu", (unsigned long long)pre.s.st.iterations,
                    (unsigned long long)now.st.iterations);
        if (fz_pt(now.p.method) && now.st.iterations) fz_fail("a new camera kept the path tracer's iterations");
    }
}

static int fz_channels(const hd_light *l, int n, int rgb)
{
    int i;
    for (i = 1; i < n; ++i)
        if (memcmp(l[i].color, l[0].color, sizeof l[0].color)) return 3;
    return rgb ? 3 : 1;
}

static void fz_op_lights(int ci)
{
    hd_light l[4], filled[4];
    const hd_light *lp = l;
    fz_pre pre;
    fz_snap now;
    fz_set allowed;
    hd_result r;
    uint8_t b = fz_u8();
    int n, i, changed;
    fz_snap_take(fz_c[ci].h, &pre.s);
    n = pre.s.nl < 4 ? pre.s.nl : 4;
    memcpy(l, pre.s.l, (size_t)n * sizeof *l);
    if (b < 140) fz_light_field(&l[fz_u8() % n], fz_u8() % 9);
    else if (b < 170 && n < 3) fz_gen_light(&l[n++]);
    else if (b < 190 && n > 1) --n;
    else lp = fz_gen_lights(l, &n);
    allowed = fz_lights_want(lp, n);
    if ((allowed & FZ_OK) && pre.s.p.method == HD_METHOD_CD && fz_has_area(lp, n)) allowed = FZ_R(HD_ERROR_UNSUPPORTED);
    fz_tr_lights(lp, n);
    fz_tr("    r = hd_set_lights(c%d, %s, %d);\n", ci, lp ? "lights" : "NULL", n);
    fz_begin(ci, &pre, "hd_set_lights");
    r = hd_set_lights(fz_c[ci].h, lp, n);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_snap_take(fz_c[ci].h, &now);
    for (i = 0; i < n; ++i) { filled[i] = l[i]; fz_light_defaults(&filled[i]); }
    if (now.nl != n || memcmp(now.l, filled, (size_t)n * sizeof *filled)) fz_fail("hd_query_desc's lights are not the ones set");
    if (now.st.illumination_channels != fz_channels(filled, n, now.p.rgb_scattering))
        fz_fail("%d illumination channels for these lights", now.st.illumination_channels);
    changed = n != pre.s.nl;
    for (i = 0; i < n && !changed; ++i) {
        int k;
        const hd_light *x = &filled[i], *y = &pre.s.l[i];
        changed |= x->type != y->type || x->intensity != y->intensity || x->inverse_square != y->inverse_square || x->radius != y->radius;
        for (k = 0; k < 3; ++k)
            changed |= x->direction[k] != y->direction[k] || x->position[k] != y->position[k] || x->color[k] != y->color[k] ||
                       x->edge1[k] != y->edge1[k] || x->edge2[k] != y->edge2[k];
    }
    /* "lights -> E, phi warm; image (CD, another light count: reset)"; new grids for another
       channel count reset them; the path tracers' image is their state */
    if (changed && now.st.frames) fz_fail("new lights kept %llu frames", (unsigned long long)now.st.frames);
    if (changed && (fz_pt(now.p.method) || (now.p.method == HD_METHOD_CD && n != pre.s.nl) ||
                    now.st.illumination_channels != pre.s.st.illumination_channels) && now.st.iterations)
        fz_fail("new lights (a reset) kept %llu iterations", (unsigned long long)now.st.iterations);
    if (changed && !fz_pt(now.p.method) && !(now.p.method == HD_METHOD_CD && n != pre.s.nl) &&
        now.st.illumination_channels == pre.s.st.illumination_channels && now.st.iterations != pre.s.st.iterations)
        fz_fail("new lights (warm) did not keep E: %llu -> %llu iterations", (unsigned long long)pre.s.st.iterations,
                (unsigned long long)now.st.iterations);
}

static void fz_op_tf(int ci)
{
    static const float ramp[8] = {1, 1, 1, 0, 1, 1, 1, 1};
    hd_transfer_function t;
    fz_pre pre;
    fz_snap now;
    fz_set allowed;
    hd_result r;
    int null = fz_u8() >= 250, i, changed;
    const float *want;
    fz_gen_tf(&t);
    allowed = null ? FZ_R(HD_ERROR_NULL_POINTER) : fz_tf_want(&t);
    if (!null) fz_tr_tf(&t);
    fz_tr("    tf_desc.rgba = %s; tf_desc.count = %d;\n    r = hd_set_transfer_function(c%d, %s);\n", t.rgba ? "tf" : "NULL",
          t.count, ci, null ? "NULL" : "&tf_desc");
    fz_begin(ci, &pre, "hd_set_transfer_function");
    r = hd_set_transfer_function(fz_c[ci].h, null ? NULL : &t);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_snap_take(fz_c[ci].h, &now);
    want = t.rgba ? t.rgba : ramp;
    if (now.ntf != (t.rgba ? t.count : 2) || memcmp(now.tf, want, (size_t)now.ntf * 4 * sizeof(float)))
        fz_fail("hd_query_desc's transfer function is not the one set");
    {
        hd_params x = now.p;
        x.majorant = pre.s.p.majorant;
        if (memcmp(&x, &pre.s.p, sizeof x) || (now.p.majorant != pre.s.p.majorant && now.p.majorant != 0.0f))
            fz_fail("a new transfer function changed the params beyond dropping the majorant");
    }
    changed = now.ntf != pre.s.ntf;
    for (i = 0; i < 4 * now.ntf && !changed; ++i) changed = now.tf[i] != pre.s.tf[i];
    /* "TF alpha, extinction -> E, phi warm; image; TF colour only -> image (phi warm with RGB
       scattering); the same TF -> nothing": E is kept, the image restarts (the path tracers') */
    if (changed && now.st.frames)
        fz_fail("a new transfer function kept %llu frames", (unsigned long long)now.st.frames);
    if (changed && fz_pt(now.p.method) && now.st.iterations)
        fz_fail("a new transfer function kept %s's %llu iterations", hd_method_name(now.p.method), (unsigned long long)now.st.iterations);
    if (!changed && (now.st.iterations != pre.s.st.iterations || now.st.frames != pre.s.st.frames))
        fz_fail("the same transfer function changed %llu iterations, %llu frames to %llu, %llu",
                (unsigned long long)pre.s.st.iterations, (unsigned long long)pre.s.st.frames,
                (unsigned long long)now.st.iterations, (unsigned long long)now.st.frames);
}

/* n for hd_iterate and hd_refine: 1..4 mostly; 0, -1, INT_MIN; INT_MAX only past iteration 0,
   where it crosses the 2^31 limit (from 0 it is valid and takes 2^31 iterations). */
static int fz_count(const fz_snap *s)
{
    uint8_t b = fz_u8();
    if (b < 230) return 1 + b % 4;
    if (b < 238) return 0;
    if (b < 246) return -1;
    if (b < 250) return INT_MIN;
    return s->st.iterations > 0 ? INT_MAX : 1;
}

static void fz_op_iterate(int ci, int refine)
{
    fz_pre pre;
    fz_snap now;
    hd_result r;
    fz_set allowed;
    int n, pt;
    size_t npx;
    fz_snap_take(fz_c[ci].h, &pre.s);
    n = fz_count(&pre.s);
    pt = fz_pt(pre.s.p.method);
    allowed = n < 1 || pre.s.st.iterations + (uint64_t)(n < 1 ? 0 : n) > 0x7fffffffu ? FZ_R(IP) : FZ_OK;
    if (refine && pt) allowed = (n < 1 ? FZ_R(IP) : 0) | FZ_R(HD_ERROR_UNSUPPORTED);
    npx = (size_t)pre.s.cam.width * (size_t)pre.s.cam.height * 4;
    if (refine && !pt && allowed == FZ_OK && pre.s.st.frames > 0) {
        if (hd_read_image_f32(fz_c[ci].h, fz_img2, npx) != HD_SUCCESS) fz_fail("hd_read_image_f32 before hd_refine");
        fz_snap_take(fz_c[ci].h, &pre.s);
    }
    fz_tr("    r = %s(c%d, %d);\n", refine ? "hd_refine" : "hd_iterate", ci, n);
    fz_begin(ci, &pre, refine ? "hd_refine" : "hd_iterate");
    r = refine ? hd_refine(fz_c[ci].h, n) : hd_iterate(fz_c[ci].h, n);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_snap_take(fz_c[ci].h, &now);
    if (now.st.iterations != pre.s.st.iterations + (uint64_t)n)
        fz_fail("%d iterations made %llu -> %llu", n, (unsigned long long)pre.s.st.iterations, (unsigned long long)now.st.iterations);
    if (!refine && pt && now.st.frames != pre.s.st.frames + (uint64_t)n)
        fz_fail("%d path iterations made %llu -> %llu frames", n, (unsigned long long)pre.s.st.frames, (unsigned long long)now.st.frames);
    if (!refine && !pt && (now.st.frames < 1 || now.st.frames > pre.s.st.frames + (uint64_t)n))
        fz_fail("%d iterations made %llu -> %llu frames", n, (unsigned long long)pre.s.st.frames, (unsigned long long)now.st.frames);
    if (refine) {
        if (now.st.frames != pre.s.st.frames && now.st.frames != 0)
            fz_fail("hd_refine made %llu -> %llu frames", (unsigned long long)pre.s.st.frames, (unsigned long long)now.st.frames);
        fz_check_image(fz_c[ci].h, "after hd_refine");
        if (now.st.frames == pre.s.st.frames && now.st.frames > 0 && memcmp(fz_img, fz_img2, npx * sizeof(float)))
            fz_fail("hd_refine changed the image");
    } else {
        fz_check_image(fz_c[ci].h, "after hd_iterate");
    }
    fz_check_light(fz_c[ci].h, refine ? "after hd_refine" : "after hd_iterate");
}

static void fz_op_render(int ci)
{
    fz_snap s, now;
    int k, reps;
    fz_snap_take(fz_c[ci].h, &s);
    reps = 1 + fz_u8() % 12;
    if (s.p.render_budget > 0.0f) reps = 1; /* each frame may take the whole budget */
    for (k = 0; k < reps; ++k) {
        fz_pre pre;
        hd_result r;
        size_t npx = (size_t)s.cam.width * (size_t)s.cam.height * 4;
        hd_result r0 = hd_read_image_f32(fz_c[ci].h, fz_img2, npx);
        if (r0 != HD_SUCCESS && r0 != HD_ERROR_NO_FRAME) fz_fail("hd_read_image_f32 before hd_render: %s", hd_result_string(r0));
        fz_tr("    r = hd_render(c%d);\n", ci);
        fz_begin(ci, &pre, "hd_render");
        r = hd_render(fz_c[ci].h);
        fz_end(&pre, r, FZ_OK);
        fz_snap_take(fz_c[ci].h, &now);
        if (fz_pt(now.p.method)) {
            if (now.st.iterations < pre.s.st.iterations + (pre.s.st.iterations < 0x7fffffffu ? 1u : 0u))
                fz_fail("a path-tracing frame made %llu -> %llu iterations", (unsigned long long)pre.s.st.iterations,
                        (unsigned long long)now.st.iterations);
        } else if (now.st.iterations < pre.s.st.iterations || now.st.frames > pre.s.st.frames + 1) {
            fz_fail("hd_render made %llu -> %llu iterations, %llu -> %llu frames", (unsigned long long)pre.s.st.iterations,
                    (unsigned long long)now.st.iterations, (unsigned long long)pre.s.st.frames, (unsigned long long)now.st.frames);
        }
        fz_check_image(fz_c[ci].h, "after hd_render");
        /* a call that ran nothing (the image done) leaves it as it was */
        if (!fz_pt(now.p.method) && now.st.iterations == pre.s.st.iterations && now.st.frames == pre.s.st.frames &&
            now.st.frames > 0 && now.st.render_scale == pre.s.st.render_scale && memcmp(fz_img, fz_img2, npx * sizeof(float)))
            fz_fail("an hd_render that added no frame changed the image");
        fz_check_light(fz_c[ci].h, "after hd_render");
    }
}

/* A buffer size: the exact one mostly, else one short, zero or SIZE_MAX. */
static size_t fz_size(size_t need, int *null)
{
    uint8_t b = fz_u8();
    *null = b >= 248;
    return b < 220 ? need : b < 232 ? need - 1 : b < 240 ? 0 : (size_t)-1;
}

static void fz_op_read(int ci, int which)
{
    fz_pre pre;
    fz_snap s;
    hd_result r;
    fz_set allowed;
    int null, w = 0;
    size_t need, size, i;
    fz_snap_take(fz_c[ci].h, &s);
    need = (size_t)s.cam.width * (size_t)s.cam.height * (which == 1 ? 4 : 4);
    if (which == 2) {
        w = fz_enum(HD_ILLUMINATION_COUNT);
        need = (size_t)s.st.illumination_dims[0] * s.st.illumination_dims[1] * s.st.illumination_dims[2] * (size_t)s.st.illumination_channels;
    }
    size = fz_size(need, &null);
    if (need == 0 && size == (size_t)-1) size = 0;
    if (which == 2) {
        allowed = (fz_bad_enum(w, HD_ILLUMINATION_COUNT) ? FZ_R(IE) : 0) | (null ? FZ_R(HD_ERROR_NULL_POINTER) : 0) |
                  (fz_pt(s.p.method) ? FZ_R(HD_ERROR_UNSUPPORTED) : 0) | (size < need ? FZ_R(HD_ERROR_BUFFER_TOO_SMALL) : 0);
    } else {
        allowed = (null ? FZ_R(HD_ERROR_NULL_POINTER) : 0) | (size < need ? FZ_R(HD_ERROR_BUFFER_TOO_SMALL) : 0);
        /* an image that holds no frame yet (new, or reset and not projected since) */
        if (!allowed && s.st.frames == 0) allowed = FZ_OK | FZ_R(HD_ERROR_NO_FRAME);
    }
    if (!allowed) allowed = FZ_OK;
    fz_tr("    r = %s(c%d, %s%s, %zu);\n", which == 0 ? "hd_read_image_f32" : which == 1 ? "hd_read_image_rgba8" : "hd_read_illumination",
          ci, which == 2 ? (w == 0 ? "HD_ILLUMINATION_DIRECT, " : w == 1 ? "HD_ILLUMINATION_SCATTERED, " : "(hd_illumination)w, ") : "",
          null ? "NULL" : "buf", size);
    fz_begin(ci, &pre, which == 0 ? "hd_read_image_f32" : which == 1 ? "hd_read_image_rgba8" : "hd_read_illumination");
    r = which == 0 ? hd_read_image_f32(fz_c[ci].h, null ? NULL : fz_img, size)
        : which == 1 ? hd_read_image_rgba8(fz_c[ci].h, null ? NULL : fz_px, size)
                     : hd_read_illumination(fz_c[ci].h, (hd_illumination)w, null ? NULL : fz_ill, size);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_same(fz_c[ci].h, &pre.s, "a read");
    if (which == 0) {
        for (i = 0; i < need; ++i)
            if (!fz_finite(fz_img[i]) || (i % 4 == 3 && !(fz_img[i] >= -1e-5f && fz_img[i] <= 1.00001f)))
                fz_fail("image value %zu (pixel %zu) is %g", i, i / 4, (double)fz_img[i]);
    } else if (which == 1) {
        /* RGBA8 is sRGB(radiance * exposure) */
        if (hd_read_image_f32(fz_c[ci].h, fz_img, need) != HD_SUCCESS) fz_fail("hd_read_image_f32 after RGBA8");
        for (i = 0; i < need; ++i) {
            float f = fz_img[i];
            int want = i % 4 == 3 ? (f <= 0.0f ? 0 : f >= 1.0f ? 255 : (int)(f * 255.0f + 0.5f)) : fz_srgb((double)f * (double)s.p.exposure);
            if (abs((int)fz_px[i] - want) > 1)
                fz_fail("RGBA8 value %zu is %d, the encoding of %g * exposure %g is %d", i, fz_px[i], (double)f, (double)s.p.exposure, want);
        }
    } else {
        for (i = 0; i < need; ++i)
            if (!fz_finite(fz_ill[i]) || (w == 0 && fz_ill[i] < 0.0f)) fz_fail("illumination %d value %zu is %g", w, i, (double)fz_ill[i]);
    }
}

static void fz_op_info(int ci)
{
    fz_pre pre;
    hd_result r;
    hd_stats st;
    hd_desc q;
    uint8_t b = fz_u8();
    int null = (b & 0x70) == 0x70, stats = b & 1;
    fz_tr("    r = %s(c%d, %s);\n", stats ? "hd_get_stats" : "hd_query_desc", ci, null ? "NULL" : "&out");
    fz_begin(ci, &pre, stats ? "hd_get_stats" : "hd_query_desc");
    r = stats ? hd_get_stats(fz_c[ci].h, null ? NULL : &st) : hd_query_desc(fz_c[ci].h, null ? NULL : &q);
    fz_end(&pre, r, null ? FZ_R(HD_ERROR_NULL_POINTER) : FZ_OK);
    if (r == HD_SUCCESS) fz_same(fz_c[ci].h, &pre.s, stats ? "hd_get_stats" : "hd_query_desc");
    if (r == HD_SUCCESS && stats && !(isfinite(st.light_error) && st.light_error >= 0.0)) fz_fail("light_error %g", st.light_error);
}

static void fz_op_preset(int ci)
{
    fz_snap s;
    hd_params p;
    hd_result r;
    hd_logger lg;
    int pr = fz_enum(HD_PRESET_COUNT), null = fz_u8() >= 250;
    fz_pre pre;
    fz_snap_take(fz_c[ci].h, &s);
    p = s.p;
    lg.func = fz_log;
    lg.user_data = fz_c[ci].o;
    fz_tr("    r = hd_params_preset(%d, %s, NULL);\n", pr, null ? "NULL" : "&p");
    fz_begin(ci, &pre, "hd_params_preset");
    r = hd_params_preset((hd_preset)pr, null ? NULL : &p, &lg);
    fz_end(&pre, r, null ? FZ_R(HD_ERROR_NULL_POINTER) | (fz_bad_enum(pr, HD_PRESET_COUNT) ? FZ_R(IE) : 0)
                         : fz_bad_enum(pr, HD_PRESET_COUNT) ? FZ_R(IE) : FZ_OK);
    if (r != HD_SUCCESS) return;
    if (pr == HD_PRESET_PAPER ? p.illumination_downsample != 1 || p.diffusion_boundary != HD_BOUNDARY_BOX ||
                                    p.solver != HD_SOLVER_RED_BLACK || p.diffusion_sweeps != 4
                              : p.illumination_downsample != 0 || p.diffusion_boundary != HD_BOUNDARY_DEFAULT ||
                                    p.solver != HD_SOLVER_DEFAULT || p.diffusion_sweeps != 0)
        fz_fail("hd_params_preset(%d) set other values", pr);
    {
        hd_params filled = p;
        fz_snap now;
        fz_params_defaults(&filled);
        fz_tr_params("p", &p);
        fz_tr("    r = hd_set_params(c%d, &p);\n", ci);
        fz_begin(ci, &pre, "hd_set_params (preset)");
        r = hd_set_params(fz_c[ci].h, &p);
        fz_end(&pre, r, filled.method == HD_METHOD_CD && fz_has_area(pre.s.l, pre.s.nl) ?
                            (fz_params_want(&filled) & ~FZ_OK) | FZ_R(HD_ERROR_UNSUPPORTED) : fz_params_want(&filled));
        if (r != HD_SUCCESS) return;
        fz_snap_take(fz_c[ci].h, &now);
        if (memcmp(&now.p, &filled, sizeof filled)) fz_fail("hd_query_desc's params are not the preset's");
        fz_check_params_restart(&pre.s, &now);
    }
}

/* The GL and Vulkan backends' calls (bit 0: which; GL: bits 6-7, Vulkan: bits 5-7, which call of
   it): unsupported here, before any other check. */
static void fz_op_backend(int ci)
{
    static const char *const vk_names[5] = {"hd_vulkan_record(c, NULL, 1)", "hd_vulkan_record_depth(c, NULL, NULL)",
                                            "hd_vulkan_record_render(c, NULL, NULL, NULL)",
                                            "hd_vulkan_record_illumination(c, NULL, 0, NULL)", "hd_vulkan_record_refine(c, NULL, 1)"};
    static const char *const gl_names[3] = {"hd_gl_render_to_texture(c, 1)", "hd_gl_illumination_texture(c, 1, 0)",
                                            "hd_gl_set_depth_texture(c, 1)"};
    fz_pre pre;
    hd_result r;
    int k = fz_u8(), gl = k & 1, v = gl ? (k >> 6) % 3 : (k >> 5) % 5;
    const char *name = gl ? gl_names[v] : vk_names[v];
    fz_tr("    r = %s;\n", name);
    fz_begin(ci, &pre, name);
    if (gl) r = v == 0 ? hd_gl_render_to_texture(fz_c[ci].h, 1u) : v == 1 ? hd_gl_illumination_texture(fz_c[ci].h, 1u, 0)
                                                                           : hd_gl_set_depth_texture(fz_c[ci].h, 1u);
    else r = v == 0   ? hd_vulkan_record(fz_c[ci].h, NULL, 1)
             : v == 1 ? hd_vulkan_record_depth(fz_c[ci].h, NULL, NULL)
             : v == 2 ? hd_vulkan_record_render(fz_c[ci].h, NULL, NULL, NULL)
             : v == 3 ? hd_vulkan_record_illumination(fz_c[ci].h, NULL, 0, NULL)
                      : hd_vulkan_record_refine(fz_c[ci].h, NULL, 1);
    fz_end(&pre, r, FZ_R(HD_ERROR_UNSUPPORTED));
}

/* hd_read_depth: every refusal that applies (NULL, PT, a look-at camera, a short buffer, no
   frame yet), else the window depths, each in [0, 1]. */
static void fz_op_read_depth(int ci)
{
    fz_pre pre;
    fz_snap s;
    hd_result r;
    fz_set allowed = 0;
    int null, i, lookat = 1;
    size_t need, size, k;
    fz_snap_take(fz_c[ci].h, &s);
    for (i = 0; i < 16; ++i) lookat &= s.cam.projection[i] == 0.0f;
    need = (size_t)s.cam.width * (size_t)s.cam.height;
    size = fz_size(need, &null);
    if (need == 0 && size == (size_t)-1) size = 0;
    if (null) allowed |= FZ_R(HD_ERROR_NULL_POINTER);
    if (fz_pt(s.p.method)) allowed |= FZ_R(HD_ERROR_UNSUPPORTED);
    if (lookat) allowed |= FZ_R(HD_ERROR_DEPTH_NEEDS_PROJECTION);
    if (size < need) allowed |= FZ_R(HD_ERROR_BUFFER_TOO_SMALL);
    if (!allowed) allowed = FZ_OK | (s.st.frames == 0 ? FZ_R(HD_ERROR_NO_FRAME) : 0);
    fz_tr("    r = hd_read_depth(c%d, %s, %zu);\n", ci, null ? "NULL" : "buf", size);
    fz_begin(ci, &pre, "hd_read_depth");
    r = hd_read_depth(fz_c[ci].h, null ? NULL : fz_img, size);
    fz_end(&pre, r, allowed);
    if (r != HD_SUCCESS) return;
    fz_same(fz_c[ci].h, &pre.s, "a depth read");
    for (k = 0; k < need; ++k)
        if (!(fz_img[k] >= 0.0f && fz_img[k] <= 1.0f)) fz_fail("depth value %zu is %g", k, (double)fz_img[k]);
}

static void fz_op_names(void)
{
    int v = (int)(int8_t)fz_u8() * 1000003;
    const char *a = hd_result_string((hd_result)v), *b = hd_method_name((hd_method)v), *c = hd_backend_name();
    ++fz_step;
    if (!a || !a[0] || !b || !b[0] || !c || !c[0]) fz_fail("a name of %d is empty", v);
}

/* ---- life cycle ---------------------------------------------------------------------------------- */
static void fz_destroy(int ci)
{
    fz_pre pre;
    hd_result r;
    fz_tr("    r = hd_destroy(c%d);\n", ci);
    fz_begin(ci, &pre, "hd_destroy");
    r = hd_destroy(fz_c[ci].h);
    pre.ci = -1; /* its snapshot cannot be taken now */
    fz_end(&pre, r, FZ_OK);
    if (fz_c[ci].o->errors) fz_fail("hd_destroy logged %d errors", fz_c[ci].o->errors);
    if (fz_c[ci].o->live) fz_fail("hd_destroy left %ld blocks allocated", fz_c[ci].o->live);
    fz_owner_free(fz_c[ci].o); /* what a caller does with its logger's data */
    if (fz_nstale < FZ_STALE) fz_stale[fz_nstale++] = fz_c[ci].h;
    else fz_stale[fz_u8() % FZ_STALE] = fz_c[ci].h;
    memset(&fz_c[ci], 0, sizeof fz_c[ci]);
}

/* A call on a handle no context has: destroyed, zero, or forged. */
static void fz_op_stale(void)
{
    hd_context h;
    hd_params p;
    hd_camera cam;
    hd_light l;
    hd_stats st;
    hd_desc q;
    hd_transfer_function t = {NULL, 0};
    hd_result r;
    fz_pre pre;
    uint8_t b = fz_u8();
    int k = fz_u8() % 16, i, errs[FZ_CTX];
    long calls[FZ_CTX] = {0, 0};
    fz_snap snaps[FZ_CTX];
    h.id = 0;
    if (b < 160 && fz_nstale) h = fz_stale[b % fz_nstale];
    else if (b < 220 && (fz_c[0].live || fz_c[1].live)) h.id = fz_c[fz_c[0].live ? 0 : 1].h.id ^ (1u << (8 + b % 24));
    else if (b >= 240) h.id = 0xffffffffu;
    memset(&p, 0, sizeof p);
    memset(&cam, 0, sizeof cam);
    memset(&l, 0, sizeof l);
    l.direction[2] = -1.0f;
    cam.width = cam.height = 4;
    fz_tr("    r = call %d on handle 0x%08x;\n", k, (unsigned)h.id);
    for (i = 0; i < FZ_CTX; ++i)
        if (fz_c[i].live) { fz_snap_take(fz_c[i].h, &snaps[i]); fz_c[i].o->errors = 0; calls[i] = fz_c[i].o->calls; }
    fz_begin(-1, &pre, "a call on an invalid handle");
    pre.other = -1;
    switch (k) {
    case 0: r = hd_destroy(h); break;
    case 1: r = hd_query_desc(h, &q); break;
    case 2: r = hd_set_transfer_function(h, &t); break;
    case 3: r = hd_set_lights(h, &l, 1); break;
    case 4: r = hd_set_camera(h, &cam); break;
    case 5: r = hd_set_params(h, &p); break;
    case 6: r = hd_iterate(h, 1); break;
    case 7: r = hd_refine(h, 1); break;
    case 8: r = hd_render(h); break;
    case 9: r = hd_read_image_rgba8(h, fz_px, sizeof fz_px); break;
    case 10: r = hd_read_image_f32(h, fz_img, sizeof fz_img / sizeof fz_img[0]); break;
    case 11: r = hd_read_illumination(h, HD_ILLUMINATION_DIRECT, fz_ill, sizeof fz_ill / sizeof fz_ill[0]); break;
    case 12: r = hd_get_stats(h, &st); break;
    case 13: r = hd_vulkan_record(h, NULL, 1); break;
    case 14: r = hd_gl_render_to_texture(h, 1u); break;
    default: r = hd_set_transfer_function(h, NULL); break;
    }
    for (i = 0; i < FZ_CTX; ++i) {
        errs[i] = fz_c[i].live ? fz_c[i].o->errors : 0;
        if (fz_c[i].live) {
            /* a live context's logger may hear of it (the slot's); nothing is allocated */
            if (errs[i] > 1 || (errs[i] == 1 && fz_c[i].o->code != HD_ERROR_INVALID_HANDLE) || fz_c[i].o->calls != calls[i])
                fz_fail("an invalid handle's call reached context %d: %d errors, %ld allocations", i, errs[i], fz_c[i].o->calls - calls[i]);
            fz_c[i].o->errors = 0;
        }
    }
    fz_end(&pre, r, FZ_R(HD_ERROR_INVALID_HANDLE));
    for (i = 0; i < FZ_CTX; ++i)
        if (fz_c[i].live) fz_same(fz_c[i].h, &snaps[i], "a call on an invalid handle");
}

/* The first frame's alpha against that of the same voxels normalised in double to F32 {0, 1}
   (HD, CD: alpha depends only on sigma_t along rays both jitter alike). */
static void fz_check_reference(int ci, const hd_desc *d)
{
    static float ref[FZ_DIM * FZ_DIM * FZ_DIM];
    hd_desc rd = *d;
    hd_context rc;
    fz_owner *o;
    double lo = d->volume.value_range[0], hi = d->volume.value_range[1];
    size_t n = (size_t)d->volume.dims[0] * d->volume.dims[1] * d->volume.dims[2], i, npx;
    hd_result r;
    if (lo == 0.0 && hi == 0.0) {
        lo = d->volume.type == HD_VOXEL_I16 ? -32768.0 : 0.0;
        hi = d->volume.type == HD_VOXEL_U8 ? 255.0 : d->volume.type == HD_VOXEL_U16 ? 65535.0 : d->volume.type == HD_VOXEL_I16 ? 32767.0 : 1.0;
    }
    for (i = 0; i < n; ++i) {
        double v, t;
        if (d->volume.type == HD_VOXEL_U8) v = ((const uint8_t *)d->volume.data)[i];
        else if (d->volume.type == HD_VOXEL_U16) { uint16_t u; memcpy(&u, (const uint8_t *)d->volume.data + 2 * i, 2); v = u; }
        else if (d->volume.type == HD_VOXEL_I16) { int16_t u; memcpy(&u, (const uint8_t *)d->volume.data + 2 * i, 2); v = u; }
        else { float f; memcpy(&f, (const uint8_t *)d->volume.data + 4 * i, 4); v = f; }
        t = (v - lo) / (hi - lo);
        ref[i] = t != t ? 0.0f : t < 0.0 ? 0.0f : t > 1.0 ? 1.0f : (float)t;
    }
    rd.volume.type = HD_VOXEL_F32;
    rd.volume.data = ref;
    rd.volume.value_range[0] = 0.0f;
    rd.volume.value_range[1] = 1.0f;
    o = fz_owner_new();
    rd.logger.user_data = o;
    rd.allocator.user_data = o;
    fz_call = "the value range's reference context";
    /* a global majorant may fit one volume's rounding and not the other's: then no comparison */
    if ((r = hd_create(&rd, &rc)) != HD_SUCCESS) rc.id = 0;
    else if ((r = hd_iterate(rc, 1)) != HD_SUCCESS) fz_fail("hd_iterate: %s", fz_name(r));
    fz_tr("    r = hd_iterate(c%d, 1); /* compared with the normalised volume's */\n", ci);
    fz_call = "hd_iterate, the first frame";
    ++fz_step;
    if ((r = hd_iterate(fz_c[ci].h, 1)) != HD_SUCCESS) fz_fail("returned %s", fz_name(r));
    npx = (size_t)d->camera.width * (size_t)d->camera.height * 4;
    if (hd_read_image_f32(fz_c[ci].h, fz_img, npx) != HD_SUCCESS) fz_fail("hd_read_image_f32");
    if (!rc.id) { fz_owner_free(o); return; }
    if (hd_read_image_f32(rc, fz_img2, npx) != HD_SUCCESS) fz_fail("hd_read_image_f32 of the reference");
    for (i = 3; i < npx; i += 4)
        if (!(fabsf(fz_img[i] - fz_img2[i]) <= 0.01f))
            fz_fail("pixel %zu's alpha is %g, that of the same voxels normalised in double %g (value range {%g, %g})", i / 4,
                    (double)fz_img[i], (double)fz_img2[i], lo, hi);
    if (hd_destroy(rc) != HD_SUCCESS || o->live) fz_fail("the reference context's hd_destroy");
    fz_owner_free(o);
}

static void fz_tr_desc(const hd_desc *d)
{
    size_t n = 1, i;
    int k;
    char b[40];
    for (k = 0; k < 3; ++k) n *= d->volume.dims[k] >= 1 && d->volume.dims[k] <= FZ_DIM ? (size_t)d->volume.dims[k] : 1;
    fz_tr("    memset(&d, 0, sizeof d);\n    d.volume.type = %d;\n    d.volume.dims[0] = %d; d.volume.dims[1] = %d; d.volume.dims[2] = %d;\n",
          (int)d->volume.type, d->volume.dims[0], d->volume.dims[1], d->volume.dims[2]);
    fz_tr_f("d.volume.spacing", d->volume.spacing, 3);
    fz_tr_f("d.volume.value_range", d->volume.value_range, 2);
    if (d->volume.data) {
        fz_tr("    /* voxels */");
        for (i = 0; i < n; ++i) {
            if (i % 8 == 0) fz_tr("\n   ");
            if (d->volume.type == HD_VOXEL_F32) { float f; memcpy(&f, fz_vox + 4 * i, 4); fz_tr(" %s,", fz_cf(f, b)); }
            else if (d->volume.type == HD_VOXEL_U16) { uint16_t u; memcpy(&u, fz_vox + 2 * i, 2); fz_tr(" %u,", (unsigned)u); }
            else if (d->volume.type == HD_VOXEL_I16) { int16_t u; memcpy(&u, fz_vox + 2 * i, 2); fz_tr(" %d,", (int)u); }
            else fz_tr(" %u,", (unsigned)fz_vox[i]);
        }
        fz_tr("\n    d.volume.data = vox;\n");
    }
    if (d->transfer_function.rgba || d->transfer_function.count) {
        fz_tr_tf(&d->transfer_function);
        fz_tr("    d.transfer_function.rgba = %s; d.transfer_function.count = %d;\n", d->transfer_function.rgba ? "tf" : "NULL",
              d->transfer_function.count);
    }
    if (d->lights || d->light_count) {
        fz_tr_lights(d->lights, d->light_count);
        fz_tr("    d.lights = %s; d.light_count = %d;\n", d->lights ? "lights" : "NULL", d->light_count);
    }
    fz_tr_camera("d.camera", &d->camera);
    fz_tr_params("d.params", &d->params);
    fz_tr("    d.threads = %d;\n", d->threads);
}

/* hd_create into slot ci from the bytes: the result the rules allow, and what it stored. */
static void fz_create(int ci)
{
    static const float ramp[8] = {1, 1, 1, 0, 1, 1, 1, 1};
    hd_desc d;
    hd_light lights[4], filled[4], def;
    hd_params fp;
    hd_camera fc;
    fz_owner *o;
    fz_snap now;
    fz_set parts[5], must = 0, maybe = 0, allowed;
    hd_result r;
    double t0, dt;
    uint8_t b;
    int k, n, nl, g[3];
    memset(&d, 0, sizeof d);
    fz_gen_volume(&d.volume);
    fz_gen_tf(&d.transfer_function);
    if (fz_u8() >= 80) d.lights = fz_gen_lights(lights, &d.light_count);
    fz_gen_camera(&d.camera);
    fz_gen_params(&d.params);
    b = fz_u8();
    d.threads = b < 230 ? 1 : b < 240 ? 2 : b < 250 ? 0 : -1;
    if (d.camera.width == 0 || d.camera.height == 0) d.camera.width = d.camera.height = 4;
    fc = d.camera;
    fz_camera_defaults(&fc);
    fp = d.params;
    fz_params_defaults(&fp);
    parts[0] = fz_volume_want(&d.volume);
    parts[1] = fz_tf_want(&d.transfer_function);
    parts[2] = !d.lights && d.light_count == 0 ? FZ_OK : fz_lights_want(d.lights, d.light_count);
    parts[3] = fz_camera_want(&fc);
    parts[4] = fz_params_want(&fp);
    for (k = 0; k < 5; ++k) {
        if (!(parts[k] & FZ_OK)) must |= parts[k];
        else maybe |= parts[k] & ~FZ_OK;
    }
    if (d.threads < 0) must |= FZ_R(IP);
    if (!must && fp.method == HD_METHOD_CD && fz_has_area(d.lights, d.light_count)) must = FZ_R(HD_ERROR_UNSUPPORTED);
    allowed = must ? must | maybe : FZ_OK | maybe;
    o = fz_owner_new();
    d.logger.func = fz_log;
    d.logger.user_data = o;
    d.allocator.alloc = fz_alloc;
    d.allocator.free = fz_free;
    d.allocator.user_data = o;
    fz_tr_desc(&d);
    fz_tr("    r = hd_create(&d, &c%d);\n", ci);
    fz_call = "hd_create";
    ++fz_step;
    t0 = fz_now();
    r = hd_create(&d, &fz_c[ci].h);
    dt = fz_now() - t0;
    fz_tr("    /* call %d -> %s */\n", fz_step, fz_name(r));
    if (dt > FZ_CALL_SECONDS) fz_fail("took %.2f s", dt);
    if (!(allowed & FZ_R(r))) fz_fail("returned %s; the rules allow %s", fz_name(r), fz_set_names(allowed));
    if (r != HD_SUCCESS) {
        if (o->errors != 1 || o->code != r) fz_fail("rejected with %s, logged %d errors (the last %s)", fz_name(r), o->errors, fz_name(o->code));
        if (o->live) fz_fail("a rejected hd_create left %ld blocks allocated", o->live);
        if (fz_c[ci].h.id != 0) fz_fail("a rejected hd_create gave the handle 0x%08x", (unsigned)fz_c[ci].h.id);
        fz_owner_free(o);
        return;
    }
    if (o->errors) fz_fail("succeeded but logged %d errors", o->errors);
    fz_c[ci].o = o;
    fz_c[ci].live = 1;
    /* what it stored: the desc with its defaults */
    fz_snap_take(fz_c[ci].h, &now);
    if (now.type != (int)d.volume.type || memcmp(now.dims, d.volume.dims, sizeof now.dims)) fz_fail("the volume's type or dims");
    for (k = 0; k < 3; ++k) {
        float sp = d.volume.spacing[0] == 0.0f && d.volume.spacing[1] == 0.0f && d.volume.spacing[2] == 0.0f ? 1.0f : d.volume.spacing[k];
        if (memcmp(&now.spacing[k], &sp, sizeof sp)) fz_fail("spacing[%d] %g", k, (double)now.spacing[k]);
    }
    if (d.volume.value_range[0] == 0.0f && d.volume.value_range[1] == 0.0f) {
        float hi = d.volume.type == HD_VOXEL_U8 ? 255.0f : d.volume.type == HD_VOXEL_U16 ? 65535.0f : d.volume.type == HD_VOXEL_I16 ? 32767.0f : 1.0f;
        float lo = d.volume.type == HD_VOXEL_I16 ? -32768.0f : 0.0f;
        if (now.range[0] != lo || now.range[1] != hi) fz_fail("the default value range {%g, %g}", (double)now.range[0], (double)now.range[1]);
    } else if (memcmp(now.range, d.volume.value_range, sizeof now.range)) fz_fail("the value range");
    if (memcmp(&now.p, &fp, sizeof fp)) fz_fail("hd_query_desc's params are not the desc's, defaults filled in");
    if (memcmp(&now.cam, &fc, sizeof fc)) fz_fail("hd_query_desc's camera is not the desc's, defaults filled in");
    if (d.transfer_function.rgba ? now.ntf != d.transfer_function.count ||
                                       memcmp(now.tf, d.transfer_function.rgba, (size_t)now.ntf * 16)
                                 : now.ntf != 2 || memcmp(now.tf, ramp, sizeof ramp))
        fz_fail("hd_query_desc's transfer function");
    memset(&def, 0, sizeof def);
    def.direction[2] = -1.0f;
    nl = d.lights ? d.light_count : 1;
    for (k = 0; k < nl; ++k) { filled[k] = d.lights ? d.lights[k] : def; fz_light_defaults(&filled[k]); }
    if (now.nl != nl || memcmp(now.l, filled, (size_t)nl * sizeof *filled)) fz_fail("hd_query_desc's lights");
    if (now.st.iterations || now.st.frames || now.st.method != fp.method || now.st.light_converged || now.st.render_scale != 1)
        fz_fail("a new context's stats: %llu iterations, %llu frames", (unsigned long long)now.st.iterations, (unsigned long long)now.st.frames);
    for (k = 0; k < 3; ++k) g[k] = (d.volume.dims[k] + fp.illumination_downsample - 1) / fp.illumination_downsample;
    if (!fz_pt(fp.method) && memcmp(now.st.illumination_dims, g, sizeof g)) fz_fail("illumination dims");
    if (now.st.illumination_channels != fz_channels(filled, nl, fp.rgb_scattering)) fz_fail("%d illumination channels", now.st.illumination_channels);
    n = fz_u8() & 1;
    if (n && !fz_pt(fp.method)) fz_check_reference(ci, &d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    int op, i;
    double start;
    fz_p = data;
    fz_n = size;
    fz_at = 0;
    fz_step = 0;
    fz_nstale = 0;
    fz_trace = getenv("HD_FZ_TRACE") != NULL;
    memset(fz_c, 0, sizeof fz_c);
    start = fz_now();
    fz_create(0);
    for (op = 0; op < FZ_OPS && fz_more() && fz_now() - start < FZ_INPUT_SECONDS; ++op) {
        uint8_t b = fz_u8();
        int ci = b & 1, kind = b >> 1; /* 0..127 */
        if (!fz_c[ci].live) ci = 1 - ci;
        if (!fz_c[ci].live || kind >= 124) { /* no context, or now and then: another */
            if (!fz_c[0].live) fz_create(0);
            else if (!fz_c[1].live) fz_create(1);
            else fz_op_stale();
            continue;
        }
        kind %= 31;
        switch (kind) {
        case 0: case 1: case 2: fz_op_params(ci, 0); break;
        case 3: fz_op_params(ci, 1); break;
        case 4: case 5: fz_op_camera(ci); break;
        case 6: case 7: fz_op_lights(ci); break;
        case 8: fz_op_tf(ci); break;
        case 9: case 10: case 11: fz_op_iterate(ci, 0); break;
        case 12: case 13: fz_op_iterate(ci, 1); break;
        case 14: case 15: case 16: case 17: fz_op_render(ci); break;
        case 18: case 19: fz_op_read(ci, 0); break;
        case 20: case 21: fz_op_read(ci, 1); break;
        case 22: fz_op_read(ci, 2); break;
        case 23: fz_op_info(ci); break;
        case 24: fz_destroy(ci); break;
        case 25: case 26: fz_op_stale(); break;
        case 27: fz_op_preset(ci); break;
        case 28: fz_op_backend(ci); break;
        case 29: fz_op_names(); break;
        case 30: fz_op_read_depth(ci); break;
        default: fz_op_render(ci); break;
        }
    }
    for (i = 0; i < FZ_CTX; ++i)
        if (fz_c[i].live) fz_destroy(i);
    for (i = 0; i < FZ_OWNERS; ++i)
        if (fz_owners[i]) fz_fail("an owner outlived its context");
    return 0;
}
