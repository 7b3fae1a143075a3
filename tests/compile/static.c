/* static.c - HYBRIDDIFF_STATIC: the implementation private to this one unit, used by the
   program of user.c in the same unit (every function it does not call is unused and must not
   warn). The backend macro comes from the command line. */
#define HYBRIDDIFF_STATIC
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "user.c"
