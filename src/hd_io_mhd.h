/* hd_io_mhd.h - the MetaImage loader (.mhd header + detached .raw/.zraw, or .mha/.mhd with
   'ElementDataFile = LOCAL'). Part of the implementation of hybriddiff.h; included once, after
   src/hd_io.h, whose helpers it uses (size checks, conversion, number parsing, gunzip, logging).

   Header: 'Key = Value' lines, keys case-insensitive, up to ElementDataFile (the last field).
   Read: NDims (1..3), DimSize, ElementSpacing (or ElementSize), ElementType (MET_UCHAR, MET_CHAR,
   MET_USHORT, MET_SHORT, MET_UINT, MET_INT, MET_ULONG, MET_LONG, MET_ULONG_LONG, MET_LONG_LONG,
   MET_FLOAT, MET_DOUBLE), ElementNumberOfChannels (1), BinaryData (True),
   BinaryDataByteOrderMSB / ElementByteOrderMSB, CompressedData (zlib or gzip),
   CompressedDataSize, HeaderSize (bytes to skip in the data file; -1: the data are its last
   bytes). ElementDataFile: LOCAL (the bytes after that line) or a file name, relative to the
   header's directory; LIST and slice patterns are HD_ERROR_UNSUPPORTED_ENCODING. A file name
   must resolve (realpath) inside the header's folder, else HD_ERROR_FILE_OUTSIDE_FOLDER, unless
   hd_load_options.allow_outside_folder; the data file must be regular (HD_ERROR_FILE_NOT_REGULAR)
   and only the bytes the header needs are read from it.
   Errors as for NRRD: a data file shorter than the header claims is HD_ERROR_FILE_TRUNCATED,
   a DimSize product that overflows HD_ERROR_SIZE_OVERFLOW, negative/zero/NaN spacing
   HD_ERROR_INVALID_SPACING, unknown element types HD_ERROR_UNSUPPORTED_ENCODING, a corrupt or
   truncated compressed stream HD_ERROR_GZIP. */
#ifndef HD_IO_MHD_H
#define HD_IO_MHD_H

#define HD__MHD_FIELD 256

typedef struct hd__io_mhd {
    int ndims;                    /* 0 unknown */
    int type;                     /* HD__IO_*, -1 unknown */
    int big, compressed;
    int64_t compressed_size;      /* -1 unknown */
    int64_t header_size;          /* 0, or -1: the data are the last bytes of the data file */
    char dim_size[HD__MHD_FIELD]; /* texts parsed once NDims is known */
    char spacing[HD__MHD_FIELD];
    char element_size[HD__MHD_FIELD];
    char data_file[HD__MHD_FIELD];
    int local;                    /* ElementDataFile = LOCAL */
    size_t data_pos;              /* LOCAL: where the data start in the header buffer */
} hd__io_mhd;

static int hd__io_mhd_bool(const char *v, int *out)
{
    if (!strcmp(v, "true") || !strcmp(v, "1")) *out = 1;
    else if (!strcmp(v, "false") || !strcmp(v, "0")) *out = 0;
    else return 0;
    return 1;
}

static int hd__io_mhd_type(const char *v)
{
    static const struct { const char *name; int type; } names[] = {
        {"met_uchar", HD__IO_U8}, {"met_char", HD__IO_I8}, {"met_ushort", HD__IO_U16},
        {"met_short", HD__IO_I16}, {"met_uint", HD__IO_U32}, {"met_int", HD__IO_I32},
        {"met_ulong", HD__IO_U32}, {"met_long", HD__IO_I32}, {"met_ulong_long", HD__IO_U64},
        {"met_long_long", HD__IO_I64}, {"met_float", HD__IO_F32}, {"met_double", HD__IO_F64},
    };
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; ++i)
        if (strcmp(v, names[i].name) == 0) return names[i].type;
    return -1;
}

/* One 'key = value' line; key lower-case without spaces, value as in the file (trimmed). */
static hd_result hd__io_mhd_field(hd__io_mhd *h, const char *key, const char *raw, int line,
                                  const hd_logger *logger)
{
    char v[HD__MHD_FIELD];
    int64_t n;
    int b;
    const char *e;
    if (!strcmp(key, "dimsize") || !strcmp(key, "elementspacing") ||
        !strcmp(key, "elementsize") || !strcmp(key, "elementdatafile")) {
        char *dst = !strcmp(key, "dimsize") ? h->dim_size
                    : !strcmp(key, "elementspacing") ? h->spacing
                    : !strcmp(key, "elementsize") ? h->element_size : h->data_file;
        if (!hd__io_copy(dst, HD__MHD_FIELD, raw, strlen(raw)))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: line %d ('%s') is too long",
                               line, key);
        return HD_SUCCESS;
    }
    if (!hd__io_copy(v, sizeof v, raw, strlen(raw)))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: line %d ('%s') is too long", line,
                           key);
    hd__io_normalize(v);
    if (!strcmp(key, "ndims")) {
        e = hd__io_parse_int(v, &n, NULL);
        if (!e || *e)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "mhd: line %d: NDims is not an integer: '%s'", line, v);
        if (n < 1 || n > 3)
            return HD__IO_FAIL(logger, HD_ERROR_INVALID_DIMENSIONS,
                               "mhd: line %d: NDims %lld is not supported (1, 2 or 3)", line,
                               (long long)n);
        h->ndims = (int)n;
    } else if (!strcmp(key, "elementtype")) {
        h->type = hd__io_mhd_type(v);
        if (h->type < 0)
            return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                               "mhd: line %d: unsupported ElementType '%s'", line, v);
    } else if (!strcmp(key, "elementnumberofchannels")) {
        e = hd__io_parse_int(v, &n, NULL);
        if (!e || *e || n != 1)
            return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                               "mhd: line %d: ElementNumberOfChannels '%s' (only 1 is supported)",
                               line, v);
    } else if (!strcmp(key, "binarydatabyteordermsb") || !strcmp(key, "elementbyteordermsb") ||
               !strcmp(key, "byteordermsb") || !strcmp(key, "compresseddata") ||
               !strcmp(key, "binarydata")) {
        if (!hd__io_mhd_bool(v, &b))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "mhd: line %d: '%s' must be True or False, not '%s'", line, key, v);
        if (!strcmp(key, "compresseddata")) h->compressed = b;
        else if (!strcmp(key, "binarydata")) {
            if (!b)
                return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                                   "mhd: line %d: ASCII data (BinaryData = False) is not supported",
                                   line);
        } else h->big = b;
    } else if (!strcmp(key, "headersize") || !strcmp(key, "compresseddatasize")) {
        int head = !strcmp(key, "headersize");
        e = hd__io_parse_int(v, &n, NULL);
        if (!e || *e || n < (head ? -1 : 0))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "mhd: line %d: '%s' must be an integer >= %d, not '%s'", line, key,
                               head ? -1 : 0, v);
        if (head) h->header_size = n;
        else h->compressed_size = n;
    }
    return HD_SUCCESS; /* ObjectType, Offset, TransformMatrix... are not needed */
}

/* Parses the header lines up to ElementDataFile. */
static hd_result hd__io_mhd_header(const unsigned char *buf, size_t size, hd__io_mhd *h,
                                   const hd_logger *logger)
{
    size_t pos = 0;
    int line = 0;
    hd_result r;
    memset(h, 0, sizeof *h);
    h->type = -1;
    h->compressed_size = -1;
    while (pos < size) {
        size_t start = pos, end, eq, k, nl = 0;
        char key[64], val[HD__IO_LINE_MAX];
        const char *s = (const char *)buf + start;
        ++line;
        while (pos < size && buf[pos] != '\n') ++pos;
        end = pos;
        if (pos < size) ++pos;
        if (end > start && buf[end - 1] == '\r') --end;
        if (end == start || s[0] == '#') continue;
        for (eq = 0; start + eq < end && s[eq] != '='; ++eq) {}
        if (start + eq == end)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "mhd: line %d is not 'Key = Value' (no '=')%s", line,
                               line == 1 ? ": not a MetaImage header" : "");
        for (k = 0; k < eq; ++k) {
            int c = (unsigned char)s[k];
            if (hd__io_space(c)) continue;
            if (nl + 1 >= sizeof key || c < 32 || c > 126)
                return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: line %d: bad key", line);
            key[nl++] = (char)hd__io_lower(c);
        }
        key[nl] = 0;
        if (!nl) return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: line %d: empty key", line);
        if (!hd__io_copy(val, sizeof val, s + eq + 1, end - start - eq - 1))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: line %d is too long", line);
        { /* trim */
            char *a = val, *z;
            size_t vl;
            while (hd__io_space((unsigned char)*a)) ++a;
            vl = strlen(a);
            z = a + vl;
            while (z > a && hd__io_space((unsigned char)z[-1])) --z;
            *z = 0;
            memmove(val, a, (size_t)(z - a) + 1);
        }
        r = hd__io_mhd_field(h, key, val, line, logger);
        if (r != HD_SUCCESS) return r;
        if (!strcmp(key, "elementdatafile")) {
            h->data_pos = pos;
            break;
        }
    }
    if (!h->ndims || !h->dim_size[0] || h->type < 0 || !h->data_file[0])
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: header has no '%s' field",
                           !h->ndims ? "NDims" : !h->dim_size[0] ? "DimSize"
                           : h->type < 0 ? "ElementType" : "ElementDataFile");
    {
        char low[HD__MHD_FIELD];
        memcpy(low, h->data_file, sizeof low);
        hd__io_normalize(low);
        h->local = !strcmp(low, "local");
        if (!strcmp(low, "list") || strchr(low, '%'))
            return HD__IO_FAIL(logger, HD_ERROR_UNSUPPORTED_ENCODING,
                               "mhd: ElementDataFile '%s': slice lists and patterns are not "
                               "supported", h->data_file);
    }
    return HD_SUCCESS;
}

/* DimSize and spacing, then the data: the bytes of s from base on (the data file, or what
   follows the ElementDataFile = LOCAL line). */
static hd_result hd__io_mhd_data(const hd__io_mhd *h, hd__io_src *s, uint64_t base,
                                 hd_volume_file *out, const hd__io_opt *o,
                                 const hd_logger *logger)
{
    int64_t dims[3] = {1, 1, 1};
    int overflow = 0, i;
    size_t count, bytes;
    uint64_t data_size = s->size > base ? s->size - base : 0, skip;
    const char *p = h->dim_size;
    hd_result r;
    for (i = 0; i < h->ndims; ++i) {
        p = hd__io_parse_int(p, &dims[i], &overflow);
        if (!p || (*p && !hd__io_space((unsigned char)*p)))
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: DimSize needs %d integers",
                               h->ndims);
    }
    if (*hd__io_skip_space(p))
        return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT, "mhd: DimSize has more than %d values",
                           h->ndims);
    r = hd__io_check_dims(dims, hd__io_type_size(h->type), overflow, &count, &bytes, "mhd",
                          logger);
    if (r != HD_SUCCESS) return r;
    r = hd__io_check_limit(count, h->type, o, "mhd", logger);
    if (r != HD_SUCCESS) return r;
    out->desc.spacing[0] = out->desc.spacing[1] = out->desc.spacing[2] = 1.0f;
    p = h->spacing[0] ? h->spacing : h->element_size[0] ? h->element_size : NULL;
    if (p) {
        for (i = 0; i < h->ndims; ++i) {
            double sp;
            p = hd__io_parse_double(p, &sp);
            if (!p || (*p && !hd__io_space((unsigned char)*p)))
                return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                                   "mhd: ElementSpacing needs %d numbers", h->ndims);
            if (!hd__io_spacing_valid(sp))
                return HD__IO_FAIL(logger, HD_ERROR_INVALID_SPACING,
                                   "mhd: spacing of axis %d is %g (must be finite and > 0)", i,
                                   sp);
            out->desc.spacing[i] = (float)sp;
        }
    }
    if (h->compressed) {
        uint64_t len;
        if (h->header_size < 0)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_FORMAT,
                               "mhd: HeaderSize -1 is only allowed for uncompressed data");
        if ((uint64_t)h->header_size > data_size)
            return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                               "mhd: HeaderSize %lld is past the end of the data (%llu bytes)",
                               (long long)h->header_size, (unsigned long long)data_size);
        skip = (uint64_t)h->header_size;
        len = data_size - skip;
        if (h->compressed_size >= 0) {
            if ((uint64_t)h->compressed_size > len)
                return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                                   "mhd: CompressedDataSize %lld, the file holds %llu bytes",
                                   (long long)h->compressed_size, (unsigned long long)len);
            len = (uint64_t)h->compressed_size;
        }
        r = hd__io_data(s, base + skip, 1, len, 0, count, h->type, h->big, out, "mhd", logger);
    } else {
        if (h->header_size < 0) {
            if (data_size < bytes) goto truncated;
            skip = data_size - bytes;
        } else {
            if ((uint64_t)h->header_size > data_size ||
                data_size - (uint64_t)h->header_size < bytes)
                goto truncated;
            skip = (uint64_t)h->header_size;
        }
        r = hd__io_data(s, base + skip, 0, 0, 0, count, h->type, h->big, out, "mhd", logger);
    }
    if (r != HD_SUCCESS) return r;
    for (i = 0; i < 3; ++i) out->desc.dims[i] = (int)dims[i];
    return HD_SUCCESS;
truncated:
    return HD__IO_FAIL(logger, HD_ERROR_FILE_TRUNCATED,
                       "mhd: header claims %zu bytes of data after a HeaderSize of %lld, the data "
                       "hold %llu", bytes, (long long)h->header_size,
                       (unsigned long long)data_size);
}

HDDEF hd_result hd_volume_parse_mhd(const void *header, size_t header_size, const void *data,
                                    size_t data_size, hd_volume_file *out,
                                    const hd_logger *logger)
{
    hd__io_mhd h;
    hd__io_opt o;
    hd__io_src s;
    hd_result r;
    if (out) memset(out, 0, sizeof *out);
    if (!header || !out)
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER, "mhd: %s is NULL",
                           !out ? "out" : "header");
    r = hd__io_mhd_header((const unsigned char *)header, header_size, &h, logger);
    if (r != HD_SUCCESS) return r;
    hd__io_opt_init(&o, NULL);
    if (h.local) {
        hd__io_src_mem(&s, header, header_size, &o);
        r = hd__io_mhd_data(&h, &s, h.data_pos, out, &o, logger);
    } else if (!data) {
        return HD__IO_FAIL(logger, HD_ERROR_NULL_POINTER,
                           "mhd: the data are in '%s' and no data buffer was given", h.data_file);
    } else {
        hd__io_src_mem(&s, data, data_size, &o);
        r = hd__io_mhd_data(&h, &s, 0, out, &o, logger);
    }
    if (r != HD_SUCCESS) hd_volume_free(out);
    return r;
}

/* A MetaImage header ends with the line of its ElementDataFile key. */
static size_t hd__io_mhd_end(const unsigned char *b, size_t n)
{
    size_t pos = 0;
    while (pos < n) {
        const unsigned char *nl = (const unsigned char *)memchr(b + pos, '\n', n - pos);
        size_t end = nl ? (size_t)(nl - b) : n, k;
        const char *key = "elementdatafile";
        for (k = pos; k < end && *key; ++k) {
            if (hd__io_space(b[k])) continue;
            if (hd__io_lower(b[k]) != *key++) break;
        }
        if (!*key) {
            while (k < end && hd__io_space(b[k])) ++k;
            if (k < end && b[k] == '=') return nl ? end + 1 : 0;
        }
        if (!nl) break;
        pos = end + 1;
    }
    return 0;
}

/* The path of the detached data file name (relative to the folder of the header at path). Unless
   o->allow_outside, name must be relative and its real path (symbolic links resolved) must lie
   in the folder's real path; *out is then that real path. *out is freed with hd__io_free. */
static hd_result hd__io_mhd_data_path(const char *path, const char *name, const hd__io_opt *o,
                                      char **out, const hd_logger *logger)
{
    const char *slash = strrchr(path, '/');
    size_t dir = slash ? (size_t)(slash - path) + 1 : 0, n;
    int absolute = name[0] == '/';
    char *joined, *rdir = NULL, *rfile = NULL;
    hd_result r = HD_SUCCESS;
    *out = NULL;
    if (absolute && !o->allow_outside)
        return HD__IO_FAIL(logger, HD_ERROR_FILE_OUTSIDE_FOLDER,
                           "mhd: ElementDataFile '%s' is an absolute path: refused "
                           "(hd_load_options.allow_outside_folder allows it)", name);
    if (absolute) dir = 0;
    n = dir + strlen(name) + 1;
    joined = (char *)hd__io_alloc(o, n);
    if (!joined) return HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "mhd: cannot allocate a path");
    memcpy(joined, path, dir);
    memcpy(joined + dir, name, n - dir);
    if (o->allow_outside) {
        *out = joined;
        return HD_SUCCESS;
    }
    rfile = realpath(joined, NULL);
    if (!rfile) {
        r = HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "mhd: data file %s: cannot open: %s", joined,
                        strerror(errno));
    } else {
        joined[dir] = 0; /* the header's folder */
        rdir = realpath(dir ? joined : ".", NULL);
        if (!rdir) {
            r = HD__IO_FAIL(logger, HD_ERROR_FILE_IO, "mhd: the header's folder: %s",
                            strerror(errno));
        } else {
            size_t len = strlen(rdir);
            if (len > 1 && (strncmp(rfile, rdir, len) != 0 || rfile[len] != '/'))
                r = HD__IO_FAIL(logger, HD_ERROR_FILE_OUTSIDE_FOLDER,
                                "mhd: ElementDataFile '%s' is %s, outside the header's folder "
                                "%s: refused (hd_load_options.allow_outside_folder allows it)",
                                name, rfile, rdir);
        }
    }
    if (r == HD_SUCCESS) {
        n = strlen(rfile) + 1;
        if ((*out = (char *)hd__io_alloc(o, n)) != NULL) memcpy(*out, rfile, n);
        else r = HD__IO_FAIL(logger, HD_ERROR_OUT_OF_MEMORY, "mhd: cannot allocate a path");
    }
    free(rfile); /* realpath's, from malloc */
    free(rdir);
    hd__io_free(o, joined);
    return r;
}

static hd_result hd__io_mhd_file(hd__io_src *s, const char *path, hd_volume_file *out,
                                 const hd__io_opt *o, const hd_logger *logger)
{
    unsigned char *head;
    size_t n;
    hd__io_mhd h;
    hd_result r = hd__io_read_header(s, hd__io_mhd_end, &head, &n, "mhd", logger);
    if (r != HD_SUCCESS) return r;
    r = hd__io_mhd_header(head, n, &h, logger);
    hd__io_free(o, head);
    if (r != HD_SUCCESS) return r;
    if (h.local) return hd__io_mhd_data(&h, s, h.data_pos, out, o, logger);
    {
        char *dpath;
        hd__io_src ds;
        r = hd__io_mhd_data_path(path, h.data_file, o, &dpath, logger);
        if (r != HD_SUCCESS) return r;
        {
            hd__io_path_logger pl;
            hd_logger wrapped;
            /* messages about the data file name it after the header's path */
            const hd_logger *dl = hd__io_wrap_logger(logger, dpath, &pl, &wrapped);
            r = hd__io_open(dpath, !o->allow_outside, &ds, o, dl);
        }
        if (r == HD_SUCCESS) {
            r = hd__io_mhd_data(&h, &ds, 0, out, o, logger);
            hd__io_src_close(&ds);
        }
        hd__io_free(o, dpath);
        return r;
    }
}

HDDEF hd_result hd_volume_load_mhd(const char *path, hd_volume_file *out, const hd_logger *logger)
{
    hd__io_opt o;
    hd__io_opt_init(&o, NULL);
    return hd__io_load_file(path, &o, out, logger, "mhd", hd__io_mhd_file);
}

#endif /* HD_IO_MHD_H */
