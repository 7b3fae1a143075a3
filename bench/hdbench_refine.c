/* hdbench_refine - a resting view's refinement (make eval-refine, docs/DESIGN-REFINE.md): PSNR
   against a PT_MS reference per time budget for HD alone, PT_MS alone and HD with
   params.rest = HD_REST_REFINE at several refine_bounces and HD_REST_BLEND, on one view of hdrender's default scene
   (bench/hd_orbit_scene.h: the head CT, the three-quarter camera, one key light, exposure 8).

   Each mode runs in a fresh context (seed 0) and calls hd_render (render_budget 0: one light
   iteration, frame or refinement pass per call) until the largest budget; the image after the
   last call that ended within budget b is the mode's image at b. With --warm the HD modes start
   with converged light (hd_refine at azimuth 45 before the clock starts, then the camera moves
   to the view), as a view reached by orbiting does; without, HD's time includes converging it.
   The clock runs only inside hd_render: process CPU time over the online cores (the wall time
   on otherwise idle cores; the machine may be shared). The reference is two PT_MS halves of
   --ref-iters / 2 paths each (seeds 101, 202), averaged; the PSNR between the halves gives the
   reference's own noise floor (its error against the converged image: that PSNR + 6.02 dB, the
   halves' difference having 4 times the full mean's variance). PSNR as hdeval: tone map
   srgb(clamp(exposure L, 0, 1)), peak 1, RGB of every pixel. Mean: the mode's mean linear
   radiance over the reference's. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "hd_orbit_scene.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

#define MAX_BUDGETS 16
#define MAX_MODES 12

static struct {
    const char *data, *tf, *cache, *csv;
    int size, ref_iters, warm, nb, nm;
    double budgets[MAX_BUDGETS];
    int modes[MAX_MODES]; /* -1000 HD, -2000 PT_MS, -3000 HD_REST_BLEND, else refine_bounces of HD_REST_REFINE */
} O;


static void check(hd_result r, const char *what)
{
    if (r != HD_SUCCESS) {
        fprintf(stderr, "hdbench_refine: %s: %s\n", what, hd_result_string(r));
        exit(1);
    }
}

static void usage(int code)
{
    fprintf(code ? stderr : stdout,
            "usage: hdbench_refine [options] [FILE]     (default data/head.nrrd)\n"
            "  --size N           image size (default 128)\n"
            "  --tf PRESET        ct-skin (default), ct-bone, ...\n"
            "  --ref-iters N      PT_MS reference paths per pixel, two halves (default 1024)\n"
            "  --budgets A,B,..   seconds (default 0.25,1,5,30)\n"
            "  --modes M,..       hd, pt, rK (HD_REST_REFINE, refine_bounces K; r-1: never reads\n"
            "                     HD's light), bl (HD_REST_BLEND) (default hd,pt,r1,r2,r3,r-1)\n"
            "  --warm             HD modes start with converged light (as after an orbit)\n"
            "  --csv FILE         results (default: none)\n"
            "  --cache DIR        reference images (default build/refine-cache)\n");
    exit(code);
}

static void parse_args(int argc, char **argv)
{
    int i;
    const char *modes = "hd,pt,r1,r2,r3,r-1", *budgets = "0.25,1,5,30";
    O.data = "data/head.nrrd";
    O.tf = "ct-skin";
    O.cache = "build/refine-cache";
    O.size = 128;
    O.ref_iters = 1024;
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i];
#define NEXT() (i + 1 < argc ? argv[++i] : (fprintf(stderr, "hdbench_refine: %s needs a value\n", a), exit(2), ""))
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) usage(0);
        else if (!strcmp(a, "--size")) O.size = atoi(NEXT());
        else if (!strcmp(a, "--tf")) O.tf = NEXT();
        else if (!strcmp(a, "--ref-iters")) O.ref_iters = atoi(NEXT());
        else if (!strcmp(a, "--budgets")) budgets = NEXT();
        else if (!strcmp(a, "--modes")) modes = NEXT();
        else if (!strcmp(a, "--warm")) O.warm = 1;
        else if (!strcmp(a, "--csv")) O.csv = NEXT();
        else if (!strcmp(a, "--cache")) O.cache = NEXT();
        else if (a[0] == '-') usage(2);
        else O.data = a;
    }
    if (O.size < 16 || O.size > 4096 || O.ref_iters < 2 || O.ref_iters > (1 << 24)) usage(2);
    while (*budgets && O.nb < MAX_BUDGETS) {
        char *e;
        double x = strtod(budgets, &e);
        if (e == budgets || !(x > 0.0) || (O.nb && x <= O.budgets[O.nb - 1])) usage(2);
        O.budgets[O.nb++] = x;
        budgets = *e ? e + 1 : e;
    }
    while (*modes && O.nm < MAX_MODES) {
        const char *e = strchr(modes, ',');
        size_t n = e ? (size_t)(e - modes) : strlen(modes);
        if (n == 2 && !strncmp(modes, "hd", 2)) O.modes[O.nm++] = -1000;
        else if (n == 2 && !strncmp(modes, "pt", 2)) O.modes[O.nm++] = -2000;
        else if (n == 2 && !strncmp(modes, "bl", 2)) O.modes[O.nm++] = -3000;
        else if (n >= 2 && modes[0] == 'r') O.modes[O.nm++] = atoi(modes + 1);
        else usage(2);
        modes += n + (e ? 1 : 0);
    }
    if (!O.nb || !O.nm) usage(2);
}

static void mkdirs(const char *dir)
{
    char buf[1024];
    size_t i;
    snprintf(buf, sizeof buf, "%s", dir);
    for (i = 1; buf[i]; ++i)
        if (buf[i] == '/') { buf[i] = 0; mkdir(buf, 0777); buf[i] = '/'; }
    mkdir(buf, 0777);
}

static double mean_rgb(const float *img, size_t npix)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < npix; ++i) s += (double)img[4 * i] + img[4 * i + 1] + img[4 * i + 2];
    return s / (3.0 * (double)npix);
}

/* The reference (linear) and its two halves' PSNR, from the cache or rendered. */
static void reference(const hd_desc *desc, float *lin, double *halves_psnr)
{
    size_t npix = (size_t)O.size * O.size, n = npix * 4, i;
    char path[1024];
    FILE *f;
    float *h[2];
    int k;
    const char *vol = strrchr(O.data, '/') ? strrchr(O.data, '/') + 1 : O.data; /* one reference per volume */
    snprintf(path, sizeof path, "%s/ref-%s-%s-%s-%d-%dspp.f32", O.cache, hd_backend_name(), vol, O.tf, O.size, O.ref_iters);
    h[0] = (float *)malloc(n * sizeof(float));
    h[1] = (float *)malloc(n * sizeof(float));
    if (!h[0] || !h[1]) { fprintf(stderr, "hdbench_refine: out of memory\n"); exit(1); }
    if ((f = fopen(path, "rb")) != NULL) {
        int ok = fread(h[0], sizeof(float), n, f) == n && fread(h[1], sizeof(float), n, f) == n;
        fclose(f);
        if (ok) goto done;
    }
    for (k = 0; k < 2; ++k) {
        hd_desc d = *desc;
        hd_context c;
        double t0 = hdo_now();
        d.params.method = HD_METHOD_PT_MS;
        d.params.seed = (uint32_t)(101 * (k + 1));
        check(hd_create(&d, &c), "hd_create (reference)");
        check(hd_iterate(c, O.ref_iters / 2), "hd_iterate (reference)");
        check(hd_read_image_f32(c, h[k], n), "hd_read_image_f32 (reference)");
        hd_destroy(c);
        fprintf(stderr, "hdbench_refine: reference half %d: %d paths/pixel in %.1f s (wall)\n", k, O.ref_iters / 2,
                hdo_now() - t0);
    }
    mkdirs(O.cache);
    if ((f = fopen(path, "wb")) != NULL) {
        fwrite(h[0], sizeof(float), n, f);
        fwrite(h[1], sizeof(float), n, f);
        fclose(f);
    }
done:
    for (i = 0; i < n; ++i) lin[i] = 0.5f * (h[0][i] + h[1][i]);
    hdx_tonemap_image(h[0], npix, HDO_EXPOSURE);
    hdx_tonemap_image(h[1], npix, HDO_EXPOSURE);
    *halves_psnr = hdx_psnr_rgb(h[0], h[1], npix);
    free(h[0]);
    free(h[1]);
}

static void mode_name(int m, char *buf, size_t n)
{
    if (m == -1000) snprintf(buf, n, "HD");
    else if (m == -2000) snprintf(buf, n, "PT_MS");
    else if (m == -3000) snprintf(buf, n, "blend");
    else snprintf(buf, n, "refine k=%d", m);
}

/* One mode through the budgets: psnr[j], mean[j] (over the reference's), paths[j] (refinement
   or PT paths per pixel), NAN where no call ended within budget j. */
static void run_mode(const hd_desc *desc, int m, const float *ref_tm, double ref_mean, double *psnr, double *mean,
                     double *paths)
{
    size_t npix = (size_t)O.size * O.size;
    float *img = (float *)malloc(npix * 4 * sizeof(float));
    hd_desc d = *desc;
    hd_context c;
    hd_stats st;
    double t = 0.0, last_psnr = NAN, last_mean = NAN, last_paths = NAN;
    int j = 0;
    if (!img) { fprintf(stderr, "hdbench_refine: out of memory\n"); exit(1); }
    d.params.method = m == -2000 ? HD_METHOD_PT_MS : HD_METHOD_HD;
    if (m == -3000) d.params.rest = HD_REST_BLEND;
    else if (m != -1000 && m != -2000) {
        d.params.rest = HD_REST_REFINE;
        d.params.refine_bounces = m;
    }
    if (O.warm && m != -2000) {
        hd_camera cam = hdo_orbit_camera(45.0, O.size);
        d.camera = cam;
        check(hd_create(&d, &c), "hd_create");
        do {
            check(hd_refine(c, 1), "hd_refine");
            check(hd_get_stats(c, &st), "hd_get_stats");
        } while (!st.light_converged && st.iterations < 200);
        cam = hdo_orbit_camera(0.0, O.size);
        check(hd_set_camera(c, &cam), "hd_set_camera");
    } else {
        check(hd_create(&d, &c), "hd_create");
    }
    while (j < O.nb) {
        double t0 = hdo_cpu_clock();
        check(hd_render(c), "hd_render");
        t += hdo_cpu_clock() - t0;
        while (j < O.nb && O.budgets[j] < t) {
            psnr[j] = last_psnr; mean[j] = last_mean; paths[j] = last_paths;
            ++j;
        }
        if (j >= O.nb) break;
        check(hd_read_image_f32(c, img, npix * 4), "hd_read_image_f32");
        check(hd_get_stats(c, &st), "hd_get_stats");
        last_mean = mean_rgb(img, npix) / ref_mean;
        last_paths = m == -2000 ? (double)st.iterations : (double)st.refine_paths;
        hdx_tonemap_image(img, npix, HDO_EXPOSURE);
        last_psnr = hdx_psnr_rgb(img, ref_tm, npix);
        /* HD's image is done and HOLD does nothing more: it is the image at every later budget */
        if (m == -1000 && st.light_converged && st.frames >= 8)
            for (; j < O.nb; ++j) { psnr[j] = last_psnr; mean[j] = last_mean; paths[j] = 0.0; }
    }
    hd_destroy(c);
    free(img);
}

int main(int argc, char **argv)
{
    static hdo_scene s;
    size_t npix;
    float *ref, *ref_tm;
    double halves, ref_mean;
    double psnr[MAX_MODES][MAX_BUDGETS], mean[MAX_MODES][MAX_BUDGETS], paths[MAX_MODES][MAX_BUDGETS];
    int i, j;
    FILE *csv = NULL;
    parse_args(argc, argv);
    if (!hdo_scene_load(&s, O.data, O.size, NULL)) return 1;
    if (!hdx_tf_preset(O.tf, &s.tf)) { fprintf(stderr, "hdbench_refine: unknown TF %s\n", O.tf); return 2; }
    hdx_tf_use(&s.desc, &s.vol.desc, &s.tf);
    npix = (size_t)O.size * O.size;
    ref = (float *)malloc(npix * 4 * sizeof(float));
    ref_tm = (float *)malloc(npix * 4 * sizeof(float));
    if (!ref || !ref_tm) { fprintf(stderr, "hdbench_refine: out of memory\n"); return 1; }
    reference(&s.desc, ref, &halves);
    ref_mean = mean_rgb(ref, npix);
    memcpy(ref_tm, ref, npix * 4 * sizeof(float));
    hdx_tonemap_image(ref_tm, npix, HDO_EXPOSURE);
    for (i = 0; i < O.nm; ++i) {
        char name[32];
        mode_name(O.modes[i], name, sizeof name);
        fprintf(stderr, "hdbench_refine: %s\n", name);
        run_mode(&s.desc, O.modes[i], ref_tm, ref_mean, psnr[i], mean[i], paths[i]);
    }
    printf("hdbench_refine: %s, %s, %dx%d, %s backend, HD %s; reference PT_MS %d paths/pixel "
           "(halves %.2f dB apart: its noise floor about %.1f dB)\n",
           O.data, O.tf, O.size, O.size, hd_backend_name(), O.warm ? "with converged light (--warm)" : "from scratch",
           O.ref_iters, halves, halves + 6.02);
    printf("PSNR dB (paths/pixel) per budget, s of CPU time / cores\n%-14s", "mode");
    for (j = 0; j < O.nb; ++j) printf("  %14.2f", O.budgets[j]);
    printf("  mean@%g s\n", O.budgets[O.nb - 1]);
    if (O.csv && !(csv = fopen(O.csv, "w"))) { fprintf(stderr, "hdbench_refine: cannot write %s\n", O.csv); return 1; }
    if (csv) fprintf(csv, "mode,budget_s,psnr_db,mean_ratio,paths\n");
    for (i = 0; i < O.nm; ++i) {
        char name[32];
        mode_name(O.modes[i], name, sizeof name);
        printf("%-14s", name);
        for (j = 0; j < O.nb; ++j) {
            printf("  %6.2f (%5.0f)", psnr[i][j], paths[i][j]);
            if (csv) fprintf(csv, "%s,%g,%.3f,%.4f,%.0f\n", name, O.budgets[j], psnr[i][j], mean[i][j], paths[i][j]);
        }
        printf("  %.4f\n", mean[i][O.nb - 1]);
    }
    if (csv) fclose(csv);
    free(ref);
    free(ref_tm);
    return 0;
}
