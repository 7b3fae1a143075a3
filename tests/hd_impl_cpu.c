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
    s->dl_brick = ctx->vw.dl_brick;
    {
        int nb[3];
        s->dl_bricks = hd__direct_bricks(ctx->vw.gdims, nb);
    }
    s->dl_n = ctx->dl_n;
    return 1;
}

/* The direct light's mask by its definition (src/hd_direct_mask.h), dual cell by dual cell with
   no majorant-cell shortcut, against the context's (after hd__prepare): 1 when every bit agrees
   and the count matches, 0 otherwise (or for a stale handle or no memory). */
int hdt_direct_mask_check(hd_context h, size_t *tracked);
int hdt_direct_mask_check(hd_context h, size_t *tracked)
{
    hd__ctx *ctx = hd__lookup(h);
    const int *n, *g;
    int dn[3], d, x, y, z, i, ok = 1;
    int32_t *run;
    uint8_t *cell;
    size_t k, count = 0;
    if (!ctx || !ctx->dl.bits) return 0;
    n = ctx->vw.dims;
    g = ctx->vw.gdims;
    for (d = 0; d < 3; ++d) dn[d] = n[d] > 1 ? n[d] - 1 : 1;
    run = (int32_t *)malloc((size_t)ctx->vw.tf_count * sizeof(int32_t));
    cell = (uint8_t *)malloc((size_t)dn[0] * dn[1] * dn[2]);
    if (!run || !cell) {
        free(run);
        free(cell);
        return 0;
    }
    for (i = 0, k = 0; i < ctx->vw.tf_count; ++i) { /* zero-alpha runs, numbered from 1 */
        int zero = !(ctx->vw.tf[4 * i + 3] > 0.0f) || !(ctx->vw.params.extinction > 0.0f);
        if (zero && (i == 0 || run[i - 1] == 0)) ++k;
        run[i] = zero ? (int32_t)k : 0;
    }
    for (z = 0; z < dn[2]; ++z)
        for (y = 0; y < dn[1]; ++y)
            for (x = 0; x < dn[0]; ++x) {
                int c[3], v8, same = 1, one = 1, a;
                float v[8];
                c[0] = x; c[1] = y; c[2] = z;
                for (v8 = 0; v8 < 8; ++v8) {
                    int p[3];
                    for (d = 0; d < 3; ++d) p[d] = c[d] + (v8 >> d & 1) < n[d] ? c[d] + (v8 >> d & 1) : c[d];
                    v[v8] = hd__vol_value(&ctx->vw, ((size_t)p[2] * n[1] + p[1]) * n[0] + p[0]);
                }
                a = hd__dl_run(run, ctx->vw.tf_count, v[0]);
                for (v8 = 1; v8 < 8; ++v8) {
                    if (v[v8] != v[0]) same = 0;
                    if (hd__dl_run(run, ctx->vw.tf_count, v[v8]) != a) one = 0;
                }
                k = 1;
                if (a != 0 && one) k = 0;
                if (same && !(hd__tf_alpha(ctx, v[0]) * ctx->vw.params.extinction > 0.0f)) k = 0;
                for (d = 0; d < 3; ++d)
                    if (!hd__crop_meets(ctx, d, c[d] == 0 ? -1.0 : ((double)c[d] + 0.5) / n[d],
                                        c[d] == dn[d] - 1 ? 2.0 : ((double)c[d] + 1.5) / n[d], HD__DL_COORD_EPS))
                        k = 0;
                cell[((size_t)z * dn[1] + y) * dn[0] + x] = (uint8_t)k;
            }
    for (z = 0; z < g[2]; ++z)
        for (y = 0; y < g[1]; ++y)
            for (x = 0; x < g[0]; ++x) {
                int lo[3], hi[3], cx, cy, cz, on = 0;
                size_t gi = ((size_t)z * g[1] + y) * g[0] + x;
                hd__dl_axis(x, g[0], n[0], &lo[0], &hi[0]);
                hd__dl_axis(y, g[1], n[1], &lo[1], &hi[1]);
                hd__dl_axis(z, g[2], n[2], &lo[2], &hi[2]);
                for (cz = lo[2]; cz <= hi[2] && !on; ++cz)
                    for (cy = lo[1]; cy <= hi[1] && !on; ++cy)
                        for (cx = lo[0]; cx <= hi[0] && !on; ++cx) on = cell[((size_t)cz * dn[1] + cy) * dn[0] + cx];
                count += (size_t)on;
                if (on != (ctx->dl.bits[gi >> 3] >> (gi & 7) & 1)) ok = 0;
            }
    free(run);
    free(cell);
    if (tracked) *tracked = count;
    return ok && count == ctx->vw.dl_count;
}
