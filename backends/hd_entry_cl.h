/* hd_entry_cl.h - OpenCL C text, not C: the __kernel entry points of the OpenCL backend. Each
   fills the private hd__kctx from its arguments and calls one shared stage function; the math
   is all in backends/kernels/. Embedded by scripts/embed-kernels after the shared sources. */
#define HD__CL_BUFFERS __constant hd__kparams *p, __global const float *vol, \
    __global const float *tf, __global const float *maj, __global float *sig, __global float *E, \
    __global float *phi, __global float *phi2, __global float *img
#define HD__CL_KCTX hd__kctx k; \
    k.p = p; k.vol = vol; k.tf = tf; k.maj = maj; k.sig = sig; k.E = E; k.phi = phi; \
    k.phi2 = phi2; k.img = img; k.lv = 0; k.lv2 = 0

/* One work-item per voxel: global size = illumination grid (x, y, z). */
__kernel void hd_k_classify(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hd_classify_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2));
}

/* One work-item per voxel: tracking cost varies per voxel, so fine-grained items balance. */
__kernel void hd_k_direct(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hd_direct_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2));
}

/* One work-item per x-row (global size y, z, channels): the row's loop vectorises and streams;
   one item per voxel was several times slower on PoCL (docs/DESIGN-OPENCL.md). */
__kernel void hd_k_diffuse(HD__CL_BUFFERS, int parity, int jacobi)
{
    HD__CL_KCTX;
    hd_diffuse_row(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), parity, jacobi);
}

/* One work-item per pixel (x, y). */
__kernel void hd_k_project(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hd_project_pixel(&k, (int)get_global_id(0), (int)get_global_id(1));
}

/* CD: one upwind convection step of light l, reading lv and writing lv2; one work-item per
   voxel (global size = illumination grid). */
__kernel void hd_k_convect(HD__CL_BUFFERS, __global const float *lv, __global float *lv2, int l)
{
    HD__CL_KCTX;
    k.lv = lv;
    k.lv2 = lv2;
    hd_convect_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), l);
}

/* CD: adds light l's volume into E (first != 0: overwrites); one work-item per voxel. */
__kernel void hd_k_sum_light(HD__CL_BUFFERS, __global const float *lv, int l, int first)
{
    HD__CL_KCTX;
    k.lv = lv;
    hd_sum_light_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), l, first);
}

/* PT_SS / PT_MS: one path per pixel (x, y). */
__kernel void hd_k_path(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hd_path_pixel(&k, (int)get_global_id(0), (int)get_global_id(1));
}
