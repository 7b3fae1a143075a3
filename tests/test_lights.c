/* test_lights.c - area lights (quad, disk, sphere) and the light choice by estimated light, on the
   CPU backend through the public API: HD's direct light E from each shape against the exact
   integral of L * T * cos / r^2 over its surface (quadrature on the host, exact T for a
   homogeneous box; a wrong pdf or a missing cosine fails it); a disk and a quad of the same
   area and radiance at a distant voxel; a small quad and a small sphere far away against the
   point light of the same intensity (same brightness, the shadow of an off-centre blob on the
   same side); one-sidedness; the choice of the light by estimate against the uniform choice
   (the same mean, less noise); bad input.

   Statistical checks: the voxels' deviations are independent (each its own random stream), so
   their mean passes when within 4 standard errors of 0; the seeds are fixed. */
#include "hybriddiff.h"
#include "hd_test.h"

hd_result hdt_light_uniform(hd_context h, int on);

#define TL_PI 3.14159265358979323846
static uint8_t tl_vol[16 * 16 * 16];
static const float tl_tf_flat[8] = {0.8f, 0.8f, 0.8f, 1.0f, 0.8f, 0.8f, 0.8f, 1.0f};
static const float tl_tf_ramp[8] = {0.8f, 0.8f, 0.8f, 0.0f, 0.8f, 0.8f, 0.8f, 1.0f}; /* value 0: empty */

/* A box of n^3 voxels of value v, HD without diffusion (E is the direct light alone), one
   illumination voxel per voxel; v = 0: the ramp TF (the extinction follows the value, 0 is empty),
   else the flat one (homogeneous). */
static void tl_desc(hd_desc *d, int n, uint8_t v, float extinction)
{
    memset(tl_vol, v, sizeof tl_vol);
    memset(d, 0, sizeof *d);
    d->params.illumination_downsample = 1;
    d->params.disable_diffusion = 1;
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = n;
    d->volume.data = tl_vol;
    d->transfer_function.rgba = v == 0 ? tl_tf_ramp : tl_tf_flat;
    d->transfer_function.count = 2;
    d->camera.width = d->camera.height = 8;
    d->params.method = HD_METHOD_HD;
    d->params.extinction = extinction;
    d->threads = 2;
}

/* Distance from p inside the cube of half side 0.5 along unit w to its edge. */
static double tl_exit(const double p[3], const double w[3])
{
    double t = 1e300;
    int a;
    for (a = 0; a < 3; ++a) {
        if (w[a] > 1e-12) { double s = (0.5 - p[a]) / w[a]; if (s < t) t = s; }
        if (w[a] < -1e-12) { double s = (-0.5 - p[a]) / w[a]; if (s < t) t = s; }
    }
    return t;
}

/* One surface element at q with unit normal n and area da, seen from p: its L = 1 light
   L * T * cos / r^2 in a homogeneous cube of extinction sigma (0 from the element's back). */
static double tl_element(const double p[3], const double q[3], const double n[3], double da, double sigma)
{
    double v[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]}, r2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2], r = sqrt(r2), w[3], cl, t;
    int a;
    for (a = 0; a < 3; ++a) w[a] = v[a] / r;
    cl = -(n[0] * w[0] + n[1] * w[1] + n[2] * w[2]);
    if (cl <= 0.0) return 0.0;
    t = tl_exit(p, w);
    return exp(-sigma * (t < r ? t : r)) * cl * da / r2;
}

/* The exact E at p of light l (radiance 1) by an s x s midpoint quadrature over its surface. */
static double tl_exact(const hd_light *l, const double p[3], double sigma, int s)
{
    double sum = 0.0;
    int i, j;
    if (l->type == HD_LIGHT_QUAD) {
        const float *e1 = l->edge1, *e2 = l->edge2;
        double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double area = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (i = 0; i < 3; ++i) n[i] /= area;
        for (j = 0; j < s; ++j)
            for (i = 0; i < s; ++i) {
                double u = (i + 0.5) / s, v = (j + 0.5) / s, q[3];
                int a;
                for (a = 0; a < 3; ++a) q[a] = l->position[a] + u * e1[a] + v * e2[a];
                sum += tl_element(p, q, n, area / (s * s), sigma);
            }
    } else if (l->type == HD_LIGHT_DISK) {
        double n[3], t1[3], t2[3], len;
        int a;
        len = sqrt((double)l->direction[0] * l->direction[0] + (double)l->direction[1] * l->direction[1] +
                   (double)l->direction[2] * l->direction[2]);
        for (a = 0; a < 3; ++a) n[a] = l->direction[a] / len;
        if (fabs(n[0]) < 0.6) { t1[0] = 0.0; t1[1] = n[2]; t1[2] = -n[1]; }
        else { t1[0] = -n[2]; t1[1] = 0.0; t1[2] = n[0]; }
        len = sqrt(t1[0] * t1[0] + t1[1] * t1[1] + t1[2] * t1[2]);
        for (a = 0; a < 3; ++a) t1[a] /= len;
        t2[0] = n[1] * t1[2] - n[2] * t1[1]; t2[1] = n[2] * t1[0] - n[0] * t1[2]; t2[2] = n[0] * t1[1] - n[1] * t1[0];
        for (j = 0; j < s; ++j) /* rings of equal width, s angles each */
            for (i = 0; i < s; ++i) {
                double r0 = l->radius * j / s, r1 = l->radius * (j + 1.0) / s, rm = 0.5 * (r0 + r1), ph = 2.0 * TL_PI * (i + 0.5) / s, q[3];
                for (a = 0; a < 3; ++a) q[a] = l->position[a] + rm * (cos(ph) * t1[a] + sin(ph) * t2[a]);
                sum += tl_element(p, q, n, TL_PI * (r1 * r1 - r0 * r0) / s, sigma);
            }
    } else { /* sphere: uniform in (cos theta, phi), area R^2 dcos dphi */
        double R = l->radius;
        for (j = 0; j < s; ++j)
            for (i = 0; i < s; ++i) {
                double ct = -1.0 + 2.0 * (j + 0.5) / s, st = sqrt(1.0 - ct * ct), ph = 2.0 * TL_PI * (i + 0.5) / s;
                double n[3] = {st * cos(ph), ct, st * sin(ph)}, q[3];
                int a;
                for (a = 0; a < 3; ++a) q[a] = l->position[a] + R * n[a];
                /* outward normal: the far side faces away (cos <= 0) and adds nothing */
                sum += tl_element(p, q, n, R * R * (2.0 / s) * (2.0 * TL_PI / s), sigma);
            }
    }
    return sum;
}

/* HD's E after n iterations of light l alone (radiance 1) in a homogeneous 16^3 cube of
   extinction sigma against tl_exact at a lattice of voxels; checks the mean deviation within
   4 standard errors; returns the mean relative deviation. */
static double tl_check_exact(const char *what, const hd_light *l, double sigma, int n, int s)
{
    static float e[16 * 16 * 16];
    hd_desc d;
    hd_context ctx;
    double sum = 0.0, sum2 = 0.0, ref_sum = 0.0;
    int x, y, z, count = 0;
    tl_desc(&d, 16, 255, (float)sigma);
    d.lights = l; d.light_count = 1;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, n) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, 16 * 16 * 16) == HD_SUCCESS);
    hd_destroy(ctx);
    for (z = 1; z < 16; z += 5)
        for (y = 1; y < 16; y += 3)
            for (x = 1; x < 16; x += 3) {
                double p[3] = {(x + 0.5) / 16 - 0.5, (y + 0.5) / 16 - 0.5, (z + 0.5) / 16 - 0.5};
                double ref = tl_exact(l, p, sigma, s), v = e[(z * 16 + y) * 16 + x] - ref;
                sum += v; sum2 += v * v; ref_sum += ref; ++count;
            }
    {
        double mean = sum / count, sd = sqrt((sum2 / count - mean * mean) * count / (count - 1.0)), se = sd / sqrt((double)count);
        printf("  %s: E - exact: mean %.4g (se %.2g), relative %.4f, mean exact %.4g, %d voxels\n", what, mean, se,
               mean / (ref_sum / count), ref_sum / count, count);
        CHECK(fabs(mean) < 4.0 * se + 1e-6 * ref_sum / count);
        return fabs(mean) / (ref_sum / count);
    }
}

/* Each shape near the box (a wide cone, T varying across it) in a homogeneous medium. */
static void test_area_shapes_match_exact(void)
{
    hd_light q = HD_LIGHT_INIT, k = HD_LIGHT_INIT, s = HD_LIGHT_INIT;
    /* a tilted quad above the box, emitting down */
    q.type = HD_LIGHT_QUAD;
    q.position[0] = -0.4f; q.position[1] = 0.7f; q.position[2] = -0.3f;
    q.edge1[0] = 0.8f; q.edge1[1] = 0.1f;
    q.edge2[1] = 0.15f; q.edge2[2] = 0.6f;
    CHECK(tl_check_exact("quad above, tilted", &q, 1.0, 1024, 48) < 0.01);
    /* a disk beside the box along +x, facing it and a little down */
    k.type = HD_LIGHT_DISK;
    k.position[0] = 0.8f; k.position[1] = 0.2f;
    k.direction[0] = -1.0f; k.direction[1] = -0.3f;
    k.radius = 0.35f;
    CHECK(tl_check_exact("disk beside", &k, 1.0, 1024, 48) < 0.01);
    /* a sphere near a corner */
    s.type = HD_LIGHT_SPHERE;
    s.position[0] = 0.6f; s.position[1] = -0.7f; s.position[2] = 0.5f;
    s.radius = 0.3f;
    CHECK(tl_check_exact("sphere near a corner", &s, 1.0, 1024, 96) < 0.01);
}

/* The emitting side: the quad with its edges swapped (normal away from the box) and a disk
   with its normal away give no light at all; a point inside a sphere gets none. */
static void test_area_one_sided(void)
{
    static float e[16 * 16 * 16];
    hd_light l = HD_LIGHT_INIT;
    hd_desc d;
    hd_context ctx;
    double sum = 0.0, inside = 0.0;
    int i;
    tl_desc(&d, 8, 255, 1.0f);
    l.type = HD_LIGHT_QUAD;
    l.position[0] = -0.3f; l.position[1] = 0.7f; l.position[2] = -0.3f;
    l.edge1[2] = 0.6f; l.edge2[0] = 0.6f; /* edge1 x edge2 = +y: up, away from the box */
    d.lights = &l; d.light_count = 1;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 8) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, 512) == HD_SUCCESS);
    for (i = 0; i < 512; ++i) sum += e[i];
    CHECK(sum == 0.0);
    l.edge1[2] = 0.0f; l.edge1[0] = 0.6f; l.edge2[0] = 0.0f; l.edge2[2] = 0.6f; /* now down */
    CHECK(hd_set_lights(ctx, &l, 1) == HD_SUCCESS && hd_reset(ctx) == HD_SUCCESS && hd_refine(ctx, 8) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, 512) == HD_SUCCESS);
    for (i = 0, sum = 0.0; i < 512; ++i) sum += e[i];
    CHECK(sum > 0.0);
    memset(&l, 0, sizeof l);
    l.type = HD_LIGHT_DISK; l.position[1] = 0.7f; l.direction[1] = 1.0f; l.radius = 0.3f;
    CHECK(hd_set_lights(ctx, &l, 1) == HD_SUCCESS && hd_reset(ctx) == HD_SUCCESS && hd_refine(ctx, 8) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, 512) == HD_SUCCESS);
    for (i = 0, sum = 0.0; i < 512; ++i) sum += e[i];
    CHECK(sum == 0.0);
    memset(&l, 0, sizeof l);
    l.type = HD_LIGHT_SPHERE; l.radius = 0.3f; /* around the box's centre */
    CHECK(hd_set_lights(ctx, &l, 1) == HD_SUCCESS && hd_reset(ctx) == HD_SUCCESS && hd_refine(ctx, 8) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, 512) == HD_SUCCESS);
    for (i = 0, sum = 0.0; i < 512; ++i) {
        int x = i % 8, y = i / 8 % 8, z = i / 64;
        double px = (x + 0.5) / 8 - 0.5, py = (y + 0.5) / 8 - 0.5, pz = (z + 0.5) / 8 - 0.5;
        if (px * px + py * py + pz * pz < 0.3 * 0.3) inside += e[i];
        else sum += e[i];
    }
    printf("  one-sided: E inside the sphere %.3g, outside %.3g\n", inside, sum);
    CHECK(inside == 0.0 && sum > 0.0);
    hd_destroy(ctx);
}

/* A disk and a square quad of the same area, centre, normal and radiance, far from a voxel:
   the same E there (their solid angles differ by O((size / distance)^4)), in almost empty space. */
static void test_area_disk_equals_quad(void)
{
    static float e1[16 * 16 * 16], e2[16 * 16 * 16];
    hd_light q = HD_LIGHT_INIT, k = HD_LIGHT_INIT;
    hd_desc d;
    hd_context ctx;
    double R = 0.1, a = R * sqrt(TL_PI), m1 = 0.0, m2 = 0.0, exact;
    int i, n = 0;
    tl_desc(&d, 16, 255, 1e-3f); /* T = 1 within 0.2 % */
    k.type = HD_LIGHT_DISK; k.position[1] = 3.0f; k.direction[1] = -1.0f; k.radius = (float)R; k.intensity = 5.0f;
    q.type = HD_LIGHT_QUAD; q.intensity = 5.0f;
    q.position[0] = (float)(-a / 2); q.position[1] = 3.0f; q.position[2] = (float)(-a / 2);
    q.edge1[0] = (float)a; q.edge2[2] = (float)a; /* edge1 x edge2 = -y */
    d.lights = &k; d.light_count = 1;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_refine(ctx, 64) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e1, 4096) == HD_SUCCESS);
    CHECK(hd_set_lights(ctx, &q, 1) == HD_SUCCESS && hd_reset(ctx) == HD_SUCCESS && hd_refine(ctx, 64) == HD_SUCCESS);
    CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e2, 4096) == HD_SUCCESS);
    hd_destroy(ctx);
    for (i = 0; i < 4096; ++i) {
        int x = i % 16, y = i / 16 % 16, z = i / 256;
        if (y != 0 || (x != 7 && x != 8) || (z != 7 && z != 8)) continue; /* the farthest, on the axis, 3.47 away */
        m1 += e1[i]; m2 += e2[i]; ++n;
    }
    m1 /= n; m2 /= n;
    /* on the axis at distance D: the disk's 2 pi (1 - D / sqrt(D^2 + R^2)) */
    exact = 5.0 * 2.0 * TL_PI * (1.0 - (3.0 + 0.5 - 0.5 / 16) / sqrt(pow(3.0 + 0.5 - 0.5 / 16, 2) + R * R));
    printf("  disk vs quad of the same area at 3.47: E %.6g vs %.6g (relative %.2e), on-axis disk exact %.6g\n", m1, m2,
           fabs(m1 - m2) / m2, exact);
    CHECK(fabs(m1 - m2) < 2e-3 * m2);
    CHECK(fabs(m1 - exact) < 0.01 * exact);
}

/* A small quad (and a small sphere) far away against the point light of the same intensity
   (L A, or L pi R^2) with 1/r^2 at its centre: the same E over an off-centre blob (shadow side
   and brightness); the point light on the mirrored side gives another E. */
static void tl_blob(void)
{
    int x, y, z;
    for (z = 0; z < 16; ++z)
        for (y = 0; y < 16; ++y)
            for (x = 0; x < 16; ++x) {
                double dx = (x + 0.5) / 16 - 0.35, dy = (y + 0.5) / 16 - 0.5, dz = (z + 0.5) / 16 - 0.5;
                tl_vol[(z * 16 + y) * 16 + x] = (uint8_t)(255.0 * exp(-(dx * dx + dy * dy + dz * dz) / (2.0 * 0.12 * 0.12)) + 0.5);
            }
}
static void test_area_far_matches_point(void)
{
    static float ea[4096], ep[4096], em[4096];
    hd_light q = HD_LIGHT_INIT, p = HD_LIGHT_INIT, s = HD_LIGHT_INIT;
    hd_desc d;
    hd_context ctx;
    double side = 0.05, num = 0.0, numm = 0.0, nums = 0.0, den = 0.0;
    int i, pass;
    tl_desc(&d, 16, 0, 12.0f);
    tl_blob();
    /* a quad 6 away along -x (the blob's side), facing +x: edge1 x edge2 = +x */
    q.type = HD_LIGHT_QUAD; q.intensity = 2000.0f;
    q.position[0] = -6.0f; q.position[1] = (float)(0.1 - side / 2); q.position[2] = (float)(-side / 2);
    q.edge1[1] = (float)side; q.edge2[2] = (float)side;
    p.type = HD_LIGHT_POINT; p.inverse_square = 1; p.intensity = (float)(2000.0 * side * side);
    p.position[0] = -6.0f; p.position[1] = 0.1f;
    s.type = HD_LIGHT_SPHERE; s.intensity = 2000.0f; s.radius = (float)(side / sqrt(TL_PI)); /* the same pi R^2 */
    s.position[0] = -6.0f; s.position[1] = 0.1f;
    d.lights = &q; d.light_count = 1;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    for (pass = 0; pass < 4; ++pass) {
        float *dst = pass == 0 ? ea : pass == 1 ? ep : pass == 2 ? em : ea;
        if (pass == 1) CHECK(hd_set_lights(ctx, &p, 1) == HD_SUCCESS);
        if (pass == 2) { p.position[0] = 6.0f; CHECK(hd_set_lights(ctx, &p, 1) == HD_SUCCESS); }
        if (pass == 3) {
            for (i = 0; i < 4096; ++i) { num += fabs((double)ea[i] - ep[i]); numm += fabs((double)em[i] - ep[i]); den += ep[i]; }
            CHECK(hd_set_lights(ctx, &s, 1) == HD_SUCCESS);
        }
        CHECK(hd_reset(ctx) == HD_SUCCESS);
        CHECK(hd_refine(ctx, 32) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, dst, 4096) == HD_SUCCESS);
    }
    hd_destroy(ctx);
    for (i = 0; i < 4096; ++i) nums += fabs((double)ea[i] - ep[i]);
    printf("  far small quad vs point light: relative L1 %.4f, sphere %.4f (point light mirrored: %.4f)\n", num / den, nums / den,
           numm / den);
    CHECK(num / den < 0.03 && nums / den < 0.03 && numm / den > 0.3);
}

/* One strong and one weak light: choosing by the estimate keeps the mean and lowers the
   spread of the per-iteration estimates of E against the uniform choice. */
static double tl_spread(hd_context ctx, int uniform, double *mean)
{
    static float e[8 * 8 * 8], prev[8 * 8 * 8];
    static double s1[8 * 8 * 8], s2[8 * 8 * 8];
    double var = 0.0, m = 0.0;
    int it, i, n = 64, vox = 512;
    CHECK(hdt_light_uniform(ctx, uniform) == HD_SUCCESS);
    CHECK(hd_reset(ctx) == HD_SUCCESS);
    memset(prev, 0, sizeof prev);
    memset(s1, 0, sizeof s1);
    memset(s2, 0, sizeof s2);
    for (it = 1; it <= n; ++it) { /* one sample per iteration: X_n = n E_n - (n - 1) E_{n-1} */
        CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, vox) == HD_SUCCESS);
        for (i = 0; i < vox; ++i) {
            double x = it * (double)e[i] - (it - 1.0) * prev[i];
            s1[i] += x; s2[i] += x * x;
        }
        memcpy(prev, e, sizeof e);
    }
    for (i = 0; i < vox; ++i) { /* each voxel's variance about its own mean */
        m += s1[i] / n / vox;
        var += (s2[i] / n - (s1[i] / n) * (s1[i] / n)) / vox;
    }
    *mean = m;
    return sqrt(var);
}
static void test_light_choice_by_estimate(void)
{
    hd_light l[2];
    hd_desc d;
    hd_context ctx;
    double su, sp, mu, mp;
    memset(l, 0, sizeof l);
    l[0].type = HD_LIGHT_DIRECTIONAL; l[0].direction[1] = -1.0f; l[0].intensity = 10.0f;
    l[1].type = HD_LIGHT_DIRECTIONAL; l[1].direction[0] = 1.0f; l[1].intensity = 0.1f;
    tl_desc(&d, 8, 128, 0.3f); /* thin: the transmittance's own noise stays small */
    d.lights = l; d.light_count = 2;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    su = tl_spread(ctx, 1, &mu);
    sp = tl_spread(ctx, 0, &mp);
    hd_destroy(ctx);
    printf("  strong + weak light: per-sample spread of E uniform %.4g, by estimate %.4g (%.2fx); mean E %.4g vs %.4g\n", su, sp,
           su / sp, mu, mp);
    CHECK(sp < 0.5 * su);
    /* runs of 8 voxels share their light: 64 x 64 independent choices */
    CHECK(fabs(mu - mp) < 4.0 * su / 64.0 + 1e-3 * mu);
}

/* Degenerate area lights: HD_ERROR_INVALID_LIGHT and one logged line each; nothing changes and
   the context keeps working. CD cannot hold an area light. */
static void test_area_bad_input(void)
{
    hd_test_log log;
    hd_light ok = HD_LIGHT_INIT, bad;
    hd_desc d;
    hd_context ctx;
    hd_params p;
    int errors;
    float zero = 0.0f;
    ok.type = HD_LIGHT_QUAD; ok.position[1] = 0.8f; ok.edge1[0] = 0.3f; ok.edge2[2] = 0.3f;
    tl_desc(&d, 4, 255, 1.0f);
    d.logger = hd_test_logger(&log);
    d.lights = &ok; d.light_count = 1;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
#define TL_BAD(code, text) \
    do { \
        errors = log.errors; \
        CHECK(hd_set_lights(ctx, &bad, 1) == (code)); \
        CHECK(log.errors == errors + 1 && log.last_code == (code)); \
        CHECK_MSG(strstr(log.last, text) != NULL, "%s", log.last); \
    } while (0)
    bad = ok; bad.edge1[0] = 0.0f; TL_BAD(HD_ERROR_INVALID_LIGHT, "zero edge");
    bad = ok; bad.edge2[0] = 0.6f; bad.edge2[2] = 0.0f; TL_BAD(HD_ERROR_INVALID_LIGHT, "parallel");
    bad = ok; bad.edge1[1] = zero / zero; TL_BAD(HD_ERROR_INVALID_LIGHT, "NaN");
    bad = ok; bad.edge2[1] = 1.0f / zero; TL_BAD(HD_ERROR_INVALID_LIGHT, "NaN");
    bad = ok; bad.edge1[0] = 2.0f * HD_MAX_LIGHT_DISTANCE; TL_BAD(HD_ERROR_INVALID_LIGHT, "beyond");
    bad = ok; bad.intensity = -1.0f; TL_BAD(HD_ERROR_INVALID_LIGHT, "negative");
    bad = ok; bad.position[0] = 1e30f; TL_BAD(HD_ERROR_INVALID_LIGHT, "beyond");
    memset(&bad, 0, sizeof bad);
    bad.type = HD_LIGHT_DISK; bad.direction[1] = -1.0f; TL_BAD(HD_ERROR_INVALID_LIGHT, "radius");
    bad.radius = -0.5f; TL_BAD(HD_ERROR_INVALID_LIGHT, "radius");
    bad.radius = zero / zero; TL_BAD(HD_ERROR_INVALID_LIGHT, "NaN");
    bad.radius = 0.2f; bad.direction[1] = 0.0f; TL_BAD(HD_ERROR_INVALID_LIGHT, "zero normal");
    memset(&bad, 0, sizeof bad);
    bad.type = HD_LIGHT_SPHERE; TL_BAD(HD_ERROR_INVALID_LIGHT, "radius");
    bad.radius = 2.0f * HD_MAX_LIGHT_DISTANCE; TL_BAD(HD_ERROR_INVALID_LIGHT, "radius");
    /* nothing changed: the quad still lights the box */
    CHECK(hd_refine(ctx, 2) == HD_SUCCESS);
    p = d.params;
    p.method = HD_METHOD_CD;
    errors = log.errors;
    CHECK(hd_set_params(ctx, &p) == HD_ERROR_UNSUPPORTED && log.errors == errors + 1);
    hd_destroy(ctx);
    d.params.method = HD_METHOD_CD;
    errors = log.errors;
    CHECK(hd_create(&d, &ctx) == HD_ERROR_UNSUPPORTED && log.errors == errors + 1);
    d.lights = NULL; d.light_count = 0;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    bad = ok; errors = log.errors;
    CHECK(hd_set_lights(ctx, &bad, 1) == HD_ERROR_UNSUPPORTED && log.errors == errors + 1);
    CHECK(hd_refine(ctx, 1) == HD_SUCCESS);
    hd_destroy(ctx);
#undef TL_BAD
}

const hd_test_case hd_tests_lights[] = {
    {"area_shapes_match_exact", test_area_shapes_match_exact},
    {"area_one_sided", test_area_one_sided},
    {"area_disk_equals_quad", test_area_disk_equals_quad},
    {"area_far_matches_point", test_area_far_matches_point},
    {"light_choice_by_estimate", test_light_choice_by_estimate},
    {"area_bad_input", test_area_bad_input},
};
const int hd_tests_lights_count = (int)(sizeof hd_tests_lights / sizeof hd_tests_lights[0]);
