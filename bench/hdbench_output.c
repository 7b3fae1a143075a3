/* hdbench_output - frames over converged light on one backend (make bench-output): the head CT
   at 1280x720, HD's light converged once by hd_render, then an orbit of camera moves, each frame
   the projection alone (no light work: hd_stats.iterations is checked to stay) and its output
   where a renderer wants it:
     CPU, OpenCL   hd_render + hd_read_image_ex (LINEAR_F16, and SRGB8) into host memory
     GL            hd_render + hd_gl_render_to_texture_ex into a GL_RGBA16F texture of the
                   bench's own context (use_current_context), glFinish'd; and hd_read_image_ex
     Vulkan        hd_vulkan_record_render into a VkImage (R16G16B16A16_SFLOAT) of the
                   backend's device, the command buffer submitted and waited for; and hd_render
                   + hd_read_image_ex
   Prints per path the median and the best ms per frame over the timed frames (after 2 warm-up
   frames): the whole frame, and the output alone where it is a call of its own. White box: the
   Vulkan path makes its image on the backend's own device (its function table). Figures, not a
   test. Usage: hdbench_output [--frames N] [--size WxH] [data/head.nrrd] */
#define HYBRIDDIFF_IMPLEMENTATION
#if !defined(HYBRIDDIFF_BACKEND_CPU) && !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_GL) && \
    !defined(HYBRIDDIFF_BACKEND_VULKAN)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#if defined(HYBRIDDIFF_BACKEND_GL)
#define GL_GLEXT_PROTOTYPES
#endif
#include "hybriddiff.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "hd_bench_median.h"

static const float bench_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f, 0.0f,     0.93f, 0.73f, 0.62f, 0.02f,
    0.93f, 0.73f, 0.62f, 0.05f, 1.0f, 0.98f, 0.9f, 0.5f,    1.0f, 1.0f, 1.0f, 1.0f,
    1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f};

#define MAX_FRAMES 64

static void orbit(hd_camera *c, int k)
{
    double a = 0.12 * k;
    c->eye[0] = (float)(2.3 * sin(a));
    c->eye[1] = (float)(2.3 * cos(a));
    c->eye[2] = 0.3f;
    c->up[0] = c->up[1] = 0.0f;
    c->up[2] = 1.0f;
    c->fov_y = 30.0f;
}

static void report(const char *what, double *ms, int n)
{
    double best = 1e30;
    int i;
    for (i = 0; i < n; ++i) best = ms[i] < best ? ms[i] : best;
    printf("  %-58s median %8.2f ms  best %8.2f ms  (%d frames)\n", what, hdb_median(ms, n), best, n);
}

#if defined(HYBRIDDIFF_BACKEND_VULKAN)
/* The caller's image and a command buffer on the backend's own device. */
static VkImage g_img;
static VkDeviceMemory g_mem;
static VkCommandPool g_pool;
static VkCommandBuffer g_cb;
static int vk_setup(hd_context h, int w, int ht)
{
    hd__backend *be = hd__lookup(h)->vw.be;
    VkImageCreateInfo ici;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo mai;
    VkCommandPoolCreateInfo cpci;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ici.imageType = VK_IMAGE_TYPE_2D;
    ici.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    ici.extent.width = (uint32_t)w;
    ici.extent.height = (uint32_t)ht;
    ici.extent.depth = 1;
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    if (be->fn.vkCreateImage(be->device, &ici, NULL, &g_img) != VK_SUCCESS) return 0;
    be->fn.vkGetImageMemoryRequirements(be->device, g_img, &req);
    memset(&mai, 0, sizeof mai);
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = (uint32_t)hd__vk_memory_type(be, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (be->fn.vkAllocateMemory(be->device, &mai, NULL, &g_mem) != VK_SUCCESS) return 0;
    if (be->fn.vkBindImageMemory(be->device, g_img, g_mem, 0) != VK_SUCCESS) return 0;
    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpci.queueFamilyIndex = be->queue_family;
    if (be->fn.vkCreateCommandPool(be->device, &cpci, NULL, &g_pool) != VK_SUCCESS) return 0;
    {
        VkCommandBufferAllocateInfo cbai;
        memset(&cbai, 0, sizeof cbai);
        cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
        cbai.commandPool = g_pool;
        cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cbai.commandBufferCount = 1;
        return be->fn.vkAllocateCommandBuffers(be->device, &cbai, &g_cb) == VK_SUCCESS;
    }
}
/* One displayed frame recorded: hd_vulkan_record_render into the image, submitted, waited. */
static int vk_frame(hd_context h, int first, int w, int ht)
{
    hd__backend *be = hd__lookup(h)->vw.be;
    VkCommandBufferBeginInfo bi;
    VkSubmitInfo si;
    VkCommandBuffer cb = g_cb;
    hd_vulkan_target t = HD_VULKAN_TARGET_INIT;
    hd_output o = HD_OUTPUT_INIT;
    hd_result r;
    if (be->fn.vkResetCommandBuffer(cb, 0) != VK_SUCCESS) return 0;
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    be->fn.vkBeginCommandBuffer(cb, &bi);
    o.format = HD_OUTPUT_LINEAR_F16;
    t.image = (uint64_t)g_img;
    t.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    t.layout = first ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    t.final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    t.width = w;
    t.height = ht;
    r = hd_vulkan_record_render(h, cb, &t, &o);
    be->fn.vkEndCommandBuffer(cb);
    if (r == HD_SUCCESS) {
        memset(&si, 0, sizeof si);
        si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cb;
        be->fn.vkQueueSubmit(be->queue, 1, &si, VK_NULL_HANDLE);
        be->fn.vkDeviceWaitIdle(be->device);
    }
    return r == HD_SUCCESS;
}
static void vk_teardown(hd_context h)
{
    hd__backend *be = hd__lookup(h)->vw.be;
    be->fn.vkDeviceWaitIdle(be->device);
    be->fn.vkDestroyCommandPool(be->device, g_pool, NULL);
    be->fn.vkDestroyImage(be->device, g_img, NULL);
    be->fn.vkFreeMemory(be->device, g_mem, NULL);
}
#endif

#if defined(HYBRIDDIFF_BACKEND_GL)
#include <GL/glcorearb.h>
static int gl_context(void)
{
    static const EGLint cfg_attrs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    static const EGLint ctx_attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    PFNEGLGETPLATFORMDISPLAYEXTPROC gpd = (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    EGLDisplay dpy = gpd ? gpd(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL) : EGL_NO_DISPLAY;
    EGLConfig cfg;
    EGLint n = 0;
    EGLContext c;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL) || !eglBindAPI(EGL_OPENGL_API) ||
        !eglChooseConfig(dpy, cfg_attrs, &cfg, 1, &n) || n < 1 ||
        (c = eglCreateContext(dpy, cfg, EGL_NO_CONTEXT, ctx_attrs)) == EGL_NO_CONTEXT)
        return 0;
    return eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, c) == EGL_TRUE;
}
#endif

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd";
    int frames = 10, w = 1280, ht = 720, i, k, calls;
    hd_volume_file vf;
    hd_desc d = HD_DESC_INIT;
    hd_light light = HD_LIGHT_INIT;
    hd_context h;
    hd_stats st;
    hd_output o = HD_OUTPUT_INIT;
    double t0, t1, t2, frame_ms[MAX_FRAMES], out_ms[MAX_FRAMES];
    uint64_t iters;
    void *host;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--frames") == 0 && i + 1 < argc) frames = atoi(argv[++i]);
        else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            if (sscanf(argv[++i], "%dx%d", &w, &ht) != 2) return 2;
        } else path = argv[i];
    }
    if (frames < 1 || frames > MAX_FRAMES) frames = 10;
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_output: cannot load %s (make data)\n", path);
        return 1;
    }
#if defined(HYBRIDDIFF_BACKEND_GL)
    if (!gl_context()) {
        fprintf(stderr, "hdbench_output: no surfaceless EGL OpenGL 4.5 context\n");
        return 1;
    }
    d.gl.use_current_context = 1;
#endif
    d.volume = vf.desc;
    d.volume.value_range[0] = -1024.0f;
    d.volume.value_range[1] = 3071.0f;
    d.transfer_function.rgba = bench_tf;
    d.transfer_function.count = (int)(sizeof bench_tf / sizeof bench_tf[0] / 4);
    light.direction[0] = -0.5f; light.direction[1] = -1.0f; light.direction[2] = -0.6f;
    d.lights = &light;
    d.light_count = 1;
    d.camera.width = w;
    d.camera.height = ht;
    orbit(&d.camera, 0);
    d.logger.func = hd_log_stderr;
    if (hd_create(&d, &h) != HD_SUCCESS) return 1;
    hd_volume_free(&vf);
    host = malloc((size_t)w * ht * 8);
    t0 = hd__now();
    for (calls = 0; calls < 200; ++calls) {
        if (hd_render(h) != HD_SUCCESS) return 1;
        hd_get_stats(h, &st);
        if (st.light_converged) break;
    }
    printf("%s backend, %dx%d: light converged after %llu iterations (%.1f s, error %.3g)\n", hd_backend_name(), w, ht,
           (unsigned long long)st.iterations, hd__now() - t0, st.light_error);
    iters = st.iterations;
    o.format = HD_OUTPUT_LINEAR_F16;
    /* hd_render (the projection alone) + hd_read_image_ex, every backend */
    for (k = 0; k < frames + 2; ++k) {
        orbit(&d.camera, k + 1);
        t0 = hd__now();
        if (hd_set_camera(h, &d.camera) != HD_SUCCESS || hd_render(h) != HD_SUCCESS) return 1;
        t1 = hd__now();
        if (hd_read_image_ex(h, &o, host, (size_t)w * ht * 8, 0) != HD_SUCCESS) return 1;
        t2 = hd__now();
        if (k >= 2) { frame_ms[k - 2] = 1e3 * (t2 - t0); out_ms[k - 2] = 1e3 * (t2 - t1); }
    }
    report("hd_render + hd_read_image_ex(LINEAR_F16): frame", frame_ms, frames);
    report("  of which hd_read_image_ex(LINEAR_F16)", out_ms, frames);
    o.format = HD_OUTPUT_SRGB8;
    for (k = 0; k < frames + 2; ++k) {
        t0 = hd__now();
        if (hd_read_image_ex(h, &o, host, (size_t)w * ht * 8, 0) != HD_SUCCESS) return 1;
        if (k >= 2) out_ms[k - 2] = 1e3 * (hd__now() - t0);
    }
    report("hd_read_image_ex(SRGB8) alone", out_ms, frames);
#if defined(HYBRIDDIFF_BACKEND_GL)
    {
        GLuint tex;
        glGenTextures(1, &tex);
        glBindTexture(GL_TEXTURE_2D, tex);
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA16F, w, ht);
        o.format = HD_OUTPUT_LINEAR_F16;
        for (k = 0; k < frames + 2; ++k) {
            orbit(&d.camera, k + 20);
            t0 = hd__now();
            if (hd_set_camera(h, &d.camera) != HD_SUCCESS || hd_render(h) != HD_SUCCESS) return 1;
            glFinish();
            t1 = hd__now();
            if (hd_gl_render_to_texture_ex(h, tex, &o) != HD_SUCCESS) return 1;
            glFinish();
            t2 = hd__now();
            if (k >= 2) { frame_ms[k - 2] = 1e3 * (t2 - t0); out_ms[k - 2] = 1e3 * (t2 - t1); }
        }
        report("hd_render + hd_gl_render_to_texture_ex(GL_RGBA16F): frame", frame_ms, frames);
        report("  of which hd_gl_render_to_texture_ex", out_ms, frames);
        glDeleteTextures(1, &tex);
    }
#endif
#if defined(HYBRIDDIFF_BACKEND_VULKAN)
    if (!vk_setup(h, w, ht)) return 1;
    for (k = 0; k < frames + 2; ++k) {
        orbit(&d.camera, k + 20);
        t0 = hd__now();
        if (hd_set_camera(h, &d.camera) != HD_SUCCESS || !vk_frame(h, k == 0, w, ht)) return 1;
        if (k >= 2) frame_ms[k - 2] = 1e3 * (hd__now() - t0);
    }
    report("hd_vulkan_record_render into a VkImage (R16G16B16A16): frame", frame_ms, frames);
    vk_teardown(h);
#endif
    hd_get_stats(h, &st);
    printf("  light iterations during the frames: %llu (the projection alone)\n", (unsigned long long)(st.iterations - iters));
    free(host);
    hd_destroy(h);
    return st.iterations == iters ? 0 : 1;
}
