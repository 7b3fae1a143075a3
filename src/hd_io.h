/* hd_io.h - the file loaders: NRRD (attached header, raw or gzip) and headerless raw volumes.
   Part of the implementation of hybriddiff.h; included once, after the public declarations.

   One parser works on a memory buffer (hd_volume_parse_nrrd, what the fuzzers drive); the file
   loaders only read the file and hand the bytes over. Nothing is allocated before the header has
   been checked against the bytes that are really there, so a hostile header cannot make the
   parser allocate more than a small multiple of its input.

   Output types: u8 stays HD_VOXEL_U8, u16 stays HD_VOXEL_U16, every other type is converted to
   HD_VOXEL_F32 (non-finite values become 0, with a warning). desc.value_range is the range of the
   values in the file ({v, v + 1} for a constant volume, so that the range is never empty).

   Order of the size checks (NRRD sizes and raw dims alike): a size <= 0 is
   HD_ERROR_INVALID_DIMENSIONS; then the product of the sizes and the bytes per voxel must fit in
   a size_t (HD_ERROR_SIZE_OVERFLOW); then each size must be <= HD_MAX_DIM
   (HD_ERROR_INVALID_DIMENSIONS). */
#ifndef HD_IO_H
#define HD_IO_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <stdarg.h>
#include <errno.h>
#include <limits.h>
#include <stdint.h>
#include <math.h>
#ifndef HYBRIDDIFF_NO_ZLIB
#include <zlib.h>
#endif

#if defined(__GNUC__) || defined(__clang__)
#define HD__IO_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define HD__IO_PRINTF(f, a)
#endif

/* Element types of a file: the first eight match hd_raw_type. */
enum {
    HD__IO_U8 = 0, HD__IO_I8, HD__IO_U16, HD__IO_I16, HD__IO_U32, HD__IO_I32, HD__IO_F32,
    HD__IO_F64, HD__IO_U64, HD__IO_I64, HD__IO_TYPE_COUNT
};

#define HD__IO_LINE_MAX 4096 /* longest header field line we parse */

static size_t hd__io_type_size(int type)
{
    static const unsigned char sizes[HD__IO_TYPE_COUNT] = {1, 1, 2, 2, 4, 4, 4, 8, 8, 8};
    return (type >= 0 && type < HD__IO_TYPE_COUNT) ? sizes[type] : 0;
}

/* ---- logging ------------------------------------------------------------------------------- */
static void hd__io_logv(const hd_logger *logger, hd_log_level level, hd_result code,
                        const char *file, int line, const char *fmt, va_list ap)
{
    char msg[512];
    if (!logger || !logger->func) return;
    vsnprintf(msg, sizeof msg, fmt, ap);
    logger->func(logger->user_data, level, code, msg, file, line);
}

HD__IO_PRINTF(5, 6)
static hd_result hd__io_fail(const hd_logger *logger, hd_result code, const char *file, int line,
                             const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    hd__io_logv(logger, HD_LOG_ERROR, code, file, line, fmt, ap);
    va_end(ap);
    return code;
}

HD__IO_PRINTF(4, 5)
static void hd__io_warn(const hd_logger *logger, const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    hd__io_logv(logger, HD_LOG_WARNING, HD_SUCCESS, file, line, fmt, ap);
    va_end(ap);
}

#define HD__IO_FAIL(logger, code, ...) hd__io_fail(logger, code, __FILE__, __LINE__, __VA_ARGS__)
#define HD__IO_WARN(logger, ...) hd__io_warn(logger, __FILE__, __LINE__, __VA_ARGS__)

/* The file loaders prefix every message with the path. */
typedef struct hd__io_path_logger {
    const hd_logger *outer;
    const char *path;
} hd__io_path_logger;

static void hd__io_path_log(void *user_data, hd_log_level level, hd_result code,
                            const char *message, const char *file, int line)
{
    const hd__io_path_logger *pl = (const hd__io_path_logger *)user_data;
    char msg[768];
    snprintf(msg, sizeof msg, "%s: %s", pl->path, message);
    pl->outer->func(pl->outer->user_data, level, code, msg, file, line);
}

/* Returns the logger to use: a path-prefixing wrapper around outer, or NULL when silent. */
static const hd_logger *hd__io_wrap_logger(const hd_logger *outer, const char *path,
                                           hd__io_path_logger *pl, hd_logger *wrapped)
{
    if (!outer || !outer->func) return NULL;
    pl->outer = outer;
    pl->path = path;
    wrapped->func = hd__io_path_log;
    wrapped->user_data = pl;
    return wrapped;
}

/* ---- sizes ----------------------------------------------------------------------------------- */
/* Checks dims (already parsed as 64-bit) and computes voxel count and bytes of elem_size each.
   what: "nrrd" or "raw", for the messages. */
static hd_result hd__io_check_dims(const int64_t dims[3], size_t elem_size, int overflowed,
                                   size_t *out_count, size_t *out_bytes, const char *what,
                                   const hd_logger *logger)
{
    size_t count = 1;
    int i;
    for (i = 0; i < 3; ++i)
        if (dims[i] <= 0)
            return HD__IO_FAIL(logger, HD_ERROR_INVALID_DIMENSIONS,
                               "%s: size of axis %d is %lld (must be 1..%d)", what, i,
                               (long long)dims[i], HD_MAX_DIM);
    if (overflowed)
        return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW, "%s: a size does not fit in 64 bits",
                           what);
    for (i = 0; i < 3; ++i) {
        if ((uint64_t)dims[i] > (uint64_t)SIZE_MAX || count > SIZE_MAX / (size_t)dims[i])
            return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW,
                               "%s: sizes %lld x %lld x %lld overflow a size_t", what,
                               (long long)dims[0], (long long)dims[1], (long long)dims[2]);
        count *= (size_t)dims[i];
    }
    /* 4: every output is at most 4 bytes a voxel; elem_size: the input. */
    if (count > SIZE_MAX / (elem_size > 4 ? elem_size : 4))
        return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW,
                           "%s: %lld x %lld x %lld voxels of %u bytes overflow a size_t", what,
                           (long long)dims[0], (long long)dims[1], (long long)dims[2],
                           (unsigned)elem_size);
    for (i = 0; i < 3; ++i)
        if (dims[i] > HD_MAX_DIM)
            return HD__IO_FAIL(logger, HD_ERROR_INVALID_DIMENSIONS,
                               "%s: size of axis %d is %lld (must be 1..%d)", what, i,
                               (long long)dims[i], HD_MAX_DIM);
    *out_count = count;
    *out_bytes = count * elem_size;
    return HD_SUCCESS;
}

/* ---- conversion ------------------------------------------------------------------------------ */
static uint64_t hd__io_get(const unsigned char *p, size_t n, int big)
{
    uint64_t v = 0;
    size_t i;
    if (big)
        for (i = 0; i < n; ++i) v = (v << 8) | p[i];
    else
        for (i = n; i-- > 0;) v = (v << 8) | p[i];
    return v;
}

static double hd__io_value(const unsigned char *p, int type, int big)
{
    uint64_t u;
    switch (type) {
    case HD__IO_U8: return (double)p[0];
    case HD__IO_I8: return (double)(signed char)p[0];
    case HD__IO_U16: return (double)hd__io_get(p, 2, big);
    case HD__IO_I16: return (double)(int16_t)(uint16_t)hd__io_get(p, 2, big);
    case HD__IO_U32: return (double)hd__io_get(p, 4, big);
    case HD__IO_I32: return (double)(int32_t)(uint32_t)hd__io_get(p, 4, big);
    case HD__IO_U64: return (double)hd__io_get(p, 8, big);
    case HD__IO_I64:
        u = hd__io_get(p, 8, big);
        return u >> 63 ? -(double)(~u) - 1.0 : (double)u; /* two's complement, no UB */
    case HD__IO_F32: {
        uint32_t b = (uint32_t)hd__io_get(p, 4, big);
        float f;
        memcpy(&f, &b, 4);
        return (double)f;
    }
    case HD__IO_F64: {
        double d;
        u = hd__io_get(p, 8, big);
        memcpy(&d, &u, 8);
        return d;
    }
    default: return 0.0;
    }
}

/* value_min/max and desc.value_range; a constant volume gets {v, v + a little} (or {v - a little,
   v} at the top of the float range, so that the range stays finite and non-empty). */
static void hd__io_set_range(hd_volume_file *out, double lo, double hi)
{
    out->value_min = (float)lo;
    out->value_max = (float)hi;
    out->desc.value_range[0] = out->value_min;
    out->desc.value_range[1] = out->value_max;
    if (!(out->desc.value_range[1] > out->desc.value_range[0])) {
        float v = out->desc.value_range[0], a = v < 0 ? -v : v;
        float d = a > 1.0f ? a * 1e-3f : 1.0f;
        if (isfinite(v + d)) out->desc.value_range[1] = v + d;
        else out->desc.value_range[0] = v - d;
    }
}

/* Converts count elements of type at src into out->data (allocated here) and fills out->desc
   (but dims and spacing), value_min and value_max. */
static hd_result hd__io_convert(const unsigned char *src, size_t count, int type, int big,
                                hd_volume_file *out, const char *what, const hd_logger *logger)
{
    size_t i, esize = hd__io_type_size(type), bad = 0;
    double lo = 0.0, hi = 0.0;
    int any = 0;
    if (count == 0) count = 1; /* never: dims are >= 1 */
    if (type == HD__IO_U8) {
        unsigned char *d = (unsigned char *)malloc(count);
        if (!d) goto oom;
        memcpy(d, src, count);
        lo = hi = d[0];
        for (i = 1; i < count; ++i) {
            if (d[i] < lo) lo = d[i];
            if (d[i] > hi) hi = d[i];
        }
        out->data = d;
        out->desc.type = HD_VOXEL_U8;
    } else if (type == HD__IO_U16) {
        uint16_t *d = (uint16_t *)malloc(count * 2);
        unsigned vlo = 65535, vhi = 0;
        if (!d) goto oom;
        for (i = 0; i < count; ++i) {
            const unsigned char *p = src + 2 * i;
            unsigned v = big ? (unsigned)(p[0] << 8 | p[1]) : (unsigned)(p[1] << 8 | p[0]);
            d[i] = (uint16_t)v;
            if (v < vlo) vlo = v;
            if (v > vhi) vhi = v;
        }
        lo = vlo;
        hi = vhi;
        out->data = d;
        out->desc.type = HD_VOXEL_U16;
    } else {
        float *d = (float *)malloc(count * sizeof(float));
        if (!d) goto oom;
        for (i = 0; i < count; ++i) {
            double v = hd__io_value(src + esize * i, type, big);
            float f = (float)v;
            if (!(v == v) || !isfinite(f)) { /* NaN, Inf, or a double beyond float range */
                f = 0.0f;
                ++bad;
            }
            d[i] = f;
            if (!any || f < lo) lo = f;
            if (!any || f > hi) hi = f;
            any = 1;
        }
        if (bad)
            HD__IO_WARN(logger, "%s: %zu non-finite voxel values were replaced by 0", what, bad);
        out->data = d;
        out->desc.type = HD_VOXEL_F32;
    }
    out->desc.data = out->data;
    hd__io_set_range(out, lo, hi);
    return HD_SUCCESS;
oom:
    return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu voxels", what,
                       count);
}

/* ---- text helpers ---------------------------------------------------------------------------- */
static int hd__io_lower(int c) { return (c >= 'A' && c <= 'Z') ? c - 'A' + 'a' : c; }
static int hd__io_space(int c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* Lower-cases s in place and collapses runs of white space to one space, trimmed. */
static void hd__io_normalize(char *s)
{
    char *w = s;
    const char *r = s;
    while (*r) {
        if (hd__io_space((unsigned char)*r)) {
            while (hd__io_space((unsigned char)*r)) ++r;
            if (w != s && *r) *w++ = ' ';
        } else {
            *w++ = (char)hd__io_lower((unsigned char)*r++);
        }
    }
    *w = 0;
}

static const char *hd__io_skip_space(const char *s)
{
    while (hd__io_space((unsigned char)*s)) ++s;
    return s;
}

/* Parses a decimal integer; saturates beyond +-2^62 and sets *overflow. NULL if none. */
static const char *hd__io_parse_int(const char *s, int64_t *out, int *overflow)
{
    int neg = 0;
    uint64_t v = 0;
    const uint64_t cap = (uint64_t)1 << 62;
    s = hd__io_skip_space(s);
    if (*s == '+' || *s == '-') neg = *s++ == '-';
    if (*s < '0' || *s > '9') return NULL;
    while (*s >= '0' && *s <= '9') {
        if (v < cap) v = v * 10 + (uint64_t)(*s - '0');
        if (v >= cap) {
            v = cap;
            if (overflow) *overflow = 1;
        }
        ++s;
    }
    *out = neg ? -(int64_t)v : (int64_t)v;
    return s;
}

static int hd__io_match_word(const char *s, const char *word)
{
    while (*word)
        if (hd__io_lower((unsigned char)*s++) != *word++) return 0;
    return 1;
}

/* Parses a decimal floating point number (locale independent), also nan, inf, infinity. */
static const char *hd__io_parse_double(const char *s, double *out)
{
    int neg = 0, digits = 0, exp10 = 0;
    uint64_t mant = 0;
    double v;
    s = hd__io_skip_space(s);
    if (*s == '+' || *s == '-') neg = *s++ == '-';
    if (hd__io_match_word(s, "nan")) {
        *out = neg ? -NAN : NAN;
        return s + 3;
    }
    if (hd__io_match_word(s, "inf")) {
        *out = neg ? -HUGE_VAL : HUGE_VAL;
        return s + (hd__io_match_word(s, "infinity") ? 8 : 3);
    }
    for (; *s >= '0' && *s <= '9'; ++s, ++digits) {
        if (mant < 100000000000000000ull) mant = mant * 10 + (uint64_t)(*s - '0');
        else if (exp10 < 100000) ++exp10;
    }
    if (*s == '.') {
        for (++s; *s >= '0' && *s <= '9'; ++s, ++digits)
            if (mant < 100000000000000000ull) {
                mant = mant * 10 + (uint64_t)(*s - '0');
                --exp10;
            }
    }
    if (!digits) return NULL;
    if (*s == 'e' || *s == 'E') {
        int eneg = 0, e = 0;
        const char *t = s + 1;
        if (*t == '+' || *t == '-') eneg = *t++ == '-';
        if (*t >= '0' && *t <= '9') {
            for (; *t >= '0' && *t <= '9'; ++t)
                if (e < 100000) e = e * 10 + (*t - '0');
            exp10 += eneg ? -e : e;
            s = t;
        }
    }
    v = (double)mant;
    if (mant != 0) {
        if (exp10 > 400) v = HUGE_VAL;
        else if (exp10 < -400) v = 0.0;
        else if (exp10 < 0) v /= pow(10.0, (double)-exp10);
        else if (exp10 > 0) v *= pow(10.0, (double)exp10);
    }
    *out = neg ? -v : v;
    return s;
}

/* ---- NRRD -------------------------------------------------------------------------------- */
typedef struct hd__io_nrrd {
    int type;         /* HD__IO_*, -1 unknown */
    int dimension;    /* 0 unknown */
    int big;          /* endian big */
    int have_endian;
    int encoding;     /* 0 unknown, 1 raw, 2 gzip */
    int64_t byte_skip;
    int64_t line_skip;
    /* per-axis fields, parsed once the dimension is known; offsets into the buffer */
    const char *sizes, *spacings, *directions;
    size_t sizes_len, spacings_len, directions_len;
    int sizes_line, spacings_line, directions_line;
} hd__io_nrrd;

static int hd__io_nrrd_type(const char *v)
{
    static const struct { const char *name; int type; } names[] = {
        {"signed char", HD__IO_I8}, {"int8", HD__IO_I8}, {"int8_t", HD__IO_I8},
        {"uchar", HD__IO_U8}, {"unsigned char", HD__IO_U8}, {"uint8", HD__IO_U8},
        {"uint8_t", HD__IO_U8},
        {"short", HD__IO_I16}, {"short int", HD__IO_I16}, {"signed short", HD__IO_I16},
        {"signed short int", HD__IO_I16}, {"int16", HD__IO_I16}, {"int16_t", HD__IO_I16},
        {"ushort", HD__IO_U16}, {"unsigned short", HD__IO_U16},
        {"unsigned short int", HD__IO_U16}, {"uint16", HD__IO_U16}, {"uint16_t", HD__IO_U16},
        {"int", HD__IO_I32}, {"signed int", HD__IO_I32}, {"int32", HD__IO_I32},
        {"int32_t", HD__IO_I32},
        {"uint", HD__IO_U32}, {"unsigned int", HD__IO_U32}, {"uint32", HD__IO_U32},
        {"uint32_t", HD__IO_U32},
        {"longlong", HD__IO_I64}, {"long long", HD__IO_I64}, {"long long int", HD__IO_I64},
        {"signed long long", HD__IO_I64}, {"signed long long int", HD__IO_I64},
        {"int64", HD__IO_I64}, {"int64_t", HD__IO_I64},
        {"ulonglong", HD__IO_U64}, {"unsigned long long", HD__IO_U64},
        {"unsigned long long int", HD__IO_U64}, {"uint64", HD__IO_U64},
        {"uint64_t", HD__IO_U64},
        {"float", HD__IO_F32}, {"double", HD__IO_F64},
    };
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (strcmp(v, names[i].name) == 0) return names[i].type;
    return -1;
}

/* Copies [s, s+len) to buf as a NUL-terminated string; 0 if it does not fit. */
static int hd__io_copy(char *buf, size_t cap, const char *s, size_t len)
{
    if (len >= cap) return 0;
    memcpy(buf, s, len);
    buf[len] = 0;
    return 1;
}

/* sizes: exactly dimension integers. */
static hd_result hd__io_nrrd_sizes(const hd__io_nrrd *h, int64_t dims[3], int *overflow,
                                   const hd_logger *logger)
{
    char buf[HD__IO_LINE_MAX];
    const char *p;
    int i;
    if (!hd__io_copy(buf, sizeof buf, h->sizes, h->sizes_len))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "nrrd: line %d ('sizes') is too long",
                           h->sizes_line);
    p = buf;
    dims[0] = dims[1] = dims[2] = 1;
    for (i = 0; i < h->dimension; ++i) {
        p = hd__io_parse_int(p, &dims[i], overflow);
        if (!p || (*p && !hd__io_space((unsigned char)*p)))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d: 'sizes' needs %d integers", h->sizes_line,
                               h->dimension);
    }
    if (*hd__io_skip_space(p))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nrrd: line %d: 'sizes' has more than %d values", h->sizes_line,
                           h->dimension);
    return HD_SUCCESS;
}

/* Shared by every loader: > 0 and finite, also once rounded to float. */
static int hd__io_spacing_valid(double s)
{
    return s > 0.0 && s < HUGE_VAL && (float)s > 0.0f && isfinite((float)s);
}

static hd_result hd__io_check_spacing(double s, int axis, int line, const hd_logger *logger)
{
    if (!hd__io_spacing_valid(s))
        return HD__IO_FAIL(logger, HD_ERROR_INVALID_SPACING,
                           "nrrd: line %d: spacing of axis %d is %g (must be finite and > 0)",
                           line, axis, s);
    return HD_SUCCESS;
}

/* spacings: dimension numbers; or space directions: dimension vectors (take the norms). */
static hd_result hd__io_nrrd_spacing(const hd__io_nrrd *h, float spacing[3],
                                     const hd_logger *logger)
{
    char buf[HD__IO_LINE_MAX];
    const char *p;
    int i;
    hd_result r;
    spacing[0] = spacing[1] = spacing[2] = 1.0f;
    if (h->directions) {
        if (!hd__io_copy(buf, sizeof buf, h->directions, h->directions_len))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d ('space directions') is too long",
                               h->directions_line);
        p = buf;
        for (i = 0; i < h->dimension; ++i) {
            double sum = 0.0, c;
            int n = 0;
            p = hd__io_skip_space(p);
            if (hd__io_match_word(p, "none")) { /* a non-spatial axis */
                p += 4;
                continue;
            }
            if (*p++ != '(') goto bad_dir;
            for (;;) {
                p = hd__io_parse_double(p, &c);
                if (!p || n >= 8) goto bad_dir;
                sum += c * c;
                ++n;
                p = hd__io_skip_space(p);
                if (*p == ',') { ++p; continue; }
                if (*p == ')') { ++p; break; }
                goto bad_dir;
            }
            r = hd__io_check_spacing(sqrt(sum), i, h->directions_line, logger);
            if (r != HD_SUCCESS) return r;
            spacing[i] = (float)sqrt(sum);
        }
        if (*hd__io_skip_space(p)) goto bad_dir;
        return HD_SUCCESS;
    bad_dir:
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nrrd: line %d: 'space directions' needs %d vectors '(x,y,z)' or 'none'",
                           h->directions_line, h->dimension);
    }
    if (h->spacings) {
        if (!hd__io_copy(buf, sizeof buf, h->spacings, h->spacings_len))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d ('spacings') is too long", h->spacings_line);
        p = buf;
        for (i = 0; i < h->dimension; ++i) {
            double s;
            p = hd__io_parse_double(p, &s);
            if (!p || (*p && !hd__io_space((unsigned char)*p)))
                return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                                   "nrrd: line %d: 'spacings' needs %d numbers", h->spacings_line,
                                   h->dimension);
            r = hd__io_check_spacing(s, i, h->spacings_line, logger);
            if (r != HD_SUCCESS) return r;
            spacing[i] = (float)s;
        }
        if (*hd__io_skip_space(p))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d: 'spacings' has more than %d values",
                               h->spacings_line, h->dimension);
    }
    return HD_SUCCESS;
}

/* One header field. name is normalised with its spaces removed. */
static hd_result hd__io_nrrd_field(hd__io_nrrd *h, const char *name, const char *value,
                                   size_t value_len, int line, const hd_logger *logger)
{
    char v[256];
    int64_t n;
    int per_axis = strcmp(name, "sizes") == 0 || strcmp(name, "spacings") == 0 ||
                   strcmp(name, "spacedirections") == 0;
    if (per_axis) {
        if (value_len >= HD__IO_LINE_MAX)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "nrrd: line %d ('%s') is too long",
                               line, name);
        if (strcmp(name, "sizes") == 0) {
            h->sizes = value; h->sizes_len = value_len; h->sizes_line = line;
        } else if (strcmp(name, "spacings") == 0) {
            h->spacings = value; h->spacings_len = value_len; h->spacings_line = line;
        } else {
            h->directions = value; h->directions_len = value_len; h->directions_line = line;
        }
        return HD_SUCCESS;
    }
    if (strcmp(name, "datafile") == 0)
        return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                           "nrrd: line %d: detached data ('data file:') is not supported; "
                           "use an attached header (.nrrd)", line);
    if (strcmp(name, "type") && strcmp(name, "dimension") && strcmp(name, "endian") &&
        strcmp(name, "encoding") && strcmp(name, "byteskip") && strcmp(name, "lineskip"))
        return HD_SUCCESS; /* a field we do not need */
    if (!hd__io_copy(v, sizeof v, value, value_len))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "nrrd: line %d ('%s') is too long",
                           line, name);
    hd__io_normalize(v);
    if (strcmp(name, "type") == 0) {
        h->type = hd__io_nrrd_type(v);
        if (h->type < 0)
            return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                               "nrrd: line %d: unsupported type '%s'", line, v);
    } else if (strcmp(name, "dimension") == 0) {
        const char *e = hd__io_parse_int(v, &n, NULL);
        if (!e || *e)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d: 'dimension' is not an integer: '%s'", line, v);
        if (n < 1 || n > 3)
            return HD__IO_FAIL(logger, HD_ERROR_INVALID_DIMENSIONS,
                               "nrrd: line %d: dimension %lld is not supported (1, 2 or 3)",
                               line, (long long)n);
        h->dimension = (int)n;
    } else if (strcmp(name, "endian") == 0) {
        if (strcmp(v, "little") == 0) h->big = 0;
        else if (strcmp(v, "big") == 0) h->big = 1;
        else
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d: endian must be 'little' or 'big', not '%s'", line,
                               v);
        h->have_endian = 1;
    } else if (strcmp(name, "encoding") == 0) {
        if (strcmp(v, "raw") == 0) h->encoding = 1;
        else if (strcmp(v, "gzip") == 0 || strcmp(v, "gz") == 0) h->encoding = 2;
        else
            return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                               "nrrd: line %d: unsupported encoding '%s' (raw or gzip)", line, v);
    } else { /* byte skip, line skip */
        const char *e = hd__io_parse_int(v, &n, NULL);
        int bytes = strcmp(name, "byteskip") == 0;
        if (!e || *e || n < (bytes ? -1 : 0))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d: '%s' must be an integer >= %d, not '%s'", line,
                               bytes ? "byte skip" : "line skip", bytes ? -1 : 0, v);
        if (bytes) h->byte_skip = n;
        else h->line_skip = n;
    }
    return HD_SUCCESS;
}

#ifndef HYBRIDDIFF_NO_ZLIB
/* Inflates into out[0..out_len) (out may be NULL with a scratch buffer: discard). Returns a zlib
   code: Z_OK (out full), Z_STREAM_END, Z_BUF_ERROR (input ended early), or an error. */
static int hd__io_inflate(z_stream *zs, const unsigned char **in, size_t *in_left,
                          unsigned char *out, size_t out_len, size_t *produced)
{
    unsigned char scratch[4096];
    *produced = 0;
    while (*produced < out_len) {
        size_t want = out_len - *produced;
        uInt chunk;
        int r;
        if (zs->avail_in == 0 && *in_left > 0) {
            uInt c = *in_left > (size_t)UINT_MAX ? UINT_MAX : (uInt)*in_left;
            zs->next_in = (Bytef *)*in;
            zs->avail_in = c;
            *in += c;
            *in_left -= c;
        }
        if (out) {
            chunk = want > (size_t)UINT_MAX ? UINT_MAX : (uInt)want;
            zs->next_out = out + *produced;
        } else {
            chunk = want > sizeof scratch ? (uInt)sizeof scratch : (uInt)want;
            zs->next_out = scratch;
        }
        zs->avail_out = chunk;
        r = inflate(zs, Z_NO_FLUSH);
        *produced += chunk - zs->avail_out;
        if (r == Z_STREAM_END) return r;
        if (r == Z_BUF_ERROR || r == Z_OK) {
            if (zs->avail_out != 0 && zs->avail_in == 0 && *in_left == 0) return Z_BUF_ERROR;
            continue;
        }
        return r;
    }
    return Z_OK;
}

static hd_result hd__io_gzip_error(int r, const z_stream *zs, const char *stage,
                                   const char *what, const hd_logger *logger)
{
    if (r == Z_MEM_ERROR)
        return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "%s: zlib is out of memory", what);
    if (r == Z_BUF_ERROR)
        return HD__IO_FAIL(logger, HD_ERROR_GZIP, "%s: gzip stream is truncated (%s)", what,
                           stage);
    return HD__IO_FAIL(logger, HD_ERROR_GZIP, "%s: gzip stream is corrupt (%s): %s", what, stage,
                       zs->msg ? zs->msg : "zlib error");
}

/* Decompresses skip + bytes bytes of a gzip or zlib stream; returns the last bytes of them in
   *out (malloc'd). what: "nrrd", "mhd", "nifti", for the messages. */
static hd_result hd__io_gunzip(const unsigned char *in, size_t in_len, size_t skip, size_t bytes,
                               unsigned char **out, const char *what, const hd_logger *logger)
{
    z_stream zs;
    size_t got = 0;
    unsigned char *buf;
    hd_result res = HD_SUCCESS;
    int r;
    *out = NULL;
    /* deflate cannot expand more than 1032:1: a header claiming more is lying, and we refuse it
       before allocating anything. */
    if (skip > SIZE_MAX - bytes || (skip + bytes) / 1032 > in_len + 64)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                           "%s: header claims %zu bytes of data, a gzip stream of %zu bytes "
                           "cannot hold that many", what, bytes, in_len);
    buf = (unsigned char *)malloc(bytes);
    if (!buf)
        return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes",
                           what, bytes);
    memset(&zs, 0, sizeof zs);
    r = inflateInit2(&zs, 15 + 32); /* gzip or zlib header */
    if (r != Z_OK) {
        free(buf);
        return hd__io_gzip_error(r, &zs, "init", what, logger);
    }
    r = hd__io_inflate(&zs, &in, &in_len, NULL, skip, &got);
    if (r == Z_OK) {
        r = hd__io_inflate(&zs, &in, &in_len, buf, bytes, &got);
        if (r == Z_STREAM_END && got == bytes) {
            /* the stream ended right after the data: inflate has checked its CRC */
        } else if (r == Z_OK) { /* data complete: check the rest of the stream (CRC) */
            size_t rest;
            do r = hd__io_inflate(&zs, &in, &in_len, NULL, (size_t)1 << 30, &rest);
            while (r == Z_OK);
            if (r != Z_STREAM_END)
                res = hd__io_gzip_error(r, &zs, "after the data", what, logger);
        } else if (r == Z_STREAM_END) {
            res = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                              "%s: header claims %zu bytes of data, gzip stream holds %zu",
                              what, bytes, got);
        } else {
            res = hd__io_gzip_error(r, &zs, "in the data", what, logger);
        }
    } else if (r == Z_STREAM_END) {
        res = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                          "%s: gzip stream holds %zu bytes, less than the byte skip %zu", what,
                          got, skip);
    } else {
        res = hd__io_gzip_error(r, &zs, "in the skipped bytes", what, logger);
    }
    inflateEnd(&zs);
    if (res != HD_SUCCESS) {
        free(buf);
        return res;
    }
    *out = buf;
    return HD_SUCCESS;
}
#endif

HDDEF void hd_volume_free(hd_volume_file *vol)
{
    if (!vol) return;
    free(vol->data);
    memset(vol, 0, sizeof *vol);
}

HDDEF hd_result hd_volume_parse_nrrd(const void *bytes, size_t size, hd_volume_file *out,
                                     const hd_logger *logger)
{
    const unsigned char *buf = (const unsigned char *)bytes;
    size_t pos, count = 0, data_bytes = 0, avail;
    int64_t dims[3];
    int line = 1, ended = 0, overflow = 0, i;
    hd__io_nrrd h;
    hd_result r;

    if (out) memset(out, 0, sizeof *out);
    if (!bytes || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "nrrd: %s is NULL",
                           !out ? "out" : "bytes");
    if (size < 8 || memcmp(buf, "NRRD000", 7) != 0 || buf[7] < '1' || buf[7] > '9')
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                           "nrrd: no 'NRRD000x' magic at the start: not a NRRD file");
    memset(&h, 0, sizeof h);
    h.type = -1;

    /* The magic line, then 'field: value' lines up to an empty line. */
    pos = 8;
    while (pos < size && buf[pos] != '\n') ++pos;
    if (pos < size) ++pos;
    while (pos < size) {
        size_t start = pos, end, len, colon;
        const char *s = (const char *)buf + start;
        char name[64];
        size_t nl = 0, k;
        ++line;
        while (pos < size && buf[pos] != '\n') ++pos;
        end = pos;
        if (pos < size) ++pos; /* past '\n' */
        if (end > start && buf[end - 1] == '\r') --end;
        len = end - start;
        if (len == 0) {
            ended = 1;
            break;
        }
        if (s[0] == '#') continue;
        for (colon = 0; colon < len && s[colon] != ':'; ++colon) {}
        if (colon == len)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d is not 'field: value' (no ':')", line);
        if (colon + 1 < len && s[colon + 1] == '=') continue; /* 'key:=value' pair */
        for (k = 0; k < colon; ++k) { /* the name, lower case, without spaces */
            int c = (unsigned char)s[k];
            if (hd__io_space(c)) continue;
            if (nl + 1 >= sizeof name || c < 32 || c > 126)
                return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                                   "nrrd: line %d: bad field name", line);
            name[nl++] = (char)hd__io_lower(c);
        }
        name[nl] = 0;
        if (nl == 0)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "nrrd: line %d: empty field name",
                               line);
        r = hd__io_nrrd_field(&h, name, s + colon + 1, len - colon - 1, line, logger);
        if (r != HD_SUCCESS) return r;
    }

    if (h.type < 0 || !h.dimension || !h.sizes || !h.encoding)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "nrrd: header has no '%s' field%s",
                           h.type < 0 ? "type" : !h.dimension ? "dimension"
                                                : !h.sizes ? "sizes" : "encoding",
                           ended ? "" : " (and no blank line ending it)");
    r = hd__io_nrrd_sizes(&h, dims, &overflow, logger);
    if (r != HD_SUCCESS) return r;
    r = hd__io_check_dims(dims, hd__io_type_size(h.type), overflow, &count, &data_bytes, "nrrd",
                          logger);
    if (r != HD_SUCCESS) return r;
    for (i = 0; i < 3; ++i) out->desc.dims[i] = (int)dims[i];
    r = hd__io_nrrd_spacing(&h, out->desc.spacing, logger);
    if (r != HD_SUCCESS) {
        memset(out, 0, sizeof *out);
        return r;
    }
    if (!h.have_endian && hd__io_type_size(h.type) > 1)
        HD__IO_WARN(logger, "nrrd: no 'endian' field for a multi-byte type; assuming little");

    /* line skip: whole lines of the file after the header */
    for (i = 0; (int64_t)i < h.line_skip; ++i) {
        while (pos < size && buf[pos] != '\n') ++pos;
        if (pos >= size) {
            memset(out, 0, sizeof *out);
            return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                               "nrrd: file ends inside the %lld lines to skip",
                               (long long)h.line_skip);
        }
        ++pos;
    }
    avail = size - pos;

    if (h.encoding == 1) {
        const unsigned char *data;
        if (h.byte_skip == -1) { /* the data are the last bytes of the file */
            if (avail < data_bytes) goto truncated;
            data = buf + size - data_bytes;
        } else {
            if ((uint64_t)h.byte_skip > (uint64_t)avail ||
                avail - (size_t)h.byte_skip < data_bytes) {
                if ((uint64_t)h.byte_skip > (uint64_t)avail) {
                    memset(out, 0, sizeof *out);
                    return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                                       "nrrd: byte skip %lld is past the end of the file "
                                       "(%zu bytes after the header)",
                                       (long long)h.byte_skip, avail);
                }
                avail -= (size_t)h.byte_skip;
                goto truncated;
            }
            data = buf + pos + (size_t)h.byte_skip;
        }
        r = hd__io_convert(data, count, h.type, h.big, out, "nrrd", logger);
        if (r != HD_SUCCESS) {
            memset(out, 0, sizeof *out);
            return r;
        }
        return HD_SUCCESS;
    }
#ifdef HYBRIDDIFF_NO_ZLIB
    memset(out, 0, sizeof *out);
    return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                       "nrrd: gzip encoding needs zlib (built with HYBRIDDIFF_NO_ZLIB)");
#else
    {
        unsigned char *raw = NULL;
        if (h.byte_skip < 0) {
            memset(out, 0, sizeof *out);
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: byte skip -1 is only allowed with raw encoding");
        }
        if ((uint64_t)h.byte_skip > (uint64_t)SIZE_MAX) {
            memset(out, 0, sizeof *out);
            return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW, "nrrd: byte skip is too large");
        }
        r = hd__io_gunzip(buf + pos, avail, (size_t)h.byte_skip, data_bytes, &raw, "nrrd",
                          logger);
        if (r == HD_SUCCESS) r = hd__io_convert(raw, count, h.type, h.big, out, "nrrd", logger);
        free(raw);
        if (r != HD_SUCCESS) memset(out, 0, sizeof *out);
        return r;
    }
#endif
truncated:
    memset(out, 0, sizeof *out);
    return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                       "nrrd: header claims %zu bytes of data, file has %zu", data_bytes, avail);
}

/* Reads a whole file into memory. */
static hd_result hd__io_read_file(const char *path, unsigned char **out, size_t *out_size,
                                  const hd_logger *logger)
{
    FILE *f = fopen(path, "rb");
    unsigned char *buf = NULL;
    size_t cap = 0, n = 0;
    *out = NULL;
    *out_size = 0;
    if (!f)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "cannot open: %s", strerror(errno));
    for (;;) {
        size_t got;
        if (n == cap) {
            size_t ncap = cap ? cap * 2 : (size_t)1 << 16;
            unsigned char *nb;
            if (ncap < cap) { /* cannot happen before memory runs out */
                free(buf);
                fclose(f);
                return HD__IO_FAIL(logger, HD_ERROR_SIZE_OVERFLOW, "file is too large");
            }
            nb = (unsigned char *)realloc(buf, ncap);
            if (!nb) {
                free(buf);
                fclose(f);
                return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY,
                                   "cannot allocate %zu bytes to read the file", ncap);
            }
            buf = nb;
            cap = ncap;
        }
        got = fread(buf + n, 1, cap - n, f);
        n += got;
        if (got == 0) break;
    }
    if (ferror(f)) {
        int e = errno;
        free(buf);
        fclose(f);
        return HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "read error: %s", strerror(e));
    }
    fclose(f);
    *out = buf;
    *out_size = n;
    return HD_SUCCESS;
}

/* A loader of a one-file format: the whole file in memory, then its parser, with the path in
   front of every logged message. */
typedef hd_result (*hd__io_parse_fn)(const void *bytes, size_t size, hd_volume_file *out,
                                     const hd_logger *logger);
static hd_result hd__io_load_whole(const char *path, hd_volume_file *out, const hd_logger *logger,
                                   const char *format, hd__io_parse_fn parse)
{
    hd__io_path_logger pl;
    hd_logger wrapped;
    const hd_logger *lg;
    unsigned char *bytes;
    size_t size;
    hd_result r;
    if (out) memset(out, 0, sizeof *out);
    if (!path || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "%s: %s is NULL", format,
                           !path ? "path" : "out");
    lg = hd__io_wrap_logger(logger, path, &pl, &wrapped);
    r = hd__io_read_file(path, &bytes, &size, lg);
    if (r != HD_SUCCESS) return r;
    r = parse(bytes, size, out, lg);
    free(bytes);
    return r;
}

HDDEF hd_result hd_volume_load_nrrd(const char *path, hd_volume_file *out,
                                    const hd_logger *logger)
{
    return hd__io_load_whole(path, out, logger, "nrrd", hd_volume_parse_nrrd);
}

HDDEF hd_result hd_volume_load_raw(const char *path, const int dims[3], hd_raw_type type,
                                   hd_endian endian, size_t offset, hd_volume_file *out,
                                   const hd_logger *logger)
{
    hd__io_path_logger pl;
    hd_logger wrapped;
    const hd_logger *lg;
    int64_t d[3];
    size_t count, bytes, got;
    long fsize;
    unsigned char *buf;
    FILE *f;
    hd_result r;
    int i;
    if (out) memset(out, 0, sizeof *out);
    if (!path || !dims || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "raw: %s is NULL",
                           !path ? "path" : !dims ? "dims" : "out");
    lg = hd__io_wrap_logger(logger, path, &pl, &wrapped);
    if ((int)type < 0 || (int)type >= (int)HD_RAW_TYPE_COUNT)
        return HD__IO_FAIL(lg, HD_ERROR_INVALID_ENUM, "raw: voxel type %d is out of range",
                           (int)type);
    if (endian != HD_ENDIAN_LITTLE && endian != HD_ENDIAN_BIG)
        return HD__IO_FAIL(lg, HD_ERROR_INVALID_ENUM, "raw: endianness %d is out of range",
                           (int)endian);
    for (i = 0; i < 3; ++i) d[i] = dims[i];
    r = hd__io_check_dims(d, hd__io_type_size((int)type), 0, &count, &bytes, "raw", lg);
    if (r != HD_SUCCESS) return r;
    if (offset > SIZE_MAX - bytes)
        return HD__IO_FAIL(lg, HD_ERROR_SIZE_OVERFLOW, "raw: offset %zu + %zu bytes overflow",
                           offset, bytes);
    f = fopen(path, "rb");
    if (!f) return HD__IO_FAIL(lg, HD_ERROR_FILE_IO, "cannot open: %s", strerror(errno));
    /* Check the size before allocating: dims from a typo must not allocate gigabytes. */
    if (fseek(f, 0, SEEK_END) == 0 && (fsize = ftell(f)) >= 0 &&
        (uint64_t)fsize < (uint64_t)(offset + bytes)) {
        fclose(f);
        return HD__IO_FAIL(lg, HD_ERROR_FILE_TRUNCATED,
                           "raw: %d x %d x %d voxels of %u bytes at offset %zu need %zu bytes, "
                           "file has %ld", dims[0], dims[1], dims[2],
                           (unsigned)hd__io_type_size((int)type), offset, offset + bytes, fsize);
    }
    if (offset > (size_t)LONG_MAX || fseek(f, (long)offset, SEEK_SET) != 0) {
        fclose(f);
        return HD__IO_FAIL(lg, HD_ERROR_FILE_TRUNCATED, "raw: cannot seek to offset %zu",
                           offset);
    }
    buf = (unsigned char *)malloc(bytes);
    if (!buf) {
        fclose(f);
        return HD__IO_FAIL(lg, HD_ERROR_OUT_OF_MEMORY, "raw: cannot allocate %zu bytes", bytes);
    }
    got = fread(buf, 1, bytes, f);
    if (got < bytes) {
        int e = errno, err = ferror(f);
        free(buf);
        fclose(f);
        if (err) return HD__IO_FAIL(lg, HD_ERROR_FILE_IO, "raw: read error: %s", strerror(e));
        return HD__IO_FAIL(lg, HD_ERROR_FILE_TRUNCATED,
                           "raw: need %zu bytes at offset %zu, file has %zu", bytes, offset,
                           offset + got);
    }
    fclose(f);
    r = hd__io_convert(buf, count, (int)type, endian == HD_ENDIAN_BIG, out, "raw", lg);
    free(buf);
    if (r != HD_SUCCESS) {
        memset(out, 0, sizeof *out);
        return r;
    }
    for (i = 0; i < 3; ++i) {
        out->desc.dims[i] = dims[i];
        out->desc.spacing[i] = 1.0f;
    }
    return HD_SUCCESS;
}

#endif /* HD_IO_H */
