/* scene_vulkan.c - hybriddiff inside a host's Vulkan scene (examples/scene.c's scene on Vulkan,
   headless): the application's own instance and device, a render pass drawing a ground plane and
   boxes with a depth buffer, a smoke cloud placed by a volume-to-world transform, one camera given
   to both as view and projection matrices (Vulkan's clip space: y down, depth zero to one). A
   second, living volume: smoke rising from the green box (examples/hd_scene_common.h's plume, as
   examples/scene.c's), its voxels replaced in place every frame by hd_update_volume on its own
   context; its light continues from the previous frame's (the warm start), one light iteration
   a frame. Everything is recorded into one command buffer per frame:
     0. hd_vulkan_record_illumination: the cloud's light (E + phi) copied into the application's
        3D image, which the meshes' shader samples: the sun on the post where it stands in the
        cloud's medium comes through the cloud (its shadow darkens the post downward);
     1. the meshes into the application's HDR image (RGBA16F colour, D32_SFLOAT depth);
     2. hd_vulkan_record_depth: the depth image copied into both contexts on the device, so the
        volumes' rays end at the meshes (a post standing in the cloud cuts it, a box in front of it
        hides it);
     3. hd_vulkan_record_render for each volume: a frame, written as linear premultiplied
        RGBA16F into the application's image of it (the library records its barriers: the image
        leaves it in SHADER_READ_ONLY_OPTIMAL);
     4. a second render pass blends them over the meshes, the farther first, with ONE,
        ONE_MINUS_SRC_ALPHA, in linear light;
     5. a third tone-maps and sRGB-encodes into an RGBA8 image, copied to the host for the PNG.
   The library's NDC y points up (row 0 of its image is NDC y = +1), Vulkan's down: the library is
   given the projection with its y row negated, so its rows are the framebuffer's.

   Usage: scene_vulkan [--size WxH] [--frames N] [--out PNG] [--validate] [--check]
   The camera turns by a fixed step per frame, then rests for the last 16 frames; the last frame
   goes to PNG. --validate enables VK_LAYER_KHRONOS_validation (with synchronization validation)
   through the application's messenger and exits 1 on any message. --check (make
   test-scene-vulkan) lets the view rest until the light has converged, then compares the
   library's image with one of the same light rendered without the depth: where the scene shows
   sky or the ground (behind the whole cloud) the two match; where the box in front covers cloud,
   the image is empty; where the post stands in the cloud, less of it is in front; and the plume's
   last frame is finite, covers part of the image and not most of it. Without a
   Vulkan device, or with --validate and no layer, those runs print SKIPPED and exit 0 (1 under
   HD_CONFORMANCE_REQUIRE=1).
   Shaders: examples/scene_vulkan.glsl, compiled by mk/scene.mk. C99, Vulkan 1.1. */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#include <vulkan/vulkan.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hd_png.h"
#include "hd_scene_common.h"
#include "scene_vulkan_spv.h" /* scene_spv_mesh_vs, _mesh_fs, _quad_vs, _blend_fs, _tonemap_fs */

#define CLOUD_N 96

/* A right-handed perspective in Vulkan's clip space: y down, depth 0 at the near plane, 1 at the far. */
static mat4 mat4_perspective_vk(float fov_y_degrees, float aspect, float znear, float zfar)
{
    mat4 r;
    float f = 1.0f / tanf(fov_y_degrees * PI / 360.0f);
    memset(&r, 0, sizeof r);
    r.m[0] = f / aspect;
    r.m[5] = -f;
    r.m[10] = zfar / (znear - zfar);
    r.m[11] = -1.0f;
    r.m[14] = znear * zfar / (znear - zfar);
    return r;
}

/* The inverse by Gauss-Jordan elimination with partial pivoting (the check's unprojection). */
static mat4 mat4_inverse(mat4 a)
{
    double m[4][8];
    mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) m[i][j] = a.m[j * 4 + i], m[i][j + 4] = i == j;
    for (int c = 0; c < 4; ++c) {
        int p = c;
        for (int i = c + 1; i < 4; ++i)
            if (fabs(m[i][c]) > fabs(m[p][c])) p = i;
        for (int j = 0; j < 8; ++j) {
            double t = m[c][j];
            m[c][j] = m[p][j], m[p][j] = t;
        }
        for (int j = 7; j >= c; --j) m[c][j] /= m[c][c];
        for (int i = 0; i < 4; ++i)
            if (i != c)
                for (int j = 7; j >= c; --j) m[i][j] -= m[i][c] * m[c][j];
    }
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) r.m[j * 4 + i] = (float)m[i][j + 4];
    return r;
}

static void mat4_apply(mat4 a, const float v[4], float out[4])
{
    for (int row = 0; row < 4; ++row)
        out[row] = a.m[row] * v[0] + a.m[4 + row] * v[1] + a.m[8 + row] * v[2] + a.m[12 + row] * v[3];
}

/* ---- the application's Vulkan objects ------------------------------------------------------ */
typedef struct image { VkImage image; VkImageView view; VkDeviceMemory memory; } image;
typedef struct buffer { VkBuffer buffer; VkDeviceMemory memory; void *map; } buffer;
typedef struct mesh { mat4 model; float albedo[3]; } mesh;

enum { MESHES = 5, FRONT_BOX = 1, POST = 3 };

typedef struct app {
    int w, h;
    VkInstance inst;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice phys;
    VkDevice dev;
    VkQueue queue;
    uint32_t family;
    VkPhysicalDeviceMemoryProperties mem;
    VkCommandPool pool;
    VkCommandBuffer cb;
    image hdr, depth, cloud, ldr;  /* RGBA16F scene, D32 depth, the library's RGBA16F image, RGBA8 */
    image smoke_img;               /* the plume's RGBA16F image */
    image light;                   /* the cloud's light, R32_SFLOAT 3D (hd_vulkan_record_illumination) */
    int light_dims[3], light_filled;
    buffer vbo, readback;
    VkSampler sampler, light_sampler;
    VkRenderPass pass_mesh, pass_blend, pass_tonemap;
    VkFramebuffer fb_mesh, fb_blend, fb_tonemap;
    VkDescriptorSetLayout set_layout;
    VkDescriptorPool dpool;
    VkDescriptorSet set_cloud, set_hdr, set_light, set_smoke;
    VkPipelineLayout layout_mesh, layout_quad;
    VkPipeline pipe_mesh, pipe_blend, pipe_tonemap;
    mesh meshes[MESHES];
    hd_context hd, smoke;
    float *smoke_vox;                /* the plume's voxels, SMOKE_N^3 */
    int frame;                       /* frames drawn: the plume's clock (1/30 s each) */
    float cloud_at[3], smoke_at[3];  /* the volumes' centres in the world (the blending order) */
    mat4 view, proj; /* the last frame's camera (Vulkan's clip space) */
    mat4 place;      /* the cloud's volume-to-world transform */
} app;

static const float sun_dir[3] = {-0.45f, -0.8f, -0.4f}; /* the direction sunlight travels in */
static const float sun_rgb[3] = {9.0f, 8.4f, 7.5f};    /* linear radiance units, as the library's */
static const float sky_rgb[4] = {0.35f, 0.45f, 0.6f, 1.0f};

static int validation_messages;
static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)severity; (void)type; (void)user;
    ++validation_messages;
    fprintf(stderr, "scene_vulkan: validation: %s\n", data->pMessage);
    return VK_FALSE;
}

static void vk_check(VkResult e, const char *what)
{
    if (e != VK_SUCCESS) {
        fprintf(stderr, "scene_vulkan: %s failed (VkResult %d)\n", what, (int)e);
        exit(1);
    }
}

static void hd_check(hd_result r, const char *what)
{
    if (r != HD_SUCCESS) {
        fprintf(stderr, "scene_vulkan: %s: %s\n", what, hd_result_string(r));
        exit(1);
    }
}

static uint32_t memory_type(const app *a, uint32_t bits, VkMemoryPropertyFlags want)
{
    for (uint32_t i = 0; i < a->mem.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (a->mem.memoryTypes[i].propertyFlags & want) == want) return i;
    fprintf(stderr, "scene_vulkan: no memory type with properties 0x%x\n", (unsigned)want);
    exit(1);
}

/* A 2D or 3D image of extent w x h x d in device-local memory, with a view of its whole. */
static image make_image_of(const app *a, VkImageType type, VkFormat format, int w, int h, int d, VkImageUsageFlags usage,
                           VkImageAspectFlags aspect)
{
    image im;
    VkImageCreateInfo ici;
    VkImageViewCreateInfo vci;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo mai;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ici.imageType = type;
    ici.format = format;
    ici.extent.width = (uint32_t)w, ici.extent.height = (uint32_t)h, ici.extent.depth = (uint32_t)d;
    ici.mipLevels = ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    vk_check(vkCreateImage(a->dev, &ici, NULL, &im.image), "vkCreateImage");
    vkGetImageMemoryRequirements(a->dev, im.image, &req);
    memset(&mai, 0, sizeof mai);
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(a, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    vk_check(vkAllocateMemory(a->dev, &mai, NULL, &im.memory), "vkAllocateMemory");
    vk_check(vkBindImageMemory(a->dev, im.image, im.memory, 0), "vkBindImageMemory");
    memset(&vci, 0, sizeof vci);
    vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vci.image = im.image;
    vci.viewType = type == VK_IMAGE_TYPE_3D ? VK_IMAGE_VIEW_TYPE_3D : VK_IMAGE_VIEW_TYPE_2D;
    vci.format = format;
    vci.subresourceRange.aspectMask = aspect;
    vci.subresourceRange.levelCount = vci.subresourceRange.layerCount = 1;
    vk_check(vkCreateImageView(a->dev, &vci, NULL, &im.view), "vkCreateImageView");
    return im;
}

/* A frame-sized 2D image. */
static image make_image(const app *a, VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect)
{
    return make_image_of(a, VK_IMAGE_TYPE_2D, format, a->w, a->h, 1, usage, aspect);
}

/* The cloud's light: a 3D R32_SFLOAT image of the illumination grid's size, sampled by the meshes. */
static image make_light_image(const app *a)
{
    return make_image_of(a, VK_IMAGE_TYPE_3D, VK_FORMAT_R32_SFLOAT, a->light_dims[0], a->light_dims[1], a->light_dims[2],
                         VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
}

static buffer make_buffer(const app *a, VkDeviceSize bytes, VkBufferUsageFlags usage)
{
    buffer b;
    VkBufferCreateInfo bci;
    VkMemoryRequirements req;
    VkMemoryAllocateInfo mai;
    memset(&bci, 0, sizeof bci);
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = bytes;
    bci.usage = usage;
    vk_check(vkCreateBuffer(a->dev, &bci, NULL, &b.buffer), "vkCreateBuffer");
    vkGetBufferMemoryRequirements(a->dev, b.buffer, &req);
    memset(&mai, 0, sizeof mai);
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req.size;
    mai.memoryTypeIndex = memory_type(a, req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    vk_check(vkAllocateMemory(a->dev, &mai, NULL, &b.memory), "vkAllocateMemory");
    vk_check(vkBindBufferMemory(a->dev, b.buffer, b.memory, 0), "vkBindBufferMemory");
    vk_check(vkMapMemory(a->dev, b.memory, 0, VK_WHOLE_SIZE, 0, &b.map), "vkMapMemory");
    return b;
}

static void free_image(const app *a, image *im)
{
    vkDestroyImageView(a->dev, im->view, NULL);
    vkDestroyImage(a->dev, im->image, NULL);
    vkFreeMemory(a->dev, im->memory, NULL);
}

static void free_buffer(const app *a, buffer *b)
{
    vkDestroyBuffer(a->dev, b->buffer, NULL);
    vkFreeMemory(a->dev, b->memory, NULL);
}

/* The instance (with the validation layer and our messenger when asked), the first physical
   device with a graphics and compute queue, a device with that queue. */
static void make_device(app *a, int validate)
{
    const char *layer = "VK_LAYER_KHRONOS_validation", *ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT vf;
    VkApplicationInfo ai;
    VkDebugUtilsMessengerCreateInfoEXT mci;
    VkInstanceCreateInfo ici;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    VkPhysicalDevice devs[8];
    VkQueueFamilyProperties fams[16];
    uint32_t n = 8, nf = 16;
    float prio = 1.0f;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    ai.pApplicationName = "hybriddiff scene_vulkan";
    ai.apiVersion = VK_API_VERSION_1_1;
    memset(&mci, 0, sizeof mci);
    mci.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mci.pfnUserCallback = on_message;
    memset(&vf, 0, sizeof vf);
    vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = &sync;
    vf.pNext = &mci;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &ai;
    if (validate) {
        ici.enabledLayerCount = 1;
        ici.ppEnabledLayerNames = &layer;
        ici.enabledExtensionCount = 1;
        ici.ppEnabledExtensionNames = &ext;
        ici.pNext = &vf;
    }
    vk_check(vkCreateInstance(&ici, NULL, &a->inst), validate ? "vkCreateInstance with VK_LAYER_KHRONOS_validation" : "vkCreateInstance");
    if (validate) {
        PFN_vkCreateDebugUtilsMessengerEXT create =
            (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(a->inst, "vkCreateDebugUtilsMessengerEXT");
        vk_check(create ? create(a->inst, &mci, NULL, &a->messenger) : VK_ERROR_EXTENSION_NOT_PRESENT, "vkCreateDebugUtilsMessengerEXT");
    }
    if (vkEnumeratePhysicalDevices(a->inst, &n, devs) < 0 || n == 0) { fprintf(stderr, "scene_vulkan: no Vulkan device\n"); exit(1); }
    a->phys = VK_NULL_HANDLE;
    for (uint32_t d = 0; d < n && !a->phys; ++d) {
        nf = 16;
        vkGetPhysicalDeviceQueueFamilyProperties(devs[d], &nf, fams);
        for (uint32_t f = 0; f < nf; ++f)
            if ((fams[f].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) == (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) {
                a->phys = devs[d], a->family = f;
                break;
            }
    }
    if (!a->phys) { fprintf(stderr, "scene_vulkan: no device with a graphics and compute queue\n"); exit(1); }
    vkGetPhysicalDeviceMemoryProperties(a->phys, &a->mem);
    memset(&qci, 0, sizeof qci);
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = a->family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    memset(&dci, 0, sizeof dci);
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    vk_check(vkCreateDevice(a->phys, &dci, NULL, &a->dev), "vkCreateDevice");
    vkGetDeviceQueue(a->dev, a->family, 0, &a->queue);
}

/* A render pass of one colour attachment (and a depth one): `load` keeps the colour (else it is
   cleared from UNDEFINED), `final_colour` is its layout after; the external dependencies order it
   after the attachments' earlier writes and before `after_stage` reads them. */
static VkRenderPass make_pass(const app *a, VkFormat colour, int load, VkImageLayout final_colour, int depth,
                              VkPipelineStageFlags after_stage, VkAccessFlags after_access)
{
    VkAttachmentDescription at[2];
    VkAttachmentReference cref = {0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkAttachmentReference dref = {1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub;
    VkSubpassDependency dep[2];
    VkRenderPassCreateInfo rpci;
    VkRenderPass rp;
    const VkPipelineStageFlags att = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                                     VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    const VkAccessFlags att_rw = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                                 VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    memset(at, 0, sizeof at);
    at[0].format = colour;
    at[0].samples = VK_SAMPLE_COUNT_1_BIT;
    at[0].loadOp = load ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR;
    at[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    at[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    at[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    at[0].initialLayout = load ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED;
    at[0].finalLayout = final_colour;
    at[1] = at[0];
    at[1].format = VK_FORMAT_D32_SFLOAT;
    at[1].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    at[1].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    at[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL; /* hd_vulkan_record_depth copies it from there */
    memset(&sub, 0, sizeof sub);
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &cref;
    sub.pDepthStencilAttachment = depth ? &dref : NULL;
    memset(dep, 0, sizeof dep);
    dep[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    dep[0].dstSubpass = 0;
    dep[0].srcStageMask = att;
    dep[0].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    dep[0].dstStageMask = att;
    dep[0].dstAccessMask = att_rw;
    dep[1].srcSubpass = 0;
    dep[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    dep[1].srcStageMask = att;
    dep[1].srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    dep[1].dstStageMask = after_stage;
    dep[1].dstAccessMask = after_access;
    memset(&rpci, 0, sizeof rpci);
    rpci.sType = VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO;
    rpci.attachmentCount = depth ? 2 : 1;
    rpci.pAttachments = at;
    rpci.subpassCount = 1;
    rpci.pSubpasses = &sub;
    rpci.dependencyCount = 2;
    rpci.pDependencies = dep;
    vk_check(vkCreateRenderPass(a->dev, &rpci, NULL, &rp), "vkCreateRenderPass");
    return rp;
}

static VkFramebuffer make_framebuffer(const app *a, VkRenderPass rp, VkImageView colour, VkImageView depth)
{
    VkImageView views[2] = {colour, depth};
    VkFramebufferCreateInfo fci;
    VkFramebuffer fb;
    memset(&fci, 0, sizeof fci);
    fci.sType = VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO;
    fci.renderPass = rp;
    fci.attachmentCount = depth ? 2 : 1;
    fci.pAttachments = views;
    fci.width = (uint32_t)a->w, fci.height = (uint32_t)a->h;
    fci.layers = 1;
    vk_check(vkCreateFramebuffer(a->dev, &fci, NULL, &fb), "vkCreateFramebuffer");
    return fb;
}

static VkShaderModule make_module(const app *a, const uint32_t *code, size_t bytes)
{
    VkShaderModuleCreateInfo smci;
    VkShaderModule m;
    memset(&smci, 0, sizeof smci);
    smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smci.codeSize = bytes;
    smci.pCode = code;
    vk_check(vkCreateShaderModule(a->dev, &smci, NULL, &m), "vkCreateShaderModule");
    return m;
}

/* A graphics pipeline: the mesh one (vertex input, depth test, the sun as specialization
   constants) or a full-screen one (blend: ONE, ONE_MINUS_SRC_ALPHA). */
static VkPipeline make_pipeline(const app *a, VkRenderPass rp, VkPipelineLayout layout, int is_mesh, int blend,
                                const uint32_t *vs, size_t vs_bytes, const uint32_t *fs, size_t fs_bytes)
{
    VkPipelineShaderStageCreateInfo st[2];
    VkVertexInputBindingDescription vb = {0, 6 * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription va[2] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0}, {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)}};
    VkPipelineVertexInputStateCreateInfo vi;
    VkPipelineInputAssemblyStateCreateInfo ia;
    VkViewport vp = {0.0f, 0.0f, (float)a->w, (float)a->h, 0.0f, 1.0f};
    VkRect2D sc = {{0, 0}, {(uint32_t)a->w, (uint32_t)a->h}};
    VkPipelineViewportStateCreateInfo vps;
    VkPipelineRasterizationStateCreateInfo rs;
    VkPipelineMultisampleStateCreateInfo ms;
    VkPipelineDepthStencilStateCreateInfo ds;
    VkPipelineColorBlendAttachmentState cba;
    VkPipelineColorBlendStateCreateInfo cb;
    VkGraphicsPipelineCreateInfo gpci;
    VkSpecializationMapEntry se[18];
    VkSpecializationInfo si;
    float sun[18];
    mat4 to_box = mat4_inverse(a->place);
    VkPipeline p;
    for (int i = 0; i < 18; ++i) { /* the sun; the world-to-box transform's first three rows */
        sun[i] = i < 3 ? sun_dir[i] : i < 6 ? sun_rgb[i - 3] : to_box.m[((i - 6) % 4) * 4 + (i - 6) / 4];
        se[i].constantID = (uint32_t)i, se[i].offset = (uint32_t)(i * sizeof(float)), se[i].size = sizeof(float);
    }
    si.mapEntryCount = 18, si.pMapEntries = se, si.dataSize = sizeof sun, si.pData = sun;
    memset(st, 0, sizeof st);
    for (int i = 0; i < 2; ++i) {
        st[i].sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        st[i].stage = i ? VK_SHADER_STAGE_FRAGMENT_BIT : VK_SHADER_STAGE_VERTEX_BIT;
        st[i].module = i ? make_module(a, fs, fs_bytes) : make_module(a, vs, vs_bytes);
        st[i].pName = "main";
    }
    if (is_mesh) st[1].pSpecializationInfo = &si;
    memset(&vi, 0, sizeof vi);
    vi.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    if (is_mesh) vi.vertexBindingDescriptionCount = 1, vi.pVertexBindingDescriptions = &vb, vi.vertexAttributeDescriptionCount = 2,
                 vi.pVertexAttributeDescriptions = va;
    memset(&ia, 0, sizeof ia);
    ia.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    memset(&vps, 0, sizeof vps);
    vps.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    vps.viewportCount = 1, vps.pViewports = &vp, vps.scissorCount = 1, vps.pScissors = &sc;
    memset(&rs, 0, sizeof rs);
    rs.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE;
    rs.lineWidth = 1.0f;
    memset(&ms, 0, sizeof ms);
    ms.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    memset(&ds, 0, sizeof ds);
    ds.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    ds.depthTestEnable = ds.depthWriteEnable = is_mesh ? VK_TRUE : VK_FALSE;
    ds.depthCompareOp = VK_COMPARE_OP_LESS;
    memset(&cba, 0, sizeof cba);
    cba.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    if (blend) { /* premultiplied alpha: dst = src + (1 - src.a) dst, colour and alpha */
        cba.blendEnable = VK_TRUE;
        cba.srcColorBlendFactor = cba.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        cba.dstColorBlendFactor = cba.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
        cba.colorBlendOp = cba.alphaBlendOp = VK_BLEND_OP_ADD;
    }
    memset(&cb, 0, sizeof cb);
    cb.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    cb.attachmentCount = 1, cb.pAttachments = &cba;
    memset(&gpci, 0, sizeof gpci);
    gpci.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    gpci.stageCount = 2, gpci.pStages = st;
    gpci.pVertexInputState = &vi;
    gpci.pInputAssemblyState = &ia;
    gpci.pViewportState = &vps;
    gpci.pRasterizationState = &rs;
    gpci.pMultisampleState = &ms;
    gpci.pDepthStencilState = &ds;
    gpci.pColorBlendState = &cb;
    gpci.layout = layout;
    gpci.renderPass = rp;
    vk_check(vkCreateGraphicsPipelines(a->dev, VK_NULL_HANDLE, 1, &gpci, NULL, &p), "vkCreateGraphicsPipelines");
    vkDestroyShaderModule(a->dev, st[0].module, NULL);
    vkDestroyShaderModule(a->dev, st[1].module, NULL);
    return p;
}

static VkDescriptorSet make_set(const app *a, VkSampler sampler, VkImageView view)
{
    VkDescriptorSetAllocateInfo ai;
    VkDescriptorImageInfo ii;
    VkWriteDescriptorSet w;
    VkDescriptorSet s;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = a->dpool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &a->set_layout;
    vk_check(vkAllocateDescriptorSets(a->dev, &ai, &s), "vkAllocateDescriptorSets");
    ii.sampler = sampler, ii.imageView = view, ii.imageLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    memset(&w, 0, sizeof w);
    w.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
    w.dstSet = s;
    w.descriptorCount = 1;
    w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    w.pImageInfo = &ii;
    vkUpdateDescriptorSets(a->dev, 1, &w, 0, NULL);
    return s;
}

/* Everything the frames draw with: images, passes, framebuffers, pipelines, sets, the cube. */
static void make_scene_objects(app *a)
{
    VkSamplerCreateInfo sci;
    VkDescriptorSetLayoutBinding b;
    VkDescriptorSetLayoutCreateInfo dslci;
    VkDescriptorPoolSize ps = {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 4};
    VkDescriptorPoolCreateInfo dpci;
    VkPushConstantRange pcr = {VK_SHADER_STAGE_VERTEX_BIT, 0, 32 * sizeof(float)}; /* 128: every device's minimum */
    VkPipelineLayoutCreateInfo plci;
    VkCommandPoolCreateInfo cpci;
    VkCommandBufferAllocateInfo cbai;
    const VkImageUsageFlags att = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
    a->hdr = make_image(a, VK_FORMAT_R16G16B16A16_SFLOAT, att | VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
    a->depth = make_image(a, VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                          VK_IMAGE_ASPECT_DEPTH_BIT);
    /* the library's output: written by a transfer (hd_vulkan_record_render), sampled by the blend */
    a->cloud = make_image(a, VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                          VK_IMAGE_ASPECT_COLOR_BIT);
    a->smoke_img = make_image(a, VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                              VK_IMAGE_ASPECT_COLOR_BIT);
    a->ldr = make_image(a, VK_FORMAT_R8G8B8A8_UNORM, att | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
    a->readback = make_buffer(a, (VkDeviceSize)a->w * a->h * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    a->vbo = make_buffer(a, 36 * 6 * sizeof(float), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    cube_vertices((float *)a->vbo.map);

    /* the meshes' pass leaves the HDR colour for the blend's pass and the depth for the library's
       copy (ALL_COMMANDS: hd_vulkan_record_depth's barrier waits on it too); the blend's leaves the
       colour for the tone map's fragment shader; the tone map's for the copy to the host */
    a->pass_mesh = make_pass(a, VK_FORMAT_R16G16B16A16_SFLOAT, 0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, 1,
                             VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    a->pass_blend = make_pass(a, VK_FORMAT_R16G16B16A16_SFLOAT, 1, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0,
                              VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    a->pass_tonemap = make_pass(a, VK_FORMAT_R8G8B8A8_UNORM, 0, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, 0, VK_PIPELINE_STAGE_TRANSFER_BIT,
                                VK_ACCESS_TRANSFER_READ_BIT);
    a->fb_mesh = make_framebuffer(a, a->pass_mesh, a->hdr.view, a->depth.view);
    a->fb_blend = make_framebuffer(a, a->pass_blend, a->hdr.view, VK_NULL_HANDLE);
    a->fb_tonemap = make_framebuffer(a, a->pass_tonemap, a->ldr.view, VK_NULL_HANDLE);

    memset(&sci, 0, sizeof sci);
    sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
    sci.magFilter = sci.minFilter = VK_FILTER_NEAREST;
    sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    vk_check(vkCreateSampler(a->dev, &sci, NULL, &a->sampler), "vkCreateSampler");
    memset(&b, 0, sizeof b);
    b.binding = 0;
    b.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
    b.descriptorCount = 1;
    b.stageFlags = VK_SHADER_STAGE_FRAGMENT_BIT;
    memset(&dslci, 0, sizeof dslci);
    dslci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    dslci.bindingCount = 1;
    dslci.pBindings = &b;
    vk_check(vkCreateDescriptorSetLayout(a->dev, &dslci, NULL, &a->set_layout), "vkCreateDescriptorSetLayout");
    memset(&dpci, 0, sizeof dpci);
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = 4;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &ps;
    vk_check(vkCreateDescriptorPool(a->dev, &dpci, NULL, &a->dpool), "vkCreateDescriptorPool");
    a->set_cloud = make_set(a, a->sampler, a->cloud.view);
    a->set_smoke = make_set(a, a->sampler, a->smoke_img.view);
    a->set_hdr = make_set(a, a->sampler, a->hdr.view);

    memset(&plci, 0, sizeof plci);
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &a->set_layout; /* the cloud's light */
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &pcr;
    vk_check(vkCreatePipelineLayout(a->dev, &plci, NULL, &a->layout_mesh), "vkCreatePipelineLayout");
    memset(&plci, 0, sizeof plci);
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = &a->set_layout;
    vk_check(vkCreatePipelineLayout(a->dev, &plci, NULL, &a->layout_quad), "vkCreatePipelineLayout");
    a->pipe_mesh = make_pipeline(a, a->pass_mesh, a->layout_mesh, 1, 0, scene_spv_mesh_vs, sizeof scene_spv_mesh_vs, scene_spv_mesh_fs,
                                 sizeof scene_spv_mesh_fs);
    a->pipe_blend = make_pipeline(a, a->pass_blend, a->layout_quad, 0, 1, scene_spv_quad_vs, sizeof scene_spv_quad_vs, scene_spv_blend_fs,
                                  sizeof scene_spv_blend_fs);
    a->pipe_tonemap = make_pipeline(a, a->pass_tonemap, a->layout_quad, 0, 0, scene_spv_quad_vs, sizeof scene_spv_quad_vs,
                                    scene_spv_tonemap_fs, sizeof scene_spv_tonemap_fs);

    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpci.queueFamilyIndex = a->family;
    vk_check(vkCreateCommandPool(a->dev, &cpci, NULL, &a->pool), "vkCreateCommandPool");
    memset(&cbai, 0, sizeof cbai);
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = a->pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    vk_check(vkAllocateCommandBuffers(a->dev, &cbai, &a->cb), "vkAllocateCommandBuffers");
}

static void begin_pass(const app *a, VkRenderPass rp, VkFramebuffer fb, int clears)
{
    VkClearValue cv[2];
    VkRenderPassBeginInfo rpbi;
    memcpy(cv[0].color.float32, sky_rgb, sizeof sky_rgb);
    cv[1].depthStencil.depth = 1.0f, cv[1].depthStencil.stencil = 0;
    memset(&rpbi, 0, sizeof rpbi);
    rpbi.sType = VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO;
    rpbi.renderPass = rp;
    rpbi.framebuffer = fb;
    rpbi.renderArea.extent.width = (uint32_t)a->w, rpbi.renderArea.extent.height = (uint32_t)a->h;
    rpbi.clearValueCount = (uint32_t)clears;
    rpbi.pClearValues = cv;
    vkCmdBeginRenderPass(a->cb, &rpbi, VK_SUBPASS_CONTENTS_INLINE);
}

/* The library's camera: the same view, and the projection with its y row negated (the library's
   NDC y points up, row 0 at +1; Vulkan's points down), depth zero to one. */
static hd_camera library_camera(const app *a)
{
    hd_camera cam = HD_CAMERA_INIT;
    memcpy(cam.view, a->view.m, sizeof cam.view);
    memcpy(cam.projection, a->proj.m, sizeof cam.projection);
    for (int c = 0; c < 4; ++c) cam.projection[c * 4 + 1] = -cam.projection[c * 4 + 1];
    cam.width = a->w, cam.height = a->h;
    cam.depth_range = HD_DEPTH_ZERO_TO_ONE;
    return cam;
}

/* One frame in one command buffer, submitted and waited for (the library's rule before its next
   call); with `read` the tone-mapped image is copied into the readback buffer. `with_depth` 0
   draws the cloud without the scene's depth (the check's reference). */
static void draw_frame(app *a, float yaw, float pitch, float dist, int read, int with_depth)
{
    float eye[3] = {dist * cosf(pitch) * sinf(yaw), 1.0f + dist * sinf(pitch), dist * cosf(pitch) * cosf(yaw)};
    const float at[3] = {0.0f, 1.2f, 0.0f}, up[3] = {0.0f, 1.0f, 0.0f};
    VkCommandBufferBeginInfo bi;
    VkMemoryBarrier mb;
    VkSubmitInfo si;
    VkDeviceSize zero = 0;
    hd_camera cam;
    hd_vulkan_depth dep = HD_VULKAN_DEPTH_INIT;
    hd_vulkan_target target = HD_VULKAN_TARGET_INIT;
    hd_vulkan_volume_target light = HD_VULKAN_VOLUME_TARGET_INIT;
    hd_output out = HD_OUTPUT_INIT;
    mat4 vp;
    a->view = mat4_look_at(eye, at, up);
    a->proj = mat4_perspective_vk(45.0f, (float)a->w / (float)a->h, 0.1f, 100.0f);
    vp = mat4_mul(a->proj, a->view);
    cam = library_camera(a);
    hd_check(hd_set_camera(a->hd, &cam), "hd_set_camera");
    hd_check(hd_set_camera(a->smoke, &cam), "hd_set_camera (plume)");
    { /* the plume's next step: new voxels in place; E and phi carry over as the warm start */
        hd_volume_update u = HD_VOLUME_UPDATE_INIT;
        make_smoke(a->smoke_vox, SMOKE_N, (float)a->frame++ / 30.0f);
        u.type = HD_VOXEL_F32;
        u.dims[0] = u.dims[1] = u.dims[2] = SMOKE_N;
        u.data = a->smoke_vox;
        hd_check(hd_update_volume(a->smoke, &u), "hd_update_volume");
    }

    vk_check(vkResetCommandBuffer(a->cb, 0), "vkResetCommandBuffer");
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vk_check(vkBeginCommandBuffer(a->cb, &bi), "vkBeginCommandBuffer");
    /* the last frame's reads of the images before this frame's writes */
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = mb.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    vkCmdPipelineBarrier(a->cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &mb, 0, NULL, 0, NULL);

    /* 0. the cloud's light as it is now (the frame's iteration below refines it for the next
       frame) into our 3D image, for the meshes inside the cloud */
    light.image = (uint64_t)a->light.image;
    light.format = VK_FORMAT_R32_SFLOAT;
    light.layout = a->light_filled ? VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_UNDEFINED;
    light.final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    light.width = a->light_dims[0], light.height = a->light_dims[1], light.depth = a->light_dims[2];
    hd_check(hd_vulkan_record_illumination(a->hd, a->cb, 0, &light), "hd_vulkan_record_illumination");
    a->light_filled = 1;

    /* 1. the meshes with the depth buffer */
    begin_pass(a, a->pass_mesh, a->fb_mesh, 2);
    vkCmdBindPipeline(a->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, a->pipe_mesh);
    vkCmdBindDescriptorSets(a->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, a->layout_mesh, 0, 1, &a->set_light, 0, NULL);
    vkCmdBindVertexBuffers(a->cb, 0, 1, &a->vbo.buffer, &zero);
    for (int i = 0; i < MESHES; ++i) {
        float pc[32];
        mat4 mvp = mat4_mul(vp, a->meshes[i].model);
        memcpy(pc, mvp.m, sizeof mvp.m);
        memcpy(pc + 16, a->meshes[i].model.m, sizeof a->meshes[i].model.m);
        for (int c = 0; c < 3; ++c) pc[16 + c * 4 + 3] = a->meshes[i].albedo[c];
        vkCmdPushConstants(a->cb, a->layout_mesh, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof pc, pc);
        vkCmdDraw(a->cb, 36, 1, 0, 0);
    }
    vkCmdEndRenderPass(a->cb);

    /* 2. the depth to the library, on the device (it records its own barriers) */
    dep.image = (uint64_t)a->depth.image;
    dep.format = VK_FORMAT_D32_SFLOAT;
    dep.layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    if (with_depth) hd_check(hd_vulkan_record_depth(a->hd, a->cb, &dep), "hd_vulkan_record_depth");
    hd_check(hd_vulkan_record_depth(a->smoke, a->cb, &dep), "hd_vulkan_record_depth (plume)");

    /* 3. a frame, linear premultiplied RGBA16F into our image, left for sampling */
    target.image = (uint64_t)a->cloud.image;
    target.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    target.layout = VK_IMAGE_LAYOUT_UNDEFINED; /* written whole */
    target.final_layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    target.width = a->w, target.height = a->h;
    out.format = HD_OUTPUT_LINEAR_F16;
    hd_check(hd_vulkan_record_render(a->hd, a->cb, &target, &out), "hd_vulkan_record_render");
    target.image = (uint64_t)a->smoke_img.image; /* the plume's frame: a light iteration while its light moves */
    hd_check(hd_vulkan_record_render(a->smoke, a->cb, &target, &out), "hd_vulkan_record_render (plume)");

    /* 4. composited over the meshes: premultiplied alpha, in linear light, the farther volume
       first (they do not overlap in space, so each is wholly in front of or behind the other) */
    begin_pass(a, a->pass_blend, a->fb_blend, 0);
    vkCmdBindPipeline(a->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, a->pipe_blend);
    {
        int smoke_first = volume_farther(eye, a->smoke_at, a->cloud_at);
        for (int k = 0; k < 2; ++k) {
            const VkDescriptorSet *set = (k == 0) == smoke_first ? &a->set_smoke : &a->set_cloud;
            vkCmdBindDescriptorSets(a->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, a->layout_quad, 0, 1, set, 0, NULL);
            vkCmdDraw(a->cb, 3, 1, 0, 0);
        }
    }
    vkCmdEndRenderPass(a->cb);

    /* 5. tone map into RGBA8 */
    begin_pass(a, a->pass_tonemap, a->fb_tonemap, 1);
    vkCmdBindPipeline(a->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, a->pipe_tonemap);
    vkCmdBindDescriptorSets(a->cb, VK_PIPELINE_BIND_POINT_GRAPHICS, a->layout_quad, 0, 1, &a->set_hdr, 0, NULL);
    vkCmdDraw(a->cb, 3, 1, 0, 0);
    vkCmdEndRenderPass(a->cb);
    if (read) {
        VkBufferImageCopy reg;
        memset(&reg, 0, sizeof reg);
        reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        reg.imageSubresource.layerCount = 1;
        reg.imageExtent.width = (uint32_t)a->w, reg.imageExtent.height = (uint32_t)a->h, reg.imageExtent.depth = 1;
        vkCmdCopyImageToBuffer(a->cb, a->ldr.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, a->readback.buffer, 1, &reg);
        mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
        vkCmdPipelineBarrier(a->cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
    }
    vk_check(vkEndCommandBuffer(a->cb), "vkEndCommandBuffer");
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &a->cb;
    vk_check(vkQueueSubmit(a->queue, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
    vk_check(vkQueueWaitIdle(a->queue), "vkQueueWaitIdle");
}

/* Which mesh the scene shows at pixel (x, y) of depth d (the last frame's camera): the world
   point unprojected (Vulkan's clip space: y down, z = d) and tested against each box; -1 for the
   sky (d = 1). */
static int mesh_at(const app *a, const mat4 *inv_vp, int x, int y, float d)
{
    float ndc[4] = {2.0f * ((float)x + 0.5f) / (float)a->w - 1.0f, 2.0f * ((float)y + 0.5f) / (float)a->h - 1.0f, d, 1.0f}, w[4];
    if (d >= 1.0f) return -1;
    mat4_apply(*inv_vp, ndc, w);
    for (int k = 0; k < 3; ++k) w[k] /= w[3];
    w[3] = 1.0f;
    for (int i = 0; i < MESHES; ++i) {
        float l[4];
        mat4_apply(mat4_inverse(a->meshes[i].model), w, l);
        if (fabsf(l[0]) <= 0.501f && fabsf(l[1]) <= 0.501f && fabsf(l[2]) <= 0.501f) return i;
    }
    return -2;
}

/* --check: the last frame (with depth) against frames of the same converged light without it. */
static int check_scene(app *a, float yaw, float pitch, float dist)
{
    size_t n = (size_t)a->w * a->h, bg = 0, bg_bad = 0, box = 0, box_bad = 0, post = 0, post_cut = 0, post_in = 0;
    float *with = (float *)malloc(n * 4 * sizeof(float)), *without = (float *)malloc(n * 4 * sizeof(float));
    float *depth = (float *)malloc(n * sizeof(float));
    buffer db;
    hd_stats st;
    mat4 inv_vp;
    int ok;
    if (!with || !without || !depth) return 0;
    hd_check(hd_get_stats(a->hd, &st), "hd_get_stats");
    if (!st.light_converged) {
        fprintf(stderr, "scene_vulkan: check: the light has not converged after the frames (%llu iterations)\n",
                (unsigned long long)st.iterations);
        free(with), free(without), free(depth);
        return 0;
    }
    db = make_buffer(a, n * sizeof(float), VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    hd_check(hd_read_image_f32(a->hd, with, n * 4), "hd_read_image_f32");
    { /* the scene's depth image, read back once */
        VkCommandBufferBeginInfo bi;
        VkImageMemoryBarrier ib;
        VkBufferImageCopy reg;
        VkSubmitInfo si;
        vk_check(vkResetCommandBuffer(a->cb, 0), "vkResetCommandBuffer");
        memset(&bi, 0, sizeof bi);
        bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        vk_check(vkBeginCommandBuffer(a->cb, &bi), "vkBeginCommandBuffer");
        memset(&ib, 0, sizeof ib);
        ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        ib.srcAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        ib.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        ib.oldLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        ib.image = a->depth.image;
        ib.subresourceRange.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
        ib.subresourceRange.levelCount = ib.subresourceRange.layerCount = 1;
        vkCmdPipelineBarrier(a->cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, &ib);
        memset(&reg, 0, sizeof reg);
        reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
        reg.imageSubresource.layerCount = 1;
        reg.imageExtent.width = (uint32_t)a->w, reg.imageExtent.height = (uint32_t)a->h, reg.imageExtent.depth = 1;
        vkCmdCopyImageToBuffer(a->cb, a->depth.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, db.buffer, 1, &reg);
        ib.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        ib.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        ib.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        ib.newLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        vkCmdPipelineBarrier(a->cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT | VK_PIPELINE_STAGE_HOST_BIT, 0, 0,
                             NULL, 0, NULL, 1, &ib);
        vk_check(vkEndCommandBuffer(a->cb), "vkEndCommandBuffer");
        memset(&si, 0, sizeof si);
        si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        si.commandBufferCount = 1;
        si.pCommandBuffers = &a->cb;
        vk_check(vkQueueSubmit(a->queue, 1, &si, VK_NULL_HANDLE), "vkQueueSubmit");
        vk_check(vkQueueWaitIdle(a->queue), "vkQueueWaitIdle");
        memcpy(depth, db.map, n * sizeof(float));
    }
    /* the reference: the same light and view, no depth, as many frames as the image holds */
    hd_check(hd_set_depth(a->hd, NULL), "hd_set_depth(NULL)");
    for (uint64_t f = 0; f < st.frames; ++f) draw_frame(a, yaw, pitch, dist, 0, 0);
    hd_check(hd_read_image_f32(a->hd, without, n * 4), "hd_read_image_f32");
    inv_vp = mat4_inverse(mat4_mul(a->proj, a->view));
    for (int y = 0; y < a->h; ++y)
        for (int x = 0; x < a->w; ++x) {
            size_t i = (size_t)y * a->w + x;
            const float *p = with + 4 * i, *q = without + 4 * i;
            int m = mesh_at(a, &inv_vp, x, y, depth[i]);
            if (m == -1 || m == 0) { /* sky or ground: behind the whole cloud, the same image */
                ++bg;
                for (int c = 0; c < 4; ++c) bg_bad += fabsf(p[c] - q[c]) > 1e-5f + 1e-4f * fabsf(q[c]);
            } else if (m == FRONT_BOX && q[3] > 0.05f) { /* cloud behind the box: hidden */
                ++box;
                box_bad += p[3] != 0.0f;
            } else if (m == POST && q[3] > 0.05f) { /* the post in the cloud: some of it in front */
                ++post;
                post_cut += p[3] < q[3] - 0.02f;
                post_in += p[3] > 0.0f;
            }
        }
    ok = bg > n / 4 && bg_bad == 0 && box > 20 && box_bad == 0 && post > 10 && post_cut > post * 9 / 10 && post_in > post / 2;
    fprintf(stderr,
            "scene_vulkan: %zu sky and ground pixels, %zu differ from the image without depth; the front box over %zu cloud pixels, "
            "%zu not hidden; the post over %zu, %zu cut (alpha below the reference's), %zu with cloud in front%s\n",
            bg, bg_bad, box, box_bad, post, post_cut, post_in, ok ? "" : " - FAILED");
    free_buffer(a, &db);
    free(with), free(without), free(depth);
    return ok;
}

int main(int argc, char **argv)
{
    static unsigned char cloud[CLOUD_N * CLOUD_N * CLOUD_N];
    app a;
    int frames = 48, check = 0, validate = 0;
    const char *out_path = NULL;
    float yaw = 0.3f, pitch = 0.06f, dist = 9.0f;
    hd_desc desc = HD_DESC_INIT;
    hd_light sun = HD_LIGHT_INIT;
    mat4 place;
    int ok = 1;

    memset(&a, 0, sizeof a);
    a.w = 960, a.h = 540;
    for (int i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--size") && i + 1 < argc && sscanf(argv[i + 1], "%dx%d", &a.w, &a.h) == 2 && a.w > 0 && a.h > 0 &&
            a.w <= 4096 && a.h <= 4096) ++i;
        else if (!strcmp(argv[i], "--frames") && i + 1 < argc && (frames = atoi(argv[i + 1])) > 0) ++i;
        else if (!strcmp(argv[i], "--out") && i + 1 < argc) out_path = argv[++i];
        else if (!strcmp(argv[i], "--validate")) validate = 1;
        else if (!strcmp(argv[i], "--check")) check = 1;
        else {
            fprintf(stderr, "usage: scene_vulkan [--size WxH] [--frames N] [--out PNG] [--validate] [--check]\n");
            return 2;
        }
    }
    if (validate || check) { /* a test's run: a machine without the layer or a device skips it */
        VkLayerProperties props[64];
        uint32_t np = 64, nd = 0, have = !validate;
        const char *req = getenv("HD_CONFORMANCE_REQUIRE");
        VkInstanceCreateInfo ici;
        VkInstance probe;
        for (uint32_t i = 0; validate && vkEnumerateInstanceLayerProperties(&np, props) >= 0 && i < np; ++i)
            have |= !strcmp(props[i].layerName, "VK_LAYER_KHRONOS_validation");
        memset(&ici, 0, sizeof ici);
        ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
        if (vkCreateInstance(&ici, NULL, &probe) == VK_SUCCESS) {
            vkEnumeratePhysicalDevices(probe, &nd, NULL);
            vkDestroyInstance(probe, NULL);
        }
        if (!have || nd == 0) {
            printf("scene_vulkan: SKIPPED: %s\n", nd == 0 ? "no Vulkan device" : "VK_LAYER_KHRONOS_validation is not installed");
            return req && req[0] == '1' ? 1 : 0;
        }
    }
    make_device(&a, validate);
    a.place = mat4_mul(mat4_translate(0.0f, 1.6f, 0.0f), mat4_mul(mat4_rotate_y(0.4f), mat4_scale(4.0f, 2.6f, 4.0f)));
    make_scene_objects(&a);

    /* the scene: a ground plane, a box in front of the cloud, one behind, a post through it */
    a.meshes[0].model = mat4_mul(mat4_translate(0.0f, -0.05f, 0.0f), mat4_scale(30.0f, 0.1f, 30.0f));
    a.meshes[1].model = mat4_translate(0.7f, 0.5f, 2.7f);
    a.meshes[2].model = mat4_mul(mat4_translate(-1.7f, 0.75f, -2.6f), mat4_scale(1.5f, 1.5f, 1.5f));
    a.meshes[3].model = mat4_mul(mat4_translate(0.4f, 1.5f, 0.2f), mat4_scale(0.18f, 3.0f, 0.18f));
    a.meshes[4].model = mat4_mul(mat4_translate(-3.5f, 0.4f, 2.0f), mat4_mul(mat4_rotate_y(0.5f), mat4_scale(0.8f, 0.8f, 0.8f)));
    {
        static const float albedo[MESHES][3] = {{0.5f, 0.48f, 0.45f}, {0.7f, 0.25f, 0.2f}, {0.2f, 0.4f, 0.7f},
                                                {0.8f, 0.75f, 0.3f}, {0.3f, 0.6f, 0.3f}};
        for (int i = 0; i < MESHES; ++i) memcpy(a.meshes[i].albedo, albedo[i], sizeof albedo[i]);
    }

    /* the cloud: its box (largest side 1, centred at 0) placed 4 units wide, 1.6 above the ground,
       turned about y; extinction and the light in world units; the library on our device */
    make_cloud(cloud, CLOUD_N);
    place = a.place;
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = CLOUD_N;
    desc.volume.data = cloud;
    memcpy(desc.volume.transform, place.m, sizeof desc.volume.transform);
    memcpy(sun.direction, sun_dir, sizeof sun.direction);
    memcpy(sun.color, sun_rgb, sizeof sun.color);
    sun.type = HD_LIGHT_DIRECTIONAL;
    desc.lights = &sun;
    desc.light_count = 1;
    desc.params.extinction = 6.0f; /* per world unit: the cloud is 4 units across */
    desc.params.albedo = 0.95f;
    a.view = mat4_identity();
    a.proj = mat4_perspective_vk(45.0f, (float)a.w / (float)a.h, 0.1f, 100.0f);
    desc.camera = library_camera(&a);
    desc.logger.func = hd_log_stderr;
    desc.vulkan.instance = a.inst;
    desc.vulkan.physical_device = a.phys;
    desc.vulkan.device = a.dev;
    desc.vulkan.queue = a.queue;
    desc.vulkan.queue_family = a.family;
    desc.vulkan.get_instance_proc_addr = (hd_proc)vkGetInstanceProcAddr;
    hd_check(hd_create(&desc, &a.hd), "hd_create");
    a.cloud_at[0] = 0.0f, a.cloud_at[1] = 1.6f, a.cloud_at[2] = 0.0f;

    /* the plume: F32 voxels replaced every frame (hd_update_volume in draw_frame), on the same
       device, its own context */
    if (!(a.smoke_vox = smoke_volume(&desc, a.smoke_at))) return 1;
    hd_check(hd_create(&desc, &a.smoke), "hd_create (plume)");
    { /* the light's image, of the illumination grid's size; filtered where the format allows */
        hd_stats st;
        VkFormatProperties fp;
        VkSamplerCreateInfo sci;
        hd_check(hd_get_stats(a.hd, &st), "hd_get_stats");
        memcpy(a.light_dims, st.illumination_dims, sizeof a.light_dims);
        a.light = make_light_image(&a);
        vkGetPhysicalDeviceFormatProperties(a.phys, VK_FORMAT_R32_SFLOAT, &fp);
        memset(&sci, 0, sizeof sci);
        sci.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO;
        sci.magFilter = sci.minFilter =
            fp.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
        sci.addressModeU = sci.addressModeV = sci.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        vk_check(vkCreateSampler(a.dev, &sci, NULL, &a.light_sampler), "vkCreateSampler");
        a.set_light = make_set(&a, a.light_sampler, a.light.view);
    }

    /* the camera turns for all but the last 16 frames, which rest so the light and the image
       converge; each hd_vulkan_record_render adds one light iteration until the light has converged */
    yaw -= 0.02f * (float)(frames > 16 ? frames - 16 : 0);
    for (int f = 0; f < frames; ++f) {
        if (f < frames - 16) yaw += 0.02f;
        draw_frame(&a, yaw, pitch, dist, f == frames - 1, 1);
    }
    if (out_path) {
        char err[256];
        if (!hdx_png_write(out_path, a.w, a.h, 4, a.readback.map, a.w * 4, err, sizeof err)) {
            fprintf(stderr, "scene_vulkan: cannot write %s: %s\n", out_path, err);
            ok = 0;
        } else {
            fprintf(stderr, "scene_vulkan: wrote %s (%dx%d)\n", out_path, a.w, a.h);
        }
    }
    if (check) { /* the view rests until the light has converged (one iteration a frame), at most 400 frames */
        hd_stats st;
        for (int f = 0; f < 400 && hd_get_stats(a.hd, &st) == HD_SUCCESS && !st.light_converged; ++f) draw_frame(&a, yaw, pitch, dist, 0, 1);
        ok &= check_scene(&a, yaw, pitch, dist);
        ok &= check_volume("scene_vulkan", a.smoke, a.w, a.h, "plume", 0.05f, 500);
    }

    hd_destroy(a.hd);
    hd_destroy(a.smoke);
    free(a.smoke_vox);
    vkDeviceWaitIdle(a.dev);
    vkDestroyPipeline(a.dev, a.pipe_mesh, NULL);
    vkDestroyPipeline(a.dev, a.pipe_blend, NULL);
    vkDestroyPipeline(a.dev, a.pipe_tonemap, NULL);
    vkDestroyPipelineLayout(a.dev, a.layout_mesh, NULL);
    vkDestroyPipelineLayout(a.dev, a.layout_quad, NULL);
    vkDestroyDescriptorPool(a.dev, a.dpool, NULL);
    vkDestroyDescriptorSetLayout(a.dev, a.set_layout, NULL);
    vkDestroySampler(a.dev, a.sampler, NULL);
    vkDestroySampler(a.dev, a.light_sampler, NULL);
    vkDestroyFramebuffer(a.dev, a.fb_mesh, NULL);
    vkDestroyFramebuffer(a.dev, a.fb_blend, NULL);
    vkDestroyFramebuffer(a.dev, a.fb_tonemap, NULL);
    vkDestroyRenderPass(a.dev, a.pass_mesh, NULL);
    vkDestroyRenderPass(a.dev, a.pass_blend, NULL);
    vkDestroyRenderPass(a.dev, a.pass_tonemap, NULL);
    free_image(&a, &a.hdr), free_image(&a, &a.depth), free_image(&a, &a.cloud), free_image(&a, &a.ldr), free_image(&a, &a.light);
    free_image(&a, &a.smoke_img);
    free_buffer(&a, &a.vbo), free_buffer(&a, &a.readback);
    vkDestroyCommandPool(a.dev, a.pool, NULL);
    vkDestroyDevice(a.dev, NULL);
    if (a.messenger) {
        PFN_vkDestroyDebugUtilsMessengerEXT destroy =
            (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(a.inst, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy) destroy(a.inst, a.messenger, NULL);
    }
    vkDestroyInstance(a.inst, NULL);
    if (validate) {
        fprintf(stderr, "scene_vulkan: %d validation messages\n", validation_messages);
        ok &= validation_messages == 0;
    }
    return ok ? 0 : 1;
}
