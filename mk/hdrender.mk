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
#   make test-vdb               OpenVDB grids written by scripts/vdb-from-nrrd (the head CT, a
#                               sparse cloud) load and render as the same voxels in NRRD, placed
#                               by their transforms; damaged files give their own errors (part of
#                               `make test`)
#   make test-dicom-hostile     hostile DICOM folders (scripts/dicom-corpus): each case's exit and
#                               message, 60 junk files and 30 mutated slices beside a series, the
#                               files that abort GDCM contained; 5 s and 256 MiB per run (part of
#                               `make test`, ~10 s)
#   make dicom-hostile-long     the same with 1000 junk files and 1000 mutated slices, then GDCM
#                               alone on them (build/gdcm_probe: aborts, time, memory)
#   make dicom-dcmtk-probe      DCMTK alone on that corpus (needs libdcmtk-dev; docs/DICOM.md)
#   make test-hdrender-cli      FIFOs, /dev/full, numbers out of range, TF files at 1 MiB, NUL
#                               bytes (part of `make test`)
.PHONY: hdrender-backends test-hdrender-backends test-hdrender-defaults test-dicom test-vdb test-dicom-hostile \
        dicom-hostile-long dicom-dcmtk-probe test-hdrender-cli

HDR_DEPS := examples/hdrender.c $(wildcard examples/*.h) $(LIB_SRC)
HDR_BACKENDS := $(B)/hdrender $(B)/hdrender-opencl $(B)/hdrender-vulkan $(B)/hdrender-gl
# DICOM series (a directory as input) through GDCM, in a C++ file of the tools (libgdcm-dev)
DICOM_CXXFLAGS := -std=c++17 -Wall -Wextra -Werror -Wpedantic -I/usr/include/gdcm-3.0
DICOM_LDLIBS := -lgdcmMSFF -lgdcmDICT -lgdcmDSED -lgdcmCommon -lstdc++

$(B)/hd_dicom.o: examples/hd_dicom.cpp examples/hd_dicom.h examples/hd_pipe.h hybriddiff.h | $(B)
	$(CXX) $(CPPFLAGS) $(DICOM_CXXFLAGS) $(CFLAGS) -c $< -o $@
# OpenVDB grids (FILE.vdb) through libopenvdb-dev, in another C++ file of the tools
$(B)/hd_vdb.o: examples/hd_vdb.cpp examples/hd_vdb.h examples/hd_pipe.h hybriddiff.h | $(B)
	$(CXX) $(CPPFLAGS) -std=c++17 -Wall -Wextra -Werror -Wpedantic $(CFLAGS) -c $< -o $@

# each backend's object (the library's implementation is most of the compile), then the link
$(B)/hdrender.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender-opencl.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender-vulkan.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_VULKAN $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender-gl.o: $(HDR_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(WARN) $(CFLAGS) -c $< -o $@
$(B)/hdrender: $(B)/hdrender.o $(TOOL_OBJS)
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(TOOL_LDLIBS)
$(B)/hdrender-opencl: $(B)/hdrender-opencl.o $(TOOL_OBJS)
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) -lOpenCL $(TOOL_LDLIBS)
$(B)/hdrender-vulkan: $(B)/hdrender-vulkan.o $(TOOL_OBJS)
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) -lvulkan $(TOOL_LDLIBS)
$(B)/hdrender-gl: $(B)/hdrender-gl.o $(TOOL_OBJS)
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) -lEGL $(TOOL_LDLIBS)

# the DICOM reader's tests: hdrender with the VR check off, so that GDCM's asserts on the files
# of tests/dicom/gdcm-aborts reach the worker; gdcm_probe, GDCM alone on a corpus
$(B)/hd_dicom_novrcheck.o: examples/hd_dicom.cpp examples/hd_dicom.h examples/hd_pipe.h hybriddiff.h | $(B)
	$(CXX) $(CPPFLAGS) -DHDX_DICOM_TEST_NO_VR_CHECK $(DICOM_CXXFLAGS) $(CFLAGS) -c $< -o $@
$(B)/hdrender_novrcheck: $(B)/hdrender.o $(B)/hd_dicom_novrcheck.o $(B)/hd_vdb.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(TOOL_LDLIBS)
$(B)/gdcm_probe: tests/dicom/gdcm_probe.cpp examples/hd_dicom.cpp examples/hd_dicom.h examples/hd_pipe.h hybriddiff.h | $(B)
	$(CXX) $(CPPFLAGS) $(DICOM_CXXFLAGS) $(CFLAGS) $< -o $@ $(DICOM_LDLIBS)

hdrender-backends: $(HDR_BACKENDS)
TEST_PROGRAMS += $(HDR_BACKENDS) $(B)/hdrender_novrcheck
all: hdrender-backends

test-hdrender-backends: $(HDR_BACKENDS) $(B)/pngcmp data
	scripts/test-hdrender-backends $(B)

test-hdrender-defaults: $(B)/hdrender $(B)/pngcmp data
	scripts/test-hdrender-defaults $(B)

test-dicom: $(B)/hdrender $(B)/hdview $(B)/pngcmp data
	scripts/test-dicom $(B)

# the OpenVDB reader alone (tests/vdb/test_vdb.c), then through hdrender and hdview
$(B)/test_vdb: tests/vdb/test_vdb.c $(B)/hd_vdb.o $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples $(WARN) $(CFLAGS) $< $(B)/hd_vdb.o -o $@ $(LDLIBS) $(VDB_LDLIBS) -lstdc++
test-vdb: $(B)/hdrender $(B)/hdview $(B)/pngcmp $(B)/test_vdb data
	scripts/test-vdb $(B)

test-dicom-hostile: $(B)/hdrender $(B)/hdrender_novrcheck
	scripts/test-dicom-hostile $(B)

dicom-hostile-long: $(B)/hdrender $(B)/hdrender_novrcheck $(B)/gdcm_probe
	scripts/test-dicom-hostile $(B) 1000 1000
	$(B)/gdcm_probe $(B)/dicom-hostile/corpus/junk/j* $(B)/dicom-hostile/corpus/mutated/*/m.dcm

# DCMTK alone on the same corpus, for docs/DICOM.md (after dicom-hostile-long; needs Debian's
# libdcmtk-dev, which the tools do not use)
DCMTK_LDLIBS := -ldcmjpls -ldcmjpeg -ldcmimgle -ldcmdata -lijg8 -lijg12 -lijg16 -ldcmtkcharls -loflog -lofstd
$(B)/dcmtk_probe: tests/dicom/dcmtk_probe.cpp | $(B)
	$(CXX) -std=c++17 -Wall -Wextra -Werror $(CFLAGS) $< -o $@ $(DCMTK_LDLIBS)
dicom-dcmtk-probe: $(B)/dcmtk_probe
	$(B)/dcmtk_probe $(B)/dicom-hostile/corpus/junk/j* $(B)/dicom-hostile/corpus/mutated/*/m.dcm

test-hdrender-cli: $(B)/hdrender
	scripts/test-hdrender-cli $(B)

test: test-hdrender-backends test-hdrender-defaults test-dicom test-vdb test-dicom-hostile test-hdrender-cli
