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
