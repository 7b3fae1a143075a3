/* test_environment.c - the environment light (hd_set_environment) on the CPU backend, through
   the public API: HD's direct light E against the exact integral of the map's radiance times
   the transmittance over the sphere (numerical quadrature on the host, exact for a homogeneous
   box), for a uniform map and for a sky with a sun (importance-sampled vs evenly spread
   quadrature: a wrong pdf fails it); a map that is one bright texel against the directional
   light from that texel's direction, with and without a rotation (the shadow on the same side);
   PT_MS in a uniform environment with a scattering-only medium, whose radiance is the
   environment's everywhere (next-event estimation and escaping paths counted once each); the
   memory it adds; bad input.

   Statistical checks: the voxels' deviations from the exact value are independent (each its
   own random stream), so their mean passes when within 4 standard errors of 0 (fails by chance
   with probability about 6e-5); the seeds are fixed. */
#include "hybriddiff.h"
#include "hd_test.h"

#define TE_PI 3.14159265358979323846
static uint8_t te_vol[16 * 16 * 16];
static const float te_tf_flat[8] = {0.8f, 0.8f, 0.8f, 1.0f, 0.8f, 0.8f, 0.8f, 1.0f};

/* A homogeneous box of dx x dy x dz voxels, HD without diffusion (E is the direct light alone),
   on the paper's grid (one illumination voxel per voxel). */
static void te_desc(hd_desc *d, int dx, int dy, int dz, float extinction)
{
    size_t i, n = (size_t)dx * dy * dz;
    for (i = 0; i < n; ++i) te_vol[i] = 255;
    memset(d, 0, sizeof *d);
    d->params.illumination_downsample = 1;
    d->params.disable_diffusion = 1;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = dx; d->volume.dims[1] = dy; d->volume.dims[2] = dz;
    d->volume.data = te_vol;
    d->transfer_function.rgba = te_tf_flat;
    d->transfer_function.count = 2;
    d->camera.width = d->camera.height = 8;
    d->params.method = HD_METHOD_HD;
    d->params.extinction = extinction;
    d->threads = 2;
}

/* Distance from p inside the box of half sides h along unit w to the box's edge. */
static double te_exit(const double p[3], const double w[3], const double h[3])
{
    double t = 1e300;
    int a;
    for (a = 0; a < 3; ++a) {
        if (w[a] > 1e-12) { double s = (h[a] - p[a]) / w[a]; if (s < t) t = s; }
        if (w[a] < -1e-12) { double s = (-h[a] - p[a]) / w[a]; if (s < t) t = s; }
    }
    return t;
}

/* The map direction of (theta, phi) (hybriddiff.h, hd_environment), rotated by row-major r
   (NULL: none). */
static void te_dir(double theta, double phi, const float *r, double w[3])
{
    double m[3] = {sin(theta) * cos(phi), cos(theta), sin(theta) * sin(phi)};
    int i;
    for (i = 0; i < 3; ++i) w[i] = r ? r[3 * i] * m[0] + r[3 * i + 1] * m[1] + r[3 * i + 2] * m[2] : m[i];
}

/* The exact direct light at p of map rgb (w x h texels) in a homogeneous box (extinction sigma,
   half sides hs): sum over the texels of their radiance times the integral of exp(-sigma t)
   over the texel's solid angle, each texel by s x s midpoint samples in (theta, phi). */
static void te_exact(const float *rgb, int w, int h, const float *rot, double sigma, const double p[3], const double hs[3], int s,
                     double out[3])
{
    int i, j, a, b, c;
    out[0] = out[1] = out[2] = 0.0;
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            const float *px = rgb + 3 * (j * w + i);
            double acc = 0.0;
            if (px[0] == 0.0f && px[1] == 0.0f && px[2] == 0.0f) continue;
            for (b = 0; b < s; ++b)
                for (a = 0; a < s; ++a) {
                    double th = TE_PI * (j + (b + 0.5) / s) / h, ph = 2.0 * TE_PI * (i + (a + 0.5) / s) / w, dw[3];
                    te_dir(th, ph, rot, dw);
                    acc += exp(-sigma * te_exit(p, dw, hs)) * sin(th) * (TE_PI / (h * s)) * (2.0 * TE_PI / (w * s));
                }
            for (c = 0; c < 3; ++c) out[c] += px[c] * acc;
        }
}

/* HD's E after n iterations with environment env alone, against te_exact at every voxel of
   the box's middle slice pairs (z = 1, 2 of 4); returns the mean relative deviation and checks
   that the mean deviation is within 4 standard errors of 0. */
static double te_check_exact(const char *what, const hd_environment *env, int n, int s)
{
    static float e[16 * 16 * 4 * 3];
    hd_desc d;
    hd_context ctx;
    hd_stats st;
    double hs[3] = {0.5, 0.5, 0.125}, sum = 0.0, sum2 = 0.0, ref_sum = 0.0;
    int x, y, z, c, count = 0, ch, rotated = 0;
    for (c = 0; c < 9; ++c) rotated |= env->rotation[c] != 0.0f;
    te_desc(&d, 16, 16, 4, 3.0f);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_set_environment(ctx, env) == HD_SUCCESS);
    CHECK(hd_set_lights(ctx, NULL, 0) == HD_SUCCESS);
    CHECK(hd_refine(ctx, n) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &st) == HD_SUCCESS);
    ch = st.illumination_channels;
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, sizeof e / sizeof e[0]) == HD_SUCCESS);
    for (z = 1; z <= 2; ++z)
        for (y = 0; y < 16; y += 3)
            for (x = 0; x < 16; x += 3) {
                double p[3] = {(x + 0.5) / 16 - 0.5, (y + 0.5) / 16 - 0.5, ((z + 0.5) / 4 - 0.5) * 0.25}, ref[3];
                te_exact(env->rgb, env->width, env->height, rotated ? env->rotation : NULL, 3.0, p, hs, s, ref);
                for (c = 0; c < ch; ++c) {
                    double v = e[((c * 4 + z) * 16 + y) * 16 + x] - ref[c] * (env->intensity > 0.0f ? env->intensity : 1.0f);
                    sum += v; sum2 += v * v; ref_sum += ref[c]; ++count;
                }
            }
    {
        double mean = sum / count, sd = sqrt((sum2 / count - mean * mean) * count / (count - 1.0)), se = sd / sqrt((double)count);
        printf("  %s: %d channels, E - exact: mean %.4g (se %.2g), relative %.4f, %d values\n", what, ch, mean, se, mean / (ref_sum / count),
               count);
        CHECK(fabs(mean) < 4.0 * se);
        hd_destroy(ctx);
        return fabs(mean) / (ref_sum / count);
    }
}

/* A uniform environment of radiance L: E = L * integral of T over the sphere. */
static void test_env_uniform_slab(void)
{
    static float rgb[16 * 8 * 3];
    hd_environment env = HD_ENVIRONMENT_INIT;
    int i;
    for (i = 0; i < 16 * 8 * 3; ++i) rgb[i] = 0.7f;
    env.width = 16; env.height = 8; env.rgb = rgb;
    CHECK(te_check_exact("uniform L = 0.7, slab 16x16x4", &env, 400, 8) < 0.01);
}

/* A sky with a sun: a blue-to-white gradient by elevation and one texel 400 times brighter,
   importance-sampled by the tables; the quadrature spreads its samples evenly. */
static void te_sky(float *rgb, int w, int h, int si, int sj, float sun)
{
    int i, j;
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            float *px = rgb + 3 * (j * w + i), up = 1.0f - (j + 0.5f) / h;
            px[0] = 0.2f + 0.3f * up; px[1] = 0.3f + 0.3f * up; px[2] = 0.5f + 0.4f * up;
            if (j >= h / 2) { px[0] = px[1] = px[2] = 0.05f; } /* the ground */
            if (i == si && j == sj) { px[0] = sun; px[1] = 0.9f * sun; px[2] = 0.7f * sun; }
        }
}
static void test_env_importance_matches_quadrature(void)
{
    static float rgb[32 * 16 * 3];
    hd_environment env = HD_ENVIRONMENT_INIT;
    te_sky(rgb, 32, 16, 5, 3, 200.0f);
    env.width = 32; env.height = 16; env.rgb = rgb; env.intensity = 0.5f;
    CHECK(te_check_exact("sky with a sun, slab 16x16x4", &env, 400, 8) < 0.02);
    /* rotated a quarter turn about +y */
    env.rotation[0] = 0.0f; env.rotation[2] = 1.0f; env.rotation[4] = 1.0f; env.rotation[6] = -1.0f;
    CHECK(te_check_exact("sky with a sun, rotated", &env, 400, 8) < 0.02);
}

/* One bright texel (the sun) and the directional light from its centre's direction with the
   same irradiance: the same E, the shadow of an off-centre blob on the same side; the mirrored
   direction's light gives another E (so the comparison can fail). rot: the map's rotation. */
static double te_sun_vs_dir(const float *rot, double *mirror)
{
    static float rgb[64 * 32 * 3], e1[16 * 16 * 16], e2[16 * 16 * 16], e3[16 * 16 * 16];
    hd_environment env = HD_ENVIRONMENT_INIT;
    hd_desc d;
    hd_context ctx;
    hd_light l = HD_LIGHT_INIT;
    int si = 13, sj = 9, x, y, z, i;
    double th = TE_PI * (sj + 0.5) / 32, solid, s[3], num = 0.0, num3 = 0.0, den = 0.0;
    te_desc(&d, 16, 16, 16, 12.0f);
    for (z = 0; z < 16; ++z) /* a Gaussian blob off the centre toward -x */
        for (y = 0; y < 16; ++y)
            for (x = 0; x < 16; ++x) {
                double dx = (x + 0.5) / 16 - 0.35, dy = (y + 0.5) / 16 - 0.5, dz = (z + 0.5) / 16 - 0.5;
                te_vol[(z * 16 + y) * 16 + x] = (uint8_t)(255.0 * exp(-(dx * dx + dy * dy + dz * dz) / (2.0 * 0.12 * 0.12)) + 0.5);
            }
    memset(rgb, 0, sizeof rgb);
    rgb[3 * (sj * 64 + si)] = rgb[3 * (sj * 64 + si) + 1] = rgb[3 * (sj * 64 + si) + 2] = 1000.0f;
    env.width = 64; env.height = 32; env.rgb = rgb;
    if (rot) memcpy(env.rotation, rot, sizeof env.rotation);
    solid = 2.0 * TE_PI / 64 * (cos(TE_PI * sj / 32) - cos(TE_PI * (sj + 1) / 32));
    te_dir(th, 2.0 * TE_PI * (si + 0.5) / 64, rot, s);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_set_environment(ctx, &env) == HD_SUCCESS);
    CHECK(hd_set_lights(ctx, NULL, 0) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 64) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e1, 16 * 16 * 16) == HD_SUCCESS);
    hd_destroy(ctx);
    l.type = HD_LIGHT_DIRECTIONAL;
    l.intensity = (float)(1000.0 * solid);
    for (i = 0; i < 3; ++i) l.direction[i] = (float)-s[i];
    d.lights = &l; d.light_count = 1;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 64) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e2, 16 * 16 * 16) == HD_SUCCESS);
    l.direction[0] = (float)s[0]; /* mirrored in x: the shadow on the other side */
    CHECK(hd_set_lights(ctx, &l, 1) == HD_SUCCESS);
    CHECK(hd_reset(ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 64) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e3, 16 * 16 * 16) == HD_SUCCESS);
    hd_destroy(ctx);
    for (i = 0; i < 16 * 16 * 16; ++i) {
        num += fabs((double)e1[i] - e2[i]);
        num3 += fabs((double)e1[i] - e3[i]);
        den += e2[i];
    }
    *mirror = num3 / den;
    return num / den;
}
static void test_env_sun_matches_directional(void)
{
    static const float quarter[9] = {0.0f, 0.0f, 1.0f, 0.0f, 1.0f, 0.0f, -1.0f, 0.0f, 0.0f};
    double mirror = 0.0, diff = te_sun_vs_dir(NULL, &mirror);
    printf("  sun texel vs directional light: relative L1 %.4f (mirrored light: %.4f)\n", diff, mirror);
    CHECK(diff < 0.05 && mirror > 4.0 * diff);
    diff = te_sun_vs_dir(quarter, &mirror);
    printf("  rotated a quarter turn: relative L1 %.4f (mirrored light: %.4f)\n", diff, mirror);
    CHECK(diff < 0.05 && mirror > 4.0 * diff);
}

/* A medium that only scatters (albedo 1, white), lit by a uniform environment of radiance L
   and seen against a background of L: the radiance is L in every pixel and direction. PT_MS
   with anisotropic scattering counts each direction once, by next-event estimation or by the
   escaping path (multiple importance sampling): a double count or a gap moves the mean. */
static void test_env_pt_ms_equilibrium(void)
{
    static const float white[8] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    static float rgb[16 * 8 * 3], img[8 * 8 * 4], prev[8 * 8 * 4], bm[16][8 * 8];
    hd_environment env = HD_ENVIRONMENT_INIT;
    hd_desc d;
    hd_context ctx;
    int i, b, nb = 16, per = 40;
    double sum = 0.0, sum2 = 0.0, L = 0.7;
    for (i = 0; i < 16 * 8 * 3; ++i) rgb[i] = (float)L;
    env.width = 16; env.height = 8; env.rgb = rgb;
    te_desc(&d, 8, 8, 8, 4.0f);
    d.transfer_function.rgba = white;
    d.params.method = HD_METHOD_PT_MS;
    d.params.albedo = 1.0f;
    d.params.anisotropy = 0.6f;
    d.params.max_bounces = 1000;
    d.params.background[0] = d.params.background[1] = d.params.background[2] = (float)L;
    d.camera.eye[2] = 1.6f;
    d.camera.fov_y = 30.0f;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_set_environment(ctx, &env) == HD_SUCCESS);
    CHECK(hd_set_lights(ctx, NULL, 0) == HD_SUCCESS);
    memset(prev, 0, sizeof prev);
    /* batch means of the running mean: (n_b img_b - n_{b-1} img_{b-1}) / per, averaged over rgb */
    for (b = 0; b < nb; ++b) {
        CHECK(hd_iterate(ctx, per) == HD_SUCCESS);
        CHECK(hd_read_image_f32(ctx, img, 8 * 8 * 4) == HD_SUCCESS);
        for (i = 0; i < 64; ++i) {
            double m = 0.0;
            int c;
            for (c = 0; c < 3; ++c) m += ((b + 1.0) * img[4 * i + c] - b * (double)prev[4 * i + c]) / 3.0;
            bm[b][i] = (float)m;
        }
        memcpy(prev, img, sizeof img);
    }
    for (b = 0; b < nb; ++b) {
        double m = 0.0;
        for (i = 0; i < 64; ++i) m += bm[b][i] / 64.0;
        sum += m; sum2 += m * m;
    }
    {
        double mean = sum / nb, se = sqrt((sum2 / nb - mean * mean) / (nb - 1.0));
        printf("  PT_MS, scattering-only medium in a uniform environment L = %.2f: mean radiance %.4f (se %.2g)\n", L, mean, se);
        CHECK(fabs(mean - L) < 4.0 * se + 1e-3);
        CHECK(fabs(mean - L) < 0.02 * L);
    }
    hd_destroy(ctx);
}

/* method_bytes grows by the tables alone: 4 w h + 2 h + 1 floats (16 bytes per texel). A grey
   map beside one white light keeps one illumination channel; a coloured map needs three, as
   lights of different colours do. */
static void test_env_method_bytes(void)
{
    static float rgb[32 * 16 * 3];
    const size_t tables = (4u * 32 * 16 + 2 * 16 + 1) * sizeof(float);
    hd_environment env = HD_ENVIRONMENT_INIT;
    hd_light l[2];
    hd_desc d;
    hd_context ctx;
    hd_stats a, b, c;
    int i;
    for (i = 0; i < 32 * 16 * 3; ++i) rgb[i] = (float)(i / 3 % 7);
    env.width = 32; env.height = 16; env.rgb = rgb;
    te_desc(&d, 8, 8, 8, 2.0f);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &a) == HD_SUCCESS);
    CHECK(hd_set_environment(ctx, &env) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &b) == HD_SUCCESS);
    printf("  method_bytes: one light %zu, with a grey 32x16 environment %zu (+%zu)\n", a.method_bytes, b.method_bytes,
           b.method_bytes - a.method_bytes);
    CHECK(a.illumination_channels == 1 && b.illumination_channels == 1);
    CHECK(b.method_bytes == a.method_bytes + tables);
    te_sky(rgb, 32, 16, 5, 3, 10.0f);
    CHECK(hd_set_environment(ctx, &env) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &b) == HD_SUCCESS);
    memset(l, 0, sizeof l);
    for (i = 0; i < 2; ++i) { l[i].type = HD_LIGHT_DIRECTIONAL; l[i].direction[2] = -1.0f; l[i].color[i] = 1.0f; }
    CHECK(hd_set_environment(ctx, NULL) == HD_SUCCESS);
    CHECK(hd_set_lights(ctx, l, 2) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(ctx, &c) == HD_SUCCESS);
    CHECK(b.illumination_channels == 3 && c.illumination_channels == 3);
    CHECK(b.method_bytes == c.method_bytes + tables);
    hd_destroy(ctx);
}

/* Each bad input: its own code, one logged line, nothing changed. */
static void test_env_bad_input(void)
{
    static float rgb[4 * 2 * 3];
    hd_test_log log;
    hd_environment env = HD_ENVIRONMENT_INIT, bad;
    hd_desc d;
    hd_context ctx;
    hd_stats st;
    int i, errors;
    float nan = 0.0f;
    for (i = 0; i < 24; ++i) rgb[i] = 0.5f;
    env.width = 4; env.height = 2; env.rgb = rgb;
    te_desc(&d, 4, 4, 4, 1.0f);
    d.logger = hd_test_logger(&log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
#define TE_BAD(code) \
    do { \
        errors = log.errors; \
        CHECK(hd_set_environment(ctx, &bad) == (code)); \
        CHECK(log.errors == errors + 1 && log.last_code == (code)); \
    } while (0)
    bad = env; bad.width = 0; TE_BAD(HD_ERROR_INVALID_DIMENSIONS);
    bad = env; bad.height = HD_MAX_ENVIRONMENT_DIM + 1; TE_BAD(HD_ERROR_INVALID_DIMENSIONS);
    bad = env; bad.rgb = NULL; TE_BAD(HD_ERROR_NULL_POINTER);
    rgb[7] = nan / nan; bad = env; TE_BAD(HD_ERROR_INVALID_ENVIRONMENT);
    CHECK(strstr(log.last, "not finite") != NULL);
    rgb[7] = 1.0f / nan; TE_BAD(HD_ERROR_INVALID_ENVIRONMENT);
    rgb[7] = -0.5f; TE_BAD(HD_ERROR_INVALID_ENVIRONMENT);
    CHECK(strstr(log.last, "negative") != NULL);
    rgb[7] = 0.5f;
    bad = env; bad.intensity = -1.0f; TE_BAD(HD_ERROR_INVALID_ENVIRONMENT);
    bad = env; bad.rotation[0] = 2.0f; bad.rotation[4] = 1.0f; bad.rotation[8] = 1.0f; TE_BAD(HD_ERROR_INVALID_ENVIRONMENT);
    bad = env; bad.rotation[0] = -1.0f; bad.rotation[4] = 1.0f; bad.rotation[8] = 1.0f; TE_BAD(HD_ERROR_INVALID_ENVIRONMENT);
    bad = env; bad.intensity = 2.0f * HD_MAX_LIGHT_POWER; TE_BAD(HD_ERROR_INVALID_LIGHT);
    CHECK(hd_get_stats(ctx, &st) == HD_SUCCESS);
    CHECK(st.illumination_channels == 1); /* nothing changed */
    /* with none set, count 0 is no light at all; with one, the environment alone */
    errors = log.errors;
    CHECK(hd_set_lights(ctx, NULL, 0) == HD_ERROR_NO_LIGHTS && log.errors == errors + 1);
    CHECK(hd_set_environment(ctx, &env) == HD_SUCCESS);
    CHECK(hd_set_lights(ctx, NULL, 0) == HD_SUCCESS);
    errors = log.errors;
    CHECK(hd_set_environment(ctx, NULL) == HD_ERROR_NO_LIGHTS && log.errors == errors + 1);
    {
        hd_params p = d.params;
        p.method = HD_METHOD_CD;
        errors = log.errors;
        CHECK(hd_set_params(ctx, &p) == HD_ERROR_UNSUPPORTED && log.errors == errors + 1);
    }
    CHECK(hd_refine(ctx, 2) == HD_SUCCESS);
    hd_destroy(ctx);
    /* CD refuses an environment */
    d.params.method = HD_METHOD_CD;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    bad = env; TE_BAD(HD_ERROR_UNSUPPORTED);
    hd_destroy(ctx);
#undef TE_BAD
}

/* params.environment_background on an empty volume: every camera ray leaves with T = 1 and shows
   the map's texel in its direction (turned 30 degrees about +y, times the intensity) over
   params.background, alpha 1; HD's projection and PT_MS's primary rays alike. The camera's
   field (2 degrees) stays inside one texel of a 15 x 7 map whose texels all differ. Off, or
   without a map, the pixels are the background with alpha 0. */
static void test_env_background(void)
{
    static const float clear[8] = {0.0f, 0.0f, 0.0f, 0.0f, 1.0f, 1.0f, 1.0f, 1.0f};
    static float rgb[15 * 7 * 3], img[8 * 8 * 4];
    const int w = 15, h = 7;
    const double ang = TE_PI / 6.0, bg[3] = {0.01, 0.02, 0.03};
    hd_environment env = HD_ENVIRONMENT_INIT;
    hd_desc d;
    hd_context ctx;
    int i, j, k, m, ti = -1, tj = -1;
    for (j = 0; j < h; ++j)
        for (i = 0; i < w; ++i) {
            float *px = rgb + 3 * (j * w + i);
            px[0] = 0.1f + (float)i; px[1] = 0.2f + (float)j; px[2] = 0.3f + (float)(i * j);
        }
    env.width = w; env.height = h; env.rgb = rgb; env.intensity = 0.5f;
    env.rotation[0] = (float)cos(ang); env.rotation[2] = (float)sin(ang); env.rotation[4] = 1.0f;
    env.rotation[6] = -(float)sin(ang); env.rotation[8] = (float)cos(ang);
    /* the texel of the camera's central ray and of its corners' (world -z, -+0.0175 x and y):
       the map direction is R^T times the world's */
    for (k = 0; k < 5; ++k) {
        double wd[3] = {k == 0 ? 0.0 : (k & 1 ? 0.0175 : -0.0175), k == 0 ? 0.0 : (k & 2 ? 0.0175 : -0.0175), -1.0}, md[3], n, th, ph;
        n = sqrt(wd[0] * wd[0] + wd[1] * wd[1] + wd[2] * wd[2]);
        for (m = 0; m < 3; ++m) md[m] = (env.rotation[m] * wd[0] + env.rotation[3 + m] * wd[1] + env.rotation[6 + m] * wd[2]) / n;
        th = acos(md[1]);
        ph = atan2(md[2], md[0]);
        if (ph < 0.0) ph += 2.0 * TE_PI;
        i = (int)(ph / (2.0 * TE_PI) * w);
        j = (int)(th / TE_PI * h);
        if (k == 0) { ti = i; tj = j; }
        CHECK(i == ti && j == tj);
    }
    CHECK(ti == 12 && tj == 3);
    for (i = 0; i < 16 * 16 * 16; ++i) te_vol[i] = 0;
    for (k = 0; k < 4; ++k) {
        /* k: 0 HD, 1 PT_MS, 2 HD without the map, 3 HD with the map and the parameter off */
        te_desc(&d, 8, 8, 8, 4.0f);
        for (i = 0; i < 8 * 8 * 8; ++i) te_vol[i] = 0;
        d.transfer_function.rgba = clear;
        d.params.method = k == 1 ? HD_METHOD_PT_MS : HD_METHOD_HD;
        d.params.environment_background = k == 3 ? 0 : 1;
        for (m = 0; m < 3; ++m) d.params.background[m] = (float)bg[m];
        d.camera.fov_y = 2.0f;
        CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
        if (k != 2) CHECK(hd_set_environment(ctx, &env) == HD_SUCCESS);
        CHECK(hd_iterate(ctx, 3) == HD_SUCCESS);
        CHECK(hd_read_image_f32(ctx, img, 8 * 8 * 4) == HD_SUCCESS);
        for (i = 0; i < 64; ++i) {
            const float *tx = rgb + 3 * (tj * w + ti);
            int shown = k < 2;
            for (m = 0; m < 3; ++m) {
                double want = bg[m] + (shown ? 0.5 * (double)tx[m] : 0.0);
                CHECK_MSG(fabs((double)img[4 * i + m] - want) <= 1e-5 * want, "case %d pixel %d channel %d: %g, want %g", k, i, m,
                          (double)img[4 * i + m], want);
            }
            CHECK_MSG(img[4 * i + 3] == (shown ? 1.0f : 0.0f), "case %d pixel %d alpha %g", k, i, (double)img[4 * i + 3]);
        }
        if (k == 0) printf("  background: pixel 0 (%.4f, %.4f, %.4f, %.1f), texel (%d, %d) * 0.5 + background\n", (double)img[0],
                           (double)img[1], (double)img[2], (double)img[3], ti, tj);
        hd_destroy(ctx);
    }
}

const hd_test_case hd_tests_environment[] = {
    {"env_uniform_slab_matches_exact", test_env_uniform_slab},
    {"env_importance_matches_quadrature", test_env_importance_matches_quadrature},
    {"env_sun_matches_directional", test_env_sun_matches_directional},
    {"env_pt_ms_equilibrium", test_env_pt_ms_equilibrium},
    {"env_method_bytes", test_env_method_bytes},
    {"env_bad_input", test_env_bad_input},
    {"env_background", test_env_background},
};
const int hd_tests_environment_count = (int)(sizeof hd_tests_environment / sizeof hd_tests_environment[0]);
