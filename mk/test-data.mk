# mk/test-data.mk - `make test` fetches the real files the loader tests read first
# (tests/test_io_formats.c: NIfTI-1 from Debian packages, scripts/fetch-test-data), so they run
# instead of being skipped; in CI (HD_CONFORMANCE_REQUIRE=1) a missing one fails.
#   make test-data   fetch them into data/test/ (idempotent)
.PHONY: test-data
test-data:
	scripts/fetch-test-data
test: test-data
# the suites that run the loader tests, also under make -j
asan tsan valgrind: test-data
