/* hdbench_depth - what depth costs a projection frame: the head CT (HD, the CT TF, one light
   refined for a few iterations, not to convergence: the frames project the same light, as frames
   over converged light do), a matrix camera (GL perspective) at W x H, frames timed one by one
   (the device drained after each), interleaved:
     plain:    no depth in (hd_set_depth(NULL) drops the previous variant's) and hd_set_camera (the
               same camera: the image restarts as a new depth buffer restarts it), one frame;
     no plane: the same frame without the depth plane's write (hd_read_depth's values: the
               kernel's per-pixel load and store, switched off by a test hook), so plain - no
               plane is what depth out costs a frame;
     far:      hd_set_depth with every value the far plane's (no geometry: the rays are as long as
               without depth, so this is depth in's whole overhead: the call's check and copy, the
               upload and the per-ray unprojection) and one frame;
     wall:     hd_set_depth of a plane through the volume's centre over the image's right half
               (those rays end there: cheaper frames).
   Prints the median ms of each and the differences in % of the plain frame, then the medians of
   the same differences taken within each round (the four frames back to back: steadier on a
   loaded machine).
   Usage: hdbench_depth [--size N | --size WxH] [--frames F] [data/head.nrrd]. Figures, not a test. */
#define HYBRIDDIFF_TESTING /* the test hooks (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#if !defined(HYBRIDDIFF_BACKEND_CPU) && !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_GL) && \
    !defined(HYBRIDDIFF_BACKEND_VULKAN)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include "hd_bench_median.h"

static const float bench_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f, 0.0f,     0.93f, 0.73f, 0.62f, 0.02f,
    0.93f, 0.73f, 0.62f, 0.05f, 1.0f, 0.98f, 0.9f, 0.5f,    1.0f, 1.0f, 1.0f, 1.0f,
    1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f};

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int frame(hd_context ctx, const hd_camera *cam, const hd_depth_desc *dd, int no_plane, double *ms)
{
    double t0 = now_s();
    int bad;
    /* plain: no depth (hd_set_depth(NULL) drops the previous variant's buffer) */
    if ((dd ? hd_set_depth(ctx, dd) : hd_set_depth(ctx, NULL) || hd_set_camera(ctx, cam)) != HD_SUCCESS) return 1;
    hd__test_no_depth_plane = no_plane;
    bad = hd__test_project(ctx, 1) != HD_SUCCESS || hd__test_finish(ctx) != HD_SUCCESS;
    hd__test_no_depth_plane = 0;
    *ms = 1e3 * (now_s() - t0);
    return bad;
}
/* One round of the four variants, in order. */
static int round4(hd_context ctx, const hd_camera *cam, const hd_depth_desc *far_d, const hd_depth_desc *wall_d, double ms[4])
{
    return frame(ctx, cam, NULL, 0, &ms[0]) || frame(ctx, cam, NULL, 1, &ms[1]) || frame(ctx, cam, far_d, 0, &ms[2]) ||
           frame(ctx, cam, wall_d, 0, &ms[3]);
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd";
    int width = 512, height = 512, frames = 15, i, k;
    hd_volume_file vf;
    hd_desc d;
    hd_light light;
    hd_context ctx;
    hd_camera cam;
    hd_depth_desc far_d, wall_d;
    float *far_buf, *wall_buf;
    double *t[4], med[4], ms[4];
    double n = 0.1, f = 20.0, th = tan(15.0 * 3.14159265358979 / 180.0), dist = 2.3;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) {
            if (sscanf(argv[++i], "%dx%d", &width, &height) != 2) height = width = atoi(argv[i]);
        }
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else path = argv[i];
    }
    if (hd_volume_load(path, &vf, NULL) != HD_SUCCESS) { fprintf(stderr, "hdbench_depth: cannot load %s\n", path); return 1; }
    memset(&d, 0, sizeof d);
    memset(&light, 0, sizeof light);
    light.direction[0] = -0.3f; light.direction[1] = -1.0f; light.direction[2] = -0.5f;
    d.volume = vf.desc;
    d.volume.value_range[0] = -1024.0f;
    d.volume.value_range[1] = 3071.0f;
    d.transfer_function.rgba = bench_tf;
    d.transfer_function.count = (int)(sizeof bench_tf / sizeof bench_tf[0] / 4);
    d.lights = &light;
    d.light_count = 1;
    d.logger.func = hd_log_stderr;
    /* the camera on +y looking at the origin, z up: view and a GL projection */
    cam = d.camera;
    if (width < 1 || height < 1 || frames < 1) { fprintf(stderr, "hdbench_depth: bad --size or --frames\n"); return 1; }
    cam.width = width;
    cam.height = height;
    cam.view[0] = -1.0f; cam.view[9] = 1.0f; cam.view[6] = 1.0f; cam.view[14] = (float)-dist; cam.view[15] = 1.0f;
    cam.projection[0] = (float)(1.0 / th * height / width); cam.projection[5] = (float)(1.0 / th);
    cam.projection[10] = (float)(-(f + n) / (f - n)); cam.projection[14] = (float)(-2.0 * f * n / (f - n));
    cam.projection[11] = -1.0f;
    d.camera = cam;
    if (hd_create(&d, &ctx) != HD_SUCCESS || hd_refine(ctx, 4) != HD_SUCCESS) return 1;
    far_buf = (float *)malloc(sizeof(float) * (size_t)width * height);
    wall_buf = (float *)malloc(sizeof(float) * (size_t)width * height);
    if (!far_buf || !wall_buf) return 1;
    {
        double ndc = ((double)cam.projection[10] * -dist + cam.projection[14]) / dist;
        for (i = 0; i < width * height; ++i) {
            far_buf[i] = 1.0f;
            wall_buf[i] = i % width >= width / 2 ? (float)(0.5 * (ndc + 1.0)) : 1.0f;
        }
    }
    far_d.data = far_buf; far_d.width = width; far_d.height = height;
    wall_d.data = wall_buf; wall_d.width = width; wall_d.height = height;
    for (k = 0; k < 4; ++k) t[k] = (double *)malloc(sizeof(double) * (size_t)frames);
    for (i = 0; i < 2; ++i) /* warm-up */
        if (round4(ctx, &cam, &far_d, &wall_d, ms)) return 1;
    for (i = 0; i < frames; ++i) {
        if (round4(ctx, &cam, &far_d, &wall_d, ms)) return 1;
        for (k = 0; k < 4; ++k) t[k][i] = ms[k];
    }
    { /* the same differences per round (its four frames ran back to back), their medians: steadier
         under load; taken before hdb_median sorts t */
        double *pr[3];
        for (k = 0; k < 3; ++k) pr[k] = (double *)malloc(sizeof(double) * (size_t)frames);
        for (i = 0; i < frames; ++i) {
            pr[0][i] = 100.0 * (t[0][i] - t[1][i]) / t[0][i];
            pr[1][i] = 100.0 * (t[2][i] - t[0][i]) / t[0][i];
            pr[2][i] = 100.0 * (t[3][i] - t[0][i]) / t[0][i];
        }
        for (k = 0; k < 4; ++k) med[k] = hdb_median(t[k], frames);
        printf("%s %dx%d, %d frames each: plain %.2f ms, without the depth plane %.2f ms (depth out %+.1f %%), depth in (far) "
               "%.2f ms (%+.1f %%), depth in (wall over half) %.2f ms (%+.1f %%)\n",
               hd_backend_name(), width, height, frames, med[0], med[1], 100.0 * (med[0] - med[1]) / med[0], med[2],
               100.0 * (med[2] - med[0]) / med[0], med[3], 100.0 * (med[3] - med[0]) / med[0]);
        printf("%s %dx%d, per round: depth out %+.1f %%, depth in (far) %+.1f %%, depth in (wall over half) %+.1f %% of the plain "
               "frame\n",
               hd_backend_name(), width, height, hdb_median(pr[0], frames), hdb_median(pr[1], frames), hdb_median(pr[2], frames));
        for (k = 0; k < 3; ++k) free(pr[k]);
    }
    hd_destroy(ctx);
    hd_volume_free(&vf);
    for (k = 0; k < 4; ++k) free(t[k]);
    free(far_buf);
    free(wall_buf);
    return 0;
}
