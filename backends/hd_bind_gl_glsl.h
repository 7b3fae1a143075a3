/* hd_bind_gl_glsl.h - GLSL 4.30 text, not C: the OpenGL backend's resources, placed before
   hd_prelude_glsl.h by scripts/embed-glsl (backends/hd_glsl_embedded.h). The same layout as the
   Vulkan backend's hd_bind_vk_glsl.h, measured again under GL (docs/DESIGN-GL.md): the grids
   (volume, sigma_t, E, phi, Jacobi's phi2, CD's light volumes) are r32f image3Ds read with
   imageLoad at the (x, y, z) the shared kernels pass beside the linear index (channel c of E / phi
   at z + c * dz); the small 1D arrays (TF, majorant grid, image accumulation) are storage buffers.
   GL keeps separate binding points per kind, numbered within GL 4.3's minimums (8 image units,
   8 storage buffers): uniform block 0 the parameter block (hd_prelude_glsl.h); image units
   0 volume, 1 sigma_t, 2 E, 3 phi, 4 phi2, 5 light volume read, 6 light volume written, 7 the
   projection's E + phi (always r32f); storage buffers 0 TF, 1 majorants, 2 image accumulation,
   4 the direct light's list of voxels (src/hd_direct_mask.h, hd__direct_mask; hd_pc.x its length in the
   direct stage), 5 the projection's TF table (hd_pc.x its entries in the projection stage), 6 the
   host's depth buffer (hd_set_depth; the projection and the path tracers), 7 the environment's
   tables (hd_set_environment; the direct light and the path tracers). GL has no push
   constants: hd_pc (x = red-black parity, y = Jacobi, z = light, w = first) is the plain
   uniform at location 0. HD_ILLUM_R16F (hd_gl.h's prefix for params.illumination_precision
   FLOAT16): E, phi and phi2 are r16f (GL_R16F textures, core in GL 4.3), converted by imageLoad /
   imageStore, the arithmetic float32. */
#define HD_GLSL_CUSTOM_BUFFERS 1
#ifdef HD_ILLUM_R16F
#define HD_ILLUM_FMT r16f
#define HD_ILLUM_ROUND(v) hdk_f16_round(min((v), 65504.0)) /* nearest even (hd_prelude_glsl.h), saturated as hdk_f2h_sat */
#else
#define HD_ILLUM_FMT r32f
#define HD_ILLUM_ROUND(v) (v)
#endif
/* The volume in its own format: HD_VOL_STORE (hd_gl.h's prefix; HD_VOL_* of hd_k_params.h, which
   comes later: 1 U8, 2 U16, 3 I16, 0 F32) picks the image's format, so imageLoad returns the raw
   voxel (GL 4.3 core formats r8ui, r16ui, r16i). */
#ifndef HD_VOL_STORE
#define HD_VOL_STORE 0
#endif
#if HD_VOL_STORE == 1
layout(binding = 0, r8ui) uniform readonly uimage3D hd_i_vol;
#elif HD_VOL_STORE == 2
layout(binding = 0, r16ui) uniform readonly uimage3D hd_i_vol;
#elif HD_VOL_STORE == 3
layout(binding = 0, r16i) uniform readonly iimage3D hd_i_vol;
#else
layout(binding = 0, r32f) uniform readonly image3D hd_i_vol;
#endif
#define HD_VOL_RAW(i, px, py, pz, t) float(imageLoad(hd_i_vol, ivec3((px), (py), (pz))).r)
layout(std430, binding = 0) readonly buffer hd_b_tf { float tf[]; };
layout(std430, binding = 1) readonly buffer hd_b_maj { float maj[]; };
layout(binding = 1, r32f) uniform image3D hd_i_sig;
layout(binding = 2, HD_ILLUM_FMT) uniform image3D hd_i_E;
layout(binding = 3, HD_ILLUM_FMT) uniform image3D hd_i_phi;
layout(binding = 4, HD_ILLUM_FMT) uniform image3D hd_i_phi2;
layout(std430, binding = 2) buffer hd_b_img { float img[]; };
layout(std430, binding = 4) readonly buffer hd_b_dl { uint dl[]; };
layout(binding = 5, r32f) uniform readonly image3D hd_i_lv;
layout(binding = 6, r32f) uniform image3D hd_i_lv2;
layout(binding = 7, r32f) uniform image3D hd_i_lsum;
layout(std430, binding = 5) readonly buffer hd_b_ptab { float ptab[]; };
layout(std430, binding = 6) readonly buffer hd_b_dep { float dep[]; };
layout(std430, binding = 7) readonly buffer hd_b_env { float env[]; };
layout(location = 0) uniform ivec4 hd_pc;
#define HD_GET(buf, i, px, py, pz) imageLoad(hd_i_##buf, ivec3((px), (py), (pz))).r
#define HD_SET(buf, i, px, py, pz, v) imageStore(hd_i_##buf, ivec3((px), (py), (pz)), vec4(HD_STV_##buf(v), 0.0f, 0.0f, 0.0f))
#define HD_STV_sig(v) (v)
#define HD_STV_lv2(v) (v)
#define HD_STV_lsum(v) (v)
#define HD_STV_E(v) HD_ILLUM_ROUND(v)
#define HD_STV_phi(v) HD_ILLUM_ROUND(v)
#define HD_STV_phi2(v) HD_ILLUM_ROUND(v)
/* The projection reads the summed light grid (hd_i_lsum, written by the light-sum stage) and the
   step's TF table (ptab, hd_pc.x entries in the projection stage); the backend keeps both up to
   date before every projection. */
#define HD_PRELUDE_LIGHT_SUM 1
#define HD_LIGHT_SUM_READY true
#define HD_LIGHT_SUM_ONLY 1 /* hdk_sample_light reads lsum alone: the path stage, which has no r16f twin, never loads E or phi */
#define HD_PRELUDE_PROJECT_TABLE 1
#define HD_PROJECT_TABLE_READY true
#define HD_PTAB_N hd_pc.x
#define HD_GET1(buf, i) buf[(i)]
#define HD_SET1(buf, i, v) buf[(i)] = (v)
