/* hd_cpu_multigrid.h - the CPU backend's geometric multigrid for the diffusion solve
   (params.solver = HD_SOLVER_MULTIGRID), included by hd_cpu.h.

   Why: one relaxation sweep moves information one voxel, so single-level sweeps need O(n^2) of
   them to carry light across an n-voxel volume. A V-cycle smooths the error on the illumination
   grid, restricts the residual to a grid of half the resolution, solves for the correction
   there (recursively, down to a few voxels), and adds it back: every scale of the error is
   reduced in one cycle.

   What is shared and what is not: every level's smoothing and residual are the shared kernels'
   (hd_k_diffuse.h: the same discretisation, both boundaries, RGB scattering), each level with a
   parameter block of its own: its dims, 1 / h^2 and h scaled by 2 per level, and on the coarse
   levels HD_FLAG_DIFFUSE_RHS (their E holds the restricted residual). The fixed point is the
   fine grid's discrete solution: the fine smoother and the fine residual define it, the coarse
   grids only speed up the way there (tested: multigrid and red-black reach the same phi).
   The transfers are this file's plain C:
   - a coarse grid has half its fine grid's voxels per axis, rounded DOWN: with an odd size the
     last fine voxel has no parent and the coarse box ends one fine voxel inside the fine one.
     Rounding up instead put the last coarse voxel's centre on the fine box's vacuum boundary,
     and the cycle diverged on odd sizes with air (63^3 sphere: residual x1.4 per cycle; the
     head CT's 27-voxel level); a boundary moved inward only makes the correction smaller there;
   - sigma_t (and with RGB scattering its colour channels) of a coarse voxel: the mean of its
     8 children, rebuilt when sigma_t changes;
   - restriction: the mean of the children's residuals (both sides of the equation are per unit
     volume);
   - prolongation: trilinear interpolation of the coarse correction at the fine voxel centres
     (weights 3/4, 1/4 per axis), 0 beyond the coarse grid, added to phi with the weight that
     minimises the error's energy (hd__cpu_mg_correct).
   A cycle: 2 red-black sweeps, residual, restrict, cycle on the coarse grid, prolong, 2 sweeps;
   the coarsest grid (at most 4 voxels per axis, or fewer than 4 on one axis) gets 16 sweeps. */

#define HD__MG_MAX_LEVELS 12
#define HD__MG_PRE 2
#define HD__MG_POST 2
#define HD__MG_COARSEST_SWEEPS 16

typedef struct hd__cpu_level {
    hd__kparams kp;          /* level 0: a copy of ctx->kp refreshed every cycle */
    hd__kctx k;
    hd__cpu_grid g;
    float *sig, *rhs, *phi; /* coarse levels only (level 0 uses the backend's buffers) */
    float *res;              /* the residual of this level's equation */
    int dims[3];
} hd__cpu_level;

struct hd__cpu_mg {
    hd__cpu_level lv[HD__MG_MAX_LEVELS];
    int levels, channels, sig_channels, fine[3];
    unsigned sig_gen;        /* the backend's sig_gen the coarse sigma_t were restricted from */
    int sig_surface;         /* ... and the boundary they were restricted for */
    int cur;                 /* the level a transfer pass writes (coarse) */
    double *dot_a, *dot_b;   /* per-row partial sums of the correction weight (level 0's rows) */
    float alpha;
};

static size_t hd__mg_vox(const int *d) { return (size_t)d[0] * d[1] * d[2]; }

static void hd__cpu_mg_free(hd__ctx *ctx)
{
    struct hd__cpu_mg *mg = ctx->be->mg;
    int l;
    if (!mg) return;
    for (l = 0; l < mg->levels; ++l) {
        hd__free(ctx, mg->lv[l].sig);
        hd__free(ctx, mg->lv[l].rhs);
        hd__free(ctx, mg->lv[l].phi);
        hd__free(ctx, mg->lv[l].res);
    }
    hd__free(ctx, mg->dot_a);
    hd__free(ctx, mg->dot_b);
    hd__free(ctx, mg);
    ctx->be->mg = NULL;
}

/* Bytes the levels hold (the fine residual and every coarse grid); 0 without multigrid. */
static size_t hd__be_solver_bytes(const hd__ctx *ctx)
{
    const struct hd__cpu_mg *mg = ctx->be->mg;
    size_t b = 0;
    int l;
    if (!mg || ctx->params.solver != HD_SOLVER_MULTIGRID) return 0;
    b += 2 * sizeof(double) * (size_t)mg->lv[0].dims[1] * mg->lv[0].dims[2] * (size_t)mg->channels; /* row sums */
    for (l = 0; l < mg->levels; ++l) {
        size_t v = hd__mg_vox(mg->lv[l].dims);
        b += v * (size_t)mg->channels * sizeof(float); /* res */
        if (l > 0) b += v * ((size_t)mg->sig_channels + 2 * (size_t)mg->channels) * sizeof(float);
    }
    return b;
}
#define HD__BE_HAS_SOLVER_BYTES 1

/* Level l's parameter block: the fine one with the level's dims, 1 / h^2 and h, and on coarse
   levels the right-hand-side flag. */
static void hd__cpu_mg_params(hd__ctx *ctx, int l)
{
    hd__cpu_level *L = &ctx->be->mg->lv[l];
    float s = (float)(1 << l);
    L->kp = ctx->kp;
    L->kp.gdims.x = L->dims[0]; L->kp.gdims.y = L->dims[1]; L->kp.gdims.z = L->dims[2];
    L->kp.grid.x = ctx->kp.grid.x / (s * s); L->kp.grid.y = ctx->kp.grid.y / (s * s); L->kp.grid.z = ctx->kp.grid.z / (s * s);
    L->kp.gridh.x = ctx->kp.gridh.x * s; L->kp.gridh.y = ctx->kp.gridh.y * s; L->kp.gridh.z = ctx->kp.gridh.z * s;
    if (l > 0) L->kp.counts.z |= HD_FLAG_DIFFUSE_RHS;
    L->k.p = &L->kp;
    if (l == 0) {
        L->k = ctx->be->k; /* the backend's buffers (phi swaps are not used by multigrid) */
        L->k.p = &L->kp;
    }
    L->g.k = &L->k;
    L->g.res = L->res;
}

/* Allocates the levels for the current grid, channels and sigma_t channels. */
static hd_result hd__cpu_mg_alloc(hd__ctx *ctx)
{
    hd__backend *be = ctx->be;
    struct hd__cpu_mg *mg;
    int l, d[3], i;
    be->mg = mg = (struct hd__cpu_mg *)hd__calloc(ctx, 1, sizeof *mg);
    if (!mg) return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the multigrid levels");
    mg->channels = ctx->channels;
    mg->sig_channels = ctx->sig_channels;
    mg->sig_gen = be->sig_gen - 1u; /* restrict sigma_t on first use */
    for (i = 0; i < 3; ++i) mg->fine[i] = d[i] = ctx->gdims[i];
    mg->dot_a = (double *)hd__calloc(ctx, (size_t)d[1] * d[2] * (size_t)mg->channels, sizeof(double));
    mg->dot_b = (double *)hd__calloc(ctx, (size_t)d[1] * d[2] * (size_t)mg->channels, sizeof(double));
    if (!mg->dot_a || !mg->dot_b) {
        hd__cpu_mg_free(ctx);
        return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the multigrid row sums");
    }
    for (l = 0; l < HD__MG_MAX_LEVELS; ++l) {
        hd__cpu_level *L = &mg->lv[l];
        size_t v = hd__mg_vox(d);
        memcpy(L->dims, d, sizeof d);
        mg->levels = l + 1;
        L->res = (float *)hd__calloc(ctx, v * (size_t)mg->channels, sizeof(float));
        if (l > 0) {
            L->sig = (float *)hd__calloc(ctx, v * (size_t)mg->sig_channels, sizeof(float));
            L->rhs = (float *)hd__calloc(ctx, v * (size_t)mg->channels, sizeof(float));
            L->phi = (float *)hd__calloc(ctx, v * (size_t)mg->channels, sizeof(float));
        }
        if (!L->res || (l > 0 && (!L->sig || !L->rhs || !L->phi))) {
            hd__cpu_mg_free(ctx);
            return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate multigrid level %d (%dx%dx%d)", l,
                           d[0], d[1], d[2]);
        }
        L->k.sig = L->sig; L->k.E = L->rhs; L->k.phi = L->phi;
        if ((d[0] <= 4 && d[1] <= 4 && d[2] <= 4) || d[0] < 4 || d[1] < 4 || d[2] < 4) break;
        for (i = 0; i < 3; ++i) d[i] = d[i] / 2;
    }
    return HD_SUCCESS;
}

/* ---- transfers, one coarse row (or fine row) per item ------------------------------------------- */
/* Mean of the existing children of coarse voxel (X, Y, Z) in the fine channel-planar field f
   (dims fd, nch channels of fd's size), channel ch. */
static float hd__mg_child_mean(const float *f, const int *fd, int X, int Y, int Z, int ch)
{
    size_t plane = hd__mg_vox(fd) * (size_t)ch;
    float s = 0.0f;
    int n = 0, i, j, k;
    for (k = 2 * Z; k <= 2 * Z + 1 && k < fd[2]; ++k)
        for (j = 2 * Y; j <= 2 * Y + 1 && j < fd[1]; ++j)
            for (i = 2 * X; i <= 2 * X + 1 && i < fd[0]; ++i) {
                s += f[plane + ((size_t)k * fd[1] + j) * fd[0] + i];
                ++n;
            }
    return s / (float)n;
}

/* sigma_t of a coarse voxel from its 8 children: the harmonic mean, i.e. the mean of their D, so
   a coarse voxel conducts like its most conductive part (the arithmetic mean of sigma_t made
   voxels of soft tissue and bone, or of air and tissue, insulators, and the cycle diverged on a
   sphere in air). Box boundary: every child counts, air floored at 1e-4 per world unit (air
   conducts). Surface boundary: empty children are vacuum, not medium: the mean is over the
   medium children, and a coarse voxel with fewer than 4 of them is empty. */
static float hd__mg_child_harmonic(const float *f, const int *fd, int X, int Y, int Z, int surface, float empty_below)
{
    float s = 0.0f;
    int n = 0, i, j, k;
    for (k = 2 * Z; k <= 2 * Z + 1; ++k)
        for (j = 2 * Y; j <= 2 * Y + 1; ++j)
            for (i = 2 * X; i <= 2 * X + 1; ++i) {
                float v = f[((size_t)k * fd[1] + j) * fd[0] + i];
                if (surface && v < empty_below) continue;
                s += 1.0f / (v > 1e-4f ? v : 1e-4f);
                ++n;
            }
    return surface && n < 4 ? 0.0f : (float)n / s;
}

/* sigma_t (all its channels) of level mg->cur from the level above. */
static void hd__cpu_mg_sig_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *C = &mg->lv[mg->cur], *F = &mg->lv[mg->cur - 1];
    const float *fs = mg->cur == 1 ? be->sig : F->sig;
    int Y = r % C->dims[1], Z = (r / C->dims[1]) % C->dims[2], ch = r / (C->dims[1] * C->dims[2]), X;
    float *dst = C->sig + hd__mg_vox(C->dims) * (size_t)ch + ((size_t)Z * C->dims[1] + Y) * C->dims[0];
    int surface = (be->k.p->counts.z & HD_FLAG_SURFACE_BOUNDARY) != 0;
    /* empty under the surface boundary: sigma' = sigma_t (1 - albedo g) below half the floor */
    float empty_below = 0.5f * be->k.p->grid.w / (1.0f - be->k.p->medium.y * be->k.p->medium.z);
    for (X = 0; X < C->dims[0]; ++X)
        dst[X] = ch == 0 ? hd__mg_child_harmonic(fs, F->dims, X, Y, Z, surface, empty_below)
                         : hd__mg_child_mean(fs, F->dims, X, Y, Z, ch);
}

/* The right-hand side of level mg->cur: the mean of the residual of the level above; its phi
   (the correction) starts at 0. */
static void hd__cpu_mg_restrict_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *C = &mg->lv[mg->cur], *F = &mg->lv[mg->cur - 1];
    int Y = r % C->dims[1], Z = (r / C->dims[1]) % C->dims[2], ch = r / (C->dims[1] * C->dims[2]), X;
    size_t off = hd__mg_vox(C->dims) * (size_t)ch + ((size_t)Z * C->dims[1] + Y) * C->dims[0];
    for (X = 0; X < C->dims[0]; ++X) {
        C->rhs[off + X] = hd__mg_child_mean(F->res, F->dims, X, Y, Z, ch);
        C->phi[off + X] = 0.0f;
    }
}

/* Coarse index and weight of the nearer coarse neighbour along one axis for fine index i:
   the fine centre lies 1/4 coarse voxel from coarse voxel i / 2, toward its far neighbour. */
static void hd__mg_axis(int i, int *near, int *far)
{
    *near = i >> 1;
    *far = (i & 1) ? *near + 1 : *near - 1;
}

/* The trilinear interpolation of level mg->cur's correction at the voxel centres of row r of
   the level above, into e[]. */
static void hd__mg_prolong_into(const hd__backend *be, int r, float *e)
{
    const struct hd__cpu_mg *mg = be->mg;
    const hd__cpu_level *C = &mg->lv[mg->cur], *F = &mg->lv[mg->cur - 1];
    int y = r % F->dims[1], z = (r / F->dims[1]) % F->dims[2], ch = r / (F->dims[1] * F->dims[2]), x, a, b;
    int yn, yf, zn, zf;
    const int *cd = C->dims;
    const float *cp = C->phi + hd__mg_vox(cd) * (size_t)ch;
    hd__mg_axis(y, &yn, &yf);
    hd__mg_axis(z, &zn, &zf);
    for (x = 0; x < F->dims[0]; ++x) {
        int xn, xf, ys[2], zs[2], xs[2];
        float w[2] = {0.75f, 0.25f}, v = 0.0f;
        hd__mg_axis(x, &xn, &xf);
        xs[0] = xn; xs[1] = xf; ys[0] = yn; ys[1] = yf; zs[0] = zn; zs[1] = zf;
        for (a = 0; a < 2; ++a)
            for (b = 0; b < 2; ++b) {
                int c2;
                if (zs[a] < 0 || zs[a] >= cd[2] || ys[b] < 0 || ys[b] >= cd[1]) continue;
                for (c2 = 0; c2 < 2; ++c2)
                    if (xs[c2] >= 0 && xs[c2] < cd[0])
                        v += w[a] * w[b] * w[c2] * cp[((size_t)zs[a] * cd[1] + ys[b]) * cd[0] + xs[c2]];
            }
        e[x] = v;
    }
}

/* The coarse correction e is added with the weight alpha = <e, r> / <e, A e> that minimises the
   error's energy norm (A is symmetric positive definite): a coarse operator that misjudges the
   fine one (air against tissue, the boundary's position) then costs convergence speed, never
   divergence. Three passes over the rows of the level above mg->cur, each summing per row
   (dot[r], added in row order afterwards: the same bits for any thread count):
   1. phi += e, dot_a[r] = <e, r_old>;  2. dot_b[r] = <e, r_old - r_new> = <e, A e>;
   3. phi += (alpha - 1) e. */
static void hd__cpu_mg_add_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    const hd__cpu_level *F = &mg->lv[mg->cur - 1];
    int x, gx = F->dims[0];
    float e[HD__CPU_ROW_MAX];
    const float *res = F->res + (size_t)r * gx;
    float *phi = F->k.phi + (size_t)r * gx;
    double d = 0.0;
    hd__mg_prolong_into(be, r, e);
    for (x = 0; x < gx; ++x) {
        d += (double)e[x] * res[x];
        phi[x] += e[x];
    }
    mg->dot_a[r] = d;
}
static void hd__cpu_mg_energy_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    const hd__cpu_level *F = &mg->lv[mg->cur - 1];
    int x, gx = F->dims[0];
    float e[HD__CPU_ROW_MAX], rn[HD__CPU_ROW_MAX];
    const float *res = F->res + (size_t)r * gx;
    double d = 0.0;
    hd__mg_prolong_into(be, r, e);
    hd__cpu_residual_row_into(be, r, rn);
    for (x = 0; x < gx; ++x) d += (double)e[x] * ((double)res[x] - rn[x]);
    mg->dot_b[r] = d;
}
static void hd__cpu_mg_scale_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    const hd__cpu_level *F = &mg->lv[mg->cur - 1];
    int x, gx = F->dims[0];
    float e[HD__CPU_ROW_MAX], s = mg->alpha - 1.0f;
    float *phi = F->k.phi + (size_t)r * gx;
    hd__mg_prolong_into(be, r, e);
    for (x = 0; x < gx; ++x) phi[x] += s * e[x];
}

/* Adds level l + 1's correction to level l with the energy-minimising weight. */
static void hd__cpu_mg_correct(hd__backend *be, int l)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *L = &mg->lv[l];
    int rows = L->dims[1] * L->dims[2] * mg->channels, r;
    double a = 0.0, b = 0.0;
    mg->cur = l + 1;
    be->grid = &L->g;
    hd__cpu_parallel(be, hd__cpu_mg_add_row, rows);
    hd__cpu_parallel(be, hd__cpu_mg_energy_row, rows);
    for (r = 0; r < rows; ++r) { a += mg->dot_a[r]; b += mg->dot_b[r]; }
    mg->alpha = b > 0.0 && a > 0.0 ? (float)(a / b) : 1.0f;
    if (mg->alpha != 1.0f) hd__cpu_parallel(be, hd__cpu_mg_scale_row, rows);
}

/* ---- the cycle --------------------------------------------------------------------------------- */
static int hd__mg_rows(const hd__cpu_level *L, int channels) { return L->dims[1] * L->dims[2] * channels; }

static void hd__cpu_mg_cycle(hd__backend *be, int l)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *L = &mg->lv[l];
    be->grid = &L->g;
    if (l == mg->levels - 1) {
        hd__cpu_red_black(be, HD__MG_COARSEST_SWEEPS);
        return;
    }
    hd__cpu_red_black(be, HD__MG_PRE);
    hd__cpu_parallel(be, hd__cpu_residual_row, hd__mg_rows(L, mg->channels));
    mg->cur = l + 1;
    hd__cpu_parallel(be, hd__cpu_mg_restrict_row, hd__mg_rows(&mg->lv[l + 1], mg->channels));
    hd__cpu_mg_cycle(be, l + 1);
    hd__cpu_mg_correct(be, l);
    be->grid = &L->g;
    hd__cpu_red_black(be, HD__MG_POST);
}

/* One V-cycle on the illumination grid (the solver's "sweep"). */
static hd_result hd__be_multigrid(hd__ctx *ctx)
{
    hd__backend *be = ctx->be;
    struct hd__cpu_mg *mg = be->mg;
    int l;
    hd_result r;
    if (mg && (mg->channels != ctx->channels || mg->sig_channels != ctx->sig_channels ||
               memcmp(mg->fine, ctx->gdims, sizeof mg->fine) != 0))
        hd__cpu_mg_free(ctx);
    if (!be->mg && (r = hd__cpu_mg_alloc(ctx)) != HD_SUCCESS) return r;
    mg = be->mg;
    for (l = 0; l < mg->levels; ++l) hd__cpu_mg_params(ctx, l);
    if (mg->sig_gen != be->sig_gen || mg->sig_surface != (ctx->kp.counts.z & HD_FLAG_SURFACE_BOUNDARY)) {
        for (mg->cur = 1; mg->cur < mg->levels; ++mg->cur)
            hd__cpu_parallel(be, hd__cpu_mg_sig_row, mg->lv[mg->cur].dims[1] * mg->lv[mg->cur].dims[2] * mg->sig_channels);
        mg->sig_gen = be->sig_gen;
        mg->sig_surface = ctx->kp.counts.z & HD_FLAG_SURFACE_BOUNDARY;
    }
    hd__cpu_mg_cycle(be, 0);
    be->grid = NULL;
    return HD_SUCCESS;
}
#define HD__BE_HAS_MULTIGRID 1
