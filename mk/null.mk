# mk/null.mk - the null backend (backends/hd_null.h): the public API over a backend that computes
# nothing and counts its primitives (tests/null/test_null.c).
#   make test-null   build/test_null, C99 and C++17 (part of `make test`)
.PHONY: test-null
$(B)/test_null: tests/null/test_null.c tests/hd_test.h $(LIB_SRC) | $(B)
	$(CC) $(CPPFLAGS) $(WARN) $(CFLAGS) $< -o $@ $(LDLIBS)
$(B)/test_null_cxx: tests/null/test_null.c tests/hd_test.h $(LIB_SRC) | $(B)
	$(CXX) $(CPPFLAGS) -x c++ -std=c++17 -Wall -Wextra -Werror -Wpedantic $(CFLAGS) $< -o $@ $(LDLIBS)
TEST_PROGRAMS += $(B)/test_null $(B)/test_null_cxx
test-null: $(B)/test_null $(B)/test_null_cxx
	$(B)/test_null
	$(B)/test_null_cxx
test: test-null
