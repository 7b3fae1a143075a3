/* hdsoak.c - soak test: N iterations of HD on a small volume (default 10,000 on 32^3, a 64x64
   image), changing the transfer function, the lights and the camera every 100 iterations.
   Prints the process RSS (/proc/self/statm) and the library's device bytes (hd_stats: method +
   image + volume) over time, and fails (exit 1) if, after the warm-up (the first 10%), either
   moves by more than 1% of its post-warm-up value, or if any image value is not finite.
   Usage: hdsoak [iterations] [size]      (make soak; make soak-short runs 500 in make test) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static long rss_kb(void)
{
    long pages = 0, resident = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f) return -1;
    if (fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = -1;
    fclose(f);
    return resident < 0 ? -1 : resident * (sysconf(_SC_PAGESIZE) / 1024);
}

int main(int argc, char **argv)
{
    int iters = argc > 1 ? atoi(argv[1]) : 10000, n = argc > 2 ? atoi(argv[2]) : 32;
    int warm, i, x, y, z, fail = 0, step = 100, w = 64, h = 64;
    long rss_lo = 0, rss_hi = 0, rss;
    size_t dev_lo = 0, dev_hi = 0, nonfinite = 0, k;
    uint8_t *vol;
    float *img = (float *)malloc((size_t)w * h * 4 * sizeof(float));
    hd_desc d;
    hd_context ctx;
    hd_stats st;
    hd_result r;
    if (iters < 200 || n < 4 || n > 256 || !img) {
        fprintf(stderr, "usage: hdsoak [iterations >= 200] [size 4..256]\n");
        return 2;
    }
    warm = iters / 10;
    vol = (uint8_t *)malloc((size_t)n * n * n);
    for (z = 0; z < n; ++z)
        for (y = 0; y < n; ++y)
            for (x = 0; x < n; ++x) {
                float dx = x - n / 2.0f, dy = y - n / 2.0f, dz = z - n / 2.0f;
                float rr = sqrtf(dx * dx + dy * dy + dz * dz) / (n / 2.0f);
                vol[((size_t)z * n + y) * n + x] = (uint8_t)(rr < 1 ? 255 * (1 - rr) : 0);
            }
    memset(&d, 0, sizeof d);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = n;
    d.volume.data = vol;
    d.camera.width = w;
    d.camera.height = h;
    d.logger.func = hd_log_stderr;
    if ((r = hd_create(&d, &ctx)) != HD_SUCCESS) {
        fprintf(stderr, "hdsoak: hd_create: %s\n", hd_result_string(r));
        return 1;
    }
    printf("hdsoak: %d HD iterations, %d^3 u8, %dx%d image, TF/lights/camera change every %d\n",
           iters, n, w, h, step);
    printf("%8s %10s %12s %10s\n", "iter", "rss_kB", "device_B", "max|img|");
    for (i = 0; i < iters; i += step) {
        int c = i / step;
        float tf[12] = {0, 0, 0, 0, 0.9f, 0.5f, 0.3f, 0.2f + 0.05f * (c % 5), 1, 1, 1, 1};
        hd_transfer_function t;
        hd_light L[2];
        hd_camera cam;
        float a = 0.37f * c, mx = 0;
        size_t dev;
        t.rgba = tf;
        t.count = 3;
        memset(L, 0, sizeof L);
        L[0].type = HD_LIGHT_DIRECTIONAL;
        L[0].direction[0] = cosf(a); L[0].direction[1] = -0.5f; L[0].direction[2] = sinf(a);
        L[1].type = HD_LIGHT_POINT;
        L[1].position[0] = 0.8f * sinf(a); L[1].position[1] = 0.9f; L[1].position[2] = 0.8f;
        L[1].intensity = 0.5f;
        memset(&cam, 0, sizeof cam);
        cam.eye[0] = 2.5f * sinf(a); cam.eye[2] = 2.5f * cosf(a); cam.eye[1] = 0.3f;
        cam.width = w; cam.height = h;
        if ((r = hd_set_transfer_function(ctx, &t)) != HD_SUCCESS ||
            (r = hd_set_lights(ctx, L, 1 + c % 2)) != HD_SUCCESS ||
            (r = hd_set_camera(ctx, &cam)) != HD_SUCCESS ||
            (r = hd_iterate(ctx, step)) != HD_SUCCESS ||
            (r = hd_read_image_f32(ctx, img, (size_t)w * h * 4)) != HD_SUCCESS ||
            (r = hd_get_stats(ctx, &st)) != HD_SUCCESS) {
            fprintf(stderr, "hdsoak: iteration %d: %s\n", i, hd_result_string(r));
            return 1;
        }
        for (k = 0; k < (size_t)w * h * 4; ++k) {
            if (!isfinite(img[k])) ++nonfinite;
            else if (fabsf(img[k]) > mx) mx = fabsf(img[k]);
        }
        rss = rss_kb();
        dev = st.method_bytes + st.image_bytes + st.volume_bytes;
        if (i + step >= warm && i >= warm) {
            if (!rss_lo || rss < rss_lo) rss_lo = rss;
            if (rss > rss_hi) rss_hi = rss;
            if (!dev_lo || dev < dev_lo) dev_lo = dev;
            if (dev > dev_hi) dev_hi = dev;
        }
        if (c % (iters / step / 20 > 0 ? iters / step / 20 : 1) == 0 || i + step >= iters)
            printf("%8d %10ld %12zu %10.4g\n", i + step, rss, dev, mx);
    }
    hd_destroy(ctx);
    printf("after warm-up (%d iterations): RSS %ld..%ld kB (%.3f%%), device bytes %zu..%zu "
           "(%.3f%%), %zu non-finite image values\n", warm, rss_lo, rss_hi,
           100.0 * (rss_hi - rss_lo) / (rss_lo ? rss_lo : 1), dev_lo, dev_hi,
           100.0 * (double)(dev_hi - dev_lo) / (double)(dev_lo ? dev_lo : 1), nonfinite);
    if (rss_lo <= 0 || (rss_hi - rss_lo) * 100 > rss_lo) fail = 1;
    if ((dev_hi - dev_lo) * 100 > dev_lo) fail = 1;
    if (nonfinite) fail = 1;
    printf("hdsoak: %s\n", fail ? "FAIL" : "ok");
    free(vol);
    free(img);
    return fail;
}
