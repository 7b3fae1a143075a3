/* test_crop.c - the crop box (params.crop_min/max) on the CPU backend: matter outside it is
   absent for every method (no shadow, no scattering, not drawn), so a cropped volume renders bit
   for bit as the same volume with the cropped voxels zeroed; changing the box restarts what it
   must; bad boxes are refused with one logged error. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

/* A 32^3 volume, light travelling +x: an occluder slab at x 2..7 in front of a half-dense block
   at x 20..23. The crop box starts at x = 0.5 (voxel 16): the occluder lies outside it, with
   exact zeros from voxel 8 to 19 on both sides of the cut and across the majorant cell (4
   voxels, one-voxel halo) on each side, so every sample of the cropped volume equals the same
   sample of the volume with voxels 0..15 zeroed. */
#define N 32
#define CUT 16
static const float tf2[8] = {0, 0, 0, 0, 1, 1, 1, 1}; /* value 0 is transparent */

static void fill(uint8_t *v, int zero_cut)
{
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                uint8_t val = 0;
                if (x >= 2 && x < 8 && y >= 4 && y < 28 && z >= 4 && z < 28) val = 255;
                if (x >= 20 && x < 24 && y >= 8 && y < 24 && z >= 8 && z < 24) val = 128;
                if (zero_cut && x < CUT) val = 0;
                v[(z * N + y) * N + x] = val;
            }
}

static void make_desc(hd_desc *d, const uint8_t *vox, hd_light *light, hd_method method)
{
    memset(d, 0, sizeof *d);
    memset(light, 0, sizeof *light);
    light->type = HD_LIGHT_DIRECTIONAL;
    light->direction[0] = 1.0f; light->direction[1] = 0.2f; light->direction[2] = -0.1f;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = N;
    d->volume.data = vox;
    d->transfer_function.rgba = tf2;
    d->transfer_function.count = 2;
    d->lights = light;
    d->light_count = 1;
    d->camera.eye[0] = -1.6f; d->camera.eye[1] = 0.7f; d->camera.eye[2] = 1.8f;
    d->camera.width = d->camera.height = 24;
    d->params.method = method;
    d->params.extinction = 20.0f;
    d->params.seed = 77u;
    d->params.illumination_downsample = 1; /* E voxel for voxel, compared per voxel below */
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
}

typedef struct outputs {
    float e[N * N * N], phi[N * N * N], img[24 * 24 * 4];
} outputs;

/* n iterations; E and phi are read for the grid methods only (the path tracers keep none). */
static void run(const hd_desc *d, const hd_params *later, int n, outputs *o)
{
    hd_context ctx;
    memset(o, 0, sizeof *o);
    CHECK(hd_create(d, &ctx) == HD_SUCCESS);
    if (later) {
        CHECK(hd_iterate(ctx, n) == HD_SUCCESS);
        CHECK(hd_set_params(ctx, later) == HD_SUCCESS);
    }
    CHECK(hd_iterate(ctx, n) == HD_SUCCESS);
    if (d->params.method != HD_METHOD_PT_SS && d->params.method != HD_METHOD_PT_MS) {
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, o->e, (size_t)N * N * N) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, o->phi, (size_t)N * N * N) == HD_SUCCESS);
    }
    CHECK(hd_read_image_f32(ctx, o->img, sizeof o->img / sizeof o->img[0]) == HD_SUCCESS);
    hd_destroy(ctx);
}

static int differ(const float *a, const float *b, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (a[i] != b[i]) return 1;
    return 0;
}

/* Cropped against zeroed, for every method: E, phi and the image bit-identical, and the
   occluder's shadow really was there without the crop box. */
static void test_cropped_region_is_absent(void)
{
    static const hd_method methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};
    uint8_t *full = (uint8_t *)malloc(N * N * N), *zeroed = (uint8_t *)malloc(N * N * N);
    outputs *a = (outputs *)malloc(sizeof *a), *b = (outputs *)malloc(sizeof *b), *c = (outputs *)malloc(sizeof *c);
    hd_light la, lb;
    hd_desc da, db;
    int m;
    fill(full, 0);
    fill(zeroed, 1);
    for (m = 0; m < 4; ++m) {
        int n = methods[m] == HD_METHOD_CD ? 40 : 3; /* CD: light crosses the box in ~N iterations */
        make_desc(&da, full, &la, methods[m]);
        make_desc(&db, zeroed, &lb, methods[m]);
        da.params.crop_min[0] = (float)CUT / N;
        run(&da, NULL, n, a);
        run(&db, NULL, n, b);
        CHECK_MSG(!differ(a->e, b->e, N * N * N), "%s: E differs", hd_method_name(methods[m]));
        CHECK_MSG(!differ(a->phi, b->phi, N * N * N), "%s: phi differs", hd_method_name(methods[m]));
        CHECK_MSG(!differ(a->img, b->img, 24 * 24 * 4), "%s: image differs", hd_method_name(methods[m]));
        /* without the crop box the occluder shades the block and shows in the image */
        da.params.crop_min[0] = 0.0f;
        run(&da, NULL, n, c);
        CHECK_MSG(differ(c->img, b->img, 24 * 24 * 4), "%s: the occluder changes nothing", hd_method_name(methods[m]));
        if (methods[m] == HD_METHOD_HD || methods[m] == HD_METHOD_CD) {
            size_t i = ((size_t)16 * N + 16) * N + 21; /* inside the block, behind the occluder */
            CHECK_MSG(c->e[i] < 0.5f * b->e[i], "%s: E %g with the occluder, %g without", hd_method_name(methods[m]),
                      (double)c->e[i], (double)b->e[i]);
        }
    }
    free(full);
    free(zeroed);
    free(a);
    free(b);
    free(c);
}

/* A crop face through uniform matter, inside a majorant cell (voxels 16..19 span x 0.5..0.625):
   the light travelling +x is attenuated only from the face on, E = exp(-extinction (x - 0.53)),
   and a ray along x through the box [0.53, 0.56] gains the opacity 1 - exp(-extinction 0.03). */
static void test_crop_face_inside_cell(void)
{
    uint8_t *full = (uint8_t *)malloc(N * N * N);
    outputs *o = (outputs *)malloc(sizeof *o);
    hd_light l;
    hd_desc d;
    hd_context ctx;
    int x, y, z, px, py;
    double alpha = 0.0, want;
    memset(full, 255, N * N * N);
    make_desc(&d, full, &l, HD_METHOD_HD);
    l.direction[1] = l.direction[2] = 0.0f;
    d.params.extinction = 8.0f;
    d.params.disable_diffusion = 1;
    d.params.crop_min[0] = 0.53f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 32) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, o->e, (size_t)N * N * N) == HD_SUCCESS);
    hd_destroy(ctx);
    for (x = 17; x < 24; ++x) {
        double mean = 0.0;
        for (z = 0; z < N; ++z)
            for (y = 0; y < N; ++y) mean += o->e[(z * N + y) * N + x];
        mean /= (double)(N * N);
        want = exp(-8.0 * (((double)x + 0.5) / N - 0.53));
        CHECK_MSG(fabs(mean - want) < 0.02, "column x = %d: mean E %.4f, expected %.4f", x, mean, want);
    }
    /* the projection: a narrow view along +x through the slab [0.53, 0.56] */
    d.params.crop_max[0] = 0.56f;
    d.params.extinction = 20.0f;
    d.params.step = 0.05f;
    d.camera.eye[0] = -3.0f; d.camera.eye[1] = 0.0f; d.camera.eye[2] = 0.0f;
    d.camera.up[2] = 1.0f;
    d.camera.fov_y = 5.0f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 8) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, o->img, sizeof o->img / sizeof o->img[0]) == HD_SUCCESS);
    hd_destroy(ctx);
    for (py = 8; py < 16; ++py)
        for (px = 8; px < 16; ++px) alpha += o->img[(py * 24 + px) * 4 + 3];
    alpha /= 64.0;
    want = 1.0 - exp(-20.0 * 0.03);
    CHECK_MSG(fabs(alpha - want) < 0.03, "opacity through the slab %.4f, expected %.4f", alpha, want);
    free(full);
    free(o);
}

/* A crop box set by hd_set_params after some iterations restarts the light and the image: the
   result is that of a context created with the box; and removing it again restores the first. */
static void test_crop_change_restarts(void)
{
    uint8_t *full = (uint8_t *)malloc(N * N * N);
    outputs *a = (outputs *)malloc(sizeof *a), *b = (outputs *)malloc(sizeof *b);
    hd_light l;
    hd_desc d;
    hd_params p;
    fill(full, 0);
    make_desc(&d, full, &l, HD_METHOD_HD);
    p = d.params;
    p.crop_min[0] = (float)CUT / N;
    p.crop_max[2] = 0.8f;
    run(&d, &p, 3, a);
    d.params = p;
    run(&d, NULL, 3, b);
    CHECK(!differ(a->e, b->e, N * N * N) && !differ(a->phi, b->phi, N * N * N) && !differ(a->img, b->img, 24 * 24 * 4));
    p.crop_min[0] = 0.0f;
    p.crop_max[2] = 1.0f; /* the whole box, as the zeroed default */
    run(&d, &p, 3, a);
    memset(&d.params.crop_min, 0, sizeof d.params.crop_min);
    memset(&d.params.crop_max, 0, sizeof d.params.crop_max);
    run(&d, NULL, 3, b);
    CHECK(!differ(a->e, b->e, N * N * N) && !differ(a->phi, b->phi, N * N * N) && !differ(a->img, b->img, 24 * 24 * 4));
    free(full);
    free(a);
    free(b);
}

/* The direct light is tracked only where it is read: a crop box leaves the voxels outside it
   (and their neighbours) untracked, at E = 0. */
static void test_crop_shrinks_direct_mask(void)
{
    uint8_t *full = (uint8_t *)malloc(N * N * N);
    outputs *a = (outputs *)malloc(sizeof *a);
    hd_light l;
    hd_desc d;
    int x, y, z;
    size_t lit_outside = 0, lit_inside = 0;
    fill(full, 0);
    make_desc(&d, full, &l, HD_METHOD_HD);
    d.params.crop_min[0] = (float)CUT / N;
    run(&d, NULL, 2, a);
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                float e = a->e[(z * N + y) * N + x];
                if (x < CUT - 2 && e != 0.0f) ++lit_outside;
                if (x >= 20 && x < 24 && y >= 8 && y < 24 && z >= 8 && z < 24 && e > 0.0f) ++lit_inside;
            }
    CHECK_MSG(lit_outside == 0, "%zu voxels outside the crop box were tracked", lit_outside);
    CHECK(lit_inside > 0);
    free(full);
    free(a);
}

static void test_crop_defaults(void)
{
    uint8_t *full = (uint8_t *)malloc(N * N * N);
    hd_light l;
    hd_desc d, q;
    hd_context ctx;
    fill(full, 0);
    make_desc(&d, full, &l, HD_METHOD_HD);
    d.params.crop_min[1] = 0.25f;
    d.params.crop_max[2] = 0.75f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &q) == HD_SUCCESS);
    CHECK(q.params.crop_min[0] == 0.0f && q.params.crop_min[1] == 0.25f && q.params.crop_min[2] == 0.0f);
    CHECK(q.params.crop_max[0] == 1.0f && q.params.crop_max[1] == 1.0f && q.params.crop_max[2] == 0.75f);
    hd_destroy(ctx);
    free(full);
}

/* NaN, infinite, inverted, empty and out-of-range boxes: HD_ERROR_INVALID_PARAMETER and one
   logged error naming the crop box, at create and at set_params (which keeps the old box). */
static void test_crop_bad_input(void)
{
    static const float bad[][2] = {{NAN, 1.0f}, {0.0f, NAN}, {0.0f, INFINITY}, {-INFINITY, 1.0f}, {0.6f, 0.4f},
                                   {0.5f, 0.5f}, {-0.1f, 1.0f}, {0.0f, 1.5f}, {1.0f, 1.0f}, {0.2f, -0.3f}};
    uint8_t *full = (uint8_t *)malloc(N * N * N);
    hd_light l;
    hd_desc d, q;
    hd_context ctx;
    hd_test_log log;
    hd_params p;
    size_t k;
    int axis;
    fill(full, 0);
    make_desc(&d, full, &l, HD_METHOD_HD);
    d.logger = hd_test_logger(&log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    for (k = 0; k < sizeof bad / sizeof bad[0]; ++k)
        for (axis = 0; axis < 3; ++axis) {
            hd_desc db = d;
            hd_context c2 = {0};
            int before = log.errors;
            db.params.crop_min[axis] = bad[k][0];
            db.params.crop_max[axis] = bad[k][1];
            CHECK_MSG(hd_create(&db, &c2) == HD_ERROR_INVALID_PARAMETER, "create: box {%g, %g} on axis %d",
                      (double)bad[k][0], (double)bad[k][1], axis);
            CHECK(log.errors == before + 1 && strstr(log.last, "crop") != NULL);
            if (c2.id) hd_destroy(c2);
            p = d.params;
            p.crop_min[axis] = bad[k][0];
            p.crop_max[axis] = bad[k][1];
            CHECK_MSG(hd_set_params(ctx, &p) == HD_ERROR_INVALID_PARAMETER, "set_params: box {%g, %g} on axis %d",
                      (double)bad[k][0], (double)bad[k][1], axis);
            CHECK(log.errors == before + 2 && strstr(log.last, "crop") != NULL);
        }
    CHECK(hd_query_desc(ctx, &q) == HD_SUCCESS);
    CHECK(q.params.crop_min[0] == 0.0f && q.params.crop_max[0] == 1.0f);
    /* the smallest valid boxes and the whole box pass */
    p = d.params;
    p.crop_min[0] = 0.0f; p.crop_max[0] = 1e-6f;
    p.crop_min[1] = 0.999f; p.crop_max[1] = 1.0f;
    CHECK(hd_set_params(ctx, &p) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS);
    CHECK(log.errors == (int)(2 * 3 * (sizeof bad / sizeof bad[0])));
    hd_destroy(ctx);
    free(full);
}

const hd_test_case hd_tests_crop[] = {
    {"crop_cropped_region_is_absent", test_cropped_region_is_absent},
    {"crop_face_inside_cell", test_crop_face_inside_cell},
    {"crop_change_restarts", test_crop_change_restarts},
    {"crop_shrinks_direct_mask", test_crop_shrinks_direct_mask},
    {"crop_defaults", test_crop_defaults},
    {"crop_bad_input", test_crop_bad_input},
};
const int hd_tests_crop_count = sizeof hd_tests_crop / sizeof hd_tests_crop[0];
