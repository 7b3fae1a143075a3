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
    k.phi2 = phi2; k.img = img; k.lv = 0; k.lv2 = 0; k.flags = p->counts.z; \
    k.hx = (p->gdims.x + 1) >> 1; k.gy = p->gdims.y; k.cx = 0; k.cp = 0; k.cid = 0; \
    k.Eh = (__global half *)E; k.phih = (__global half *)phi; k.phi2h = (__global half *)phi2; k.f16 = 0

/* One work-item per voxel: global size = illumination grid (x, y, z). */
__kernel void hd_k_classify(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hd_classify_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2));
}

/* One work-item per voxel: tracking cost varies per voxel, so fine-grained items balance. */
/* Each stage that touches E or phi has a twin with a _half suffix whose k.f16 is the literal 1:
   binary16 storage (params.illumination_precision), float32 arithmetic. */
#define HD__CL_DIRECT(name, is16) \
    __kernel void name(HD__CL_BUFFERS) \
    { \
        HD__CL_KCTX; \
        k.f16 = (is16); \
        hd_direct_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2)); \
    }
HD__CL_DIRECT(hd_k_direct, 0)
HD__CL_DIRECT(hd_k_direct_half, 1)

/* Diffusion: one work-item per voxel of the colour being updated, global size ((gx + 1) / 2,
   gy, gz * channels), one x-row per work-group (hd_opencl.h), so PoCL runs each row as one loop
   and vectorises it. The grids are stored colour by colour (the prelude's HD_GET): the
   work-item with packed index id updates x = 2 id + cp, cp = (y + z + parity) & 1 the row's
   first x of the colour, and every neighbour it reads is of the other colour at packed index
   id - 1 + cp, id + cp (x -+ 1) or id (y -+ 1, z -+ 1): contiguous loads. Red-black: half-sweep
   `parity` updates the voxels with (x + y + z) & 1 == parity in place, as the CPU does (so the
   sweeps stay bit-identical); Jacobi: the same two passes, reading phi and writing phi2. What
   keeps the loop vectorisable:
   - the solver, the RGB flag and the boundary are literals (eight kernels: the flags through
     the HD_DIFFUSE_FLAGS hook, K->flags), so the update's only selects are on the in-grid
     tests; the prelude forces inlining;
   - every work-item stores, unconditionally (a conditional store made LLVM sink the update
     under the condition and give up): with odd gx the last work-item of a row whose colour
     starts at x = 1 has x = gx, outside the grid, and writes its (finite, unused) result into
     that row's padding slot, which no voxel reads (its x + 1 neighbour test is false);
   - cx = x and cid = id make the addresses affine in the work-item index;
   - the buffer arguments are restrict, so the parameter block's loads leave the loop.
   Before this layout the kernel computed both colours of a whole row and kept one (stride-2
   stores and loads gathered): twice the arithmetic of a compute-bound update. */
#define HD__CL_DIFFUSE(name, bits, jacobi, is16) \
    __kernel void name(HD__CL_BUFFERS, int parity) \
    { \
        HD__CL_KCTX; \
        const hd__kctx *K = &k; \
        int gz = p->gdims.z, y = (int)get_global_id(1); \
        int z = (int)get_global_id(2) % gz, c = (int)get_global_id(2) / gz; \
        int cp = (y + z + parity) & 1, x = 2 * (int)get_global_id(0) + cp; \
        float den, num; \
        k.flags = (k.flags & ~(HD_FLAG_RGB_SCATTERING | HD_FLAG_SURFACE_BOUNDARY)) | (bits); \
        k.cx = x; \
        k.cp = cp; \
        k.cid = get_global_id(0); \
        k.f16 = (is16); \
        num = hd_diffuse_terms(&k, x, y, z, c, &den); \
        if (jacobi) HD_SET(phi2, 0, x, y, z + c * gz, num / den); \
        else HD_SET(phi, 0, x, y, z + c * gz, num / den); \
    }
#define HD__CL_DIFFUSE_SET(suffix, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse##suffix, 0, 0, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_rgb##suffix, HD_FLAG_RGB_SCATTERING, 0, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_surface##suffix, HD_FLAG_SURFACE_BOUNDARY, 0, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_surface_rgb##suffix, HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_RGB_SCATTERING, 0, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_jacobi##suffix, 0, 1, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_jacobi_rgb##suffix, HD_FLAG_RGB_SCATTERING, 1, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_jacobi_surface##suffix, HD_FLAG_SURFACE_BOUNDARY, 1, is16) \
    HD__CL_DIFFUSE(hd_k_diffuse_jacobi_surface_rgb##suffix, HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_RGB_SCATTERING, 1, is16)
HD__CL_DIFFUSE_SET(, 0)
HD__CL_DIFFUSE_SET(_half, 1)

/* One work-item per pixel (x, y). */
#define HD__CL_PROJECT(name, is16) \
    __kernel void name(HD__CL_BUFFERS) \
    { \
        HD__CL_KCTX; \
        k.f16 = (is16); \
        hd_project_pixel(&k, (int)get_global_id(0), (int)get_global_id(1)); \
    }
HD__CL_PROJECT(hd_k_project, 0)
HD__CL_PROJECT(hd_k_project_half, 1)

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
#define HD__CL_SUM_LIGHT(name, is16) \
    __kernel void name(HD__CL_BUFFERS, __global const float *lv, int l, int first) \
    { \
        HD__CL_KCTX; \
        k.lv = lv; \
        k.f16 = (is16); \
        hd_sum_light_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), l, first); \
    }
HD__CL_SUM_LIGHT(hd_k_sum_light, 0)
HD__CL_SUM_LIGHT(hd_k_sum_light_half, 1)

/* PT_SS / PT_MS: one path per pixel (x, y). */
__kernel void hd_k_path(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hd_path_pixel(&k, (int)get_global_id(0), (int)get_global_id(1));
}
