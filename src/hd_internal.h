/* hd_internal.h - the context's private state, logging and allocation, shared by the core
   (hd_context.h) and the backends. Private names are hd__ / HD__. */
#ifndef HD_INTERNAL_H
#define HD_INTERNAL_H
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

#ifndef HD_MAX_CONTEXTS
#define HD_MAX_CONTEXTS 64
#endif
/* A handle keeps its slot in 8 bits (hd__lookup): more slots would alias each other's handles. */
#if HD_MAX_CONTEXTS < 1 || HD_MAX_CONTEXTS > 255
#error "hybriddiff: HD_MAX_CONTEXTS must be in 1..255 (a context handle holds its slot in 8 bits)"
#endif
/* Kernels index with 32-bit ints: the largest grid they may address, channels included. */
#define HD__MAX_VOXELS (1u << 30)
#define HD__MAX_RENDER_SCALE 8 /* params.render_scale's largest divisor */
#define HD__MAJORANT_CELL 4 /* voxels per majorant-grid cell edge: the balance between tight
                                majorants and few DDA steps (docs/DESIGN-CPU.md) */

/* What a setter invalidates (see the table above hd_set_transfer_function). */
enum {
    HD__DIRTY_SIGMA = 1,   /* sigma_t grid and majorant grid */
    HD__DIRTY_DIRECT = 2,  /* E and its iteration count */
    HD__DIRTY_PHI = 4,     /* phi */
    HD__DIRTY_IMAGE = 8,   /* image accumulation */
    HD__DIRTY_ALLOC = 16,  /* illumination grids must be (re)allocated (size or channels) */
    HD__DIRTY_IMAGE_ALLOC = 32, /* the image must be (re)allocated (its size changed) */
    HD__DIRTY_JACOBI = 64, /* Jacobi's second buffer must be allocated or freed */
    HD__DIRTY_ALL = 127
};

#if defined(__GNUC__) || defined(__clang__)
#define HD__MAYBE_UNUSED __attribute__((unused))
#else
#define HD__MAYBE_UNUSED
#endif

typedef struct hd__backend hd__backend; /* defined by the selected backend */

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

typedef struct hd__ctx {
    hd_desc desc;            /* with defaults filled in; pointers refer to the copies below */
    hd_allocator alloc;
    hd_logger log;
    /* volume */
    int dims[3];
    size_t nvox;
    float box[3];            /* world size of the volume box */
    float *vol;              /* normalised voxel values in [0, 1] */
    float *cell_range;       /* per majorant cell: min and max value incl. the filter halo */
    int mdims[3];
    float *majorant;         /* per cell: max sigma_t */
    float max_sigma;         /* max over the whole grid */
    /* inputs */
    float *tf;               /* RGBA * tf_count */
    int tf_count;
    unsigned tf_serial;      /* bumped by every TF change (the projection's table key, hd_backend.h) */
    hd_light lights[HD_MAX_LIGHTS];
    int light_count;
    hd_camera camera;
    hd_params params;
    /* method state */
    int gdims[3];            /* illumination grid */
    int channels;            /* 1 or 3 */
    int lights_one_colour;   /* every light has the same colour */
    int sig_channels;        /* sigma_t grid channels: 1, or 4 with the TF colour (RGB scattering) */
    float chan_color[3];
    unsigned dirty;
    uint64_t iterations;
    uint64_t frames;
    hd__kparams kp;
    double seconds[3];       /* direct (or convection / paths), diffusion, projection */
    /* light convergence (hd__light_measure): E and phi of the medium's voxels after the
       previous light iteration, to estimate the error from their change */
    uint32_t *conv_idx;      /* in-slice indices (y * gx + x) of the voxels measured, slice by slice */
    size_t conv_count;
    int *conv_zz;            /* the stacked slices read back: conv_nz per channel, channel-major */
    size_t *conv_off;        /* conv_nz + 1 starts in conv_idx, one per measured slice */
    int conv_nz;             /* measured slices per channel */
    float *conv_prev;        /* conv_count * channels values of E, then the same of phi */
    float *conv_tmp;         /* the measured slices of one illumination volume read back, all channels */
    int conv_have_prev;      /* conv_prev holds the previous iteration */
    int conv_below;          /* light iterations in a row with light_error below the tolerance */
    double conv_dphi;        /* |phi_n - phi_n-1| of the previous iteration */
    double conv_q;           /* the solver's observed contraction of that change */
    double light_error;
    uint64_t converged_frames; /* projection frames since the light converged */
    int frame_scale;         /* render scale of the image's frames; 0: none chosen since the image
                                was reset (HD_RENDER_SCALE_AUTO starts coarse again) */
    /* HD_RENDER_SCALE_AUTO's frame cost model (hd__frame_cost_add / _predict in hd_context.h):
       per render scale 1, 2, 4, 8 (slot log2 s) the pixels its last frame marched (0: none yet),
       its smoothed seconds and the measurement count when it was last measured; the newest
       measurement's slot; measurements so far (0: none) */
    double cost_pixels[4], cost_seconds[4];
    unsigned cost_at[4];
    int cost_last;
    unsigned cost_gen;
    int image_room;          /* the image buffer holds the reduced frames' region (made when a
                                scale > 1 is first used, hd__image_room) */
    int no_measure;          /* light iterations are being recorded (hd_vulkan_record), not run */
    unsigned light_gen;      /* bumped whenever E or phi is reset: a solver's run state is stale */
    unsigned sig_gen;        /* bumped whenever sigma_t is reclassified (multigrid re-restricts) */
    hd__mg_cg mg;            /* HD_SOLVER_MULTIGRID's run state (src/hd_multigrid.h) */
    /* HD's direct light is tracked only at the illumination-grid voxels whose E is read (the
       projection's and the diffusion's footprint of the medium, hd__direct_mask); rebuilt with
       sigma_t, E elsewhere stays 0 */
    uint32_t *dl_idx;        /* their grid indices in bricks (hd__direct_mask; every voxel, ascending, with dl_all) */
    size_t dl_count;
    uint8_t *dl_bits;        /* the same voxels, one bit each (read by the convergence estimate) */
    int dl_all;              /* track every voxel (a test hook: the reference for the mask) */
    unsigned dl_gen;         /* bumped whenever dl_idx changes: a backend re-uploads it */
    uint16_t *srgb;          /* hd_read_image_rgba8's encoding table (hd__srgb_table), made on its first call */
    hd__backend *be;
} hd__ctx;

/* ---- logging ---------------------------------------------------------------------------- */
static void hd__logf(const hd_logger *log, hd_log_level level, hd_result code, const char *file,
                     int line, const char *fmt, ...)
{
    char msg[1024];
    va_list ap;
    if (!log || !log->func) return;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    log->func(log->user_data, level, code, msg, file, line);
}
/* Logs an error and evaluates to its code: `return HD__ERR(log, HD_ERROR_X, "...", ...);` */
#define HD__ERR(log, code, ...) (hd__logf((log), HD_LOG_ERROR, (code), __FILE__, __LINE__, __VA_ARGS__), (code))
#define HD__INFO(log, ...) hd__logf((log), HD_LOG_INFO, HD_SUCCESS, __FILE__, __LINE__, __VA_ARGS__)

/* ---- allocation through the caller's allocator ------------------------------------------ */
static void *hd__malloc_default(size_t size, void *user) { (void)user; return malloc(size); }
static void hd__free_default(void *ptr, void *user) { (void)user; free(ptr); }

static void *hd__alloc(hd__ctx *ctx, size_t size)
{
    return ctx->alloc.alloc(size ? size : 1, ctx->alloc.user_data);
}
static void *hd__calloc(hd__ctx *ctx, size_t count, size_t size)
{
    void *p;
    if (size && count > (size_t)-1 / size) return NULL;
    p = hd__alloc(ctx, count * size);
    if (p) memset(p, 0, count * size);
    return p;
}
static void hd__free(hd__ctx *ctx, void *ptr)
{
    if (ptr) ctx->alloc.free(ptr, ctx->alloc.user_data);
}

/* Wall clock for the per-stage timers. */
#include <time.h>
#if defined(CLOCK_MONOTONIC)
static double hd__now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
#else
/* <time.h> read before hybriddiff.h under a strict C feature set leaves out clock_gettime. */
#include <sys/time.h>
static double hd__now(void)
{
    struct timeval tv;
    gettimeofday(&tv, NULL);
    return (double)tv.tv_sec + 1e-6 * (double)tv.tv_usec;
}
#endif

static int hd__finite(float v) { return v == v && v - v == 0.0f; }

#endif /* HD_INTERNAL_H */
