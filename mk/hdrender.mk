# mk/hdrender.mk - hdrender, one binary per backend from examples/hdrender.c (the default build
# makes all four; `hdrender --backend B` runs build/hdrender-B), and their tests.
#   make hdrender-backends      build/hdrender (CPU), build/hdrender-opencl, -vulkan, -gl
#   make test-hdrender-backends each backend renders the head CT from the command line with one
#                               flag; the four PNGs must agree (part of `make test`)
#   make test-hdrender-defaults the histogram TF and camera on the MRI head give a lit image;
#                               a black image is warned about (part of `make test`)
#   make test-dicom             a DICOM series written from the head CT renders as the NRRD in
#                               hdrender and hdview; malformed series give their own errors
#                               (part of `make test`)
.PHONY: hdrender-backends test-hdrender-backends test-hdrender-defaults test-dicom

HDR_DEPS := examples/hdrender.c $(wildcard examples/*.h) $(LIB_SRC)
HDR_BACKENDS := $(B)/hdrender $(B)/hdrender-opencl $(B)/hdrender-vulkan $(B)/hdrender-gl
# DICOM series (a directory as input) through GDCM, in a C++ file of the tools (libgdcm-dev)
DICOM_CXXFLAGS := -std=c++17 -Wall -Wextra -Werror -Wpedantic -I/usr/include/gdcm-3.0
DICOM_LDLIBS := -lgdcmMSFF -lgdcmDICT -lgdcmDSED -lgdcmCommon -lstdc++

$(B)/hd_dicom.o: examples/hd_dicom.cpp examples/hd_dicom.h hybriddiff.h | $(B)
	$(CXX) $(CPPFLAGS) $(DICOM_CXXFLAGS) $(CFLAGS) -c $< -o $@

# each backend's object (the library's implementation is most of the compile), then the link
$(B)/hdrender.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender-opencl.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender-vulkan.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_VULKAN $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender-gl.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender: $(B)/hdrender.o $(B)/hd_dicom.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(DICOM_LDLIBS)
$(B)/hdrender-opencl: $(B)/hdrender-opencl.o $(B)/hd_dicom.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) -lOpenCL $(DICOM_LDLIBS)
$(B)/hdrender-vulkan: $(B)/hdrender-vulkan.o $(B)/hd_dicom.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) -lvulkan $(DICOM_LDLIBS)
$(B)/hdrender-gl: $(B)/hdrender-gl.o $(B)/hd_dicom.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) -lEGL $(DICOM_LDLIBS)

hdrender-backends: $(HDR_BACKENDS)
TEST_PROGRAMS += $(HDR_BACKENDS)
all: hdrender-backends

test-hdrender-backends: $(HDR_BACKENDS) $(B)/pngcmp data
	scripts/test-hdrender-backends $(B)

test-hdrender-defaults: $(B)/hdrender $(B)/pngcmp data
	scripts/test-hdrender-defaults $(B)

test-dicom: $(B)/hdrender $(B)/hdview $(B)/pngcmp data
	scripts/test-dicom $(B)

test: test-hdrender-backends test-hdrender-defaults test-dicom
