/* hdbench_rb_schedule - the CPU backend's red-black schedule measured against the one it replaced,
   in one process on the same row function (so the ratio, not the loaded machine, is the figure):
     - "one walk": the library's hd__cpu_red_black, both colours in one walk through z
       (backends/hd_cpu.h);
     - "colour by colour": the schedule before it (466e1a8), rebuilt here: per colour, every block
       of 16 rows but its last row, then the blocks' last rows; each plane streams twice a sweep;
     - the same rows relaxed over and over (48 rows, L2-resident): the row code's own rate, what
       a sweep would cost if the memory traffic were free;
     - N sweeps as one call hd__cpu_red_black(be, N, 0) (walks of several sweeps, temporal
       blocking) against N calls of one sweep, N = 2 and 4, walks of up to 2 and of up to 4 sweeps.
   Interleaved rounds from the same phi, best of each; the phi of both schedules is compared bit
   for bit. Head CT, one light, box and surface boundary. Both schedules run the library's current
   row code (since the colour layout, hd_prelude_c.h: unit-stride half-rows), so the ratio is the
   schedule's alone; the row code before it is measured by building this file at an older commit.
   Usage: hdbench_rb_schedule [data/head.nrrd] [threads (default 2)]
   Figures, not a test. */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"

#include <stdio.h>
#include <string.h>
#include <time.h>

#define OLD_ROWS 16
static int old_pass; /* 0: the blocks' rows but the last, 1: their last rows */

static int old_blocks(const hd__backend *be)
{
    int gy = be->grid->k->p->gdims.y, nb = (gy + OLD_ROWS - 1) / OLD_ROWS;
    return nb > 1 && gy - (nb - 1) * OLD_ROWS == 1 ? nb - 1 : nb;
}

static void old_block(hd__backend *be, int r)
{
    int gy = be->grid->k->p->gdims.y, gz = be->grid->k->p->gdims.z, nb = old_blocks(be);
    int b = r % nb, c = r / nb, y0 = b * OLD_ROWS, y1 = b == nb - 1 ? gy : y0 + OLD_ROWS, y, z;
    if (old_pass == 1) y0 = y1 - 1;
    else --y1;
    for (z = 0; z < gz; ++z)
        for (y = y0; y < y1; ++y) hd__cpu_diffuse_row_at(be, y, z, c, be->parity);
}

static void old_sweep(hd__backend *be)
{
    int items = old_blocks(be) * be->grid->k->p->gdims.w;
    be->jacobi = 0;
    for (be->parity = 0; be->parity < 2; ++be->parity)
        for (old_pass = 0; old_pass < 2; ++old_pass) hd__cpu_parallel(be, old_block, items);
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static unsigned long long phi_hash(const float *phi, size_t n)
{
    unsigned long long h = 1469598103934665603ull;
    size_t i;
    for (i = 0; i < n; ++i) {
        unsigned u;
        memcpy(&u, phi + i, sizeof u);
        h = (h ^ u) * 1099511628211ull;
    }
    return h;
}

static const float bench_tf[] = {0.0f, 0.0f, 0.0f, 0.0f,    0.0f, 0.0f, 0.0f, 0.0f,    0.93f, 0.73f, 0.62f, 0.02f,
                                 0.93f, 0.73f, 0.62f, 0.05f, 1.0f, 0.98f, 0.9f, 0.5f,   1.0f, 1.0f, 1.0f, 1.0f};

/* One timed run of `sweeps` sweeps: variant 0 or 1 of an A/B pair. */
typedef void (*ab_run)(hd__backend *be, int variant, int sweeps);

/* Best seconds per sweep of each variant of `run` (reps runs of `sweeps` sweeps per round, 12
   interleaved rounds, each from the same phi) into best[], and into *same whether both left the
   same phi bit for bit after the first round. Leaves phi as it found it; keeps be->grid set (the
   caller's) until the end. */
static void interleave(hd__ctx *ctx, ab_run run, int reps, int sweeps, double best[2], int *same)
{
    hd__backend *be = ctx->vw.be;
    size_t n = be->illum_slots; /* phi in the colour layout, padding slots included */
    float *start = (float *)malloc(n * sizeof(float));
    unsigned long long hash[2] = {0, 0};
    int r, i, s;
    if (!start) { fprintf(stderr, "hdbench_rb_schedule: out of memory\n"); exit(1); }
    memcpy(start, be->phi, n * sizeof(float));
    best[0] = best[1] = 1e30;
    for (r = 0; r < 12; ++r)
        for (i = 0; i < 2; ++i) {
            double t;
            memcpy(be->phi, start, n * sizeof(float));
            t = now();
            for (s = 0; s < reps; ++s) run(be, i, sweeps);
            t = (now() - t) / (reps * sweeps);
            if (t < best[i]) best[i] = t;
            if (r == 0) hash[i] = phi_hash(be->phi, n);
        }
    *same = hash[0] == hash[1];
    memcpy(be->phi, start, n * sizeof(float));
    free(start);
}

/* Points the backend at the context's own grid (what hd__be_diffuse does for a sweep). */
static void use_fine_grid(hd__ctx *ctx, hd__cpu_grid *g)
{
    g->k = &ctx->vw.be->k;
    g->res = NULL;
    ctx->vw.be->grid = g;
    hd__fill_kparams(ctx);
}

/* Variant 0: the colour-by-colour schedule, 1: the library's one walk, `sweeps` sweeps each. */
static void run_schedules(hd__backend *be, int variant, int sweeps)
{
    int s;
    for (s = 0; s < sweeps; ++s) {
        if (variant) hd__cpu_red_black(be, 1, 0);
        else old_sweep(be);
    }
}

/* Variant 0: `sweeps` calls of one sweep, 1: one call of `sweeps` (walks of be->rb_walk_sweeps). */
static void run_walks(hd__backend *be, int variant, int sweeps)
{
    int k;
    if (variant) hd__cpu_red_black(be, sweeps, 0);
    else for (k = 0; k < sweeps; ++k) hd__cpu_red_black(be, 1, 0);
}

/* Seconds per sweep of each schedule (best of interleaved rounds), and the L2-resident rows' time
   per voxel update, on the context's grid from its current phi. */
static void measure(hd__ctx *ctx, double best[2], double *l2_update, int *same)
{
    hd__backend *be = ctx->vw.be;
    hd__cpu_grid g;
    int r, i, rep, y, z;
    use_fine_grid(ctx, &g);
    interleave(ctx, run_schedules, 1, 4, best, same);
    /* 48 rows in the middle of the head, both colours, 400 times: one thread, L2-resident */
    *l2_update = 1e30;
    for (r = 0; r < 5; ++r) {
        double t = now();
        for (rep = 0; rep < 400; ++rep)
            for (i = 0; i < 2; ++i)
                for (z = 50; z < 53; ++z)
                    for (y = 100; y < 116; ++y) hd__cpu_diffuse_row_at(be, y, z, 0, i);
        t = (now() - t) / (400.0 * 48 * be->k.p->gdims.x);
        if (t < *l2_update) *l2_update = t;
    }
    be->grid = NULL;
}

/* Seconds per sweep of N sweeps as N calls of one (best[0]) and as one call in walks of up to
   `walk` sweeps (best[1]), interleaved rounds from the same phi, best of each; *same: phi equal
   bit for bit after the first round. */
static void measure_walks(hd__ctx *ctx, int N, int walk, double best[2], int *same)
{
    hd__cpu_grid g;
    use_fine_grid(ctx, &g);
    ctx->vw.be->rb_walk_sweeps = walk;
    interleave(ctx, run_walks, 8 / N, N, best, same);
    ctx->vw.be->rb_walk_sweeps = HD__CPU_RB_WALK_SWEEPS;
    ctx->vw.be->grid = NULL;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "data/head.nrrd";
    int threads = argc > 2 ? atoi(argv[2]) : 2, boundary;
    hd_volume_file vf;
    hd_light light;
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_rb_schedule: cannot load %s (run `make data` first)\n", path);
        return 2;
    }
    memset(&light, 0, sizeof light);
    light.direction[0] = -0.5f; light.direction[1] = -1.0f; light.direction[2] = -0.6f;
    printf("hdbench_rb_schedule: %s %dx%dx%d, %d threads\n", path, vf.desc.dims[0], vf.desc.dims[1], vf.desc.dims[2],
           threads);
    for (boundary = HD_BOUNDARY_BOX; boundary <= HD_BOUNDARY_SURFACE; ++boundary) {
        hd_desc d;
        hd_context h;
        double best[2], l2, nvox = (double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2];
        int same;
        memset(&d, 0, sizeof d);
        d.volume = vf.desc;
        d.volume.value_range[0] = -1024.0f;
        d.volume.value_range[1] = 3071.0f;
        d.transfer_function.rgba = bench_tf;
        d.transfer_function.count = (int)(sizeof bench_tf / sizeof bench_tf[0] / 4);
        d.lights = &light;
        d.light_count = 1;
        d.camera.eye[1] = 2.3f; d.camera.up[2] = 1.0f; d.camera.fov_y = 30.0f;
        d.camera.width = d.camera.height = 64;
        d.params.diffusion_boundary = (hd_boundary)boundary;
        d.threads = threads;
        if (hd_create(&d, &h) != HD_SUCCESS || hd_iterate(h, 1) != HD_SUCCESS) return 1;
        {
            HD__GET_CTX(ctx, h);
            measure(ctx, best, &l2, &same);
        }
        printf("%s boundary: colour by colour %.2f ms, one walk %.2f ms per sweep (%.2fx, phi %s); "
               "%.2f ns per voxel update in a sweep x threads, %.2f ns with the rows L2-resident (one thread)\n",
               boundary == HD_BOUNDARY_BOX ? "box" : "surface", best[0] * 1e3, best[1] * 1e3, best[0] / best[1],
               same ? "bit-identical" : "DIFFERENT", best[1] / nvox * threads * 1e9, l2 * 1e9);
        {
            static const int walks[][2] = {{2, 2}, {4, 2}, {4, 4}};
            int w;
            for (w = 0; w < 3; ++w) {
                HD__GET_CTX(ctx, h);
                measure_walks(ctx, walks[w][0], walks[w][1], best, &same);
                printf("  %d sweeps: %d calls of one %.2f ms, one call (walks of up to %d) %.2f ms per sweep (%.2fx, phi %s); "
                       "%.2f ns per voxel update x threads\n",
                       walks[w][0], walks[w][0], best[0] * 1e3, walks[w][1], best[1] * 1e3, best[0] / best[1],
                       same ? "bit-identical" : "DIFFERENT", best[1] / nvox * threads * 1e9);
            }
        }
        hd_destroy(h);
    }
    hd_volume_free(&vf);
    return 0;
}
