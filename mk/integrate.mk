# mk/integrate.mk - the integration programs (examples/integrate_*), as an application writes them
# from README.md and docs/INTEGRATION.md: each built with plain -std=c99 (and as C++17) with
# -Wall -Wextra -Wpedantic -Werror and no feature macro, hybriddiff.h included before and after
# the system headers (-DINTEGRATE_HD_LAST); one variant of each is built and run (part of
# `make test`; ~25 s of CPU, builds included).
#   make integrate          build all and run them (the GLFW one under xvfb-run -a, GLX context)
#   make readme-check       every code block of README.md compiled as C99 and C++17 and run
#                           (scripts/readme-check)
IB := $(B)/integrate
INT_WARN := -Wall -Wextra -Wpedantic -Werror -I.
INT_C99 := $(CC) -std=c99 $(INT_WARN) -O0
INT_CXX := $(CXX) -std=c++17 $(INT_WARN) -O0
INT_LIBS := -lm -lpthread -lz
INT_LIB_vulkan := -lvulkan
INT_LIB_opencl := -lOpenCL
INT_LIB_contexts :=
INT_ONE := vulkan opencl contexts

.PHONY: integrate integrate-compile readme-check

$(IB):
	mkdir -p $@

# The programs that run: C99 (the .cpp ones C++17), hybriddiff.h first, -O0 (a build is ~2 s).
$(IB)/%: examples/integrate_%.c $(LIB_SRC) | $(IB)
	$(INT_C99) $< -o $@ $(INT_LIBS) $(INT_LIB_$*)
$(IB)/units: examples/integrate_units.c examples/integrate_units_cxx.cpp $(LIB_SRC) | $(IB)
	$(INT_C99) -c examples/integrate_units.c -o $@.o
	$(INT_CXX) -c examples/integrate_units_cxx.cpp -o $@.cxx.o
	$(CXX) $@.o $@.cxx.o -o $@ $(INT_LIBS)
$(IB)/glfw: examples/integrate_glfw.cpp $(LIB_SRC) | $(IB)
	$(INT_CXX) $< -o $@ $(INT_LIBS) -lglfw -lOpenGL -lEGL

# The other language and include order of each: compiled only (-fsyntax-only, ~0.2 s each); then
# the implementation after each system header whose feature set strict C99 would otherwise narrow.
INT_FIRST := unistd.h fcntl.h sys/stat.h stdlib.h stdio.h time.h pthread.h
integrate-compile:
	@set -e; for p in $(INT_ONE) units; do f=examples/integrate_$$p.c; \
	  $(CC) -std=c99 $(INT_WARN) -fsyntax-only -DINTEGRATE_HD_LAST $$f; \
	  $(CXX) -std=c++17 $(INT_WARN) -fsyntax-only -x c++ $$f; \
	  $(CXX) -std=c++17 $(INT_WARN) -fsyntax-only -x c++ -DINTEGRATE_HD_LAST $$f; done; \
	$(CXX) -std=c++17 $(INT_WARN) -fsyntax-only -DINTEGRATE_HD_LAST examples/integrate_glfw.cpp; \
	echo "integrate-compile: 13 language/include-order variants compile warning-free"; \
	for h in $(INT_FIRST); do for b in CPU OPENCL VULKAN GL; do \
	  printf '#include <%s>\n#define HYBRIDDIFF_IMPLEMENTATION\n#define HYBRIDDIFF_BACKEND_%s\n#include "hybriddiff.h"\n' \
	    $$h $$b | $(CC) -std=c99 $(INT_WARN) -fsyntax-only -x c -; done; done; \
	echo "integrate-compile: the implementation after each of $(INT_FIRST), strict C99, every backend"

# `make dist-builds` builds every examples/*.c as a program of its own from dist/hybriddiff.h.
$(B)/integrate_%: examples/integrate_%.c $(LIB_SRC) | $(B)
	$(INT_C99) $< -o $@ $(INT_LIBS) $(INT_LIB_$*)
$(B)/integrate_units: examples/integrate_units.c examples/integrate_units_cxx.cpp $(LIB_SRC) | $(B)
	$(INT_C99) -c examples/integrate_units.c -o $@.o
	$(INT_CXX) -c examples/integrate_units_cxx.cpp -o $@.cxx.o
	$(CXX) $@.o $@.cxx.o -o $@ $(INT_LIBS)

integrate: $(addprefix $(IB)/,$(INT_ONE) units glfw) integrate-compile
	@set -e; for p in $(INT_ONE) units; do $(IB)/$$p 2>$(IB)/$$p.log || { cat $(IB)/$$p.log; echo "integrate: $$p FAILED"; exit 1; }; done
	@xvfb-run -a $(IB)/glfw 2>$(IB)/glfw.log || { cat $(IB)/glfw.log; echo "integrate: glfw FAILED"; exit 1; }

readme-check: | $(B)
	scripts/readme-check README.md $(B)/readme

test: integrate readme-check
