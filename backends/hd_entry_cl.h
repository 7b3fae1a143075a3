/* hd_entry_cl.h - OpenCL C text, not C: the __kernel entry points of the OpenCL backend. Each
   fills the private hd__kctx from its arguments and calls one shared stage function; the math
   is all in backends/kernels/. Embedded by scripts/embed-kernels after the shared sources.
   The buffers are restrict (the backend never binds one buffer twice): PoCL's compiler may then
   keep the parameter block's loads out of its work-item loops, which lets it vectorise them. */
#define HD__CL_BUFFERS __constant hd__kparams *restrict p, __global const float *restrict vol, \
    __global const float *restrict tf, __global const float *restrict maj, __global float *restrict sig, \
    __global float *restrict E, __global float *restrict phi, __global float *restrict phi2, \
    __global float *restrict img
#define HD__CL_KCTX hd__kctx k; \
    k.p = p; k.vol = vol; k.tf = tf; k.maj = maj; k.sig = sig; k.E = E; k.phi = phi; \
    k.phi2 = phi2; k.img = img; k.lv = 0; k.lv2 = 0; k.flags = p->counts.z; k.dx = 0

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

/* Diffusion: one work-item per voxel, global size (gx, gy, gz * channels), one x-row per
   work-group (hd_opencl.h), so PoCL runs each row as one loop and vectorises it along x; the
   previous kernel (one work-item per row, the shared hd_diffuse_row) ran scalar, 3x slower
   (docs/DESIGN-OPENCL.md). What keeps the loop vectorisable:
   - the solver, the RGB flag and the boundary are literals (eight kernels: the flags through
     the HD_DIFFUSE_FLAGS hook, K->flags), so the update's only selects are on the in-grid
     tests; the prelude forces inlining;
   - every work-item stores: red-black computes both colours and a work-item of the other
     colour writes its voxel's own value back, bit for bit (a conditional store made LLVM sink
     the update under the condition and give up). No voxel changes value while it is read:
     the updated colour reads only the other one, whose rewrites store the bits already there;
   - K->dx = x makes the neighbour addresses affine (the prelude's HD_GET);
   - the buffer arguments are restrict, so the parameter block's loads leave the loop. */
#define HD__CL_DIFFUSE(name, bits, jacobi) \
    __kernel void name(HD__CL_BUFFERS, int parity) \
    { \
        HD__CL_KCTX; \
        int gx = p->gdims.x, gy = p->gdims.y, gz = p->gdims.z; \
        int x = (int)get_global_id(0), y = (int)get_global_id(1); \
        int z = (int)get_global_id(2) % gz, c = (int)get_global_id(2) / gz; \
        size_t i = (size_t)(((c * gz + z) * gy + y) * gx) + get_global_id(0); \
        float den, num, v; \
        k.flags = (k.flags & ~(HD_FLAG_RGB_SCATTERING | HD_FLAG_SURFACE_BOUNDARY)) | (bits); \
        k.dx = get_global_id(0); \
        num = hd_diffuse_terms(&k, x, y, z, c, &den); \
        v = num / den; \
        if (jacobi) { \
            phi2[i] = v; \
        } else { \
            uint mine = 0u - (uint)(((x + y + z + parity) & 1) == 0); \
            phi[i] = as_float((as_uint(v) & mine) | (as_uint(phi[i]) & ~mine)); \
        } \
    }
HD__CL_DIFFUSE(hd_k_diffuse, 0, 0)
HD__CL_DIFFUSE(hd_k_diffuse_rgb, HD_FLAG_RGB_SCATTERING, 0)
HD__CL_DIFFUSE(hd_k_diffuse_surface, HD_FLAG_SURFACE_BOUNDARY, 0)
HD__CL_DIFFUSE(hd_k_diffuse_surface_rgb, HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_RGB_SCATTERING, 0)
HD__CL_DIFFUSE(hd_k_diffuse_jacobi, 0, 1)
HD__CL_DIFFUSE(hd_k_diffuse_jacobi_rgb, HD_FLAG_RGB_SCATTERING, 1)
HD__CL_DIFFUSE(hd_k_diffuse_jacobi_surface, HD_FLAG_SURFACE_BOUNDARY, 1)
HD__CL_DIFFUSE(hd_k_diffuse_jacobi_surface_rgb, HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_RGB_SCATTERING, 1)

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
