/* hd_env.h - environment maps for the examples: a Radiance .hdr (RGBE) file read by stb_image
   (Debian: libstb-dev; its HDR reader alone, implementation once per program, its warnings
   silenced here only) into a hd_environment, and the map's rotation from an angle about the
   scene's up axis. The library itself reads no image files: it takes the linear RGB floats. */
#ifndef HD_ENV_H
#define HD_ENV_H
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_HDR
#include <stb/stb_image.h>
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif

#if defined(__GNUC__) || defined(__clang__)
#define HDX_ENV_FN static __attribute__((unused))
#else
#define HDX_ENV_FN static
#endif
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* The map's rotation (row-major, world = R map) that stands the map's up (+y) on up (need not be
   unit, nonzero) and turns it by deg degrees about it: the map's +x goes to a, a unit vector
   perpendicular to up, turned; its +z to a x up. */
HDX_ENV_FN void hdx_env_rotation(const float up[3], float deg, float r[9])
{
    double u[3] = {up[0], up[1], up[2]}, a[3], b[3], n, c = cos(deg * 3.14159265358979 / 180.0), s = sin(deg * 3.14159265358979 / 180.0);
    int i;
    n = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (i = 0; i < 3; ++i) u[i] /= n;
    /* a: the world axis least along up, made perpendicular to it */
    i = fabs(u[0]) <= fabs(u[1]) && fabs(u[0]) <= fabs(u[2]) ? 0 : fabs(u[1]) <= fabs(u[2]) ? 1 : 2;
    a[0] = a[1] = a[2] = 0.0;
    a[i] = 1.0;
    n = a[0] * u[0] + a[1] * u[1] + a[2] * u[2];
    for (i = 0; i < 3; ++i) a[i] -= n * u[i];
    n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (i = 0; i < 3; ++i) a[i] /= n;
    /* turned by deg about up: a c + (up x a) s */
    b[0] = u[1] * a[2] - u[2] * a[1]; b[1] = u[2] * a[0] - u[0] * a[2]; b[2] = u[0] * a[1] - u[1] * a[0];
    for (i = 0; i < 3; ++i) a[i] = a[i] * c + b[i] * s;
    /* b = a x up, the map's +z */
    b[0] = a[1] * u[2] - a[2] * u[1]; b[1] = a[2] * u[0] - a[0] * u[2]; b[2] = a[0] * u[1] - a[1] * u[0];
    for (i = 0; i < 3; ++i) {
        r[3 * i] = (float)a[i];
        r[3 * i + 1] = (float)u[i];
        r[3 * i + 2] = (float)b[i];
    }
}

/* FILE[:ROTATION][:INTENSITY]: the path into path (path_size bytes) and up to two numbers after
   its last ':'s (defaults 0 and 1). 1, or 0 when the path does not fit or a number is out of
   range (ROTATION within +-3600 degrees, INTENSITY in (0, 1e9]). */
HDX_ENV_FN int hdx_env_arg(const char *s, char *path, size_t path_size, float *rot, float *inten)
{
    double v[2];
    int k = 0;
    size_t n = strlen(s);
    *rot = 0.0f;
    *inten = 1.0f;
    if (n + 1 > path_size || n == 0) return 0;
    memcpy(path, s, n + 1);
    while (k < 2) {
        char *colon = strrchr(path, ':'), *end;
        if (!colon) break;
        v[k] = strtod(colon + 1, &end);
        if (end == colon + 1 || *end || !(v[k] == v[k]) || fabs(v[k]) > 1e30) break;
        *colon = 0;
        ++k;
    }
    if (k == 2) { *rot = (float)v[1]; *inten = (float)v[0]; }
    else if (k == 1) *rot = (float)v[0];
    return path[0] != 0 && fabs(*rot) <= 3600.0f && *inten > 0.0f && *inten <= 1e9f;
}

/* Reads a Radiance .hdr file into env (env->rgb malloc'd: free it). 1, or 0 with the reason in err. */
HDX_ENV_FN int hdx_env_load(const char *path, hd_environment *env, char *err, size_t err_size)
{
    int w = 0, h = 0, comp = 0;
    float *px;
    FILE *f = fopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "cannot open '%.400s'", path);
        return 0;
    }
    if (!stbi_is_hdr_from_file(f)) {
        fclose(f);
        snprintf(err, err_size, "'%.400s' is not a Radiance .hdr file", path);
        return 0;
    }
    px = stbi_loadf_from_file(f, &w, &h, &comp, 3);
    fclose(f);
    if (!px) {
        const char *why = stbi_failure_reason();
        snprintf(err, err_size, "'%.400s': %s", path, why ? why : "cannot be decoded");
        return 0;
    }
    memset(env, 0, sizeof *env);
    env->width = w;
    env->height = h;
    env->rgb = px;
    return 1;
}
#endif
