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
    k.phi2 = phi2; k.img = img; k.lsum = 0; k.ptab = 0; k.ptab_n = 0; k.dep = 0; k.env = 0; k.lv = 0; k.lv2 = 0; k.flags = p->counts.z; \
    k.hx = (p->gdims.x + 1) >> 1; k.gy = p->gdims.y; k.cx = 0; k.cp = 0; k.cid = 0; \
    k.Eh = (__global half *)E; k.phih = (__global half *)phi; k.phi2h = (__global half *)phi2; k.f16 = 0

/* The projection's program (HD_CL_PROJECTION_PROGRAM, hd_opencl.h's hd__cl_build) holds the
   projection's entry points only, at the end of this file; the main program everything else. */
#ifndef HD_CL_PROJECTION_PROGRAM
/* One work-item per voxel: global size = illumination grid (x, y, z). */
__kernel void hd_k_classify(HD__CL_BUFFERS)
{
    HD__CL_KCTX;
    hdk_classify_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2));
}

/* One work-item per entry of the list of voxels whose E is read (hd__direct_mask), count
   entries from entry first: tracking cost varies per voxel, so fine-grained items balance. */
/* Each stage that touches E or phi has a twin with a _half suffix whose k.f16 is the literal 1:
   binary16 storage (params.illumination_precision), float32 arithmetic. */
#define HD__CL_DIRECT(name, is16) \
    __kernel void name(HD__CL_BUFFERS, __global const uint *restrict list, int count, int first, \
                       __global const float *restrict env) \
    { \
        HD__CL_KCTX; \
        k.f16 = (is16); \
        k.env = env; \
        if ((int)get_global_id(0) < count) hdk_direct_index(&k, (int)list[first + (int)get_global_id(0)]); \
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
        num = hdk_diffuse_terms(&k, x, y, z, c, &den); \
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

/* lsum = E + phi: one work-item per voxel, global size = illumination grid (x, y, z * channels). */
#define HD__CL_LIGHT_SUM(name, is16) \
    __kernel void name(HD__CL_BUFFERS, __global float *restrict lsum) \
    { \
        HD__CL_KCTX; \
        k.f16 = (is16); \
        k.lsum = lsum; \
        hdk_light_sum_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2)); \
    }
HD__CL_LIGHT_SUM(hd_k_light_sum, 0)
HD__CL_LIGHT_SUM(hd_k_light_sum_half, 1)

/* CD: one upwind convection step of light l, reading lv and writing lv2; one work-item per
   voxel (global size = illumination grid). */
__kernel void hd_k_convect(HD__CL_BUFFERS, __global const float *lv, __global float *lv2, int l)
{
    HD__CL_KCTX;
    k.lv = lv;
    k.lv2 = lv2;
    hdk_convect_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), l);
}

/* CD: adds light l's volume into E (first != 0: overwrites); one work-item per voxel. */
#define HD__CL_SUM_LIGHT(name, is16) \
    __kernel void name(HD__CL_BUFFERS, __global const float *lv, int l, int first) \
    { \
        HD__CL_KCTX; \
        k.lv = lv; \
        k.f16 = (is16); \
        hdk_sum_light_voxel(&k, (int)get_global_id(0), (int)get_global_id(1), (int)get_global_id(2), l, first); \
    }
HD__CL_SUM_LIGHT(hd_k_sum_light, 0)
HD__CL_SUM_LIGHT(hd_k_sum_light_half, 1)

/* PT_SS / PT_MS: one path per pixel (x, y); dep: the host's depth buffer (a placeholder while
   depth_dims.z is 0); lsum: HD's summed light, read by a resting view's refinement (image.w > 0,
   hd_k_path.h; unread, and possibly null, otherwise); env the environment's tables (a
   placeholder while env.x is 0). */
__kernel void hd_k_path(HD__CL_BUFFERS, __global const float *restrict dep, __global const float *restrict lsum,
                        __global const float *restrict env)
{
    HD__CL_KCTX;
    k.dep = dep;
    k.lsum = lsum;
    k.env = env;
    hdk_path_pixel(&k, (int)get_global_id(0), (int)get_global_id(1));
}

/* ---- HD_SOLVER_MULTIGRID: the per-voxel passes of hd_opencl.h's hd__be_mg_* -------------------
   The math is hd_k_multigrid.h's; the V-cycle's smoothing is the diffusion kernels above, run on a
   level's own parameter block (its dims, 1 / h^2, h and HD_FLAG_DIFFUSE_RHS) and buffers. Every
   grid of the solver (each level's sigma_t, right-hand side, correction and residual, conjugate
   gradients' vectors) is stored in the colour layout of its own dims, the layout those kernels
   read; the kernels here reach a grid through a context made from its parameter block
   (hd__cl_mg_ctx: cx = cp = cid = 0, so HD_GET / HD_SET give any voxel's slot), one work-item
   per voxel of the grid they write (global size (gx, gy, gz * channels)), or per row for the dot
   products (global size (gy, gz * channels)). */
HD_FN hd__kctx hd__cl_mg_ctx(__constant hd__kparams *p)
{
    hd__kctx k;
    k.p = p; k.vol = 0; k.tf = 0; k.maj = 0; k.sig = 0; k.E = 0; k.phi = 0; k.phi2 = 0; k.img = 0; k.lv = 0;
    k.lv2 = 0; k.Eh = 0; k.phih = 0; k.phi2h = 0; k.f16 = 0; k.flags = p->counts.z;
    k.hx = (p->gdims.x + 1) >> 1; k.gy = p->gdims.y; k.cx = 0; k.cp = 0; k.cid = 0;
    return k;
}
/* Stores into voxel (x, y, zz) of one of K's grids (HD_SET names its context K). */
HD_FN void hd__cl_mg_set_sig(const hd__kctx *K, int x, int y, int zz, float v) { HD_SET(sig, 0, x, y, zz, v); }
HD_FN void hd__cl_mg_set_E(const hd__kctx *K, int x, int y, int zz, float v) { HD_SET(E, 0, x, y, zz, v); }
HD_FN void hd__cl_mg_set_phi(const hd__kctx *K, int x, int y, int zz, float v) { HD_SET(phi, 0, x, y, zz, v); }
HD_FN void hd__cl_mg_set_phi2(const hd__kctx *K, int x, int y, int zz, float v) { HD_SET(phi2, 0, x, y, zz, v); }
HD_FN float hd__cl_mg_get_E(const hd__kctx *K, int x, int y, int zz) { return HD_GET(E, 0, x, y, zz); }
HD_FN float hd__cl_mg_get_phi(const hd__kctx *K, int x, int y, int zz) { return HD_GET(phi, 0, x, y, zz); }
HD_FN float hd__cl_mg_get_phi2(const hd__kctx *K, int x, int y, int zz) { return HD_GET(phi2, 0, x, y, zz); }

/* A coarse level's sigma_t (all its channels: global z = gz * sigma_t channels) from the level
   above (pf, fsig). */
__kernel void hd_k_mg_sig(__constant hd__kparams *pf, __constant hd__kparams *pc, __global float *fsig,
                          __global float *csig)
{
    hd__kctx kf = hd__cl_mg_ctx(pf), kc = hd__cl_mg_ctx(pc);
    int X = (int)get_global_id(0), Y = (int)get_global_id(1), zz = (int)get_global_id(2), gz = pc->gdims.z;
    kf.sig = fsig;
    kc.sig = csig;
    hd__cl_mg_set_sig(&kc, X, Y, zz, hdk_mg_coarse_sig(&kf, X, Y, zz % gz, zz / gz));
}

/* A level's float residual f - A phi into phi2 (the level's residual buffer; sig, E = the
   right-hand side, phi = the correction: the smoothing's bindings): the diffusion kernels' own
   work-item mapping, colour `parity` per pass (so loads are contiguous and the loop vectorises),
   and hdk_diffuse_terms' num - den phi, hdk_diffuse_residual's and the CPU's hd__cpu_residual_row's
   expression. Padding slots get a finite, unused value, as in the sweep. */
#define HD__CL_MG_RESIDUAL(name, bits) \
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
        num = hdk_diffuse_terms(&k, x, y, z, c, &den); \
        HD_SET(phi2, 0, x, y, z + c * gz, num - den * HD_GET(phi, 0, x, y, z + c * gz)); \
    }
HD__CL_MG_RESIDUAL(hd_k_mg_residual, 0)
HD__CL_MG_RESIDUAL(hd_k_mg_residual_rgb, HD_FLAG_RGB_SCATTERING)
HD__CL_MG_RESIDUAL(hd_k_mg_residual_surface, HD_FLAG_SURFACE_BOUNDARY)
HD__CL_MG_RESIDUAL(hd_k_mg_residual_surface_rgb, HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_RGB_SCATTERING)

/* The restriction's first half, as the CPU's row: the share hdk_mg_restrict_line of every fine
   column x of coarse row (Y, Z), channel c, into the row buffer `line` (x-fastest, rows of
   2 * hx, the fine grid's padded row), the columns of one parity per pass: the fine loads then
   use the diffusion's addressing (K->cx = x) and are contiguous. An odd grid's last item reads
   its rows' padding slot (finite, as the sweep's) and writes a column nobody reads. */
__kernel void hd_k_mg_restrict_line(__constant hd__kparams *restrict pf, __constant hd__kparams *restrict pc,
                                    __global float *restrict fres, __global float *restrict line, int parity,
                                    __global float *restrict fsig)
{
    hd__kctx kf = hd__cl_mg_ctx(pf);
    int gz = pc->gdims.z, Y = (int)get_global_id(1), zz = (int)get_global_id(2), x = 2 * (int)get_global_id(0) + parity;
    kf.phi = fres;
    kf.sig = fsig; /* the mask hdk_mg_medium */
    kf.cx = x; kf.cp = parity; kf.cid = get_global_id(0);
    line[((size_t)zz * pc->gdims.y + Y) * (size_t)(2 * kf.hx) + (size_t)x] = hdk_mg_restrict_line(&kf, x, Y, zz % gz, zz / gz);
}

/* Its second half: a coarse level's right-hand side, the shares of fine columns 2 X - 1 .. 2 X + 2
   combined in order (hdk_mg_restrict_x); its correction cphi starts at 0. */
__kernel void hd_k_mg_restrict(__constant hd__kparams *restrict pf, __constant hd__kparams *restrict pc,
                               __global float *restrict line, __global float *restrict crhs, __global float *restrict cphi)
{
    hd__kctx kc = hd__cl_mg_ctx(pc);
    int X = (int)get_global_id(0), Y = (int)get_global_id(1), zz = (int)get_global_id(2), gx = pf->gdims.x;
    __global const float *row = line + ((size_t)zz * pc->gdims.y + Y) * (size_t)(2 * ((gx + 1) >> 1));
    float s = 0.0f;
    for (int t = 0; t < 4; ++t) {
        int x = 2 * X - 1 + t;
        if (x >= 0 && x < gx) s = hdk_mg_restrict_x(s, t, row[x]);
    }
    kc.E = crhs; kc.phi = cphi;
    hd__cl_mg_set_E(&kc, X, Y, zz, s);
    hd__cl_mg_set_phi(&kc, X, Y, zz, 0.0f);
}

/* Adds the coarse correction cphi, interpolated, to the fine correction fphi: the diffusion's
   work-item mapping over the fine grid, colour `parity` per pass, so the fine grid's load and
   store are contiguous (the coarse loads are gathers in any mapping: a coarse row's colours
   alternate with x). */
__kernel void hd_k_mg_prolong(__constant hd__kparams *restrict pf, __constant hd__kparams *restrict pc,
                              __global float *restrict cphi, __global float *restrict fphi, int parity,
                              __global float *restrict fsig)
{
    hd__kctx kf = hd__cl_mg_ctx(pf), kc = hd__cl_mg_ctx(pc);
    int gz = pf->gdims.z, y = (int)get_global_id(1), z = (int)get_global_id(2) % gz, c = (int)get_global_id(2) / gz;
    int cp = (y + z + parity) & 1, x = 2 * (int)get_global_id(0) + cp, xk = hdk_mini(x, pf->gdims.x - 1);
    kc.phi = cphi;
    kf.phi = fphi;
    kf.sig = fsig; /* the mask hdk_mg_medium */
    kf.cx = x; kf.cp = cp; kf.cid = get_global_id(0);
    hd__cl_mg_set_phi(&kf, x, y, z + c * gz,
                      hd__cl_mg_get_phi(&kf, x, y, z + c * gz) +
                          hdk_mg_prolong(&kc, xk, y, z, c) * hdk_mg_medium(&kf, 0, xk, y, z));
}

/* p = z + beta p, then z = 0. */
__kernel void hd_k_mg_dir(__constant hd__kparams *p, __global float *z, __global float *dir, float beta)
{
    hd__kctx k = hd__cl_mg_ctx(p);
    int x = (int)get_global_id(0), y = (int)get_global_id(1), zz = (int)get_global_id(2);
    k.E = z; k.phi = dir;
    hd__cl_mg_set_phi(&k, x, y, zz, hdk_mg_dir_of(hd__cl_mg_get_E(&k, x, y, zz), hd__cl_mg_get_phi(&k, x, y, zz), beta));
    hd__cl_mg_set_E(&k, x, y, zz, 0.0f);
}

#ifdef HD_MG_F64
/* The fine grid's residual in double (hdk_mg_res_f64): f - A (phi + lo) with use_lo, into out
   (negate: -(f - A phi), conjugate gradients' q = A p with E = 0). The diffusion's work-item
   mapping (colour `parity` per pass) and literal boundary and RGB flags, as the residual above. */
#define HD__CL_MG_RES_F64(name, surface, rgb) \
    __kernel void name(__constant hd__kparams *restrict p, __global float *restrict sig, __global float *restrict E, \
                       __global float *restrict phi, __global float *restrict lo, __global float *restrict out, \
                       int parity, int use_lo, int negate) \
    { \
        hd__kctx k = hd__cl_mg_ctx(p), ko; \
        int gx = p->gdims.x, gy = p->gdims.y, gz = p->gdims.z, y = (int)get_global_id(1); \
        int z = (int)get_global_id(2) % gz, c = (int)get_global_id(2) / gz; \
        int cp = (y + z + parity) & 1, x = 2 * (int)get_global_id(0) + cp; \
        float v; \
        k.sig = sig; k.E = E; k.phi = phi; k.phi2 = lo; \
        k.cx = x; k.cp = cp; k.cid = get_global_id(0); \
        ko = k; \
        ko.phi = out; \
        v = (float)hdk_mg_res_f64(&k, x, y, z, c, surface, rgb, use_lo, x > 0 ? 1 : 0, x < gx - 1 ? 1 : 0, y > 0 ? 1 : 0, \
                                 y < gy - 1 ? 1 : 0, z > 0 ? 1 : 0, z < gz - 1 ? 1 : 0); \
        hd__cl_mg_set_phi(&ko, x, y, z + c * gz, negate != 0 ? -v : v); \
    }
HD__CL_MG_RES_F64(hd_k_mg_res_f64, 0, 0)
HD__CL_MG_RES_F64(hd_k_mg_res_f64_rgb, 0, 1)
HD__CL_MG_RES_F64(hd_k_mg_res_f64_surface, 1, 0)
HD__CL_MG_RES_F64(hd_k_mg_res_f64_surface_rgb, 1, 1)

/* dot[r] = <a, b> of row r = zz * gy + y (hdk_mg_dot_row); the host sums the rows in order. */
__kernel void hd_k_mg_dot(__constant hd__kparams *p, __global float *a, __global float *b, __global double *dot)
{
    hd__kctx k = hd__cl_mg_ctx(p);
    int y = (int)get_global_id(0), zz = (int)get_global_id(1);
    k.E = a; k.phi = b;
    dot[(size_t)zz * p->gdims.y + y] = hdk_mg_dot_row(&k, y, zz);
}

/* phi + lo += alpha p in double (hdk_mg_update_of). */
__kernel void hd_k_mg_update(__constant hd__kparams *p, __global float *phi, __global float *lo, __global float *dir,
                             double alpha)
{
    hd__kctx k = hd__cl_mg_ctx(p);
    int x = (int)get_global_id(0), y = (int)get_global_id(1), zz = (int)get_global_id(2);
    float l, f;
    k.phi = phi; k.phi2 = lo; k.E = dir;
    l = hd__cl_mg_get_phi2(&k, x, y, zz);
    f = hdk_mg_update_of(hd__cl_mg_get_phi(&k, x, y, zz), &l, hd__cl_mg_get_E(&k, x, y, zz), alpha);
    hd__cl_mg_set_phi(&k, x, y, zz, f);
    hd__cl_mg_set_phi2(&k, x, y, zz, l);
}

/* Surface boundary: the empty voxels of colour `colour` ((x + y + z) & 1) get phi = the sweeps'
   extrapolation, lo = -phi (hdk_diffuse_extrapolate; p the fine parameters, without the
   right-hand-side flag). */
__kernel void hd_k_mg_extrap(__constant hd__kparams *p, __global float *sig, __global float *E, __global float *phi,
                             __global float *lo, int colour)
{
    hd__kctx k = hd__cl_mg_ctx(p);
    int x = (int)get_global_id(0), y = (int)get_global_id(1), zz = (int)get_global_id(2), gz = p->gdims.z;
    float v = 0.0f;
    k.sig = sig; k.E = E; k.phi = phi; k.phi2 = lo;
    if (((x + y + zz % gz + colour) & 1) != 0) return;
    if (hdk_diffuse_extrapolate(&k, x, y, zz % gz, zz / gz, &v) != 0) {
        hd__cl_mg_set_phi(&k, x, y, zz, v);
        hd__cl_mg_set_phi2(&k, x, y, zz, -v);
    }
}
#endif
#endif /* !HD_CL_PROJECTION_PROGRAM */

#ifdef HD_CL_PROJECTION_PROGRAM
/* One work-item per pixel (x, y); the global size is rounded up to whole work-groups
   (hd__be_project), so items past the image's width or height do nothing. lsum and the table
   (ptab_n entries) as hd_k_project.h reads them, dep the host's depth buffer (a placeholder while
   depth_dims.z is 0), env the environment's tables (shown behind the volume while background.w
   is 1; a placeholder while env.x is 0). */
#define HD__CL_PROJECT(name, is16) \
    __kernel void name(HD__CL_BUFFERS, __global float *restrict lsum, __global const float *restrict ptab, int ptab_n, \
                       __global const float *restrict dep, __global const float *restrict env) \
    { \
        int px = (int)get_global_id(0), py = (int)get_global_id(1); \
        HD__CL_KCTX; \
        k.f16 = (is16); \
        k.lsum = lsum; k.ptab = ptab; k.ptab_n = ptab_n; k.dep = dep; k.env = env; \
        if (px >= p->image.x || py >= p->image.y) return; \
        hdk_project_pixel(&k, px, py); \
    }
HD__CL_PROJECT(hd_k_project, 0)
HD__CL_PROJECT(hd_k_project_half, 1)

/* A reduced frame's upsample pass (hd_k_upsample.h's arithmetic), one work-item per run of
   HD_CL_UPSAMPLE_RUN pixels of a row (global size (ceil(w / run), h)), the row's source rows
   found once and each pixel's 4 floats loaded and stored together: on PoCL a work-item per pixel
   through hdk_upsample_pixel was most of a reduced frame's time (docs/PERFORMANCE.md). With
   HD_FLAG_BLEND the same runs take HD_REST_BLEND's blend passes (hdk_blend_pixel). */
#define HD_CL_UPSAMPLE_RUN 16
__kernel void hd_k_upsample(HD__CL_BUFFERS)
{
    int w = p->image.x, h = p->image.y, s = p->region.y, lw = (w + s - 1) / s, lh = (h + s - 1) / s;
    int px = (int)get_global_id(0) * HD_CL_UPSAMPLE_RUN, py = (int)get_global_id(1), end, x0, x1 = 0, y0, y1 = 0;
    float wx = 0.0f, wy = 0.0f;
    __global const float *r0, *r1;
    if (py >= h) return;
    if ((p->counts.z & HD_FLAG_BLEND) != 0) { /* HD_REST_BLEND's blend passes instead */
        HD__CL_KCTX;
        for (end = min(px + HD_CL_UPSAMPLE_RUN, w); px < end; ++px) hdk_blend_pixel(&k, px, py);
        return;
    }
    y0 = hdk_upsample_axis(py, h, lh, &y1, &wy);
    r0 = img + ((size_t)w * h + (size_t)y0 * lw) * 4;
    r1 = img + ((size_t)w * h + (size_t)y1 * lw) * 4;
    for (end = min(px + HD_CL_UPSAMPLE_RUN, w); px < end; ++px) {
        float4 a, b, c, d, top, bot;
        x0 = hdk_upsample_axis(px, w, lw, &x1, &wx);
        a = vload4(x0, r0); b = vload4(x1, r0); c = vload4(x0, r1); d = vload4(x1, r1);
        top = a + wx * (b - a);
        bot = c + wx * (d - c);
        vstore4(top + wy * (bot - top), (size_t)py * w + px, img);
    }
}
#endif
