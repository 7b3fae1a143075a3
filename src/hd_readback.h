/* hd_readback.h - the image and illumination read back, the sRGB encoding and the statistics.
   Part of the core (src/hd_core.h). */
/* ---- read-back --------------------------------------------------------------------------------- */
/* The image read back (in the bracket, after hd__prepare): HD_ERROR_NO_FRAME, logged, while it
   holds no frame (after hd_create, a new camera size or a change that restarted the image, before
   the next hd_render or hd_iterate), rather than an empty, transparent image. */
static hd_result hd__read_image(hd__ctx *ctx, float *dst, const char *call)
{
    if (ctx->image_empty)
        return HD__ERR(&ctx->vw.log, HD_ERROR_NO_FRAME, "%s: the %dx%d image holds no frame yet (render one first)", call,
                       ctx->vw.camera.width, ctx->vw.camera.height);
    return hd__be_read_image(&ctx->vw, dst);
}

static hd_result hd__api_read_image_f32(hd__ctx *ctx, float *dst, size_t dst_floats)
{
    hd_result r;
    size_t need;
    if (!dst) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_read_image_f32: dst is NULL");
    need = (size_t)ctx->vw.camera.width * ctx->vw.camera.height * 4;
    if (dst_floats < need) return HD__ERR(&ctx->vw.log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_image_f32: %zu floats given, %zu needed", dst_floats, need);
    HD__BE_CALL(r, ctx, hd__read_image(ctx, dst, "hd_read_image_f32"));
    return r;
}
HDDEF hd_result hd_read_image_f32(hd_context h, float *dst, size_t dst_floats)
{
    HD__GUARDED(h, "hd_read_image_f32", hd__api_read_image_f32(ctx, dst, dst_floats));
}

/* hd__srgb8 of the floats in [2^-9, 1), the range where it calls powf, by table: the floats there
   in groups of 2^12 consecutive ones (their top 20 bits); entry k is the code every float of
   group k maps to, or 0x100 where the group's first and last floats map to different codes (a
   code boundary inside: those floats take hd__srgb8 itself). hd__srgb8 is non-decreasing, so a
   group whose ends agree maps to that code throughout, and the table gives its bytes exactly at
   a table lookup per value. NULL when there is no memory for it (hd__srgb8 then does it all).
   hd__srgb8 is src/hd_backend.h's, the one definition the GPU passes' thresholds follow too. */
#define HD__SRGB_LO 0x3B000000u /* 2^-9 */
#define HD__SRGB_HI 0x3F800000u /* 1.0f */
#define HD__SRGB_SHIFT 12
static const uint16_t *hd__srgb_table(hd__ctx *ctx)
{
    uint32_t k, n = (HD__SRGB_HI - HD__SRGB_LO) >> HD__SRGB_SHIFT;
    if (ctx->srgb || !(ctx->srgb = (uint16_t *)hd__alloc(&ctx->vw, n * sizeof(uint16_t)))) return ctx->srgb;
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

static hd_result hd__api_read_image_rgba8(hd__ctx *ctx, uint8_t *dst, size_t dst_bytes)
{
    hd_result r;
    size_t need, i, n;
    float *tmp;
    const uint16_t *t;
    if (!dst) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_read_image_rgba8: dst is NULL");
    n = (size_t)ctx->vw.camera.width * ctx->vw.camera.height;
    need = n * 4;
    if (dst_bytes < need) return HD__ERR(&ctx->vw.log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_image_rgba8: %zu bytes given, %zu needed", dst_bytes, need);
    tmp = (float *)hd__alloc(&ctx->vw, need * sizeof(float));
    if (!tmp) return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "hd_read_image_rgba8: no memory for the conversion");
    HD__BE_CALL(r, ctx, hd__read_image(ctx, tmp, "hd_read_image_rgba8"));
    if (r == HD_SUCCESS) {
        float e = ctx->vw.params.exposure;
        t = hd__srgb_table(ctx);
        for (i = 0; i < n; ++i) {
            float a = tmp[4 * i + 3];
            dst[4 * i] = hd__srgb8_by(t, tmp[4 * i] * e);
            dst[4 * i + 1] = hd__srgb8_by(t, tmp[4 * i + 1] * e);
            dst[4 * i + 2] = hd__srgb8_by(t, tmp[4 * i + 2] * e);
            dst[4 * i + 3] = hd__alpha8(a);
        }
    }
    hd__free(&ctx->vw, tmp);
    return r;
}
HDDEF hd_result hd_read_image_rgba8(hd_context h, uint8_t *dst, size_t dst_bytes)
{
    HD__GUARDED(h, "hd_read_image_rgba8", hd__api_read_image_rgba8(ctx, dst, dst_bytes));
}

/* The output description of a call with defaults filled in (NULL: all zero), checked against
   what needs no target: the format, the size (the camera's), x and y not negative. */
static hd_result hd__output_check(hd__ctx *ctx, const hd_output *in, hd_output *out, const char *fn)
{
    int w = ctx->vw.camera.width, h = ctx->vw.camera.height;
    if (in) *out = *in;
    else memset(out, 0, sizeof *out);
    if ((int)out->format < 0 || out->format >= HD_OUTPUT_FORMAT_COUNT)
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_ENUM, "%s: output format %d is not a hd_output_format", fn, (int)out->format);
    if (out->width == 0) out->width = w;
    if (out->height == 0) out->height = h;
    if (out->width != w || out->height != h)
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUTPUT_SIZE, "%s: output region %dx%d, the camera's image is %dx%d (written 1:1)", fn,
                       out->width, out->height, w, h);
    if (out->x < 0 || out->y < 0)
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "%s: output region at (%d, %d): negative", fn, out->x, out->y);
    return HD_SUCCESS;
}

static hd_result hd__api_read_image_ex(hd__ctx *ctx, const hd_output *output, void *dst, size_t dst_bytes, size_t row_pitch)
{
    hd_result r;
    hd_output o;
    size_t px, row, need, n, x, y;
    float *tmp;
    const uint16_t *t = NULL;
    unsigned char *d;
    if (!dst) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_read_image_ex: dst is NULL");
    if ((r = hd__output_check(ctx, output, &o, "hd_read_image_ex")) != HD_SUCCESS) return r;
    px = hd__output_pixel_bytes(o.format);
    row = ((size_t)o.x + (size_t)o.width) * px; /* a row of the target up to the region's end */
    if (row_pitch == 0) row_pitch = row;
    if (row_pitch < row)
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUTPUT_OUTSIDE_TARGET,
                       "hd_read_image_ex: region x %d..%d (%zu bytes a pixel) past the row pitch of %zu bytes", o.x, o.x + o.width, px,
                       row_pitch);
    if ((size_t)o.y + (size_t)o.height - 1 > ((size_t)-1 - row) / row_pitch)
        return HD__ERR(&ctx->vw.log, HD_ERROR_SIZE_OVERFLOW, "hd_read_image_ex: the region's last byte overflows a size_t");
    need = ((size_t)o.y + (size_t)o.height - 1) * row_pitch + row;
    if (dst_bytes < need)
        return HD__ERR(&ctx->vw.log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_image_ex: %zu bytes given, %zu needed for rows %d..%d", dst_bytes,
                       need, o.y, o.y + o.height);
    n = (size_t)o.width * o.height;
    tmp = (float *)hd__alloc(&ctx->vw, n * 4 * sizeof(float));
    if (!tmp) return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "hd_read_image_ex: no memory for the conversion");
    HD__BE_CALL(r, ctx, hd__read_image(ctx, tmp, "hd_read_image_ex"));
    if (r == HD_SUCCESS) {
        float e = ctx->vw.params.exposure;
        if (o.format == HD_OUTPUT_SRGB8) t = hd__srgb_table(ctx);
        for (y = 0; y < (size_t)o.height; ++y) {
            d = (unsigned char *)dst + ((size_t)o.y + y) * row_pitch + (size_t)o.x * px;
            for (x = 0; x < (size_t)o.width; ++x, d += px) {
                const float *p = tmp + (y * o.width + x) * 4;
                if (o.format == HD_OUTPUT_LINEAR_F32) {
                    float v[4];
                    v[0] = p[0] * e; v[1] = p[1] * e; v[2] = p[2] * e; v[3] = p[3];
                    memcpy(d, v, sizeof v);
                } else if (o.format == HD_OUTPUT_LINEAR_F16) {
                    uint16_t v[4];
                    v[0] = hdk_f2h(p[0] * e); v[1] = hdk_f2h(p[1] * e); v[2] = hdk_f2h(p[2] * e); v[3] = hdk_f2h(p[3]);
                    memcpy(d, v, sizeof v);
                } else {
                    d[0] = hd__srgb8_by(t, p[0] * e);
                    d[1] = hd__srgb8_by(t, p[1] * e);
                    d[2] = hd__srgb8_by(t, p[2] * e);
                    d[3] = hd__alpha8(p[3]);
                }
            }
        }
    }
    hd__free(&ctx->vw, tmp);
    return r;
}
HDDEF hd_result hd_read_image_ex(hd_context h, const hd_output *output, void *dst, size_t dst_bytes, size_t row_pitch)
{
    HD__GUARDED(h, "hd_read_image_ex", hd__api_read_image_ex(ctx, output, dst, dst_bytes, row_pitch));
}

/* The volume's depth (hd_read_depth) from the depth plane's q (hdk_depth_q: the window depth's
   distance from the far plane's value; 0 there and where no frame crossed): depth = 1 - q, or q
   reversed. */
static void hd__depth_from_plane(const hd__ctx *ctx, float *dst)
{
    size_t i, n = (size_t)ctx->vw.camera.width * ctx->vw.camera.height;
    if (ctx->vw.camera.depth_range != HD_DEPTH_REVERSED)
        for (i = 0; i < n; ++i) dst[i] = 1.0f - dst[i];
}

static hd_result hd__api_read_depth(hd__ctx *ctx, float *dst, size_t dst_floats)
{
    hd_result r;
    size_t need;
    if (!dst) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_read_depth: dst is NULL");
    if (hd__method_is_pt(ctx->vw.params.method))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "hd_read_depth: method %s has no projection frames to take a depth from",
                       hd_method_name(ctx->vw.params.method));
    if (!ctx->cf.matrix)
        return HD__ERR(&ctx->vw.log, HD_ERROR_DEPTH_NEEDS_PROJECTION,
                       "hd_read_depth: the camera is a look-at camera; the depth is written through the host's projection (camera.projection)");
    need = (size_t)ctx->vw.camera.width * ctx->vw.camera.height;
    if (dst_floats < need) return HD__ERR(&ctx->vw.log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_depth: %zu floats given, %zu needed", dst_floats, need);
    HD__BE_CALL(r, ctx, ctx->image_empty ? HD__ERR(&ctx->vw.log, HD_ERROR_NO_FRAME, "hd_read_depth: the %dx%d image holds no frame yet (render one first)",
                                                   ctx->vw.camera.width, ctx->vw.camera.height)
                                         : hd__be_read_depth(&ctx->vw, dst));
    if (r == HD_SUCCESS) hd__depth_from_plane(ctx, dst);
    return r;
}
HDDEF hd_result hd_read_depth(hd_context h, float *dst, size_t dst_floats)
{
    HD__GUARDED(h, "hd_read_depth", hd__api_read_depth(ctx, dst, dst_floats));
}

static hd_result hd__api_read_illumination(hd__ctx *ctx, hd_illumination which, float *dst, size_t dst_floats)
{
    hd_result r;
    size_t need;
    if ((int)which < 0 || which >= HD_ILLUMINATION_COUNT)
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_ENUM, "hd_read_illumination: which = %d is not a hd_illumination", (int)which);
    if (!dst) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_read_illumination: dst is NULL");
    if (hd__method_is_pt(ctx->vw.params.method))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "hd_read_illumination: method %s keeps no illumination volume",
                       hd_method_name(ctx->vw.params.method));
    need = hd__illum_floats(ctx);
    if (dst_floats < need) return HD__ERR(&ctx->vw.log, HD_ERROR_BUFFER_TOO_SMALL, "hd_read_illumination: %zu floats given, %zu needed", dst_floats, need);
    if (which == HD_ILLUMINATION_TOTAL) {
        /* E into dst, phi beside it, summed as the projection's hdk_sample_light sums them */
        float *phi = (float *)hd__alloc(&ctx->vw, need * sizeof(float));
        size_t i;
        if (!phi) return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "hd_read_illumination: no memory for phi beside E (%zu floats)", need);
        HD__BE_CALL(r, ctx, hd__be_read_illumination(&ctx->vw, HD_ILLUMINATION_DIRECT, NULL, 0, dst));
        if (r == HD_SUCCESS) {
            HD__BE_CALL(r, ctx, hd__be_read_illumination(&ctx->vw, HD_ILLUMINATION_SCATTERED, NULL, 0, phi));
            for (i = 0; r == HD_SUCCESS && i < need; ++i) dst[i] += phi[i];
        }
        hd__free(&ctx->vw, phi);
        return r;
    }
    HD__BE_CALL(r, ctx, hd__be_read_illumination(&ctx->vw, which, NULL, 0, dst));
    return r;
}
HDDEF hd_result hd_read_illumination(hd_context h, hd_illumination which, float *dst, size_t dst_floats)
{
    HD__GUARDED(h, "hd_read_illumination", hd__api_read_illumination(ctx, which, dst, dst_floats));
}

static hd_result hd__api_get_stats(hd__ctx *ctx, hd_stats *out)
{
    size_t gvox;
    int open;
    if (!out) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_get_stats: out_stats is NULL");
    memset(out, 0, sizeof *out);
    gvox = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2];
    open = ctx->part.open && !(ctx->dirty & HD__PART_ENDS); /* a change ends it (hd__prepare) */
    out->method = ctx->vw.params.method;
    out->iterations = (ctx->dirty & HD__DIRTY_DIRECT) ? 0 : ctx->iterations - ctx->part.dropped - (ctx->part.open ? 1u : 0u);
    if (hd__method_is_pt(ctx->vw.params.method) && (ctx->dirty & HD__DIRTY_IMAGE)) out->iterations = 0;
    out->frames = (ctx->dirty & HD__DIRTY_IMAGE) ? 0 : ctx->frames;
    out->render_scale = out->frames > 0 && ctx->frame_scale > 0 ? ctx->frame_scale : 1;
    out->refine_paths = ctx->refined;
    /* HD: sigma_t grid + E + phi (+ Jacobi's buffer), independent of the lights, and the direct
       light's list; CD: the same plus one light volume per light and the spare of its ping-pong,
       no list; PT: nothing per voxel */
#ifdef HD__BE_SPLIT_LAYOUT /* the colour layout: one padding slot per row when gx is odd */
    out->method_bytes = hd__split_slots(ctx->vw.gdims[0], ctx->vw.gdims[1], (size_t)ctx->vw.gdims[2] * (size_t)ctx->vw.sig_channels) * sizeof(float) +
                        hd__split_slots(ctx->vw.gdims[0], ctx->vw.gdims[1], (size_t)ctx->vw.gdims[2] * (size_t)ctx->vw.channels) *
                            hd__illum_elem_bytes(ctx) * (ctx->vw.params.solver == HD_SOLVER_JACOBI ? 3 : 2);
#else
    out->method_bytes = gvox * sizeof(float) * (size_t)ctx->vw.sig_channels +
                        hd__illum_floats(ctx) * hd__illum_elem_bytes(ctx) * (ctx->vw.params.solver == HD_SOLVER_JACOBI ? 3 : 2);
#endif
    if (ctx->vw.params.method == HD_METHOD_CD) out->method_bytes += gvox * sizeof(float) * ((size_t)ctx->light_count + 1);
    out->method_bytes += hd__be_solver_bytes(&ctx->vw); /* the solver's own state (multigrid levels) */
    out->method_bytes += hd__illum_floats(ctx) * sizeof(float); /* the projection's E + phi, float32 */
    /* HD: the direct light's list of grid voxels (src/hd_direct_mask.h), a uint32 each, which the
       GPU backends hold on the device; the CPU backend reads the core's mask instead (a bit per
       grid voxel) and the count of entries before each brick, whose size the grid fixes, so it is
       counted before they are made (a list's size is known once it is) */
    if (ctx->vw.params.method == HD_METHOD_HD && ctx->vw.dl_idx) {
        out->method_bytes += ctx->vw.dl_count * sizeof(uint32_t);
    } else if (ctx->vw.params.method == HD_METHOD_HD && (hd__be_features() & HD__BE_LIST_FROM_BITS)) {
        int nb[3];
        out->method_bytes += (gvox + 7) / 8 + (hd__direct_bricks(ctx->vw.gdims, nb) + 1) * sizeof(uint32_t);
    }
    if (hd__method_is_pt(ctx->vw.params.method)) out->method_bytes = 0;
    out->method_bytes += ctx->vw.env_floats * sizeof(float); /* the environment's tables, any method */
    /* the buffer held, or the one the next call makes for a new camera size */
    out->image_bytes = hd__image_floats(ctx->vw.camera.width, ctx->vw.camera.height,
                                        ((ctx->dirty & HD__DIRTY_IMAGE_ALLOC) ? hd__image_room_kept(ctx) : ctx->image_room) |
                                            (hd__image_blend_wanted(ctx) ? HD__IMAGE_BLEND : 0)) *
                       sizeof(float);
    /* the volume as stored (U8, U16, I16 or normalised floats; Vulkan pads each row to 4 bytes),
       the majorant grid as floats and the TF as RGBA floats */
    out->volume_bytes = ctx->vw.nvox * hd__vol_elem(ctx->vw.vtype) + (size_t)ctx->vw.tf_count * 16 +
                        (size_t)ctx->vw.mdims[0] * ctx->vw.mdims[1] * ctx->vw.mdims[2] * sizeof(float);
    memcpy(out->illumination_dims, ctx->vw.gdims, sizeof ctx->vw.gdims);
    out->illumination_channels = ctx->vw.channels;
    out->seconds_direct = ctx->seconds[0];
    out->seconds_diffusion = ctx->seconds[1];
    out->seconds_projection = ctx->seconds[2];
    if (!hd__method_is_pt(ctx->vw.params.method)) {
        int fresh = (ctx->dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_SIGMA | HD__DIRTY_ALLOC | HD__DIRTY_WARM_E |
                                   HD__DIRTY_WARM_PHI | HD__DIRTY_VOLUME)) != 0;
        out->light_error = fresh ? 1.0 : ctx->light_error;
        if (open) {
            size_t nd = hd__direct_units(ctx);
            int ns = hd__sweep_units(ctx);
            double d = nd ? (double)ctx->part.dl / (double)nd : 1.0, w = ns ? (double)ctx->part.sweeps / ns : 1.0;
            out->light_progress = 0.5 * ((d < 1.0 ? d : 1.0) + (w < 1.0 ? w : 1.0));
            if (out->light_progress >= 1.0) out->light_progress = 0.0;
        }
        out->light_converged = !fresh && hd__light_converged(ctx);
    }
    return HD_SUCCESS;
}
HDDEF hd_result hd_get_stats(hd_context h, hd_stats *out)
{
    HD__GUARDED(h, "hd_get_stats", hd__api_get_stats(ctx, out));
}
