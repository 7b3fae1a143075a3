/* hd_probe_vk.h - hd_backend_runtime_present (hd_api.h) for the Vulkan backend: an instance of
   its own and vkEnumeratePhysicalDevices, not the library's. Included once per program, after
   the implementation (impl_vk.c, impl_backend.c with HYBRIDDIFF_BACKEND_VULKAN). */
#include <stdio.h>

int hd_backend_runtime_present(char *why, size_t why_size)
{
    VkApplicationInfo app;
    VkInstanceCreateInfo ici;
    VkInstance inst = VK_NULL_HANDLE;
    VkPhysicalDeviceProperties props;
    VkPhysicalDevice phys[8];
    uint32_t n = 8;
    VkResult r;
    memset(&app, 0, sizeof app);
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.apiVersion = VK_API_VERSION_1_1;
    memset(&ici, 0, sizeof ici);
    ici.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    ici.pApplicationInfo = &app;
    if ((r = vkCreateInstance(&ici, NULL, &inst)) != VK_SUCCESS) {
        snprintf(why, why_size, "no Vulkan 1.1 instance (vkCreateInstance: %d)", (int)r);
        return 0;
    }
    r = vkEnumeratePhysicalDevices(inst, &n, phys);
    if ((r != VK_SUCCESS && r != VK_INCOMPLETE) || n == 0) {
        snprintf(why, why_size, "a Vulkan instance with no physical device (%d)", (int)r);
        vkDestroyInstance(inst, NULL);
        return 0;
    }
    vkGetPhysicalDeviceProperties(phys[0], &props);
    snprintf(why, why_size, "Vulkan: %u physical device(s), the first %s", (unsigned)n, props.deviceName);
    vkDestroyInstance(inst, NULL);
    return 1;
}
