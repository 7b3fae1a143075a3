/* hd_prelude_c.h - makes the shared kernel sources (backends/kernels/) valid C99 and C++.
   The kernels are written once in a subset that C99, OpenCL C 1.2 and GLSL 4.30 all accept;
   each prelude defines the few words that differ: function qualifiers, the vector types and their
   operations, casts, the math built-ins, and how a kernel reaches its parameters and buffers.
   The GPU preludes (hd_prelude_cl.h, hd_prelude_glsl.h) define the same names. */
#ifndef HD_PRELUDE_C_H
#define HD_PRELUDE_C_H
#include <math.h>
#include <stdint.h>

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

HD_FN hd_v3 hd_v3_make(float x, float y, float z) { hd_v3 r; r.x = x; r.y = y; r.z = z; return r; }
HD_FN hd_v4 hd_v4_make(float x, float y, float z, float w)
{
    hd_v4 r; r.x = x; r.y = y; r.z = z; r.w = w; return r;
}
#define HD_V3(x, y, z) hd_v3_make((x), (y), (z))
#define HD_V4(x, y, z, w) hd_v4_make((x), (y), (z), (w))
#define HD_XYZ(v4) hd_v3_make((v4).x, (v4).y, (v4).z)
HD_FN hd_v3 hd_add(hd_v3 a, hd_v3 b) { return hd_v3_make(a.x + b.x, a.y + b.y, a.z + b.z); }
HD_FN hd_v3 hd_sub(hd_v3 a, hd_v3 b) { return hd_v3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
HD_FN hd_v3 hd_scale(hd_v3 a, float s) { return hd_v3_make(a.x * s, a.y * s, a.z * s); }
HD_FN hd_v3 hd_vmul(hd_v3 a, hd_v3 b) { return hd_v3_make(a.x * b.x, a.y * b.y, a.z * b.z); }
HD_FN hd_v3 hd_vdiv(hd_v3 a, hd_v3 b) { return hd_v3_make(a.x / b.x, a.y / b.y, a.z / b.z); }
HD_FN hd_v3 hd_madd(hd_v3 p, hd_v3 d, float t)
{
    return hd_v3_make(p.x + d.x * t, p.y + d.y * t, p.z + d.z * t);
}
HD_FN float hd_dot(hd_v3 a, hd_v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
HD_FN float hd_len(hd_v3 a) { return sqrtf(hd_dot(a, a)); }
HD_FN hd_v3 hd_normalize(hd_v3 a) { return hd_scale(a, 1.0f / hd_len(a)); }

#define hd_log(x) logf(x)
#define hd_exp(x) expf(x)
#define hd_sqrt(x) sqrtf(x)
#define hd_floor(x) floorf(x)
#define hd_absf(x) fabsf(x)
#define hd_powf(x, y) powf((x), (y))
HD_FN float hd_minf(float a, float b) { return a < b ? a : b; }
HD_FN float hd_maxf(float a, float b) { return a > b ? a : b; }
HD_FN int hd_mini(int a, int b) { return a < b ? a : b; }
HD_FN int hd_maxi(int a, int b) { return a > b ? a : b; }
HD_FN float hd_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
HD_FN int hd_clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

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
    const float *vol;  /* normalised voxel values, dims.x*dims.y*dims.z */
    const float *tf;   /* RGBA * TF count */
    const float *maj;  /* majorant per cell of the majorant grid */
    float *sig;        /* sigma_t at the illumination grid's voxel centres */
    float *E;          /* direct light, channel-planar */
    float *phi;        /* scattered light (fluence), channel-planar */
    float *phi2;       /* Jacobi's second buffer */
    float *img;        /* RGBA float accumulation, width*height*4 */
    const float *lv;   /* CD: the light volume being read (one light's rho) */
    float *lv2;        /* CD: the light volume being written (ping-pong) */
} hd__kctx;

#define HD_KARGS const hd__kctx *K,
#define HD_KPASS K,
#define HD_PRM(name) (K->p->name)
/* Buffer element i; x,y,z is the same element as image coordinates (channel c at z + c*dz), which
   image-backed GPU preludes use instead of i. */
#define HD_GET(buf, i, x, y, z) ((void)(x), (void)(y), (void)(z), K->buf[(i)])
#define HD_SET(buf, i, x, y, z, v) ((void)(x), (void)(y), (void)(z), K->buf[(i)] = (v))
#define HD_GET1(buf, i) (K->buf[(i)])
#define HD_SET1(buf, i, v) (K->buf[(i)] = (v))
#endif
#endif /* HD_PRELUDE_C_H */
