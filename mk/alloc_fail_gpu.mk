# mk/alloc_fail_gpu.mk - resource failure on a GPU backend (OpenCL on PoCL), part of `make test`:
#   make alloc-fail-opencl   tests/test_alloc_fail.c on the OpenCL backend: every k-th host
#                            allocation failed once over create/HD/CD/PT/read/destroy
#   make device-oom-opencl   POCL_MEMORY_LIMIT=1 (GiB) and a 512^3 volume: the device allocation
#                            fails with HD_ERROR_OUT_OF_DEVICE_MEMORY and the context destroys
# Both reuse tests/test_main.c with a suite list of their own (tests/alloc_fail/suites-*.h).
AFG := $(B)/afgpu
.PHONY: alloc-fail-opencl device-oom-opencl

$(AFG):
	mkdir -p $(AFG)/af $(AFG)/oom
$(AFG)/af/hd_suites.h: | $(AFG)
	echo 'X(alloc_fail)' > $@
$(AFG)/oom/hd_suites.h: | $(AFG)
	echo 'X(device_oom)' > $@
$(AFG)/impl_opencl.o: tests/alloc_fail/impl.c $(LIB_SRC) | $(AFG)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(CFLAGS) -c $< -o $@
$(AFG)/alloc-fail-opencl: tests/test_main.c tests/test_alloc_fail.c $(AFG)/impl_opencl.o $(AFG)/af/hd_suites.h tests/hd_test.h
	$(CC) $(CPPFLAGS) -I$(AFG)/af -Itests $(WARN) $(CFLAGS) tests/test_main.c tests/test_alloc_fail.c $(AFG)/impl_opencl.o -o $@ $(LDLIBS) -lOpenCL
$(AFG)/device-oom-opencl: tests/test_main.c tests/alloc_fail/device_oom.c $(AFG)/impl_opencl.o $(AFG)/oom/hd_suites.h tests/hd_test.h
	$(CC) $(CPPFLAGS) -I$(AFG)/oom -Itests $(WARN) $(CFLAGS) tests/test_main.c tests/alloc_fail/device_oom.c $(AFG)/impl_opencl.o -o $@ $(LDLIBS) -lOpenCL

alloc-fail-opencl: $(AFG)/alloc-fail-opencl
	$(AFG)/alloc-fail-opencl
device-oom-opencl: $(AFG)/device-oom-opencl
	POCL_MEMORY_LIMIT=1 $(AFG)/device-oom-opencl

TEST_PROGRAMS += $(AFG)/alloc-fail-opencl $(AFG)/device-oom-opencl
test: alloc-fail-opencl device-oom-opencl
