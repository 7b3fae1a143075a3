/* hd_multigrid.h - HD_SOLVER_MULTIGRID's step and its run state (when conjugate gradients
   restart, when the coarse levels' sigma_t must be restricted again, beta), written once over the backend's per-level
   primitives (src/hd_backend.h): conjugate gradients on the diffusion equation A phi = f,
   preconditioned by one symmetric multigrid V-cycle (docs/METHOD.md; docs/DESIGN-RENDER.md has
   the choices and their measurements). Every backend runs the same passes in the same order, and
   the dot products' row sums are added here in row order, so a backend's result has the CPU's
   bits wherever its kernels' float operations do. */
#ifndef HD_MULTIGRID_H
#define HD_MULTIGRID_H

#define HD__MG_PRE 2             /* pre-smoothing: red-black sweeps */
#define HD__MG_POST 2            /* post-smoothing: black-red sweeps (the adjoint order) */
#define HD__MG_COARSEST_SWEEPS 8 /* the coarsest level: red-black, then as many black-red */

/* A new state for a backend whose sigma_t generation is sig_gen: the first step restricts. */
HD__MAYBE_UNUSED static void hd__mg_cg_init(hd__mg_cg *cg, unsigned sig_gen)
{
    memset(cg, 0, sizeof *cg);
    cg->sig_gen = sig_gen - 1u;
}

/* The start of a step, for a backend at sigma_t generation sig_gen. *restart: CG restarts (a new
   HD iteration brought a new E, or A changed); *stale: besides, the iterate's low part belongs to
   another phi (A changed, or E and phi were reset: ctx->light_gen moved on; it is at most half an
   ulp of phi, so a stale one would only perturb the start) and the backend zeroes it. Returns
   whether the coarse sigma_t must be restricted again (sigma_t or the boundary changed): the
   backend does so, then calls hd__mg_cg_restricted. */
HD__MAYBE_UNUSED static int hd__mg_cg_begin(hd__mg_cg *cg, const hd__ctx *ctx, unsigned sig_gen, int *restart, int *stale)
{
    hd__kparams key;
    int resig = cg->sig_gen != sig_gen || cg->sig_surface != (ctx->vw.kp.counts.z & HD_FLAG_SURFACE_BOUNDARY);
    memset(&key, 0, sizeof key);
    key.gdims = ctx->vw.kp.gdims;
    key.counts.z = ctx->vw.kp.counts.z;
    key.medium = ctx->vw.kp.medium;
    key.grid = ctx->vw.kp.grid;
    key.gridh = ctx->vw.kp.gridh;
    *stale = resig || memcmp(&key, &cg->akey, sizeof key) != 0 || ctx->iterations < cg->iteration ||
             cg->light_gen != ctx->light_gen;
    *restart = *stale || !cg->have_dir || cg->iteration != ctx->iterations;
    cg->akey = key;
    cg->iteration = ctx->iterations;
    cg->light_gen = ctx->light_gen;
    return resig;
}

/* The coarse sigma_t now match generation sig_gen and the context's boundary. */
HD__MAYBE_UNUSED static void hd__mg_cg_restricted(hd__mg_cg *cg, const hd__ctx *ctx, unsigned sig_gen)
{
    cg->sig_gen = sig_gen;
    cg->sig_surface = ctx->vw.kp.counts.z & HD_FLAG_SURFACE_BOUNDARY;
}

/* beta = <r, z> / the previous <r, z>, 0 at a restart (or without a positive previous one, or
   where the ratio is not a finite float: the run restarts rather than carry an overflow). */
HD__MAYBE_UNUSED static float hd__mg_cg_beta(hd__mg_cg *cg, double rz, int restart)
{
    double q = restart || !(cg->rz > 0.0) ? 0.0 : rz / cg->rz;
    float beta = q >= 0.0 && q <= 3.4e38 ? (float)q : 0.0f;
    cg->rz = rz;
    return beta;
}


/* z = M r from level l down: smoothing, residual, restriction, the coarser cycle, prolongation,
   smoothing in the adjoint order, so M is symmetric, as CG needs; z is zero on entry. */
static hd_result hd__mg_vcycle(hd__ctx *ctx, int l, int levels)
{
    hd_result r;
    if (l == levels - 1) {
        if ((r = hd__be_mg_smooth(&ctx->vw, l, HD__MG_COARSEST_SWEEPS, 0)) != HD_SUCCESS) return r;
        return hd__be_mg_smooth(&ctx->vw, l, HD__MG_COARSEST_SWEEPS, 1);
    }
    if ((r = hd__be_mg_smooth(&ctx->vw, l, HD__MG_PRE, 0)) != HD_SUCCESS || (r = hd__be_mg_residual(&ctx->vw, l)) != HD_SUCCESS ||
        (r = hd__be_mg_restrict(&ctx->vw, l)) != HD_SUCCESS || (r = hd__mg_vcycle(ctx, l + 1, levels)) != HD_SUCCESS ||
        (r = hd__be_mg_prolong(&ctx->vw, l)) != HD_SUCCESS)
        return r;
    return hd__be_mg_smooth(&ctx->vw, l, HD__MG_POST, 1);
}

/* The step's passes between hd__be_mg_begin and hd__be_mg_end. */
static hd_result hd__mg_step_passes(hd__ctx *ctx, int fresh)
{
    hd__mg_cg *cg = &ctx->mg;
    size_t rows = (size_t)ctx->vw.gdims[1] * ctx->vw.gdims[2] * (size_t)ctx->vw.channels;
    int levels = hd__mg_levels(ctx->vw.gdims), restart, stale, l, colour;
    double t0, rz, pq, rp;
    const double *a = NULL, *b = NULL;
    hd_result r;
    if (fresh) hd__mg_cg_init(cg, ctx->sig_gen);
    if (hd__mg_cg_begin(cg, ctx, ctx->sig_gen, &restart, &stale)) {
        for (l = 1; l < levels; ++l)
            if ((r = hd__be_mg_coarsen(&ctx->vw, l)) != HD_SUCCESS) return r;
        hd__mg_cg_restricted(cg, ctx, ctx->sig_gen);
    }
    if (stale && (r = hd__be_mg_zero_lo(&ctx->vw)) != HD_SUCCESS) return r;
    /* r = f - A (phi + lo); z = M r (z is 0 here: zeroed by the last direction pass, or new) */
    if ((r = hd__be_mg_residual_f64(&ctx->vw)) != HD_SUCCESS) return r;
    t0 = hd__now();
    if ((r = hd__mg_vcycle(ctx, 0, levels)) != HD_SUCCESS) return r;
    cg->vcycle_seconds += hd__now() - t0;
    /* beta = <r, z> / the previous <r, z>; p = z + beta p */
    if ((r = hd__be_mg_dot_rz(&ctx->vw)) != HD_SUCCESS || (r = hd__be_mg_row_sums(&ctx->vw, 1, &a, &b)) != HD_SUCCESS) return r;
    rz = hd__mg_row_sum(a, rows);
    if ((r = hd__be_mg_direction(&ctx->vw, hd__mg_cg_beta(cg, rz, restart))) != HD_SUCCESS) return r;
    /* q = A p; alpha = <r, p> / <p, q> */
    if ((r = hd__be_mg_apply(&ctx->vw)) != HD_SUCCESS || (r = hd__be_mg_row_sums(&ctx->vw, 2, &a, &b)) != HD_SUCCESS) return r;
    pq = hd__mg_row_sum(a, rows);
    rp = hd__mg_row_sum(b, rows);
    cg->have_dir = 1;
    /* pq > 0 unless p = 0 (phi already solves the equation to the last bit): then no step */
    if (pq > 0.0 && (r = hd__be_mg_update(&ctx->vw, rp / pq)) != HD_SUCCESS) return r;
    /* surface boundary: the empty voxels' extrapolation, one colour at a time (it reads the other) */
    if (ctx->vw.kp.counts.z & HD_FLAG_SURFACE_BOUNDARY)
        for (colour = 0; colour < 2; ++colour)
            if ((r = hd__be_mg_extrapolate(&ctx->vw, colour)) != HD_SUCCESS) return r;
    return HD_SUCCESS;
}

/* One solver step (params.diffusion_sweeps counts them): r, z = M r, beta, p, q = A p, alpha,
   the update and the surface extrapolation. CG restarts (beta = 0) at each new HD iteration (a
   new E) and whenever A changes (hd__mg_cg_begin). */
static hd_result hd__mg_step(hd__ctx *ctx)
{
    int fresh = 0;
    hd_result r = hd__be_mg_begin(&ctx->vw, &fresh);
    if (r != HD_SUCCESS) return r;
    return hd__be_mg_end(&ctx->vw, hd__mg_step_passes(ctx, fresh));
}

#endif
