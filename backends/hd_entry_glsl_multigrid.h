/* hd_entry_glsl_multigrid.h - GLSL text, not C: HD_SOLVER_MULTIGRID's passes, one program (GL,
   hd_gl.h; 4.30, scripts/embed-glsl) or SPIR-V module (Vulkan, hd_vulkan.h; 4.50,
   scripts/build-spirv) each, selected by HD_MG_STAGE=n, in place of hd_entry_glsl.h. The math is
   the shared hd_k_multigrid.h / hd_k_diffuse.h; the V-cycle's smoothing is hd_entry_glsl.h's
   diffusion stage on the level's bindings. One invocation per voxel (x along the 64-wide work
   group).
   GLSL has one parameter block (binding 0) and no kernel context: the block bound is the grid
   the shared function READS (hd_k_multigrid.h's K); the other grid's dims come in hd_pc and it
   is reached through hd_i_lv2 (r32f, read-write; GL image unit 6, Vulkan binding 10), which no
   multigrid pass uses otherwise. Other grids as the sweep's: sig, E, phi, phi2. Double precision
   is core GLSL 4.00 (llvmpipe compiles it; Vulkan: the device feature shaderFloat64, which
   lavapipe has). The row sums go to a storage buffer of doubles: GL binding 3, Vulkan binding 11
   (3 is the majorant grid there). beta and alpha: GL uniforms at locations 1 and 2; Vulkan has no
   loose uniforms, so they come in the push constants the direction and update passes leave free
   (HD_MG_PUSH_SCALARS, hd_bind_vk_glsl.h): beta's bits in hd_pc.x, alpha's low and high words in
   hd_pc.x and hd_pc.y. */
#define HD_MG_SIG 1      /* K fine; hd_pc = coarse dims, sigma_t channels; coarse sigma_t -> unit 6 */
#define HD_MG_RESIDUAL 2 /* K the level (sig, E = rhs, phi); f - A phi in float -> phi2 */
#define HD_MG_RESTRICT 3 /* K fine (phi = its residual, sig); hd_pc = coarse dims, channels; rhs -> unit 6, phi2 = 0 */
#define HD_MG_PROLONG 4  /* K coarse (phi = its correction; sig = the FINE sigma_t, for hdk_mg_medium);
                            hd_pc = fine dims, channels; unit 6 += P */
#define HD_MG_DIR 5      /* E = z, phi = p: p = z + beta p, z = 0 */
#define HD_MG_RES_F64 6  /* K fine (sig, E, phi, phi2 = lo); hd_pc.x use_lo, .y negate; -> unit 6 */
#define HD_MG_DOT 7      /* K level 0 (E, phi): the row sums -> hd_mg_row_sums */
#define HD_MG_UPDATE 8   /* phi + lo (phi2) += alpha p (E) */
#define HD_MG_EXTRAP 9   /* K fine (sig, E, phi, phi2 = lo); hd_pc.x colour: empty voxels' phi = extrapolation, lo = -phi */
#ifdef HD_MG_PUSH_SCALARS
layout(std430, binding = 11) writeonly buffer hd_b_dot { double hd_mg_row_sums[]; };
#define hd_mg_beta intBitsToFloat(hd_pc.x)
#define hd_mg_alpha packDouble2x32(uvec2(hd_pc.xy))
#else
layout(std430, binding = 3) writeonly buffer hd_b_dot { double hd_mg_row_sums[]; };
layout(location = 1) uniform float hd_mg_beta;
layout(location = 2) uniform double hd_mg_alpha;
#endif

float hdk_mg_other(int x, int y, int zz)
{
    return imageLoad(hd_i_lv2, ivec3(x, y, zz)).r;
}
void hdk_mg_set_other(int x, int y, int zz, float v)
{
    imageStore(hd_i_lv2, ivec3(x, y, zz), vec4(v, 0.0f, 0.0f, 0.0f));
}

void main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), zz = int(gl_GlobalInvocationID.z);
    ivec4 g = HD_PRM(gdims);
#if HD_MG_STAGE == HD_MG_SIG
    if (x < hd_pc.x && y < hd_pc.y && zz < hd_pc.z * hd_pc.w)
        hdk_mg_set_other(x, y, zz, hdk_mg_coarse_sig(x, y, zz % hd_pc.z, zz / hd_pc.z));
#elif HD_MG_STAGE == HD_MG_RESTRICT
    /* the CPU's row form combines each fine column's share (hdk_mg_restrict_line) of the coarse
       row in t order; here each coarse voxel computes its 4 columns' shares itself: the same
       operations in the same order, so the same bits */
    if (x < hd_pc.x && y < hd_pc.y && zz < hd_pc.z * hd_pc.w) {
        int Z = zz % hd_pc.z, c = zz / hd_pc.z;
        float s = 0.0f;
        for (int t = 0; t < 4; ++t) {
            int xf = 2 * x - 1 + t;
            if (xf >= 0 && xf < g.x) s = hdk_mg_restrict_x(s, t, hdk_mg_restrict_line(xf, y, Z, c));
        }
        hdk_mg_set_other(x, y, zz, s);
        HD_SET(phi2, 0, x, y, zz, 0.0f);
    }
#elif HD_MG_STAGE == HD_MG_PROLONG
    if (x < hd_pc.x && y < hd_pc.y && zz < hd_pc.z * hd_pc.w) {
        int z = zz % hd_pc.z, c = zz / hd_pc.z;
        hdk_mg_set_other(x, y, zz, hdk_mg_other(x, y, zz) +
                                      hdk_mg_prolong(x, y, z, c) * hdk_mg_medium((z * hd_pc.y + y) * hd_pc.x + x, x, y, z));
    }
#elif HD_MG_STAGE == HD_MG_RESIDUAL
    if (x < g.x && y < g.y && zz < g.z * hd_pc.w) {
        int z = zz % g.z, c = zz / g.z;
        float den = 0.0f;
        float num = hdk_diffuse_terms(x, y, z, c, den);
        HD_SET(phi2, 0, x, y, zz, num - den * HD_GET(phi, 0, x, y, zz));
    }
#elif HD_MG_STAGE == HD_MG_RES_F64
    if (x < g.x && y < g.y && zz < g.z * hd_pc.w) {
        int z = zz % g.z, c = zz / g.z;
        int surface = (HD_DIFFUSE_FLAGS & HD_FLAG_SURFACE_BOUNDARY) != 0 ? 1 : 0;
        int rgb = (HD_DIFFUSE_FLAGS & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0;
        float v = float(hdk_mg_res_f64(x, y, z, c, surface, rgb, hd_pc.x, x > 0 ? 1 : 0, x < g.x - 1 ? 1 : 0,
                                      y > 0 ? 1 : 0, y < g.y - 1 ? 1 : 0, z > 0 ? 1 : 0, z < g.z - 1 ? 1 : 0));
        hdk_mg_set_other(x, y, zz, hd_pc.y != 0 ? -v : v);
    }
#elif HD_MG_STAGE == HD_MG_DOT
    /* x: the row's y, y: its zz (z + c gz) */
    if (x < g.y && y < g.z * hd_pc.w) hd_mg_row_sums[y * g.y + x] = hdk_mg_dot_row(x, y);
#elif HD_MG_STAGE == HD_MG_DIR
    if (x < g.x && y < g.y && zz < g.z * hd_pc.w) {
        HD_SET(phi, 0, x, y, zz, hdk_mg_dir_of(HD_GET(E, 0, x, y, zz), HD_GET(phi, 0, x, y, zz), hd_mg_beta));
        HD_SET(E, 0, x, y, zz, 0.0f);
    }
#elif HD_MG_STAGE == HD_MG_UPDATE
    if (x < g.x && y < g.y && zz < g.z * hd_pc.w) {
        float l = HD_GET(phi2, 0, x, y, zz);
        float f = hdk_mg_update_of(HD_GET(phi, 0, x, y, zz), l, HD_GET(E, 0, x, y, zz), hd_mg_alpha);
        HD_SET(phi, 0, x, y, zz, f);
        HD_SET(phi2, 0, x, y, zz, l);
    }
#elif HD_MG_STAGE == HD_MG_EXTRAP
    /* surface boundary: hdk_diffuse_extrapolate on the voxels of colour hd_pc.x, so none it reads
       is being written (the CPU's hd__cpu_mg_extrap_row) */
    if (x < g.x && y < g.y && zz < g.z * hd_pc.w && ((x + y + zz % g.z + hd_pc.x) & 1) == 0) {
        float v = 0.0f;
        if (hdk_diffuse_extrapolate(x, y, zz % g.z, zz / g.z, v) != 0) {
            HD_SET(phi, 0, x, y, zz, v);
            HD_SET(phi2, 0, x, y, zz, -v);
        }
    }
#else
#error "hd_entry_glsl_multigrid.h: define HD_MG_STAGE"
#endif
}
