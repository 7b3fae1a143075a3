# mk/bench_direct.mk - HD's direct-light stage per backend: tracked only where E is read against
# every voxel, in one process (bench/hdbench_direct.c, figures in docs/DESIGN-DIRECT.md).
#   make bench-direct    build/hdbench_direct_{cpu,opencl,gl,vulkan} on the head CT, full grid,
#                        ct-skin and ct-bone TFs; DIRECT_ITERS passes per block, DIRECT_REPS blocks
#   make bench-mask      build/hdbench_mask: the direct light's mask build time, head CT, ct-skin
#                        and ct-bone, grid /1 and /2, with a hash of the tracked set
#   make bench-rays      build/hdbench_rays: ratio against delta tracking for the direct light (cost,
#                        noise, efficiency), CPU, head CT, default grid; RAYS_ARGS (--passes, --reps)
DIRECT_BACKENDS := cpu opencl gl vulkan
DIRECT_DEF_cpu := -DHYBRIDDIFF_BACKEND_CPU
DIRECT_DEF_opencl := -DHYBRIDDIFF_BACKEND_OPENCL
DIRECT_DEF_gl := -DHYBRIDDIFF_BACKEND_GL
DIRECT_DEF_vulkan := -DHYBRIDDIFF_BACKEND_VULKAN
DIRECT_LIB_cpu :=
DIRECT_LIB_opencl := -lOpenCL
DIRECT_LIB_gl := -lEGL
DIRECT_LIB_vulkan := -lvulkan
DIRECT_ITERS ?= 4
DIRECT_REPS ?= 3

RAYS_ARGS ?= --passes 4 --reps 5

.PHONY: bench-direct bench-rays bench-mask

$(B)/hdbench_direct_%: bench/hdbench_direct.c bench/hd_bench_median.h examples/hd_tf.h $(LIB_SRC) src/hd_test_hooks.h | $(B)
	$(CC) $(CPPFLAGS) $(DIRECT_DEF_$*) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(DIRECT_LIB_$*)

bench-direct: $(foreach b,$(DIRECT_BACKENDS),$(B)/hdbench_direct_$(b)) data
	@for be in $(DIRECT_BACKENDS); do $(B)/hdbench_direct_$$be --iters $(DIRECT_ITERS) --reps $(DIRECT_REPS) data/head.nrrd || exit 1; done

$(B)/hdbench_rays: bench/hdbench_rays.c bench/hd_bench_median.h examples/hd_tf.h $(LIB_SRC) src/hd_test_hooks.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-rays: $(B)/hdbench_rays data
	$(B)/hdbench_rays $(RAYS_ARGS) data/head.nrrd

$(B)/hdbench_mask: bench/hdbench_mask.c bench/hd_bench_median.h examples/hd_tf.h $(LIB_SRC) src/hd_test_hooks.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-mask: $(B)/hdbench_mask data
	$(B)/hdbench_mask data/head.nrrd
