/* hdbench_vulkan.c - Vulkan figures on the head CT (data/head.nrrd; `make data`), with a plain-C
   stencil in the same run for scale:
     - iterations/s of every method (HD, CD, PT_SS, PT_MS) with 1 and 3 lights, through hd_iterate
       (each stage submitted and waited for, as the library runs);
     - the diffusion sweep alone (src/hd_test_hooks.h): sweeps/s and bytes/s, counting the
       minimum traffic of one sweep: sigma_t, E and phi read once, phi written once (16 B/voxel);
     - a plain-C 7-point Jacobi stencil on the same grid, one thread, for scale.
   Usage: hdbench_vulkan [file.nrrd] [seconds per figure, default 2] */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include <stdio.h>

static double budget = 2.0;

/* Runs fn(ctx, 1) until the budget is spent; returns calls per second. */
static double rate(hd_context h, hd_result (*fn)(hd_context, int))
{
    double t0, t;
    int n = 0;
    if (fn(h, 1) != HD_SUCCESS) return -1.0; /* warm-up: allocation, upload, classify */
    t0 = hd__now();
    do {
        if (fn(h, 1) != HD_SUCCESS) return -1.0;
        ++n;
        t = hd__now() - t0;
    } while (t < budget);
    return n / t;
}

static hd_result iterate(hd_context h, int n) { return hd_iterate(h, n); }

/* Plain C: phi' = (b + sum of the 6 neighbours' phi) / 7 with zero outside, Jacobi ping-pong. */
static double c_stencil(const int *g)
{
    size_t n = (size_t)g[0] * g[1] * g[2], sxy = (size_t)g[0] * g[1];
    float *a = (float *)calloc(n, sizeof(float)), *b = (float *)calloc(n, sizeof(float)), *rhs = (float *)calloc(n, sizeof(float));
    double t0, t;
    int it = 0, x, y, z;
    size_t i;
    for (i = 0; i < n; ++i) rhs[i] = (float)(i % 97) * 0.01f;
    t0 = hd__now();
    do {
        for (z = 0; z < g[2]; ++z)
            for (y = 0; y < g[1]; ++y)
                for (x = 0; x < g[0]; ++x) {
                    size_t k = z * sxy + (size_t)y * g[0] + x;
                    float s = rhs[k];
                    s += x > 0 ? a[k - 1] : 0.0f;
                    s += x < g[0] - 1 ? a[k + 1] : 0.0f;
                    s += y > 0 ? a[k - g[0]] : 0.0f;
                    s += y < g[1] - 1 ? a[k + g[0]] : 0.0f;
                    s += z > 0 ? a[k - sxy] : 0.0f;
                    s += z < g[2] - 1 ? a[k + sxy] : 0.0f;
                    b[k] = s * (1.0f / 7.0f);
                }
        { float *tmp = a; a = b; b = tmp; }
        ++it;
        t = hd__now() - t0;
    } while (t < budget);
    free(a); free(b); free(rhs);
    return it / t;
}

int main(int argc, char **argv)
{
    const char *path = argc > 1 ? argv[1] : "data/head.nrrd";
    hd_volume_file vol;
    hd_desc d;
    hd_context h;
    hd_result r;
    hd_logger log;
    static const hd_method methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};
    hd_light lights[3];
    int m, L, g[3];
    double vox, sweeps, cps;
    (void)hd__test_prepare; (void)hd__test_direct; (void)hd__test_project; /* hooks this bench does not use */
    (void)hd__test_write_illumination; (void)hd__test_finish;
    if (argc > 2) budget = atof(argv[2]);
    memset(&log, 0, sizeof log);
    log.func = hd_log_stderr;
    if ((r = hd_volume_load_nrrd(path, &vol, &log)) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_vulkan: %s: %s (run `make data`)\n", path, hd_result_string(r));
        return 1;
    }
    memset(lights, 0, sizeof lights);
    lights[0].direction[0] = 0.3f; lights[0].direction[1] = -1.0f; lights[0].direction[2] = -0.4f;
    lights[1].type = HD_LIGHT_POINT; lights[1].position[0] = 1.0f; lights[1].position[1] = 0.5f; lights[1].position[2] = 0.8f;
    lights[2].direction[0] = -0.8f; lights[2].direction[1] = -0.2f; lights[2].direction[2] = -0.6f;
    memset(&d, 0, sizeof d);
    d.volume = vol.desc;
    d.logger.func = NULL;
    d.camera.width = 256; d.camera.height = 256;
    g[0] = vol.desc.dims[0]; g[1] = vol.desc.dims[1]; g[2] = vol.desc.dims[2];
    vox = (double)g[0] * g[1] * g[2];
    printf("hdbench_vulkan: %s, %dx%dx%d voxels, image 256x256, %.1f s per figure\n", path, g[0], g[1], g[2], budget);
    r = hd_create(&d, &h);
    if (r != HD_SUCCESS) { printf("Vulkan unavailable: %s\n", hd_result_string(r)); return 1; }
    printf("device: %s\n", hd__lookup(h, NULL)->be->device_name);
    /* the diffusion sweep alone (red-black: both half-sweeps; one submit + wait per sweep) */
    sweeps = rate(h, hd__test_diffuse);
    printf("diffusion sweep (red-black, image3D, 64x1 groups): %.1f sweeps/s, %.2f GB/s (16 B/voxel)\n", sweeps, sweeps * vox * 16.0 / 1e9);
    hd_destroy(h);
    cps = c_stencil(g);
    printf("plain-C 7-point Jacobi stencil, 1 thread:          %.1f it/s,     %.2f GB/s (12 B/voxel)\n", cps, cps * vox * 12.0 / 1e9);
    printf("%-6s %7s %10s\n", "method", "lights", "Vulkan it/s");
    for (m = 0; m < 4; ++m)
        for (L = 1; L <= 3; L += 2) {
            d.params.method = methods[m];
            d.lights = lights;
            d.light_count = L;
            if ((r = hd_create(&d, &h)) != HD_SUCCESS) { printf("%-6s %7d  create failed: %s\n", hd_method_name(methods[m]), L, hd_result_string(r)); continue; }
            printf("%-6s %7d %10.2f\n", hd_method_name(methods[m]), L, rate(h, iterate));
            fflush(stdout);
            hd_destroy(h);
        }
    hd_volume_free(&vol);
    return 0;
}
