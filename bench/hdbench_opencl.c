/* hdbench_opencl - the OpenCL backend's figures, next to the CPU reference's in the same run:
     - the diffusion sweep (red-black) on the head CT's grid: sweeps/s and bytes/s;
     - HD iterations/s and per-stage times, 1 and 3 lights, CPU vs OpenCL;
     - the two design experiments of docs/DESIGN-OPENCL.md, on the same data:
         the diffusion's kernel (one work-item per voxel, a row per work-group) vs the previous
         one (one work-item per x-row, the shared hdk_diffuse_row loop);
         volume reads through a buffer + the shared software trilinear filter vs a 3D image
         with a linear sampler (projection and direct light).
   Usage: hdbench_opencl [data/head.nrrd] [--quick] [--sweep]   (without the file: a synthetic
   256x256x108; --sweep: for A/B runs of two builds, only each backend's sweep, best of 5 rounds,
   and its projection of a 256x256 image, best of 5 rounds of 2 frames)
   Figures, not a test. The experiments' extra kernels are built here from the same embedded
   sources plus a few bench-only entry points; the library uses rows and buffers. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_STATIC
#define HYBRIDDIFF_BACKEND_OPENCL
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hd_api.h"

HD_API_TABLE(hd_api_backend);

#include "hdbench_triad.h"

static const float bench_tf[] = {
    0.0f, 0.0f, 0.0f, 0.0f,     0.0f, 0.0f, 0.0f, 0.0f,       0.93f, 0.73f, 0.62f, 0.02f,
    0.93f, 0.73f, 0.62f, 0.05f, 1.0f, 0.98f, 0.9f, 0.5f,      1.0f, 1.0f, 1.0f, 1.0f,
    1.0f, 1.0f, 1.0f, 1.0f,     1.0f, 1.0f, 1.0f, 1.0f};
static hd_light bench_lights[3];

static void fill_desc(hd_desc *d, const hd_volume_file *vf, int size, int lights)
{
    memset(d, 0, sizeof *d);
    d->volume = vf->desc;
    if (vf->desc.type != HD_VOXEL_U8) { d->volume.value_range[0] = -1024.0f; d->volume.value_range[1] = 3071.0f; }
    d->transfer_function.rgba = bench_tf;
    d->transfer_function.count = (int)(sizeof bench_tf / sizeof bench_tf[0] / 4);
    d->lights = bench_lights;
    d->light_count = lights;
    d->camera.eye[1] = 2.3f; d->camera.eye[2] = 0.3f; d->camera.up[2] = 1.0f;
    d->camera.fov_y = 30.0f;
    d->camera.width = d->camera.height = size;
    d->logger.func = hd_log_stderr;
}

/* Without the head CT: a synthetic volume of its size (a sphere of "bone" in "tissue"). */
static void synthetic(hd_volume_file *vf)
{
    int x, y, z, n[3] = {256, 256, 108};
    float *v = (float *)malloc(sizeof(float) * 256 * 256 * 108);
    memset(vf, 0, sizeof *vf);
    for (z = 0; z < n[2]; ++z)
        for (y = 0; y < n[1]; ++y)
            for (x = 0; x < n[0]; ++x) {
                float u = (float)x / 256.0f - 0.5f, w = (float)y / 256.0f - 0.5f, s = (float)z / 108.0f - 0.5f;
                float r = sqrtf(u * u + w * w + s * s);
                v[((size_t)z * 256 + y) * 256 + x] = r < 0.2f ? 1500.0f : r < 0.45f ? 40.0f : -1000.0f;
            }
    vf->data = v;
    vf->desc.type = HD_VOXEL_F32;
    memcpy(vf->desc.dims, n, sizeof n);
    vf->desc.spacing[0] = vf->desc.spacing[1] = 0.957f; vf->desc.spacing[2] = 1.5f;
    vf->desc.data = v;
}

/* ---- the experiments: extra kernels over the backend's own buffers ------------------------- */
static const char *exp_entries =
    "__kernel void hdx_diffuse_row(HD__CL_BUFFERS, int parity)\n"
    "{\n"
    "    HD__CL_KCTX;\n"
    "    hdk_diffuse_row(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), parity, 0);\n"
    "}\n";
/* The image variant: the prelude's K gains the image and its sampler (kernel arguments, not
   __constant samplers: choosing between two of those crashes PoCL 3.1's compiler). */
static const char *img_prelude =
    "#define HD_PRELUDE_SAMPLES_VOLUME 1\n"
    "#undef HD_KARGS\n#undef HD_KPASS\n"
    "#define HD_KARGS const hd__kctx *K, __read_only image3d_t hd_vimg, sampler_t hd_vsmp,\n"
    "#define HD_KPASS K, hd_vimg, hd_vsmp,\n"
    "inline float hdk_sample_value(HD_KARGS float3 u) { return read_imagef(hd_vimg, hd_vsmp, (float4)(u, 0.0f)).x; }\n";
static const char *img_entries =
    "__kernel void hdx_project_img(HD__CL_BUFFERS, __read_only image3d_t vimg, sampler_t smp)\n"
    "{ HD__CL_KCTX; hdk_project_pixel(&k, vimg, smp, (int)get_global_id(0), (int)get_global_id(1)); }\n"
    "__kernel void hdx_direct_img(HD__CL_BUFFERS, __read_only image3d_t vimg, sampler_t smp)\n"
    "{ HD__CL_KCTX; hdk_direct_voxel(&k, vimg, smp, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2)); }\n";

/* The embedded lines of one file (by its #line marker), to splice sources. */
static size_t src_index(const char *file)
{
    size_t i;
    char marker[128];
    snprintf(marker, sizeof marker, "#line 1 \"%s\"\n", file);
    for (i = 0; i < HD__CL_SOURCE_LINES; ++i)
        if (strcmp(hd__cl_source[i], marker) == 0) return i;
    return HD__CL_SOURCE_LINES;
}

static cl_program build_variant(hd__backend *be, int image)
{
    const char *lines[4096];
    size_t n = 0, i, params = src_index("backends/kernels/hd_k_params.h"), entry = src_index("backends/hd_entry_cl.h");
    cl_int e;
    cl_program prog;
    char opts[64];
    for (i = 0; i < HD__CL_SOURCE_LINES && n < 4000; ++i) {
        if (image && i == params) lines[n++] = img_prelude;
        if (i == entry && image) break;
        lines[n++] = hd__cl_source[i];
    }
    if (image) {
        /* the entry file's two macros, then the image entries */
        for (i = entry; i < HD__CL_SOURCE_LINES; ++i)
            if (strncmp(hd__cl_source[i], "__kernel", 8) == 0) break;
            else lines[n++] = hd__cl_source[i];
        lines[n++] = img_entries;
    } else {
        lines[n++] = exp_entries;
    }
    prog = clCreateProgramWithSource(be->context, (cl_uint)n, lines, NULL, &e);
    snprintf(opts, sizeof opts, "-cl-std=CL1.2 -DHD_MAX_LIGHTS=%d", HD_MAX_LIGHTS);
    if (e != CL_SUCCESS || clBuildProgram(prog, 1, &be->device, opts, NULL, NULL) != CL_SUCCESS) {
        char log[8192] = {0};
        clGetProgramBuildInfo(prog, be->device, CL_PROGRAM_BUILD_LOG, sizeof log - 1, log, NULL);
        fprintf(stderr, "experiment build failed:\n%s\n", log);
        return NULL;
    }
    return prog;
}

static void bind9(hd__backend *be, cl_kernel k)
{
    cl_mem a[9];
    cl_uint i;
    a[0] = be->params; a[1] = be->vol; a[2] = be->tf; a[3] = be->maj; a[4] = be->sig;
    a[5] = be->E; a[6] = be->phi; a[7] = be->phi2; a[8] = be->img;
    for (i = 0; i < 9; ++i) clSetKernelArg(k, i, sizeof(cl_mem), &a[i]);
}

static void experiments(hd_context h, int quick)
{
    hd__ctx *ctx = hd__lookup(h);
    hd__backend *be = ctx->vw.be;
    cl_program pv, pi;
    cl_kernel kv, kp, kd;
    cl_int e;
    int i, reps = quick ? 5 : 20, gx = ctx->vw.gdims[0], gy = ctx->vw.gdims[1], gz = ctx->vw.gdims[2];
    double t0, t_row, t_vox, t_pb, t_pi, t_db, t_di;
    size_t gv[3], gp[2], gd[3], npix = (size_t)ctx->vw.kp.image.x * ctx->vw.kp.image.y * 4, ngrid = ctx->vw.nvox;
    float *img_b = (float *)malloc(npix * 4), *img_i = (float *)malloc(npix * 4);
    float *e_b = (float *)malloc(ngrid * 4), *e_i = (float *)malloc(ngrid * 4);
    cl_image_format fmt;
    cl_image_desc idesc;
    cl_mem vimg;
    cl_sampler smp;
    double d2 = 0, r2 = 0, de2 = 0, re2 = 0;
    hd__test_prepare(h);
    hd__fill_kparams(ctx);
    /* the backend's per-voxel kernel vs one work-item per row, red-black sweeps */
    pv = build_variant(be, 0);
    if (!pv) return;
    kv = clCreateKernel(pv, "hdx_diffuse_row", &e);
    bind9(be, kv);
    hd__be_diffuse(&ctx->vw, 0); clFinish(be->queue);
    t0 = hd__now();
    for (i = 0; i < reps; ++i) hd__be_diffuse(&ctx->vw, 0);
    clFinish(be->queue);
    t_vox = (hd__now() - t0) / reps;
    gv[0] = (size_t)gy; gv[1] = (size_t)gz; gv[2] = 1;
    t0 = hd__now();
    for (i = 0; i < reps; ++i) {
        cl_int par;
        for (par = 0; par < 2; ++par) {
            clSetKernelArg(kv, 9, sizeof par, &par);
            clEnqueueNDRangeKernel(be->queue, kv, 3, NULL, gv, NULL, 0, NULL, NULL);
        }
    }
    clFinish(be->queue);
    t_row = (hd__now() - t0) / reps;
    printf("diffusion work-items (red-black sweep, %dx%dx%d): per voxel, a row per work-group (the backend) %.1f ms = %.0f sweeps/s; "
           "per x-row (previous) %.1f ms = %.0f sweeps/s; voxel/row speed %.2fx\n",
           gx, gy, gz, t_vox * 1e3, 1.0 / t_vox, t_row * 1e3, 1.0 / t_row, t_row / t_vox);
    clReleaseKernel(kv);
    clReleaseProgram(pv);

    /* image + linear sampler vs buffer + software trilinear */
    pi = build_variant(be, 1);
    if (!pi) return;
    kp = clCreateKernel(pi, "hdx_project_img", &e);
    kd = clCreateKernel(pi, "hdx_direct_img", &e);
    fmt.image_channel_order = CL_R;
    fmt.image_channel_data_type = CL_FLOAT;
    memset(&idesc, 0, sizeof idesc);
    idesc.image_type = CL_MEM_OBJECT_IMAGE3D;
    idesc.image_width = (size_t)ctx->vw.dims[0]; idesc.image_height = (size_t)ctx->vw.dims[1]; idesc.image_depth = (size_t)ctx->vw.dims[2];
    vimg = clCreateImage(be->context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, &fmt, &idesc, ctx->vw.vol, &e);
    if (e != CL_SUCCESS) { printf("3D image: %s\n", hd__cl_error_name(e)); return; }
    smp = clCreateSampler(be->context, CL_TRUE, CL_ADDRESS_CLAMP_TO_EDGE, CL_FILTER_LINEAR, &e);
    gp[0] = (size_t)ctx->vw.kp.image.x; gp[1] = (size_t)ctx->vw.kp.image.y;
    gd[0] = (size_t)gx; gd[1] = (size_t)gy; gd[2] = (size_t)gz;
    /* projection: same frame parameters, the image cleared before each variant */
    ctx->frames = 1; hd__fill_kparams(ctx);
    hd__be_clear(&ctx->vw, HD__DIRTY_IMAGE);
    hd__be_project(&ctx->vw);
    t0 = hd__now();
    for (i = 0; i < reps; ++i) hd__be_project(&ctx->vw);
    t_pb = (hd__now() - t0) / reps;
    hd__be_clear(&ctx->vw, HD__DIRTY_IMAGE);
    hd__be_project(&ctx->vw);
    hd__be_read_image(&ctx->vw, img_b);
    bind9(be, kp);
    clSetKernelArg(kp, 9, sizeof vimg, &vimg);
    clSetKernelArg(kp, 10, sizeof smp, &smp);
    hd__be_clear(&ctx->vw, HD__DIRTY_IMAGE);
    clEnqueueNDRangeKernel(be->queue, kp, 2, NULL, gp, NULL, 0, NULL, NULL);
    clFinish(be->queue);
    hd__be_read_image(&ctx->vw, img_i);
    t0 = hd__now();
    for (i = 0; i < reps; ++i) clEnqueueNDRangeKernel(be->queue, kp, 2, NULL, gp, NULL, 0, NULL, NULL);
    clFinish(be->queue);
    t_pi = (hd__now() - t0) / reps;
    /* direct light: one pass each from E = 0, iteration 1 */
    ctx->iterations = 1; hd__fill_kparams(ctx);
    hd__cl_bind(&ctx->vw, HD__CL_DIRECT);
    hd__be_clear(&ctx->vw, HD__DIRTY_DIRECT);
    t0 = hd__now();
    hd__be_direct(&ctx->vw, 0, ctx->vw.dl_count); clFinish(be->queue);
    t_db = hd__now() - t0;
    hd__be_read_illumination(&ctx->vw, HD_ILLUMINATION_DIRECT, NULL, 0, e_b);
    bind9(be, kd);
    clSetKernelArg(kd, 9, sizeof vimg, &vimg);
    clSetKernelArg(kd, 10, sizeof smp, &smp);
    hd__be_clear(&ctx->vw, HD__DIRTY_DIRECT);
    t0 = hd__now();
    clEnqueueNDRangeKernel(be->queue, kd, 3, NULL, gd, NULL, 0, NULL, NULL);
    clFinish(be->queue);
    t_di = hd__now() - t0;
    hd__be_read_illumination(&ctx->vw, HD_ILLUMINATION_DIRECT, NULL, 0, e_i);
    for (i = 0; i < (int)npix; ++i) { d2 += (double)(img_i[i] - img_b[i]) * (img_i[i] - img_b[i]); r2 += (double)img_b[i] * img_b[i]; }
    for (i = 0; i < (int)ngrid; ++i) { de2 += (double)(e_i[i] - e_b[i]) * (e_i[i] - e_b[i]); re2 += (double)e_b[i] * e_b[i]; }
    printf("volume reads, projection %dx%d: buffer+software trilinear %.1f ms, 3D image+linear sampler %.1f ms (image/buffer time %.2fx), image vs buffer rel L2 %.1e\n",
           ctx->vw.kp.image.x, ctx->vw.kp.image.y, t_pb * 1e3, t_pi * 1e3, t_pi / t_pb, sqrt(d2 / (r2 > 0 ? r2 : 1)));
    printf("volume reads, direct light pass: buffer %.1f ms, 3D image %.1f ms (image/buffer time %.2fx), rel L2 of E %.1e\n",
           t_db * 1e3, t_di * 1e3, t_di / t_db, sqrt(de2 / (re2 > 0 ? re2 : 1)));
    clReleaseKernel(kp); clReleaseKernel(kd); clReleaseProgram(pi);
    clReleaseMemObject(vimg); clReleaseSampler(smp);
    free(img_b); free(img_i); free(e_b); free(e_i);
}

/* ---- the figures ---------------------------------------------------------------------------- */
static double sweep_seconds(const hd_api *api, hd_context c, int sweeps)
{
    double t0;
    api->test_diffuse(c, 1);
    api->test_finish(c);
    t0 = hd__now();
    api->test_diffuse(c, sweeps);
    api->test_finish(c);
    return (hd__now() - t0) / sweeps;
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd";
    const hd_api *apis[2] = {&hd_api_cpu, &hd_api_backend};
    int quick = 0, sweep_only = 0, i, a, li, nthreads = (int)sysconf(_SC_NPROCESSORS_ONLN);
    hd_volume_file vf;
    double triad, nvox, rate[2][2], best_rate[2][2];
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) quick = 1;
        else if (strcmp(argv[i], "--sweep") == 0) sweep_only = 1;
        else path = argv[i];
    }
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) {
        printf("(no %s: a synthetic 256x256x108 volume; `make data` fetches the head CT)\n", path);
        synthetic(&vf);
        path = "synthetic";
    }
    memset(bench_lights, 0, sizeof bench_lights);
    bench_lights[0].direction[0] = -0.5f; bench_lights[0].direction[1] = -1.0f; bench_lights[0].direction[2] = -0.6f;
    bench_lights[1].direction[0] = 1.0f; bench_lights[1].direction[1] = -0.3f; bench_lights[1].direction[2] = 0.2f;
    bench_lights[2].direction[0] = 0.2f; bench_lights[2].direction[1] = 0.8f; bench_lights[2].direction[2] = -1.0f;
    nvox = (double)vf.desc.dims[0] * vf.desc.dims[1] * vf.desc.dims[2];
    triad = hdbench_triad_bandwidth(nthreads);
    printf("hdbench_opencl: volume %s %dx%dx%d, %d cores, STREAM triad %.2f GB/s\n", path, vf.desc.dims[0],
           vf.desc.dims[1], vf.desc.dims[2], nthreads, triad * 1e-9);

    /* diffusion sweep: red-black, 32 bytes per voxel (two half-sweeps streaming sigma, E, phi in
       and phi out), the convention of bench/hdbench.c */
    for (a = 0; a < 2; ++a) {
        hd_desc d;
        hd_context c;
        double t;
        fill_desc(&d, &vf, sweep_only ? 256 : 64, 1);
        if (apis[a]->create(&d, &c) != HD_SUCCESS) { printf("%s: cannot create\n", apis[a]->backend_name()); return 1; }
        t = sweep_seconds(apis[a], c, quick ? 10 : 50);
        for (i = 1; sweep_only && i < 5; ++i) { /* best of 5: the machine is shared */
            double t2 = sweep_seconds(apis[a], c, quick ? 10 : 50);
            if (t2 < t) t = t2;
        }
        printf("%-6s diffusion sweep (red-black): %.2f ms = %.0f sweeps/s, %.2f GB/s = %.0f%% of the triad\n",
               apis[a]->backend_name(), t * 1e3, 1.0 / t, 32.0 * nvox / t * 1e-9, 100.0 * 32.0 * nvox / t / triad);
        if (sweep_only) { /* and the projection, which reads E and phi through the same layout */
            double tp = 1e30, t0;
            int r;
            for (r = 0; r < 5; ++r) {
                apis[a]->test_project(c, 1);
                apis[a]->test_finish(c);
                t0 = hd__now();
                apis[a]->test_project(c, 2);
                apis[a]->test_finish(c);
                if ((hd__now() - t0) / 2 < tp) tp = (hd__now() - t0) / 2;
            }
            printf("%-6s projection 256x256: %.2f ms (best of 5 rounds of 2 frames)\n", apis[a]->backend_name(), tp * 1e3);
        }
        if (a == 1 && !sweep_only) experiments(c, quick);
        apis[a]->destroy(c);
    }
    if (sweep_only) { hd_volume_free(&vf); return 0; }

    /* HD iterations: 512^2 image, 1 and 3 lights, default params (4 sweeps per iteration). Each
       iteration is timed on its own: the mean over all of them, and the best one with its stage
       times (on a machine shared with other jobs the best is the steadier figure). */
    printf("\n| backend | lights | HD it/s (mean) | best it/s | best ms/iteration | direct ms | diffusion ms | projection ms |\n"
           "|---|---|---|---|---|---|---|---|\n");
    for (li = 0; li < 2; ++li) {
        for (a = 0; a < 2; ++a) {
            hd_desc d;
            hd_context c;
            hd_stats s0, s1;
            int iters = quick ? 3 : 10, lights = li == 0 ? 1 : 3, it;
            double total = 0.0, best = 1e30, bd = 0.0, bf = 0.0, bp = 0.0;
            fill_desc(&d, &vf, 512, lights);
            if (apis[a]->create(&d, &c) != HD_SUCCESS) return 1;
            apis[a]->iterate(c, 1);
            for (it = 0; it < iters; ++it) {
                double t0, dt;
                apis[a]->get_stats(c, &s0);
                t0 = hd__now();
                apis[a]->iterate(c, 1);
                dt = hd__now() - t0;
                apis[a]->get_stats(c, &s1);
                total += dt;
                if (dt < best) {
                    best = dt;
                    bd = s1.seconds_direct - s0.seconds_direct;
                    bf = s1.seconds_diffusion - s0.seconds_diffusion;
                    bp = s1.seconds_projection - s0.seconds_projection;
                }
            }
            rate[li][a] = iters / total;
            best_rate[li][a] = 1.0 / best;
            printf("| %s | %d | %.2f | %.2f | %.1f | %.1f | %.1f | %.1f |\n", apis[a]->backend_name(), lights, iters / total,
                   1.0 / best, best * 1e3, bd * 1e3, bf * 1e3, bp * 1e3);
            apis[a]->destroy(c);
        }
        printf("| opencl/cpu | %d | %.2fx | %.2fx | | | | |\n", li == 0 ? 1 : 3, rate[li][1] / rate[li][0],
               best_rate[li][1] / best_rate[li][0]);
    }
    hd_volume_free(&vf);
    return 0;
}
