/* hdeval - the evaluation of hybriddiff against its baselines, as the paper made it.

     make eval                  reduced run (scene file's plain settings) -> docs/eval/
     build/hdeval [SCENE] [--paper] [--out DIR] [--cache DIR] [--size N] [--table-size N]

   On the scene of SCENE (default examples/eval/head.scene; every setting lives there) it writes
   to --out (default docs/eval):
     table1.csv, table1.md        Table 1: iterations/s of PT_SS, PT_MS, CD, HD with 1 and 3
                                  lights at table_size^2, and bytes of device-side state
     curves.csv                   PSNR/RMSE of every method against the PT_SS and PT_MS
                                  references, over iterations and wall time, 1 and 3 lights
     fig3_psnr_iterations.png .. fig6_rmse_time.png     Figures 3-6 (gnuplot)
     fig7_time_to_quality.png, ttq.csv, ttq.md          wall time to reach the PSNR levels
     fig2_methods.png             Figure 2: PT_SS, PT_MS, CD, HD; 1 light on top, 3 below
     fig_startup.png              HD after 1 iteration, CD after 1 and 10 (1 light)
     checks.txt                   the paper's claims as measured (also printed)
   References are cached in --cache (default out/eval-cache) under a hash of every setting that
   changes them; gnuplot scripts and data go to out/eval-work.

   Tone map and error metric: every image (references included) is mapped per channel by
   t(L) = srgb(clamp(exposure * L, 0, 1)) -- the encoding of hd_read_image_rgba8 without the
   8-bit rounding. MSE is over the RGB channels of all pixels (or of the "lit part": pixels whose
   reference opacity exceeds lit_opacity); RMSE = sqrt(MSE) and PSNR = 10 log10(1 / MSE), peak 1.

   One PT iteration is one full path per pixel (the paper's reference code counted one photon
   step per pixel). One HD or CD iteration is one direct-light update + the diffusion sweeps +
   one frame; their image is the mean of the last frame_window frames. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#define HYBRIDDIFF_BACKEND_CPU
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "hd_tf.h"
#include "hd_tonemap.h"
#include "hd_eval_scene.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "hd_png.h"

#define REF_MAGIC "HDEVALREF1"

static const hd_method k_method[HDE_METHODS] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS,
                                                HD_METHOD_PT_MS};
static const char *const k_name[HDE_METHODS] = {"HD", "CD", "PT_SS", "PT_MS"};
static const int k_lights[2] = {1, 3};

static double g_t0;
static hde_scene S;
static hdx_tf g_tf;
static hd_volume_file g_vol;
static FILE *g_checks;

/* ---- small helpers ------------------------------------------------------------------------------ */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 1, 2), noreturn))
#endif
static void die(const char *fmt, ...)
{
    va_list ap;
    fputs("hdeval: error: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    exit(1);
}

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Process CPU time divided by the worker threads: the wall time the work would take on that many
   otherwise idle cores. The CPU backend's workers block (no spinning), so this is robust to load
   from other processes, unlike the wall clock (both are recorded). */
static int g_cores = 1;
static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ((double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec) / g_cores;
}

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 1, 2)))
#endif
static void say(const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "[%6.0f s] ", now() - g_t0);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

/* A result line: printed and kept in checks.txt. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 1, 2)))
#endif
static void check_line(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vprintf(fmt, ap);
    va_end(ap);
    putchar('\n');
    if (g_checks) {
        va_start(ap, fmt);
        vfprintf(g_checks, fmt, ap);
        va_end(ap);
        fputc('\n', g_checks);
    }
    fflush(stdout);
}

static void mkdirs(const char *dir)
{
    char buf[1024];
    char *p;
    if (strlen(dir) >= sizeof buf) die("path too long: %s", dir);
    strcpy(buf, dir);
    for (p = buf + 1;; ++p) {
        if (*p == '/' || *p == 0) {
            char c = *p;
            *p = 0;
            if (mkdir(buf, 0777) != 0 && errno != EEXIST) die("cannot create %s: %s", buf, strerror(errno));
            *p = c;
            if (!c) break;
        }
    }
}

static FILE *open_w(const char *dir, const char *name, char *path_out)
{
    char path[1024];
    FILE *f;
    snprintf(path, sizeof path, "%s/%s", dir, name);
    f = fopen(path, "w");
    if (!f) die("cannot write %s: %s", path, strerror(errno));
    if (path_out) strcpy(path_out, path);
    return f;
}

static void *xmalloc(size_t n)
{
    void *p = malloc(n ? n : 1);
    if (!p) die("out of memory (%zu bytes)", n);
    return p;
}

/* ---- contexts ------------------------------------------------------------------------------------- */
static int g_downsample = 1; /* params.illumination_downsample of HD and CD contexts */
static int g_rgb = 0;        /* params.rgb_scattering of HD and CD contexts */
static hd_boundary g_boundary = HD_BOUNDARY_BOX; /* params.diffusion_boundary of HD and CD contexts */
static hd_precision g_precision = HD_PRECISION_FLOAT32; /* params.illumination_precision of HD and CD */
static hd_solver g_solver = HD_SOLVER_DEFAULT; /* params.solver of HD and CD contexts; DEFAULT: the scene's */
static int g_sweeps = 0;     /* params.diffusion_sweeps of HD and CD contexts; 0: the scene's */

static hd_context make_ctx(int m, int lights, int size, uint32_t seed)
{
    hd_desc d;
    hd_light L[HDE_MAX_LIGHTS];
    hd_context ctx;
    hd_result r;
    int i;
    memset(&d, 0, sizeof d);
    memset(L, 0, sizeof L);
    for (i = 0; i < lights; ++i) {
        L[i].type = HD_LIGHT_DIRECTIONAL;
        memcpy(L[i].direction, S.light_dir[i], sizeof L[i].direction);
        L[i].color[0] = L[i].color[1] = L[i].color[2] = 1.0f;
        L[i].intensity = S.light_intensity[i];
    }
    hdx_tf_use(&d, &g_vol.desc, &g_tf);
    d.lights = L;
    d.light_count = lights;
    memcpy(d.camera.eye, S.eye, sizeof S.eye);
    memcpy(d.camera.target, S.target, sizeof S.target);
    memcpy(d.camera.up, S.up, sizeof S.up);
    d.camera.fov_y = S.fov;
    d.camera.width = d.camera.height = size;
    d.params.method = k_method[m];
    d.params.extinction = S.extinction;
    d.params.albedo = S.albedo;
    d.params.anisotropy = S.anisotropy;
    d.params.diffusion_sweeps = g_sweeps ? g_sweeps : S.diffusion_sweeps;
    d.params.solver = g_solver != HD_SOLVER_DEFAULT ? g_solver
                      : S.solver == 2 ? HD_SOLVER_MULTIGRID : HD_SOLVER_RED_BLACK;
    d.params.seed = seed;
    d.params.step = S.step;
    d.params.frame_window = S.frame_window;
    d.params.exposure = S.exposure;
    d.params.max_bounces = S.max_bounces;
    d.params.illumination_downsample = g_downsample;
    d.params.rgb_scattering = g_rgb;
    d.params.diffusion_boundary = g_boundary;
    d.params.illumination_precision = g_precision;
    d.threads = S.threads;
    d.logger.func = hd_log_stderr;
    r = hd_create(&d, &ctx);
    if (r != HD_SUCCESS) die("hd_create (%s, %d lights): %s", k_name[m], lights, hd_result_string(r));
    return ctx;
}

static void iterate(hd_context ctx, int n)
{
    hd_result r = hd_iterate(ctx, n);
    if (r != HD_SUCCESS) die("hd_iterate: %s", hd_result_string(r));
}

static void read_image(hd_context ctx, float *img, int size)
{
    hd_result r = hd_read_image_f32(ctx, img, (size_t)size * size * 4);
    if (r != HD_SUCCESS) die("hd_read_image_f32: %s", hd_result_string(r));
}

/* ---- tone map and metrics ------------------------------------------------------------------------ */

typedef struct ref_img {
    int method, lights, paths;
    float *lin;          /* RGBA linear radiance and opacity */
    float *tm;           /* RGB tone-mapped */
    unsigned char *lit;  /* opacity > lit_opacity */
    size_t nlit;
    double noise_mse, noise_mse_lit; /* estimated MSE of the reference itself */
    double seconds;
    int cached;
} ref_img;

typedef struct err2 { double mse, mse_lit; } err2;

static err2 compare(const float *img, const ref_img *ref, size_t npix)
{
    double s = 0.0, sl = 0.0;
    size_t i;
    int c;
    err2 e;
    for (i = 0; i < npix; ++i) {
        double d2 = 0.0;
        for (c = 0; c < 3; ++c) {
            double d = (double)hdx_tonemap(img[4 * i + c], S.exposure) - (double)ref->tm[3 * i + c];
            d2 += d * d;
        }
        s += d2;
        if (ref->lit[i]) sl += d2;
    }
    e.mse = s / (3.0 * (double)npix);
    e.mse_lit = ref->nlit ? sl / (3.0 * (double)ref->nlit) : 0.0;
    return e;
}


/* ---- reference images, cached -------------------------------------------------------------------- */
static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; ++i) { h ^= b[i]; h *= 1099511628211ull; }
    return h;
}

/* Hash of every input of a reference image: volume voxels and range, TF entries, lights, camera,
   optics, size, paths and seeds. */
static uint64_t ref_key(int m, int lights)
{
    char buf[2048];
    uint64_t h = 1469598103934665603ull;
    size_t nvox = (size_t)g_vol.desc.dims[0] * g_vol.desc.dims[1] * g_vol.desc.dims[2];
    size_t vbytes = g_vol.desc.type == HD_VOXEL_U8 ? 1 : g_vol.desc.type == HD_VOXEL_U16 || g_vol.desc.type == HD_VOXEL_I16 ? 2 : 4;
    int i;
    h = fnv(h, g_vol.data, nvox * vbytes);
    h = fnv(h, g_tf.rgba, (size_t)g_tf.count * 4 * sizeof(float));
    snprintf(buf, sizeof buf, "v1 m%d L%d dims %d %d %d sp %.9g %.9g %.9g dom %.9g %.9g ext %.9g alb %.9g g %.9g "
             "step %.9g bounces %d eye %.9g %.9g %.9g tgt %.9g %.9g %.9g up %.9g %.9g %.9g fov %.9g size %d "
             "paths %d seed %u", m, lights, g_vol.desc.dims[0], g_vol.desc.dims[1], g_vol.desc.dims[2],
             (double)g_vol.desc.spacing[0], (double)g_vol.desc.spacing[1], (double)g_vol.desc.spacing[2],
             (double)g_tf.domain[0], (double)g_tf.domain[1], (double)S.extinction, (double)S.albedo,
             (double)S.anisotropy, (double)S.step, S.max_bounces, (double)S.eye[0], (double)S.eye[1],
             (double)S.eye[2], (double)S.target[0], (double)S.target[1], (double)S.target[2],
             (double)S.up[0], (double)S.up[1], (double)S.up[2], (double)S.fov, S.size, S.ref_paths[m],
             S.ref_seed);
    h = fnv(h, buf, strlen(buf));
    for (i = 0; i < lights; ++i) {
        h = fnv(h, S.light_dir[i], sizeof S.light_dir[i]);
        h = fnv(h, &S.light_intensity[i], sizeof S.light_intensity[i]);
    }
    return h;
}

static void ref_finish(ref_img *ref, size_t npix)
{
    size_t i;
    int c;
    ref->tm = (float *)xmalloc(npix * 3 * sizeof(float));
    ref->lit = (unsigned char *)xmalloc(npix);
    ref->nlit = 0;
    for (i = 0; i < npix; ++i) {
        for (c = 0; c < 3; ++c) ref->tm[3 * i + c] = hdx_tonemap(ref->lin[4 * i + c], S.exposure);
        ref->lit[i] = ref->lin[4 * i + 3] > S.lit_opacity;
        ref->nlit += ref->lit[i];
    }
}

static int ref_load(const char *path, ref_img *ref, uint64_t key, size_t npix)
{
    FILE *f = fopen(path, "rb");
    char line[512], keyhex[32];
    int w, h, paths;
    double nm, nml, secs;
    if (!f) return 0;
    snprintf(keyhex, sizeof keyhex, "%016llx", (unsigned long long)key);
    if (!fgets(line, sizeof line, f)) { fclose(f); return 0; }
    {
        char magic[32], k[32];
        if (sscanf(line, "%31s %d %d %d %lf %lf %lf %31s", magic, &w, &h, &paths, &nm, &nml, &secs, k) != 8 ||
            strcmp(magic, REF_MAGIC) != 0 || strcmp(k, keyhex) != 0 || w != S.size || h != S.size) {
            fclose(f);
            return 0;
        }
    }
    ref->lin = (float *)xmalloc(npix * 4 * sizeof(float));
    if (fread(ref->lin, sizeof(float), npix * 4, f) != npix * 4) {
        free(ref->lin);
        ref->lin = NULL;
        fclose(f);
        return 0;
    }
    fclose(f);
    ref->paths = paths;
    ref->noise_mse = nm;
    ref->noise_mse_lit = nml;
    ref->seconds = secs;
    ref->cached = 1;
    return 1;
}

/* PT_SS or PT_MS with ref_paths paths per pixel, as two independent halves (seeds ref_seed and
   ref_seed + 1): their difference estimates the reference's own noise, MSE(A,B)/4 for the mean. */
static void ref_get(ref_img *ref, int m, int lights, const char *cache_dir)
{
    size_t npix = (size_t)S.size * S.size, i;
    uint64_t key = ref_key(m, lights);
    char path[1024];
    memset(ref, 0, sizeof *ref);
    ref->method = m;
    ref->lights = lights;
    snprintf(path, sizeof path, "%s/ref-%s-%dL-%016llx.f32", cache_dir, k_name[m], lights,
             (unsigned long long)key);
    if (!ref_load(path, ref, key, npix)) {
        float *half[2];
        int k, done;
        double t0 = now();
        FILE *f;
        int per_half = S.ref_paths[m] / 2;
        for (k = 0; k < 2; ++k) {
            hd_context ctx = make_ctx(m, lights, S.size, S.ref_seed + (uint32_t)k);
            half[k] = (float *)xmalloc(npix * 4 * sizeof(float));
            for (done = 0; done < per_half;) {
                int n = per_half - done < 64 ? per_half - done : 64;
                iterate(ctx, n);
                done += n;
                if (done % 1024 == 0 || done == per_half)
                    fprintf(stderr, "\r           reference %s %d light%s: half %d, %d/%d paths  ",
                            k_name[m], lights, lights == 1 ? "" : "s", k + 1, done, per_half);
            }
            read_image(ctx, half[k], S.size);
            hd_destroy(ctx);
        }
        fputc('\n', stderr);
        ref->lin = (float *)xmalloc(npix * 4 * sizeof(float));
        for (i = 0; i < npix * 4; ++i) ref->lin[i] = 0.5f * (half[0][i] + half[1][i]);
        ref->paths = per_half * 2;
        ref->seconds = now() - t0;
        ref_finish(ref, npix);
        {
            ref_img hb;
            err2 e;
            memset(&hb, 0, sizeof hb);
            hb.lin = half[1];
            ref_finish(&hb, npix);
            memcpy(hb.lit, ref->lit, npix); /* the lit part of the mean */
            hb.nlit = ref->nlit;
            e = compare(half[0], &hb, npix);
            ref->noise_mse = e.mse / 4.0;
            ref->noise_mse_lit = e.mse_lit / 4.0;
            free(hb.tm);
            free(hb.lit);
        }
        free(half[0]);
        free(half[1]);
        f = fopen(path, "wb");
        if (!f) die("cannot write %s: %s", path, strerror(errno));
        fprintf(f, "%s %d %d %d %.9g %.9g %.3f %016llx\n", REF_MAGIC, S.size, S.size, ref->paths,
                ref->noise_mse, ref->noise_mse_lit, ref->seconds, (unsigned long long)key);
        if (fwrite(ref->lin, sizeof(float), npix * 4, f) != npix * 4 || fclose(f) != 0)
            die("cannot write %s", path);
    } else {
        ref_finish(ref, npix);
    }
    say("reference %s %d light%s: %d paths/pixel, %s %.1f s; its own noise: PSNR %.1f dB (lit %.1f dB); %s",
        k_name[m], lights, lights == 1 ? "" : "s", ref->paths, ref->cached ? "cached, rendered in" : "rendered in",
        ref->seconds, hdx_psnr(ref->noise_mse), hdx_psnr(ref->noise_mse_lit), path);
}

/* ---- Table 1 ---------------------------------------------------------------------------------------- */
typedef struct table_row {
    double rate[2];       /* iterations/s, 1 and 3 lights, on g_cores idle cores (CPU time) */
    double wall_rate[2];  /* iterations/s by the wall clock (load from other processes included) */
    size_t method_bytes[2], image_bytes[2], volume_bytes[2];
    double stage[2][3];   /* seconds per iteration: direct (or paths), diffusion, projection */
} table_row;

static double measure_rate(hd_context ctx, double *stage, double *wall_rate)
{
    int n = 0, chunk = 1;
    double t = 0.0, c0 = cpu_now();
    hd_stats s0, s1;
    hd_get_stats(ctx, &s0);
    while (t < S.table_seconds || n < S.table_min_iterations) {
        double a = now(), dt;
        iterate(ctx, chunk);
        dt = now() - a;
        t += dt;
        n += chunk;
        if (dt < 0.25) chunk *= 2;
    }
    hd_get_stats(ctx, &s1);
    stage[0] = (s1.seconds_direct - s0.seconds_direct) / n;
    stage[1] = (s1.seconds_diffusion - s0.seconds_diffusion) / n;
    stage[2] = (s1.seconds_projection - s0.seconds_projection) / n;
    *wall_rate = n / t;
    return n / (cpu_now() - c0);
}

static void run_table(table_row rows[HDE_METHODS], const char *out_dir)
{
    static const int order[HDE_METHODS] = {HDE_SS, HDE_MS, HDE_CD, HDE_HD}; /* the paper's columns */
    int mi, li, round;
    char path[1024];
    FILE *f;
    for (mi = 0; mi < HDE_METHODS; ++mi) {
        int m = order[mi];
        hd_context ctx[2];
        table_row *row = &rows[m];
        memset(row, 0, sizeof *row);
        for (li = 0; li < 2; ++li) {
            hd_stats st;
            ctx[li] = make_ctx(m, k_lights[li], S.table_size, S.seed);
            iterate(ctx[li], 1); /* warm-up: first touch, majorant grid; not timed */
            hd_get_stats(ctx[li], &st);
            row->method_bytes[li] = st.method_bytes;
            row->image_bytes[li] = st.image_bytes;
            row->volume_bytes[li] = st.volume_bytes;
        }
        /* 1- and 3-light runs alternate so that load from elsewhere hits both alike; best round */
        for (round = 0; round < S.table_rounds; ++round)
            for (li = 0; li < 2; ++li) {
                double stage[3], wr, r = measure_rate(ctx[li], stage, &wr);
                if (wr > row->wall_rate[li]) row->wall_rate[li] = wr;
                if (r > row->rate[li]) {
                    row->rate[li] = r;
                    memcpy(row->stage[li], stage, sizeof stage);
                }
            }
        for (li = 0; li < 2; ++li) hd_destroy(ctx[li]);
        say("table: %-5s %8.3f it/s (1 light) %8.3f it/s (3 lights), 3/1 = %.2f (wall clock: %.3f, %.3f)",
            k_name[m], row->rate[0], row->rate[1], row->rate[1] / row->rate[0], row->wall_rate[0],
            row->wall_rate[1]);
    }
    f = open_w(out_dir, "table1.csv", NULL);
    fprintf(f, "method,lights,image,iterations_per_s,wall_iterations_per_s,method_bytes,image_bytes,state_bytes,volume_bytes,"
               "s_direct_or_paths,s_diffusion,s_projection\n");
    for (mi = 0; mi < HDE_METHODS; ++mi)
        for (li = 0; li < 2; ++li) {
            int m = order[mi];
            table_row *r = &rows[m];
            fprintf(f, "%s,%d,%d,%.4f,%.4f,%zu,%zu,%zu,%zu,%.5f,%.5f,%.5f\n", k_name[m], k_lights[li], S.table_size,
                    r->rate[li], r->wall_rate[li], r->method_bytes[li], r->image_bytes[li], r->method_bytes[li] + r->image_bytes[li],
                    r->volume_bytes[li], r->stage[li][0], r->stage[li][1], r->stage[li][2]);
        }
    fclose(f);
    f = open_w(out_dir, "table1.md", path);
    fprintf(f, "Iterations per second (higher is better), head CT %dx%dx%d, image %dx%d, CPU backend, %d threads; "
               "rate = iterations / (process CPU seconds / %d), i.e. on %d otherwise idle cores (the machine was "
               "shared; the wall-clock rates are in table1.csv). 1- and 3-light runs alternated, best of %d rounds. "
               "One PT iteration = one full path per pixel (the paper's code counted one photon step per pixel).\n\n",
            g_vol.desc.dims[0], g_vol.desc.dims[1], g_vol.desc.dims[2], S.table_size, S.table_size, g_cores,
            g_cores, g_cores, S.table_rounds);
    fprintf(f, "| lights | PT single | PT multiple | convection-diffusion | hybrid diffusion |\n|---|---|---|---|---|\n");
    for (li = 0; li < 2; ++li)
        fprintf(f, "| %d | %.2f | %.2f | %.3f | %.3f |\n", k_lights[li], rows[HDE_SS].rate[li],
                rows[HDE_MS].rate[li], rows[HDE_CD].rate[li], rows[HDE_HD].rate[li]);
    fprintf(f, "| 3/1 | %.2f | %.2f | %.2f | %.2f |\n", rows[HDE_SS].rate[1] / rows[HDE_SS].rate[0],
            rows[HDE_MS].rate[1] / rows[HDE_MS].rate[0], rows[HDE_CD].rate[1] / rows[HDE_CD].rate[0],
            rows[HDE_HD].rate[1] / rows[HDE_HD].rate[0]);
    fprintf(f, "\nDevice-side state in MiB (method_bytes + image_bytes; the volume, TF and majorant grid, "
               "%.1f MiB, are shared by all and not counted):\n\n",
            rows[HDE_HD].volume_bytes[0] / 1048576.0);
    fprintf(f, "| lights | PT single | PT multiple | convection-diffusion | hybrid diffusion |\n|---|---|---|---|---|\n");
    for (li = 0; li < 2; ++li) {
        fprintf(f, "| %d |", k_lights[li]);
        for (mi = 0; mi < HDE_METHODS; ++mi) {
            int m = mi == 0 ? HDE_SS : mi == 1 ? HDE_MS : mi == 2 ? HDE_CD : HDE_HD;
            fprintf(f, " %.1f (%.1f + %.1f) |", (rows[m].method_bytes[li] + rows[m].image_bytes[li]) / 1048576.0,
                    rows[m].method_bytes[li] / 1048576.0, rows[m].image_bytes[li] / 1048576.0);
        }
        fputc('\n', f);
    }
    fprintf(f, "\nSeconds per iteration by stage, 1 light / 3 lights, from the library's wall-clock stage "
               "timers (so they include load from other processes; read them as shares; PT: the whole path "
               "tracing counts as \"direct\"):\n\n| method | direct | diffusion | projection |\n|---|---|---|---|\n");
    for (mi = 0; mi < HDE_METHODS; ++mi) {
        int m = mi == 0 ? HDE_SS : mi == 1 ? HDE_MS : mi == 2 ? HDE_CD : HDE_HD;
        fprintf(f, "| %s | %.4f / %.4f | %.4f / %.4f | %.4f / %.4f |\n", k_name[m], rows[m].stage[0][0],
                rows[m].stage[1][0], rows[m].stage[0][1], rows[m].stage[1][1], rows[m].stage[0][2],
                rows[m].stage[1][2]);
    }
    fclose(f);
}

/* ---- quality curves -------------------------------------------------------------------------------- */
typedef struct point {
    int it;
    double sec;  /* CPU time / cores of hd_iterate */
    double wall; /* wall time of hd_iterate */
    err2 e[2]; /* against PT_SS, PT_MS references */
} point;

typedef struct curve {
    int n;
    point *p;
    float *snap[3]; /* images after 1 and 10 iterations and at the end */
    int snap_it[3];
} curve;

static int next_checkpoint(int it)
{
    int n = it < 32 ? it + 1 : (int)(it * 1.08), p = 64;
    while (p <= it) p *= 2;
    if (n > p) n = p; /* every power of two is a checkpoint */
    return n > it ? n : it + 1;
}

static void run_curve(curve *c, int m, int lights, ref_img *ref_ss, ref_img *ref_ms)
{
    size_t npix = (size_t)S.size * S.size;
    float *img = (float *)xmalloc(npix * 4 * sizeof(float));
    hd_context ctx = make_ctx(m, lights, S.size, S.seed);
    int it = 0, total = S.iterations[m], cap = 64, target;
    double sec = 0.0, wall = 0.0;
    memset(c, 0, sizeof *c);
    c->p = (point *)xmalloc((size_t)cap * sizeof(point));
    for (target = 1; it < total; target = next_checkpoint(target)) {
        double a, ca;
        if (target > total) target = total;
        a = now();
        ca = cpu_now();
        iterate(ctx, target - it); /* only the iterations are timed, not the read-back */
        sec += cpu_now() - ca;
        wall += now() - a;
        it = target;
        read_image(ctx, img, S.size);
        if (c->n == cap) c->p = (point *)realloc(c->p, (size_t)(cap *= 2) * sizeof(point));
        if (!c->p) die("out of memory");
        c->p[c->n].it = it;
        c->p[c->n].sec = sec;
        c->p[c->n].wall = wall;
        c->p[c->n].e[0] = compare(img, ref_ss, npix);
        c->p[c->n].e[1] = compare(img, ref_ms, npix);
        ++c->n;
        if (it == 1 || it == 10 || it == total) {
            int k = it == 1 ? 0 : it == 10 ? 1 : 2;
            if (it == total) k = 2;
            c->snap[k] = (float *)xmalloc(npix * 4 * sizeof(float));
            memcpy(c->snap[k], img, npix * 4 * sizeof(float));
            c->snap_it[k] = it;
        }
    }
    hd_destroy(ctx);
    free(img);
    say("curve %-5s %d light%s: %d iterations in %.1f s (wall %.1f s), PSNR %.2f dB vs PT_SS, %.2f dB vs PT_MS", k_name[m],
        lights, lights == 1 ? " " : "s", total, sec, wall, hdx_psnr(c->p[c->n - 1].e[0].mse), hdx_psnr(c->p[c->n - 1].e[1].mse));
}

/* First time (and iteration) at which PSNR against PT_MS reaches level; -1 if never. */
static double time_to(const curve *c, double level, int *it)
{
    int i;
    for (i = 0; i < c->n; ++i)
        if (hdx_psnr(c->p[i].e[1].mse) >= level) {
            if (it) *it = c->p[i].it;
            return c->p[i].sec;
        }
    return -1.0;
}

static double psnr_at(const curve *c, int it, int ref, int lit)
{
    int i;
    for (i = 0; i < c->n; ++i)
        if (c->p[i].it == it) return hdx_psnr(lit ? c->p[i].e[ref].mse_lit : c->p[i].e[ref].mse);
    return -1.0;
}

/* ---- images ------------------------------------------------------------------------------------------ */
static void blit(uint8_t *dst, int dst_w, int x0, int y0, const float *img, int size)
{
    int x, y, c;
    for (y = 0; y < size; ++y)
        for (x = 0; x < size; ++x)
            for (c = 0; c < 3; ++c)
                dst[3 * ((size_t)(y0 + y) * dst_w + x0 + x) + c] =
                    (uint8_t)(hdx_tonemap(img[4 * ((size_t)y * size + x) + c], S.exposure) * 255.0f + 0.5f);
}

static void write_grid(const char *dir, const char *name, const float *const *tiles, int cols, int rows)
{
    int gap = 4, w = cols * S.size + (cols - 1) * gap, h = rows * S.size + (rows - 1) * gap, i;
    uint8_t *px = (uint8_t *)xmalloc((size_t)w * h * 3);
    char path[1024];
    memset(px, 255, (size_t)w * h * 3);
    for (i = 0; i < cols * rows; ++i)
        if (tiles[i]) blit(px, w, (i % cols) * (S.size + gap), (i / cols) * (S.size + gap), tiles[i], S.size);
    snprintf(path, sizeof path, "%s/%s", dir, name);
    stbi_write_png_compression_level = 9;
    if (!stbi_write_png(path, w, h, 3, px, w * 3)) die("cannot write %s", path);
    free(px);
}

/* ---- plots ------------------------------------------------------------------------------------------- */
static void write_dat(const char *work, const curve *c, int m, int lights)
{
    char name[64];
    FILE *f;
    int i;
    snprintf(name, sizeof name, "curve_%s_%d.dat", hde_method_keys[m], lights);
    f = open_w(work, name, NULL);
    fprintf(f, "# it sec psnr_ss rmse_ss psnr_ms rmse_ms psnr_lit_ss psnr_lit_ms\n");
    for (i = 0; i < c->n; ++i)
        fprintf(f, "%d %.5f %.4f %.6f %.4f %.6f %.4f %.4f\n", c->p[i].it, c->p[i].sec, hdx_psnr(c->p[i].e[0].mse),
                sqrt(c->p[i].e[0].mse), hdx_psnr(c->p[i].e[1].mse), sqrt(c->p[i].e[1].mse),
                hdx_psnr(c->p[i].e[0].mse_lit), hdx_psnr(c->p[i].e[1].mse_lit));
    fclose(f);
}

static const char *k_color[HDE_METHODS] = {"#d62728", "#1f77b4", "#7f7f7f", "#2ca02c"};

/* One figure: two panels (against PT_SS, against PT_MS) of column ycol over x (1 = iterations,
   2 = seconds); methods: bit mask. */
static void plot_figure(FILE *gp, const char *work, const char *out, const char *file, const char *title,
                        int xcol, int ycol_ss, const char *ylabel, int methods, int logy)
{
    int panel, m, li;
    fprintf(gp, "set output '%s/%s'\nset multiplot layout 1,2 title '%s'\n", out, file, title);
    fprintf(gp, "set xlabel '%s'\nset ylabel '%s'\nset logscale x\n%s\n", xcol == 1 ? "iterations" : "time (s): CPU seconds / 2 cores",
            ylabel, logy ? "set logscale y" : "unset logscale y");
    for (panel = 0; panel < 2; ++panel) {
        int first = 1;
        fprintf(gp, "set title 'against the %s reference'\nplot ", panel ? "PT\\_MS" : "PT\\_SS");
        for (m = 0; m < HDE_METHODS; ++m) {
            if (!(methods & (1 << m))) continue;
            for (li = 0; li < 2; ++li) {
                fprintf(gp, "%s'%s/curve_%s_%d.dat' using %d:%d with lines lw 2 dt %d lc rgb '%s' title '%s, %d light%s'",
                        first ? "" : ", ", work, hde_method_keys[m], k_lights[li], xcol, ycol_ss + 2 * panel,
                        li ? 2 : 1, k_color[m], m == HDE_SS ? "PT\\_SS" : m == HDE_MS ? "PT\\_MS" : k_name[m],
                        k_lights[li], li ? "s" : "");
                first = 0;
            }
        }
        fputc('\n', gp);
    }
    fprintf(gp, "unset multiplot\nunset logscale y\n");
}

static void make_plots(const char *work, const char *out, curve cur[HDE_METHODS][2])
{
    char path[1024], cmd[1200];
    FILE *gp = open_w(work, "plots.gp", path);
    int m, li, k;
    FILE *t;
    (void)cur;
    fprintf(gp, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
                "  set terminal pngcairo size 1100,520 font 'Sans,10'\n"
                "} else {\n  set terminal png size 1100,520 small\n}\n"
                "set grid\nset key outside bottom center horizontal maxrows 2\n");
    plot_figure(gp, work, out, "fig3_psnr_iterations.png", "Figure 3: PSNR over iterations (higher is better)", 1, 3,
                "PSNR (dB)", 3, 0);
    plot_figure(gp, work, out, "fig4_rmse_iterations.png", "Figure 4: RMSE over iterations (lower is better)", 1, 4,
                "RMSE (tone-mapped, [0,1])", 3, 1);
    fprintf(gp, "set key outside bottom center horizontal maxrows 2\n");
    plot_figure(gp, work, out, "fig5_psnr_time.png", "Figure 5: PSNR over time (CPU seconds / 2 cores)", 2, 3,
                "PSNR (dB)", 15, 0);
    plot_figure(gp, work, out, "fig6_rmse_time.png", "Figure 6: RMSE over time (CPU seconds / 2 cores)", 2, 4,
                "RMSE (tone-mapped, [0,1])", 15, 1);
    /* time to quality: one data file per method and light count */
    for (m = 0; m < HDE_METHODS; ++m)
        for (li = 0; li < 2; ++li) {
            char name[64];
            snprintf(name, sizeof name, "ttq_%s_%d.dat", hde_method_keys[m], k_lights[li]);
            t = open_w(work, name, NULL);
            for (k = 0; k < S.level_count; ++k) {
                double s = time_to(&cur[m][li], S.levels[k], NULL);
                if (s >= 0.0) fprintf(t, "%.2f %.5f\n", (double)S.levels[k], s);
            }
            fclose(t);
        }
    fprintf(gp, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
                "  set terminal pngcairo size 700,460 font 'Sans,10'\n"
                "} else {\n  set terminal png size 700,460 small\n}\n"
                "set output '%s/fig7_time_to_quality.png'\nset title 'Time to reach a PSNR against PT\\_MS "
                "(2 CPU cores; no point = never reached)'\n"
                "unset logscale x\nset logscale y\nset xlabel 'PSNR level against PT\\_MS (dB)'\n"
                "set ylabel 'time (s): CPU seconds / 2 cores'\nset key top left\nset xrange [%g:%g]\nplot ", out,
            (double)S.levels[0] - 1.0, (double)S.levels[S.level_count - 1] + 1.0);
    for (m = 0; m < HDE_METHODS; ++m)
        for (li = 0; li < 2; ++li)
            fprintf(gp, "%s'%s/ttq_%s_%d.dat' using 1:2 with linespoints lw 2 pt %d ps 1.3 dt %d lc rgb '%s' "
                        "title '%s, %d light%s'", m || li ? ", " : "", work, hde_method_keys[m], k_lights[li],
                    li ? 6 : 7, li ? 2 : 1, k_color[m], m == HDE_SS ? "PT\\_SS" : m == HDE_MS ? "PT\\_MS" : k_name[m],
                    k_lights[li], li ? "s" : "");
    fprintf(gp, "\n");
    fclose(gp);
    snprintf(cmd, sizeof cmd, "gnuplot '%s'", path);
    if (system(cmd) != 0) fprintf(stderr, "hdeval: warning: gnuplot failed (%s)\n", cmd);
}

/* ---- main -------------------------------------------------------------------------------------------- */
/* Beyond the paper: HD with its illumination stored at the data's resolution / 1, 2, 4 per axis.
   For each factor: the grid, the bytes per data voxel, iterations/s and PSNR against the 1-light
   PT_MS reference after the scene's HD iteration count, and at equal time: after the CPU time
   factor 1 takes for a quarter of those iterations. docs/eval/downsample.md and check lines. */
static void run_downsample_study(const ref_img *ref, const char *out)
{
    static const int factors[3] = {1, 2, 4};
    size_t npix = (size_t)S.size * S.size;
    float *img = (float *)xmalloc(npix * 4 * sizeof(float));
    double nvox = (double)g_vol.desc.dims[0] * g_vol.desc.dims[1] * g_vol.desc.dims[2];
    double budget = 0.0, rate1 = 0.0;
    int k, n = S.iterations[HDE_HD], saved = g_downsample;
    FILE *md = open_w(out, "downsample.md", NULL);
    fprintf(md, "| factor | illumination grid | state bytes per data voxel | HD it/s | speed-up | PSNR vs PT_MS after %d it | lit part | PSNR at equal time | lit part |\n"
                "|---|---|---|---|---|---|---|---|---|\n", n);
    for (k = 0; k < 3; ++k) {
        hd_context ctx;
        hd_stats st;
        double t0, t, rate, eq = 0, eq_lit = 0;
        err2 e, en;
        int done = 0;
        g_downsample = factors[k];
        ctx = make_ctx(HDE_HD, 1, S.size, 1u);
        t0 = cpu_now();
        t = 0.0;
        /* n iterations, and on until the equal-time budget is spent */
        while (done < n || eq == 0) {
            iterate(ctx, 1);
            ++done;
            if (k == 0 && done == (n + 3) / 4) budget = cpu_now() - t0;
            if (budget > 0 && eq == 0 && cpu_now() - t0 >= budget) {
                read_image(ctx, img, S.size);
                e = compare(img, ref, npix);
                eq = hdx_psnr(e.mse); eq_lit = hdx_psnr(e.mse_lit);
            }
            if (done == n) {
                t = cpu_now() - t0;
                read_image(ctx, img, S.size);
                en = compare(img, ref, npix);
            }
        }
        e = en;
        if (hd_get_stats(ctx, &st) != HD_SUCCESS) die("hd_get_stats");
        rate = n / t;
        if (k == 0) rate1 = rate;
        fprintf(md, "| %d | %dx%dx%d | %.2f | %.3f | %.2fx | %.2f dB | %.2f dB | %.2f dB | %.2f dB |\n", factors[k],
                st.illumination_dims[0], st.illumination_dims[1], st.illumination_dims[2],
                (double)st.method_bytes / nvox, rate, rate / rate1, hdx_psnr(e.mse), hdx_psnr(e.mse_lit), eq, eq_lit);
        check_line("downsample %d: grid %dx%dx%d, %.2f B/voxel, %.3f it/s (%.2fx), PSNR vs PT_MS %.2f dB (lit %.2f) after %d it",
                   factors[k], st.illumination_dims[0], st.illumination_dims[1], st.illumination_dims[2],
                   (double)st.method_bytes / nvox, rate, rate / rate1, hdx_psnr(e.mse), hdx_psnr(e.mse_lit), n);
        hd_destroy(ctx);
    }
    g_downsample = saved;
    fclose(md);
    free(img);
}

/* Beyond the paper: HD's diffusion variants against the 1-light PT_MS reference, at the scene's HD
   iteration count and at 4x it: grey (the paper) and RGB scattering, each with the box boundary
   (docs/METHOD.md) and the surface (Marshak) boundary. rgb.md, rgb-checks lines, the mean radiance of
   each image against the reference's (the diffusion's energy balance), and the side-by-side
   figure rgb_scattering.png (the four variants, then PT_MS).
   Colour, apart from brightness: PT_MS multiplies a path by the TF colour at every scattering
   vertex, so grey diffusion (colour applied once) over-lights the weak channels of coloured
   tissue, and that excess is the colour error. rgb.md's second table separates it: each
   channel's mean over PT_MS's (where the light is missing or in excess), the G/R and B/R ratios
   of the means over PT_MS's (the mean hue; 1 = PT_MS's), and the PSNR after scaling the whole
   image by one number to PT_MS's mean luminance (what is left when brightness is matched). */
static void channel_means(const float *img, size_t npix, double m[3])
{
    size_t i;
    int c;
    m[0] = m[1] = m[2] = 0.0;
    for (i = 0; i < npix; ++i)
        for (c = 0; c < 3; ++c) m[c] += (double)img[4 * i + c];
    for (c = 0; c < 3; ++c) m[c] /= (double)npix;
}

static double mean_radiance(const float *img, size_t npix)
{
    double m[3];
    channel_means(img, npix, m);
    return (m[0] + m[1] + m[2]) / 3.0;
}

/* Rec. 709 luminance of linear RGB. */
static double luminance(const double m[3]) { return 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2]; }

/* Error of img scaled by one factor so that its mean luminance is the reference's: brightness
   taken out, hue and spatial distribution left. *scale gets the factor. */
static err2 compare_luminance_matched(const float *img, const ref_img *ref, size_t npix, double *scale)
{
    double mi[3], mr[3];
    float *tmp = (float *)xmalloc(npix * 4 * sizeof(float));
    size_t i;
    err2 e;
    channel_means(img, npix, mi);
    channel_means(ref->lin, npix, mr);
    *scale = luminance(mi) > 0.0 ? luminance(mr) / luminance(mi) : 1.0;
    for (i = 0; i < npix * 4; ++i) tmp[i] = (float)(*scale * img[i]);
    e = compare(tmp, ref, npix);
    free(tmp);
    return e;
}

typedef struct rgb_row {
    double mean, ch[3];      /* after 4n it: mean radiance and R, G, B means over PT_MS's */
    double gr, br;           /* (G/R) and (B/R) of the means over PT_MS's */
    double scale;            /* after 4n it: the luminance-matching factor */
    err2 lm1, lm4;           /* luminance-matched error after n and 4n it */
} rgb_row;

static void run_rgb_study(const ref_img *ref, const char *out)
{
    size_t npix = (size_t)S.size * S.size;
    float *img[4];
    const float *tiles[5];
    rgb_row rows[4];
    int k, c, n = S.iterations[HDE_HD];
    double ref_mean = mean_radiance(ref->lin, npix), ref_ch[3];
    FILE *md = open_w(out, "rgb.md", NULL);
    channel_means(ref->lin, npix, ref_ch);
    fprintf(md, "| diffusion | boundary | state bytes per voxel | mean radiance / PT_MS's | PSNR vs PT_MS after %d it | lit part | after %d it | lit part |\n"
                "|---|---|---|---|---|---|---|---|\n", n, 4 * n);
    for (k = 0; k < 4; ++k) {
        hd_context ctx;
        hd_stats st;
        err2 e1, e4;
        double mean, ch[3], scale1;
        rgb_row *r = &rows[k];
        img[k] = (float *)xmalloc(npix * 4 * sizeof(float));
        g_rgb = k & 1;
        g_boundary = k >= 2 ? HD_BOUNDARY_SURFACE : HD_BOUNDARY_BOX;
        ctx = make_ctx(HDE_HD, 1, S.size, 1u);
        iterate(ctx, n);
        read_image(ctx, img[k], S.size);
        e1 = compare(img[k], ref, npix);
        r->lm1 = compare_luminance_matched(img[k], ref, npix, &scale1);
        iterate(ctx, 3 * n);
        read_image(ctx, img[k], S.size);
        e4 = compare(img[k], ref, npix);
        r->lm4 = compare_luminance_matched(img[k], ref, npix, &r->scale);
        mean = mean_radiance(img[k], npix) / ref_mean;
        channel_means(img[k], npix, ch);
        r->mean = mean;
        for (c = 0; c < 3; ++c) r->ch[c] = ch[c] / ref_ch[c];
        r->gr = r->ch[1] / r->ch[0];
        r->br = r->ch[2] / r->ch[0];
        if (hd_get_stats(ctx, &st) != HD_SUCCESS) die("hd_get_stats");
        fprintf(md, "| %s | %s | %.1f | %.3f | %.2f dB | %.2f dB | %.2f dB | %.2f dB |\n", g_rgb ? "RGB" : "grey",
                k >= 2 ? "surface" : "box",
                (double)st.method_bytes / ((double)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2]),
                mean, hdx_psnr(e1.mse), hdx_psnr(e1.mse_lit), hdx_psnr(e4.mse), hdx_psnr(e4.mse_lit));
        check_line("rgb_scattering %d, boundary %s: mean radiance %.3f x PT_MS, PSNR vs PT_MS %.2f dB (lit %.2f) after %d it, "
                   "%.2f dB (lit %.2f) after %d it; R G B means %.3f %.3f %.3f x PT_MS, G/R %.3f and B/R %.3f x PT_MS's; "
                   "luminance-matched (x%.3f) PSNR %.2f dB (lit %.2f) after %d it, %.2f dB (lit %.2f) after %d it",
                   g_rgb, k >= 2 ? "surface" : "box", mean, hdx_psnr(e1.mse), hdx_psnr(e1.mse_lit), n, hdx_psnr(e4.mse),
                   hdx_psnr(e4.mse_lit), 4 * n, r->ch[0], r->ch[1], r->ch[2], r->gr, r->br, r->scale, hdx_psnr(r->lm1.mse),
                   hdx_psnr(r->lm1.mse_lit), n, hdx_psnr(r->lm4.mse), hdx_psnr(r->lm4.mse_lit), 4 * n);
        hd_destroy(ctx);
    }
    fprintf(md, "\nColour apart from brightness, after %d it (PT_MS's R G B means %.4g %.4g %.4g, G/R %.3f, B/R %.3f). "
                "Luminance-matched: the image scaled by one factor to PT_MS's mean luminance (Rec. 709), then "
                "compared as above.\n\n"
                "| diffusion | boundary | R mean / PT_MS's | G | B | G/R / PT_MS's | B/R / PT_MS's | luminance factor | "
                "luminance-matched PSNR after %d it | lit part | after %d it | lit part |\n"
                "|---|---|---|---|---|---|---|---|---|---|---|---|\n",
            4 * n, ref_ch[0], ref_ch[1], ref_ch[2], ref_ch[1] / ref_ch[0], ref_ch[2] / ref_ch[0], n, 4 * n);
    for (k = 0; k < 4; ++k) {
        const rgb_row *r = &rows[k];
        fprintf(md, "| %s | %s | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f dB | %.2f dB | %.2f dB | %.2f dB |\n",
                k & 1 ? "RGB" : "grey", k >= 2 ? "surface" : "box", r->ch[0], r->ch[1], r->ch[2], r->gr, r->br,
                r->scale, hdx_psnr(r->lm1.mse), hdx_psnr(r->lm1.mse_lit), hdx_psnr(r->lm4.mse), hdx_psnr(r->lm4.mse_lit));
    }
    g_rgb = 0;
    g_boundary = HD_BOUNDARY_BOX;
    fclose(md);
    for (k = 0; k < 4; ++k) tiles[k] = img[k];
    tiles[4] = ref->lin;
    write_grid(out, "rgb_scattering.png", tiles, 5, 1);
    for (k = 0; k < 4; ++k) free(img[k]);
}

/* Beyond the paper: HD with E and phi stored as float32 and as float16 (params.
   illumination_precision), box boundary, 1 light, against the 1-light PT_MS reference at the
   scene's HD iteration count and 4x it; the bytes per voxel of E + phi and of the whole state,
   and the float16 image's PSNR against the float32 one (what the rounding alone costs).
   OUT/half.md and half-checks lines. */
static void run_half_study(const ref_img *ref, const char *out)
{
    size_t npix = (size_t)S.size * S.size;
    float *img[2][2];
    int k, j, n = S.iterations[HDE_HD];
    FILE *md = open_w(out, "half.md", NULL);
    fprintf(md, "| storage | E + phi bytes per voxel | state bytes per voxel | PSNR vs PT_MS after %d it | lit part | after %d it | lit part |\n"
                "|---|---|---|---|---|---|---|\n", n, 4 * n);
    for (k = 0; k < 2; ++k) {
        hd_context ctx;
        hd_stats st;
        err2 e1, e4;
        double gvox, illum;
        g_precision = k ? HD_PRECISION_FLOAT16 : HD_PRECISION_FLOAT32;
        for (j = 0; j < 2; ++j) img[k][j] = (float *)xmalloc(npix * 4 * sizeof(float));
        ctx = make_ctx(HDE_HD, 1, S.size, 1u);
        iterate(ctx, n);
        read_image(ctx, img[k][0], S.size);
        e1 = compare(img[k][0], ref, npix);
        iterate(ctx, 3 * n);
        read_image(ctx, img[k][1], S.size);
        e4 = compare(img[k][1], ref, npix);
        if (hd_get_stats(ctx, &st) != HD_SUCCESS) die("hd_get_stats");
        gvox = (double)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2];
        illum = 2.0 * st.illumination_channels * (k ? 2.0 : 4.0); /* E and phi, per channel */
        fprintf(md, "| %s | %.0f | %.1f | %.2f dB | %.2f dB | %.2f dB | %.2f dB |\n", k ? "float16" : "float32", illum,
                (double)st.method_bytes / gvox, hdx_psnr(e1.mse), hdx_psnr(e1.mse_lit), hdx_psnr(e4.mse), hdx_psnr(e4.mse_lit));
        check_line("precision %s: E+phi %.0f B/voxel, state %.1f B/voxel, PSNR vs PT_MS %.2f dB (lit %.2f) after %d it, "
                   "%.2f dB (lit %.2f) after %d it", k ? "float16" : "float32", illum, (double)st.method_bytes / gvox,
                   hdx_psnr(e1.mse), hdx_psnr(e1.mse_lit), n, hdx_psnr(e4.mse), hdx_psnr(e4.mse_lit), 4 * n);
        hd_destroy(ctx);
    }
    g_precision = HD_PRECISION_FLOAT32;
    for (j = 0; j < 2; ++j) {
        /* the float32 image as the reference of the float16 one: tone-mapped MSE as compare() */
        double mse = 0.0, d;
        size_t i;
        int c;
        for (i = 0; i < npix; ++i)
            for (c = 0; c < 3; ++c) {
                d = (double)hdx_tonemap(img[1][j][4 * i + c], S.exposure) - hdx_tonemap(img[0][j][4 * i + c], S.exposure);
                mse += d * d;
            }
        mse /= 3.0 * (double)npix;
        fprintf(md, "%sfloat16 against float32 after %d it: %.2f dB%s", j ? "; " : "\n", j ? 4 * n : n, hdx_psnr(mse), j ? "\n" : "");
        check_line("float16 vs float32 image after %d it: PSNR %.2f dB", j ? 4 * n : n, hdx_psnr(mse));
    }
    fclose(md);
    for (k = 0; k < 2; ++k)
        for (j = 0; j < 2; ++j) free(img[k][j]);
}

/* Beyond the paper: what the multigrid-preconditioned CG solver (HD_SOLVER_MULTIGRID) buys HD's
   image in the first seconds. HD with 1 light against the 1-light PT_MS reference, as curves over
   time: every iteration is timed alone (wall clock and CPU time / cores around hd_iterate; the
   read-back and the comparison are not timed) and followed by a comparison, so the PSNR at time t
   is that of the image on screen at t: the last one finished by then. Four solver settings (the
   scene's red-black sweeps per iteration, 8x as many, CG with 1 and with 2 multigrid-
   preconditioned steps per iteration), each with the surface and the box boundary, each run for
   --study-seconds on both clocks. OUT/multigrid.md, multigrid.csv (PSNR at fixed times),
   multigrid-curves.csv (every iteration), multigrid_psnr_time.png (gnuplot), multigrid_1s.png
   (surface boundary: each setting's image at 1 s wall, then PT_MS) and multigrid-checks.txt. */
enum { MG_CONFIGS = 4, MG_BOUNDARIES = 2, MG_TIMES = 7 };
static const double k_mg_times[MG_TIMES] = {0.5, 1, 2, 5, 10, 20, 40};
static const char *const k_mg_color[MG_CONFIGS] = {"#7f7f7f", "#1f77b4", "#d62728", "#2ca02c"};

typedef struct mg_run {
    hd_solver solver;
    int steps;     /* params.diffusion_sweeps: red-black sweeps or CG steps per HD iteration */
    hd_boundary boundary;
    curve c;       /* p[].e[1]: against PT_MS (e[0] unused) */
    hd_stats st;   /* at the end: the library's stage timers (wall) and the grid */
    double mean;   /* mean radiance of the last image / PT_MS's */
} mg_run;

static const char *mg_label(const mg_run *r, char *buf, size_t n)
{
    snprintf(buf, n, "%s, %d %s/it", r->solver == HD_SOLVER_MULTIGRID ? "multigrid CG" : "red-black", r->steps,
             r->solver == HD_SOLVER_MULTIGRID ? (r->steps == 1 ? "step" : "steps") : "sweeps");
    return buf;
}

/* The load average from /proc/loadavg (the machine is shared: the wall clock carries the load). */
static void load_average(char *buf, size_t n)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double a = 0, b = 0, c = 0;
    if (f && fscanf(f, "%lf %lf %lf", &a, &b, &c) == 3) snprintf(buf, n, "%.2f %.2f %.2f", a, b, c);
    else snprintf(buf, n, "n/a");
    if (f) fclose(f);
}

/* One configuration: iterations one at a time until both clocks pass `seconds`; snap (if not
   NULL) gets the last image finished within 1 s of wall time (left untouched if none was). */
static void mg_run_curve(mg_run *run, const ref_img *ref, double seconds, float *snap)
{
    size_t npix = (size_t)S.size * S.size;
    float *img = (float *)xmalloc(npix * 4 * sizeof(float));
    hd_context ctx;
    int cap = 64;
    double wall = 0.0, cpu = 0.0;
    curve *c = &run->c;
    g_solver = run->solver;
    g_sweeps = run->steps;
    g_boundary = run->boundary;
    ctx = make_ctx(HDE_HD, 1, S.size, 1u);
    memset(c, 0, sizeof *c);
    c->p = (point *)xmalloc((size_t)cap * sizeof(point));
    while (wall < seconds || cpu < seconds) {
        double a = now(), ca = cpu_now();
        iterate(ctx, 1);
        cpu += cpu_now() - ca;
        wall += now() - a;
        read_image(ctx, img, S.size);
        if (c->n == cap) c->p = (point *)realloc(c->p, (size_t)(cap *= 2) * sizeof(point));
        if (!c->p) die("out of memory");
        memset(&c->p[c->n], 0, sizeof(point));
        c->p[c->n].it = c->n + 1;
        c->p[c->n].sec = cpu;
        c->p[c->n].wall = wall;
        c->p[c->n].e[1] = compare(img, ref, npix);
        ++c->n;
        if (snap && wall <= 1.0) memcpy(snap, img, npix * 4 * sizeof(float));
    }
    if (hd_get_stats(ctx, &run->st) != HD_SUCCESS) die("hd_get_stats");
    run->mean = mean_radiance(img, npix) / mean_radiance(ref->lin, npix);
    hd_destroy(ctx);
    free(img);
    g_solver = HD_SOLVER_DEFAULT;
    g_sweeps = 0;
    g_boundary = HD_BOUNDARY_BOX;
}

/* PSNR against PT_MS of the image on screen at time t (wall or CPU clock): the last iteration
   finished by t; -1 before the first one. *it gets its iteration (0 if none). */
static double mg_psnr_at(const curve *c, double t, int wall, int lit, int *it)
{
    int i, last = -1;
    for (i = 0; i < c->n; ++i)
        if ((wall ? c->p[i].wall : c->p[i].sec) <= t) last = i;
    if (it) *it = last < 0 ? 0 : c->p[last].it;
    if (last < 0) return -1.0;
    return hdx_psnr(lit ? c->p[last].e[1].mse_lit : c->p[last].e[1].mse);
}

static void mg_write_md_table(FILE *md, mg_run runs[MG_BOUNDARIES][MG_CONFIGS], int wall, int ntimes)
{
    int b, k, j;
    char lab[64];
    fprintf(md, "| boundary | solver | it/s | diffusion s/it |");
    for (j = 0; j < ntimes; ++j) fprintf(md, " %g s |", k_mg_times[j]);
    fprintf(md, "\n|---|---|---|---|");
    for (j = 0; j < ntimes; ++j) fprintf(md, "---|");
    fputc('\n', md);
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k) {
            const mg_run *r = &runs[b][k];
            const point *last = &r->c.p[r->c.n - 1];
            fprintf(md, "| %s | %s | %.2f | %.3f |", b ? "box" : "surface", mg_label(r, lab, sizeof lab),
                    r->c.n / (wall ? last->wall : last->sec), r->st.seconds_diffusion / r->c.n);
            for (j = 0; j < ntimes; ++j) {
                int it;
                double v = mg_psnr_at(&r->c, k_mg_times[j], wall, 0, &it);
                if (v < 0) fprintf(md, " no image |");
                else fprintf(md, " %.2f (%d) |", v, it);
            }
            fputc('\n', md);
        }
}

static void mg_plot(const char *work, const char *out, mg_run runs[MG_BOUNDARIES][MG_CONFIGS], double seconds)
{
    char path[1024], cmd[1200], lab[64];
    FILE *gp;
    int b, k, clk, i;
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k) {
            char name[64];
            FILE *f;
            snprintf(name, sizeof name, "mg_%d_%d.dat", b, k);
            f = open_w(work, name, NULL);
            fprintf(f, "# it wall_s cpu_s psnr_ms psnr_lit_ms\n");
            for (i = 0; i < runs[b][k].c.n; ++i) {
                const point *p = &runs[b][k].c.p[i];
                fprintf(f, "%d %.5f %.5f %.4f %.4f\n", p->it, p->wall, p->sec, hdx_psnr(p->e[1].mse), hdx_psnr(p->e[1].mse_lit));
            }
            fclose(f);
        }
    gp = open_w(work, "multigrid.gp", path);
    fprintf(gp, "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
                "  set terminal pngcairo size 1100,900 font 'Sans,10'\n"
                "} else {\n  set terminal png size 1100,900 small\n}\n"
                "set output '%s/multigrid_psnr_time.png'\nset grid\nset logscale x\nset xrange [0.1:%g]\n"
                "set key at screen 0.5,0.955 center top horizontal maxrows 2 samplen 2\n"
                "set ylabel 'PSNR against PT\\_MS (dB)'\n"
                "set arrow 1 from 1, graph 0 to 1, graph 1 nohead dt 3 lc rgb '#000000'\n"
                "set multiplot layout 2,2 margins 0.07,0.98,0.06,0.88 spacing 0.08,0.1 title 'HD, 1 light, %dx%d, "
                "illumination grid %dx%dx%d: PSNR over time (a point per iteration; dotted: 1 s)'\n",
            out, seconds, S.size, S.size, runs[0][0].st.illumination_dims[0], runs[0][0].st.illumination_dims[1],
            runs[0][0].st.illumination_dims[2]);
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (clk = 0; clk < 2; ++clk) {
            fprintf(gp, "set title '%s boundary, %s'\nset xlabel '%s'\nplot ", b ? "box" : "surface",
                    clk ? "CPU time" : "wall clock",
                    clk ? "time (s): process CPU seconds / worker threads" : "time (s): wall clock of hd\\_iterate");
            for (k = 0; k < MG_CONFIGS; ++k)
                fprintf(gp, "%s'%s/mg_%d_%d.dat' using %d:4 with linespoints lw 2 pt 7 ps 0.4 lc rgb '%s' title '%s'",
                        k ? ", " : "", work, b, k, clk ? 3 : 2, k_mg_color[k], mg_label(&runs[b][k], lab, sizeof lab));
            fprintf(gp, "\nunset key\n"); /* one key, above the panels, for all four */
        }
    fprintf(gp, "unset multiplot\n");
    fclose(gp);
    snprintf(cmd, sizeof cmd, "gnuplot '%s'", path);
    if (system(cmd) != 0) fprintf(stderr, "hdeval: warning: gnuplot failed (%s)\n", cmd);
}

static void run_multigrid_study(const ref_img *ref, const char *out, const char *work, double seconds)
{
    size_t npix = (size_t)S.size * S.size;
    static mg_run runs[MG_BOUNDARIES][MG_CONFIGS];
    const float *tiles[MG_CONFIGS + 1];
    float *snap[MG_CONFIGS];
    int b, k, j, ntimes = 0;
    char lab[64], load0[64], load1[64], path[1024];
    FILE *f, *md;
    load_average(load0, sizeof load0);
    while (ntimes < MG_TIMES && k_mg_times[ntimes] <= seconds) ++ntimes;
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k) {
            mg_run *r = &runs[b][k];
            r->boundary = b ? HD_BOUNDARY_BOX : HD_BOUNDARY_SURFACE;
            r->solver = k < 2 ? HD_SOLVER_RED_BLACK : HD_SOLVER_MULTIGRID;
            r->steps = k == 0 ? S.diffusion_sweeps : k == 1 ? 8 * S.diffusion_sweeps : k - 1;
            if (b == 0) {
                snap[k] = (float *)xmalloc(npix * 4 * sizeof(float));
                memset(snap[k], 0, npix * 4 * sizeof(float));
            }
            mg_run_curve(r, ref, seconds, b == 0 ? snap[k] : NULL);
            {
                const point *last = &r->c.p[r->c.n - 1];
                check_line("multigrid study: %s boundary, %s: %d it in %.2f s wall (%.2f it/s), %.2f s CPU/%d "
                           "(%.2f it/s); per it: direct %.3f s, diffusion %.3f s, projection %.3f s (wall); "
                           "PSNR vs PT_MS at 1 s wall %.2f dB, at the end %.2f dB (lit %.2f); mean radiance %.3f x PT_MS",
                           b ? "box" : "surface", mg_label(r, lab, sizeof lab), r->c.n, last->wall, r->c.n / last->wall,
                           last->sec, g_cores, r->c.n / last->sec, r->st.seconds_direct / r->c.n,
                           r->st.seconds_diffusion / r->c.n, r->st.seconds_projection / r->c.n,
                           mg_psnr_at(&r->c, 1.0, 1, 0, NULL), hdx_psnr(last->e[1].mse), hdx_psnr(last->e[1].mse_lit), r->mean);
            }
        }
    load_average(load1, sizeof load1);
    check_line("multigrid study: load average %s at the start, %s at the end", load0, load1);

    f = open_w(out, "multigrid.csv", NULL);
    fprintf(f, "boundary,solver,steps_per_iteration,clock,seconds,iterations,psnr_vs_pt_ms,psnr_lit_vs_pt_ms,"
               "iterations_per_s,s_direct_per_it,s_diffusion_per_it,s_projection_per_it\n");
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k) {
            const mg_run *r = &runs[b][k];
            const point *last = &r->c.p[r->c.n - 1];
            int clk;
            for (clk = 0; clk < 2; ++clk)
                for (j = 0; j < ntimes; ++j) {
                    int it;
                    double v = mg_psnr_at(&r->c, k_mg_times[j], !clk, 0, &it);
                    double vl = mg_psnr_at(&r->c, k_mg_times[j], !clk, 1, NULL);
                    fprintf(f, "%s,%s,%d,%s,%g,%d,", b ? "box" : "surface",
                            r->solver == HD_SOLVER_MULTIGRID ? "multigrid" : "red_black", r->steps,
                            clk ? "cpu" : "wall", k_mg_times[j], it);
                    if (v < 0) fprintf(f, ",");
                    else fprintf(f, "%.3f,%.3f", v, vl);
                    fprintf(f, ",%.4f,%.5f,%.5f,%.5f\n", r->c.n / (clk ? last->sec : last->wall),
                            r->st.seconds_direct / r->c.n, r->st.seconds_diffusion / r->c.n,
                            r->st.seconds_projection / r->c.n);
                }
        }
    fclose(f);

    f = open_w(out, "multigrid-curves.csv", NULL);
    fprintf(f, "boundary,solver,steps_per_iteration,iteration,wall_seconds,cpu_seconds,psnr_vs_pt_ms,psnr_lit_vs_pt_ms\n");
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k)
            for (j = 0; j < runs[b][k].c.n; ++j) {
                const point *p = &runs[b][k].c.p[j];
                fprintf(f, "%s,%s,%d,%d,%.4f,%.4f,%.3f,%.3f\n", b ? "box" : "surface",
                        runs[b][k].solver == HD_SOLVER_MULTIGRID ? "multigrid" : "red_black", runs[b][k].steps, p->it,
                        p->wall, p->sec, hdx_psnr(p->e[1].mse), hdx_psnr(p->e[1].mse_lit));
            }
    fclose(f);

    md = open_w(out, "multigrid.md", path);
    fprintf(md, "HD, 1 light, %dx%d image, illumination grid %dx%dx%d (data %dx%dx%d), CPU backend, %d threads; "
                "PSNR (dB, all pixels) against the 1-light PT_MS reference (%d paths/pixel, its own noise %.1f dB) "
                "of the image on screen at each time, i.e. after the last iteration finished by then (that "
                "iteration in brackets; \"no image\": none finished yet). Load average %s at the start, %s at "
                "the end.\n\n",
            S.size, S.size, runs[0][0].st.illumination_dims[0], runs[0][0].st.illumination_dims[1],
            runs[0][0].st.illumination_dims[2], g_vol.desc.dims[0], g_vol.desc.dims[1], g_vol.desc.dims[2], g_cores,
            ref->paths, hdx_psnr(ref->noise_mse), load0, load1);
    fprintf(md, "Wall clock of hd_iterate (it/s by the wall clock; diffusion s/it from the library's stage timer):\n\n");
    mg_write_md_table(md, runs, 1, ntimes);
    fprintf(md, "\nCPU time of hd_iterate / %d threads (what the same work takes on %d otherwise idle cores; "
                "it/s by this clock):\n\n", g_cores, g_cores);
    mg_write_md_table(md, runs, 0, ntimes);
    fprintf(md, "\nMean radiance of the last image / PT_MS's (the diffusion's energy balance):");
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k)
            fprintf(md, "%s %s, %s: %.3f", b || k ? ";" : "", b ? "box" : "surface", mg_label(&runs[b][k], lab, sizeof lab),
                    runs[b][k].mean);
    fprintf(md, "\n");
    fclose(md);
    say("wrote %s", path);

    mg_plot(work, out, runs, seconds);
    for (k = 0; k < MG_CONFIGS; ++k) tiles[k] = snap[k];
    tiles[MG_CONFIGS] = ref->lin;
    write_grid(out, "multigrid_1s.png", tiles, MG_CONFIGS + 1, 1);
    for (k = 0; k < MG_CONFIGS; ++k) free(snap[k]);
    for (b = 0; b < MG_BOUNDARIES; ++b)
        for (k = 0; k < MG_CONFIGS; ++k) free(runs[b][k].c.p);
}

/* Which defaults serve users best: HD with 1 light against the 1-light PT_MS reference, for the
   paper's settings (full-resolution illumination grid, box boundary, red-black sweeps) and the
   candidates that change one or more of them (illumination_downsample 2, the surface boundary,
   multigrid CG). Every setting has its own context and they run interleaved, one iteration each
   per round, so the machine's load falls on all of them alike; each hd_iterate is timed alone
   (wall clock and process CPU time / cores) and followed by a comparison. OUT/defaults.md and
   defaults.csv: PSNR after 1..N iterations, it/s and its ratio to the paper's settings, and the
   PSNR of each at the time the paper's settings take for N/4 iterations. */
enum { DF_CONFIGS = 6, DF_MARKS = 8 };
typedef struct df_config {
    int downsample;
    hd_boundary boundary;
    hd_solver solver;
    int steps;
} df_config;

static void run_defaults_study(const ref_img *ref, const char *out)
{
    static const df_config cfg[DF_CONFIGS] = {
        {1, HD_BOUNDARY_BOX, HD_SOLVER_RED_BLACK, 4},       /* the paper's settings */
        {2, HD_BOUNDARY_BOX, HD_SOLVER_RED_BLACK, 4},
        {2, HD_BOUNDARY_SURFACE, HD_SOLVER_RED_BLACK, 4},
        {2, HD_BOUNDARY_SURFACE, HD_SOLVER_MULTIGRID, 1},
        {1, HD_BOUNDARY_SURFACE, HD_SOLVER_RED_BLACK, 4},
        {1, HD_BOUNDARY_SURFACE, HD_SOLVER_MULTIGRID, 1},
    };
    static const int marks[DF_MARKS] = {1, 2, 4, 8, 16, 32, 64, 128};
    size_t npix = (size_t)S.size * S.size;
    float *img = (float *)xmalloc(npix * 4 * sizeof(float));
    hd_context ctx[DF_CONFIGS];
    curve c[DF_CONFIGS];
    hd_stats st[DF_CONFIGS];
    double nvox = (double)g_vol.desc.dims[0] * g_vol.desc.dims[1] * g_vol.desc.dims[2];
    int n = S.iterations[HDE_HD], k, it, j;
    double budget_cpu, budget_wall;
    char load0[64], load1[64], path[1024];
    FILE *md, *f;
    load_average(load0, sizeof load0);
    for (k = 0; k < DF_CONFIGS; ++k) {
        g_downsample = cfg[k].downsample;
        g_boundary = cfg[k].boundary;
        g_solver = cfg[k].solver;
        g_sweeps = cfg[k].steps;
        ctx[k] = make_ctx(HDE_HD, 1, S.size, 1u);
        memset(&c[k], 0, sizeof c[k]);
        c[k].p = (point *)xmalloc((size_t)n * sizeof(point));
    }
    g_downsample = 1;
    g_boundary = HD_BOUNDARY_BOX;
    g_solver = HD_SOLVER_DEFAULT;
    g_sweeps = 0;
    for (it = 0; it < n; ++it)
        for (k = 0; k < DF_CONFIGS; ++k) {
            double a = now(), ca = cpu_now();
            point *p = &c[k].p[it];
            iterate(ctx[k], 1);
            memset(p, 0, sizeof *p);
            p->sec = (it ? c[k].p[it - 1].sec : 0.0) + cpu_now() - ca;
            p->wall = (it ? c[k].p[it - 1].wall : 0.0) + now() - a;
            p->it = it + 1;
            read_image(ctx[k], img, S.size);
            p->e[1] = compare(img, ref, npix);
            c[k].n = it + 1;
        }
    load_average(load1, sizeof load1);
    for (k = 0; k < DF_CONFIGS; ++k) {
        if (hd_get_stats(ctx[k], &st[k]) != HD_SUCCESS) die("hd_get_stats");
        hd_destroy(ctx[k]);
    }
    budget_cpu = c[0].p[(n + 3) / 4 - 1].sec;
    budget_wall = c[0].p[(n + 3) / 4 - 1].wall;

    md = open_w(out, "defaults.md", path);
    fprintf(md, "HD, 1 light, %dx%d image, data %dx%dx%d, CPU backend, %d threads; PSNR (dB, all pixels) against the "
                "1-light PT_MS reference (%d paths/pixel, its own noise %.1f dB). The settings ran interleaved, one "
                "iteration each per round; it/s by the wall clock of hd_iterate and by process CPU time / %d; "
                "'equal time': the PSNR of the last image finished within the time the first row takes for %d "
                "iterations (CPU clock; wall clock in brackets). Load average %s at the start, %s at the end.\n\n",
            S.size, S.size, g_vol.desc.dims[0], g_vol.desc.dims[1], g_vol.desc.dims[2], g_cores, ref->paths,
            hdx_psnr(ref->noise_mse), g_cores, (n + 3) / 4, load0, load1);
    fprintf(md, "| grid | boundary | solver | state B/voxel | it/s wall | it/s CPU | speed-up (CPU) |");
    for (j = 0; j < DF_MARKS && marks[j] <= n; ++j) fprintf(md, " %d it |", marks[j]);
    fprintf(md, " lit part, %d it | equal time |\n|---|---|---|---|---|---|---|", n);
    for (j = 0; j < DF_MARKS && marks[j] <= n; ++j) fprintf(md, "---|");
    fprintf(md, "---|---|\n");
    f = open_w(out, "defaults.csv", NULL);
    fprintf(f, "downsample,boundary,solver,steps,iteration,wall_seconds,cpu_seconds,psnr_vs_pt_ms,psnr_lit_vs_pt_ms\n");
    for (k = 0; k < DF_CONFIGS; ++k) {
        const point *last = &c[k].p[n - 1];
        double eqc = -1.0, eqw = -1.0;
        const char *sol = cfg[k].solver == HD_SOLVER_MULTIGRID ? "multigrid" : "red_black";
        for (it = 0; it < n; ++it) {
            const point *p = &c[k].p[it];
            if (p->sec <= budget_cpu) eqc = hdx_psnr(p->e[1].mse);
            if (p->wall <= budget_wall) eqw = hdx_psnr(p->e[1].mse);
            fprintf(f, "%d,%s,%s,%d,%d,%.4f,%.4f,%.3f,%.3f\n", cfg[k].downsample,
                    cfg[k].boundary == HD_BOUNDARY_SURFACE ? "surface" : "box", sol, cfg[k].steps, p->it, p->wall,
                    p->sec, hdx_psnr(p->e[1].mse), hdx_psnr(p->e[1].mse_lit));
        }
        fprintf(md, "| %dx%dx%d | %s | %s, %d %s | %.2f | %.3f | %.3f | %.2fx |", st[k].illumination_dims[0],
                st[k].illumination_dims[1], st[k].illumination_dims[2],
                cfg[k].boundary == HD_BOUNDARY_SURFACE ? "surface" : "box",
                cfg[k].solver == HD_SOLVER_MULTIGRID ? "multigrid CG" : "red-black", cfg[k].steps,
                cfg[k].solver == HD_SOLVER_MULTIGRID ? "step" : "sweeps", (double)st[k].method_bytes / nvox,
                n / last->wall, n / last->sec, c[0].p[n - 1].sec / last->sec);
        for (j = 0; j < DF_MARKS && marks[j] <= n; ++j) fprintf(md, " %.2f |", hdx_psnr(c[k].p[marks[j] - 1].e[1].mse));
        fprintf(md, " %.2f |", hdx_psnr(last->e[1].mse_lit));
        if (eqc < 0) fprintf(md, " no image |");
        else fprintf(md, " %.2f (%.2f) |", eqc, eqw);
        fputc('\n', md);
        check_line("defaults study: grid /%d, %s boundary, %s %d: %.3f it/s wall, %.3f it/s CPU/%d (%.2fx), "
                   "PSNR vs PT_MS after 1 it %.2f dB, after %d it %.2f dB (lit %.2f); per it: direct %.3f s, "
                   "diffusion %.3f s, projection %.3f s (wall)",
                   cfg[k].downsample, cfg[k].boundary == HD_BOUNDARY_SURFACE ? "surface" : "box", sol, cfg[k].steps,
                   n / last->wall, n / last->sec, g_cores, c[0].p[n - 1].sec / last->sec, hdx_psnr(c[k].p[0].e[1].mse), n,
                   hdx_psnr(last->e[1].mse), hdx_psnr(last->e[1].mse_lit), st[k].seconds_direct / n,
                   st[k].seconds_diffusion / n, st[k].seconds_projection / n);
        free(c[k].p);
    }
    check_line("defaults study: load average %s at the start, %s at the end", load0, load1);
    fclose(f);
    fclose(md);
    say("wrote %s", path);
    free(img);
}


static const char *usage =
    "usage: hdeval [SCENE] [--paper] [--out DIR] [--cache DIR] [--work DIR] [--size N] [--table-size N]\n"
    "              [--skip-table] [--downsample N] [--downsample-study] [--rgb-study] [--half-study]\n"
    "              [--multigrid-study] [--study-seconds S] [--defaults-study]\n"
    "  SCENE           scene file (default examples/eval/head.scene): every setting\n"
    "  --paper         use the scene's paper.* settings (1024^2, paper-scale iterations/references)\n"
    "  --out DIR       tables, plots, figures (default docs/eval)\n"
    "  --cache DIR     reference images (default out/eval-cache)\n"
    "  --work DIR      gnuplot scripts and data (default out/eval-work)\n"
    "  --size N        override the scene's image size of the curves and figures\n"
    "  --table-size N  override the scene's image size of Table 1 (default 1024, like the paper)\n"
    "  --skip-table    no Table 1 (quality only)\n"
    "  --downsample N  params.illumination_downsample of HD and CD (default 1; the downsample study\n"
    "                  sets its own)\n"
    "  --downsample-study  only HD with its illumination at 1/1, 1/2, 1/4 resolution against the\n"
    "                  1-light PT_MS reference (docs/eval/downsample.md), then stop\n"
    "  --rgb-study     only HD with grey and RGB scattering, each with the box and the surface\n"
    "                  boundary, against the 1-light PT_MS reference (OUT/rgb.md,\n"
    "                  OUT/rgb_scattering.png), then stop\n"
    "  --half-study    only HD with E and phi stored as float32 and as float16, against the\n"
    "                  1-light PT_MS reference (OUT/half.md), then stop\n"
    "  --multigrid-study  only HD with red-black (the scene's sweeps and 8x) and multigrid CG (1 and 2\n"
    "                  steps per iteration), surface and box boundary, as curves of PSNR against the\n"
    "                  1-light PT_MS reference over wall and CPU time (OUT/multigrid.md, .csv,\n"
    "                  multigrid_psnr_time.png), then stop; with --downsample 2 the first second\n"
    "                  holds several iterations\n"
    "  --study-seconds S  how long each multigrid-study run lasts on both clocks (default 20)\n"
    "  --defaults-study  only HD with the paper's settings and the candidate defaults (grid /2,\n"
    "                  surface boundary, multigrid CG), interleaved, against the 1-light PT_MS\n"
    "                  reference (OUT/defaults.md, defaults.csv), then stop\n";

int main(int argc, char **argv)
{
    const char *scene_path = "examples/eval/head.scene", *out = "docs/eval", *cache = "out/eval-cache";
    const char *work = "out/eval-work";
    int paper = 0, size = 0, table_size = 0, skip_table = 0, downsample_study = 0, rgb_study = 0, i, m, li, k;
    int half_study = 0, multigrid_study = 0, defaults_study = 0;
    double study_seconds = 20.0;
    char err[1024];
    static ref_img refs[HDE_METHODS][2];
    static curve cur[HDE_METHODS][2];
    static table_row rows[HDE_METHODS];
    hd_result r;
    FILE *f;

    g_t0 = now();
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i];
#define NEXT() (i + 1 < argc ? argv[++i] : (die("%s needs a value", a), ""))
        if (!strcmp(a, "-h") || !strcmp(a, "--help")) { fputs(usage, stdout); return 0; }
        else if (!strcmp(a, "--paper")) paper = 1;
        else if (!strcmp(a, "--out")) out = NEXT();
        else if (!strcmp(a, "--cache")) cache = NEXT();
        else if (!strcmp(a, "--work")) work = NEXT();
        else if (!strcmp(a, "--size")) size = atoi(NEXT());
        else if (!strcmp(a, "--table-size")) table_size = atoi(NEXT());
        else if (!strcmp(a, "--skip-table")) skip_table = 1;
        else if (!strcmp(a, "--downsample-study")) downsample_study = 1;
        else if (!strcmp(a, "--rgb-study")) rgb_study = 1;
        else if (!strcmp(a, "--half-study")) half_study = 1;
        else if (!strcmp(a, "--multigrid-study")) multigrid_study = 1;
        else if (!strcmp(a, "--defaults-study")) defaults_study = 1;
        else if (!strcmp(a, "--study-seconds")) study_seconds = atof(NEXT());
        else if (!strcmp(a, "--downsample")) g_downsample = atoi(NEXT());
        else if (a[0] == '-') { fprintf(stderr, "hdeval: unknown option %s\n%s", a, usage); return 2; }
        else scene_path = a;
#undef NEXT
    }
    if (!hde_scene_load(scene_path, paper, &S, err, sizeof err)) {
        fprintf(stderr, "hdeval: %s\n", err);
        return 2;
    }
    if (size) S.size = size;
    if (table_size) S.table_size = table_size;
    if (S.size < 8 || S.size > 16384 || S.table_size < 8 || S.table_size > 16384) die("bad image size");
    if (g_downsample < 1 || g_downsample > 8) die("--downsample: 1..8");
    if (!(study_seconds > 0.0 && study_seconds <= 3600.0)) die("--study-seconds: (0, 3600]");
    g_cores = S.threads > 0 ? S.threads : (int)sysconf(_SC_NPROCESSORS_ONLN);
    if (g_cores < 1) g_cores = 1;
    mkdirs(out);
    mkdirs(cache);
    mkdirs(work);

    {
        char *tfname = (char *)xmalloc(strlen(S.tf) + 1); /* heap: unbounded for the TF helpers */
        strcpy(tfname, S.tf);
        char pname[64]; /* preset names are short */
        snprintf(pname, sizeof pname, "%.63s", S.tf);
        if ((strlen(S.tf) >= sizeof pname || !hdx_tf_preset(pname, &g_tf)) &&
            !hdx_tf_load(tfname, &g_tf, err, sizeof err))
            die("tf '%s': not a preset, and as a file: %s", S.tf, err);
        free(tfname);
    }
    r = hd_volume_load_nrrd(S.volume, &g_vol, NULL);
    if (r != HD_SUCCESS) die("%s: %s (make data fetches the head CT)", S.volume, hd_result_string(r));
    if (g_tf.data_domain) hdx_tf_set_domain(&g_tf, g_vol.value_min, g_vol.value_max);

    g_checks = open_w(out, downsample_study ? "downsample-checks.txt" : rgb_study ? "rgb-checks.txt" :
                           half_study ? "half-checks.txt" : multigrid_study ? "multigrid-checks.txt" :
                           defaults_study ? "defaults-checks.txt" : "checks.txt",
                     NULL);
    check_line("hdeval: %s%s, %s %dx%dx%d, tf %s, backend %s, curves %dx%d, table %dx%d", scene_path,
               paper ? " (--paper)" : "", S.volume, g_vol.desc.dims[0], g_vol.desc.dims[1], g_vol.desc.dims[2],
               S.tf, hd_backend_name(), S.size, S.size, S.table_size, S.table_size);
    check_line("settings: iterations HD %d, CD %d, PT_SS %d, PT_MS %d; references PT_SS %d, PT_MS %d paths/pixel; "
               "extinction %g, albedo %g, g %g, exposure %g, frame_window %d, sweeps %d%s, illumination downsample %d",
               S.iterations[HDE_HD], S.iterations[HDE_CD], S.iterations[HDE_SS], S.iterations[HDE_MS],
               S.ref_paths[HDE_SS], S.ref_paths[HDE_MS], (double)S.extinction, (double)S.albedo,
               (double)S.anisotropy, (double)S.exposure, S.frame_window, S.diffusion_sweeps,
               S.solver == 2 ? " (multigrid CG steps)" : "", g_downsample);

    if (defaults_study) {
        ref_get(&refs[HDE_MS][0], HDE_MS, 1, cache);
        run_defaults_study(&refs[HDE_MS][0], out);
        fclose(g_checks);
        return 0;
    }
    if (multigrid_study) {
        ref_get(&refs[HDE_MS][0], HDE_MS, 1, cache);
        run_multigrid_study(&refs[HDE_MS][0], out, work, study_seconds);
        fclose(g_checks);
        return 0;
    }
    if (half_study) {
        ref_get(&refs[HDE_MS][0], HDE_MS, 1, cache);
        run_half_study(&refs[HDE_MS][0], out);
        fclose(g_checks);
        return 0;
    }
    if (rgb_study) {
        ref_get(&refs[HDE_MS][0], HDE_MS, 1, cache);
        run_rgb_study(&refs[HDE_MS][0], out);
        fclose(g_checks);
        return 0;
    }
    if (downsample_study) {
        ref_get(&refs[HDE_MS][0], HDE_MS, 1, cache);
        run_downsample_study(&refs[HDE_MS][0], out);
        fclose(g_checks);
        return 0;
    }

    /* 1. Table 1 */
    if (!skip_table) run_table(rows, out);

    /* 2. references */
    for (li = 0; li < 2; ++li)
        for (m = HDE_SS; m <= HDE_MS; ++m) ref_get(&refs[m][li], m, k_lights[li], cache);

    /* 3. curves of every method (PT curves use seed `seed`, independent of the references) */
    for (li = 0; li < 2; ++li)
        for (m = 0; m < HDE_METHODS; ++m) {
            run_curve(&cur[m][li], m, k_lights[li], &refs[HDE_SS][li], &refs[HDE_MS][li]);
            write_dat(work, &cur[m][li], m, k_lights[li]);
        }
    f = open_w(out, "curves.csv", NULL);
    fprintf(f, "method,lights,iterations,seconds,wall_seconds,psnr_vs_pt_ss,rmse_vs_pt_ss,psnr_vs_pt_ms,rmse_vs_pt_ms,"
               "psnr_lit_vs_pt_ss,psnr_lit_vs_pt_ms\n");
    for (m = 0; m < HDE_METHODS; ++m)
        for (li = 0; li < 2; ++li)
            for (i = 0; i < cur[m][li].n; ++i) {
                const point *p = &cur[m][li].p[i];
                fprintf(f, "%s,%d,%d,%.4f,%.4f,%.3f,%.5f,%.3f,%.5f,%.3f,%.3f\n", k_name[m], k_lights[li], p->it, p->sec, p->wall,
                        hdx_psnr(p->e[0].mse), sqrt(p->e[0].mse), hdx_psnr(p->e[1].mse), sqrt(p->e[1].mse),
                        hdx_psnr(p->e[0].mse_lit), hdx_psnr(p->e[1].mse_lit));
            }
    fclose(f);

    /* 4. plots and figures */
    make_plots(work, out, cur);
    {
        const float *tiles[8];
        for (li = 0; li < 2; ++li) {
            tiles[4 * li + 0] = refs[HDE_SS][li].lin;
            tiles[4 * li + 1] = refs[HDE_MS][li].lin;
            tiles[4 * li + 2] = cur[HDE_CD][li].snap[2];
            tiles[4 * li + 3] = cur[HDE_HD][li].snap[2];
        }
        write_grid(out, "fig2_methods.png", (const float *const *)tiles, 4, 2);
        tiles[0] = cur[HDE_HD][0].snap[0];
        tiles[1] = cur[HDE_CD][0].snap[0];
        tiles[2] = cur[HDE_CD][0].snap[1];
        tiles[3] = refs[HDE_MS][0].lin;
        write_grid(out, "fig_startup.png", (const float *const *)tiles, 4, 1);
    }

    /* 5. the paper's claims, measured */
    check_line("\n== references (two independent halves; noise = PSNR of the mean against the truth, estimated)");
    for (li = 0; li < 2; ++li)
        for (m = HDE_SS; m <= HDE_MS; ++m)
            check_line("  %s %d light%s: %d paths/pixel, noise floor %.1f dB (lit part %.1f dB, %zu pixels)",
                       k_name[m], k_lights[li], li ? "s" : "", refs[m][li].paths, hdx_psnr(refs[m][li].noise_mse),
                       hdx_psnr(refs[m][li].noise_mse_lit), refs[m][li].nlit);
    if (!skip_table) {
        double hd_ratio = rows[HDE_HD].rate[1] / rows[HDE_HD].rate[0];
        double cd_ratio = rows[HDE_CD].rate[1] / rows[HDE_CD].rate[0];
        check_line("\n== cost with 3 lights / cost with 1 light (iterations/s ratio, %dx%d)", S.table_size,
                   S.table_size);
        check_line("  HD: %.2f (paper 560/726 = 0.77; target >= 0.8): %s", hd_ratio, hd_ratio >= 0.8 ? "PASS" : "FAIL");
        check_line("  CD: %.2f (paper 247/808 = 0.31; claim: about 1/3): %s", cd_ratio,
                   cd_ratio < 0.45 ? "as claimed" : "NOT reproduced (CD's light sweeps are not its bottleneck here)");
        check_line("  PT_SS: %.2f, PT_MS: %.2f (paper 0.95, 0.94)", rows[HDE_SS].rate[1] / rows[HDE_SS].rate[0],
                   rows[HDE_MS].rate[1] / rows[HDE_MS].rate[0]);
        check_line("  state bytes (method + image), 1 -> 3 lights: HD %zu -> %zu, CD %zu -> %zu",
                   rows[HDE_HD].method_bytes[0] + rows[HDE_HD].image_bytes[0],
                   rows[HDE_HD].method_bytes[1] + rows[HDE_HD].image_bytes[1],
                   rows[HDE_CD].method_bytes[0] + rows[HDE_CD].image_bytes[0],
                   rows[HDE_CD].method_bytes[1] + rows[HDE_CD].image_bytes[1]);
    }
    check_line("\n== time to reach a PSNR against the PT_MS reference (time of hd_iterate: CPU s / cores, %dx%d)", S.size,
               S.size);
    f = open_w(out, "ttq.csv", NULL);
    fprintf(f, "method,lights,psnr_level,seconds,iterations\n");
    {
        FILE *md = open_w(out, "ttq.md", NULL);
        fprintf(md, "| PSNR vs PT_MS | lights | HD | CD | PT_SS | PT_MS |\n|---|---|---|---|---|---|\n");
        for (k = 0; k < S.level_count; ++k)
            for (li = 0; li < 2; ++li) {
                double t[HDE_METHODS];
                int its[HDE_METHODS];
                fprintf(md, "| %g dB | %d |", (double)S.levels[k], k_lights[li]);
                for (m = 0; m < HDE_METHODS; ++m) {
                    its[m] = 0;
                    t[m] = time_to(&cur[m][li], S.levels[k], &its[m]);
                    fprintf(f, "%s,%d,%g,%.4f,%d\n", k_name[m], k_lights[li], (double)S.levels[k], t[m], its[m]);
                    if (t[m] >= 0) fprintf(md, " %.2f s (%d it) |", t[m], its[m]);
                    else fprintf(md, " never (best %.1f dB) |", hdx_psnr(cur[m][li].p[cur[m][li].n - 1].e[1].mse));
                }
                fputc('\n', md);
                {
                    char ts[HDE_METHODS][32];
                    for (m = 0; m < HDE_METHODS; ++m) {
                        if (t[m] >= 0) snprintf(ts[m], sizeof ts[m], "%.2f s", t[m]);
                        else snprintf(ts[m], sizeof ts[m], "never");
                    }
                    check_line("  %5.1f dB, %d light%s: HD %s, CD %s, PT_SS %s, PT_MS %s -> HD sooner than CD: %s",
                               (double)S.levels[k], k_lights[li], li ? "s" : " ", ts[HDE_HD], ts[HDE_CD],
                               ts[HDE_SS], ts[HDE_MS],
                               t[HDE_HD] >= 0 && (t[HDE_CD] < 0 || t[HDE_HD] < t[HDE_CD]) ? "YES"
                               : t[HDE_HD] < 0 && t[HDE_CD] < 0 ? "neither reaches it" : "NO");
                }
            }
        fclose(md);
    }
    fclose(f);
    check_line("\n== equal iterations, PSNR against PT_MS (all pixels): the paper's low-iteration claim");
    for (li = 0; li < 2; ++li) {
        static const int its[] = {1, 2, 4, 8, 16, 32, 64, 128, 256};
        char line[512];
        int n = 0;
        n += snprintf(line + n, sizeof line - n, "  %d light%s:", k_lights[li], li ? "s" : " ");
        for (k = 0; k < 9; ++k) {
            double h = psnr_at(&cur[HDE_HD][li], its[k], 1, 0), c = psnr_at(&cur[HDE_CD][li], its[k], 1, 0);
            if (h < 0 || c < 0) continue;
            n += snprintf(line + n, sizeof line - n, " it %d: HD %.1f / CD %.1f;", its[k], h, c);
        }
        check_line("%s", line);
    }
    check_line("\n== dark start-up: lit part (reference opacity > %g), HD after 1 iteration vs CD after 10",
               (double)S.lit_opacity);
    for (li = 0; li < 2; ++li)
        for (k = 0; k < 2; ++k) {
            double h1 = psnr_at(&cur[HDE_HD][li], 1, k, 1), c1 = psnr_at(&cur[HDE_CD][li], 1, k, 1);
            double c10 = psnr_at(&cur[HDE_CD][li], 10, k, 1);
            check_line("  %d light%s, vs %s: HD@1 %.2f dB, CD@1 %.2f dB, CD@10 %.2f dB -> HD@1 > CD@10: %s",
                       k_lights[li], li ? "s" : " ", k ? "PT_MS" : "PT_SS", h1, c1, c10, h1 > c10 ? "PASS" : "FAIL");
        }
    check_line("\nhdeval: done in %.0f s wall (%.1f min); process CPU time %.0f s = %.1f min on %d idle cores",
               now() - g_t0, (now() - g_t0) / 60.0, cpu_now() * g_cores, cpu_now() / 60.0, g_cores);
    fclose(g_checks);

    for (m = 0; m < HDE_METHODS; ++m)
        for (li = 0; li < 2; ++li) {
            free(refs[m][li].lin); free(refs[m][li].tm); free(refs[m][li].lit);
            free(cur[m][li].p);
            for (k = 0; k < 3; ++k) free(cur[m][li].snap[k]);
        }
    hd_volume_free(&g_vol);
    return 0;
}
