/* fuzz_api.c - libFuzzer target over the API's inputs (mk/reliability.mk: make fuzz-smoke, run
   with -timeout so a hang is a finding; regressions in regressions/api/). The bytes become an
   hd_desc (a volume of at most 5x5x5 voxels, its spacing and value range, a transfer function,
   up to 3 lights, a camera of at most 4x4 pixels, every hd_params field) whose floats are drawn
   mostly from finite extremes (0, +-1e+-30, denormals, FLT_MIN, FLT_MAX, 1e6, ...) and otherwise
   from raw bits (NaN, Inf). hd_create must either fail with one logged error naming its code or
   give a context that runs one iteration, and a second after hd_set_lights / hd_set_camera /
   hd_set_params with more of the bytes, with a finite image and finite illumination; anything
   else aborts, which keeps the input. */
#include "hybriddiff.h" /* the implementation: tests/fuzz/hd_impl_fuzz.c */
#include <float.h>
#include <stdlib.h>
#include <string.h>

typedef struct fz_in { const uint8_t *p; size_t n, at; } fz_in;

static uint8_t fz_u8(fz_in *in) { return in->at < in->n ? in->p[in->at++] : 0; }

static float fz_float(fz_in *in)
{
    static const float table[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, 2.0f, 100.0f, 1e-30f, -1e-30f, 1e30f, -1e30f,
                                  FLT_MIN, -FLT_MIN, FLT_MIN / 4096.0f, -FLT_MIN / 4096.0f, FLT_MAX, -FLT_MAX,
                                  1e-6f, 1e6f, -1e6f, 1e15f, 1e4f, 65536.0f, 0.999999f, 1e-45f, 3.0f};
    uint8_t b = fz_u8(in);
    if (b < 200) return table[b % (sizeof table / sizeof table[0])];
    {
        uint32_t u = (uint32_t)fz_u8(in) | (uint32_t)fz_u8(in) << 8 | (uint32_t)fz_u8(in) << 16 | (uint32_t)fz_u8(in) << 24;
        float f;
        memcpy(&f, &u, sizeof f);
        return f;
    }
}

static void fz_float3(fz_in *in, float v[3]) { v[0] = fz_float(in); v[1] = fz_float(in); v[2] = fz_float(in); }

/* a small int: mostly the low values an API takes, sometimes an out-of-range one */
static int fz_small(fz_in *in, int range)
{
    uint8_t b = fz_u8(in);
    if (b >= 250) return b == 250 ? -1 : b == 251 ? range : b == 252 ? 1 << 30 : -(1 << 30);
    return b % range;
}

/* an image side: 1..4, or out of range (0 would be the default 512) */
static int fz_size(fz_in *in)
{
    uint8_t b = fz_u8(in);
    return b == 255 ? -1 : b == 254 ? HD_MAX_IMAGE_DIM + 1 : 1 + b % 4;
}

static int fz_errors;
static hd_result fz_code;
static void fz_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    (void)u; (void)file; (void)line;
    if (!msg || !msg[0]) abort();
    if (level == HD_LOG_ERROR) { ++fz_errors; fz_code = code; }
}

/* A rejected call: one logged error with its code. */
static void fz_rejected(hd_result r)
{
    if ((int)r <= 0 || (int)r >= (int)HD_RESULT_COUNT || fz_errors != 1 || fz_code != r) abort();
}

static void fz_light(fz_in *in, hd_light *l)
{
    memset(l, 0, sizeof *l);
    l->type = (hd_light_type)fz_small(in, 2);
    fz_float3(in, l->direction);
    fz_float3(in, l->position);
    fz_float3(in, l->color);
    l->intensity = fz_float(in);
    l->inverse_square = fz_u8(in) & 1;
}

static void fz_camera(fz_in *in, hd_camera *c)
{
    memset(c, 0, sizeof *c);
    if (fz_u8(in) & 1) { fz_float3(in, c->eye); fz_float3(in, c->target); }
    if (fz_u8(in) & 1) fz_float3(in, c->up);
    if (fz_u8(in) & 1) c->fov_y = fz_float(in);
    c->width = fz_size(in);
    c->height = fz_size(in);
}

static void fz_params(fz_in *in, hd_params *p)
{
    memset(p, 0, sizeof *p);
    p->method = (hd_method)fz_small(in, HD_METHOD_COUNT);
    if (fz_u8(in) & 1) p->extinction = fz_float(in);
    if (fz_u8(in) & 1) p->albedo = fz_float(in);
    if (fz_u8(in) & 1) p->anisotropy = fz_float(in);
    if (fz_u8(in) & 1) p->majorant = fz_float(in);
    p->diffusion_sweeps = fz_small(in, 3);
    p->disable_diffusion = fz_small(in, 2);
    p->solver = (hd_solver)fz_small(in, HD_SOLVER_COUNT);
    p->tracking = (hd_tracking)fz_small(in, HD_TRACKING_COUNT);
    p->seed = fz_u8(in);
    if (fz_u8(in) & 1) fz_float3(in, p->background);
    if (fz_u8(in) & 1) p->step = fz_float(in);
    p->frame_window = fz_small(in, 4);
    if (fz_u8(in) & 1) p->exposure = fz_float(in);
    p->max_bounces = fz_small(in, 5);
    p->illumination_downsample = fz_small(in, 3);
    p->rgb_scattering = fz_small(in, 2);
    p->diffusion_boundary = (hd_boundary)fz_small(in, HD_BOUNDARY_COUNT);
    p->illumination_precision = (hd_precision)fz_small(in, HD_PRECISION_COUNT);
}

static int fz_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!(v[i] - v[i] == 0.0f)) return 0;
    return 1;
}

/* One iteration, then the image and both illumination volumes must be finite. */
static void fz_run(hd_context ctx)
{
    static float buf[5 * 5 * 5 * 3]; /* the illumination (dims <= 5, 3 channels) or 4x4 RGBA */
    hd_stats st;
    hd_desc q;
    hd_result r;
    fz_errors = 0;
    r = hd_iterate(ctx, 1);
    if (r == HD_ERROR_UNSUPPORTED) { fz_rejected(r); return; }
    if (r != HD_SUCCESS || fz_errors != 0) abort();
    if (hd_get_stats(ctx, &st) != HD_SUCCESS) abort();
    if (hd_query_desc(ctx, &q) != HD_SUCCESS) abort();
    if (hd_read_image_f32(ctx, buf, sizeof buf / sizeof buf[0]) != HD_SUCCESS ||
        !fz_finite(buf, (size_t)q.camera.width * (size_t)q.camera.height * 4))
        abort();
    if (st.method == HD_METHOD_HD || st.method == HD_METHOD_CD) {
        size_t n = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] *
                   (size_t)st.illumination_channels;
        if (hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, buf, sizeof buf / sizeof buf[0]) != HD_SUCCESS ||
            !fz_finite(buf, n))
            abort();
        if (hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, buf, sizeof buf / sizeof buf[0]) != HD_SUCCESS ||
            !fz_finite(buf, n))
            abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static uint8_t vox[5 * 5 * 5 * 4]; /* dims 1 + fz_small(4): 0..5, or rejected */
    static float tf[4 * 4];
    hd_light lights[3];
    fz_in in;
    hd_desc d;
    hd_context ctx;
    hd_result r;
    int i, nvox;
    in.p = data; in.n = size; in.at = 0;
    memset(&d, 0, sizeof d);
    d.volume.type = (hd_voxel_type)(1 + fz_small(&in, 3));
    for (i = 0; i < 3; ++i) d.volume.dims[i] = 1 + fz_small(&in, 4);
    if (fz_u8(&in) & 1) fz_float3(&in, d.volume.spacing);
    if (fz_u8(&in) & 1) { d.volume.value_range[0] = fz_float(&in); d.volume.value_range[1] = fz_float(&in); }
    nvox = d.volume.dims[0] > 0 && d.volume.dims[0] <= 5 && d.volume.dims[1] > 0 && d.volume.dims[1] <= 5 &&
           d.volume.dims[2] > 0 && d.volume.dims[2] <= 5 ? d.volume.dims[0] * d.volume.dims[1] * d.volume.dims[2] : 0;
    memset(vox, 0, sizeof vox);
    if (d.volume.type == HD_VOXEL_F32) {
        float *f = (float *)(void *)vox;
        for (i = 0; i < nvox; ++i) f[i] = fz_float(&in);
    } else {
        for (i = 0; i < nvox * (d.volume.type == HD_VOXEL_U16 ? 2 : 1); ++i) vox[i] = fz_u8(&in);
    }
    d.volume.data = vox;
    d.transfer_function.count = fz_small(&in, 5);
    if (d.transfer_function.count >= 2 && d.transfer_function.count <= 4) {
        for (i = 0; i < 4 * d.transfer_function.count; ++i) tf[i] = (fz_u8(&in) & 1) ? fz_float(&in) : (float)fz_u8(&in) / 255.0f;
        d.transfer_function.rgba = tf;
    } else {
        d.transfer_function.count = 0;
    }
    d.light_count = fz_small(&in, 4);
    if (d.light_count >= 1 && d.light_count <= 3) {
        for (i = 0; i < d.light_count; ++i) fz_light(&in, &lights[i]);
        d.lights = lights;
    } else {
        d.light_count = 0;
    }
    fz_camera(&in, &d.camera);
    fz_params(&in, &d.params);
    d.threads = 1;
    d.logger.func = fz_log;
    fz_errors = 0;
    fz_code = HD_SUCCESS;
    r = hd_create(&d, &ctx);
    if (r != HD_SUCCESS) { fz_rejected(r); return 0; }
    if (fz_errors != 0) abort();
    fz_run(ctx);
    /* the setters with the rest of the bytes: rejected with one error, or the context runs */
    for (i = 0; i < 3 && in.at < in.n; ++i) {
        hd_camera cam;
        hd_params p;
        fz_errors = 0;
        switch (fz_u8(&in) % 3) {
        case 0:
            fz_light(&in, &lights[0]);
            r = hd_set_lights(ctx, lights, 1);
            break;
        case 1:
            fz_camera(&in, &cam);
            r = hd_set_camera(ctx, &cam);
            break;
        default:
            fz_params(&in, &p);
            r = hd_set_params(ctx, &p);
            break;
        }
        if (r != HD_SUCCESS) fz_rejected(r);
        else if (fz_errors != 0) abort();
        fz_run(ctx);
    }
    if (hd_destroy(ctx) != HD_SUCCESS) abort();
    return 0;
}
