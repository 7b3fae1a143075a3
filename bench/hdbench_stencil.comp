/* hdbench_stencil.comp - GLSL 4.50: the plain constant-coefficient 7-point Jacobi stencil that
   bench/hdbench_vulkan.c runs beside the library's diffusion sweep, for scale:
       b = (rhs + sum of the 6 neighbours of a) / 7,  zero outside the grid,
   one voxel per invocation, 64 x 1 x 1 work groups (the library's shape). Compiled 3 times by
   `scripts/build-spirv --bench`: HD_STENCIL_SSBO=0 reads and writes r32f storage image3Ds (the
   library's choice), HD_STENCIL_SSBO=1 std430 storage buffers (the alternative the choice was
   made against); HD_STENCIL_SSBO=2 the same buffers read as vec4, 4 x-consecutive voxels per
   invocation (the x-packed form, bench/hdbench_sweep.comp's PSTENCIL on buffers). Bindings: 0 a
   (read), 1 b (written), 2 rhs (read); push constants: the grid dimensions. */
layout(local_size_x = 64, local_size_y = 1, local_size_z = 1) in;
layout(push_constant) uniform hd_stencil_pc { ivec4 dims; };
#if HD_STENCIL_SSBO == 2
/* x-packed: 4 x-consecutive voxels per vec4 (the same bytes as the float grid), one vec4 per
   invocation: does a 16-byte load cost lavapipe less per voxel than 4 float loads? */
layout(std430, binding = 0) readonly buffer hd_a_block { vec4 a[]; };
layout(std430, binding = 1) writeonly buffer hd_b_block { vec4 b[]; };
layout(std430, binding = 2) readonly buffer hd_rhs_block { vec4 rhs[]; };
#define AT(x, y, z) ((((z) * dims.y) + (y)) * (dims.x / 4) + (x))
#elif HD_STENCIL_SSBO
layout(std430, binding = 0) readonly buffer hd_a_block { float a[]; };
layout(std430, binding = 1) writeonly buffer hd_b_block { float b[]; };
layout(std430, binding = 2) readonly buffer hd_rhs_block { float rhs[]; };
#define AT(x, y, z) ((((z) * dims.y) + (y)) * dims.x + (x))
#define LOAD(x, y, z) a[AT(x, y, z)]
#define RHS(x, y, z) rhs[AT(x, y, z)]
#define STORE(x, y, z, v) b[AT(x, y, z)] = (v)
#else
layout(binding = 0, r32f) uniform readonly image3D a;
layout(binding = 1, r32f) uniform writeonly image3D b;
layout(binding = 2, r32f) uniform readonly image3D rhs;
#define LOAD(x, y, z) imageLoad(a, ivec3((x), (y), (z))).r
#define RHS(x, y, z) imageLoad(rhs, ivec3((x), (y), (z))).r
#define STORE(x, y, z, v) imageStore(b, ivec3((x), (y), (z)), vec4((v), 0.0f, 0.0f, 0.0f))
#endif

void main()
{
#if HD_STENCIL_SSBO == 2
    int t = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    int W = dims.x / 4;
    if (t >= W || y >= dims.y || z >= dims.z) return;
    vec4 c = a[AT(t, y, z)], s4 = rhs[AT(t, y, z)];
    s4 += vec4(0.0f, c.x, c.y, c.z) + vec4(c.y, c.z, c.w, 0.0f);
    if (t > 0) s4.x += a[AT(t - 1, y, z)].w;
    if (t < W - 1) s4.w += a[AT(t + 1, y, z)].x;
    if (y > 0) s4 += a[AT(t, y - 1, z)];
    if (y < dims.y - 1) s4 += a[AT(t, y + 1, z)];
    if (z > 0) s4 += a[AT(t, y, z - 1)];
    if (z < dims.z - 1) s4 += a[AT(t, y, z + 1)];
    b[AT(t, y, z)] = s4 * (1.0f / 7.0f);
#else
    int x = int(gl_GlobalInvocationID.x), y = int(gl_GlobalInvocationID.y), z = int(gl_GlobalInvocationID.z);
    float s;
    if (x >= dims.x || y >= dims.y || z >= dims.z) return;
    s = RHS(x, y, z);
    if (x > 0) s += LOAD(x - 1, y, z);
    if (x < dims.x - 1) s += LOAD(x + 1, y, z);
    if (y > 0) s += LOAD(x, y - 1, z);
    if (y < dims.y - 1) s += LOAD(x, y + 1, z);
    if (z > 0) s += LOAD(x, y, z - 1);
    if (z < dims.z - 1) s += LOAD(x, y, z + 1);
    STORE(x, y, z, s * (1.0f / 7.0f));
#endif
}
