/* hd_k_diffuse.h - stage 2 of HD and CD: one relaxation sweep of the diffusion equation
   -div(D grad phi) + sigma_a phi = sigma_s E  (shared source)
   on the illumination grid, D = 1 / (3 sigma_t'), sigma_t' = sigma_a + sigma_s (1 - g)
   = sigma_t (1 - albedo g). Face coefficients are the harmonic mean of the two voxels' D,
   2 / (3 (sigma'_i + sigma'_j)), floored so empty space stays finite; outside the box phi = 0
   (vacuum) with the voxel's own D. Each update is the paper's weighted sum of the 6 neighbours:
   phi_i = (sigma_s E_i + sum_j w_j phi_j) / (sigma_a + sum_j w_j),  w_j = D_ij / h^2. */

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

/* The numerator of voxel (x,y,z)'s update in channel c; its denominator goes to *den.
   in_xm ... in_zp say whether the neighbour on each side lies inside the grid, rgb whether the
   albedo is per channel (HD_FLAG_RGB_SCATTERING): the CPU backend passes literals for interior
   voxels so the compiler drops the tests (see hd_cpu.h). With rgb = 0 and a white TF the RGB
   path computes the same bits as the grey one. */
HD_FN float hd_diffuse_terms_at(HD_KARGS int x, int y, int z, int c, int in_xm, int in_xp,
                                int in_ym, int in_yp, int in_zm, int in_zp, int rgb, HD_INOUT(float) den)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x, nvox = gx * gy * gz;
    int ic = i + c * nvox, zc = z + c * gz, sxy = gx * gy;
    float a = rgb != 0 ? HD_PRM(medium).y * HD_GET(sig, i + (1 + c) * nvox, x, y, z + (1 + c) * gz) : HD_PRM(medium).y;
    float ag = 1.0f - a * HD_PRM(medium).z;
    float fl = HD_PRM(grid).w;
    float st = HD_GET(sig, i, x, y, z);
    float sp = st * ag;
    float own = 0.6666667f / hd_maxf(sp + sp, fl);
    float num = a * st * HD_GET(E, ic, x, y, zc);
    float dn = (1.0f - a) * st;
    float w;
    w = HD_PRM(grid).x * (in_xm != 0 ? 0.6666667f / hd_maxf(sp + hd_diffuse_sigp(HD_KPASS i - 1, x - 1, y, z, c, rgb, ag), fl) : own);
    if (in_xm != 0) num += w * HD_GET(phi, ic - 1, x - 1, y, zc);
    dn += w;
    w = HD_PRM(grid).x * (in_xp != 0 ? 0.6666667f / hd_maxf(sp + hd_diffuse_sigp(HD_KPASS i + 1, x + 1, y, z, c, rgb, ag), fl) : own);
    if (in_xp != 0) num += w * HD_GET(phi, ic + 1, x + 1, y, zc);
    dn += w;
    w = HD_PRM(grid).y * (in_ym != 0 ? 0.6666667f / hd_maxf(sp + hd_diffuse_sigp(HD_KPASS i - gx, x, y - 1, z, c, rgb, ag), fl) : own);
    if (in_ym != 0) num += w * HD_GET(phi, ic - gx, x, y - 1, zc);
    dn += w;
    w = HD_PRM(grid).y * (in_yp != 0 ? 0.6666667f / hd_maxf(sp + hd_diffuse_sigp(HD_KPASS i + gx, x, y + 1, z, c, rgb, ag), fl) : own);
    if (in_yp != 0) num += w * HD_GET(phi, ic + gx, x, y + 1, zc);
    dn += w;
    w = HD_PRM(grid).z * (in_zm != 0 ? 0.6666667f / hd_maxf(sp + hd_diffuse_sigp(HD_KPASS i - sxy, x, y, z - 1, c, rgb, ag), fl) : own);
    if (in_zm != 0) num += w * HD_GET(phi, ic - sxy, x, y, zc - 1);
    dn += w;
    w = HD_PRM(grid).z * (in_zp != 0 ? 0.6666667f / hd_maxf(sp + hd_diffuse_sigp(HD_KPASS i + sxy, x, y, z + 1, c, rgb, ag), fl) : own);
    if (in_zp != 0) num += w * HD_GET(phi, ic + sxy, x, y, zc + 1);
    dn += w;
    HD_DEREF(den) = dn;
    return num;
}

HD_FN float hd_diffuse_terms(HD_KARGS int x, int y, int z, int c, HD_INOUT(float) den)
{
    return hd_diffuse_terms_at(HD_KPASS x, y, z, c, x > 0 ? 1 : 0, x < HD_PRM(gdims).x - 1 ? 1 : 0,
                               y > 0 ? 1 : 0, y < HD_PRM(gdims).y - 1 ? 1 : 0,
                               z > 0 ? 1 : 0, z < HD_PRM(gdims).z - 1 ? 1 : 0,
                               (HD_PRM(counts).z & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0, den);
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
    HD_DEREF(rhs) = HD_PRM(medium).y * HD_GET(sig, i, x, y, z) * HD_GET(E, ic, x, y, z + c * gz);
    return num - den * HD_GET(phi, ic, x, y, z + c * gz);
}
