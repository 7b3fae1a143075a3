/* hdbench - prints the figures the core's targets are measured by, in one run:
     - memory bandwidth (STREAM triad a = b + s c, all threads), the roofline for the stencil;
     - the diffusion sweep's time and bytes/s as a share of the triad (box and surface boundary);
     - HD iterations/s and per-stage times on the head CT at 512^2 and 1024^2, 1 and 3 lights;
     - bytes per voxel of HD's state for 1, 3 and 16 lights.
   Usage: hdbench [data/head.nrrd] [--quick] [--sweep] [--defaults ROUNDS]   (make data fetches
   the head CT; --sweep: the triad and the sweeps only; --defaults: only the paper's settings
   against the library's defaults at 512^2, ROUNDS interleaved rounds)
   Figures, not a test: nothing here passes or fails. */
#define HYBRIDDIFF_IMPLEMENTATION
#ifndef HYBRIDDIFF_BACKEND_OPENCL
#define HYBRIDDIFF_BACKEND_CPU
#endif
#include "hybriddiff.h"
#include "examples/hd_tf.h"

#include "hdbench_triad.h"
#include "hd_bench_median.h"

/* The plain constant-coefficient 7-point Jacobi stencil the 70 % target was set with:
   b = (sum of a's 6 neighbours) / 7 over the grid's interior, zero boundary, z-slabs per
   thread. 8 B/voxel (a in, b out): the same convention as the triad. */
typedef struct stencil_job { const float *a; float *b; int g[3], z0, z1; } stencil_job;

static void *stencil_worker(void *arg)
{
    stencil_job *j = (stencil_job *)arg;
    size_t gx = (size_t)j->g[0], sxy = gx * (size_t)j->g[1];
    int y, z;
    for (z = j->z0 > 1 ? j->z0 : 1; z < j->z1 && z < j->g[2] - 1; ++z)
        for (y = 1; y < j->g[1] - 1; ++y) {
            const float *a = j->a + z * sxy + (size_t)y * gx;
            float *b = j->b + z * sxy + (size_t)y * gx;
            size_t x;
            for (x = 1; x < gx - 1; ++x)
                b[x] = (a[x - 1] + a[x + 1] + a[x - gx] + a[x + gx] + a[x - sxy] + a[x + sxy]) * (1.0f / 7.0f);
        }
    return NULL;
}

/* Seconds per sweep of the plain stencil on a g[0] x g[1] x g[2] grid, best of 5 runs of 20. */
static double stencil_seconds(const int *g, int nthreads)
{
    size_t n = (size_t)g[0] * g[1] * g[2], i;
    float *a = (float *)calloc(n, sizeof(float)), *b = (float *)calloc(n, sizeof(float));
    pthread_t th[64];
    stencil_job jobs[64];
    double best = 1e30;
    int rep, it, t;
    for (i = 0; i < n; ++i) a[i] = (float)(i % 97) * 0.01f;
    for (rep = 0; rep < 5; ++rep) {
        double t0 = hd__now(), dt;
        for (it = 0; it < 20; ++it) {
            for (t = 0; t < nthreads; ++t) {
                jobs[t].a = it & 1 ? b : a; jobs[t].b = it & 1 ? a : b;
                memcpy(jobs[t].g, g, sizeof jobs[t].g);
                jobs[t].z0 = g[2] * t / nthreads; jobs[t].z1 = g[2] * (t + 1) / nthreads;
                pthread_create(&th[t], NULL, stencil_worker, &jobs[t]);
            }
            for (t = 0; t < nthreads; ++t) pthread_join(th[t], NULL);
        }
        dt = (hd__now() - t0) / 20.0;
        if (dt < best) best = dt;
    }
    free(a); free(b);
    return best;
}

static hd_light bench_lights[3];

static void setup_lights(void)
{
    memset(bench_lights, 0, sizeof bench_lights);
    bench_lights[0].direction[0] = -0.5f; bench_lights[0].direction[1] = -1.0f; bench_lights[0].direction[2] = -0.6f;
    bench_lights[1].direction[0] = 1.0f; bench_lights[1].direction[1] = -0.3f; bench_lights[1].direction[2] = 0.2f;
    bench_lights[2].direction[0] = 0.2f; bench_lights[2].direction[1] = 0.8f; bench_lights[2].direction[2] = -1.0f;
}

/* A CT transfer function over HU -1024..3071: skin faint, bone dense. */
static const float bench_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,        /* -1024 air */
    0.0f, 0.0f, 0.0f, 0.0f,        /* -512 */
    0.93f, 0.73f, 0.62f, 0.02f,    /* 0 soft tissue */
    0.93f, 0.73f, 0.62f, 0.05f,    /* 512 */
    1.0f, 0.98f, 0.9f, 0.5f,       /* 1024 bone */
    1.0f, 1.0f, 1.0f, 1.0f,        /* 1536 */
    1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};

static void fill_desc(hd_desc *d, const hd_volume_file *vf, int size, int lights)
{
    memset(d, 0, sizeof *d);
    hdx_desc_volume_tf(d, &vf->desc, -1024.0f, 3071.0f, bench_tf, (int)(sizeof bench_tf / sizeof bench_tf[0] / 4));
    d->lights = bench_lights;
    d->light_count = lights;
    d->camera.eye[1] = 2.3f; d->camera.eye[2] = 0.3f; d->camera.up[2] = 1.0f;
    d->camera.fov_y = 30.0f;
    d->camera.width = d->camera.height = size;
    d->logger.func = hd_log_stderr;
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* --defaults: HD at 512^2 with 1 light, the paper's settings (hd_params_preset) against the
   library's defaults, in one process. After a warm-up iteration each, every round times one
   hd_refine(ctx, 1) (light only) and one hd_iterate(ctx, 1) (light and a projection frame) of
   each context in turn, so the load falls on both alike; medians over the rounds, by the wall
   clock and by process CPU time / threads. */
#define BENCH_ROUNDS_MAX 64
static int bench_defaults(const hd_volume_file *vf, int rounds, int nthreads)
{
    static const char *const name[2] = {"paper (grid /1, box, red-black 4)", "defaults"};
    double t[2][4][BENCH_ROUNDS_MAX], med[2][4];
    hd_context ctx[2];
    hd_desc d;
    hd_stats st;
    int k, r, m;
    if (rounds > BENCH_ROUNDS_MAX) rounds = BENCH_ROUNDS_MAX;
    for (k = 0; k < 2; ++k) {
        fill_desc(&d, vf, 512, 1);
        if (k == 0 && hd_params_preset(HD_PRESET_PAPER, &d.params, &d.logger) != HD_SUCCESS) return 1;
        if (hd_create(&d, &ctx[k]) != HD_SUCCESS || hd_iterate(ctx[k], 1) != HD_SUCCESS) return 1;
    }
    for (r = 0; r < rounds; ++r)
        for (m = 0; m < 2; ++m)
            for (k = 0; k < 2; ++k) {
                double w = hd__now(), c = cpu_seconds();
                if ((m ? hd_iterate(ctx[k], 1) : hd_refine(ctx[k], 1)) != HD_SUCCESS) return 1;
                t[k][2 * m][r] = hd__now() - w;
                t[k][2 * m + 1][r] = (cpu_seconds() - c) / nthreads;
            }
    printf("\nHD at 512^2, 1 light, %d rounds interleaved: median ms per call (wall / CPU per thread)\n", rounds);
    printf("| settings | illumination grid | bytes/voxel | hd_refine wall | CPU | hd_iterate wall | CPU | it/s (hd_iterate, wall) |\n");
    printf("|---|---|---|---|---|---|---|---|\n");
    for (k = 0; k < 2; ++k) {
        for (m = 0; m < 4; ++m) med[k][m] = hdb_median(t[k][m], rounds);
        hd_get_stats(ctx[k], &st);
        printf("| %s | %dx%dx%d | %.2f | %.1f | %.1f | %.1f | %.1f | %.3f |\n", name[k], st.illumination_dims[0],
               st.illumination_dims[1], st.illumination_dims[2],
               (double)st.method_bytes / ((double)vf->desc.dims[0] * vf->desc.dims[1] * vf->desc.dims[2]),
               med[k][0] * 1e3, med[k][1] * 1e3, med[k][2] * 1e3, med[k][3] * 1e3, 1.0 / med[k][2]);
        hd_destroy(ctx[k]);
    }
    printf("| speed-up | | | %.2fx | %.2fx | %.2fx | %.2fx | |\n", med[0][0] / med[1][0], med[0][1] / med[1][1],
           med[0][2] / med[1][2], med[0][3] / med[1][3]);
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd";
    int quick = 0, sweep_only = 0, defaults_rounds = 0, i, sizes[2] = {512, 1024}, si, li, nthreads;
    hd_volume_file vf;
    hd_result r;
    double triad, hd_rate[2][2] = {{0, 0}, {0, 0}};
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) quick = 1;
        else if (strcmp(argv[i], "--sweep") == 0) sweep_only = 1;
        else if (strcmp(argv[i], "--defaults") == 0 && i + 1 < argc) defaults_rounds = atoi(argv[++i]);
        else path = argv[i];
    }
    r = hd_volume_load_nrrd(path, &vf, NULL);
    if (r != HD_SUCCESS) {
        fprintf(stderr, "hdbench: cannot load %s: %s (run `make data` first)\n", path, hd_result_string(r));
        return 2;
    }
    setup_lights();
    nthreads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    printf("hdbench: backend %s, %d threads, volume %s %dx%dx%d\n", hd_backend_name(), nthreads, path,
           vf.desc.dims[0], vf.desc.dims[1], vf.desc.dims[2]);
    if (defaults_rounds > 0) {
        int rc = bench_defaults(&vf, defaults_rounds, nthreads);
        hd_volume_free(&vf);
        return rc;
    }
    triad = hdbench_triad_bandwidth(nthreads);
    printf("STREAM triad: %.2f GB/s\n", triad * 1e-9);

    /* the plain stencil on the head's grid, for scale */
    {
        double t = stencil_seconds(vf.desc.dims, nthreads), nvox = (double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2];
        printf("plain 7-point stencil (constant coefficients, 8 B/voxel): %.2f ms = %.0f sweeps/s, %.2f GB/s = %.0f%% of the triad\n",
               t * 1e3, 1.0 / t, 8.0 * nvox / t * 1e-9, 100.0 * 8.0 * nvox / t / triad);
    }

    /* the diffusion sweep, timed through the per-stage clock: the best of `rounds` iterations of
       `sweeps` sweeps each, as the stencil's best of 5 (a mean over one long run took every load
       spike of the shared machine in with it) */
    {
        hd_desc d;
        hd_context ctx;
        hd_stats s0, s1;
        int solver, boundary, sweeps = 10, rounds = quick ? 2 : 10, k;
        for (boundary = HD_BOUNDARY_BOX; boundary <= HD_BOUNDARY_SURFACE; ++boundary)
        for (solver = HD_SOLVER_RED_BLACK; solver <= HD_SOLVER_JACOBI; ++solver) {
            double t, nvox, bytes;
            fill_desc(&d, &vf, 64, 1);
            d.params.illumination_downsample = 1; /* the sweep on the head's own grid */
            d.params.solver = (hd_solver)solver;
            d.params.diffusion_boundary = (hd_boundary)boundary;
            d.params.diffusion_sweeps = sweeps;
            if (hd_create(&d, &ctx) != HD_SUCCESS) return 1;
            hd_iterate(ctx, 1); /* warm-up: first touch of the pages */
            for (t = 1e30, k = 0; k < rounds; ++k) {
                hd_get_stats(ctx, &s0);
                hd_iterate(ctx, 1);
                hd_get_stats(ctx, &s1);
                if ((s1.seconds_diffusion - s0.seconds_diffusion) / sweeps < t)
                    t = (s1.seconds_diffusion - s0.seconds_diffusion) / sweeps;
            }
            nvox = (double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2];
            /* sigma, E, phi in and phi (red-black) or phi2 (Jacobi) out: 16 B/voxel. Red-black
               relaxes both colours in one walk through z (hd_cpu.h), so it streams the grid once
               per sweep (the colour-by-colour schedule before it streamed it twice, and this
               bench counted 2 x 16 B then) */
            bytes = nvox * 16.0;
            printf("diffusion sweep (%s, %s boundary): %.2f ms = %.0f sweeps/s, %.2f GB/s = %.0f%% of the triad\n",
                   solver == HD_SOLVER_RED_BLACK ? "red-black" : "Jacobi",
                   boundary == HD_BOUNDARY_BOX ? "box" : "surface", t * 1e3, 1.0 / t, bytes / t * 1e-9,
                   100.0 * bytes / t / triad);
            hd_destroy(ctx);
        }
    }
    if (sweep_only) { hd_volume_free(&vf); return 0; }

    /* HD iterations per second and per-stage times */
    printf("\n| image | lights | HD it/s | direct ms | diffusion ms | projection ms | bytes/voxel |\n");
    printf("|---|---|---|---|---|---|---|\n");
    for (si = 0; si < 2; ++si) {
        for (li = 0; li < 2; ++li) {
            int lights = li == 0 ? 1 : 3, iters = quick ? 2 : 5;
            hd_desc d;
            hd_context ctx;
            hd_stats s0, s1;
            double t0, dt, n;
            fill_desc(&d, &vf, sizes[si], lights);
            if (hd_create(&d, &ctx) != HD_SUCCESS) return 1;
            hd_iterate(ctx, 1);
            hd_get_stats(ctx, &s0);
            t0 = hd__now();
            hd_iterate(ctx, iters);
            dt = hd__now() - t0;
            hd_get_stats(ctx, &s1);
            n = (double)iters;
            hd_rate[si][li] = n / dt;
            printf("| %d^2 | %d | %.3f | %.1f | %.1f | %.1f | %.1f |\n", sizes[si], lights, n / dt,
                   (s1.seconds_direct - s0.seconds_direct) / n * 1e3, (s1.seconds_diffusion - s0.seconds_diffusion) / n * 1e3,
                   (s1.seconds_projection - s0.seconds_projection) / n * 1e3,
                   (double)s1.method_bytes / ((double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2]));
            hd_destroy(ctx);
        }
        printf("| %d^2 | 3 vs 1 | %.2fx | | | | |\n", sizes[si], hd_rate[si][1] / hd_rate[si][0]);
    }

    /* bytes per voxel against the light count */
    {
        hd_light many[16];
        hd_desc d;
        hd_context ctx;
        hd_stats s;
        int counts[3] = {1, 3, 16};
        memset(many, 0, sizeof many);
        for (i = 0; i < 16; ++i) { many[i].direction[0] = cosf((float)i); many[i].direction[1] = sinf((float)i); many[i].direction[2] = -1.0f; }
        printf("\nHD state per voxel:");
        for (i = 0; i < 3; ++i) {
            fill_desc(&d, &vf, 64, counts[i]);
            d.lights = many;
            if (hd_create(&d, &ctx) != HD_SUCCESS) return 1;
            hd_get_stats(ctx, &s);
            printf(" %d lights %.1f B;", counts[i],
                   (double)s.method_bytes / ((double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2]));
            hd_destroy(ctx);
        }
        printf("\n");
    }
    hd_volume_free(&vf);
    return 0;
}
