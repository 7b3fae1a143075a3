/* hd_k_diffuse.h - stage 2 of HD and CD: one relaxation sweep of the diffusion equation
   -div(D grad phi) + sigma_a phi = sigma_s E  (shared source)
   on the illumination grid, D = 1 / (3 sigma_t'), sigma_t' = sigma_a + sigma_s (1 - g)
   = sigma_t (1 - albedo g). Face coefficients are the harmonic mean of the two voxels' D,
   2 / (3 (sigma'_i + sigma'_j)), floored so empty space stays finite. Each update is the paper's
   weighted sum of the 6 neighbours:
   phi_i = (sigma_s E_i + sum_j w_j phi_j) / (sigma_a + sum_j w_j),  w_j = D_ij / h^2.
   Two boundary conditions (params.diffusion_boundary):
   - box (default, METHOD.md): phi = 0 outside the box, reached through the voxel's own D. Empty
     voxels are solved too, with the floored D: air conducts light to the box faces almost
     freely, so every tissue surface acts nearly as phi = 0.
   - surface (HD_FLAG_SURFACE_BOUNDARY): empty voxels (sigma' below half the floor) hold phi = 0
     and a face between a medium voxel and an empty one (or the box) carries the Marshak vacuum
     condition J = phi_s / 2 (no light enters from outside): conductance 1 / (h / (2D) + 2) per
     area, i.e. w = 1 / (h^2 / (2 D) + 2 h) = 1 / (1.5 sigma' h^2 + 2 h). */

/* The flags word the diffusion tests (RGB scattering, boundary). A backend may define it as a
   compile-time constant per pipeline (Vulkan: a specialization constant, hd_bind_vk_glsl.h), so
   the untaken variant costs nothing where both sides of a branch would run. */
#ifndef HD_DIFFUSE_FLAGS
#define HD_DIFFUSE_FLAGS HD_PRM(counts).z
#endif

/* sigma' = sigma_t (1 - albedo g) of grid voxel j (image coordinates x, y, z) in channel c.
   With RGB scattering the albedo of channel c is albedo * TF colour_c(j), read from the sigma_t
   grid's channel 1 + c; otherwise ag = 1 - albedo g, the same for every voxel. */
HD_FN float hd_diffuse_sigp(HD_KARGS int j, int x, int y, int z, int c, int rgb, float ag)
{
    float st = HD_GET(sig, j, x, y, z);
    if (rgb != 0) {
        int gz = HD_PRM(gdims).z, nvox = HD_PRM(gdims).x * HD_PRM(gdims).y * gz;
        float aj = HD_PRM(medium).y * HD_GET(sig, j + (1 + c) * nvox, x, y, z + (1 + c) * gz);
        return st * (1.0f - aj * HD_PRM(medium).z);
    }
    return ag * st;
}

/* The weight w = D_ij / h^2 of the face between two voxels with sigma' spi and spj: the harmonic
   mean of their D = 1 / (3 sigma'), 2 / (3 (spi + spj)), floored at fl so empty space stays finite,
   times the axis' 1 / h^2 (scale). A face on the box boundary passes spj = spi: phi = 0 outside
   with the voxel's own D. Both voxels of a face get the same bits (a + b == b + a in IEEE
   arithmetic). */
HD_FN float hd_diffuse_face(float scale, float spi, float spj, float fl)
{
    return scale * (0.6666667f / hd_maxf(spi + spj, fl));
}

/* The weight of a face between medium (sigma' spi) and vacuum under the surface boundary: the
   Marshak condition at distance h / 2 from the voxel centre (see the top of this file). */
HD_FN float hd_diffuse_vacuum_face(float h, float spi)
{
    return 1.0f / (1.5f * spi * h * h + 2.0f * h);
}

/* One face of the surface boundary's update: the weight toward a neighbour with sigma' spj that
   lies in the grid (inside != 0), else toward the box's outside; empty neighbours and the outside
   are vacuum, whose phi is 0, so they add to the denominator only. */
HD_FN float hd_diffuse_surface_face(float scale, float h, float spi, float spj, int inside, float fl,
                                    HD_INOUT(float) open)
{
    float empty = inside != 0 ? (spj + spj < fl ? 1.0f : 0.0f) : 1.0f;
    HD_DEREF(open) = 1.0f - empty;
    return empty != 0.0f ? hd_diffuse_vacuum_face(h, spi) : hd_diffuse_face(scale, spi, spj, fl);
}

/* The voxel's own part of its update: returns the source term (sigma_s E, or with rhs the
   right-hand side E holds) and gives its absorption sigma_a in *dn, its sigma' in *sp and
   1 - albedo g in *ag (with RGB scattering the albedo of channel c). */
HD_FN float hd_diffuse_own(HD_KARGS int i, int x, int y, int z, int c, int rgb, int rhs, HD_INOUT(float) sp,
                           HD_INOUT(float) ag, HD_INOUT(float) dn)
{
    int nvox = HD_PRM(gdims).x * HD_PRM(gdims).y * HD_PRM(gdims).z, gz = HD_PRM(gdims).z;
    int ic = i + c * nvox, zc = z + c * gz;
    float a = rgb != 0 ? HD_PRM(medium).y * HD_GET(sig, i + (1 + c) * nvox, x, y, z + (1 + c) * gz) : HD_PRM(medium).y;
    float st = HD_GET(sig, i, x, y, z);
    HD_DEREF(ag) = 1.0f - a * HD_PRM(medium).z;
    HD_DEREF(sp) = st * HD_DEREF(ag);
    HD_DEREF(dn) = (1.0f - a) * st;
    return rhs != 0 ? HD_GET(E, ic, x, y, zc) : a * st * HD_GET(E, ic, x, y, zc);
}

/* The numerator of voxel (x,y,z)'s update in channel c under the box boundary; its denominator
   goes to *den. in_xm ... in_zp say whether the neighbour on each side lies inside the grid, rgb
   whether the albedo is per channel (HD_FLAG_RGB_SCATTERING): the CPU backend passes literals for
   interior voxels so the compiler drops the tests (see hd_cpu.h). With rgb = 0 and a white TF the
   RGB path computes the same bits as the grey one. rhs (HD_FLAG_DIFFUSE_RHS): E holds the whole
   right-hand side (multigrid's coarse levels solve for a correction), not the direct light. */
HD_FN float hd_diffuse_terms_box(HD_KARGS int x, int y, int z, int c, int in_xm, int in_xp,
                                 int in_ym, int in_yp, int in_zm, int in_zp, int rgb, int rhs, HD_INOUT(float) den)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x;
    int ic = i + c * gx * gy * gz, zc = z + c * gz, sxy = gx * gy;
    float fl = HD_PRM(grid).w, sp, ag, dn;
    float num = hd_diffuse_own(HD_KPASS i, x, y, z, c, rgb, rhs, HD_REF(sp), HD_REF(ag), HD_REF(dn));
    float w;
    w = hd_diffuse_face(HD_PRM(grid).x, sp, in_xm != 0 ? hd_diffuse_sigp(HD_KPASS i - 1, x - 1, y, z, c, rgb, ag) : sp, fl);
    if (in_xm != 0) num += w * HD_GET(phi, ic - 1, x - 1, y, zc);
    dn += w;
    w = hd_diffuse_face(HD_PRM(grid).x, sp, in_xp != 0 ? hd_diffuse_sigp(HD_KPASS i + 1, x + 1, y, z, c, rgb, ag) : sp, fl);
    if (in_xp != 0) num += w * HD_GET(phi, ic + 1, x + 1, y, zc);
    dn += w;
    w = hd_diffuse_face(HD_PRM(grid).y, sp, in_ym != 0 ? hd_diffuse_sigp(HD_KPASS i - gx, x, y - 1, z, c, rgb, ag) : sp, fl);
    if (in_ym != 0) num += w * HD_GET(phi, ic - gx, x, y - 1, zc);
    dn += w;
    w = hd_diffuse_face(HD_PRM(grid).y, sp, in_yp != 0 ? hd_diffuse_sigp(HD_KPASS i + gx, x, y + 1, z, c, rgb, ag) : sp, fl);
    if (in_yp != 0) num += w * HD_GET(phi, ic + gx, x, y + 1, zc);
    dn += w;
    w = hd_diffuse_face(HD_PRM(grid).z, sp, in_zm != 0 ? hd_diffuse_sigp(HD_KPASS i - sxy, x, y, z - 1, c, rgb, ag) : sp, fl);
    if (in_zm != 0) num += w * HD_GET(phi, ic - sxy, x, y, zc - 1);
    dn += w;
    w = hd_diffuse_face(HD_PRM(grid).z, sp, in_zp != 0 ? hd_diffuse_sigp(HD_KPASS i + sxy, x, y, z + 1, c, rgb, ag) : sp, fl);
    if (in_zp != 0) num += w * HD_GET(phi, ic + sxy, x, y, zc + 1);
    dn += w;
    HD_DEREF(den) = dn;
    return num;
}

/* The same under the surface boundary (HD_FLAG_SURFACE_BOUNDARY): an empty voxel gets num 0 and
   den 1 (phi = 0); a medium voxel's faces toward empty neighbours or the box's outside carry the
   Marshak weight and no neighbour term. Every select is arithmetic, so the CPU's row loop stays
   branch-free. */
HD_FN float hd_diffuse_terms_surface(HD_KARGS int x, int y, int z, int c, int in_xm, int in_xp,
                                     int in_ym, int in_yp, int in_zm, int in_zp, int rgb, int rhs, HD_INOUT(float) den)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x;
    int ic = i + c * gx * gy * gz, zc = z + c * gz, sxy = gx * gy;
    float fl = HD_PRM(grid).w, sp, ag, dn;
    float num = hd_diffuse_own(HD_KPASS i, x, y, z, c, rgb, rhs, HD_REF(sp), HD_REF(ag), HD_REF(dn));
    float w, open, self = sp + sp < fl ? 0.0f : 1.0f;
    w = hd_diffuse_surface_face(HD_PRM(grid).x, HD_PRM(gridh).x, sp, in_xm != 0 ? hd_diffuse_sigp(HD_KPASS i - 1, x - 1, y, z, c, rgb, ag) : 0.0f, in_xm, fl, HD_REF(open));
    if (in_xm != 0) num += open * w * HD_GET(phi, ic - 1, x - 1, y, zc);
    dn += w;
    w = hd_diffuse_surface_face(HD_PRM(grid).x, HD_PRM(gridh).x, sp, in_xp != 0 ? hd_diffuse_sigp(HD_KPASS i + 1, x + 1, y, z, c, rgb, ag) : 0.0f, in_xp, fl, HD_REF(open));
    if (in_xp != 0) num += open * w * HD_GET(phi, ic + 1, x + 1, y, zc);
    dn += w;
    w = hd_diffuse_surface_face(HD_PRM(grid).y, HD_PRM(gridh).y, sp, in_ym != 0 ? hd_diffuse_sigp(HD_KPASS i - gx, x, y - 1, z, c, rgb, ag) : 0.0f, in_ym, fl, HD_REF(open));
    if (in_ym != 0) num += open * w * HD_GET(phi, ic - gx, x, y - 1, zc);
    dn += w;
    w = hd_diffuse_surface_face(HD_PRM(grid).y, HD_PRM(gridh).y, sp, in_yp != 0 ? hd_diffuse_sigp(HD_KPASS i + gx, x, y + 1, z, c, rgb, ag) : 0.0f, in_yp, fl, HD_REF(open));
    if (in_yp != 0) num += open * w * HD_GET(phi, ic + gx, x, y + 1, zc);
    dn += w;
    w = hd_diffuse_surface_face(HD_PRM(grid).z, HD_PRM(gridh).z, sp, in_zm != 0 ? hd_diffuse_sigp(HD_KPASS i - sxy, x, y, z - 1, c, rgb, ag) : 0.0f, in_zm, fl, HD_REF(open));
    if (in_zm != 0) num += open * w * HD_GET(phi, ic - sxy, x, y, zc - 1);
    dn += w;
    w = hd_diffuse_surface_face(HD_PRM(grid).z, HD_PRM(gridh).z, sp, in_zp != 0 ? hd_diffuse_sigp(HD_KPASS i + sxy, x, y, z + 1, c, rgb, ag) : 0.0f, in_zp, fl, HD_REF(open));
    if (in_zp != 0) num += open * w * HD_GET(phi, ic + sxy, x, y, zc + 1);
    dn += w;
    HD_DEREF(den) = self * dn + (1.0f - self);
    return self * num;
}

/* The update's numerator and denominator at (x, y, z) under the configured boundary. */
HD_FN float hd_diffuse_terms(HD_KARGS int x, int y, int z, int c, HD_INOUT(float) den)
{
    int rgb = (HD_DIFFUSE_FLAGS & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0;
    int rhs = (HD_DIFFUSE_FLAGS & HD_FLAG_DIFFUSE_RHS) != 0 ? 1 : 0;
    int in_xm = x > 0 ? 1 : 0, in_xp = x < HD_PRM(gdims).x - 1 ? 1 : 0;
    int in_ym = y > 0 ? 1 : 0, in_yp = y < HD_PRM(gdims).y - 1 ? 1 : 0;
    int in_zm = z > 0 ? 1 : 0, in_zp = z < HD_PRM(gdims).z - 1 ? 1 : 0;
    if ((HD_DIFFUSE_FLAGS & HD_FLAG_SURFACE_BOUNDARY) != 0)
        return hd_diffuse_terms_surface(HD_KPASS x, y, z, c, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, rgb, rhs, den);
    return hd_diffuse_terms_box(HD_KPASS x, y, z, c, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, rgb, rhs, den);
}

/* Relaxes the voxels x0, x0 + xstep, ... of row (y, z), channel c. Red-black Gauss-Seidel:
   xstep 2 and x0 chosen by the parity, in place. Jacobi: xstep 1, reads phi, writes phi2. */
HD_FN void hd_diffuse_row(HD_KARGS int y, int z, int c, int parity, int jacobi)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int base = (c * gz + z) * gy * gx + y * gx;
    int x = jacobi != 0 ? 0 : ((y + z + parity) & 1);
    int xstep = jacobi != 0 ? 1 : 2;
    for (; x < gx; x += xstep) {
        float den;
        float num = hd_diffuse_terms(HD_KPASS x, y, z, c, HD_REF(den));
        if (jacobi != 0) HD_SET(phi2, base + x, x, y, z + c * gz, num / den);
        else HD_SET(phi, base + x, x, y, z + c * gz, num / den);
    }
}

/* Residual of the discrete equation at one voxel, and its right-hand side in *rhs: the solver's
   convergence measure (relative residual = |r| / |rhs| over the grid). */
HD_FN float hd_diffuse_residual(HD_KARGS int x, int y, int z, int c, HD_INOUT(float) rhs)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x, ic = i + c * gx * gy * gz;
    float den;
    float num = hd_diffuse_terms(HD_KPASS x, y, z, c, HD_REF(den));
    HD_DEREF(rhs) = (HD_DIFFUSE_FLAGS & HD_FLAG_DIFFUSE_RHS) != 0 ? HD_GET(E, ic, x, y, z + c * gz)
                  : HD_PRM(medium).y * HD_GET(sig, i, x, y, z) * HD_GET(E, ic, x, y, z + c * gz);
    return num - den * HD_GET(phi, ic, x, y, z + c * gz);
}
