/* test_params.c - hd_params' table (src/hd_params.h) against what the library does: every field
   changed alone invalidates what its row says and nothing else, and a field the state depends on
   (measured from fresh contexts) is invalidated by its row. Handles: a slot's generation runs out
   into retirement, never into a reused handle. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <float.h>
#include <stddef.h>

int hdt_param_rows(void);
const char *hdt_param_row(int i, size_t *offset, size_t *size, unsigned *invalidates);
int hdt_param_bits(unsigned *direct, unsigned *phi, unsigned *image, unsigned *paths);
int hdt_param_warm_bits(unsigned *warm_e, unsigned *warm_phi);
unsigned hdt_slot_generation(int slot, unsigned generation);
int hdt_slots(void);

/* Another valid value for each field: a row without one here fails the walk, so a new field must
   say how it is changed. */
static int param_change(const char *name, hd_params *p)
{
#define F(n, stmt) if (strcmp(name, #n) == 0) { stmt; return 1; }
    F(method, p->method = p->method == HD_METHOD_HD ? HD_METHOD_CD : HD_METHOD_HD)
    F(extinction, p->extinction *= 0.5f)
    F(albedo, p->albedo = 0.6f)
    F(anisotropy, p->anisotropy = 0.4f)
    F(majorant, p->majorant = 0.0f) /* set on the walk's contexts, changed back to the grid */
    F(solver, p->solver = HD_SOLVER_JACOBI)
    F(diffusion_sweeps, p->diffusion_sweeps += 3)
    F(disable_diffusion, p->disable_diffusion = !p->disable_diffusion)
    F(tracking, p->tracking = HD_TRACKING_DELTA)
    F(seed, p->seed += 11)
    F(background, p->background[1] = 0.25f)
    F(step, p->step = 0.8f)
    F(frame_window, p->frame_window = 3)
    F(exposure, p->exposure = 2.0f)
    F(max_bounces, p->max_bounces = 1)
    F(illumination_downsample, p->illumination_downsample = 1)
    F(rgb_scattering, p->rgb_scattering = 1)
    F(diffusion_boundary, p->diffusion_boundary = HD_BOUNDARY_BOX)
    F(illumination_precision, p->illumination_precision = HD_PRECISION_FLOAT16)
    F(light_tolerance, p->light_tolerance = 0.02f)
    F(render_budget, p->render_budget = 0.001f)
    F(crop_min, p->crop_min[0] = 0.3f)
    F(crop_max, p->crop_max[2] = 0.7f)
    F(render_scale, p->render_scale = 2)
    F(light_window, p->light_window = 3)
    F(rest, p->rest = HD_REST_REFINE)
    F(refine_bounces, p->refine_bounces = 2)
    F(depth_threshold, p->depth_threshold = 0.8f)
    F(environment_background, p->environment_background = 1)
#undef F
    return 0;
}

/* The fields whose change leaves every limit as it is: the solver's path to the same solution
   (solver, sweeps), an estimator of the same expectation (tracking), what only the 8-bit encoding
   or hd_render's loop reads (exposure, light_tolerance, render_budget), the warm start's window
   (light_window: read only at the next warm change). Their rows invalidate nothing, though a run
   of a few iterations can differ. */
static int same_limit(const char *name)
{
    static const char *names[] = {"solver", "diffusion_sweeps", "tracking", "exposure", "light_tolerance", "render_budget", "light_window"};
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (strcmp(name, names[i]) == 0) return 1;
    return 0;
}

enum { PN = 12, PW = 12 };
static unsigned char pvox[PN * PN * PN];

static void param_desc(hd_desc *d, hd_method m)
{
    int x, y, z;
    for (z = 0; z < PN; ++z)
        for (y = 0; y < PN; ++y)
            for (x = 0; x < PN; ++x) pvox[(z * PN + y) * PN + x] = (unsigned char)((x * 37 + y * 11 + z * 5) % 200 + 40);
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = PN;
    d->volume.data = pvox;
    d->camera.width = d->camera.height = PW;
    d->params.method = m;
    d->params.extinction = 30.0f;
    d->params.max_bounces = 8;
    d->threads = 1;
}

/* E, phi and the image after n iterations of a fresh context with params p (method p->method). */
typedef struct param_state {
    float img[PW * PW * 4];
    float e[PN * PN * PN * 3], phi[PN * PN * PN * 3];
    int ok;
} param_state;
static void param_run(const hd_params *p, int n, param_state *st)
{
    hd_desc d;
    hd_context c;
    param_desc(&d, p->method);
    d.params = *p;
    memset(st, 0, sizeof *st);
    if (hd_create(&d, &c) != HD_SUCCESS) return;
    st->ok = hd_iterate(c, n) == HD_SUCCESS && hd_read_image_f32(c, st->img, PW * PW * 4) == HD_SUCCESS;
    if (p->method == HD_METHOD_HD)
        st->ok = st->ok && hd_read_illumination(c, HD_ILLUMINATION_DIRECT, st->e, sizeof st->e / sizeof st->e[0]) == HD_SUCCESS &&
                 hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, st->phi, sizeof st->phi / sizeof st->phi[0]) == HD_SUCCESS;
    hd_destroy(c);
}

/* Every field changed alone, on an HD and a PT_MS context after two iterations: what the next
   call would reset (hd_get_stats: iterations 0 when E restarts, frames 0 when the image restarts,
   light_error 1 when E or phi restarts or is a warm start) is exactly the row's invalidation; a
   warm row keeps E and phi as they were (bit for bit) and its iterations. */
static void test_param_table_invalidation(void)
{
    unsigned bd, bp, bi, bpaths, bwe, bwp;
    int i, k, rows = hdt_param_rows();
    static const hd_method methods[2] = {HD_METHOD_HD, HD_METHOD_PT_MS};
    static float e0[PN * PN * PN * 3], p0[PN * PN * PN * 3], e1[PN * PN * PN * 3], p1[PN * PN * PN * 3];
    hdt_param_bits(&bd, &bp, &bi, &bpaths);
    hdt_param_warm_bits(&bwe, &bwp);
    CHECK(rows >= 24);
    for (i = 0; i < rows; ++i) {
        size_t off, size;
        unsigned row_inv;
        const char *name = hdt_param_row(i, &off, &size, &row_inv);
        for (k = 0; k < 2; ++k) {
            unsigned inv = row_inv;
            hd_desc d;
            hd_context c;
            hd_params p;
            hd_stats s;
            int want_d, want_i, want_fresh, pt = methods[k] == HD_METHOD_PT_MS;
            param_desc(&d, methods[k]);
            if (strcmp(name, "majorant") == 0) d.params.majorant = 100.0f;
            CHECK(hd_create(&d, &c) == HD_SUCCESS);
            CHECK(hd_iterate(c, 2) == HD_SUCCESS);
            CHECK(hd_query_desc(c, &d) == HD_SUCCESS);
            if (!pt) {
                CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e0, sizeof e0 / sizeof e0[0]) == HD_SUCCESS);
                CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, p0, sizeof p0 / sizeof p0[0]) == HD_SUCCESS);
            }
            p = d.params;
            CHECK_MSG(param_change(name, &p), "params.%s has no change in test_params.c", name);
            CHECK_MSG(memcmp((const char *)&p + off, (const char *)&d.params + off, size) != 0, "params.%s did not change", name);
            CHECK_MSG(hd_set_params(c, &p) == HD_SUCCESS, "params.%s", name);
            CHECK(hd_get_stats(c, &s) == HD_SUCCESS);
            if (inv & bpaths) inv = (inv & ~bpaths) | (pt ? bi : 0u);
            if (pt && (inv & bi)) inv |= bd; /* a path tracer's image is its whole state */
            if (strcmp(name, "method") == 0) inv = bd | bp | bi;
            want_d = (inv & bd) != 0;
            want_i = (inv & bi) != 0;
            want_fresh = !pt && (inv & (bd | bp | bwe | bwp)) != 0;
            CHECK_MSG((s.iterations == 0) == want_d && (s.frames == 0) == want_i && (!pt && s.light_error == 1.0) == want_fresh,
                      "params.%s on %s: iterations %llu, frames %llu, light_error %g; the row invalidates E %d, image %d, light %d",
                      name, pt ? "PT_MS" : "HD", (unsigned long long)s.iterations, (unsigned long long)s.frames, s.light_error,
                      want_d, want_i, want_fresh);
            if (!pt && (inv & (bwe | bwp)) && !(inv & (bd | bp)) && !(row_inv & ~(bwe | bwp | bi | 1u))) {
                /* a warm row on the same grid: E and phi as they were */
                CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e1, sizeof e1 / sizeof e1[0]) == HD_SUCCESS);
                CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, p1, sizeof p1 / sizeof p1[0]) == HD_SUCCESS);
                CHECK_MSG(memcmp(e0, e1, sizeof e0) == 0 && memcmp(p0, p1, sizeof p0) == 0, "params.%s: a warm row lost E or phi", name);
                CHECK(hd_get_stats(c, &s) == HD_SUCCESS && s.iterations == 2 && !s.light_converged);
            }
            hd_destroy(c);
        }
    }
}

/* Every field the state depends on is invalidated by its row: fresh contexts with the old and the
   new value, 3 iterations each; where E, phi or the image differ, the row must reset it (a
   field of same_limit() excepted). Fails on a row that forgets a dependence, as max_bounces did
   for PT_MS's running mean. */
static void test_param_table_dependence(void)
{
    static param_state a, b;
    unsigned bd, bp, bi, bpaths, bwe, bwp;
    int i, k, rows = hdt_param_rows();
    static const hd_method methods[2] = {HD_METHOD_HD, HD_METHOD_PT_MS};
    hdt_param_bits(&bd, &bp, &bi, &bpaths);
    hdt_param_warm_bits(&bwe, &bwp);
    for (i = 0; i < rows; ++i) {
        size_t off, size;
        unsigned inv;
        const char *name = hdt_param_row(i, &off, &size, &inv);
        if (strcmp(name, "method") == 0 || same_limit(name)) continue;
        for (k = 0; k < 2; ++k) {
            hd_desc d;
            hd_params p;
            int pt = methods[k] == HD_METHOD_PT_MS, de, dphi, dimg;
            unsigned eff = inv;
            param_desc(&d, methods[k]);
            if (strcmp(name, "majorant") == 0) d.params.majorant = 100.0f;
            p = d.params;
            param_run(&p, 3, &a);
            CHECK(param_change(name, &p));
            param_run(&p, 3, &b);
            CHECK_MSG(a.ok && b.ok, "params.%s: runs failed", name);
            if (eff & bpaths) eff = (eff & ~bpaths) | (pt ? bi : 0u);
            de = memcmp(a.e, b.e, sizeof a.e) != 0;
            dphi = memcmp(a.phi, b.phi, sizeof a.phi) != 0;
            dimg = memcmp(a.img, b.img, sizeof a.img) != 0;
            CHECK_MSG(!de || (eff & (bd | bwe)), "params.%s: E depends on it, its row neither resets E nor re-weights it", name);
            CHECK_MSG(!dphi || (eff & (bp | bwp)), "params.%s: phi depends on it, its row neither resets phi nor restarts its solve", name);
            CHECK_MSG(!dimg || (eff & bi), "params.%s on %s: the image depends on it, its row does not reset the image", name,
                      pt ? "PT_MS" : "HD");
        }
    }
}

/* The fields whose change keeps E and phi as the warm start of the new light (hybriddiff.h, the
   table above hd_set_transfer_function): their rows are warm, never a reset, and the walk above
   checks that a warm row keeps E and phi bit for bit. */
static void test_param_warm_rows(void)
{
    static const char *warm[] = {"extinction", "albedo", "anisotropy"};
    unsigned bd, bp, bi, bpaths, bwe, bwp;
    int i, k, found = 0, rows = hdt_param_rows();
    hdt_param_bits(&bd, &bp, &bi, &bpaths);
    hdt_param_warm_bits(&bwe, &bwp);
    for (i = 0; i < rows; ++i) {
        size_t off, size;
        unsigned inv;
        const char *name = hdt_param_row(i, &off, &size, &inv);
        for (k = 0; k < 3; ++k)
            if (strcmp(name, warm[k]) == 0) {
                ++found;
                CHECK_MSG(!(inv & (bd | bp)) && (inv & bwp) && (inv & bi), "params.%s: row 0x%x is not warm", name, inv);
            }
    }
    CHECK(found == 3);
}

/* PT_MS after a max_bounces change: the running mean restarts (hd_stats.frames 1 after a call). */
static void test_param_max_bounces_restarts(void)
{
    hd_desc d;
    hd_context c;
    hd_stats s;
    param_desc(&d, HD_METHOD_PT_MS);
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_iterate(c, 3) == HD_SUCCESS);
    d.params.max_bounces = 2;
    CHECK(hd_set_params(c, &d.params) == HD_SUCCESS);
    CHECK(hd_iterate(c, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(c, &s) == HD_SUCCESS);
    CHECK_MSG(s.frames == 1 && s.iterations == 1, "frames %llu, iterations %llu", (unsigned long long)s.frames,
              (unsigned long long)s.iterations);
    hd_destroy(c);
}

/* Every enum field out of range is HD_ERROR_INVALID_ENUM, logged; render_budget above its bound
   and a background that could overflow the image's sums are rejected. */
static void test_param_codes(void)
{
    hd_desc d;
    hd_context c;
    hd_test_log log;
    hd_params p;
    param_desc(&d, HD_METHOD_HD);
    d.logger = hd_test_logger(&log);
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_query_desc(c, &d) == HD_SUCCESS);
#define BAD(stmt, code) do { p = d.params; stmt; log.errors = 0; \
        CHECK_MSG(hd_set_params(c, &p) == (code) && log.errors == 1, "%s", #stmt); } while (0)
    BAD(p.method = (hd_method)9, HD_ERROR_INVALID_ENUM);
    BAD(p.solver = (hd_solver)-2, HD_ERROR_INVALID_ENUM);
    BAD(p.tracking = (hd_tracking)3, HD_ERROR_INVALID_ENUM);
    BAD(p.diffusion_boundary = (hd_boundary)3, HD_ERROR_INVALID_ENUM);
    BAD(p.diffusion_boundary = (hd_boundary)-1, HD_ERROR_INVALID_ENUM);
    BAD(p.illumination_precision = (hd_precision)1000, HD_ERROR_INVALID_ENUM);
    BAD(p.render_budget = 10.5f, HD_ERROR_INVALID_PARAMETER);
    BAD(p.render_budget = 1e30f, HD_ERROR_INVALID_PARAMETER);
    BAD(p.background[0] = FLT_MAX, HD_ERROR_INVALID_PARAMETER);
    BAD(p.background[2] = 2e6f, HD_ERROR_INVALID_PARAMETER);
    BAD(p.exposure = NAN, HD_ERROR_INVALID_PARAMETER);
    BAD(p.render_scale = 0 - 2, HD_ERROR_INVALID_PARAMETER);
    BAD(p.frame_window = -1, HD_ERROR_INVALID_PARAMETER);
    BAD(p.crop_min[1] = 0.9f; p.crop_max[1] = 0.5f, HD_ERROR_INVALID_PARAMETER);
#undef BAD
    p = d.params;
    p.render_budget = 10.0f;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS);
    hd_destroy(c);
}

/* HD_SOLVER_AUTO (the default) by the illumination grid's voxels: a 160^3 volume at
   illumination_downsample 1 (4.1 M grid voxels) gets multigrid with 1 CG step, at 2 (0.5 M)
   red-black with 4 sweeps, and red-black with float16 illumination; hd_set_params picks again.
   An explicit solver stays. The grid's index limit: 1024^3 at downsample 1 is refused (the
   check comes before the voxels are read), a volume over 2^30 voxels too. */
enum { AN = 160 };
static unsigned char avox[AN * AN * AN];
static void test_solver_auto(void)
{
    hd_desc d, q;
    hd_context c;
    hd_test_log log;
    hd_params p;
    memset(&d, 0, sizeof d);
    memset(avox, 100, sizeof avox);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = AN;
    d.volume.data = avox;
    d.camera.width = d.camera.height = 8;
    d.threads = 1;
    d.logger = hd_test_logger(&log);
    d.params.illumination_downsample = 1;
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(q.params.solver == HD_SOLVER_MULTIGRID && q.params.diffusion_sweeps == 1);
    p = d.params;
    p.illumination_downsample = 2;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS && hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(q.params.solver == HD_SOLVER_RED_BLACK && q.params.diffusion_sweeps == 4);
    p.illumination_downsample = 1;
    p.illumination_precision = HD_PRECISION_FLOAT16;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS && hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(q.params.solver == HD_SOLVER_RED_BLACK && q.params.diffusion_sweeps == 4);
    p.illumination_precision = HD_PRECISION_FLOAT32;
    p.solver = HD_SOLVER_JACOBI;
    CHECK(hd_set_params(c, &p) == HD_SUCCESS && hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(q.params.solver == HD_SOLVER_JACOBI && q.params.diffusion_sweeps == 4);
    hd_destroy(c);
    d.params.illumination_downsample = 2;
    CHECK(hd_create(&d, &c) == HD_SUCCESS && hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(q.params.solver == HD_SOLVER_RED_BLACK && q.params.diffusion_sweeps == 4);
    hd_destroy(c);
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = 1024;
    d.params.illumination_downsample = 1;
    log.errors = 0;
    CHECK(hd_create(&d, &c) == HD_ERROR_SIZE_OVERFLOW && log.errors == 1);
    d.volume.dims[2] = 1025;
    d.params.illumination_downsample = 4;
    log.errors = 0;
    CHECK(hd_create(&d, &c) == HD_ERROR_SIZE_OVERFLOW && log.errors == 1);
}

/* Every slot at the end of its generations: the last handle of a slot works, and once destroyed
   the slot is retired (its handles never come back); the next context takes another slot. The
   slots' generations are restored after. */
static void test_handle_retirement(void)
{
    hd_desc d;
    hd_context a, b;
    unsigned saved[256];
    int i, n = hdt_slots();
    param_desc(&d, HD_METHOD_HD);
    for (i = 0; i < n; ++i) saved[i] = hdt_slot_generation(i, 0xfffffeu);
    CHECK(hd_create(&d, &a) == HD_SUCCESS);
    CHECK_MSG((a.id >> 8) == 0xffffffu, "handle 0x%08x", (unsigned)a.id);
    CHECK(hd_get_stats(a, NULL) == HD_ERROR_NULL_POINTER); /* valid */
    CHECK(hd_destroy(a) == HD_SUCCESS);
    CHECK(hd_get_stats(a, NULL) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_destroy(a) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_create(&d, &b) == HD_SUCCESS);
    CHECK_MSG((b.id & 0xffu) != (a.id & 0xffu) && b.id != a.id, "a retired slot was reused: 0x%08x after 0x%08x", (unsigned)b.id,
              (unsigned)a.id);
    CHECK(hd_get_stats(a, NULL) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_destroy(b) == HD_SUCCESS);
    for (i = 0; i < n; ++i) hdt_slot_generation(i, saved[i]);
}

/* After hd_destroy the context's logger is never called, also for the stale handle's use. */
static int destroyed_logger_calls;
static void count_log(void *user, hd_log_level level, hd_result code, const char *message, const char *file, int line)
{
    (void)user; (void)level; (void)code; (void)message; (void)file; (void)line;
    ++destroyed_logger_calls;
}
static void test_logger_after_destroy(void)
{
    hd_desc d;
    hd_context c;
    param_desc(&d, HD_METHOD_HD);
    d.logger.func = count_log;
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    CHECK(hd_destroy(c) == HD_SUCCESS);
    destroyed_logger_calls = 0;
    CHECK(hd_render(c) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_set_params(c, &d.params) == HD_ERROR_INVALID_HANDLE);
    CHECK(hd_destroy(c) == HD_ERROR_INVALID_HANDLE);
    CHECK(destroyed_logger_calls == 0);
}

/* Value ranges whose width or its inverse leaves float ({-2^127, 2^127}: the width overflows;
   {0, 2^-140}, a denormal: its inverse overflows) map the voxels as an ordinary range does: the
   same pattern of TF coordinates 0, 1/4, 1/2, 1 (exact in both) gives the image of range {0, 1}. */
static void test_value_range_extremes(void)
{
    static float f[PN * PN * PN], t[PN * PN * PN];
    static float ref[PW * PW * 4], img[PW * PW * 4];
    static const float levels[4] = {0.0f, 0.25f, 0.5f, 1.0f};
    const float big = ldexpf(1.0f, 127), tiny = ldexpf(1.0f, -140);
    const float ranges[2][2] = {{-big, big}, {0.0f, tiny}};
    hd_desc d;
    hd_context c;
    int i, k;
    for (i = 0; i < PN * PN * PN; ++i) t[i] = levels[(i * 7 + i / 13) % 4];
    param_desc(&d, HD_METHOD_HD);
    d.volume.type = HD_VOXEL_F32;
    d.volume.data = t;
    CHECK(hd_create(&d, &c) == HD_SUCCESS && hd_iterate(c, 2) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, ref, PW * PW * 4) == HD_SUCCESS);
    hd_destroy(c);
    for (k = 0; k < 2; ++k) {
        float nz = 0.0f;
        /* lo + t (hi - lo), exactly: k 0 as -2^127 + 2 (t 2^127) (hi - lo overflows), k 1 as t 2^-140 */
        for (i = 0; i < PN * PN * PN; ++i) f[i] = k == 0 ? (t[i] == 1.0f ? big : -big + (t[i] * big) * 2.0f) : t[i] * tiny;
        param_desc(&d, HD_METHOD_HD);
        d.volume.type = HD_VOXEL_F32;
        d.volume.data = f;
        d.volume.value_range[0] = ranges[k][0];
        d.volume.value_range[1] = ranges[k][1];
        CHECK(hd_create(&d, &c) == HD_SUCCESS && hd_iterate(c, 2) == HD_SUCCESS);
        CHECK(hd_read_image_f32(c, img, PW * PW * 4) == HD_SUCCESS);
        for (i = 0; i < PW * PW * 4; ++i) nz += img[i];
        CHECK_MSG(nz > 0.0f && memcmp(img, ref, sizeof img) == 0, "value range {%g, %g}: the image differs from range {0, 1}'s",
                  (double)ranges[k][0], (double)ranges[k][1]);
        hd_destroy(c);
    }
}

const hd_test_case hd_tests_params[] = {
    {"param_table_invalidation", test_param_table_invalidation},
    {"param_table_dependence", test_param_table_dependence},
    {"param_warm_rows", test_param_warm_rows},
    {"param_max_bounces_restarts", test_param_max_bounces_restarts},
    {"param_codes", test_param_codes},
    {"solver_auto", test_solver_auto},
    {"handle_retirement", test_handle_retirement},
    {"logger_after_destroy", test_logger_after_destroy},
    {"value_range_extremes", test_value_range_extremes},
};
const int hd_tests_params_count = sizeof hd_tests_params / sizeof hd_tests_params[0];
