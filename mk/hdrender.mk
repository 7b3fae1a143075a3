# mk/hdrender.mk - hdrender, one binary per backend from examples/hdrender.c (the default build
# makes all four; `hdrender --backend B` runs build/hdrender-B), and their tests.
#   make hdrender-backends      build/hdrender (CPU), build/hdrender-opencl, -vulkan, -gl
#   make test-hdrender-backends each backend renders the head CT from the command line with one
#                               flag; the four PNGs must agree (part of `make test`)
#   make test-hdrender-defaults the histogram TF and camera on the MRI head give a lit image;
#                               a black image is warned about (part of `make test`)
.PHONY: hdrender-backends test-hdrender-backends test-hdrender-defaults

HDR_DEPS := examples/hdrender.c $(wildcard examples/*.h) $(LIB_SRC)
HDR_BACKENDS := $(B)/hdrender $(B)/hdrender-opencl $(B)/hdrender-vulkan $(B)/hdrender-gl

$(B)/hdrender: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
$(B)/hdrender-opencl: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lOpenCL
$(B)/hdrender-vulkan: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_VULKAN $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lvulkan
$(B)/hdrender-gl: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) -lEGL

hdrender-backends: $(HDR_BACKENDS)
all: hdrender-backends

test-hdrender-backends: $(HDR_BACKENDS) $(B)/pngcmp data
	scripts/test-hdrender-backends $(B)

test-hdrender-defaults: $(B)/hdrender $(B)/pngcmp data
	scripts/test-hdrender-defaults $(B)

test: test-hdrender-backends test-hdrender-defaults
