/* hdbench_budget.c - whether render_budget holds (make bench-budget): the head CT scene of the
   orbit benchmarks (bench/hd_orbit_scene.h) at W x H, HD_RENDER_SCALE_AUTO, a camera orbit of F
   frames (one hd_set_camera + hd_render per frame, 1.8 degrees apart), the light cold at the
   orbit's start, so the first frames split light iterations over calls (direct light over part
   of its list, some diffusion sweeps) and every frame is a new view. Per budget: the hd_render
   call's wall time p50 / p99 / max, the frames over the budget, and the light's state at the end.
   The context's set-up call (upload, classification, the direct light's mask: once per volume)
   runs before the orbit, then hd_reset makes the light cold again. Budgets are tried in
   ascending order; the first with no frame over it is the smallest held (--all runs every one).
   Usage: hdbench_budget [--size WxH]... [--frames F] [--budgets ms,ms,...] [--all] [--verbose] [--head path]
   Built for every backend (hdbench_budget, _opencl, _vulkan, _gl). */
#define HYBRIDDIFF_IMPLEMENTATION
#include "hd_orbit_scene.h"

static void die(const char *what, hd_result r)
{
    fprintf(stderr, "hdbench_budget: %s: %s\n", what, hd_result_string(r));
    exit(1);
}

static int verbose; /* --verbose: each frame's stage times on stderr */

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The orbit under a budget of ms milliseconds; returns the frames over it. */
static int run(hdo_scene *sc, int w, int h, int frames, double ms)
{
    hd_desc d = sc->desc;
    hd_context c;
    hd_result r;
    hd_stats st;
    double *t = (double *)malloc(sizeof(double) * (size_t)frames), worst = 0.0, sum = 0.0;
    int f, over = 0, first_conv = -1;
    d.camera = hdo_orbit_camera(0.0, w);
    d.camera.height = h;
    d.params.render_scale = HD_RENDER_SCALE_AUTO;
    d.params.render_budget = (float)(ms * 1e-3);
    if ((r = hd_create(&d, &c)) != HD_SUCCESS) die("hd_create", r);
    if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render (set-up)", r);
    if ((r = hd_reset(c)) != HD_SUCCESS) die("hd_reset", r);
    for (f = 0; f < frames; ++f) {
        hd_camera cam = hdo_orbit_camera(1.8 * (f + 1), w);
        double t0;
        cam.height = h;
        if ((r = hd_set_camera(c, &cam)) != HD_SUCCESS) die("hd_set_camera", r);
        t0 = hdo_now();
        if ((r = hd_render(c)) != HD_SUCCESS) die("hd_render", r);
        t[f] = hdo_now() - t0;
        sum += t[f];
        if (t[f] > worst) worst = t[f];
        if (t[f] > ms * 1e-3) ++over;
        if (verbose) {
            hd_stats s0 = st;
            hd_get_stats(c, &st);
            if (f > 0)
                fprintf(stderr, "frame %3d: %6.2f ms (direct %6.2f, diffusion %6.2f, projection %6.2f), scale %d, iterations %llu + %.2f\n",
                        f, 1e3 * t[f], 1e3 * (st.seconds_direct - s0.seconds_direct), 1e3 * (st.seconds_diffusion - s0.seconds_diffusion),
                        1e3 * (st.seconds_projection - s0.seconds_projection), st.render_scale, (unsigned long long)st.iterations,
                        st.light_progress);
        }
        if (first_conv < 0 && hd_get_stats(c, &st) == HD_SUCCESS && st.light_converged) first_conv = f + 1;
    }
    hd_get_stats(c, &st);
    qsort(t, (size_t)frames, sizeof *t, cmp_d);
    printf("%s %dx%d budget %5.1f ms: hd_render p50 %6.2f ms, p99 %6.2f ms, max %6.2f ms, %3d of %d frames over; "
           "light %s (frame %d), %llu iterations, last scale %d\n",
           hd_backend_name(), w, h, ms, 1e3 * t[frames / 2], 1e3 * t[(int)(0.99 * (frames - 1) + 0.5)], 1e3 * worst, over, frames,
           st.light_converged ? "converged" : "not converged", first_conv, (unsigned long long)st.iterations, st.render_scale);
    fflush(stdout);
    hd_destroy(c);
    free(t);
    (void)sum;
    return over;
}

int main(int argc, char **argv)
{
    int sizes[8][2], nsizes = 0, frames = 200, all = 0, i, k;
    double budgets[32];
    int nb = 0;
    const char *head = "data/head.nrrd", *list = "4,6,8,12,16,24,32,48,64,96,128,192,256";
    hdo_scene sc;
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc && nsizes < 8) {
            if (sscanf(argv[++i], "%dx%d", &sizes[nsizes][0], &sizes[nsizes][1]) == 2) ++nsizes;
        } else if (!strcmp(argv[i], "--frames") && i + 1 < argc) frames = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--budgets") && i + 1 < argc) list = argv[++i];
        else if (!strcmp(argv[i], "--head") && i + 1 < argc) head = argv[++i];
        else if (!strcmp(argv[i], "--all")) all = 1;
        else if (!strcmp(argv[i], "--verbose")) verbose = 1;
        else {
            fprintf(stderr, "usage: hdbench_budget [--size WxH]... [--frames F] [--budgets ms,ms,...] [--all] [--head path]\n");
            return 2;
        }
    }
    while (*list && nb < 32) {
        char *end;
        budgets[nb] = strtod(list, &end);
        if (end == list || !(budgets[nb] > 0.0)) return 2;
        ++nb;
        list = *end == ',' ? end + 1 : end;
    }
    if (nsizes == 0) {
        sizes[0][0] = 1280; sizes[0][1] = 720;
        sizes[1][0] = 1920; sizes[1][1] = 1080;
        nsizes = 2;
    }
    if (frames < 2 || nb == 0) return 2;
    if (!hdo_scene_load(&sc, head, 512, NULL)) return 1;
    for (k = 0; k < nsizes; ++k) {
        int held = 0;
        for (i = 0; i < nb; ++i) {
            int over = run(&sc, sizes[k][0], sizes[k][1], frames, budgets[i]);
            if (over == 0 && !held) {
                printf("%s %dx%d: smallest budget held over %d frames: %.1f ms\n", hd_backend_name(), sizes[k][0], sizes[k][1], frames,
                       budgets[i]);
                held = 1;
                if (!all) break;
            }
        }
        if (!held) printf("%s %dx%d: no budget tried held over %d frames\n", hd_backend_name(), sizes[k][0], sizes[k][1], frames);
    }
    hd_volume_free(&sc.vol);
    return 0;
}
