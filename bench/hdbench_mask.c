/* hdbench_mask - the time to build the direct light's mask (hd__direct_mask, as a TF or
   extinction change rebuilds it) on the head CT, ct-skin and ct-bone, at illumination grid /1 and
   /2: median of 5 builds each, with the tracked voxel count and a hash of the tracked set (grid
   indices in ascending order), so that builds of two versions of the library can be run one
   after the other and checked to make the same mask. Figures, not a test.
   Usage: hdbench_mask [data/head.nrrd] */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "examples/hd_tf.h"

#include <stdio.h>
#include <stdlib.h>
#include "hd_bench_median.h"

int main(int argc, char **argv)
{
    static const char *const tfs[2] = {"ct-skin", "ct-bone"};
    hd_volume_file vf;
    int t, g, rep;
    if (hd_volume_load_nrrd(argc > 1 ? argv[1] : "data/head.nrrd", &vf, NULL) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_mask: cannot load the volume (make data)\n");
        return 1;
    }
    for (g = 1; g <= 2; ++g)
        for (t = 0; t < 2; ++t) {
            hdx_tf tf;
            hd_desc d;
            hd_light light;
            hd_context h;
            hd__ctx *ctx;
            double b[5], t0;
            uint32_t sum = 0;
            size_t i, gvox;
            if (!hdx_tf_preset(tfs[t], &tf)) return 1;
            memset(&light, 0, sizeof light);
            light.type = HD_LIGHT_DIRECTIONAL;
            light.direction[1] = -1.0f;
            memset(&d, 0, sizeof d);
            hdx_tf_use(&d, &vf.desc, &tf);
            d.lights = &light;
            d.light_count = 1;
            d.camera.eye[1] = 2.3f; d.camera.up[2] = 1.0f; d.camera.width = d.camera.height = 64;
            d.params.illumination_downsample = g;
            if (hd_create(&d, &h) != HD_SUCCESS) return 1;
            if (hd__test_prepare(h) != HD_SUCCESS) { hd_destroy(h); return 1; }
            ctx = hd__lookup(h);
            for (rep = 0; rep < 5; ++rep) {
                t0 = hd__now();
                if (hd__direct_mask(ctx) != HD_SUCCESS) { hd_destroy(h); return 1; }
                b[rep] = (hd__now() - t0) * 1e3;
            }
            gvox = (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2];
            for (i = 0; i < gvox; ++i)
                if (ctx->dl.bits[i >> 3] >> (i & 7) & 1u) sum = sum * 31u + (uint32_t)i;
            printf("%s grid /%d: tracked %zu, set hash %08x, mask build %.1f ms (median of 5)\n", tfs[t], g, ctx->vw.dl_count,
                   (unsigned)sum, hdb_median(b, 5));
            hd_destroy(h);
        }
    hd_volume_free(&vf);
    return 0;
}
