/* hd_residual_f64.c - bench only (hdbench_multigrid): the diffusion's relative residual
   |f - A phi| / |f| evaluated in double, for float32 grids. The float residual of a converged
   phi carries the rounding of diagonal * phi (about 7e4 * phi in soft tissue at h = 1/256), which
   floors the relative residual near 1e-3; evaluated in double, what is left is phi's own error.
   The operator is the shared kernel itself (backends/kernels/hd_k_diffuse.h) compiled with
   `float` spelled `double` in this translation unit only: the same discrete equation (its float
   literals keep their values) in another precision, no second copy of the math. Not library
   code: it includes the kernels, not hybriddiff.h. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include "hd_residual_f64.h"

#define HD_MAX_LIGHTS 64 /* must match hybriddiff.h: the parameter block's layout */
#define float double
#include "backends/hd_prelude_c.h"
#undef hdk_log
#undef hdk_exp
#undef hdk_sqrt
#undef hdk_floor
#undef hdk_absf
#undef hdk_powf
#define hdk_log(x) log(x)
#define hdk_exp(x) exp(x)
#define hdk_sqrt(x) sqrt(x)
#define hdk_floor(x) floor(x)
#define hdk_absf(x) fabs(x)
#define hdk_powf(x, y) pow((x), (y))
#include "backends/kernels/hd_k_common.h"
#include "backends/kernels/hd_k_diffuse.h"
#undef float

/* The float32 parameter block into its double twin, field by field: every field is a 16-byte
   vector (4 int32 or 4 float), walked with the same list the block is declared with. */
static void params_to_f64(const unsigned char *src, hd__kparams *P)
{
    int k;
    float f[4];
#define CVT4(dst) (memcpy(f, src, 16), (dst).x = f[0], (dst).y = f[1], (dst).z = f[2], (dst).w = f[3], src += 16)
#undef HD_PARAMS_BEGIN
#undef HD_PARAMS_END
#undef HD_PARAM_I4
#undef HD_PARAM_F4
#undef HD_PARAM_F4_ARRAY
#define HD_PARAMS_BEGIN
#define HD_PARAMS_END
#define HD_PARAM_I4(name) memcpy(&P->name, src, 16); src += 16;
#define HD_PARAM_F4(name) CVT4(P->name);
#define HD_PARAM_F4_ARRAY(name, n) for (k = 0; k < (n); ++k) CVT4(P->name[k]);
#include "backends/kernels/hd_k_params.h"
#undef CVT4
}

static double *to_f64(const float *a, size_t n)
{
    double *d = (double *)malloc(n * sizeof(double));
    size_t i;
    if (d)
        for (i = 0; i < n; ++i) d[i] = a[i];
    return d;
}

double hdb_residual_f64(const void *params_f32, const float *sig, size_t sig_count, const float *E, const float *phi)
{
    hd__kparams P;
    hd__kctx K;
    double *ds, *dE, *dphi, r2 = 0.0, b2 = 0.0;
    size_t n;
    int x, y, z, c, gx, gy, gz;
    params_to_f64((const unsigned char *)params_f32, &P);
    gx = P.gdims.x; gy = P.gdims.y; gz = P.gdims.z;
    n = (size_t)gx * gy * gz * (size_t)P.gdims.w;
    ds = to_f64(sig, sig_count); dE = to_f64(E, n); dphi = to_f64(phi, n);
    if (!ds || !dE || !dphi) { free(ds); free(dE); free(dphi); return -1.0; }
    memset(&K, 0, sizeof K);
    K.p = &P; K.sig = ds; K.E = dE; K.phi = dphi;
    for (c = 0; c < P.gdims.w; ++c)
        for (z = 0; z < gz; ++z)
            for (y = 0; y < gy; ++y)
                for (x = 0; x < gx; ++x) {
                    double rhs, r = hdk_diffuse_residual(&K, x, y, z, c, &rhs);
                    r2 += r * r;
                    b2 += rhs * rhs;
                }
    free(ds); free(dE); free(dphi);
    return b2 > 0.0 ? sqrt(r2 / b2) : 0.0;
}
