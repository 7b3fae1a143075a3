/* hd_prelude_glsl.h - GLSL 4.30 text, not C: makes the shared kernel sources (backends/kernels/)
   valid GLSL compute shaders, defining the same names as hd_prelude_c.h (read that file for what
   each means). Buffers are globals here (GLSL has no pointers), so HD_KARGS/HD_KPASS are empty
   and HD_GET(buf, ...) names the buffer's array. This version binds every buffer as a storage
   buffer; a backend that prefers images (lavapipe/llvmpipe run storage buffers about 6x slower
   than image3D) defines HD_GLSL_CUSTOM_BUFFERS and its own HD_GET/HD_SET before the kernels.
   The backend prepends `#version`, `#define HD_MAX_LIGHTS n` and its local size. */
#define HD_FN
#define HD_LANG_GLSL 1
/* The projection marches the span between its first and last non-empty cells in one loop
   (hd_k_project.h): the invocations of a GLSL stage run in SIMD lanes. */
#define HD_PROJECT_MARCH_SPAN 1
/* hdk_track walks to each collision's cell, then takes it (hd_k_common.h, hdk_track_rounds). */
#define HD_TRACK_ROUNDS 1
#define hd_u32 uint
#define hd_v3 vec3
#define hd_v4 vec4
#define hd_i4 ivec4
#define hd_f4 vec4

#define HD_F(v) float(v)
#define HD_I(v) int(v)
#define HD_U(v) uint(v)

#define HD_V3(x, y, z) vec3((x), (y), (z))
#define HD_V4(x, y, z, w) vec4((x), (y), (z), (w))
#define HD_XYZ(v4) ((v4).xyz)
vec3 hdk_add(vec3 a, vec3 b) { return a + b; }
vec3 hdk_sub(vec3 a, vec3 b) { return a - b; }
vec3 hdk_scale(vec3 a, float s) { return a * s; }
vec3 hdk_vmul(vec3 a, vec3 b) { return a * b; }
vec3 hdk_vdiv(vec3 a, vec3 b) { return a / b; }
vec3 hdk_madd(vec3 p, vec3 d, float t) { return p + d * t; }
/* Spelled out, not dot(): the same order of operations as the C prelude. */
float hdk_dot(vec3 a, vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
float hdk_len(vec3 a) { return sqrt(hdk_dot(a, a)); }
vec3 hdk_normalize(vec3 a) { return hdk_scale(a, 1.0f / hdk_len(a)); }

#define hdk_log(x) log(x)
#define hdk_exp(x) exp(x)
#define hdk_sqrt(x) sqrt(x)
#define hdk_floor(x) floor(x)
#define hdk_absf(x) abs(x)
#define hdk_powf(x, y) pow((x), (y))
float hdk_minf(float a, float b) { return a < b ? a : b; }
float hdk_maxf(float a, float b) { return a > b ? a : b; }
int hdk_mini(int a, int b) { return a < b ? a : b; }
int hdk_maxi(int a, int b) { return a > b ? a : b; }
float hdk_clampf(float v, float lo, float hi) { return v < lo ? lo : (v > hi ? hi : v); }
int hdk_clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

/* v rounded to the nearest binary16, ties to even, as a float: what hdk_f2h (hd_prelude_c.h) and
   OpenCL's vstore_half_rte store. Float16 illumination (HD_ILLUM_R16F) stores this, so the r16f
   image's own float -> half conversion has nothing left to round: lavapipe and llvmpipe convert
   by truncation (toward zero), measured on every stored voxel of a direct pass (docs/DESIGN-
   VULKAN.md), a bias that E's and phi's iterations accumulate. Normal halves: the 13 dropped
   mantissa bits rounded in integer arithmetic (a carry into the exponent is right); subnormal
   halves (|v| < 2^-14): to a multiple of 2^-24 by roundEven, the scalings exact; |v| >= 65520:
   inf, as hdk_f2h; NaN as it is. */
float hdk_f16_round(float v)
{
    uint u = floatBitsToUint(v), s = u & 0x80000000u, a = u & 0x7fffffffu;
    float nrm = uintBitsToFloat(s | ((a + 0x0fffu + ((a >> 13) & 1u)) & 0xffffe000u));
    float sub = uintBitsToFloat(s | floatBitsToUint(roundEven(uintBitsToFloat(a) * 16777216.0f) * 5.9604644775390625e-8f));
    float big = uintBitsToFloat(s | 0x7f800000u);
    return a > 0x7f800000u ? v : (a >= 0x477ff000u ? big : (a >= 0x38800000u ? nrm : sub));
}

#define HD_STRUCT(name) struct name {
#define HD_STRUCT_END(name) };

/* Output parameters: GLSL's inout, which copies the argument in, so a caller initialises what it
   passes, even a pure output (else the copy reads an undefined value; Mesa warns of it). */
#define HD_INOUT(type) inout type
#define HD_DEREF(p) p
#define HD_REF(v) v

/* The parameter block: a std140 uniform block; only 16-byte vectors, as in C. */
#define HD_PARAM_I4(name) ivec4 name;
#define HD_PARAM_F4(name) vec4 name;
#define HD_PARAM_F4_ARRAY(name, n) vec4 name[n];
#define HD_PARAMS_BEGIN layout(std140, binding = 0) uniform hd_kparams_block {
#define HD_PARAMS_END } hd_kp;

#define HD_KARGS
#define HD_KPASS
#define HD_PRM(name) (hd_kp.name)

#ifndef HD_GLSL_CUSTOM_BUFFERS
/* The volume packed in words: an F32 volume's floats, 2 voxels a word for the 16-bit storages,
   4 for U8 (voxel i in word i >> 1 or i >> 2, the first in the low bits); t is HD_VOL_* (1 U8,
   2 U16, 3 I16, hd_k_params.h, which comes after this file). */
layout(std430, binding = 1) readonly buffer hd_b_vol { uint vol[]; };
float hd_vol_raw_at(int i, int t)
{
    if (t == 1) return float(bitfieldExtract(vol[i >> 2], 8 * (i & 3), 8));
    if (t == 2) return float(bitfieldExtract(vol[i >> 1], 16 * (i & 1), 16));
    if (t == 3) return float(bitfieldExtract(int(vol[i >> 1]), 16 * (i & 1), 16));
    return uintBitsToFloat(vol[i]);
}
#define HD_VOL_RAW(i, x, y, z, t) hd_vol_raw_at((i), (t))
layout(std430, binding = 2) readonly buffer hd_b_tf { float tf[]; };
layout(std430, binding = 3) readonly buffer hd_b_maj { float maj[]; };
layout(std430, binding = 4) buffer hd_b_sig { float sig[]; };
layout(std430, binding = 5) buffer hd_b_E { float E[]; };
layout(std430, binding = 6) buffer hd_b_phi { float phi[]; };
layout(std430, binding = 7) buffer hd_b_phi2 { float phi2[]; };
layout(std430, binding = 8) buffer hd_b_img { float img[]; };
layout(std430, binding = 9) readonly buffer hd_b_lv { float lv[]; };
layout(std430, binding = 10) buffer hd_b_lv2 { float lv2[]; };
layout(std430, binding = 12) readonly buffer hd_b_dl { uint dl[]; };
layout(std430, binding = 15) readonly buffer hd_b_dep { float dep[]; };
layout(std430, binding = 16) readonly buffer hd_b_env { float env[]; };
#define HD_GET(buf, i, x, y, z) buf[(i)]
#define HD_SET(buf, i, x, y, z, v) buf[(i)] = (v)
#define HD_GET1(buf, i) buf[(i)]
#define HD_SET1(buf, i, v) buf[(i)] = (v)
#endif
