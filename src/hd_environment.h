/* hd_environment.h - the environment light (hd_set_environment): its checks, the importance
   tables the kernels sample it by (backends/kernels/hd_k_light.h describes their layout) and
   its part of the parameter block. Part of the core (src/hd_core.h). */

/* The map's rotation as given (all zero: the identity) into r, checked: finite, orthonormal
   within 1e-3, determinant +1. */
static hd_result hd__env_rotation(const hd_environment *e, double r[9], const hd_logger *log)
{
    int i, j, zero = 1;
    double det;
    for (i = 0; i < 9; ++i) {
        if (!hd__finite(e->rotation[i]))
            return HD__ERR(log, HD_ERROR_INVALID_ENVIRONMENT, "environment rotation[%d] = %g is not finite", i, (double)e->rotation[i]);
        zero &= e->rotation[i] == 0.0f;
        r[i] = (double)e->rotation[i];
    }
    if (zero) {
        for (i = 0; i < 9; ++i) r[i] = i % 4 == 0 ? 1.0 : 0.0;
        return HD_SUCCESS;
    }
    for (i = 0; i < 3; ++i)
        for (j = 0; j < 3; ++j) {
            double d = r[3 * i] * r[3 * j] + r[3 * i + 1] * r[3 * j + 1] + r[3 * i + 2] * r[3 * j + 2];
            if (fabs(d - (i == j ? 1.0 : 0.0)) > 1e-3)
                return HD__ERR(log, HD_ERROR_INVALID_ENVIRONMENT, "environment rotation is not orthonormal (row %d . row %d = %g)", i, j, d);
        }
    det = r[0] * (r[4] * r[8] - r[5] * r[7]) - r[1] * (r[3] * r[8] - r[5] * r[6]) + r[2] * (r[3] * r[7] - r[4] * r[6]);
    if (!(det > 0.0)) return HD__ERR(log, HD_ERROR_INVALID_ENVIRONMENT, "environment rotation has determinant %g, not +1 (a reflection)", det);
    return HD_SUCCESS;
}

/* Checks an environment before anything is allocated; its power (intensity * the largest
   texel component) into *power and whether every texel is grey into *grey. */
static hd_result hd__check_environment(const hd_environment *e, double *power, int *grey, const hd_logger *log)
{
    size_t n, k;
    double cmax = 0.0, rot[9];
    hd_result r;
    int g = 1;
    if (e->width < 1 || e->height < 1 || e->width > HD_MAX_ENVIRONMENT_DIM || e->height > HD_MAX_ENVIRONMENT_DIM)
        return HD__ERR(log, HD_ERROR_INVALID_DIMENSIONS, "environment size %dx%d is outside 1..%d", e->width, e->height, HD_MAX_ENVIRONMENT_DIM);
    if (!e->rgb) return HD__ERR(log, HD_ERROR_NULL_POINTER, "environment rgb is NULL with a size of %dx%d", e->width, e->height);
    if (!hd__finite(e->intensity) || e->intensity < 0.0f)
        return HD__ERR(log, HD_ERROR_INVALID_ENVIRONMENT, "environment intensity %g must be finite and >= 0", (double)e->intensity);
    if ((r = hd__env_rotation(e, rot, log)) != HD_SUCCESS) return r;
    n = (size_t)e->width * (size_t)e->height;
    for (k = 0; k < 3 * n; ++k) {
        float v = e->rgb[k];
        if (!hd__finite(v) || v < 0.0f)
            return HD__ERR(log, HD_ERROR_INVALID_ENVIRONMENT, "environment texel (%d, %d) channel %d = %g is %s", (int)(k / 3 % (size_t)e->width),
                           (int)(k / 3 / (size_t)e->width), (int)(k % 3), (double)v, v < 0.0f ? "negative" : "not finite");
        if ((double)v > cmax) cmax = (double)v;
        if (k % 3 == 2 && !(e->rgb[k - 2] == e->rgb[k - 1] && e->rgb[k - 1] == v)) g = 0;
    }
    *power = (e->intensity == 0.0f ? 1.0 : (double)e->intensity) * cmax;
    *grey = g;
    if (!(*power * 1.0 <= (double)HD_MAX_LIGHT_POWER))
        return HD__ERR(log, HD_ERROR_INVALID_LIGHT, "environment intensity * largest texel = %g is above HD_MAX_LIGHT_POWER %g", *power,
                       (double)HD_MAX_LIGHT_POWER);
    return HD_SUCCESS;
}

/* The kernels' tables of a checked map: rgb * intensity per texel, the marginal CDF over rows
   and each row's conditional CDF, of the texel weights max(rgb) * sin(theta) at the texel's
   centre (summed in double). A row (or map) of weight 0 gets a uniform CDF its zero
   probability never picks. 4 w h + 2 h + 1 floats. */
static float *hd__env_tables(const hd__view *vw, const hd_environment *e, size_t *floats)
{
    int w = e->width, h = e->height, i, j;
    size_t n = (size_t)w * (size_t)h, at_m = 3 * n, at_c = at_m + (size_t)h + 1;
    float inten = e->intensity == 0.0f ? 1.0f : e->intensity;
    double total = 0.0, *rows;
    float *t = (float *)hd__alloc(vw, (4 * n + 2 * (size_t)h + 1) * sizeof(float));
    if (!t) return NULL;
    if (!(rows = (double *)hd__alloc(vw, (size_t)h * sizeof(double)))) { hd__free(vw, t); return NULL; }
    for (i = 0; i < (int)(3 * n); ++i) t[i] = e->rgb[i] * inten;
    for (j = 0; j < h; ++j) {
        double st = sin(3.14159265358979323846 * ((double)j + 0.5) / (double)h), s = 0.0;
        float *c = t + at_c + (size_t)j * (size_t)(w + 1);
        const float *px = e->rgb + (size_t)j * (size_t)w * 3;
        for (i = 0; i < w; ++i) s += (double)hd__max3(px + 3 * i) * st;
        rows[j] = s;
        total += s;
        {
            double acc = 0.0;
            c[0] = 0.0f;
            for (i = 0; i < w; ++i) {
                acc += s > 0.0 ? (double)hd__max3(px + 3 * i) * st : 1.0;
                c[i + 1] = (float)(acc / (s > 0.0 ? s : (double)w));
            }
            c[w] = 1.0f;
        }
    }
    {
        double acc = 0.0;
        t[at_m] = 0.0f;
        for (j = 0; j < h; ++j) {
            acc += total > 0.0 ? rows[j] : 1.0;
            t[at_m + (size_t)j + 1] = (float)(acc / (total > 0.0 ? total : (double)h));
        }
        t[at_m + (size_t)h] = 1.0f;
    }
    hd__free(vw, rows);
    *floats = 4 * n + 2 * (size_t)h + 1;
    return t;
}

/* The fluence of a map's tables (radiance times the intensity) in the open: the sum over the
   texels of max(rgb) times the solid angle, 2 pi^2 sin(theta) / (w h). The light choice's
   estimate (hd__light_cdf). */
static double hd__env_fluence(const float *t, int w, int h)
{
    double sum = 0.0;
    int i, j;
    for (j = 0; j < h; ++j) {
        double st = sin(3.14159265358979323846 * ((double)j + 0.5) / (double)h), s = 0.0;
        for (i = 0; i < w; ++i) s += (double)hd__max3(t + 3 * ((size_t)j * (size_t)w + (size_t)i));
        sum += s * st;
    }
    return sum * 2.0 * 3.14159265358979323846 * 3.14159265358979323846 / ((double)w * (double)h);
}

/* The environment's part of the parameter block: the tables' places and the rotation from the
   volume's frame into the map's, whose rows are the map's axes (world = R map) mapped into the
   volume's frame. */
static void hd__env_kparams(const hd__ctx *ctx, hd__kparams *k)
{
    double rot[9];
    int j;
    size_t n;
    if (!ctx->env_on) return;
    n = (size_t)ctx->env.width * (size_t)ctx->env.height;
    k->env.x = ctx->env.width; k->env.y = ctx->env.height;
    k->env.z = (int32_t)(3 * n); k->env.w = (int32_t)(3 * n + (size_t)ctx->env.height + 1);
    if (hd__env_rotation(&ctx->env, rot, NULL) != HD_SUCCESS) return; /* checked by hd_set_environment */
    for (j = 0; j < 3; ++j) {
        double col[3] = {rot[j], rot[3 + j], rot[6 + j]}, m[3];
        float f[3], u[3];
        hd_f4 *row = j == 0 ? &k->env_r0 : j == 1 ? &k->env_r1 : &k->env_r2;
        if (!ctx->xf.identity) hd__xform_dir(&ctx->xf, col, m);
        else { m[0] = col[0]; m[1] = col[1]; m[2] = col[2]; }
        hd__store3(f, m);
        hd__unit3(f, u);
        row->x = u[0]; row->y = u[1]; row->z = u[2]; row->w = 0.0f;
    }
}

static hd_result hd__api_set_environment(hd__ctx *ctx, const hd_environment *env)
{
    hd_result r;
    double power = 0.0;
    int grey = 1, channels_before = ctx->vw.channels;
    float *tab;
    size_t floats = 0;
    if (!env) {
        if (!ctx->env_on) return HD_SUCCESS;
        if (ctx->light_count == 0)
            return HD__ERR(&ctx->vw.log, HD_ERROR_NO_LIGHTS, "hd_set_environment: clearing the environment would leave no lights (set lights first)");
        hd__free(&ctx->vw, ctx->vw.env);
        ctx->vw.env = NULL;
        ctx->vw.env_floats = 0;
        ctx->env_on = 0;
    } else {
        if ((r = hd__check_environment(env, &power, &grey, &ctx->vw.log)) != HD_SUCCESS) return r;
        if (ctx->vw.params.method == HD_METHOD_CD)
            return HD__ERR(&ctx->vw.log, HD_ERROR_UNSUPPORTED, "hd_set_environment: method CD keeps one light volume per light and cannot hold an environment");
        if ((r = hd__check_lights(ctx->lights, ctx->light_count, power, &ctx->vw.log)) != HD_SUCCESS) return r;
        if (!(tab = hd__env_tables(&ctx->vw, env, &floats)))
            return HD__ERR(&ctx->vw.log, HD_ERROR_OUT_OF_MEMORY, "hd_set_environment: cannot allocate the tables of a %dx%d map", env->width, env->height);
        hd__free(&ctx->vw, ctx->vw.env);
        ctx->vw.env = tab;
        ctx->vw.env_floats = floats;
        ctx->env = *env;
        ctx->env.rgb = NULL; /* the caller's buffer is not kept */
        ctx->env_on = 1;
        ctx->env_grey = grey;
        ctx->env_power = power;
        ctx->env_fluence = hd__env_fluence(tab, env->width, env->height);
    }
    hd__set_channels(ctx);
    ctx->dirty |= HD__DIRTY_ENV | HD__INV_WARM_LIGHT;
    if (ctx->vw.channels != channels_before) ctx->dirty |= HD__DIRTY_ALLOC | HD__INV_LIGHT; /* new grids */
    return HD_SUCCESS;
}
