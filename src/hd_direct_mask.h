/* hd_direct_mask.h - where HD's direct light is tracked: the illumination-grid voxels whose E
   the projection or the diffusion reads. Part of the core (src/hd_core.h). */
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

/* 1 when no value within HD__DL_VALUE_EPS of [t0, t1] lies in a zero-alpha run: a value's
   entries (hd__dl_run_range) are at least two, from its first on, and the first entries of the
   range's values lie between those of t0 and t1, so no pair of zero-alpha entries starting there
   (pairs: src/hd_direct_mask.h, hd__direct_mask_box) leaves each value an entry with alpha > 0. */
static int hd__dl_live_range(const int32_t *pairs, int n, float t0, float t1)
{
    float lo = t0 - HD__DL_VALUE_EPS, hi = t1 - HD__DL_VALUE_EPS, n1 = (float)(n - 1);
    int i0, i1;
    lo = lo < 0.0f ? 0.0f : lo;
    hi = hi < 0.0f ? 0.0f : hi;
    lo = lo > 1.0f ? 1.0f : lo;
    hi = hi > 1.0f ? 1.0f : hi;
    i0 = (int)(lo * n1);
    i1 = (int)(hi * n1);
    if (i0 > n - 2) i0 = n - 2;
    if (i1 > n - 2) i1 = n - 2;
    return pairs[i1 + 1] - pairs[i0] == 0;
}

/* 1 when hd__tf_alpha(v) * extinction > 0 for every v in [t0, t1]: hd__tf_alpha interpolates
   entries i and i + 1, i = min(floor(v (n - 1)), n - 2), monotone in v, and no pair it can
   interpolate is weak (weak: hd__direct_mask_box). A pair is strong when its smaller alpha is at
   least HD__DL_ALPHA_RATIO of the larger (the interpolation's rounding, a few units in the last
   place of the larger, cannot bring it to 0) and times the extinction is far from underflow. */
#define HD__DL_ALPHA_RATIO (1.0f / 65536.0f)
static int hd__dl_solid_range(const int32_t *weak, int n, float t0, float t1)
{
    float n1 = (float)(n - 1), lo = t0 < 0.0f ? 0.0f : (t0 > 1.0f ? 1.0f : t0), hi = t1 < 0.0f ? 0.0f : (t1 > 1.0f ? 1.0f : t1);
    int i0 = (int)(lo * n1) < n - 2 ? (int)(lo * n1) : n - 2, i1 = (int)(hi * n1) < n - 2 ? (int)(hi * n1) : n - 2;
    return weak[i1 + 1] - weak[i0] == 0;
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
    hd__free(&ctx->vw, ctx->vw.dl_idx);
    hd__free(&ctx->vw, ctx->vw.dl_brick);
    hd__free(&ctx->vw, ctx->dl.bits);
    ctx->vw.dl_idx = ctx->vw.dl_brick = NULL;
    ctx->dl.bits = NULL;
    ctx->vw.dl_bits = NULL;
    ctx->vw.dl_count = 0;
}


/* dl_idx from dl_bits (every grid voxel with the test hook dl.all), brick by brick
   (HD__DL_BRICK voxels an edge, x fastest inside): consecutive entries, one work item's, start
   side by side, so their rays read the same part of the volume. */
static hd_result hd__direct_list_build(hd__ctx *ctx)
{
    const int *g = ctx->vw.gdims;
    size_t gvox = (size_t)g[0] * g[1] * g[2], i, k;
    int bx, by, bz, x, y, z, b = HD__DL_BRICK, nb[3];
    hd__free(&ctx->vw, ctx->vw.dl_idx);
    hd__free(&ctx->vw, ctx->vw.dl_brick);
    ctx->vw.dl_idx = ctx->vw.dl_brick = NULL;
    ctx->vw.dl_bits = ctx->dl.bits;
    ctx->vw.dl_gen++;
    if ((hd__be_features() & HD__BE_LIST_FROM_BITS) && !ctx->dl.all) {
        /* the entries before each brick; the backend reads the bits (the list's 4 bytes an entry
           would hold the same, a second time) */
        size_t n = hd__direct_bricks(g, nb);
        ctx->vw.dl_brick = (uint32_t *)hd__alloc(&ctx->vw, (n + 1) * sizeof(uint32_t));
        if (!ctx->vw.dl_brick)
            return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "no memory for the direct light's bricks (%zu)", n);
        for (bz = 0, i = 0, n = 0; bz < g[2]; bz += b)
            for (by = 0; by < g[1]; by += b)
                for (bx = 0; bx < g[0]; bx += b) {
                    ctx->vw.dl_brick[n++] = (uint32_t)i;
                    for (z = bz; z < bz + b && z < g[2]; ++z)
                        for (y = by; y < by + b && y < g[1]; ++y)
                            for (x = bx, k = ((size_t)z * g[1] + y) * g[0] + (size_t)bx; x < bx + b && x < g[0]; ++x, ++k)
                                i += ctx->dl.bits[k >> 3] >> (k & 7) & 1u;
                }
        ctx->vw.dl_brick[n] = (uint32_t)i;
        return HD_SUCCESS;
    }
    if (ctx->dl.all) ctx->vw.dl_count = gvox;
    ctx->vw.dl_idx = (uint32_t *)hd__alloc(&ctx->vw, (ctx->vw.dl_count ? ctx->vw.dl_count : 1) * sizeof(uint32_t));
    if (!ctx->vw.dl_idx)
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "no memory for the direct light's list (%zu voxels)", ctx->vw.dl_count);
    if (ctx->dl.all) {
        for (k = 0; k < gvox; ++k) ctx->vw.dl_idx[k] = (uint32_t)k;
        return HD_SUCCESS;
    }
    for (bz = 0, i = 0; bz < g[2]; bz += b)
        for (by = 0; by < g[1]; by += b)
            for (bx = 0; bx < g[0]; bx += b)
                for (z = bz; z < bz + b && z < g[2]; ++z)
                    for (y = by; y < by + b && y < g[1]; ++y)
                        for (x = bx, k = ((size_t)z * g[1] + y) * g[0] + (size_t)bx; x < bx + b && x < g[0]; ++x, ++k)
                            if (ctx->dl.bits[k >> 3] >> (k & 7) & 1u) ctx->vw.dl_idx[i++] = (uint32_t)k;
    return HD_SUCCESS;
}

/* Builds dl_bits and dl_idx for the current TF, extinction, crop box, grid and volume: with vox
   NULL (or no mask yet) everywhere; else only for the grid voxels whose reads reach a dual cell
   holding a voxel of the box vox (the voxels hd_update_volume changed), the others' bits kept.
   *changed (may be NULL) says whether any bit changed; the list is rebuilt when one did. */
static hd_result hd__direct_mask_box(hd__ctx *ctx, const hd__box *vox, int *changed)
{
    const int *n = ctx->vw.dims, *g = ctx->vw.gdims, M = HD__MAJORANT_CELL;
    int dn[3], G0[3], G1[3], Gn[3], D0[3], D1[3], Dn[3], d, x, y, z, j, full = !vox || !ctx->dl.bits, any = 0;
    size_t gvox = (size_t)g[0] * g[1] * g[2], k;
    int32_t *entry_run = NULL, *pairs = NULL, *weak = NULL, *ps = NULL;
    uint8_t *cell = NULL, *ax = NULL, *ay = NULL, *crop = NULL, *line = NULL;
    int (*span)[2] = NULL;
    hd_result r = HD_SUCCESS;
    if (changed) *changed = 0;
    for (d = 0; d < 3; ++d) dn[d] = n[d] > 1 ? n[d] - 1 : 1;
    if (full) {
        hd__direct_mask_free(ctx);
        ctx->dl.bits = (uint8_t *)hd__calloc(&ctx->vw, (gvox + 7) / 8, 1);
        ctx->vw.dl_count = 0;
    }
    span = (int (*)[2])hd__alloc(&ctx->vw, (size_t)(g[0] + g[1] + g[2]) * sizeof *span);
    entry_run = (int32_t *)hd__alloc(&ctx->vw, (size_t)ctx->vw.tf_count * sizeof(int32_t));
    pairs = (int32_t *)hd__alloc(&ctx->vw, (size_t)ctx->vw.tf_count * sizeof(int32_t));
    weak = (int32_t *)hd__alloc(&ctx->vw, (size_t)ctx->vw.tf_count * sizeof(int32_t));
    crop = (uint8_t *)hd__alloc(&ctx->vw, (size_t)(dn[0] + dn[1] + dn[2]));
    if (!ctx->dl.bits || !span || !entry_run || !pairs || !weak || !crop) goto oom;
    for (d = 0, k = 0; d < 3; ++d)
        for (x = 0; x < g[d]; ++x, ++k) hd__dl_axis(x, g[d], n[d], &span[k][0], &span[k][1]);
    /* the grid voxels to redo, G0..G1 per axis (the spans are monotone in x: a range), and the
       dual cells D0..D1 their reads reach */
    for (d = 0, k = 0; d < 3; k += (size_t)g[d], ++d) {
        int a = 0, b = dn[d] - 1;
        if (!full) {
            a = vox->lo[d] - 1 > 0 ? vox->lo[d] - 1 : 0;       /* dual cell j holds voxels j and j + 1 */
            b = vox->hi[d] - 1 < dn[d] - 1 ? vox->hi[d] - 1 : dn[d] - 1;
        }
        G0[d] = g[d];
        G1[d] = -1;
        for (x = 0; x < g[d]; ++x)
            if (span[k + x][0] <= b && span[k + x][1] >= a) {
                if (x < G0[d]) G0[d] = x;
                G1[d] = x;
            }
        if (G1[d] < G0[d]) goto done; /* no grid voxel reads there */
        Gn[d] = G1[d] - G0[d] + 1;
        D0[d] = span[k + G0[d]][0];
        D1[d] = span[k + G1[d]][1];
        Dn[d] = D1[d] - D0[d] + 1;
    }
    cell = (uint8_t *)hd__calloc(&ctx->vw, (size_t)Dn[0] * Dn[1] * Dn[2], 1);
    ax = (uint8_t *)hd__alloc(&ctx->vw, (size_t)Gn[0] * Dn[1] * Dn[2]);
    ay = (uint8_t *)hd__alloc(&ctx->vw, (size_t)Gn[0] * Gn[1] * Dn[2]);
    ps = (int32_t *)hd__alloc(&ctx->vw, ((size_t)Dn[0] + 1) * sizeof(int32_t));
    line = (uint8_t *)hd__alloc(&ctx->vw, (size_t)Gn[0]);
    if (!cell || !ax || !ay || !ps || !line) goto oom;
    /* runs of zero-alpha entries; with no extinction nothing is medium */
    for (j = 0, k = 0; j < ctx->vw.tf_count; ++j) {
        int zero = !(ctx->vw.tf[4 * j + 3] > 0.0f) || !(ctx->vw.params.extinction > 0.0f);
        if (zero && (j == 0 || entry_run[j - 1] == 0)) ++k;
        entry_run[j] = zero ? (int32_t)k : 0;
    }
    /* pairs[j]: how many of the entries i < j start a pair of zero-alpha entries (i, i + 1) */
    for (j = 0, pairs[0] = 0; j + 1 < ctx->vw.tf_count; ++j) pairs[j + 1] = pairs[j] + (entry_run[j] != 0 && entry_run[j + 1] != 0);
    /* weak[j]: how many of the entries i < j start a pair (i, i + 1) whose interpolation may not
       keep alpha * extinction > 0 (hd__dl_solid_range) */
    for (j = 0, weak[0] = 0; j + 1 < ctx->vw.tf_count; ++j) {
        float a0 = ctx->vw.tf[4 * j + 3], a1 = ctx->vw.tf[4 * j + 7], lo = a0 < a1 ? a0 : a1, hi = a0 < a1 ? a1 : a0;
        int strong = lo >= hi * HD__DL_ALPHA_RATIO && (double)lo * (double)ctx->vw.params.extinction >= 1e-30;
        weak[j + 1] = weak[j] + !strong;
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
       voxel's run is needed; when no value of the range can lie in a zero run (hd__dl_live_range)
       only 8 equal values of alpha 0 empty one, and when besides every value's alpha is > 0
       (hd__dl_solid_range) only the crop box does; elsewhere the runs of the cell's block of
       voxels are computed once */
    {
        int cx, cy, cz;
        for (cz = D0[2] / M; cz <= D1[2] / M; ++cz)
            for (cy = D0[1] / M; cy <= D1[1] / M; ++cy)
                for (cx = D0[0] / M; cx <= D1[0] / M; ++cx) {
                    enum { B = HD__MAJORANT_CELL + 1 };
                    int32_t blk[B * B * B];
                    int c[3], lo[3], hi[3], bx, by, bz, kind;
                    size_t i = ((size_t)cz * ctx->vw.mdims[1] + cy) * ctx->vw.mdims[0] + cx;
                    float vlo = ctx->cell_range[2 * i], vhi = ctx->cell_range[2 * i + 1];
                    if (hd__dl_run_range(entry_run, ctx->vw.tf_count, vlo, vhi) != 0) continue;
                    /* 0: the voxels' runs are needed; 1: every run is 0; 2: every alpha is > 0 too */
                    kind = !hd__dl_live_range(pairs, ctx->vw.tf_count, vlo, vhi) ? 0 : hd__dl_solid_range(weak, ctx->vw.tf_count, vlo, vhi) ? 2 : 1;
                    c[0] = cx; c[1] = cy; c[2] = cz;
                    for (d = 0; d < 3; ++d) {
                        lo[d] = c[d] * M;                              /* first dual cell and voxel */
                        hi[d] = lo[d] + M < dn[d] ? lo[d] + M : dn[d]; /* dual cells end (exclusive) */
                        if (lo[d] < D0[d]) lo[d] = D0[d];              /* those to redo */
                        if (hi[d] > D1[d] + 1) hi[d] = D1[d] + 1;
                    }
                    if (lo[0] >= hi[0] || lo[1] >= hi[1] || lo[2] >= hi[2]) continue;
                    if (kind == 2) {
                        for (z = lo[2]; z < hi[2]; ++z)
                            for (y = lo[1]; y < hi[1]; ++y) {
                                uint8_t *row = cell + ((size_t)(z - D0[2]) * Dn[1] + (y - D0[1])) * Dn[0] - D0[0];
                                uint8_t yz = (uint8_t)(crop[dn[0] + y] && crop[dn[0] + dn[1] + z]);
                                for (x = lo[0]; x < hi[0]; ++x) row[x] = (uint8_t)(yz && crop[x]);
                            }
                        continue;
                    }
                    /* runs of voxels lo .. min(hi, n - 1) */
                    bx = (hi[0] < n[0] - 1 ? hi[0] : n[0] - 1) - lo[0] + 1;
                    by = (hi[1] < n[1] - 1 ? hi[1] : n[1] - 1) - lo[1] + 1;
                    bz = (hi[2] < n[2] - 1 ? hi[2] : n[2] - 1) - lo[2] + 1;
                    if (kind == 0)
                        for (z = 0; z < bz; ++z)
                            for (y = 0; y < by; ++y)
                                for (x = 0; x < bx; ++x)
                                    blk[(z * B + y) * B + x] = hd__dl_run(entry_run, ctx->vw.tf_count,
                                                                          hd__vol_value(&ctx->vw, ((size_t)(lo[2] + z) * n[1] + lo[1] + y) * n[0] + lo[0] + x));
                    for (z = lo[2]; z < hi[2]; ++z)
                        for (y = lo[1]; y < hi[1]; ++y)
                            for (x = lo[0]; x < hi[0]; ++x) {
                                int x1 = x + 1 < n[0] ? x + 1 : x, y1 = y + 1 < n[1] ? y + 1 : y, z1 = z + 1 < n[2] ? z + 1 : z;
                                size_t r00 = ((size_t)z * n[1] + y) * n[0], r10 = ((size_t)z * n[1] + y1) * n[0];
                                size_t r01 = ((size_t)z1 * n[1] + y) * n[0], r11 = ((size_t)z1 * n[1] + y1) * n[0];
                                float v;
                                uint8_t full_cell = 1;
                                if (!crop[x] || !crop[dn[0] + y] || !crop[dn[0] + dn[1] + z]) full_cell = 0;
                                if (full_cell && kind == 0) {
                                    /* the block's rows of the 4 voxel rows, at x and x1 */
                                    const int32_t *b0 = blk + ((z - lo[2]) * B + (y - lo[1])) * B;
                                    const int32_t *b1 = blk + ((z - lo[2]) * B + (y1 - lo[1])) * B;
                                    const int32_t *b2 = blk + ((z1 - lo[2]) * B + (y - lo[1])) * B;
                                    const int32_t *b3 = blk + ((z1 - lo[2]) * B + (y1 - lo[1])) * B;
                                    int xa = x - lo[0], xb = x1 - lo[0];
                                    int32_t a = b0[xa];
                                    full_cell = !(a != 0 && b0[xb] == a && b1[xa] == a && b1[xb] == a && b2[xa] == a && b2[xb] == a &&
                                                  b3[xa] == a && b3[xb] == a);
                                }
                                /* 8 equal values interpolate to that value exactly, whatever the weights */
                                if (full_cell && (v = hd__vol_value(&ctx->vw, r00 + x), hd__vol_value(&ctx->vw, r00 + x1) == v) &&
                                    hd__vol_value(&ctx->vw, r10 + x) == v && hd__vol_value(&ctx->vw, r10 + x1) == v &&
                                    hd__vol_value(&ctx->vw, r01 + x) == v && hd__vol_value(&ctx->vw, r01 + x1) == v &&
                                    hd__vol_value(&ctx->vw, r11 + x) == v && hd__vol_value(&ctx->vw, r11 + x1) == v &&
                                    !(hd__tf_alpha(ctx, v) * ctx->vw.params.extinction > 0.0f))
                                    full_cell = 0;
                                cell[((size_t)(z - D0[2]) * Dn[1] + (y - D0[1])) * Dn[0] + (x - D0[0])] = full_cell;
                            }
                }
    }
    /* grid voxels whose reads reach a non-empty cell: the OR over their span, axis by axis (along
       x from a row's running count of non-empty cells, along y and z row by row) */
    for (z = 0; z < Dn[2]; ++z)
        for (y = 0; y < Dn[1]; ++y) {
            const uint8_t *c = cell + ((size_t)z * Dn[1] + y) * Dn[0];
            uint8_t *o = ax + ((size_t)z * Dn[1] + y) * Gn[0];
            for (j = 0, ps[0] = 0; j < Dn[0]; ++j) ps[j + 1] = ps[j] + c[j];
            for (x = 0; x < Gn[0]; ++x) o[x] = (uint8_t)(ps[span[G0[0] + x][1] - D0[0] + 1] != ps[span[G0[0] + x][0] - D0[0]]);
        }
    for (z = 0; z < Dn[2]; ++z)
        for (y = 0; y < Gn[1]; ++y) {
            uint8_t *o = ay + ((size_t)z * Gn[1] + y) * Gn[0];
            memset(o, 0, (size_t)Gn[0]);
            for (j = span[g[0] + G0[1] + y][0]; j <= span[g[0] + G0[1] + y][1]; ++j) {
                const uint8_t *a = ax + ((size_t)z * Dn[1] + (j - D0[1])) * Gn[0];
                for (x = 0; x < Gn[0]; ++x) o[x] |= a[x];
            }
        }
    for (z = 0; z < Gn[2]; ++z)
        for (y = 0; y < Gn[1]; ++y) {
            memset(line, 0, (size_t)Gn[0]);
            for (j = span[g[0] + g[1] + G0[2] + z][0]; j <= span[g[0] + g[1] + G0[2] + z][1]; ++j) {
                const uint8_t *a = ay + ((size_t)(j - D0[2]) * Gn[1] + y) * Gn[0];
                for (x = 0; x < Gn[0]; ++x) line[x] |= a[x];
            }
            k = ((size_t)(G0[2] + z) * g[1] + (size_t)(G0[1] + y)) * g[0] + (size_t)G0[0];
            for (x = 0; x < Gn[0]; ++x, ++k) {
                uint8_t v = line[x], was = (uint8_t)(ctx->dl.bits[k >> 3] >> (k & 7) & 1u);
                if (v == was) continue;
                any = 1;
                if (v) {
                    ctx->dl.bits[k >> 3] |= (uint8_t)(1u << (k & 7));
                    ++ctx->vw.dl_count;
                } else {
                    ctx->dl.bits[k >> 3] &= (uint8_t)~(1u << (k & 7));
                    --ctx->vw.dl_count;
                }
            }
        }
done:
    if (full || any) r = hd__direct_list_build(ctx);
    if (changed) *changed = full || any;
    hd__free(&ctx->vw, entry_run);
    hd__free(&ctx->vw, pairs);
    hd__free(&ctx->vw, weak);
    hd__free(&ctx->vw, ps);
    hd__free(&ctx->vw, line);
    hd__free(&ctx->vw, cell);
    hd__free(&ctx->vw, ax);
    hd__free(&ctx->vw, ay);
    hd__free(&ctx->vw, span);
    hd__free(&ctx->vw, crop);
    if (r != HD_SUCCESS) hd__direct_mask_free(ctx);
    return r;
oom:
    r = HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "no memory for the direct light's mask (%zu voxels)", gvox);
    hd__free(&ctx->vw, entry_run);
    hd__free(&ctx->vw, pairs);
    hd__free(&ctx->vw, weak);
    hd__free(&ctx->vw, ps);
    hd__free(&ctx->vw, line);
    hd__free(&ctx->vw, cell);
    hd__free(&ctx->vw, ax);
    hd__free(&ctx->vw, ay);
    hd__free(&ctx->vw, span);
    hd__free(&ctx->vw, crop);
    hd__direct_mask_free(ctx);
    ctx->vw.dl_gen++;
    return r;
}

/* The whole mask (hd__direct_mask_box everywhere). */
static hd_result hd__direct_mask(hd__ctx *ctx) { return hd__direct_mask_box(ctx, NULL, NULL); }
