/* test_cpu_fp.c - the CPU backend's floating-point mode: its threads flush denormals to zero
   (x86 FTZ/DAZ, hd_cpu.h) and the caller's mode is what it was after every call. Not among
   mk/reliability.mk's VG_SUITES: valgrind ignores MXCSR's FTZ and DAZ bits, so under memcheck
   the denormals stay (86 in the bar below). */
#include "hybriddiff.h"
#include "hd_test.h"
#include <float.h>
#include <stdlib.h>
#if defined(__SSE__) || defined(_M_X64)
#include <xmmintrin.h>
#define TEST_SSE 1
#endif

/* A 96x4x4 bar: dense medium in x < 4, empty space beyond. Under the box boundary the diffusion
   solves the empty space too, from phi = 0: its front decays by orders of magnitude per voxel and
   underflows, so computing with denormals would leave some in phi. */
#define BX 96
static uint8_t bar[BX * 4 * 4];
static const float bar_tf[8] = {0, 0, 0, 0, 1, 1, 1, 1};

static void bar_desc(hd_desc *d, int threads)
{
    int i;
    for (i = 0; i < BX * 16; ++i) bar[i] = (uint8_t)(i % BX < 4 ? 255 : 0);
    memset(d, 0, sizeof *d);
    /* the paper's grid and boundary (hd_params_preset): these cases are not about the defaults */
    d->params.illumination_downsample = 1;
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = BX;
    d->volume.dims[1] = d->volume.dims[2] = 4;
    d->volume.data = bar;
    d->transfer_function.rgba = bar_tf;
    d->transfer_function.count = 2;
    d->camera.width = d->camera.height = 8;
    d->params.extinction = 100.0f;
    d->params.diffusion_sweeps = 24;
    d->threads = threads;
}

/* Denormal values in the scattered light after a few iterations (x86 only: elsewhere the backend
   computes with denormals, as documented). */
static void test_denormals_flushed(void)
{
#ifdef TEST_SSE
    int threads, zeros = 0;
    for (threads = 1; threads <= 2; ++threads) {
        hd_desc d;
        hd_context ctx;
        size_t i, n = BX * 16, denormal = 0;
        float *phi = (float *)malloc(n * sizeof(float));
        bar_desc(&d, threads);
        CHECK(phi && hd_create(&d, &ctx) == HD_SUCCESS);
        if (!phi) return;
        CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, phi, n) == HD_SUCCESS);
        for (i = 0; i < n; ++i) {
            if (phi[i] != 0.0f && fabsf(phi[i]) < FLT_MIN) ++denormal;
            if (phi[i] == 0.0f) ++zeros;
        }
        CHECK_MSG(denormal == 0, "%d threads: %zu denormal values in phi", threads, denormal);
        CHECK(phi[0] > 0.0f);
        hd_destroy(ctx);
        free(phi);
    }
    CHECK(zeros > 0); /* the front did underflow */
#endif
}

/* The caller's MXCSR (rounding, FTZ/DAZ, exception masks) is unchanged by the calls that compute. */
static void test_caller_mode_kept(void)
{
#ifdef TEST_SSE
    unsigned before = _mm_getcsr(), after;
    int threads;
    _mm_setcsr(before & ~0x8040u); /* denormals on, as a C program starts */
    for (threads = 1; threads <= 2; ++threads) {
        hd_desc d;
        hd_context ctx;
        unsigned mode = _mm_getcsr() & ~0x3Fu; /* the sticky exception flags may change */
        bar_desc(&d, threads);
        CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
        CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
        after = _mm_getcsr() & ~0x3Fu;
        CHECK_MSG(after == mode, "%d threads: MXCSR %#x before, %#x after", threads, mode, after);
        hd_destroy(ctx);
    }
    _mm_setcsr(before);
#endif
}

const hd_test_case hd_tests_cpu_fp[] = {
    {"cpu_fp_denormals_flushed", test_denormals_flushed},
    {"cpu_fp_caller_mode_kept", test_caller_mode_kept},
};
const int hd_tests_cpu_fp_count = sizeof hd_tests_cpu_fp / sizeof hd_tests_cpu_fp[0];
