/* hdbench_lights - area lights and the light choice on the head CT (CPU backend), in one
   process: the evaluation's scene (ct-skin, extinction 100, albedo 0.9, the face camera,
   hdrender's crop box) lit by the key light (directional), by a quad light of side 0.5 at 1.2
   from the centre in the key light's direction, facing the head, of radiance 1.44 / 0.25 (about
   the key light's irradiance), and by a sphere of radius 0.25 there. Prints
   - the HD iteration's cost: light iterations (hd_refine) of the contexts interleaved in
     rounds, the median seconds per iteration of each and the ratio to the directional light's;
   - PSNR of HD after 32 iterations against PT_MS at --paths paths per pixel (two halves with
     independent seeds: the reference's own PSNR too), tone map sRGB(clamp(8 L)) per channel,
     for the directional light and the quad;
   - the light choice: the key light beside a fill light 1/20 as strong (directional, from the
     other side): the per-sample variance of E (summed over the grid, over the sum of E^2) over
     --samples iterations, with the light drawn uniformly and by its estimated light (the
     library's default), and the seconds per iteration of both.
   Figures, not a test. Usage: hdbench_lights [--size N] [--paths N] [--rounds N] [--samples N]
   [data/head.nrrd] */
#define HYBRIDDIFF_TESTING /* the test hooks (src/hd_test_hooks.h): the uniform light choice */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "examples/hd_tf.h"
#include "examples/hd_crop.h"
#include "examples/hd_tonemap.h"
#include "hd_bench_median.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_ROUNDS 64
#define NCTX 3

static double mean_rgb(const float *a, int n)
{
    double s = 0.0;
    int i;
    for (i = 0; i < n; ++i) s += (a[4 * i] + a[4 * i + 1] + a[4 * i + 2]) / 3.0;
    return s / n;
}

static hd_desc g_desc;
static hd_light g_lights[NCTX];

/* A context of method m lit by lights l[0..n). */
static hd_context make(hd_method m, const hd_light *l, int n, unsigned seed)
{
    hd_desc d = g_desc;
    hd_context h;
    d.params.method = m;
    d.params.seed = seed;
    d.lights = l;
    d.light_count = n;
    if (hd_create(&d, &h) != HD_SUCCESS) exit(1);
    return h;
}

/* PT_MS at `paths` paths per pixel in two halves; the mean into ref, the halves' PSNR returned. */
static double reference(const hd_light *l, int paths, float *ref, float *tmp, int npix)
{
    hd_context a = make(HD_METHOD_PT_MS, l, 1, 101u), b = make(HD_METHOD_PT_MS, l, 1, 202u);
    double p;
    int i;
    if (hd_iterate(a, paths / 2) != HD_SUCCESS || hd_iterate(b, paths / 2) != HD_SUCCESS) exit(1);
    hd_read_image_f32(a, ref, (size_t)npix * 4);
    hd_read_image_f32(b, tmp, (size_t)npix * 4);
    p = hdx_psnr_linear(ref, tmp, npix, 8.0);
    for (i = 0; i < 4 * npix; ++i) ref[i] = 0.5f * (ref[i] + tmp[i]);
    hd_destroy(a);
    hd_destroy(b);
    return p;
}

/* The per-sample variance of E over n light iterations, relative: the sum over the grid of each
   voxel's variance of X_k = k E_k - (k - 1) E_{k-1} over the sum of its mean squared; and the
   median seconds per iteration. */
static double choice_variance(hd_context h, int uniform, int n, double *sec)
{
    hd_stats st;
    size_t nv, i;
    float *e, *prev;
    double *s1, *s2, var = 0.0, m2 = 0.0, t[MAX_ROUNDS * 4];
    int k;
    if (hd__test_light_uniform(h, uniform) != HD_SUCCESS || hd_reset(h) != HD_SUCCESS || hd_refine(h, 1) != HD_SUCCESS) exit(1);
    hd_get_stats(h, &st);
    nv = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] * st.illumination_channels;
    e = (float *)malloc(nv * sizeof(float));
    prev = (float *)malloc(nv * sizeof(float));
    s1 = (double *)calloc(nv, sizeof(double));
    s2 = (double *)calloc(nv, sizeof(double));
    hd_read_illumination(h, HD_ILLUMINATION_DIRECT, prev, nv);
    for (i = 0; i < nv; ++i) { s1[i] = prev[i]; s2[i] = (double)prev[i] * prev[i]; }
    for (k = 2; k <= n; ++k) {
        hd_stats a, b;
        hd_get_stats(h, &a);
        if (hd_refine(h, 1) != HD_SUCCESS) exit(1);
        hd_get_stats(h, &b);
        t[k - 2] = b.seconds_direct + b.seconds_diffusion - a.seconds_direct - a.seconds_diffusion;
        hd_read_illumination(h, HD_ILLUMINATION_DIRECT, e, nv);
        for (i = 0; i < nv; ++i) {
            double x = k * (double)e[i] - (k - 1.0) * prev[i];
            s1[i] += x; s2[i] += x * x;
        }
        memcpy(prev, e, nv * sizeof(float));
    }
    for (i = 0; i < nv; ++i) {
        double m = s1[i] / n;
        var += s2[i] / n - m * m;
        m2 += m * m;
    }
    *sec = hdb_median(t, n - 1);
    free(e); free(prev); free(s1); free(s2);
    return var / m2;
}

int main(int argc, char **argv)
{
    const char *vol_path = "data/head.nrrd";
    int size = 128, paths = 1024, rounds = 8, samples = 32, i, r, k, npix;
    hd_volume_file vf;
    hdx_tf tf;
    hd_context h[NCTX];
    double sec[NCTX][MAX_ROUNDS], med[NCTX], kd[3] = {-0.6452, -0.3560, -0.6760}, len, c[3], e1[3], e2[3], s = 0.5;
    static const char *names[NCTX] = {"one directional light", "quad light", "sphere light"};
    float *img, *ref, *tmp;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--paths") && i + 1 < argc) paths = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--samples") && i + 1 < argc) samples = atoi(argv[++i]);
        else vol_path = argv[i];
    }
    if (size < 8 || paths < 2 || rounds < 1 || rounds > MAX_ROUNDS || samples < 4 || samples > 4 * MAX_ROUNDS) {
        fprintf(stderr, "usage: hdbench_lights [--size N] [--paths N] [--rounds N<=64] [--samples 4..256] [data/head.nrrd]\n");
        return 2;
    }
    if (hd_volume_load_nrrd(vol_path, &vf, NULL) != HD_SUCCESS) { fprintf(stderr, "hdbench_lights: cannot load %s\n", vol_path); return 1; }
    hdx_tf_preset("ct-skin", &tf);
    memset(&g_desc, 0, sizeof g_desc);
    hdx_tf_use(&g_desc, &vf.desc, &tf);
    memset(g_lights, 0, sizeof g_lights);
    g_lights[0].type = HD_LIGHT_DIRECTIONAL;
    for (i = 0; i < 3; ++i) g_lights[0].direction[i] = (float)kd[i];
    g_lights[0].intensity = 1.0f;
    /* the quad: centre 1.2 against the key light's direction, normal along it, edges across */
    len = sqrt(kd[0] * kd[0] + kd[1] * kd[1] + kd[2] * kd[2]);
    for (i = 0; i < 3; ++i) { kd[i] /= len; c[i] = -1.2 * kd[i]; }
    len = sqrt(kd[0] * kd[0] + kd[1] * kd[1]);
    e1[0] = -kd[1] / len; e1[1] = kd[0] / len; e1[2] = 0.0; /* horizontal, across the direction */
    e2[0] = kd[1] * e1[2] - kd[2] * e1[1]; e2[1] = kd[2] * e1[0] - kd[0] * e1[2]; e2[2] = kd[0] * e1[1] - kd[1] * e1[0];
    /* e1 x (n x e1) = n for unit orthogonal e1, n: the quad emits along the key light's travel */
    g_lights[1].type = HD_LIGHT_QUAD;
    g_lights[1].intensity = (float)(1.44 / (s * s));
    for (i = 0; i < 3; ++i) {
        g_lights[1].edge1[i] = (float)(s * e1[i]);
        g_lights[1].edge2[i] = (float)(s * e2[i]);
        g_lights[1].position[i] = (float)(c[i] - 0.5 * s * (e1[i] + e2[i]));
    }
    g_lights[2].type = HD_LIGHT_SPHERE;
    g_lights[2].radius = 0.25f;
    g_lights[2].intensity = (float)(1.44 / (3.14159265 * 0.25 * 0.25));
    for (i = 0; i < 3; ++i) g_lights[2].position[i] = (float)c[i];
    g_desc.camera.eye[0] = 0.6f; g_desc.camera.eye[1] = 1.65f; g_desc.camera.eye[2] = 0.3f;
    g_desc.camera.target[2] = -0.04f;
    g_desc.camera.up[2] = 1.0f;
    g_desc.camera.fov_y = 40.0f;
    g_desc.camera.width = g_desc.camera.height = size;
    g_desc.params.extinction = 100.0f;
    g_desc.params.albedo = 0.9f;
    g_desc.logger.func = hd_log_stderr;
    hdx_known_crop(vol_path, vf.desc.dims, &g_desc.params);
    npix = size * size;
    img = (float *)malloc((size_t)npix * 4 * sizeof(float));
    ref = (float *)malloc((size_t)npix * 4 * sizeof(float));
    tmp = (float *)malloc((size_t)npix * 4 * sizeof(float));

    /* cost: interleaved rounds of 2 light iterations per context */
    for (k = 0; k < NCTX; ++k) h[k] = make(HD_METHOD_HD, &g_lights[k], 1, 1u);
    for (k = 0; k < NCTX; ++k) hd_refine(h[k], 1); /* uploads and the first iteration outside the timing */
    for (r = 0; r < rounds; ++r)
        for (k = 0; k < NCTX; ++k) {
            hd_stats a, b;
            hd_get_stats(h[k], &a);
            if (hd_refine(h[k], 2) != HD_SUCCESS) return 1;
            hd_get_stats(h[k], &b);
            sec[k][r] = (b.seconds_direct + b.seconds_diffusion - a.seconds_direct - a.seconds_diffusion) / 2.0;
        }
    printf("hdbench_lights: head CT %dx%dx%d, HD light iterations, %d interleaved rounds of 2\n", vf.desc.dims[0], vf.desc.dims[1],
           vf.desc.dims[2], rounds);
    printf("  quad: corner %.3f,%.3f,%.3f edges %.3f,%.3f,%.3f and %.3f,%.3f,%.3f, radiance %.2f; sphere radius 0.25, radiance %.2f\n",
           g_lights[1].position[0], g_lights[1].position[1], g_lights[1].position[2], g_lights[1].edge1[0], g_lights[1].edge1[1],
           g_lights[1].edge1[2], g_lights[1].edge2[0], g_lights[1].edge2[1], g_lights[1].edge2[2], g_lights[1].intensity,
           g_lights[2].intensity);
    for (k = 0; k < NCTX; ++k) {
        med[k] = hdb_median(sec[k], rounds);
        printf("  %-24s %7.3f s per iteration (%.2fx)\n", names[k], med[k], med[k] / med[0]);
    }
    for (k = 0; k < NCTX; ++k) hd_destroy(h[k]);

    /* quality: HD after 32 iterations against PT_MS */
    for (k = 0; k < 2; ++k) {
        double floor_db = reference(&g_lights[k], paths, ref, tmp, npix), p;
        hd_context hd = make(HD_METHOD_HD, &g_lights[k], 1, 7u);
        if (hd_iterate(hd, 32) != HD_SUCCESS) return 1;
        hd_read_image_f32(hd, img, (size_t)npix * 4);
        p = hdx_psnr_linear(img, ref, npix, 8.0);
        printf("  %-24s %d^2: HD (32 it) vs PT_MS (%d paths) %.2f dB; reference halves %.2f dB; mean radiance HD %.4f, PT_MS %.4f\n",
               names[k], size, paths, p, floor_db, mean_rgb(img, npix), mean_rgb(ref, npix));
        hd_destroy(hd);
    }

    /* the light choice: the key light and a fill 1/20 as strong from the other side */
    {
        hd_light two[2];
        hd_context hc;
        double vu, ve, tu, te;
        two[0] = g_lights[0];
        two[1] = g_lights[0];
        two[1].direction[0] = -two[1].direction[0];
        two[1].direction[1] = -two[1].direction[1];
        two[1].intensity = 0.05f;
        hc = make(HD_METHOD_HD, two, 2, 3u);
        vu = choice_variance(hc, 1, samples, &tu);
        ve = choice_variance(hc, 0, samples, &te);
        printf("  key + fill 1/20: per-sample variance of E, relative, over %d iterations: uniform %.4f, by estimate %.4f (%.2fx less); "
               "%.3f vs %.3f s per iteration\n", samples, vu, ve, vu / ve, tu, te);
        hd_destroy(hc);
    }
    free(img); free(ref); free(tmp);
    hd_volume_free(&vf);
    return 0;
}
