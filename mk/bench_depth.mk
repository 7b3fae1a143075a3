# mk/bench_depth.mk - what depth in (hd_set_depth) and depth out (the depth plane hd_read_depth
# reads) cost a frame, per backend.
#   make bench-depth    build/hdbench_depth_{cpu,gl,vulkan} on the head CT at DEPTH_SIZE: plain
#                       frames against frames without the depth plane's write (depth out), with a
#                       depth buffer of far values (depth in's overhead) and with a wall over half
#                       the image (bench/hdbench_depth.c; docs/PERFORMANCE.md)
DEPTH_BACKENDS ?= cpu gl vulkan
DEPTH_DEF_cpu := -DHYBRIDDIFF_BACKEND_CPU
DEPTH_DEF_opencl := -DHYBRIDDIFF_BACKEND_OPENCL
DEPTH_DEF_gl := -DHYBRIDDIFF_BACKEND_GL
DEPTH_DEF_vulkan := -DHYBRIDDIFF_BACKEND_VULKAN
DEPTH_LIB_cpu :=
DEPTH_LIB_opencl := -lOpenCL
DEPTH_LIB_gl := -lEGL
DEPTH_LIB_vulkan := -lvulkan
DEPTH_SIZE ?= 1280x720
DEPTH_FRAMES ?= 7

.PHONY: bench-depth

$(B)/hdbench_depth_%: bench/hdbench_depth.c bench/hd_bench_median.h $(LIB_SRC) src/hd_test_hooks.h | $(B)
	$(CC) $(CPPFLAGS) $(DEPTH_DEF_$*) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(DEPTH_LIB_$*)

bench-depth: $(foreach b,$(DEPTH_BACKENDS),$(B)/hdbench_depth_$(b)) data
	@for be in $(DEPTH_BACKENDS); do $(B)/hdbench_depth_$$be --size $(DEPTH_SIZE) --frames $(DEPTH_FRAMES) data/head.nrrd || exit 1; done
