/* hdbench_animated.c - living volumes (make bench-animated; built for every backend).
   1. A procedural smoke puff (three Gaussian puffs advected along a loop, modulated by
      time-varying value noise) at S^3, F frames, the camera orbiting, 512^2 (--size):
      per-frame wall time of hd_update_volume + hd_set_camera + hd_render (render_budget: each
      of the --budget list, in ms; 0 is one light iteration per frame) + hd_read_image_rgba8,
      and the frames over the budget, against hd_destroy + hd_create + hd_render + read (the
      only way before hd_update_volume; --cold frames of it, with the first budget). The lag:
      the PSNR of every --every-th frame's image against the same frame's converged light (a
      fresh context run to convergence, then frame_window frames, same camera; made once for
      all budgets). --csv appends one row per frame: backend, S, size, budget ms, frame, ms,
      PSNR (-1 where not measured); and per slider step: "slider", warm or cold, step, mean.
   2. The TF slider on the head CT (data/head.nrrd): the opacity scale moves one way over 61
      steps, one hd_render per step; the brightness (mean of the 8-bit image) should follow
      monotonically: trend reversals are counted; then the renders until hd_stats.light_converged
      after the last step. Run warm (the library's setters) and cold (hd_reset after each step:
      the old behaviour).
   --scale N|auto sets params.render_scale of the timed frames under a budget (default auto; both
   ways; the reference renders full frames).
   Usage: hdbench_animated [--dims S] [--frames F] [--cold C] [--every K] [--size P]
                           [--budget ms[,ms...]] [--scale N|auto] [--csv path] [--no-puff]
                           [--no-tf] [--head path] */
#define HYBRIDDIFF_IMPLEMENTATION
#if !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_VULKAN) && !defined(HYBRIDDIFF_BACKEND_GL)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#include "hybriddiff.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void die(const char *what, hd_result r)
{
    fprintf(stderr, "hdbench_animated: %s: %s\n", what, hd_result_string(r));
    exit(1);
}

/* ---- the puff ---------------------------------------------------------------------------------- */
static float hash3(int x, int y, int z, int t)
{
    uint32_t h = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u ^ (uint32_t)t * 2654435761u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return (float)(h & 0xffffff) / 16777216.0f;
}
/* Trilinear value noise at a lattice of `cell` voxels, drifting with time. */
static float vnoise(float x, float y, float z, float t)
{
    float fx = x + 0.7f * t, fy = y - 0.4f * t, fz = z + 0.3f * t;
    int ix = (int)floorf(fx), iy = (int)floorf(fy), iz = (int)floorf(fz);
    float u = fx - ix, v = fy - iy, w = fz - iz, r = 0.0f;
    int a, b, c;
    for (c = 0; c < 2; ++c)
        for (b = 0; b < 2; ++b)
            for (a = 0; a < 2; ++a)
                r += (a ? u : 1 - u) * (b ? v : 1 - v) * (c ? w : 1 - w) * hash3(ix + a, iy + b, iz + c, 0);
    return r;
}
static void puff(float *vol, int s, int frame, int frames)
{
    float t = 6.2831853f * (float)frame / (float)frames;
    float cx[3], cy[3], cz[3];
    int k, x, y, z;
    for (k = 0; k < 3; ++k) {
        float ph = t + 2.094f * k;
        cx[k] = 0.5f + 0.2f * cosf(ph);
        cy[k] = 0.5f + 0.2f * sinf(ph);
        cz[k] = 0.35f + 0.1f * k + 0.1f * sinf(2.0f * ph);
    }
    for (z = 0; z < s; ++z)
        for (y = 0; y < s; ++y)
            for (x = 0; x < s; ++x) {
                float px = (x + 0.5f) / s, py = (y + 0.5f) / s, pz = (z + 0.5f) / s, d = 0.0f;
                for (k = 0; k < 3; ++k) {
                    float dx = px - cx[k], dy = py - cy[k], dz = pz - cz[k];
                    d += expf(-(dx * dx + dy * dy + dz * dz) / 0.012f);
                }
                d *= 0.6f + 0.8f * vnoise(px * 8.0f, py * 8.0f, pz * 8.0f, 4.0f * (float)frame / (float)frames * 8.0f);
                vol[((size_t)z * s + y) * s + x] = d > 1.0f ? 1.0f : d;
            }
}

static const float smoke_tf[12] = {0, 0, 0, 0, 0.9f, 0.9f, 0.9f, 0.35f, 1, 1, 1, 1};

static hd_camera orbit(int frame, int frames, int size)
{
    hd_camera c = HD_CAMERA_INIT;
    float a = 6.2831853f * (float)frame / (float)frames;
    c.eye[0] = 2.2f * sinf(a);
    c.eye[1] = 0.6f;
    c.eye[2] = 2.2f * cosf(a);
    c.up[1] = 1.0f;
    c.width = c.height = size;
    return c;
}

static int render_scale = HD_RENDER_SCALE_AUTO; /* --scale: params.render_scale of the timed frames */

static hd_desc puff_desc(const float *vol, int s, int size, float budget)
{
    hd_desc d = HD_DESC_INIT;
    d.volume.type = HD_VOXEL_F32;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = s;
    d.volume.data = vol;
    d.transfer_function.rgba = smoke_tf;
    d.transfer_function.count = 3;
    d.camera = orbit(0, 1, size);
    d.params.extinction = 60.0f;
    d.params.render_budget = budget;
    d.params.render_scale = budget > 0.0f ? render_scale : 0;
    return d;
}

static double psnr8(const uint8_t *a, const uint8_t *b, size_t n)
{
    double se = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        if ((i & 3) != 3) se += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    se /= (double)(n / 4 * 3);
    return se > 0.0 ? 10.0 * log10(255.0 * 255.0 / se) : 99.0;
}

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}
static double pct(double *v, int n, double p)
{
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return v[(int)(p * (n - 1) + 0.5)];
}

/* The converged image of one frame: a fresh context run until its light converged and its image
   is final. */
static void reference(const float *vol, int s, int size, const hd_camera *cam, uint8_t *out)
{
    hd_desc d = puff_desc(vol, s, size, 0.0f);
    hd_context c;
    hd_stats st;
    hd_result r;
    int i;
    d.camera = *cam;
    d.params.light_tolerance = 0.02f;
    if ((r = hd_create(&d, &c)) != HD_SUCCESS) die("hd_create (reference)", r);
    for (i = 0; i < 400; ++i) {
        uint64_t f;
        hd_get_stats(c, &st);
        f = st.frames;
        if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render (reference)", r);
        hd_get_stats(c, &st);
        if (st.light_converged && st.frames == f && f > 0) break;
    }
    if ((r = hd_read_image_rgba8(c, out, (size_t)size * size * 4)) != HD_SUCCESS) die("read (reference)", r);
    hd_destroy(c);
}

/* The converged images of the frames the lag is measured at (f % every == every - 1), made once
   and shared by every budget's run. */
typedef struct refs {
    int every, count;
    uint8_t **img;
} refs;

static const uint8_t *ref_of(refs *rf, const float *vol, int s, int size, int f, const hd_camera *cam)
{
    int k = f / rf->every;
    if (!rf->img[k]) {
        rf->img[k] = (uint8_t *)malloc((size_t)size * size * 4);
        reference(vol, s, size, cam, rf->img[k]);
    }
    return rf->img[k];
}

static FILE *csv; /* --csv: one row per timed frame */

/* hd_update_volume per frame under a budget of `budget` seconds: frame time p50 / p99, the frames
   over the budget, the lag against the converged light; with cold > 0 first destroy + create. */
static void bench_puff(int s, int frames, int cold, refs *rf, int size, float budget)
{
    size_t nv = (size_t)s * s * s, np = (size_t)size * size * 4;
    float *vol = (float *)malloc(nv * sizeof(float));
    uint8_t *img = (uint8_t *)malloc(np);
    double *tw = (double *)malloc(sizeof(double) * (size_t)frames), *tc = (double *)malloc(sizeof(double) * (size_t)(cold > 0 ? cold : 1));
    double psum = 0.0, pmin = 1e9, t0;
    int f, np_ = 0, over = 0;
    hd_context c;
    hd_desc d;
    hd_result r;
    hd_volume_update u = HD_VOLUME_UPDATE_INIT;
    /* destroy + create per frame */
    for (f = 0; f < cold; ++f) {
        hd_camera cam = orbit(f, frames, size);
        puff(vol, s, f, frames);
        t0 = now();
        d = puff_desc(vol, s, size, budget);
        d.camera = cam;
        if ((r = hd_create(&d, &c)) != HD_SUCCESS) die("hd_create", r);
        if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render", r);
        if ((r = hd_read_image_rgba8(c, img, np)) != HD_SUCCESS) die("read", r);
        hd_destroy(c);
        tc[f] = now() - t0;
    }
    /* one context, hd_update_volume per frame; its set-up call (upload, classification, mask)
       before the first timed frame */
    puff(vol, s, 0, frames);
    d = puff_desc(vol, s, size, budget);
    if ((r = hd_create(&d, &c)) != HD_SUCCESS) die("hd_create", r);
    if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render (set-up)", r);
    u.type = HD_VOXEL_F32;
    u.dims[0] = u.dims[1] = u.dims[2] = s;
    u.data = vol;
    for (f = 0; f < frames; ++f) {
        hd_camera cam = orbit(f, frames, size);
        double p = -1.0;
        puff(vol, s, f, frames); /* the simulation's step: not timed */
        t0 = now();
        if ((r = hd_update_volume(c, &u)) != HD_SUCCESS) die("hd_update_volume", r);
        if ((r = hd_set_camera(c, &cam)) != HD_SUCCESS) die("hd_set_camera", r);
        if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render", r);
        if ((r = hd_read_image_rgba8(c, img, np)) != HD_SUCCESS) die("read", r);
        tw[f] = now() - t0;
        if (budget > 0.0f && tw[f] > budget) ++over;
        if (rf && f % rf->every == rf->every - 1) {
            p = psnr8(img, ref_of(rf, vol, s, size, f, &cam), np);
            psum += p;
            if (p < pmin) pmin = p;
            ++np_;
        }
        if (csv) fprintf(csv, "%s %d %d %.1f %d %.3f %.2f\n", hd_backend_name(), s, size, budget * 1e3, f, tw[f] * 1e3, p);
    }
    hd_destroy(c);
    printf("%s puff %d^3, %dx%d, %d frames, render_budget %.0f ms: hd_update_volume frame p50 %.1f ms, p99 %.1f ms, %d over the budget",
           hd_backend_name(), s, size, size, frames, budget * 1e3, 1e3 * pct(tw, frames, 0.5), 1e3 * pct(tw, frames, 0.99), over);
    if (cold > 0) printf("; destroy + create frame (%d frames) p50 %.1f ms, p99 %.1f ms", cold, 1e3 * pct(tc, cold, 0.5), 1e3 * pct(tc, cold, 0.99));
    if (np_) printf("; lag PSNR against each frame's converged light (%d frames): mean %.1f dB, min %.1f dB", np_, psum / np_, pmin);
    printf("\n");
    fflush(stdout);
    free(vol); free(img); free(tw); free(tc);
}

/* ---- the TF slider on the head CT ------------------------------------------------------------------ */
static void slider_tf(float scale, float *rgba)
{
    /* air, soft tissue faint, bone opaque; the opacity scaled by the slider */
    static const float base[5 * 4] = {0, 0, 0, 0, 0.8f, 0.5f, 0.4f, 0, 0.9f, 0.6f, 0.5f, 0.05f, 1, 0.95f, 0.9f, 0.8f, 1, 1, 1, 1};
    int i;
    memcpy(rgba, base, sizeof base);
    for (i = 0; i < 5; ++i) rgba[4 * i + 3] *= scale;
}

static double mean8(const uint8_t *p, size_t n)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < n; ++i)
        if ((i & 3) != 3) s += p[i];
    return s / (double)(n / 4 * 3);
}

static void bench_slider(const char *path, int cold)
{
    hd_volume_file vf;
    hd_desc d = HD_DESC_INIT;
    hd_context c;
    hd_result r;
    hd_stats st;
    float rgba[20];
    hd_transfer_function tf;
    int size = 256, steps = 61, i, reversals = 0, after = 0;
    size_t np = (size_t)size * size * 4;
    uint8_t *img = (uint8_t *)malloc(np);
    double prev = 0.0, prevd = 0.0, maxstep = 0.0, t0 = now();
    if ((r = hd_volume_load(path, &vf, NULL)) != HD_SUCCESS) die(path, r);
    d.volume = vf.desc;
    d.volume.data = vf.data;
    slider_tf(0.3f, rgba);
    d.transfer_function.rgba = rgba;
    d.transfer_function.count = 5;
    d.camera.eye[1] = -2.5f;
    d.camera.up[2] = 1.0f;
    d.camera.width = d.camera.height = size;
    if ((r = hd_create(&d, &c)) != HD_SUCCESS) die("hd_create (head)", r);
    for (i = 0; i < 200; ++i) { /* converged at the slider's start */
        hd_render(c);
        hd_get_stats(c, &st);
        if (st.light_converged) break;
    }
    tf.rgba = rgba;
    tf.count = 5;
    for (i = 0; i < steps; ++i) {
        double m, dm;
        slider_tf(0.3f + 0.7f * (float)(i + 1) / (float)steps, rgba); /* opacity up: the image darkens or brightens monotonically */
        if ((r = hd_set_transfer_function(c, &tf)) != HD_SUCCESS) die("hd_set_transfer_function", r);
        if (cold) hd_reset(c);
        if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render", r);
        if ((r = hd_read_image_rgba8(c, img, np)) != HD_SUCCESS) die("read", r);
        m = mean8(img, np);
        if (csv) fprintf(csv, "slider %s %d %.3f\n", cold ? "cold" : "warm", i, m);
        if (i > 0) {
            dm = m - prev;
            if (fabs(dm) / (prev > 0 ? prev : 1) > maxstep) maxstep = fabs(dm) / (prev > 0 ? prev : 1);
            if (i > 1 && dm * prevd < 0.0) ++reversals;
            if (dm != 0.0) prevd = dm;
        }
        prev = m;
    }
    for (after = 0; after < 400; ++after) {
        hd_get_stats(c, &st);
        if (st.light_converged) break;
        hd_render(c);
    }
    printf("TF slider on %s (%dx%d, %d steps, %s): %d trend reversals of %d, largest frame-to-frame change %.1f %%, %d renders to "
           "converge after release (%.1f s in all)\n",
           path, size, size, steps, cold ? "cold: hd_reset after each change, as before" : "warm start", reversals, steps - 2,
           100.0 * maxstep, after, now() - t0);
    fflush(stdout);
    hd_destroy(c);
    hd_volume_free(&vf);
    free(img);
}

int main(int argc, char **argv)
{
    int s = 64, frames = 300, cold = 20, every = 30, size = 512, puffs = 1, tfs = 1, i, nb = 0;
    float budgets[16];
    const char *head = "data/head.nrrd", *list = "50";
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--dims") && i + 1 < argc) s = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--cold") && i + 1 < argc) cold = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--every") && i + 1 < argc) every = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--budget") && i + 1 < argc) list = argv[++i];
        else if (!strcmp(argv[i], "--csv") && i + 1 < argc) {
            if (!(csv = fopen(argv[++i], "a"))) { fprintf(stderr, "cannot write %s\n", argv[i]); return 1; }
        }
        else if (!strcmp(argv[i], "--head") && i + 1 < argc) head = argv[++i];
        else if (!strcmp(argv[i], "--no-puff")) puffs = 0;
        else if (!strcmp(argv[i], "--no-tf")) tfs = 0;
        else if (!strcmp(argv[i], "--scale") && i + 1 < argc) {
            ++i;
            render_scale = !strcmp(argv[i], "auto") ? HD_RENDER_SCALE_AUTO : atoi(argv[i]);
        }
        else {
            fprintf(stderr, "usage: hdbench_animated [--dims S] [--frames F] [--cold C] [--every K] [--size P] [--budget ms[,ms...]] "
                            "[--scale N|auto] [--csv path] [--no-puff] [--no-tf] [--head path]\n");
            return 2;
        }
    }
    while (*list && nb < 16) { /* --budget ms[,ms...] */
        char *end;
        budgets[nb] = (float)(strtod(list, &end) * 1e-3);
        if (end == list || budgets[nb] < 0.0f) return 2;
        ++nb;
        list = *end == ',' ? end + 1 : end;
    }
    if (s < 8 || frames < 1 || size < 16 || nb == 0) return 2;
    if (puffs) {
        refs rf;
        int k;
        rf.every = every;
        rf.count = every > 0 ? frames / every + 1 : 0;
        rf.img = rf.count ? (uint8_t **)calloc((size_t)rf.count, sizeof(uint8_t *)) : NULL;
        for (k = 0; k < nb; ++k) bench_puff(s, frames, k == 0 ? cold : 0, rf.img ? &rf : NULL, size, budgets[k]);
        for (k = 0; k < rf.count; ++k) free(rf.img[k]);
        free(rf.img);
    }
    if (tfs) {
        bench_slider(head, 1);
        bench_slider(head, 0);
    }
    if (csv) fclose(csv);
    return 0;
}
