/* test_guard.c - the per-context in-call guard (src/hd_handles.h): calls on one context must not
   overlap, and one that would gets HD_ERROR_BUSY instead of sharing the context's state with the
   call in progress. Deterministic overlaps first: from inside the context's logger (the call in
   progress holds the guard) the same thread gets HD_ERROR_BUSY with no log line (it would
   re-enter the logger), another thread gets it with one line, hd_destroy included, and a call on
   another context works. Then two threads hammer one context (rendering and reading back against
   resizing the camera, changing parameters and reading back): every call succeeds or is
   HD_ERROR_BUSY with one line, the images stay finite and the context works afterwards; under
   `make tsan` no data race may be reported and under `make asan` no invalid access. */
#include "hybriddiff.h"
#include "hd_test.h"
#include <pthread.h>
#include <sched.h>
#include <stdint.h>
#include <time.h>

#define GN 8
static uint8_t g_vox[GN * GN * GN];

static void g_desc(hd_desc *d)
{
    int i;
    for (i = 0; i < GN * GN * GN; ++i) g_vox[i] = (uint8_t)((i * 37 + i / 7) % 200 + 40);
    memset(d, 0, sizeof *d);
    d->volume.type = HD_VOXEL_U8;
    d->volume.dims[0] = d->volume.dims[1] = d->volume.dims[2] = GN;
    d->volume.data = g_vox;
    d->camera.width = d->camera.height = 16;
    d->params.extinction = 20.0f;
    d->threads = 2;
}

static int g_finite(const float *v, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!isfinite(v[i])) return 0;
    return 1;
}

/* ---- overlaps made from inside the logger ------------------------------------------------------ */
/* The other thread makes one call when asked (g_req: its number) and reports its result. */
static pthread_mutex_t g_mu = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t g_cv = PTHREAD_COND_INITIALIZER;
static int g_req, g_done, g_quit;
static hd_result g_other_r;
static hd_context g_ctx, g_second;
static pthread_t g_main_thread;
static int g_busy_lines_other, g_lines_main, g_depth, g_reentered;
static hd_result g_same_r[3];

static hd_result g_other_call(int k)
{
    hd_stats st;
    float img[16 * 16 * 4];
    switch (k) {
    case 1: return hd_get_stats(g_ctx, &st);
    case 2: return hd_read_image_f32(g_ctx, img, sizeof img / sizeof img[0]);
    default: return hd_destroy(g_ctx);
    }
}

static void *g_other(void *arg)
{
    (void)arg;
    pthread_mutex_lock(&g_mu);
    for (;;) {
        while (!g_req && !g_quit) pthread_cond_wait(&g_cv, &g_mu);
        if (g_quit) break;
        pthread_mutex_unlock(&g_mu);
        g_other_r = g_other_call(g_req);
        pthread_mutex_lock(&g_mu);
        g_req = 0;
        g_done = 1;
        pthread_cond_broadcast(&g_cv);
    }
    pthread_mutex_unlock(&g_mu);
    return NULL;
}

/* The context's logger. On the main thread, inside a call (the guard held): the same-thread
   calls, then each of the other thread's calls, waited for. On the other thread: its BUSY line. */
static void g_log(void *user, hd_log_level level, hd_result code, const char *m, const char *f, int l)
{
    (void)user; (void)m; (void)f; (void)l;
    if (!pthread_equal(pthread_self(), g_main_thread)) {
        if (level == HD_LOG_ERROR && code == HD_ERROR_BUSY) __atomic_add_fetch(&g_busy_lines_other, 1, __ATOMIC_RELAXED);
        return;
    }
    ++g_lines_main;
    if (g_depth++ > 0) { ++g_reentered; --g_depth; return; } /* a line from a call made in here */
    if (level == HD_LOG_ERROR && code == HD_ERROR_INVALID_PARAMETER) {
        hd_stats st;
        hd_params p;
        int k;
        memset(&p, 0, sizeof p);
        g_same_r[0] = hd_get_stats(g_ctx, &st);
        g_same_r[1] = hd_set_params(g_ctx, &p);
        g_same_r[2] = hd_iterate(g_second, 1); /* another context: no guard in the way */
        for (k = 1; k <= 3; ++k) {
            pthread_mutex_lock(&g_mu);
            g_done = 0;
            g_req = k;
            pthread_cond_broadcast(&g_cv);
            while (!g_done) pthread_cond_wait(&g_cv, &g_mu);
            pthread_mutex_unlock(&g_mu);
            CHECK_MSG(g_other_r == HD_ERROR_BUSY, "the other thread's call %d during a call: %s", k, hd_result_string(g_other_r));
        }
    }
    --g_depth;
}

static void test_guard_from_logger(void)
{
    hd_desc d;
    hd_stats st;
    pthread_t t;
    float img[16 * 16 * 4];
    g_desc(&d);
    g_main_thread = pthread_self();
    g_busy_lines_other = g_lines_main = g_depth = g_reentered = 0;
    g_req = g_done = g_quit = 0;
    CHECK(hd_create(&d, &g_second) == HD_SUCCESS);
    d.logger.func = g_log;
    CHECK(hd_create(&d, &g_ctx) == HD_SUCCESS);
    CHECK(pthread_create(&t, NULL, g_other, NULL) == 0);
    g_lines_main = 0;
    /* a rejected call logs its line from inside the call: the logger does the rest */
    CHECK(hd_iterate(g_ctx, 0) == HD_ERROR_INVALID_PARAMETER);
    CHECK_MSG(g_same_r[0] == HD_ERROR_BUSY && g_same_r[1] == HD_ERROR_BUSY,
              "calls on the context from its own logger: %s, %s", hd_result_string(g_same_r[0]), hd_result_string(g_same_r[1]));
    CHECK_MSG(g_same_r[2] == HD_SUCCESS, "a call on another context from the logger: %s", hd_result_string(g_same_r[2]));
    CHECK_MSG(g_lines_main == 1 && g_reentered == 0, "the logger was called %d times on the calling thread (%d re-entered)",
              g_lines_main, g_reentered);
    CHECK_MSG(g_busy_lines_other == 3, "%d HD_ERROR_BUSY lines from the other thread, want 3", g_busy_lines_other);
    /* the guard is dropped: the context is whole, hd_destroy from the other thread was refused */
    CHECK(hd_iterate(g_ctx, 1) == HD_SUCCESS);
    CHECK(hd_read_image_f32(g_ctx, img, sizeof img / sizeof img[0]) == HD_SUCCESS && g_finite(img, sizeof img / sizeof img[0]));
    CHECK(hd_get_stats(g_ctx, &st) == HD_SUCCESS && st.iterations == 1);
    pthread_mutex_lock(&g_mu);
    g_quit = 1;
    pthread_cond_broadcast(&g_cv);
    pthread_mutex_unlock(&g_mu);
    pthread_join(t, NULL);
    CHECK(hd_destroy(g_ctx) == HD_SUCCESS);
    CHECK(hd_destroy(g_second) == HD_SUCCESS);
    CHECK(strstr(hd_result_string(HD_ERROR_BUSY), "HD_ERROR_BUSY") != NULL);
}

/* ---- two threads on one context ------------------------------------------------------------- */
#define G_FRAMES 40
#define G_ROUNDS 200000
#define G_SECONDS 5.0
typedef struct g_side {
    hd_context c;
    int calls, busy, bad, nonfinite, finish;
    hd_result bad_r;
} g_side;
static int g_lines; /* HD_ERROR_BUSY lines logged (__atomic) */
static int g_stop;  /* the renderer is done (__atomic) */
static int g_resized; /* the resizer's hd_set_camera calls that went through (__atomic) */

static void g_count(void *user, hd_log_level level, hd_result code, const char *m, const char *f, int l)
{
    (void)user; (void)m; (void)f; (void)l;
    if (level == HD_LOG_ERROR && code == HD_ERROR_BUSY) __atomic_add_fetch(&g_lines, 1, __ATOMIC_RELAXED);
}

static void g_result(g_side *s, hd_result r)
{
    ++s->calls;
    if (r == HD_ERROR_BUSY) ++s->busy;
    else if (r != HD_SUCCESS) { ++s->bad; s->bad_r = r; }
}

/* A read-back may also find the image just reset by the other side's setter: HD_ERROR_NO_FRAME. */
static void g_read_result(g_side *s, hd_result r) { g_result(s, r == HD_ERROR_NO_FRAME ? HD_SUCCESS : r); }

static double g_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* hd_render and the image read back until G_FRAMES renders and G_FRAMES resizes have gone
   through and a call has met the other thread's (at most G_ROUNDS rounds and G_SECONDS). */
static void *g_renderer(void *arg)
{
    g_side *s = (g_side *)arg;
    static float img[32 * 32 * 4];
    int k, frames = 0;
    double t0 = g_now();
    for (k = 0; k < G_ROUNDS && g_now() - t0 < G_SECONDS && (frames < G_FRAMES || __atomic_load_n(&g_resized, __ATOMIC_ACQUIRE) < G_FRAMES ||
                                 !__atomic_load_n(&s->finish, __ATOMIC_ACQUIRE)); ++k) {
        hd_result r = hd_render(s->c);
        g_result(s, r);
        frames += r == HD_SUCCESS;
        r = hd_read_image_f32(s->c, img, sizeof img / sizeof img[0]);
        g_read_result(s, r);
        if (r == HD_SUCCESS && !g_finite(img, 16 * 16 * 4)) ++s->nonfinite;
    }
    __atomic_store_n(&g_stop, 1, __ATOMIC_RELEASE);
    return NULL;
}

/* The camera resized between 16x16 and 32x32, the background changed, the image and the
   statistics read back, until the renderer stops. */
static void *g_resizer(void *arg)
{
    g_side *s = (g_side *)arg;
    static float img[32 * 32 * 4];
    hd_camera cam;
    hd_params p;
    hd_stats st;
    hd_desc q;
    int k = 0;
    for (;;) { /* the first one may meet a render */
        hd_result r = hd_query_desc(s->c, &q);
        g_result(s, r);
        if (r == HD_SUCCESS) break;
    }
    cam = q.camera;
    p = q.params;
    while (!__atomic_load_n(&g_stop, __ATOMIC_ACQUIRE)) {
        hd_result r;
        cam.width = cam.height = k % 2 ? 32 : 16;
        r = hd_set_camera(s->c, &cam);
        g_result(s, r);
        if (r == HD_SUCCESS) __atomic_add_fetch(&g_resized, 1, __ATOMIC_RELEASE);
        p.background[1] = (float)(k % 3) * 0.25f;
        g_result(s, hd_set_params(s->c, &p));
        r = hd_read_image_f32(s->c, img, sizeof img / sizeof img[0]);
        g_read_result(s, r);
        if (r == HD_SUCCESS && !g_finite(img, 16 * 16 * 4)) ++s->nonfinite;
        g_result(s, hd_get_stats(s->c, &st));
        ++k;
    }
    return NULL;
}

static void test_guard_two_threads(void)
{
    hd_desc d;
    hd_context c;
    g_side a, b;
    pthread_t ta, tb;
    static float img[32 * 32 * 4];
    hd_desc q;
    g_desc(&d);
    d.logger.func = g_count;
    g_lines = 0;
    g_stop = 0;
    g_resized = 0;
    CHECK(hd_create(&d, &c) == HD_SUCCESS);
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.c = b.c = c;
    CHECK(pthread_create(&ta, NULL, g_renderer, &a) == 0);
    CHECK(pthread_create(&tb, NULL, g_resizer, &b) == 0);
    /* the renderer goes on until a call has met the other thread's */
    while (!__atomic_load_n(&g_stop, __ATOMIC_ACQUIRE)) {
        if (__atomic_load_n(&g_lines, __ATOMIC_RELAXED) > 0) __atomic_store_n(&a.finish, 1, __ATOMIC_RELEASE);
        sched_yield();
    }
    pthread_join(ta, NULL);
    pthread_join(tb, NULL);
    fprintf(stderr, "  renderer: %d calls, %d HD_ERROR_BUSY; resizer: %d calls, %d HD_ERROR_BUSY, %d resizes\n", a.calls, a.busy,
            b.calls, b.busy, g_resized);
    CHECK_MSG(a.bad == 0 && b.bad == 0, "calls neither succeeded nor were busy: %d (%s), %d (%s)", a.bad,
              hd_result_string(a.bad_r), b.bad, hd_result_string(b.bad_r));
    CHECK_MSG(a.busy + b.busy > 0, "no call of %d met the other thread's", a.calls + b.calls);
    CHECK_MSG(g_lines == a.busy + b.busy, "%d HD_ERROR_BUSY lines logged for %d such results", g_lines, a.busy + b.busy);
    CHECK_MSG(a.nonfinite == 0 && b.nonfinite == 0, "non-finite images read back: %d, %d", a.nonfinite, b.nonfinite);
    /* the context is whole */
    CHECK(hd_query_desc(c, &q) == HD_SUCCESS);
    CHECK(hd_render(c) == HD_SUCCESS);
    CHECK(hd_read_image_f32(c, img, (size_t)q.camera.width * q.camera.height * 4) == HD_SUCCESS &&
          g_finite(img, (size_t)q.camera.width * q.camera.height * 4));
    CHECK(hd_destroy(c) == HD_SUCCESS);
}

const hd_test_case hd_tests_guard[] = {
    {"guard: calls from inside the logger", test_guard_from_logger},
    {"guard: two threads on one context", test_guard_two_threads},
};
const int hd_tests_guard_count = sizeof hd_tests_guard / sizeof hd_tests_guard[0];
