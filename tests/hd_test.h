/* hd_test.h - the tiny test runner every test program shares.
   A test is a function; CHECK records a failure with file and line and carries on, so one run
   shows every broken assertion. HD_TEST_SKIP marks the running test skipped (it reports
   "[ SKIP ]", counted apart, never as passed). The runner's last line is "N passed, N failed"
   (", N skipped" when some were). */
#ifndef HD_TEST_H
#define HD_TEST_H
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>

typedef struct hd_test_case {
    const char *name;
    void (*fn)(void);
} hd_test_case;

extern int hd_test_failures; /* failures in the running test */
extern int hd_test_skipped;  /* the running test skipped (part of) what it checks */

#define HD_TEST_SKIP(...) \
    do { \
        hd_test_skipped = 1; \
        fprintf(stderr, "  skipped: "); \
        fprintf(stderr, __VA_ARGS__); \
        fputc('\n', stderr); \
    } while (0)

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

/* An allocator (hd_desc.allocator, user_data an hd_test_alloc) that fails the fail_at-th call
   (1-based; 0: none) and counts the calls, the blocks still live and the failures. */
typedef struct hd_test_alloc {
    long calls, fail_at;
    long live, failed;
} hd_test_alloc;

static inline void *hd_test_alloc_fn(size_t size, void *user)
{
    hd_test_alloc *s = (hd_test_alloc *)user;
    void *p;
    if (++s->calls == s->fail_at) {
        ++s->failed;
        return NULL;
    }
    p = malloc(size ? size : 1);
    if (p) ++s->live;
    return p;
}

static inline void hd_test_free_fn(void *ptr, void *user)
{
    hd_test_alloc *s = (hd_test_alloc *)user;
    if (ptr) --s->live;
    free(ptr);
}

/* The allocator of desc d made the one above, counting into s (cleared). */
static inline void hd_test_allocator(hd_desc *d, hd_test_alloc *s)
{
    memset(s, 0, sizeof *s);
    d->allocator.alloc = hd_test_alloc_fn;
    d->allocator.free = hd_test_free_fn;
    d->allocator.user_data = s;
}

/* The CPU backend's bytes of HD's direct light in method_bytes on an illumination grid of st's
   dims: the mask (a bit per grid voxel) and the entries before each 8^3 brick (one more). */
static inline size_t hd_test_mask_bytes(const hd_stats *st)
{
    const int *g = st->illumination_dims;
    size_t bricks = (size_t)((g[0] + 7) / 8) * (size_t)((g[1] + 7) / 8) * (size_t)((g[2] + 7) / 8);
    return ((size_t)g[0] * g[1] * g[2] + 7) / 8 + (bricks + 1) * 4;
}
#endif

/* Runs every case whose name contains filter (NULL: all); returns the number of failed cases. */
int hd_test_run(const hd_test_case *cases, int count, const char *filter, int *passed, int *failed, int *skipped);

#endif
