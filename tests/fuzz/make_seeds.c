/* make_seeds.c - writes the fuzzers' seed corpora: small valid NRRD, MetaImage and NIfTI-1 files
   (the generators of tests/fuzz/hd_fuzz_gen.h, which tests/test_io_formats.c proves valid).
   Usage: make_seeds DIR  ->  DIR/nrrd/, DIR/mhd/, DIR/nifti/ */
#include "tests/fuzz/hd_fuzz_gen.h"
#include <sys/stat.h>

static const char *dir;
static int failed;

static void put(const char *sub, const char *name, const void *b, size_t n)
{
    char p[1024];
    FILE *f;
    snprintf(p, sizeof p, "%s/%s/%s", dir, sub, name);
    f = fopen(p, "wb");
    if (!f || fwrite(b, 1, n, f) != n) failed = 1;
    if (f && fclose(f) != 0) failed = 1;
}

int main(int argc, char **argv)
{
    unsigned char u8[4 * 3 * 2], s16[24 * 2], s16be[24 * 2], f32[24 * 4], *b, *z;
    int dim[3] = {4, 3, 2}, dim4[4] = {2, 3, 2, 2}, i;
    float pix[3] = {1.5f, 2.0f, 3.0f};
    size_t n, zn;
    char sub[1024];
    if (argc != 2) {
        fprintf(stderr, "usage: make_seeds DIR\n");
        return 2;
    }
    dir = argv[1];
    mkdir(dir, 0755);
    for (i = 0; i < 3; ++i) {
        snprintf(sub, sizeof sub, "%s/%s", dir, i == 0 ? "nrrd" : i == 1 ? "mhd" : "nifti");
        mkdir(sub, 0755);
    }
    for (i = 0; i < 24; ++i) {
        u8[i] = (unsigned char)(i * 11);
        gen_put(s16 + 2 * i, (uint16_t)(int16_t)(i * 97 - 1000), 2, 0);
        gen_put(s16be + 2 * i, (uint16_t)(int16_t)(i * 97 - 1000), 2, 1);
        gen_putf(f32 + 4 * i, (float)i * 0.5f - 3.0f, 0);
    }
    /* NRRD */
    b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 3 2\nspacings: 1 1 2\n"
                "encoding: raw\n\n", u8, 24, &n);
    put("nrrd", "u8_raw.nrrd", b, n);
    free(b);
    b = gen_cat("NRRD0005\n# c\ntype: short\ndimension: 3\nsizes: 4 3 2\nendian: big\n"
                "space directions: (1,0,0) (0,2,0) (0,0,3)\nbyte skip: 0\nencoding: raw\n\n",
                s16be, 48, &n);
    put("nrrd", "s16_be.nrrd", b, n);
    free(b);
    z = gen_deflate(f32, 96, 1, &zn);
    b = gen_cat("NRRD0004\ntype: float\ndimension: 2\nsizes: 6 4\nendian: little\n"
                "encoding: gzip\n\n", z, zn, &n);
    put("nrrd", "f32_gz.nrrd", b, n);
    free(b);
    free(z);
    /* MetaImage: LOCAL raw, LOCAL compressed, detached (the input is also the data file) */
    b = gen_cat("ObjectType = Image\nNDims = 3\nDimSize = 4 3 2\nElementSpacing = 1 1 2\n"
                "ElementType = MET_UCHAR\nElementDataFile = LOCAL\n", u8, 24, &n);
    put("mhd", "u8_local.mha", b, n);
    free(b);
    b = gen_cat("NDims = 3\nDimSize = 4 3 2\nBinaryDataByteOrderMSB = True\n"
                "ElementType = MET_SHORT\nElementDataFile = LOCAL\n", s16be, 48, &n);
    put("mhd", "s16_be_local.mha", b, n);
    free(b);
    z = gen_deflate(f32, 96, 0, &zn);
    b = gen_cat("NDims = 2\nDimSize = 6 4\nCompressedData = True\nElementType = MET_FLOAT\n"
                "ElementDataFile = LOCAL\n", z, zn, &n);
    put("mhd", "f32_zlib_local.mha", b, n);
    free(b);
    free(z);
    b = gen_cat("NDims = 1\nDimSize = 8\nElementType = MET_USHORT\nHeaderSize = -1\n"
                "ElementDataFile = data.raw\n", NULL, 0, &n);
    put("mhd", "u16_detached.mhd", b, n);
    free(b);
    /* NIfTI-1: LE int16, BE int16, u8 scaled, 4D, float, and gzip of each */
    {
        struct { const char *name; int big, type, bits, ndim; const int *dim; float slope, inter;
                 const void *data; size_t bytes; } c[] = {
            {"s16_le", 0, 4, 16, 3, dim, 0, 0, s16, 48},
            {"s16_be", 1, 4, 16, 3, dim, 0, 0, s16be, 48},
            {"u8_scaled", 0, 2, 8, 3, dim, 2.0f, -1.0f, u8, 24},
            {"u8_4d", 0, 2, 8, 4, dim4, 0, 0, u8, 24},
            {"f32", 0, 16, 32, 3, dim, 0, 0, f32, 96},
        };
        size_t k;
        for (k = 0; k < sizeof c / sizeof c[0]; ++k) {
            char name[64];
            b = gen_nifti(c[k].big, c[k].type, c[k].bits, c[k].ndim, c[k].dim, pix, 352,
                          c[k].slope, c[k].inter, c[k].data, c[k].bytes, &n);
            snprintf(name, sizeof name, "%s.nii", c[k].name);
            put("nifti", name, b, n);
            z = gen_deflate(b, n, 1, &zn);
            snprintf(name, sizeof name, "%s.nii.gz", c[k].name);
            put("nifti", name, z, zn);
            free(z);
            free(b);
        }
    }
    if (failed) fprintf(stderr, "make_seeds: cannot write under %s\n", dir);
    return failed;
}
