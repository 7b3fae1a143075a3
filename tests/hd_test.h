/* hd_test.h - the tiny test runner every test program shares.
   A test is a function; CHECK records a failure with file and line and carries on, so one run
   shows every broken assertion. The runner's last line is "N passed, N failed". */
#ifndef HD_TEST_H
#define HD_TEST_H
#include <stdio.h>
#include <string.h>
#include <math.h>

typedef struct hd_test_case {
    const char *name;
    void (*fn)(void);
} hd_test_case;

extern int hd_test_failures; /* failures in the running test */

#define CHECK(cond) \
    do { \
        if (!(cond)) { \
            ++hd_test_failures; \
            fprintf(stderr, "  %s:%d: CHECK(%s) failed\n", __FILE__, __LINE__, #cond); \
        } \
    } while (0)

#define CHECK_MSG(cond, ...) \
    do { \
        if (!(cond)) { \
            ++hd_test_failures; \
            fprintf(stderr, "  %s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
            fprintf(stderr, __VA_ARGS__); \
            fputc('\n', stderr); \
        } \
    } while (0)

/* Runs every case whose name contains filter (NULL: all); returns the number of failed cases. */
int hd_test_run(const hd_test_case *cases, int count, const char *filter, int *passed, int *failed);

#endif
