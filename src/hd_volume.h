/* hd_volume.h - the volume, its majorant grid, the transfer function and the lights as the core
   holds them: the inputs hd__be_upload_inputs sends. Part of the core (src/hd_core.h). */
/* ---- volume preparation ------------------------------------------------------------------------ */
static float hd__raw_value(const hd_volume_desc *v, size_t i)
{
    switch (v->type) {
    case HD_VOXEL_U8: return (float)((const uint8_t *)v->data)[i];
    case HD_VOXEL_U16: return (float)((const uint16_t *)v->data)[i];
    case HD_VOXEL_I16: return (float)((const int16_t *)v->data)[i];
    default: return ((const float *)v->data)[i];
    }
}

/* The map from raw values to TF coordinates [0, 1] of value_range {lo, hi}: NaN maps to 0,
   values outside are clamped. The width of a finite range may pass FLT_MAX ({-3e38, 3e38}), or
   its inverse (a denormal width): then in double. */
typedef struct hd__norm {
    float lo, scale;
    int wide;
    double dscale;
} hd__norm;
static hd__norm hd__norm_of(const hd_volume_desc *v)
{
    hd__norm m;
    float lo = v->value_range[0], hi = v->value_range[1];
    m.lo = lo;
    m.scale = 1.0f / (hi - lo);
    m.wide = !hd__finite(hi - lo) || !hd__finite(m.scale);
    m.dscale = 1.0 / ((double)hi - (double)lo);
    return m;
}
static float hd__norm_value(const hd__norm *m, float raw)
{
    float t = m->wide ? (float)(((double)raw - (double)m->lo) * m->dscale) : (raw - m->lo) * m->scale;
    return t != t ? 0.0f : (t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t));
}

/* The normalised value of voxel i as the kernels compute it (hdk_voxel, hd_k_common.h). */
static float hd__vol_value(const hd__view *vw, size_t i)
{
    float raw;
    switch (vw->vtype) {
    case HD_VOL_U8: raw = (float)((const uint8_t *)vw->vol)[i]; break;
    case HD_VOL_U16: raw = (float)((const uint16_t *)vw->vol)[i]; break;
    case HD_VOL_I16: raw = (float)((const int16_t *)vw->vol)[i]; break;
    default: return ((const float *)vw->vol)[i];
    }
    raw = (raw - vw->vnorm[0]) * vw->vnorm[1];
    return raw < 0.0f ? 0.0f : (raw > 1.0f ? 1.0f : raw);
}

/* The value range a trilinear sample inside each majorant cell of the box can take: the min and
   max over the cell's voxels and a one-voxel halo (voxels c M - 1 .. c M + M per axis). */
static void hd__cell_ranges(hd__ctx *ctx, const hd__box *cells)
{
    const int *n = ctx->vw.dims, *md = ctx->vw.mdims, M = HD__MAJORANT_CELL;
    int cx, cy, cz, x, y, z;
    for (cz = cells->lo[2]; cz < cells->hi[2]; ++cz)
        for (cy = cells->lo[1]; cy < cells->hi[1]; ++cy)
            for (cx = cells->lo[0]; cx < cells->hi[0]; ++cx) {
                int x0 = cx * M - 1 < 0 ? 0 : cx * M - 1, x1 = cx * M + M < n[0] - 1 ? cx * M + M : n[0] - 1;
                int y0 = cy * M - 1 < 0 ? 0 : cy * M - 1, y1 = cy * M + M < n[1] - 1 ? cy * M + M : n[1] - 1;
                int z0 = cz * M - 1 < 0 ? 0 : cz * M - 1, z1 = cz * M + M < n[2] - 1 ? cz * M + M : n[2] - 1;
                float lo = 1.0f, hi = 0.0f;
                for (z = z0; z <= z1; ++z)
                    for (y = y0; y <= y1; ++y) {
                        size_t row = ((size_t)z * n[1] + y) * n[0];
                        for (x = x0; x <= x1; ++x) {
                            float t = hd__vol_value(&ctx->vw, row + (size_t)x);
                            if (t < lo) lo = t;
                            if (t > hi) hi = t;
                        }
                    }
                ctx->cell_range[2 * (((size_t)cz * md[1] + cy) * md[0] + cx)] = lo;
                ctx->cell_range[2 * (((size_t)cz * md[1] + cy) * md[0] + cx) + 1] = hi;
            }
}

/* The whole grid of majorant cells. */
static hd__box hd__all_cells(const hd__ctx *ctx)
{
    hd__box b;
    int d;
    for (d = 0; d < 3; ++d) {
        b.lo[d] = 0;
        b.hi[d] = ctx->vw.mdims[d];
    }
    return b;
}

/* How the volume is kept: U8, U16 and I16 voxels as they are, with the map to TF coordinates
   that hd__norm_value computes in float (an F32 volume's voxels are normalised here, once).
   A value range whose map needs double (hd__norm) keeps the normalised floats instead. */
static int hd__vol_store(const hd_volume_desc *v, const hd__norm *m)
{
    if (m->wide) return HD_VOL_F32;
    return v->type == HD_VOXEL_U8 ? HD_VOL_U8 : v->type == HD_VOXEL_U16 ? HD_VOL_U16 : v->type == HD_VOXEL_I16 ? HD_VOL_I16 : HD_VOL_F32;
}

/* Keeps the voxels (hd__vol_store) and records, per majorant cell, the value range a trilinear
   sample inside the cell can take (its voxels and a one-voxel halo). */
static hd_result hd__prepare_volume(hd__ctx *ctx, const hd_volume_desc *v)
{
    hd__norm m = hd__norm_of(v);
    hd__box all;
    size_t i, ncell;
    int d;
    double extent[3], emax = 0.0; /* double: dims * spacing may pass FLT_MAX (hd__check_extent) */
    for (d = 0; d < 3; ++d) {
        ctx->vw.dims[d] = v->dims[d];
        extent[d] = (double)v->dims[d] * (double)v->spacing[d];
        if (extent[d] > emax) emax = extent[d];
        ctx->vw.mdims[d] = (v->dims[d] + HD__MAJORANT_CELL - 1) / HD__MAJORANT_CELL;
    }
    for (d = 0; d < 3; ++d) ctx->box[d] = (float)(extent[d] / emax);
    ctx->vw.nvox = (size_t)ctx->vw.dims[0] * ctx->vw.dims[1] * ctx->vw.dims[2];
    ctx->vw.vtype = hd__vol_store(v, &m);
    ctx->vw.vnorm[0] = ctx->vw.vtype == HD_VOL_F32 ? 0.0f : m.lo;
    ctx->vw.vnorm[1] = ctx->vw.vtype == HD_VOL_F32 ? 1.0f : m.scale;
    if (ctx->vw.vtype == HD_VOL_F32 && v->type != HD_VOXEL_F32)
        HD__INFO(&ctx->vw.log, "volume.value_range {%g, %g} is too wide or too narrow for float: the volume is kept as normalised floats",
                 (double)v->value_range[0], (double)v->value_range[1]);
    ctx->vw.vol = hd__alloc(&ctx->vw, ctx->vw.nvox * hd__vol_elem(ctx->vw.vtype));
    ncell = (size_t)ctx->vw.mdims[0] * ctx->vw.mdims[1] * ctx->vw.mdims[2];
    ctx->cell_range = (float *)hd__alloc(&ctx->vw, ncell * 2 * sizeof(float));
    ctx->vw.majorant = (float *)hd__calloc(&ctx->vw, ncell, sizeof(float));
    if (!ctx->vw.vol || !ctx->cell_range || !ctx->vw.majorant)
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "cannot allocate the volume (%zu voxels)", ctx->vw.nvox);
    if (ctx->vw.vtype != HD_VOL_F32)
        memcpy(ctx->vw.vol, v->data, ctx->vw.nvox * hd__vol_elem(ctx->vw.vtype));
    else
        for (i = 0; i < ctx->vw.nvox; ++i) ((float *)ctx->vw.vol)[i] = hd__norm_value(&m, hd__raw_value(v, i));
    all = hd__all_cells(ctx);
    hd__cell_ranges(ctx, &all);
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

/* The majorant of cell (cx, cy, cz), index i, without the crop box. */
static float hd__cell_majorant(const hd__ctx *ctx, size_t i)
{
    return hd__range_majorant(ctx, ctx->cell_range[2 * i], ctx->cell_range[2 * i + 1]);
}

/* The majorant per cell of the box; 0 in a cell outside the crop box, which holds no medium, so
   tracking and the projection skip it. Returns the largest majorant of the box's cells, crop box
   or not. */
static float hd__build_majorants_box(hd__ctx *ctx, const hd__box *cells)
{
    int cx, cy, cz, c = HD__MAJORANT_CELL;
    float top = 0.0f;
    for (cz = cells->lo[2]; cz < cells->hi[2]; ++cz)
        for (cy = cells->lo[1]; cy < cells->hi[1]; ++cy)
            for (cx = cells->lo[0]; cx < cells->hi[0]; ++cx) {
                size_t i = ((size_t)cz * ctx->vw.mdims[1] + cy) * ctx->vw.mdims[0] + cx;
                float m = hd__cell_majorant(ctx, i);
                if (m > top) top = m;
                if (!hd__crop_meets(ctx, 0, (double)(cx * c) / ctx->vw.dims[0], (double)((cx + 1) * c) / ctx->vw.dims[0], HD__CROP_CELL_EPS) ||
                    !hd__crop_meets(ctx, 1, (double)(cy * c) / ctx->vw.dims[1], (double)((cy + 1) * c) / ctx->vw.dims[1], HD__CROP_CELL_EPS) ||
                    !hd__crop_meets(ctx, 2, (double)(cz * c) / ctx->vw.dims[2], (double)((cz + 1) * c) / ctx->vw.dims[2], HD__CROP_CELL_EPS))
                    m = 0.0f;
                ctx->vw.majorant[i] = m;
            }
    return top;
}

/* Every cell's majorant. max_sigma stays that of the whole volume, so the limits on a global
   majorant do not move with the crop box. */
static void hd__build_majorants(hd__ctx *ctx)
{
    hd__box all = hd__all_cells(ctx);
    ctx->max_sigma = hd__build_majorants_box(ctx, &all);
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

/* What a new TF changes against the one held: nothing, only its colours (the same entries'
   alphas), or its alphas (sigma_t). */
enum { HD__TF_SAME, HD__TF_COLOUR, HD__TF_ALPHA };
static int hd__tf_change(const hd__ctx *ctx, const hd_transfer_function *tf)
{
    static const float ramp[8] = {1.0f, 1.0f, 1.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    const float *src = tf->rgba ? tf->rgba : ramp;
    int i, count = tf->rgba ? tf->count : 2, colour = 0;
    if (count != ctx->vw.tf_count) return HD__TF_ALPHA;
    for (i = 0; i < count; ++i) {
        if (memcmp(&src[4 * i + 3], &ctx->vw.tf[4 * i + 3], sizeof(float)) != 0) return HD__TF_ALPHA;
        if (memcmp(&src[4 * i], &ctx->vw.tf[4 * i], 3 * sizeof(float)) != 0) colour = 1;
    }
    return colour ? HD__TF_COLOUR : HD__TF_SAME;
}

/* Lights of one colour and grey scattering need one illumination channel; lights of different
   colours or RGB scattering need three (and RGB scattering the TF colour beside sigma_t). */
static float hd__max3(const float v[3]) { return v[0] > v[1] ? (v[0] > v[2] ? v[0] : v[2]) : (v[1] > v[2] ? v[1] : v[2]); }
static void hd__set_channels(hd__ctx *ctx)
{
    static const float white[3] = {1.0f, 1.0f, 1.0f};
    /* an environment alone is white; with lights, a grey one needs them grey too */
    const float *col = ctx->light_count > 0 ? ctx->lights[0].color : white;
    int i, grey = ctx->lights_one_colour && !ctx->vw.params.rgb_scattering &&
                  (!ctx->env_on || (ctx->env_grey && col[0] == col[1] && col[1] == col[2]));
    /* one channel: E carries intensity * max colour (the quantity hd__check_lights limits) and the
       projection the colour over its maximum, so neither factor alone can overflow */
    float cmax = hd__max3(col);
    ctx->vw.channels = grey ? 1 : 3;
    ctx->vw.sig_channels = ctx->vw.params.rgb_scattering ? 4 : 1;
    for (i = 0; i < 3; ++i) ctx->chan_color[i] = grey ? col[i] / cmax : 1.0f;
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

/* A global majorant (params.majorant) the medium has outgrown or that is above 16x its largest
   extinction is dropped for the majorant grid, with a line in the log; `what` names the change. */
static void hd__majorant_follow(hd__ctx *ctx, const char *what)
{
    if (ctx->vw.params.majorant > 0.0f &&
        (ctx->vw.params.majorant < ctx->max_sigma / (1.0f + 1e-5f) || ctx->vw.params.majorant > hd__majorant_cap(ctx->max_sigma))) {
        HD__INFO(&ctx->vw.log, "params.majorant %g is outside 1..16x the %s's largest extinction %g: using the majorant grid",
                 (double)ctx->vw.params.majorant, what, (double)ctx->max_sigma);
        ctx->vw.params.majorant = 0.0f;
    }
}

/* ---- hd_update_volume ------------------------------------------------------------------------- */
static size_t hd__voxel_bytes(hd_voxel_type t) { return t == HD_VOXEL_U8 ? 1 : t == HD_VOXEL_U16 || t == HD_VOXEL_I16 ? 2 : 4; }

static float hd__raw_at(hd_voxel_type t, const unsigned char *p)
{
    if (t == HD_VOXEL_U8) return (float)*p;
    if (t == HD_VOXEL_U16) {
        uint16_t v;
        memcpy(&v, p, sizeof v);
        return (float)v;
    }
    if (t == HD_VOXEL_I16) {
        int16_t v;
        memcpy(&v, p, sizeof v);
        return (float)v;
    }
    {
        float v;
        memcpy(&v, p, sizeof v);
        return v;
    }
}

/* Checks an update (every error before anything changes, one log line each), then writes its
   voxels into the core's copy and brings the majorant cells they reach up to date. The changed
   voxels' bounding box joins ctx->upd for hd__prepare (HD__DIRTY_VOLUME); *changed = 0 when every
   voxel equals the one held. */
static hd_result hd__update_voxels(hd__ctx *ctx, const hd_volume_update *u, int *changed)
{
    const hd_logger *log = &ctx->vw.log;
    const hd_volume_desc *v = &ctx->vw.desc.volume;
    const int *dims = ctx->vw.dims;
    static const char *types[] = {"INVALID", "U8", "U16", "F32", "I16"};
    hd__norm m = hd__norm_of(v);
    hd__box box, chg, cells;
    size_t es, rp, sp;
    int d, x, y, z, whole;
    float top;
    *changed = 0;
    if (!u) return HD__ERR(log, HD_ERROR_NULL_POINTER, "hd_update_volume: update is NULL");
    if (u->type != v->type || u->dims[0] != dims[0] || u->dims[1] != dims[1] || u->dims[2] != dims[2])
        return HD__ERR(log, HD_ERROR_VOLUME_MISMATCH, "hd_update_volume: the update is %s %dx%dx%d, the volume %s %dx%dx%d",
                       (int)u->type >= 0 && u->type < HD_VOXEL_COUNT ? types[u->type] : "(not a type)", u->dims[0], u->dims[1],
                       u->dims[2], types[v->type], dims[0], dims[1], dims[2]);
    whole = u->size[0] == 0 && u->size[1] == 0 && u->size[2] == 0;
    for (d = 0; d < 3; ++d) {
        /* checked before the box's end is summed: offset + size may pass INT_MAX */
        if (u->size[d] < 0 || (!whole && u->size[d] == 0) || u->offset[d] < 0 || u->offset[d] > dims[d] ||
            (whole ? u->offset[d] != 0 : u->size[d] > dims[d] - u->offset[d]))
            return HD__ERR(log, HD_ERROR_BOX_OUTSIDE_VOLUME,
                           "hd_update_volume: the box at (%d, %d, %d) of size (%d, %d, %d) is not inside the %dx%dx%d volume", u->offset[0],
                           u->offset[1], u->offset[2], u->size[0], u->size[1], u->size[2], dims[0], dims[1], dims[2]);
        box.lo[d] = u->offset[d];
        box.hi[d] = whole ? dims[d] : u->offset[d] + u->size[d];
    }
    if (!u->data) return HD__ERR(log, HD_ERROR_NULL_POINTER, "hd_update_volume: data is NULL");
    es = hd__voxel_bytes(v->type);
    rp = u->row_pitch ? u->row_pitch : (size_t)(box.hi[0] - box.lo[0]) * es;
    sp = u->slice_pitch ? u->slice_pitch : rp * (size_t)(box.hi[1] - box.lo[1]);
    if (rp < (size_t)(box.hi[0] - box.lo[0]) * es || sp < rp * (size_t)(box.hi[1] - box.lo[1]))
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "hd_update_volume: row_pitch %zu or slice_pitch %zu is below the box's %zu-byte rows, %d per slice",
                       u->row_pitch, u->slice_pitch, (size_t)(box.hi[0] - box.lo[0]) * es, box.hi[1] - box.lo[1]);
    if (v->type == HD_VOXEL_F32)
        for (z = box.lo[2]; z < box.hi[2]; ++z)
            for (y = box.lo[1]; y < box.hi[1]; ++y) {
                const unsigned char *row = (const unsigned char *)u->data + (size_t)(z - box.lo[2]) * sp + (size_t)(y - box.lo[1]) * rp;
                for (x = 0; x < box.hi[0] - box.lo[0]; ++x) {
                    float f = hd__raw_at(HD_VOXEL_F32, row + (size_t)x * 4);
                    if (!hd__finite(f))
                        return HD__ERR(log, HD_ERROR_INVALID_VOXELS, "hd_update_volume: voxel (%d, %d, %d) is %g", box.lo[0] + x, y, z, (double)f);
                }
            }
    /* the new voxels, and the bounding box of those that differ */
    for (d = 0; d < 3; ++d) {
        chg.lo[d] = dims[d];
        chg.hi[d] = 0;
    }
    for (z = box.lo[2]; z < box.hi[2]; ++z)
        for (y = box.lo[1]; y < box.hi[1]; ++y) {
            const unsigned char *row = (const unsigned char *)u->data + (size_t)(z - box.lo[2]) * sp + (size_t)(y - box.lo[1]) * rp;
            size_t at = ((size_t)z * dims[1] + y) * dims[0];
            for (x = box.lo[0]; x < box.hi[0]; ++x) {
                const unsigned char *src = row + (size_t)(x - box.lo[0]) * es;
                float t;
                if (ctx->vw.vtype == HD_VOL_F32) {
                    float *dst = (float *)ctx->vw.vol + at + x;
                    t = hd__norm_value(&m, hd__raw_at(v->type, src));
                    if (t == *dst) continue;
                    *dst = t;
                } else { /* the raw voxel is kept; a change its normalised value does not see is no change */
                    unsigned char *dst = (unsigned char *)ctx->vw.vol + (at + (size_t)x) * es;
                    float was = hd__vol_value(&ctx->vw, at + (size_t)x);
                    if (memcmp(dst, src, es) == 0) continue;
                    memcpy(dst, src, es);
                    if (hd__vol_value(&ctx->vw, at + (size_t)x) == was) continue;
                }
                if (x < chg.lo[0]) chg.lo[0] = x;
                if (x >= chg.hi[0]) chg.hi[0] = x + 1;
                if (y < chg.lo[1]) chg.lo[1] = y;
                if (y >= chg.hi[1]) chg.hi[1] = y + 1;
                if (z < chg.lo[2]) chg.lo[2] = z;
                if (z >= chg.hi[2]) chg.hi[2] = z + 1;
            }
        }
    if (chg.hi[0] == 0) return HD_SUCCESS;
    *changed = 1;
    cells = hd__box_cells(&ctx->vw, &chg);
    hd__cell_ranges(ctx, &cells);
    top = hd__build_majorants_box(ctx, &cells);
    if (top >= ctx->max_sigma) {
        ctx->max_sigma = top;
    } else { /* the largest may have been in the box: over every cell again, without writing */
        size_t i, ncell = (size_t)ctx->vw.mdims[0] * ctx->vw.mdims[1] * ctx->vw.mdims[2];
        ctx->max_sigma = 0.0f;
        for (i = 0; i < ncell; ++i) {
            float mj = hd__cell_majorant(ctx, i);
            if (mj > ctx->max_sigma) ctx->max_sigma = mj;
        }
    }
    hd__majorant_follow(ctx, "new volume");
    if (!(ctx->dirty & HD__DIRTY_VOLUME)) ctx->upd = chg;
    for (d = 0; d < 3; ++d) {
        if (chg.lo[d] < ctx->upd.lo[d]) ctx->upd.lo[d] = chg.lo[d];
        if (chg.hi[d] > ctx->upd.hi[d]) ctx->upd.hi[d] = chg.hi[d];
    }
    return HD_SUCCESS;
}
