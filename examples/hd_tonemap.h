/* hd_tonemap.h - the tone map and error metric of the evaluation tools (examples/hdeval.c,
   bench/hd_orbit_scene.h): t(L) = srgb(clamp(exposure * L, 0, 1)) per channel, the encoding of
   hd_read_image_rgba8 without the 8-bit rounding, and PSNR = 10 log10(1 / MSE) over RGB, peak 1.
   Example helpers, not library API: every function is static, hdx_. */
#ifndef HD_TONEMAP_H
#define HD_TONEMAP_H

#include <math.h>
#include <stddef.h>

#if defined(__GNUC__) || defined(__clang__)
#define HDX_TM_FN static __attribute__((unused))
#else
#define HDX_TM_FN static
#endif

/* The sRGB encoding of x clamped to [0, 1]. */
HDX_TM_FN double hdx_srgb(double x)
{
    x = x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

/* t(L) of one linear radiance value. */
HDX_TM_FN float hdx_tonemap(float v, float exposure) { return (float)hdx_srgb((double)exposure * v); }

/* Tone-maps a linear RGBA float image in place (RGB; alpha kept). */
HDX_TM_FN void hdx_tonemap_image(float *img, size_t npix, float exposure)
{
    size_t i;
    int c;
    for (i = 0; i < npix; ++i)
        for (c = 0; c < 3; ++c) img[4 * i + c] = hdx_tonemap(img[4 * i + c], exposure);
}

/* PSNR (dB, peak 1) of a mean squared error; 200 for identical images. */
HDX_TM_FN double hdx_psnr(double mse) { return mse > 0.0 ? 10.0 * log10(1.0 / mse) : 200.0; }

/* PSNR over the RGB channels of two tone-mapped RGBA float images. */
HDX_TM_FN double hdx_psnr_rgb(const float *a, const float *b, size_t npix)
{
    double s = 0.0;
    size_t i;
    int c;
    for (i = 0; i < npix; ++i)
        for (c = 0; c < 3; ++c) {
            double d = (double)a[4 * i + c] - (double)b[4 * i + c];
            s += d * d;
        }
    return hdx_psnr(s / (3.0 * (double)npix));
}

/* The MSE over the RGB channels of two linear RGBA float images, a tone-mapped at exposure ea and
   b at eb on the fly (hdx_psnr_rgb's metric without tone-mapped copies; ea != eb compares a
   scaled by ea / eb). */
HDX_TM_FN double hdx_mse_linear(const float *a, double ea, const float *b, double eb, size_t npix)
{
    double s = 0.0;
    size_t i;
    int c;
    for (i = 0; i < npix; ++i)
        for (c = 0; c < 3; ++c) {
            double d = hdx_srgb(ea * a[4 * i + c]) - hdx_srgb(eb * b[4 * i + c]);
            s += d * d;
        }
    return s / (3.0 * (double)npix);
}

/* PSNR over the RGB channels of two linear RGBA float images, both tone-mapped at exposure. */
HDX_TM_FN double hdx_psnr_linear(const float *a, const float *b, size_t npix, double exposure)
{
    return hdx_psnr(hdx_mse_linear(a, exposure, b, exposure, npix));
}

#endif
