/* hd_scene.h - the volume inside the host's scene: the volume-to-world transform, the camera's
   rays in the volume's frame (look-at, or the host's view and projection matrices) and the
   checks of the host's depth buffer. Part of the core (src/hd_core.h).

   Frames. The volume's box (centred at 0, largest side 1, hd__prepare_volume) is placed in the
   world by an affine transform world = t + Q S box, with Q orthonormal (a rotation, or one with
   a reflection) and S the per-axis scale (the lengths of the transform's first three columns).
   The kernels work in the "volume's frame" k = S box = Q^T (world - t): the box there has the
   per-axis extents box * S (hd_k_params.h's box), and the map from the world is rigid, so a
   distance in it is a distance in the world: extinction per world unit and 1/r^2 in world
   units hold as given. The host maps everything the kernels see of the world into that frame:
   the camera's rays, the lights' directions and positions, the depth buffer's unprojection.
   A shear has no such decomposition (the grid's axes would not stay orthogonal) and is refused. */

/* 1 unless a column-major 4x4 is all zero. */
static int hd__mat_given(const float m[16])
{
    int i;
    for (i = 0; i < 16; ++i)
        if (m[i] != 0.0f) return 1;
    return 0;
}

static int hd__mat_finite(const float m[16])
{
    int i;
    for (i = 0; i < 16; ++i)
        if (!hd__finite(m[i])) return 0;
    return 1;
}

/* c = a b, column-major 4x4 in double. */
static void hd__mat_mul(const double a[16], const double b[16], double c[16])
{
    int r, k, j;
    for (j = 0; j < 4; ++j)
        for (r = 0; r < 4; ++r) {
            double s = 0.0;
            for (k = 0; k < 4; ++k) s += a[k * 4 + r] * b[j * 4 + k];
            c[j * 4 + r] = s;
        }
}

/* The inverse of a column-major 4x4 by Gauss-Jordan elimination with partial pivoting, in
   double; 0 when a pivot falls below 1e-12 of the matrix's largest element (singular for the
   float inputs it comes from) or the result is not finite. */
static int hd__mat_inverse(const double m[16], double inv[16])
{
    double a[4][8], big = 0.0;
    int r, c, k;
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 4; ++c) {
            a[r][c] = m[c * 4 + r];
            a[r][c + 4] = r == c ? 1.0 : 0.0;
            if (fabs(a[r][c]) > big) big = fabs(a[r][c]);
        }
    if (!(big > 0.0)) return 0;
    for (c = 0; c < 4; ++c) {
        int p = c;
        double piv;
        for (r = c + 1; r < 4; ++r)
            if (fabs(a[r][c]) > fabs(a[p][c])) p = r;
        if (!(fabs(a[p][c]) > 1e-12 * big)) return 0;
        if (p != c)
            for (k = 0; k < 8; ++k) { double t = a[c][k]; a[c][k] = a[p][k]; a[p][k] = t; }
        piv = a[c][c];
        for (k = 0; k < 8; ++k) a[c][k] /= piv;
        for (r = 0; r < 4; ++r) {
            double f = a[r][c];
            if (r == c || f == 0.0) continue;
            for (k = 0; k < 8; ++k) a[r][k] -= f * a[c][k];
        }
    }
    for (r = 0; r < 4; ++r)
        for (c = 0; c < 4; ++c) {
            inv[c * 4 + r] = a[r][c + 4];
            if (!(fabs(inv[c * 4 + r]) <= DBL_MAX)) return 0;
        }
    return 1;
}

/* ---- the volume-to-world transform ------------------------------------------------------------ */

#define HD__XFORM_SCALE_MIN 1e-6
#define HD__XFORM_SCALE_MAX 1e6
#define HD__XFORM_SHEAR_TOL 1e-4 /* |cos| between two columns: float inputs of an orthogonal basis
                                    made by a host's matrix library sit far below it */

/* The volume's box (largest side 1) of a validated volume desc, as hd__prepare_volume makes it. */
static void hd__volume_box(const hd_volume_desc *v, float box[3])
{
    double ext[3], emax = 0.0;
    int i, unit = v->spacing[0] == 0.0f && v->spacing[1] == 0.0f && v->spacing[2] == 0.0f;
    for (i = 0; i < 3; ++i) {
        ext[i] = (double)v->dims[i] * (unit ? 1.0 : (double)v->spacing[i]);
        if (ext[i] > emax) emax = ext[i];
    }
    for (i = 0; i < 3; ++i) box[i] = (float)(ext[i] / emax);
}

/* Checks and decomposes the column-major transform m (NULL or all zero: the identity) for a
   volume of box `box` and `dims`. */
static hd_result hd__xform_make(const float *m, const float box[3], const int dims[3], hd__xform *x, const hd_logger *log)
{
    double a[3][3], kb[3], kmax = 0.0;
    int i, j, r;
    memset(x, 0, sizeof *x);
    for (i = 0; i < 3; ++i) { x->q[i][i] = 1.0; x->s[i] = 1.0; }
    x->identity = 1;
    if (!m || !hd__mat_given(m)) return HD_SUCCESS;
    if (!hd__mat_finite(m)) return HD__ERR(log, HD_ERROR_INVALID_TRANSFORM, "volume transform has a NaN or infinite element");
    for (i = 0; i < 16; ++i)
        if (m[i] != ((i % 5) == 0 ? 1.0f : 0.0f)) x->identity = 0;
    if (x->identity) return HD_SUCCESS;
    if (m[3] != 0.0f || m[7] != 0.0f || m[11] != 0.0f || m[15] != 1.0f)
        return HD__ERR(log, HD_ERROR_INVALID_TRANSFORM, "volume transform's last row is (%g, %g, %g, %g), not (0, 0, 0, 1): not affine",
                       (double)m[3], (double)m[7], (double)m[11], (double)m[15]);
    for (j = 0; j < 3; ++j) {
        for (r = 0; r < 3; ++r) a[j][r] = (double)m[j * 4 + r]; /* a[j]: column j */
        x->s[j] = sqrt(a[j][0] * a[j][0] + a[j][1] * a[j][1] + a[j][2] * a[j][2]);
        if (!(x->s[j] >= HD__XFORM_SCALE_MIN && x->s[j] <= HD__XFORM_SCALE_MAX))
            return HD__ERR(log, HD_ERROR_INVALID_TRANSFORM, "volume transform's column %d has length %g, outside [%g, %g]%s", j, x->s[j],
                           HD__XFORM_SCALE_MIN, HD__XFORM_SCALE_MAX, x->s[j] == 0.0 ? " (singular)" : "");
        x->t[j] = (double)m[12 + j];
        if (!(fabs(x->t[j]) <= (double)HD_MAX_LIGHT_DISTANCE))
            return HD__ERR(log, HD_ERROR_INVALID_TRANSFORM, "volume transform's translation %g along axis %d is beyond %g", x->t[j], j,
                           (double)HD_MAX_LIGHT_DISTANCE);
    }
    for (i = 0; i < 3; ++i)
        for (j = i + 1; j < 3; ++j) {
            double c = (a[i][0] * a[j][0] + a[i][1] * a[j][1] + a[i][2] * a[j][2]) / (x->s[i] * x->s[j]);
            if (!(fabs(c) <= HD__XFORM_SHEAR_TOL))
                return HD__ERR(log, HD_ERROR_TRANSFORM_SHEAR,
                               "volume transform's columns %d and %d are not orthogonal (cosine %g): a shear cannot be followed by the "
                               "axis-aligned illumination grid; give scale, rotation, reflection and translation only",
                               i, j, c);
        }
    /* Q: the columns made exactly orthonormal (Gram-Schmidt), the handedness kept */
    for (j = 0; j < 3; ++j) {
        double v[3], n;
        for (r = 0; r < 3; ++r) v[r] = a[j][r];
        for (i = 0; i < j; ++i) {
            double d = v[0] * x->q[0][i] + v[1] * x->q[1][i] + v[2] * x->q[2][i];
            for (r = 0; r < 3; ++r) v[r] -= d * x->q[r][i];
        }
        n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        for (r = 0; r < 3; ++r) x->q[r][j] = v[r] / n;
    }
    /* a voxel must still span enough float steps of the scaled box (hd__check_extent's rule) */
    for (i = 0; i < 3; ++i) {
        kb[i] = (double)box[i] * x->s[i];
        if (kb[i] > kmax) kmax = kb[i];
    }
    for (i = 0; i < 3; ++i)
        if (!(kb[i] / (double)dims[i] * (double)HD_MAX_SPACING_RATIO >= kmax))
            return HD__ERR(log, HD_ERROR_INVALID_TRANSFORM,
                           "volume transform scales a voxel along axis %d to %g of the largest side, below 1/%g", i,
                           kb[i] / (double)dims[i] / kmax, (double)HD_MAX_SPACING_RATIO);
    return HD_SUCCESS;
}

/* The scaled box: the volume's world extents along its own axes. */
static void hd__xform_box(const hd__xform *x, const float box[3], float kbox[3])
{
    int i;
    for (i = 0; i < 3; ++i) kbox[i] = x->identity ? box[i] : (float)((double)box[i] * x->s[i]);
}

/* World point / direction p into the volume's frame: Q^T (p - t), Q^T p. */
static void hd__xform_point(const hd__xform *x, const float p[3], double out[3])
{
    int c;
    for (c = 0; c < 3; ++c)
        out[c] = x->q[0][c] * ((double)p[0] - x->t[0]) + x->q[1][c] * ((double)p[1] - x->t[1]) + x->q[2][c] * ((double)p[2] - x->t[2]);
}
static void hd__xform_dir(const hd__xform *x, const double p[3], double out[3])
{
    int c;
    for (c = 0; c < 3; ++c) out[c] = x->q[0][c] * p[0] + x->q[1][c] * p[1] + x->q[2][c] * p[2];
}

/* Point lights must lie within HD_MAX_LIGHT_DISTANCE world units of the volume's centre along
   its axes (hd__check_lights checks the world position, which is the same with the identity). */
static hd_result hd__check_lights_frame(const hd_light *lights, int count, const hd__xform *x, const hd_logger *log)
{
    int i, c;
    if (x->identity) return HD_SUCCESS;
    for (i = 0; i < count; ++i) {
        double p[3];
        if (lights[i].type == HD_LIGHT_DIRECTIONAL) continue;
        hd__xform_point(x, lights[i].position, p);
        for (c = 0; c < 3; ++c)
            if (!(fabs(p[c]) <= (double)HD_MAX_LIGHT_DISTANCE))
                return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: light %g world units from the volume's centre along its axis %d, beyond %g",
                               i, fabs(p[c]), c, (double)HD_MAX_LIGHT_DISTANCE);
    }
    return HD_SUCCESS;
}

/* ---- the camera's rays in the volume's frame ------------------------------------------------ */

static void hd__store3(float dst[3], const double v[3])
{
    dst[0] = (float)v[0]; dst[1] = (float)v[1]; dst[2] = (float)v[2];
}

/* The look-at camera (defaults filled in, hd__check_camera passed): the basis exactly as the
   kernels always had it, in float, then (a placed volume only) mapped into the volume's frame. */
static void hd__camframe_lookat(const hd_camera *c, const hd__xform *x, hd__camframe *cf)
{
    float w[3], u[3], v[3], th, aspect;
    int i;
    /* through unit vectors (hd__unit3: a tiny up must not underflow the cross product;
       hd__check_camera keeps it away from parallel) */
    for (i = 0; i < 3; ++i) v[i] = c->target[i] - c->eye[i];
    hd__unit3(v, w);
    hd__unit3(c->up, u);
    v[0] = w[1] * u[2] - w[2] * u[1];
    v[1] = w[2] * u[0] - w[0] * u[2];
    v[2] = w[0] * u[1] - w[1] * u[0];
    hd__unit3(v, u);
    v[0] = u[1] * w[2] - u[2] * w[1];
    v[1] = u[2] * w[0] - u[0] * w[2];
    v[2] = u[0] * w[1] - u[1] * w[0];
    th = tanf(0.5f * c->fov_y * 3.14159265f / 180.0f);
    aspect = (float)c->width / (float)c->height;
    memset(cf, 0, sizeof *cf);
    for (i = 0; i < 3; ++i) {
        cf->pos[i] = c->eye[i];
        cf->u[i] = u[i] * th * aspect;
        cf->v[i] = v[i] * th;
        cf->w[i] = w[i];
    }
    if (!x->identity) {
        double p[3], d[3];
        hd__xform_point(x, c->eye, p);
        hd__store3(cf->pos, p);
        for (i = 0; i < 3; ++i) p[i] = cf->u[i];
        hd__xform_dir(x, p, d);
        hd__store3(cf->u, d);
        for (i = 0; i < 3; ++i) p[i] = cf->v[i];
        hd__xform_dir(x, p, d);
        hd__store3(cf->v, d);
        for (i = 0; i < 3; ++i) p[i] = cf->w[i];
        hd__xform_dir(x, p, d);
        hd__store3(cf->w, d);
    }
}

/* The matrix camera: rays from the inverse of projection * view, mapped into the volume's frame
   (Mk = frame * (P V)^-1, clip to frame; its columns m0..m3). Perspective: every ray passes the
   centre of projection, Mk (0, 0, 1, 0) (clip x = y = w = 0), and the point of NDC (sx, sy) on
   the near plane, Mk (sx, sy, zn, 1), whose offset from the centre is linear in sx, sy once both
   are scaled by its w: c + sx u + sy v. Orthographic: origins on the near plane, linear in sx,
   sy, one direction toward the far plane. */
static hd_result hd__camframe_matrix(const hd_camera *c, const hd__xform *x, hd__camframe *cf, const hd_logger *log)
{
    double V[16], P[16], M[16], Mi[16], F[16], Mk[16], vmax = 0.0, lmax = 0.0, zn, zf;
    int i, r, persp;
    const float *pr = c->projection;
    memset(cf, 0, sizeof *cf);
    cf->matrix = 1;
    if (!hd__mat_finite(c->view) || !hd__mat_finite(c->projection))
        return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera view or projection matrix has a NaN or infinite element");
    for (i = 0; i < 16; ++i) {
        V[i] = hd__mat_given(c->view) ? (double)c->view[i] : (i % 5 == 0 ? 1.0 : 0.0);
        P[i] = (double)pr[i];
        if (fabs(V[i]) > vmax) vmax = fabs(V[i]);
    }
    if (fabs(V[3]) > 1e-6 * vmax || fabs(V[7]) > 1e-6 * vmax || fabs(V[11]) > 1e-6 * vmax || fabs(V[15] - 1.0) > 1e-6)
        return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera view matrix's last row is (%g, %g, %g, %g), not (0, 0, 0, 1)", V[3], V[7],
                       V[11], V[15]);
    for (i = 0; i < 4; ++i)
        if (fabs(P[i * 4 + 3]) > lmax) lmax = fabs(P[i * 4 + 3]);
    if (fabs(P[3]) <= 1e-6 * lmax && fabs(P[7]) <= 1e-6 * lmax && fabs(P[15]) <= 1e-6 * lmax && lmax > 0.0) persp = 1;
    else if (fabs(P[3]) <= 1e-6 * lmax && fabs(P[7]) <= 1e-6 * lmax && fabs(P[11]) <= 1e-6 * lmax && lmax > 0.0) persp = 0;
    else
        return HD__ERR(log, HD_ERROR_INVALID_CAMERA,
                       "camera projection's last row (%g, %g, %g, %g) is neither perspective (0, 0, a, 0) nor orthographic (0, 0, 0, b)",
                       P[3], P[7], P[11], P[15]);
    hd__mat_mul(P, V, M);
    if (!hd__mat_inverse(M, Mi)) return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera projection * view is singular");
    /* F: world -> the volume's frame, [Q^T, -Q^T t] */
    memset(F, 0, sizeof F);
    for (r = 0; r < 3; ++r) { /* column r of Q^T: row r of Q */
        F[r * 4 + 0] = x->q[r][0]; F[r * 4 + 1] = x->q[r][1]; F[r * 4 + 2] = x->q[r][2];
    }
    for (r = 0; r < 3; ++r)
        F[12 + r] = -(x->q[0][r] * x->t[0] + x->q[1][r] * x->t[1] + x->q[2][r] * x->t[2]);
    F[15] = 1.0;
    hd__mat_mul(F, Mi, Mk);
    zn = c->depth_range == HD_DEPTH_NEG_ONE_TO_ONE ? -1.0 : c->depth_range == HD_DEPTH_ZERO_TO_ONE ? 0.0 : 1.0;
    zf = c->depth_range == HD_DEPTH_REVERSED ? 0.0 : 1.0;
    {
        const double *m0 = Mk, *m1 = Mk + 4, *m2 = Mk + 8, *m3 = Mk + 12;
        double hn[4], cc[3], uu[3], vv[3], n;
        for (i = 0; i < 4; ++i) hn[i] = zn * m2[i] + m3[i]; /* the near plane's centre, homogeneous */
        if (persp) {
            double e[3], sgn;
            if (!(fabs(m2[3]) > 1e-12 * (fabs(m2[0]) + fabs(m2[1]) + fabs(m2[2]))))
                return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera projection has no centre of projection");
            for (i = 0; i < 3; ++i) e[i] = m2[i] / m2[3];
            sgn = hn[3] < 0.0 ? -1.0 : 1.0;
            for (i = 0; i < 3; ++i) {
                cc[i] = sgn * (hn[i] - e[i] * hn[3]);
                uu[i] = sgn * (m0[i] - e[i] * m0[3]);
                vv[i] = sgn * (m1[i] - e[i] * m1[3]);
            }
            n = sqrt(cc[0] * cc[0] + cc[1] * cc[1] + cc[2] * cc[2]);
            if (!(n > 0.0)) return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera projection's near plane passes its centre");
            for (i = 0; i < 3; ++i) { cc[i] /= n; uu[i] /= n; vv[i] /= n; }
            hd__store3(cf->pos, e);
            hd__store3(cf->w, cc);
            hd__store3(cf->u, uu);
            hd__store3(cf->v, vv);
        } else {
            double hf[4], o[3], d[3];
            for (i = 0; i < 4; ++i) hf[i] = zf * m2[i] + m3[i];
            if (!(fabs(hn[3]) > 0.0) || !(fabs(hf[3]) > 0.0))
                return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera projection maps its near or far plane to infinity");
            for (i = 0; i < 3; ++i) {
                o[i] = hn[i] / hn[3];
                d[i] = hf[i] / hf[3] - o[i];
                uu[i] = (m0[i] - o[i] * m0[3]) / hn[3];
                vv[i] = (m1[i] - o[i] * m1[3]) / hn[3];
            }
            n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
            if (!(n > 0.0)) return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera projection's near and far planes coincide");
            for (i = 0; i < 3; ++i) d[i] /= n;
            hd__store3(cf->pos, o);
            hd__store3(cf->w, d);
            hd__store3(cf->ou, uu);
            hd__store3(cf->ov, vv);
        }
    }
    for (r = 0; r < 4; ++r)
        for (i = 0; i < 4; ++i) cf->dm[r * 4 + i] = (float)Mk[i * 4 + r];
    cf->depth_z[0] = c->depth_range == HD_DEPTH_NEG_ONE_TO_ONE ? 2.0f : 1.0f;
    cf->depth_z[1] = c->depth_range == HD_DEPTH_NEG_ONE_TO_ONE ? -1.0f : 0.0f;
    cf->depth_z[2] = (float)zf;
    {
        /* the volume's depth out: G = P V [Q, t] (the volume's frame to clip); window depth * w =
           (G2 - b G3) / a for NDC z = a depth + b; q = 1 - depth (depth when reversed) times w */
        double Wm[16], G[16], a = (double)cf->depth_z[0], b = (double)cf->depth_z[1];
        memset(Wm, 0, sizeof Wm);
        for (i = 0; i < 3; ++i)
            for (r = 0; r < 3; ++r) Wm[i * 4 + r] = x->q[r][i];
        for (r = 0; r < 3; ++r) Wm[12 + r] = x->t[r];
        Wm[15] = 1.0;
        hd__mat_mul(M, Wm, G);
        for (i = 0; i < 4; ++i) {
            double dz = (G[i * 4 + 2] - b * G[i * 4 + 3]) / a;
            cf->dq[i] = (float)(c->depth_range == HD_DEPTH_REVERSED ? dz : G[i * 4 + 3] - dz);
            cf->dw[i] = (float)G[i * 4 + 3];
        }
    }
    for (i = 0; i < 3; ++i)
        if (!hd__finite(cf->pos[i]) || !hd__finite(cf->u[i]) || !hd__finite(cf->v[i]) || !hd__finite(cf->w[i]) ||
            !hd__finite(cf->ou[i]) || !hd__finite(cf->ov[i]))
            return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera matrices give rays beyond float range");
    for (i = 0; i < 16; ++i)
        if (!hd__finite(cf->dm[i])) return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera matrices' inverse is beyond float range");
    return HD_SUCCESS;
}

/* The camera (defaults filled in, hd__check_camera passed) as rays in the volume's frame of
   transform x and scaled box kbox, and the distance limit: its ray origins (look-at: eye and
   target) within HD_MAX_CAMERA_DISTANCE times the volume's largest world side of its centre,
   along each of its axes (with the identity transform: of the origin, in world units). */
static hd_result hd__camera_frame(const hd_camera *c, const hd__xform *x, const float kbox[3], hd__camframe *cf,
                                  const hd_logger *log)
{
    double lim = (double)HD_MAX_CAMERA_DISTANCE * (double)hd__max3(kbox), p[4][3];
    int i, k, n = 1;
    hd_result r;
    if (hd__mat_given(c->projection)) {
        if ((r = hd__camframe_matrix(c, x, cf, log)) != HD_SUCCESS) return r;
        for (k = 0; k < 4; ++k) /* an orthographic camera's corner origins, the eye four times */
            for (i = 0; i < 3; ++i)
                p[k][i] = (double)cf->pos[i] + ((k & 1) ? -1.0 : 1.0) * cf->ou[i] + ((k & 2) ? -1.0 : 1.0) * cf->ov[i];
        n = 4;
    } else {
        hd__camframe_lookat(c, x, cf);
        if (x->identity)
            for (i = 0; i < 3; ++i) { p[0][i] = c->eye[i]; p[1][i] = c->target[i]; }
        else {
            hd__xform_point(x, c->eye, p[0]);
            hd__xform_point(x, c->target, p[1]);
        }
        n = 2;
    }
    for (k = 0; k < n; ++k)
        for (i = 0; i < 3; ++i)
            if (!(fabs(p[k][i]) <= lim))
                return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera %s %g beyond %g from the volume's centre along its axis %d (%g times its largest side)",
                               cf->matrix ? "ray origin" : k == 0 ? "eye" : "target", fabs(p[k][i]), lim, i,
                               (double)HD_MAX_CAMERA_DISTANCE);
    return HD_SUCCESS;
}

/* ---- the host's depth buffer ------------------------------------------------------------------ */
/* Checks depth (not NULL, data not NULL) for a camera c whose frame is cf. */
static hd_result hd__check_depth(const hd_depth_desc *d, const hd_camera *c, const hd__camframe *cf, const hd_logger *log)
{
    size_t i, n;
    if (!cf->matrix)
        return HD__ERR(log, HD_ERROR_DEPTH_NEEDS_PROJECTION,
                       "hd_set_depth: the camera is a look-at camera; depth is read through the host's projection (camera.projection)");
    if (d->width != c->width || d->height != c->height)
        return HD__ERR(log, HD_ERROR_DEPTH_SIZE, "hd_set_depth: depth is %dx%d, the camera %dx%d", d->width, d->height, c->width, c->height);
    n = (size_t)d->width * (size_t)d->height;
    for (i = 0; i < n; ++i) {
        float v = d->data[i];
        if (!hd__finite(v) || v < 0.0f || v > 1.0f)
            return HD__ERR(log, HD_ERROR_INVALID_DEPTH, "hd_set_depth: depth at pixel (%d, %d) is %g, not in [0, 1]", (int)(i % (size_t)d->width),
                           (int)(i / (size_t)d->width), (double)v);
    }
    return HD_SUCCESS;
}
