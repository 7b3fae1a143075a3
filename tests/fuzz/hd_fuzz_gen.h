/* hd_fuzz_gen.h - small valid NIfTI-1, MetaImage and NRRD files made in memory: shared by
   tests/test_io_formats.c and tests/fuzz/make_seeds.c (the fuzzers' seed corpora), so the seeds
   are the files the unit tests prove valid. Static functions only; needs zlib. */
#ifndef HD_FUZZ_GEN_H
#define HD_FUZZ_GEN_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>
#if defined(__GNUC__) || defined(__clang__)
#define GEN_FN static __attribute__((unused))
#else
#define GEN_FN static
#endif

GEN_FN void gen_put(unsigned char *p, uint64_t v, int n, int big)
{
    int i;
    for (i = 0; i < n; ++i) p[big ? n - 1 - i : i] = (unsigned char)(v >> (8 * i));
}

GEN_FN void gen_putf(unsigned char *p, float f, int big)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    gen_put(p, u, 4, big);
}

/* A .nii: 348-byte header, 4 bytes of extension flag, then nbytes of data (already in the
   file's byte order). dim: dim[0..ndim-1] are the sizes. malloc'd; *size set. */
GEN_FN unsigned char *gen_nifti(int big, int datatype, int bitpix, int ndim, const int *dim,
                                const float pixdim[3], float vox_offset, float slope, float inter,
                                const void *data, size_t nbytes, size_t *size)
{
    /* the data go at vox_offset when it is sane, else at 352 (a lying header) */
    size_t off = vox_offset >= 352.0f && vox_offset <= 4096.0f ? (size_t)vox_offset : 352;
    unsigned char *b = (unsigned char *)calloc(1, off + nbytes + 1);
    int i;
    gen_put(b, 348, 4, big);
    gen_put(b + 40, (uint64_t)ndim, 2, big);
    for (i = 1; i <= 7; ++i) gen_put(b + 40 + 2 * i, (uint64_t)(uint16_t)(i <= ndim ? dim[i - 1] : 1), 2, big);
    gen_put(b + 70, (uint64_t)datatype, 2, big);
    gen_put(b + 72, (uint64_t)bitpix, 2, big);
    gen_putf(b + 76, 1.0f, big); /* qfac */
    for (i = 0; i < 3; ++i) gen_putf(b + 80 + 4 * i, pixdim[i], big);
    gen_putf(b + 108, vox_offset, big);
    gen_putf(b + 112, slope, big);
    gen_putf(b + 116, inter, big);
    memcpy(b + 344, "n+1", 4);
    if (nbytes) memcpy(b + off, data, nbytes);
    *size = off + nbytes;
    return b;
}

/* deflate: gzip member (gzip = 1) or zlib stream, malloc'd */
GEN_FN unsigned char *gen_deflate(const void *data, size_t n, int gzip, size_t *out_n)
{
    z_stream zs;
    size_t cap = n + n / 100 + 64;
    unsigned char *out = (unsigned char *)malloc(cap);
    memset(&zs, 0, sizeof zs);
    if (deflateInit2(&zs, 9, Z_DEFLATED, gzip ? 15 + 16 : 15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        free(out);
        return NULL;
    }
    zs.next_in = (Bytef *)data;
    zs.avail_in = (uInt)n;
    zs.next_out = out;
    zs.avail_out = (uInt)cap;
    if (deflate(&zs, Z_FINISH) != Z_STREAM_END) {
        deflateEnd(&zs);
        free(out);
        return NULL;
    }
    *out_n = cap - zs.avail_out;
    deflateEnd(&zs);
    return out;
}

/* header text followed by n bytes, malloc'd */
GEN_FN unsigned char *gen_cat(const char *text, const void *data, size_t n, size_t *size)
{
    size_t h = strlen(text);
    unsigned char *b = (unsigned char *)malloc(h + n + 1);
    memcpy(b, text, h);
    if (n) memcpy(b + h, data, n);
    *size = h + n;
    return b;
}

#endif
