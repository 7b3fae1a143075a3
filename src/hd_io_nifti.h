/* hd_io_nifti.h - the NIfTI-1 loader (.nii single file, or .nii.gz) and hd_volume_load, which
   picks a loader by the file's first bytes. Part of the implementation of hybriddiff.h; included
   once, after src/hd_io.h and src/hd_io_mhd.h, whose helpers it uses.

   NIfTI-1: the 348-byte header (little or big endian, told by sizeof_hdr), magic "n+1" (the
   two-file "ni1" form and NIfTI-2 are HD_ERROR_UNSUPPORTED_ENCODING, Analyze without a magic is
   HD_ERROR_FILE_FORMAT). dim[0] in 1..7; dims 4..7 are volumes of which the first is loaded (with
   a warning). datatype: UINT8, INT8, UINT16, INT16, UINT32, INT32, UINT64, INT64, FLOAT32,
   FLOAT64; complex, RGB and float128 are HD_ERROR_UNSUPPORTED_ENCODING. Spacing is
   pixdim[1..3] (negative, zero, NaN: HD_ERROR_INVALID_SPACING). The data start at vox_offset.
   scl_slope/scl_inter (slope neither 0 nor non-finite, and not the identity) are applied, and
   the volume is then F32. A .nii.gz is a gzip stream of the same bytes; a truncated or corrupt
   stream is HD_ERROR_GZIP, a complete stream shorter than the header claims
   HD_ERROR_FILE_TRUNCATED. */
#ifndef HD_IO_NIFTI_H
#define HD_IO_NIFTI_H

#define HD__NII_HDR 348

static float hd__io_f32(const unsigned char *p, int big)
{
    uint32_t b = (uint32_t)hd__io_get(p, 4, big);
    float f;
    memcpy(&f, &b, 4);
    return f;
}

/* The integer voxel i of an U8, U16 or I16 volume. */
static double hd__io_int_at(const hd_volume_file *out, size_t i)
{
    return out->desc.type == HD_VOXEL_U8 ? (double)((const unsigned char *)out->data)[i]
         : out->desc.type == HD_VOXEL_U16 ? (double)((const uint16_t *)out->data)[i] : (double)((const int16_t *)out->data)[i];
}

/* value * slope + inter, in place. An integer volume whose rescaled values are integers that
   I16 holds (a CT stored unsigned with intercept -1024) becomes I16; otherwise out becomes F32
   (converted from U8/U16/I16 when needed). */
static hd_result hd__io_rescale(hd_volume_file *out, size_t count, double slope, double inter,
                                const hd__io_opt *o, const hd_logger *logger)
{
    float *d;
    double lo = 0.0, hi = 0.0;
    size_t i, bad = 0;
    if (out->desc.type != HD_VOXEL_F32 && slope == floor(slope) && inter == floor(inter)) {
        double a = (double)out->value_min * slope + inter, b = (double)out->value_max * slope + inter;
        if (a >= -32768.0 && a <= 32767.0 && b >= -32768.0 && b <= 32767.0) {
            int16_t *q = out->desc.type == HD_VOXEL_I16 ? (int16_t *)out->data : (int16_t *)hd__io_alloc(o, count * sizeof(int16_t));
            if (!q)
                return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "nifti: cannot allocate %zu voxels", count);
            for (i = 0; i < count; ++i) q[i] = (int16_t)(hd__io_int_at(out, i) * slope + inter);
            if (q != out->data) hd__io_free(o, out->data);
            out->data = q;
            out->desc.data = q;
            out->desc.type = HD_VOXEL_I16;
            hd__io_set_range(out, a < b ? a : b, a < b ? b : a);
            return HD_SUCCESS;
        }
    }
    if (out->desc.type == HD_VOXEL_F32) {
        d = (float *)out->data;
    } else {
        d = (float *)hd__io_alloc(o, count * sizeof(float));
        if (!d)
            return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "nifti: cannot allocate %zu voxels",
                               count);
        for (i = 0; i < count; ++i) d[i] = (float)hd__io_int_at(out, i);
        hd__io_free(o, out->data);
        out->data = d;
        out->desc.type = HD_VOXEL_F32;
        out->desc.data = d;
    }
    for (i = 0; i < count; ++i) {
        float f = (float)(d[i] * slope + inter);
        if (!isfinite(f)) {
            f = 0.0f;
            ++bad;
        }
        d[i] = f;
        if (i == 0 || f < lo) lo = f;
        if (i == 0 || f > hi) hi = f;
    }
    if (bad)
        HD__IO_WARN(logger, "nifti: %zu voxel values became non-finite after scl_slope/scl_inter "
                            "and were replaced by 0", bad);
    hd__io_set_range(out, lo, hi);
    return HD_SUCCESS;
}

typedef struct hd__io_nii {
    int big, type;
    int64_t dims[3];
    size_t count, bytes, offset;
    float spacing[3];
    double slope, inter;
} hd__io_nii;

/* Checks a 348-byte header; fills h. */
static hd_result hd__io_nii_header(const unsigned char *p, hd__io_nii *h, const hd__io_opt *o,
                                   const hd_logger *logger)
{
    static const struct { int code, type; } types[] = {
        {2, HD__IO_U8}, {4, HD__IO_I16}, {8, HD__IO_I32}, {16, HD__IO_F32}, {64, HD__IO_F64},
        {256, HD__IO_I8}, {512, HD__IO_U16}, {768, HD__IO_U32}, {1024, HD__IO_I64},
        {1280, HD__IO_U64},
    };
    int big, i, ndim, code, extra = 0;
    int64_t dim[8];
    double vox;
    size_t k;
    hd_result r;
    memset(h, 0, sizeof *h);
    if (hd__io_get(p, 4, 0) == HD__NII_HDR) big = 0;
    else if (hd__io_get(p, 4, 1) == HD__NII_HDR) big = 1;
    else if (hd__io_get(p, 4, 0) == 540 || hd__io_get(p, 4, 1) == 540)
        return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                           "nifti: NIfTI-2 (sizeof_hdr 540) is not supported");
    else
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nifti: sizeof_hdr is not 348 in either byte order: not NIfTI-1");
    h->big = big;
    if (memcmp(p + 344, "ni1\0", 4) == 0)
        return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                           "nifti: a two-file (.hdr/.img, magic 'ni1') image is not supported");
    if (memcmp(p + 344, "n+1\0", 4) != 0)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nifti: no 'n+1' magic (Analyze 7.5 files are not supported)");
    for (i = 0; i < 8; ++i) dim[i] = (int16_t)(uint16_t)hd__io_get(p + 40 + 2 * i, 2, big);
    ndim = (int)dim[0];
    if (ndim < 1 || ndim > 7)
        return HD__IO_FAIL(logger, HD_ERROR_INVALID_DIMENSIONS,
                           "nifti: dim[0] is %d (must be 1..7)", ndim);
    for (i = 0; i < 3; ++i) h->dims[i] = i < ndim ? dim[i + 1] : 1;
    for (i = 4; i <= ndim; ++i) {
        if (dim[i] <= 0)
            return HD__IO_FAIL(logger, HD_ERROR_INVALID_DIMENSIONS,
                               "nifti: dim[%d] is %lld (must be >= 1)", i, (long long)dim[i]);
        if (dim[i] > 1) extra = 1;
    }
    code = (int)(uint16_t)hd__io_get(p + 70, 2, big);
    h->type = -1;
    for (k = 0; k < sizeof types / sizeof types[0]; ++k)
        if (types[k].code == code) h->type = types[k].type;
    if (h->type < 0)
        return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                           "nifti: datatype %d is not supported (integer and real scalars only)",
                           code);
    r = hd__io_check_dims(h->dims, hd__io_type_size(h->type), 0, &h->count, &h->bytes, "nifti",
                          logger);
    if (r != HD_SUCCESS) return r;
    r = hd__io_check_limit(h->count, h->type, o, "nifti", logger);
    if (r != HD_SUCCESS) return r;
    if (extra)
        HD__IO_WARN(logger, "nifti: %d-dimensional image: only the first 3D volume is loaded",
                    ndim);
    for (i = 0; i < 3; ++i) {
        float s = i < ndim ? hd__io_f32(p + 76 + 4 * (i + 1), big) : 1.0f;
        if (!hd__io_spacing_valid(s))
            return HD__IO_FAIL(logger, HD_ERROR_INVALID_SPACING,
                               "nifti: pixdim[%d] is %g (must be finite and > 0)", i + 1,
                               (double)s);
        h->spacing[i] = s;
    }
    vox = hd__io_f32(p + 108, big);
    if (!(vox >= 0.0) || vox != floor(vox))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nifti: vox_offset %g is not a non-negative integer", vox);
    if (vox < HD__NII_HDR) vox = 352; /* 0 in some writers: the default for .nii */
    if (vox > (double)(SIZE_MAX / 2))
        return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW, "nifti: vox_offset %g is too large",
                           vox);
    h->offset = (size_t)vox;
    if (h->offset > SIZE_MAX - h->bytes)
        return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW,
                           "nifti: vox_offset + data size overflow");
    h->slope = hd__io_f32(p + 112, big);
    h->inter = hd__io_f32(p + 116, big);
    if (!isfinite(h->slope) || !isfinite(h->inter)) {
        HD__IO_WARN(logger, "nifti: scl_slope %g / scl_inter %g not finite: ignored", h->slope,
                    h->inter);
        h->slope = 0.0;
    }
    return HD_SUCCESS;
}

static hd_result hd__io_nii_finish(const hd__io_nii *h, hd_volume_file *out, const hd__io_opt *o,
                                   const hd_logger *logger)
{
    int i;
    hd_result r = HD_SUCCESS;
    if (h->slope != 0.0 && !(h->slope == 1.0 && h->inter == 0.0))
        r = hd__io_rescale(out, h->count, h->slope, h->inter, o, logger);
    if (r != HD_SUCCESS) return r;
    for (i = 0; i < 3; ++i) {
        out->desc.dims[i] = (int)h->dims[i];
        out->desc.spacing[i] = h->spacing[i];
    }
    return HD_SUCCESS;
}

/* A .nii (raw) or .nii.gz (one gzip stream of the same bytes) from s. */
static hd_result hd__io_nii_load(hd__io_src *s, hd_volume_file *out, const hd__io_opt *o,
                            const hd_logger *logger)
{
    unsigned char hdr[HD__NII_HDR];
    size_t got;
    hd__io_nii h;
    hd_result r;
    s->pos = 0;
    r = hd__io_src_read(s, hdr, 2, &got, logger);
    if (r != HD_SUCCESS) return r;
    if (got == 2 && hdr[0] == 0x1f && hdr[1] == 0x8b) {
#ifdef HYBRIDDIFF_NO_ZLIB
        return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                           "nifti: .nii.gz needs zlib (built with HYBRIDDIFF_NO_ZLIB)");
#else
        /* one pass: the header, the bytes up to vox_offset, the data, the rest of the stream */
        hd__io_gz g;
        int z;
        s->pos = 0;
        r = hd__io_gz_init(&g, s, s->size, "nifti", logger);
        if (r != HD_SUCCESS) return r;
        z = hd__io_gz_read(&g, hdr, HD__NII_HDR, &got);
        if (z == Z_STREAM_END && got < HD__NII_HDR)
            r = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                            "nifti: gzip stream holds %zu bytes, less than the 348-byte header",
                            got);
        else if (z != Z_OK && z != Z_STREAM_END)
            r = hd__io_gzip_error(z, &g, "in the header", "nifti", logger);
        if (r == HD_SUCCESS) r = hd__io_nii_header(hdr, &h, o, logger);
        if (r == HD_SUCCESS)
            r = hd__io_gz_data(&g, h.offset - HD__NII_HDR, h.count, h.type, h.big, out, "nifti",
                               logger);
        inflateEnd(&g.zs);
        return r == HD_SUCCESS ? hd__io_nii_finish(&h, out, o, logger) : r;
#endif
    }
    if (s->size < HD__NII_HDR)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nifti: %llu bytes, shorter than the 348-byte header",
                           (unsigned long long)s->size);
    s->pos = 0;
    r = hd__io_src_read(s, hdr, HD__NII_HDR, &got, logger);
    if (r == HD_SUCCESS && got < HD__NII_HDR)
        r = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED, "nifti: the file ended inside the "
                        "header");
    if (r == HD_SUCCESS) r = hd__io_nii_header(hdr, &h, o, logger);
    if (r != HD_SUCCESS) return r;
    if ((uint64_t)h.offset > s->size || s->size - h.offset < (uint64_t)h.bytes)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                           "nifti: header claims %zu bytes of data at offset %zu, file has %llu",
                           h.bytes, h.offset, (unsigned long long)s->size);
    r = hd__io_data(s, h.offset, 0, 0, 0, h.count, h.type, h.big, out, "nifti", logger);
    return r == HD_SUCCESS ? hd__io_nii_finish(&h, out, o, logger) : r;
}

HDDEF hd_result hd_volume_parse_nifti(const void *bytes, size_t size, hd_volume_file *out,
                                      const hd_logger *logger)
{
    hd__io_opt o;
    hd__io_src s;
    hd_result r;
    if (out) memset(out, 0, sizeof *out);
    if (!bytes || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "nifti: %s is NULL",
                           !out ? "out" : "bytes");
    hd__io_opt_init(&o, NULL);
    hd__io_src_mem(&s, bytes, size, &o);
    r = hd__io_nii_load(&s, out, &o, logger);
    if (r != HD_SUCCESS) hd_volume_free(out);
    return r;
}

static hd_result hd__io_nii_file(hd__io_src *s, const char *path, hd_volume_file *out,
                                 const hd__io_opt *o, const hd_logger *logger)
{
    (void)path;
    return hd__io_nii_load(s, out, o, logger);
}

HDDEF hd_result hd_volume_load_nifti(const char *path, hd_volume_file *out,
                                     const hd_logger *logger)
{
    hd__io_opt o;
    hd__io_opt_init(&o, NULL);
    return hd__io_load_file(path, &o, out, logger, "nifti", hd__io_nii_file);
}

/* ---- any format -------------------------------------------------------------------------- */
/* By the first bytes: "NRRD000", a gzip stream or sizeof_hdr 348 (NIfTI-1), "NDims" or
   "Object..." (MetaImage), else MetaImage if the extension is .mhd or .mha. */
static hd_result hd__io_any_file(hd__io_src *s, const char *path, hd_volume_file *out,
                                 const hd__io_opt *o, const hd_logger *logger)
{
    unsigned char m[8] = {0};
    size_t n, len = strlen(path);
    hd_result r;
    s->pos = 0;
    r = hd__io_src_read(s, m, sizeof m, &n, logger);
    if (r != HD_SUCCESS) return r;
    if (n >= 7 && memcmp(m, "NRRD000", 7) == 0) return hd__io_nrrd_file(s, path, out, o, logger);
    if ((n >= 2 && m[0] == 0x1f && m[1] == 0x8b) ||
        (n >= 4 && (hd__io_get(m, 4, 0) == HD__NII_HDR || hd__io_get(m, 4, 1) == HD__NII_HDR)))
        return hd__io_nii_load(s, out, o, logger);
    if ((n >= 5 && (hd__io_match_word((const char *)m, "ndims") ||
                    hd__io_match_word((const char *)m, "object"))) ||
        (len >= 4 && (hd__io_match_word(path + len - 4, ".mhd") ||
                      hd__io_match_word(path + len - 4, ".mha"))))
        return hd__io_mhd_file(s, path, out, o, logger);
    return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                       "load: not a NRRD, NIfTI-1 or (by its extension .mhd/.mha) MetaImage file");
}

HDDEF hd_result hd_volume_load(const char *path, hd_volume_file *out, const hd_logger *logger)
{
    return hd_volume_load_ex(path, NULL, out, logger);
}

HDDEF hd_result hd_volume_load_ex(const char *path, const hd_load_options *options,
                                  hd_volume_file *out, const hd_logger *logger)
{
    static const hd__io_file_fn fns[HD_FILE_FORMAT_COUNT] = {
        hd__io_any_file, hd__io_nrrd_file, hd__io_mhd_file, hd__io_nii_file,
    };
    static const char *const names[HD_FILE_FORMAT_COUNT] = {"load", "nrrd", "mhd", "nifti"};
    hd__io_opt o;
    int f = options ? (int)options->format : 0;
    if (out) memset(out, 0, sizeof *out);
    if (f < 0 || f >= (int)HD_FILE_FORMAT_COUNT)
        return HD__IO_FAIL(logger, HD_ERROR_INVALID_ENUM, "load: format %d is out of range", f);
    if (options && !options->allocator.alloc != !options->allocator.free)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER,
                           "load: allocator needs both alloc and free, or neither");
    hd__io_opt_init(&o, options);
    return hd__io_load_file(path, &o, out, logger, names[f], fns[f]);
}

#endif /* HD_IO_NIFTI_H */
