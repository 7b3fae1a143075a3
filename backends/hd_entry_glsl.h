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
#ifndef HD_DIFFUSE_ZK
#define HD_DIFFUSE_ZK 1 /* voxels per invocation of the diffusion stage (Vulkan: hd_bind_vk_glsl.h) */
#endif
#ifndef HD_DIFFUSE_JACOBI
#define HD_DIFFUSE_JACOBI hd_pc.y /* Jacobi (1) or red-black (0); Vulkan: a constant per pipeline */
#endif

void main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    ivec4 g = HD_PRM(gdims);
#if HD_STAGE == HD_STAGE_CLASSIFY
    if (x < g.x && y < g.y && z < g.z) hd_classify_voxel(x, y, z);
#elif HD_STAGE == HD_STAGE_DIRECT
    if (x < g.x && y < g.y && z < g.z) hd_direct_voxel(x, y, z);
#elif HD_STAGE == HD_STAGE_DIFFUSE
    /* HD_DIFFUSE_ZK voxels per invocation, one per slice z * ZK + k (slices run over channels *
       depth). Red-black: in each slice, invocation x relaxes voxel 2x + ((y + z + parity) & 1) of
       its row, hd_diffuse_row's voxels, in place; Jacobi: voxel x, phi -> phi2. The same terms
       and division as hd_diffuse_row. All the voxels' terms come before their stores: a red-black
       half-sweep reads only the other colour's phi (Jacobi reads phi, writes phi2), so the order
       changes no value, and with no store between them the loads of a texel two voxels share (the
       black voxel between two red ones of the column) can be merged. Lanes past the grid compute
       at a clamped voxel (every load in bounds) and store nothing. */
    int jacobi = HD_DIFFUSE_JACOBI, nz = g.z * g.w;
    float v[HD_DIFFUSE_ZK];
    for (int k = 0; k < HD_DIFFUSE_ZK; ++k) {
        int zs = hd_mini(z * HD_DIFFUSE_ZK + k, nz - 1);
        int c = (zs >= g.z ? 1 : 0) + (zs >= 2 * g.z ? 1 : 0), zz = zs - c * g.z; /* zs / g.z, <= 3 channels */
        int xv = hd_mini(jacobi != 0 ? x : 2 * x + ((y + zz + hd_pc.x) & 1), g.x - 1);
        float den;
        v[k] = hd_diffuse_terms(xv, y, zz, c, den);
        v[k] = v[k] / den;
    }
    for (int k = 0; k < HD_DIFFUSE_ZK; ++k) {
        int zs = z * HD_DIFFUSE_ZK + k;
        int c = (zs >= g.z ? 1 : 0) + (zs >= 2 * g.z ? 1 : 0), zz = zs - c * g.z;
        int xv = jacobi != 0 ? x : 2 * x + ((y + zz + hd_pc.x) & 1);
        if (xv < g.x && y < g.y && zs < nz) {
            if (jacobi != 0) HD_SET(phi2, 0, xv, y, zs, v[k]);
            else HD_SET(phi, 0, xv, y, zs, v[k]);
        }
    }
#elif HD_STAGE == HD_STAGE_PROJECT
    if (x < HD_PRM(image).x && y < HD_PRM(image).y) hd_project_pixel(x, y);
#elif HD_STAGE == HD_STAGE_CONVECT
    if (x < g.x && y < g.y && z < g.z) hd_convect_voxel(x, y, z, hd_pc.z);
#elif HD_STAGE == HD_STAGE_SUM_LIGHT
    if (x < g.x && y < g.y && z < g.z) hd_sum_light_voxel(x, y, z, hd_pc.z, hd_pc.w);
#elif HD_STAGE == HD_STAGE_PATH
    if (x < HD_PRM(image).x && y < HD_PRM(image).y) hd_path_pixel(x, y);
#else
#error "hd_entry_glsl.h: define HD_STAGE"
#endif
}
