/* hd_entry_glsl.h - GLSL 4.50 text, not C: the compute entry points of the Vulkan backend, one
   per SPIR-V module, selected by -DHD_STAGE=n (scripts/build-spirv). Each calls one shared stage
   function; the math is all in backends/kernels/. Work groups are 64 x 1 x 1 along x (the
   fastest-varying axis of the grids and of the image rows). */
#define HD_STAGE_CLASSIFY 1
#define HD_STAGE_DIRECT 2
#define HD_STAGE_DIFFUSE 3
#define HD_STAGE_PROJECT 4
#define HD_STAGE_CONVECT 5
#define HD_STAGE_SUM_LIGHT 6
#define HD_STAGE_PATH 7
#define HD_STAGE_LIGHT_SUM 8
#define HD_STAGE_UPSAMPLE 9 /* a reduced frame's upsample pass alone: the projection's pipeline is far dearer per pixel on lavapipe */
#ifndef HD_DIFFUSE_ZK
#define HD_DIFFUSE_ZK 1 /* slices per invocation of the diffusion stage (Vulkan: hd_bind_vk_glsl.h) */
#endif
#ifndef HD_DIFFUSE_YK
#define HD_DIFFUSE_YK 1 /* rows per invocation of the diffusion stage (Vulkan: hd_bind_vk_glsl.h) */
#endif
#ifndef HD_DIFFUSE_JACOBI
#define HD_DIFFUSE_JACOBI hd_pc.y /* Jacobi (1) or red-black (0); Vulkan: a constant per pipeline */
#endif

#if HD_STAGE == HD_STAGE_DIFFUSE
/* The diffusion stage relaxes a block of HD_DIFFUSE_YK rows x HD_DIFFUSE_ZK slices per
   invocation, one voxel per row: red-black, in row (y, z) invocation bx relaxes voxel
   2 bx + ((y + z + parity) & 1), hdk_diffuse_row's voxels, in place; Jacobi voxel bx, phi -> phi2.
   Lavapipe pays per static imageLoad (docs/DESIGN-VULKAN.md), so the block loads each texel once
   and hands it to every voxel that needs it: a row's two x-neighbours are loaded with the row;
   the y- and z-neighbours of a voxel are, inside the block, the texel at its x in the adjacent
   rows, already loaded there (red-black: one of that row's x-neighbours, the rows' colours
   alternate; Jacobi: that row's own voxel), so only the block's faces load extra texels. Grey
   loads per voxel: 6 + 4 (YK + ZK) / (YK ZK) against 14 (8 at 4 x 4). The values go through
   the shared hdk_diffuse_update_of, as hdk_diffuse_terms does after its own loads: the same
   bits. A half-sweep reads only the other colour's phi (Jacobi writes phi2), so all loads come
   before the stores. Out-of-grid coordinates are clamped for the loads (their values are unused:
   the in-grid flags drop them) and store nothing. Blocks do not straddle channels: invocation z
   is channel c's block z - c * hd_pc.z (hd_pc.z: blocks per channel, from the backend). */
#define HD_DB (HD_DIFFUSE_YK * HD_DIFFUSE_ZK)
/* HD_UNROLL: [[unroll]] on the block's loops where the front end takes it (hd_bind_vk_glsl.h):
   lavapipe left 4 x 4 and 8 x 2 blocks' arrays in memory without it (0.48 of the stencil) */
#ifndef HD_UNROLL
#define HD_UNROLL
#endif

/* The voxel's x in block row (j, k): red-black's colour alternates between adjacent rows. */
int hdk_diffuse_bx(int bx, int o0, int j, int k, int jacobi)
{
    return jacobi != 0 ? bx : 2 * bx + (o0 ^ ((j + k) & 1));
}

/* sigma' and phi of texel (x, y, z) of channel c, x clamped into the grid (y, z already are). */
void hdk_diffuse_texel(int x, int y, int z, int c, int rgb, float ag, out float s, out float p)
{
    int xc = hdk_clampi(x, 0, HD_PRM(gdims).x - 1);
    s = hdk_diffuse_sigp(0, xc, y, z, c, rgb, ag);
    p = HD_GET(phi, 0, xc, y, z + c * HD_PRM(gdims).z);
}

/* Relaxes the block of invocation (bx, by, bz): loads, then the updates, then the stores. */
void hdk_diffuse_block(int bx, int by, int bz)
{
    ivec4 g = HD_PRM(gdims);
    int jacobi = HD_DIFFUSE_JACOBI;
    int rgb = (HD_DIFFUSE_FLAGS & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0;
    int rhs = (HD_DIFFUSE_FLAGS & HD_FLAG_DIFFUSE_RHS) != 0 ? 1 : 0;
    int nzb = hd_pc.z, c = (bz >= nzb ? 1 : 0) + (bz >= 2 * nzb ? 1 : 0); /* bz / nzb, <= 3 channels */
    int y0 = by * HD_DIFFUSE_YK, z0 = (bz - c * nzb) * HD_DIFFUSE_ZK, o0 = (y0 + z0 + hd_pc.x) & 1;
    /* per block row r = k * YK + j: own source, absorption and sigma'; x-neighbours' sigma' and
       phi; the texel at the adjacent rows' voxel x (C) */
    float src[HD_DB], dn[HD_DB], sp[HD_DB], sl[HD_DB], pl[HD_DB], sr[HD_DB], pr[HD_DB], sc[HD_DB], pc[HD_DB];
    /* the faces: rows y0 - 1 and y0 + YK per slice, slices z0 - 1 and z0 + ZK per row */
    float sym[HD_DIFFUSE_ZK], pym[HD_DIFFUSE_ZK], syp[HD_DIFFUSE_ZK], pyp[HD_DIFFUSE_ZK];
    float szm[HD_DIFFUSE_YK], pzm[HD_DIFFUSE_YK], szp[HD_DIFFUSE_YK], pzp[HD_DIFFUSE_YK];
    float v[HD_DB], ag = hdk_diffuse_ag(HD_PRM(medium).y), agr = 0.0f; /* 1 - albedo g (grey; RGB per texel) */
    HD_UNROLL for (int k = 0; k < HD_DIFFUSE_ZK; ++k)
        HD_UNROLL for (int j = 0; j < HD_DIFFUSE_YK; ++j) {
            int r = k * HD_DIFFUSE_YK + j, x = hdk_diffuse_bx(bx, o0, j, k, jacobi);
            int y = hdk_mini(y0 + j, g.y - 1), z = hdk_mini(z0 + k, g.z - 1), xc = hdk_mini(x, g.x - 1);
            sp[r] = 0.0f; /* inout arguments are copied in: defined first (hd_prelude_glsl.h) */
            dn[r] = 0.0f;
            src[r] = hdk_diffuse_own(0, xc, y, z, c, rgb, rhs, sp[r], agr, dn[r]);
            hdk_diffuse_texel(x - 1, y, z, c, rgb, ag, sl[r], pl[r]);
            hdk_diffuse_texel(x + 1, y, z, c, rgb, ag, sr[r], pr[r]);
            if (jacobi != 0) {
                sc[r] = sp[r];
                pc[r] = HD_GET(phi, 0, xc, y, z + c * g.z);
            } else {
                int o = x & 1; /* red-black: the adjacent rows' voxel is x - 1 (o = 1) or x + 1 */
                sc[r] = o != 0 ? sl[r] : sr[r];
                pc[r] = o != 0 ? pl[r] : pr[r];
            }
        }
    HD_UNROLL for (int k = 0; k < HD_DIFFUSE_ZK; ++k) {
        int z = hdk_mini(z0 + k, g.z - 1);
        hdk_diffuse_texel(hdk_diffuse_bx(bx, o0, 0, k, jacobi), hdk_maxi(y0 - 1, 0), z, c, rgb, ag, sym[k], pym[k]);
        hdk_diffuse_texel(hdk_diffuse_bx(bx, o0, HD_DIFFUSE_YK - 1, k, jacobi), hdk_mini(y0 + HD_DIFFUSE_YK, g.y - 1), z, c,
                         rgb, ag, syp[k], pyp[k]);
    }
    HD_UNROLL for (int j = 0; j < HD_DIFFUSE_YK; ++j) {
        int y = hdk_mini(y0 + j, g.y - 1);
        hdk_diffuse_texel(hdk_diffuse_bx(bx, o0, j, 0, jacobi), y, hdk_maxi(z0 - 1, 0), c, rgb, ag, szm[j], pzm[j]);
        hdk_diffuse_texel(hdk_diffuse_bx(bx, o0, j, HD_DIFFUSE_ZK - 1, jacobi), y, hdk_mini(z0 + HD_DIFFUSE_ZK, g.z - 1), c,
                         rgb, ag, szp[j], pzp[j]);
    }
    HD_UNROLL for (int k = 0; k < HD_DIFFUSE_ZK; ++k)
        HD_UNROLL for (int j = 0; j < HD_DIFFUSE_YK; ++j) {
            int r = k * HD_DIFFUSE_YK + j, x = hdk_diffuse_bx(bx, o0, j, k, jacobi), y = y0 + j, z = z0 + k;
            int rym = hdk_maxi(r - 1, 0), ryp = hdk_mini(r + 1, HD_DB - 1);
            int rzm = hdk_maxi(r - HD_DIFFUSE_YK, 0), rzp = hdk_mini(r + HD_DIFFUSE_YK, HD_DB - 1);
            float den = 0.0f;
            v[r] = hdk_diffuse_update_of(src[r], dn[r], sp[r], sl[r], sr[r], j > 0 ? sc[rym] : sym[k],
                                        j < HD_DIFFUSE_YK - 1 ? sc[ryp] : syp[k], k > 0 ? sc[rzm] : szm[j],
                                        k < HD_DIFFUSE_ZK - 1 ? sc[rzp] : szp[j], pl[r], pr[r],
                                        j > 0 ? pc[rym] : pym[k], j < HD_DIFFUSE_YK - 1 ? pc[ryp] : pyp[k],
                                        k > 0 ? pc[rzm] : pzm[j], k < HD_DIFFUSE_ZK - 1 ? pc[rzp] : pzp[j],
                                        x > 0 ? 1 : 0, x < g.x - 1 ? 1 : 0, y > 0 ? 1 : 0, y < g.y - 1 ? 1 : 0,
                                        z > 0 ? 1 : 0, z < g.z - 1 ? 1 : 0, den);
            v[r] = v[r] / den;
        }
    HD_UNROLL for (int k = 0; k < HD_DIFFUSE_ZK; ++k)
        HD_UNROLL for (int j = 0; j < HD_DIFFUSE_YK; ++j) {
            int r = k * HD_DIFFUSE_YK + j, x = hdk_diffuse_bx(bx, o0, j, k, jacobi), y = y0 + j, z = z0 + k;
            if (x < g.x && y < g.y && z < g.z) {
                if (jacobi != 0) HD_SET(phi2, 0, x, y, z + c * g.z, v[r]);
                else HD_SET(phi, 0, x, y, z + c * g.z, v[r]);
            }
        }
}
#endif

void main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    ivec4 g = HD_PRM(gdims);
#if HD_STAGE == HD_STAGE_CLASSIFY
    if (x < g.x && y < g.y && z < g.z) hdk_classify_voxel(x, y, z);
#elif HD_STAGE == HD_STAGE_DIRECT
    /* over the list of voxels whose E is read, hd_pc.x entries from entry hd_pc.y, in rows of the
       dispatch's width */
    int j = x + y * int(gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (j < hd_pc.x) hdk_direct_index(int(dl[hd_pc.y + j]));
#elif HD_STAGE == HD_STAGE_DIFFUSE
    hdk_diffuse_block(x, y, z);
#elif HD_STAGE == HD_STAGE_PROJECT
    /* hd_pc.y > 1: the dispatch's rows in blocks of hd_pc.z, block b drawing the image's block
       b * hd_pc.y mod blocks (backends/hd_gpu.h, hd__gpu_row_stride), so that each contiguous run
       of work groups covers the whole image (a reduced frame's upsample pass is
       HD_STAGE_UPSAMPLE's) */
    if (hd_pc.y > 1) {
        int rb = hd_pc.z, nb = (HD_PRM(image).y + rb - 1) / rb;
        y = int(uint(y / rb) * uint(hd_pc.y) % uint(nb)) * rb + y % rb;
    }
    if (x < HD_PRM(image).x && y < HD_PRM(image).y) hdk_project_pixel(x, y);
#elif HD_STAGE == HD_STAGE_UPSAMPLE
    /* with HD_FLAG_BLEND, HD_REST_BLEND's blend passes (hd_k_upsample.h) */
    if (x < HD_PRM(image).x && y < HD_PRM(image).y) {
        if ((HD_PRM(counts).z & HD_FLAG_BLEND) != 0) hdk_blend_pixel(x, y);
        else hdk_upsample_pixel(x, y);
    }
#elif HD_STAGE == HD_STAGE_CONVECT
    if (x < g.x && y < g.y && z < g.z) hdk_convect_voxel(x, y, z, hd_pc.z);
#elif HD_STAGE == HD_STAGE_SUM_LIGHT
    if (x < g.x && y < g.y && z < g.z) hdk_sum_light_voxel(x, y, z, hd_pc.z, hd_pc.w);
#elif HD_STAGE == HD_STAGE_PATH
    if (x < HD_PRM(image).x && y < HD_PRM(image).y) hdk_path_pixel(x, y);
#elif HD_STAGE == HD_STAGE_LIGHT_SUM
    /* z over the channels' slices (z + c * gz) */
    if (x < g.x && y < g.y && z < g.z * g.w) hdk_light_sum_voxel(x, y, z);
#else
#error "hd_entry_glsl.h: define HD_STAGE"
#endif
}
