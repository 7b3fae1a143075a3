/* The library's implementation for the test program, on the CPU backend. */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"

/* The private hooks test_render.c drives HD_RENDER_SCALE_AUTO's cost model with. */
hd_result hdt_frame_cost(hd_context h, int scale, double seconds);
int hdt_first_scale(hd_context h);
hd_result hdt_frame_cost(hd_context h, int scale, double seconds) { return hd__test_frame_cost(h, scale, seconds); }
int hdt_first_scale(hd_context h) { return hd__test_first_scale(h); }
