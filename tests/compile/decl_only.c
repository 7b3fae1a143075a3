/* decl_only.c - the declarations alone (no HYBRIDDIFF_IMPLEMENTATION, with or without a backend
   macro) must pull in no GPU API header. Each name below is a typedef or a function in one of
   those headers; declared here as an object, the header's own declaration of it would be a hard
   error ("redeclared as different kind of symbol", also inside a system header, where a mere
   warning would be silenced). The matrix proves the trap works: with HD_COMPILE_CONTROL set to
   one of the headers, this unit must fail to compile. */
static const int cl_int = 1, clGetPlatformIDs = 2;   /* CL/cl.h (cl_platform.h)           */
static const int VkFlags = 3, vkCreateInstance = 4;  /* vulkan/vulkan.h (vulkan_core.h)   */
static const int GLenum = 5, glGetError = 6;         /* GL/gl.h, GL/glcorearb.h            */
static const int EGLint = 7, eglGetDisplay = 8;      /* EGL/egl.h                          */

#include "hybriddiff.h"
#include "hybriddiff.h"

#ifdef HD_COMPILE_CONTROL
#include HD_COMPILE_CONTROL
#endif

int main(void)
{
    hd_desc desc;
    desc.light_count = cl_int + clGetPlatformIDs + VkFlags + vkCreateInstance + GLenum +
                       glGetError + EGLint + eglGetDisplay;
    return desc.light_count == 36 ? 0 : 1;
}
