# mk/bench_project.mk - the projection's frame time per backend, old against new in one run.
#   make bench-project    bench/hdbench_project.c built twice per backend (CPU, OpenCL, GL,
#                         Vulkan): against this tree and against the tree of PROJECT_BASE (beee094,
#                         the march before its cell walk became a DDA; override to compare
#                         others),
#                         runs interleaved old/new per backend and size, on one light converged
#                         once (build/bench_project_light.f32); prints ms per frame and the PSNR
#                         of the new image against the old; PNGs in build/bench_project/.
#                         PROJECT_ARGS=--orbit: bench-peer's scene instead (ct-skin TF, its
#                         camera; light build/bench_project_light_orbit.f32).
PROJECT_BASE ?= beee094
PROJECT_OLD := $(B)/proj-old
PROJECT_BACKENDS := cpu opencl gl vulkan
PROJECT_DEF_cpu := -DHYBRIDDIFF_BACKEND_CPU
PROJECT_DEF_opencl := -DHYBRIDDIFF_BACKEND_OPENCL
PROJECT_DEF_gl := -DHYBRIDDIFF_BACKEND_GL
PROJECT_DEF_vulkan := -DHYBRIDDIFF_BACKEND_VULKAN
PROJECT_LIB_cpu :=
PROJECT_LIB_opencl := -lOpenCL
PROJECT_LIB_gl := -lEGL
PROJECT_LIB_vulkan := -lvulkan
PROJECT_ITERS ?= 24
PROJECT_SIZES ?= 512 1024
PROJECT_REPS ?= 2
PROJECT_FRAMES ?= 5

.PHONY: bench-project

$(B)/hdbench_project_%: bench/hdbench_project.c bench/hd_bench_median.h bench/hd_orbit_scene.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples $(PROJECT_DEF_$*) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(PROJECT_LIB_$*)

$(PROJECT_OLD)/.stamp: | $(B)
	rm -rf $(PROJECT_OLD) && mkdir -p $(PROJECT_OLD)
	git archive $(PROJECT_BASE) | tar -x -C $(PROJECT_OLD)
	touch $@

$(B)/hdbench_project_old_%: bench/hdbench_project.c bench/hd_bench_median.h bench/hd_orbit_scene.h $(PROJECT_OLD)/.stamp
	$(CC) -I$(PROJECT_OLD) -Iexamples -D_POSIX_C_SOURCE=200809L $(PROJECT_DEF_$*) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(PROJECT_LIB_$*)

PROJECT_ARGS ?=
PROJECT_LIGHT := $(B)/bench_project_light$(if $(findstring --orbit,$(PROJECT_ARGS)),_orbit).f32
$(PROJECT_LIGHT): | $(B)/hdbench_project_cpu data
	$(B)/hdbench_project_cpu $(PROJECT_ARGS) --make-light $@ $(PROJECT_ITERS)

bench-project: $(foreach b,$(PROJECT_BACKENDS),$(B)/hdbench_project_$(b) $(B)/hdbench_project_old_$(b)) $(PROJECT_LIGHT)
	@mkdir -p $(B)/bench_project
	@for size in $(PROJECT_SIZES); do for be in $(PROJECT_BACKENDS); do for rep in $$(seq $(PROJECT_REPS)); do \
	  o=$(B)/bench_project/$$be-$$size; \
	  $(B)/hdbench_project_old_$$be $(PROJECT_ARGS) --tag old --size $$size --frames $(PROJECT_FRAMES) --save $$o-old.f32 --png $$o-old.png || exit 1; \
	  $(B)/hdbench_project_$$be $(PROJECT_ARGS) --tag new --size $$size --frames $(PROJECT_FRAMES) --compare $$o-old.f32 --png $$o-new.png || exit 1; \
	done; done; done
