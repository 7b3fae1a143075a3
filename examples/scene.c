/* scene.c - hybriddiff inside a host's GL scene: a ground plane and boxes drawn with a depth
   buffer, a smoke cloud placed by a volume-to-world transform, one camera given to both as view and
   projection matrices, the library's linear premultiplied output composited over the scene. A
   second, living volume: smoke rising from the green box, a small procedural plume (value noise
   carried up with time) given to its own context by hd_update_volume every frame; its light
   continues from the previous frame's (the warm start) within a 10 ms render_budget
   (interactive runs; the scripted ones, --frames, run without a budget).

   Each frame:
     1. the meshes go into the application's HDR framebuffer (RGBA16F colour, float depth);
     2. their depth goes to the library (hd_set_depth), so the cloud's rays end at the meshes:
        a post standing in the cloud cuts it, a box in front of it hides it;
     3. hd_render, then hd_gl_render_to_texture_ex writes linear premultiplied RGBA16F;
     4. the cloud and the plume (the farther first) are blended over the scene with ONE,
        ONE_MINUS_SRC_ALPHA, in linear light;
     5. tone mapping and sRGB encoding into the window.

   Usage: scene [--size WxH] [--frames N] [--out PNG] [--check]   (drag to orbit, wheel to zoom)
   With --frames the camera turns by a fixed step per frame, then rests, and the last frame is
   written to PNG (make scene runs it under xvfb-run: out/scene.png). --check exits 1 unless the
   last frame's cloud is finite, covers part of the image and leaves part of it uncovered (the
   test make test-scene runs). C99, OpenGL 4.5 core, GLFW. */
#define GL_GLEXT_PROTOTYPES /* before hybriddiff.h, which includes GL/glcorearb.h */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_GL
#include "hybriddiff.h"
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <GL/glcorearb.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hd_png.h"
#include "hd_scene_common.h"

#define CLOUD_N 96

/* gluPerspective: right-handed eye space, NDC z in [-1, 1] */
static mat4 mat4_perspective(float fov_y_degrees, float aspect, float znear, float zfar)
{
    mat4 r;
    float f = 1.0f / tanf(fov_y_degrees * PI / 360.0f);
    memset(&r, 0, sizeof r);
    r.m[0] = f / aspect;
    r.m[5] = f;
    r.m[10] = (zfar + znear) / (znear - zfar);
    r.m[11] = -1.0f;
    r.m[14] = 2.0f * zfar * znear / (znear - zfar);
    return r;
}

/* ---- the meshes: unit cubes under a model matrix, a ground plane ---------------------------- */
static const char *mesh_vs =
    "#version 450 core\n"
    "layout(location = 0) in vec3 pos; layout(location = 1) in vec3 nrm;\n"
    "uniform mat4 mvp, model; out vec3 n_world;\n"
    "void main() { n_world = mat3(model) * nrm; gl_Position = mvp * vec4(pos, 1.0); }\n";
static const char *mesh_fs =
    "#version 450 core\n"
    "in vec3 n_world; uniform vec3 albedo, sun_dir, sun_rgb; out vec4 colour; /* Lambert, a sky term */\n"
    "void main() { float l = max(dot(normalize(n_world), -sun_dir), 0.0);\n"
    "  colour = vec4(albedo / 3.14159265 * (sun_rgb * l + vec3(0.8, 0.95, 1.25)), 1.0); }\n";
/* a full-screen triangle: the cloud's texture blended over the scene, then the tone map */
static const char *quad_vs =
    "#version 450 core\n"
    "out vec2 uv; void main() { uv = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);\n"
    "  gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0); }\n";
static const char *blend_fs =
    "#version 450 core\n"
    "in vec2 uv; uniform sampler2D img; out vec4 colour; void main() { colour = texture(img, uv); }\n";
static const char *tonemap_fs =
    "#version 450 core\n"
    "in vec2 uv; uniform sampler2D img; out vec4 colour;\n"
    "void main() { vec3 c = texture(img, uv).rgb; c = c / (1.0 + c);\n"
    "  colour = vec4(mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c)), 1.0); }\n";

static GLuint compile(GLenum type, const char *src)
{
    GLuint s = glCreateShader(type);
    GLint ok = 0;
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024];
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        fprintf(stderr, "scene: shader: %s\n", log);
        exit(1);
    }
    return s;
}

static GLuint program(const char *vs, const char *fs)
{
    GLuint p = glCreateProgram();
    GLint ok = 0;
    glAttachShader(p, compile(GL_VERTEX_SHADER, vs));
    glAttachShader(p, compile(GL_FRAGMENT_SHADER, fs));
    glLinkProgram(p);
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        fprintf(stderr, "scene: a shader program does not link\n");
        exit(1);
    }
    return p;
}


typedef struct mesh { mat4 model; float albedo[3]; } mesh;

typedef struct app {
    GLFWwindow *win;
    int w, h;
    float yaw, pitch, dist;
    double mx, my;
    int dragging;
    GLuint fbo, colour, depth, cloud_tex, smoke_tex, vao, vbo, empty_vao, p_mesh, p_blend, p_tonemap;
    float *depth_top_first, *depth_rows;
    hd_context hd, smoke;
    float *smoke_vox;            /* the plume's voxels, SMOKE_N^3 */
    int frame;                   /* frames drawn: the plume's clock (1/30 s each) */
    float cloud_at[3], smoke_at[3]; /* the volumes' centres in the world (the blending order) */
} app;

static const float sun_dir[3] = {-0.45f, -0.8f, -0.4f}; /* the direction sunlight travels in */
static const float sun_rgb[3] = {9.0f, 8.4f, 7.5f}; /* linear radiance units, as the library's */

static void die(const char *what, hd_result r)
{
    fprintf(stderr, "scene: %s: %s\n", what, hd_result_string(r));
    exit(1);
}

static void on_button(GLFWwindow *w, int button, int action, int mods)
{
    app *a = (app *)glfwGetWindowUserPointer(w);
    (void)mods;
    if (button == GLFW_MOUSE_BUTTON_LEFT) a->dragging = action == GLFW_PRESS;
    glfwGetCursorPos(w, &a->mx, &a->my);
}

static void on_cursor(GLFWwindow *w, double x, double y)
{
    app *a = (app *)glfwGetWindowUserPointer(w);
    if (a->dragging) {
        a->yaw -= (float)(x - a->mx) * 0.008f;
        a->pitch += (float)(y - a->my) * 0.008f;
        a->pitch = a->pitch < -0.1f ? -0.1f : a->pitch > 1.4f ? 1.4f : a->pitch;
    }
    a->mx = x, a->my = y;
}

static void on_scroll(GLFWwindow *w, double dx, double dy)
{
    app *a = (app *)glfwGetWindowUserPointer(w);
    (void)dx;
    a->dist *= dy > 0 ? 0.9f : 1.1f;
    a->dist = a->dist < 3.0f ? 3.0f : a->dist > 40.0f ? 40.0f : a->dist;
}

static void draw_frame(app *a, const mesh *meshes, int mesh_count)
{
    float eye[3] = {a->dist * cosf(a->pitch) * sinf(a->yaw), 1.0f + a->dist * sinf(a->pitch),
                    a->dist * cosf(a->pitch) * cosf(a->yaw)};
    const float at[3] = {0.0f, 1.2f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    mat4 view = mat4_look_at(eye, at, up);
    mat4 proj = mat4_perspective(45.0f, (float)a->w / (float)a->h, 0.1f, 100.0f);
    mat4 vp = mat4_mul(proj, view);
    hd_camera cam = HD_CAMERA_INIT;
    hd_depth_desc depth = HD_DEPTH_DESC_INIT;
    hd_output out = HD_OUTPUT_INIT;
    hd_result r;

    /* 1. the meshes, into the HDR framebuffer with a depth buffer */
    glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
    glViewport(0, 0, a->w, a->h);
    glClearColor(0.35f, 0.45f, 0.6f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glUseProgram(a->p_mesh);
    glUniform3fv(glGetUniformLocation(a->p_mesh, "sun_dir"), 1, sun_dir);
    glUniform3fv(glGetUniformLocation(a->p_mesh, "sun_rgb"), 1, sun_rgb);
    glBindVertexArray(a->vao);
    for (int i = 0; i < mesh_count; ++i) {
        mat4 mvp = mat4_mul(vp, meshes[i].model);
        glUniformMatrix4fv(glGetUniformLocation(a->p_mesh, "mvp"), 1, GL_FALSE, mvp.m);
        glUniformMatrix4fv(glGetUniformLocation(a->p_mesh, "model"), 1, GL_FALSE, meshes[i].model.m);
        glUniform3fv(glGetUniformLocation(a->p_mesh, "albedo"), 1, meshes[i].albedo);
        glDrawArrays(GL_TRIANGLES, 0, 36);
    }
    glDisable(GL_DEPTH_TEST);

    /* 2. the same camera and the scene's depth to the library (rows top first, the library's
       image order; GL's are bottom first) */
    memcpy(cam.view, view.m, sizeof cam.view);
    memcpy(cam.projection, proj.m, sizeof cam.projection);
    cam.width = a->w, cam.height = a->h;
    if ((r = hd_set_camera(a->hd, &cam)) != HD_SUCCESS) die("hd_set_camera", r);
    glReadPixels(0, 0, a->w, a->h, GL_DEPTH_COMPONENT, GL_FLOAT, a->depth_rows);
    for (int y = 0; y < a->h; ++y)
        memcpy(a->depth_top_first + (size_t)y * a->w, a->depth_rows + (size_t)(a->h - 1 - y) * a->w,
               sizeof(float) * (size_t)a->w);
    depth.data = a->depth_top_first;
    depth.width = a->w, depth.height = a->h;
    if ((r = hd_set_depth(a->hd, &depth)) != HD_SUCCESS) die("hd_set_depth", r);
    if ((r = hd_set_camera(a->smoke, &cam)) != HD_SUCCESS) die("hd_set_camera (plume)", r);
    if ((r = hd_set_depth(a->smoke, &depth)) != HD_SUCCESS) die("hd_set_depth (plume)", r);

    /* the plume's next step: new voxels in place; E and phi carry over as the warm start */
    {
        hd_volume_update u = HD_VOLUME_UPDATE_INIT;
        make_smoke(a->smoke_vox, SMOKE_N, (float)a->frame++ / 30.0f);
        u.type = HD_VOXEL_F32;
        u.dims[0] = u.dims[1] = u.dims[2] = SMOKE_N;
        u.data = a->smoke_vox;
        if ((r = hd_update_volume(a->smoke, &u)) != HD_SUCCESS) die("hd_update_volume", r);
    }

    /* 3. the cloud and the plume, linear premultiplied RGBA16F (the library restores the GL state
       it changes) */
    out.format = HD_OUTPUT_LINEAR_F16;
    if ((r = hd_render(a->hd)) != HD_SUCCESS) die("hd_render", r);
    if ((r = hd_gl_render_to_texture_ex(a->hd, a->cloud_tex, &out)) != HD_SUCCESS) die("hd_gl_render_to_texture_ex", r);
    if ((r = hd_render(a->smoke)) != HD_SUCCESS) die("hd_render (plume)", r);
    if ((r = hd_gl_render_to_texture_ex(a->smoke, a->smoke_tex, &out)) != HD_SUCCESS) die("hd_gl_render_to_texture_ex (plume)", r);

    /* 4. composited over the scene: premultiplied alpha, the farther volume first (they do not
       overlap in space, so each is wholly in front of or behind the other along a ray) */
    {
        int smoke_first = volume_farther(eye, a->smoke_at, a->cloud_at);
        GLuint order[2];
        order[0] = smoke_first ? a->smoke_tex : a->cloud_tex;
        order[1] = smoke_first ? a->cloud_tex : a->smoke_tex;
        glBindFramebuffer(GL_FRAMEBUFFER, a->fbo);
        glEnable(GL_BLEND);
        glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
        glUseProgram(a->p_blend);
        glBindVertexArray(a->empty_vao);
        glActiveTexture(GL_TEXTURE0);
        for (int k = 0; k < 2; ++k) {
            glBindTexture(GL_TEXTURE_2D, order[k]);
            glDrawArrays(GL_TRIANGLES, 0, 3);
        }
        glDisable(GL_BLEND);
    }

    /* 5. tone map into the window */
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glUseProgram(a->p_tonemap);
    glBindTexture(GL_TEXTURE_2D, a->colour);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

/* The window's image (read before the buffers swap) as a PNG, rows top first. */
static int write_png(app *a, const char *path)
{
    size_t row = (size_t)a->w * 4;
    unsigned char *px = (unsigned char *)malloc(row * a->h * 2);
    char err[256];
    int ok;
    if (!px) return 0;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, a->w, a->h, GL_RGBA, GL_UNSIGNED_BYTE, px);
    for (int y = 0; y < a->h; ++y) memcpy(px + row * (a->h + y), px + row * (a->h - 1 - y), row);
    ok = hdx_png_write(path, a->w, a->h, 4, px + row * a->h, (int)row, err, sizeof err);
    if (!ok) fprintf(stderr, "scene: cannot write %s: %s\n", path, err);
    free(px);
    return ok;
}

static GLuint texture2d(GLenum format, int w, int h)
{
    GLuint t;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, format, w, h);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return t;
}

int main(int argc, char **argv)
{
    app a;
    int frames = -1, check = 0;
    const char *out_path = NULL;
    static unsigned char cloud[CLOUD_N * CLOUD_N * CLOUD_N];
    float cube[36 * 6];
    hd_desc desc = HD_DESC_INIT;
    hd_light sun = HD_LIGHT_INIT;
    mat4 place;
    mesh meshes[5];
    hd_result r;

    memset(&a, 0, sizeof a);
    a.w = 960, a.h = 540, a.yaw = 0.6f, a.pitch = 0.25f, a.dist = 9.0f;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc && sscanf(argv[i + 1], "%dx%d", &a.w, &a.h) == 2 &&
            a.w > 0 && a.h > 0 && a.w <= 4096 && a.h <= 4096) ++i;
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc && (frames = atoi(argv[i + 1])) > 0) ++i;
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out_path = argv[++i];
        else if (!strcmp(argv[i], "--check")) check = 1;
        else {
            fprintf(stderr, "usage: scene [--size WxH] [--frames N] [--out PNG] [--check]\n");
            return 2;
        }
    }
    if ((out_path || check) && frames < 0) frames = 64;
    if (!glfwInit()) { fprintf(stderr, "scene: glfwInit failed (no display?)\n"); return 1; }
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    if (!(a.win = glfwCreateWindow(a.w, a.h, "hybriddiff scene", NULL, NULL))) {
        fprintf(stderr, "scene: no window with an OpenGL 4.5 core context\n");
        return 1;
    }
    glfwMakeContextCurrent(a.win);
    glfwSwapInterval(1);
    glfwSetWindowUserPointer(a.win, &a);
    glfwSetMouseButtonCallback(a.win, on_button);
    glfwSetCursorPosCallback(a.win, on_cursor);
    glfwSetScrollCallback(a.win, on_scroll);
    glfwGetFramebufferSize(a.win, &a.w, &a.h);

    /* the application's framebuffer: linear HDR colour and a float depth buffer */
    a.colour = texture2d(GL_RGBA16F, a.w, a.h);
    a.depth = texture2d(GL_DEPTH_COMPONENT32F, a.w, a.h);
    a.cloud_tex = texture2d(GL_RGBA16F, a.w, a.h);
    a.smoke_tex = texture2d(GL_RGBA16F, a.w, a.h);
    glGenFramebuffers(1, &a.fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, a.fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, a.colour, 0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, a.depth, 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        fprintf(stderr, "scene: the HDR framebuffer is incomplete\n");
        return 1;
    }
    a.depth_rows = (float *)malloc(sizeof(float) * (size_t)a.w * a.h);
    a.depth_top_first = (float *)malloc(sizeof(float) * (size_t)a.w * a.h);
    if (!a.depth_rows || !a.depth_top_first) return 1;
    cube_vertices(cube);
    glGenVertexArrays(1, &a.vao);
    glGenVertexArrays(1, &a.empty_vao);
    glBindVertexArray(a.vao);
    glGenBuffers(1, &a.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, a.vbo);
    glBufferData(GL_ARRAY_BUFFER, sizeof cube, cube, GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)0);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), (void *)(3 * sizeof(float)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    a.p_mesh = program(mesh_vs, mesh_fs);
    a.p_blend = program(quad_vs, blend_fs);
    a.p_tonemap = program(quad_vs, tonemap_fs);

    /* the scene: a ground plane, a box in front of the cloud, one behind, a post through it */
    meshes[0].model = mat4_mul(mat4_translate(0.0f, -0.05f, 0.0f), mat4_scale(30.0f, 0.1f, 30.0f));
    meshes[1].model = mat4_mul(mat4_translate(0.7f, 0.5f, 2.7f), mat4_scale(1.0f, 1.0f, 1.0f));
    meshes[2].model = mat4_mul(mat4_translate(-1.7f, 0.75f, -2.6f), mat4_scale(1.5f, 1.5f, 1.5f));
    meshes[3].model = mat4_mul(mat4_translate(0.4f, 1.5f, 0.2f), mat4_scale(0.18f, 3.0f, 0.18f));
    meshes[4].model = mat4_mul(mat4_translate(-3.5f, 0.4f, 2.0f), mat4_mul(mat4_rotate_y(0.5f), mat4_scale(0.8f, 0.8f, 0.8f)));
    {
        static const float albedo[5][3] = {{0.5f, 0.48f, 0.45f}, {0.7f, 0.25f, 0.2f}, {0.2f, 0.4f, 0.7f},
                                           {0.8f, 0.75f, 0.3f}, {0.3f, 0.6f, 0.3f}};
        for (int i = 0; i < 5; ++i) memcpy(meshes[i].albedo, albedo[i], sizeof albedo[i]);
    }

    /* the cloud: its box (largest side 1, centred at 0) placed 4 units wide, 1.6 above the
       ground, turned about y; extinction and the light are in world units */
    make_cloud(cloud, CLOUD_N);
    place = mat4_mul(mat4_translate(0.0f, 1.6f, 0.0f), mat4_mul(mat4_rotate_y(0.4f), mat4_scale(4.0f, 2.6f, 4.0f)));
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = CLOUD_N;
    desc.volume.data = cloud;
    memcpy(desc.volume.transform, place.m, sizeof desc.volume.transform);
    memcpy(sun.direction, sun_dir, sizeof sun.direction);
    memcpy(sun.color, sun_rgb, sizeof sun.color);
    sun.type = HD_LIGHT_DIRECTIONAL;
    desc.lights = &sun;
    desc.light_count = 1;
    desc.params.extinction = 6.0f; /* per world unit: the cloud is 4 units across */
    desc.params.albedo = 0.95f;
    desc.params.render_scale = HD_RENDER_SCALE_AUTO;
    /* 30 ms per frame (the plume 10 ms): render_budget is a hard limit, so on a software
       rasteriser, where no frame fits one, the scripted runs (--frames) take one whole light
       iteration per frame instead and refine the image while the camera rests */
    desc.params.render_budget = frames > 0 ? 0.0f : 0.03f;
    desc.camera.width = a.w, desc.camera.height = a.h;
    desc.logger.func = hd_log_stderr;
    desc.gl.use_current_context = 1;
    desc.gl.get_proc_address = glfwGetProcAddress;
    if ((r = hd_create(&desc, &a.hd)) != HD_SUCCESS) die("hd_create", r);
    a.cloud_at[0] = 0.0f, a.cloud_at[1] = 1.6f, a.cloud_at[2] = 0.0f;

    /* the plume: a box 1.2 wide and 2.8 tall standing on the green box, F32 voxels replaced every
       frame (hd_update_volume in draw_frame), a budget of 10 ms per frame */
    if (!(a.smoke_vox = smoke_volume(&desc, a.smoke_at))) return 1;
    desc.params.render_budget = frames > 0 ? 0.0f : 0.01f;
    if ((r = hd_create(&desc, &a.smoke)) != HD_SUCCESS) die("hd_create (plume)", r);

    /* --frames: the camera turns for all but the last 16 frames, which rest so the light and
       the image converge before the screenshot */
    if (frames > 0) a.yaw -= 0.02f * (float)(frames > 16 ? frames - 16 : 0); /* ends at the default view */
    for (int f = 0; frames < 0 ? !glfwWindowShouldClose(a.win) : f < frames; ++f) {
        if (frames > 0 && f < frames - 16) a.yaw += 0.02f;
        draw_frame(&a, meshes, 5);
        if (out_path && f == frames - 1) {
            if (!write_png(&a, out_path)) return 1;
            fprintf(stderr, "scene: wrote %s (%dx%d)\n", out_path, a.w, a.h);
        }
        glfwSwapBuffers(a.win);
        glfwPollEvents();
    }
    if (check && !(check_volume("scene", a.hd, a.w, a.h, "cloud", 0.2f, 100) & check_volume("scene", a.smoke, a.w, a.h, "plume", 0.05f, 500)))
        return 1;
    hd_destroy(a.hd);
    hd_destroy(a.smoke);
    free(a.smoke_vox);
    free(a.depth_rows);
    free(a.depth_top_first);
    glfwDestroyWindow(a.win);
    glfwTerminate();
    return 0;
}
