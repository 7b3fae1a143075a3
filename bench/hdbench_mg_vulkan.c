/* hdbench_mg_vulkan - the time of one HD_SOLVER_MULTIGRID step (conjugate gradients preconditioned
   by a V-cycle) on the Vulkan backend against the CPU backend, in one process: the CPU reference
   and Vulkan are tests/conformance's two API tables (impl_cpu.c, impl_vk.c), each built in its
   own translation unit. Head CT (256x256x108), one light, the direct light of 4 HD iterations as
   the source (test hooks), box and surface boundary, illumination grid /1 and /2. Per case: one
   untimed step on each (allocations, pipelines), then interleaved rounds (CPU `--steps` steps,
   then Vulkan as many), wall time per step; medians over the rounds, and the ratio of the
   sums. Then phi of both after the same steps, rel L2 (the same algorithm in the same order,
   from direct light that agrees to the stochastic bound only).
   Usage: hdbench_mg_vulkan [data/head.nrrd] [--rounds N] [--steps N] [--downsample N]
   Figures, not a test: nothing here passes or fails. Run it under flock /tmp/hd-bench.lock. */
#include "tests/conformance/hd_api.h"
#include "examples/hd_tf.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "hd_bench_median.h"

static const float mg_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f, 0.0f,       /* -1024, -512: air */
    0.93f, 0.73f, 0.62f, 0.02f, 0.93f, 0.73f, 0.62f, 0.05f,   /* 0, 512: soft tissue */
    1.0f, 0.98f, 0.9f, 0.5f,    1.0f, 1.0f, 1.0f, 1.0f,       /* 1024, 1536: bone */
    1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f};

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* rel L2 of phi between the two contexts (n floats each). */
static double phi_rel_l2(hd_context cpu, hd_context vk, size_t n)
{
    float *a = (float *)malloc(n * sizeof(float)), *b = (float *)malloc(n * sizeof(float));
    double d2 = 0.0, r2 = 0.0;
    size_t i;
    if (!a || !b || hd_api_cpu.read_illumination(cpu, HD_ILLUMINATION_SCATTERED, a, n) != HD_SUCCESS ||
        hd_api_backend.read_illumination(vk, HD_ILLUMINATION_SCATTERED, b, n) != HD_SUCCESS) {
        free(a); free(b);
        return -1.0;
    }
    for (i = 0; i < n; ++i) {
        d2 += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
        r2 += (double)a[i] * a[i];
    }
    free(a); free(b);
    return r2 > 0.0 ? sqrt(d2 / r2) : 0.0;
}

#define MAX_ROUNDS 32

/* Warnings and errors only (the backends' info lines would interleave with the table). */
static void quiet_log(void *user, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    if (level != HD_LOG_INFO) hd_api_cpu.log_stderr(user, level, code, msg, file, line);
}

/* One case: returns 0 on success. */
static int run_case(const hd_volume_file *vf, int boundary, int downsample, int rounds, int steps)
{
    const hd_api *api[2] = {&hd_api_cpu, &hd_api_backend};
    hd_context h[2];
    hd_desc d;
    hd_stats st;
    double t[2][MAX_ROUNDS], sum[2] = {0.0, 0.0};
    int k, b;
    memset(&d, 0, sizeof d);
    hdx_desc_volume_tf(&d, &vf->desc, -1024.0f, 3071.0f, mg_tf, (int)(sizeof mg_tf / sizeof mg_tf[0] / 4));
    d.camera.width = d.camera.height = 16;
    d.params.solver = HD_SOLVER_MULTIGRID;
    d.params.diffusion_boundary = (hd_boundary)boundary;
    d.params.illumination_downsample = downsample;
    d.logger.func = quiet_log;
    for (b = 0; b < 2; ++b) {
        hd_result r = api[b]->create(&d, &h[b]);
        if (r != HD_SUCCESS) {
            fprintf(stderr, "hdbench_mg_vulkan: %s: hd_create: %s\n", api[b]->backend_name(), api[b]->result_string(r));
            if (b == 1) api[0]->destroy(h[0]);
            return 1;
        }
    }
    for (b = 0; b < 2; ++b)
        if (api[b]->test_direct(h[b], 4) != HD_SUCCESS || api[b]->test_diffuse(h[b], 1) != HD_SUCCESS) {
            fprintf(stderr, "hdbench_mg_vulkan: %s: the untimed start failed\n", api[b]->backend_name());
            api[0]->destroy(h[0]);
            api[1]->destroy(h[1]);
            return 1;
        }
    for (k = 0; k < rounds; ++k)
        for (b = 0; b < 2; ++b) {
            double t0 = now();
            if (api[b]->test_diffuse(h[b], steps) != HD_SUCCESS) {
                fprintf(stderr, "hdbench_mg_vulkan: %s: a step failed\n", api[b]->backend_name());
                api[0]->destroy(h[0]);
                api[1]->destroy(h[1]);
                return 1;
            }
            t[b][k] = (now() - t0) / steps;
            sum[b] += t[b][k];
        }
    memset(&st, 0, sizeof st);
    hd_api_cpu.get_stats(h[0], &st);
    printf("%3dx%3dx%3d %-7s %10.1f %12.1f %8.2f %10.2e\n", st.illumination_dims[0], st.illumination_dims[1],
           st.illumination_dims[2], boundary == HD_BOUNDARY_SURFACE ? "surface" : "box", 1e3 * hdb_median(t[0], rounds),
           1e3 * hdb_median(t[1], rounds), sum[1] / sum[0],
           phi_rel_l2(h[0], h[1], (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2]));
    fflush(stdout);
    api[0]->destroy(h[0]);
    api[1]->destroy(h[1]);
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd";
    hd_volume_file vf;
    hd_logger log;
    int i, rounds = 5, steps = 2, downsample = 0, ds, boundary, fail = 0;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) rounds = atoi(argv[++i]);
        else if (strcmp(argv[i], "--steps") == 0 && i + 1 < argc) steps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--downsample") == 0 && i + 1 < argc) downsample = atoi(argv[++i]);
        else path = argv[i];
    }
    if (rounds < 1) rounds = 1;
    if (rounds > MAX_ROUNDS) rounds = MAX_ROUNDS;
    if (steps < 1) steps = 1;
    memset(&log, 0, sizeof log);
    log.func = hd_api_cpu.log_stderr;
    if (hd_api_cpu.volume_load_nrrd(path, &vf, &log) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_mg_vulkan: cannot load %s (make data)\n", path);
        return 1;
    }
    printf("%s %dx%dx%d, one light, 4 direct-light passes; %d rounds of %d steps per backend, interleaved\n", path,
           vf.desc.dims[0], vf.desc.dims[1], vf.desc.dims[2], rounds, steps);
    printf("%-11s %-7s %10s %12s %8s %10s\n", "grid", "bound.", "CPU ms", "Vulkan ms", "VK/CPU", "phi rel L2");
    for (ds = 1; ds <= 2; ++ds) {
        if (downsample && ds != downsample) continue;
        for (boundary = HD_BOUNDARY_BOX; boundary <= HD_BOUNDARY_SURFACE; ++boundary)
            fail |= run_case(&vf, boundary, ds, rounds, steps);
    }
    printf("(ms: median per step over the rounds; VK/CPU: ratio of the summed times)\n");
    hd_api_cpu.volume_free(&vf);
    return fail;
}
