/* hdbench_energy - HD's energy balance against the path-traced references (CPU backend).

   For each volume and TF it renders PT_MS and PT_SS references (two independent halves each,
   cached under --cache by a hash of every setting that changes them) and HD in a list of
   configurations, each with its light converged (multigrid CG, --steps steps per iteration, for
   --iters iterations), and prints per configuration: the mean linear radiance over PT_MS's (and
   over PT_SS's), PSNR against PT_MS (tone map of docs/EVALUATION.md: exposure 8, sRGB, clamped)
   and HD's seconds per iteration with the library's default solver (red-black sweeps), timed
   after the quality run on a fresh context.

     build/hdbench_energy [--size N] [--ref-paths P] [--iters I] [--steps S] [--time-iters T]
                          [--cases LIST] [--configs LIST] [--cache DIR] [--threads T] [--images DIR]
     build/hdbench_energy --cost A,B [--rounds R] [--size N] [--cases LIST] [--threads T]
       cases:   head-skin head-bone brainsmall skull (comma separated; default all)
       configs: direct, direct2 (HD without diffusion on the grid /1, /2: against PT_SS), box1
                surface1 box2 surface2 (boundary and illumination_downsample), rgb1 rgb2 (surface
                boundary with params.rgb_scattering); default direct,box2,surface2,box1,surface1
       --images DIR: per case and configuration a PNG of HD, PT_MS and their signed difference
                side by side (DIR/<case>-<config>.png), and per configuration a line of figures
                by image region (where the light is missing or in excess: see region_report)
       --cost A,B: no references; the seconds of one iteration of configurations A and B, timed
                alternately in one process (cost_case), for the iteration-cost target

   Volumes: data/head.nrrd and data/brainsmall.nrrd (scripts/fetch-data), data/skull.nrrd
   (scripts/fetch-skull). Figures in docs/EVALUATION.md ("Energy balance"). */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "examples/hd_tf.h"
#include "examples/hd_png.h"
#include "examples/hd_tonemap.h"
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

typedef struct ecase {
    const char *name, *path, *tf; /* tf: a preset, or "skull" (bone of the CGAL skull) */
    float eye[3], up[3];
} ecase;

/* The head CT's camera is hdrender's default (face +y, top +z); brainsmall's is hdrender's for it
   (face -x, top -y); the skull is seen as the head. */
static const ecase k_cases[] = {
    {"head-skin", "data/head.nrrd", "ct-skin", {0.6f, 1.65f, 0.3f}, {0, 0, 1}},
    {"head-bone", "data/head.nrrd", "ct-bone", {0.6f, 1.65f, 0.3f}, {0, 0, 1}},
    {"brainsmall", "data/brainsmall.nrrd", "ramp", {-0.95f, -0.75f, 1.25f}, {0, -1, 0}},
    {"skull", "data/skull.nrrd", "skull", {0.6f, 1.65f, 0.3f}, {0, 0, 1}},
};
#define NCASES ((int)(sizeof k_cases / sizeof k_cases[0]))

typedef struct econfig {
    const char *name;
    hd_boundary boundary;
    int downsample, nodiff, rgb; /* rgb: params.rgb_scattering */
} econfig;

static const econfig k_configs[] = {
    {"direct", HD_BOUNDARY_BOX, 1, 1, 0},
    {"direct2", HD_BOUNDARY_BOX, 2, 1, 0},
    {"box1", HD_BOUNDARY_BOX, 1, 0, 0},
    {"surface1", HD_BOUNDARY_SURFACE, 1, 0, 0},
    {"box2", HD_BOUNDARY_BOX, 2, 0, 0},
    {"surface2", HD_BOUNDARY_SURFACE, 2, 0, 0},
    {"rgb2", HD_BOUNDARY_SURFACE, 2, 0, 1},
    {"rgb1", HD_BOUNDARY_SURFACE, 1, 0, 1},
};
#define NCONFIGS ((int)(sizeof k_configs / sizeof k_configs[0]))

/* The scene: the head scene's optics, key light and exposure (examples/eval/head.scene). */
static const float k_light[3] = {-0.6452f, -0.3560f, -0.6760f};
#define EXTINCTION 100.0f
#define ALBEDO 0.9f
#define EXPOSURE 8.0f
#define MAX_BOUNCES 64

static int g_size = 128, g_ref_paths = 512, g_iters = 32, g_steps = 4, g_time_iters = 4, g_threads = 0;
static int g_rounds = 9; /* --rounds: the alternating rounds of --cost */
static const char *g_cache = "build/energy-cache";
static const char *g_images = NULL; /* --images: where the difference images go (NULL: none) */

static void die(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("hdbench_energy: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    exit(1);
}

/* Warnings and errors only: the info lines of every context would bury the table. */
static void log_quiet(void *user, hd_log_level level, hd_result code, const char *message, const char *file, int line)
{
    if (level <= HD_LOG_WARNING) hd_log_stderr(user, level, code, message, file, line);
}

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

typedef struct scene {
    const ecase *c;
    hd_volume_file vol;
    hdx_tf tf;
} scene;

static void load_scene(scene *s, const ecase *c)
{
    hd_logger log;
    hd_result r;
    memset(s, 0, sizeof *s);
    memset(&log, 0, sizeof log);
    log.func = log_quiet;
    s->c = c;
    r = hd_volume_load(c->path, &s->vol, &log);
    if (r != HD_SUCCESS) die("%s: %s (scripts/fetch-data, scripts/fetch-skull)", c->path, hd_result_string(r));
    if (strcmp(c->tf, "skull") == 0) {
        /* The CGAL skull's bone (its mesh demo's isovalue is 2.9): ct-bone's colours, transparent
           below 2.5, opaque from 3.5. */
        static const char text[] = "domain 0 6\n0 0.95 0.9 0.8 0\n2.5 0.95 0.9 0.8 0\n"
                                   "3.5 1 0.97 0.9 1\n6 1 0.97 0.9 1\n";
        char err[256];
        if (!hdx_tf_parse(text, sizeof text - 1, "skull", &s->tf, err, sizeof err)) die("%s", err);
    } else {
        if (!hdx_tf_preset(c->tf, &s->tf)) die("no TF preset %s", c->tf);
        if (s->tf.data_domain) hdx_tf_set_domain(&s->tf, s->vol.value_min, s->vol.value_max);
    }
}

static hd_context make_ctx(const scene *s, hd_method m, const econfig *cfg, hd_solver solver, int sweeps,
                           uint32_t seed)
{
    hd_desc d;
    hd_light L;
    hd_context ctx;
    hd_result r;
    memset(&d, 0, sizeof d);
    memset(&L, 0, sizeof L);
    L.type = HD_LIGHT_DIRECTIONAL;
    memcpy(L.direction, k_light, sizeof L.direction);
    L.color[0] = L.color[1] = L.color[2] = 1.0f;
    L.intensity = 1.0f;
    hdx_tf_use(&d, &s->vol.desc, &s->tf);
    d.lights = &L;
    d.light_count = 1;
    memcpy(d.camera.eye, s->c->eye, sizeof d.camera.eye);
    memcpy(d.camera.up, s->c->up, sizeof d.camera.up);
    d.camera.fov_y = 40.0f;
    d.camera.width = d.camera.height = g_size;
    d.params.method = m;
    d.params.extinction = EXTINCTION;
    d.params.albedo = ALBEDO;
    d.params.max_bounces = MAX_BOUNCES;
    d.params.step = 0.5f;
    d.params.frame_window = 8;
    d.params.seed = seed;
    d.params.solver = solver;
    d.params.diffusion_sweeps = sweeps;
    if (cfg != NULL) {
        d.params.diffusion_boundary = cfg->boundary;
        d.params.illumination_downsample = cfg->downsample;
        d.params.disable_diffusion = cfg->nodiff;
        d.params.rgb_scattering = cfg->rgb;
    }
    d.threads = g_threads;
    d.logger.func = log_quiet;
    r = hd_create(&d, &ctx);
    if (r != HD_SUCCESS) die("hd_create: %s", hd_result_string(r));
    return ctx;
}

static void run(hd_context ctx, int n, float *img)
{
    hd_result r = hd_iterate(ctx, n);
    if (r != HD_SUCCESS) die("hd_iterate: %s", hd_result_string(r));
    if (img != NULL) {
        r = hd_read_image_f32(ctx, img, (size_t)4 * g_size * g_size);
        if (r != HD_SUCCESS) die("hd_read_image_f32: %s", hd_result_string(r));
    }
}

/* ---- metrics ---------------------------------------------------------------------------------- */
static double tonemap(double v) { return hdx_srgb(EXPOSURE * v); }

static double mean_of(const float *img, size_t npix)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < npix; ++i) s += (double)img[4 * i] + img[4 * i + 1] + img[4 * i + 2];
    return s / (3.0 * (double)npix);
}

/* The MSE over RGB of image a scaled by k against b, both linear and tone-mapped on the fly
   (hdx_mse_linear). PSNR after scaling HD by the ratio of the means separates a global energy
   error (the scaled PSNR is high) from one of the image's structure (it stays low). */
static double mse_of(const float *a, const float *b, size_t npix, double k)
{
    return hdx_mse_linear(a, EXPOSURE * k, b, EXPOSURE, npix);
}

/* ---- where the light differs: regions and images ---------------------------------------------
   Pixels are split by PT_MS's coverage (its alpha, the share of paths that hit the medium) and
   PT_SS's brightness (the direct light the medium receives there):
   - edge: the silhouette, covered pixels (alpha >= 0.02) that are partly covered (alpha < 0.98)
     or lie within 2 pixels of an uncovered one (alpha < 0.5);
   - lit / shadow: the other covered pixels, split at the median of PT_SS's luminance among them
     (surfaces facing the light, and the side away from it);
   - background: the rest.
   Per region: its share of the pixels, HD's light over PT_MS's (sums), f = (HD - SS) / (MS - SS),
   the share of PT_MS's scattered light HD finds there, and the region's share of the squared
   error behind the PSNR. */
enum { REG_EDGE, REG_LIT, REG_SHADOW, REG_BG, NREG };
static const char *const k_reg_names[NREG] = {"edge", "lit", "shadow", "bg"};

static double lum(const float *p) { return ((double)p[0] + p[1] + p[2]) / 3.0; }

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

/* The region of every pixel, from the references (the same for every configuration). */
static void regions_of(const float *ms, const float *ss, int n, unsigned char *reg)
{
    size_t npix = (size_t)n * n, i, nin = 0;
    double *v = (double *)malloc(sizeof(double) * npix), med = 0.0;
    int x, y, dx, dy;
    if (v == NULL) die("out of memory");
    for (y = 0; y < n; ++y)
        for (x = 0; x < n; ++x) {
            size_t p = (size_t)y * n + x;
            float a = ms[4 * p + 3];
            int near_bg = 0;
            for (dy = -2; dy <= 2 && !near_bg; ++dy)
                for (dx = -2; dx <= 2 && !near_bg; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (xx >= 0 && yy >= 0 && xx < n && yy < n && ms[4 * ((size_t)yy * n + xx) + 3] < 0.5f) near_bg = 1;
                }
            if (a < 0.02f) reg[p] = REG_BG;
            else if (a < 0.98f || near_bg) reg[p] = REG_EDGE;
            else {
                reg[p] = REG_LIT; /* split below */
                v[nin++] = lum(ss + 4 * p);
            }
        }
    if (nin > 0) {
        qsort(v, nin, sizeof(double), cmp_double);
        med = v[nin / 2];
    }
    for (i = 0; i < npix; ++i)
        if (reg[i] == REG_LIT && lum(ss + 4 * i) < med) reg[i] = REG_SHADOW;
    free(v);
}

/* Prints the regions' figures for HD's image hd (see above), and the quartiles of the per-pixel
   ratio HD / PT_MS over the covered pixels outside the silhouette. */
static void region_report(const float *hd, const float *ms, const float *ss, const unsigned char *reg, size_t npix)
{
    double sh[NREG] = {0}, sm[NREG] = {0}, s1[NREG] = {0}, se[NREG] = {0}, cnt[NREG] = {0}, tot = 0.0;
    double *r = (double *)malloc(sizeof(double) * npix);
    size_t i, nr = 0;
    int k, c;
    if (r == NULL) die("out of memory");
    for (i = 0; i < npix; ++i) {
        double e = 0.0, m = lum(ms + 4 * i);
        for (c = 0; c < 3; ++c) {
            double d = tonemap(hd[4 * i + c]) - tonemap(ms[4 * i + c]);
            e += d * d;
        }
        k = reg[i];
        sh[k] += lum(hd + 4 * i);
        sm[k] += m;
        s1[k] += lum(ss + 4 * i);
        se[k] += e;
        cnt[k] += 1.0;
        tot += e;
        if ((k == REG_LIT || k == REG_SHADOW) && m > 0.0) r[nr++] = lum(hd + 4 * i) / m;
    }
    printf("    regions (pixels %%, HD/PT_MS, f, error %%):");
    for (k = 0; k < NREG; ++k) {
        if (cnt[k] == 0.0) continue;
        printf(" %s %.0f%% %.3f %.2f %.0f%%;", k_reg_names[k], 100.0 * cnt[k] / (double)npix,
               sm[k] > 0.0 ? sh[k] / sm[k] : 0.0, sm[k] > s1[k] ? (sh[k] - s1[k]) / (sm[k] - s1[k]) : 0.0,
               tot > 0.0 ? 100.0 * se[k] / tot : 0.0);
    }
    if (nr > 0) {
        qsort(r, nr, sizeof(double), cmp_double);
        printf(" ratio quartiles %.3f %.3f %.3f", r[nr / 4], r[nr / 2], r[3 * nr / 4]);
    }
    /* the hue: each channel's mean over PT_MS's, and PSNR with each channel scaled to PT_MS's */
    {
        double ch[3] = {0}, cm[3] = {0}, e = 0.0;
        for (i = 0; i < npix; ++i)
            for (c = 0; c < 3; ++c) {
                ch[c] += hd[4 * i + c];
                cm[c] += ms[4 * i + c];
            }
        for (i = 0; i < npix; ++i)
            for (c = 0; c < 3; ++c) {
                double d = tonemap(ch[c] > 0.0 ? hd[4 * i + c] * cm[c] / ch[c] : 0.0) - tonemap(ms[4 * i + c]);
                e += d * d;
            }
        printf("\n    channels / PT_MS: R %.3f G %.3f B %.3f; PSNR each channel scaled %.2f dB",
               cm[0] > 0.0 ? ch[0] / cm[0] : 0.0, cm[1] > 0.0 ? ch[1] / cm[1] : 0.0, cm[2] > 0.0 ? ch[2] / cm[2] : 0.0,
               hdx_psnr(e / (3.0 * (double)npix)));
    }
    printf("\n");
    free(r);
}

static unsigned char to_u8(double v) { return (unsigned char)(v <= 0.0 ? 0 : v >= 1.0 ? 255 : v * 255.0 + 0.5); }

/* DIR/<case>-<config>.png: HD, PT_MS (both tone mapped) and their signed difference side by side,
   each panel n pixels enlarged to at least 384 (nearest pixel) for viewing. The difference is that
   of the tone-mapped values (what the PSNR measures), averaged over the channels and drawn 4x over
   a dimmed PT_MS: red where HD is too bright, blue where too dark (full at 0.25). */
static void write_images(const char *cname, const char *config, const float *hd, const float *ms, int n)
{
    size_t z = n >= 384 ? 1 : (size_t)((384 + n - 1) / n), m = z * (size_t)n, w = 3 * m, x, y;
    unsigned char *rgb = (unsigned char *)malloc(3 * w * m);
    char path[1024];
    int c;
    if (rgb == NULL) die("out of memory");
    for (y = 0; y < m; ++y)
        for (x = 0; x < m; ++x) {
            size_t p = (y / z) * (size_t)n + x / z;
            const float *a = hd + 4 * p, *b = ms + 4 * p;
            unsigned char *o = rgb + 3 * (y * w + x);
            double d = 0.0, g = 0.0;
            for (c = 0; c < 3; ++c) {
                o[c] = to_u8(tonemap(a[c]));
                o[3 * m + c] = to_u8(tonemap(b[c]));
                d += (tonemap(a[c]) - tonemap(b[c])) / 3.0;
                g += 0.25 * tonemap(b[c]) / 3.0;
            }
            o[6 * m] = to_u8(g + (d > 0.0 ? 4.0 * d : 0.0));
            o[6 * m + 1] = to_u8(g);
            o[6 * m + 2] = to_u8(g + (d < 0.0 ? -4.0 * d : 0.0));
        }
    snprintf(path, sizeof path, "%s/%s-%s.png", g_images, cname, config);
    if (!stbi_write_png(path, (int)w, (int)m, 3, rgb, (int)(3 * w))) die("cannot write %s", path);
    free(rgb);
}

/* ---- references ------------------------------------------------------------------------------- */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
    return h;
}

static uint64_t ref_key(const scene *s, hd_method m)
{
    uint64_t h = 1469598103934665603ull;
    size_t nvox = (size_t)s->vol.desc.dims[0] * s->vol.desc.dims[1] * s->vol.desc.dims[2];
    size_t vb = s->vol.desc.type == HD_VOXEL_U8 ? 1 : s->vol.desc.type == HD_VOXEL_U16 || s->vol.desc.type == HD_VOXEL_I16 ? 2 : 4;
    float optics[4] = {EXTINCTION, ALBEDO, (float)MAX_BOUNCES, 40.0f};
    int ints[4];
    ints[0] = (int)m;
    ints[1] = g_size;
    ints[2] = g_ref_paths;
    ints[3] = 1;
    h = fnv(h, s->c->name, strlen(s->c->name));
    h = fnv(h, s->vol.data, nvox * vb);
    h = fnv(h, s->vol.desc.spacing, sizeof s->vol.desc.spacing);
    h = fnv(h, s->tf.rgba, sizeof(float) * 4 * (size_t)s->tf.count);
    h = fnv(h, s->tf.domain, sizeof s->tf.domain);
    h = fnv(h, s->c->eye, sizeof s->c->eye);
    h = fnv(h, s->c->up, sizeof s->c->up);
    h = fnv(h, k_light, sizeof k_light);
    h = fnv(h, optics, sizeof optics);
    return fnv(h, ints, sizeof ints);
}

typedef struct ref_img {
    float *lin;      /* RGBA, the mean of the two halves */
    double noise_db; /* PSNR of the mean against the truth, estimated from the halves */
} ref_img;

/* Renders (or loads) the reference of method m: two halves of g_ref_paths / 2 paths per pixel. */
static void ref_get(const scene *s, hd_method m, ref_img *ref)
{
    size_t npix = (size_t)g_size * g_size, n4 = 4 * npix, i;
    uint64_t key = ref_key(s, m), k2 = 0;
    char path[1024];
    float *h[2];
    FILE *f;
    int half;
    snprintf(path, sizeof path, "%s/%s-%s-%016llx.f32", g_cache, s->c->name, hd_method_name(m),
             (unsigned long long)key);
    for (half = 0; half < 2; ++half)
        if ((h[half] = (float *)malloc(sizeof(float) * n4)) == NULL) die("out of memory");
    f = fopen(path, "rb");
    if (f == NULL || fread(&k2, sizeof k2, 1, f) != 1 || k2 != key || fread(h[0], sizeof(float), n4, f) != n4 ||
        fread(h[1], sizeof(float), n4, f) != n4) {
        double t0 = now();
        if (f != NULL) fclose(f);
        for (half = 0; half < 2; ++half) {
            hd_context ctx = make_ctx(s, m, NULL, HD_SOLVER_DEFAULT, 0, 1000u + (uint32_t)half);
            run(ctx, g_ref_paths / 2, h[half]);
            hd_destroy(ctx);
        }
        printf("  %s reference: %d paths per pixel, %.1f s\n", hd_method_name(m), g_ref_paths, now() - t0);
        f = fopen(path, "wb");
        if (f == NULL || fwrite(&key, sizeof key, 1, f) != 1 || fwrite(h[0], sizeof(float), n4, f) != n4 ||
            fwrite(h[1], sizeof(float), n4, f) != n4 || fclose(f) != 0)
            die("cannot write %s", path);
    } else {
        fclose(f);
    }
    ref->noise_db = hdx_psnr(mse_of(h[0], h[1], npix, 1.0) / 4.0);
    for (i = 0; i < n4; ++i) h[0][i] = 0.5f * (h[0][i] + h[1][i]);
    free(h[1]);
    ref->lin = h[0];
}

/* ---- the benchmark ---------------------------------------------------------------------------- */
static int in_list(const char *list, const char *name)
{
    size_t n = strlen(name);
    const char *p = list;
    if (list == NULL) return 1;
    while ((p = strstr(p, name)) != NULL) {
        if ((p == list || p[-1] == ',') && (p[n] == 0 || p[n] == ',')) return 1;
        p += n;
    }
    return 0;
}

/* 1 if every comma-separated name of list (NULL: all) is a case (cases != 0) or a configuration. */
static int names_known(const char *list, int cases)
{
    const char *p = list;
    if (list == NULL) return 1;
    for (;;) {
        size_t n = strcspn(p, ",");
        int k, found = 0, count = cases ? NCASES : NCONFIGS;
        for (k = 0; k < count && !found; ++k) {
            const char *name = cases ? k_cases[k].name : k_configs[k].name;
            found = strlen(name) == n && strncmp(name, p, n) == 0;
        }
        if (!found) return 0;
        if (p[n] == 0) return 1;
        p += n + 1;
    }
}

static void run_case(const ecase *c, const char *configs)
{
    scene s;
    ref_img ms, ss;
    size_t npix = (size_t)g_size * g_size;
    float *img = (float *)malloc(sizeof(float) * 4 * npix);
    unsigned char *reg = (unsigned char *)malloc(npix);
    int k;
    if (img == NULL || reg == NULL) die("out of memory");
    load_scene(&s, c);
    printf("%s (%s, TF %s, %dx%dx%d), %d^2:\n", c->name, c->path, c->tf, s.vol.desc.dims[0], s.vol.desc.dims[1],
           s.vol.desc.dims[2], g_size);
    fflush(stdout);
    ref_get(&s, HD_METHOD_PT_MS, &ms);
    ref_get(&s, HD_METHOD_PT_SS, &ss);
    printf("  references: PT_MS mean %.5f (noise %.1f dB), PT_SS mean %.5f (noise %.1f dB), PT_SS / PT_MS %.3f\n",
           mean_of(ms.lin, npix), ms.noise_db, mean_of(ss.lin, npix), ss.noise_db,
           mean_of(ss.lin, npix) / mean_of(ms.lin, npix));
    regions_of(ms.lin, ss.lin, g_size, reg);
    printf("  %-9s %9s %8s %8s %11s %11s %11s %9s %12s\n", "config", "mean", "/PT_MS", "/PT_SS", "PSNR MS",
           "PSNR SS", "MS scaled", "light_err", "s/it default");
    fflush(stdout);
    for (k = 0; k < NCONFIGS; ++k) {
        const econfig *cfg = &k_configs[k];
        hd_context ctx;
        hd_stats st;
        double t0, spi, m;
        if (!in_list(configs, cfg->name)) continue;
        ctx = make_ctx(&s, HD_METHOD_HD, cfg, HD_SOLVER_MULTIGRID, g_steps, 0);
        run(ctx, g_iters, img);
        if (hd_get_stats(ctx, &st) != HD_SUCCESS) die("hd_get_stats failed");
        hd_destroy(ctx);
        m = mean_of(img, npix);
        ctx = make_ctx(&s, HD_METHOD_HD, cfg, HD_SOLVER_DEFAULT, 0, 0);
        run(ctx, 1, NULL);
        t0 = now();
        run(ctx, g_time_iters, NULL);
        spi = (now() - t0) / g_time_iters;
        hd_destroy(ctx);
        /* "MS scaled": PSNR against PT_MS with HD scaled to PT_MS's mean */
        printf("  %-9s %9.5f %8.3f %8.3f %8.2f dB %8.2f dB %8.2f dB %9.4f %12.4f\n", cfg->name, m,
               m / mean_of(ms.lin, npix), m / mean_of(ss.lin, npix), hdx_psnr(mse_of(img, ms.lin, npix, 1.0)),
               hdx_psnr(mse_of(img, ss.lin, npix, 1.0)),
               hdx_psnr(mse_of(img, ms.lin, npix, m > 0.0 ? mean_of(ms.lin, npix) / m : 1.0)), st.light_error, spi);
        if (g_images != NULL) {
            region_report(img, ms.lin, ss.lin, reg, npix);
            write_images(c->name, cfg->name, img, ms.lin, g_size);
        }
        fflush(stdout);
    }
    free(ms.lin);
    free(ss.lin);
    free(img);
    free(reg);
    hd_volume_free(&s.vol);
}

/* The configuration named name (NULL if none). */
static const econfig *config_named(const char *name, size_t n)
{
    int k;
    for (k = 0; k < NCONFIGS; ++k)
        if (strlen(k_configs[k].name) == n && strncmp(k_configs[k].name, name, n) == 0) return &k_configs[k];
    return NULL;
}

/* --cost A,B: the wall seconds of one HD iteration (hd_iterate(1), the library's default solver)
   of configurations A and B on two contexts in one process, alternating one call each per round
   (the order swapped every round) so that both see the same machine load; medians of g_rounds. */
static void cost_case(const ecase *c, const char *pair)
{
    scene s;
    const econfig *cfg[2];
    hd_context ctx[2];
    double *t[2];
    size_t n = strcspn(pair, ",");
    int k, r;
    cfg[0] = config_named(pair, n);
    cfg[1] = pair[n] == ',' ? config_named(pair + n + 1, strlen(pair + n + 1)) : NULL;
    if (cfg[0] == NULL || cfg[1] == NULL) die("--cost needs two configurations A,B");
    load_scene(&s, c);
    for (k = 0; k < 2; ++k) {
        if ((t[k] = (double *)malloc(sizeof(double) * (size_t)g_rounds)) == NULL) die("out of memory");
        ctx[k] = make_ctx(&s, HD_METHOD_HD, cfg[k], HD_SOLVER_DEFAULT, 0, 0);
        run(ctx[k], 2, NULL);
    }
    for (r = 0; r < g_rounds; ++r)
        for (k = 0; k < 2; ++k) {
            int j = (k + r) & 1;
            double t0 = now();
            run(ctx[j], 1, NULL);
            t[j][r] = now() - t0;
        }
    for (k = 0; k < 2; ++k) {
        qsort(t[k], (size_t)g_rounds, sizeof(double), cmp_double);
        hd_destroy(ctx[k]);
    }
    printf("%s, %d^2: one iteration %s %.4f s, %s %.4f s, %s / %s %.3f (wall, medians of %d alternating rounds)\n",
           c->name, g_size, cfg[0]->name, t[0][g_rounds / 2], cfg[1]->name, t[1][g_rounds / 2], cfg[1]->name,
           cfg[0]->name, t[1][g_rounds / 2] / t[0][g_rounds / 2], g_rounds);
    fflush(stdout);
    free(t[0]);
    free(t[1]);
    hd_volume_free(&s.vol);
}

static const char *usage =
    "usage: hdbench_energy [--size N] [--ref-paths P] [--iters I] [--steps S] [--time-iters T]\n"
    "                      [--cases LIST] [--configs LIST] [--cache DIR] [--threads T] [--images DIR]\n"
    "  cases: head-skin,head-bone,brainsmall,skull\n"
    "  configs: direct,direct2,box1,surface1,box2,surface2,rgb1,rgb2\n"
    "  --images DIR: HD | PT_MS | difference PNGs (red: HD too bright) and figures by region\n"
    "  --cost A,B [--rounds R]: only time one iteration of configurations A and B, alternating\n";

int main(int argc, char **argv)
{
    const char *cases = NULL, *configs = "direct,box2,surface2,box1,surface1", *cost = NULL;
    int i;
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            return 0;
        }
        if (strcmp(a, "--size") && strcmp(a, "--ref-paths") && strcmp(a, "--iters") && strcmp(a, "--steps") &&
            strcmp(a, "--time-iters") && strcmp(a, "--threads") && strcmp(a, "--cases") && strcmp(a, "--configs") &&
            strcmp(a, "--cache") && strcmp(a, "--images") && strcmp(a, "--cost") && strcmp(a, "--rounds"))
            die("unknown option %s\n%s", a, usage);
        if (i + 1 >= argc) die("%s needs a value\n%s", a, usage);
        if (!strcmp(a, "--size")) g_size = atoi(argv[++i]);
        else if (!strcmp(a, "--ref-paths")) g_ref_paths = atoi(argv[++i]);
        else if (!strcmp(a, "--iters")) g_iters = atoi(argv[++i]);
        else if (!strcmp(a, "--steps")) g_steps = atoi(argv[++i]);
        else if (!strcmp(a, "--time-iters")) g_time_iters = atoi(argv[++i]);
        else if (!strcmp(a, "--threads")) g_threads = atoi(argv[++i]);
        else if (!strcmp(a, "--cases")) cases = argv[++i];
        else if (!strcmp(a, "--configs")) configs = argv[++i];
        else if (!strcmp(a, "--cache")) g_cache = argv[++i];
        else if (!strcmp(a, "--images")) g_images = argv[++i];
        else if (!strcmp(a, "--cost")) cost = argv[++i];
        else if (!strcmp(a, "--rounds")) g_rounds = atoi(argv[++i]);
        else die("unknown option %s\n%s", a, usage);
    }
    if (g_size < 8 || g_size > 4096 || g_ref_paths < 2 || g_iters < 1 || g_steps < 1 || g_time_iters < 1 ||
        g_threads < 0 || g_rounds < 1 || g_rounds > 1000)
        die("bad value\n%s", usage);
    if (!names_known(cases, 1) || !names_known(configs, 0)) die("unknown case or configuration\n%s", usage);
    if (cost != NULL) {
        for (i = 0; i < NCASES; ++i)
            if (in_list(cases, k_cases[i].name)) cost_case(&k_cases[i], cost);
        return 0;
    }
    if (mkdir(g_cache, 0777) != 0 && errno != EEXIST) die("cannot create %s", g_cache);
    if (g_images != NULL && mkdir(g_images, 0777) != 0 && errno != EEXIST) die("cannot create %s", g_images);
    printf("hdbench_energy: HD against PT_MS/PT_SS; extinction %.0f, albedo %.2f, 1 light; HD converged by "
           "multigrid CG, %d steps x %d iterations; references %d paths per pixel (2 halves)\n",
           EXTINCTION, ALBEDO, g_steps, g_iters, g_ref_paths);
    for (i = 0; i < NCASES; ++i)
        if (in_list(cases, k_cases[i].name)) run_case(&k_cases[i], configs);
    return 0;
}
