/* hd_io.h - the file loaders: NRRD (attached header, raw or gzip) and headerless raw volumes,
   and what every loader shares: opening a file, reading it in bounded chunks, inflating gzip,
   converting voxels. Part of the implementation of hybriddiff.h; included once, after the
   public declarations.

   The parsers read from a source, a memory buffer (hd_volume_parse_*, what the fuzzers drive) or
   an open regular file. A file loader reads the header (at most HD__IO_HEADER_MAX bytes), then
   only the bytes the header says the data need, in HD__IO_CHUNK pieces converted as they
   arrive. Raw data are allocated once the source is known to hold them; gzip data grow with
   what really inflates. So the peak allocation is the loaded volume (twice it while a growing
   buffer is copied) plus the header and one chunk, whatever the header claims.

   Output types: u8 stays HD_VOXEL_U8, u16 stays HD_VOXEL_U16, i16 stays HD_VOXEL_I16 (a CT in
   Hounsfield units) and i8 widens to it; every other type is converted to HD_VOXEL_F32
   (non-finite values become 0, with a warning). desc.value_range is the range of the
   values in the file ({v, v + 1} for a constant volume, so that the range is never empty).

   Order of the size checks (NRRD sizes and raw dims alike): a size <= 0 is
   HD_ERROR_INVALID_DIMENSIONS; then the product of the sizes and the bytes per voxel must fit in
   a size_t (HD_ERROR_SIZE_OVERFLOW); then each size must be <= HD_MAX_DIM
   (HD_ERROR_INVALID_DIMENSIONS); then the bytes must be <= hd_load_options.max_bytes
   (HD_ERROR_FILE_TOO_LARGE). */
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
#include <sys/types.h>
#include <sys/stat.h>
#include <fcntl.h>
#include <unistd.h>
/* A strict C translation unit that read <fcntl.h> before the implementation hides O_CLOEXEC and
   O_NOFOLLOW (POSIX 2008); glibc still has them under its reserved names. */
#if defined(O_CLOEXEC)
#define HD__O_CLOEXEC O_CLOEXEC
#elif defined(__O_CLOEXEC)
#define HD__O_CLOEXEC __O_CLOEXEC
#else
#define HD__O_CLOEXEC 0
#endif
#if defined(O_NOFOLLOW)
#define HD__O_NOFOLLOW O_NOFOLLOW
#elif defined(__O_NOFOLLOW)
#define HD__O_NOFOLLOW __O_NOFOLLOW
#endif
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

/* ---- options and allocation ------------------------------------------------------------------ */
typedef struct hd__io_opt {
    hd_allocator al;  /* never empty: malloc/free unless the caller gave one */
    size_t max_bytes; /* SIZE_MAX: no limit */
    int allow_outside;
} hd__io_opt;

static void hd__io_opt_init(hd__io_opt *o, const hd_load_options *lo)
{
    memset(o, 0, sizeof *o);
    o->al.alloc = hd__malloc_default;
    o->al.free = hd__free_default;
    o->max_bytes = SIZE_MAX;
    if (!lo) return;
    if (lo->allocator.alloc) o->al = lo->allocator;
    if (lo->max_bytes) o->max_bytes = lo->max_bytes;
    o->allow_outside = lo->allow_outside_folder != 0;
}

static void *hd__io_alloc(const hd__io_opt *o, size_t n)
{
    return o->al.alloc(n ? n : 1, o->al.user_data);
}

static void hd__io_free(const hd__io_opt *o, void *p)
{
    if (p) o->al.free(p, o->al.user_data);
}

/* Bytes a voxel takes once loaded: u8 and u16 stay, the rest becomes f32. */
static size_t hd__io_out_size(int type)
{
    return type == HD__IO_U8 ? 1 : type == HD__IO_U16 || type == HD__IO_I16 || type == HD__IO_I8 ? 2 : 4;
}

/* hd_load_options.max_bytes: the data as stored and as loaded, whichever is larger. */
static hd_result hd__io_check_limit(size_t count, int type, const hd__io_opt *o, const char *what,
                                    const hd_logger *logger)
{
    size_t es = hd__io_type_size(type), os = hd__io_out_size(type);
    size_t bytes = count * (es > os ? es : os); /* fits: hd__io_check_dims checked it */
    if (bytes > o->max_bytes)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_TOO_LARGE,
                           "%s: the volume takes %zu bytes, more than max_bytes %zu", what, bytes,
                           o->max_bytes);
    return HD_SUCCESS;
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
/* Conversion as the bytes arrive: count elements of type, fed in pieces of any length (an
   element split between pieces is carried over). The output is allocated whole at the start
   when the source is known to hold the data (grow = 0), else as elements arrive, doubling from
   HD__IO_GROW_FIRST voxels up to count. */
#define HD__IO_GROW_FIRST ((size_t)1 << 16)

typedef struct hd__io_conv {
    int type, big, grow, any;
    size_t esize, osize;
    size_t count, done, cap; /* voxels: expected, converted, allocated */
    unsigned char *out;
    double lo, hi;
    size_t bad;              /* non-finite values replaced by 0 */
    unsigned char carry[8];
    size_t carry_n;
} hd__io_conv;

static hd_result hd__io_conv_reserve(hd__io_conv *c, size_t need, const hd__io_opt *o,
                                     const char *what, const hd_logger *logger)
{
    size_t ncap;
    unsigned char *n;
    if (need <= c->cap) return HD_SUCCESS;
    ncap = c->cap ? c->cap : HD__IO_GROW_FIRST;
    while (ncap < need) ncap = ncap > c->count / 2 ? c->count : ncap * 2;
    if (ncap > c->count) ncap = c->count;
    n = (unsigned char *)hd__io_alloc(o, ncap * c->osize);
    if (!n)
        return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu voxels", what,
                           ncap);
    if (c->done) memcpy(n, c->out, c->done * c->osize);
    hd__io_free(o, c->out);
    c->out = n;
    c->cap = ncap;
    return HD_SUCCESS;
}

static hd_result hd__io_conv_begin(hd__io_conv *c, size_t count, int type, int big, int grow,
                                   const hd__io_opt *o, const char *what,
                                   const hd_logger *logger)
{
    memset(c, 0, sizeof *c);
    c->type = type;
    c->big = big;
    c->grow = grow;
    c->esize = hd__io_type_size(type);
    c->osize = hd__io_out_size(type);
    c->count = count ? count : 1; /* never 0: dims are >= 1 */
    return grow ? HD_SUCCESS : hd__io_conv_reserve(c, c->count, o, what, logger);
}

/* k whole elements at src into the output (room for them reserved). */
static void hd__io_conv_elems(hd__io_conv *c, const unsigned char *src, size_t k)
{
    size_t i;
    double lo = c->any ? c->lo : HUGE_VAL, hi = c->any ? c->hi : -HUGE_VAL;
    if (c->type == HD__IO_U8) {
        unsigned char *d = c->out + c->done;
        unsigned vlo = 255, vhi = 0;
        memcpy(d, src, k);
        for (i = 0; i < k; ++i) {
            if (d[i] < vlo) vlo = d[i];
            if (d[i] > vhi) vhi = d[i];
        }
        if (vlo < lo) lo = vlo;
        if (vhi > hi) hi = vhi;
    } else if (c->type == HD__IO_U16) {
        uint16_t *d = (uint16_t *)(void *)c->out + c->done;
        unsigned vlo = 65535, vhi = 0;
        for (i = 0; i < k; ++i) {
            const unsigned char *p = src + 2 * i;
            unsigned v = c->big ? (unsigned)(p[0] << 8 | p[1]) : (unsigned)(p[1] << 8 | p[0]);
            d[i] = (uint16_t)v;
            if (v < vlo) vlo = v;
            if (v > vhi) vhi = v;
        }
        if (vlo < lo) lo = vlo;
        if (vhi > hi) hi = vhi;
    } else if (c->type == HD__IO_I16 || c->type == HD__IO_I8) {
        int16_t *d = (int16_t *)(void *)c->out + c->done;
        int vlo = 32767, vhi = -32768;
        for (i = 0; i < k; ++i) {
            int v = (int)hd__io_value(src + c->esize * i, c->type, c->big);
            d[i] = (int16_t)v;
            if (v < vlo) vlo = v;
            if (v > vhi) vhi = v;
        }
        if (vlo < lo) lo = vlo;
        if (vhi > hi) hi = vhi;
    } else {
        float *d = (float *)(void *)c->out + c->done;
        for (i = 0; i < k; ++i) {
            double v = hd__io_value(src + c->esize * i, c->type, c->big);
            float f = (float)v;
            if (!(v == v) || !isfinite(f)) { /* NaN, Inf, or a double beyond float range */
                f = 0.0f;
                ++c->bad;
            }
            d[i] = f;
            if (f < lo) lo = f;
            if (f > hi) hi = f;
        }
    }
    c->lo = lo;
    c->hi = hi;
    c->any = 1;
    c->done += k;
}

/* Bytes still wanted. */
static size_t hd__io_conv_left(const hd__io_conv *c)
{
    return (c->count - c->done) * c->esize - c->carry_n;
}

/* Feeds n bytes (beyond the last element they are ignored). */
static hd_result hd__io_conv_feed(hd__io_conv *c, const unsigned char *p, size_t n,
                                  const hd__io_opt *o, const char *what, const hd_logger *logger)
{
    size_t k, left = hd__io_conv_left(c);
    hd_result r;
    if (n > left) n = left;
    if (c->carry_n) {
        size_t t = c->esize - c->carry_n;
        if (t > n) t = n;
        memcpy(c->carry + c->carry_n, p, t);
        c->carry_n += t;
        p += t;
        n -= t;
        if (c->carry_n < c->esize) return HD_SUCCESS;
        if ((r = hd__io_conv_reserve(c, c->done + 1, o, what, logger)) != HD_SUCCESS) return r;
        hd__io_conv_elems(c, c->carry, 1);
        c->carry_n = 0;
    }
    k = n / c->esize;
    if (k) {
        if ((r = hd__io_conv_reserve(c, c->done + k, o, what, logger)) != HD_SUCCESS) return r;
        hd__io_conv_elems(c, p, k);
        p += k * c->esize;
        n -= k * c->esize;
    }
    if (n) {
        memcpy(c->carry, p, n);
        c->carry_n = n;
    }
    return HD_SUCCESS;
}

/* Hands the complete output to out (desc.type, data, value range; not dims or spacing). */
static void hd__io_conv_end(hd__io_conv *c, hd_volume_file *out, const hd__io_opt *o,
                            const char *what, const hd_logger *logger)
{
    if (c->bad)
        HD__IO_WARN(logger, "%s: %zu non-finite voxel values were replaced by 0", what, c->bad);
    out->data = c->out;
    out->desc.data = c->out;
    out->desc.type = c->type == HD__IO_U8 ? HD_VOXEL_U8
                     : c->type == HD__IO_U16 ? HD_VOXEL_U16
                     : c->type == HD__IO_I16 || c->type == HD__IO_I8 ? HD_VOXEL_I16 : HD_VOXEL_F32;
    out->allocator = o->al;
    hd__io_set_range(out, c->lo, c->hi);
    c->out = NULL;
}

static void hd__io_conv_drop(hd__io_conv *c, const hd__io_opt *o)
{
    hd__io_free(o, c->out);
    c->out = NULL;
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

/* ---- sources: a memory buffer or an open regular file ---------------------------------------- */
#define HD__IO_CHUNK ((size_t)1 << 16)       /* bytes read from a file at a time */
#define HD__IO_HEADER_MAX ((size_t)1 << 20)  /* longest text header a file loader reads */

typedef struct hd__io_src {
    const unsigned char *mem; /* the buffer, or NULL: the file fd */
    int fd;
    uint64_t size;            /* bytes in the source (a file: its size when opened) */
    uint64_t pos;             /* next byte to read */
    unsigned char *buf;       /* a file's read buffer, HD__IO_CHUNK bytes */
    const hd__io_opt *o;
} hd__io_src;

static void hd__io_src_mem(hd__io_src *s, const void *p, size_t n, const hd__io_opt *o)
{
    memset(s, 0, sizeof *s);
    s->mem = (const unsigned char *)p;
    s->fd = -1;
    s->size = n;
    s->o = o;
}

static void hd__io_src_close(hd__io_src *s)
{
    hd__io_free(s->o, s->buf);
    s->buf = NULL;
    if (!s->mem && s->fd >= 0) close(s->fd);
    s->fd = -1;
}

static const char *hd__io_kind(mode_t m)
{
    return S_ISDIR(m) ? "a directory" : S_ISCHR(m) ? "a character device"
           : S_ISBLK(m) ? "a block device" : S_ISFIFO(m) ? "a FIFO"
#if defined(S_ISSOCK) /* hidden under a strict C feature set fixed before the implementation */
           : S_ISSOCK(m) ? "a socket"
#endif
           : "not a regular file";
}

/* Opens path if it is a regular file. stat comes first, so a FIFO or a device is refused before
   open (which could block or have effects); the opened file must be the one stat saw.
   nofollow: path has no symbolic links (a realpath result); a link appearing in its last
   component since is refused by open. Only stat, open, fstat, lseek and read are used: what a
   strict C translation unit's earlier <unistd.h> or <sys/stat.h> still declares. */
static hd_result hd__io_open(const char *path, int nofollow, hd__io_src *s, const hd__io_opt *o,
                             const hd_logger *logger)
{
    struct stat st, st2;
    int fd, flags = O_RDONLY | O_NONBLOCK | O_NOCTTY | HD__O_CLOEXEC;
    memset(s, 0, sizeof *s);
    s->fd = -1;
    s->o = o;
    if (stat(path, &st) != 0)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "cannot open: %s", strerror(errno));
    if (!S_ISREG(st.st_mode))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_NOT_REGULAR, "%s: refused (only regular files "
                           "are read)", hd__io_kind(st.st_mode));
#if defined(HD__O_NOFOLLOW)
    if (nofollow) flags |= HD__O_NOFOLLOW;
#else
    (void)nofollow;
#endif
    fd = open(path, flags);
    if (fd < 0) return HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "cannot open: %s", strerror(errno));
    if (fstat(fd, &st2) != 0 || !S_ISREG(st2.st_mode) || st2.st_dev != st.st_dev ||
        st2.st_ino != st.st_ino) {
        close(fd);
        return HD__IO_FAIL(logger, HD_ERROR_FILE_NOT_REGULAR,
                           "the file changed between stat and open: refused");
    }
    s->fd = fd;
    s->size = st2.st_size > 0 ? (uint64_t)st2.st_size : 0;
    return HD_SUCCESS;
}

/* Up to max bytes from pos on, *n == 0 at the end; *p points into the buffer or into the read
   buffer (valid until the next call). A file that shrank since it was opened ends early. */
static hd_result hd__io_src_next(hd__io_src *s, size_t max, const unsigned char **p, size_t *n,
                                 const hd_logger *logger)
{
    uint64_t left = s->pos < s->size ? s->size - s->pos : 0;
    size_t want = left < (uint64_t)max ? (size_t)left : max;
    *p = NULL;
    *n = 0;
    if (!want) return HD_SUCCESS;
    if (s->mem) {
        *p = s->mem + s->pos;
        *n = want;
        s->pos += want;
        return HD_SUCCESS;
    }
    if (want > HD__IO_CHUNK) want = HD__IO_CHUNK;
    if (!s->buf && !(s->buf = (unsigned char *)hd__io_alloc(s->o, HD__IO_CHUNK)))
        return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "cannot allocate a read buffer");
    for (;;) {
        ssize_t got = lseek(s->fd, (off_t)s->pos, SEEK_SET) == (off_t)-1 ? -1
                      : read(s->fd, s->buf, want);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "read error: %s", strerror(errno));
        if (got == 0) s->size = s->pos;
        *p = s->buf;
        *n = (size_t)got;
        s->pos += (uint64_t)got;
        return HD_SUCCESS;
    }
}

/* Copies up to n bytes from pos on into dst; *got says how many there were. */
static hd_result hd__io_src_read(hd__io_src *s, unsigned char *dst, size_t n, size_t *got,
                                 const hd_logger *logger)
{
    *got = 0;
    while (*got < n) {
        const unsigned char *p;
        size_t m;
        hd_result r = hd__io_src_next(s, n - *got, &p, &m, logger);
        if (r != HD_SUCCESS) return r;
        if (!m) break;
        memcpy(dst + *got, p, m);
        *got += m;
    }
    return HD_SUCCESS;
}

/* Returns the offset just past the header's end in b[0..n), 0 if it is not there yet. */
typedef size_t (*hd__io_end_fn)(const unsigned char *b, size_t n);

/* A text header: the first bytes of a file, read until end() finds its end, the file ends, or
   HD__IO_HEADER_MAX bytes (HD_ERROR_FILE_FORMAT). *out is allocated through s's options. */
static hd_result hd__io_read_header(hd__io_src *s, hd__io_end_fn end, unsigned char **out,
                                    size_t *out_n, const char *what, const hd_logger *logger)
{
    size_t cap = 4096, n = 0, got;
    unsigned char *b = NULL;
    hd_result r;
    *out = NULL;
    *out_n = 0;
    s->pos = 0;
    for (;;) {
        unsigned char *nb = (unsigned char *)hd__io_alloc(s->o, cap);
        if (!nb) {
            hd__io_free(s->o, b);
            return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "cannot allocate %zu bytes for "
                               "the header", cap);
        }
        if (n) memcpy(nb, b, n);
        hd__io_free(s->o, b);
        b = nb;
        r = hd__io_src_read(s, b + n, cap - n, &got, logger);
        if (r != HD_SUCCESS) {
            hd__io_free(s->o, b);
            return r;
        }
        n += got;
        if (n < cap || end(b, n)) break; /* the file ended, or the header did */
        if (cap >= HD__IO_HEADER_MAX) {
            hd__io_free(s->o, b);
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "%s: no end of the header in the first %zu bytes", what, cap);
        }
        cap *= 2;
    }
    *out = b;
    *out_n = n;
    return HD_SUCCESS;
}

/* ---- gzip ------------------------------------------------------------------------------------- */
#ifndef HYBRIDDIFF_NO_ZLIB
/* A gzip or zlib stream of in_left bytes of a source, from its current position on; zlib's own
   memory comes from the loader's allocator. */
typedef struct hd__io_gz {
    z_stream zs;
    hd__io_src *src;
    uint64_t in_left;  /* bytes of the source not yet given to zlib */
    int ended;         /* Z_STREAM_END seen (its check value verified) */
    hd_result src_err; /* a read error, when hd__io_gz_read returns Z_ERRNO */
    const hd_logger *logger;
} hd__io_gz;

static voidpf hd__io_zalloc(voidpf opaque, uInt items, uInt size)
{
    if (size && items > SIZE_MAX / size) return Z_NULL;
    return hd__io_alloc((const hd__io_opt *)opaque, (size_t)items * size);
}

static void hd__io_zfree(voidpf opaque, voidpf p)
{
    hd__io_free((const hd__io_opt *)opaque, p);
}

static hd_result hd__io_gzip_error(int r, const hd__io_gz *g, const char *stage,
                                   const char *what, const hd_logger *logger)
{
    if (r == Z_ERRNO) return g->src_err; /* logged by the source */
    if (r == Z_MEM_ERROR)
        return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "%s: zlib is out of memory", what);
    if (r == Z_BUF_ERROR)
        return HD__IO_FAIL(logger, HD_ERROR_GZIP, "%s: gzip stream is truncated (%s)", what,
                           stage);
    return HD__IO_FAIL(logger, HD_ERROR_GZIP, "%s: gzip stream is corrupt (%s): %s", what, stage,
                       g->zs.msg ? g->zs.msg : "zlib error");
}

static hd_result hd__io_gz_init(hd__io_gz *g, hd__io_src *src, uint64_t in_len,
                                const char *what, const hd_logger *logger)
{
    int r;
    memset(g, 0, sizeof *g);
    g->src = src;
    g->in_left = in_len;
    g->logger = logger;
    g->zs.zalloc = hd__io_zalloc;
    g->zs.zfree = hd__io_zfree;
    g->zs.opaque = (voidpf)src->o;
    r = inflateInit2(&g->zs, 15 + 32); /* gzip or zlib header */
    if (r != Z_OK) return hd__io_gzip_error(r, g, "init", what, logger);
    return HD_SUCCESS;
}

/* Inflates up to n bytes into dst; *got: how many. Returns Z_OK (dst full), Z_STREAM_END,
   Z_BUF_ERROR (the input ended first), Z_ERRNO (a read error, in src_err) or a zlib error. */
static int hd__io_gz_read(hd__io_gz *g, unsigned char *dst, size_t n, size_t *got)
{
    *got = 0;
    while (*got < n) {
        size_t want = n - *got;
        uInt chunk = want > (size_t)UINT_MAX ? UINT_MAX : (uInt)want;
        int r;
        if (g->zs.avail_in == 0 && g->in_left > 0) {
            const unsigned char *p;
            size_t m;
            hd_result e = hd__io_src_next(g->src, g->in_left < (uint64_t)UINT_MAX
                                                      ? (size_t)g->in_left : (size_t)UINT_MAX,
                                          &p, &m, g->logger);
            if (e != HD_SUCCESS) {
                g->src_err = e;
                return Z_ERRNO;
            }
            g->in_left = m ? g->in_left - m : 0;
            g->zs.next_in = (Bytef *)p;
            g->zs.avail_in = (uInt)m;
        }
        g->zs.next_out = dst + *got;
        g->zs.avail_out = chunk;
        r = inflate(&g->zs, Z_NO_FLUSH);
        *got += chunk - g->zs.avail_out;
        if (r == Z_STREAM_END) {
            g->ended = 1;
            return r;
        }
        if (r == Z_OK || r == Z_BUF_ERROR) {
            if (g->zs.avail_out != 0 && g->zs.avail_in == 0 && g->in_left == 0) return Z_BUF_ERROR;
            continue;
        }
        return r;
    }
    return Z_OK;
}

/* From the stream's current position: drops skip bytes, converts count elements of type
   (allocated as they inflate), then inflates the rest of the stream to check it. */
static hd_result hd__io_gz_data(hd__io_gz *g, uint64_t skip, size_t count, int type, int big,
                                hd_volume_file *out, const char *what, const hd_logger *logger)
{
    const hd__io_opt *o = g->src->o;
    unsigned char *scratch = (unsigned char *)hd__io_alloc(o, HD__IO_CHUNK);
    uint64_t skipped = 0;
    size_t got, total = 0;
    hd__io_conv c;
    hd_result res = HD_SUCCESS;
    int r = Z_OK;
    memset(&c, 0, sizeof c);
    if (!scratch)
        return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "%s: cannot allocate %zu bytes", what,
                           HD__IO_CHUNK);
    while (skipped < skip) {
        uint64_t left = skip - skipped;
        r = hd__io_gz_read(g, scratch, left < HD__IO_CHUNK ? (size_t)left : HD__IO_CHUNK, &got);
        skipped += got;
        if (r == Z_STREAM_END && skipped < skip) {
            res = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                              "%s: gzip stream holds %llu bytes, less than the %llu to skip",
                              what, (unsigned long long)skipped, (unsigned long long)skip);
            goto done;
        }
        if (r != Z_OK && r != Z_STREAM_END) {
            res = hd__io_gzip_error(r, g, "in the skipped bytes", what, logger);
            goto done;
        }
    }
    res = hd__io_conv_begin(&c, count, type, big, 1, o, what, logger);
    while (res == HD_SUCCESS && hd__io_conv_left(&c) > 0) {
        size_t left = hd__io_conv_left(&c);
        r = hd__io_gz_read(g, scratch, left < HD__IO_CHUNK ? left : HD__IO_CHUNK, &got);
        total += got;
        if (r != Z_OK && r != Z_STREAM_END) {
            res = hd__io_gzip_error(r, g, "in the data", what, logger);
            break;
        }
        res = hd__io_conv_feed(&c, scratch, got, o, what, logger);
        if (res == HD_SUCCESS && r == Z_STREAM_END && hd__io_conv_left(&c) > 0)
            res = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                              "%s: header claims %zu bytes of data, gzip stream holds %zu",
                              what, count * c.esize, total);
    }
    while (res == HD_SUCCESS && !g->ended) { /* the rest of the stream, for its check value */
        r = hd__io_gz_read(g, scratch, HD__IO_CHUNK, &got);
        if (r != Z_OK && r != Z_STREAM_END)
            res = hd__io_gzip_error(r, g, "after the data", what, logger);
    }
    if (res == HD_SUCCESS) hd__io_conv_end(&c, out, o, what, logger);
done:
    hd__io_conv_drop(&c, o);
    hd__io_free(o, scratch);
    return res;
}
#endif

/* ---- voxel data -------------------------------------------------------------------------------- */
/* count elements of type at offset of s, raw (the caller has checked that the source holds
   them) or, gzip != 0, a stream of in_len bytes there whose first skip inflated bytes are
   dropped. Fills out's data, type and value range. */
static hd_result hd__io_data(hd__io_src *s, uint64_t offset, int gzip, uint64_t in_len,
                             uint64_t skip, size_t count, int type, int big, hd_volume_file *out,
                             const char *what, const hd_logger *logger)
{
    hd__io_conv c;
    hd_result r;
    s->pos = offset;
    if (gzip) {
#ifdef HYBRIDDIFF_NO_ZLIB
        (void)in_len; (void)skip; (void)count; (void)type; (void)big; (void)out;
        return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                           "%s: gzip encoding needs zlib (built with HYBRIDDIFF_NO_ZLIB)", what);
#else
        hd__io_gz g;
        r = hd__io_gz_init(&g, s, in_len, what, logger);
        if (r != HD_SUCCESS) return r;
        r = hd__io_gz_data(&g, skip, count, type, big, out, what, logger);
        inflateEnd(&g.zs);
        return r;
#endif
    }
    r = hd__io_conv_begin(&c, count, type, big, 0, s->o, what, logger);
    while (r == HD_SUCCESS && hd__io_conv_left(&c) > 0) {
        const unsigned char *p;
        size_t n, left = hd__io_conv_left(&c);
        r = hd__io_src_next(s, left, &p, &n, logger);
        if (r == HD_SUCCESS && n == 0)
            r = HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                            "%s: the file ended %zu bytes before the end of the data", what,
                            left);
        if (r == HD_SUCCESS) r = hd__io_conv_feed(&c, p, n, s->o, what, logger);
    }
    if (r == HD_SUCCESS) hd__io_conv_end(&c, out, s->o, what, logger);
    hd__io_conv_drop(&c, s->o);
    return r;
}

HDDEF void hd_volume_free(hd_volume_file *vol)
{
    if (!vol) return;
    if (vol->data) {
        if (vol->allocator.free) vol->allocator.free(vol->data, vol->allocator.user_data);
        else free(vol->data);
    }
    memset(vol, 0, sizeof *vol);
}

/* The NRRD header in buf[0..size) (a memory source's bytes, or a file's first bytes up to the
   blank line at least), then the data from s, where the header's offsets point. */
static hd_result hd__io_nrrd_load(const unsigned char *buf, size_t size, hd__io_src *s,
                             hd_volume_file *out, const hd__io_opt *o, const hd_logger *logger)
{
    size_t pos, count = 0, data_bytes = 0;
    uint64_t avail;
    int64_t dims[3];
    int line = 1, ended = 0, overflow = 0, i;
    hd__io_nrrd h;
    hd_result r;

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
        const char *t = (const char *)buf + start;
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
        if (t[0] == '#') continue;
        for (colon = 0; colon < len && t[colon] != ':'; ++colon) {}
        if (colon == len)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: line %d is not 'field: value' (no ':')", line);
        if (colon + 1 < len && t[colon + 1] == '=') continue; /* 'key:=value' pair */
        for (k = 0; k < colon; ++k) { /* the name, lower case, without spaces */
            int c = (unsigned char)t[k];
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
        r = hd__io_nrrd_field(&h, name, t + colon + 1, len - colon - 1, line, logger);
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
    r = hd__io_check_limit(count, h.type, o, "nrrd", logger);
    if (r != HD_SUCCESS) return r;
    r = hd__io_nrrd_spacing(&h, out->desc.spacing, logger);
    if (r != HD_SUCCESS) return r;
    if (!h.have_endian && hd__io_type_size(h.type) > 1)
        HD__IO_WARN(logger, "nrrd: no 'endian' field for a multi-byte type; assuming little");

    /* line skip: whole lines of the file after the header */
    s->pos = pos;
    for (i = 0; (int64_t)i < h.line_skip; ++i) {
        for (;;) {
            const unsigned char *p, *nl;
            size_t n;
            r = hd__io_src_next(s, HD__IO_CHUNK, &p, &n, logger);
            if (r != HD_SUCCESS) return r;
            if (n == 0)
                return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                                   "nrrd: file ends inside the %lld lines to skip",
                                   (long long)h.line_skip);
            nl = (const unsigned char *)memchr(p, '\n', n);
            if (nl) {
                s->pos -= n - (size_t)(nl - p) - 1; /* back to just past the '\n' */
                break;
            }
        }
    }
    avail = s->size - s->pos;

    if (h.encoding == 1) {
        uint64_t at;
        if (h.byte_skip == -1) { /* the data are the last bytes of the file */
            if (avail < data_bytes) goto truncated;
            at = s->size - data_bytes;
        } else {
            if ((uint64_t)h.byte_skip > avail)
                return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                                   "nrrd: byte skip %lld is past the end of the file "
                                   "(%llu bytes after the header)",
                                   (long long)h.byte_skip, (unsigned long long)avail);
            avail -= (uint64_t)h.byte_skip;
            if (avail < data_bytes) goto truncated;
            at = s->pos + (uint64_t)h.byte_skip;
        }
        r = hd__io_data(s, at, 0, 0, 0, count, h.type, h.big, out, "nrrd", logger);
    } else {
        if (h.byte_skip < 0)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "nrrd: byte skip -1 is only allowed with raw encoding");
        r = hd__io_data(s, s->pos, 1, avail, (uint64_t)h.byte_skip, count, h.type, h.big, out,
                        "nrrd", logger);
    }
    if (r != HD_SUCCESS) return r;
    for (i = 0; i < 3; ++i) out->desc.dims[i] = (int)dims[i];
    return HD_SUCCESS;
truncated:
    return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                       "nrrd: header claims %zu bytes of data, file has %llu", data_bytes,
                       (unsigned long long)avail);
}

HDDEF hd_result hd_volume_parse_nrrd(const void *bytes, size_t size, hd_volume_file *out,
                                     const hd_logger *logger)
{
    hd__io_opt o;
    hd__io_src s;
    hd_result r;
    if (out) memset(out, 0, sizeof *out);
    if (!bytes || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "nrrd: %s is NULL",
                           !out ? "out" : "bytes");
    hd__io_opt_init(&o, NULL);
    hd__io_src_mem(&s, bytes, size, &o);
    r = hd__io_nrrd_load((const unsigned char *)bytes, size, &s, out, &o, logger);
    if (r != HD_SUCCESS) hd_volume_free(out);
    return r;
}

/* A NRRD header ends at its first empty line. */
static size_t hd__io_nrrd_end(const unsigned char *b, size_t n)
{
    size_t i;
    for (i = 1; i < n; ++i)
        if (b[i] == '\n' && (b[i - 1] == '\n' || (i >= 2 && b[i - 1] == '\r' && b[i - 2] == '\n')))
            return i + 1;
    return 0;
}

/* A loader of one file: opened (regular files only), then fn on it, with the path in front of
   every logged message; out is empty after an error. */
typedef hd_result (*hd__io_file_fn)(hd__io_src *s, const char *path, hd_volume_file *out,
                                    const hd__io_opt *o, const hd_logger *logger);

static hd_result hd__io_nrrd_file(hd__io_src *s, const char *path, hd_volume_file *out,
                                  const hd__io_opt *o, const hd_logger *logger)
{
    unsigned char *head;
    size_t n;
    hd_result r = hd__io_read_header(s, hd__io_nrrd_end, &head, &n, "nrrd", logger);
    (void)path;
    if (r != HD_SUCCESS) return r;
    r = hd__io_nrrd_load(head, n, s, out, o, logger);
    hd__io_free(o, head);
    return r;
}

static hd_result hd__io_load_file(const char *path, const hd__io_opt *o, hd_volume_file *out,
                                  const hd_logger *logger, const char *format, hd__io_file_fn fn)
{
    hd__io_path_logger pl;
    hd_logger wrapped;
    const hd_logger *lg;
    hd__io_src s;
    hd_result r;
    if (out) memset(out, 0, sizeof *out);
    if (!path || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "%s: %s is NULL", format,
                           !path ? "path" : "out");
    lg = hd__io_wrap_logger(logger, path, &pl, &wrapped);
    r = hd__io_open(path, 0, &s, o, lg);
    if (r != HD_SUCCESS) return r;
    r = fn(&s, path, out, o, lg);
    hd__io_src_close(&s);
    if (r != HD_SUCCESS) hd_volume_free(out);
    return r;
}

HDDEF hd_result hd_volume_load_nrrd(const char *path, hd_volume_file *out,
                                    const hd_logger *logger)
{
    hd__io_opt o;
    hd__io_opt_init(&o, NULL);
    return hd__io_load_file(path, &o, out, logger, "nrrd", hd__io_nrrd_file);
}

HDDEF hd_result hd_volume_load_raw(const char *path, const int dims[3], hd_raw_type type,
                                   hd_endian endian, size_t offset, hd_volume_file *out,
                                   const hd_logger *logger)
{
    hd__io_path_logger pl;
    hd_logger wrapped;
    const hd_logger *lg;
    int64_t d[3];
    size_t count, bytes;
    hd__io_opt o;
    hd__io_src s;
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
    hd__io_opt_init(&o, NULL);
    r = hd__io_open(path, 0, &s, &o, lg);
    if (r != HD_SUCCESS) return r;
    /* the size before allocating: dims from a typo must not allocate gigabytes */
    if (s.size < (uint64_t)(offset + bytes)) {
        r = HD__IO_FAIL(lg, HD_ERROR_FILE_TRUNCATED,
                        "raw: %d x %d x %d voxels of %u bytes at offset %zu need %zu bytes, "
                        "file has %llu", dims[0], dims[1], dims[2],
                        (unsigned)hd__io_type_size((int)type), offset, offset + bytes,
                        (unsigned long long)s.size);
    } else {
        r = hd__io_data(&s, offset, 0, 0, 0, count, (int)type, endian == HD_ENDIAN_BIG, out,
                        "raw", lg);
    }
    hd__io_src_close(&s);
    if (r != HD_SUCCESS) {
        hd_volume_free(out);
        return r;
    }
    for (i = 0; i < 3; ++i) {
        out->desc.dims[i] = dims[i];
        out->desc.spacing[i] = 1.0f;
    }
    return HD_SUCCESS;
}

#endif /* HD_IO_H */
