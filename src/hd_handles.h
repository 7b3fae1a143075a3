/* hd_handles.h - context handles: a slot index (8 bits) and the slot's generation (24 bits) per
   handle, so a stale handle is caught, not dereferenced. A handle is never valid twice: a slot
   whose generation reaches HD__GEN_MAX is retired, and a new context takes the free slot with the
   lowest generation, so the slots age together: a process can create HD_MAX_CONTEXTS x
   (2^24 - 1) contexts (over 10^9 with the default 64), then hd_create returns
   HD_ERROR_TOO_MANY_CONTEXTS. A destroyed context's logger is never called again: the use of a
   stale handle is reported by its result alone. Part of the core (src/hd_core.h). */
#include <pthread.h>
#define HD__GEN_MAX 0xffffffu
typedef struct hd__slot {
    hd__ctx *ctx;
    uint32_t generation; /* of the slot's current or last context; HD__GEN_MAX: retired */
} hd__slot;
static hd__slot hd__slots[HD_MAX_CONTEXTS];
static pthread_mutex_t hd__slots_mu = PTHREAD_MUTEX_INITIALIZER;

static hd__ctx *hd__lookup(hd_context h)
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
    pthread_mutex_unlock(&hd__slots_mu);
}

/* Resolves a handle or returns HD_ERROR_INVALID_HANDLE from the calling function. */
#define HD__GET_CTX(var, handle) \
    hd__ctx *var; \
    do { \
        var = hd__lookup(handle); \
        if (!var) return HD_ERROR_INVALID_HANDLE; \
    } while (0)
