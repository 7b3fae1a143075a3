/* hdpeer - hybriddiff's side of the VTK side-by-side (bench/peer/vtk_peer.py drives it; make
   bench-peer). Loads the head CT with the orbit scene (bench/hd_orbit_scene.h), converges the
   light (hd_refine until hd_stats.light_converged, at most HDPEER_LIGHT_ITERS iterations, default
   32; past the cap light_tolerance is raised so the frames stay projections, see hdo_converge),
   then answers commands on stdin, one a line, each answered by one line on stdout:
     tf                    the TF the driver must mirror: "tf LO HI COUNT EXTINCTION STEP_WORLD
                           SX SY SZ DX DY DZ" then COUNT lines "R G B A" (SX.. the world box
                           sides, DX.. the dims)
     frames SIZE N         N orbit frames at SIZE x SIZE (azimuth 360 i / N), one hd_render
                           each: "ms MEAN_MS LIGHT_SECONDS CPU_MS" (LIGHT_SECONDS: direct +
                           diffusion time spent during them, 0 once the light has converged;
                           CPU_MS: this process's CPU time per frame)
     picture SIZE PATH     azimuth 0 at SIZE x SIZE, frame_window frames averaged, PNG: "ok"
     quit
   Usage: hdpeer [FILE]   (default data/head.nrrd)
   The CPU backend unless built with HYBRIDDIFF_BACKEND_OPENCL, _GL or _VULKAN (build/hdpeer_opencl,
   hdpeer_gl, hdpeer_vulkan; mk/bench.mk); on those the timed frames end with an image read, so
   that the device has finished them. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#define HYBRIDDIFF_IMPLEMENTATION
#if !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_GL) && !defined(HYBRIDDIFF_BACKEND_VULKAN)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#include "hybriddiff.h"
#include "hd_orbit_scene.h"
#include "hd_png.h"

static hd_context g_ctx;

static void check(hd_result r, const char *what)
{
    if (r != HD_SUCCESS) {
        fprintf(stderr, "hdpeer: %s: %s\n", what, hd_result_string(r));
        exit(1);
    }
}

static double light_seconds(void)
{
    hd_stats st;
    check(hd_get_stats(g_ctx, &st), "hd_get_stats");
    return st.seconds_direct + st.seconds_diffusion;
}

static double cpu_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void set_view(double deg, int size)
{
    hd_camera c = hdo_orbit_camera(deg, size);
    check(hd_set_camera(g_ctx, &c), "hd_set_camera");
}

static void picture(int size, const char *path)
{
    size_t npix = (size_t)size * (size_t)size, i;
    uint8_t *rgba = (uint8_t *)malloc(npix * 4), *rgb = (uint8_t *)malloc(npix * 3);
    hd_desc d = HD_DESC_INIT; /* zeroed: gcc 12 cannot see hd_query_desc set it */
    int f;
    if (!rgba || !rgb) {
        fprintf(stderr, "hdpeer: out of memory\n");
        exit(1);
    }
    check(hd_query_desc(g_ctx, &d), "hd_query_desc");
    set_view(0.0, size);
    for (f = 0; f < d.params.frame_window; ++f) check(hd_render(g_ctx), "hd_render");
    check(hd_read_image_rgba8(g_ctx, rgba, npix * 4), "hd_read_image_rgba8");
    for (i = 0; i < npix; ++i) memcpy(rgb + 3 * i, rgba + 4 * i, 3);
    if (!stbi_write_png(path, size, size, 3, rgb, size * 3)) {
        fprintf(stderr, "hdpeer: cannot write %s\n", path);
        exit(1);
    }
    free(rgba);
    free(rgb);
}

int main(int argc, char **argv)
{
    static hdo_scene s;
    const char *path = argc > 1 ? argv[1] : "data/head.nrrd";
    const char *env = getenv("HDPEER_LIGHT_ITERS");
    int max_light = env ? atoi(env) : 32;
    hd_logger log = {hd_log_stderr, NULL};
    char line[4096];
    double t0;

    if (argc > 2 || (argc == 2 && argv[1][0] == '-')) {
        fprintf(stderr, "usage: hdpeer [FILE]   (commands on stdin, see bench/peer/hdpeer.c)\n");
        return 2;
    }
    if (max_light < 1) max_light = 1;
    if (!hdo_scene_load(&s, path, 512, &log)) return 1;
    check(hd_create(&s.desc, &g_ctx), "hd_create");
    fprintf(stderr, "hdpeer: %s backend\n", hd_backend_name());

    if (hdo_converge(g_ctx, max_light, "hdpeer", &t0) < 0) return 1;

    while (fgets(line, sizeof line, stdin)) {
        char cmd[32], arg[4000];
        int size = 0, n = 0;
        arg[0] = 0;
        if (sscanf(line, "%31s", cmd) != 1) continue;
        if (strcmp(cmd, "quit") == 0) break;
        if (strcmp(cmd, "tf") == 0) {
            hd_desc d;
            int i, k;
            float side[3], m = 0.0f;
            check(hd_query_desc(g_ctx, &d), "hd_query_desc");
            for (k = 0; k < 3; ++k) {
                side[k] = (float)d.volume.dims[k] * d.volume.spacing[k];
                if (side[k] > m) m = side[k];
            }
            for (k = 0; k < 3; ++k) side[k] /= m;
            /* the projection's step is in voxels of the smallest world voxel size */
            m = side[0] / (float)d.volume.dims[0];
            for (k = 1; k < 3; ++k)
                if (side[k] / (float)d.volume.dims[k] < m) m = side[k] / (float)d.volume.dims[k];
            printf("tf %.9g %.9g %d %.9g %.9g %.9g %.9g %.9g %d %d %d\n",
                   (double)d.volume.value_range[0], (double)d.volume.value_range[1],
                   d.transfer_function.count, (double)d.params.extinction,
                   (double)(d.params.step * m), (double)side[0], (double)side[1], (double)side[2],
                   d.volume.dims[0], d.volume.dims[1], d.volume.dims[2]);
            for (i = 0; i < d.transfer_function.count; ++i)
                printf("%.6g %.6g %.6g %.6g\n", (double)d.transfer_function.rgba[4 * i],
                       (double)d.transfer_function.rgba[4 * i + 1],
                       (double)d.transfer_function.rgba[4 * i + 2],
                       (double)d.transfer_function.rgba[4 * i + 3]);
        } else if (strcmp(cmd, "frames") == 0 && sscanf(line, "%*s %d %d", &size, &n) == 2 &&
                   size >= 16 && size <= 4096 && n >= 1) {
            double l0, ts, te, cs;
            int i;
            set_view(0.0, size);
            check(hd_render(g_ctx), "hd_render"); /* the image at this size exists */
            l0 = light_seconds();
            ts = hdo_now();
            cs = cpu_seconds();
            for (i = 0; i < n; ++i) {
                set_view(360.0 * i / n, size);
                check(hd_render(g_ctx), "hd_render");
            }
#ifndef HYBRIDDIFF_BACKEND_CPU
            {
                size_t bytes = (size_t)size * (size_t)size * 4;
                uint8_t *rgba = (uint8_t *)malloc(bytes);
                if (!rgba) {
                    fprintf(stderr, "hdpeer: out of memory\n");
                    exit(1);
                }
                check(hd_read_image_rgba8(g_ctx, rgba, bytes), "hd_read_image_rgba8");
                free(rgba);
            }
#endif
            te = hdo_now();
            printf("ms %.3f %.6f %.3f\n", 1e3 * (te - ts) / n, light_seconds() - l0,
                   1e3 * (cpu_seconds() - cs) / n);
        } else if (strcmp(cmd, "picture") == 0 && sscanf(line, "%*s %d %3999s", &size, arg) == 2 &&
                   size >= 16 && size <= 4096) {
            picture(size, arg);
            printf("ok\n");
        } else {
            fprintf(stderr, "hdpeer: bad command: %s", line);
            printf("error\n");
        }
        fflush(stdout);
    }
    hd_destroy(g_ctx);
    hd_volume_free(&s.vol);
    return 0;
}
