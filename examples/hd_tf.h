/* hd_tf.h - transfer-function presets and a text TF file parser for the hybriddiff examples
   (hdrender, the viewers). Example helpers, not library API: every function is static, hdx_.

   A transfer function here is a list of control points in data units (Hounsfield units for CT)
   resampled to `count` evenly spaced RGBA entries over a domain [lo, hi]; the volume's
   value_range is set to the domain, so that the library maps lo to the first entry and hi to
   the last (values outside are clamped). rgb is the scattering colour (0..1), alpha scales the
   extinction (0..1): sigma_t = alpha * params.extinction.

   Presets (hdx_tf_preset):
     ct-skin    CT, domain -1024..3071 HU: the skin surface opaque and skin-coloured, bone bright
     ct-bone    CT: bone only (from ~200 HU), ivory
     ct-tissue  CT: the skin faint and pale, muscle and soft tissue red, bone white
     ct-flesh   CT: all soft tissue (skin, fat, muscle, brain) one flesh colour (0.95, 0.50, 0.35)
                at ct-skin's opacities, bone hidden: light seen has scattered many times in
                strongly coloured tissue (the RGB-scattering study)
     ramp       any data: a white ramp over the data's own range (minimum to maximum), the
                lowest 5% transparent

   TF file format (docs/TF_FORMAT.md says the same):
     # a comment; blank lines are ignored; '#' also starts a comment after a value
     domain LO HI          optional: the data values mapped to the first and last entry;
                           default: the first and last control point's value
     entries N             optional: resolution, 2..4096 (default 256)
     VALUE R G B A         a control point, at least two; VALUE in data units, non-decreasing
                           (two points at one value make a step); R G B A in 0..1
   Entry i sits at value lo + (hi - lo) * i / (N - 1) and is the linear interpolation of the two
   control points around it; below the first point it is the first point, above the last the
   last. Numbers are C decimal numbers ('.' as the decimal point, any locale). A file is a regular
   file of at most 1 MiB (hdx_tf_load: a FIFO or device is refused, not waited on); a NUL byte on
   a line is an error, as is a line over 511 characters. */
#ifndef HD_TF_H
#define HD_TF_H

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include "hybriddiff.h"
#if defined(__unix__) || defined(__APPLE__)
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#define HDX_TF_POSIX 1
#endif

#if defined(__GNUC__) || defined(__clang__)
#define HDX_TF_FN static __attribute__((unused))
#else
#define HDX_TF_FN static
#endif

#define HDX_TF_MAX_ENTRIES 4096
#define HDX_TF_MAX_POINTS 256
#define HDX_TF_DEFAULT_ENTRIES 256
#define HDX_TF_MAX_FILE_BYTES (1 << 20)

typedef struct hdx_tf_point {
    float value;   /* data units */
    float rgba[4];
} hdx_tf_point;

typedef struct hdx_tf {
    char name[64];
    float domain[2];     /* data values of the first and last entry */
    int data_domain;     /* 1: use the volume's own range as the domain (the ramp preset) */
    int is_ct;           /* 1: a CT preset over Hounsfield units */
    int count;           /* entries */
    float rgba[HDX_TF_MAX_ENTRIES * 4];
    int point_count;     /* the control points it was made from */
    hdx_tf_point points[HDX_TF_MAX_POINTS];
} hdx_tf;

/* Resamples tf->points to tf->count entries over tf->domain. */
HDX_TF_FN void hdx_tf_resample(hdx_tf *tf)
{
    int i, j = 0, n = tf->count, np = tf->point_count;
    for (i = 0; i < n; ++i) {
        float x = tf->domain[0] + (tf->domain[1] - tf->domain[0]) * (float)i / (float)(n - 1);
        const hdx_tf_point *a, *b;
        float w;
        int c;
        while (j + 1 < np && tf->points[j + 1].value < x) ++j;
        a = &tf->points[j];
        b = &tf->points[j + 1 < np ? j + 1 : j];
        if (x <= a->value || b->value <= a->value) w = x <= a->value ? 0.0f : 1.0f;
        else w = (x - a->value) / (b->value - a->value);
        if (w > 1.0f) w = 1.0f;
        for (c = 0; c < 4; ++c) tf->rgba[4 * i + c] = a->rgba[c] + w * (b->rgba[c] - a->rgba[c]);
    }
}

/* ---- presets ----------------------------------------------------------------------------------- */
/* Control points of the presets: value, r, g, b, a. */
static const float hdx__tf_ct_skin[][5] = {
    {-1024, 0.00f, 0.00f, 0.00f, 0.00f},
    {-500, 0.95f, 0.75f, 0.62f, 0.00f},
    {-250, 0.95f, 0.75f, 0.62f, 0.00f}, /* below fat: air, foam, the head holder */
    {-100, 0.95f, 0.70f, 0.55f, 0.60f}, /* fat, skin */
    {100, 0.92f, 0.58f, 0.48f, 0.70f},  /* muscle, brain */
    {250, 0.93f, 0.70f, 0.60f, 0.70f},
    {500, 1.00f, 0.97f, 0.90f, 0.95f},  /* bone */
    {3071, 1.00f, 1.00f, 0.96f, 1.00f},
};
static const float hdx__tf_ct_bone[][5] = {
    {-1024, 0.00f, 0.00f, 0.00f, 0.00f},
    {150, 0.95f, 0.90f, 0.80f, 0.00f},
    {350, 0.95f, 0.90f, 0.80f, 0.60f},
    {800, 1.00f, 0.97f, 0.90f, 1.00f},
    {3071, 1.00f, 1.00f, 0.96f, 1.00f},
};
static const float hdx__tf_ct_tissue[][5] = {
    {-1024, 0.00f, 0.00f, 0.00f, 0.00f},
    {-400, 0.95f, 0.85f, 0.75f, 0.00f},
    {-150, 0.95f, 0.85f, 0.75f, 0.00f},
    {-90, 0.97f, 0.88f, 0.70f, 0.015f}, /* fat and skin, faint */
    {-20, 0.95f, 0.80f, 0.70f, 0.015f},
    {20, 0.85f, 0.25f, 0.20f, 0.06f},   /* muscle, brain, vessels */
    {80, 0.85f, 0.25f, 0.20f, 0.06f},
    {180, 0.90f, 0.80f, 0.70f, 0.00f},
    {250, 1.00f, 0.98f, 0.94f, 0.50f},  /* bone */
    {800, 1.00f, 1.00f, 1.00f, 1.00f},
    {3071, 1.00f, 1.00f, 1.00f, 1.00f},
};
/* Soft tissue as one optically thick, strongly coloured scatterer, for testing coloured multiple
   scattering (hdeval --rgb-study, examples/eval/head-flesh.scene). Colour: blood-perfused tissue
   scatters red almost without loss, while haemoglobin absorbs green (Q bands, 540-580 nm) and
   blue (Soret band, ~415 nm) strongly; a per-channel albedo of about (0.95, 0.5, 0.35) is that
   of muscle-like "flesh" (before the scene's global albedo multiplies it). Opacity is ct-skin's
   (0.6 for fat and skin, 0.7 for muscle and brain, so the head is tens of mean free paths
   across and its look is multiply scattered light), and bone fades out from 150 to 250 HU and
   stays transparent: white bone (colour 1, where grey and RGB diffusion are identical) would
   otherwise dominate the image, as it does with ct-tissue. */
static const float hdx__tf_ct_flesh[][5] = {
    {-1024, 0.00f, 0.00f, 0.00f, 0.00f},
    {-500, 0.95f, 0.50f, 0.35f, 0.00f},
    {-250, 0.95f, 0.50f, 0.35f, 0.00f}, /* below fat: air, foam, the head holder */
    {-100, 0.95f, 0.50f, 0.35f, 0.60f}, /* fat, skin */
    {100, 0.95f, 0.50f, 0.35f, 0.70f},  /* muscle, brain */
    {150, 0.95f, 0.50f, 0.35f, 0.70f},
    {250, 0.95f, 0.50f, 0.35f, 0.00f},  /* bone and above: hidden */
    {3071, 0.95f, 0.50f, 0.35f, 0.00f},
};
static const float hdx__tf_ramp[][5] = {
    {0.00f, 1.0f, 1.0f, 1.0f, 0.0f},
    {0.05f, 1.0f, 1.0f, 1.0f, 0.0f},
    {1.00f, 1.0f, 1.0f, 1.0f, 1.0f},
};

static const struct hdx__tf_preset {
    const char *name;
    const float (*points)[5];
    int count;
    float domain[2];
    int is_ct;
    const char *help;
} hdx__tf_presets[] = {
    {"ct-skin", hdx__tf_ct_skin, (int)(sizeof hdx__tf_ct_skin / sizeof hdx__tf_ct_skin[0]),
     {-1024.0f, 3071.0f}, 1, "CT: skin surface, bone bright"},
    {"ct-bone", hdx__tf_ct_bone, (int)(sizeof hdx__tf_ct_bone / sizeof hdx__tf_ct_bone[0]),
     {-1024.0f, 3071.0f}, 1, "CT: bone only"},
    {"ct-tissue", hdx__tf_ct_tissue,
     (int)(sizeof hdx__tf_ct_tissue / sizeof hdx__tf_ct_tissue[0]), {-1024.0f, 3071.0f}, 1,
     "CT: faint skin, red muscle, white bone"},
    {"ct-flesh", hdx__tf_ct_flesh, (int)(sizeof hdx__tf_ct_flesh / sizeof hdx__tf_ct_flesh[0]),
     {-1024.0f, 3071.0f}, 1, "CT: soft tissue flesh-coloured, bone hidden"},
    {"ramp", hdx__tf_ramp, (int)(sizeof hdx__tf_ramp / sizeof hdx__tf_ramp[0]), {0.0f, 1.0f}, 0,
     "any data: white ramp over the data's range"},
};
#define HDX_TF_PRESET_COUNT ((int)(sizeof hdx__tf_presets / sizeof hdx__tf_presets[0]))

/* Name and one-line description of preset i (0 <= i < HDX_TF_PRESET_COUNT). */
HDX_TF_FN const char *hdx_tf_preset_name(int i, const char **help)
{
    if (i < 0 || i >= HDX_TF_PRESET_COUNT) return NULL;
    if (help) *help = hdx__tf_presets[i].help;
    return hdx__tf_presets[i].name;
}

/* Fills tf from a preset; 0 if there is no preset of that name. The ramp preset's domain is
   0..1 with data_domain = 1: call hdx_tf_set_domain with the data's range. */
HDX_TF_FN int hdx_tf_preset(const char *name, hdx_tf *tf)
{
    int p, i, c;
    for (p = 0; p < HDX_TF_PRESET_COUNT; ++p)
        if (strcmp(name, hdx__tf_presets[p].name) == 0) break;
    if (p == HDX_TF_PRESET_COUNT) return 0;
    memset(tf, 0, sizeof *tf);
    snprintf(tf->name, sizeof tf->name, "%s", name);
    tf->domain[0] = hdx__tf_presets[p].domain[0];
    tf->domain[1] = hdx__tf_presets[p].domain[1];
    tf->is_ct = hdx__tf_presets[p].is_ct;
    tf->data_domain = !tf->is_ct;
    tf->count = HDX_TF_DEFAULT_ENTRIES;
    tf->point_count = hdx__tf_presets[p].count;
    for (i = 0; i < tf->point_count; ++i) {
        tf->points[i].value = hdx__tf_presets[p].points[i][0];
        for (c = 0; c < 4; ++c) tf->points[i].rgba[c] = hdx__tf_presets[p].points[i][1 + c];
    }
    hdx_tf_resample(tf);
    return 1;
}

/* Moves the TF to a new domain, scaling its control points along (for the ramp preset: the
   data's minimum and maximum). lo < hi. */
HDX_TF_FN void hdx_tf_set_domain(hdx_tf *tf, float lo, float hi)
{
    int i;
    float s = (hi - lo) / (tf->domain[1] - tf->domain[0]);
    for (i = 0; i < tf->point_count; ++i)
        tf->points[i].value = lo + (tf->points[i].value - tf->domain[0]) * s;
    tf->domain[0] = lo;
    tf->domain[1] = hi;
    hdx_tf_resample(tf);
}

/* ---- the text format ----------------------------------------------------------------------------- */
/* Reads one number; locale independent. */
static const char *hdx__tf_number(const char *s, float *out)
{
    double v = 0.0, scale = 1.0;
    int neg = 0, digits = 0, e = 0, eneg = 0;
    while (*s == ' ' || *s == '\t') ++s;
    if (*s == '+' || *s == '-') neg = *s++ == '-';
    for (; *s >= '0' && *s <= '9'; ++s, ++digits) v = v * 10.0 + (*s - '0');
    if (*s == '.')
        for (++s; *s >= '0' && *s <= '9'; ++s, ++digits) v += (*s - '0') * (scale *= 0.1);
    if (!digits) return NULL;
    if (*s == 'e' || *s == 'E') {
        const char *t = s + 1;
        if (*t == '+' || *t == '-') eneg = *t++ == '-';
        if (*t < '0' || *t > '9') return NULL;
        for (; *t >= '0' && *t <= '9'; ++t)
            if (e < 1000) e = e * 10 + (*t - '0');
        v *= pow(10.0, eneg ? -e : e);
        s = t;
    }
    if (*s && *s != ' ' && *s != '\t' && *s != '\r' && *s != '\n') return NULL;
    if (!(v < 3.0e38)) return NULL;
    *out = (float)(neg ? -v : v);
    return s;
}

/* Parses TF text (len bytes, need not be NUL-terminated). name is used in the messages (a file
   name). Returns 1, or 0 with a one-line message "name:LINE: what is wrong" in err. */
HDX_TF_FN int hdx_tf_parse(const char *text, size_t len, const char *name, hdx_tf *tf, char *err,
                           size_t err_size)
{
    size_t pos = 0;
    int line = 0, have_domain = 0, i;
    memset(tf, 0, sizeof *tf);
    snprintf(tf->name, sizeof tf->name, "%s", name);
    tf->count = HDX_TF_DEFAULT_ENTRIES;
    while (pos < len) {
        char buf[512];
        size_t n = 0;
        char *s, *hash;
        ++line;
        while (pos < len && text[pos] != '\n') {
            if (text[pos] == 0) {
                snprintf(err, err_size, "%s:%d: a NUL byte (not a text file?)", name, line);
                return 0;
            }
            if (n + 1 < sizeof buf) buf[n++] = text[pos];
            else {
                snprintf(err, err_size, "%s:%d: line is too long", name, line);
                return 0;
            }
            ++pos;
        }
        ++pos;
        buf[n] = 0;
        if ((hash = strchr(buf, '#')) != NULL) *hash = 0;
        for (s = buf; *s == ' ' || *s == '\t' || *s == '\r'; ++s) {}
        if (!*s) continue;
        if (strncmp(s, "domain", 6) == 0 && (s[6] == ' ' || s[6] == '\t')) {
            const char *p = hdx__tf_number(s + 6, &tf->domain[0]);
            if (p) p = hdx__tf_number(p, &tf->domain[1]);
            if (p) while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
            if (!p || *p || !(tf->domain[1] > tf->domain[0])) {
                snprintf(err, err_size, "%s:%d: expected 'domain LO HI' with LO < HI", name,
                         line);
                return 0;
            }
            have_domain = 1;
        } else if (strncmp(s, "entries", 7) == 0 && (s[7] == ' ' || s[7] == '\t')) {
            float v;
            const char *p = hdx__tf_number(s + 7, &v);
            if (p) while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
            if (!p || *p || v != floorf(v) || v < 2 || v > HDX_TF_MAX_ENTRIES) {
                snprintf(err, err_size, "%s:%d: expected 'entries N' with N in 2..%d", name, line,
                         HDX_TF_MAX_ENTRIES);
                return 0;
            }
            tf->count = (int)v;
        } else {
            hdx_tf_point pt;
            const char *p = hdx__tf_number(s, &pt.value);
            int c;
            for (c = 0; c < 4 && p; ++c) p = hdx__tf_number(p, &pt.rgba[c]);
            if (p) while (*p == ' ' || *p == '\t' || *p == '\r') ++p;
            if (!p || *p) {
                snprintf(err, err_size, "%s:%d: expected 'VALUE R G B A' (5 numbers), "
                         "'domain LO HI' or 'entries N'", name, line);
                return 0;
            }
            for (c = 0; c < 4; ++c)
                if (!(pt.rgba[c] >= 0.0f && pt.rgba[c] <= 1.0f)) {
                    snprintf(err, err_size, "%s:%d: %c = %g is outside 0..1", name, line,
                             "RGBA"[c], (double)pt.rgba[c]);
                    return 0;
                }
            if (tf->point_count && pt.value < tf->points[tf->point_count - 1].value) {
                snprintf(err, err_size, "%s:%d: value %g is below the previous point's %g "
                         "(values must not decrease)", name, line, (double)pt.value,
                         (double)tf->points[tf->point_count - 1].value);
                return 0;
            }
            if (tf->point_count == HDX_TF_MAX_POINTS) {
                snprintf(err, err_size, "%s:%d: more than %d control points", name, line,
                         HDX_TF_MAX_POINTS);
                return 0;
            }
            tf->points[tf->point_count++] = pt;
        }
    }
    if (tf->point_count < 2) {
        snprintf(err, err_size, "%s: needs at least 2 control points 'VALUE R G B A', has %d",
                 name, tf->point_count);
        return 0;
    }
    if (!have_domain) {
        tf->domain[0] = tf->points[0].value;
        tf->domain[1] = tf->points[tf->point_count - 1].value;
        if (!(tf->domain[1] > tf->domain[0])) {
            snprintf(err, err_size, "%s: all control points are at %g; give 'domain LO HI'", name,
                     (double)tf->domain[0]);
            return 0;
        }
    }
    for (i = 0; i < 2; ++i) /* a big domain whose float span overflows */
        if (!(fabsf(tf->domain[i]) < 1e37f)) {
            snprintf(err, err_size, "%s: domain is too large", name);
            return 0;
        }
    hdx_tf_resample(tf);
    return 1;
}

/* Reads a TF file of at most 1 MiB. Returns 1, or 0 with a one-line message in err. Only a
   regular file is read (a FIFO or a device is refused, never waited on). */
HDX_TF_FN int hdx_tf_load(const char *path, hdx_tf *tf, char *err, size_t err_size)
{
    char *buf;
    size_t n = 0;
    int ok, failed = 0;
#ifdef HDX_TF_POSIX
    struct stat st;
    int fd = open(path, O_RDONLY | O_NONBLOCK);
    if (fd < 0) {
        snprintf(err, err_size, "%s: cannot open the transfer function file: %s", path, strerror(errno));
        return 0;
    }
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        snprintf(err, err_size, "%s: not a regular file (a FIFO, device or folder is not read)", path);
        return 0;
    }
#else
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open the transfer function file", path);
        return 0;
    }
#endif
    buf = (char *)malloc(HDX_TF_MAX_FILE_BYTES + 1);
    if (buf) {
#ifdef HDX_TF_POSIX
        for (;;) { /* one byte more than the limit tells a file over it */
            ssize_t r = read(fd, buf + n, HDX_TF_MAX_FILE_BYTES + 1 - n);
            if (r < 0 && errno == EINTR) continue;
            if (r < 0) failed = 1;
            if (r <= 0) break;
            n += (size_t)r;
            if (n == HDX_TF_MAX_FILE_BYTES + 1) break;
        }
        close(fd);
#else
        n = fread(buf, 1, HDX_TF_MAX_FILE_BYTES + 1, f);
        failed = ferror(f);
        fclose(f);
#endif
    } else {
#ifdef HDX_TF_POSIX
        close(fd);
#else
        fclose(f);
#endif
    }
    if (!buf || failed || n > HDX_TF_MAX_FILE_BYTES) {
        snprintf(err, err_size, "%s: %s", path, !buf ? "out of memory" : failed ? "read error" : "larger than 1 MiB");
        free(buf);
        return 0;
    }
    ok = hdx_tf_parse(buf, n, path, tf, err, err_size);
    free(buf);
    return ok;
}

/* Writes tf's control points in the file format (a starting point for an own TF). */
HDX_TF_FN void hdx_tf_write(FILE *out, const hdx_tf *tf)
{
    int i;
    fprintf(out, "# hybriddiff transfer function '%s': VALUE R G B A (docs/TF_FORMAT.md)\n",
            tf->name);
    fprintf(out, "domain %g %g\nentries %d\n", (double)tf->domain[0], (double)tf->domain[1],
            tf->count);
    for (i = 0; i < tf->point_count; ++i)
        fprintf(out, "%g %g %g %g %g\n", (double)tf->points[i].value,
                (double)tf->points[i].rgba[0], (double)tf->points[i].rgba[1],
                (double)tf->points[i].rgba[2], (double)tf->points[i].rgba[3]);
}

/* The library's view of tf (valid while tf lives). */
HDX_TF_FN hd_transfer_function hdx_tf_desc(const hdx_tf *tf)
{
    hd_transfer_function d;
    d.rgba = tf->rgba;
    d.count = tf->count;
    return d;
}

/* Puts volume vol and a transfer function of count RGBA entries over the data values lo..hi
   into d: the volume's value_range is [lo, hi], so the library maps lo to the first entry and
   hi to the last. d points at vol's voxels and at rgba until hd_create copies them. */
HDX_TF_FN void hdx_desc_volume_tf(hd_desc *d, const hd_volume_desc *vol, float lo, float hi, const float *rgba, int count)
{
    d->volume = *vol;
    d->volume.value_range[0] = lo;
    d->volume.value_range[1] = hi;
    d->transfer_function.rgba = rgba;
    d->transfer_function.count = count;
}

/* The same with tf over its domain. */
HDX_TF_FN void hdx_tf_use(hd_desc *d, const hd_volume_desc *vol, const hdx_tf *tf)
{
    hdx_desc_volume_tf(d, vol, tf->domain[0], tf->domain[1], tf->rgba, tf->count);
}

#endif /* HD_TF_H */
