# hybriddiff development build. `make test` builds and runs every test; `make help` lists targets.
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
	@echo "make test      build and run the unit and analytic tests (CPU backend)"
	@echo "make all       tests, examples/hdrender, bench/hdbench"
	@echo "make data      fetch the head CT into data/ (Debian package invesalius-examples)"
	@echo "make render    fetch the data, build hdrender and render the head to out/head.png"
	@echo "make bench     print the benchmark figures (bench/hdbench)"
	@echo "make bench-rb-schedule   the CPU red-black schedule against the previous one, one process"
	@echo "make dist      regenerate dist/hybriddiff.h (after every source change; see mk/dist.mk)"
	@echo "make check-generated   embedded kernels, SPIR-V and dist/hybriddiff.h are up to date"
	@echo "mk/*.mk        per-backend and per-tool targets, each listed at the top of its file"

LIB_SRC := hybriddiff.h $(wildcard src/*.h backends/*.h backends/kernels/*.h)

$(B)/%.o: tests/%.c $(LIB_SRC) $(wildcard examples/*.h) tests/hd_test.h $(B)/hd_suites.h | $(B)
	$(CC) $(CPPFLAGS) -I$(B) $(WARN) $(CFLAGS) -c $< -o $@

# Every tests/*.c that defines `const hd_test_case hd_tests_NAME[]` is a suite of build/hdtest.
$(B)/hd_suites.h: $(wildcard tests/*.c) | $(B)
	sed -n 's/^const hd_test_case hd_tests_\([a-z0-9_]*\)\[\].*/X(\1)/p' tests/*.c > $@.tmp
	cmp -s $@.tmp $@ || mv $@.tmp $@; rm -f $@.tmp

TEST_OBJ := $(patsubst tests/%.c,$(B)/%.o,$(wildcard tests/*.c))
$(B)/hdtest: $(TEST_OBJ)
	$(CC) $(CFLAGS) $^ -o $@ $(LDLIBS)

# build/hdrender and its per-backend siblings: mk/hdrender.mk
$(B)/hdbench: bench/hdbench.c bench/hdbench_triad.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

# the CPU red-black schedule against the one before it, in one process (bench/hdbench_rb_schedule.c)
$(B)/hdbench_rb_schedule: bench/hdbench_rb_schedule.c $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)

bench-rb-schedule: $(B)/hdbench_rb_schedule data
	$(B)/hdbench_rb_schedule data/head.nrrd 2

$(B):
	mkdir -p $(B)

test: $(B)/hdtest
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
-include $(wildcard mk/*.mk)
