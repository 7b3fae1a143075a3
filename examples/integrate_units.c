/* integrate_units.c - two translation units: this C99 file holds the implementation and main,
   integrate_units_cxx.cpp (C++17) includes hybriddiff.h with no macro and sees only the
   declarations. Exits 1 on any failure (mk/integrate.mk). */
#ifndef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#endif
#include <stdio.h>
#include <stdlib.h>
#ifdef INTEGRATE_HD_LAST
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#endif

#ifdef __cplusplus
extern "C"
#endif
int render_in_cxx(const unsigned char *voxels, int n, int size); /* integrate_units_cxx.cpp */

int main(void)
{
    enum { N = 16 };
    unsigned char *v = (unsigned char *)malloc(N * N * N);
    int i, lit;
    if (!v) return 1;
    for (i = 0; i < N * N * N; ++i) v[i] = (unsigned char)((i / N) % N > N / 2 ? 220 : 0);
    lit = render_in_cxx(v, N, 32);
    free(v);
    printf("integrate_units: %d lit pixels from the C++ unit\n", lit);
    return lit > 0 ? 0 : 1;
}
