/* hdbench_energy - HD's energy balance against the path-traced references (CPU backend).

   For each volume and TF it renders PT_MS and PT_SS references (two independent halves each,
   cached under --cache by a hash of every setting that changes them) and HD in a list of
   configurations, each with its light converged (multigrid CG, --steps steps per iteration, for
   --iters iterations), and prints per configuration: the mean linear radiance over PT_MS's (and
   over PT_SS's), PSNR against PT_MS (tone map of docs/EVALUATION.md: exposure 8, sRGB, clamped)
   and HD's seconds per iteration with the library's default solver (red-black sweeps), timed
   after the quality run on a fresh context.

     build/hdbench_energy [--size N] [--ref-paths P] [--iters I] [--steps S] [--time-iters T]
                          [--cases LIST] [--configs LIST] [--cache DIR] [--threads T]
       cases:   head-skin head-bone brainsmall skull (comma separated; default all)
       configs: direct (HD without diffusion, against PT_SS), box1 surface1 box2 surface2
                (boundary and illumination_downsample); default direct,box2,surface2,box1,surface1

   Volumes: data/head.nrrd and data/brainsmall.nrrd (scripts/fetch-data), data/skull.nrrd
   (scripts/fetch-skull). Figures in docs/EVALUATION.md ("Energy balance"). */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "examples/hd_tf.h"
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
    int downsample, nodiff;
} econfig;

static const econfig k_configs[] = {
    {"direct", HD_BOUNDARY_BOX, 1, 1},
    {"box1", HD_BOUNDARY_BOX, 1, 0},
    {"surface1", HD_BOUNDARY_SURFACE, 1, 0},
    {"box2", HD_BOUNDARY_BOX, 2, 0},
    {"surface2", HD_BOUNDARY_SURFACE, 2, 0},
};
#define NCONFIGS ((int)(sizeof k_configs / sizeof k_configs[0]))

/* The scene: the head scene's optics, key light and exposure (examples/eval/head.scene). */
static const float k_light[3] = {-0.6452f, -0.3560f, -0.6760f};
#define EXTINCTION 100.0f
#define ALBEDO 0.9f
#define EXPOSURE 8.0f
#define MAX_BOUNCES 64

static int g_size = 128, g_ref_paths = 512, g_iters = 32, g_steps = 4, g_time_iters = 4, g_threads = 0;
static const char *g_cache = "build/energy-cache";

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
    d.volume = s->vol.desc;
    d.volume.value_range[0] = s->tf.domain[0];
    d.volume.value_range[1] = s->tf.domain[1];
    d.transfer_function = hdx_tf_desc(&s->tf);
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
static double tonemap(double v)
{
    v *= EXPOSURE;
    if (!(v > 0.0)) return 0.0;
    if (v >= 1.0) return 1.0;
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

static double mse_of(const float *a, const float *b, size_t npix)
{
    double s = 0.0;
    size_t i;
    int c;
    for (i = 0; i < npix; ++i)
        for (c = 0; c < 3; ++c) {
            double d = tonemap(a[4 * i + c]) - tonemap(b[4 * i + c]);
            s += d * d;
        }
    return s / (3.0 * (double)npix);
}

static double psnr(double mse) { return mse > 0.0 ? 10.0 * log10(1.0 / mse) : 200.0; }

static double mean_of(const float *img, size_t npix)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < npix; ++i) s += (double)img[4 * i] + img[4 * i + 1] + img[4 * i + 2];
    return s / (3.0 * (double)npix);
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
    size_t vb = s->vol.desc.type == HD_VOXEL_U8 ? 1 : s->vol.desc.type == HD_VOXEL_U16 ? 2 : 4;
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
    ref->noise_db = psnr(mse_of(h[0], h[1], npix) / 4.0);
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
    int k;
    if (img == NULL) die("out of memory");
    load_scene(&s, c);
    printf("%s (%s, TF %s, %dx%dx%d), %d^2:\n", c->name, c->path, c->tf, s.vol.desc.dims[0], s.vol.desc.dims[1],
           s.vol.desc.dims[2], g_size);
    fflush(stdout);
    ref_get(&s, HD_METHOD_PT_MS, &ms);
    ref_get(&s, HD_METHOD_PT_SS, &ss);
    printf("  references: PT_MS mean %.5f (noise %.1f dB), PT_SS mean %.5f (noise %.1f dB), PT_SS / PT_MS %.3f\n",
           mean_of(ms.lin, npix), ms.noise_db, mean_of(ss.lin, npix), ss.noise_db,
           mean_of(ss.lin, npix) / mean_of(ms.lin, npix));
    printf("  %-9s %9s %8s %8s %11s %11s %9s %12s\n", "config", "mean", "/PT_MS", "/PT_SS", "PSNR MS", "PSNR SS",
           "light_err", "s/it default");
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
        printf("  %-9s %9.5f %8.3f %8.3f %8.2f dB %8.2f dB %9.4f %12.4f\n", cfg->name, m, m / mean_of(ms.lin, npix),
               m / mean_of(ss.lin, npix), psnr(mse_of(img, ms.lin, npix)), psnr(mse_of(img, ss.lin, npix)),
               st.light_error, spi);
        fflush(stdout);
    }
    free(ms.lin);
    free(ss.lin);
    free(img);
    hd_volume_free(&s.vol);
}

static const char *usage =
    "usage: hdbench_energy [--size N] [--ref-paths P] [--iters I] [--steps S] [--time-iters T]\n"
    "                      [--cases LIST] [--configs LIST] [--cache DIR] [--threads T]\n"
    "  cases: head-skin,head-bone,brainsmall,skull; configs: direct,box1,surface1,box2,surface2\n";

int main(int argc, char **argv)
{
    const char *cases = NULL, *configs = "direct,box2,surface2,box1,surface1";
    int i;
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i];
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) {
            fputs(usage, stdout);
            return 0;
        }
        if (strcmp(a, "--size") && strcmp(a, "--ref-paths") && strcmp(a, "--iters") && strcmp(a, "--steps") &&
            strcmp(a, "--time-iters") && strcmp(a, "--threads") && strcmp(a, "--cases") && strcmp(a, "--configs") &&
            strcmp(a, "--cache"))
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
        else die("unknown option %s\n%s", a, usage);
    }
    if (g_size < 8 || g_size > 4096 || g_ref_paths < 2 || g_iters < 1 || g_steps < 1 || g_time_iters < 1 ||
        g_threads < 0)
        die("bad value\n%s", usage);
    if (!names_known(cases, 1) || !names_known(configs, 0)) die("unknown case or configuration\n%s", usage);
    if (mkdir(g_cache, 0777) != 0 && errno != EEXIST) die("cannot create %s", g_cache);
    printf("hdbench_energy: HD against PT_MS/PT_SS; extinction %.0f, albedo %.2f, 1 light; HD converged by "
           "multigrid CG, %d steps x %d iterations; references %d paths per pixel (2 halves)\n",
           EXTINCTION, ALBEDO, g_steps, g_iters, g_ref_paths);
    for (i = 0; i < NCASES; ++i)
        if (in_list(cases, k_cases[i].name)) run_case(&k_cases[i], configs);
    return 0;
}
