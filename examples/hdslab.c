/* hdslab - a controlled case for HD's brightness against PT_MS: a homogeneous slab of medium
   (the lower part of an N^3 box, optionally a thin top layer over a void over the rest) lit by
   one white directional light and viewed from above through a narrow camera. Prints the mean
   linear radiance per channel over the central quarter of the image for PT_MS, PT_SS, HD with
   direct light only, and HD with the surface (Marshak) and box boundaries, and HD / PT_MS.

     build/hdslab [WHAT] [KEY VALUE]...
       WHAT: letters, default "psdrb": p PT_MS, s PT_SS, d HD direct only, r HD RGB surface,
             g HD grey surface, b HD RGB box
       N 64          box voxels per axis
       zs 48         medium fills z < zs (so the slab is zs voxels deep)
       wall 0        > 0: only the top `wall` voxels of the slab, then (with gap) ...
       gap 0         ... `gap` empty voxels, then medium again down to z = 0
       ext 35        extinction (sigma_t of the medium per box side; sigma_t h = ext / N)
       alb 1         the global albedo; the TF colour c0 c1 c2 (0.95 0.5 0.35) is the per-channel
                     one (PT_MS multiplies by it at every vertex, HD's RGB diffusion uses it)
       theta 0       light's angle from the vertical, degrees (in the x-z plane)
       view 0        camera's angle from the vertical, degrees
       hdit 32       HD iterations; sweeps 32: red-black sweeps per iteration
       ptit 256      PT paths per pixel; size 64: image side; ds 1: illumination downsample

   With zs = 48 the slab is semi-infinite to within 1.5 % (ext 35): PT_MS's R at normal incidence
   (0.1631) is Chandrasekhar's exact a / (4 pi) * mu0 / (mu + mu0) * H(mu) H(mu0) for albedo 0.95
   (0.1631). docs/EVALUATION.md ("ct-flesh", why HD is too dark) gives the measured ratios. */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct slab_cfg {
    int n, zs, wall, gap, size, hdit, sweeps, ptit, ds;
    float ext, albedo, theta, view, col[3];
    unsigned char *vol;
} slab_cfg;

/* Renders one method on the slab and returns the mean radiance per channel over the central
   quarter of the image in out[3]. */
static void slab_run(const slab_cfg *s, const char *name, hd_method m, int rgb, hd_boundary bnd, int nodiff,
                     float *out)
{
    hd_desc d;
    hd_light l;
    hd_context ctx;
    float tf[8];
    double sum[3] = {0, 0, 0};
    float *img;
    int i, x, y, n = 0, iters = m == HD_METHOD_HD ? s->hdit : s->ptit;
    for (i = 0; i < 2; ++i) {
        tf[4 * i] = s->col[0]; tf[4 * i + 1] = s->col[1]; tf[4 * i + 2] = s->col[2]; tf[4 * i + 3] = (float)i;
    }
    memset(&d, 0, sizeof d);
    memset(&l, 0, sizeof l);
    l.type = HD_LIGHT_DIRECTIONAL;
    l.direction[0] = sinf(s->theta);
    l.direction[2] = -cosf(s->theta);
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = 1.0f;
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = s->n;
    d.volume.data = s->vol;
    d.volume.value_range[1] = 255.0f;
    d.transfer_function.rgba = tf;
    d.transfer_function.count = 2;
    d.lights = &l;
    d.light_count = 1;
    d.camera.eye[0] = 5.0f * sinf(s->view);
    d.camera.eye[2] = 5.0f * cosf(s->view);
    d.camera.up[1] = 1.0f;
    d.camera.fov_y = 6.0f;
    d.camera.width = d.camera.height = s->size;
    d.params.method = m;
    d.params.extinction = s->ext;
    d.params.albedo = s->albedo;
    d.params.diffusion_sweeps = s->sweeps;
    d.params.max_bounces = 100000; /* no cap: at albedo 0.95 a cap of 64 loses 4 % of the weight */
    d.params.rgb_scattering = rgb;
    d.params.diffusion_boundary = bnd;
    d.params.disable_diffusion = nodiff;
    d.params.step = 0.25f;
    d.params.illumination_downsample = s->ds;
    d.params.seed = 7;
    d.logger.func = hd_log_stderr;
    if (hd_create(&d, &ctx) != HD_SUCCESS) { fprintf(stderr, "hdslab: hd_create failed\n"); exit(1); }
    if (hd_iterate(ctx, iters) != HD_SUCCESS) { fprintf(stderr, "hdslab: hd_iterate failed\n"); exit(1); }
    img = (float *)malloc(sizeof(float) * 4 * (size_t)s->size * (size_t)s->size);
    if (img == NULL || hd_read_image_f32(ctx, img, (size_t)4 * s->size * s->size) != HD_SUCCESS) {
        fprintf(stderr, "hdslab: reading the image failed\n");
        exit(1);
    }
    for (y = s->size / 4; y < 3 * s->size / 4; ++y)
        for (x = s->size / 4; x < 3 * s->size / 4; ++x, ++n)
            for (i = 0; i < 3; ++i) sum[i] += img[4 * (y * s->size + x) + i];
    for (i = 0; i < 3; ++i) out[i] = (float)(sum[i] / n);
    printf("%-16s R %.5f G %.5f B %.5f\n", name, out[0], out[1], out[2]);
    fflush(stdout);
    free(img);
    hd_destroy(ctx);
}

static void slab_ratio(const float *v, const float *pt)
{
    printf("  / PT_MS        R %.4f G %.4f B %.4f\n", v[0] / pt[0], v[1] / pt[1], v[2] / pt[2]);
}

static int slab_set(slab_cfg *s, const char *k, double v)
{
    const double deg = 3.14159265358979 / 180.0;
    if (!strcmp(k, "N")) s->n = (int)v;
    else if (!strcmp(k, "zs")) s->zs = (int)v;
    else if (!strcmp(k, "wall")) s->wall = (int)v;
    else if (!strcmp(k, "gap")) s->gap = (int)v;
    else if (!strcmp(k, "ext")) s->ext = (float)v;
    else if (!strcmp(k, "alb")) s->albedo = (float)v;
    else if (!strcmp(k, "theta")) s->theta = (float)(v * deg);
    else if (!strcmp(k, "view")) s->view = (float)(v * deg);
    else if (!strcmp(k, "hdit")) s->hdit = (int)v;
    else if (!strcmp(k, "sweeps")) s->sweeps = (int)v;
    else if (!strcmp(k, "ptit")) s->ptit = (int)v;
    else if (!strcmp(k, "size")) s->size = (int)v;
    else if (!strcmp(k, "ds")) s->ds = (int)v;
    else if (!strcmp(k, "c0")) s->col[0] = (float)v;
    else if (!strcmp(k, "c1")) s->col[1] = (float)v;
    else if (!strcmp(k, "c2")) s->col[2] = (float)v;
    else return 0;
    return 1;
}

int main(int argc, char **argv)
{
    slab_cfg s = {64, 48, 0, 0, 64, 32, 32, 256, 1, 35.0f, 1.0f, 0.0f, 0.0f, {0.95f, 0.5f, 0.35f}, NULL};
    const char *what = argc > 1 ? argv[1] : "psdrb";
    float pt[3] = {0, 0, 0}, v[3];
    int i, x, y, z, have_pt;
    for (i = 2; i + 1 < argc; i += 2)
        if (!slab_set(&s, argv[i], atof(argv[i + 1]))) { fprintf(stderr, "hdslab: unknown key %s\n", argv[i]); return 2; }
    if (s.n < 4 || s.n > 512 || s.zs < 1 || s.zs > s.n || s.size < 4) { fprintf(stderr, "hdslab: bad sizes\n"); return 2; }
    s.vol = (unsigned char *)calloc((size_t)s.n * s.n * s.n, 1);
    if (s.vol == NULL) return 1;
    for (z = 0; z < s.zs; ++z) {
        int medium = s.wall == 0 || z >= s.zs - s.wall || (s.gap > 0 && z < s.zs - s.wall - s.gap);
        for (y = 0; y < s.n; ++y)
            for (x = 0; x < s.n; ++x) s.vol[((size_t)z * s.n + y) * s.n + x] = medium ? 255 : 0;
    }
    printf("N %d zs %d wall %d gap %d ext %.2f (sigma_t h %.3f) albedo %.3f colour %.2f %.2f %.2f theta %.1f view %.1f ds %d\n",
           s.n, s.zs, s.wall, s.gap, s.ext, s.ext / s.n, s.albedo, s.col[0], s.col[1], s.col[2],
           s.theta * 57.2957795, s.view * 57.2957795, s.ds);
    have_pt = strchr(what, 'p') != NULL;
    if (have_pt) slab_run(&s, "PT_MS", HD_METHOD_PT_MS, 0, HD_BOUNDARY_BOX, 0, pt);
    if (strchr(what, 's')) slab_run(&s, "PT_SS", HD_METHOD_PT_SS, 0, HD_BOUNDARY_BOX, 0, v);
    if (strchr(what, 'd')) slab_run(&s, "HD direct only", HD_METHOD_HD, 1, HD_BOUNDARY_SURFACE, 1, v);
    if (strchr(what, 'r')) { slab_run(&s, "HD RGB surface", HD_METHOD_HD, 1, HD_BOUNDARY_SURFACE, 0, v); if (have_pt) slab_ratio(v, pt); }
    if (strchr(what, 'g')) { slab_run(&s, "HD grey surface", HD_METHOD_HD, 0, HD_BOUNDARY_SURFACE, 0, v); if (have_pt) slab_ratio(v, pt); }
    if (strchr(what, 'b')) { slab_run(&s, "HD RGB box", HD_METHOD_HD, 1, HD_BOUNDARY_BOX, 0, v); if (have_pt) slab_ratio(v, pt); }
    free(s.vol);
    return 0;
}
