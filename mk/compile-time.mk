# mk/compile-time.mk - how long the library takes to compile (not part of `make test`).
#   make compile-time    scripts/compile-time: CPU seconds (user + sys, median of
#                        COMPILE_TIME_REPS interleaved runs) and peak memory to compile each
#                        backend's implementation TU (CPU, also under HYBRIDDIFF_FAST_COMPILE;
#                        OpenCL, Vulkan, GL) with COMPILE_TIME_FLAGS, and the ratio to
#                        stb_image.h's implementation (Debian libstb-dev) compiled in the same run;
#                        figures in docs/PERFORMANCE.md, "Compile time". COMPILE_TIME_ARGS adds
#                        e.g. "--also DIR": the CPU TU of another checkout in the same run
.PHONY: compile-time
COMPILE_TIME_FLAGS ?= -O2
COMPILE_TIME_REPS ?= 3
COMPILE_TIME_ARGS ?=

compile-time:
	CC="$(CC)" scripts/compile-time --flags "$(COMPILE_TIME_FLAGS)" --reps $(COMPILE_TIME_REPS) $(COMPILE_TIME_ARGS)
