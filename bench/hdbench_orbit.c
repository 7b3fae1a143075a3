/* hdbench_orbit - the orbit benchmark (make bench-orbit): what reusing converged light across
   views buys. The scene is hdrender's default on the head CT (bench/hd_orbit_scene.h).

   1. Converge HD's light once (hd_refine until hd_stats.light_converged; past --light-iters
      iterations light_tolerance is raised to the error reached: bench/hd_orbit_scene.h).
   2. Frame time: K views of an orbit around the head (azimuth 360 k / K), hd_set_camera +
      hd_render each, at --frame-size, at render_scale 1, 2 and 4; prints ms per orbit frame and
      the light work they did (none once the light has converged). Built once per backend
      (mk/bench.mk). With --auto-budgets, then a dragged camera under HD_RENDER_SCALE_AUTO per
      render_budget (auto_drag): the scales picked, ms per frame, frames over budget.
   3. Quality per time budget (unless --no-psnr), at --size: for each view k and each per-view
      budget b (--budgets, seconds of this machine):
        HD     the converged light, camera at view k, as many hd_render calls as finish within b
               (projection frames, averaged over frame_window; by default render_scale
               HD_RENDER_SCALE_AUTO: a 1/4 and a 1/2 resolution frame, then full frames);
        PT_MS  started afresh at view k (the camera change restarts it), as many path iterations
               as finish within b;
      each against a PT_MS reference of view k (--ref-iters paths per pixel, another seed; cached
      in --cache). PSNR as hdeval: tone map srgb(clamp(exposure L, 0, 1)), peak 1, RGB of every
      pixel. A budget in which not even one frame finishes has no image: PSNR "nan" (frames 0);
      means, minima and maxima are over the views that have one (their count is printed).
      Writes --csv (every view), --out/orbit-mean.csv and --out/orbit-psnr.png (gnuplot), and
      prints the crossover budget: the smallest budget from which on PT_MS has an image in
      every view and a mean PSNR above HD's (or HD lacks an image in some view).
   --single-view: instead of the orbit, one view (azimuth 0) at --size from a fresh context, as
   hdrender renders it: HD refines the light until it converges (hd_refine, no frames), then
   projects frame_window frames (hd_render); PT_MS, also fresh, iterates until its PSNR reaches
   HD's (or --pt-cap times HD's time passes). Prints both times against the same PT_MS
   reference (another seed) and which method got there first.
   The clock runs only inside hd_render / hd_refine / hd_iterate calls; reading the image back for the PSNR
   is outside it. It is, by default, process CPU time over the online cores (see bench_clock;
   --clock wall for the wall clock), the time the work takes on otherwise idle cores. Run `hdbench_orbit --help` for the knobs. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "hd_orbit_scene.h"
#include "hd_frames.h"

#include <errno.h>
#include <sys/stat.h>
#include <unistd.h>

#define MAX_VIEWS 360
#define MAX_BUDGETS 32
#define MAX_FRAMES 256

static struct {
    const char *data, *csv, *out, *cache;
    int views, size, frame_size, ref_iters, light_iters, psnr, downsample, boundary, paper;
    int nb, nab, wall, single, scale, window;
    double pt_cap;
    double budgets[MAX_BUDGETS], auto_budgets[MAX_BUDGETS];
} O;

/* The budget clock: wall time, or (default) this process's CPU time over the online cores, which
   is the wall time on otherwise idle cores when the workers block instead of spinning (the CPU
   backend's do): on a shared machine it stays put while the wall clock stretches with the load. */
static double bench_clock(void) { return O.wall ? hdo_now() : hdo_cpu_clock(); }

static void check(hd_result r, const char *what)
{
    if (r != HD_SUCCESS) {
        fprintf(stderr, "hdbench_orbit: %s: %s\n", what, hd_result_string(r));
        exit(1);
    }
}

static void usage(int code)
{
    fprintf(code ? stderr : stdout,
            "usage: hdbench_orbit [options] [FILE]      (default data/head.nrrd)\n"
            "  --views K          views of the orbit (default 8)\n"
            "  --frame-size N     image size of the frame-time part (default 512)\n"
            "  --size N           image size of the PSNR part (default 256)\n"
            "  --budgets A,B,..   per-view budgets in seconds (default 0.05,0.1,0.25,0.5,1,2,5)\n"
            "  --ref-iters N      PT_MS reference paths per pixel (default 128)\n"
            "  --light-iters N    cap on HD light iterations while converging (default 24; 2 with\n"
            "                     --no-psnr); past it light_tolerance is raised to the error\n"
            "                     reached, so frames stay projections (said in the output)\n"
            "  --preset default|paper   HD's settings: the library's defaults (zeroed hd_params:\n"
            "                     grid /2, surface boundary; default, hdrender's) or the paper's\n"
            "                     (hd_params_preset: full grid, box boundary, 4 sweeps)\n"
            "  --boundary box|surface   HD's diffusion boundary (default: the preset's)\n"
            "  --downsample N     HD's illumination grid divisor (default: the preset's)\n"
            "  --render-scale S   HD's frames in the PSNR part: auto (default: HD_RENDER_SCALE_AUTO,\n"
            "                     1/4, 1/2, then full frames at each view) or a divisor 1..8\n"
            "  --frame-window N   HD's frame_window (default 0: the library's, 8)\n"
            "  --clock cpu|wall   what the budgets measure: process CPU time / online cores\n"
            "                     (default; load-independent on a shared machine) or wall time\n"
            "  --no-psnr          frame time only (what the GPU backends' builds run)\n"
            "  --auto-budgets A,B,..  frame time part: then, for each render_budget (seconds),\n"
            "                     one hd_render per view with HD_RENDER_SCALE_AUTO (a dragged\n"
            "                     camera): the scales it picked, ms per frame, frames over budget\n"
            "  --single-view      one view at --size, hdrender's schedule against PT_MS afresh:\n"
            "                     the time each needs to reach HD's converged PSNR\n"
            "  --pt-cap X         single view: PT_MS stops after X times HD's time (default 8)\n"
            "  --csv FILE         per-view results (default docs/orbit/orbit.csv)\n"
            "  --out DIR          the plot (default docs/orbit)\n"
            "  --cache DIR        reference images (default build/orbit-cache)\n");
    exit(code);
}

static int parse_int(const char *s, int lo, int hi)
{
    char *e;
    long v;
    errno = 0;
    v = strtol(s, &e, 10);
    if (errno || e == s || *e || v < lo || v > hi) {
        fprintf(stderr, "hdbench_orbit: '%s' is not an integer in %d..%d\n", s, lo, hi);
        exit(2);
    }
    return (int)v;
}

/* A comma-separated list of increasing positive seconds into v; returns the count. */
static int parse_seconds(const char *opt, const char *s, double *v)
{
    int n = 0;
    while (*s) {
        char *e;
        double x = strtod(s, &e);
        if (e == s || !(x > 0.0) || x > 1e5 || n == MAX_BUDGETS || (n && x <= v[n - 1]) || (*e && *e != ',')) {
            fprintf(stderr, "hdbench_orbit: %s: increasing positive seconds, comma-separated, at most %d\n", opt,
                    MAX_BUDGETS);
            exit(2);
        }
        v[n++] = x;
        s = *e ? e + 1 : e;
    }
    if (!n) { fprintf(stderr, "hdbench_orbit: %s is empty\n", opt); exit(2); }
    return n;
}

static void parse_args(int argc, char **argv)
{
    int i;
    O.data = "data/head.nrrd";
    O.csv = "docs/orbit/orbit.csv";
    O.out = "docs/orbit";
    O.cache = "build/orbit-cache";
    O.views = 8;
    O.size = 256;
    O.frame_size = 512;
    O.ref_iters = 128;
    O.light_iters = -1;
    O.psnr = 1;
    O.downsample = 0;
    O.pt_cap = 8.0;
    O.scale = HD_RENDER_SCALE_AUTO;
    {
        static const double def[] = {0.05, 0.1, 0.25, 0.5, 1, 2, 5};
        O.nb = 7;
        memcpy(O.budgets, def, sizeof def);
    }
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i];
#define NEXT() (i + 1 < argc ? argv[++i] : (fprintf(stderr, "hdbench_orbit: %s needs a value\n", a), exit(2), ""))
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) usage(0);
        else if (!strcmp(a, "--views")) O.views = parse_int(NEXT(), 1, MAX_VIEWS);
        else if (!strcmp(a, "--size")) O.size = parse_int(NEXT(), 16, 4096);
        else if (!strcmp(a, "--frame-size")) O.frame_size = parse_int(NEXT(), 16, 4096);
        else if (!strcmp(a, "--ref-iters")) O.ref_iters = parse_int(NEXT(), 1, 1 << 24);
        else if (!strcmp(a, "--light-iters")) O.light_iters = parse_int(NEXT(), 1, 1 << 20);
        else if (!strcmp(a, "--downsample")) O.downsample = parse_int(NEXT(), 1, 8);
        else if (!strcmp(a, "--frame-window")) O.window = parse_int(NEXT(), 1, 1 << 20);
        else if (!strcmp(a, "--render-scale")) {
            const char *v = NEXT();
            O.scale = !strcmp(v, "auto") ? HD_RENDER_SCALE_AUTO : parse_int(v, 1, 8);
        }
        else if (!strcmp(a, "--no-psnr")) O.psnr = 0;
        else if (!strcmp(a, "--single-view")) O.single = 1;
        else if (!strcmp(a, "--pt-cap")) {
            char *e;
            const char *v = NEXT();
            O.pt_cap = strtod(v, &e);
            if (e == v || *e || !(O.pt_cap >= 1.0) || O.pt_cap > 1e4) {
                fprintf(stderr, "hdbench_orbit: --pt-cap: a number in 1..10000\n");
                exit(2);
            }
        }
        else if (!strcmp(a, "--clock")) {
            const char *v = NEXT();
            if (!strcmp(v, "wall")) O.wall = 1;
            else if (!strcmp(v, "cpu")) O.wall = 0;
            else { fprintf(stderr, "hdbench_orbit: --clock: cpu or wall\n"); exit(2); }
        }
        else if (!strcmp(a, "--csv")) O.csv = NEXT();
        else if (!strcmp(a, "--out")) O.out = NEXT();
        else if (!strcmp(a, "--cache")) O.cache = NEXT();
        else if (!strcmp(a, "--boundary")) {
            const char *v = NEXT();
            if (!strcmp(v, "box")) O.boundary = HD_BOUNDARY_BOX;
            else if (!strcmp(v, "surface")) O.boundary = HD_BOUNDARY_SURFACE;
            else { fprintf(stderr, "hdbench_orbit: --boundary: box or surface\n"); exit(2); }
        } else if (!strcmp(a, "--preset")) {
            const char *v = NEXT();
            if (!strcmp(v, "default")) O.paper = 0;
            else if (!strcmp(v, "paper")) O.paper = 1;
            else { fprintf(stderr, "hdbench_orbit: --preset: default or paper\n"); exit(2); }
        } else if (!strcmp(a, "--budgets")) O.nb = parse_seconds(a, NEXT(), O.budgets);
        else if (!strcmp(a, "--auto-budgets")) O.nab = parse_seconds(a, NEXT(), O.auto_budgets);
        else if (a[0] == '-') {
            fprintf(stderr, "hdbench_orbit: unknown option '%s' (see --help)\n", a);
            exit(2);
        } else O.data = a;
#undef NEXT
    }
    if (O.light_iters < 0) O.light_iters = O.psnr ? 24 : 2;
}

static void mkdirs(const char *dir)
{
    char buf[4096], *p;
    if (strlen(dir) >= sizeof buf) return;
    strcpy(buf, dir);
    for (p = buf + 1; *p; ++p)
        if (*p == '/') { *p = 0; mkdir(buf, 0777); *p = '/'; }
    mkdir(buf, 0777);
}

static void parent_dirs(const char *path)
{
    char buf[4096], *s;
    if (strlen(path) >= sizeof buf) return;
    strcpy(buf, path);
    s = strrchr(buf, '/');
    if (s) { *s = 0; mkdirs(buf); }
}

static double light_seconds(hd_context c)
{
    hd_stats st;
    check(hd_get_stats(c, &st), "hd_get_stats");
    return st.seconds_direct + st.seconds_diffusion;
}

static void set_view(hd_context c, int k, int size)
{
    hd_camera cam = hdo_orbit_camera(360.0 * k / O.views, size);
    check(hd_set_camera(c, &cam), "hd_set_camera");
}

/* The tone-mapped image of ctx into img (npix RGBA floats). */
static void read_tonemapped(hd_context c, float *img, size_t npix)
{
    check(hd_read_image_f32(c, img, npix * 4), "hd_read_image_f32");
    hdx_tonemap_image(img, npix, HDO_EXPOSURE);
}

/* The PT_MS reference of view k, tone-mapped, from the cache or rendered (and cached). */
static void reference(const hdo_scene *s, int k, float *img)
{
    size_t npix = (size_t)O.size * (size_t)O.size;
    char path[4200];
    FILE *f;
    hd_desc d = s->desc;
    hd_context c;
    double t0;
    snprintf(path, sizeof path, "%s/ref-%s-%d-v%dof%d-%dspp.f32", O.cache, hd_backend_name(),
             O.size, k, O.views, O.ref_iters);
    f = fopen(path, "rb");
    if (f) {
        size_t got = fread(img, sizeof(float), npix * 4, f);
        fclose(f);
        if (got == npix * 4) return;
    }
    d.camera = hdo_orbit_camera(360.0 * k / O.views, O.size);
    d.params.method = HD_METHOD_PT_MS;
    d.params.seed = 0x5eed0f;
    check(hd_create(&d, &c), "hd_create (reference)");
    t0 = hdo_now();
    check(hd_iterate(c, O.ref_iters), "hd_iterate (reference)");
    read_tonemapped(c, img, npix);
    hd_destroy(c);
    fprintf(stderr, "hdbench_orbit: reference view %d: %d paths/pixel in %.1f s\n", k,
            O.ref_iters, hdo_now() - t0);
    mkdirs(O.cache);
    f = fopen(path, "wb");
    if (f) {
        fwrite(img, sizeof(float), npix * 4, f);
        fclose(f);
    }
}

/* --auto-budgets: a dragged camera under HD_RENDER_SCALE_AUTO, for each render_budget: one
   hd_render per view (each a new image, so each frame is at the first scale AUTO picks for it,
   predicted from the frames measured so far), over the orbit. Prints how often each scale was
   picked, the wall time per frame and how many frames took longer than the budget. */
static void auto_drag(hd_context hd)
{
    int j, k;
    for (j = 0; j < O.nab; ++j) {
        hd_desc q;
        hd_stats st;
        int n[4] = {0, 0, 0, 0}, over = 0;
        double sum = 0.0, worst = 0.0, l0 = light_seconds(hd);
        check(hd_query_desc(hd, &q), "hd_query_desc");
        q.params.render_scale = HD_RENDER_SCALE_AUTO;
        q.params.render_budget = (float)O.auto_budgets[j];
        check(hd_set_params(hd, &q.params), "hd_set_params");
        for (k = 0; k < O.views; ++k) {
            double t;
            set_view(hd, k, O.frame_size);
            t = hdo_now();
            check(hd_render(hd), "hd_render");
            t = hdo_now() - t;
            check(hd_get_stats(hd, &st), "hd_get_stats");
            n[st.render_scale >= 8 ? 3 : st.render_scale >= 4 ? 2 : st.render_scale >= 2 ? 1 : 0]++;
            sum += t;
            if (t > worst) worst = t;
            if (t > O.auto_budgets[j]) ++over;
        }
        printf("auto: %s backend, %dx%d, render_budget %g ms, %d views: scale 1/2/4/8 picked %d/%d/%d/%d times, "
               "%.1f ms per frame (wall; slowest %.1f), %d over budget, light work %.3f s\n", hd_backend_name(),
               O.frame_size, O.frame_size, 1e3 * O.auto_budgets[j], O.views, n[0], n[1], n[2], n[3],
               1e3 * sum / O.views, 1e3 * worst, over, light_seconds(hd) - l0);
        fflush(stdout);
    }
}

/* Runs step() (one hd_render or one PT iteration) while the budgets last; psnr[j] and count[j]:
   the image after the last step that finished within budgets[j]. hd_mode: stop once the image is
   final (light converged, frame_window frames at the final scale: further calls change nothing). */
static void budget_run(hd_context c, int hd_mode, const float *ref, float *img, double *psnr,
                       int *count)
{
    size_t npix = (size_t)O.size * (size_t)O.size;
    double t = 0.0, last = NAN;
    int j = 0, n = 0;
    hd_desc d = HD_DESC_INIT; /* zeroed: gcc 12 cannot see hd_query_desc set it */
    check(hd_query_desc(c, &d), "hd_query_desc");
    while (j < O.nb) {
        double ts = bench_clock();
        hd_stats st;
        check(hd_mode ? hd_render(c) : hd_iterate(c, 1), hd_mode ? "hd_render" : "hd_iterate");
        t += bench_clock() - ts;
        while (j < O.nb && O.budgets[j] < t) { psnr[j] = last; count[j] = n; ++j; }
        ++n;
        read_tonemapped(c, img, npix);
        last = hdx_psnr_rgb(img, ref, npix);
        check(hd_get_stats(c, &st), "hd_get_stats");
        if (hd_mode && st.light_converged && st.frames >= (uint64_t)d.params.frame_window &&
            (d.params.render_scale != HD_RENDER_SCALE_AUTO || st.render_scale == 1))
            while (j < O.nb) { psnr[j] = last; count[j] = n; ++j; }
    }
}

/* --single-view: hdrender's schedule for HD against PT_MS on one view, both from a fresh
   context, each against the PT_MS reference of view 0 at --size. */
static int single_view(const hdo_scene *s)
{
    size_t npix = (size_t)O.size * (size_t)O.size;
    float *ref = (float *)malloc(npix * 4 * sizeof(float)), *img = (float *)malloc(npix * 4 * sizeof(float));
    hd_desc d = s->desc;
    hd_context c;
    hd_stats st;
    double t = 0.0, ts, hd_psnr, pt_psnr = NAN, t_light, t_hd, t_pt = -1.0;
    /* after frame k + 1: HD's time and PSNR, and when PT_MS first reached that PSNR */
    double fr_t[MAX_FRAMES], fr_psnr[MAX_FRAMES], fr_pt[MAX_FRAMES];
    int fr_paths[MAX_FRAMES], nfr = 0, it = 0, paths = 0, k, stop = -1;
    uint8_t *prev8 = (uint8_t *)malloc(npix * 4), *cur8 = (uint8_t *)malloc(npix * 4);
    if (!ref || !img || !prev8 || !cur8) { fprintf(stderr, "hdbench_orbit: out of memory\n"); return 1; }
    reference(s, 0, ref);
    /* HD: light to convergence without frames, then the frames (examples/hdrender.c) */
    d.camera = hdo_orbit_camera(0.0, O.size);
    check(hd_create(&d, &c), "hd_create (HD)");
    do {
        ts = bench_clock();
        check(hd_refine(c, 1), "hd_refine");
        t += bench_clock() - ts;
        check(hd_get_stats(c, &st), "hd_get_stats");
    } while (!st.light_converged && ++it < O.light_iters);
    t_light = t;
    check(hd_query_desc(c, &d), "hd_query_desc");
    /* hdrender's stop (examples/hd_frames.h) unless --frame-window is given; the frames after it
       are still projected for the per-frame table */
    do {
        ts = bench_clock();
        check(hd_render(c), "hd_render");
        check(hd_get_stats(c, &st), "hd_get_stats");
        if (stop < 0 && !O.window && st.frames < (uint64_t)d.params.frame_window) {
            uint8_t *tmp;
            check(hd_read_image_rgba8(c, cur8, npix * 4), "hd_read_image_rgba8");
            if (hdx_frames_noise_left(prev8, cur8, npix, st.frames) < HDX_FRAMES_NOISE_DONE && nfr < MAX_FRAMES)
                stop = nfr;
            tmp = prev8, prev8 = cur8, cur8 = tmp;
        }
        t += bench_clock() - ts;
        read_tonemapped(c, img, npix);
        if (nfr < MAX_FRAMES) {
            fr_t[nfr] = t;
            fr_psnr[nfr] = hdx_psnr_rgb(img, ref, npix);
            fr_pt[nfr] = -1.0;
            fr_paths[nfr++] = 0;
        }
    } while (st.frames < (uint64_t)d.params.frame_window);
    if (stop < 0) stop = nfr - 1;
    hd_psnr = fr_psnr[stop];
    printf("single view: %s backend, head CT, %dx%d, %s clock\n", hd_backend_name(), O.size, O.size,
           O.wall ? "wall" : "CPU time / cores");
    t_hd = fr_t[stop];
    printf("  HD     %.2f dB after %.2f s (light: %llu iterations, %.2f s, %s, light_error %.4g; then %d "
           "frames, %.2f s%s)\n", hd_psnr, t_hd, (unsigned long long)st.iterations, t_light,
           st.light_converged ? "converged" : "iteration cap", st.light_error, stop + 1, t_hd - t_light,
           O.window ? "" : ", hdrender's stop");
    fflush(stdout);
    hd_destroy(c);
    free(prev8);
    free(cur8);
    /* PT_MS from scratch until it reaches HD's PSNR */
    d = s->desc;
    d.camera = hdo_orbit_camera(0.0, O.size);
    d.params.method = HD_METHOD_PT_MS;
    check(hd_create(&d, &c), "hd_create (PT_MS)");
    t = 0.0;
    for (;;) {
        ts = bench_clock();
        check(hd_iterate(c, 1), "hd_iterate (PT_MS)");
        t += bench_clock() - ts;
        ++paths;
        read_tonemapped(c, img, npix);
        pt_psnr = hdx_psnr_rgb(img, ref, npix);
        for (k = 0; k < nfr; ++k)
            if (fr_pt[k] < 0.0 && pt_psnr >= fr_psnr[k]) { fr_pt[k] = t; fr_paths[k] = paths; }
        if (pt_psnr >= hd_psnr) { t_pt = t; break; }
        if (t > O.pt_cap * t_hd) break;
    }
    hd_destroy(c);
    if (t_pt >= 0.0)
        printf("  PT_MS  %.2f dB after %.2f s (%d paths/pixel): HD's PSNR reached\n", pt_psnr, t_pt, paths);
    else
        printf("  PT_MS  %.2f dB after %.2f s (%d paths/pixel): below HD's PSNR when stopped (--pt-cap %g)\n",
               pt_psnr, t, paths, O.pt_cap);
    printf("  reference: PT_MS, %d paths/pixel, another seed\n", O.ref_iters);
    printf("  HD after each frame (the light's time included) and PT_MS's time to that PSNR:\n"
           "  frames  HD s     HD dB   PT_MS s  paths\n");
    for (k = 0; k < nfr; ++k) {
        if (fr_pt[k] >= 0.0)
            printf("  %6d  %7.2f  %6.2f  %7.2f  %5d\n", k + 1, fr_t[k], fr_psnr[k], fr_pt[k], fr_paths[k]);
        else
            printf("  %6d  %7.2f  %6.2f  not reached\n", k + 1, fr_t[k], fr_psnr[k]);
    }
    if (t_pt >= 0.0 && t_pt < t_hd)
        printf("  PT_MS first: it reached HD's PSNR in %.2f s, HD took %.2f s (%.2fx)\n", t_pt, t_hd, t_hd / t_pt);
    else if (t_pt >= 0.0)
        printf("  HD first: %.2f s, PT_MS needed %.2f s for the same PSNR (%.2fx)\n", t_hd, t_pt, t_pt / t_hd);
    else
        printf("  HD first: %.2f s, PT_MS below HD's PSNR after %.2f s (> %.2fx)\n", t_hd, t, t / t_hd);
    free(ref);
    free(img);
    return 0;
}

static void plot(const char *mean_csv, const char *png)
{
    char script[4600], cmd[4800];
    FILE *f;
    mkdirs(O.cache);
    snprintf(script, sizeof script, "%s/orbit-psnr.gp", O.cache);
    f = fopen(script, "w");
    if (!f) return;
    fprintf(f,
            "set terminal pngcairo size 900,560 noenhanced\nset output '%s'\n"
            "set datafile separator ','\nset logscale x\nset grid\nset key bottom right\n"
            "set xlabel 'per-view time budget (s of %s, %s backend)'\nset ylabel 'PSNR vs PT_MS reference (dB)'\n"
            "set title 'Orbit of %d views, head CT %dx%d: HD over its light (refined once) vs PT_MS afresh per view'\n"
            "plot '%s' every ::1 using 1:2:3:4 with yerrorlines lw 2 title 'HD (projection frames; mean, min..max over views)', "
            "'' every ::1 using 1:5:6:7 with yerrorlines lw 2 title 'PT_MS (paths; mean, min..max)'\n",
            png, O.wall ? "wall clock" : "CPU time / cores", hd_backend_name(), O.views, O.size, O.size, mean_csv);
    fclose(f);
    snprintf(cmd, sizeof cmd, "gnuplot '%s'", script);
    if (system(cmd) != 0) fprintf(stderr, "hdbench_orbit: gnuplot failed (%s)\n", script);
}

int main(int argc, char **argv)
{
    static hdo_scene s;
    hd_logger log = {hd_log_stderr, NULL};
    hd_context hd;
    hd_stats st;
    double t0, c0, l0, ms, cms, lit, conv_s;
    int k, conv, scale;

    parse_args(argc, argv);
    log.func = NULL; /* info lines would drown the table; errors come back as results */
    if (!hdo_scene_load(&s, O.data, O.frame_size, &log)) return 1;
    check(hd_params_preset(O.paper ? HD_PRESET_PAPER : HD_PRESET_DEFAULT, &s.desc.params, NULL),
          "hd_params_preset");
    if (O.downsample) s.desc.params.illumination_downsample = O.downsample;
    if (O.boundary) s.desc.params.diffusion_boundary = (hd_boundary)O.boundary;
    s.desc.params.frame_window = O.window;
    printf("HD settings: %s preset, illumination grid /%d, %s boundary, frame_window %d; orbit PSNR part: "
           "render_scale %s\n", O.paper ? "paper" : "default",
           s.desc.params.illumination_downsample ? s.desc.params.illumination_downsample : 2,
           s.desc.params.diffusion_boundary == HD_BOUNDARY_BOX ? "box" : "surface", O.window ? O.window : 8,
           O.scale == HD_RENDER_SCALE_AUTO ? "auto" : (char[2]){(char)('0' + O.scale), 0});
    if (O.single) {
        int r = single_view(&s);
        hd_volume_free(&s.vol);
        return r;
    }
    check(hd_create(&s.desc, &hd), "hd_create");

    /* 1. converge the light */
    conv = hdo_converge(hd, O.light_iters, "hdbench_orbit", &conv_s);
    if (conv < 0) return 1;
    check(hd_get_stats(hd, &st), "hd_get_stats");
    printf("orbit: %s backend, head CT, HD light %s after %llu iterations in %.1f s (light_error "
           "%.4g%s)\n", hd_backend_name(), conv ? "converged" : "accepted", (unsigned long long)st.iterations,
           conv_s, st.light_error, conv ? "" : "; --light-iters cap, light_tolerance raised to it");

    /* 2. frame time over the orbit, full frames and render_scale 2 and 4 */
    for (scale = 1; scale <= 4; scale *= 2) {
        hd_desc q;
        check(hd_query_desc(hd, &q), "hd_query_desc");
        q.params.render_scale = scale;
        check(hd_set_params(hd, &q.params), "hd_set_params");
        set_view(hd, 0, O.frame_size);
        check(hd_render(hd), "hd_render"); /* warm-up: the image at this size */
        l0 = light_seconds(hd);
        t0 = hdo_now();
        c0 = bench_clock();
        for (k = 0; k < O.views; ++k) {
            set_view(hd, k, O.frame_size);
            check(hd_render(hd), "hd_render");
        }
        ms = 1e3 * (hdo_now() - t0) / O.views;
        cms = 1e3 * (bench_clock() - c0) / O.views;
        lit = light_seconds(hd) - l0;
        printf("orbit: %s backend, %dx%d, render_scale %d, %d views: %.1f ms per orbit frame (set_camera + "
               "hd_render; wall; %s %.1f ms), light work during them %.3f s\n", hd_backend_name(), O.frame_size,
               O.frame_size, scale, O.views, ms, O.wall ? "wall" : "CPU time / cores", cms, lit);
        fflush(stdout);
    }
    auto_drag(hd);
    {
        hd_desc q;
        check(hd_query_desc(hd, &q), "hd_query_desc");
        q.params.render_scale = O.scale;
        check(hd_set_params(hd, &q.params), "hd_set_params");
    }

    /* 3. PSNR per view and budget */
    if (O.psnr) {
        size_t npix = (size_t)O.size * (size_t)O.size;
        float *ref = (float *)malloc(npix * 4 * sizeof(float));
        float *img = (float *)malloc(npix * 4 * sizeof(float));
        static double hp[MAX_VIEWS][MAX_BUDGETS], pp[MAX_VIEWS][MAX_BUDGETS];
        static int hn[MAX_VIEWS][MAX_BUDGETS], pn[MAX_VIEWS][MAX_BUDGETS];
        hd_desc d = s.desc;
        hd_context pt;
        char mean_csv[4200], png[4200];
        double cross = -1.0;
        FILE *f;
        int j;
        if (!ref || !img) { fprintf(stderr, "hdbench_orbit: out of memory\n"); return 1; }
        check(hd_query_desc(hd, &d), "hd_query_desc");
        d.camera = hdo_orbit_camera(0.0, O.size);
        d.params.method = HD_METHOD_PT_MS;
        d.lights = &s.light;
        d.light_count = 1;
        hdx_tf_use(&d, &s.vol.desc, &s.tf);
        check(hd_create(&d, &pt), "hd_create (PT_MS)");
        for (k = 0; k < O.views; ++k) {
            reference(&s, k, ref);
            set_view(hd, k, O.size);
            budget_run(hd, 1, ref, img, hp[k], hn[k]);
            set_view(pt, k, O.size);
            budget_run(pt, 0, ref, img, pp[k], pn[k]);
            printf("view %d:", k);
            for (j = 0; j < O.nb; ++j) printf(" %gs HD %.2f (%d) PT_MS %.2f (%d) |", O.budgets[j],
                                              hp[k][j], hn[k][j], pp[k][j], pn[k][j]);
            printf("\n");
            fflush(stdout);
        }
        hd_destroy(pt);
        parent_dirs(O.csv);
        f = fopen(O.csv, "w");
        if (!f) { fprintf(stderr, "hdbench_orbit: cannot write %s\n", O.csv); return 1; }
        fprintf(f, "view,azimuth_deg,budget_s,hd_psnr_db,hd_frames,ptms_psnr_db,ptms_paths\n");
        for (k = 0; k < O.views; ++k)
            for (j = 0; j < O.nb; ++j)
                fprintf(f, "%d,%.2f,%g,%.4f,%d,%.4f,%d\n", k, 360.0 * k / O.views, O.budgets[j],
                        hp[k][j], hn[k][j], pp[k][j], pn[k][j]);
        fclose(f);
        snprintf(mean_csv, sizeof mean_csv, "%s/orbit-mean.csv", O.out);
        mkdirs(O.out);
        f = fopen(mean_csv, "w");
        if (!f) { fprintf(stderr, "hdbench_orbit: cannot write %s\n", mean_csv); return 1; }
        fprintf(f, "budget_s,hd_mean,hd_min,hd_max,ptms_mean,ptms_min,ptms_max,hd_views,ptms_views\n");
        printf("\nbudget_s  HD mean (min..max) dB [views with a frame]   PT_MS mean (min..max) dB [views]"
               "   (%d views, %dx%d, reference %d paths/pixel)\n", O.views, O.size, O.size, O.ref_iters);
        for (j = 0; j < O.nb; ++j) {
            /* over the views in which at least one frame finished within the budget */
            double m[2] = {0, 0}, lo[2] = {NAN, NAN}, hi[2] = {NAN, NAN};
            int c, nv[2] = {0, 0};
            for (k = 0; k < O.views; ++k)
                for (c = 0; c < 2; ++c) {
                    double v = c ? pp[k][j] : hp[k][j];
                    if (v != v) continue;
                    m[c] += v;
                    if (!nv[c] || v < lo[c]) lo[c] = v;
                    if (!nv[c] || v > hi[c]) hi[c] = v;
                    ++nv[c];
                }
            for (c = 0; c < 2; ++c) m[c] = nv[c] ? m[c] / nv[c] : NAN;
            fprintf(f, "%g,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d,%d\n", O.budgets[j], m[0], lo[0], hi[0],
                    m[1], lo[1], hi[1], nv[0], nv[1]);
            printf("%8g  %6.2f (%6.2f..%6.2f) [%d]          %6.2f (%6.2f..%6.2f) [%d]\n", O.budgets[j],
                   m[0], lo[0], hi[0], nv[0], m[1], lo[1], hi[1], nv[1]);
            /* the crossover: PT_MS above HD here and at every later budget (a method with no
               frame in every view counts as below) */
            if (!(nv[1] == O.views && (nv[0] < O.views || m[1] > m[0]))) cross = -1.0;
            else if (cross < 0) cross = O.budgets[j];
        }
        fclose(f);
        if (cross > 0)
            printf("crossover: PT_MS's mean PSNR is above HD's from a per-view budget of %g s on\n",
                   cross);
        else
            printf("crossover: none within the budgets: HD's mean PSNR stays above PT_MS's at the "
                   "largest budget\n");
        snprintf(png, sizeof png, "%s/orbit-psnr.png", O.out);
        plot(mean_csv, png);
        printf("wrote %s, %s, %s\n", O.csv, mean_csv, png);
        free(ref);
        free(img);
    }
    hd_destroy(hd);
    hd_volume_free(&s.vol);
    return 0;
}
