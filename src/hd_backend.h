/* hd_backend.h - the contract between the core (src/) and a backend (backends/hd_cpu.h,
   hd_opencl.h, hd_vulkan.h, hd_gl.h, hd_null.h): every primitive the core calls, declared once
   with its contract. Exactly one backend is compiled in; it defines struct hd__backend and every
   function declared below, with these signatures (the helpers at the end are the core's, for
   backends to use). One it lacks is a compile error ("used but never defined") and a different
   signature a conflicting declaration, so the list is the whole job of a new backend
   (docs/BACKENDS.md, "Adding a backend"; backends/hd_null.h is the smallest complete one).

   The contract is closed both ways:
   - A primitive sees the context only through its view (hd__view, src/hd_internal.h), const:
     the volume, majorants, TF, grids' dims and channels, the parameter block, the direct
     light's voxel list, the camera and parameters, the backend's own desc section. The core's
     context (hd__ctx) is defined after the backend and cannot be named by it.
   - A backend calls no function of the core's: only the helpers below and those of
     src/hd_internal.h and the kernels. Its public entry points (hd_vulkan_record,
     hd_vulkan_record_render, hd_gl_render_to_texture_ex) are the core's, over the optional
     primitives at the end.
   The GPU backends make their grids (hd__be_alloc_*, hd__be_clear, the multigrid's levels)
   through backends/hd_gpu.h, which also defines for them the multigrid's primitives that are
   single passes.

   Common rules:
   - Every primitive returns HD_SUCCESS or a specific hd_result with one line logged through
     vw->log (HD__ERR). A device that is lost stays lost: every later call says so.
   - vw->kp (hd__kparams, filled by the core's hd__fill_kparams) holds the parameters the
     kernels read; vw->gdims, vw->channels and vw->sig_channels the illumination grid. Grids are
     in the colour layout (hd_prelude_c.h's hd__split_slot) wherever the backend keeps them in
     memory.
   - A primitive may only enqueue work; it must have finished, or be ordered before any later
     primitive's work, by the time a read-back (hd__be_read_*, hd__be_mg_row_sums) returns.
   - Nothing of the caller's state is changed: a backend working in a context the application
     owns (GL) saves and restores what it binds.
   - A capability a device may lack (double precision, 16-bit images) is checked at run time and
     refused with HD_ERROR_UNSUPPORTED and a logged reason. */
#ifndef HD_BACKEND_H
#define HD_BACKEND_H

/* ---- life cycle ------------------------------------------------------------------------------- */
/* The backend's short name ("cpu", "opencl", ...), a static string. */
static const char *hd__be_name(void);
/* Creates vw->be (the view's volume, TF, params and desc already validated and filled in). On failure
   everything it made is released and vw->be is NULL or destroyable. */
static hd_result hd__be_create(hd__view *vw);
/* Releases everything the backend holds, vw->be included; safe on a partly created backend. */
static void hd__be_destroy(hd__view *vw);

/* ---- the bracket of a public call ------------------------------------------------------------
   The core opens one bracket per public call that reaches the device (hd_iterate, hd_render, the
   read-backs, hd_vulkan_record, hd_gl_render_to_texture, ...) and runs its own preparation and
   every primitive below inside it; hd__be_create and hd__be_destroy run outside any. */
/* Refuses a device lost earlier (HD_ERROR_DEVICE_LOST, logged), makes the backend's context
   current on this thread and saves the caller's state the primitives will change (GL). On
   failure nothing is open and hd__be_end is not called. */
static hd_result hd__be_begin(const hd__view *vw);
/* Closes the bracket whatever r is (the call's first error, or HD_SUCCESS): what the backend
   recorded but did not submit is submitted and waited for (on success), the caller's state and
   context restored. Returns r, or its own error where r is HD_SUCCESS. */
static hd_result hd__be_end(const hd__view *vw, hd_result r);
/* ---- allocation (the core calls these from hd__prepare when its dirty bits say so) ----------- */
/* The volume, TF and majorant of the view are new: upload them (classification follows). */
static hd_result hd__be_upload_inputs(const hd__view *vw);
/* A box of a grid, [lo, hi) per axis x, y, z. */
typedef struct hd__box {
    int lo[3], hi[3];
} hd__box;
/* The majorant cells whose value range (their voxels and a one-voxel halo, src/hd_volume.h) holds
   a voxel of the box vox: the cells hd_update_volume changes with it. */
HD__MAYBE_UNUSED static hd__box hd__box_cells(const hd__view *vw, const hd__box *vox)
{
    hd__box c;
    int d, m = HD__MAJORANT_CELL;
    for (d = 0; d < 3; ++d) {
        c.lo[d] = vox->lo[d] > 0 ? (vox->lo[d] - 1) / m : 0;
        c.hi[d] = vox->hi[d] / m + 1;
        if (c.hi[d] > vw->mdims[d]) c.hi[d] = vw->mdims[d];
    }
    return c;
}
/* hd_update_volume: vw->vol's voxels in the box vox changed, and with them vw->majorant's cells
   in the box cells (hd__box_cells): upload those alone, nothing else of the volume or grid.
   hd__be_classify follows (the core calls it); the illumination is kept. */
static hd_result hd__be_update_volume(const hd__view *vw, const hd__box *vox, const hd__box *cells);
/* E, phi and phi2 for illum_floats values (0: free them; PT methods), contents undefined until
   hd__be_clear. Multigrid levels on the old grid may be dropped here; hd__be_mg_begin remakes
   them whenever they are missing or the grid changed. */
static hd_result hd__be_alloc_illumination(const hd__view *vw, size_t illum_floats);
/* The Jacobi solver's second phi buffer: allocated when enable, freed otherwise. */
static hd_result hd__be_alloc_jacobi(const hd__view *vw, int enable);
/* The RGBA float image of width x height and the parts hd__image_floats adds for the flags in
   `parts` (HD__IMAGE_REDUCED, HD__IMAGE_BLEND), contents undefined until hd__be_clear. The new
   buffer is made before the old one is released, so on failure the image held before is kept as
   it was. */
static hd_result hd__be_alloc_image(const hd__view *vw, int width, int height, int parts);
#define HD__IMAGE_REDUCED 1 /* the reduced frames' region */
#define HD__IMAGE_BLEND 2   /* HD_REST_BLEND's four planes */
/* The image buffer's floats: width x height RGBA, then with HD__IMAGE_REDUCED the room for a
   frame at render scale 2 (the largest reduced frame; hd_k_upsample.h), which only reduced frames
   use, then the depth plane (width x height floats from hd__image_depth_first: hd_k_project.h's
   hdk_project_depth, read by hd__be_read_depth), then with HD__IMAGE_BLEND four RGBA planes of
   width x height from hd__image_blend_first (the paths' mean and statistics, HD's frame and the
   blend's own: hd_k_upsample.h's hdk_blend_pixel). */
HD__MAYBE_UNUSED static size_t hd__image_depth_first(int width, int height, int parts)
{
    return ((size_t)width * height + ((parts & HD__IMAGE_REDUCED) ? (size_t)((width + 1) / 2) * ((height + 1) / 2) : 0)) * 4;
}
HD__MAYBE_UNUSED static size_t hd__image_blend_first(int width, int height, int parts)
{
    return hd__image_depth_first(width, height, parts) + (size_t)width * height;
}
HD__MAYBE_UNUSED static size_t hd__image_floats(int width, int height, int parts)
{
    return hd__image_blend_first(width, height, parts) + ((parts & HD__IMAGE_BLEND) ? (size_t)width * height * 16 : 0);
}
/* What the buffer holds besides the image, for the backends' messages: "" or " with ...". */
HD__MAYBE_UNUSED static const char *hd__image_parts_name(int parts)
{
    static const char *const names[4] = {"", " with room for reduced frames", " with the blend's planes",
                                         " with room for reduced frames and the blend's planes"};
    return names[parts & 3];
}
/* CD's light volumes: count of them (0 frees them), dark. */
static hd_result hd__be_alloc_lights(const hd__view *vw, int count);
/* The host's depth buffer changed (hd_set_depth): vw->depth, vw->depth_w x depth_h floats, or
   NULL (free what the backend holds, unless vw->depth_device: then keep the buffer
   hd__be_depth_texture filled). The projection and the path tracers read it as hdk_depth_t
   (hd_k_project.h) does, through their buffer `dep`, while vw->kp.depth_dims.z is 1. */
static hd_result hd__be_upload_depth(const hd__view *vw);
/* The environment's tables changed (hd_set_environment): vw->env, vw->env_floats floats, or NULL
   (free what the backend holds). The direct light and the path tracers read them as buffer
   `env` (hd_k_light.h) while vw->kp.env.x > 0. */
static hd_result hd__be_upload_env(const hd__view *vw);
/* Zeroes what the HD__DIRTY_* bits in what name: DIRECT (E and CD's light volumes), PHI (phi,
   phi2), IMAGE (the image). */
static hd_result hd__be_clear(const hd__view *vw, unsigned what);

/* ---- the method's stages (each over the whole grid or image, from vw->kp) --------------------- */
/* sigma_t from the volume and TF (hd_k_classify.h); the core counts the reclassifications
   (vw->sig_gen) for the solvers' coarse grids. */
static hd_result hd__be_classify(const hd__view *vw);
/* HD: one Monte Carlo sample of the direct light into E's running mean (hd_k_direct.h) at each of
   the grid voxels listed in vw->dl_idx[first, first + count) (with HD__BE_LIST_FROM_BITS and no
   dl_idx: the same entries of vw->dl_bits, vw->dl_brick) (first + count <= vw->dl_count; the
   core splits a light iteration's list over hd_render calls under render_budget); E elsewhere
   is left as it is. A voxel's sample depends on vw->kp and the voxel alone, so the ranges of one
   iteration give the bits of one call over the whole list. */
static hd_result hd__be_direct(const hd__view *vw, size_t first, size_t count);
/* HD: vw->dl_idx (vw->dl_count grid indices, in bricks) changed with sigma_t: make it the list
   hd__be_direct reads (a GPU backend uploads it). */
static hd_result hd__be_direct_list(const hd__view *vw);
/* One sweep of the single-level solver (jacobi: Jacobi into phi2, then swapped; else one
   red-black sweep, red then black) on phi (hd_k_diffuse.h). */
static hd_result hd__be_diffuse(const hd__view *vw, int jacobi);
/* `sweeps` such sweeps: the same result as as many hd__be_diffuse calls. */
static hd_result hd__be_diffuse_sweeps(const hd__view *vw, int jacobi, int sweeps);
/* CD: one convection step of light `light` (hd_k_convect.h). */
static hd_result hd__be_convect(const hd__view *vw, int light);
/* CD: the light volumes summed into E. */
static hd_result hd__be_sum_lights(const hd__view *vw);
/* One frame of the emission-absorption projection into the image's running mean (hd_k_project.h). */
static hd_result hd__be_project(const hd__view *vw);
/* A reduced frame's upsample pass (hd_k_upsample.h): the frame just projected at render scale
   s > 1 (vw->kp.image at the reduced size, into the image buffer's second region) bilinearly
   filled into the full image's running mean. vw->kp describes the full image, with the scale in
   region.y. With HD_FLAG_BLEND in counts.z instead, HD_REST_BLEND's blend pass (hdk_blend_pixel)
   into the image. */
static hd_result hd__be_upsample(const hd__view *vw);
/* PT_SS / PT_MS: one path per pixel into the image's running mean (hd_k_path.h). */
static hd_result hd__be_path(const hd__view *vw);

/* Waits until the device has run every primitive enqueued so far: hd_render under render_budget
   times each piece of light work and its frame by the wall clock after it. */
static hd_result hd__be_wait(const hd__view *vw);

/* ---- read-back (blocking: every earlier primitive's result) ------------------------------------ */
/* The image as RGBA floats, vw->camera.width x height, rows top to bottom. */
static hd_result hd__be_read_image(const hd__view *vw, float *dst);
/* The image buffer's depth plane (hd__image_floats), vw->camera.width x height floats from float
   vw->kp.region.z of the buffer: what hdk_project_depth wrote. */
static hd_result hd__be_read_depth(const hd__view *vw, float *dst);
/* E (HD_ILLUMINATION_DIRECT) or phi (SCATTERED) as floats, x fastest, channels stacked in z:
   with zz NULL the whole grid; else the z slices zz[0..count) of that stacking (slice zz: channel
   zz / gdims[2], z zz % gdims[2]) in that order, each gdims[0] * gdims[1] floats, one after
   another into dst (the light's convergence estimate reads only what it measures). */
static hd_result hd__be_read_illumination(const hd__view *vw, hd_illumination which, const int *zz, int count, float *dst);

/* ---- HD_SOLVER_MULTIGRID's per-level primitives -------------------------------------------------
   The core's hd__mg_step (src/hd_multigrid.h) runs conjugate gradients preconditioned by a
   V-cycle over these (docs/METHOD.md has the method, hd_multigrid_cg.h the level rule). The
   backend owns the buffers: per level l < hd__mg_levels(vw->gdims), of grid hd__mg_level_dims and
   vw->channels channels, a right-hand side (level 0: r), a correction (level 0: z) and a residual
   (level 0: q = A p); coarse levels a sigma_t of vw->sig_channels channels; on the fine grid the
   search direction p and the iterate's low part lo (CG's iterate is phi + lo); two buffers A and B
   of one double per fine row (vw->gdims[1] * gdims[2] * channels rows). Each level smooths and
   restricts with the parameter block hd__mg_level_kp. The per-voxel math of every pass is
   backends/kernels/hd_k_multigrid.h and hd_k_diffuse.h, so each backend's results have the CPU's
   bits wherever its float operations do. */
/* Starts a step: refuses what the device cannot do (double precision), makes the levels for the
   current grid, channels and sigma_t channels (new ones zeroed, *fresh = 1; kept ones *fresh = 0)
   and writes every level's parameter block. On success the core calls hd__be_mg_end once. */
static hd_result hd__be_mg_begin(const hd__view *vw, int *fresh);
/* Ends the step begun by hd__be_mg_begin, whatever r is (the first error of the step, or
   HD_SUCCESS): on success waits for its passes; restores what begin changed. Returns r, or its
   own error where r is HD_SUCCESS. */
static hd_result hd__be_mg_end(const hd__view *vw, hd_result r);
/* Level l's sigma_t (l >= 1) restricted from level l - 1's (hdk_mg_coarse_sig). */
static hd_result hd__be_mg_coarsen(const hd__view *vw, int l);
/* lo = 0 (the iterate's low part belongs to another phi). */
static hd_result hd__be_mg_zero_lo(const hd__view *vw);
/* r = f - A (phi + lo) on the fine grid, summed in double (hdk_mg_res_f64), into level 0's rhs. */
static hd_result hd__be_mg_residual_f64(const hd__view *vw);
/* `sweeps` red-black sweeps of level l's equation (first = 0: red then black; 1: black then red,
   the adjoint order). */
static hd_result hd__be_mg_smooth(const hd__view *vw, int l, int sweeps, int first);
/* Level l's residual (rhs - A correction, in float) into its residual buffer. */
static hd_result hd__be_mg_residual(const hd__view *vw, int l);
/* Level l + 1's rhs = R (level l's residual), masked to the medium; level l + 1's correction = 0. */
static hd_result hd__be_mg_restrict(const hd__view *vw, int l);
/* Level l's correction += P (level l + 1's correction), masked to the medium. */
static hd_result hd__be_mg_prolong(const hd__view *vw, int l);
/* Row sums of <r, z> into A (per fine row, x in order, in double: hdk_mg_dot_term). */
static hd_result hd__be_mg_dot_rz(const hd__view *vw);
/* p = z + beta p, then z = 0 (the next V-cycle starts from it). */
static hd_result hd__be_mg_direction(const hd__view *vw, float beta);
/* q = A p (in double, as hd__be_mg_residual_f64 with a zero right-hand side) into level 0's
   residual; the row sums of <p, q> into A and of <r, p> into B. */
static hd_result hd__be_mg_apply(const hd__view *vw);
/* Waits for every pass enqueued so far and points *a (and, n = 2, *b) at host copies of the row
   sums A (and B), valid until the next primitive; with n = 1 B need not be read back. The core
   adds them in row order (hd__mg_row_sum). */
static hd_result hd__be_mg_row_sums(const hd__view *vw, int n, const double **a, const double **b);
/* phi + lo += alpha p in double, phi its float rounding and lo the rest (hdk_mg_update_of). */
static hd_result hd__be_mg_update(const hd__view *vw, double alpha);
/* Surface boundary: the empty voxels of colour `colour` get the Marshak extrapolation in phi and
   lo = -phi (hdk_diffuse_extrapolate), with the fine parameters (no right-hand-side flag). */
static hd_result hd__be_mg_extrapolate(const hd__view *vw, int colour);
/* Bytes the solver's buffers hold (counted in method_bytes); 0 without them or with another solver. */
static size_t hd__be_solver_bytes(const hd__view *vw);
/* NULL where multigrid can run on this device, else why not (no double precision): what
   HD_SOLVER_AUTO's fall-back logs, asked before a step, so no refusal is logged as an error. */
static const char *hd__be_mg_unavailable(const hd__view *vw);

/* ---- optional features (hd__be_features says which a backend has) ------------------------------
   A backend without a feature still defines its primitives; the core never calls them then. */
#define HD__BE_RECORD 1  /* hd_vulkan_record, _record_render: work recorded into the caller's command buffer */
#define HD__BE_TEXTURE 2 /* hd_gl_render_to_texture(_ex): the image encoded into the caller's texture */
#define HD__BE_LIST_FROM_BITS 8 /* the direct light's entries read from vw->dl_bits and vw->dl_brick:
                                   the core builds no vw->dl_idx (but for the test hook's every voxel) */
#define HD__BE_CL_BUFFER 4 /* hd_opencl_set_depth_buffer: the host's depth from its cl_mem */
static unsigned hd__be_features(void);
/* Recording (HD__BE_RECORD). The core's hd_vulkan_record and hd_vulkan_record_render run their
   preparation, then hd__be_record_begin, then the method's primitives, which the backend
   records into `target` instead of submitting (each with its own parameter slots; `slots`
   parameter blocks at most), with hd__be_record_mark(vw, 0) and (vw, 1) around each HD or CD
   frame, then (hd_vulkan_record_render with a target) hd__be_record_output, then
   hd__be_record_end with the first error. */
static hd_result hd__be_record_begin(const hd__view *vw, void *target, int slots);
static void hd__be_record_mark(const hd__view *vw, int end);
static hd_result hd__be_record_end(const hd__view *vw, hd_result r);
/* The device time in seconds between the marks of the last recorded frame, once the caller has
   run it: 1 with *seconds set, 0 when there is none to read (none recorded since, no timestamps). */
static int hd__be_record_seconds(const hd__view *vw, double *seconds);
/* Records, after the frames recorded before it, the image (vw->camera's size) encoded in
   out->format (hd_read_image_ex's bytes) into the caller's target at (out->x, out->y), with
   the barriers hybriddiff.h documents at hd_vulkan_target. The core has checked the output
   (format, size: the camera's) and what needs no device (one of image or buffer, the region
   inside target->width x height, the buffer's rows inside buffer_size); the backend checks the
   rest in hd__be_output_target_check (the image's format against out->format, the layouts), each
   with its own result code and log line, which the core calls in the bracket before
   hd__be_record_begin, so a refused target leaves the command buffer untouched. */
static hd_result hd__be_output_target_check(const hd__view *vw, const hd_vulkan_target *target, const hd_output *out);
static hd_result hd__be_record_output(const hd__view *vw, const hd_vulkan_target *target, const hd_output *out);
/* HD__BE_RECORD: records into the caller's command buffer `cb` the copy of the host's depth
   (hybriddiff.h's hd_vulkan_depth, the camera's size) into the buffer the kernels read as `dep`,
   with its barriers, after checking what the core has not (the image's format: HD_ERROR_DEPTH_FORMAT,
   its layout: HD_ERROR_INVALID_PARAMETER; each with one log line, nothing recorded). The core has
   checked the pointers, one of image and buffer, the buffer's range and the camera, and sets
   vw->depth_device after. Runs in a bracket after the core's preparation. */
static hd_result hd__be_record_depth(const hd__view *vw, void *cb, const hd_vulkan_depth *depth);
/* HD__BE_RECORD: records into the caller's command buffer `cb` the copy of channel `channel` of
   E + phi (the projection's summed light, made first on the backend's own queue when stale) into
   the caller's 3D image or buffer (hybriddiff.h's hd_vulkan_volume_target), with its barriers,
   after checking what the core has not (the image's format: HD_ERROR_OUTPUT_FORMAT, its layouts:
   HD_ERROR_INVALID_ENUM; each with one log line, nothing recorded). The core has checked the
   method (HD, CD), the pointers, one of image and buffer, the channel, the image's extent and the
   buffer's range. Runs in a bracket after the core's preparation. */
static hd_result hd__be_record_illumination(const hd__view *vw, void *cb, int channel, const hd_vulkan_volume_target *target);
/* HD__BE_RECORD, inside a recording (hd_vulkan_record_refine): E + phi into the projection's
   summed light, recorded after the light iterations before it, where a pass changed them since
   (nothing when the sum is up to date); the sum is then up to date. */
static hd_result hd__be_record_light_sum(const hd__view *vw);
/* HD__BE_TEXTURE: checks that `texture` can take the image (its own result code and log line:
   HD_ERROR_INVALID_TEXTURE not a 2D texture, HD_ERROR_OUTPUT_FORMAT its internal format,
   HD_ERROR_OUTPUT_OUTSIDE_TARGET the region past its size; exact: hd_gl_render_to_texture's
   rule instead, GL_RGBA8 of exactly the camera's size or HD_ERROR_INVALID_TEXTURE), then writes
   the image encoded in out->format (hd_read_image_ex's bytes) into its region at (out->x,
   out->y), rows bottom first. The core has checked out (format, size: the camera's, x and y
   >= 0). Runs in a bracket after the core's preparation. */
static hd_result hd__be_output_texture(const hd__view *vw, unsigned texture, const hd_output *out, int exact);
/* HD__BE_TEXTURE: channel `channel` of E + phi (as the projection samples it) into texels from
   (0, 0, 0) of level 0 of the caller's 3D texture (GL_R32F, at least vw->gdims; checked here,
   each with its own result and log line: HD_ERROR_INVALID_TEXTURE, _OUTPUT_FORMAT,
   _OUTPUT_OUTSIDE_TARGET), on the device. The core has checked the method (HD, CD), the name
   (not 0) and the channel. Runs in a bracket after the core's preparation. */
static hd_result hd__be_illumination_texture(const hd__view *vw, unsigned texture, int channel);
/* HD__BE_TEXTURE: the host's depth texture (level 0 of a 2D texture of a depth format and the
   camera's size; checked here: HD_ERROR_INVALID_TEXTURE, _DEPTH_FORMAT, _DEPTH_SIZE, each with
   one log line, the buffer held before untouched) copied on the device into the buffer the
   kernels read as `dep`, GL's rows (bottom first, which kp.depth_dims.w = 1 tells them). The core
   then sets vw->depth_device. Runs in a bracket after the core's preparation. */
static hd_result hd__be_depth_texture(const hd__view *vw, unsigned texture);
/* HD__BE_CL_BUFFER: the host's cl_mem buffer (of the backend's context, width x height floats
   from byte offset; checked here: HD_ERROR_INVALID_PARAMETER not a buffer or another context,
   HD_ERROR_BUFFER_TOO_SMALL, each with one log line, the buffer held before untouched) copied
   on the device into `dep`, rows top first. The core has checked the pointer, the offset's
   alignment and the camera, and sets vw->depth_device after. */
static hd_result hd__be_depth_cl_buffer(const hd__view *vw, void *buffer, size_t offset);
/* The primitives of a feature a backend lacks, in one line each: they log and refuse, though the
   core never calls them (hd__be_features). NAME is the backend's name in the log line. */
#define HD__BE_NO_RECORDING(NAME)                                                                       \
    static hd_result hd__be_record_begin(const hd__view *vw, void *target, int slots)                   \
    {                                                                                                   \
        (void)target; (void)slots;                                                                      \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no recording");                          \
    }                                                                                                   \
    static void hd__be_record_mark(const hd__view *vw, int end) { (void)vw; (void)end; }                \
    static hd_result hd__be_record_end(const hd__view *vw, hd_result r) { (void)vw; return r; }         \
    static int hd__be_record_seconds(const hd__view *vw, double *seconds) { (void)vw; (void)seconds; return 0; } \
    static hd_result hd__be_output_target_check(const hd__view *vw, const hd_vulkan_target *target,     \
                                                const hd_output *out)                                   \
    {                                                                                                   \
        (void)target; (void)out;                                                                        \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no recording");                          \
    }                                                                                                   \
    static hd_result hd__be_record_output(const hd__view *vw, const hd_vulkan_target *target, const hd_output *out) \
    {                                                                                                   \
        (void)target; (void)out;                                                                        \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no recording");                          \
    }                                                                                                   \
    static hd_result hd__be_record_depth(const hd__view *vw, void *cb, const hd_vulkan_depth *depth)    \
    {                                                                                                   \
        (void)cb; (void)depth;                                                                          \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no recording");                          \
    }                                                                                                   \
    static hd_result hd__be_record_illumination(const hd__view *vw, void *cb, int channel,              \
                                                const hd_vulkan_volume_target *target)                  \
    {                                                                                                   \
        (void)cb; (void)channel; (void)target;                                                          \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no recording");                          \
    }                                                                                                   \
    static hd_result hd__be_record_light_sum(const hd__view *vw)                                        \
    {                                                                                                   \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no recording");                          \
    }
#define HD__BE_NO_CL_BUFFER(NAME)                                                                       \
    static hd_result hd__be_depth_cl_buffer(const hd__view *vw, void *buffer, size_t offset)            \
    {                                                                                                   \
        (void)buffer; (void)offset;                                                                     \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no OpenCL buffer");                      \
    }
#define HD__BE_NO_TEXTURE(NAME)                                                                         \
    static hd_result hd__be_output_texture(const hd__view *vw, unsigned texture, const hd_output *out, int exact) \
    {                                                                                                   \
        (void)texture; (void)out; (void)exact;                                                          \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no GL texture");                         \
    }                                                                                                   \
    static hd_result hd__be_illumination_texture(const hd__view *vw, unsigned texture, int channel)     \
    {                                                                                                   \
        (void)texture; (void)channel;                                                                   \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no GL texture");                         \
    }                                                                                                   \
    static hd_result hd__be_depth_texture(const hd__view *vw, unsigned texture)                         \
    {                                                                                                   \
        (void)texture;                                                                                  \
        return HD__ERR(&vw->log, HD_ERROR_UNSUPPORTED, NAME ": no GL texture");                         \
    }

/* ---- helpers a backend may use ----------------------------------------------------------------- */
/* hd__be_diffuse_sweeps for a backend whose sweeps are separate passes: hd__be_diffuse each. */
HD__MAYBE_UNUSED static hd_result hd__be_diffuse_each(const hd__view *vw, int jacobi, int sweeps)
{
    hd_result r = HD_SUCCESS;
    int s;
    for (s = 0; s < sweeps && r == HD_SUCCESS; ++s) r = hd__be_diffuse(vw, jacobi);
    return r;
}

/* The projection's TF table for the current TF, step and medium, as hdk_project_lookup reads it
   (hd_k_project.h): entry j at value j / (n - 1) is (rgb * a * albedo / (4 pi), a), a = 1 -
   exp(-sigma_t dt). n - 1 is a multiple of the TF's segments and at least HD__PTAB_MIN, so each
   table segment lies inside one TF segment. Every backend builds it here, so all of them read
   the same table. hd__project_table_n: its entries; hd__project_table: fills dst (n * 4 floats). */
#define HD__PTAB_MIN 4096
HD__MAYBE_UNUSED static int hd__project_table_n(const hd__view *vw)
{
    int segs = vw->tf_count - 1, m = segs < HD__PTAB_MIN ? (HD__PTAB_MIN + segs - 1) / segs : 1;
    return segs * m + 1;
}
/* What the table is built from: a backend keeps the key of the table it holds and rebuilds or
   uploads it only when hd__project_table_key_same says the inputs changed (a TF, step, extinction
   or albedo change); valid 0 (a zeroed key, or one reset with the table's buffer) never matches. */
typedef struct hd__ptab_key {
    int valid, n;
    unsigned tf_serial;
    float dt, extinction, scale;
} hd__ptab_key;
HD__MAYBE_UNUSED static hd__ptab_key hd__project_table_key(const hd__view *vw)
{
    hd__ptab_key k;
    k.valid = 1;
    k.n = hd__project_table_n(vw);
    k.tf_serial = vw->tf_serial;
    k.dt = vw->kp.march.x;
    k.extinction = vw->kp.medium.x;
    k.scale = vw->kp.medium.y * vw->kp.box.w;
    return k;
}
HD__MAYBE_UNUSED static int hd__project_table_key_same(const hd__view *vw, const hd__ptab_key *held)
{
    hd__ptab_key k = hd__project_table_key(vw);
    return held->valid && held->n == k.n && held->tf_serial == k.tf_serial && held->dt == k.dt &&
           held->extinction == k.extinction && held->scale == k.scale;
}
HD__MAYBE_UNUSED static void hd__project_table(const hd__view *vw, float *dst, int n)
{
    hd__kctx k;
    hd__kctx *K = &k;
    float dt = vw->kp.march.x, s = vw->kp.medium.y * vw->kp.box.w;
    int j;
    memset(&k, 0, sizeof k);
    k.p = &vw->kp;
    k.tf = vw->tf;
    for (j = 0; j < n; ++j) {
        hd_v4 c = hdk_tf(K, (float)j / (float)(n - 1));
        float a = 1.0f - hdk_exp(-(c.w * vw->kp.medium.x) * dt);
        dst[j * 4] = c.x * a * s;
        dst[j * 4 + 1] = c.y * a * s;
        dst[j * 4 + 2] = c.z * a * s;
        dst[j * 4 + 3] = a;
    }
}
/* The table in a new host buffer (free with hd__free), for a backend to upload; NULL, logged,
   without memory. */
HD__MAYBE_UNUSED static float *hd__project_table_new(const hd__view *vw, int n)
{
    float *t = (float *)hd__alloc(vw, (size_t)n * 4 * sizeof(float));
    if (t)
        hd__project_table(vw, t, n);
    else
        (void)HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "%s: cannot allocate the projection's TF table (%d entries)",
                      hd__be_name(), n);
    return t;
}

/* ---- the output encodings (hybriddiff.h, hd_output_format), one definition for every path -----
   HD_OUTPUT_SRGB8: hd__srgb8 of rgb * exposure, hd__alpha8 of alpha; LINEAR_F16: hdk_f2h of
   rgb * exposure and of alpha; LINEAR_F32: rgb * exposure and alpha. The core's read-backs
   encode with these on the host; a GPU pass gets the same bytes from the float products (IEEE
   multiplication, correctly rounded there too) by hdk_f2h's integer steps and, for RGBA8, by
   counting the thresholds of hd__output_thresholds at or below each value (no pow on the
   device). */
HD__MAYBE_UNUSED static uint8_t hd__srgb8(float v)
{
    float s;
    if (!(v > 0.0f)) return 0;
    if (v >= 1.0f) return 255;
    s = v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
    return (uint8_t)(s * 255.0f + 0.5f);
}
HD__MAYBE_UNUSED static uint8_t hd__alpha8(float a)
{
    return (uint8_t)(a <= 0.0f ? 0 : a >= 1.0f ? 255 : (int)(a * 255.0f + 0.5f));
}
/* Bytes per pixel of an output format. */
HD__MAYBE_UNUSED static size_t hd__output_pixel_bytes(hd_output_format f)
{
    return f == HD_OUTPUT_LINEAR_F32 ? 16 : f == HD_OUTPUT_LINEAR_F16 ? 8 : 4;
}
/* dst[k - 1], k = 1..255: the smallest positive float whose hd__srgb8 is >= k; dst[255 + k - 1]
   the same for hd__alpha8. Both are non-decreasing in v, so a value's code is the count of its
   thresholds <= v (NaN, compared false: 0, as hd__srgb8's !(v > 0)). Found by bisection over the
   positive floats' bit patterns, which are ordered as the floats. */
#define HD__OUTPUT_THRESHOLDS 510
HD__MAYBE_UNUSED static void hd__output_thresholds(float *dst)
{
    int k, which;
    for (which = 0; which < 2; ++which)
        for (k = 1; k <= 255; ++k) {
            uint32_t lo = 0, hi = 0x3f800000u; /* code(lo) < k <= code(hi): 0.0f and 1.0f */
            while (hi - lo > 1) {
                uint32_t mid = lo + (hi - lo) / 2;
                float v = hdk_u2f(mid);
                if ((which ? hd__alpha8(v) : hd__srgb8(v)) >= k) hi = mid;
                else lo = mid;
            }
            dst[which * 255 + k - 1] = hdk_u2f(hi);
        }
}

#endif
