/* hd_k_upsample.h - the reduced-resolution frame's upsample pass (shared source). A frame at
   render scale s marches ceil(w / s) x ceil(h / s) rays (hdk_project_pixel with image.x, y the
   reduced size) into the image buffer's second region, which starts after the w x h image
   (region.x = w h, the pixel offset hdk_accumulate_pixel adds), as a running mean of its own. This
   pass then fills the full image from that region by bilinear interpolation, so the image read
   back is always w x h (image.x, y = w, h; region.y = s). OpenCL, GL and Vulkan run it through
   an entry point of its own (hd_k_upsample, HD_STAGE_UPSAMPLE), the CPU backend from a column
   table (hd__cpu_upsample_row). */

/* Along one axis, full-image pixel i of n from the reduced frame's ln pixels: pixel centres map
   onto the reduced grid's extent (the reduced frame covers the same field of view), clamped at
   its edges. Returns the first source pixel; i1 gets the second and w the second's weight. */
HD_FN int hdk_upsample_axis(int i, int n, int ln, HD_INOUT(int) i1, HD_INOUT(float) w)
{
    float f = hdk_clampf((HD_F(i) + 0.5f) * HD_F(ln) / HD_F(n) - 0.5f, 0.0f, HD_F(ln - 1));
    int i0 = hdk_mini(HD_I(f), ln - 1);
    HD_DEREF(i1) = hdk_mini(i0 + 1, ln - 1);
    HD_DEREF(w) = f - HD_F(i0);
    return i0;
}

/* Full-image pixel (px, py) from the reduced region. */
HD_FN void hdk_upsample_pixel(HD_KARGS int px, int py)
{
    int w = HD_PRM(image).x, h = HD_PRM(image).y, s = HD_PRM(region).y;
    int lw = (w + s - 1) / s, lh = (h + s - 1) / s;
    int x1 = 0, y1 = 0;
    float wx = 0.0f, wy = 0.0f;
    int x0 = hdk_upsample_axis(px, w, lw, HD_REF(x1), HD_REF(wx));
    int y0 = hdk_upsample_axis(py, h, lh, HD_REF(y1), HD_REF(wy));
    int a = (w * h + y0 * lw + x0) * 4, b = (w * h + y0 * lw + x1) * 4;
    int c = (w * h + y1 * lw + x0) * 4, d = (w * h + y1 * lw + x1) * 4;
    int o = (py * w + px) * 4, k;
    for (k = 0; k < 4; ++k) {
        float top = HD_GET1(img, a + k) + wx * (HD_GET1(img, b + k) - HD_GET1(img, a + k));
        float bot = HD_GET1(img, c + k) + wx * (HD_GET1(img, d + k) - HD_GET1(img, c + k));
        HD_SET1(img, o + k, top + wy * (bot - top));
    }
}

/* HD_REST_BLEND (src/hd_schedule.h): the paths of a resting view go into planes of their own
   after the depth plane (region.w = the first of their floats; each plane w x h RGBA, `np`
   floats): M the paths' running mean, S their statistics, H a copy of HD's frame, P the blend's
   own. The image is made from them by the blend's two passes (hdk_blend_pixel), so HD's frame is
   never lost. With D = M - H (the paths' mean less HD's frame: HD's bias plus the paths' noise):
     pass 1 (frame.w = 1): Dbar, D's mean over the tile of radius region.y (the low frequencies
       of HD's bias, with the paths' noise averaged down), into P.rgb, and into P.w the squared
       remainder sum_rgb (D - Dbar)^2 less its noise's share var (1 - 1 / N), N the tile's pixels;
     pass 2 (frame.w = 2): the image M + a (max(H + Dbar, 0) - M), HD's frame corrected by Dbar where the
       weight a = var / (var + bias^2) is high, the paths' mean where it is low; var and bias^2 =
       max(0, P.w) averaged over the tile of radius region.y.
   var is the variance of M (sum over RGB: the paths' sample variance over n - 1, then over n).
   Tiles are the pixels of the square inside the image. With fewer than 2 paths (frame.x) pass 2
   writes HD's frame. */
#define HD_FLAG_BLEND 64

/* Path n (frame.x, weight march.y = 1 / n) of pixel i into the blend planes: M, S.x the mean of
   the path's squared RGB (summed over the channels), S.z var. The first path copies HD's frame
   from the image into H. */
HD_FN void hdk_blend_accumulate(HD_KARGS int i, hd_v4 v)
{
    int np = HD_PRM(image).x * HD_PRM(image).y * 4, b = HD_PRM(region).w + i * 4, n = HD_PRM(frame).x;
    float w = HD_PRM(march).y, q = v.x * v.x + v.y * v.y + v.z * v.z, m2 = 0.0f;
    int k;
    if (n <= 1) {
        for (k = 0; k < 4; ++k) HD_SET1(img, b + 2 * np + k, HD_GET1(img, i * 4 + k));
        HD_SET1(img, b, v.x);
        HD_SET1(img, b + 1, v.y);
        HD_SET1(img, b + 2, v.z);
        HD_SET1(img, b + 3, v.w);
        HD_SET1(img, b + np, q);
    } else {
        HD_SET1(img, b, HD_GET1(img, b) + (v.x - HD_GET1(img, b)) * w);
        HD_SET1(img, b + 1, HD_GET1(img, b + 1) + (v.y - HD_GET1(img, b + 1)) * w);
        HD_SET1(img, b + 2, HD_GET1(img, b + 2) + (v.z - HD_GET1(img, b + 2)) * w);
        HD_SET1(img, b + 3, HD_GET1(img, b + 3) + (v.w - HD_GET1(img, b + 3)) * w);
        HD_SET1(img, b + np, HD_GET1(img, b + np) + (q - HD_GET1(img, b + np)) * w);
    }
    for (k = 0; k < 3; ++k) m2 += HD_GET1(img, b + k) * HD_GET1(img, b + k);
    HD_SET1(img, b + np + 2, hdk_maxf(HD_GET1(img, b + np) - m2, 0.0f) / HD_F(hdk_maxi(n - 1, 1)));
}

/* Pixel (px, py) of the blend's pass frame.w (1 or 2, above). */
HD_FN void hdk_blend_pixel(HD_KARGS int px, int py)
{
    int w = HD_PRM(image).x, h = HD_PRM(image).y, r = HD_PRM(region).y, np = w * h * 4, B = HD_PRM(region).w;
    int b = B + (py * w + px) * 4, o = (py * w + px) * 4, k, x, y;
    float s0 = 0.0f, s1 = 0.0f, s2 = 0.0f, c = 0.0f;
    for (y = hdk_maxi(py - r, 0); y <= hdk_mini(py + r, h - 1); ++y)
        for (x = hdk_maxi(px - r, 0); x <= hdk_mini(px + r, w - 1); ++x) {
            int q = B + (y * w + x) * 4;
            if (HD_PRM(frame).w == 1) {
                s0 += HD_GET1(img, q) - HD_GET1(img, q + 2 * np);
                s1 += HD_GET1(img, q + 1) - HD_GET1(img, q + 1 + 2 * np);
                s2 += HD_GET1(img, q + 2) - HD_GET1(img, q + 2 + 2 * np);
            } else {
                s0 += HD_GET1(img, q + 3 * np + 3);
                s1 += HD_GET1(img, q + np + 2);
            }
            c += 1.0f;
        }
    if (HD_PRM(frame).w == 1) {
        float d0 = HD_GET1(img, b) - HD_GET1(img, b + 2 * np) - s0 / c;
        float d1 = HD_GET1(img, b + 1) - HD_GET1(img, b + 1 + 2 * np) - s1 / c;
        float d2 = HD_GET1(img, b + 2) - HD_GET1(img, b + 2 + 2 * np) - s2 / c;
        HD_SET1(img, b + 3 * np, s0 / c);
        HD_SET1(img, b + 3 * np + 1, s1 / c);
        HD_SET1(img, b + 3 * np + 2, s2 / c);
        HD_SET1(img, b + 3 * np + 3, d0 * d0 + d1 * d1 + d2 * d2 - HD_GET1(img, b + np + 2) * (1.0f - 1.0f / c));
    } else if (HD_PRM(frame).x < 2) {
        for (k = 0; k < 4; ++k) HD_SET1(img, o + k, HD_GET1(img, b + 2 * np + k));
    } else {
        float bias2 = hdk_maxf(s0 / c, 0.0f), var = s1 / c;
        float a = var + bias2 > 0.0f ? var / (var + bias2) : 0.0f;
        for (k = 0; k < 4; ++k) {
            float m = HD_GET1(img, b + k), hv = HD_GET1(img, b + 2 * np + k);
            if (k < 3) hv = hdk_maxf(hv + HD_GET1(img, b + 3 * np + k), 0.0f); /* no negative radiance */
            HD_SET1(img, o + k, m + a * (hv - m));
        }
    }
}
