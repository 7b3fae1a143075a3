/* hybriddiff.h - global illumination for volumes by the hybrid diffusion method.
   MIT or public domain, see the end of the file.

   Do this:
      #define HYBRIDDIFF_IMPLEMENTATION
      #define HYBRIDDIFF_BACKEND_CPU        (or _OPENCL, _VULKAN, _GL)
   before you include this file in *one* C or C++ file to create the implementation.
   Every other file includes it with no macros and sees only the declarations.

   What it does
      Lights a scalar volume (CT, MRI, simulation) seen through a 1D RGBA transfer function with
      physically based global illumination, progressively:
        1. direct light E, per voxel, by Monte Carlo tracking of transmittance toward one randomly
           chosen light per iteration (progressive mean; memory independent of the light count);
        2. multiple scattering phi, by a diffusion solve on the grid, warm-started each iteration;
        3. an emission-absorption ray-marched projection of sigma_s * c * (E + phi) / (4 pi).
      Only stage 3 depends on the camera: moving the camera keeps the converged illumination, and
      hd_render stops all light work once the light has converged (hd_stats.light_converged).

   Quick start (C and C++; docs/INTEGRATION.md has the rest)
      hd_desc desc = HD_DESC_INIT;              // all zero: every default
      desc.volume.type = HD_VOXEL_U8;
      desc.volume.dims[0] = 128; desc.volume.dims[1] = 128; desc.volume.dims[2] = 84;
      desc.volume.data = voxels;                 // copied; may be freed after hd_create
      hd_context ctx;
      if (hd_create(&desc, &ctx) != HD_SUCCESS) { ... }
      while (app_running) {                      // one call per displayed frame
          hd_render(ctx);                        // light work only until it converges
          hd_read_image_rgba8(ctx, pixels, w * h * 4);
      }
      hd_destroy(ctx);

   Configuration macros (define before including the implementation)
      HYBRIDDIFF_BACKEND_CPU     plain C99 reference backend, multi-threaded with pthreads
      HYBRIDDIFF_BACKEND_OPENCL  OpenCL 1.2+ (link -lOpenCL)
      HYBRIDDIFF_BACKEND_VULKAN  Vulkan 1.1+  (link -lvulkan)
      HYBRIDDIFF_BACKEND_GL      OpenGL 4.3+ compute (link -lEGL -lOpenGL)
      HYBRIDDIFF_BACKEND_NULL    computes nothing (images and illumination stay zero): the
                                 public API's checks and schedule alone, for tests, and the
                                 template of a new backend (docs/BACKENDS.md)
      HYBRIDDIFF_STATIC          make every function static (private to one translation unit)
      HYBRIDDIFF_NO_ZLIB         build the file loaders without zlib (gzip-encoded files are then
                                 rejected with HD_ERROR_UNSUPPORTED_ENCODING); otherwise link -lz
      HYBRIDDIFF_FAST_COMPILE    CPU backend: compile the implementation in about half the time
                                 (no per-flag copies of the diffusion's row loops), the same
                                 images, the diffusion 5-10x slower (docs/PERFORMANCE.md)
      HD_MAX_CONTEXTS            live contexts per process (default 64)

   Conventions (docs/METHOD.md has the method)
      - The volume fills a box centred on the origin whose largest side has length 1; the other
        sides follow dims * spacing. Voxel centres sit at (i + 0.5) / n in texture space.
        volume.transform (hd_set_volume_transform) places that box in the world; the camera,
        the lights, the depth buffer and extinction (per unit length) are in world units.
      - sigma_t(x) = TF_alpha(v(x)) * extinction, sigma_s = albedo * sigma_t; v(x) is the trilinear
        interpolation of the normalised voxel values, the TF is sampled after interpolation.
      - One HD iteration = one direct-light sample per voxel + the diffusion sweeps + one frame.
      - Random numbers are a counter-based hash of (voxel or pixel, iteration, dimension, seed),
        so every backend draws the same samples.

   Threading: calls on one context must not overlap; different contexts may be used from
   different threads at the same time. A call that would overlap another on its context (from
   another thread, or from inside the context's own logger) returns HD_ERROR_BUSY.

   Integration (docs/INTEGRATION.md has each rule in full, examples/integrate_* use them)
      - Include order: the implementation compiles under plain -std=c99 or -std=c++17 before or
        after <stdio.h>, <stdlib.h>, <time.h>, <pthread.h>, <unistd.h>, <fcntl.h>,
        <sys/stat.h>, vulkan.h, cl.h or glfw3.h, and leaves no feature macro or
        VK_NO_PROTOTYPES behind.
      - Zero initialisers for C and C++: HD_DESC_INIT, HD_PARAMS_INIT, HD_LIGHT_INIT, ...
      - Volume: x fastest, then y, then z; a box centred on 0 whose largest side is 1;
        value_range maps raw values to TF 0..1 ({0,0}: the type's range); the loaders set it to
        the file's min/max.
      - Your GL context: desc.gl.use_current_context = 1, get_proc_address = glfwGetProcAddress;
        it must be current at every call; the GL state each call touches is restored (program,
        buffer bindings 0..3, image units 0..6, texture unit 0's 2D/3D bindings, pixel store).
        The library's own EGL context cannot be current beside a GLX context on one thread
        (libglvnd): pass yours, or make yours not current around the calls.
      - Your Vulkan device: desc.vulkan.instance/physical_device/device/queue/queue_family and
        get_instance_proc_addr = (hd_proc)vkGetInstanceProcAddr; hd_vulkan_record records into
        your command buffer. Your OpenCL context: desc.opencl.context/device/queue (retained).

   Changelog
      0.1  first release: CPU backend, hybrid diffusion method.
*/
#ifndef HYBRIDDIFF_H
#define HYBRIDDIFF_H

#include <stddef.h>
#include <stdint.h>

#ifdef HYBRIDDIFF_STATIC
/* static, and "maybe unused": a program that calls a few of the functions still builds under
   -Wall -Werror (tests/compile builds it so). */
#if defined(__GNUC__) || defined(__clang__)
#define HDDEF static __attribute__((unused))
#else
#define HDDEF static
#endif
#else
#define HDDEF extern
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- results ------------------------------------------------------------------------------ */
/* Every error has its own code; hd_result_string() names it, the logger says what was wrong. */
#define HD__RESULT_LIST(X) \
    X(HD_SUCCESS, "success") \
    X(HD_ERROR_NULL_POINTER, "a required pointer is NULL") \
    X(HD_ERROR_INVALID_HANDLE, "the context handle is invalid, stale or already destroyed") \
    X(HD_ERROR_INVALID_ENUM, "an enum value is out of range") \
    X(HD_ERROR_INVALID_DIMENSIONS, "volume or image dimensions are zero, negative or too large") \
    X(HD_ERROR_SIZE_OVERFLOW, "a size computed from the dimensions overflows") \
    X(HD_ERROR_INVALID_SPACING, "voxel spacing is negative, zero, NaN or infinite") \
    X(HD_ERROR_INVALID_PARAMETER, "a parameter is NaN, infinite or out of range") \
    X(HD_ERROR_INVALID_TRANSFER_FUNCTION, "the transfer function has too few or invalid entries") \
    X(HD_ERROR_INVALID_CAMERA, "the camera is degenerate") \
    X(HD_ERROR_NO_LIGHTS, "no lights were given") \
    X(HD_ERROR_INVALID_LIGHT, "a light is degenerate or has invalid values") \
    X(HD_ERROR_TOO_MANY_LIGHTS, "more lights than HD_MAX_LIGHTS") \
    X(HD_ERROR_BUFFER_TOO_SMALL, "the destination buffer is too small") \
    X(HD_ERROR_TOO_MANY_CONTEXTS, "HD_MAX_CONTEXTS contexts are alive already") \
    X(HD_ERROR_UNSUPPORTED, "the method or feature is not available on this backend") \
    X(HD_ERROR_OUT_OF_MEMORY, "host memory allocation failed") \
    X(HD_ERROR_OUT_OF_DEVICE_MEMORY, "device memory allocation failed") \
    X(HD_ERROR_DEVICE_LOST, "the compute device was lost") \
    X(HD_ERROR_BACKEND, "the compute API reported an error (see the log)") \
    X(HD_ERROR_FILE_IO, "the file cannot be opened or read") \
    X(HD_ERROR_FILE_FORMAT, "the file header is malformed") \
    X(HD_ERROR_FILE_TRUNCATED, "the file is shorter than its header claims") \
    X(HD_ERROR_UNSUPPORTED_ENCODING, "the file's encoding or voxel type is not supported") \
    X(HD_ERROR_GZIP, "the gzip stream is corrupt or truncated") \
    X(HD_ERROR_FILE_NOT_REGULAR, "the path is a directory, device, FIFO or socket, not a file") \
    X(HD_ERROR_FILE_OUTSIDE_FOLDER, "a detached data file lies outside the header's folder") \
    X(HD_ERROR_FILE_TOO_LARGE, "the volume is larger than the loader's max_bytes") \
    X(HD_ERROR_GL_CONTEXT_NOT_CURRENT, "GL backend: the caller's context (use_current_context) is not current") \
    X(HD_ERROR_INVALID_TEXTURE, "GL backend: the texture is not a 2D texture (hd_gl_render_to_texture: not GL_RGBA8 of the camera's size)") \
    X(HD_ERROR_INVALID_TRANSFORM, "the volume transform is non-finite, singular, not affine or out of range") \
    X(HD_ERROR_TRANSFORM_SHEAR, "the volume transform shears (its columns are not orthogonal): the grid cannot follow it") \
    X(HD_ERROR_DEPTH_SIZE, "the depth buffer's size is not the camera's") \
    X(HD_ERROR_INVALID_DEPTH, "a depth value is NaN, infinite or outside [0, 1]") \
    X(HD_ERROR_DEPTH_NEEDS_PROJECTION, "depth needs a camera given by its projection matrix") \
    X(HD_ERROR_NO_FRAME, "the image holds no frame yet: render one first") \
    X(HD_ERROR_VOLUME_MISMATCH, "the update's voxel type or dims differ from the context's volume") \
    X(HD_ERROR_BOX_OUTSIDE_VOLUME, "the update's box is empty or reaches outside the volume") \
    X(HD_ERROR_INVALID_VOXELS, "a voxel value of the update is NaN or infinite") \
    X(HD_ERROR_OUTPUT_OUTSIDE_TARGET, "the output region does not lie inside the target") \
    X(HD_ERROR_OUTPUT_SIZE, "the output region's size is not the camera's (the image is written 1:1)") \
    X(HD_ERROR_OUTPUT_FORMAT, "the target's format does not take the output format") \
    X(HD_ERROR_BUSY, "another call on this context is in progress (calls on one context must not overlap)") \
    X(HD_ERROR_INVALID_ENVIRONMENT, "an environment map texel, rotation or intensity is invalid") \
    X(HD_ERROR_DEPTH_FORMAT, "the depth texture's internal format is not a depth format")

typedef enum hd_result {
#define HD__X(name, text) name,
    HD__RESULT_LIST(HD__X)
#undef HD__X
    HD_RESULT_COUNT
} hd_result;

/* ---- enums: zero always means "default" -------------------------------------------------- */
typedef enum hd_method {
    HD_METHOD_DEFAULT = 0, /* = HD_METHOD_HD */
    HD_METHOD_HD,          /* hybrid diffusion: tracked direct light + diffusion + projection */
    HD_METHOD_CD,          /* convection-diffusion baseline (one light volume per light) */
    HD_METHOD_PT_SS,       /* camera path tracing, single scattering */
    HD_METHOD_PT_MS,       /* camera path tracing, multiple scattering */
    HD_METHOD_COUNT
} hd_method;

typedef enum hd_voxel_type {
    HD_VOXEL_INVALID = 0, /* the type must be given */
    HD_VOXEL_U8,
    HD_VOXEL_U16,
    HD_VOXEL_F32,
    HD_VOXEL_I16, /* signed 16-bit (a CT in Hounsfield units) */
    HD_VOXEL_COUNT
} hd_voxel_type;

typedef enum hd_light_type {
    HD_LIGHT_DIRECTIONAL = 0,
    HD_LIGHT_POINT,
    HD_LIGHT_QUAD,   /* area lights (hd_light): a parallelogram, a disk, a sphere */
    HD_LIGHT_DISK,
    HD_LIGHT_SPHERE,
    HD_LIGHT_TYPE_COUNT
} hd_light_type;

typedef enum hd_tracking {
    HD_TRACKING_DEFAULT = 0, /* = RATIO */
    HD_TRACKING_RATIO,       /* ratio tracking with Russian roulette: lower variance */
    HD_TRACKING_DELTA,       /* delta (Woodcock) tracking: a 0/1 estimate per sample */
    HD_TRACKING_COUNT
} hd_tracking;

typedef enum hd_solver {
    HD_SOLVER_DEFAULT = 0,   /* = AUTO */
    HD_SOLVER_AUTO = HD_SOLVER_DEFAULT, /* RED_BLACK for an illumination grid below 4 M voxels
                                (the volume's voxels / illumination_downsample^3; 32 M volume voxels
                                at the default 2), MULTIGRID from there: it converges in about the
                                same iterations at any size (docs/PERFORMANCE.md, "Scale").
                                hd_create and hd_set_params put the choice into params.solver
                                (hd_get_params reads it) and fill diffusion_sweeps for it.
                                RED_BLACK with float16 illumination, and for good where multigrid
                                cannot run (a device without double precision, hd_vulkan_record):
                                one info line saying why, no error */
    HD_SOLVER_RED_BLACK,     /* red-black Gauss-Seidel, in place: two half-sweeps per sweep */
    HD_SOLVER_JACOBI,        /* Jacobi with a ping-pong buffer (+4 bytes per voxel) */
    HD_SOLVER_MULTIGRID,     /* conjugate gradients preconditioned by a geometric multigrid
                                V-cycle (red-black smoothing on every level); diffusion_sweeps
                                counts CG steps (one V-cycle and two residual passes each);
                                +about 22 bytes per voxel and channel. Every backend; OpenCL
                                and Vulkan need double precision (cl_khr_fp64, shaderFloat64:
                                a caller's Vulkan device must have enabled it), else
                                HD_ERROR_UNSUPPORTED at hd_create (after hd_set_params: at the
                                next step) */
    HD_SOLVER_COUNT
} hd_solver;

typedef enum hd_boundary {
    HD_BOUNDARY_DEFAULT = 0, /* = SURFACE */
    HD_BOUNDARY_BOX,         /* phi = 0 outside the volume box (docs/METHOD.md, the paper's) */
    HD_BOUNDARY_SURFACE,     /* Marshak vacuum condition at the medium's surface */
    HD_BOUNDARY_COUNT
} hd_boundary;

/* What hd_render does for HD and CD once the view rests (the light has converged and the image
   holds its frame_window frames; params.rest). */
typedef enum hd_rest {
    HD_REST_DEFAULT = 0, /* = HOLD */
    HD_REST_HOLD,        /* nothing: HD's image stays as it is */
    HD_REST_REFINE,      /* every call adds paths per pixel that start at the camera and end into
                            HD's converged light at vertex params.refine_bounces: the image moves
                            from HD's frame toward the path-traced solution (docs/DESIGN-REFINE.md) */
    HD_REST_BLEND,       /* every call adds PT_MS paths per pixel into a mean of their own, kept
                            apart from HD's frame; the image is a per-pixel blend of the two weighted
                            by the paths' variance and HD's bias estimated over a tile that shrinks
                            as the paths grow: it tends to PT_MS's (docs/DESIGN-REFINE.md) */
    HD_REST_COUNT
} hd_rest;

typedef enum hd_precision {
    HD_PRECISION_FLOAT32 = 0, /* 4 bytes per voxel and channel (default) */
    HD_PRECISION_FLOAT16,     /* IEEE binary16 storage, float32 arithmetic: half the bytes */
    HD_PRECISION_COUNT
} hd_precision;

/* Named settings of hd_params (hd_params_preset). */
typedef enum hd_preset {
    HD_PRESET_DEFAULT = 0, /* the library's defaults: the fields below set to 0 (filled in by
                              hd_create and hd_set_params) */
    HD_PRESET_PAPER,       /* the paper's settings (docs/METHOD.md): illumination grid at the
                              data's resolution (illumination_downsample 1), phi = 0 outside the
                              box (HD_BOUNDARY_BOX), 4 red-black sweeps per iteration */
    HD_PRESET_COUNT
} hd_preset;

typedef enum hd_log_level { HD_LOG_ERROR = 0, HD_LOG_WARNING, HD_LOG_INFO } hd_log_level;

typedef enum hd_illumination {
    HD_ILLUMINATION_DIRECT = 0, /* E: direct light, progressive mean */
    HD_ILLUMINATION_SCATTERED,  /* phi: fluence of scattered light from the diffusion solve */
    HD_ILLUMINATION_TOTAL,      /* E + phi, summed in float per voxel and channel: what the
                                   projection samples (docs/INTEGRATION.md, "Light out") */
    HD_ILLUMINATION_COUNT
} hd_illumination;

/* ---- zero initialisers ------------------------------------------------------------------------ */
/* Every struct of this header is valid zeroed ("default" everywhere). `= {0}` is not C++ for a
   struct whose first member is an enum, and `= {}` is not C99: these work in both.
      hd_desc desc = HD_DESC_INIT;   hd_params p = HD_PARAMS_INIT;   hd_light l = HD_LIGHT_INIT; */
#ifdef __cplusplus
#define HD_ZERO_INIT {}
#else
#define HD_ZERO_INIT {0}
#endif
#define HD_DESC_INIT HD_ZERO_INIT
#define HD_PARAMS_INIT HD_ZERO_INIT
#define HD_LIGHT_INIT HD_ZERO_INIT
#define HD_CAMERA_INIT HD_ZERO_INIT
#define HD_LOAD_OPTIONS_INIT HD_ZERO_INIT
#define HD_DEPTH_DESC_INIT HD_ZERO_INIT
#define HD_VOLUME_UPDATE_INIT HD_ZERO_INIT
#define HD_ENVIRONMENT_INIT HD_ZERO_INIT

/* ---- callbacks ------------------------------------------------------------------------------ */
/* Silent unless a logger is given. hd_log_stderr is a ready one. */
typedef void (*hd_log_fn)(void *user_data, hd_log_level level, hd_result code, const char *message,
                          const char *file, int line);
typedef struct hd_logger {
    hd_log_fn func;
    void *user_data;
} hd_logger;

/* A function pointer of any type: loaders (glfwGetProcAddress, eglGetProcAddress) return it, and
   any function pointer converts to it and back by a cast, which ISO C and C++ allow. */
typedef void (*hd_proc)(void);

/* All or none: giving one of alloc/free without the other is HD_ERROR_NULL_POINTER. */
typedef struct hd_allocator {
    void *(*alloc)(size_t size, void *user_data);
    void (*free)(void *ptr, void *user_data);
    void *user_data;
} hd_allocator;

/* ---- inputs ---------------------------------------------------------------------------------- */
#define HD_MAX_LIGHTS 64
#define HD_MAX_DIM 8192           /* per axis */
#define HD_MAX_IMAGE_DIM 16384
/* Finite limits that keep every intermediate value finite and every loop short (hd_create and
   the setters reject beyond them; README "Guarantees"):
   - the volume's extent (dims * spacing) over its smallest spacing, per axis pair, is at most
     HD_MAX_SPACING_RATIO, so a voxel spans enough float steps of the box for the march;
   - the sum over the lights of intensity * max(colour) is at most HD_MAX_LIGHT_POWER;
   - point-light positions and camera eye/target components (a matrix camera's ray origins) are
     at most HD_MAX_LIGHT_DISTANCE world units and HD_MAX_CAMERA_DISTANCE times the volume's
     largest world side in magnitude, measured from the volume's centre along its own axes
     (volume.transform; with the default transform the world's, and the largest side is 1). */
/* Loop bounds, the same on every backend (backends/kernels/hd_k_common.h): one transmittance or
   free-flight walk ends after 2^16 collisions and majorant cells with transmittance 0 (reached
   only with an extinction or majorant above about 3.8e4 per world unit); one projection ray after 2^24 samples (a valid one needs at most
   1.13e7); a path after max_bounces vertices. Float16 illumination (illumination_precision)
   saturates at 65504, the largest half. */
#define HD_MAX_SPACING_RATIO 65536.0f
#define HD_MAX_LIGHT_POWER 1e6f
#define HD_MAX_LIGHT_DISTANCE 1e15f
#define HD_MAX_CAMERA_DISTANCE 1e4f

typedef struct hd_volume_desc {
    hd_voxel_type type;   /* required */
    int dims[3];          /* x, y, z; x varies fastest in data. Each in 1..HD_MAX_DIM */
    float spacing[3];     /* physical voxel size; {0,0,0} -> {1,1,1}; must be finite and > 0,
                             each >= the largest extent (dims * spacing) / HD_MAX_SPACING_RATIO */
    const void *data;     /* dims[0]*dims[1]*dims[2] voxels; copied by hd_create */
    float value_range[2]; /* raw value mapped to TF coordinate 0 and 1; {0,0} -> {0,255} for U8,
                             {0,65535} for U16, {-32768,32767} for I16, {0,1} for F32. Values
                             outside are clamped. Every backend keeps U8, U16 and I16 voxels as
                             they are (1 or 2 bytes each) and maps them in its kernels. */
    float transform[16];  /* volume to world, a 4x4 affine matrix, column-major (element row r,
                             column c at [c * 4 + r]), applied to the box above (centred at 0,
                             largest side 1); all zero: the identity (the box as it is). Per-axis
                             scale, rotation, reflection and translation: its first three columns
                             must be orthogonal (a shear cannot be followed by the axis-aligned
                             illumination grid: HD_ERROR_TRANSFORM_SHEAR), each of length in
                             [1e-6, 1e6], translation within +-HD_MAX_LIGHT_DISTANCE, last row
                             (0, 0, 0, 1) (else HD_ERROR_INVALID_TRANSFORM). Lengths in world
                             units follow it: extinction is per world unit, 1/r^2 in world units.
                             hd_set_volume_transform changes it. */
} hd_volume_desc;

/* RGBA entries placed at TF coordinates i/(count-1), linearly interpolated.
   rgb is the scattering colour (0..1), alpha scales the extinction (0..1). */
typedef struct hd_transfer_function {
    const float *rgba; /* count * 4 floats; copied */
    int count;         /* >= 2; a desc with rgba == NULL and count == 0 gets a linear grey ramp */
} hd_transfer_function;

typedef struct hd_light {
    hd_light_type type;
    float direction[3]; /* DIRECTIONAL: the direction the light travels in (need not be unit;
                           any nonzero finite vector); DISK: its normal */
    float position[3];  /* POINT: position in world space (QUAD: a corner, DISK, SPHERE: the
                           centre; the volume box is centred at 0
                           unless volume.transform moves it),
                           components within +-HD_MAX_LIGHT_DISTANCE */
    float color[3];     /* linear RGB, >= 0; {0,0,0} -> {1,1,1} */
    float intensity;    /* >= 0; 0 -> 1. Over all lights, sum of intensity * max(color) <=
                           HD_MAX_LIGHT_POWER */
    int inverse_square; /* POINT: 1 = intensity / r^2 falloff (r in world units), 0 = none */
    float edge1[3];     /* QUAD: the two edges from the corner at position (world units, within */
    float edge2[3];     /*   +-HD_MAX_LIGHT_DISTANCE, nonzero, not parallel) */
    float radius;       /* DISK, SPHERE: radius in world units, in (0, HD_MAX_LIGHT_DISTANCE] */
} hd_light;
/* Area lights. QUAD: the parallelogram position + u edge1 + v edge2, u, v in [0, 1]; it emits on
   the side of edge1 x edge2 only. DISK: centre position, normal direction (the side it emits
   on, one-sided as the quad), radius. SPHERE: centre position, radius; it emits outward, so a
   point inside it gets none of its light. Units: intensity * colour is the emitted radiance,
   the same from every point of the surface in every direction it emits in (not the power: a
   light twice the area gives twice the light); a small quad of area A far away at distance r
   gives the irradiance intensity * A * cos / r^2, as a point light of intensity * A with
   inverse_square. The direct light samples a quad and a disk uniformly over the area, a sphere
   uniformly over the cone it subtends; the path tracers reach them by next-event estimation
   only: a scattered or camera ray does not see them. Method CD cannot hold them
   (HD_ERROR_UNSUPPORTED). Degenerate ones (zero or parallel edges, zero normal, radius <= 0,
   NaN or infinite values) are HD_ERROR_INVALID_LIGHT. */

/* An environment: light arriving from every direction at infinity, given as an equirectangular
   (latitude-longitude) map of linear RGB radiance. Set by its own call (hd_set_environment), not
   as a hd_light type: the map is a large image copied once and turned into sampling tables
   once, where hd_set_lights is cheap enough to call every frame, and a context holds at most
   one. Map texel (i, j), row j from the top, is the radiance arriving from the map direction
   theta = pi (j + 0.5) / height from +y (the top row looks up), phi = 2 pi (i + 0.5) / width,
   dir = (sin theta cos phi, cos theta, sin theta sin phi): the left edge looks along +x, a
   quarter of the width along +z, the centre along -x. */
typedef struct hd_environment {
    int width, height;   /* 1..HD_MAX_ENVIRONMENT_DIM each */
    const float *rgb;    /* width * height * 3 floats, rows top first, each finite and >= 0; copied */
    float rotation[9];   /* map to world directions, row-major 3x3 (world = R * map): a rotation
                            (orthonormal within 1e-3, determinant +1); all zero: the identity */
    float intensity;     /* >= 0; 0 -> 1. intensity * the largest texel component counts toward
                            HD_MAX_LIGHT_POWER with the lights */
} hd_environment;
#define HD_MAX_ENVIRONMENT_DIM 8192

/* How a projection's NDC z maps to the depth buffer's values (hd_set_depth) and which end is
   near: the convention the host renders its scene with. */
typedef enum hd_depth_range {
    HD_DEPTH_NEG_ONE_TO_ONE = 0, /* GL's default: NDC z in [-1, 1], near at -1; depth = (z + 1) / 2 */
    HD_DEPTH_ZERO_TO_ONE,        /* D3D, Vulkan, Metal (GL with glClipControl): NDC z = depth in
                                    [0, 1], near at 0 */
    HD_DEPTH_REVERSED,           /* zero-to-one with near at 1 and far at 0 (reversed-Z; an
                                    infinite far plane is allowed) */
    HD_DEPTH_RANGE_COUNT
} hd_depth_range;

/* A look-at camera (eye, target, up, fov_y), or the host's own matrices: when projection is not
   all zero, view and projection define the camera and eye, target, up and fov_y are ignored.
   Matrices are column-major (element row r, column c at [c * 4 + r]), the GL convention
   (clip = projection * view * world, a column vector on the right): view maps world to eye
   space (all zero: identity), projection eye to clip space. A perspective projection has the
   last row (0, 0, a, 0), a != 0 (any frustum: off-centre, jittered, left- or right-handed, an
   infinite far plane), an orthographic one (0, 0, 0, b), b != 0; view's last row is
   (0, 0, 0, 1). Anything else, a non-finite or singular projection * view: HD_ERROR_INVALID_CAMERA.
   Pixel (px, py) of the image (top row first) sees the ray through NDC
   x = 2 (px + 0.5) / width - 1, y = 1 - 2 (py + 0.5) / height (jittered within the pixel), from
   the eye (perspective; medium between the eye and the near plane is drawn as with the look-at
   camera) or from the near plane (orthographic). */
typedef struct hd_camera {
    float eye[3];    /* {0,0,0} together with target {0,0,0} -> eye {0,0,2.5}; eye and target
                        components within +-HD_MAX_CAMERA_DISTANCE */
    float target[3]; /* looked-at point */
    float up[3];     /* {0,0,0} -> {0,1,0}; must not be parallel to target - eye */
    float fov_y;     /* vertical field of view in degrees, 0 -> 40; must be in (0, 180) */
    int width;       /* image size, 0 -> 512 */
    int height;      /* 0 -> 512 */
    float view[16];       /* world -> eye, column-major; all zero: identity (with a projection) */
    float projection[16]; /* eye -> clip, column-major; all zero: the look-at camera above */
    hd_depth_range depth_range; /* the projection's NDC z convention (hd_set_depth) */
} hd_camera;

/* The host's depth buffer (hd_set_depth): width x height floats, rows top first (the image's
   order; a GL depth buffer read with glReadPixels is bottom first), each the window depth in
   [0, 1] the host's projection wrote under camera.depth_range (1, or 0 when reversed: nothing
   there). */
typedef struct hd_depth_desc {
    const float *data; /* NULL: no depth */
    int width, height; /* the camera's */
} hd_depth_desc;

typedef struct hd_params {
    hd_method method;
    float extinction;       /* sigma_t = TF alpha * extinction, per world unit; 0 -> 100 */
    float albedo;           /* sigma_s / sigma_t in (0, 1]; 0 -> 0.9 */
    float anisotropy;       /* Henyey-Greenstein g in (-1, 1): reduces the diffusion's sigma_s
                               to sigma_s (1 - g); used by PT_MS as its phase; default 0 */
    float majorant;         /* 0 -> a coarse grid of local majorants (empty space is skipped);
                               > 0 -> this global majorant: >= max sigma_t, <= 16 max sigma_t
                               (and <= max(16, 1e6)); a TF that breaks that drops it (grid) */
    int diffusion_sweeps;   /* solver sweeps per iteration, 0 -> 4 (multigrid: CG steps, 0 -> 1) */
    int disable_diffusion;  /* 1: phi stays 0 (direct light only, the PT_SS equivalent) */
    hd_solver solver;
    hd_tracking tracking;
    uint32_t seed;
    float background[3];    /* linear RGB radiance behind the volume, default black; each
                               component in [0, 1e6] */
    float step;             /* ray-march step of the projection in voxels, 0 -> 0.5 */
    int frame_window;       /* the image is a running mean of at most this many frames, so it
                               follows the converging illumination; 0 -> 8 */
    float exposure;         /* scale applied before the sRGB encoding of RGBA8 output; 0 -> 1 */
    int max_bounces;        /* PT_MS bounce cap, 0 -> 64; 1..100000 */
    int illumination_downsample; /* E and phi (and sigma_t for the diffusion) live on a grid of
                               the volume's dims divided by this factor per axis, rounded up,
                               sampled trilinearly by the projection: 1..8, 0 -> 2 (1/8 of the
                               voxels to track and solve: 3-4x the iterations per second and
                               closer to PT_MS than 1 in the first iterations; a small volume run
                               to convergence can gain from 1, the paper's: docs/EVALUATION.md,
                               "Defaults"). Direct light is still tracked through the
                               full-resolution volume. */
    int rgb_scattering;     /* 1: multiple scattering per colour channel: the diffusion uses
                               sigma_s,c = albedo * TF colour_c * sigma_t, so light that scatters
                               deep takes the colour shift PT_MS shows (3 channels of E and phi and
                               a colour grid: +28 bytes per voxel). 0 (default): grey diffusion,
                               tinted once at projection, as in the paper. */
    hd_boundary diffusion_boundary; /* where the diffusion's vacuum is: HD_BOUNDARY_SURFACE
                               (default: the medium's surface carries the Marshak vacuum
                               condition; empty voxels are not solved for and hold the Marshak
                               extrapolation of their medium neighbours' phi, which the
                               projection interpolates toward; closer to PT_MS, see
                               docs/EVALUATION.md, "Defaults") or HD_BOUNDARY_BOX (the paper's,
                               docs/METHOD.md: phi = 0 outside the volume box, empty voxels
                               solved with a floored D, so air drains light) */
    hd_precision illumination_precision; /* storage of E and phi (and Jacobi's buffer):
                               HD_PRECISION_FLOAT16 stores them as IEEE binary16, rounded to
                               nearest even, while every operation stays float32: 2 bytes per
                               voxel and channel instead of 4 (see docs/EVALUATION.md for the
                               PSNR cost). Every backend (Vulkan/GL: r16f images, where the
                               device lacks them HD_ERROR_UNSUPPORTED at the next render); the
                               multigrid solver returns HD_ERROR_UNSUPPORTED. hd_read_illumination
                               still returns floats. The projection's summed copy of E + phi
                               (one grid per channel, counted in method_bytes) stays float32. */
    float light_tolerance;  /* hd_render stops refining the light once hd_stats.light_error, the
                               estimated relative error of E + phi, is below this for two light
                               iterations in a row: 0 -> 0.1 (head CT: 10-20 iterations, the
                               image within about 43 dB of one with 8x as many: the projection
                               averages many voxels; docs/DESIGN-RENDER.md); finite and >= 0 */
    float render_budget;    /* seconds one hd_render call may take, light work and frame together,
                               counted from the call's start: 0 -> one whole light iteration per
                               call, then the frame. HD, CD: the call predicts its frame's time
                               (the frame cost model of HD_RENDER_SCALE_AUTO; half the budget
                               before a frame is measured) and fills the rest, less a tenth for
                               its own overhead, with pieces of light iterations: the direct light
                               over part of its voxel list, then some diffusion sweeps, each
                               sized from the measured cost of the last ones; an iteration split
                               so over calls gives the light of a whole one (the convergence
                               estimate follows complete iterations; hd_stats.light_progress says
                               how far the one in progress is). Each call runs at least one piece
                               (about 1/256 of the list, or one sweep), so the light always
                               advances, and a volume update's upload and reclassification are
                               not split. PT_SS, PT_MS: paths while the next fits. In [0, 10] */
    float crop_min[3];      /* the crop box's low corner in box coordinates: 0 at the volume's
                               low face, 1 at its high face, per axis x, y, z; default 0 */
    float crop_max[3];      /* its high corner, 0 -> 1 per axis, so zeroed params crop nothing.
                               Matter outside [crop_min, crop_max] is absent for every method
                               and stage: it casts no shadow, scatters nothing and is not
                               drawn. Per axis 0 <= min < max <= 1, finite */
    int render_scale;       /* projection frames at 1/s of the camera's resolution per axis: s = 1..16
                               marches ceil(width / s) x ceil(height / s) rays and fills the full
                               image by a bilinear upsample on the device (the image read back stays
                               width x height); 0 -> 1. HD_RENDER_SCALE_AUTO: each new image (camera
                               move, setter, reset) starts at a reduced scale, then every further
                               frame doubles the resolution up to full frames, which then
                               accumulate as usual (a moving camera gets cheap frames, a still one
                               converges to the full image). The first scale is the smallest power
                               of two whose predicted frame time (a + b * pixels, fitted to the
                               frames this context has measured at each scale) fits the frame's
                               share of render_budget (all of it once the light has converged,
                               half before), 16 if none does, or 4 while render_budget is 0 or
                               nothing is measured; under a budget the resolution doubles only
                               while the finer frame's predicted time fits that share.
                               A change of scale restarts the running mean. The first frame at a
                               scale > 1 adds a quarter of the image's memory for the reduced
                               frames (hd_stats.image_bytes); where that fails, the call returns
                               HD_ERROR_OUT_OF_MEMORY / _OUT_OF_DEVICE_MEMORY and full frames still
                               work. The path tracers ignore it. Else HD_ERROR_INVALID_PARAMETER */
    int light_window;       /* a change that keeps E and phi as the warm start of the new light
                               (hd_update_volume, and the setters' "warm" changes listed above
                               hd_set_transfer_function) re-weights the direct light's running
                               mean so it holds at most this many samples' worth of the light
                               before the change: the next samples weigh 1/(w + 1), 1/(w + 2), ...
                               and the old light fades as the new one's samples come in. Smaller
                               follows a changing volume with less lag and more noise. 0 -> 8;
                               1..1000000 */
    hd_rest rest;           /* HD and CD, once the view rests: HD_REST_HOLD (default) keeps HD's
                               image; HD_REST_REFINE refines it toward PT_MS with paths that read
                               HD's light, as many per call as render_budget allows (at least
                               one); HD_REST_BLEND blends PT_MS paths' mean with HD's frame (the
                               image buffer then holds 3 more RGBA planes). The first call after
                               any change (camera, setter) still shows HD's frame, as with HOLD.
                               hd_stats.refine_paths counts the paths */
    int refine_bounces;     /* HD_REST_REFINE: the vertex at which a refinement path ends into HD's
                               light ((E + phi) / 4 pi there); the vertices before it track toward
                               the lights and scatter as PT_MS's do. 0 -> -1: never, the paths are
                               PT_MS's and the image tends to PT_MS's (unbiased); K in 1..100000
                               (2: a final gather) converges faster to an image that keeps part of
                               HD's bias (on the head CT 2 and 3 lose to -1 from 1 s on:
                               docs/DESIGN-REFINE.md). HD_REST_BLEND's paths are always PT_MS's */
    float depth_threshold;  /* the volume's depth (hd_read_depth) is where a camera ray's
                               accumulated opacity 1 - T first reaches this: 0 -> 0.5; (0, 1]
                               (1: where the march stops, T below 1e-4) */
    int environment_background; /* 1: camera rays that leave the volume (HD's and CD's projection,
                               the path tracers' primary rays) see the environment (hd_set_environment)
                               behind it: T times its radiance in the ray's direction (rotated and
                               scaled by intensity, as its light), added to params.background.
                               The output is premultiplied: such a pixel's alpha is 1, not
                               1 - T, so a host compositing the volume over its own scene
                               leaves this 0 (default). No effect without an environment (nor
                               where hd_set_depth's geometry is); 0 or 1 */
} hd_params;

#define HD_RENDER_SCALE_AUTO (-1) /* hd_params.render_scale: coarse frames first at each new image */

typedef struct hd_desc {
    hd_volume_desc volume;
    hd_transfer_function transfer_function;
    const hd_light *lights; /* NULL with light_count 0 -> one white directional light along -z */
    int light_count;
    hd_camera camera;
    hd_params params;
    int threads;            /* CPU backend worker threads, 0 -> all cores; results do not
                               depend on it */
    hd_logger logger;
    hd_allocator allocator;
    /* Backend-specific, ignored by the others; void* so this header needs no API header. */
    struct {
        void *context, *device, *queue; /* cl_context, cl_device_id, cl_command_queue or NULL */
        const char *device_name;        /* substring of the device to pick (or env HD_CL_DEVICE) */
    } opencl;
    struct {
        void *instance, *physical_device, *device, *queue; /* VkInstance... or NULL: the
                                           backend's own device, on one VkInstance it keeps for
                                           the process (drivers limit instance re-creation) */
        uint32_t queue_family;
        hd_proc get_instance_proc_addr; /* (hd_proc)vkGetInstanceProcAddr (or volk's), NULL for
                                           the loader's */
        const char *device_name;      /* substring (or env HD_VK_DEVICE) */
        int enable_validation;
    } vulkan;
    struct {
        int use_current_context; /* 1: use the caller's current GL context; it must be current
                                    at every later call that reaches GL (iterate, read, render,
                                    destroy), else HD_ERROR_GL_CONTEXT_NOT_CURRENT (the one current
                                    at hd_create, where EGL or GLX can tell) */
        hd_proc (*get_proc_address)(const char *name); /* glfwGetProcAddress (no cast),
                                                      eglGetProcAddress; NULL -> eglGetProcAddress */
    } gl;
} hd_desc;

/* New voxels for the whole volume or a box of it (hd_update_volume). */
typedef struct hd_volume_update {
    hd_voxel_type type;  /* must be the context's volume type */
    int dims[3];         /* must be the context's volume dims */
    int offset[3];       /* the box's first voxel (x, y, z) */
    int size[3];         /* the box's voxels per axis, each >= 1 and inside the volume;
                            {0,0,0} with offset {0,0,0}: the whole volume */
    const void *data;    /* the box's voxels, x fastest, mapped to TF coordinates by the
                            context's value_range (hd_create's) */
    size_t row_pitch;    /* bytes from a row of the box to the next; 0: size[0] voxels. To update
                            a box of a whole volume in memory: data = its first voxel, row_pitch =
                            dims[0] voxels, slice_pitch = dims[0] * dims[1] voxels */
    size_t slice_pitch;  /* bytes from a z slice of the box to the next; 0: row_pitch * size[1] */
} hd_volume_update;

/* ---- outputs --------------------------------------------------------------------------------- */
typedef struct hd_stats {
    hd_method method;
    uint64_t iterations;      /* iterations of the current method since its state was reset
                                 (complete ones: see light_progress) */
    uint64_t frames;          /* frames accumulated into the current image */
    size_t method_bytes;      /* bytes of per-voxel state the method holds on the device
                                 (illumination grids, the projection's summed light E + phi, the
                                 direct light's voxel list once the first light work after a
                                 change has made it, helpers; volume and image excluded) */
    size_t image_bytes;       /* bytes of the image accumulation */
    size_t volume_bytes;      /* bytes of the volume, the TF and the majorant grid on the device */
    int illumination_dims[3]; /* grid of the illumination volumes */
    int illumination_channels;/* 1 (grey) or 3 (lights of different colours) */
    double seconds_direct;    /* accumulated wall time per stage since creation */
    double seconds_diffusion;
    double seconds_projection;
    /* Light convergence (HD and CD; 0 for the path tracers). After each light iteration the
       change of E and phi on the medium's voxels gives an estimate of their relative RMS error:
       sqrt(n) |E_n - E_n-1| for E's Monte Carlo mean, |phi_n - phi_n-1| q / (1 - q) for the
       solver (q: the change's observed contraction, at most 0.9), over |E_n + phi_n|; 1 before
       two iterations. */
    double light_error;
    int light_converged;      /* light_error < params.light_tolerance twice in a row */
    int render_scale;         /* the divisor of the current image's frames (params.render_scale);
                                 1 for full-resolution frames and for the path tracers */
    uint64_t refine_paths;    /* paths per pixel a resting view's refinement (HD_REST_REFINE, BLEND) has
                                 added to the current image; 0 while it shows HD's frames */
    double light_progress;    /* HD, CD: the part done of a light iteration that render_budget has
                                 split over hd_render calls, in [0, 1): the direct stage is the
                                 first half, the diffusion sweeps the second; 0 between iterations */
} hd_stats;

typedef struct hd_context {
    uint32_t id; /* 0 is never valid */
} hd_context;

/* ---- API --------------------------------------------------------------------------------------- */
HDDEF const char *hd_result_string(hd_result result);
HDDEF const char *hd_method_name(hd_method method);
HDDEF const char *hd_backend_name(void);
HDDEF void hd_log_stderr(void *user_data, hd_log_level level, hd_result code, const char *message,
                         const char *file, int line);

/* Sets the fields of *params that a preset names (illumination_downsample, diffusion_boundary,
   solver, diffusion_sweeps) and leaves the others as they are:
      hd_params p = HD_PARAMS_INIT;  hd_params_preset(HD_PRESET_PAPER, &p, NULL);  desc.params = p;
   HD_ERROR_NULL_POINTER or HD_ERROR_INVALID_ENUM (logged to log, which may be NULL). */
HDDEF hd_result hd_params_preset(hd_preset preset, hd_params *params, const hd_logger *log);

/* A handle is never valid twice: each of the HD_MAX_CONTEXTS slots serves 2^24 - 1 contexts,
   then is retired, so a process may create HD_MAX_CONTEXTS * (2^24 - 1) contexts in all (over
   10^9 by default) before hd_create returns HD_ERROR_TOO_MANY_CONTEXTS. After hd_destroy the
   context's logger is never called again: a call with the stale handle returns
   HD_ERROR_INVALID_HANDLE and logs nothing. */
HDDEF hd_result hd_create(const hd_desc *desc, hd_context *out_ctx);
HDDEF hd_result hd_destroy(hd_context ctx);
/* The desc with every default filled in (lights and TF pointers refer to the context's copies,
   valid until the next call on this context). */
HDDEF hd_result hd_query_desc(hd_context ctx, hd_desc *out_desc);

/* Setters invalidate only what depends on them. "warm": E and phi are kept as the warm start of
   the new light (the diffusion converges from any start; E's running mean is re-weighted to hold
   at most params.light_window samples of the old light), the convergence estimate restarts
   (hd_stats.light_converged is 0 until the new light converges); "reset": zeroed. hd_reset gives
   the clean restart after a warm change.
     TF alpha, extinction                      -> majorant grid; E, phi warm; image
     TF colour only (the same alphas)          -> image only with grey scattering (no light work);
                                                  phi warm with rgb_scattering
     the same TF                               -> nothing
     lights                                    -> E, phi warm; image (CD, another light count:
                                                  reset)
     albedo, anisotropy                        -> phi warm (E stays valid); image
     majorant                                  -> majorant grid, E, phi reset, image
     seed                                      -> E, phi reset, image
     disable_diffusion, diffusion_boundary     -> phi reset, image
     hd_update_volume                          -> the box's majorant cells; E, phi warm; image
     volume transform                          -> E, phi reset, image
     camera, depth, step, background,
     frame_window, rest, refine_bounces        -> image only (E and phi are kept)
     method                                    -> the new method starts from scratch
     illumination_downsample, rgb_scattering,
     illumination_precision                    -> E, phi, image (new grids)
     max_bounces                               -> the path tracers' image (nothing for HD, CD)
     solver, sweeps, tracking, exposure,
     light_tolerance, render_budget,
     light_window                              -> nothing (same solution, estimator or encoding)
   src/hd_params.h holds this as a table, the one place each field's default, range and
   invalidation are written. An out-of-range enum is HD_ERROR_INVALID_ENUM, any other bad value
   HD_ERROR_INVALID_PARAMETER, each with one logged line; a rejected call changes nothing. */
HDDEF hd_result hd_set_transfer_function(hd_context ctx, const hd_transfer_function *tf);
HDDEF hd_result hd_set_lights(hd_context ctx, const hd_light *lights, int count);
HDDEF hd_result hd_set_camera(hd_context ctx, const hd_camera *camera);
HDDEF hd_result hd_set_params(hd_context ctx, const hd_params *params);

/* The volume-to-world transform (hd_volume_desc.transform; NULL: the identity), checked as there.
   Invalidates E, phi and the image (the lights' directions change in the volume's frame). The
   current camera and lights must stay within their limits under it (HD_ERROR_INVALID_CAMERA,
   HD_ERROR_INVALID_LIGHT), else nothing changes. */
HDDEF hd_result hd_set_volume_transform(hd_context ctx, const float transform[16]);

/* The host scene's depth (hd_depth_desc; NULL or data NULL: none), copied at the call and used
   by every later frame until replaced or cleared: each camera ray (and each path's first free
   flight) ends where it meets the scene's surface, so what stands in front of the volume hides
   it and what stands inside cuts it; where there is geometry (a value other than the far
   plane's) the background is not added. The depth belongs to a matrix camera's projection
   (camera.projection, HD_ERROR_DEPTH_NEEDS_PROJECTION otherwise) and its size: a camera set
   with another width or height, or a look-at camera, drops it (logged). A reduced frame
   (params.render_scale) reads each ray's nearest full-resolution pixel. Errors:
   HD_ERROR_DEPTH_SIZE (width x height not the camera's), HD_ERROR_NULL_POINTER (NULL data with
   a nonzero size), HD_ERROR_INVALID_DEPTH (a NaN, infinite or out-of-[0, 1] value); each logs
   one line and changes nothing. Invalidates the image only (the light is kept). */
HDDEF hd_result hd_set_depth(hd_context ctx, const hd_depth_desc *depth);

/* The environment light (hd_environment; NULL: none), copied; with it the scene's lights are
   the hd_set_lights list plus the environment, and hd_set_lights may then give count 0 (the
   environment alone). Each HD iteration samples, per voxel, one of them uniformly; the
   environment's direction is drawn from a piecewise-constant distribution over the map
   (texel radiance times sin theta, built once here, 16 bytes of tables and radiance per map
   texel on the device), the transmittance tracked to the box's edge, the sample weighted by
   radiance over pdf. PT_SS and PT_MS sample it by next-event estimation, and PT_MS's scattered
   paths that leave the box see it, the two combined by multiple importance sampling (balance
   heuristic). params.environment_background shows it behind the volume to the camera's rays.
   HD_METHOD_CD, one light volume per light, cannot hold it (HD_ERROR_UNSUPPORTED,
   also from hd_set_params choosing CD while one is set). Errors, each with one logged line and
   nothing changed: HD_ERROR_INVALID_DIMENSIONS (a size outside 1..HD_MAX_ENVIRONMENT_DIM),
   HD_ERROR_NULL_POINTER (rgb NULL), HD_ERROR_INVALID_ENVIRONMENT (a NaN, infinite or negative
   texel, a rotation that is not one, a NaN, infinite or negative intensity),
   HD_ERROR_INVALID_LIGHT (the power above HD_MAX_LIGHT_POWER), HD_ERROR_NO_LIGHTS (clearing the
   environment while the light list is empty), HD_ERROR_OUT_OF_MEMORY. Invalidates E and phi
   (warm start, as hd_set_lights) and the image. */
HDDEF hd_result hd_set_environment(hd_context ctx, const hd_environment *env);

/* New voxels for the whole volume or a box of it, same type and dims, without a new context (an
   animated or simulated volume, a time series). The core's copy, the majorant grid and the
   direct light's mask change for the box's cells only, the backend uploads the box alone, and
   the light continues from where it was: E and phi are the warm start of the new solution and
   the direct light's running mean is re-weighted (params.light_window); the light's convergence
   estimate restarts (hd_stats.light_converged is 0 until the new light converges); the image
   restarts (the path tracers restart their means). Voxels equal to those held change nothing.
   The device work runs at the next call that reaches the device (hd_render, hd_iterate, ...).
   Errors, each with one log line, leave the context as it was: a NULL update or data
   HD_ERROR_NULL_POINTER; another type or other dims HD_ERROR_VOLUME_MISMATCH; a box not inside
   the volume (or empty) HD_ERROR_BOX_OUTSIDE_VOLUME; a pitch below the box's row or slice
   HD_ERROR_INVALID_PARAMETER; a NaN or infinite F32 voxel HD_ERROR_INVALID_VOXELS. */
HDDEF hd_result hd_update_volume(hd_context ctx, const hd_volume_update *update);

/* A clean restart of the light and the image: E, phi (CD's light volumes) and the image start
   from zero at the next call, as in a new context, instead of from the warm start a change
   keeps. */
HDDEF hd_result hd_reset(hd_context ctx);

/* Runs n >= 1 iterations of the current method, each refining the light (HD, CD) and projecting
   one frame; it refines even light that has converged (hd_stats.light_converged). */
HDDEF hd_result hd_iterate(hd_context ctx, int n);

/* n >= 1 light iterations (HD: direct light and diffusion; CD: convection and diffusion) with no
   projection: the image is left as it was. For a single view, refine until
   hd_stats.light_converged, then project with hd_render. A light iteration that render_budget
   split over hd_render calls is finished first, as the first of the n (so is hd_iterate's).
   The path tracers have no light to refine: HD_ERROR_UNSUPPORTED. */
HDDEF hd_result hd_refine(hd_context ctx, int n);

/* One frame for a per-frame loop: call it once per displayed frame.
     HD, CD: while the light has not converged, one light iteration (under
             params.render_budget: the pieces of light iterations that fit it), then one
             projection frame from the current E
             and phi into the image's running mean. Once the light has converged, no light work:
             the projection alone, and when the frame_window frames since the convergence are in
             the image (it is done), nothing at all until a setter invalidates something; with
             params.rest HD_REST_REFINE or HD_REST_BLEND, refinement passes toward PT_MS instead
             (one, or as many as render_budget allows), until the next change.
     PT_SS, PT_MS: one path iteration (or as many as render_budget allows).
   A camera move (hd_set_camera) keeps converged light: the next call projects at once. For a
   frame budget below one projection's time, params.render_scale projects at reduced resolution
   (HD_RENDER_SCALE_AUTO: coarse frames at each new view, full ones once the camera rests); the
   image read back keeps the camera's size.

      for (;;) {                              // the application's frame loop
          if (camera_moved) hd_set_camera(ctx, &cam);
          hd_render(ctx);                     // cheap once hd_stats.light_converged
          hd_read_image_rgba8(ctx, px, n);    // or hd_gl_render_to_texture
      }
*/
HDDEF hd_result hd_render(hd_context ctx);

/* The image, top row first. RGBA8: sRGB-encoded radiance * exposure, alpha = opacity.
   Float: linear RGB radiance and opacity. Sizes are in bytes / in floats. While the image holds
   no frame (after hd_create, a change of the camera's size, or a change that restarts the image,
   before the next hd_render or hd_iterate) both return HD_ERROR_NO_FRAME and leave dst as it was. */
HDDEF hd_result hd_read_image_rgba8(hd_context ctx, uint8_t *dst, size_t dst_bytes);
HDDEF hd_result hd_read_image_f32(hd_context ctx, float *dst, size_t dst_floats);
/* An illumination volume, channel-planar: channel c of voxel (x,y,z) at
   ((c * dz + z) * dy + y) * dx + x, with the dims and channels of hd_stats. Voxel (x, y, z)'s
   centre is the volume's box coordinate ((x + 0.5) / dx, ...) (0 and 1 at the box's faces, as
   params.crop_min), where the projection samples it trilinearly, clamped at the faces: a 3D
   texture's texel centres with GL_LINEAR and CLAMP_TO_EDGE. The PT methods keep none:
   HD_ERROR_UNSUPPORTED. */
HDDEF hd_result hd_read_illumination(hd_context ctx, hd_illumination which, float *dst,
                                     size_t dst_floats);
/* The volume's depth for the host's later passes (HD, CD; a matrix camera): width x height
   floats, rows top first (hd_set_depth's order), each the window depth under camera.depth_range
   of the nearest point where a ray of the pixel's accumulated opacity reached
   params.depth_threshold, over the frames in the image since it last restarted (full-resolution
   frames only: a reduced frame, params.render_scale, adds none); the far plane's value (1, or 0
   reversed) where none did. The crossing is the first march sample at or past the threshold
   (within one params.step of it), placed on the ray through the pixel's centre. Where the
   host's depth (hd_set_depth) ends the rays first there is none. Errors, one log line each:
   HD_ERROR_NULL_POINTER, HD_ERROR_BUFFER_TOO_SMALL, HD_ERROR_DEPTH_NEEDS_PROJECTION (a look-at
   camera), HD_ERROR_UNSUPPORTED (PT_SS, PT_MS), HD_ERROR_NO_FRAME (as the image's). */
HDDEF hd_result hd_read_depth(hd_context ctx, float *dst, size_t dst_floats);
HDDEF hd_result hd_get_stats(hd_context ctx, hd_stats *out_stats);

/* ---- output into the renderer's target ------------------------------------------------------
   What the image is (docs/INTEGRATION.md, "Compositing"): emission-absorption radiance along
   each ray, PREMULTIPLIED by its opacity, and alpha = 1 - the ray's transmittance through the
   volume. Composite it over the host's scene with blend ONE, ONE_MINUS_SRC_ALPHA (colour and
   alpha), in linear space: dst = src + (1 - src.a) dst. params.background is radiance added
   behind the volume (times the transmittance, alpha unchanged): leave it 0 when compositing,
   or the host's scene is covered by it. Exposure scales rgb (not alpha) of every format; no
   tone mapping is applied: a host in linear HDR tone-maps after compositing.
     HD_OUTPUT_SRGB8        RGBA8, 4 bytes a pixel: rgb sRGB-encoded (clamped to [0, 1]),
                            alpha linear, as hd_read_image_rgba8. Premultiplied in linear
                            space before the encoding: a host that samples it through an sRGB
                            format (GL_SRGB8_ALPHA8, VK_FORMAT_R8G8B8A8_SRGB) gets linear
                            premultiplied values back and blends them correctly in linear space
                            (GL_FRAMEBUFFER_SRGB); through a UNORM format it gets the encoded
                            values, display-ready, whose blend in sRGB space is an approximation.
     HD_OUTPUT_LINEAR_F16   RGBA binary16, 8 bytes a pixel: linear, rounded to nearest even
                            (hdk_f2h: above 65504 inf), unclamped.
     HD_OUTPUT_LINEAR_F32   RGBA float, 16 bytes a pixel: linear, unclamped (hd_read_image_f32
                            times exposure). */
typedef enum hd_output_format {
    HD_OUTPUT_SRGB8 = 0,
    HD_OUTPUT_LINEAR_F16,
    HD_OUTPUT_LINEAR_F32,
    HD_OUTPUT_FORMAT_COUNT
} hd_output_format;

/* Where in the target the image goes: the region of width x height pixels whose first pixel is
   (x, y) of the target; the library writes its image there 1:1 (no scaling) and nothing
   outside it. Zeroed (HD_OUTPUT_INIT, or a NULL pointer): RGBA8 at (0, 0), the camera's size.
   width and height: 0 -> the camera's; otherwise they must be the camera's
   (HD_ERROR_OUTPUT_SIZE). A region that does not lie inside the target, or a negative x or y,
   is HD_ERROR_OUTPUT_OUTSIDE_TARGET; a target whose format does not take `format`,
   HD_ERROR_OUTPUT_FORMAT; each with one logged line, and the context keeps working. */
typedef struct hd_output {
    hd_output_format format;
    int x, y;          /* the region's first pixel in the target (see each call for the rows) */
    int width, height; /* 0 -> the camera's; else it must equal it */
} hd_output;
#define HD_OUTPUT_INIT HD_ZERO_INIT

/* The image in `format` into a caller's memory, every backend: the region (output->x, y) of a
   target of rows row_pitch bytes apart (0 -> (x + width) * the pixel's bytes), top row first.
   The target must hold the region: a row of (x + width) pixels wider than row_pitch is
   HD_ERROR_OUTPUT_OUTSIDE_TARGET; fewer than (y + height - 1) * row_pitch + (x + width) *
   pixel bytes in dst_bytes, HD_ERROR_BUFFER_TOO_SMALL; before any frame, HD_ERROR_NO_FRAME (as
   the other read-backs). Bytes outside the region are not touched. dst needs no alignment. */
HDDEF hd_result hd_read_image_ex(hd_context ctx, const hd_output *output, void *dst, size_t dst_bytes,
                                 size_t row_pitch);

/* Vulkan backend only (the others return HD_ERROR_UNSUPPORTED): records n iterations of the
   current method into the caller's VkCommandBuffer (passed as void*, in the recording state,
   from a pool of desc.vulkan.queue_family) instead of submitting them, as hd_iterate runs them
   (light refined even once converged); hd_iterate submits and waits itself. Changed inputs are
   uploaded first (submitted and waited for). The caller submits the command buffer and waits
   for it before the next call on this context. The light's convergence (hd_stats.light_error,
   light_converged) of recorded iterations is measured by the next call that reaches the device,
   once they have run (hence that wait). HD_RENDER_SCALE_AUTO times recorded frames on the
   device (timestamps read by the next call). HD_SOLVER_MULTIGRID (with HD or CD diffusing)
   cannot be recorded: each step reads its dot products back on the host; HD_ERROR_UNSUPPORTED. */
HDDEF hd_result hd_vulkan_record(hd_context ctx, void *command_buffer, int n);

/* The caller's Vulkan target of hd_vulkan_record_render: an image or a buffer (one of them).
   Handles as uint64_t, which holds a VkImage / VkBuffer on 32- and 64-bit platforms alike:
   target.image = (uint64_t)image. The library cannot query a handle: format, extent and size
   are as the caller made them (wrong ones are the validation layer's to report).
   Image: a 2D color image, mip level 0 and array layer 0 written, made with
   VK_IMAGE_USAGE_TRANSFER_DST_BIT and owned by desc.vulkan.queue_family. Its format: for
   HD_OUTPUT_SRGB8 VK_FORMAT_R8G8B8A8_UNORM or _SRGB, or B8G8R8A8_UNORM or _SRGB (the same
   sRGB-encoded bytes; B and R swapped for BGRA); for LINEAR_F16 R16G16B16A16_SFLOAT; for
   LINEAR_F32 R32G32B32A32_SFLOAT. Rows top first (Vulkan's y down): the image's top row goes
   to row output->y.
   Barriers (the library records them; the caller records none around the call): the image must
   be in `layout` when the command buffer reaches the write; the library's barrier takes it from
   `layout` (after every earlier command: source stage ALL_COMMANDS, access MEMORY_READ |
   MEMORY_WRITE) to TRANSFER_DST_OPTIMAL, copies the region in (vkCmdCopyBufferToImage), and
   takes it to `final_layout` (before every later command: destination stage ALL_COMMANDS,
   access MEMORY_READ | MEMORY_WRITE). layout UNDEFINED discards the image's contents (pixels
   outside the region then undefined); final_layout 0 (UNDEFINED) -> `layout`, which must then
   not be UNDEFINED or PREINITIALIZED. Buffer: the same bytes as hd_read_image_ex, rows top
   first, `offset` bytes from the buffer's start to the target's first pixel, rows row_pitch
   apart (0 -> width * pixel bytes), width x height pixels; buffer_size the buffer's size
   (required: the rows must lie inside it), made with VK_BUFFER_USAGE_TRANSFER_DST_BIT; the
   same ALL_COMMANDS buffer barriers before and after the copies (vkCmdCopyBuffer). */
typedef struct hd_vulkan_target {
    uint64_t image;          /* VkImage, or 0 with a buffer */
    int format;              /* the image's VkFormat */
    int layout;              /* the VkImageLayout it is in before the write */
    int final_layout;        /* the VkImageLayout it is left in; 0 -> layout */
    int width, height;       /* the target's size in pixels (the image's extent) */
    uint64_t buffer;         /* VkBuffer, or 0 with an image */
    uint64_t offset;         /* buffer: bytes to the target's first pixel */
    uint64_t row_pitch;      /* buffer: bytes from a row to the next, 0 -> width * pixel bytes */
    uint64_t buffer_size;    /* buffer: its size in bytes */
} hd_vulkan_target;
#define HD_VULKAN_TARGET_INIT HD_ZERO_INIT

/* Vulkan backend only (the others return HD_ERROR_UNSUPPORTED): what hd_render does, recorded
   into the caller's command buffer (as hd_vulkan_record's), one call per displayed frame, then
   with target non-NULL the image written into the caller's image or buffer (output: NULL -> all
   zero) by the library's compute pass and a transfer, after the frame:
     HD, CD: while the light has not converged, one light iteration (its convergence measured by
             the next call, once the caller has run this one), then one projection frame; once
             it has converged, the projection frame alone (no light work), and once the
             frame_window frames since are in, no frame: only the write.
     PT_SS, PT_MS: one path iteration.
   So hd_stats.light_converged reaches 1 under recording as under hd_render, and frames over
   converged light cost the projection (and the write) alone. The same rules as
   hd_vulkan_record: submit and wait before the next call; MULTIGRID is refused. The target's
   checks (format, layouts, region, pitch) come before anything is recorded: on an error nothing
   is recorded and the command buffer is as it was. */
HDDEF hd_result hd_vulkan_record_render(hd_context ctx, void *command_buffer, const hd_vulkan_target *target,
                                        const hd_output *output);

/* The host's depth on the device for hd_vulkan_record_depth: an image or a buffer (one of them),
   the camera's size (the library cannot query it: the validation layer reports a wrong one).
   Image: a 2D depth image, VK_FORMAT_D32_SFLOAT or D32_SFLOAT_S8_UINT (its depth aspect), mip 0
   layer 0, made with VK_IMAGE_USAGE_TRANSFER_SRC_BIT, owned by desc.vulkan.queue_family, in
   `layout` when the command buffer reaches the copy (GENERAL, TRANSFER_SRC_OPTIMAL,
   SHADER_READ_ONLY_OPTIMAL or a depth attachment or read-only layout) and left in it. Rows top
   first (Vulkan's y down, as hd_set_depth's). Buffer: width x height floats, rows top first,
   `offset` bytes from its start, inside buffer_size, made with VK_BUFFER_USAGE_TRANSFER_SRC_BIT.
   Barriers (the library records them): source stage ALL_COMMANDS, access MEMORY_READ |
   MEMORY_WRITE before the copy (and the image's transition to TRANSFER_SRC_OPTIMAL), its
   transition back and an ALL_COMMANDS barrier after. */
typedef struct hd_vulkan_depth {
    uint64_t image;       /* VkImage, or 0 with a buffer */
    int format;           /* the image's VkFormat */
    int layout;           /* the VkImageLayout it is in at the copy, and is left in */
    uint64_t buffer;      /* VkBuffer, or 0 with an image */
    uint64_t offset;      /* buffer: bytes to the first value (a multiple of 4) */
    uint64_t buffer_size; /* buffer: its size in bytes */
} hd_vulkan_depth;
#define HD_VULKAN_DEPTH_INIT HD_ZERO_INIT

/* Vulkan backend only (the others return HD_ERROR_UNSUPPORTED): hd_set_depth from the host's
   depth image or buffer, recorded into the caller's command buffer (in the recording state, as
   hd_vulkan_record's): a copy into the library's depth buffer, with no CPU round trip, which the
   frames recorded after it (hd_vulkan_record_render in the same command buffer, or any later
   call once it has run) read: the same image as hd_set_depth of the same values, with its
   lifetime (replaced by either call, cleared by hd_set_depth(NULL), dropped with the camera's
   size). Submit and wait before the next call, as for hd_vulkan_record. Errors, one log line
   each, nothing recorded and the depth held before kept: HD_ERROR_NULL_POINTER (command buffer,
   depth), HD_ERROR_INVALID_PARAMETER (not one of image and buffer, a layout, an offset),
   HD_ERROR_DEPTH_FORMAT, HD_ERROR_BUFFER_TOO_SMALL (the values past buffer_size),
   HD_ERROR_DEPTH_NEEDS_PROJECTION (a look-at camera). */
HDDEF hd_result hd_vulkan_record_depth(hd_context ctx, void *command_buffer, const hd_vulkan_depth *depth);

/* The caller's Vulkan target of hd_vulkan_record_illumination: a 3D image or a buffer (one of
   them), handles as uint64_t (as hd_vulkan_target's); the library cannot query them.
   Image: a 3D image of VK_FORMAT_R32_SFLOAT, mip level 0, at least hd_stats.illumination_dims
   large (width, height, depth: its extent), made with VK_IMAGE_USAGE_TRANSFER_DST_BIT and owned
   by desc.vulkan.queue_family. Texels (0, 0, 0) .. illumination_dims - 1 are written (x, y, z as
   hd_read_illumination's), the others kept. Barriers (the library records them; the caller
   records none around the call): the image must be in `layout` (GENERAL, TRANSFER_SRC_OPTIMAL,
   TRANSFER_DST_OPTIMAL, SHADER_READ_ONLY_OPTIMAL; UNDEFINED discards its contents) when the
   command buffer reaches the copy; the library takes it from `layout` (after every earlier
   command: source stage ALL_COMMANDS, access MEMORY_READ | MEMORY_WRITE) to
   TRANSFER_DST_OPTIMAL, copies the grid in (vkCmdCopyImage) and takes it to `final_layout`
   (before every later command: destination stage ALL_COMMANDS, access MEMORY_READ |
   MEMORY_WRITE); final_layout 0 -> `layout`, which must then not be UNDEFINED. A shader that
   samples it asks for SHADER_READ_ONLY_OPTIMAL. Buffer: the channel's floats as
   hd_read_illumination lays out one channel (x fastest, then y, then z), `offset` bytes (a
   multiple of 4) from the buffer's start, inside buffer_size, made with
   VK_BUFFER_USAGE_TRANSFER_DST_BIT; the same ALL_COMMANDS barriers around the copy
   (vkCmdCopyImageToBuffer). */
typedef struct hd_vulkan_volume_target {
    uint64_t image;          /* VkImage, or 0 with a buffer */
    int format;              /* the image's VkFormat: VK_FORMAT_R32_SFLOAT */
    int layout;              /* the VkImageLayout it is in before the copy */
    int final_layout;        /* the VkImageLayout it is left in; 0 -> layout */
    int width, height, depth; /* the image's extent in texels */
    uint64_t buffer;         /* VkBuffer, or 0 with an image */
    uint64_t offset;         /* buffer: bytes to the first float (a multiple of 4) */
    uint64_t buffer_size;    /* buffer: its size in bytes */
} hd_vulkan_volume_target;
#define HD_VULKAN_VOLUME_TARGET_INIT HD_ZERO_INIT

/* Vulkan backend only (the others return HD_ERROR_UNSUPPORTED): hd_gl_illumination_texture's
   counterpart. Channel `channel` (0 .. hd_stats.illumination_channels - 1) of
   HD_ILLUMINATION_TOTAL (E + phi, as the projection samples it: bit for bit
   hd_read_illumination's) copied on the device into the caller's 3D image or buffer, recorded
   into the caller's command buffer (in the recording state, as hd_vulkan_record's), with no CPU
   round trip. The light copied is the light the calls before it leave: after
   hd_vulkan_record_refine or hd_vulkan_record_render in the same command buffer, the light they
   recorded (the library's barriers order the copy after them; this call measures nothing, so
   their convergence is still measured by the next other call, once the caller has run them);
   otherwise the light of the work the caller has run (submit and wait, as for hd_vulkan_record).
   Where a pass changed E or phi since and nothing recorded their sum, it is made first on the
   library's queue (submitted and waited for). In one frame's command buffer, before
   hd_vulkan_record_render it copies the light the frame's iteration then refines, after it the
   refined light. Errors, one log line each, nothing recorded:
   HD_ERROR_NULL_POINTER (command buffer, target), HD_ERROR_INVALID_PARAMETER (not one of image
   and buffer, the channel, the offset), HD_ERROR_OUTPUT_FORMAT (not R32_SFLOAT),
   HD_ERROR_INVALID_ENUM (a layout), HD_ERROR_OUTPUT_OUTSIDE_TARGET (an image smaller than the
   grid), HD_ERROR_BUFFER_TOO_SMALL (the floats past buffer_size), HD_ERROR_UNSUPPORTED (PT_SS,
   PT_MS keep no light volume). */
HDDEF hd_result hd_vulkan_record_illumination(hd_context ctx, void *command_buffer, int channel,
                                              const hd_vulkan_volume_target *target);

/* Vulkan backend only (the others return HD_ERROR_UNSUPPORTED): hd_refine recorded into the
   caller's command buffer (in the recording state, as hd_vulkan_record's): n >= 1 light
   iterations (HD: direct light and diffusion; CD: convection and diffusion) and no projection,
   the image left as it was, then E + phi summed on the device (the light the projection samples
   and hd_vulkan_record_illumination copies). The light alone, for a host that lights its own
   particles and meshes by the volume's light on frames that do not draw the volume: this call,
   then hd_vulkan_record_illumination in the same command buffer, which copies the refined light.
   Like hd_refine it refines converged light too (test hd_stats.light_converged to stop); the
   iterations' convergence is measured by the next call other than hd_vulkan_record_illumination,
   once the caller has run them. The rules of hd_vulkan_record: submit and wait before the next
   call, hd_vulkan_record_illumination excepted (it may follow in the same command buffer, as
   hd_vulkan_record_depth and hd_vulkan_record_illumination may precede it); MULTIGRID is
   refused. Errors, one log line each, nothing recorded:
   HD_ERROR_NULL_POINTER (command buffer), HD_ERROR_INVALID_PARAMETER (n < 1, past 2^31
   iterations), HD_ERROR_UNSUPPORTED (PT_SS, PT_MS have no light volume; MULTIGRID). */
HDDEF hd_result hd_vulkan_record_refine(hd_context ctx, void *command_buffer, int n);

/* GL backend only (the others return HD_ERROR_UNSUPPORTED): writes the image, sRGB-encoded as
   hd_read_image_rgba8, into the caller's GL_RGBA8 2D texture `texture` (a GLuint; its size must
   be the camera's: else HD_ERROR_INVALID_TEXTURE) with no CPU round trip; rows bottom first,
   GL's order. The context must be current (desc.gl.use_current_context) or share objects with
   the backend's. */
HDDEF hd_result hd_gl_render_to_texture(hd_context ctx, unsigned int texture);
/* The same into a region of a 2D texture of any size (level 0), in `output->format`: the
   texture's internal format must be GL_RGBA8 or GL_SRGB8_ALPHA8 for HD_OUTPUT_SRGB8 (the same
   sRGB-encoded bytes: an sRGB texture samples as linear premultiplied values), GL_RGBA16F for
   LINEAR_F16, GL_RGBA32F for LINEAR_F32 (checked with glGetTexLevelParameteriv). Rows bottom
   first: the image's bottom row goes to texel row output->y, x to column output->x; texels
   outside the region are not touched. A compute pass encodes the image into a buffer and
   glTexSubImage2D copies it in from there (a pixel unpack buffer), so the bytes are exactly
   hd_read_image_ex's. Not a 2D texture: HD_ERROR_INVALID_TEXTURE. */
HDDEF hd_result hd_gl_render_to_texture_ex(hd_context ctx, unsigned int texture, const hd_output *output);
/* GL backend only (the others return HD_ERROR_UNSUPPORTED): channel `channel` (0 .. hd_stats.
   illumination_channels - 1) of HD_ILLUMINATION_TOTAL (E + phi, as the projection samples it)
   copied on the device (glCopyImageSubData) into texels (0, 0, 0) .. illumination_dims - 1 of
   level 0 of the caller's GL_TEXTURE_3D `texture`, internal format GL_R32F, at least
   illumination_dims large (texels beyond are not touched); x, y, z as hd_read_illumination's.
   Errors, one log line each: HD_ERROR_INVALID_TEXTURE (0, or not a 3D texture),
   HD_ERROR_OUTPUT_FORMAT (not GL_R32F), HD_ERROR_OUTPUT_OUTSIDE_TARGET (smaller than the grid),
   HD_ERROR_INVALID_PARAMETER (channel), HD_ERROR_UNSUPPORTED (PT_SS, PT_MS). */
HDDEF hd_result hd_gl_illumination_texture(hd_context ctx, unsigned int texture, int channel);
/* GL backend only (the others return HD_ERROR_UNSUPPORTED): hd_set_depth from the host's depth
   texture, with no CPU round trip: level 0 of the 2D texture `texture` (internal format
   GL_DEPTH_COMPONENT16, 24, 32F, GL_DEPTH24_STENCIL8 or GL_DEPTH32F_STENCIL8, the camera's size;
   GL's rows, bottom first) is copied on the device at the call into the backend's depth buffer
   and used as hd_set_depth's values (the same image as hd_set_depth of the same values, rows
   top first), with its lifetime (replaced by either call, cleared by hd_set_depth(NULL),
   dropped with the camera's size). Errors, one log line each, the depth held before kept:
   HD_ERROR_INVALID_TEXTURE (0, not a 2D texture), HD_ERROR_DEPTH_FORMAT, HD_ERROR_DEPTH_SIZE,
   HD_ERROR_DEPTH_NEEDS_PROJECTION (a look-at camera). */
HDDEF hd_result hd_gl_set_depth_texture(hd_context ctx, unsigned int texture);
/* OpenCL backend only (the others return HD_ERROR_UNSUPPORTED): hd_set_depth from the host's
   cl_mem buffer (passed as void*) of the backend's context (desc.opencl.context): width x height
   floats, rows top first, from byte `offset` (a multiple of 4), copied on the device
   (clEnqueueCopyBuffer on the backend's queue: the caller's writes must be finished or on that
   queue) at the call, with hd_set_depth's lifetime and image. Errors, one log line each, the
   depth held before kept: HD_ERROR_NULL_POINTER, HD_ERROR_INVALID_PARAMETER (the offset, not a
   buffer, another context), HD_ERROR_BUFFER_TOO_SMALL, HD_ERROR_DEPTH_NEEDS_PROJECTION. */
HDDEF hd_result hd_opencl_set_depth_buffer(hd_context ctx, void *buffer, size_t offset);

/* ---- file loaders ----------------------------------------------------------------------------- */
/* A loaded volume owns its voxels; free it with hd_volume_free. Signed and 32/64-bit integer
   types are converted to F32.
   Every loader opens only regular files: a directory, device, FIFO or socket is
   HD_ERROR_FILE_NOT_REGULAR, refused before it is read, so a FIFO cannot block the call
   (tests/test_io_limits.c, io_not_regular). A loader reads the header (at most 1 MiB), then
   only the bytes the header says the data need (io_data_length). Raw data are allocated once
   the file is known to hold them; gzip data as they inflate, never on the header's claim alone,
   so a short stream claiming a huge volume fails without a large allocation (io_gzip_claim).
   Peak allocation while loading a file is at most twice the loaded volume (or its decompressed
   data, whichever is larger) plus 1.25 MiB (io_peak_allocation). The memory parsers
   (hd_volume_parse_*) allocate with malloc and have no limit but HD_MAX_DIM. */
typedef struct hd_volume_file {
    hd_volume_desc desc; /* ready to be copied into hd_desc.volume */
    void *data;          /* what desc.data points to */
    float value_min, value_max; /* range of the values in the file */
    hd_allocator allocator; /* what allocated data (hd_load_options.allocator); hd_volume_free
                               uses it */
} hd_volume_file;

typedef enum hd_endian { HD_ENDIAN_LITTLE = 0, HD_ENDIAN_BIG } hd_endian;

typedef enum hd_raw_type {
    HD_RAW_U8 = 0, HD_RAW_I8, HD_RAW_U16, HD_RAW_I16, HD_RAW_U32, HD_RAW_I32, HD_RAW_F32,
    HD_RAW_F64, HD_RAW_TYPE_COUNT
} hd_raw_type;

typedef enum hd_file_format {
    HD_FILE_AUTO = 0, /* by the file's first bytes (or a .mhd/.mha extension), as hd_volume_load */
    HD_FILE_NRRD, HD_FILE_METAIMAGE, HD_FILE_NIFTI, HD_FILE_FORMAT_COUNT
} hd_file_format;

/* Options of hd_volume_load_ex; all zero is what the other loaders use.
   MetaImage detached data (ElementDataFile = name): by default the name must be relative and
   resolve (symbolic links followed, by realpath) to a regular file inside the header's folder;
   an absolute name, '..' leading out, or a link pointing out is HD_ERROR_FILE_OUTSIDE_FOLDER
   (tests/test_io_limits.c, io_mhd_detached_policy). The path is resolved once; its last component
   is then opened without following a link. allow_outside_folder lifts the folder rule (the file
   must still be regular). max_bytes bounds the voxel data a header may declare, counted in the
   file's element type and in the loaded type, whichever is larger: more is
   HD_ERROR_FILE_TOO_LARGE before anything is allocated or inflated (io_max_bytes). */
typedef struct hd_load_options {
    hd_file_format format;    /* HD_FILE_AUTO (0): detect */
    int allow_outside_folder; /* MetaImage: ElementDataFile may name any regular file */
    size_t max_bytes;         /* 0: no limit but HD_MAX_DIM per axis */
    hd_allocator allocator;   /* every allocation of the loader (zlib's too) and the voxels;
                                 all or none, {0}: malloc/free */
} hd_load_options;

/* NRRD (.nrrd, attached header; raw or gzip encoding). */
HDDEF hd_result hd_volume_load_nrrd(const char *path, hd_volume_file *out, const hd_logger *log);
/* Headerless raw: dims, type, endianness and byte offset given by the caller. */
HDDEF hd_result hd_volume_load_raw(const char *path, const int dims[3], hd_raw_type type,
                                   hd_endian endian, size_t offset, hd_volume_file *out,
                                   const hd_logger *log);
/* The same parsers on a memory buffer (what the fuzzers drive). */
HDDEF hd_result hd_volume_parse_nrrd(const void *bytes, size_t size, hd_volume_file *out,
                                     const hd_logger *log);
/* MetaImage (.mhd + detached .raw/.zraw, or LOCAL data as in .mha) and NIfTI-1 (.nii, .nii.gz,
   either byte order; scl_slope/scl_inter applied). parse_mhd: data/data_size are the detached
   data file's bytes (ignored for LOCAL data). hd_volume_load picks the format by the file's
   first bytes (or a .mhd/.mha extension). */
HDDEF hd_result hd_volume_load_mhd(const char *path, hd_volume_file *out, const hd_logger *log);
HDDEF hd_result hd_volume_parse_mhd(const void *header, size_t header_size, const void *data,
                                    size_t data_size, hd_volume_file *out, const hd_logger *log);
HDDEF hd_result hd_volume_load_nifti(const char *path, hd_volume_file *out, const hd_logger *log);
HDDEF hd_result hd_volume_parse_nifti(const void *bytes, size_t size, hd_volume_file *out,
                                      const hd_logger *log);
HDDEF hd_result hd_volume_load(const char *path, hd_volume_file *out, const hd_logger *log);
/* Any format with options (NULL: all zero); an out-of-range format is HD_ERROR_INVALID_ENUM,
   one of allocator.alloc/free without the other HD_ERROR_NULL_POINTER. */
HDDEF hd_result hd_volume_load_ex(const char *path, const hd_load_options *options,
                                  hd_volume_file *out, const hd_logger *log);
HDDEF void hd_volume_free(hd_volume_file *vol);

#ifdef __cplusplus
}
#endif
#endif /* HYBRIDDIFF_H */

/* ================================================================================================
   Implementation
   ================================================================================================ */
#ifdef HYBRIDDIFF_IMPLEMENTATION
#ifndef HYBRIDDIFF_IMPLEMENTATION_DONE
#define HYBRIDDIFF_IMPLEMENTATION_DONE

#if (defined(HYBRIDDIFF_BACKEND_CPU) + defined(HYBRIDDIFF_BACKEND_OPENCL) + \
     defined(HYBRIDDIFF_BACKEND_VULKAN) + defined(HYBRIDDIFF_BACKEND_GL) + defined(HYBRIDDIFF_BACKEND_NULL)) == 0
#error "hybriddiff: define exactly one backend: HYBRIDDIFF_BACKEND_CPU, HYBRIDDIFF_BACKEND_OPENCL, HYBRIDDIFF_BACKEND_VULKAN, HYBRIDDIFF_BACKEND_GL or HYBRIDDIFF_BACKEND_NULL"
#elif (defined(HYBRIDDIFF_BACKEND_CPU) + defined(HYBRIDDIFF_BACKEND_OPENCL) + \
       defined(HYBRIDDIFF_BACKEND_VULKAN) + defined(HYBRIDDIFF_BACKEND_GL) + defined(HYBRIDDIFF_BACKEND_NULL)) > 1
#error "hybriddiff: more than one backend defined; define exactly one of HYBRIDDIFF_BACKEND_CPU, HYBRIDDIFF_BACKEND_OPENCL, HYBRIDDIFF_BACKEND_VULKAN, HYBRIDDIFF_BACKEND_GL, HYBRIDDIFF_BACKEND_NULL"
#else /* exactly one backend: the implementation (skipped after an #error, so that is all the
         compiler reports) */

/* The implementation calls POSIX 2008 (clock_gettime, pthreads, realpath, O_NOFOLLOW), which a
   strict -std=c99 translation unit hides. The feature set is widened for the
   implementation's own system headers and restored after it, so the include order does not
   matter and no feature macro leaks into or is needed from the including file. glibc fixes its
   feature set at the first system header (<features.h>), so it is evaluated again both ways. */
#if !defined(_WIN32)
#include <limits.h> /* any C library header: brings glibc's <features.h> and __GLIBC__ */
#if defined(__GLIBC__)
#if !defined(__USE_XOPEN2K8) || !(defined(__USE_MISC) || defined(__USE_XOPEN_EXTENDED))
#define HD__WIDEN_POSIX 1
#endif
#elif defined(__STRICT_ANSI__) && !defined(__cplusplus)
#define HD__WIDEN_POSIX 1
#endif
#if defined(HD__WIDEN_POSIX)
#pragma push_macro("_POSIX_C_SOURCE")
#pragma push_macro("_XOPEN_SOURCE")
#undef _POSIX_C_SOURCE
#undef _XOPEN_SOURCE
#define _POSIX_C_SOURCE 200809L
#define _XOPEN_SOURCE 700
#if defined(__GLIBC__)
#undef _FEATURES_H
#include <features.h>
#endif
#if !defined(__cplusplus)
/* <stdlib.h> included before under the narrower set does not declare it; a compatible
   redeclaration is valid C. */
extern char *realpath(const char *path, char *resolved);
#endif
#endif
#endif

#include "backends/hd_prelude_c.h"
#include "src/hd_internal.h"
#include "backends/kernels/hd_kernels.h"
#include "src/hd_multigrid_cg.h"
#include "src/hd_backend.h"
#if defined(HYBRIDDIFF_BACKEND_CPU)
#include "backends/hd_cpu.h"
#include "backends/hd_cpu_multigrid.h"
#elif defined(HYBRIDDIFF_BACKEND_OPENCL)
#include "backends/hd_gpu.h"
#include "backends/hd_opencl.h"
#elif defined(HYBRIDDIFF_BACKEND_VULKAN)
#include "backends/hd_gpu.h"
#include "backends/hd_vulkan.h"
#elif defined(HYBRIDDIFF_BACKEND_GL)
#include "backends/hd_gpu.h"
#include "backends/hd_gl.h"
#elif defined(HYBRIDDIFF_BACKEND_NULL)
#include "backends/hd_null.h"
#endif
#include "src/hd_core.h"
#include "src/hd_io.h"
#include "src/hd_io_mhd.h"
#include "src/hd_io_nifti.h"

#if defined(HD__WIDEN_POSIX) /* the including file's feature set again */
#undef _POSIX_C_SOURCE
#undef _XOPEN_SOURCE
#pragma pop_macro("_POSIX_C_SOURCE")
#pragma pop_macro("_XOPEN_SOURCE")
#if defined(__GLIBC__)
#undef _FEATURES_H
#include <features.h>
#endif
#undef HD__WIDEN_POSIX
#endif

/* The test suites' stage hooks, which need the implementation's macros. */
#if defined(HYBRIDDIFF_TESTING)
#include "src/hd_test_hooks.h"
#endif

/* Last: every macro the implementation defined, undefined (generated by scripts/gen-undef), so
   the including file's namespace after it holds the declarations' macros only. */
#include "backends/hd_undef.h"

#endif /* exactly one backend */
#endif /* HYBRIDDIFF_IMPLEMENTATION_DONE */
#endif /* HYBRIDDIFF_IMPLEMENTATION */

/*
------------------------------------------------------------------------------
This software is available under 2 licenses -- choose whichever you prefer.
------------------------------------------------------------------------------
ALTERNATIVE A - MIT License
Copyright (c) 2026 The hybriddiff authors
Permission is hereby granted, free of charge, to any person obtaining a copy of
this software and associated documentation files (the "Software"), to deal in
the Software without restriction, including without limitation the rights to
use, copy, modify, merge, publish, distribute, sublicense, and/or sell copies
of the Software, and to permit persons to whom the Software is furnished to do
so, subject to the following conditions:
The above copyright notice and this permission notice shall be included in all
copies or substantial portions of the Software.
THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS OR COPYRIGHT HOLDERS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER
LIABILITY, WHETHER IN AN ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM,
OUT OF OR IN CONNECTION WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE
SOFTWARE.
------------------------------------------------------------------------------
ALTERNATIVE B - Public Domain (www.unlicense.org)
This is free and unencumbered software released into the public domain.
Anyone is free to copy, modify, publish, use, compile, sell, or distribute this
software, either in source code form or as a compiled binary, for any purpose,
commercial or non-commercial, and by any means.
In jurisdictions that recognize copyright laws, the author or authors of this
software dedicate any and all copyright interest in the software to the public
domain. We make this dedication in perpetuity for the benefit of the software
to the public and to the detriment of all attempts to gain control of the
software under copyright law.
THE SOFTWARE IS PROVIDED "AS IS", WITHOUT WARRANTY OF ANY KIND, EXPRESS OR
IMPLIED, INCLUDING BUT NOT LIMITED TO THE WARRANTIES OF MERCHANTABILITY,
FITNESS FOR A PARTICULAR PURPOSE AND NONINFRINGEMENT. IN NO EVENT SHALL THE
AUTHORS BE LIABLE FOR ANY CLAIM, DAMAGES OR OTHER LIABILITY, WHETHER IN AN
ACTION OF CONTRACT, TORT OR OTHERWISE, ARISING FROM, OUT OF OR IN CONNECTION
WITH THE SOFTWARE OR THE USE OR OTHER DEALINGS IN THE SOFTWARE.
------------------------------------------------------------------------------
*/
