/* test_vdb.c - examples/hd_vdb.cpp against files written by scripts/vdb-from-nrrd (Debian's
   python3-openvdb): the head CT as a grid holds the NRRD's voxels, spacing and a transform that
   puts voxel centres at index * spacing; the rotated, translated sparse cloud holds its NRRD's
   voxels over the active box, its transform puts every voxel centre where OpenVDB's map puts its
   index, and the library renders it there; damaged files, missing grids and grids of another
   type each fail with their own message. Run by scripts/test-vdb DIR (make test-vdb). */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "hd_vdb.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures;
#define CHECK(c, ...)                                                                              \
    do {                                                                                           \
        if (!(c)) {                                                                                \
            ++failures;                                                                            \
            printf("FAIL %s:%d: ", __FILE__, __LINE__);                                            \
            printf(__VA_ARGS__);                                                                   \
            printf("\n");                                                                          \
        }                                                                                          \
    } while (0)

static const char *dir;
static char *path(const char *name)
{
    static char p[4][1024];
    static int k;
    k = (k + 1) & 3;
    snprintf(p[k], sizeof p[k], "%s/%s", dir, name);
    return p[k];
}

/* World position of voxel v's centre through the library's box (centred, largest side 1; voxel
   centres at (i + 0.5) / n) and desc.transform. */
static void voxel_world(const hd_volume_desc *d, const int v[3], double w[3])
{
    double L = 0, b[3];
    int a, r;
    for (a = 0; a < 3; ++a) L = fmax(L, d->dims[a] * (double)d->spacing[a]);
    for (a = 0; a < 3; ++a) b[a] = ((v[a] + 0.5) / d->dims[a] - 0.5) * d->dims[a] * d->spacing[a] / L;
    for (r = 0; r < 3; ++r)
        w[r] = d->transform[12 + r] + d->transform[r] * b[0] + d->transform[4 + r] * b[1] + d->transform[8 + r] * b[2];
}

static void same_voxels(const char *what, const hd_volume_file *vdb, const hd_volume_file *nrrd)
{
    size_t n, i, bad = 0;
    int a;
    for (a = 0; a < 3; ++a) CHECK(vdb->desc.dims[a] == nrrd->desc.dims[a], "%s: dims[%d] %d vs %d", what, a, vdb->desc.dims[a], nrrd->desc.dims[a]);
    for (a = 0; a < 3; ++a)
        CHECK(fabsf(vdb->desc.spacing[a] - nrrd->desc.spacing[a]) <= 1e-6f * nrrd->desc.spacing[a], "%s: spacing[%d] %g vs %g", what, a,
              (double)vdb->desc.spacing[a], (double)nrrd->desc.spacing[a]);
    if (failures) return;
    n = (size_t)vdb->desc.dims[0] * vdb->desc.dims[1] * vdb->desc.dims[2];
    for (i = 0; i < n; ++i) {
        float f = ((const float *)vdb->desc.data)[i];
        float g = nrrd->desc.type == HD_VOXEL_F32 ? ((const float *)nrrd->desc.data)[i]
                  : nrrd->desc.type == HD_VOXEL_U16 ? (float)((const uint16_t *)nrrd->desc.data)[i]
                  : nrrd->desc.type == HD_VOXEL_U8 ? (float)((const uint8_t *)nrrd->desc.data)[i]
                  : (float)((const int16_t *)nrrd->desc.data)[i];
        bad += f != g;
    }
    CHECK(bad == 0, "%s: %zu of %zu voxels differ from the NRRD's", what, bad, n);
    printf("  %s: %dx%dx%d, voxels equal to the NRRD's, range [%g, %g]\n", what, vdb->desc.dims[0], vdb->desc.dims[1],
           vdb->desc.dims[2], (double)vdb->value_min, (double)vdb->value_max);
}

static void head(void)
{
    hd_volume_file v, n;
    char err[512];
    int ok, c, a;
    ok = hdx_vdb_load(path("head.vdb"), &v, err, sizeof err);
    CHECK(ok, "head.vdb: %s", err);
    if (!ok) return;
    CHECK(hd_volume_load("data/head.nrrd", &n, NULL) == HD_SUCCESS,
          "data/head.nrrd does not load");
    same_voxels("head.vdb (grid 'density' after a bool grid)", &v, &n);
    /* corners and the centre: voxel centres at index * spacing */
    for (c = 0; c < 3; ++c) {
        int vx[3];
        double w[3];
        for (a = 0; a < 3; ++a) vx[a] = c == 0 ? 0 : c == 1 ? v.desc.dims[a] - 1 : v.desc.dims[a] / 2;
        voxel_world(&v.desc, vx, w);
        for (a = 0; a < 3; ++a)
            CHECK(fabs(w[a] - vx[a] * (double)v.desc.spacing[a]) <= 1e-4, "head: voxel (%d,%d,%d) axis %d at %g, expected %g", vx[0], vx[1],
                  vx[2], a, w[a], vx[a] * (double)v.desc.spacing[a]);
    }
    hd_volume_free(&v);
    hd_volume_free(&n);
}

static void cloud(void)
{
    hd_volume_file v, n;
    char err[512];
    int lo[3], hi[3], ok, a, k;
    double worst = 0;
    FILE *f = fopen(path("cloud.box"), "r");
    CHECK(f && fscanf(f, "%d %d %d %d %d %d", &lo[0], &lo[1], &lo[2], &hi[0], &hi[1], &hi[2]) == 6, "cloud.box unreadable");
    if (f) fclose(f);
    ok = hdx_vdb_load(path("cloud.vdb"), &v, err, sizeof err);
    CHECK(ok, "cloud.vdb: %s", err);
    if (!ok || failures) return;
    CHECK(hd_volume_load(path("cloud.nrrd"), &n, NULL) == HD_SUCCESS, "cloud.nrrd does not load");
    same_voxels("cloud.vdb", &v, &n);
    for (a = 0; a < 3; ++a) CHECK(v.desc.dims[a] == hi[a] - lo[a] + 1, "cloud: dims[%d] %d, active box %d..%d", a, v.desc.dims[a], lo[a], hi[a]);
    /* every 97th voxel: its world position by OpenVDB's map, world = index * M (row vectors),
       M = [[c s 0] [-s c 0] [0 0 0.05]] * 0.05 scale, translation (3, 1, -2) */
    for (k = 0; k < v.desc.dims[0] * v.desc.dims[1] * v.desc.dims[2]; k += 97) {
        int vx[3] = {k % v.desc.dims[0], k / v.desc.dims[0] % v.desc.dims[1], k / v.desc.dims[0] / v.desc.dims[1]};
        double w[3], e[3], ix = lo[0] + vx[0], iy = lo[1] + vx[1], iz = lo[2] + vx[2];
        double c = cos(30.0 * 3.14159265358979323846 / 180.0) * 0.05, s = sin(30.0 * 3.14159265358979323846 / 180.0) * 0.05;
        e[0] = ix * c - iy * s + 3.0;
        e[1] = ix * s + iy * c + 1.0;
        e[2] = iz * 0.05 - 2.0;
        voxel_world(&v.desc, vx, w);
        for (a = 0; a < 3; ++a) worst = fmax(worst, fabs(w[a] - e[a]));
    }
    CHECK(worst <= 1e-4, "cloud: voxel centres up to %g world units from OpenVDB's", worst);
    printf("  cloud.vdb: voxel centres within %.2g of OpenVDB's index-to-world map\n", worst);

    /* the library places it there: a camera looking at the cloud's world centre sees it, one
       looking at the point opposite it through the origin sees nothing */
    {
        hd_desc d = HD_DESC_INIT;
        hd_context ctx;
        hd_result r;
        float ctr[3], rgba_c[4 * 32 * 32];
        int view, centre_lit[2] = {0, 0};
        int mid[3] = {v.desc.dims[0] / 2, v.desc.dims[1] / 2, v.desc.dims[2] / 2};
        double w[3];
        voxel_world(&v.desc, mid, w);
        for (a = 0; a < 3; ++a) ctr[a] = (float)w[a];
        d.volume = v.desc;
        d.camera.width = d.camera.height = 32;
        d.params.illumination_downsample = 4;
        d.threads = 1;
        for (view = 0; view < 2; ++view) {
            d.camera.target[0] = view ? -ctr[0] : ctr[0];
            d.camera.target[1] = view ? -ctr[1] : ctr[1];
            d.camera.target[2] = view ? -ctr[2] : ctr[2];
            d.camera.fov_y = view ? 20.0f : 40.0f;
            d.camera.eye[0] = d.camera.target[0];
            d.camera.eye[1] = d.camera.target[1];
            d.camera.eye[2] = d.camera.target[2] + 8.0f;
            r = hd_create(&d, &ctx);
            CHECK(r == HD_SUCCESS, "hd_create with the cloud's transform: %s", hd_result_string(r));
            if (r != HD_SUCCESS) break;
            CHECK(hd_render(ctx) == HD_SUCCESS, "hd_render");
            CHECK(hd_read_image_f32(ctx, rgba_c, sizeof rgba_c / sizeof rgba_c[0]) == HD_SUCCESS, "read");
            for (k = 0; k < 32 * 32; ++k) centre_lit[view] += rgba_c[4 * k + 3] > 0.05f;
            hd_destroy(ctx);
        }
        CHECK(centre_lit[0] > 100, "camera at the cloud's world centre: %d of 1024 pixels covered", centre_lit[0]);
        CHECK(centre_lit[1] == 0, "camera at the opposite point: %d pixels covered (the cloud is not there)", centre_lit[1]);
        printf("  cloud placed: %d of 1024 pixels covered looking at its world centre, %d opposite\n", centre_lit[0], centre_lit[1]);
    }
    hd_volume_free(&v);
    hd_volume_free(&n);
}

static void expect_fail(const char *what, const char *file, const char *message)
{
    hd_volume_file v;
    char err[512] = "";
    int ok = hdx_vdb_load(file, &v, err, sizeof err);
    CHECK(!ok, "%s: loaded", what);
    CHECK(strstr(err, message) != NULL, "%s: '%s', expected '%s'", what, err, message);
    if (ok) hd_volume_free(&v);
    else printf("  %s: %s\n", what, err);
}

int main(int argc, char **argv)
{
    char cut[1024];
    dir = argc > 1 ? argv[1] : "build/vdb";
    head();
    cloud();
    expect_fail("no such grid", path("head.vdb:nothing"), "no grid named 'nothing' (the file has ");
    expect_fail("no such grid, the grids named", path("head.vdb:nothing"), "mask (bool)");
    expect_fail("a bool grid", path("head.vdb:mask"), "grid 'mask' holds bool values, not float");
    expect_fail("junk after the magic number", path("junk.vdb"), "junk.vdb: the file holds no grid");
    expect_fail("not OpenVDB", path("notvdb.vdb"), "notvdb.vdb: OpenVDB: ");
    snprintf(cut, sizeof cut, "%s", path("head-cut.vdb"));
    expect_fail("truncated file", cut, "head-cut.vdb: ");
    expect_fail("empty file", path("empty.vdb"), "empty file");
    expect_fail("a folder", path("folder.vdb"), "not a regular file");
    expect_fail("missing file", path("none.vdb"), "No such file");
    printf(failures ? "test_vdb: %d failures\n" : "test_vdb: passed\n", failures);
    return failures != 0;
}
