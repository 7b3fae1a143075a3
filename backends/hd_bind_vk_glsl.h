/* hd_bind_vk_glsl.h - GLSL 4.50 text, not C: the Vulkan backend's resources, placed before
   hd_prelude_glsl.h by scripts/build-spirv. The grids (volume, sigma_t, E, phi, Jacobi's phi2,
   CD's light volumes) are r32f storage image3Ds, read with imageLoad at the (x, y, z) the shared
   kernels pass beside the linear index (channel c of E / phi at z + c * dz): on lavapipe a
   storage image ran the diffusion sweep several times faster than a storage buffer
   (docs/DESIGN-VULKAN.md has the table). The small 1D arrays (TF, majorant grid, image
   accumulation) stay storage buffers, indexed by HD_GET1 / HD_SET1.
   Set 0: binding 0 the parameter block (hd_prelude_glsl.h, a dynamic uniform buffer), 1 volume,
   2 TF, 3 majorants, 4 sigma_t, 5 E, 6 phi, 7 phi2, 8 image, 9 light volume read, 10 light
   volume written. Push constants: x = red-black parity, y = Jacobi, z = light, w = first.
   Specialization constant 0, hd_sc_flags: in the diffusion module, the flags word (counts.z) as
   a constant fixed when hd_vulkan.h makes the pipeline, one per flags value, read by the kernel
   through HD_DIFFUSE_FLAGS: lavapipe runs both sides of every branch, so a flag tested at run
   time costs the untaken path's image loads (docs/DESIGN-VULKAN.md has the measurement).
   Specialization constants 1, hd_sc_zk, and 3, hd_sc_yk: the slices and rows of the block each
   diffusion invocation relaxes (HD_DIFFUSE_ZK, HD_DIFFUSE_YK, hd_entry_glsl.h), fixed by
   hd_vulkan.h, which dispatches to match; 2, hd_sc_jacobi: the solver (HD_DIFFUSE_JACOBI), so
   only one of the two stores is compiled.
   HD_ILLUM_R16F (scripts/build-spirv's _half modules of the stages that touch E / phi): E, phi
   and phi2 are r16f (VK_FORMAT_R16_SFLOAT, params.illumination_precision FLOAT16), converted by
   imageLoad / imageStore, the arithmetic float32; r16f needs shaderStorageImageExtendedFormats.
   Binding 11: HD_SOLVER_MULTIGRID's row sums (doubles, hd_entry_glsl_multigrid.h, its modules
   compiled with HD_MG_STAGE = n and HD_STAGE 0); its passes' flags, like the diffusion stage's,
   are hd_sc_flags, and their beta / alpha come in the push constants (HD_MG_PUSH_SCALARS).
   Binding 12: the direct light's list of voxels (src/hd_direct_mask.h, hd__direct_mask); the direct
   stage's push constant x is its length. Binding 13: the projection's TF table (the projection
   stage's push constant x is its entries); 14: the projection's E + phi, r32f at any precision;
   15: the host's depth buffer (hd_set_depth; the projection and the path tracers); 16: the
   environment's tables (hd_set_environment; the direct light and the path tracers). */
#define HD_GLSL_CUSTOM_BUFFERS 1
#extension GL_EXT_control_flow_attributes : require
#define HD_UNROLL [[unroll]] /* loops over a block (hd_entry_glsl.h): unrolled, their arrays registers */
#ifdef HD_ILLUM_R16F
#define HD_ILLUM_FMT r16f
#define HD_ILLUM_ROUND(v) hdk_f16_round(min((v), 65504.0)) /* nearest even (hd_prelude_glsl.h), saturated as hdk_f2h_sat */
#else
#define HD_ILLUM_FMT r32f
#define HD_ILLUM_ROUND(v) (v)
#endif
/* The volume packed along x in an r32ui image (a format every device stores): an F32 volume's
   floats one a texel, 16-bit voxels two a texel, U8 four, the first in the low bits (rows padded
   to whole texels). Specialization constant 4, hd_sc_vstore, is its HD_VOL_* (1 U8, 2 U16, 3 I16,
   0 F32; hd_k_params.h comes later), fixed when hd_vulkan.h makes the pipelines, so only its own
   load is compiled. */
layout(binding = 1, r32ui) uniform readonly uimage3D hd_i_vol;
layout(constant_id = 4) const int hd_sc_vstore = 0;
#define HD_VOL_STORE hd_sc_vstore
float hd_vol_raw_at(int x, int y, int z, int t)
{
    if (t == 1) return float(bitfieldExtract(imageLoad(hd_i_vol, ivec3(x >> 2, y, z)).r, 8 * (x & 3), 8));
    if (t == 2) return float(bitfieldExtract(imageLoad(hd_i_vol, ivec3(x >> 1, y, z)).r, 16 * (x & 1), 16));
    if (t == 3) return float(bitfieldExtract(int(imageLoad(hd_i_vol, ivec3(x >> 1, y, z)).r), 16 * (x & 1), 16));
    return uintBitsToFloat(imageLoad(hd_i_vol, ivec3(x, y, z)).r);
}
#define HD_VOL_RAW(i, px, py, pz, t) hd_vol_raw_at((px), (py), (pz), (t))
layout(std430, binding = 2) readonly buffer hd_b_tf { float tf[]; };
layout(std430, binding = 3) readonly buffer hd_b_maj { float maj[]; };
layout(binding = 4, r32f) uniform image3D hd_i_sig;
layout(binding = 5, HD_ILLUM_FMT) uniform image3D hd_i_E;
layout(binding = 6, HD_ILLUM_FMT) uniform image3D hd_i_phi;
layout(binding = 7, HD_ILLUM_FMT) uniform image3D hd_i_phi2;
layout(std430, binding = 8) buffer hd_b_img { float img[]; };
layout(binding = 9, r32f) uniform readonly image3D hd_i_lv;
layout(binding = 10, r32f) uniform image3D hd_i_lv2;
layout(std430, binding = 12) readonly buffer hd_b_dl { uint dl[]; };
layout(std430, binding = 13) readonly buffer hd_b_ptab { float ptab[]; };
layout(binding = 14, r32f) uniform image3D hd_i_lsum;
layout(std430, binding = 15) readonly buffer hd_b_dep { float dep[]; };
layout(std430, binding = 16) readonly buffer hd_b_env { float env[]; };
layout(push_constant) uniform hd_push_block { ivec4 hd_pc; };
layout(constant_id = 0) const int hd_sc_flags = 0;
layout(constant_id = 1) const int hd_sc_zk = 1;
layout(constant_id = 2) const int hd_sc_jacobi = 0;
layout(constant_id = 3) const int hd_sc_yk = 1;
#define HD_MG_PUSH_SCALARS 1
#if HD_STAGE == 3 || defined(HD_MG_STAGE) /* HD_STAGE_DIFFUSE (hd_entry_glsl.h), multigrid; the other stages read counts.z */
#define HD_DIFFUSE_FLAGS hd_sc_flags
#define HD_DIFFUSE_ZK hd_sc_zk
#define HD_DIFFUSE_YK hd_sc_yk
#define HD_DIFFUSE_JACOBI hd_sc_jacobi
#endif
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
