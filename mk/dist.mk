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

# A release build from dist/hybriddiff.h (no HYBRIDDIFF_TESTING) keeps no test-only function and
# no fault-injection knob: each backend's implementation at -O0 (unused static functions are
# still emitted there), checked by nm and by the binary's strings (part of `make test`).
.PHONY: check-release
RELEASE_B := $(B)/release
check-release: check-generated
	@mkdir -p $(RELEASE_B); set -e; \
	for b in CPU OPENCL VULKAN GL; do \
	  printf '#define HYBRIDDIFF_IMPLEMENTATION\n#define HYBRIDDIFF_BACKEND_%s\n#include "hybriddiff.h"\n' $$b > $(RELEASE_B)/impl_$$b.c; \
	  $(CC) -Idist $(CPPFLAGS) $(WARN) -O0 -c $(RELEASE_B)/impl_$$b.c -o $(RELEASE_B)/impl_$$b.o; \
	  if nm $(RELEASE_B)/impl_$$b.o | grep -q write_illumination; then echo "check-release: $$b keeps a test hook"; exit 1; fi; \
	  if grep -q -a 'HD_VK_LOSE_DEVICE\|HD_VK_MEMORY_LIMIT\|HD_VK_NO_HALF' $(RELEASE_B)/impl_$$b.o; then \
	    echo "check-release: $$b keeps a fault-injection knob"; exit 1; fi; \
	  echo "check-release: $$b: no test hook, no fault injection"; \
	done
test: check-release
