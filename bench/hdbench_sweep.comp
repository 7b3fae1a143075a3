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
   Bindings: 0 st, 1 E, 2 phi (r32f storage), 3 packed (st, phi) (rg32f storage), 4 st, 5 E,
   6 phi (sampler3D over the images of bindings 0-2). */
layout(local_size_x = LX, local_size_y = LY, local_size_z = 1) in;
layout(push_constant) uniform hd_sweep_pc { ivec4 dims; ivec4 ctl; };
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

/* ZK voxels per invocation along z (one per slice, each of this half-sweep's colour) */
void main()
{
#ifndef YK
#define YK 1
#endif
#ifndef XK
#define XK 1
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
