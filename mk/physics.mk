# mk/physics.mk - tests/physics: each backend against closed forms of the method's equations
# (direct light, the thin slab's image, the diffusion's grid Green's function), through the
# public API; the shared kernels' bugs that the conformance suite cannot see (it compares with
# the CPU, which runs the same kernels). One program per backend, linked with the conformance
# suite's implementation objects; the GPU ones are in mk/opencl.mk, mk/vulkan.mk, mk/gl.mk.
#   make physics-cpu      build/physics-cpu (part of `make test`)
#   make physics          every backend's (cpu, opencl, vulkan, gl)
#   make mutation-test    scripts/mutation-test: each known mutation of the library applied to a
#                         copy of the tree, rebuilt, and the suite that must catch it run; fails
#                         if one survives (not part of `make test`; docs/TESTING.md)
PHYS_DIR := tests/physics
.PHONY: physics physics-cpu mutation-test

$(B)/physics.o: $(PHYS_DIR)/physics.c tests/conformance/hd_api.h hybriddiff.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/physics_cpu.o: $(PHYS_DIR)/physics.c tests/conformance/hd_api.h hybriddiff.h | $(B)
	$(CC) $(CPPFLAGS) -DHD_PHYS_API=hd_api_cpu -DHD_PHYS_CPU $(WARN) $(CFLAGS) -c $< -o $@
$(B)/physics-cpu: $(B)/physics_cpu.o $(B)/conf_impl_cpu.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS)

physics-cpu: $(B)/physics-cpu
	$(B)/physics-cpu

physics: physics-cpu physics-opencl physics-vulkan physics-gl

mutation-test:
	scripts/mutation-test $(MUTATIONS)

TEST_PROGRAMS += $(B)/physics-cpu
test: physics-cpu
