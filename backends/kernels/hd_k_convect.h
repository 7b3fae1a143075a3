/* hd_k_convect.h - stage 1 of CD (convection-diffusion, Zhang & Ma 2013): direct light by
   convection, one light volume per light (shared source).

   The equation. The direct light of one light, rho(x, tau), obeys the convection part of
       d rho / d tau = -u . grad rho - sigma_t rho
   (tau: pseudo-time in world units of distance travelled, i.e. c t; u: the unit direction the
   light travels; sigma_t: extinction per world unit, what light leaving the beam loses; the
   scattered part re-enters through the shared diffusion stage). Its steady state along a ray is
   rho = I exp(-integral sigma_t ds): the transmittance HD estimates by tracking.

   Discretisation. Voxel i of the illumination grid, world voxel size h_a per axis a, first-order
   upwind differences per axis (backward where u_a > 0, forward where u_a < 0):
       u . grad rho ~ sum_a w_a (rho_i - rho_up(a)),   w_a = |u_a| / h_a,   A = sum_a w_a,
   explicit in the convection, implicit in the absorption:
       rho_i' = (rho_i - dtau A (rho_i - sum_a (w_a / A) rho_up(a))) / (1 + dtau sigma_i).
   This is the paper's update rho' = (1 - sigma_a)(rho - dx u.drho / (2 (1 - sigma_a))) =
   (1 - sigma_a) rho - (dx / 2) u.drho, written in world units (its sigma_a is the absorption of
   one step, sigma_t dtau, and dx/2 is dtau = half a voxel), except that the absorption is taken
   implicitly: the explicit form needs dtau (A + sigma_t) <= 1 to stay positive, which dense media
   (sigma_t h >> 1, e.g. extinction 100 on a 64^3 grid) break; the implicit one needs only the
   CFL condition dtau A <= 1, whatever sigma_t.
   Step: dtau = HD_CD_STEP * h_min, HD_CD_STEP = 0.5: light advances half a voxel per step, as
   in the paper. Its CFL number C = dtau A = 0.5 sum_a |u_a| h_min / h_a <= 0.5 sqrt(3) < 1, so
   every update is a convex combination
       rho_i' = ((1 - C) rho_i + dtau sum_a w_a rho_up(a)) / (1 + dtau sigma_i),
   hence stable and monotone for any light direction and any sigma_t.
   Steady state (independent of dtau): rho_i = sum_a (w_a / A) rho_up(a) / (1 + sigma_i / A);
   along an axis rho_k = rho_{k-1} / (1 + sigma h), against the exact exp(-sigma h): the scheme
   is first order, ln(rho / exact) ~ depth * sigma^2 h / 2 (measured in tests/test_methods.c).

   Boundaries. An upwind neighbour outside the grid is a ghost voxel held at the light's value:
   the faces the light enters through are held at its intensity (outside the box is vacuum). A
   point light picks the faces per voxel by its direction (u = unit vector from the light to the
   voxel), so a light outside the box enters through whatever faces it sees; a point light inside
   the box holds the small block of voxels closer to it than one voxel on every axis (1 to 8
   voxels) at its intensity.

   Storage. rho is stored as a fraction of the light's intensity (1 at the held voxels), so one
   float per voxel per light, whatever the number of colour channels; hdk_sum_light_voxel scales
   it by the light's colour and, for an inverse-square point light, 1/r^2 (the convected rho is
   the transmittance; the geometric falloff is applied exactly at summation). Reads lv, writes
   lv2 (ping-pong; the backend rotates one spare buffer through the lights). */

#define HD_CD_STEP 0.5f /* pseudo-time step in voxels (of the smallest voxel side) */

/* One convection step of light l at voxel (x, y, z): lv -> lv2. */
HD_FN void hdk_convect_voxel(HD_KARGS int x, int y, int z, int l)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x;
    float hx = HD_PRM(box).x / HD_F(gx), hy = HD_PRM(box).y / HD_F(gy), hz = HD_PRM(box).z / HD_F(gz);
    hd_v3 p = HD_V3((HD_F(x) + 0.5f) * hx - 0.5f * HD_PRM(box).x,
                    (HD_F(y) + 0.5f) * hy - 0.5f * HD_PRM(box).y,
                    (HD_F(z) + 0.5f) * hz - 0.5f * HD_PRM(box).z);
    hd_v4 la = HD_PRM(light_a)[l];
    hd_v3 u;
    float dtau = HD_CD_STEP * hdk_minf(hx, hdk_minf(hy, hz));
    float wx = 0.0f, wy = 0.0f, wz = 0.0f, up, rho, st, res;
    int xu, yu, zu;
    if (la.w < 0.5f) {
        u = HD_XYZ(la); /* directional: the direction the light travels */
    } else {
        hd_v3 v = hdk_sub(p, HD_XYZ(la));
        if (hdk_absf(v.x) < hx && hdk_absf(v.y) < hy && hdk_absf(v.z) < hz) {
            HD_SET(lv2, i, x, y, z, 1.0f); /* the held block around a point light */
            return;
        }
        u = hdk_normalize(v);
    }
    wx = hdk_absf(u.x) / hx;
    wy = hdk_absf(u.y) / hy;
    wz = hdk_absf(u.z) / hz;
    /* upwind neighbours; outside the grid: a ghost voxel held at the light's intensity (1) */
    xu = u.x > 0.0f ? x - 1 : x + 1;
    yu = u.y > 0.0f ? y - 1 : y + 1;
    zu = u.z > 0.0f ? z - 1 : z + 1;
    up = 0.0f;
    if (wx > 0.0f) up += wx * (xu >= 0 && xu < gx ? HD_GET(lv, i + (xu - x), xu, y, z) : 1.0f);
    if (wy > 0.0f) up += wy * (yu >= 0 && yu < gy ? HD_GET(lv, i + (yu - y) * gx, x, yu, z) : 1.0f);
    if (wz > 0.0f) up += wz * (zu >= 0 && zu < gz ? HD_GET(lv, i + (zu - z) * gx * gy, x, y, zu) : 1.0f);
    rho = HD_GET(lv, i, x, y, z);
    st = HD_GET(sig, i, x, y, z);
    res = ((1.0f - dtau * (wx + wy + wz)) * rho + dtau * up) / (1.0f + dtau * st);
    HD_SET(lv2, i, x, y, z, res);
}

/* E (all channels) at voxel (x, y, z) += light l's volume lv scaled by its colour and falloff;
   first != 0: E = that (the first light of the sum). */
HD_FN void hdk_sum_light_voxel(HD_KARGS int x, int y, int z, int l, int first)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int nch = HD_PRM(gdims).w;
    int i = (z * gy + y) * gx + x, nvox = gx * gy * gz;
    hd_v3 p = HD_V3(((HD_F(x) + 0.5f) / HD_F(gx) - 0.5f) * HD_PRM(box).x,
                    ((HD_F(y) + 0.5f) / HD_F(gy) - 0.5f) * HD_PRM(box).y,
                    ((HD_F(z) + 0.5f) / HD_F(gz) - 0.5f) * HD_PRM(box).z);
    float tmax = 0.0f, falloff = 0.0f;
    float rho = HD_GET(lv, i, x, y, z);
    int c;
    hdk_light_dir(HD_KPASS l, p, HD_REF(tmax), HD_REF(falloff));
    for (c = 0; c < nch; ++c) {
        int ic = i + c * nvox;
        float e = first != 0 ? 0.0f : HD_GET(E, ic, x, y, z + c * gz);
        HD_SET(E, ic, x, y, z + c * gz, e + hdk_light_channel(HD_KPASS l, c) * falloff * rho);
    }
}
