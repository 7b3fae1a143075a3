/* hd_k_multigrid.h - the per-voxel math of HD_SOLVER_MULTIGRID (conjugate gradients
   preconditioned by a geometric multigrid V-cycle; the design and its measurements are in
   docs/DESIGN-MULTIGRID.md): the coarse levels' sigma_t, the V-cycle's transfers, and
   conjugate gradients' double-summed residual, dot products and updates (shared source).
   The smoothing and the levels' float residual are hd_k_diffuse.h's, with HD_FLAG_DIFFUSE_RHS.
   Conventions, so one text serves every backend's layout:
   - K is the kernel context of the grid a function READS (its parameter block gives that grid's
     dims); the caller stores the returned value into the other grid itself. A source grid other
     than sigma_t is reached as K's phi (the restriction's fine residual, the prolongation's
     coarse correction); the fine residual's low part of the iterate is K's phi2.
   - Every load passes both the x-fastest channel-planar index (C) and the image coordinates,
     channel c at z + c * gz (the OpenCL colour layout, image3Ds), as hd_k_diffuse.h does.
   - Each function does its arithmetic in the order the CPU reference did before it moved here, so
     the CPU's bits did not change (hashes of phi, E and the image compared).
   Double precision: core in C and GLSL 4.00+, the extension cl_khr_fp64 in OpenCL C 1.2. Without
   it (HD_MG_F64 undefined) the double functions are left out and the OpenCL backend reports the
   solver unsupported (hd_opencl.h). HD_D is HD_F's double twin. */
#ifdef HD_LANG_CL
#ifdef cl_khr_fp64
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
#define HD_MG_F64 1
#endif
#else
#define HD_MG_F64 1
#endif
#ifdef HD_LANG_GLSL
#define HD_D(v) double(v)
#else
#define HD_D(v) ((double)(v))
#endif

/* ---- the coarse levels' sigma_t ------------------------------------------------------------- */
/* sigma_t of coarse voxel (X, Y, Z) from its 8 children in the fine grid K (a coarse grid has half
   its fine grid's voxels per axis rounded down, so all 8 exist), sigma_t channel ch.
   Channel 0: the harmonic mean, i.e. the mean of the children's D, so a coarse voxel conducts like
   its most conductive part (the arithmetic mean of sigma_t made voxels of soft tissue and bone, or
   of air and tissue, insulators, and the cycle diverged on a sphere in air). Empty children
   (sigma' = sigma_t (1 - albedo g) below half the floor, hdk_mg_medium) do not count while at
   least 4 of the 8 are medium: the mean is over the medium children. With fewer, the surface
   boundary makes the coarse voxel empty and the box boundary takes the mean over every child,
   air floored at 1e-4 per world unit (air conducts). Why the box boundary ignores air in a mostly
   medium voxel: with the transfers masked to medium voxels (hdk_mg_medium) the coarse grid's
   medium is then the fine grid's to within a fine voxel, where one air child used to make the
   voxel an air-like conductor (24^3 sphere, 12 steps: 3.8e-6 with every child, 1.9e-6 so).
   RGB scattering's colour channels 1..3: the plain mean. Children in z, y, x order. */
HD_FN float hdk_mg_coarse_sig(HD_KARGS int X, int Y, int Z, int ch)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int surface = (HD_PRM(counts).z & HD_FLAG_SURFACE_BOUNDARY) != 0 ? 1 : 0;
    float empty_below = 0.5f * HD_PRM(grid).w / (1.0f - HD_PRM(medium).y * HD_PRM(medium).z);
    float s = 0.0f, sa = 0.0f;
    int n = 0, na = 0;
    for (int k = 2 * Z; k <= 2 * Z + 1; ++k)
        for (int j = 2 * Y; j <= 2 * Y + 1; ++j)
            for (int i = 2 * X; i <= 2 * X + 1; ++i) {
                float v = HD_GET(sig, ((ch * gz + k) * gy + j) * gx + i, i, j, k + ch * gz);
                if (ch != 0) {
                    s += v;
                    n += 1;
                } else if (!(v < empty_below)) {
                    s += 1.0f / v;
                    n += 1;
                } else {
                    sa += 1.0f / (v > 1e-4f ? v : 1e-4f);
                    na += 1;
                }
            }
    if (ch != 0) return s / HD_F(n);
    if (n >= 4) return HD_F(n) / s;
    return surface != 0 ? 0.0f : HD_F(n + na) / (s + sa);
}

/* ---- the transfers' mask ----------------------------------------------------------------------- */
/* 1 if voxel (x, y, z) of K's grid (channel-0 index j of its sigma_t) is medium or the boundary is
   the surface one, else 0: under the box boundary the restriction reads the residual, and the
   prolongation writes the correction, of medium voxels only (M stays symmetric: R = (D P)^T / 8
   for the prolongation D P, D this mask). Why: air's floored D makes its faces about 1e4 times
   tissue's conductance; trilinear interpolation spread a quarter of the tissue's correction into
   the air beside it, an error of that much energy that CG's line search scaled every step down
   to nothing (24^3 sphere, max error after 12 steps 9.1e-3 unmasked, 3.8e-6 masked; the
   smoothers alone carry air's own correction). The surface boundary's empty voxels are identity
   rows already, and its transfers keep their bits (a product by 1). hdk_mg_medium_of: the mask of a voxel whose sigma_t the caller loaded (the
   CPU's row passes load a row once: in the colour layout a load by coordinates is a gather). */
HD_FN float hdk_mg_medium_of(HD_KARGS float sig)
{
    float empty_below = 0.5f * HD_PRM(grid).w / (1.0f - HD_PRM(medium).y * HD_PRM(medium).z);
    if ((HD_PRM(counts).z & HD_FLAG_SURFACE_BOUNDARY) != 0) return 1.0f;
    return sig < empty_below ? 0.0f : 1.0f;
}

/* The mask loaded at grid voxel j (image coordinates x, y, z). */
HD_FN float hdk_mg_medium(HD_KARGS int j, int x, int y, int z)
{
    return hdk_mg_medium_of(HD_KPASS HD_GET(sig, j, x, y, z));
}

/* ---- restriction R = P^T / 8 (full weighting) ------------------------------------------------- */
/* The full-weighting weight of fine index 2 C - 1 + t (t = 0..3) for coarse index C: 1/8 3/8 3/8
   1/8, the transpose of the prolongation's 3/4, 1/4 halved (the 8 children's volume): a weighted
   mean, as both sides of the equation are per unit volume. */
HD_FN float hdk_mg_fw(int t)
{
    return t == 0 || t == 3 ? 0.125f : 0.375f;
}

/* Fine column x's share of coarse row (Y, Z), channel c: the fine residual (K's phi, K the fine
   grid) of the up to 16 fine rows 2 Z - 1 + a, 2 Y - 1 + b (a, b = 0..3) at x, weighted
   fw(a) fw(b), each residual times its voxel's hdk_mg_medium (K's sigma_t), summed in a, b order
   (rows outside the grid skipped by a branch: the select form hdk_mg_prolong uses made the OpenCL
   step slower, docs/DESIGN-MULTIGRID.md, and the rows' tests are uniform along x anyway). A
   backend computes it once per fine x and coarse row (the CPU a vector loop per row, OpenCL a
   pass into a row buffer) and combines four of them per coarse voxel, in order, with
   hdk_mg_restrict_x. */
/* hdk_mg_restrict_line's step for fine row (a, b) on values the caller loaded: the residual res
   and its voxel's hdk_mg_medium m (the same operations in the same order: the same bits). */
HD_FN float hdk_mg_restrict_term(float line, int a, int b, float res, float m)
{
    return line + (hdk_mg_fw(a) * hdk_mg_fw(b)) * (res * m);
}

HD_FN float hdk_mg_restrict_line(HD_KARGS int x, int Y, int Z, int c)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    float line = 0.0f;
    for (int a = 0; a < 4; ++a) {
        int z = 2 * Z - 1 + a;
        if (z < 0 || z >= gz) continue;
        for (int b = 0; b < 4; ++b) {
            int y = 2 * Y - 1 + b;
            if (y < 0 || y >= gy) continue;
            line = hdk_mg_restrict_term(line, a, b, HD_GET(phi, ((c * gz + z) * gy + y) * gx + x, x, y, z + c * gz),
                                       hdk_mg_medium(HD_KPASS (z * gy + y) * gx + x, x, y, z));
        }
    }
    return line;
}

/* s plus the share of fine column 2 X - 1 + t (its hdk_mg_restrict_line value `line`). */
HD_FN float hdk_mg_restrict_x(float s, int t, float line)
{
    return s + hdk_mg_fw(t) * line;
}

/* ---- prolongation P: trilinear interpolation ---------------------------------------------------- */
/* A fine voxel centre lies 1/4 coarse voxel from coarse voxel i / 2 (the near one, weight 3/4),
   toward its far neighbour (weight 1/4): i / 2 + 1 for odd i, i / 2 - 1 for even i. */
HD_FN int hdk_mg_far(int i)
{
    return (i & 1) != 0 ? (i >> 1) + 1 : (i >> 1) - 1;
}
HD_FN float hdk_mg_pw(int t)
{
    return t == 0 ? 0.75f : 0.25f;
}

/* The coarse correction (K's phi, K the coarse grid) interpolated at fine voxel (x, y, z), channel
   c: the 8 nearest coarse voxels, weights 3/4, 1/4 per axis, 0 beyond the coarse grid (a fixed
   linear map, so the V-cycle stays a symmetric preconditioner). Terms beyond the grid are skipped
   by a select on a clamped load, not a branch (the x tests vary along a row), which made the
   CPU's step faster (docs/DESIGN-MULTIGRID.md); skipping rather than adding a zero term keeps the
   CPU's bits (a zero term could flip the sign of a zero sum). The caller multiplies the value by
   the fine voxel's hdk_mg_medium (the restriction's mask) before adding it. */
/* hdk_mg_prolong's step for corner (a, b, t) inside the coarse grid on the coarse value u the
   caller loaded (the same operations in the same order: the same bits). */
HD_FN float hdk_mg_prolong_term(float v, int a, int b, int t, float u)
{
    return v + hdk_mg_pw(a) * hdk_mg_pw(b) * hdk_mg_pw(t) * u;
}

HD_FN float hdk_mg_prolong(HD_KARGS int x, int y, int z, int c)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    float v = 0.0f;
    for (int a = 0; a < 2; ++a) {
        int zc = a == 0 ? z >> 1 : hdk_mg_far(z), zk = hdk_clampi(zc, 0, gz - 1);
        for (int b = 0; b < 2; ++b) {
            int yc = b == 0 ? y >> 1 : hdk_mg_far(y), yk = hdk_clampi(yc, 0, gy - 1);
            for (int t = 0; t < 2; ++t) {
                int xc = t == 0 ? x >> 1 : hdk_mg_far(x), xk = hdk_clampi(xc, 0, gx - 1);
                float u = HD_GET(phi, ((c * gz + zk) * gy + yk) * gx + xk, xk, yk, zk + c * gz);
                v = zc >= 0 && zc < gz && yc >= 0 && yc < gy && xc >= 0 && xc < gx
                        ? hdk_mg_prolong_term(v, a, b, t, u) : v;
            }
        }
    }
    return v;
}

/* ---- conjugate gradients ---------------------------------------------------------------------- */
/* The search direction's update p = z + beta p (the caller then zeroes z: the next V-cycle's
   start and A p's zero right-hand side). */
HD_FN float hdk_mg_dir_of(float z, float p, float beta)
{
    return z + beta * p;
}

#ifdef HD_MG_F64
/* phi of grid voxel j (image coordinates x, y, zz), plus with use_lo the low part of the iterate
   (K's phi2), in double. */
HD_FN double hdk_mg_phi_f64(HD_KARGS int j, int x, int y, int zz, int use_lo)
{
    return HD_D(HD_GET(phi, j, x, y, zz)) + HD_D(use_lo != 0 ? HD_GET(phi2, j, x, y, zz) : 0.0f);
}

/* r minus one face's term of f - A phi at voxel (channel-0 index i, channel c) with sigma' sp,
   1 - albedo g ag and phi + lo pi, toward grid voxel j at (x, y, z) (z without the
   channel), inside != 0 if it lies in the grid; axis 0, 1, 2 = x, y, z. The weight is the exact
   per-face one (hdk_diffuse_face / hdk_diffuse_surface_face), the term a difference in double. */
HD_FN double hdk_mg_face_f64(HD_KARGS double r, double pi, float sp, float ag, int j, int x, int y, int z, int c,
                            int axis, int inside, int surface, int rgb, int use_lo)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z, nvox = gx * gy * gz;
    float fl = HD_PRM(grid).w, w, open = 1.0f;
    float scale = axis == 0 ? HD_PRM(grid).x : (axis == 1 ? HD_PRM(grid).y : HD_PRM(grid).z);
    float h = axis == 0 ? HD_PRM(gridh).x : (axis == 1 ? HD_PRM(gridh).y : HD_PRM(gridh).z);
    if (surface != 0) {
        float spj = inside != 0 ? hdk_diffuse_sigp(HD_KPASS j, x, y, z, c, rgb, ag) : 0.0f;
        w = hdk_diffuse_surface_face(scale, h, sp, spj, inside, fl, HD_REF(open));
    } else {
        float spj = inside != 0 ? hdk_diffuse_sigp(HD_KPASS j, x, y, z, c, rgb, ag) : sp;
        w = hdk_diffuse_face(scale, sp, spj, fl);
        open = inside != 0 ? 1.0f : 0.0f;
    }
    if (open != 0.0f) return r - HD_D(w) * (pi - hdk_mg_phi_f64(HD_KPASS j + c * nvox, x, y, z + c * gz, use_lo));
    return r - HD_D(w) * pi;
}

/* f - A (phi + lo) at voxel (x, y, z), channel c (use_lo: with K's phi2 as lo), with the shared
   kernel's own float coefficients: the same source term and sigma_a as hdk_diffuse_own, and each
   face's exact weight (one division per face, bit-identical from both voxels, so this A is
   exactly symmetric, as conjugate gradients need; the sweep puts an axis' two faces over one
   division, hdk_diffuse_box_axis, and relaxes the same A to within a few ulps), summed in double
   with every neighbour's term a difference w (phi_i - phi_j). Why: the float residual
   num - den phi cancels two terms of about den phi (den ~ 2e4 in soft tissue at h = 1/128), so it
   carries rounding of about 1e-4 of the source, and CG driven by it stalled at a relative
   residual of 1.2e-4 on the head CT at half resolution; the difference form in double is exact
   to the last bit of its float inputs. in_* say whether the neighbour on each side lies in the
   grid (the CPU passes literals for interior voxels). An empty voxel's row under the surface
   boundary is phi + lo = 0: its residual is -(phi + lo) (exactly 0: after each step phi holds the
   sweeps' extrapolation there and lo its negative, hdk_diffuse_extrapolate). */
HD_FN double hdk_mg_res_f64(HD_KARGS int x, int y, int z, int c, int surface, int rgb, int use_lo, int in_xm,
                           int in_xp, int in_ym, int in_yp, int in_zm, int in_zp)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z, sxy = gx * gy;
    int i = (z * gy + y) * gx + x, ic = i + c * sxy * gz;
    int rhs = (HD_PRM(counts).z & HD_FLAG_DIFFUSE_RHS) != 0 ? 1 : 0;
    float sp = 0.0f, ag = 0.0f, dn = 0.0f;
    float src = hdk_diffuse_own(HD_KPASS i, x, y, z, c, rgb, rhs, HD_REF(sp), HD_REF(ag), HD_REF(dn));
    double pi = hdk_mg_phi_f64(HD_KPASS ic, x, y, z + c * gz, use_lo), r = HD_D(src) - HD_D(dn) * pi;
    if (surface != 0 && sp + sp < HD_PRM(grid).w) return -pi;
    r = hdk_mg_face_f64(HD_KPASS r, pi, sp, ag, i - 1, x - 1, y, z, c, 0, in_xm, surface, rgb, use_lo);
    r = hdk_mg_face_f64(HD_KPASS r, pi, sp, ag, i + 1, x + 1, y, z, c, 0, in_xp, surface, rgb, use_lo);
    r = hdk_mg_face_f64(HD_KPASS r, pi, sp, ag, i - gx, x, y - 1, z, c, 1, in_ym, surface, rgb, use_lo);
    r = hdk_mg_face_f64(HD_KPASS r, pi, sp, ag, i + gx, x, y + 1, z, c, 1, in_yp, surface, rgb, use_lo);
    r = hdk_mg_face_f64(HD_KPASS r, pi, sp, ag, i - sxy, x, y, z - 1, c, 2, in_zm, surface, rgb, use_lo);
    r = hdk_mg_face_f64(HD_KPASS r, pi, sp, ag, i + sxy, x, y, z + 1, c, 2, in_zp, surface, rgb, use_lo);
    return r;
}

/* hdk_mg_res_f64 with the in-grid tests and the flags (K's counts.z) at run time. */
HD_FN double hdk_mg_res_f64_at(HD_KARGS int x, int y, int z, int c, int use_lo)
{
    int f = HD_PRM(counts).z;
    return hdk_mg_res_f64(HD_KPASS x, y, z, c, (f & HD_FLAG_SURFACE_BOUNDARY) != 0 ? 1 : 0,
                         (f & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0, use_lo, x > 0 ? 1 : 0,
                         x < HD_PRM(gdims).x - 1 ? 1 : 0, y > 0 ? 1 : 0, y < HD_PRM(gdims).y - 1 ? 1 : 0,
                         z > 0 ? 1 : 0, z < HD_PRM(gdims).z - 1 ? 1 : 0);
}

/* <a, b> over row (y, zz) of a grid (zz = z + c * gz), a = K's E, b = K's phi: products and sum in
   double, x in order. Rows are then summed in row order (on the host or in one fixed-order pass),
   so a dot product has the same bits for any thread count and on any backend. */
/* hdk_mg_dot_row's step on values the caller loaded (the CPU loads a row once, as its two colour
   half-rows): the same operations, so the same bits when x runs in order. */
HD_FN double hdk_mg_dot_term(double d, float a, float b)
{
    return d + HD_D(a) * HD_D(b);
}

HD_FN double hdk_mg_dot_row(HD_KARGS int y, int zz)
{
    int gx = HD_PRM(gdims).x, base = (zz * HD_PRM(gdims).y + y) * gx;
    double d = HD_D(0.0f);
    for (int x = 0; x < gx; ++x) d = hdk_mg_dot_term(d, HD_GET(E, base + x, x, y, zz), HD_GET(phi, base + x, x, y, zz));
    return d;
}

/* phi + lo += alpha p in double: returns the new phi, the sum rounded to float (what the
   projection reads), and leaves the rest in *lo. Why: with phi alone, every step's rounding (up
   to half an ulp per voxel) added a fresh rough error one line search cannot remove (the head
   CT's relative residual climbed from 4.7e-5 back to 1.1e-4 over 24 further steps). */
HD_FN float hdk_mg_update_of(float phi, HD_INOUT(float) lo, float p, double alpha)
{
    double t = HD_D(phi) + HD_D(HD_DEREF(lo)) + alpha * HD_D(p);
    float f = HD_F(t);
    HD_DEREF(lo) = HD_F(t - HD_D(f));
    return f;
}
#endif
