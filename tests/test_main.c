/* test_main.c - runs every suite. Usage: hdtest [name-filter]; a filter that matches no test
   fails (exit 2), so a mistyped one cannot pass. A skipped test (HD_TEST_SKIP) is counted apart;
   with HD_CONFORMANCE_REQUIRE=1 (CI) a skip fails.
   hd_suites.h (made by the Makefile) lists X(name) for each test file that defines
   `const hd_test_case hd_tests_name[]`, so a new suite needs no edit here. */
#include "hd_test.h"
#include <stdlib.h>

int hd_test_failures;
int hd_test_skipped;

#define X(s) extern const hd_test_case hd_tests_##s[]; extern const int hd_tests_##s##_count;
#include "hd_suites.h"
#undef X

int hd_test_run(const hd_test_case *cases, int count, const char *filter, int *passed, int *failed, int *skipped)
{
    int i, bad = 0;
    for (i = 0; i < count; ++i) {
        if (filter && !strstr(cases[i].name, filter)) continue;
        hd_test_failures = 0;
        hd_test_skipped = 0;
        fprintf(stderr, "[ RUN  ] %s\n", cases[i].name);
        cases[i].fn();
        if (hd_test_failures) { ++*failed; ++bad; fprintf(stderr, "[ FAIL ] %s\n", cases[i].name); }
        else if (hd_test_skipped) { ++*skipped; fprintf(stderr, "[ SKIP ] %s\n", cases[i].name); }
        else { ++*passed; fprintf(stderr, "[  OK  ] %s\n", cases[i].name); }
    }
    return bad;
}

int main(int argc, char **argv)
{
    int passed = 0, failed = 0, skipped = 0;
    const char *filter = argc > 1 ? argv[1] : NULL, *req = getenv("HD_CONFORMANCE_REQUIRE");
#define X(s) hd_test_run(hd_tests_##s, hd_tests_##s##_count, filter, &passed, &failed, &skipped);
#include "hd_suites.h"
#undef X
    if (skipped) printf("%d passed, %d failed, %d skipped\n", passed, failed, skipped);
    else printf("%d passed, %d failed\n", passed, failed);
    if (passed + failed + skipped == 0) {
        printf("no test matches \"%s\"\n", filter ? filter : "");
        return 2;
    }
    return failed || (skipped && req && strcmp(req, "1") == 0) ? 1 : 0;
}
