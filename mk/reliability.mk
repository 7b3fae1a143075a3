# mk/reliability.mk - hostile input, sanitizers and checkers. Each job exits non-zero
# on any report. Timings measured on the 2-core CI machine: docs/DESIGN-OVERVIEW.md, "Guarantees".
#   make fuzz-smoke   libFuzzer, FUZZ_RUNS executions per loader from generated seeds plus
#                     tests/fuzz/regressions/ (part of `make test`); every accepted volume of at
#                     most 64^3 voxels is rendered (tests/fuzz/hd_fuzz_check.h)
#   make fuzz-long    FUZZ_SECONDS per loader (local; keeps new corpus in build/fuzz/work_*)
#   make fuzz-smoke-api / fuzz-long-api   the same for the API fuzzer (tests/fuzz/fuzz_api.c;
#                     fuzz-smoke runs fuzz-smoke-api)
#   make fuzz-smoke-state / fuzz-long-state   the state-machine fuzzer (tests/fuzz/fuzz_state.c:
#                     call sequences over the whole API; fuzz-smoke runs fuzz-smoke-state)
#   make asan         build/hdtest and the OpenCL conformance suite under ASan+UBSan+LSan
#   make tsan         the CPU backend's threaded tests under TSan
#   make valgrind     build/hdtest's API/loader/error-path suites (CPU) under memcheck, built
#                     without AVX-512 (-march=x86-64-v2)
#   make soak         bench/hdsoak: 10,000 HD iterations, RSS and device bytes over time
#   make check-all    = make test (which includes all of the above but fuzz-long and soak)
SAN_CC      ?= clang
FUZZ_RUNS   ?= 200000
FUZZ_SECONDS ?= 180
FUZZ_TARGETS := nrrd mhd nifti
FZ          := $(B)/fuzz
SAN         := $(B)/san
SAN_COMMON  := -g -O1 -fno-omit-frame-pointer
ASAN_FLAGS  := $(SAN_COMMON) -fsanitize=address,undefined -fno-sanitize-recover=all
TSAN_FLAGS  := $(SAN_COMMON) -fsanitize=thread
# halt_on_error: the first report fails the job; LSan is on by default with ASan on x86-64.
ASAN_ENV    := ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:abort_on_error=0:exitcode=23 \
               UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
TSAN_ENV    := TSAN_OPTIONS=halt_on_error=1:exitcode=24
TEST_SRC    := $(wildcard tests/*.c)
VG_CFLAGS   := -O1 -g -march=x86-64-v2

.PHONY: fuzz-smoke fuzz-long asan tsan valgrind soak check-all

$(FZ) $(SAN):
	mkdir -p $@

# ---- fuzzing ----
FUZZ_SAN := $(SAN_COMMON) -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
# The implementation is compiled once (tests/fuzz/hd_impl_fuzz.c) and linked into every target.
$(FZ)/hd_impl_fuzz.o: tests/fuzz/hd_impl_fuzz.c $(LIB_SRC) | $(FZ)
	$(SAN_CC) $(CPPFLAGS) $(WARN) $(FUZZ_SAN) -c $< -o $@
$(FZ)/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/hd_fuzz_check.h $(FZ)/hd_impl_fuzz.o $(LIB_SRC) | $(FZ)
	$(SAN_CC) $(CPPFLAGS) $(WARN) $(FUZZ_SAN) $< $(FZ)/hd_impl_fuzz.o -o $@ $(LDLIBS)
$(FZ)/make_seeds: tests/fuzz/make_seeds.c tests/fuzz/hd_fuzz_gen.h | $(FZ)
	$(CC) $(CPPFLAGS) $(WARN) -O1 $< -o $@ -lz
$(FZ)/seeds.stamp: $(FZ)/make_seeds
	rm -rf $(FZ)/seeds && $(FZ)/make_seeds $(FZ)/seeds && touch $@

FUZZ_ARGS := -seed=1 -max_len=4096 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
# A fresh copy of the seeds each run: the smoke run's length does not grow with its corpus.
fuzz-smoke: $(FUZZ_TARGETS:%=$(FZ)/fuzz_%) $(FZ)/seeds.stamp
	@set -e; for t in $(FUZZ_TARGETS); do \
	  rm -rf $(FZ)/work_$$t; cp -r $(FZ)/seeds/$$t $(FZ)/work_$$t; \
	  start=$$(date +%s); \
	  if ! $(FZ)/fuzz_$$t -runs=$(FUZZ_RUNS) $(FUZZ_ARGS) -artifact_prefix=$(FZ)/crash-$$t- \
	       $(FZ)/work_$$t tests/fuzz/regressions/$$t > $(FZ)/fuzz_$$t.log 2>&1; then \
	    tail -n 60 $(FZ)/fuzz_$$t.log; echo "fuzz-smoke: $$t FAILED (input in $(FZ)/crash-$$t-*)"; exit 1; fi; \
	  echo "fuzz-smoke: $$t: $(FUZZ_RUNS) runs, nothing found ($$(( $$(date +%s) - start )) s)"; \
	done

fuzz-long: $(FUZZ_TARGETS:%=$(FZ)/fuzz_%) $(FZ)/seeds.stamp
	@set -e; for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(FZ)/work_$$t; cp -n $(FZ)/seeds/$$t/* $(FZ)/work_$$t/ 2>/dev/null || true; \
	  $(FZ)/fuzz_$$t -max_total_time=$(FUZZ_SECONDS) -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
	    -artifact_prefix=tests/fuzz/regressions/$$t/crash- $(FZ)/work_$$t tests/fuzz/regressions/$$t \
	    2>&1 | tail -n 3; \
	done

# ---- ASan + UBSan (+ LSan) ----
$(SAN)/hdtest-asan: $(TEST_SRC) $(LIB_SRC) $(wildcard tests/*.h) $(B)/hd_suites.h | $(SAN)
	$(SAN_CC) $(CPPFLAGS) -I$(B) $(WARN) $(ASAN_FLAGS) $(TEST_SRC) -o $@ $(LDLIBS)
$(SAN)/conf_impl_cpu.o: $(CONF_DIR)/impl_cpu.c $(CONF_DEPS) | $(SAN)
	$(SAN_CC) $(CPPFLAGS) $(WARN) $(ASAN_FLAGS) -c $< -o $@
$(SAN)/conf_impl_opencl.o: $(CONF_DIR)/impl_backend.c $(CONF_DEPS) | $(SAN)
	$(SAN_CC) $(CPPFLAGS) -DHYBRIDDIFF_BACKEND_OPENCL $(WARN) $(ASAN_FLAGS) -c $< -o $@
$(SAN)/conformance.o: $(CONF_DIR)/conformance.c $(CONF_DIR)/hd_api.h hybriddiff.h | $(SAN)
	$(SAN_CC) $(CPPFLAGS) $(WARN) $(ASAN_FLAGS) -c $< -o $@
$(SAN)/conformance-asan: $(SAN)/conformance.o $(SAN)/conf_impl_cpu.o $(SAN)/conf_impl_opencl.o
	$(SAN_CC) $(ASAN_FLAGS) $^ -o $@ $(LDLIBS) $(CL_LDLIBS)

# PoCL and its LLVM keep allocations for the process lifetime: tests/lsan-pocl.supp names them
# (their libraries only; a leak with a hybriddiff frame on top is still reported).
asan: $(SAN)/hdtest-asan $(SAN)/conformance-asan
	$(ASAN_ENV) $(SAN)/hdtest-asan
	$(ASAN_ENV) LSAN_OPTIONS=suppressions=tests/lsan-pocl.supp:print_suppressions=0 \
		$(SAN)/conformance-asan --quick

# ---- TSan: every test that runs the CPU backend's worker threads ----
$(SAN)/hdtest-tsan: $(TEST_SRC) $(LIB_SRC) $(wildcard tests/*.h) $(B)/hd_suites.h | $(SAN)
	$(SAN_CC) $(CPPFLAGS) -I$(B) $(WARN) $(TSAN_FLAGS) $(TEST_SRC) -o $@ $(LDLIBS)
tsan: $(SAN)/hdtest-tsan
	$(TSAN_ENV) $(SAN)/hdtest-tsan $(TSAN_FILTER)

# ---- valgrind memcheck (no AVX-512 in valgrind) ----
$(SAN)/hdtest-vg: $(TEST_SRC) $(LIB_SRC) $(wildcard tests/*.h) $(B)/hd_suites.h | $(SAN)
	$(CC) $(CPPFLAGS) -I$(B) $(WARN) $(VG_CFLAGS) $(TEST_SRC) -o $@ $(LDLIBS)
# The suites that exercise the API, the loaders and the error paths; the numeric suites
# (kernels_, methods_) take >10 min under memcheck and run under ASan instead. A filter that
# runs no test fails (hdtest exits 2 then, and the log must count one passed), so a renamed
# suite cannot leave its filter passing on nothing.
VG_SUITES ?= core_ io_ hostile alloc_fail tf_ render_
valgrind: $(SAN)/hdtest-vg
	@set -e; for s in $(VG_SUITES); do echo "valgrind: hdtest $$s"; \
	  valgrind -q --error-exitcode=9 --leak-check=full --errors-for-leak-kinds=definite,indirect \
		--show-leak-kinds=definite,indirect $(SAN)/hdtest-vg $$s > $(SAN)/vg_$$s.log 2>&1 \
		|| { tail -n 80 $(SAN)/vg_$$s.log; echo "valgrind: hdtest $$s FAILED"; exit 1; }; \
	  tail -n 1 $(SAN)/vg_$$s.log; \
	  grep -Eq '^[1-9][0-9]* passed' $(SAN)/vg_$$s.log || { echo "valgrind: the filter $$s ran no test"; exit 1; }; done

# Measured on the 2-core machine, builds included: fuzz-smoke ~95 s (2026-12-02, runs alone:
# loaders 56 s, API 14 s, state 22 s), asan ~75 s, tsan ~45 s,
# valgrind ~225 s, soak-short ~6 s: with the rest of make test about 10 minutes, inside the
# 30-minute CI budget, so all of them are part of `make test`. Rendering what the fuzzers accept
# (2026-11-27, `make fuzz-smoke`'s command, old and new binaries interleaved on the loaded
# machine): 200,000 runs of fuzz_nrrd 21-24 s against 9.4-9.7 s, fuzz_mhd 18-22 s against 10-11 s.
check-all: test

TEST_PROGRAMS += $(FUZZ_TARGETS:%=$(FZ)/fuzz_%) $(FZ)/fuzz_api $(FZ)/make_seeds $(SAN)/hdtest-asan \
                 $(SAN)/conformance-asan $(SAN)/hdtest-tsan $(SAN)/hdtest-vg
test: fuzz-smoke asan tsan valgrind

# ---- soak ----
$(B)/hdsoak: bench/hdsoak.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
soak: $(B)/hdsoak
	$(B)/hdsoak 10000 32
.PHONY: soak-short
soak-short: $(B)/hdsoak
	$(B)/hdsoak 500 24
TEST_PROGRAMS += $(B)/hdsoak
test: soak-short

# ---- the API fuzzer (tests/fuzz/fuzz_api.c): hd_desc / hd_params / lights / camera bytes with
# finite extremes, one context and iterations per input; -timeout makes a hang a finding. It
# starts from its regressions only (no generated seeds). FUZZ_API_RUNS in make test;
# docs/DESIGN-OVERVIEW.md ("Guarantees") gives the 200,000-run figure.
FUZZ_API_RUNS ?= 20000
FUZZ_API_ARGS := -seed=1 -max_len=1024 -timeout=10 -rss_limit_mb=2048 -print_final_stats=1
.PHONY: fuzz-smoke-api fuzz-long-api
fuzz-smoke-api: $(FZ)/fuzz_api
	@rm -rf $(FZ)/work_api; mkdir -p $(FZ)/work_api; start=$$(date +%s); \
	if ! $(FZ)/fuzz_api -runs=$(FUZZ_API_RUNS) $(FUZZ_API_ARGS) -artifact_prefix=$(FZ)/crash-api- \
	     $(FZ)/work_api tests/fuzz/regressions/api > $(FZ)/fuzz_api.log 2>&1; then \
	  tail -n 60 $(FZ)/fuzz_api.log; echo "fuzz-smoke: api FAILED (input in $(FZ)/crash-api-*)"; exit 1; fi; \
	echo "fuzz-smoke: api: $(FUZZ_API_RUNS) runs, nothing found ($$(( $$(date +%s) - start )) s)"
fuzz-smoke: fuzz-smoke-api
fuzz-long-api: $(FZ)/fuzz_api
	mkdir -p $(FZ)/work_api
	$(FZ)/fuzz_api -max_total_time=$(FUZZ_SECONDS) $(FUZZ_API_ARGS) \
	  -artifact_prefix=tests/fuzz/regressions/api/crash- $(FZ)/work_api tests/fuzz/regressions/api 2>&1 | tail -n 3

# ---- the state-machine fuzzer (tests/fuzz/fuzz_state.c): sequences of up to 48 calls over the
# whole API on volumes of at most 8^3 and images of at most 16x16, every result, rejected call,
# image and setter checked against the documented rules after each call (the file's header).
# -len_control=0: an input needs a few hundred bytes to reach deep call sequences. A call over
# 5 s fails inside the target; -timeout catches one that never returns. It starts from its
# regressions only. FUZZ_STATE_RUNS in make test; fuzz-long-state runs FUZZ_SECONDS (or
# FUZZ_STATE_LONG_RUNS runs when given), keeping new corpus in build/fuzz/work_state and what it
# finds in tests/fuzz/regressions/state.
FUZZ_STATE_RUNS ?= 4000
FUZZ_STATE_LONG_RUNS ?=
FUZZ_STATE_ARGS := -max_len=1024 -len_control=0 -timeout=20 -rss_limit_mb=2048 -print_final_stats=1
.PHONY: fuzz-smoke-state fuzz-long-state
fuzz-smoke-state: $(FZ)/fuzz_state
	@rm -rf $(FZ)/work_state_smoke; mkdir -p $(FZ)/work_state_smoke; start=$$(date +%s); \
	if ! $(FZ)/fuzz_state -seed=1 -runs=$(FUZZ_STATE_RUNS) $(FUZZ_STATE_ARGS) -artifact_prefix=$(FZ)/crash-state- \
	     $(FZ)/work_state_smoke tests/fuzz/regressions/state > $(FZ)/fuzz_state.log 2>&1; then \
	  grep -m1 '^fuzz_state:' $(FZ)/fuzz_state.log; tail -n 40 $(FZ)/fuzz_state.log; \
	  echo "fuzz-smoke: state FAILED (input in $(FZ)/crash-state-*; HD_FZ_TRACE=1 $(FZ)/fuzz_state INPUT prints its calls)"; exit 1; fi; \
	echo "fuzz-smoke: state: $(FUZZ_STATE_RUNS) runs, nothing found ($$(( $$(date +%s) - start )) s)"
fuzz-smoke: fuzz-smoke-state
fuzz-long-state: $(FZ)/fuzz_state
	mkdir -p $(FZ)/work_state
	$(FZ)/fuzz_state $(if $(FUZZ_STATE_LONG_RUNS),-runs=$(FUZZ_STATE_LONG_RUNS),-max_total_time=$(FUZZ_SECONDS)) $(FUZZ_STATE_ARGS) \
	  -artifact_prefix=tests/fuzz/regressions/state/crash- $(FZ)/work_state tests/fuzz/regressions/state 2>&1 | tail -n 3
TEST_PROGRAMS += $(FZ)/fuzz_state
