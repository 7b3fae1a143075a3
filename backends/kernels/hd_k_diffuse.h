/* hd_k_diffuse.h - stage 2 of HD and CD: one relaxation sweep of the diffusion equation
   -div(D grad phi) + sigma_a phi = sigma_s E  (shared source)
   on the illumination grid, D = 1 / (3 sigma_t'), sigma_t' = sigma_a + sigma_s (1 - g)
   = sigma_t (1 - albedo g). Face coefficients are the harmonic mean of the two voxels' D,
   2 / (3 (sigma'_i + sigma'_j)), floored so empty space stays finite. Each update is the paper's
   weighted sum of the 6 neighbours:
   phi_i = (sigma_s E_i + sum_j w_j phi_j) / (sigma_a + sum_j w_j),  w_j = D_ij / h^2.
   Two boundary conditions (params.diffusion_boundary):
   - box (default, docs/METHOD.md): phi = 0 outside the box, reached through the voxel's own D. Empty
     voxels are solved too, with the floored D: air conducts light to the box faces almost
     freely, so every tissue surface acts nearly as phi = 0.
   - surface (HD_FLAG_SURFACE_BOUNDARY): empty voxels (sigma' below half the floor) are not
     solved for (they hold the Marshak extrapolation of their medium neighbours, for the
     projection: hdk_diffuse_surface_end) and a face between a medium voxel and an empty one (or
     the box) carries the Marshak vacuum condition J = phi_s / 2 (no light enters from outside):
     conductance 1 / (h / (2D) + 2) per area, i.e. w = 1 / (h^2 / (2 D) + 2 h) = 1 / (1.5 sigma' h^2 + 2 h). */

/* The flags word the diffusion tests (RGB scattering, boundary). A backend may define it as a
   compile-time constant per pipeline (Vulkan: a specialization constant, hd_bind_vk_glsl.h), so
   the untaken variant costs nothing where both sides of a branch would run. */
#ifndef HD_DIFFUSE_FLAGS
#define HD_DIFFUSE_FLAGS HD_PRM(counts).z
#endif

/* The update is written twice over: as pure arithmetic on values already loaded (the *_of
   functions below: no grid access), and as the loading wrappers every backend's row or voxel loop
   calls (hdk_diffuse_terms_box / _surface), which load a voxel's 14 values and pass them on. A
   backend whose loads are dear (lavapipe: each imageLoad a full gather, docs/DESIGN-VULKAN.md)
   loads a block of texels once and passes the values its voxels share to each of them
   (hd_entry_glsl.h); the formulae stay in this file only, and the same operations on the same
   values give the same bits either way. */

/* The albedo of a texel in channel c: albedo * TF colour_c from the sigma_t grid's channel 1 + c
   (sc, loaded by the caller) with RGB scattering, else the constant albedo. */
HD_FN float hdk_diffuse_albedo_of(HD_KARGS float sc, int rgb)
{
    return rgb != 0 ? HD_PRM(medium).y * sc : HD_PRM(medium).y;
}

/* 1 - albedo g for albedo a. */
HD_FN float hdk_diffuse_ag(HD_KARGS float a)
{
    return 1.0f - a * HD_PRM(medium).z;
}

/* sigma' = sigma_t (1 - albedo g) of a texel with sigma_t st and albedo a. */
HD_FN float hdk_diffuse_sigp_of(HD_KARGS float st, float a)
{
    return st * hdk_diffuse_ag(HD_KPASS a);
}

/* The albedo of grid voxel j (image coordinates x, y, z) in channel c: loads channel 1 + c of the
   sigma_t grid only with RGB scattering. */
HD_FN float hdk_diffuse_albedo(HD_KARGS int j, int x, int y, int z, int c, int rgb)
{
    int gz = HD_PRM(gdims).z, nvox = HD_PRM(gdims).x * HD_PRM(gdims).y * gz;
    return hdk_diffuse_albedo_of(HD_KPASS rgb != 0 ? HD_GET(sig, j + (1 + c) * nvox, x, y, z + (1 + c) * gz) : 0.0f, rgb);
}

/* sigma' of grid voxel j (image coordinates x, y, z) in channel c, loaded; ag: 1 - albedo g
   without RGB scattering (the same for every voxel: hdk_diffuse_own gives it). */
HD_FN float hdk_diffuse_sigp(HD_KARGS int j, int x, int y, int z, int c, int rgb, float ag)
{
    float st = HD_GET(sig, j, x, y, z);
    return rgb != 0 ? hdk_diffuse_sigp_of(HD_KPASS st, hdk_diffuse_albedo(HD_KPASS j, x, y, z, c, rgb)) : ag * st;
}

/* The weight w = D_ij / h^2 of the face between two voxels with sigma' spi and spj: the harmonic
   mean of their D = 1 / (3 sigma'), 2 / (3 (spi + spj)), floored at fl so empty space stays finite,
   times the axis' 1 / h^2 (scale). A face on the box boundary passes spj = spi: phi = 0 outside
   with the voxel's own D. One division per face, and both voxels of a face get the same bits
   (a + b == b + a in IEEE arithmetic): the operator conjugate gradients applies
   (src/hd_multigrid.h) is exactly symmetric. The sweep computes the same weights as a / d, an
   axis' two faces over one division (hdk_diffuse_box_axis below), within a few ulps of these. */
HD_FN float hdk_diffuse_face(float scale, float spi, float spj, float fl)
{
    return scale * (0.6666667f / hdk_maxf(spi + spj, fl));
}

/* The weight of a face between medium (sigma' spi) and vacuum under the surface boundary: the
   Marshak condition at distance h / 2 from the voxel centre (see the top of this file). */
HD_FN float hdk_diffuse_vacuum_face(float h, float spi)
{
    return 1.0f / (1.5f * spi * h * h + 2.0f * h);
}

/* Under the surface boundary, 1 if a neighbour with sigma' spj that lies in the grid
   (inside != 0) is medium, its phi entering the update; 0 if it is vacuum: empty (sigma' below
   half the floor) or the box's outside, whose phi is 0. */
HD_FN float hdk_diffuse_open_of(float spj, int inside, float fl)
{
    return inside != 0 ? (spj + spj < fl ? 0.0f : 1.0f) : 0.0f;
}

/* One face of the surface boundary's update: the weight toward a neighbour with sigma' spj that
   lies in the grid (inside != 0), else toward the box's outside; vacuum neighbours add to the
   denominator only (*open = 0). (Exact per-face form, as hdk_diffuse_face: the sweep's is
   hdk_diffuse_surface_den.) */
HD_FN float hdk_diffuse_surface_face(float scale, float h, float spi, float spj, int inside, float fl,
                                    HD_INOUT(float) open)
{
    float o = hdk_diffuse_open_of(spj, inside, fl);
    HD_DEREF(open) = o;
    return o == 0.0f ? hdk_diffuse_vacuum_face(h, spi) : hdk_diffuse_face(scale, spi, spj, fl);
}

/* The voxel's own part of its update from its sigma_t st, albedo a and E e: returns the source
   term (sigma_s E, or with rhs the right-hand side E holds) and gives its absorption sigma_a in
   *dn and its sigma' in *sp. */
HD_FN float hdk_diffuse_own_of(HD_KARGS float st, float a, float e, int rhs, HD_INOUT(float) sp, HD_INOUT(float) dn)
{
    HD_DEREF(sp) = hdk_diffuse_sigp_of(HD_KPASS st, a);
    HD_DEREF(dn) = (1.0f - a) * st;
    return rhs != 0 ? e : a * st * e;
}

/* The same, loaded at grid voxel i (image coordinates x, y, z) in channel c; also gives its
   1 - albedo g in *ag. */
HD_FN float hdk_diffuse_own(HD_KARGS int i, int x, int y, int z, int c, int rgb, int rhs, HD_INOUT(float) sp,
                           HD_INOUT(float) ag, HD_INOUT(float) dn)
{
    int nvox = HD_PRM(gdims).x * HD_PRM(gdims).y * HD_PRM(gdims).z, gz = HD_PRM(gdims).z;
    float a = hdk_diffuse_albedo(HD_KPASS i, x, y, z, c, rgb);
    HD_DEREF(ag) = hdk_diffuse_ag(HD_KPASS a);
    return hdk_diffuse_own_of(HD_KPASS HD_GET(sig, i, x, y, z), a, HD_GET(E, i + c * nvox, x, y, z + c * gz), rhs, sp, dn);
}

/* ---- the sweep's faces: an axis' two weights over one division -------------------------------
   Divisions are the dearest arithmetic of the update on every backend (lavapipe: a per-lane
   vdivps; docs/DESIGN-VULKAN.md "Shared loads"): the update made 7 per voxel under the box
   boundary (one per face weight, and num / den), 13 under the surface boundary (its selects
   compute both the vacuum and the medium weight). Each weight is written w = a / d (box face:
   a = 0.6666667 / h^2 of the axis, d = max(sp + spj, fl); vacuum face: a = 1 / h,
   d = 1.5 sp h + 2, the same 1 / (1.5 sp h^2 + 2 h)) and an axis' two faces (-, +) go over one
   division: w_- p_- + w_+ p_+ = (a_- d_+ p_- + a_+ d_- p_+) / (d_- d_+), and the same for
   w_- + w_+. 4 divisions per voxel under either boundary, one multiplication more per axis (box).
   Range, for every valid input (no float overflow, underflow or denormal, so GPUs that flush
   denormals compute the same): sigma_t <= extinction <= 1e6 (hd_validate.h), 1 - albedo g < 2, so
   sp < 2e6 and a box face's d in [fl, 4e6] = [1e-3, 4e6]; a vacuum face's d in [2, 3e6 + 2]
   (h <= 1: the box's longest side is 1). So d_- d_+ in [1e-6, 1.6e13] and a / (d_- d_+) at most
   1e6 a; the terms a d p are at most 4e6 a |phi| where the per-face form's w p reached 667 a
   |phi| (and the sum they form is the same), so the update overflows for no input the per-face
   form did not (|phi| near 1e31 at h = 1/256). The sums are symmetric in the two faces (a
   mirrored grid gives the same bits), but a face's effective weight depends on the voxel's
   opposite face, so the two voxels of a face may see it differ in the last bits:
   hdk_diffuse_face / _surface_face above stay the exact per-face forms, for the operator
   conjugate gradients applies (src/hd_multigrid.h), which must be exactly symmetric. */

/* The denominator d of a box face toward a neighbour with sigma' s (inside == 0: the box's
   outside, the voxel's own D). */
HD_FN float hdk_diffuse_box_den(float sp, float s, int inside, float fl)
{
    return hdk_maxf(sp + (inside != 0 ? s : sp), fl);
}

/* The denominator d of a surface boundary face (scale: the axis' 1 / h^2, h its spacing), its
   numerator in *a and in *open whether its neighbour's phi enters the update (empty neighbours
   and the box's outside are vacuum: Marshak weight, phi 0). self: 1 if the voxel itself is medium;
   for an empty one (0) a face toward a medium neighbour j gives instead the Marshak extrapolation's
   factor a / d = max(0, 2 - 1.5 s_j h) / (2 + 1.5 s_j h) (hdk_diffuse_surface_end), so the axis'
   sum and its one division serve both (d in [2, 3e6 + 2], as a vacuum face's). */
HD_FN float hdk_diffuse_surface_den(float scale, float h, float sp, float s, int inside, float fl, float self,
                                   HD_INOUT(float) a, HD_INOUT(float) open)
{
    float spj = inside != 0 ? s : 0.0f, o = hdk_diffuse_open_of(spj, inside, fl);
    float m = o * self; /* 1: a medium face of a medium voxel (selects on values, no branch) */
    float g = 1.5f * (o == 0.0f ? sp : spj) * h; /* vacuum face: 1.5 sp h; extrapolation: 1.5 s_j h */
    HD_DEREF(open) = o;
    HD_DEREF(a) = m != 0.0f ? 0.6666667f * scale : (o == 0.0f ? h * scale : hdk_maxf(0.0f, 2.0f - g));
    return m != 0.0f ? hdk_maxf(sp + spj, fl) : g + 2.0f;
}

/* An axis' two faces of the box boundary's update, toward neighbours with sigma' s0, s1 and phi
   p0, p1 (in0, in1: whether each lies in the grid; the box's outside has phi = 0): adds
   w0 p0 + w1 p1 to *num and w0 + w1 to *dn. a = 0.6666667 / h^2 of the axis, the same for both. */
HD_FN void hdk_diffuse_box_axis(float a, float sp, float s0, float s1, float p0, float p1, int in0, int in1, float fl,
                               HD_INOUT(float) num, HD_INOUT(float) dn)
{
    float d0 = hdk_diffuse_box_den(sp, s0, in0, fl), d1 = hdk_diffuse_box_den(sp, s1, in1, fl);
    float t = a / (d0 * d1);
    float q0 = in0 != 0 ? p0 * d1 : 0.0f, q1 = in1 != 0 ? p1 * d0 : 0.0f;
    HD_DEREF(num) += t * (q0 + q1);
    HD_DEREF(dn) += t * (d0 + d1);
}

/* The same under the surface boundary (scale: the axis' 1 / h^2, h its spacing): vacuum faces add
   their weight to *dn only. self (hdk_diffuse_open_of of the voxel's own sigma'): 0 for an empty
   voxel, whose *num then accumulates the Marshak extrapolation instead, sum of e_j phi_j over its
   medium neighbours j with e_j = max(0, 2 - 1.5 s_j h) / (2 + 1.5 s_j h) (a linear profile from
   medium voxel j that reaches the face's boundary value at h / 2, the Marshak face's assumption,
   continued to the empty voxel's centre; hdk_diffuse_surface_den), and *cnt counts them. The same
   operations as without the extrapolation for a medium voxel (the same bits), 4 divisions per
   update still. */
HD_FN void hdk_diffuse_surface_axis(float scale, float h, float sp, float self, float s0, float s1, float p0, float p1,
                                   int in0, int in1, float fl, HD_INOUT(float) num, HD_INOUT(float) dn,
                                   HD_INOUT(float) cnt)
{
    float a0 = 0.0f, a1 = 0.0f, o0 = 0.0f, o1 = 0.0f;
    float d0 = hdk_diffuse_surface_den(scale, h, sp, s0, in0, fl, self, HD_REF(a0), HD_REF(o0));
    float d1 = hdk_diffuse_surface_den(scale, h, sp, s1, in1, fl, self, HD_REF(a1), HD_REF(o1));
    float r = 1.0f / (d0 * d1), u0 = a0 * d1, u1 = a1 * d0;
    float q0 = in0 != 0 ? o0 * u0 * p0 : 0.0f, q1 = in1 != 0 ? o1 * u1 * p1 : 0.0f;
    HD_DEREF(num) += r * (q0 + q1);
    HD_DEREF(dn) += r * (u0 + u1);
    HD_DEREF(cnt) += o0 + o1;
}

/* The surface boundary's start of the update: the voxel's own source term src and self
   (hdk_diffuse_open_of of its sigma' sp: 1 medium, 0 empty) in *self; an empty voxel's sum starts
   at 0 (it holds the extrapolation, hdk_diffuse_surface_end). */
HD_FN float hdk_diffuse_surface_start(float src, float sp, float fl, HD_INOUT(float) self)
{
    float o = hdk_diffuse_open_of(sp, 1, fl);
    HD_DEREF(self) = o;
    return o * src; /* a product, not a select: gcc sank src's loads under a select's branch, and the
                       CPU's row loops stopped vectorising (docs/DESIGN-CPU.md) */
}

/* The surface boundary's end of the update. A medium voxel: num / dn. An empty voxel (self 0)
   takes no part in the medium's equations (its faces are vacuum faces), so the value it stores is
   free: with extrap (the ordinary solve), the Marshak extrapolation of its medium neighbours,
   num / cnt, the mean of their e_j phi_j (0 if it has none: num 0, den 1), which the projection
   interpolates toward instead of a placeholder 0 (docs/EVALUATION.md, "Why converged HD is too
   dark against PT_MS"); without (HD_FLAG_DIFFUSE_RHS: multigrid's correction equations), num 0 and
   den 1: an identity row, phi = 0. No division here: num / den is the caller's. */
HD_FN float hdk_diffuse_surface_end(float self, float num, float dn, float cnt, int extrap, HD_INOUT(float) den)
{
    HD_DEREF(den) = self * dn + (1.0f - self) * (extrap != 0 ? hdk_maxf(cnt, 1.0f) : 1.0f);
    return extrap != 0 ? num : self * num;
}

/* The box boundary's update from loaded values: num and dn the voxel's own part
   (hdk_diffuse_own_of), sp its sigma'; s_* the 6 neighbours' sigma' and p_* their phi (x-, x+,
   y-, y+, z-, z+), in_* whether each lies inside the grid (the values of one that does not are
   ignored). Returns the numerator, the denominator goes to *den. */
HD_FN float hdk_diffuse_box_of(HD_KARGS float num, float dn, float sp, float s_xm, float s_xp, float s_ym,
                              float s_yp, float s_zm, float s_zp, float p_xm, float p_xp, float p_ym, float p_yp,
                              float p_zm, float p_zp, int in_xm, int in_xp, int in_ym, int in_yp, int in_zm,
                              int in_zp, HD_INOUT(float) den)
{
    float fl = HD_PRM(grid).w;
    hdk_diffuse_box_axis(0.6666667f * HD_PRM(grid).x, sp, s_xm, s_xp, p_xm, p_xp, in_xm, in_xp, fl, HD_REF(num),
                        HD_REF(dn));
    hdk_diffuse_box_axis(0.6666667f * HD_PRM(grid).y, sp, s_ym, s_yp, p_ym, p_yp, in_ym, in_yp, fl, HD_REF(num),
                        HD_REF(dn));
    hdk_diffuse_box_axis(0.6666667f * HD_PRM(grid).z, sp, s_zm, s_zp, p_zm, p_zp, in_zm, in_zp, fl, HD_REF(num),
                        HD_REF(dn));
    HD_DEREF(den) = dn;
    return num;
}

/* The surface boundary's update from loaded values, the arguments as hdk_diffuse_box_of's after
   rhs (HD_FLAG_DIFFUSE_RHS: no extrapolation into empty voxels): an empty voxel gets its
   extrapolation (hdk_diffuse_surface_end); a medium voxel's faces toward empty neighbours or the
   box's outside carry the Marshak weight and no neighbour term. Every select is arithmetic, so
   the CPU's row loop stays branch-free; it passes rhs as a literal (with the flag loaded at run
   time its loops stopped vectorising, docs/DESIGN-CPU.md). */
HD_FN float hdk_diffuse_surface_rhs_of(HD_KARGS int rhs, float num, float dn, float sp, float s_xm, float s_xp,
                                      float s_ym, float s_yp, float s_zm, float s_zp, float p_xm, float p_xp,
                                      float p_ym, float p_yp, float p_zm, float p_zp, int in_xm, int in_xp, int in_ym,
                                      int in_yp, int in_zm, int in_zp, HD_INOUT(float) den)
{
    float fl = HD_PRM(grid).w, cnt = 0.0f, self = 0.0f;
    int extrap = rhs == 0 ? 1 : 0;
    num = hdk_diffuse_surface_start(num, sp, fl, HD_REF(self));
    hdk_diffuse_surface_axis(HD_PRM(grid).x, HD_PRM(gridh).x, sp, self, s_xm, s_xp, p_xm, p_xp, in_xm, in_xp, fl,
                            HD_REF(num), HD_REF(dn), HD_REF(cnt));
    hdk_diffuse_surface_axis(HD_PRM(grid).y, HD_PRM(gridh).y, sp, self, s_ym, s_yp, p_ym, p_yp, in_ym, in_yp, fl,
                            HD_REF(num), HD_REF(dn), HD_REF(cnt));
    hdk_diffuse_surface_axis(HD_PRM(grid).z, HD_PRM(gridh).z, sp, self, s_zm, s_zp, p_zm, p_zp, in_zm, in_zp, fl,
                            HD_REF(num), HD_REF(dn), HD_REF(cnt));
    return hdk_diffuse_surface_end(self, num, dn, cnt, extrap, den);
}

/* The same with rhs from the flags (HD_DIFFUSE_FLAGS). */
HD_FN float hdk_diffuse_surface_of(HD_KARGS float num, float dn, float sp, float s_xm, float s_xp, float s_ym,
                                  float s_yp, float s_zm, float s_zp, float p_xm, float p_xp, float p_ym, float p_yp,
                                  float p_zm, float p_zp, int in_xm, int in_xp, int in_ym, int in_yp, int in_zm,
                                  int in_zp, HD_INOUT(float) den)
{
    return hdk_diffuse_surface_rhs_of(HD_KPASS (HD_DIFFUSE_FLAGS & HD_FLAG_DIFFUSE_RHS) != 0 ? 1 : 0, num, dn, sp, s_xm,
                                     s_xp, s_ym, s_yp, s_zm, s_zp, p_xm, p_xp, p_ym, p_yp, p_zm, p_zp, in_xm, in_xp,
                                     in_ym, in_yp, in_zm, in_zp, den);
}

/* The update from loaded values under the configured boundary (HD_DIFFUSE_FLAGS). */
HD_FN float hdk_diffuse_update_of(HD_KARGS float num, float dn, float sp, float s_xm, float s_xp, float s_ym,
                                 float s_yp, float s_zm, float s_zp, float p_xm, float p_xp, float p_ym, float p_yp,
                                 float p_zm, float p_zp, int in_xm, int in_xp, int in_ym, int in_yp, int in_zm,
                                 int in_zp, HD_INOUT(float) den)
{
    if ((HD_DIFFUSE_FLAGS & HD_FLAG_SURFACE_BOUNDARY) != 0)
        return hdk_diffuse_surface_of(HD_KPASS num, dn, sp, s_xm, s_xp, s_ym, s_yp, s_zm, s_zp, p_xm, p_xp, p_ym, p_yp,
                                     p_zm, p_zp, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, den);
    return hdk_diffuse_box_of(HD_KPASS num, dn, sp, s_xm, s_xp, s_ym, s_yp, s_zm, s_zp, p_xm, p_xp, p_ym, p_yp, p_zm,
                             p_zp, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, den);
}

/* A neighbour's sigma' and phi, loaded only when it lies inside the grid (inside != 0): grid voxel
   j at image coordinates (x, y, z), phi's channel c at z + c * gz. */
HD_FN float hdk_diffuse_nb_sigp(HD_KARGS int inside, int j, int x, int y, int z, int c, int rgb, float ag)
{
    return inside != 0 ? hdk_diffuse_sigp(HD_KPASS j, x, y, z, c, rgb, ag) : 0.0f;
}
HD_FN float hdk_diffuse_nb_phi(HD_KARGS int inside, int j, int x, int y, int z, int c)
{
    int gz = HD_PRM(gdims).z, nvox = HD_PRM(gdims).x * HD_PRM(gdims).y * gz;
    return inside != 0 ? HD_GET(phi, j + c * nvox, x, y, z + c * gz) : 0.0f;
}

/* The numerator of voxel (x,y,z)'s update in channel c; its denominator goes to *den. surface:
   the boundary (HD_FLAG_SURFACE_BOUNDARY). in_xm ... in_zp say whether the neighbour on each side
   lies inside the grid, rgb whether the albedo is per channel (HD_FLAG_RGB_SCATTERING): the CPU
   backend passes literals for interior voxels so the compiler drops the tests (see hd_cpu.h).
   With rgb = 0 and a white TF the RGB path computes the same bits as the grey one. rhs
   (HD_FLAG_DIFFUSE_RHS): E holds the whole right-hand side (multigrid's coarse levels solve for
   a correction), not the direct light. The same hd_diffuse_*_axis calls, in the same axis order,
   as hdk_diffuse_box_of / _surface_of, so the same bits; each axis' values are loaded right before
   its terms: loading all 12 first tripled the CPU row loops' vector spills (365 -> 1113 zmm
   moves to the stack). */
HD_FN float hdk_diffuse_terms_loaded(HD_KARGS int x, int y, int z, int c, int in_xm, int in_xp, int in_ym,
                                    int in_yp, int in_zm, int in_zp, int rgb, int rhs, int surface,
                                    HD_INOUT(float) den)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, sxy = gx * gy;
    int i = (z * gy + y) * gx + x;
    float sp = 0.0f, ag = 0.0f, dn = 0.0f, fl = HD_PRM(grid).w;
    float num = hdk_diffuse_own(HD_KPASS i, x, y, z, c, rgb, rhs, HD_REF(sp), HD_REF(ag), HD_REF(dn));
    if (surface != 0) {
        float cnt = 0.0f, self = 0.0f;
        num = hdk_diffuse_surface_start(num, sp, fl, HD_REF(self));
        hdk_diffuse_surface_axis(HD_PRM(grid).x, HD_PRM(gridh).x, sp, self,
                                hdk_diffuse_nb_sigp(HD_KPASS in_xm, i - 1, x - 1, y, z, c, rgb, ag),
                                hdk_diffuse_nb_sigp(HD_KPASS in_xp, i + 1, x + 1, y, z, c, rgb, ag),
                                hdk_diffuse_nb_phi(HD_KPASS in_xm, i - 1, x - 1, y, z, c),
                                hdk_diffuse_nb_phi(HD_KPASS in_xp, i + 1, x + 1, y, z, c), in_xm, in_xp, fl,
                                HD_REF(num), HD_REF(dn), HD_REF(cnt));
        hdk_diffuse_surface_axis(HD_PRM(grid).y, HD_PRM(gridh).y, sp, self,
                                hdk_diffuse_nb_sigp(HD_KPASS in_ym, i - gx, x, y - 1, z, c, rgb, ag),
                                hdk_diffuse_nb_sigp(HD_KPASS in_yp, i + gx, x, y + 1, z, c, rgb, ag),
                                hdk_diffuse_nb_phi(HD_KPASS in_ym, i - gx, x, y - 1, z, c),
                                hdk_diffuse_nb_phi(HD_KPASS in_yp, i + gx, x, y + 1, z, c), in_ym, in_yp, fl,
                                HD_REF(num), HD_REF(dn), HD_REF(cnt));
        hdk_diffuse_surface_axis(HD_PRM(grid).z, HD_PRM(gridh).z, sp, self,
                                hdk_diffuse_nb_sigp(HD_KPASS in_zm, i - sxy, x, y, z - 1, c, rgb, ag),
                                hdk_diffuse_nb_sigp(HD_KPASS in_zp, i + sxy, x, y, z + 1, c, rgb, ag),
                                hdk_diffuse_nb_phi(HD_KPASS in_zm, i - sxy, x, y, z - 1, c),
                                hdk_diffuse_nb_phi(HD_KPASS in_zp, i + sxy, x, y, z + 1, c), in_zm, in_zp, fl,
                                HD_REF(num), HD_REF(dn), HD_REF(cnt));
        return hdk_diffuse_surface_end(self, num, dn, cnt, rhs == 0 ? 1 : 0, den);
    }
    hdk_diffuse_box_axis(0.6666667f * HD_PRM(grid).x, sp, hdk_diffuse_nb_sigp(HD_KPASS in_xm, i - 1, x - 1, y, z, c, rgb, ag),
                        hdk_diffuse_nb_sigp(HD_KPASS in_xp, i + 1, x + 1, y, z, c, rgb, ag),
                        hdk_diffuse_nb_phi(HD_KPASS in_xm, i - 1, x - 1, y, z, c),
                        hdk_diffuse_nb_phi(HD_KPASS in_xp, i + 1, x + 1, y, z, c), in_xm, in_xp, fl, HD_REF(num),
                        HD_REF(dn));
    hdk_diffuse_box_axis(0.6666667f * HD_PRM(grid).y, sp, hdk_diffuse_nb_sigp(HD_KPASS in_ym, i - gx, x, y - 1, z, c, rgb, ag),
                        hdk_diffuse_nb_sigp(HD_KPASS in_yp, i + gx, x, y + 1, z, c, rgb, ag),
                        hdk_diffuse_nb_phi(HD_KPASS in_ym, i - gx, x, y - 1, z, c),
                        hdk_diffuse_nb_phi(HD_KPASS in_yp, i + gx, x, y + 1, z, c), in_ym, in_yp, fl, HD_REF(num),
                        HD_REF(dn));
    hdk_diffuse_box_axis(0.6666667f * HD_PRM(grid).z, sp, hdk_diffuse_nb_sigp(HD_KPASS in_zm, i - sxy, x, y, z - 1, c, rgb, ag),
                        hdk_diffuse_nb_sigp(HD_KPASS in_zp, i + sxy, x, y, z + 1, c, rgb, ag),
                        hdk_diffuse_nb_phi(HD_KPASS in_zm, i - sxy, x, y, z - 1, c),
                        hdk_diffuse_nb_phi(HD_KPASS in_zp, i + sxy, x, y, z + 1, c), in_zm, in_zp, fl, HD_REF(num),
                        HD_REF(dn));
    HD_DEREF(den) = dn;
    return num;
}

/* hdk_diffuse_terms_loaded under the box boundary (the CPU's row loops name one boundary each). */
HD_FN float hdk_diffuse_terms_box(HD_KARGS int x, int y, int z, int c, int in_xm, int in_xp,
                                 int in_ym, int in_yp, int in_zm, int in_zp, int rgb, int rhs, HD_INOUT(float) den)
{
    return hdk_diffuse_terms_loaded(HD_KPASS x, y, z, c, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, rgb, rhs, 0, den);
}

/* The same under the surface boundary. */
HD_FN float hdk_diffuse_terms_surface(HD_KARGS int x, int y, int z, int c, int in_xm, int in_xp,
                                     int in_ym, int in_yp, int in_zm, int in_zp, int rgb, int rhs, HD_INOUT(float) den)
{
    return hdk_diffuse_terms_loaded(HD_KPASS x, y, z, c, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, rgb, rhs, 1, den);
}

/* The update's numerator and denominator at (x, y, z) under the configured boundary. */
HD_FN float hdk_diffuse_terms(HD_KARGS int x, int y, int z, int c, HD_INOUT(float) den)
{
    int rgb = (HD_DIFFUSE_FLAGS & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0;
    int rhs = (HD_DIFFUSE_FLAGS & HD_FLAG_DIFFUSE_RHS) != 0 ? 1 : 0;
    int in_xm = x > 0 ? 1 : 0, in_xp = x < HD_PRM(gdims).x - 1 ? 1 : 0;
    int in_ym = y > 0 ? 1 : 0, in_yp = y < HD_PRM(gdims).y - 1 ? 1 : 0;
    int in_zm = z > 0 ? 1 : 0, in_zp = z < HD_PRM(gdims).z - 1 ? 1 : 0;
    if ((HD_DIFFUSE_FLAGS & HD_FLAG_SURFACE_BOUNDARY) != 0)
        return hdk_diffuse_terms_surface(HD_KPASS x, y, z, c, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, rgb, rhs, den);
    return hdk_diffuse_terms_box(HD_KPASS x, y, z, c, in_xm, in_xp, in_ym, in_yp, in_zm, in_zp, rgb, rhs, den);
}

/* Relaxes the voxels x0, x0 + xstep, ... of row (y, z), channel c. Red-black Gauss-Seidel:
   xstep 2 and x0 chosen by the parity, in place. Jacobi: xstep 1, reads phi, writes phi2. */
HD_FN void hdk_diffuse_row(HD_KARGS int y, int z, int c, int parity, int jacobi)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int base = (c * gz + z) * gy * gx + y * gx;
    int x = jacobi != 0 ? 0 : ((y + z + parity) & 1);
    int xstep = jacobi != 0 ? 1 : 2;
    for (; x < gx; x += xstep) {
        float den = 0.0f;
        float num = hdk_diffuse_terms(HD_KPASS x, y, z, c, HD_REF(den));
        if (jacobi != 0) HD_SET(phi2, base + x, x, y, z + c * gz, num / den);
        else HD_SET(phi, base + x, x, y, z + c * gz, num / den);
    }
}

/* Residual of the discrete equation at one voxel, and its right-hand side in *rhs: the solver's
   convergence measure (relative residual = |r| / |rhs| over the grid). */
HD_FN float hdk_diffuse_residual(HD_KARGS int x, int y, int z, int c, HD_INOUT(float) rhs)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x, ic = i + c * gx * gy * gz;
    float den = 0.0f;
    float num = hdk_diffuse_terms(HD_KPASS x, y, z, c, HD_REF(den));
    int rgb = (HD_DIFFUSE_FLAGS & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0;
    /* sigma_s E with the channel's albedo (per channel with RGB scattering, as the update uses) */
    HD_DEREF(rhs) = (HD_DIFFUSE_FLAGS & HD_FLAG_DIFFUSE_RHS) != 0 ? HD_GET(E, ic, x, y, z + c * gz)
                  : hdk_diffuse_albedo(HD_KPASS i, x, y, z, c, rgb) * HD_GET(sig, i, x, y, z) * HD_GET(E, ic, x, y, z + c * gz);
    /* an empty voxel under the surface boundary holds its extrapolation, not an equation: no
       residual (the medium's equations do not read it) */
    if ((HD_DIFFUSE_FLAGS & (HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_DIFFUSE_RHS)) == HD_FLAG_SURFACE_BOUNDARY &&
        hdk_diffuse_open_of(hdk_diffuse_sigp(HD_KPASS i, x, y, z, c, rgb, hdk_diffuse_ag(HD_KPASS HD_PRM(medium).y)), 1,
                           HD_PRM(grid).w) == 0.0f)
        return 0.0f;
    return num - den * HD_GET(phi, ic, x, y, z + c * gz);
}

/* The value an empty voxel (x, y, z) of channel c holds under the surface boundary
   (hdk_diffuse_surface_end: the Marshak extrapolation of its medium neighbours), in *v; returns 1
   for such a voxel, 0 for a medium one or under the box boundary (nothing to store). Multigrid's
   pass after each conjugate-gradient step (its iterate is 0 there: an identity row), so its phi
   holds what the sweeps' does; the same hdk_diffuse_terms, so the same bits for the same
   neighbours. It reads the 6 neighbours' phi (the medium ones' enter): a backend runs it one
   colour ((x + y + z) & 1) at a time, so no voxel it reads is being written. */
HD_FN int hdk_diffuse_extrapolate(HD_KARGS int x, int y, int z, int c, HD_INOUT(float) v)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y;
    int rgb = (HD_DIFFUSE_FLAGS & HD_FLAG_RGB_SCATTERING) != 0 ? 1 : 0;
    float den = 0.0f, num, sp;
    if ((HD_DIFFUSE_FLAGS & (HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_DIFFUSE_RHS)) != HD_FLAG_SURFACE_BOUNDARY) return 0;
    sp = hdk_diffuse_sigp(HD_KPASS (z * gy + y) * gx + x, x, y, z, c, rgb, hdk_diffuse_ag(HD_KPASS HD_PRM(medium).y));
    if (hdk_diffuse_open_of(sp, 1, HD_PRM(grid).w) != 0.0f) return 0;
    num = hdk_diffuse_terms(HD_KPASS x, y, z, c, HD_REF(den));
    HD_DEREF(v) = num / den;
    return 1;
}
