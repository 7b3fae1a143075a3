# mk/bench_output.mk - frames over converged light, with their output, per backend (not part of
# `make test`; figures in docs/PERFORMANCE.md, "Frames over converged light and their output").
#   make bench-output   bench/hdbench_output.c on CPU, OpenCL, GL and Vulkan: the head CT at
#                       OUTPUT_SIZE (1280x720), HD's light converged by hd_render, then
#                       OUTPUT_FRAMES camera moves, each the projection alone and its output:
#                       hd_read_image_ex (LINEAR_F16, SRGB8), hd_gl_render_to_texture_ex into a
#                       GL_RGBA16F texture, hd_vulkan_record_render into a VkImage. ms per frame.
.PHONY: bench-output
OUTPUT_BACKENDS ?= cpu opencl gl vulkan
OUTPUT_SIZE ?= 1280x720
OUTPUT_FRAMES ?= 10
OUTPUT_DEF_cpu := -DHYBRIDDIFF_BACKEND_CPU
OUTPUT_DEF_opencl := -DHYBRIDDIFF_BACKEND_OPENCL
OUTPUT_DEF_gl := -DHYBRIDDIFF_BACKEND_GL
OUTPUT_DEF_vulkan := -DHYBRIDDIFF_BACKEND_VULKAN
OUTPUT_LIB_cpu :=
OUTPUT_LIB_opencl := -lOpenCL
OUTPUT_LIB_gl := -lEGL -lOpenGL
OUTPUT_LIB_vulkan := -lvulkan

$(B)/hdbench_output_%: bench/hdbench_output.c bench/hd_bench_median.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(OUTPUT_DEF_$*) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(OUTPUT_LIB_$*)

bench-output: $(patsubst %,$(B)/hdbench_output_%,$(OUTPUT_BACKENDS)) data
	@for be in $(OUTPUT_BACKENDS); do $(B)/hdbench_output_$$be --size $(OUTPUT_SIZE) --frames $(OUTPUT_FRAMES) || exit 1; done
