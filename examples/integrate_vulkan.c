/* integrate_vulkan.c - hybriddiff on the application's own Vulkan instance, device and queue, with
   the validation layer and the application's messenger: hd_vulkan_record records iterations into
   the application's command buffer, which it submits itself. Exits 1 on any validation message
   or a blank image. Built in C99 and C++17, with hybriddiff.h before (default) or after
   (-DINTEGRATE_HD_LAST) the system headers (mk/integrate.mk). */
#ifndef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#endif
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <vulkan/vulkan.h>
#ifdef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#endif

static int messages;
static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT type,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data, void *user)
{
    (void)severity; (void)type; (void)user;
    ++messages;
    fprintf(stderr, "validation: %s\n", data->pMessage);
    return VK_FALSE;
}

int main(void)
{
    enum { N = 32, W = 64 };
    static unsigned char voxels[N * N * N];
    static unsigned char pixels[W * W * 4];
    const char *layer = "VK_LAYER_KHRONOS_validation", *ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkApplicationInfo app;
    VkDebugUtilsMessengerCreateInfoEXT mci;
    VkInstanceCreateInfo ici;
    VkDeviceQueueCreateInfo qci;
    VkDeviceCreateInfo dci;
    VkCommandPoolCreateInfo pci;
    VkCommandBufferAllocateInfo cai;
    VkCommandBufferBeginInfo bi;
    VkSubmitInfo si;
    VkInstance inst;
    VkDebugUtilsMessengerEXT messenger;
    VkPhysicalDevice phys;
    VkDevice dev;
    VkQueue queue;
    VkCommandPool pool;
    VkCommandBuffer cb;
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger;
    PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger;
    uint32_t count = 1, family = 0, nfam = 0, i;
    VkQueueFamilyProperties fams[16];
    float prio = 1.0f;
    hd_desc desc = HD_DESC_INIT;
    hd_context ctx;
    hd_result r;
    int x, y, z, lit = 0;

    memset(&app, 0, sizeof app); app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    memset(&mci, 0, sizeof mci); mci.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    memset(&ici, 0, sizeof ici); ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    memset(&qci, 0, sizeof qci); qci.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    memset(&dci, 0, sizeof dci); dci.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    memset(&pci, 0, sizeof pci); pci.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    memset(&cai, 0, sizeof cai); cai.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    memset(&bi, 0, sizeof bi); bi.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    memset(&si, 0, sizeof si); si.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    app.apiVersion = VK_API_VERSION_1_1;
    mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    mci.pfnUserCallback = on_message;
    ici.pApplicationInfo = &app;
    ici.enabledLayerCount = 1;
    ici.ppEnabledLayerNames = &layer;
    ici.enabledExtensionCount = 1;
    ici.ppEnabledExtensionNames = &ext;
    ici.pNext = &mci;
    if (vkCreateInstance(&ici, NULL, &inst) != VK_SUCCESS) { fprintf(stderr, "no instance with %s\n", layer); return 1; }
    create_messenger = (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(inst, "vkCreateDebugUtilsMessengerEXT");
    destroy_messenger = (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(inst, "vkDestroyDebugUtilsMessengerEXT");
    create_messenger(inst, &mci, NULL, &messenger);
    if (vkEnumeratePhysicalDevices(inst, &count, &phys) < 0 || count == 0) { fprintf(stderr, "no device\n"); return 1; }
    vkGetPhysicalDeviceQueueFamilyProperties(phys, &nfam, NULL);
    if (nfam > 16) nfam = 16;
    vkGetPhysicalDeviceQueueFamilyProperties(phys, &nfam, fams);
    for (i = nfam; i-- > 0;)
        if (fams[i].queueFlags & VK_QUEUE_COMPUTE_BIT) family = i;
    qci.queueFamilyIndex = family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &prio;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    if (vkCreateDevice(phys, &dci, NULL, &dev) != VK_SUCCESS) { fprintf(stderr, "no device\n"); return 1; }
    vkGetDeviceQueue(dev, family, 0, &queue);
    pci.queueFamilyIndex = family;
    vkCreateCommandPool(dev, &pci, NULL, &pool);
    cai.commandPool = pool;
    cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cai.commandBufferCount = 1;
    vkAllocateCommandBuffers(dev, &cai, &cb);

    for (z = 0; z < N; ++z) /* a ball of density 200 in air */
        for (y = 0; y < N; ++y)
            for (x = 0; x < N; ++x) {
                int dx = 2 * x - N + 1, dy = 2 * y - N + 1, dz = 2 * z - N + 1;
                voxels[(z * N + y) * N + x] = (unsigned char)(dx * dx + dy * dy + dz * dz < N * N / 2 ? 200 : 0);
            }
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = N;
    desc.volume.data = voxels;
    desc.camera.width = desc.camera.height = W;
    desc.logger.func = hd_log_stderr;
    desc.vulkan.instance = inst;
    desc.vulkan.physical_device = phys;
    desc.vulkan.device = dev;
    desc.vulkan.queue = queue;
    desc.vulkan.queue_family = family;
    desc.vulkan.get_instance_proc_addr = (hd_proc)vkGetInstanceProcAddr;
    if ((r = hd_create(&desc, &ctx)) != HD_SUCCESS) { fprintf(stderr, "hd_create: %s\n", hd_result_string(r)); return 1; }

    vkBeginCommandBuffer(cb, &bi);
    r = hd_vulkan_record(ctx, cb, 4); /* 4 iterations into our command buffer */
    vkEndCommandBuffer(cb);
    if (r != HD_SUCCESS) { fprintf(stderr, "hd_vulkan_record: %s\n", hd_result_string(r)); return 1; }
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cb;
    vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE);
    vkQueueWaitIdle(queue); /* before the next call on ctx */
    hd_read_image_rgba8(ctx, pixels, sizeof pixels);
    hd_destroy(ctx);

    vkDestroyCommandPool(dev, pool, NULL);
    vkDestroyDevice(dev, NULL);
    destroy_messenger(inst, messenger, NULL);
    vkDestroyInstance(inst, NULL);
    for (i = 0; i < sizeof pixels; i += 4) lit += pixels[i] > 8;
    printf("integrate_vulkan: %d lit pixels, %d validation messages\n", lit, messages);
    return lit > 0 && messages == 0 ? 0 : 1;
}
