/* hdbench_vulkan.c - Vulkan figures on the head CT (data/head.nrrd; `make data`). In ONE run, so
   the ratios hold however loaded the machine is:
     - the diffusion sweep targets: a plain constant-coefficient 7-point Jacobi stencil on the
       Vulkan device through r32f storage image3Ds and through storage buffers (its own shader,
       bench/hdbench_stencil.comp, compiled by `scripts/build-spirv --bench`), the same stencil in
       plain C (one thread), and the library's red-black and Jacobi sweeps on the same grid
       (src/hd_test_hooks.h). Every Vulkan figure is one submit + wait per sweep, as the library
       runs; the stencils reuse the library's device, images and command buffer. Each figure is
       the best of `rounds` round-robin passes, so a burst of load elsewhere hits one pass only;
     - iterations/s of every method (HD, CD, PT_SS, PT_MS) with 1 and 3 lights, through hd_iterate
       (skipped with --sweeps).
     - with --variants instead: the plain image3D stencil (and through storage buffers, as floats
       and as x-packed vec4) and the library's red-black sweep beside bench/hdbench_sweep.comp's
       variants of the sweep's memory access (what lavapipe's cost is made of), on the library's
       head-CT sigma_t and E; first every variant that computes the library's update (rb, the
       x-packed p4 / p2) is checked against the library's phi after 8 sweeps;
     - with --ab FILE.spv also: the library's sweeps with the diffusion module FILE (a candidate
       build/spirv/diffuse.spv, specialized and dispatched for blocks of --ab-zk slices x --ab-yk
       rows per invocation, default 1 x 1), interleaved with the library's own.
   Usage: hdbench_vulkan [file.nrrd] [seconds per figure, default 2] [--sweeps] [--rounds n]
                         [--variants[=name,name...]] [--ab FILE.spv [--ab-zk n] [--ab-yk n]] */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HD__KEEP_MACROS /* white-box: reaches the implementation's macros after it */
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hdbench_vulkan_spirv.h" /* generated into the build directory by mk/vulkan.mk */
#include <math.h>
#include <stdio.h>

static double budget = 2.0;

typedef hd_result (*step_fn)(void *user);

/* Runs step(user) until the budget is spent; returns steps per second (-1 on failure). */
static double rate(step_fn step, void *user)
{
    double t0, t;
    int n = 0;
    if (step(user) != HD_SUCCESS) return -1.0; /* warm-up: allocation, upload, classify */
    t0 = hd__now();
    do {
        if (step(user) != HD_SUCCESS) return -1.0;
        ++n;
        t = hd__now() - t0;
    } while (t < budget);
    return n / t;
}

/* The library's errors only (a failed figure says why); its info lines would clutter the table. */
static void log_errors(void *user, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    (void)user; (void)code; (void)file; (void)line;
    if (level == HD_LOG_ERROR) fprintf(stderr, "hdbench_vulkan: %s\n", msg);
}

static hd_result sweep_step(void *h) { return hd__test_diffuse(*(hd_context *)h, 1); }

/* --ab FILE.spv: the library's sweep with its diffusion pipeline swapped for one made from FILE
   (e.g. build/spirv/diffuse.spv of a candidate tree), interleaved with the library's own, so a
   change to the diffusion module is measured against the committed one in one process. */
static uint32_t *ab_code;
static size_t ab_bytes;
static int32_t ab_zk = 1; /* --ab-zk n: FILE's slices per invocation (1 for a module without hd_sc_zk) */
static int32_t ab_yk = 1; /* --ab-yk n: FILE's rows per invocation (1 for a module without hd_sc_yk) */
typedef struct ab_sweep {
    hd_context h;
    VkPipeline alt;
    int live; /* ab_init ran */
} ab_sweep;

static hd_result ab_step(void *user)
{
    ab_sweep *a = (ab_sweep *)user;
    hd__backend *be = (&hd__lookup(a->h)->vw)->be;
    VkPipeline own = be->diffuse[0];
    int32_t own_zk = be->diffuse_zk, own_yk = be->diffuse_yk;
    hd_result r;
    be->diffuse[0] = a->alt;
    be->diffuse_zk = ab_zk;
    be->diffuse_yk = ab_yk;
    r = hd__test_diffuse(a->h, 1);
    be->diffuse[0] = own;
    be->diffuse_zk = own_zk;
    be->diffuse_yk = own_yk;
    return r;
}

/* After one sweep made the library's pipeline: the alternative with the same specialization. */
static hd_result ab_init(ab_sweep *a, hd_context h)
{
    const hd__view *ctx = (&hd__lookup(h)->vw);
    hd_result r;
    a->h = h;
    a->alt = VK_NULL_HANDLE;
    a->live = 1;
    if ((r = hd__test_diffuse(h, 1)) != HD_SUCCESS) return r;
    if (ctx->be->ndiffuse != 1) return HD_ERROR_BACKEND;
    {
        int32_t own_zk = ctx->be->diffuse_zk, own_yk = ctx->be->diffuse_yk;
        ctx->be->diffuse_zk = ab_zk;
        ctx->be->diffuse_yk = ab_yk;
        r = hd__vk_pipeline_code(ctx, ab_code, ab_bytes, &ctx->be->diffuse_flags[0], ctx->be->diffuse_jacobi[0], &a->alt);
        ctx->be->diffuse_zk = own_zk;
        ctx->be->diffuse_yk = own_yk;
        return r;
    }
}

static void ab_free(ab_sweep *a)
{
    hd__backend *be = (&hd__lookup(a->h)->vw)->be;
    be->fn.vkDeviceWaitIdle(be->device);
    if (a->alt) be->fn.vkDestroyPipeline(be->device, a->alt, NULL);
}

static int ab_load(const char *path)
{
    FILE *f = fopen(path, "rb");
    long n;
    if (!f) return 0;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    ab_code = n > 0 && n % 4 == 0 ? (uint32_t *)malloc((size_t)n) : NULL;
    ab_bytes = ab_code && fread(ab_code, 1, (size_t)n, f) == (size_t)n ? (size_t)n : 0;
    fclose(f);
    return ab_bytes > 0;
}
static hd_result iterate_step(void *h) { return hd_iterate(*(hd_context *)h, 1); }

/* ---- the plain stencil on the Vulkan device ------------------------------------------------- */
typedef struct stencil {
    const hd__view *ctx;
    int ssbo, cur, g[3]; /* ssbo: 0 r32f images, 1 float buffers, 2 the buffers as vec4 (x-packed) */
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipeline;
    VkDescriptorPool pool;
    VkDescriptorSet sets[2]; /* a -> b and b -> a */
    hd__vk_image im[3];      /* a, b, rhs (image variant) */
    hd__vk_buffer buf[3];    /* a, b, rhs (SSBO variant) */
} stencil;

static void stencil_free(stencil *s)
{
    hd__backend *be = s->ctx->be;
    int i;
    be->fn.vkDeviceWaitIdle(be->device);
    for (i = 0; i < 3; ++i) { hd__vk_free_image(s->ctx, &s->im[i]); hd__vk_free_buffer(s->ctx, &s->buf[i]); }
    if (s->pipeline) be->fn.vkDestroyPipeline(be->device, s->pipeline, NULL);
    if (s->pool) be->fn.vkDestroyDescriptorPool(be->device, s->pool, NULL);
    if (s->layout) be->fn.vkDestroyPipelineLayout(be->device, s->layout, NULL);
    if (s->set_layout) be->fn.vkDestroyDescriptorSetLayout(be->device, s->set_layout, NULL);
    be->sets_valid = 0; /* the library's own sets are untouched, but re-checking costs nothing */
}

/* Three grids of g: a and b zeroed, rhs = (i % 97) * 0.01 as in c_stencil. */
static hd_result stencil_resources(stencil *s)
{
    const hd__view *ctx = s->ctx;
    size_t n = (size_t)s->g[0] * s->g[1] * s->g[2], i;
    VkDeviceSize bytes = n * sizeof(float);
    float *rhs = (float *)malloc(n * sizeof(float));
    hd_result r = HD_SUCCESS;
    int k;
    if (!rhs) return HD_ERROR_OUT_OF_MEMORY;
    for (i = 0; i < n; ++i) rhs[i] = (float)(i % 97) * 0.01f;
    for (k = 0; k < 3 && r == HD_SUCCESS; ++k)
        r = s->ssbo ? hd__vk_buffer_create(ctx, &s->buf[k], bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                           k == 2, "a stencil buffer")
                    : hd__vk_image_new(ctx, &s->im[k], s->g[0], s->g[1], s->g[2], "a stencil image");
    if (r == HD_SUCCESS && s->ssbo) {
        VkCommandBuffer cb;
        memcpy(s->buf[2].map, rhs, (size_t)bytes); /* rhs is host-visible: read in place */
        if ((r = hd__vk_cmd(ctx, &cb)) == HD_SUCCESS) {
            ctx->be->fn.vkCmdFillBuffer(cb, s->buf[0].buffer, 0, VK_WHOLE_SIZE, 0u);
            ctx->be->fn.vkCmdFillBuffer(cb, s->buf[1].buffer, 0, VK_WHOLE_SIZE, 0u);
            r = hd__vk_flush(ctx);
        }
    } else if (r == HD_SUCCESS) {
        r = hd__vk_upload_image(ctx, &s->im[2], rhs);
    }
    free(rhs);
    return r;
}

static hd_result stencil_sets(stencil *s)
{
    hd__backend *be = s->ctx->be;
    VkDescriptorType type = s->ssbo ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    VkDescriptorPoolSize ps;
    VkDescriptorPoolCreateInfo dpci;
    VkDescriptorSetLayout layouts[2];
    VkDescriptorSetAllocateInfo ai;
    int k, i;
    ps.type = type;
    ps.descriptorCount = 6;
    memset(&dpci, 0, sizeof dpci);
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 2;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &ps;
    HD__VK_TRY(s->ctx, be->fn.vkCreateDescriptorPool(be->device, &dpci, NULL, &s->pool), "vkCreateDescriptorPool");
    layouts[0] = layouts[1] = s->set_layout;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = s->pool;
    ai.descriptorSetCount = 2;
    ai.pSetLayouts = layouts;
    HD__VK_TRY(s->ctx, be->fn.vkAllocateDescriptorSets(be->device, &ai, s->sets), "vkAllocateDescriptorSets");
    for (k = 0; k < 2; ++k) {
        VkWriteDescriptorSet w[3];
        VkDescriptorBufferInfo bi[3];
        VkDescriptorImageInfo ii[3];
        for (i = 0; i < 3; ++i) {
            int res = i == 2 ? 2 : (i + k) & 1; /* set k reads grid k, writes grid 1 - k */
            memset(&w[i], 0, sizeof w[i]);
            w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            w[i].dstSet = s->sets[k];
            w[i].dstBinding = (uint32_t)i;
            w[i].descriptorCount = 1;
            w[i].descriptorType = type;
            bi[i].buffer = s->buf[res].buffer;
            bi[i].offset = 0;
            bi[i].range = VK_WHOLE_SIZE;
            ii[i].sampler = VK_NULL_HANDLE;
            ii[i].imageView = s->im[res].view;
            ii[i].imageLayout = VK_IMAGE_LAYOUT_GENERAL;
            if (s->ssbo) w[i].pBufferInfo = &bi[i];
            else w[i].pImageInfo = &ii[i];
        }
        be->fn.vkUpdateDescriptorSets(be->device, 3, w, 0, NULL);
    }
    return HD_SUCCESS;
}

static hd_result stencil_init(stencil *s, const hd__view *ctx, const int *g, int ssbo)
{
    VkDescriptorType types[3];
    hd_result r;
    int i;
    memset(s, 0, sizeof *s);
    s->ctx = ctx;
    s->ssbo = ssbo;
    memcpy(s->g, g, sizeof s->g);
    for (i = 0; i < 3; ++i) types[i] = ssbo ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    if ((r = hd__vk_layouts(ctx, types, 3, 4 * sizeof(int32_t), &s->set_layout, &s->layout)) != HD_SUCCESS) return r;
    r = ssbo == 2 ? hd__vk_compute_pipeline(ctx, hd__spv_stencil_ssbo4, sizeof hd__spv_stencil_ssbo4, NULL, s->layout, &s->pipeline)
      : ssbo ? hd__vk_compute_pipeline(ctx, hd__spv_stencil_ssbo, sizeof hd__spv_stencil_ssbo, NULL, s->layout, &s->pipeline)
             : hd__vk_compute_pipeline(ctx, hd__spv_stencil_image, sizeof hd__spv_stencil_image, NULL, s->layout, &s->pipeline);
    if (r != HD_SUCCESS) return r;
    if ((r = stencil_resources(s)) != HD_SUCCESS) return r;
    return stencil_sets(s);
}

/* One Jacobi pass a -> b (then b -> a), submitted and waited for like a library sweep. */
static hd_result stencil_step(void *user)
{
    stencil *s = (stencil *)user;
    hd__backend *be = s->ctx->be;
    VkCommandBuffer cb;
    int32_t pc[4];
    hd_result r;
    if ((r = hd__vk_cmd(s->ctx, &cb)) != HD_SUCCESS) return r;
    pc[0] = s->g[0]; pc[1] = s->g[1]; pc[2] = s->g[2]; pc[3] = 0;
    hd__vk_barrier(be, cb);
    be->fn.vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->pipeline);
    be->fn.vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, s->layout, 0, 1, &s->sets[s->cur], 0, NULL);
    be->fn.vkCmdPushConstants(cb, s->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, pc);
    be->fn.vkCmdDispatch(cb, ((uint32_t)s->g[0] / (s->ssbo == 2 ? 4u : 1u) + 63u) / 64u, (uint32_t)s->g[1], (uint32_t)s->g[2]);
    s->cur ^= 1;
    return hd__vk_flush(s->ctx);
}

/* ---- variants of the sweep's memory access (bench/hdbench_sweep.comp, --variants) ------------- */
#define NVAR ((int)(sizeof hd__sweep_variants / sizeof hd__sweep_variants[0]))
#define VAR_BINDINGS 14
#define VAR_IMAGES 11
typedef struct variants {
    const hd__view *ctx;
    int g[3], cur;
    float prm[4], med[4]; /* push constants of RB / PACKED: the library's parameters (variants_params) */
    /* st, E, phi (r32f), packed (st, phi) (rg32f); st, E, phi, out x-packed by 4 (rgba32f); st, E,
       phi x-packed by 2 (rg32f) */
    hd__vk_image im[VAR_IMAGES];
    VkSampler sampler;
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkDescriptorPool pool;
    VkDescriptorSet set;
    VkPipeline pipe[NVAR];
} variants;

static void variants_free(variants *v)
{
    hd__backend *be = v->ctx->be;
    int i;
    be->fn.vkDeviceWaitIdle(be->device);
    for (i = 0; i < VAR_IMAGES; ++i) hd__vk_free_image(v->ctx, &v->im[i]);
    for (i = 0; i < NVAR; ++i)
        if (v->pipe[i]) be->fn.vkDestroyPipeline(be->device, v->pipe[i], NULL);
    if (v->pool) be->fn.vkDestroyDescriptorPool(be->device, v->pool, NULL);
    if (v->layout) be->fn.vkDestroyPipelineLayout(be->device, v->layout, NULL);
    if (v->set_layout) be->fn.vkDestroyDescriptorSetLayout(be->device, v->set_layout, NULL);
    if (v->sampler) {
        PFN_vkDestroySampler destroy = (PFN_vkDestroySampler)be->fn.vkGetDeviceProcAddr(be->device, "vkDestroySampler");
        destroy(be->device, v->sampler, NULL);
    }
}

/* st and E: the library's (lib_st, lib_e: the head CT's sigma_t and one direct pass) where given,
   else a CT-like mix of empty (0) and medium voxels and the stencil's rhs; phi 0. The x-packed
   images hold the same floats in the same order (a texel is PK x-consecutive voxels), so they take
   the same arrays. */
static hd_result variants_data(variants *v, const float *lib_st, const float *lib_e)
{
    size_t n = (size_t)v->g[0] * v->g[1] * v->g[2], i;
    float *st = (float *)malloc(n * sizeof(float)), *e = (float *)malloc(n * sizeof(float));
    float *pk = (float *)malloc(2 * n * sizeof(float));
    hd_result r = HD_ERROR_OUT_OF_MEMORY;
    if (st && e && pk) {
        for (i = 0; i < n; ++i) {
            st[i] = lib_st ? lib_st[i] : i % 89 < 20 ? 0.0f : 0.05f + (float)(i % 89) * 0.01f;
            e[i] = lib_e ? lib_e[i] : (float)(i % 97) * 0.01f;
            pk[2 * i] = st[i];
            pk[2 * i + 1] = 0.0f;
        }
        r = hd__vk_upload_image(v->ctx, &v->im[0], st);
        if (r == HD_SUCCESS) r = hd__vk_upload_image(v->ctx, &v->im[1], e);
        if (r == HD_SUCCESS) r = hd__vk_upload_image(v->ctx, &v->im[3], pk);
        for (i = 0; r == HD_SUCCESS && i < 2; ++i) { /* rgba32f x4 and rg32f x2: st, E */
            r = hd__vk_upload_image(v->ctx, &v->im[4 + 4 * i], st);
            if (r == HD_SUCCESS) r = hd__vk_upload_image(v->ctx, &v->im[5 + 4 * i], e);
        }
    }
    free(st); free(e); free(pk);
    return r;
}

/* Bindings 4-6 are samplers over images 0-2; 0-3 and 7-13 storage images 0-3 and 4-10. */
static int var_sampled(int binding) { return binding >= 4 && binding < 7; }
static int var_image(int binding) { return binding < 4 ? binding : binding < 7 ? binding - 4 : binding - 3; }

static hd_result variants_set(variants *v)
{
    hd__backend *be = v->ctx->be;
    VkDescriptorPoolSize ps[2];
    VkDescriptorPoolCreateInfo dpci;
    VkDescriptorSetAllocateInfo ai;
    VkWriteDescriptorSet w[VAR_BINDINGS];
    VkDescriptorImageInfo ii[VAR_BINDINGS];
    int i;
    ps[0].type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE; ps[0].descriptorCount = VAR_IMAGES;
    ps[1].type = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER; ps[1].descriptorCount = 3;
    memset(&dpci, 0, sizeof dpci);
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 1;
    dpci.poolSizeCount = 2;
    dpci.pPoolSizes = ps;
    HD__VK_TRY(v->ctx, be->fn.vkCreateDescriptorPool(be->device, &dpci, NULL, &v->pool), "vkCreateDescriptorPool");
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = v->pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &v->set_layout;
    HD__VK_TRY(v->ctx, be->fn.vkAllocateDescriptorSets(be->device, &ai, &v->set), "vkAllocateDescriptorSets");
    for (i = 0; i < VAR_BINDINGS; ++i) {
        memset(&w[i], 0, sizeof w[i]);
        w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[i].dstSet = v->set;
        w[i].dstBinding = (uint32_t)i;
        w[i].descriptorCount = 1;
        w[i].descriptorType = var_sampled(i) ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
        ii[i].sampler = var_sampled(i) ? v->sampler : VK_NULL_HANDLE;
        ii[i].imageView = v->im[var_image(i)].view;
        ii[i].imageLayout = VK_IMAGE_LAYOUT_GENERAL;
        w[i].pImageInfo = &ii[i];
    }
    be->fn.vkUpdateDescriptorSets(be->device, VAR_BINDINGS, w, 0, NULL);
    return HD_SUCCESS;
}

static hd_result variants_pipelines(variants *v)
{
    hd_result r;
    int k;
    for (k = 0; k < NVAR; ++k)
        if ((r = hd__vk_compute_pipeline(v->ctx, hd__sweep_variants[k].code, hd__sweep_variants[k].bytes, NULL, v->layout,
                                         &v->pipe[k])) != HD_SUCCESS)
            return r;
    return HD_SUCCESS;
}

static hd_result variants_init(variants *v, const hd__view *ctx, const int *g, const float *lib_st, const float *lib_e)
{
    hd__backend *be = ctx->be;
    VkDescriptorType types[VAR_BINDINGS];
    VkSamplerCreateInfo sci;
    PFN_vkCreateSampler create;
    hd_result r;
    int i;
    memset(v, 0, sizeof *v);
    v->ctx = ctx;
    memcpy(v->g, g, sizeof v->g);
    if (g[0] % 4 != 0) { /* the x-packed variants assume whole texels */
        fprintf(stderr, "hdbench_vulkan: --variants needs nx %% 4 == 0 (nx = %d)\n", g[0]);
        return HD_ERROR_INVALID_DIMENSIONS;
    }
    for (i = 0, r = HD_SUCCESS; i < VAR_IMAGES && r == HD_SUCCESS; ++i) {
        int pk = i >= 4 && i < 8 ? 4 : i >= 8 ? 2 : 1;
        VkFormat f = pk == 4 ? VK_FORMAT_R32G32B32A32_SFLOAT : pk == 2 || i == 3 ? VK_FORMAT_R32G32_SFLOAT : VK_FORMAT_R32_SFLOAT;
        if ((r = hd__vk_image_create_as(ctx, &v->im[i], g[0] / pk, g[1], g[2], f, i < 3 ? VK_IMAGE_USAGE_SAMPLED_BIT : 0,
                                        "a variant image")) == HD_SUCCESS)
            r = hd__vk_image_init(ctx, &v->im[i]);
        if (pk == 4) v->im[i].texel = 16; /* the library's images know r32f, rg32f and r16f only */
    }
    if (r != HD_SUCCESS || (r = variants_data(v, lib_st, lib_e)) != HD_SUCCESS) return r;
    memset(&sci, 0, sizeof sci);
    sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    create = (PFN_vkCreateSampler)be->fn.vkGetDeviceProcAddr(be->device, "vkCreateSampler"); /* the library needs none */
    HD__VK_TRY(ctx, create(be->device, &sci, NULL, &v->sampler), "vkCreateSampler");
    for (i = 0; i < VAR_BINDINGS; ++i)
        types[i] = var_sampled(i) ? VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    if ((r = hd__vk_layouts(ctx, types, VAR_BINDINGS, 16 * sizeof(int32_t), &v->set_layout, &v->layout)) != HD_SUCCESS)
        return r;
    if ((r = variants_pipelines(v)) != HD_SUCCESS) return r;
    return variants_set(v);
}

/* One full red-black sweep of variant v->cur: two half-sweeps, submitted and waited for. */
static hd_result variant_step(void *user)
{
    variants *v = (variants *)user;
    hd__backend *be = v->ctx->be;
    VkCommandBuffer cb;
    uint32_t lx = (uint32_t)hd__sweep_variants[v->cur].lx, ly = (uint32_t)hd__sweep_variants[v->cur].ly;
    uint32_t zk = (uint32_t)hd__sweep_variants[v->cur].zk, yk = (uint32_t)hd__sweep_variants[v->cur].yk;
    uint32_t xk = (uint32_t)hd__sweep_variants[v->cur].xk, sv = (uint32_t)hd__sweep_variants[v->cur].sv;
    /* invocations along x: one per texel of the x-packed images (14 PACKED: nx / PK; 15 PSTENCIL,
       16 PCOPY: nx / 4), else one per voxel of a colour (nx / 2, rounded up) */
    uint32_t nx = sv == 14 ? (uint32_t)(v->g[0] / hd__sweep_variants[v->cur].pk) : sv == 15 || sv == 16 ? (uint32_t)v->g[0] / 4u : (uint32_t)(v->g[0] + 1) / 2;
    int32_t pc[16];
    hd_result r;
    int parity;
    if ((r = hd__vk_cmd(v->ctx, &cb)) != HD_SUCCESS) return r;
    memset(pc, 0, sizeof pc);
    pc[0] = v->g[0]; pc[1] = v->g[1]; pc[2] = v->g[2];
    pc[5] = (int32_t)zk; /* ZRT variants read their count here */
    memcpy(&pc[8], v->prm, sizeof v->prm);
    memcpy(&pc[12], v->med, sizeof v->med);
    be->fn.vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, v->pipe[v->cur]);
    be->fn.vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, v->layout, 0, 1, &v->set, 0, NULL);
    for (parity = 0; parity < (sv == 15 || sv == 16 ? 1 : 2); ++parity) { /* 15, 16: one pass over every texel */
        pc[4] = parity;
        hd__vk_barrier(be, cb);
        be->fn.vkCmdPushConstants(cb, v->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, pc);
        be->fn.vkCmdDispatch(cb, (nx + lx * xk - 1) / (lx * xk), ((uint32_t)v->g[1] + ly * yk - 1) / (ly * yk),
                              ((uint32_t)v->g[2] + zk - 1) / zk);
    }
    return hd__vk_flush(v->ctx);
}

/* ---- the same stencil in plain C --------------------------------------------------------------- */
typedef struct c_grid {
    int g[3];
    float *a, *b, *rhs;
} c_grid;

/* phi' = (b + sum of the 6 neighbours' phi) / 7 with zero outside, Jacobi ping-pong. */
static hd_result c_step(void *user)
{
    c_grid *c = (c_grid *)user;
    const int *g = c->g;
    size_t sxy = (size_t)g[0] * g[1];
    int x, y, z;
    for (z = 0; z < g[2]; ++z)
        for (y = 0; y < g[1]; ++y)
            for (x = 0; x < g[0]; ++x) {
                size_t k = z * sxy + (size_t)y * g[0] + x;
                float s = c->rhs[k];
                s += x > 0 ? c->a[k - 1] : 0.0f;
                s += x < g[0] - 1 ? c->a[k + 1] : 0.0f;
                s += y > 0 ? c->a[k - g[0]] : 0.0f;
                s += y < g[1] - 1 ? c->a[k + g[0]] : 0.0f;
                s += z > 0 ? c->a[k - sxy] : 0.0f;
                s += z < g[2] - 1 ? c->a[k + sxy] : 0.0f;
                c->b[k] = s * (1.0f / 7.0f);
            }
    { float *tmp = c->a; c->a = c->b; c->b = tmp; }
    return HD_SUCCESS;
}

/* ---- the figures ------------------------------------------------------------------------------- */
enum { F_IMAGE, F_SSBO, F_C, F_RB, F_JACOBI, F_RB_AB, F_JACOBI_AB, F_COUNT };

static void sweep_figures(const hd_desc *base, const int *g, int rounds)
{
    static const char *names[F_COUNT] = {
        "plain 7-point stencil, Vulkan, storage image3D",
        "plain 7-point stencil, Vulkan, storage buffer",
        "plain 7-point stencil, C, 1 thread",
        "library sweep, red-black (2 half-sweeps)",
        "library sweep, Jacobi (+ copy back)",
        "--ab module, red-black",
        "--ab module, Jacobi"};
    double best[F_COUNT], vox = (double)g[0] * g[1] * g[2];
    hd_desc d = *base;
    hd_context h[2];
    ab_sweep ab[2];
    stencil st[2];
    int nfig = ab_code ? F_COUNT : F_RB_AB;
    c_grid c;
    size_t n = (size_t)vox, i;
    int k, f, ok = 1;
    memset(best, 0, sizeof best);
    d.params.solver = HD_SOLVER_RED_BLACK;
    if (hd_create(&d, &h[0]) != HD_SUCCESS) { printf("Vulkan unavailable\n"); return; }
    d.params.solver = HD_SOLVER_JACOBI;
    if (hd_create(&d, &h[1]) != HD_SUCCESS) { hd_destroy(h[0]); printf("Vulkan unavailable\n"); return; }
    printf("device: %s\n", (&hd__lookup(h[0])->vw)->be->device_name);
    for (k = 0; k < 2; ++k)
        if (stencil_init(&st[k], (&hd__lookup(h[0])->vw), g, k) != HD_SUCCESS) ok = 0;
    memset(ab, 0, sizeof ab);
    for (k = 0; ab_code && k < 2; ++k)
        if (ab_init(&ab[k], h[k]) != HD_SUCCESS) ok = 0;
    c.g[0] = g[0]; c.g[1] = g[1]; c.g[2] = g[2];
    c.a = (float *)calloc(n, sizeof(float)); c.b = (float *)calloc(n, sizeof(float)); c.rhs = (float *)calloc(n, sizeof(float));
    if (!c.a || !c.b || !c.rhs) ok = 0;
    for (i = 0; ok && i < n; ++i) c.rhs[i] = (float)(i % 97) * 0.01f;
    for (k = 0; ok && k < rounds; ++k)
        for (f = 0; f < nfig; ++f) {
            double v = f == F_IMAGE || f == F_SSBO ? rate(stencil_step, &st[f == F_SSBO])
                     : f == F_C ? rate(c_step, &c)
                     : f >= F_RB_AB ? rate(ab_step, &ab[f == F_JACOBI_AB]) : rate(sweep_step, &h[f == F_JACOBI]);
            if (v > best[f]) best[f] = v;
        }
    if (ok) {
        printf("%-48s %9s %8s %12s\n", "diffusion sweep figure (best of rounds)", "sweeps/s", "GB/s*", "/ image3D");
        for (f = 0; f < nfig; ++f)
            printf("%-48s %9.1f %8.2f %12.2f\n", names[f], best[f], best[f] * vox * (f <= F_C ? 12.0 : 16.0) / 1e9,
                   best[f] / best[F_IMAGE]);
        printf("* minimum traffic: 12 B/voxel for the stencil (a, rhs read, b written), 16 B/voxel for the\n"
               "  library's sweep (sigma_t, E, phi read, phi written)\n");
    } else {
        printf("the stencil figures failed (see the log)\n");
    }
    for (k = 0; k < 2; ++k) stencil_free(&st[k]);
    for (k = 0; k < 2; ++k)
        if (ab[k].live) ab_free(&ab[k]);
    free(c.a); free(c.b); free(c.rhs);
    hd_destroy(h[0]);
    hd_destroy(h[1]);
}

/* The plain image3D stencil and every sweep variant, round-robin, best of rounds. */
static const char *variant_list; /* --variants=a,b,c: only these (by name) */

static int variant_wanted(int k)
{
    const char *p = variant_list, *name = hd__sweep_variants[k].name;
    size_t n = strlen(name);
    if (!p) return 1;
    for (; (p = strstr(p, name)) != NULL; p += n)
        if ((p == variant_list || p[-1] == ',') && (p[n] == ',' || p[n] == '\0')) return 1;
    return 0;
}

/* The library's parameters for RB / PACKED (hd_k_diffuse.h reads them from the parameter block):
   1 / h^2 per axis (the shader multiplies by 0.6666667 as hd_k_diffuse.h does), the sigma' floor,
   albedo and anisotropy. */
static void variants_params(variants *v, const hd__view *ctx)
{
    v->prm[0] = ctx->kp.grid.x;
    v->prm[1] = ctx->kp.grid.y;
    v->prm[2] = ctx->kp.grid.z;
    v->prm[3] = ctx->kp.grid.w;
    v->med[0] = ctx->kp.medium.y;
    v->med[1] = ctx->kp.medium.z;
    v->med[2] = v->med[3] = 0.0f;
}

/* The phi image variant k writes (r32f, rgba32f x4 or rg32f x2: the same floats in the same order). */
static hd__vk_image *variant_phi(variants *v, int k)
{
    return hd__sweep_variants[k].sv != 14 ? &v->im[2] : hd__sweep_variants[k].pk == 4 ? &v->im[6] : &v->im[10];
}

/* --variants checks every RB / PACKED variant against the library: `nsweeps` red-black sweeps from
   phi = 0 on the library's sigma_t and E (lib_phi: the library's phi after them), the variant's
   phi read back and compared voxel by voxel. A variant that computes other values is no candidate,
   however fast. Returns the number of variants off by more than a few ulps (max rel 1e-5). */
static int variants_check(variants *v, const float *lib_phi, size_t n, int nsweeps)
{
    float *zero = (float *)calloc(n, sizeof(float)), *out = (float *)malloc(n * sizeof(float));
    float *first = (float *)malloc(n * sizeof(float)); /* the first variant's phi (13 RB, r32f) */
    const char *fname = "";
    int k, bad = 0, nfirst = 0;
    double big = 0.0;
    size_t i;
    for (i = 0; i < n; ++i) big = fabs(lib_phi[i]) > big ? fabs(lib_phi[i]) : big;
    printf("check: %d red-black sweeps from phi = 0 on the library's sigma_t and E; max |phi| %.4g\n", nsweeps, big);
    for (k = 0; zero && out && first && k < NVAR; ++k) {
        int sv = hd__sweep_variants[k].sv, s;
        double maxd = 0.0, l2d = 0.0, l2 = 0.0;
        size_t ndiff = 0, nfd = 0;
        if ((sv != 13 && sv != 14 && sv != 17) || (sv == 17 && hd__sweep_variants[k].pk == 2)) continue; /* 17 SGB, PK 2: timing only */
        v->cur = k;
        if (hd__vk_upload_image(v->ctx, variant_phi(v, k), zero) != HD_SUCCESS) { ++bad; continue; }
        for (s = 0; s < nsweeps; ++s)
            if (variant_step(v) != HD_SUCCESS) break;
        if (s < nsweeps || hd__vk_download_image(v->ctx, variant_phi(v, k), out, NULL, 0) != HD_SUCCESS) { ++bad; continue; }
        for (i = 0; i < n; ++i) {
            double d = fabs((double)out[i] - lib_phi[i]);
            if (out[i] != lib_phi[i]) ++ndiff;
            if (nfirst && out[i] != first[i]) ++nfd;
            if (!(d <= maxd)) maxd = d; /* NaN sticks */
            l2d += d * d;
            l2 += (double)lib_phi[i] * lib_phi[i];
        }
        if (!nfirst++) {
            memcpy(first, out, n * sizeof(float));
            fname = hd__sweep_variants[k].name;
        }
        printf("check %-12s vs the library: %8zu of %zu voxels differ, max |diff| / max |phi| %.3g, rel L2 %.3g; vs %s: %zu differ%s\n",
               hd__sweep_variants[k].name, ndiff, n, maxd / big, sqrt(l2d / l2), fname, nfd,
               !(maxd <= 1e-5 * big) ? "  WRONG" : "");
        if (!(maxd <= 1e-5 * big)) ++bad;
    }
    free(zero);
    free(out);
    free(first);
    return bad;
}

/* The library's sigma_t (channel 0), E after one direct pass and phi after nsweeps red-black sweeps
   from 0: the variants' data and the check's reference. */
static hd_result library_state(hd_context h, float *st, float *e, float *phi, size_t n, int nsweeps)
{
    const hd__view *ctx = (&hd__lookup(h)->vw);
    hd__vk_image *sig = &ctx->be->sig;
    float *all = NULL;
    hd_result r = hd__test_direct(h, 1); /* allocates the images first */
    if (r == HD_SUCCESS && !(all = (float *)malloc((size_t)sig->extent[0] * sig->extent[1] * sig->extent[2] * sizeof(float))))
        r = HD_ERROR_OUT_OF_MEMORY;
    if (r == HD_SUCCESS) r = hd__vk_download_image(ctx, sig, all, NULL, 0);
    if (r == HD_SUCCESS) memcpy(st, all, n * sizeof(float));
    if (r == HD_SUCCESS) r = hd__vk_download_image(ctx, &ctx->be->E, e, NULL, 0);
    if (r == HD_SUCCESS) r = hd__test_diffuse(h, nsweeps);
    if (r == HD_SUCCESS) r = hd__vk_download_image(ctx, &ctx->be->phi, phi, NULL, 0);
    free(all);
    return r;
}

/* The device's subgroup properties (17 SGB and 18 SHUF need the basic and shuffle operations and
   SGB a subgroup of at least its block's rows; a smaller one shows as WRONG in the check). */
static void subgroup_properties(const hd__view *ctx)
{
    hd__backend *be = ctx->be;
    PFN_vkGetPhysicalDeviceProperties2 gp2 = (PFN_vkGetPhysicalDeviceProperties2)be->gipa(be->instance, "vkGetPhysicalDeviceProperties2");
    VkPhysicalDeviceSubgroupProperties sg;
    VkPhysicalDeviceProperties2 p2;
    if (!gp2) { printf("subgroups: vkGetPhysicalDeviceProperties2 missing\n"); return; }
    memset(&sg, 0, sizeof sg);
    memset(&p2, 0, sizeof p2);
    sg.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES;
    p2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2;
    p2.pNext = &sg;
    gp2(be->phys, &p2);
    printf("subgroups: size %u, stages 0x%x (compute %d), operations 0x%x (basic %d, vote %d, arithmetic %d, ballot %d, "
           "shuffle %d, shuffle_relative %d, clustered %d, quad %d), quad in all stages %d\n", sg.subgroupSize,
           (unsigned)sg.supportedStages, !!(sg.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT), (unsigned)sg.supportedOperations,
           !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_BASIC_BIT), !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_VOTE_BIT),
           !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_ARITHMETIC_BIT), !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT),
           !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_BIT),
           !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_SHUFFLE_RELATIVE_BIT),
           !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_CLUSTERED_BIT), !!(sg.supportedOperations & VK_SUBGROUP_FEATURE_QUAD_BIT),
           (int)sg.quadOperationsInAllStages);
}

/* The plain image3D stencil, the library's red-black sweep and every sweep variant, round-robin,
   best of rounds; first the check of RB / PACKED against the library. */
/* The median over the rounds of per[r][f] / per[r][ref] (figures of one round run back to back, so
   a burst of load elsewhere hits both: steadier than best / best on a busy machine). */
static double median_ratio(const double *per, int rounds, int nf, int f, int ref)
{
    double q[64], t;
    int n = 0, i, j;
    for (i = 0; i < rounds && n < 64; ++i)
        if (per[(size_t)i * nf + ref] > 0.0) q[n++] = per[(size_t)i * nf + f] / per[(size_t)i * nf + ref];
    for (i = 1; i < n; ++i) /* insertion sort: a few dozen rounds at most */
        for (j = i; j > 0 && q[j - 1] > q[j]; --j) { t = q[j]; q[j] = q[j - 1]; q[j - 1] = t; }
    return n == 0 ? 0.0 : n % 2 ? q[n / 2] : 0.5 * (q[n / 2 - 1] + q[n / 2]);
}

static void variant_figures(const hd_desc *base, const int *g, int rounds)
{
    double best[NVAR + 4], v_, *per = (double *)calloc((size_t)rounds * (NVAR + 4), sizeof(double)); /* per[round][figure] */
    hd_desc d = *base;
    hd_context h;
    stencil st, sb[2]; /* r32f images; float buffers, the buffers as vec4 */
    variants v;
    size_t n = (size_t)g[0] * g[1] * g[2];
    float *lst = (float *)malloc(n * sizeof(float)), *le = (float *)malloc(n * sizeof(float));
    float *lphi = (float *)malloc(n * sizeof(float));
    int k, f, ok;
    const int nsweeps = 8;
    memset(best, 0, sizeof best);
    memset(&st, 0, sizeof st);
    memset(sb, 0, sizeof sb);
    memset(&v, 0, sizeof v);
    d.params.solver = HD_SOLVER_RED_BLACK;
    d.params.anisotropy = 0.3f; /* 1 - albedo g != 1: the check covers sigma' */
    if (hd_create(&d, &h) != HD_SUCCESS) { printf("Vulkan unavailable\n"); return; }
    ok = lst && le && lphi && per;
    subgroup_properties((&hd__lookup(h)->vw));
    if (ok) {
        const hd__view *ctx = (&hd__lookup(h)->vw);
        ok = library_state(h, lst, le, lphi, n, nsweeps) == HD_SUCCESS;
        ok = ok && ctx->gdims[0] == g[0] && ctx->gdims[1] == g[1] && ctx->gdims[2] == g[2] && ctx->sig_channels >= 1;
    }
    ok = ok && stencil_init(&st, (&hd__lookup(h)->vw), g, 0) == HD_SUCCESS;
    ok = ok && stencil_init(&sb[0], (&hd__lookup(h)->vw), g, 1) == HD_SUCCESS;
    ok = ok && stencil_init(&sb[1], (&hd__lookup(h)->vw), g, 2) == HD_SUCCESS;
    ok = ok && variants_init(&v, (&hd__lookup(h)->vw), g, lst, le) == HD_SUCCESS;
    if (ok) {
        variants_params(&v, (&hd__lookup(h)->vw));
        if (variants_check(&v, lphi, n, nsweeps) != 0) printf("check: some variants compute other values (above)\n");
    }
    for (k = 0; ok && k < rounds; ++k)
        for (f = 0; f <= NVAR + 3; ++f) {
            if (f < NVAR && !variant_wanted(f)) continue;
            if (f < NVAR) v.cur = f;
            v_ = f == NVAR ? rate(stencil_step, &st) : f == NVAR + 1 ? rate(sweep_step, &h)
               : f > NVAR + 1 ? rate(stencil_step, &sb[f - NVAR - 2]) : rate(variant_step, &v);
            if (v_ > best[f]) best[f] = v_;
            per[(size_t)k * (NVAR + 4) + f] = v_;
        }
    if (ok) {
        printf("%-40s %9s %10s %10s %11s %11s\n", "sweep variant (bench/hdbench_sweep.comp)", "sweeps/s", "/ image3D", "/ library",
               "median of", "rounds' ratios");
        for (f = 0; f < NVAR + 4; ++f) {
            int o = f < 4 ? NVAR + f : f - 4; /* the stencils and the library first */
            static const char *own[4] = {"plain 7-point stencil, storage image3D", "library red-black sweep (its module)",
                                         "plain stencil, storage buffer (float)", "plain stencil, buffer as vec4 (x-packed)"};
            if (o < NVAR && !variant_wanted(o)) continue;
            printf("%-40s %9.1f %10.2f %10.2f %11.2f %11.2f\n", o < NVAR ? hd__sweep_variants[o].name : own[o - NVAR], best[o],
                   best[o] / best[NVAR], best[o] / best[NVAR + 1], median_ratio(per, rounds, NVAR + 4, o, NVAR),
                   median_ratio(per, rounds, NVAR + 4, o, NVAR + 1));
        }
        printf("(best of %d rounds; the medians are over the rounds of figure / image3D stencil and / library in the same round)\n", rounds);
    } else {
        printf("the variant figures failed (see the log)\n");
    }
    if (st.ctx) stencil_free(&st);
    for (k = 0; k < 2; ++k)
        if (sb[k].ctx) stencil_free(&sb[k]);
    if (v.ctx) variants_free(&v);
    free(lst); free(le); free(lphi); free(per);
    hd_destroy(h);
}

static void method_figures(hd_desc d)
{
    static const hd_method methods[4] = {HD_METHOD_HD, HD_METHOD_CD, HD_METHOD_PT_SS, HD_METHOD_PT_MS};
    hd_light lights[3];
    hd_context h;
    hd_result r;
    int m, L;
    memset(lights, 0, sizeof lights);
    lights[0].direction[0] = 0.3f; lights[0].direction[1] = -1.0f; lights[0].direction[2] = -0.4f;
    lights[1].type = HD_LIGHT_POINT; lights[1].position[0] = 1.0f; lights[1].position[1] = 0.5f; lights[1].position[2] = 0.8f;
    lights[2].direction[0] = -0.8f; lights[2].direction[1] = -0.2f; lights[2].direction[2] = -0.6f;
    printf("%-6s %7s %10s\n", "method", "lights", "Vulkan it/s");
    for (m = 0; m < 4; ++m)
        for (L = 1; L <= 3; L += 2) {
            d.params.method = methods[m];
            d.lights = lights;
            d.light_count = L;
            if ((r = hd_create(&d, &h)) != HD_SUCCESS) { printf("%-6s %7d  create failed: %s\n", hd_method_name(methods[m]), L, hd_result_string(r)); continue; }
            printf("%-6s %7d %10.2f\n", hd_method_name(methods[m]), L, rate(iterate_step, &h));
            fflush(stdout);
            hd_destroy(h);
        }
}

int main(int argc, char **argv)
{
    const char *path = "data/head.nrrd";
    hd_volume_file vol;
    hd_desc d;
    hd_result r;
    hd_logger log;
    int g[3], i, sweeps_only = 0, rounds = 2, nth = 0, only_variants = 0;
    (void)hd__test_prepare; (void)hd__test_direct; (void)hd__test_project; /* hooks this bench does not use */
    (void)hd__test_write_illumination; (void)hd__test_finish;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--sweeps") == 0) sweeps_only = 1;
        else if (strncmp(argv[i], "--variants", 10) == 0 && (argv[i][10] == '\0' || argv[i][10] == '=')) {
            only_variants = 1;
            variant_list = argv[i][10] == '=' ? argv[i] + 11 : NULL;
        }
        else if (strcmp(argv[i], "--ab-zk") == 0 && i + 1 < argc) ab_zk = atoi(argv[++i]) > 0 ? atoi(argv[i]) : 1;
        else if (strcmp(argv[i], "--ab-yk") == 0 && i + 1 < argc) ab_yk = atoi(argv[++i]) > 0 ? atoi(argv[i]) : 1;
        else if (strcmp(argv[i], "--ab") == 0 && i + 1 < argc) {
            if (!ab_load(argv[++i])) { fprintf(stderr, "hdbench_vulkan: cannot read %s\n", argv[i]); return 1; }
        }
        else if (strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) rounds = atoi(argv[++i]);
        else if (nth++ == 0) path = argv[i];
        else budget = atof(argv[i]);
    }
    if (rounds < 1) rounds = 1;
    memset(&log, 0, sizeof log);
    log.func = hd_log_stderr;
    if ((r = hd_volume_load_nrrd(path, &vol, &log)) != HD_SUCCESS) {
        fprintf(stderr, "hdbench_vulkan: %s: %s (run `make data`)\n", path, hd_result_string(r));
        return 1;
    }
    memset(&d, 0, sizeof d);
    d.volume = vol.desc;
    d.logger.func = log_errors;
    d.camera.width = 256; d.camera.height = 256;
    g[0] = vol.desc.dims[0]; g[1] = vol.desc.dims[1]; g[2] = vol.desc.dims[2];
    printf("hdbench_vulkan: %s, %dx%dx%d voxels, image 256x256, %.1f s per figure, %d round%s\n", path, g[0], g[1], g[2],
           budget, rounds, rounds == 1 ? "" : "s");
    if (only_variants) {
        variant_figures(&d, g, rounds);
        hd_volume_free(&vol);
        free(ab_code);
        return 0;
    }
    sweep_figures(&d, g, rounds);
    if (!sweeps_only) method_figures(d);
    hd_volume_free(&vol);
    free(ab_code);
    return 0;
}
