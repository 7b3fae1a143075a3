/* hd_kparams.h - the kernels' parameter block (backends/kernels/hd_k_params.h) packed from the
   context. Part of the core (src/hd_core.h). */
/* ---- the kernels' parameter block ------------------------------------------------------------ */
static void hd__fill_kparams(hd__ctx *ctx)
{
    hd__kparams *k = &ctx->vw.kp;
    const hd_camera *c = &ctx->vw.camera;
    float w[3], u[3], v[3], th, aspect;
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
    k->box.x = ctx->box[0]; k->box.y = ctx->box[1]; k->box.z = ctx->box[2]; k->box.w = 0.0795774715f;
    k->medium.x = ctx->vw.params.extinction; k->medium.y = ctx->vw.params.albedo;
    k->medium.z = ctx->vw.params.method == HD_METHOD_PT_SS ? 0.0f : ctx->vw.params.anisotropy;
    k->medium.w = ctx->vw.params.majorant;
    for (i = 0; i < 3; ++i) {
        float h = ctx->box[i] / (float)ctx->vw.gdims[i];
        (&k->grid.x)[i] = 1.0f / (h * h);
        (&k->gridh.x)[i] = h;
    }
    k->grid.w = 1e-3f; /* sigma' floor: keeps D finite in empty space */
    {
        float vs = ctx->box[0] / (float)ctx->vw.dims[0];
        if (ctx->box[1] / (float)ctx->vw.dims[1] < vs) vs = ctx->box[1] / (float)ctx->vw.dims[1];
        if (ctx->box[2] / (float)ctx->vw.dims[2] < vs) vs = ctx->box[2] / (float)ctx->vw.dims[2];
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
    /* camera basis, through unit vectors (hd__unit3: a tiny up must not underflow the cross
       product; hd__check_camera keeps it away from parallel) */
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
    k->cam_pos.x = c->eye[0]; k->cam_pos.y = c->eye[1]; k->cam_pos.z = c->eye[2];
    k->cam_u.x = u[0] * th * aspect; k->cam_u.y = u[1] * th * aspect; k->cam_u.z = u[2] * th * aspect;
    k->cam_v.x = v[0] * th; k->cam_v.y = v[1] * th; k->cam_v.z = v[2] * th;
    k->cam_w.x = w[0]; k->cam_w.y = w[1]; k->cam_w.z = w[2];
    k->background.x = ctx->vw.params.background[0];
    k->background.y = ctx->vw.params.background[1];
    k->background.z = ctx->vw.params.background[2];
    k->chan_color.x = ctx->chan_color[0]; k->chan_color.y = ctx->chan_color[1]; k->chan_color.z = ctx->chan_color[2];
    /* the crop box is on when it cuts an axis; an axis it spans whole gets bounds no sample
       reaches, so samples at the volume's faces stay as without a crop box */
    for (i = 0; i < 3; ++i) {
        (&k->crop_lo.x)[i] = ctx->vw.params.crop_min[i] > 0.0f ? ctx->vw.params.crop_min[i] : -1.0f;
        (&k->crop_hi.x)[i] = ctx->vw.params.crop_max[i] < 1.0f ? ctx->vw.params.crop_max[i] : 2.0f;
        if (ctx->vw.params.crop_min[i] > 0.0f || ctx->vw.params.crop_max[i] < 1.0f) k->crop_lo.w = 1.0f;
    }
    for (i = 0; i < ctx->light_count; ++i) {
        const hd_light *l = &ctx->lights[i];
        hd_f4 *a = &k->light_a[i], *b = &k->light_b[i];
        if (l->type == HD_LIGHT_DIRECTIONAL) {
            float n[3];
            hd__unit3(l->direction, n); /* nonzero: hd__check_lights */
            a->x = n[0]; a->y = n[1]; a->z = n[2]; a->w = 0.0f;
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
