/* pngcmp - the checks of the viewer test (make test-hdview) on 8-bit PNGs.
     pngcmp --nonblank A.png         A is not blank: >= 5% of its pixels are above the background
                                     (black: any channel > 8) and its mean is above 4/255
     pngcmp A.png REF.png            A matches REF: same size, every channel within 1/255, and
                                     relative L2 |A - REF| / |REF| <= 1e-2
     pngcmp --psnr A.png REF.png     prints A's PSNR against REF over the 8-bit RGB values (the
                                     benchmarks that compare hdrender's PNGs); 2 if unreadable
   Why 1/255 and not the conformance suite's projection bound (rel L2 <= 1e-5 on floats): both
   images are 8-bit sRGB encodings of floats that agree to about 1e-6 (the GL and CPU
   projections, conformance-gl), and a float that close to a rounding boundary can round to
   either neighbour, so one code value is the float bound's image after quantisation; the
   relative L2 then is at most about (1/255) / mean, far below 1e-2 on a lit image. */
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#endif
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <math.h>
#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    int w, h, c, w2, h2, c2;
    unsigned char *a, *b;
    long i, n, lit = 0, maxd = 0, over = 0;
    double sum = 0.0, d2 = 0.0, r2 = 0.0;
    if (argc == 3 && strcmp(argv[1], "--nonblank") == 0) {
        if (!(a = stbi_load(argv[2], &w, &h, &c, 3))) { printf("pngcmp: cannot read %s\n", argv[2]); return 2; }
        n = (long)w * h;
        for (i = 0; i < n; ++i) {
            unsigned char *p = a + 3 * i;
            if (p[0] > 8 || p[1] > 8 || p[2] > 8) ++lit;
            sum += (p[0] + p[1] + p[2]) / 3.0;
        }
        printf("pngcmp %s: %dx%d, %.1f%% of the pixels above the background, mean %.2f/255\n", argv[2], w, h,
               100.0 * lit / n, sum / n);
        return lit >= n / 20 && sum / n > 4.0 ? 0 : 1;
    }
    int psnr = argc == 4 && strcmp(argv[1], "--psnr") == 0;
    if (argc != 3 && !psnr) { printf("usage: pngcmp --nonblank A.png | pngcmp A.png REF.png | pngcmp --psnr A.png REF.png\n"); return 2; }
    a = stbi_load(argv[1 + psnr], &w, &h, &c, 3);
    b = stbi_load(argv[2 + psnr], &w2, &h2, &c2, 3);
    if (!a || !b) { printf("pngcmp: cannot read %s or %s\n", argv[1 + psnr], argv[2 + psnr]); return 2; }
    if (w != w2 || h != h2) { printf("pngcmp: %dx%d against %dx%d\n", w, h, w2, h2); return psnr ? 2 : 1; }
    n = (long)w * h * 3;
    for (i = 0; i < n; ++i) {
        long d = labs((long)a[i] - (long)b[i]);
        if (d > maxd) maxd = d;
        if (d > 1) ++over;
        d2 += (double)d * d;
        r2 += (double)b[i] * b[i];
    }
    if (psnr) {
        if (d2 == 0.0) printf("pngcmp %s vs %s: identical (PSNR infinite)\n", argv[2], argv[3]);
        else printf("pngcmp %s vs %s: PSNR %.2f dB (8-bit RGB)\n", argv[2], argv[3], 10.0 * log10(255.0 * 255.0 * n / d2));
        return 0;
    }
    printf("pngcmp %s vs %s: max |difference| %ld/255, %ld channel values over 1/255, rel L2 %.2e (bounds: 1/255, 1e-2)\n",
           argv[1], argv[2], maxd, over, r2 > 0 ? sqrt(d2 / r2) : 0.0);
    return maxd <= 1 && r2 > 0 && sqrt(d2 / r2) <= 1e-2 ? 0 : 1;
}
