/* hd_k_upsample.h - the reduced-resolution frame's upsample pass (shared source). A frame at
   render scale s marches ceil(w / s) x ceil(h / s) rays (hdk_project_pixel with image.x, y the
   reduced size) into the image buffer's second region, which starts after the w x h image
   (region.x = w h, the pixel offset hdk_accumulate_pixel adds), as a running mean of its own. This
   pass then fills the full image from that region by bilinear interpolation, so the image read
   back is always w x h (image.x, y = w, h; region.y = s; counts.z has HD_FLAG_UPSAMPLE). OpenCL
   runs it through the projection's kernel on that flag; GL and Vulkan through an entry point of
   its own (HD_STAGE_UPSAMPLE), and the CPU backend from a column table (hd__cpu_upsample_row). */
#define HD_FLAG_UPSAMPLE 32

/* Full-image pixel (px, py) from the reduced region: pixel centres map onto the reduced grid's
   extent (the reduced frame covers the same field of view), clamped at its edges. */
HD_FN void hdk_upsample_pixel(HD_KARGS int px, int py)
{
    int w = HD_PRM(image).x, h = HD_PRM(image).y, s = HD_PRM(region).y;
    int lw = (w + s - 1) / s, lh = (h + s - 1) / s;
    float fx = hdk_clampf((HD_F(px) + 0.5f) * HD_F(lw) / HD_F(w) - 0.5f, 0.0f, HD_F(lw - 1));
    float fy = hdk_clampf((HD_F(py) + 0.5f) * HD_F(lh) / HD_F(h) - 0.5f, 0.0f, HD_F(lh - 1));
    int x0 = hdk_mini(HD_I(fx), lw - 1), y0 = hdk_mini(HD_I(fy), lh - 1);
    int x1 = hdk_mini(x0 + 1, lw - 1), y1 = hdk_mini(y0 + 1, lh - 1);
    float wx = fx - HD_F(x0), wy = fy - HD_F(y0);
    int a = (w * h + y0 * lw + x0) * 4, b = (w * h + y0 * lw + x1) * 4;
    int c = (w * h + y1 * lw + x0) * 4, d = (w * h + y1 * lw + x1) * 4;
    int o = (py * w + px) * 4, k;
    for (k = 0; k < 4; ++k) {
        float top = HD_GET1(img, a + k) + wx * (HD_GET1(img, b + k) - HD_GET1(img, a + k));
        float bot = HD_GET1(img, c + k) + wx * (HD_GET1(img, d + k) - HD_GET1(img, c + k));
        HD_SET1(img, o + k, top + wy * (bot - top));
    }
}
