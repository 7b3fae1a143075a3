/* hdrender - renders a volume with hybriddiff to a PNG.

     make build/hdrender && scripts/fetch-data && build/hdrender     -> out/head.png

   `hdrender --help` lists the options. Exit status: 0 done, 2 a bad option, value or input file
   (one line on stderr names it), 1 the library or the output failed while rendering.
   One binary per backend is built from this file: build/hdrender (CPU, the default) and
   build/hdrender-opencl, -vulkan, -gl (-DHYBRIDDIFF_BACKEND_*); `--backend NAME` runs the
   binary of that backend from the same directory with the same arguments. */
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#if !defined(HYBRIDDIFF_BACKEND_CPU) && !defined(HYBRIDDIFF_BACKEND_OPENCL) && \
    !defined(HYBRIDDIFF_BACKEND_VULKAN) && !defined(HYBRIDDIFF_BACKEND_GL)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#if defined(HYBRIDDIFF_BACKEND_OPENCL)
#define HDR_BACKEND "opencl"
#elif defined(HYBRIDDIFF_BACKEND_VULKAN)
#define HDR_BACKEND "vulkan"
#elif defined(HYBRIDDIFF_BACKEND_GL)
#define HDR_BACKEND "gl"
#else
#define HDR_BACKEND "cpu"
#endif
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "hd_tf.h"
#include "hd_crop.h"
#include "hd_frames.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "hd_input.h"
#include "hd_png.h"
#include "hd_env.h"

#define DEFAULT_INPUT "data/head.nrrd"
#define DEFAULT_OUTPUT "out/head.png"
#define DEFAULT_EXPOSURE 8.0f
#define HDR_MAX_LIGHT "2000"

static const char *usage_text =
    "usage: hdrender [options] [FILE|DIR]           (default input: " DEFAULT_INPUT ")\n"
    "       hdrender [options] --raw FILE --dims X,Y,Z --type TYPE\n"
    "\n"
    "Renders a volume with global illumination (hybriddiff) and writes a PNG. FILE: NRRD,\n"
    "MetaImage, NIfTI, or OpenVDB (FILE.vdb, FILE.vdb:GRID: a float grid); DIR: a DICOM series.\n"
    "\n"
    "backend\n"
    "  --backend B             cpu (default), opencl, vulkan or gl: runs build/hdrender-B\n"
    "                          (one binary per backend, built by `make`). The device:\n"
    "                          HD_CL_DEVICE, HD_VK_DEVICE (name substrings), VK_DRIVER_FILES,\n"
    "                          __EGL_VENDOR_LIBRARY_FILENAMES; see README\n"
    "  --list-backends         each backend and the device it would use, then exit\n"
    "\n"
    "input\n"
    "  FILE                    NRRD (.nrrd: attached header, raw or gzip), MetaImage\n"
    "                          (.mhd, .mha) or NIfTI-1 (.nii, .nii.gz) volume, or a\n"
    "                          directory: a DICOM series (GDCM), sorted along the normal\n"
    "  --raw FILE              headerless raw volume, x fastest; needs --dims and --type\n"
    "  --dims X,Y,Z            raw: voxels per axis\n"
    "  --type T                raw: u8 i8 u16 i16 u32 i32 f32 f64\n"
    "  --endian little|big     raw: byte order (default little)\n"
    "  --offset N              raw: bytes to skip at the start (default 0)\n"
    "  --spacing X,Y,Z         voxel size, overrides the file's (default: file or 1,1,1)\n"
    "\n"
    "transfer function\n"
    "  --tf PRESET|FILE        ct-skin, ct-bone, ct-tissue, ct-flesh, ramp, or a TF file\n"
    "                          (docs/TF_FORMAT.md). Default: ct-skin for CT data (values\n"
    "                          below -500), else from the histogram: transparent up to the\n"
    "                          Otsu threshold, a white ramp to the 99.5th percentile.\n"
    "                          CT presets map -1024..3071 HU.\n"
    "  --print-tf              print the chosen TF in the file format and exit\n"
    "\n"
    "lights (world space: the volume box is centred at 0, its largest side is 1)\n"
    "  --light dir:X,Y,Z[:R,G,B][:INTENSITY]\n"
    "                          directional light travelling along X,Y,Z (dir:0,0,-1 shines\n"
    "                          down); repeatable, up to 64 lights\n"
    "  --light point:X,Y,Z[:R,G,B][:INTENSITY][:falloff]\n"
    "                          point light at X,Y,Z; falloff: intensity / r^2\n"
    "  --light quad:X,Y,Z:E1X,E1Y,E1Z:E2X,E2Y,E2Z[:R,G,B][:INTENSITY]\n"
    "                          area light: the parallelogram from corner X,Y,Z along edges\n"
    "                          E1 and E2, emitting on the side of E1 x E2 only\n"
    "  --light disk:X,Y,Z:NX,NY,NZ:RADIUS[:R,G,B][:INTENSITY]\n"
    "                          area light: a disk at X,Y,Z emitting toward its normal N\n"
    "  --light sphere:X,Y,Z:RADIUS[:R,G,B][:INTENSITY]\n"
    "                          area light: a sphere emitting outward. For area lights\n"
    "                          INTENSITY x colour is the emitted radiance (per area and\n"
    "                          solid angle), so a larger light is brighter; they light\n"
    "                          the volume but are not drawn, and method cd cannot use them\n"
    "  --lights N              N preset directional lights placed around the camera\n"
    "                          (1: key light, 3: key, fill and rim; default 1)\n"
    "  --env FILE.hdr[:ROTATION][:INTENSITY]\n"
    "                          environment light from a Radiance .hdr lat-long map, its\n"
    "                          top toward --up, turned ROTATION degrees about it; alone,\n"
    "                          or beside --light / --lights (scripts/make-env writes one)\n"
    "  --env-background        show the --env map behind the volume (alpha 1 there)\n"
    "\n"
    "camera (default: in front of the face, for the head CT's axes: face +y, top +z;\n"
    "        data/brainsmall.nrrd: its left side, from the front and above)\n"
    "  --eye X,Y,Z             camera position (default 0.6,1.65,0.3: face, three-quarter)\n"
    "  --target X,Y,Z          looked-at point (default 0,0,-0.04)\n"
    "  --up X,Y,Z              up direction (default 0,0,1)\n"
    "  --fov DEG               vertical field of view (default 37)\n"
    "  --size WxH              image size (default 512x512)\n"
    "\n";
/* the rest of --help (one string would exceed the 4095 characters C99 guarantees) */
static const char *usage_text_method =
    "crop box (box coordinates: 0..1 along each volume axis x, y, z)\n"
    "  --crop X0,Y0,Z0,X1,Y1,Z1\n"
    "                          keep only the box [X0,X1] x [Y0,Y1] x [Z0,Z1]: the matter\n"
    "                          outside casts no shadow, scatters nothing and is not drawn.\n"
    "                          Default: the whole volume; for data/head.nrrd the head rest\n"
    "                          behind the head is cut away (--crop 0,0,0,1,1,1 keeps it)\n"
    "\n"
    "method\n"
    "  --method M              hd (hybrid diffusion, default), cd, pt_ss, pt_ms\n"
    "  --iterations N          hd, cd: N full iterations, each projecting a frame (default:\n"
    "                          refine the light without frames until it converges, at most\n"
    "                          " HDR_MAX_LIGHT " iterations, CD at least 200, then project\n"
    "                          --frame-window frames);\n"
    "                          pt_ss, pt_ms: paths per pixel (default 256)\n"
    "  --budget SECONDS        render for this wall time (0.01..86400) instead: hd_render\n"
    "                          calls with hd, cd the light, HD's frames, then the resting\n"
    "                          view's blend with PT_MS paths (params.rest HD_REST_BLEND);\n"
    "                          pt_ss, pt_ms: paths until the time is spent\n"
    "  --refine-bounces K      --budget: refine with HD's frame as prior instead (HD_REST_REFINE),\n"
    "                          paths reading HD's light at vertex K (-1: never; 2: a final gather)\n"
    "  --tolerance F           hd, cd: the light's estimated relative error at which it counts\n"
    "                          as converged (default 0.1)\n"
    "  --extinction F          sigma_t per world unit at TF alpha 1 (default 100)\n"
    "  --albedo F              sigma_s / sigma_t in (0,1] (default 0.9)\n"
    "  --anisotropy G          Henyey-Greenstein g in (-1,1) (default 0)\n"
    "  --majorant F            global majorant, 0 = grid of local majorants (default 0)\n"
    "  --sweeps N              diffusion solver sweeps per iteration (default 4)\n"
    "  --solver S              diffusion solver: auto (default: rb below 4 M grid voxels, else\n"
    "                          multigrid), rb (red-black Gauss-Seidel), jacobi, multigrid (CG\n"
    "                          steps preconditioned by a V-cycle; --sweeps counts steps, default\n"
    "                          1; every backend, Vulkan with shaderFloat64)\n"
    "  --tracking ratio|delta  transmittance estimator (default ratio)\n"
    "  --boundary box|surface  the diffusion's vacuum: phi = 0 outside the volume box (the\n"
    "                          paper's), or the Marshak condition at the medium's surface (default)\n"
    "  --no-diffusion          direct light only (single scattering)\n"
    "  --seed N                random seed (default 0)\n"
    "  --threads N             CPU threads, 0 = all cores (default 0)\n"
    "  --step F                ray-march step in voxels (default 0.5)\n"
    "  --frame-window N        the image is the mean of the last N frames (default 8)\n"
    "  --rgb-scattering        multiple scattering per colour channel (TF colour as albedo in the\n"
    "                          diffusion): the colour shift of deep light, +28 bytes/voxel\n"
    "  --grid-downsample N     store E and phi at the volume's resolution / N per axis (1..8,\n"
    "                          default 2: 8x less illumination memory and ~5x faster HD than 1)\n"
    "  --half                  store E and phi as float16 (float32 arithmetic): 2 bytes per\n"
    "                          voxel and channel instead of 4 (every backend)\n"
    "\n"
    "output\n"
    "  -o, --out FILE.png      output image (default " DEFAULT_OUTPUT "; its directory is\n"
    "                          created if needed)\n"
    "  --exposure F            scale before the sRGB encoding (default 8)\n"
    "  --background R,G,B      linear radiance behind the volume (default 0,0,0)\n"
    "  --quiet                 no progress bar and no summary\n"
    "  -v, --verbose           also print the library's information messages\n"
    "  -h, --help              this text\n"
    "\n"
    "Options take their value as the next argument or after '=' (--size=256x256).\n";

/* ---- messages -------------------------------------------------------------------------------- */
static int g_quiet, g_verbose;

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 2, 3), noreturn))
#endif
static void fail(int status, const char *fmt, ...)
{
    va_list ap;
    fputs("hdrender: error: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    exit(status);
}

/* The library's messages: errors are kept for the one line we print, the rest shown. */
typedef struct log_state {
    char last[1024];
    hd_result code;
    char device[256]; /* the device the backend picked, from its information message */
} log_state;

/* The backends name their device in an information message at hd_create: "cpu: N threads",
   "opencl: device NAME (VERSION)...", "vulkan: device NAME (...)...", "gl: RENDERER, VERSION
   (...)"; the device is what follows the prefix. */
static void note_device(log_state *s, const char *m)
{
    static const char *prefix[] = {"opencl: device ", "vulkan: device ", "gl: "};
    size_t i, n;
    if (strncmp(m, "cpu: ", 5) == 0 && strstr(m, " threads") && !strstr(m, "started")) {
        snprintf(s->device, sizeof s->device, "CPU, %s", m + 5);
        return;
    }
    for (i = 0; i < sizeof prefix / sizeof prefix[0]; ++i) {
        n = strlen(prefix[i]);
        if (strncmp(m, prefix[i], n) != 0) continue;
        if (i == 2 && (!strstr(m, " context)") || strncmp(m + n, "EGL", 3) == 0)) return;
        if (!s->device[0]) {
            char *end;
            snprintf(s->device, sizeof s->device, "%s", m + n);
            /* the context's ownership is no part of the device's name */
            if ((end = strstr(s->device, " (own")) != NULL || (end = strstr(s->device, " (the caller")) != NULL)
                *end = 0;
        }
        return;
    }
}

static void log_fn(void *user, hd_log_level level, hd_result code, const char *message,
                   const char *file, int line)
{
    log_state *s = (log_state *)user;
    (void)file;
    (void)line;
    if (level == HD_LOG_INFO) note_device(s, message);
    if (level == HD_LOG_ERROR) {
        snprintf(s->last, sizeof s->last, "%s", message);
        s->code = code;
    } else if (level == HD_LOG_WARNING) {
        if (!g_quiet) fprintf(stderr, "hdrender: warning: %s\n", message);
    } else if (g_verbose) {
        fprintf(stderr, "hdrender: %s\n", message);
    }
}

/* One line for a failed library call: its message and the result's name. */
static void fail_lib(int status, const log_state *s, hd_result r, const char *what, const char *hint)
{
    fail(status, "%s%s%s (%s)%s", what ? what : "", what && s->last[0] ? ": " : "",
         s->last[0] ? s->last : "", hd_result_string(r), hint ? hint : "");
}

/* ---- values ---------------------------------------------------------------------------------- */
static float parse_float(const char *flag, const char *s, float lo, float hi, int lo_open,
                         int hi_open)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end || errno == ERANGE || !isfinite(v))
        fail(2, "%s: '%s' is not a number", flag, s);
    if (v < lo || v > hi || (lo_open && v == lo) || (hi_open && v == hi))
        fail(2, "%s: %s is outside %s%g, %g%s", flag, s, lo_open ? "(" : "[", (double)lo,
             (double)hi, hi_open ? ")" : "]");
    return (float)v;
}

/* --env FILE[:ROTATION][:INTENSITY]: up to two numeric fields after the last ':'s of the path. */
static const char *parse_env(const char *s, float *rot, float *inten, char *path, size_t path_size)
{
    const char *c[2] = {NULL, NULL};
    char *end;
    size_t n = strlen(s);
    int k = 0, m;
    *rot = 0.0f;
    *inten = 1.0f;
    if (n >= path_size) fail(2, "--env: '%s' is too long", s);
    memcpy(path, s, n + 1);
    while (k < 2) {
        char *colon = strrchr(path, ':');
        double v;
        if (!colon) break;
        errno = 0;
        v = strtod(colon + 1, &end);
        if (end == colon + 1 || *end || errno == ERANGE || !isfinite(v)) break;
        c[k++] = colon + 1;
        *colon = 0;
    }
    /* the fields were found right to left */
    for (m = 0; m < k; ++m) {
        const char *f = c[k - 1 - m];
        if (m == 0) *rot = parse_float("--env rotation", f, -3600.0f, 3600.0f, 0, 0);
        else *inten = parse_float("--env intensity", f, 0.0f, 1e9f, 1, 0);
    }
    if (!path[0]) fail(2, "--env: '%s' names no file", s);
    return path;
}

static long parse_int(const char *flag, const char *s, long lo, long hi)
{
    char *end;
    long v;
    errno = 0;
    v = strtol(s, &end, 10);
    if (end == s || *end || errno == ERANGE) fail(2, "%s: '%s' is not an integer", flag, s);
    if (v < lo || v > hi) fail(2, "%s: %s is outside %ld..%ld", flag, s, lo, hi);
    return v;
}


/* "X,Y,Z" -> v; count numbers exactly, each within +-max_abs. */
static void parse_floats_in(const char *flag, const char *s, float *v, int count, double max_abs)
{
    const char *p = s;
    int i;
    for (i = 0; i < count; ++i) {
        char *end;
        double d;
        errno = 0;
        d = strtod(p, &end);
        if (end == p || (errno == ERANGE && d != 0.0) || !isfinite(d) ||
            (i + 1 < count ? *end != ',' : *end != 0))
            fail(2, "%s: '%s' is not %d comma-separated numbers", flag, s, count);
        if (fabs(d) > max_abs) fail(2, "%s: '%s': %g is outside +-%g", flag, s, d, max_abs);
        v[i] = (float)d;
        p = end + 1;
    }
}

/* The same within float range (1e30: sums and products of a few stay finite). */
static void parse_floats(const char *flag, const char *s, float *v, int count)
{
    parse_floats_in(flag, s, v, count, 1e30);
}

static void parse_dims(const char *flag, const char *s, int dims[3])
{
    float v[3];
    int i;
    parse_floats(flag, s, v, 3);
    for (i = 0; i < 3; ++i) {
        if (v[i] != floorf(v[i]) || v[i] < 1 || v[i] > HD_MAX_DIM)
            fail(2, "%s: '%s': each size must be an integer in 1..%d", flag, s, HD_MAX_DIM);
        dims[i] = (int)v[i];
    }
}

static void parse_size(const char *flag, const char *s, int *w, int *h)
{
    const char *p = s;
    char *end;
    long a, b;
    errno = 0;
    a = strtol(p, &end, 10);
    if (end == p || (*end != 'x' && *end != 'X')) fail(2, "%s: '%s' is not WxH", flag, s);
    if (errno == ERANGE) a = HD_MAX_IMAGE_DIM + 1L; /* outside, reported below */
    p = end + 1;
    errno = 0;
    b = strtol(p, &end, 10);
    if (end == p || *end) fail(2, "%s: '%s' is not WxH", flag, s);
    if (errno == ERANGE) b = HD_MAX_IMAGE_DIM + 1L;
    if (a < 1 || b < 1 || a > HD_MAX_IMAGE_DIM || b > HD_MAX_IMAGE_DIM)
        fail(2, "%s: '%s' is outside 1..%d per side", flag, s, HD_MAX_IMAGE_DIM);
    *w = (int)a;
    *h = (int)b;
}

/* dir:X,Y,Z[:R,G,B][:INTENSITY], point:X,Y,Z[:R,G,B][:INTENSITY][:falloff],
   quad:X,Y,Z:E1X,E1Y,E1Z:E2X,E2Y,E2Z[:R,G,B][:INTENSITY] (a corner and two edges),
   disk:X,Y,Z:NX,NY,NZ:RADIUS[:R,G,B][:INTENSITY] (centre, normal), sphere:X,Y,Z:RADIUS[...] */
static hd_light parse_light(const char *s)
{
    hd_light l;
    char buf[256], *parts[8];
    int n = 0, i, have_color = 0, have_intensity = 0, first = 2;
    char *p;
    memset(&l, 0, sizeof l);
    if (strlen(s) >= sizeof buf) fail(2, "--light: '%s' is too long", s);
    strcpy(buf, s);
    for (p = buf; n < 8;) {
        parts[n++] = p;
        p = strchr(p, ':');
        if (!p) break;
        *p++ = 0;
    }
    if (p) fail(2, "--light: '%s' has too many ':' fields", s);
    if (strcmp(parts[0], "dir") == 0 || strcmp(parts[0], "directional") == 0)
        l.type = HD_LIGHT_DIRECTIONAL;
    else if (strcmp(parts[0], "point") == 0)
        l.type = HD_LIGHT_POINT;
    else if (strcmp(parts[0], "quad") == 0)
        l.type = HD_LIGHT_QUAD;
    else if (strcmp(parts[0], "disk") == 0)
        l.type = HD_LIGHT_DISK;
    else if (strcmp(parts[0], "sphere") == 0)
        l.type = HD_LIGHT_SPHERE;
    else
        fail(2, "--light: '%s' must start with dir:, point:, quad:, disk: or sphere:", s);
    if (n < 2) fail(2, "--light: '%s' needs a %s X,Y,Z", s,
                    l.type == HD_LIGHT_DIRECTIONAL ? "direction" : l.type == HD_LIGHT_QUAD ? "corner" :
                    l.type == HD_LIGHT_POINT ? "position" : "centre");
    /* the library's limit for positions; a direction's squares stay finite in float as well */
    parse_floats_in("--light", parts[1], l.type == HD_LIGHT_DIRECTIONAL ? l.direction : l.position, 3, HD_MAX_LIGHT_DISTANCE);
    if (l.type == HD_LIGHT_DIRECTIONAL &&
        l.direction[0] == 0.0f && l.direction[1] == 0.0f && l.direction[2] == 0.0f)
        fail(2, "--light: '%s': the direction is zero", s);
    /* the shape of an area light; the library refuses a degenerate one with its own message */
    if (l.type == HD_LIGHT_QUAD) {
        if (n < 4) fail(2, "--light: '%s' needs a corner and two edges: quad:X,Y,Z:E1X,E1Y,E1Z:E2X,E2Y,E2Z", s);
        parse_floats_in("--light quad edge", parts[2], l.edge1, 3, HD_MAX_LIGHT_DISTANCE);
        parse_floats_in("--light quad edge", parts[3], l.edge2, 3, HD_MAX_LIGHT_DISTANCE);
        first = 4;
    } else if (l.type == HD_LIGHT_DISK) {
        if (n < 4) fail(2, "--light: '%s' needs a centre, a normal and a radius: disk:X,Y,Z:NX,NY,NZ:RADIUS", s);
        parse_floats_in("--light disk normal", parts[2], l.direction, 3, HD_MAX_LIGHT_DISTANCE);
        l.radius = parse_float("--light disk radius", parts[3], 0.0f, HD_MAX_LIGHT_DISTANCE, 1, 0);
        first = 4;
    } else if (l.type == HD_LIGHT_SPHERE) {
        if (n < 3) fail(2, "--light: '%s' needs a centre and a radius: sphere:X,Y,Z:RADIUS", s);
        l.radius = parse_float("--light sphere radius", parts[2], 0.0f, HD_MAX_LIGHT_DISTANCE, 1, 0);
        first = 3;
    }
    for (i = first; i < n; ++i) {
        if (strcmp(parts[i], "falloff") == 0) {
            if (l.type != HD_LIGHT_POINT)
                fail(2, "--light: '%s': falloff is for point lights", s);
            l.inverse_square = 1;
        } else if (strchr(parts[i], ',')) {
            if (have_color++) fail(2, "--light: '%s' has two colours", s);
            parse_floats("--light colour", parts[i], l.color, 3);
            if (l.color[0] < 0 || l.color[1] < 0 || l.color[2] < 0 ||
                (l.color[0] == 0 && l.color[1] == 0 && l.color[2] == 0))
                fail(2, "--light: '%s': the colour must be >= 0 and not black", s);
        } else {
            if (have_intensity++) fail(2, "--light: '%s' has two intensities", s);
            l.intensity = parse_float("--light intensity", parts[i], 0.0f, 1e9f, 1, 0);
        }
    }
    return l;
}

static void normalize3(float v[3])
{
    float n = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (n > 0.0f) { v[0] /= n; v[1] /= n; v[2] /= n; }
}

static void cross3(const float a[3], const float b[3], float out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* n directional lights placed in the camera's frame, so they light what the camera sees:
   a key light from the upper left, a fill from the right, a rim light from behind, then more
   around the view axis. */
static int preset_lights(int n, const hd_camera *cam, hd_light *out)
{
    /* from-directions in camera space (right, up, toward the camera) and intensities */
    static const float base[3][4] = {
        {-0.55f, 0.65f, 0.75f, 1.0f},  /* key */
        {0.80f, 0.10f, 0.60f, 0.45f},  /* fill */
        {0.30f, 0.60f, -0.75f, 0.70f}, /* rim */
    };
    float w[3], u[3], v[3];
    int i, k;
    for (k = 0; k < 3; ++k) w[k] = cam->target[k] - cam->eye[k];
    normalize3(w);
    cross3(w, cam->up, u);
    normalize3(u);
    cross3(u, w, v);
    for (i = 0; i < n; ++i) {
        float c[3], from[3], inten;
        if (i < 3) {
            c[0] = base[i][0]; c[1] = base[i][1]; c[2] = base[i][2];
            inten = base[i][3];
        } else { /* a ring around the view axis, slightly in front */
            float a = 6.2831853f * (float)(i - 3) / (float)(n - 3) + 0.4f;
            c[0] = cosf(a); c[1] = sinf(a); c[2] = 0.35f;
            inten = 0.35f;
        }
        for (k = 0; k < 3; ++k) from[k] = c[0] * u[k] + c[1] * v[k] - c[2] * w[k];
        normalize3(from);
        memset(&out[i], 0, sizeof out[i]);
        out[i].type = HD_LIGHT_DIRECTIONAL;
        for (k = 0; k < 3; ++k) out[i].direction[k] = -from[k];
        out[i].color[0] = out[i].color[1] = out[i].color[2] = 1.0f;
        out[i].intensity = inten;
    }
    return n;
}

/* ---- files ----------------------------------------------------------------------------------- */
/* Creates the directories above path (like mkdir -p of its dirname). */
static void make_parent_dirs(const char *path)
{
    char buf[4096];
    char *p;
    if (strlen(path) >= sizeof buf) fail(2, "--out: path is too long");
    strcpy(buf, path);
    for (p = buf + 1; *p; ++p) {
        if (*p != '/') continue;
        *p = 0;
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            fail(2, "--out: cannot create directory %s: %s", buf, strerror(errno));
        *p = '/';
    }
}

/* Fails now, not after the render, if path cannot be written. Leaves an existing file alone; a
   FIFO without a reader is refused instead of waited on. */
static void check_writable(const char *path)
{
    struct stat st;
    int existed = stat(path, &st) == 0, fd;
    fd = open(path, O_WRONLY | O_APPEND | O_CREAT | O_NONBLOCK, 0666);
    if (fd < 0 && errno == ENXIO) fail(2, "--out: %s is a FIFO with no reader", path);
    if (fd < 0) fail(2, "--out: cannot write %s: %s", path, strerror(errno));
    close(fd);
    if (!existed) remove(path);
}

static double now_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void progress(int done, int total, double elapsed, int final)
{
    char bar[31];
    int i, fill = total > 0 ? (int)(30.0 * done / total) : 30;
    double rate = elapsed > 0.0 ? done / elapsed : 0.0;
    double eta = rate > 0.0 ? (total - done) / rate : 0.0;
    for (i = 0; i < 30; ++i) bar[i] = i < fill ? '#' : '.';
    bar[30] = 0;
    fprintf(stderr, "\r  [%s] %d/%d iterations  %.2f it/s  %s %d:%02d ", bar, done, total, rate,
            final ? "took" : "ETA", (int)((final ? elapsed : eta) + 0.5) / 60,
            (int)((final ? elapsed : eta) + 0.5) % 60);
    if (final) fputc('\n', stderr);
    fflush(stderr);
}

static const char *voxel_type_name(hd_voxel_type t)
{
    return t == HD_VOXEL_U8 ? "u8" : t == HD_VOXEL_U16 ? "u16" : t == HD_VOXEL_I16 ? "i16" : "f32";
}

/* ---- defaults for data other than the head CT ------------------------------------------------- */
/* The value of voxel i in file units. */
static float voxel_value(const hd_volume_file *v, size_t i)
{
    if (v->desc.type == HD_VOXEL_U8) return (float)((const uint8_t *)v->data)[i];
    if (v->desc.type == HD_VOXEL_U16) return (float)((const uint16_t *)v->data)[i];
    if (v->desc.type == HD_VOXEL_I16) return (float)((const int16_t *)v->data)[i];
    return ((const float *)v->data)[i];
}

/* A TF for data of unknown modality, from its histogram: transparent up to the Otsu threshold
   (which separates the background, air, from the object), then a white ramp to opaque at the
   99.5th percentile, so the object's surface shows instead of a cloud filling the box. */
static void histogram_tf(const hd_volume_file *v, hdx_tf *tf)
{
    enum { NB = 256 };
    static double hist[NB];
    size_t i, n = (size_t)v->desc.dims[0] * v->desc.dims[1] * v->desc.dims[2];
    float lo = v->value_min, hi = v->value_max;
    double total = 0.0, sum = 0.0, w0 = 0.0, s0 = 0.0, best = -1.0, acc = 0.0;
    int b, t = 0, p995 = NB - 1;
    if (!(hi > lo)) hi = lo + 1.0f;
    memset(hist, 0, sizeof hist);
    for (i = 0; i < n; ++i) {
        float x = voxel_value(v, i);
        if (!isfinite(x)) continue;
        b = (int)((x - lo) / (hi - lo) * (NB - 1) + 0.5f);
        hist[b < 0 ? 0 : b > NB - 1 ? NB - 1 : b] += 1.0;
    }
    for (b = 0; b < NB; ++b) { total += hist[b]; sum += b * hist[b]; }
    for (b = 0; b < NB - 1 && total > 0.0; ++b) { /* Otsu: the split of most between-class variance */
        double w1, m0, m1, var;
        w0 += hist[b];
        s0 += b * hist[b];
        w1 = total - w0;
        if (w0 <= 0.0 || w1 <= 0.0) continue;
        m0 = s0 / w0;
        m1 = (sum - s0) / w1;
        var = w0 * w1 * (m0 - m1) * (m0 - m1);
        if (var > best) { best = var; t = b; }
    }
    for (b = 0; b < NB; ++b) {
        acc += hist[b];
        if (acc >= 0.995 * total) { p995 = b; break; }
    }
    if (p995 <= t + 1) p995 = t + 2 < NB ? t + 2 : NB - 1;
    memset(tf, 0, sizeof *tf);
    snprintf(tf->name, sizeof tf->name, "histogram");
    tf->domain[0] = lo;
    tf->domain[1] = hi;
    tf->count = HDX_TF_DEFAULT_ENTRIES;
    tf->point_count = 4;
    tf->points[0].value = lo;
    tf->points[1].value = lo + (hi - lo) * (float)t / (NB - 1);
    tf->points[2].value = lo + (hi - lo) * (float)p995 / (NB - 1);
    tf->points[3].value = hi;
    for (b = 0; b < 4; ++b) {
        tf->points[b].rgba[0] = tf->points[b].rgba[1] = tf->points[b].rgba[2] = 1.0f;
        tf->points[b].rgba[3] = b >= 2 ? 1.0f : 0.0f;
    }
    hdx_tf_resample(tf);
}

/* Cameras for the volumes scripts/fetch-data fetches, by file name and size: the default camera
   suits the head CT's axes (face +y, top +z); brainsmall (VolPack's MRI head) has the face
   toward -x and the top toward -y, and is seen from its left side, front and above. */
static int known_volume_camera(const char *path, const hd_volume_file *v, hd_camera *cam)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (strcmp(base, "brainsmall.nrrd") == 0 && v->desc.dims[0] == 128 && v->desc.dims[1] == 128 &&
        v->desc.dims[2] == 84) {
        cam->eye[0] = -0.95f; cam->eye[1] = -0.75f; cam->eye[2] = 1.25f;
        cam->target[0] = cam->target[1] = cam->target[2] = 0.0f;
        cam->up[0] = 0.0f; cam->up[1] = -1.0f; cam->up[2] = 0.0f;
        return 1;
    }
    return 0;
}

/* Mean of the image in 8-bit code values and the share of pixels above near black. */
static void image_brightness(const uint8_t *rgba, size_t npix, double *mean, double *lit)
{
    size_t i, n = 0;
    double sum = 0.0;
    for (i = 0; i < npix; ++i) {
        const uint8_t *p = rgba + 4 * i;
        if (p[0] > 8 || p[1] > 8 || p[2] > 8) ++n;
        sum += (p[0] + p[1] + p[2]) / 3.0;
    }
    *mean = npix ? sum / (double)npix : 0.0;
    *lit = npix ? (double)n / (double)npix : 0.0;
}

/* The single view's frames over converged light: hd_render until the frame window is full or,
   unless --frame-window was given, until the jitter noise left in the image is below one 8-bit
   level (examples/hd_frames.h). */
static void render_frames(hd_context ctx, log_state *ls, int window_given, hd_stats *stats)
{
    hd_desc desc; /* with the library's defaults filled in (frame_window) */
    size_t npix;
    uint8_t *prev, *cur;
    uint64_t window;
    hd_result r;
    if ((r = hd_query_desc(ctx, &desc)) != HD_SUCCESS) fail_lib(1, ls, r, "hd_query_desc", NULL);
    npix = (size_t)desc.camera.width * desc.camera.height;
    prev = window_given ? NULL : (uint8_t *)malloc(npix * 4);
    cur = window_given ? NULL : (uint8_t *)malloc(npix * 4);
    window = (uint64_t)desc.params.frame_window;
    if (!window_given && (!prev || !cur)) fail(1, "out of memory for a %dx%d image", desc.camera.width, desc.camera.height);
    do {
        uint8_t *t;
        ls->last[0] = 0;
        if ((r = hd_render(ctx)) != HD_SUCCESS) fail_lib(1, ls, r, "hd_render", NULL);
        hd_get_stats(ctx, stats);
        if (!cur || stats->frames >= window) continue;
        if ((r = hd_read_image_rgba8(ctx, cur, npix * 4)) != HD_SUCCESS) fail_lib(1, ls, r, "hd_read_image_rgba8", NULL);
        if (hdx_frames_noise_left(prev, cur, npix, stats->frames) < HDX_FRAMES_NOISE_DONE) break;
        t = prev, prev = cur, cur = t;
    } while (stats->frames < window);
    free(prev);
    free(cur);
}

/* --budget: hd_render until `seconds` of wall time since t0 are spent, each call given the time
   left (params.render_budget, at most the library's 10 s) so that it refines the light, projects
   or traces within it; the library's schedule picks the work (light, HD's frames, then the
   resting view's refinement, params.rest). Each call does at least one pass of its work, so the
   time may be passed by one light iteration, frame or refinement pass. */
static void render_budget(hd_context ctx, log_state *ls, double seconds, double t0, hd_stats *stats)
{
    hd_desc desc;
    hd_result r;
    if ((r = hd_query_desc(ctx, &desc)) != HD_SUCCESS) fail_lib(1, ls, r, "hd_query_desc", NULL);
    for (;;) {
        double ts = now_seconds(), left = seconds - (ts - t0);
        if (left <= 0.005) break;
        desc.params.render_budget = (float)(left > 10.0 ? 10.0 : left);
        ls->last[0] = 0;
        if ((r = hd_set_params(ctx, &desc.params)) != HD_SUCCESS) fail_lib(1, ls, r, "hd_set_params", NULL);
        if ((r = hd_render(ctx)) != HD_SUCCESS) fail_lib(1, ls, r, "hd_render", NULL);
        if (!g_quiet && isatty(2)) fprintf(stderr, "\r  %.1f / %.1f s ", now_seconds() - t0, seconds);
    }
    if (!g_quiet && isatty(2)) fputc('\n', stderr);
    hd_get_stats(ctx, stats);
}

/* ---- backends -------------------------------------------------------------------------------- */
static const char *const backend_names[] = {"cpu", "opencl", "vulkan", "gl"};

/* The path of backend's binary: the directory of this executable, then "hdrender" (cpu) or
   "hdrender-NAME". 0 if this executable's path is unknown. */
static int backend_path(const char *argv0, const char *backend, char *out, size_t size)
{
    char self[4096];
    ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
    char *slash;
    if (n > 0) {
        self[n] = 0;
    } else if (strchr(argv0, '/') && strlen(argv0) < sizeof self) {
        strcpy(self, argv0);
    } else {
        return 0;
    }
    slash = strrchr(self, '/');
    slash[1] = 0;
    return snprintf(out, size, "%shdrender%s%s", self, strcmp(backend, "cpu") ? "-" : "",
                    strcmp(backend, "cpu") ? backend : "") < (int)size;
}

/* Replaces this process by backend's binary, with the same arguments. */
static void exec_backend(const char *backend, char **argv)
{
    char path[4200];
    if (!backend_path(argv[0], backend, path, sizeof path))
        fail(2, "--backend %s: cannot find this program's directory", backend);
    if (access(path, X_OK) != 0)
        fail(2, "--backend %s: %s is not built (make %s; see mk/hdrender.mk)", backend, path,
             strcmp(backend, "cpu") ? "hdrender-backends" : "build/hdrender");
    fflush(NULL);
    execv(path, argv);
    fail(2, "--backend %s: cannot run %s: %s", backend, path, strerror(errno));
}

/* --probe: creates a context on a 4^3 volume and prints "BACKEND  DEVICE" or why it cannot. */
static int probe_backend(void)
{
    static const uint8_t voxels[64] = {0};
    hd_desc desc;
    hd_context ctx;
    log_state ls;
    hd_result r;
    memset(&desc, 0, sizeof desc);
    memset(&ls, 0, sizeof ls);
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = 4;
    desc.volume.data = voxels;
    desc.camera.width = desc.camera.height = 8;
    desc.camera.eye[1] = 2.0f;
    desc.camera.up[2] = 1.0f;
    desc.logger.func = log_fn;
    desc.logger.user_data = &ls;
    g_quiet = 1;
    r = hd_create(&desc, &ctx);
    if (r != HD_SUCCESS) {
        printf("%-8s unavailable: %s (%s)\n", HDR_BACKEND, ls.last[0] ? ls.last : "hd_create failed",
               hd_result_string(r));
        return 1;
    }
    printf("%-8s %s\n", HDR_BACKEND, ls.device[0] ? ls.device : "(device not named)");
    hd_destroy(ctx);
    return 0;
}

/* --list-backends: each backend's binary probed in turn, in its own process. */
static int list_backends(const char *argv0)
{
    size_t b;
    int any = 0;
    for (b = 0; b < sizeof backend_names / sizeof backend_names[0]; ++b) {
        char path[4200];
        pid_t pid;
        int st = 0;
        if (!backend_path(argv0, backend_names[b], path, sizeof path) || access(path, X_OK) != 0) {
            printf("%-8s not built (make hdrender-backends)\n", backend_names[b]);
            continue;
        }
        fflush(stdout);
        pid = fork();
        if (pid == 0) {
            char *args[3];
            args[0] = path;
            args[1] = (char *)"--probe";
            args[2] = NULL;
            execv(path, args);
            _exit(127);
        }
        if (pid < 0 || waitpid(pid, &st, 0) != pid || !WIFEXITED(st) || WEXITSTATUS(st) == 127) {
            printf("%-8s unavailable: %s did not run\n", backend_names[b], path);
            continue;
        }
        any += WEXITSTATUS(st) == 0;
    }
    return any ? 0 : 1;
}

/* ---- main ------------------------------------------------------------------------------------ */
/* The value of option argv[*i] ("--x V" or "--x=V"). */
static const char *opt_value(int argc, char **argv, int *i, const char *eq)
{
    if (eq) return eq + 1;
    if (*i + 1 >= argc || (argv[*i + 1][0] == '-' && argv[*i + 1][1] == '-'))
        fail(2, "%s needs a value (see --help)", argv[*i]);
    return argv[++*i];
}

int main(int argc, char **argv)
{
    static hdx_tf tf;
    const char *input = NULL, *raw = NULL, *out_path = DEFAULT_OUTPUT, *tf_arg = NULL;
    int dims[3] = {0, 0, 0}, have_dims = 0, raw_type = -1, lights_n = 0, iterations = 0;
    int print_tf = 0, i, k, have_spacing = 0, camera_given = 0, min_light = 0, crop_given = 0, window_given = 0;
    double budget = 0.0; /* --budget: seconds of wall time, 0: the iteration schedule */
    int refine_given = 0; /* --refine-bounces: the resting view refined (HD_REST_REFINE), not blended */
    double mean, lit;
    hd_endian endian = HD_ENDIAN_LITTLE;
    size_t offset = 0;
    float spacing[3] = {0, 0, 0};
    hd_light lights[HD_MAX_LIGHTS];
    int light_count = 0;
    const char *env_arg = NULL;
    char env_path[4096];
    float env_rot = 0.0f, env_intensity = 1.0f;
    hd_environment env;
    hd_desc desc;
    hd_volume_file vol;
    hd_context ctx;
    hd_result r;
    log_state ls;
    hd_logger logger;
    hd_stats stats;
    uint8_t *rgba, *rgb;
    double t0, t_end;
    int done = 0, chunk = 1, pt;
    size_t npix;
    char err[512];

    /* the backend first: another backend's binary takes over the whole command line */
    for (i = 1; i < argc; ++i) {
        const char *a = argv[i], *b = NULL;
        if (strcmp(a, "--backend") == 0) {
            if (i + 1 >= argc) fail(2, "--backend needs a value (see --help)");
            b = argv[++i];
        } else if (strncmp(a, "--backend=", 10) == 0) {
            b = a + 10;
        } else if (strcmp(a, "--list-backends") == 0) {
            return list_backends(argv[0]);
        } else if (strcmp(a, "--probe") == 0) {
            return probe_backend();
        }
        if (!b) continue;
        for (k = 0; k < 4 && strcmp(b, backend_names[k]) != 0; ++k) {}
        if (k == 4) fail(2, "--backend: '%s' is not cpu, opencl, vulkan or gl", b);
        if (strcmp(b, HDR_BACKEND) != 0) exec_backend(b, argv);
    }

    memset(&desc, 0, sizeof desc);
    memset(&ls, 0, sizeof ls);
    logger.func = log_fn;
    logger.user_data = &ls;
    desc.camera.eye[0] = 0.6f; desc.camera.eye[1] = 1.65f; desc.camera.eye[2] = 0.3f;
    desc.camera.target[2] = -0.04f;
    desc.camera.up[2] = 1.0f;
    desc.camera.fov_y = 37.0f;
    desc.camera.width = desc.camera.height = 512;
    desc.params.exposure = DEFAULT_EXPOSURE;

    for (i = 1; i < argc; ++i) {
        char name[64];
        const char *a = argv[i], *eq = NULL, *v;
        if (a[0] == '-' && a[1] == '-' && (eq = strchr(a, '=')) != NULL) {
            size_t n = (size_t)(eq - a);
            if (n >= sizeof name) fail(2, "unknown option '%s' (see --help)", a);
            memcpy(name, a, n);
            name[n] = 0;
            a = name;
        }
#define IS(s) (strcmp(a, s) == 0)
#define VAL() (v = opt_value(argc, argv, &i, eq))
#define FLAG() do { if (eq) fail(2, "%s takes no value", a); } while (0)
        if (IS("--backend")) {
            VAL(); /* handled above */
        } else if (IS("-h") || IS("--help")) {
            fputs(usage_text, stdout);
            fputs(usage_text_method, stdout);
            return 0;
        } else if (IS("--raw")) {
            raw = VAL();
        } else if (IS("--dims")) {
            parse_dims(a, VAL(), dims);
            have_dims = 1;
        } else if (IS("--type")) {
            static const char *names[] = {"u8", "i8", "u16", "i16", "u32", "i32", "f32", "f64"};
            VAL();
            for (k = 0; k < 8 && strcmp(v, names[k]) != 0; ++k) {}
            if (k == 8) fail(2, "--type: '%s' is not one of u8 i8 u16 i16 u32 i32 f32 f64", v);
            raw_type = k;
        } else if (IS("--endian")) {
            VAL();
            if (strcmp(v, "little") == 0) endian = HD_ENDIAN_LITTLE;
            else if (strcmp(v, "big") == 0) endian = HD_ENDIAN_BIG;
            else fail(2, "--endian: '%s' is not little or big", v);
        } else if (IS("--offset")) {
            char *end;
            unsigned long long o;
            VAL();
            errno = 0;
            o = strtoull(v, &end, 10);
            if (end == v || *end || errno == ERANGE || v[0] == '-' || o > (size_t)-1)
                fail(2, "--offset: '%s' is not a byte count", v);
            offset = (size_t)o;
        } else if (IS("--spacing")) {
            parse_floats(a, VAL(), spacing, 3);
            for (k = 0; k < 3; ++k)
                if (!(spacing[k] > 0.0f)) fail(2, "--spacing: '%s': each must be > 0", v);
            have_spacing = 1;
        } else if (IS("--tf")) {
            tf_arg = VAL();
        } else if (IS("--print-tf")) {
            FLAG();
            print_tf = 1;
        } else if (IS("--light")) {
            VAL();
            if (light_count == HD_MAX_LIGHTS) fail(2, "--light: more than %d lights", HD_MAX_LIGHTS);
            lights[light_count++] = parse_light(v);
        } else if (IS("--lights")) {
            lights_n = (int)parse_int(a, VAL(), 1, HD_MAX_LIGHTS);
        } else if (IS("--env")) {
            if (env_arg) fail(2, "--env: given twice");
            env_arg = parse_env(VAL(), &env_rot, &env_intensity, env_path, sizeof env_path);
        } else if (IS("--env-background")) {
            FLAG();
            desc.params.environment_background = 1;
        } else if (IS("--eye")) {
            parse_floats_in(a, VAL(), desc.camera.eye, 3, HD_MAX_CAMERA_DISTANCE);
            camera_given = 1;
        } else if (IS("--target")) {
            parse_floats_in(a, VAL(), desc.camera.target, 3, HD_MAX_CAMERA_DISTANCE);
            camera_given = 1;
        } else if (IS("--up")) {
            parse_floats_in(a, VAL(), desc.camera.up, 3, 1e15);
            if (desc.camera.up[0] == 0.0f && desc.camera.up[1] == 0.0f && desc.camera.up[2] == 0.0f)
                fail(2, "--up: '%s' is the zero vector", v);
            camera_given = 1;
        } else if (IS("--fov")) {
            desc.camera.fov_y = parse_float(a, VAL(), 0.0f, 180.0f, 1, 1);
        } else if (IS("--size")) {
            parse_size(a, VAL(), &desc.camera.width, &desc.camera.height);
        } else if (IS("--crop")) {
            float box[6];
            parse_floats(a, VAL(), box, 6);
            for (k = 0; k < 3; ++k) {
                if (!(box[k] >= 0.0f && box[k] < box[k + 3] && box[k + 3] <= 1.0f))
                    fail(2, "--crop: '%s': need 0 <= min < max <= 1 on each axis (axis %d: %g, %g)", v, k,
                         (double)box[k], (double)box[k + 3]);
                desc.params.crop_min[k] = box[k];
                desc.params.crop_max[k] = box[k + 3];
            }
            crop_given = 1;
        } else if (IS("--method")) {
            VAL();
            if (strcmp(v, "hd") == 0) desc.params.method = HD_METHOD_HD;
            else if (strcmp(v, "cd") == 0) desc.params.method = HD_METHOD_CD;
            else if (strcmp(v, "pt_ss") == 0) desc.params.method = HD_METHOD_PT_SS;
            else if (strcmp(v, "pt_ms") == 0) desc.params.method = HD_METHOD_PT_MS;
            else fail(2, "--method: '%s' is not hd, cd, pt_ss or pt_ms", v);
        } else if (IS("--tolerance")) {
            desc.params.light_tolerance = parse_float(a, VAL(), 0.0f, 10.0f, 1, 0);
        } else if (IS("--iterations")) {
            iterations = (int)parse_int(a, VAL(), 1, 1000000);
        } else if (IS("--budget")) {
            budget = parse_float(a, VAL(), 0.01f, 86400.0f, 0, 0);
        } else if (IS("--refine-bounces")) {
            desc.params.refine_bounces = (int)parse_int(a, VAL(), -1, 100000);
            if (desc.params.refine_bounces == 0) fail(2, "--refine-bounces: 0 is not -1 or 1..100000");
            refine_given = 1;
        } else if (IS("--extinction")) {
            desc.params.extinction = parse_float(a, VAL(), 0.0f, 1e6f, 1, 0);
        } else if (IS("--albedo")) {
            desc.params.albedo = parse_float(a, VAL(), 0.0f, 1.0f, 1, 0);
        } else if (IS("--anisotropy")) {
            desc.params.anisotropy = parse_float(a, VAL(), -1.0f, 1.0f, 1, 1);
        } else if (IS("--majorant")) {
            desc.params.majorant = parse_float(a, VAL(), 0.0f, 1e30f, 0, 0);
        } else if (IS("--sweeps")) {
            desc.params.diffusion_sweeps = (int)parse_int(a, VAL(), 1, 100000);
        } else if (IS("--solver")) {
            VAL();
            if (strcmp(v, "auto") == 0) desc.params.solver = HD_SOLVER_AUTO;
            else if (strcmp(v, "rb") == 0) desc.params.solver = HD_SOLVER_RED_BLACK;
            else if (strcmp(v, "jacobi") == 0) desc.params.solver = HD_SOLVER_JACOBI;
            else if (strcmp(v, "multigrid") == 0) desc.params.solver = HD_SOLVER_MULTIGRID;
            else fail(2, "--solver: '%s' is not auto, rb, jacobi or multigrid", v);
        } else if (IS("--tracking")) {
            VAL();
            if (strcmp(v, "ratio") == 0) desc.params.tracking = HD_TRACKING_RATIO;
            else if (strcmp(v, "delta") == 0) desc.params.tracking = HD_TRACKING_DELTA;
            else fail(2, "--tracking: '%s' is not ratio or delta", v);
        } else if (IS("--boundary")) {
            VAL();
            if (strcmp(v, "box") == 0) desc.params.diffusion_boundary = HD_BOUNDARY_BOX;
            else if (strcmp(v, "surface") == 0) desc.params.diffusion_boundary = HD_BOUNDARY_SURFACE;
            else fail(2, "--boundary: '%s' is not box or surface", v);
        } else if (IS("--no-diffusion")) {
            FLAG();
            desc.params.disable_diffusion = 1;
        } else if (IS("--seed")) {
            desc.params.seed = (uint32_t)parse_int(a, VAL(), 0, 2147483647L);
        } else if (IS("--threads")) {
            desc.threads = (int)parse_int(a, VAL(), 0, 4096);
        } else if (IS("--step")) {
            desc.params.step = parse_float(a, VAL(), 0.01f, 16.0f, 0, 0);
        } else if (IS("--exposure")) {
            desc.params.exposure = parse_float(a, VAL(), 0.0f, 1e9f, 1, 0);
        } else if (IS("--background")) {
            parse_floats(a, VAL(), desc.params.background, 3);
            for (k = 0; k < 3; ++k)
                if (desc.params.background[k] < 0.0f) fail(2, "--background: '%s' is negative", v);
        } else if (IS("--frame-window")) {
            window_given = 1;
            desc.params.frame_window = (int)parse_int(a, VAL(), 1, 1000000);
        } else if (IS("--rgb-scattering")) {
            desc.params.rgb_scattering = 1;
        } else if (IS("--half")) {
            FLAG();
            desc.params.illumination_precision = HD_PRECISION_FLOAT16;
        } else if (IS("--grid-downsample")) {
            desc.params.illumination_downsample = (int)parse_int(a, VAL(), 1, 8);
        } else if (IS("-o") || IS("--out")) {
            out_path = VAL();
            if (!*out_path) fail(2, "%s: empty file name", a);
        } else if (IS("--quiet") || IS("-q")) {
            FLAG();
            g_quiet = 1;
        } else if (IS("--verbose") || IS("-v")) {
            FLAG();
            g_verbose = 1;
        } else if (a[0] == '-' && a[1] != 0) {
            fail(2, "unknown option '%s' (see --help)", a);
        } else {
            if (input) fail(2, "two input files: '%s' and '%s'", input, a);
            input = a;
        }
#undef IS
#undef VAL
#undef FLAG
    }

    /* ---- check the combination ---- */
    if (raw && input) fail(2, "give either FILE or --raw FILE, not both");
    if (!raw && (have_dims || raw_type >= 0 || offset))
        fail(2, "--dims, --type and --offset are for --raw input");
    if (raw && (!have_dims || raw_type < 0)) fail(2, "--raw needs --dims X,Y,Z and --type T");
    if (light_count && lights_n) fail(2, "give either --light (one or more) or --lights N");

    pt = desc.params.method == HD_METHOD_PT_SS || desc.params.method == HD_METHOD_PT_MS;
    if (budget > 0.0 && iterations) fail(2, "give either --budget or --iterations, not both");
    if (budget > 0.0) desc.params.rest = refine_given ? HD_REST_REFINE : HD_REST_BLEND;
    if (!iterations && pt && budget <= 0.0) iterations = 256;
    /* CD's multiple scattering spreads one cell per sweep: its convergence estimate settles
       (about 100 iterations on the head CT) long before the light has reached the far side,
       and the image is nearly black below about 200 */
    if (desc.params.method == HD_METHOD_CD) min_light = 200;

    /* ---- transfer function ---- */
    if (tf_arg) {
        if (!hdx_tf_preset(tf_arg, &tf)) {
            struct stat st;
            if (stat(tf_arg, &st) != 0)
                fail(2, "--tf: '%s' is neither a preset (ct-skin, ct-bone, ct-tissue, ct-flesh, ramp) "
                        "nor a file (%s)", tf_arg, strerror(errno));
            if (!hdx_tf_load(tf_arg, &tf, err, sizeof err)) fail(2, "--tf: %s", err);
        }
        if (print_tf) {
            hdx_tf_write(stdout, &tf);
            return 0;
        }
    } else if (print_tf) {
        fail(2, "--print-tf needs --tf PRESET|FILE");
    }

    /* ---- volume ---- */
    if (raw) {
        r = hd_volume_load_raw(raw, dims, (hd_raw_type)raw_type, endian, offset, &vol, &logger);
        if (r != HD_SUCCESS) fail_lib(2, &ls, r, NULL, NULL);
    } else {
        if (!input) input = DEFAULT_INPUT;
        r = hdx_load_input(input, &vol, &logger, err, sizeof err);
        if (r != HD_SUCCESS && err[0]) fail(2, "%s", err);
        if (r != HD_SUCCESS)
            fail_lib(2, &ls, r, NULL,
                     r == HD_ERROR_FILE_IO && strcmp(input, DEFAULT_INPUT) == 0
                         ? "; run scripts/fetch-data (make data) to fetch the head CT" : NULL);
    }

    if (!tf_arg) {
        if ((vol.desc.type == HD_VOXEL_F32 || vol.desc.type == HD_VOXEL_I16) && vol.value_min <= -500.0f) hdx_tf_preset("ct-skin", &tf);
        else histogram_tf(&vol, &tf);
    }
    if (!camera_given && !raw) known_volume_camera(input, &vol, &desc.camera);
    if (desc.camera.eye[0] == desc.camera.target[0] && desc.camera.eye[1] == desc.camera.target[1] &&
        desc.camera.eye[2] == desc.camera.target[2])
        fail(2, "--eye and --target are the same point (%g,%g,%g): the camera has no view direction",
             (double)desc.camera.eye[0], (double)desc.camera.eye[1], (double)desc.camera.eye[2]);
    if (!crop_given && !raw) hdx_known_crop(input, vol.desc.dims, &desc.params);
    if (tf.data_domain) {
        float lo = vol.value_min, hi = vol.value_max;
        if (!(hi > lo)) hi = lo + 1.0f;
        hdx_tf_set_domain(&tf, lo, hi);
    }
    hdx_tf_use(&desc, &vol.desc, &tf);
    if (have_spacing) memcpy(desc.volume.spacing, spacing, sizeof spacing);

    /* ---- lights, the rest ---- */
    memset(&env, 0, sizeof env);
    if (desc.params.environment_background && !env_arg) fail(2, "--env-background: needs --env");
    if (env_arg) {
        if (!hdx_env_load(env_arg, &env, err, sizeof err)) fail(2, "--env: %s", err);
        env.intensity = env_intensity;
        static const float y_up[3] = {0.0f, 1.0f, 0.0f}; /* the library's default camera up */
        int zero_up = desc.camera.up[0] == 0.0f && desc.camera.up[1] == 0.0f && desc.camera.up[2] == 0.0f;
        hdx_env_rotation(zero_up ? y_up : desc.camera.up, env_rot, env.rotation);
    }
    if (!light_count && (!env_arg || lights_n)) light_count = preset_lights(lights_n ? lights_n : 1, &desc.camera, lights);
    desc.lights = light_count ? lights : NULL; /* none: the environment alone, set after hd_create */
    desc.light_count = light_count;
    desc.logger = logger;
    make_parent_dirs(out_path);
    check_writable(out_path);

    ls.last[0] = 0;
    r = hd_create(&desc, &ctx);
    if (r != HD_SUCCESS) {
        int usage_error = r == HD_ERROR_UNSUPPORTED || (r >= HD_ERROR_NULL_POINTER &&
                                                        r <= HD_ERROR_TOO_MANY_LIGHTS);
        fail_lib(usage_error ? 2 : 1, &ls, r, "cannot create the renderer", NULL);
    }
    if (env_arg) {
        ls.last[0] = 0;
        if ((r = hd_set_environment(ctx, &env)) != HD_SUCCESS) fail_lib(2, &ls, r, "--env", NULL);
        if (!light_count && (r = hd_set_lights(ctx, NULL, 0)) != HD_SUCCESS) fail_lib(1, &ls, r, "--env", NULL);
        free((void *)env.rgb);
        if (!g_quiet) fprintf(stderr, "hdrender: environment %s, %dx%d, turned %g degrees, intensity %g\n", env_arg, env.width, env.height,
                              (double)env_rot, (double)env.intensity);
    }
    if (!g_quiet)
        fprintf(stderr, "hdrender: %s %dx%dx%d %s, values %g..%g, tf %s, %d light%s, %s on %s, "
                "%dx%d, %s\nhdrender: device: %s\n", raw ? raw : input, vol.desc.dims[0], vol.desc.dims[1],
                vol.desc.dims[2], voxel_type_name(vol.desc.type), (double)vol.value_min,
                (double)vol.value_max, tf.name, light_count, light_count == 1 ? "" : "s",
                hd_method_name(desc.params.method == HD_METHOD_DEFAULT ? HD_METHOD_HD
                                                                        : desc.params.method),
                hd_backend_name(), desc.camera.width, desc.camera.height,
                iterations ? "fixed iterations" : "light refined to convergence",
                ls.device[0] ? ls.device : "(not named by the backend)");
    if (!g_quiet && desc.params.crop_max[0] > 0.0f)
        fprintf(stderr, "hdrender: crop box x %g..%g, y %g..%g, z %g..%g%s\n", (double)desc.params.crop_min[0],
                (double)desc.params.crop_max[0], (double)desc.params.crop_min[1], (double)desc.params.crop_max[1],
                (double)desc.params.crop_min[2], (double)desc.params.crop_max[2], crop_given ? "" : " (this volume's default)");
    hd_volume_free(&vol);

    t0 = now_seconds();
    if (budget > 0.0) {
        render_budget(ctx, &ls, budget, t0, &stats);
        done = iterations = (int)stats.iterations;
    } else if (!iterations) {
        /* the single-view schedule: light without frames until it converges, then the frames */
        int max_light = atoi(HDR_MAX_LIGHT);
        while (done < max_light) {
            ls.last[0] = 0;
            if ((r = hd_refine(ctx, 1)) != HD_SUCCESS) {
                if (!g_quiet && isatty(2)) fputc('\n', stderr);
                fail_lib(1, &ls, r, "hd_refine", NULL);
            }
            ++done;
            hd_get_stats(ctx, &stats);
            if (!g_quiet && isatty(2))
                fprintf(stderr, "\r  light: %d iterations, estimated error %.4f (converged below %g), %.1f s ", done,
                        stats.light_error, (double)desc.params.light_tolerance, now_seconds() - t0);
            if (stats.light_converged && done >= min_light) break;
        }
        if (!g_quiet && isatty(2)) fputc('\n', stderr);
        if (!stats.light_converged && !g_quiet)
            fprintf(stderr, "hdrender: the light did not converge in %d iterations (estimated error %.4f)\n", done,
                    stats.light_error);
        render_frames(ctx, &ls, window_given, &stats);
        done = iterations = (int)stats.iterations;
    }
    /* ---- fixed iterations, in chunks of about 0.2 s ---- */
    while (done < iterations) {
        int n = chunk < iterations - done ? chunk : iterations - done;
        double ts = now_seconds(), te, per;
        ls.last[0] = 0;
        r = hd_iterate(ctx, n);
        if (r != HD_SUCCESS) {
            if (!g_quiet && isatty(2)) fputc('\n', stderr);
            fail_lib(1, &ls, r, "hd_iterate", NULL);
        }
        te = now_seconds();
        done += n;
        per = (te - ts) / n;
        chunk = per > 0.0 ? (int)(0.2 / per) : 1000;
        if (chunk < 1) chunk = 1;
        if (chunk > 100000) chunk = 100000;
        if (!g_quiet && isatty(2)) progress(done, iterations, te - t0, done == iterations);
    }
    t_end = now_seconds();

    /* ---- image ---- */
    npix = (size_t)desc.camera.width * desc.camera.height;
    rgba = (uint8_t *)malloc(npix * 4);
    rgb = (uint8_t *)malloc(npix * 3);
    if (!rgba || !rgb) fail(1, "out of memory for a %dx%d image", desc.camera.width,
                            desc.camera.height);
    ls.last[0] = 0;
    r = hd_read_image_rgba8(ctx, rgba, npix * 4);
    if (r != HD_SUCCESS) fail_lib(1, &ls, r, "hd_read_image_rgba8", NULL);
    for (i = 0; (size_t)i < npix; ++i) memcpy(rgb + 3 * (size_t)i, rgba + 4 * (size_t)i, 3);
    image_brightness(rgba, npix, &mean, &lit);
    if (mean < 4.0 || lit < 0.05)
        fprintf(stderr, "hdrender: warning: the image is essentially black (mean %.2f/255, %.1f%% of "
                "the pixels above 8/255): raise --exposure or --iterations%s, or check --tf and the "
                "camera (--eye, --target)\n", mean, 100.0 * lit,
                desc.params.method == HD_METHOD_CD ? " (CD needs about 200)" : "");
    if (!hdx_png_write(out_path, desc.camera.width, desc.camera.height, 3, rgb, desc.camera.width * 3, err,
                       sizeof err))
        fail(1, "cannot write %s: %s", out_path, err);
    if (!g_quiet && hd_get_stats(ctx, &stats) == HD_SUCCESS) {
        char refined[64] = "";
        if (stats.refine_paths)
            snprintf(refined, sizeof refined, ", %llu refinement paths/pixel", (unsigned long long)stats.refine_paths);
        fprintf(stderr, "hdrender: %d iteration%s, %d frame%s%s in %.2f s (%.2f it/s; direct %.2f s, diffusion "
                "%.2f s, projection %.2f s) -> %s\n", iterations, iterations == 1 ? "" : "s",
                (int)stats.frames, stats.frames == 1 ? "" : "s", refined, t_end - t0,
                iterations / (t_end - t0), stats.seconds_direct, stats.seconds_diffusion,
                stats.seconds_projection, out_path);
    }
    free(rgba);
    free(rgb);
    hd_destroy(ctx);
    return 0;
}
