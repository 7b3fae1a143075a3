/* hdbench_project - the projection's frame time on one backend, over a fixed light.
   The light (E and phi of HD on the head CT, CT skin TF, one directional light, full grid) is
   converged once and saved by `--make-light FILE ITERS` (CPU backend); every run then loads it
   through the test hook, so runs of different backends and of different builds of the library
   (old and new projection, mk/bench_project.mk) project exactly the same light. Each size:
   2 warm-up frames, then frames timed one by one (the device drained after each); prints the
   median and the best ms per frame. --save writes the image after the timed frames as raw
   float RGBA, --compare prints the PSNR of this run's image against such a file (peak: the
   reference's largest RGB value), --png writes it as a PNG to look at.
   --threads adds, per thread, the ms per timed frame on a CPU, in the run queue and asleep
   (bench/hd_thread_times.h: the workers' sleep is the time the backend left a core unused).
   --orbit takes bench-peer's scene instead (bench/hd_orbit_scene.h: the ct-skin TF, hdrender's
   camera at azimuth 0, its key light; light file build/bench_project_light_orbit.f32), the
   scene whose frame make bench-peer times against VTK; --azimuth DEG turns its camera around the
   vertical axis as bench-peer's orbit frames do (its light stays).
   Usage: hdbench_project [--orbit [--azimuth DEG]] [--threads] [--make-light FILE ITERS] [--light FILE] [--size N | --size WxH]
                          [--width W] [--height H] [--frames F] [--save F32] [--compare F32]
                          [--png PNG] [--tag WORD] [data/head.nrrd]
   --size N is an N x N frame; --size 1920x1080 (or --width / --height) any other.
   Figures, not a test: nothing here passes or fails. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#if !defined(HYBRIDDIFF_BACKEND_CPU) && !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_GL) && \
    !defined(HYBRIDDIFF_BACKEND_VULKAN)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "examples/hd_png.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "hd_bench_median.h"
#include "hd_orbit_scene.h"
#include "hd_thread_times.h"

/* A CT transfer function over HU -1024..3071 (bench/hdbench.c's): skin faint, bone dense. */
static const float bench_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f, 0.0f,     0.93f, 0.73f, 0.62f, 0.02f,
    0.93f, 0.73f, 0.62f, 0.05f, 1.0f, 0.98f, 0.9f, 0.5f,    1.0f, 1.0f, 1.0f, 1.0f,
    1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f};

static hdo_scene g_orbit; /* --orbit: bench-peer's scene (loaded by main) */
static int g_use_orbit;
static double g_azimuth; /* --azimuth: the orbit camera's azimuth in degrees (bench-peer's views) */

static void fill_desc(hd_desc *d, const hd_volume_file *vf, const hd_light *light, int width, int height)
{
    if (g_use_orbit) {
        *d = g_orbit.desc;
        if (g_azimuth != 0.0) d->camera = hdo_orbit_camera(g_azimuth, width);
        d->camera.width = width;
        d->camera.height = height;
        d->logger.func = hd_log_stderr;
        return;
    }
    memset(d, 0, sizeof *d);
    d->volume = vf->desc;
    d->volume.value_range[0] = -1024.0f;
    d->volume.value_range[1] = 3071.0f;
    d->transfer_function.rgba = bench_tf;
    d->transfer_function.count = (int)(sizeof bench_tf / sizeof bench_tf[0] / 4);
    d->lights = light;
    d->light_count = 1;
    d->camera.eye[1] = 2.3f; d->camera.eye[2] = 0.3f; d->camera.up[2] = 1.0f;
    d->camera.fov_y = 30.0f;
    d->camera.width = width;
    d->camera.height = height;
    d->logger.func = hd_log_stderr;
}

/* File layout: int32 voxel count n, then E (n floats), then phi (n floats). */
static int make_light(const hd_volume_file *vf, const hd_light *light, const char *path, int iters)
{
    hd_desc d;
    hd_context ctx;
    hd_stats st;
    float *buf;
    int32_t n;
    FILE *f;
    fill_desc(&d, vf, light, 64, 64); /* small image: the iterations' projections cost little */
    if (hd_create(&d, &ctx) != HD_SUCCESS || hd_iterate(ctx, iters) != HD_SUCCESS) return 1;
    hd_get_stats(ctx, &st);
    n = (int32_t)((size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] * st.illumination_channels);
    buf = (float *)malloc((size_t)n * 2 * sizeof(float));
    f = fopen(path, "wb");
    if (!buf || !f || hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, buf, (size_t)n) != HD_SUCCESS ||
        hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, buf + n, (size_t)n) != HD_SUCCESS ||
        fwrite(&n, sizeof n, 1, f) != 1 || fwrite(buf, sizeof(float), (size_t)n * 2, f) != (size_t)n * 2) {
        fprintf(stderr, "hdbench_project: cannot write %s\n", path);
        return 1;
    }
    fclose(f);
    printf("light: %d HD iterations (%d voxels) saved to %s\n", iters, n, path);
    free(buf);
    hd_destroy(ctx);
    return 0;
}

static float *read_floats(const char *path, size_t *count)
{
    FILE *f = fopen(path, "rb");
    long bytes;
    float *p;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    bytes = ftell(f);
    fseek(f, 0, SEEK_SET);
    p = (float *)malloc((size_t)bytes);
    if (p && fread(p, 1, (size_t)bytes, f) != (size_t)bytes) { free(p); p = NULL; }
    fclose(f);
    *count = (size_t)bytes / sizeof(float);
    return p;
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd", *light_path = "build/bench_project_light.f32", *save = NULL;
    const char *compare = NULL, *png = NULL, *tag = "";
    int light_given = 0, threads = 0;
    int width = 512, height = 512, frames = 8, make_iters = 0, i;
    hd_volume_file vf;
    hd_light light;
    hd_desc d;
    hd_context ctx;
    hd_stats st;
    size_t nlight, npix;
    float *lightbuf, *img;
    double *ms, t, cpu_ms;
    clock_t cpu0;
    hdt_snap th0, th1;
    int32_t n;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--make-light") == 0 && i + 2 < argc) {
            light_path = argv[++i];
            make_iters = atoi(argv[++i]);
            light_given = 1;
        } else if (strcmp(argv[i], "--light") == 0 && i + 1 < argc) {
            light_path = argv[++i];
            light_given = 1;
        } else if (strcmp(argv[i], "--orbit") == 0) g_use_orbit = 1;
        else if (strcmp(argv[i], "--threads") == 0) threads = 1;
        else if (strcmp(argv[i], "--azimuth") == 0 && i + 1 < argc) g_azimuth = atof(argv[++i]);
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            const char *x = strchr(argv[++i], 'x');
            width = atoi(argv[i]);
            height = x ? atoi(x + 1) : width;
        } else if (strcmp(argv[i], "--width") == 0 && i + 1 < argc) width = atoi(argv[++i]);
        else if (strcmp(argv[i], "--height") == 0 && i + 1 < argc) height = atoi(argv[++i]);
        else if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) frames = atoi(argv[++i]);
        else if (strcmp(argv[i], "--save") == 0 && i + 1 < argc) save = argv[++i];
        else if (strcmp(argv[i], "--compare") == 0 && i + 1 < argc) compare = argv[++i];
        else if (strcmp(argv[i], "--png") == 0 && i + 1 < argc) png = argv[++i];
        else if (strcmp(argv[i], "--tag") == 0 && i + 1 < argc) tag = argv[++i];
        else if (argv[i][0] == '-') { fprintf(stderr, "hdbench_project: unknown option %s\n", argv[i]); return 2; }
        else path = argv[i];
    }
    if (width < 1 || height < 1 || frames < 1) {
        fprintf(stderr, "hdbench_project: --size, --width, --height and --frames must be >= 1\n");
        return 2;
    }
    if (g_use_orbit) {
        hd_logger quiet = {NULL, NULL};
        if (!hdo_scene_load(&g_orbit, path, width, &quiet)) return 2;
        if (!light_given) light_path = "build/bench_project_light_orbit.f32";
    }
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_project: cannot load %s (run `make data` first)\n", path);
        return 2;
    }
    memset(&light, 0, sizeof light);
    light.direction[0] = -0.5f; light.direction[1] = -1.0f; light.direction[2] = -0.6f;
    if (make_iters > 0) return make_light(&vf, &light, light_path, make_iters);

    lightbuf = read_floats(light_path, &nlight);
    if (!lightbuf || nlight < 1) { fprintf(stderr, "hdbench_project: cannot read %s (--make-light first)\n", light_path); return 2; }
    memcpy(&n, lightbuf, sizeof n);
    fill_desc(&d, &vf, &light, width, height);
    if (hd_create(&d, &ctx) != HD_SUCCESS) return 1;
    hd_get_stats(ctx, &st);
    if ((size_t)n != (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] * st.illumination_channels ||
        nlight != 1 + 2 * (size_t)n) {
        fprintf(stderr, "hdbench_project: %s does not fit this volume's grid\n", light_path);
        return 2;
    }
    if (hd__test_write_illumination(ctx, HD_ILLUMINATION_DIRECT, lightbuf + 1) != HD_SUCCESS ||
        hd__test_write_illumination(ctx, HD_ILLUMINATION_SCATTERED, lightbuf + 1 + n) != HD_SUCCESS ||
        hd__test_project(ctx, 2) != HD_SUCCESS || hd__test_finish(ctx) != HD_SUCCESS)
        return 1;
    ms = (double *)malloc((size_t)frames * sizeof(double));
    hdt_take(&th0);
    cpu0 = clock();
    for (i = 0; i < frames; ++i) {
        t = hd__now();
        if (hd__test_project(ctx, 1) != HD_SUCCESS || hd__test_finish(ctx) != HD_SUCCESS) return 1;
        ms[i] = (hd__now() - t) * 1e3;
    }
    hdt_take(&th1);
    cpu_ms = (double)(clock() - cpu0) * 1e3 / (double)CLOCKS_PER_SEC / (double)frames;
    qsort(ms, (size_t)frames, sizeof(double), hdb_cmp_double);
    if (width == height) printf("%-4s %-7s %4d^2     ", tag, hd_backend_name(), width);
    else printf("%-4s %-7s %4dx%-4d ", tag, hd_backend_name(), width, height);
    printf(" projection %8.1f ms/frame (median of %d, best %.1f; process CPU %.1f ms/frame)", ms[frames / 2], frames, ms[0],
           cpu_ms);
    if (threads) hdt_print(&th0, &th1, frames);
    npix = (size_t)width * height;
    img = (float *)malloc(npix * 4 * sizeof(float));
    if (!img || hd_read_image_f32(ctx, img, npix * 4) != HD_SUCCESS) return 1;
    if (compare) {
        size_t nref, p;
        float *ref = read_floats(compare, &nref);
        double se = 0.0, peak = 0.0;
        if (!ref || nref != npix * 4) { printf("\n"); fprintf(stderr, "hdbench_project: cannot read %s\n", compare); return 2; }
        for (p = 0; p < npix * 4; ++p) {
            double e = (double)img[p] - ref[p];
            if (p % 4 == 3) continue;
            se += e * e;
            if (ref[p] > peak) peak = ref[p];
        }
        se /= (double)npix * 3.0;
        if (se > 0.0) printf("  PSNR vs %s %.1f dB", compare, 10.0 * log10(peak * peak / se));
        else printf("  identical to %s", compare);
        free(ref);
    }
    printf("\n");
    if (save) {
        FILE *f = fopen(save, "wb");
        if (!f || fwrite(img, sizeof(float), npix * 4, f) != npix * 4) { fprintf(stderr, "hdbench_project: cannot write %s\n", save); return 2; }
        fclose(f);
    }
    if (png) {
        uint8_t *rgba = (uint8_t *)malloc(npix * 4);
        if (!rgba || hd_read_image_rgba8(ctx, rgba, npix * 4) != HD_SUCCESS ||
            !stbi_write_png(png, width, height, 4, rgba, width * 4)) {
            fprintf(stderr, "hdbench_project: cannot write %s\n", png);
            return 2;
        }
        free(rgba);
    }
    free(img);
    free(ms);
    free(lightbuf);
    hd_destroy(ctx);
    hd_volume_free(&vf);
    if (g_use_orbit) hd_volume_free(&g_orbit.vol);
    return 0;
}
