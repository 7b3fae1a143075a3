# mk/gl.mk - the OpenGL backend: the conformance suite against the CPU reference (headless EGL,
# no X), its own tests (host state survives, render to texture, shader errors), the C++17 compile
# check, the viewer and its test under Xvfb, and the GL benchmark.
#   make conformance-gl     tests/conformance on GL (part of `make test`)
#   make test-gl            tests/gl/test_gl.c (part of `make test`)
#   make compile-gl-cxx     the GL implementation as C++17, warnings as errors (part of `make test`)
#   make physics-gl         tests/physics on GL (part of `make test`; mk/physics.mk)
#   make hdview             build/hdview, the interactive viewer (examples/hdview.c, GLFW)
#   make test-hdview        hdview under xvfb-run for a fixed number of frames: screenshot checks
#   make bench-gl           build/hdbench_gl on the head CT (make data)
# Headless EGL: EGL_MESA_platform_surfaceless (Mesa), else EGL_EXT_platform_device.
GL_LDLIBS := -lEGL
GL_CONF := tests/conformance
GL_DEPS := $(GL_CONF)/hd_api.h $(GL_CONF)/hd_probe_vk.h src/hd_test_hooks.h $(LIB_SRC)
GL_CXXWARN := -std=c++17 -Wall -Wextra -Werror -Wpedantic

.PHONY: conformance-gl test-gl compile-gl-cxx hdview test-hdview bench-gl physics-gl

$(B)/conf_impl_gl.o: $(GL_CONF)/impl_backend.c $(GL_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(WARN) $(CFLAGS) -c $< -o $@
# The driver and the CPU reference are the OpenCL suite's objects (mk/opencl.mk): one compile each.
$(B)/conformance-gl: $(B)/conformance.o $(B)/conf_impl_cpu.o $(B)/conf_impl_gl.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(GL_LDLIBS)

conformance-gl: $(B)/conformance-gl
	$(B)/conformance-gl

$(B)/physics-gl: $(B)/physics.o $(B)/conf_impl_gl.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(GL_LDLIBS)

physics-gl: $(B)/physics-gl
	$(B)/physics-gl

$(B)/test_gl: tests/gl/test_gl.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(GL_LDLIBS) -lOpenGL

test-gl: $(B)/test_gl
	$(B)/test_gl

compile-gl-cxx: | $(B)
	$(CXX) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(GL_CXXWARN) -O1 -x c++ -c $(GL_CONF)/impl_backend.c -o $(B)/conf_impl_gl_cxx.o

TEST_PROGRAMS += $(B)/conformance-gl $(B)/test_gl $(B)/physics-gl
test: conformance-gl test-gl compile-gl-cxx physics-gl

# ---- the viewer -------------------------------------------------------------------------------
VIEW_LDLIBS := -lglfw -lOpenGL -lEGL
$(B)/hdview: examples/hdview.c $(wildcard examples/*.h) $(LIB_SRC) $(TOOL_OBJS) | $(B)
	$(CC) $(CPPFLAGS) -Iexamples $(WARN) $(CFLAGS) $< $(TOOL_OBJS) -o $@ $(LDLIBS) $(VIEW_LDLIBS) $(TOOL_LDLIBS)
hdview: $(B)/hdview

$(B)/pngcmp: tests/gl/pngcmp.c | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ -lm

# hdview under Xvfb: camera moves and the crop box keys (the x+ face moved in, logged, then the
# default box back), then a restart at the default camera and 4 frames; the screenshot must not
# be blank and must match hdrender on the CPU backend, same scene, seed and iterations
# (tests/gl/pngcmp.c: within 1/255 per channel, and why). 256x256 on the head CT.
# `data` first: make test (and so CI) fetches the head CT, so this test runs rather than skips
# (under HD_CONFORMANCE_REQUIRE=1 a skip fails).
test-hdview: $(B)/hdview $(B)/hdrender $(B)/pngcmp data
	@if [ ! -f data/head.nrrd ]; then echo "test-hdview SKIPPED: no data/head.nrrd (make data)"; \
	  [ "$${HD_CONFORMANCE_REQUIRE:-0}" != 1 ] || { echo "test-hdview: HD_CONFORMANCE_REQUIRE=1: a skip fails"; exit 1; }; exit 0; fi; \
	mkdir -p $(B)/gl && rm -f $(B)/gl/hdview.png $(B)/gl/hdview-moved.png $(B)/gl/hdview-orbit.png && \
	{ xvfb-run -a -s "-screen 0 640x480x24" $(B)/hdview --size 256x256 --script tests/gl/hdview.script data/head.nrrd \
	      2> $(B)/gl/hdview.log || { cat $(B)/gl/hdview.log; echo "test-hdview: hdview failed"; exit 1; }; } && \
	grep -v " info: " $(B)/gl/hdview.log; \
	{ grep -q "^hdview: crop box x 0.11-0.87 y 0.17-1.00 z 0.00-1.00" $(B)/gl/hdview.log || \
	  { echo "test-hdview: the crop box keys did not move the x+ face"; exit 1; }; } && \
	$(B)/hdrender --quiet --size 256x256 --iterations 4 -o $(B)/gl/hdrender-cpu.png data/head.nrrd && \
	$(B)/pngcmp --nonblank $(B)/gl/hdview-moved.png && \
	$(B)/pngcmp --nonblank $(B)/gl/hdview.png && \
	$(B)/pngcmp $(B)/gl/hdview.png $(B)/gl/hdrender-cpu.png
	@if [ -f data/head.nrrd ]; then \
	{ xvfb-run -a -s "-screen 0 640x480x24" $(B)/hdview --size 256x256 --script tests/gl/hdview-orbit.script data/head.nrrd \
	      2> $(B)/gl/hdview-orbit.log || { cat $(B)/gl/hdview-orbit.log; echo "test-hdview: hdview-orbit.script failed"; exit 1; }; } && \
	{ grep -v " info: " $(B)/gl/hdview-orbit.log || true; } && \
	$(B)/pngcmp --nonblank $(B)/gl/hdview-orbit.png; fi

TEST_PROGRAMS += $(B)/hdview $(B)/hdrender $(B)/pngcmp
test: test-hdview

$(B)/hdbench_gl: bench/hdbench_gl.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(GL_LDLIBS)

bench-gl: $(B)/hdbench_gl data
	$(B)/hdbench_gl
