/* hd_backend.h - the interface between the core (src/) and a backend (backends/hd_cpu.h,
   hd_opencl.h, hd_vulkan.h, hd_gl.h): every primitive the core calls, declared once with its
   contract. Exactly one backend is compiled in; it defines struct hd__backend and every function
   declared below, with these signatures (the helpers at the end are the core's, for backends to
   use). One it lacks is a compile error ("used but never defined") and a different signature a
   conflicting declaration, so the list is the whole job of a new backend. The GPU backends make
   their grids (hd__be_alloc_*, hd__be_clear, the multigrid's levels) through src/hd_gpu.h, which
   also defines for them the multigrid's primitives that are single passes.

   Common rules:
   - Every primitive returns HD_SUCCESS or a specific hd_result with one line logged through
     ctx->log (HD__ERR). A device that is lost stays lost: every later call says so.
   - ctx->kp (hd__kparams, filled by hd__fill_kparams) holds the parameters the kernels read;
     ctx->gdims, ctx->channels and ctx->sig_channels the illumination grid. Grids are in the colour
     layout (hd_prelude_c.h's hd__split_slot) wherever the backend keeps them in memory.
   - A primitive may only enqueue work; it must have finished, or be ordered before any later
     primitive's work, by the time a read-back (hd__be_read_*, hd__be_mg_row_sums) returns.
   - Nothing of the caller's state is changed: a backend working in a context the application
     owns (GL) saves and restores what it binds.
   - A capability a device may lack (double precision, 16-bit images) is checked at run time and
     refused with HD_ERROR_UNSUPPORTED and a logged reason. */
#ifndef HD_BACKEND_H
#define HD_BACKEND_H

/* ---- life cycle ------------------------------------------------------------------------------- */
/* The backend's short name ("cpu", "opencl", ...), a static string. */
static const char *hd__be_name(void);
/* Creates ctx->be for ctx (volume, TF, lights, params already validated and copied). On failure
   everything it made is released and ctx->be is NULL or destroyable. */
static hd_result hd__be_create(hd__ctx *ctx);
/* Releases everything the backend holds, ctx->be included; safe on a partly created backend. */
static void hd__be_destroy(hd__ctx *ctx);

/* ---- the bracket of a public call ------------------------------------------------------------
   The core opens one bracket per public call that reaches the device (hd_iterate, hd_render, the
   read-backs, ...; a backend's own entry points such as hd_gl_render_to_texture do the same) and
   runs hd__prepare and every primitive below inside it; hd__be_create and hd__be_destroy run
   outside any. */
/* Refuses a device lost earlier (HD_ERROR_DEVICE_LOST, logged), makes the backend's context
   current on this thread and saves the caller's state the primitives will change (GL). On
   failure nothing is open and hd__be_end is not called. */
static hd_result hd__be_begin(hd__ctx *ctx);
/* Closes the bracket whatever r is (the call's first error, or HD_SUCCESS): what the backend
   recorded but did not submit is submitted and waited for (on success), the caller's state and
   context restored. Returns r, or its own error where r is HD_SUCCESS. */
static hd_result hd__be_end(hd__ctx *ctx, hd_result r);
/* The core's hd__prepare (src/hd_context.h): the device state brought up to date with the setters. */
static hd_result hd__prepare(hd__ctx *ctx);
/* r = the result of hd__prepare and then of expr, both in one bracket; expr is not evaluated when
   an earlier step failed. */
#define HD__BE_CALL(r, ctx, expr) \
    do { \
        if (((r) = hd__be_begin(ctx)) == HD_SUCCESS) { \
            if (((r) = hd__prepare(ctx)) == HD_SUCCESS) (r) = (expr); \
            (r) = hd__be_end((ctx), (r)); \
        } \
    } while (0)

/* ---- allocation (the core calls these from hd__prepare when its dirty bits say so) ----------- */
/* The volume, TF and majorant of ctx are new: upload them (classification follows). */
static hd_result hd__be_upload_inputs(hd__ctx *ctx);
/* E, phi and phi2 for illum_floats values (0: free them; PT methods), contents undefined until
   hd__be_clear. Multigrid levels on the old grid may be dropped here; hd__be_mg_begin remakes
   them whenever they are missing or the grid changed. */
static hd_result hd__be_alloc_illumination(hd__ctx *ctx, size_t illum_floats);
/* The Jacobi solver's second phi buffer: allocated when enable, freed otherwise. */
static hd_result hd__be_alloc_jacobi(hd__ctx *ctx, int enable);
/* The RGBA float image of width x height and, with reduced, after it the reduced frames' region
   (hd__image_floats), contents undefined until hd__be_clear. The new buffer is made before the
   old one is released, so on failure the image held before is kept as it was. */
static hd_result hd__be_alloc_image(hd__ctx *ctx, int width, int height, int reduced);
/* The image buffer's floats: width x height RGBA, then with reduced the room for a frame at render
   scale 2 (the largest reduced frame; hd_k_upsample.h), which only reduced frames use. */
HD__MAYBE_UNUSED static size_t hd__image_floats(int width, int height, int reduced)
{
    return ((size_t)width * height + (reduced ? (size_t)((width + 1) / 2) * ((height + 1) / 2) : 0)) * 4;
}
/* CD's light volumes: count of them (0 frees them), dark. */
static hd_result hd__be_alloc_lights(hd__ctx *ctx, int count);
/* Zeroes what the HD__DIRTY_* bits in what name: DIRECT (E and CD's light volumes), PHI (phi,
   phi2), IMAGE (the image). */
static hd_result hd__be_clear(hd__ctx *ctx, unsigned what);

/* ---- the method's stages (each over the whole grid or image, from ctx->kp) --------------------- */
/* sigma_t from the volume and TF (hd_k_classify.h); the core counts the reclassifications
   (ctx->sig_gen) for the solvers' coarse grids. */
static hd_result hd__be_classify(hd__ctx *ctx);
/* HD: one Monte Carlo sample of the direct light into E's running mean (hd_k_direct.h) at each of
   the ctx->dl_count grid voxels listed in ctx->dl_idx; E elsewhere is left as it is (0). */
static hd_result hd__be_direct(hd__ctx *ctx);
/* HD: ctx->dl_idx (ctx->dl_count grid indices, in bricks) changed with sigma_t: make it the list
   hd__be_direct reads (a GPU backend uploads it). */
static hd_result hd__be_direct_list(hd__ctx *ctx);
/* One sweep of the single-level solver (jacobi: Jacobi into phi2, then swapped; else one
   red-black sweep, red then black) on phi (hd_k_diffuse.h). */
static hd_result hd__be_diffuse(hd__ctx *ctx, int jacobi);
/* `sweeps` such sweeps: the same result as as many hd__be_diffuse calls. */
static hd_result hd__be_diffuse_sweeps(hd__ctx *ctx, int jacobi, int sweeps);
/* CD: one convection step of light `light` (hd_k_convect.h). */
static hd_result hd__be_convect(hd__ctx *ctx, int light);
/* CD: the light volumes summed into E. */
static hd_result hd__be_sum_lights(hd__ctx *ctx);
/* One frame of the emission-absorption projection into the image's running mean (hd_k_project.h). */
static hd_result hd__be_project(hd__ctx *ctx);
/* PT_SS / PT_MS: one path per pixel into the image's running mean (hd_k_path.h). */
static hd_result hd__be_path(hd__ctx *ctx);

/* ---- read-back (blocking: every earlier primitive's result) ------------------------------------ */
/* The image as RGBA floats, ctx->camera.width x height, rows top to bottom. */
static hd_result hd__be_read_image(hd__ctx *ctx, float *dst);
/* E (HD_ILLUMINATION_DIRECT) or phi (SCATTERED) as floats, x fastest, channels stacked in z:
   with zz NULL the whole grid; else the z slices zz[0..count) of that stacking (slice zz: channel
   zz / gdims[2], z zz % gdims[2]) in that order, each gdims[0] * gdims[1] floats, one after
   another into dst (the light's convergence estimate reads only what it measures). */
static hd_result hd__be_read_illumination(hd__ctx *ctx, hd_illumination which, const int *zz, int count, float *dst);

/* ---- HD_SOLVER_MULTIGRID's per-level primitives -------------------------------------------------
   The core's hd__mg_step (src/hd_multigrid.h) runs conjugate gradients preconditioned by a
   V-cycle over these (docs/METHOD.md has the method, hd_multigrid_cg.h the level rule). The
   backend owns the buffers: per level l < hd__mg_levels(ctx->gdims), of grid hd__mg_level_dims and
   ctx->channels channels, a right-hand side (level 0: r), a correction (level 0: z) and a residual
   (level 0: q = A p); coarse levels a sigma_t of ctx->sig_channels channels; on the fine grid the
   search direction p and the iterate's low part lo (CG's iterate is phi + lo); two buffers A and B
   of one double per fine row (ctx->gdims[1] * gdims[2] * channels rows). Each level smooths and
   restricts with the parameter block hd__mg_level_kp. The per-voxel math of every pass is
   backends/kernels/hd_k_multigrid.h and hd_k_diffuse.h, so each backend's results have the CPU's
   bits wherever its float operations do. */
/* Starts a step: refuses what the device cannot do (double precision), makes the levels for the
   current grid, channels and sigma_t channels (new ones zeroed, *fresh = 1; kept ones *fresh = 0)
   and writes every level's parameter block. On success the core calls hd__be_mg_end once. */
static hd_result hd__be_mg_begin(hd__ctx *ctx, int *fresh);
/* Ends the step begun by hd__be_mg_begin, whatever r is (the first error of the step, or
   HD_SUCCESS): on success waits for its passes; restores what begin changed. Returns r, or its
   own error where r is HD_SUCCESS. */
static hd_result hd__be_mg_end(hd__ctx *ctx, hd_result r);
/* Level l's sigma_t (l >= 1) restricted from level l - 1's (hd_mg_coarse_sig). */
static hd_result hd__be_mg_coarsen(hd__ctx *ctx, int l);
/* lo = 0 (the iterate's low part belongs to another phi). */
static hd_result hd__be_mg_zero_lo(hd__ctx *ctx);
/* r = f - A (phi + lo) on the fine grid, summed in double (hd_mg_res_f64), into level 0's rhs. */
static hd_result hd__be_mg_residual_f64(hd__ctx *ctx);
/* `sweeps` red-black sweeps of level l's equation (first = 0: red then black; 1: black then red,
   the adjoint order). */
static hd_result hd__be_mg_smooth(hd__ctx *ctx, int l, int sweeps, int first);
/* Level l's residual (rhs - A correction, in float) into its residual buffer. */
static hd_result hd__be_mg_residual(hd__ctx *ctx, int l);
/* Level l + 1's rhs = R (level l's residual), masked to the medium; level l + 1's correction = 0. */
static hd_result hd__be_mg_restrict(hd__ctx *ctx, int l);
/* Level l's correction += P (level l + 1's correction), masked to the medium. */
static hd_result hd__be_mg_prolong(hd__ctx *ctx, int l);
/* Row sums of <r, z> into A (per fine row, x in order, in double: hd_mg_dot_term). */
static hd_result hd__be_mg_dot_rz(hd__ctx *ctx);
/* p = z + beta p, then z = 0 (the next V-cycle starts from it). */
static hd_result hd__be_mg_direction(hd__ctx *ctx, float beta);
/* q = A p (in double, as hd__be_mg_residual_f64 with a zero right-hand side) into level 0's
   residual; the row sums of <p, q> into A and of <r, p> into B. */
static hd_result hd__be_mg_apply(hd__ctx *ctx);
/* Waits for every pass enqueued so far and points *a (and, n = 2, *b) at host copies of the row
   sums A (and B), valid until the next primitive; with n = 1 B need not be read back. The core
   adds them in row order (hd__mg_row_sum). */
static hd_result hd__be_mg_row_sums(hd__ctx *ctx, int n, const double **a, const double **b);
/* phi + lo += alpha p in double, phi its float rounding and lo the rest (hd_mg_update_of). */
static hd_result hd__be_mg_update(hd__ctx *ctx, double alpha);
/* Surface boundary: the empty voxels of colour `colour` get the Marshak extrapolation in phi and
   lo = -phi (hd_diffuse_extrapolate), with the fine parameters (no right-hand-side flag). */
static hd_result hd__be_mg_extrapolate(hd__ctx *ctx, int colour);
/* Bytes the solver's buffers hold (counted in method_bytes); 0 without them or with another solver. */
static size_t hd__be_solver_bytes(const hd__ctx *ctx);

/* ---- helpers a backend may use ----------------------------------------------------------------- */
/* hd__be_diffuse_sweeps for a backend whose sweeps are separate passes: hd__be_diffuse each. */
HD__MAYBE_UNUSED static hd_result hd__be_diffuse_each(hd__ctx *ctx, int jacobi, int sweeps)
{
    hd_result r = HD_SUCCESS;
    int s;
    for (s = 0; s < sweeps && r == HD_SUCCESS; ++s) r = hd__be_diffuse(ctx, jacobi);
    return r;
}

/* The projection's TF table for the current TF, step and medium, as hd_project_lookup reads it
   (hd_k_project.h): entry j at value j / (n - 1) is (rgb * a * albedo / (4 pi), a), a = 1 -
   exp(-sigma_t dt). n - 1 is a multiple of the TF's segments and at least HD__PTAB_MIN, so each
   table segment lies inside one TF segment. Every backend builds it here, so all of them read
   the same table. hd__project_table_n: its entries; hd__project_table: fills dst (n * 4 floats). */
#define HD__PTAB_MIN 4096
HD__MAYBE_UNUSED static int hd__project_table_n(const hd__ctx *ctx)
{
    int segs = ctx->tf_count - 1, m = segs < HD__PTAB_MIN ? (HD__PTAB_MIN + segs - 1) / segs : 1;
    return segs * m + 1;
}
/* What the table is built from: a backend keeps the key of the table it holds and rebuilds or
   uploads it only when hd__project_table_key_same says the inputs changed (a TF, step, extinction
   or albedo change); valid 0 (a zeroed key, or one reset with the table's buffer) never matches. */
typedef struct hd__ptab_key {
    int valid, n;
    unsigned tf_serial;
    float dt, extinction, scale;
} hd__ptab_key;
HD__MAYBE_UNUSED static hd__ptab_key hd__project_table_key(const hd__ctx *ctx)
{
    hd__ptab_key k;
    k.valid = 1;
    k.n = hd__project_table_n(ctx);
    k.tf_serial = ctx->tf_serial;
    k.dt = ctx->kp.march.x;
    k.extinction = ctx->kp.medium.x;
    k.scale = ctx->kp.medium.y * ctx->kp.box.w;
    return k;
}
HD__MAYBE_UNUSED static int hd__project_table_key_same(const hd__ctx *ctx, const hd__ptab_key *held)
{
    hd__ptab_key k = hd__project_table_key(ctx);
    return held->valid && held->n == k.n && held->tf_serial == k.tf_serial && held->dt == k.dt &&
           held->extinction == k.extinction && held->scale == k.scale;
}
HD__MAYBE_UNUSED static void hd__project_table(const hd__ctx *ctx, float *dst, int n)
{
    hd__kctx k;
    hd__kctx *K = &k;
    float dt = ctx->kp.march.x, s = ctx->kp.medium.y * ctx->kp.box.w;
    int j;
    memset(&k, 0, sizeof k);
    k.p = &ctx->kp;
    k.tf = ctx->tf;
    for (j = 0; j < n; ++j) {
        hd_v4 c = hd_tf(K, (float)j / (float)(n - 1));
        float a = 1.0f - hd_exp(-(c.w * ctx->kp.medium.x) * dt);
        dst[j * 4] = c.x * a * s;
        dst[j * 4 + 1] = c.y * a * s;
        dst[j * 4 + 2] = c.z * a * s;
        dst[j * 4 + 3] = a;
    }
}
/* The table in a new host buffer (free with hd__free), for a backend to upload; NULL, logged,
   without memory. */
HD__MAYBE_UNUSED static float *hd__project_table_new(hd__ctx *ctx, int n)
{
    float *t = (float *)hd__alloc(ctx, (size_t)n * 4 * sizeof(float));
    if (t)
        hd__project_table(ctx, t, n);
    else
        (void)HD__ERR(&ctx->log, HD_ERROR_OUT_OF_MEMORY, "%s: cannot allocate the projection's TF table (%d entries)",
                      hd__be_name(), n);
    return t;
}

#endif
