/* hdbench_direct - HD's direct-light stage per iteration on one backend: tracked only at the
   voxels whose E is read (the library's way, hd__direct_mask) against every voxel of the
   illumination grid (the test hook hd__test_direct_all), in one process, interleaved. Head CT,
   full grid (illumination_downsample 1, or N with --grid N), one directional light, the ct-skin and ct-bone TFs of
   examples/hd_tf.h. Per TF: the tracked voxels and the list's bytes, the time to build the mask,
   then reps x (masked, every voxel) blocks of `iters` direct passes, each timed with the device
   drained; prints the median ms per pass of each and their ratio, and checks that E agrees at
   every tracked voxel. Figures, not a test: it fails only on an error or an E mismatch.
   --tracked-only times the tracked run alone (no every-voxel context, no agreement check).
   --dump PREFIX writes the tracked run's E (float32, as hd_read_illumination gives it) to
   PREFIX-<tf>.f32, for comparing two builds' E byte for byte (cmp).
   Usage: hdbench_direct [--iters N] [--reps R] [--grid N] [--tracked-only] [--dump PREFIX] [data/head.nrrd] */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#if !defined(HYBRIDDIFF_BACKEND_CPU) && !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_GL) && \
    !defined(HYBRIDDIFF_BACKEND_VULKAN)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "examples/hd_tf.h"

#include <stdio.h>
#include <stdlib.h>
#include "hd_bench_median.h"

#define MAX_REPS 32

/* ms per direct pass over `iters` passes, the device drained before and after. */
static double time_passes(hd_context h, int iters, int *ok)
{
    double t0;
    if (hd__test_finish(h) != HD_SUCCESS) *ok = 0;
    t0 = hd__now();
    if (hd__test_direct(h, iters) != HD_SUCCESS || hd__test_finish(h) != HD_SUCCESS) *ok = 0;
    return (hd__now() - t0) * 1e3 / iters;
}

static int bench_tf(const hd_volume_file *vf, const char *preset, int iters, int reps, int grid, int nm, const char *dump)
{
    hdx_tf tf;
    hd_desc d;
    hd_light light;
    hd_context h[2] = {{0}, {0}};
    hd_stats st;
    double ms[2][MAX_REPS], build = 0.0, t0;
    float *e[2] = {NULL, NULL};
    size_t n = 0, i, tracked = 0, gvox, mismatch = 0;
    int m, rep, ok = 1;
    hd__ctx *ctx;
    if (!hdx_tf_preset(preset, &tf)) return 0;
    memset(&light, 0, sizeof light);
    light.type = HD_LIGHT_DIRECTIONAL;
    light.direction[0] = -0.4f; light.direction[1] = -1.0f; light.direction[2] = -0.6f;
    light.color[0] = light.color[1] = light.color[2] = 1.0f;
    light.intensity = 1.0f;
    memset(&d, 0, sizeof d);
    hdx_tf_use(&d, &vf->desc, &tf);
    d.lights = &light;
    d.light_count = 1;
    d.camera.eye[1] = 2.3f; d.camera.up[2] = 1.0f; d.camera.width = d.camera.height = 64;
    d.params.illumination_downsample = grid;
    d.params.diffusion_boundary = HD_BOUNDARY_BOX;
    d.logger.func = hd_log_stderr;
    for (m = 0; m < nm && ok; ++m) {
        if (hd_create(&d, &h[m]) != HD_SUCCESS || hd__test_direct_all(h[m], m) != HD_SUCCESS ||
            hd__test_prepare(h[m]) != HD_SUCCESS)
            ok = 0;
    }
    if (!ok) goto done;
    hd_get_stats(h[0], &st);
    gvox = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2];
    tracked = hd__test_direct_count(h[0]);
    /* the mask alone, as a TF change rebuilds it (median of 3) */
    ctx = hd__lookup(h[0]);
    {
        double b[3];
        for (rep = 0; rep < 3; ++rep) {
            t0 = hd__now();
            if (hd__direct_mask(ctx) != HD_SUCCESS) ok = 0;
            b[rep] = (hd__now() - t0) * 1e3;
        }
        build = hdb_median(b, 3);
    }
    /* one untimed pass each: kernels compiled, pipelines made */
    for (m = 0; m < nm; ++m)
        if (hd__test_direct(h[m], 1) != HD_SUCCESS) ok = 0;
    for (rep = 0; rep < reps && ok; ++rep)
        for (m = 0; m < nm; ++m) ms[m][rep] = time_passes(h[m], iters, &ok);
    if (!ok) goto done;
    /* the same passes ran on both: E must agree wherever the mask tracks it */
    n = gvox * (size_t)st.illumination_channels;
    for (m = 0; m < nm; ++m) {
        e[m] = (float *)malloc(n * sizeof(float));
        if (!e[m] || hd_read_illumination(h[m], HD_ILLUMINATION_DIRECT, e[m], n) != HD_SUCCESS) { ok = 0; goto done; }
    }
    for (i = 0; i < n && nm == 2; ++i) {
        size_t k = i % gvox;
        if ((ctx->dl.bits[k >> 3] >> (k & 7) & 1u) ? e[0][i] != e[1][i] : e[0][i] != 0.0f) ++mismatch;
    }
    {
        double a = hdb_median(ms[0], reps), b = nm == 2 ? hdb_median(ms[1], reps) : 0.0;
        printf("%-7s %-8s grid %dx%dx%d  tracked %zu of %zu voxels (%.1f %%), list %.2f bytes/voxel, mask build %.0f ms\n",
               hd_backend_name(), preset, st.illumination_dims[0], st.illumination_dims[1], st.illumination_dims[2], tracked,
               gvox, 100.0 * (double)tracked / (double)gvox, 4.0 * (double)tracked / (double)gvox, build);
        if (nm == 1)
            printf("%-7s %-8s direct ms/pass: tracked %.1f (median of %d x %d passes)\n", hd_backend_name(), preset, a, reps, iters);
        else
            printf("%-7s %-8s direct ms/pass: every voxel %.1f, tracked %.1f: %.2fx faster (median of %d x %d passes); "
                   "E %s at tracked voxels\n",
                   hd_backend_name(), preset, b, a, b / a, reps, iters, mismatch ? "DIFFERS" : "identical");
        fflush(stdout);
    }
    if (mismatch) ok = 0;
    if (dump) {
        char name[1024];
        FILE *f;
        snprintf(name, sizeof name, "%s-%s.f32", dump, preset);
        f = fopen(name, "wb");
        if (!f || fwrite(e[0], sizeof(float), n, f) != n) ok = 0;
        if (f && fclose(f) != 0) ok = 0;
        if (!ok) fprintf(stderr, "hdbench_direct: cannot write %s\n", name);
    }
done:
    for (m = 0; m < 2; ++m) {
        if (h[m].id) hd_destroy(h[m]);
        free(e[m]);
    }
    return ok;
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd", *dump = NULL;
    int iters = 4, reps = 3, grid = 1, nm = 2, i, ok = 1;
    hd_volume_file vf;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--iters") == 0 && i + 1 < argc) iters = atoi(argv[++i]);
        else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
        else if (strcmp(argv[i], "--grid") == 0 && i + 1 < argc) grid = atoi(argv[++i]);
        else if (strcmp(argv[i], "--tracked-only") == 0) nm = 1;
        else if (strcmp(argv[i], "--dump") == 0 && i + 1 < argc) dump = argv[++i];
        else if (argv[i][0] != '-') path = argv[i];
        else { fprintf(stderr, "usage: hdbench_direct [--iters N] [--reps R] [--grid N] [--tracked-only] [--dump PREFIX] [data/head.nrrd]\n"); return 2; }
    }
    if (iters < 1 || reps < 1 || reps > MAX_REPS || grid < 1 || grid > 8) {
        fprintf(stderr, "hdbench_direct: iters >= 1, reps in 1..%d, grid in 1..8\n", MAX_REPS);
        return 2;
    }
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) { fprintf(stderr, "hdbench_direct: cannot load %s\n", path); return 1; }
    ok = bench_tf(&vf, "ct-skin", iters, reps, grid, nm, dump) && bench_tf(&vf, "ct-bone", iters, reps, grid, nm, dump);
    hd_volume_free(&vf);
    return ok ? 0 : 1;
}
