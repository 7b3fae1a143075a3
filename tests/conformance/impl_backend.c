/* impl_backend.c - the backend under test as the table hd_api_backend (see hd_api.h). Build it
   with exactly one of -DHYBRIDDIFF_BACKEND_OPENCL, _VULKAN, _GL (or _CPU, to test the suite).
   Also hd_backend_runtime_present: the backend's runtime probed directly, not through the
   library, so a library that fails to start on a machine with a device is not taken for a
   machine without one. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_STATIC
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hd_api.h"
#include <stdio.h>

HD_API_TABLE(hd_api_backend);

#if defined(HYBRIDDIFF_BACKEND_OPENCL)
int hd_backend_runtime_present(char *why, size_t why_size)
{
    cl_platform_id platforms[16];
    cl_uint np = 0, i, devices = 0;
    cl_int err = clGetPlatformIDs(16, platforms, &np);
    if (err != CL_SUCCESS || np == 0) {
        snprintf(why, why_size, "no OpenCL platform (clGetPlatformIDs: %d, %u platforms)", (int)err, (unsigned)np);
        return 0;
    }
    for (i = 0; i < np && i < 16; ++i) {
        cl_uint nd = 0;
        if (clGetDeviceIDs(platforms[i], CL_DEVICE_TYPE_ALL, 0, NULL, &nd) == CL_SUCCESS) devices += nd;
    }
    snprintf(why, why_size, "OpenCL: %u platform(s), %u device(s)", (unsigned)np, (unsigned)devices);
    return devices > 0;
}
#elif defined(HYBRIDDIFF_BACKEND_GL)
int hd_backend_runtime_present(char *why, size_t why_size)
{
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_display =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    const char *cext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    EGLDisplay dpy = EGL_NO_DISPLAY;
    EGLint major = 0, minor = 0;
    EGLint attrs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 3, EGL_CONTEXT_OPENGL_PROFILE_MASK,
                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLContext c;
    if (get_display && cext && strstr(cext, "EGL_MESA_platform_surfaceless")) {
        dpy = get_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
        if (dpy != EGL_NO_DISPLAY && !eglInitialize(dpy, &major, &minor)) dpy = EGL_NO_DISPLAY;
    }
    if (dpy == EGL_NO_DISPLAY) {
        dpy = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        if (dpy != EGL_NO_DISPLAY && !eglInitialize(dpy, &major, &minor)) dpy = EGL_NO_DISPLAY;
    }
    if (dpy == EGL_NO_DISPLAY) {
        snprintf(why, why_size, "no EGL display (surfaceless or default: 0x%04x)", (unsigned)eglGetError());
        return 0;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        snprintf(why, why_size, "EGL %d.%d without the OpenGL API", (int)major, (int)minor);
        return 0;
    }
    /* no config: EGL_KHR_no_config_context (Mesa, NVIDIA) */
    c = eglCreateContext(dpy, (EGLConfig)0, EGL_NO_CONTEXT, attrs);
    if (c == EGL_NO_CONTEXT) {
        snprintf(why, why_size, "EGL %d.%d (%s): no OpenGL 4.3 core context (0x%04x)", (int)major, (int)minor,
                 eglQueryString(dpy, EGL_VENDOR), (unsigned)eglGetError());
        return 0;
    }
    eglDestroyContext(dpy, c);
    snprintf(why, why_size, "EGL %d.%d (%s) makes an OpenGL 4.3 core context", (int)major, (int)minor,
             eglQueryString(dpy, EGL_VENDOR));
    return 1;
}
#elif defined(HYBRIDDIFF_BACKEND_VULKAN)
#include "hd_probe_vk.h"
#elif defined(HYBRIDDIFF_BACKEND_CPU)
int hd_backend_runtime_present(char *why, size_t why_size)
{
    snprintf(why, why_size, "the CPU backend needs no runtime");
    return 1;
}
#endif
