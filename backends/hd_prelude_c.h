/* hd_prelude_c.h - makes the shared kernel sources (backends/kernels/) valid C99 and C++.
   The kernels are written once in a subset that C99, OpenCL C 1.2 and GLSL 4.30 all accept;
   each prelude defines the few words that differ: function qualifiers, the vector types and their
   operations, casts, the math built-ins, and how a kernel reaches its parameters and buffers.
   The GPU preludes (hd_prelude_cl.h, hd_prelude_glsl.h) define the same names. */
#ifndef HD_PRELUDE_C_H
#define HD_PRELUDE_C_H
#include <math.h>
#include <stdint.h>
#include <string.h>

#define HD_FN static inline
#define HD_LANG_C 1

typedef uint32_t hd_u32;
typedef struct hd_v3 { float x, y, z; } hd_v3;
typedef struct hd_v4 { float x, y, z, w; } hd_v4;
typedef struct hd_i4 { int32_t x, y, z, w; } hd_i4;
typedef hd_v4 hd_f4; /* the parameter block's vectors are the kernels' vec4 */

/* Casts: GLSL spells them as constructors. */
#define HD_F(v) ((float)(v))
#define HD_I(v) ((int)(v))
#define HD_U(v) ((hd_u32)(v))

HD_FN hd_v3 hdk_v3_make(float x, float y, float z) { hd_v3 r; r.x = x; r.y = y; r.z = z; return r; }
HD_FN hd_v4 hdk_v4_make(float x, float y, float z, float w)
{
    hd_v4 r; r.x = x; r.y = y; r.z = z; r.w = w; return r;
}
#define HD_V3(x, y, z) hdk_v3_make((x), (y), (z))
#define HD_V4(x, y, z, w) hdk_v4_make((x), (y), (z), (w))
#define HD_XYZ(v4) hdk_v3_make((v4).x, (v4).y, (v4).z)
HD_FN hd_v3 hdk_add(hd_v3 a, hd_v3 b) { return hdk_v3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
HD_FN hd_v3 hdk_sub(hd_v3 a, hd_v3 b) { return hdk_v3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
HD_FN hd_v3 hdk_scale(hd_v3 a, float s) { return hdk_v3_make(a.x * s, a.y * s, a.z * s); }
HD_FN hd_v3 hdk_vmul(hd_v3 a, hd_v3 b) { return hdk_v3_make(a.x * b.x, a.y * b.y, a.z * b.z); }
HD_FN hd_v3 hdk_vdiv(hd_v3 a, hd_v3 b) { return hdk_v3_make(a.x / b.x, a.y / b.y, a.z / b.z); }
HD_FN hd_v3 hdk_madd(hd_v3 p, hd_v3 d, float t)
{
    return hdk_v3_make(p.x + d.x * t, p.y + d.y * t, p.z + d.z * t);
}
HD_FN float hdk_dot(hd_v3 a, hd_v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
HD_FN float hdk_len(hd_v3 a) { return sqrtf(hdk_dot(a, a)); }
HD_FN hd_v3 hdk_normalize(hd_v3 a) { return hdk_scale(a, 1.0f / hdk_len(a)); }

#define hdk_log(x) logf(x)
#define hdk_exp(x) expf(x)
/* float trigonometry (hd_k_light.h's default is the double functions): the environment's and the
   area lights' samples, the phase function's direction */
#define HD_PRELUDE_HAS_TRIG 1
#define hdk_cos(x) cosf(x)
#define hdk_sin(x) sinf(x)
#define hdk_acos(x) acosf(x)
#define hdk_atan2(y, x) atan2f((y), (x))
#define hdk_sqrt(x) sqrtf(x)
#define hdk_floor(x) floorf(x)
#define hdk_absf(x) fabsf(x)
#define hdk_powf(x, y) powf((x), (y))
HD_FN float hdk_minf(float a, float b) { return a < b ? a : b; }
HD_FN float hdk_maxf(float a, float b) { return a > b ? a : b; }
HD_FN int hdk_mini(int a, int b) { return a < b ? a : b; }
HD_FN int hdk_maxi(int a, int b) { return a > b ? a : b; }
HD_FN float hdk_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
HD_FN int hdk_clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* IEEE binary16 <-> float32, portable: the storage of E and phi with
   params.illumination_precision = HD_PRECISION_FLOAT16 (the arithmetic stays float32). Both are
   selects on integer bit patterns, no branches, so a loop over them vectorises. hdk_h2f is exact
   (every half is a float); hdk_f2h rounds to nearest, ties to even, as OpenCL's vstore_half_rte:
   overflow gives inf, tiny values give subnormal halves or zero, NaN stays NaN (quiet, its sign
   and top payload bits kept). */
HD_FN uint32_t hdk_f2u(float f) { uint32_t u; memcpy(&u, &f, 4); return u; }
HD_FN float hdk_u2f(uint32_t u) { float f; memcpy(&f, &u, 4); return f; }
HD_FN float hdk_h2f(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, em = h & 0x7fffu;
    /* normal: rebias the exponent (127 - 15 = 112); inf/NaN (exponent 31): exponent 255 */
    uint32_t normal = (em << 13) + (112u << 23) + (uint32_t)(em >= 0x7c00u) * (112u << 23);
    /* subnormal (and zero): mantissa * 2^-24, exact in float; picked by a mask, as a ?: here
       kept GCC 12 from vectorising */
    uint32_t sub = hdk_f2u((float)em * 5.9604644775390625e-8f), m = 0u - (uint32_t)(em < 0x0400u);
    return hdk_u2f(sign | (sub & m) | (normal & ~m));
}
HD_FN uint16_t hdk_f2h(float f)
{
    uint32_t u = hdk_f2u(f), sign = (u >> 16) & 0x8000u, a = u & 0x7fffffffu;
    /* NaN: quiet, top 10 payload bits; >= 65520 (rounds past the largest half 65504): inf */
    uint32_t special = a > 0x7f800000u ? 0x7e00u | ((a >> 13) & 0x3ffu) : 0x7c00u;
    /* normal half (a >= 2^-14): drop 13 mantissa bits with round-to-nearest-even; a carry into
       the exponent is the right result (up to inf at the top) */
    uint32_t normal = (a - (112u << 23) + 0x0fffu + ((a >> 13) & 1u)) >> 13;
    /* subnormal half (a < 2^-14): adding 0.5 (2^-1) lines the half's last mantissa bit up with
       the float's last one (2^-24 = 2^-1 * 2^-23), and the float adder rounds to nearest even */
    uint32_t sub = hdk_f2u(hdk_u2f(a) + 0.5f) - 0x3f000000u;
    uint32_t h = a >= 0x477ff000u ? special : (a >= 0x38800000u ? normal : sub);
    return (uint16_t)(sign | h);
}
/* The illumination's float16 store: saturates at the largest half, 65504, so a bright E or phi
   is clipped instead of becoming inf (and NaN in the image); every backend stores this. */
#define HD_HALF_MAX 65504.0f
HD_FN uint16_t hdk_f2h_sat(float f) { return hdk_f2h(f > HD_HALF_MAX ? HD_HALF_MAX : f); }

/* The colour-separated layout of the buffers the diffusion reads (sigma_t with its RGB channels,
   E, phi, phi2; also the CPU multigrid's vectors), the same on the CPU and OpenCL backends
   (hd_prelude_cl.h's HD__CL_AT): voxel (x, y, zz), zz = z + c * gz for channel c, has colour
   k = (x + y + zz) & 1 and lives at slot
       ((zz * 2 + k) * gy + y) * hx + (x >> 1),   hx = (gx + 1) / 2,
   i.e. each z-slice (of each channel) holds its colour-0 voxels row by row, then its colour-1
   voxels; a row of odd gx has one padding slot in one colour, which stays 0. Why: red-black
   relaxes one colour at a time, and in this layout a row's voxels of one colour and their
   neighbours of the other colour are contiguous, so the CPU's row loop loads them unit-stride
   (hd_cpu.h) instead of at stride 2 through permutes. hd__split_slot is the host-side formula
   (the OpenCL backend's copies to and from the API's x-fastest order use it too). */
HD_FN size_t hd__split_slot(int gx, int gy, int x, int y, int zz)
{
    return (((size_t)zz * 2 + (size_t)((x + y + zz) & 1)) * (size_t)gy + (size_t)y) * (((size_t)gx + 1) >> 1) +
           (size_t)(x >> 1);
}
/* Slots of a grid of `slices` z-slices (gz per channel): 2 * hx per row, one of them padding
   when gx is odd. */
HD_FN size_t hd__split_slots(int gx, int gy, size_t slices)
{
    return slices * (size_t)gy * 2 * (((size_t)gx + 1) >> 1);
}

/* Structs: GLSL has no typedef. */
#define HD_STRUCT(name) typedef struct name {
#define HD_STRUCT_END(name) } name;

/* Output parameters: pointers in C and OpenCL, `inout` in GLSL. */
#define HD_INOUT(type) type *
#define HD_DEREF(p) (*(p))
#define HD_REF(v) (&(v))

/* The kernel parameter block, identical in layout in C, OpenCL (a __constant struct) and GLSL
   (a std140 uniform block): only 16-byte vectors, so no padding rule differs. */
#define HD_PARAM_I4(name) hd_i4 name;
#define HD_PARAM_F4(name) hd_f4 name;
#define HD_PARAM_F4_ARRAY(name, n) hd_f4 name[n];



/* The parameter block and what a kernel invocation reaches through `K`. */
#ifndef HD_PRELUDE_C_CONTEXT
#define HD_PRELUDE_C_CONTEXT
#define HD_PARAMS_BEGIN typedef struct hd__kparams {
#define HD_PARAMS_END } hd__kparams;
#include "kernels/hd_k_params.h"

typedef struct hd__kctx {
    const hd__kparams *p;
    const void *vol;   /* the volume, dims.x*dims.y*dims.z voxels as p->vstore.x stores them */
    const float *tf;   /* RGBA * TF count */
    const float *maj;  /* majorant per cell of the majorant grid */
    float *sig;        /* sigma_t at the illumination grid's voxel centres */
    float *E;          /* direct light, channel-planar */
    float *phi;        /* scattered light (fluence), channel-planar */
    float *phi2;       /* Jacobi's second buffer */
    int f16;           /* 1: E, phi and phi2 are stored as binary16 in Eh, phih, phi2h (and the
                          float pointers are NULL); see HD_GET */
    uint16_t *Eh, *phih, *phi2h;
    float *img;        /* RGBA float accumulation, width*height*4 */
    float *lsum;       /* projection: E + phi summed, x-fastest channel-planar (NULL: read both) */
    const float *ptab; /* projection: the step's TF table, ptab_n RGBA entries (NULL: TF and exp) */
    int ptab_n;
    const float *dep;  /* the host's depth buffer, depth_dims.x * y window depths (hd_set_depth) */
    const float *env;  /* the environment's tables (hd_set_environment, hd_k_light.h) */
    const float *lv;   /* CD: the light volume being read (one light's rho) */
    float *lv2;        /* CD: the light volume being written (ping-pong) */
} hd__kctx;

HD_FN float hd__c_vol_raw(const hd__kctx *K, int i, int t)
{
    return t == HD_VOL_U8 ? (float)((const uint8_t *)K->vol)[i]
         : t == HD_VOL_U16 ? (float)((const uint16_t *)K->vol)[i]
         : t == HD_VOL_I16 ? (float)((const int16_t *)K->vol)[i] : ((const float *)K->vol)[i];
}

/* The projection's shortcuts (hd_k_project.h), taken where the CPU backend fills them in. */
#define HD_PRELUDE_LIGHT_SUM 1
#define HD_LIGHT_SUM_READY (K->lsum != NULL)
#define HD_PRELUDE_PROJECT_TABLE 1
#define HD_PROJECT_TABLE_READY (K->ptab != NULL)
#define HD_PTAB_N (K->ptab_n)
#define HD_KARGS const hd__kctx *K,
#define HD_KPASS K,
#define HD_PRM(name) (K->p->name)
/* Buffer element i; x,y,z is the same element as image coordinates (channel c at z + c*dz).
   The volume (vol) and CD's light volumes (lv, lv2) are x-fastest and use i. The buffers the
   diffusion reads (sig with its RGB channels, E, phi, phi2) are in the colour-separated layout
   (hd__split_slot above) of the grid K->p->gdims describes, so they use the coordinates; the
   shared kernels pass them everywhere. The illumination buffers E, phi, phi2 go through
   HD__LD_ / HD__ST_ (pasted on the buffer's name): float32 or binary16 by K->f16. The CPU
   backend runs its vectorised rows on a copy of K whose f16 is a literal, so the compiler drops
   the test there (hd_cpu.h); elsewhere it is one well-predicted branch. */
#define HD_GET(buf, i, x, y, z) HD__LD_##buf((i), (x), (y), (z))
#define HD_SET(buf, i, x, y, z, v) HD__ST_##buf((i), (x), (y), (z), (v))
/* hd__split_slot in int arithmetic, as the kernels' own indices (i, ic) are: the projection's 16
   loads per sample pay for every instruction of the address */
#define HD__C_AT(xx, yy, zz) \
    ((((zz) * 2 + (((xx) + (yy) + (zz)) & 1)) * K->p->gdims.y + (yy)) * ((K->p->gdims.x + 1) >> 1) + ((xx) >> 1))
/* Voxel i of the volume as stored (t: HD_VOL_*), the raw integer or the F32 volume's value. */
#define HD_VOL_RAW(i, x, y, z, t) ((void)(x), (void)(y), (void)(z), hd__c_vol_raw(K, (i), (t)))
#define HD__LD_lv(i, x, y, z) ((void)(x), (void)(y), (void)(z), K->lv[(i)])
#define HD__LD_lv2(i, x, y, z) ((void)(x), (void)(y), (void)(z), K->lv2[(i)])
#define HD__LD_lsum(i, x, y, z) ((void)(x), (void)(y), (void)(z), K->lsum[(i)])
#define HD__ST_lsum(i, x, y, z, v) ((void)(x), (void)(y), (void)(z), K->lsum[(i)] = (v))
#define HD__ST_lv2(i, x, y, z, v) ((void)(x), (void)(y), (void)(z), K->lv2[(i)] = (v))
#define HD__LD_sig(i, x, y, z) ((void)(i), K->sig[HD__C_AT(x, y, z)])
#define HD__ST_sig(i, x, y, z, v) ((void)(i), K->sig[HD__C_AT(x, y, z)] = (v))
#define HD__LD_HALF(buf, x, y, z) (K->f16 != 0 ? hdk_h2f(K->buf##h[HD__C_AT(x, y, z)]) : K->buf[HD__C_AT(x, y, z)])
#define HD__ST_HALF(buf, x, y, z, v) \
    (K->f16 != 0 ? (void)(K->buf##h[HD__C_AT(x, y, z)] = hdk_f2h_sat(v)) : (void)(K->buf[HD__C_AT(x, y, z)] = (v)))
#define HD__LD_E(i, x, y, z) ((void)(i), HD__LD_HALF(E, x, y, z))
#define HD__LD_phi(i, x, y, z) ((void)(i), HD__LD_HALF(phi, x, y, z))
#define HD__LD_phi2(i, x, y, z) ((void)(i), HD__LD_HALF(phi2, x, y, z))
#define HD__ST_E(i, x, y, z, v) ((void)(i), HD__ST_HALF(E, x, y, z, v))
#define HD__ST_phi(i, x, y, z, v) ((void)(i), HD__ST_HALF(phi, x, y, z, v))
#define HD__ST_phi2(i, x, y, z, v) ((void)(i), HD__ST_HALF(phi2, x, y, z, v))
#define HD_GET1(buf, i) (K->buf[(i)])
#define HD_SET1(buf, i, v) (K->buf[(i)] = (v))
#endif
#endif /* HD_PRELUDE_C_H */
