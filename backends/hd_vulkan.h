/* hd_vulkan.h - the Vulkan 1.1 compute backend: the shared kernels (backends/kernels/) as
   SPIR-V compiled ahead of time by scripts/build-spirv (backends/hd_spirv.h, with the exact
   glslangValidator command beside each array), so the library needs no shader compiler at run
   time. Defines the same hd__be_* functions, with the same contracts, as the CPU reference.

   Whose device: desc.vulkan.instance, physical_device, device (all three, or none), queue (or
   NULL: queue 0 of desc.vulkan.queue_family) as void*. The caller keeps them alive until
   hd_destroy and synchronises access to the queue. Functions are loaded through
   desc.vulkan.get_instance_proc_addr (volk's or your own loader's), else through the Vulkan
   loader's vkGetInstanceProcAddr, the only Vulkan symbol the library links against (none with
   HD_VK_NO_LOADER defined: then get_instance_proc_addr is required). Without a caller device the
   backend makes a headless instance and device: the first whose name contains
   desc.vulkan.device_name or $HD_VK_DEVICE, else a discrete, integrated, virtual, then CPU
   device. Force lavapipe on a machine with a GPU with
       VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
   The first such context's instance is kept for the process and shared by every later context
   that makes its own device through the same get_instance_proc_addr: NVIDIA's driver refuses
   vkCreateInstance after about 30 create/destroy cycles in one process (docs/DESIGN-VULKAN.md),
   so an application that recreates its context must not cycle instances.
   Validation: desc.vulkan.enable_validation or $HD_VK_VALIDATION=1 (own instance only) enables
   VK_LAYER_KHRONOS_validation with synchronization validation; every message of its debug
   messenger is logged as an error ("vulkan validation: ...") and counted.

   Submission: each stage records one command buffer, submits it and waits on a fence (so the
   core's stage clocks measure the device, as with OpenCL's clFinish). hd_vulkan_record() instead
   records whole iterations into the caller's command buffer; see hybriddiff.h.

   Memory: the grids (volume, sigma_t, E, phi, phi2, CD's light volumes) are r32f storage
   image3Ds, the TF, majorants and image accumulation storage buffers, the parameter block a
   ring of slots in one host-visible uniform buffer (a dynamic offset per iteration, so recorded
   iterations each see their own parameters). No sub-allocator: there are at most a dozen
   resources plus one per CD light (<= 66 + 10) plus HD_SOLVER_MULTIGRID's (4 per level, <= 12
   levels, and 5; the coarse levels small), far below maxMemoryAllocationCount
   (4096 guaranteed), so every resource has its own vkAllocateMemory; a sub-allocator would add
   code and save nothing measurable. With params.illumination_precision FLOAT16, E, phi and phi2
   are r16f (VK_FORMAT_R16_SFLOAT) images, read and written by the _half SPIR-V of the stages
   that touch them (direct, diffuse, project, sum_light); imageLoad / imageStore convert, the
   arithmetic stays float32. r16f storage images need the format's STORAGE_IMAGE feature and
   shaderStorageImageExtendedFormats: the own device enables it where the physical device has
   it, a caller's device must have enabled it; without either, FLOAT16 is HD_ERROR_UNSUPPORTED
   (logged) at hd_create and at the next render after hd_set_params. The grids as images are not
   bound by maxStorageBufferRange (128 MiB on lavapipe), only by maxImageDimension3D per axis
   (channels stack along z).
   With HYBRIDDIFF_TESTING defined (tests only; a release build reads none of these):
   $HD_VK_MEMORY_LIMIT=bytes caps the device memory the backend allocates; an allocation above it
   fails as VK_ERROR_OUT_OF_DEVICE_MEMORY would (a test knob: tests/vulkan/test_vulkan.c).
   $HD_VK_LOSE_DEVICE=n makes the n-th queue submission since hd_create fail as
   VK_ERROR_DEVICE_LOST instead of being submitted (the other test knob: the error path of a lost
   device cannot be provoked on lavapipe). $HD_VK_NO_HALF=1 plays a device without r16f storage
   images (lavapipe has them): float16 illumination is then refused as it would be there.
   Errors: every VkResult below zero is logged with the failing call and becomes an hd_result
   (OUT_OF_DEVICE_MEMORY -> HD_ERROR_OUT_OF_DEVICE_MEMORY, DEVICE_LOST -> HD_ERROR_DEVICE_LOST,
   which sticks: later calls fail fast, hd_destroy still frees everything). */
/* Every call goes through the table below; the prototypes are left to the including file's
   choice (VK_NO_PROTOTYPES is neither defined nor required here). */
#include <pthread.h>
#include <vulkan/vulkan.h>
#include "hd_spirv.h"

#if !defined(HD_VK_NO_LOADER)
#ifdef __cplusplus
extern "C" {
#endif
VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetInstanceProcAddr(VkInstance instance, const char *pName);
#ifdef __cplusplus
}
#endif
#endif


/* ---- function table: everything is loaded through vkGetInstanceProcAddr ------------------ */
#define HD__VK_GLOBAL_FNS(X) X(vkCreateInstance) X(vkEnumerateInstanceLayerProperties) \
    X(vkEnumerateInstanceExtensionProperties)
#define HD__VK_INSTANCE_FNS(X) X(vkDestroyInstance) X(vkEnumeratePhysicalDevices) \
    X(vkGetPhysicalDeviceProperties) X(vkGetPhysicalDeviceQueueFamilyProperties) \
    X(vkGetPhysicalDeviceMemoryProperties) X(vkCreateDevice) X(vkGetDeviceProcAddr) \
    X(vkGetPhysicalDeviceFeatures) X(vkGetPhysicalDeviceFormatProperties)
#define HD__VK_DEVICE_FNS(X) X(vkDestroyDevice) X(vkGetDeviceQueue) X(vkDeviceWaitIdle) \
    X(vkQueueSubmit) X(vkCreateFence) X(vkDestroyFence) X(vkWaitForFences) X(vkResetFences) \
    X(vkCreateCommandPool) X(vkDestroyCommandPool) X(vkAllocateCommandBuffers) \
    X(vkBeginCommandBuffer) X(vkEndCommandBuffer) X(vkResetCommandBuffer) \
    X(vkCreateBuffer) X(vkDestroyBuffer) X(vkGetBufferMemoryRequirements) X(vkBindBufferMemory) \
    X(vkCreateImage) X(vkDestroyImage) X(vkGetImageMemoryRequirements) X(vkBindImageMemory) \
    X(vkCreateImageView) X(vkDestroyImageView) X(vkAllocateMemory) X(vkFreeMemory) \
    X(vkMapMemory) X(vkUnmapMemory) X(vkCreateShaderModule) X(vkDestroyShaderModule) \
    X(vkCreateDescriptorSetLayout) X(vkDestroyDescriptorSetLayout) X(vkCreatePipelineLayout) \
    X(vkDestroyPipelineLayout) X(vkCreateComputePipelines) X(vkDestroyPipeline) \
    X(vkCreateDescriptorPool) X(vkDestroyDescriptorPool) X(vkResetDescriptorPool) \
    X(vkAllocateDescriptorSets) X(vkUpdateDescriptorSets) X(vkCmdBindPipeline) \
    X(vkCmdBindDescriptorSets) X(vkCmdPushConstants) X(vkCmdDispatch) X(vkCmdPipelineBarrier) \
    X(vkCmdCopyBuffer) X(vkCmdCopyBufferToImage) X(vkCmdCopyImageToBuffer) X(vkCmdFillBuffer) \
    X(vkCmdClearColorImage) X(vkCmdCopyImage) X(vkCreateQueryPool) X(vkDestroyQueryPool) \
    X(vkCmdResetQueryPool) X(vkCmdWriteTimestamp) X(vkGetQueryPoolResults)

typedef struct hd__vk_fns {
#define HD__VK_FN(name) PFN_##name name;
    HD__VK_GLOBAL_FNS(HD__VK_FN) HD__VK_INSTANCE_FNS(HD__VK_FN) HD__VK_DEVICE_FNS(HD__VK_FN)
#undef HD__VK_FN
    PFN_vkCreateDebugUtilsMessengerEXT vkCreateDebugUtilsMessengerEXT;
    PFN_vkDestroyDebugUtilsMessengerEXT vkDestroyDebugUtilsMessengerEXT;
} hd__vk_fns;

enum { HD__VK_CLASSIFY, HD__VK_DIRECT, HD__VK_DIFFUSE, HD__VK_PROJECT, HD__VK_CONVECT, HD__VK_SUM_LIGHT,
       HD__VK_PATH, HD__VK_LIGHT_SUM, HD__VK_UPSAMPLE, HD__VK_PIPELINE_COUNT };
#define HD__VK_LOCAL_X 64u /* hd_entry_glsl.h's work group: 64 x 1 x 1 */
#define HD__VK_DIFFUSE_VARIANTS 160 /* diffusion pipelines per context, one per flags value, solver and precision
                                     (128 + multigrid's 16 flag words with HD_FLAG_DIFFUSE_RHS, red-black, float32) */
#define HD__VK_DIFFUSE_ZK 4 /* slices of the block each diffusion invocation relaxes (hd_sc_zk; docs/DESIGN-VULKAN.md) */
#define HD__VK_DIFFUSE_YK 2 /* its rows (hd_sc_yk) */
#define HD__VK_BINDINGS 17

typedef struct hd__vk_buffer {
    VkBuffer buffer;
    VkDeviceMemory memory;
    VkDeviceSize bytes;
    void *map; /* host-visible buffers stay mapped */
} hd__vk_buffer;

typedef struct hd__vk_image {
    VkImage image;
    VkImageView view;
    VkDeviceMemory memory;
    VkDeviceSize bytes;
    int extent[3];
    int texel; /* bytes per texel: 2 (r16f), 4 (r32f), 8 (rg32f) */
} hd__vk_image;

typedef struct hd__vk_level {
    hd__vk_image sig;         /* coarse levels only (level 0 reads the backend's sigma_t) */
    hd__vk_image rhs, phi, res; /* right-hand side, correction, residual; level 0: r, z and q = A p */
} hd__vk_level;

/* HD_SOLVER_MULTIGRID's objects besides the grids (hd__gpu_mg_extras) and its grids */
struct hd__vk_mg {
    hd__vk_level lv[HD__MG_MAX_LEVELS];
    hd__vk_image p, lo;       /* the search direction; the iterate's low part (phi + lo) */
    hd__vk_buffer dot_a, dot_b; /* per-row partial sums (double), host-visible */
    hd__vk_buffer params;     /* slot l: level l's parameter block; slot `levels`: vw->kp */
    VkDeviceSize slot_bytes;
    VkDescriptorPool pool;
    VkDescriptorSet sets[HD__GPU_MG_SETS]; /* by backends/hd_gpu.h's set numbers */
    unsigned sets_gen;        /* be->sets_gen the sets were written at */
    int sets_valid;
};

struct hd__backend {
    const hd__view *vw;
    hd__vk_fns fn;
    PFN_vkGetInstanceProcAddr gipa;
    VkInstance instance;
    VkPhysicalDevice phys;
    VkDevice device;
    VkQueue queue;
    uint32_t queue_family;
    int own_device;               /* 1: the device is the backend's, and the instance unless kept */
    int kept_instance;            /* 1: instance is one of hd__vk_kept's, never destroyed here */
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDeviceLimits limits;
    VkPhysicalDeviceMemoryProperties memprops;
    char device_name[VK_MAX_PHYSICAL_DEVICE_NAME_SIZE];
    /* submission */
    VkCommandPool pool;
    VkCommandBuffer cmd;
    VkFence fence;
    int open;                     /* cmd is recording */
    VkCommandBuffer rec;          /* the caller's command buffer (hd_vulkan_record), or NULL */
    /* the device time of the last recorded frame (HD_RENDER_SCALE_AUTO's frame cost): timestamps
       0 and 1 of ts_pool around it, read by the next hd_vulkan_record */
    VkQueryPool ts_pool;
    int ts_state;                 /* 0: not looked at yet; 1: pool made; -1: the queue has no timestamps */
    uint64_t ts_mask;             /* the queue family's timestampValidBits as a mask */
    int ts_pending;               /* a recorded frame's timestamps to read (hd__be_record_seconds) */
    /* pipelines and bindings */
    VkDescriptorSetLayout set_layout;
    VkPipelineLayout layout;
    VkPipeline pipelines[HD__VK_PIPELINE_COUNT]; /* [HD__VK_DIFFUSE] unused: see diffuse */
    VkPipeline pipelines_half[HD__VK_PIPELINE_COUNT]; /* the r16f E / phi variants, made on first use */
    VkPipeline diffuse[HD__VK_DIFFUSE_VARIANTS];  /* the diffusion stage specialized for diffuse_flags[i], diffuse_jacobi[i] */
    int32_t diffuse_flags[HD__VK_DIFFUSE_VARIANTS], diffuse_jacobi[HD__VK_DIFFUSE_VARIANTS];
    int diffuse_half[HD__VK_DIFFUSE_VARIANTS];   /* ... from the r16f SPIR-V */
    int ndiffuse;
    int32_t diffuse_zk, diffuse_yk; /* HD__VK_DIFFUSE_ZK, _YK: what the pipelines are specialized for */
    int spread_rows;              /* 1 (a CPU device: lavapipe): the projection's rows in blocks spread (backends/hd_gpu.h) */
    VkDescriptorPool dpool;
    VkDescriptorSet sets[HD_MAX_LIGHTS];
    int sets_valid;
    /* parameter ring */
    hd__vk_buffer params;
    VkDeviceSize slot_bytes;
    uint32_t slots, next_slot;
    int have_slot;
    uint32_t slot;
    hd__kparams slot_kp;          /* what the current slot holds */
    /* resources */
    hd__vk_buffer tf, maj, img, staging, dummy_buffer;
    hd__vk_buffer dl;             /* the direct light's list of voxels (vw->dl_idx), binding 12 */
    hd__vk_buffer dep;            /* the host's depth buffer (vw->depth), binding 15; none: the placeholder */
    size_t dep_floats;            /* what dep holds */
    hd__vk_buffer env;            /* the environment's tables (vw->env), binding 16; none: the placeholder */
    hd__vk_image vol, sig, E, phi, phi2, dummy, dummy16;
    const char *no_half;          /* why r16f storage images are missing, or NULL */
    const char *no_f64;           /* why shaderFloat64 (HD_SOLVER_MULTIGRID) is missing, or NULL */
    hd__gpu_grids gg;             /* what the grids are made for (backends/hd_gpu.h) */
    struct hd__vk_mg mg;          /* HD_SOLVER_MULTIGRID's extras and grids while gg.levels */
    VkPipeline mg_pipes[HD__GPU_MG_VARIANTS]; /* HD_SOLVER_MULTIGRID's (backends/hd_gpu.h), made on first use */
    unsigned sets_gen;            /* bumped whenever hd__vk_sets rebuilds: the multigrid sets follow */
    hd__vk_image lv[HD_MAX_LIGHTS + 1]; /* CD: gg.nlv light volumes + a spare at lv[gg.nlv] */
    /* the projection's own inputs (hd__be_project): E + phi (binding 14, r32f), valid while
       gg.lsum_ok (backends/hd_gpu.h), and the step's TF table (binding 13,
       host-visible, ptab_cap entries, sized with the TF), written when its inputs change
       (ptab_key) */
    hd__vk_image lsum;
    hd__vk_buffer ptab;
    int ptab_n, ptab_cap;
    hd__ptab_key ptab_key;
    size_t img_floats, tf_bytes;
    VkDeviceSize mem_used, mem_limit;
    unsigned long submits, lose_at; /* queue submissions so far; HD_VK_LOSE_DEVICE (0: off) */
    int lost;
    unsigned long validation_messages;
    /* the output pass (hd__be_record_output, backends/hd_output_glsl.h), made on first use: its
       set layout (the image, the thresholds, the encoded image), pipeline, pool and set (written
       for the buffers named in out_img / out_enc), the RGBA8 thresholds (host-visible) and the
       encoded image (device-local) */
    VkDescriptorSetLayout out_set_layout;
    VkPipelineLayout out_layout;
    VkPipeline out_pipe;
    VkDescriptorPool out_pool;
    VkDescriptorSet out_set;
    VkBuffer out_img, out_enc;
    hd__vk_buffer otab, obuf;
};

static const char *hd__be_name(void) { return "vulkan"; }

/* ---- errors ---------------------------------------------------------------------------------- */
static const char *hd__vk_result_name(VkResult e)
{
    switch (e) {
#define HD__VKE(name) case name: return #name;
    HD__VKE(VK_SUCCESS) HD__VKE(VK_NOT_READY) HD__VKE(VK_TIMEOUT) HD__VKE(VK_INCOMPLETE)
    HD__VKE(VK_ERROR_OUT_OF_HOST_MEMORY) HD__VKE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    HD__VKE(VK_ERROR_INITIALIZATION_FAILED) HD__VKE(VK_ERROR_DEVICE_LOST) HD__VKE(VK_ERROR_MEMORY_MAP_FAILED)
    HD__VKE(VK_ERROR_LAYER_NOT_PRESENT) HD__VKE(VK_ERROR_EXTENSION_NOT_PRESENT)
    HD__VKE(VK_ERROR_FEATURE_NOT_PRESENT) HD__VKE(VK_ERROR_INCOMPATIBLE_DRIVER) HD__VKE(VK_ERROR_TOO_MANY_OBJECTS)
    HD__VKE(VK_ERROR_FORMAT_NOT_SUPPORTED) HD__VKE(VK_ERROR_FRAGMENTED_POOL) HD__VKE(VK_ERROR_UNKNOWN)
    HD__VKE(VK_ERROR_OUT_OF_POOL_MEMORY) HD__VKE(VK_ERROR_INVALID_EXTERNAL_HANDLE) HD__VKE(VK_ERROR_FRAGMENTATION)
#undef HD__VKE
    default: return "unknown VkResult";
    }
}

/* Logs the failing call with its VkResult name and returns the hd_result it means. */
static hd_result hd__vk_fail(const hd__view *vw, VkResult e, const char *call, int line)
{
    hd_result r = HD_ERROR_BACKEND;
    if (e == VK_ERROR_OUT_OF_DEVICE_MEMORY || e == VK_ERROR_FRAGMENTATION || e == VK_ERROR_FRAGMENTED_POOL ||
        e == VK_ERROR_OUT_OF_POOL_MEMORY || e == VK_ERROR_TOO_MANY_OBJECTS)
        r = HD_ERROR_OUT_OF_DEVICE_MEMORY;
    else if (e == VK_ERROR_OUT_OF_HOST_MEMORY)
        r = HD_ERROR_OUT_OF_MEMORY;
    else if (e == VK_ERROR_DEVICE_LOST)
        r = HD_ERROR_DEVICE_LOST;
    else if (e == VK_ERROR_INITIALIZATION_FAILED || e == VK_ERROR_INCOMPATIBLE_DRIVER || e == VK_ERROR_LAYER_NOT_PRESENT ||
             e == VK_ERROR_EXTENSION_NOT_PRESENT || e == VK_ERROR_FEATURE_NOT_PRESENT || e == VK_ERROR_FORMAT_NOT_SUPPORTED)
        r = HD_ERROR_UNSUPPORTED;
    if (r == HD_ERROR_DEVICE_LOST && vw->be) vw->be->lost = 1;
    hd__logf(&vw->log, HD_LOG_ERROR, r, __FILE__, line, "vulkan: %s failed: %s (%d)", call, hd__vk_result_name(e), (int)e);
    return r;
}
/* Returns from the calling function when a Vulkan call failed. */
#define HD__VK_TRY(vw, call_expr, name) \
    do { VkResult hd__e = (call_expr); \
         if (hd__e < 0) return hd__vk_fail((vw), hd__e, (name), __LINE__); } while (0)
#define HD__VK_LOST_CHECK(vw) \
    do { if ((vw)->be->lost) return HD__ERR(&(vw)->log, HD_ERROR_DEVICE_LOST, "vulkan: the device was lost earlier"); } while (0)
/* What the backend recorded submitted and waited for (hd__vk_flush), so nothing is in flight;
   returns from the calling function on failure. */
#define HD__VK_IDLE(vw) \
    do { hd_result hd__r = hd__vk_flush(vw); if (hd__r != HD_SUCCESS) return hd__r; } while (0)

/* The validation layer's messages: logged as errors and counted (the tests fail on any). */
static VKAPI_ATTR VkBool32 VKAPI_CALL hd__vk_messenger(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                        VkDebugUtilsMessageTypeFlagsEXT types,
                                                        const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    hd__backend *be = (hd__backend *)user;
    (void)types;
    be->validation_messages++;
    hd__logf(&be->vw->log, HD_LOG_ERROR, HD_ERROR_BACKEND, __FILE__, __LINE__, "vulkan validation (%s): %s",
             severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error" : "warning",
             data && data->pMessage ? data->pMessage : "(no message)");
    return VK_FALSE;
}

/* ---- instance, device, functions ------------------------------------------------------------- */
static hd_result hd__vk_load_instance_fns(const hd__view *vw)
{
    hd__backend *be = vw->be;
#define HD__VK_LOAD(name) \
    if (!(be->fn.name = (PFN_##name)be->gipa(be->instance, #name))) \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: vkGetInstanceProcAddr(\"%s\") returned NULL", #name);
    HD__VK_INSTANCE_FNS(HD__VK_LOAD)
#undef HD__VK_LOAD
    be->fn.vkCreateDebugUtilsMessengerEXT = (PFN_vkCreateDebugUtilsMessengerEXT)be->gipa(be->instance, "vkCreateDebugUtilsMessengerEXT");
    be->fn.vkDestroyDebugUtilsMessengerEXT = (PFN_vkDestroyDebugUtilsMessengerEXT)be->gipa(be->instance, "vkDestroyDebugUtilsMessengerEXT");
    return HD_SUCCESS;
}

static hd_result hd__vk_load_device_fns(const hd__view *vw)
{
    hd__backend *be = vw->be;
#define HD__VK_LOAD(name) \
    if (!(be->fn.name = (PFN_##name)be->fn.vkGetDeviceProcAddr(be->device, #name))) \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: vkGetDeviceProcAddr(\"%s\") returned NULL", #name);
    HD__VK_DEVICE_FNS(HD__VK_LOAD)
#undef HD__VK_LOAD
    return HD_SUCCESS;
}

static int hd__vk_env_flag(const char *name)
{
    const char *v = getenv(name);
    return v && v[0] && strcmp(v, "0") != 0;
}

/* The process's kept instances (without validation), one per loader (get_instance_proc_addr)
   for up to HD__VK_KEPT loaders: made by the first context that needs one, reused by every later
   one, destroyed only with the process. Past that many loaders a context makes and destroys its
   own instance. */
#define HD__VK_KEPT 4
static struct {
    pthread_mutex_t mu;
    PFN_vkGetInstanceProcAddr gipa[HD__VK_KEPT];
    VkInstance instance[HD__VK_KEPT];
} hd__vk_kept = {PTHREAD_MUTEX_INITIALIZER, {NULL}, {VK_NULL_HANDLE}};

/* The backend's own headless instance, with the validation layer when asked. */
static hd_result hd__vk_create_instance(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkDebugUtilsMessengerCreateInfoEXT dci;
    VkValidationFeaturesEXT vf;
    VkValidationFeatureEnableEXT enables[1];
    const char *layer = "VK_LAYER_KHRONOS_validation";
    const char *ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    int validate = vw->desc.vulkan.enable_validation || hd__vk_env_flag("HD_VK_VALIDATION");
#define HD__VK_LOAD(name) \
    if (!(be->fn.name = (PFN_##name)be->gipa(NULL, #name))) \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: vkGetInstanceProcAddr(NULL, \"%s\") returned NULL", #name);
    HD__VK_GLOBAL_FNS(HD__VK_LOAD)
#undef HD__VK_LOAD
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "hybriddiff";
    app.pEngineName = "hybriddiff";
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    memset(&dci, 0, sizeof dci);
    dci.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    dci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    dci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    dci.pfnUserCallback = hd__vk_messenger;
    dci.pUserData = be;
    if (validate) {
        uint32_t n = 0, i;
        int found = 0;
        VkLayerProperties *props;
        HD__VK_TRY(vw, be->fn.vkEnumerateInstanceLayerProperties(&n, NULL), "vkEnumerateInstanceLayerProperties");
        props = (VkLayerProperties *)hd__calloc(vw, n ? n : 1, sizeof *props);
        if (!props) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "vulkan: no memory for the layer list");
        if (be->fn.vkEnumerateInstanceLayerProperties(&n, props) >= 0)
            for (i = 0; i < n; ++i) found |= strcmp(props[i].layerName, layer) == 0;
        hd__free(vw, props);
        if (!found)
            return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: validation asked for, but %s is not installed (Debian: vulkan-validationlayers)", layer);
        enables[0] = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
        memset(&vf, 0, sizeof vf);
        vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
        vf.enabledValidationFeatureCount = 1;
        vf.pEnabledValidationFeatures = enables;
        vf.pNext = &dci; /* also reports on vkCreateInstance / vkDestroyInstance themselves */
        ici.pNext = &vf;
        ici.enabledLayerCount = 1;
        ici.ppEnabledLayerNames = &layer;
        ici.enabledExtensionCount = 1;
        ici.ppEnabledExtensionNames = &ext;
    }
    if (!validate) {
        VkResult vr = VK_SUCCESS;
        int k;
        pthread_mutex_lock(&hd__vk_kept.mu);
        for (k = 0; k < HD__VK_KEPT && hd__vk_kept.instance[k] && hd__vk_kept.gipa[k] != be->gipa; ++k) {}
        if (k < HD__VK_KEPT && hd__vk_kept.instance[k]) {
            be->instance = hd__vk_kept.instance[k];
            be->kept_instance = 1;
        } else if ((vr = be->fn.vkCreateInstance(&ici, NULL, &be->instance)) >= 0 && k < HD__VK_KEPT) {
            hd__vk_kept.instance[k] = be->instance;
            hd__vk_kept.gipa[k] = be->gipa;
            be->kept_instance = 1;
        }
        pthread_mutex_unlock(&hd__vk_kept.mu);
        HD__VK_TRY(vw, vr, "vkCreateInstance");
    } else {
        HD__VK_TRY(vw, be->fn.vkCreateInstance(&ici, NULL, &be->instance), "vkCreateInstance");
    }
    if (hd__vk_load_instance_fns(vw) != HD_SUCCESS) return HD_ERROR_UNSUPPORTED;
    if (validate) {
        if (!be->fn.vkCreateDebugUtilsMessengerEXT || !be->fn.vkDestroyDebugUtilsMessengerEXT)
            return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: VK_EXT_debug_utils has no vkCreateDebugUtilsMessengerEXT");
        HD__VK_TRY(vw, be->fn.vkCreateDebugUtilsMessengerEXT(be->instance, &dci, NULL, &be->messenger), "vkCreateDebugUtilsMessengerEXT");
        HD__INFO(&vw->log, "vulkan: VK_LAYER_KHRONOS_validation with synchronization validation");
    }
    return HD_SUCCESS;
}

/* A compute queue family of phys, or -1. */
static int hd__vk_compute_family(hd__backend *be, VkPhysicalDevice phys)
{
    VkQueueFamilyProperties q[32];
    uint32_t n = 32, i;
    be->fn.vkGetPhysicalDeviceQueueFamilyProperties(phys, &n, q);
    for (i = 0; i < n && i < 32; ++i)
        if (q[i].queueFlags & VK_QUEUE_COMPUTE_BIT) return (int)i;
    return -1;
}

/* By name (desc or $HD_VK_DEVICE, substring), else by type: discrete, integrated, virtual, CPU. */
static hd_result hd__vk_pick_device(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkPhysicalDevice devs[16];
    uint32_t n = 16, i;
    const char *want = vw->desc.vulkan.device_name;
    static const int rank[] = {4, 1, 0, 2, 3}; /* OTHER, INTEGRATED, DISCRETE, VIRTUAL, CPU */
    int best = -1, best_rank = 99;
    VkResult e;
    if (!want || !*want) want = getenv("HD_VK_DEVICE");
    e = be->fn.vkEnumeratePhysicalDevices(be->instance, &n, devs);
    if (e < 0) return hd__vk_fail(vw, e, "vkEnumeratePhysicalDevices", __LINE__);
    if (n == 0) return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: no Vulkan device (is a driver such as mesa-vulkan-drivers installed?)");
    for (i = 0; i < n && i < 16; ++i) {
        VkPhysicalDeviceProperties p;
        int r;
        be->fn.vkGetPhysicalDeviceProperties(devs[i], &p);
        if (hd__vk_compute_family(be, devs[i]) < 0 || p.apiVersion < VK_API_VERSION_1_1) continue;
        if (want && *want && !strstr(p.deviceName, want)) continue;
        r = (int)p.deviceType <= 4 ? rank[p.deviceType] : 5;
        if (r < best_rank) { best_rank = r; best = (int)i; }
    }
    if (best < 0) {
        if (want && *want) return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: no Vulkan 1.1 compute device's name contains \"%s\"", want);
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: no Vulkan 1.1 device with a compute queue");
    }
    be->phys = devs[best];
    be->queue_family = (uint32_t)hd__vk_compute_family(be, be->phys);
    return HD_SUCCESS;
}

static hd_result hd__vk_create_device(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    VkPhysicalDeviceFeatures have, want;
    float prio = 1.0f;
    be->fn.vkGetPhysicalDeviceFeatures(be->phys, &have);
    memset(&want, 0, sizeof want);
    want.shaderStorageImageExtendedFormats = have.shaderStorageImageExtendedFormats; /* r16f: float16 illumination */
    want.shaderFloat64 = have.shaderFloat64; /* HD_SOLVER_MULTIGRID's double residual, dot products, update */
    memset(&qci, 0, sizeof qci);
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = be->queue_family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    memset(&dci, 0, sizeof dci);
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    dci.pEnabledFeatures = &want;
    HD__VK_TRY(vw, be->fn.vkCreateDevice(be->phys, &dci, NULL, &be->device), "vkCreateDevice");
    return HD_SUCCESS;
}

/* ---- memory ------------------------------------------------------------------------------------ */
static int hd__vk_memory_type(hd__backend *be, uint32_t bits, VkMemoryPropertyFlags want, VkMemoryPropertyFlags prefer)
{
    uint32_t i;
    for (i = 0; i < be->memprops.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (be->memprops.memoryTypes[i].propertyFlags & (want | prefer)) == (want | prefer)) return (int)i;
    for (i = 0; i < be->memprops.memoryTypeCount; ++i)
        if ((bits & (1u << i)) && (be->memprops.memoryTypes[i].propertyFlags & want) == want) return (int)i;
    return -1;
}

/* One vkAllocateMemory, counted against $HD_VK_MEMORY_LIMIT. */
static hd_result hd__vk_allocate(const hd__view *vw, const VkMemoryRequirements *req, VkMemoryPropertyFlags want,
                                 VkMemoryPropertyFlags prefer, VkDeviceMemory *out, const char *what)
{
    hd__backend *be = vw->be;
    VkMemoryAllocateInfo mai;
    int type = hd__vk_memory_type(be, req->memoryTypeBits, want, prefer);
    if (type < 0) return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: no memory type for %s", what);
    if (be->mem_limit && be->mem_used + req->size > be->mem_limit) {
        hd__logf(&vw->log, HD_LOG_ERROR, HD_ERROR_OUT_OF_DEVICE_MEMORY, __FILE__, __LINE__,
                 "vulkan: vkAllocateMemory(%s, %llu bytes) failed: VK_ERROR_OUT_OF_DEVICE_MEMORY (the test limit %llu, %llu in use)",
                 what, (unsigned long long)req->size, (unsigned long long)be->mem_limit, (unsigned long long)be->mem_used);
        return HD_ERROR_OUT_OF_DEVICE_MEMORY;
    }
    memset(&mai, 0, sizeof mai);
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req->size;
    mai.memoryTypeIndex = (uint32_t)type;
    HD__VK_TRY(vw, be->fn.vkAllocateMemory(be->device, &mai, NULL, out), "vkAllocateMemory");
    be->mem_used += req->size;
    return HD_SUCCESS;
}

static void hd__vk_free_buffer(const hd__view *vw, hd__vk_buffer *b)
{
    hd__backend *be = vw->be;
    if (b->buffer) be->fn.vkDestroyBuffer(be->device, b->buffer, NULL);
    if (b->memory) {
        if (b->map) be->fn.vkUnmapMemory(be->device, b->memory);
        be->fn.vkFreeMemory(be->device, b->memory, NULL);
        be->mem_used -= b->bytes;
    }
    memset(b, 0, sizeof *b);
    be->sets_valid = 0;
}

static void hd__vk_free_image(const hd__view *vw, hd__vk_image *im)
{
    hd__backend *be = vw->be;
    if (im->view) be->fn.vkDestroyImageView(be->device, im->view, NULL);
    if (im->image) be->fn.vkDestroyImage(be->device, im->image, NULL);
    if (im->memory) {
        be->fn.vkFreeMemory(be->device, im->memory, NULL);
        be->mem_used -= im->bytes;
    }
    memset(im, 0, sizeof *im);
    be->sets_valid = 0;
}

/* A buffer; host != 0: host-visible, coherent and mapped (else device-local). */
static hd_result hd__vk_buffer_create(const hd__view *vw, hd__vk_buffer *b, VkDeviceSize bytes, VkBufferUsageFlags usage,
                                      int host, const char *what)
{
    hd__backend *be = vw->be;
    VkBufferCreateInfo bci;
    VkMemoryRequirements req;
    hd_result r;
    memset(b, 0, sizeof *b);
    be->sets_valid = 0;
    if (bytes == 0) bytes = 16;
    memset(&bci, 0, sizeof bci);
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = bytes;
    bci.usage = usage;
    bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    HD__VK_TRY(vw, be->fn.vkCreateBuffer(be->device, &bci, NULL, &b->buffer), "vkCreateBuffer");
    be->fn.vkGetBufferMemoryRequirements(be->device, b->buffer, &req);
    r = hd__vk_allocate(vw, &req, host ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                        : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT,
                        host ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : 0, &b->memory, what);
    if (r != HD_SUCCESS) return r;
    b->bytes = req.size;
    HD__VK_TRY(vw, be->fn.vkBindBufferMemory(be->device, b->buffer, b->memory, 0), "vkBindBufferMemory");
    if (host) HD__VK_TRY(vw, be->fn.vkMapMemory(be->device, b->memory, 0, VK_WHOLE_SIZE, 0, &b->map), "vkMapMemory");
    return HD_SUCCESS;
}

/* A storage image3D of format fmt (R16, R32 or R32G32 SFLOAT), also usable as `usage` (e.g. sampled);
   layout GENERAL once the next command buffer has run. */
static hd_result hd__vk_image_create_as(const hd__view *vw, hd__vk_image *im, int w, int h, int d, VkFormat fmt,
                                        VkImageUsageFlags usage, const char *what)
{
    hd__backend *be = vw->be;
    VkImageCreateInfo ici;
    VkImageViewCreateInfo vci;
    VkMemoryRequirements req;
    hd_result r;
    memset(im, 0, sizeof *im);
    be->sets_valid = 0;
    if ((uint32_t)w > be->limits.maxImageDimension3D || (uint32_t)h > be->limits.maxImageDimension3D ||
        (uint32_t)d > be->limits.maxImageDimension3D)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: %s needs a %dx%dx%d image, above maxImageDimension3D = %u",
                       what, w, h, d, be->limits.maxImageDimension3D);
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ici.imageType = VK_IMAGE_TYPE_3D;
    ici.format = fmt;
    ici.extent.width = (uint32_t)w; ici.extent.height = (uint32_t)h; ici.extent.depth = (uint32_t)d;
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = usage | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    ici.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    HD__VK_TRY(vw, be->fn.vkCreateImage(be->device, &ici, NULL, &im->image), "vkCreateImage");
    be->fn.vkGetImageMemoryRequirements(be->device, im->image, &req);
    if ((r = hd__vk_allocate(vw, &req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0, &im->memory, what)) != HD_SUCCESS) return r;
    im->bytes = req.size;
    HD__VK_TRY(vw, be->fn.vkBindImageMemory(be->device, im->image, im->memory, 0), "vkBindImageMemory");
    memset(&vci, 0, sizeof vci);
    vci.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    vci.image = im->image;
    vci.viewType = VK_IMAGE_VIEW_TYPE_3D;
    vci.format = fmt;
    vci.subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    vci.subresourceRange.levelCount = 1;
    vci.subresourceRange.layerCount = 1;
    HD__VK_TRY(vw, be->fn.vkCreateImageView(be->device, &vci, NULL, &im->view), "vkCreateImageView");
    im->extent[0] = w; im->extent[1] = h; im->extent[2] = d;
    im->texel = fmt == VK_FORMAT_R32G32_SFLOAT ? 8 : fmt == VK_FORMAT_R16_SFLOAT ? 2 : 4;
    return HD_SUCCESS;
}


/* ---- command buffers -------------------------------------------------------------------------- */
/* The command buffer to record into: the caller's (hd_vulkan_record) or the backend's, begun. */
static hd_result hd__vk_cmd(const hd__view *vw, VkCommandBuffer *out)
{
    hd__backend *be = vw->be;
    VkCommandBufferBeginInfo bi;
    HD__VK_LOST_CHECK(vw);
    if (be->rec) { *out = be->rec; return HD_SUCCESS; }
    if (!be->open) {
        HD__VK_TRY(vw, be->fn.vkResetCommandBuffer(be->cmd, 0), "vkResetCommandBuffer");
        memset(&bi, 0, sizeof bi);
        bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        HD__VK_TRY(vw, be->fn.vkBeginCommandBuffer(be->cmd, &bi), "vkBeginCommandBuffer");
        be->open = 1;
    }
    *out = be->cmd;
    return HD_SUCCESS;
}

/* Submits what the backend recorded and waits for it (nothing when recording for the caller). */
static hd_result hd__vk_flush(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkSubmitInfo si;
    VkResult e;
    if (be->rec || !be->open) return HD_SUCCESS;
    be->open = 0;
    HD__VK_TRY(vw, be->fn.vkEndCommandBuffer(be->cmd), "vkEndCommandBuffer");
    memset(&si, 0, sizeof si);
    si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    si.commandBufferCount = 1;
    si.pCommandBuffers = &be->cmd;
    if (++be->submits == be->lose_at) return hd__vk_fail(vw, VK_ERROR_DEVICE_LOST, "vkQueueSubmit (a lost device played by the test knob)", __LINE__);
    HD__VK_TRY(vw, be->fn.vkQueueSubmit(be->queue, 1, &si, be->fence), "vkQueueSubmit");
    e = be->fn.vkWaitForFences(be->device, 1, &be->fence, VK_TRUE, UINT64_MAX);
    if (e != VK_SUCCESS) return hd__vk_fail(vw, e < 0 ? e : VK_ERROR_DEVICE_LOST, "vkWaitForFences", __LINE__);
    HD__VK_TRY(vw, be->fn.vkResetFences(be->device, 1, &be->fence), "vkResetFences");
    be->next_slot = 0; /* the parameter slots are free again */
    be->have_slot = 0;
    return HD_SUCCESS;
}

/* Orders everything recorded before against everything after: compute and transfer, both ways. */
static void hd__vk_barrier(hd__backend *be, VkCommandBuffer cb)
{
    VkMemoryBarrier mb;
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT;
    mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                       VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_HOST_READ_BIT | VK_ACCESS_UNIFORM_READ_BIT;
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                                0, 1, &mb, 0, NULL, 0, NULL);
}

/* Layout transitions of up to two images around a transfer: storage images live in GENERAL;
   copies and clears use the TRANSFER_* layouts (what the validation layer's advice asks for),
   and each transition is also a full compute/transfer memory barrier. */
static void hd__vk_layout(hd__backend *be, VkCommandBuffer cb, VkImage a, VkImageLayout a_from, VkImageLayout a_to,
                          VkImage b, VkImageLayout b_from, VkImageLayout b_to)
{
    VkImageMemoryBarrier ib[2];
    int i, n = b ? 2 : 1;
    memset(ib, 0, sizeof ib);
    for (i = 0; i < n; ++i) {
        ib[i].sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        ib[i].srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT;
        ib[i].dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
        ib[i].oldLayout = i == 0 ? a_from : b_from;
        ib[i].newLayout = i == 0 ? a_to : b_to;
        ib[i].srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        ib[i].dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        ib[i].image = i == 0 ? a : b;
        ib[i].subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        ib[i].subresourceRange.levelCount = 1;
        ib[i].subresourceRange.layerCount = 1;
    }
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                                VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL,
                                (uint32_t)n, ib);
}
#define HD__VK_G VK_IMAGE_LAYOUT_GENERAL
#define HD__VK_SRC VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL
#define HD__VK_DST VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL

/* Copies image a into image b (same extent), GENERAL before and after. */
static void hd__vk_copy_image(hd__backend *be, VkCommandBuffer cb, const hd__vk_image *a, const hd__vk_image *b)
{
    VkImageCopy ic;
    memset(&ic, 0, sizeof ic);
    ic.srcSubresource.aspectMask = ic.dstSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    ic.srcSubresource.layerCount = ic.dstSubresource.layerCount = 1;
    ic.extent.width = (uint32_t)a->extent[0];
    ic.extent.height = (uint32_t)a->extent[1];
    ic.extent.depth = (uint32_t)a->extent[2];
    hd__vk_layout(be, cb, a->image, HD__VK_G, HD__VK_SRC, b->image, HD__VK_G, HD__VK_DST);
    be->fn.vkCmdCopyImage(cb, a->image, HD__VK_SRC, b->image, HD__VK_DST, 1, &ic);
    hd__vk_layout(be, cb, a->image, HD__VK_SRC, HD__VK_G, b->image, HD__VK_DST, HD__VK_G);
}

/* Zeroes an image, GENERAL before and after (from: its layout now, UNDEFINED when new). */
static void hd__vk_zero_image(hd__backend *be, VkCommandBuffer cb, VkImage im, VkImageLayout from)
{
    VkClearColorValue zero;
    VkImageSubresourceRange range;
    memset(&zero, 0, sizeof zero);
    memset(&range, 0, sizeof range);
    range.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    range.levelCount = 1;
    range.layerCount = 1;
    hd__vk_layout(be, cb, im, from, HD__VK_DST, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
    be->fn.vkCmdClearColorImage(cb, im, HD__VK_DST, &zero, 1, &range);
    hd__vk_layout(be, cb, im, HD__VK_DST, HD__VK_G, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
}

/* New images: UNDEFINED -> GENERAL (the only layout they are used in), then zeroed. */
static hd_result hd__vk_image_init(const hd__view *vw, hd__vk_image *im)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
    hd__vk_zero_image(vw->be, cb, im->image, VK_IMAGE_LAYOUT_UNDEFINED);
    return HD_SUCCESS;
}

static hd_result hd__vk_image_new_as(const hd__view *vw, hd__vk_image *im, int w, int h, int d, VkFormat fmt, const char *what)
{
    hd_result r;
    if ((r = hd__vk_image_create_as(vw, im, w, h, d, fmt, 0, what)) != HD_SUCCESS) return r;
    return hd__vk_image_init(vw, im);
}

static hd_result hd__vk_image_new(const hd__view *vw, hd__vk_image *im, int w, int h, int d, const char *what)
{
    return hd__vk_image_new_as(vw, im, w, h, d, VK_FORMAT_R32_SFLOAT, what);
}

/* Grid id's image (backends/hd_gpu.h): E, phi, phi2 r16f at float16 storage, the others r32f. */
static hd__vk_image *hd__vk_grid(hd__backend *be, int id)
{
    hd__vk_image *named[HD__G_MG_LEVELS] = {&be->sig, &be->E, &be->phi, &be->phi2, &be->lsum, &be->mg.p, &be->mg.lo};
    hd__vk_level *L = &be->mg.lv[HD__G_LEVEL_OF(id)];
    hd__vk_image *level[4] = {&L->sig, &L->rhs, &L->phi, &L->res}; /* by HD__G_MG_SIG, _RHS, _PHI, _RES */
    return id < HD__G_MG_LEVELS ? named[id] : id >= HD__G_LIGHT ? &be->lv[id - HD__G_LIGHT] : level[(id - HD__G_MG_LEVELS) % 4];
}
/* What was recorded is submitted first: it may name the image (a new one's zeroing). */
static void hd__gpu_grid_free(const hd__view *vw, int id)
{
    hd__vk_image *im = hd__vk_grid(vw->be, id);
    if (im->image && vw->be->open && !vw->be->lost) hd__vk_flush(vw);
    hd__vk_free_image(vw, im);
}
static hd_result hd__gpu_grid_new(const hd__view *vw, int id, int w, int h, int d, const char *what)
{
    VkFormat fmt = vw->be->gg.f16 && id >= HD__G_E && id <= HD__G_PHI2 ? VK_FORMAT_R16_SFLOAT : VK_FORMAT_R32_SFLOAT;
    hd__gpu_grid_free(vw, id);
    return hd__vk_image_new_as(vw, hd__vk_grid(vw->be, id), w, h, d, fmt, what);
}
static hd_result hd__gpu_grid_zero(const hd__view *vw, int id)
{
    const hd__vk_image *im = hd__vk_grid(vw->be, id);
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if (!im->image) return HD_SUCCESS;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
    hd__vk_barrier(vw->be, cb);
    hd__vk_zero_image(vw->be, cb, im->image, HD__VK_G);
    return HD_SUCCESS;
}

static hd_result hd__vk_staging(const hd__view *vw, VkDeviceSize bytes)
{
    hd__backend *be = vw->be;
    if (be->staging.buffer && be->staging.bytes >= bytes) return HD_SUCCESS;
    hd__vk_free_buffer(vw, &be->staging);
    return hd__vk_buffer_create(vw, &be->staging, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                1, "the staging buffer");
}

static VkBufferImageCopy hd__vk_region(const hd__vk_image *im)
{
    VkBufferImageCopy reg;
    memset(&reg, 0, sizeof reg);
    reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    reg.imageSubresource.layerCount = 1;
    reg.imageExtent.width = (uint32_t)im->extent[0];
    reg.imageExtent.height = (uint32_t)im->extent[1];
    reg.imageExtent.depth = (uint32_t)im->extent[2];
    return reg;
}

/* The volume image packs voxels along x into r32ui texels (hd_bind_vk_glsl.h): 4 U8, 2 U16 / I16
   or 1 float each. Texels of a row of n voxels: */
static size_t hd__vk_vol_texels(const hd__view *vw, int n)
{
    size_t per = 4 / hd__vol_elem(vw->vtype);
    return ((size_t)n + per - 1) / per;
}

/* The most bytes of the volume one staged copy takes (at least one slice of the box): the staging
   buffer stays this small instead of holding a second copy of the volume (2 bytes a voxel of I16
   in host-visible memory, kept for the context's life). */
#define HD__VK_VOL_SLAB_BYTES ((size_t)8 << 20)

/* The texels holding box vox's voxels, from the core's copy through the staging buffer, in slabs
   of z slices of at most HD__VK_VOL_SLAB_BYTES (each a region, submitted and waited for): the box
   widened to whole texels along x, a row's last texel zero-padded past the volume's end. */
static hd_result hd__vk_vol_write(const hd__view *vw, const hd__box *vox)
{
    hd__backend *be = vw->be;
    hd__vk_image *im = &be->vol;
    size_t e = hd__vol_elem(vw->vtype), per = 4 / e;
    size_t t0 = (size_t)vox->lo[0] / per, t1 = hd__vk_vol_texels(vw, vox->hi[0]), row = (t1 - t0) * 4;
    size_t v0 = t0 * per, v1 = t1 * per < (size_t)vw->dims[0] ? t1 * per : (size_t)vw->dims[0];
    int h = vox->hi[1] - vox->lo[1], dz = vox->hi[2] - vox->lo[2], y, z, z0, slab;
    size_t slice = row * (size_t)h;
    unsigned char *dst;
    VkBufferImageCopy reg = hd__vk_region(im);
    hd_result r;
    slab = slice >= HD__VK_VOL_SLAB_BYTES ? 1 : (int)(HD__VK_VOL_SLAB_BYTES / slice);
    if (slab > dz) slab = dz;
    if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r; /* the staging buffer is free */
    if ((r = hd__vk_staging(vw, slice * (size_t)slab)) != HD_SUCCESS) return r;
    for (z0 = vox->lo[2]; z0 < vox->hi[2]; z0 += slab) {
        int z1 = z0 + slab < vox->hi[2] ? z0 + slab : vox->hi[2];
        VkCommandBuffer cb = VK_NULL_HANDLE;
        dst = (unsigned char *)be->staging.map;
        for (z = z0; z < z1; ++z)
            for (y = vox->lo[1]; y < vox->hi[1]; ++y) {
                const unsigned char *src = (const unsigned char *)vw->vol + (((size_t)z * vw->dims[1] + y) * vw->dims[0] + v0) * e;
                memcpy(dst, src, (v1 - v0) * e);
                memset(dst + (v1 - v0) * e, 0, row - (v1 - v0) * e);
                dst += row;
            }
        reg.imageOffset.x = (int32_t)t0;
        reg.imageOffset.y = vox->lo[1];
        reg.imageOffset.z = z0;
        reg.imageExtent.width = (uint32_t)(t1 - t0);
        reg.imageExtent.height = (uint32_t)h;
        reg.imageExtent.depth = (uint32_t)(z1 - z0);
        if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
        hd__vk_layout(be, cb, im->image, HD__VK_G, HD__VK_DST, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
        be->fn.vkCmdCopyBufferToImage(cb, be->staging.buffer, im->image, HD__VK_DST, 1, &reg);
        hd__vk_layout(be, cb, im->image, HD__VK_DST, HD__VK_G, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
        if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r; /* waited for: the next slab may reuse it */
    }
    return HD_SUCCESS;
}

#ifdef HYBRIDDIFF_TESTING
/* Whole image <- host floats (x fastest), submitted and waited for (the test hooks' and the
   benchmarks' writes of E and phi); an r16f image gets them
   rounded to nearest even (hdk_f2h, the CPU backend's rounding). */
static hd_result hd__vk_upload_image(const hd__view *vw, hd__vk_image *im, const float *src)
{
    hd__backend *be = vw->be;
    size_t bytes = (size_t)im->extent[0] * im->extent[1] * im->extent[2] * (size_t)im->texel;
    VkBufferImageCopy reg = hd__vk_region(im);
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r; /* the staging buffer is free */
    if ((r = hd__vk_staging(vw, bytes)) != HD_SUCCESS) return r;
    if (im->texel == 2) {
        size_t i;
        for (i = 0; i < bytes / 2; ++i) ((uint16_t *)be->staging.map)[i] = hdk_f2h(src[i]);
    } else {
        memcpy(be->staging.map, src, bytes);
    }
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
    hd__vk_layout(be, cb, im->image, HD__VK_G, HD__VK_DST, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
    be->fn.vkCmdCopyBufferToImage(cb, be->staging.buffer, im->image, HD__VK_DST, 1, &reg);
    hd__vk_layout(be, cb, im->image, HD__VK_DST, HD__VK_G, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
    return hd__vk_flush(vw);
}
#endif

/* Whole image -> host floats (x fastest; channels stacked along z come out channel-planar), or
   with a slice list (list, count) those z slices only, in its order, in one copy; an r16f
   image's halves are widened exactly (hdk_h2f). */
static hd_result hd__vk_download_image(const hd__view *vw, hd__vk_image *im, float *dst, const int *list, int count)
{
    hd__backend *be = vw->be;
    size_t slice = (size_t)im->extent[0] * im->extent[1] * (size_t)im->texel;
    size_t bytes = slice * (size_t)(list ? count : im->extent[2]);
    VkBufferImageCopy one = hd__vk_region(im), *regs = &one;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    int k;
    if (list) {
        if (count <= 0) return HD_SUCCESS;
        if (!(regs = (VkBufferImageCopy *)hd__calloc(vw, (size_t)count, sizeof *regs)))
            return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "vulkan: no memory for %d copy regions", count);
        for (k = 0; k < count; ++k) {
            regs[k] = one;
            regs[k].bufferOffset = (VkDeviceSize)k * slice;
            regs[k].imageOffset.z = list[k];
            regs[k].imageExtent.depth = 1;
        }
    }
    if ((r = hd__vk_flush(vw)) == HD_SUCCESS && (r = hd__vk_staging(vw, bytes)) == HD_SUCCESS &&
        (r = hd__vk_cmd(vw, &cb)) == HD_SUCCESS) {
        hd__vk_layout(be, cb, im->image, HD__VK_G, HD__VK_SRC, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
        be->fn.vkCmdCopyImageToBuffer(cb, im->image, HD__VK_SRC, be->staging.buffer, list ? (uint32_t)count : 1u, regs);
        hd__vk_layout(be, cb, im->image, HD__VK_SRC, HD__VK_G, VK_NULL_HANDLE, HD__VK_G, HD__VK_G);
        hd__vk_barrier(be, cb);
        r = hd__vk_flush(vw);
    }
    if (regs != &one) hd__free(vw, regs);
    if (r != HD_SUCCESS) return r;
    if (im->texel == 2) {
        size_t i;
        for (i = 0; i < bytes / 2; ++i) dst[i] = hdk_h2f(((const uint16_t *)be->staging.map)[i]);
    } else {
        memcpy(dst, be->staging.map, bytes);
    }
    return HD_SUCCESS;
}

/* ---- pipelines -------------------------------------------------------------------------------- */
/* A compute pipeline of SPIR-V `code` (entry "main") with layout and the specialization spec
   (NULL for none); the shader module lives only while the pipeline is made. */
static hd_result hd__vk_compute_pipeline(const hd__view *vw, const uint32_t *code, size_t bytes, const VkSpecializationInfo *spec,
                                         VkPipelineLayout layout, VkPipeline *out)
{
    hd__backend *be = vw->be;
    VkShaderModuleCreateInfo smci;
    VkComputePipelineCreateInfo cpci;
    VkShaderModule sm;
    VkResult e;
    memset(&smci, 0, sizeof smci);
    smci.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    smci.codeSize = bytes;
    smci.pCode = code;
    HD__VK_TRY(vw, be->fn.vkCreateShaderModule(be->device, &smci, NULL, &sm), "vkCreateShaderModule");
    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO;
    cpci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    cpci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cpci.stage.module = sm;
    cpci.stage.pName = "main";
    cpci.stage.pSpecializationInfo = spec;
    cpci.layout = layout;
    e = be->fn.vkCreateComputePipelines(be->device, VK_NULL_HANDLE, 1, &cpci, NULL, out);
    be->fn.vkDestroyShaderModule(be->device, sm, NULL);
    if (e < 0) { *out = VK_NULL_HANDLE; return hd__vk_fail(vw, e, "vkCreateComputePipelines", __LINE__); }
    return HD_SUCCESS;
}

/* Pipeline of stage p from its SPIR-V. The diffusion stage's is specialized: its specialization
   constant hd_sc_flags (constant_id 0, hd_bind_vk_glsl.h) is the flags word, so the kernels'
   branches on the flags (RGB scattering, boundary condition) fold away at pipeline creation.
   Lavapipe executes both sides of every branch, uniform ones included, so each flag left to a
   run-time test makes every voxel pay for the paths it does not take. Its constant 1 is
   be->diffuse_zk and constant 3 be->diffuse_yk, the slices and rows of the block each invocation
   relaxes (one voxel per row, hd_entry_glsl.h): lavapipe pays a fixed cost per invocation (the
   store and its own set-up cost as much as 7 loads) and per static load, and the block loads each
   texel its voxels share once. Constant 2 is the solver (jacobi), so the
   store of the other one is not compiled (docs/DESIGN-VULKAN.md has the gain). flags: constant
   0's value, NULL for the other stages (bench/hdbench_vulkan.c's --ab also calls this). */
static hd_result hd__vk_pipeline_code(const hd__view *vw, const uint32_t *code, size_t bytes, const int32_t *flags, int32_t jacobi,
                                      VkPipeline *out)
{
    hd__backend *be = vw->be;
    VkSpecializationMapEntry sme[5];
    VkSpecializationInfo spec;
    int32_t data[5];
    int i;
    data[0] = flags ? *flags : 0;
    data[1] = be->diffuse_zk;
    data[2] = jacobi;
    data[3] = be->diffuse_yk;
    data[4] = vw->vtype; /* hd_sc_vstore: every stage's volume load */
    for (i = 0; i < 5; ++i) {
        sme[i].constantID = (uint32_t)i;
        sme[i].offset = (uint32_t)(i * sizeof data[0]);
        sme[i].size = sizeof data[0];
    }
    /* without flags (not the diffusion stage) only the volume's storage is specialized */
    spec.mapEntryCount = flags ? 5 : 1;
    spec.pMapEntries = flags ? sme : sme + 4;
    spec.dataSize = sizeof data;
    spec.pData = data;
    return hd__vk_compute_pipeline(vw, code, bytes, &spec, be->layout, out);
}

/* Stage p's pipeline; half: from its r16f SPIR-V (only the stages that touch E / phi have one). */
static hd_result hd__vk_pipeline(const hd__view *vw, int p, int32_t flags, int32_t jacobi, int half, VkPipeline *out)
{
    static const uint32_t *const code[2][HD__VK_PIPELINE_COUNT] = {
        {hd__spv_classify, hd__spv_direct, hd__spv_diffuse, hd__spv_project, hd__spv_convect, hd__spv_sum_light, hd__spv_path,
         hd__spv_light_sum, hd__spv_upsample},
        {NULL, hd__spv_direct_half, hd__spv_diffuse_half, hd__spv_project_half, NULL, hd__spv_sum_light_half, NULL,
         hd__spv_light_sum_half, NULL}};
    static const size_t size[2][HD__VK_PIPELINE_COUNT] = {
        {sizeof hd__spv_classify, sizeof hd__spv_direct, sizeof hd__spv_diffuse, sizeof hd__spv_project,
         sizeof hd__spv_convect, sizeof hd__spv_sum_light, sizeof hd__spv_path, sizeof hd__spv_light_sum, sizeof hd__spv_upsample},
        {0, sizeof hd__spv_direct_half, sizeof hd__spv_diffuse_half, sizeof hd__spv_project_half, 0, sizeof hd__spv_sum_light_half, 0,
         sizeof hd__spv_light_sum_half, 0}};
    half = half && code[1][p] != NULL;
    return hd__vk_pipeline_code(vw, code[half][p], size[half][p], p == HD__VK_DIFFUSE ? &flags : NULL, jacobi, out);
}

/* The pipeline of stage p (not the diffusion stage) for the current precision: a float16 one
   made on first use, kept until hd_destroy. */
static hd_result hd__vk_stage_pipeline(const hd__view *vw, int p, VkPipeline *out)
{
    hd__backend *be = vw->be;
    hd_result r;
    if (!be->gg.f16 || (p != HD__VK_DIRECT && p != HD__VK_PROJECT && p != HD__VK_SUM_LIGHT && p != HD__VK_LIGHT_SUM)) {
        *out = be->pipelines[p];
        return HD_SUCCESS;
    }
    if (!be->pipelines_half[p] && (r = hd__vk_pipeline(vw, p, 0, 0, 1, &be->pipelines_half[p])) != HD_SUCCESS) return r;
    *out = be->pipelines_half[p];
    return HD_SUCCESS;
}

/* The diffusion pipeline for the flags word `flags` and the solver, made on first use and kept
   until hd_destroy (a command buffer recorded by hd_vulkan_record may still name an older one). */
static hd_result hd__vk_diffuse_pipeline_for(const hd__view *vw, int32_t flags, int32_t jacobi, VkPipeline *out)
{
    hd__backend *be = vw->be;
    hd_result r;
    int i;
    for (i = 0; i < be->ndiffuse; ++i)
        if (be->diffuse_flags[i] == flags && be->diffuse_jacobi[i] == jacobi && be->diffuse_half[i] == be->gg.f16) {
            *out = be->diffuse[i];
            return HD_SUCCESS;
        }
    if (be->ndiffuse == HD__VK_DIFFUSE_VARIANTS)
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: more than %d flag, solver and precision combinations for the diffusion stage",
                       HD__VK_DIFFUSE_VARIANTS);
    if ((r = hd__vk_pipeline(vw, HD__VK_DIFFUSE, flags, jacobi, be->gg.f16, &be->diffuse[be->ndiffuse])) != HD_SUCCESS) return r;
    be->diffuse_flags[be->ndiffuse] = flags;
    be->diffuse_jacobi[be->ndiffuse] = jacobi;
    be->diffuse_half[be->ndiffuse] = be->gg.f16;
    *out = be->diffuse[be->ndiffuse++];
    return HD_SUCCESS;
}

/* ... for the current flags (vw->kp). */
static hd_result hd__vk_diffuse_pipeline(const hd__view *vw, int32_t jacobi, VkPipeline *out)
{
    return hd__vk_diffuse_pipeline_for(vw, vw->kp.counts.z, jacobi, out);
}

/* A compute descriptor-set layout of n bindings (binding i of types[i], one descriptor each)
   and the pipeline layout of that one set with push_bytes of push constants (the library's
   layouts and the benchmarks' share this). */
#define HD__VK_MAX_SET_BINDINGS 17
static hd_result hd__vk_layouts(const hd__view *vw, const VkDescriptorType *types, uint32_t n, uint32_t push_bytes,
                                VkDescriptorSetLayout *set_layout, VkPipelineLayout *layout)
{
    hd__backend *be = vw->be;
    VkDescriptorSetLayoutBinding b[HD__VK_MAX_SET_BINDINGS];
    VkDescriptorSetLayoutCreateInfo lci;
    VkPushConstantRange pcr;
    VkPipelineLayoutCreateInfo plci;
    uint32_t i;
    if (n > HD__VK_MAX_SET_BINDINGS)
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: %u bindings in one set, at most %d", n, HD__VK_MAX_SET_BINDINGS);
    memset(b, 0, sizeof b);
    for (i = 0; i < n; ++i) {
        b[i].binding = i;
        b[i].descriptorType = types[i];
        b[i].descriptorCount = 1;
        b[i].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    }
    memset(&lci, 0, sizeof lci);
    lci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO;
    lci.bindingCount = n;
    lci.pBindings = b;
    HD__VK_TRY(vw, be->fn.vkCreateDescriptorSetLayout(be->device, &lci, NULL, set_layout), "vkCreateDescriptorSetLayout");
    memset(&pcr, 0, sizeof pcr);
    pcr.stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
    pcr.size = push_bytes;
    memset(&plci, 0, sizeof plci);
    plci.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    plci.setLayoutCount = 1;
    plci.pSetLayouts = set_layout;
    plci.pushConstantRangeCount = 1;
    plci.pPushConstantRanges = &pcr;
    HD__VK_TRY(vw, be->fn.vkCreatePipelineLayout(be->device, &plci, NULL, layout), "vkCreatePipelineLayout");
    return HD_SUCCESS;
}

/* A descriptor pool for `sets` sets of the backend's set layout (hd__vk_pipelines' types: per set
   1 dynamic uniform buffer, 8 storage images, 8 storage buffers): the backend's sets and the
   multigrid's (HD_SOLVER_MULTIGRID) each have one. */
static hd_result hd__vk_pool(const hd__view *vw, uint32_t sets, VkDescriptorPool *pool)
{
    hd__backend *be = vw->be;
    VkDescriptorPoolSize ps[3];
    VkDescriptorPoolCreateInfo dpci;
    ps[0].type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC; ps[0].descriptorCount = sets;
    ps[1].type = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE; ps[1].descriptorCount = 8 * sets;
    ps[2].type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER; ps[2].descriptorCount = 8 * sets;
    memset(&dpci, 0, sizeof dpci);
    dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
    dpci.maxSets = sets;
    dpci.poolSizeCount = 3;
    dpci.pPoolSizes = ps;
    HD__VK_TRY(vw, be->fn.vkCreateDescriptorPool(be->device, &dpci, NULL, pool), "vkCreateDescriptorPool");
    return HD_SUCCESS;
}

/* The most sets one pool holds: the backend's (a set per light); the multigrid's
   (HD__GPU_MG_SETS, backends/hd_gpu.h) fit too. */
#define HD__VK_POOL_SETS_MAX HD_MAX_LIGHTS
typedef char hd__vk_mg_sets_fit_a_pool[HD__GPU_MG_SETS <= HD__VK_POOL_SETS_MAX ? 1 : -1];

/* Empties `pool` and allocates n (<= HD__VK_POOL_SETS_MAX) sets of the backend's set layout from
   it into sets[]; reset_name and alloc_name name the calls in a failure's log line. */
static hd_result hd__vk_pool_sets(const hd__view *vw, VkDescriptorPool pool, int n, VkDescriptorSet *sets,
                                  const char *reset_name, const char *alloc_name)
{
    hd__backend *be = vw->be;
    VkDescriptorSetLayout layouts[HD__VK_POOL_SETS_MAX];
    VkDescriptorSetAllocateInfo ai;
    int i;
    HD__VK_TRY(vw, be->fn.vkResetDescriptorPool(be->device, pool, 0), reset_name);
    for (i = 0; i < n; ++i) layouts[i] = be->set_layout;
    memset(&ai, 0, sizeof ai);
    ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
    ai.descriptorPool = pool;
    ai.descriptorSetCount = (uint32_t)n;
    ai.pSetLayouts = layouts;
    HD__VK_TRY(vw, be->fn.vkAllocateDescriptorSets(be->device, &ai, sets), alloc_name);
    return HD_SUCCESS;
}

static hd_result hd__vk_pipelines(const hd__view *vw)
{
    hd__backend *be = vw->be;
    static const VkDescriptorType types[HD__VK_BINDINGS] = {
        VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
        VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
        VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
        VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
        VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
        VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    hd_result r;
    int i;
    /* the set's storage buffers (TF, majorants, image, row sums, direct light's list, the
       projection's TF table, the depth buffer, the environment's tables) and storage images (volume, sigma_t, E, phi, phi2,
       two light volumes, the projection's E + phi): above Vulkan's guaranteed minimum of 4 per
       stage each */
    if (be->limits.maxPerStageDescriptorStorageBuffers < 8 || be->limits.maxPerStageDescriptorStorageImages < 8)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED,
                       "vulkan: the device binds %u storage buffers and %u storage images per shader stage; 8 and 8 needed",
                       be->limits.maxPerStageDescriptorStorageBuffers, be->limits.maxPerStageDescriptorStorageImages);
    if ((r = hd__vk_layouts(vw, types, HD__VK_BINDINGS, 4 * sizeof(int32_t), &be->set_layout, &be->layout)) != HD_SUCCESS)
        return r;
    for (i = 0; i < HD__VK_PIPELINE_COUNT; ++i) /* the diffusion stage's on first use, per flags */
        if (i != HD__VK_DIFFUSE && (r = hd__vk_pipeline(vw, i, 0, 0, 0, &be->pipelines[i])) != HD_SUCCESS) return r;
    return hd__vk_pool(vw, HD_MAX_LIGHTS, &be->dpool); /* a set per light */
}

/* Writes set `set`: binding 0 the parameter buffer `params` (dynamic offset, one block), the
   others im[i] / bu[i] (absent resources, NULL or not allocated, bind placeholders: at float16
   storage an r16f one for E / phi / phi2, a view's format must match the shader's). */
static void hd__vk_write_set(const hd__view *vw, VkDescriptorSet set, const hd__vk_buffer *params, const hd__vk_image *const *im,
                             const hd__vk_buffer *const *bu)
{
    hd__backend *be = vw->be;
    VkWriteDescriptorSet w[HD__VK_BINDINGS];
    VkDescriptorBufferInfo bi[HD__VK_BINDINGS];
    VkDescriptorImageInfo ii[HD__VK_BINDINGS];
    int i;
    for (i = 0; i < HD__VK_BINDINGS; ++i) {
        memset(&w[i], 0, sizeof w[i]);
        w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
        w[i].dstSet = set;
        w[i].dstBinding = (uint32_t)i;
        w[i].descriptorCount = 1;
        if (i == 0 || bu[i]) {
            const hd__vk_buffer *x = i == 0 ? params : bu[i]->buffer ? bu[i] : &be->dummy_buffer;
            bi[i].buffer = x->buffer;
            bi[i].offset = 0;
            bi[i].range = i == 0 ? sizeof(hd__kparams) : VK_WHOLE_SIZE;
            w[i].descriptorType = i == 0 ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            w[i].pBufferInfo = &bi[i];
        } else {
            const hd__vk_image *x = im[i] && im[i]->image ? im[i] : be->gg.f16 && i >= 5 && i <= 7 ? &be->dummy16 : &be->dummy;
            ii[i].sampler = VK_NULL_HANDLE;
            ii[i].imageView = x->view;
            ii[i].imageLayout = VK_IMAGE_LAYOUT_GENERAL;
            w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
            w[i].pImageInfo = &ii[i];
        }
    }
    be->fn.vkUpdateDescriptorSets(be->device, HD__VK_BINDINGS, w, 0, NULL);
}

/* The buffers every set binds (TF, majorants, image; binding 11, multigrid's row sums, a
   placeholder unless given; 12, the direct light's list; 13, the projection's TF table; 15, the
   depth buffer's placeholder, which hd__vk_sets replaces; 16, the environment's tables) into bu. */
static void hd__vk_common_buffers(hd__backend *be, const hd__vk_buffer **bu, const hd__vk_buffer *dot)
{
    bu[2] = &be->tf; bu[3] = &be->maj; bu[8] = &be->img; bu[11] = dot ? dot : &be->dummy_buffer;
    bu[12] = &be->dl; bu[13] = &be->ptab; bu[15] = &be->dummy_buffer; bu[16] = &be->env;
}

/* The descriptor sets, rebuilt after any resource changed: set l binds CD's light l (and the
   spare) at bindings 9 and 10; set 0 serves every other stage (multigrid's passes have their own,
   hd__vk_mg_sets). Nothing may be in flight (the backend waits after each stage;
   hd_vulkan_record's contract). */
static hd_result hd__vk_sets(const hd__view *vw)
{
    hd__backend *be = vw->be;
    hd_result r;
    int n = be->gg.nlv > 0 ? be->gg.nlv : 1, s;
    if (be->sets_valid) return HD_SUCCESS;
    if ((r = hd__vk_pool_sets(vw, be->dpool, n, be->sets, "vkResetDescriptorPool", "vkAllocateDescriptorSets")) != HD_SUCCESS)
        return r;
    for (s = 0; s < n; ++s) {
        const hd__vk_image *im[HD__VK_BINDINGS];
        const hd__vk_buffer *bu[HD__VK_BINDINGS];
        memset(im, 0, sizeof im);
        memset(bu, 0, sizeof bu);
        hd__vk_common_buffers(be, bu, NULL);
        im[1] = &be->vol; im[4] = &be->sig; im[5] = &be->E; im[6] = &be->phi; im[7] = &be->phi2;
        im[9] = be->gg.nlv > 0 ? &be->lv[s] : &be->dummy;
        im[10] = be->gg.nlv > 0 ? &be->lv[be->gg.nlv] : &be->dummy;
        im[14] = &be->lsum;
        bu[15] = &be->dep;
        hd__vk_write_set(vw, be->sets[s], &be->params, im, bu);
    }
    be->sets_valid = 1;
    be->sets_gen++;
    return HD_SUCCESS;
}

/* The parameter ring: vw->kp in a slot of its own whenever it changed since the last one, so
   every recorded iteration reads the parameters it was recorded with. */
static hd_result hd__vk_ring(const hd__view *vw, uint32_t slots)
{
    hd__backend *be = vw->be;
    VkDeviceSize align = be->limits.minUniformBufferOffsetAlignment ? be->limits.minUniformBufferOffsetAlignment : 256;
    if (be->params.buffer && be->slots >= slots) return HD_SUCCESS;
    hd__vk_free_buffer(vw, &be->params);
    be->slots = 0;
    be->slot_bytes = (sizeof(hd__kparams) + align - 1) / align * align;
    if (slots > (1u << 20))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_PARAMETER, "vulkan: %u parameter slots (recorded iterations) are too many; record at most 2^19 iterations at a time", slots);
    {
        hd_result r = hd__vk_buffer_create(vw, &be->params, be->slot_bytes * slots, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 1,
                                           "the parameter ring");
        if (r != HD_SUCCESS) return r;
    }
    be->slots = slots;
    be->next_slot = 0;
    be->have_slot = 0;
    return HD_SUCCESS;
}

static hd_result hd__vk_params(const hd__view *vw, uint32_t *offset)
{
    hd__backend *be = vw->be;
    if (!be->have_slot || memcmp(&be->slot_kp, &vw->kp, sizeof vw->kp) != 0) {
        if (be->next_slot >= be->slots)
            return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: the parameter ring's %u slots are used up", be->slots);
        be->slot = be->next_slot++;
        memcpy((char *)be->params.map + be->slot * be->slot_bytes, &vw->kp, sizeof vw->kp);
        be->slot_kp = vw->kp;
        be->have_slot = 1;
    }
    *offset = (uint32_t)(be->slot * be->slot_bytes);
    return HD_SUCCESS;
}

/* Records, after a barrier, one dispatch of pipeline pipe over groups of 64 x 1 x 1 covering
   nx x ny x nz, with descriptor set `set` at parameter offset `offset` and push constants pc. */
static void hd__vk_record_dispatch(hd__backend *be, VkCommandBuffer cb, VkPipeline pipe, VkDescriptorSet set, uint32_t offset,
                                   int nx, int ny, int nz, const int32_t *pc)
{
    hd__vk_barrier(be, cb);
    be->fn.vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
    be->fn.vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, be->layout, 0, 1, &set, 1, &offset);
    be->fn.vkCmdPushConstants(cb, be->layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, 4 * sizeof pc[0], pc);
    be->fn.vkCmdDispatch(cb, ((uint32_t)nx + HD__VK_LOCAL_X - 1) / HD__VK_LOCAL_X, (uint32_t)ny, (uint32_t)nz);
}

/* Records one dispatch of pipeline pipe over groups of 64 x 1 x 1 covering nx x ny x nz, with
   the given set (of be->sets) and push constants, after a barrier. */
static hd_result hd__vk_dispatch(const hd__view *vw, VkCommandBuffer cb, VkPipeline pipe, int set, int nx, int ny, int nz,
                                 int pc0, int pc1, int pc2, int pc3)
{
    hd__backend *be = vw->be;
    int32_t pc[4];
    uint32_t offset;
    hd_result r;
    if (nx <= 0 || ny <= 0 || nz <= 0) return HD_SUCCESS;
    if ((r = hd__vk_params(vw, &offset)) != HD_SUCCESS) return r;
    pc[0] = pc0; pc[1] = pc1; pc[2] = pc2; pc[3] = pc3;
    hd__vk_record_dispatch(be, cb, pipe, be->sets[set], offset, nx, ny, nz, pc);
    return HD_SUCCESS;
}

/* Everything a stage needs before recording: the sets and a command buffer. */
static hd_result hd__vk_begin(const hd__view *vw, VkCommandBuffer *cb)
{
    hd_result r;
    if (!vw->be->sets_valid) {
        if (vw->be->rec)
            return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: resources changed while recording (internal error)");
        if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r;
        if ((r = hd__vk_sets(vw)) != HD_SUCCESS) return r;
    }
    return hd__vk_cmd(vw, cb);
}

/* ---- life cycle -------------------------------------------------------------------------------- */
/* The bracket of a public call (src/hd_backend.h): a lost device refused; at the end, what is
   still recorded (a clear, a new grid's zeroing) submitted and waited for. */
static hd_result hd__be_begin(const hd__view *vw)
{
    HD__VK_LOST_CHECK(vw);
    return HD_SUCCESS;
}
static hd_result hd__be_end(const hd__view *vw, hd_result r) { return r != HD_SUCCESS ? r : hd__vk_flush(vw); }

static void hd__be_destroy(hd__view *vw)
{
    hd__backend *be = vw->be;
    int i;
    if (!be) return;
    if (be->device && be->fn.vkDeviceWaitIdle) {
        if (be->open && !be->lost) hd__vk_flush(vw);
        be->fn.vkDeviceWaitIdle(be->device); /* also after a lost device: then it returns at once */
        hd__gpu_free(vw, &be->gg);
        hd__vk_free_image(vw, &be->vol); hd__vk_free_image(vw, &be->dummy); hd__vk_free_image(vw, &be->dummy16);
        hd__vk_free_buffer(vw, &be->params); hd__vk_free_buffer(vw, &be->tf); hd__vk_free_buffer(vw, &be->maj);
        hd__vk_free_buffer(vw, &be->img); hd__vk_free_buffer(vw, &be->staging); hd__vk_free_buffer(vw, &be->dummy_buffer);
        hd__vk_free_buffer(vw, &be->dl); hd__vk_free_buffer(vw, &be->ptab); hd__vk_free_buffer(vw, &be->dep);
        hd__vk_free_buffer(vw, &be->env);
        hd__vk_free_buffer(vw, &be->otab); hd__vk_free_buffer(vw, &be->obuf);
        if (be->out_pipe) be->fn.vkDestroyPipeline(be->device, be->out_pipe, NULL);
        if (be->out_pool) be->fn.vkDestroyDescriptorPool(be->device, be->out_pool, NULL);
        if (be->out_layout) be->fn.vkDestroyPipelineLayout(be->device, be->out_layout, NULL);
        if (be->out_set_layout) be->fn.vkDestroyDescriptorSetLayout(be->device, be->out_set_layout, NULL);
        for (i = 0; i < HD__VK_PIPELINE_COUNT; ++i)
            if (be->pipelines[i]) be->fn.vkDestroyPipeline(be->device, be->pipelines[i], NULL);
        for (i = 0; i < HD__VK_PIPELINE_COUNT; ++i)
            if (be->pipelines_half[i]) be->fn.vkDestroyPipeline(be->device, be->pipelines_half[i], NULL);
        for (i = 0; i < be->ndiffuse; ++i) be->fn.vkDestroyPipeline(be->device, be->diffuse[i], NULL);
        for (i = 0; i < HD__GPU_MG_VARIANTS; ++i)
            if (be->mg_pipes[i]) be->fn.vkDestroyPipeline(be->device, be->mg_pipes[i], NULL);
        if (be->dpool) be->fn.vkDestroyDescriptorPool(be->device, be->dpool, NULL);
        if (be->layout) be->fn.vkDestroyPipelineLayout(be->device, be->layout, NULL);
        if (be->set_layout) be->fn.vkDestroyDescriptorSetLayout(be->device, be->set_layout, NULL);
        if (be->fence) be->fn.vkDestroyFence(be->device, be->fence, NULL);
        if (be->ts_pool) be->fn.vkDestroyQueryPool(be->device, be->ts_pool, NULL);
        if (be->pool) be->fn.vkDestroyCommandPool(be->device, be->pool, NULL);
        if (be->own_device) be->fn.vkDestroyDevice(be->device, NULL);
    }
    if (be->own_device && !be->kept_instance && be->instance && be->fn.vkDestroyInstance) {
        if (be->messenger) be->fn.vkDestroyDebugUtilsMessengerEXT(be->instance, be->messenger, NULL);
        be->fn.vkDestroyInstance(be->instance, NULL);
    }
    hd__free(vw, be);
    vw->be = NULL;
}

/* Whether the device has r16f storage images (float16 illumination): be->no_half says why not.
   A caller's device: the physical device's feature is checked; enabling it was the caller's job. */
static void hd__vk_check_half(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkPhysicalDeviceFeatures f;
    VkFormatProperties fp;
#ifdef HYBRIDDIFF_TESTING /* plays a device without r16f storage */
    const char *knob = getenv("HD_VK_NO_HALF");
#else
    const char *knob = NULL;
#endif
    be->fn.vkGetPhysicalDeviceFeatures(be->phys, &f);
    be->fn.vkGetPhysicalDeviceFormatProperties(be->phys, VK_FORMAT_R16_SFLOAT, &fp);
    be->no_half = NULL;
    if (knob && *knob && strcmp(knob, "0") != 0)
        be->no_half = "the test knob plays a device without them";
    else if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT))
        be->no_half = "VK_FORMAT_R16_SFLOAT has no VK_FORMAT_FEATURE_STORAGE_IMAGE_BIT";
    else if (!(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_TRANSFER_SRC_BIT) ||
             !(fp.optimalTilingFeatures & VK_FORMAT_FEATURE_TRANSFER_DST_BIT))
        be->no_half = "VK_FORMAT_R16_SFLOAT images cannot be copied (no TRANSFER_SRC / TRANSFER_DST)";
    else if (!f.shaderStorageImageExtendedFormats)
        be->no_half = "the device lacks shaderStorageImageExtendedFormats (r16f storage images)";
}

/* Whether the device has shaderFloat64 (HD_SOLVER_MULTIGRID's double passes): be->no_f64 says why
   not. The own device enables it where the physical device has it; a caller's device must have
   enabled it (Vulkan cannot be asked which features a device was created with, so only the
   physical device's is checked, as for r16f). $HD_VK_NO_F64=1 plays a device without it. */
static void hd__vk_check_f64(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkPhysicalDeviceFeatures f;
    be->fn.vkGetPhysicalDeviceFeatures(be->phys, &f);
    be->no_f64 = NULL;
    if (hd__vk_env_flag("HD_VK_NO_F64"))
        be->no_f64 = "$HD_VK_NO_F64 is set (the test knob that plays a device without shaderFloat64)";
    else if (!f.shaderFloat64)
        be->no_f64 = "the device lacks shaderFloat64 (the solver's residuals and dot products are double)";
}

/* HD_ERROR_UNSUPPORTED, logged, when float16 illumination is asked for and the device lacks it. */
static hd_result hd__vk_half_ok(const hd__view *vw)
{
    if (vw->params.illumination_precision != HD_PRECISION_FLOAT16 || !vw->be->no_half) return HD_SUCCESS;
    return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: illumination_precision FLOAT16 is not available on %s: %s",
                   vw->be->device_name, vw->be->no_half);
}

static hd_result hd__be_create(hd__view *vw)
{
    hd__backend *be;
    hd_result r;
    VkPhysicalDeviceProperties props;
    VkCommandPoolCreateInfo cpci;
    VkCommandBufferAllocateInfo cbai;
    VkFenceCreateInfo fci;
#ifdef HYBRIDDIFF_TESTING /* fault injection: a device memory limit, a lost device at the n-th submission */
    const char *limit = getenv("HD_VK_MEMORY_LIMIT"), *lose = getenv("HD_VK_LOSE_DEVICE");
#else
    const char *limit = NULL, *lose = NULL;
#endif
    const hd_desc *d = &vw->desc;
    int caller = d->vulkan.instance || d->vulkan.physical_device || d->vulkan.device;
    be = (hd__backend *)hd__calloc(vw, 1, sizeof *be);
    if (!be) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "vulkan: cannot allocate the backend");
    vw->be = be;
    be->vw = vw;
    be->diffuse_zk = HD__VK_DIFFUSE_ZK;
    be->diffuse_yk = HD__VK_DIFFUSE_YK;
    if (limit && *limit) be->mem_limit = (VkDeviceSize)strtoull(limit, NULL, 10);
    if (lose && *lose) be->lose_at = strtoul(lose, NULL, 10);
    /* void* -> function pointer by memcpy: a cast is not ISO C */
    if (d->vulkan.get_instance_proc_addr) be->gipa = (PFN_vkGetInstanceProcAddr)d->vulkan.get_instance_proc_addr;
#if !defined(HD_VK_NO_LOADER)
    if (!be->gipa) be->gipa = vkGetInstanceProcAddr;
#endif
    if (!be->gipa)
        return HD__ERR(&vw->log, HD_ERROR_NULL_POINTER, "vulkan: built with HD_VK_NO_LOADER: desc.vulkan.get_instance_proc_addr is required");
    if (caller) {
        if (!d->vulkan.instance || !d->vulkan.physical_device || !d->vulkan.device)
            return HD__ERR(&vw->log, HD_ERROR_NULL_POINTER, "vulkan: give desc.vulkan.instance, physical_device and device together, or none");
        be->instance = (VkInstance)d->vulkan.instance;
        be->phys = (VkPhysicalDevice)d->vulkan.physical_device;
        be->device = (VkDevice)d->vulkan.device;
        be->queue_family = d->vulkan.queue_family;
        if ((r = hd__vk_load_instance_fns(vw)) != HD_SUCCESS) return r;
    } else {
        be->own_device = 1;
        if ((r = hd__vk_create_instance(vw)) != HD_SUCCESS) return r;
        if ((r = hd__vk_pick_device(vw)) != HD_SUCCESS) return r;
        if ((r = hd__vk_create_device(vw)) != HD_SUCCESS) return r;
    }
    if ((r = hd__vk_load_device_fns(vw)) != HD_SUCCESS) {
        if (be->own_device) be->device = VK_NULL_HANDLE; /* cannot destroy it without its functions */
        return r;
    }
    if (caller && d->vulkan.queue) be->queue = (VkQueue)d->vulkan.queue;
    else be->fn.vkGetDeviceQueue(be->device, be->queue_family, 0, &be->queue);
    be->fn.vkGetPhysicalDeviceProperties(be->phys, &props);
    be->fn.vkGetPhysicalDeviceMemoryProperties(be->phys, &be->memprops);
    be->limits = props.limits;
    /* lavapipe runs the work groups of a dispatch as one contiguous run per thread */
    be->spread_rows = props.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    memcpy(be->device_name, props.deviceName, sizeof be->device_name);
    be->device_name[sizeof be->device_name - 1] = '\0';
    HD__INFO(&vw->log, "vulkan: device %s (%s), queue family %u", be->device_name, caller ? "the caller's" : "own", be->queue_family);
    if (props.limits.maxUniformBufferRange < sizeof(hd__kparams))
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: maxUniformBufferRange %u < the %zu-byte parameter block",
                       props.limits.maxUniformBufferRange, sizeof(hd__kparams));
    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cpci.queueFamilyIndex = be->queue_family;
    HD__VK_TRY(vw, be->fn.vkCreateCommandPool(be->device, &cpci, NULL, &be->pool), "vkCreateCommandPool");
    memset(&cbai, 0, sizeof cbai);
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = be->pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    HD__VK_TRY(vw, be->fn.vkAllocateCommandBuffers(be->device, &cbai, &be->cmd), "vkAllocateCommandBuffers");
    memset(&fci, 0, sizeof fci);
    fci.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    HD__VK_TRY(vw, be->fn.vkCreateFence(be->device, &fci, NULL, &be->fence), "vkCreateFence");
    if ((r = hd__vk_pipelines(vw)) != HD_SUCCESS) return r;
    if ((r = hd__vk_ring(vw, 16)) != HD_SUCCESS) return r;
    hd__vk_check_half(vw);
    if ((r = hd__vk_half_ok(vw)) != HD_SUCCESS) return r;
    hd__vk_check_f64(vw); /* a multigrid it rules out: hd_create's hd__mg_available */
    if (!be->no_half && (r = hd__vk_image_new_as(vw, &be->dummy16, 1, 1, 1, VK_FORMAT_R16_SFLOAT, "a float16 placeholder image")) != HD_SUCCESS)
        return r;
    if ((r = hd__vk_buffer_create(vw, &be->dummy_buffer, 16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 0, "a placeholder buffer")) != HD_SUCCESS) return r;
    if ((r = hd__vk_image_new(vw, &be->dummy, 1, 1, 1, "a placeholder image")) != HD_SUCCESS) return r;
    if ((r = hd__vk_buffer_create(vw, &be->maj, (VkDeviceSize)vw->mdims[0] * vw->mdims[1] * vw->mdims[2] * sizeof(float),
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1, "the majorant grid")) != HD_SUCCESS) return r;
    {
        hd__box all;
        int d;
        if ((r = hd__vk_image_create_as(vw, &be->vol, (int)hd__vk_vol_texels(vw, vw->dims[0]), vw->dims[1], vw->dims[2],
                                        VK_FORMAT_R32_UINT, 0, "the volume")) != HD_SUCCESS)
            return r;
        if ((r = hd__vk_image_init(vw, &be->vol)) != HD_SUCCESS) return r;
        for (d = 0; d < 3; ++d) {
            all.lo[d] = 0;
            all.hi[d] = vw->dims[d];
        }
        return hd__vk_vol_write(vw, &all);
    }
}

/* TF and majorants: small host-visible buffers written in place (nothing is in flight here). */
static hd_result hd__be_upload_inputs(const hd__view *vw)
{
    hd__backend *be = vw->be;
    size_t tf_bytes = (size_t)vw->tf_count * 4 * sizeof(float);
    size_t ncell = (size_t)vw->mdims[0] * vw->mdims[1] * vw->mdims[2];
    hd_result r;
    HD__VK_IDLE(vw);
    if (tf_bytes != be->tf_bytes) {
        hd__vk_free_buffer(vw, &be->tf);
        be->tf_bytes = 0;
        if ((r = hd__vk_buffer_create(vw, &be->tf, tf_bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1, "the transfer function")) != HD_SUCCESS)
            return r;
        be->tf_bytes = tf_bytes;
    }
    memcpy(be->tf.map, vw->tf, tf_bytes);
    memcpy(be->maj.map, vw->majorant, ncell * sizeof(float));
    /* the projection's TF table has as many entries as long as the TF has as many: sized here, while
       nothing is being recorded; written by hd__vk_project */
    if (hd__project_table_n(vw) != be->ptab_cap) {
        hd__vk_free_buffer(vw, &be->ptab);
        be->ptab_n = be->ptab_cap = 0;
        be->ptab_key.valid = 0;
        if ((r = hd__vk_buffer_create(vw, &be->ptab, (size_t)hd__project_table_n(vw) * 4 * sizeof(float),
                                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1, "the projection's TF table")) != HD_SUCCESS)
            return r;
        be->ptab_cap = hd__project_table_n(vw);
    }
    return HD_SUCCESS;
}

/* hd_update_volume: the box of the volume into the volume image (hd__vk_vol_write), the majorant
   cells' rows written in place. */
static hd_result hd__be_update_volume(const hd__view *vw, const hd__box *vox, const hd__box *cells)
{
    hd__backend *be = vw->be;
    int y, z;
    hd_result r;
    HD__VK_IDLE(vw); /* the staging buffer and the majorants are free */
    if ((r = hd__vk_vol_write(vw, vox)) != HD_SUCCESS) return r;
    for (z = cells->lo[2]; z < cells->hi[2]; ++z)
        for (y = cells->lo[1]; y < cells->hi[1]; ++y) {
            size_t at = ((size_t)z * vw->mdims[1] + y) * vw->mdims[0] + (size_t)cells->lo[0];
            memcpy((float *)be->maj.map + at, vw->majorant + at, (size_t)(cells->hi[0] - cells->lo[0]) * sizeof(float));
        }
    return HD_SUCCESS;
}

static hd_result hd__be_alloc_illumination(const hd__view *vw, size_t illum_floats)
{
    hd__backend *be = vw->be;
    hd_result r;
    HD__VK_IDLE(vw);
    be->sets_valid = 0; /* the placeholders bound for absent E / phi / phi2 follow the precision */
    if ((r = hd__vk_half_ok(vw)) != HD_SUCCESS) { /* after hd_set_params */
        hd__gpu_alloc_illumination(vw, &be->gg, 0);
        return r;
    }
    return hd__gpu_alloc_illumination(vw, &be->gg, illum_floats);
}

static hd_result hd__be_alloc_jacobi(const hd__view *vw, int enable)
{
    HD__VK_IDLE(vw);
    return hd__gpu_alloc_jacobi(vw, &vw->be->gg, enable);
}

static hd_result hd__be_alloc_image(const hd__view *vw, int width, int height, int parts)
{
    hd__backend *be = vw->be;
    size_t floats = hd__image_floats(width, height, parts);
    VkDeviceSize bytes = (VkDeviceSize)floats * sizeof(float);
    hd__vk_buffer img;
    hd_result r;
    HD__VK_IDLE(vw);
    if (be->rec) /* a recorded command names the buffer: hd_vulkan_record makes it before recording */
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: the image buffer changed while recording (internal error)");
    if (bytes > be->limits.maxStorageBufferRange)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: a %dx%d image%s needs %llu bytes, above maxStorageBufferRange = %u",
                       width, height, hd__image_parts_name(parts), (unsigned long long)bytes,
                       be->limits.maxStorageBufferRange);
    if ((r = hd__vk_buffer_create(vw, &img, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT, 0, (parts & HD__IMAGE_REDUCED) ? "the image with room for reduced frames" : "the image")) !=
        HD_SUCCESS) {
        hd__vk_free_buffer(vw, &img);
        return r;
    }
    hd__vk_free_buffer(vw, &be->img);
    be->img = img;
    be->img_floats = floats;
    return HD_SUCCESS;
}

static hd_result hd__be_clear(const hd__view *vw, unsigned what)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if ((r = hd__gpu_clear(vw, &be->gg, what)) != HD_SUCCESS) return r;
    if ((what & HD__DIRTY_IMAGE) && be->img.buffer) {
        if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
        hd__vk_barrier(be, cb);
        be->fn.vkCmdFillBuffer(cb, be->img.buffer, 0, VK_WHOLE_SIZE, 0u);
    }
    return HD_SUCCESS;
}

/* ---- stages ------------------------------------------------------------------------------------ */
/* Stage p (not the diffusion) as one dispatch of its pipeline (hd__vk_stage_pipeline) over
   nx x ny x nz with set 0 and push constants (pc0, 0, 0, 0), then submitted. */
static hd_result hd__vk_stage(const hd__view *vw, int p, int nx, int ny, int nz, int pc0)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkPipeline pipe;
    hd_result r;
    if ((r = hd__vk_stage_pipeline(vw, p, &pipe)) != HD_SUCCESS || (r = hd__vk_begin(vw, &cb)) != HD_SUCCESS ||
        (r = hd__vk_dispatch(vw, cb, pipe, 0, nx, ny, nz, pc0, 0, 0, 0)) != HD_SUCCESS)
        return r;
    return hd__vk_flush(vw);
}

static hd_result hd__be_classify(const hd__view *vw)
{
    return hd__vk_stage(vw, HD__VK_CLASSIFY, vw->gdims[0], vw->gdims[1], vw->gdims[2], 0);
}

/* Uploads the direct light's list of voxels (rebuilt with sigma_t) into a host-visible buffer;
   the sets are rewritten (nothing is in flight here). */
/* The host's depth buffer (host-visible, binding 15), made again when its size changes; freed
   without one (the sets then bind the placeholder). */
static hd_result hd__be_upload_depth(const hd__view *vw)
{
    hd__backend *be = vw->be;
    size_t n = vw->depth ? (size_t)vw->depth_w * vw->depth_h : 0;
    hd_result r;
    if (!vw->depth && vw->depth_device) return HD_SUCCESS; /* hd__be_record_depth's copy, kept */
    HD__VK_IDLE(vw);
    if (!vw->depth || !be->dep.buffer || be->dep_floats != n) {
        hd__vk_free_buffer(vw, &be->dep);
        be->dep_floats = 0;
        be->sets_valid = 0;
        if (!vw->depth) return HD_SUCCESS;
        if ((r = hd__vk_buffer_create(vw, &be->dep, n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      1, "the depth buffer")) != HD_SUCCESS)
            return r;
        be->dep_floats = n;
    }
    memcpy(be->dep.map, vw->depth, n * sizeof(float));
    return HD_SUCCESS;
}

/* The environment's tables (host-visible, binding 16), made anew; freed without them (the sets
   then bind the placeholder). */
static hd_result hd__be_upload_env(const hd__view *vw)
{
    hd__backend *be = vw->be;
    hd_result r;
    HD__VK_IDLE(vw);
    hd__vk_free_buffer(vw, &be->env);
    be->sets_valid = 0;
    if (!vw->env) return HD_SUCCESS;
    if ((r = hd__vk_buffer_create(vw, &be->env, vw->env_floats * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1,
                                  "the environment's tables")) != HD_SUCCESS)
        return r;
    memcpy(be->env.map, vw->env, vw->env_floats * sizeof(float));
    return HD_SUCCESS;
}

/* The depth layouts a copy may start from (hd_vulkan_depth.layout). */
static int hd__vk_depth_layout(int l)
{
    return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL || l == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL ||
           l == VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL || l == VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL ||
           l == VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_STENCIL_ATTACHMENT_OPTIMAL || l == VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_STENCIL_READ_ONLY_OPTIMAL;
}

/* The host's depth image or buffer copied into dep inside the caller's command buffer: dep made
   first (the camera's size, host-visible as hd__be_upload_depth's, a transfer's destination),
   then barrier, [transition,] copy, [transition back,] barrier. */
static hd_result hd__be_record_depth(const hd__view *vw, void *cbp, const hd_vulkan_depth *d)
{
    const char *fn = "hd_vulkan_record_depth";
    hd__backend *be = vw->be;
    VkCommandBuffer cb = (VkCommandBuffer)cbp;
    size_t n = (size_t)vw->camera.width * vw->camera.height;
    VkMemoryBarrier mb;
    hd_result r;
    int stencil = d->format == VK_FORMAT_D32_SFLOAT_S8_UINT;
    if (d->image && d->format != VK_FORMAT_D32_SFLOAT && !stencil)
        return HD__ERR(&vw->log, HD_ERROR_DEPTH_FORMAT, "%s: image format %d; needs VK_FORMAT_D32_SFLOAT or D32_SFLOAT_S8_UINT (float depth)", fn,
                       d->format);
    if (d->image && !hd__vk_depth_layout(d->layout))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_PARAMETER, "%s: layout %d is not one a depth image is copied from", fn, d->layout);
    if (!be->dep.buffer || be->dep_floats != n) {
        HD__VK_IDLE(vw);
        hd__vk_free_buffer(vw, &be->dep);
        be->dep_floats = 0;
        be->sets_valid = 0;
        if ((r = hd__vk_buffer_create(vw, &be->dep, n * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      1, "the depth buffer")) != HD_SUCCESS)
            return r;
        be->dep_floats = n;
    }
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    if (d->image) {
        VkImageMemoryBarrier ib;
        VkBufferImageCopy reg;
        memset(&ib, 0, sizeof ib);
        ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        ib.srcAccessMask = mb.srcAccessMask;
        ib.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        ib.oldLayout = (VkImageLayout)d->layout;
        ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        ib.image = (VkImage)d->image;
        ib.subresourceRange.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT | (stencil ? VK_IMAGE_ASPECT_STENCIL_BIT : 0);
        ib.subresourceRange.levelCount = 1;
        ib.subresourceRange.layerCount = 1;
        be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, NULL, 1, &ib);
        memset(&reg, 0, sizeof reg);
        reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
        reg.imageSubresource.layerCount = 1;
        reg.imageExtent.width = (uint32_t)vw->camera.width;
        reg.imageExtent.height = (uint32_t)vw->camera.height;
        reg.imageExtent.depth = 1;
        be->fn.vkCmdCopyImageToBuffer(cb, ib.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, be->dep.buffer, 1, &reg);
        ib.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        ib.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        ib.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        ib.newLayout = (VkImageLayout)d->layout;
        mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &mb, 0, NULL, 1, &ib);
    } else {
        VkBufferCopy bc;
        be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
        memset(&bc, 0, sizeof bc);
        bc.srcOffset = (VkDeviceSize)d->offset;
        bc.size = (VkDeviceSize)(n * sizeof(float));
        be->fn.vkCmdCopyBuffer(cb, (VkBuffer)d->buffer, be->dep.buffer, 1, &bc);
        mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        mb.dstAccessMask = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
        be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
    }
    return HD_SUCCESS;
}

static hd_result hd__be_direct_list(const hd__view *vw)
{
    hd__backend *be = vw->be;
    hd_result r;
    HD__VK_IDLE(vw);
    hd__vk_free_buffer(vw, &be->dl);
    if ((r = hd__vk_buffer_create(vw, &be->dl, vw->dl_count * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1,
                                  "the direct light's list")) != HD_SUCCESS)
        return r;
    if (vw->dl_count) memcpy(be->dl.map, vw->dl_idx, vw->dl_count * sizeof(uint32_t));
    return HD_SUCCESS;
}

/* Every stage is submitted and waited for as it is enqueued (hd__vk_flush), outside a recording. */
static hd_result hd__be_wait(const hd__view *vw) { return hd__vk_flush(vw); }

/* The direct stage over the list, in rows of at most HD__DIRECT_ROW entries (a dispatch's work
   groups along x are limited to maxComputeWorkGroupCount, at least 65535). */
#define HD__DIRECT_ROW ((int)HD__VK_LOCAL_X * 32768)
static hd_result hd__be_direct(const hd__view *vw, size_t first, size_t count)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkPipeline pipe;
    hd_result r;
    int n = (int)count, rows = (n + HD__DIRECT_ROW - 1) / HD__DIRECT_ROW;
    vw->be->gg.lsum_ok = 0;
    if (n == 0) return HD_SUCCESS;
    if ((r = hd__vk_stage_pipeline(vw, HD__VK_DIRECT, &pipe)) != HD_SUCCESS || (r = hd__vk_begin(vw, &cb)) != HD_SUCCESS ||
        (r = hd__vk_dispatch(vw, cb, pipe, 0, rows > 1 ? HD__DIRECT_ROW : n, rows, 1, n, (int)first, 0, 0)) != HD_SUCCESS)
        return r;
    return hd__vk_flush(vw);
}

/* One full sweep: two half-sweeps (red, black; half the voxels of each row per dispatch) or one
   Jacobi pass, phi -> phi2, and a copy back (the descriptor sets stay fixed, which recorded
   command buffers need). */
static hd_result hd__be_diffuse(const hd__view *vw, int jacobi)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    /* invocations along y and z: blocks of diffuse_yk rows and diffuse_zk slices, nzb per channel
       (push constant z, hd_entry_glsl.h) */
    int ny = (vw->gdims[1] + be->diffuse_yk - 1) / be->diffuse_yk, nzb = (vw->gdims[2] + be->diffuse_zk - 1) / be->diffuse_zk;
    int nz = nzb * vw->channels;
    VkPipeline pipe;
    be->gg.lsum_ok = 0;
    if ((r = hd__vk_begin(vw, &cb)) != HD_SUCCESS) return r;
    if ((r = hd__vk_diffuse_pipeline(vw, jacobi ? 1 : 0, &pipe)) != HD_SUCCESS) return r;
    if (jacobi) {
        if ((r = hd__vk_dispatch(vw, cb, pipe, 0, vw->gdims[0], ny, nz, 0, 1, nzb, 0)) != HD_SUCCESS) return r;
        hd__vk_copy_image(be, cb, &be->phi2, &be->phi);
    } else {
        int parity;
        for (parity = 0; parity < 2; ++parity)
            if ((r = hd__vk_dispatch(vw, cb, pipe, 0, (vw->gdims[0] + 1) / 2, ny, nz, parity, 0, nzb, 0)) != HD_SUCCESS)
                return r;
    }
    return hd__vk_flush(vw);
}

/* E + phi into lsum (the light-sum stage), dispatched into cb, where a pass changed them since. */
static hd_result hd__vk_light_sum(const hd__view *vw, VkCommandBuffer cb)
{
    VkPipeline sum;
    hd_result r;
    if (vw->be->gg.lsum_ok) return HD_SUCCESS;
    if ((r = hd__vk_stage_pipeline(vw, HD__VK_LIGHT_SUM, &sum)) != HD_SUCCESS ||
        (r = hd__vk_dispatch(vw, cb, sum, 0, vw->gdims[0], vw->gdims[1], vw->gdims[2] * vw->channels, 0, 0, 0, 0)) != HD_SUCCESS)
        return r;
    vw->be->gg.lsum_ok = 1;
    return HD_SUCCESS;
}

/* hd_vulkan_record_refine's sum, into the caller's command buffer. */
static hd_result hd__be_record_light_sum(const hd__view *vw)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if (!vw->be->rec) return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: the light's sum recorded outside a recording (internal error)");
    if ((r = hd__vk_begin(vw, &cb)) != HD_SUCCESS) return r;
    return hd__vk_light_sum(vw, cb);
}

/* The projection, after its inputs: lsum rebuilt (the light-sum stage) when a pass changed E or
   phi since, and the TF table (hd__project_table) written when it differs from the one in the
   buffer. A recorded frame reads the table as it is when the command buffer runs, as the TF. */
static hd_result hd__be_project(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkPipeline proj;
    int n = hd__project_table_n(vw), nb, p;
    hd_result r;
    if (!be->ptab.map || be->ptab_cap != n)
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: the projection's TF table has no room for %d entries (internal error)",
                       n);
    if (!hd__project_table_key_same(vw, &be->ptab_key)) {
        hd__project_table(vw, (float *)be->ptab.map, n); /* written in place: the table is only written */
        be->ptab_key = hd__project_table_key(vw);
        be->ptab_n = n;
    }
    if ((r = hd__vk_stage_pipeline(vw, HD__VK_PROJECT, &proj)) != HD_SUCCESS || (r = hd__vk_begin(vw, &cb)) != HD_SUCCESS ||
        (r = hd__vk_light_sum(vw, cb)) != HD_SUCCESS)
        return r;
    nb = (vw->kp.image.y + HD__GPU_ROW_BLOCK - 1) / HD__GPU_ROW_BLOCK;
    p = be->spread_rows ? hd__gpu_row_stride(nb) : 1;
    if ((r = hd__vk_dispatch(vw, cb, proj, 0, vw->kp.image.x, p > 1 ? nb * HD__GPU_ROW_BLOCK : vw->kp.image.y, 1, n, p,
                             HD__GPU_ROW_BLOCK, 0)) != HD_SUCCESS)
        return r;
    return hd__vk_flush(vw);
}

/* The upsample pass: its own small pipeline (HD_STAGE_UPSAMPLE), one invocation per pixel. */
static hd_result hd__be_upsample(const hd__view *vw)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if ((r = hd__vk_begin(vw, &cb)) != HD_SUCCESS) return r;
    if ((r = hd__vk_dispatch(vw, cb, vw->be->pipelines[HD__VK_UPSAMPLE], 0, vw->kp.image.x, vw->kp.image.y, 1, 0, 0, 0, 0)) != HD_SUCCESS)
        return r;
    return hd__vk_flush(vw);
}

/* ---- read-back ------------------------------------------------------------------------------- */
/* Floats [first, first + n) of the image buffer into dst. */
static hd_result hd__vk_read_img(const hd__view *vw, size_t first, size_t n, float *dst)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkBufferCopy bc;
    size_t bytes = n * sizeof(float);
    hd_result r;
    HD__VK_IDLE(vw);
    if ((r = hd__vk_staging(vw, bytes)) != HD_SUCCESS) return r;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
    hd__vk_barrier(be, cb);
    memset(&bc, 0, sizeof bc);
    bc.srcOffset = first * sizeof(float);
    bc.size = bytes;
    be->fn.vkCmdCopyBuffer(cb, be->img.buffer, be->staging.buffer, 1, &bc);
    hd__vk_barrier(be, cb);
    if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r;
    memcpy(dst, be->staging.map, bytes);
    return HD_SUCCESS;
}
static hd_result hd__be_read_image(const hd__view *vw, float *dst)
{
    return hd__vk_read_img(vw, 0, (size_t)vw->kp.image.x * vw->kp.image.y * 4, dst);
}
static hd_result hd__be_read_depth(const hd__view *vw, float *dst)
{
    return hd__vk_read_img(vw, (size_t)vw->kp.region.z, (size_t)vw->kp.image.x * vw->kp.image.y, dst);
}

static hd_result hd__be_read_illumination(const hd__view *vw, hd_illumination which, const int *zz, int count, float *dst)
{
    return hd__vk_download_image(vw, which == HD_ILLUMINATION_DIRECT ? &vw->be->E : &vw->be->phi, dst, zz, count);
}

#ifdef HYBRIDDIFF_TESTING
/* For src/hd_test_hooks.h: overwrites E or phi (channel-planar floats). */
HD__MAYBE_UNUSED static hd_result hd__vk_write_illumination(const hd__view *vw, hd_illumination which, const float *src)
{
    vw->be->gg.lsum_ok = 0;
    return hd__vk_upload_image(vw, which == HD_ILLUMINATION_DIRECT ? &vw->be->E : &vw->be->phi, src);
}
#endif

/* ---- CD: light volumes, convection, their sum into E ---------------------------------------- */
static hd_result hd__be_alloc_lights(const hd__view *vw, int count)
{
    HD__VK_IDLE(vw);
    return hd__gpu_alloc_lights(vw, &vw->be->gg, count);
}

/* One convection step of light `light`: its volume -> the spare, copied back (the CPU backend
   swaps the two instead; a copy keeps the descriptor sets fixed for recorded command buffers). */
static hd_result hd__be_convect(const hd__view *vw, int light)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if ((r = hd__vk_begin(vw, &cb)) != HD_SUCCESS) return r;
    if ((r = hd__vk_dispatch(vw, cb, vw->be->pipelines[HD__VK_CONVECT], light, vw->gdims[0], vw->gdims[1], vw->gdims[2], 0, 0, light, 0)) != HD_SUCCESS)
        return r;
    hd__vk_copy_image(be, cb, &be->lv[be->gg.nlv], &be->lv[light]);
    return hd__vk_flush(vw);
}

/* E = sum over the lights of colour * falloff * light volume, the first pass overwriting E. */
static hd_result hd__be_sum_lights(const hd__view *vw)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    int l;
    VkPipeline pipe;
    vw->be->gg.lsum_ok = 0;
    if ((r = hd__vk_stage_pipeline(vw, HD__VK_SUM_LIGHT, &pipe)) != HD_SUCCESS) return r;
    if ((r = hd__vk_begin(vw, &cb)) != HD_SUCCESS) return r;
    for (l = 0; l < vw->be->gg.nlv; ++l)
        if ((r = hd__vk_dispatch(vw, cb, pipe, l, vw->gdims[0], vw->gdims[1], vw->gdims[2], 0, 0, l, l == 0)) != HD_SUCCESS)
            return r;
    return hd__vk_flush(vw);
}

/* ---- PT_SS / PT_MS ------------------------------------------------------------------------------ */
static hd_result hd__be_path(const hd__view *vw)
{
    return hd__vk_stage(vw, HD__VK_PATH, vw->kp.image.x, vw->kp.image.y, 1, 0);
}

/* ---- HD_SOLVER_MULTIGRID ------------------------------------------------------------------------
   The per-level primitives of src/hd_multigrid.h's step (docs/DESIGN-MULTIGRID.md), structured as
   the GL port (hd_gl.h): the per-voxel math is the shared hd_k_multigrid.h (entry points
   hd_entry_glsl_multigrid.h, SPIR-V hd__spv_mg_*), the V-cycle's smoothing the diffusion pipeline
   specialized with HD_FLAG_DIFFUSE_RHS on each level's own parameter block. Every level's sigma_t / rhs / phi / residual and CG's
   p and lo are r32f storage images like the backend's own; the double passes need shaderFloat64;
   the dot products are summed per row on the device (x in order, doubles into a host-visible
   storage buffer at binding 11) and the rows in row order by the core, as on the CPU.
   Vulkan binds through descriptor sets, not per pass as GL does: each pass's combination of
   images (a level's smoothing, a restriction, ...) is a set of the multigrid's own pool, written
   when the levels are made and again whenever the backend's sets are rebuilt (its sigma_t, E and
   phi may be new: be->sets_gen); the parameter blocks are slots of the multigrid's own uniform
   buffer, one per level and one for the fine vw->kp, bound with a dynamic offset.
   The passes are recorded into the backend's command buffer (hd__vk_cmd) and submitted at each
   read-back of the row sums and at the end: three submissions a step, each waited for, so
   hd_vulkan_record cannot record it (HD_ERROR_UNSUPPORTED there). */
/* Bytes the solver holds on the device (counted in method_bytes); 0 without it. */
static size_t hd__be_solver_bytes(const hd__view *vw) { return hd__gpu_solver_bytes(vw, &vw->be->gg); }
static const char *hd__be_mg_unavailable(const hd__view *vw) { return vw->be->no_f64; }
static hd__gpu_grids *hd__gpu_grids_of(const hd__view *vw) { return &vw->be->gg; }

/* The row-sum buffers, the parameter slots and the set pool; nothing of theirs may be in flight
   when they are freed (each step ends waited for). */
static hd_result hd__gpu_mg_extras(const hd__view *vw, int make)
{
    hd__backend *be = vw->be;
    struct hd__vk_mg *mg = &be->mg;
    VkDeviceSize align = be->limits.minUniformBufferOffsetAlignment ? be->limits.minUniformBufferOffsetAlignment : 256;
    size_t rows = hd__gpu_mg_rows(&be->gg);
    hd_result r;
    hd__vk_free_buffer(vw, &mg->dot_a); hd__vk_free_buffer(vw, &mg->dot_b); hd__vk_free_buffer(vw, &mg->params);
    if (mg->pool) be->fn.vkDestroyDescriptorPool(be->device, mg->pool, NULL);
    mg->pool = VK_NULL_HANDLE;
    mg->sets_valid = 0;
    if (!make) return HD_SUCCESS;
    mg->slot_bytes = (sizeof(hd__kparams) + align - 1) / align * align;
    if ((r = hd__vk_buffer_create(vw, &mg->dot_a, rows * sizeof(double), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1,
                                  "multigrid's row sums")) != HD_SUCCESS ||
        (r = hd__vk_buffer_create(vw, &mg->dot_b, rows * sizeof(double), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1,
                                  "multigrid's row sums")) != HD_SUCCESS ||
        (r = hd__vk_buffer_create(vw, &mg->params, mg->slot_bytes * (VkDeviceSize)(be->gg.levels + 1),
                                  VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, 1, "multigrid's parameter blocks")) != HD_SUCCESS)
        return r;
    return hd__vk_pool(vw, HD__GPU_MG_SETS, &mg->pool);
}

/* Every pass's set (backends/hd_gpu.h's hd__gpu_mg_set: sigma_t, E, phi, phi2 and the other grid at
   bindings 4..7 and 10, the row sums at 11), written when the levels are new or the backend's
   sets were rebuilt since (its grids may be new). Nothing is in flight. */
static hd_result hd__vk_mg_sets(const hd__view *vw)
{
    static const int binding[5] = {4, 5, 6, 7, 10};
    hd__backend *be = vw->be;
    struct hd__vk_mg *mg = &be->mg;
    hd_result r;
    int n = HD__GPU_MG_CG(&be->gg, HD__GPU_MG_CG_SETS), s, i;
    if (mg->sets_valid && mg->sets_gen == be->sets_gen) return HD_SUCCESS;
    mg->sets_valid = 0;
    if ((r = hd__vk_pool_sets(vw, mg->pool, n, mg->sets, "vkResetDescriptorPool (multigrid)",
                              "vkAllocateDescriptorSets (multigrid)")) != HD_SUCCESS)
        return r;
    for (s = 0; s < n; ++s) {
        const hd__vk_image *im[HD__VK_BINDINGS];
        const hd__vk_buffer *bu[HD__VK_BINDINGS];
        hd__gpu_mg_binds b;
        if (!hd__gpu_mg_set(&be->gg, s, &b)) continue;
        memset(im, 0, sizeof im);
        memset(bu, 0, sizeof bu);
        hd__vk_common_buffers(be, bu, b.dot == 1 ? &mg->dot_a : b.dot == 2 ? &mg->dot_b : NULL);
        im[1] = &be->vol;
        for (i = 0; i < 5; ++i) im[binding[i]] = b.grid[i] < 0 ? NULL : hd__vk_grid(be, b.grid[i]);
        hd__vk_write_set(vw, mg->sets[s], &mg->params, im, bu);
    }
    mg->sets_gen = be->sets_gen;
    mg->sets_valid = 1;
    return HD_SUCCESS;
}

/* Parameter block kp into slot l (level l's; slot `levels`: the fine one). Nothing is in flight:
   each step ends waited for. */
static hd_result hd__gpu_mg_send(const hd__view *vw, int l, const hd__kparams *kp)
{
    memcpy((char *)vw->be->mg.params.map + (size_t)l * vw->be->mg.slot_bytes, kp, sizeof *kp);
    return HD_SUCCESS;
}

/* The pipeline of multigrid pass `stage` for the current flags, made on first use. */
static hd_result hd__vk_mg_pipeline(const hd__view *vw, int stage, VkPipeline *out)
{
    static const uint32_t *const code[HD__MG_STAGES] = {hd__spv_mg_sig, hd__spv_mg_residual, hd__spv_mg_restrict,
                                                           hd__spv_mg_prolong, hd__spv_mg_dir, hd__spv_mg_res_f64,
                                                           hd__spv_mg_dot, hd__spv_mg_update, hd__spv_mg_extrap};
    static const size_t size[HD__MG_STAGES] = {sizeof hd__spv_mg_sig, sizeof hd__spv_mg_residual, sizeof hd__spv_mg_restrict,
                                                  sizeof hd__spv_mg_prolong, sizeof hd__spv_mg_dir, sizeof hd__spv_mg_res_f64,
                                                  sizeof hd__spv_mg_dot, sizeof hd__spv_mg_update,
                                                  sizeof hd__spv_mg_extrap};
    hd__backend *be = vw->be;
    int f, variant = hd__gpu_mg_variant(stage, vw->kp.counts.z, &f);
    VkPipeline *slot = &be->mg_pipes[variant];
    int32_t flags = (int32_t)f;
    hd_result r;
    if (!*slot && (r = hd__vk_pipeline_code(vw, code[stage - 1], size[stage - 1], &flags, 0, slot)) != HD_SUCCESS) {
        HD__INFO(&vw->log, "vulkan: making the %s pipeline failed", hd__mg_stage_names[stage - 1]);
        return r;
    }
    *out = *slot;
    return HD_SUCCESS;
}

/* Records pass p into the backend's command buffer with its set and parameter slot; the
   direction's beta (its bits) and the update's alpha (low and high words: packDouble2x32's x and
   y; the host's byte order is the device's) in hd_pc.x and .y. */
static hd_result hd__gpu_mg_pass(const hd__view *vw, const hd__gpu_mg_run *p)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkPipeline pipe;
    int32_t pc[4];
    uint64_t u;
    hd_result r;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS || (r = hd__vk_mg_pipeline(vw, p->stage, &pipe)) != HD_SUCCESS) return r;
    memcpy(pc, p->pc, sizeof pc);
    if (p->stage == HD__MG_DIR) memcpy(&pc[0], &p->beta, sizeof p->beta);
    if (p->stage == HD__MG_UPDATE) {
        memcpy(&u, &p->alpha, sizeof u);
        pc[0] = (int32_t)(uint32_t)u;
        pc[1] = (int32_t)(uint32_t)(u >> 32);
    }
    hd__vk_record_dispatch(be, cb, pipe, be->mg.sets[p->set], (uint32_t)((VkDeviceSize)p->slot * be->mg.slot_bytes), p->n[0],
                           p->n[1], p->n[2], pc);
    return HD_SUCCESS;
}

/* Level l's smoothing: the diffusion pipeline with HD_FLAG_DIFFUSE_RHS on its parameter slot. */
static hd_result hd__be_mg_smooth(const hd__view *vw, int l, int sweeps, int first)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    const int *d = be->gg.lv[l].dims;
    int ny = (d[1] + be->diffuse_yk - 1) / be->diffuse_yk, nzb = (d[2] + be->diffuse_zk - 1) / be->diffuse_zk;
    int32_t flags = be->gg.lv[l].kp.counts.z & (HD_FLAG_RGB_SCATTERING | HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_DIFFUSE_RHS);
    uint32_t offset = (uint32_t)((VkDeviceSize)l * be->mg.slot_bytes);
    VkPipeline pipe;
    hd_result r;
    int s, h;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS || (r = hd__vk_diffuse_pipeline_for(vw, flags, 0, &pipe)) != HD_SUCCESS) return r;
    for (s = 0; s < sweeps; ++s)
        for (h = 0; h < 2; ++h) {
            int32_t pc[4];
            pc[0] = first ^ h; pc[1] = 0; pc[2] = nzb; pc[3] = 0;
            hd__vk_record_dispatch(be, cb, pipe, be->mg.sets[HD__GPU_MG_SET(l, HD__GPU_MG_SMOOTH)], offset, (d[0] + 1) / 2, ny, nzb * be->gg.channels, pc);
        }
    return HD_SUCCESS;
}

/* ---- the step's primitives (src/hd_backend.h) ------------------------------------------------ */
/* Submits what is pending, makes the levels, writes the parameter slots and the sets; the step's
   passes are recorded into one command buffer up to each read-back (hd__be_mg_row_sums), so a
   step is three submissions. */
static hd_result hd__be_mg_begin(const hd__view *vw, int *fresh)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    if (be->no_f64)
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "vulkan: solver MULTIGRID is not available on %s: %s", be->device_name,
                       be->no_f64);
    if (be->rec) /* hd_vulkan_record refuses the solver before it starts */
        return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: a multigrid step while recording (internal error)");
    if ((r = hd__vk_flush(vw)) != HD_SUCCESS || (r = hd__gpu_mg_begin(vw, &be->gg, fresh)) != HD_SUCCESS ||
        (r = hd__gpu_mg_send(vw, be->gg.levels, &vw->kp)) != HD_SUCCESS)
        return r;
    if ((r = hd__vk_begin(vw, &cb)) != HD_SUCCESS) return r; /* submits the new images' clears, rebuilds be->sets */
    return hd__vk_mg_sets(vw);
}

static hd_result hd__be_mg_end(const hd__view *vw, hd_result r)
{
    VkCommandBuffer cb = VK_NULL_HANDLE;
    if (r != HD_SUCCESS) return r;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
    return hd__vk_flush(vw);
}

/* Submits what was recorded, the row sums made visible to the host, and waits; the sums are read
   in the host-visible buffers themselves. */
static hd_result hd__be_mg_row_sums(const hd__view *vw, int n, const double **a, const double **b)
{
    struct hd__vk_mg *mg = &vw->be->mg;
    VkCommandBuffer cb = VK_NULL_HANDLE;
    hd_result r;
    (void)n;
    if ((r = hd__vk_cmd(vw, &cb)) != HD_SUCCESS) return r;
    hd__vk_barrier(vw->be, cb);
    if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r;
    *a = (const double *)mg->dot_a.map;
    *b = (const double *)mg->dot_b.map;
    return HD_SUCCESS;
}

/* The single-level solver's sweeps: each its own submission. */
static hd_result hd__be_diffuse_sweeps(const hd__view *vw, int jacobi, int sweeps) { return hd__be_diffuse_each(vw, jacobi, sweeps); }

/* ---- recording into the caller's command buffer (HD__BE_RECORD) ------------------------------- */
static unsigned hd__be_features(void) { return HD__BE_RECORD; }

/* The timestamp pool for recorded frames, made on the first recording; none (ts_state -1) where
   the queue family has no timestamps, and then HD_RENDER_SCALE_AUTO has no frame time to go on
   while recording (its first scale stays 4, or what an unrecorded frame measured). */
static hd_result hd__vk_timestamps(const hd__view *vw)
{
    hd__backend *be = vw->be;
    VkQueueFamilyProperties q[32];
    VkQueryPoolCreateInfo qpci;
    uint32_t n = 32, bits;
    if (be->ts_state != 0) return HD_SUCCESS;
    be->fn.vkGetPhysicalDeviceQueueFamilyProperties(be->phys, &n, q);
    bits = be->queue_family < n && be->queue_family < 32 ? q[be->queue_family].timestampValidBits : 0;
    if (bits == 0) {
        be->ts_state = -1;
        HD__INFO(&vw->log, "vulkan: queue family %u has no timestamps: recorded frames are not timed for HD_RENDER_SCALE_AUTO",
                 be->queue_family);
        return HD_SUCCESS;
    }
    be->ts_mask = bits >= 64 ? ~(uint64_t)0 : (((uint64_t)1 << bits) - 1);
    memset(&qpci, 0, sizeof qpci);
    qpci.sType = VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO;
    qpci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qpci.queryCount = 2;
    HD__VK_TRY(vw, be->fn.vkCreateQueryPool(be->device, &qpci, NULL, &be->ts_pool), "vkCreateQueryPool");
    be->ts_state = 1;
    return HD_SUCCESS;
}

/* The last recorded frame's device time (the caller has run the command buffer by now). */
static int hd__be_record_seconds(const hd__view *vw, double *seconds)
{
    hd__backend *be = vw->be;
    uint64_t t[2];
    VkResult e;
    if (!be->ts_pending) return 0;
    be->ts_pending = 0;
    e = be->fn.vkGetQueryPoolResults(be->device, be->ts_pool, 0, 2, sizeof t, t, sizeof t[0], VK_QUERY_RESULT_64_BIT);
    if (e != VK_SUCCESS) return 0;
    *seconds = (double)((t[1] - t[0]) & be->ts_mask) * (double)be->limits.timestampPeriod * 1e-9;
    return 1;
}

/* A timestamp before (end 0) and after (end 1) a recorded frame. */
static void hd__be_record_mark(const hd__view *vw, int end)
{
    hd__backend *be = vw->be;
    if (!be->ts_pool) return;
    if (!end) {
        be->fn.vkCmdResetQueryPool(be->rec, be->ts_pool, 0, 2);
        be->fn.vkCmdWriteTimestamp(be->rec, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, be->ts_pool, 0);
    } else {
        be->fn.vkCmdWriteTimestamp(be->rec, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, be->ts_pool, 1);
        be->ts_pending = 1;
    }
}

/* Recording into cb starts after the preparation's work is submitted and waited for: only
   iterations are recorded, each with its own parameter slots. */
static hd_result hd__be_record_begin(const hd__view *vw, void *target, int slots)
{
    hd__backend *be = vw->be;
    hd_result r;
    if ((r = hd__vk_flush(vw)) != HD_SUCCESS) return r;
    if ((r = hd__vk_timestamps(vw)) != HD_SUCCESS) return r;
    if ((r = hd__vk_ring(vw, (uint32_t)slots)) != HD_SUCCESS) return r;
    if ((r = hd__vk_sets(vw)) != HD_SUCCESS) return r;
    be->next_slot = 0;
    be->have_slot = 0;
    be->rec = (VkCommandBuffer)target;
    be->ts_pending = 0;
    return HD_SUCCESS;
}

static hd_result hd__be_record_end(const hd__view *vw, hd_result r)
{
    hd__backend *be = vw->be;
    if (r == HD_SUCCESS) hd__vk_barrier(be, be->rec); /* the caller's next commands see the results */
    else be->ts_pending = 0;                           /* a failed recording is not submitted */
    be->rec = VK_NULL_HANDLE;
    return r;
}

/* ---- the image into the caller's image or buffer (hd_vulkan_record_render) --------------------- */
/* Whether VkFormat f takes output format o; *swap: B and R swapped (a BGRA format). */
static int hd__vk_output_takes(int f, hd_output_format o, int *swap)
{
    *swap = f == VK_FORMAT_B8G8R8A8_UNORM || f == VK_FORMAT_B8G8R8A8_SRGB;
    if (o == HD_OUTPUT_SRGB8)
        return f == VK_FORMAT_R8G8B8A8_UNORM || f == VK_FORMAT_R8G8B8A8_SRGB || f == VK_FORMAT_B8G8R8A8_UNORM ||
               f == VK_FORMAT_B8G8R8A8_SRGB;
    return f == (o == HD_OUTPUT_LINEAR_F16 ? VK_FORMAT_R16G16B16A16_SFLOAT : VK_FORMAT_R32G32B32A32_SFLOAT);
}

/* A color image's layouts a transfer may start from (before: UNDEFINED and PREINITIALIZED too). */
static int hd__vk_output_layout(int l, int before)
{
    return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL ||
           l == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL || l == VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL ||
           l == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL || l == VK_IMAGE_LAYOUT_PRESENT_SRC_KHR ||
           (before && (l == VK_IMAGE_LAYOUT_UNDEFINED || l == VK_IMAGE_LAYOUT_PREINITIALIZED));
}

static hd_result hd__be_output_target_check(const hd__view *vw, const hd_vulkan_target *t, const hd_output *out)
{
    int swap;
    if (!t->image) return HD_SUCCESS; /* a buffer: the core has checked its rows */
    if (!hd__vk_output_takes(t->format, out->format, &swap))
        return HD__ERR(&vw->log, HD_ERROR_OUTPUT_FORMAT, "hd_vulkan_record_render: VkFormat %d does not take output format %d (%s)",
                       t->format, (int)out->format,
                       out->format == HD_OUTPUT_SRGB8         ? "R8G8B8A8 or B8G8R8A8, UNORM or SRGB"
                       : out->format == HD_OUTPUT_LINEAR_F16 ? "R16G16B16A16_SFLOAT"
                                                             : "R32G32B32A32_SFLOAT");
    if (!hd__vk_output_layout(t->layout, 1))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_ENUM, "hd_vulkan_record_render: layout %d is not a color image's layout a copy can start from",
                       t->layout);
    if (t->final_layout ? !hd__vk_output_layout(t->final_layout, 0) : !hd__vk_output_layout(t->layout, 0))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_ENUM, "hd_vulkan_record_render: final_layout %d%s is not a layout to leave a color image in",
                       t->final_layout ? t->final_layout : t->layout, t->final_layout ? "" : " (0: layout)");
    return HD_SUCCESS;
}

/* The output pass's objects, made on first use: set layout (three storage buffers) and pipeline
   layout (20 bytes of push constants), pipeline, a pool of one set, the thresholds; the encoded
   image at least `bytes` long; the set rewritten when the image or the encoded image is a new
   buffer (nothing is in flight: hd_vulkan_record_render's contract). */
static hd_result hd__vk_output_prepare(const hd__view *vw, VkDeviceSize bytes)
{
    static const VkDescriptorType types[3] = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER,
                                              VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    hd__backend *be = vw->be;
    hd_result r;
    if (!be->out_pipe) {
        VkDescriptorPoolSize ps;
        VkDescriptorPoolCreateInfo dpci;
        VkDescriptorSetAllocateInfo ai;
        if (!be->out_layout &&
            (r = hd__vk_layouts(vw, types, 3, 5 * sizeof(int32_t), &be->out_set_layout, &be->out_layout)) != HD_SUCCESS)
            return r;
        if (!be->out_pool) {
            ps.type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            ps.descriptorCount = 3;
            memset(&dpci, 0, sizeof dpci);
            dpci.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO;
            dpci.maxSets = 1;
            dpci.poolSizeCount = 1;
            dpci.pPoolSizes = &ps;
            HD__VK_TRY(vw, be->fn.vkCreateDescriptorPool(be->device, &dpci, NULL, &be->out_pool), "vkCreateDescriptorPool");
            memset(&ai, 0, sizeof ai);
            ai.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO;
            ai.descriptorPool = be->out_pool;
            ai.descriptorSetCount = 1;
            ai.pSetLayouts = &be->out_set_layout;
            HD__VK_TRY(vw, be->fn.vkAllocateDescriptorSets(be->device, &ai, &be->out_set), "vkAllocateDescriptorSets");
        }
        if (!be->otab.buffer) {
            if ((r = hd__vk_buffer_create(vw, &be->otab, HD__OUTPUT_THRESHOLDS * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1,
                                          "the output's thresholds")) != HD_SUCCESS)
                return r;
            hd__output_thresholds((float *)be->otab.map);
        }
        if ((r = hd__vk_compute_pipeline(vw, hd__spv_output, sizeof hd__spv_output, NULL, be->out_layout, &be->out_pipe)) != HD_SUCCESS)
            return r;
    }
    if (be->obuf.bytes < bytes) {
        hd__vk_free_buffer(vw, &be->obuf);
        if ((r = hd__vk_buffer_create(vw, &be->obuf, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, 0,
                                      "the encoded image")) != HD_SUCCESS)
            return r;
    }
    if (be->out_img != be->img.buffer || be->out_enc != be->obuf.buffer) {
        VkWriteDescriptorSet w[3];
        VkDescriptorBufferInfo bi[3];
        const hd__vk_buffer *b[3];
        int i;
        b[0] = &be->img; b[1] = &be->otab; b[2] = &be->obuf;
        for (i = 0; i < 3; ++i) {
            memset(&w[i], 0, sizeof w[i]);
            bi[i].buffer = b[i]->buffer;
            bi[i].offset = 0;
            bi[i].range = VK_WHOLE_SIZE;
            w[i].sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET;
            w[i].dstSet = be->out_set;
            w[i].dstBinding = (uint32_t)i;
            w[i].descriptorCount = 1;
            w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            w[i].pBufferInfo = &bi[i];
        }
        be->fn.vkUpdateDescriptorSets(be->device, 3, w, 0, NULL);
        be->out_img = be->img.buffer;
        be->out_enc = be->obuf.buffer;
    }
    return HD_SUCCESS;
}

/* A barrier on a range of buffer b from (src stage, access) to (dst stage, access). */
static void hd__vk_buffer_barrier(hd__backend *be, VkCommandBuffer cb, VkBuffer b, VkDeviceSize offset, VkDeviceSize size,
                                  VkPipelineStageFlags src, VkAccessFlags src_access, VkPipelineStageFlags dst,
                                  VkAccessFlags dst_access)
{
    VkBufferMemoryBarrier bb;
    memset(&bb, 0, sizeof bb);
    bb.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    bb.srcAccessMask = src_access;
    bb.dstAccessMask = dst_access;
    bb.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bb.buffer = b;
    bb.offset = offset;
    bb.size = size;
    be->fn.vkCmdPipelineBarrier(cb, src, dst, 0, 0, NULL, 1, &bb, 0, NULL);
}

/* The caller's image from `from` to `to`, after every earlier command (ALL_COMMANDS, MEMORY_READ |
   MEMORY_WRITE) or, after the copy, from the transfer's write. */
static void hd__vk_target_layout(hd__backend *be, VkCommandBuffer cb, VkImage im, VkImageLayout from, VkImageLayout to, int after)
{
    VkImageMemoryBarrier ib;
    const VkAccessFlags any = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    memset(&ib, 0, sizeof ib);
    ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    ib.srcAccessMask = after ? (VkAccessFlags)VK_ACCESS_TRANSFER_WRITE_BIT : any;
    ib.dstAccessMask = after ? any : (VkAccessFlags)VK_ACCESS_TRANSFER_WRITE_BIT;
    ib.oldLayout = from;
    ib.newLayout = to;
    ib.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    ib.image = im;
    ib.subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    ib.subresourceRange.levelCount = 1;
    ib.subresourceRange.layerCount = 1;
    be->fn.vkCmdPipelineBarrier(cb, after ? VK_PIPELINE_STAGE_TRANSFER_BIT : VK_PIPELINE_STAGE_ALL_COMMANDS_BIT,
                                after ? VK_PIPELINE_STAGE_ALL_COMMANDS_BIT : VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, &ib);
}

/* The output pass into the encoded image, then the caller's target's barriers and copies
   (hybriddiff.h, hd_vulkan_target). */
static hd_result hd__be_record_output(const hd__view *vw, const hd_vulkan_target *t, const hd_output *out)
{
    hd__backend *be = vw->be;
    VkCommandBuffer cb = be->rec;
    const VkAccessFlags any = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    VkDeviceSize px = hd__output_pixel_bytes(out->format), row = (VkDeviceSize)out->width * px;
    VkDeviceSize bytes = row * (VkDeviceSize)out->height;
    int32_t pc[5];
    int swap = 0;
    hd_result r;
    if (!cb) return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: the output recorded outside a recording (internal error)");
    if ((r = hd__vk_output_prepare(vw, bytes)) != HD_SUCCESS) return r;
    if (t->image) hd__vk_output_takes(t->format, out->format, &swap);
    pc[0] = out->width;
    pc[1] = out->height;
    pc[2] = (int32_t)out->format;
    pc[3] = swap ? 2 : 0; /* rows top first, Vulkan's order */
    memcpy(&pc[4], &vw->params.exposure, sizeof pc[4]);
    hd__vk_barrier(be, cb); /* the frame's image writes before the pass reads them */
    be->fn.vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, be->out_pipe);
    be->fn.vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, be->out_layout, 0, 1, &be->out_set, 0, NULL);
    be->fn.vkCmdPushConstants(cb, be->out_layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof pc, pc);
    be->fn.vkCmdDispatch(cb, ((uint32_t)out->width + HD__VK_LOCAL_X - 1) / HD__VK_LOCAL_X, (uint32_t)out->height, 1);
    hd__vk_buffer_barrier(be, cb, be->obuf.buffer, 0, bytes, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT);
    if (t->image) {
        VkImage im = (VkImage)t->image;
        VkImageLayout final = (VkImageLayout)(t->final_layout ? t->final_layout : t->layout);
        VkBufferImageCopy reg;
        memset(&reg, 0, sizeof reg);
        reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        reg.imageSubresource.layerCount = 1;
        reg.imageOffset.x = out->x;
        reg.imageOffset.y = out->y;
        reg.imageExtent.width = (uint32_t)out->width;
        reg.imageExtent.height = (uint32_t)out->height;
        reg.imageExtent.depth = 1;
        hd__vk_target_layout(be, cb, im, (VkImageLayout)t->layout, HD__VK_DST, 0);
        be->fn.vkCmdCopyBufferToImage(cb, be->obuf.buffer, im, HD__VK_DST, 1, &reg);
        hd__vk_target_layout(be, cb, im, HD__VK_DST, final, 1);
    } else {
        VkBuffer b = (VkBuffer)t->buffer;
        VkDeviceSize pitch = t->row_pitch ? t->row_pitch : (VkDeviceSize)t->width * px;
        VkDeviceSize first = t->offset + (VkDeviceSize)out->y * pitch + (VkDeviceSize)out->x * px;
        VkDeviceSize span = (VkDeviceSize)(out->height - 1) * pitch + row;
        VkBufferCopy one, *regs = &one;
        uint32_t n = 1, k;
        if (pitch == row) {
            one.srcOffset = 0;
            one.dstOffset = first;
            one.size = bytes;
        } else {
            n = (uint32_t)out->height;
            if (!(regs = (VkBufferCopy *)hd__calloc(vw, n, sizeof *regs)))
                return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "vulkan: no memory for %u copy regions", n);
            for (k = 0; k < n; ++k) {
                regs[k].srcOffset = (VkDeviceSize)k * row;
                regs[k].dstOffset = first + (VkDeviceSize)k * pitch;
                regs[k].size = row;
            }
        }
        hd__vk_buffer_barrier(be, cb, b, first, span, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, any, VK_PIPELINE_STAGE_TRANSFER_BIT,
                              VK_ACCESS_TRANSFER_WRITE_BIT);
        be->fn.vkCmdCopyBuffer(cb, be->obuf.buffer, b, n, regs);
        hd__vk_buffer_barrier(be, cb, b, first, span, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                              VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, any);
        if (regs != &one) hd__free(vw, regs);
    }
    return HD_SUCCESS;
}

/* ---- the light into the caller's 3D image or buffer (hd_vulkan_record_illumination) ---------- */
/* The layouts a 3D colour image may be in before the copy (before: UNDEFINED too) or be left in. */
static int hd__vk_volume_layout(int l, int before)
{
    return l == VK_IMAGE_LAYOUT_GENERAL || l == VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL || l == VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL ||
           l == VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL || (before && l == VK_IMAGE_LAYOUT_UNDEFINED);
}

/* lsum (E + phi, made first on the backend's queue when stale) copied into the caller's target
   between two barriers: ALL_COMMANDS -> transfer, taking lsum to TRANSFER_SRC and the target
   image to TRANSFER_DST; the copy; transfer -> ALL_COMMANDS, lsum back to GENERAL and the target
   image to its final layout. */
static hd_result hd__be_record_illumination(const hd__view *vw, void *cbp, int channel, const hd_vulkan_volume_target *t)
{
    const char *fn = "hd_vulkan_record_illumination";
    hd__backend *be = vw->be;
    VkCommandBuffer cb = (VkCommandBuffer)cbp;
    const VkAccessFlags any = VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT;
    VkImageLayout final = (VkImageLayout)(t->final_layout ? t->final_layout : t->layout);
    VkMemoryBarrier mb;
    VkImageMemoryBarrier ib[2];
    VkBufferMemoryBarrier bb;
    VkDeviceSize bytes = (VkDeviceSize)vw->gdims[0] * vw->gdims[1] * vw->gdims[2] * sizeof(float);
    hd_result r;
    int i;
    if (t->image && t->format != VK_FORMAT_R32_SFLOAT)
        return HD__ERR(&vw->log, HD_ERROR_OUTPUT_FORMAT, "%s: VkFormat %d; the light needs VK_FORMAT_R32_SFLOAT", fn, t->format);
    if (t->image && !hd__vk_volume_layout(t->layout, 1))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_ENUM, "%s: layout %d is not a 3D image's layout a copy can start from", fn, t->layout);
    if (t->image && !hd__vk_volume_layout((int)final, 0))
        return HD__ERR(&vw->log, HD_ERROR_INVALID_ENUM, "%s: final_layout %d%s is not a layout to leave a 3D image in", fn, (int)final,
                       t->final_layout ? "" : " (0: layout)");
    if (!be->lsum.image) return HD__ERR(&vw->log, HD_ERROR_BACKEND, "vulkan: no summed light grid (internal error)");
    if (!be->gg.lsum_ok) {
        VkCommandBuffer own = VK_NULL_HANDLE;
        if ((r = hd__vk_begin(vw, &own)) != HD_SUCCESS || (r = hd__vk_light_sum(vw, own)) != HD_SUCCESS || (r = hd__vk_flush(vw)) != HD_SUCCESS)
            return r;
    }
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = any;
    mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    memset(ib, 0, sizeof ib);
    for (i = 0; i < 2; ++i) {
        ib[i].sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
        ib[i].srcAccessMask = any;
        ib[i].srcQueueFamilyIndex = ib[i].dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
        ib[i].subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        ib[i].subresourceRange.levelCount = 1;
        ib[i].subresourceRange.layerCount = 1;
    }
    ib[0].image = be->lsum.image;
    ib[0].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    ib[0].oldLayout = HD__VK_G;
    ib[0].newLayout = HD__VK_SRC;
    ib[1].image = (VkImage)t->image;
    ib[1].dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    ib[1].oldLayout = (VkImageLayout)t->layout;
    ib[1].newLayout = HD__VK_DST;
    memset(&bb, 0, sizeof bb);
    bb.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER;
    bb.srcAccessMask = any;
    bb.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bb.srcQueueFamilyIndex = bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    bb.buffer = (VkBuffer)t->buffer;
    bb.offset = (VkDeviceSize)t->offset;
    bb.size = bytes;
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, t->buffer ? 1u : 0u, &bb,
                                t->image ? 2u : 1u, ib);
    if (t->image) {
        VkImageCopy ic;
        memset(&ic, 0, sizeof ic);
        ic.srcSubresource.aspectMask = ic.dstSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
        ic.srcSubresource.layerCount = ic.dstSubresource.layerCount = 1;
        ic.srcOffset.z = channel * vw->gdims[2];
        ic.extent.width = (uint32_t)vw->gdims[0];
        ic.extent.height = (uint32_t)vw->gdims[1];
        ic.extent.depth = (uint32_t)vw->gdims[2];
        be->fn.vkCmdCopyImage(cb, be->lsum.image, HD__VK_SRC, ib[1].image, HD__VK_DST, 1, &ic);
    } else {
        VkBufferImageCopy reg = hd__vk_region(&be->lsum);
        reg.bufferOffset = (VkDeviceSize)t->offset;
        reg.imageOffset.z = channel * vw->gdims[2];
        reg.imageExtent.depth = (uint32_t)vw->gdims[2];
        be->fn.vkCmdCopyImageToBuffer(cb, be->lsum.image, HD__VK_SRC, bb.buffer, 1, &reg);
    }
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = any;
    ib[0].srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    ib[0].dstAccessMask = any;
    ib[0].oldLayout = HD__VK_SRC;
    ib[0].newLayout = HD__VK_G;
    ib[1].srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    ib[1].dstAccessMask = any;
    ib[1].oldLayout = HD__VK_DST;
    ib[1].newLayout = final;
    bb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    bb.dstAccessMask = any;
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &mb, t->buffer ? 1u : 0u, &bb,
                                t->image ? 2u : 1u, ib);
    return HD_SUCCESS;
}

/* No GL texture: the core never calls it. */
HD__BE_NO_TEXTURE("vulkan")
HD__BE_NO_CL_BUFFER("vulkan")
