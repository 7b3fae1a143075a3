/* hd_gpu.h - the grids of the GPU backends (hd_opencl.h, hd_vulkan.h, hd_gl.h), made, zeroed and
   freed once here over three primitives each of them defines: sigma_t, E, phi, phi2, the
   projection's summed light, CD's light volumes and HD_SOLVER_MULTIGRID's levels and vectors.
   A grid is named by its id (HD__G_*); the backend keeps it in its own form (a buffer, a 3D
   texture or image) and chooses the format from the id: E, phi and phi2 at the illumination
   precision, the others float. What the backend makes besides (parameter blocks, row sums,
   descriptor sets) follows the levels through hd__gpu_mg_extras. The multigrid's primitives that
   are single passes are defined here too, over the backend's hd__gpu_mg_pass.
   Included before the GPU backend, after src/hd_backend.h; it calls only the primitives it
   declares. */
#ifndef HD_GPU_H
#define HD_GPU_H

/* The grids' ids: the illumination grids, multigrid's p and lo, level l's grids (HD__G_MG), CD's
   light volumes (HD__G_LIGHT + l; l = nlv is the spare the convection writes). */
enum { HD__G_SIG, HD__G_E, HD__G_PHI, HD__G_PHI2, HD__G_LSUM, HD__G_MG_P, HD__G_MG_LO, HD__G_MG_LEVELS,
       HD__G_LIGHT = HD__G_MG_LEVELS + 4 * HD__MG_MAX_LEVELS };
/* level l's sigma_t (l >= 1; level 0 reads HD__G_SIG), right-hand side, correction, residual */
enum { HD__G_MG_SIG, HD__G_MG_RHS, HD__G_MG_PHI, HD__G_MG_RES };
#define HD__G_MG(l, k) (HD__G_MG_LEVELS + 4 * (l) + (k))
/* The level of a level's grid id, 0 for the other ids (a backend's lookup indexes its levels by it). */
#define HD__G_LEVEL_OF(id) ((id) >= HD__G_MG_LEVELS && (id) < HD__G_LIGHT ? ((id) - HD__G_MG_LEVELS) / 4 : 0)

/* HD_SOLVER_MULTIGRID's passes as hd_entry_glsl_multigrid.h numbers them (HD_MG_STAGE: the GL
   backend's programs, the Vulkan backend's SPIR-V), and their names in the log. */
enum { HD__MG_SIG = 1, HD__MG_RESIDUAL, HD__MG_RESTRICT, HD__MG_PROLONG, HD__MG_DIR, HD__MG_RES_F64, HD__MG_DOT,
       HD__MG_UPDATE, HD__MG_EXTRAP, HD__MG_STAGES = HD__MG_EXTRAP };
HD__MAYBE_UNUSED static const char *const hd__mg_stage_names[HD__MG_STAGES] = {
    "multigrid sigma_t", "multigrid residual", "multigrid restriction", "multigrid prolongation",
    "multigrid direction", "multigrid double residual", "multigrid dot products", "multigrid update",
    "multigrid extrapolation"};
/* GL's programs and Vulkan's pipelines of those passes are made per stage and the flags they are
   specialized for (HD_DIFFUSE_FLAGS: RGB scattering, the surface boundary, and for the levels'
   float residual the right-hand side). Returns the pass's index among HD__GPU_MG_VARIANTS (by
   stage - 1, then the 4 combinations of the first two flags); *flags its HD_DIFFUSE_FLAGS. */
#define HD__GPU_MG_VARIANTS (4 * HD__MG_STAGES)
HD__MAYBE_UNUSED static int hd__gpu_mg_variant(int stage, int counts_z, int *flags)
{
    int rgb = (counts_z & HD_FLAG_RGB_SCATTERING) != 0, surface = (counts_z & HD_FLAG_SURFACE_BOUNDARY) != 0;
    *flags = (rgb ? HD_FLAG_RGB_SCATTERING : 0) | (surface ? HD_FLAG_SURFACE_BOUNDARY : 0) |
             (stage == HD__MG_RESIDUAL ? HD_FLAG_DIFFUSE_RHS : 0);
    return (stage - 1) * 4 + rgb + 2 * surface;
}

/* A multigrid level as every GPU backend sees it: the dims of its grids, and its parameter block
   (the fine parameters with its dims, 1 / h^2, h and the rhs flag: hd__mg_level_kp) as last
   given to the backend (kp_sent). */
typedef struct hd__gpu_level {
    int dims[3];
    hd__kparams kp;
    int kp_sent;
} hd__gpu_level;

/* What the grids are made for: E and phi's values (0: none, the path tracers) and their storage
   (f16: E, phi and phi2 at float16, params.illumination_precision), CD's lights and the
   multigrid's levels (0: none; lv[0..levels)) on fine grid `fine` with channels and
   sig_channels. lsum_ok: the projection's summed light (HD__G_LSUM) holds E + phi; the backend
   clears it with every pass that writes E or phi, hd__gpu_alloc_illumination and hd__gpu_clear
   with theirs. */
typedef struct hd__gpu_grids {
    size_t illum_floats;
    int f16, lsum_ok;
    int nlv;
    int levels, channels, sig_channels, fine[3];
    hd__gpu_level lv[HD__MG_MAX_LEVELS];
} hd__gpu_grids;

/* The multigrid's fine rows (a row sum each): y, z and channels. */
static size_t hd__gpu_mg_rows(const hd__gpu_grids *g) { return (size_t)g->fine[1] * g->fine[2] * g->channels; }

/* ---- the primitives a GPU backend defines -------------------------------------------------- */
/* Grid id as w x h x d values (channels stacked in d), zeroed (a device backend may record the
   zeroing for its next submission). A grid id already holds is freed first. */
static hd_result hd__gpu_grid_new(const hd__view *vw, int id, int w, int h, int d, const char *what);
/* Frees grid id (first submitting what the backend recorded that may use it); nothing when it
   holds none. */
static void hd__gpu_grid_free(const hd__view *vw, int id);
/* Zeroes grid id; nothing when it holds none. */
static hd_result hd__gpu_grid_zero(const hd__view *vw, int id);
/* The backend's own multigrid objects for the levels its hd__gpu_grids describes: made (make =
   1; on failure hd__gpu_mg_free follows) or freed (make = 0, also when partly made). */
static hd_result hd__gpu_mg_extras(const hd__view *vw, int make);
/* Gives level l's parameter block kp to the device (level l's buffer or slot of the extras). */
static hd_result hd__gpu_mg_send(const hd__view *vw, int l, const hd__kparams *kp);

/* ---- the life cycle, for the backends' hd__be_alloc_* and hd__be_clear ---------------------- */
/* Frees the multigrid's levels, vectors and extras. */
static void hd__gpu_mg_free(const hd__view *vw, hd__gpu_grids *g)
{
    int l, k;
    if (!g->levels) return;
    hd__gpu_mg_extras(vw, 0);
    for (l = 0; l < g->levels; ++l)
        for (k = 0; k < 4; ++k) hd__gpu_grid_free(vw, HD__G_MG(l, k));
    hd__gpu_grid_free(vw, HD__G_MG_P);
    hd__gpu_grid_free(vw, HD__G_MG_LO);
    g->levels = 0;
}

/* The multigrid's grids for vw's grid and channels: kept when they fit (*fresh = 0), else made
   anew, zeroed, with the backend's extras (*fresh = 1). */
static hd_result hd__gpu_mg_ready(const hd__view *vw, hd__gpu_grids *g, int *fresh)
{
    int l, n;
    hd_result r;
    if (g->levels && hd__mg_stale(vw, g->fine, g->channels, g->sig_channels)) hd__gpu_mg_free(vw, g);
    *fresh = !g->levels;
    if (g->levels) return HD_SUCCESS;
    g->channels = vw->channels;
    g->sig_channels = vw->sig_channels;
    memcpy(g->fine, vw->gdims, sizeof g->fine);
    g->levels = 1; /* from here on hd__gpu_mg_free frees what was made */
    r = hd__gpu_grid_new(vw, HD__G_MG_P, g->fine[0], g->fine[1], g->fine[2] * g->channels, "multigrid's p");
    if (r == HD_SUCCESS) r = hd__gpu_grid_new(vw, HD__G_MG_LO, g->fine[0], g->fine[1], g->fine[2] * g->channels, "multigrid's lo");
    for (l = 0, n = hd__mg_levels(g->fine); l < n && r == HD_SUCCESS; ++l) {
        const int *d = g->lv[l].dims;
        hd__mg_level_dims(g->fine, l, g->lv[l].dims);
        g->lv[l].kp_sent = 0;
        g->levels = l + 1;
        if ((r = hd__gpu_grid_new(vw, HD__G_MG(l, HD__G_MG_RHS), d[0], d[1], d[2] * g->channels, "a multigrid level")) ==
                HD_SUCCESS &&
            (r = hd__gpu_grid_new(vw, HD__G_MG(l, HD__G_MG_PHI), d[0], d[1], d[2] * g->channels, "a multigrid level")) ==
                HD_SUCCESS &&
            (r = hd__gpu_grid_new(vw, HD__G_MG(l, HD__G_MG_RES), d[0], d[1], d[2] * g->channels, "a multigrid level")) ==
                HD_SUCCESS &&
            l > 0)
            r = hd__gpu_grid_new(vw, HD__G_MG(l, HD__G_MG_SIG), d[0], d[1], d[2] * g->sig_channels, "a multigrid level's sigma_t");
    }
    if (r == HD_SUCCESS) r = hd__gpu_mg_extras(vw, 1);
    if (r != HD_SUCCESS) hd__gpu_mg_free(vw, g);
    return r;
}

/* hd__be_mg_begin's common part: the levels made or kept (hd__gpu_mg_ready), and each level's
   parameter block for vw->kp sent where it changed (hd__gpu_mg_send). */
static hd_result hd__gpu_mg_begin(const hd__view *vw, hd__gpu_grids *g, int *fresh)
{
    hd_result r = hd__gpu_mg_ready(vw, g, fresh);
    int l;
    for (l = 0; l < g->levels && r == HD_SUCCESS; ++l) {
        hd__gpu_level *L = &g->lv[l];
        hd__kparams kp = hd__mg_level_kp(&vw->kp, l, L->dims);
        if (L->kp_sent && memcmp(&kp, &L->kp, sizeof kp) == 0) continue;
        if ((r = hd__gpu_mg_send(vw, l, &kp)) != HD_SUCCESS) break;
        L->kp = kp;
        L->kp_sent = 1;
    }
    return r;
}

/* Bytes of the multigrid's state on a backend whose grids are unpadded (hd__mg_bytes); 0 without
   it or with another solver. */
HD__MAYBE_UNUSED static size_t hd__gpu_solver_bytes(const hd__view *vw, const hd__gpu_grids *g)
{
    if (!g->levels || vw->params.solver != HD_SOLVER_MULTIGRID) return 0;
    return hd__mg_bytes(g->fine, g->levels, g->channels, g->sig_channels);
}

/* hd__be_alloc_illumination: sigma_t, E, phi (at the precision the backend chose) and the
   summed light anew for vw's grid, or none (illum_floats 0); phi2 and the levels go with them. */
static hd_result hd__gpu_alloc_illumination(const hd__view *vw, hd__gpu_grids *g, size_t illum_floats)
{
    const int *gd = vw->gdims;
    hd_result r;
    int id;
    hd__gpu_mg_free(vw, g); /* its fine grid is this one */
    for (id = HD__G_SIG; id <= HD__G_LSUM; ++id) hd__gpu_grid_free(vw, id);
    g->illum_floats = 0;
    g->lsum_ok = 0;
    g->f16 = vw->params.illumination_precision == HD_PRECISION_FLOAT16;
    if (illum_floats == 0) return HD_SUCCESS;
    if ((r = hd__gpu_grid_new(vw, HD__G_SIG, gd[0], gd[1], gd[2] * vw->sig_channels, "sigma_t")) != HD_SUCCESS ||
        (r = hd__gpu_grid_new(vw, HD__G_E, gd[0], gd[1], gd[2] * vw->channels, "E")) != HD_SUCCESS ||
        (r = hd__gpu_grid_new(vw, HD__G_PHI, gd[0], gd[1], gd[2] * vw->channels, "phi")) != HD_SUCCESS ||
        (r = hd__gpu_grid_new(vw, HD__G_LSUM, gd[0], gd[1], gd[2] * vw->channels, "the summed light")) != HD_SUCCESS)
        return r;
    g->illum_floats = illum_floats;
    return HD_SUCCESS;
}

/* hd__be_alloc_jacobi: phi2 while enabled and the illumination grids exist. */
static hd_result hd__gpu_alloc_jacobi(const hd__view *vw, const hd__gpu_grids *g, int enable)
{
    hd__gpu_grid_free(vw, HD__G_PHI2);
    if (!enable || g->illum_floats == 0) return HD_SUCCESS;
    return hd__gpu_grid_new(vw, HD__G_PHI2, vw->gdims[0], vw->gdims[1], vw->gdims[2] * vw->channels, "Jacobi's buffer");
}

/* CD's light volumes freed. */
static void hd__gpu_free_lights(const hd__view *vw, hd__gpu_grids *g)
{
    int l;
    for (l = 0; g->nlv > 0 && l <= g->nlv; ++l) hd__gpu_grid_free(vw, HD__G_LIGHT + l);
    g->nlv = 0;
}

/* hd__be_alloc_lights: count + 1 dark light volumes (the lights and the convection's spare), as
   the CPU backend; count 0 frees them. */
static hd_result hd__gpu_alloc_lights(const hd__view *vw, hd__gpu_grids *g, int count)
{
    hd_result r = HD_SUCCESS;
    int l;
    hd__gpu_free_lights(vw, g);
    for (l = 0; l <= count && count > 0 && r == HD_SUCCESS; ++l) {
        g->nlv = count;
        r = hd__gpu_grid_new(vw, HD__G_LIGHT + l, vw->gdims[0], vw->gdims[1], vw->gdims[2], "a CD light volume");
    }
    if (r != HD_SUCCESS) hd__gpu_free_lights(vw, g);
    return r;
}

/* Every grid freed (hd__be_destroy). */
static void hd__gpu_free(const hd__view *vw, hd__gpu_grids *g)
{
    hd__gpu_alloc_illumination(vw, g, 0);
    hd__gpu_free_lights(vw, g);
}

/* hd__be_clear's grids: E (HD__DIRTY_DIRECT), phi and phi2 (HD__DIRTY_PHI) zeroed. */
static hd_result hd__gpu_clear(const hd__view *vw, hd__gpu_grids *g, unsigned what)
{
    hd_result r = HD_SUCCESS;
    if (what & (HD__DIRTY_DIRECT | HD__DIRTY_PHI)) g->lsum_ok = 0;
    if (what & HD__DIRTY_DIRECT) r = hd__gpu_grid_zero(vw, HD__G_E);
    if ((what & HD__DIRTY_PHI) && r == HD_SUCCESS) r = hd__gpu_grid_zero(vw, HD__G_PHI);
    if ((what & HD__DIRTY_PHI) && r == HD_SUCCESS) r = hd__gpu_grid_zero(vw, HD__G_PHI2);
    return r;
}


/* ---- HD_SOLVER_MULTIGRID's passes --------------------------------------------------------------
   The primitives of src/hd_backend.h that are single passes are written here, once, over one
   primitive: hd__gpu_mg_pass. Each pass reads one parameter block (slot l: level l's; slot
   `levels`: the fine vw->kp) and one set of grids: sigma_t, E, phi, phi2 and the other grid
   (hd_entry_glsl_multigrid.h's names; GL image unit 6, Vulkan binding 10) and a row-sum buffer.
   The sets are numbered per level (HD__GPU_MG_SET), then CG's (HD__GPU_MG_CG), and
   hd__gpu_mg_set says what each binds: GL binds a set per pass, Vulkan writes each into a
   descriptor set once, OpenCL passes them as its kernels' arguments. Smoothing (the diffusion
   kernel), the step's bracket and the row sums' read-back stay with the backend. */
/* level l's sets: smoothing and its residual; restriction to l + 1; prolongation from l + 1;
   sigma_t from l - 1 */
enum { HD__GPU_MG_SMOOTH, HD__GPU_MG_RESTRICT_TO, HD__GPU_MG_PROLONG_FROM, HD__GPU_MG_COARSEN, HD__GPU_MG_PER_LEVEL };
/* CG's sets (level 0 and the backend's grids) */
enum { HD__GPU_MG_RES_R, HD__GPU_MG_RES_Q, HD__GPU_MG_DOT_RZ, HD__GPU_MG_DIR, HD__GPU_MG_DOT_PQ, HD__GPU_MG_DOT_RP,
       HD__GPU_MG_UPDATE, HD__GPU_MG_EXTRAP, HD__GPU_MG_CG_SETS };
#define HD__GPU_MG_SET(l, k) (HD__GPU_MG_PER_LEVEL * (l) + (k))
#define HD__GPU_MG_CG(g, k) (HD__GPU_MG_PER_LEVEL * (g)->levels + (k))
#define HD__GPU_MG_SETS (HD__GPU_MG_PER_LEVEL * HD__MG_MAX_LEVELS + HD__GPU_MG_CG_SETS)

/* A set's grids by id (-1: none; the backend binds a placeholder) in the order sigma_t, E, phi,
   phi2, other; its row sums (dot: 0 none, 1 A, 2 B). */
typedef struct hd__gpu_mg_binds {
    int grid[5];
    int dot;
} hd__gpu_mg_binds;

/* What set `set` binds; 0 for a set no pass uses (the coarsest level's transfers, level 0's
   sigma_t). Level 0's sigma_t is the backend's; the transfers mask with the fine level's. */
static int hd__gpu_mg_set(const hd__gpu_grids *g, int set, hd__gpu_mg_binds *b)
{
    static const int cg[HD__GPU_MG_CG_SETS][6] = {
        {HD__G_SIG, HD__G_E, HD__G_PHI, HD__G_MG_LO, HD__G_MG(0, HD__G_MG_RHS), 0},
        {HD__G_SIG, HD__G_MG(0, HD__G_MG_PHI), HD__G_MG_P, HD__G_MG_LO, HD__G_MG(0, HD__G_MG_RES), 0},
        {-1, HD__G_MG(0, HD__G_MG_RHS), HD__G_MG(0, HD__G_MG_PHI), -1, -1, 1},
        {-1, HD__G_MG(0, HD__G_MG_PHI), HD__G_MG_P, -1, -1, 0},
        {-1, HD__G_MG_P, HD__G_MG(0, HD__G_MG_RES), -1, -1, 1},
        {-1, HD__G_MG(0, HD__G_MG_RHS), HD__G_MG_P, -1, -1, 2},
        {-1, HD__G_MG_P, HD__G_PHI, HD__G_MG_LO, -1, 0},
        {HD__G_SIG, HD__G_E, HD__G_PHI, HD__G_MG_LO, -1, 0}};
    int l = set / HD__GPU_MG_PER_LEVEL, k = set % HD__GPU_MG_PER_LEVEL, i;
    int sig = l == 0 ? HD__G_SIG : HD__G_MG(l, HD__G_MG_SIG);
    for (i = 0; i < 5; ++i) b->grid[i] = -1;
    b->dot = 0;
    if (set >= HD__GPU_MG_CG(g, 0)) {
        for (i = 0; i < 5; ++i) b->grid[i] = cg[set - HD__GPU_MG_CG(g, 0)][i];
        b->dot = cg[set - HD__GPU_MG_CG(g, 0)][5];
        return 1;
    }
    if (k == HD__GPU_MG_SMOOTH) {
        b->grid[0] = sig;
        b->grid[1] = HD__G_MG(l, HD__G_MG_RHS);
        b->grid[2] = HD__G_MG(l, HD__G_MG_PHI);
        b->grid[3] = HD__G_MG(l, HD__G_MG_RES);
    } else if (k == HD__GPU_MG_RESTRICT_TO && l + 1 < g->levels) {
        b->grid[0] = sig;
        b->grid[2] = HD__G_MG(l, HD__G_MG_RES);
        b->grid[3] = HD__G_MG(l + 1, HD__G_MG_PHI);
        b->grid[4] = HD__G_MG(l + 1, HD__G_MG_RHS);
    } else if (k == HD__GPU_MG_PROLONG_FROM && l + 1 < g->levels) {
        b->grid[0] = sig;
        b->grid[2] = HD__G_MG(l + 1, HD__G_MG_PHI);
        b->grid[4] = HD__G_MG(l, HD__G_MG_PHI);
    } else if (k == HD__GPU_MG_COARSEN && l > 0) {
        b->grid[0] = l == 1 ? HD__G_SIG : HD__G_MG(l - 1, HD__G_MG_SIG);
        b->grid[4] = HD__G_MG(l, HD__G_MG_SIG);
    } else {
        return 0;
    }
    return 1;
}

/* One pass: stage (HD__MG_*) with set `set` and parameter slot `slot` over n[0] x n[1] x n[2]
   invocations on level `level`'s grid, hd_pc = pc; the direction's beta and the update's alpha
   as the backend passes scalars (GL: uniforms; Vulkan: hd_pc.x and .y, which those passes leave
   free; OpenCL: kernel arguments). */
typedef struct hd__gpu_mg_run {
    int stage, set, slot, level, n[3];
    int32_t pc[4];
    float beta;
    double alpha;
} hd__gpu_mg_run;

/* The backend's: its grids, and one pass run (GL) or recorded (Vulkan) in order after the
   earlier ones. */
static hd__gpu_grids *hd__gpu_grids_of(const hd__view *vw);
static hd_result hd__gpu_mg_pass(const hd__view *vw, const hd__gpu_mg_run *p);

/* Pass `stage` over level l's grid of `channels` channels stacked in z; hd_pc: the level's dims
   (dims_pc; else zeros) and channels. */
static hd_result hd__gpu_mg_level_pass(const hd__view *vw, int stage, int set, int slot, int l, int channels, int dims_pc)
{
    const int *d = hd__gpu_grids_of(vw)->lv[l].dims;
    hd__gpu_mg_run p;
    int i;
    memset(&p, 0, sizeof p);
    p.stage = stage;
    p.set = set;
    p.slot = slot;
    p.level = l;
    for (i = 0; i < 3; ++i) {
        p.n[i] = i == 2 ? d[2] * channels : d[i];
        p.pc[i] = dims_pc ? d[i] : 0;
    }
    p.pc[3] = channels;
    return hd__gpu_mg_pass(vw, &p);
}

/* Pass `stage` with CG's set cg over the fine grid, hd_pc (pc0, pc1, 0, channels); the dot
   products over the fine rows instead (y, then z and channels). */
static hd_result hd__gpu_mg_fine_pass(const hd__view *vw, int stage, int cg, int slot, int pc0, int pc1, float beta, double alpha)
{
    const hd__gpu_grids *g = hd__gpu_grids_of(vw);
    hd__gpu_mg_run p;
    memset(&p, 0, sizeof p);
    p.stage = stage;
    p.set = HD__GPU_MG_CG(g, cg);
    p.slot = slot;
    p.n[0] = stage == HD__MG_DOT ? g->fine[1] : g->fine[0];
    p.n[1] = stage == HD__MG_DOT ? g->fine[2] * g->channels : g->fine[1];
    p.n[2] = stage == HD__MG_DOT ? 1 : g->fine[2] * g->channels;
    p.pc[0] = pc0;
    p.pc[1] = pc1;
    p.pc[3] = g->channels;
    p.beta = beta;
    p.alpha = alpha;
    return hd__gpu_mg_pass(vw, &p);
}

static hd_result hd__be_mg_coarsen(const hd__view *vw, int l)
{
    return hd__gpu_mg_level_pass(vw, HD__MG_SIG, HD__GPU_MG_SET(l, HD__GPU_MG_COARSEN), l - 1, l,
                                 hd__gpu_grids_of(vw)->sig_channels, 1);
}

static hd_result hd__be_mg_residual(const hd__view *vw, int l)
{
    return hd__gpu_mg_level_pass(vw, HD__MG_RESIDUAL, HD__GPU_MG_SET(l, HD__GPU_MG_SMOOTH), l, l, hd__gpu_grids_of(vw)->channels, 0);
}

/* With level l's parameters over level l + 1's grid. */
static hd_result hd__be_mg_restrict(const hd__view *vw, int l)
{
    return hd__gpu_mg_level_pass(vw, HD__MG_RESTRICT, HD__GPU_MG_SET(l, HD__GPU_MG_RESTRICT_TO), l, l + 1,
                                 hd__gpu_grids_of(vw)->channels, 1);
}

/* With level l + 1's parameters over level l's grid. */
static hd_result hd__be_mg_prolong(const hd__view *vw, int l)
{
    return hd__gpu_mg_level_pass(vw, HD__MG_PROLONG, HD__GPU_MG_SET(l, HD__GPU_MG_PROLONG_FROM), l + 1, l,
                                 hd__gpu_grids_of(vw)->channels, 1);
}

/* f - A (phi + lo) in double with the fine parameters (hd_pc.x: use lo). */
static hd_result hd__be_mg_residual_f64(const hd__view *vw)
{
    return hd__gpu_mg_fine_pass(vw, HD__MG_RES_F64, HD__GPU_MG_RES_R, hd__gpu_grids_of(vw)->levels, 1, 0, 0.0f, 0.0);
}

static hd_result hd__be_mg_dot_rz(const hd__view *vw) { return hd__gpu_mg_fine_pass(vw, HD__MG_DOT, HD__GPU_MG_DOT_RZ, 0, 0, 0, 0.0f, 0.0); }

static hd_result hd__be_mg_direction(const hd__view *vw, float beta)
{
    return hd__gpu_mg_fine_pass(vw, HD__MG_DIR, HD__GPU_MG_DIR, 0, 0, 0, beta, 0.0);
}

/* q = A p: the double residual negated (hd_pc.y) on level 0's parameters, E = z = 0, phi = p. */
static hd_result hd__be_mg_apply(const hd__view *vw)
{
    hd_result r;
    if ((r = hd__gpu_mg_fine_pass(vw, HD__MG_RES_F64, HD__GPU_MG_RES_Q, 0, 0, 1, 0.0f, 0.0)) != HD_SUCCESS ||
        (r = hd__gpu_mg_fine_pass(vw, HD__MG_DOT, HD__GPU_MG_DOT_PQ, 0, 0, 0, 0.0f, 0.0)) != HD_SUCCESS)
        return r;
    return hd__gpu_mg_fine_pass(vw, HD__MG_DOT, HD__GPU_MG_DOT_RP, 0, 0, 0, 0.0f, 0.0);
}

static hd_result hd__be_mg_update(const hd__view *vw, double alpha)
{
    hd__gpu_grids_of(vw)->lsum_ok = 0;
    return hd__gpu_mg_fine_pass(vw, HD__MG_UPDATE, HD__GPU_MG_UPDATE, 0, 0, 0, 0.0f, alpha);
}

/* The fine parameters (no right-hand-side flag); hd_pc.x the colour. */
static hd_result hd__be_mg_extrapolate(const hd__view *vw, int colour)
{
    hd__gpu_grids *g = hd__gpu_grids_of(vw);
    g->lsum_ok = 0;
    return hd__gpu_mg_fine_pass(vw, HD__MG_EXTRAP, HD__GPU_MG_EXTRAP, g->levels, colour, 0, 0.0f, 0.0);
}

/* lo = 0. */
static hd_result hd__be_mg_zero_lo(const hd__view *vw) { return hd__gpu_grid_zero(vw, HD__G_MG_LO); }

/* The projection's dispatch on CPU devices: llvmpipe and lavapipe hand each of their threads one
   contiguous run of a dispatch's work groups, so with the rows in order one thread marches the top
   of the image and another the bottom, and the one with less medium waits. The dispatch's rows
   go in blocks of HD__GPU_ROW_BLOCK, block b drawing the image's block b p mod n
   (hd_entry_glsl.h) for n blocks and p = hd__gpu_row_stride(n): the integer coprime to n nearest
   n (3 - sqrt 5) / 2, so that the blocks of any run spread evenly over the image (a Kronecker
   sequence of the golden ratio). 1 (in order) below 3 blocks. The blocks are tall because rays
   of neighbouring rows read the same cache lines: single rows spread so cost llvmpipe more CPU
   time than the balance saved (docs/PERFORMANCE.md). */
#define HD__GPU_ROW_BLOCK 32
HD__MAYBE_UNUSED static int hd__gpu_row_stride(int n)
{
    int c = (int)(0.381966 * (double)n + 0.5), d, k;
    for (d = 0; n >= 3 && d < n; ++d)
        for (k = 0; k < 2; ++k) {
            int p = k ? c + d : c - d, a = n, b = p;
            if (p <= 1 || p >= n) continue;
            while (b) {
                int t = a % b;
                a = b;
                b = t;
            }
            if (a == 1) return p;
        }
    return 1;
}

#endif
