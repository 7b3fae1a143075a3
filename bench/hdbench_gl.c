/* hdbench_gl - the GL column: iterations/s of every method with 1 and 3 lights on the head CT
   (data/head.nrrd, make data), image 256x256, headless EGL (make bench-gl). Each figure is
   hd_iterate over at least 2 iterations and ~2 s after one warm-up iteration (shader compile,
   uploads), with glFinish before the clock stops. Also one diffusion sweep (red-black) alone.
   Usage: hdbench_gl [file.nrrd [N]]; N: also the sweep's A/B against N voxels per invocation. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_BACKEND_GL
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include <stdio.h>

/* the hooks this bench does not use */
static void unused_hooks(void)
{
    (void)hd__test_prepare; (void)hd__test_direct; (void)hd__test_project; (void)hd__test_write_illumination;
}

static double rate(hd_context c, int sweeps_only)
{
    double t0, t;
    int n = 0;
    if (sweeps_only) hd__test_diffuse(c, 1); else hd_iterate(c, 1);
    hd__test_finish(c);
    t0 = hd__now();
    do {
        if (sweeps_only) hd__test_diffuse(c, 1); else hd_iterate(c, 1);
        hd__test_finish(c);
        t = hd__now();
        ++n;
    } while (n < 2 || t - t0 < 2.0);
    return n / (t - t0);
}

/* hdbench_gl FILE N: the sweep with N voxels per diffusion invocation against the library's
   HD__GL_DIFFUSE_ZK, alternated over 4 rounds in this process (the diffusion programs are
   recompiled at each switch, in rate()'s warm-up), best of each. */
static void sweep_ab(hd_context c, int zk)
{
    const hd__view *ctx = (&hd__lookup(c)->vw);
    hd__backend *be = ctx->be;
    double best[2] = {0.0, 0.0};
    int k, i, own = be->diffuse_zk;
    for (k = 0; k < 8; ++k) {
        double v;
        if (hd__be_begin(ctx) != HD_SUCCESS) return;
        for (i = HD__GL_PROGRAM_COUNT; i < HD__GL_SLOTS; ++i)
            if (be->programs[i]) { be->gl.DeleteProgram(be->programs[i]); be->programs[i] = 0; }
        hd__be_end(ctx, HD_SUCCESS);
        be->diffuse_zk = k & 1 ? zk : own;
        v = rate(c, 1);
        if (v > best[k & 1]) best[k & 1] = v;
    }
    printf("diffusion sweep, %d voxel(s) per invocation: %.2f sweeps/s; %d: %.2f sweeps/s (%.2fx)\n", own, best[0], zk, best[1],
           best[0] / best[1]);
}

int main(int argc, char **argv)
{
    static const hd_method methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};
    const char *path = argc > 1 ? argv[1] : "data/head.nrrd";
    hd_volume_file vol;
    hd_light lights[3];
    hd_desc d;
    hd_context c;
    hd_result r;
    int m, l, i;
    (void)unused_hooks;
    if ((r = hd_volume_load(path, &vol, NULL)) != HD_SUCCESS) {
        printf("hdbench_gl: cannot load %s (%s); make data\n", path, hd_result_string(r));
        return 1;
    }
    memset(lights, 0, sizeof lights);
    for (i = 0; i < 3; ++i) {
        lights[i].type = HD_LIGHT_DIRECTIONAL;
        lights[i].direction[0] = i == 1 ? 1.0f : -0.3f;
        lights[i].direction[1] = i == 2 ? 1.0f : -1.0f;
        lights[i].direction[2] = -0.5f;
    }
    memset(&d, 0, sizeof d);
    d.volume = vol.desc;
    d.volume.value_range[0] = -1024.0f;
    d.volume.value_range[1] = 3071.0f;
    d.camera.width = d.camera.height = 256;
    d.camera.eye[0] = 0.6f; d.camera.eye[1] = 1.65f; d.camera.eye[2] = 0.3f;
    d.camera.up[2] = 1.0f;
    d.lights = lights;
    d.light_count = 1;
    if ((r = hd_create(&d, &c)) != HD_SUCCESS) { printf("hdbench_gl: hd_create: %s\n", hd_result_string(r)); return 1; }
    printf("hdbench_gl: %s %dx%dx%d, image 256x256, backend %s\n", path, vol.desc.dims[0], vol.desc.dims[1], vol.desc.dims[2],
           hd_backend_name());
    printf("diffusion sweep (red-black, both half-sweeps): %.2f sweeps/s\n", rate(c, 1));
    if (argc > 2) sweep_ab(c, atoi(argv[2]));
    printf("| method | 1 light it/s | 3 lights it/s |\n|---|---|---|\n");
    for (m = 0; m < 4; ++m) {
        double f[2];
        for (l = 0; l < 2; ++l) {
            hd_params p;
            hd_query_desc(c, &d);
            p = d.params;
            p.method = methods[m];
            hd_set_params(c, &p);
            hd_set_lights(c, lights, l ? 3 : 1);
            f[l] = rate(c, 0);
        }
        printf("| %s | %.2f | %.2f |\n", hd_method_name(methods[m]), f[0], f[1]);
        fflush(stdout);
    }
    hd_destroy(c);
    hd_volume_free(&vol);
    return 0;
}
