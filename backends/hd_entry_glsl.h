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

void main()
{
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    ivec4 g = HD_PRM(gdims);
#if HD_STAGE == HD_STAGE_CLASSIFY
    if (x < g.x && y < g.y && z < g.z) hd_classify_voxel(x, y, z);
#elif HD_STAGE == HD_STAGE_DIRECT
    if (x < g.x && y < g.y && z < g.z) hd_direct_voxel(x, y, z);
#elif HD_STAGE == HD_STAGE_DIFFUSE
    /* one voxel per invocation; z runs over channels * depth. Red-black: invocation x relaxes
       voxel 2x + ((y + z + parity) & 1) of its row, hd_diffuse_row's voxels, in place;
       Jacobi: voxel x, phi -> phi2. The same terms and division as hd_diffuse_row. */
    int c = z / g.z, zz = z - c * g.z;
    int jacobi = hd_pc.y;
    int xv = jacobi != 0 ? x : 2 * x + ((y + zz + hd_pc.x) & 1);
    if (xv < g.x && y < g.y && c < g.w) {
        float den;
        float num = hd_diffuse_terms(xv, y, zz, c, den);
        if (jacobi != 0) HD_SET(phi2, 0, xv, y, z, num / den);
        else HD_SET(phi, 0, xv, y, z, num / den);
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
