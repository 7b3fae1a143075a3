/* hdbench_rays - the cost and the noise of one direct-light ray per voxel, for the transmittance
   estimators HD can use: ratio tracking with Russian roulette below HD_RR_THRESHOLD (the
   library's default) and delta tracking (params.tracking). Head CT, ct-skin, one directional
   light, the library's default illumination grid, the voxels the library tracks (hd__direct_mask).
   Per estimator two contexts with different seeds run the same number of direct passes
   (hd__test_direct), interleaved in blocks with the other estimator's, each block timed with the
   device drained. Both estimators are unbiased, so the difference of the two seeds' E measures
   the noise alone: var = |E_a - E_b|^2 / 2 over the tracked voxels, relative to |E|^2. Prints
   ms per pass, the relative noise of one pass (sqrt(var * passes)), the mean of E (the
   estimators must agree within noise), and the efficiency 1 / (noise^2 * time) relative to the
   first estimator: above 1 means less error for the same time. HD_RR_THRESHOLD is a constant of
   the shared kernels; other thresholds are measured by building this program with it changed
   (docs/DESIGN-DIRECT.md). Figures, not a test.
   Usage: hdbench_rays [--passes N] [--reps R] [data/head.nrrd] */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "examples/hd_tf.h"

#include <stdio.h>
#include <stdlib.h>
#include "hd_bench_median.h"

#define MAX_REPS 32
enum { EST = 2 };

int main(int argc, char **argv)
{
    static const hd_tracking est[EST] = {HD_TRACKING_RATIO, HD_TRACKING_DELTA};
    static const char *const est_name[EST] = {"ratio", "delta"};
    const char *path = "data/head.nrrd";
    int passes = 4, reps = 3, i, k, s, rep, ok = 1;
    hd_volume_file vf;
    hdx_tf tf;
    hd_desc d;
    hd_light light;
    hd_context h[EST][2];
    hd_stats st;
    double ms[EST][MAX_REPS], var[EST], mean[EST], eff0 = 0.0, t;
    float *e[2];
    size_t n, j, tracked;
    hd__ctx *ctx;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--passes") == 0 && i + 1 < argc) passes = atoi(argv[++i]);
        else if (strcmp(argv[i], "--reps") == 0 && i + 1 < argc) reps = atoi(argv[++i]);
        else if (argv[i][0] != '-') path = argv[i];
        else { fprintf(stderr, "usage: hdbench_rays [--passes N] [--reps R] [data/head.nrrd]\n"); return 2; }
    }
    if (passes < 1 || reps < 1 || reps > MAX_REPS) { fprintf(stderr, "hdbench_rays: --passes >= 1, --reps 1..%d\n", MAX_REPS); return 2; }
    if (hd_volume_load_nrrd(path, &vf, NULL) != HD_SUCCESS) { fprintf(stderr, "hdbench_rays: cannot load %s (make data)\n", path); return 2; }
    if (!hdx_tf_preset("ct-skin", &tf)) return 2;
    memset(&light, 0, sizeof light);
    light.type = HD_LIGHT_DIRECTIONAL;
    light.direction[0] = -0.6452f; light.direction[1] = -0.3560f; light.direction[2] = -0.6760f;
    memset(&d, 0, sizeof d);
    d.volume = vf.desc;
    d.volume.value_range[0] = tf.domain[0];
    d.volume.value_range[1] = tf.domain[1];
    d.transfer_function.rgba = tf.rgba;
    d.transfer_function.count = tf.count;
    d.lights = &light;
    d.light_count = 1;
    d.camera.width = d.camera.height = 64;
    d.logger.func = hd_log_stderr;
    memset(h, 0, sizeof h);
    for (k = 0; k < EST && ok; ++k)
        for (s = 0; s < 2 && ok; ++s) {
            d.params.tracking = est[k];
            d.params.seed = 11u + (uint32_t)s;
            if (hd_create(&d, &h[k][s]) != HD_SUCCESS || hd__test_prepare(h[k][s]) != HD_SUCCESS) ok = 0;
        }
    if (!ok) return 1;
    hd_get_stats(h[0][0], &st);
    tracked = hd__test_direct_count(h[0][0]);
    ctx = hd__lookup(h[0][0]);
    printf("hdbench_rays: cpu, %s, grid %dx%dx%d, %zu voxels tracked, HD_RR_THRESHOLD %g, %d x %d passes\n", path,
           st.illumination_dims[0], st.illumination_dims[1], st.illumination_dims[2], tracked, (double)HD_RR_THRESHOLD,
           reps, passes);
    for (rep = 0; rep < reps && ok; ++rep)
        for (k = 0; k < EST; ++k) {
            t = hd__now();
            for (s = 0; s < 2; ++s)
                if (hd__test_direct(h[k][s], passes) != HD_SUCCESS || hd__test_finish(h[k][s]) != HD_SUCCESS) ok = 0;
            ms[k][rep] = (hd__now() - t) * 1e3 / (2.0 * passes);
        }
    n = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2];
    e[0] = (float *)malloc(n * sizeof(float));
    e[1] = (float *)malloc(n * sizeof(float));
    if (!ok || !e[0] || !e[1]) return 1;
    for (k = 0; k < EST; ++k) {
        double dd = 0.0, ee = 0.0, sum = 0.0;
        for (s = 0; s < 2; ++s)
            if (hd_read_illumination(h[k][s], HD_ILLUMINATION_DIRECT, e[s], n) != HD_SUCCESS) return 1;
        for (j = 0; j < n; ++j) {
            double a = e[0][j], b = e[1][j];
            if (!(ctx->dl.bits[j >> 3] >> (j & 7) & 1u)) continue;
            dd += (a - b) * (a - b);
            ee += 0.25 * (a + b) * (a + b);
            sum += 0.5 * (a + b);
        }
        var[k] = 0.5 * dd / ee; /* relative variance of E after reps * passes passes */
        mean[k] = sum / (double)tracked;
    }
    printf("| estimator | ms per pass (median of %d) | relative noise of one pass | mean E | efficiency |\n|---|---|---|---|---|\n", reps);
    for (k = 0; k < EST; ++k) {
        double m = hdb_median(ms[k], reps), noise1 = sqrt(var[k] * reps * passes), eff = 1.0 / (noise1 * noise1 * m);
        if (k == 0) eff0 = eff;
        printf("| %s | %.1f | %.4f | %.6f | %.2f |\n", est_name[k], m, noise1, mean[k], eff / eff0);
    }
    for (k = 0; k < EST; ++k)
        for (s = 0; s < 2; ++s) hd_destroy(h[k][s]);
    free(e[0]);
    free(e[1]);
    hd_volume_free(&vf);
    return 0;
}
