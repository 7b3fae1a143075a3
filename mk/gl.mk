# mk/gl.mk - the OpenGL backend: the conformance suite against the CPU reference (headless EGL,
# no X), its own tests (host state survives, render to texture, shader errors), the C++17 compile
# check, the viewer and its test under Xvfb, and the GL benchmark.
#   make conformance-gl     tests/conformance on GL (part of `make test`)
#   make test-gl            tests/gl/test_gl.c (part of `make test`)
#   make compile-gl-cxx     the GL implementation as C++17, warnings as errors (part of `make test`)
#   make hdview             build/hdview, the interactive viewer (examples/hdview.c, GLFW)
#   make test-hdview        hdview under xvfb-run for a fixed number of frames: screenshot checks
#   make bench-gl           build/hdbench_gl on the head CT (make data)
# Headless EGL: EGL_MESA_platform_surfaceless (Mesa), else EGL_EXT_platform_device.
GL_LDLIBS := -lEGL
GL_CONF := tests/conformance
GL_DEPS := $(GL_CONF)/hd_api.h src/hd_test_hooks.h $(LIB_SRC)
GL_CXXWARN := -std=c++17 -Wall -Wextra -Werror -Wpedantic

.PHONY: conformance-gl test-gl compile-gl-cxx hdview test-hdview bench-gl

$(B)/conf_impl_gl.o: $(GL_CONF)/impl_backend.c $(GL_DEPS) | $(B)
	$(CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(WARN) $(CFLAGS) -c $< -o $@
$(B)/conf_impl_cpu_gl.o: $(GL_CONF)/impl_cpu.c $(GL_DEPS) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/conformance_gl.o: $(GL_CONF)/conformance.c $(GL_CONF)/hd_api.h hybriddiff.h | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) -c $< -o $@
$(B)/conformance-gl: $(B)/conformance_gl.o $(B)/conf_impl_cpu_gl.o $(B)/conf_impl_gl.o
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS) $(GL_LDLIBS)

conformance-gl: $(B)/conformance-gl
	$(B)/conformance-gl

$(B)/test_gl: tests/gl/test_gl.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS) $(GL_LDLIBS) -lOpenGL

test-gl: $(B)/test_gl
	$(B)/test_gl

compile-gl-cxx: | $(B)
	$(CXX) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_GL $(GL_CXXWARN) -O1 -x c++ -c $(GL_CONF)/impl_backend.c -o $(B)/conf_impl_gl_cxx.o

test: conformance-gl test-gl compile-gl-cxx
