/* hd_kparams.h - the kernels' parameter block (backends/kernels/hd_k_params.h) packed from the
   context. Part of the core (src/hd_core.h). */
/* ---- the kernels' parameter block ------------------------------------------------------------ */
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
            a->x = (float)q[0]; a->y = (float)q[1]; a->z = (float)q[2]; a->w = 1.0f;
        } else {
            a->x = l->position[0]; a->y = l->position[1]; a->z = l->position[2]; a->w = 1.0f;
        }
        if (ctx->vw.channels == 1) {
            b->x = b->y = b->z = l->intensity * hd__max3(l->color); /* the colour is chan_color */
        } else {
            b->x = l->color[0] * l->intensity; b->y = l->color[1] * l->intensity; b->z = l->color[2] * l->intensity;
        }
        b->w = l->type == HD_LIGHT_POINT && l->inverse_square ? 1.0f : 0.0f;
    }
}
