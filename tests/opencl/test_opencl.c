/* test_opencl.c - the OpenCL backend's own checks (make test-opencl): hd_opencl_set_depth_buffer,
   the host's depth as a cl_mem buffer of the caller's context (desc.opencl), copied on the
   device: the image is bit for bit hd_set_depth's of the same values (rows top first), which
   differs from the image without depth, also after a method change (the buffer is kept) and at
   a byte offset; hd_set_depth(NULL) clears it. Refusals, each its own hd_result and one logged
   error with the depth held kept: NULL, an offset not a multiple of 4, a buffer too small, an
   image object, a buffer of another context, a look-at camera. Without an OpenCL device it
   prints SKIPPED (a failure under HD_CONFORMANCE_REQUIRE=1). */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_OPENCL
#include "hybriddiff.h"
#include <stdio.h>
#include <stdlib.h>

static int failures, errors;
static hd_result last;
#define CHECK(cond, ...) do { if (!(cond)) { printf("FAIL %s:%d: ", __FILE__, __LINE__); printf(__VA_ARGS__); printf("\n"); ++failures; } } while (0)
static void count_log(void *u, hd_log_level level, hd_result code, const char *msg, const char *f, int l)
{
    (void)u; (void)f; (void)l;
    if (level == HD_LOG_ERROR) { ++errors; last = code; printf("  logged: %s\n", msg); }
}

enum { N = 24, W = 40, H = 32 };
static uint8_t vox[N * N * N];

static void make_desc(hd_desc *d, cl_context c, cl_device_id dev, cl_command_queue q)
{
    double n = 0.1, f = 10.0, th = tan(20.0 * 3.14159265358979 / 180.0);
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                float u = (x + 0.5f) / N - 0.5f, v = (y + 0.5f) / N - 0.5f, w = (z + 0.5f) / N - 0.5f;
                float r = sqrtf(u * u + v * v + w * w);
                vox[(z * N + y) * N + x] = (uint8_t)(r < 0.45f ? 255.0f * (1.0f - r / 0.45f) : 0.0f);
            }
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = N;
    d->volume.data = vox;
    d->camera.width = W;
    d->camera.height = H;
    d->camera.view[0] = d->camera.view[5] = d->camera.view[10] = d->camera.view[15] = 1.0f;
    d->camera.view[14] = -2.5f;
    d->camera.projection[0] = (float)(1.0 / (th * W / H));
    d->camera.projection[5] = (float)(1.0 / th);
    d->camera.projection[10] = (float)(-(f + n) / (f - n));
    d->camera.projection[11] = -1.0f;
    d->camera.projection[14] = (float)(-2.0 * f * n / (f - n));
    d->params.seed = 5;
    d->logger.func = count_log;
    d->opencl.context = c;
    d->opencl.device = dev;
    d->opencl.queue = q;
}

static void render(hd_context h, float *img)
{
    CHECK(hd_iterate(h, 2) == HD_SUCCESS && hd_read_image_f32(h, img, (size_t)W * H * 4) == HD_SUCCESS, "render");
}

int main(void)
{
    static float vals[64 / 4 + W * H], ia[W * H * 4], ib[W * H * 4], in[W * H * 4];
    const char *req = getenv("HD_CONFORMANCE_REQUIRE");
    cl_platform_id platform;
    cl_device_id device;
    cl_context context, other;
    cl_command_queue queue;
    cl_mem buf, small, oth, img;
    cl_image_format fmt;
    cl_int e;
    hd_desc d;
    hd_context a, b, none, look;
    hd_depth_desc dd;
    hd_params p;
    float *v = vals + 16;
    int x, y;
    double n = 0.1, f = 10.0;
    if (clGetPlatformIDs(1, &platform, NULL) != CL_SUCCESS || clGetDeviceIDs(platform, CL_DEVICE_TYPE_ALL, 1, &device, NULL) != CL_SUCCESS) {
        printf("SKIPPED test_opencl: no OpenCL device\n");
        return req && req[0] == '1' ? 1 : 0;
    }
    context = clCreateContext(NULL, 1, &device, NULL, NULL, &e);
    other = clCreateContext(NULL, 1, &device, NULL, NULL, &e);
    queue = clCreateCommandQueue(context, device, 0, &e);
    for (y = 0; y < H; ++y) /* a wall over the left third and the top half, a post through the middle */
        for (x = 0; x < W; ++x) {
            double z = x < W / 3 || y < H / 2 ? -2.2 : (x >= W / 2 - 2 && x < W / 2 + 2) ? -2.5 : 0.0;
            v[y * W + x] = z == 0.0 ? 1.0f : (float)(0.5 * ((-(f + n) / (f - n) * z - 2.0 * f * n / (f - n)) / -z + 1.0));
        }
    buf = clCreateBuffer(context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, sizeof vals, vals, &e);
    small = clCreateBuffer(context, CL_MEM_READ_ONLY, sizeof vals - 64 - 4, NULL, &e);
    oth = clCreateBuffer(other, CL_MEM_READ_ONLY, sizeof vals, NULL, &e);
    fmt.image_channel_order = CL_R;
    fmt.image_channel_data_type = CL_FLOAT;
    {
        cl_image_desc idesc;
        memset(&idesc, 0, sizeof idesc);
        idesc.image_type = CL_MEM_OBJECT_IMAGE2D;
        idesc.image_width = W;
        idesc.image_height = H;
        img = clCreateImage(context, CL_MEM_READ_ONLY, &fmt, &idesc, NULL, &e);
    }
    make_desc(&d, context, device, queue);
    CHECK(hd_create(&d, &a) == HD_SUCCESS && hd_create(&d, &b) == HD_SUCCESS && hd_create(&d, &none) == HD_SUCCESS, "hd_create");
    dd.data = v; dd.width = W; dd.height = H;
    CHECK(hd_set_depth(a, &dd) == HD_SUCCESS, "hd_set_depth");
    CHECK(hd_opencl_set_depth_buffer(b, buf, 64) == HD_SUCCESS, "hd_opencl_set_depth_buffer");
    render(a, ia);
    render(b, ib);
    render(none, in);
    CHECK(memcmp(ia, ib, sizeof ia) == 0, "the cl_mem depth's image is not hd_set_depth's");
    CHECK(memcmp(ia, in, sizeof ia) != 0, "the depth changed nothing");
    /* refusals: one error each, the depth kept */
    errors = 0; CHECK(hd_opencl_set_depth_buffer(b, NULL, 0) == HD_ERROR_NULL_POINTER && errors == 1, "NULL");
    errors = 0; CHECK(hd_opencl_set_depth_buffer(b, buf, 2) == HD_ERROR_INVALID_PARAMETER && errors == 1, "offset 2");
    errors = 0; CHECK(hd_opencl_set_depth_buffer(b, small, 0) == HD_ERROR_BUFFER_TOO_SMALL && errors == 1, "too small");
    errors = 0; CHECK(hd_opencl_set_depth_buffer(b, buf, 128) == HD_ERROR_BUFFER_TOO_SMALL && errors == 1, "offset past the values");
    errors = 0; CHECK(hd_opencl_set_depth_buffer(b, img, 0) == HD_ERROR_INVALID_PARAMETER && errors == 1, "an image");
    errors = 0; CHECK(hd_opencl_set_depth_buffer(b, oth, 0) == HD_ERROR_INVALID_PARAMETER && errors == 1, "another context");
    {
        hd_desc dl = d;
        memset(dl.camera.view, 0, sizeof dl.camera.view);
        memset(dl.camera.projection, 0, sizeof dl.camera.projection);
        CHECK(hd_create(&dl, &look) == HD_SUCCESS, "look-at context");
        errors = 0; CHECK(hd_opencl_set_depth_buffer(look, buf, 64) == HD_ERROR_DEPTH_NEEDS_PROJECTION && errors == 1, "look-at camera");
        hd_destroy(look);
    }
    p = d.params;
    p.method = HD_METHOD_CD; /* every dirty bit: a host buffer is uploaded again, the device's kept */
    CHECK(hd_set_params(a, &p) == HD_SUCCESS && hd_set_params(b, &p) == HD_SUCCESS, "method CD");
    render(a, ia);
    render(b, ib);
    CHECK(memcmp(ia, ib, sizeof ia) == 0, "after the refusals and a method change the images differ");
    CHECK(hd_set_depth(a, NULL) == HD_SUCCESS && hd_set_depth(b, NULL) == HD_SUCCESS, "cleared");
    render(a, ia);
    render(b, ib);
    CHECK(memcmp(ia, ib, sizeof ia) == 0, "hd_set_depth(NULL) did not clear the cl_mem depth");
    hd_destroy(a); hd_destroy(b); hd_destroy(none);
    clReleaseMemObject(buf); clReleaseMemObject(small); clReleaseMemObject(oth); clReleaseMemObject(img);
    clReleaseCommandQueue(queue);
    clReleaseContext(context);
    clReleaseContext(other);
    printf(failures ? "test_opencl: FAILED\n" : "PASS hd_opencl_set_depth_buffer: bit for bit hd_set_depth's image; 7 refusals one error each\n");
    return failures ? 1 : 0;
}
