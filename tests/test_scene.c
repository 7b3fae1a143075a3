/* test_scene.c - the volume inside a host's scene, on the CPU backend: a camera given by view and
   projection matrices (GL, zero-to-one, reversed-Z, left-handed, off-centre, orthographic), a
   volume placed by a transform (lengths in world units), the host's depth buffer (what stands in
   front hides the volume, what stands inside cuts it), and the bad inputs of each. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <stdlib.h>

#define N 32
#define W 48
#define H 40
static const float tf_blob[12] = {0, 0, 0, 0, 0.9f, 0.7f, 0.5f, 0.3f, 1, 1, 1, 1};
static const float tf_flat[8] = {0, 0, 0, 0, 1, 1, 1, 1};

/* ---- matrices (double, column-major: element row r, column c at [c * 4 + r]) ---------------- */
typedef struct mat4 { double m[16]; } mat4;
#define M4(a, r, c) ((a).m[(c) * 4 + (r)])

static mat4 m4_zero(void) { mat4 a; memset(&a, 0, sizeof a); return a; }
static mat4 m4_identity(void)
{
    mat4 a = m4_zero();
    M4(a, 0, 0) = M4(a, 1, 1) = M4(a, 2, 2) = M4(a, 3, 3) = 1.0;
    return a;
}
static mat4 m4_mul(mat4 a, mat4 b)
{
    mat4 c = m4_zero();
    int r, k, j;
    for (j = 0; j < 4; ++j)
        for (r = 0; r < 4; ++r)
            for (k = 0; k < 4; ++k) M4(c, r, j) += M4(a, r, k) * M4(b, k, j);
    return c;
}
static void m4_store(mat4 a, float out[16])
{
    int i;
    for (i = 0; i < 16; ++i) out[i] = (float)a.m[i];
}
static void v3_norm(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    v[0] /= n; v[1] /= n; v[2] /= n;
}
static void v3_cross(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}
/* gluLookAt / glm::lookAt (right-handed: the camera looks down -z in eye space) */
static mat4 m4_lookat(const float eye[3], const float target[3], const float up[3])
{
    double f[3], s[3], u[3], e[3], upd[3];
    mat4 a = m4_identity();
    int i;
    for (i = 0; i < 3; ++i) { f[i] = (double)target[i] - eye[i]; e[i] = eye[i]; upd[i] = up[i]; }
    v3_norm(f);
    v3_cross(f, upd, s);
    v3_norm(s);
    v3_cross(s, f, u);
    for (i = 0; i < 3; ++i) { M4(a, 0, i) = s[i]; M4(a, 1, i) = u[i]; M4(a, 2, i) = -f[i]; }
    M4(a, 0, 3) = -(s[0] * e[0] + s[1] * e[1] + s[2] * e[2]);
    M4(a, 1, 3) = -(u[0] * e[0] + u[1] * e[1] + u[2] * e[2]);
    M4(a, 2, 3) = f[0] * e[0] + f[1] * e[1] + f[2] * e[2];
    return a;
}
/* glFrustum, with the depth row of each convention (right-handed eye space) */
static mat4 m4_frustum(double l, double r, double b, double t, double n, double f, hd_depth_range range)
{
    mat4 a = m4_zero();
    M4(a, 0, 0) = 2 * n / (r - l); M4(a, 0, 2) = (r + l) / (r - l);
    M4(a, 1, 1) = 2 * n / (t - b); M4(a, 1, 2) = (t + b) / (t - b);
    M4(a, 3, 2) = -1.0;
    if (range == HD_DEPTH_NEG_ONE_TO_ONE) { M4(a, 2, 2) = -(f + n) / (f - n); M4(a, 2, 3) = -2 * f * n / (f - n); }
    else if (range == HD_DEPTH_ZERO_TO_ONE) { M4(a, 2, 2) = f / (n - f); M4(a, 2, 3) = f * n / (n - f); }
    else { M4(a, 2, 2) = 0.0; M4(a, 2, 3) = n; } /* reversed-Z, infinite far plane */
    return a;
}
static mat4 m4_perspective(double fovy_deg, double aspect, double n, double f, hd_depth_range range)
{
    double t = n * tan(0.5 * fovy_deg * 3.14159265358979 / 180.0);
    return m4_frustum(-t * aspect, t * aspect, -t, t, n, f, range);
}
static mat4 m4_ortho(double l, double r, double b, double t, double n, double f)
{
    mat4 a = m4_identity();
    M4(a, 0, 0) = 2 / (r - l); M4(a, 0, 3) = -(r + l) / (r - l);
    M4(a, 1, 1) = 2 / (t - b); M4(a, 1, 3) = -(t + b) / (t - b);
    M4(a, 2, 2) = -2 / (f - n); M4(a, 2, 3) = -(f + n) / (f - n);
    return a;
}
/* the window depth of world point p under projection * view pv */
static float window_depth(mat4 pv, const double p[3], hd_depth_range range)
{
    double z = M4(pv, 2, 0) * p[0] + M4(pv, 2, 1) * p[1] + M4(pv, 2, 2) * p[2] + M4(pv, 2, 3);
    double w = M4(pv, 3, 0) * p[0] + M4(pv, 3, 1) * p[1] + M4(pv, 3, 2) * p[2] + M4(pv, 3, 3);
    double ndc = z / w;
    return (float)(range == HD_DEPTH_NEG_ONE_TO_ONE ? 0.5 * (ndc + 1.0) : ndc);
}

/* ---- scenes ------------------------------------------------------------------------------------ */
static uint8_t vox_blob[N * N * N], vox_full[N * N * N];
static void make_volumes(void)
{
    int x, y, z;
    for (z = 0; z < N; ++z)
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                float u = (x + 0.5f) / N - 0.5f, v = (y + 0.5f) / N - 0.45f, w = (z + 0.5f) / N - 0.5f;
                float r2 = u * u + v * v + w * w, val = 255.0f * expf(-9.0f * r2) + (float)((x * 7 + y * 3 + z) % 23);
                vox_blob[(z * N + y) * N + x] = (uint8_t)(val > 255.0f ? 255.0f : val);
                vox_full[(z * N + y) * N + x] = 255;
            }
}

static hd_light g_lights[2];
static hd_desc scene_desc(const uint8_t *vox, const float *tf, int tf_count)
{
    hd_desc d = HD_DESC_INIT;
    memset(g_lights, 0, sizeof g_lights);
    g_lights[0].direction[0] = 0.4f; g_lights[0].direction[1] = -1.0f; g_lights[0].direction[2] = -0.3f;
    g_lights[1].type = HD_LIGHT_POINT; g_lights[1].position[0] = 0.9f; g_lights[1].position[1] = 0.6f; g_lights[1].position[2] = 0.8f;
    g_lights[1].inverse_square = 1; g_lights[1].intensity = 1.5f; g_lights[1].color[0] = 1.0f; g_lights[1].color[1] = 0.8f;
    g_lights[1].color[2] = 0.5f;
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = N;
    d.volume.spacing[0] = 1.0f; d.volume.spacing[1] = 1.0f; d.volume.spacing[2] = 1.25f;
    d.volume.data = vox;
    d.transfer_function.rgba = tf;
    d.transfer_function.count = tf_count;
    d.lights = g_lights;
    d.light_count = 2;
    d.camera.eye[0] = 1.2f; d.camera.eye[1] = 0.8f; d.camera.eye[2] = 1.9f;
    d.camera.width = W; d.camera.height = H;
    d.params.seed = 99u;
    d.params.extinction = 30.0f;
    return d;
}

/* The look-at camera of d as matrices under a depth convention. */
static void camera_matrices(hd_camera *c, hd_depth_range range, mat4 *pv_out)
{
    float up[3] = {0.0f, 1.0f, 0.0f}, zero[3] = {0.0f, 0.0f, 0.0f};
    mat4 v = m4_lookat(c->eye, zero, up), p = m4_perspective(40.0, (double)c->width / c->height, 0.1, 100.0, range);
    m4_store(v, c->view);
    m4_store(p, c->projection);
    c->depth_range = range;
    if (pv_out) *pv_out = m4_mul(p, v);
}

static float *render(const hd_desc *d, int iterations, const hd_depth_desc *depth, size_t *n_out)
{
    hd_context ctx;
    size_t n = (size_t)d->camera.width * d->camera.height * 4;
    float *img = (float *)calloc(n, sizeof(float));
    hd_result r = hd_create(d, &ctx);
    CHECK_MSG(r == HD_SUCCESS, "hd_create: %s", hd_result_string(r));
    if (r != HD_SUCCESS) return img;
    if (depth) CHECK((r = hd_set_depth(ctx, depth)) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, iterations) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
    hd_destroy(ctx);
    if (n_out) *n_out = n;
    return img;
}

static double rel_l2(const float *a, const float *b, size_t n)
{
    double num = 0.0, den = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) { num += ((double)b[i] - a[i]) * ((double)b[i] - a[i]); den += (double)a[i] * a[i]; }
    return den > 0.0 ? sqrt(num / den) : sqrt(num);
}

/* ---- matrices ---------------------------------------------------------------------------------- */
/* The look-at camera and the same view as matrices render the same image within float rounding:
   GL's, zero-to-one and reversed-Z (infinite far) projections, and a left-handed view and
   projection, for the projection (HD) and the path tracers (PT_SS); a camera moved by 1 % of its
   distance differs by far more. */
static void test_lookat_equals_matrices(void)
{
    static const hd_method methods[2] = {HD_METHOD_HD, HD_METHOD_PT_SS};
    int m, k;
    make_volumes();
    for (m = 0; m < 2; ++m) {
        hd_desc d = scene_desc(vox_blob, tf_blob, 3), dm;
        size_t n = 0;
        float *ref, *img;
        double e;
        d.params.method = methods[m];
        ref = render(&d, 2, NULL, &n);
        for (k = 0; k < 4; ++k) {
            dm = d;
            camera_matrices(&dm.camera, k == 3 ? HD_DEPTH_NEG_ONE_TO_ONE : (hd_depth_range)k, NULL);
            if (k == 3) { /* left-handed: eye space z flipped in view and projection */
                mat4 v, p, flip = m4_identity();
                int i;
                M4(flip, 2, 2) = -1.0;
                for (i = 0; i < 16; ++i) { v.m[i] = dm.camera.view[i]; p.m[i] = dm.camera.projection[i]; }
                m4_store(m4_mul(flip, v), dm.camera.view);
                m4_store(m4_mul(p, flip), dm.camera.projection);
            }
            dm.camera.eye[0] = 77.0f; /* ignored with matrices */
            img = render(&dm, 2, NULL, NULL);
            e = rel_l2(ref, img, n);
            CHECK_MSG(e < 2e-4, "%s, convention %d: relative L2 %g against the look-at camera", hd_method_name(methods[m]), k, e);
            free(img);
        }
        dm = d;
        dm.camera.eye[0] *= 1.05f;
        camera_matrices(&dm.camera, HD_DEPTH_NEG_ONE_TO_ONE, NULL);
        img = render(&dm, 2, NULL, NULL);
        e = rel_l2(ref, img, n);
        CHECK_MSG(e > 1e-2, "%s: a moved camera differs by only %g", hd_method_name(methods[m]), e);
        free(img);
        free(ref);
    }
}

/* Frames of fixed light: the light refined to convergence, then `frames` frames into a mean of
   as many. */
static void converged_frames(hd_context ctx, int frames, float *img, size_t n)
{
    int i;
    for (i = 0; i < frames; ++i) CHECK(hd_render(ctx) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
}

/* An off-centre projection (glFrustum of a sub-rectangle) renders that sub-rectangle of the full
   frame: per pixel within the jitter's noise, which a sub-rectangle shifted by 3 pixels (what
   ignoring the off-centre terms would draw, in part) exceeds several times over. */
static void test_offcentre_subrectangle(void)
{
    enum { BW = 64, BH = 48, SX = 12, SY = 20, SW = 32, SH = 24, F = 64 };
    hd_desc d = scene_desc(vox_blob, tf_blob, 3);
    hd_context ctx;
    hd_camera big, sub;
    float up[3] = {0.0f, 1.0f, 0.0f}, zero[3] = {0.0f, 0.0f, 0.0f};
    double n = 0.1, t = n * tan(20.0 * 3.14159265358979 / 180.0), aspect = (double)BW / BH;
    float *a = (float *)malloc(sizeof(float) * BW * BH * 4), *b = (float *)malloc(sizeof(float) * SW * SH * 4);
    double se = 0.0, ss = 0.0, sum = 0.0;
    int x, y, c;
    make_volumes();
    d.camera.width = BW; d.camera.height = BH;
    d.params.frame_window = F;
    d.params.light_tolerance = 1e3f; /* converged after two light iterations */
    big = d.camera;
    m4_store(m4_lookat(big.eye, zero, up), big.view);
    m4_store(m4_perspective(40.0, aspect, n, 100.0, HD_DEPTH_NEG_ONE_TO_ONE), big.projection);
    d.camera = big;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    converged_frames(ctx, F + 3, a, (size_t)BW * BH * 4);
    sub = big;
    sub.width = SW; sub.height = SH;
    {
        double l = -t * aspect + 2 * t * aspect * SX / BW, r = -t * aspect + 2 * t * aspect * (SX + SW) / BW;
        double top = t - 2 * t * SY / BH, bot = t - 2 * t * (SY + SH) / BH;
        m4_store(m4_frustum(l, r, bot, top, n, 100.0, HD_DEPTH_NEG_ONE_TO_ONE), sub.projection);
    }
    CHECK(hd_set_camera(ctx, &sub) == HD_SUCCESS);
    converged_frames(ctx, F, b, (size_t)SW * SH * 4);
    for (y = 0; y < SH; ++y)
        for (x = 0; x < SW; ++x)
            for (c = 0; c < 4; ++c) {
                double v = b[(y * SW + x) * 4 + c], ref = a[((y + SY) * BW + x + SX) * 4 + c];
                double sh = a[((y + SY) * BW + x + SX + 3) * 4 + c];
                se += (v - ref) * (v - ref);
                ss += (v - sh) * (v - sh);
                sum += ref * ref;
            }
    CHECK_MSG(sqrt(se / sum) < 0.02 && se < 0.1 * ss, "sub-rectangle: relative RMS %g, shifted by 3 pixels %g", sqrt(se / sum),
              sqrt(ss / sum));
    hd_destroy(ctx);
    free(a);
    free(b);
}

/* An orthographic camera along -z over a uniform cube of extinction s: every ray inside the
   cube's footprint crosses its depth L, alpha = 1 - exp(-s L) (within the march's step), and no
   ray outside it sees anything. Scaled by 2 along z (volume.transform) the cube is twice as
   deep in world units: alpha = 1 - exp(-2 s L). */
static void test_orthographic_world_units(void)
{
    int pass;
    make_volumes();
    for (pass = 0; pass < 2; ++pass) {
        hd_desc d = scene_desc(vox_full, tf_flat, 2);
        float *img;
        double depth = pass ? 2.0 : 1.0, want, sum = 0.0;
        int x, y, inside = 0, bad_out = 0;
        d.volume.spacing[2] = 1.0f;
        d.params.extinction = 1.5f;
        d.camera.width = d.camera.height = 32;
        m4_store(m4_ortho(-1.0, 1.0, -1.0, 1.0, 0.1, 10.0), d.camera.projection);
        {
            float eye[3] = {0.0f, 0.0f, 3.0f}, zero[3] = {0.0f, 0.0f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
            m4_store(m4_lookat(eye, zero, up), d.camera.view);
        }
        if (pass) {
            mat4 s = m4_identity();
            M4(s, 2, 2) = 2.0;
            m4_store(s, d.volume.transform);
        }
        img = render(&d, 8, NULL, NULL);
        want = 1.0 - exp(-1.5 * depth);
        for (y = 0; y < 32; ++y)
            for (x = 0; x < 32; ++x) {
                double px = -1.0 + (x + 0.5) / 16.0, py = 1.0 - (y + 0.5) / 16.0, a = img[(y * 32 + x) * 4 + 3];
                if (fabs(px) < 0.45 && fabs(py) < 0.45) { sum += a; ++inside; }
                if ((fabs(px) > 0.55 || fabs(py) > 0.55) && a != 0.0f) ++bad_out;
            }
        CHECK_MSG(fabs(sum / inside - want) < 0.01, "depth %g: mean alpha %g inside, want %g", depth, sum / inside, want);
        CHECK_MSG(bad_out == 0, "depth %g: %d pixels outside the footprint see the volume", depth, bad_out);
        free(img);
    }
}

/* ---- a placed volume --------------------------------------------------------------------------- */
/* A volume rotated 30 degrees about a tilted axis, scaled 2 x 1 x 0.5 and translated renders as
   the volume scaled alone seen by the inverse-rotated and -translated camera and lights: the
   images, E and phi agree within float rounding. The volume without the scale looks different. */
static void test_transform_equals_inverse_camera(void)
{
    hd_desc da = scene_desc(vox_blob, tf_blob, 3), db;
    mat4 rot = m4_identity(), scale = m4_identity(), tr = m4_identity(), rt, xa;
    double ax[3] = {0.3, 1.0, 0.5}, ang = 30.0 * 3.14159265358979 / 180.0, c = cos(ang), s = sin(ang);
    double t[3] = {5.0, -2.0, 3.0};
    hd_light lb[2];
    float *ia, *ib, *ic;
    size_t n = 0;
    int r, k, i;
    double e;
    make_volumes();
    v3_norm(ax);
    for (r = 0; r < 3; ++r) /* Rodrigues */
        for (k = 0; k < 3; ++k) {
            double cr = (r == k ? c : 0.0) + (1.0 - c) * ax[r] * ax[k];
            if ((r + 1) % 3 == k) cr -= s * ax[3 - r - k];
            if ((k + 1) % 3 == r) cr += s * ax[3 - r - k];
            M4(rot, r, k) = cr;
        }
    M4(scale, 0, 0) = 2.0; M4(scale, 1, 1) = 1.0; M4(scale, 2, 2) = 0.5;
    for (i = 0; i < 3; ++i) M4(tr, i, 3) = t[i];
    rt = m4_mul(tr, rot);
    xa = m4_mul(rt, scale);
    /* scene A: the placed volume, camera and lights in the world around it */
    db = da;
    m4_store(xa, da.volume.transform);
    {
        float eye[3] = {1.5f, 2.0f, 3.5f}, target[3] = {0.0f, 0.2f, 0.0f};
        for (i = 0; i < 3; ++i) {
            /* B's camera: A's world camera mapped by (T R)^-1 = R^T (x - t) */
            double pe = 0.0, pt = 0.0, pu = 0.0;
            for (k = 0; k < 3; ++k) {
                pe += M4(rot, k, i) * ((double)eye[k] + 0.0);
                pt += M4(rot, k, i) * ((double)target[k] + 0.0);
                pu += M4(rot, k, i) * (k == 1 ? 1.0 : 0.0);
            }
            db.camera.eye[i] = (float)pe;
            db.camera.target[i] = (float)pt;
            db.camera.up[i] = (float)pu;
        }
        for (i = 0; i < 3; ++i) { da.camera.eye[i] = (float)(eye[i] + t[i]); da.camera.target[i] = (float)(target[i] + t[i]); }
        da.camera.up[0] = 0.0f; da.camera.up[1] = 1.0f; da.camera.up[2] = 0.0f;
    }
    memcpy(lb, g_lights, sizeof lb);
    {
        static hd_light la[2];
        memcpy(la, g_lights, sizeof la);
        for (i = 0; i < 3; ++i) la[1].position[i] = lb[1].position[i] + (float)t[i];
        for (i = 0; i < 3; ++i) {
            double pd = 0.0, pp = 0.0;
            for (k = 0; k < 3; ++k) {
                pd += M4(rot, k, i) * g_lights[0].direction[k];
                pp += M4(rot, k, i) * g_lights[1].position[k];
            }
            lb[0].direction[i] = (float)pd;
            lb[1].position[i] = (float)pp;
        }
        da.lights = la;
        m4_store(scale, db.volume.transform);
        db.lights = lb;
        ia = render(&da, 3, NULL, &n);
        ib = render(&db, 3, NULL, NULL);
        e = rel_l2(ib, ia, n);
        CHECK_MSG(e < 1e-3, "placed volume against the inverse-transformed camera and lights: relative L2 %g", e);
        free(ia);
        { /* A's camera as matrices */
            float up[3] = {0.0f, 1.0f, 0.0f};
            m4_store(m4_lookat(da.camera.eye, da.camera.target, up), da.camera.view);
            m4_store(m4_perspective(40.0, (double)W / H, 0.1, 100.0, HD_DEPTH_ZERO_TO_ONE), da.camera.projection);
            da.camera.depth_range = HD_DEPTH_ZERO_TO_ONE;
        }
        ia = render(&da, 3, NULL, &n);
        e = rel_l2(ib, ia, n);
        CHECK_MSG(e < 1e-3, "placed volume, camera as matrices: relative L2 %g", e);
        memset(db.volume.transform, 0, sizeof db.volume.transform);
        ic = render(&db, 3, NULL, NULL);
        e = rel_l2(ib, ic, n);
        CHECK_MSG(e > 0.05, "the unscaled volume differs by only %g", e);
        free(ia);
        free(ib);
        free(ic);
    }
}

/* hd_set_volume_transform: restarts the light and the image, hd_query_desc returns it, NULL goes
   back to the identity (the image bit-identical to one never transformed). */
static void test_set_volume_transform(void)
{
    hd_desc d = scene_desc(vox_blob, tf_blob, 3), q;
    hd_context ctx;
    hd_stats st;
    float m[16] = {0}, *ref, img[W * H * 4];
    size_t n = 0;
    make_volumes();
    ref = render(&d, 2, NULL, &n);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
    m[0] = 1.5f; m[5] = 1.0f; m[10] = 1.0f; m[15] = 1.0f; m[13] = 0.1f;
    CHECK(hd_set_volume_transform(ctx, m) == HD_SUCCESS);
    CHECK(hd_query_desc(ctx, &q) == HD_SUCCESS && memcmp(q.volume.transform, m, sizeof m) == 0);
    CHECK(hd_iterate(ctx, 1) == HD_SUCCESS && hd_get_stats(ctx, &st) == HD_SUCCESS && st.iterations == 1 && st.frames == 1);
    CHECK(hd_set_volume_transform(ctx, NULL) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
    CHECK(memcmp(img, ref, n * sizeof(float)) == 0);
    hd_destroy(ctx);
    free(ref);
}

/* ---- depth ------------------------------------------------------------------------------------- */
/* The depth buffer of a world-space box [lo, hi] for the camera (look-at eye at the origin, the
   projection of camera_matrices), through pixel centres; 1 (or 0, reversed) where it misses.
   *t_hit: the ray parameter where each pixel centre meets it (3e38 where it misses). */
static void box_depth(const hd_camera *c, mat4 pv, const double lo[3], const double hi[3], float *depth, double *t_hit)
{
    double f[3], s[3], u[3], up[3] = {0.0, 1.0, 0.0}, th = tan(20.0 * 3.14159265358979 / 180.0), aspect = (double)c->width / c->height;
    int x, y, i;
    for (i = 0; i < 3; ++i) f[i] = -(double)c->eye[i];
    v3_norm(f);
    v3_cross(f, up, s);
    v3_norm(s);
    v3_cross(s, f, u);
    for (y = 0; y < c->height; ++y)
        for (x = 0; x < c->width; ++x) {
            double sx = 2.0 * (x + 0.5) / c->width - 1.0, sy = 1.0 - 2.0 * (y + 0.5) / c->height, d[3], t0 = 0.0, t1 = 1e300;
            for (i = 0; i < 3; ++i) d[i] = f[i] + sx * th * aspect * s[i] + sy * th * u[i];
            v3_norm(d);
            for (i = 0; i < 3; ++i) {
                double a = (lo[i] - c->eye[i]) / d[i], b = (hi[i] - c->eye[i]) / d[i];
                if (a > b) { double tmp = a; a = b; b = tmp; }
                if (a > t0) t0 = a;
                if (b < t1) t1 = b;
            }
            if (t0 < t1) {
                double p[3];
                for (i = 0; i < 3; ++i) p[i] = c->eye[i] + t0 * d[i];
                depth[y * c->width + x] = window_depth(pv, p, c->depth_range);
                t_hit[y * c->width + x] = t0;
            } else {
                depth[y * c->width + x] = c->depth_range == HD_DEPTH_REVERSED ? 0.0f : 1.0f;
                t_hit[y * c->width + x] = 3e38;
            }
        }
}

/* The volume box's entry along pixel (x, y)'s rays, at its least over the pixel's corners (3e300
   where none meets it); *all = 1 where every corner does. */
static double volume_entry_all(const hd_camera *c, const float box[3], int x, int y, int *all)
{
    double f[3], s[3], u[3], up[3] = {0.0, 1.0, 0.0}, th = tan(20.0 * 3.14159265358979 / 180.0), aspect = (double)c->width / c->height;
    double best = 1e300;
    int i, k;
    *all = 1;
    for (i = 0; i < 3; ++i) f[i] = -(double)c->eye[i];
    v3_norm(f);
    v3_cross(f, up, s);
    v3_norm(s);
    v3_cross(s, f, u);
    for (k = 0; k < 4; ++k) {
        double sx = 2.0 * (x + (k & 1)) / c->width - 1.0, sy = 1.0 - 2.0 * (y + (k >> 1)) / c->height, d[3], t0 = 0.0, t1 = 1e300;
        for (i = 0; i < 3; ++i) d[i] = f[i] + sx * th * aspect * s[i] + sy * th * u[i];
        v3_norm(d);
        for (i = 0; i < 3; ++i) {
            double a = (-0.5 * box[i] - c->eye[i]) / d[i], b = (0.5 * box[i] - c->eye[i]) / d[i];
            if (a > b) { double tmp = a; a = b; b = tmp; }
            if (a > t0) t0 = a;
            if (b < t1) t1 = b;
        }
        if (t0 < t1 && t0 < best) best = t0;
        if (!(t0 < t1)) *all = 0;
    }
    return best;
}
static double volume_entry(const hd_camera *c, const float box[3], int x, int y)
{
    int all = 1;
    return volume_entry_all(c, box, x, y, &all);
}

/* A box standing half in front of the volume (its depth made analytically through the same
   matrices), under each depth convention and for HD and PT_SS: every pixel where the box is
   nearer than the volume's box shows nothing (rgb and alpha 0, no background either), every
   pixel where the box is absent is bit for bit the image without depth, and the box's pixels
   did show the volume without it. With render_scale 2 the box's inner pixels stay empty. */
static void test_depth_box_in_front(void)
{
    static const float box[3] = {0.8f, 0.8f, 1.0f}; /* the volume's box: spacing 1, 1, 1.25 */
    int conv, m;
    make_volumes();
    for (m = 0; m < 3; ++m)
        for (conv = 0; conv < 3; ++conv) {
            hd_desc d = scene_desc(vox_full, tf_blob, 3);
            hd_depth_desc dd = HD_DEPTH_DESC_INIT;
            float *depth = (float *)malloc(sizeof(float) * W * H), *ref, *img;
            double *th = (double *)malloc(sizeof(double) * W * H), lo[3] = {-2.0, -2.0, 0.8}, hi[3] = {0.1, 2.0, 1.1};
            mat4 pv;
            size_t n = 0;
            int x, y, hidden = 0, shown = 0, bad_hidden = 0, bad_shown = 0, was_visible = 0;
            d.params.method = m == 1 ? HD_METHOD_PT_SS : HD_METHOD_HD;
            if (m == 2) { d.params.render_scale = 2; d.params.background[0] = 0.3f; }
            d.params.background[1] = 0.2f; /* no background where the box is */
            d.camera.eye[0] = 0.4f; d.camera.eye[1] = 0.3f; d.camera.eye[2] = 2.4f;
            camera_matrices(&d.camera, (hd_depth_range)conv, &pv);
            box_depth(&d.camera, pv, lo, hi, depth, th);
            dd.data = depth; dd.width = W; dd.height = H;
            ref = render(&d, 2, NULL, &n);
            img = render(&d, 2, &dd, NULL);
            for (y = 0; y < H; ++y)
                for (x = 0; x < W; ++x) {
                    int i = y * W + x, c, same = 1, zero = 1;
                    for (c = 0; c < 4; ++c) {
                        same &= img[i * 4 + c] == ref[i * 4 + c];
                        zero &= img[i * 4 + c] == 0.0f;
                    }
                    if (m == 2) { /* reduced frames: the box's inner pixels, away from the upsample's reach */
                        int inner = 1, dx, dy;
                        for (dy = -3; dy <= 3; ++dy)
                            for (dx = -3; dx <= 3; ++dx) {
                                int xx = x + dx, yy = y + dy;
                                if (xx < 0 || yy < 0 || xx >= W || yy >= H || th[yy * W + xx] > 2.0) inner = 0;
                                else if (volume_entry(&d.camera, box, xx, yy) > 1e30 || th[yy * W + xx] > volume_entry(&d.camera, box, xx, yy) - 0.05)
                                    inner = 0;
                            }
                        if (inner) { ++hidden; bad_hidden += !zero; was_visible += ref[i * 4 + 3] > 0.1f; }
                        continue;
                    }
                    if (volume_entry(&d.camera, box, x, y) < 1e30 && th[i] < volume_entry(&d.camera, box, x, y) - 0.05) {
                        int all = 1;
                        volume_entry_all(&d.camera, box, x, y, &all);
                        ++hidden;
                        bad_hidden += !zero;
                        was_visible += !all || ref[i * 4 + 3] > 0.1f;
                    } else if (th[i] > 1e30) {
                        ++shown;
                        bad_shown += !same;
                    }
                }
            CHECK_MSG(hidden > 100 && bad_hidden == 0 && was_visible == hidden, "method %d convention %d: %d of %d hidden pixels not empty (%d showed the volume without depth)",
                      m, conv, bad_hidden, hidden, was_visible);
            if (m < 2) CHECK_MSG(shown > 100 && bad_shown == 0, "method %d convention %d: %d of %d pixels without the box differ", m, conv, bad_shown, shown);
            free(depth);
            free(th);
            free(ref);
            free(img);
        }
}

/* A thin post standing through the volume cuts it: the pixels on the post (where the ray would
   cross the whole volume) show the volume in front of it only (less opacity than without the
   post, yet some), the pixels beside it the
   image without depth, bit for bit; the three conventions agree on the post. */
static void test_depth_post_cuts(void)
{
    float *post[3];
    int conv;
    make_volumes();
    for (conv = 0; conv < 3; ++conv) {
        hd_desc d = scene_desc(vox_full, tf_blob, 3);
        hd_depth_desc dd = HD_DEPTH_DESC_INIT;
        float *depth = (float *)malloc(sizeof(float) * W * H), *ref;
        double *th = (double *)malloc(sizeof(double) * W * H), lo[3] = {-0.08, -3.0, -0.08}, hi[3] = {0.08, 3.0, 0.08};
        mat4 pv;
        int x, y, on = 0, bad_on = 0, beside = 0, bad_beside = 0;
        d.params.extinction = 4.0f;
        d.camera.eye[0] = 0.0f; d.camera.eye[1] = 0.2f; d.camera.eye[2] = 2.5f;
        camera_matrices(&d.camera, (hd_depth_range)conv, &pv);
        box_depth(&d.camera, pv, lo, hi, depth, th);
        dd.data = depth; dd.width = W; dd.height = H;
        ref = render(&d, 3, NULL, NULL);
        post[conv] = render(&d, 3, &dd, NULL);
        for (y = 4; y < H - 4; ++y)
            for (x = 0; x < W; ++x) {
                int i = y * W + x, c, same = 1;
                for (c = 0; c < 4; ++c) same &= post[conv][i * 4 + c] == ref[i * 4 + c];
                if (th[i] < 1e30 && (x == 0 || th[i - 1] < 1e30) && (x == W - 1 || th[i + 1] < 1e30) && ref[i * 4 + 3] > 0.95f) {
                    ++on;
                    bad_on += !(post[conv][i * 4 + 3] > 0.05f && post[conv][i * 4 + 3] < ref[i * 4 + 3] - 0.05f);
                } else if (th[i] > 1e30) {
                    ++beside;
                    bad_beside += !same;
                }
            }
        CHECK_MSG(on >= 20 && bad_on == 0, "convention %d: %d of %d post pixels do not show the volume in front only", conv, bad_on, on);
        CHECK_MSG(beside > 1000 && bad_beside == 0, "convention %d: %d of %d pixels beside the post differ", conv, bad_beside, beside);
        free(depth);
        free(th);
        free(ref);
    }
    CHECK_MSG(rel_l2(post[0], post[1], W * H * 4) < 1e-3 && rel_l2(post[0], post[2], W * H * 4) < 1e-3,
              "the conventions disagree: %g, %g", rel_l2(post[0], post[1], W * H * 4), rel_l2(post[0], post[2], W * H * 4));
    for (conv = 0; conv < 3; ++conv) free(post[conv]);
}

/* The depth is kept across camera moves of the same size, dropped by a resize or a look-at
   camera (then the image is the one without depth), cleared by NULL. */
static void test_depth_lifetime(void)
{
    hd_desc d = scene_desc(vox_full, tf_blob, 3);
    hd_depth_desc dd = HD_DEPTH_DESC_INIT;
    hd_context ctx;
    hd_camera c;
    float depth[W * H], img[W * H * 4], *ref;
    size_t n = 0;
    int i;
    make_volumes();
    camera_matrices(&d.camera, HD_DEPTH_NEG_ONE_TO_ONE, NULL);
    ref = render(&d, 2, NULL, &n);
    for (i = 0; i < W * H; ++i) depth[i] = 0.5f; /* a wall in front of everything */
    dd.data = depth; dd.width = W; dd.height = H;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_set_depth(ctx, &dd) == HD_SUCCESS);
    c = d.camera;
    CHECK(hd_set_camera(ctx, &c) == HD_SUCCESS); /* same size: kept */
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS && hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
    for (i = 0; i < W * H * 4 && img[i] == 0.0f; ++i) {}
    CHECK_MSG(i == W * H * 4, "a wall at depth 0.5 leaves pixel %d at %g", i / 4, (double)img[i]);
    {
        /* resized and back: dropped; a twin context that never had it, the same calls */
        hd_context twin;
        float *img2 = (float *)malloc(n * sizeof(float));
        CHECK(hd_create(&d, &twin) == HD_SUCCESS && hd_iterate(twin, 2) == HD_SUCCESS);
        c.width = W / 2;
        CHECK(hd_set_camera(ctx, &c) == HD_SUCCESS && hd_set_camera(twin, &c) == HD_SUCCESS);
        c.width = W;
        CHECK(hd_set_camera(ctx, &c) == HD_SUCCESS && hd_set_camera(twin, &c) == HD_SUCCESS);
        CHECK(hd_iterate(ctx, 2) == HD_SUCCESS && hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
        CHECK(hd_iterate(twin, 2) == HD_SUCCESS && hd_read_image_f32(twin, img2, n) == HD_SUCCESS);
        CHECK_MSG(memcmp(img, img2, n * sizeof(float)) == 0, "the depth survived a resize");
        hd_destroy(twin);
        free(img2);
    }
    CHECK(hd_set_depth(ctx, &dd) == HD_SUCCESS);
    CHECK(hd_set_depth(ctx, NULL) == HD_SUCCESS);
    hd_destroy(ctx);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    CHECK(hd_set_depth(ctx, &dd) == HD_SUCCESS && hd_set_depth(ctx, NULL) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS && hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
    CHECK_MSG(memcmp(img, ref, n * sizeof(float)) == 0, "the depth survived hd_set_depth(NULL)");
    /* a look-at camera drops it */
    CHECK(hd_set_depth(ctx, &dd) == HD_SUCCESS);
    c = d.camera;
    memset(c.projection, 0, sizeof c.projection);
    CHECK(hd_set_camera(ctx, &c) == HD_SUCCESS);
    CHECK(hd_set_camera(ctx, &d.camera) == HD_SUCCESS);
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS && hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
    hd_destroy(ctx);
    for (i = 0; i < W * H * 4 && img[i] == 0.0f; ++i) {}
    CHECK_MSG(i < W * H * 4, "the depth survived a look-at camera");
    free(ref);
}

/* ---- the volume's depth out ----------------------------------------------------------------------- */
/* A slab of uniform medium (the whole 32 x 32 x 8 volume, 1 x 1 x 0.25 world units) translated to
   z = -1, seen down -z from the origin through a 90-degree perspective: a ray's opacity reaches
   1/2 at ln 2 / sigma_t past the front face at z = -0.875 along the ray, so hd_read_depth is the
   window depth of eye z -(0.875 + cos(theta) ln 2 / sigma_t) (theta: the pixel's ray's angle to
   the axis), within one step (the crossing sample's jitter); where a ray misses the slab, the
   far plane's value; threshold 0.9: ln 10 instead of ln 2. Under GL's, zero-to-one and reversed-Z
   conventions. A wall of host depth in front: the far value everywhere. */
static uint8_t vox_slab[N * N * 8];
static void test_depth_out_slab(void)
{
    static const float tf_one[8] = {0, 0, 0, 1, 1, 1, 1, 1};
    hd_desc d = HD_DESC_INIT;
    hd_light l;
    hd_context ctx;
    float *dep = (float *)malloc(W * H * sizeof(float)), *wall = (float *)malloc(W * H * sizeof(float));
    const double sigma = 20.0, dt = 0.5 / N, zface = 0.875;
    int conv, i, x, y;
    memset(vox_slab, 255, sizeof vox_slab);
    memset(&l, 0, sizeof l);
    l.direction[2] = -1.0f;
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = N; d.volume.dims[2] = 8;
    d.volume.data = vox_slab;
    d.volume.transform[0] = d.volume.transform[5] = d.volume.transform[10] = d.volume.transform[15] = 1.0f;
    d.volume.transform[14] = -1.0f;
    d.transfer_function.rgba = tf_one;
    d.transfer_function.count = 2;
    d.lights = &l;
    d.light_count = 1;
    d.camera.width = W; d.camera.height = H;
    d.params.extinction = (float)sigma;
    for (conv = 0; conv < 3; ++conv) {
        hd_depth_range range = (hd_depth_range)conv;
        mat4 p = m4_perspective(90.0, (double)W / H, 0.1, 10.0, range), pv;
        float far = range == HD_DEPTH_REVERSED ? 0.0f : 1.0f;
        int thr;
        memset(d.camera.view, 0, sizeof d.camera.view);
        m4_store(p, d.camera.projection);
        d.camera.depth_range = range;
        pv = p; /* view: identity */
        for (thr = 0; thr < 2; ++thr) {
            double len = (thr ? log(10.0) : log(2.0)) / sigma;
            int hit = 0, miss = 0, bad = 0;
            d.params.depth_threshold = thr ? 0.9f : 0.0f;
            CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
            CHECK(hd_iterate(ctx, 4) == HD_SUCCESS);
            CHECK(hd_read_depth(ctx, dep, W * H) == HD_SUCCESS);
            for (y = 0; y < H; ++y)
                for (x = 0; x < W; ++x) {
                    /* the centre ray's point on the front face's plane */
                    double sx = 2.0 * (x + 0.5) / W - 1.0, sy = 1.0 - 2.0 * (y + 0.5) / H;
                    double fx = fabs(sx * zface / M4(p, 0, 0)), fy = fabs(sy * zface / M4(p, 1, 1));
                    double ct = 1.0 / sqrt(1.0 + (fx * fx + fy * fy) / (zface * zface)), zc = zface + ct * len;
                    double pn[3] = {0.0, 0.0, -(zc - 1.01 * dt)}, pf[3] = {0.0, 0.0, -(zc + 1.01 * dt)};
                    float dn = window_depth(pv, pn, range), df = window_depth(pv, pf, range), lo = dn < df ? dn : df, hi = dn < df ? df : dn;
                    float v = dep[y * W + x];
                    if (fx < 0.5 - 3.0 / N && fy < 0.5 - 3.0 / N) {
                        ++hit;
                        bad += !(v >= lo - 1e-6f && v <= hi + 1e-6f);
                        if (!(v >= lo - 1e-6f && v <= hi + 1e-6f) && bad < 4)
                            fprintf(stderr, "  conv %d thr %d (%d, %d): %.7f not in [%.7f, %.7f]\n", conv, thr, x, y, (double)v, (double)lo, (double)hi);
                    } else if (fx > 0.5 + 1.0 / N || fy > 0.5 + 1.0 / N) {
                        ++miss;
                        bad += v != far;
                    }
                }
            CHECK_MSG(hit > 300 && miss > 100 && bad == 0, "convention %d, threshold %d: %d of %d + %d pixels off", conv, thr, bad, hit, miss);
            if (thr == 0) { /* the host's wall in front of the slab: no volume depth anywhere */
                hd_depth_desc dd = HD_DEPTH_DESC_INIT;
                double pw[3] = {0.0, 0.0, -0.5};
                float wv = window_depth(pv, pw, range);
                for (i = 0; i < W * H; ++i) wall[i] = wv;
                dd.data = wall; dd.width = W; dd.height = H;
                CHECK(hd_set_depth(ctx, &dd) == HD_SUCCESS && hd_iterate(ctx, 2) == HD_SUCCESS);
                CHECK(hd_read_depth(ctx, dep, W * H) == HD_SUCCESS);
                for (i = 0; i < W * H && dep[i] == far; ++i) {}
                CHECK_MSG(i == W * H, "convention %d: behind the host's wall pixel %d has depth %g", conv, i, (double)dep[i]);
            }
            hd_destroy(ctx);
        }
    }
    free(dep);
    free(wall);
}

/* ---- the light out ------------------------------------------------------------------------------ */
/* HD_ILLUMINATION_TOTAL is E + phi of the other two read-backs, bit for bit, for one channel and
   three (lights of different colours); the GL-only calls (hd_gl_illumination_texture,
   hd_gl_set_depth_texture) and the Vulkan-only hd_vulkan_record_illumination and
   hd_vulkan_record_refine are HD_ERROR_UNSUPPORTED here with one logged line, the path tracers'
   read HD_ERROR_UNSUPPORTED. */
static void test_light_out(void)
{
    hd_desc d = scene_desc(vox_blob, tf_blob, 3);
    hd_test_log log;
    hd_context ctx;
    hd_stats st;
    int rgb;
    make_volumes();
    d.logger = hd_test_logger(&log);
    for (rgb = 0; rgb < 2; ++rgb) {
        size_t n, i, bad = 0, lit = 0;
        float *t, *e, *p;
        d.light_count = rgb ? 2 : 1;
        CHECK(hd_create(&d, &ctx) == HD_SUCCESS && hd_iterate(ctx, 3) == HD_SUCCESS && hd_get_stats(ctx, &st) == HD_SUCCESS);
        CHECK(st.illumination_channels == (rgb ? 3 : 1));
        n = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] * st.illumination_channels;
        t = (float *)malloc(n * sizeof(float)); e = (float *)malloc(n * sizeof(float)); p = (float *)malloc(n * sizeof(float));
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_TOTAL, t, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_DIRECT, e, n) == HD_SUCCESS);
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_SCATTERED, p, n) == HD_SUCCESS);
        for (i = 0; i < n; ++i) { bad += t[i] != e[i] + p[i]; lit += p[i] > 0.0f && e[i] > 0.0f; }
        CHECK_MSG(bad == 0 && lit > n / 10, "%d channels: %zu voxels not E + phi, %zu lit by both", st.illumination_channels, bad, lit);
        log.errors = 0;
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_TOTAL, t, n - 1) == HD_ERROR_BUFFER_TOO_SMALL && log.errors == 1);
        log.errors = 0;
        CHECK(hd_gl_illumination_texture(ctx, 1u, 0) == HD_ERROR_UNSUPPORTED && log.errors == 1);
        log.errors = 0;
        CHECK(hd_gl_set_depth_texture(ctx, 1u) == HD_ERROR_UNSUPPORTED && log.errors == 1);
        {
            hd_vulkan_volume_target vt = HD_VULKAN_VOLUME_TARGET_INIT;
            vt.buffer = 1u;
            vt.buffer_size = (uint64_t)n * sizeof(float);
            log.errors = 0;
            CHECK(hd_vulkan_record_illumination(ctx, &vt, 0, &vt) == HD_ERROR_UNSUPPORTED && log.errors == 1);
            log.errors = 0;
            CHECK(hd_vulkan_record_refine(ctx, &vt, 1) == HD_ERROR_UNSUPPORTED && log.errors == 1);
        }
        free(t); free(e); free(p);
        hd_destroy(ctx);
    }
    d.params.method = HD_METHOD_PT_SS;
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS && hd_iterate(ctx, 1) == HD_SUCCESS);
    {
        float one[4];
        log.errors = 0;
        CHECK(hd_read_illumination(ctx, HD_ILLUMINATION_TOTAL, one, 4) == HD_ERROR_UNSUPPORTED && log.errors == 1);
    }
    hd_destroy(ctx);
}

/* ---- bad input --------------------------------------------------------------------------------- */
static hd_test_log g_log;
/* `call`'s result is `code`, with exactly one logged error. */
#define EXPECT_ONE(call, code) \
    do { \
        hd_result r_; \
        g_log.errors = 0; \
        r_ = (call); \
        CHECK_MSG(r_ == (code) && g_log.errors == 1, "%s: %s, %d errors logged (%s)", #call, hd_result_string(r_), g_log.errors, g_log.last); \
    } while (0)

/* Each bad matrix, transform and depth buffer: its own hd_result and one logged line, and the
   context is as before: the image afterwards bit for bit the one of a context never given them. */
static void test_bad_input(void)
{
    hd_desc d = scene_desc(vox_blob, tf_blob, 3), bad;
    hd_context ctx, tmp;
    hd_camera c;
    hd_depth_desc dd = HD_DEPTH_DESC_INIT;
    float m[16], depth[W * H], img[W * H * 4], *ref, nanv = 0.0f;
    size_t n = 0;
    int i;
    make_volumes();
    camera_matrices(&d.camera, HD_DEPTH_ZERO_TO_ONE, NULL);
    for (i = 0; i < W * H; ++i) depth[i] = 0.6f;
    ref = render(&d, 2, NULL, &n);
    d.logger = hd_test_logger(&g_log);
    CHECK(hd_create(&d, &ctx) == HD_SUCCESS);
    nanv = nanv / nanv;
    /* cameras */
    c = d.camera; c.projection[0] = nanv; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA);
    c = d.camera; c.view[5] = 1.0f / 0.0f; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA);
    c = d.camera; c.projection[0] = 0.0f; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA); /* singular */
    c = d.camera; memset(c.view, 0, sizeof c.view); for (i = 0; i < 3; ++i) c.view[i * 5] = 1.0f; c.view[10] = 0.0f; c.view[15] = 1.0f;
    EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA); /* singular view */
    c = d.camera; c.projection[3] = 0.5f; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA); /* neither kind */
    c = d.camera; c.view[3] = 0.5f; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA); /* view not affine */
    c = d.camera; c.depth_range = (hd_depth_range)7; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_ENUM);
    c = d.camera; c.view[12] = 1e6f; EXPECT_ONE(hd_set_camera(ctx, &c), HD_ERROR_INVALID_CAMERA); /* too far away */
    /* transforms */
    memset(m, 0, sizeof m); m[0] = m[5] = m[10] = m[15] = 1.0f;
    m[4] = 0.3f; EXPECT_ONE(hd_set_volume_transform(ctx, m), HD_ERROR_TRANSFORM_SHEAR);
    m[4] = 0.0f; m[5] = 0.0f; EXPECT_ONE(hd_set_volume_transform(ctx, m), HD_ERROR_INVALID_TRANSFORM); /* singular */
    m[5] = 1.0f; m[3] = 0.1f; EXPECT_ONE(hd_set_volume_transform(ctx, m), HD_ERROR_INVALID_TRANSFORM); /* not affine */
    m[3] = 0.0f; m[14] = nanv; EXPECT_ONE(hd_set_volume_transform(ctx, m), HD_ERROR_INVALID_TRANSFORM);
    m[14] = 0.0f; m[0] = m[5] = m[10] = 1e-5f;
    EXPECT_ONE(hd_set_volume_transform(ctx, m), HD_ERROR_INVALID_CAMERA); /* the camera 1e5 sides away */
    m[0] = m[5] = m[10] = 1.0f; m[12] = 2e15f; EXPECT_ONE(hd_set_volume_transform(ctx, m), HD_ERROR_INVALID_TRANSFORM);
    bad = d;
    bad.volume.transform[0] = 1.0f; bad.volume.transform[1] = 1.0f; bad.volume.transform[5] = 1.0f;
    bad.volume.transform[10] = 1.0f; bad.volume.transform[15] = 1.0f;
    EXPECT_ONE(hd_create(&bad, &tmp), HD_ERROR_TRANSFORM_SHEAR);
    /* depth */
    dd.data = depth; dd.width = W - 1; dd.height = H; EXPECT_ONE(hd_set_depth(ctx, &dd), HD_ERROR_DEPTH_SIZE);
    dd.data = NULL; dd.width = W; EXPECT_ONE(hd_set_depth(ctx, &dd), HD_ERROR_NULL_POINTER);
    dd.data = depth; depth[77] = nanv; EXPECT_ONE(hd_set_depth(ctx, &dd), HD_ERROR_INVALID_DEPTH);
    depth[77] = 1.5f; EXPECT_ONE(hd_set_depth(ctx, &dd), HD_ERROR_INVALID_DEPTH);
    depth[77] = -0.25f; EXPECT_ONE(hd_set_depth(ctx, &dd), HD_ERROR_INVALID_DEPTH);
    depth[77] = 0.6f;
    bad = d;
    memset(bad.camera.projection, 0, sizeof bad.camera.projection);
    bad.logger = d.logger;
    CHECK(hd_create(&bad, &tmp) == HD_SUCCESS);
    EXPECT_ONE(hd_set_depth(tmp, &dd), HD_ERROR_DEPTH_NEEDS_PROJECTION);
    CHECK(hd_iterate(tmp, 1) == HD_SUCCESS);
    EXPECT_ONE(hd_read_depth(tmp, depth, W * H), HD_ERROR_DEPTH_NEEDS_PROJECTION);
    hd_destroy(tmp);
    /* the volume's depth out */
    EXPECT_ONE(hd_read_depth(ctx, depth, W * H), HD_ERROR_NO_FRAME);
    EXPECT_ONE(hd_read_depth(ctx, NULL, W * H), HD_ERROR_NULL_POINTER);
    EXPECT_ONE(hd_read_depth(ctx, depth, W * H - 1), HD_ERROR_BUFFER_TOO_SMALL);
    bad = d;
    bad.params.method = HD_METHOD_PT_SS;
    CHECK(hd_create(&bad, &tmp) == HD_SUCCESS && hd_iterate(tmp, 1) == HD_SUCCESS);
    EXPECT_ONE(hd_read_depth(tmp, depth, W * H), HD_ERROR_UNSUPPORTED);
    hd_destroy(tmp);
    bad.params.method = HD_METHOD_HD;
    bad.params.depth_threshold = 1.5f;
    EXPECT_ONE(hd_create(&bad, &tmp), HD_ERROR_INVALID_PARAMETER);
    /* nothing changed */
    g_log.errors = 0;
    CHECK(hd_iterate(ctx, 2) == HD_SUCCESS && hd_read_image_f32(ctx, img, n) == HD_SUCCESS);
    CHECK_MSG(memcmp(img, ref, n * sizeof(float)) == 0, "a refused call changed the context");
    CHECK(g_log.errors == 0);
    hd_destroy(ctx);
    free(ref);
}

const hd_test_case hd_tests_scene[] = {
    {"scene_lookat_equals_matrices", test_lookat_equals_matrices},
    {"scene_offcentre_subrectangle", test_offcentre_subrectangle},
    {"scene_orthographic_world_units", test_orthographic_world_units},
    {"scene_transform_equals_inverse_camera", test_transform_equals_inverse_camera},
    {"scene_set_volume_transform", test_set_volume_transform},
    {"scene_depth_box_in_front", test_depth_box_in_front},
    {"scene_depth_post_cuts", test_depth_post_cuts},
    {"scene_depth_lifetime", test_depth_lifetime},
    {"scene_depth_out_slab", test_depth_out_slab},
    {"scene_light_out", test_light_out},
    {"scene_bad_input", test_bad_input},
};
const int hd_tests_scene_count = (int)(sizeof hd_tests_scene / sizeof hd_tests_scene[0]);
