/* hdview - the interactive viewer: a GLFW window with an OpenGL 4.3+ core context, and
   hybriddiff's GL backend computing in that same context (desc.gl.use_current_context); each
   frame is one hd_render drawn straight from the GPU (hd_gl_render_to_texture, then a blit), no
   CPU round trip. hd_render refines the light only until it has converged; after that a frame is
   one projection, and once the image holds frame_window frames the viewer waits for input.

     make hdview && build/hdview [FILE|DIR]      (default data/head.nrrd; make data fetches it;
                                                  DIR: a DICOM series, read with GDCM)

   Mouse: left drag orbits, right (or shift + left) drag pans, the wheel zooms. The illumination
   (E, phi) does not depend on the camera, so moving the camera restarts only the image: over
   converged light orbiting, panning and zooming do no light work. Keys:
     1 2 3 4   method HD, CD, PT_SS, PT_MS        T   next transfer function preset
     L         1 / 3 lights                        E / shift+E   extinction x1.25 / /1.25
     A / shift+A  albedo +0.05 / -0.05             R   restart     S   screenshot (hdview-N.png)
     H         the default camera                  G   illumination grid 1/1 -> 1/2 -> 1/4 resolution
     C         grey / RGB multiple scattering         B   diffusion boundary: box / surface
     F         float32 / float16 illumination storage (GL_R16F images on the GL backend; a
               backend that refuses it logs why and the viewer stays at float32)
     M         diffusion solver: red-black sweeps / multigrid (a backend without multigrid logs
               why and the viewer stays at red-black)
     O / shift+O  select the next / previous face of the crop box (x-, x+, y-, y+, z-, z+)
     I / shift+I  move the selected face 0.02 of the volume in / out (the box shrinks / grows)
     U         crop box: the whole volume / the volume's default (data/head.nrrd: no head rest)
     V / shift+V  turn the environment (--env FILE.hdr[:ROTATION][:INTENSITY]) 15 degrees about +z
     K         the environment shown behind the volume / not (params.environment_background)
     P         preview on / off: while the camera moves, frames at reduced resolution (render_scale
               HD_RENDER_SCALE_AUTO, the scale whose frame time fits 50 ms), refined to full
               resolution when it stops; on by default in the window, off in scripted runs
     Esc / Q   quit
   The title shows the method, whether the light has converged (its error estimate and
   iterations; paths per pixel for PT), the frame time, the bytes the method holds and the crop
   box with its selected face in brackets.

   Scripted (for tests): --frames N runs N frames and exits; --screenshot FILE saves the last
   one; --script FILE runs the commands in FILE, one a line: `orbit DEG_X DEG_Y`, `pan DX DY`,
   `zoom FACTOR`, `home` (the default camera), `key CHARS` (as typed), `restart`, `frames N`, `screenshot FILE`,
   `tolerance T` (light_tolerance), `converge N` (hd_refine until converged, at most N iterations), `expect-light-idle N` (N frames
   that must do no light work, else exit 1), `preview on|off` (P, with no frame budget: each new
   view starts at 1/4 resolution), `expect-scale S` (the image's frames are at 1/S resolution,
   else exit 1); with --script
   the window closes when the script ends. --size WxH sets the window (and image) size, --seed N
   the seed; the rest of the scene is hdrender's default (camera, 1 key light, ct-skin or ramp,
   exposure 8), so `hdrender --size WxH --iterations N` renders what hdview shows after a
   restart and N frames. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#define GL_GLEXT_PROTOTYPES /* before hybriddiff.h, which includes GL/glcorearb.h */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_GL
#include "hybriddiff.h"
#include "hd_tf.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <GL/glcorearb.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hd_crop.h"
#include "hd_input.h"
#include "hd_png.h"
#include "hd_env.h"

#define DEFAULT_INPUT "data/head.nrrd"

typedef struct viewer {
    GLFWwindow *win;
    hd_context ctx;
    hd_camera cam;
    hd_params params;
    hd_light lights[3];
    int light_count;
    hdx_tf tf;
    int tf_preset, is_ct;
    float vmin, vmax;
    float yaw, pitch, dist, target[3];
    GLuint tex, fbo;
    int width, height;        /* image = framebuffer size */
    int camera_dirty;
    double last_x, last_y;
    int dragging, panning;
    double t_title, frame_ms; /* frame_ms: smoothed wall time of frame() */
    int idle, idle_titled;    /* idle: light converged and the image final (hd_render is a no-op) */
    int preview;              /* render_scale HD_RENDER_SCALE_AUTO: reduced frames while the camera moves */
    int shots;
    int crop_face;            /* the face I moves: 2 * axis + (0 low, 1 high) */
    float crop_min[3], crop_max[3]; /* the volume's default crop box (U toggles to it) */
    hd_environment env;       /* --env: the map (rgb NULL: none), turned env_deg about the up axis */
    float env_deg;
} viewer;

static void die(const char *what, hd_result r)
{
    fprintf(stderr, "hdview: %s: %s\n", what, hd_result_string(r));
    exit(1);
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- camera: orbit around the target, the head CT's up is +z ---------------------------------- */
static void normalize3(float v[3])
{
    float n = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (n > 0.0f) { v[0] /= n; v[1] /= n; v[2] /= n; }
}
static void cross3(const float a[3], const float b[3], float o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static void camera_update(viewer *v)
{
    float cp = cosf(v->pitch), sp = sinf(v->pitch);
    v->cam.eye[0] = v->target[0] + v->dist * cp * sinf(v->yaw);
    v->cam.eye[1] = v->target[1] + v->dist * cp * cosf(v->yaw);
    v->cam.eye[2] = v->target[2] + v->dist * sp;
    memcpy(v->cam.target, v->target, sizeof v->target);
    v->cam.up[0] = 0.0f; v->cam.up[1] = 0.0f; v->cam.up[2] = 1.0f;
    v->cam.width = v->width;
    v->cam.height = v->height;
    v->camera_dirty = 1;
}

/* hdrender's default camera (eye 0.6,1.65,0.3, target 0,0,-0.04, fov 37) as yaw/pitch/dist. */
static void camera_default(viewer *v)
{
    float d[3] = {0.6f, 1.65f, 0.34f};
    v->target[0] = 0.0f; v->target[1] = 0.0f; v->target[2] = -0.04f;
    v->dist = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    v->yaw = atan2f(d[0], d[1]);
    v->pitch = asinf(d[2] / v->dist);
    v->cam.fov_y = 37.0f;
    camera_update(v);
    /* exactly hdrender's numbers, not their round trip through yaw/pitch */
    v->cam.eye[0] = 0.6f; v->cam.eye[1] = 1.65f; v->cam.eye[2] = 0.3f;
}

static void orbit(viewer *v, float dx_deg, float dy_deg)
{
    v->yaw += dx_deg * 0.01745329f;
    v->pitch += dy_deg * 0.01745329f;
    if (v->pitch > 1.5f) v->pitch = 1.5f;
    if (v->pitch < -1.5f) v->pitch = -1.5f;
    camera_update(v);
}

static void pan(viewer *v, float dx, float dy)
{
    float w[3], u[3], up[3] = {0.0f, 0.0f, 1.0f}, vv[3];
    int k;
    for (k = 0; k < 3; ++k) w[k] = v->cam.target[k] - v->cam.eye[k];
    normalize3(w);
    cross3(w, up, u);
    normalize3(u);
    cross3(u, w, vv);
    for (k = 0; k < 3; ++k) v->target[k] += (-dx * u[k] + dy * vv[k]) * v->dist;
    camera_update(v);
}

static void zoom(viewer *v, float f)
{
    v->dist *= f;
    if (v->dist < 0.2f) v->dist = 0.2f;
    if (v->dist > 20.0f) v->dist = 20.0f;
    camera_update(v);
}

/* hdrender's preset lights (key, fill, rim), placed in the default camera's frame. */
static void set_lights(viewer *v, int n)
{
    static const float base[3][4] = {{-0.55f, 0.65f, 0.75f, 1.0f}, {0.80f, 0.10f, 0.60f, 0.45f}, {0.30f, 0.60f, -0.75f, 0.70f}};
    static const float eye[3] = {0.6f, 1.65f, 0.3f}, target[3] = {0.0f, 0.0f, -0.04f}, up[3] = {0.0f, 0.0f, 1.0f};
    float w[3], u[3], vv[3];
    int i, k;
    for (k = 0; k < 3; ++k) w[k] = target[k] - eye[k];
    normalize3(w);
    cross3(w, up, u);
    normalize3(u);
    cross3(u, w, vv);
    for (i = 0; i < n; ++i) {
        float from[3];
        for (k = 0; k < 3; ++k) from[k] = base[i][0] * u[k] + base[i][1] * vv[k] - base[i][2] * w[k];
        normalize3(from);
        memset(&v->lights[i], 0, sizeof v->lights[i]);
        v->lights[i].type = HD_LIGHT_DIRECTIONAL;
        for (k = 0; k < 3; ++k) v->lights[i].direction[k] = -from[k];
        v->lights[i].color[0] = v->lights[i].color[1] = v->lights[i].color[2] = 1.0f;
        v->lights[i].intensity = base[i][3];
    }
    v->light_count = n;
}

static void set_tf(viewer *v, int preset)
{
    hd_transfer_function t;
    hd_result r;
    const char *name = hdx_tf_preset_name(preset, NULL);
    hdx_tf_preset(name, &v->tf);
    /* the volume was normalised with hdrender's value range for its default TF: a CT preset maps
       -1024..3071, the ramp the data's range; other presets are resampled onto that range */
    if (v->is_ct) { if (!v->tf.is_ct) hdx_tf_set_domain(&v->tf, -1024.0f, 3071.0f); }
    else hdx_tf_set_domain(&v->tf, v->vmin, v->vmax > v->vmin ? v->vmax : v->vmin + 1.0f);
    t = hdx_tf_desc(&v->tf);
    v->tf_preset = preset;
    if (v->ctx.id && (r = hd_set_transfer_function(v->ctx, &t)) != HD_SUCCESS) die("hd_set_transfer_function", r);
}

/* ---- the image in a texture of the framebuffer's size ---------------------------------------- */
static void resize(viewer *v, int w, int h)
{
    if (w < 1 || h < 1 || (w == v->width && h == v->height && v->tex)) return;
    v->width = w;
    v->height = h;
    if (v->tex) glDeleteTextures(1, &v->tex);
    glGenTextures(1, &v->tex);
    glBindTexture(GL_TEXTURE_2D, v->tex);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA8, w, h);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, v->fbo);
    glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, v->tex, 0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    camera_update(v);
}

static void screenshot(viewer *v, const char *path)
{
    int w = v->width, h = v->height, y;
    unsigned char *px = (unsigned char *)malloc((size_t)w * h * 3), *flip = (unsigned char *)malloc((size_t)w * h * 3);
    if (!px || !flip) { fprintf(stderr, "hdview: no memory for a screenshot\n"); exit(1); }
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_BACK);
    glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, px);
    for (y = 0; y < h; ++y) memcpy(flip + (size_t)y * w * 3, px + (size_t)(h - 1 - y) * w * 3, (size_t)w * 3);
    if (!stbi_write_png(path, w, h, 3, flip, w * 3)) fprintf(stderr, "hdview: cannot write %s\n", path);
    else fprintf(stderr, "hdview: screenshot %s (%dx%d)\n", path, w, h);
    free(px);
    free(flip);
}

static void restart(viewer *v)
{
    hd_result r = hd_reset(v->ctx); /* E, phi and the image from zero, as in a new context */
    if (r != HD_SUCCESS) die("hd_reset", r);
}

static void apply_params(viewer *v)
{
    hd_result r = hd_set_params(v->ctx, &v->params);
    if (r != HD_SUCCESS) die("hd_set_params", r);
}

/* Preview on: params.render_scale HD_RENDER_SCALE_AUTO with a frame budget of budget s, so
   each new view (a drag moves the camera every frame) starts at the reduced scale whose
   predicted frame time fits the budget (1/4 with budget 0), and a camera at rest refines to full
   frames, doubling the resolution per frame. Off: every frame at full resolution. */
#define PREVIEW_BUDGET 0.05f
static void set_preview(viewer *v, int on, float budget)
{
    v->preview = on;
    v->params.render_scale = on ? HD_RENDER_SCALE_AUTO : 1;
    v->params.render_budget = on ? budget : 0.0f;
    apply_params(v);
}

static void crop_applied(viewer *v)
{
    const float *a = v->params.crop_min, *b = v->params.crop_max;
    apply_params(v);
    fprintf(stderr, "hdview: crop box x %.2f-%.2f y %.2f-%.2f z %.2f-%.2f\n", (double)a[0], (double)b[0], (double)a[1],
            (double)b[1], (double)a[2], (double)b[2]);
}

/* Moves the selected face of the crop box by step toward the box's inside (step < 0: out),
   keeping 0 <= min < max <= 1 with at least 0.02 between the faces. */
static void crop_move(viewer *v, float step)
{
    int axis = v->crop_face / 2, high = v->crop_face % 2;
    float *lo = &v->params.crop_min[axis], *hi = &v->params.crop_max[axis];
    if (high) {
        *hi -= step;
        if (*hi > 1.0f) *hi = 1.0f;
        if (*hi < *lo + 0.02f) *hi = *lo + 0.02f;
    } else {
        *lo += step;
        if (*lo < 0.0f) *lo = 0.0f;
        if (*lo > *hi - 0.02f) *lo = *hi - 0.02f;
    }
    crop_applied(v);
}

/* U: the whole volume, or the volume's default crop box when the whole volume is shown. */
static void crop_toggle(viewer *v)
{
    static const float whole_min[3] = {0.0f, 0.0f, 0.0f}, whole_max[3] = {1.0f, 1.0f, 1.0f};
    int whole = memcmp(v->params.crop_min, whole_min, sizeof whole_min) == 0 &&
                memcmp(v->params.crop_max, whole_max, sizeof whole_max) == 0;
    memcpy(v->params.crop_min, whole ? v->crop_min : whole_min, sizeof whole_min);
    memcpy(v->params.crop_max, whole ? v->crop_max : whole_max, sizeof whole_max);
    crop_applied(v);
}

/* One key as typed: shift gives the capital. */
static void key_char(viewer *v, int c)
{
    static const hd_method methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};
    char name[64];
    hd_result r;
    switch (c) {
    case '1': case '2': case '3': case '4': v->params.method = methods[c - '1']; apply_params(v); break;
    case 't': case 'T': set_tf(v, (v->tf_preset + 1) % HDX_TF_PRESET_COUNT); break;
    case 'v': case 'V': /* the environment 15 degrees further about the up axis (shift: back) */
        if (v->env.rgb) {
            static const float up[3] = {0.0f, 0.0f, 1.0f};
            v->env_deg += c == 'v' ? 15.0f : -15.0f;
            hdx_env_rotation(up, v->env_deg, v->env.rotation);
            if ((r = hd_set_environment(v->ctx, &v->env)) != HD_SUCCESS) die("hd_set_environment", r);
            fprintf(stderr, "hdview: environment turned %g degrees\n", (double)v->env_deg);
        }
        break;
    case 'k': case 'K': /* the environment behind the volume, on / off */
        if (v->env.rgb) {
            v->params.environment_background = !v->params.environment_background;
            apply_params(v);
        }
        break;
    case 'l': case 'L':
        set_lights(v, v->light_count == 1 ? 3 : 1);
        if ((r = hd_set_lights(v->ctx, v->lights, v->light_count)) != HD_SUCCESS) die("hd_set_lights", r);
        break;
    case 'e': v->params.extinction *= 1.25f; apply_params(v); break;
    case 'E': v->params.extinction /= 1.25f; apply_params(v); break;
    case 'a': v->params.albedo = v->params.albedo + 0.05f > 1.0f ? 1.0f : v->params.albedo + 0.05f; apply_params(v); break;
    case 'A': v->params.albedo = v->params.albedo - 0.05f < 0.05f ? 0.05f : v->params.albedo - 0.05f; apply_params(v); break;
    case 'r': case 'R': restart(v); break;
    case 'h': case 'H': camera_default(v); break;
    case 'c': case 'C': v->params.rgb_scattering = !v->params.rgb_scattering; apply_params(v); break;
    case 'b': case 'B':
        v->params.diffusion_boundary = v->params.diffusion_boundary == HD_BOUNDARY_BOX ? HD_BOUNDARY_SURFACE : HD_BOUNDARY_BOX;
        apply_params(v);
        break;
    case 'g': case 'G': /* params.illumination_downsample: 8x less memory per step */
        v->params.illumination_downsample = v->params.illumination_downsample >= 4 ? 1 : v->params.illumination_downsample * 2;
        apply_params(v);
        break;
    case 'f': case 'F': /* params.illumination_precision; a backend without it keeps the old one */
        v->params.illumination_precision = v->params.illumination_precision == HD_PRECISION_FLOAT16 ? HD_PRECISION_FLOAT32
                                                                                                   : HD_PRECISION_FLOAT16;
        if ((r = hd_set_params(v->ctx, &v->params)) == HD_ERROR_UNSUPPORTED) v->params.illumination_precision = HD_PRECISION_FLOAT32;
        else if (r != HD_SUCCESS) die("hd_set_params", r);
        break;
    case 'm': case 'M': /* params.solver; a backend without multigrid keeps red-black */
        v->params.solver = v->params.solver == HD_SOLVER_MULTIGRID ? HD_SOLVER_RED_BLACK : HD_SOLVER_MULTIGRID;
        if ((r = hd_set_params(v->ctx, &v->params)) == HD_ERROR_UNSUPPORTED) v->params.solver = HD_SOLVER_RED_BLACK;
        else if (r != HD_SUCCESS) die("hd_set_params", r);
        break;
    case 'o': v->crop_face = (v->crop_face + 1) % 6; v->t_title = 0.0; break;
    case 'O': v->crop_face = (v->crop_face + 5) % 6; v->t_title = 0.0; break;
    case 'i': crop_move(v, 0.02f); break;
    case 'I': crop_move(v, -0.02f); break;
    case 'u': case 'U': crop_toggle(v); break;
    case 'p': case 'P': set_preview(v, !v->preview, PREVIEW_BUDGET); break;
    case 's': case 'S':
        snprintf(name, sizeof name, "hdview-%d.png", v->shots++);
        screenshot(v, name);
        break;
    case 'q': case 'Q': glfwSetWindowShouldClose(v->win, 1); break;
    default: break;
    }
}

static void on_key(GLFWwindow *w, int key, int scancode, int action, int mods)
{
    viewer *v = (viewer *)glfwGetWindowUserPointer(w);
    (void)scancode;
    if (action != GLFW_PRESS) return;
    if (key == GLFW_KEY_ESCAPE) { glfwSetWindowShouldClose(w, 1); return; }
    if (key >= GLFW_KEY_1 && key <= GLFW_KEY_4) key_char(v, '1' + (key - GLFW_KEY_1));
    else if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) key_char(v, (mods & GLFW_MOD_SHIFT ? 'A' : 'a') + (key - GLFW_KEY_A));
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    viewer *v = (viewer *)glfwGetWindowUserPointer(w);
    glfwGetCursorPos(w, &v->last_x, &v->last_y);
    if (button == GLFW_MOUSE_BUTTON_LEFT) {
        v->dragging = action == GLFW_PRESS;
        v->panning = v->dragging && (mods & GLFW_MOD_SHIFT);
    } else if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) {
        v->dragging = v->panning = action == GLFW_PRESS;
    }
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    viewer *v = (viewer *)glfwGetWindowUserPointer(w);
    double dx = x - v->last_x, dy = y - v->last_y;
    v->last_x = x;
    v->last_y = y;
    if (!v->dragging) return;
    if (v->panning) pan(v, (float)dx / (float)v->height, (float)dy / (float)v->height);
    else orbit(v, (float)-dx * 0.4f, (float)dy * 0.4f);
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    viewer *v = (viewer *)glfwGetWindowUserPointer(w);
    (void)dx;
    zoom(v, powf(0.9f, (float)dy));
}

static void on_resize(GLFWwindow *w, int width, int height)
{
    resize((viewer *)glfwGetWindowUserPointer(w), width, height);
}

/* One frame: hd_render (HD/CD refine the light only while it has not converged, so moving the
   camera over converged light costs one projection), the image into the texture, the texture
   onto the window. */
static void frame(viewer *v)
{
    hd_result r;
    hd_stats st;
    double t, t0 = now_seconds();
    if (v->camera_dirty) {
        if ((r = hd_set_camera(v->ctx, &v->cam)) != HD_SUCCESS) die("hd_set_camera", r);
        v->camera_dirty = 0;
    }
    if ((r = hd_render(v->ctx)) != HD_SUCCESS) die("hd_render", r);
    if ((r = hd_gl_render_to_texture(v->ctx, v->tex)) != HD_SUCCESS) die("hd_gl_render_to_texture", r);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, v->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, v->width, v->height, 0, 0, v->width, v->height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glFinish(); /* the frame time includes the GPU's work */
    t = now_seconds();
    v->frame_ms = v->frame_ms > 0.0 ? 0.8 * v->frame_ms + 0.2 * 1e3 * (t - t0) : 1e3 * (t - t0);
    if (hd_get_stats(v->ctx, &st) != HD_SUCCESS) return;
    v->idle = st.light_converged && st.frames >= (uint64_t)v->params.frame_window && st.render_scale == 1;
    if (t - v->t_title > 0.5 || v->idle != v->idle_titled) {
        static const char *faces[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
        char title[448], light[96];
        const float *c0 = v->params.crop_min, *c1 = v->params.crop_max;
        if (st.method == HD_METHOD_HD || st.method == HD_METHOD_CD)
            snprintf(light, sizeof light, "light %s (error %.3g, %llu it)",
                     st.light_converged ? "converged" : "refining", st.light_error,
                     (unsigned long long)st.iterations);
        else
            snprintf(light, sizeof light, "%llu paths/pixel", (unsigned long long)st.iterations);
        char scale[32] = "";
        if (st.render_scale > 1) snprintf(scale, sizeof scale, " at 1/%d res", st.render_scale);
        snprintf(title, sizeof title, "hdview - %s | %s | %.1f ms/frame%s%s | %.1f MB | tf %s | %d light%s | ext %.0f albedo %.2f"
                 " | crop x %.2f-%.2f y %.2f-%.2f z %.2f-%.2f [%s]",
                 hd_method_name(st.method), light, v->frame_ms, scale, v->idle ? " (idle: image final)" : "",
                 (double)st.method_bytes / 1048576.0, v->tf.name, v->light_count, v->light_count == 1 ? "" : "s",
                 (double)v->params.extinction, (double)v->params.albedo, (double)c0[0], (double)c1[0], (double)c0[1],
                 (double)c1[1], (double)c0[2], (double)c1[2], faces[v->crop_face]);
        glfwSetWindowTitle(v->win, title);
        v->t_title = t;
        v->idle_titled = v->idle;
    }
}

/* n frames; interactive: once the image is final, wait for input instead of spinning. */
static void run_frames(viewer *v, int n, int interactive)
{
    int i;
    for (i = 0; i < n && !glfwWindowShouldClose(v->win); ++i) {
        frame(v);
        glfwSwapBuffers(v->win);
        if (interactive && v->idle && !v->camera_dirty) glfwWaitEventsTimeout(0.5);
        else glfwPollEvents();
    }
}

/* Script command: the light's convergence tolerance (hd_params.light_tolerance). */
static void set_tolerance(viewer *v, float tol)
{
    hd_result r;
    v->params.light_tolerance = tol;
    if ((r = hd_set_params(v->ctx, &v->params)) != HD_SUCCESS) die("hd_set_params (tolerance)", r);
}

/* Script command: refines the light until it has converged (at most max iterations). */
static void converge(viewer *v, int max)
{
    hd_stats st;
    hd_result r;
    int i = 0;
    do {
        if ((r = hd_refine(v->ctx, 1)) != HD_SUCCESS) die("hd_refine", r);
        if ((r = hd_get_stats(v->ctx, &st)) != HD_SUCCESS) die("hd_get_stats", r);
    } while (!st.light_converged && ++i < max);
    fprintf(stderr, "hdview: light %s after %llu iterations (error %.3g)\n",
            st.light_converged ? "converged" : "not converged", (unsigned long long)st.iterations,
            st.light_error);
}

/* Script command: n frames over converged light must do no light work (exit 1 otherwise). */
static void expect_light_idle(viewer *v, int n)
{
    hd_stats a, b;
    hd_result r;
    if ((r = hd_get_stats(v->ctx, &a)) != HD_SUCCESS) die("hd_get_stats", r);
    if (!a.light_converged) { fprintf(stderr, "hdview: expect-light-idle: the light has not converged\n"); exit(1); }
    run_frames(v, n, 0);
    if ((r = hd_get_stats(v->ctx, &b)) != HD_SUCCESS) die("hd_get_stats", r);
    if (b.iterations != a.iterations || b.seconds_direct != a.seconds_direct ||
        b.seconds_diffusion != a.seconds_diffusion) {
        fprintf(stderr, "hdview: expect-light-idle: %d frames did light work (%llu -> %llu light iterations)\n",
                n, (unsigned long long)a.iterations, (unsigned long long)b.iterations);
        exit(1);
    }
    fprintf(stderr, "hdview: %d frames over converged light, no light work (%.1f ms/frame)\n", n, v->frame_ms);
}

/* The screenshot is read from the back buffer: draw the current image once more first. */
/* Script command: the image's frames must be at render scale s (hd_stats.render_scale), else
   exit 1. */
static void expect_scale(viewer *v, int s)
{
    hd_stats st;
    hd_result r;
    if ((r = hd_get_stats(v->ctx, &st)) != HD_SUCCESS) die("hd_get_stats", r);
    if (st.render_scale != s) {
        fprintf(stderr, "hdview: expect-scale: the frames are at 1/%d resolution, not 1/%d\n", st.render_scale, s);
        exit(1);
    }
    fprintf(stderr, "hdview: frames at 1/%d resolution (%.1f ms/frame)\n", s, v->frame_ms);
}

static void scripted_screenshot(viewer *v, const char *path)
{
    glBindFramebuffer(GL_READ_FRAMEBUFFER, v->fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, v->width, v->height, 0, 0, v->width, v->height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    screenshot(v, path);
}

static void run_script(viewer *v, const char *path)
{
    FILE *f = fopen(path, "r");
    char line[512], cmd[64], arg[448];
    int lineno = 0;
    if (!f) { fprintf(stderr, "hdview: cannot open the script %s\n", path); exit(2); }
    while (fgets(line, sizeof line, f)) {
        float a = 0.0f, b = 0.0f;
        int n;
        ++lineno;
        arg[0] = '\0';
        if (sscanf(line, "%63s %447[^\n]", cmd, arg) < 1 || cmd[0] == '#') continue;
        if (strcmp(cmd, "orbit") == 0 && sscanf(arg, "%f %f", &a, &b) == 2) orbit(v, a, b);
        else if (strcmp(cmd, "pan") == 0 && sscanf(arg, "%f %f", &a, &b) == 2) pan(v, a, b);
        else if (strcmp(cmd, "zoom") == 0 && sscanf(arg, "%f", &a) == 1) zoom(v, a);
        else if (strcmp(cmd, "key") == 0) { for (n = 0; arg[n]; ++n) if (arg[n] != ' ') key_char(v, arg[n]); }
        else if (strcmp(cmd, "restart") == 0) restart(v);
        else if (strcmp(cmd, "home") == 0) camera_default(v);
        else if (strcmp(cmd, "frames") == 0 && sscanf(arg, "%d", &n) == 1) run_frames(v, n, 0);
        else if (strcmp(cmd, "tolerance") == 0 && sscanf(arg, "%f", &a) == 1) set_tolerance(v, a);
        else if (strcmp(cmd, "converge") == 0 && sscanf(arg, "%d", &n) == 1) converge(v, n);
        else if (strcmp(cmd, "expect-light-idle") == 0 && sscanf(arg, "%d", &n) == 1) expect_light_idle(v, n);
        else if (strcmp(cmd, "expect-scale") == 0 && sscanf(arg, "%d", &n) == 1) expect_scale(v, n);
        else if (strcmp(cmd, "preview") == 0 && (!strcmp(arg, "on") || !strcmp(arg, "off"))) set_preview(v, !strcmp(arg, "on"), 0.0f);
        else if (strcmp(cmd, "screenshot") == 0 && arg[0]) scripted_screenshot(v, arg);
        else { fprintf(stderr, "hdview: %s:%d: cannot read '%s'\n", path, lineno, line); exit(2); }
    }
    fclose(f);
}

int main(int argc, char **argv)
{
    static viewer v;
    const char *input = DEFAULT_INPUT, *script = NULL, *shot = NULL;
    int frames = -1, w = 640, h = 640, i;
    unsigned seed = 0;
    hd_volume_file vol;
    hd_desc desc;
    hd_logger logger = {hd_log_stderr, NULL};
    hd_result r;
    char err[512];
    const char *env_arg = NULL;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) frames = atoi(argv[++i]);
        else if (strcmp(argv[i], "--env") == 0 && i + 1 < argc) env_arg = argv[++i];
        else if (strcmp(argv[i], "--screenshot") == 0 && i + 1 < argc) shot = argv[++i];
        else if (strcmp(argv[i], "--script") == 0 && i + 1 < argc) script = argv[++i];
        else if (strcmp(argv[i], "--seed") == 0 && i + 1 < argc) seed = (unsigned)strtoul(argv[++i], NULL, 10);
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc && sscanf(argv[i + 1], "%dx%d", &w, &h) == 2) ++i;
        else if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            printf("usage: hdview [--size WxH] [--seed N] [--frames N] [--screenshot FILE] [--script FILE]\n"
                   "              [--env FILE.hdr[:ROTATION][:INTENSITY]] [FILE|DIR]\n"
                   "(DIR: a DICOM series; FILE.vdb[:GRID]: an OpenVDB float grid; default FILE: " DEFAULT_INPUT "); keys and mouse: see the top of examples/hdview.c\n"
                   "crop box: O / shift+O select a face, I / shift+I move it in / out, U whole volume / default box\n");
            return 0;
        } else if (argv[i][0] == '-') { fprintf(stderr, "hdview: unknown option %s (--help)\n", argv[i]); return 2; }
        else input = argv[i];
    }
    if ((r = hdx_load_input(input, &vol, &logger, err, sizeof err)) != HD_SUCCESS && err[0]) {
        fprintf(stderr, "hdview: %s\n", err);
        return 2;
    } else if (r != HD_SUCCESS) {
        fprintf(stderr, "hdview: cannot load %s: %s%s\n", input, hd_result_string(r),
                strcmp(input, DEFAULT_INPUT) == 0 ? " (make data fetches the head CT)" : "");
        return 2;
    }
    if (!glfwInit()) { fprintf(stderr, "hdview: glfwInit failed (no display?)\n"); return 1; }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    v.win = glfwCreateWindow(w, h, "hdview", NULL, NULL);
    if (!v.win) { fprintf(stderr, "hdview: no window with an OpenGL 4.3 core context\n"); glfwTerminate(); return 1; }
    glfwMakeContextCurrent(v.win);
    glfwSwapInterval(0);
    glfwSetWindowUserPointer(v.win, &v);
    glGenFramebuffers(1, &v.fbo);
    glfwGetFramebufferSize(v.win, &w, &h);
    camera_default(&v);
    resize(&v, w, h);

    /* the scene: hdrender's defaults */
    v.is_ct = (vol.desc.type == HD_VOXEL_F32 || vol.desc.type == HD_VOXEL_I16) && vol.value_min <= -500.0f;
    v.vmin = vol.value_min;
    v.vmax = vol.value_max;
    set_tf(&v, v.is_ct ? 0 : HDX_TF_PRESET_COUNT - 1);
    set_lights(&v, 1);
    memset(&desc, 0, sizeof desc);
    hdx_tf_use(&desc, &vol.desc, &v.tf);
    desc.lights = v.lights;
    desc.light_count = v.light_count;
    desc.camera = v.cam;
    desc.params.exposure = 8.0f;
    desc.params.seed = seed;
    if (!hdx_known_crop(input, vol.desc.dims, &desc.params)) /* the whole volume, filled in for U */
        desc.params.crop_max[0] = desc.params.crop_max[1] = desc.params.crop_max[2] = 1.0f;
    memcpy(v.crop_min, desc.params.crop_min, sizeof v.crop_min);
    memcpy(v.crop_max, desc.params.crop_max, sizeof v.crop_max);
    desc.logger = logger;
    desc.gl.use_current_context = 1;
    desc.gl.get_proc_address = glfwGetProcAddress;
    if ((r = hd_create(&desc, &v.ctx)) != HD_SUCCESS) die("hd_create", r);
    hd_volume_free(&vol);
    if (env_arg) { /* the environment alone (L adds the lights beside it), its top on +z */
        static const float up[3] = {0.0f, 0.0f, 1.0f};
        char path[4096];
        float inten = 1.0f;
        if (!hdx_env_arg(env_arg, path, sizeof path, &v.env_deg, &inten)) { fprintf(stderr, "hdview: --env '%s' is not FILE[:ROTATION][:INTENSITY]\n", env_arg); return 2; }
        if (!hdx_env_load(path, &v.env, err, sizeof err)) { fprintf(stderr, "hdview: --env: %s\n", err); return 2; }
        v.env.intensity = inten;
        hdx_env_rotation(up, v.env_deg, v.env.rotation);
        if ((r = hd_set_environment(v.ctx, &v.env)) != HD_SUCCESS) die("hd_set_environment", r);
        if ((r = hd_set_lights(v.ctx, NULL, 0)) != HD_SUCCESS) die("hd_set_lights", r);
    }
    hd_query_desc(v.ctx, &desc);
    v.params = desc.params;
    v.camera_dirty = 0;
    if (!script && frames < 0) set_preview(&v, 1, PREVIEW_BUDGET); /* interactive: reduced frames while moving */
    fprintf(stderr, "hdview: %s, %dx%d, backend %s on %s\n", input, w, h, hd_backend_name(), (const char *)glGetString(GL_RENDERER));

    glfwSetKeyCallback(v.win, on_key);
    glfwSetMouseButtonCallback(v.win, on_button);
    glfwSetCursorPosCallback(v.win, on_cursor);
    glfwSetScrollCallback(v.win, on_scroll);
    glfwSetFramebufferSizeCallback(v.win, on_resize);
    v.t_title = now_seconds();
    if (script) run_script(&v, script);
    else if (frames >= 0) run_frames(&v, frames, 0);
    else run_frames(&v, 0x7fffffff, 1);
    if (shot) scripted_screenshot(&v, shot);
    hd_destroy(v.ctx);
    glDeleteTextures(1, &v.tex);
    glDeleteFramebuffers(1, &v.fbo);
    glfwDestroyWindow(v.win);
    glfwTerminate();
    return 0;
}
