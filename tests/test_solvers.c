/* test_solvers.c - the diffusion solvers against each other through the public API on the CPU
   backend: geometric multigrid (HD_SOLVER_MULTIGRID) reaches the single-level red-black
   solution. (Its speed is a benchmark figure: bench/hdbench_multigrid.c.) */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

#define SN 24
static uint8_t solver_blob[SN * SN * SN];

/* A sphere of radius 10 voxels with a denser core, in a 24^3 grid of air, one light along -z. */
static void solver_desc(hd_desc *d)
{
    int x, y, z;
    for (z = 0; z < SN; ++z)
        for (y = 0; y < SN; ++y)
            for (x = 0; x < SN; ++x) {
                float dx = x - 11.5f, dy = y - 11.5f, dz = z - 11.5f;
                float r = sqrtf(dx * dx + dy * dy + dz * dz);
                solver_blob[(z * SN + y) * SN + x] = (uint8_t)(r < 10 ? (r < 5 ? 255 : 128) : 0);
            }
    memset(d, 0, sizeof *d);
    /* the paper's grid and boundary (hd_params_preset): these cases are not about the defaults */
    d->params.illumination_downsample = 1;
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = SN;
    d->volume.data = solver_blob;
    d->transfer_function.count = 3;
    d->camera.width = d->camera.height = 16;
    d->params.extinction = 40.0f;
}

/* Multigrid converges to the single-level solver's phi: on a blob (24^3, coarse levels 12, 6, 3), with both boundaries and with RGB scattering, red-black at 2000 sweeps per
   iteration and multigrid at 40 V-cycles agree to 1e-4 of max phi after 2 iterations (the same
   seed, so the same E), the air's voxels too (surface boundary: the Marshak extrapolation). Its levels are counted in method_bytes. Measured: see the printed lines. */
static void test_multigrid_matches(void)
{
    static const float tf[12] = {1, 0.5f, 0.25f, 0, 1, 0.5f, 0.25f, 0.3f, 1, 0.5f, 0.25f, 1};
    int variant;
    for (variant = 0; variant < 3; ++variant) {
        hd_desc d;
        hd_context rb, mg;
        hd_stats srb, smg;
        size_t n = (size_t)SN * SN * SN * 3, i, nread;
        float *a = (float *)malloc(n * 4), *b = (float *)malloc(n * 4);
        double maxd = 0, maxv = 0, maxe = 0;
        int extrapolated = 0;
        solver_desc(&d);
        d.transfer_function.rgba = tf;
        d.params.diffusion_boundary = variant == 1 ? HD_BOUNDARY_SURFACE : HD_BOUNDARY_BOX;
        d.params.rgb_scattering = variant == 2;
        d.params.diffusion_sweeps = 2000;
        CHECK(hd_create(&d, &rb) == HD_SUCCESS);
        d.params.solver = HD_SOLVER_MULTIGRID;
        d.params.diffusion_sweeps = 40;
        CHECK(hd_create(&d, &mg) == HD_SUCCESS);
        CHECK(hd_iterate(rb, 2) == HD_SUCCESS && hd_iterate(mg, 2) == HD_SUCCESS);
        CHECK(hd_get_stats(rb, &srb) == HD_SUCCESS && hd_get_stats(mg, &smg) == HD_SUCCESS);
        nread = (size_t)SN * SN * SN * (size_t)srb.illumination_channels;
        CHECK(hd_read_illumination(rb, HD_ILLUMINATION_SCATTERED, a, nread) == HD_SUCCESS);
        CHECK(hd_read_illumination(mg, HD_ILLUMINATION_SCATTERED, b, nread) == HD_SUCCESS);
        for (i = 0; i < nread; ++i) {
            if (fabs((double)a[i] - b[i]) > maxd) maxd = fabs((double)a[i] - b[i]);
            if (a[i] > maxv) maxv = a[i];
            if (solver_blob[i % ((size_t)SN * SN * SN)] == 0) { /* air */
                if (fabs((double)a[i] - b[i]) > maxe) maxe = fabs((double)a[i] - b[i]);
                extrapolated += a[i] > 0.0f;
            }
        }
        printf("  multigrid vs red-black (%s%s): max |diff| %.2e of max phi %.3e (air: %.2e, %d voxels lit); bytes %zu vs %zu\n",
               variant == 1 ? "surface" : "box", variant == 2 ? ", rgb" : "", maxd, maxv, maxe, extrapolated,
               smg.method_bytes, srb.method_bytes);
        CHECK(maxv > 0 && maxd < 1e-4 * maxv);
        /* surface boundary: the air next to the sphere holds the Marshak extrapolation (both solvers) */
        if (variant == 1) CHECK(extrapolated > 0 && maxe < 1e-4 * maxv);
        CHECK(smg.method_bytes > srb.method_bytes);
        hd_destroy(rb);
        hd_destroy(mg);
        free(a); free(b);
    }
}

/* Multigrid-preconditioned CG reaches a bound in a few steps: on the blob (box, surface, RGB),
   one HD iteration with k solver steps from phi = 0, against red-black after 3000 sweeps (the
   same seed, so the same E). A CG whose direction, step length or preconditioner were wrong
   (e.g. a nonsymmetric V-cycle, a beta of the wrong sign) would stall far above it; k = 0..12
   are printed. Measured (max |phi_k - phi_ref| / max phi_ref): surface 7.6e-7 after 5 steps
   (red-black's own distance from the solution, about 1.5e-6, after that); box 8.8e-4 after 4
   steps and 1.9e-6 after 12, RGB 9.0e-4 and 2.1e-6, since the box boundary's transfers skip
   air (hdk_mg_medium; before: box 2.1e-1 and 9.1e-3, RGB 2.3e-1 and 1.4e-2, as trilinear
   interpolation put part of the tissue's correction into air, whose conductance is about 1e4
   times tissue's). Bounds: surface 1e-5 after 6 steps; box and RGB 1e-2 after 4 steps and 2e-5
   after 12 (the unmasked transfers fail both). */
static void test_multigrid_pcg_bound(void)
{
    static const float tf[12] = {1, 0.5f, 0.25f, 0, 1, 0.5f, 0.25f, 0.3f, 1, 0.5f, 0.25f, 1};
    int variant, k;
    for (variant = 0; variant < 3; ++variant) {
        hd_desc d;
        hd_context ref;
        hd_stats st;
        size_t n = (size_t)SN * SN * SN * 3, i, nread;
        float *a = (float *)malloc(n * 4), *b = (float *)malloc(n * 4);
        double maxv = 0, err[13];
        solver_desc(&d);
        d.transfer_function.rgba = tf;
        d.params.diffusion_boundary = variant == 1 ? HD_BOUNDARY_SURFACE : HD_BOUNDARY_BOX;
        d.params.rgb_scattering = variant == 2;
        d.params.diffusion_sweeps = 3000;
        CHECK(hd_create(&d, &ref) == HD_SUCCESS);
        CHECK(hd_iterate(ref, 1) == HD_SUCCESS && hd_get_stats(ref, &st) == HD_SUCCESS);
        nread = (size_t)SN * SN * SN * (size_t)st.illumination_channels;
        CHECK(hd_read_illumination(ref, HD_ILLUMINATION_SCATTERED, a, nread) == HD_SUCCESS);
        for (i = 0; i < nread; ++i)
            if (a[i] > maxv) maxv = a[i];
        hd_destroy(ref);
        d.params.solver = HD_SOLVER_MULTIGRID;
        printf("  multigrid PCG (%s%s), max |phi_k - phi_ref| / max phi_ref:", variant == 1 ? "surface" : "box",
               variant == 2 ? ", rgb" : "");
        for (k = 0; k <= 12; ++k) {
            hd_context mg;
            double e = 0;
            d.params.diffusion_sweeps = k;
            d.params.disable_diffusion = k == 0; /* 0 sweeps means the default: no solve instead */
            CHECK(hd_create(&d, &mg) == HD_SUCCESS);
            CHECK(hd_iterate(mg, 1) == HD_SUCCESS);
            CHECK(hd_read_illumination(mg, HD_ILLUMINATION_SCATTERED, b, nread) == HD_SUCCESS);
            for (i = 0; i < nread; ++i)
                if (fabs((double)a[i] - b[i]) > e) e = fabs((double)a[i] - b[i]);
            err[k] = e / maxv;
            printf(" %.1e", err[k]);
            hd_destroy(mg);
        }
        printf("\n");
        CHECK(maxv > 0 && err[0] > 0.5);
        if (variant == 1) CHECK_MSG(err[6] <= 1e-5, "surface: after 6 steps %.2e of max phi", err[6]);
        else CHECK_MSG(err[4] <= 1e-2 && err[12] <= 2e-5, "box: after 4 and 12 steps %.2e, %.2e", err[4], err[12]);
        free(a); free(b);
    }
}

/* The multigrid solver's result is the same bits for 1, 2 and 3 threads (its dot products are
   summed per row, then in row order): 17 rows (a block's remainder), box, surface and RGB, two
   iterations of 5 steps (the second warm-started, with the CG restarted on its new E). */
static void test_multigrid_threads(void)
{
    static const float tf[12] = {1, 0.5f, 0.25f, 0, 1, 0.5f, 0.25f, 0.3f, 1, 0.5f, 0.25f, 1};
    int variant, t;
    for (variant = 0; variant < 3; ++variant) {
        size_t n = (size_t)SN * 17 * SN * 3;
        float *a = (float *)malloc(n * 4), *b = (float *)malloc(n * 4);
        for (t = 1; t <= 3; ++t) {
            hd_desc d;
            hd_context ctx;
            solver_desc(&d);
            d.transfer_function.rgba = tf;
            d.volume.dims[1] = 17;
            d.params.diffusion_boundary = variant == 1 ? HD_BOUNDARY_SURFACE : HD_BOUNDARY_BOX;
            d.params.rgb_scattering = variant == 2;
            d.params.solver = HD_SOLVER_MULTIGRID;
            d.params.diffusion_sweeps = 5;
            d.threads = t;
            CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
            CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
            memset(t == 1 ? a : b, 0, n * 4);
            CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, t == 1 ? a : b,
                                       (size_t)SN * 17 * SN * (variant == 2 ? 3 : 1)) == HD_SUCCESS);
            if (t > 1) CHECK_MSG(memcmp(a, b, n * 4) == 0, "variant %d: 1 and %d threads differ", variant, t);
            hd_destroy(ctx);
        }
        free(a); free(b);
    }
}

/* The CPU's block schedule (16-row blocks, a last-row pass) for row counts around a block's
   size, 16 * k + 1 included (its remainder joins the previous block): red-black and Jacobi give
   the same bits on 1 and 2 threads; under `make tsan` this also shows no thread reads a row
   another writes. */
static void test_block_schedule(void)
{
    static const int gys[4] = {15, 16, 17, 33};
    int k, solver;
    for (k = 0; k < 4; ++k)
        for (solver = HD_SOLVER_RED_BLACK; solver <= HD_SOLVER_JACOBI; ++solver) {
            hd_desc d;
            hd_context one, two;
            size_t n;
            float *a, *b;
            solver_desc(&d);
            d.transfer_function.count = 0; /* the default grey ramp */
            d.volume.dims[1] = gys[k];
            d.volume.dims[2] = 9;
            d.params.solver = (hd_solver)solver;
            d.params.diffusion_sweeps = 6;
            n = (size_t)SN * gys[k] * 9;
            a = (float *)malloc(n * 4);
            b = (float *)malloc(n * 4);
            d.threads = 1;
            CHECK(hd_create(&d, &one) == HD_SUCCESS);
            d.threads = 2;
            CHECK(hd_create(&d, &two) == HD_SUCCESS);
            CHECK(hd_iterate(one, 2) == HD_SUCCESS && hd_iterate(two, 2) == HD_SUCCESS);
            CHECK(hd_read_illumination(one, HD_ILLUMINATION_SCATTERED, a, n) == HD_SUCCESS);
            CHECK(hd_read_illumination(two, HD_ILLUMINATION_SCATTERED, b, n) == HD_SUCCESS);
            CHECK_MSG(memcmp(a, b, n * 4) == 0, "%d rows, solver %d: 1 and 2 threads differ", gys[k], solver);
            hd_destroy(one);
            hd_destroy(two);
            free(a);
            free(b);
        }
}

const hd_test_case hd_tests_solvers[] = {
    {"solvers_multigrid_matches_red_black", test_multigrid_matches},
    {"solvers_block_schedule_threads", test_block_schedule},
    {"solvers_multigrid_pcg_bound", test_multigrid_pcg_bound},
    {"solvers_multigrid_threads_bitwise", test_multigrid_threads},
};
const int hd_tests_solvers_count = (int)(sizeof hd_tests_solvers / sizeof hd_tests_solvers[0]);
