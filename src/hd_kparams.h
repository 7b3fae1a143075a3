/* hd_kparams.h - the kernels' parameter block (backends/kernels/hd_k_params.h) packed from the
   context. Part of the core (src/hd_core.h). */
/* ---- the kernels' parameter block ------------------------------------------------------------ */
/* A vector of the world in the volume's frame (lengths kept: the frame's axes are unit). */
static void hd__dir_to_volume(const hd__ctx *ctx, const float v[3], double out[3])
{
    double dv[3] = {v[0], v[1], v[2]};
    if (ctx->xf.identity) { out[0] = dv[0]; out[1] = dv[1]; out[2] = dv[2]; }
    else hd__xform_dir(&ctx->xf, dv, out);
}

/* An area light's shape in the volume's frame (hd_k_light.h, hdk_light_pick): a quad's edges
   and area, a disk's unit normal, radius and a unit tangent, a sphere's radius. */
static void hd__area_kparams(const hd__ctx *ctx, const hd_light *l, hd_f4 *c, hd_f4 *d)
{
    double e1[3], e2[3], n[3], t[3], len;
    if (l->type == HD_LIGHT_QUAD) {
        hd__dir_to_volume(ctx, l->edge1, e1);
        hd__dir_to_volume(ctx, l->edge2, e2);
        n[0] = e1[1] * e2[2] - e1[2] * e2[1];
        n[1] = e1[2] * e2[0] - e1[0] * e2[2];
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        c->x = (float)e1[0]; c->y = (float)e1[1]; c->z = (float)e1[2];
        c->w = (float)sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        d->x = (float)e2[0]; d->y = (float)e2[1]; d->z = (float)e2[2];
    } else if (l->type == HD_LIGHT_DISK) {
        float f[3], u[3];
        hd__dir_to_volume(ctx, l->direction, n);
        hd__store3(f, n);
        hd__unit3(f, u); /* nonzero: hd__check_area_light */
        c->x = u[0]; c->y = u[1]; c->z = u[2]; c->w = l->radius;
        /* a tangent: the normal crossed with the axis it is least along */
        if (fabsf(u[0]) < 0.6f) { t[0] = 0.0; t[1] = u[2]; t[2] = -u[1]; }
        else { t[0] = -u[2]; t[1] = 0.0; t[2] = u[0]; }
        len = sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
        d->x = (float)(t[0] / len); d->y = (float)(t[1] / len); d->z = (float)(t[2] / len);
    } else {
        c->x = c->y = c->z = 0.0f; c->w = l->radius;
        d->x = d->y = d->z = 0.0f;
    }
}

/* The share of the lights' samples each light gets unconditionally: the rest goes by the
   estimate, so a light the estimate gets wrong is still sampled often enough. */
#define HD__LIGHT_UNIFORM_SHARE 0.1

/* The chance the kernels draw each light with (hdk_light_choose, hd_k_light.h): its estimated
   light at the box's centre over the sum, mixed with a uniform share; the CDF over the list in
   light_d[l].w, the environment the rest up to 1. The estimate is the fluence at the centre
   in the open (largest channel): a directional light's irradiance, a point light's intensity
   over r^2 (r at least half the box's diagonal), an area light's radiance times the solid angle
   it subtends (at most 2 pi), the map's integral. */
static void hd__light_cdf(const hd__ctx *ctx, hd__kparams *k)
{
    double est[HD_MAX_LIGHTS + 1], sum = 0.0, acc = 0.0, hb2;
    const float *box = ctx->kbox;
    int i, n = ctx->light_count, nl = n + (ctx->env_on ? 1 : 0);
    hb2 = 0.25 * ((double)box[0] * box[0] + (double)box[1] * box[1] + (double)box[2] * box[2]);
    for (i = 0; i < n; ++i) {
        const hd_light *l = &ctx->lights[i];
        const hd_f4 *a = &k->light_a[i], *b = &k->light_b[i], *c = &k->light_c[i];
        double rad = b->x > b->y ? b->x : b->y, r2 = (double)a->x * a->x + (double)a->y * a->y + (double)a->z * a->z;
        if (b->z > rad) rad = b->z;
        if (r2 < hb2) r2 = hb2;
        if (l->type == HD_LIGHT_DIRECTIONAL || (l->type == HD_LIGHT_POINT && !l->inverse_square)) est[i] = rad;
        else if (l->type == HD_LIGHT_POINT) est[i] = rad / r2;
        else {
            double area = l->type == HD_LIGHT_QUAD ? (double)c->w : 3.14159265358979323846 * (double)c->w * (double)c->w;
            double omega = area / r2;
            if (l->type == HD_LIGHT_QUAD) { /* the centre, not the corner */
                double m[3] = {a->x + 0.5 * (k->light_c[i].x + k->light_d[i].x), a->y + 0.5 * (k->light_c[i].y + k->light_d[i].y),
                               a->z + 0.5 * (k->light_c[i].z + k->light_d[i].z)};
                double q2 = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
                omega = area / (q2 > hb2 ? q2 : hb2);
            }
            est[i] = rad * (omega < 6.283185307179586 ? omega : 6.283185307179586);
        }
        if (!(est[i] >= 0.0) || est[i] > 1e30) est[i] = 0.0;
        sum += est[i];
    }
    if (ctx->env_on) { est[n] = ctx->env_fluence; sum += est[n]; }
    for (i = 0; i < n; ++i) {
        double p = 1.0 / (double)nl;
        if (!ctx->light_uniform && sum > 0.0)
            p = (1.0 - HD__LIGHT_UNIFORM_SHARE) * est[i] / sum + HD__LIGHT_UNIFORM_SHARE / (double)nl;
        acc += p;
        k->light_d[i].w = (float)acc;
    }
    if (n > 0 && !ctx->env_on) k->light_d[n - 1].w = 1.0f;
}

static void hd__fill_kparams(hd__ctx *ctx)
{
    hd__kparams *k = &ctx->vw.kp;
    const hd_camera *c = &ctx->vw.camera;
    const hd__camframe *cf = &ctx->cf;
    const float *box = ctx->kbox; /* the volume's world extents (src/hd_scene.h) */
    int i;
    memset(k, 0, sizeof *k);
    k->dims.x = ctx->vw.dims[0]; k->dims.y = ctx->vw.dims[1]; k->dims.z = ctx->vw.dims[2]; k->dims.w = ctx->vw.tf_count;
    k->gdims.x = ctx->vw.gdims[0]; k->gdims.y = ctx->vw.gdims[1]; k->gdims.z = ctx->vw.gdims[2]; k->gdims.w = ctx->vw.channels;
    k->mdims.x = ctx->vw.mdims[0]; k->mdims.y = ctx->vw.mdims[1]; k->mdims.z = ctx->vw.mdims[2]; k->mdims.w = HD__MAJORANT_CELL;
    k->counts.x = ctx->light_count;
    k->counts.y = ctx->vw.params.tracking == HD_TRACKING_DELTA ? HD_TRACK_DELTA : HD_TRACK_RATIO;
    k->counts.z = (ctx->vw.params.majorant > 0.0f ? HD_FLAG_GLOBAL_MAJORANT : 0) |
                  (ctx->vw.params.disable_diffusion ? HD_FLAG_NO_DIFFUSION : 0) |
                  (ctx->vw.params.rgb_scattering ? HD_FLAG_RGB_SCATTERING : 0) |
                  (ctx->vw.params.diffusion_boundary == HD_BOUNDARY_SURFACE ? HD_FLAG_SURFACE_BOUNDARY : 0);
    /* PT_SS is the path kernel with one vertex and the isotropic phase (hd_k_path.h) */
    k->counts.w = ctx->vw.params.method == HD_METHOD_PT_SS ? 1 : ctx->vw.params.max_bounces;
    k->frame.x = (int32_t)ctx->iterations;
    k->frame.y = (int32_t)ctx->frames;
    k->frame.z = (int32_t)ctx->vw.params.seed;
    k->image.x = c->width; k->image.y = c->height; k->image.z = (int32_t)ctx->vw.params.method;
    k->region.z = (int32_t)hd__image_depth_first(c->width, c->height, ctx->image_room); /* the depth plane */
    k->box.x = box[0]; k->box.y = box[1]; k->box.z = box[2]; k->box.w = 0.0795774715f;
    k->medium.x = ctx->vw.params.extinction; k->medium.y = ctx->vw.params.albedo;
    k->medium.z = ctx->vw.params.method == HD_METHOD_PT_SS ? 0.0f : ctx->vw.params.anisotropy;
    k->medium.w = ctx->vw.params.majorant;
    for (i = 0; i < 3; ++i) {
        float h = box[i] / (float)ctx->vw.gdims[i];
        (&k->grid.x)[i] = 1.0f / (h * h);
        (&k->gridh.x)[i] = h;
    }
    k->grid.w = 1e-3f; /* sigma' floor: keeps D finite in empty space */
    k->gridh.w = HD_BOX_DIAGONAL * hd__max3(box); /* a camera ray's chord is at most this long */
    {
        float vs = box[0] / (float)ctx->vw.dims[0];
        if (box[1] / (float)ctx->vw.dims[1] < vs) vs = box[1] / (float)ctx->vw.dims[1];
        if (box[2] / (float)ctx->vw.dims[2] < vs) vs = box[2] / (float)ctx->vw.dims[2];
        k->march.x = ctx->vw.params.step * vs;
    }
    {
        /* HD and CD: a windowed mean that follows the converging illumination; the path
           tracers' frames are independent unbiased estimates: a plain 1/n mean */
        uint64_t f = ctx->frames < 1 ? 1 : ctx->frames;
        uint64_t win = hd__method_is_pt(ctx->vw.params.method) ? f : (uint64_t)ctx->vw.params.frame_window;
        k->march.y = (float)(1.0 / (double)(f < win ? f : win));
    }
    k->march.z = 1e-4f; /* stop marching below this transmittance */
    k->march.w = 1.0f / (float)(ctx->dl_n < 1 ? 1 : ctx->dl_n); /* E's running mean: the new sample's weight */
    /* the camera's rays in the volume's frame (hd__camera_frame); the host's depth buffer */
    k->cam_pos.x = cf->pos[0]; k->cam_pos.y = cf->pos[1]; k->cam_pos.z = cf->pos[2];
    k->cam_u.x = cf->u[0]; k->cam_u.y = cf->u[1]; k->cam_u.z = cf->u[2];
    k->cam_v.x = cf->v[0]; k->cam_v.y = cf->v[1]; k->cam_v.z = cf->v[2];
    k->cam_w.x = cf->w[0]; k->cam_w.y = cf->w[1]; k->cam_w.z = cf->w[2];
    k->cam_ou.x = cf->ou[0]; k->cam_ou.y = cf->ou[1]; k->cam_ou.z = cf->ou[2];
    k->cam_ov.x = cf->ov[0]; k->cam_ov.y = cf->ov[1]; k->cam_ov.z = cf->ov[2];
    k->depth_z.w = 1.0f - ctx->vw.params.depth_threshold; /* the volume's depth: T at the crossing */
    k->depth_q.x = cf->dq[0]; k->depth_q.y = cf->dq[1]; k->depth_q.z = cf->dq[2]; k->depth_q.w = cf->dq[3];
    k->depth_w.x = cf->dw[0]; k->depth_w.y = cf->dw[1]; k->depth_w.z = cf->dw[2]; k->depth_w.w = cf->dw[3];
    if ((ctx->vw.depth || ctx->vw.depth_device) && cf->matrix) {
        k->depth_dims.x = ctx->vw.depth_w; k->depth_dims.y = ctx->vw.depth_h; k->depth_dims.z = 1;
        k->depth_dims.w = ctx->vw.depth_device == 1; /* rows bottom first */
        k->depth_z.x = cf->depth_z[0]; k->depth_z.y = cf->depth_z[1]; k->depth_z.z = cf->depth_z[2];
        for (i = 0; i < 4; ++i) {
            (&k->depth_m0.x)[i] = cf->dm[i]; (&k->depth_m1.x)[i] = cf->dm[4 + i];
            (&k->depth_m2.x)[i] = cf->dm[8 + i]; (&k->depth_m3.x)[i] = cf->dm[12 + i];
        }
    }

    k->background.x = ctx->vw.params.background[0];
    k->background.y = ctx->vw.params.background[1];
    k->background.z = ctx->vw.params.background[2];
    k->background.w = ctx->env_on && ctx->vw.params.environment_background ? 1.0f : 0.0f; /* hdk_env_background */
    k->vstore.x = ctx->vw.vtype;
    k->vnorm.x = ctx->vw.vnorm[0]; k->vnorm.y = ctx->vw.vnorm[1];
    k->chan_color.x = ctx->chan_color[0]; k->chan_color.y = ctx->chan_color[1]; k->chan_color.z = ctx->chan_color[2];
    /* the crop box is on when it cuts an axis; an axis it spans whole gets bounds no sample
       reaches, so samples at the volume's faces stay as without a crop box */
    for (i = 0; i < 3; ++i) {
        (&k->crop_lo.x)[i] = ctx->vw.params.crop_min[i] > 0.0f ? ctx->vw.params.crop_min[i] : -1.0f;
        (&k->crop_hi.x)[i] = ctx->vw.params.crop_max[i] < 1.0f ? ctx->vw.params.crop_max[i] : 2.0f;
        if (ctx->vw.params.crop_min[i] > 0.0f || ctx->vw.params.crop_max[i] < 1.0f) k->crop_lo.w = 1.0f;
    }
    hd__env_kparams(ctx, k);
    for (i = 0; i < ctx->light_count; ++i) {
        const hd_light *l = &ctx->lights[i];
        hd_f4 *a = &k->light_a[i], *b = &k->light_b[i];
        /* in the volume's frame: directions by Q^T, positions by Q^T (p - t) (src/hd_scene.h) */
        if (l->type == HD_LIGHT_DIRECTIONAL) {
            float n[3], m[3];
            hd__unit3(l->direction, n); /* nonzero: hd__check_lights */
            if (!ctx->xf.identity) {
                double dn[3] = {n[0], n[1], n[2]}, dm[3];
                hd__xform_dir(&ctx->xf, dn, dm);
                hd__store3(m, dm);
                hd__unit3(m, n);
            }
            a->x = n[0]; a->y = n[1]; a->z = n[2]; a->w = 0.0f;
        } else if (!ctx->xf.identity) {
            double q[3];
            hd__xform_point(&ctx->xf, l->position, q);
            a->x = (float)q[0]; a->y = (float)q[1]; a->z = (float)q[2]; a->w = (float)l->type;
        } else {
            a->x = l->position[0]; a->y = l->position[1]; a->z = l->position[2]; a->w = (float)l->type;
        }
        if (l->type >= HD_LIGHT_QUAD) hd__area_kparams(ctx, l, &k->light_c[i], &k->light_d[i]);
        if (ctx->vw.channels == 1) {
            b->x = b->y = b->z = l->intensity * hd__max3(l->color); /* the colour is chan_color */
        } else {
            b->x = l->color[0] * l->intensity; b->y = l->color[1] * l->intensity; b->z = l->color[2] * l->intensity;
        }
        b->w = l->type == HD_LIGHT_POINT && l->inverse_square ? 1.0f : 0.0f;
    }
    hd__light_cdf(ctx, k);
}
