/* impl_backend.c - the backend under test as the table hd_api_backend (see hd_api.h). Build it
   with exactly one of -DHYBRIDDIFF_BACKEND_OPENCL, _VULKAN, _GL (or _CPU, to test the suite). */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_STATIC
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hd_api.h"

HD_API_TABLE(hd_api_backend);
