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
    *paths = HD__DIRTY_PATHS;
    *image = HD__DIRTY_IMAGE;
    return 0;
}
/* The warm classes' bits: E and phi kept as the warm start of the new light. */
int hdt_param_warm_bits(unsigned *warm_e, unsigned *warm_phi);
int hdt_param_warm_bits(unsigned *warm_e, unsigned *warm_phi)
{
    *warm_e = HD__DIRTY_WARM_E;
    *warm_phi = HD__DIRTY_WARM_PHI;
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
hd_result hdt_light_uniform(hd_context h, int on);
hd_result hdt_light_uniform(hd_context h, int on) { return hd__test_light_uniform(h, on); }
int hdt_slots(void);
int hdt_slots(void) { return HD_MAX_CONTEXTS; }

#include "hdt_volume_state.h"
int hdt_volume_state_get(hd_context h, hdt_volume_state *s)
{
    hd__ctx *ctx = hd__lookup(h);
    if (!ctx) return 0;
    s->nvox = ctx->vw.nvox;
    s->ncell = (size_t)ctx->vw.mdims[0] * ctx->vw.mdims[1] * ctx->vw.mdims[2];
    s->gvox = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2];
    s->dl_count = ctx->vw.dl_count;
    s->vol = ctx->vw.vol;
    s->vol_bytes = ctx->vw.nvox * hd__vol_elem(ctx->vw.vtype);
    s->cell_range = ctx->cell_range;
    s->majorant = ctx->vw.majorant;
    s->max_sigma = ctx->max_sigma;
    s->bits = ctx->dl.bits;
    s->dl_idx = ctx->vw.dl_idx;
    s->dl_n = ctx->dl_n;
    return 1;
}
