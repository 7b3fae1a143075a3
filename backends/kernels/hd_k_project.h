/* hd_k_project.h - stage 3: emission-absorption ray marching from the camera (shared source).
   L = sum T_cam * c(x) * albedo * (E + phi)(x) / (4 pi) * (1 - exp(-sigma_t dt)) + T_end * L_bg:
   each segment's emission sigma_s c (E + phi) / (4 pi) integrated exactly for a constant
   sigma_t over the segment (sigma_s / sigma_t = albedo). The pixel position and the first
   sample are jittered per frame; frames go into a running mean with weight march.y. */

#ifndef HD_PRELUDE_SAMPLES_LIGHT
/* Trilinear E + phi of channel c at texture coordinate u, on the illumination grid. */
HD_FN float hd_sample_light(HD_KARGS hd_v3 u, int c)
{
    int nx = HD_PRM(gdims).x, ny = HD_PRM(gdims).y, nz = HD_PRM(gdims).z;
    float wx, wy, wz;
    int x0 = hd_lerp_axis(u.x, nx, HD_REF(wx));
    int y0 = hd_lerp_axis(u.y, ny, HD_REF(wy));
    int z0 = hd_lerp_axis(u.z, nz, HD_REF(wz));
    int x1 = hd_mini(x0 + 1, nx - 1), y1 = hd_mini(y0 + 1, ny - 1), z1 = hd_mini(z0 + 1, nz - 1);
    int za = z0 + c * nz, zb = z1 + c * nz;
    int r00 = (za * ny + y0) * nx, r10 = (za * ny + y1) * nx;
    int r01 = (zb * ny + y0) * nx, r11 = (zb * ny + y1) * nx;
    float v000 = HD_GET(E, r00 + x0, x0, y0, za) + HD_GET(phi, r00 + x0, x0, y0, za);
    float v100 = HD_GET(E, r00 + x1, x1, y0, za) + HD_GET(phi, r00 + x1, x1, y0, za);
    float v010 = HD_GET(E, r10 + x0, x0, y1, za) + HD_GET(phi, r10 + x0, x0, y1, za);
    float v110 = HD_GET(E, r10 + x1, x1, y1, za) + HD_GET(phi, r10 + x1, x1, y1, za);
    float v001 = HD_GET(E, r01 + x0, x0, y0, zb) + HD_GET(phi, r01 + x0, x0, y0, zb);
    float v101 = HD_GET(E, r01 + x1, x1, y0, zb) + HD_GET(phi, r01 + x1, x1, y0, zb);
    float v011 = HD_GET(E, r11 + x0, x0, y1, zb) + HD_GET(phi, r11 + x0, x0, y1, zb);
    float v111 = HD_GET(E, r11 + x1, x1, y1, zb) + HD_GET(phi, r11 + x1, x1, y1, zb);
    float c00 = v000 + wx * (v100 - v000), c10 = v010 + wx * (v110 - v010);
    float c01 = v001 + wx * (v101 - v001), c11 = v011 + wx * (v111 - v011);
    float c0 = c00 + wy * (c10 - c00), c1 = c01 + wy * (c11 - c01);
    return c0 + wz * (c1 - c0);
}
#endif

/* The camera ray through image position (fx, fy) in pixels (top row first). */
HD_FN hd_v3 hd_camera_dir(HD_KARGS float fx, float fy)
{
    float sx = 2.0f * fx / HD_F(HD_PRM(image).x) - 1.0f;
    float sy = 1.0f - 2.0f * fy / HD_F(HD_PRM(image).y);
    hd_v3 d = hd_add(HD_XYZ(HD_PRM(cam_w)),
                     hd_add(hd_scale(HD_XYZ(HD_PRM(cam_u)), sx), hd_scale(HD_XYZ(HD_PRM(cam_v)), sy)));
    return hd_normalize(d);
}

/* Folds one frame value into the running mean of pixel i (RGBA). */
HD_FN void hd_accumulate_pixel(HD_KARGS int i, hd_v4 v)
{
    float w = HD_PRM(march).y;
    int b = i * 4;
    HD_SET1(img, b, HD_GET1(img, b) + (v.x - HD_GET1(img, b)) * w);
    HD_SET1(img, b + 1, HD_GET1(img, b + 1) + (v.y - HD_GET1(img, b + 1)) * w);
    HD_SET1(img, b + 2, HD_GET1(img, b + 2) + (v.z - HD_GET1(img, b + 2)) * w);
    HD_SET1(img, b + 3, HD_GET1(img, b + 3) + (v.w - HD_GET1(img, b + 3)) * w);
}

HD_FN void hd_project_pixel(HD_KARGS int px, int py)
{
    int i = py * HD_PRM(image).x + px;
    hd_u32 key = hd_rng_key(HD_U(i), HD_U(HD_PRM(frame).y), HD_U(HD_PRM(frame).z), HD_STREAM_PROJECT);
    hd_v3 o = HD_XYZ(HD_PRM(cam_pos));
    hd_v3 d = hd_camera_dir(HD_KPASS HD_F(px) + hd_rand(key, 0u), HD_F(py) + hd_rand(key, 1u));
    float t1;
    float t0 = hd_box_entry(HD_KPASS o, d, HD_REF(t1));
    float dt = HD_PRM(march).x;
    float T = 1.0f, r = 0.0f, g = 0.0f, b = 0.0f;
    int nch = HD_PRM(gdims).w;
    float k = HD_PRM(medium).y * HD_PRM(box).w; /* albedo / (4 pi) */
    /* samples at s0 + n dt from the entry point, n counted: the step advances however far the
       eye is, the chord is at most the box diagonal, and n < HD_MAX_MARCH_STEPS */
    hd_v3 pe = hd_madd(o, d, t0);
    float len = hd_minf(t1 - t0, HD_BOX_DIAGONAL);
    float s0 = hd_rand(key, 2u) * dt;
    int n;
    for (n = 0; n < HD_MAX_MARCH_STEPS; ++n) {
        float s = s0 + HD_F(n) * dt;
        hd_v3 u = hd_world_to_tex(HD_KPASS hd_madd(pe, d, s));
        hd_v4 c;
        float st;
        if (!(s < len)) break;
        c = hd_tf(HD_KPASS hd_sample_value(HD_KPASS u));
        st = c.w * HD_PRM(medium).x;
        if (st > 0.0f) {
            float a = 1.0f - hd_exp(-st * dt);
            float e = T * a * k;
            if (nch == 1) {
                float l0 = hd_sample_light(HD_KPASS u, 0) * e;
                r += c.x * l0 * HD_PRM(chan_color).x;
                g += c.y * l0 * HD_PRM(chan_color).y;
                b += c.z * l0 * HD_PRM(chan_color).z;
            } else {
                r += c.x * hd_sample_light(HD_KPASS u, 0) * e;
                g += c.y * hd_sample_light(HD_KPASS u, 1) * e;
                b += c.z * hd_sample_light(HD_KPASS u, 2) * e;
            }
            T *= 1.0f - a;
            if (T < HD_PRM(march).z) { T = 0.0f; break; }
        }
    }
    hd_accumulate_pixel(HD_KPASS i, HD_V4(r + T * HD_PRM(background).x, g + T * HD_PRM(background).y,
                                          b + T * HD_PRM(background).z, 1.0f - T));
}
