/* hd_core.h - the core: the context (hd__ctx) and, in dependency order, the parts that own its
   state. Included after the selected backend, which sees only the context's view (hd__view,
   src/hd_internal.h) through the primitives of src/hd_backend.h: a backend that named hd__ctx
   would not compile.
     hd_handles.h      handles and their slots
     hd_validate.h     checks of the volume, TF, lights and camera, and their defaults
     hd_params.h       hd_params as one table: defaults, checks, what each field invalidates
     hd_volume.h       the volume, majorants, TF and lights (the inputs the backend uploads)
     hd_scene.h        the volume transform, the camera's rays in the volume's frame, depth
     hd_kparams.h      the kernels' parameter block packed from the context
     hd_multigrid.h    HD_SOLVER_MULTIGRID's driver over the backend's level primitives
     hd_direct_mask.h  where the direct light is tracked
     hd_convergence.h  the light's error estimate
     hd_frame_cost.h   HD_RENDER_SCALE_AUTO's frame-cost model and scale choice
     hd_schedule.h     the methods' stages, hd_render's loop, recording
     hd_readback.h     the image, illumination and statistics read back
     hd_api.h          the public calls */
#ifndef HD_CORE_H
#define HD_CORE_H

/* HD_SOLVER_MULTIGRID's run state, the same on every backend (src/hd_multigrid.h). */
typedef struct hd__mg_cg {
    unsigned sig_gen;        /* ctx->sig_gen the coarse sigma_t were restricted from */
    int sig_surface;         /* ... and the boundary they were restricted for */
    uint64_t iteration;      /* the HD iteration (ctx->iterations) the CG run belongs to */
    hd__kparams akey;        /* the parameters A depends on, at the last step (restart on change) */
    int have_dir;            /* the backend's p holds a direction of the current CG run */
    double rz;               /* <r, z> of the previous step (beta's denominator) */
    unsigned light_gen;      /* the context's light_gen of the current CG run */
    double vcycle_seconds;   /* wall time in V-cycles (bench/hdbench_multigrid.c: a step against a V-cycle) */
} hd__mg_cg;

/* The light's convergence estimate (src/hd_convergence.h): E and phi of the medium's voxels
   after the previous light iteration, to estimate the error from their change. */
typedef struct hd__conv {
    uint32_t *idx;           /* in-slice indices (y * gx + x) of the voxels measured, slice by slice */
    size_t count;
    int *zz;                 /* the stacked slices read back: nz per channel, channel-major */
    size_t *off;             /* nz + 1 starts in idx, one per measured slice */
    int nz;                  /* measured slices per channel */
    float *prev;             /* count * channels values of E, then the same of phi */
    float *tmp;              /* the measured slices of one illumination volume read back, all channels */
    int have_prev;           /* prev holds the previous iteration */
    int below;               /* light iterations in a row with light_error below the tolerance */
    double dphi;             /* |phi_n - phi_n-1| of the previous iteration */
    double q;                /* the solver's observed contraction of that change */
} hd__conv;

/* HD_RENDER_SCALE_AUTO's frame cost model (src/hd_frame_cost.h): per render scale 1, 2, 4, 8, 16
   (slot log2 s) the pixels its last frame marched (0: none yet), its smoothed seconds and the
   measurement count when it was last measured; the newest measurement's slot; measurements so
   far (0: none). */
#define HD__COST_SLOTS 5
typedef struct hd__cost {
    double pixels[HD__COST_SLOTS], seconds[HD__COST_SLOTS];
    unsigned at[HD__COST_SLOTS];
    int last;
    unsigned gen;
    /* a frame recorded into a caller's command buffer (hd_vulkan_record), timed on the device and
       read by the next call: its scale, pixels and the measurement count when it was recorded */
    int rec_pending, rec_scale;
    double rec_pixels;
    unsigned rec_gen;
} hd__cost;

/* The light iteration in progress when render_budget splits one over hd_render calls
   (src/hd_schedule.h), and the light work's measured costs the budget plans with. */
typedef struct hd__part {
    int open;            /* an iteration is in progress: its counters have advanced */
    size_t dl;           /* its direct stage's units done: HD's list entries, CD's 1 when done */
    int sweeps;          /* its diffusion sweeps done (multigrid: steps) */
    uint64_t dropped;    /* iterations a change ended before their last part (not counted as
                            complete by hd_stats; the counter, the random numbers' key, runs on) */
    size_t last_dl;      /* the last direct piece's units (the next is at most twice as long) */
    double s_entry;      /* seconds per direct unit, smoothed; 0: none measured yet */
    double s_sweep;      /* seconds per sweep */
    double s_measure;    /* seconds of the convergence estimate */
    double late;         /* how much later than planned a budgeted call with light work ended,
                            smoothed (src/hd_schedule.h, hd__budget_late): the next plans less */
    int planned;         /* the current call planned its light work against the budget */
} hd__part;

/* The direct light's voxels besides what the backend reads (vw.dl_idx, src/hd_direct_mask.h). */
typedef struct hd__dl {
    uint8_t *bits;           /* the tracked voxels, one bit each (read by the convergence estimate) */
    int all;                 /* track every voxel (a test hook: the reference for the mask) */
} hd__dl;

/* The volume-to-world transform, decomposed (src/hd_scene.h). */
typedef struct hd__xform {
    int identity;   /* all zero or the identity: every map below is skipped (exactly today's box) */
    double q[3][3]; /* q[r][c]: row r of the box's unit axis c in the world */
    double t[3];    /* the box's centre in the world */
    double s[3];    /* world length of the box's unit along each axis */
} hd__xform;

/* What hdk_camera_ray and hdk_depth_t read (hd_k_params.h's cam_* and depth_* slots). */
typedef struct hd__camframe {
    int matrix;      /* 1: from the host's matrices (depth may be given) */
    float pos[3], ou[3], ov[3], u[3], v[3], w[3];
    float dm[16];    /* the inverse of projection * view into the volume's frame, row-major */
    float depth_z[3]; /* NDC z = [0] * depth + [1]; [2]: the far plane's depth */
    float dq[4], dw[4]; /* the volume's depth out: q = dq . (k, 1) / dw . (k, 1) (hdk_depth_q) */
} hd__camframe;

typedef struct hd__ctx {
    hd__view vw;             /* what the backend sees (src/hd_internal.h) */
    /* volume */
    float box[3];            /* size of the volume box (largest side 1) */
    float kbox[3];           /* its world extents along its own axes: box scaled by the transform
                                (src/hd_scene.h; the kernels' box) */
    hd__xform xf;            /* the volume-to-world transform, decomposed */
    hd__camframe cf;         /* the camera's rays in the volume's frame (hd__camera_frame) */
    float *cell_range;       /* per majorant cell: min and max value incl. the filter halo */
    float max_sigma;         /* max over the whole grid */
    /* inputs */
    hd_light lights[HD_MAX_LIGHTS];
    int light_count;
    int lights_one_colour;   /* every light has the same colour */
    float chan_color[3];
    /* the environment (hd_set_environment): on, its desc (rgb not kept: the tables in vw.env
       hold its radiance), every texel grey (r = g = b), and intensity * its largest component */
    int env_on;
    hd_environment env;
    int env_grey;
    double env_power;
    double env_fluence;      /* the map's fluence at a point in the open: the integral of its
                                max(rgb) radiance (times the intensity) over the sphere */
    int light_uniform;       /* 1: the light of a sample is drawn uniformly, not by its estimated
                                light (hd__light_cdf); set only by a test hook */
    /* method state */
    unsigned dirty;
    uint64_t iterations;
    uint64_t frames;
    double seconds[3];       /* direct (or convection / paths), diffusion, projection */
    hd__conv conv;
    double light_error;
    uint64_t converged_frames; /* projection frames since the light converged */
    uint64_t refined;        /* refinement paths per pixel in the resting view's image (HD_REST_REFINE,
                                BLEND; src/hd_schedule.h); 0: the image is HD's frames */
    int frame_scale;         /* render scale of the image's frames; 0: none chosen since the image
                                was reset (HD_RENDER_SCALE_AUTO starts coarse again) */
    hd__cost cost;
    int image_room;          /* the image buffer holds the reduced frames' region (made when a
                                scale > 1 is first used, hd__image_room) */
    int image_blend;         /* it holds HD_REST_BLEND's planes (made when the rest asks for them) */
    double blend_cost;       /* the last blend pass's seconds (hd__blend_image) */
    int no_measure;          /* light iterations are being recorded (hd_vulkan_record*), not run, or a
                                copy is recorded after them (hd_vulkan_record_illumination) */
    int rec_light;           /* light iterations recorded and not yet measured: the next call measures
                                them once the caller has run them (hd__prepare) */
    unsigned light_gen;      /* bumped whenever E or phi is reset: a solver's run state is stale */
    unsigned sig_gen;        /* bumped whenever sigma_t is reclassified (multigrid re-restricts) */
    hd__mg_cg mg;            /* HD_SOLVER_MULTIGRID's run state (src/hd_multigrid.h) */
    hd_params params_given;  /* the parameters as the caller gave them (zeros: defaults): what
                                HD_SOLVER_AUTO's fall-back fills in again (hd__solver_fallback) */
    int no_multigrid;        /* HD_SOLVER_AUTO picks red-black: multigrid could not run here */
    hd__dl dl;
    uint16_t *srgb;          /* hd_read_image_rgba8's encoding table (hd__srgb_table), made on its first call */
    int image_empty;         /* the image holds no frame: new (a new camera size) or reset, none
                                projected since (the read-backs say HD_ERROR_NO_FRAME) */
    uint64_t dl_n;           /* samples E's running mean holds: the next weighs 1 / (dl_n + 1); a
                                warm start caps it at params.light_window (src/hd_schedule.h) */
    hd__box upd;             /* the voxels hd_update_volume changed since the last hd__prepare
                                (HD__DIRTY_VOLUME), [lo, hi) */
    hd__part part;           /* a light iteration split over hd_render calls (render_budget) */
    double call_t0;          /* when the current hd_render call began (its budget's start) */
    int busy_logs;           /* HD_ERROR_BUSY lines being logged from other threads (hd__enter; __atomic) */
} hd__ctx;

/* The path tracers keep no illumination grid: the image is their whole state. */
static int hd__method_is_pt(hd_method m) { return m == HD_METHOD_PT_SS || m == HD_METHOD_PT_MS; }

/* Brings the device state up to date with what the setters changed (src/hd_schedule.h). */
static hd_result hd__prepare(hd__ctx *ctx);
/* r = the result of hd__prepare and then of expr, both in one bracket of the backend's
   (hd__be_begin / hd__be_end); expr is not evaluated when an earlier step failed. */
#define HD__BE_CALL(r, ctx, expr) \
    do { \
        if (((r) = hd__be_begin(&(ctx)->vw)) == HD_SUCCESS) { \
            if (((r) = hd__prepare(ctx)) == HD_SUCCESS) (r) = (expr); \
            (r) = hd__be_end(&(ctx)->vw, (r)); \
        } \
    } while (0)

#include "hd_handles.h"
#include "hd_validate.h"
#include "hd_params.h"
#include "hd_volume.h"
#include "hd_scene.h"
#include "hd_environment.h"
#include "hd_kparams.h"
#include "hd_multigrid.h"
#include "hd_direct_mask.h"
#include "hd_convergence.h"
#include "hd_frame_cost.h"
#include "hd_schedule.h"
#include "hd_readback.h"
#include "hd_api.h"

#endif
