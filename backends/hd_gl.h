/* hd_gl.h - the OpenGL 4.3 compute backend: the shared kernels (backends/kernels/) as GLSL 4.30
   compute shaders, embedded as strings (backends/hd_glsl_embedded.h, from scripts/embed-glsl)
   and compiled by the driver at run time, each stage on its first use. Defines the same hd__be_*
   functions, with the same contracts, as the CPU reference.

   Whose context: with desc.gl.use_current_context the caller's GL context, current on the
   calling thread at hd_create and at every later call on the hd context; otherwise a headless
   context of the backend's own through EGL (the surfaceless platform, EGL_MESA_platform_
   surfaceless, else the first EGL_EXT_platform_device device, else the default display), the
   OpenGL API, 4.5 core, else 4.3 core. The own context is made current for each call and the
   context that was current before is made current again afterwards (none before: the backend's
   stays current, to save the switch on the next call). The EGL display is initialised and never
   terminated (EGL displays are not reference counted: terminating it would break other users).
   Functions are loaded through desc.gl.get_proc_address (glfwGetProcAddress, SDL_GL_
   GetProcAddress, ...), else eglGetProcAddress; the library links -lEGL only.

   Host state: every call restores what it touched: the program, uniform block binding 0, storage
   buffer bindings 0..3, image units 0..6, the generic buffer bindings (uniform, storage, copy
   read/write, pixel pack/unpack), the active texture and the 2D/3D texture bindings of unit 0,
   and the pixel pack/unpack parameters (tests/gl/test_gl.c checks it).

   Resources (docs/DESIGN-GL.md has the measurements): the grids (volume, sigma_t, E, phi, phi2,
   CD's light volumes) are GL_R32F 3D textures used as r32f images (channels stacked along z);
   with params.illumination_precision FLOAT16, E, phi and phi2 are GL_R16F textures used as r16f
   images (core GL 4.3, so never refused here) by a second program of each stage that touches
   them, compiled with `#define HD_ILLUM_R16F` (hd_bind_gl_glsl.h);
   the TF, majorant grid and image accumulation are storage buffers; the parameter block a
   uniform buffer rewritten when it changes; hd_pc a plain uniform. Jacobi's phi2 and CD's spare
   swap names with phi / the light's volume, as the CPU backend swaps pointers.

   HD_SOLVER_MULTIGRID (the end of this file; docs/DESIGN-GL.md): the levels and CG's vectors
   are r32f 3D textures too, smoothed by the diffusion program on each level's own uniform
   buffer; the other passes are hd_entry_glsl_multigrid.h, with GLSL doubles where the CPU sums
   in double, the dot products' rows (storage buffer 3) summed on the host in row order.

   Errors: a shader that fails to compile or link is HD_ERROR_BACKEND with the driver's info log
   (source-string numbers in it name the files listed in hd_glsl_embedded.h); a GL error after a
   stage is HD_ERROR_BACKEND naming the stage (OUT_OF_MEMORY: HD_ERROR_OUT_OF_DEVICE_MEMORY).
   Errors already pending when a call starts are not ours: they are logged (info) and cleared.
   Debug builds (no NDEBUG) with the own context create a debug context and pass KHR_debug
   messages above notification severity to the logger (warning; type ERROR as error). The
   caller's context keeps its own debug callback.

   Output without a CPU round trip: hd_gl_render_to_texture(_ex) (hybriddiff.h): the output pass
   (backends/hd_output_glsl.h) encodes the image into a buffer (sRGB RGBA8, or linear half or
   float RGBA), which glTexSubImage2D copies from the pixel unpack binding into a region of the
   caller's 2D texture: one path for every texture format (GL_SRGB8_ALPHA8 cannot be an image
   unit's format) and exactly hd_read_image_ex's bytes. */
#include <EGL/egl.h>
#include <EGL/eglext.h>
/* <GL/gl.h> first, as GLFW and SDL include it: a window header included after this file then
   still finds the GL 1.1 prototypes it expects (it skips its own include once GL is defined). */
#if !defined(__gl_h_) && !defined(__GL_H__) && !defined(__gl_glcorearb_h_)
#include <GL/gl.h>
#endif
#include <GL/glcorearb.h>
#include "hd_glsl_embedded.h"


/* ---- function table: every GL function through the loader ------------------------------- */
#define HD__GL_FNS(X) \
    X(GETERROR, GetError) X(GETINTEGERV, GetIntegerv) X(GETINTEGERI_V, GetIntegeri_v) \
    X(GETINTEGER64I_V, GetInteger64i_v) X(GETSTRING, GetString) X(FINISH, Finish) X(ENABLE, Enable) \
    X(CREATESHADER, CreateShader) X(SHADERSOURCE, ShaderSource) X(COMPILESHADER, CompileShader) \
    X(GETSHADERIV, GetShaderiv) X(GETSHADERINFOLOG, GetShaderInfoLog) X(DELETESHADER, DeleteShader) \
    X(CREATEPROGRAM, CreateProgram) X(ATTACHSHADER, AttachShader) X(LINKPROGRAM, LinkProgram) \
    X(GETPROGRAMIV, GetProgramiv) X(GETPROGRAMINFOLOG, GetProgramInfoLog) X(DELETEPROGRAM, DeleteProgram) \
    X(USEPROGRAM, UseProgram) X(UNIFORM4I, Uniform4i) X(UNIFORM1F, Uniform1f) \
    X(PROGRAMUNIFORM1F, ProgramUniform1f) X(PROGRAMUNIFORM1D, ProgramUniform1d) \
    X(DISPATCHCOMPUTE, DispatchCompute) X(MEMORYBARRIER, MemoryBarrier) \
    X(GENBUFFERS, GenBuffers) X(DELETEBUFFERS, DeleteBuffers) X(BINDBUFFER, BindBuffer) \
    X(BUFFERDATA, BufferData) X(BUFFERSUBDATA, BufferSubData) X(GETBUFFERSUBDATA, GetBufferSubData) \
    X(BINDBUFFERBASE, BindBufferBase) X(BINDBUFFERRANGE, BindBufferRange) X(CLEARBUFFERDATA, ClearBufferData) \
    X(_HD_GENTEXTURES, GenTextures) X(_HD_DELETETEXTURES, DeleteTextures) X(_HD_BINDTEXTURE, BindTexture) \
    X(ACTIVETEXTURE, ActiveTexture) X(TEXSTORAGE3D, TexStorage3D) X(TEXSUBIMAGE3D, TexSubImage3D) \
    X(GETTEXIMAGE, GetTexImage) X(GETTEXLEVELPARAMETERIV, GetTexLevelParameteriv) \
    X(BINDIMAGETEXTURE, BindImageTexture) X(PIXELSTOREI, PixelStorei) X(_HD_TEXSUBIMAGE2D, TexSubImage2D) \
    X(COPYIMAGESUBDATA, CopyImageSubData)
/* optional: GL 4.4 / ARB_clear_texture, KHR_debug, GL 4.5 / ARB_get_texture_sub_image */
#define HD__GL_OPT_FNS(X) X(CLEARTEXIMAGE, ClearTexImage) X(DEBUGMESSAGECALLBACK, DebugMessageCallback) \
    X(DEBUGMESSAGECONTROL, DebugMessageControl) X(GETTEXTURESUBIMAGE, GetTextureSubImage)

/* GL 1.1's texture entry points, typed here: a <GL/gl.h> included first (GLFW's) defines
   GL_VERSION_1_1, and <GL/glcorearb.h> then leaves out their pointer types. */
typedef void (APIENTRYP PFNGL_HD_GENTEXTURESPROC)(GLsizei n, GLuint *textures);
typedef void (APIENTRYP PFNGL_HD_DELETETEXTURESPROC)(GLsizei n, const GLuint *textures);
typedef void (APIENTRYP PFNGL_HD_BINDTEXTUREPROC)(GLenum target, GLuint texture);
typedef void (APIENTRYP PFNGL_HD_TEXSUBIMAGE2DPROC)(GLenum target, GLint level, GLint xoffset, GLint yoffset, GLsizei width,
                                                    GLsizei height, GLenum format, GLenum type, const void *pixels);

typedef struct hd__gl_fns {
#define HD__GL_FN(up, name) PFNGL##up##PROC name;
    HD__GL_FNS(HD__GL_FN) HD__GL_OPT_FNS(HD__GL_FN)
#undef HD__GL_FN
} hd__gl_fns;

enum { HD__GL_CLASSIFY, HD__GL_DIRECT, HD__GL_DIFFUSE, HD__GL_PROJECT, HD__GL_CONVECT, HD__GL_SUM_LIGHT,
       HD__GL_PATH, HD__GL_LIGHT_SUM, HD__GL_UPSAMPLE, HD__GL_OUTPUT, HD__GL_PROGRAM_COUNT };
static const char *const hd__gl_stage_names[HD__GL_PROGRAM_COUNT] = {
    "classify", "direct", "diffuse", "project", "convect", "sum_light", "path", "light_sum", "upsample", "output"};
/* The diffusion program is compiled once per combination of the flags it tests (RGB scattering,
   surface boundary), each with `#define HD_DIFFUSE_FLAGS n`: llvmpipe, like lavapipe, runs both
   sides of a branch on a uniform, so a flag read at run time costs the untaken path's image loads
   (docs/DESIGN-VULKAN.md measures the same specialization). Program slots past
   HD__GL_PROGRAM_COUNT hold these variants. */
#define HD__GL_DIFFUSE_VARIANTS 8 /* bit 4: HD_FLAG_DIFFUSE_RHS (multigrid's levels) */
#define HD__GL_SLOTS_F32 (HD__GL_PROGRAM_COUNT + HD__GL_DIFFUSE_VARIANTS)
/* Then the same slots again for float16 illumination storage (HD_ILLUM_R16F): only those of the
   stages that touch E / phi / phi2 are ever compiled (hd__gl_touches_illum). */
#define HD__GL_SLOTS (2 * HD__GL_SLOTS_F32)
static int hd__gl_touches_illum(int stage)
{
    return stage == HD__GL_DIRECT || stage == HD__GL_DIFFUSE || stage == HD__GL_PROJECT || stage == HD__GL_SUM_LIGHT ||
           stage == HD__GL_LIGHT_SUM;
}
static int hd__gl_diffuse_flags(int variant)
{
    return ((variant & 1) ? HD_FLAG_RGB_SCATTERING : 0) | ((variant & 2) ? HD_FLAG_SURFACE_BOUNDARY : 0) |
           ((variant & 4) ? HD_FLAG_DIFFUSE_RHS : 0);
}
static int hd__gl_diffuse_slot(int counts_z)
{
    return HD__GL_PROGRAM_COUNT + ((counts_z & HD_FLAG_RGB_SCATTERING) ? 1 : 0) +
           ((counts_z & HD_FLAG_SURFACE_BOUNDARY) ? 2 : 0) + ((counts_z & HD_FLAG_DIFFUSE_RHS) ? 4 : 0);
}
#define HD__GL_LOCAL_X 64 /* hd_entry_glsl.h's work group: 64 x 1 x 1 */
/* The block of slices x rows each diffusion invocation relaxes (HD_DIFFUSE_ZK, HD_DIFFUSE_YK in
   hd_entry_glsl.h): llvmpipe pays a fixed cost per invocation and per static image load, and the
   block loads the texels its voxels share once (docs/DESIGN-GL.md). */
#define HD__GL_DIFFUSE_ZK 4
#define HD__GL_DIFFUSE_YK 2
#define HD__GL_IMAGE_UNITS 8 /* hd_bind_gl_glsl.h: image units 0..7, GL 4.3's minimum */
#define HD__GL_SSBOS 8       /* storage buffers 0..7 (3: multigrid's row sums, 4: the direct light's list,
                                5: the projection's TF table, 6: the host's depth buffer, 7: the
                                environment's tables), GL 4.3's minimum */

typedef struct hd__gl_tex {
    GLuint name;
    int extent[3];
    GLenum format; /* GL_R32F, or GL_R16F (E / phi / phi2 at float16); the volume's by its storage */
} hd__gl_tex;

/* HD_SOLVER_MULTIGRID's per-level objects besides the grids (hd__gpu_mg_extras) and its grids */
typedef struct hd__gl_level {
    GLuint params;           /* the level's parameter block (backends/hd_gpu.h's hd__gpu_level) */
    hd__gl_tex sig;          /* coarse levels only (level 0 reads the backend's sigma_t) */
    hd__gl_tex rhs, phi, res; /* right-hand side, correction, residual; level 0: r, z and q = A p */
} hd__gl_level;

struct hd__gl_mg {
    hd__gl_level lv[HD__MG_MAX_LEVELS];
    hd__gl_tex p, lo;        /* the search direction; the iterate's low part (phi + lo) */
    GLuint dot_a, dot_b;     /* per-row partial sums (double) */
    double *host_dot;        /* their host copy */
};

/* The host state a call may touch (saved on entry, restored on exit). */
typedef struct hd__gl_state {
    EGLDisplay egl_dpy;
    EGLSurface egl_draw, egl_read;
    EGLContext egl_ctx;
    int switched;
    GLint program, active_texture, tex2d, tex3d;
    GLint ubo0, ssbo[HD__GL_SSBOS];
    GLint64 ubo0_start, ubo0_size, ssbo_start[HD__GL_SSBOS], ssbo_size[HD__GL_SSBOS];
    GLint image[HD__GL_IMAGE_UNITS][6];
    GLint generic[6];
    GLint pixel[16];
} hd__gl_state;

struct hd__backend {
    const hd__view *vw;
    hd__gl_fns gl;
    hd_proc (*gpa)(const char *);
    int own;                    /* 1: the EGL context is the backend's */
    EGLDisplay dpy;
    EGLContext egl;
    /* the caller's context (use_current_context), as current at hd_create: EGL, else GLX
       (glXGetCurrentContext through get_proc_address), else neither (only "some context") */
    EGLContext caller_egl;
    void *(*glx_current)(void);
    void *caller_glx;
    int version;                /* major * 10 + minor */
    int depth;                  /* nesting of hd__be_begin */
    hd__gl_state saved;
    GLuint programs[HD__GL_SLOTS]; /* by stage, then the diffusion variants; twice (float32, float16) */
    GLuint params;              /* uniform buffer of hd__kparams */
    hd__kparams params_kp;      /* what it holds */
    int params_valid;
    GLuint tf, maj, img, dummy_buffer;
    GLuint dl;                  /* the direct light's list of voxels (vw->dl_idx), storage buffer 4 */
    GLuint dep;                 /* the host's depth buffer (vw->depth), storage buffer 6; 0: none */
    GLuint env;                 /* the environment's tables (vw->env), storage buffer 7; 0: none */
    hd__gl_tex vol, sig, E, phi, phi2, dummy, dummy16;
    hd__gl_tex lv[HD_MAX_LIGHTS + 1]; /* CD: gg.nlv light volumes + a spare at lv[gg.nlv] */
    /* the projection's own inputs (hd__gl_project_prepare): E + phi (image unit 7), valid while
       gg.lsum_ok (backends/hd_gpu.h), and the step's TF table (storage
       buffer 5, ptab_n entries), uploaded when its inputs change (ptab_key) */
    hd__gl_tex lsum;
    GLuint ptab;
    int ptab_n;
    hd__ptab_key ptab_key;
    size_t img_floats, tf_bytes;
    GLint max_3d, max_ssbo_block;
    int diffuse_zk, diffuse_yk; /* HD__GL_DIFFUSE_ZK, _YK: what the diffusion programs are compiled for */
    int spread_rows;            /* 1 (llvmpipe): the projection's rows in blocks spread (backends/hd_gpu.h) */
    hd__gpu_grids gg;           /* what the grids are made for (backends/hd_gpu.h) */
    struct hd__gl_mg mg;        /* multigrid's extras and grids while gg.levels */
    GLuint mg_programs[HD__GPU_MG_VARIANTS]; /* HD_SOLVER_MULTIGRID's (backends/hd_gpu.h), compiled on first use */
    /* the output pass (hd__be_output_texture): the RGBA8 thresholds (hd__output_thresholds),
       storage buffer 0, made on first use; the encoded image, storage buffer 1 and then the
       pixel unpack buffer, obuf_bytes long */
    GLuint otab, obuf;
    size_t obuf_bytes;
};

static const char *hd__be_name(void) { return "gl"; }

/* ---- loading --------------------------------------------------------------------------------- */
typedef void (*hd__gl_proc)(void);
static hd__gl_proc hd__gl_load(hd__backend *be, const char *name)
{
    hd__gl_proc f = NULL;
    if (be->gpa) {
        f = be->gpa(name);
    } else {
        f = (hd__gl_proc)eglGetProcAddress(name);
    }
    return f;
}

static hd_result hd__gl_load_fns(const hd__view *vw)
{
    hd__backend *be = vw->be;
#define HD__GL_LOAD(up, name) \
    be->gl.name = (PFNGL##up##PROC)hd__gl_load(be, "gl" #name); \
    if (!be->gl.name) return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: cannot load gl" #name);
    HD__GL_FNS(HD__GL_LOAD)
#undef HD__GL_LOAD
#define HD__GL_LOAD_OPT(up, name) be->gl.name = (PFNGL##up##PROC)hd__gl_load(be, "gl" #name);
    HD__GL_OPT_FNS(HD__GL_LOAD_OPT)
#undef HD__GL_LOAD_OPT
    return HD_SUCCESS;
}

/* ---- errors ------------------------------------------------------------------------------------ */
static const char *hd__gl_error_name(GLenum e)
{
    switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
    case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
    default: return "unknown GL error";
    }
}

/* The GL errors raised since the last check, as one hd_result (logged with what failed). */
static hd_result hd__gl_check(const hd__view *vw, const char *what, int line)
{
    hd__backend *be = vw->be;
    hd_result r = HD_SUCCESS;
    GLenum e;
    int n = 0;
    while ((e = be->gl.GetError()) != GL_NO_ERROR && n++ < 16) {
        hd_result c = e == GL_OUT_OF_MEMORY ? HD_ERROR_OUT_OF_DEVICE_MEMORY : HD_ERROR_BACKEND;
        hd__logf(&vw->log, HD_LOG_ERROR, c, __FILE__, line, "gl: %s after %s (0x%04x)", hd__gl_error_name(e), what, (unsigned)e);
        if (r == HD_SUCCESS) r = c;
    }
    return r;
}
#define HD__GL_CHECK(vw, what) \
    do { hd_result hd__r = hd__gl_check((vw), (what), __LINE__); if (hd__r != HD_SUCCESS) return hd__r; } while (0)

#ifndef NDEBUG
static void APIENTRY hd__gl_debug(GLenum source, GLenum type, GLuint id, GLenum severity, GLsizei length,
                                    const GLchar *message, const void *user)
{
    const hd__view *vw = (const hd__view *)user;
    (void)source; (void)length; (void)severity;
    /* a performance hint (e.g. NVIDIA's note that the image buffer moves to host memory for
       hd_read_image) is information, not a fault */
    hd_log_level level = type == GL_DEBUG_TYPE_ERROR ? HD_LOG_ERROR : type == GL_DEBUG_TYPE_PERFORMANCE ? HD_LOG_INFO : HD_LOG_WARNING;
    hd__logf(&vw->log, level, HD_SUCCESS, __FILE__, __LINE__, "gl debug (id %u): %s", (unsigned)id, message);
}
#endif

/* ---- the host's state: saved on entry, restored on exit ---------------------------------- */
static const GLenum hd__gl_generic_targets[6][2] = {
    {GL_UNIFORM_BUFFER, GL_UNIFORM_BUFFER_BINDING}, {GL_SHADER_STORAGE_BUFFER, GL_SHADER_STORAGE_BUFFER_BINDING},
    {GL_COPY_READ_BUFFER, GL_COPY_READ_BUFFER_BINDING}, {GL_COPY_WRITE_BUFFER, GL_COPY_WRITE_BUFFER_BINDING},
    {GL_PIXEL_PACK_BUFFER, GL_PIXEL_PACK_BUFFER_BINDING}, {GL_PIXEL_UNPACK_BUFFER, GL_PIXEL_UNPACK_BUFFER_BINDING}};
static const GLenum hd__gl_pixel_params[16] = {
    GL_PACK_ALIGNMENT, GL_PACK_ROW_LENGTH, GL_PACK_IMAGE_HEIGHT, GL_PACK_SKIP_PIXELS, GL_PACK_SKIP_ROWS,
    GL_PACK_SKIP_IMAGES, GL_PACK_SWAP_BYTES, GL_PACK_LSB_FIRST, GL_UNPACK_ALIGNMENT, GL_UNPACK_ROW_LENGTH,
    GL_UNPACK_IMAGE_HEIGHT, GL_UNPACK_SKIP_PIXELS, GL_UNPACK_SKIP_ROWS, GL_UNPACK_SKIP_IMAGES,
    GL_UNPACK_SWAP_BYTES, GL_UNPACK_LSB_FIRST};
static const GLenum hd__gl_image_queries[6] = {GL_IMAGE_BINDING_NAME, GL_IMAGE_BINDING_LEVEL, GL_IMAGE_BINDING_LAYERED,
                                               GL_IMAGE_BINDING_LAYER, GL_IMAGE_BINDING_ACCESS, GL_IMAGE_BINDING_FORMAT};

static void hd__gl_restore_indexed(hd__backend *be, GLenum target, GLuint index, GLint name, GLint64 start, GLint64 size)
{
    if (name != 0 && size > 0) be->gl.BindBufferRange(target, index, (GLuint)name, (GLintptr)start, (GLsizeiptr)size);
    else be->gl.BindBufferBase(target, index, (GLuint)name);
}

/* The caller's context (use_current_context) must be current at every call that reaches GL:
   the one current at hd_create where EGL or GLX can tell, else any (GL_VERSION answers). A GL
   call without a current context does nothing, so without this check iterations would count
   as run and the image would be stale. */
static hd_result hd__gl_check_current(const hd__view *vw)
{
    hd__backend *be = vw->be;
    if (be->caller_egl != EGL_NO_CONTEXT) {
        EGLContext cur = eglGetCurrentContext();
        if (cur == be->caller_egl) return HD_SUCCESS;
        return HD__ERR(&vw->log, HD_ERROR_GL_CONTEXT_NOT_CURRENT, cur == EGL_NO_CONTEXT
                       ? "gl: no EGL context is current; make the one given at hd_create (use_current_context) current"
                       : "gl: another EGL context is current than the one given at hd_create (use_current_context)");
    }
    if (be->glx_current) {
        void *cur = be->glx_current();
        if (cur == be->caller_glx) return HD_SUCCESS;
        return HD__ERR(&vw->log, HD_ERROR_GL_CONTEXT_NOT_CURRENT, cur == NULL
                       ? "gl: no GLX context is current; make the one given at hd_create (use_current_context) current"
                       : "gl: another GLX context is current than the one given at hd_create (use_current_context)");
    }
    if (!be->gl.GetString(GL_VERSION))
        return HD__ERR(&vw->log, HD_ERROR_GL_CONTEXT_NOT_CURRENT,
                       "gl: no GL context is current (use_current_context: the caller's must be current at every call)");
    return HD_SUCCESS;
}

/* The bracket (src/hd_backend.h): makes the context current (own context) and saves the host's
   bindings. Nested brackets (hd__be_create's, the test hooks') save once. Pending GL errors are
   not ours. */
static hd_result hd__be_begin(const hd__view *vw)
{
    hd__backend *be = vw->be;
    hd__gl_state *s = &be->saved;
    GLenum e;
    int i, j;
    if (be->depth++ > 0) return HD_SUCCESS;
    s->switched = 0;
    if (be->own && eglGetCurrentContext() != be->egl) {
        s->egl_dpy = eglGetCurrentDisplay();
        s->egl_draw = eglGetCurrentSurface(EGL_DRAW);
        s->egl_read = eglGetCurrentSurface(EGL_READ);
        s->egl_ctx = eglGetCurrentContext();
        if (!eglMakeCurrent(be->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, be->egl)) {
            EGLint err = eglGetError();
            be->depth--;
            /* libglvnd lets a thread have one current context across EGL and GLX: a GLX context
               (GLFW's default) makes every eglMakeCurrent on that thread fail so. */
            if (err == EGL_BAD_ACCESS && s->egl_ctx == EGL_NO_CONTEXT)
                return HD__ERR(&vw->log, HD_ERROR_BACKEND,
                               "gl: eglMakeCurrent failed (EGL_BAD_ACCESS): another API's context (GLX) is current on this "
                               "thread; pass it (desc.gl.use_current_context = 1) or make it not current around the call");
            return HD__ERR(&vw->log, HD_ERROR_BACKEND, "gl: eglMakeCurrent failed (0x%04x)", (unsigned)err);
        }
        s->switched = 1;
    } else if (!be->own) {
        hd_result r = hd__gl_check_current(vw);
        if (r != HD_SUCCESS) { be->depth--; return r; }
    }
    while ((e = be->gl.GetError()) != GL_NO_ERROR)
        HD__INFO(&vw->log, "gl: %s was pending before this call (not hybriddiff's; cleared)", hd__gl_error_name(e));
    be->gl.GetIntegerv(GL_CURRENT_PROGRAM, &s->program);
    be->gl.GetIntegerv(GL_ACTIVE_TEXTURE, &s->active_texture);
    be->gl.ActiveTexture(GL_TEXTURE0);
    be->gl.GetIntegerv(GL_TEXTURE_BINDING_2D, &s->tex2d);
    be->gl.GetIntegerv(GL_TEXTURE_BINDING_3D, &s->tex3d);
    be->gl.GetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, 0, &s->ubo0);
    be->gl.GetInteger64i_v(GL_UNIFORM_BUFFER_START, 0, &s->ubo0_start);
    be->gl.GetInteger64i_v(GL_UNIFORM_BUFFER_SIZE, 0, &s->ubo0_size);
    for (i = 0; i < HD__GL_SSBOS; ++i) {
        be->gl.GetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, (GLuint)i, &s->ssbo[i]);
        be->gl.GetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, (GLuint)i, &s->ssbo_start[i]);
        be->gl.GetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, (GLuint)i, &s->ssbo_size[i]);
    }
    for (i = 0; i < HD__GL_IMAGE_UNITS; ++i)
        for (j = 0; j < 6; ++j) be->gl.GetIntegeri_v(hd__gl_image_queries[j], (GLuint)i, &s->image[i][j]);
    for (i = 0; i < 6; ++i) be->gl.GetIntegerv(hd__gl_generic_targets[i][1], &s->generic[i]);
    for (i = 0; i < 16; ++i) be->gl.GetIntegerv(hd__gl_pixel_params[i], &s->pixel[i]);
    /* what the backend's transfers assume */
    be->gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    be->gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    for (i = 0; i < 16; ++i) be->gl.PixelStorei(hd__gl_pixel_params[i], (i & 7) == 0 ? 4 : 0);
    return HD_SUCCESS;
}

/* Restores what hd__be_begin saved; r is the result of the call, returned unless the restore
   itself raised a GL error. */
static hd_result hd__be_end(const hd__view *vw, hd_result r)
{
    hd__backend *be = vw->be;
    hd__gl_state *s = &be->saved;
    hd_result r2;
    int i;
    if (--be->depth > 0) return r;
    r2 = hd__gl_check(vw, "the stage", __LINE__); /* errors of this call not caught yet */
    if (r == HD_SUCCESS) r = r2;
    be->gl.UseProgram((GLuint)s->program);
    hd__gl_restore_indexed(be, GL_UNIFORM_BUFFER, 0, s->ubo0, s->ubo0_start, s->ubo0_size);
    for (i = 0; i < HD__GL_SSBOS; ++i)
        hd__gl_restore_indexed(be, GL_SHADER_STORAGE_BUFFER, (GLuint)i, s->ssbo[i], s->ssbo_start[i], s->ssbo_size[i]);
    for (i = 0; i < HD__GL_IMAGE_UNITS; ++i)
        be->gl.BindImageTexture((GLuint)i, (GLuint)s->image[i][0], s->image[i][1], (GLboolean)s->image[i][2], s->image[i][3],
                                (GLenum)s->image[i][4], (GLenum)s->image[i][5]);
    /* after the indexed ones: glBindBufferBase sets the generic binding too */
    for (i = 0; i < 6; ++i) be->gl.BindBuffer(hd__gl_generic_targets[i][0], (GLuint)s->generic[i]);
    for (i = 0; i < 16; ++i) be->gl.PixelStorei(hd__gl_pixel_params[i], s->pixel[i]);
    be->gl.BindTexture(GL_TEXTURE_2D, (GLuint)s->tex2d);
    be->gl.BindTexture(GL_TEXTURE_3D, (GLuint)s->tex3d);
    be->gl.ActiveTexture((GLenum)s->active_texture);
    r2 = hd__gl_check(vw, "restoring the host's state", __LINE__);
    if (r == HD_SUCCESS) r = r2;
    if (s->switched && s->egl_ctx != EGL_NO_CONTEXT)
        eglMakeCurrent(s->egl_dpy, s->egl_draw, s->egl_read, s->egl_ctx);
    return r;
}

/* ---- programs ---------------------------------------------------------------------------------- */
/* Compiles and links the program of slot p (a stage, or a diffusion variant) on its first use. */
static hd_result hd__gl_build(const hd__view *vw, const char *const *src, GLsizei n, const char *name, GLuint *out);
static hd_result hd__gl_program(const hd__view *vw, int p)
{
    int half = p >= HD__GL_SLOTS_F32, q = p % HD__GL_SLOTS_F32;
    int stage = q < HD__GL_PROGRAM_COUNT ? q : HD__GL_DIFFUSE;
    hd__backend *be = vw->be;
    const char *src[1 + HD__GL_SOURCE_LINES];
    char prefix[384];
    GLsizei n = 0;
    size_t i;
    if (be->programs[p]) return HD_SUCCESS;
    if (p == HD__GL_OUTPUT) {
        src[0] = "#version 430 core\n";
        for (i = 0; i < HD__GL_SOURCE_OUTPUT_LINES; ++i) src[1 + i] = hd__gl_source_output[i];
        n = (GLsizei)(1 + HD__GL_SOURCE_OUTPUT_LINES);
    } else {
        int len = snprintf(prefix, sizeof prefix,
                           "#version 430 core\n#define HD_MAX_LIGHTS %d\n#define HD_STAGE %d\n"
                           "#define HD_VOL_STORE %d\nlayout(local_size_x = %d, local_size_y = 1, local_size_z = 1) in;\n%s",
                           HD_MAX_LIGHTS, stage + 1, vw->vtype, HD__GL_LOCAL_X, half ? "#define HD_ILLUM_R16F 1\n" : "");
        if (q >= HD__GL_PROGRAM_COUNT)
            snprintf(prefix + len, sizeof prefix - (size_t)len, "#define HD_DIFFUSE_FLAGS %d\n#define HD_DIFFUSE_ZK %d\n#define HD_DIFFUSE_YK %d\n",
                     hd__gl_diffuse_flags(q - HD__GL_PROGRAM_COUNT), be->diffuse_zk, be->diffuse_yk);
        src[0] = prefix;
        for (i = 0; i < HD__GL_SOURCE_LINES; ++i) src[1 + i] = hd__gl_source[i];
        n = (GLsizei)(1 + HD__GL_SOURCE_LINES);
    }
    return hd__gl_build(vw, src, n, hd__gl_stage_names[stage], &be->programs[p]);
}

/* Compiles and links n source strings into *out. */
static hd_result hd__gl_build(const hd__view *vw, const char *const *src, GLsizei n, const char *name, GLuint *out)
{
    hd__backend *be = vw->be;
    char log[4096];
    GLuint sh, prog;
    GLint ok = 0;
    sh = be->gl.CreateShader(GL_COMPUTE_SHADER);
    if (!sh) return HD__ERR(&vw->log, HD_ERROR_BACKEND, "gl: glCreateShader(GL_COMPUTE_SHADER) failed");
    be->gl.ShaderSource(sh, n, src, NULL);
    be->gl.CompileShader(sh);
    be->gl.GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        log[0] = '\0';
        be->gl.GetShaderInfoLog(sh, (GLsizei)sizeof log, NULL, log);
        be->gl.DeleteShader(sh);
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "gl: the %s shader does not compile (source-string numbers: "
                       "backends/hd_glsl_embedded.h):\n%s", name, log);
    }
    prog = be->gl.CreateProgram();
    be->gl.AttachShader(prog, sh);
    be->gl.LinkProgram(prog);
    be->gl.DeleteShader(sh);
    be->gl.GetProgramiv(prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        log[0] = '\0';
        be->gl.GetProgramInfoLog(prog, (GLsizei)sizeof log, NULL, log);
        be->gl.DeleteProgram(prog);
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "gl: the %s program does not link:\n%s", name, log);
    }
    *out = prog;
    HD__GL_CHECK(vw, "building a program");
    return HD_SUCCESS;
}

/* ---- resources ----------------------------------------------------------------------------------- */
static void hd__gl_free_tex(hd__backend *be, hd__gl_tex *t)
{
    if (t->name) be->gl.DeleteTextures(1, &t->name);
    memset(t, 0, sizeof *t);
}

static void hd__gl_free_buffer(hd__backend *be, GLuint *b)
{
    if (*b) be->gl.DeleteBuffers(1, b);
    *b = 0;
}

/* A w x h x d 3D texture of format fmt (GL_R32F or GL_R16F), zeroed (or filled from src, which
   the GL converts to fmt). */
static hd_result hd__gl_tex_new_as(const hd__view *vw, hd__gl_tex *t, int w, int h, int d, GLenum fmt, const float *src,
                                   const char *what)
{
    hd__backend *be = vw->be;
    hd_result r;
    hd__gl_free_tex(be, t);
    if (w > be->max_3d || h > be->max_3d || d > be->max_3d)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: %s needs a %dx%dx%d 3D texture, above GL_MAX_3D_TEXTURE_SIZE = %d",
                       what, w, h, d, be->max_3d);
    be->gl.GenTextures(1, &t->name);
    be->gl.BindTexture(GL_TEXTURE_3D, t->name);
    be->gl.TexStorage3D(GL_TEXTURE_3D, 1, fmt, w, h, d);
    t->extent[0] = w; t->extent[1] = h; t->extent[2] = d;
    t->format = fmt;
    if ((r = hd__gl_check(vw, what, __LINE__)) != HD_SUCCESS) { hd__gl_free_tex(be, t); return r; }
    if (src) be->gl.TexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, w, h, d, GL_RED, GL_FLOAT, src);
    else if (fmt == GL_R8UI || fmt == GL_R16UI || fmt == GL_R16I) (void)0; /* the volume: hd__gl_vol_new fills it */
    else if (be->gl.ClearTexImage && be->version >= 44) be->gl.ClearTexImage(t->name, 0, GL_RED, GL_FLOAT, NULL);
    else {
        float *zero = (float *)hd__calloc(vw, (size_t)w * h * d, sizeof(float));
        if (!zero) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "gl: no memory to clear %s", what);
        be->gl.TexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, w, h, d, GL_RED, GL_FLOAT, zero);
        hd__free(vw, zero);
    }
    if ((r = hd__gl_check(vw, what, __LINE__)) != HD_SUCCESS) { hd__gl_free_tex(be, t); return r; }
    return HD_SUCCESS;
}

/* The volume's texture format and its upload's format and type, by the core's storage (vtype):
   the integer formats keep the raw voxels, which the programs read with imageLoad as they are
   (hd_bind_gl_glsl.h's HD_VOL_STORE). */
static void hd__gl_vol_format(int vtype, GLenum *fmt, GLenum *up_fmt, GLenum *up_type)
{
    *fmt = vtype == HD_VOL_U8 ? GL_R8UI : vtype == HD_VOL_U16 ? GL_R16UI : vtype == HD_VOL_I16 ? GL_R16I : GL_R32F;
    *up_fmt = vtype == HD_VOL_F32 ? GL_RED : GL_RED_INTEGER;
    *up_type = vtype == HD_VOL_U8 ? GL_UNSIGNED_BYTE : vtype == HD_VOL_U16 ? GL_UNSIGNED_SHORT : vtype == HD_VOL_I16 ? GL_SHORT : GL_FLOAT;
}

/* Voxels of box vox from the core's copy into the volume texture: one TexSubImage3D, the unpack
   row length and image height set for it (rows of 1- and 2-byte voxels are not 4-byte aligned)
   and put back to the bracket's defaults. */
static void hd__gl_vol_write(const hd__view *vw, const hd__box *vox)
{
    hd__backend *be = vw->be;
    GLenum fmt, up_fmt, up_type;
    hd__gl_vol_format(vw->vtype, &fmt, &up_fmt, &up_type);
    be->gl.BindTexture(GL_TEXTURE_3D, be->vol.name);
    be->gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    be->gl.PixelStorei(GL_UNPACK_ROW_LENGTH, vw->dims[0]);
    be->gl.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, vw->dims[1]);
    be->gl.TexSubImage3D(GL_TEXTURE_3D, 0, vox->lo[0], vox->lo[1], vox->lo[2], vox->hi[0] - vox->lo[0], vox->hi[1] - vox->lo[1],
                         vox->hi[2] - vox->lo[2], up_fmt, up_type,
                         (const unsigned char *)vw->vol +
                             (((size_t)vox->lo[2] * vw->dims[1] + vox->lo[1]) * vw->dims[0] + vox->lo[0]) * hd__vol_elem(vw->vtype));
    be->gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    be->gl.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    be->gl.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
}

/* The volume's texture in the core's storage, filled from its copy. */
static hd_result hd__gl_vol_new(const hd__view *vw)
{
    hd__backend *be = vw->be;
    hd__box all;
    GLenum fmt, up_fmt, up_type;
    hd_result r;
    int d;
    hd__gl_vol_format(vw->vtype, &fmt, &up_fmt, &up_type);
    if ((r = hd__gl_tex_new_as(vw, &be->vol, vw->dims[0], vw->dims[1], vw->dims[2], fmt, NULL, "the volume")) != HD_SUCCESS) return r;
    for (d = 0; d < 3; ++d) {
        all.lo[d] = 0;
        all.hi[d] = vw->dims[d];
    }
    hd__gl_vol_write(vw, &all);
    return hd__gl_check(vw, "uploading the volume", __LINE__);
}

/* A GL_R32F 3D texture, the grids' usual form. */
static hd_result hd__gl_tex_new(const hd__view *vw, hd__gl_tex *t, int w, int h, int d, const float *src, const char *what)
{
    return hd__gl_tex_new_as(vw, t, w, h, d, GL_R32F, src, what);
}

static hd_result hd__gl_tex_zero(const hd__view *vw, hd__gl_tex *t)
{
    if (!t->name) return HD_SUCCESS;
    return hd__gl_tex_new_as(vw, t, t->extent[0], t->extent[1], t->extent[2], t->format, NULL, "clearing an illumination grid");
}

/* Grid id's texture (backends/hd_gpu.h): E, phi, phi2 GL_R16F at float16 storage, the others GL_R32F. */
static hd__gl_tex *hd__gl_grid(hd__backend *be, int id)
{
    hd__gl_tex *named[HD__G_MG_LEVELS] = {&be->sig, &be->E, &be->phi, &be->phi2, &be->lsum, &be->mg.p, &be->mg.lo};
    hd__gl_level *L = &be->mg.lv[HD__G_LEVEL_OF(id)];
    hd__gl_tex *level[4] = {&L->sig, &L->rhs, &L->phi, &L->res}; /* by HD__G_MG_SIG, _RHS, _PHI, _RES */
    return id < HD__G_MG_LEVELS ? named[id] : id >= HD__G_LIGHT ? &be->lv[id - HD__G_LIGHT] : level[(id - HD__G_MG_LEVELS) % 4];
}
static hd_result hd__gpu_grid_new(const hd__view *vw, int id, int w, int h, int d, const char *what)
{
    GLenum fmt = vw->be->gg.f16 && id >= HD__G_E && id <= HD__G_PHI2 ? GL_R16F : GL_R32F;
    return hd__gl_tex_new_as(vw, hd__gl_grid(vw->be, id), w, h, d, fmt, NULL, what);
}
static void hd__gpu_grid_free(const hd__view *vw, int id) { hd__gl_free_tex(vw->be, hd__gl_grid(vw->be, id)); }
static hd_result hd__gpu_grid_zero(const hd__view *vw, int id) { return hd__gl_tex_zero(vw, hd__gl_grid(vw->be, id)); }

static hd_result hd__gl_buffer_data(const hd__view *vw, GLuint *b, size_t bytes, const void *src, GLenum usage, const char *what)
{
    hd__backend *be = vw->be;
    if (!*b) be->gl.GenBuffers(1, b);
    be->gl.BindBuffer(GL_COPY_WRITE_BUFFER, *b);
    be->gl.BufferData(GL_COPY_WRITE_BUFFER, (GLsizeiptr)(bytes ? bytes : 16), src, usage);
    return hd__gl_check(vw, what, __LINE__);
}

/* Binds every resource to its unit (placeholders for the absent ones) and the program. An image
   unit's format is its texture's: a float16 program's absent phi2 gets the GL_R16F placeholder. */
static void hd__gl_bind_image(hd__backend *be, GLuint unit, const hd__gl_tex *t, GLenum access, int half)
{
    const hd__gl_tex *u = t && t->name ? t : half ? &be->dummy16 : &be->dummy;
    be->gl.BindImageTexture(unit, u->name, 0, GL_TRUE, 0, access, u->format);
}

/* Sends vw->kp to the backend's uniform buffer when it changed. */
static void hd__gl_send_params(const hd__view *vw)
{
    hd__backend *be = vw->be;
    if (!be->params_valid || memcmp(&be->params_kp, &vw->kp, sizeof vw->kp) != 0) {
        be->gl.BindBuffer(GL_UNIFORM_BUFFER, be->params);
        be->gl.BufferData(GL_UNIFORM_BUFFER, (GLsizeiptr)sizeof vw->kp, &vw->kp, GL_STREAM_DRAW);
        be->params_kp = vw->kp;
        be->params_valid = 1;
    }
}

/* What one dispatch binds: the parameter block's buffer and the textures of image units 0..6
   (NULL: the placeholder); half: the float16 program's units 2..4. */
typedef struct hd__gl_binds {
    GLuint params;
    const hd__gl_tex *img[HD__GL_IMAGE_UNITS];
    int half;
} hd__gl_binds;

/* Runs program prog over nx x ny x nz invocations (x in work groups of HD__GL_LOCAL_X) with the
   bindings b and hd_pc = (pc_x, pc_y, pc_z, pc_w); what names it in errors. */
static hd_result hd__gl_run(const hd__view *vw, GLuint prog, const char *what, const hd__gl_binds *b, int nx, int ny, int nz,
                            int pc_x, int pc_y, int pc_z, int pc_w)
{
    hd__backend *be = vw->be;
    int i;
    be->gl.UseProgram(prog);
    be->gl.Uniform4i(0, pc_x, pc_y, pc_z, pc_w);
    be->gl.BindBufferBase(GL_UNIFORM_BUFFER, 0, b->params);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, be->tf ? be->tf : be->dummy_buffer);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, be->maj ? be->maj : be->dummy_buffer);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, be->img ? be->img : be->dummy_buffer);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, be->dl ? be->dl : be->dummy_buffer);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, be->ptab ? be->ptab : be->dummy_buffer);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, be->dep ? be->dep : be->dummy_buffer);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, be->env ? be->env : be->dummy_buffer);
    for (i = 0; i < HD__GL_IMAGE_UNITS; ++i)
        hd__gl_bind_image(be, (GLuint)i, b->img[i], i == 0 || i == 5 ? GL_READ_ONLY : GL_READ_WRITE, b->half && i >= 2 && i <= 4);
    be->gl.DispatchCompute((GLuint)((nx + HD__GL_LOCAL_X - 1) / HD__GL_LOCAL_X), (GLuint)ny, (GLuint)nz);
    be->gl.MemoryBarrier(GL_ALL_BARRIER_BITS);
    return hd__gl_check(vw, what, __LINE__);
}

static hd_result hd__gl_dispatch(const hd__view *vw, int p, int light, int nx, int ny, int nz, int pc_x, int pc_y, int pc_z,
                                 int pc_w)
{
    hd__backend *be = vw->be;
    hd_result r;
    hd__gl_binds b;
    int half = be->gg.f16 && hd__gl_touches_illum(p);
    int slot = (p == HD__GL_DIFFUSE ? hd__gl_diffuse_slot(vw->kp.counts.z) : p) + (half ? HD__GL_SLOTS_F32 : 0);
    if ((r = hd__gl_program(vw, slot)) != HD_SUCCESS) return r;
    hd__gl_send_params(vw);
    b.params = be->params;
    b.img[0] = &be->vol; b.img[1] = &be->sig; b.img[2] = &be->E; b.img[3] = &be->phi; b.img[4] = &be->phi2;
    b.img[5] = light < be->gg.nlv ? &be->lv[light] : NULL;
    b.img[6] = be->gg.nlv ? &be->lv[be->gg.nlv] : NULL;
    b.img[7] = &be->lsum;
    b.half = half;
    return hd__gl_run(vw, be->programs[slot], hd__gl_stage_names[p], &b, nx, ny, nz, pc_x, pc_y, pc_z, pc_w);
}


/* ---- the context --------------------------------------------------------------------------------- */
static int hd__gl_has_ext(const char *list, const char *name)
{
    size_t n = strlen(name);
    const char *p = list;
    while (p && (p = strstr(p, name)) != NULL) {
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0')) return 1;
        p += n;
    }
    return 0;
}

/* A headless display: surfaceless, else the first EGL device, else the default display. */
static hd_result hd__gl_egl_display(const hd__view *vw)
{
    hd__backend *be = vw->be;
    const char *cext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    EGLint major = 0, minor = 0;
    const char *how = "the default display";
    be->dpy = EGL_NO_DISPLAY;
    if (cext && get_platform_display && hd__gl_has_ext(cext, "EGL_MESA_platform_surfaceless")) {
        be->dpy = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
        how = "EGL_MESA_platform_surfaceless";
        if (be->dpy != EGL_NO_DISPLAY && !eglInitialize(be->dpy, &major, &minor)) be->dpy = EGL_NO_DISPLAY;
    }
    if (be->dpy == EGL_NO_DISPLAY && cext && get_platform_display && hd__gl_has_ext(cext, "EGL_EXT_platform_device")) {
        PFNEGLQUERYDEVICESEXTPROC query_devices = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
        EGLDeviceEXT devices[8];
        EGLint count = 0, i;
        if (query_devices && query_devices(8, devices, &count))
            for (i = 0; i < count && be->dpy == EGL_NO_DISPLAY; ++i) {
                be->dpy = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], NULL);
                how = "EGL_EXT_platform_device";
                if (be->dpy != EGL_NO_DISPLAY && !eglInitialize(be->dpy, &major, &minor)) be->dpy = EGL_NO_DISPLAY;
            }
    }
    if (be->dpy == EGL_NO_DISPLAY) {
        be->dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        how = "the default display";
        if (be->dpy != EGL_NO_DISPLAY && !eglInitialize(be->dpy, &major, &minor)) be->dpy = EGL_NO_DISPLAY;
    }
    if (be->dpy == EGL_NO_DISPLAY)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: no EGL display (surfaceless, device or default): 0x%04x",
                       (unsigned)eglGetError());
    HD__INFO(&vw->log, "gl: EGL %d.%d through %s (%s)", (int)major, (int)minor, how, eglQueryString(be->dpy, EGL_VENDOR));
    return HD_SUCCESS;
}

static hd_result hd__gl_egl_context(const hd__view *vw)
{
    hd__backend *be = vw->be;
    static const EGLint config_attrs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    static const int versions[2][2] = {{4, 5}, {4, 3}};
    EGLConfig config = NULL;
    EGLint nconfig = 0;
    int v;
    hd_result r;
    if ((r = hd__gl_egl_display(vw)) != HD_SUCCESS) return r;
    if (!eglBindAPI(EGL_OPENGL_API))
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: eglBindAPI(EGL_OPENGL_API) failed: 0x%04x", (unsigned)eglGetError());
    if (!eglChooseConfig(be->dpy, config_attrs, &config, 1, &nconfig) || nconfig < 1) {
        if (!hd__gl_has_ext(eglQueryString(be->dpy, EGL_EXTENSIONS), "EGL_KHR_no_config_context"))
            return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: no EGL config with EGL_OPENGL_BIT and no EGL_KHR_no_config_context");
        config = (EGLConfig)0; /* EGL_NO_CONFIG_KHR */
    }
    for (v = 0; v < 2 && !be->egl; ++v) {
        EGLint attrs[16], n = 0;
        attrs[n++] = EGL_CONTEXT_MAJOR_VERSION; attrs[n++] = versions[v][0];
        attrs[n++] = EGL_CONTEXT_MINOR_VERSION; attrs[n++] = versions[v][1];
        attrs[n++] = EGL_CONTEXT_OPENGL_PROFILE_MASK; attrs[n++] = EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT;
#ifndef NDEBUG
        attrs[n++] = EGL_CONTEXT_OPENGL_DEBUG; attrs[n++] = EGL_TRUE;
#endif
        attrs[n++] = EGL_NONE;
        be->egl = eglCreateContext(be->dpy, config, EGL_NO_CONTEXT, attrs);
        if (be->egl == EGL_NO_CONTEXT) be->egl = NULL;
    }
    if (!be->egl)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: eglCreateContext: no OpenGL 4.5 or 4.3 core context (0x%04x)",
                       (unsigned)eglGetError());
    return HD_SUCCESS;
}

static void hd__be_destroy(hd__view *vw)
{
    hd__backend *be = vw->be;
    int i;
    if (!be) return;
    if (be->gl.GetError && (be->own ? be->egl != NULL : 1) && hd__be_begin(vw) == HD_SUCCESS) {
        for (i = 0; i < HD__GL_SLOTS; ++i)
            if (be->programs[i]) be->gl.DeleteProgram(be->programs[i]);
        for (i = 0; i < HD__GPU_MG_VARIANTS; ++i)
            if (be->mg_programs[i]) be->gl.DeleteProgram(be->mg_programs[i]);
        hd__gpu_free(vw, &be->gg);
        hd__gl_free_buffer(be, &be->params); hd__gl_free_buffer(be, &be->tf); hd__gl_free_buffer(be, &be->maj);
        hd__gl_free_buffer(be, &be->img); hd__gl_free_buffer(be, &be->dummy_buffer);
        hd__gl_free_buffer(be, &be->dl); hd__gl_free_buffer(be, &be->ptab); hd__gl_free_buffer(be, &be->dep);
        hd__gl_free_buffer(be, &be->env);
        hd__gl_free_buffer(be, &be->otab); hd__gl_free_buffer(be, &be->obuf);
        hd__gl_free_tex(be, &be->vol); hd__gl_free_tex(be, &be->dummy); hd__gl_free_tex(be, &be->dummy16);
        hd__be_end(vw, HD_SUCCESS);
    }
    hd__free(vw, be->mg.host_dot); /* left when GL was unreachable */
    if (be->own && be->egl) {
        if (eglGetCurrentContext() == be->egl) eglMakeCurrent(be->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(be->dpy, be->egl);
    }
    hd__free(vw, be);
    vw->be = NULL;
}

static hd_result hd__gl_setup(const hd__view *vw)
{
    hd__backend *be = vw->be;
    GLint major = 0, minor = 0, units = 0, ssbos = 0;
    hd_result r;
    if (!be->gl.GetString(GL_VERSION))
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: no GL context is current (use_current_context = %d)",
                       vw->desc.gl.use_current_context);
    be->gl.GetIntegerv(GL_MAJOR_VERSION, &major);
    be->gl.GetIntegerv(GL_MINOR_VERSION, &minor);
    be->version = major * 10 + minor;
    HD__INFO(&vw->log, "gl: %s, %s (%s context)", (const char *)be->gl.GetString(GL_RENDERER),
             (const char *)be->gl.GetString(GL_VERSION), be->own ? "own EGL" : "the caller's");
    /* llvmpipe runs the work groups of a dispatch as one contiguous run per thread */
    be->spread_rows = be->gl.GetString(GL_RENDERER) && strstr((const char *)be->gl.GetString(GL_RENDERER), "llvmpipe");
    if (be->version < 43)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: OpenGL %d.%d; compute shaders need 4.3", (int)major, (int)minor);
    be->gl.GetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &be->max_3d);
    be->gl.GetIntegerv(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &be->max_ssbo_block);
    be->gl.GetIntegerv(GL_MAX_IMAGE_UNITS, &units);
    be->gl.GetIntegerv(GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS, &ssbos);
    if (units < HD__GL_IMAGE_UNITS || ssbos < HD__GL_SSBOS)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: %d image units and %d storage buffer bindings; %d and %d needed",
                       (int)units, (int)ssbos, HD__GL_IMAGE_UNITS, HD__GL_SSBOS);
#ifndef NDEBUG
    if (be->own && be->gl.DebugMessageCallback && be->gl.DebugMessageControl) {
        be->gl.Enable(GL_DEBUG_OUTPUT);
        be->gl.DebugMessageCallback(hd__gl_debug, vw);
        be->gl.DebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DEBUG_SEVERITY_NOTIFICATION, 0, NULL, GL_FALSE);
    }
#endif
    be->gl.GenBuffers(1, &be->params);
    if ((r = hd__gl_buffer_data(vw, &be->dummy_buffer, 16, NULL, GL_STATIC_DRAW, "a placeholder buffer")) != HD_SUCCESS) return r;
    if ((r = hd__gl_tex_new(vw, &be->dummy, 1, 1, 1, NULL, "a placeholder image")) != HD_SUCCESS) return r;
    if ((r = hd__gl_tex_new_as(vw, &be->dummy16, 1, 1, 1, GL_R16F, NULL, "a float16 placeholder image")) != HD_SUCCESS) return r;
    return hd__gl_vol_new(vw);
}

static hd_result hd__be_create(hd__view *vw)
{
    hd__backend *be;
    hd_result r;
    be = (hd__backend *)hd__calloc(vw, 1, sizeof *be);
    if (!be) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "gl: cannot allocate the backend");
    vw->be = be;
    be->vw = vw;
    be->diffuse_zk = HD__GL_DIFFUSE_ZK;
    be->diffuse_yk = HD__GL_DIFFUSE_YK;
    be->gpa = vw->desc.gl.get_proc_address;
    be->own = !vw->desc.gl.use_current_context;
    if (be->own) {
        if ((r = hd__gl_egl_context(vw)) != HD_SUCCESS) return r;
    } else {
        be->caller_egl = eglGetCurrentContext();
        if (be->caller_egl == EGL_NO_CONTEXT && be->gpa) {
            /* a GLX caller: its loader knows glXGetCurrentContext; a NULL answer tells nothing */
            be->glx_current = (void *(*)(void))be->gpa("glXGetCurrentContext");
            be->caller_glx = be->glx_current ? be->glx_current() : NULL;
            if (!be->caller_glx) be->glx_current = NULL;
        }
        if (!be->gpa && be->caller_egl == EGL_NO_CONTEXT)
            HD__INFO(&vw->log, "gl: use_current_context with no current EGL context: loading through eglGetProcAddress anyway");
    }
    if ((r = hd__gl_load_fns(vw)) != HD_SUCCESS) {
        be->gl.GetError = NULL; /* hd__be_destroy must not call into GL */
        return r;
    }
    /* the own context is made current by hd__be_begin, which makes the caller's current again */
    if ((r = hd__be_begin(vw)) != HD_SUCCESS) return r;
    return hd__be_end(vw, hd__gl_setup(vw));
}

/* ---- inputs and allocations ---------------------------------------------------------------------- */
static hd_result hd__be_upload_inputs(const hd__view *vw)
{
    hd__backend *be = vw->be;
    hd_result r;
    size_t ncell = (size_t)vw->mdims[0] * vw->mdims[1] * vw->mdims[2];
    if ((r = hd__gl_buffer_data(vw, &be->tf, (size_t)vw->tf_count * 4 * sizeof(float), vw->tf, GL_DYNAMIC_DRAW,
                                "uploading the transfer function")) != HD_SUCCESS)
        return r;
    return hd__gl_buffer_data(vw, &be->maj, ncell * sizeof(float), vw->majorant, GL_DYNAMIC_DRAW, "uploading the majorant grid");
}

/* hd_update_volume: the box of the volume into the volume texture (one TexSubImage3D from the
   core's copy, the unpack row length and image height set for it and put back to the bracket's
   0), the majorant cells' rows into their buffer. */
static hd_result hd__be_update_volume(const hd__view *vw, const hd__box *vox, const hd__box *cells)
{
    hd__backend *be = vw->be;
    int y, z;
    hd__gl_vol_write(vw, vox);
    be->gl.BindBuffer(GL_COPY_WRITE_BUFFER, be->maj);
    for (z = cells->lo[2]; z < cells->hi[2]; ++z)
        for (y = cells->lo[1]; y < cells->hi[1]; ++y) {
            size_t at = ((size_t)z * vw->mdims[1] + y) * vw->mdims[0] + (size_t)cells->lo[0];
            be->gl.BufferSubData(GL_COPY_WRITE_BUFFER, (GLintptr)(at * sizeof(float)),
                                 (GLsizeiptr)((size_t)(cells->hi[0] - cells->lo[0]) * sizeof(float)), vw->majorant + at);
        }
    return hd__gl_check(vw, "updating the volume", __LINE__);
}

static hd_result hd__be_alloc_illumination(const hd__view *vw, size_t illum_floats)
{
    return hd__gpu_alloc_illumination(vw, &vw->be->gg, illum_floats);
}
static hd_result hd__be_alloc_jacobi(const hd__view *vw, int enable) { return hd__gpu_alloc_jacobi(vw, &vw->be->gg, enable); }

static hd_result hd__be_alloc_image(const hd__view *vw, int width, int height, int parts)
{
    hd__backend *be = vw->be;
    size_t floats = hd__image_floats(width, height, parts), bytes = floats * sizeof(float);
    GLuint img = 0;
    hd_result r;
    if (bytes > (size_t)be->max_ssbo_block)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "gl: a %dx%d image%s needs %zu bytes, above GL_MAX_SHADER_STORAGE_BLOCK_SIZE = %d",
                       width, height, hd__image_parts_name(parts), bytes, (int)be->max_ssbo_block);
    if ((r = hd__gl_buffer_data(vw, &img, bytes, NULL, GL_DYNAMIC_COPY, (parts & HD__IMAGE_REDUCED) ? "the image with room for reduced frames" : "the image")) !=
        HD_SUCCESS) {
        hd__gl_free_buffer(be, &img);
        return r;
    }
    hd__gl_free_buffer(be, &be->img);
    be->img = img;
    be->img_floats = floats;
    return HD_SUCCESS;
}

static hd_result hd__be_clear(const hd__view *vw, unsigned what)
{
    hd__backend *be = vw->be;
    hd_result r;
    if ((r = hd__gpu_clear(vw, &be->gg, what)) != HD_SUCCESS) return r;
    if ((what & HD__DIRTY_IMAGE) && be->img) {
        be->gl.BindBuffer(GL_COPY_WRITE_BUFFER, be->img);
        be->gl.ClearBufferData(GL_COPY_WRITE_BUFFER, GL_R32F, GL_RED, GL_FLOAT, NULL);
    }
    return hd__gl_check(vw, "clearing", __LINE__);
}

/* ---- stages ------------------------------------------------------------------------------------ */
static hd_result hd__be_classify(const hd__view *vw)
{
    return hd__gl_dispatch(vw, HD__GL_CLASSIFY, 0, vw->gdims[0], vw->gdims[1], vw->gdims[2], 0, 0, 0, 0);
}

/* The host's depth buffer into storage buffer 6 (freed without one). */
static hd_result hd__be_upload_depth(const hd__view *vw)
{
    if (!vw->depth) { /* none, or the one hd__be_depth_texture copied in (depth_device), kept */
        if (!vw->depth_device) hd__gl_free_buffer(vw->be, &vw->be->dep);
        return HD_SUCCESS;
    }
    return hd__gl_buffer_data(vw, &vw->be->dep, (size_t)vw->depth_w * vw->depth_h * sizeof(float), vw->depth, GL_DYNAMIC_DRAW,
                              "the depth buffer");
}

/* The environment's tables into storage buffer 7 (freed without them). */
static hd_result hd__be_upload_env(const hd__view *vw)
{
    if (!vw->env) {
        hd__gl_free_buffer(vw->be, &vw->be->env);
        return HD_SUCCESS;
    }
    return hd__gl_buffer_data(vw, &vw->be->env, vw->env_floats * sizeof(float), vw->env, GL_STATIC_DRAW, "the environment's tables");
}

static hd_result hd__be_wait(const hd__view *vw)
{
    vw->be->gl.Finish();
    return hd__gl_check(vw, "glFinish", __LINE__);
}

/* Uploads the direct light's list of voxels (rebuilt with sigma_t). */
static hd_result hd__be_direct_list(const hd__view *vw)
{
    return hd__gl_buffer_data(vw, &vw->be->dl, vw->dl_count * sizeof(uint32_t), vw->dl_idx, GL_STATIC_DRAW,
                              "the direct light's list");
}

/* The direct stage over the list, in rows of at most HD__DIRECT_ROW entries (a dispatch's work
   groups along x are limited to 65535). */
#define HD__DIRECT_ROW (HD__GL_LOCAL_X * 32768)
static hd_result hd__be_direct(const hd__view *vw, size_t first, size_t count)
{
    int n = (int)count, rows = (n + HD__DIRECT_ROW - 1) / HD__DIRECT_ROW;
    vw->be->gg.lsum_ok = 0;
    if (n == 0) return HD_SUCCESS;
    return hd__gl_dispatch(vw, HD__GL_DIRECT, 0, rows > 1 ? HD__DIRECT_ROW : n, rows, 1, n, (int)first, 0, 0);
}

/* One full sweep: two half-sweeps (red, black; half the voxels of each row per dispatch) or one
   Jacobi pass phi -> phi2 and a swap of the two names. */
static hd_result hd__be_diffuse(const hd__view *vw, int jacobi)
{
    hd__backend *be = vw->be;
    hd_result r;
    /* invocations along y and z: blocks of diffuse_yk rows and diffuse_zk slices, nzb per channel
       (uniform hd_pc.z, hd_entry_glsl.h) */
    int ny = (vw->gdims[1] + be->diffuse_yk - 1) / be->diffuse_yk, nzb = (vw->gdims[2] + be->diffuse_zk - 1) / be->diffuse_zk;
    int nz = nzb * vw->channels, parity;
    be->gg.lsum_ok = 0;
    if (jacobi) {
        hd__gl_tex t;
        if ((r = hd__gl_dispatch(vw, HD__GL_DIFFUSE, 0, vw->gdims[0], ny, nz, 0, 1, nzb, 0)) != HD_SUCCESS) return r;
        t = be->phi; be->phi = be->phi2; be->phi2 = t;
        return HD_SUCCESS;
    }
    for (parity = 0; parity < 2; ++parity)
        if ((r = hd__gl_dispatch(vw, HD__GL_DIFFUSE, 0, (vw->gdims[0] + 1) / 2, ny, nz, parity, 0, nzb, 0)) != HD_SUCCESS)
            return r;
    return HD_SUCCESS;
}

/* The projection's inputs: lsum rebuilt (the light-sum stage) after a pass that changed E or phi,
   and the TF table (hd__project_table) built and uploaded when its inputs changed (ptab_key). */
static hd_result hd__gl_project_prepare(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int n = hd__project_table_n(vw);
    float *t;
    hd_result r;
    if (!be->gg.lsum_ok) {
        if ((r = hd__gl_dispatch(vw, HD__GL_LIGHT_SUM, 0, vw->gdims[0], vw->gdims[1], vw->gdims[2] * vw->channels, 0, 0,
                                 0, 0)) != HD_SUCCESS)
            return r;
        be->gg.lsum_ok = 1;
    }
    if (hd__project_table_key_same(vw, &be->ptab_key)) return HD_SUCCESS;
    if (!(t = hd__project_table_new(vw, n))) return HD_ERROR_OUT_OF_MEMORY;
    be->ptab_key.valid = 0;
    be->ptab_n = 0;
    r = hd__gl_buffer_data(vw, &be->ptab, (size_t)n * 4 * sizeof(float), t, GL_DYNAMIC_DRAW, "the projection's TF table");
    hd__free(vw, t);
    if (r != HD_SUCCESS) return r;
    be->ptab_key = hd__project_table_key(vw);
    be->ptab_n = n;
    return HD_SUCCESS;
}
static hd_result hd__be_project(const hd__view *vw)
{
    int nb = (vw->kp.image.y + HD__GPU_ROW_BLOCK - 1) / HD__GPU_ROW_BLOCK, p = vw->be->spread_rows ? hd__gpu_row_stride(nb) : 1;
    hd_result r = hd__gl_project_prepare(vw);
    if (r != HD_SUCCESS) return r;
    return hd__gl_dispatch(vw, HD__GL_PROJECT, 0, vw->kp.image.x, p > 1 ? nb * HD__GPU_ROW_BLOCK : vw->kp.image.y, 1,
                           vw->be->ptab_n, p, HD__GPU_ROW_BLOCK, 0);
}

/* The upsample pass: its own small program (HD_STAGE_UPSAMPLE), one invocation per pixel. */
static hd_result hd__be_upsample(const hd__view *vw)
{
    return hd__gl_dispatch(vw, HD__GL_UPSAMPLE, 0, vw->kp.image.x, vw->kp.image.y, 1, 0, 0, 0, 0);
}

/* ---- read-back ------------------------------------------------------------------------------- */
static hd_result hd__be_read_image(const hd__view *vw, float *dst)
{
    hd__backend *be = vw->be;
    be->gl.BindBuffer(GL_COPY_READ_BUFFER, be->img);
    be->gl.GetBufferSubData(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)((size_t)vw->kp.image.x * vw->kp.image.y * 4 * sizeof(float)), dst);
    return hd__gl_check(vw, "reading the image", __LINE__);
}
static hd_result hd__be_read_depth(const hd__view *vw, float *dst)
{
    hd__backend *be = vw->be;
    be->gl.BindBuffer(GL_COPY_READ_BUFFER, be->img);
    be->gl.GetBufferSubData(GL_COPY_READ_BUFFER, (GLintptr)((size_t)vw->kp.region.z * sizeof(float)),
                            (GLsizeiptr)((size_t)vw->kp.image.x * vw->kp.image.y * sizeof(float)), dst);
    return hd__gl_check(vw, "reading the depth plane", __LINE__);
}

/* A grid into dst, whole (list NULL) or the z slices list[0..count) one after another: one
   glGetTextureSubImage each, or without GL 4.5 the whole grid read and the slices copied out of
   it. GL_R16F grids come back widened to float by the GL, exactly (every half is a float). The
   image units are unbound first (the next dispatch binds its own): NVIDIA's driver reads a
   texture still bound as a writable image slowly, about 2 ms a slice on an H200. */
static hd_result hd__gl_read_tex(const hd__view *vw, const hd__gl_tex *t, const int *list, int count, float *dst)
{
    size_t slice = (size_t)t->extent[0] * t->extent[1];
    float *all = dst;
    int k;
    for (k = 0; k < HD__GL_IMAGE_UNITS; ++k) vw->be->gl.BindImageTexture((GLuint)k, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    if (list && vw->be->gl.GetTextureSubImage) {
        for (k = 0; k < count; ++k)
            vw->be->gl.GetTextureSubImage(t->name, 0, 0, 0, list[k], t->extent[0], t->extent[1], 1, GL_RED, GL_FLOAT,
                                           (GLsizei)(slice * sizeof(float)), dst + (size_t)k * slice);
        return hd__gl_check(vw, "reading illumination slices", __LINE__);
    }
    if (list && !(all = (float *)hd__alloc(vw, slice * (size_t)t->extent[2] * sizeof(float))))
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "gl: no memory to read an illumination grid");
    vw->be->gl.BindTexture(GL_TEXTURE_3D, t->name);
    vw->be->gl.GetTexImage(GL_TEXTURE_3D, 0, GL_RED, GL_FLOAT, all);
    for (k = 0; list && k < count; ++k) memcpy(dst + (size_t)k * slice, all + (size_t)list[k] * slice, slice * sizeof(float));
    if (list) hd__free(vw, all);
    return hd__gl_check(vw, "reading an illumination grid", __LINE__);
}
static hd_result hd__be_read_illumination(const hd__view *vw, hd_illumination which, const int *zz, int count, float *dst)
{
    return hd__gl_read_tex(vw, which == HD_ILLUMINATION_DIRECT ? &vw->be->E : &vw->be->phi, zz, count, dst);
}

#ifdef HYBRIDDIFF_TESTING
/* For src/hd_test_hooks.h: overwrites E or phi (channel-planar floats). */
/* A GL_R16F grid gets the floats rounded to nearest even on the host (hdk_f2h, the CPU backend's
   halves): the GL's own conversion may truncate, as llvmpipe's image stores do. */
static hd_result hd__gl_write_tex(const hd__view *vw, const hd__gl_tex *t, const float *src)
{
    size_t n = (size_t)t->extent[0] * t->extent[1] * t->extent[2], i;
    uint16_t *h = NULL;
    if (t->format == GL_R16F) {
        if (!(h = (uint16_t *)hd__calloc(vw, n, sizeof(uint16_t))))
            return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "gl: no memory to convert an illumination grid");
        for (i = 0; i < n; ++i) h[i] = hdk_f2h(src[i]);
    }
    vw->be->gl.BindTexture(GL_TEXTURE_3D, t->name);
    vw->be->gl.TexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, t->extent[0], t->extent[1], t->extent[2], GL_RED,
                              h ? GL_HALF_FLOAT : GL_FLOAT, h ? (const void *)h : (const void *)src);
    if (h) hd__free(vw, h);
    return hd__gl_check(vw, "writing an illumination grid", __LINE__);
}
HD__MAYBE_UNUSED static hd_result hd__gl_write_illumination(const hd__view *vw, hd_illumination which, const float *src)
{
    vw->be->gg.lsum_ok = 0;
    return hd__gl_write_tex(vw, which == HD_ILLUMINATION_DIRECT ? &vw->be->E : &vw->be->phi, src);
}
#endif
/* For src/hd_test_hooks.h: waits until the GL has done everything queued. */
HD__MAYBE_UNUSED static hd_result hd__gl_finish(const hd__view *vw)
{
    hd_result r = hd__be_begin(vw);
    if (r == HD_SUCCESS) vw->be->gl.Finish();
    return r == HD_SUCCESS ? hd__be_end(vw, r) : r;
}

/* ---- CD: light volumes, convection, their sum into E ---------------------------------------- */
static hd_result hd__be_alloc_lights(const hd__view *vw, int count) { return hd__gpu_alloc_lights(vw, &vw->be->gg, count); }

/* One convection step of light `light`: its volume -> the spare, and the two swap names. */
static hd_result hd__be_convect(const hd__view *vw, int light)
{
    hd__backend *be = vw->be;
    hd_result r;
    hd__gl_tex t;
    if ((r = hd__gl_dispatch(vw, HD__GL_CONVECT, light, vw->gdims[0], vw->gdims[1], vw->gdims[2], 0, 0, light, 0)) != HD_SUCCESS)
        return r;
    t = be->lv[light]; be->lv[light] = be->lv[be->gg.nlv]; be->lv[be->gg.nlv] = t;
    return HD_SUCCESS;
}

/* E = sum over the lights of colour * falloff * light volume, the first pass overwriting E. */
static hd_result hd__be_sum_lights(const hd__view *vw)
{
    hd_result r;
    int l;
    vw->be->gg.lsum_ok = 0;
    for (l = 0; l < vw->be->gg.nlv; ++l)
        if ((r = hd__gl_dispatch(vw, HD__GL_SUM_LIGHT, l, vw->gdims[0], vw->gdims[1], vw->gdims[2], 0, 0, l, l == 0)) != HD_SUCCESS)
            return r;
    return HD_SUCCESS;
}

/* ---- PT_SS / PT_MS ------------------------------------------------------------------------------ */
/* ---- HD_SOLVER_MULTIGRID ------------------------------------------------------------------------
   The per-level primitives of src/hd_multigrid.h's step (docs/DESIGN-MULTIGRID.md), structured
   as the OpenCL port (docs/DESIGN-OPENCL.md): the per-voxel math is the shared hd_k_multigrid.h
   (entry points hd_entry_glsl_multigrid.h), the V-cycle's smoothing the diffusion program with
   HD_FLAG_DIFFUSE_RHS on each level's own parameter block. Every level's sigma_t / rhs / phi /
   residual and CG's p and lo are r32f 3D textures like the backend's own; the double passes are
   GLSL 4.00 doubles; the dot products are summed per row on the GPU (x in order, doubles into
   storage buffer 3) and the rows in row order by the core, as on the CPU. */
/* Bytes the solver holds on the device (counted in method_bytes); 0 without it. */
static size_t hd__be_solver_bytes(const hd__view *vw) { return hd__gpu_solver_bytes(vw, &vw->be->gg); }
/* GL 4.3 core has GLSL doubles (ARB_gpu_shader_fp64): multigrid runs wherever the backend does. */
static const char *hd__be_mg_unavailable(const hd__view *vw) { (void)vw; return NULL; }
static hd__gpu_grids *hd__gpu_grids_of(const hd__view *vw) { return &vw->be->gg; }

/* The levels' parameter buffers and the row sums (device and host). */
static hd_result hd__gpu_mg_extras(const hd__view *vw, int make)
{
    hd__backend *be = vw->be;
    struct hd__gl_mg *mg = &be->mg;
    size_t rows = hd__gpu_mg_rows(&be->gg);
    hd_result r;
    int l;
    for (l = 0; l < be->gg.levels; ++l) {
        hd__gl_level *L = &mg->lv[l];
        hd__gl_free_buffer(be, &L->params);
        if (make) be->gl.GenBuffers(1, &L->params);
    }
    hd__gl_free_buffer(be, &mg->dot_a); hd__gl_free_buffer(be, &mg->dot_b);
    hd__free(vw, mg->host_dot);
    mg->host_dot = NULL;
    if (!make) return HD_SUCCESS;
    if (!(mg->host_dot = (double *)hd__calloc(vw, 2 * rows, sizeof(double))))
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "gl: cannot allocate the dot products' rows");
    if ((r = hd__gl_buffer_data(vw, &mg->dot_a, rows * sizeof(double), NULL, GL_DYNAMIC_READ, "multigrid's row sums")) != HD_SUCCESS)
        return r;
    return hd__gl_buffer_data(vw, &mg->dot_b, rows * sizeof(double), NULL, GL_DYNAMIC_READ, "multigrid's row sums");
}

static hd_result hd__gpu_mg_send(const hd__view *vw, int l, const hd__kparams *kp)
{
    vw->be->gl.BindBuffer(GL_UNIFORM_BUFFER, vw->be->mg.lv[l].params);
    vw->be->gl.BufferData(GL_UNIFORM_BUFFER, (GLsizeiptr)sizeof *kp, kp, GL_STATIC_DRAW);
    return hd__gl_check(vw, "multigrid level parameters", __LINE__);
}

/* The program of multigrid stage `stage` for the flags in counts_z (RGB, surface), compiled on
   first use: hd__gl_source up to hd_entry_glsl.h, then hd_entry_glsl_multigrid.h. */
static hd_result hd__gl_mg_program(const hd__view *vw, int stage, int counts_z, GLuint *out)
{
    hd__backend *be = vw->be;
    int flags, variant = hd__gpu_mg_variant(stage, counts_z, &flags);
    GLuint *slot = &be->mg_programs[variant];
    const char *src[1 + HD__GL_COMMON_LINES + HD__GL_SOURCE_MG_LINES];
    char prefix[320];
    size_t i;
    hd_result r;
    if (!*slot) {
        snprintf(prefix, sizeof prefix,
                 "#version 430 core\n#define HD_MAX_LIGHTS %d\n#define HD_STAGE 0\n#define HD_MG_STAGE %d\n"
                 "#define HD_DIFFUSE_FLAGS %d\n#define HD_VOL_STORE %d\nlayout(local_size_x = %d, local_size_y = 1, local_size_z = 1) in;\n",
                 HD_MAX_LIGHTS, stage, flags, vw->vtype, HD__GL_LOCAL_X);
        src[0] = prefix;
        for (i = 0; i < HD__GL_COMMON_LINES; ++i) src[1 + i] = hd__gl_source[i];
        for (i = 0; i < HD__GL_SOURCE_MG_LINES; ++i) src[1 + HD__GL_COMMON_LINES + i] = hd__gl_source_mg[i];
        r = hd__gl_build(vw, src, (GLsizei)(1 + HD__GL_COMMON_LINES + HD__GL_SOURCE_MG_LINES), hd__mg_stage_names[stage - 1], slot);
        if (r != HD_SUCCESS) return r;
    }
    *out = *slot;
    return HD_SUCCESS;
}

/* Set `set`'s grids (backends/hd_gpu.h) on image units 1..4 and 6, its row sums on storage buffer 3,
   and parameter slot `slot`: level slot's buffer, or the backend's own for the fine vw->kp. */
static void hd__gl_mg_binds(const hd__view *vw, int set, int slot, hd__gl_binds *b)
{
    static const int unit[5] = {1, 2, 3, 4, 6};
    hd__backend *be = vw->be;
    hd__gpu_mg_binds s;
    int i;
    memset(b, 0, sizeof *b);
    hd__gpu_mg_set(&be->gg, set, &s);
    b->params = slot == be->gg.levels ? be->params : be->mg.lv[slot].params;
    b->img[0] = &be->vol;
    for (i = 0; i < 5; ++i) b->img[unit[i]] = s.grid[i] < 0 ? NULL : hd__gl_grid(be, s.grid[i]);
    if (s.dot) be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, s.dot == 1 ? be->mg.dot_a : be->mg.dot_b);
}

/* Runs pass p with the program of its stage for the flags of vw->kp; the direction's beta and
   the update's alpha are the uniforms at locations 1 and 2 (hd_entry_glsl_multigrid.h). */
static hd_result hd__gpu_mg_pass(const hd__view *vw, const hd__gpu_mg_run *p)
{
    hd__backend *be = vw->be;
    hd__gl_binds b;
    GLuint prog;
    hd_result r;
    if ((r = hd__gl_mg_program(vw, p->stage, vw->kp.counts.z, &prog)) != HD_SUCCESS) return r;
    if (p->stage == HD__MG_DIR || p->stage == HD__MG_UPDATE) {
        if (p->stage == HD__MG_DIR) be->gl.ProgramUniform1f(prog, 1, p->beta);
        else be->gl.ProgramUniform1d(prog, 2, p->alpha);
        if ((r = hd__gl_check(vw, "multigrid's uniforms", __LINE__)) != HD_SUCCESS) return r;
    }
    hd__gl_mg_binds(vw, p->set, p->slot, &b);
    return hd__gl_run(vw, prog, hd__mg_stage_names[p->stage - 1], &b, p->n[0], p->n[1], p->n[2], p->pc[0], p->pc[1], p->pc[2],
                      p->pc[3]);
}

/* Level l's smoothing: the diffusion program (HD_FLAG_DIFFUSE_RHS variant) on its parameter block. */
static hd_result hd__be_mg_smooth(const hd__view *vw, int l, int sweeps, int first)
{
    hd__backend *be = vw->be;
    const int *d = be->gg.lv[l].dims;
    int slot = hd__gl_diffuse_slot(be->gg.lv[l].kp.counts.z), s, h;
    int ny = (d[1] + be->diffuse_yk - 1) / be->diffuse_yk, nzb = (d[2] + be->diffuse_zk - 1) / be->diffuse_zk;
    hd__gl_binds b;
    hd_result r;
    if ((r = hd__gl_program(vw, slot)) != HD_SUCCESS) return r;
    hd__gl_mg_binds(vw, HD__GPU_MG_SET(l, HD__GPU_MG_SMOOTH), l, &b);
    for (s = 0; s < sweeps; ++s)
        for (h = 0; h < 2; ++h)
            if ((r = hd__gl_run(vw, be->programs[slot], "multigrid smoothing", &b, (d[0] + 1) / 2, ny,
                                nzb * be->gg.channels, first ^ h, 0, nzb, 0)) != HD_SUCCESS)
                return r;
    return HD_SUCCESS;
}

/* ---- the step's primitives (src/hd_backend.h) ------------------------------------------------ */
/* Makes the levels and sends their parameter blocks. */
static hd_result hd__be_mg_begin(const hd__view *vw, int *fresh)
{
    hd_result r = hd__gpu_mg_begin(vw, &vw->be->gg, fresh);
    if (r == HD_SUCCESS) hd__gl_send_params(vw);
    return r;
}

/* A step ends complete, as OpenCL's clFinish (timings per step mean the step). */
static hd_result hd__be_mg_end(const hd__view *vw, hd_result r)
{
    if (r == HD_SUCCESS) {
        vw->be->gl.Finish();
        r = hd__gl_check(vw, "glFinish", __LINE__);
    }
    return r;
}

/* The row sums read into their host copy (glGetBufferSubData waits for the passes). */
static hd_result hd__be_mg_row_sums(const hd__view *vw, int n, const double **a, const double **b)
{
    hd__backend *be = vw->be;
    struct hd__gl_mg *mg = &be->mg;
    size_t rows = hd__gpu_mg_rows(&be->gg);
    int i;
    for (i = 0; i < n && i < 2; ++i) {
        be->gl.BindBuffer(GL_COPY_READ_BUFFER, i ? mg->dot_b : mg->dot_a);
        be->gl.GetBufferSubData(GL_COPY_READ_BUFFER, 0, (GLsizeiptr)(rows * sizeof(double)), mg->host_dot + i * rows);
        HD__GL_CHECK(vw, "reading multigrid's row sums");
    }
    *a = mg->host_dot;
    *b = mg->host_dot + rows;
    return HD_SUCCESS;
}

/* The single-level solver's sweeps: each its own dispatches. */
static hd_result hd__be_diffuse_sweeps(const hd__view *vw, int jacobi, int sweeps) { return hd__be_diffuse_each(vw, jacobi, sweeps); }

static hd_result hd__be_path(const hd__view *vw)
{
    return hd__gl_dispatch(vw, HD__GL_PATH, 0, vw->kp.image.x, vw->kp.image.y, 1, 0, 0, 0, 0);
}

/* ---- the image into the caller's texture ---------------------------------------------------------- */
/* The output format a texture's internal format takes (-1: none), and the pixel type of its copy. */
static int hd__gl_output_format(GLint internal, GLenum *type)
{
    *type = internal == GL_RGBA16F ? GL_HALF_FLOAT : internal == GL_RGBA32F ? GL_FLOAT : GL_UNSIGNED_BYTE;
    return internal == GL_RGBA8 || internal == GL_SRGB8_ALPHA8 ? HD_OUTPUT_SRGB8
           : internal == GL_RGBA16F                            ? HD_OUTPUT_LINEAR_F16
           : internal == GL_RGBA32F                            ? HD_OUTPUT_LINEAR_F32
                                                               : -1;
}

/* Binds the caller's texture to target on unit 0 and reads its level 0's size and internal format;
   a name that is not a texture of that target is HD_ERROR_INVALID_TEXTURE. */
static hd_result hd__gl_texture_query(const hd__view *vw, const char *fn, GLenum target, unsigned texture, GLint size[3], GLint *internal)
{
    hd__backend *be = vw->be;
    size[0] = size[1] = size[2] = 0;
    *internal = 0;
    be->gl.BindTexture(target, (GLuint)texture);
    if (be->gl.GetError() != GL_NO_ERROR)
        return HD__ERR(&vw->log, HD_ERROR_INVALID_TEXTURE, "%s: %u is not a %s texture name in the current context", fn, texture,
                       target == GL_TEXTURE_3D ? "3D" : "2D");
    be->gl.GetTexLevelParameteriv(target, 0, GL_TEXTURE_WIDTH, &size[0]);
    be->gl.GetTexLevelParameteriv(target, 0, GL_TEXTURE_HEIGHT, &size[1]);
    if (target == GL_TEXTURE_3D) be->gl.GetTexLevelParameteriv(target, 0, GL_TEXTURE_DEPTH, &size[2]);
    be->gl.GetTexLevelParameteriv(target, 0, GL_TEXTURE_INTERNAL_FORMAT, internal);
    return HD_SUCCESS;
}

static hd_result hd__be_output_texture(const hd__view *vw, unsigned texture, const hd_output *out, int exact)
{
    static const char *const names[HD_OUTPUT_FORMAT_COUNT] = {"GL_RGBA8 or GL_SRGB8_ALPHA8", "GL_RGBA16F", "GL_RGBA32F"};
    const char *fn = exact ? "hd_gl_render_to_texture" : "hd_gl_render_to_texture_ex";
    hd__backend *be = vw->be;
    GLint size[3], internal, w, h;
    GLenum type;
    int cw = out->width, ch = out->height;
    size_t bytes = (size_t)cw * ch * hd__output_pixel_bytes(out->format);
    hd_result r;
    if ((r = hd__gl_texture_query(vw, fn, GL_TEXTURE_2D, texture, size, &internal)) != HD_SUCCESS) return r;
    w = size[0], h = size[1];
    if (exact && (w != cw || h != ch || internal != GL_RGBA8))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_TEXTURE, "%s: texture %u is %dx%d, format 0x%04x; needs %dx%d GL_RGBA8 (the camera's size)",
                       fn, texture, (int)w, (int)h, (unsigned)internal, cw, ch);
    if (hd__gl_output_format(internal, &type) != (int)out->format)
        return HD__ERR(&vw->log, HD_ERROR_OUTPUT_FORMAT, "%s: texture %u has internal format 0x%04x; output format %d needs %s", fn,
                       texture, (unsigned)internal, (int)out->format, names[out->format]);
    if ((int64_t)out->x + cw > w || (int64_t)out->y + ch > h)
        return HD__ERR(&vw->log, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "%s: region %dx%d at (%d, %d) outside texture %u's %dx%d", fn, cw, ch,
                       out->x, out->y, texture, (int)w, (int)h);
    if ((r = hd__gl_program(vw, HD__GL_OUTPUT)) != HD_SUCCESS) return r;
    if (!be->otab) {
        float t[HD__OUTPUT_THRESHOLDS];
        hd__output_thresholds(t);
        if ((r = hd__gl_buffer_data(vw, &be->otab, sizeof t, t, GL_STATIC_DRAW, "the output's thresholds")) != HD_SUCCESS) return r;
    }
    if (be->obuf_bytes < bytes) {
        be->obuf_bytes = 0;
        if ((r = hd__gl_buffer_data(vw, &be->obuf, bytes, NULL, GL_STREAM_COPY, "the encoded image")) != HD_SUCCESS) return r;
        be->obuf_bytes = bytes;
    }
    be->gl.UseProgram(be->programs[HD__GL_OUTPUT]);
    be->gl.Uniform4i(0, cw, ch, (GLint)out->format, 1); /* rows bottom first */
    be->gl.Uniform1f(1, vw->params.exposure);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, be->otab);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, be->obuf);
    be->gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, be->img);
    be->gl.DispatchCompute((GLuint)((cw + HD__GL_LOCAL_X - 1) / HD__GL_LOCAL_X), (GLuint)ch, 1);
    be->gl.MemoryBarrier(GL_PIXEL_BUFFER_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
    /* the bracket left the unpack state at its defaults (alignment 4: rows of 4, 8 or 16 bytes a
       pixel are aligned) with no unpack buffer; texture unit 0's 2D binding is restored after */
    be->gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, be->obuf);
    be->gl.TexSubImage2D(GL_TEXTURE_2D, 0, out->x, out->y, cw, ch, GL_RGBA, type, NULL);
    be->gl.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    return hd__gl_check(vw, "the output into the texture", __LINE__);
}

/* E + phi's channel from lsum (the projection's summed copy, rebuilt first when stale) into the
   caller's GL_R32F 3D texture: one glCopyImageSubData of slices [c gz, (c + 1) gz). */
static hd_result hd__be_illumination_texture(const hd__view *vw, unsigned texture, int channel)
{
    const char *fn = "hd_gl_illumination_texture";
    hd__backend *be = vw->be;
    GLint size[3], internal, w, h, d;
    hd_result r;
    if ((r = hd__gl_texture_query(vw, fn, GL_TEXTURE_3D, texture, size, &internal)) != HD_SUCCESS) return r;
    w = size[0], h = size[1], d = size[2];
    if (internal != GL_R32F)
        return HD__ERR(&vw->log, HD_ERROR_OUTPUT_FORMAT, "%s: texture %u has internal format 0x%04x; the light needs GL_R32F", fn, texture,
                       (unsigned)internal);
    if (w < vw->gdims[0] || h < vw->gdims[1] || d < vw->gdims[2])
        return HD__ERR(&vw->log, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "%s: texture %u is %dx%dx%d, the illumination grid %dx%dx%d", fn, texture,
                       (int)w, (int)h, (int)d, vw->gdims[0], vw->gdims[1], vw->gdims[2]);
    if (!be->gg.lsum_ok) {
        if ((r = hd__gl_dispatch(vw, HD__GL_LIGHT_SUM, 0, vw->gdims[0], vw->gdims[1], vw->gdims[2] * vw->channels, 0, 0, 0, 0)) != HD_SUCCESS)
            return r;
        be->gg.lsum_ok = 1;
    }
    be->gl.MemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    be->gl.CopyImageSubData(be->lsum.name, GL_TEXTURE_3D, 0, 0, 0, channel * vw->gdims[2], (GLuint)texture, GL_TEXTURE_3D, 0, 0, 0, 0,
                            vw->gdims[0], vw->gdims[1], vw->gdims[2]);
    return hd__gl_check(vw, "copying the light into the texture", __LINE__);
}

/* The host's depth texture into dep: glGetTexImage into dep bound as the pixel pack buffer (a
   copy on the device), GL's rows as they are (kp.depth_dims.w says bottom first). A depth-stencil
   texture gives its depth with GL_DEPTH_COMPONENT. */
static hd_result hd__be_depth_texture(const hd__view *vw, unsigned texture)
{
    const char *fn = "hd_gl_set_depth_texture";
    hd__backend *be = vw->be;
    GLint size[3], internal, w, h;
    size_t bytes = (size_t)vw->camera.width * vw->camera.height * sizeof(float);
    hd_result r;
    if ((r = hd__gl_texture_query(vw, fn, GL_TEXTURE_2D, texture, size, &internal)) != HD_SUCCESS) return r;
    w = size[0], h = size[1];
    if (internal != GL_DEPTH_COMPONENT16 && internal != GL_DEPTH_COMPONENT24 && internal != GL_DEPTH_COMPONENT32F &&
        internal != GL_DEPTH24_STENCIL8 && internal != GL_DEPTH32F_STENCIL8)
        return HD__ERR(&vw->log, HD_ERROR_DEPTH_FORMAT, "%s: texture %u has internal format 0x%04x, not GL_DEPTH_COMPONENT16, 24, 32F, "
                       "GL_DEPTH24_STENCIL8 or GL_DEPTH32F_STENCIL8", fn, texture, (unsigned)internal);
    if (w != vw->camera.width || h != vw->camera.height)
        return HD__ERR(&vw->log, HD_ERROR_DEPTH_SIZE, "%s: texture %u is %dx%d, the camera %dx%d", fn, texture, (int)w, (int)h,
                       vw->camera.width, vw->camera.height);
    if ((r = hd__gl_buffer_data(vw, &be->dep, bytes, NULL, GL_DYNAMIC_COPY, "the depth buffer")) != HD_SUCCESS) return r;
    be->gl.MemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_FRAMEBUFFER_BARRIER_BIT);
    be->gl.BindBuffer(GL_PIXEL_PACK_BUFFER, be->dep);
    be->gl.GetTexImage(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    be->gl.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    be->gl.MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    return hd__gl_check(vw, "copying the depth texture", __LINE__);
}

static unsigned hd__be_features(void) { return HD__BE_TEXTURE; }

/* No recording (a Vulkan feature): the core never calls these. */
HD__BE_NO_RECORDING("gl")
HD__BE_NO_CL_BUFFER("gl")
