/* test_half.c - binary16 illumination storage (params.illumination_precision): the portable
   float <-> half conversion of hd_prelude_c.h (a table of edge cases, every one of the 65536
   halves, round-to-nearest-even on a sweep of floats), and HD with half storage through the
   public API on the CPU backend: close to float32 within the rounding bound, half the bytes,
   invalidated by the switch, validated. */
#include "hybriddiff.h"
#include "backends/hd_prelude_c.h"
#include "hd_test.h"
#include <stdlib.h>

/* The value of half h computed independently of hdk_h2f, in double: (-1)^s 2^(e-15) 1.m, or
   2^-14 0.m for e = 0; NaN for e = 31 with m != 0, inf for m = 0. */
static double half_value(unsigned h)
{
    unsigned e = (h >> 10) & 31u, m = h & 1023u;
    double v = e == 0 ? ldexp((double)m, -24) : e == 31 ? (m ? NAN : INFINITY) : ldexp((double)(1024u + m), (int)e - 25);
    return (h & 0x8000u) ? -v : v;
}

static int is_half_nan(unsigned h) { return (h & 0x7c00u) == 0x7c00u && (h & 0x3ffu) != 0; }

static float bits_float(uint32_t u) { float f; memcpy(&f, &u, 4); return f; }

/* Edge cases: zeros, the largest half and the rounding boundary to inf (65520 ties to even,
   which is inf), subnormal halves and their ties, ties between normal halves, float subnormals,
   NaN (quiet, sign kept). Expected bits worked out by hand from IEEE 754 binary16. */
static void test_conversion_table(void)
{
    static const struct { float f; unsigned h; } cases[] = {
        {0.0f, 0x0000}, {-0.0f, 0x8000}, {1.0f, 0x3c00}, {-2.0f, 0xc000},
        {65504.0f, 0x7bff}, {65519.0f, 0x7bff}, {65520.0f, 0x7c00}, {-65520.0f, 0xfc00}, {1e10f, 0x7c00},
        {6.103515625e-05f, 0x0400},                 /* 2^-14, the smallest normal half */
        {5.9604644775390625e-08f, 0x0001},          /* 2^-24, the smallest subnormal */
        {2.98023223876953125e-08f, 0x0000},         /* 2^-25: tie between 0 and 2^-24 -> even 0 */
        {8.94069671630859375e-08f, 0x0002},         /* 3 * 2^-25: tie between 1 and 2 -> 2 */
        {1.490116119384765625e-07f, 0x0002},        /* 5 * 2^-25: tie between 2 and 3 -> 2 */
        {6.1005353927612305e-05f, 0x0400},          /* 2^-14 - 2^-25: tie 0x03ff / 0x0400 -> 0x0400 */
        {1.00048828125f, 0x3c00},                   /* 1 + 2^-11: tie -> 0x3c00 */
        {1.00146484375f, 0x3c02},                   /* 1 + 3 * 2^-11: tie -> 0x3c02 */
        {0.1f, 0x2e66}, {0.33333334f, 0x3555}, {1e-45f, 0x0000}, {-1e-45f, 0x8000},
    };
    size_t i;
    unsigned h;
    for (i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        h = hdk_f2h(cases[i].f);
        CHECK_MSG(h == cases[i].h, "hdk_f2h(%.9g) = 0x%04x, expected 0x%04x", (double)cases[i].f, h, cases[i].h);
    }
    /* just above the 2^-25 tie, just above the 1 + 2^-11 tie */
    CHECK(hdk_f2h(bits_float(0x33000001u)) == 0x0001);
    CHECK(hdk_f2h(bits_float(0x3f801001u)) == 0x3c01);
    CHECK(hdk_f2h(INFINITY) == 0x7c00 && hdk_f2h(-INFINITY) == 0xfc00);
    h = hdk_f2h(NAN);
    CHECK(is_half_nan(h) && (h & 0x0200u));
    h = hdk_f2h(bits_float(0xff800001u)); /* a signalling NaN with the lowest payload bit: stays NaN, quiet, negative */
    CHECK(is_half_nan(h) && (h & 0x0200u) && (h & 0x8000u));
}

/* Every half: hdk_h2f gives its exact value (bit for bit against half_value), and back through
   hdk_f2h gives the same half; a NaN stays a NaN of the same sign, made quiet. */
static void test_conversion_all_halves(void)
{
    unsigned h, bad_value = 0, bad_trip = 0;
    for (h = 0; h < 65536u; ++h) {
        float f = hdk_h2f((uint16_t)h);
        double want = half_value(h);
        unsigned back = hdk_f2h(f);
        if (is_half_nan(h)) {
            if (f == f || !is_half_nan(back) || (back & 0x8000u) != (h & 0x8000u) || !(back & 0x0200u)) ++bad_trip;
            continue;
        }
        if ((double)f != want || (signbit(f) != 0) != ((h & 0x8000u) != 0)) ++bad_value;
        if (back != h) ++bad_trip;
    }
    CHECK_MSG(bad_value == 0, "%u halves convert to the wrong float", bad_value);
    CHECK_MSG(bad_trip == 0, "%u halves do not survive the round trip", bad_trip);
}

/* hdk_f2h rounds to nearest, ties to even: for floats spread over every exponent (each 1021st
   bit pattern below 65520, plus the sign), no other half lies closer and a tie went to the even
   one. The half above 0x7bff counts as 65536, the value rounding aims at past the largest. */
static void test_conversion_nearest_even(void)
{
    uint32_t u;
    unsigned bad = 0, checked = 0;
    for (u = 0; u < 0x477ff000u; u += 1021u) {
        float f = bits_float(u);
        unsigned h = hdk_f2h(f);
        double v = half_value(h), up = h == 0x7bffu ? 65536.0 : half_value(h + 1u), d = fabs(v - (double)f);
        double du = fabs(up - (double)f), dd = h > 0 ? fabs(half_value(h - 1u) - (double)f) : INFINITY;
        ++checked;
        if (d > du || d > dd || (d == du && (h & 1u)) || (d == dd && (h & 1u)) || hdk_f2h(-f) != (h | 0x8000u)) ++bad;
    }
    CHECK_MSG(bad == 0, "%u of %u floats not rounded to the nearest even half", bad, checked);
}

/* ---- HD with binary16 storage ----------------------------------------------------------------- */
#define HN 20
static uint8_t half_blob[HN * HN * HN];

/* A sphere with a dense core in a 20^3 grid of air, 2 lights of different colours (3 channels). */
static void half_desc(hd_desc *d, hd_light *l, hd_test_log *log)
{
    int x, y, z;
    for (z = 0; z < HN; ++z)
        for (y = 0; y < HN; ++y)
            for (x = 0; x < HN; ++x) {
                float dx = x - 9.5f, dy = y - 9.5f, dz = z - 9.5f, r = sqrtf(dx * dx + dy * dy + dz * dz);
                half_blob[(z * HN + y) * HN + x] = (uint8_t)(r < 8 ? (r < 4 ? 255 : 120) : 0);
            }
    memset(d, 0, sizeof *d);
    /* the paper's grid and boundary (hd_params_preset): these cases are not about the defaults */
    d->params.illumination_downsample = 1;
    d->params.diffusion_boundary = HD_BOUNDARY_BOX;
    memset(l, 0, 2 * sizeof *l);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = HN;
    d->volume.data = half_blob;
    d->transfer_function.count = 0;
    l[0].direction[2] = -1.0f;
    l[1].direction[0] = 1.0f; l[1].direction[1] = -0.5f; l[1].color[0] = 1.0f; l[1].color[1] = 0.6f; l[1].color[2] = 0.3f;
    d->lights = l;
    d->light_count = 2;
    d->camera.width = d->camera.height = 24;
    d->params.extinction = 40.0f;
    d->logger = hd_test_logger(log);
}

/* max |b - a| / max |a| */
static double rel_linf(const float *a, const float *b, size_t n)
{
    double dm = 0.0, am = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) {
        if (fabs((double)b[i] - a[i]) > dm) dm = fabs((double)b[i] - a[i]);
        if (fabs((double)a[i]) > am) am = fabs((double)a[i]);
    }
    return am > 0.0 ? dm / am : dm;
}

/* Half and float storage, same seed, NIT iterations, red-black and Jacobi: the tracked samples
   are the same (tracking reads sigma_t, not E), so E differs only by the stores' rounding. Each
   store of the running mean rounds once, at most 2^-12 of the stored value (11-bit significand,
   to nearest), and the mean's weight (1 - 1/n) <= 1 carries earlier errors on undamped: after
   NIT iterations at most NIT * 2^-12 of max E. A phi update is a positive combination of E and
   neighbouring phi, so its relative error is at most its inputs' plus its own store's 2^-12:
   after NIT iterations of 4 sweeps at most (NIT + 4 NIT) * 2^-12. The projection is a positive
   combination of E + phi: the same bound holds for the image. Every value read back is a half. */
#define NIT 6
static void test_half_matches_float(void)
{
    int solver;
    for (solver = HD_SOLVER_RED_BLACK; solver <= HD_SOLVER_JACOBI; ++solver) {
        hd_desc d;
        hd_light l[2];
        hd_test_log log;
        hd_context c32, c16;
        hd_stats s;
        size_t n, ni, i;
        float *a, *b;
        unsigned not_half = 0;
        double eE, ePhi, eImg, bound_e = NIT * ldexp(1.0, -12), bound_phi = 5.0 * NIT * ldexp(1.0, -12);
        half_desc(&d, l, &log);
        d.params.solver = (hd_solver)solver;
        CHECK(hd_create(&d, &c32) == HD_SUCCESS);
        d.params.illumination_precision = HD_PRECISION_FLOAT16;
        CHECK(hd_create(&d, &c16) == HD_SUCCESS);
        CHECK(hd_iterate(c32, NIT) == HD_SUCCESS && hd_iterate(c16, NIT) == HD_SUCCESS);
        CHECK(hd_get_stats(c32, &s) == HD_SUCCESS);
        n = (size_t)s.illumination_dims[0] * s.illumination_dims[1] * s.illumination_dims[2] * s.illumination_channels;
        ni = (size_t)d.camera.width * d.camera.height * 4;
        a = (float *)malloc((n > ni ? n : ni) * sizeof(float));
        b = (float *)malloc((n > ni ? n : ni) * sizeof(float));
        CHECK(hd_read_illumination(c32, HD_ILLUMINATION_DIRECT, a, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(c16, HD_ILLUMINATION_DIRECT, b, n) == HD_SUCCESS);
        eE = rel_linf(a, b, n);
        for (i = 0; i < n; ++i) not_half += hdk_h2f(hdk_f2h(b[i])) != b[i];
        CHECK(hd_read_illumination(c32, HD_ILLUMINATION_SCATTERED, a, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(c16, HD_ILLUMINATION_SCATTERED, b, n) == HD_SUCCESS);
        ePhi = rel_linf(a, b, n);
        for (i = 0; i < n; ++i) not_half += hdk_h2f(hdk_f2h(b[i])) != b[i];
        CHECK(hd_read_image_f32(c32, a, ni) == HD_SUCCESS && hd_read_image_f32(c16, b, ni) == HD_SUCCESS);
        eImg = rel_linf(a, b, ni);
        printf("  half vs float (%s, %d it): rel Linf E %.2e (bound %.2e), phi %.2e (bound %.2e), image %.2e\n",
               solver == HD_SOLVER_JACOBI ? "Jacobi" : "red-black", NIT, eE, bound_e, ePhi, bound_phi, eImg);
        CHECK(not_half == 0);
        CHECK(eE > 0.0 && eE <= bound_e); /* > 0: the storage is really half */
        CHECK(ePhi <= bound_phi);
        CHECK(eImg <= bound_phi);
        free(a);
        free(b);
        hd_destroy(c32);
        hd_destroy(c16);
    }
}

/* method_bytes: E and phi (and Jacobi's buffer) take 2 bytes per voxel and channel instead of 4;
   sigma_t, the projection's summed light and the CPU backend's direct-light mask (a bit per grid
   voxel, an entry count per 8^3 brick) are the same in both. */
static void test_half_bytes(void)
{
    int solver;
    for (solver = HD_SOLVER_RED_BLACK; solver <= HD_SOLVER_JACOBI; ++solver) {
        hd_desc d;
        hd_light l[2];
        hd_test_log log;
        hd_context c32, c16;
        hd_stats s32, s16;
        size_t gvox, sig, lsum, bricks = (size_t)((HN + 7) / 8) * ((HN + 7) / 8) * ((HN + 7) / 8);
        half_desc(&d, l, &log);
        d.params.solver = (hd_solver)solver;
        CHECK(hd_create(&d, &c32) == HD_SUCCESS);
        d.params.illumination_precision = HD_PRECISION_FLOAT16;
        CHECK(hd_create(&d, &c16) == HD_SUCCESS);
        CHECK(hd_get_stats(c32, &s32) == HD_SUCCESS && hd_get_stats(c16, &s16) == HD_SUCCESS);
        gvox = (size_t)HN * HN * HN;
        sig = gvox * 4;
        lsum = gvox * 3 * 4 + (gvox + 7) / 8 + (bricks + 1) * 4; /* and the mask */
        CHECK(s32.illumination_channels == 3 && s16.illumination_channels == 3);
        CHECK(s32.method_bytes - sig - lsum == gvox * 3 * 4 * (solver == HD_SOLVER_JACOBI ? 3 : 2));
        CHECK(s16.method_bytes - sig - lsum == (s32.method_bytes - sig - lsum) / 2);
        hd_destroy(c32);
        hd_destroy(c16);
    }
}

/* Switching the precision restarts E, phi and the image (new grids), in both directions; the
   iteration after it runs. */
static void test_half_invalidation(void)
{
    hd_desc d;
    hd_light l[2];
    hd_test_log log;
    hd_context c;
    hd_params p;
    hd_stats s;
    size_t n = (size_t)HN * HN * HN * 3, i;
    float *e = (float *)malloc(n * sizeof(float)), *f = (float *)malloc(n * sizeof(float));
    int k, nonzero;
    half_desc(&d, l, &log);
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    for (k = 0; k < 2; ++k) {
        CHECK(hd_iterate(c, 2) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &s) == HD_SUCCESS && s.iterations == 2 && s.frames == 2);
        CHECK(hd_query_desc(c, &d) == HD_SUCCESS);
        p = d.params;
        p.illumination_precision = k == 0 ? HD_PRECISION_FLOAT16 : HD_PRECISION_FLOAT32;
        CHECK(hd_set_params(c, &p) == HD_SUCCESS);
        CHECK(hd_get_stats(c, &s) == HD_SUCCESS && s.iterations == 0 && s.frames == 0);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_DIRECT, e, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(c, HD_ILLUMINATION_SCATTERED, f, n) == HD_SUCCESS);
        for (i = 0, nonzero = 0; i < n; ++i) nonzero += e[i] != 0.0f || f[i] != 0.0f;
        CHECK(nonzero == 0);
    }
    CHECK(hd_iterate(c, 1) == HD_SUCCESS);
    hd_destroy(c);
    free(e);
    free(f);
}

/* The binary16 stores are per voxel like the float ones: 1 and 2 threads give the same bits
   (red-black and Jacobi, 3 iterations). */
static void test_half_threads(void)
{
    int solver;
    for (solver = HD_SOLVER_RED_BLACK; solver <= HD_SOLVER_JACOBI; ++solver) {
        hd_desc d;
        hd_light l[2];
        hd_test_log log;
        hd_context one, two;
        size_t n = (size_t)HN * HN * HN * 3;
        float *a = (float *)malloc(n * sizeof(float)), *b = (float *)malloc(n * sizeof(float));
        half_desc(&d, l, &log);
        d.params.solver = (hd_solver)solver;
        d.params.illumination_precision = HD_PRECISION_FLOAT16;
        d.threads = 1;
        CHECK(hd_create(&d, &one) == HD_SUCCESS);
        d.threads = 2;
        CHECK(hd_create(&d, &two) == HD_SUCCESS);
        CHECK(hd_iterate(one, 3) == HD_SUCCESS && hd_iterate(two, 3) == HD_SUCCESS);
        CHECK(hd_read_illumination(one, HD_ILLUMINATION_SCATTERED, a, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(two, HD_ILLUMINATION_SCATTERED, b, n) == HD_SUCCESS);
        CHECK(memcmp(a, b, n * sizeof(float)) == 0);
        CHECK(hd_read_illumination(one, HD_ILLUMINATION_DIRECT, a, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(two, HD_ILLUMINATION_DIRECT, b, n) == HD_SUCCESS);
        CHECK(memcmp(a, b, n * sizeof(float)) == 0);
        hd_destroy(one);
        hd_destroy(two);
        free(a);
        free(b);
    }
}

/* An out-of-range precision is HD_ERROR_INVALID_ENUM with a message naming the field; half with
   the multigrid solver is HD_ERROR_UNSUPPORTED (its levels are float32), and the context keeps
   its parameters. */
static void test_half_validation(void)
{
    hd_desc d;
    hd_light l[2];
    hd_test_log log;
    hd_context c;
    hd_params p;
    half_desc(&d, l, &log);
    d.params.illumination_precision = HD_PRECISION_COUNT;
    CHECK(hd_create(&d, &c) == HD_ERROR_INVALID_ENUM);
    CHECK(log.last_code == HD_ERROR_INVALID_ENUM && strstr(log.last, "illumination_precision") != NULL);
    d.params.illumination_precision = HD_PRECISION_FLOAT16;
    d.params.solver = HD_SOLVER_MULTIGRID;
    CHECK(hd_create(&d, &c) == HD_ERROR_UNSUPPORTED);
    CHECK(strstr(log.last, "MULTIGRID") != NULL);
    d.params.solver = HD_SOLVER_RED_BLACK;
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    p = d.params;
    p.illumination_precision = (hd_precision)-1;
    CHECK(hd_set_params(c, &p) == HD_ERROR_INVALID_ENUM);
    CHECK(hd_query_desc(c, &d) == HD_SUCCESS && d.params.illumination_precision == HD_PRECISION_FLOAT16);
    hd_destroy(c);
}

const hd_test_case hd_tests_half[] = {
    {"half_conversion_table", test_conversion_table},
    {"half_conversion_all_halves", test_conversion_all_halves},
    {"half_conversion_nearest_even", test_conversion_nearest_even},
    {"half_matches_float", test_half_matches_float},
    {"half_bytes", test_half_bytes},
    {"half_invalidation", test_half_invalidation},
    {"half_threads", test_half_threads},
    {"half_validation", test_half_validation},
};
const int hd_tests_half_count = (int)(sizeof hd_tests_half / sizeof hd_tests_half[0]);
