/* hd_cpu_multigrid.h - the CPU backend's multigrid-preconditioned conjugate gradients for the
   diffusion solve (params.solver = HD_SOLVER_MULTIGRID), included by hd_cpu.h. This file is the
   design; the per-voxel math is the shared backends/kernels/hd_k_multigrid.h, and the OpenCL
   backend (hd_opencl.h's hd__be_multigrid) runs the same passes in the same order.

   Why: one relaxation sweep moves information one voxel, so single-level sweeps need O(n^2) of
   them to carry light across an n-voxel volume. A V-cycle reduces every scale of the error at
   once, but on the head CT alone it contracted only 0.89-0.99 per cycle: thin, optically thin
   structures (skin next to bone) are not represented on the coarse grids, and the few error
   modes they carry are left to the smoother. Used as the preconditioner of conjugate gradients
   (the discrete operator A is symmetric positive definite: harmonic-mean face weights, the
   Marshak terms and sigma_a on the diagonal; empty voxels of the surface boundary are identity
   rows), CG removes those few slow modes in a few extra steps.

   One solver step (diffusion_sweeps counts them; default 1 per HD iteration):
   1. r = f - A (phi + lo), recomputed from the iterate and E at every step (so a new E is used
      at once and rounding in the updates never accumulates into r), with the kernel's own float
      coefficients but summed in double as differences (hd_mg_res_f64): the float kernel's
      residual cancels two terms of about den phi and floored the residual near 1e-4;
   2. z = M r: one symmetric V-cycle (below) from z = 0;
   3. beta = <r, z> / <r, z>_previous (0 at a restart), p = z + beta p;
   4. q = A p (the same double-summed residual with a zero right-hand side),
      alpha = <r, p> / <p, q>;
   5. phi + lo += alpha p in double, phi the float rounding of the sum (what the projection
      reads), lo the rest: the iterate keeps about 48 bits, and phi is the solution rounded once;
   6. surface boundary: the empty voxels' phi = the sweeps' Marshak extrapolation, lo = -phi
      (hd__cpu_mg_extrap_row: the iterate stays 0 on their identity rows).
   The dot products are summed in double, per row and then in row order: the same bits for any
   thread count. Step 5 is an exact line search along p, so the error's energy norm never grows,
   whatever p is. CG restarts (beta = 0) at each new HD iteration (a new E: ctx->iterations
   changed) and whenever A changes (sigma_t reclassified, albedo, g, grid, boundary).
   Cost: about 15 red-black sweeps of wall time per step (head CT, surface boundary, 2 threads:
   300 ms against 20.5 ms per sweep at 256x256x108, 47.8 against 3.23 at half resolution); the
   V-cycle is two thirds of it, the two double-summed residual passes most of the rest.
   Every level's buffers are in the colour layout (hd__mg_slots), so the smoothing runs the
   sweep's unit-stride rows. A load by coordinates alternates between the two colour halves of a
   row (a gather): with the transfers loading so (hd_mg_prolong, hd_mg_restrict_line) a step went
   from 213 to 280 ms (box) and 268 to 316 ms (surface) at full resolution (one A/B pair, load 2;
   perf: the prolongation 1.7x, the restriction 1.3-1.4x), so they load each row they read once,
   as its two unit-stride half-rows (hd__cpu_mg_load_row), and run the kernel's per-term
   functions on the values (hd_mg_prolong_term, hd_mg_restrict_term, hd_mg_medium_of: the same
   operations in the same order, the same bits), as do CG's dot products (hd_mg_dot_term): full
   resolution box 211-213 ms against 212-236 before the colour layout and 274-278 with the
   gathers, surface 267-277 against 261-266 and 304; half resolution 31-32 / 38 against 29 / 36
   and 39 / 43 (two interleaved rounds, load 2.5-3). Still through coordinates: the double
   residual (1.2x) and the surface extrapolation (1.3x; a literal f16 there gained nothing).

   The V-cycle is a symmetric positive definite preconditioner (M^-1 symmetric, what CG needs):
   - every level's smoothing and residual are the shared kernel's (hd_k_diffuse.h: the same
     discretisation, both boundaries, RGB scattering) with HD_FLAG_DIFFUSE_RHS (E holds the
     right-hand side: r on the fine level, the restricted residual below) and a parameter block
     of its own: its dims, 1 / h^2 and h scaled by 2 per level;
   - pre-smoothing: 2 red-black sweeps (red, then black); post-smoothing: 2 black-red sweeps,
     the adjoint order; the coarsest grid (at most 4 voxels per axis, or fewer than 4 on one
     axis): 8 red-black then 8 black-red sweeps from 0 (symmetric too);
   - prolongation P: trilinear interpolation of the coarse correction at the fine voxel centres
     (weights 3/4, 1/4 per axis), 0 beyond the coarse grid, added with weight 1 (a fixed linear
     map: the energy-minimising weight the plain V-cycle used made M nonlinear);
   - restriction R = P^T / 8 (full weighting, 1/8 3/8 3/8 1/8 per axis: a weighted mean, as both
     sides of the equation are per unit volume);
   - box boundary: both transfers masked to medium voxels (hd_mg_medium: the prolongation writes
     no correction into air, the restriction reads no residual from it; still R = (D P)^T / 8):
     trilinear interpolation put a quarter of the tissue's correction into the air beside it,
     whose conductance is about 1e4 times tissue's, and CG's line search shrank every step
     (24^3 sphere, 12 steps: max error 9.1e-3 before, 1.9e-6 with the coarse sigma_t rule);
   - a coarse grid has half its fine grid's voxels per axis, rounded DOWN: with an odd size the
     last fine voxel has no parent (rounding up put the last coarse voxel's centre on the fine
     box's vacuum boundary, and the plain cycle diverged on odd sizes with air);
   - coarse sigma_t: the harmonic mean of the 8 children (hd_mg_coarse_sig; over the medium ones
     when at least 4 are), rebuilt when sigma_t changes; RGB colour channels: the mean.
   The fixed point is the fine grid's discrete solution (tested: phi matches red-black's).
   Memory: r, z, p, lo and the fine residual (which doubles as q) are 20 bytes per voxel and
   channel, the coarse levels about 2.3 more (hd__be_solver_bytes, counted in method_bytes). */

#define HD__MG_MAX_LEVELS 12
#define HD__MG_PRE 2
#define HD__MG_POST 2
#define HD__MG_COARSEST_SWEEPS 8 /* red-black, then as many black-red */

typedef struct hd__cpu_level {
    hd__kparams kp;          /* the fine parameters with this level's dims, h and the rhs flag */
    hd__kctx k;
    hd__cpu_grid g;
    float *sig;              /* coarse levels only (level 0 reads the backend's sigma_t) */
    float *rhs, *phi;        /* the right-hand side and the correction; level 0: r and z */
    float *res;              /* the residual of this level's equation; level 0: also q = A p */
    int dims[3];
} hd__cpu_level;

struct hd__cpu_mg {
    hd__cpu_level lv[HD__MG_MAX_LEVELS];
    int levels, channels, sig_channels, fine[3];
    hd__mg_cg cg;            /* restarts, the coarse sigma_t's generation, <r, z> (hd_multigrid_cg.h) */
    int cur;                 /* the level a transfer pass writes (coarse) */
    int colour;              /* the colour ((x + y + z) & 1) hd__cpu_mg_extrap_row writes */
    float *p;                /* CG's search direction (fine grid) */
    float *lo;               /* the iterate's low part: CG's iterate is phi + lo, phi its float
                                rounding (hd__cpu_mg_update_row) */
    hd__kparams opkp;        /* A p: level 0's parameters, E = z (zeroed by then), phi = p */
    hd__kctx opk;
    hd__cpu_grid opg, fineg; /* A p into level 0's res; f - A phi into level 0's rhs (r) */
    double *dot_a, *dot_b;   /* per-row partial sums of the dot products (level 0's rows) */
    double alpha;
    float beta;
    double vcycle_seconds;   /* wall time in V-cycles (benchmark: a step against a V-cycle) */
};

/* Elements of a level's grid of `channels` channels: every buffer is in the colour layout
   (hd_prelude_c.h's hd__split_slot, as the backend's sigma_t, E and phi), so the shared kernels
   and the sweep's row loop read them alike; padding slots stay 0. */
static size_t hd__mg_slots(const int *d, int channels) { return hd__split_slots(d[0], d[1], (size_t)d[2] * (size_t)channels); }

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
    hd__free(ctx, mg->p);
    hd__free(ctx, mg->lo);
    hd__free(ctx, mg->dot_a);
    hd__free(ctx, mg->dot_b);
    hd__free(ctx, mg);
    ctx->be->mg = NULL;
}

/* Bytes the solver holds (r, z, p, the fine residual and every coarse grid); 0 without it. */
static size_t hd__be_solver_bytes(const hd__ctx *ctx)
{
    const struct hd__cpu_mg *mg = ctx->be->mg;
    size_t b = 0;
    int l;
    if (!mg || ctx->params.solver != HD_SOLVER_MULTIGRID) return 0;
    b += 2 * sizeof(double) * (size_t)mg->lv[0].dims[1] * mg->lv[0].dims[2] * (size_t)mg->channels; /* row sums */
    b += 2 * hd__mg_slots(mg->lv[0].dims, mg->channels) * sizeof(float);                             /* p, lo */
    for (l = 0; l < mg->levels; ++l) {
        b += hd__mg_slots(mg->lv[l].dims, mg->channels) * 3 * sizeof(float); /* rhs, phi, res */
        if (l > 0) b += hd__mg_slots(mg->lv[l].dims, mg->sig_channels) * sizeof(float);
    }
    return b;
}
#define HD__BE_HAS_SOLVER_BYTES 1

/* Level l's parameter block and kernel context: the fine block with the level's dims, 1 / h^2
   and h, and the right-hand-side flag; its buffers (level 0: the backend's sigma_t). */
static void hd__cpu_mg_params(hd__ctx *ctx, int l)
{
    hd__cpu_level *L = &ctx->be->mg->lv[l];
    L->kp = hd__mg_level_kp(&ctx->kp, l, L->dims);
    L->k = ctx->be->k;
    L->k.p = &L->kp;
    L->k.sig = l == 0 ? ctx->be->sig : L->sig;
    L->k.E = L->rhs;
    L->k.phi = L->phi;
    L->k.phi2 = NULL;
    L->k.f16 = 0;
    L->g.k = &L->k;
    L->g.res = L->res;
}

/* The fine grid's two extra passes: f - A phi with the backend's own context into r, and A p
   (level 0's context with E = z, which is zero when it runs, and phi = p) into level 0's res. */
static void hd__cpu_mg_fine_params(hd__ctx *ctx)
{
    struct hd__cpu_mg *mg = ctx->be->mg;
    mg->fineg.k = &ctx->be->k;
    mg->fineg.res = mg->lv[0].rhs;
    mg->opkp = mg->lv[0].kp;
    mg->opk = mg->lv[0].k;
    mg->opk.p = &mg->opkp;
    mg->opk.E = mg->lv[0].phi;
    mg->opk.phi = mg->p;
    mg->opg.k = &mg->opk;
    mg->opg.res = mg->lv[0].res;
}

/* Allocates the levels and CG's vectors for the current grid, channels and sigma_t channels. */
static hd_result hd__cpu_mg_alloc(hd__ctx *ctx)
{
    hd__backend *be = ctx->be;
    struct hd__cpu_mg *mg;
    int l, d[3], i;
    size_t rows, fine;
    be->mg = mg = (struct hd__cpu_mg *)hd__calloc(ctx, 1, sizeof *mg);
    if (!mg) return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the multigrid levels");
    mg->channels = ctx->channels;
    mg->sig_channels = ctx->sig_channels;
    hd__mg_cg_init(&mg->cg, be->sig_gen);
    for (i = 0; i < 3; ++i) mg->fine[i] = d[i] = ctx->gdims[i];
    rows = (size_t)d[1] * d[2] * (size_t)mg->channels;
    fine = hd__mg_slots(d, mg->channels);
    mg->dot_a = (double *)hd__calloc(ctx, rows, sizeof(double));
    mg->dot_b = (double *)hd__calloc(ctx, rows, sizeof(double));
    mg->p = (float *)hd__calloc(ctx, fine, sizeof(float));
    mg->lo = (float *)hd__calloc(ctx, fine, sizeof(float));
    if (!mg->dot_a || !mg->dot_b || !mg->p || !mg->lo) {
        hd__cpu_mg_free(ctx);
        return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the conjugate gradients' vectors");
    }
    for (l = 0; l < HD__MG_MAX_LEVELS; ++l) {
        hd__cpu_level *L = &mg->lv[l];
        size_t v = hd__mg_slots(d, mg->channels);
        memcpy(L->dims, d, sizeof d);
        mg->levels = l + 1;
        L->res = (float *)hd__calloc(ctx, v, sizeof(float));
        L->rhs = (float *)hd__calloc(ctx, v, sizeof(float));
        L->phi = (float *)hd__calloc(ctx, v, sizeof(float));
        if (l > 0) L->sig = (float *)hd__calloc(ctx, hd__mg_slots(d, mg->sig_channels), sizeof(float));
        if (!L->res || !L->rhs || !L->phi || (l > 0 && !L->sig)) {
            hd__cpu_mg_free(ctx);
            return HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate multigrid level %d (%dx%dx%d)", l,
                           d[0], d[1], d[2]);
        }
        if ((d[0] <= 4 && d[1] <= 4 && d[2] <= 4) || d[0] < 4 || d[1] < 4 || d[2] < 4) break;
        hd__mg_level_dims(mg->fine, l + 1, d); /* as hd__mg_bytes counts them */
    }
    return HD_SUCCESS;
}

/* ---- transfers, one coarse row (or fine row) per item ------------------------------------------- */
/* The per-voxel math is the shared kernel's (backends/kernels/hd_k_multigrid.h, with the OpenCL
   backend); these rows run it on a copy of a level's kernel context whose f16 is a literal 0 (the
   levels are float32: no per-load precision test, hd_prelude_c.h's HD_GET) and whose phi is the
   grid the function reads. */

/* sigma_t (all its channels) of level mg->cur from the level above (hd_mg_coarse_sig). */
static HD__CPU_FLATTEN void hd__cpu_mg_sig_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *C = &mg->lv[mg->cur];
    hd__kctx k = mg->lv[mg->cur - 1].k;
    int Y = r % C->dims[1], Z = (r / C->dims[1]) % C->dims[2], ch = r / (C->dims[1] * C->dims[2]), X;
    k.f16 = 0;
    for (X = 0; X < C->dims[0]; ++X)
        C->sig[hd__split_slot(C->dims[0], C->dims[1], X, Y, Z + ch * C->dims[2])] = hd_mg_coarse_sig(&k, X, Y, Z, ch);
}

/* Row (y, zz) of a grid of dims gx, gy in the colour layout into out[] in x order: its two
   colour half-rows, each unit-stride (a load by coordinates would alternate between them). */
static void hd__cpu_mg_load_row(const float *buf, int gx, int gy, int y, int zz, float *out)
{
    int h, i, n;
    for (h = 0; h < 2; ++h) {
        const float *src = buf + hd__split_slot(gx, gy, h, y, zz);
        n = hd__cpu_half_len(gx, h);
        for (i = 0; i < n; ++i) out[2 * i + h] = src[i];
    }
}

/* The right-hand side of level mg->cur: R = P^T / 8 of the residual of the level above
   (hd_k_multigrid.h), each fine column's share of the row computed once (hd_mg_restrict_line's
   terms, hd_mg_restrict_term, on each of the up to 16 fine rows loaded once, in its a, b order)
   and four of them combined per coarse voxel (hd_mg_restrict_x); its phi (the correction)
   starts at 0. */
static HD__CPU_FLATTEN void hd__cpu_mg_restrict_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *C = &mg->lv[mg->cur], *F = &mg->lv[mg->cur - 1];
    int Y = r % C->dims[1], Z = (r / C->dims[1]) % C->dims[2], ch = r / (C->dims[1] * C->dims[2]), X, x, t, a, b;
    int gx = F->dims[0], gy = F->dims[1], gz = F->dims[2];
    hd__kctx k = F->k;
    float line[HD__CPU_ROW_MAX], res[HD__CPU_ROW_MAX], m[HD__CPU_ROW_MAX];
    k.f16 = 0;
    for (x = 0; x < gx; ++x) line[x] = 0.0f;
    for (a = 0; a < 4; ++a) {
        int z = 2 * Z - 1 + a;
        if (z < 0 || z >= gz) continue;
        for (b = 0; b < 4; ++b) {
            int y = 2 * Y - 1 + b;
            if (y < 0 || y >= gy) continue;
            hd__cpu_mg_load_row(F->res, gx, gy, y, z + ch * gz, res);
            hd__cpu_mg_load_row(k.sig, gx, gy, y, z, m);
            for (x = 0; x < gx; ++x) line[x] = hd_mg_restrict_term(line[x], a, b, res[x], hd_mg_medium_of(&k, m[x]));
        }
    }
    for (X = 0; X < C->dims[0]; ++X) {
        float s = 0.0f;
        for (t = 0; t < 4; ++t) {
            x = 2 * X - 1 + t;
            if (x >= 0 && x < gx) s = hd_mg_restrict_x(s, t, line[x]);
        }
        size_t o = hd__split_slot(C->dims[0], C->dims[1], X, Y, Z + ch * C->dims[2]);
        C->rhs[o] = s;
        C->phi[o] = 0.0f;
    }
}

/* Adds the prolonged correction of level mg->cur (hd_mg_prolong's terms, hd_mg_prolong_term, on
   the up to 4 coarse rows loaded once), masked to the medium (hd_mg_medium_of the level above's
   sigma_t), to row r of the level above. */
static HD__CPU_FLATTEN void hd__cpu_mg_prolong_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    const hd__cpu_level *F = &mg->lv[mg->cur - 1], *C = &mg->lv[mg->cur];
    hd__kctx kf = F->k;
    int gx = F->dims[0], gy = F->dims[1], gz = F->dims[2], y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    int GX = C->dims[0], GY = C->dims[1], GZ = C->dims[2], x, a, b, t, h, i, n;
    int zc[2], yc[2];
    float e[HD__CPU_ROW_MAX], m[HD__CPU_ROW_MAX], u[2][2][HD__CPU_ROW_MAX / 2 + 1];
    kf.f16 = 0;
    zc[0] = z >> 1;
    zc[1] = hd_mg_far(z);
    yc[0] = y >> 1;
    yc[1] = hd_mg_far(y);
    for (a = 0; a < 2; ++a)
        for (b = 0; b < 2; ++b)
            if (zc[a] >= 0 && zc[a] < GZ && yc[b] >= 0 && yc[b] < GY)
                hd__cpu_mg_load_row(C->phi, GX, GY, yc[b], zc[a] + c * GZ, u[a][b]);
    hd__cpu_mg_load_row(kf.sig, gx, gy, y, z, m);
    for (x = 0; x < gx; ++x) {
        int xc[2];
        float v = 0.0f;
        xc[0] = x >> 1;
        xc[1] = hd_mg_far(x);
        for (a = 0; a < 2; ++a) {
            if (zc[a] < 0 || zc[a] >= GZ) continue;
            for (b = 0; b < 2; ++b) {
                if (yc[b] < 0 || yc[b] >= GY) continue;
                for (t = 0; t < 2; ++t)
                    if (xc[t] >= 0 && xc[t] < GX) v = hd_mg_prolong_term(v, a, b, t, u[a][b][xc[t]]);
            }
        }
        e[x] = v * hd_mg_medium_of(&kf, m[x]);
    }
    for (h = 0; h < 2; ++h) {
        float *dst = F->phi + hd__split_slot(gx, gy, h, y, z + c * gz);
        n = hd__cpu_half_len(gx, h);
        for (i = 0; i < n; ++i) dst[i] += e[2 * i + h];
    }
}

/* ---- the V-cycle: z = M r ------------------------------------------------------------------------ */
static int hd__mg_rows(const hd__cpu_level *L, int channels) { return L->dims[1] * L->dims[2] * channels; }

static void hd__cpu_mg_cycle(hd__backend *be, int l)
{
    struct hd__cpu_mg *mg = be->mg;
    hd__cpu_level *L = &mg->lv[l];
    be->grid = &L->g;
    if (l == mg->levels - 1) {
        hd__cpu_red_black(be, HD__MG_COARSEST_SWEEPS, 0);
        hd__cpu_red_black(be, HD__MG_COARSEST_SWEEPS, 1);
        return;
    }
    hd__cpu_red_black(be, HD__MG_PRE, 0);
    hd__cpu_parallel(be, hd__cpu_residual_row, hd__mg_rows(L, mg->channels));
    mg->cur = l + 1;
    hd__cpu_parallel(be, hd__cpu_mg_restrict_row, hd__mg_rows(&mg->lv[l + 1], mg->channels));
    hd__cpu_mg_cycle(be, l + 1);
    mg->cur = l + 1;
    hd__cpu_parallel(be, hd__cpu_mg_prolong_row, hd__mg_rows(L, mg->channels));
    be->grid = &L->g;
    hd__cpu_red_black(be, HD__MG_POST, 1);
}

/* ---- the fine residual in double ------------------------------------------------------------------ */
/* f - A (phi + lo) of row r (= (c * gz + z) * gy + y) of be->grid into out[], evaluated in double
   by the shared hd_mg_res_f64 (hd_k_multigrid.h says why), stored as float; lo (the iterate's low
   part) only on the fine grid of the iterate (mg->fineg). Literal in-grid flags, boundary and RGB
   for the interior voxels, so each variant's loop has no test. */
static HD__CPU_FLATTEN void hd__cpu_mg_residual_f64_into(const hd__backend *be, int r, float *out)
{
    hd__kctx k = *be->grid->k;
    const hd__kctx *K = &k;
    int lo = be->mg && be->grid == &be->mg->fineg;
    int gx = K->p->gdims.x, gy = K->p->gdims.y, gz = K->p->gdims.z, x;
    int y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    int surface = (K->p->counts.z & HD_FLAG_SURFACE_BOUNDARY) != 0, rgb = (K->p->counts.z & HD_FLAG_RGB_SCATTERING) != 0;
    int edge = gx < 3 || y == 0 || y == gy - 1 || z == 0 || z == gz - 1;
    k.f16 = 0;
    k.phi2 = lo ? be->mg->lo : NULL;
    for (x = 0; x < gx; ++x) {
        int ix = x > 0 && x < gx - 1;
        if (edge || !ix)
            out[x] = (float)hd_mg_res_f64(K, x, y, z, c, surface, rgb, lo, x > 0, x < gx - 1, y > 0, y < gy - 1, z > 0, z < gz - 1);
        else if (lo)
            out[x] = (float)(surface ? (rgb ? hd_mg_res_f64(K, x, y, z, c, 1, 1, 1, 1, 1, 1, 1, 1, 1)
                                            : hd_mg_res_f64(K, x, y, z, c, 1, 0, 1, 1, 1, 1, 1, 1, 1))
                                     : (rgb ? hd_mg_res_f64(K, x, y, z, c, 0, 1, 1, 1, 1, 1, 1, 1, 1)
                                            : hd_mg_res_f64(K, x, y, z, c, 0, 0, 1, 1, 1, 1, 1, 1, 1)));
        else
            out[x] = (float)(surface ? (rgb ? hd_mg_res_f64(K, x, y, z, c, 1, 1, 0, 1, 1, 1, 1, 1, 1)
                                            : hd_mg_res_f64(K, x, y, z, c, 1, 0, 0, 1, 1, 1, 1, 1, 1))
                                     : (rgb ? hd_mg_res_f64(K, x, y, z, c, 0, 1, 0, 1, 1, 1, 1, 1, 1)
                                            : hd_mg_res_f64(K, x, y, z, c, 0, 0, 0, 1, 1, 1, 1, 1, 1)));
    }
}

/* Row r (= zz * gy + y) of a grid in the colour layout of dims d: from row[] (x in order) into
   buf's slots, one unit-stride colour half-row at a time. */
static void hd__cpu_mg_scatter_row(const hd__kparams *d, float *buf, int r, const float *row)
{
    int gx = d->gdims.x, gy = d->gdims.y, h, i, n;
    for (h = 0; h < 2; ++h) {
        float *dst = buf + hd__split_slot(gx, gy, h, r % gy, r / gy);
        n = hd__cpu_half_len(gx, h);
        for (i = 0; i < n; ++i) dst[i] = row[2 * i + h];
    }
}

/* The residual of row r of be->grid into its res. */
static void hd__cpu_mg_residual_f64_row(hd__backend *be, int r)
{
    float out[HD__CPU_ROW_MAX];
    hd__cpu_mg_residual_f64_into(be, r, out);
    hd__cpu_mg_scatter_row(be->grid->k->p, be->grid->res, r, out);
}

/* ---- conjugate gradients' passes over the fine rows --------------------------------------------- */
/* <a, b> of row r of level 0 (hd_mg_dot_row's terms, hd_mg_dot_term: in double, x in order) on
   the two rows loaded once (loads by coordinates are gathers in the colour layout). */
static double hd__cpu_mg_dot(const hd__backend *be, int r, const float *a, const float *b)
{
    const int *d = be->mg->lv[0].dims;
    float ra[HD__CPU_ROW_MAX], rb[HD__CPU_ROW_MAX];
    double s = 0.0;
    int x;
    hd__cpu_mg_load_row(a, d[0], d[1], r % d[1], r / d[1], ra);
    hd__cpu_mg_load_row(b, d[0], d[1], r % d[1], r / d[1], rb);
    for (x = 0; x < d[0]; ++x) s = hd_mg_dot_term(s, ra[x], rb[x]);
    return s;
}

/* The half-row of x parity h of fine row r (= zz * gy + y) of the colour layout: its first slot,
   and its length in *n. The element-wise passes below walk a row as its two halves (every voxel
   once, the padding slot never). */
static size_t hd__cpu_mg_half(const hd__backend *be, int r, int h, int *n)
{
    const int *d = be->mg->lv[0].dims;
    *n = hd__cpu_half_len(d[0], h);
    return hd__split_slot(d[0], d[1], h, r % d[1], r / d[1]);
}

/* dot_a[r] = <r, z> of row r. */
static void hd__cpu_mg_rz_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    mg->dot_a[r] = hd__cpu_mg_dot(be, r, mg->lv[0].rhs, mg->lv[0].phi);
}

/* p = z + beta p, then z = 0 (the next V-cycle's start, and A p's zero right-hand side). */
static void hd__cpu_mg_dir_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int i, h, n;
    float beta = mg->beta;
    for (h = 0; h < 2; ++h) {
        size_t o = hd__cpu_mg_half(be, r, h, &n);
        float *z = mg->lv[0].phi + o, *p = mg->p + o;
        for (i = 0; i < n; ++i) {
            p[i] = hd_mg_dir_of(z[i], p[i], beta);
            z[i] = 0.0f;
        }
    }
}

/* q = A p (minus the residual of p with a zero right-hand side, in double: p is smooth, A p
   much smaller than den p, and the float kernel's cancellation made alpha wrong once the
   residual neared 1e-4) into level 0's res;
   dot_a[r] = <p, q>, dot_b[r] = <r, p>. */
static void hd__cpu_mg_op_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int x, gx = mg->lv[0].dims[0];
    float q[HD__CPU_ROW_MAX];
    hd__cpu_mg_residual_f64_into(be, r, q);
    for (x = 0; x < gx; ++x) q[x] = -q[x];
    hd__cpu_mg_scatter_row(&mg->lv[0].kp, mg->lv[0].res, r, q);
    mg->dot_a[r] = hd__cpu_mg_dot(be, r, mg->p, mg->lv[0].res);
    mg->dot_b[r] = hd__cpu_mg_dot(be, r, mg->lv[0].rhs, mg->p);
}

/* phi + lo += alpha p in double (hd_mg_update_of): phi is the sum rounded to float, lo the rest. */
static void hd__cpu_mg_update_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int i, h, n;
    double alpha = mg->alpha;
    for (h = 0; h < 2; ++h) {
        size_t o = hd__cpu_mg_half(be, r, h, &n);
        float *phi = be->phi + o, *lo = mg->lo + o;
        const float *p = mg->p + o;
        for (i = 0; i < n; ++i) phi[i] = hd_mg_update_of(phi[i], &lo[i], p[i], alpha);
    }
}

/* Empty voxels of the surface boundary, colour mg->colour, of row r: phi = the extrapolation the
   sweeps store there (hd_diffuse_extrapolate, read by the projection), lo = -phi, so CG's iterate
   phi + lo stays exactly 0 on those identity rows (hd_mg_res_f64's -(phi + lo); z and so p are 0
   there, the V-cycle's rows being identity rows too). */
static HD__CPU_FLATTEN void hd__cpu_mg_extrap_row(hd__backend *be, int r)
{
    struct hd__cpu_mg *mg = be->mg;
    int gx = mg->lv[0].dims[0], gy = mg->lv[0].dims[1], gz = mg->lv[0].dims[2], x;
    int y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    float v = 0.0f;
    for (x = (y + z + mg->colour) & 1; x < gx; x += 2)
        if (hd_diffuse_extrapolate(&be->k, x, y, z, c, &v)) {
            size_t s = hd__split_slot(gx, gy, x, y, z + c * gz);
            be->phi[s] = v;
            mg->lo[s] = -v;
        }
}

/* Rebuilds the levels if the grid changed, refreshes every level's parameters and restricts
   sigma_t when it changed; returns whether CG must restart. */
static hd_result hd__cpu_mg_prepare(hd__ctx *ctx, int *restart)
{
    hd__backend *be = ctx->be;
    struct hd__cpu_mg *mg = be->mg;
    hd_result r;
    int l, stale;
    if (mg && (mg->channels != ctx->channels || mg->sig_channels != ctx->sig_channels ||
               memcmp(mg->fine, ctx->gdims, sizeof mg->fine) != 0))
        hd__cpu_mg_free(ctx);
    if (!be->mg && (r = hd__cpu_mg_alloc(ctx)) != HD_SUCCESS) return r;
    mg = be->mg;
    for (l = 0; l < mg->levels; ++l) hd__cpu_mg_params(ctx, l);
    hd__cpu_mg_fine_params(ctx);
    if (hd__mg_cg_begin(&mg->cg, ctx, be->sig_gen, restart, &stale)) {
        for (mg->cur = 1; mg->cur < mg->levels; ++mg->cur)
            hd__cpu_parallel(be, hd__cpu_mg_sig_row, mg->lv[mg->cur].dims[1] * mg->lv[mg->cur].dims[2] * mg->sig_channels);
        hd__mg_cg_restricted(&mg->cg, ctx, be->sig_gen);
    }
    if (stale) memset(mg->lo, 0, hd__mg_slots(mg->fine, mg->channels) * sizeof(float));
    return HD_SUCCESS;
}

/* One step of multigrid-preconditioned conjugate gradients on the illumination grid (the
   solver's "sweep"; the top of this file lists its passes). */
static hd_result hd__be_multigrid(hd__ctx *ctx)
{
    hd__backend *be = ctx->be;
    struct hd__cpu_mg *mg;
    int restart, rows;
    double t0, rz, pq, rp;
    hd_result r;
    if ((r = hd__cpu_mg_prepare(ctx, &restart)) != HD_SUCCESS) return r;
    mg = be->mg;
    rows = hd__mg_rows(&mg->lv[0], mg->channels);
    be->grid = &mg->fineg; /* r = f - A phi */
    hd__cpu_parallel(be, hd__cpu_mg_residual_f64_row, rows);
    t0 = hd__now(); /* z = M r (z is 0 here: zeroed by the last step's direction pass, or new) */
    hd__cpu_mg_cycle(be, 0);
    mg->vcycle_seconds += hd__now() - t0;
    hd__cpu_parallel(be, hd__cpu_mg_rz_row, rows);
    rz = hd__mg_row_sum(mg->dot_a, (size_t)rows);
    mg->beta = hd__mg_cg_beta(&mg->cg, rz, restart);
    hd__cpu_parallel(be, hd__cpu_mg_dir_row, rows);
    be->grid = &mg->opg; /* q = A p */
    hd__cpu_parallel(be, hd__cpu_mg_op_row, rows);
    pq = hd__mg_row_sum(mg->dot_a, (size_t)rows);
    rp = hd__mg_row_sum(mg->dot_b, (size_t)rows);
    be->grid = NULL;
    mg->cg.have_dir = 1;
    /* pq > 0 unless p = 0 (phi already solves the equation to the last bit): then no step */
    if (pq > 0.0) {
        mg->alpha = rp / pq;
        hd__cpu_parallel(be, hd__cpu_mg_update_row, rows);
    }
    if (ctx->kp.counts.z & HD_FLAG_SURFACE_BOUNDARY) /* one colour at a time: it reads the other */
        for (mg->colour = 0; mg->colour < 2; ++mg->colour) hd__cpu_parallel(be, hd__cpu_mg_extrap_row, rows);
    return HD_SUCCESS;
}
#define HD__BE_HAS_MULTIGRID 1
