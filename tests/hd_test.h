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

/* A logger that counts what the library reports and keeps the last error, for tests that check
   "returns code X and logs a message". Only for files that include hybriddiff.h first. */
#ifdef HYBRIDDIFF_H
typedef struct hd_test_log {
    int errors, warnings;
    hd_result last_code;
    char last[1024];
} hd_test_log;

static inline void hd_test_log_fn(void *user, hd_log_level level, hd_result code, const char *message,
                                  const char *file, int line)
{
    hd_test_log *l = (hd_test_log *)user;
    (void)file;
    (void)line;
    if (level == HD_LOG_ERROR) {
        ++l->errors;
        l->last_code = code;
        snprintf(l->last, sizeof l->last, "%s", message ? message : "");
    } else {
        ++l->warnings;
    }
}

/* Clears *l and returns a logger that fills it. */
static inline hd_logger hd_test_logger(hd_test_log *l)
{
    hd_logger lg;
    memset(l, 0, sizeof *l);
    lg.func = hd_test_log_fn;
    lg.user_data = l;
    return lg;
}
#endif

/* Runs every case whose name contains filter (NULL: all); returns the number of failed cases. */
int hd_test_run(const hd_test_case *cases, int count, const char *filter, int *passed, int *failed);

#endif
