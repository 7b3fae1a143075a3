/* hd_k_path.h - PT_SS and PT_MS: camera path tracing, one full path per pixel per iteration
   (shared source).

   From the camera, delta tracking (hdk_free_flight, the DDA walker shared with the direct-light
   stage) finds the first real collision. At every collision vertex x:
     - the path weight w *= albedo * c(x): the TF colour is the per-channel scattering albedo, so
       the expected weight is exactly the chance the path survives as scattering in each channel
       (absorption is not sampled, it is carried in w: no bias, less variance);
     - next-event estimation: one light l drawn with chance P_l among the list and the
       environment (hdk_light_choose, hd_k_light.h), its transmittance by the selected tracking
       estimator (ratio tracking by default), so the vertex adds
           w * I_l * falloff * T(x -> l) * p(mu) * m / P_l,   mu = d . omega_l,
       p the phase function (isotropic 1/(4 pi), or Henyey-Greenstein with g = medium.z), I_l
       the environment's radiance over its direction's density q (an area light's over its
       point's), and m the multiple importance sampling weight (balance heuristic)
       P q / (P q + p) for the environment at a vertex whose path goes on, 1 otherwise (area
       lights too: no ray sees them);
     - then the path scatters in a direction drawn from p (importance sampled, so w is unchanged),
       after Russian roulette from HD_PT_RR_BOUNCES vertices on, until counts.w vertices.
   PT_SS is this kernel with counts.w = 1 and g = 0 (set by the host): one collision, one shadow
   ray, isotropic phase; so PT_MS with max_bounces = 1 and g = 0 is the same estimator.
   Every loop is bounded: at most counts.w (max_bounces <= 100000) vertices per path, each
   free flight and shadow ray at most HD_MAX_TRACK_STEPS (hdk_track).
   A camera ray that leaves the box unscattered sees the background (and the environment where
   it is shown, hdk_env_background, with alpha 1); a scattered ray that leaves
   sees the environment (if one is set) with the other weight of the pair, p / (P q + p), so
   each direction is counted once; the background is a backdrop, not a light, as in HD's
   projection. Alpha is 1 if
   the camera ray collides, so its mean is 1 - T_cam as in the projection. With the host's depth
   (hdk_depth_t) the first free flight ends at the scene's surface: a path that reaches it ends
   there with nothing (the geometry is opaque and black for the volume's image) and sees no
   background; scattered rays do not see the geometry (the light ignores it, as HD's does).
   Refinement of a resting HD view (params.rest, src/hd_schedule.h) runs this kernel
   on HD's converged light with image.w = k >= 1: at the k-th vertex the path ends into HD's
   cache instead of tracking toward a light, adding w * (E + phi)(x) / (4 pi) (the in-scattered
   radiance HD's projection uses there, isotropic), so vertices 1..k-1 carry what the diffusion
   lacks (light across air, exact shadows) and the cache the rest. k = 1 is HD's own estimator
   traced; image.w = 0 never reads it: PT_MS. With region.w > 0 (HD_REST_BLEND) the path goes
   into the blend planes instead (hdk_blend_accumulate, hd_k_upsample.h).
   Random numbers: key (pixel, iteration, seed, HD_STREAM_PATH); dims 0, 1 jitter the pixel,
   then every decision takes the next dims in order. Frames go into the image's running mean with
   weight march.y, which the host sets to 1/n for these methods (a plain progressive mean). */

#define HD_PT_RR_BOUNCES 3 /* Russian roulette from this many vertices on */

/* Henyey-Greenstein phase function per steradian; mu = cosine between the propagation
   directions before and after scattering; g = 0 is isotropic, 1 / (4 pi). */
HD_FN float hdk_phase_hg(float g, float mu)
{
    float den = 1.0f + g * g - 2.0f * g * mu;
    if (hdk_absf(g) < 1.0e-3f) return HD_INV_4PI;
    return HD_INV_4PI * (1.0f - g * g) / (den * hdk_sqrt(den));
}

/* A direction drawn from the HG phase function around the propagation direction d (unit). */
HD_FN hd_v3 hdk_sample_phase_hg(hd_v3 d, float g, float xi0, float xi1)
{
    float mu, s, st, ph;
    hd_v3 a, b1, b2;
    if (hdk_absf(g) < 1.0e-3f) {
        mu = 1.0f - 2.0f * xi0;
    } else {
        s = (1.0f - g * g) / (1.0f - g + 2.0f * g * xi0);
        mu = (1.0f + g * g - s * s) / (2.0f * g);
    }
    mu = hdk_clampf(mu, -1.0f, 1.0f);
    st = hdk_sqrt(hdk_maxf(0.0f, 1.0f - mu * mu));
    ph = 6.28318531f * xi1;
    a = hdk_absf(d.x) > 0.9f ? HD_V3(0.0f, 1.0f, 0.0f) : HD_V3(1.0f, 0.0f, 0.0f);
    b1 = hdk_normalize(hdk_cross(a, d));
    b2 = hdk_cross(d, b1);
    return hdk_normalize(hdk_add(hdk_scale(d, mu), hdk_add(hdk_scale(b1, st * hdk_cos(ph)), hdk_scale(b2, st * hdk_sin(ph)))));
}

/* The in-scattered radiance HD's light gives at texture coordinate u, per colour channel:
   (E + phi) / (4 pi), with 1 illumination channel times the lights' common colour. */
HD_FN float hdk_cache_rgb(HD_KARGS hd_v3 u, int c)
{
    float cc = c == 0 ? HD_PRM(chan_color).x : (c == 1 ? HD_PRM(chan_color).y : HD_PRM(chan_color).z);
    if (HD_PRM(gdims).w == 1) return hdk_sample_light(HD_KPASS u, 0) * HD_PRM(box).w * cc;
    return hdk_sample_light(HD_KPASS u, c) * HD_PRM(box).w;
}

HD_FN void hdk_path_pixel(HD_KARGS int px, int py)
{
    int i = py * HD_PRM(image).x + px;
    hd_u32 key = hdk_rng_key(HD_U(i), HD_U(HD_PRM(frame).x), HD_U(HD_PRM(frame).z), HD_STREAM_PATH);
    hd_v3 o = HD_V3(0.0f, 0.0f, 0.0f);
    float sx = 0.0f, sy = 0.0f;
    float fx = HD_F(px) + hdk_rand(key, 0u), fy = HD_F(py) + hdk_rand(key, 1u);
    hd_v3 d = hdk_camera_ray(HD_KPASS fx, fy, HD_REF(o), HD_REF(sx), HD_REF(sy));
    float t1 = 0.0f;
    float t0 = hdk_box_entry(HD_KPASS o, d, HD_REF(t1));
    int geo = 0;
    float td = hdk_depth_t(HD_KPASS px, py, fx, fy, sx, sy, o, d, HD_REF(geo));
    int max_vertices = HD_PRM(counts).w, mode = HD_PRM(counts).y;
    float albedo = HD_PRM(medium).y, g = HD_PRM(medium).z;
    float lr = 0.0f, lg = 0.0f, lb = 0.0f, alpha = 0.0f;
    float wr = 1.0f, wg = 1.0f, wb = 1.0f;
    float pphase = 0.0f; /* the phase function's density of d, once d is a scattered direction */
    hd_u32 dim = 2u;
    int vertices = 0;
    hd_v3 p = hdk_madd(o, d, t0);
    float tmax = t1 - t0;
    if (!(t0 < t1)) { /* misses the box */
        if (geo == 0) {
            hd_v3 bk = hdk_env_background(HD_KPASS d);
            lr = bk.x; lg = bk.y; lb = bk.z;
        }
        tmax = 0.0f;
    } else if (geo != 0) { /* the first free flight ends at the scene's surface */
        tmax = hdk_maxf(hdk_minf(tmax, td - t0), 0.0f);
    }
    while (tmax > 0.0f) {
        hd_u32 nd = 0u;
        float t = hdk_free_flight(HD_KPASS p, d, tmax, key, dim, HD_REF(nd));
        hd_v4 c;
        int l;
        float lt = 0.0f, lpdf = 0.0f, lprob = 1.0f, tr, f, ph, xe0 = 0.0f, xe1 = 0.0f;
        hd_v3 ld, lw = HD_V3(0.0f, 0.0f, 0.0f);
        dim = nd;
        if (!(t < tmax)) {
            if (vertices == 0 && geo == 0) {
                hd_v3 bk = hdk_env_background(HD_KPASS d);
                lr = bk.x; lg = bk.y; lb = bk.z;
            }
            if (vertices > 0 && HD_PRM(env).x > 0) { /* a scattered ray that leaves sees the environment */
                float st = 0.0f;
                int et = hdk_env_texel(HD_KPASS d, HD_REF(st));
                float q = hdk_env_pdf(HD_KPASS et, st) * hdk_env_chance(HD_KPASS HD_PRM(counts).x);
                hd_v3 le = hdk_env_rgb(HD_KPASS et);
                float m = pphase / (pphase + q);
                lr += wr * m * hdk_light_colour(HD_KPASS le, 0);
                lg += wg * m * hdk_light_colour(HD_KPASS le, 1);
                lb += wb * m * hdk_light_colour(HD_KPASS le, 2);
            }
            break;
        }
        alpha = 1.0f;
        p = hdk_madd(p, d, t);
        c = hdk_tf(HD_KPASS hdk_sample_value(HD_KPASS hdk_world_to_tex(HD_KPASS p)));
        wr *= albedo * c.x; wg *= albedo * c.y; wb *= albedo * c.z;
        if (vertices + 1 == HD_PRM(image).w) { /* the path ends into HD's light */
            hd_v3 u = hdk_world_to_tex(HD_KPASS p);
            lr += wr * hdk_cache_rgb(HD_KPASS u, 0);
            lg += wg * hdk_cache_rgb(HD_KPASS u, 1);
            lb += wb * hdk_cache_rgb(HD_KPASS u, 2);
            break;
        }
        /* next-event estimation toward one light */
        l = hdk_light_choose(HD_KPASS hdk_rand(key, dim), HD_REF(lprob));
        dim += 1u;
        if (l >= HD_PRM(counts).x || HD_PRM(light_a)[hdk_mini(l, HD_MAX_LIGHTS - 1)].w > 1.5f) { /* the environment, an area light */
            xe0 = hdk_rand(key, dim); xe1 = hdk_rand(key, dim + 1u); dim += 2u;
        }
        ld = hdk_light_pick(HD_KPASS l, p, xe0, xe1, HD_REF(lt), HD_REF(lw), HD_REF(lpdf));
        tr = hdk_transmittance(HD_KPASS p, ld, lt, key, dim, mode, HD_REF(nd));
        dim = nd;
        ph = hdk_phase_hg(g, hdk_dot(d, ld));
        f = tr * ph / lprob;
        /* the environment's share of a direction a scattered ray may also reach */
        if (lpdf > 0.0f && vertices + 1 < max_vertices) f *= lprob * lpdf / (lprob * lpdf + ph);
        lr += wr * f * hdk_light_colour(HD_KPASS lw, 0);
        lg += wg * f * hdk_light_colour(HD_KPASS lw, 1);
        lb += wb * f * hdk_light_colour(HD_KPASS lw, 2);
        vertices += 1;
        if (vertices >= max_vertices) break;
        if (vertices >= HD_PT_RR_BOUNCES) {
            float q = hdk_minf(hdk_maxf(wr, hdk_maxf(wg, wb)), 0.95f);
            float xi = hdk_rand(key, dim);
            dim += 1u;
            if (!(xi < q)) break;
            wr /= q; wg /= q; wb /= q;
        }
        {
            hd_v3 dn = hdk_sample_phase_hg(d, g, hdk_rand(key, dim), hdk_rand(key, dim + 1u));
            pphase = hdk_phase_hg(g, hdk_dot(d, dn));
            d = dn;
        }
        dim += 2u;
        tmax = hdk_box_exit(HD_KPASS p, d);
    }
    if (geo == 0 && HD_PRM(background).w > 0.5f) alpha = 1.0f; /* the environment fills the pixel */
    if (HD_PRM(region).w > 0) hdk_blend_accumulate(HD_KPASS i, HD_V4(lr, lg, lb, alpha));
    else hdk_accumulate_pixel(HD_KPASS i, HD_V4(lr, lg, lb, alpha));
}
