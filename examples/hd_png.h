/* hd_png.h - stb_image_write (Debian: libstb-dev) for the examples: its implementation, once per
   program, with the warnings it trips under -Wall -Wextra -Wpedantic -Werror silenced here only.
   Include it in the one .c file of an example that writes PNGs; hdx_png_write is stbi_write_png
   with its write errors reported. */
#ifndef HD_PNG_H
#define HD_PNG_H
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <errno.h>
#include <stdio.h>
#include <string.h>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/stat.h>
#endif

/* Writes an 8-bit PNG (comp channels) to path, checking every write: 1, or 0 with the reason in
   err (stbi_write_png reports success when the disk is full). A regular file left cut short is
   removed. */
#if defined(__GNUC__) || defined(__clang__)
__attribute__((unused))
#endif
static int hdx_png_write(const char *path, int w, int h, int comp, const void *pixels, int stride, char *err,
                         size_t err_size)
{
    int len = 0, ok, e = 0;
    unsigned char *png = stbi_write_png_to_mem((const unsigned char *)pixels, stride, w, h, comp, &len);
    FILE *f;
    if (!png) {
        snprintf(err, err_size, "out of memory for the PNG");
        return 0;
    }
    f = fopen(path, "wb");
    if (!f) {
        snprintf(err, err_size, "%s", strerror(errno));
        STBIW_FREE(png);
        return 0;
    }
    errno = 0;
    ok = fwrite(png, 1, (size_t)len, f) == (size_t)len && fflush(f) == 0;
    if (!ok) e = errno;
    if (fclose(f) != 0 && ok) ok = 0, e = errno;
    STBIW_FREE(png);
    if (ok) return 1;
    snprintf(err, err_size, "%s", e ? strerror(e) : "write error");
#if defined(__unix__) || defined(__APPLE__)
    {
        struct stat st;
        if (stat(path, &st) == 0 && S_ISREG(st.st_mode)) remove(path);
    }
#endif
    return 0;
}
#endif
