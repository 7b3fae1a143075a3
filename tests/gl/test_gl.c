/* test_gl.c - the GL backend's own checks (make test-gl):
   1. host state survives: a host GL context (EGL, surfaceless) with its own program, uniform and
      storage buffer bindings (ranges), image units, active texture, 2D/3D textures, generic
      buffer bindings and pixel store parameters; hd_create / hd_set_* / hd_iterate /
      hd_read_image_* / hd_read_illumination / hd_gl_render_to_texture(_ex) / hd_destroy on
      (a) the caller's context (desc.gl.use_current_context) and (b) the backend's own EGL
      context while the host's is current; every queried value is unchanged afterwards, the
      host's context is still current and no GL error is pending;
   2. hd_gl_render_to_texture writes the same pixels as hd_read_image_rgba8 (rows flipped: GL's
      bottom-first order), within 1/255 (the GPU's sRGB pow and unorm rounding), every method;
   3. a texture of the wrong size or format is refused with HD_ERROR_INVALID_TEXTURE, and the
      other backends' hd_gl_render_to_texture is HD_ERROR_UNSUPPORTED (tests/test_core.c side:
      the CPU build of this call is compiled in every other test program).
   4. float16 illumination stores: hdk_f16_round (hd_prelude_glsl.h, the embedded GLSL) and an
      r16f imageStore give hdk_f2h's bits (the CPU's round to nearest even) for every finite half,
      both signs, the midpoint above it (a tie) and the floats either side of that midpoint,
      and for overflow (>= 65520: inf) and inf; the same store without hdk_f16_round is counted
      and printed (llvmpipe truncates), not checked: a driver may round.
   5. the caller's context (use_current_context) not current, or another one current: hd_iterate
      and hd_read_image_f32 return HD_ERROR_GL_CONTEXT_NOT_CURRENT with one logged error and count
      no iteration; with it current again the context goes on from the iterations that ran.
   6. a device limit that holds the image but not its reduced frames' region: the first frame at
      render scale 2 fails with HD_ERROR_UNSUPPORTED and one logged error, full frames go on.
   7. the driver compiles every stage without a warning: the backend's own (debug) context, the
      shader cache off (MESA_SHADER_CACHE_DISABLE, set before EGL starts), each method, solver
      and boundary iterated once; no "gl debug" line logged (Mesa warned "used uninitialized"
      of every variable passed to an inout parameter before it was initialised).
   8. hd_gl_render_to_texture_ex, each output format into a region at (13, 9) of a 70x60
      texture: GL_RGBA8 and GL_SRGB8_ALPHA8 (HD_OUTPUT_SRGB8), GL_RGBA16F (LINEAR_F16), GL_RGBA32F
      (LINEAR_F32), read back with glGetTexImage: the region (rows bottom first) is bit for bit
      hd_read_image_ex's bytes of the same format and, independently, hd_read_image_rgba8's
      (RGBA8), hdk_f2h of hd_read_image_f32 times the exposure (half), that product itself
      (float); every texel outside the region keeps the pattern written before. A region past the
      texture's edge or at a negative x, a format the texture does not take, a region of another
      size than the camera's and a name that is no 2D texture: each its own hd_result and one
      logged error, nothing written, and the context renders on.
   9. the output pass's encodings where they are hardest (every RGBA8 threshold and the float
      below it, every finite half, the ties between halves and the floats either side of them),
      written into the image buffer: each format bit for bit hd_read_image_ex's, exposure 1 and
      0.75.
   10. hd_gl_illumination_texture: E + phi into the caller's GL_R32F 3D texture (the grid's size,
      and a larger one whose texels beyond the grid keep their pattern), read back with
      glGetTexImage: bit for bit hd_read_illumination's HD_ILLUMINATION_TOTAL, which is E + phi
      of the DIRECT and SCATTERED read-backs; after more iterations it follows the light; each
      channel of a 3-channel grid. A 2D texture, a GL_R16F one, one smaller than the grid, a
      channel past the grid's, texture 0: each its own hd_result and one logged error, nothing
      written, and the context goes on.
   11. hd_gl_set_depth_texture: the host's GL_DEPTH_COMPONENT32F and GL_DEPTH_COMPONENT24 textures
      (a wall over the left third and the bottom half, a post through the middle; GL's rows,
      bottom first) give bit for bit the image
      of hd_set_depth with the same values (rows flipped to top first), which differs from the
      image without depth; hd_set_depth(NULL) then gives the image without depth. An RGBA8
      texture, one of another size, a 3D texture, texture 0 and a look-at camera: each its own
      hd_result and one logged error, and the depth held before stays.
   Not tested here: a shader compile failure (the shaders are fixed strings; the path is the
   driver's info log into HD__ERR) and KHR_debug delivery. */
#define GL_GLEXT_PROTOTYPES /* before hybriddiff.h, which includes GL/glcorearb.h */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_BACKEND_GL
#include "hybriddiff.h"
#include <GL/glcorearb.h>
#include <stdio.h>
#include <stdlib.h>

static int failures;
#define CHECK(cond, ...) do { if (!(cond)) { printf("FAIL %s:%d: ", __FILE__, __LINE__); printf(__VA_ARGS__); printf("\n"); ++failures; } } while (0)

typedef struct host_state {
    GLint v[128];
    GLint64 v64[16];
    int n, n64;
} host_state;

static void snap(host_state *s)
{
    static const GLenum pix[16] = {GL_PACK_ALIGNMENT, GL_PACK_ROW_LENGTH, GL_PACK_IMAGE_HEIGHT, GL_PACK_SKIP_PIXELS,
                                   GL_PACK_SKIP_ROWS, GL_PACK_SKIP_IMAGES, GL_PACK_SWAP_BYTES, GL_PACK_LSB_FIRST,
                                   GL_UNPACK_ALIGNMENT, GL_UNPACK_ROW_LENGTH, GL_UNPACK_IMAGE_HEIGHT, GL_UNPACK_SKIP_PIXELS,
                                   GL_UNPACK_SKIP_ROWS, GL_UNPACK_SKIP_IMAGES, GL_UNPACK_SWAP_BYTES, GL_UNPACK_LSB_FIRST};
    static const GLenum gen[7] = {GL_UNIFORM_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_BINDING, GL_COPY_READ_BUFFER_BINDING,
                                  GL_COPY_WRITE_BUFFER_BINDING, GL_PIXEL_PACK_BUFFER_BINDING, GL_PIXEL_UNPACK_BUFFER_BINDING,
                                  GL_ARRAY_BUFFER_BINDING};
    static const GLenum img[6] = {GL_IMAGE_BINDING_NAME, GL_IMAGE_BINDING_LEVEL, GL_IMAGE_BINDING_LAYERED,
                                  GL_IMAGE_BINDING_LAYER, GL_IMAGE_BINDING_ACCESS, GL_IMAGE_BINDING_FORMAT};
    GLint active;
    int i, j, u;
    s->n = s->n64 = 0;
    glGetIntegerv(GL_CURRENT_PROGRAM, &s->v[s->n++]);
    glGetIntegerv(GL_ACTIVE_TEXTURE, &active);
    s->v[s->n++] = active;
    for (u = 0; u < 4; ++u) { /* texture bindings of units 0..3 */
        glActiveTexture((GLenum)(GL_TEXTURE0 + u));
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &s->v[s->n++]);
        glGetIntegerv(GL_TEXTURE_BINDING_3D, &s->v[s->n++]);
    }
    glActiveTexture((GLenum)active);
    for (i = 0; i < 16; ++i) glGetIntegerv(pix[i], &s->v[s->n++]);
    for (i = 0; i < 7; ++i) glGetIntegerv(gen[i], &s->v[s->n++]);
    for (i = 0; i < 8; ++i)
        for (j = 0; j < 6; ++j) glGetIntegeri_v(img[j], (GLuint)i, &s->v[s->n++]);
    for (i = 0; i < 4; ++i) {
        glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, (GLuint)i, &s->v[s->n++]);
        glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, (GLuint)i, &s->v64[s->n64++]);
        glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, (GLuint)i, &s->v64[s->n64++]);
    }
    glGetIntegeri_v(GL_UNIFORM_BUFFER_BINDING, 0, &s->v[s->n++]);
    glGetInteger64i_v(GL_UNIFORM_BUFFER_START, 0, &s->v64[s->n64++]);
    glGetInteger64i_v(GL_UNIFORM_BUFFER_SIZE, 0, &s->v64[s->n64++]);
}

static void compare(const host_state *a, const host_state *b, const char *what)
{
    int i, bad = 0;
    for (i = 0; i < a->n; ++i)
        if (a->v[i] != b->v[i]) { printf("  %s: state value %d was %d, is %d\n", what, i, (int)a->v[i], (int)b->v[i]); ++bad; }
    for (i = 0; i < a->n64; ++i)
        if (a->v64[i] != b->v64[i]) { printf("  %s: 64-bit state value %d was %lld, is %lld\n", what, i, (long long)a->v64[i], (long long)b->v64[i]); ++bad; }
    CHECK(bad == 0, "%s: %d host state values changed", what, bad);
}

/* A host application's state: everything the backend touches set to something non-default. */
static void set_host_state(void)
{
    static const char *src = "#version 430 core\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER), prog = glCreateProgram(), bufs[6], tex[4];
    int i;
    glShaderSource(sh, 1, &src, NULL);
    glCompileShader(sh);
    glAttachShader(prog, sh);
    glLinkProgram(prog);
    glUseProgram(prog);
    glGenBuffers(6, bufs);
    for (i = 0; i < 6; ++i) {
        glBindBuffer(GL_COPY_WRITE_BUFFER, bufs[i]);
        glBufferData(GL_COPY_WRITE_BUFFER, 4096, NULL, GL_STATIC_DRAW);
    }
    glBindBufferRange(GL_UNIFORM_BUFFER, 0, bufs[0], 256, 512);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 0, bufs[1], 256, 1024);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bufs[2]);
    glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 2, bufs[3], 512, 256);
    glBindBuffer(GL_UNIFORM_BUFFER, bufs[4]);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[5]);
    glBindBuffer(GL_COPY_READ_BUFFER, bufs[0]);
    glBindBuffer(GL_COPY_WRITE_BUFFER, bufs[1]);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, bufs[2]);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, bufs[3]);
    glBindBuffer(GL_ARRAY_BUFFER, bufs[4]);
    glGenTextures(4, tex);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, tex[0]);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 4, 4);
    glBindTexture(GL_TEXTURE_3D, tex[1]);
    glTexStorage3D(GL_TEXTURE_3D, 1, GL_R32F, 4, 4, 4);
    glBindImageTexture(0, tex[0], 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA8);
    glBindImageTexture(3, tex[1], 0, GL_TRUE, 0, GL_WRITE_ONLY, GL_R32F);
    glBindImageTexture(6, tex[1], 0, GL_FALSE, 2, GL_READ_WRITE, GL_R32F);
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D, tex[2]);
    glBindTexture(GL_TEXTURE_3D, tex[3]);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glPixelStorei(GL_PACK_ROW_LENGTH, 7);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 2);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 5);
    glPixelStorei(GL_UNPACK_SKIP_IMAGES, 1);
    glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 3);
    CHECK(glGetError() == GL_NO_ERROR, "setting the host state raised a GL error");
}

static const float tf[] = {0, 0, 0, 0, 0.9f, 0.6f, 0.5f, 0.1f, 1, 1, 0.9f, 0.6f, 1, 1, 1, 1};

static void make_desc(hd_desc *d, uint8_t *vox, int n)
{
    int x, y, z;
    for (z = 0; z < n; ++z)
        for (y = 0; y < n; ++y)
            for (x = 0; x < n; ++x) {
                float u = (x + 0.5f) / n - 0.5f, v = (y + 0.5f) / n - 0.5f, w = (z + 0.5f) / n - 0.5f;
                float r = sqrtf(u * u + v * v + w * w);
                vox[(z * n + y) * n + x] = (uint8_t)(r < 0.4f ? 255.0f * (1.0f - r / 0.4f) : 0.0f);
            }
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = n;
    d->volume.data = vox;
    d->transfer_function.rgba = tf;
    d->transfer_function.count = 4;
    d->camera.width = 48;
    d->camera.height = 40;
    d->params.seed = 7;
    d->params.illumination_downsample = 1; /* the paper's grid and boundary: the buffer sizes below */
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
}

/* Every call a host app makes, with the host's state checked around it all. */
static void run_calls(int use_current, const char *what)
{
    static uint8_t vox[24 * 24 * 24];
    static float img[48 * 40 * 4], illum[24 * 24 * 24];
    static uint8_t px[48 * 40 * 4], tpx[48 * 40 * 4];
    static const hd_method methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};
    host_state before, after;
    EGLContext cur = eglGetCurrentContext();
    hd_desc d;
    hd_context c;
    hd_result r;
    GLuint tex, wrong, tex16;
    hd_output o16 = HD_OUTPUT_INIT;
    int m, i, maxd;
    make_desc(&d, vox, 24);
    d.gl.use_current_context = use_current;
    d.logger.func = hd_log_stderr;
    /* the texture is made before the snapshot: it is the host's */
    glGenTextures(1, &tex);
    glGenTextures(1, &wrong);
    glGenTextures(1, &tex16);
    {
        GLint prev;
        glGetIntegerv(GL_TEXTURE_BINDING_2D, &prev);
        glBindTexture(GL_TEXTURE_2D, tex16);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, 64, 64, 0, GL_RGBA, GL_FLOAT, NULL); /* mutable storage */
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 48, 40);
        glBindTexture(GL_TEXTURE_2D, wrong);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, 40, 48);
        glBindTexture(GL_TEXTURE_2D, (GLuint)prev);
    }
    set_host_state();
    snap(&before);
    r = hd_create(&d, &c);
    CHECK(r == HD_SUCCESS, "%s: hd_create: %s", what, hd_result_string(r));
    if (r != HD_SUCCESS) return;
    for (m = 0; m < 4; ++m) {
        hd_params p;
        hd_query_desc(c, &d);
        p = d.params;
        p.method = methods[m];
        CHECK(hd_set_params(c, &p) == HD_SUCCESS, "%s: set_params", what);
        r = hd_iterate(c, 3);
        CHECK(r == HD_SUCCESS, "%s %s: hd_iterate: %s", what, hd_method_name(methods[m]), hd_result_string(r));
        CHECK(hd_read_image_f32(c, img, sizeof img / sizeof img[0]) == HD_SUCCESS, "%s: read f32", what);
        CHECK(hd_read_image_rgba8(c, px, sizeof px) == HD_SUCCESS, "%s: read rgba8", what);
        if (m < 2) CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, illum, sizeof illum / sizeof illum[0]) == HD_SUCCESS, "%s: illum", what);
        r = hd_gl_render_to_texture(c, tex);
        CHECK(r == HD_SUCCESS, "%s: hd_gl_render_to_texture: %s", what, hd_result_string(r));
        o16.format = HD_OUTPUT_LINEAR_F16;
        o16.x = 5;
        o16.y = 11;
        r = hd_gl_render_to_texture_ex(c, tex16, &o16);
        CHECK(r == HD_SUCCESS, "%s: hd_gl_render_to_texture_ex: %s", what, hd_result_string(r));
        /* the texture's pixels (read on the host's context, default pack state) */
        {
            host_state mid;
            GLint prev;
            snap(&mid);
            compare(&before, &mid, what);
            glGetIntegerv(GL_TEXTURE_BINDING_2D, &prev);
            glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
            glPixelStorei(GL_PACK_ALIGNMENT, 4);
            glPixelStorei(GL_PACK_ROW_LENGTH, 0);
            glBindTexture(GL_TEXTURE_2D, tex);
            glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, tpx);
            glBindTexture(GL_TEXTURE_2D, (GLuint)prev);
            glPixelStorei(GL_PACK_ALIGNMENT, 1);
            glPixelStorei(GL_PACK_ROW_LENGTH, 7);
            glBindBuffer(GL_PIXEL_PACK_BUFFER, (GLuint)before.v[2 + 8 + 16 + 4]);
        }
        maxd = 0;
        for (i = 0; i < 48 * 40 * 4; ++i) {
            int y = i / (48 * 4), rest = i % (48 * 4);
            int dv = abs((int)tpx[(39 - y) * 48 * 4 + rest] - (int)px[i]);
            if (dv > maxd) maxd = dv;
        }
        CHECK(maxd <= 1, "%s %s: render_to_texture differs from hd_read_image_rgba8 by %d/255", what, hd_method_name(methods[m]), maxd);
        printf("%s %s: render_to_texture vs read_image_rgba8: max difference %d/255\n", what, hd_method_name(methods[m]), maxd);
    }
    r = hd_gl_render_to_texture(c, wrong);
    CHECK(r == HD_ERROR_INVALID_TEXTURE, "%s: a 40x48 texture for a 48x40 image: %s", what, hd_result_string(r));
    CHECK(hd_destroy(c) == HD_SUCCESS, "%s: destroy", what);
    snap(&after);
    compare(&before, &after, what);
    CHECK(eglGetCurrentContext() == cur, "%s: the host's EGL context is no longer current", what);
    CHECK(glGetError() == GL_NO_ERROR, "%s: a GL error is pending after the calls", what);
    glDeleteTextures(1, &tex);
    glDeleteTextures(1, &wrong);
    glDeleteTextures(1, &tex16);
}

/* The prelude's text (source string 2 of hd_glsl_embedded.h) between #version and a main()
   that stores hdk_f16_round(src[i]) (or src[i] itself, raw != 0) into an r16f 512x512 image. */
static GLuint round_program(int raw)
{
    static const char *head = "#version 430 core\n#define HD_GLSL_CUSTOM_BUFFERS 1\n";
    static const char *tail =
        "layout(local_size_x = 64) in;\n"
        "layout(std430, binding = 0) readonly buffer hd_t_in { float src[]; };\n"
        "layout(binding = 0, r16f) uniform writeonly image2D hd_t_out;\n"
        "void main() {\n"
        "    int i = int(gl_GlobalInvocationID.x);\n"
        "    imageStore(hd_t_out, ivec2(i % 512, i / 512), vec4(HD_T_ROUND(src[i]), 0.0, 0.0, 0.0));\n"
        "}\n";
    const char *src[3 + HD__GL_SOURCE_LINES];
    GLsizei n = 0;
    size_t i;
    int in = 0;
    GLint ok = 0;
    GLuint sh = glCreateShader(GL_COMPUTE_SHADER), prog = glCreateProgram();
    src[n++] = head;
    src[n++] = raw ? "#define HD_T_ROUND(v) (v)\n" : "#define HD_T_ROUND(v) hdk_f16_round(v)\n";
    for (i = 0; i < HD__GL_SOURCE_LINES; ++i) {
        if (strncmp(hd__gl_source[i], "#line 1 ", 8) == 0) in = strcmp(hd__gl_source[i], "#line 1 2\n") == 0;
        else if (in) src[n++] = hd__gl_source[i];
    }
    src[n++] = tail;
    glShaderSource(sh, n, src, NULL);
    glCompileShader(sh);
    glGetShaderiv(sh, GL_COMPILE_STATUS, &ok);
    CHECK(ok, "the rounding shader does not compile");
    glAttachShader(prog, sh);
    glLinkProgram(prog);
    glDeleteShader(sh);
    return prog;
}

/* Check 4: returns how many of the stores differ from hdk_f2h. */
static int round_mismatches(const float *in, int count, int raw)
{
    static uint16_t out[512 * 512];
    GLuint prog = round_program(raw), buf, tex;
    int i, bad = 0;
    glGenBuffers(1, &buf);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buf);
    glBufferData(GL_SHADER_STORAGE_BUFFER, (GLsizeiptr)(512 * 512 * sizeof(float)), NULL, GL_STATIC_DRAW);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, (GLsizeiptr)(count * sizeof(float)), in);
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_R16F, 512, 512);
    glUseProgram(prog);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, buf);
    glBindImageTexture(0, tex, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R16F);
    glDispatchCompute((GLuint)(count + 63) / 64, 1, 1);
    glMemoryBarrier(GL_ALL_BARRIER_BITS);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RED, GL_HALF_FLOAT, out);
    for (i = 0; i < count; ++i) {
        uint16_t want = hdk_f2h(in[i]);
        if (out[i] != want) {
            if (!raw && bad < 5) printf("  hdk_f16_round: %.9g (0x%08x) stored 0x%04x, hdk_f2h 0x%04x\n", in[i], (unsigned)hdk_f2u(in[i]), out[i], want);
            ++bad;
        }
    }
    glUseProgram(0);
    glDeleteProgram(prog);
    glDeleteBuffers(1, &buf);
    glDeleteTextures(1, &tex);
    return bad;
}

static void check_f16_round(void)
{
    static float in[512 * 512];
    int n = 0, s, bad, raw;
    uint32_t h;
    for (s = 0; s < 2; ++s) {
        uint16_t sign = (uint16_t)(s << 15);
        for (h = 0; h < 0x7c00u; ++h) {
            /* the midpoint of two neighbouring halves has 12 significant bits: exact in float;
               above the largest half (65504) the midpoint is 65520, where inf begins */
            float v = hdk_h2f((uint16_t)(sign | h)), mid = h < 0x7bffu ? 0.5f * (v + hdk_h2f((uint16_t)(sign | (h + 1)))) : (s ? -65520.0f : 65520.0f);
            in[n++] = v;
            in[n++] = mid;
            in[n++] = hdk_u2f(hdk_f2u(mid) - 1u);
            in[n++] = hdk_u2f(hdk_f2u(mid) + 1u);
        }
        in[n++] = s ? -1e30f : 1e30f;
        in[n++] = hdk_u2f(hdk_f2u(1.0f / 0.0f) | ((uint32_t)s << 31));
    }
    bad = round_mismatches(in, n, 0);
    raw = round_mismatches(in, n, 1);
    CHECK(bad == 0, "hdk_f16_round + r16f imageStore: %d of %d values differ from hdk_f2h", bad, n);
    printf("float16 stores: hdk_f16_round + r16f imageStore equal hdk_f2h for %d of %d values; the raw store for %d (the driver's own conversion)\n",
           n - bad, n, n - raw);
}

static int nc_errors;
static hd_result nc_last;
static void nc_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *f, int l)
{
    (void)u; (void)msg; (void)f; (void)l;
    if (level == HD_LOG_ERROR) { ++nc_errors; nc_last = code; }
}

/* Check 7: no driver warning from compiling any stage (the KHR_debug messages the backend logs
   as "gl debug" warnings in a debug build). */
static int warn_count;
static void warn_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *f, int l)
{
    (void)u; (void)code; (void)f; (void)l;
    if (level == HD_LOG_WARNING && strstr(msg, "gl debug")) {
        if (++warn_count <= 3) printf("  %s\n", msg);
    }
}
static void check_shader_warnings(void)
{
    static uint8_t vox[16 * 16 * 16];
    static const hd_method methods[3] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_MS};
    static const hd_solver solvers[2] = {HD_SOLVER_RED_BLACK, HD_SOLVER_MULTIGRID};
    static const hd_boundary bounds[2] = {HD_BOUNDARY_BOX, HD_BOUNDARY_SURFACE};
    int m, s, b, runs = 0;
    warn_count = 0;
    for (m = 0; m < 3; ++m)
        for (s = 0; s < 2; ++s)
            for (b = 0; b < 2; ++b) {
                hd_desc d;
                hd_context c;
                hd_result r;
                make_desc(&d, vox, 16);
                d.logger.func = warn_log;
                d.params.method = methods[m];
                d.params.solver = solvers[s];
                d.params.diffusion_boundary = bounds[b];
                r = hd_create(&d, &c);
                CHECK(r == HD_SUCCESS, "shader warnings: hd_create: %s", hd_result_string(r));
                if (r != HD_SUCCESS) continue;
                CHECK(hd_iterate(c, 1) == HD_SUCCESS, "shader warnings: hd_iterate");
                hd_destroy(c);
                ++runs;
            }
    CHECK(warn_count == 0, "shader warnings: %d gl debug warnings over %d contexts", warn_count, runs);
    printf("%s shader warnings: %d over %d contexts (3 methods x 2 solvers x 2 boundaries, shader cache off)\n",
           warn_count == 0 ? "PASS" : "FAIL", warn_count, runs);
}

/* Check 5: calls on a caller's-context backend whose context is not current. */
static void check_not_current(EGLDisplay dpy, EGLConfig cfg, const EGLint *attrs, EGLContext host)
{
    static uint8_t vox[16 * 16 * 16];
    static float img[48 * 40 * 4];
    EGLContext other = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, attrs);
    hd_desc d;
    hd_context c;
    hd_stats st;
    hd_result r;
    int k;
    make_desc(&d, vox, 16);
    d.gl.use_current_context = 1;
    d.logger.func = nc_log;
    CHECK(other != EGL_NO_CONTEXT, "not current: a second EGL context");
    r = hd_create(&d, &c);
    CHECK(r == HD_SUCCESS, "not current: hd_create: %s", hd_result_string(r));
    if (r != HD_SUCCESS) return;
    CHECK(hd_iterate(c, 1) == HD_SUCCESS, "not current: first iterate");
    for (k = 0; k < 2; ++k) { /* none current, then another one */
        const char *what = k == 0 ? "no context current" : "another context current";
        eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, k == 0 ? EGL_NO_CONTEXT : other);
        nc_errors = 0;
        r = hd_iterate(c, 2);
        CHECK(r == HD_ERROR_GL_CONTEXT_NOT_CURRENT && nc_errors == 1 && nc_last == r, "%s: hd_iterate: %s, %d errors",
              what, hd_result_string(r), nc_errors);
        nc_errors = 0;
        r = hd_read_image_f32(c, img, sizeof img / sizeof img[0]);
        CHECK(r == HD_ERROR_GL_CONTEXT_NOT_CURRENT && nc_errors == 1, "%s: hd_read_image_f32: %s, %d errors", what,
              hd_result_string(r), nc_errors);
        CHECK(hd_get_stats(c, &st) == HD_SUCCESS && st.iterations == 1, "%s: %llu iterations counted, 1 ran", what,
              (unsigned long long)st.iterations);
    }
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, host);
    nc_errors = 0;
    CHECK(hd_iterate(c, 2) == HD_SUCCESS && nc_errors == 0, "not current: iterate with the context current again");
    CHECK(hd_get_stats(c, &st) == HD_SUCCESS && st.iterations == 3, "not current: %llu iterations after 3 ran",
          (unsigned long long)st.iterations);
    CHECK(hd_read_image_f32(c, img, sizeof img / sizeof img[0]) == HD_SUCCESS, "not current: read with the context current");
    hd_destroy(c);
    if (other != EGL_NO_CONTEXT) eglDestroyContext(dpy, other);
}

/* Check 6: the image buffer's reduced frames' region comes with the first frame at a render
   scale > 1; a device whose largest storage block holds the image but not the region (the
   limit lowered to the image's size) fails that frame with HD_ERROR_UNSUPPORTED and one logged
   error, keeps its image buffer and renders full frames on; with the limit back, scale 2 works
   and hd_stats.image_bytes counts the region. */
static void check_image_room(void)
{
    static uint8_t vox[16 * 16 * 16];
    hd_desc d;
    hd_context c;
    hd_stats st;
    hd_params p;
    hd_result r;
    hd__ctx *ctx;
    GLint limit;
    size_t full = (size_t)48 * 40 * 20, room = (size_t)24 * 20 * 16; /* the image with its depth plane */
    make_desc(&d, vox, 16);
    d.gl.use_current_context = 1;
    d.logger.func = nc_log;
    nc_errors = 0;
    r = hd_create(&d, &c);
    CHECK(r == HD_SUCCESS, "image room: hd_create: %s", hd_result_string(r));
    if (r != HD_SUCCESS) return;
    ctx = hd__lookup(c);
    CHECK(hd_iterate(c, 1) == HD_SUCCESS && hd_get_stats(c, &st) == HD_SUCCESS && st.image_bytes == full,
          "image room: %zu image bytes at scale 1, want %zu", st.image_bytes, full);
    limit = ctx->vw.be->max_ssbo_block;
    ctx->vw.be->max_ssbo_block = (GLint)full;
    p = d.params;
    p.render_scale = 2;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS, "image room: render_scale 2");
    r = hd_iterate(c, 1);
    CHECK(r == HD_ERROR_UNSUPPORTED && nc_errors == 1 && nc_last == r, "image room: scale 2 above the limit: %s, %d errors",
          hd_result_string(r), nc_errors);
    CHECK(hd_get_stats(c, &st) == HD_SUCCESS && st.image_bytes == full, "image room: %zu bytes after the failure", st.image_bytes);
    p.render_scale = 1;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS && hd_iterate(c, 1) == HD_SUCCESS && nc_errors == 1, "image room: scale 1 after it");
    ctx->vw.be->max_ssbo_block = limit;
    p.render_scale = 2;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS && hd_iterate(c, 2) == HD_SUCCESS && hd_get_stats(c, &st) == HD_SUCCESS &&
              st.image_bytes == full + room && st.render_scale == 2 && nc_errors == 1,
          "image room: scale 2 with the limit back: %zu bytes, scale %d", st.image_bytes, st.render_scale);
    hd_destroy(c);
}

/* Check 8: the output formats into a region of a larger texture. */
static int out_errors;
static hd_result out_last;
static void out_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *f, int l)
{
    (void)u; (void)f; (void)l;
    if (level == HD_LOG_ERROR) { ++out_errors; out_last = code; printf("  logged: %s\n", msg); }
}

enum { TW = 70, TH = 60, RX = 13, RY = 9, IW = 48, IH = 40 };

/* A TW x TH texture of internal format `internal` filled with a byte pattern (type's texels). */
static GLuint pattern_texture(GLenum internal, GLenum type, size_t px, unsigned char *pat)
{
    GLuint t;
    GLint prev;
    size_t i;
    for (i = 0; i < (size_t)TW * TH * px; ++i) pat[i] = (unsigned char)(i * 131u + 7u);
    if (type == GL_HALF_FLOAT) /* keep the halves finite (no NaN payload games): exponent below 31 */
        for (i = 1; i < (size_t)TW * TH * px; i += 2) pat[i] &= 0x3f;
    if (type == GL_FLOAT)
        for (i = 3; i < (size_t)TW * TH * px; i += 4) pat[i] &= 0x3f;
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &prev);
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, internal, TW, TH);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_IMAGES, 0);
    glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, TW, TH, GL_RGBA, type, pat);
    glBindTexture(GL_TEXTURE_2D, (GLuint)prev);
    return t;
}

static void read_texture(GLuint t, GLenum type, unsigned char *dst)
{
    GLint prev;
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &prev);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glBindTexture(GL_TEXTURE_2D, t);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, type, dst);
    glBindTexture(GL_TEXTURE_2D, (GLuint)prev);
}

static void check_output_formats(void)
{
    static const GLenum internals[4] = {GL_RGBA8, GL_SRGB8_ALPHA8, GL_RGBA16F, GL_RGBA32F};
    static const GLenum types[4] = {GL_UNSIGNED_BYTE, GL_UNSIGNED_BYTE, GL_HALF_FLOAT, GL_FLOAT};
    static const hd_output_format formats[4] = {HD_OUTPUT_SRGB8, HD_OUTPUT_SRGB8, HD_OUTPUT_LINEAR_F16, HD_OUTPUT_LINEAR_F32};
    static const char *const names[4] = {"GL_RGBA8", "GL_SRGB8_ALPHA8", "GL_RGBA16F", "GL_RGBA32F"};
    static uint8_t vox[24 * 24 * 24], px8[IW * IH * 4];
    static float img[IW * IH * 4];
    static unsigned char pat[TW * TH * 16], got[TW * TH * 16], ex[TW * TH * 16];
    hd_desc d;
    hd_context c;
    hd_output o = HD_OUTPUT_INIT;
    hd_params p;
    hd_result r;
    float e = 1.7f;
    int k;
    make_desc(&d, vox, 24);
    d.gl.use_current_context = 1;
    d.logger.func = out_log;
    d.params.exposure = e;
    out_errors = 0;
    r = hd_create(&d, &c);
    CHECK(r == HD_SUCCESS, "output formats: hd_create: %s", hd_result_string(r));
    if (r != HD_SUCCESS) return;
    CHECK(hd_iterate(c, 3) == HD_SUCCESS, "output formats: iterate");
    for (k = 0; k < 4; ++k) {
        size_t pxb = formats[k] == HD_OUTPUT_LINEAR_F32 ? 16 : formats[k] == HD_OUTPUT_LINEAR_F16 ? 8 : 4;
        GLuint t = pattern_texture(internals[k], types[k], pxb, pat);
        int x, y, outside = 0, vs_ex = 0, vs_ref = 0, nonzero = 0;
        CHECK(hd_read_image_f32(c, img, sizeof img / sizeof img[0]) == HD_SUCCESS, "output formats: read f32");
        CHECK(hd_read_image_rgba8(c, px8, sizeof px8) == HD_SUCCESS, "output formats: read rgba8");
        o.format = formats[k];
        o.x = RX;
        o.y = RY;
        r = hd_gl_render_to_texture_ex(c, t, &o);
        CHECK(r == HD_SUCCESS, "output %s: %s", names[k], hd_result_string(r));
        read_texture(t, types[k], got);
        /* the same format read back into the same region of a TW x TH host image, top row first */
        memset(ex, 0, sizeof ex);
        CHECK(hd_read_image_ex(c, &o, ex, (size_t)TW * TH * pxb, (size_t)TW * pxb) == HD_SUCCESS, "output %s: read_image_ex", names[k]);
        for (y = 0; y < TH; ++y)
            for (x = 0; x < TW; ++x) {
                const unsigned char *g = got + ((size_t)y * TW + x) * pxb;
                int in = x >= RX && x < RX + IW && y >= RY && y < RY + IH;
                if (!in) {
                    outside += memcmp(g, pat + ((size_t)y * TW + x) * pxb, pxb) != 0;
                    continue;
                }
                {
                    int ix = x - RX, iy = IH - 1 - (y - RY); /* GL rows bottom first */
                    const float *f = img + ((size_t)iy * IW + ix) * 4;
                    unsigned char want[16];
                    int c4;
                    vs_ex += memcmp(g, ex + ((size_t)(RY + iy) * TW + x) * pxb, pxb) != 0;
                    if (formats[k] == HD_OUTPUT_SRGB8) {
                        memcpy(want, px8 + ((size_t)iy * IW + ix) * 4, 4);
                    } else if (formats[k] == HD_OUTPUT_LINEAR_F16) {
                        uint16_t hv[4];
                        for (c4 = 0; c4 < 4; ++c4) hv[c4] = hdk_f2h(c4 < 3 ? f[c4] * e : f[c4]);
                        memcpy(want, hv, 8);
                    } else {
                        float fv[4];
                        for (c4 = 0; c4 < 4; ++c4) fv[c4] = c4 < 3 ? f[c4] * e : f[c4];
                        memcpy(want, fv, 16);
                    }
                    vs_ref += memcmp(g, want, pxb) != 0;
                    for (c4 = 0; c4 < (int)pxb; ++c4) nonzero += g[c4] != 0;
                }
            }
        CHECK(outside == 0 && vs_ex == 0 && vs_ref == 0 && nonzero > 0,
              "output %s: %d texels outside the region changed, %d region texels differ from hd_read_image_ex, %d from the reference",
              names[k], outside, vs_ex, vs_ref);
        printf("%s output %s (%s) into (%d, %d) of %dx%d: %d of %d texels differ from hd_read_image_ex, %d from the reference, %d outside changed\n",
               outside || vs_ex || vs_ref ? "FAIL" : "PASS", names[k], formats[k] == HD_OUTPUT_SRGB8 ? "SRGB8" : formats[k] == HD_OUTPUT_LINEAR_F16 ? "LINEAR_F16" : "LINEAR_F32",
               RX, RY, TW, TH, vs_ex, IW * IH, vs_ref, outside);
        if (k == 2) { /* bad input on the RGBA16F texture: one error each, the texture untouched */
            struct { hd_output_format f; int x, y, w, h; hd_result want; const char *what; } cases[5] = {
                {HD_OUTPUT_LINEAR_F16, TW - IW + 1, 0, 0, 0, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "a region past the right edge"},
                {HD_OUTPUT_LINEAR_F16, 0, TH - IH + 1, 0, 0, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "a region past the top"},
                {HD_OUTPUT_LINEAR_F16, -1, 0, 0, 0, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "a negative x"},
                {HD_OUTPUT_LINEAR_F32, 0, 0, 0, 0, HD_ERROR_OUTPUT_FORMAT, "float32 into GL_RGBA16F"},
                {HD_OUTPUT_LINEAR_F16, 0, 0, IW - 1, IH, HD_ERROR_OUTPUT_SIZE, "a region one pixel narrower than the image"}};
            int j;
            memcpy(pat, got, (size_t)TW * TH * pxb);
            for (j = 0; j < 5; ++j) {
                hd_output b = HD_OUTPUT_INIT;
                b.format = cases[j].f;
                b.x = cases[j].x;
                b.y = cases[j].y;
                b.width = cases[j].w;
                b.height = cases[j].h;
                out_errors = 0;
                r = hd_gl_render_to_texture_ex(c, t, &b);
                CHECK(r == cases[j].want && out_errors == 1 && out_last == r, "output: %s: %s, %d errors logged", cases[j].what,
                      hd_result_string(r), out_errors);
            }
            out_errors = 0;
            r = hd_gl_render_to_texture_ex(c, t + 1000, &o);
            CHECK(r == HD_ERROR_INVALID_TEXTURE && out_errors == 1, "output: a name that is no texture: %s", hd_result_string(r));
            r = hd_gl_render_to_texture(c, t);
            CHECK(r == HD_ERROR_INVALID_TEXTURE, "output: hd_gl_render_to_texture on a 70x60 GL_RGBA16F texture: %s", hd_result_string(r));
            read_texture(t, types[k], got);
            CHECK(memcmp(got, pat, (size_t)TW * TH * pxb) == 0, "output: a refused call wrote into the texture");
            out_errors = 0;
            CHECK(hd_iterate(c, 1) == HD_SUCCESS && hd_gl_render_to_texture_ex(c, t, &o) == HD_SUCCESS && out_errors == 0,
                  "output: the context does not render on after the refusals");
            printf("PASS output refusals: region outside (x, y, negative), format, size, not a texture: one error each, nothing written\n");
        }
        glDeleteTextures(1, &t);
    }
    /* exposure 1 and the float read-back itself: LINEAR_F32 is hd_read_image_f32 */
    hd_query_desc(c, &d);
    p = d.params;
    p.exposure = 1.0f;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS, "output: exposure 1");
    CHECK(hd_read_image_f32(c, img, sizeof img / sizeof img[0]) == HD_SUCCESS, "output formats: read f32");
    o.format = HD_OUTPUT_LINEAR_F32;
    o.x = o.y = 0;
    CHECK(hd_read_image_ex(c, &o, ex, (size_t)IW * IH * 16, 0) == HD_SUCCESS && memcmp(ex, img, sizeof img) == 0,
          "output: LINEAR_F32 at exposure 1 is not hd_read_image_f32");
    hd_destroy(c);
}

/* Check 9: the output pass's encodings on the values where they are hardest, written straight
   into the image buffer (white box): every RGBA8 threshold of hd__output_thresholds and the float
   below it (rgb and alpha), and for the halves every finite binary16 value, the midpoint above it
   (a tie), the floats either side of that midpoint, overflow and inf. Each output format of the
   GL pass against hd_read_image_ex, bit for bit, at exposure 1 (so the values reach the encoders
   as written) and at 0.75. */
static void check_output_encoding(void)
{
    enum { EW = 256, EH = 256 };
    static uint8_t vox[16 * 16 * 16];
    static float img[EW * EH * 4];
    static unsigned char got[EW * EH * 16], ex[EW * EH * 16];
    static const GLenum internals[3] = {GL_RGBA8, GL_RGBA16F, GL_RGBA32F};
    static const GLenum types[3] = {GL_UNSIGNED_BYTE, GL_HALF_FLOAT, GL_FLOAT};
    float th[HD__OUTPUT_THRESHOLDS];
    hd_desc d;
    hd_context c;
    hd_params p;
    hd_result r;
    hd__ctx *ctx;
    int n = 0, k, s2, ie;
    uint32_t h;
    make_desc(&d, vox, 16);
    d.camera.width = EW;
    d.camera.height = EH;
    d.gl.use_current_context = 1;
    d.logger.func = out_log;
    r = hd_create(&d, &c);
    CHECK(r == HD_SUCCESS, "output encoding: hd_create: %s", hd_result_string(r));
    if (r != HD_SUCCESS) return;
    CHECK(hd_iterate(c, 1) == HD_SUCCESS, "output encoding: iterate");
    hd__output_thresholds(th);
    for (k = 0; k < HD__OUTPUT_THRESHOLDS; ++k) {
        int at = k < 255 ? 0 : 3; /* rgb thresholds in red, alpha's in alpha */
        img[4 * n + at] = th[k];
        img[4 * n + 1] = th[k];
        ++n;
        img[4 * n + at] = hdk_u2f(hdk_f2u(th[k]) - 1u);
        img[4 * n + 2] = hdk_u2f(hdk_f2u(th[k]) - 1u);
        ++n;
    }
    for (s2 = 0; s2 < 2; ++s2) /* the halves, both signs: four values a pixel */
        for (h = 0; h < 0x7c00u; ++h) {
            uint16_t sign = (uint16_t)(s2 << 15);
            float v = hdk_h2f((uint16_t)(sign | h));
            float mid = h < 0x7bffu ? 0.5f * (v + hdk_h2f((uint16_t)(sign | (h + 1)))) : (s2 ? -65520.0f : 65520.0f);
            img[4 * n] = v;
            img[4 * n + 1] = mid;
            img[4 * n + 2] = hdk_u2f(hdk_f2u(mid) - 1u);
            img[4 * n + 3] = hdk_u2f(hdk_f2u(mid) + 1u);
            ++n;
        }
    img[4 * n] = 1e30f;
    img[4 * n + 1] = hdk_u2f(0x7f800000u);
    img[4 * n + 2] = -1e30f;
    img[4 * n + 3] = 2.0f;
    ++n;
    CHECK(n <= EW * EH, "output encoding: %d values do not fit", n);
    ctx = hd__lookup(c);
    glBindBuffer(GL_COPY_WRITE_BUFFER, ctx->vw.be->img);
    glBufferSubData(GL_COPY_WRITE_BUFFER, 0, (GLsizeiptr)sizeof img, img);
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    for (ie = 0; ie < 2; ++ie) {
        if (ie == 1) {
            hd_query_desc(c, &d);
            p = d.params;
            p.exposure = 0.75f; /* invalidates nothing: the image stays as written */
            CHECK(hd_set_params(c, &p) == HD_SUCCESS, "output encoding: exposure");
        }
        for (k = 0; k < 3; ++k) {
            hd_output o = HD_OUTPUT_INIT;
            size_t pxb = k == 2 ? 16 : k == 1 ? 8 : 4, i;
            GLuint t;
            int y, bad = 0, first = -1;
            o.format = k == 0 ? HD_OUTPUT_SRGB8 : k == 1 ? HD_OUTPUT_LINEAR_F16 : HD_OUTPUT_LINEAR_F32;
            glGenTextures(1, &t);
            glBindTexture(GL_TEXTURE_2D, t);
            glTexStorage2D(GL_TEXTURE_2D, 1, internals[k], EW, EH);
            glBindTexture(GL_TEXTURE_2D, 0);
            r = hd_gl_render_to_texture_ex(c, t, &o);
            CHECK(r == HD_SUCCESS, "output encoding: %s", hd_result_string(r));
            read_texture(t, types[k], got);
            CHECK(hd_read_image_ex(c, &o, ex, sizeof ex, 0) == HD_SUCCESS, "output encoding: hd_read_image_ex");
            for (y = 0; y < EH; ++y) /* the texture's rows bottom first */
                for (i = 0; i < (size_t)EW * pxb; ++i)
                    if (got[(size_t)y * EW * pxb + i] != ex[(size_t)(EH - 1 - y) * EW * pxb + i]) {
                        if (first < 0) first = (int)(((size_t)(EH - 1 - y) * EW * pxb + i) / pxb);
                        ++bad;
                    }
            CHECK(bad == 0, "output encoding: format %d, exposure %g: %d bytes differ from hd_read_image_ex (first at pixel %d: %.9g %.9g %.9g %.9g)",
                  (int)o.format, ie ? 0.75 : 1.0, bad, first, first >= 0 ? img[4 * first] : 0.0, first >= 0 ? img[4 * first + 1] : 0.0,
                  first >= 0 ? img[4 * first + 2] : 0.0, first >= 0 ? img[4 * first + 3] : 0.0);
            printf("%s output encoding %s at exposure %g: %d values, %d bytes differ from hd_read_image_ex\n", bad ? "FAIL" : "PASS",
                   k == 0 ? "SRGB8" : k == 1 ? "LINEAR_F16" : "LINEAR_F32", ie ? 0.75 : 1.0, 4 * n, bad);
            glDeleteTextures(1, &t);
        }
    }
    hd_destroy(c);
}

/* Check 10: the light out into the caller's 3D texture. */
static GLuint tex3d(GLenum internal, int w, int h, int d, float fill)
{
    GLuint t;
    GLint prev;
    size_t i, n = (size_t)w * h * d;
    float *v = (float *)malloc(n * sizeof(float));
    for (i = 0; i < n; ++i) v[i] = fill;
    glGetIntegerv(GL_TEXTURE_BINDING_3D, &prev);
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_3D, t);
    glTexStorage3D(GL_TEXTURE_3D, 1, internal, w, h, d);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
    glPixelStorei(GL_UNPACK_SKIP_IMAGES, 0);
    glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, w, h, d, GL_RED, GL_FLOAT, v);
    glBindTexture(GL_TEXTURE_3D, (GLuint)prev);
    free(v);
    return t;
}
static void read_tex3d(GLuint t, float *dst)
{
    GLint prev;
    glGetIntegerv(GL_TEXTURE_BINDING_3D, &prev);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glPixelStorei(GL_PACK_ROW_LENGTH, 0);
    glPixelStorei(GL_PACK_IMAGE_HEIGHT, 0);
    glBindTexture(GL_TEXTURE_3D, t);
    glGetTexImage(GL_TEXTURE_3D, 0, GL_RED, GL_FLOAT, dst);
    glBindTexture(GL_TEXTURE_3D, (GLuint)prev);
}
static void check_light_texture(void)
{
    static uint8_t vox[24 * 24 * 24];
    hd_desc d;
    hd_context c;
    hd_stats st;
    hd_result r;
    hd_light l[2];
    int rgb;
    make_desc(&d, vox, 24);
    d.gl.use_current_context = 1;
    d.logger.func = out_log;
    d.params.illumination_downsample = 2;
    memset(l, 0, sizeof l);
    l[0].direction[1] = -1.0f; l[0].color[0] = 1.0f; l[0].color[1] = 0.5f; l[0].color[2] = 0.2f;
    l[1].direction[0] = 1.0f; l[1].color[0] = 0.2f; l[1].color[1] = 0.6f; l[1].color[2] = 1.0f;
    for (rgb = 0; rgb < 2; ++rgb) {
        int gx, gy, gz, ch, k, pass;
        size_t n, g;
        float *tot, *e, *phi, *got, *big;
        GLuint t, tb, bad2d, bad16, small;
        d.lights = l;
        d.light_count = rgb ? 2 : 1;
        out_errors = 0;
        r = hd_create(&d, &c);
        CHECK(r == HD_SUCCESS, "light texture: hd_create: %s", hd_result_string(r));
        if (r != HD_SUCCESS) return;
        CHECK(hd_iterate(c, 2) == HD_SUCCESS && hd_get_stats(c, &st) == HD_SUCCESS, "light texture: iterate");
        gx = st.illumination_dims[0]; gy = st.illumination_dims[1]; gz = st.illumination_dims[2]; ch = st.illumination_channels;
        CHECK(ch == (rgb ? 3 : 1), "light texture: %d channels", ch);
        g = (size_t)gx * gy * gz;
        n = g * ch;
        tot = (float *)malloc(n * sizeof(float)); e = (float *)malloc(n * sizeof(float)); phi = (float *)malloc(n * sizeof(float));
        got = (float *)malloc(g * sizeof(float)); big = (float *)malloc((size_t)(gx + 3) * (gy + 2) * (gz + 1) * sizeof(float));
        t = tex3d(GL_R32F, gx, gy, gz, -7.0f);
        tb = tex3d(GL_R32F, gx + 3, gy + 2, gz + 1, -7.0f);
        for (pass = 0; pass < 2; ++pass) {
            size_t i, bad = 0, nonzero = 0, kept = 0;
            if (pass) CHECK(hd_iterate(c, 3) == HD_SUCCESS, "light texture: iterate more");
            CHECK(hd_read_illumination(c, HD_ILLUMINATION_TOTAL, tot, n) == HD_SUCCESS &&
                      hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e, n) == HD_SUCCESS &&
                      hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, phi, n) == HD_SUCCESS, "light texture: read-backs");
            for (i = 0; i < n; ++i) bad += tot[i] != e[i] + phi[i];
            CHECK(bad == 0, "light texture: HD_ILLUMINATION_TOTAL differs from E + phi at %zu voxels", bad);
            for (k = 0; k < ch; ++k) {
                int x, y, z;
                r = hd_gl_illumination_texture(c, t, k);
                CHECK(r == HD_SUCCESS, "light texture: channel %d: %s", k, hd_result_string(r));
                read_tex3d(t, got);
                for (i = 0, bad = 0; i < g; ++i) { bad += memcmp(&got[i], &tot[k * g + i], sizeof(float)) != 0; nonzero += got[i] > 0.0f; }
                CHECK(bad == 0, "light texture: channel %d: %zu of %zu texels are not E + phi", k, bad, g);
                CHECK(hd_gl_illumination_texture(c, tb, k) == HD_SUCCESS, "light texture: larger texture");
                read_tex3d(tb, big);
                for (z = 0, bad = 0; z < gz + 1; ++z)
                    for (y = 0; y < gy + 2; ++y)
                        for (x = 0; x < gx + 3; ++x) {
                            float v = big[((size_t)z * (gy + 2) + y) * (gx + 3) + x];
                            if (x < gx && y < gy && z < gz) bad += v != tot[k * g + ((size_t)z * gy + y) * gx + x];
                            else kept += v == -7.0f, bad += v != -7.0f;
                        }
                CHECK(bad == 0 && kept > 0, "light texture: channel %d into a larger texture: %zu texels wrong", k, bad);
            }
            CHECK(nonzero > g / 20, "light texture: only %zu lit texels", nonzero);
        }
        /* refusals: one error each, nothing written, the context goes on */
        {
            static unsigned char pat[TW * TH * 16];
            bad2d = pattern_texture(GL_RGBA32F, GL_FLOAT, 16, pat);
        }
        bad16 = tex3d(GL_R16F, gx, gy, gz, 0.0f);
        small = tex3d(GL_R32F, gx, gy, gz - 1, 0.0f);
        {
            struct { GLuint tex; int ch; hd_result want; const char *what; } cases[5];
            int j;
            size_t i, bad = 0;
            cases[0].tex = bad2d; cases[0].ch = 0; cases[0].want = HD_ERROR_INVALID_TEXTURE; cases[0].what = "a 2D texture";
            cases[1].tex = bad16; cases[1].ch = 0; cases[1].want = HD_ERROR_OUTPUT_FORMAT; cases[1].what = "GL_R16F";
            cases[2].tex = small; cases[2].ch = 0; cases[2].want = HD_ERROR_OUTPUT_OUTSIDE_TARGET; cases[2].what = "smaller than the grid";
            cases[3].tex = t; cases[3].ch = ch; cases[3].want = HD_ERROR_INVALID_PARAMETER; cases[3].what = "channel past the grid's";
            cases[4].tex = 0; cases[4].ch = 0; cases[4].want = HD_ERROR_INVALID_TEXTURE; cases[4].what = "texture 0";
            CHECK(hd_gl_illumination_texture(c, t, 0) == HD_SUCCESS, "light texture: channel 0");
            for (j = 0; j < 5; ++j) {
                out_errors = 0;
                r = hd_gl_illumination_texture(c, cases[j].tex, cases[j].ch);
                CHECK(r == cases[j].want && out_errors == 1 && out_last == r, "light texture: %s: %s, %d errors logged", cases[j].what,
                      hd_result_string(r), out_errors);
            }
            CHECK(glGetError() == GL_NO_ERROR, "light texture: a refusal left a GL error pending");
            read_tex3d(t, got);
            for (i = 0; i < g; ++i) bad += got[i] != tot[i];
            CHECK(bad == 0, "light texture: a refused call wrote into the texture");
            out_errors = 0;
            CHECK(hd_iterate(c, 1) == HD_SUCCESS && hd_gl_illumination_texture(c, t, 0) == HD_SUCCESS && out_errors == 0,
                  "light texture: the context does not go on after the refusals");
        }
        glDeleteTextures(1, &bad2d); glDeleteTextures(1, &bad16); glDeleteTextures(1, &small);
        glDeleteTextures(1, &t); glDeleteTextures(1, &tb);
        free(tot); free(e); free(phi); free(got); free(big);
        hd_destroy(c);
        printf("PASS light texture (%d channel%s): E + phi bit for bit, a larger texture, refusals one error each\n", ch, ch > 1 ? "s" : "");
    }
}

/* Check 11: the host's depth texture as the depth input. */
static float *render_depth(hd_context c, const float *top_first, GLuint tex, int w, int h)
{
    float *img = (float *)malloc((size_t)w * h * 4 * sizeof(float));
    hd_result r = HD_SUCCESS;
    if (top_first) {
        hd_depth_desc dd;
        dd.data = top_first; dd.width = w; dd.height = h;
        r = hd_set_depth(c, &dd);
    } else if (tex) {
        r = hd_gl_set_depth_texture(c, tex);
    }
    CHECK(r == HD_SUCCESS, "depth texture: setting the depth: %s", hd_result_string(r));
    CHECK(hd_iterate(c, 2) == HD_SUCCESS && hd_read_image_f32(c, img, (size_t)w * h * 4) == HD_SUCCESS, "depth texture: render");
    return img;
}
static void check_depth_texture(void)
{
    static uint8_t vox[24 * 24 * 24];
    static const GLenum fmts[2] = {GL_DEPTH_COMPONENT32F, GL_DEPTH_COMPONENT24};
    hd_desc d;
    int w, h, x, y, k;
    double n = 0.1, f = 10.0, th = tan(20.0 * 3.14159265358979 / 180.0);
    float *gl_rows, *top, *back;
    make_desc(&d, vox, 24);
    d.gl.use_current_context = 1;
    d.logger.func = out_log;
    w = d.camera.width; h = d.camera.height;
    memset(d.camera.view, 0, sizeof d.camera.view);
    d.camera.view[0] = d.camera.view[5] = d.camera.view[10] = d.camera.view[15] = 1.0f;
    d.camera.view[14] = -2.5f; /* the default look-at camera, (0, 0, 2.5) toward the origin */
    d.camera.projection[0] = (float)(1.0 / (th * w / h));
    d.camera.projection[5] = (float)(1.0 / th);
    d.camera.projection[10] = (float)(-(f + n) / (f - n));
    d.camera.projection[11] = -1.0f;
    d.camera.projection[14] = (float)(-2.0 * f * n / (f - n));
    gl_rows = (float *)malloc((size_t)w * h * sizeof(float));
    top = (float *)malloc((size_t)w * h * sizeof(float));
    back = (float *)malloc((size_t)w * h * sizeof(float));
    for (y = 0; y < h; ++y) /* GL's row y (bottom first) */
        for (x = 0; x < w; ++x) {
            double z = x < w / 3 || y < h / 2 ? -2.2 : (x >= w / 2 - 2 && x < w / 2 + 2) ? -2.5 : 0.0;
            gl_rows[y * w + x] = z == 0.0 ? 1.0f : (float)(0.5 * ((-(f + n) / (f - n) * z - 2.0 * f * n / (f - n)) / -z + 1.0));
        }
    for (k = 0; k < 2; ++k) {
        hd_context a, b, none;
        GLuint t, prev;
        float *ia, *ib, *in, *ic;
        size_t np = (size_t)w * h * 4;
        glGetIntegerv(GL_TEXTURE_BINDING_2D, (GLint *)&prev);
        glGenTextures(1, &t);
        glBindTexture(GL_TEXTURE_2D, t);
        glTexStorage2D(GL_TEXTURE_2D, 1, fmts[k], w, h);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, w, h, GL_DEPTH_COMPONENT, GL_FLOAT, gl_rows);
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glPixelStorei(GL_PACK_ROW_LENGTH, 0);
        glGetTexImage(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT, GL_FLOAT, back); /* the values it holds */
        glBindTexture(GL_TEXTURE_2D, prev);
        for (y = 0; y < h; ++y) memcpy(top + (size_t)y * w, back + (size_t)(h - 1 - y) * w, (size_t)w * sizeof(float));
        CHECK(hd_create(&d, &a) == HD_SUCCESS && hd_create(&d, &b) == HD_SUCCESS && hd_create(&d, &none) == HD_SUCCESS,
              "depth texture: hd_create");
        ia = render_depth(a, top, 0, w, h);
        ib = render_depth(b, NULL, t, w, h);
        in = render_depth(none, NULL, 0, w, h);
        CHECK(memcmp(ia, ib, np * sizeof(float)) == 0, "depth texture 0x%04x: the image is not hd_set_depth's of the same values", fmts[k]);
        CHECK(memcmp(ia, in, np * sizeof(float)) != 0, "depth texture 0x%04x: the depth changed nothing", fmts[k]);
        if (k == 0) { /* refusals keep the depth held */
            GLuint rgba, small, t3;
            hd_context look;
            hd_desc dl = d;
            hd_result r;
            float *iz;
            glGenTextures(1, &rgba); glBindTexture(GL_TEXTURE_2D, rgba); glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, w, h);
            glGenTextures(1, &small); glBindTexture(GL_TEXTURE_2D, small); glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, w, h - 1);
            glBindTexture(GL_TEXTURE_2D, prev);
            t3 = tex3d(GL_R32F, 4, 4, 4, 0.0f);
            out_errors = 0; r = hd_gl_set_depth_texture(b, rgba);
            CHECK(r == HD_ERROR_DEPTH_FORMAT && out_errors == 1, "depth texture: RGBA8: %s, %d errors", hd_result_string(r), out_errors);
            out_errors = 0; r = hd_gl_set_depth_texture(b, small);
            CHECK(r == HD_ERROR_DEPTH_SIZE && out_errors == 1, "depth texture: another size: %s, %d errors", hd_result_string(r), out_errors);
            out_errors = 0; r = hd_gl_set_depth_texture(b, t3);
            CHECK(r == HD_ERROR_INVALID_TEXTURE && out_errors == 1, "depth texture: a 3D texture: %s, %d errors", hd_result_string(r), out_errors);
            out_errors = 0; r = hd_gl_set_depth_texture(b, 0);
            CHECK(r == HD_ERROR_INVALID_TEXTURE && out_errors == 1, "depth texture: 0: %s, %d errors", hd_result_string(r), out_errors);
            CHECK(glGetError() == GL_NO_ERROR, "depth texture: a refusal left a GL error pending");
            memset(dl.camera.view, 0, sizeof dl.camera.view);
            memset(dl.camera.projection, 0, sizeof dl.camera.projection);
            CHECK(hd_create(&dl, &look) == HD_SUCCESS, "depth texture: look-at context");
            out_errors = 0; r = hd_gl_set_depth_texture(look, t);
            CHECK(r == HD_ERROR_DEPTH_NEEDS_PROJECTION && out_errors == 1, "depth texture: look-at camera: %s", hd_result_string(r));
            hd_destroy(look);
            /* the depth held: a and b go on alike (a method change re-uploads a host buffer, keeps the texture's) */
            {
                hd_params p = d.params;
                p.method = HD_METHOD_CD;
                CHECK(hd_set_params(a, &p) == HD_SUCCESS && hd_set_params(b, &p) == HD_SUCCESS, "depth texture: method CD");
            }
            free(ia); free(ib);
            ia = render_depth(a, NULL, 0, w, h);
            ib = render_depth(b, NULL, 0, w, h);
            CHECK(memcmp(ia, ib, np * sizeof(float)) == 0, "depth texture: after the refusals and a method change b is not a's");
            CHECK(hd_set_depth(b, NULL) == HD_SUCCESS && hd_set_depth(a, NULL) == HD_SUCCESS, "depth texture: cleared");
            iz = render_depth(b, NULL, 0, w, h);
            ic = render_depth(a, NULL, 0, w, h);
            CHECK(memcmp(iz, ic, np * sizeof(float)) == 0, "depth texture: hd_set_depth(NULL) did not clear the texture's depth");
            free(iz); free(ic);
            glDeleteTextures(1, &rgba); glDeleteTextures(1, &small); glDeleteTextures(1, &t3);
        }
        free(ia); free(ib); free(in);
        hd_destroy(a); hd_destroy(b); hd_destroy(none);
        glDeleteTextures(1, &t);
        printf("PASS depth texture 0x%04x: the image of hd_set_depth with the same values, bit for bit\n", fmts[k]);
    }
    free(gl_rows); free(top); free(back);
}

/* A volume the GL cannot hold as one 3D texture (a side above GL_MAX_3D_TEXTURE_SIZE; the
   library's own limits, HD_MAX_DIM and the grid's 32-bit indices, pass it): HD_ERROR_UNSUPPORTED
   and one logged error, at hd_create or at the first iteration, never a crash. */
static int limit_errors;
static void limit_log(void *u, hd_log_level l, hd_result c, const char *m, const char *f, int line)
{
    (void)u; (void)c; (void)f; (void)line;
    if (l == HD_LOG_ERROR) { ++limit_errors; printf("volume limit: logged \"%s\"\n", m); }
}
static void check_volume_limit(void)
{
    static float vox[8192 * 2 * 2];
    GLint max3d = 0;
    hd_desc d;
    hd_context c;
    hd_result r;
    int i;
    glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3d);
    if (max3d >= HD_MAX_DIM) { printf("volume limit: GL_MAX_3D_TEXTURE_SIZE %d holds HD_MAX_DIM: skipped\n", max3d); return; }
    for (i = 0; i < 8192 * 2 * 2; ++i) vox[i] = (float)(i % 7) / 7.0f;
    memset(&d, 0, sizeof d);
    d.volume.type = HD_VOXEL_F32;
    d.volume.dims[0] = HD_MAX_DIM;
    d.volume.dims[1] = d.volume.dims[2] = 2;
    d.volume.data = vox;
    d.camera.width = d.camera.height = 16;
    d.logger.func = limit_log;
    limit_errors = 0;
    r = hd_create(&d, &c);
    if (r == HD_SUCCESS) {
        r = hd_iterate(c, 1);
        hd_destroy(c);
    }
    CHECK(r == HD_ERROR_UNSUPPORTED && limit_errors == 1, "a %dx2x2 volume over GL_MAX_3D_TEXTURE_SIZE %d: %s, %d errors logged",
          HD_MAX_DIM, max3d, hd_result_string(r), limit_errors);
}

int main(void)
{
    static const EGLint cfg_attrs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    static const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    PFNEGLGETPLATFORMDISPLAYEXTPROC gpd;
    EGLDisplay dpy;
    EGLConfig cfg;
    EGLint n = 0;
    EGLContext host;
    /* check 7 needs every stage compiled by the driver, not loaded from Mesa's disk cache */
    setenv("MESA_SHADER_CACHE_DISABLE", "true", 1);
    gpd = (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    dpy = gpd ? gpd(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL) : EGL_NO_DISPLAY;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL) || !eglBindAPI(EGL_OPENGL_API) ||
        !eglChooseConfig(dpy, cfg_attrs, &cfg, 1, &n) || n < 1 ||
        (host = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attrs)) == EGL_NO_CONTEXT ||
        !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, host)) {
        printf("SKIPPED test_gl: no surfaceless EGL OpenGL 4.5 context for the host\n");
        return getenv("HD_CONFORMANCE_REQUIRE") && getenv("HD_CONFORMANCE_REQUIRE")[0] == '1' ? 1 : 0;
    }
    printf("host context: %s\n", (const char *)glGetString(GL_RENDERER));
    check_f16_round();
    run_calls(1, "caller's context");
    check_not_current(dpy, cfg, ctx_attrs, host);
    check_image_room();
    check_output_formats();
    check_output_encoding();
    check_light_texture();
    check_depth_texture();
    check_shader_warnings();
    check_volume_limit();
    /* the backend's own EGL context while the host's is current: it cannot render into the host's
       texture (different context, no sharing), so only the state is checked there */
    {
        static uint8_t vox[24 * 24 * 24];
        host_state before, after;
        hd_desc d;
        hd_context c;
        hd_result r;
        make_desc(&d, vox, 24);
        d.logger.func = hd_log_stderr;
        set_host_state();
        snap(&before);
        r = hd_create(&d, &c);
        CHECK(r == HD_SUCCESS, "own context: hd_create: %s", hd_result_string(r));
        if (r == HD_SUCCESS) {
            CHECK(eglGetCurrentContext() == host, "own context: hd_create left the host's context not current");
            CHECK(hd_iterate(c, 2) == HD_SUCCESS, "own context: iterate");
            CHECK(eglGetCurrentContext() == host, "own context: hd_iterate left the host's context not current");
            hd_destroy(c);
        }
        snap(&after);
        compare(&before, &after, "own context");
        CHECK(eglGetCurrentContext() == host, "own context: the host's context is not current after hd_destroy");
    }
    printf("%s\n", failures ? "test_gl: FAILED" : "test_gl: all checks passed");
    return failures ? 1 : 0;
}
