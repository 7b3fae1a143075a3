/* hd_fuzz_check.h - what every loader fuzz target asserts beyond "no sanitizer report":
   an error leaves the output empty and has logged exactly one error naming its code; a success
   gives a volume with dims 1..HD_MAX_DIM, finite spacing > 0 and a non-empty finite value range,
   whose every voxel is readable, and which renders: hd_create on the CPU backend with an 8x8
   camera either refuses it (one logged error naming its code) or one hd_iterate runs and every
   pixel of the image is finite (an error there must be logged the same way). Only volumes of at
   most HD_FUZZ_RENDER_MAX voxels render, so that a gzip stream inflating to megabytes does not
   slow the run; the values a header controls (dims, spacing, value range) reach the render path
   at any size. abort() makes libFuzzer keep the input. */
#ifndef HD_FUZZ_CHECK_H
#define HD_FUZZ_CHECK_H
#include <stdlib.h>
#include <math.h>
#include <string.h>

static int hd_fuzz_errors;
static hd_result hd_fuzz_code;
static void hd_fuzz_log(void *u, hd_log_level level, hd_result code, const char *msg,
                        const char *file, int line)
{
    (void)u; (void)file; (void)line;
    if (!msg || !msg[0]) abort();
    if (level == HD_LOG_ERROR) {
        ++hd_fuzz_errors;
        hd_fuzz_code = code;
    }
}

static const hd_logger *hd_fuzz_logger(void)
{
    static hd_logger lg = {hd_fuzz_log, NULL};
    hd_fuzz_errors = 0;
    hd_fuzz_code = HD_SUCCESS;
    return &lg;
}

#ifndef HD_FUZZ_RENDER_MAX
#define HD_FUZZ_RENDER_MAX (64 * 64 * 64)
#endif

static void hd_fuzz_render(const hd_volume_file *v)
{
    hd_desc d;
    hd_context ctx;
    hd_result r;
    float img[8 * 8 * 4];
    size_t n = (size_t)v->desc.dims[0] * v->desc.dims[1] * v->desc.dims[2], i;
    if (n > HD_FUZZ_RENDER_MAX) return;
    memset(&d, 0, sizeof d);
    d.volume = v->desc;
    d.camera.width = d.camera.height = 8;
    d.threads = 1;
    d.logger = *hd_fuzz_logger();
    r = hd_create(&d, &ctx);
    if (r != HD_SUCCESS) {
        if (hd_fuzz_errors != 1 || hd_fuzz_code != r) abort();
        return;
    }
    r = hd_iterate(ctx, 1);
    if (r == HD_SUCCESS) r = hd_read_image_f32(ctx, img, sizeof img / sizeof img[0]);
    if (r != HD_SUCCESS) {
        if (hd_fuzz_errors != 1 || hd_fuzz_code != r) abort();
    } else {
        for (i = 0; i < sizeof img / sizeof img[0]; ++i)
            if (!isfinite(img[i])) abort();
    }
    if (hd_destroy(ctx) != HD_SUCCESS) abort();
}

static void hd_fuzz_check(hd_result r, hd_volume_file *v)
{
    if (r != HD_SUCCESS) {
        if (v->data || hd_fuzz_errors != 1 || hd_fuzz_code != r || (int)r <= 0 ||
            (int)r >= (int)HD_RESULT_COUNT)
            abort();
        return;
    }
    {
        size_t n = 1, i, es;
        volatile double sum = 0;
        int a;
        if (!v->data || v->desc.data != v->data || hd_fuzz_errors) abort();
        for (a = 0; a < 3; ++a) {
            if (v->desc.dims[a] < 1 || v->desc.dims[a] > HD_MAX_DIM) abort();
            if (!(v->desc.spacing[a] > 0.0f) || !isfinite(v->desc.spacing[a])) abort();
            n *= (size_t)v->desc.dims[a];
        }
        if (!isfinite(v->desc.value_range[0]) || !isfinite(v->desc.value_range[1]) ||
            !(v->desc.value_range[1] > v->desc.value_range[0]))
            abort();
        es = v->desc.type == HD_VOXEL_U8 ? 1 : v->desc.type == HD_VOXEL_U16 || v->desc.type == HD_VOXEL_I16 ? 2
             : v->desc.type == HD_VOXEL_F32 ? 4 : 0;
        if (!es) abort();
        for (i = 0; i < n * es; ++i) sum += ((const unsigned char *)v->data)[i];
        if (v->desc.type == HD_VOXEL_F32)
            for (i = 0; i < n; ++i)
                if (!isfinite(((const float *)v->data)[i])) abort();
        (void)sum;
    }
    hd_fuzz_render(v);
    hd_volume_free(v);
}
#endif
