/* impl.c - the implementation unit of the compile matrix (tests/compile/matrix): the backend
   macro, and HYBRIDDIFF_STATIC or HYBRIDDIFF_NO_ZLIB, come from the command line. Compiled as
   C99 and as C++17 with -I dist only, so nothing of the split layout can be picked up.
   The header is included twice: the second copy must add nothing. */
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "hybriddiff.h"
