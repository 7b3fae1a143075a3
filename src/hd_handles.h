/* hd_handles.h - context handles: a slot index (8 bits) and the slot's generation (24 bits) per
   handle, so a stale handle is caught, not dereferenced. A handle is never valid twice: a slot
   whose generation reaches HD__GEN_MAX is retired, and a new context takes the free slot with the
   lowest generation, so the slots age together: a process can create HD_MAX_CONTEXTS x
   (2^24 - 1) contexts (over 10^9 with the default 64), then hd_create returns
   HD_ERROR_TOO_MANY_CONTEXTS. A destroyed context's logger is never called again: the use of a
   stale handle is reported by its result alone.
   Calls on one context must not overlap: each public call holds its slot's in-call flag
   (HD__GUARDED), so a call that finds it held returns HD_ERROR_BUSY instead of sharing the
   context's state with the call in progress. A call from another thread logs one error line
   from that thread; a call from the thread holding the flag (from inside the context's own
   logger or allocator) logs nothing, as the line would re-enter the logger. The flag is taken
   under the slots' mutex that the handle's lookup holds anyway and dropped by an atomic store.
   Part of the core (src/hd_core.h). */
#include <pthread.h>
#include <sched.h>
#define HD__GEN_MAX 0xffffffu
typedef struct hd__slot {
    hd__ctx *ctx;
    uint32_t generation; /* of the slot's current or last context; HD__GEN_MAX: retired */
    int busy;            /* a call on ctx is in progress (__atomic: set under hd__slots_mu,
                            cleared by hd__leave without it) */
    pthread_t owner;     /* the thread of that call (under hd__slots_mu) */
} hd__slot;
static hd__slot hd__slots[HD_MAX_CONTEXTS];
static pthread_mutex_t hd__slots_mu = PTHREAD_MUTEX_INITIALIZER;

HD__MAYBE_UNUSED static hd__ctx *hd__lookup(hd_context h)
{
    uint32_t slot = (h.id & 0xffu), gen = h.id >> 8;
    hd__ctx *ctx = NULL;
    if (slot == 0 || slot > HD_MAX_CONTEXTS || gen == 0) return NULL;
    pthread_mutex_lock(&hd__slots_mu);
    if (hd__slots[slot - 1].generation == gen) ctx = hd__slots[slot - 1].ctx;
    pthread_mutex_unlock(&hd__slots_mu);
    return ctx;
}

/* A handle for ctx in a free slot, or id 0 when every slot is taken or retired. */
static hd_context hd__slot_take(hd__ctx *ctx)
{
    hd_context h;
    uint32_t s, best = HD_MAX_CONTEXTS;
    h.id = 0;
    pthread_mutex_lock(&hd__slots_mu);
    for (s = 0; s < HD_MAX_CONTEXTS; ++s)
        if (!hd__slots[s].ctx && hd__slots[s].generation < HD__GEN_MAX &&
            (best == HD_MAX_CONTEXTS || hd__slots[s].generation < hd__slots[best].generation))
            best = s;
    if (best < HD_MAX_CONTEXTS) {
        hd__slots[best].ctx = ctx;
        hd__slots[best].generation++;
        /* hd_create holds the new context until it returns (hd__leave) */
        __atomic_store_n(&hd__slots[best].busy, 1, __ATOMIC_RELAXED);
        hd__slots[best].owner = pthread_self();
        h.id = (hd__slots[best].generation << 8) | (best + 1);
    }
    pthread_mutex_unlock(&hd__slots_mu);
    return h;
}

/* Frees h's slot (h resolved by hd__lookup); its generation stays, so h is stale from now on. */
static void hd__slot_release(hd_context h)
{
    pthread_mutex_lock(&hd__slots_mu);
    hd__slots[(h.id & 0xffu) - 1].ctx = NULL;
    __atomic_store_n(&hd__slots[(h.id & 0xffu) - 1].busy, 0, __ATOMIC_RELEASE);
    pthread_mutex_unlock(&hd__slots_mu);
}

/* Resolves h and takes its context's in-call flag: the context, or NULL with *r set to
   HD_ERROR_INVALID_HANDLE or HD_ERROR_BUSY (the one line logged from another thread: call is the
   public call's name). The logger is copied under the mutex and counted in ctx->busy_logs, which
   hd_destroy waits on, so it is never called after hd_destroy returns. */
static hd__ctx *hd__enter(hd_context h, const char *call, hd_result *r)
{
    uint32_t slot = (h.id & 0xffu), gen = h.id >> 8;
    hd__ctx *ctx = NULL, *held = NULL;
    hd__slot *s;
    hd_logger log;
    *r = HD_ERROR_INVALID_HANDLE;
    log.func = NULL;
    log.user_data = NULL;
    if (slot == 0 || slot > HD_MAX_CONTEXTS || gen == 0) return NULL;
    s = &hd__slots[slot - 1];
    pthread_mutex_lock(&hd__slots_mu);
    if (s->generation == gen && s->ctx) {
        if (!__atomic_load_n(&s->busy, __ATOMIC_ACQUIRE)) {
            __atomic_store_n(&s->busy, 1, __ATOMIC_RELAXED);
            s->owner = pthread_self();
            ctx = s->ctx;
            *r = HD_SUCCESS;
        } else {
            *r = HD_ERROR_BUSY;
            if (!pthread_equal(s->owner, pthread_self())) {
                held = s->ctx;
                log = held->vw.log;
                __atomic_add_fetch(&held->busy_logs, 1, __ATOMIC_RELAXED);
            }
        }
    }
    pthread_mutex_unlock(&hd__slots_mu);
    if (held) {
        hd__logf(&log, HD_LOG_ERROR, HD_ERROR_BUSY, __FILE__, __LINE__,
                 "%s: another call on this context is in progress (calls on one context must not overlap)", call);
        __atomic_sub_fetch(&held->busy_logs, 1, __ATOMIC_RELEASE);
    }
    return ctx;
}

/* Drops the in-call flag hd__enter took for h. */
static void hd__leave(hd_context h) { __atomic_store_n(&hd__slots[(h.id & 0xffu) - 1].busy, 0, __ATOMIC_RELEASE); }

/* The body of a public call on a context: `expr` (which sees the context as ctx) with the
   context's in-call flag held, or HD_ERROR_INVALID_HANDLE / HD_ERROR_BUSY. HD__NO_CALL_GUARD
   (bench/hdbench_guard.c only, which measures the guard against it) leaves the lookup alone. */
#ifdef HD__NO_CALL_GUARD
#define HD__GUARDED(h, name, expr) \
    do { \
        hd__ctx *ctx = hd__lookup(h); \
        (void)(name); \
        if (!ctx) return HD_ERROR_INVALID_HANDLE; \
        return (expr); \
    } while (0)
#else
#define HD__GUARDED(h, name, expr) \
    do { \
        hd_result hd__r_; \
        hd__ctx *ctx = hd__enter((h), (name), &hd__r_); \
        if (!ctx) return hd__r_; \
        hd__r_ = (expr); \
        hd__leave(h); \
        return hd__r_; \
    } while (0)
#endif

/* Resolves a handle or returns HD_ERROR_INVALID_HANDLE from the calling function, without the
   in-call flag (the test hooks, src/hd_test_hooks.h; a public call uses HD__GUARDED). */
#define HD__GET_CTX(var, handle) \
    hd__ctx *var; \
    do { \
        var = hd__lookup(handle); \
        if (!var) return HD_ERROR_INVALID_HANDLE; \
    } while (0)
