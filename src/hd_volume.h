/* hd_volume.h - the volume, its majorant grid, the transfer function and the lights as the core
   holds them: the inputs hd__be_upload_inputs sends. Part of the core (src/hd_core.h). */
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
    float lo = v->value_range[0], hi = v->value_range[1], scale = 1.0f / (hi - lo);
    /* the width of a finite range may pass FLT_MAX ({-3e38, 3e38}), or its inverse (a
       denormal width): then in double */
    int wide = !hd__finite(hi - lo) || !hd__finite(scale);
    double dscale = 1.0 / ((double)hi - (double)lo);
    size_t i, ncell;
    int d, x, y, z;
    double extent[3], emax = 0.0; /* double: dims * spacing may pass FLT_MAX (hd__check_extent) */
    for (d = 0; d < 3; ++d) {
        ctx->vw.dims[d] = v->dims[d];
        extent[d] = (double)v->dims[d] * (double)v->spacing[d];
        if (extent[d] > emax) emax = extent[d];
        ctx->vw.mdims[d] = (v->dims[d] + HD__MAJORANT_CELL - 1) / HD__MAJORANT_CELL;
    }
    for (d = 0; d < 3; ++d) ctx->box[d] = (float)(extent[d] / emax);
    ctx->vw.nvox = (size_t)ctx->vw.dims[0] * ctx->vw.dims[1] * ctx->vw.dims[2];
    ctx->vw.vol = (float *)hd__alloc(&ctx->vw, ctx->vw.nvox * sizeof(float));
    ncell = (size_t)ctx->vw.mdims[0] * ctx->vw.mdims[1] * ctx->vw.mdims[2];
    ctx->cell_range = (float *)hd__alloc(&ctx->vw, ncell * 2 * sizeof(float));
    ctx->vw.majorant = (float *)hd__calloc(&ctx->vw, ncell, sizeof(float));
    if (!ctx->vw.vol || !ctx->cell_range || !ctx->vw.majorant)
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "cannot allocate the volume (%zu voxels)", ctx->vw.nvox);
    for (i = 0; i < ctx->vw.nvox; ++i) {
        float t = wide ? (float)(((double)hd__raw_value(v, i) - (double)lo) * dscale) : (hd__raw_value(v, i) - lo) * scale;
        ctx->vw.vol[i] = t != t ? 0.0f : (t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t));
    }
    for (i = 0; i < ncell; ++i) { ctx->cell_range[2 * i] = 1.0f; ctx->cell_range[2 * i + 1] = 0.0f; }
    /* each voxel widens the range of every cell whose halo-extended footprint holds it */
    for (z = 0; z < ctx->vw.dims[2]; ++z)
        for (y = 0; y < ctx->vw.dims[1]; ++y)
            for (x = 0; x < ctx->vw.dims[0]; ++x) {
                float val = ctx->vw.vol[((size_t)z * ctx->vw.dims[1] + y) * ctx->vw.dims[0] + x];
                int c0[3], c1[3], p[3], cx, cy, cz;
                p[0] = x; p[1] = y; p[2] = z;
                for (d = 0; d < 3; ++d) {
                    c0[d] = (p[d] - 1 + HD__MAJORANT_CELL) / HD__MAJORANT_CELL - 1; /* cell whose last halo voxel is p */
                    c1[d] = (p[d] + 1) / HD__MAJORANT_CELL;                         /* cell whose first halo voxel is p */
                    if (c0[d] < 0) c0[d] = 0;
                    if (c1[d] > ctx->vw.mdims[d] - 1) c1[d] = ctx->vw.mdims[d] - 1;
                }
                for (cz = c0[2]; cz <= c1[2]; ++cz)
                    for (cy = c0[1]; cy <= c1[1]; ++cy)
                        for (cx = c0[0]; cx <= c1[0]; ++cx) {
                            float *r = &ctx->cell_range[2 * (((size_t)cz * ctx->vw.mdims[1] + cy) * ctx->vw.mdims[0] + cx)];
                            if (val < r[0]) r[0] = val;
                            if (val > r[1]) r[1] = val;
                        }
            }
    return HD_SUCCESS;
}

/* TF alpha at coordinate t, exactly as the kernels interpolate it. */
static float hd__tf_alpha(const hd__ctx *ctx, float t)
{
    float f = (t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t)) * (float)(ctx->vw.tf_count - 1);
    int i = (int)f < ctx->vw.tf_count - 2 ? (int)f : ctx->vw.tf_count - 2;
    float w = f - (float)i;
    return ctx->vw.tf[4 * i + 3] + w * (ctx->vw.tf[4 * i + 7] - ctx->vw.tf[4 * i + 3]);
}

/* Max sigma_t over a value range: the TF is piecewise linear, so its maximum over [lo, hi] is at
   an end or at an entry inside. Padded so float rounding in the kernels never exceeds it. */
static float hd__range_majorant(const hd__ctx *ctx, float lo, float hi)
{
    float m, n1 = (float)(ctx->vw.tf_count - 1);
    int i, i0, i1;
    if (hi < lo) return 0.0f;
    m = hd__tf_alpha(ctx, lo);
    if (hd__tf_alpha(ctx, hi) > m) m = hd__tf_alpha(ctx, hi);
    i0 = (int)ceilf(lo * n1);
    i1 = (int)floorf(hi * n1);
    for (i = i0 < 0 ? 0 : i0; i <= i1 && i < ctx->vw.tf_count; ++i)
        if (ctx->vw.tf[4 * i + 3] > m) m = ctx->vw.tf[4 * i + 3];
    return m > 0.0f ? m * ctx->vw.params.extinction * (1.0f + 1e-5f) + 1e-30f : 0.0f;
}

/* Whether the texture-coordinate interval [a, b] along axis d meets the crop box, widened by
   eps voxels for the kernels' rounding of a sample's coordinates. */
static int hd__crop_meets(const hd__ctx *ctx, int d, double a, double b, double eps)
{
    double e = eps / (double)ctx->vw.dims[d];
    return b + e >= (double)ctx->vw.params.crop_min[d] && a - e <= (double)ctx->vw.params.crop_max[d];
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
    for (cz = 0, i = 0; cz < ctx->vw.mdims[2]; ++cz)
        for (cy = 0; cy < ctx->vw.mdims[1]; ++cy)
            for (cx = 0; cx < ctx->vw.mdims[0]; ++cx, ++i) {
                float m = hd__range_majorant(ctx, ctx->cell_range[2 * i], ctx->cell_range[2 * i + 1]);
                if (m > ctx->max_sigma) ctx->max_sigma = m;
                if (!hd__crop_meets(ctx, 0, (double)(cx * c) / ctx->vw.dims[0], (double)((cx + 1) * c) / ctx->vw.dims[0], HD__CROP_CELL_EPS) ||
                    !hd__crop_meets(ctx, 1, (double)(cy * c) / ctx->vw.dims[1], (double)((cy + 1) * c) / ctx->vw.dims[1], HD__CROP_CELL_EPS) ||
                    !hd__crop_meets(ctx, 2, (double)(cz * c) / ctx->vw.dims[2], (double)((cz + 1) * c) / ctx->vw.dims[2], HD__CROP_CELL_EPS))
                    m = 0.0f;
                ctx->vw.majorant[i] = m;
            }
}

/* ---- inputs --------------------------------------------------------------------------------- */
static hd_result hd__set_tf(hd__ctx *ctx, const hd_transfer_function *tf)
{
    static const float ramp[8] = {1.0f, 1.0f, 1.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    const float *src = tf->rgba ? tf->rgba : ramp;
    int count = tf->rgba ? tf->count : 2;
    float *copy = (float *)hd__alloc(&ctx->vw, (size_t)count * 4 * sizeof(float));
    if (!copy) return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "cannot copy a %d-entry transfer function", count);
    memcpy(copy, src, (size_t)count * 4 * sizeof(float));
    hd__free(&ctx->vw, ctx->vw.tf);
    ctx->vw.tf = copy;
    ctx->vw.tf_count = count;
    ctx->vw.tf_serial++;
    ctx->vw.desc.transfer_function.rgba = ctx->vw.tf;
    ctx->vw.desc.transfer_function.count = count;
    return HD_SUCCESS;
}

/* Lights of one colour and grey scattering need one illumination channel; lights of different
   colours or RGB scattering need three (and RGB scattering the TF colour beside sigma_t). */
static float hd__max3(const float v[3]) { return v[0] > v[1] ? (v[0] > v[2] ? v[0] : v[2]) : (v[1] > v[2] ? v[1] : v[2]); }
static void hd__set_channels(hd__ctx *ctx)
{
    int i, grey = ctx->lights_one_colour && !ctx->vw.params.rgb_scattering;
    /* one channel: E carries intensity * max colour (the quantity hd__check_lights limits) and the
       projection the colour over its maximum, so neither factor alone can overflow */
    float cmax = hd__max3(ctx->lights[0].color);
    ctx->vw.channels = grey ? 1 : 3;
    ctx->vw.sig_channels = ctx->vw.params.rgb_scattering ? 4 : 1;
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
    ctx->vw.desc.lights = ctx->lights;
    ctx->vw.desc.light_count = count;
}

/* A global majorant above HD__MAJORANT_SLACK times the largest sigma_t (at least 1 per world
   unit) only adds null collisions: each walk would cost majorant * distance of them. */
#define HD__MAJORANT_SLACK 16.0f
static float hd__majorant_cap(float max_sigma) { return HD__MAJORANT_SLACK * (max_sigma > 1.0f ? max_sigma : 1.0f); }
static hd_result hd__check_majorant(hd__ctx *ctx, const hd_params *p)
{
    float max_sigma = ctx->max_sigma * (p->extinction / ctx->vw.params.extinction);
    if (p->majorant > 0.0f && p->majorant < max_sigma / (1.0f + 1e-5f))
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER,
                       "params.majorant = %g is below the largest extinction %g: tracking would be biased",
                       (double)p->majorant, (double)max_sigma);
    if (p->majorant > hd__majorant_cap(max_sigma))
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER,
                       "params.majorant = %g is above %g x the largest extinction %g (at least 1): only null collisions",
                       (double)p->majorant, (double)HD__MAJORANT_SLACK, (double)max_sigma);
    return HD_SUCCESS;
}


/* The illumination grid: the volume's dims over the downsampling factor, rounded up. */
static void hd__set_grid(hd__ctx *ctx)
{
    int d, f = ctx->vw.params.illumination_downsample;
    for (d = 0; d < 3; ++d) ctx->vw.gdims[d] = (ctx->vw.dims[d] + f - 1) / f;
}
