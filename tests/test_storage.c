/* test_storage.c - native voxel storage on the CPU backend: U8, U16 and I16 volumes kept as they
   are (hd_stats.volume_bytes), mapped by value_range in the kernels exactly as the core maps the
   same values given as F32, and hd_update_volume on an I16 volume. */
#include "hybriddiff.h"
#include "hd_test.h"

#define ST_N 20
static int16_t st_i16[ST_N * ST_N * ST_N];
static float st_f32[ST_N * ST_N * ST_N];
static float st_img_a[64 * 48 * 4], st_img_b[64 * 48 * 4];

/* A CT-like volume in Hounsfield units: air, tissue, a bone shell, noise. */
static void st_fill(void)
{
    int x, y, z;
    for (z = 0; z < ST_N; ++z)
        for (y = 0; y < ST_N; ++y)
            for (x = 0; x < ST_N; ++x) {
                float u = (float)x / ST_N - 0.5f, v = (float)y / ST_N - 0.5f, w = (float)z / ST_N - 0.5f;
                float r = sqrtf(u * u + v * v + w * w);
                int hu = r < 0.3f ? 40 + (int)((x * 7 + y * 13 + z * 5) % 60) : r < 0.38f ? 1400 : -1000;
                size_t i = ((size_t)z * ST_N + y) * ST_N + x;
                st_i16[i] = (int16_t)hu;
                st_f32[i] = (float)hu;
            }
}

static hd_desc st_desc(hd_voxel_type type, const void *data, hd_method method, float lo, float hi)
{
    static const float tf[] = {0, 0, 0, 0, 0.9f, 0.6f, 0.5f, 0.1f, 1, 1, 0.9f, 0.9f};
    static hd_light light;
    hd_desc d = HD_DESC_INIT;
    d.volume.type = type;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = ST_N;
    d.volume.data = data;
    d.volume.value_range[0] = lo;
    d.volume.value_range[1] = hi;
    d.transfer_function.rgba = tf;
    d.transfer_function.count = 3;
    light.direction[0] = 0.3f; light.direction[1] = -1.0f; light.direction[2] = 0.2f;
    d.lights = &light;
    d.light_count = 1;
    d.camera.eye[0] = 1.2f; d.camera.eye[1] = 0.7f; d.camera.eye[2] = 1.6f;
    d.camera.width = 64; d.camera.height = 48;
    d.params.method = method;
    d.params.seed = 7u;
    d.threads = 1;
    return d;
}

/* The image after n iterations of a context made from d (0 on failure). */
static int st_render(const hd_desc *d, int n, float *img, hd_stats *st)
{
    hd_context c;
    int ok;
    if (hd_create(d, &c) != HD_SUCCESS) return 0;
    ok = hd_iterate(c, n) == HD_SUCCESS && hd_read_image_f32(c, img, 64 * 48 * 4) == HD_SUCCESS && hd_get_stats(c, st) == HD_SUCCESS;
    hd_destroy(c);
    return ok;
}

static double st_max_diff(void)
{
    double m = 0.0;
    size_t i;
    for (i = 0; i < 64 * 48 * 4; ++i) m = fmax(m, fabs((double)st_img_a[i] - (double)st_img_b[i]));
    return m;
}

/* The same Hounsfield units as I16 and as F32, one value_range: the same image within float
   rounding (in fact bit-identical here), for HD, CD and a path tracer; a different range is a
   different image, so the comparison sees the map. */
static void storage_i16_as_f32(void)
{
    static const hd_method methods[3] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_MS};
    hd_stats a, b;
    int m;
    st_fill();
    for (m = 0; m < 3; ++m) {
        hd_desc di = st_desc(HD_VOXEL_I16, st_i16, methods[m], -1024.0f, 2000.0f);
        hd_desc df = st_desc(HD_VOXEL_F32, st_f32, methods[m], -1024.0f, 2000.0f);
        CHECK(st_render(&di, 4, st_img_a, &a) && st_render(&df, 4, st_img_b, &b));
        CHECK_MSG(st_max_diff() <= 1e-6, "%s: max |I16 - F32| %g", hd_method_name(methods[m]), st_max_diff());
        /* 2 bytes a voxel against 4 */
        CHECK(b.volume_bytes - a.volume_bytes == (size_t)ST_N * ST_N * ST_N * 2);
    }
    {
        hd_desc di = st_desc(HD_VOXEL_I16, st_i16, HD_METHOD_HD, -1024.0f, 2000.0f);
        hd_desc dj = st_desc(HD_VOXEL_I16, st_i16, HD_METHOD_HD, -1024.0f, 1000.0f);
        CHECK(st_render(&di, 4, st_img_a, &a) && st_render(&dj, 4, st_img_b, &b));
        CHECK_MSG(st_max_diff() > 1e-3, "another value_range gave the same image (%g)", st_max_diff());
    }
    /* the default range of I16 is the type's */
    {
        hd_desc di = st_desc(HD_VOXEL_I16, st_i16, HD_METHOD_HD, 0.0f, 0.0f), q;
        hd_context c;
        CHECK(hd_create(&di, &c) == HD_SUCCESS);
        CHECK(hd_query_desc(c, &q) == HD_SUCCESS && q.volume.value_range[0] == -32768.0f && q.volume.value_range[1] == 32767.0f);
        hd_destroy(c);
    }
}

/* hd_update_volume on an I16 volume: the same box given to an I16 and an F32 context keeps their
   images equal; an F32 update to the I16 context is refused. */
static void storage_i16_update(void)
{
    static int16_t box_i[6 * 5 * 4];
    static float box_f[6 * 5 * 4];
    hd_desc di, df;
    hd_context ci, cf;
    hd_volume_update u = HD_VOLUME_UPDATE_INIT;
    hd_stats st;
    int i;
    st_fill();
    di = st_desc(HD_VOXEL_I16, st_i16, HD_METHOD_HD, -1024.0f, 2000.0f);
    df = st_desc(HD_VOXEL_F32, st_f32, HD_METHOD_HD, -1024.0f, 2000.0f);
    CHECK(hd_create(&di, &ci) == HD_SUCCESS && hd_create(&df, &cf) == HD_SUCCESS);
    CHECK(hd_iterate(ci, 2) == HD_SUCCESS && hd_iterate(cf, 2) == HD_SUCCESS);
    for (i = 0; i < 6 * 5 * 4; ++i) {
        box_i[i] = (int16_t)(1800 - 30 * i);
        box_f[i] = (float)box_i[i];
    }
    u.dims[0] = u.dims[1] = u.dims[2] = ST_N;
    u.offset[0] = 3; u.offset[1] = 9; u.offset[2] = 7;
    u.size[0] = 6; u.size[1] = 5; u.size[2] = 4;
    u.type = HD_VOXEL_F32;
    u.data = box_f;
    CHECK(hd_update_volume(ci, &u) == HD_ERROR_VOLUME_MISMATCH);
    CHECK(hd_update_volume(cf, &u) == HD_SUCCESS);
    u.type = HD_VOXEL_I16;
    u.data = box_i;
    CHECK(hd_update_volume(ci, &u) == HD_SUCCESS);
    CHECK(hd_iterate(ci, 3) == HD_SUCCESS && hd_iterate(cf, 3) == HD_SUCCESS);
    CHECK(hd_read_image_f32(ci, st_img_a, 64 * 48 * 4) == HD_SUCCESS && hd_read_image_f32(cf, st_img_b, 64 * 48 * 4) == HD_SUCCESS);
    CHECK_MSG(st_max_diff() <= 1e-6, "after the update: max |I16 - F32| %g", st_max_diff());
    CHECK(hd_get_stats(ci, &st) == HD_SUCCESS && st.iterations == 5);
    hd_destroy(ci);
    hd_destroy(cf);
}

const hd_test_case hd_tests_storage[] = {
    {"storage_i16_as_f32", storage_i16_as_f32},
    {"storage_i16_update", storage_i16_update},
};
const int hd_tests_storage_count = sizeof(hd_tests_storage) / sizeof(hd_tests_storage[0]);
