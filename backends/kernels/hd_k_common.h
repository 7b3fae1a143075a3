/* hd_k_common.h - shared kernel math: random numbers, the medium, tracking (shared source).
   Written in the subset C99, OpenCL C 1.2 and GLSL 4.30 all accept (see hd_prelude_c.h):
   no pointers (HD_INOUT instead), no recursion, no names that are keywords in one of them
   (sample, filter, local, global, half, ...), float literals with an f suffix. */

#define HD_FLAG_GLOBAL_MAJORANT 1
#define HD_FLAG_NO_DIFFUSION 2
#define HD_FLAG_RGB_SCATTERING 4 /* the sigma_t grid carries the TF colour in channels 1..3 */
#define HD_FLAG_SURFACE_BOUNDARY 8 /* diffusion: vacuum (Marshak) condition at the medium's surface */
#define HD_FLAG_DIFFUSE_RHS 16 /* diffusion: E holds the right-hand side itself (multigrid's coarse levels) */
#define HD_TRACK_RATIO 1
#define HD_TRACK_DELTA 2
/* Decorrelates the random streams of the stages that share a pixel or voxel index. */
#define HD_STREAM_DIRECT 0x68bc21ebu
#define HD_STREAM_PROJECT 0x02e5be93u
#define HD_STREAM_PATH 0x967a889bu
#define HD_STREAM_LIGHT 0x3c6ef372u
#define HD_INV_4PI 0.0795774715f
/* Ratio tracking stops by Russian roulette below this transmittance (unbiased). */
#define HD_RR_THRESHOLD 0.1f
/* Loop bounds, the same on every backend, so no input can hang a kernel (README "Guarantees").
   HD_MAX_TRACK_STEPS: collisions plus majorant cells of one hdk_track walk, so an iteration costs
   at most that per voxel (per path vertex for the path tracers). A walk expects the majorant's
   optical depth along it (majorant * distance, <= 1.74 * majorant per world unit) plus the
   cells it crosses (<= 3 * 2048); the bound is reached only beyond about 3.8e4 per world unit
   (extinction, or a global majorant, which hd_create keeps within 16x the largest sigma_t), or
   where the free path no longer advances t. Such a walk is taken as absorbed: T = 0, and the
   collision at the current t.
   HD_MAX_MARCH_STEPS: samples of one projection ray. The chord is at most the diagonal and a
   step at least 0.01 voxel of at least 1 / HD_MAX_SPACING_RATIO (1.13e7 steps), so the bound
   (2^24, where step indices stay exact in float) never shortens a valid march. */
#define HD_MAX_TRACK_STEPS 65536
#define HD_MAX_MARCH_STEPS 16777216
#define HD_BOX_DIAGONAL 1.7320509f /* per unit of the box's largest side (gridh.w: times that side) */

/* ---- random numbers: a stateless hash of 32-bit integers, bit-identical everywhere -------- */
/* lowbias32 (C. Wellons): full avalanche with two multiplies. */
HD_FN hd_u32 hdk_hash(hd_u32 v)
{
    v ^= v >> 16;
    v *= 0x7feb352du;
    v ^= v >> 15;
    v *= 0x846ca68bu;
    v ^= v >> 16;
    return v;
}

/* The key of one voxel or pixel in one iteration of one stream. */
HD_FN hd_u32 hdk_rng_key(hd_u32 index, hd_u32 iteration, hd_u32 seed, hd_u32 stream)
{
    return hdk_hash(index ^ hdk_hash(iteration ^ hdk_hash(seed ^ stream)));
}

/* The dim-th uniform number in [0, 1) of a key: 24 bits, so the float is exact. */
HD_FN float hdk_rand(hd_u32 key, hd_u32 dim)
{
    return HD_F(hdk_hash(key ^ (dim * 0x9e3779b9u)) >> 8u) * (1.0f / 16777216.0f);
}

/* ---- the medium ---------------------------------------------------------------------------- */
/* Texture coordinate in [0,1]^3 of a world position (the box is centred at the origin). */
HD_FN hd_v3 hdk_world_to_tex(HD_KARGS hd_v3 p)
{
    return HD_V3(p.x / HD_PRM(box).x + 0.5f, p.y / HD_PRM(box).y + 0.5f, p.z / HD_PRM(box).z + 0.5f);
}

/* Linear-filter footprint along one axis, clamp to edge (as a GPU sampler does): the lower texel
   is returned, the weight of the upper one goes to HD_INOUT w. */
HD_FN int hdk_lerp_axis(float u, int n, HD_INOUT(float) w)
{
    float f = hdk_clampf(u * HD_F(n) - 0.5f, 0.0f, HD_F(n - 1));
    int i0 = hdk_mini(HD_I(f), hdk_maxi(n - 2, 0));
    HD_DEREF(w) = f - HD_F(i0);
    return i0;
}

/* The volume's storage (HD_VOL_*, hd_k_params.h): a constant where the backend fixes it when it
   builds its kernels (GL, Vulkan), else the parameter block's. */
#ifndef HD_VOL_STORE
#define HD_VOL_STORE HD_PRM(vstore).x
#endif

/* The normalised value of voxel (x, y, z), index i (x fastest). An F32 volume holds it; the
   integer storages hold the raw voxel (HD_VOL_RAW, the prelude's load), mapped here exactly as the
   core maps an F32 volume's voxels, so an integer volume and the same values given as F32 render
   alike (docs/DESIGN-STORAGE.md). */
HD_FN float hdk_voxel(HD_KARGS int i, int x, int y, int z)
{
    if (HD_VOL_STORE == HD_VOL_F32) return HD_VOL_RAW(i, x, y, z, HD_VOL_F32);
    return hdk_clampf((HD_VOL_RAW(i, x, y, z, HD_VOL_STORE) - HD_PRM(vnorm).x) * HD_PRM(vnorm).y, 0.0f, 1.0f);
}

/* Trilinear interpolation of the normalised volume at texture coordinate u: of the 8 voxels'
   normalised values, so that it does not depend on how the volume is stored. */
HD_FN float hdk_sample_value(HD_KARGS hd_v3 u)
{
    int nx = HD_PRM(dims).x, ny = HD_PRM(dims).y, nz = HD_PRM(dims).z;
    float wx = 0.0f, wy = 0.0f, wz = 0.0f;
    int x0 = hdk_lerp_axis(u.x, nx, HD_REF(wx));
    int y0 = hdk_lerp_axis(u.y, ny, HD_REF(wy));
    int z0 = hdk_lerp_axis(u.z, nz, HD_REF(wz));
    int x1 = hdk_mini(x0 + 1, nx - 1), y1 = hdk_mini(y0 + 1, ny - 1), z1 = hdk_mini(z0 + 1, nz - 1);
    int r00 = (z0 * ny + y0) * nx, r10 = (z0 * ny + y1) * nx;
    int r01 = (z1 * ny + y0) * nx, r11 = (z1 * ny + y1) * nx;
    float v000 = hdk_voxel(HD_KPASS r00 + x0, x0, y0, z0), v100 = hdk_voxel(HD_KPASS r00 + x1, x1, y0, z0);
    float v010 = hdk_voxel(HD_KPASS r10 + x0, x0, y1, z0), v110 = hdk_voxel(HD_KPASS r10 + x1, x1, y1, z0);
    float v001 = hdk_voxel(HD_KPASS r01 + x0, x0, y0, z1), v101 = hdk_voxel(HD_KPASS r01 + x1, x1, y0, z1);
    float v011 = hdk_voxel(HD_KPASS r11 + x0, x0, y1, z1), v111 = hdk_voxel(HD_KPASS r11 + x1, x1, y1, z1);
    float c00 = v000 + wx * (v100 - v000);
    float c10 = v010 + wx * (v110 - v010);
    float c01 = v001 + wx * (v101 - v001);
    float c11 = v011 + wx * (v111 - v011);
    float c0 = c00 + wy * (c10 - c00);
    float c1 = c01 + wy * (c11 - c01);
    return c0 + wz * (c1 - c0);
}

/* A table of n rgba entries, entry i at value i / (n - 1) (the TF, the projection's step table):
   the first float of the segment value v falls in (v clamped to 0..1), and v's place f in it.
   HD_TABLE_LERP(buf, a, f, k) is channel k of that segment's entries interpolated by f. */
HD_FN int hdk_table_segment(float v, int n, HD_INOUT(float) f)
{
    float t = hdk_clampf(v, 0.0f, 1.0f) * HD_F(n - 1);
    int i = hdk_mini(HD_I(t), n - 2);
    HD_DEREF(f) = t - HD_F(i);
    return i * 4;
}
#define HD_TABLE_LERP(buf, a, f, k) (HD_GET1(buf, (a) + (k)) + (f) * (HD_GET1(buf, (a) + (k) + 4) - HD_GET1(buf, (a) + (k))))

/* The transfer function: entries at i/(count-1), linearly interpolated; rgba. */
HD_FN hd_v4 hdk_tf(HD_KARGS float v)
{
    float f = 0.0f;
    int a = hdk_table_segment(v, HD_PRM(dims).w, HD_REF(f));
    return HD_V4(HD_TABLE_LERP(tf, a, f, 0), HD_TABLE_LERP(tf, a, f, 1), HD_TABLE_LERP(tf, a, f, 2), HD_TABLE_LERP(tf, a, f, 3));
}

/* 1 inside the crop box (params.crop_min/max), 0 outside, where matter is absent; crop_lo.w = 0
   (a zeroed parameter block) is no crop box. */
HD_FN int hdk_in_crop(HD_KARGS hd_v3 u)
{
    if (HD_PRM(crop_lo).w == 0.0f) return 1;
    return (u.x >= HD_PRM(crop_lo).x && u.x <= HD_PRM(crop_hi).x && u.y >= HD_PRM(crop_lo).y &&
            u.y <= HD_PRM(crop_hi).y && u.z >= HD_PRM(crop_lo).z && u.z <= HD_PRM(crop_hi).z) ? 1 : 0;
}

/* Extinction at a texture coordinate: 0 outside the crop box. */
HD_FN float hdk_sigma_t(HD_KARGS hd_v3 u)
{
    if (hdk_in_crop(HD_KPASS u) == 0) return 0.0f;
    return hdk_tf(HD_KPASS hdk_sample_value(HD_KPASS u)).w * HD_PRM(medium).x;
}

/* Distance from p (inside the box) along unit d to where it leaves the box. */
HD_FN float hdk_box_exit(HD_KARGS hd_v3 p, hd_v3 d)
{
    float hx = 0.5f * HD_PRM(box).x, hy = 0.5f * HD_PRM(box).y, hz = 0.5f * HD_PRM(box).z;
    float t = 3.0e38f;
    if (d.x > 0.0f) t = hdk_minf(t, (hx - p.x) / d.x);
    if (d.x < 0.0f) t = hdk_minf(t, (-hx - p.x) / d.x);
    if (d.y > 0.0f) t = hdk_minf(t, (hy - p.y) / d.y);
    if (d.y < 0.0f) t = hdk_minf(t, (-hy - p.y) / d.y);
    if (d.z > 0.0f) t = hdk_minf(t, (hz - p.z) / d.z);
    if (d.z < 0.0f) t = hdk_minf(t, (-hz - p.z) / d.z);
    return hdk_maxf(t, 0.0f);
}

/* Entry and exit distances of the ray o + t d through the box (entry > exit: a miss). */
HD_FN float hdk_box_entry(HD_KARGS hd_v3 o, hd_v3 d, HD_INOUT(float) t_exit)
{
    float t0 = 0.0f, t1 = 3.0e38f;
    float hx = 0.5f * HD_PRM(box).x, hy = 0.5f * HD_PRM(box).y, hz = 0.5f * HD_PRM(box).z;
    float ia, ta, tb;
    ia = 1.0f / d.x; ta = (-hx - o.x) * ia; tb = (hx - o.x) * ia;
    t0 = hdk_maxf(t0, hdk_minf(ta, tb)); t1 = hdk_minf(t1, hdk_maxf(ta, tb));
    ia = 1.0f / d.y; ta = (-hy - o.y) * ia; tb = (hy - o.y) * ia;
    t0 = hdk_maxf(t0, hdk_minf(ta, tb)); t1 = hdk_minf(t1, hdk_maxf(ta, tb));
    ia = 1.0f / d.z; ta = (-hz - o.z) * ia; tb = (hz - o.z) * ia;
    t0 = hdk_maxf(t0, hdk_minf(ta, tb)); t1 = hdk_minf(t1, hdk_maxf(ta, tb));
    HD_DEREF(t_exit) = t1;
    return t0;
}

/* ---- the majorant grid's cell walk -------------------------------------------------------- */
/* A ray p + t d walked through the majorant grid (cells of mdims.w voxels) cell by cell, a 3D
   DDA: hdk_track's and the projection march's (hd_k_project.h) one setup and step, so both cross
   the same faces at the same t. */
HD_STRUCT(hd_cell_walk)
    int cx, cy, cz;   /* the current cell */
    int sx, sy, sz;   /* the step along each axis, +1 or -1 */
    float nx, ny, nz; /* t where the ray crosses the current cell's next face on each axis */
    float dx, dy, dz; /* t between two faces on each axis (3e38 on an axis the ray runs along) */
HD_STRUCT_END(hd_cell_walk)

/* floor(v) as a cell index clamped to 0..n-1, clamped as a float first: v may be far outside the
   grid (a camera ray that misses the box starts its walk, which takes no sample, at a far-off
   point), and converting such a float (or NaN, which gives 0) to int is undefined in C. */
HD_FN int hdk_cell_of(float v, int n)
{
    float f = hdk_floor(v);
    return f >= 0.0f ? (f < HD_F(n - 1) ? HD_I(f) : n - 1) : 0;
}

/* The walk of p + t d (p in world coordinates, inside the box or on it for a walk that samples)
   from t = 0: the ray in cell coordinates is g(t) = g0 + t gd, its first cell g0's, clamped into
   the grid. */
HD_FN hd_cell_walk hdk_cell_walk_begin(HD_KARGS hd_v3 p, hd_v3 d)
{
    hd_cell_walk w;
    float inf = 3.0e38f;
    float cell = HD_F(HD_PRM(mdims).w);
    hd_v3 cs = HD_V3(HD_F(HD_PRM(dims).x) / cell, HD_F(HD_PRM(dims).y) / cell, HD_F(HD_PRM(dims).z) / cell);
    hd_v3 g0 = hdk_vmul(hdk_world_to_tex(HD_KPASS p), cs);
    hd_v3 gd = hdk_vmul(HD_V3(d.x / HD_PRM(box).x, d.y / HD_PRM(box).y, d.z / HD_PRM(box).z), cs);
    w.cx = hdk_cell_of(g0.x, HD_PRM(mdims).x);
    w.cy = hdk_cell_of(g0.y, HD_PRM(mdims).y);
    w.cz = hdk_cell_of(g0.z, HD_PRM(mdims).z);
    w.sx = gd.x > 0.0f ? 1 : -1;
    w.sy = gd.y > 0.0f ? 1 : -1;
    w.sz = gd.z > 0.0f ? 1 : -1;
    w.nx = gd.x != 0.0f ? (HD_F(w.cx + (w.sx > 0 ? 1 : 0)) - g0.x) / gd.x : inf;
    w.ny = gd.y != 0.0f ? (HD_F(w.cy + (w.sy > 0 ? 1 : 0)) - g0.y) / gd.y : inf;
    w.nz = gd.z != 0.0f ? (HD_F(w.cz + (w.sz > 0 ? 1 : 0)) - g0.z) / gd.z : inf;
    w.dx = gd.x != 0.0f ? hdk_absf(1.0f / gd.x) : inf;
    w.dy = gd.y != 0.0f ? hdk_absf(1.0f / gd.y) : inf;
    w.dz = gd.z != 0.0f ? hdk_absf(1.0f / gd.z) : inf;
    return w;
}

/* The axis (0: x, 1: y, 2: z) whose face the ray crosses first when it leaves the current cell. */
HD_FN int hdk_cell_walk_axis(hd_cell_walk w)
{
    return w.nx <= w.ny && w.nx <= w.nz ? 0 : (w.ny <= w.nz ? 1 : 2);
}

/* Where (t) the ray leaves the current cell across axis ax's face. */
HD_FN float hdk_cell_walk_exit(hd_cell_walk w, int ax)
{
    return ax == 0 ? w.nx : (ax == 1 ? w.ny : w.nz);
}

/* 1 when stepping across axis ax's face leaves the grid of md (mdims) cells, else 0. */
HD_FN int hdk_cell_walk_leaves(hd_cell_walk w, int ax, hd_i4 md)
{
    int next = ax == 0 ? w.cx + w.sx : (ax == 1 ? w.cy + w.sy : w.cz + w.sz);
    return next < 0 || next >= (ax == 0 ? md.x : (ax == 1 ? md.y : md.z)) ? 1 : 0;
}

/* Steps into the neighbouring cell across axis ax's face. */
HD_FN void hdk_cell_walk_step(HD_INOUT(hd_cell_walk) w, int ax)
{
    if (ax == 0) { HD_DEREF(w).cx += HD_DEREF(w).sx; HD_DEREF(w).nx += HD_DEREF(w).dx; }
    else if (ax == 1) { HD_DEREF(w).cy += HD_DEREF(w).sy; HD_DEREF(w).ny += HD_DEREF(w).dy; }
    else { HD_DEREF(w).cz += HD_DEREF(w).sz; HD_DEREF(w).nz += HD_DEREF(w).dz; }
}

/* Where (t) the ray leaves the current cell, axis ax's face first, or len where the walk ends
   there: the cell is the grid's last along the ray, or reaches past len. */
HD_FN float hdk_cell_walk_end(hd_cell_walk w, int ax, hd_i4 md, float len)
{
    float sn = hdk_cell_walk_exit(w, ax);
    return hdk_cell_walk_leaves(w, ax, md) != 0 || !(sn < len) ? len : sn;
}

/* The current cell's index in the majorant grid of md (mdims) cells, x fastest. */
HD_FN int hdk_cell_walk_index(hd_cell_walk w, hd_i4 md)
{
    return (w.cz * md.y + w.cy) * md.x + w.cx;
}

/* ---- transmittance tracking --------------------------------------------------------------- */
/* A tentative collision at p + t d in a cell of majorant 1 / inv_mu: HD_TRACK_DELTA ends the ray
   there (T = 0, *hit = t) with probability sigma_t / mu; HD_TRACK_RATIO weighs T by
   1 - sigma_t / mu, with Russian roulette below HD_RR_THRESHOLD. Takes the dims it draws from
   *dim; returns 1 when the ray ended. hdk_track's and hdk_track_rounds' one collision. */
HD_FN int hdk_track_collide(HD_KARGS hd_v3 p, hd_v3 d, float t, float inv_mu, int mode, hd_u32 key,
                           HD_INOUT(hd_u32) dim, HD_INOUT(float) T, HD_INOUT(float) hit)
{
    float sig = hdk_sigma_t(HD_KPASS hdk_world_to_tex(HD_KPASS hdk_madd(p, d, t)));
    float ratio = hdk_minf(sig * inv_mu, 1.0f);
    int done = 0;
    if (mode == HD_TRACK_DELTA) {
        if (hdk_rand(key, HD_DEREF(dim)) < ratio) { HD_DEREF(T) = 0.0f; done = 1; HD_DEREF(hit) = t; }
        HD_DEREF(dim) += 1u;
    } else {
        HD_DEREF(T) *= 1.0f - ratio;
        if (HD_DEREF(T) < HD_RR_THRESHOLD) {
            /* survive with probability T / threshold, then weigh by its inverse */
            if (hdk_rand(key, HD_DEREF(dim)) * HD_RR_THRESHOLD >= HD_DEREF(T)) { HD_DEREF(T) = 0.0f; done = 1; }
            else HD_DEREF(T) = HD_RR_THRESHOLD;
            HD_DEREF(dim) += 1u;
        }
    }
    return done;
}

/* One unbiased estimate of the transmittance along p + t d, t in [0, tmax] (p inside the box,
   d unit). Null-collision tracking with a local majorant per cell of the majorant grid, walked
   cell by cell (a 3D DDA), so empty cells cost no collision at all. The free path is drawn as an
   optical depth tau ~ Exp(1) and spent cell by cell (mu * length): a collision where it runs out,
   the same distribution as a fresh exponential per cell, with one draw per collision. mode: HD_TRACK_RATIO (ratio
   tracking, Russian roulette below HD_RR_THRESHOLD) or HD_TRACK_DELTA (0 or 1).
   Random numbers: dims dim0, dim0 + 1, ... of key; returns the next unused dim in *next_dim.
   hdk_track is the shared walker: with HD_TRACK_DELTA it also reports in *t_hit the distance of
   the real collision that ended the walk (tmax when the ray got through), which makes it the
   free-flight sampler of the path tracers (hdk_free_flight); hdk_transmittance wraps it.
   At most HD_MAX_TRACK_STEPS collisions and cells; a walk that reaches it returns T = 0. */
HD_FN float hdk_track(HD_KARGS hd_v3 p, hd_v3 d, float tmax, hd_u32 key, hd_u32 dim0, int mode,
                     HD_INOUT(hd_u32) next_dim, HD_INOUT(float) t_hit)
{
    float T = 1.0f;
    float hit = tmax;
    hd_u32 dim = dim0;
    float t = 0.0f;
    float tau = -1.0f; /* optical depth to the next collision, drawn when first needed (< 0: none) */
    int done = 0;
    hd_cell_walk w = hdk_cell_walk_begin(HD_KPASS p, d);
    int global_majorant = (HD_PRM(counts).z & HD_FLAG_GLOBAL_MAJORANT) != 0 ? 1 : 0;
    int steps = 0; /* collisions and cells, at most HD_MAX_TRACK_STEPS */
    while (done == 0 && t < tmax) {
        int ax;
        float t_end = global_majorant != 0 ? tmax : hdk_minf(hdk_minf(w.nx, w.ny), hdk_minf(w.nz, tmax));
        float mu = global_majorant != 0 ? HD_PRM(medium).w
                 : HD_GET1(maj, hdk_cell_walk_index(w, HD_PRM(mdims)));
        if (mu > 0.0f) {
            float inv_mu = 1.0f / mu;
            for (;;) {
                float tc;
                if (tau < 0.0f) {
                    tau = -hdk_log(1.0f - hdk_rand(key, dim));
                    dim += 1u;
                }
                tc = t + tau * inv_mu;
                if (tc >= t_end) {
                    /* no collision in this cell: the optical depth left carries into the next */
                    tau = hdk_maxf(tau - (t_end - t) * mu, 0.0f);
                    break;
                }
                t = tc;
                tau = -1.0f;
                steps += 1;
                if (steps >= HD_MAX_TRACK_STEPS) { T = 0.0f; done = 1; hit = t; break; }
                done = hdk_track_collide(HD_KPASS p, d, t, inv_mu, mode, key, HD_REF(dim), HD_REF(T), HD_REF(hit));
                if (done != 0) break;
            }
        }
        if (done != 0) break;
        t = t_end;
        if (global_majorant != 0) break;
        steps += 1;
        if (steps >= HD_MAX_TRACK_STEPS) { T = 0.0f; hit = t; break; }
        /* step into the next cell along the axis whose boundary comes first, or leave the grid */
        ax = hdk_cell_walk_axis(w);
        if (hdk_cell_walk_leaves(w, ax, HD_PRM(mdims)) != 0) break;
        hdk_cell_walk_step(HD_REF(w), ax);
    }
    HD_DEREF(next_dim) = dim;
    HD_DEREF(t_hit) = hit;
    return T;
}

/* hdk_track for rays that run in SIMD lanes under a mask (llvmpipe, lavapipe: both sides of every
   branch run, a loop runs until every lane has left it): a walk cell by cell to the cell that
   holds the next collision (or to the end), then, while a lane has one, that collision and the
   next walk. hdk_track's inner loop pays a collision's sample in every non-empty cell, even where
   no lane collides; here a walk pays cell steps only and the loop one sample per collision of
   its busiest lane. The same cells, collisions, random dims and arithmetic as hdk_track, so the
   same T, *next_dim and *t_hit. The GLSL prelude picks it (HD_TRACK_ROUNDS). */
HD_STRUCT(hd_track_ray)
    hd_cell_walk w;
    float t;       /* where the ray is */
    float tau;     /* optical depth to the next collision (< 0: not drawn) */
    float tc;      /* the collision the walk found */
    float inv_mu;  /* 1 / its cell's majorant */
    hd_u32 dim;    /* the next random dim */
    hd_u32 pending; /* 1 while tau is drawn but its dim not yet counted */
    int steps;     /* collisions and cells, at most HD_MAX_TRACK_STEPS */
    int found;     /* the walk found a collision (at tc) */
    int done;      /* the walk ended: left the grid, reached tmax, or the step bound (T = 0) */
HD_STRUCT_END(hd_track_ray)

/* Draws the next free path where none is left, then walks to the cell that holds its collision.
   The draw's dim is counted on reaching a non-empty cell, where hdk_track draws it. */
HD_FN void hdk_track_walk(HD_KARGS HD_INOUT(hd_track_ray) r, float tmax, int global_majorant, HD_INOUT(float) T,
                         HD_INOUT(float) hit, hd_u32 key)
{
    HD_DEREF(r).found = 0;
    if (HD_DEREF(r).done == 0 && HD_DEREF(r).tau < 0.0f) {
        HD_DEREF(r).tau = -hdk_log(1.0f - hdk_rand(key, HD_DEREF(r).dim));
        HD_DEREF(r).pending = 1u;
    }
    while (HD_DEREF(r).done == 0 && HD_DEREF(r).found == 0) {
        float t_end, mu;
        if (HD_DEREF(r).t >= tmax) { HD_DEREF(r).done = 1; break; }
        t_end = global_majorant != 0 ? tmax : hdk_minf(hdk_minf(HD_DEREF(r).w.nx, HD_DEREF(r).w.ny), hdk_minf(HD_DEREF(r).w.nz, tmax));
        mu = global_majorant != 0 ? HD_PRM(medium).w : HD_GET1(maj, hdk_cell_walk_index(HD_DEREF(r).w, HD_PRM(mdims)));
        if (mu > 0.0f) {
            HD_DEREF(r).dim += HD_DEREF(r).pending;
            HD_DEREF(r).pending = 0u;
            HD_DEREF(r).inv_mu = 1.0f / mu;
            HD_DEREF(r).tc = HD_DEREF(r).t + HD_DEREF(r).tau * HD_DEREF(r).inv_mu;
            if (HD_DEREF(r).tc < t_end) HD_DEREF(r).found = 1;
            else HD_DEREF(r).tau = hdk_maxf(HD_DEREF(r).tau - (t_end - HD_DEREF(r).t) * mu, 0.0f); /* carries on */
        }
        if (HD_DEREF(r).found == 0) {
            HD_DEREF(r).t = t_end;
            if (global_majorant != 0) HD_DEREF(r).done = 1;
            else {
                int ax;
                HD_DEREF(r).steps += 1;
                if (HD_DEREF(r).steps >= HD_MAX_TRACK_STEPS) { HD_DEREF(T) = 0.0f; HD_DEREF(hit) = HD_DEREF(r).t; HD_DEREF(r).done = 1; }
                else {
                    ax = hdk_cell_walk_axis(HD_DEREF(r).w);
                    if (hdk_cell_walk_leaves(HD_DEREF(r).w, ax, HD_PRM(mdims)) != 0) HD_DEREF(r).done = 1;
                    else hdk_cell_walk_step(HD_REF(HD_DEREF(r).w), ax);
                }
            }
        }
    }
}

HD_FN float hdk_track_rounds(HD_KARGS hd_v3 p, hd_v3 d, float tmax, hd_u32 key, hd_u32 dim0, int mode,
                            HD_INOUT(hd_u32) next_dim, HD_INOUT(float) t_hit)
{
    float T = 1.0f;
    float hit = tmax;
    int global_majorant = (HD_PRM(counts).z & HD_FLAG_GLOBAL_MAJORANT) != 0 ? 1 : 0;
    hd_track_ray r;
    r.w = hdk_cell_walk_begin(HD_KPASS p, d);
    r.t = 0.0f; r.tau = -1.0f; r.tc = 0.0f; r.inv_mu = 1.0f;
    r.dim = dim0; r.pending = 0u;
    r.steps = 0; r.found = 0; r.done = 0;
    hdk_track_walk(HD_KPASS HD_REF(r), tmax, global_majorant, HD_REF(T), HD_REF(hit), key);
    while (r.found != 0) {
        r.t = r.tc;
        r.tau = -1.0f;
        r.steps += 1;
        if (r.steps >= HD_MAX_TRACK_STEPS) { T = 0.0f; r.done = 1; hit = r.t; }
        else r.done = hdk_track_collide(HD_KPASS p, d, r.t, r.inv_mu, mode, key, HD_REF(r.dim), HD_REF(T), HD_REF(hit));
        hdk_track_walk(HD_KPASS HD_REF(r), tmax, global_majorant, HD_REF(T), HD_REF(hit), key);
    }
    HD_DEREF(next_dim) = r.dim;
    HD_DEREF(t_hit) = hit;
    return T;
}

HD_FN float hdk_transmittance(HD_KARGS hd_v3 p, hd_v3 d, float tmax, hd_u32 key, hd_u32 dim0,
                             int mode, HD_INOUT(hd_u32) next_dim)
{
    float t_hit = 0.0f;
#ifdef HD_TRACK_ROUNDS
    return hdk_track_rounds(HD_KPASS p, d, tmax, key, dim0, mode, next_dim, HD_REF(t_hit));
#else
    return hdk_track(HD_KPASS p, d, tmax, key, dim0, mode, next_dim, HD_REF(t_hit));
#endif
}

/* Delta tracking to the first real collision along p + t d: its distance, or tmax when the ray
   gets through. Same random dims as hdk_transmittance in delta mode. */
HD_FN float hdk_free_flight(HD_KARGS hd_v3 p, hd_v3 d, float tmax, hd_u32 key, hd_u32 dim0,
                           HD_INOUT(hd_u32) next_dim)
{
    float t_hit = 0.0f;
#ifdef HD_TRACK_ROUNDS
    hdk_track_rounds(HD_KPASS p, d, tmax, key, dim0, HD_TRACK_DELTA, next_dim, HD_REF(t_hit));
#else
    hdk_track(HD_KPASS p, d, tmax, key, dim0, HD_TRACK_DELTA, next_dim, HD_REF(t_hit));
#endif
    return t_hit;
}

/* Direction toward light l from p, the distance to stop tracking at (light or box exit) and the
   light's falloff factor (1, or 1/r^2 for a point light that asks for it). */
HD_FN hd_v3 hdk_light_dir(HD_KARGS int l, hd_v3 p, HD_INOUT(float) tmax, HD_INOUT(float) falloff)
{
    hd_v4 la = HD_PRM(light_a)[l];
    hd_v3 d;
    HD_DEREF(falloff) = 1.0f;
    if (la.w < 0.5f) { /* directional: travels along la.xyz, so look back against it */
        d = HD_V3(-la.x, -la.y, -la.z);
        HD_DEREF(tmax) = hdk_box_exit(HD_KPASS p, d);
    } else {
        hd_v3 v = hdk_sub(HD_XYZ(la), p);
        float r2 = hdk_maxf(hdk_dot(v, v), 1.0e-12f);
        float r = hdk_sqrt(r2);
        d = hdk_scale(v, 1.0f / r);
        HD_DEREF(tmax) = hdk_minf(r, hdk_box_exit(HD_KPASS p, d));
        if (HD_PRM(light_b)[l].w > 0.5f) HD_DEREF(falloff) = 1.0f / r2;
    }
    return d;
}

/* Light l's radiance in channel c (1 channel: the scalar weight; the colour comes at projection). */
HD_FN float hdk_light_channel(HD_KARGS int l, int c)
{
    hd_v4 lb = HD_PRM(light_b)[l];
    return c == 0 ? lb.x : (c == 1 ? lb.y : lb.z);
}
