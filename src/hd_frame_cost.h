/* hd_frame_cost.h - HD_RENDER_SCALE_AUTO: the frame-cost model (a least-squares line of frame
   time against pixels) and the render scale of each frame. Part of the core (src/hd_core.h). */
/* The pixels a frame at render scale s marches at the current camera size. */
static double hd__scale_pixels(const hd__ctx *ctx, int s)
{
    return (double)((ctx->vw.camera.width + s - 1) / s) * (double)((ctx->vw.camera.height + s - 1) / s);
}

static int hd__scale_slot(int s) { return s >= 16 ? 4 : s >= 8 ? 3 : s >= 4 ? 2 : s >= 2 ? 1 : 0; }

/* Records that a frame at render scale s, marching `pixels` rays, took `seconds` (measured by
   hd__project_frame, or on the device for a recorded one). Each scale keeps its last pixel count
   and the mean of its new time with its previous estimate (one slow frame moves it halfway). */
static void hd__frame_cost_add(hd__ctx *ctx, int s, double pixels, double seconds)
{
    int k = hd__scale_slot(s);
    if (!(seconds > 0.0) || !(pixels > 0.0)) return;
    ctx->cost.seconds[k] = ctx->cost.pixels[k] == pixels ? 0.5 * (ctx->cost.seconds[k] + seconds) : seconds;
    ctx->cost.pixels[k] = pixels;
    ctx->cost.last = k;
    ctx->cost.at[k] = ++ctx->cost.gen;
}

/* Measurements after which a scale's estimate counts as stale: a scale the frames no longer visit
   (a drag that never rests long enough for full frames) keeps the time of an older view or load. */
#define HD__COST_FRESH 32u

/* A frame's predicted seconds at render scale s: a + b * pixels. The fixed part a (per-call
   overhead, and at s > 1 the full-size upsample pass, which do not shrink with s) and b are the
   least-squares line through the scales measured (a >= 0, b >= 0; a negative a fits through the
   origin instead), scaled to pass through the newest estimate, so the level follows the current
   view and the ratios between scales come from all of them. The line runs through the scales
   measured in the last HD__COST_FRESH measurements when there are two or more, else through all.
   With one scale measured a is 0: time proportional to pixels. */
static double hd__frame_cost_predict(const hd__ctx *ctx, int s)
{
    double n = 0.0, sp = 0.0, st = 0.0, spp = 0.0, spt = 0.0, a = 0.0, b = 1.0, var, at_last;
    int k, fresh = 0, only_fresh;
    for (k = 0; k < HD__COST_SLOTS; ++k)
        if (ctx->cost.pixels[k] > 0.0 && ctx->cost.gen - ctx->cost.at[k] < HD__COST_FRESH) ++fresh;
    only_fresh = fresh >= 2;
    for (k = 0; k < HD__COST_SLOTS; ++k) {
        double p = ctx->cost.pixels[k], t = ctx->cost.seconds[k];
        if (!(p > 0.0) || (only_fresh && ctx->cost.gen - ctx->cost.at[k] >= HD__COST_FRESH)) continue;
        n += 1.0; sp += p; st += t; spp += p * p; spt += p * t;
    }
    var = n * spp - sp * sp;
    if (n >= 2.0 && var > 0.0 && n * spt - sp * st > 0.0) {
        b = (n * spt - sp * st) / var;
        a = (st - b * sp) / n;
        if (a < 0.0) { a = 0.0; b = spt / spp; }
    }
    at_last = a + b * ctx->cost.pixels[ctx->cost.last];
    return (a + b * hd__scale_pixels(ctx, s)) * ctx->cost.seconds[ctx->cost.last] / at_last;
}

/* The part of render_budget a frame may take: all of it once the light has converged, else
   HD__FRAME_SHARE of it (the light's work in the call takes the rest, src/hd_schedule.h). */
#define HD__FRAME_SHARE 0.5
static int hd__light_converged(const hd__ctx *ctx);
static double hd__frame_share(const hd__ctx *ctx)
{
    double b = (double)ctx->vw.params.render_budget;
    return hd__method_is_pt(ctx->vw.params.method) || hd__light_converged(ctx) ? b : b * HD__FRAME_SHARE;
}

/* The smallest power-of-two scale whose predicted frame time fits `limit` seconds (the largest,
   HD__MAX_RENDER_SCALE, when none does). */
static int hd__fit_scale(const hd__ctx *ctx, double limit)
{
    int s;
    for (s = 1; s < HD__MAX_RENDER_SCALE; s *= 2)
        if (hd__frame_cost_predict(ctx, s) <= limit) break;
    return s;
}

/* The scale HD_RENDER_SCALE_AUTO gives a new image's first frame: the smallest whose predicted
   time fits the frame's share of render_budget (hd__frame_share; 16 when none does); 4 without a
   budget or a measured frame. */
static int hd__first_scale(const hd__ctx *ctx)
{
    if (!(ctx->vw.params.render_budget > 0.0f) || ctx->cost.gen == 0) return 4;
    return hd__fit_scale(ctx, hd__frame_share(ctx));
}

/* The render scale of the next projection frame (params.render_scale). HD_RENDER_SCALE_AUTO: a
   new image's first frame at hd__first_scale, then half the divisor per frame down to 1; under a
   budget only while the finer frame's predicted time fits the frame's share, and a scale whose
   frames have come to cost more than 1.5 times the share gives way to a coarser one. */
static int hd__next_scale(const hd__ctx *ctx)
{
    int s = ctx->frame_scale;
    if (hd__method_is_pt(ctx->vw.params.method)) return 1;
    if (ctx->vw.params.render_scale != HD_RENDER_SCALE_AUTO) return ctx->vw.params.render_scale;
    if (s <= 0) return hd__first_scale(ctx);
    if (ctx->vw.params.render_budget > 0.0f && ctx->cost.gen > 0) {
        double share = hd__frame_share(ctx);
        if (ctx->frames > 0 && s > 1 && hd__frame_cost_predict(ctx, s / 2) <= share) return s / 2;
        if (s < HD__MAX_RENDER_SCALE && hd__frame_cost_predict(ctx, s) > 1.5 * share) return hd__fit_scale(ctx, share);
        return s;
    }
    return ctx->frames > 0 && s > 1 ? s / 2 : s;
}

/* The parts the image buffer holds besides the image (hd__image_floats). */
static int hd__image_parts(const hd__ctx *ctx)
{
    return (ctx->image_room ? HD__IMAGE_REDUCED : 0) | (ctx->image_blend ? HD__IMAGE_BLEND : 0);
}

/* Gives the image buffer the reduced frames' region if it lacks it (the first frame at a scale
   > 1), then clears it (the new buffer's contents are undefined; the frame about to be made
   restarts the running mean anyway). On failure the full-size image is kept as it was and
   frames at scale 1 go on working. */
static hd_result hd__image_room(hd__ctx *ctx)
{
    hd_result r;
    if (ctx->image_room) return HD_SUCCESS;
    if ((r = hd__be_alloc_image(&ctx->vw, ctx->vw.camera.width, ctx->vw.camera.height, hd__image_parts(ctx) | HD__IMAGE_REDUCED)) !=
        HD_SUCCESS)
        return r;
    ctx->image_room = 1;
    ctx->frames = ctx->converged_frames = ctx->refined = 0;
    return hd__be_clear(&ctx->vw, HD__DIRTY_IMAGE);
}

/* Makes s the scale of the image's frames; frames at another scale are dropped (the running
   mean restarts). A scale > 1 first needs the reduced frames' region (hd__image_room). */
static hd_result hd__use_scale(hd__ctx *ctx, int s)
{
    hd_result r;
    if (s > 1 && (r = hd__image_room(ctx)) != HD_SUCCESS) return r;
    if (ctx->frames > 0 && s != ctx->frame_scale) ctx->frames = ctx->converged_frames = 0;
    ctx->frame_scale = s;
    return HD_SUCCESS;
}
