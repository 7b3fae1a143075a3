/* hd_api.h - the library's API as a table of function pointers, so two implementations (the CPU
   reference and the backend under test, both built with HYBRIDDIFF_STATIC in their own
   translation units) live side by side in one process. impl_cpu.c exports hd_api_cpu,
   impl_backend.c (built with -DHYBRIDDIFF_BACKEND_X) exports hd_api_backend. */
#ifndef HD_API_H
#define HD_API_H
#include "hybriddiff.h"

typedef struct hd_api {
    const char *(*backend_name)(void);
    const char *(*result_string)(hd_result);
    const char *(*method_name)(hd_method);
    void (*log_stderr)(void *, hd_log_level, hd_result, const char *, const char *, int);
    hd_result (*create)(const hd_desc *, hd_context *);
    hd_result (*destroy)(hd_context);
    hd_result (*query_desc)(hd_context, hd_desc *);
    hd_result (*set_transfer_function)(hd_context, const hd_transfer_function *);
    hd_result (*set_lights)(hd_context, const hd_light *, int);
    hd_result (*set_camera)(hd_context, const hd_camera *);
    hd_result (*set_params)(hd_context, const hd_params *);
    hd_result (*iterate)(hd_context, int);
    hd_result (*read_image_rgba8)(hd_context, uint8_t *, size_t);
    hd_result (*read_image_f32)(hd_context, float *, size_t);
    hd_result (*read_illumination)(hd_context, hd_illumination, float *, size_t);
    hd_result (*get_stats)(hd_context, hd_stats *);
    hd_result (*volume_load_nrrd)(const char *, hd_volume_file *, const hd_logger *);
    hd_result (*volume_load_raw)(const char *, const int[3], hd_raw_type, hd_endian, size_t, hd_volume_file *, const hd_logger *);
    hd_result (*volume_parse_nrrd)(const void *, size_t, hd_volume_file *, const hd_logger *);
    void (*volume_free)(hd_volume_file *);
    /* private stage hooks (src/hd_test_hooks.h) */
    hd_result (*test_prepare)(hd_context);
    hd_result (*test_direct)(hd_context, int);
    hd_result (*test_diffuse)(hd_context, int);
    hd_result (*test_project)(hd_context, int);
    hd_result (*test_write_illumination)(hd_context, hd_illumination, const float *);
    hd_result (*test_finish)(hd_context);
    hd_result (*test_direct_all)(hd_context, int);
    hd_result (*refine)(hd_context, int);
    hd_result (*render)(hd_context);
    hd_result (*set_depth)(hd_context, const hd_depth_desc *);
    hd_result (*set_volume_transform)(hd_context, const float *);
    hd_result (*update_volume)(hd_context, const hd_volume_update *);
    hd_result (*set_environment)(hd_context, const hd_environment *);
    hd_result (*read_depth)(hd_context, float *, size_t);
} hd_api;

extern const hd_api hd_api_cpu;
extern const hd_api hd_api_backend;

/* 1 when the backend's runtime offers a device, found without the library (OpenCL: a platform
   with a device; Vulkan: a physical device; GL: an EGL display with an OpenGL 4.3 core
   context), 0 when it does not; why gets what was found. A suite whose hd_create fails asks it:
   with a device there the failure is the library's (FAIL), without one the machine lacks the
   runtime (SKIPPED, or FAIL under HD_CONFORMANCE_REQUIRE=1). Defined beside hd_api_backend
   (impl_backend.c, impl_vk.c). */
#ifdef __cplusplus
extern "C" {
#endif
int hd_backend_runtime_present(char *why, size_t why_size);
#ifdef __cplusplus
}
#endif

/* Defines the table of the implementation included above it in the same translation unit. */
#define HD_API_TABLE(var) \
    const hd_api var = {hd_backend_name, hd_result_string, hd_method_name, hd_log_stderr, hd_create, \
                        hd_destroy, hd_query_desc, hd_set_transfer_function, hd_set_lights, hd_set_camera, \
                        hd_set_params, hd_iterate, hd_read_image_rgba8, hd_read_image_f32, \
                        hd_read_illumination, hd_get_stats, hd_volume_load_nrrd, hd_volume_load_raw, \
                        hd_volume_parse_nrrd, hd_volume_free, hd__test_prepare, hd__test_direct, \
                        hd__test_diffuse, hd__test_project, hd__test_write_illumination, hd__test_finish, \
                        hd__test_direct_all, hd_refine, hd_render, hd_set_depth, hd_set_volume_transform, hd_update_volume, \
                        hd_set_environment, \
                        hd_read_depth}
#endif
