/* hdbench_multigrid - the multigrid solver against single-level sweeps, in one run: on the head
   CT (256x256x108, full-resolution illumination grid, one light, the direct light of 4 HD iterations as the
   source), the time single-level red-black sweeps and HD_SOLVER_MULTIGRID's steps (conjugate
   gradients preconditioned by a V-cycle, docs/DESIGN-MULTIGRID.md) take to bring the
   diffusion's relative residual |f - A phi| / |f| from phi = 0 below 1e-4, for the box and the
   surface boundary. Times: wall clock of the solver calls only (residual checks excluded) and
   process CPU seconds / threads (robust to other load on the machine). Red-black stops at
   --cap seconds (default 300) if it has not converged: its ratio is then a lower bound.
   --f64 evaluates the residual in double (bench/hd_residual_f64.c): float32's rounding floors
   the float residual near 1e-3 in soft tissue. With --f64 each printed line also gives the
   residual with the kernel's own float coefficients summed in double (the solver's residual),
   and at the end the residual of phi moved by one float32 ulp per voxel: the floor float32
   storage of phi sets (rounding to nearest is about 0.29 ulp rms).
   Usage: hdbench_multigrid [data/head.nrrd] [--cap SECONDS] [--tol T] [--downsample N]
                            [--print-every STEPS] [--surface-only] [--f64]
                            [--tissue-error REF_STEPS [--tissue-ref FILE]]
   Figures, not a test: nothing here passes or fails. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "examples/hd_tf.h"
#include "hd_residual_f64.h"
#include <time.h>

static const float mg_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f, 0.0f,       /* -1024, -512: air */
    0.93f, 0.73f, 0.62f, 0.02f, 0.93f, 0.73f, 0.62f, 0.05f,   /* 0, 512: soft tissue */
    1.0f, 0.98f, 0.9f, 0.5f,    1.0f, 1.0f, 1.0f, 1.0f,       /* 1024, 1536: bone */
    1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f};

typedef struct mg_run { int steps; double wall, cpu, res; } mg_run;

static double cpu_seconds(void) { return (double)clock() / CLOCKS_PER_SEC; }

/* A copy of `slices` z-slices (gz per channel) of a buffer in the CPU backend's colour layout
   (hd_prelude_c.h's hd__split_slot) in x-fastest order; NULL if out of memory. */
static float *x_fastest(const hd__ctx *ctx, const float *buf, int slices)
{
    int gx = ctx->vw.gdims[0], gy = ctx->vw.gdims[1], x, y, zz;
    float *out = (float *)malloc((size_t)gx * gy * slices * sizeof(float)), *o = out;
    if (!out) return NULL;
    for (zz = 0; zz < slices; ++zz)
        for (y = 0; y < gy; ++y)
            for (x = 0; x < gx; ++x) *o++ = buf[hd__split_slot(gx, gy, x, y, zz)];
    return out;
}

/* The relative residual of the context's fine grid evaluated in double (hd_residual_f64.c, on
   x-fastest copies): below float32's rounding floor. -1 when it cannot be computed. */
static double residual_f64(hd_context h)
{
    hd__ctx *ctx = hd__lookup(h);
    size_t gvox;
    float *sig, *E, *phi;
    double r = -1.0;
    if (!ctx || !ctx->vw.be->sig || !ctx->vw.be->E || !ctx->vw.be->phi) return -1.0;
    gvox = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2];
    sig = x_fastest(ctx, ctx->vw.be->sig, ctx->vw.gdims[2] * ctx->vw.sig_channels);
    E = x_fastest(ctx, ctx->vw.be->E, ctx->vw.gdims[2] * ctx->vw.channels);
    phi = x_fastest(ctx, ctx->vw.be->phi, ctx->vw.gdims[2] * ctx->vw.channels);
    if (sig && E && phi) r = hdb_residual_f64(&ctx->vw.kp, sig, gvox * (size_t)ctx->vw.sig_channels, E, phi);
    free(sig); free(E); free(phi);
    return r;
}

/* The relative residual of the equation the library solves, with the kernel's own float
   coefficients (source, sigma_a, face weights), the sums in double (hd__cpu_mg_residual_f64_into,
   the multigrid solver's residual): residual_f64 recomputes the coefficients themselves in
   double, a different operator by float32 rounding. iterate: of the multigrid solver's own
   iterate phi + lo instead of phi. -1 when it cannot be computed. */
static double residual_kernel_f64(hd_context h, int iterate)
{
    hd__ctx *ctx = hd__lookup(h);
    hd__cpu_grid g;
    int rows, r, x, gx;
    float *row;
    double r2 = 0.0, b2 = 0.0;
    if (!ctx || !ctx->vw.be->phi) return -1.0;
    gx = ctx->vw.gdims[0];
    rows = ctx->vw.gdims[1] * ctx->vw.gdims[2] * ctx->vw.channels;
    if (!(row = (float *)malloc((size_t)gx * sizeof(float)))) return -1.0;
    if (iterate && !ctx->vw.be->mg) { free(row); return -1.0; }
    g.k = &ctx->vw.be->k;
    g.res = NULL;
    ctx->vw.be->grid = iterate ? &ctx->vw.be->mg->fineg : &g; /* the fine grid's residual reads phi + lo */
    for (r = 0; r < rows; ++r) {
        int y = r % ctx->vw.gdims[1], z = (r / ctx->vw.gdims[1]) % ctx->vw.gdims[2], c = r / (ctx->vw.gdims[1] * ctx->vw.gdims[2]);
        hd__cpu_mg_residual_f64_into(ctx->vw.be, r, row);
        for (x = 0; x < gx; ++x) {
            float rhs;
            (void)hdk_diffuse_residual(&ctx->vw.be->k, x, y, z, c, &rhs);
            r2 += (double)row[x] * row[x];
            b2 += (double)rhs * rhs;
        }
    }
    ctx->vw.be->grid = NULL;
    free(row);
    return b2 > 0.0 ? sqrt(r2 / b2) : 0.0;
}

/* Runs the context's solver `batch` steps at a time until the residual is below tol or cap
   wall seconds have passed; prints the residual every `print_every` steps. */
static int f64; /* --f64: the residual evaluated in double (residual_f64) */

/* --tissue-error STEPS: the error that matters under the box boundary, where the residual does
   not (air's diagonal, about 1e4 tissue's, makes one float32 ulp of phi a residual of order 1):
   |phi - phi_ref| / |phi_ref| in L2 over the medium voxels only (sigma' at least half the
   floor, the surface boundary's "empty" test), phi_ref the multigrid solver's phi after STEPS
   steps (its fixed point is red-black's: solvers_multigrid_matches_red_black). Printed at
   1, 2, 4, 8, ... batches instead of every print_every. --tissue-ref FILE: the reference is read
   from FILE.box / FILE.surface if it exists, else written there (to compare two builds against
   one reference). */
static float *tissue_ref;
static unsigned char *tissue_mask;

/* The medium voxels of a context's grid (channel 0's sigma_t) into tissue_mask. */
static void tissue_mask_of(hd_context h)
{
    hd__ctx *ctx = hd__lookup(h);
    size_t n = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2], i;
    float empty_below = 0.5f * ctx->vw.kp.grid.w / (1.0f - ctx->vw.kp.medium.y * ctx->vw.kp.medium.z);
    float *sig = x_fastest(ctx, ctx->vw.be->sig, ctx->vw.gdims[2]);
    tissue_mask = (unsigned char *)malloc(n);
    for (i = 0; i < n; ++i) tissue_mask[i] = sig[i] >= empty_below;
    free(sig);
}

/* The relative L2 error of phi (channel 0) over the medium voxels against tissue_ref. */
static double tissue_error(hd_context h)
{
    hd__ctx *ctx = hd__lookup(h);
    size_t n = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2], i;
    double e2 = 0.0, r2 = 0.0;
    for (i = 0; i < n; ++i)
        if (tissue_mask[i]) {
            int gx = ctx->vw.gdims[0], gy = ctx->vw.gdims[1];
            double d = (double)ctx->vw.be->phi[hd__split_slot(gx, gy, (int)(i % gx), (int)(i / gx % gy), (int)(i / gx / gy))] -
                       tissue_ref[i];
            e2 += d * d;
            r2 += (double)tissue_ref[i] * tissue_ref[i];
        }
    return r2 > 0.0 ? sqrt(e2 / r2) : -1.0;
}

static mg_run solve(hd_context ctx, int batch, double tol, double cap, int threads, int print_every, const char *name)
{
    mg_run r;
    double res = 1.0;
    r.steps = 0; r.wall = 0.0; r.cpu = 0.0;
    while (!(res < tol) && r.wall < cap && res == res) {
        double w0 = hd__now(), c0 = cpu_seconds();
        if (hd__test_diffuse(ctx, batch) != HD_SUCCESS) { fprintf(stderr, "hd__test_diffuse failed\n"); exit(1); }
        r.wall += hd__now() - w0;
        r.cpu += (cpu_seconds() - c0) / threads;
        r.steps += batch;
        hd__test_residual(ctx, &res);
        if (f64) res = residual_f64(ctx);
        if (tissue_ref ? ((r.steps / batch) & (r.steps / batch - 1)) == 0 : r.steps % (batch * print_every) == 0 || res < tol) {
            hd__ctx *c = hd__lookup(ctx);
            printf("  %s: %6d steps, %8.2f s wall, %8.2f s cpu/thread, ", name, r.steps, r.wall, r.cpu);
            if (tissue_ref) printf("tissue error %.3e, ", tissue_error(ctx));
            printf("residual %.3e (kernel coefficients %.3e", res, f64 ? residual_kernel_f64(ctx, 0) : res);
            if (f64 && c && c->vw.be->mg && c->vw.params.solver == HD_SOLVER_MULTIGRID)
                printf("; the solver's iterate phi + lo %.3e", residual_kernel_f64(ctx, 1));
            printf(")\n");
        }
        fflush(stdout);
    }
    r.res = res;
    return r;
}

/* The double residual of phi with every voxel moved by one float32 ulp, up or down by a fixed
   hash of its index (then restored): the floor float32 storage of phi puts under any solver
   (rounding to nearest moves a voxel by up to half an ulp, about 0.29 ulp rms; this is 1 ulp). */
static double residual_ulp_f64(hd_context h)
{
    hd__ctx *ctx = hd__lookup(h);
    size_t n, i;
    float *phi, *keep;
    double res;
    if (!ctx || !ctx->vw.be->phi) return -1.0;
    n = ctx->vw.be->illum_slots; /* the padding slots too: residual_f64 reads only the voxels */
    phi = ctx->vw.be->phi;
    if (!(keep = (float *)malloc(n * sizeof(float)))) return -1.0;
    memcpy(keep, phi, n * sizeof(float));
    for (i = 0; i < n; ++i) {
        uint32_t k = (uint32_t)i * 2654435761u;
        phi[i] = nextafterf(phi[i], (k >> 16) & 1 ? HUGE_VALF : -HUGE_VALF);
    }
    res = residual_f64(h);
    memcpy(phi, keep, n * sizeof(float));
    free(keep);
    return res;
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd", *ref_file = NULL;
    double cap = 300.0, tol = 1e-4;
    int i, ref_steps = 0, boundary, threads = (int)sysconf(_SC_NPROCESSORS_ONLN), downsample = 1, print_every = 20, first = HD_BOUNDARY_BOX;
    hd_volume_file vf;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--cap") == 0 && i + 1 < argc) cap = atof(argv[++i]);
        else if (strcmp(argv[i], "--tol") == 0 && i + 1 < argc) tol = atof(argv[++i]);
        else if (strcmp(argv[i], "--downsample") == 0 && i + 1 < argc) downsample = atoi(argv[++i]);
        else if (strcmp(argv[i], "--print-every") == 0 && i + 1 < argc) print_every = atoi(argv[++i]);
        else if (strcmp(argv[i], "--surface-only") == 0) first = HD_BOUNDARY_SURFACE;
        else if (strcmp(argv[i], "--f64") == 0) f64 = 1;
        else if (strcmp(argv[i], "--tissue-error") == 0 && i + 1 < argc) ref_steps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--tissue-ref") == 0 && i + 1 < argc) ref_file = argv[++i];
        else path = argv[i];
    }
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_multigrid: cannot load %s (run `make data` first)\n", path);
        return 2;
    }
    printf("hdbench_multigrid: %s %dx%dx%d, %d threads, tolerance %.0e, red-black cap %.0f s, residual in %s\n", path,
           vf.desc.dims[0], vf.desc.dims[1], vf.desc.dims[2], threads, tol, cap, f64 ? "double" : "float");
    for (boundary = first; boundary <= HD_BOUNDARY_SURFACE; ++boundary) {
        hd_desc d;
        hd_context rb, mg;
        hd_stats s_rb, s_mg;
        mg_run a, b;
        memset(&d, 0, sizeof d);
        hdx_desc_volume_tf(&d, &vf.desc, -1024.0f, 3071.0f, mg_tf, (int)(sizeof mg_tf / sizeof mg_tf[0] / 4));
        d.camera.width = d.camera.height = 16;
        d.params.diffusion_boundary = (hd_boundary)boundary;
        d.params.illumination_downsample = downsample;
        d.logger.func = hd_log_stderr;
        if (hd_create(&d, &rb) != HD_SUCCESS) return 1;
        d.params.solver = HD_SOLVER_MULTIGRID;
        if (hd_create(&d, &mg) != HD_SUCCESS) return 1;
        if (hd__test_direct(rb, 4) != HD_SUCCESS || hd__test_direct(mg, 4) != HD_SUCCESS) return 1;
        printf("\nboundary %s:\n", boundary == HD_BOUNDARY_BOX ? "box" : "surface");
        if (ref_steps > 0) { /* the reference: ref_steps multigrid steps from the same E */
            hd_context ref;
            hd__ctx *rc;
            double rres = -1.0;
            size_t n;
            if (hd_create(&d, &ref) != HD_SUCCESS || hd__test_direct(ref, 4) != HD_SUCCESS ||
                hd__test_diffuse(ref, ref_steps) != HD_SUCCESS)
                return 1;
            rc = hd__lookup(ref);
            n = (size_t)rc->vw.gdims[0] * rc->vw.gdims[1] * rc->vw.gdims[2];
            free(tissue_ref);
            free(tissue_mask);
            tissue_ref = x_fastest(rc, rc->vw.be->phi, rc->vw.gdims[2]); /* channel 0 */
            tissue_mask_of(ref);
            if (ref_file) { /* --tissue-ref FILE.box / FILE.surface: one reference for two builds */
                char fn[1024];
                FILE *f;
                snprintf(fn, sizeof fn, "%s.%s", ref_file, boundary == HD_BOUNDARY_BOX ? "box" : "surface");
                if ((f = fopen(fn, "rb")) != NULL) {
                    if (fread(tissue_ref, sizeof(float), n, f) != n) return 1;
                    printf("reference read from %s (this run's own: tissue error %.3e against it)\n", fn,
                           tissue_error(ref));
                } else if ((f = fopen(fn, "wb")) != NULL) {
                    if (fwrite(tissue_ref, sizeof(float), n, f) != n) return 1;
                    printf("reference written to %s\n", fn);
                }
                if (f) fclose(f);
            }
            hd__test_residual(ref, &rres);
            printf("reference: %d multigrid steps (float residual %.3e); tolerance off, every solver runs --cap s\n",
                   ref_steps, rres);
            tol = 0.0;
            hd_destroy(ref);
        }
        b = solve(mg, 1, tol, cap, threads, print_every, "multigrid PCG steps");
        /* the double residual costs about a sweep's time x 20: checked every 250 sweeps */
        a = solve(rb, f64 ? 250 : 25, tol, cap, threads, print_every, "red-black sweeps  ");
        if (f64)
            printf("phi moved by 1 ulp per voxel: residual (double) red-black %.2e, multigrid %.2e\n", residual_ulp_f64(rb),
                   residual_ulp_f64(mg));
        hd_get_stats(rb, &s_rb);
        hd_get_stats(mg, &s_mg);
        printf("| boundary | solver | steps | wall s | cpu s / thread | residual |\n|---|---|---|---|---|---|\n");
        printf("| %s | red-black | %d sweeps | %.2f | %.2f | %.2e |\n", boundary == HD_BOUNDARY_SURFACE ? "surface" : "box", a.steps, a.wall, a.cpu, a.res);
        printf("| %s | multigrid | %d PCG steps | %.2f | %.2f | %.2e |\n", boundary == HD_BOUNDARY_SURFACE ? "surface" : "box", b.steps, b.wall, b.cpu, b.res);
        {
            hd__ctx *m = hd__lookup(mg);
            double vc = m && m->vw.be->mg ? m->mg.vcycle_seconds : 0.0;
            printf("per step (wall): red-black sweep %.2f ms, PCG step %.2f ms, of which its V-cycle %.2f ms\n",
                   1e3 * a.wall / a.steps, 1e3 * b.wall / b.steps, 1e3 * vc / b.steps);
        }
        if (b.res < tol)
            printf("multigrid is %s%.1fx faster in wall time, %s%.1fx in CPU time (target >= 10x)\n",
                   a.res >= tol ? ">= " : "", a.wall / b.wall, a.res >= tol ? ">= " : "", a.cpu / b.cpu);
        else
            printf("neither reached %.0e within %.0f s: at equal time multigrid's residual is %.0fx lower\n", tol, cap,
                   a.res / b.res);
        if (f64) /* the solver's own iterate, phi + lo (src/hd_multigrid.h): no float32 storage floor */
            printf("the multigrid solver's own iterate phi + lo (about 48 bits; phi is its float32 rounding): "
                   "residual %.2e\n", residual_kernel_f64(mg, 1));
        printf("the solver's vectors and levels add %.2f bytes per data voxel\n",
               ((double)s_mg.method_bytes - (double)s_rb.method_bytes) / ((double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2]));
        hd_destroy(rb);
        hd_destroy(mg);
    }
    hd_volume_free(&vf);
    return 0;
}
