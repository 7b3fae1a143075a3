/* hdbench_sweep.comp - GLSL 4.50: variants of the diffusion update's memory access, for
   `hdbench_vulkan --variants` (bench/hdbench_vulkan.c) to measure what lavapipe's cost of the
   library's sweep is made of. Every variant is one red-black half-sweep (push constant ctl.x the
   parity, invocation x relaxes voxel 2x + ((y + z + parity) & 1)) of the box-boundary grey update
   of backends/kernels/hd_k_diffuse.h, with constant albedo a and g:
       phi_i = (a st_i E_i + sum_j w_j phi_j) / ((1 - a) st_i + sum_j w_j),
       w_j = 0.6666667 / max(sp_i + sp_j, fl),  sp = (1 - a g) st.
   Compiled by `scripts/build-spirv --bench` once per variant (HD_SV = the variant, LX x LY the
   work group, ZK voxels per invocation along z, ZRT 1: ZK passed at run time, ctl.y):
     1 LIB    r32f storage images st, E, phi: 13 loads (the library's form)
     2 NODIV  as LIB with the 7 divisions replaced by multiplications (what the divisions cost)
     3 PACK   rg32f storage image (st, phi) + E: 7 rg loads + 1 (the voxel and its 6 neighbours
              each one texel); one imageLoad per texel in the source
     4 PACK2  as PACK, but sigma and phi of a texel read by two imageLoad calls (the shape the
              shared kernel's separate HD_GET(sig) / HD_GET(phi) would give): does the compiler
              merge them?
     5 TEX    st and E through sampled images (texelFetch), phi through the storage image
     6 TEXALL st, E and phi through sampled images, phi written through the storage image
     7 SHARED LIB with the x-neighbours' st and phi from a shared-memory row tile
     8 LOADS13 no arithmetic beyond a sum: 13 r32f loads and a store (the loads' cost alone)
     9 LOADS7  the same with the plain stencil's 7 loads (its red-black twin)
    10 STORE   no load: the store and the invocation's own cost
    11 LOADS1  one load and the store
    12 LIBLS   LIB, XK x YK x ZK voxels (same-colour voxels of a row x rows x slices) per
               invocation, all loads before all stores
    13 RB     the library's grey box update as it is now (hd_k_diffuse.h: hdk_diffuse_own_of, an
              axis' two faces over one division, hdk_diffuse_box_axis), r32f, 14 loads per voxel,
              ZK voxels per invocation along z: the reference the packed variants are checked
              against (`--check`), itself checked against the library's module
    14 PACKED x-packed texels: PK (4: rgba32f, 2: rg32f) x-consecutive voxels of st, E and phi
              per texel, the images nx / PK texels wide (the same bytes in the same order as the
              r32f grids). A half-sweep invocation relaxes a block of ZK slices x YK rows of one
              texel each: per texel its PK / 2 voxels of the half-sweep's colour (components
              o, o + 2 with o = (y + z + parity) & 1), their x-neighbours inside the texel except
              one, taken from the texel before (o = 0, component 3) or after (o = 1, component 0);
              the y- and z-neighbours are the same components of the adjacent rows' texels,
              loaded once per block as the library's hdk_diffuse_block does. The whole texel is
              stored back, the other colour's components as loaded (a half-sweep never writes
              them, so the value stored is the value there). Loads per invocation: 5 per row (st,
              phi, E, the side texel's st and phi) + 4 (YK + ZK) for the block's faces.
    15 PSTENCIL the plain stencil of hdbench_stencil.comp on rgba32f x-packed texels (4 voxels per
              invocation, 7 loads and 1 store per texel), Jacobi phi4 -> out4, one pass per step
    16 PCOPY  out4 = phi4 / 2 on rgba32f x-packed texels: 1 load and 1 store per 4 voxels (LOADS1's
              twin: what an rgba32f texel op costs against an r32f one)
    17 SGB    RB's update on a block of ZK slices x YK rows (one voxel of the half-sweep's colour per
              row, the library's hdk_diffuse_block shape) with the x-neighbours shared across lanes:
              lane l of a subgroup (64x1 work groups: consecutive x, the same rows) loads per row
              its voxel's st and E and the other colour's voxel of its x-pair (2l + 1 - o: st,
              phi), which is one x-neighbour; the other one is the next / previous lane's
              (subgroupShuffle, lane +- 1); the subgroup's edge lane takes its missing neighbour
              from one gather per block (lane i loads row i's edge texel, then subgroupShuffle
              from lane r), so a block of YK ZK <= gl_SubgroupSize rows makes 4 loads per row + 2
              + the faces' 4 (YK + ZK), against the library's 6 per row + the same faces. The y- /
              z-neighbour in the block is the adjacent row's x-pair partner (its colour
              alternates). Needs the subgroup basic + shuffle operations. PK 1: the neighbour by
              subgroupShuffleUp / Down (both made, one picked: the direction is the row's colour)
              (the edge by subgroupShuffle from lane r: subgroupBroadcast needs a literal lane),
              else (PK 4) subgroupShuffle from lane l +- 1; PK 2 as PK 4 without the edge
              gather (timing only, wrong values at the edges: what the 2 loads per block cost).
    18 SHUF   LOADS1 (one load and the store per voxel) with the loaded value passed through a
              subgroup operation before the store, PK selecting it (timing only, wrong values):
              0 none, 1 subgroupShuffleDown(v, 1), 2 subgroupShuffle(v, id + 1 + ctl.z) (an index
              the compiler cannot fold), 3 four subgroupShuffleDown in a row, 5 eight independent
              subgroupShuffleDown (of v + k, summed), 6 eight subgroupShuffle (of v + k, lane
              id + k + ctl.z): what one costs
   Bindings: 0 st, 1 E, 2 phi (r32f storage), 3 packed (st, phi) (rg32f storage), 4 st, 5 E,
   6 phi (sampler3D over the images of bindings 0-2), 7 st, 8 E, 9 phi, 10 out (rgba32f x-packed,
   nx / 4 wide), 11 st, 12 E, 13 phi (rg32f x-packed, nx / 2 wide). Push constants: dims, ctl
   (x parity, y run-time ZK), prm (xyz: 1 / h^2 per axis, w: the sigma' floor), med (x
   albedo, y anisotropy g): RB and PACKED take the library's parameters from them. */
#extension GL_EXT_control_flow_attributes : enable
#if HD_SV == 17 || HD_SV == 18
#extension GL_KHR_shader_subgroup_basic : enable
#extension GL_KHR_shader_subgroup_shuffle : enable
#extension GL_KHR_shader_subgroup_shuffle_relative : enable
#endif
layout(local_size_x = LX, local_size_y = LY, local_size_z = 1) in;
layout(push_constant) uniform hd_sweep_pc { ivec4 dims; ivec4 ctl; vec4 prm; vec4 med; };
layout(binding = 7, rgba32f) uniform image3D st4_i;
layout(binding = 8, rgba32f) uniform image3D e4_i;
layout(binding = 9, rgba32f) uniform image3D phi4_i;
layout(binding = 10, rgba32f) uniform image3D out4_i;
layout(binding = 11, rg32f) uniform image3D st2_i;
layout(binding = 12, rg32f) uniform image3D e2_i;
layout(binding = 13, rg32f) uniform image3D phi2_i;
#ifndef PK
#define PK 4
#endif
layout(binding = 0, r32f) uniform image3D st_i;
layout(binding = 1, r32f) uniform image3D e_i;
layout(binding = 2, r32f) uniform image3D phi_i;
layout(binding = 3, rg32f) uniform image3D pk_i;
layout(binding = 4) uniform sampler3D st_t;
layout(binding = 5) uniform sampler3D e_t;
layout(binding = 6) uniform sampler3D phi_t;

const float A = 0.9f, AG = 1.0f - 0.9f * 0.5f, FL = 1e-3f;

#if HD_SV == 5 || HD_SV == 6
#define ST(p) texelFetch(st_t, (p), 0).r
#define EE(p) texelFetch(e_t, (p), 0).r
#else
#define ST(p) imageLoad(st_i, (p)).r
#define EE(p) imageLoad(e_i, (p)).r
#endif
#if HD_SV == 6
#define PHI(p) texelFetch(phi_t, (p), 0).r
#else
#define PHI(p) imageLoad(phi_i, (p)).r
#endif
#if HD_SV == 2
#define DIV(a, b) ((a) * (b))
#else
#define DIV(a, b) ((a) / (b))
#endif

#if HD_SV == 7
shared float sh_st[2 * LX + 2];
shared float sh_phi[2 * LX + 2];
#endif

/* sigma' and phi of the neighbour at p (in the grid when in != 0) */
void nb(ivec3 p, bool in_grid, float spi, inout float num, inout float den)
{
#if HD_SV == 3
    vec2 t = imageLoad(pk_i, p).rg;
    float spj = in_grid ? AG * t.r : spi, ph = t.g;
#elif HD_SV == 4
    float spj = in_grid ? AG * imageLoad(pk_i, p).r : spi, ph = imageLoad(pk_i, p).g;
#else
    float spj = in_grid ? AG * ST(p) : spi, ph = PHI(p);
#endif
    float w = DIV(0.6666667f, max(spi + spj, FL));
    if (in_grid) num += w * ph;
    den += w;
}

void voxel(int x, int y, int z)
{
    int xv = 2 * x + ((y + z + ctl.x) & 1);
#if HD_SV == 7
    /* the row's voxels 2 * x0 - 1 ... 2 * (x0 + LX): each invocation loads two (its own pair),
       invocation 0 the one before; then the x-neighbours come from shared memory */
    int x0 = int(gl_WorkGroupID.x) * LX, l = int(gl_LocalInvocationID.x);
    if (y < dims.y && z < dims.z) {
        for (int k = 0; k < 2; ++k) {
            int xs = 2 * (x0 + l) + k;
            bool ok = xs < dims.x;
            sh_st[2 * l + k + 1] = ok ? imageLoad(st_i, ivec3(xs, y, z)).r : 0.0f;
            sh_phi[2 * l + k + 1] = ok ? imageLoad(phi_i, ivec3(xs, y, z)).r : 0.0f;
        }
        if (l == 0) {
            bool ok = x0 > 0;
            sh_st[0] = ok ? imageLoad(st_i, ivec3(2 * x0 - 1, y, z)).r : 0.0f;
            sh_phi[0] = ok ? imageLoad(phi_i, ivec3(2 * x0 - 1, y, z)).r : 0.0f;
        }
        if (l == LX - 1) {
            bool ok = 2 * (x0 + LX) < dims.x;
            sh_st[2 * LX + 1] = ok ? imageLoad(st_i, ivec3(2 * (x0 + LX), y, z)).r : 0.0f;
            sh_phi[2 * LX + 1] = ok ? imageLoad(phi_i, ivec3(2 * (x0 + LX), y, z)).r : 0.0f;
        }
    }
    barrier();
#endif
    if (xv >= dims.x || y >= dims.y || z >= dims.z) return;
    ivec3 p = ivec3(xv, y, z);
#if HD_SV == 10
    imageStore(phi_i, p, vec4(float(xv) * 0.01f, 0.0f, 0.0f, 0.0f));
#elif HD_SV == 11
    imageStore(phi_i, p, vec4(imageLoad(e_i, p).r * 0.5f, 0.0f, 0.0f, 0.0f));
#elif HD_SV == 9
    float s = imageLoad(e_i, p).r;
    s += imageLoad(phi_i, p + ivec3(-1, 0, 0)).r + imageLoad(phi_i, p + ivec3(1, 0, 0)).r;
    s += imageLoad(phi_i, p + ivec3(0, -1, 0)).r + imageLoad(phi_i, p + ivec3(0, 1, 0)).r;
    s += imageLoad(phi_i, p + ivec3(0, 0, -1)).r + imageLoad(phi_i, p + ivec3(0, 0, 1)).r;
    imageStore(phi_i, p, vec4(s * 0.14f, 0.0f, 0.0f, 0.0f));
#elif HD_SV == 8
    float s = imageLoad(st_i, p).r + imageLoad(e_i, p).r;
    s += imageLoad(st_i, p + ivec3(-1, 0, 0)).r + imageLoad(phi_i, p + ivec3(-1, 0, 0)).r;
    s += imageLoad(st_i, p + ivec3(1, 0, 0)).r + imageLoad(phi_i, p + ivec3(1, 0, 0)).r;
    s += imageLoad(st_i, p + ivec3(0, -1, 0)).r + imageLoad(phi_i, p + ivec3(0, -1, 0)).r;
    s += imageLoad(st_i, p + ivec3(0, 1, 0)).r + imageLoad(phi_i, p + ivec3(0, 1, 0)).r;
    s += imageLoad(st_i, p + ivec3(0, 0, -1)).r + imageLoad(phi_i, p + ivec3(0, 0, -1)).r;
    s += imageLoad(st_i, p + ivec3(0, 0, 1)).r + imageLoad(phi_i, p + ivec3(0, 0, 1)).r;
    imageStore(phi_i, p, vec4(s * 0.07f, 0.0f, 0.0f, 0.0f));
#else
#if HD_SV == 3 || HD_SV == 4
    float st = imageLoad(pk_i, p).r;
#elif HD_SV == 7
    float st = sh_st[xv - 2 * x0 + 1];
#else
    float st = ST(p);
#endif
    float spi = AG * st, num = A * st * EE(p), den = (1.0f - A) * st;
#if HD_SV == 7
    {
        int lx = xv - 2 * x0 + 1; /* the voxel's place in the tile */
        float spj = xv > 0 ? AG * sh_st[lx - 1] : spi;
        float w = 0.6666667f / max(spi + spj, FL);
        if (xv > 0) num += w * sh_phi[lx - 1];
        den += w;
        bool inx = xv < dims.x - 1;
        spj = inx ? AG * sh_st[lx + 1] : spi;
        w = 0.6666667f / max(spi + spj, FL);
        if (inx) num += w * sh_phi[lx + 1];
        den += w;
    }
#else
    nb(p + ivec3(-1, 0, 0), xv > 0, spi, num, den);
    nb(p + ivec3(1, 0, 0), xv < dims.x - 1, spi, num, den);
#endif
    nb(p + ivec3(0, -1, 0), y > 0, spi, num, den);
    nb(p + ivec3(0, 1, 0), y < dims.y - 1, spi, num, den);
    nb(p + ivec3(0, 0, -1), z > 0, spi, num, den);
    nb(p + ivec3(0, 0, 1), z < dims.z - 1, spi, num, den);
#if HD_SV == 3 || HD_SV == 4
    imageStore(pk_i, p, vec4(st, DIV(num, den), 0.0f, 0.0f));
#else
    imageStore(phi_i, p, vec4(DIV(num, den), 0.0f, 0.0f, 0.0f));
#endif
#endif
}

/* LIB's value at p (12 LIBLS) */
float lib_value(ivec3 p)
{
    float st = ST(p);
    float spi = AG * st, num = A * st * EE(p), den = (1.0f - A) * st;
    nb(p + ivec3(-1, 0, 0), p.x > 0, spi, num, den);
    nb(p + ivec3(1, 0, 0), p.x < dims.x - 1, spi, num, den);
    nb(p + ivec3(0, -1, 0), p.y > 0, spi, num, den);
    nb(p + ivec3(0, 1, 0), p.y < dims.y - 1, spi, num, den);
    nb(p + ivec3(0, 0, -1), p.z > 0, spi, num, den);
    nb(p + ivec3(0, 0, 1), p.z < dims.z - 1, spi, num, den);
    return num / den;
}

/* ---- 13 RB, 14 PACKED: the library's update (hd_k_diffuse.h, grey, box boundary, rhs off) ---- */
#ifndef YK
#define YK 1
#endif
/* hdk_diffuse_box_den */
float lib_den(float sp, float s, bool inside, float fl)
{
    return max(sp + (inside ? s : sp), fl);
}

/* hdk_diffuse_box_axis: an axis' two faces over one division */
void lib_axis(float a, float sp, float s0, float s1, float p0, float p1, bool in0, bool in1, float fl, inout float num,
              inout float dn)
{
    float d0 = lib_den(sp, s0, in0, fl), d1 = lib_den(sp, s1, in1, fl);
    float t = a / (d0 * d1);
    float q0 = in0 ? p0 * d1 : 0.0f, q1 = in1 ? p1 * d0 : 0.0f;
    num += t * (q0 + q1);
    dn += t * (d0 + d1);
}

/* hdk_diffuse_own_of + hdk_diffuse_box_of + the entry's division: the voxel's sigma_t st and E e,
   its neighbours' sigma_t s* and phi p* (x-, x+, y-, y+, z-, z+), whether each is in the grid */
float lib_update(float st, float e, float sxm, float sxp, float sym, float syp, float szm, float szp, float pxm,
                 float pxp, float pym, float pyp, float pzm, float pzp, bool ixm, bool ixp, bool iym, bool iyp,
                 bool izm, bool izp)
{
    float a = med.x, ag = 1.0f - a * med.y, fl = prm.w;
    float sp = st * ag, dn = (1.0f - a) * st, num = a * st * e;
    lib_axis(0.6666667f * prm.x, sp, ag * sxm, ag * sxp, pxm, pxp, ixm, ixp, fl, num, dn);
    lib_axis(0.6666667f * prm.y, sp, ag * sym, ag * syp, pym, pyp, iym, iyp, fl, num, dn);
    lib_axis(0.6666667f * prm.z, sp, ag * szm, ag * szp, pzm, pzp, izm, izp, fl, num, dn);
    return num / dn;
}

#if HD_SV == 13
/* 13 RB: ZK voxels of the half-sweep's colour along z, 14 loads each (coordinates clamped: an
   out-of-grid neighbour's value is dropped by its flag), all loads before all stores */
void rb_main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z0 = int(gl_GlobalInvocationID.z) * ZK;
    float v[ZK];
    [[unroll]] for (int k = 0; k < ZK; ++k) {
        int z = min(z0 + k, dims.z - 1), yc = min(y, dims.y - 1);
        int xv = min(2 * x + ((y + z0 + k + ctl.x) & 1), dims.x - 1);
        ivec3 p = ivec3(xv, yc, z);
        ivec3 xm = ivec3(max(xv - 1, 0), yc, z), xp = ivec3(min(xv + 1, dims.x - 1), yc, z);
        ivec3 ym = ivec3(xv, max(yc - 1, 0), z), yp = ivec3(xv, min(yc + 1, dims.y - 1), z);
        ivec3 zm = ivec3(xv, yc, max(z - 1, 0)), zp = ivec3(xv, yc, min(z + 1, dims.z - 1));
        v[k] = lib_update(imageLoad(st_i, p).r, imageLoad(e_i, p).r, imageLoad(st_i, xm).r, imageLoad(st_i, xp).r,
                          imageLoad(st_i, ym).r, imageLoad(st_i, yp).r, imageLoad(st_i, zm).r, imageLoad(st_i, zp).r,
                          imageLoad(phi_i, xm).r, imageLoad(phi_i, xp).r, imageLoad(phi_i, ym).r,
                          imageLoad(phi_i, yp).r, imageLoad(phi_i, zm).r, imageLoad(phi_i, zp).r, xv > 0,
                          xv < dims.x - 1, yc > 0, yc < dims.y - 1, z > 0, z < dims.z - 1);
    }
    [[unroll]] for (int k = 0; k < ZK; ++k) {
        int xv = 2 * x + ((y + z0 + k + ctl.x) & 1);
        if (xv < dims.x && y < dims.y && z0 + k < dims.z) imageStore(phi_i, ivec3(xv, y, z0 + k), vec4(v[k], 0.0f, 0.0f, 0.0f));
    }
}
#endif

#if HD_SV == 14
#if PK == 4
#define LDST(p) imageLoad(st4_i, (p))
#define LDE(p) imageLoad(e4_i, (p))
#define LDPHI(p) imageLoad(phi4_i, (p))
#define STPHI(p, v) imageStore(phi4_i, (p), (v))
#else
#define LDST(p) imageLoad(st2_i, (p))
#define LDE(p) imageLoad(e2_i, (p))
#define LDPHI(p) imageLoad(phi2_i, (p))
#define STPHI(p, v) imageStore(phi2_i, (p), (v))
#endif
#define NO (PK / 2) /* voxels of one colour per texel */
#define DB (YK * ZK)

/* Voxel n (0 .. NO - 1) of colour o in texel t: component 2 n + o. */
float own_c(vec4 t, int n, int o)
{
#if PK == 4
    return n == 0 ? (o != 0 ? t.y : t.x) : (o != 0 ? t.w : t.z);
#else
    return o != 0 ? t.y : t.x;
#endif
}

/* Its x - 1 neighbour: in the texel, or component PK - 1 of the texel before (side, o = 0). */
float xm_c(vec4 t, vec4 side, int n, int o)
{
#if PK == 4
    return n == 0 ? (o != 0 ? t.x : side.w) : (o != 0 ? t.z : t.y);
#else
    return o != 0 ? t.x : side.y;
#endif
}

/* Its x + 1 neighbour: in the texel, or component 0 of the texel after (side, o = 1). */
float xp_c(vec4 t, vec4 side, int n, int o)
{
#if PK == 4
    return n == 0 ? (o != 0 ? t.z : t.y) : (o != 0 ? side.x : t.w);
#else
    return o != 0 ? side.x : t.y;
#endif
}

/* Texel t with its colour-o voxels replaced by v0 (and v1). */
vec4 with_own(vec4 t, float v0, float v1, int o)
{
#if PK == 4
    return o != 0 ? vec4(t.x, v0, t.z, v1) : vec4(v0, t.y, v1, t.w);
#else
    return o != 0 ? vec4(t.x, v0, 0.0f, 0.0f) : vec4(v0, t.y, 0.0f, 0.0f);
#endif
}

void packed_main()
{
    int W = dims.x / PK, t = int(gl_GlobalInvocationID.x), tc = min(t, W - 1);
    int y0 = int(gl_GlobalInvocationID.y) * YK, z0 = int(gl_GlobalInvocationID.z) * ZK;
    /* per block row r = k YK + j: own texel's st, phi, E; the side texel's st and phi */
    vec4 S[DB], P[DB], E[DB], SS[DB], PS[DB];
    vec4 sym[ZK], pym[ZK], syp[ZK], pyp[ZK], szm[YK], pzm[YK], szp[YK], pzp[YK];
    float v[DB * NO];
    [[unroll]] for (int k = 0; k < ZK; ++k)
        [[unroll]] for (int j = 0; j < YK; ++j) {
            int r = k * YK + j, o = (y0 + j + z0 + k + ctl.x) & 1;
            int y = min(y0 + j, dims.y - 1), z = min(z0 + k, dims.z - 1), ts = clamp(tc - 1 + 2 * o, 0, W - 1);
            S[r] = LDST(ivec3(tc, y, z));
            P[r] = LDPHI(ivec3(tc, y, z));
            E[r] = LDE(ivec3(tc, y, z));
            SS[r] = LDST(ivec3(ts, y, z));
            PS[r] = LDPHI(ivec3(ts, y, z));
        }
    [[unroll]] for (int k = 0; k < ZK; ++k) {
        int z = min(z0 + k, dims.z - 1), ym = max(y0 - 1, 0), yp = min(y0 + YK, dims.y - 1);
        sym[k] = LDST(ivec3(tc, ym, z));
        pym[k] = LDPHI(ivec3(tc, ym, z));
        syp[k] = LDST(ivec3(tc, yp, z));
        pyp[k] = LDPHI(ivec3(tc, yp, z));
    }
    [[unroll]] for (int j = 0; j < YK; ++j) {
        int y = min(y0 + j, dims.y - 1), zm = max(z0 - 1, 0), zp = min(z0 + ZK, dims.z - 1);
        szm[j] = LDST(ivec3(tc, y, zm));
        pzm[j] = LDPHI(ivec3(tc, y, zm));
        szp[j] = LDST(ivec3(tc, y, zp));
        pzp[j] = LDPHI(ivec3(tc, y, zp));
    }
    [[unroll]] for (int k = 0; k < ZK; ++k)
        [[unroll]] for (int j = 0; j < YK; ++j) {
            int r = k * YK + j, o = (y0 + j + z0 + k + ctl.x) & 1, y = y0 + j, z = z0 + k;
            int rym = max(r - 1, 0), ryp = min(r + 1, DB - 1), rzm = max(r - YK, 0), rzp = min(r + YK, DB - 1);
            vec4 sa = j > 0 ? S[rym] : sym[k], sb = j < YK - 1 ? S[ryp] : syp[k];
            vec4 sc = k > 0 ? S[rzm] : szm[j], sd = k < ZK - 1 ? S[rzp] : szp[j];
            vec4 pa = j > 0 ? P[rym] : pym[k], pb = j < YK - 1 ? P[ryp] : pyp[k];
            vec4 pc = k > 0 ? P[rzm] : pzm[j], pd = k < ZK - 1 ? P[rzp] : pzp[j];
            [[unroll]] for (int n = 0; n < NO; ++n) {
                int x = PK * t + 2 * n + o;
                v[r * NO + n] = lib_update(own_c(S[r], n, o), own_c(E[r], n, o), xm_c(S[r], SS[r], n, o),
                                           xp_c(S[r], SS[r], n, o), own_c(sa, n, o), own_c(sb, n, o), own_c(sc, n, o),
                                           own_c(sd, n, o), xm_c(P[r], PS[r], n, o), xp_c(P[r], PS[r], n, o),
                                           own_c(pa, n, o), own_c(pb, n, o), own_c(pc, n, o), own_c(pd, n, o), x > 0,
                                           x < dims.x - 1, y > 0, y < dims.y - 1, z > 0, z < dims.z - 1);
            }
        }
    [[unroll]] for (int k = 0; k < ZK; ++k)
        [[unroll]] for (int j = 0; j < YK; ++j) {
            int r = k * YK + j, o = (y0 + j + z0 + k + ctl.x) & 1;
            if (t < W && y0 + j < dims.y && z0 + k < dims.z)
                STPHI(ivec3(t, y0 + j, z0 + k), with_own(P[r], v[r * NO], v[r * NO + NO - 1], o));
        }
}
#endif

#if HD_SV == 15
/* 15 PSTENCIL: b = (rhs + the 6 neighbours of a) / 7 for the 4 voxels of texel t, zero outside */
void pstencil_main()
{
    int W = dims.x / 4, t = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    if (t >= W || y >= dims.y || z >= dims.z) return;
    vec4 a = imageLoad(phi4_i, ivec3(t, y, z)), s = imageLoad(e4_i, ivec3(t, y, z));
    s += vec4(0.0f, a.x, a.y, a.z) + vec4(a.y, a.z, a.w, 0.0f);
    if (t > 0) s.x += imageLoad(phi4_i, ivec3(t - 1, y, z)).w;
    if (t < W - 1) s.w += imageLoad(phi4_i, ivec3(t + 1, y, z)).x;
    if (y > 0) s += imageLoad(phi4_i, ivec3(t, y - 1, z));
    if (y < dims.y - 1) s += imageLoad(phi4_i, ivec3(t, y + 1, z));
    if (z > 0) s += imageLoad(phi4_i, ivec3(t, y, z - 1));
    if (z < dims.z - 1) s += imageLoad(phi4_i, ivec3(t, y, z + 1));
    imageStore(out4_i, ivec3(t, y, z), s * (1.0f / 7.0f));
}
#endif

#if HD_SV == 17
/* 17 SGB: the block of ZK slices x YK rows, x-neighbours from the neighbouring lanes (above) */
#define DB (YK * ZK)
void sgb_main()
{
    int x = int(gl_GlobalInvocationID.x), y0 = int(gl_GlobalInvocationID.y) * YK, z0 = int(gl_GlobalInvocationID.z) * ZK;
    int sl = int(gl_SubgroupInvocationID), sn = int(gl_SubgroupSize), x0 = x - sl; /* the subgroup's first lane */
    int nx = dims.x;
    float S[DB], E[DB], BS[DB], BP[DB], v[DB];
    float sym[ZK], pym[ZK], syp[ZK], pyp[ZK], szm[YK], pzm[YK], szp[YK], pzp[YK];
    /* the edge gather: lane i loads row i's neighbour outside the subgroup (o = 0: voxel
       2 x0 - 1 left of lane 0's; o = 1: voxel 2 (x0 + sn) right of the last lane's) */
    float est, eph;
    {
        int r = min(sl, DB - 1), k = r / YK, j = r - k * YK, o = (y0 + j + z0 + k + ctl.x) & 1;
        int y = min(y0 + j, dims.y - 1), z = min(z0 + k, dims.z - 1);
        int xe = clamp(o != 0 ? 2 * (x0 + sn) : 2 * x0 - 1, 0, nx - 1);
#if PK == 2 /* timing only, wrong at the subgroups' edges: no edge gather */
        est = float(xe);
        eph = 0.0f;
#else
        est = imageLoad(st_i, ivec3(xe, y, z)).r;
        eph = imageLoad(phi_i, ivec3(xe, y, z)).r;
#endif
    }
    [[unroll]] for (int k = 0; k < ZK; ++k)
        [[unroll]] for (int j = 0; j < YK; ++j) {
            int r = k * YK + j, o = (y0 + j + z0 + k + ctl.x) & 1;
            int y = min(y0 + j, dims.y - 1), z = min(z0 + k, dims.z - 1);
            int xv = min(2 * x + o, nx - 1), xb = min(2 * x + 1 - o, nx - 1);
            S[r] = imageLoad(st_i, ivec3(xv, y, z)).r;
            E[r] = imageLoad(e_i, ivec3(xv, y, z)).r;
            BS[r] = imageLoad(st_i, ivec3(xb, y, z)).r;
            BP[r] = imageLoad(phi_i, ivec3(xb, y, z)).r;
        }
    [[unroll]] for (int k = 0; k < ZK; ++k) {
        int z = min(z0 + k, dims.z - 1), ym = max(y0 - 1, 0), yp = min(y0 + YK, dims.y - 1);
        int o0 = (y0 + z0 + k + ctl.x) & 1, o1 = (y0 + YK - 1 + z0 + k + ctl.x) & 1;
        int xa = min(2 * x + o0, nx - 1), xc = min(2 * x + o1, nx - 1);
        sym[k] = imageLoad(st_i, ivec3(xa, ym, z)).r;
        pym[k] = imageLoad(phi_i, ivec3(xa, ym, z)).r;
        syp[k] = imageLoad(st_i, ivec3(xc, yp, z)).r;
        pyp[k] = imageLoad(phi_i, ivec3(xc, yp, z)).r;
    }
    [[unroll]] for (int j = 0; j < YK; ++j) {
        int y = min(y0 + j, dims.y - 1), zm = max(z0 - 1, 0), zp = min(z0 + ZK, dims.z - 1);
        int o0 = (y0 + j + z0 + ctl.x) & 1, o1 = (y0 + j + z0 + ZK - 1 + ctl.x) & 1;
        int xa = min(2 * x + o0, nx - 1), xc = min(2 * x + o1, nx - 1);
        szm[j] = imageLoad(st_i, ivec3(xa, y, zm)).r;
        pzm[j] = imageLoad(phi_i, ivec3(xa, y, zm)).r;
        szp[j] = imageLoad(st_i, ivec3(xc, y, zp)).r;
        pzp[j] = imageLoad(phi_i, ivec3(xc, y, zp)).r;
    }
    [[unroll]] for (int k = 0; k < ZK; ++k)
        [[unroll]] for (int j = 0; j < YK; ++j) {
            int r = k * YK + j, o = (y0 + j + z0 + k + ctl.x) & 1, y = y0 + j, z = z0 + k;
            int xv = 2 * x + o, d = 2 * o - 1; /* the other x-neighbour is lane sl + d's partner */
            bool edge = sl + d < 0 || sl + d >= sn;
#if PK == 1 /* relative shuffles (both directions, one picked) and a broadcast from lane r */
            float su = subgroupShuffleUp(BS[r], 1u), sd_ = subgroupShuffleDown(BS[r], 1u);
            float pu = subgroupShuffleUp(BP[r], 1u), pd_ = subgroupShuffleDown(BP[r], 1u);
            float ns = o != 0 ? sd_ : su, np = o != 0 ? pd_ : pu;
            float es = subgroupShuffle(est, uint(r)), ep = subgroupShuffle(eph, uint(r));
#else
            float ns = subgroupShuffle(BS[r], uint(clamp(sl + d, 0, sn - 1)));
            float np = subgroupShuffle(BP[r], uint(clamp(sl + d, 0, sn - 1)));
            float es = subgroupShuffle(est, uint(r)), ep = subgroupShuffle(eph, uint(r));
#endif
            ns = edge ? es : ns;
            np = edge ? ep : np;
            /* x - 1 / x + 1: the partner is x + 1 for o = 0, x - 1 for o = 1 */
            float sxm = o != 0 ? BS[r] : ns, sxp = o != 0 ? ns : BS[r];
            float pxm = o != 0 ? BP[r] : np, pxp = o != 0 ? np : BP[r];
            /* y- / z-neighbours inside the block: the adjacent row's partner */
            int rym = max(r - 1, 0), ryp = min(r + 1, DB - 1), rzm = max(r - YK, 0), rzp = min(r + YK, DB - 1);
            float sa = j > 0 ? BS[rym] : sym[k], sb = j < YK - 1 ? BS[ryp] : syp[k];
            float sc = k > 0 ? BS[rzm] : szm[j], sd = k < ZK - 1 ? BS[rzp] : szp[j];
            float pa = j > 0 ? BP[rym] : pym[k], pb = j < YK - 1 ? BP[ryp] : pyp[k];
            float pc = k > 0 ? BP[rzm] : pzm[j], pd = k < ZK - 1 ? BP[rzp] : pzp[j];
            v[r] = lib_update(S[r], E[r], sxm, sxp, sa, sb, sc, sd, pxm, pxp, pa, pb, pc, pd, xv > 0, xv < nx - 1,
                              y > 0, y < dims.y - 1, z > 0, z < dims.z - 1);
        }
    [[unroll]] for (int k = 0; k < ZK; ++k)
        [[unroll]] for (int j = 0; j < YK; ++j) {
            int r = k * YK + j, xv = 2 * x + ((y0 + j + z0 + k + ctl.x) & 1);
            if (xv < nx && y0 + j < dims.y && z0 + k < dims.z)
                imageStore(phi_i, ivec3(xv, y0 + j, z0 + k), vec4(v[r], 0.0f, 0.0f, 0.0f));
        }
}
#endif

#if HD_SV == 18
/* 18 SHUF: LOADS1 with the value through PK's subgroup operation (timing only) */
void shuf_main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    int xv = min(2 * x + ((y + z + ctl.x) & 1), dims.x - 1);
    ivec3 p = ivec3(xv, min(y, dims.y - 1), min(z, dims.z - 1));
    float v = imageLoad(e_i, p).r;
#if PK == 1
    v = subgroupShuffleDown(v, 1u);
#elif PK == 2
    v = subgroupShuffle(v, (gl_SubgroupInvocationID + 1u + uint(ctl.z)) & (gl_SubgroupSize - 1u));
#elif PK == 3
    v = subgroupShuffleDown(v, 1u) + 0.5f;
    v = subgroupShuffleDown(v, 1u) + 0.5f;
    v = subgroupShuffleDown(v, 1u) + 0.5f;
    v = subgroupShuffleDown(v, 1u);
#elif PK == 5
    float w = 0.0f;
    [[unroll]] for (int k = 1; k <= 8; ++k) w += subgroupShuffleDown(v + float(k), 1u);
    v = w;
#elif PK == 6
    float w = 0.0f;
    [[unroll]] for (int k = 1; k <= 8; ++k)
        w += subgroupShuffle(v + float(k), (gl_SubgroupInvocationID + uint(k + ctl.z)) & (gl_SubgroupSize - 1u));
    v = w;
#endif
    if (y < dims.y && z < dims.z && 2 * x < dims.x) imageStore(phi_i, p, vec4(v * 0.5f, 0.0f, 0.0f, 0.0f));
}
#endif

/* ZK voxels per invocation along z (one per slice, each of this half-sweep's colour) */
void main()
{
#ifndef YK
#define YK 1
#endif
#ifndef XK
#define XK 1
#endif
#if HD_SV == 13
    rb_main();
    return;
#elif HD_SV == 14
    packed_main();
    return;
#elif HD_SV == 15
    pstencil_main();
    return;
#elif HD_SV == 17
    sgb_main();
    return;
#elif HD_SV == 18
    shuf_main();
    return;
#elif HD_SV == 16
    {
        ivec3 p = ivec3(gl_GlobalInvocationID);
        if (p.x < dims.x / 4 && p.y < dims.y && p.z < dims.z) imageStore(out4_i, p, imageLoad(phi4_i, p) * 0.5f);
    }
    return;
#endif
#if HD_SV == 12
    /* 12 LIBLS: the ZK voxels' loads and arithmetic first, then their stores, so that a texel two
       of them read (the black voxel between two red ones) may be loaded once */
    int x = int(gl_GlobalInvocationID.x), y0 = int(gl_GlobalInvocationID.y) * YK, z0 = int(gl_GlobalInvocationID.z) * ZK;
    float v[XK * YK * ZK];
    for (int i = 0; i < XK; ++i)
        for (int j = 0; j < YK; ++j)
            for (int k = 0; k < ZK; ++k)
                v[(i * YK + j) * ZK + k] = lib_value(ivec3(2 * (x * XK + i) + ((y0 + j + z0 + k + ctl.x) & 1), y0 + j, z0 + k));
    for (int i = 0; i < XK; ++i)
        for (int j = 0; j < YK; ++j)
            for (int k = 0; k < ZK; ++k) {
                ivec3 p = ivec3(2 * (x * XK + i) + ((y0 + j + z0 + k + ctl.x) & 1), y0 + j, z0 + k);
                if (p.x < dims.x && p.y < dims.y && p.z < dims.z)
                    imageStore(phi_i, p, vec4(v[(i * YK + j) * ZK + k], 0.0f, 0.0f, 0.0f));
            }
    return;
#endif
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y);
#if ZRT /* the count from the push constants: a loop the compiler cannot unroll */
    for (int k = 0; k < ctl.y; ++k) voxel(x, y, int(gl_GlobalInvocationID.z) * ctl.y + k);
#else
    for (int k = 0; k < ZK; ++k) voxel(x, y, int(gl_GlobalInvocationID.z) * ZK + k);
#endif
}
}
