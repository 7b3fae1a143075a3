/* The library's implementation for the test program, on the CPU backend. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"

/* The private hooks test_render.c drives HD_RENDER_SCALE_AUTO's cost model with. */
hd_result hdt_frame_cost(hd_context h, int scale, double seconds);
int hdt_first_scale(hd_context h);
hd_result hdt_frame_cost(hd_context h, int scale, double seconds) { return hd__test_frame_cost(h, scale, seconds); }
int hdt_first_scale(hd_context h) { return hd__test_first_scale(h); }

/* The parameter table's rows (src/hd_params.h) for test_params.c. */
int hdt_param_rows(void);
const char *hdt_param_row(int i, size_t *offset, size_t *size, unsigned *invalidates);
int hdt_param_bits(unsigned *direct, unsigned *phi, unsigned *image, unsigned *paths);
int hdt_param_rows(void) { return HD__PARAM_ROWS; }
const char *hdt_param_row(int i, size_t *offset, size_t *size, unsigned *invalidates)
{
    *offset = hd__param_rows[i].offset;
    *size = hd__param_rows[i].size;
    *invalidates = hd__param_rows[i].invalidates;
    return hd__param_rows[i].name;
}
int hdt_param_bits(unsigned *direct, unsigned *phi, unsigned *image, unsigned *paths)
{
    *direct = HD__DIRTY_DIRECT;
    *phi = HD__DIRTY_PHI;
    *image = HD__DIRTY_IMAGE;
    *paths = HD__DIRTY_PATHS;
    return 0;
}
/* A slot's generation set close to its end, for the handle tests (the slot must be free). */
unsigned hdt_slot_generation(int slot, unsigned generation);
unsigned hdt_slot_generation(int slot, unsigned generation)
{
    unsigned old = hd__slots[slot].generation;
    hd__slots[slot].generation = generation;
    return old;
}
int hdt_slots(void);
int hdt_slots(void) { return HD_MAX_CONTEXTS; }
