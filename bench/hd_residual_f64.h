/* hd_residual_f64.h - bench only: see hd_residual_f64.c. */
#ifndef HD_RESIDUAL_F64_H
#define HD_RESIDUAL_F64_H
#include <stddef.h>
#ifdef __cplusplus
extern "C" {
#endif
/* The relative residual, in double, of the diffusion on a float32 grid: params_f32 is the
   grid's kernel parameter block (hd__kparams), sig its sigma_t grid (sig_count floats), E and phi
   its illumination (gdims.x * y * z * w floats each). -1 when out of memory. */
double hdb_residual_f64(const void *params_f32, const float *sig, size_t sig_count, const float *E, const float *phi);
#ifdef __cplusplus
}
#endif
#endif
