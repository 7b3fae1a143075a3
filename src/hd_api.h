/* hd_api.h - the public calls: names, the context's life cycle and the setters. Part of the core
   (src/hd_core.h). */
/* ---- names ----------------------------------------------------------------------------------- */
HDDEF const char *hd_result_string(hd_result result)
{
    switch (result) {
#define HD__X(name, text) case name: return #name ": " text;
        HD__RESULT_LIST(HD__X)
#undef HD__X
    default: return "HD_ERROR_UNKNOWN: not a hd_result value";
    }
}

HDDEF const char *hd_method_name(hd_method method)
{
    switch (method) {
    case HD_METHOD_DEFAULT: return "default";
    case HD_METHOD_HD: return "HD";
    case HD_METHOD_CD: return "CD";
    case HD_METHOD_PT_SS: return "PT_SS";
    case HD_METHOD_PT_MS: return "PT_MS";
    default: return "unknown";
    }
}

HDDEF const char *hd_backend_name(void) { return hd__be_name(); }

HDDEF void hd_log_stderr(void *user_data, hd_log_level level, hd_result code, const char *message,
                         const char *file, int line)
{
    static const char *names[] = {"error", "warning", "info"};
    (void)user_data; (void)file; (void)line;
    fprintf(stderr, "hybriddiff %s: %s%s%s\n", names[level <= HD_LOG_INFO ? level : 0], message,
            code != HD_SUCCESS ? " -- " : "", code != HD_SUCCESS ? hd_result_string(code) : "");
}

/* ---- life cycle ---------------------------------------------------------------------------- */
static void hd__conv_free(hd__ctx *ctx);

static void hd__direct_mask_free(hd__ctx *ctx);

static void hd__ctx_free(hd__ctx *ctx)
{
    hd__conv_free(ctx);
    hd__direct_mask_free(ctx);
    if (ctx->vw.be) hd__be_destroy(&ctx->vw);
    hd__free(&ctx->vw, ctx->vw.vol);
    hd__free(&ctx->vw, ctx->cell_range);
    hd__free(&ctx->vw, ctx->vw.majorant);
    hd__free(&ctx->vw, ctx->vw.tf);
    hd__free(&ctx->vw, ctx->srgb);
    hd__free(&ctx->vw, ctx->vw.depth);
    hd__free(&ctx->vw, ctx->vw.env);
    hd__free(&ctx->vw, ctx);
}

HDDEF hd_result hd_create(const hd_desc *desc, hd_context *out_ctx)
{
    hd_desc d;
    hd_params given;
    const hd_logger *log;
    hd__ctx *ctx;
    hd_result r;
    hd_light default_light;
    hd__xform xf;
    hd__camframe cf;
    float box[3], kbox[3];
    if (!desc) return HD_ERROR_NULL_POINTER; /* no logger to tell */
    log = &desc->logger;
    if (!out_ctx) return HD__ERR(log, HD_ERROR_NULL_POINTER, "hd_create: out_ctx is NULL");
    out_ctx->id = 0;
    d = *desc;
    if ((d.allocator.alloc == NULL) != (d.allocator.free == NULL))
        return HD__ERR(log, HD_ERROR_NULL_POINTER, "allocator: give both alloc and free, or neither");
    /* validate everything first: nothing is allocated for a bad desc */
    if ((r = hd__check_volume(&d.volume, log)) != HD_SUCCESS) return r;
    if ((r = hd__check_tf(&d.transfer_function, log)) != HD_SUCCESS) return r;
    memset(&default_light, 0, sizeof default_light);
    default_light.direction[2] = -1.0f;
    if (!d.lights && d.light_count == 0) { d.lights = &default_light; d.light_count = 1; }
    if ((r = hd__check_lights(d.lights, d.light_count, -1.0, log)) != HD_SUCCESS) return r;
    hd__volume_box(&d.volume, box);
    if ((r = hd__xform_make(d.volume.transform, box, d.volume.dims, &xf, log)) != HD_SUCCESS) return r;
    hd__xform_box(&xf, box, kbox);
    if ((r = hd__check_lights_frame(d.lights, d.light_count, &xf, log)) != HD_SUCCESS) return r;
    hd__camera_defaults(&d.camera);
    if ((r = hd__check_camera(&d.camera, log)) != HD_SUCCESS) return r;
    if ((r = hd__camera_frame(&d.camera, &xf, kbox, &cf, log)) != HD_SUCCESS) return r;
    given = d.params;
    hd__params_defaults(&d.params, d.volume.dims, 0);
    if ((r = hd__check_params(&d.params, log)) != HD_SUCCESS) return r;
    if ((r = hd__check_grid(d.volume.dims, &d.params, log)) != HD_SUCCESS) return r;
    if ((r = hd__check_cd_lights(d.params.method, d.lights, d.light_count, "hd_create", log)) != HD_SUCCESS) return r;
    if (d.threads < 0) return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "threads = %d is negative", d.threads);
    if (d.volume.spacing[0] == 0.0f && d.volume.spacing[1] == 0.0f && d.volume.spacing[2] == 0.0f)
        d.volume.spacing[0] = d.volume.spacing[1] = d.volume.spacing[2] = 1.0f;
    if (d.volume.value_range[0] == 0.0f && d.volume.value_range[1] == 0.0f) {
        d.volume.value_range[0] = d.volume.type == HD_VOXEL_I16 ? -32768.0f : 0.0f;
        d.volume.value_range[1] = d.volume.type == HD_VOXEL_U8 ? 255.0f : d.volume.type == HD_VOXEL_U16 ? 65535.0f
                                : d.volume.type == HD_VOXEL_I16 ? 32767.0f : 1.0f;
    }
    if (!d.allocator.alloc) { d.allocator.alloc = hd__malloc_default; d.allocator.free = hd__free_default; }

    ctx = (hd__ctx *)d.allocator.alloc(sizeof *ctx, d.allocator.user_data);
    if (!ctx) return HD__ERR(log, HD_ERROR_OUT_OF_MEMORY, "cannot allocate the context");
    memset(ctx, 0, sizeof *ctx);
    ctx->vw.desc = d;
    ctx->vw.alloc = d.allocator;
    ctx->vw.log = d.logger;
    ctx->vw.camera = d.camera;
    ctx->vw.params = d.params;
    ctx->params_given = given;
    ctx->vw.desc.volume.data = NULL; /* the caller's buffer is not kept */
    ctx->xf = xf;
    ctx->cf = cf;
    hd__set_lights(ctx, d.lights, d.light_count);
    if ((r = hd__set_tf(ctx, &d.transfer_function)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    if ((r = hd__prepare_volume(ctx, &d.volume)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    hd__xform_box(&ctx->xf, ctx->box, ctx->kbox);
    hd__build_majorants(ctx);
    if ((r = hd__check_majorant(ctx, &ctx->vw.params)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    hd__set_grid(ctx);
    ctx->dirty = HD__DIRTY_ALL | HD__DIRTY_ENV; /* the environment's placeholder */
    if ((r = hd__be_create(&ctx->vw)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }
    if ((r = hd__mg_available(ctx)) != HD_SUCCESS) { hd__ctx_free(ctx); return r; }

    *out_ctx = hd__slot_take(ctx);
    if (out_ctx->id == 0) {
        hd__ctx_free(ctx);
        return HD__ERR(log, HD_ERROR_TOO_MANY_CONTEXTS, "no free context slot: %d contexts are alive, or the slots' handles are used up",
                       HD_MAX_CONTEXTS);
    }
    HD__INFO(&ctx->vw.log, "created: %s backend, volume %dx%dx%d, %d lights", hd__be_name(),
             ctx->vw.dims[0], ctx->vw.dims[1], ctx->vw.dims[2], ctx->light_count);
    hd__leave(*out_ctx);
    return HD_SUCCESS;
}

HDDEF hd_result hd_destroy(hd_context h)
{
    hd_result r;
    hd__ctx *ctx = hd__enter(h, "hd_destroy", &r);
    if (!ctx) return r;
    hd__slot_release(h);
    /* another thread's HD_ERROR_BUSY line may still be in the logger: it must not outlive us */
    while (__atomic_load_n(&ctx->busy_logs, __ATOMIC_ACQUIRE) != 0) sched_yield();
    hd__ctx_free(ctx);
    return HD_SUCCESS;
}

static hd_result hd__api_query_desc(hd__ctx *ctx, hd_desc *out)
{
    if (!out) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_query_desc: out_desc is NULL");
    *out = ctx->vw.desc;
    out->camera = ctx->vw.camera;
    out->params = ctx->vw.params;
    return HD_SUCCESS;
}
HDDEF hd_result hd_query_desc(hd_context h, hd_desc *out)
{
    HD__GUARDED(h, "hd_query_desc", hd__api_query_desc(ctx, out));
}

/* ---- setters ----------------------------------------------------------------------------------- */
static hd_result hd__api_set_transfer_function(hd__ctx *ctx, const hd_transfer_function *tf)
{
    hd_result r;
    int change;
    if (!tf) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_set_transfer_function: tf is NULL");
    if ((r = hd__check_tf(tf, &ctx->vw.log)) != HD_SUCCESS) return r;
    change = hd__tf_change(ctx, tf);
    if (change == HD__TF_SAME) return HD_SUCCESS;
    if ((r = hd__set_tf(ctx, tf)) != HD_SUCCESS) return r;
    if (change == HD__TF_COLOUR) {
        /* alpha as it was: sigma_t, the majorants and the mask stay; with grey scattering E and
           phi do not depend on the colour (only the projection reads it), with RGB scattering
           phi's sigma_s per colour does */
        ctx->dirty |= ctx->vw.sig_channels == 1 ? (HD__DIRTY_TF | HD__DIRTY_IMAGE) : (HD__DIRTY_SIGMA | HD__INV_WARM_PHI);
        return HD_SUCCESS;
    }
    hd__build_majorants(ctx);
    hd__majorant_follow(ctx, "new TF");
    ctx->dirty |= HD__INV_WARM_MEDIUM;
    return HD_SUCCESS;
}
HDDEF hd_result hd_set_transfer_function(hd_context h, const hd_transfer_function *tf)
{
    HD__GUARDED(h, "hd_set_transfer_function", hd__api_set_transfer_function(ctx, tf));
}

static hd_result hd__api_set_lights(hd__ctx *ctx, const hd_light *lights, int count)
{
    hd_result r;
    int channels_before;
    if ((r = hd__check_lights(lights, count, ctx->env_on ? ctx->env_power : -1.0, &ctx->vw.log)) != HD_SUCCESS) return r;
    if ((r = hd__check_lights_frame(lights, count, &ctx->xf, &ctx->vw.log)) != HD_SUCCESS) return r;
    if ((r = hd__check_cd_lights(ctx->vw.params.method, lights, count, "hd_set_lights", &ctx->vw.log)) != HD_SUCCESS) return r;
    channels_before = ctx->vw.channels;
    /* CD keeps one light volume per light: another count makes them anew */
    if (ctx->vw.params.method == HD_METHOD_CD && count != ctx->light_count) ctx->dirty |= HD__INV_LIGHT;
    hd__set_lights(ctx, lights, count);
    ctx->dirty |= HD__INV_WARM_LIGHT;
    if (ctx->vw.channels != channels_before) ctx->dirty |= HD__DIRTY_ALLOC | HD__INV_LIGHT; /* new grids */
    return HD_SUCCESS;
}
HDDEF hd_result hd_set_lights(hd_context h, const hd_light *lights, int count)
{
    HD__GUARDED(h, "hd_set_lights", hd__api_set_lights(ctx, lights, count));
}
HDDEF hd_result hd_set_environment(hd_context h, const hd_environment *env)
{
    HD__GUARDED(h, "hd_set_environment", hd__api_set_environment(ctx, env));
}

static hd_result hd__api_set_camera(hd__ctx *ctx, const hd_camera *camera)
{
    hd_camera c;
    hd__camframe cf;
    hd_result r;
    int resized;
    if (!camera) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_set_camera: camera is NULL");
    c = *camera;
    hd__camera_defaults(&c);
    if ((r = hd__check_camera(&c, &ctx->vw.log)) != HD_SUCCESS) return r;
    if ((r = hd__camera_frame(&c, &ctx->xf, ctx->kbox, &cf, &ctx->vw.log)) != HD_SUCCESS) return r;
    resized = c.width != ctx->vw.camera.width || c.height != ctx->vw.camera.height;
    if (resized) ctx->dirty |= HD__DIRTY_IMAGE_ALLOC;
    /* the depth belongs to a matrix camera of its size */
    if ((ctx->vw.depth || ctx->vw.depth_device) && (resized || !cf.matrix)) {
        HD__INFO(&ctx->vw.log, "hd_set_camera: the depth buffer (%dx%d) is dropped: the camera is %s", ctx->vw.depth_w, ctx->vw.depth_h,
                 resized ? "resized" : "a look-at camera");
        hd__free(&ctx->vw, ctx->vw.depth);
        ctx->vw.depth = NULL;
        ctx->vw.depth_w = ctx->vw.depth_h = 0;
        ctx->vw.depth_device = 0;
        ctx->dirty |= HD__DIRTY_DEPTH;
    }
    ctx->vw.camera = c;
    ctx->cf = cf;
    ctx->dirty |= HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}
HDDEF hd_result hd_set_camera(hd_context h, const hd_camera *camera)
{
    HD__GUARDED(h, "hd_set_camera", hd__api_set_camera(ctx, camera));
}

static hd_result hd__api_set_volume_transform(hd__ctx *ctx, const float transform[16])
{
    hd__xform xf;
    hd__camframe cf;
    float kbox[3];
    hd_result r;
    if ((r = hd__xform_make(transform, ctx->box, ctx->vw.dims, &xf, &ctx->vw.log)) != HD_SUCCESS) return r;
    hd__xform_box(&xf, ctx->box, kbox);
    if ((r = hd__check_lights_frame(ctx->lights, ctx->light_count, &xf, &ctx->vw.log)) != HD_SUCCESS) return r;
    if ((r = hd__camera_frame(&ctx->vw.camera, &xf, kbox, &cf, &ctx->vw.log)) != HD_SUCCESS) return r;
    ctx->xf = xf;
    ctx->cf = cf;
    memcpy(ctx->kbox, kbox, sizeof kbox);
    if (transform) memcpy(ctx->vw.desc.volume.transform, transform, sizeof ctx->vw.desc.volume.transform);
    else memset(ctx->vw.desc.volume.transform, 0, sizeof ctx->vw.desc.volume.transform);
    ctx->dirty |= HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}
HDDEF hd_result hd_set_volume_transform(hd_context h, const float transform[16])
{
    HD__GUARDED(h, "hd_set_volume_transform", hd__api_set_volume_transform(ctx, transform));
}

static hd_result hd__api_set_depth(hd__ctx *ctx, const hd_depth_desc *depth)
{
    hd_result r;
    size_t n;
    float *buf;
    if (!depth || (!depth->data && depth->width == 0 && depth->height == 0)) {
        if (ctx->vw.depth || ctx->vw.depth_device) ctx->dirty |= HD__DIRTY_DEPTH | HD__DIRTY_IMAGE;
        hd__free(&ctx->vw, ctx->vw.depth);
        ctx->vw.depth = NULL;
        ctx->vw.depth_w = ctx->vw.depth_h = 0;
        ctx->vw.depth_device = 0;
        return HD_SUCCESS;
    }
    if (!depth->data)
        return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_set_depth: data is NULL with a size of %dx%d", depth->width, depth->height);
    if ((r = hd__check_depth(depth, &ctx->vw.camera, &ctx->cf, &ctx->vw.log)) != HD_SUCCESS) return r;
    n = (size_t)depth->width * (size_t)depth->height;
    buf = ctx->vw.depth_w == depth->width && ctx->vw.depth_h == depth->height ? ctx->vw.depth : NULL;
    if (!buf && !(buf = (float *)hd__alloc(&ctx->vw, n * sizeof(float))))
        return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "hd_set_depth: cannot allocate %dx%d depth values", depth->width, depth->height);
    memcpy(buf, depth->data, n * sizeof(float));
    if (buf != ctx->vw.depth) hd__free(&ctx->vw, ctx->vw.depth);
    ctx->vw.depth = buf;
    ctx->vw.depth_w = depth->width;
    ctx->vw.depth_h = depth->height;
    ctx->vw.depth_device = 0;
    ctx->dirty |= HD__DIRTY_DEPTH | HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}

/* hd_gl_set_depth_texture: the checks that need no device, the backend's copy in a bracket, then
   the depth is the backend's (the host copy, if any, released). */
static hd_result hd__api_depth_texture(hd__ctx *ctx, unsigned int texture)
{
    const char *fn = "hd_gl_set_depth_texture";
    hd_result r;
    if (!(hd__be_features() & HD__BE_TEXTURE)) return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", fn, hd__be_name());
    if (texture == 0) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_TEXTURE, "%s: texture 0", fn);
    if (!ctx->cf.matrix)
        return HD__ERR(&ctx->vw.log, HD_ERROR_DEPTH_NEEDS_PROJECTION,
                       "%s: the camera is a look-at camera; depth is read through the host's projection (camera.projection)", fn);
    HD__BE_CALL(r, ctx, hd__be_depth_texture(&ctx->vw, texture));
    if (r != HD_SUCCESS) return r;
    hd__free(&ctx->vw, ctx->vw.depth);
    ctx->vw.depth = NULL;
    ctx->vw.depth_w = ctx->vw.camera.width;
    ctx->vw.depth_h = ctx->vw.camera.height;
    ctx->vw.depth_device = 1;
    ctx->dirty |= HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}

/* hd_vulkan_record_depth: the checks that need no device, the backend's recording of the copy
   (its own checks first), then the depth is the backend's. */
static hd_result hd__api_vulkan_record_depth(hd__ctx *ctx, void *command_buffer, const hd_vulkan_depth *d)
{
    const char *fn = "hd_vulkan_record_depth";
    hd_result r;
    if (!(hd__be_features() & HD__BE_RECORD)) return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", fn, hd__be_name());
    if (!command_buffer) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "%s: command_buffer is NULL", fn);
    if (!d) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "%s: depth is NULL", fn);
    if ((d->image != 0) == (d->buffer != 0))
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "%s: the depth names %s; give an image or a buffer", fn,
                       d->image ? "an image and a buffer" : "neither an image nor a buffer");
    if (!ctx->cf.matrix)
        return HD__ERR(&ctx->vw.log, HD_ERROR_DEPTH_NEEDS_PROJECTION,
                       "%s: the camera is a look-at camera; depth is read through the host's projection (camera.projection)", fn);
    if (d->buffer) {
        uint64_t bytes = (uint64_t)ctx->vw.camera.width * (uint64_t)ctx->vw.camera.height * 4u;
        if (d->offset % 4u != 0) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "%s: offset %llu is not a multiple of 4", fn, (unsigned long long)d->offset);
        if (d->offset > d->buffer_size || d->buffer_size - d->offset < bytes)
            return HD__ERR(&ctx->vw.log, HD_ERROR_BUFFER_TOO_SMALL, "%s: %llu bytes from offset %llu past the buffer's %llu", fn,
                           (unsigned long long)bytes, (unsigned long long)d->offset, (unsigned long long)d->buffer_size);
    }
    HD__BE_CALL(r, ctx, hd__be_record_depth(&ctx->vw, command_buffer, d));
    if (r != HD_SUCCESS) return r;
    hd__free(&ctx->vw, ctx->vw.depth);
    ctx->vw.depth = NULL;
    ctx->vw.depth_w = ctx->vw.camera.width;
    ctx->vw.depth_h = ctx->vw.camera.height;
    ctx->vw.depth_device = 2;
    ctx->dirty |= HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}
/* hd_vulkan_record_illumination: the checks that need no device (the backend checks the image's
   format and layouts), then the backend's recording of the copy. */
static hd_result hd__api_vulkan_record_illumination(hd__ctx *ctx, void *command_buffer, int channel, const hd_vulkan_volume_target *t)
{
    const char *fn = "hd_vulkan_record_illumination";
    const hd_logger *log = &ctx->vw.log;
    hd_result r;
    if (!(hd__be_features() & HD__BE_RECORD)) return HD__ERR(log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", fn, hd__be_name());
    if (hd__method_is_pt(ctx->vw.params.method))
        return HD__ERR(log, HD_ERROR_UNSUPPORTED, "%s: method %s keeps no illumination volume", fn, hd_method_name(ctx->vw.params.method));
    if (!command_buffer) return HD__ERR(log, HD_ERROR_NULL_POINTER, "%s: command_buffer is NULL", fn);
    if (!t) return HD__ERR(log, HD_ERROR_NULL_POINTER, "%s: target is NULL", fn);
    if ((t->image != 0) == (t->buffer != 0))
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "%s: the target names %s; give an image or a buffer", fn,
                       t->image ? "an image and a buffer" : "neither an image nor a buffer");
    if (channel < 0 || channel >= ctx->vw.channels)
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "%s: channel %d, the grid has %d", fn, channel, ctx->vw.channels);
    if (t->image && (t->width < ctx->vw.gdims[0] || t->height < ctx->vw.gdims[1] || t->depth < ctx->vw.gdims[2]))
        return HD__ERR(log, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "%s: the image is %dx%dx%d, the illumination grid %dx%dx%d", fn, t->width,
                       t->height, t->depth, ctx->vw.gdims[0], ctx->vw.gdims[1], ctx->vw.gdims[2]);
    if (t->buffer) {
        uint64_t bytes = (uint64_t)ctx->vw.gdims[0] * (uint64_t)ctx->vw.gdims[1] * (uint64_t)ctx->vw.gdims[2] * 4u;
        if (t->offset % 4u != 0) return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "%s: offset %llu is not a multiple of 4", fn, (unsigned long long)t->offset);
        if (t->offset > t->buffer_size || t->buffer_size - t->offset < bytes)
            return HD__ERR(log, HD_ERROR_BUFFER_TOO_SMALL, "%s: %llu bytes from offset %llu past the buffer's %llu", fn,
                           (unsigned long long)bytes, (unsigned long long)t->offset, (unsigned long long)t->buffer_size);
    }
    /* the caller's command buffer may hold light iterations recorded before this copy, not yet
       run: their measurement waits for the next other call */
    ctx->no_measure = 1;
    HD__BE_CALL(r, ctx, hd__be_record_illumination(&ctx->vw, command_buffer, channel, t));
    ctx->no_measure = 0;
    return r;
}
HDDEF hd_result hd_vulkan_record_illumination(hd_context h, void *command_buffer, int channel, const hd_vulkan_volume_target *target)
{
    HD__GUARDED(h, "hd_vulkan_record_illumination", hd__api_vulkan_record_illumination(ctx, command_buffer, channel, target));
}
/* hd_opencl_set_depth_buffer: the checks that need no device, the backend's copy, then the depth
   is the backend's. */
static hd_result hd__api_cl_depth(hd__ctx *ctx, void *buffer, size_t offset)
{
    const char *fn = "hd_opencl_set_depth_buffer";
    hd_result r;
    if (!(hd__be_features() & HD__BE_CL_BUFFER)) return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", fn, hd__be_name());
    if (!buffer) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "%s: buffer is NULL", fn);
    if (offset % 4u != 0) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "%s: offset %zu is not a multiple of 4", fn, offset);
    if (!ctx->cf.matrix)
        return HD__ERR(&ctx->vw.log, HD_ERROR_DEPTH_NEEDS_PROJECTION,
                       "%s: the camera is a look-at camera; depth is read through the host's projection (camera.projection)", fn);
    HD__BE_CALL(r, ctx, hd__be_depth_cl_buffer(&ctx->vw, buffer, offset));
    if (r != HD_SUCCESS) return r;
    hd__free(&ctx->vw, ctx->vw.depth);
    ctx->vw.depth = NULL;
    ctx->vw.depth_w = ctx->vw.camera.width;
    ctx->vw.depth_h = ctx->vw.camera.height;
    ctx->vw.depth_device = 3;
    ctx->dirty |= HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}
HDDEF hd_result hd_opencl_set_depth_buffer(hd_context h, void *buffer, size_t offset)
{
    HD__GUARDED(h, "hd_opencl_set_depth_buffer", hd__api_cl_depth(ctx, buffer, offset));
}
HDDEF hd_result hd_vulkan_record_depth(hd_context h, void *command_buffer, const hd_vulkan_depth *depth)
{
    HD__GUARDED(h, "hd_vulkan_record_depth", hd__api_vulkan_record_depth(ctx, command_buffer, depth));
}
HDDEF hd_result hd_gl_set_depth_texture(hd_context h, unsigned int texture)
{
    HD__GUARDED(h, "hd_gl_set_depth_texture", hd__api_depth_texture(ctx, texture));
}
HDDEF hd_result hd_set_depth(hd_context h, const hd_depth_desc *depth)
{
    HD__GUARDED(h, "hd_set_depth", hd__api_set_depth(ctx, depth));
}

static hd_result hd__api_set_params(hd__ctx *ctx, const hd_params *params)
{
    hd_params p;
    hd_result r;
    if (!params) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "hd_set_params: params is NULL");
    p = *params;
    hd__params_defaults(&p, ctx->vw.dims, ctx->no_multigrid);
    if ((r = hd__check_params(&p, &ctx->vw.log)) != HD_SUCCESS) return r;
    if ((r = hd__check_grid(ctx->vw.dims, &p, &ctx->vw.log)) != HD_SUCCESS) return r;
    if ((r = hd__check_majorant(ctx, &p)) != HD_SUCCESS) return r;
    if (ctx->env_on && p.method == HD_METHOD_CD)
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "hd_set_params: method CD cannot hold the environment (one light volume per light); clear it first");
    if ((r = hd__check_cd_lights(p.method, ctx->lights, ctx->light_count, "hd_set_params", &ctx->vw.log)) != HD_SUCCESS) return r;
    ctx->dirty |= hd__params_dirty(&ctx->vw.params, &p);
    ctx->vw.params = p;
    ctx->params_given = *params;
    hd__set_channels(ctx);
    if (ctx->dirty & HD__DIRTY_ALLOC) hd__set_grid(ctx);
    if (ctx->dirty & HD__DIRTY_SIGMA) hd__build_majorants(ctx);
    return HD_SUCCESS;
}
HDDEF hd_result hd_set_params(hd_context h, const hd_params *params)
{
    HD__GUARDED(h, "hd_set_params", hd__api_set_params(ctx, params));
}

/* ---- a volume that changes ------------------------------------------------------------------- */
/* The voxels, majorant cells and (at the next hd__prepare) the backend's copy and the direct
   light's mask follow the update; E and phi are the warm start of the new light. */
static hd_result hd__api_update_volume(hd__ctx *ctx, const hd_volume_update *update)
{
    hd_result r;
    int changed;
    if ((r = hd__update_voxels(ctx, update, &changed)) != HD_SUCCESS || !changed) return r;
    ctx->dirty |= HD__DIRTY_VOLUME | HD__DIRTY_WARM_E | HD__DIRTY_WARM_PHI | HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}
HDDEF hd_result hd_update_volume(hd_context h, const hd_volume_update *update)
{
    HD__GUARDED(h, "hd_update_volume", hd__api_update_volume(ctx, update));
}

static hd_result hd__api_reset(hd__ctx *ctx)
{
    ctx->dirty |= HD__INV_LIGHT;
    return HD_SUCCESS;
}
HDDEF hd_result hd_reset(hd_context h)
{
    HD__GUARDED(h, "hd_reset", hd__api_reset(ctx));
}

/* ---- iterations and frames ---------------------------------------------------------------- */
static hd_result hd__api_iterate(hd__ctx *ctx, int n)
{
    hd_result r;
    if (n < 1) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "hd_iterate: n = %d, must be >= 1", n);
    if (ctx->iterations + (uint64_t)n > 0x7fffffffu)
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "hd_iterate: more than 2^31 iterations; reset with a new seed");
    HD__BE_CALL(r, ctx, hd__iterate_n(ctx, n, hd__iterate_method));
    return r;
}
HDDEF hd_result hd_iterate(hd_context h, int n)
{
    HD__GUARDED(h, "hd_iterate", hd__api_iterate(ctx, n));
}


static hd_result hd__api_refine(hd__ctx *ctx, int n)
{
    hd_result r;
    if (n < 1) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "hd_refine: n = %d, must be >= 1", n);
    if (hd__method_is_pt(ctx->vw.params.method))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "hd_refine: method %s has no light volume to refine; use hd_iterate or hd_render",
                       hd_method_name(ctx->vw.params.method));
    if (ctx->iterations + (uint64_t)n > 0x7fffffffu)
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "hd_refine: more than 2^31 iterations; reset with a new seed");
    HD__BE_CALL(r, ctx, hd__iterate_n(ctx, n, hd__refine_once));
    return r;
}
HDDEF hd_result hd_refine(hd_context h, int n)
{
    HD__GUARDED(h, "hd_refine", hd__api_refine(ctx, n));
}


static hd_result hd__api_render(hd__ctx *ctx)
{
    hd_result r;
    ctx->call_t0 = hd__now();
    ctx->part.planned = 0;
    HD__BE_CALL(r, ctx, hd__render(ctx));
    hd__budget_late(ctx, ctx->call_t0, hd__now());
    return r;
}
HDDEF hd_result hd_render(hd_context h)
{
    HD__GUARDED(h, "hd_render", hd__api_render(ctx));
}

/* The optional features' entry points, for every backend (hd__be_features). */
/* hd_gl_render_to_texture (exact: GL_RGBA8 of the camera's size, output NULL) and its _ex. */
static hd_result hd__api_output_texture(hd__ctx *ctx, unsigned int texture, const hd_output *output, int exact,
                                        const char *what)
{
    hd_result r;
    hd_output o;
    if (!(hd__be_features() & HD__BE_TEXTURE))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", what, hd__be_name());
    if (texture == 0) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_TEXTURE, "%s: texture 0", what);
    if ((r = hd__output_check(ctx, output, &o, what)) != HD_SUCCESS) return r;
    HD__BE_CALL(r, ctx, hd__be_output_texture(&ctx->vw, texture, &o, exact));
    return r;
}
/* hd_gl_illumination_texture: the checks that need no device, then the backend's copy. */
static hd_result hd__api_illumination_texture(hd__ctx *ctx, unsigned int texture, int channel)
{
    hd_result r;
    const char *fn = "hd_gl_illumination_texture";
    if (!(hd__be_features() & HD__BE_TEXTURE)) return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", fn, hd__be_name());
    if (hd__method_is_pt(ctx->vw.params.method))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: method %s keeps no illumination volume", fn, hd_method_name(ctx->vw.params.method));
    if (texture == 0) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_TEXTURE, "%s: texture 0", fn);
    if (channel < 0 || channel >= ctx->vw.channels)
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "%s: channel %d, the grid has %d", fn, channel, ctx->vw.channels);
    HD__BE_CALL(r, ctx, hd__be_illumination_texture(&ctx->vw, texture, channel));
    return r;
}
HDDEF hd_result hd_gl_illumination_texture(hd_context h, unsigned int texture, int channel)
{
    HD__GUARDED(h, "hd_gl_illumination_texture", hd__api_illumination_texture(ctx, texture, channel));
}
HDDEF hd_result hd_gl_render_to_texture(hd_context h, unsigned int texture)
{
    HD__GUARDED(h, "hd_gl_render_to_texture", hd__api_output_texture(ctx, texture, NULL, 1, "hd_gl_render_to_texture"));
}
HDDEF hd_result hd_gl_render_to_texture_ex(hd_context h, unsigned int texture, const hd_output *output)
{
    HD__GUARDED(h, "hd_gl_render_to_texture_ex",
                hd__api_output_texture(ctx, texture, output, 0, "hd_gl_render_to_texture_ex"));
}

/* The checks of hd_vulkan_record and _record_render that come before the device: the feature,
   the command buffer, multigrid (not recordable), the iteration count. */
static hd_result hd__record_check(hd__ctx *ctx, void *command_buffer, int n, const char *fn)
{
    const hd_params *p = &ctx->vw.params;
    if (!(hd__be_features() & HD__BE_RECORD))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: this is the %s backend", fn, hd__be_name());
    if (!command_buffer) return HD__ERR(&ctx->vw.log, HD_ERROR_NULL_POINTER, "%s: command_buffer is NULL", fn);
    if (n < 1) return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "%s: n = %d, must be >= 1", fn, n);
    if (ctx->iterations + (uint64_t)n > 0x7fffffffu)
        return HD__ERR(&ctx->vw.log, HD_ERROR_INVALID_PARAMETER, "%s: more than 2^31 iterations; reset with a new seed", fn);
    if (p->solver == HD_SOLVER_MULTIGRID && !p->disable_diffusion && (p->method == HD_METHOD_HD || p->method == HD_METHOD_CD) &&
        !hd__solver_fallback(ctx, "multigrid cannot be recorded"))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED,
                       "%s: solver MULTIGRID reads its dot products back within each step, so it cannot be recorded; use hd_iterate", fn);
    return HD_SUCCESS;
}

/* hd_vulkan_target's checks that need no device: one of image and buffer, a size, the region
   inside it, a buffer's rows inside its pitch and size. */
static hd_result hd__vulkan_target_check(hd__ctx *ctx, const hd_vulkan_target *t, const hd_output *o)
{
    const hd_logger *log = &ctx->vw.log;
    uint64_t px = hd__output_pixel_bytes(o->format), pitch, end;
    if ((t->image != 0) == (t->buffer != 0))
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "hd_vulkan_record_render: the target names %s; give an image or a buffer",
                       t->image ? "an image and a buffer" : "neither an image nor a buffer");
    if (t->width < 1 || t->height < 1 || t->width > HD_MAX_IMAGE_DIM || t->height > HD_MAX_IMAGE_DIM)
        return HD__ERR(log, HD_ERROR_INVALID_DIMENSIONS, "hd_vulkan_record_render: the target is %dx%d pixels; 1..%d each", t->width,
                       t->height, HD_MAX_IMAGE_DIM);
    if ((int64_t)o->x + o->width > t->width || (int64_t)o->y + o->height > t->height)
        return HD__ERR(log, HD_ERROR_OUTPUT_OUTSIDE_TARGET, "hd_vulkan_record_render: region %dx%d at (%d, %d) outside the %dx%d target",
                       o->width, o->height, o->x, o->y, t->width, t->height);
    if (!t->buffer) return HD_SUCCESS;
    pitch = t->row_pitch ? t->row_pitch : (uint64_t)t->width * px;
    if (pitch < (uint64_t)t->width * px)
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "hd_vulkan_record_render: row_pitch %llu below the %d-pixel rows' %llu bytes",
                       (unsigned long long)pitch, t->width, (unsigned long long)((uint64_t)t->width * px));
    if (pitch > ((uint64_t)1 << 40) || t->offset > ((uint64_t)1 << 62))
        return HD__ERR(log, HD_ERROR_SIZE_OVERFLOW, "hd_vulkan_record_render: row_pitch %llu or offset %llu is too large",
                       (unsigned long long)pitch, (unsigned long long)t->offset);
    end = t->offset + (uint64_t)(o->y + o->height - 1) * pitch + (uint64_t)(o->x + o->width) * px;
    if (end > t->buffer_size)
        return HD__ERR(log, HD_ERROR_BUFFER_TOO_SMALL, "hd_vulkan_record_render: the region ends at byte %llu, the buffer holds %llu",
                       (unsigned long long)end, (unsigned long long)t->buffer_size);
    return HD_SUCCESS;
}

static hd_result hd__api_vulkan_record_render(hd__ctx *ctx, void *command_buffer, const hd_vulkan_target *target, const hd_output *output)
{
    hd_result r;
    hd_output o;
    memset(&o, 0, sizeof o);
    if ((r = hd__record_check(ctx, command_buffer, 1, "hd_vulkan_record_render")) != HD_SUCCESS) return r;
    if (target && ((r = hd__output_check(ctx, output, &o, "hd_vulkan_record_render")) != HD_SUCCESS ||
                   (r = hd__vulkan_target_check(ctx, target, &o)) != HD_SUCCESS))
        return r;
    hd__record_cost(ctx);
    HD__BE_CALL(r, ctx, hd__record_render(ctx, command_buffer, target, &o));
    return r;
}
HDDEF hd_result hd_vulkan_record_render(hd_context h, void *command_buffer, const hd_vulkan_target *target, const hd_output *output)
{
    HD__GUARDED(h, "hd_vulkan_record_render", hd__api_vulkan_record_render(ctx, command_buffer, target, output));
}

static hd_result hd__api_vulkan_record(hd__ctx *ctx, void *command_buffer, int n)
{
    hd_result r;
    if ((r = hd__record_check(ctx, command_buffer, n, "hd_vulkan_record")) != HD_SUCCESS) return r;
    hd__record_cost(ctx);
    HD__BE_CALL(r, ctx, hd__record(ctx, command_buffer, n));
    return r;
}
HDDEF hd_result hd_vulkan_record(hd_context h, void *command_buffer, int n)
{
    HD__GUARDED(h, "hd_vulkan_record", hd__api_vulkan_record(ctx, command_buffer, n));
}

static hd_result hd__api_vulkan_record_refine(hd__ctx *ctx, void *command_buffer, int n)
{
    hd_result r;
    if ((r = hd__record_check(ctx, command_buffer, n, "hd_vulkan_record_refine")) != HD_SUCCESS) return r;
    if (hd__method_is_pt(ctx->vw.params.method))
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED,
                       "hd_vulkan_record_refine: method %s has no light volume to refine; use hd_vulkan_record_render",
                       hd_method_name(ctx->vw.params.method));
    hd__record_cost(ctx);
    HD__BE_CALL(r, ctx, hd__record_refine(ctx, command_buffer, n));
    return r;
}
HDDEF hd_result hd_vulkan_record_refine(hd_context h, void *command_buffer, int n)
{
    HD__GUARDED(h, "hd_vulkan_record_refine", hd__api_vulkan_record_refine(ctx, command_buffer, n));
}
