/* hd_internal.h - the low layer the core (src/) and the backends (backends/) share: limits, the
   dirty bits, the view of a context a backend is handed (hd__view), logging and allocation.
   Private names are hd__ / HD__. */
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
/* Kernels index with 32-bit ints. The volume's voxels: at most 2^30 (1024^3). The illumination
   grid's voxels times its most channels (sigma_t and 3 colours with rgb_scattering, E and phi
   with 3 colours): below 2^31, so at most 2^29 - 1 voxels (hd__check_grid). */
#define HD__MAX_VOXELS (1u << 30)
#define HD__MAX_GRID_CHANNELS 4
#define HD__MAX_GRID_VOXELS ((1u << 29) - 1u)
#define HD__MAX_RENDER_SCALE 16 /* params.render_scale's largest divisor */
#define HD__DL_BRICK 8 /* voxels per edge of the direct light's list's bricks (src/hd_direct_mask.h;
                          a multiple of the light's runs of 8) */
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
    HD__DIRTY_DEPTH = 128, /* the host's depth buffer (vw.depth) changed: upload it or free it */
    HD__DIRTY_ALL = 255
};

#if defined(__GNUC__) || defined(__clang__)
#define HD__MAYBE_UNUSED __attribute__((unused))
#else
#define HD__MAYBE_UNUSED
#endif

typedef struct hd__backend hd__backend; /* defined by the selected backend */

/* What a backend sees of a context: the one struct the core hands every primitive of
   src/hd_backend.h, read-only (const) except in hd__be_create and hd__be_destroy, which own be.
   The core keeps these fields here and only here, and brings them up to date before each
   primitive; everything else of the context (src/hd_core.h) is the core's alone. */
typedef struct hd__view {
    hd__backend *be;         /* the backend's own state, made by hd__be_create */
    hd_logger log;
    hd_allocator alloc;
    hd_desc desc;            /* the desc with defaults filled in: the backend's own sections
                                (desc.opencl, .vulkan, .gl, .threads) */
    hd_params params;        /* the current parameters (defaults filled in) */
    hd_camera camera;        /* the current camera: the image is camera.width x height */
    /* the volume, x fastest, as vtype stores it (hd_k_params.h): HD_VOL_F32 holds the voxels'
       normalised values in [0, 1], HD_VOL_U8 / U16 / I16 the raw voxels, which the kernels and
       hd__vol_value map to [0, 1] as clamp((raw - vnorm[0]) * vnorm[1], 0, 1) */
    int dims[3];
    size_t nvox;
    void *vol;
    int vtype;
    float vnorm[2];
    int mdims[3];            /* the majorant grid (HD__MAJORANT_CELL voxels per cell edge) */
    float *majorant;         /* per cell: max sigma_t (0 outside the crop box) */
    float *tf;               /* the transfer function: RGBA * tf_count */
    int tf_count;
    unsigned tf_serial;      /* bumped by every TF change (the projection's table key, hd_backend.h) */
    /* the illumination grid */
    int gdims[3];
    int channels;            /* 1 or 3 */
    int sig_channels;        /* sigma_t grid channels: 1, or 4 with the TF colour (RGB scattering) */
    hd__kparams kp;          /* the kernels' parameter block for the next primitive */
    /* HD's direct light: the grid voxels it tracks (src/hd_direct_mask.h) */
    uint32_t *dl_idx;        /* their grid indices in bricks of HD__DL_BRICK^3, bricks and the
                                voxels inside them x fastest; NULL with dl_brick */
    uint32_t *dl_brick;      /* a backend with HD__BE_LIST_FROM_BITS: per brick, the entries
                                before it (one more: dl_count), the entries read from dl_bits */
    const uint8_t *dl_bits;  /* the mask, a bit per grid voxel (x fastest): the core's */
    size_t dl_count;
    unsigned dl_gen;         /* bumped whenever dl_idx changes: a backend re-uploads it */
    /* the host's depth buffer (hd_set_depth): depth_w x depth_h window depths, rows top first,
       NULL: none (kp.depth_dims.z = 0) */
    float *depth;
    int depth_w, depth_h;
    /* the environment's tables (hd_set_environment, src/hd_environment.h; the kernels' buffer
       env, hd_k_light.h): env_floats floats, NULL: none (kp.env.x = 0) */
    float *env;
    size_t env_floats;
    int depth_device;        /* the backend's buffer holds the host's depth (depth NULL), copied on
                                the device: 1 from a GL texture (hd_gl_set_depth_texture), rows
                                bottom first; 2 from a Vulkan image or buffer (hd_vulkan_record_depth),
                                3 from an OpenCL buffer (hd_opencl_set_depth_buffer), rows top first */
} hd__view;

/* Bytes of one voxel as vtype stores it. */
static size_t hd__vol_elem(int vtype) { return vtype == HD_VOL_U8 ? 1 : vtype == HD_VOL_F32 ? 4 : 2; }

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

static void *hd__alloc(const hd__view *vw, size_t size)
{
    return vw->alloc.alloc(size ? size : 1, vw->alloc.user_data);
}
static void *hd__calloc(const hd__view *vw, size_t count, size_t size)
{
    void *p;
    if (size && count > (size_t)-1 / size) return NULL;
    p = hd__alloc(vw, count * size);
    if (p) memset(p, 0, count * size);
    return p;
}

/* Bricks of the direct light's list along each axis (HD__DL_BRICK voxels an edge) of grid g. */
static size_t hd__direct_bricks(const int *g, int *nb)
{
    int d;
    for (d = 0; d < 3; ++d) nb[d] = (g[d] + HD__DL_BRICK - 1) / HD__DL_BRICK;
    return (size_t)nb[0] * nb[1] * nb[2];
}
static void hd__free(const hd__view *vw, void *ptr)
{
    if (ptr) vw->alloc.free(ptr, vw->alloc.user_data);
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
