/* hd_k_direct.h - stage 1 of HD: direct light per voxel by tracking toward one light (shared
   source). Every voxel of the illumination grid takes exactly one sample per iteration, so one
   count serves every voxel and no per-voxel counter is needed:
   E_n = E_{n-1} + (X_n - E_{n-1}) / n with X = I_l * T(x -> l) / P_l, l drawn among the lights
   (the list and the environment, hd_k_light.h) with chance P_l (hdk_light_choose); for the
   environment I_l is the map's radiance over the density of the direction drawn by importance,
   T tracked to the box's edge; for an area light the radiance over the density of a point of
   its area (or of its cone) as seen from x.
   The host gives 1 / n as march.w: n is the iteration count, or after a warm start (a change
   that keeps E as the start of the new light) the count capped at params.light_window, so the
   light before the change fades. */
HD_FN void hdk_direct_voxel(HD_KARGS int x, int y, int z)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int nch = HD_PRM(gdims).w;
    int i = (z * gy + y) * gx + x;
    int nvox = gx * gy * gz;
    hd_u32 key = hdk_rng_key(HD_U(i), HD_U(HD_PRM(frame).x), HD_U(HD_PRM(frame).z), HD_STREAM_DIRECT);
    /* The light is drawn per run of 8 voxels along x, not per voxel: still with the same
       chances for every voxel (unbiased), and SIMD lanes on a GPU (or in llvmpipe/PoCL) that
       walk toward the same light stay coherent. */
    hd_u32 lkey = hdk_rng_key(HD_U(i) >> 3u, HD_U(HD_PRM(frame).x), HD_U(HD_PRM(frame).z), HD_STREAM_LIGHT);
    float prob = 1.0f;
    int l = hdk_light_choose(HD_KPASS hdk_rand(lkey, 0u), HD_REF(prob));
    hd_v3 p = HD_V3(((HD_F(x) + 0.5f) / HD_F(gx) - 0.5f) * HD_PRM(box).x,
                    ((HD_F(y) + 0.5f) / HD_F(gy) - 0.5f) * HD_PRM(box).y,
                    ((HD_F(z) + 0.5f) / HD_F(gz) - 0.5f) * HD_PRM(box).z);
    float tmax = 0.0f, pdf = 0.0f, T, w;
    hd_u32 next_dim = 0u;
    hd_u32 ekey = hdk_rng_key(HD_U(i), HD_U(HD_PRM(frame).x), HD_U(HD_PRM(frame).z), HD_STREAM_ENV);
    hd_v3 lw = HD_V3(0.0f, 0.0f, 0.0f);
    int c;
    hd_v3 d = hdk_light_pick(HD_KPASS l, p, hdk_rand(ekey, 0u), hdk_rand(ekey, 1u), HD_REF(tmax), HD_REF(lw), HD_REF(pdf));
    T = hdk_transmittance(HD_KPASS p, d, tmax, key, 1u, HD_PRM(counts).y, HD_REF(next_dim));
    w = HD_PRM(march).w;
    for (c = 0; c < nch; ++c) {
        int ic = i + c * nvox;
        float e = HD_GET(E, ic, x, y, z + c * gz);
        float sample_x = hdk_v3_at(lw, c) * T / prob;
        HD_SET(E, ic, x, y, z + c * gz, e + (sample_x - e) * w);
    }
}

/* The same at illumination-grid index i (x fastest): the dispatch over the list of voxels whose
   E is read (src/hd_direct_mask.h, hd__direct_mask). The random key stays the voxel's grid index, so a
   tracked voxel's E is bit-identical to tracking every voxel. */
HD_FN void hdk_direct_index(HD_KARGS int i)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y;
    int row = i / gx;
    hdk_direct_voxel(HD_KPASS i - row * gx, row % gy, row / gy);
}
