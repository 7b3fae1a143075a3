# mk/opencl.mk - the OpenCL backend: the conformance suite against the CPU reference, the
# C++17 compile check of the backend, the generated-file check and the OpenCL benchmark.
#   make conformance-opencl   build and run tests/conformance on OpenCL (part of `make test`)
#   make compile-opencl-cxx   the OpenCL implementation compiled as C++17, warnings as errors
#   make check-generated      the generated files are up to date with their sources, and the
#                             implementation leaves no macro defined (scripts/check-generated)
#   make bench-opencl         build/hdbench_opencl: OpenCL vs CPU figures in one run
#   make valgrind-opencl      the quick conformance subset under valgrind (PoCL suppressed)
#   make physics-opencl       tests/physics on OpenCL (part of `make test`; mk/physics.mk)
#   make test-opencl          tests/opencl: the backend's own checks (the host's cl_mem depth; part of `make test`)
CL_LDLIBS := -lOpenCL
CONF_DIR := tests/conformance
CONF_DEPS := $(CONF_DIR)/hd_api.h $(CONF_DIR)/hd_probe_vk.h src/hd_test_hooks.h $(LIB_SRC)
CXXWARN := -std=c++17 -Wall -Wextra -Werror -Wpedantic

.PHONY: conformance-opencl compile-opencl-cxx check-generated bench-opencl valgrind-opencl physics-opencl

$(B)/conf_impl_cpu.o: $(CONF_DIR)/impl_cpu.c $(CONF_DEPS) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/conf_impl_opencl.o: $(CONF_DIR)/impl_backend.c $(CONF_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(CFLAGS) -c $< -o $@
$(B)/conformance.o: $(CONF_DIR)/conformance.c $(CONF_DIR)/hd_api.h hybriddiff.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/conformance-opencl: $(B)/conformance.o $(B)/conf_impl_cpu.o $(B)/conf_impl_opencl.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(CL_LDLIBS)

conformance-opencl: $(B)/conformance-opencl check-generated
	$(B)/conformance-opencl

$(B)/physics-opencl: $(B)/physics.o $(B)/conf_impl_opencl.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(CL_LDLIBS)

physics-opencl: $(B)/physics-opencl
	$(B)/physics-opencl

# The backend, the test hooks and the conformance tables as C++17 (stb-style headers must be).
compile-opencl-cxx: | $(B)
	$(CXX) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(CXXWARN) -O1 -x c++ -c $(CONF_DIR)/impl_backend.c -o $(B)/conf_impl_opencl_cxx.o
	$(CXX) $(CPPFLAGS) $(CXXWARN) -O1 -x c++ -c $(CONF_DIR)/impl_cpu.c -o $(B)/conf_impl_cpu_cxx.o
	$(CXX) $(CPPFLAGS) $(CXXWARN) -O1 -x c++ -c $(CONF_DIR)/conformance.c -o $(B)/conformance_cxx.o

check-generated:
	scripts/check-generated

# The bench is its own OpenCL implementation unit (its experiments reach the backend's buffers).
$(B)/hdbench_opencl: bench/hdbench_opencl.c bench/hdbench_triad.h $(B)/conf_impl_cpu.o $(CONF_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -I$(CONF_DIR) $(WARN) $(CFLAGS) bench/hdbench_opencl.c $(B)/conf_impl_cpu.o -o $@ $(LDLIBS) $(CL_LDLIBS)

# Memcheck on the quick subset; PoCL's and LLVM's own leaks are suppressed (see the .supp).
valgrind-opencl: $(B)/conformance-opencl
	valgrind --error-exitcode=9 --leak-check=full --suppressions=$(CONF_DIR)/valgrind-pocl.supp $(B)/conformance-opencl --quick

bench-opencl: $(B)/hdbench_opencl
	$(B)/hdbench_opencl

$(B)/test_opencl: tests/opencl/test_opencl.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(CL_LDLIBS)
.PHONY: test-opencl
test-opencl: $(B)/test_opencl
	$(B)/test_opencl

TEST_PROGRAMS += $(B)/conformance-opencl $(B)/physics-opencl $(B)/test_opencl
test: conformance-opencl compile-opencl-cxx physics-opencl test-opencl
