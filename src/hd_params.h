/* hd_params.h - hd_params as one table (HD__PARAM_TABLE): each field's kind, default, valid
   values and what a change of it invalidates. The defaults (hd__params_defaults), the checks with
   their log lines (hd__check_params), hd_set_params' invalidation (hd__params_dirty) and the list
   the tests walk (hd__param_rows) are generated from it, so a new field is one row. Part of the
   core (src/hd_core.h). */
#include <float.h>
#include <stddef.h>

/* What a change invalidates (hd__params_dirty ORs the rows' bits into the context's dirty set). */
#define HD__DIRTY_PATHS 0x100u /* the path tracers' running mean only: the image while the
                                  method is PT_SS or PT_MS, nothing for HD and CD */
#define HD__DIRTY_WARM_E 0x200u   /* E's solution changed, its mean is the warm start of the new one:
                                     re-weighted to hold at most light_window samples (src/hd_schedule.h) */
#define HD__DIRTY_WARM_PHI 0x400u /* phi's solution changed, phi is the warm start of the new one */
#define HD__DIRTY_VOLUME 0x800u   /* hd_update_volume changed the voxels of the context's box upd:
                                     uploaded, reclassified and the direct light's mask redone there */
#define HD__DIRTY_TF 0x1000u      /* the TF's colours changed and nothing the light depends on: the
                                     TF is uploaded again, nothing reclassified */
#define HD__DIRTY_ENV 0x2000u     /* the environment's tables (vw.env) changed: upload them or free them */
#define HD__INV_NONE 0u        /* the same solution, estimator or encoding */
#define HD__INV_IMAGE ((unsigned)HD__DIRTY_IMAGE)
#define HD__INV_PHI ((unsigned)(HD__DIRTY_PHI | HD__DIRTY_IMAGE))
#define HD__INV_LIGHT ((unsigned)(HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE))
#define HD__INV_MEDIUM ((unsigned)(HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE))
#define HD__INV_GRIDS ((unsigned)(HD__DIRTY_ALLOC | HD__INV_MEDIUM))
/* The warm classes: the solution changes, but the diffusion converges from any start and E's mean
   re-weights (params.light_window), so what is held is the start of the new light, not zeroed */
#define HD__INV_WARM_PHI ((unsigned)(HD__DIRTY_WARM_PHI | HD__DIRTY_IMAGE))
#define HD__INV_WARM_LIGHT ((unsigned)(HD__DIRTY_WARM_E | HD__DIRTY_WARM_PHI | HD__DIRTY_IMAGE))
#define HD__INV_WARM_MEDIUM ((unsigned)(HD__DIRTY_SIGMA | HD__INV_WARM_LIGHT))
#define HD__INV_ALL ((unsigned)HD__DIRTY_ALL)

/* The longest hd_render may refine light or trace paths in one call (params.render_budget). */
#define HD__MAX_RENDER_BUDGET 10.0f
/* The largest background radiance per channel: the image's running mean and the upsample's
   weighted sums of it stay finite (README "Guarantees"). */
#define HD__MAX_BACKGROUND 1e6f

/* The table, in the order the defaults are filled in (a default may read a field above it).
   Every field is zero for "default"; a kind's row is
     ENUM(name, type, default, count, invalidates)            [0, count), else HD_ERROR_INVALID_ENUM
     FLOAT(name, default, lo, hi, open, valid, invalidates)   finite and in [lo, hi] ((lo, hi) with
                                                              open), else HD_ERROR_INVALID_PARAMETER
     INT(name, default, lo, hi, valid, invalidates)           in [lo, hi]
     BOOL(name, invalidates)                                  0 or 1
     SEED(name, invalidates)                                  any value
     FLOAT3(name, default, lo, hi, valid, invalidates)        each component as FLOAT
   `valid` is the log line's wording of the valid values. Checks between fields (the crop box's
   corners, the global majorant against the TF, float16 with multigrid) follow the table in
   hd__check_params and hd__check_majorant. */
#define HD__PARAM_TABLE(ENUM, FLOAT, INT, BOOL, SEED, FLOAT3) \
    ENUM(method, hd_method, HD_METHOD_HD, HD_METHOD_COUNT, HD__INV_ALL) \
    FLOAT(extinction, 100.0f, 0.0f, 1e6f, 0, "in (0, 1e6]", HD__INV_WARM_MEDIUM) \
    FLOAT(albedo, 0.9f, 0.0f, 1.0f, 0, "in (0, 1]", HD__INV_WARM_PHI) \
    FLOAT(anisotropy, 0.0f, -1.0f, 1.0f, 1, "in (-1, 1)", HD__INV_WARM_PHI) \
    FLOAT(majorant, 0.0f, 0.0f, 1e6f, 0, "in [0, 1e6]", HD__INV_MEDIUM) \
    INT(illumination_downsample, 2, 1, 8, "in 1..8", HD__INV_GRIDS) \
    ENUM(illumination_precision, hd_precision, HD_PRECISION_FLOAT32, HD_PRECISION_COUNT, HD__INV_GRIDS) \
    ENUM(solver, hd_solver, hd__solver_auto(p, dims, no_multigrid), HD_SOLVER_COUNT, HD__INV_NONE) \
    INT(diffusion_sweeps, (p->solver == HD_SOLVER_MULTIGRID ? 1 : 4), 1, 100000, "in 1..100000", HD__INV_NONE) \
    BOOL(disable_diffusion, HD__INV_PHI) \
    ENUM(tracking, hd_tracking, HD_TRACKING_RATIO, HD_TRACKING_COUNT, HD__INV_NONE) \
    SEED(seed, HD__INV_LIGHT) \
    FLOAT3(background, 0.0f, 0.0f, HD__MAX_BACKGROUND, "in [0, 1e6]", HD__INV_IMAGE) \
    FLOAT(step, 0.5f, 0.01f, 16.0f, 0, "in [0.01, 16] voxels", HD__INV_IMAGE) \
    INT(frame_window, 8, 1, 0x7fffffff, "at least 1", HD__INV_IMAGE) \
    FLOAT(exposure, 1.0f, 0.0f, FLT_MAX, 0, "finite and >= 0", HD__INV_NONE) \
    INT(max_bounces, 64, 1, 100000, "in 1..100000", HD__DIRTY_PATHS) \
    BOOL(rgb_scattering, HD__INV_GRIDS) \
    ENUM(diffusion_boundary, hd_boundary, HD_BOUNDARY_SURFACE, HD_BOUNDARY_COUNT, HD__INV_PHI) \
    FLOAT(light_tolerance, 0.1f, 0.0f, FLT_MAX, 0, "finite and >= 0", HD__INV_NONE) \
    FLOAT(render_budget, 0.0f, 0.0f, HD__MAX_RENDER_BUDGET, 0, "in [0, 10] seconds", HD__INV_NONE) \
    FLOAT3(crop_min, 0.0f, 0.0f, 1.0f, "in [0, 1]", HD__INV_MEDIUM) \
    FLOAT3(crop_max, 1.0f, 0.0f, 1.0f, "in [0, 1]", HD__INV_MEDIUM) \
    INT(render_scale, 1, -1, HD__MAX_RENDER_SCALE, "1..16 or HD_RENDER_SCALE_AUTO (-1)", HD__INV_IMAGE) \
    INT(light_window, 8, 1, 1000000, "in 1..1000000", HD__INV_NONE) \
    ENUM(rest, hd_rest, HD_REST_HOLD, HD_REST_COUNT, HD__INV_IMAGE) \
    INT(refine_bounces, -1, -1, 100000, "-1 or 1..100000", HD__INV_IMAGE) \
    FLOAT(depth_threshold, 0.5f, 0.0f, 1.0f, 0, "in (0, 1]", HD__INV_IMAGE) \
    BOOL(environment_background, HD__INV_IMAGE)

/* ---- HD_SOLVER_AUTO -------------------------------------------------------------------------------
   Red-black's iterations to converge grow with the grid (18 at the head CT's 0.9 M grid voxels,
   28 at 7.1 M, 35 at 16.8 M), multigrid's do not (15-18), and a multigrid step costs 1.3-1.7
   light iterations of red-black's: multigrid converges sooner from HD__SOLVER_AUTO_VOXELS grid
   voxels on (docs/PERFORMANCE.md, "Scale"). Red-black where multigrid cannot run: float16
   illumination, or a device without double precision (no_multigrid, set once a step was refused). */
#define HD__SOLVER_AUTO_VOXELS 4000000u
static hd_solver hd__solver_auto(const hd_params *p, const int *dims, int no_multigrid)
{
    size_t n = 1;
    int d, f = p->illumination_downsample;
    if (!dims || no_multigrid || p->illumination_precision == HD_PRECISION_FLOAT16 || f < 1) return HD_SOLVER_RED_BLACK;
    /* Runs before the checks: f may be INT_MAX, so no dims + f - 1. */
    for (d = 0; d < 3; ++d) n *= (size_t)dims[d] / (size_t)f + ((size_t)dims[d] % (size_t)f != 0);
    return n >= HD__SOLVER_AUTO_VOXELS ? HD_SOLVER_MULTIGRID : HD_SOLVER_RED_BLACK;
}

/* ---- defaults: a zero field gets the row's default --------------------------------------------- */
#define HD__PD_ENUM(n, t, def, count, inv) if ((int)p->n == 0) p->n = def;
#define HD__PD_FLOAT(n, def, lo, hi, open, valid, inv) if (p->n == 0.0f) p->n = def;
#define HD__PD_INT(n, def, lo, hi, valid, inv) if (p->n == 0) p->n = def;
#define HD__PD_NONE(n, inv)
#define HD__PD_FLOAT3(n, def, lo, hi, valid, inv) \
    for (i = 0; i < 3; ++i) \
        if (p->n[i] == 0.0f) p->n[i] = def;
/* dims: the volume's, for HD_SOLVER_AUTO (NULL: red-black); no_multigrid: AUTO picks red-black. */
static void hd__params_defaults(hd_params *p, const int *dims, int no_multigrid)
{
    int i;
    HD__PARAM_TABLE(HD__PD_ENUM, HD__PD_FLOAT, HD__PD_INT, HD__PD_NONE, HD__PD_NONE, HD__PD_FLOAT3)
    (void)i;
}

/* ---- checks: one log line naming the field, its value and what is valid ------------------------- */
static int hd__param_float_ok(float v, float lo, float hi, int open)
{
    return hd__finite(v) && (open ? v > lo && v < hi : v >= lo && v <= hi);
}
#define HD__PC_ENUM(n, t, def, count, inv) \
    if ((int)p->n < 0 || (int)p->n >= (int)(count)) \
        return HD__ERR(log, HD_ERROR_INVALID_ENUM, "params." #n " = %d is not a " #t, (int)p->n);
#define HD__PC_FLOAT(n, def, lo, hi, open, valid, inv) \
    if (!hd__param_float_ok(p->n, lo, hi, open)) \
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "params." #n " = %g must be " valid, (double)p->n);
#define HD__PC_INT(n, def, lo, hi, valid, inv) \
    if (p->n < (lo) || p->n > (hi)) \
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "params." #n " = %d must be " valid, (int)p->n);
#define HD__PC_BOOL(n, inv) \
    if (p->n != 0 && p->n != 1) return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "params." #n " = %d must be 0 or 1", p->n);
#define HD__PC_SEED(n, inv)
#define HD__PC_FLOAT3(n, def, lo, hi, valid, inv) \
    for (i = 0; i < 3; ++i) \
        if (!hd__param_float_ok(p->n[i], lo, hi, 0)) \
            return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "params." #n "[%d] = %g must be " valid, i, (double)p->n[i]);

/* Checks parameters whose defaults are filled in. */
static hd_result hd__check_params(const hd_params *p, const hd_logger *log)
{
    int i;
    HD__PARAM_TABLE(HD__PC_ENUM, HD__PC_FLOAT, HD__PC_INT, HD__PC_BOOL, HD__PC_SEED, HD__PC_FLOAT3)
    for (i = 0; i < 3; ++i)
        if (!(p->crop_min[i] < p->crop_max[i]))
            return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "params.crop_min[%d] = %g, crop_max[%d] = %g: need min < max", i,
                           (double)p->crop_min[i], i, (double)p->crop_max[i]);
    /* the multigrid levels (src/hd_multigrid.h) restrict and prolong float32 fine grids */
    if (p->illumination_precision == HD_PRECISION_FLOAT16 && p->solver == HD_SOLVER_MULTIGRID)
        return HD__ERR(log, HD_ERROR_UNSUPPORTED, "illumination_precision FLOAT16 with solver MULTIGRID is not available (float32 levels only)");
    return HD_SUCCESS;
}

/* ---- the rows as data: the fields' places and what each invalidates ------------------------------ */
typedef struct hd__param_row {
    const char *name;
    size_t offset, size;
    unsigned invalidates;
} hd__param_row;
#define HD__PR_ENUM(n, t, def, count, inv) {#n, offsetof(hd_params, n), sizeof(((hd_params *)0)->n), inv},
#define HD__PR_FLOAT(n, def, lo, hi, open, valid, inv) {#n, offsetof(hd_params, n), sizeof(((hd_params *)0)->n), inv},
#define HD__PR_INT(n, def, lo, hi, valid, inv) {#n, offsetof(hd_params, n), sizeof(((hd_params *)0)->n), inv},
#define HD__PR_BOOL(n, inv) {#n, offsetof(hd_params, n), sizeof(((hd_params *)0)->n), inv},
#define HD__PR_FLOAT3(n, def, lo, hi, valid, inv) {#n, offsetof(hd_params, n), sizeof(((hd_params *)0)->n), inv},
HD__MAYBE_UNUSED static const hd__param_row hd__param_rows[] = {
    HD__PARAM_TABLE(HD__PR_ENUM, HD__PR_FLOAT, HD__PR_INT, HD__PR_BOOL, HD__PR_BOOL, HD__PR_FLOAT3)
};
#define HD__PARAM_ROWS ((int)(sizeof hd__param_rows / sizeof hd__param_rows[0]))

/* What changing the parameters from o to p invalidates (HD__DIRTY_* bits): each changed field's
   row, the path tracers' running mean as the image while a path tracer runs, and Jacobi's second
   buffer when the solver changes to or from Jacobi. */
static unsigned hd__params_dirty(const hd_params *o, const hd_params *p)
{
    unsigned d = 0;
    int i;
    for (i = 0; i < HD__PARAM_ROWS; ++i) {
        const hd__param_row *row = &hd__param_rows[i];
        if (memcmp((const char *)o + row->offset, (const char *)p + row->offset, row->size) != 0) d |= row->invalidates;
    }
    if (d & HD__DIRTY_PATHS) {
        d &= ~HD__DIRTY_PATHS;
        if (hd__method_is_pt(p->method)) d |= HD__DIRTY_IMAGE;
    }
    if ((p->solver == HD_SOLVER_JACOBI) != (o->solver == HD_SOLVER_JACOBI)) d |= HD__DIRTY_JACOBI;
    return d;
}

#undef HD__PD_ENUM
#undef HD__PD_FLOAT
#undef HD__PD_INT
#undef HD__PD_NONE
#undef HD__PD_FLOAT3
#undef HD__PC_ENUM
#undef HD__PC_FLOAT
#undef HD__PC_INT
#undef HD__PC_BOOL
#undef HD__PC_SEED
#undef HD__PC_FLOAT3
#undef HD__PR_ENUM
#undef HD__PR_FLOAT
#undef HD__PR_INT
#undef HD__PR_BOOL
#undef HD__PR_FLOAT3
