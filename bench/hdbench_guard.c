/* hdbench_guard - the cost of the per-context in-call guard (src/hd_handles.h, HD__GUARDED):
   this file is built three times into one program (make bench-guard): twice as the library's
   implementation, with the guard and with HD__NO_CALL_GUARD (the handle's lookup alone, as
   before the guard), each HYBRIDDIFF_STATIC so the two stay apart, and once as the driver. It
   times tight loops on a 4^3 volume with a 4x4 image, one thread: hd_get_stats (the cheapest
   call: the lookup and the guard are most of it) and hd_render once the light has converged
   (a projection frame), in interleaved rounds, best round of each; ns per call.
   Usage: hdbench_guard [rounds (default 7)]. Figures, not a test. */
#ifdef HB_SIDE
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_STATIC
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include <time.h>

#define HB_CAT2(a, b) a##b
#define HB_CAT(a, b) HB_CAT2(a, b)

static double hb_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Seconds for n calls of hd_get_stats (what == 0) or hd_render (1) on a fresh context; -1 on error. */
double HB_CAT(HB_SIDE, _run)(int what, long n);
double HB_CAT(HB_SIDE, _run)(int what, long n)
{
    static uint8_t vox[64];
    hd_desc d;
    hd_context c;
    hd_stats st;
    double t0, t;
    long i;
    int k;
    for (k = 0; k < 64; ++k) vox[k] = (uint8_t)(k * 4);
    memset(&d, 0, sizeof d);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = 4;
    d.volume.data = vox;
    d.camera.width = d.camera.height = 4;
    d.threads = 1;
    if (hd_create(&d, &c) != HD_SUCCESS) return -1.0;
    for (k = 0; k < 200; ++k) /* the light converges: hd_render projects a frame only */
        if (hd_render(c) != HD_SUCCESS) return -1.0;
    t0 = hb_now();
    for (i = 0; i < n; ++i)
        if ((what == 0 ? hd_get_stats(c, &st) : hd_render(c)) != HD_SUCCESS) return -1.0;
    t = hb_now() - t0;
    hd_destroy(c);
    return t;
}
#else
#include <stdio.h>
#include <stdlib.h>

double hb_on_run(int what, long n);
double hb_off_run(int what, long n);

int main(int argc, char **argv)
{
    static const char *names[2] = {"hd_get_stats", "hd_render (converged light, 4x4)"};
    static const long calls[2] = {2000000, 50000};
    int rounds = argc > 1 ? atoi(argv[1]) : 7, w, r;
    if (rounds < 1) rounds = 1;
    printf("hdbench_guard: %d interleaved rounds, best of each, ns per call\n", rounds);
    for (w = 0; w < 2; ++w) {
        double best_on = 1e30, best_off = 1e30;
        for (r = 0; r < rounds; ++r) {
            double a = hb_off_run(w, calls[w]), b = hb_on_run(w, calls[w]);
            if (a < 0.0 || b < 0.0) { fprintf(stderr, "hdbench_guard: a call failed\n"); return 1; }
            if (a < best_off) best_off = a;
            if (b < best_on) best_on = b;
        }
        printf("  %-34s without the guard %8.1f ns, with it %8.1f ns: %+.1f ns (%+.1f%%), %ld calls a round\n", names[w],
               1e9 * best_off / (double)calls[w], 1e9 * best_on / (double)calls[w],
               1e9 * (best_on - best_off) / (double)calls[w], 100.0 * (best_on - best_off) / best_off, calls[w]);
    }
    return 0;
}
#endif
