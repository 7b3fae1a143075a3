/* hd_impl_fuzz.c - the library's implementation (CPU backend) for every fuzz target, compiled
   once with the fuzzers' sanitizer flags and linked into each (mk/reliability.mk). */
#define HYBRIDDIFF_IMPLEMENTATION
#define HYBRIDDIFF_BACKEND_CPU
#include "hybriddiff.h"
