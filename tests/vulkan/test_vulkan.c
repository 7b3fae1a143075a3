/* test_vulkan.c - the Vulkan backend's own checks (`make test-vulkan`), beside the conformance
   suite:
     1. the debug messenger really fires: a deliberately invalid vkCreateBuffer (usage 0) on the
        backend's device under the validation layer must produce a message;
     2. a caller-owned instance/device (validation and synchronization validation on, through the
        caller's messenger), functions loaded through the caller's vkGetInstanceProcAddr, and
        hd_vulkan_record into the caller's command buffer: the same E, phi and image, bit for bit,
        as hd_iterate on a context of the backend's own, and no validation message;
     3. HD_VK_MEMORY_LIMIT provokes HD_ERROR_OUT_OF_DEVICE_MEMORY in hd_create and in hd_iterate;
        the contexts are destroyed without leaks (validation on: the layer reports objects left
        alive at vkDestroyDevice / vkDestroyInstance as messages, and there must be none);
     4. HD_VK_LOSE_DEVICE=n turns the n-th queue submission into VK_ERROR_DEVICE_LOST: whether it
        hits hd_create or hd_iterate, the call returns HD_ERROR_DEVICE_LOST with the failing call
        logged, later calls fail fast with the same code, hd_destroy frees everything (validation
        on, no message);
     5. float16 illumination (r16f E / phi): method_bytes 4 bytes per grid voxel below float32's
        (E and phi 2 bytes each against 4; sigma_t, the projection's float32 E + phi and the
        direct light's list as they were); with $HD_VK_NO_HALF=1 (a device without r16f storage
        images) hd_create refuses FLOAT16 with HD_ERROR_UNSUPPORTED and a log line, and a context
        switched to it by hd_set_params refuses at hd_iterate, then renders again at FLOAT32
        (validation on, no message);
     6. HD_SOLVER_MULTIGRID: steps run (method_bytes grows by the solver's levels); with
        $HD_VK_NO_F64=1 (a device without shaderFloat64) hd_create refuses it with
        HD_ERROR_UNSUPPORTED and a log line, a context switched to it refuses at hd_iterate and
        renders again with red-black; hd_vulkan_record refuses it (its steps read dot products
        back); a new illumination grid (hd_set_params) gets new levels; HD_VK_MEMORY_LIMIT
        between red-black's and multigrid's needs fails the first step with
        HD_ERROR_OUT_OF_DEVICE_MEMORY at many points of the levels' allocation, and a device
        lost at any of a step's submissions gives HD_ERROR_DEVICE_LOST; every context is
        destroyed with no object left (validation on, no message);
     7. contexts that make their own device share one kept instance: 42 created and destroyed
        (some rendering) through one vkCreateInstance, a validation context through its own;
     8. the image buffer's reduced-frame region: absent at render scale 1, made by the first
        reduced frame (submitted or recorded); short device memory fails that frame with
        HD_ERROR_OUT_OF_DEVICE_MEMORY and full frames go on (validation on, no message);
     9. HD_RENDER_SCALE_AUTO under recording takes its first scale from the device time of the
        last recorded frame: full frames with a budget of 100 of them, reduced with an eighth;
    10. hd_vulkan_record_render into the caller's image (R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT,
        R8G8B8A8_UNORM and _SRGB, B8G8R8A8_UNORM) and buffer (offset, padded pitch), after the
        caller's own clear in the same command buffer: the region byte for byte hd_read_image_ex's,
        nothing outside it changed; refusals (region, negative y, format, size, image and buffer,
        layout, short buffer) one error each; core and synchronization validation, no message;
    11. frames over converged light under recording: light_converged reached, then no light
        iteration recorded, frame_window frames and then none, the write every call equal to the
        read-back (no message);
    12. hd_vulkan_record_depth from the caller's VkBuffer and D32_SFLOAT image in the same
        command buffer as the frame: bit for bit hd_set_depth's image; refusals one error each
        (no message);
    13. hd_vulkan_record_illumination into the caller's buffer and 3D R32_SFLOAT image, 1 and 3
        channels: bit for bit hd_read_illumination's E + phi, texels past the grid kept, the light
        after hd_refine, the light at the call before a frame's iteration; refusals one error each
        (no message);
    14. hd_vulkan_record_refine, the light alone in the caller's command buffer (HD and CD):
        followed there by hd_vulkan_record_illumination, the copies are bit for bit
        hd_read_illumination's E + phi and hd_refine's light on a twin context, the image is kept,
        the iterations are measured by the next call (not by the copies); a copy after a recorded
        frame holds the frame's light; refusals one error each (no message).
   And: every row of a 40x100 projection drawn (the background at every pixel); a volume wider
   than maxImageDimension3D refused with HD_ERROR_UNSUPPORTED and one error; HD_SOLVER_AUTO's
   multigrid falls back to red-black under recording while a named multigrid is refused (no
   message); with no device, the order of the projection's blocks of rows on CPU devices
   (hd__gpu_row_stride) visits every block once at every count up to 4096 and near
   HD_MAX_IMAGE_DIM, and splitting the dispatch's blocks into 2, 3, 4, 8 or 16 contiguous runs
   (llvmpipe's and lavapipe's threads) gives each run blocks from every quarter of the image,
   within 35 % of a quarter of its blocks each.
   Skips, each reported as SKIPPED with its reason, never as passed: with no Vulkan device
   (found by the runtime's own vkEnumeratePhysicalDevices, not the library) every check that
   needs one; without VK_LAYER_KHRONOS_validation check 1, and the others run without the layer
   (their "no validation message" parts then say nothing). A create that fails where the device
   is there fails. The last line is "all passed", "passed, N skipped (...)" or "FAILED"; exit 1
   on a failure, and on a skip under HD_CONFORMANCE_REQUIRE=1 (CI). */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#include "../conformance/hd_probe_vk.h"
#include <stdio.h>

static int failures;
static int skips;
static char skip_why[512];
static int have_layer; /* VK_LAYER_KHRONOS_validation is installed: the checks run under it */
static unsigned long messages;   /* "vulkan validation" lines from the library's logger */
static unsigned long caller_messages; /* from the caller's own messenger (test 2) */
static unsigned long gipa_calls;
static char lost_log[512];    /* the last error logged that mentions VK_ERROR_DEVICE_LOST */
static char half_log[512];    /* the last message that mentions FLOAT16 */
static char mg_log[512];      /* the last message that mentions MULTIGRID */
static char auto_log[512];    /* the last message of HD_SOLVER_AUTO's fall-back */

#define CHECK(cond) \
    do { if (!(cond)) { ++failures; fprintf(stderr, "  %s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #cond); } } while (0)

static unsigned long err_count; /* errors logged */
static void count_log(void *user, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    (void)user; (void)code; (void)file; (void)line;
    if (level == HD_LOG_ERROR) ++err_count;
    if (strncmp(msg, "vulkan validation", 17) == 0) ++messages;
    if (strstr(msg, "VK_ERROR_DEVICE_LOST")) snprintf(lost_log, sizeof lost_log, "%s", msg);
    if (strstr(msg, "FLOAT16")) snprintf(half_log, sizeof half_log, "%s", msg);
    if (strstr(msg, "MULTIGRID")) snprintf(mg_log, sizeof mg_log, "%s", msg);
    if (strstr(msg, "solver AUTO")) snprintf(auto_log, sizeof auto_log, "%s", msg);
    if (level == HD_LOG_ERROR) fprintf(stderr, "  log: %s\n", msg);
}

static VKAPI_ATTR VkBool32 VKAPI_CALL caller_messenger(VkDebugUtilsMessageSeverityFlagBitsEXT s, VkDebugUtilsMessageTypeFlagsEXT t,
                                                       const VkDebugUtilsMessengerCallbackDataEXT *d, void *u)
{
    (void)s; (void)t; (void)u;
    ++caller_messages;
    fprintf(stderr, "  caller's messenger: %s\n", d->pMessage);
    return VK_FALSE;
}

static PFN_vkVoidFunction VKAPI_CALL counting_gipa(VkInstance instance, const char *name)
{
    ++gipa_calls;
    return vkGetInstanceProcAddr(instance, name);
}

/* A loader that counts the instances made through it (test 7). */
static unsigned long instances_made;
static PFN_vkCreateInstance real_create_instance;
static VKAPI_ATTR VkResult VKAPI_CALL counting_create_instance(const VkInstanceCreateInfo *ci, const VkAllocationCallbacks *a,
                                                                VkInstance *out)
{
    ++instances_made;
    return real_create_instance(ci, a, out);
}
static PFN_vkVoidFunction VKAPI_CALL instance_counting_gipa(VkInstance instance, const char *name)
{
    if (!instance && strcmp(name, "vkCreateInstance") == 0) {
        real_create_instance = (PFN_vkCreateInstance)vkGetInstanceProcAddr(NULL, name);
        return (PFN_vkVoidFunction)counting_create_instance;
    }
    return vkGetInstanceProcAddr(instance, name);
}

static unsigned char vox[24 * 20 * 16];

static hd_desc test_desc(void)
{
    hd_desc d;
    int i;
    for (i = 0; i < (int)sizeof vox; ++i) vox[i] = (unsigned char)((i * 37) ^ (i >> 5));
    memset(&d, 0, sizeof d);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = 24; d.volume.dims[1] = 20; d.volume.dims[2] = 16;
    d.volume.data = vox;
    d.camera.width = 32; d.camera.height = 24;
    d.params.illumination_downsample = 1; /* the paper's grid and boundary: the buffer sizes below */
    d.params.diffusion_boundary = HD_BOUNDARY_BOX;
    d.logger.func = count_log;
    return d;
}

/* 1: the messenger fires on a broken call. */
static int test_messenger(void)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_result r;
    hd__ctx *ctx;
    VkBufferCreateInfo bci;
    VkBuffer buf = VK_NULL_HANDLE;
    unsigned long before;
    d.vulkan.enable_validation = have_layer;
    r = hd_create(&d, &h);
    if (r != HD_SUCCESS) { /* the device and the layer are there (main): the library failed */
        ++failures;
        printf("FAIL messenger: hd_create with validation: %s\n", hd_result_string(r));
        return 0;
    }
    CHECK(messages == 0);
    ctx = hd__lookup(h);
    memset(&bci, 0, sizeof bci);
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = 16;
    bci.usage = 0; /* invalid: VUID-VkBufferCreateInfo-usage-requiredbitmask */
    before = messages;
    if (ctx->vw.be->fn.vkCreateBuffer(ctx->vw.be->device, &bci, NULL, &buf) == VK_SUCCESS && buf)
        ctx->vw.be->fn.vkDestroyBuffer(ctx->vw.be->device, buf, NULL);
    CHECK(messages > before);
    printf("%s messenger fires on a broken call (%lu message%s)\n", messages > before ? "PASS" : "FAIL",
           messages - before, messages - before == 1 ? "" : "s");
    hd_destroy(h);
    messages = 0;
    return 1;
}

/* 2: caller-owned device, caller's loader, recording into the caller's command buffer. */
static void test_caller_device(void)
{
    const char *layer = "VK_LAYER_KHRONOS_validation", *ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    PFN_vkCreateInstance create_instance = (PFN_vkCreateInstance)vkGetInstanceProcAddr(NULL, "vkCreateInstance");
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkValidationFeaturesEXT vf;
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkDebugUtilsMessengerCreateInfoEXT mci;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkInstance inst = VK_NULL_HANDLE;
    VkPhysicalDevice phys[8];
    uint32_t nphys = 8;
    VkDevice dev = VK_NULL_HANDLE;
    VkQueue queue;
    float prio = 1.0f;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    VkCommandPoolCreateInfo cpci;
    VkCommandPool pool;
    VkCommandBufferAllocateInfo cbai;
    VkCommandBuffer cb;
    VkCommandBufferBeginInfo bi;
    VkSubmitInfo si;
    hd_desc d = test_desc();
    hd_context mine, theirs;
    hd_result r1, r2;
    size_t n = (size_t)24 * 20 * 16, ni = (size_t)32 * 24 * 4;
    float *a = (float *)calloc(n > ni ? n : ni, sizeof(float)), *b = (float *)calloc(n > ni ? n : ni, sizeof(float));
    int k, same = 1;
    PFN_vkDestroyInstance destroy_instance;
    PFN_vkDestroyDevice destroy_device;
    PFN_vkCreateCommandPool create_pool;
    PFN_vkDestroyCommandPool destroy_pool;
    PFN_vkAllocateCommandBuffers alloc_cb;
    PFN_vkBeginCommandBuffer begin_cb;
    PFN_vkEndCommandBuffer end_cb;
    PFN_vkQueueSubmit submit;
    PFN_vkQueueWaitIdle wait_idle;
    PFN_vkGetDeviceQueue get_queue;
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger;

    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&mci, 0, sizeof mci);
    mci.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                      VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mci.pfnUserCallback = caller_messenger;
    memset(&vf, 0, sizeof vf);
    vf.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT;
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = &sync;
    vf.pNext = &mci;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pNext = have_layer ? &vf : NULL;
    ici.pApplicationInfo = &app;
    ici.enabledLayerCount = have_layer ? 1 : 0;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = have_layer ? 1 : 0;
    ici.ppEnabledExtensionNames = &ext;
    if (!create_instance || create_instance(&ici, NULL, &inst) != VK_SUCCESS) {
        ++failures;
        printf("FAIL caller device: cannot create an instance%s%s\n", have_layer ? " with " : "", have_layer ? layer : "");
        free(a); free(b);
        return;
    }
#define LOAD(var, type, name) var = (type)vkGetInstanceProcAddr(inst, name)
    LOAD(destroy_instance, PFN_vkDestroyInstance, "vkDestroyInstance");
    LOAD(create_messenger, PFN_vkCreateDebugUtilsMessengerEXT, "vkCreateDebugUtilsMessengerEXT");
    LOAD(destroy_messenger, PFN_vkDestroyDebugUtilsMessengerEXT, "vkDestroyDebugUtilsMessengerEXT");
    if (have_layer && create_messenger) create_messenger(inst, &mci, NULL, &messenger);
    ((PFN_vkEnumeratePhysicalDevices)vkGetInstanceProcAddr(inst, "vkEnumeratePhysicalDevices"))(inst, &nphys, phys);
    memset(&qci, 0, sizeof qci);
    qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    qci.queueFamilyIndex = 0; /* lavapipe's one family does compute */
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    memset(&dci, 0, sizeof dci);
    dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    ((PFN_vkCreateDevice)vkGetInstanceProcAddr(inst, "vkCreateDevice"))(phys[0], &dci, NULL, &dev);
    LOAD(destroy_device, PFN_vkDestroyDevice, "vkDestroyDevice");
    LOAD(create_pool, PFN_vkCreateCommandPool, "vkCreateCommandPool");
    LOAD(destroy_pool, PFN_vkDestroyCommandPool, "vkDestroyCommandPool");
    LOAD(alloc_cb, PFN_vkAllocateCommandBuffers, "vkAllocateCommandBuffers");
    LOAD(begin_cb, PFN_vkBeginCommandBuffer, "vkBeginCommandBuffer");
    LOAD(end_cb, PFN_vkEndCommandBuffer, "vkEndCommandBuffer");
    LOAD(submit, PFN_vkQueueSubmit, "vkQueueSubmit");
    LOAD(wait_idle, PFN_vkQueueWaitIdle, "vkQueueWaitIdle");
    LOAD(get_queue, PFN_vkGetDeviceQueue, "vkGetDeviceQueue");
#undef LOAD
    get_queue(dev, 0, 0, &queue);

    /* the library on the caller's device, loading through the caller's vkGetInstanceProcAddr */
    d.vulkan.instance = inst;
    d.vulkan.physical_device = phys[0];
    d.vulkan.device = dev;
    d.vulkan.queue = queue;
    d.vulkan.queue_family = 0;
    d.vulkan.get_instance_proc_addr = (hd_proc)counting_gipa;
    r1 = hd_create(&d, &theirs);
    CHECK(r1 == HD_SUCCESS);
    CHECK(gipa_calls > 0);
    memset(&d.vulkan, 0, sizeof d.vulkan);
    r2 = hd_create(&d, &mine);
    CHECK(r2 == HD_SUCCESS);
    if (r1 == HD_SUCCESS && r2 == HD_SUCCESS) {
        memset(&cpci, 0, sizeof cpci);
        cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
        cpci.queueFamilyIndex = 0;
        create_pool(dev, &cpci, NULL, &pool);
        memset(&cbai, 0, sizeof cbai);
        cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
        cbai.commandPool = pool;
        cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
        cbai.commandBufferCount = 1;
        alloc_cb(dev, &cbai, &cb);
        memset(&bi, 0, sizeof bi);
        bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
        begin_cb(cb, &bi);
        CHECK(hd_vulkan_record(theirs, cb, 6) == HD_SUCCESS);
        end_cb(cb);
        memset(&si, 0, sizeof si);
        si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cb;
        CHECK(submit(queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS);
        wait_idle(queue);
        CHECK(hd_iterate(mine, 6) == HD_SUCCESS);
        for (k = 0; k < 3; ++k) {
            size_t cnt = k < 2 ? n : ni;
            if (k < 2) {
                CHECK(hd_read_illumination(theirs, (hd_illumination)k, a, n) == HD_SUCCESS);
                CHECK(hd_read_illumination(mine, (hd_illumination)k, b, n) == HD_SUCCESS);
            } else {
                CHECK(hd_read_image_f32(theirs, a, ni) == HD_SUCCESS);
                CHECK(hd_read_image_f32(mine, b, ni) == HD_SUCCESS);
            }
            if (memcmp(a, b, cnt * sizeof(float)) != 0) same = 0;
        }
        CHECK(same);
        destroy_pool(dev, pool, NULL);
    }
    if (r1 == HD_SUCCESS) hd_destroy(theirs);
    if (r2 == HD_SUCCESS) hd_destroy(mine);
    destroy_device(dev, NULL);
    if (messenger) destroy_messenger(inst, messenger, NULL);
    destroy_instance(inst, NULL);
    CHECK(caller_messages == 0);
    printf("%s caller-owned device: 6 recorded iterations %s 6 submitted ones; %lu loads through the caller's "
           "vkGetInstanceProcAddr; %lu validation messages\n", same && caller_messages == 0 ? "PASS" : "FAIL",
           same ? "equal (bit for bit)" : "DIFFER from", gipa_calls, caller_messages);
    free(a);
    free(b);
}

/* 3: out of device memory, in create and in iterate; clean destroy. */
static void test_out_of_memory(void)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_result r;
    int ok = 1;
    d.vulkan.enable_validation = have_layer;
    messages = 0;
    setenv("HD_VK_MEMORY_LIMIT", "20000", 1); /* below the 36 KB parameter ring and the 30 KB volume */
    r = hd_create(&d, &h);
    CHECK(r == HD_ERROR_OUT_OF_DEVICE_MEMORY);
    ok &= r == HD_ERROR_OUT_OF_DEVICE_MEMORY;
    if (r == HD_SUCCESS) hd_destroy(h);
    setenv("HD_VK_MEMORY_LIMIT", "150000", 1); /* the volume fits, the illumination grids do not */
    r = hd_create(&d, &h);
    CHECK(r == HD_SUCCESS);
    ok &= r == HD_SUCCESS;
    if (r == HD_SUCCESS) {
        r = hd_iterate(h, 2);
        CHECK(r == HD_ERROR_OUT_OF_DEVICE_MEMORY);
        ok &= r == HD_ERROR_OUT_OF_DEVICE_MEMORY;
        CHECK(hd_destroy(h) == HD_SUCCESS);
    }
    unsetenv("HD_VK_MEMORY_LIMIT");
    /* validation messages counted here: only the layer's, the OOM errors are logged separately */
    CHECK(messages == 0);
    ok &= messages == 0;
    printf("%s out of device memory in hd_create and hd_iterate, destroyed with no object left (%lu validation messages)\n",
           ok ? "PASS" : "FAIL", messages);
}

/* 4: the device lost at submission n (1, 2: inside hd_create; later: inside hd_iterate). */
static void test_device_lost(void)
{
    static const int at[] = {1, 2, 3, 5, 8, 12};
    hd_desc d = test_desc();
    hd_context h;
    static float px[32 * 24 * 4];
    int k, in_create = 0, in_iterate = 0, ok = 1;
    char n[16];
    d.vulkan.enable_validation = have_layer;
    messages = 0;
    for (k = 0; k < (int)(sizeof at / sizeof at[0]); ++k) {
        hd_result r;
        snprintf(n, sizeof n, "%d", at[k]);
        setenv("HD_VK_LOSE_DEVICE", n, 1);
        lost_log[0] = '\0';
        r = hd_create(&d, &h);
        if (r == HD_SUCCESS) {
            r = hd_iterate(h, 2); /* two HD iterations submit more than 12 times */
            ++in_iterate;
            ok &= hd_iterate(h, 1) == HD_ERROR_DEVICE_LOST; /* sticky: fails fast */
            ok &= hd_read_image_f32(h, px, sizeof px / sizeof px[0]) == HD_ERROR_DEVICE_LOST;
            ok &= hd_destroy(h) == HD_SUCCESS;
        } else {
            ++in_create;
        }
        if (r != HD_ERROR_DEVICE_LOST || !strstr(lost_log, "vkQueueSubmit")) {
            fprintf(stderr, "  HD_VK_LOSE_DEVICE=%d: %s, log \"%s\"\n", at[k], hd_result_string(r), lost_log);
            ok = 0;
        }
    }
    unsetenv("HD_VK_LOSE_DEVICE");
    CHECK(ok);
    CHECK(in_create > 0 && in_iterate > 0);
    CHECK(messages == 0);
    printf("%s device lost at submission 1..12: HD_ERROR_DEVICE_LOST from hd_create (%d) and hd_iterate (%d), logged with "
           "vkQueueSubmit, sticky, destroyed with no object left (%lu validation messages)\n",
           ok && in_create > 0 && in_iterate > 0 && messages == 0 ? "PASS" : "FAIL", in_create, in_iterate, messages);
}

/* 5: float16 storage's bytes, and its refusal on a device without r16f storage images. */
/* method_bytes after one iteration; *elems: E's elements (grid voxels times channels). */
static size_t method_bytes(hd_precision prec, size_t *elems)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_stats st;
    memset(&st, 0, sizeof st);
    d.params.illumination_precision = prec;
    if (hd_create(&d, &h) != HD_SUCCESS) return 0;
    if (hd_iterate(h, 1) != HD_SUCCESS || hd_get_stats(h, &st) != HD_SUCCESS) st.method_bytes = 0;
    hd_destroy(h);
    *elems = (size_t)st.illumination_dims[0] * st.illumination_dims[1] * st.illumination_dims[2] * (size_t)st.illumination_channels;
    return st.method_bytes;
}

static void test_half(void)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_result r;
    size_t n = 0, b32 = method_bytes(HD_PRECISION_FLOAT32, &n), b16 = method_bytes(HD_PRECISION_FLOAT16, &n);
    int ok = b16 > 0 && b32 - b16 == n * 2 * 2; /* E and phi 2 bytes an element, not 4 */
    d.vulkan.enable_validation = have_layer;
    messages = 0;
    setenv("HD_VK_NO_HALF", "1", 1);
    d.params.illumination_precision = HD_PRECISION_FLOAT16;
    half_log[0] = '\0';
    r = hd_create(&d, &h);
    ok &= r == HD_ERROR_UNSUPPORTED && strstr(half_log, "test knob") != NULL;
    if (r == HD_SUCCESS) hd_destroy(h);
    d.params.illumination_precision = HD_PRECISION_FLOAT32;
    if ((r = hd_create(&d, &h)) == HD_SUCCESS) {
        hd_params p = d.params;
        ok &= hd_iterate(h, 1) == HD_SUCCESS;
        p.illumination_precision = HD_PRECISION_FLOAT16;
        ok &= hd_set_params(h, &p) == HD_SUCCESS; /* the device is not asked until the grids are made */
        half_log[0] = '\0';
        ok &= hd_iterate(h, 1) == HD_ERROR_UNSUPPORTED && strstr(half_log, "FLOAT16") != NULL;
        p.illumination_precision = HD_PRECISION_FLOAT32;
        ok &= hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 2) == HD_SUCCESS;
        ok &= hd_destroy(h) == HD_SUCCESS;
    } else {
        ok = 0;
    }
    unsetenv("HD_VK_NO_HALF");
    CHECK(ok);
    CHECK(messages == 0);
    printf("%s float16 illumination: method_bytes %zu against %zu at float32; refused (HD_ERROR_UNSUPPORTED, logged) at hd_create "
           "and after hd_set_params on a device without r16f storage images, float32 renders again (%lu validation messages)\n",
           ok && messages == 0 ? "PASS" : "FAIL", b16, b32, messages);
}

/* 6: multigrid: its refusals, out of device memory in its levels, a lost device in its steps. */
static size_t solver_bytes(hd_solver solver)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_stats st;
    memset(&st, 0, sizeof st);
    d.params.solver = solver;
    if (hd_create(&d, &h) != HD_SUCCESS) return 0;
    if (hd_iterate(h, 2) != HD_SUCCESS || hd_get_stats(h, &st) != HD_SUCCESS) st.method_bytes = 0;
    hd_destroy(h);
    return st.method_bytes;
}

static void test_multigrid(void)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_result r;
    size_t brb = solver_bytes(HD_SOLVER_RED_BLACK), bmg = solver_bytes(HD_SOLVER_MULTIGRID);
    int ok = brb > 0 && bmg > brb, k, oom = 0, fits = 0, lost = 0;
    char n[32];
    VkCommandBuffer never_used = (VkCommandBuffer)(void *)&d; /* refused before any use */
    d.vulkan.enable_validation = have_layer;
    messages = 0;
    /* without shaderFloat64 */
    setenv("HD_VK_NO_F64", "1", 1);
    d.params.solver = HD_SOLVER_MULTIGRID;
    mg_log[0] = '\0';
    r = hd_create(&d, &h);
    ok &= r == HD_ERROR_UNSUPPORTED && strstr(mg_log, "HD_VK_NO_F64") != NULL;
    if (r == HD_SUCCESS) hd_destroy(h);
    d.params.solver = HD_SOLVER_RED_BLACK;
    if ((r = hd_create(&d, &h)) == HD_SUCCESS) {
        hd_params p = d.params;
        ok &= hd_iterate(h, 1) == HD_SUCCESS;
        p.solver = HD_SOLVER_MULTIGRID;
        ok &= hd_set_params(h, &p) == HD_SUCCESS;
        mg_log[0] = '\0';
        ok &= hd_iterate(h, 1) == HD_ERROR_UNSUPPORTED && strstr(mg_log, "shaderFloat64") != NULL;
        p.solver = HD_SOLVER_RED_BLACK;
        ok &= hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS;
        ok &= hd_destroy(h) == HD_SUCCESS;
    } else {
        ok = 0;
    }
    unsetenv("HD_VK_NO_F64");
    /* not recordable; new levels for a new grid (illumination_downsample), and back */
    d.params.solver = HD_SOLVER_MULTIGRID;
    if ((r = hd_create(&d, &h)) == HD_SUCCESS) {
        hd_params p = d.params;
        mg_log[0] = '\0';
        ok &= hd_vulkan_record(h, (void *)never_used, 1) == HD_ERROR_UNSUPPORTED && strstr(mg_log, "MULTIGRID") != NULL;
        ok &= hd_iterate(h, 1) == HD_SUCCESS;
        p.illumination_downsample = 2;
        ok &= hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS;
        p.illumination_downsample = 1;
        ok &= hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS;
        ok &= hd_destroy(h) == HD_SUCCESS;
    } else {
        ok = 0;
    }
    /* out of device memory inside the levels' allocation: limits from below red-black's needs
       (staging buffer, the projection's summed light and TF table included) to above
       multigrid's, 20 KB apart */
    for (k = 0; k < 24; ++k) {
        snprintf(n, sizeof n, "%d", 240000 + 20000 * k);
        setenv("HD_VK_MEMORY_LIMIT", n, 1);
        d.params.solver = HD_SOLVER_RED_BLACK;
        if ((r = hd_create(&d, &h)) != HD_SUCCESS) { ok = 0; break; }
        if (hd_iterate(h, 1) == HD_SUCCESS) {
            hd_params p = d.params;
            p.solver = HD_SOLVER_MULTIGRID;
            r = hd_set_params(h, &p) == HD_SUCCESS ? hd_iterate(h, 1) : HD_ERROR_BACKEND;
            oom += r == HD_ERROR_OUT_OF_DEVICE_MEMORY;
            fits += r == HD_SUCCESS;
            ok &= r == HD_ERROR_OUT_OF_DEVICE_MEMORY || r == HD_SUCCESS;
            p.solver = HD_SOLVER_RED_BLACK; /* a failed allocation freed what it made: red-black still renders */
            ok &= hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS;
        }
        ok &= hd_destroy(h) == HD_SUCCESS;
    }
    unsetenv("HD_VK_MEMORY_LIMIT");
    /* the device lost at each submission of the first steps */
    d.params.solver = HD_SOLVER_MULTIGRID;
    for (k = 3; k <= 12; ++k) {
        snprintf(n, sizeof n, "%d", k);
        setenv("HD_VK_LOSE_DEVICE", n, 1);
        if ((r = hd_create(&d, &h)) != HD_SUCCESS) continue;
        r = hd_iterate(h, 2);
        lost += r == HD_ERROR_DEVICE_LOST;
        ok &= r == HD_ERROR_DEVICE_LOST && hd_iterate(h, 1) == HD_ERROR_DEVICE_LOST;
        ok &= hd_destroy(h) == HD_SUCCESS;
    }
    unsetenv("HD_VK_LOSE_DEVICE");
    ok &= oom >= 3 && fits > 0 && lost >= 8;
    CHECK(ok);
    CHECK(messages == 0);
    printf("%s multigrid: method_bytes %zu against %zu with red-black; refused (HD_ERROR_UNSUPPORTED, logged) without shaderFloat64 "
           "and by hd_vulkan_record; out of device memory in the levels at %d limits (fits at %d), device lost in a step (%d of 10), "
           "destroyed with no object left (%lu validation messages)\n",
           ok && messages == 0 ? "PASS" : "FAIL", bmg, brb, oom, fits, lost, messages);
}

/* 7: contexts that make their own device share one instance for the process, so that creating
   and destroying many contexts never cycles vkCreateInstance (NVIDIA's driver refuses it after
   about 30 cycles); a validation context still gets, and destroys, its own. */
static void test_kept_instance(void)
{
    enum { CYCLES = 40 };
    hd_desc d = test_desc();
    hd_context h, live;
    int i, ok = 1, rendered = 0;
    d.vulkan.get_instance_proc_addr = (hd_proc)instance_counting_gipa;
    CHECK(hd_create(&d, &live) == HD_SUCCESS); /* alive while the others come and go */
    for (i = 0; i < CYCLES && ok; ++i) {
        ok = hd_create(&d, &h) == HD_SUCCESS;
        if (ok && i % 8 == 0) { ok = hd_render(h) == HD_SUCCESS; rendered += ok; }
        if (ok) hd_destroy(h);
    }
    CHECK(ok);
    CHECK(hd_render(live) == HD_SUCCESS);
    hd_destroy(live);
    CHECK(hd_create(&d, &h) == HD_SUCCESS);
    hd_destroy(h);
    ok = ok && instances_made == 1;
    CHECK(instances_made == 1);
    d.vulkan.enable_validation = 1;
    if (have_layer) { /* without the layer a validation context is refused: nothing to count */
        ok = ok && hd_create(&d, &h) == HD_SUCCESS;
        if (ok) hd_destroy(h);
        CHECK(instances_made == 2);
        ok = ok && instances_made == 2 && messages == 0;
    }
    printf("%s %d contexts created and destroyed, %d rendered, through %lu vkCreateInstance call%s "
           "(the kept instance%s)\n", ok ? "PASS" : "FAIL", CYCLES + 2, rendered + 1, instances_made,
           instances_made == 1 ? "" : "s", have_layer ? ", and one for a validation context" : "; no validation layer");
}

/* Records n iterations of h into a command buffer of the backend's own device, submits it and
   waits, as an application using hd_vulkan_record would. */
static hd_result record_run(hd_context h, int n)
{
    hd__ctx *ctx = hd__lookup(h);
    hd__backend *be = ctx->vw.be;
    VkCommandPoolCreateInfo cpci;
    VkCommandBufferAllocateInfo cbai;
    VkCommandBufferBeginInfo bi;
    VkSubmitInfo si;
    VkCommandPool pool;
    VkCommandBuffer cb;
    hd_result r;
    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpci.queueFamilyIndex = be->queue_family;
    if (be->fn.vkCreateCommandPool(be->device, &cpci, NULL, &pool) != VK_SUCCESS) return HD_ERROR_BACKEND;
    memset(&cbai, 0, sizeof cbai);
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    be->fn.vkAllocateCommandBuffers(be->device, &cbai, &cb);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    be->fn.vkBeginCommandBuffer(cb, &bi);
    r = hd_vulkan_record(h, cb, n);
    be->fn.vkEndCommandBuffer(cb);
    if (r == HD_SUCCESS) {
        memset(&si, 0, sizeof si);
        si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cb;
        if (be->fn.vkQueueSubmit(be->queue, 1, &si, VK_NULL_HANDLE) != VK_SUCCESS) r = HD_ERROR_BACKEND;
        be->fn.vkDeviceWaitIdle(be->device);
    }
    be->fn.vkDestroyCommandPool(be->device, pool, NULL);
    return r;
}

/* 8: the image buffer's reduced-frame region: absent at render scale 1, made with the first
   reduced frame (submitted or recorded); when device memory is short for it, the frame fails
   with HD_ERROR_OUT_OF_DEVICE_MEMORY and the context renders full frames on (validation on, no
   message). */
static void test_image_room(void)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_stats s;
    hd_params p;
    hd__ctx *ctx;
    size_t full = (size_t)32 * 24 * 20, room = (size_t)16 * 12 * 16; /* the image with its depth plane */
    int ok = 1;
    d.vulkan.enable_validation = have_layer;
    messages = 0;
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    ctx = hd__lookup(h);
    ok &= hd_iterate(h, 1) == HD_SUCCESS && hd_get_stats(h, &s) == HD_SUCCESS && s.image_bytes == full;
    p = d.params;
    p.render_scale = 2;
    ok &= hd_set_params(h, &p) == HD_SUCCESS;
    ctx->vw.be->mem_limit = ctx->vw.be->mem_used + 4096; /* no room for a second image buffer */
    ok &= hd_iterate(h, 1) == HD_ERROR_OUT_OF_DEVICE_MEMORY;
    ok &= record_run(h, 1) == HD_ERROR_OUT_OF_DEVICE_MEMORY;
    ok &= hd_get_stats(h, &s) == HD_SUCCESS && s.image_bytes == full;
    p.render_scale = 1;
    ok &= hd_set_params(h, &p) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS && record_run(h, 1) == HD_SUCCESS;
    ctx->vw.be->mem_limit = 0;
    p.render_scale = 2;
    ok &= hd_set_params(h, &p) == HD_SUCCESS && record_run(h, 2) == HD_SUCCESS;
    ok &= hd_get_stats(h, &s) == HD_SUCCESS && s.image_bytes == full + room && s.render_scale == 2 && s.frames == 2;
    ok &= hd_iterate(h, 1) == HD_SUCCESS;
    CHECK(hd_destroy(h) == HD_SUCCESS);
    ok &= messages == 0;
    CHECK(ok);
    printf("%s image buffer: %zu bytes at scale 1, %zu with the reduced region made by the first reduced frame; short device "
           "memory fails it (hd_iterate and hd_vulkan_record) and full frames go on (%lu validation messages)\n",
           ok ? "PASS" : "FAIL", full, full + room, messages);
}

/* 9: HD_RENDER_SCALE_AUTO while recording picks its first scale from the device time of the last
   recorded frame, as it does from the measured time of a submitted one: full frames when the
   budget holds many full frames (the prediction from a scale-4 frame, its time times 16, is
   above a full frame's: fixed costs per frame), reduced ones when it holds an eighth of one.
   Without a measurement the first scale would be 4; timed by recording, 1 for both budgets. */
static void test_record_auto_scale(void)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_stats s0, s1;
    hd_params p;
    double t = 1e30;
    int k, first_fit, first_small;
    d.camera.width = d.camera.height = 512;
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    for (k = 0; k < 3; ++k) { /* a full frame's time: the fastest of three projections */
        CHECK(hd_get_stats(h, &s0) == HD_SUCCESS && hd_iterate(h, 1) == HD_SUCCESS && hd_get_stats(h, &s1) == HD_SUCCESS);
        if (s1.seconds_projection - s0.seconds_projection < t) t = s1.seconds_projection - s0.seconds_projection;
    }
    hd_destroy(h);
    d.params.render_scale = HD_RENDER_SCALE_AUTO;
    d.params.render_budget = (float)(100.0 * t < 10.0 ? 100.0 * t : 10.0); /* at most 10 s (the parameter's range): a loaded machine */
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    CHECK(record_run(h, 1) == HD_SUCCESS); /* nothing measured yet: scale 4 */
    CHECK(hd_get_stats(h, &s0) == HD_SUCCESS && s0.render_scale == 4);
    CHECK(hd_set_camera(h, &d.camera) == HD_SUCCESS && record_run(h, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(h, &s0) == HD_SUCCESS);
    first_fit = s0.render_scale;
    CHECK(hd_query_desc(h, &d) == HD_SUCCESS);
    p = d.params;
    p.render_budget = (float)(t / 8.0);
    CHECK(hd_set_params(h, &p) == HD_SUCCESS && hd_set_camera(h, &d.camera) == HD_SUCCESS && record_run(h, 1) == HD_SUCCESS);
    CHECK(hd_get_stats(h, &s1) == HD_SUCCESS);
    first_small = s1.render_scale;
    hd_destroy(h);
    CHECK(first_fit == 1 && first_small >= 2);
    printf("%s HD_RENDER_SCALE_AUTO while recording: a new view's first frame at scale %d with a budget of 100 full frames "
           "(%.1f ms each), %d with an eighth of one\n",
           first_fit == 1 && first_small >= 2 ? "PASS" : "FAIL", first_fit, 1e3 * t, first_small);
}

/* 10, 11: hd_vulkan_record_render into the caller's image or buffer. The test's own objects on the
   backend's device (white box: its function table), so the validation layer (core and
   synchronization, the backend's own instance) sees the caller's commands and the library's. */
typedef struct vk_obj {
    VkImage image;
    VkBuffer buffer;
    VkDeviceMemory memory;
    void *map;
} vk_obj;

static int vk_memory(hd__backend *be, VkMemoryRequirements *req, int host, vk_obj *o)
{
    VkMemoryAllocateInfo mai;
    int type = hd__vk_memory_type(be, req->memoryTypeBits,
                                  host ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                       : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
    if (type < 0) return 0;
    memset(&mai, 0, sizeof mai);
    mai.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
    mai.allocationSize = req->size;
    mai.memoryTypeIndex = (uint32_t)type;
    if (be->fn.vkAllocateMemory(be->device, &mai, NULL, &o->memory) != VK_SUCCESS) return 0;
    if (host && be->fn.vkMapMemory(be->device, o->memory, 0, VK_WHOLE_SIZE, 0, &o->map) != VK_SUCCESS) return 0;
    return 1;
}

/* A 2D (d = 1) or 3D image in device memory, usable for copies both ways and sampling (and as the
   depth attachment when D32). */
static int vk_image_of(hd__backend *be, VkImageType type, VkFormat fmt, int w, int h, int d, vk_obj *o)
{
    VkImageCreateInfo ici;
    VkMemoryRequirements req;
    memset(o, 0, sizeof *o);
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    ici.imageType = type;
    ici.format = fmt;
    ici.extent.width = (uint32_t)w;
    ici.extent.height = (uint32_t)h;
    ici.extent.depth = (uint32_t)d;
    ici.mipLevels = 1;
    ici.arrayLayers = 1;
    ici.samples = VK_SAMPLE_COUNT_1_BIT;
    ici.tiling = VK_IMAGE_TILING_OPTIMAL;
    ici.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                (fmt == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT : 0);
    ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    if (be->fn.vkCreateImage(be->device, &ici, NULL, &o->image) != VK_SUCCESS) return 0;
    be->fn.vkGetImageMemoryRequirements(be->device, o->image, &req);
    return vk_memory(be, &req, 0, o) && be->fn.vkBindImageMemory(be->device, o->image, o->memory, 0) == VK_SUCCESS;
}

static int vk_image(hd__backend *be, VkFormat fmt, int w, int h, vk_obj *o) { return vk_image_of(be, VK_IMAGE_TYPE_2D, fmt, w, h, 1, o); }

static int vk_buffer(hd__backend *be, VkDeviceSize bytes, vk_obj *o)
{
    VkBufferCreateInfo bci;
    VkMemoryRequirements req;
    memset(o, 0, sizeof *o);
    memset(&bci, 0, sizeof bci);
    bci.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    bci.size = bytes;
    bci.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT;
    if (be->fn.vkCreateBuffer(be->device, &bci, NULL, &o->buffer) != VK_SUCCESS) return 0;
    be->fn.vkGetBufferMemoryRequirements(be->device, o->buffer, &req);
    return vk_memory(be, &req, 1, o) && be->fn.vkBindBufferMemory(be->device, o->buffer, o->memory, 0) == VK_SUCCESS;
}

static void vk_free(hd__backend *be, vk_obj *o)
{
    if (o->image) be->fn.vkDestroyImage(be->device, o->image, NULL);
    if (o->buffer) be->fn.vkDestroyBuffer(be->device, o->buffer, NULL);
    if (o->memory) be->fn.vkFreeMemory(be->device, o->memory, NULL);
    memset(o, 0, sizeof *o);
}

/* The caller's commands around a call: a command buffer begun, then `after` run on it (the test's
   copies), ended, submitted and waited for, the host's reads made visible. */
typedef struct vk_cmd {
    VkCommandPool pool;
    VkCommandBuffer cb;
} vk_cmd;
static int cmd_begin(hd__backend *be, vk_cmd *c)
{
    VkCommandPoolCreateInfo cpci;
    VkCommandBufferAllocateInfo cbai;
    VkCommandBufferBeginInfo bi;
    memset(&cpci, 0, sizeof cpci);
    cpci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    cpci.queueFamilyIndex = be->queue_family;
    if (be->fn.vkCreateCommandPool(be->device, &cpci, NULL, &c->pool) != VK_SUCCESS) return 0;
    memset(&cbai, 0, sizeof cbai);
    cbai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    cbai.commandPool = c->pool;
    cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cbai.commandBufferCount = 1;
    be->fn.vkAllocateCommandBuffers(be->device, &cbai, &c->cb);
    memset(&bi, 0, sizeof bi);
    bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    return be->fn.vkBeginCommandBuffer(c->cb, &bi) == VK_SUCCESS;
}
static int cmd_submit(hd__backend *be, vk_cmd *c, int submit)
{
    VkSubmitInfo si;
    VkMemoryBarrier mb;
    int ok = 1;
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    be->fn.vkCmdPipelineBarrier(c->cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
    be->fn.vkEndCommandBuffer(c->cb);
    if (submit) {
        memset(&si, 0, sizeof si);
        si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
        si.commandBufferCount = 1;
        si.pCommandBuffers = &c->cb;
        ok = be->fn.vkQueueSubmit(be->queue, 1, &si, VK_NULL_HANDLE) == VK_SUCCESS;
        be->fn.vkDeviceWaitIdle(be->device);
    }
    be->fn.vkDestroyCommandPool(be->device, c->pool, NULL);
    return ok;
}

/* The image's whole contents into host buffer `host` (the image in `layout`, GENERAL or
   TRANSFER_SRC_OPTIMAL). */
static void cmd_read_image(hd__backend *be, VkCommandBuffer cb, const vk_obj *im, VkImageLayout layout, const vk_obj *host, int w, int h)
{
    VkBufferImageCopy reg;
    memset(&reg, 0, sizeof reg);
    reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    reg.imageSubresource.layerCount = 1;
    reg.imageExtent.width = (uint32_t)w;
    reg.imageExtent.height = (uint32_t)h;
    reg.imageExtent.depth = 1;
    be->fn.vkCmdCopyImageToBuffer(cb, im->image, layout, host->buffer, 1, &reg);
}

/* A barrier and layout transition the caller itself would record (the test's own commands):
   transfers before and after, or (to_compute) before a compute shader's reads. */
static void cmd_layout_to(hd__backend *be, VkCommandBuffer cb, VkImage im, VkImageLayout from, VkImageLayout to, int to_compute)
{
    VkImageMemoryBarrier ib;
    memset(&ib, 0, sizeof ib);
    ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    ib.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
    ib.dstAccessMask = to_compute ? VK_ACCESS_SHADER_READ_BIT : VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT;
    ib.oldLayout = from;
    ib.newLayout = to;
    ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    ib.image = im;
    ib.subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    ib.subresourceRange.levelCount = 1;
    ib.subresourceRange.layerCount = 1;
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT,
                                to_compute ? VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT : VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1,
                                &ib);
}
static void cmd_layout(hd__backend *be, VkCommandBuffer cb, VkImage im, VkImageLayout from, VkImageLayout to)
{
    cmd_layout_to(be, cb, im, from, to, 0);
}

enum { OTW = 50, OTH = 37, ORX = 11, ORY = 6 };

/* 10: each format into a region of the caller's image, and into its buffer: the region equal, byte
   for byte, to hd_read_image_ex of the same format after the caller's submission; everything
   outside as it was; the refusals; no validation message. */
static void test_output_target(void)
{
    static const struct { VkFormat vk; hd_output_format f; const char *name; } fmts[5] = {
        {VK_FORMAT_R16G16B16A16_SFLOAT, HD_OUTPUT_LINEAR_F16, "R16G16B16A16_SFLOAT"},
        {VK_FORMAT_R32G32B32A32_SFLOAT, HD_OUTPUT_LINEAR_F32, "R32G32B32A32_SFLOAT"},
        {VK_FORMAT_R8G8B8A8_UNORM, HD_OUTPUT_SRGB8, "R8G8B8A8_UNORM"},
        {VK_FORMAT_R8G8B8A8_SRGB, HD_OUTPUT_SRGB8, "R8G8B8A8_SRGB"},
        {VK_FORMAT_B8G8R8A8_UNORM, HD_OUTPUT_SRGB8, "B8G8R8A8_UNORM"}};
    static unsigned char ex[OTW * OTH * 16 + 64];
    hd_desc d = test_desc();
    hd_context h;
    hd__backend *be;
    vk_obj host, before;
    int k, ok = 1, bad_total = 0;
    d.vulkan.enable_validation = have_layer;
    d.params.exposure = 1.3f;
    d.params.background[0] = 0.1f; /* red and blue apart: a BGRA target's swap shows */
    d.params.background[2] = 0.6f;
    messages = 0;
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    be = hd__lookup(h)->vw.be;
    if (!vk_buffer(be, (VkDeviceSize)OTW * OTH * 16 + 64, &host) || !vk_buffer(be, (VkDeviceSize)OTW * OTH * 16 + 64, &before)) {
        CHECK(0);
        return;
    }
    for (k = 0; k < 6; ++k) { /* 5 images, then a buffer */
        hd_vulkan_target t = HD_VULKAN_TARGET_INIT;
        hd_output o = HD_OUTPUT_INIT;
        hd_output_format f = k < 5 ? fmts[k].f : HD_OUTPUT_LINEAR_F16;
        size_t px = f == HD_OUTPUT_LINEAR_F32 ? 16 : f == HD_OUTPUT_LINEAR_F16 ? 8 : 4, pitch = OTW * px + (k < 5 ? 0 : 24);
        size_t off = k < 5 ? 0 : 40, x, y;
        vk_obj im;
        vk_cmd c;
        hd_result r;
        int outside = 0, region = 0, nonzero = 0;
        memset(&im, 0, sizeof im);
        o.format = f;
        o.x = ORX;
        o.y = ORY;
        t.width = OTW;
        t.height = OTH;
        /* the target's contents before: a clear (image) or a fill (buffer), read back */
        if (!cmd_begin(be, &c)) { CHECK(0); break; }
        if (k < 5) {
            VkClearColorValue cc;
            VkImageSubresourceRange range;
            if (!vk_image(be, fmts[k].vk, OTW, OTH, &im)) { CHECK(0); break; }
            cc.float32[0] = 0.25f; cc.float32[1] = 0.5f; cc.float32[2] = 0.75f; cc.float32[3] = 1.0f;
            memset(&range, 0, sizeof range);
            range.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
            range.levelCount = range.layerCount = 1;
            cmd_layout(be, c.cb, im.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
            be->fn.vkCmdClearColorImage(c.cb, im.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &cc, 1, &range);
            cmd_layout(be, c.cb, im.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
            cmd_read_image(be, c.cb, &im, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, &before, OTW, OTH);
            t.image = (uint64_t)im.image;
            t.format = fmts[k].vk;
            t.layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL; /* where the test's copy left it */
            if (k & 1) { /* or as a sampled image would be */
                cmd_layout(be, c.cb, im.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
                t.layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
            }
            t.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        } else {
            be->fn.vkCmdFillBuffer(c.cb, host.buffer, 0, VK_WHOLE_SIZE, 0xa5c3e1f0u);
            t.buffer = (uint64_t)host.buffer;
            t.offset = off;
            t.row_pitch = pitch;
            t.buffer_size = (uint64_t)OTW * OTH * 16 + 64;
        }
        ok &= cmd_submit(be, &c, 1);
        if (k == 5) memcpy(before.map, host.map, (size_t)OTW * OTH * 16 + 64);
        /* the frame and the write, recorded after the caller's own write of the target in the same
           command buffer (the clear or fill again: the same bytes), then the caller's copy: the
           library's barriers order it after the one and before the other */
        if (!cmd_begin(be, &c)) { CHECK(0); break; }
        if (k < 5) {
            VkClearColorValue cc;
            VkImageSubresourceRange range;
            cc.float32[0] = 0.25f; cc.float32[1] = 0.5f; cc.float32[2] = 0.75f; cc.float32[3] = 1.0f;
            memset(&range, 0, sizeof range);
            range.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
            range.levelCount = range.layerCount = 1;
            cmd_layout(be, c.cb, im.image, (VkImageLayout)t.layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
            be->fn.vkCmdClearColorImage(c.cb, im.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &cc, 1, &range);
            /* left as the clear wrote it (no barrier of the caller's after it), or handed to a
               compute shader's reads in SHADER_READ_ONLY: either way only the library's barrier
               orders its copy after the clear */
            if (k & 1)
                cmd_layout_to(be, c.cb, im.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 1);
            else
                t.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
        } else {
            be->fn.vkCmdFillBuffer(c.cb, host.buffer, 0, VK_WHOLE_SIZE, 0xa5c3e1f0u);
        }
        r = hd_vulkan_record_render(h, c.cb, &t, &o);
        CHECK(r == HD_SUCCESS);
        if (k < 5) cmd_read_image(be, c.cb, &im, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, &host, OTW, OTH);
        ok &= cmd_submit(be, &c, r == HD_SUCCESS) && r == HD_SUCCESS;
        memset(ex, 0, sizeof ex);
        CHECK(hd_read_image_ex(h, &o, ex + off, sizeof ex - off, pitch) == HD_SUCCESS);
        for (y = 0; y < OTH; ++y)
            for (x = 0; x < OTW; ++x) {
                size_t at = off + y * pitch + x * px, i;
                const unsigned char *g = (const unsigned char *)host.map + at, *b = (const unsigned char *)before.map + at;
                if (x >= ORX && x < ORX + 32 && y >= ORY && y < ORY + 24) {
                    unsigned char want[16];
                    memcpy(want, ex + at, px);
                    if (k == 4) { unsigned char tmp = want[0]; want[0] = want[2]; want[2] = tmp; } /* BGRA */
                    region += memcmp(g, want, px) != 0;
                    for (i = 0; i < px; ++i) nonzero += g[i] != 0;
                } else {
                    outside += memcmp(g, b, px) != 0;
                }
            }
        if (k == 5) /* the buffer's bytes outside the target's rows: the padding and the offset */
            for (y = 0; y < OTH; ++y)
                outside += memcmp((const unsigned char *)host.map + off + y * pitch + OTW * px,
                                  (const unsigned char *)before.map + off + y * pitch + OTW * px, pitch - OTW * px) != 0;
        outside += memcmp(host.map, before.map, off) != 0;
        CHECK(region == 0 && outside == 0 && nonzero > 0);
        printf("%s output into the caller's %s %s at (%d, %d) of %dx%d: %d of 768 pixels differ from hd_read_image_ex, %d outside changed\n",
               region || outside || !nonzero ? "FAIL" : "PASS", k < 5 ? "image" : "buffer (offset 40, pitch +24)",
               k < 5 ? fmts[k].name : "LINEAR_F16", ORX, ORY, OTW, OTH, region, outside);
        bad_total += region + outside;
        if (k == 0) { /* refusals before anything is recorded: one error each, the context renders on */
            hd_vulkan_target b = t;
            hd_output bo = o;
            unsigned long before_errors;
            int j;
            for (j = 0; j < 7; ++j) {
                hd_result want;
                b = t;
                bo = o;
                switch (j) {
                case 0: bo.x = OTW - 32 + 1; want = HD_ERROR_OUTPUT_OUTSIDE_TARGET; break;
                case 1: bo.y = -2; want = HD_ERROR_OUTPUT_OUTSIDE_TARGET; break;
                case 2: bo.format = HD_OUTPUT_SRGB8; want = HD_ERROR_OUTPUT_FORMAT; break;
                case 3: bo.width = 31; want = HD_ERROR_OUTPUT_SIZE; break;
                case 4: b.buffer = (uint64_t)host.buffer; want = HD_ERROR_INVALID_PARAMETER; break;
                case 5: b.layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL; want = HD_ERROR_INVALID_ENUM; break;
                default: b.image = 0; b.buffer = (uint64_t)host.buffer; b.buffer_size = 100; want = HD_ERROR_BUFFER_TOO_SMALL; break;
                }
                err_count = 0;
                before_errors = err_count;
                if (!cmd_begin(be, &c)) { CHECK(0); break; }
                r = hd_vulkan_record_render(h, c.cb, &b, &bo);
                cmd_submit(be, &c, 1); /* nothing was recorded: an empty command buffer */
                CHECK(r == want && err_count - before_errors == 1);
                if (r != want || err_count - before_errors != 1)
                    printf("  refusal %d: %s (want %s), %lu errors\n", j, hd_result_string(r), hd_result_string(want), err_count - before_errors);
            }
            printf("PASS output refusals (region outside, negative y, format, size, image and buffer, layout, short buffer): one error each\n");
        }
        if (im.image) vk_free(be, &im);
    }
    vk_free(be, &host);
    vk_free(be, &before);
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(hd_destroy(h) == HD_SUCCESS);
    CHECK(ok && messages == 0);
    printf("%s output targets: %d pixels differ in all, %lu validation messages (core and synchronization%s)\n",
           ok && !bad_total && messages == 0 ? "PASS" : "FAIL", bad_total, messages, have_layer ? "" : ": no layer");
}

/* 11: frames over converged light under recording: hd_vulkan_record_render calls, each submitted
   and waited for, reach light_converged 1 (the light measured by the next call); from then on no
   light iteration is recorded (iterations stay), the image restarts and its frames go up to
   frame_window and stop, and the write into the caller's image goes on (equal to the read-back,
   every call). With rest HD_REST_BLEND the calls after the frames record a pass of paths and the
   blend passes instead: the paths are counted and the written image is still the read-back. */
static void test_record_converged(hd_rest rest)
{
    hd_desc d = test_desc();
    hd_context h;
    hd_stats s;
    hd__backend *be;
    vk_obj im, host;
    uint64_t it_conv = 0, fr = 0;
    int calls = 0, conv_at = -1, k, ok = 1, region = 0;
    static unsigned char ex[32 * 24 * 8];
    d.vulkan.enable_validation = have_layer;
    d.params.light_tolerance = 0.2f;
    d.params.frame_window = 3;
    d.params.rest = rest;
    messages = 0;
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    be = hd__lookup(h)->vw.be;
    if (!vk_image(be, VK_FORMAT_R16G16B16A16_SFLOAT, 32, 24, &im) || !vk_buffer(be, 32 * 24 * 8, &host)) { CHECK(0); return; }
    for (calls = 0; calls < 80; ++calls) {
        hd_vulkan_target t = HD_VULKAN_TARGET_INIT;
        hd_output o = HD_OUTPUT_INIT;
        vk_cmd c;
        o.format = HD_OUTPUT_LINEAR_F16;
        t.image = (uint64_t)im.image;
        t.format = VK_FORMAT_R16G16B16A16_SFLOAT;
        t.layout = calls == 0 ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        t.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        t.width = 32;
        t.height = 24;
        if (!cmd_begin(be, &c)) { CHECK(0); break; }
        ok &= hd_vulkan_record_render(h, c.cb, &t, &o) == HD_SUCCESS;
        cmd_read_image(be, c.cb, &im, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, &host, 32, 24);
        ok &= cmd_submit(be, &c, 1);
        CHECK(hd_read_image_ex(h, &o, ex, sizeof ex, 0) == HD_SUCCESS);
        region += memcmp(ex, host.map, sizeof ex) != 0;
        CHECK(hd_get_stats(h, &s) == HD_SUCCESS);
        if (conv_at < 0 && s.light_converged) {
            conv_at = calls;
            it_conv = s.iterations;
            fr = s.frames;
        }
        if (conv_at >= 0 && calls >= conv_at + 6) break;
    }
    CHECK(conv_at >= 0);
    CHECK(hd_get_stats(h, &s) == HD_SUCCESS);
    /* the read-back after a call's submission measured its light iteration (the next call to reach
       the device does) and found it converged: the image restarted there (no frame yet), and no
       later call recorded a light iteration; the image then holds frame_window frames */
    k = conv_at >= 0 && s.light_converged && s.iterations == it_conv && s.frames == 3 && fr == 0 &&
        (rest == HD_REST_BLEND ? s.refine_paths >= 2 : s.refine_paths == 0);
    CHECK(k);
    vk_free(be, &im);
    vk_free(be, &host);
    CHECK(hd_destroy(h) == HD_SUCCESS);
    CHECK(ok && region == 0 && messages == 0);
    printf("%s frames over converged light under recording%s: light_converged after %d calls (%llu iterations, %llu after 6 more "
           "calls), %llu frame then, %llu after (frame_window 3), %llu paths; %d written images differ from the read-back; %lu "
           "validation messages\n",
           ok && k && region == 0 && messages == 0 ? "PASS" : "FAIL", rest == HD_REST_BLEND ? " (rest BLEND)" : "", conv_at + 1,
           (unsigned long long)it_conv, (unsigned long long)s.iterations, (unsigned long long)fr, (unsigned long long)s.frames,
           (unsigned long long)s.refine_paths, region, messages);
}

/* 12: hd_vulkan_record_depth: the host's depth as a VkBuffer of floats, and as a D32_SFLOAT
   image in DEPTH_STENCIL_ATTACHMENT_OPTIMAL (filled by the caller's own copy in the same command
   buffer), copied inside the caller's command buffer before hd_vulkan_record_render's frame:
   two frames (the second without a new copy) give bit for bit the image of hd_set_depth with the
   same values, which differs from the image without depth. Refusals (a colour format, layout
   UNDEFINED, an image and a buffer, a buffer too small, a NULL command buffer, a look-at camera)
   each its own hd_result and one logged error, nothing recorded. No validation message. */
enum { DW = 32, DH = 24 };
static void depth_values(float *v)
{
    double n = 0.1, f = 10.0;
    int x, y;
    for (y = 0; y < DH; ++y)
        for (x = 0; x < DW; ++x) {
            double z = x < DW / 3 || y < DH / 2 ? -2.2 : (x >= DW / 2 - 2 && x < DW / 2 + 2) ? -2.5 : 0.0;
            v[y * DW + x] = z == 0.0 ? 1.0f : (float)((f / (n - f) * z + f * n / (n - f)) / -z);
        }
}
static void depth_camera(hd_desc *d)
{
    double n = 0.1, f = 10.0, th = tan(20.0 * 3.14159265358979 / 180.0);
    d->camera.view[0] = d->camera.view[5] = d->camera.view[10] = d->camera.view[15] = 1.0f;
    d->camera.view[14] = -2.5f;
    d->camera.projection[0] = (float)(1.0 / (th * DW / DH));
    d->camera.projection[5] = (float)(1.0 / th);
    d->camera.projection[10] = (float)(f / (n - f));
    d->camera.projection[11] = -1.0f;
    d->camera.projection[14] = (float)(f * n / (n - f));
    d->camera.depth_range = HD_DEPTH_ZERO_TO_ONE;
}
/* The image after two recorded frames with the depth given by `mode`: 0 none, 1 hd_set_depth,
   2 a buffer, 3 an image (and, mode 3, the refusals first). */
static int depth_frames(int mode, float *img)
{
    hd_desc d = test_desc();
    hd_context h;
    hd__backend *be;
    vk_obj buf, im;
    float vals[DW * DH];
    int k, ok = 1;
    depth_values(vals);
    depth_camera(&d);
    d.vulkan.enable_validation = have_layer;
    if (hd_create(&d, &h) != HD_SUCCESS) return 0;
    be = hd__lookup(h)->vw.be;
    memset(&buf, 0, sizeof buf);
    memset(&im, 0, sizeof im);
    if (mode == 1) {
        hd_depth_desc dd;
        dd.data = vals; dd.width = DW; dd.height = DH;
        ok &= hd_set_depth(h, &dd) == HD_SUCCESS;
    }
    if (mode >= 2) {
        ok &= vk_buffer(be, 64 + sizeof vals, &buf);
        if (ok) memcpy((char *)buf.map + 64, vals, sizeof vals);
    }
    if (mode == 3) ok &= vk_image(be, VK_FORMAT_D32_SFLOAT, DW, DH, &im);
    for (k = 0; k < 2 && ok; ++k) {
        vk_cmd c;
        if (!cmd_begin(be, &c)) { ok = 0; break; }
        if (k == 0 && mode >= 2) {
            hd_vulkan_depth dep = HD_VULKAN_DEPTH_INIT;
            if (mode == 2) {
                dep.buffer = (uint64_t)buf.buffer;
                dep.offset = 64;
                dep.buffer_size = 64 + sizeof vals;
            } else {
                /* the caller's own upload into its depth attachment */
                VkImageMemoryBarrier ib;
                VkBufferImageCopy reg;
                memset(&ib, 0, sizeof ib);
                ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
                ib.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
                ib.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
                ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                ib.image = im.image;
                ib.subresourceRange.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
                ib.subresourceRange.levelCount = 1;
                ib.subresourceRange.layerCount = 1;
                be->fn.vkCmdPipelineBarrier(c.cb, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, &ib);
                memset(&reg, 0, sizeof reg);
                reg.bufferOffset = 64;
                reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_DEPTH_BIT;
                reg.imageSubresource.layerCount = 1;
                reg.imageExtent.width = DW;
                reg.imageExtent.height = DH;
                reg.imageExtent.depth = 1;
                be->fn.vkCmdCopyBufferToImage(c.cb, buf.buffer, im.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &reg);
                ib.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
                ib.dstAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
                ib.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                ib.newLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
                be->fn.vkCmdPipelineBarrier(c.cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT, 0, 0, NULL, 0, NULL,
                                            1, &ib);
                dep.image = (uint64_t)im.image;
                dep.format = VK_FORMAT_D32_SFLOAT;
                dep.layout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
                { /* refusals: nothing recorded, one error each */
                    hd_vulkan_depth bad = dep;
                    unsigned long e0;
                    hd_result r;
                    bad.format = VK_FORMAT_R8G8B8A8_UNORM;
                    e0 = err_count; r = hd_vulkan_record_depth(h, c.cb, &bad);
                    CHECK(r == HD_ERROR_DEPTH_FORMAT && err_count == e0 + 1);
                    bad = dep; bad.layout = VK_IMAGE_LAYOUT_UNDEFINED;
                    e0 = err_count; r = hd_vulkan_record_depth(h, c.cb, &bad);
                    CHECK(r == HD_ERROR_INVALID_PARAMETER && err_count == e0 + 1);
                    bad = dep; bad.buffer = (uint64_t)buf.buffer;
                    e0 = err_count; r = hd_vulkan_record_depth(h, c.cb, &bad);
                    CHECK(r == HD_ERROR_INVALID_PARAMETER && err_count == e0 + 1);
                    bad = dep; bad.image = 0; bad.buffer = (uint64_t)buf.buffer; bad.offset = 64; bad.buffer_size = sizeof vals;
                    e0 = err_count; r = hd_vulkan_record_depth(h, c.cb, &bad);
                    CHECK(r == HD_ERROR_BUFFER_TOO_SMALL && err_count == e0 + 1);
                    e0 = err_count; r = hd_vulkan_record_depth(h, NULL, &dep);
                    CHECK(r == HD_ERROR_NULL_POINTER && err_count == e0 + 1);
                }
            }
            ok &= hd_vulkan_record_depth(h, c.cb, &dep) == HD_SUCCESS;
        }
        ok &= hd_vulkan_record_render(h, c.cb, NULL, NULL) == HD_SUCCESS;
        ok &= cmd_submit(be, &c, 1);
    }
    ok &= hd_read_image_f32(h, img, (size_t)DW * DH * 4) == HD_SUCCESS;
    vk_free(be, &buf);
    vk_free(be, &im);
    CHECK(hd_destroy(h) == HD_SUCCESS);
    return ok;
}
static void test_record_depth(void)
{
    static float img[4][DW * DH * 4];
    int mode, ok = 1, same, differs;
    messages = 0;
    for (mode = 0; mode < 4; ++mode) ok &= depth_frames(mode, img[mode]);
    same = memcmp(img[1], img[2], sizeof img[1]) == 0 && memcmp(img[1], img[3], sizeof img[1]) == 0;
    differs = memcmp(img[0], img[1], sizeof img[0]) != 0;
    { /* a look-at camera cannot take it */
        hd_desc d = test_desc();
        hd_context h;
        hd_vulkan_depth dep = HD_VULKAN_DEPTH_INIT;
        unsigned long e0;
        dep.buffer = 1; dep.buffer_size = (uint64_t)DW * DH * 4;
        CHECK(hd_create(&d, &h) == HD_SUCCESS);
        e0 = err_count;
        CHECK(hd_vulkan_record_depth(h, (void *)&dep, &dep) == HD_ERROR_DEPTH_NEEDS_PROJECTION && err_count == e0 + 1);
        CHECK(hd_destroy(h) == HD_SUCCESS);
    }
    CHECK(ok && same && differs && messages == 0);
    printf("%s depth from the caller's VkBuffer and D32_SFLOAT image inside its command buffer: %s hd_set_depth's image%s; "
           "refusals one error each; %lu validation messages\n",
           ok && same && differs && messages == 0 ? "PASS" : "FAIL", same ? "bit for bit" : "NOT", differs ? "" : " (no effect!)", messages);
}

/* 13: hd_vulkan_record_illumination: E + phi of each channel (one light: 1; two of different
   colours: 3) into the caller's VkBuffer (at an offset) and into a 3D R32_SFLOAT image one texel
   larger each way, cleared to a pattern by the caller in the same command buffer: bit for bit
   hd_read_illumination's HD_ILLUMINATION_TOTAL, the texels beyond the grid kept; after
   hd_refine (the summed light stale) it follows the light; recorded before hd_vulkan_record_render
   in one command buffer it holds the light at the call, the frame's iteration after it. Refusals
   (NULL command buffer or target, an image and a buffer, neither, a channel past the grid's, a
   negative one, R16_SFLOAT, layout PRESENT_SRC, final layout UNDEFINED, an image smaller than the
   grid, an odd offset, a buffer too small, method PT_SS) each its own hd_result and one logged
   error, nothing recorded (the image keeps its pattern). No validation message. */
static int light_equal(const float *a, const float *b, size_t n)
{
    return memcmp(a, b, n * sizeof(float)) == 0;
}
static void cmd_clear3d(hd__backend *be, VkCommandBuffer cb, VkImage im, VkImageLayout from)
{
    VkImageMemoryBarrier ib;
    VkClearColorValue c;
    VkImageSubresourceRange range;
    memset(&ib, 0, sizeof ib);
    ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
    ib.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    ib.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    ib.oldLayout = from;
    ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    ib.image = im;
    ib.subresourceRange.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    ib.subresourceRange.levelCount = 1;
    ib.subresourceRange.layerCount = 1;
    range = ib.subresourceRange;
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, NULL, 0, NULL, 1, &ib);
    memset(&c, 0, sizeof c);
    c.float32[0] = -7.0f;
    be->fn.vkCmdClearColorImage(cb, im, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &c, 1, &range);
}
/* The 3D image (in TRANSFER_SRC_OPTIMAL) into host buffer `host`. */
static void cmd_read3d(hd__backend *be, VkCommandBuffer cb, VkImage im, VkBuffer host, int w, int h, int dd)
{
    VkBufferImageCopy reg;
    VkMemoryBarrier mb;
    memset(&mb, 0, sizeof mb);
    mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
    mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
    be->fn.vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, NULL, 0, NULL);
    memset(&reg, 0, sizeof reg);
    reg.imageSubresource.aspectMask = VK_IMAGE_ASPECT_COLOR_BIT;
    reg.imageSubresource.layerCount = 1;
    reg.imageExtent.width = (uint32_t)w;
    reg.imageExtent.height = (uint32_t)h;
    reg.imageExtent.depth = (uint32_t)dd;
    be->fn.vkCmdCopyImageToBuffer(cb, im, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, host, 1, &reg);
}
static void test_record_illumination(void)
{
    int rgb, ok = 1, refusals_ok = 1, kept_ok = 1, follows = 0, at_call = 1, channels_seen = 0;
    hd_light l[2];
    messages = 0;
    memset(l, 0, sizeof l);
    l[0].direction[1] = -1.0f; l[0].color[0] = 1.0f; l[0].color[1] = 0.5f; l[0].color[2] = 0.2f;
    l[1].direction[0] = 1.0f; l[1].color[0] = 0.2f; l[1].color[1] = 0.6f; l[1].color[2] = 1.0f;
    for (rgb = 0; rgb < 2 && ok; ++rgb) {
        hd_desc d = test_desc();
        hd_context h;
        hd__backend *be;
        hd_stats st;
        vk_obj buf, im, host;
        float *tot, *prev;
        size_t g, n, i;
        int gx, gy, gz, ch, k, pass;
        VkDeviceSize bytes, ibytes;
        d.lights = l;
        d.light_count = rgb ? 2 : 1;
        d.vulkan.enable_validation = have_layer;
        if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
        be = hd__lookup(h)->vw.be;
        CHECK(hd_iterate(h, 2) == HD_SUCCESS && hd_get_stats(h, &st) == HD_SUCCESS);
        gx = st.illumination_dims[0]; gy = st.illumination_dims[1]; gz = st.illumination_dims[2]; ch = st.illumination_channels;
        CHECK(ch == (rgb ? 3 : 1));
        g = (size_t)gx * gy * gz;
        n = g * ch;
        bytes = g * sizeof(float);
        ibytes = (VkDeviceSize)(gx + 1) * (gy + 1) * (gz + 1) * sizeof(float);
        tot = (float *)malloc(n * sizeof(float));
        prev = (float *)malloc(n * sizeof(float));
        ok &= tot && prev && vk_buffer(be, 64 + bytes, &buf) && vk_buffer(be, ibytes, &host) &&
              vk_image_of(be, VK_IMAGE_TYPE_3D, VK_FORMAT_R32_SFLOAT, gx + 1, gy + 1, gz + 1, &im);
        for (pass = 0; pass < 3 && ok; ++pass) {
            if (pass == 1) CHECK(hd_refine(h, 2) == HD_SUCCESS); /* light only: the summed light is stale */
            ok &= hd_read_illumination(h, HD_ILLUMINATION_TOTAL, tot, n) == HD_SUCCESS;
            if (pass == 1) follows = !light_equal(tot, prev, n);
            memcpy(prev, tot, n * sizeof(float));
            for (k = 0; k < ch && ok; ++k) {
                vk_cmd c;
                hd_vulkan_volume_target tb = HD_VULKAN_VOLUME_TARGET_INIT, ti = HD_VULKAN_VOLUME_TARGET_INIT;
                const float *img = (const float *)host.map;
                int x, y, z;
                tb.buffer = (uint64_t)buf.buffer; tb.offset = 64; tb.buffer_size = 64 + bytes;
                ti.image = (uint64_t)im.image; ti.format = VK_FORMAT_R32_SFLOAT;
                ti.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL; ti.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
                ti.width = gx + 1; ti.height = gy + 1; ti.depth = gz + 1;
                memset(buf.map, 0xff, (size_t)(64 + bytes));
                if (!cmd_begin(be, &c)) { ok = 0; break; }
                cmd_clear3d(be, c.cb, im.image, VK_IMAGE_LAYOUT_UNDEFINED);
                ok &= hd_vulkan_record_illumination(h, c.cb, k, &tb) == HD_SUCCESS;
                if (pass == 0 && k == 0) { /* refusals: nothing recorded, one error each */
                    struct { hd_vulkan_volume_target t; int ch; void *cb; hd_result want; } cs[12];
                    unsigned long e0;
                    int j, nc = 0;
                    hd_result r;
                    for (j = 0; j < 12; ++j) { cs[j].t = ti; cs[j].ch = 0; cs[j].cb = c.cb; }
                    cs[nc].cb = NULL; cs[nc++].want = HD_ERROR_NULL_POINTER;
                    cs[nc].t.buffer = (uint64_t)buf.buffer; cs[nc++].want = HD_ERROR_INVALID_PARAMETER;
                    cs[nc].t.image = 0; cs[nc++].want = HD_ERROR_INVALID_PARAMETER;
                    cs[nc].ch = ch; cs[nc++].want = HD_ERROR_INVALID_PARAMETER;
                    cs[nc].ch = -1; cs[nc++].want = HD_ERROR_INVALID_PARAMETER;
                    cs[nc].t.format = VK_FORMAT_R16_SFLOAT; cs[nc++].want = HD_ERROR_OUTPUT_FORMAT;
                    cs[nc].t.layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR; cs[nc++].want = HD_ERROR_INVALID_ENUM;
                    cs[nc].t.layout = VK_IMAGE_LAYOUT_UNDEFINED; cs[nc].t.final_layout = 0; cs[nc++].want = HD_ERROR_INVALID_ENUM;
                    cs[nc].t.depth = gz - 1; cs[nc++].want = HD_ERROR_OUTPUT_OUTSIDE_TARGET;
                    cs[nc].t = tb; cs[nc].t.offset = 66; cs[nc++].want = HD_ERROR_INVALID_PARAMETER;
                    cs[nc].t = tb; cs[nc].t.buffer_size = 60 + bytes; cs[nc++].want = HD_ERROR_BUFFER_TOO_SMALL;
                    for (j = 0; j < nc; ++j) {
                        e0 = err_count;
                        r = hd_vulkan_record_illumination(h, cs[j].cb, cs[j].ch, &cs[j].t);
                        if (r != cs[j].want || err_count != e0 + 1) {
                            refusals_ok = 0;
                            fprintf(stderr, "  refusal %d: %s, %lu errors\n", j, hd_result_string(r), err_count - e0);
                        }
                    }
                    e0 = err_count;
                    r = hd_vulkan_record_illumination(h, c.cb, 0, NULL);
                    refusals_ok &= r == HD_ERROR_NULL_POINTER && err_count == e0 + 1;
                }
                ok &= hd_vulkan_record_illumination(h, c.cb, k, &ti) == HD_SUCCESS;
                cmd_read3d(be, c.cb, im.image, host.buffer, gx + 1, gy + 1, gz + 1);
                if (pass == 2) ok &= hd_vulkan_record_render(h, c.cb, NULL, NULL) == HD_SUCCESS; /* after the copies */
                ok &= cmd_submit(be, &c, 1);
                if (!ok) break;
                if (!light_equal((const float *)((const char *)buf.map + 64), tot + (size_t)k * g, g)) {
                    ok = 0;
                    fprintf(stderr, "  pass %d channel %d: the buffer is not E + phi\n", pass, k);
                }
                for (z = 0; z <= gz; ++z)
                    for (y = 0; y <= gy; ++y)
                        for (x = 0; x <= gx; ++x) {
                            float v = img[((size_t)z * (gy + 1) + y) * (gx + 1) + x];
                            if (x < gx && y < gy && z < gz) {
                                if (memcmp(&v, &tot[k * g + ((size_t)z * gy + y) * gx + x], sizeof v) != 0) ok = 0;
                            } else if (v != -7.0f) kept_ok = 0;
                        }
                if (!ok) fprintf(stderr, "  pass %d channel %d: the image is not E + phi\n", pass, k);
                if (pass == 2) { /* the frame's light iteration ran after the copy */
                    ok &= hd_read_illumination(h, HD_ILLUMINATION_TOTAL, prev, n) == HD_SUCCESS;
                    at_call &= !light_equal(prev, tot, n);
                    memcpy(tot, prev, n * sizeof(float));
                }
                channels_seen += pass == 0;
            }
            for (i = 0, k = 0; i < g; ++i) k += tot[i] > 0.0f;
            CHECK((size_t)k > g / 20);
        }
        vk_free(be, &buf); vk_free(be, &im); vk_free(be, &host);
        free(tot); free(prev);
        CHECK(hd_destroy(h) == HD_SUCCESS);
    }
    { /* the path tracers keep no light volume */
        hd_desc d = test_desc();
        hd_context h;
        hd_vulkan_volume_target t = HD_VULKAN_VOLUME_TARGET_INIT;
        unsigned long e0;
        d.params.method = HD_METHOD_PT_SS;
        t.buffer = 1; t.buffer_size = 1u << 30;
        CHECK(hd_create(&d, &h) == HD_SUCCESS);
        e0 = err_count;
        refusals_ok &= hd_vulkan_record_illumination(h, (void *)&t, 0, &t) == HD_ERROR_UNSUPPORTED && err_count == e0 + 1;
        CHECK(hd_destroy(h) == HD_SUCCESS);
    }
    CHECK(ok && refusals_ok && kept_ok && follows && at_call && channels_seen == 4 && messages == 0);
    printf("%s light into the caller's VkBuffer and 3D R32_SFLOAT image (1 and 3 channels): %s hd_read_illumination's E + phi, "
           "texels beyond the grid %s, %s the light after hd_refine, %s before the frame's iteration; refusals %s; %lu validation messages\n",
           ok && refusals_ok && kept_ok && follows && at_call && channels_seen == 4 && messages == 0 ? "PASS" : "FAIL",
           ok ? "bit for bit" : "NOT", kept_ok ? "kept" : "WRITTEN", follows ? "follows" : "does NOT follow",
           at_call ? "the light at the call" : "NOT the light at the call", refusals_ok ? "one error each" : "WRONG", messages);
}

static hd__backend *be_of(hd_context h) { return hd__lookup(h)->vw.be; }

/* 14: hd_vulkan_record_refine, the light alone inside the caller's command buffer: after a frame,
   three recorded light iterations followed in the same command buffer by
   hd_vulkan_record_illumination into the caller's 3D R32_SFLOAT image (cleared by the caller in
   that command buffer first) and into its buffer give, bit for bit, hd_read_illumination's
   HD_ILLUMINATION_TOTAL after the submission, and the same light as hd_refine(3) on a twin
   context; the light differs from the one before; the image and its frame count are as they
   were; the iterations count and are measured by the next call, not by the copies (the light
   error is that of the same recording without them, and not the one before); a copy recorded
   after hd_vulkan_record_render in one command buffer holds that frame's refined light.
   Methods HD and CD. Refusals (NULL command buffer, n 0, PT_SS, solver MULTIGRID) each its own
   hd_result and one logged error, nothing recorded. No validation message. */
static void test_record_refine(void)
{
    static const hd_method methods[2] = {HD_METHOD_HD, HD_METHOD_CD};
    int m, ok = 1, same = 1, twin = 1, follows = 1, image_kept = 1, measured = 1, after_frame = 1, refusals_ok = 1;
    messages = 0;
    for (m = 0; m < 2; ++m) {
        hd_desc d = test_desc();
        hd_context h, ref;
        hd__backend *be;
        hd_stats s0, s1, sr;
        vk_obj buf, im, host;
        float *before, *tot, *want, *img0, *img1;
        size_t g, i, npx = (size_t)32 * 24 * 4;
        int gx, gy, gz, x, y, z;
        VkDeviceSize bytes, ibytes;
        vk_cmd c;
        hd_vulkan_volume_target tb = HD_VULKAN_VOLUME_TARGET_INIT, ti = HD_VULKAN_VOLUME_TARGET_INIT;
        d.params.method = methods[m];
        d.vulkan.enable_validation = have_layer;
        if (hd_create(&d, &h) != HD_SUCCESS || hd_create(&d, &ref) != HD_SUCCESS) { CHECK(0); return; }
        be = hd__lookup(h)->vw.be;
        CHECK(hd_iterate(h, 1) == HD_SUCCESS && hd_iterate(ref, 1) == HD_SUCCESS && hd_get_stats(h, &s0) == HD_SUCCESS);
        gx = s0.illumination_dims[0]; gy = s0.illumination_dims[1]; gz = s0.illumination_dims[2];
        g = (size_t)gx * gy * gz;
        bytes = g * sizeof(float);
        ibytes = (VkDeviceSize)(gx + 1) * (gy + 1) * (gz + 1) * sizeof(float);
        before = (float *)malloc(g * sizeof(float));
        tot = (float *)malloc(g * sizeof(float));
        want = (float *)malloc(g * sizeof(float));
        img0 = (float *)malloc(npx * sizeof(float));
        img1 = (float *)malloc(npx * sizeof(float));
        ok &= before && tot && want && img0 && img1 && vk_buffer(be, 64 + bytes, &buf) && vk_buffer(be, ibytes, &host) &&
              vk_image_of(be, VK_IMAGE_TYPE_3D, VK_FORMAT_R32_SFLOAT, gx + 1, gy + 1, gz + 1, &im);
        if (!ok) { CHECK(0); break; }
        ok &= hd_read_illumination(h, HD_ILLUMINATION_TOTAL, before, g) == HD_SUCCESS;
        ok &= hd_read_image_f32(h, img0, npx) == HD_SUCCESS;
        tb.buffer = (uint64_t)buf.buffer; tb.offset = 64; tb.buffer_size = 64 + bytes;
        ti.image = (uint64_t)im.image; ti.format = VK_FORMAT_R32_SFLOAT;
        ti.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL; ti.final_layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        ti.width = gx + 1; ti.height = gy + 1; ti.depth = gz + 1;
        memset(buf.map, 0xff, (size_t)(64 + bytes));
        /* the light alone: refined, summed and copied in one command buffer */
        if (!cmd_begin(be, &c)) { CHECK(0); break; }
        cmd_clear3d(be, c.cb, im.image, VK_IMAGE_LAYOUT_UNDEFINED);
        ok &= hd_vulkan_record_refine(h, c.cb, 3) == HD_SUCCESS;
        ok &= hd_vulkan_record_illumination(h, c.cb, 0, &ti) == HD_SUCCESS;
        ok &= hd_vulkan_record_illumination(h, c.cb, 0, &tb) == HD_SUCCESS;
        cmd_read3d(be, c.cb, im.image, host.buffer, gx + 1, gy + 1, gz + 1);
        ok &= cmd_submit(be, &c, 1);
        CHECK(ok);
        /* the read reaches the device: it measures the recorded iterations (hd_get_stats does not) */
        ok &= hd_read_illumination(h, HD_ILLUMINATION_TOTAL, tot, g) == HD_SUCCESS && hd_get_stats(h, &s1) == HD_SUCCESS;
        ok &= hd_refine(ref, 3) == HD_SUCCESS && hd_read_illumination(ref, HD_ILLUMINATION_TOTAL, want, g) == HD_SUCCESS &&
              hd_get_stats(ref, &sr) == HD_SUCCESS;
        same &= light_equal((const float *)((const char *)buf.map + 64), tot, g);
        for (z = 0; z <= gz; ++z)
            for (y = 0; y <= gy; ++y)
                for (x = 0; x <= gx; ++x) {
                    float v = ((const float *)host.map)[((size_t)z * (gy + 1) + y) * (gx + 1) + x];
                    if (x < gx && y < gy && z < gz) same &= memcmp(&v, &tot[((size_t)z * gy + y) * gx + x], sizeof v) == 0;
                    else same &= v == -7.0f;
                }
        twin &= light_equal(tot, want, g);
        follows &= !light_equal(tot, before, g);
        for (i = 0, x = 0; i < g; ++i) x += tot[i] > 0.0f;
        follows &= (size_t)x > g / 20;
        ok &= hd_read_image_f32(h, img1, npx) == HD_SUCCESS;
        image_kept &= memcmp(img0, img1, npx * sizeof(float)) == 0 && s1.frames == s0.frames;
        { /* the copies measured nothing: the error is that of the same recording without them */
            hd_context solo;
            hd_stats ss;
            memset(&ss, 0, sizeof ss);
            if (hd_create(&d, &solo) == HD_SUCCESS && hd_iterate(solo, 1) == HD_SUCCESS && cmd_begin(be_of(solo), &c)) {
                ok &= hd_vulkan_record_refine(solo, c.cb, 3) == HD_SUCCESS && cmd_submit(be_of(solo), &c, 1);
                ok &= hd_read_illumination(solo, HD_ILLUMINATION_TOTAL, want, g) == HD_SUCCESS && hd_get_stats(solo, &ss) == HD_SUCCESS;
                CHECK(hd_destroy(solo) == HD_SUCCESS);
            } else ok = 0;
            measured &= ss.light_error == s1.light_error && light_equal(want, tot, g);
        }
        measured &= s1.iterations == s0.iterations + 3 && sr.iterations == s1.iterations && s1.light_error != s0.light_error;
        if (!measured)
            fprintf(stderr, "  %s: iterations %llu -> %llu (twin %llu), light error %g -> %g\n", hd_method_name(methods[m]),
                    (unsigned long long)s0.iterations, (unsigned long long)s1.iterations, (unsigned long long)sr.iterations,
                    s0.light_error, s1.light_error);
        /* a copy after a frame in the same command buffer: the frame's refined light */
        memset(buf.map, 0xff, (size_t)(64 + bytes));
        if (!cmd_begin(be, &c)) { CHECK(0); break; }
        ok &= hd_vulkan_record_render(h, c.cb, NULL, NULL) == HD_SUCCESS;
        ok &= hd_vulkan_record_illumination(h, c.cb, 0, &tb) == HD_SUCCESS;
        ok &= cmd_submit(be, &c, 1);
        ok &= hd_read_illumination(h, HD_ILLUMINATION_TOTAL, want, g) == HD_SUCCESS;
        after_frame &= light_equal((const float *)((const char *)buf.map + 64), want, g) && !light_equal(want, tot, g);
        if (m == 0) { /* refusals: one error each, nothing recorded */
            hd_desc dp = test_desc();
            hd_params p;
            hd_context pt;
            unsigned long e0;
            hd_result r;
            if (!cmd_begin(be, &c)) { CHECK(0); break; }
            e0 = err_count; r = hd_vulkan_record_refine(h, NULL, 1);
            refusals_ok &= r == HD_ERROR_NULL_POINTER && err_count == e0 + 1;
            e0 = err_count; r = hd_vulkan_record_refine(h, c.cb, 0);
            refusals_ok &= r == HD_ERROR_INVALID_PARAMETER && err_count == e0 + 1;
            CHECK(hd_query_desc(h, &dp) == HD_SUCCESS);
            p = dp.params;
            p.solver = HD_SOLVER_MULTIGRID;
            p.diffusion_sweeps = 1;
            CHECK(hd_set_params(h, &p) == HD_SUCCESS);
            e0 = err_count; r = hd_vulkan_record_refine(h, c.cb, 1);
            refusals_ok &= r == HD_ERROR_UNSUPPORTED && err_count == e0 + 1;
            dp = test_desc();
            dp.params.method = HD_METHOD_PT_SS;
            dp.vulkan.enable_validation = have_layer;
            CHECK(hd_create(&dp, &pt) == HD_SUCCESS);
            e0 = err_count; r = hd_vulkan_record_refine(pt, c.cb, 1);
            refusals_ok &= r == HD_ERROR_UNSUPPORTED && err_count == e0 + 1;
            CHECK(hd_destroy(pt) == HD_SUCCESS);
            ok &= cmd_submit(be, &c, 1); /* nothing was recorded: an empty command buffer */
        }
        vk_free(be, &buf); vk_free(be, &im); vk_free(be, &host);
        free(before); free(tot); free(want); free(img0); free(img1);
        CHECK(hd_destroy(h) == HD_SUCCESS && hd_destroy(ref) == HD_SUCCESS);
    }
    CHECK(ok && same && twin && follows && image_kept && measured && after_frame && refusals_ok && messages == 0);
    printf("%s the light alone recorded (hd_vulkan_record_refine, HD and CD): its copy in the same command buffer %s "
           "hd_read_illumination's E + phi, %s hd_refine's on a twin context, %s the light before; the image %s; iterations %s; "
           "a copy after a recorded frame %s; refusals %s; %lu validation messages (core and synchronization%s)\n",
           ok && same && twin && follows && image_kept && measured && after_frame && refusals_ok && messages == 0 ? "PASS" : "FAIL",
           same ? "bit for bit" : "NOT", twin ? "bit for bit" : "NOT", follows ? "differs from" : "does NOT differ from",
           image_kept ? "kept" : "CHANGED", measured ? "counted and measured by the next call" : "NOT counted or measured",
           after_frame ? "holds the frame's refined light" : "does NOT hold the frame's light", refusals_ok ? "one error each" : "WRONG",
           messages, have_layer ? "" : ": no layer");
}

/* Every block count's stride makes b -> b p mod n a permutation (p coprime to n), and each
   contiguous run of the dispatch's blocks, as a thread pool of T threads splits them, draws about
   a quarter of its blocks from each quarter of the image (blocks in order would give one run the
   top and one the bottom). */
static void test_row_order(void)
{
    static const int threads[] = {2, 3, 4, 8, 16};
    int h, bad = 0, i;
    double worst = 0.0;
    for (h = 1; h <= HD_MAX_IMAGE_DIM; h = h == 4096 ? HD_MAX_IMAGE_DIM - 64 : h + 1) {
        int p = hd__gpu_row_stride(h), a = h, b = p;
        while (b) {
            int t = a % b;
            a = b;
            b = t;
        }
        if (p < 1 || (h > 1 && p >= h) || a != 1) {
            if (bad++ < 5) fprintf(stderr, "  %d blocks: stride %d is not coprime to it\n", h, p);
            continue;
        }
        for (i = 0; i < (int)(sizeof threads / sizeof threads[0]); ++i) {
            int T = threads[i], n = h / T, k, y, q;
            if (h < 64 * T) continue;
            for (k = 0; k < T; ++k) {
                int count[4] = {0, 0, 0, 0};
                for (y = k * n; y < (k + 1) * n; ++y) count[(int)((long long)y * p % h * 4 / h)]++;
                for (q = 0; q < 4; ++q) {
                    double dev = fabs(count[q] - n / 4.0) / (n / 4.0);
                    if (dev > worst) worst = dev;
                    if (dev > 0.35 && bad++ < 5)
                        fprintf(stderr, "  %d blocks, %d runs: run %d has %d of its %d blocks in quarter %d\n", h, T, k, count[q], n, q);
                }
            }
        }
    }
    CHECK(bad == 0);
    printf("%s the projection's block order: a permutation at every block count, each thread's run of blocks %.0f %% from "
           "a quarter of them per image quarter at worst\n", bad ? "FAIL" : "PASS", 100.0 * worst);
}

/* Every image row is drawn with the rows spread (on lavapipe): a 40x100 view (blocks of 32, 32,
   32 and 4 rows) that misses the volume is the background, exactly, at every pixel. */
static void test_rows_covered(void)
{
    hd_desc d = test_desc();
    hd_context h;
    static float img[40 * 100 * 4];
    int i, bad = 0;
    d.camera.width = 40;
    d.camera.height = 100;
    d.camera.eye[2] = 3.0f;
    d.camera.target[2] = 6.0f; /* looking away from the volume */
    d.camera.up[1] = 1.0f;
    d.params.background[0] = 0.25f; d.params.background[1] = 0.5f; d.params.background[2] = 0.75f;
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    CHECK(hd_iterate(h, 1) == HD_SUCCESS);
    CHECK(hd_read_image_f32(h, img, sizeof img / sizeof img[0]) == HD_SUCCESS);
    for (i = 0; i < 40 * 100; ++i)
        bad += img[4 * i] != 0.25f || img[4 * i + 1] != 0.5f || img[4 * i + 2] != 0.75f || img[4 * i + 3] != 0.0f;
    hd_destroy(h);
    CHECK(bad == 0);
    printf("%s every row of a 40x100 projection drawn (%d of 4000 pixels not the background)\n", bad ? "FAIL" : "PASS", bad);
}

/* 1 when VK_LAYER_KHRONOS_validation is installed. */
static int validation_layer_present(void)
{
    VkLayerProperties props[64];
    uint32_t n = 64, i;
    if (vkEnumerateInstanceLayerProperties(&n, props) < 0) return 0;
    for (i = 0; i < n; ++i)
        if (strcmp(props[i].layerName, "VK_LAYER_KHRONOS_validation") == 0) return 1;
    return 0;
}

/* HD_SOLVER_AUTO's multigrid (a 160^3 volume at illumination_downsample 1: 4.1 M grid voxels)
   under hd_vulkan_record: red-black from then on (4 sweeps), the recording succeeds; a
   multigrid the caller named is still refused, with one error. On a device without
   shaderFloat64 ($HD_VK_NO_F64) AUTO's multigrid becomes red-black at hd_create with one info
   line naming the reason and no error logged. */
static void test_record_solver_auto(void)
{
    enum { N = 160 };
    static unsigned char avox[N * N * N];
    hd_desc d = test_desc(), q;
    hd_context h;
    hd__backend *be;
    vk_cmd c;
    hd_params p;
    hd_result r1 = HD_ERROR_UNSUPPORTED, r2 = HD_SUCCESS;
    int i, mg = 0, ok;
    for (i = 0; i < N * N * N; ++i) avox[i] = (unsigned char)(i % N < N / 2 ? 200 : 0);
    d.volume.type = HD_VOXEL_U8;
    d.volume.dims[0] = d.volume.dims[1] = d.volume.dims[2] = N;
    d.volume.data = avox;
    d.params.illumination_downsample = 1;
    d.params.solver = HD_SOLVER_AUTO;
    d.params.diffusion_sweeps = 0;
    d.vulkan.enable_validation = have_layer;
    messages = 0;
    if (hd_create(&d, &h) != HD_SUCCESS) { CHECK(0); return; }
    be = hd__lookup(h)->vw.be;
    CHECK(hd_query_desc(h, &q) == HD_SUCCESS);
    mg = q.params.solver == HD_SOLVER_MULTIGRID && q.params.diffusion_sweeps == 1;
    if (cmd_begin(be, &c)) {
        r1 = hd_vulkan_record(h, c.cb, 1);
        cmd_submit(be, &c, 1);
    }
    CHECK(hd_query_desc(h, &q) == HD_SUCCESS);
    ok = mg && r1 == HD_SUCCESS && q.params.solver == HD_SOLVER_RED_BLACK && q.params.diffusion_sweeps == 4;
    p = q.params;
    p.solver = HD_SOLVER_MULTIGRID;
    p.diffusion_sweeps = 1;
    CHECK(hd_set_params(h, &p) == HD_SUCCESS);
    if (cmd_begin(be, &c)) {
        r2 = hd_vulkan_record(h, c.cb, 1);
        cmd_submit(be, &c, 0);
    }
    ok = ok && r2 == HD_ERROR_UNSUPPORTED;
    CHECK(hd_destroy(h) == HD_SUCCESS);
    CHECK(ok && messages == 0);
    printf("%s solver AUTO under recording: multigrid picked %d, record %s, then red-black; multigrid named: %s; %lu validation messages\n",
           ok && messages == 0 ? "PASS" : "FAIL", mg, hd_result_string(r1), hd_result_string(r2), messages);
    setenv("HD_VK_NO_F64", "1", 1);
    auto_log[0] = '\0';
    err_count = 0;
    ok = hd_create(&d, &h) == HD_SUCCESS;
    if (ok) {
        ok = hd_query_desc(h, &q) == HD_SUCCESS && q.params.solver == HD_SOLVER_RED_BLACK && q.params.diffusion_sweeps == 4;
        ok &= hd_iterate(h, 1) == HD_SUCCESS;
        CHECK(hd_destroy(h) == HD_SUCCESS);
    }
    unsetenv("HD_VK_NO_F64");
    ok &= err_count == 0 && strstr(auto_log, "HD_VK_NO_F64") != NULL && strstr(auto_log, "red-black") != NULL;
    CHECK(ok);
    printf("%s solver AUTO without shaderFloat64: red-black from hd_create, no error logged, info: %s\n", ok ? "PASS" : "FAIL",
           auto_log);
}

/* A volume wider than the device's maxImageDimension3D (the library's own limits pass it):
   HD_ERROR_UNSUPPORTED and one logged error, at hd_create or the first iteration. */
static int limit_errors;
static void limit_log(void *u, hd_log_level l, hd_result c, const char *m, const char *f, int line)
{
    (void)u; (void)c; (void)f; (void)line;
    if (l == HD_LOG_ERROR) { ++limit_errors; printf("volume limit: logged \"%s\"\n", m); }
}
static void test_volume_limit(void)
{
    static float vox[HD_MAX_DIM * 2 * 2];
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkInstance inst;
    VkPhysicalDevice phys[8];
    VkPhysicalDeviceProperties props;
    uint32_t nphys = 8, max3d = 0;
    hd_desc d;
    hd_context c;
    hd_result r;
    int i;
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    if (vkCreateInstance(&ici, NULL, &inst) != VK_SUCCESS) { ++failures; printf("FAIL volume limit: no instance\n"); return; }
    if (vkEnumeratePhysicalDevices(inst, &nphys, phys) >= 0 && nphys > 0) {
        vkGetPhysicalDeviceProperties(phys[0], &props); /* the backend's device: the first */
        max3d = props.limits.maxImageDimension3D;
    }
    vkDestroyInstance(inst, NULL);
    if (max3d == 0 || max3d >= HD_MAX_DIM) { printf("volume limit: maxImageDimension3D %u: skipped\n", max3d); return; }
    for (i = 0; i < HD_MAX_DIM * 2 * 2; ++i) vox[i] = (float)(i % 7) / 7.0f;
    memset(&d, 0, sizeof d);
    d.volume.type = HD_VOXEL_F32; /* one voxel a texel */
    d.volume.dims[0] = HD_MAX_DIM;
    d.volume.dims[1] = d.volume.dims[2] = 2;
    d.volume.data = vox;
    d.camera.width = d.camera.height = 16;
    d.logger.func = limit_log;
    limit_errors = 0;
    r = hd_create(&d, &c);
    if (r == HD_SUCCESS) {
        r = hd_iterate(c, 1);
        hd_destroy(c);
    }
    if (!(r == HD_ERROR_UNSUPPORTED && limit_errors == 1)) {
        ++failures;
        printf("FAIL volume limit: a %dx2x2 volume over maxImageDimension3D %u: %s, %d errors logged\n", HD_MAX_DIM, max3d,
               hd_result_string(r), limit_errors);
    } else printf("ok volume limit: a %dx2x2 volume over maxImageDimension3D %u refused\n", HD_MAX_DIM, max3d);
}

int main(void)
{
    const char *req = getenv("HD_CONFORMANCE_REQUIRE");
    int require = req && req[0] == '1';
    char why[512] = "";
    test_row_order(); /* no device needed */
    if (!hd_backend_runtime_present(why, sizeof why)) {
        ++skips;
        printf("SKIPPED every check on a device: %s\n", why);
        snprintf(skip_why, sizeof skip_why, "no Vulkan device: %s", why);
    } else {
        have_layer = validation_layer_present();
        if (!have_layer) {
            ++skips;
            printf("SKIPPED messenger (check 1): VK_LAYER_KHRONOS_validation is not installed (Debian: "
                   "vulkan-validationlayers); checks 2-14 run without it\n");
            snprintf(skip_why, sizeof skip_why, "no validation layer: check 1 not run, 2-14 without the layer");
        }
        if (!have_layer || test_messenger()) {
            test_rows_covered();
            test_caller_device();
            test_out_of_memory();
            test_device_lost();
            test_half();
            test_multigrid();
            test_kept_instance();
            test_image_room();
            test_record_auto_scale();
            test_output_target();
            test_record_converged(HD_REST_HOLD);
            test_record_converged(HD_REST_BLEND);
            test_record_depth();
            test_volume_limit();
            test_record_solver_auto();
            test_record_illumination();
            test_record_refine();
        }
    }
    if (failures) printf("FAILED\n");
    else if (skips) printf("passed, %d skipped (%s)%s\n", skips, skip_why,
                           require ? "; HD_CONFORMANCE_REQUIRE=1: a skip fails" : "");
    else printf("all passed\n");
    return failures || (skips && require) ? 1 : 0;
}
