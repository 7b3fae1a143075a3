/* hd_frames.h - when a single view's image has enough frames (hdrender, hdbench_orbit), so both
   follow the same schedule; header-only. */
#ifndef HD_FRAMES_H
#define HD_FRAMES_H
#include <math.h>
#include <stddef.h>
#include <stdint.h>

/* The jitter noise (pixel position, first sample) left in a running mean of k >= 2 frames, in
   8-bit levels RMS over R, G and B, from the RGBA8 image before (prev) and after (cur) frame k:
   frame k moves the mean by c = (f_k - m_(k-1)) / k, whose RMS is s sqrt(k / (k - 1)) / k for a
   frame's noise s, so s = c sqrt(k (k - 1)) and the mean keeps s / sqrt(k) = c sqrt(k - 1). */
static double hdx_frames_noise_left(const uint8_t *prev, const uint8_t *cur, size_t npix, uint64_t k)
{
    double sum = 0.0;
    size_t i;
    if (k < 2 || npix == 0) return INFINITY;
    for (i = 0; i < npix * 4; ++i) {
        double d = (double)cur[i] - (double)prev[i];
        if ((i & 3) != 3) sum += d * d;
    }
    return sqrt(sum / (double)(npix * 3)) * sqrt((double)(k - 1));
}

/* A single view stops adding frames once the noise left is below one 8-bit level RMS. */
#define HDX_FRAMES_NOISE_DONE 1.0
#endif
