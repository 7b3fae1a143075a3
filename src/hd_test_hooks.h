/* hd_test_hooks.h - PRIVATE hooks that run single stages of the schedule (not API: no hd_ names,
   no stability promise). The conformance suite and the benchmarks call them from the
   library's implementation's translation unit to compare stages across backends: one diffusion
   sweep, a solve, the projection of illumination they wrote themselves. The implementation
   includes this file itself under HYBRIDDIFF_TESTING, before it undefines its macros
   (backends/hd_undef.h), as the hooks need them; an include after the implementation is a no-op.
   Each hook first brings the context up to date (hd__prepare) exactly as hd_iterate does, in one
   bracket of the backend's (HD__BE_CALL). A translation unit that includes it defines
   HYBRIDDIFF_TESTING before the implementation, which then keeps the backends' test-only
   functions and fault injection (without it a release build has neither). */
#ifndef HYBRIDDIFF_TESTING
#error "hybriddiff: src/hd_test_hooks.h needs HYBRIDDIFF_TESTING defined before the implementation"
#endif
#if !defined(HYBRIDDIFF_IMPLEMENTATION_DONE)
#error "hybriddiff: src/hd_test_hooks.h comes with the implementation: define HYBRIDDIFF_TESTING and HYBRIDDIFF_IMPLEMENTATION"
#endif
/* HD_CORE_H (src/hd_core.h's guard) is defined inside the implementation only: after it, the
   hooks are already there. */
#if defined(HD_CORE_H) && !defined(HD__TEST_HOOKS_H)
#define HD__TEST_HOOKS_H

/* The state a hook starts from: allocations, sigma_t, cleared accumulations. */
HD__MAYBE_UNUSED static hd_result hd__test_prepare(hd_context h)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    HD__BE_CALL(r, ctx, HD_SUCCESS);
    return r;
}

/* n direct-light passes (HD stage 1 only), each one iteration of the progressive mean. */
static hd_result hd__test_direct_once(hd__ctx *ctx)
{
    ctx->iterations++;
    ctx->dl_n++; /* E's mean holds one sample more */
    hd__fill_kparams(ctx);
    return hd__be_direct(&ctx->vw, 0, ctx->vw.dl_count);
}
HD__MAYBE_UNUSED static hd_result hd__test_direct(hd_context h, int n)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    HD__BE_CALL(r, ctx, hd__iterate_n(ctx, n, hd__test_direct_once));
    return r;
}

/* on = 1: HD's direct light tracks every voxel of the illumination grid; 0: only the voxels
   whose E is read (the library's way, hd__direct_mask). The reference the mask is tested and
   benchmarked against; E, phi and the image restart. */
HD__MAYBE_UNUSED static hd_result hd__test_direct_all(hd_context h, int on)
{
    HD__GET_CTX(ctx, h);
    ctx->dl.all = on != 0;
    ctx->dirty |= HD__DIRTY_SIGMA | HD__DIRTY_DIRECT | HD__DIRTY_PHI | HD__DIRTY_IMAGE;
    return HD_SUCCESS;
}

/* The number of illumination-grid voxels the direct light tracks (after hd__test_prepare). */
HD__MAYBE_UNUSED static size_t hd__test_direct_count(hd_context h)
{
    hd__ctx *ctx = hd__lookup(h);
    return ctx ? ctx->vw.dl_count : 0;
}

/* n diffusion sweeps of the selected solver (multigrid: CG steps) on the current E and phi. */
static hd_result hd__test_diffuse_n(hd__ctx *ctx, int n)
{
    hd__fill_kparams(ctx);
    return hd__iterate_n(ctx, n, hd__diffuse_once);
}
HD__MAYBE_UNUSED static hd_result hd__test_diffuse(hd_context h, int n)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    HD__BE_CALL(r, ctx, hd__test_diffuse_n(ctx, n));
    return r;
}

#ifdef HYBRIDDIFF_BACKEND_CPU
/* The relative residual |f - A phi| / |f| of the diffusion equation for the current E and phi. */
HD__MAYBE_UNUSED static hd_result hd__test_residual(hd_context h, double *out)
{
    HD__GET_CTX(ctx, h);
    hd__fill_kparams(ctx);
    *out = hd__cpu_residual(&ctx->vw);
    return HD_SUCCESS;
}
#endif

/* Set: hd__test_project's frames write no depth plane (kp.region.z = 0, as a block without one),
   so a benchmark sees what writing it costs (bench/hdbench_depth.c). */
HD__MAYBE_UNUSED static int hd__test_no_depth_plane;

/* n projection frames of the current E and phi into the image. */
static hd_result hd__test_project_once(hd__ctx *ctx)
{
    hd_result r;
    ctx->frames++;
    hd__fill_kparams(ctx);
    if (hd__test_no_depth_plane) ctx->vw.kp.region.z = 0;
    if ((r = hd__be_project(&ctx->vw)) == HD_SUCCESS) ctx->image_empty = 0; /* the image holds a frame */
    return r;
}
HD__MAYBE_UNUSED static hd_result hd__test_project(hd_context h, int n)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
    HD__BE_CALL(r, ctx, hd__iterate_n(ctx, n, hd__test_project_once));
    return r;
}

/* Overwrites E or phi (channel-planar, hd_stats' dims and channels) with src: the only hook that
   reaches into a backend's buffers, so it has one branch per backend. */
HD__MAYBE_UNUSED static hd_result hd__test_write_illumination(hd_context h, hd_illumination which, const float *src)
{
    hd_result r;
    HD__GET_CTX(ctx, h);
#if defined(HYBRIDDIFF_BACKEND_CPU)
    HD__BE_CALL(r, ctx, hd__cpu_write_illumination(&ctx->vw, which, src));
#elif defined(HYBRIDDIFF_BACKEND_OPENCL)
    HD__BE_CALL(r, ctx, hd__cl_write_illumination(&ctx->vw, which, src));
#elif defined(HYBRIDDIFF_BACKEND_VULKAN)
    HD__BE_CALL(r, ctx, hd__vk_write_illumination(&ctx->vw, which, src));
#elif defined(HYBRIDDIFF_BACKEND_GL)
    HD__BE_CALL(r, ctx, hd__gl_write_illumination(&ctx->vw, which, src));
#else
    (void)which; (void)src;
    r = HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "hd__test_write_illumination: no hook for the %s backend", hd__be_name());
#endif
    return r;
}

/* Waits until the device has done everything queued (for timing). */
HD__MAYBE_UNUSED static hd_result hd__test_finish(hd_context h)
{
    HD__GET_CTX(ctx, h);
#if defined(HYBRIDDIFF_BACKEND_OPENCL)
    HD__CL_TRY(&ctx->vw, clFinish(ctx->vw.be->queue), "clFinish");
#elif defined(HYBRIDDIFF_BACKEND_GL)
    return hd__gl_finish(&ctx->vw);
#endif
    (void)ctx;
    return HD_SUCCESS;
}

/* HD_RENDER_SCALE_AUTO's cost model without running frames: records that a frame at render
   scale s of the current camera took `seconds`, as a measured one does. */
HD__MAYBE_UNUSED static hd_result hd__test_frame_cost(hd_context h, int s, double seconds)
{
    HD__GET_CTX(ctx, h);
    hd__frame_cost_add(ctx, s, hd__scale_pixels(ctx, s), seconds);
    return HD_SUCCESS;
}

/* The scale HD_RENDER_SCALE_AUTO would give a new image's first frame now. */
HD__MAYBE_UNUSED static int hd__test_first_scale(hd_context h)
{
    hd__ctx *ctx = hd__lookup(h);
    return ctx ? hd__first_scale(ctx) : 0;
}
/* on = 1: draw the light of each sample uniformly among the lights instead of by their
   estimated light (hd__light_cdf), to measure what the choice by estimate gains. */
HD__MAYBE_UNUSED static hd_result hd__test_light_uniform(hd_context h, int on)
{
    HD__GET_CTX(ctx, h);
    ctx->light_uniform = on != 0;
    ctx->dirty |= HD__INV_WARM_LIGHT;
    return HD_SUCCESS;
}
#endif /* HD_CORE_H: inside the implementation */
