# mk/vulkan.mk - the Vulkan backend: the conformance suite against the CPU reference (plain and
# under the validation layer), its own tests, the C++17 compile check, the SPIR-V freshness check
# and the Vulkan benchmark.
#   make conformance-vulkan             tests/conformance on Vulkan (part of `make test`)
#   make conformance-vulkan-validation  the same under VK_LAYER_KHRONOS_validation + sync
#                                       validation; fails on any message (part of `make test`)
#   make test-vulkan                    tests/vulkan: messenger fires, caller-owned device and
#                                       recording, out-of-device-memory and destroy
#   make compile-vulkan-cxx             the Vulkan implementation as C++17, warnings as errors
#   make physics-vulkan                 tests/physics on Vulkan (part of `make test`; mk/physics.mk)
#   make bench-vulkan                   build/hdbench_vulkan on the head CT (make data): the
#                                       sweep against a plain stencil (image3D, SSBO, C), then
#                                       it/s per method; BENCH_ARGS=--sweeps for the first part,
#                                       --variants for bench/hdbench_sweep.comp's cost breakdown,
#                                       --ab FILE.spv [--ab-zk n] to A/B a diffusion module
#   make bench-vulkan-multigrid         build/hdbench_mg_vulkan on the head CT: ms per
#                                       HD_SOLVER_MULTIGRID step, Vulkan against the CPU in one
#                                       process (interleaved rounds), grid /1 and /2, box and
#                                       surface boundary (BENCH_ARGS: --rounds, --steps, --downsample)
# Lavapipe on a machine with a GPU: VK_DRIVER_FILES=/usr/share/vulkan/icd.d/lvp_icd.x86_64.json
VK_LDLIBS := -lvulkan
VK_CONF := tests/conformance
VK_DEPS := $(VK_CONF)/hd_api.h $(VK_CONF)/hd_probe_vk.h src/hd_test_hooks.h $(LIB_SRC)
VK_CXXWARN := -std=c++17 -Wall -Wextra -Werror -Wpedantic

.PHONY: conformance-vulkan conformance-vulkan-validation test-vulkan compile-vulkan-cxx bench-vulkan bench-vulkan-multigrid physics-vulkan

$(B)/conf_impl_vk.o: $(VK_CONF)/impl_vk.c $(VK_DEPS) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
# The driver and the CPU reference are the OpenCL suite's objects (mk/opencl.mk): one compile each.
$(B)/conformance-vulkan: $(B)/conformance.o $(B)/conf_impl_cpu.o $(B)/conf_impl_vk.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(VK_LDLIBS)

conformance-vulkan: $(B)/conformance-vulkan
	$(B)/conformance-vulkan

conformance-vulkan-validation: $(B)/conformance-vulkan
	HD_VK_VALIDATION=1 $(B)/conformance-vulkan

$(B)/physics-vulkan: $(B)/physics.o $(B)/conf_impl_vk.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(VK_LDLIBS)

physics-vulkan: $(B)/physics-vulkan
	$(B)/physics-vulkan

$(B)/test_vulkan: tests/vulkan/test_vulkan.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(VK_LDLIBS)

test-vulkan: $(B)/test_vulkan
	$(B)/test_vulkan

compile-vulkan-cxx: | $(B)
	$(CXX) $(CPPFLAGS) $(VK_CXXWARN) -O1 -x c++ -c $(VK_CONF)/impl_vk.c -o $(B)/conf_impl_vk_cxx.o

# the benchmark's own stencil shaders, compiled here (glslangValidator) rather than committed
$(B)/hdbench_vulkan_spirv.h: bench/hdbench_stencil.comp bench/hdbench_sweep.comp scripts/build-spirv | $(B)
	scripts/build-spirv --bench $@

$(B)/hdbench_vulkan: bench/hdbench_vulkan.c $(B)/hdbench_vulkan_spirv.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -I$(B) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(VK_LDLIBS)

bench-vulkan: $(B)/hdbench_vulkan data
	$(B)/hdbench_vulkan data/head.nrrd 2 $(BENCH_ARGS)

$(B)/hdbench_mg_vulkan.o: bench/hdbench_mg_vulkan.c bench/hd_bench_median.h examples/hd_tf.h $(VK_CONF)/hd_api.h hybriddiff.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdbench_mg_vulkan: $(B)/hdbench_mg_vulkan.o $(B)/conf_impl_cpu.o $(B)/conf_impl_vk.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(VK_LDLIBS)

bench-vulkan-multigrid: $(B)/hdbench_mg_vulkan data
	$(B)/hdbench_mg_vulkan data/head.nrrd $(BENCH_ARGS)

TEST_PROGRAMS += $(B)/conformance-vulkan $(B)/test_vulkan $(B)/physics-vulkan
test: conformance-vulkan conformance-vulkan-validation test-vulkan compile-vulkan-cxx physics-vulkan
