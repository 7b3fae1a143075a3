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
   Usage: hdbench_vulkan [file.nrrd] [seconds per figure, default 2] [--sweeps] [--rounds n] */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hdbench_vulkan_spirv.h" /* generated into the build directory by mk/vulkan.mk */
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
static hd_result iterate_step(void *h) { return hd_iterate(*(hd_context *)h, 1); }

/* ---- the plain stencil on the Vulkan device ------------------------------------------------- */
typedef struct stencil {
    hd__ctx *ctx;
    int ssbo, cur, g[3];
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
    hd__ctx *ctx = s->ctx;
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

static hd_result stencil_init(stencil *s, hd__ctx *ctx, const int *g, int ssbo)
{
    hd__backend *be = ctx->be;
    VkDescriptorSetLayoutBinding b[3];
    VkDescriptorSetLayoutCreateInfo lci;
    VkPushConstantRange pcr;
    VkPipelineLayoutCreateInfo plci;
    VkShaderModuleCreateInfo smci;
    VkComputePipelineCreateInfo cpci;
    VkShaderModule sm;
    VkResult e;
    hd_result r;
    int i;
    memset(s, 0, sizeof *s);
    s->ctx = ctx;
    s->ssbo = ssbo;
    memcpy(s->g, g, sizeof s->g);
    memset(b, 0, sizeof b);
    for (i = 0; i < 3; ++i) {
        b[i].binding = (uint32_t)i;
        b[i].descriptorType = ssbo ? VK_DESCRIPTOR_TYPE_STORAGE_BUFFER : VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
        b[i].descriptorCount = 1;
        b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    memset(&lci, 0, sizeof lci);
    lci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    lci.bindingCount = 3;
    lci.pBindings = b;
    HD__VK_TRY(ctx, be->fn.vkCreateDescriptorSetLayout(be->device, &lci, NULL, &s->set_layout), "vkCreateDescriptorSetLayout");
    memset(&pcr, 0, sizeof pcr);
    pcr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pcr.size = 4 * sizeof(int32_t);
    memset(&plci, 0, sizeof plci);
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &s->set_layout;
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &pcr;
    HD__VK_TRY(ctx, be->fn.vkCreatePipelineLayout(be->device, &plci, NULL, &s->layout), "vkCreatePipelineLayout");
    memset(&smci, 0, sizeof smci);
    smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smci.codeSize = ssbo ? sizeof hd__spv_stencil_ssbo : sizeof hd__spv_stencil_image;
    smci.pCode = ssbo ? hd__spv_stencil_ssbo : hd__spv_stencil_image;
    HD__VK_TRY(ctx, be->fn.vkCreateShaderModule(be->device, &smci, NULL, &sm), "vkCreateShaderModule");
    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = sm;
    cpci.stage.pName = "main";
    cpci.layout = s->layout;
    e = be->fn.vkCreateComputePipelines(be->device, VK_NULL_HANDLE, 1, &cpci, NULL, &s->pipeline);
    be->fn.vkDestroyShaderModule(be->device, sm, NULL);
    if (e < 0) { s->pipeline = VK_NULL_HANDLE; return hd__vk_fail(ctx, e, "vkCreateComputePipelines", __LINE__); }
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
    be->fn.vkCmdDispatch(cb, ((uint32_t)s->g[0] + 63u) / 64u, (uint32_t)s->g[1], (uint32_t)s->g[2]);
    s->cur ^= 1;
    return hd__vk_flush(s->ctx);
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
enum { F_IMAGE, F_SSBO, F_C, F_RB, F_JACOBI, F_COUNT };

static void sweep_figures(const hd_desc *base, const int *g, int rounds)
{
    static const char *names[F_COUNT] = {
        "plain 7-point stencil, Vulkan, storage image3D",
        "plain 7-point stencil, Vulkan, storage buffer",
        "plain 7-point stencil, C, 1 thread",
        "library sweep, red-black (2 half-sweeps)",
        "library sweep, Jacobi (+ copy back)"};
    double best[F_COUNT], vox = (double)g[0] * g[1] * g[2];
    hd_desc d = *base;
    hd_context h[2];
    stencil st[2];
    c_grid c;
    size_t n = (size_t)vox, i;
    int k, f, ok = 1;
    memset(best, 0, sizeof best);
    d.params.solver = HD_SOLVER_RED_BLACK;
    if (hd_create(&d, &h[0]) != HD_SUCCESS) { printf("Vulkan unavailable\n"); return; }
    d.params.solver = HD_SOLVER_JACOBI;
    if (hd_create(&d, &h[1]) != HD_SUCCESS) { hd_destroy(h[0]); printf("Vulkan unavailable\n"); return; }
    printf("device: %s\n", hd__lookup(h[0], NULL)->be->device_name);
    for (k = 0; k < 2; ++k)
        if (stencil_init(&st[k], hd__lookup(h[0], NULL), g, k) != HD_SUCCESS) ok = 0;
    c.g[0] = g[0]; c.g[1] = g[1]; c.g[2] = g[2];
    c.a = (float *)calloc(n, sizeof(float)); c.b = (float *)calloc(n, sizeof(float)); c.rhs = (float *)calloc(n, sizeof(float));
    if (!c.a || !c.b || !c.rhs) ok = 0;
    for (i = 0; ok && i < n; ++i) c.rhs[i] = (float)(i % 97) * 0.01f;
    for (k = 0; ok && k < rounds; ++k)
        for (f = 0; f < F_COUNT; ++f) {
            double v = f == F_IMAGE || f == F_SSBO ? rate(stencil_step, &st[f == F_SSBO])
                     : f == F_C ? rate(c_step, &c) : rate(sweep_step, &h[f == F_JACOBI]);
            if (v > best[f]) best[f] = v;
        }
    if (ok) {
        printf("%-48s %9s %8s %12s\n", "diffusion sweep figure (best of rounds)", "sweeps/s", "GB/s*", "/ image3D");
        for (f = 0; f < F_COUNT; ++f)
            printf("%-48s %9.1f %8.2f %12.2f\n", names[f], best[f], best[f] * vox * (f <= F_C ? 12.0 : 16.0) / 1e9,
                   best[f] / best[F_IMAGE]);
        printf("* minimum traffic: 12 B/voxel for the stencil (a, rhs read, b written), 16 B/voxel for the\n"
               "  library's sweep (sigma_t, E, phi read, phi written)\n");
    } else {
        printf("the stencil figures failed (see the log)\n");
    }
    for (k = 0; k < 2; ++k) stencil_free(&st[k]);
    free(c.a); free(c.b); free(c.rhs);
    hd_destroy(h[0]);
    hd_destroy(h[1]);
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
    int g[3], i, sweeps_only = 0, rounds = 2, nth = 0;
    (void)hd__test_prepare; (void)hd__test_direct; (void)hd__test_project; /* hooks this bench does not use */
    (void)hd__test_write_illumination; (void)hd__test_finish;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--sweeps") == 0) sweeps_only = 1;
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
    sweep_figures(&d, g, rounds);
    if (!sweeps_only) method_figures(d);
    hd_volume_free(&vol);
    return 0;
}
