/* The library for the allocation-failure tests on a GPU backend: the backend macro comes from
   the command line (-DHYBRIDDIFF_BACKEND_OPENCL, ...); see mk/alloc_fail_gpu.mk. */
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
