# hybriddiff development build. `make test` builds and runs every test; `make help` lists every target.
CC      ?= cc
# -march=native: the CPU backend's diffusion rows vectorise (AVX-512 here: 3x the SSE rate); the
# binaries are built where they run. Valgrind builds override it (no AVX-512 in valgrind).
CFLAGS  ?= -O3 -march=native -g
WARN    := -std=c99 -Wall -Wextra -Werror -Wpedantic
CPPFLAGS := -I. -D_POSIX_C_SOURCE=200809L
LDLIBS  := -lm -lpthread -lz
B       := build

.PHONY: all test clean help data render bench bench-rb-schedule
all: $(B)/hdtest $(B)/hdrender $(B)/hdbench

help:
	@echo "building and running:"
	@echo "  make all                            build/hdtest, build/hdrender and build/hdbench"
	@echo "  make test                           every test (T below), serially or with -j2; ~15 min quiet on 2 cores (README)"
	@echo "  make check-all                      the same as make test"
	@echo "  make data                           fetch the head CT into data/ (Debian package invesalius-examples)"
	@echo "  make render                         fetch the data, build hdrender, render the head CT to out/head.png"
	@echo "  make hdview                         build/hdview, the GLFW viewer on the GL backend (needs a display)"
	@echo "  make scene                          build/scene, the host-scene example (GL, meshes, depth, a placed cloud) into out/scene.png"
	@echo "  make scene-vulkan                   build/scene_vulkan, the same scene on Vulkan (own device, offscreen) into out/scene_vulkan.png"
	@echo "  make dist                           regenerate dist/hybriddiff.h from hybriddiff.h, src/ and backends/"
	@echo "  make clean                          remove build/"
	@echo "  make help                           this list"
	@echo "tests (T: part of make test):"
	@echo "  make check-generated                T embedded kernels, SPIR-V, hd_undef.h, dist/hybriddiff.h up to date; no macro leaks"
	@echo "  make check-glsl                     T every shared kernel compiles as GLSL 4.30 and 4.50"
	@echo "  make compile-matrix                 T dist/hybriddiff.h as C99/C++17, gcc/clang, every backend, #error cases"
	@echo "  make dist-builds                    T examples and conformance suites built from dist/hybriddiff.h, run --quick"
	@echo "  make check-release                  T a release build from dist/ keeps no test hook or fault-injection knob"
	@echo "  make conformance-opencl             T the OpenCL backend against the CPU reference (PoCL)"
	@echo "  make conformance-vulkan             T the Vulkan backend against the CPU reference (lavapipe)"
	@echo "  make conformance-vulkan-validation  T the same under the validation layer; fails on any message"
	@echo "  make conformance-gl                 T the GL backend against the CPU reference (llvmpipe, headless EGL)"
	@echo "  make physics-cpu                    T the CPU backend against closed forms (E, the slab's image, phi's Green's function)"
	@echo "  make physics-opencl                 T the same on OpenCL (physics-vulkan, physics-gl: T too; make physics: all four)"
	@echo "  make compile-opencl-cxx             T the OpenCL implementation as C++17, warnings as errors"
	@echo "  make compile-vulkan-cxx             T the Vulkan implementation as C++17, warnings as errors"
	@echo "  make compile-gl-cxx                 T the GL implementation as C++17, warnings as errors"
	@echo "  make test-gl                        T GL host state restored, render to texture, caller's context checks"
	@echo "  make test-opencl                    T OpenCL: the host's cl_mem depth buffer gives hd_set_depth's image"
	@echo "  make test-null                      T the public API over the null backend (computes nothing, counts primitives)"
	@echo "  make test-vulkan                    T caller's device and hd_vulkan_record, device memory and device-lost paths"
	@echo "  make test-hdview                    T the viewer under Xvfb against hdrender's image"
	@echo "  make test-scene                     T the host-scene example under Xvfb: runs and writes a lit image"
	@echo "  make test-scene-vulkan              T the Vulkan scene under the validation layer: depth hides and cuts the cloud, no message"
	@echo "  make alloc-fail-opencl              T every k-th host allocation failed on the OpenCL backend"
	@echo "  make device-oom-opencl              T device memory exhausted under POCL_MEMORY_LIMIT=1"
	@echo "  make fuzz-smoke                     T libFuzzer runs of the NRRD, MetaImage and NIfTI loaders, the API and the call-sequence fuzzers"
	@echo "  make fuzz-smoke-api                 T the API fuzzer alone (part of fuzz-smoke)"
	@echo "  make fuzz-smoke-state               T the state-machine fuzzer (call sequences) alone (part of fuzz-smoke)"
	@echo "  make asan                           T build/hdtest and the OpenCL conformance subset under ASan+UBSan+LSan"
	@echo "  make tsan                           T the CPU backend's threaded tests under TSan"
	@echo "  make valgrind                       T the API, loader and error-path suites under memcheck"
	@echo "  make soak-short                     T 500 HD iterations: memory flat, images finite"
	@echo "  make integrate                      T examples/integrate_*: built (C99/C++17, both include orders) and run"
	@echo "  make integrate-compile              T the integration programs' other language and include order, compiled"
	@echo "  make readme-check                   T every code block of README.md compiled (C99, C++17) and run"
	@echo "  make test-vdb                       T OpenVDB grids (head CT, a sparse cloud) load, place and render as their NRRDs"
	@echo "  make test-dicom-hostile             T hdrender on hostile DICOM folders: links, FIFOs, junk, mutated slices"
	@echo "  make test-hdrender-cli              T hdrender's command line: FIFOs, /dev/full, numbers out of range, TF files"
	@echo "  make valgrind-opencl                the quick OpenCL conformance subset under valgrind"
	@echo "  make mutation-test                  known bugs applied to a copy of the tree: each must fail its suite (docs/TESTING.md)"
	@echo "  make fuzz-long                      FUZZ_SECONDS of libFuzzer per loader, new corpus kept"
	@echo "  make fuzz-long-api                  FUZZ_SECONDS of the API fuzzer"
	@echo "  make fuzz-long-state                FUZZ_SECONDS of the state-machine fuzzer (FUZZ_STATE_LONG_RUNS: runs), findings kept"
	@echo "  make soak                           10,000 HD iterations: RSS and device bytes over time"
	@echo "  make dicom-hostile-long             test-dicom-hostile with 1000 junk files and 1000 mutated slices"
	@echo "benchmarks and evaluation (not part of make test; figures in docs/):"
	@echo "  make bench                          build/hdbench: CPU backend iterations/s and stage times on the head CT"
	@echo "  make bench-rb-schedule              the CPU red-black schedule against the previous one, one process"
	@echo "  make bench-guard                    the per-context in-call guard's cost per call, with and without it, one process"
	@echo "  make bench-opencl                   OpenCL against the CPU in one run"
	@echo "  make bench-vulkan                   Vulkan sweeps and iterations/s (BENCH_ARGS: --sweeps, --variants, --ab)"
	@echo "  make bench-vulkan-multigrid         Vulkan multigrid steps against the CPU, interleaved"
	@echo "  make bench-gl                       GL backend figures on the head CT"
	@echo "  make bench-multigrid                time to a 1e-4 residual: red-black sweeps against multigrid CG"
	@echo "  make bench-scale                    light and memory against volume size: head CT and a sparse cloud, 256^3, 512^3"
	@echo "  make bench-project                  projection frame time per backend, this tree against PROJECT_BASE"
	@echo "  make bench-orbit                    orbit frames per backend and PSNR per time budget (docs/orbit/)"
	@echo "  make bench-budget                   the smallest render_budget each backend holds on a 1280x720 / 1080p orbit"
	@echo "  make bench-peer                     one orbit frame against VTK's ray casters (needs pvpython; docs/peer/)"
	@echo "  make eval                           the reduced evaluation of the paper's claims (docs/eval/, ~15 min)"
	@echo "  make eval-paper                     the evaluation at the paper's scale (out/eval-paper)"
	@echo "  make eval-refine                    a resting view refined toward PT_MS: PSNR per budget (docs/DESIGN-REFINE.md)"
	@echo "  make eval-multigrid                 the multigrid study: PSNR against PT_MS over time (docs/eval/multigrid/)"
	@echo "  make bench-energy                   HD's mean radiance and PSNR against PT_MS per scene (docs/DESIGN-ENERGY.md)"
	@echo "  make bench-lights                   HD's cost with a quad and a sphere light, PSNR against PT_MS, the light choice (docs/DESIGN-LIGHTS.md)"
	@echo "  make compile-time                   CPU seconds to compile each backend's implementation against stb_image.h"

LIB_SRC := hybriddiff.h $(wildcard src/*.h backends/*.h backends/kernels/*.h)

# The GPU backends' kernels are generated from backends/kernels/ and committed (the library needs
# no generator): every build remakes one whose sources are newer, so a kernel edit is what the
# GPU backends run. A remade file with the same bytes is only touched; a changed one says so, to
# be committed. When git shows its sources as committed, a change means the committed copy was
# stale (a commit without its regenerated file, as a clean clone in CI would build): that fails
# the build once, with the file remade. scripts/check-generated (make test) compares them too.
# Without glslangValidator the SPIR-V is kept only while git shows it and its sources as
# committed (a fresh clone's timestamps), else the build fails saying so.
GEN_KERNELS := $(wildcard backends/kernels/*.h)
GEN_GLSL := backends/hd_prelude_glsl.h backends/hd_entry_glsl.h backends/hd_entry_glsl_multigrid.h $(GEN_KERNELS)
GEN_FILES := backends/hd_kernels_embedded.h backends/hd_glsl_embedded.h backends/hd_spirv.h
# git vouches for files only in this tree's own checkout (not in a copy under build/)
HD_GIT_HERE = [ "$$(git rev-parse --show-toplevel 2>/dev/null)" = "$(CURDIR)" ]
define hd_regen_new
	if cmp -s $@.new $@; then rm -f $@.new; touch $@; \
	else mv $@.new $@; echo "$@ regenerated by $(1): commit it"; \
	  if $(HD_GIT_HERE) && git diff --quiet HEAD -- $(filter-out $@,$^) && ! git diff --quiet HEAD -- $@; then \
	    echo "$@ as committed is stale (its sources are as committed): commit the regenerated file" >&2; exit 1; fi; fi
endef
backends/hd_kernels_embedded.h: scripts/embed-kernels backends/hd_prelude_cl.h backends/hd_entry_cl.h $(GEN_KERNELS)
	@scripts/embed-kernels $@.new && $(call hd_regen_new,scripts/embed-kernels)
backends/hd_glsl_embedded.h: scripts/embed-glsl backends/hd_bind_gl_glsl.h $(GEN_GLSL)
	@scripts/embed-glsl $@.new && $(call hd_regen_new,scripts/embed-glsl)
backends/hd_spirv.h: scripts/build-spirv backends/hd_bind_vk_glsl.h hybriddiff.h $(GEN_GLSL)
	@if ! command -v glslangValidator >/dev/null 2>&1; then \
	  if $(HD_GIT_HERE) && git diff --quiet HEAD -- $^ $@; then touch $@; \
	    echo "$@: no glslangValidator; it and its sources are as committed: kept"; exit 0; fi; \
	  echo "$@ is older than its sources and glslangValidator (Debian: glslang-tools) is missing" >&2; exit 1; fi; \
	scripts/build-spirv $@.new && $(call hd_regen_new,scripts/build-spirv)
dist: $(GEN_FILES)

$(B)/%.o: tests/%.c $(LIB_SRC) $(wildcard examples/*.h) $(wildcard tests/*.h) $(B)/hd_suites.h | $(B)
	$(CC) $(CPPFLAGS) -I$(B) $(WARN) $(CFLAGS) -c $< -o $@

# Every tests/*.c that defines `const hd_test_case hd_tests_NAME[]` is a suite of build/hdtest.
$(B)/hd_suites.h: $(wildcard tests/*.c) | $(B)
	sed -n 's/^const hd_test_case hd_tests_\([a-z0-9_]*\)\[\].*/X(\1)/p' tests/*.c > $@.tmp
	cmp -s $@.tmp $@ || mv $@.tmp $@; rm -f $@.tmp

TEST_OBJ := $(patsubst tests/%.c,$(B)/%.o,$(wildcard tests/*.c))
$(B)/hdtest: $(TEST_OBJ)
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS)

# build/hdrender and its per-backend siblings: mk/hdrender.mk
$(B)/hdbench: bench/hdbench.c bench/hdbench_triad.h bench/hd_bench_median.h examples/hd_tf.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

# the CPU red-black schedule against the one before it, in one process (bench/hdbench_rb_schedule.c)
$(B)/hdbench_rb_schedule: bench/hdbench_rb_schedule.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-rb-schedule: $(B)/hdbench_rb_schedule data
	$(B)/hdbench_rb_schedule data/head.nrrd 2

$(B):
	mkdir -p $(B)

# make test builds every program it runs first, TEST_JOBS compiles at a time (compiling the
# implementation is most of the build), then runs the tests one after another. Each mk/*.mk adds
# its programs to TEST_PROGRAMS. The loader tests' real files come next (mk/test-data.mk).
TEST_JOBS ?= $(shell getconf _NPROCESSORS_ONLN 2>/dev/null || echo 2)
TEST_PROGRAMS := $(B)/hdtest
.PHONY: test-programs
test-programs:
	$(MAKE) --no-print-directory $(if $(filter -j%,$(MAKEFLAGS)),,-j$(TEST_JOBS)) $(TEST_PROGRAMS)
test: test-programs test-data $(B)/hdtest
	$(B)/hdtest

data:
	scripts/fetch-data

render: $(B)/hdrender data
	$(B)/hdrender data/head.nrrd -o out/head.png

bench: $(B)/hdbench data
	$(B)/hdbench

clean:
	rm -rf $(B)

# Backends, tools and test programs that bring their own rules (one fragment each).
# what every tool (hdrender, hdview) links beside its own object: the DICOM and OpenVDB readers
# (mk/hdrender.mk); set before the includes, which use it in prerequisites
TOOL_OBJS := $(B)/hd_dicom.o $(B)/hd_vdb.o
TOOL_LDLIBS = $(DICOM_LDLIBS) $(VDB_LDLIBS)
VDB_LDLIBS := -lopenvdb -lImath-3_1 -ltbb
-include $(wildcard mk/*.mk)
