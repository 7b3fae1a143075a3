/* hd_k_project.h - stage 3: emission-absorption ray marching from the camera (shared source).
   L = sum T_cam * c(x) * albedo * (E + phi)(x) / (4 pi) * (1 - exp(-sigma_t dt)) + T_end * L_bg:
   each segment's emission sigma_s c (E + phi) / (4 pi) integrated exactly for a constant
   sigma_t over the segment (sigma_s / sigma_t = albedo). The pixel position and the first
   sample are jittered per frame; frames go into a running mean with weight march.y. */

#ifndef HD_PRELUDE_SAMPLES_LIGHT
/* Trilinear E + phi of channel c at texture coordinate u, on the illumination grid. */
HD_FN float hdk_sample_light(HD_KARGS hd_v3 u, int c)
{
    int nx = HD_PRM(gdims).x, ny = HD_PRM(gdims).y, nz = HD_PRM(gdims).z;
    float wx = 0.0f, wy = 0.0f, wz = 0.0f;
    int x0 = hdk_lerp_axis(u.x, nx, HD_REF(wx));
    int y0 = hdk_lerp_axis(u.y, ny, HD_REF(wy));
    int z0 = hdk_lerp_axis(u.z, nz, HD_REF(wz));
    int x1 = hdk_mini(x0 + 1, nx - 1), y1 = hdk_mini(y0 + 1, ny - 1), z1 = hdk_mini(z0 + 1, nz - 1);
    int za = z0 + c * nz, zb = z1 + c * nz;
    int r00 = (za * ny + y0) * nx, r10 = (za * ny + y1) * nx;
    int r01 = (zb * ny + y0) * nx, r11 = (zb * ny + y1) * nx;
#ifdef HD_PRELUDE_LIGHT_SUM
    /* a backend that keeps E + phi summed in one grid (hdk_light_sum_voxel): the same sums, half
       the loads */
    if (HD_LIGHT_SUM_READY) {
        float s000 = HD_GET(lsum, r00 + x0, x0, y0, za), s100 = HD_GET(lsum, r00 + x1, x1, y0, za);
        float s010 = HD_GET(lsum, r10 + x0, x0, y1, za), s110 = HD_GET(lsum, r10 + x1, x1, y1, za);
        float s001 = HD_GET(lsum, r01 + x0, x0, y0, zb), s101 = HD_GET(lsum, r01 + x1, x1, y0, zb);
        float s011 = HD_GET(lsum, r11 + x0, x0, y1, zb), s111 = HD_GET(lsum, r11 + x1, x1, y1, zb);
        float d00 = s000 + wx * (s100 - s000), d10 = s010 + wx * (s110 - s010);
        float d01 = s001 + wx * (s101 - s001), d11 = s011 + wx * (s111 - s011);
        float d0 = d00 + wy * (d10 - d00), d1 = d01 + wy * (d11 - d01);
        return d0 + wz * (d1 - d0);
    }
#endif
#ifdef HD_LIGHT_SUM_ONLY
    return 0.0f; /* not reached: the backend's summed light is always there, and no stage loads E or phi here */
#else
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
#endif
}
#endif

#ifdef HD_PRELUDE_LIGHT_SUM
/* lsum = E + phi at voxel (x, y, zz) of the illumination grid (zz = z + c * gz for channel c),
   stored x-fastest at (zz * gy + y) * gx + x: rebuilt by the backend after a pass that changed E
   or phi, read by hdk_sample_light. */
HD_FN void hdk_light_sum_voxel(HD_KARGS int x, int y, int zz)
{
    int i = (zz * HD_PRM(gdims).y + y) * HD_PRM(gdims).x + x;
    HD_SET(lsum, i, x, y, zz, HD_GET(E, i, x, y, zz) + HD_GET(phi, i, x, y, zz));
}
#endif

/* The camera ray through image position (fx, fy) in pixels (top row first), at NDC (sx, sy):
   origin cam_pos + sx cam_ou + sy cam_ov, unit direction along cam_w + sx cam_u + sy cam_v (the
   host's hd__camera_frame: a look-at camera has ou = ov = 0, a perspective projection too, an
   orthographic one u = v = 0). Returns the direction; the origin and NDC go to o, sx and sy. */
HD_FN hd_v3 hdk_camera_ray(HD_KARGS float fx, float fy, HD_INOUT(hd_v3) o, HD_INOUT(float) sx, HD_INOUT(float) sy)
{
    float x = 2.0f * fx / HD_F(HD_PRM(image).x) - 1.0f;
    float y = 1.0f - 2.0f * fy / HD_F(HD_PRM(image).y);
    hd_v3 d = hdk_add(HD_XYZ(HD_PRM(cam_w)),
                     hdk_add(hdk_scale(HD_XYZ(HD_PRM(cam_u)), x), hdk_scale(HD_XYZ(HD_PRM(cam_v)), y)));
    HD_DEREF(o) = hdk_add(HD_XYZ(HD_PRM(cam_pos)), hdk_add(hdk_scale(HD_XYZ(HD_PRM(cam_ou)), x), hdk_scale(HD_XYZ(HD_PRM(cam_ov)), y)));
    HD_DEREF(sx) = x;
    HD_DEREF(sy) = y;
    return hdk_normalize(d);
}

/* Where the camera ray o + t d of pixel (px, py) at jittered position (fx, fy), NDC (sx, sy),
   meets the host's depth buffer (depth_dims.z = 1; hd_set_depth): the buffer's value at the
   full-resolution pixel under (fx, fy) (the pixel itself in a full frame; a reduced frame's
   frame is image.x x image.y) mapped to NDC z (depth_z), unprojected through the inverse of
   projection * view (depth_m0..3, into the volume's frame) and measured along d. Returns that t
   (>= 0) with *hit = 1, or 3e38 with *hit = 0 where there is no buffer or the value is the far
   plane's (nothing there), or the point is not in front of the camera. */
HD_FN float hdk_depth_t(HD_KARGS int px, int py, float fx, float fy, float sx, float sy, hd_v3 o, hd_v3 d,
                       HD_INOUT(int) hit)
{
    hd_i4 dd = HD_PRM(depth_dims);
    int x = px, y = py;
    float w, z, hx, hy, hz, hw;
    hd_v4 m0 = HD_PRM(depth_m0), m1 = HD_PRM(depth_m1), m2 = HD_PRM(depth_m2), m3 = HD_PRM(depth_m3);
    HD_DEREF(hit) = 0;
    if (dd.z == 0) return 3.0e38f;
    if (dd.x != HD_PRM(image).x || dd.y != HD_PRM(image).y) {
        x = hdk_clampi(HD_I(fx * HD_F(dd.x) / HD_F(HD_PRM(image).x)), 0, dd.x - 1);
        y = hdk_clampi(HD_I(fy * HD_F(dd.y) / HD_F(HD_PRM(image).y)), 0, dd.y - 1);
    }
    w = HD_GET1(dep, (dd.w != 0 ? dd.y - 1 - y : y) * dd.x + x);
    if (w == HD_PRM(depth_z).z) return 3.0e38f;
    z = w * HD_PRM(depth_z).x + HD_PRM(depth_z).y;
    hx = m0.x * sx + m0.y * sy + m0.z * z + m0.w;
    hy = m1.x * sx + m1.y * sy + m1.z * z + m1.w;
    hz = m2.x * sx + m2.y * sy + m2.z * z + m2.w;
    hw = m3.x * sx + m3.y * sy + m3.z * z + m3.w;
    if (!(hw > 0.0f)) return 3.0e38f;
    HD_DEREF(hit) = 1;
    return hdk_maxf(hdk_dot(hdk_sub(HD_V3(hx / hw, hy / hw, hz / hw), o), d), 0.0f);
}

/* Folds one frame value into the running mean of pixel i (RGBA) of the image region that
   starts at pixel region.x (0; a reduced frame's region: hd_k_upsample.h). */
HD_FN void hdk_accumulate_pixel(HD_KARGS int i, hd_v4 v)
{
    float w = HD_PRM(march).y;
    int b = (i + HD_PRM(region).x) * 4;
    HD_SET1(img, b, HD_GET1(img, b) + (v.x - HD_GET1(img, b)) * w);
    HD_SET1(img, b + 1, HD_GET1(img, b + 1) + (v.y - HD_GET1(img, b + 1)) * w);
    HD_SET1(img, b + 2, HD_GET1(img, b + 2) + (v.z - HD_GET1(img, b + 2)) * w);
    HD_SET1(img, b + 3, HD_GET1(img, b + 3) + (v.w - HD_GET1(img, b + 3)) * w);
}

#ifdef HD_PRELUDE_PROJECT_TABLE
/* The step's TF table, for backends that keep one (HD_PROJECT_TABLE_READY): entry j, at value
   j / (n - 1), is (rgb * a * albedo / (4 pi), a) with a = 1 - exp(-sigma_t dt), one step's
   opacity. n - 1 is a multiple of the TF's segments, so each table segment lies inside one TF
   segment: a transparent TF segment stays exactly 0 (the empty-space skip relies on it) and the
   interpolated opacity differs from the exact one only by the exponential's curvature. */
HD_FN hd_v4 hdk_project_lookup(HD_KARGS float v)
{
    float f = 0.0f;
    int a = hdk_table_segment(v, HD_PTAB_N, HD_REF(f));
    return HD_V4(HD_TABLE_LERP(ptab, a, f, 0), HD_TABLE_LERP(ptab, a, f, 1), HD_TABLE_LERP(ptab, a, f, 2),
                 HD_TABLE_LERP(ptab, a, f, 3));
}
#endif

/* Adds one sample's emission to (r, g, b) and its absorption to T: colour and extinction from
   the TF at the volume sample (or the step's table), the light from hdk_sample_light. */
HD_FN void hdk_project_sample(HD_KARGS hd_v3 u, float dt, HD_INOUT(float) T, HD_INOUT(float) r,
                             HD_INOUT(float) g, HD_INOUT(float) b)
{
    hd_v4 c;    /* rgb: the emission's colour weights */
    float e;    /* the emission's scale: transmittance so far (and opacity, albedo / (4 pi)) */
    float keep; /* the share of T the step keeps */
    if (hdk_in_crop(HD_KPASS u) == 0) return; /* no medium outside the crop box */
#ifdef HD_PRELUDE_PROJECT_TABLE
    if (HD_PROJECT_TABLE_READY) {
        c = hdk_project_lookup(HD_KPASS hdk_sample_value(HD_KPASS u));
        if (!(c.w > 0.0f)) return;
        e = HD_DEREF(T);
        keep = 1.0f - c.w;
    } else
#endif
    {
        float st, a;
        c = hdk_tf(HD_KPASS hdk_sample_value(HD_KPASS u));
        st = c.w * HD_PRM(medium).x;
        if (!(st > 0.0f)) return;
        a = 1.0f - hdk_exp(-st * dt);
        e = HD_DEREF(T) * a * HD_PRM(medium).y * HD_PRM(box).w; /* albedo / (4 pi) */
        keep = 1.0f - a;
    }
    if (HD_PRM(gdims).w == 1) {
        float l0 = hdk_sample_light(HD_KPASS u, 0) * e;
        HD_DEREF(r) += c.x * l0 * HD_PRM(chan_color).x;
        HD_DEREF(g) += c.y * l0 * HD_PRM(chan_color).y;
        HD_DEREF(b) += c.z * l0 * HD_PRM(chan_color).z;
    } else {
        HD_DEREF(r) += c.x * hdk_sample_light(HD_KPASS u, 0) * e;
        HD_DEREF(g) += c.y * hdk_sample_light(HD_KPASS u, 1) * e;
        HD_DEREF(b) += c.z * hdk_sample_light(HD_KPASS u, 2) * e;
    }
    HD_DEREF(T) *= keep;
}

/* The index of the first sample past se, for a march that resumes at se after empty cells
   (none before n): samples sit at s0 + n dt, n below HD_MAX_MARCH_STEPS. */
HD_FN int hdk_march_resume(float se, float s0, float idt, int n)
{
    float m = hdk_floor((se - s0) * idt) + 1.0f;
    if (!(se > s0)) return n;
    return m < HD_F(HD_MAX_MARCH_STEPS) ? hdk_maxi(HD_I(m), n) : HD_MAX_MARCH_STEPS;
}

/* Pixel (px, py)'s camera ray for this frame: its entry into the box pe, unit direction d, the
   length len of its chord (at most the box diagonal; negative for a miss) and its jitter s0.
   With the host's depth the chord ends where the ray meets the scene (hdk_depth_t; *geo = 1
   where there is geometry): the jittered samples, each standing for one step, cover [0, len)
   exactly in expectation, as at the box's far face, so the last step is not shortened. */
HD_FN void hdk_project_ray(HD_KARGS int px, int py, HD_INOUT(hd_v3) pe, HD_INOUT(hd_v3) d, HD_INOUT(float) len,
                          HD_INOUT(float) s0, HD_INOUT(int) geo)
{
    int i = py * HD_PRM(image).x + px;
    hd_u32 key = hdk_rng_key(HD_U(i), HD_U(HD_PRM(frame).y), HD_U(HD_PRM(frame).z), HD_STREAM_PROJECT);
    hd_v3 o = HD_V3(0.0f, 0.0f, 0.0f);
    float sx = 0.0f, sy = 0.0f;
    float fx = HD_F(px) + hdk_rand(key, 0u), fy = HD_F(py) + hdk_rand(key, 1u);
    hd_v3 dir = hdk_camera_ray(HD_KPASS fx, fy, HD_REF(o), HD_REF(sx), HD_REF(sy));
    float t1 = 0.0f;
    float t0 = hdk_box_entry(HD_KPASS o, dir, HD_REF(t1));
    float td = hdk_depth_t(HD_KPASS px, py, fx, fy, sx, sy, o, dir, geo);
    HD_DEREF(pe) = hdk_madd(o, dir, t0);
    HD_DEREF(d) = dir;
    HD_DEREF(len) = hdk_minf(t1 - t0, HD_PRM(gridh).w);
    if (HD_DEREF(geo) != 0) HD_DEREF(len) = hdk_minf(HD_DEREF(len), td - t0);
    HD_DEREF(s0) = hdk_rand(key, 2u) * HD_PRM(march).x;
}

/* The march of the ray pe + s d, s in [0, len), returns (r, g, b, T): the emission it gathered
   and its transmittance. Its samples sit at s0 + n dt from the box entry, n counted (s0: the
   jitter), so the step advances however far the eye is; n stays below HD_MAX_MARCH_STEPS, and
   the march stops once T falls below march.z. Empty space is skipped through the majorant grid
   (cells of mdims.w voxels, each majorant bounding every trilinear sample inside the cell with a
   one-voxel halo, src/hd_volume.h), walked cell by cell (hd_cell_walk, the 3D DDA hdk_track also
   walks): in a cell whose majorant is 0 every sample has sigma_t = 0 and adds nothing. The walk
   visits each cell once and ends at the grid's far face or at len (the grid's last cell reaches
   to len). Two marches take the same samples, in the same order, to the same image; each
   backend's prelude picks one (HD_PROJECT_MARCH_SPAN):

   hdk_project_march_cells (CPU, OpenCL) walks the cells and marches each non-empty one in turn:
   after a run of empty cells it resumes at the first sample past the next one's entry, so no
   sample of an empty cell is taken. The tight loop a processor running one ray at a time wants.

   hdk_project_march_span (GLSL: llvmpipe, lavapipe, GPUs) first walks every cell and keeps the
   spans of consecutive non-empty cells, from a span's first cell's entry to its last cell's exit,
   the first spans - 1 of them apart and any after them merged into the last (spans: 1 to
   HD_MARCH_SPANS, which hdk_project_pixel passes); then one
   loop marches the spans, resuming past each one's entry as the cell march does. Samples in empty
   cells inside a merged span add nothing (hdk_project_sample returns at a zero opacity; a rounding
   difference at a cell face stays inside the halo). Where rays run in the lanes of one SIMD
   instruction stream and the compiler runs both sides of every branch under a mask (llvmpipe and
   lavapipe do), every iteration of one loop that both walks and samples pays for both; here the
   walk's iterations pay for a step and the march's for a sample.

   Both set *xs to the position s of the first sample after which T is at or below depth_z.w
   (1 - params.depth_threshold) or below the cutoff march.z: where the accumulated opacity first
   reaches the threshold (the volume's depth, hdk_project_depth); -1 where it never does. */
#ifndef HD_MARCH_SPANS
#define HD_MARCH_SPANS 6 /* spans the span march keeps apart: 6 measured best of 1, 4, 6, 8 on llvmpipe */
#endif
HD_FN hd_v4 hdk_project_march_cells(HD_KARGS hd_v3 pe, hd_v3 d, float len, float s0, HD_INOUT(float) xs)
{
    float dt = HD_PRM(march).x, idt = 1.0f / dt, tth = HD_PRM(depth_z).w;
    float T = 1.0f, r = 0.0f, g = 0.0f, b = 0.0f;
    hd_cell_walk w = hdk_cell_walk_begin(HD_KPASS pe, d);
    hd_i4 md = HD_PRM(mdims);
    float se = 0.0f; /* where the ray entered the current cell */
    int skipped = 1;  /* the cells since the last sample were empty: n must catch up with se */
    int n = 0;
    int cells = md.x + md.y + md.z; /* each step moves one index toward the grid's far face */
    for (;;) {
        int ax = hdk_cell_walk_axis(w);
        float sc = hdk_cell_walk_end(w, ax, md, len);
        if (HD_GET1(maj, hdk_cell_walk_index(w, md)) > 0.0f) {
            float s;
            if (skipped != 0) n = hdk_march_resume(se, s0, idt, n);
            skipped = 0;
            s = s0 + HD_F(n) * dt;
            while (s < sc && n < HD_MAX_MARCH_STEPS) {
                hdk_project_sample(HD_KPASS hdk_world_to_tex(HD_KPASS hdk_madd(pe, d, s)), dt, HD_REF(T), HD_REF(r),
                                  HD_REF(g), HD_REF(b));
                if (HD_DEREF(xs) < 0.0f && (T <= tth || T < HD_PRM(march).z)) HD_DEREF(xs) = s;
                if (T < HD_PRM(march).z) break;
                ++n;
                s = s0 + HD_F(n) * dt;
            }
            if (T < HD_PRM(march).z) break; /* the ray ended inside the cell */
        } else {
            skipped = 1;
        }
        if (!(sc < len) || n >= HD_MAX_MARCH_STEPS || cells <= 1) break;
        se = sc;
        hdk_cell_walk_step(HD_REF(w), ax);
        --cells;
    }
    return HD_V4(r, g, b, T);
}

HD_FN hd_v4 hdk_project_march_span(HD_KARGS hd_v3 pe, hd_v3 d, float len, float s0, int spans, HD_INOUT(float) xs)
{
    float dt = HD_PRM(march).x, idt = 1.0f / dt, tth = HD_PRM(depth_z).w;
    float T = 1.0f, r = 0.0f, g = 0.0f, b = 0.0f;
    hd_cell_walk w = hdk_cell_walk_begin(HD_KPASS pe, d);
    hd_i4 md = HD_PRM(mdims);
    float se = 0.0f;                /* where the ray entered the current cell */
    float sa[HD_MARCH_SPANS], sb[HD_MARCH_SPANS]; /* span j: from sa[j] to sb[j] */
    float s;
    int n, k = -1, prev = 0, j;     /* k: the last span; prev: the previous cell was not empty */
    int cells = md.x + md.y + md.z; /* each step moves one index toward the grid's far face */
    for (j = 0; j < HD_MARCH_SPANS; ++j) { sa[j] = 0.0f; sb[j] = 0.0f; }
    for (;;) {
        int ax = hdk_cell_walk_axis(w);
        float sc = hdk_cell_walk_end(w, ax, md, len);
        int occ = HD_GET1(maj, hdk_cell_walk_index(w, md)) > 0.0f ? 1 : 0;
        if (occ != 0) {
            if (prev == 0 && k < spans - 1) { ++k; sa[k] = se; }
            sb[k] = sc;
        }
        prev = occ;
        if (!(sc < len) || cells <= 1) break;
        se = sc;
        hdk_cell_walk_step(HD_REF(w), ax);
        --cells;
    }
    j = 0;
    n = k >= 0 ? hdk_march_resume(sa[0], s0, idt, 0) : 0;
    s = s0 + HD_F(n) * dt;
    while (j <= k && n < HD_MAX_MARCH_STEPS) {
        if (s < sb[j]) { /* a sample of span j, else on to the next span */
            hdk_project_sample(HD_KPASS hdk_world_to_tex(HD_KPASS hdk_madd(pe, d, s)), dt, HD_REF(T), HD_REF(r), HD_REF(g),
                              HD_REF(b));
            if (HD_DEREF(xs) < 0.0f && (T <= tth || T < HD_PRM(march).z)) HD_DEREF(xs) = s;
            if (T < HD_PRM(march).z) break;
            ++n;
        } else {
            ++j;
            if (j <= k) n = hdk_march_resume(sa[j], s0, idt, n);
        }
        s = s0 + HD_F(n) * dt;
    }
    return HD_V4(r, g, b, T);
}

/* The volume's depth at point p of the volume's frame, as the depth plane holds it: q = (depth_q .
   (p, 1)) / (depth_w . (p, 1)), the host's projection * view * volume-to-world folded into two
   rows (src/hd_kparams.h) so that q is the window depth's distance from the far plane's value
   (1 - depth, or depth when reversed), in [0, 1]: larger is nearer, 0 the far plane's (also
   beyond it, behind the camera and without a matrix camera, depth_w = 0). */
HD_FN float hdk_depth_q(HD_KARGS hd_v3 p)
{
    hd_v4 a = HD_PRM(depth_q), b = HD_PRM(depth_w);
    float w = b.x * p.x + b.y * p.y + b.z * p.z + b.w;
    if (!(w > 0.0f)) return 0.0f;
    return hdk_clampf((a.x * p.x + a.y * p.y + a.z * p.z + a.w) / w, 0.0f, 1.0f);
}

/* The volume's depth of full-resolution pixel i (a reduced frame, region.x > 0, writes none; nor
   a block without a plane, region.z = 0): the image buffer's depth plane (region.z floats from its
   start, width x height floats) holds, per pixel, the largest q (hdk_depth_q: the nearest) of
   the crossings (where the opacity reached the threshold, hdk_project_march_*) over the frames
   since the running mean restarted (march.y = 1: the frame's own value), 0 where none crossed. */
HD_FN void hdk_project_depth(HD_KARGS int i, float q)
{
    int j = HD_PRM(region).z + i;
    if (HD_PRM(region).x != 0 || HD_PRM(region).z == 0) return;
    HD_SET1(img, j, HD_PRM(march).y == 1.0f ? q : hdk_maxf(HD_GET1(img, j), q));
}

/* Folds the march's (r, g, b, T) into pixel i: what is behind it in direction d
   (hdk_env_background; none where the host's geometry is, geo = 1) times T, and T = 0 where the
   march stopped on it; and the crossing's q (0: none) into the depth plane. Alpha is 1 - T, or 1
   where the environment is shown behind the volume (premultiplied: the map fills the pixel). */
HD_FN void hdk_project_finish(HD_KARGS int i, hd_v4 m, int geo, float q, hd_v3 d)
{
    float T = m.w < HD_PRM(march).z ? 0.0f : m.w;
    float bg = geo != 0 ? 0.0f : T;
    float a = geo == 0 && HD_PRM(background).w > 0.5f ? 1.0f : 1.0f - T;
    hd_v3 b = bg > 0.0f ? hdk_env_background(HD_KPASS d) : HD_V3(0.0f, 0.0f, 0.0f);
    hdk_accumulate_pixel(HD_KPASS i, HD_V4(m.x + bg * b.x, m.y + bg * b.y, m.z + bg * b.z, a));
    hdk_project_depth(HD_KPASS i, q);
}

HD_FN void hdk_project_pixel(HD_KARGS int px, int py)
{
    hd_v3 pe = HD_V3(0.0f, 0.0f, 0.0f), d = HD_V3(0.0f, 0.0f, 1.0f);
    float len = 0.0f, s0 = 0.0f, xs = -1.0f;
    int geo = 0;
    hd_v4 m;
    hdk_project_ray(HD_KPASS px, py, HD_REF(pe), HD_REF(d), HD_REF(len), HD_REF(s0), HD_REF(geo));
#ifdef HD_PROJECT_MARCH_SPAN
    m = hdk_project_march_span(HD_KPASS pe, d, len, s0, HD_MARCH_SPANS, HD_REF(xs));
#else
    m = hdk_project_march_cells(HD_KPASS pe, d, len, s0, HD_REF(xs));
#endif
    hdk_project_finish(HD_KPASS py * HD_PRM(image).x + px, m, geo, xs >= 0.0f ? hdk_depth_q(HD_KPASS hdk_madd(pe, d, xs)) : 0.0f, d);
}
