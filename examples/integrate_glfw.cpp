// integrate_glfw.cpp - C++17, GLFW's default (GLX) context: hybriddiff renders in that context
// (desc.gl.use_current_context) straight into the application's texture, which the application
// reads back and compares with hd_read_image_rgba8. Then a context of the library's own (EGL),
// called with GLFW's context not current (the two APIs cannot be current on one thread at once).
// Exits 1 on a blank or differing image or an error. Run under xvfb-run (mk/integrate.mk), with
// hybriddiff.h before (default) or after (-DINTEGRATE_HD_LAST) the GLFW header.
#ifndef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_GL
#include "hybriddiff.h"
#endif
#include <GLFW/glfw3.h>
#include <cstdio>
#include <cstdlib>
#include <vector>
#ifdef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_GL
#include "hybriddiff.h"
#endif

static int fail(const char *what, hd_result r)
{
    std::fprintf(stderr, "integrate_glfw: %s: %s\n", what, hd_result_string(r));
    return 1;
}

int main()
{
    const int n = 32, w = 64;
    std::vector<unsigned char> voxels(size_t(n) * n * n);
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x)
                voxels[(size_t(z) * n + y) * n + x] = (unsigned char)((x - 16) * (x - 16) + (y - 16) * (y - 16) < 100 ? 230 : 0);
    if (!glfwInit()) return std::fprintf(stderr, "integrate_glfw: no display\n"), 1;
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
    GLFWwindow *win = glfwCreateWindow(w, w, "integrate_glfw", nullptr, nullptr);
    if (!win) return std::fprintf(stderr, "integrate_glfw: no GL 4.5 context\n"), 1;
    glfwMakeContextCurrent(win);

    hd_desc desc = HD_DESC_INIT;
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = n;
    desc.volume.data = voxels.data();
    desc.camera.width = desc.camera.height = w;
    desc.logger.func = hd_log_stderr;
    desc.gl.use_current_context = 1;                   // GLFW's context, current on this thread
    desc.gl.get_proc_address = glfwGetProcAddress;     // no cast: both return a void (*)(void)
    hd_context ctx;
    hd_result r = hd_create(&desc, &ctx);
    if (r != HD_SUCCESS) return fail("hd_create (the application's context)", r);

    GLuint tex = 0;
    glGenTextures(1, &tex);
    glBindTexture(GL_TEXTURE_2D, tex);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, w, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    for (int i = 0; i < 4; ++i)
        if ((r = hd_render(ctx)) != HD_SUCCESS) return fail("hd_render", r);
    if ((r = hd_gl_render_to_texture(ctx, tex)) != HD_SUCCESS) return fail("hd_gl_render_to_texture", r);
    std::vector<unsigned char> fromtex(size_t(w) * w * 4), fromread(fromtex.size());
    glBindTexture(GL_TEXTURE_2D, tex);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_UNSIGNED_BYTE, fromtex.data());
    if ((r = hd_read_image_rgba8(ctx, fromread.data(), fromread.size())) != HD_SUCCESS) return fail("hd_read_image_rgba8", r);
    int lit = 0, diff = 0;
    for (int y = 0; y < w; ++y) // the texture's rows are bottom first
        for (int i = 0; i < w * 4; ++i) {
            int a = fromtex[size_t(w - 1 - y) * w * 4 + i], b = fromread[size_t(y) * w * 4 + i];
            diff = std::abs(a - b) > diff ? std::abs(a - b) : diff;
            lit += i % 4 == 0 && a > 8;
        }
    if ((r = hd_gl_render_to_texture(ctx, tex + 1000)) != HD_ERROR_INVALID_TEXTURE) return fail("a wrong texture name", r);
    glDeleteTextures(1, &tex);
    hd_destroy(ctx);

    // The library's own EGL context: GLFW's GLX context must not be current during the calls.
    glfwMakeContextCurrent(nullptr);
    desc.gl.use_current_context = 0;
    desc.gl.get_proc_address = nullptr;
    hd_context own;
    if ((r = hd_create(&desc, &own)) != HD_SUCCESS) return fail("hd_create (own context)", r);
    if ((r = hd_iterate(own, 2)) != HD_SUCCESS) return fail("hd_iterate (own context)", r);
    if ((r = hd_read_image_rgba8(own, fromread.data(), fromread.size())) != HD_SUCCESS) return fail("read (own context)", r);
    hd_destroy(own);
    glfwMakeContextCurrent(win);
    glfwDestroyWindow(win);
    glfwTerminate();
    std::printf("integrate_glfw: %d lit pixels, texture against read_image: max difference %d/255\n", lit, diff);
    return lit > 0 && diff == 0 ? 0 : 1;
}
