/* hd_null.h - the null backend (HYBRIDDIFF_BACKEND_NULL): every primitive of src/hd_backend.h,
   computing nothing. It holds the image and the illumination as zeros, so every read-back
   succeeds, and counts each primitive it is called with, so a test can run the public API over
   it and see which stages each call reached (tests/null/test_null.c). It is the template for a
   new backend (docs/BACKENDS.md): each function below is where that backend's version goes. */
#ifndef HD_NULL_H
#define HD_NULL_H

/* The primitives, in hd_backend.h's order: their counters' indices (hd__null_calls names them). */
#define HD__NULL_PRIMITIVES(X) \
    X(upload_inputs) X(update_volume) X(alloc_illumination) X(alloc_jacobi) X(alloc_image) X(alloc_lights) X(clear) \
    X(classify) X(direct) X(direct_list) X(diffuse) X(diffuse_sweeps) X(convect) X(sum_lights) \
    X(project) X(upsample) X(path) X(upload_depth) X(upload_env) X(read_image) X(read_depth) X(record_depth) X(record_illumination) X(read_illumination) X(mg_begin) X(mg_end) \
    X(mg_coarsen) X(mg_zero_lo) X(mg_residual_f64) X(mg_smooth) X(mg_residual) X(mg_restrict) \
    X(mg_prolong) X(mg_dot_rz) X(mg_direction) X(mg_apply) X(mg_row_sums) X(mg_update) \
    X(mg_extrapolate) X(wait) X(begin) X(end) X(record_begin) X(record_end) X(output_target_check) X(record_output) X(record_light_sum)
enum {
#define HD__NULL_X(name) HD__NULL_##name,
    HD__NULL_PRIMITIVES(HD__NULL_X)
#undef HD__NULL_X
    HD__NULL_COUNT
};
HD__MAYBE_UNUSED static const char *const hd__null_names[HD__NULL_COUNT] = {
#define HD__NULL_X(name) #name,
    HD__NULL_PRIMITIVES(HD__NULL_X)
#undef HD__NULL_X
};

struct hd__backend {
    unsigned long calls[HD__NULL_COUNT]; /* per primitive, since hd__be_create */
    unsigned cleared;          /* the HD__DIRTY_* bits hd__be_clear was given, ORed */
    size_t illum_floats;       /* what hd__be_alloc_illumination asked for */
    int width, height, reduced, lights, jacobi;
    int open;                  /* inside a bracket (hd__be_begin .. hd__be_end) */
    int recording;             /* inside hd__be_record_begin .. hd__be_record_end */
    int misuse;                /* a primitive called outside a bracket, or a bracket opened twice */
    double *rows;              /* the multigrid's row sums, zeros (hd__be_mg_row_sums) */
    size_t nrows;
};

/* Counts a primitive and notes one called outside a bracket (the core's contract). */
static void hd__null_call(const hd__view *vw, int which)
{
    vw->be->calls[which]++;
    if (!vw->be->open) vw->be->misuse = 1;
}

static const char *hd__be_name(void) { return "null"; }

static hd_result hd__be_create(hd__view *vw)
{
    vw->be = (hd__backend *)hd__calloc(vw, 1, sizeof(hd__backend));
    if (!vw->be) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "null: cannot allocate the backend");
    return HD_SUCCESS;
}
static void hd__be_destroy(hd__view *vw)
{
    if (!vw->be) return;
    hd__free(vw, vw->be->rows);
    hd__free(vw, vw->be);
    vw->be = NULL;
}

static hd_result hd__be_begin(const hd__view *vw)
{
    if (vw->be->open) vw->be->misuse = 1;
    vw->be->open = 1;
    vw->be->calls[HD__NULL_begin]++;
    return HD_SUCCESS;
}
static hd_result hd__be_end(const hd__view *vw, hd_result r)
{
    if (!vw->be->open) vw->be->misuse = 1;
    vw->be->open = 0;
    vw->be->calls[HD__NULL_end]++;
    return r;
}

static hd_result hd__be_upload_inputs(const hd__view *vw) { hd__null_call(vw, HD__NULL_upload_inputs); return HD_SUCCESS; }
static hd_result hd__be_upload_depth(const hd__view *vw) { hd__null_call(vw, HD__NULL_upload_depth); return HD_SUCCESS; }
static hd_result hd__be_upload_env(const hd__view *vw) { hd__null_call(vw, HD__NULL_upload_env); return HD_SUCCESS; }
static hd_result hd__be_update_volume(const hd__view *vw, const hd__box *vox, const hd__box *cells)
{
    (void)vox; (void)cells;
    hd__null_call(vw, HD__NULL_update_volume);
    return HD_SUCCESS;
}
static hd_result hd__be_alloc_illumination(const hd__view *vw, size_t illum_floats)
{
    hd__null_call(vw, HD__NULL_alloc_illumination);
    vw->be->illum_floats = illum_floats;
    return HD_SUCCESS;
}
static hd_result hd__be_alloc_jacobi(const hd__view *vw, int enable)
{
    hd__null_call(vw, HD__NULL_alloc_jacobi);
    vw->be->jacobi = enable;
    return HD_SUCCESS;
}
static hd_result hd__be_alloc_image(const hd__view *vw, int width, int height, int parts)
{
    hd__null_call(vw, HD__NULL_alloc_image);
    vw->be->width = width;
    vw->be->height = height;
    vw->be->reduced = parts & HD__IMAGE_REDUCED;
    return HD_SUCCESS;
}
static hd_result hd__be_alloc_lights(const hd__view *vw, int count)
{
    hd__null_call(vw, HD__NULL_alloc_lights);
    vw->be->lights = count;
    return HD_SUCCESS;
}
static hd_result hd__be_clear(const hd__view *vw, unsigned what)
{
    hd__null_call(vw, HD__NULL_clear);
    vw->be->cleared |= what;
    return HD_SUCCESS;
}

static hd_result hd__be_classify(const hd__view *vw) { hd__null_call(vw, HD__NULL_classify); return HD_SUCCESS; }
static hd_result hd__be_direct(const hd__view *vw, size_t first, size_t count)
{
    hd__null_call(vw, HD__NULL_direct);
    if (first > vw->dl_count || count > vw->dl_count - first) vw->be->misuse = 1; /* past the list */
    return HD_SUCCESS;
}
static hd_result hd__be_direct_list(const hd__view *vw) { hd__null_call(vw, HD__NULL_direct_list); return HD_SUCCESS; }
static hd_result hd__be_wait(const hd__view *vw) { hd__null_call(vw, HD__NULL_wait); return HD_SUCCESS; }
static hd_result hd__be_diffuse(const hd__view *vw, int jacobi)
{
    (void)jacobi;
    hd__null_call(vw, HD__NULL_diffuse);
    return HD_SUCCESS;
}
static hd_result hd__be_diffuse_sweeps(const hd__view *vw, int jacobi, int sweeps)
{
    hd__null_call(vw, HD__NULL_diffuse_sweeps);
    return hd__be_diffuse_each(vw, jacobi, sweeps);
}
static hd_result hd__be_convect(const hd__view *vw, int light)
{
    (void)light;
    hd__null_call(vw, HD__NULL_convect);
    return HD_SUCCESS;
}
static hd_result hd__be_sum_lights(const hd__view *vw) { hd__null_call(vw, HD__NULL_sum_lights); return HD_SUCCESS; }
static hd_result hd__be_project(const hd__view *vw) { hd__null_call(vw, HD__NULL_project); return HD_SUCCESS; }
static hd_result hd__be_upsample(const hd__view *vw) { hd__null_call(vw, HD__NULL_upsample); return HD_SUCCESS; }
static hd_result hd__be_path(const hd__view *vw) { hd__null_call(vw, HD__NULL_path); return HD_SUCCESS; }

static hd_result hd__be_read_image(const hd__view *vw, float *dst)
{
    hd__null_call(vw, HD__NULL_read_image);
    memset(dst, 0, (size_t)vw->camera.width * vw->camera.height * 4 * sizeof(float));
    return HD_SUCCESS;
}
static hd_result hd__be_read_depth(const hd__view *vw, float *dst)
{
    hd__null_call(vw, HD__NULL_read_depth);
    memset(dst, 0, (size_t)vw->camera.width * vw->camera.height * sizeof(float));
    return HD_SUCCESS;
}
static hd_result hd__be_read_illumination(const hd__view *vw, hd_illumination which, const int *zz, int count, float *dst)
{
    size_t slice = (size_t)vw->gdims[0] * vw->gdims[1];
    (void)which;
    hd__null_call(vw, HD__NULL_read_illumination);
    memset(dst, 0, (zz ? (size_t)count : (size_t)vw->gdims[2] * vw->channels) * slice * sizeof(float));
    return HD_SUCCESS;
}

/* ---- HD_SOLVER_MULTIGRID: zero row sums, so the core's CG sees a converged (zero) residual ---- */
static hd_result hd__be_mg_begin(const hd__view *vw, int *fresh)
{
    size_t n = (size_t)vw->gdims[1] * vw->gdims[2] * vw->channels;
    hd__backend *be = vw->be;
    hd__null_call(vw, HD__NULL_mg_begin);
    *fresh = be->nrows != n;
    if (be->nrows != n) {
        hd__free(vw, be->rows);
        be->rows = (double *)hd__calloc(vw, n ? n : 1, sizeof(double));
        be->nrows = be->rows ? n : 0;
        if (!be->rows) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "null: cannot allocate %zu row sums", n);
    }
    return HD_SUCCESS;
}
static hd_result hd__be_mg_end(const hd__view *vw, hd_result r) { hd__null_call(vw, HD__NULL_mg_end); return r; }
static hd_result hd__be_mg_coarsen(const hd__view *vw, int l) { (void)l; hd__null_call(vw, HD__NULL_mg_coarsen); return HD_SUCCESS; }
static hd_result hd__be_mg_zero_lo(const hd__view *vw) { hd__null_call(vw, HD__NULL_mg_zero_lo); return HD_SUCCESS; }
static hd_result hd__be_mg_residual_f64(const hd__view *vw) { hd__null_call(vw, HD__NULL_mg_residual_f64); return HD_SUCCESS; }
static hd_result hd__be_mg_smooth(const hd__view *vw, int l, int sweeps, int first)
{
    (void)l; (void)sweeps; (void)first;
    hd__null_call(vw, HD__NULL_mg_smooth);
    return HD_SUCCESS;
}
static hd_result hd__be_mg_residual(const hd__view *vw, int l) { (void)l; hd__null_call(vw, HD__NULL_mg_residual); return HD_SUCCESS; }
static hd_result hd__be_mg_restrict(const hd__view *vw, int l) { (void)l; hd__null_call(vw, HD__NULL_mg_restrict); return HD_SUCCESS; }
static hd_result hd__be_mg_prolong(const hd__view *vw, int l) { (void)l; hd__null_call(vw, HD__NULL_mg_prolong); return HD_SUCCESS; }
static hd_result hd__be_mg_dot_rz(const hd__view *vw) { hd__null_call(vw, HD__NULL_mg_dot_rz); return HD_SUCCESS; }
static hd_result hd__be_mg_direction(const hd__view *vw, float beta)
{
    (void)beta;
    hd__null_call(vw, HD__NULL_mg_direction);
    return HD_SUCCESS;
}
static hd_result hd__be_mg_apply(const hd__view *vw) { hd__null_call(vw, HD__NULL_mg_apply); return HD_SUCCESS; }
static hd_result hd__be_mg_row_sums(const hd__view *vw, int n, const double **a, const double **b)
{
    (void)n;
    hd__null_call(vw, HD__NULL_mg_row_sums);
    *a = vw->be->rows;
    if (b) *b = vw->be->rows;
    return HD_SUCCESS;
}
static hd_result hd__be_mg_update(const hd__view *vw, double alpha)
{
    (void)alpha;
    hd__null_call(vw, HD__NULL_mg_update);
    return HD_SUCCESS;
}
static hd_result hd__be_mg_extrapolate(const hd__view *vw, int colour)
{
    (void)colour;
    hd__null_call(vw, HD__NULL_mg_extrapolate);
    return HD_SUCCESS;
}
static size_t hd__be_solver_bytes(const hd__view *vw) { (void)vw; return 0; }
static const char *hd__be_mg_unavailable(const hd__view *vw) { (void)vw; return NULL; }

/* ---- optional features: recording (nothing recorded, the schedule counted); no GL texture ---- */
static unsigned hd__be_features(void) { return HD__BE_RECORD; }
static hd_result hd__be_record_begin(const hd__view *vw, void *target, int slots)
{
    (void)target; (void)slots;
    hd__null_call(vw, HD__NULL_record_begin);
    if (vw->be->recording) vw->be->misuse = 1;
    vw->be->recording = 1;
    return HD_SUCCESS;
}
static void hd__be_record_mark(const hd__view *vw, int end) { (void)vw; (void)end; }
static hd_result hd__be_record_end(const hd__view *vw, hd_result r)
{
    hd__null_call(vw, HD__NULL_record_end);
    if (!vw->be->recording) vw->be->misuse = 1;
    vw->be->recording = 0;
    return r;
}
static int hd__be_record_seconds(const hd__view *vw, double *seconds) { (void)vw; (void)seconds; return 0; }
static hd_result hd__be_output_target_check(const hd__view *vw, const hd_vulkan_target *target, const hd_output *out)
{
    (void)target; (void)out;
    hd__null_call(vw, HD__NULL_output_target_check);
    if (vw->be->recording) vw->be->misuse = 1; /* the check comes before anything is recorded */
    return HD_SUCCESS;
}
static hd_result hd__be_record_output(const hd__view *vw, const hd_vulkan_target *target, const hd_output *out)
{
    (void)target; (void)out;
    hd__null_call(vw, HD__NULL_record_output);
    if (!vw->be->recording) vw->be->misuse = 1;
    return HD_SUCCESS;
}
static hd_result hd__be_output_texture(const hd__view *vw, unsigned texture, const hd_output *out, int exact)
{
    (void)texture; (void)out; (void)exact;
    return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "null: no GL texture");
}
static hd_result hd__be_record_depth(const hd__view *vw, void *cb, const hd_vulkan_depth *depth)
{
    (void)cb; (void)depth;
    hd__null_call(vw, HD__NULL_record_depth);
    return HD_SUCCESS;
}
static hd_result hd__be_record_illumination(const hd__view *vw, void *cb, int channel, const hd_vulkan_volume_target *target)
{
    (void)cb; (void)channel; (void)target;
    hd__null_call(vw, HD__NULL_record_illumination);
    return HD_SUCCESS;
}
static hd_result hd__be_record_light_sum(const hd__view *vw)
{
    hd__null_call(vw, HD__NULL_record_light_sum);
    if (!vw->be->recording) vw->be->misuse = 1;
    return HD_SUCCESS;
}
static hd_result hd__be_depth_cl_buffer(const hd__view *vw, void *buffer, size_t offset)
{
    (void)buffer; (void)offset;
    return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "null: no OpenCL buffer");
}
static hd_result hd__be_depth_texture(const hd__view *vw, unsigned texture)
{
    (void)texture;
    return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "null: no GL texture");
}
static hd_result hd__be_illumination_texture(const hd__view *vw, unsigned texture, int channel)
{
    (void)texture; (void)channel;
    return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, "null: no GL texture");
}

#endif
