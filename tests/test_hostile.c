/* test_hostile.c - every public function under hostile arguments, table-driven. Extends
   test_core.c (which covers hd_create's desc fields and a first set of setter errors) with: every
   handle-taking function x {id 0, never issued, stale, destroyed}; every setter/reader x {NULL,
   NaN, Inf, negative, zero, huge, out-of-range enum}; each must return its specific hd_result,
   log exactly one error with that code, allocate nothing (a counting allocator hook: validation
   happens before any backend work), and leave the context working. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>
#include <limits.h>
#include <float.h>
#include <unistd.h>
#ifndef HD_MAX_CONTEXTS
#define HD_MAX_CONTEXTS 64 /* the implementation's default */
#endif

typedef struct hs_state { long allocs, live; int errors; hd_result last; } hs_state;
static hs_state hs;
static void *hs_alloc(size_t n, void *u) { (void)u; ++hs.allocs; ++hs.live; return malloc(n ? n : 1); }
static void hs_free(void *p, void *u) { (void)u; if (p) --hs.live; free(p); }
static void hs_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *f, int l)
{
    (void)u; (void)f; (void)l;
    if (level == HD_LOG_ERROR && msg && msg[0]) { ++hs.errors; hs.last = code; }
}

#define HS_N 10
static uint8_t hs_vol[HS_N * HS_N * HS_N];
static float hs_nan(void) { volatile float z = 0.0f; return z / z; }
static float hs_inf(void) { volatile float z = 0.0f; return 1.0f / z; }

static void hs_desc(hd_desc *d)
{
    memset(d, 0, sizeof *d);
    memset(hs_vol, 200, sizeof hs_vol);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = HS_N;
    d->volume.data = hs_vol;
    d->camera.width = d->camera.height = 8;
    d->params.illumination_downsample = 1; /* the table's buffer sizes are the volume's */
    d->threads = 1;
    d->logger.func = hs_log;
    d->allocator.alloc = hs_alloc;
    d->allocator.free = hs_free;
}

/* ---- the table: one hostile call each on a valid context ---- */
static hd_context C; /* the context under attack */
static hd_params P0;
static hd_camera CAM0;
static hd_light L0;
static const float TF0[8] = {0, 0, 0, 0, 1, 1, 1, 1};

static hd_result c_tf_null(void) { return hd_set_transfer_function(C, NULL); }
static hd_result c_tf_rgba_null(void) { hd_transfer_function t = {NULL, 2}; return hd_set_transfer_function(C, &t); }
static hd_result c_tf_zero(void) { hd_transfer_function t = {TF0, 0}; return hd_set_transfer_function(C, &t); }
static hd_result c_tf_neg(void) { hd_transfer_function t = {TF0, -2}; return hd_set_transfer_function(C, &t); }
static hd_result c_tf_huge(void) { hd_transfer_function t = {TF0, INT_MAX}; return hd_set_transfer_function(C, &t); }
static hd_result c_tf_inf(void) { float f[8]; hd_transfer_function t = {f, 2}; memcpy(f, TF0, sizeof f); f[5] = hs_inf(); return hd_set_transfer_function(C, &t); }
static hd_result c_tf_nan(void) { float f[8]; hd_transfer_function t = {f, 2}; memcpy(f, TF0, sizeof f); f[0] = hs_nan(); return hd_set_transfer_function(C, &t); }
static hd_result c_tf_big(void) { float f[8]; hd_transfer_function t = {f, 2}; memcpy(f, TF0, sizeof f); f[3] = 2.0f; return hd_set_transfer_function(C, &t); }
static hd_result c_li_null(void) { return hd_set_lights(C, NULL, 1); }
static hd_result c_li_zero(void) { return hd_set_lights(C, &L0, 0); }
static hd_result c_li_neg(void) { return hd_set_lights(C, &L0, -1); }
static hd_result c_li_huge(void) { return hd_set_lights(C, &L0, INT_MAX); }
static hd_result c_li_enum(void) { hd_light l = L0; l.type = (hd_light_type)7; return hd_set_lights(C, &l, 1); }
static hd_result c_li_enum_neg(void) { hd_light l = L0; l.type = (hd_light_type)-1; return hd_set_lights(C, &l, 1); }
static hd_result c_li_nan(void) { hd_light l = L0; l.direction[1] = hs_nan(); return hd_set_lights(C, &l, 1); }
static hd_result c_li_inf(void) { hd_light l = L0; l.intensity = hs_inf(); return hd_set_lights(C, &l, 1); }
static hd_result c_li_negcol(void) { hd_light l = L0; l.color[2] = -0.1f; return hd_set_lights(C, &l, 1); }
static hd_result c_li_pos_inf(void) { hd_light l = L0; l.type = HD_LIGHT_POINT; l.position[0] = hs_inf(); return hd_set_lights(C, &l, 1); }
/* finite extremes: each would hang the tracking, overflow a product or lose the ray */
static hd_result c_li_pos_far(void) { hd_light l = L0; l.type = HD_LIGHT_POINT; l.position[0] = 1e30f; return hd_set_lights(C, &l, 1); }
static hd_result c_li_power_max(void) { hd_light l = L0; l.intensity = FLT_MAX; return hd_set_lights(C, &l, 1); }
static hd_result c_li_colour_max(void) { hd_light l = L0; l.intensity = 1e20f; l.color[0] = l.color[1] = l.color[2] = 1e20f; return hd_set_lights(C, &l, 1); }
static hd_result c_li_power_sum(void) { hd_light l[2]; l[0] = l[1] = L0; l[0].intensity = l[1].intensity = 0.6f * HD_MAX_LIGHT_POWER; return hd_set_lights(C, l, 2); }
static hd_result c_cam_far(void) { hd_camera c = CAM0; c.eye[2] = 1e30f; return hd_set_camera(C, &c); }
static hd_result c_p_maj_max(void) { hd_params p = P0; p.majorant = FLT_MAX; return hd_set_params(C, &p); }
static hd_result c_p_maj_1e30(void) { hd_params p = P0; p.majorant = 1e30f; return hd_set_params(C, &p); }
static hd_result c_p_maj_1e6(void) { hd_params p = P0; p.majorant = 1e6f; return hd_set_params(C, &p); }
static hd_result c_cam_null(void) { return hd_set_camera(C, NULL); }
static hd_result c_cam_inf(void) { hd_camera c = CAM0; c.target[2] = hs_inf(); return hd_set_camera(C, &c); }
static hd_result c_cam_fov_nan(void) { hd_camera c = CAM0; c.fov_y = hs_nan(); return hd_set_camera(C, &c); }
static hd_result c_cam_fov_neg(void) { hd_camera c = CAM0; c.fov_y = -10.0f; return hd_set_camera(C, &c); }
static hd_result c_cam_huge(void) { hd_camera c = CAM0; c.width = HD_MAX_IMAGE_DIM + 1; return hd_set_camera(C, &c); }
static hd_result c_cam_int_max(void) { hd_camera c = CAM0; c.height = INT_MAX; return hd_set_camera(C, &c); }
static hd_result c_cam_neg(void) { hd_camera c = CAM0; c.height = -1; return hd_set_camera(C, &c); }
/* a tiny up is normalised (any nonzero one works); a tiny one along the view is still parallel */
static hd_result c_cam_up0(void) { hd_camera c = CAM0; c.up[0] = c.up[1] = c.up[2] = 0; c.up[2] = 1e-30f; return hd_set_camera(C, &c); }
static hd_result c_p_null(void) { return hd_set_params(C, NULL); }
static hd_result c_p_method(void) { hd_params p = P0; p.method = HD_METHOD_COUNT; return hd_set_params(C, &p); }
static hd_result c_p_method_neg(void) { hd_params p = P0; p.method = (hd_method)-3; return hd_set_params(C, &p); }
static hd_result c_p_solver(void) { hd_params p = P0; p.solver = (hd_solver)99; return hd_set_params(C, &p); }
static hd_result c_p_ext_inf(void) { hd_params p = P0; p.extinction = hs_inf(); return hd_set_params(C, &p); }
static hd_result c_p_ext_huge(void) { hd_params p = P0; p.extinction = 1e7f; return hd_set_params(C, &p); }
static hd_result c_p_alb_nan(void) { hd_params p = P0; p.albedo = hs_nan(); return hd_set_params(C, &p); }
static hd_result c_p_g_inf(void) { hd_params p = P0; p.anisotropy = -hs_inf(); return hd_set_params(C, &p); }
static hd_result c_p_maj_neg(void) { hd_params p = P0; p.majorant = -1.0f; return hd_set_params(C, &p); }
static hd_result c_p_maj_nan(void) { hd_params p = P0; p.majorant = hs_nan(); return hd_set_params(C, &p); }
static hd_result c_p_sweeps_huge(void) { hd_params p = P0; p.diffusion_sweeps = INT_MAX; return hd_set_params(C, &p); }
static hd_result c_p_bg_nan(void) { hd_params p = P0; p.background[1] = hs_nan(); return hd_set_params(C, &p); }
static hd_result c_p_bg_neg(void) { hd_params p = P0; p.background[0] = -1.0f; return hd_set_params(C, &p); }
static hd_result c_p_step_inf(void) { hd_params p = P0; p.step = hs_inf(); return hd_set_params(C, &p); }
static hd_result c_p_step_tiny(void) { hd_params p = P0; p.step = 1e-9f; return hd_set_params(C, &p); }
static hd_result c_p_window_neg(void) { hd_params p = P0; p.frame_window = -1; return hd_set_params(C, &p); }
static hd_result c_p_exp_inf(void) { hd_params p = P0; p.exposure = hs_inf(); return hd_set_params(C, &p); }
static hd_result c_p_bounces(void) { hd_params p = P0; p.max_bounces = -5; return hd_set_params(C, &p); }
static hd_result c_p_dd(void) { hd_params p = P0; p.disable_diffusion = 2; return hd_set_params(C, &p); }
static hd_result c_p_prec(void) { hd_params p = P0; p.illumination_precision = (hd_precision)5; return hd_set_params(C, &p); }
static hd_result c_it_zero(void) { return hd_iterate(C, 0); }
static hd_result c_it_min(void) { return hd_iterate(C, INT_MIN); }
static hd_result c_rgba_null(void) { return hd_read_image_rgba8(C, NULL, 8 * 8 * 4); }
static hd_result c_rgba_zero(void) { uint8_t b[4]; return hd_read_image_rgba8(C, b, 0); }
static hd_result c_rgba_short(void) { static uint8_t b[8 * 8 * 4]; return hd_read_image_rgba8(C, b, sizeof b - 1); }
static hd_result c_f32_null(void) { return hd_read_image_f32(C, NULL, (size_t)-1); }
static hd_result c_f32_short(void) { static float b[8 * 8 * 4]; return hd_read_image_f32(C, b, 8 * 8 * 4 - 1); }
static hd_result c_ill_null(void) { return hd_read_illumination(C, HD_ILLUMINATION_DIRECT, NULL, (size_t)-1); }
static hd_result c_ill_enum(void) { static float b[HS_N * HS_N * HS_N]; return hd_read_illumination(C, HD_ILLUMINATION_COUNT, b, sizeof b / 4); }
static hd_result c_ill_enum_neg(void) { static float b[HS_N * HS_N * HS_N]; return hd_read_illumination(C, (hd_illumination)-1, b, sizeof b / 4); }
static hd_result c_ill_short(void) { static float b[HS_N * HS_N * HS_N]; return hd_read_illumination(C, HD_ILLUMINATION_SCATTERED, b, sizeof b / 4 - 1); }
static hd_result c_stats_null(void) { return hd_get_stats(C, NULL); }
static hd_result c_query_null(void) { return hd_query_desc(C, NULL); }

typedef struct hs_case { const char *name; hd_result expect; hd_result (*call)(void); } hs_case;
static const hs_case hs_cases[] = {
    {"tf NULL", HD_ERROR_NULL_POINTER, c_tf_null},
    {"tf rgba NULL", HD_ERROR_NULL_POINTER, c_tf_rgba_null},
    {"tf count 0", HD_ERROR_INVALID_TRANSFER_FUNCTION, c_tf_zero},
    {"tf count -2", HD_ERROR_INVALID_TRANSFER_FUNCTION, c_tf_neg},
    {"tf count INT_MAX", HD_ERROR_INVALID_TRANSFER_FUNCTION, c_tf_huge},
    {"tf Inf entry", HD_ERROR_INVALID_TRANSFER_FUNCTION, c_tf_inf},
    {"tf NaN entry", HD_ERROR_INVALID_TRANSFER_FUNCTION, c_tf_nan},
    {"tf entry > 1", HD_ERROR_INVALID_TRANSFER_FUNCTION, c_tf_big},
    {"lights NULL", HD_ERROR_NULL_POINTER, c_li_null},
    {"lights 0", HD_ERROR_NO_LIGHTS, c_li_zero},
    {"lights -1", HD_ERROR_NO_LIGHTS, c_li_neg},
    {"lights INT_MAX", HD_ERROR_TOO_MANY_LIGHTS, c_li_huge},
    {"light type 7", HD_ERROR_INVALID_ENUM, c_li_enum},
    {"light type -1", HD_ERROR_INVALID_ENUM, c_li_enum_neg},
    {"light NaN direction", HD_ERROR_INVALID_LIGHT, c_li_nan},
    {"light Inf intensity", HD_ERROR_INVALID_LIGHT, c_li_inf},
    {"light negative colour", HD_ERROR_INVALID_LIGHT, c_li_negcol},
    {"point light Inf position", HD_ERROR_INVALID_LIGHT, c_li_pos_inf},
    {"point light at 1e30", HD_ERROR_INVALID_LIGHT, c_li_pos_far},
    {"light intensity FLT_MAX", HD_ERROR_INVALID_LIGHT, c_li_power_max},
    {"light intensity * colour 1e40", HD_ERROR_INVALID_LIGHT, c_li_colour_max},
    {"lights' summed power > limit", HD_ERROR_INVALID_LIGHT, c_li_power_sum},
    {"camera eye at 1e30", HD_ERROR_INVALID_CAMERA, c_cam_far},
    {"majorant FLT_MAX", HD_ERROR_INVALID_PARAMETER, c_p_maj_max},
    {"majorant 1e30", HD_ERROR_INVALID_PARAMETER, c_p_maj_1e30},
    {"majorant 1e6 (> 16 x max sigma_t)", HD_ERROR_INVALID_PARAMETER, c_p_maj_1e6},
    {"camera NULL", HD_ERROR_NULL_POINTER, c_cam_null},
    {"camera Inf target", HD_ERROR_INVALID_CAMERA, c_cam_inf},
    {"camera NaN fov", HD_ERROR_INVALID_CAMERA, c_cam_fov_nan},
    {"camera negative fov", HD_ERROR_INVALID_CAMERA, c_cam_fov_neg},
    {"camera width > max", HD_ERROR_INVALID_DIMENSIONS, c_cam_huge},
    {"camera height INT_MAX", HD_ERROR_INVALID_DIMENSIONS, c_cam_int_max},
    {"camera height -1", HD_ERROR_INVALID_DIMENSIONS, c_cam_neg},
    {"camera up 1e-30 along the view", HD_ERROR_INVALID_CAMERA, c_cam_up0},
    {"params NULL", HD_ERROR_NULL_POINTER, c_p_null},
    {"method COUNT", HD_ERROR_INVALID_ENUM, c_p_method},
    {"method -3", HD_ERROR_INVALID_ENUM, c_p_method_neg},
    {"solver 99", HD_ERROR_INVALID_ENUM, c_p_solver},
    {"extinction Inf", HD_ERROR_INVALID_PARAMETER, c_p_ext_inf},
    {"extinction 1e7", HD_ERROR_INVALID_PARAMETER, c_p_ext_huge},
    {"albedo NaN", HD_ERROR_INVALID_PARAMETER, c_p_alb_nan},
    {"anisotropy -Inf", HD_ERROR_INVALID_PARAMETER, c_p_g_inf},
    {"majorant -1", HD_ERROR_INVALID_PARAMETER, c_p_maj_neg},
    {"majorant NaN", HD_ERROR_INVALID_PARAMETER, c_p_maj_nan},
    {"sweeps INT_MAX", HD_ERROR_INVALID_PARAMETER, c_p_sweeps_huge},
    {"background NaN", HD_ERROR_INVALID_PARAMETER, c_p_bg_nan},
    {"background -1", HD_ERROR_INVALID_PARAMETER, c_p_bg_neg},
    {"step Inf", HD_ERROR_INVALID_PARAMETER, c_p_step_inf},
    {"step 1e-9", HD_ERROR_INVALID_PARAMETER, c_p_step_tiny},
    {"frame_window -1", HD_ERROR_INVALID_PARAMETER, c_p_window_neg},
    {"exposure Inf", HD_ERROR_INVALID_PARAMETER, c_p_exp_inf},
    {"max_bounces -5", HD_ERROR_INVALID_PARAMETER, c_p_bounces},
    {"disable_diffusion 2", HD_ERROR_INVALID_PARAMETER, c_p_dd},
    {"illumination_precision 5", HD_ERROR_INVALID_ENUM, c_p_prec},
    {"iterate 0", HD_ERROR_INVALID_PARAMETER, c_it_zero},
    {"iterate INT_MIN", HD_ERROR_INVALID_PARAMETER, c_it_min},
    {"rgba8 NULL", HD_ERROR_NULL_POINTER, c_rgba_null},
    {"rgba8 0 bytes", HD_ERROR_BUFFER_TOO_SMALL, c_rgba_zero},
    {"rgba8 one byte short", HD_ERROR_BUFFER_TOO_SMALL, c_rgba_short},
    {"f32 NULL, SIZE_MAX", HD_ERROR_NULL_POINTER, c_f32_null},
    {"f32 one float short", HD_ERROR_BUFFER_TOO_SMALL, c_f32_short},
    {"illumination NULL", HD_ERROR_NULL_POINTER, c_ill_null},
    {"illumination enum COUNT", HD_ERROR_INVALID_ENUM, c_ill_enum},
    {"illumination enum -1", HD_ERROR_INVALID_ENUM, c_ill_enum_neg},
    {"illumination one short", HD_ERROR_BUFFER_TOO_SMALL, c_ill_short},
    {"stats NULL", HD_ERROR_NULL_POINTER, c_stats_null},
    {"query NULL", HD_ERROR_NULL_POINTER, c_query_null},
};

static void test_hostile_args(void)
{
    hd_desc d;
    hd_desc q;
    size_t i;
    hs_desc(&d);
    memset(&hs, 0, sizeof hs);
    CHECK(hd_create(&d, &C) == HD_SUCCESS);
    CHECK(hd_query_desc(C, &q) == HD_SUCCESS);
    P0 = q.params;
    CAM0 = q.camera;
    L0 = q.lights[0];
    CHECK(hd_iterate(C, 1) == HD_SUCCESS);
    for (i = 0; i < sizeof hs_cases / sizeof hs_cases[0]; ++i) {
        long allocs;
        hd_result r;
        hs.errors = 0;
        hs.last = HD_SUCCESS;
        allocs = hs.allocs;
        r = hs_cases[i].call();
        CHECK_MSG(r == hs_cases[i].expect, "%s: got %s, want %s", hs_cases[i].name,
                  hd_result_string(r), hd_result_string(hs_cases[i].expect));
        CHECK_MSG(hs.errors == 1 && hs.last == r, "%s: %d errors logged", hs_cases[i].name,
                  hs.errors);
        CHECK_MSG(hs.allocs == allocs, "%s: a rejected call allocated %ld times", hs_cases[i].name,
                  hs.allocs - allocs);
    }
    /* still fully usable, and the rejected calls changed nothing */
    hs.errors = 0;
    CHECK(hd_query_desc(C, &q) == HD_SUCCESS);
    CHECK(memcmp(&q.params, &P0, sizeof P0) == 0 && memcmp(&q.camera, &CAM0, sizeof CAM0) == 0);
    CHECK(hd_iterate(C, 1) == HD_SUCCESS && hs.errors == 0);
    CHECK(hd_destroy(C) == HD_SUCCESS);
    CHECK(hs.live == 0);
}

/* Every handle-taking function x {0, never issued, stale (destroyed), destroyed twice}. */
static void test_hostile_handles(void)
{
    hd_desc d, q;
    hd_context live, stale, zero, forged;
    hd_stats st;
    float f[4];
    uint8_t b[4];
    hd_transfer_function tf = {TF0, 2};
    int k, which;
    hs_desc(&d);
    memset(&hs, 0, sizeof hs);
    CHECK(hd_create(&d, &stale) == HD_SUCCESS);
    CHECK(hd_query_desc(stale, &q) == HD_SUCCESS);
    P0 = q.params; CAM0 = q.camera; L0 = q.lights[0];
    CHECK(hd_destroy(stale) == HD_SUCCESS);
    CHECK(hd_create(&d, &live) == HD_SUCCESS); /* may reuse the slot: the stale id must not work */
    CHECK(live.id != stale.id);
    zero.id = 0;
    forged.id = live.id ^ 0x5a5a0000u;
    for (which = 0; which < 3; ++which) {
        hd_context h = which == 0 ? zero : which == 1 ? forged : stale;
        for (k = 0; k < 11; ++k) {
            hd_result r;
            long allocs = hs.allocs;
            hs.errors = 0;
            switch (k) {
            case 0: r = hd_destroy(h); break;
            case 1: r = hd_query_desc(h, &q); break;
            case 2: r = hd_set_transfer_function(h, &tf); break;
            case 3: r = hd_set_lights(h, &L0, 1); break;
            case 4: r = hd_set_camera(h, &CAM0); break;
            case 5: r = hd_set_params(h, &P0); break;
            case 6: r = hd_iterate(h, 1); break;
            case 7: r = hd_read_image_rgba8(h, b, sizeof b); break;
            case 8: r = hd_read_image_f32(h, f, 4); break;
            case 9: r = hd_read_illumination(h, HD_ILLUMINATION_DIRECT, f, 4); break;
            default: r = hd_get_stats(h, &st); break;
            }
            CHECK_MSG(r == HD_ERROR_INVALID_HANDLE, "handle %d call %d: %s", which, k,
                      hd_result_string(r));
            CHECK_MSG(hs.allocs == allocs, "handle %d call %d allocated", which, k);
            /* a destroyed handle whose slot knows a logger says why */
            if (which == 2) CHECK_MSG(hs.errors <= 1, "call %d: %d messages", k, hs.errors);
        }
    }
    /* the live context was not disturbed by any of that */
    CHECK(hd_iterate(live, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(live, &st) == HD_SUCCESS && st.iterations == 1);
    CHECK(hd_destroy(live) == HD_SUCCESS);
    CHECK(hd_destroy(live) == HD_ERROR_INVALID_HANDLE); /* double destroy */
    CHECK(hs.live == 0);
}

/* ---- finite extremes through hd_create: 1e+-30, denormals, FLT_MAX ---- */
/* Each case edits a valid desc; want HD_SUCCESS means the context must iterate (HD, then PT_MS)
   and give a finite image; an error must be that code with one logged line. A hang is caught by
   alarm(): SIGALRM ends the run. */
typedef struct hx_case { const char *name; hd_result expect; void (*edit)(hd_desc *d, hd_light *l); } hx_case;
static float hx_denormal(void) { volatile float f = FLT_MIN; return f / 1024.0f; }
static void x_sp_mixed(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = 1e-30f; d->volume.spacing[1] = 1.0f; d->volume.spacing[2] = 1e30f; }
static void x_sp_tiny(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = 1e-30f; d->volume.spacing[1] = d->volume.spacing[2] = 1.0f; }
static void x_sp_denormal_one(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = hx_denormal(); d->volume.spacing[1] = d->volume.spacing[2] = 1.0f; }
static void x_sp_max_one(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = d->volume.spacing[1] = FLT_MAX; d->volume.spacing[2] = 1.0f; }
static void x_sp_max_all(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = d->volume.spacing[1] = d->volume.spacing[2] = FLT_MAX; }
static void x_sp_denormal_all(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = d->volume.spacing[1] = d->volume.spacing[2] = hx_denormal(); }
static void x_sp_1e30_all(hd_desc *d, hd_light *l) { (void)l; d->volume.spacing[0] = d->volume.spacing[1] = d->volume.spacing[2] = 1e30f; }
static void x_maj_max(hd_desc *d, hd_light *l) { (void)l; d->params.majorant = FLT_MAX; }
static void x_dir_huge(hd_desc *d, hd_light *l) { l->direction[0] = 1e30f; l->direction[1] = -3e30f; l->direction[2] = 2e30f; d->light_count = 1; }
static void x_dir_max(hd_desc *d, hd_light *l) { l->direction[0] = FLT_MAX; l->direction[1] = FLT_MAX; l->direction[2] = -FLT_MAX; d->light_count = 1; }
static void x_dir_tiny(hd_desc *d, hd_light *l) { l->direction[0] = 0.0f; l->direction[1] = 1e-30f; l->direction[2] = -1e-30f; d->light_count = 1; }
static void x_dir_denormal(hd_desc *d, hd_light *l) { l->direction[0] = 0.0f; l->direction[1] = 0.0f; l->direction[2] = -hx_denormal(); d->light_count = 1; }
static void x_pt_far(hd_desc *d, hd_light *l) { l->type = HD_LIGHT_POINT; l->position[0] = 1e30f; d->light_count = 1; }
static void x_pt_far_ok(hd_desc *d, hd_light *l) { l->type = HD_LIGHT_POINT; l->position[0] = 1e14f; l->inverse_square = 1; d->light_count = 1; }
static void x_pt_at_voxel(hd_desc *d, hd_light *l) { l->type = HD_LIGHT_POINT; l->position[0] = 0.05f; l->position[1] = 0.05f; l->position[2] = 0.05f; l->inverse_square = 1; l->intensity = HD_MAX_LIGHT_POWER; d->light_count = 1; }
static void x_int_max(hd_desc *d, hd_light *l) { l->intensity = FLT_MAX; d->light_count = 1; }
static void x_col_max(hd_desc *d, hd_light *l) { l->intensity = 2.0f; l->color[0] = FLT_MAX; l->color[1] = 1.0f; d->light_count = 1; }
static void x_power_limit(hd_desc *d, hd_light *l) { l->intensity = HD_MAX_LIGHT_POWER; d->light_count = 1; d->params.albedo = 1.0f; }
static void x_eye_far(hd_desc *d, hd_light *l) { (void)l; d->camera.eye[2] = 1e30f; }
static void x_target_far(hd_desc *d, hd_light *l) { (void)l; d->camera.eye[2] = 2.5f; d->camera.target[0] = -1e30f; }
static void x_int_max_col_min(hd_desc *d, hd_light *l) { l->intensity = FLT_MAX; l->color[2] = FLT_MIN; d->light_count = 1; }
static void x_up_tiny(hd_desc *d, hd_light *l) { (void)l; d->camera.up[0] = 1e-24f; }
static void x_bg_max(hd_desc *d, hd_light *l) { (void)l; d->params.background[0] = FLT_MAX; d->params.background[2] = 1e30f; }

static const hx_case hx_cases[] = {
    {"spacing 1e-30, 1, 1e30", HD_ERROR_INVALID_SPACING, x_sp_mixed},
    {"spacing 1e-30, 1, 1", HD_ERROR_INVALID_SPACING, x_sp_tiny},
    {"spacing denormal, 1, 1", HD_ERROR_INVALID_SPACING, x_sp_denormal_one},
    {"spacing FLT_MAX, FLT_MAX, 1", HD_ERROR_INVALID_SPACING, x_sp_max_one},
    {"spacing FLT_MAX x3", HD_SUCCESS, x_sp_max_all},
    {"spacing denormal x3", HD_SUCCESS, x_sp_denormal_all},
    {"spacing 1e30 x3", HD_SUCCESS, x_sp_1e30_all},
    {"majorant FLT_MAX", HD_ERROR_INVALID_PARAMETER, x_maj_max},
    {"direction 1e30", HD_SUCCESS, x_dir_huge},
    {"direction FLT_MAX", HD_SUCCESS, x_dir_max},
    {"direction 1e-30", HD_SUCCESS, x_dir_tiny},
    {"direction denormal", HD_SUCCESS, x_dir_denormal},
    {"point light at 1e30", HD_ERROR_INVALID_LIGHT, x_pt_far},
    {"point light at 1e14, 1/r^2", HD_SUCCESS, x_pt_far_ok},
    {"point light in the volume, 1/r^2, max power", HD_SUCCESS, x_pt_at_voxel},
    {"intensity FLT_MAX", HD_ERROR_INVALID_LIGHT, x_int_max},
    {"colour FLT_MAX", HD_ERROR_INVALID_LIGHT, x_col_max},
    {"power at the limit, albedo 1", HD_SUCCESS, x_power_limit},
    {"camera eye at 1e30", HD_ERROR_INVALID_CAMERA, x_eye_far},
    {"camera target at -1e30", HD_ERROR_INVALID_CAMERA, x_target_far},
    {"background FLT_MAX", HD_ERROR_INVALID_PARAMETER, x_bg_max},
    {"intensity FLT_MAX, colour {0, 0, FLT_MIN}", HD_SUCCESS, x_int_max_col_min},
    {"camera up {1e-24, 0, 0}", HD_SUCCESS, x_up_tiny},
};

static int hx_image_finite(hd_context ctx)
{
    static float img[8 * 8 * 4];
    int i;
    if (hd_read_image_f32(ctx, img, 8 * 8 * 4) != HD_SUCCESS) return 0;
    for (i = 0; i < 8 * 8 * 4; ++i)
        if (!(img[i] - img[i] == 0.0f)) return 0;
    return 1;
}

static void test_hostile_extremes(void)
{
    size_t i;
    alarm(300); /* every case takes milliseconds; a hang ends the run */
    for (i = 0; i < sizeof hx_cases / sizeof hx_cases[0]; ++i) {
        hd_desc d;
        hd_light l;
        hd_context ctx;
        hd_result r;
        hs_desc(&d);
        memset(&l, 0, sizeof l);
        l.direction[2] = -1.0f;
        d.lights = &l;
        d.light_count = 1;
        hx_cases[i].edit(&d, &l);
        memset(&hs, 0, sizeof hs);
        r = hd_create(&d, &ctx);
        CHECK_MSG(r == hx_cases[i].expect, "%s: got %s, want %s", hx_cases[i].name, hd_result_string(r),
                  hd_result_string(hx_cases[i].expect));
        if (r != HD_SUCCESS) {
            CHECK_MSG(hs.errors == 1 && hs.last == r, "%s: %d errors logged", hx_cases[i].name, hs.errors);
        } else {
            hd_params p;
            hd_desc q;
            CHECK_MSG(hd_iterate(ctx, 2) == HD_SUCCESS, "%s: HD iterate", hx_cases[i].name);
            CHECK_MSG(hx_image_finite(ctx), "%s: HD image not finite", hx_cases[i].name);
            CHECK(hd_query_desc(ctx, &q) == HD_SUCCESS);
            p = q.params;
            p.method = HD_METHOD_PT_MS;
            CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
            CHECK_MSG(hd_iterate(ctx, 2) == HD_SUCCESS, "%s: PT_MS iterate", hx_cases[i].name);
            CHECK_MSG(hx_image_finite(ctx), "%s: PT_MS image not finite", hx_cases[i].name);
            CHECK_MSG(hs.errors == 0, "%s: %d errors logged", hx_cases[i].name, hs.errors);
            CHECK(hd_destroy(ctx) == HD_SUCCESS);
        }
        CHECK(hs.live == 0);
    }
    alarm(0);
}

/* Names of out-of-range enums and the context limit. */
static void test_hostile_misc(void)
{
    hd_desc d;
    static hd_context ctx[HD_MAX_CONTEXTS + 1];
    int i, n = 0;
    hd_result r = HD_SUCCESS;
    CHECK(hd_result_string((hd_result)-1) != NULL && hd_result_string(HD_RESULT_COUNT) != NULL);
    CHECK(hd_result_string((hd_result)INT_MAX) != NULL);
    CHECK(hd_method_name((hd_method)-1) != NULL && hd_method_name(HD_METHOD_COUNT) != NULL);
    CHECK(hd_backend_name() != NULL);
    hs_desc(&d);
    memset(&hs, 0, sizeof hs);
    for (i = 0; i <= HD_MAX_CONTEXTS; ++i) {
        r = hd_create(&d, &ctx[i]);
        if (r != HD_SUCCESS) break;
        ++n;
    }
    CHECK_MSG(r == HD_ERROR_TOO_MANY_CONTEXTS && hs.last == r, "%d contexts, then %s", n,
              hd_result_string(r));
    CHECK(n <= HD_MAX_CONTEXTS && ctx[n].id == 0);
    for (i = 0; i < n; ++i) CHECK(hd_destroy(ctx[i]) == HD_SUCCESS);
    CHECK(hs.live == 0);
}

const hd_test_case hd_tests_hostile[] = {
    {"hostile_args_table", test_hostile_args},
    {"hostile_handles", test_hostile_handles},
    {"hostile_misc", test_hostile_misc},
    {"hostile_extremes", test_hostile_extremes},
};
const int hd_tests_hostile_count = sizeof hd_tests_hostile / sizeof hd_tests_hostile[0];
