/* hd_k_light.h - choosing and sampling a light (shared source): the list's directional and
   point lights (hdk_light_dir, hd_k_common.h), its area lights (quad, disk, sphere) and the
   environment map (hd_set_environment).
   Light index l: 0 .. counts.x - 1 the list, counts.x the environment while env.x > 0; the
   direct light (hd_k_direct.h) and the path tracers' next-event estimation (hd_k_path.h) draw
   one with the chances the host gives (hdk_light_choose: by each light's estimated light,
   src/hd_kparams.h, hd__light_cdf) and weigh its sample by one over its chance.

   Area lights are sampled uniformly over their area (quad, disk: one-sided, emitting on the
   side of the normal) or over the cone a sphere subtends from the point, and weigh the
   radiance by the area's solid angle per sample: L A cos / r^2 (at most HD_AREA_G_MAX times L,
   as a point light's 1/r^2 is floored), L 2 pi (1 - cos theta_max) for the sphere. They are
   not delta lights, but no scattered ray sees them (hd_k_path.h), so their density is given as 0
   and next-event estimation takes their whole weight.

   The environment is an equirectangular map, sampled by importance through the tables the host
   builds once per map (src/hd_environment.h) in the buffer env:
     env[3 t + c]                texel t = j * w + i (row j from the top): radiance times the
                                 intensity, channel c
     env[env.z + j], j = 0..h    the marginal CDF over the rows (0 first, 1 last)
     env[env.w + j (w + 1) + i]  row j's conditional CDF over its texels, i = 0..w
   A texel's probability is max(rgb) * sin(theta) at its centre over the map's sum; within the
   texel the density is constant in (u, v) = (phi / 2 pi, theta / pi), so per steradian it is
   p_texel * w * h / (2 pi^2 sin theta) at the sampled theta. The map frame's directions are
   (sin theta cos phi, cos theta, sin theta sin phi); env_r0..2, the rows of the rotation from
   the volume's frame into the map's, carry the map's rotation and the volume transform. */

#define HD_STREAM_ENV 0x1f83d9abu
#define HD_PI 3.14159265f
#define HD_2PI_SQ 19.7392088f /* 2 pi^2: the solid angle of the (u, v) unit square per sin theta */

#ifndef HD_PRELUDE_HAS_TRIG
#define hdk_cos(x) cos(x)
#define hdk_sin(x) sin(x)
#define hdk_acos(x) acos(x)
#ifdef HD_LANG_GLSL
#define hdk_atan2(y, x) atan((y), (x))
#else
#define hdk_atan2(y, x) atan2((y), (x))
#endif
#endif

#define HD_AREA_G_MAX 1.0e12f /* the largest A cos / r^2 of one area-light sample (r^2 >= 1e-12 for a point light) */

HD_FN hd_v3 hdk_cross(hd_v3 a, hd_v3 b)
{
    return HD_V3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}

/* The light drawn by u in [0, 1): the first l of the list with u < light_d[l].w (the host's CDF
   over the list), the environment past it; its chance in *prob (> 0). */
HD_FN int hdk_light_choose(HD_KARGS float u, HD_INOUT(float) prob)
{
    int n = HD_PRM(counts).x, lo = 0, hi = HD_PRM(counts).x;
    float c0, c1;
    while (lo < hi) { /* at most 7 steps for HD_MAX_LIGHTS */
        int mid = (lo + hi) >> 1;
        if (u < HD_PRM(light_d)[mid].w) hi = mid;
        else lo = mid + 1;
    }
    if (lo >= n && HD_PRM(env).x <= 0) lo = n - 1; /* u at the CDF's rounding end */
    c0 = lo > 0 ? HD_PRM(light_d)[hdk_maxi(lo - 1, 0)].w : 0.0f;
    c1 = lo < n ? HD_PRM(light_d)[hdk_mini(lo, n - 1)].w : 1.0f;
    HD_DEREF(prob) = hdk_maxf(c1 - c0, 1.0e-6f);
    return lo;
}

/* The chance of drawing the environment (0 without one), n = counts.x the list's lights. */
HD_FN float hdk_env_chance(HD_KARGS int n)
{
    if (HD_PRM(env).x <= 0) return 0.0f;
    return n > 0 ? 1.0f - HD_PRM(light_d)[hdk_mini(n, HD_MAX_LIGHTS) - 1].w : 1.0f;
}

/* Component c (0..2) of v. */
HD_FN float hdk_v3_at(hd_v3 v, int c)
{
    return c == 0 ? v.x : (c == 1 ? v.y : v.z);
}

/* The i in [0, n) with cdf[at + i] <= u < cdf[at + i + 1], for cdf[at] = 0 <= u < cdf[at + n] = 1:
   a binary search, log2(n) steps; empty intervals are never chosen. */
HD_FN int hdk_cdf_find(HD_KARGS int at, int n, float u)
{
    int lo = 0, hi = n;
    while (hi - lo > 1) {
        int mid = (lo + hi) >> 1;
        if (HD_GET1(env, at + mid) <= u) lo = mid;
        else hi = mid;
    }
    return lo;
}

/* A map direction in the volume's frame, and back. */
HD_FN hd_v3 hdk_env_to_volume(HD_KARGS hd_v3 m)
{
    return hdk_add(hdk_add(hdk_scale(HD_XYZ(HD_PRM(env_r0)), m.x), hdk_scale(HD_XYZ(HD_PRM(env_r1)), m.y)),
                   hdk_scale(HD_XYZ(HD_PRM(env_r2)), m.z));
}
HD_FN hd_v3 hdk_env_to_map(HD_KARGS hd_v3 d)
{
    return HD_V3(hdk_dot(HD_XYZ(HD_PRM(env_r0)), d), hdk_dot(HD_XYZ(HD_PRM(env_r1)), d), hdk_dot(HD_XYZ(HD_PRM(env_r2)), d));
}

/* Texel t's radiance, rgb. */
HD_FN hd_v3 hdk_env_rgb(HD_KARGS int t)
{
    return HD_V3(HD_GET1(env, 3 * t), HD_GET1(env, 3 * t + 1), HD_GET1(env, 3 * t + 2));
}

/* The density per steradian of drawing a direction in texel t at sin theta st. */
HD_FN float hdk_env_pdf(HD_KARGS int t, float st)
{
    int w = HD_PRM(env).x, h = HD_PRM(env).y;
    int j = t / w, i = t - j * w;
    int row = HD_PRM(env).w + j * (w + 1);
    float pm = HD_GET1(env, HD_PRM(env).z + j + 1) - HD_GET1(env, HD_PRM(env).z + j);
    float pc = HD_GET1(env, row + i + 1) - HD_GET1(env, row + i);
    return pm * pc * HD_F(w) * HD_F(h) / (HD_2PI_SQ * hdk_maxf(st, 1.0e-7f));
}

/* The texel direction d (volume frame, unit) looks into, and its sin theta in *st. */
HD_FN int hdk_env_texel(HD_KARGS hd_v3 d, HD_INOUT(float) st)
{
    int w = HD_PRM(env).x, h = HD_PRM(env).y;
    hd_v3 m = hdk_env_to_map(HD_KPASS d);
    float ct = hdk_clampf(m.y, -1.0f, 1.0f);
    float v = HD_F(hdk_acos(ct)) * (1.0f / HD_PI);
    float u = HD_F(hdk_atan2(m.z, m.x)) * (0.5f / HD_PI);
    int i, j;
    if (u < 0.0f) u += 1.0f;
    i = hdk_clampi(HD_I(u * HD_F(w)), 0, w - 1);
    j = hdk_clampi(HD_I(v * HD_F(h)), 0, h - 1);
    HD_DEREF(st) = hdk_sqrt(hdk_maxf(0.0f, 1.0f - ct * ct));
    return j * w + i;
}

/* What a camera ray that leaves the volume in direction d (volume frame, unit) sees behind it:
   params.background, plus the environment's radiance in d (its texel's, rotated and scaled as
   the light) where it is shown (background.w = 1, only with a map set). */
HD_FN hd_v3 hdk_env_background(HD_KARGS hd_v3 d)
{
    hd_v3 b = HD_XYZ(HD_PRM(background));
    if (HD_PRM(background).w > 0.5f) {
        float st = 0.0f;
        b = hdk_add(b, hdk_env_rgb(HD_KPASS hdk_env_texel(HD_KPASS d, HD_REF(st))));
    }
    return b;
}

/* A direction toward the environment drawn by importance from xi0 (the row) and xi1 (the texel
   in it), in the volume's frame; its density per steradian in *pdf (> 0), its texel in *t. */
HD_FN hd_v3 hdk_env_sample(HD_KARGS float xi0, float xi1, HD_INOUT(float) pdf, HD_INOUT(int) t)
{
    int w = HD_PRM(env).x, h = HD_PRM(env).y;
    int j = hdk_cdf_find(HD_KPASS HD_PRM(env).z, h, xi0);
    int row = HD_PRM(env).w + j * (w + 1);
    int i = hdk_cdf_find(HD_KPASS row, w, xi1);
    float m0 = HD_GET1(env, HD_PRM(env).z + j), m1 = HD_GET1(env, HD_PRM(env).z + j + 1);
    float c0 = HD_GET1(env, row + i), c1 = HD_GET1(env, row + i + 1);
    /* the place inside the chosen interval is again uniform: the offset within the texel */
    float fv = hdk_clampf((xi0 - m0) / (m1 - m0), 0.0f, 0.999999f);
    float fu = hdk_clampf((xi1 - c0) / (c1 - c0), 0.0f, 0.999999f);
    float theta = HD_PI * (HD_F(j) + fv) / HD_F(h);
    float ph = 2.0f * HD_PI * (HD_F(i) + fu) / HD_F(w);
    float st = HD_F(hdk_sin(theta));
    hd_v3 m = HD_V3(st * HD_F(hdk_cos(ph)), HD_F(hdk_cos(theta)), st * HD_F(hdk_sin(ph)));
    HD_DEREF(pdf) = (m1 - m0) * (c1 - c0) * HD_F(w) * HD_F(h) / (HD_2PI_SQ * hdk_maxf(st, 1.0e-7f));
    HD_DEREF(t) = j * w + i;
    return hdk_normalize(hdk_env_to_volume(HD_KPASS m));
}

/* Area light l (type 2 quad, 3 disk, 4 sphere) seen from p: the direction toward a point of it
   drawn from xi0, xi1, where tracking stops (*tmax), the radiance over the direction's density
   (falloff included) in the return's x, y, z as hdk_light_pick's *w. */
HD_FN hd_v3 hdk_area_sample(HD_KARGS int l, hd_v3 p, float xi0, float xi1, HD_INOUT(float) tmax, HD_INOUT(hd_v3) w)
{
    hd_v4 la = HD_PRM(light_a)[l], lc = HD_PRM(light_c)[l], ld = HD_PRM(light_d)[l];
    hd_v3 lb = HD_XYZ(HD_PRM(light_b)[l]);
    hd_v3 d, q, n;
    float g = 0.0f, r2, r;
    if (la.w > 3.5f) { /* sphere: uniform in the cone it subtends */
        hd_v3 v = hdk_sub(HD_XYZ(la), p), wz, a, b1, b2;
        float d2 = hdk_dot(v, v), rad2 = lc.w * lc.w, dist, s2, omc, ct, st, ph, th;
        if (!(d2 > rad2)) { /* inside the sphere: it emits outward only */
            HD_DEREF(tmax) = 0.0f;
            HD_DEREF(w) = HD_V3(0.0f, 0.0f, 0.0f);
            return HD_V3(0.0f, 0.0f, 1.0f);
        }
        dist = hdk_sqrt(d2);
        wz = hdk_scale(v, 1.0f / dist);
        s2 = rad2 / d2;
        omc = s2 / (1.0f + hdk_sqrt(hdk_maxf(0.0f, 1.0f - s2))); /* 1 - cos theta_max, no cancellation */
        ct = 1.0f - xi0 * omc;
        st = hdk_sqrt(hdk_maxf(0.0f, xi0 * omc * (2.0f - xi0 * omc)));
        ph = 6.28318531f * xi1;
        a = hdk_absf(wz.x) > 0.9f ? HD_V3(0.0f, 1.0f, 0.0f) : HD_V3(1.0f, 0.0f, 0.0f);
        b1 = hdk_normalize(hdk_cross(a, wz));
        b2 = hdk_cross(wz, b1);
        d = hdk_normalize(hdk_add(hdk_scale(wz, ct), hdk_add(hdk_scale(b1, st * hdk_cos(ph)), hdk_scale(b2, st * hdk_sin(ph)))));
        /* the nearer crossing of the sphere along d */
        th = dist * ct - hdk_sqrt(hdk_maxf(0.0f, rad2 - d2 * st * st));
        HD_DEREF(tmax) = hdk_minf(hdk_maxf(th, 0.0f), hdk_box_exit(HD_KPASS p, d));
        HD_DEREF(w) = hdk_scale(lb, 6.28318531f * omc);
        return d;
    }
    if (la.w < 2.5f) { /* quad: corner + xi0 edge 1 + xi1 edge 2, normal edge1 x edge2 */
        q = hdk_add(HD_XYZ(la), hdk_add(hdk_scale(HD_XYZ(lc), xi0), hdk_scale(HD_XYZ(ld), xi1)));
        n = hdk_normalize(hdk_cross(HD_XYZ(lc), HD_XYZ(ld)));
        g = lc.w;
    } else { /* disk: uniform in area, radius sqrt(xi0) */
        float rr = lc.w * hdk_sqrt(xi0), ph = 6.28318531f * xi1;
        hd_v3 t1 = HD_XYZ(ld), t2;
        n = HD_XYZ(lc);
        t2 = hdk_cross(n, t1);
        q = hdk_add(HD_XYZ(la), hdk_add(hdk_scale(t1, rr * hdk_cos(ph)), hdk_scale(t2, rr * hdk_sin(ph))));
        g = HD_PI * lc.w * lc.w;
    }
    {
        hd_v3 v = hdk_sub(q, p);
        float cl;
        r2 = hdk_maxf(hdk_dot(v, v), 1.0e-12f);
        r = hdk_sqrt(r2);
        d = hdk_scale(v, 1.0f / r);
        cl = -hdk_dot(n, d); /* the cosine at the light: > 0 on the side it emits on */
        g = cl > 0.0f ? hdk_minf(g * cl / r2, HD_AREA_G_MAX) : 0.0f;
        HD_DEREF(tmax) = hdk_minf(r, hdk_box_exit(HD_KPASS p, d));
        HD_DEREF(w) = hdk_scale(lb, g);
    }
    return d;
}

/* Light l seen from p (inside the box): the direction toward it, where tracking toward it stops
   (*tmax: the light or the box's edge), in *w its radiance over the density of the direction
   per channel (falloff included; only x with one illumination channel), and that density in
   *pdf: 0 for the list's lights, which no scattered path can hit. xi0, xi1 place the
   sample of the environment or of an area light. */
HD_FN hd_v3 hdk_light_pick(HD_KARGS int l, hd_v3 p, float xi0, float xi1, HD_INOUT(float) tmax, HD_INOUT(hd_v3) w,
                          HD_INOUT(float) pdf)
{
    hd_v3 d;
    if (l < HD_PRM(counts).x && HD_PRM(light_a)[hdk_mini(l, HD_MAX_LIGHTS - 1)].w > 1.5f) {
        d = hdk_area_sample(HD_KPASS l, p, xi0, xi1, tmax, w);
        HD_DEREF(pdf) = 0.0f;
    } else if (l < HD_PRM(counts).x) {
        float falloff = 0.0f;
        hd_v4 lb = HD_PRM(light_b)[l];
        d = hdk_light_dir(HD_KPASS l, p, tmax, HD_REF(falloff));
        HD_DEREF(w) = hdk_scale(HD_XYZ(lb), falloff);
        HD_DEREF(pdf) = 0.0f;
    } else {
        float pd = 1.0f;
        int t = 0;
        d = hdk_env_sample(HD_KPASS xi0, xi1, HD_REF(pd), HD_REF(t));
        HD_DEREF(tmax) = hdk_box_exit(HD_KPASS p, d);
        HD_DEREF(w) = hdk_scale(hdk_env_rgb(HD_KPASS t), 1.0f / pd);
        HD_DEREF(pdf) = pd;
    }
    return d;
}

/* Channel c (0..2) of a light's weight w for a path's colour: with one illumination channel
   the scalar x times the lights' common colour. */
HD_FN float hdk_light_colour(HD_KARGS hd_v3 w, int c)
{
    if (HD_PRM(gdims).w == 1) return w.x * hdk_v3_at(HD_XYZ(HD_PRM(chan_color)), c);
    return hdk_v3_at(w, c);
}
