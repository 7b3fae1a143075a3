/* test_io.c - the file loaders: NRRD (raw and gzip) and headerless raw volumes.
   Every file is made here, in a temporary directory or in memory; every error code the loaders
   can return is provoked and must come with a logged message. */
#include "hybriddiff.h"
#include "hd_test.h"
#include "tests/fuzz/hd_fuzz_gen.h" /* gen_cat, gen_put, gen_deflate: shared with the fuzz seeds */
#include <stdlib.h>
#include <stdint.h>
#include <limits.h>
#include <unistd.h>
#include <zlib.h>

/* ---- helpers ---------------------------------------------------------------------------------- */
/* io_log: the shared capturing logger of hd_test.h */
typedef hd_test_log io_log;
#define io_logger hd_test_logger

static char io_dir[256];

static void io_cleanup(void)
{
    if (io_dir[0]) rmdir(io_dir);
}

static const char *io_tmpdir(void)
{
    if (!io_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(io_dir, sizeof io_dir, "%s/hd_test_io_XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(io_dir)) {
            fprintf(stderr, "  mkdtemp(%s) failed\n", io_dir);
            io_dir[0] = 0;
            return "/tmp";
        }
        atexit(io_cleanup);
    }
    return io_dir;
}

static const char *io_path(const char *name)
{
    static char p[4][512];
    static int k;
    k = (k + 1) % 4;
    snprintf(p[k], sizeof p[k], "%s/%s", io_tmpdir(), name);
    return p[k];
}

static void io_remove(const char *path)
{
    remove(path);
}

static int io_write(const char *path, const void *a, size_t na, const void *b, size_t nb)
{
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f) return 0;
    ok = fwrite(a, 1, na, f) == na;
    if (nb) ok = ok && fwrite(b, 1, nb, f) == nb;
    return fclose(f) == 0 && ok;
}

/* Parses from memory and, through a file, with the file loader; both must agree. */
static hd_result io_parse_both(const unsigned char *b, size_t n, hd_volume_file *out, io_log *l)
{
    hd_logger lg = io_logger(l);
    hd_volume_file v2;
    io_log l2;
    hd_logger lg2 = io_logger(&l2);
    const char *path = io_path("both.nrrd");
    hd_result r = hd_volume_parse_nrrd(b, n, out, &lg), r2;
    CHECK(io_write(path, b, n, NULL, 0));
    r2 = hd_volume_load_nrrd(path, &v2, &lg2);
    CHECK_MSG(r2 == r, "file loader %s, memory parser %s", hd_result_string(r2),
              hd_result_string(r));
    if (r == HD_SUCCESS && r2 == HD_SUCCESS) {
        size_t bytes = (size_t)out->desc.dims[0] * out->desc.dims[1] * out->desc.dims[2] *
                       (out->desc.type == HD_VOXEL_U8 ? 1 : out->desc.type == HD_VOXEL_U16 || out->desc.type == HD_VOXEL_I16 ? 2 : 4);
        CHECK(v2.desc.type == out->desc.type);
        CHECK(memcmp(v2.desc.dims, out->desc.dims, sizeof v2.desc.dims) == 0);
        CHECK(memcmp(v2.desc.spacing, out->desc.spacing, sizeof v2.desc.spacing) == 0);
        CHECK(memcmp(v2.data, out->data, bytes) == 0);
    } else {
        CHECK(l2.errors >= 1 && strstr(l2.last, "both.nrrd") != NULL); /* path in the message */
    }
    hd_volume_free(&v2);
    io_remove(path);
    return r;
}

/* An error case: the code, a logged message, and an empty output. */
#define IO_EXPECT(r, want, log) \
    do { \
        CHECK_MSG((r) == (want), "got %s, want %s", hd_result_string(r), \
                  hd_result_string(want)); \
        CHECK_MSG((log).errors >= 1 && (log).last[0], "no message logged"); \
        CHECK((log).last_code == (want)); \
    } while (0)

static hd_result io_parse_text(const char *text, io_log *l)
{
    hd_volume_file v;
    size_t n;
    unsigned char *b = gen_cat(text, NULL, 0, &n);
    hd_result r = io_parse_both(b, n, &v, l);
    CHECK(v.data == NULL || r == HD_SUCCESS);
    hd_volume_free(&v);
    free(b);
    return r;
}

/* ---- successful loads ------------------------------------------------------------------------- */
static void io_nrrd_roundtrip(void)
{
    unsigned char data[4 * 3 * 2];
    hd_volume_file v;
    io_log l;
    size_t n, i;
    unsigned char *b;
    for (i = 0; i < sizeof data; ++i) data[i] = (unsigned char)(10 + i * 7);
    b = gen_cat("NRRD0004\n# a comment\ntype: uchar\ndimension: 3\nsizes: 4 3 2\n"
                "spacings: 0.5 1 2.25\nencoding: raw\ncontent:=anything at all\n\n",
                data, sizeof data, &n);
    CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
    CHECK(l.errors == 0);
    CHECK(v.desc.type == HD_VOXEL_U8);
    CHECK(v.desc.dims[0] == 4 && v.desc.dims[1] == 3 && v.desc.dims[2] == 2);
    CHECK(v.desc.spacing[0] == 0.5f && v.desc.spacing[1] == 1.0f && v.desc.spacing[2] == 2.25f);
    CHECK(v.data != NULL && v.desc.data == v.data);
    CHECK(v.data && memcmp(v.data, data, sizeof data) == 0);
    CHECK(v.value_min == 10.0f && v.value_max == 10.0f + 23 * 7);
    CHECK(v.desc.value_range[0] == v.value_min && v.desc.value_range[1] == v.value_max);
    hd_volume_free(&v);
    CHECK(v.data == NULL);
    hd_volume_free(&v); /* twice is harmless */
    hd_volume_free(NULL);
    free(b);
}

static void io_nrrd_type_spellings(void)
{
    static const char *u8[] = {"uchar", "unsigned char", "uint8", "uint8_t", "UCHAR"};
    static const char *i16[] = {"short", "short int", "signed short", "signed short int",
                                "int16", "int16_t", "signed char", "int8"};
    static const char *u16[] = {"ushort", "unsigned short", "unsigned short int", "uint16",
                                "uint16_t"};
    static const char *i32[] = {"int", "signed int", "int32", "int32_t"};
    static const char *f32[] = {"float", "double", "uint", "uint32", "longlong", "int64",
                                "ulonglong", "uint64_t"};
    char text[256];
    size_t i;
    hd_volume_file v;
    io_log l;
    hd_logger lg;
    unsigned char data[64];
    memset(data, 0, sizeof data);
#define IO_TYPE_CASE(list, want) \
    for (i = 0; i < sizeof list / sizeof list[0]; ++i) { \
        size_t n; \
        unsigned char *b; \
        snprintf(text, sizeof text, "NRRD0004\ntype:   %s \ndimension: 3\nsizes: 2 2 2\n" \
                 "endian: little\nencoding: raw\n\n", list[i]); \
        b = gen_cat(text, data, sizeof data, &n); \
        lg = io_logger(&l); \
        CHECK_MSG(hd_volume_parse_nrrd(b, n, &v, &lg) == HD_SUCCESS, "type '%s': %s", list[i], \
                  l.last); \
        CHECK_MSG(v.desc.type == (want), "type '%s'", list[i]); \
        hd_volume_free(&v); \
        free(b); \
    }
    IO_TYPE_CASE(u8, HD_VOXEL_U8)
    IO_TYPE_CASE(u16, HD_VOXEL_U16)
    IO_TYPE_CASE(i16, HD_VOXEL_I16)
    IO_TYPE_CASE(i32, HD_VOXEL_F32)
    IO_TYPE_CASE(f32, HD_VOXEL_F32)
#undef IO_TYPE_CASE
}

static void io_nrrd_u16_endian(void)
{
    static const uint16_t vals[6] = {0, 1, 0x1234, 0xfedc, 65535, 300};
    int big;
    for (big = 0; big < 2; ++big) {
        unsigned char data[12];
        hd_volume_file v;
        io_log l;
        size_t n;
        int i;
        unsigned char *b;
        char text[200];
        for (i = 0; i < 6; ++i) gen_put(data + 2 * i, vals[i], 2, big);
        snprintf(text, sizeof text,
                 "NRRD0005\ntype: unsigned short\ndimension: 3\nsizes: 3 2 1\nendian: %s\n"
                 "encoding: raw\n\n", big ? "big" : "little");
        b = gen_cat(text, data, sizeof data, &n);
        CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
        CHECK(v.desc.type == HD_VOXEL_U16);
        if (v.data) {
            const uint16_t *d = (const uint16_t *)v.data;
            for (i = 0; i < 6; ++i) CHECK_MSG(d[i] == vals[i], "%s endian voxel %d: %u",
                                              big ? "big" : "little", i, d[i]);
        }
        CHECK(v.value_min == 0.0f && v.value_max == 65535.0f);
        hd_volume_free(&v);
        free(b);
    }
}

static void io_nrrd_int16_kept(void)
{
    static const int16_t vals[8] = {-1024, -1, 0, 1, 3071, -32768, 32767, 40};
    int big;
    for (big = 0; big < 2; ++big) {
        unsigned char data[16];
        hd_volume_file v;
        io_log l;
        size_t n;
        int i;
        unsigned char *b;
        char text[256];
        for (i = 0; i < 8; ++i) gen_put(data + 2 * i, (uint16_t)vals[i], 2, big);
        snprintf(text, sizeof text,
                 "NRRD0004\r\ntype: int16\r\ndimension: 3\r\nsizes: 2 2 2\r\n"
                 "space: left-posterior-superior\r\n"
                 "space directions: (0.5,0,0) (0, 0.6, 0.8) (0,0,-3)\r\n"
                 "endian: %s\r\nencoding: raw\r\n\r\n", big ? "big" : "little");
        b = gen_cat(text, data, sizeof data, &n);
        CHECK_MSG(io_parse_both(b, n, &v, &l) == HD_SUCCESS, "%s", l.last);
        CHECK(v.desc.type == HD_VOXEL_I16);
        if (v.data)
            for (i = 0; i < 8; ++i) CHECK(((const int16_t *)v.data)[i] == vals[i]);
        CHECK(v.value_min == -32768.0f && v.value_max == 32767.0f);
        CHECK(v.desc.value_range[0] == -32768.0f && v.desc.value_range[1] == 32767.0f);
        CHECK(fabsf(v.desc.spacing[0] - 0.5f) < 1e-6f);
        CHECK(fabsf(v.desc.spacing[1] - 1.0f) < 1e-6f);
        CHECK(fabsf(v.desc.spacing[2] - 3.0f) < 1e-6f);
        hd_volume_free(&v);
        free(b);
    }
}

static void io_nrrd_float_double(void)
{
    static const float fv[4] = {-2.5f, 0.0f, 1e-3f, 12345.75f};
    unsigned char data[32];
    hd_volume_file v;
    io_log l;
    size_t n;
    int i;
    unsigned char *b;
    uint32_t u;
    uint64_t u64;
    for (i = 0; i < 4; ++i) {
        memcpy(&u, &fv[i], 4);
        gen_put(data + 4 * i, u, 4, 0);
    }
    b = gen_cat("NRRD0004\ntype: float\ndimension: 2\nsizes: 2 2\nspacings: 2 3\n"
                "endian: little\nencoding: raw\n\n", data, 16, &n);
    CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
    CHECK(v.desc.type == HD_VOXEL_F32);
    CHECK(v.desc.dims[0] == 2 && v.desc.dims[1] == 2 && v.desc.dims[2] == 1);
    CHECK(v.desc.spacing[0] == 2.0f && v.desc.spacing[1] == 3.0f && v.desc.spacing[2] == 1.0f);
    if (v.data) CHECK(memcmp(v.data, fv, sizeof fv) == 0);
    CHECK(v.value_min == -2.5f && v.value_max == 12345.75f);
    hd_volume_free(&v);
    free(b);

    for (i = 0; i < 4; ++i) {
        double d = (double)fv[i];
        memcpy(&u64, &d, 8);
        gen_put(data + 8 * i, u64, 8, 1);
    }
    b = gen_cat("NRRD0004\ntype: double\ndimension: 1\nsizes: 4\nendian: big\nencoding: raw\n\n",
                data, 32, &n);
    CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
    CHECK(v.desc.dims[0] == 4 && v.desc.dims[1] == 1 && v.desc.dims[2] == 1);
    if (v.data) CHECK(memcmp(v.data, fv, sizeof fv) == 0);
    hd_volume_free(&v);
    free(b);
}

static void io_nrrd_nonfinite_and_constant(void)
{
    unsigned char data[16];
    float f[4];
    hd_volume_file v;
    io_log l;
    hd_logger lg = io_logger(&l);
    size_t n;
    int i;
    unsigned char *b;
    f[0] = 7.0f; f[1] = NAN; f[2] = 7.0f; f[3] = HUGE_VALF;
    for (i = 0; i < 4; ++i) {
        uint32_t u;
        memcpy(&u, &f[i], 4);
        gen_put(data + 4 * i, u, 4, 0);
    }
    b = gen_cat("NRRD0004\ntype: float\ndimension: 3\nsizes: 4 1 1\nendian: little\n"
                "encoding: raw\n\n", data, 16, &n);
    CHECK(hd_volume_parse_nrrd(b, n, &v, &lg) == HD_SUCCESS);
    CHECK(l.warnings == 1); /* non-finite values replaced by 0 */
    if (v.data) CHECK(((const float *)v.data)[1] == 0.0f && ((const float *)v.data)[3] == 0.0f);
    CHECK(v.value_min == 0.0f && v.value_max == 7.0f);
    hd_volume_free(&v);
    free(b);

    memset(data, 42, sizeof data); /* constant: the range is never empty */
    b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 2 2\nencoding: raw\n\n", data, 16,
                &n);
    CHECK(hd_volume_parse_nrrd(b, n, &v, &lg) == HD_SUCCESS);
    CHECK(v.value_min == 42.0f && v.value_max == 42.0f);
    CHECK(v.desc.value_range[0] == 42.0f && v.desc.value_range[1] > 42.0f);
    hd_volume_free(&v);
    free(b);
}

static void io_nrrd_skips(void)
{
    unsigned char data[8 + 8];
    hd_volume_file v;
    io_log l;
    size_t n, i;
    unsigned char *b;
    for (i = 0; i < sizeof data; ++i) data[i] = (unsigned char)i;
    /* byte skip 8: the data are bytes 8..15 */
    b = gen_cat("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nbyte skip: 8\n"
                "encoding: raw\n\n", data, sizeof data, &n);
    CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
    if (v.data) CHECK(((const unsigned char *)v.data)[0] == 8);
    hd_volume_free(&v);
    free(b);
    /* byte skip -1: the data are the last bytes */
    b = gen_cat("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 1\nbyteskip: -1\n"
                "encoding: raw\n\n", data, sizeof data, &n);
    CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
    if (v.data) CHECK(((const unsigned char *)v.data)[0] == 12);
    hd_volume_free(&v);
    free(b);
    /* line skip 1 */
    b = gen_cat("NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nline skip: 1\n"
                "encoding: raw\n\nskip me\n", data, 8, &n);
    CHECK(io_parse_both(b, n, &v, &l) == HD_SUCCESS);
    if (v.data) CHECK(memcmp(v.data, data, 8) == 0);
    hd_volume_free(&v);
    free(b);
}

static void io_nrrd_gzip(void)
{
    enum { NX = 20, NY = 17, NZ = 9 };
    static int16_t vals[NX * NY * NZ];
    unsigned char raw[sizeof vals];
    const char *header = "NRRD0004\ntype: short\ndimension: 3\nsizes: 20 17 9\n"
                         "spacings: 1 1 1.5\nendian: big\nencoding: gzip\n\n";
    const char *path = io_path("gz.nrrd");
    size_t i, zn = 0, n;
    unsigned char *z, *b;
    hd_volume_file v;
    io_log l;
    hd_logger lg = io_logger(&l);
    gzFile gz;
    for (i = 0; i < NX * NY * NZ; ++i) {
        vals[i] = (int16_t)((int)(i * 37 % 4096) - 1024);
        gen_put(raw + 2 * i, (uint16_t)vals[i], 2, 1);
    }
    /* in memory, through deflate */
    z = gen_deflate(raw, sizeof raw, 1, &zn);
    CHECK(z != NULL);
    b = gen_cat(header, z, zn, &n);
    CHECK_MSG(io_parse_both(b, n, &v, &l) == HD_SUCCESS, "%s", l.last);
    CHECK(v.desc.type == HD_VOXEL_I16 && v.desc.spacing[2] == 1.5f);
    if (v.data)
        for (i = 0; i < NX * NY * NZ; ++i) CHECK(((const int16_t *)v.data)[i] == vals[i]);
    CHECK(v.value_min == -1024.0f && v.value_max == 3071.0f);
    hd_volume_free(&v);
    free(b);
    free(z);

    /* on disk, through gzopen appending a gzip member after the header; "gz" spelling */
    {
        const char *h2 = "NRRD0004\ntype: int16\ndimension: 3\nsizes: 20 17 9\nendian: big\n"
                         "encoding: gz\n\n";
        CHECK(io_write(path, h2, strlen(h2), NULL, 0));
    }
    gz = gzopen(path, "ab");
    CHECK(gz != NULL);
    if (gz) {
        CHECK(gzwrite(gz, raw, (unsigned)sizeof raw) == (int)sizeof raw);
        gzclose(gz);
    }
    CHECK_MSG(hd_volume_load_nrrd(path, &v, &lg) == HD_SUCCESS, "%s", l.last);
    if (v.data)
        for (i = 0; i < NX * NY * NZ; ++i) CHECK(((const int16_t *)v.data)[i] == vals[i]);
    hd_volume_free(&v);
    io_remove(path);
}

static void io_raw_loader(void)
{
    const char *path = io_path("vol.raw");
    unsigned char buf[5 + 2 * 24];
    int dims[3] = {4, 3, 2};
    hd_volume_file v;
    io_log l;
    hd_logger lg = io_logger(&l);
    int i;
    memset(buf, 0xee, 5); /* a 5-byte header to skip */
    for (i = 0; i < 24; ++i) gen_put(buf + 5 + 2 * i, (uint16_t)(i * 1000 - 5000), 2, 1);
    CHECK(io_write(path, buf, sizeof buf, NULL, 0));

    CHECK(hd_volume_load_raw(path, dims, HD_RAW_I16, HD_ENDIAN_BIG, 5, &v, &lg) == HD_SUCCESS);
    CHECK(v.desc.type == HD_VOXEL_I16 && v.desc.dims[0] == 4 && v.desc.dims[2] == 2);
    CHECK(v.desc.spacing[0] == 1.0f && v.desc.spacing[1] == 1.0f && v.desc.spacing[2] == 1.0f);
    if (v.data)
        for (i = 0; i < 24; ++i) CHECK(((const int16_t *)v.data)[i] == i * 1000 - 5000);
    CHECK(v.value_min == -5000.0f && v.value_max == 18000.0f);
    CHECK(v.desc.value_range[0] == -5000.0f && v.desc.value_range[1] == 18000.0f);
    hd_volume_free(&v);

    CHECK(hd_volume_load_raw(path, dims, HD_RAW_U16, HD_ENDIAN_BIG, 5, &v, &lg) == HD_SUCCESS);
    CHECK(v.desc.type == HD_VOXEL_U16);
    if (v.data) CHECK(((const uint16_t *)v.data)[1] == (uint16_t)(1000 - 5000));
    hd_volume_free(&v);

    CHECK(hd_volume_load_raw(path, dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, &v, &lg) == HD_SUCCESS);
    CHECK(v.desc.type == HD_VOXEL_U8);
    if (v.data) CHECK(memcmp(v.data, buf, 24) == 0);
    hd_volume_free(&v);

    dims[0] = 3; dims[1] = 1; dims[2] = 2; /* 6 f64 = 48 bytes after the 5 */
    CHECK(hd_volume_load_raw(path, dims, HD_RAW_F64, HD_ENDIAN_LITTLE, 5, &v, &lg) == HD_SUCCESS);
    CHECK(v.desc.type == HD_VOXEL_F32);
    hd_volume_free(&v);
    CHECK(l.errors == 0);
    io_remove(path);
}

/* ---- errors ----------------------------------------------------------------------------------- */
static void io_error_file_io(void)
{
    hd_volume_file v;
    io_log l;
    hd_logger lg = io_logger(&l);
    int dims[3] = {1, 1, 1};
    hd_result r = hd_volume_load_nrrd(io_path("does-not-exist.nrrd"), &v, &lg);
    IO_EXPECT(r, HD_ERROR_FILE_IO, l);
    CHECK(strstr(l.last, "does-not-exist.nrrd") != NULL);
    CHECK(v.data == NULL);
    lg = io_logger(&l);
    r = hd_volume_load_raw(io_path("does-not-exist.raw"), dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, &v,
                           &lg);
    IO_EXPECT(r, HD_ERROR_FILE_IO, l);
    lg = io_logger(&l); /* a directory is refused before it is opened */
    r = hd_volume_load_nrrd(io_tmpdir(), &v, &lg);
    IO_EXPECT(r, HD_ERROR_FILE_NOT_REGULAR, l);
    /* silent without a logger, still the same code */
    CHECK(hd_volume_load_nrrd(io_path("does-not-exist.nrrd"), &v, NULL) == HD_ERROR_FILE_IO);
}

static void io_error_null(void)
{
    hd_volume_file v;
    io_log l;
    hd_logger lg = io_logger(&l);
    int dims[3] = {1, 1, 1};
    hd_result r = hd_volume_parse_nrrd(NULL, 10, &v, &lg);
    IO_EXPECT(r, HD_ERROR_NULL_POINTER, l);
    lg = io_logger(&l);
    r = hd_volume_parse_nrrd("NRRD0004\n", 9, NULL, &lg);
    IO_EXPECT(r, HD_ERROR_NULL_POINTER, l);
    lg = io_logger(&l);
    r = hd_volume_load_nrrd(NULL, &v, &lg);
    IO_EXPECT(r, HD_ERROR_NULL_POINTER, l);
    lg = io_logger(&l);
    r = hd_volume_load_raw("x", NULL, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, &v, &lg);
    IO_EXPECT(r, HD_ERROR_NULL_POINTER, l);
    lg = io_logger(&l);
    r = hd_volume_load_raw("x", dims, HD_RAW_TYPE_COUNT, HD_ENDIAN_LITTLE, 0, &v, &lg);
    IO_EXPECT(r, HD_ERROR_INVALID_ENUM, l);
    lg = io_logger(&l);
    r = hd_volume_load_raw("x", dims, HD_RAW_U8, (hd_endian)7, 0, &v, &lg);
    IO_EXPECT(r, HD_ERROR_INVALID_ENUM, l);
}

static void io_error_format(void)
{
    static const char *bad[] = {
        "",
        "NRRD",
        "NRRD000",
        "nrrd0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",
        "NRRDXXXX\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",
        "P6\n1 1\n255\n",
        "NRRD0004\ntype uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",      /* no ':' */
        "NRRD0004\n: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",          /* no name */
        "NRRD0004\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",                   /* no type */
        "NRRD0004\ntype: uchar\nsizes: 1 1 1\nencoding: raw\n\n",                    /* no dim */
        "NRRD0004\ntype: uchar\ndimension: 3\nencoding: raw\n\n",                    /* no sizes */
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\n\n",                     /* no enc */
        "NRRD0004\ntype: uchar\ndimension: three\nsizes: 1 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 x 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1.5 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 a 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspace directions: (1,0,0) (0,1,0)\n"
        "encoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspace directions: (1,0,0) (0,1,0) "
        "(0,0,1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nendian: middle\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nbyte skip: -2\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nline skip: -1\nencoding: raw\n\n",
    };
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        io_log l;
        hd_result r = io_parse_text(bad[i], &l);
        CHECK_MSG(r == HD_ERROR_FILE_FORMAT, "case %d: got %s (%s)", (int)i, hd_result_string(r),
                  l.last);
        CHECK_MSG(l.errors >= 1 && l.last[0], "case %d: no message", (int)i);
    }
}

static void io_error_dimensions(void)
{
    static const char *bad[] = {
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 0 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 -3 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8193 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 100000 100000 100000\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 4\nsizes: 1 1 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 0\nsizes: 1\nencoding: raw\n\n",
    };
    size_t i;
    int dims[3] = {4, 0, 1};
    hd_volume_file v;
    io_log l;
    hd_logger lg;
    hd_result r;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        r = io_parse_text(bad[i], &l);
        CHECK_MSG(r == HD_ERROR_INVALID_DIMENSIONS, "case %d: got %s (%s)", (int)i,
                  hd_result_string(r), l.last);
        CHECK_MSG(l.errors >= 1 && l.last[0], "case %d: no message", (int)i);
    }
    lg = io_logger(&l);
    r = hd_volume_load_raw(io_path("never-opened.raw"), dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, &v,
                           &lg);
    IO_EXPECT(r, HD_ERROR_INVALID_DIMENSIONS, l);
    dims[1] = HD_MAX_DIM + 1;
    lg = io_logger(&l);
    r = hd_volume_load_raw(io_path("never-opened.raw"), dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, &v,
                           &lg);
    IO_EXPECT(r, HD_ERROR_INVALID_DIMENSIONS, l);
}

static void io_error_size_overflow(void)
{
    static const char *bad[] = {
        "NRRD0004\ntype: double\ndimension: 3\nsizes: 4294967296 4294967296 4294967296\n"
        "endian: little\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 99999999999999999999999999 1 1\n"
        "encoding: raw\n\n",
    };
    size_t i;
    int dims[3] = {INT_MAX, INT_MAX, INT_MAX};
    hd_volume_file v;
    io_log l;
    hd_logger lg;
    hd_result r;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        r = io_parse_text(bad[i], &l);
        CHECK_MSG(r == HD_ERROR_SIZE_OVERFLOW, "case %d: got %s (%s)", (int)i, hd_result_string(r),
                  l.last);
        CHECK_MSG(l.errors >= 1 && l.last[0], "case %d: no message", (int)i);
    }
    lg = io_logger(&l);
    r = hd_volume_load_raw(io_path("never-opened.raw"), dims, HD_RAW_F64, HD_ENDIAN_LITTLE, 0, &v,
                           &lg);
    IO_EXPECT(r, HD_ERROR_SIZE_OVERFLOW, l);
    dims[0] = dims[1] = dims[2] = 2; /* offset + bytes overflow */
    lg = io_logger(&l);
    r = hd_volume_load_raw(io_path("never-opened.raw"), dims, HD_RAW_U8, HD_ENDIAN_LITTLE,
                           SIZE_MAX - 3, &v, &lg);
    IO_EXPECT(r, HD_ERROR_SIZE_OVERFLOW, l);
}

static void io_error_spacing(void)
{
    static const char *bad[] = {
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 -1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 1 0\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: nan 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 inf 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 1 1e999\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nspacings: 1 1 1e-300\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\n"
        "space directions: (1,0,0) (0,0,0) (0,0,1)\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\n"
        "space directions: (1,0,0) (0,1,0) (0,nan,1)\nencoding: raw\n\n",
    };
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        io_log l;
        hd_result r = io_parse_text(bad[i], &l);
        CHECK_MSG(r == HD_ERROR_INVALID_SPACING, "case %d: got %s (%s)", (int)i,
                  hd_result_string(r), l.last);
        CHECK_MSG(l.errors >= 1 && l.last[0], "case %d: no message", (int)i);
    }
}

static void io_error_unsupported(void)
{
    static const char *bad[] = {
        "NRRD0004\ntype: block\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: complex\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: bzip2\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: ascii\n\n",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nencoding: raw\ndata file: x.raw\n\n",
    };
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        io_log l;
        hd_result r = io_parse_text(bad[i], &l);
        CHECK_MSG(r == HD_ERROR_UNSUPPORTED_ENCODING, "case %d: got %s (%s)", (int)i,
                  hd_result_string(r), l.last);
        CHECK_MSG(l.errors >= 1 && l.last[0], "case %d: no message", (int)i);
    }
}

static void io_error_truncated(void)
{
    unsigned char data[1000];
    hd_volume_file v;
    io_log l;
    hd_logger lg;
    size_t n;
    unsigned char *b;
    hd_result r;
    int dims[3] = {10, 10, 10};
    const char *path = io_path("short.raw");
    memset(data, 1, sizeof data);
    /* a header that lies: 256 x 256 x 108 uchar = 7077888 bytes, 1000 present */
    b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 256 256 108\nencoding: raw\n\n",
                data, sizeof data, &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    CHECK_MSG(strstr(l.last, "7077888") && strstr(l.last, "1000"), "message: %s", l.last);
    CHECK(v.data == NULL);
    free(b);
    /* one byte short; header with no blank line and no data; byte skip past the end */
    b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10 10 10\nencoding: raw\n\n", data,
                999, &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    free(b);
    r = io_parse_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10 10 10\nencoding: raw\n", &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    r = io_parse_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nbyte skip: 5000\n"
                      "encoding: raw\n\n", &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    r = io_parse_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 1\nline skip: 3\n"
                      "encoding: raw\n\nx\n", &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    /* raw loader */
    CHECK(io_write(path, data, 999, NULL, 0));
    lg = io_logger(&l);
    r = hd_volume_load_raw(path, dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, &v, &lg);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    CHECK(v.data == NULL);
    lg = io_logger(&l);
    dims[0] = 9;
    r = hd_volume_load_raw(path, dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 100, &v, &lg);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    lg = io_logger(&l);
    dims[0] = HD_MAX_DIM; dims[1] = HD_MAX_DIM; dims[2] = HD_MAX_DIM; /* 4 TB: no allocation */
    r = hd_volume_load_raw(path, dims, HD_RAW_F64, HD_ENDIAN_LITTLE, 0, &v, &lg);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    io_remove(path);
}

static void io_error_gzip(void)
{
    enum { N = 64 * 64 * 8 };
    static unsigned char raw[N];
    const char *header = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 64 64 8\nencoding: gzip\n\n";
    size_t i, zn = 0, n;
    unsigned char *z, *b;
    hd_volume_file v;
    io_log l;
    hd_result r;
    uint32_t s = 12345;
    for (i = 0; i < N; ++i) { /* not too compressible */
        s = s * 1664525u + 1013904223u;
        raw[i] = (unsigned char)((s >> 24) & 0x3f);
    }
    z = gen_deflate(raw, N, 1, &zn);
    CHECK(z != NULL && zn > 200);
    if (!z) return;
    /* cut in the middle of the deflate data */
    b = gen_cat(header, z, zn / 2, &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_GZIP, l);
    CHECK(v.data == NULL);
    free(b);
    /* all data there but the 8-byte trailer (CRC, size) cut */
    b = gen_cat(header, z, zn - 4, &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_GZIP, l);
    free(b);
    /* a wrong CRC */
    b = gen_cat(header, z, zn, &n);
    b[n - 6] ^= 0x55;
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_GZIP, l);
    free(b);
    /* garbage instead of a gzip stream */
    b = gen_cat(header, raw, 500, &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_GZIP, l);
    free(b);
    /* a corrupt byte inside the deflate data */
    b = gen_cat(header, z, zn, &n);
    for (i = n - zn + 20; i < n - zn + 40; ++i) b[i] ^= 0xa5;
    r = io_parse_both(b, n, &v, &l);
    CHECK_MSG(r == HD_ERROR_GZIP, "got %s", hd_result_string(r));
    free(b);
    /* a complete stream that holds less than the header claims */
    b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 64 64 9\nencoding: gzip\n\n", z, zn,
                &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    free(b);
    /* a header claiming far more than any stream of this size can hold: refused unallocated */
    b = gen_cat("NRRD0004\ntype: double\ndimension: 3\nsizes: 8192 8192 8192\nendian: big\n"
                "encoding: gzip\n\n", z, zn, &n);
    r = io_parse_both(b, n, &v, &l);
    IO_EXPECT(r, HD_ERROR_FILE_TRUNCATED, l);
    free(b);
    free(z);
}

/* Every prefix and many random corruptions of valid files: never a crash (run under ASan). */
static void io_nrrd_hostile(void)
{
    static const int16_t vals[60] = {1, -2, 3, 500};
    unsigned char data[120], gz[122], *z, *files[3], *m;
    size_t sizes[3], zn = 0, i, k;
    int f;
    uint32_t s = 99;
    const char *hdr_raw = "NRRD0004\ntype: short\ndimension: 3\nsizes: 5 4 3\nspacings: 1 2 3\n"
                          "endian: little\nencoding: raw\n\n";
    const char *hdr_gz = "NRRD0004\ntype: int16\ndimension: 3\nsizes: 5 4 3\n"
                         "space directions: (1,0,0) (0,1,0) (0,0,1)\nbyte skip: 2\n"
                         "endian: big\nencoding: gzip\n\n";
    for (i = 0; i < 60; ++i) gen_put(data + 2 * i, (uint16_t)vals[i], 2, 0);
    files[0] = gen_cat(hdr_raw, data, sizeof data, &sizes[0]);
    memset(gz, 0xab, 2); /* the 2 bytes the gzip header skips */
    memcpy(gz + 2, data, sizeof data);
    z = gen_deflate(gz, sizeof gz, 1, &zn);
    files[1] = gen_cat(hdr_gz, z, zn, &sizes[1]);
    files[2] = gen_cat("NRRD0004\ntype: uchar\ndimension: 2\nsizes: 10 6\nencoding: raw\n\n", data,
                       60, &sizes[2]);
    free(z);
    for (f = 0; f < 3; ++f) {
        hd_volume_file v;
        io_log l;
        hd_logger lg = io_logger(&l);
        CHECK(hd_volume_parse_nrrd(files[f], sizes[f], &v, &lg) == HD_SUCCESS);
        hd_volume_free(&v);
        for (i = 0; i < sizes[f]; ++i) { /* every prefix, copied so ASan sees over-reads */
            hd_result r;
            m = (unsigned char *)malloc(i ? i : 1);
            memcpy(m, files[f], i);
            lg = io_logger(&l);
            r = hd_volume_parse_nrrd(m, i, &v, &lg);
            CHECK_MSG(r != HD_SUCCESS, "file %d prefix %d accepted", f, (int)i);
            CHECK_MSG(l.errors >= 1 && v.data == NULL, "file %d prefix %d", f, (int)i);
            hd_volume_free(&v);
            free(m);
        }
        for (i = 0; i < 3000; ++i) { /* random byte edits */
            hd_result r;
            size_t edits;
            m = (unsigned char *)malloc(sizes[f]);
            memcpy(m, files[f], sizes[f]);
            s = s * 1664525u + 1013904223u;
            edits = 1 + (s >> 28) % 4;
            for (k = 0; k < edits; ++k) {
                s = s * 1664525u + 1013904223u;
                m[(s >> 8) % sizes[f]] = (unsigned char)(s >> 3);
            }
            lg = io_logger(&l);
            r = hd_volume_parse_nrrd(m, sizes[f], &v, &lg);
            CHECK(r == HD_SUCCESS ? v.data != NULL : (v.data == NULL && l.errors >= 1));
            hd_volume_free(&v);
            free(m);
        }
        free(files[f]);
    }
}

const hd_test_case hd_tests_io[] = {
    {"io_nrrd_roundtrip", io_nrrd_roundtrip},
    {"io_nrrd_type_spellings", io_nrrd_type_spellings},
    {"io_nrrd_u16_endian", io_nrrd_u16_endian},
    {"io_nrrd_int16_kept", io_nrrd_int16_kept},
    {"io_nrrd_float_double", io_nrrd_float_double},
    {"io_nrrd_nonfinite_and_constant", io_nrrd_nonfinite_and_constant},
    {"io_nrrd_skips", io_nrrd_skips},
    {"io_nrrd_gzip", io_nrrd_gzip},
    {"io_raw_loader", io_raw_loader},
    {"io_error_file_io", io_error_file_io},
    {"io_error_null", io_error_null},
    {"io_error_format", io_error_format},
    {"io_error_dimensions", io_error_dimensions},
    {"io_error_size_overflow", io_error_size_overflow},
    {"io_error_spacing", io_error_spacing},
    {"io_error_unsupported", io_error_unsupported},
    {"io_error_truncated", io_error_truncated},
    {"io_error_gzip", io_error_gzip},
    {"io_nrrd_hostile", io_nrrd_hostile},
};
const int hd_tests_io_count = sizeof(hd_tests_io) / sizeof(hd_tests_io[0]);
