/* hd_schedule.h - the schedule of each method's stages over the backend's primitives: bringing
   the device up to date (hd__prepare), light iterations, projection frames, hd_render's loop and
   recording. Part of the core (src/hd_core.h). */
/* ---- the schedule ---------------------------------------------------------------------------- */
/* Bytes per stored element of E, phi and Jacobi's buffer: binary16 or float32. */
static size_t hd__illum_elem_bytes(const hd__ctx *ctx)
{
    return ctx->vw.params.illumination_precision == HD_PRECISION_FLOAT16 ? 2 : sizeof(float);
}

static size_t hd__illum_floats(const hd__ctx *ctx)
{
    return (size_t)ctx->vw.gdims[0] * ctx->vw.gdims[1] * ctx->vw.gdims[2] * (size_t)ctx->vw.channels;
}

/* Whether a new image buffer (a new camera size) keeps the reduced frames' region: the old one
   had it and the parameters may still ask for reduced frames. */
static int hd__image_room_kept(const hd__ctx *ctx)
{
    return ctx->image_room && ctx->vw.params.render_scale != 1 && !hd__method_is_pt(ctx->vw.params.method);
}

/* Whether the image buffer should hold HD_REST_BLEND's planes. */
static int hd__image_blend_wanted(const hd__ctx *ctx)
{
    return ctx->vw.params.rest == HD_REST_BLEND && !hd__method_is_pt(ctx->vw.params.method);
}

/* Whether a resting view adds paths (HD_REST_REFINE, HD_REST_BLEND). */
static int hd__rest_paths(const hd__ctx *ctx)
{
    return ctx->vw.params.rest == HD_REST_REFINE || ctx->vw.params.rest == HD_REST_BLEND;
}

static hd_result hd__record_measure(hd__ctx *ctx);
static hd_result hd__blend_image(hd__ctx *ctx, uint64_t n);

/* The dirty bits that end a split light iteration (hd__prepare). */
#define HD__PART_ENDS \
    (HD__DIRTY_ALLOC | HD__DIRTY_JACOBI | HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_WARM_E | HD__DIRTY_WARM_PHI | \
     HD__DIRTY_VOLUME)

/* No light iteration in progress (ctx->part: src/hd_core.h). */
static void hd__part_end(hd__ctx *ctx)
{
    ctx->part.open = 0;
    ctx->part.dl = 0;
    ctx->part.sweeps = 0;
}

/* Brings the device state up to date with what the setters changed, in dependency order. */
static hd_result hd__prepare(hd__ctx *ctx)
{
    hd_result r;
    unsigned dirty = ctx->dirty;
    int pt = hd__method_is_pt(ctx->vw.params.method);
    if (dirty & HD__DIRTY_ALLOC) {
        if ((r = hd__be_alloc_illumination(&ctx->vw, pt ? 0 : hd__illum_floats(ctx))) != HD_SUCCESS) return r;
        dirty |= HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE | HD__DIRTY_JACOBI;
    }
    if (dirty & HD__DIRTY_JACOBI) {
        if ((r = hd__be_alloc_jacobi(&ctx->vw, !pt && ctx->vw.params.solver == HD_SOLVER_JACOBI)) != HD_SUCCESS) return r;
    }
    /* CD's light volumes follow the lights: reallocated (dark) when they change; freed for the
       other methods (a method change sets every dirty bit) */
    if (dirty & HD__DIRTY_DIRECT) {
        if ((r = hd__be_alloc_lights(&ctx->vw, ctx->vw.params.method == HD_METHOD_CD ? ctx->light_count : 0)) != HD_SUCCESS)
            return r;
    }
    /* the path tracers' state is their image: whatever resets it restarts them */
    if (pt && (dirty & HD__DIRTY_IMAGE)) dirty |= HD__DIRTY_DIRECT;
    /* a new camera size, or HD_REST_BLEND's planes wanted or no longer (a change of rest or
       method restarts the image) */
    if ((dirty & HD__DIRTY_IMAGE_ALLOC) || ((dirty & HD__DIRTY_IMAGE) && hd__image_blend_wanted(ctx) != ctx->image_blend)) {
        int room = (dirty & HD__DIRTY_IMAGE_ALLOC) ? hd__image_room_kept(ctx) : ctx->image_room, blend = hd__image_blend_wanted(ctx);
        size_t floats = hd__image_floats(ctx->vw.camera.width, ctx->vw.camera.height, (room ? HD__IMAGE_REDUCED : 0) | HD__IMAGE_BLEND);
        /* the kernels address the blend planes with 32-bit offsets */
        if (blend && floats > 0x7fffffffu)
            return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "params.rest HD_REST_BLEND: a %dx%d image's planes need %zu floats, above 2^31 - 1",
                           ctx->vw.camera.width, ctx->vw.camera.height, floats);
        if ((r = hd__be_alloc_image(&ctx->vw, ctx->vw.camera.width, ctx->vw.camera.height,
                                    (room ? HD__IMAGE_REDUCED : 0) | (blend ? HD__IMAGE_BLEND : 0))) != HD_SUCCESS)
            return r;
        ctx->image_room = room;
        ctx->image_blend = blend;
        dirty |= HD__DIRTY_IMAGE;
    }
    ctx->dirty = dirty & ~(unsigned)(HD__DIRTY_ALLOC | HD__DIRTY_IMAGE_ALLOC | HD__DIRTY_JACOBI);
    if (dirty & HD__DIRTY_DEPTH) {
        if ((r = hd__be_upload_depth(&ctx->vw)) != HD_SUCCESS) return r;
        ctx->dirty &= ~(unsigned)HD__DIRTY_DEPTH;
    }
    if (dirty & HD__DIRTY_ENV) {
        if ((r = hd__be_upload_env(&ctx->vw)) != HD_SUCCESS) return r;
        ctx->dirty &= ~(unsigned)HD__DIRTY_ENV;
    }
    if (dirty & HD__DIRTY_DIRECT) ctx->iterations = ctx->dl_n = ctx->part.dropped = 0;
    /* a change of the light's inputs ends a split light iteration where it is (its voxels not yet
       sampled keep their mean; the counters stay, so the random numbers are never reused) */
    if (dirty & HD__PART_ENDS) {
        if (ctx->part.open && !(dirty & HD__DIRTY_DIRECT)) ctx->part.dropped++;
        hd__part_end(ctx);
    }
    /* a warm start: E's mean keeps at most light_window samples of the light before the change
       (the iteration count, the random numbers' key, runs on) */
    if ((dirty & HD__DIRTY_WARM_E) && ctx->dl_n > (uint64_t)ctx->vw.params.light_window) ctx->dl_n = (uint64_t)ctx->vw.params.light_window;
    if (dirty & HD__DIRTY_IMAGE) {
        ctx->frames = ctx->converged_frames = ctx->refined = 0;
        ctx->frame_scale = 0;
        ctx->image_empty = 1;
    }
    /* the measured voxels follow the medium and the grid; the error estimate follows E and phi */
    if (dirty & (HD__DIRTY_SIGMA | HD__DIRTY_ALLOC | HD__DIRTY_VOLUME)) hd__conv_free(ctx);
    if (dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_WARM_E | HD__DIRTY_WARM_PHI)) {
        hd__conv_reset(ctx);
        ctx->light_gen++;
    }
    hd__fill_kparams(ctx);
    if (dirty & HD__DIRTY_VOLUME) {
        /* hd_update_volume's voxels and majorant cells; with SIGMA the whole medium follows */
        hd__box cells = hd__box_cells(&ctx->vw, &ctx->upd);
        if ((r = hd__be_update_volume(&ctx->vw, &ctx->upd, &cells)) != HD_SUCCESS) return r;
        if (!(dirty & HD__DIRTY_SIGMA)) {
            int changed = 0;
            if (!pt) {
                ++ctx->sig_gen;
                if ((r = hd__be_classify(&ctx->vw)) != HD_SUCCESS) return r;
            }
            if (ctx->vw.params.method == HD_METHOD_HD) {
                if ((r = hd__direct_mask_box(ctx, &ctx->upd, &changed)) != HD_SUCCESS) return r;
                if (changed && (r = hd__be_direct_list(&ctx->vw)) != HD_SUCCESS) return r;
            }
        }
        ctx->dirty &= ~(unsigned)HD__DIRTY_VOLUME;
    }
    if ((dirty & HD__DIRTY_TF) && !(dirty & HD__DIRTY_SIGMA)) {
        if ((r = hd__be_upload_inputs(&ctx->vw)) != HD_SUCCESS) return r;
    }
    if (dirty & HD__DIRTY_SIGMA) {
        if ((r = hd__be_upload_inputs(&ctx->vw)) != HD_SUCCESS) return r;
        if (!pt) {
            ++ctx->sig_gen;
            if ((r = hd__be_classify(&ctx->vw)) != HD_SUCCESS) return r;
        }
        hd__direct_mask_free(ctx);
        if (ctx->vw.params.method == HD_METHOD_HD) {
            if ((r = hd__direct_mask(ctx)) != HD_SUCCESS) return r;
            if ((r = hd__be_direct_list(&ctx->vw)) != HD_SUCCESS) return r;
        }
    }
    if ((r = hd__be_clear(&ctx->vw, dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE))) != HD_SUCCESS) return r;
    ctx->dirty = 0;
    /* light iterations an earlier call recorded have run by now (the caller waits before the next
       call): their light is measured, unless a setter has reset it or its estimate since */
    if (dirty & (HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_WARM_E | HD__DIRTY_WARM_PHI)) ctx->rec_light = 0;
    if (ctx->rec_light && !ctx->no_measure) return hd__record_measure(ctx);
    return HD_SUCCESS;
}

/* Multigrid that HD_SOLVER_AUTO picked cannot run (why: a step refused, or recording): red-black
   from now on, with the caller's other parameters filled in again (diffusion_sweeps 0: red-black's
   default). 0 where the caller asked for multigrid itself: the refusal stands. */
static int hd__solver_fallback(hd__ctx *ctx, const char *why)
{
    hd_params p;
    if (ctx->params_given.solver != HD_SOLVER_AUTO || ctx->vw.params.solver != HD_SOLVER_MULTIGRID) return 0;
    ctx->no_multigrid = 1;
    p = ctx->params_given;
    hd__params_defaults(&p, ctx->vw.dims, 1);
    ctx->dirty |= hd__params_dirty(&ctx->vw.params, &p);
    ctx->vw.params = p;
    HD__INFO(&ctx->vw.log, "solver AUTO: %s; red-black from now on", why);
    return 1;
}

/* AUTO's multigrid on a device that cannot run it (why: the backend's reason): red-black from
   now on, with one info line naming the backend and the reason; 0 where the caller named it. */
static int hd__mg_fall_back(hd__ctx *ctx, const char *why)
{
    char line[256];
    snprintf(line, sizeof line, "%s: multigrid is not available: %s", hd__be_name(), why);
    return hd__solver_fallback(ctx, line);
}

/* hd_create's check of the solver against the device: AUTO's multigrid falls back (no error is
   logged: nothing was refused), a multigrid the caller named is refused. */
static hd_result hd__mg_available(hd__ctx *ctx)
{
    const char *why = ctx->vw.params.solver == HD_SOLVER_MULTIGRID ? hd__be_mg_unavailable(&ctx->vw) : NULL;
    if (!why || hd__mg_fall_back(ctx, why)) return HD_SUCCESS;
    return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "%s: solver MULTIGRID is not available: %s", hd__be_name(), why);
}

/* One step of multigrid; where AUTO's multigrid cannot run (hd_set_params may pick it later, on
   a larger grid), red-black's sweeps instead, asked before the step so no refusal is logged. A
   multigrid the caller named is refused by the step, with its error. */
static hd_result hd__mg_step_or_fallback(hd__ctx *ctx)
{
    const char *why = hd__be_mg_unavailable(&ctx->vw);
    if (why && hd__mg_fall_back(ctx, why)) return hd__be_diffuse(&ctx->vw, 0);
    return hd__mg_step(ctx);
}

/* One sweep of the selected solver (multigrid: one conjugate-gradient step, preconditioned by a
   V-cycle; docs/DESIGN-MULTIGRID.md has its cost in red-black sweeps). */
static hd_result hd__diffuse_once(hd__ctx *ctx)
{
    if (ctx->vw.params.solver == HD_SOLVER_MULTIGRID) return hd__mg_step_or_fallback(ctx);
    return hd__be_diffuse(&ctx->vw, ctx->vw.params.solver == HD_SOLVER_JACOBI);
}

/* A light iteration's parts: its direct stage (HD: one unit per entry of the direct light's
   list; CD: the convection of every light and their sum, one unit) and its diffusion sweeps
   (none with disable_diffusion; multigrid: conjugate-gradient steps). hd_render under
   render_budget runs them over several calls (hd__light_budget); every other caller runs what is
   left of the open iteration at once (hd__light_iteration). The parts run in the order of a
   whole iteration with the same parameter block, so a split iteration gives the same E and phi. */
static size_t hd__direct_units(const hd__ctx *ctx)
{
    return ctx->vw.params.method == HD_METHOD_CD ? 1 : ctx->vw.dl_count;
}
static int hd__sweep_units(const hd__ctx *ctx)
{
    return ctx->vw.params.disable_diffusion ? 0 : ctx->vw.params.diffusion_sweeps;
}

/* Opens a light iteration: its counters (the random numbers' key, E's sample count) advance. */
static void hd__light_open(hd__ctx *ctx)
{
    ctx->iterations++;
    ctx->dl_n++;
    ctx->part.open = 1;
    ctx->part.dl = 0;
    ctx->part.sweeps = 0;
}

/* The open iteration's direct stage over its next n units. */
static hd_result hd__direct_part(hd__ctx *ctx, size_t n)
{
    hd_result r = HD_SUCCESS;
    double t0 = hd__now();
    hd__fill_kparams(ctx);
    if (ctx->vw.params.method == HD_METHOD_CD) {
        int l;
        for (l = 0; l < ctx->light_count && r == HD_SUCCESS; ++l) r = hd__be_convect(&ctx->vw, l);
        if (r == HD_SUCCESS) r = hd__be_sum_lights(&ctx->vw);
    } else {
        r = hd__be_direct(&ctx->vw, ctx->part.dl, n);
    }
    ctx->part.dl += n;
    ctx->seconds[0] += hd__now() - t0;
    return r;
}

/* n more of the open iteration's diffusion sweeps (all of them in one call where the solver
   allows: the CPU backend walks memory once for several red-black sweeps). */
static hd_result hd__sweeps_part(hd__ctx *ctx, int n)
{
    hd_result r = HD_SUCCESS;
    double t0 = hd__now();
    int s;
    hd__fill_kparams(ctx);
    if (ctx->vw.params.solver != HD_SOLVER_MULTIGRID)
        r = hd__be_diffuse_sweeps(&ctx->vw, ctx->vw.params.solver == HD_SOLVER_JACOBI, n);
    else
        for (s = 0; s < n && r == HD_SUCCESS && ctx->vw.params.solver == HD_SOLVER_MULTIGRID; ++s) r = hd__diffuse_once(ctx);
    ctx->part.sweeps += n;
    ctx->seconds[1] += hd__now() - t0;
    return r;
}

/* Closes the open iteration, all its parts done: the convergence estimate, counted with the
   diffusion (iterations recorded into a caller's command buffer have not run yet: the next call
   measures them, hd__record_measure). */
static hd_result hd__light_close(hd__ctx *ctx)
{
    hd_result r = HD_SUCCESS;
    double t0 = hd__now();
    hd__part_end(ctx);
    if (ctx->no_measure) ctx->rec_light++;
    else r = hd__light_measure(ctx);
    ctx->seconds[1] += hd__now() - t0;
    if (!hd__light_converged(ctx)) ctx->converged_frames = 0;
    return r;
}

/* One light iteration, no projection, or what is left of the one in progress. HD: a direct-light
   sample per voxel and the diffusion sweeps; CD: one convection step per light, their sum into
   E, and the sweeps (convection and sum count as the direct stage). Then the convergence
   estimate. A failed part ends the iteration. */
static hd_result hd__light_iteration(hd__ctx *ctx)
{
    hd_result r = HD_SUCCESS;
    size_t nd;
    int ns;
    if (!ctx->part.open) hd__light_open(ctx);
    nd = hd__direct_units(ctx);
    ns = hd__sweep_units(ctx);
    if (ctx->part.dl < nd) r = hd__direct_part(ctx, nd - ctx->part.dl);
    if (r == HD_SUCCESS && ctx->part.sweeps < ns) r = hd__sweeps_part(ctx, ns - ctx->part.sweeps);
    if (r != HD_SUCCESS) {
        hd__part_end(ctx);
        return r;
    }
    return hd__light_close(ctx);
}

/* The fewest direct-list entries a piece of a split iteration runs (HD__PART_MIN_ENTRIES, or the
   list's 1/256th where that is more): smaller pieces cost more in dispatch than they save. */
#define HD__PART_MIN_ENTRIES 1024

/* The units of a piece that fit `left` seconds at `rate` seconds each, at most `remaining`; 0
   when fewer than `least` fit. Without a measured rate: a probe of `least` units. */
static size_t hd__part_fit(double left, double rate, size_t remaining, size_t least)
{
    double n;
    if (least > remaining) least = remaining;
    if (!(rate > 0.0)) return least;
    n = left / rate;
    if (n >= (double)remaining) return remaining;
    if (n < (double)least) return 0;
    return (size_t)n;
}

/* A unit cost measured over n units: a dearer one is taken at once, a cheaper one moves the
   estimate halfway to it (the direct light's cost per entry varies several times along the list,
   with the medium's density: the estimate errs on the dear side). */
static void hd__part_rate(double *rate, double seconds, size_t n)
{
    double r = seconds / (double)(n ? n : 1);
    if (!(r > 0.0)) return;
    *rate = *rate > 0.0 && r < *rate ? 0.5 * (*rate + r) : r;
}

static void hd__light_settled(hd__ctx *ctx, int before);

/* hd_render's light work under render_budget: pieces of light iterations (hd__part_fit over the
   measured unit costs) until the next does not fit before `deadline` (hd__now() seconds) or
   the light has converged. The first piece of a call runs whatever the time left (the smallest
   piece: HD__PART_MIN_ENTRIES entries or one sweep), so the light always advances. An
   iteration's measurement runs once its last sweep is done. */
static hd_result hd__light_budget(hd__ctx *ctx, double deadline)
{
    int pieces = 0;
    for (;;) {
        hd_result r;
        double left = deadline - hd__now(), t0;
        size_t nd = hd__direct_units(ctx), least, k;
        int ns = hd__sweep_units(ctx);
        if (!ctx->part.open && (hd__light_converged(ctx) || ctx->iterations >= 0x7fffffffu)) return HD_SUCCESS;
        if (pieces > 0 && !(left > 0.0)) return HD_SUCCESS;
        if (ctx->part.dl < nd) {
            least = ctx->vw.params.method == HD_METHOD_CD ? 1 : nd / 256 > HD__PART_MIN_ENTRIES ? nd / 256 : HD__PART_MIN_ENTRIES;
            k = hd__part_fit(left, ctx->part.s_entry, nd - ctx->part.dl, least);
            if (k == 0 && pieces > 0) return HD_SUCCESS;
            if (k == 0) k = least < nd - ctx->part.dl ? least : nd - ctx->part.dl;
            /* a piece at most twice the last one: the next stretch of the list may cost more */
            if (ctx->part.last_dl > 0 && k > 2 * ctx->part.last_dl && k > least) k = 2 * ctx->part.last_dl > least ? 2 * ctx->part.last_dl : least;
            ctx->part.last_dl = k;
            if (!ctx->part.open) hd__light_open(ctx);
            t0 = hd__now();
            if ((r = hd__direct_part(ctx, k)) != HD_SUCCESS || (r = hd__be_wait(&ctx->vw)) != HD_SUCCESS) {
                hd__part_end(ctx);
                return r;
            }
            hd__part_rate(&ctx->part.s_entry, hd__now() - t0, k);
        } else if (ctx->part.sweeps < ns) {
            /* the measurement comes with the last sweep: its time counts against the piece */
            double l2 = left - ctx->part.s_measure;
            k = hd__part_fit(l2, ctx->part.s_sweep, (size_t)(ns - ctx->part.sweeps), 1);
            if (k == 0 && pieces > 0) return HD_SUCCESS;
            if (k == 0) k = 1;
            if (!ctx->part.open) hd__light_open(ctx);
            t0 = hd__now();
            if ((r = hd__sweeps_part(ctx, (int)k)) != HD_SUCCESS || (r = hd__be_wait(&ctx->vw)) != HD_SUCCESS) {
                hd__part_end(ctx);
                return r;
            }
            hd__part_rate(&ctx->part.s_sweep, hd__now() - t0, k);
        } else if (!ctx->part.open) {
            hd__light_open(ctx); /* nothing to run (an empty list, no diffusion): a measurement */
        }
        if (ctx->part.open && ctx->part.dl >= nd && ctx->part.sweeps >= ns) {
            int before = hd__light_converged(ctx);
            t0 = hd__now();
            if ((r = hd__light_close(ctx)) != HD_SUCCESS) return r;
            hd__part_rate(&ctx->part.s_measure, hd__now() - t0, 1);
            hd__light_settled(ctx, before);
        }
        ++pieces;
    }
}

/* One projection frame from the current E and phi into the image's running mean. At render
   scale s > 1 the march covers the reduced size into the image buffer's second region, then the
   upsample pass (hd__be_upsample, hd_k_upsample.h) fills the full
   image from it; the parameter block is left describing the full image. */
static hd_result hd__project_frame(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now(), t1, t2;
    int s;
    if ((r = hd__use_scale(ctx, hd__next_scale(ctx))) != HD_SUCCESS) return r;
    t1 = hd__now(); /* the frame cost starts after a first reduced frame's allocation */
    s = ctx->frame_scale;
    /* the image is HD's frames again (a blended one gets HD's frame back first) */
    if (ctx->refined > 0 && ctx->image_blend && ctx->vw.params.rest == HD_REST_BLEND && (r = hd__blend_image(ctx, 0)) != HD_SUCCESS) return r;
    ctx->frames++;
    ctx->refined = 0;
    hd__fill_kparams(ctx);
    if (s > 1) {
        int w = ctx->vw.kp.image.x, h = ctx->vw.kp.image.y;
        ctx->vw.kp.image.x = (w + s - 1) / s;
        ctx->vw.kp.image.y = (h + s - 1) / s;
        ctx->vw.kp.region.x = w * h;
        r = hd__be_project(&ctx->vw);
        if (r == HD_SUCCESS) {
            ctx->vw.kp.image.x = w;
            ctx->vw.kp.image.y = h;
            ctx->vw.kp.region.x = 0;
            ctx->vw.kp.region.y = s;
            r = hd__be_upsample(&ctx->vw);
        }
        hd__fill_kparams(ctx);
    } else {
        r = hd__be_project(&ctx->vw);
    }
    /* under a budget the frame's time is the device's, not its enqueueing's */
    if (r == HD_SUCCESS && ctx->vw.params.render_budget > 0.0f && !ctx->no_measure) r = hd__be_wait(&ctx->vw);
    t2 = hd__now();
    ctx->seconds[2] += t2 - t0;
    /* a recorded frame has not run: hd_vulkan_record times it on the device instead */
    if (r == HD_SUCCESS && !ctx->no_measure) hd__frame_cost_add(ctx, s, hd__scale_pixels(ctx, s), t2 - t1);
    if (r == HD_SUCCESS) ctx->image_empty = 0;
    return r;
}

/* One HD or CD iteration: a light iteration and one frame. */
static hd_result hd__iterate_light(hd__ctx *ctx)
{
    hd_result r;
    if ((r = hd__light_iteration(ctx)) != HD_SUCCESS) return r;
    return hd__project_frame(ctx);
}

/* One PT_SS / PT_MS iteration: one full path per pixel into the image's plain running mean.
   Its time counts as the direct stage (paths), none as diffusion or projection. */
static hd_result hd__iterate_pt(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now();
    ctx->iterations++;
    ctx->frames++;
    hd__fill_kparams(ctx);
    if ((r = hd__be_path(&ctx->vw)) != HD_SUCCESS) return r;
    ctx->image_empty = 0;
    ctx->seconds[0] += hd__now() - t0;
    return HD_SUCCESS;
}

/* HD's frame as refine_prior paths' worth of the resting view's image: the k-th refinement path
   per pixel enters the mean with weight 1 / (HD__REFINE_PRIOR + k), so the image moves from HD's
   frame toward the paths' mean as the rest lasts (docs/DESIGN-REFINE.md has the measurements). */
#define HD__REFINE_PRIOR 8.0

/* One refinement pass of a resting HD or CD view (HD_REST_REFINE): one path per pixel that ends
   into the converged E + phi at vertex refine_bounces (hd_k_path.h, image.w), into the image's
   mean; HD_REST_BLEND: one PT_MS path per pixel into the blend planes (region.w). The view rests only after a projection of the current light, so the backends' summed
   light (lsum) the paths read is up to date. Its time counts as the projection's. */
static hd_result hd__refine_paths(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now();
    int k = ctx->vw.params.refine_bounces, blend = ctx->vw.params.rest == HD_REST_BLEND;
    ctx->refined++;
    hd__fill_kparams(ctx);
    ctx->vw.kp.image.w = k < 0 || blend ? 0 : k;
    ctx->vw.kp.region.w = blend ? (int32_t)hd__image_blend_first(ctx->vw.camera.width, ctx->vw.camera.height, hd__image_parts(ctx)) : 0;
    ctx->vw.kp.frame.x = (int32_t)ctx->refined;
    /* BLEND: the paths' plain mean; REFINE: HD's frame as HD__REFINE_PRIOR paths */
    ctx->vw.kp.march.y = (float)(1.0 / ((blend ? 0.0 : HD__REFINE_PRIOR) + (double)ctx->refined));
    r = hd__be_path(&ctx->vw);
    hd__fill_kparams(ctx);
    ctx->seconds[2] += hd__now() - t0;
    return r;
}

/* HD_REST_BLEND's tile radii after n paths per pixel (hd_k_upsample.h): pass 1's, over which
   HD's bias is smoothed, from 3 (n < 8) to 1 (n > 16); pass 2's, over which the weights'
   variance and bias are estimated, from 3 (n < 29) to 1 (n > 64). As the paths' noise falls the
   estimates follow the image's detail more closely; the radii were measured on the head CT
   (docs/DESIGN-REFINE.md). */
static int hd__blend_radius(uint64_t n, double c)
{
    double r = c / sqrt((double)(n < 1 ? 1 : n));
    return r >= 3.0 ? 3 : r >= 2.0 ? 2 : 1;
}

/* HD_REST_BLEND's blend passes (hdk_blend_pixel, through hd__be_upsample) after n paths per
   pixel: the image from HD's frame and the paths' mean; n < 2 puts HD's frame back. Their time
   counts as the projection's. */
static hd_result hd__blend_image(hd__ctx *ctx, uint64_t n)
{
    hd_result r = HD_SUCCESS;
    double t0 = hd__now();
    int pass;
    for (pass = n < 2 ? 2 : 1; pass <= 2 && r == HD_SUCCESS; ++pass) {
        hd__fill_kparams(ctx);
        ctx->vw.kp.counts.z |= HD_FLAG_BLEND;
        ctx->vw.kp.frame.x = (int32_t)n;
        ctx->vw.kp.frame.w = pass;
        ctx->vw.kp.region.y = hd__blend_radius(n, pass == 1 ? 8.0 : 16.0);
        ctx->vw.kp.region.w = (int32_t)hd__image_blend_first(ctx->vw.camera.width, ctx->vw.camera.height, hd__image_parts(ctx));
        r = hd__be_upsample(&ctx->vw);
    }
    hd__fill_kparams(ctx);
    ctx->blend_cost = hd__now() - t0;
    ctx->seconds[2] += ctx->blend_cost;
    return r;
}

/* One iteration of the current method (docs/METHOD.md: what an iteration is, per method). */
static hd_result hd__iterate_method(hd__ctx *ctx)
{
    switch (ctx->vw.params.method) {
    case HD_METHOD_CD: return hd__iterate_light(ctx);
    case HD_METHOD_PT_SS:
    case HD_METHOD_PT_MS: return hd__iterate_pt(ctx);
    case HD_METHOD_HD: return hd__iterate_light(ctx);
    default:
        return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "method %s is not available on the %s backend",
                       hd_method_name(ctx->vw.params.method), hd__be_name());
    }
}

/* n iterations of step (one iteration of hd_iterate or hd_refine), stopping at the first error. */
static hd_result hd__iterate_n(hd__ctx *ctx, int n, hd_result (*step)(hd__ctx *))
{
    hd_result r = HD_SUCCESS;
    int i;
    for (i = 0; i < n && r == HD_SUCCESS; ++i) r = step(ctx);
    return r;
}

/* After a measurement of the light that was converged (before) or not: when it has just
   converged, the frames in the image saw light that was still changing, so the image starts
   afresh. */
static void hd__light_settled(hd__ctx *ctx, int before)
{
    if (!before && hd__light_converged(ctx)) {
        ctx->frames = 0;
        ctx->converged_frames = 0;
        HD__INFO(&ctx->vw.log, "light converged after %llu iterations (estimated error %.3g)",
                 (unsigned long long)ctx->iterations, ctx->light_error);
    }
}

/* A light iteration of hd_refine or hd_render. */
static hd_result hd__refine_once(hd__ctx *ctx)
{
    int before = hd__light_converged(ctx);
    hd_result r = hd__light_iteration(ctx);
    if (r == HD_SUCCESS) hd__light_settled(ctx, before);
    return r;
}

/* The light iterations the last recording call recorded (ctx->rec_light), measured in the next
   call's preparation, once the caller has run them: one measurement over all of them (their
   change over n iterations: for n > 1 E's error is overestimated by about sqrt(n), so the light
   converges later, never earlier, than one measured per iteration). */
static hd_result hd__record_measure(hd__ctx *ctx)
{
    int before = hd__light_converged(ctx);
    hd_result r;
    ctx->rec_light = 0;
    if ((r = hd__light_measure(ctx)) != HD_SUCCESS) return r;
    if (!hd__light_converged(ctx)) ctx->converged_frames = 0;
    hd__light_settled(ctx, before);
    return HD_SUCCESS;
}

/* The share of render_budget the light and the frame plan for; the rest is the call's overhead
   (the preparation, the backend's bracket and wait). */
#define HD__BUDGET_MARGIN 0.9

/* After an hd_render call that planned light work against render_budget (part.planned), which
   began at `start` and ended at `end`: how much later than the plan's end (HD__BUDGET_MARGIN of
   the budget) it ended, taken at once when later than the estimate, else moving it an eighth of
   the way (a loaded machine stretches the pieces and the frame alike; the estimate, when
   positive, comes off the next calls' light deadlines). */
static void hd__budget_late(hd__ctx *ctx, double start, double end)
{
    double l = end - start - (double)ctx->vw.params.render_budget * HD__BUDGET_MARGIN;
    if (!ctx->part.planned) return;
    ctx->part.planned = 0;
    ctx->part.late = l > ctx->part.late ? l : ctx->part.late + 0.125 * (l - ctx->part.late);
}

/* hd_render's work after hd__prepare. */
static hd_result hd__render(hd__ctx *ctx)
{
    hd_result r;
    double t0 = hd__now(), last = 0.0, budget;
    budget = (double)ctx->vw.params.render_budget;
    if (hd__method_is_pt(ctx->vw.params.method)) {
        /* the image is the path tracers' state: each call adds at least one path per pixel */
        do {
            double ti = hd__now();
            if (ctx->iterations >= 0x7fffffffu) break;
            if ((r = hd__iterate_method(ctx)) != HD_SUCCESS) return r;
            last = hd__now() - ti;
        } while (hd__now() - t0 + last <= budget);
        return HD_SUCCESS;
    }
    if (budget > 0.0) {
        /* a hard limit from the call's start: the light's pieces until the time the frame is
           predicted to need (half the budget before any frame is measured), with a margin of
           HD__BUDGET_MARGIN for the call's own overhead */
        double start = ctx->call_t0 > 0.0 && ctx->call_t0 <= t0 ? ctx->call_t0 : t0;
        double frame = ctx->cost.gen > 0 ? hd__frame_cost_predict(ctx, hd__next_scale(ctx)) : budget * HD__FRAME_SHARE;
        double late = ctx->part.late > 0.0 ? ctx->part.late : 0.0;
        ctx->part.planned = !hd__light_converged(ctx);
        if ((r = hd__light_budget(ctx, start + budget * HD__BUDGET_MARGIN - frame - late)) != HD_SUCCESS) return r;
    } else {
        /* no budget: one light iteration per call (the rest of one a budget split) */
        if (!hd__light_converged(ctx) && ctx->iterations < 0x7fffffffu && (r = hd__refine_once(ctx)) != HD_SUCCESS) return r;
    }
    if (hd__light_converged(ctx)) {
        /* the image is done once frame_window frames at its final scale are in; then the view
           rests: HD_REST_REFINE and BLEND add refinement paths, at least one pass, while the
           budget has room for another (and BLEND's blend pass) */
        int s = hd__next_scale(ctx);
        if (s == ctx->frame_scale && ctx->converged_frames >= (uint64_t)ctx->vw.params.frame_window) {
            int blend = ctx->vw.params.rest == HD_REST_BLEND;
            uint64_t n0 = ctx->refined;
            if (!hd__rest_paths(ctx)) return HD_SUCCESS;
            do {
                double ti = hd__now();
                if (ctx->refined >= 0x7fffffffu) break;
                if ((r = hd__refine_paths(ctx)) != HD_SUCCESS) return r;
                last = hd__now() - ti;
            } while (hd__now() - t0 + last + (blend ? ctx->blend_cost : 0.0) <= budget);
            /* the blend pass once per call, after its paths */
            if (blend && ctx->refined > n0) return hd__blend_image(ctx, ctx->refined);
            return HD_SUCCESS;
        }
        if ((r = hd__use_scale(ctx, s)) != HD_SUCCESS) return r;
        ctx->converged_frames++;
    }
    return hd__project_frame(ctx);
}

/* A recording that failed is not submitted: no frame to time, no light to measure. */
static void hd__record_failed(hd__ctx *ctx)
{
    ctx->cost.rec_pending = 0;
    ctx->rec_light = 0;
}

/* hd_vulkan_record's work after hd__prepare: n iterations whose primitives the backend records
   into the caller's command buffer (HD__BE_RECORD). Recorded iterations have not run when this
   returns: their light is measured by the next call (hd__record_measure), and each HD or CD
   frame is timed on the device between two marks, read by the next call (hd__record_cost). */
static hd_result hd__record(hd__ctx *ctx, void *target, int n)
{
    hd_result r;
    int i, light = ctx->vw.params.method == HD_METHOD_HD || ctx->vw.params.method == HD_METHOD_CD;
    /* reduced frames need the image buffer's second region, which cannot be made mid-recording */
    if (!hd__method_is_pt(ctx->vw.params.method) && ctx->vw.params.render_scale != 1 && (r = hd__image_room(ctx)) != HD_SUCCESS)
        return r;
    /* per iteration: light, frame and a reduced frame's upsample pass */
    if ((r = hd__be_record_begin(&ctx->vw, target, 3 * n + 2)) != HD_SUCCESS) return r;
    ctx->no_measure = 1;
    ctx->cost.rec_pending = 0;
    for (i = 0; i < n && r == HD_SUCCESS; ++i) {
        if (!light) {
            r = hd__iterate_method(ctx);
            continue;
        }
        if ((r = hd__light_iteration(ctx)) != HD_SUCCESS) break;
        hd__be_record_mark(&ctx->vw, 0);
        if ((r = hd__project_frame(ctx)) != HD_SUCCESS) break;
        hd__be_record_mark(&ctx->vw, 1);
        ctx->cost.rec_pending = 1;
        ctx->cost.rec_scale = ctx->frame_scale;
        ctx->cost.rec_pixels = hd__scale_pixels(ctx, ctx->frame_scale);
        ctx->cost.rec_gen = ctx->cost.gen;
    }
    ctx->no_measure = 0;
    if (r != HD_SUCCESS) hd__record_failed(ctx);
    return hd__be_record_end(&ctx->vw, r);
}

/* hd_vulkan_record_refine's work after hd__prepare: hd_refine's n light iterations recorded (no
   projection, measured by the next call as hd__record's), then E + phi summed in the recording
   (hd__be_record_light_sum), so hd_vulkan_record_illumination after it in the same command
   buffer copies the refined light. */
static hd_result hd__record_refine(hd__ctx *ctx, void *target, int n)
{
    hd_result r;
    int i;
    if ((r = hd__be_record_begin(&ctx->vw, target, 3 * n + 2)) != HD_SUCCESS) return r;
    ctx->no_measure = 1;
    for (i = 0; i < n && r == HD_SUCCESS; ++i) r = hd__light_iteration(ctx);
    if (r == HD_SUCCESS) r = hd__be_record_light_sum(&ctx->vw);
    ctx->no_measure = 0;
    if (r != HD_SUCCESS) hd__record_failed(ctx);
    return hd__be_record_end(&ctx->vw, r);
}

/* hd_vulkan_record_render's work after hd__prepare: hd__render's schedule, recorded. HD and CD:
   while the light has not converged, one light iteration (measured by the next call) and a
   frame; once it has, the frame alone, none once the image is done; the path tracers one
   iteration. Then, with a target, the image written into it (hd__be_record_output), checked
   (hd__be_output_target_check) before anything is recorded. */
static hd_result hd__record_render(hd__ctx *ctx, void *cb, const hd_vulkan_target *target, const hd_output *out)
{
    hd_result r = HD_SUCCESS;
    int frame = 1;
    if (target && (r = hd__be_output_target_check(&ctx->vw, target, out)) != HD_SUCCESS) return r;
    if (!hd__method_is_pt(ctx->vw.params.method) && ctx->vw.params.render_scale != 1 && (r = hd__image_room(ctx)) != HD_SUCCESS)
        return r;
    /* a light iteration, a frame and a reduced frame's upsample pass */
    if ((r = hd__be_record_begin(&ctx->vw, cb, 5)) != HD_SUCCESS) return r;
    ctx->no_measure = 1;
    ctx->cost.rec_pending = 0;
    if (hd__method_is_pt(ctx->vw.params.method)) {
        if (ctx->iterations < 0x7fffffffu) r = hd__iterate_method(ctx);
        frame = 0;
    } else if (!hd__light_converged(ctx) && ctx->iterations < 0x7fffffffu) {
        r = hd__light_iteration(ctx);
    } else if (hd__light_converged(ctx)) {
        int s = hd__next_scale(ctx);
        if (s == ctx->frame_scale && ctx->converged_frames >= (uint64_t)ctx->vw.params.frame_window) {
            frame = 0;
            if (hd__rest_paths(ctx) && ctx->refined < 0x7fffffffu && (r = hd__refine_paths(ctx)) == HD_SUCCESS &&
                ctx->vw.params.rest == HD_REST_BLEND)
                r = hd__blend_image(ctx, ctx->refined);
        } else if ((r = hd__use_scale(ctx, s)) == HD_SUCCESS) ctx->converged_frames++;
    }
    if (r == HD_SUCCESS && frame) {
        hd__be_record_mark(&ctx->vw, 0);
        r = hd__project_frame(ctx);
        hd__be_record_mark(&ctx->vw, 1);
        ctx->cost.rec_pending = 1;
        ctx->cost.rec_scale = ctx->frame_scale;
        ctx->cost.rec_pixels = hd__scale_pixels(ctx, ctx->frame_scale);
        ctx->cost.rec_gen = ctx->cost.gen;
    }
    if (r == HD_SUCCESS && target) r = hd__be_record_output(&ctx->vw, target, out);
    ctx->no_measure = 0;
    if (r != HD_SUCCESS) hd__record_failed(ctx);
    return hd__be_record_end(&ctx->vw, r);
}

/* The last recorded frame's device time into the frame cost model HD_RENDER_SCALE_AUTO predicts
   from, once the caller has run it; a frame measured since by hd_iterate or hd_render is newer
   and is kept. */
static void hd__record_cost(hd__ctx *ctx)
{
    double dt = 0.0;
    if (!ctx->cost.rec_pending) return;
    ctx->cost.rec_pending = 0;
    if (hd__be_record_seconds(&ctx->vw, &dt) && ctx->cost.gen == ctx->cost.rec_gen)
        hd__frame_cost_add(ctx, ctx->cost.rec_scale, ctx->cost.rec_pixels, dt);
}
