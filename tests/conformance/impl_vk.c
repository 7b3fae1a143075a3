/* impl_vk.c - the Vulkan backend under test as the table hd_api_backend (see hd_api.h), with a
   check of the validation layer. With HD_VK_VALIDATION=1 in the environment every context runs
   under VK_LAYER_KHRONOS_validation with synchronization validation (backends/hd_vulkan.h); its
   debug messenger logs each message as an error ("vulkan validation ..."). This table wraps the
   logger: a call during which a validation message arrived returns HD_ERROR_BACKEND, so the case
   FAILS, and messages outside any checked call (hd_destroy) make the program exit 1. */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_STATIC
#define HYBRIDDIFF_BACKEND_VULKAN
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hd_api.h"
#include "hd_probe_vk.h"
#include <unistd.h>

static unsigned long vk_messages;      /* validation messages seen, all contexts */
static hd_logger vk_loggers[HD_MAX_CONTEXTS + 1]; /* the callers' loggers, by handle slot */
static int vk_atexit_set;

static void vk_log(void *user, hd_log_level level, hd_result code, const char *msg, const char *file, int line)
{
    hd_logger *orig = (hd_logger *)user;
    if (strncmp(msg, "vulkan validation", 17) == 0) ++vk_messages;
    if (orig && orig->func) orig->func(orig->user_data, level, code, msg, file, line);
}

static void vk_exit_check(void)
{
    if (vk_messages == 0) return;
    printf("FAIL vulkan validation: %lu message(s) from the validation layer (see the log above)\n", vk_messages);
    fflush(stdout);
    _exit(1);
}

static hd_result vk_checked(hd_result r, unsigned long before)
{
    return r == HD_SUCCESS && vk_messages != before ? HD_ERROR_BACKEND : r;
}

static hd_result vk_create(const hd_desc *desc, hd_context *out)
{
    static hd_logger pending; /* the logger of the context being created */
    hd_desc d = *desc;
    unsigned long before = vk_messages;
    hd_result r;
    if (!vk_atexit_set) { atexit(vk_exit_check); vk_atexit_set = 1; }
    pending = desc->logger;
    d.logger.func = vk_log;
    d.logger.user_data = &pending;
    r = hd_create(&d, out);
    if (r == HD_SUCCESS) {
        /* the context keeps user_data: point it at its own slot's copy */
        hd__ctx *ctx = hd__lookup(*out);
        vk_loggers[out->id & 0xffu] = pending;
        ctx->vw.log.user_data = &vk_loggers[out->id & 0xffu];
        ctx->vw.desc.logger.user_data = ctx->vw.log.user_data;
    }
    return vk_checked(r, before);
}

#define VK_WRAP(name, params, args) \
    static hd_result vk_##name params { unsigned long before = vk_messages; return vk_checked(hd_##name args, before); }
#define VK_WRAP_HOOK(name, params, args) \
    static hd_result vk_##name params { unsigned long before = vk_messages; return vk_checked(hd__##name args, before); }
VK_WRAP(destroy, (hd_context c), (c))
VK_WRAP(set_transfer_function, (hd_context c, const hd_transfer_function *tf), (c, tf))
VK_WRAP(set_lights, (hd_context c, const hd_light *l, int n), (c, l, n))
VK_WRAP(set_camera, (hd_context c, const hd_camera *cam), (c, cam))
VK_WRAP(set_params, (hd_context c, const hd_params *p), (c, p))
VK_WRAP(iterate, (hd_context c, int n), (c, n))
VK_WRAP(refine, (hd_context c, int n), (c, n))
VK_WRAP(render, (hd_context c), (c))
VK_WRAP(set_depth, (hd_context c, const hd_depth_desc *dd), (c, dd))
VK_WRAP(set_environment, (hd_context c, const hd_environment *e), (c, e))
VK_WRAP(set_volume_transform, (hd_context c, const float *m), (c, m))
VK_WRAP(read_image_rgba8, (hd_context c, uint8_t *dst, size_t n), (c, dst, n))
VK_WRAP(read_image_f32, (hd_context c, float *dst, size_t n), (c, dst, n))
VK_WRAP(read_illumination, (hd_context c, hd_illumination w, float *dst, size_t n), (c, w, dst, n))
VK_WRAP(update_volume, (hd_context c, const hd_volume_update *u), (c, u))
VK_WRAP(read_depth, (hd_context c, float *dst, size_t n), (c, dst, n))
VK_WRAP_HOOK(test_prepare, (hd_context c), (c))
VK_WRAP_HOOK(test_direct, (hd_context c, int n), (c, n))
VK_WRAP_HOOK(test_diffuse, (hd_context c, int n), (c, n))
VK_WRAP_HOOK(test_project, (hd_context c, int n), (c, n))
VK_WRAP_HOOK(test_write_illumination, (hd_context c, hd_illumination w, const float *src), (c, w, src))
VK_WRAP_HOOK(test_finish, (hd_context c), (c))
VK_WRAP_HOOK(test_direct_all, (hd_context c, int on), (c, on))

const hd_api hd_api_backend = {hd_backend_name, hd_result_string, hd_method_name, hd_log_stderr, vk_create,
                               vk_destroy, hd_query_desc, vk_set_transfer_function, vk_set_lights, vk_set_camera,
                               vk_set_params, vk_iterate, vk_read_image_rgba8, vk_read_image_f32,
                               vk_read_illumination, hd_get_stats, hd_volume_load_nrrd, hd_volume_load_raw,
                               hd_volume_parse_nrrd, hd_volume_free, vk_test_prepare, vk_test_direct,
                               vk_test_diffuse, vk_test_project, vk_test_write_illumination, vk_test_finish,
                               vk_test_direct_all, vk_refine, vk_render, vk_set_depth, vk_set_volume_transform, vk_update_volume,
                               vk_set_environment,
                               vk_read_depth};
