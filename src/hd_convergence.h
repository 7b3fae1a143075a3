/* hd_convergence.h - the light's convergence estimate (hd_stats.light_error) from the change of
   E and phi between light iterations. Part of the core (src/hd_core.h). */
/* ---- light convergence ------------------------------------------------------------------------ */
static void hd__conv_reset(hd__ctx *ctx)
{
    ctx->conv.have_prev = 0;
    ctx->conv.below = 0;
    ctx->conv.dphi = 0.0;
    ctx->conv.q = 0.0;
    ctx->light_error = 1.0;
    ctx->converged_frames = 0;
}

static void hd__conv_free(hd__ctx *ctx)
{
    hd__free(&ctx->vw, ctx->conv.idx);
    hd__free(&ctx->vw, ctx->conv.prev);
    hd__free(&ctx->vw, ctx->conv.tmp);
    hd__free(&ctx->vw, ctx->conv.zz);
    hd__free(&ctx->vw, ctx->conv.off);
    ctx->conv.idx = NULL;
    ctx->conv.prev = ctx->conv.tmp = NULL;
    ctx->conv.zz = NULL;
    ctx->conv.off = NULL;
    ctx->conv.count = 0;
    ctx->conv.nz = 0;
    hd__conv_reset(ctx);
}

/* The illumination-grid voxels the estimate is taken over: those whose majorant cell holds
   medium (the projection reads E and phi only there; light in air is exact and would dilute
   the relative error), and with HD's direct-light mask only those it tracks. */
static int hd__conv_in_medium(const hd__ctx *ctx, int x, int y, int z)
{
    int f = ctx->vw.params.illumination_downsample, c = HD__MAJORANT_CELL;
    int vx = hdk_mini(x * f + f / 2, ctx->vw.dims[0] - 1);
    int vy = hdk_mini(y * f + f / 2, ctx->vw.dims[1] - 1);
    int vz = hdk_mini(z * f + f / 2, ctx->vw.dims[2] - 1);
    size_t k = ((size_t)z * ctx->vw.gdims[1] + (size_t)y) * ctx->vw.gdims[0] + (size_t)x;
    if (ctx->dl.bits && !(ctx->dl.bits[k >> 3] >> (k & 7) & 1u)) return 0; /* E and phi never read */
    return ctx->vw.majorant[((size_t)(vz / c) * ctx->vw.mdims[1] + (size_t)(vy / c)) * ctx->vw.mdims[0] + (size_t)(vx / c)] > 0.0f;
}

/* Medium voxels the estimate reads, about, at most: past this, every k-th z slice is measured
   (the relative change is an average, which a lattice of slices estimates as well), so the
   read-back and the fold stay small on large grids, where a GPU's transfer would dominate. */
#define HD__CONV_SAMPLE 131072

static hd_result hd__conv_alloc(hd__ctx *ctx)
{
    size_t n = 0, i = 0, total = 0, slice = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1];
    int x, y, z, c, j, step, gz = ctx->vw.gdims[2], nz;
    if (ctx->conv.tmp) return HD_SUCCESS;
    for (z = 0; z < gz; ++z)
        for (y = 0; y < ctx->vw.gdims[1]; ++y)
            for (x = 0; x < ctx->vw.gdims[0]; ++x) total += (size_t)hd__conv_in_medium(ctx, x, y, z);
    step = total > HD__CONV_SAMPLE ? (int)((total + HD__CONV_SAMPLE - 1) / HD__CONV_SAMPLE) : 1;
    if (step > gz) step = gz;
    nz = (gz - step / 2 + step - 1) / step;
    for (j = 0; j < nz; ++j)
        for (y = 0; y < ctx->vw.gdims[1]; ++y)
            for (x = 0; x < ctx->vw.gdims[0]; ++x) n += (size_t)hd__conv_in_medium(ctx, x, y, step / 2 + j * step);
    ctx->conv.idx = (uint32_t *)hd__alloc(&ctx->vw, (n ? n : 1) * sizeof(uint32_t));
    ctx->conv.prev = (float *)hd__calloc(&ctx->vw, (n ? n : 1) * 2 * (size_t)ctx->vw.channels, sizeof(float));
    ctx->conv.tmp = (float *)hd__alloc(&ctx->vw, (size_t)nz * (size_t)ctx->vw.channels * slice * sizeof(float));
    ctx->conv.zz = (int *)hd__alloc(&ctx->vw, (size_t)nz * (size_t)ctx->vw.channels * sizeof(int));
    ctx->conv.off = (size_t *)hd__alloc(&ctx->vw, ((size_t)nz + 1) * sizeof(size_t));
    if (!ctx->conv.idx || !ctx->conv.prev || !ctx->conv.tmp || !ctx->conv.zz || !ctx->conv.off) {
        hd__conv_free(ctx);
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "no memory for the light's convergence estimate (%zu voxels)", n);
    }
    for (j = 0; j < nz; ++j) {
        z = step / 2 + j * step;
        ctx->conv.off[j] = i;
        for (c = 0; c < ctx->vw.channels; ++c) ctx->conv.zz[c * nz + j] = c * gz + z;
        for (y = 0; y < ctx->vw.gdims[1]; ++y)
            for (x = 0; x < ctx->vw.gdims[0]; ++x)
                if (hd__conv_in_medium(ctx, x, y, z)) ctx->conv.idx[i++] = (uint32_t)((size_t)y * ctx->vw.gdims[0] + (size_t)x);
    }
    ctx->conv.off[nz] = i;
    ctx->conv.nz = nz;
    ctx->conv.count = n;
    return HD_SUCCESS;
}

/* Reads the measured slices of one illumination volume, every channel in one read, into the
   measured voxels' copies: *dsq gets the sum of squared changes; for phi (read after E) *lsq gets
   the sum of squares of E + phi. */
static hd_result hd__conv_fold(hd__ctx *ctx, hd_illumination which, double *dsq, double *lsq)
{
    hd_result r;
    size_t i, slice = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1], n = ctx->conv.count;
    size_t m = n * (size_t)ctx->vw.channels;
    float *prev = ctx->conv.prev + (which == HD_ILLUMINATION_DIRECT ? 0 : m);
    double d = 0.0, l = 0.0;
    int c, j, nz = ctx->conv.nz;
    if ((r = hd__be_read_illumination(&ctx->vw, which, ctx->conv.zz, nz * ctx->vw.channels, ctx->conv.tmp)) != HD_SUCCESS) return r;
    for (c = 0; c < ctx->vw.channels; ++c)
        for (j = 0; j < nz; ++j)
            for (i = ctx->conv.off[j]; i < ctx->conv.off[j + 1]; ++i) {
                float v = ctx->conv.tmp[((size_t)c * nz + j) * slice + ctx->conv.idx[i]];
                float e = v - prev[(size_t)c * n + i];
                d += (double)e * e;
                prev[(size_t)c * n + i] = v;
                if (which == HD_ILLUMINATION_SCATTERED) {
                    double t = (double)ctx->conv.prev[(size_t)c * n + i] + v;
                    l += t * t;
                }
            }
    *dsq = d;
    *lsq = l;
    return HD_SUCCESS;
}

/* After a light iteration: the estimate of E + phi's relative RMS error (hd_stats.light_error).
   E is a Monte Carlo mean of n samples (ctx->dl_n: capped by a warm start), whose change is
   (s_n - E_n-1) / n: its RMS times sqrt(n) estimates the standard error. phi follows a fixed-point iteration, whose remaining error is
   about its change times q / (1 - q) for a contraction q, taken from successive changes.
   CD's E is deterministic and counted with phi. */
static hd_result hd__light_measure(hd__ctx *ctx)
{
    hd_result r;
    double de = 0.0, dp = 0.0, ls = 0.0, err, q;
    if ((r = hd__conv_alloc(ctx)) != HD_SUCCESS) return r;
    if ((r = hd__conv_fold(ctx, HD_ILLUMINATION_DIRECT, &de, &ls)) != HD_SUCCESS) return r;
    if ((r = hd__conv_fold(ctx, HD_ILLUMINATION_SCATTERED, &dp, &ls)) != HD_SUCCESS) return r;
    if (!ctx->conv.have_prev) {
        ctx->conv.have_prev = 1;
        ctx->light_error = 1.0;
        return HD_SUCCESS;
    }
    if (ctx->vw.params.method == HD_METHOD_HD) {
        err = sqrt((double)(ctx->dl_n ? ctx->dl_n : 1) * de); /* the samples E's mean holds */
    } else {
        err = 0.0;
        dp += de;
    }
    dp = sqrt(dp);
    q = ctx->conv.dphi > 0.0 ? dp / ctx->conv.dphi : 0.0;
    ctx->conv.q = q > 0.9 ? 0.9 : q;
    ctx->conv.dphi = dp;
    err += dp * ctx->conv.q / (1.0 - ctx->conv.q);
    /* no light reaches the medium: nothing left to refine */
    ctx->light_error = ls > 0.0 ? err / sqrt(ls) : 0.0;
    ctx->conv.below = ctx->light_error < (double)ctx->vw.params.light_tolerance ? ctx->conv.below + 1 : 0;
    return HD_SUCCESS;
}

static int hd__light_converged(const hd__ctx *ctx) { return ctx->conv.below >= 2; }
