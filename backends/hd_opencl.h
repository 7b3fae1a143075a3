/* hd_opencl.h - the OpenCL 1.2 backend: the shared kernels (backends/kernels/), compiled at run
   time behind the OpenCL C prelude (hd_prelude_cl.h) from the strings scripts/embed-kernels
   writes into hd_kernels_embedded.h, so there is no second copy of the math.
   Defines the same hd__be_* functions, with the same contracts, as the CPU reference hd_cpu.h.

   Whose device: the caller may pass its cl_command_queue (the context and device are taken from
   it), or its cl_context (+ optionally a cl_device_id of it), in desc.opencl; the backend retains
   them and releases them when the context is destroyed. Otherwise it picks a device itself: the
   first whose name contains desc.opencl.device_name or $HD_CL_DEVICE (substring), else the first
   GPU, else the first device of any type.
   Memory: the volume, TF, majorant grid, sigma_t, E, phi (+ Jacobi's phi2) and the image are
   plain buffers; volume reads use the shared software trilinear filter (docs/DESIGN-OPENCL.md
   has the measurement against 3D images with a linear sampler). sigma_t, E, phi and phi2 are
   stored colour by colour (red-black), the layout hd_prelude_cl.h describes: each z-slice of
   each channel is its colour-0 voxels then its colour-1 voxels, (gx + 1) / 2 per row, so a
   half-sweep reads and writes contiguous runs. hd__be_read_illumination and the test hook's
   hd__cl_write_illumination convert from and to the API's x-fastest layout.
   Errors: every CL call is checked; the failing call and its CL error name are logged and the
   code becomes an hd_result (allocation -> HD_ERROR_OUT_OF_DEVICE_MEMORY, lost device ->
   HD_ERROR_DEVICE_LOST, which then sticks: later calls fail fast). */
#ifndef CL_TARGET_OPENCL_VERSION
#define CL_TARGET_OPENCL_VERSION 120
#endif
#if defined(__APPLE__)
#include <OpenCL/cl.h>
#else
#include <CL/cl.h>
#endif
#include "hd_kernels_embedded.h"


/* the eight diffusion kernels from HD__CL_DIFFUSE on, indexed by 4 * Jacobi + 2 * surface
   boundary + RGB scattering; then the binary16-storage twins of the stages that touch E or phi
   (hd__cl_k picks them), the diffusion's in the same order */
enum { HD__CL_CLASSIFY, HD__CL_DIRECT, HD__CL_DIFFUSE, HD__CL_PROJECT = HD__CL_DIFFUSE + 8, HD__CL_CONVECT,
       HD__CL_SUM_LIGHT, HD__CL_PATH, HD__CL_DIRECT_HALF, HD__CL_DIFFUSE_HALF,
       HD__CL_PROJECT_HALF = HD__CL_DIFFUSE_HALF + 8, HD__CL_SUM_LIGHT_HALF, HD__CL_LIGHT_SUM, HD__CL_LIGHT_SUM_HALF,
       /* HD_SOLVER_MULTIGRID's passes (hd_entry_cl.h); the residuals in four variants each, indexed
          by 2 * surface boundary + RGB scattering; those from HD__CL_MG_RES_F64 on compute in
          double and exist only on a device with cl_khr_fp64 */
       HD__CL_MG_SIG, HD__CL_MG_RESIDUAL, HD__CL_MG_RESTRICT_LINE = HD__CL_MG_RESIDUAL + 4, HD__CL_MG_RESTRICT,
       HD__CL_MG_PROLONG, HD__CL_MG_DIR,
       HD__CL_MG_RES_F64, HD__CL_MG_DOT = HD__CL_MG_RES_F64 + 4, HD__CL_MG_UPDATE, HD__CL_MG_EXTRAP,
       HD__CL_UPSAMPLE, HD__CL_KERNEL_COUNT };
static const char *const hd__cl_kernel_names[HD__CL_KERNEL_COUNT] = {
    "hd_k_classify", "hd_k_direct", "hd_k_diffuse", "hd_k_diffuse_rgb", "hd_k_diffuse_surface",
    "hd_k_diffuse_surface_rgb", "hd_k_diffuse_jacobi", "hd_k_diffuse_jacobi_rgb", "hd_k_diffuse_jacobi_surface",
    "hd_k_diffuse_jacobi_surface_rgb", "hd_k_project", "hd_k_convect", "hd_k_sum_light", "hd_k_path",
    "hd_k_direct_half", "hd_k_diffuse_half", "hd_k_diffuse_rgb_half", "hd_k_diffuse_surface_half",
    "hd_k_diffuse_surface_rgb_half", "hd_k_diffuse_jacobi_half", "hd_k_diffuse_jacobi_rgb_half",
    "hd_k_diffuse_jacobi_surface_half", "hd_k_diffuse_jacobi_surface_rgb_half", "hd_k_project_half",
    "hd_k_sum_light_half", "hd_k_light_sum", "hd_k_light_sum_half",
    "hd_k_mg_sig", "hd_k_mg_residual", "hd_k_mg_residual_rgb", "hd_k_mg_residual_surface",
    "hd_k_mg_residual_surface_rgb", "hd_k_mg_restrict_line", "hd_k_mg_restrict", "hd_k_mg_prolong", "hd_k_mg_dir", "hd_k_mg_res_f64",
    "hd_k_mg_res_f64_rgb", "hd_k_mg_res_f64_surface", "hd_k_mg_res_f64_surface_rgb", "hd_k_mg_dot", "hd_k_mg_update",
    "hd_k_mg_extrap", "hd_k_upsample"};

/* HD_SOLVER_MULTIGRID's per-level objects besides the grids (hd__gpu_mg_extras) and its grids */
typedef struct hd__cl_level {
    cl_mem params;           /* the level's parameter block (backends/hd_gpu.h's hd__gpu_level) */
    cl_mem sig;              /* coarse levels only (level 0 reads the backend's sigma_t) */
    cl_mem rhs, phi, res;    /* right-hand side, correction, residual; level 0: r, z and q = A p */
} hd__cl_level;

struct hd__cl_mg {
    hd__cl_level lv[HD__MG_MAX_LEVELS];
    cl_mem p, lo;            /* the search direction; the iterate's low part (phi + lo) */
    cl_mem dot_a, dot_b;     /* per-row partial sums (double) */
    cl_mem line;             /* the restriction's row buffer: a fine row's shares per coarse row */
    double *host_dot;        /* their host copy, one row sum per fine row */
};

struct hd__backend {
    const hd__view *vw;
    cl_context context;
    cl_device_id device;
    cl_command_queue queue;
    cl_program program;
    cl_program project_program; /* the projection's entry points, FP contraction on (hd__cl_build) */
    cl_kernel kernels[HD__CL_KERNEL_COUNT];
    /* kernel arguments 0..8, in the order of HD__CL_BUFFERS in hd_entry_cl.h */
    cl_mem params, vol, tf, maj, sig, E, phi, phi2, img;
    cl_mem dl;               /* the direct light's list of voxels (vw->dl_idx), direct kernels' argument 9 */
    cl_mem dep;              /* the host's depth buffer (vw->depth; a placeholder without one): the
                                projection's argument 12, the path kernel's 9 */
    size_t dep_floats;       /* what dep holds (0: the placeholder) */
    cl_mem env;              /* the environment's tables (vw->env; a placeholder without one): the
                                direct kernels' argument 12, the path kernel's 11, the projection's 13 */
    cl_mem lv[HD_MAX_LIGHTS + 1]; /* CD: gg.nlv light volumes + one spare (the ping-pong buffer) */
    /* the projection's own inputs (hd__cl_project_prepare): E + phi summed x-fastest, valid while
       gg.lsum_ok (backends/hd_gpu.h), and the step's TF table (ptab_n
       entries), uploaded when its inputs change (ptab_key) */
    cl_mem lsum, ptab;
    int ptab_n;
    hd__ptab_key ptab_key;
    size_t tf_bytes, img_floats;
    cl_ulong max_alloc;
    hd__kparams params_sent; /* what the params buffer holds */
    int params_valid;
    int lost;                /* a call reported a lost device: every later call fails fast */
    int fp64;                /* the device has cl_khr_fp64 (multigrid's double passes) */
    hd__gpu_grids gg;        /* what the grids are made for (backends/hd_gpu.h) */
    struct hd__cl_mg mg;     /* multigrid's extras and grids while gg.levels */
};

static const char *hd__be_name(void) { return "opencl"; }

/* ---- errors ------------------------------------------------------------------------------ */
static const char *hd__cl_error_name(cl_int e)
{
    switch (e) {
#define HD__CLE(name) case name: return #name;
    HD__CLE(CL_SUCCESS) HD__CLE(CL_DEVICE_NOT_FOUND) HD__CLE(CL_DEVICE_NOT_AVAILABLE)
    HD__CLE(CL_COMPILER_NOT_AVAILABLE) HD__CLE(CL_MEM_OBJECT_ALLOCATION_FAILURE)
    HD__CLE(CL_OUT_OF_RESOURCES) HD__CLE(CL_OUT_OF_HOST_MEMORY)
    HD__CLE(CL_PROFILING_INFO_NOT_AVAILABLE) HD__CLE(CL_MEM_COPY_OVERLAP) HD__CLE(CL_IMAGE_FORMAT_MISMATCH)
    HD__CLE(CL_IMAGE_FORMAT_NOT_SUPPORTED) HD__CLE(CL_BUILD_PROGRAM_FAILURE) HD__CLE(CL_MAP_FAILURE)
    HD__CLE(CL_MISALIGNED_SUB_BUFFER_OFFSET) HD__CLE(CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
    HD__CLE(CL_COMPILE_PROGRAM_FAILURE) HD__CLE(CL_LINKER_NOT_AVAILABLE) HD__CLE(CL_LINK_PROGRAM_FAILURE)
    HD__CLE(CL_DEVICE_PARTITION_FAILED) HD__CLE(CL_KERNEL_ARG_INFO_NOT_AVAILABLE)
    HD__CLE(CL_INVALID_VALUE) HD__CLE(CL_INVALID_DEVICE_TYPE) HD__CLE(CL_INVALID_PLATFORM)
    HD__CLE(CL_INVALID_DEVICE) HD__CLE(CL_INVALID_CONTEXT) HD__CLE(CL_INVALID_QUEUE_PROPERTIES)
    HD__CLE(CL_INVALID_COMMAND_QUEUE) HD__CLE(CL_INVALID_HOST_PTR) HD__CLE(CL_INVALID_MEM_OBJECT)
    HD__CLE(CL_INVALID_IMAGE_FORMAT_DESCRIPTOR) HD__CLE(CL_INVALID_IMAGE_SIZE) HD__CLE(CL_INVALID_SAMPLER)
    HD__CLE(CL_INVALID_BINARY) HD__CLE(CL_INVALID_BUILD_OPTIONS) HD__CLE(CL_INVALID_PROGRAM)
    HD__CLE(CL_INVALID_PROGRAM_EXECUTABLE) HD__CLE(CL_INVALID_KERNEL_NAME)
    HD__CLE(CL_INVALID_KERNEL_DEFINITION) HD__CLE(CL_INVALID_KERNEL) HD__CLE(CL_INVALID_ARG_INDEX)
    HD__CLE(CL_INVALID_ARG_VALUE) HD__CLE(CL_INVALID_ARG_SIZE) HD__CLE(CL_INVALID_KERNEL_ARGS)
    HD__CLE(CL_INVALID_WORK_DIMENSION) HD__CLE(CL_INVALID_WORK_GROUP_SIZE)
    HD__CLE(CL_INVALID_WORK_ITEM_SIZE) HD__CLE(CL_INVALID_GLOBAL_OFFSET)
    HD__CLE(CL_INVALID_EVENT_WAIT_LIST) HD__CLE(CL_INVALID_EVENT) HD__CLE(CL_INVALID_OPERATION)
    HD__CLE(CL_INVALID_GL_OBJECT) HD__CLE(CL_INVALID_BUFFER_SIZE) HD__CLE(CL_INVALID_MIP_LEVEL)
    HD__CLE(CL_INVALID_GLOBAL_WORK_SIZE) HD__CLE(CL_INVALID_PROPERTY)
#undef HD__CLE
    case -1001: return "CL_PLATFORM_NOT_FOUND_KHR";
    default: return "unknown CL error";
    }
}

/* Logs the failing call with its CL error name and returns the hd_result it means. alloc: the
   call allocates, so a lack of resources is a lack of device memory, not a lost device. */
static hd_result hd__cl_fail(const hd__view *vw, cl_int e, const char *call, int alloc, int line)
{
    hd_result r = HD_ERROR_BACKEND;
    if (e == CL_MEM_OBJECT_ALLOCATION_FAILURE || e == CL_INVALID_BUFFER_SIZE || (alloc && e == CL_OUT_OF_RESOURCES))
        r = HD_ERROR_OUT_OF_DEVICE_MEMORY;
    else if (e == CL_OUT_OF_HOST_MEMORY)
        r = HD_ERROR_OUT_OF_MEMORY;
    else if (e == CL_DEVICE_NOT_AVAILABLE || e == CL_OUT_OF_RESOURCES || e == CL_EXEC_STATUS_ERROR_FOR_EVENTS_IN_WAIT_LIST)
        r = HD_ERROR_DEVICE_LOST;
    if (r == HD_ERROR_DEVICE_LOST && vw->be) vw->be->lost = 1;
    hd__logf(&vw->log, HD_LOG_ERROR, r, __FILE__, line, "opencl: %s failed: %s (%d)", call,
             hd__cl_error_name(e), (int)e);
    return r;
}
/* Returns from the calling function when a CL call failed. */
#define HD__CL_TRY(vw, call_expr, name) \
    do { cl_int hd__e = (call_expr); \
         if (hd__e != CL_SUCCESS) return hd__cl_fail((vw), hd__e, (name), 0, __LINE__); } while (0)

#define HD__CL_LOST_CHECK(vw) \
    do { if ((vw)->be->lost) return HD__ERR(&(vw)->log, HD_ERROR_DEVICE_LOST, "opencl: the device was lost earlier"); } while (0)
/* Sets kernel k's argument i to the scalar lvalue v; returns from the calling function on failure. */
#define HD__CL_ARG(vw, k, i, v) \
    HD__CL_TRY(vw, clSetKernelArg((vw)->be->kernels[k], (cl_uint)(i), sizeof(v), &(v)), "clSetKernelArg(" #v ")")

/* ---- device selection -------------------------------------------------------------------- */
static int hd__cl_name_matches(cl_device_id dev, const char *want, char *name, size_t cap)
{
    name[0] = '\0';
    if (clGetDeviceInfo(dev, CL_DEVICE_NAME, cap, name, NULL) != CL_SUCCESS) return 0;
    name[cap - 1] = '\0';
    return !want || !*want || strstr(name, want) != NULL;
}

/* Picks a device of the first platform that has one: by name, else a GPU, else any. */
static hd_result hd__cl_pick_device(const hd__view *vw, cl_device_id *out)
{
    cl_platform_id plats[16];
    cl_uint np = 0, p, pass;
    cl_int e;
    const char *want = vw->desc.opencl.device_name;
    char name[256];
    if (!want || !*want) want = getenv("HD_CL_DEVICE");
    e = clGetPlatformIDs(16, plats, &np);
    if (e == -1001 || (e == CL_SUCCESS && np == 0))
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "opencl: no OpenCL platform is installed (clGetPlatformIDs: %s)",
                       hd__cl_error_name(e == CL_SUCCESS ? -1001 : e));
    if (e != CL_SUCCESS) return hd__cl_fail(vw, e, "clGetPlatformIDs", 0, __LINE__);
    if (np > 16) np = 16;
    for (pass = 0; pass < 2; ++pass) {
        for (p = 0; p < np; ++p) {
            cl_device_id devs[16];
            cl_uint nd = 0, d;
            cl_device_type type = (pass == 0 && !(want && *want)) ? CL_DEVICE_TYPE_GPU : CL_DEVICE_TYPE_ALL;
            if (clGetDeviceIDs(plats[p], type, 16, devs, &nd) != CL_SUCCESS) continue;
            if (nd > 16) nd = 16;
            for (d = 0; d < nd; ++d) {
                cl_bool avail = CL_FALSE, compiler = CL_FALSE;
                clGetDeviceInfo(devs[d], CL_DEVICE_AVAILABLE, sizeof avail, &avail, NULL);
                clGetDeviceInfo(devs[d], CL_DEVICE_COMPILER_AVAILABLE, sizeof compiler, &compiler, NULL);
                if (!avail || !compiler) continue;
                if (!hd__cl_name_matches(devs[d], want, name, sizeof name)) continue;
                *out = devs[d];
                return HD_SUCCESS;
            }
        }
    }
    if (want && *want)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "opencl: no available device's name contains \"%s\"", want);
    return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "opencl: no available OpenCL device with a compiler");
}

/* The caller's queue, context and device, or ones the backend makes. Every object is retained
   once here and released once in hd__be_destroy. */
static hd_result hd__cl_open(const hd__view *vw)
{
    hd__backend *be = vw->be;
    cl_int e;
    if (vw->desc.opencl.queue) {
        be->queue = (cl_command_queue)vw->desc.opencl.queue;
        HD__CL_TRY(vw, clRetainCommandQueue(be->queue), "clRetainCommandQueue(desc.opencl.queue)");
        HD__CL_TRY(vw, clGetCommandQueueInfo(be->queue, CL_QUEUE_CONTEXT, sizeof be->context, &be->context, NULL), "clGetCommandQueueInfo(CL_QUEUE_CONTEXT)");
        HD__CL_TRY(vw, clRetainContext(be->context), "clRetainContext");
        HD__CL_TRY(vw, clGetCommandQueueInfo(be->queue, CL_QUEUE_DEVICE, sizeof be->device, &be->device, NULL), "clGetCommandQueueInfo(CL_QUEUE_DEVICE)");
        return HD_SUCCESS;
    }
    if (vw->desc.opencl.context) {
        be->context = (cl_context)vw->desc.opencl.context;
        HD__CL_TRY(vw, clRetainContext(be->context), "clRetainContext(desc.opencl.context)");
        if (vw->desc.opencl.device) {
            be->device = (cl_device_id)vw->desc.opencl.device;
        } else {
            HD__CL_TRY(vw, clGetContextInfo(be->context, CL_CONTEXT_DEVICES, sizeof be->device, &be->device, NULL), "clGetContextInfo(CL_CONTEXT_DEVICES)");
        }
    } else {
        hd_result r;
        if (vw->desc.opencl.device) be->device = (cl_device_id)vw->desc.opencl.device;
        else if ((r = hd__cl_pick_device(vw, &be->device)) != HD_SUCCESS) return r;
        be->context = clCreateContext(NULL, 1, &be->device, NULL, NULL, &e);
        if (e != CL_SUCCESS) { be->context = NULL; return hd__cl_fail(vw, e, "clCreateContext", 0, __LINE__); }
    }
    /* OpenCL 1.2's call; a <CL/cl.h> the including file read first for 2.0+ marks it deprecated */
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
#endif
    be->queue = clCreateCommandQueue(be->context, be->device, 0, &e);
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif
    if (e != CL_SUCCESS) { be->queue = NULL; return hd__cl_fail(vw, e, "clCreateCommandQueue", 0, __LINE__); }
    return HD_SUCCESS;
}

/* Builds the embedded source into *out with the options opts; a failure logs the build log (in
   pieces the logger can hold). */
static hd_result hd__cl_build_program(const hd__view *vw, cl_program *out, const char *opts)
{
    hd__backend *be = vw->be;
    cl_int e;
    *out = clCreateProgramWithSource(be->context, (cl_uint)HD__CL_SOURCE_LINES, (const char **)hd__cl_source, NULL, &e);
    if (e != CL_SUCCESS) { *out = NULL; return hd__cl_fail(vw, e, "clCreateProgramWithSource", 0, __LINE__); }
    e = clBuildProgram(*out, 1, &be->device, opts, NULL, NULL);
    if (e != CL_SUCCESS) {
        size_t n = 0, i;
        char *text;
        hd_result r = hd__cl_fail(vw, e, "clBuildProgram", 0, __LINE__);
        clGetProgramBuildInfo(*out, be->device, CL_PROGRAM_BUILD_LOG, 0, NULL, &n);
        text = (char *)hd__alloc(vw, n + 1);
        if (text && clGetProgramBuildInfo(*out, be->device, CL_PROGRAM_BUILD_LOG, n, text, NULL) == CL_SUCCESS) {
            text[n] = '\0';
            for (i = 0; i < n && text[i]; i += 900)
                hd__logf(&vw->log, HD_LOG_ERROR, r, __FILE__, __LINE__, "opencl: build log: %.900s", text + i);
        }
        hd__free(vw, text);
        return r;
    }
    return HD_SUCCESS;
}

/* The two programs: every stage but the projection, and the projection alone, built with
   HD_CL_PROJECTION_PROGRAM (hd_prelude_cl.h: a*b+c may fuse there, not in the deterministic
   stages), so each kernel comes from the program that has it. */
static hd_result hd__cl_build(const hd__view *vw)
{
    hd__backend *be = vw->be;
    cl_int e;
    char opts[128];
    hd_result r;
    int k;
    snprintf(opts, sizeof opts, "-cl-std=CL1.2 -DHD_MAX_LIGHTS=%d", HD_MAX_LIGHTS);
    if ((r = hd__cl_build_program(vw, &be->program, opts)) != HD_SUCCESS) return r;
    snprintf(opts, sizeof opts, "-cl-std=CL1.2 -DHD_MAX_LIGHTS=%d -DHD_CL_PROJECTION_PROGRAM", HD_MAX_LIGHTS);
    if ((r = hd__cl_build_program(vw, &be->project_program, opts)) != HD_SUCCESS) return r;
    for (k = 0; k < HD__CL_KERNEL_COUNT; ++k) {
        int project = k == HD__CL_PROJECT || k == HD__CL_PROJECT_HALF || k == HD__CL_UPSAMPLE;
        if (!be->fp64 && k >= HD__CL_MG_RES_F64 && k <= HD__CL_MG_EXTRAP) continue; /* not compiled (HD_MG_F64) */
        be->kernels[k] = clCreateKernel(project ? be->project_program : be->program, hd__cl_kernel_names[k], &e);
        if (e != CL_SUCCESS) { be->kernels[k] = NULL; return hd__cl_fail(vw, e, hd__cl_kernel_names[k], 0, __LINE__); }
    }
    return HD_SUCCESS;
}

/* ---- buffers ------------------------------------------------------------------------------ */
static void hd__cl_release(cl_mem *m)
{
    if (*m) clReleaseMemObject(*m);
    *m = NULL;
}

/* A device buffer of `bytes`, filled from host (copied) or with zeros. */
static hd_result hd__cl_buffer(const hd__view *vw, cl_mem *out, size_t bytes, const void *host, const char *what)
{
    hd__backend *be = vw->be;
    cl_int e;
    float zero = 0.0f;
    *out = NULL;
    if (bytes == 0) bytes = 16;
    if ((cl_ulong)bytes > be->max_alloc)
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_DEVICE_MEMORY, "opencl: %s needs %zu bytes, above the device's largest allocation (%llu)",
                       what, bytes, (unsigned long long)be->max_alloc);
    *out = clCreateBuffer(be->context, CL_MEM_READ_WRITE | (host ? CL_MEM_COPY_HOST_PTR : 0), bytes, (void *)host, &e);
    if (e != CL_SUCCESS) { *out = NULL; return hd__cl_fail(vw, e, "clCreateBuffer", 1, __LINE__); }
    if (!host) {
        e = clEnqueueFillBuffer(be->queue, *out, &zero, sizeof zero, 0, bytes & ~(size_t)3, 0, NULL, NULL);
        if (e != CL_SUCCESS) return hd__cl_fail(vw, e, "clEnqueueFillBuffer", 1, __LINE__);
    }
    return HD_SUCCESS;
}

static hd_result hd__cl_zero(const hd__view *vw, cl_mem m, size_t floats)
{
    float zero = 0.0f;
    if (!m || floats == 0) return HD_SUCCESS;
    HD__CL_TRY(vw, clEnqueueFillBuffer(vw->be->queue, m, &zero, sizeof zero, 0, floats * sizeof(float), 0, NULL, NULL), "clEnqueueFillBuffer");
    return HD_SUCCESS;
}

/* Grid id's buffer (backends/hd_gpu.h). */
static cl_mem *hd__cl_grid(hd__backend *be, int id)
{
    cl_mem *named[HD__G_MG_LEVELS] = {&be->sig, &be->E, &be->phi, &be->phi2, &be->lsum, &be->mg.p, &be->mg.lo};
    hd__cl_level *L = &be->mg.lv[HD__G_LEVEL_OF(id)];
    cl_mem *level[4] = {&L->sig, &L->rhs, &L->phi, &L->res}; /* by HD__G_MG_SIG, _RHS, _PHI, _RES */
    return id < HD__G_MG_LEVELS ? named[id] : id >= HD__G_LIGHT ? &be->lv[id - HD__G_LIGHT] : level[(id - HD__G_MG_LEVELS) % 4];
}

/* E, phi, phi2: in the colour layout (hd__split_slots), 2 bytes per binary16 element rounded up
   to whole floats (hd__cl_buffer's 4-byte fill reaches the end); sigma_t and the multigrid's
   grids in the colour layout too; the summed light and the light volumes x-fastest floats. */
static hd_result hd__gpu_grid_new(const hd__view *vw, int id, int w, int h, int d, const char *what)
{
    size_t n = id == HD__G_LSUM || id >= HD__G_LIGHT ? (size_t)w * h * d : hd__split_slots(w, h, (size_t)d);
    int half = vw->be->gg.f16 && id >= HD__G_E && id <= HD__G_PHI2;
    hd__cl_release(hd__cl_grid(vw->be, id));
    return hd__cl_buffer(vw, hd__cl_grid(vw->be, id), half ? (n * 2 + 3) & ~(size_t)3 : n * sizeof(float), NULL, what);
}

static void hd__gpu_grid_free(const hd__view *vw, int id) { hd__cl_release(hd__cl_grid(vw->be, id)); }

static hd_result hd__gpu_grid_zero(const hd__view *vw, int id)
{
    cl_mem m = *hd__cl_grid(vw->be, id);
    size_t bytes = 0;
    if (m) HD__CL_TRY(vw, clGetMemObjectInfo(m, CL_MEM_SIZE, sizeof bytes, &bytes, NULL), "clGetMemObjectInfo(CL_MEM_SIZE)");
    return hd__cl_zero(vw, m, bytes / sizeof(float));
}

/* ---- life cycle -------------------------------------------------------------------------- */
/* The bracket of a public call (src/hd_backend.h): a lost device refused; each stage has waited
   for its own work already (hd__cl_finish). */
static hd_result hd__be_begin(const hd__view *vw)
{
    HD__CL_LOST_CHECK(vw);
    return HD_SUCCESS;
}
static hd_result hd__be_end(const hd__view *vw, hd_result r)
{
    (void)vw;
    return r;
}

static void hd__be_destroy(hd__view *vw)
{
    hd__backend *be = vw->be;
    int k;
    if (!be) return;
    if (be->queue) clFinish(be->queue);
    hd__gpu_free(vw, &be->gg);
    hd__cl_release(&be->params); hd__cl_release(&be->vol); hd__cl_release(&be->tf); hd__cl_release(&be->maj);
    hd__cl_release(&be->img); hd__cl_release(&be->dl); hd__cl_release(&be->ptab); hd__cl_release(&be->dep);
    hd__cl_release(&be->env);
    for (k = 0; k < HD__CL_KERNEL_COUNT; ++k)
        if (be->kernels[k]) clReleaseKernel(be->kernels[k]);
    if (be->program) clReleaseProgram(be->program);
    if (be->project_program) clReleaseProgram(be->project_program);
    if (be->queue) clReleaseCommandQueue(be->queue);
    if (be->context) clReleaseContext(be->context);
    hd__free(vw, be);
    vw->be = NULL;
}

static hd_result hd__be_create(hd__view *vw)
{
    hd__backend *be;
    hd_result r;
    char name[256] = {0}, version[128] = {0};
    cl_ulong const_size = 0;
    size_t ncell = (size_t)vw->mdims[0] * vw->mdims[1] * vw->mdims[2];
    be = (hd__backend *)hd__calloc(vw, 1, sizeof *be);
    if (!be) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "opencl: cannot allocate the backend");
    vw->be = be;
    be->vw = vw;
    if ((r = hd__cl_open(vw)) != HD_SUCCESS) return r;
    clGetDeviceInfo(be->device, CL_DEVICE_NAME, sizeof name - 1, name, NULL);
    clGetDeviceInfo(be->device, CL_DEVICE_VERSION, sizeof version - 1, version, NULL);
    HD__CL_TRY(vw, clGetDeviceInfo(be->device, CL_DEVICE_MAX_MEM_ALLOC_SIZE, sizeof be->max_alloc, &be->max_alloc, NULL), "clGetDeviceInfo(CL_DEVICE_MAX_MEM_ALLOC_SIZE)");
    HD__CL_TRY(vw, clGetDeviceInfo(be->device, CL_DEVICE_MAX_CONSTANT_BUFFER_SIZE, sizeof const_size, &const_size, NULL), "clGetDeviceInfo(CL_DEVICE_MAX_CONSTANT_BUFFER_SIZE)");
    if (const_size < sizeof(hd__kparams))
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "opencl: %s holds %llu bytes of __constant memory, the parameters need %zu",
                       name, (unsigned long long)const_size, sizeof(hd__kparams));
    {
        cl_device_fp_config fp64 = 0; /* 0 without double support (OpenCL 1.2: cl_khr_fp64) */
        if (clGetDeviceInfo(be->device, CL_DEVICE_DOUBLE_FP_CONFIG, sizeof fp64, &fp64, NULL) == CL_SUCCESS) be->fp64 = fp64 != 0;
    }
    HD__INFO(&vw->log, "opencl: device %s (%s)%s", name, version, be->fp64 ? "" : ", no double precision (no multigrid solver)");
    if ((r = hd__cl_build(vw)) != HD_SUCCESS) return r;
    if ((r = hd__cl_buffer(vw, &be->params, sizeof(hd__kparams), NULL, "the parameter block")) != HD_SUCCESS) return r;
    /* the volume as the core keeps it: U8 / U16 / I16 (read as uchar / ushort / short) or floats */
    if ((r = hd__cl_buffer(vw, &be->vol, vw->nvox * hd__vol_elem(vw->vtype), vw->vol, "the volume")) != HD_SUCCESS) return r;
    if ((r = hd__cl_buffer(vw, &be->maj, ncell * sizeof(float), NULL, "the majorant grid")) != HD_SUCCESS) return r;
    return HD_SUCCESS;
}

static hd_result hd__be_upload_inputs(const hd__view *vw)
{
    hd__backend *be = vw->be;
    size_t tf_bytes = (size_t)vw->tf_count * 4 * sizeof(float);
    size_t ncell = (size_t)vw->mdims[0] * vw->mdims[1] * vw->mdims[2];
    hd_result r;
    if (tf_bytes != be->tf_bytes) {
        hd__cl_release(&be->tf);
        be->tf_bytes = 0;
        if ((r = hd__cl_buffer(vw, &be->tf, tf_bytes, NULL, "the transfer function")) != HD_SUCCESS) return r;
        be->tf_bytes = tf_bytes;
    }
    /* blocking: vw->tf and vw->majorant may change as soon as this returns */
    HD__CL_TRY(vw, clEnqueueWriteBuffer(be->queue, be->tf, CL_TRUE, 0, tf_bytes, vw->tf, 0, NULL, NULL), "clEnqueueWriteBuffer(tf)");
    HD__CL_TRY(vw, clEnqueueWriteBuffer(be->queue, be->maj, CL_TRUE, 0, ncell * sizeof(float), vw->majorant, 0, NULL, NULL), "clEnqueueWriteBuffer(majorant)");
    return HD_SUCCESS;
}

/* hd_update_volume: the box of the volume and the majorant cells, each one rectangular write
   from the core's copies (blocking: they may change as soon as this returns). */
static hd_result hd__be_update_volume(const hd__view *vw, const hd__box *vox, const hd__box *cells)
{
    hd__backend *be = vw->be;
    size_t o[3], n[3], f = sizeof(float), e = hd__vol_elem(vw->vtype);
    size_t vr = (size_t)vw->dims[0] * e, vs = vr * (size_t)vw->dims[1];
    size_t mr = (size_t)vw->mdims[0] * f, ms = mr * (size_t)vw->mdims[1];
    int d;
    for (d = 0; d < 3; ++d) {
        o[d] = (size_t)vox->lo[d] * (d == 0 ? e : 1);
        n[d] = (size_t)(vox->hi[d] - vox->lo[d]) * (d == 0 ? e : 1);
    }
    HD__CL_TRY(vw, clEnqueueWriteBufferRect(be->queue, be->vol, CL_TRUE, o, o, n, vr, vs, vr, vs, vw->vol, 0, NULL, NULL),
               "clEnqueueWriteBufferRect(volume)");
    for (d = 0; d < 3; ++d) {
        o[d] = (size_t)cells->lo[d] * (d == 0 ? f : 1);
        n[d] = (size_t)(cells->hi[d] - cells->lo[d]) * (d == 0 ? f : 1);
    }
    HD__CL_TRY(vw, clEnqueueWriteBufferRect(be->queue, be->maj, CL_TRUE, o, o, n, mr, ms, mr, ms, vw->majorant, 0, NULL, NULL),
               "clEnqueueWriteBufferRect(majorant)");
    return HD_SUCCESS;
}

/* Elements of a colour-layout grid of `slices` z-slices (gz per channel): each row of gx voxels
   takes 2 * ((gx + 1) / 2) slots, one of them padding when gx is odd. */
#define HD__BE_SPLIT_LAYOUT 1 /* hd_get_stats counts the layout's padding slots */
static size_t hd__cl_slots(const hd__view *vw, size_t slices)
{
    return hd__split_slots(vw->gdims[0], vw->gdims[1], slices);
}

/* The slot of voxel (x, y, zz) in the colour layout: hd_prelude_cl.h's HD__CL_AT, host side (the
   CPU backend's layout too, hd_prelude_c.h). */
static size_t hd__cl_slot(const hd__view *vw, int x, int y, int zz)
{
    return hd__split_slot(vw->gdims[0], vw->gdims[1], x, y, zz);
}

/* The kernel of stage k for the storage precision: its _half twin with binary16 illumination. */
static int hd__cl_k(const hd__view *vw, int k)
{
    if (!vw->be->gg.f16) return k;
    if (k == HD__CL_DIRECT) return HD__CL_DIRECT_HALF;
    if (k == HD__CL_PROJECT) return HD__CL_PROJECT_HALF;
    if (k == HD__CL_SUM_LIGHT) return HD__CL_SUM_LIGHT_HALF;
    if (k == HD__CL_LIGHT_SUM) return HD__CL_LIGHT_SUM_HALF;
    if (k >= HD__CL_DIFFUSE && k < HD__CL_DIFFUSE + 8) return k - HD__CL_DIFFUSE + HD__CL_DIFFUSE_HALF;
    return k;
}

static hd_result hd__be_alloc_illumination(const hd__view *vw, size_t illum_floats)
{
    return hd__gpu_alloc_illumination(vw, &vw->be->gg, illum_floats);
}

static hd_result hd__be_alloc_jacobi(const hd__view *vw, int enable) { return hd__gpu_alloc_jacobi(vw, &vw->be->gg, enable); }

static hd_result hd__be_alloc_image(const hd__view *vw, int width, int height, int parts)
{
    hd__backend *be = vw->be;
    size_t floats = hd__image_floats(width, height, parts);
    cl_mem img;
    hd_result r;
    if ((r = hd__cl_buffer(vw, &img, floats * sizeof(float), NULL, (parts & HD__IMAGE_REDUCED) ? "the image with room for reduced frames" : "the image")) !=
        HD_SUCCESS) {
        hd__cl_release(&img);
        return r;
    }
    hd__cl_release(&be->img);
    be->img = img;
    be->img_floats = floats;
    return HD_SUCCESS;
}

static hd_result hd__be_clear(const hd__view *vw, unsigned what)
{
    hd__backend *be = vw->be;
    hd_result r;
    if ((r = hd__gpu_clear(vw, &be->gg, what)) != HD_SUCCESS) return r;
    return (what & HD__DIRTY_IMAGE) ? hd__cl_zero(vw, be->img, be->img_floats) : HD_SUCCESS;
}

/* ---- dispatch ------------------------------------------------------------------------------ */
/* Sends vw->kp to the params buffer when it changed since the last send (blocking: the host
   copy changes every iteration). */
static hd_result hd__cl_send_params(const hd__view *vw)
{
    hd__backend *be = vw->be;
    if (!be->params_valid || memcmp(&be->params_sent, &vw->kp, sizeof vw->kp) != 0) {
        HD__CL_TRY(vw, clEnqueueWriteBuffer(be->queue, be->params, CL_TRUE, 0, sizeof vw->kp, &vw->kp, 0, NULL, NULL), "clEnqueueWriteBuffer(params)");
        be->params_sent = vw->kp;
        be->params_valid = 1;
    }
    return HD_SUCCESS;
}

/* Sets kernel k's arguments first, first + 1, ... to the n buffers (cl_mem) in ap. */
static hd_result hd__cl_vmems(const hd__view *vw, int k, cl_uint first, int n, va_list ap)
{
    cl_int e = CL_SUCCESS;
    int i;
    for (i = 0; i < n && e == CL_SUCCESS; ++i) {
        cl_mem m = va_arg(ap, cl_mem);
        e = clSetKernelArg(vw->be->kernels[k], first + (cl_uint)i, sizeof m, &m);
    }
    return e == CL_SUCCESS ? HD_SUCCESS : hd__cl_fail(vw, e, "clSetKernelArg", 0, __LINE__);
}

/* The same with the n buffers following n. */
static hd_result hd__cl_mems(const hd__view *vw, int k, cl_uint first, int n, ...)
{
    va_list ap;
    hd_result r;
    va_start(ap, n);
    r = hd__cl_vmems(vw, k, first, n, ap);
    va_end(ap);
    return r;
}

/* Sends vw->kp if it changed (hd__cl_send_params) and binds the buffers to kernel k's first
   nine arguments. */
static hd_result hd__cl_bind(const hd__view *vw, int k)
{
    hd__backend *be = vw->be;
    hd_result r;
    if ((r = hd__cl_send_params(vw)) != HD_SUCCESS) return r;
    return hd__cl_mems(vw, k, 0, 9, be->params, be->vol, be->tf, be->maj, be->sig, be->E, be->phi, be->phi2, be->img);
}

static hd_result hd__cl_run_local(const hd__view *vw, int k, cl_uint dims, size_t gx, size_t gy, size_t gz, const size_t *local)
{
    size_t global[3];
    global[0] = gx; global[1] = gy; global[2] = gz;
    if (gx == 0 || gy == 0 || gz == 0) return HD_SUCCESS;
    HD__CL_TRY(vw, clEnqueueNDRangeKernel(vw->be->queue, vw->be->kernels[k], dims, NULL, global, local, 0, NULL, NULL),
               hd__cl_kernel_names[k]);
    return HD_SUCCESS;
}

static hd_result hd__cl_run(const hd__view *vw, int k, cl_uint dims, size_t gx, size_t gy, size_t gz)
{
    return hd__cl_run_local(vw, k, dims, gx, gy, gz, NULL);
}

/* Binds kernel k (hd__cl_bind) and runs it over gx x gy x gz. */
static hd_result hd__cl_bind_run(const hd__view *vw, int k, cl_uint dims, size_t gx, size_t gy, size_t gz)
{
    hd_result r = hd__cl_bind(vw, k);
    return r != HD_SUCCESS ? r : hd__cl_run(vw, k, dims, gx, gy, gz);
}

/* Waits for the queue. Each stage returns when its work is done, as on the CPU, so the core's
   per-stage clocks measure the device rather than the enqueueing (cost: one clFinish per stage). */
static hd_result hd__cl_finish(const hd__view *vw)
{
    HD__CL_TRY(vw, clFinish(vw->be->queue), "clFinish");
    return HD_SUCCESS;
}

/* The variant of a kernel family (diffusion, residuals) for the boundary and RGB flags. */
static int hd__cl_variant(const hd__view *vw, int first)
{
    return first + ((vw->kp.counts.z & HD_FLAG_SURFACE_BOUNDARY) ? 2 : 0) + ((vw->kp.counts.z & HD_FLAG_RGB_SCATTERING) ? 1 : 0);
}

/* n passes of kernel k over alternate colours of a grid of dims d (channels stacked in z), the
   first of colour `first`, the parity kernel argument `arg`. A pass has one work-item per voxel
   of its colour, (gx + 1) / 2 per row (hd_entry_cl.h), and a work-group is one x-row: PoCL
   vectorises a work-group along x, and its own choice of local size can cut a row into pieces as
   small as one item (it did for a prime row length). A row longer than the kernel's largest
   work-group leaves the choice to the runtime. */
static hd_result hd__cl_colour_passes(const hd__view *vw, int k, const int *d, int channels, cl_uint arg, int first, int n)
{
    hd__backend *be = vw->be;
    size_t hx = ((size_t)d[0] + 1) / 2, local[3], wg = 0;
    hd_result r;
    int i;
    HD__CL_TRY(vw, clGetKernelWorkGroupInfo(be->kernels[k], be->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof wg, &wg, NULL),
               "clGetKernelWorkGroupInfo");
    local[0] = hx; local[1] = 1; local[2] = 1;
    for (i = 0; i < n; ++i) {
        cl_int parity = (first ^ i) & 1;
        HD__CL_ARG(vw, k, arg, parity);
        if ((r = hd__cl_run_local(vw, k, 3, hx, (size_t)d[1], (size_t)d[2] * (size_t)channels, hx <= wg ? local : NULL)) != HD_SUCCESS)
            return r;
    }
    return HD_SUCCESS;
}

static hd_result hd__be_classify(const hd__view *vw)
{
    return hd__cl_bind_run(vw, HD__CL_CLASSIFY, 3, (size_t)vw->gdims[0], (size_t)vw->gdims[1], (size_t)vw->gdims[2]);
}

/* The host's depth buffer into dep (made again when its size changes; a 16-byte placeholder
   without one), written blocking: the core's copy may change before the next call. */
static hd_result hd__be_upload_depth(const hd__view *vw)
{
    hd__backend *be = vw->be;
    size_t n = vw->depth ? (size_t)vw->depth_w * vw->depth_h : 0;
    hd_result r;
    if (!vw->depth && vw->depth_device && be->dep) return HD_SUCCESS; /* hd__be_depth_cl_buffer's copy, kept */
    if (!be->dep || n != be->dep_floats) {
        hd__cl_release(&be->dep);
        be->dep_floats = 0;
        if ((r = hd__cl_buffer(vw, &be->dep, n * sizeof(float), NULL, "the depth buffer")) != HD_SUCCESS) return r;
        be->dep_floats = n;
    }
    if (n) HD__CL_TRY(vw, clEnqueueWriteBuffer(be->queue, be->dep, CL_TRUE, 0, n * sizeof(float), vw->depth, 0, NULL, NULL), "clEnqueueWriteBuffer(depth)");
    return HD_SUCCESS;
}

/* The environment's tables into env, made anew (a 16-byte placeholder without them). */
static hd_result hd__be_upload_env(const hd__view *vw)
{
    hd__cl_release(&vw->be->env);
    return hd__cl_buffer(vw, &vw->be->env, vw->env_floats * sizeof(float), vw->env, "the environment's tables");
}

/* The host's cl_mem into dep, on the queue (in order before every later kernel). */
static hd_result hd__be_depth_cl_buffer(const hd__view *vw, void *buffer, size_t offset)
{
    const char *fn = "hd_opencl_set_depth_buffer";
    hd__backend *be = vw->be;
    cl_mem src = (cl_mem)buffer;
    cl_mem_object_type type = 0;
    cl_context c = NULL;
    size_t size = 0, n = (size_t)vw->camera.width * vw->camera.height;
    hd_result r;
    if (clGetMemObjectInfo(src, CL_MEM_TYPE, sizeof type, &type, NULL) != CL_SUCCESS || type != CL_MEM_OBJECT_BUFFER ||
        clGetMemObjectInfo(src, CL_MEM_CONTEXT, sizeof c, &c, NULL) != CL_SUCCESS ||
        clGetMemObjectInfo(src, CL_MEM_SIZE, sizeof size, &size, NULL) != CL_SUCCESS)
        return HD__ERR(&vw->log, HD_ERROR_INVALID_PARAMETER, "%s: not a cl_mem buffer", fn);
    if (c != be->context) return HD__ERR(&vw->log, HD_ERROR_INVALID_PARAMETER, "%s: the buffer belongs to another cl_context", fn);
    if (offset > size || size - offset < n * sizeof(float))
        return HD__ERR(&vw->log, HD_ERROR_BUFFER_TOO_SMALL, "%s: %zu bytes from offset %zu past the buffer's %zu", fn, n * sizeof(float), offset,
                       size);
    if (!be->dep || n != be->dep_floats) {
        hd__cl_release(&be->dep);
        be->dep_floats = 0;
        if ((r = hd__cl_buffer(vw, &be->dep, n * sizeof(float), NULL, "the depth buffer")) != HD_SUCCESS) return r;
        be->dep_floats = n;
    }
    HD__CL_TRY(vw, clEnqueueCopyBuffer(be->queue, src, be->dep, offset, 0, n * sizeof(float), 0, NULL, NULL), "clEnqueueCopyBuffer(depth)");
    return HD_SUCCESS;
}

static hd_result hd__be_wait(const hd__view *vw) { return hd__cl_finish(vw); }

/* Uploads the direct light's list of voxels (rebuilt with sigma_t). */
static hd_result hd__be_direct_list(const hd__view *vw)
{
    hd__cl_release(&vw->be->dl);
    return hd__cl_buffer(vw, &vw->be->dl, vw->dl_count * sizeof(uint32_t), vw->dl_idx, "the direct light's list");
}

/* Work-groups of the direct stage: fixed, so a range of any length (render_budget's pieces) runs
   the kernel PoCL compiled for the first (its own choice follows the global size, and each new
   choice compiled a new variant: about 0.5 s per call on this machine's PoCL 3.1). */
#define HD__CL_DIRECT_LOCAL 64
static hd_result hd__be_direct(const hd__view *vw, size_t first, size_t n)
{
    hd_result r;
    int k = hd__cl_k(vw, HD__CL_DIRECT);
    cl_int count = (cl_int)n, from = (cl_int)first;
    size_t local = HD__CL_DIRECT_LOCAL;
    vw->be->gg.lsum_ok = 0;
    if (n == 0) return HD_SUCCESS;
    HD__CL_ARG(vw, k, 10, count);
    HD__CL_ARG(vw, k, 11, from);
    if ((r = hd__cl_mems(vw, k, 9, 1, vw->be->dl)) != HD_SUCCESS || (r = hd__cl_mems(vw, k, 12, 1, vw->be->env)) != HD_SUCCESS ||
        (r = hd__cl_bind(vw, k)) != HD_SUCCESS ||
        (r = hd__cl_run_local(vw, k, 1, (n + local - 1) / local * local, 1, 1, &local)) != HD_SUCCESS)
        return r;
    return hd__cl_finish(vw);
}

/* One full sweep: two half-sweeps (red, black), or Jacobi's two colour passes and a swap. */
static hd_result hd__be_diffuse(const hd__view *vw, int jacobi)
{
    hd__backend *be = vw->be;
    int k = hd__cl_k(vw, hd__cl_variant(vw, HD__CL_DIFFUSE + (jacobi ? 4 : 0)));
    hd_result r;
    be->gg.lsum_ok = 0;
    if ((r = hd__cl_bind(vw, k)) != HD_SUCCESS || (r = hd__cl_colour_passes(vw, k, vw->gdims, vw->channels, 9, 0, 2)) != HD_SUCCESS)
        return r;
    if (jacobi) { cl_mem t = be->phi; be->phi = be->phi2; be->phi2 = t; }
    return hd__cl_finish(vw);
}

/* The projection's inputs: lsum rebuilt (hd_k_light_sum) after a pass that changed E or phi, and
   the TF table (hd__project_table) built and uploaded when its inputs changed (ptab_key). */
static hd_result hd__cl_project_prepare(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int n = hd__project_table_n(vw), k = hd__cl_k(vw, HD__CL_LIGHT_SUM);
    float *t;
    hd_result r;
    if (!be->gg.lsum_ok) {
        if ((r = hd__cl_mems(vw, k, 9, 1, be->lsum)) != HD_SUCCESS ||
            (r = hd__cl_bind_run(vw, k, 3, (size_t)vw->gdims[0], (size_t)vw->gdims[1],
                                 (size_t)vw->gdims[2] * (size_t)vw->channels)) != HD_SUCCESS)
            return r;
        be->gg.lsum_ok = 1;
    }
    if (hd__project_table_key_same(vw, &be->ptab_key)) return HD_SUCCESS;
    if (!(t = hd__project_table_new(vw, n))) return HD_ERROR_OUT_OF_MEMORY;
    hd__cl_release(&be->ptab);
    be->ptab_key.valid = 0;
    be->ptab_n = 0;
    r = hd__cl_buffer(vw, &be->ptab, (size_t)n * 4 * sizeof(float), t, "the projection's TF table");
    hd__free(vw, t);
    if (r != HD_SUCCESS) return r;
    be->ptab_key = hd__project_table_key(vw);
    be->ptab_n = n;
    return HD_SUCCESS;
}

/* The projection's work-groups: tiles of HD__CL_PROJECT_GROUP_X x HD__CL_PROJECT_GROUP_Y pixels
   (one row of them where the kernel allows fewer items), the global size rounded up to whole
   tiles; the entry skips the items past the image. PoCL hands its threads runs of work-groups;
   with the groups it picks itself (512 x 8 at 512^2: 64 groups) one thread sat idle at the end of
   a frame while the other finished the costlier rows (docs/PERFORMANCE.md); 32 x 8 tiles keep
   the same 8-row locality in 2048 pieces. */
#define HD__CL_PROJECT_GROUP_X 32
#define HD__CL_PROJECT_GROUP_Y 8
/* Kernel k (bound) over the image in those tiles: fewer items per group where the kernel allows
   fewer. */
static hd_result hd__cl_run_tiles(const hd__view *vw, int k)
{
    hd__backend *be = vw->be;
    size_t local[3] = {HD__CL_PROJECT_GROUP_X, HD__CL_PROJECT_GROUP_Y, 1}, wg = 0, gx, gy;
    HD__CL_TRY(vw, clGetKernelWorkGroupInfo(be->kernels[k], be->device, CL_KERNEL_WORK_GROUP_SIZE, sizeof wg, &wg, NULL),
               "clGetKernelWorkGroupInfo");
    if (wg < local[0] * local[1]) {
        local[0] = wg < local[0] ? (wg > 0 ? wg : 1) : local[0];
        local[1] = 1;
    }
    gx = ((size_t)vw->kp.image.x + local[0] - 1) / local[0] * local[0];
    gy = ((size_t)vw->kp.image.y + local[1] - 1) / local[1] * local[1];
    return hd__cl_run_local(vw, k, 2, gx, gy, 1, local);
}

static hd_result hd__be_project(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int k = hd__cl_k(vw, HD__CL_PROJECT);
    cl_int n;
    hd_result r;
    if ((r = hd__cl_project_prepare(vw)) != HD_SUCCESS) return r;
    n = be->ptab_n;
    HD__CL_ARG(vw, k, 11, n);
    if ((r = hd__cl_mems(vw, k, 9, 2, be->lsum, be->ptab)) != HD_SUCCESS || (r = hd__cl_mems(vw, k, 12, 2, be->dep, be->env)) != HD_SUCCESS ||
        (r = hd__cl_bind(vw, k)) != HD_SUCCESS || (r = hd__cl_run_tiles(vw, k)) != HD_SUCCESS)
        return r;
    return hd__cl_finish(vw);
}

#define HD__CL_UPSAMPLE_RUN 16 /* pixels per work-item: HD_CL_UPSAMPLE_RUN in hd_entry_cl.h */
static hd_result hd__be_upsample(const hd__view *vw)
{
    hd_result r;
    size_t runs = ((size_t)vw->kp.image.x + HD__CL_UPSAMPLE_RUN - 1) / HD__CL_UPSAMPLE_RUN;
    if ((r = hd__cl_bind_run(vw, HD__CL_UPSAMPLE, 2, runs, (size_t)vw->kp.image.y, 1)) != HD_SUCCESS) return r;
    return hd__cl_finish(vw);
}

/* No recording and no GL texture: the core never calls these (hd__be_features). */
static unsigned hd__be_features(void) { return HD__BE_CL_BUFFER; }
HD__BE_NO_RECORDING("opencl")
HD__BE_NO_TEXTURE("opencl")

/* ---- read-back ------------------------------------------------------------------------------ */
static hd_result hd__be_read_image(const hd__view *vw, float *dst)
{
    hd__backend *be = vw->be;
    HD__CL_TRY(vw, clEnqueueReadBuffer(be->queue, be->img, CL_TRUE, 0, (size_t)vw->kp.image.x * vw->kp.image.y * 4 * sizeof(float), dst, 0, NULL, NULL),
               "clEnqueueReadBuffer(image)");
    return HD_SUCCESS;
}
static hd_result hd__be_read_depth(const hd__view *vw, float *dst)
{
    hd__backend *be = vw->be;
    HD__CL_TRY(vw, clEnqueueReadBuffer(be->queue, be->img, CL_TRUE, (size_t)vw->kp.region.z * sizeof(float),
                                       (size_t)vw->kp.image.x * vw->kp.image.y * sizeof(float), dst, 0, NULL, NULL),
               "clEnqueueReadBuffer(depth plane)");
    return HD_SUCCESS;
}

/* Maps E or phi (which) for reading or writing; *out is NULL on failure (logged). */
static hd_result hd__cl_map_illumination(const hd__view *vw, hd_illumination which, cl_map_flags flags, void **out)
{
    hd__backend *be = vw->be;
    cl_int e;
    *out = clEnqueueMapBuffer(be->queue, which == HD_ILLUMINATION_DIRECT ? be->E : be->phi, CL_TRUE, flags, 0,
                              hd__cl_slots(vw, (size_t)vw->gdims[2] * vw->channels) * (be->gg.f16 ? 2 : sizeof(float)), 0, NULL, NULL, &e);
    if (e != CL_SUCCESS) { *out = NULL; return hd__cl_fail(vw, e, "clEnqueueMapBuffer(illumination)", 0, __LINE__); }
    return HD_SUCCESS;
}

static hd_result hd__cl_unmap_illumination(const hd__view *vw, hd_illumination which, void *mapped)
{
    hd__backend *be = vw->be;
    HD__CL_TRY(vw, clEnqueueUnmapMemObject(be->queue, which == HD_ILLUMINATION_DIRECT ? be->E : be->phi, mapped, 0, NULL, NULL),
               "clEnqueueUnmapMemObject(illumination)");
    return hd__cl_finish(vw);
}

/* Copies E or phi between the colour layout, mapped, and the API's x-fastest channel-planar
   order, one direction per call: into dst (src NULL; binary16 widened with the CPU's exact
   hdk_h2f) or from src (dst NULL; rounded with the CPU's hdk_f2h). */
static hd_result hd__cl_copy_illumination(const hd__view *vw, hd_illumination which, const float *src, float *dst, const int *list,
                                          int count)
{
    hd__backend *be = vw->be;
    int gx = vw->gdims[0], gy = vw->gdims[1], nz = list ? count : vw->gdims[2] * vw->channels, x, y, k, zz;
    unsigned char *m;
    void *mv;
    hd_result r;
    if ((r = hd__cl_map_illumination(vw, which, src != NULL ? CL_MAP_WRITE : CL_MAP_READ, &mv)) != HD_SUCCESS) return r;
    m = (unsigned char *)mv;
    for (k = 0; k < nz; ++k)
        for (zz = list ? list[k] : k, y = 0; y < gy; ++y)
            for (x = 0; x < gx; ++x) {
                size_t s = hd__cl_slot(vw, x, y, zz);
                if (be->gg.f16) {
                    uint16_t v;
                    if (src != NULL) { v = hdk_f2h(*src++); memcpy(m + 2 * s, &v, 2); }
                    else { memcpy(&v, m + 2 * s, 2); *dst++ = hdk_h2f(v); }
                } else {
                    if (src != NULL) memcpy(m + 4 * s, src++, 4);
                    else memcpy(dst++, m + 4 * s, 4);
                }
            }
    return hd__cl_unmap_illumination(vw, which, mv);
}

static hd_result hd__be_read_illumination(const hd__view *vw, hd_illumination which, const int *zz, int count, float *dst)
{
    return hd__cl_copy_illumination(vw, which, NULL, dst, zz, count);
}

#ifdef HYBRIDDIFF_TESTING
/* The inverse, for the test hooks (src/hd_test_hooks.h). */
HD__MAYBE_UNUSED static hd_result hd__cl_write_illumination(const hd__view *vw, hd_illumination which, const float *src)
{
    vw->be->gg.lsum_ok = 0;
    return hd__cl_copy_illumination(vw, which, src, NULL, NULL, 0);
}
#endif

/* ---- CD: light volumes, convection, their sum into E ----------------------------------------- */
static hd_result hd__be_alloc_lights(const hd__view *vw, int count) { return hd__gpu_alloc_lights(vw, &vw->be->gg, count); }

/* One convection step of light `light`: reads its volume, writes the spare, the two swap. */
static hd_result hd__be_convect(const hd__view *vw, int light)
{
    hd__backend *be = vw->be;
    cl_int l = light;
    cl_mem t;
    hd_result r;
    HD__CL_ARG(vw, HD__CL_CONVECT, 11, l);
    if ((r = hd__cl_mems(vw, HD__CL_CONVECT, 9, 2, be->lv[light], be->lv[be->gg.nlv])) != HD_SUCCESS ||
        (r = hd__cl_bind_run(vw, HD__CL_CONVECT, 3, (size_t)vw->gdims[0], (size_t)vw->gdims[1], (size_t)vw->gdims[2])) != HD_SUCCESS)
        return r;
    t = be->lv[light]; be->lv[light] = be->lv[be->gg.nlv]; be->lv[be->gg.nlv] = t;
    return hd__cl_finish(vw);
}

/* E = sum over the lights of colour * falloff * light volume, the first pass overwriting E. */
static hd_result hd__be_sum_lights(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int k = hd__cl_k(vw, HD__CL_SUM_LIGHT);
    hd_result r;
    int l;
    be->gg.lsum_ok = 0;
    if ((r = hd__cl_bind(vw, k)) != HD_SUCCESS) return r;
    for (l = 0; l < be->gg.nlv; ++l) {
        cl_int li = l, first = l == 0;
        HD__CL_ARG(vw, k, 10, li);
        HD__CL_ARG(vw, k, 11, first);
        if ((r = hd__cl_mems(vw, k, 9, 1, be->lv[l])) != HD_SUCCESS ||
            (r = hd__cl_run(vw, k, 3, (size_t)vw->gdims[0], (size_t)vw->gdims[1], (size_t)vw->gdims[2])) != HD_SUCCESS)
            return r;
    }
    return hd__cl_finish(vw);
}

/* ---- PT_SS / PT_MS ------------------------------------------------------------------------ */
/* One path per pixel, folded into the image with weight march.y. */
static hd_result hd__be_path(const hd__view *vw)
{
    hd_result r = hd__cl_mems(vw, HD__CL_PATH, 9, 3, vw->be->dep, vw->be->lsum, vw->be->env);
    if (r == HD_SUCCESS) r = hd__cl_bind_run(vw, HD__CL_PATH, 2, (size_t)vw->kp.image.x, (size_t)vw->kp.image.y, 1);
    return r != HD_SUCCESS ? r : hd__cl_finish(vw);
}

/* The single-level solver's sweeps: each its own pair of passes. */
static hd_result hd__be_diffuse_sweeps(const hd__view *vw, int jacobi, int sweeps) { return hd__be_diffuse_each(vw, jacobi, sweeps); }

/* ---- HD_SOLVER_MULTIGRID ------------------------------------------------------------------------
   The per-level primitives of src/hd_multigrid.h's step (docs/DESIGN-MULTIGRID.md) on the
   device: the per-voxel math is the shared hd_k_multigrid.h, the V-cycle's
   smoothing the diffusion kernels on each level's own parameter block. Every grid (levels and CG
   vectors) is in the colour layout of its own dims, so those kernels smooth a level unchanged;
   level 0's sigma_t is the backend's. Where the CPU sums in double, so does the device
   (cl_khr_fp64; without it the solver is unsupported, logged); the dot products are summed per
   row on the device (x in order) and the rows in order by the core, as on the CPU: the same
   operations in the same order, so the result has the CPU's bits wherever the kernels do (the
   conformance suite measures it). */

static size_t hd__cl_mg_slots(const int *d, int channels)
{
    return hd__split_slots(d[0], d[1], (size_t)channels * d[2]);
}
/* The restriction's row buffer: a padded fine row per coarse row of level 1, the largest. */
static size_t hd__cl_mg_line_floats(const hd__gpu_grids *g)
{
    return 2 * (((size_t)g->fine[0] + 1) / 2) * (size_t)(g->fine[1] / 2) * (size_t)(g->fine[2] / 2) * (size_t)g->channels;
}

/* Bytes the solver holds on the device (as the CPU's hd__be_solver_bytes: counted in
   method_bytes); 0 without it. Its grids are padded to the colour layout. */
static size_t hd__be_solver_bytes(const hd__view *vw)
{
    const hd__gpu_grids *g = &vw->be->gg;
    size_t b;
    int l, d[3];
    if (!g->levels || vw->params.solver != HD_SOLVER_MULTIGRID) return 0;
    b = 2 * sizeof(double) * hd__gpu_mg_rows(g) + 2 * sizeof(float) * hd__cl_mg_slots(g->fine, g->channels);
    b += sizeof(float) * hd__cl_mg_line_floats(g);
    for (l = 0; l < g->levels; ++l) {
        hd__mg_level_dims(g->fine, l, d);
        b += 3 * sizeof(float) * hd__cl_mg_slots(d, g->channels);
        if (l > 0) b += sizeof(float) * hd__cl_mg_slots(d, g->sig_channels);
    }
    return b;
}

/* The levels' parameter blocks, the row sums (device and host) and the row buffer. */
static hd_result hd__gpu_mg_extras(const hd__view *vw, int make)
{
    hd__backend *be = vw->be;
    struct hd__cl_mg *mg = &be->mg;
    size_t rows = hd__gpu_mg_rows(&be->gg);
    hd_result r = HD_SUCCESS;
    int l;
    for (l = 0; l < be->gg.levels; ++l) {
        hd__cl_level *L = &mg->lv[l];
        hd__cl_release(&L->params);
        if (make && r == HD_SUCCESS) r = hd__cl_buffer(vw, &L->params, sizeof(hd__kparams), NULL, "a multigrid level's parameters");
    }
    hd__cl_release(&mg->dot_a); hd__cl_release(&mg->dot_b); hd__cl_release(&mg->line);
    hd__free(vw, mg->host_dot);
    mg->host_dot = NULL;
    if (!make || r != HD_SUCCESS) return r;
    if (!(mg->host_dot = (double *)hd__calloc(vw, 2 * rows, sizeof(double))))
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "opencl: cannot allocate the dot products' rows");
    if ((r = hd__cl_buffer(vw, &mg->dot_a, rows * sizeof(double), NULL, "multigrid's row sums")) != HD_SUCCESS ||
        (r = hd__cl_buffer(vw, &mg->dot_b, rows * sizeof(double), NULL, "multigrid's row sums")) != HD_SUCCESS)
        return r;
    return hd__cl_buffer(vw, &mg->line, hd__cl_mg_line_floats(&be->gg) * sizeof(float), NULL, "multigrid's row buffer");
}

static hd_result hd__gpu_mg_send(const hd__view *vw, int l, const hd__kparams *kp)
{
    HD__CL_TRY(vw, clEnqueueWriteBuffer(vw->be->queue, vw->be->mg.lv[l].params, CL_TRUE, 0, sizeof *kp, kp, 0, NULL, NULL),
               "clEnqueueWriteBuffer(multigrid level parameters)");
    return HD_SUCCESS;
}

/* n colour passes of kernel k over level l (hd__cl_colour_passes), the parity argument `arg`. */
static hd_result hd__cl_mg_passes(const hd__view *vw, int k, int l, cl_uint arg, int first, int n)
{
    return hd__cl_colour_passes(vw, k, vw->be->gg.lv[l].dims, vw->be->gg.channels, arg, first, n);
}

/* n colour passes of kernel k with level l bound to its nine HD__CL_BUFFERS arguments: sigma_t,
   E = the right-hand side, phi = the correction, phi2 = the residual (written by the residual
   kernels only). */
static hd_result hd__cl_mg_level_passes(const hd__view *vw, int k, int l, int first, int n)
{
    hd__backend *be = vw->be;
    hd__cl_level *L = &be->mg.lv[l];
    hd_result r = hd__cl_mems(vw, k, 0, 9, L->params, be->vol, be->tf, be->maj, l == 0 ? be->sig : L->sig, L->rhs, L->phi, L->res,
                              be->img);
    return r != HD_SUCCESS ? r : hd__cl_mg_passes(vw, k, l, 9, first, n);
}

/* Level l's smoothing: the diffusion kernel on its parameter block. */
static hd_result hd__be_mg_smooth(const hd__view *vw, int l, int sweeps, int first)
{
    return hd__cl_mg_level_passes(vw, hd__cl_variant(vw, HD__CL_DIFFUSE), l, first, 2 * sweeps);
}

static hd__gpu_grids *hd__gpu_grids_of(const hd__view *vw) { return &vw->be->gg; }

/* Pass p on the kernels of hd_entry_cl.h, which take the grids of p's set (backends/hd_gpu.h: m[0..4]
   sigma_t, E, phi, phi2, other) and the parameter blocks each in its own order: the transfers
   and the coarse sigma_t both levels' (slot's and p->level's), the others slot's alone. The
   residuals and the prolongation run as colour passes; the restriction as each fine column's
   share of the coarse rows (both parities, into the row buffer; argument 5 of that kernel is the
   transfers' mask), then their sum per coarse voxel. */
static hd_result hd__gpu_mg_pass(const hd__view *vw, const hd__gpu_mg_run *p)
{
    hd__backend *be = vw->be;
    struct hd__cl_mg *mg = &be->mg;
    const int *d = be->gg.lv[p->level].dims;
    cl_mem m[5], par = p->slot == be->gg.levels ? be->params : mg->lv[p->slot].params, lp = mg->lv[p->level].params;
    cl_int pc0 = p->pc[0], pc1 = p->pc[1];
    hd__gpu_mg_binds b;
    hd_result r = HD_SUCCESS;
    int i, k;
    hd__gpu_mg_set(&be->gg, p->set, &b);
    for (i = 0; i < 5; ++i) m[i] = b.grid[i] < 0 ? NULL : *hd__cl_grid(be, b.grid[i]);
    switch (p->stage) {
    case HD__MG_SIG:
        r = hd__cl_mems(vw, k = HD__CL_MG_SIG, 0, 4, par, lp, m[0], m[4]);
        break;
    case HD__MG_RESIDUAL: /* the smoothing's bindings */
        return hd__cl_mg_level_passes(vw, hd__cl_variant(vw, HD__CL_MG_RESIDUAL), p->level, 0, 2);
    case HD__MG_RESTRICT:
        k = HD__CL_MG_RESTRICT_LINE;
        if ((r = hd__cl_mems(vw, k, 0, 4, par, lp, m[2], mg->line)) != HD_SUCCESS || (r = hd__cl_mems(vw, k, 5, 1, m[0])) != HD_SUCCESS)
            return r;
        for (pc0 = 0; pc0 < 2 && r == HD_SUCCESS; ++pc0) {
            HD__CL_ARG(vw, k, 4, pc0);
            r = hd__cl_run(vw, k, 3, ((size_t)be->gg.lv[p->slot].dims[0] + 1) / 2, (size_t)d[1], (size_t)d[2] * (size_t)be->gg.channels);
        }
        if (r == HD_SUCCESS) r = hd__cl_mems(vw, k = HD__CL_MG_RESTRICT, 0, 5, par, lp, mg->line, m[4], m[3]);
        break;
    case HD__MG_PROLONG:
        if ((r = hd__cl_mems(vw, HD__CL_MG_PROLONG, 0, 4, lp, par, m[2], m[4])) == HD_SUCCESS)
            r = hd__cl_mems(vw, HD__CL_MG_PROLONG, 5, 1, m[0]);
        return r != HD_SUCCESS ? r : hd__cl_mg_passes(vw, HD__CL_MG_PROLONG, p->level, 4, 0, 2);
    case HD__MG_RES_F64:
        k = hd__cl_variant(vw, HD__CL_MG_RES_F64);
        HD__CL_ARG(vw, k, 7, pc0);
        HD__CL_ARG(vw, k, 8, pc1);
        r = hd__cl_mems(vw, k, 0, 6, par, m[0], m[1], m[2], m[3], m[4]);
        return r != HD_SUCCESS ? r : hd__cl_mg_passes(vw, k, 0, 6, 0, 2);
    case HD__MG_DOT:
        r = hd__cl_mems(vw, HD__CL_MG_DOT, 0, 4, par, m[1], m[2], b.dot == 1 ? mg->dot_a : mg->dot_b);
        return r != HD_SUCCESS ? r : hd__cl_run(vw, HD__CL_MG_DOT, 2, (size_t)p->n[0], (size_t)p->n[1], 1);
    case HD__MG_DIR:
        HD__CL_ARG(vw, HD__CL_MG_DIR, 3, p->beta);
        r = hd__cl_mems(vw, k = HD__CL_MG_DIR, 0, 3, par, m[1], m[2]);
        break;
    case HD__MG_UPDATE:
        HD__CL_ARG(vw, HD__CL_MG_UPDATE, 4, p->alpha);
        r = hd__cl_mems(vw, k = HD__CL_MG_UPDATE, 0, 4, par, m[2], m[3], m[1]);
        break;
    default: /* HD__MG_EXTRAP */
        HD__CL_ARG(vw, HD__CL_MG_EXTRAP, 5, pc0);
        r = hd__cl_mems(vw, k = HD__CL_MG_EXTRAP, 0, 5, par, m[0], m[1], m[2], m[3]);
        break;
    }
    return r != HD_SUCCESS ? r : hd__cl_run(vw, k, 3, (size_t)p->n[0], (size_t)p->n[1], (size_t)p->n[2]);
}

/* ---- the step's primitives (src/hd_backend.h) ------------------------------------------------ */
static const char *hd__be_mg_unavailable(const hd__view *vw)
{
    return vw->be->fp64 ? NULL : "the device lacks double precision (cl_khr_fp64)";
}

static hd_result hd__be_mg_begin(const hd__view *vw, int *fresh)
{
    hd_result r;
    if (!vw->be->fp64)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "opencl: solver MULTIGRID needs double precision (cl_khr_fp64), which this device lacks");
    if ((r = hd__gpu_mg_begin(vw, &vw->be->gg, fresh)) != HD_SUCCESS) return r;
    return hd__cl_send_params(vw);
}

static hd_result hd__be_mg_end(const hd__view *vw, hd_result r)
{
    return r != HD_SUCCESS ? r : hd__cl_finish(vw);
}

/* The buffers read (blocking: after every pass enqueued before) into their host copies. */
static hd_result hd__be_mg_row_sums(const hd__view *vw, int n, const double **a, const double **b)
{
    hd__backend *be = vw->be;
    struct hd__cl_mg *mg = &be->mg;
    size_t rows = hd__gpu_mg_rows(&be->gg);
    int i;
    for (i = 0; i < n && i < 2; ++i)
        HD__CL_TRY(vw, clEnqueueReadBuffer(be->queue, i ? mg->dot_b : mg->dot_a, CL_TRUE, 0, rows * sizeof(double),
                                            mg->host_dot + i * rows, 0, NULL, NULL), "clEnqueueReadBuffer(multigrid row sums)");
    *a = mg->host_dot;
    *b = mg->host_dot + rows;
    return HD_SUCCESS;
}
