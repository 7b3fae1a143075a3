/* impl_cpu.c - the CPU reference implementation as the table hd_api_cpu (see hd_api.h). */
#define HYBRIDDIFF_TESTING /* the test hooks and fault injection (src/hd_test_hooks.h) */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_STATIC
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
#include "src/hd_test_hooks.h"
#include "hd_api.h"

HD_API_TABLE(hd_api_cpu);
