/* hd_context.h - the public API: handles, context life cycle, what a change invalidates, and
   the schedule of each method's stages on the selected backend (hd__be_* functions). */
#include <pthread.h>

/* ---- names ----------------------------------------------------------------------------------- */
HDDEF const char *hd_result_string(hd_result result)
{
    switch (result) {
#define HD__X(name, text) case name: return #name ": " text;
        HD__RESULT_LIST(HD__X)
#undef HD__X
    default: return "HD_ERROR_UNKNOWN: not a hd_result value";
    }
}

HDDEF const char *hd_method_name(hd_method method)
{
    switch (method) {
    case HD_METHOD_DEFAULT: return "default";
    case HD_METHOD_HD: return "HD";
    case HD_METHOD_CD: return "CD";
    case HD_METHOD_PT_SS: return "PT_SS";
    case HD_METHOD_PT_MS: return "PT_MS";
    default: return "unknown";
    }
}

HDDEF const char *hd_backend_name(void) { return hd__be_name(); }

HDDEF void hd_log_stderr(void *user_data, hd_log_level level, hd_result code, const char *message,
                         const char *file, int line)
{
    static const char *names[] = {"error", "warning", "info"};
    (void)user_data; (void)file; (void)line;
    fprintf(stderr, "hybriddiff %s: %s%s%s\n", names[level <= HD_LOG_INFO ? level : 0], message,
            code != HD_SUCCESS ? " -- " : "", code != HD_SUCCESS ? hd_result_string(code) : "");
}

/* ---- handles: a slot index and a generation, so a stale handle is caught, not dereferenced ---- */
typedef struct hd__slot {
    hd__ctx *ctx;
    uint32_t generation;
    hd_logger last_logger; /* stays after destroy, so use of a stale handle can still be logged */
} hd__slot;
static hd__slot hd__slots[HD_MAX_CONTEXTS];
static pthread_mutex_t hd__slots_mu = PTHREAD_MUTEX_INITIALIZER;

static hd__ctx *hd__lookup(hd_context h, hd_logger *log_out)
{
    uint32_t slot = (h.id & 0xffu), gen = h.id >> 8;
    hd__ctx *ctx = NULL;
    if (log_out) memset(log_out, 0, sizeof *log_out);
    if (slot == 0 || slot > HD_MAX_CONTEXTS) return NULL;
    pthread_mutex_lock(&hd__slots_mu);
    if (hd__slots[slot - 1].generation == gen) ctx = hd__slots[slot - 1].ctx;
    if (log_out) *log_out = hd__slots[slot - 1].last_logger;
    pthread_mutex_unlock(&hd__slots_mu);
    return ctx;
}

/* Resolves a handle or returns HD_ERROR_INVALID_HANDLE from the calling function. */
#define HD__GET_CTX(var, handle) \
    hd__ctx *var; \
    do { \
        hd_logger hd__stale_log; \
        var = hd__lookup((handle), &hd__stale_log); \
        if (!var) return HD__ERR(&hd__stale_log, HD_ERROR_INVALID_HANDLE, "context handle 0x%08x is invalid, stale or destroyed", (unsigned)(handle).id); \
    } while (0)

/* ---- volume preparation ------------------------------------------------------------------------ */
static float hd__raw_value(const hd_volume_desc *v, size_t i)
{
    switch (v->type) {
    case HD_VOXEL_U8: return (float)((const uint8_t *)v->data)[i];
    case HD_VOXEL_U16: return (float)((const uint16_t *)v->data)[i];
    default: return ((const float *)v->data)[i];
    }
}

/* Normalises the voxels to TF coordinates and records, per majorant cell, the value range a
   trilinear sample inside the cell can take (its voxels and a one-voxel halo). */
static hd_result hd__prepare_volume(hd__ctx *ctx, const hd_volume_desc *v)
{
    float lo = v->value_range[0], hi = v->value_range[1], scale;
    size_t i, ncell;
    int d, x, y, z;
    double extent[3], emax = 0.0; /* double: dims * spacing may pass FLT_MAX (hd__check_extent) */
    for (d = 0; d < 3; ++d) {
        ctx->dims[d] = v->dims[d];
        extent[d] = (double)v->dims[d] * (double)v->spacing[d];
        if (extent[d] > emax) emax = extent[d];
        ctx->mdims[d] = (v->dims[d] + HD__MAJORANT_CELL - 1) / HD__MAJORANT_CELL;
    }
    for (d = 0; d < 3; ++d) ctx->box[d] = (float)(extent[d] / emax);
    ctx->nvox = (size_t)ctx->dims[0] * ctx->dims[1] * ctx->dims[2];
    ctx->vol = (float *)hd__alloc(ctx, ctx->nvox * sizeof(float));
    ncell = (size_t)ctx->mdims[0] * ctx->mdims[1] * ctx->mdims[2];
    ctx->cell_range = (float *)hd__alloc(ctx, ncell * 2 * sizeof(float));
    ctx->majorant = (float *)hd__calloc(ctx, ncell, sizeof(float));
    if (!ctx->vol || !ctx->cell_range || !ctx->majorant)
        return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cannot allocate the volume (%zu voxels)", ctx->nvox);
    scale = 1.0f / (hi - lo);
    for (i = 0; i < ctx->nvox; ++i) {
        float t = (hd__raw_value(v, i) - lo) * scale;
        ctx->vol[i] = t != t ? 0.0f : (t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t));
    }
    for (i = 0; i < ncell; ++i) { ctx->cell_range[2 * i] = 1.0f; ctx->cell_range[2 * i + 1] = 0.0f; }
    /* each voxel widens the range of every cell whose halo-extended footprint holds it */
    for (z = 0; z < ctx->dims[2]; ++z)
        for (y = 0; y < ctx->dims[1]; ++y)
            for (x = 0; x < ctx->dims[0]; ++x) {
                float val = ctx->vol[((size_t)z * ctx->dims[1] + y) * ctx->dims[0] + x];
                int c0[3], c1[3], p[3], cx, cy, cz;
                p[0] = x; p[1] = y; p[2] = z;
                for (d = 0; d < 3; ++d) {
                    c0[d] = (p[d] - 1 + HD__MAJORANT_CELL) / HD__MAJORANT_CELL - 1; /* cell whose last halo voxel is p */
                    c1[d] = (p[d] + 1) / HD__MAJORANT_CELL;                         /* cell whose first halo voxel is p */
                    if (c0[d] < 0) c0[d] = 0;
                    if (c1[d] > ctx->mdims[d] - 1) c1[d] = ctx->mdims[d] - 1;
                }
                for (cz = c0[2]; cz <= c1[2]; ++cz)
                    for (cy = c0[1]; cy <= c1[1]; ++cy)
                        for (cx = c0[0]; cx <= c1[0]; ++cx) {
                            float *r = &ctx->cell_range[2 * (((size_t)cz * ctx->mdims[1] + cy) * ctx->mdims[0] + cx)];
                            if (val < r[0]) r[0] = val;
                            if (val > r[1]) r[1] = val;
                        }
            }
    return HD_SUCCESS;
}

/* TF alpha at coordinate t, exactly as the kernels interpolate it. */
static float hd__tf_alpha(const hd__ctx *ctx, float t)
{
    float f = (t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t)) * (float)(ctx->tf_count - 1);
    int i = (int)f < ctx->tf_count - 2 ? (int)f : ctx->tf_count - 2;
    float w = f - (float)i;
    return ctx->tf[4 * i + 3] + w * (ctx->tf[4 * i + 7] - ctx->tf[4 * i + 3]);
}

/* Max sigma_t over a value range: the TF is piecewise linear, so its maximum over [lo, hi] is at
   an end or at an entry inside. Padded so float rounding in the kernels never exceeds it. */
static float hd__range_majorant(const hd__ctx *ctx, float lo, float hi)
{
    float m, n1 = (float)(ctx->tf_count - 1);
    int i, i0, i1;
    if (hi < lo) return 0.0f;
    m = hd__tf_alpha(ctx, lo);
    if (hd__tf_alpha(ctx, hi) > m) m = hd__tf_alpha(ctx, hi);
    i0 = (int)ceilf(lo * n1);
    i1 = (int)floorf(hi * n1);
    for (i = i0 < 0 ? 0 : i0; i <= i1 && i < ctx->tf_count; ++i)
        if (ctx->tf[4 * i + 3] > m) m = ctx->tf[4 * i + 3];
    return m > 0.0f ? m * ctx->params.extinction * (1.0f + 1e-5f) + 1e-30f : 0.0f;
}

/* Whether the texture-coordinate interval [a, b] along axis d meets the crop box, widened by
   eps voxels for the kernels' rounding of a sample's coordinates. */
static int hd__crop_meets(const hd__ctx *ctx, int d, double a, double b, double eps)
{
    double e = eps / (double)ctx->dims[d];
    return b + e >= (double)ctx->params.crop_min[d] && a - e <= (double)ctx->params.crop_max[d];
}

#define HD__CROP_CELL_EPS 0.25 /* voxels: a sample the DDA places in a cell may lie this far out */

/* The majorant per cell; 0 in a cell outside the crop box, which holds no medium, so tracking
   and the projection skip it. max_sigma stays that of the whole volume, so the limits on a
   global majorant do not move with the crop box. */
static void hd__build_majorants(hd__ctx *ctx)
{
    int cx, cy, cz, c = HD__MAJORANT_CELL;
    size_t i;
    ctx->max_sigma = 0.0f;
    for (cz = 0, i = 0; cz < ctx->mdims[2]; ++cz)
        for (cy = 0; cy < ctx->mdims[1]; ++cy)
            for (cx = 0; cx < ctx->mdims[0]; ++cx, ++i) {
                float m = hd__range_majorant(ctx, ctx->cell_range[2 * i], ctx->cell_range[2 * i + 1]);
                if (m > ctx->max_sigma) ctx->max_sigma = m;
                if (!hd__crop_meets(ctx, 0, (double)(cx * c) / ctx->dims[0], (double)((cx + 1) * c) / ctx->dims[0], HD__CROP_CELL_EPS) ||
                    !hd__crop_meets(ctx, 1, (double)(cy * c) / ctx->dims[1], (double)((cy + 1) * c) / ctx->dims[1], HD__CROP_CELL_EPS) ||
                    !hd__crop_meets(ctx, 2, (double)(cz * c) / ctx->dims[2], (double)((cz + 1) * c) / ctx->dims[2], HD__CROP_CELL_EPS))
                    m = 0.0f;
                ctx->majorant[i] = m;
            }
}

/* ---- inputs --------------------------------------------------------------------------------- */
static hd_result hd__set_tf(hd__ctx *ctx, const hd_transfer_function *tf)
{
    static const float ramp[8] = {1.0f, 1.0f, 1.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    const float *src = tf->rgba ? tf->rgba : ramp;
    int count = tf->rgba ? tf->count : 2;
    float *copy = (float *)hd__alloc(ctx, (size_t)count * 4 * sizeof(float));
    if (!copy) return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cannot copy a %d-entry transfer function", count);
    memcpy(copy, src, (size_t)count * 4 * sizeof(float));
    hd__free(ctx, ctx->tf);
    ctx->tf = copy;
    ctx->tf_count = count;
    ctx->tf_serial++;
    ctx->desc.transfer_function.rgba = ctx->tf;
    ctx->desc.transfer_function.count = count;
    return HD_SUCCESS;
}

/* Lights of one colour and grey scattering need one illumination channel; lights of different
   colours or RGB scattering need three (and RGB scattering the TF colour beside sigma_t). */
static float hd__max3(const float v[3]) { return v[0] > v[1] ? (v[0] > v[2] ? v[0] : v[2]) : (v[1] > v[2] ? v[1] : v[2]); }
static void hd__set_channels(hd__ctx *ctx)
{
    int i, grey = ctx->lights_one_colour && !ctx->params.rgb_scattering;
    /* one channel: E carries intensity * max colour (the quantity hd__check_lights limits) and the
       projection the colour over its maximum, so neither factor alone can overflow */
    float cmax = hd__max3(ctx->lights[0].color);
    ctx->channels = grey ? 1 : 3;
    ctx->sig_channels = ctx->params.rgb_scattering ? 4 : 1;
    for (i = 0; i < 3; ++i) ctx->chan_color[i] = grey ? ctx->lights[0].color[i] / cmax : 1.0f;
}

static void hd__set_lights(hd__ctx *ctx, const hd_light *lights, int count)
{
    int i, same = 1;
    for (i = 0; i < count; ++i) {
        hd_light l = lights[i];
        if (l.color[0] == 0.0f && l.color[1] == 0.0f && l.color[2] == 0.0f) l.color[0] = l.color[1] = l.color[2] = 1.0f;
        if (l.intensity == 0.0f) l.intensity = 1.0f;
        ctx->lights[i] = l;
        if (i > 0 && memcmp(l.color, ctx->lights[0].color, sizeof l.color) != 0) same = 0;
    }
    ctx->light_count = count;
    ctx->lights_one_colour = same;
    hd__set_channels(ctx);
    ctx->desc.lights = ctx->lights;
    ctx->desc.light_count = count;
}

/* A global majorant above HD__MAJORANT_SLACK times the largest sigma_t (at least 1 per world
   unit) only adds null collisions: each walk would cost majorant * distance of them. */
#define HD__MAJORANT_SLACK 16.0f
static float hd__majorant_cap(float max_sigma) { return HD__MAJORANT_SLACK * (max_sigma > 1.0f ? max_sigma : 1.0f); }
static hd_result hd__check_majorant(hd__ctx *ctx, const hd_params *p)
{
    float max_sigma = ctx->max_sigma * (p->extinction / ctx->params.extinction);
    if (p->majorant > 0.0f && p->majorant < max_sigma / (1.0f + 1e-5f))
        return HD__ERR(&ctx->log, HD_ERROR_INVALID_PARAMETER,
                       "params.majorant = %g is below the largest extinction %g: tracking would be biased",
                       (double)p->majorant, (double)max_sigma);
    if (p->majorant > hd__majorant_cap(max_sigma))
        return HD__ERR(&ctx->log, HD_ERROR_INVALID_PARAMETER,
                       "params.majorant = %g is above %g x the largest extinction %g (at least 1): only null collisions",
                       (double)p->majorant, (double)HD__MAJORANT_SLACK, (double)max_sigma);
    return HD_SUCCESS;
}

/* The path tracers keep no illumination grid: the image is their whole state. */
static int hd__method_is_pt(hd_method m) { return m == HD_METHOD_PT_SS || m == HD_METHOD_PT_MS; }

/* The illumination grid: the volume's dims over the downsampling factor, rounded up. */
static void hd__set_grid(hd__ctx *ctx)
{
    int d, f = ctx->params.illumination_downsample;
    for (d = 0; d < 3; ++d) ctx->gdims[d] = (ctx->dims[d] + f - 1) / f;
}

/* ---- the kernels' parameter block ------------------------------------------------------------ */
static void hd__fill_kparams(hd__ctx *ctx)
{
    hd__kparams *k = &ctx->kp;
    const hd_camera *c = &ctx->camera;
    float w[3], u[3], v[3], th, aspect;
    int i;
    memset(k, 0, sizeof *k);
    k->dims.x = ctx->dims[0]; k->dims.y = ctx->dims[1]; k->dims.z = ctx->dims[2]; k->dims.w = ctx->tf_count;
    k->gdims.x = ctx->gdims[0]; k->gdims.y = ctx->gdims[1]; k->gdims.z = ctx->gdims[2]; k->gdims.w = ctx->channels;
    k->mdims.x = ctx->mdims[0]; k->mdims.y = ctx->mdims[1]; k->mdims.z = ctx->mdims[2]; k->mdims.w = HD__MAJORANT_CELL;
    k->counts.x = ctx->light_count;
    k->counts.y = ctx->params.tracking == HD_TRACKING_DELTA ? HD_TRACK_DELTA : HD_TRACK_RATIO;
    k->counts.z = (ctx->params.majorant > 0.0f ? HD_FLAG_GLOBAL_MAJORANT : 0) |
                  (ctx->params.disable_diffusion ? HD_FLAG_NO_DIFFUSION : 0) |
                  (ctx->params.rgb_scattering ? HD_FLAG_RGB_SCATTERING : 0) |
                  (ctx->params.diffusion_boundary == HD_BOUNDARY_SURFACE ? HD_FLAG_SURFACE_BOUNDARY : 0);
    /* PT_SS is the path kernel with one vertex and the isotropic phase (hd_k_path.h) */
    k->counts.w = ctx->params.method == HD_METHOD_PT_SS ? 1 : ctx->params.max_bounces;
    k->frame.x = (int32_t)ctx->iterations;
    k->frame.y = (int32_t)ctx->frames;
    k->frame.z = (int32_t)ctx->params.seed;
    k->image.x = c->width; k->image.y = c->height; k->image.z = (int32_t)ctx->params.method;
    k->box.x = ctx->box[0]; k->box.y = ctx->box[1]; k->box.z = ctx->box[2]; k->box.w = 0.0795774715f;
    k->medium.x = ctx->params.extinction; k->medium.y = ctx->params.albedo;
    k->medium.z = ctx->params.method == HD_METHOD_PT_SS ? 0.0f : ctx->params.anisotropy;
    k->medium.w = ctx->params.majorant;
    for (i = 0; i < 3; ++i) {
        float h = ctx->box[i] / (float)ctx->gdims[i];
        (&k->grid.x)[i] = 1.0f / (h * h);
        (&k->gridh.x)[i] = h;
    }
    k->grid.w = 1e-3f; /* sigma' floor: keeps D finite in empty space */
    {
        float vs = ctx->box[0] / (float)ctx->dims[0];
        if (ctx->box[1] / (float)ctx->dims[1] < vs) vs = ctx->box[1] / (float)ctx->dims[1];
        if (ctx->box[2] / (float)ctx->dims[2] < vs) vs = ctx->box[2] / (float)ctx->dims[2];
        k->march.x = ctx->params.step * vs;
    }
    {
        /* HD and CD: a windowed mean that follows the converging illumination; the path
           tracers' frames are independent unbiased estimates: a plain 1/n mean */
        uint64_t f = ctx->frames < 1 ? 1 : ctx->frames;
        uint64_t win = hd__method_is_pt(ctx->params.method) ? f : (uint64_t)ctx->params.frame_window;
        k->march.y = (float)(1.0 / (double)(f < win ? f : win));
    }
    k->march.z = 1e-4f; /* stop marching below this transmittance */
    /* camera basis, through unit vectors (hd__unit3: a tiny up must not underflow the cross
       product; hd__check_camera keeps it away from parallel) */
    for (i = 0; i < 3; ++i) v[i] = c->target[i] - c->eye[i];
    hd__unit3(v, w);
    hd__unit3(c->up, u);
    v[0] = w[1] * u[2] - w[2] * u[1];
    v[1] = w[2] * u[0] - w[0] * u[2];
    v[2] = w[0] * u[1] - w[1] * u[0];
    hd__unit3(v, u);
    v[0] = u[1] * w[2] - u[2] * w[1];
    v[1] = u[2] * w[0] - u[0] * w[2];
    v[2] = u[0] * w[1] - u[1] * w[0];
    th = tanf(0.5f * c->fov_y * 3.14159265f / 180.0f);
    aspect = (float)c->width / (float)c->height;
    k->cam_pos.x = c->eye[0]; k->cam_pos.y = c->eye[1]; k->cam_pos.z = c->eye[2];
    k->cam_u.x = u[0] * th * aspect; k->cam_u.y = u[1] * th * aspect; k->cam_u.z = u[2] * th * aspect;
    k->cam_v.x = v[0] * th; k->cam_v.y = v[1] * th; k->cam_v.z = v[2] * th;
    k->cam_w.x = w[0]; k->cam_w.y = w[1]; k->cam_w.z = w[2];
    k->background.x = ctx->params.background[0];
    k->background.y = ctx->params.background[1];
    k->background.z = ctx->params.background[2];
    k->chan_color.x = ctx->chan_color[0]; k->chan_color.y = ctx->chan_color[1]; k->chan_color.z = ctx->chan_color[2];
    /* the crop box is on when it cuts an axis; an axis it spans whole gets bounds no sample
       reaches, so samples at the volume's faces stay as without a crop box */
    for (i = 0; i < 3; ++i) {
        (&k->crop_lo.x)[i] = ctx->params.crop_min[i] > 0.0f ? ctx->params.crop_min[i] : -1.0f;
        (&k->crop_hi.x)[i] = ctx->params.crop_max[i] < 1.0f ? ctx->params.crop_max[i] : 2.0f;
        if (ctx->params.crop_min[i] > 0.0f || ctx->params.crop_max[i] < 1.0f) k->crop_lo.w = 1.0f;
    }
    for (i = 0; i < ctx->light_count; ++i) {
        const hd_light *l = &ctx->lights[i];
        hd_f4 *a = &k->light_a[i], *b = &k->light_b[i];
        if (l->type == HD_LIGHT_DIRECTIONAL) {
            float n[3];
            hd__unit3(l->direction, n); /* nonzero: hd__check_lights */
            a->x = n[0]; a->y = n[1]; a->z = n[2]; a->w = 0.0f;
        } else {
            a->x = l->position[0]; a->y = l->position[1]; a->z = l->position[2]; a->w = 1.0f;
        }
        if (ctx->channels == 1) {
            b->x = b->y = b->z = l->intensity * hd__max3(l->color); /* the colour is chan_color */
        } else {
            b->x = l->color[0] * l->intensity; b->y = l->color[1] * l->intensity; b->z = l->color[2] * l->intensity;
        }
        b->w = l->type == HD_LIGHT_POINT && l->inverse_square ? 1.0f : 0.0f;
    }
}

/* ---- life cycle ---------------------------------------------------------------------------- */
static void hd__conv_free(hd__ctx *ctx);

static void hd__direct_mask_free(hd__ctx *ctx);

static void hd__ctx_free(hd__ctx *ctx)
{
    hd__conv_free(ctx);
    hd__direct_mask_free(ctx);
    if (ctx->be) hd__be_destroy(ctx);
    hd__free(ctx, ctx->vol);
    hd__free(ctx, ctx->cell_range);
    hd__free(ctx, ctx->majorant);
    hd__free(ctx, ctx->tf);
    hd__free(ctx, ctx->srgb);
    hd__free(ctx, ctx);
}

HDDEF hd_result hd_create(const hd_desc *desc, hd_context *out_ctx)
{
    hd_desc d;
    const hd_logger *log;
    hd__ctx *ctx;
    hd_result r;
    hd_light default_light;
    uint32_t slot;
    if (!desc) return HD_ERROR_NULL_POINTER; /* no logger to tell */
    log = &desc->logger;
    if (!out_ctx) return HD__ERR(log, HD_ERROR_NULL_POINTER, "hd_create: out_ctx is NULL");
    out_ctx->id = 0;
    d = *desc;
    if ((d.allocator.alloc == NULL) != (d.allocator.free == NULL))
        return HD__ERR(log, HD_ERROR_NULL_POINTER, "allocator: give both alloc and free, or neither");
    /* validate everything first: nothing is allocated for a bad desc */
    if ((r = hd__check_volume(&d.volume, log)) != HD_SUCCESS) return r;
    if ((r = hd__check_tf(&d.transfer_function, log)) != HD_SUCCESS) return r;
    memset(&default_light, 0, sizeof default_light);
    default_light.direction[2] = -1.0f;
    if (!d.lights && d.light_count == 0) { d.lights = &default_light; d.light_count = 1; }
    if ((r = hd__check_lights(d.lights, d.light_count, log)) != HD_SUCCESS) return r;
    hd__camera_defaults(&d.camera);
    if ((r = hd__check_camera(&d.camera, log)) != HD_SUCCESS) return r;
    hd__params_defaults(&d.params);
    if ((r = hd__check_params(&d.params, log)) != HD_SUCCESS) return r;
    if (d.threads < 0) return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "threads = %d is negative", d.threads);
    if (d.volume.spacing[0] == 0.0f && d.volume.spacing[1] == 0.0f && d.volume.spacing[2] == 0.0f)
        d.volume.spacing[0] = d.volume.spacing[1] = d.volume.spacing[2] = 1.0f;
    if (d.volume.value_range[0] == 0.0f && d.volume.value_range[1] == 0.0f)
        d.volume.value_range[1] = d.volume.type == HD_VOXEL_U8 ? 255.0f : d.volume.type == HD_VOXEL_U16 ? 65535.0f : 1.0f;
    if (!d.allocator.alloc) { d.allocator.alloc = hd__malloc_default; d.allocator.free = hd__free_default; }

    ctx = (hd__ctx *)d.allocator.alloc(sizeof *ctx, d.allocator.user_data);
    if (!ctx) return HD__ERR(log, HD_ERROR_OUT_OF_MEMORY, "cannot allocate the context");
    memset(ctx, 0, sizeof *ctx);
    ctx->desc = d;
    ctx->alloc = d.allocator;
    ctx->log = d.logger;
    ctx->camera = d.camera;
    ctx->params = d.params;
    ctx->desc.volume.data = NULL; /* the caller's buffer is not kept */
    hd__set_lights(ctx, d.lights, d.light_count);
    if ((r = hd__set_tf(ctx, &d.transfer_function)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    if ((r = hd__prepare_volume(ctx, &d.volume)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    hd__build_majorants(ctx);
    if ((r = hd__check_majorant(ctx, &ctx->params)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    hd__set_grid(ctx);
    ctx->dirty = HD__DIRTY_ALL;
    if ((r = hd__be_create(ctx)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }

    pthread_mutex_lock(&hd__slots_mu);
    for (slot = 0; slot < HD_MAX_CONTEXTS && hd__slots[slot].ctx; ++slot) {}
    if (slot < HD_MAX_CONTEXTS) {
        hd__slots[slot].ctx = ctx;
        hd__slots[slot].generation = (hd__slots[slot].generation + 1) & 0xffffffu;
        if (hd__slots[slot].generation == 0) hd__slots[slot].generation = 1;
        hd__slots[slot].last_logger = ctx->log;
        out_ctx->id = (hd__slots[slot].generation << 8) | (slot + 1);
    }
    pthread_mutex_unlock(&hd__slots_mu);
    if (slot == HD_MAX_CONTEXTS) {
        hd__ctx_free(ctx);
        return HD__ERR(log, HD_ERROR_TOO_MANY_CONTEXTS, "%d contexts are alive already", HD_MAX_CONTEXTS);
    }
    HD__INFO(&ctx->log, "created: %s backend, volume %dx%dx%d, %d lights", hd__be_name(),
             ctx->dims[0], ctx->dims[1], ctx->dims[2], ctx->light_count);
    return HD_SUCCESS;
}

HDDEF hd_result hd_destroy(hd_context h)
{
    uint32_t slot = h.id & 0xffu;
    HD__GET_CTX(ctx, h);
    pthread_mutex_lock(&hd__slots_mu);
    hd__slots[slot - 1].ctx = NULL;
    pthread_mutex_unlock(&hd__slots_mu);
    hd__ctx_free(ctx);
    return HD_SUCCESS;
}

HDDEF hd_result hd_query_desc(hd_context h, hd_desc *out)
{
    HD__GET_CTX(ctx, h);
    if (!out) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_query_desc: out_desc is NULL");
    *out = ctx->desc;
    out->camera = ctx->camera;
    out->params = ctx->params;
    return HD_SUCCESS;
}

/* ---- setters ----------------------------------------------------------------------------------- */
HDDEF hd_result hd_set_transfer_function(hd_context h, const hd_transfer_function *tf)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    if (!tf) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_set_transfer_function: tf is NULL");
    if ((r = hd__check_tf(tf, &ctx->log)) != HD_SUCCESS) return r;
    if ((r = hd__set_tf(ctx, tf)) != HD_SUCCESS) return r;
    hd__build_majorants(ctx);
    if (ctx->params.majorant > 0.0f &&
        (ctx->params.majorant < ctx->max_sigma / (1.0f + 1e-5f) || ctx->params.majorant > hd__majorant_cap(ctx->max_sigma))) {
        HD__INFO(&ctx->log, "params.majorant %g is outside 1..16x the new TF's largest extinction %g: using the majorant grid",
                 (double)ctx->params.majorant, (double)ctx->max_sigma);
        ctx->params.majorant = 0.0f;
    }
    ctx->dirty |= HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}

HDDEF hd_result hd_set_lights(hd_context h, const hd_light *lights, int count)
{
    hd_result r;
    int channels_before;
    HD__GET_CTX(ctx, h);
    if ((r = hd__check_lights(lights, count, &ctx->log)) != HD_SUCCESS) return r;
    channels_before = ctx->channels;
    hd__set_lights(ctx, lights, count);
    ctx->dirty |= HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    if (ctx->channels != channels_before) ctx->dirty |= HD__DIRTY_ALLOC;
    return HD_SUCCESS;
}

HDDEF hd_result hd_set_camera(hd_context h, const hd_camera *camera)
{
    hd_camera c;
    hd_result r;
    HD__GET_CTX(ctx, h);
    if (!camera) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_set_camera: camera is NULL");
    c = *camera;
    hd__camera_defaults(&c);
    if ((r = hd__check_camera(&c, &ctx->log)) != HD_SUCCESS) return r;
    if (c.width != ctx->camera.width || c.height != ctx->camera.height) ctx->dirty |= HD__DIRTY_IMAGE_ALLOC;
    ctx->camera = c;
    ctx->dirty |= HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}

HDDEF hd_result hd_set_params(hd_context h, const hd_params *params)
{
    hd_params p;
    hd_result r;
    const hd_params *o;
    HD__GET_CTX(ctx, h);
    if (!params) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_set_params: params is NULL");
    p = *params;
    hd__params_defaults(&p);
    if ((r = hd__check_params(&p, &ctx->log)) != HD_SUCCESS) return r;
    if ((r = hd__check_majorant(ctx, &p)) != HD_SUCCESS) return r;
    o = &ctx->params;
    if (p.method != o->method) ctx->dirty |= HD__DIRTY_ALL;
    if (p.extinction != o->extinction || p.majorant != o->majorant ||
        memcmp(p.crop_min, o->crop_min, sizeof p.crop_min) != 0 || memcmp(p.crop_max, o->crop_max, sizeof p.crop_max) != 0)
        ctx->dirty |= HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    if (p.seed != o->seed) ctx->dirty |= HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    if (p.albedo != o->albedo || p.anisotropy != o->anisotropy || p.disable_diffusion != o->disable_diffusion ||
        p.diffusion_boundary != o->diffusion_boundary)
        ctx->dirty |= HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    if (p.step != o->step || p.frame_window != o->frame_window || p.render_scale != o->render_scale ||
        memcmp(p.background, o->background, sizeof p.background) != 0)
        ctx->dirty |= HD__DIRTY_IMAGE;
    if ((p.solver == HD_SOLVER_JACOBI) != (o->solver == HD_SOLVER_JACOBI)) ctx->dirty |= HD__DIRTY_JACOBI;
    if (p.illumination_downsample != o->illumination_downsample || p.rgb_scattering != o->rgb_scattering ||
        p.illumination_precision != o->illumination_precision)
        ctx->dirty |= HD__DIRTY_ALLOC | HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    ctx->params = p;
    hd__set_channels(ctx);
    if (ctx->dirty & HD__DIRTY_ALLOC) hd__set_grid(ctx);
    if (ctx->dirty & HD__DIRTY_SIGMA) hd__build_majorants(ctx);
    return HD_SUCCESS;
}

/* ---- the schedule ---------------------------------------------------------------------------- */
/* Bytes per stored element of E, phi and Jacobi's buffer: binary16 or float32. */
static size_t hd__illum_elem_bytes(const hd__ctx *ctx)
{
    return ctx->params.illumination_precision == HD_PRECISION_FLOAT16 ? 2 : sizeof(float);
}

static size_t hd__illum_floats(const hd__ctx *ctx)
{
    return (size_t)ctx->gdims[0] * ctx->gdims[1] * ctx->gdims[2] * (size_t)ctx->channels;
}

/* ---- where the direct light is read ------------------------------------------------------------
   E is read by the projection, trilinearly at samples whose sigma_t > 0, and by the diffusion as
   sigma_s E at voxels whose sigma_t > 0 (the surface boundary reads sigma_t only); a grid voxel
   no such read reaches keeps E = 0 with no effect on phi or the image. The mask is exact at the
   level of the volume's dual cells (the 8 voxels a trilinear sample interpolates): a cell is
   empty when its 8 values lie in one run of TF entries whose alpha is 0, widened by
   HD__DL_VALUE_EPS for the kernels' rounding of the interpolation, or when they are 8 equal
   values (interpolated exactly) where alpha is 0, or when no sample it holds lies in the crop
   box (with HD__DL_COORD_EPS); a grid voxel is tracked when
   an interpolation that reads it (weight 0 included) can sample a non-empty cell. */
#define HD__DL_VALUE_EPS 1e-5f
#define HD__DL_COORD_EPS 0.01f /* voxels: kernels' rounding of a sample's coordinates */
#define HD__DL_BRICK 8 /* voxels per edge of the list's bricks (a multiple of the light's runs of 8) */

/* The run of zero-alpha TF entries (numbered from 1) that every value within HD__DL_VALUE_EPS of
   [t0, t1] lies in, 0 when some of them may have sigma_t > 0. A value's entries lie within those
   of the range (both ends are monotone in the value), so a range in one run puts each of its
   values there. */
static int32_t hd__dl_run_range(const int32_t *entry_run, int n, float t0, float t1)
{
    float lo = t0 - HD__DL_VALUE_EPS, hi = t1 + HD__DL_VALUE_EPS, n1 = (float)(n - 1);
    int i, i0, i1;
    lo = lo < 0.0f ? 0.0f : lo;
    hi = hi > 1.0f ? 1.0f : hi;
    i0 = (int)(lo * n1);
    i1 = (int)(hi * n1) + 1;
    if (i0 > n - 2) i0 = n - 2;
    if (i1 > n - 1) i1 = n - 1;
    for (i = i0; i <= i1; ++i)
        if (entry_run[i] == 0) return 0;
    return entry_run[i0]; /* consecutive zero entries share their run */
}

/* The same for one value. */
static int32_t hd__dl_run(const int32_t *entry_run, int n, float t)
{
    return hd__dl_run_range(entry_run, n, t, t);
}

/* Dual cells [lo, hi] along one axis (volume size n) that an interpolation reading grid voxel x
   (grid size g) can sample: the grid's lerp reads x for s = u g in [x - 0.5, x + 1.5), and its
   clamps make voxels 0 and 1 read from s = 0 on and voxels g - 2 and g - 1 up to s = g; the
   volume's lerp samples cell min(floor(u n - 0.5), n - 2), clamped to [0, n - 2]. */
static void hd__dl_axis(int x, int g, int n, int *lo, int *hi)
{
    int last = n - 2 > 0 ? n - 2 : 0;
    float eps = g == n ? 0.0f : HD__DL_COORD_EPS; /* same grid: the same float expression */
    float plo = ((float)x - 0.5f) / (float)g * (float)n - 0.5f - eps;
    float phi = ((float)x + 1.5f) / (float)g * (float)n - 0.5f + eps;
    int a = plo <= 0.0f ? 0 : (int)floorf(plo), b = phi <= 0.0f ? 0 : (int)ceilf(phi) - 1; /* s < x + 1.5 */
    if (x <= 1) a = 0;
    if (x >= g - 2) b = last;
    *lo = a > last ? last : a;
    *hi = b > last ? last : b;
}

static void hd__direct_mask_free(hd__ctx *ctx)
{
    hd__free(ctx, ctx->dl_idx);
    hd__free(ctx, ctx->dl_bits);
    ctx->dl_idx = NULL;
    ctx->dl_bits = NULL;
    ctx->dl_count = 0;
}

/* Builds dl_bits and dl_idx for the current TF, extinction, crop box and grid. */
static hd_result hd__direct_mask(hd__ctx *ctx)
{
    const int *n = ctx->dims, *g = ctx->gdims;
    int dn[3], d, x, y, z, j;
    size_t gvox = (size_t)g[0] * g[1] * g[2], ncell = (size_t)ctx->mdims[0] * ctx->mdims[1] * ctx->mdims[2], ndual, i, k;
    int32_t *entry_run = NULL;
    uint8_t *cell = NULL, *ax = NULL, *ay = NULL, *crop = NULL;
    int (*span)[2] = NULL;
    hd_result r = HD_SUCCESS;
    hd__direct_mask_free(ctx);
    for (d = 0; d < 3; ++d) dn[d] = n[d] > 1 ? n[d] - 1 : 1;
    ndual = (size_t)dn[0] * dn[1] * dn[2];
    ctx->dl_bits = (uint8_t *)hd__calloc(ctx, (gvox + 7) / 8, 1);
    entry_run = (int32_t *)hd__alloc(ctx, (size_t)ctx->tf_count * sizeof(int32_t));
    cell = (uint8_t *)hd__alloc(ctx, ndual);
    ax = (uint8_t *)hd__alloc(ctx, (size_t)g[0] * dn[1] * dn[2]);
    ay = (uint8_t *)hd__alloc(ctx, (size_t)g[0] * g[1] * dn[2]);
    span = (int (*)[2])hd__alloc(ctx, (size_t)(g[0] + g[1] + g[2]) * sizeof *span);
    crop = (uint8_t *)hd__alloc(ctx, (size_t)(dn[0] + dn[1] + dn[2]));
    if (!ctx->dl_bits || !entry_run || !cell || !ax || !ay || !span || !crop) {
        r = HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "no memory for the direct light's mask (%zu voxels)", gvox);
        goto done;
    }
    /* runs of zero-alpha entries; with no extinction nothing is medium */
    for (j = 0, k = 0; j < ctx->tf_count; ++j) {
        int zero = !(ctx->tf[4 * j + 3] > 0.0f) || !(ctx->params.extinction > 0.0f);
        if (zero && (j == 0 || entry_run[j - 1] == 0)) ++k;
        entry_run[j] = zero ? (int32_t)k : 0;
    }
    /* dual cells per axis that meet the crop box: cell j holds the samples at u n - 0.5 in
       [j, j + 1], the first and last also those the clamp folds onto them */
    for (d = 0, k = 0; d < 3; ++d)
        for (j = 0; j < dn[d]; ++j, ++k)
            crop[k] = (uint8_t)hd__crop_meets(ctx, d, j == 0 ? -1.0 : ((double)j + 0.5) / n[d],
                                              j == dn[d] - 1 ? 2.0 : ((double)j + 1.5) / n[d], HD__DL_COORD_EPS);
    /* a dual cell is empty when its 8 voxels share one zero run. Dual cells are taken per
       majorant cell (those whose lower corner it holds): the cell's value range, filter halo
       included, covers their 8 voxels, so when it lies in one zero run they are all empty and no
       voxel's run is needed; elsewhere the runs of the cell's block of voxels are computed once */
    memset(cell, 0, ndual);
    for (i = 0; i < ncell; ++i) {
        enum { M = HD__MAJORANT_CELL, B = HD__MAJORANT_CELL + 1 };
        int32_t blk[B * B * B];
        int c[3], lo[3], hi[3], bx, by, bz;
        const float *vol = ctx->vol;
        if (hd__dl_run_range(entry_run, ctx->tf_count, ctx->cell_range[2 * i], ctx->cell_range[2 * i + 1]) != 0) continue;
        c[0] = (int)(i % (size_t)ctx->mdims[0]);
        c[1] = (int)(i / (size_t)ctx->mdims[0] % (size_t)ctx->mdims[1]);
        c[2] = (int)(i / ((size_t)ctx->mdims[0] * ctx->mdims[1]));
        for (d = 0; d < 3; ++d) {
            lo[d] = c[d] * M;                                       /* first dual cell and voxel */
            hi[d] = lo[d] + M < dn[d] ? lo[d] + M : dn[d];          /* dual cells end (exclusive) */
        }
        if (lo[0] >= hi[0] || lo[1] >= hi[1] || lo[2] >= hi[2]) continue;
        /* runs of voxels lo .. min(hi, n - 1) */
        bx = (hi[0] < n[0] - 1 ? hi[0] : n[0] - 1) - lo[0] + 1;
        by = (hi[1] < n[1] - 1 ? hi[1] : n[1] - 1) - lo[1] + 1;
        bz = (hi[2] < n[2] - 1 ? hi[2] : n[2] - 1) - lo[2] + 1;
        for (z = 0; z < bz; ++z)
            for (y = 0; y < by; ++y)
                for (x = 0; x < bx; ++x)
                    blk[(z * B + y) * B + x] = hd__dl_run(entry_run, ctx->tf_count,
                                                          vol[((size_t)(lo[2] + z) * n[1] + lo[1] + y) * n[0] + lo[0] + x]);
        for (z = lo[2]; z < hi[2]; ++z)
            for (y = lo[1]; y < hi[1]; ++y)
                for (x = lo[0]; x < hi[0]; ++x) {
                    int x1 = x + 1 < n[0] ? x + 1 : x, y1 = y + 1 < n[1] ? y + 1 : y, z1 = z + 1 < n[2] ? z + 1 : z;
                    size_t r00 = ((size_t)z * n[1] + y) * n[0], r10 = ((size_t)z * n[1] + y1) * n[0];
                    size_t r01 = ((size_t)z1 * n[1] + y) * n[0], r11 = ((size_t)z1 * n[1] + y1) * n[0];
                    /* the block's rows of the 4 voxel rows, at x and x1 */
                    const int32_t *b0 = blk + ((z - lo[2]) * B + (y - lo[1])) * B;
                    const int32_t *b1 = blk + ((z - lo[2]) * B + (y1 - lo[1])) * B;
                    const int32_t *b2 = blk + ((z1 - lo[2]) * B + (y - lo[1])) * B;
                    const int32_t *b3 = blk + ((z1 - lo[2]) * B + (y1 - lo[1])) * B;
                    int xa = x - lo[0], xb = x1 - lo[0];
                    int32_t a = b0[xa];
                    float v = vol[r00 + x];
                    uint8_t full = !(a != 0 && b0[xb] == a && b1[xa] == a && b1[xb] == a && b2[xa] == a && b2[xb] == a &&
                                     b3[xa] == a && b3[xb] == a);
                    /* 8 equal values interpolate to that value exactly, whatever the weights */
                    if (full && vol[r00 + x1] == v && vol[r10 + x] == v && vol[r10 + x1] == v && vol[r01 + x] == v &&
                        vol[r01 + x1] == v && vol[r11 + x] == v && vol[r11 + x1] == v &&
                        !(hd__tf_alpha(ctx, v) * ctx->params.extinction > 0.0f))
                        full = 0;
                    if (!crop[x] || !crop[dn[0] + y] || !crop[dn[0] + dn[1] + z]) full = 0;
                    cell[((size_t)z * dn[1] + y) * dn[0] + x] = full;
                }
    }
    /* grid voxels whose reads reach a non-empty cell: the OR over their span, axis by axis */
    for (d = 0, k = 0; d < 3; ++d)
        for (x = 0; x < g[d]; ++x, ++k) hd__dl_axis(x, g[d], n[d], &span[k][0], &span[k][1]);
    for (z = 0; z < dn[2]; ++z)
        for (y = 0; y < dn[1]; ++y)
            for (x = 0; x < g[0]; ++x) {
                const uint8_t *c = cell + ((size_t)z * dn[1] + y) * dn[0];
                uint8_t v = 0;
                for (j = span[x][0]; j <= span[x][1]; ++j) v |= c[j];
                ax[((size_t)z * dn[1] + y) * g[0] + x] = v;
            }
    for (z = 0; z < dn[2]; ++z)
        for (y = 0; y < g[1]; ++y)
            for (x = 0; x < g[0]; ++x) {
                uint8_t v = 0;
                for (j = span[g[0] + y][0]; j <= span[g[0] + y][1]; ++j) v |= ax[((size_t)z * dn[1] + j) * g[0] + x];
                ay[((size_t)z * g[1] + y) * g[0] + x] = v;
            }
    ctx->dl_count = 0;
    for (z = 0, k = 0; z < g[2]; ++z)
        for (y = 0; y < g[1]; ++y)
            for (x = 0; x < g[0]; ++x, ++k) {
                uint8_t v = 0;
                for (j = span[g[0] + g[1] + z][0]; j <= span[g[0] + g[1] + z][1]; ++j)
                    v |= ay[((size_t)j * g[1] + y) * g[0] + x];
                if (v) {
                    ctx->dl_bits[k >> 3] |= (uint8_t)(1u << (k & 7));
                    ++ctx->dl_count;
                }
            }
    if (ctx->dl_all) ctx->dl_count = gvox;
    ctx->dl_idx = (uint32_t *)hd__alloc(ctx, (ctx->dl_count ? ctx->dl_count : 1) * sizeof(uint32_t));
    if (!ctx->dl_idx) {
        r = HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "no memory for the direct light's list (%zu voxels)", ctx->dl_count);
        goto done;
    }
    if (ctx->dl_all) {
        for (k = 0; k < gvox; ++k) ctx->dl_idx[k] = (uint32_t)k;
    } else {
        /* brick by brick (HD__DL_BRICK voxels an edge, x fastest inside): consecutive entries,
           one work item's, start side by side, so their rays read the same part of the volume */
        int bx, by, bz, b = HD__DL_BRICK;
        for (bz = 0, i = 0; bz < g[2]; bz += b)
            for (by = 0; by < g[1]; by += b)
                for (bx = 0; bx < g[0]; bx += b)
                    for (z = bz; z < bz + b && z < g[2]; ++z)
                        for (y = by; y < by + b && y < g[1]; ++y)
                            for (x = bx, k = ((size_t)z * g[1] + y) * g[0] + (size_t)bx; x < bx + b && x < g[0]; ++x, ++k)
                                if (ctx->dl_bits[k >> 3] >> (k & 7) & 1u) ctx->dl_idx[i++] = (uint32_t)k;
    }
done:
    hd__free(ctx, entry_run);
    hd__free(ctx, cell);
    hd__free(ctx, ax);
    hd__free(ctx, ay);
    hd__free(ctx, span);
    hd__free(ctx, crop);
    if (r != HD_SUCCESS) hd__direct_mask_free(ctx);
    ctx->dl_gen++;
    return r;
}

/* ---- light convergence ------------------------------------------------------------------------ */
static void hd__conv_reset(hd__ctx *ctx)
{
    ctx->conv_have_prev = 0;
    ctx->conv_below = 0;
    ctx->conv_dphi = 0.0;
    ctx->conv_q = 0.0;
    ctx->light_error = 1.0;
    ctx->converged_frames = 0;
}

static void hd__conv_free(hd__ctx *ctx)
{
    hd__free(ctx, ctx->conv_idx);
    hd__free(ctx, ctx->conv_prev);
    hd__free(ctx, ctx->conv_tmp);
    hd__free(ctx, ctx->conv_zz);
    hd__free(ctx, ctx->conv_off);
    ctx->conv_idx = NULL;
    ctx->conv_prev = ctx->conv_tmp = NULL;
    ctx->conv_zz = NULL;
    ctx->conv_off = NULL;
    ctx->conv_count = 0;
    ctx->conv_nz = 0;
    hd__conv_reset(ctx);
}

/* The illumination-grid voxels the estimate is taken over: those whose majorant cell holds
   medium (the projection reads E and phi only there; light in air is exact and would dilute
   the relative error), and with HD's direct-light mask only those it tracks. */
static int hd__conv_in_medium(const hd__ctx *ctx, int x, int y, int z)
{
    int f = ctx->params.illumination_downsample, c = HD__MAJORANT_CELL;
    int vx = hd_mini(x * f + f / 2, ctx->dims[0] - 1);
    int vy = hd_mini(y * f + f / 2, ctx->dims[1] - 1);
    int vz = hd_mini(z * f + f / 2, ctx->dims[2] - 1);
    size_t k = ((size_t)z * ctx->gdims[1] + (size_t)y) * ctx->gdims[0] + (size_t)x;
    if (ctx->dl_bits && !(ctx->dl_bits[k >> 3] >> (k & 7) & 1u)) return 0; /* E and phi never read */
    return ctx->majorant[((size_t)(vz / c) * ctx->mdims[1] + (size_t)(vy / c)) * ctx->mdims[0] + (size_t)(vx / c)] > 0.0f;
}

/* Medium voxels the estimate reads, about, at most: past this, every k-th z slice is measured
   (the relative change is an average, which a lattice of slices estimates as well), so the
   read-back and the fold stay small on large grids, where a GPU's transfer would dominate. */
#define HD__CONV_SAMPLE 131072

static hd_result hd__conv_alloc(hd__ctx *ctx)
{
    size_t n = 0, i = 0, total = 0, slice = (size_t)ctx->gdims[0] * ctx->gdims[1];
    int x, y, z, c, j, step, gz = ctx->gdims[2], nz;
    if (ctx->conv_tmp) return HD_SUCCESS;
    for (z = 0; z < gz; ++z)
        for (y = 0; y < ctx->gdims[1]; ++y)
            for (x = 0; x < ctx->gdims[0]; ++x) total += (size_t)hd__conv_in_medium(ctx, x, y, z);
    step = total > HD__CONV_SAMPLE ? (int)((total + HD__CONV_SAMPLE - 1) / HD__CONV_SAMPLE) : 1;
    if (step > gz) step = gz;
    nz = (gz - step / 2 + step - 1) / step;
    for (j = 0; j < nz; ++j)
        for (y = 0; y < ctx->gdims[1]; ++y)
            for (x = 0; x < ctx->gdims[0]; ++x) n += (size_t)hd__conv_in_medium(ctx, x, y, step / 2 + j * step);
    ctx->conv_idx = (uint32_t *)hd__alloc(ctx, (n ? n : 1) * sizeof(uint32_t));
    ctx->conv_prev = (float *)hd__calloc(ctx, (n ? n : 1) * 2 * (size_t)ctx->channels, sizeof(float));
    ctx->conv_tmp = (float *)hd__alloc(ctx, (size_t)nz * (size_t)ctx->channels * slice * sizeof(float));
    ctx->conv_zz = (int *)hd__alloc(ctx, (size_t)nz * (size_t)ctx->channels * sizeof(int));
    ctx->conv_off = (size_t *)hd__alloc(ctx, ((size_t)nz + 1) * sizeof(size_t));
    if (!ctx->conv_idx || !ctx->conv_prev || !ctx->conv_tmp || !ctx->conv_zz || !ctx->conv_off) {
        hd__conv_free(ctx);
        return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "no memory for the light's convergence estimate (%zu voxels)", n);
    }
    for (j = 0; j < nz; ++j) {
        z = step / 2 + j * step;
        ctx->conv_off[j] = i;
        for (c = 0; c < ctx->channels; ++c) ctx->conv_zz[c * nz + j] = c * gz + z;
        for (y = 0; y < ctx->gdims[1]; ++y)
            for (x = 0; x < ctx->gdims[0]; ++x)
                if (hd__conv_in_medium(ctx, x, y, z)) ctx->conv_idx[i++] = (uint32_t)((size_t)y * ctx->gdims[0] + (size_t)x);
    }
    ctx->conv_off[nz] = i;
    ctx->conv_nz = nz;
    ctx->conv_count = n;
    return HD_SUCCESS;
}

/* Reads the measured slices of one illumination volume, every channel in one read, into the
   measured voxels' copies: *dsq gets the sum of squared changes; for phi (read after E) *lsq gets
   the sum of squares of E + phi. */
static hd_result hd__conv_fold(hd__ctx *ctx, hd_illumination which, double *dsq, double *lsq)
{
    hd_result r;
    size_t i, slice = (size_t)ctx->gdims[0] * ctx->gdims[1], n = ctx->conv_count;
    size_t m = n * (size_t)ctx->channels;
    float *prev = ctx->conv_prev + (which == HD_ILLUMINATION_DIRECT ? 0 : m);
    double d = 0.0, l = 0.0;
    int c, j, nz = ctx->conv_nz;
    if ((r = hd__be_read_illumination(ctx, which, ctx->conv_zz, nz * ctx->channels, ctx->conv_tmp)) != HD_SUCCESS) return r;
    for (c = 0; c < ctx->channels; ++c)
        for (j = 0; j < nz; ++j)
            for (i = ctx->conv_off[j]; i < ctx->conv_off[j + 1]; ++i) {
                float v = ctx->conv_tmp[((size_t)c * nz + j) * slice + ctx->conv_idx[i]];
                float e = v - prev[(size_t)c * n + i];
                d += (double)e * e;
                prev[(size_t)c * n + i] = v;
                if (which == HD_ILLUMINATION_SCATTERED) {
                    double t = (double)ctx->conv_prev[(size_t)c * n + i] + v;
                    l += t * t;
                }
            }
    *dsq = d;
    *lsq = l;
    return HD_SUCCESS;
}

/* After a light iteration: the estimate of E + phi's relative RMS error (hd_stats.light_error).
   E is a Monte Carlo mean of n samples, whose change is (s_n - E_n-1) / n: its RMS times sqrt(n)
   estimates the standard error. phi follows a fixed-point iteration, whose remaining error is
   about its change times q / (1 - q) for a contraction q, taken from successive changes.
   CD's E is deterministic and counted with phi. */
static hd_result hd__light_measure(hd__ctx *ctx)
{
    hd_result r;
    double de = 0.0, dp = 0.0, ls = 0.0, err, q;
    if ((r = hd__conv_alloc(ctx)) != HD_SUCCESS) return r;
    if ((r = hd__conv_fold(ctx, HD_ILLUMINATION_DIRECT, &de, &ls)) != HD_SUCCESS) return r;
    if ((r = hd__conv_fold(ctx, HD_ILLUMINATION_SCATTERED, &dp, &ls)) != HD_SUCCESS) return r;
    if (!ctx->conv_have_prev) {
        ctx->conv_have_prev = 1;
        ctx->light_error = 1.0;
        return HD_SUCCESS;
    }
    if (ctx->params.method == HD_METHOD_HD) {
        err = sqrt((double)ctx->iterations * de);
    } else {
        err = 0.0;
        dp += de;
    }
    dp = sqrt(dp);
    q = ctx->conv_dphi > 0.0 ? dp / ctx->conv_dphi : 0.0;
    ctx->conv_q = q > 0.9 ? 0.9 : q;
    ctx->conv_dphi = dp;
    err += dp * ctx->conv_q / (1.0 - ctx->conv_q);
    /* no light reaches the medium: nothing left to refine */
    ctx->light_error = ls > 0.0 ? err / sqrt(ls) : 0.0;
    ctx->conv_below = ctx->light_error < (double)ctx->params.light_tolerance ? ctx->conv_below + 1 : 0;
    return HD_SUCCESS;
}

static int hd__light_converged(const hd__ctx *ctx) { return ctx->conv_below >= 2; }

/* Whether a new image buffer (a new camera size) keeps the reduced frames' region: the old one
   had it and the parameters may still ask for reduced frames. */
static int hd__image_room_kept(const hd__ctx *ctx)
{
    return ctx->image_room && ctx->params.render_scale != 1 && !hd__method_is_pt(ctx->params.method);
}

/* Brings the device state up to date with what the setters changed, in dependency order. */
static hd_result hd__prepare(hd__ctx *ctx)
{
    hd_result r;
    unsigned dirty = ctx->dirty;
    int pt = hd__method_is_pt(ctx->params.method);
    if (dirty & HD__DIRTY_ALLOC) {
        if ((r = hd__be_alloc_illumination(ctx, pt ? 0 : hd__illum_floats(ctx))) != HD_SUCCESS) return r;
        dirty |= HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE | HD__DIRTY_JACOBI;
    }
    if (dirty & HD__DIRTY_JACOBI) {
        if ((r = hd__be_alloc_jacobi(ctx, !pt && ctx->params.solver == HD_SOLVER_JACOBI)) != HD_SUCCESS) return r;
    }
    /* CD's light volumes follow the lights: reallocated (dark) when they change; freed for the
       other methods (a method change sets every dirty bit) */
    if (dirty & HD__DIRTY_DIRECT) {
        if ((r = hd__be_alloc_lights(ctx, ctx->params.method == HD_METHOD_CD ? ctx->light_count : 0)) != HD_SUCCESS)
            return r;
    }
    /* the path tracers' state is their image: whatever resets it restarts them */
    if (pt && (dirty & HD__DIRTY_IMAGE)) dirty |= HD__DIRTY_DIRECT;
    if (dirty & HD__DIRTY_IMAGE_ALLOC) {
        int room = hd__image_room_kept(ctx);
        if ((r = hd__be_alloc_image(ctx, ctx->camera.width, ctx->camera.height, room)) != HD_SUCCESS) return r;
        ctx->image_room = room;
        dirty |= HD__DIRTY_IMAGE;
    }
    ctx->dirty = dirty & ~(unsigned)(HD__DIRTY_ALLOC | HD__DIRTY_IMAGE_ALLOC | HD__DIRTY_JACOBI);
    if (dirty & HD__DIRTY_DIRECT) ctx->iterations = 0;
    if (dirty & HD__DIRTY_IMAGE) {
        ctx->frames = ctx->converged_frames = 0;
        ctx->frame_scale = 0;
    }
    /* the measured voxels follow the medium and the grid; the error estimate follows E and phi */
    if (dirty & (HD__DIRTY_SIGMA | HD__DIRTY_ALLOC)) hd__conv_free(ctx);
    if (dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI)) {
        hd__conv_reset(ctx);
        ctx->light_gen++;
    }
    hd__fill_kparams(ctx);
    if (dirty & HD__DIRTY_SIGMA) {
        if ((r = hd__be_upload_inputs(ctx)) != HD_SUCCESS) return r;
        if (!pt) {
            ++ctx->sig_gen;
            if ((r = hd__be_classify(ctx)) != HD_SUCCESS) return r;
        }
        hd__direct_mask_free(ctx);
        if (ctx->params.method == HD_METHOD_HD) {
            if ((r = hd__direct_mask(ctx)) != HD_SUCCESS) return r;
            if ((r = hd__be_direct_list(ctx)) != HD_SUCCESS) return r;
        }
    }
    if ((r = hd__be_clear(ctx, dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE))) != HD_SUCCESS) return r;
    ctx->dirty = 0;
    return HD_SUCCESS;
}

/* One sweep of the selected solver (multigrid: one conjugate-gradient step, preconditioned by a
   V-cycle; docs/DESIGN-MULTIGRID.md has its cost in red-black sweeps). */
static hd_result hd__diffuse_once(hd__ctx *ctx)
{
    if (ctx->params.solver == HD_SOLVER_MULTIGRID) return hd__mg_step(ctx);
    return hd__be_diffuse(ctx, ctx->params.solver == HD_SOLVER_JACOBI);
}

/* The diffusion sweeps of HD and CD (none with disable_diffusion). */
static hd_result hd__diffuse_sweeps(hd__ctx *ctx)
{
    hd_result r;
    int s;
    if (ctx->params.disable_diffusion) return HD_SUCCESS;
    /* all of them in one call: the CPU backend walks memory once for several red-black sweeps */
    if (ctx->params.solver != HD_SOLVER_MULTIGRID)
        return hd__be_diffuse_sweeps(ctx, ctx->params.solver == HD_SOLVER_JACOBI, ctx->params.diffusion_sweeps);
    for (s = 0; s < ctx->params.diffusion_sweeps; ++s)
        if ((r = hd__diffuse_once(ctx)) != HD_SUCCESS) return r;
    return HD_SUCCESS;
}

/* One light iteration, no projection. HD: a direct-light sample per voxel and the diffusion
   sweeps; CD: one convection step per light, their sum into E, and the sweeps (convection and
   sum count as the direct stage). Then the convergence estimate, counted with the diffusion. */
static hd_result hd__light_iteration(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now(), t1, t2;
    ctx->iterations++;
    hd__fill_kparams(ctx);
    if (ctx->params.method == HD_METHOD_CD) {
        int l;
        for (l = 0; l < ctx->light_count; ++l)
            if ((r = hd__be_convect(ctx, l)) != HD_SUCCESS) return r;
        if ((r = hd__be_sum_lights(ctx)) != HD_SUCCESS) return r;
    } else if ((r = hd__be_direct(ctx)) != HD_SUCCESS) return r;
    t1 = hd__now();
    if ((r = hd__diffuse_sweeps(ctx)) != HD_SUCCESS) return r;
    /* iterations recorded into a caller's command buffer have not run yet: nothing to measure */
    if (ctx->no_measure) hd__conv_reset(ctx);
    else r = hd__light_measure(ctx);
    t2 = hd__now();
    ctx->seconds[0] += t1 - t0;
    ctx->seconds[1] += t2 - t1;
    if (!hd__light_converged(ctx)) ctx->converged_frames = 0;
    return r;
}

/* The pixels a frame at render scale s marches at the current camera size. */
static double hd__scale_pixels(const hd__ctx *ctx, int s)
{
    return (double)((ctx->camera.width + s - 1) / s) * (double)((ctx->camera.height + s - 1) / s);
}

static int hd__scale_slot(int s) { return s >= 8 ? 3 : s >= 4 ? 2 : s >= 2 ? 1 : 0; }

/* Records that a frame at render scale s, marching `pixels` rays, took `seconds` (measured by
   hd__project_frame, or on the device for a recorded one). Each scale keeps its last pixel count
   and the mean of its new time with its previous estimate (one slow frame moves it halfway). */
static void hd__frame_cost_add(hd__ctx *ctx, int s, double pixels, double seconds)
{
    int k = hd__scale_slot(s);
    if (!(seconds > 0.0) || !(pixels > 0.0)) return;
    ctx->cost_seconds[k] = ctx->cost_pixels[k] == pixels ? 0.5 * (ctx->cost_seconds[k] + seconds) : seconds;
    ctx->cost_pixels[k] = pixels;
    ctx->cost_last = k;
    ctx->cost_at[k] = ++ctx->cost_gen;
}

/* Measurements after which a scale's estimate counts as stale: a scale the frames no longer visit
   (a drag that never rests long enough for full frames) keeps the time of an older view or load. */
#define HD__COST_FRESH 32u

/* A frame's predicted seconds at render scale s: a + b * pixels. The fixed part a (per-call
   overhead, and at s > 1 the full-size upsample pass, which do not shrink with s) and b are the
   least-squares line through the scales measured (a >= 0, b >= 0; a negative a fits through the
   origin instead), scaled to pass through the newest estimate, so the level follows the current
   view and the ratios between scales come from all of them. The line runs through the scales
   measured in the last HD__COST_FRESH measurements when there are two or more, else through all.
   With one scale measured a is 0: time proportional to pixels. */
static double hd__frame_cost_predict(const hd__ctx *ctx, int s)
{
    double n = 0.0, sp = 0.0, st = 0.0, spp = 0.0, spt = 0.0, a = 0.0, b = 1.0, var, at_last;
    int k, fresh = 0, only_fresh;
    for (k = 0; k < 4; ++k)
        if (ctx->cost_pixels[k] > 0.0 && ctx->cost_gen - ctx->cost_at[k] < HD__COST_FRESH) ++fresh;
    only_fresh = fresh >= 2;
    for (k = 0; k < 4; ++k) {
        double p = ctx->cost_pixels[k], t = ctx->cost_seconds[k];
        if (!(p > 0.0) || (only_fresh && ctx->cost_gen - ctx->cost_at[k] >= HD__COST_FRESH)) continue;
        n += 1.0; sp += p; st += t; spp += p * p; spt += p * t;
    }
    var = n * spp - sp * sp;
    if (n >= 2.0 && var > 0.0 && n * spt - sp * st > 0.0) {
        b = (n * spt - sp * st) / var;
        a = (st - b * sp) / n;
        if (a < 0.0) { a = 0.0; b = spt / spp; }
    }
    at_last = a + b * ctx->cost_pixels[ctx->cost_last];
    return (a + b * hd__scale_pixels(ctx, s)) * ctx->cost_seconds[ctx->cost_last] / at_last;
}

/* The scale HD_RENDER_SCALE_AUTO gives a new image's first frame: the smallest whose predicted
   time fits render_budget (the largest, 8, when none does); 4 without a budget or a measured
   frame. */
static int hd__first_scale(const hd__ctx *ctx)
{
    int s;
    if (!(ctx->params.render_budget > 0.0f) || ctx->cost_gen == 0) return 4;
    for (s = 1; s < HD__MAX_RENDER_SCALE; s *= 2)
        if (hd__frame_cost_predict(ctx, s) <= (double)ctx->params.render_budget) break;
    return s;
}

/* The render scale of the next projection frame (params.render_scale). HD_RENDER_SCALE_AUTO: a
   new image's first frame at hd__first_scale, then half the divisor per frame down to 1. */
static int hd__next_scale(const hd__ctx *ctx)
{
    if (hd__method_is_pt(ctx->params.method)) return 1;
    if (ctx->params.render_scale != HD_RENDER_SCALE_AUTO) return ctx->params.render_scale;
    if (ctx->frame_scale > 0)
        return ctx->frames > 0 && ctx->frame_scale > 1 ? ctx->frame_scale / 2 : ctx->frame_scale;
    return hd__first_scale(ctx);
}

/* Gives the image buffer the reduced frames' region if it lacks it (the first frame at a scale
   > 1), then clears it (the new buffer's contents are undefined; the frame about to be made
   restarts the running mean anyway). On failure the full-size image is kept as it was and
   frames at scale 1 go on working. */
static hd_result hd__image_room(hd__ctx *ctx)
{
    hd_result r;
    if (ctx->image_room) return HD_SUCCESS;
    if ((r = hd__be_alloc_image(ctx, ctx->camera.width, ctx->camera.height, 1)) != HD_SUCCESS) return r;
    ctx->image_room = 1;
    ctx->frames = ctx->converged_frames = 0;
    return hd__be_clear(ctx, HD__DIRTY_IMAGE);
}

/* Makes s the scale of the image's frames; frames at another scale are dropped (the running
   mean restarts). A scale > 1 first needs the reduced frames' region (hd__image_room). */
static hd_result hd__use_scale(hd__ctx *ctx, int s)
{
    hd_result r;
    if (s > 1 && (r = hd__image_room(ctx)) != HD_SUCCESS) return r;
    if (ctx->frames > 0 && s != ctx->frame_scale) ctx->frames = ctx->converged_frames = 0;
    ctx->frame_scale = s;
    return HD_SUCCESS;
}

/* One projection frame from the current E and phi into the image's running mean. At render
   scale s > 1 the march covers the reduced size into the image buffer's second region, then the
   upsample pass (the projection's entry with HD_FLAG_UPSAMPLE, hd_k_upsample.h) fills the full
   image from it; the parameter block is left describing the full image. */
static hd_result hd__project_frame(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now(), t1, t2;
    int s;
    if ((r = hd__use_scale(ctx, hd__next_scale(ctx))) != HD_SUCCESS) return r;
    t1 = hd__now(); /* the frame cost starts after a first reduced frame's allocation */
    s = ctx->frame_scale;
    ctx->frames++;
    hd__fill_kparams(ctx);
    if (s > 1) {
        int w = ctx->kp.image.x, h = ctx->kp.image.y;
        ctx->kp.image.x = (w + s - 1) / s;
        ctx->kp.image.y = (h + s - 1) / s;
        ctx->kp.image.w = w * h;
        r = hd__be_project(ctx);
        if (r == HD_SUCCESS) {
            ctx->kp.image.x = w;
            ctx->kp.image.y = h;
            ctx->kp.image.w = s;
            ctx->kp.counts.z |= HD_FLAG_UPSAMPLE;
            r = hd__be_project(ctx);
        }
        hd__fill_kparams(ctx);
    } else {
        r = hd__be_project(ctx);
    }
    t2 = hd__now();
    ctx->seconds[2] += t2 - t0;
    /* a recorded frame has not run: hd_vulkan_record times it on the device instead */
    if (r == HD_SUCCESS && !ctx->no_measure) hd__frame_cost_add(ctx, s, hd__scale_pixels(ctx, s), t2 - t1);
    return r;
}

/* One HD or CD iteration: a light iteration and one frame. */
static hd_result hd__iterate_light(hd__ctx *ctx)
{
    hd_result r;
    if ((r = hd__light_iteration(ctx)) != HD_SUCCESS) return r;
    return hd__project_frame(ctx);
}

/* One PT_SS / PT_MS iteration: one full path per pixel into the image's plain running mean.
   Its time counts as the direct stage (paths), none as diffusion or projection. */
static hd_result hd__iterate_pt(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now();
    ctx->iterations++;
    ctx->frames++;
    hd__fill_kparams(ctx);
    if ((r = hd__be_path(ctx)) != HD_SUCCESS) return r;
    ctx->seconds[0] += hd__now() - t0;
    return HD_SUCCESS;
}

/* One iteration of the current method (docs/METHOD.md: what an iteration is, per method). */
static hd_result hd__iterate_method(hd__ctx *ctx)
{
    switch (ctx->params.method) {
    case HD_METHOD_CD: return hd__iterate_light(ctx);
    case HD_METHOD_PT_SS:
    case HD_METHOD_PT_MS: return hd__iterate_pt(ctx);
    case HD_METHOD_HD: return hd__iterate_light(ctx);
    default:
        return HD__ERR(&ctx->log, HD_ERROR_UNSUPPORTED, "method %s is not available on the %s backend",
                       hd_method_name(ctx->params.method), hd__be_name());
    }
}

/* n iterations of step (one iteration of hd_iterate or hd_refine), stopping at the first error. */
static hd_result hd__iterate_n(hd__ctx *ctx, int n, hd_result (*step)(hd__ctx *))
{
    hd_result r = HD_SUCCESS;
    int i;
    for (i = 0; i < n && r == HD_SUCCESS; ++i) r = step(ctx);
    return r;
}

HDDEF hd_result hd_iterate(hd_context h, int n)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    if (n < 1) return HD__ERR(&ctx->log, HD_ERROR_INVALID_PARAMETER, "hd_iterate: n = %d, must be >= 1", n);
    if (ctx->iterations + (uint64_t)n > 0x7fffffffu)
        return HD__ERR(&ctx->log, HD_ERROR_INVALID_PARAMETER, "hd_iterate: more than 2^31 iterations; reset with a new seed");
    HD__BE_CALL(r, ctx, hd__iterate_n(ctx, n, hd__iterate_method));
    return r;
}

/* A light iteration of hd_refine or hd_render. When the light converges, the frames in the
   image saw light that was still changing: the image starts afresh. */
static hd_result hd__refine_once(hd__ctx *ctx)
{
    int before = hd__light_converged(ctx);
    hd_result r = hd__light_iteration(ctx);
    if (r == HD_SUCCESS && !before && hd__light_converged(ctx)) {
        ctx->frames = 0;
        ctx->converged_frames = 0;
        HD__INFO(&ctx->log, "light converged after %llu iterations (estimated error %.3g)",
                 (unsigned long long)ctx->iterations, ctx->light_error);
    }
    return r;
}

HDDEF hd_result hd_refine(hd_context h, int n)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    if (n < 1) return HD__ERR(&ctx->log, HD_ERROR_INVALID_PARAMETER, "hd_refine: n = %d, must be >= 1", n);
    if (hd__method_is_pt(ctx->params.method))
        return HD__ERR(&ctx->log, HD_ERROR_UNSUPPORTED, "hd_refine: method %s has no light volume to refine; use hd_iterate or hd_render",
                       hd_method_name(ctx->params.method));
    if (ctx->iterations + (uint64_t)n > 0x7fffffffu)
        return HD__ERR(&ctx->log, HD_ERROR_INVALID_PARAMETER, "hd_refine: more than 2^31 iterations; reset with a new seed");
    HD__BE_CALL(r, ctx, hd__iterate_n(ctx, n, hd__refine_once));
    return r;
}

/* hd_render's work after hd__prepare. */
static hd_result hd__render(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now(), last = 0.0, budget;
    budget = (double)ctx->params.render_budget;
    if (hd__method_is_pt(ctx->params.method)) {
        /* the image is the path tracers' state: each call adds at least one path per pixel */
        do {
            double ti = hd__now();
            if (ctx->iterations >= 0x7fffffffu) break;
            if ((r = hd__iterate_method(ctx)) != HD_SUCCESS) return r;
            last = hd__now() - ti;
        } while (hd__now() - t0 + last <= budget);
        return HD_SUCCESS;
    }
    /* refine while not converged: at least once, then while the budget has room for another */
    while (!hd__light_converged(ctx) && ctx->iterations < 0x7fffffffu) {
        double ti = hd__now();
        if ((r = hd__refine_once(ctx)) != HD_SUCCESS) return r;
        last = hd__now() - ti;
        if (hd__now() - t0 + last > budget) break;
    }
    if (hd__light_converged(ctx)) {
        /* the image is done once frame_window frames at its final scale are in */
        int s = hd__next_scale(ctx);
        if (s == ctx->frame_scale && ctx->converged_frames >= (uint64_t)ctx->params.frame_window) return HD_SUCCESS;
        if ((r = hd__use_scale(ctx, s)) != HD_SUCCESS) return r;
        ctx->converged_frames++;
    }
    return hd__project_frame(ctx);
}

HDDEF hd_result hd_render(hd_context h)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    HD__BE_CALL(r, ctx, hd__render(ctx));
    return r;
}

#if !defined(HYBRIDDIFF_BACKEND_GL)
HDDEF hd_result hd_gl_render_to_texture(hd_context h, unsigned int texture)
{
    HD__GET_CTX(ctx, h);
    (void)texture;
    return HD__ERR(&ctx->log, HD_ERROR_UNSUPPORTED, "hd_gl_render_to_texture: this is the %s backend", hd__be_name());
}
#endif

#if !defined(HYBRIDDIFF_BACKEND_VULKAN)
HDDEF hd_result hd_vulkan_record(hd_context h, void *command_buffer, int n)
{
    HD__GET_CTX(ctx, h);
    (void)command_buffer; (void)n;
    return HD__ERR(&ctx->log, HD_ERROR_UNSUPPORTED, "hd_vulkan_record: this is the %s backend", hd__be_name());
}
#endif

/* ---- read-back --------------------------------------------------------------------------------- */
HDDEF hd_result hd_read_image_f32(hd_context h, float *dst, size_t dst_floats)
{
    hd_result r;
    size_t need;
    HD__GET_CTX(ctx, h);
    if (!dst) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_read_image_f32: dst is NULL");
    need = (size_t)ctx->camera.width * ctx->camera.height * 4;
    if (dst_floats < need) return HD__ERR(&ctx->log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_image_f32: %zu floats given, %zu needed", dst_floats, need);
    HD__BE_CALL(r, ctx, hd__be_read_image(ctx, dst));
    return r;
}

static uint8_t hd__srgb8(float v)
{
    float s;
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)(s * 255.0f + 0.5f);
}

/* hd__srgb8 of the floats in [2^-9, 1), the range where it calls powf, by table: the floats there
   in groups of 2^12 consecutive ones (their top 20 bits); entry k is the code every float of
   group k maps to, or 0x100 where the group's first and last floats map to different codes (a
   code boundary inside: those floats take hd__srgb8 itself). hd__srgb8 is non-decreasing, so a
   group whose ends agree maps to that code throughout, and the table gives its bytes exactly at
   a table lookup per value. NULL when there is no memory for it (hd__srgb8 then does it all). */
#define HD__SRGB_LO 0x3B000000u /* 2^-9 */
#define HD__SRGB_HI 0x3F800000u /* 1.0f */
#define HD__SRGB_SHIFT 12
static const uint16_t *hd__srgb_table(hd__ctx *ctx)
{
    uint32_t k, n = (HD__SRGB_HI - HD__SRGB_LO) >> HD__SRGB_SHIFT;
    if (ctx->srgb || !(ctx->srgb = (uint16_t *)hd__alloc(ctx, n * sizeof(uint16_t)))) return ctx->srgb;
    for (k = 0; k < n; ++k) {
        uint32_t a = HD__SRGB_LO + (k << HD__SRGB_SHIFT), b = a + (1u << HD__SRGB_SHIFT) - 1u;
        float fa, fb;
        uint8_t ca, cb;
        memcpy(&fa, &a, sizeof fa);
        memcpy(&fb, &b, sizeof fb);
        ca = hd__srgb8(fa);
        cb = hd__srgb8(fb);
        ctx->srgb[k] = ca == cb ? ca : 0x100;
    }
    return ctx->srgb;
}

/* hd__srgb8(v), through table t (hd__srgb_table) where it holds v's code. */
static uint8_t hd__srgb8_by(const uint16_t *t, float v)
{
    uint32_t u;
    memcpy(&u, &v, sizeof u);
    if (t && u - HD__SRGB_LO < HD__SRGB_HI - HD__SRGB_LO) {
        uint16_t c = t[(u - HD__SRGB_LO) >> HD__SRGB_SHIFT];
        if (c < 0x100) return (uint8_t)c;
    }
    return hd__srgb8(v);
}

HDDEF hd_result hd_read_image_rgba8(hd_context h, uint8_t *dst, size_t dst_bytes)
{
    hd_result r;
    size_t need, i, n;
    float *tmp;
    const uint16_t *t;
    HD__GET_CTX(ctx, h);
    if (!dst) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_read_image_rgba8: dst is NULL");
    n = (size_t)ctx->camera.width * ctx->camera.height;
    need = n * 4;
    if (dst_bytes < need) return HD__ERR(&ctx->log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_image_rgba8: %zu bytes given, %zu needed", dst_bytes, need);
    tmp = (float *)hd__alloc(ctx, need * sizeof(float));
    if (!tmp) return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "hd_read_image_rgba8: no memory for the conversion");
    HD__BE_CALL(r, ctx, hd__be_read_image(ctx, tmp));
    if (r == HD_SUCCESS) {
        float e = ctx->params.exposure;
        t = hd__srgb_table(ctx);
        for (i = 0; i < n; ++i) {
            float a = tmp[4 * i + 3];
            dst[4 * i] = hd__srgb8_by(t, tmp[4 * i] * e);
            dst[4 * i + 1] = hd__srgb8_by(t, tmp[4 * i + 1] * e);
            dst[4 * i + 2] = hd__srgb8_by(t, tmp[4 * i + 2] * e);
            dst[4 * i + 3] = (uint8_t)(a <= 0.0f ? 0 : a >= 1.0f ? 255 : (int)(a * 255.0f + 0.5f));
        }
    }
    hd__free(ctx, tmp);
    return r;
}

HDDEF hd_result hd_read_illumination(hd_context h, hd_illumination which, float *dst, size_t dst_floats)
{
    hd_result r;
    size_t need;
    HD__GET_CTX(ctx, h);
    if ((int)which < 0 || which >= HD_ILLUMINATION_COUNT)
        return HD__ERR(&ctx->log, HD_ERROR_INVALID_ENUM, "hd_read_illumination: which = %d is not a hd_illumination", (int)which);
    if (!dst) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_read_illumination: dst is NULL");
    if (hd__method_is_pt(ctx->params.method))
        return HD__ERR(&ctx->log, HD_ERROR_UNSUPPORTED, "hd_read_illumination: method %s keeps no illumination volume",
                       hd_method_name(ctx->params.method));
    need = hd__illum_floats(ctx);
    if (dst_floats < need) return HD__ERR(&ctx->log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_illumination: %zu floats given, %zu needed", dst_floats, need);
    HD__BE_CALL(r, ctx, hd__be_read_illumination(ctx, which, NULL, 0, dst));
    return r;
}

HDDEF hd_result hd_get_stats(hd_context h, hd_stats *out)
{
    size_t gvox;
    HD__GET_CTX(ctx, h);
    if (!out) return HD__ERR(&ctx->log, HD_ERROR_NULL_POINTER, "hd_get_stats: out_stats is NULL");
    memset(out, 0, sizeof *out);
    gvox = (size_t)ctx->gdims[0] * ctx->gdims[1] * ctx->gdims[2];
    out->method = ctx->params.method;
    out->iterations = (ctx->dirty & HD__DIRTY_DIRECT) ? 0 : ctx->iterations;
    if (hd__method_is_pt(ctx->params.method) && (ctx->dirty & HD__DIRTY_IMAGE)) out->iterations = 0;
    out->frames = (ctx->dirty & HD__DIRTY_IMAGE) ? 0 : ctx->frames;
    out->render_scale = out->frames > 0 && ctx->frame_scale > 0 ? ctx->frame_scale : 1;
    /* HD: sigma_t grid + E + phi (+ Jacobi's buffer), independent of the lights; CD: the same
       plus one light volume per light and the spare of its ping-pong; PT: nothing per voxel */
#ifdef HD__BE_SPLIT_LAYOUT /* the colour layout: one padding slot per row when gx is odd */
    out->method_bytes = hd__split_slots(ctx->gdims[0], ctx->gdims[1], (size_t)ctx->gdims[2] * (size_t)ctx->sig_channels) * sizeof(float) +
                        hd__split_slots(ctx->gdims[0], ctx->gdims[1], (size_t)ctx->gdims[2] * (size_t)ctx->channels) *
                            hd__illum_elem_bytes(ctx) * (ctx->params.solver == HD_SOLVER_JACOBI ? 3 : 2);
#else
    out->method_bytes = gvox * sizeof(float) * (size_t)ctx->sig_channels +
                        hd__illum_floats(ctx) * hd__illum_elem_bytes(ctx) * (ctx->params.solver == HD_SOLVER_JACOBI ? 3 : 2);
#endif
    if (ctx->params.method == HD_METHOD_CD) out->method_bytes += gvox * sizeof(float) * ((size_t)ctx->light_count + 1);
    out->method_bytes += hd__be_solver_bytes(ctx); /* the solver's own state (multigrid levels) */
    out->method_bytes += hd__illum_floats(ctx) * sizeof(float); /* the projection's E + phi, float32 */
    if (hd__method_is_pt(ctx->params.method)) out->method_bytes = 0;
    /* the buffer held, or the one the next call makes for a new camera size */
    out->image_bytes = hd__image_floats(ctx->camera.width, ctx->camera.height,
                                        (ctx->dirty & HD__DIRTY_IMAGE_ALLOC) ? hd__image_room_kept(ctx) : ctx->image_room) *
                       sizeof(float);
    /* every backend holds the volume and the majorant grid as floats and the TF as RGBA floats */
    out->volume_bytes = ctx->nvox * sizeof(float) + (size_t)ctx->tf_count * 16 +
                        (size_t)ctx->mdims[0] * ctx->mdims[1] * ctx->mdims[2] * sizeof(float);
    memcpy(out->illumination_dims, ctx->gdims, sizeof ctx->gdims);
    out->illumination_channels = ctx->channels;
    out->seconds_direct = ctx->seconds[0];
    out->seconds_diffusion = ctx->seconds[1];
    out->seconds_projection = ctx->seconds[2];
    if (!hd__method_is_pt(ctx->params.method)) {
        int fresh = (ctx->dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_SIGMA | HD__DIRTY_ALLOC)) != 0;
        out->light_error = fresh ? 1.0 : ctx->light_error;
        out->light_converged = !fresh && hd__light_converged(ctx);
    }
    return HD_SUCCESS;
}
