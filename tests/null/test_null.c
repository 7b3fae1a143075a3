/* test_null.c - the public API over the null backend (backends/hd_null.h), which computes
   nothing and counts the primitives it is called with: every call the header documents works
   through the contract of src/hd_backend.h alone, each primitive runs inside a bracket, and each
   setter reaches exactly the stages its invalidation names (hybriddiff.h, above
   hd_set_transfer_function). `make test-null` runs it (part of make test). */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_NULL
#include "hybriddiff.h"
#include "tests/hd_test.h"

int hd_test_failures;

static const hd__backend *be_of(hd_context h)
{
    const hd__ctx *c = hd__lookup(h);
    return c ? c->vw.be : NULL;
}

/* The counters' change over one call (after - before), per primitive. */
typedef struct calls {
    unsigned long n[HD__NULL_COUNT];
    unsigned cleared;
} calls;
static calls snap(hd_context h)
{
    calls c;
    const hd__backend *be = be_of(h);
    memcpy(c.n, be->calls, sizeof c.n);
    c.cleared = be->cleared;
    return c;
}
static unsigned long delta(hd_context h, const calls *before, int which) { return be_of(h)->calls[which] - before->n[which]; }

enum { N = 8, W = 16 };
static unsigned char vox[N * N * N];

static void make_desc(hd_desc *d)
{
    int i;
    for (i = 0; i < N * N * N; ++i) vox[i] = (unsigned char)(i * 7 % 251);
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = N;
    d->volume.data = vox;
    d->camera.width = d->camera.height = W;
}

/* Every public call succeeds (or is refused as documented) over the null backend. */
static void test_null_api(void)
{
    static float img[W * W * 4], ill[N * N * N * 3];
    static uint8_t px[W * W * 4];
    hd_desc d;
    hd_context h;
    hd_stats s;
    hd_params p;
    hd_camera cam;
    hd_light l[2];
    float tf[8] = {0, 0, 0, 0, 1, 1, 1, 1};
    hd_transfer_function t;
    int m;
    make_desc(&d);
    CHECK(strcmp(hd_backend_name(), "null") == 0);
    CHECK(hd_create(&d, &h) == HD_SUCCESS);
    CHECK(hd_iterate(h, 2) == HD_SUCCESS);
    CHECK(hd_refine(h, 1) == HD_SUCCESS);
    CHECK(hd_render(h) == HD_SUCCESS);
    CHECK(hd_read_image_f32(h, img, sizeof img / sizeof img[0]) == HD_SUCCESS && img[0] == 0.0f);
    CHECK(hd_read_image_rgba8(h, px, sizeof px) == HD_SUCCESS && px[3] == 0);
    CHECK(hd_read_illumination(h, HD_ILLUMINATION_DIRECT, ill, sizeof ill / sizeof ill[0]) == HD_SUCCESS);
    CHECK(hd_read_illumination(h, HD_ILLUMINATION_SCATTERED, ill, sizeof ill / sizeof ill[0]) == HD_SUCCESS);
    CHECK(hd_get_stats(h, &s) == HD_SUCCESS && s.iterations == 3 && s.method == HD_METHOD_HD);
    CHECK(hd_vulkan_record(h, (void *)px, 1) == HD_SUCCESS); /* records nothing, counts the schedule */
    CHECK(hd_vulkan_record_refine(h, (void *)px, 1) == HD_SUCCESS);
    CHECK(hd_gl_render_to_texture(h, 1) == HD_ERROR_UNSUPPORTED);
    t.rgba = tf;
    t.count = 2;
    CHECK(hd_set_transfer_function(h, &t) == HD_SUCCESS);
    memset(l, 0, sizeof l);
    l[0].direction[1] = -1.0f;
    l[1].type = HD_LIGHT_POINT;
    l[1].position[0] = 2.0f;
    l[1].color[0] = 1.0f;
    CHECK(hd_set_lights(h, l, 2) == HD_SUCCESS);
    CHECK(hd_query_desc(h, &d) == HD_SUCCESS);
    cam = d.camera;
    cam.width = 9;
    CHECK(hd_set_camera(h, &cam) == HD_SUCCESS);
    for (m = HD_METHOD_HD; m < HD_METHOD_COUNT; ++m) {
        p = d.params;
        p.method = (hd_method)m;
        p.render_scale = m == HD_METHOD_HD ? HD_RENDER_SCALE_AUTO : 2;
        CHECK(hd_set_params(h, &p) == HD_SUCCESS);
        CHECK_MSG(hd_iterate(h, 2) == HD_SUCCESS && hd_render(h) == HD_SUCCESS, "method %s", hd_method_name((hd_method)m));
        CHECK(hd_read_image_f32(h, img, sizeof img / sizeof img[0]) == HD_SUCCESS);
    }
    p = d.params;
    p.solver = HD_SOLVER_MULTIGRID;
    p.diffusion_sweeps = 2;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    CHECK(hd_iterate(h, 2) == HD_SUCCESS);
    CHECK(be_of(h)->calls[HD__NULL_mg_begin] > 0 && be_of(h)->calls[HD__NULL_mg_row_sums] > 0);
    p.solver = HD_SOLVER_JACOBI;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS && be_of(h)->jacobi == 1);
    CHECK(!be_of(h)->misuse);
    CHECK(be_of(h)->calls[HD__NULL_begin] == be_of(h)->calls[HD__NULL_end]);
    CHECK(hd_destroy(h) == HD_SUCCESS);
    CHECK(hd_destroy(h) == HD_ERROR_INVALID_HANDLE);
}

/* Each setter, then one hd_iterate: the stages it reaches are what its invalidation names. */
static void test_null_invalidation(void)
{
    hd_desc d;
    hd_context h;
    hd_params p;
    hd_camera cam;
    calls c;
    make_desc(&d);
    CHECK(hd_create(&d, &h) == HD_SUCCESS);
    c = snap(h);
    CHECK(hd_iterate(h, 1) == HD_SUCCESS); /* the first: everything */
    CHECK(delta(h, &c, HD__NULL_upload_inputs) == 1 && delta(h, &c, HD__NULL_classify) == 1 && delta(h, &c, HD__NULL_direct_list) == 1);
    CHECK(delta(h, &c, HD__NULL_alloc_illumination) == 1 && delta(h, &c, HD__NULL_alloc_image) == 1);
    CHECK(delta(h, &c, HD__NULL_direct) == 1 && delta(h, &c, HD__NULL_diffuse_sweeps) == 1 && delta(h, &c, HD__NULL_project) == 1);
    CHECK(hd_query_desc(h, &d) == HD_SUCCESS);
    /* the camera: the image only, no light work beyond the iteration's own */
    cam = d.camera;
    cam.eye[0] = 1.0f;
    CHECK(hd_set_camera(h, &cam) == HD_SUCCESS);
    c = snap(h);
    ((hd__backend *)be_of(h))->cleared = 0;
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(delta(h, &c, HD__NULL_classify) == 0 && delta(h, &c, HD__NULL_upload_inputs) == 0 && delta(h, &c, HD__NULL_alloc_image) == 0);
    CHECK_MSG(be_of(h)->cleared == HD__DIRTY_IMAGE, "cleared 0x%x", be_of(h)->cleared);
    /* a new image size: a new image buffer */
    cam.width = 12;
    CHECK(hd_set_camera(h, &cam) == HD_SUCCESS);
    c = snap(h);
    CHECK(hd_iterate(h, 1) == HD_SUCCESS && delta(h, &c, HD__NULL_alloc_image) == 1);
    /* albedo: the image, not sigma_t; E and phi kept (phi the warm start of the new solve) */
    p = d.params;
    p.albedo = 0.5f;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    c = snap(h);
    ((hd__backend *)be_of(h))->cleared = 0;
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(delta(h, &c, HD__NULL_classify) == 0);
    CHECK_MSG(be_of(h)->cleared == HD__DIRTY_IMAGE, "cleared 0x%x", be_of(h)->cleared);
    /* extinction: sigma_t again and the image; E and phi the warm start */
    p.extinction = 50.0f;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    c = snap(h);
    ((hd__backend *)be_of(h))->cleared = 0;
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(delta(h, &c, HD__NULL_upload_inputs) == 1 && delta(h, &c, HD__NULL_classify) == 1 && delta(h, &c, HD__NULL_direct_list) == 1);
    CHECK(be_of(h)->cleared == HD__DIRTY_IMAGE);
    /* exposure, tracking, sweeps: nothing */
    p.exposure = 3.0f;
    p.tracking = HD_TRACKING_DELTA;
    p.diffusion_sweeps = 2;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    c = snap(h);
    ((hd__backend *)be_of(h))->cleared = 0;
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(be_of(h)->cleared == 0 && delta(h, &c, HD__NULL_classify) == 0);
    /* the grid: new illumination grids */
    p.illumination_downsample = 1;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    c = snap(h);
    CHECK(hd_iterate(h, 1) == HD_SUCCESS && delta(h, &c, HD__NULL_alloc_illumination) == 1 && delta(h, &c, HD__NULL_classify) == 1);
    CHECK(be_of(h)->illum_floats == (size_t)N * N * N);
    /* a reduced frame: projection then upsample */
    p.render_scale = 2;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    c = snap(h);
    CHECK(hd_iterate(h, 1) == HD_SUCCESS && delta(h, &c, HD__NULL_project) == 1 && delta(h, &c, HD__NULL_upsample) == 1);
    CHECK(be_of(h)->reduced == 1);
    /* converged light: hd_render projects without light work, then stops once the image is done */
    p.light_tolerance = 1e30f;
    p.render_scale = 1;
    p.frame_window = 2;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    CHECK(hd_render(h) == HD_SUCCESS && hd_render(h) == HD_SUCCESS && hd_render(h) == HD_SUCCESS);
    c = snap(h);
    CHECK(hd_render(h) == HD_SUCCESS && hd_render(h) == HD_SUCCESS);
    CHECK_MSG(delta(h, &c, HD__NULL_direct) == 0 && delta(h, &c, HD__NULL_project) == 0, "direct %lu, project %lu",
              delta(h, &c, HD__NULL_direct), delta(h, &c, HD__NULL_project));
    CHECK(!be_of(h)->misuse);
    CHECK(hd_destroy(h) == HD_SUCCESS);
}

/* hd_update_volume reaches the backend once per changed box (hd__be_update_volume, with the
   box of the changed voxels and its majorant cells), then classification and the direct light's
   list: no new inputs, grids or image, E and phi not cleared (the warm start); equal voxels reach
   nothing; hd_reset clears E, phi and the image. */
static void test_null_update(void)
{
    static unsigned char next[N * N * N];
    hd_desc d;
    hd_context h;
    hd_volume_update u = HD_VOLUME_UPDATE_INIT;
    calls c;
    const hd__ctx *ctx;
    make_desc(&d);
    CHECK(hd_create(&d, &h) == HD_SUCCESS);
    CHECK(hd_iterate(h, 2) == HD_SUCCESS);
    ctx = hd__lookup(h);
    memcpy(next, vox, sizeof next);
    next[(3 * N + 2) * N + 5] ^= 0x55; /* one voxel: (5, 2, 3) */
    u.type = HD_VOXEL_U8;
    u.dims[0] = u.dims[1] = u.dims[2] = N;
    u.data = next;
    c = snap(h);
    CHECK(hd_update_volume(h, &u) == HD_SUCCESS);
    CHECK(ctx->upd.lo[0] == 5 && ctx->upd.hi[0] == 6 && ctx->upd.lo[1] == 2 && ctx->upd.hi[1] == 3 && ctx->upd.lo[2] == 3 &&
          ctx->upd.hi[2] == 4);
    CHECK(delta(h, &c, HD__NULL_update_volume) == 0); /* at the next call that reaches the device */
    ((hd__backend *)be_of(h))->cleared = 0;
    c = snap(h);
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(delta(h, &c, HD__NULL_update_volume) == 1 && delta(h, &c, HD__NULL_classify) == 1);
    CHECK(delta(h, &c, HD__NULL_upload_inputs) == 0 && delta(h, &c, HD__NULL_alloc_illumination) == 0 &&
          delta(h, &c, HD__NULL_alloc_image) == 0 && delta(h, &c, HD__NULL_alloc_lights) == 0);
    CHECK_MSG(be_of(h)->cleared == HD__DIRTY_IMAGE, "cleared 0x%x", be_of(h)->cleared);
    CHECK(delta(h, &c, HD__NULL_direct) == 1 && delta(h, &c, HD__NULL_project) == 1);
    /* the same voxels again: nothing */
    c = snap(h);
    CHECK(hd_update_volume(h, &u) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(delta(h, &c, HD__NULL_update_volume) == 0 && delta(h, &c, HD__NULL_classify) == 0 && delta(h, &c, HD__NULL_direct_list) == 0);
    /* a TF of new colours only (grey scattering): the TF uploaded, no light work, the image cleared */
    {
        float tf[8] = {0, 0, 0, 0, 1, 1, 1, 1}, red[8] = {0, 0, 0, 0, 1, 0.2f, 0.1f, 1};
        hd_transfer_function t;
        t.rgba = tf;
        t.count = 2;
        CHECK(hd_set_transfer_function(h, &t) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS);
        ((hd__backend *)be_of(h))->cleared = 0;
        c = snap(h);
        t.rgba = red;
        CHECK(hd_set_transfer_function(h, &t) == HD_SUCCESS && hd_refine(h, 1) == HD_SUCCESS);
        CHECK(delta(h, &c, HD__NULL_upload_inputs) == 1 && delta(h, &c, HD__NULL_classify) == 0 && delta(h, &c, HD__NULL_direct_list) == 0);
        CHECK_MSG(be_of(h)->cleared == HD__DIRTY_IMAGE, "cleared 0x%x", be_of(h)->cleared);
    }
    /* a clean restart */
    ((hd__backend *)be_of(h))->cleared = 0;
    CHECK(hd_reset(h) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(be_of(h)->cleared == (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE));
    CHECK(be_of(h)->calls[HD__NULL_begin] == be_of(h)->calls[HD__NULL_end] && !be_of(h)->misuse);
    hd_destroy(h);
}

/* hd_vulkan_record_render's schedule: light iterations while the light has not converged, each
   measured by the next call (its read-back of E and phi in the preparation), none once it has
   (the projection alone), no projection once the image is done; the write into the target every
   call, checked before anything is recorded. The null backend's light is zero, so the estimate
   is 0 from the second measurement on: converged at the fourth call's preparation. */
static void test_null_record_render(void)
{
    hd_desc d;
    hd_context h;
    hd_stats s;
    hd_vulkan_target t = HD_VULKAN_TARGET_INIT;
    hd_output o = HD_OUTPUT_INIT;
    calls c;
    int k, cb = 0;
    make_desc(&d);
    d.params.frame_window = 2;
    CHECK(hd_create(&d, &h) == HD_SUCCESS);
    t.image = 1;
    t.width = W + 3;
    t.height = W;
    o.x = 3;
    for (k = 0; k < 3; ++k) { /* calls 1-3: a light iteration and a frame each, not converged yet */
        c = snap(h);
        CHECK(hd_vulkan_record_render(h, &cb, &t, &o) == HD_SUCCESS);
        CHECK(delta(h, &c, HD__NULL_direct) == 1 && delta(h, &c, HD__NULL_project) == 1 && delta(h, &c, HD__NULL_record_output) == 1);
        CHECK(delta(h, &c, HD__NULL_output_target_check) == 1 && delta(h, &c, HD__NULL_record_begin) == 1);
        /* calls 2 and 3 measured the previous call's iteration: one read of E and one of phi */
        CHECK_MSG(delta(h, &c, HD__NULL_read_illumination) == (k ? 2u : 0u), "call %d: %lu reads", k + 1,
                  delta(h, &c, HD__NULL_read_illumination));
        CHECK(hd_get_stats(h, &s) == HD_SUCCESS && !s.light_converged && s.iterations == (uint64_t)k + 1);
    }
    for (k = 0; k < 4; ++k) { /* call 4 measures the third: converged; no light work from then on */
        c = snap(h);
        CHECK(hd_vulkan_record_render(h, &cb, &t, &o) == HD_SUCCESS);
        CHECK(hd_get_stats(h, &s) == HD_SUCCESS && s.light_converged && s.iterations == 3);
        CHECK(delta(h, &c, HD__NULL_direct) == 0 && delta(h, &c, HD__NULL_diffuse_sweeps) == 0 && delta(h, &c, HD__NULL_record_output) == 1);
        CHECK_MSG(delta(h, &c, HD__NULL_project) == (k < 2 ? 1u : 0u), "converged call %d: %lu frames", k + 1,
                  delta(h, &c, HD__NULL_project)); /* frame_window 2, then the image is done */
        CHECK(delta(h, &c, HD__NULL_read_illumination) == (k ? 0u : 2u));
    }
    CHECK(s.frames == 2);
    /* without a target: the frame alone; a camera move: a new image, the light kept */
    CHECK(hd_query_desc(h, &d) == HD_SUCCESS);
    d.camera.eye[0] = 1.0f;
    CHECK(hd_set_camera(h, &d.camera) == HD_SUCCESS);
    c = snap(h);
    CHECK(hd_vulkan_record_render(h, &cb, NULL, NULL) == HD_SUCCESS);
    CHECK(delta(h, &c, HD__NULL_project) == 1 && delta(h, &c, HD__NULL_direct) == 0 && delta(h, &c, HD__NULL_record_output) == 0);
    /* hd_vulkan_record's iterations are measured by the next call too, as one change */
    c = snap(h);
    CHECK(hd_vulkan_record(h, &cb, 3) == HD_SUCCESS && delta(h, &c, HD__NULL_direct) == 3);
    CHECK(hd_get_stats(h, &s) == HD_SUCCESS && s.iterations == 6);
    c = snap(h);
    CHECK(hd_render(h) == HD_SUCCESS && delta(h, &c, HD__NULL_read_illumination) == 2 && delta(h, &c, HD__NULL_direct) == 0);
    /* hd_vulkan_record_refine: light iterations and the sum, no frame, converged light refined
       too; the copies recorded after it measure nothing, the next other call measures them */
    {
        hd_vulkan_volume_target vt = HD_VULKAN_VOLUME_TARGET_INIT;
        vt.buffer = 1;
        vt.buffer_size = (uint64_t)N * N * N * 4;
        c = snap(h);
        CHECK(hd_vulkan_record_refine(h, &cb, 2) == HD_SUCCESS && delta(h, &c, HD__NULL_direct) == 2);
        CHECK(delta(h, &c, HD__NULL_project) == 0 && delta(h, &c, HD__NULL_record_light_sum) == 1 && delta(h, &c, HD__NULL_record_begin) == 1);
        CHECK(hd_get_stats(h, &s) == HD_SUCCESS && s.iterations == 8);
        c = snap(h);
        CHECK(hd_vulkan_record_illumination(h, &cb, 0, &vt) == HD_SUCCESS && delta(h, &c, HD__NULL_read_illumination) == 0);
        c = snap(h);
        CHECK(hd_render(h) == HD_SUCCESS && delta(h, &c, HD__NULL_read_illumination) == 2);
        CHECK(hd_vulkan_record_refine(h, &cb, 0) == HD_ERROR_INVALID_PARAMETER && hd_vulkan_record_refine(h, NULL, 1) == HD_ERROR_NULL_POINTER);
    }
    /* refusals before the device: the region, the size, the format enum, the target's kind */
    {
        struct { int x, y, w, fmt; uint64_t image, buffer; hd_result want; } bad[6] = {
            {4, 0, 0, 0, 1, 0, HD_ERROR_OUTPUT_OUTSIDE_TARGET}, {0, 1, 0, 0, 1, 0, HD_ERROR_OUTPUT_OUTSIDE_TARGET},
            {0, 0, W - 1, 0, 1, 0, HD_ERROR_OUTPUT_SIZE},      {0, 0, 0, 7, 1, 0, HD_ERROR_INVALID_ENUM},
            {0, 0, 0, 0, 1, 1, HD_ERROR_INVALID_PARAMETER},    {0, 0, 0, 0, 0, 1, HD_ERROR_BUFFER_TOO_SMALL}};
        for (k = 0; k < 6; ++k) {
            hd_vulkan_target b = t;
            hd_output bo = o;
            bo.x = bad[k].x;
            bo.y = bad[k].y;
            bo.width = bad[k].w;
            bo.format = (hd_output_format)bad[k].fmt;
            b.image = bad[k].image;
            b.buffer = bad[k].buffer;
            c = snap(h);
            CHECK_MSG(hd_vulkan_record_render(h, &cb, &b, &bo) == bad[k].want, "refusal %d", k);
            CHECK(delta(h, &c, HD__NULL_record_begin) == 0 && delta(h, &c, HD__NULL_begin) == 0);
        }
    }
    CHECK(hd_vulkan_record_render(h, NULL, NULL, NULL) == HD_ERROR_NULL_POINTER);
    CHECK(!be_of(h)->misuse);
    CHECK(be_of(h)->calls[HD__NULL_record_begin] == be_of(h)->calls[HD__NULL_record_end]);
    CHECK(hd_destroy(h) == HD_SUCCESS);
}

/* hd_read_image_ex on every backend's core path: the region in a larger target, bytes outside
   untouched, the refusals. */
static void test_null_read_image_ex(void)
{
    static unsigned char buf[(W + 5) * (W + 2) * 16 + 8];
    hd_desc d;
    hd_context h;
    hd_output o = HD_OUTPUT_INIT;
    size_t pitch = (W + 5) * 8, i, changed = 0, zeros = 0, y;
    make_desc(&d);
    CHECK(hd_create(&d, &h) == HD_SUCCESS);
    CHECK(hd_read_image_ex(h, NULL, buf, sizeof buf, 0) == HD_ERROR_NO_FRAME); /* as the other read-backs */
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    memset(buf, 0x5a, sizeof buf);
    o.format = HD_OUTPUT_LINEAR_F16;
    o.x = 4;
    o.y = 2;
    CHECK(hd_read_image_ex(h, &o, buf, sizeof buf, pitch) == HD_SUCCESS);
    for (i = 0; i < sizeof buf; ++i) {
        size_t row = i / pitch, col = (i % pitch) / 8;
        int in = row >= 2 && row < 2 + W && col >= 4 && col < 4 + W;
        if (in) zeros += buf[i] == 0;
        else changed += buf[i] != 0x5a;
    }
    CHECK_MSG(zeros == (size_t)W * W * 8 && changed == 0, "%zu zero bytes in the region, %zu changed outside", zeros, changed);
    /* the rows' bytes must lie in dst and in row_pitch */
    CHECK(hd_read_image_ex(h, &o, buf, (2 + W - 1) * pitch + (4 + W) * 8 - 1, pitch) == HD_ERROR_BUFFER_TOO_SMALL);
    CHECK(hd_read_image_ex(h, &o, buf, (2 + W - 1) * pitch + (4 + W) * 8, pitch) == HD_SUCCESS);
    CHECK(hd_read_image_ex(h, &o, buf, sizeof buf, (4 + W) * 8 - 1) == HD_ERROR_OUTPUT_OUTSIDE_TARGET);
    o.x = -1;
    CHECK(hd_read_image_ex(h, &o, buf, sizeof buf, pitch) == HD_ERROR_OUTPUT_OUTSIDE_TARGET);
    o.x = 0;
    o.height = W + 1;
    CHECK(hd_read_image_ex(h, &o, buf, sizeof buf, pitch) == HD_ERROR_OUTPUT_SIZE);
    o.height = 0;
    o.format = HD_OUTPUT_FORMAT_COUNT;
    CHECK(hd_read_image_ex(h, &o, buf, sizeof buf, pitch) == HD_ERROR_INVALID_ENUM);
    CHECK(hd_read_image_ex(h, NULL, NULL, sizeof buf, 0) == HD_ERROR_NULL_POINTER);
    /* NULL: RGBA8, the camera's size, tight rows */
    memset(buf, 0x5a, sizeof buf);
    CHECK(hd_read_image_ex(h, NULL, buf, (size_t)W * W * 4, 0) == HD_SUCCESS);
    for (y = 0, changed = 0; y < (size_t)W * W * 4; ++y) changed += buf[y] != 0;
    CHECK(changed == 0 && buf[W * W * 4] == 0x5a);
    CHECK(hd_destroy(h) == HD_SUCCESS);
}

static const hd_test_case cases[] = {
    {"null_api", test_null_api},
    {"null_invalidation", test_null_invalidation},
    {"null_update", test_null_update},
    {"null_record_render", test_null_record_render},
    {"null_read_image_ex", test_null_read_image_ex},
};

int main(void)
{
    int i, passed = 0, failed = 0;
    for (i = 0; i < (int)(sizeof cases / sizeof cases[0]); ++i) {
        hd_test_failures = 0;
        fprintf(stderr, "[ RUN  ] %s\n", cases[i].name);
        cases[i].fn();
        if (hd_test_failures) { ++failed; fprintf(stderr, "[ FAIL ] %s\n", cases[i].name); }
        else { ++passed; fprintf(stderr, "[  OK  ] %s\n", cases[i].name); }
    }
    printf("%d passed, %d failed\n", passed, failed);
    return failed ? 1 : 0;
}
