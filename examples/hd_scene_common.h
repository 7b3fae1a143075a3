/* The host-scene examples' shared pieces (examples/scene.c, examples/scene_vulkan.c): column-major
   4x4 matrices, the procedural smoke cloud, the animated plume and where it stands, the unit cube
   the meshes are made of, and the --check test of a volume's image. Include it after
   hybriddiff.h. */
#ifndef HD_SCENE_COMMON_H
#define HD_SCENE_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979f

/* ---- column-major 4x4 matrices, GL conventions (element row r, column c at m[c * 4 + r]) ---- */
typedef struct mat4 { float m[16]; } mat4;

static mat4 mat4_identity(void)
{
    mat4 r;
    memset(&r, 0, sizeof r);
    r.m[0] = r.m[5] = r.m[10] = r.m[15] = 1.0f;
    return r;
}

static mat4 mat4_mul(mat4 a, mat4 b)
{
    mat4 r;
    for (int c = 0; c < 4; ++c)
        for (int row = 0; row < 4; ++row) {
            float s = 0.0f;
            for (int k = 0; k < 4; ++k) s += a.m[k * 4 + row] * b.m[c * 4 + k];
            r.m[c * 4 + row] = s;
        }
    return r;
}

static mat4 mat4_translate(float x, float y, float z)
{
    mat4 r = mat4_identity();
    r.m[12] = x, r.m[13] = y, r.m[14] = z;
    return r;
}

static mat4 mat4_scale(float x, float y, float z)
{
    mat4 r = mat4_identity();
    r.m[0] = x, r.m[5] = y, r.m[10] = z;
    return r;
}

static mat4 mat4_rotate_y(float radians)
{
    mat4 r = mat4_identity();
    r.m[0] = cosf(radians), r.m[8] = sinf(radians);
    r.m[2] = -sinf(radians), r.m[10] = cosf(radians);
    return r;
}

/* gluLookAt */
static mat4 mat4_look_at(const float eye[3], const float at[3], const float up[3])
{
    float f[3] = {at[0] - eye[0], at[1] - eye[1], at[2] - eye[2]}, s[3], u[3];
    float fl = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]), sl;
    mat4 r = mat4_identity();
    for (int i = 0; i < 3; ++i) f[i] /= fl;
    s[0] = f[1] * up[2] - f[2] * up[1], s[1] = f[2] * up[0] - f[0] * up[2], s[2] = f[0] * up[1] - f[1] * up[0];
    sl = sqrtf(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (int i = 0; i < 3; ++i) s[i] /= sl;
    u[0] = s[1] * f[2] - s[2] * f[1], u[1] = s[2] * f[0] - s[0] * f[2], u[2] = s[0] * f[1] - s[1] * f[0];
    for (int i = 0; i < 3; ++i) {
        r.m[i * 4 + 0] = s[i];
        r.m[i * 4 + 1] = u[i];
        r.m[i * 4 + 2] = -f[i];
    }
    r.m[12] = -(s[0] * eye[0] + s[1] * eye[1] + s[2] * eye[2]);
    r.m[13] = -(u[0] * eye[0] + u[1] * eye[1] + u[2] * eye[2]);
    r.m[14] = f[0] * eye[0] + f[1] * eye[1] + f[2] * eye[2];
    return r;
}

/* ---- the smoke cloud: a few soft blobs carved by value noise --------------------------------- */
static float hash3(int x, int y, int z)
{
    unsigned h = (unsigned)x * 73856093u ^ (unsigned)y * 19349663u ^ (unsigned)z * 83492791u;
    h = (h ^ (h >> 13)) * 1274126177u;
    return (float)((h ^ (h >> 16)) & 0xffffu) / 65535.0f;
}

static float value_noise(float x, float y, float z)
{
    int ix = (int)floorf(x), iy = (int)floorf(y), iz = (int)floorf(z);
    float fx = x - (float)ix, fy = y - (float)iy, fz = z - (float)iz, r = 0.0f;
    fx = fx * fx * (3.0f - 2.0f * fx), fy = fy * fy * (3.0f - 2.0f * fy), fz = fz * fz * (3.0f - 2.0f * fz);
    for (int k = 0; k < 8; ++k) {
        float w = (k & 1 ? fx : 1.0f - fx) * (k & 2 ? fy : 1.0f - fy) * (k & 4 ? fz : 1.0f - fz);
        r += w * hash3(ix + (k & 1), iy + ((k >> 1) & 1), iz + ((k >> 2) & 1));
    }
    return r;
}

static void make_cloud(unsigned char *v, int n)
{
    static const float blobs[4][4] = {{0.0f, -0.1f, 0.0f, 0.42f}, {0.28f, 0.05f, 0.1f, 0.3f},
                                      {-0.3f, 0.0f, -0.08f, 0.28f}, {0.05f, 0.22f, -0.05f, 0.26f}};
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                float p[3] = {(x + 0.5f) / n - 0.5f, (y + 0.5f) / n - 0.5f, (z + 0.5f) / n - 0.5f}, d = 0.0f, fbm;
                for (int b = 0; b < 4; ++b) {
                    float dx = p[0] - blobs[b][0], dy = p[1] - blobs[b][1], dz = p[2] - blobs[b][2];
                    float t = 1.0f - sqrtf(dx * dx + dy * dy + dz * dz) / blobs[b][3];
                    d = t > d ? t : d;
                }
                fbm = 0.5f * value_noise(p[0] * 8.0f + 11.0f, p[1] * 8.0f, p[2] * 8.0f) +
                      0.25f * value_noise(p[0] * 16.0f, p[1] * 16.0f + 5.0f, p[2] * 16.0f) +
                      0.125f * value_noise(p[0] * 32.0f, p[1] * 32.0f, p[2] * 32.0f + 3.0f);
                d = d * 1.6f - (1.0f - fbm) * 0.7f;
                v[((size_t)z * n + y) * n + x] = (unsigned char)(d <= 0.0f ? 0 : d >= 1.0f ? 255 : (int)(d * 255.0f));
            }
}

/* ---- the living volume: a plume of smoke rising from the green box -------------------------- */
#define SMOKE_N 40 /* its voxels per side, F32, replaced every frame by hd_update_volume */

/* The plume at time t (seconds): a column widening upward, its centre swaying, its density
   carved by two octaves of value noise that rise with the smoke (advected noise). */
static void make_smoke(float *v, int n, float t)
{
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                float p[3] = {(x + 0.5f) / n - 0.5f, (y + 0.5f) / n - 0.5f, (z + 0.5f) / n - 0.5f};
                float h = p[1] + 0.5f, r = 0.08f + 0.3f * h;
                float cx = 0.12f * h * h * sinf(1.3f * t), cz = 0.1f * h * cosf(0.9f * t);
                float dx = p[0] - cx, dz = p[2] - cz, d = 1.0f - sqrtf(dx * dx + dz * dz) / r;
                float rise = 1.2f * t, fbm;
                if (d <= 0.0f) { v[((size_t)z * n + y) * n + x] = 0.0f; continue; }
                fbm = 0.65f * value_noise(p[0] * 6.0f, p[1] * 6.0f - rise * 6.0f, p[2] * 6.0f) +
                      0.35f * value_noise(p[0] * 13.0f + 7.0f, p[1] * 13.0f - rise * 13.0f, p[2] * 13.0f);
                d = d * (1.0f - 0.8f * h) * (0.3f + 1.4f * fbm);
                v[((size_t)z * n + y) * n + x] = d > 1.0f ? 1.0f : d;
            }
}

/* The plume's volume in desc: its first voxels (returned, malloc'd; NULL without memory) as F32
   in a box 1.2 wide and 2.8 tall standing on the green box (the volume-to-world transform), the
   box's centre in `at` (the blending order), extinction 10. */
static float *smoke_volume(hd_desc *desc, float at[3])
{
    float *vox = (float *)malloc(sizeof(float) * SMOKE_N * SMOKE_N * SMOKE_N);
    mat4 place;
    if (!vox) return NULL;
    make_smoke(vox, SMOKE_N, 0.0f);
    at[0] = -3.5f, at[1] = 0.8f + 1.4f, at[2] = 2.0f;
    place = mat4_mul(mat4_translate(at[0], at[1], at[2]), mat4_scale(1.2f, 2.8f, 1.2f));
    memcpy(desc->volume.transform, place.m, sizeof desc->volume.transform);
    desc->volume.type = HD_VOXEL_F32;
    desc->volume.dims[0] = desc->volume.dims[1] = desc->volume.dims[2] = SMOKE_N;
    desc->volume.data = vox;
    desc->params.extinction = 10.0f;
    return vox;
}

/* Whether the volume centred at p is farther from the eye than the one at q: two volumes that
   do not overlap are blended the farther first. */
static int volume_farther(const float eye[3], const float p[3], const float q[3])
{
    float dp = 0.0f, dq = 0.0f;
    for (int k = 0; k < 3; ++k) dp += (p[k] - eye[k]) * (p[k] - eye[k]), dq += (q[k] - eye[k]) * (q[k] - eye[k]);
    return dp > dq;
}

/* --check: a volume's last frame, read back as linear floats (w x h), is finite everywhere, opaque
   enough (alpha above `opaque`) over more than 1/cover_div of the pixels and absent from a
   quarter (the cloud: the sky above it, where the box in front hides it; the plume: most of the
   image). `tag` prefixes the line it prints. */
static int check_volume(const char *tag, hd_context ctx, int w, int h, const char *name, float opaque, size_t cover_div)
{
    size_t n = (size_t)w * h, covered = 0, clear = 0, bad = 0;
    float *img = (float *)malloc(n * 4 * sizeof(float));
    hd_result r;
    if (!img) return 0;
    if ((r = hd_read_image_f32(ctx, img, n * 4)) != HD_SUCCESS) {
        fprintf(stderr, "%s: %s: hd_read_image_f32: %s\n", tag, name, hd_result_string(r));
        free(img);
        return 0;
    }
    for (size_t i = 0; i < n; ++i) {
        float *p = img + 4 * i;
        bad += !(isfinite(p[0]) && isfinite(p[1]) && isfinite(p[2]) && p[3] >= 0.0f && p[3] <= 1.0f);
        covered += p[3] > opaque;
        clear += p[3] == 0.0f;
    }
    free(img);
    fprintf(stderr, "%s: %s over %.1f%% of the image (alpha > %.2f), absent from %.1f%%, %zu bad pixels\n", tag, name,
            100.0 * (double)covered / (double)n, (double)opaque, 100.0 * (double)clear / (double)n, bad);
    return bad == 0 && covered > n / cover_div && clear > n / 4;
}

/* 36 vertices of a unit cube centred at 0 (position, normal) */
static void cube_vertices(float *out)
{
    static const int faces[6][4][3] = {
        {{1, -1, -1}, {1, 1, -1}, {1, 1, 1}, {1, -1, 1}},     {{-1, -1, 1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, -1}},
        {{-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}},     {{-1, -1, 1}, {-1, -1, -1}, {1, -1, -1}, {1, -1, 1}},
        {{-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},     {{1, -1, -1}, {-1, -1, -1}, {-1, 1, -1}, {1, 1, -1}}};
    static const float normals[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    static const int tri[6] = {0, 1, 2, 0, 2, 3};
    for (int f = 0; f < 6; ++f)
        for (int k = 0; k < 6; ++k) {
            float *v = out + (f * 6 + k) * 6;
            for (int i = 0; i < 3; ++i) v[i] = 0.5f * (float)faces[f][tri[k]][i], v[3 + i] = normals[f][i];
        }
}

#endif
