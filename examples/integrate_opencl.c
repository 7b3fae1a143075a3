/* integrate_opencl.c - hybriddiff on the application's own OpenCL context and queue: the
   application keeps using the context after hd_destroy. Exits 1 on a blank image or an error.
   Built in C99 and C++17, with hybriddiff.h before (default) or after (-DINTEGRATE_HD_LAST)
   the system headers (mk/integrate.mk). */
#ifndef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_OPENCL
#include "hybriddiff.h"
#endif
#include <stdio.h>
#define CL_TARGET_OPENCL_VERSION 120
#include <CL/cl.h>
#ifdef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_OPENCL
#include "hybriddiff.h"
#endif

int main(void)
{
    enum { N = 32, W = 64 };
    static unsigned short voxels[N * N * N];
    static unsigned char pixels[W * W * 4];
    cl_platform_id platform;
    cl_device_id device;
    cl_context context;
    cl_command_queue queue;
    cl_mem mine;
    cl_int e;
    hd_desc desc = HD_DESC_INIT;
    hd_context ctx;
    hd_result r;
    int i, x, y, z, lit = 0;

    if (clGetPlatformIDs(1, &platform, NULL) != CL_SUCCESS ||
        clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, NULL) != CL_SUCCESS) {
        fprintf(stderr, "no OpenCL device\n");
        return 1;
    }
    context = clCreateContext(NULL, 1, &device, NULL, NULL, &e);
    queue = clCreateCommandQueue(context, device, 0, &e);

    for (z = 0; z < N; ++z) /* a 16-bit slab, denser toward +z */
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) voxels[(z * N + y) * N + x] = (unsigned short)(x > 4 && x < N - 4 ? 1000 * z : 0);
    desc.volume.type = HD_VOXEL_U16;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = N;
    desc.volume.data = voxels;
    desc.volume.value_range[0] = 0.0f; /* raw values mapped to TF coordinates 0 and 1 */
    desc.volume.value_range[1] = 1000.0f * (N - 1);
    desc.camera.width = desc.camera.height = W;
    desc.logger.func = hd_log_stderr;
    desc.opencl.context = context;
    desc.opencl.device = device;
    desc.opencl.queue = queue;
    if ((r = hd_create(&desc, &ctx)) != HD_SUCCESS) { fprintf(stderr, "hd_create: %s\n", hd_result_string(r)); return 1; }
    for (i = 0; i < 4; ++i)
        if ((r = hd_render(ctx)) != HD_SUCCESS) { fprintf(stderr, "hd_render: %s\n", hd_result_string(r)); return 1; }
    hd_read_image_rgba8(ctx, pixels, sizeof pixels);
    hd_destroy(ctx);

    mine = clCreateBuffer(context, CL_MEM_READ_WRITE, 64, NULL, &e); /* the context is still ours */
    if (e != CL_SUCCESS) { fprintf(stderr, "the context is unusable after hd_destroy\n"); return 1; }
    clReleaseMemObject(mine);
    clReleaseCommandQueue(queue);
    clReleaseContext(context);
    for (i = 0; i < W * W * 4; i += 4) lit += pixels[i] > 8;
    printf("integrate_opencl: %d lit pixels\n", lit);
    return lit > 0 ? 0 : 1;
}
