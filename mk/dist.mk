# mk/dist.mk - the distributable single header and the proof that it is what users can take.
#   make dist            ./amalgamate: hybriddiff.h + src/ + backends/ -> dist/hybriddiff.h
#                        (committed; scripts/check-generated fails when it is stale)
#   make compile-matrix  tests/compile/matrix: dist/hybriddiff.h as C99 and C++17, gcc and clang,
#                        every backend, STATIC, two units, the #error cases, no GPU header in the
#                        declarations (part of `make test`)
#   make dist-builds     the examples and every backend's conformance suite built from
#                        dist/hybriddiff.h (-Idist ahead of -I.) into build/dist/, each conformance
#                        suite run (DIST_CONFORMANCE_ARGS, default --quick: one case per stage; the
#                        full suites run on the split layout) (part of `make test`)
.PHONY: dist compile-matrix dist-builds

dist:
	./amalgamate

# The matrix and the dist builds test the committed file: a stale one fails first, saying
# `make dist` (scripts/check-generated, whose target is in mk/opencl.mk).
compile-matrix: check-generated
	tests/compile/matrix

# The same rules as the development builds (Makefile, mk/*.mk), with the build directory, the
# include path and the library dependency pointed at dist: `#include "hybriddiff.h"` resolves to
# dist/hybriddiff.h, while the private test hooks (src/hd_test_hooks.h) still come from -I.
# Every examples/*.c and every $(B)/conformance-* program a fragment defines is built.
DIST_B := $(B)/dist
DIST_CONFORMANCE_ARGS ?= --quick
DIST_EXAMPLES := $(patsubst examples/%.c,$(DIST_B)/%,$(wildcard examples/*.c))
DIST_CONFORMANCE := $(addprefix $(DIST_B)/,$(shell sed -n 's/^\$$(B)\/\(conformance-[a-z0-9_]*\):.*/\1/p' $(wildcard mk/*.mk)))
# -O0: these builds prove that dist/hybriddiff.h builds and agrees (the quick conformance runs
# take seconds unoptimised); the split layout's -O3 builds of the same code carry the optimiser's
# warnings. Optimised, the CPU backend's flattened diffusion rows take about a minute per program.
DIST_CFLAGS ?= -O0 -g
DIST_MAKE := $(MAKE) --no-print-directory B=$(DIST_B) LIB_SRC=dist/hybriddiff.h \
             CPPFLAGS="-Idist $(CPPFLAGS)" CFLAGS="$(DIST_CFLAGS)"

dist-builds: check-generated
	$(DIST_MAKE) $(DIST_EXAMPLES) $(DIST_CONFORMANCE)
	@set -e; for p in $(DIST_CONFORMANCE); do echo "$$p $(DIST_CONFORMANCE_ARGS)"; $$p $(DIST_CONFORMANCE_ARGS); done

test: compile-matrix dist-builds
