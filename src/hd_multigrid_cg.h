/* hd_multigrid_cg.h - the host-side bookkeeping of HD_SOLVER_MULTIGRID that is the same on every
   backend with the solver (hd_cpu_multigrid.h, hd_opencl.h, hd_gl.h, hd_vulkan.h):
   when conjugate gradients restart, when the coarse levels' sigma_t must be restricted again, beta,
   and the row-order sum of the dot products' row sums. The passes are each backend's; their
   per-voxel math is backends/kernels/hd_k_multigrid.h. The design is at the top of
   hd_cpu_multigrid.h. */
#ifndef HD_MULTIGRID_CG_H
#define HD_MULTIGRID_CG_H

typedef struct hd__mg_cg {
    unsigned sig_gen;        /* the backend's sig_gen the coarse sigma_t were restricted from */
    int sig_surface;         /* ... and the boundary they were restricted for */
    uint64_t iteration;      /* the HD iteration (ctx->iterations) the CG run belongs to */
    hd__kparams akey;        /* the parameters A depends on, at the last step (restart on change) */
    int have_dir;            /* the backend's p holds a direction of the current CG run */
    double rz;               /* <r, z> of the previous step (beta's denominator) */
} hd__mg_cg;

/* A new state for a backend whose sigma_t generation is sig_gen: the first step restricts. */
HD__MAYBE_UNUSED static void hd__mg_cg_init(hd__mg_cg *cg, unsigned sig_gen)
{
    memset(cg, 0, sizeof *cg);
    cg->sig_gen = sig_gen - 1u;
}

/* The start of a step, for a backend at sigma_t generation sig_gen. *restart: CG restarts (a new
   HD iteration brought a new E, or A changed); *stale: besides, the iterate's low part belongs to
   another phi (A changed, or phi was reset: the iteration count went back; it is at most half an
   ulp of phi, so a stale one would only perturb the start) and the backend zeroes it. Returns
   whether the coarse sigma_t must be restricted again (sigma_t or the boundary changed): the
   backend does so, then calls hd__mg_cg_restricted. */
HD__MAYBE_UNUSED static int hd__mg_cg_begin(hd__mg_cg *cg, const hd__ctx *ctx, unsigned sig_gen, int *restart, int *stale)
{
    hd__kparams key;
    int resig = cg->sig_gen != sig_gen || cg->sig_surface != (ctx->kp.counts.z & HD_FLAG_SURFACE_BOUNDARY);
    memset(&key, 0, sizeof key);
    key.gdims = ctx->kp.gdims;
    key.counts.z = ctx->kp.counts.z;
    key.medium = ctx->kp.medium;
    key.grid = ctx->kp.grid;
    key.gridh = ctx->kp.gridh;
    *stale = resig || memcmp(&key, &cg->akey, sizeof key) != 0 || ctx->iterations < cg->iteration;
    *restart = *stale || !cg->have_dir || cg->iteration != ctx->iterations;
    cg->akey = key;
    cg->iteration = ctx->iterations;
    return resig;
}

/* The coarse sigma_t now match generation sig_gen and the context's boundary. */
HD__MAYBE_UNUSED static void hd__mg_cg_restricted(hd__mg_cg *cg, const hd__ctx *ctx, unsigned sig_gen)
{
    cg->sig_gen = sig_gen;
    cg->sig_surface = ctx->kp.counts.z & HD_FLAG_SURFACE_BOUNDARY;
}

/* beta = <r, z> / the previous <r, z>, 0 at a restart (or without a positive previous one). */
HD__MAYBE_UNUSED static float hd__mg_cg_beta(hd__mg_cg *cg, double rz, int restart)
{
    float beta = restart || !(cg->rz > 0.0) ? 0.0f : (float)(rz / cg->rz);
    cg->rz = rz;
    return beta;
}

/* The sum of the first `rows` row sums in row order: the same bits for any thread count and on
   any backend. */
HD__MAYBE_UNUSED static double hd__mg_row_sum(const double *d, size_t rows)
{
    double s = 0.0;
    size_t r;
    for (r = 0; r < rows; ++r) s += d[r];
    return s;
}

#endif
