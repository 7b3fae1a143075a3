/* hd_validate.h - checks every input and fills the documented defaults, before anything is
   allocated or dispatched. Each check returns its own hd_result and logs what was wrong. */
#include <float.h>

static int hd__finite3(const float v[3]) { return hd__finite(v[0]) && hd__finite(v[1]) && hd__finite(v[2]); }

/* The derived geometry, in double (dims * spacing may pass FLT_MAX): the box's largest side is
   1, so a voxel's world size along axis i is spacing[i] / max extent. Below 1 / HD_MAX_SPACING_RATIO
   a ray position no longer resolves the voxel in float and the march and DDA step counts grow
   without use; the all-zero spacing (the default {1,1,1}) passes. */
static hd_result hd__check_extent(const hd_volume_desc *v, const hd_logger *log)
{
    double ext[3], emax = 0.0;
    int i;
    if (v->spacing[0] == 0.0f && v->spacing[1] == 0.0f && v->spacing[2] == 0.0f) return HD_SUCCESS;
    for (i = 0; i < 3; ++i) {
        ext[i] = (double)v->dims[i] * (double)v->spacing[i];
        if (ext[i] > emax) emax = ext[i];
    }
    for (i = 0; i < 3; ++i) {
        double voxel = (double)v->spacing[i] / emax;
        if (!(voxel * (double)HD_MAX_SPACING_RATIO >= 1.0) || !((float)(ext[i] / emax) > 0.0f))
            return HD__ERR(log, HD_ERROR_INVALID_SPACING,
                           "volume.spacing {%g, %g, %g}: a voxel along axis %d is %g of the largest extent, "
                           "below 1/%g", (double)v->spacing[0], (double)v->spacing[1], (double)v->spacing[2],
                           i, voxel, (double)HD_MAX_SPACING_RATIO);
    }
    return HD_SUCCESS;
}

static hd_result hd__check_volume(const hd_volume_desc *v, const hd_logger *log)
{
    size_t nvox = 1;
    int i;
    hd_result r;
    if (v->type <= HD_VOXEL_INVALID || v->type >= HD_VOXEL_COUNT)
        return HD__ERR(log, HD_ERROR_INVALID_ENUM, "volume.type %d is not a hd_voxel_type", (int)v->type);
    for (i = 0; i < 3; ++i) {
        if (v->dims[i] < 1 || v->dims[i] > HD_MAX_DIM)
            return HD__ERR(log, HD_ERROR_INVALID_DIMENSIONS, "volume.dims[%d] = %d is outside 1..%d", i, v->dims[i], HD_MAX_DIM);
    }
    for (i = 0; i < 3; ++i) nvox *= (size_t)v->dims[i];
    /* the kernels index the volume with 32-bit ints */
    if (nvox > HD__MAX_VOXELS)
        return HD__ERR(log, HD_ERROR_SIZE_OVERFLOW, "volume of %dx%dx%d voxels exceeds the %u-voxel limit",
                       v->dims[0], v->dims[1], v->dims[2], HD__MAX_VOXELS);
    if (!v->data) return HD__ERR(log, HD_ERROR_NULL_POINTER, "volume.data is NULL");
    for (i = 0; i < 3; ++i) {
        if (v->spacing[0] == 0.0f && v->spacing[1] == 0.0f && v->spacing[2] == 0.0f) break;
        if (!hd__finite(v->spacing[i]) || !(v->spacing[i] > 0.0f))
            return HD__ERR(log, HD_ERROR_INVALID_SPACING, "volume.spacing[%d] = %g must be finite and > 0", i, (double)v->spacing[i]);
    }
    if ((r = hd__check_extent(v, log)) != HD_SUCCESS) return r;
    if (!hd__finite(v->value_range[0]) || !hd__finite(v->value_range[1]) ||
        (v->value_range[0] == v->value_range[1] && v->value_range[0] != 0.0f))
        return HD__ERR(log, HD_ERROR_INVALID_PARAMETER, "volume.value_range {%g, %g} must be finite and not empty",
                       (double)v->value_range[0], (double)v->value_range[1]);
    return HD_SUCCESS;
}

/* The illumination grid of dims over params.illumination_downsample (hd__set_grid's rounding):
   its voxels times HD__MAX_GRID_CHANNELS must stay within the kernels' 32-bit indices. */
static hd_result hd__check_grid(const int *dims, const hd_params *p, const hd_logger *log)
{
    int d, f = p->illumination_downsample, g[3];
    size_t n = 1;
    for (d = 0; d < 3; ++d) n *= (size_t)(g[d] = (dims[d] + f - 1) / f);
    if (n > HD__MAX_GRID_VOXELS)
        return HD__ERR(log, HD_ERROR_SIZE_OVERFLOW,
                       "illumination grid of %dx%dx%d voxels (illumination_downsample %d) exceeds the %u-voxel limit "
                       "(%d channels indexed by 32-bit ints): raise illumination_downsample",
                       g[0], g[1], g[2], f, HD__MAX_GRID_VOXELS, HD__MAX_GRID_CHANNELS);
    return HD_SUCCESS;
}

static hd_result hd__check_tf(const hd_transfer_function *tf, const hd_logger *log)
{
    int i;
    if (!tf->rgba && tf->count == 0) return HD_SUCCESS; /* the default ramp */
    if (tf->count < 2) return HD__ERR(log, HD_ERROR_INVALID_TRANSFER_FUNCTION, "transfer function has %d entries, needs >= 2", tf->count);
    if (tf->count > (1 << 20)) return HD__ERR(log, HD_ERROR_INVALID_TRANSFER_FUNCTION, "transfer function has %d entries, at most %d", tf->count, 1 << 20);
    if (!tf->rgba) return HD__ERR(log, HD_ERROR_NULL_POINTER, "transfer_function.rgba is NULL with count %d", tf->count);
    for (i = 0; i < tf->count * 4; ++i) {
        float v = tf->rgba[i];
        if (!hd__finite(v) || v < 0.0f || v > 1.0f)
            return HD__ERR(log, HD_ERROR_INVALID_TRANSFER_FUNCTION, "transfer function entry %d component %d = %g is not in [0, 1]",
                           i / 4, i % 4, (double)v);
    }
    return HD_SUCCESS;
}

/* The unit vector along v, scaled by its largest component first so the squared length neither
   overflows nor underflows; 0 (and out zeroed) when v is zero or the result is not finite. */
static int hd__unit3(const float v[3], float out[3])
{
    double m = 0.0, a[3], n;
    int i;
    for (i = 0; i < 3; ++i) { double c = fabs((double)v[i]); if (c > m) m = c; }
    out[0] = out[1] = out[2] = 0.0f;
    if (!(m > 0.0) || !(m <= (double)FLT_MAX)) return 0;
    for (i = 0; i < 3; ++i) a[i] = (double)v[i] / m;
    n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    for (i = 0; i < 3; ++i) out[i] = (float)(a[i] / n);
    return hd__finite(out[0]) && hd__finite(out[1]) && hd__finite(out[2]) &&
           out[0] * out[0] + out[1] * out[1] + out[2] * out[2] > 0.5f;
}

/* An area light's shape (hybriddiff.h, hd_light): finite, nonzero, not parallel, within
   HD_MAX_LIGHT_DISTANCE. */
static hd_result hd__check_area_light(const hd_light *l, int i, const hd_logger *log)
{
    const char *name = l->type == HD_LIGHT_QUAD ? "quad" : l->type == HD_LIGHT_DISK ? "disk" : "sphere";
    float u1[3], u2[3], c[3];
    int k;
    if (!hd__finite3(l->edge1) || !hd__finite3(l->edge2) || !hd__finite(l->radius))
        return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: %s light has a NaN or infinite edge or radius", i, name);
    if (l->type == HD_LIGHT_QUAD) {
        for (k = 0; k < 3; ++k)
            if (fabsf(l->edge1[k]) > HD_MAX_LIGHT_DISTANCE || fabsf(l->edge2[k]) > HD_MAX_LIGHT_DISTANCE)
                return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: quad light edge beyond %g world units", i, (double)HD_MAX_LIGHT_DISTANCE);
        if (!hd__unit3(l->edge1, u1) || !hd__unit3(l->edge2, u2))
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: quad light with a zero edge (size 0)", i);
        c[0] = u1[1] * u2[2] - u1[2] * u2[1];
        c[1] = u1[2] * u2[0] - u1[0] * u2[2];
        c[2] = u1[0] * u2[1] - u1[1] * u2[0];
        if (!(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] > 1e-8f))
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: quad light with parallel edges (no area)", i);
        return HD_SUCCESS;
    }
    if (!(l->radius > 0.0f) || l->radius > HD_MAX_LIGHT_DISTANCE)
        return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: %s light radius %g is outside (0, %g]", i, name,
                       (double)l->radius, (double)HD_MAX_LIGHT_DISTANCE);
    if (l->type == HD_LIGHT_DISK && !hd__unit3(l->direction, u1))
        return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: disk light with a zero normal (direction)", i);
    return HD_SUCCESS;
}

/* Method CD keeps one light volume per direction or point, so it refuses area lights (fn: the
   calling entry point, for the log line). */
static hd_result hd__check_cd_lights(hd_method method, const hd_light *lights, int count, const char *fn, const hd_logger *log)
{
    int i;
    if (method != HD_METHOD_CD) return HD_SUCCESS;
    for (i = 0; lights && i < count; ++i)
        if (lights[i].type >= HD_LIGHT_QUAD && lights[i].type < HD_LIGHT_TYPE_COUNT)
            return HD__ERR(log, HD_ERROR_UNSUPPORTED, "%s: method CD keeps one light volume per direction or point and cannot hold an area light (light %d)",
                           fn, i);
    return HD_SUCCESS;
}

/* Lights as given (env_power: an environment's power, -1 without one), before the defaults (zero colour -> white, zero intensity -> 1), which the
   power limit applies after: sum of intensity * max(colour) <= HD_MAX_LIGHT_POWER keeps E, phi
   and the image finite (a sample is at most 10 (HD_MAX_LIGHTS + 1) * power * 1e12: one over
   the least chance of a light (src/hd_kparams.h, hd__light_cdf) times the point lights' 1/r^2
   floor, which caps an area light's A cos / r^2 too; README "Guarantees"). */
static hd_result hd__check_lights(const hd_light *lights, int count, double env_power, const hd_logger *log)
{
    int i;
    hd_result r;
    double power = env_power > 0.0 ? env_power : 0.0; /* an environment's (src/hd_environment.h), which may stand alone */
    if (count == 0 && env_power >= 0.0) return HD_SUCCESS;
    if (count == 0) return HD__ERR(log, HD_ERROR_NO_LIGHTS, "no lights: give at least one, or set an environment");
    if (count < 0) return HD__ERR(log, HD_ERROR_NO_LIGHTS, "light count %d is negative", count);
    if (count > HD_MAX_LIGHTS) return HD__ERR(log, HD_ERROR_TOO_MANY_LIGHTS, "%d lights, at most %d", count, HD_MAX_LIGHTS);
    if (!lights) return HD__ERR(log, HD_ERROR_NULL_POINTER, "lights is NULL with count %d", count);
    for (i = 0; i < count; ++i) {
        const hd_light *l = &lights[i];
        float unit[3];
        double cmax, inten;
        if ((int)l->type < 0 || l->type >= HD_LIGHT_TYPE_COUNT)
            return HD__ERR(log, HD_ERROR_INVALID_ENUM, "light %d: type %d is not a hd_light_type", i, (int)l->type);
        if (!hd__finite3(l->direction) || !hd__finite3(l->position) || !hd__finite3(l->color) || !hd__finite(l->intensity))
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d has a NaN or infinite value", i);
        if (l->color[0] < 0.0f || l->color[1] < 0.0f || l->color[2] < 0.0f || l->intensity < 0.0f)
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d has a negative colour or intensity", i);
        if (l->type == HD_LIGHT_DIRECTIONAL && !hd__unit3(l->direction, unit))
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: directional light with a zero direction", i);
        if (l->type >= HD_LIGHT_QUAD && (r = hd__check_area_light(l, i, log)) != HD_SUCCESS) return r;
        if (l->type != HD_LIGHT_DIRECTIONAL &&
            (fabsf(l->position[0]) > HD_MAX_LIGHT_DISTANCE || fabsf(l->position[1]) > HD_MAX_LIGHT_DISTANCE ||
             fabsf(l->position[2]) > HD_MAX_LIGHT_DISTANCE))
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "light %d: light at {%g, %g, %g}, beyond %g world units",
                           i, (double)l->position[0], (double)l->position[1], (double)l->position[2],
                           (double)HD_MAX_LIGHT_DISTANCE);
        cmax = l->color[0] > l->color[1] ? l->color[0] : l->color[1];
        if (l->color[2] > cmax) cmax = l->color[2];
        if (cmax == 0.0) cmax = 1.0;
        inten = l->intensity == 0.0f ? 1.0 : (double)l->intensity;
        power += inten * cmax;
        if (!(power <= (double)HD_MAX_LIGHT_POWER))
            return HD__ERR(log, HD_ERROR_INVALID_LIGHT,
                           "light %d: intensity * colour summed over lights 0..%d%s is %g, above HD_MAX_LIGHT_POWER %g",
                           i, i, env_power > 0.0 ? " and the environment" : "", power, (double)HD_MAX_LIGHT_POWER);
    }
    return HD_SUCCESS;
}

static void hd__camera_defaults(hd_camera *c)
{
    int i, zero = 1;
    for (i = 0; i < 3; ++i) zero &= c->eye[i] == 0.0f && c->target[i] == 0.0f;
    if (zero) c->eye[2] = 2.5f;
    if (c->up[0] == 0.0f && c->up[1] == 0.0f && c->up[2] == 0.0f) c->up[1] = 1.0f;
    if (c->fov_y == 0.0f) c->fov_y = 40.0f;
    if (c->width == 0) c->width = 512;
    if (c->height == 0) c->height = 512;
}

/* Checks a camera whose defaults are filled in. A camera given by matrices (projection not all
   zero) ignores eye, target, up and fov_y; its matrices and the distance limit of every camera
   are checked where its rays are made (hd__camera_frame, src/hd_scene.h). */
static hd_result hd__check_camera(const hd_camera *c, const hd_logger *log)
{
    float f[3], fu[3], uu[3], cr[3], lf, lc;
    int i, matrix = 0;
    for (i = 0; i < 16; ++i) matrix |= c->projection[i] != 0.0f;
    if ((int)c->depth_range < 0 || c->depth_range >= HD_DEPTH_RANGE_COUNT)
        return HD__ERR(log, HD_ERROR_INVALID_ENUM, "camera depth_range %d is not a hd_depth_range", (int)c->depth_range);
    if (c->width < 1 || c->height < 1 || c->width > HD_MAX_IMAGE_DIM || c->height > HD_MAX_IMAGE_DIM)
        return HD__ERR(log, HD_ERROR_INVALID_DIMENSIONS, "image size %dx%d is outside 1..%d", c->width, c->height, HD_MAX_IMAGE_DIM);
    if (matrix) return HD_SUCCESS;
    if (!hd__finite3(c->eye) || !hd__finite3(c->target) || !hd__finite3(c->up) || !hd__finite(c->fov_y))
        return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera has a NaN or infinite value");
    if (!(c->fov_y > 0.0f && c->fov_y < 180.0f))
        return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera fov_y = %g degrees is outside (0, 180)", (double)c->fov_y);
    f[0] = c->target[0] - c->eye[0]; f[1] = c->target[1] - c->eye[1]; f[2] = c->target[2] - c->eye[2];
    lf = sqrtf(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (!(lf > 1e-6f)) return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera eye and target coincide");
    /* unit vectors first (hd__unit3), so a tiny or huge up neither underflows nor overflows the
       cross product hd__fill_kparams normalises */
    if (!hd__unit3(f, fu) || !hd__unit3(c->up, uu))
        return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera up is zero");
    cr[0] = fu[1] * uu[2] - fu[2] * uu[1];
    cr[1] = fu[2] * uu[0] - fu[0] * uu[2];
    cr[2] = fu[0] * uu[1] - fu[1] * uu[0];
    lc = sqrtf(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
    if (!(lc > 1e-4f)) return HD__ERR(log, HD_ERROR_INVALID_CAMERA, "camera up is parallel to the view direction");
    return HD_SUCCESS;
}

/* The defaults (src/hd_params.h) were chosen by measurement against PT_MS (docs/EVALUATION.md, "Defaults");
   the paper's preset keeps its settings reachable. */
HDDEF hd_result hd_params_preset(hd_preset preset, hd_params *params, const hd_logger *log)
{
    if (!params) return HD__ERR(log, HD_ERROR_NULL_POINTER, "hd_params_preset: params is NULL");
    if ((int)preset < 0 || preset >= HD_PRESET_COUNT)
        return HD__ERR(log, HD_ERROR_INVALID_ENUM, "hd_params_preset: preset %d is not a hd_preset", (int)preset);
    if (preset == HD_PRESET_PAPER) {
        params->illumination_downsample = 1;
        params->diffusion_boundary = HD_BOUNDARY_BOX;
        params->solver = HD_SOLVER_RED_BLACK;
        params->diffusion_sweeps = 4;
    } else {
        params->illumination_downsample = 0;
        params->diffusion_boundary = HD_BOUNDARY_DEFAULT;
        params->solver = HD_SOLVER_DEFAULT;
        params->diffusion_sweeps = 0;
    }
    return HD_SUCCESS;
}
