/* hdbench_env - the environment light on the head CT (CPU backend), against one directional
   light, in one process: the evaluation's scene (ct-skin, extinction 100, albedo 0.9, the face
   camera, hdrender's crop box), the key light, or the map given (a Radiance .hdr, top on +z as
   hdrender puts it) at intensity --intensity, in colour and averaged to grey. Prints
   - the HD iteration's cost: light iterations (hd_refine) of the contexts interleaved in
     rounds, the median seconds per iteration of each and the ratio to the directional light's;
     with --directions also one directional light from each of the 6 axis directions, and the
     maps' ratios to the mean over the 7 directional lights (the walk's cost depends on the
     direction: the head CT is shortest along z);
   - hd_stats.method_bytes of each, and what the map's tables add per texel;
   - PSNR of HD after 32 iterations against PT_MS at --paths paths per pixel (two halves with
     independent seeds: the reference's own PSNR too), tone map sRGB(clamp(8 L)) per channel,
     for the directional light and the coloured map.
   Figures, not a test. Usage: hdbench_env [--size N] [--paths N] [--rounds N] [--intensity X]
   [--directions] [--cost-only] ENV.hdr [data/head.nrrd] (--cost-only: no PSNR part) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "examples/hd_tf.h"
#include "examples/hd_crop.h"
#include "examples/hd_tonemap.h"
#include "examples/hd_env.h"
#include "hd_bench_median.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_ROUNDS 64

static double mean_rgb(const float *a, int n)
{
    double s = 0.0;
    int i;
    for (i = 0; i < n; ++i) s += (a[4 * i] + a[4 * i + 1] + a[4 * i + 2]) / 3.0;
    return s / n;
}

static hd_desc g_desc;
static hd_light g_key;

/* A context of method m lit by the directional light l (NULL: the key light; env NULL) or env
   alone. */
static hd_context make_lit(hd_method m, const hd_light *l, const hd_environment *env, unsigned seed)
{
    hd_desc d = g_desc;
    hd_context h;
    d.params.method = m;
    d.params.seed = seed;
    if (l) d.lights = l;
    if (hd_create(&d, &h) != HD_SUCCESS) exit(1);
    if (env && (hd_set_environment(h, env) != HD_SUCCESS || hd_set_lights(h, NULL, 0) != HD_SUCCESS)) exit(1);
    return h;
}
static hd_context make(hd_method m, const hd_environment *env, unsigned seed) { return make_lit(m, NULL, env, seed); }

/* PT_MS at `paths` paths per pixel in two halves; the mean into ref, the halves' PSNR returned. */
static double reference(const hd_environment *env, int paths, float *ref, float *tmp, int npix)
{
    hd_context a = make(HD_METHOD_PT_MS, env, 101u), b = make(HD_METHOD_PT_MS, env, 202u);
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

int main(int argc, char **argv)
{
    const char *env_path = NULL, *vol_path = "data/head.nrrd";
    int size = 128, paths = 1024, rounds = 8, i, r, k, npix, dirs = 0, cost_only = 0, nctx;
    float intensity = 0.2f;
    static const float up[3] = {0.0f, 0.0f, 1.0f};
    hd_volume_file vf;
    hdx_tf tf;
    hd_environment env, grey;
    char err[512];
    hd_context h[9];
    hd_light axis[6];
    double sec[9][MAX_ROUNDS], sdir[9][MAX_ROUNDS], med[9], mean_dir;
    static const char *names[9] = {"one directional light", "environment (colour)", "environment (grey)",
                                   "directional toward +x", "directional toward -x", "directional toward +y",
                                   "directional toward -y", "directional toward +z", "directional toward -z"};
    float *img, *ref, *tmp, *grey_rgb;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc) size = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--paths") && i + 1 < argc) paths = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--rounds") && i + 1 < argc) rounds = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--intensity") && i + 1 < argc) intensity = (float)atof(argv[++i]);
        else if (!strcmp(argv[i], "--directions")) dirs = 1;
        else if (!strcmp(argv[i], "--cost-only")) cost_only = 1;
        else if (!env_path) env_path = argv[i];
        else vol_path = argv[i];
    }
    if (!env_path || size < 8 || paths < 2 || rounds < 1 || rounds > MAX_ROUNDS) {
        fprintf(stderr, "usage: hdbench_env [--size N] [--paths N] [--rounds N<=64] [--intensity X] ENV.hdr [data/head.nrrd]\n");
        return 2;
    }
    if (!hdx_env_load(env_path, &env, err, sizeof err)) { fprintf(stderr, "hdbench_env: %s\n", err); return 1; }
    env.intensity = intensity;
    hdx_env_rotation(up, 0.0f, env.rotation);
    grey = env;
    grey_rgb = (float *)malloc((size_t)env.width * env.height * 3 * sizeof(float));
    for (i = 0; i < env.width * env.height; ++i) {
        float m = (env.rgb[3 * i] + env.rgb[3 * i + 1] + env.rgb[3 * i + 2]) / 3.0f;
        grey_rgb[3 * i] = grey_rgb[3 * i + 1] = grey_rgb[3 * i + 2] = m;
    }
    grey.rgb = grey_rgb;
    if (hd_volume_load_nrrd(vol_path, &vf, NULL) != HD_SUCCESS) { fprintf(stderr, "hdbench_env: cannot load %s\n", vol_path); return 1; }
    hdx_tf_preset("ct-skin", &tf);
    memset(&g_desc, 0, sizeof g_desc);
    hdx_tf_use(&g_desc, &vf.desc, &tf);
    g_key.type = HD_LIGHT_DIRECTIONAL;
    g_key.direction[0] = -0.6452f; g_key.direction[1] = -0.3560f; g_key.direction[2] = -0.6760f;
    g_key.intensity = 1.0f;
    g_desc.lights = &g_key;
    g_desc.light_count = 1;
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
    nctx = dirs ? 9 : 3;
    h[0] = make(HD_METHOD_HD, NULL, 1u);
    h[1] = make(HD_METHOD_HD, &env, 1u);
    h[2] = make(HD_METHOD_HD, &grey, 1u);
    for (k = 3; k < nctx; ++k) {
        hd_light *l = &axis[k - 3];
        *l = g_key;
        l->direction[0] = l->direction[1] = l->direction[2] = 0.0f;
        l->direction[(k - 3) / 2] = (k - 3) % 2 == 0 ? 1.0f : -1.0f;
        h[k] = make_lit(HD_METHOD_HD, l, NULL, 1u);
    }
    for (k = 0; k < nctx; ++k) hd_refine(h[k], 1); /* uploads and the first iteration outside the timing */
    for (r = 0; r < rounds; ++r)
        for (k = 0; k < nctx; ++k) {
            hd_stats a, b;
            hd_get_stats(h[k], &a);
            if (hd_refine(h[k], 2) != HD_SUCCESS) return 1;
            hd_get_stats(h[k], &b);
            sec[k][r] = (b.seconds_direct + b.seconds_diffusion - a.seconds_direct - a.seconds_diffusion) / 2.0;
            sdir[k][r] = (b.seconds_direct - a.seconds_direct) / 2.0;
        }
    printf("hdbench_env: head CT %dx%dx%d, map %s %dx%d, HD light iterations, %d interleaved rounds of 2\n", vf.desc.dims[0],
           vf.desc.dims[1], vf.desc.dims[2], env_path, env.width, env.height, rounds);
    for (k = 0, mean_dir = 0.0; k < nctx; ++k) {
        hd_stats st;
        med[k] = hdb_median(sec[k], rounds);
        if (k == 0 || k >= 3) mean_dir += med[k] / (nctx - 2);
        hd_get_stats(h[k], &st);
        printf("  %-24s %7.3f s per iteration (%.2fx), direct light %.3f s  %d channel%s  method_bytes %zu\n", names[k], med[k],
               med[k] / med[0], hdb_median(sdir[k], rounds), st.illumination_channels, st.illumination_channels == 1 ? " " : "s",
               st.method_bytes);
    }
    printf("  the map's tables: %zu bytes, %.2f per texel\n", (4 * (size_t)env.width * env.height + 2 * (size_t)env.height + 1) * sizeof(float),
           (4.0 * env.width * env.height + 2.0 * env.height + 1.0) * 4.0 / ((double)env.width * env.height));
    if (dirs)
        printf("  mean over the 7 directional lights %.3f s: colour map %.2fx, grey map %.2fx (the key light %.2fx)\n", mean_dir,
               med[1] / mean_dir, med[2] / mean_dir, med[0] / mean_dir);
    for (k = 0; k < nctx; ++k) hd_destroy(h[k]);

    /* quality: HD after 32 iterations against PT_MS */
    for (k = 0; k < (cost_only ? 0 : 2); ++k) {
        const hd_environment *e = k == 0 ? NULL : &env;
        double floor_db = reference(e, paths, ref, tmp, npix), p;
        hd_context hd = make(HD_METHOD_HD, e, 7u);
        if (hd_iterate(hd, 32) != HD_SUCCESS) return 1;
        hd_read_image_f32(hd, img, (size_t)npix * 4);
        p = hdx_psnr_linear(img, ref, npix, 8.0);
        printf("  %-24s %d^2: HD (32 it) vs PT_MS (%d paths) %.2f dB; reference halves %.2f dB; mean radiance HD %.4f, PT_MS %.4f\n",
               names[k], size, paths, p, floor_db, mean_rgb(img, npix), mean_rgb(ref, npix));
        hd_destroy(hd);
    }
    free(img); free(ref); free(tmp); free(grey_rgb);
    free((void *)env.rgb);
    hd_volume_free(&vf);
    return 0;
}
