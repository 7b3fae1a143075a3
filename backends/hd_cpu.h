/* hd_cpu.h - the plain-C reference backend: the shared kernels run on a small pthread pool.
   Work is split into rows (x-rows of the grid, image rows); every row is computed by the same
   code whatever thread takes it and no result depends on another row of the same pass, so the
   output is bit-identical for any thread count. This backend is the golden model the GPU
   backends are checked against. */
#include <pthread.h>
#include <unistd.h>
#if defined(__SSE__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 1)
#include <xmmintrin.h>
#define HD__CPU_FTZ 1
#endif

typedef void (*hd__cpu_job)(hd__backend *be, int item);
/* Red-black sweeps per walk through memory (hd__cpu_red_black): by default and at most */
#define HD__CPU_RB_WALK_SWEEPS 2
#define HD__CPU_RB_WALK_SWEEPS_MAX 8
static void hd__cpu_mg_free(const hd__view *vw); /* with the multigrid levels, below */

struct hd__backend {
    const hd__view *vw;
    int nthreads;
    int nworkers;            /* threads started besides the caller's */
    pthread_t *workers;
    pthread_mutex_t mu;
    pthread_cond_t cv_work, cv_done;
    int sync_ready;
    /* the pass being run */
    hd__cpu_job job;
    int items, next, chunk, busy, quit;
    unsigned generation;
    /* buffers */
    float *sig, *E, *phi, *phi2, *img;
    uint16_t *Eh, *phih, *phi2h; /* E, phi, phi2 as binary16 (illumination_precision FLOAT16),
                                    the float pointers then NULL */
    size_t illum_floats;     /* voxels of E (and of phi, phi2) over all channels */
    size_t illum_slots;      /* their elements in the colour layout (hd__split_slots: one padding
                                slot per row when gx is odd), whatever their precision */
    hd__kctx k;
    int parity, jacobi;      /* the diffusion pass being run (red-black: the colour relaxed first) */
    int rb_phases;           /* red-black walks of several sweeps: half-sweeps per walk (4: 2 sweeps) */
    int rb_walk_sweeps;      /* the most sweeps one walk takes (HD__CPU_RB_WALK_SWEEPS; bench/ varies it) */
    const struct hd__cpu_grid *grid; /* the grid the diffusion pass works on */
    struct hd__cpu_mg *mg;   /* multigrid levels (hd_cpu_multigrid.h), NULL until first used */
    /* CD: one light volume per light plus one spare, rotated through them as the ping-pong */
    float **lv;
    int nlv;                 /* lights with a volume (the buffers are nlv + 1) */
    int light;               /* the light of the convection / sum pass being run */
    /* the projection's own inputs (hd__cpu_project_prepare): E + phi summed in the API's
       x-fastest layout, valid while lsum_ok, and the TF table for the current step, rebuilt
       when its inputs change (ptab_key). lsum_ok is cleared by the clears, the test hook's writes and every pass
       that writes E or phi (a frame may come between the parts of a split light iteration) */
    float *lsum, *ptab;
    int lsum_ok, ptab_cap, ptab_n;
    size_t dl_first, dl_end; /* hd__be_direct's range of the list, [dl_first, dl_end) */
    /* the upsample pass's columns (hd__be_upsample): per full-image column its two reduced
       columns and weight, for an image up_w wide from a reduced one up_lw wide */
    int *up_x;
    float *up_wx;
    int up_w, up_lw;
    hd__ptab_key ptab_key;
};

static const char *hd__be_name(void) { return "cpu"; }

/* Denormals flushed to zero (x86 MXCSR FTZ and DAZ) while this backend's threads compute, as GPUs
   compute: a diffusion solve started from phi = 0 spreads through empty space as a front of
   values that underflow, and every operation on a denormal takes a microcode assist (about 3x
   slower first sweeps: docs/DESIGN-CPU.md). The workers set it once;
   the calling thread sets it for each pass and restores its own mode after (hd__cpu_parallel,
   through which every pass runs).
   Other architectures compute with denormals. */
static unsigned hd__cpu_fp_enter(void)
{
#ifdef HD__CPU_FTZ
    unsigned m = _mm_getcsr();
    _mm_setcsr(m | 0x8040u); /* FTZ (bit 15) | DAZ (bit 6) */
    return m;
#else
    return 0;
#endif
}
static void hd__cpu_fp_leave(unsigned m)
{
#ifdef HD__CPU_FTZ
    _mm_setcsr(m);
#else
    (void)m;
#endif
}

/* Takes chunks of the current pass until none is left. */
static void hd__cpu_work(hd__backend *be)
{
    for (;;) {
        int i, end;
        pthread_mutex_lock(&be->mu);
        i = be->next;
        be->next += be->chunk;
        pthread_mutex_unlock(&be->mu);
        if (i >= be->items) break;
        end = i + be->chunk < be->items ? i + be->chunk : be->items;
        for (; i < end; ++i) be->job(be, i);
    }
}

static void *hd__cpu_worker(void *arg)
{
    hd__backend *be = (hd__backend *)arg;
    unsigned seen = 0;
    hd__cpu_fp_enter(); /* this thread's own mode: nothing to restore */
    for (;;) {
        pthread_mutex_lock(&be->mu);
        while (!be->quit && be->generation == seen) pthread_cond_wait(&be->cv_work, &be->mu);
        if (be->quit) { pthread_mutex_unlock(&be->mu); break; }
        seen = be->generation;
        pthread_mutex_unlock(&be->mu);
        hd__cpu_work(be);
        pthread_mutex_lock(&be->mu);
        if (--be->busy == 0) pthread_cond_signal(&be->cv_done);
        pthread_mutex_unlock(&be->mu);
    }
    return NULL;
}

/* Runs job(item) for every item in [0, items) on all threads and returns when all are done. */
static void hd__cpu_parallel(hd__backend *be, hd__cpu_job job, int items)
{
    int chunk = items / (be->nthreads * 16);
    unsigned fp;
    be->job = job;
    be->items = items;
    be->next = 0;
    be->chunk = chunk > 0 ? chunk : 1;
    fp = hd__cpu_fp_enter();
    if (be->nworkers == 0) {
        hd__cpu_work(be);
        hd__cpu_fp_leave(fp);
        return;
    }
    pthread_mutex_lock(&be->mu);
    be->busy = be->nworkers;
    ++be->generation;
    pthread_cond_broadcast(&be->cv_work);
    pthread_mutex_unlock(&be->mu);
    hd__cpu_work(be);
    hd__cpu_fp_leave(fp);
    pthread_mutex_lock(&be->mu);
    while (be->busy > 0) pthread_cond_wait(&be->cv_done, &be->mu);
    pthread_mutex_unlock(&be->mu);
}

/* Frees CD's light volumes. */
static void hd__cpu_free_lights(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int l;
    if (be->lv)
        for (l = 0; l <= be->nlv; ++l) hd__free(vw, be->lv[l]);
    hd__free(vw, be->lv);
    be->lv = NULL;
    be->nlv = 0;
    be->k.lv = NULL;
    be->k.lv2 = NULL;
}

/* A call's bracket: nothing to make current, nothing left in flight (src/hd_backend.h). */
static hd_result hd__be_begin(const hd__view *vw)
{
    (void)vw;
    return HD_SUCCESS;
}
static hd_result hd__be_end(const hd__view *vw, hd_result r)
{
    (void)vw;
    return r;
}

static void hd__be_destroy(hd__view *vw)
{
    hd__backend *be = vw->be;
    int i;
    if (!be) return;
    if (be->sync_ready) {
        pthread_mutex_lock(&be->mu);
        be->quit = 1;
        pthread_cond_broadcast(&be->cv_work);
        pthread_mutex_unlock(&be->mu);
        for (i = 0; i < be->nworkers; ++i) pthread_join(be->workers[i], NULL);
        pthread_cond_destroy(&be->cv_done);
        pthread_cond_destroy(&be->cv_work);
        pthread_mutex_destroy(&be->mu);
    }
    hd__free(vw, be->workers);
    hd__cpu_mg_free(vw);
    hd__free(vw, be->sig);
    hd__free(vw, be->lsum);
    hd__free(vw, be->ptab);
    hd__free(vw, be->up_x);
    hd__free(vw, be->up_wx);
    hd__free(vw, be->E);
    hd__free(vw, be->phi);
    hd__free(vw, be->phi2);
    hd__free(vw, be->Eh);
    hd__free(vw, be->phih);
    hd__free(vw, be->phi2h);
    hd__free(vw, be->img);
    hd__cpu_free_lights(vw);
    hd__free(vw, be);
    vw->be = NULL;
}

static hd_result hd__be_create(hd__view *vw)
{
    hd__backend *be;
    int n = vw->desc.threads, i;
    if (n <= 0) {
        long cores = sysconf(_SC_NPROCESSORS_ONLN);
        n = cores > 0 ? (int)cores : 1;
    }
    if (n > 256) n = 256;
    be = (hd__backend *)hd__calloc(vw, 1, sizeof *be);
    if (!be) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate the backend");
    vw->be = be;
    be->vw = vw;
    be->nthreads = n;
    be->k.p = &vw->kp;
    be->k.vol = vw->vol;
    be->rb_walk_sweeps = HD__CPU_RB_WALK_SWEEPS;
    if (n > 1) {
        be->workers = (pthread_t *)hd__calloc(vw, (size_t)(n - 1), sizeof(pthread_t));
        if (!be->workers) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate %d threads", n);
        if (pthread_mutex_init(&be->mu, NULL) != 0) return HD__ERR(&vw->log, HD_ERROR_BACKEND, "cpu: pthread_mutex_init failed");
        if (pthread_cond_init(&be->cv_work, NULL) != 0) {
            pthread_mutex_destroy(&be->mu);
            return HD__ERR(&vw->log, HD_ERROR_BACKEND, "cpu: pthread_cond_init failed");
        }
        if (pthread_cond_init(&be->cv_done, NULL) != 0) {
            pthread_cond_destroy(&be->cv_work);
            pthread_mutex_destroy(&be->mu);
            return HD__ERR(&vw->log, HD_ERROR_BACKEND, "cpu: pthread_cond_init failed");
        }
        be->sync_ready = 1;
        for (i = 0; i < n - 1; ++i) {
            if (pthread_create(&be->workers[i], NULL, hd__cpu_worker, be) != 0) {
                HD__INFO(&vw->log, "cpu: started %d of %d worker threads", i, n - 1);
                break;
            }
            be->nworkers = i + 1;
        }
        be->nthreads = be->nworkers + 1;
    }
    HD__INFO(&vw->log, "cpu: %d threads", be->nthreads);
    return HD_SUCCESS;
}

/* The volume lives in vw->vol, the TF and majorants in vw: the kernels read them in place. */
static hd_result hd__be_upload_inputs(const hd__view *vw)
{
    vw->be->k.tf = vw->tf;
    vw->be->k.maj = vw->majorant;
    return HD_SUCCESS;
}

/* The projection and the path tracers read the core's copy of the host's depth in place. */
static hd_result hd__be_upload_depth(const hd__view *vw)
{
    vw->be->k.dep = vw->depth;
    return HD_SUCCESS;
}

/* The direct light and the path tracers read the core's environment tables in place. */
static hd_result hd__be_upload_env(const hd__view *vw)
{
    vw->be->k.env = vw->env;
    return HD_SUCCESS;
}

/* hd_update_volume: the kernels read vw->vol and vw->majorant in place, so the core's copy is
   already the backend's. */
static hd_result hd__be_update_volume(const hd__view *vw, const hd__box *vox, const hd__box *cells)
{
    (void)vw; (void)vox; (void)cells;
    return HD_SUCCESS;
}

#define HD__BE_SPLIT_LAYOUT 1 /* sig, E, phi in the colour layout: hd_get_stats counts its padding */

/* Frees an illumination buffer of either precision and clears its pointers. */
static void hd__cpu_free_illum(const hd__view *vw, float **f, uint16_t **h)
{
    hd__free(vw, *f); hd__free(vw, *h);
    *f = NULL; *h = NULL;
}

/* A zeroed illumination buffer of n elements in the context's precision (the other pointer NULL);
   0 when the allocation failed. Zero bits are 0.0 in both precisions. */
static int hd__cpu_alloc_illum(const hd__view *vw, size_t n, float **f, uint16_t **h)
{
    hd__cpu_free_illum(vw, f, h);
    if (vw->params.illumination_precision == HD_PRECISION_FLOAT16) *h = (uint16_t *)hd__calloc(vw, n, sizeof(uint16_t));
    else *f = (float *)hd__calloc(vw, n, sizeof(float));
    return *f != NULL || *h != NULL;
}

/* Points the kernel context at the backend's illumination buffers. */
static void hd__cpu_bind_illum(hd__backend *be)
{
    be->k.E = be->E; be->k.phi = be->phi; be->k.phi2 = be->phi2;
    be->k.Eh = be->Eh; be->k.phih = be->phih; be->k.phi2h = be->phi2h;
    be->k.f16 = be->vw->params.illumination_precision == HD_PRECISION_FLOAT16;
}

/* (Re)allocates sigma_t, E and phi (zeroed) for the current illumination grid, channels and
   precision. illum_floats == 0 frees them: the path tracers keep no illumination grid. */
static hd_result hd__be_alloc_illumination(const hd__view *vw, size_t illum_floats)
{
    hd__backend *be = vw->be;
    size_t slots = hd__split_slots(vw->gdims[0], vw->gdims[1], (size_t)vw->gdims[2] * (size_t)vw->channels);
    int ok;
    hd__free(vw, be->sig);
    be->sig = be->k.sig = NULL;
    hd__free(vw, be->lsum);
    be->lsum = NULL;
    be->lsum_ok = 0;
    hd__cpu_free_illum(vw, &be->E, &be->Eh);
    hd__cpu_free_illum(vw, &be->phi, &be->phih);
    hd__cpu_free_illum(vw, &be->phi2, &be->phi2h);
    hd__cpu_bind_illum(be);
    be->illum_floats = be->illum_slots = 0;
    if (illum_floats == 0) return HD_SUCCESS;
    be->sig = (float *)hd__calloc(vw, hd__split_slots(vw->gdims[0], vw->gdims[1], (size_t)vw->gdims[2] * (size_t)vw->sig_channels),
                                  sizeof(float));
    ok = hd__cpu_alloc_illum(vw, slots, &be->E, &be->Eh);
    ok &= hd__cpu_alloc_illum(vw, slots, &be->phi, &be->phih);
    if (!be->sig || !ok)
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate %zu floats of illumination", slots);
    be->illum_floats = illum_floats;
    be->illum_slots = slots;
    be->k.sig = be->sig;
    hd__cpu_bind_illum(be);
    return HD_SUCCESS;
}

/* Jacobi's second phi buffer, allocated only while the Jacobi solver is selected. */
static hd_result hd__be_alloc_jacobi(const hd__view *vw, int enable)
{
    hd__backend *be = vw->be;
    int ok;
    hd__cpu_free_illum(vw, &be->phi2, &be->phi2h);
    hd__cpu_bind_illum(be);
    if (!enable || be->illum_floats == 0) return HD_SUCCESS;
    ok = hd__cpu_alloc_illum(vw, be->illum_slots, &be->phi2, &be->phi2h);
    hd__cpu_bind_illum(be);
    if (!ok) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate Jacobi's buffer");
    return HD_SUCCESS;
}

static hd_result hd__be_alloc_image(const hd__view *vw, int width, int height, int parts)
{
    hd__backend *be = vw->be;
    float *img = (float *)hd__calloc(vw, hd__image_floats(width, height, parts), sizeof(float));
    if (!img)
        return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate a %dx%d image%s", width, height,
                       hd__image_parts_name(parts));
    hd__free(vw, be->img);
    be->img = be->k.img = img;
    return HD_SUCCESS;
}

static hd_result hd__be_clear(const hd__view *vw, unsigned what)
{
    hd__backend *be = vw->be;
    size_t n = be->illum_slots;
    if (what & (HD__DIRTY_DIRECT | HD__DIRTY_PHI)) be->lsum_ok = 0;
    if ((what & HD__DIRTY_DIRECT) && be->E) memset(be->E, 0, n * sizeof(float));
    if ((what & HD__DIRTY_PHI) && be->phi) memset(be->phi, 0, n * sizeof(float));
    if ((what & HD__DIRTY_PHI) && be->phi2) memset(be->phi2, 0, n * sizeof(float));
    if ((what & HD__DIRTY_DIRECT) && be->Eh) memset(be->Eh, 0, n * sizeof(uint16_t));
    if ((what & HD__DIRTY_PHI) && be->phih) memset(be->phih, 0, n * sizeof(uint16_t));
    if ((what & HD__DIRTY_PHI) && be->phi2h) memset(be->phi2h, 0, n * sizeof(uint16_t));
    if ((what & HD__DIRTY_IMAGE) && be->img)
        memset(be->img, 0, (size_t)vw->kp.image.x * vw->kp.image.y * 4 * sizeof(float));
    return HD_SUCCESS;
}

static void hd__cpu_classify_row(hd__backend *be, int r)
{
    int gx = be->vw->gdims[0], gy = be->vw->gdims[1], x;
    for (x = 0; x < gx; ++x) hdk_classify_voxel(&be->k, x, r % gy, r / gy);
}
/* The direct light's entries [j, end) from the mask's bits, in the list's order (bricks of
   HD__DL_BRICK^3 x fastest, voxels inside them x fastest): from the brick holding entry j (the
   last whose count of entries before it, vw->dl_brick, is at most j) on. */
static void hd__cpu_direct_bits(hd__backend *be, size_t j, size_t end)
{
    const hd__view *vw = be->vw;
    const int *g = vw->gdims, B = HD__DL_BRICK;
    int nbr[3], x, y, z;
    size_t nb = hd__direct_bricks(g, nbr), nbx = (size_t)nbr[0], nby = (size_t)nbr[1], lo = 0, hi = nb, b;
    while (hi - lo > 1) {
        size_t mid = lo + (hi - lo) / 2;
        if (vw->dl_brick[mid] <= j) lo = mid;
        else hi = mid;
    }
    for (b = lo; b < nb && j < end; ++b) {
        size_t n = vw->dl_brick[b]; /* the entry of the brick's next tracked voxel */
        int bx = (int)(b % nbx) * B, by = (int)(b / nbx % nby) * B, bz = (int)(b / (nbx * nby)) * B;
        for (z = bz; z < bz + B && z < g[2] && j < end; ++z)
            for (y = by; y < by + B && y < g[1] && j < end; ++y) {
                size_t k = ((size_t)z * g[1] + y) * g[0] + (size_t)bx;
                for (x = bx; x < bx + B && x < g[0] && j < end; ++x, ++k)
                    if (vw->dl_bits[k >> 3] >> (k & 7) & 1u) {
                        if (n == j) {
                            hdk_direct_index(&be->k, (int)k);
                            ++j;
                        }
                        ++n;
                    }
            }
    }
}

/* Direct light: items of HD__CPU_DIRECT_CHUNK consecutive entries of the tracked voxels: the
   core's list where it made one (the test hook's every voxel), else the mask's bits. */
#define HD__CPU_DIRECT_CHUNK 64
static void hd__cpu_direct_chunk(hd__backend *be, int item)
{
    const hd__view *vw = be->vw;
    size_t j = be->dl_first + (size_t)item * HD__CPU_DIRECT_CHUNK, end = j + HD__CPU_DIRECT_CHUNK;
    if (end > be->dl_end) end = be->dl_end;
    if (!vw->dl_idx) {
        hd__cpu_direct_bits(be, j, end);
        return;
    }
    for (; j < end; ++j) hdk_direct_index(&be->k, (int)vw->dl_idx[j]);
}
/* ---- diffusion -------------------------------------------------------------------------------
   A pass works on be->grid: the illumination grid itself, or a multigrid level
   (hd_cpu_multigrid.h), each with its own kernel context (parameters and buffers).
   sigma_t, E and phi are stored colour by colour (hd_prelude_c.h, hd__split_slot): a row's
   voxels of one colour are contiguous, and so are the voxels of the other colour they read.
   Rows inside the grid in y and z relax their interior voxels of one colour through a loop
   over the packed index id (x = 2 id + cp, cp the x parity of the colour's first voxel): own
   sigma_t and E from the colour's half of the row, the x - 1 / x + 1 neighbours from the other
   colour's half of the row at id - 1 + cp and id + cp, the y +- 1 and z +- 1 neighbours at id in
   the neighbouring rows' halves of the other colour: unit-stride loads, no permutes. The loop
   loads the values itself and hands them to the shared pure functions of hd_k_diffuse.h
   (hdk_diffuse_own_of, hdk_diffuse_box_of / _surface_rhs_of) with rgb, rhs and the boundary as
   literals and every in-grid flag 1, so each variant is a branch-free loop the compiler
   vectorises; the same operations in the same order as hdk_diffuse_terms_loaded, so the same
   bits as the per-voxel path (hdk_diffuse_row). Rows on the grid's faces in y or z (y = 0 or
   gy - 1, z = 0 or gz - 1) take the same loop with their four y/z in-grid flags as run-time
   values (a second copy of each variant; an outside neighbour's loads read the row's own other
   colour instead, and the kernels ignore the values of an outside neighbour), because the
   per-voxel path made those few rows a large share of a sweep; the colour layout spares the
   permutes a stride-2 loop over an x-fastest layout needs for every load (docs/DESIGN-CPU.md
   has both measurements, bench/hdbench_rb_schedule.c reproduces them). The two end
   voxels (the x-1 or x+1 neighbour lies outside the row) go through hd__cpu_voxels, the same loop
   body with every flag at run time, one out-of-line copy per precision. */
#define HD__CPU_ROW_MAX 8192

/* A grid the diffusion passes work on. */
typedef struct hd__cpu_grid {
    const hd__kctx *k;       /* its parameters (gdims, 1/h^2, flags) and buffers */
    float *res;              /* the residual pass's output (multigrid), in the colour layout */
} hd__cpu_grid;

/* HD_SOLVER_MULTIGRID's levels and CG's vectors (their passes: hd_cpu_multigrid.h). */
typedef struct hd__cpu_level {
    hd__kparams kp;          /* the fine parameters with this level's dims, h and the rhs flag */
    hd__kctx k;
    hd__cpu_grid g;
    float *sig;              /* coarse levels only (level 0 reads the backend's sigma_t) */
    float *rhs, *phi;        /* the right-hand side and the correction; level 0: r and z */
    float *res;              /* the residual of this level's equation; level 0: also q = A p */
    int dims[3];
} hd__cpu_level;

struct hd__cpu_mg {
    hd__cpu_level lv[HD__MG_MAX_LEVELS];
    int levels, channels, sig_channels, fine[3];
    int cur;                 /* the level a transfer pass writes (coarse) */
    int colour;              /* the colour ((x + y + z) & 1) hd__cpu_mg_extrap_row writes */
    float *p;                /* CG's search direction (fine grid) */
    float *lo;               /* the iterate's low part: CG's iterate is phi + lo, phi its float
                                rounding (hd__cpu_mg_update_row) */
    hd__kparams opkp;        /* A p: level 0's parameters, E = z (zeroed by then), phi = p */
    hd__kctx opk;
    hd__cpu_grid opg, fineg; /* A p into level 0's res; f - A phi into level 0's rhs (r) */
    double *dot_a, *dot_b;   /* per-row partial sums of the dot products (level 0's rows) */
    double alpha;
    float beta;
};

static void hd__cpu_mg_free(const hd__view *vw)
{
    struct hd__cpu_mg *mg = vw->be->mg;
    int l;
    if (!mg) return;
    for (l = 0; l < mg->levels; ++l) {
        hd__free(vw, mg->lv[l].sig);
        hd__free(vw, mg->lv[l].rhs);
        hd__free(vw, mg->lv[l].phi);
        hd__free(vw, mg->lv[l].res);
    }
    hd__free(vw, mg->p);
    hd__free(vw, mg->lo);
    hd__free(vw, mg->dot_a);
    hd__free(vw, mg->dot_b);
    hd__free(vw, mg);
    vw->be->mg = NULL;
}

static int hd__cpu_row_variant(const hd__kctx *K)
{
    int f = K->p->counts.z;
    return ((f & HD_FLAG_RGB_SCATTERING) ? 1 : 0) | ((f & HD_FLAG_DIFFUSE_RHS) ? 2 : 0) |
           ((f & HD_FLAG_SURFACE_BOUNDARY) ? 4 : 0);
}

/* HD__CPU_FLATTEN: every call inside inlined, so each variant's loop is one body the compiler
   can vectorise (with both precisions GCC 12 stopped inlining the terms into half the loops).
   HYBRIDDIFF_FAST_COMPILE (the user's, before the implementation) drops it and HD__CPU_INLINE's
   always_inline, and (HD__CPU_ROW_LOOPS 0) relaxes every row through the kernels' per-voxel path
   (hdk_diffuse_row, hdk_diffuse_residual): the same bits, the implementation compiled in half
   the time (1.4-1.5x stb_image.h's at -O2), the diffusion 5-10x slower (docs/PERFORMANCE.md,
   "Compile time"). */
#if (defined(__GNUC__) || defined(__clang__)) && !defined(HYBRIDDIFF_FAST_COMPILE)
#define HD__CPU_INLINE static inline __attribute__((always_inline))
#define HD__CPU_FLATTEN __attribute__((flatten))
#else
#define HD__CPU_INLINE static inline
#define HD__CPU_FLATTEN
#endif
#ifdef HYBRIDDIFF_FAST_COMPILE
#define HD__CPU_ROW_LOOPS 0
#else
#define HD__CPU_ROW_LOOPS 1
#endif
#if defined(__GNUC__) || defined(__clang__)
#define HD__CPU_NOINLINE __attribute__((noinline))
#else
#define HD__CPU_NOINLINE
#endif

/* Voxels of x parity xpar in a row of gx voxels: the length of that colour's half-row. */
static int hd__cpu_half_len(int gx, int xpar) { return (gx - xpar + 1) >> 1; }

/* Where one colour of row (y, z) of channel c finds its values: the start of each half-row, as
   slots (hd__split_slot of the half's first voxel). Index 0: the row's own colour (x parity x0);
   1: the other colour of the same row (the x-neighbours); 2, 3: the rows y - 1, y + 1 and 4, 5:
   the slices z - 1, z + 1, at the same x (their halves of the other colour). s: sigma_t, a: its
   RGB albedo channel 1 + c, p: E, phi and phi2 (channel c). */
typedef struct hd__cpu_rows {
    size_t s[6], a[6], p[6];
} hd__cpu_rows;

static void hd__cpu_rows_of(const hd__kctx *K, int y, int z, int c, int x0, hd__cpu_rows *o)
{
    static const int dy[6] = {0, 0, -1, 1, 0, 0}, dz[6] = {0, 0, 0, 0, -1, 1};
    int gx = K->p->gdims.x, gy = K->p->gdims.y, gz = K->p->gdims.z, j;
    for (j = 0; j < 6; ++j) {
        int xp = j == 1 ? x0 ^ 1 : x0, yy = y + dy[j], zj = z + dz[j];
        o->s[j] = hd__split_slot(gx, gy, xp, yy, zj);
        o->a[j] = hd__split_slot(gx, gy, xp, yy, zj + (1 + c) * gz);
        o->p[j] = hd__split_slot(gx, gy, xp, yy, zj + c * gz);
    }
}

/* An edge row's rows outside the grid (in[j - 2] == 0 for j = 2 .. 5: y - 1, y + 1, z - 1, z + 1)
   read the row's other colour (j = 1) instead: valid memory, whose values the kernels ignore there. */
static void hd__cpu_rows_clip(hd__cpu_rows *o, int iym, int iyp, int izm, int izp)
{
    const int in[4] = {iym, iyp, izm, izp};
    int j;
    for (j = 2; j < 6; ++j)
        if (!in[j - 2]) {
            o->s[j] = o->s[1];
            o->a[j] = o->a[1];
            o->p[j] = o->p[1];
        }
}

/* hd__cpu_rows_of with an edge row's outside rows clipped (the in-grid flags literal 1s in
   interior rows, where the test folds away). */
HD__CPU_INLINE void hd__cpu_rows_at(const hd__kctx *K, int y, int z, int c, int x0, int iym, int iyp, int izm, int izp,
                                    hd__cpu_rows *o)
{
    hd__cpu_rows_of(K, y, z, c, x0, o);
    if (!(iym && iyp && izm && izp)) hd__cpu_rows_clip(o, iym, iyp, izm, izp);
}

/* Whether row (y, z) lies on a face of the grid in y or z (an edge row). */
static int hd__cpu_edge_row(const hd__kparams *p, int y, int z)
{
    return y == 0 || y == p->gdims.y - 1 || z == 0 || z == p->gdims.z - 1;
}

/* E, phi or phi2 at slot o in K's storage precision (K->f16 a literal in the row loops). */
#define HD__CPU_LD(buf, o) (K->f16 != 0 ? hdk_h2f(K->buf##h[(o)]) : K->buf[(o)])

/* sigma' of a neighbour with sigma_t st and RGB albedo channel sc: hdk_diffuse_sigp on loaded
   values (ag: 1 - albedo g of the grey albedo, used without RGB scattering). */
HD__CPU_INLINE float hd__cpu_nb_sigp(const hd__kctx *K, float st, float sc, int rgb, float ag)
{
    return rgb != 0 ? hdk_diffuse_sigp_of(K, st, hdk_diffuse_albedo_of(K, sc, rgb)) : ag * st;
}

/* The voxels id = lo .. hi of one colour of a row (offsets o, x parity cp) into out[id]: num / den,
   or with residual the residual num - den phi. rgb, rhs, surface and residual are literals at
   every call (HD__CPU_COLOUR_SWITCH), so the loop has no test; so are the in-grid flags iym, iyp,
   izm, izp of the y-1, y+1, z-1, z+1 rows (1) except in edge rows, and (ends 0) the x-1 and x+1
   ones. ends 1: the x in-grid flags per voxel, for the row's end voxels; an outside neighbour's
   loads then read the inside one's slot, whose value the kernels ignore (a slot past the
   half-row may lie past the buffer or in a row another thread is writing). */
HD__CPU_INLINE void hd__cpu_colour_loop(const hd__kctx *K, const hd__cpu_rows *o, int lo, int hi, int cp, float *out,
                                        int rgb, int rhs, int surface, int residual, int ends, int iym, int iyp,
                                        int izm, int izp)
{
    const float *sg = K->sig;
    const size_t *s = o->s, *a = o->a, *p = o->p;
    int id, gx = K->p->gdims.x;
    for (id = lo; id <= hi; ++id) {
        int x = 2 * id + cp, ixm = !ends || x > 0, ixp = !ends || x < gx - 1;
        int xm = id - 1 + cp + !ixm, xq = id + cp - !ixp;
        float sp, dn, den, num;
        float st = sg[s[0] + id], al = hdk_diffuse_albedo_of(K, rgb != 0 ? sg[a[0] + id] : 0.0f, rgb);
        float ag = hdk_diffuse_ag(K, al);
        num = hdk_diffuse_own_of(K, st, al, HD__CPU_LD(E, p[0] + id), rhs, &sp, &dn);
#define HD__CPU_NB(j, i) hd__cpu_nb_sigp(K, sg[s[j] + (i)], rgb != 0 ? sg[a[j] + (i)] : 0.0f, rgb, ag)
        if (surface)
            num = hdk_diffuse_surface_rhs_of(K, rhs, num, dn, sp, HD__CPU_NB(1, xm), HD__CPU_NB(1, xq),
                                            HD__CPU_NB(2, id), HD__CPU_NB(3, id), HD__CPU_NB(4, id), HD__CPU_NB(5, id),
                                            HD__CPU_LD(phi, p[1] + xm), HD__CPU_LD(phi, p[1] + xq),
                                            HD__CPU_LD(phi, p[2] + id), HD__CPU_LD(phi, p[3] + id),
                                            HD__CPU_LD(phi, p[4] + id), HD__CPU_LD(phi, p[5] + id), ixm, ixp, iym, iyp,
                                            izm, izp, &den);
        else
            num = hdk_diffuse_box_of(K, num, dn, sp, HD__CPU_NB(1, xm), HD__CPU_NB(1, xq), HD__CPU_NB(2, id),
                                    HD__CPU_NB(3, id), HD__CPU_NB(4, id), HD__CPU_NB(5, id),
                                    HD__CPU_LD(phi, p[1] + xm), HD__CPU_LD(phi, p[1] + xq),
                                    HD__CPU_LD(phi, p[2] + id), HD__CPU_LD(phi, p[3] + id),
                                    HD__CPU_LD(phi, p[4] + id), HD__CPU_LD(phi, p[5] + id), ixm, ixp, iym, iyp, izm,
                                    izp, &den);
#undef HD__CPU_NB
        out[id] = residual ? num - den * HD__CPU_LD(phi, p[0] + id) : num / den;
    }
}

/* Voxels id = lo .. hi of one colour of a row into out[id], as hd__cpu_colour_loop's, with every
   flag at run time (the x in-grid flags per voxel): the row's end voxels and the variants no loop
   is compiled for (HD__CPU_COLOUR_SWITCH). One out-of-line copy per storage precision, shared by
   every variant: each variant's own inlined copies of its end voxels were most of the backend's
   compile time (docs/PERFORMANCE.md, "Compile time"). */
static HD__CPU_NOINLINE HD__CPU_FLATTEN void hd__cpu_voxels(const hd__kctx *K, const hd__cpu_rows *o, int x0, int lo,
                                                            int hi, int residual, int iym, int iyp, int izm, int izp,
                                                            float *out)
{
    int f = K->p->counts.z, rgb = (f & HD_FLAG_RGB_SCATTERING) != 0, rhs = (f & HD_FLAG_DIFFUSE_RHS) != 0;
    int surface = (f & HD_FLAG_SURFACE_BOUNDARY) != 0;
    hd__kctx k = *K;
    if (k.f16) {
        k.f16 = 1;
        hd__cpu_colour_loop(&k, o, lo, hi, x0, out, rgb, rhs, surface, residual, 1, iym, iyp, izm, izp);
    } else {
        k.f16 = 0;
        hd__cpu_colour_loop(&k, o, lo, hi, x0, out, rgb, rhs, surface, residual, 1, iym, iyp, izm, izp);
    }
}

/* Whether variant v's loop (hd__cpu_row_variant: rgb | rhs << 1 | surface << 2) is compiled for the
   pass (residual) and storage precision (K->f16), both literals where it is used: the combinations
   the library runs. HD_FLAG_DIFFUSE_RHS comes only with the multigrid solver's levels, which are
   float32 and the only grids the residual pass runs on; the others go through hd__cpu_voxels. */
#define HD__CPU_VARIANT_BUILT(v, residual) (((v) & 2) != 0 ? !K->f16 : !(residual))
/* One case of the variant switch: the interior voxels' loop with rgb, rhs and the boundary
   literal (and the y/z in-grid flags ym .. zp: literal 1s in interior rows). */
#define HD__CPU_COLOUR_CASE(rgb, rhs, surface, residual, ym, yp, zm, zp)                             \
    do {                                                                                            \
        if (HD__CPU_VARIANT_BUILT((rgb) | (rhs) << 1, residual))                                     \
            hd__cpu_colour_loop(K, &o, 1 - x0, (gx - 2 - x0) >> 1, x0, out, rgb, rhs, surface, residual, 0, ym, yp, \
                                zm, zp);                                                            \
        else                                                                                        \
            hd__cpu_voxels(K, &o, x0, 1 - x0, (gx - 2 - x0) >> 1, residual, ym, yp, zm, zp, out);      \
    } while (0)
/* The switch, then the row's end voxels x = 0 (if of this colour) and x = gx - 1 (if so). */
#define HD__CPU_COLOUR_SWITCH(residual, ym, yp, zm, zp)                                              \
    switch (hd__cpu_row_variant(K)) {                                                               \
    case 0: HD__CPU_COLOUR_CASE(0, 0, 0, residual, ym, yp, zm, zp); break;                         \
    case 1: HD__CPU_COLOUR_CASE(1, 0, 0, residual, ym, yp, zm, zp); break;                         \
    case 2: HD__CPU_COLOUR_CASE(0, 1, 0, residual, ym, yp, zm, zp); break;                         \
    case 3: HD__CPU_COLOUR_CASE(1, 1, 0, residual, ym, yp, zm, zp); break;                         \
    case 4: HD__CPU_COLOUR_CASE(0, 0, 1, residual, ym, yp, zm, zp); break;                         \
    case 5: HD__CPU_COLOUR_CASE(1, 0, 1, residual, ym, yp, zm, zp); break;                         \
    case 6: HD__CPU_COLOUR_CASE(0, 1, 1, residual, ym, yp, zm, zp); break;                         \
    default: HD__CPU_COLOUR_CASE(1, 1, 1, residual, ym, yp, zm, zp); break;                        \
    }                                                                                               \
    if (x0 == 0) hd__cpu_voxels(K, &o, x0, 0, 0, residual, ym, yp, zm, zp, out);                     \
    if (((gx - 1 - x0) & 1) == 0)                                                                   \
        hd__cpu_voxels(K, &o, x0, (gx - 1) >> 1, (gx - 1) >> 1, residual, ym, yp, zm, zp, out);

/* Relaxes the voxels of x parity x0 of row (y, z) of channel c (3 <= gx) into phi (red-black: in
   place, the colour reads only the other one) or phi2 (Jacobi): computed into a local half-row,
   then stored contiguously (a store through K's pointers inside the loop might alias its loads,
   which would keep the compiler from vectorising it). iym, iyp, izm, izp: whether the rows y - 1,
   y + 1, z - 1, z + 1 lie in the grid (literal 1s for interior rows). */
HD__CPU_INLINE void hd__cpu_relax_colour(const hd__kctx *K, int y, int z, int c, int x0, int jacobi, int iym, int iyp,
                                         int izm, int izp)
{
    int gx = K->p->gdims.x, n = hd__cpu_half_len(gx, x0), i;
    float out[HD__CPU_ROW_MAX / 2 + 1];
    hd__cpu_rows o;
    hd__cpu_rows_at(K, y, z, c, x0, iym, iyp, izm, izp, &o);
    HD__CPU_COLOUR_SWITCH(0, iym, iyp, izm, izp)
    if (K->f16) {
        uint16_t *dst = (jacobi ? K->phi2h : K->phih) + o.p[0];
        for (i = 0; i < n; ++i) dst[i] = hdk_f2h_sat(out[i]);
    } else {
        memcpy((jacobi ? K->phi2 : K->phi) + o.p[0], out, (size_t)n * sizeof(float));
    }
}

/* Relaxes row (y, z) of channel c: red-black its colour `parity` (voxels with x + y + z + parity
   even), Jacobi (be->jacobi) both colours into phi2; the in-grid flags as hd__cpu_relax_colour's. */
HD__CPU_INLINE void hd__cpu_diffuse_row_k(hd__backend *be, const hd__kctx *K, int y, int z, int c, int parity, int iym,
                                          int iyp, int izm, int izp)
{
    /* one call site: every inlined copy of the loops is compiled once per row function (with three,
       the CPU backend took twice as long to compile) */
    int first = be->jacobi ? 0 : (y + z + parity) & 1, last = be->jacobi ? 1 : first, x0;
    for (x0 = first; x0 <= last; ++x0) hd__cpu_relax_colour(K, y, z, c, x0, be->jacobi, iym, iyp, izm, izp);
}

/* The row on a copy of the grid's kernel context whose storage precision (f16) is a literal:
   the compiler drops the kernels' per-load precision test (hd_prelude_c.h's HD_GET) from each
   inlined copy, so the float32 loop is the loop it was and the binary16 one converts inline. */
#define HD__CPU_ROW_ON_COPY(iym, iyp, izm, izp)                                                       \
    do {                                                                                            \
        hd__kctx k = *be->grid->k;                                                                  \
        if (k.f16) { k.f16 = 1; hd__cpu_diffuse_row_k(be, &k, y, z, c, parity, iym, iyp, izm, izp); }  \
        else { k.f16 = 0; hd__cpu_diffuse_row_k(be, &k, y, z, c, parity, iym, iyp, izm, izp); }        \
    } while (0)

/* A row on a face of the grid in y or z: the loops with run-time in-grid flags, out of line so
   the interior rows' function keeps only the loops with literal ones. */
static HD__CPU_NOINLINE HD__CPU_FLATTEN void hd__cpu_diffuse_edge_row(hd__backend *be, int y, int z, int c,
                                                                      int parity)
{
    int gy = be->grid->k->p->gdims.y, gz = be->grid->k->p->gdims.z;
    HD__CPU_ROW_ON_COPY(y > 0, y < gy - 1, z > 0, z < gz - 1);
}

/* The per-voxel sweep of a row under 3 voxels (of every row without HD__CPU_ROW_LOOPS), out of
   line: the flattened row function would otherwise carry an inlined copy of it. */
static HD__CPU_NOINLINE void hd__cpu_diffuse_row_short(const hd__kctx *K, int y, int z, int c, int parity, int jacobi)
{
    hdk_diffuse_row(K, y, z, c, parity, jacobi);
}

static HD__CPU_FLATTEN void hd__cpu_diffuse_row_at(hd__backend *be, int y, int z, int c, int parity)
{
    const hd__kparams *p = be->grid->k->p;
    if (!HD__CPU_ROW_LOOPS || p->gdims.x < 3) {
        hd__cpu_diffuse_row_short(be->grid->k, y, z, c, parity, be->jacobi);
        return;
    }
    if (hd__cpu_edge_row(p, y, z)) {
        hd__cpu_diffuse_edge_row(be, y, z, c, parity);
        return;
    }
    HD__CPU_ROW_ON_COPY(1, 1, 1, 1);
}

/* Jacobi's schedule: blocks of HD__CPU_BLOCK_ROWS rows (y) per work item, each walked through
   every z in order, so the rows a row reads (y +- 1, z +- 1) are the ones just used: 3 planes of
   a block (about 16 KB per plane and buffer at 256 voxels a row) stay in L2 instead of streaming
   whole planes through L3. Jacobi writes phi2 only, so blocks never race. */
#define HD__CPU_BLOCK_ROWS 16
/* Blocks per channel: HD__CPU_BLOCK_ROWS rows each, the last one taking the remainder. */
static int hd__cpu_blocks(const hd__backend *be)
{
    return (be->grid->k->p->gdims.y + HD__CPU_BLOCK_ROWS - 1) / HD__CPU_BLOCK_ROWS;
}

/* Item r = c * blocks + b: every row of block b of channel c (Jacobi). */
static void hd__cpu_diffuse_block(hd__backend *be, int r)
{
    int gy = be->grid->k->p->gdims.y, gz = be->grid->k->p->gdims.z, nb = hd__cpu_blocks(be);
    int b = r % nb, c = r / nb, y0 = b * HD__CPU_BLOCK_ROWS, y1 = b == nb - 1 ? gy : y0 + HD__CPU_BLOCK_ROWS, y, z;
    for (z = 0; z < gz; ++z)
        for (y = y0; y < y1; ++y) hd__cpu_diffuse_row_at(be, y, z, c, 0);
}

/* ---- red-black: both colours in one walk through z ------------------------------------------
   A red-black sweep relaxes the first colour from the second's old values, then the second from
   the first's new ones. Both fit in one walk through z: at step z the first colour in plane z,
   then the second in plane z - 1, whose first-colour neighbours (planes z - 2 .. z) are all new
   by then, while the first colour in plane z read the second's plane z - 1 before it changed. So
   each plane streams through the caches once per sweep instead of once per colour (faster per
   sweep on the head CT: docs/DESIGN-CPU.md, `make bench-rb-schedule`). The same updates from the
   same values as
   relaxing colour by colour: the same bits, for any block size and thread count.
   Threads take blocks of rows (y). Rows beside a block's edge depend on the next block's, so a
   sweep is two parallel passes:
   1. each block [a, e) walks z relaxing the first colour in rows [a, e - 1) and the second in
      rows [a + 1, e - 2), one plane behind. The first colour in row a reads the second in rows
      a - 1 and a, which only pass 2 relaxes (old values, as it must); the second colour in rows
      up to e - 3 reads first-colour rows up to e - 2, all relaxed in this walk by then.
   2. each seam s (every block's start a, and gy) walks z relaxing the first colour in row s - 1
      and the second in rows s - 2, s - 1 and s, one plane behind: their first-colour rows s - 3,
      s and s + 1 were relaxed in pass 1, row s - 1 in this walk.
   Every row of each colour is relaxed once. With blocks of 4 rows or more no item writes a row
   another item of its pass reads (a row's vector loads read its neighbour rows whole), so there
   is no data race; grids of fewer than 4 rows go colour by colour on one thread. */
#define HD__CPU_RB_ROWS_MAX 32
/* Rows per block: 2 blocks per thread and channel where that leaves 8 rows or more (multigrid's
   coarse levels), at most HD__CPU_RB_ROWS_MAX (10 planes of a block's rows, about 340 KB at 256
   voxels a row, stay in L2). */
static int hd__cpu_rb_rows_per_block(const hd__backend *be)
{
    int rows = be->grid->k->p->gdims.y / (2 * be->nthreads);
    return rows > HD__CPU_RB_ROWS_MAX ? HD__CPU_RB_ROWS_MAX : rows < 8 ? 8 : rows;
}
/* Blocks per channel, the last one taking the remainder (a remainder under 4 rows joins the block
   before it); 0 for grids of fewer than 4 rows. */
static int hd__cpu_rb_blocks(const hd__backend *be)
{
    int gy = be->grid->k->p->gdims.y, rows = hd__cpu_rb_rows_per_block(be), nb = (gy + rows - 1) / rows;
    if (gy < 4) return 0;
    return nb > 1 && gy - (nb - 1) * rows < 4 ? nb - 1 : nb;
}

/* Relaxes colour `parity` in rows [ya, yb) of plane z of channel c, clipped to the grid. */
static void hd__cpu_rb_rows(hd__backend *be, int parity, int ya, int yb, int z, int c)
{
    int gy = be->grid->k->p->gdims.y, y;
    if (z < 0 || z >= be->grid->k->p->gdims.z) return;
    for (y = ya > 0 ? ya : 0; y < yb && y < gy; ++y) hd__cpu_diffuse_row_at(be, y, z, c, parity);
}

/* One walk through z of channel c: the first colour (be->parity) in rows [fa, fb) of plane z,
   then the second in rows [sa, sb) of plane z - 1. */
static void hd__cpu_rb_walk(hd__backend *be, int c, int fa, int fb, int sa, int sb)
{
    int z;
    for (z = 0; z <= be->grid->k->p->gdims.z; ++z) {
        hd__cpu_rb_rows(be, be->parity, fa, fb, z, c);
        hd__cpu_rb_rows(be, be->parity ^ 1, sa, sb, z - 1, c);
    }
}

/* Pass 1, item r = c * blocks + b: block b of channel c. */
static void hd__cpu_rb_block(hd__backend *be, int r)
{
    int gy = be->grid->k->p->gdims.y, nb = hd__cpu_rb_blocks(be), rows = hd__cpu_rb_rows_per_block(be);
    int b = r % nb, a = b * rows, e = b == nb - 1 ? gy : a + rows;
    hd__cpu_rb_walk(be, r / nb, a, e - 1, a + 1, e - 2);
}

/* Pass 2, item r = c * (blocks + 1) + b: the seam at block b's start (b = blocks: at gy). */
static void hd__cpu_rb_seam(hd__backend *be, int r)
{
    int nb = hd__cpu_rb_blocks(be), b = r % (nb + 1), s = b == nb ? be->grid->k->p->gdims.y : b * hd__cpu_rb_rows_per_block(be);
    hd__cpu_rb_walk(be, r / (nb + 1), s - 1, s, s - 2, s + 1);
}

/* ---- red-black: several sweeps in one walk through z (temporal blocking) --------------------
   One walk of the schedule above streams sigma_t, E and phi once per sweep (16 B a voxel); a
   walk of T sweeps streams them once for T sweeps (a small gain where the grid fits the L3:
   docs/DESIGN-CPU.md): its 2T half-sweeps ("phases" k = 0 .. 2T - 1, colour first ^ (k & 1))
   follow each other through z, phase k in plane z - k at step z. Phase k of a row reads the other
   colour (phase k - 1's) in rows y - 1 .. y + 1 of planes z - k - 1 .. z - k + 1 and must see
   exactly what the sweeps one after another give it: phase k - 1 done there, phase k + 1 not.
   In z: phase k - 1 did planes up to z - k + 1 by step z (plane z - k + 1 earlier in this step,
   as k ascends), and phase k + 1 has done planes up to z - k - 2 only (plane z - k - 1 later in
   this step). So lags of one plane per phase are exact, for any number of phases.
   In y the rows of a phase must lie inside the rows the previous phase has done, so a block's
   rows shrink by one per phase on each side with a neighbour block, and the seams between blocks
   take the rest in a second pass:
   1. block [a, e) walks phase k in rows [a + k, e - k) (no shrink at y = 0 or gy: no neighbour).
      Phase k >= 1 reads rows [a + k - 1, e - k + 1): phase k - 1's. Phase 0 reads the second
      colour in rows a - 1 and e, which no block writes in this pass (the blocks beside write that
      colour from rows a - 2 and e + 1 on): their values from before the walk, as it must.
   2. after pass 1, row y within P = 2T rows of a seam s (a block's start, s > 0) has done phases
      0 .. d(y) - 1: d = s - y below the seam (the block below reached row s - 1 - k in phase k),
      d = y - s + 1 above it (the block above started phase k at s + k). The seam walks phase k
      (k >= 1) in rows [s - k, s + k), all rows with d <= k, in the same z lags. Phase k there
      reads rows [s - k - 1, s + k + 1): inside the band phase k - 1 is done in this walk (plane
      z - k + 1 earlier in this step), at its ends d(s - k - 1) = d(s + k) = k + 1 and
      d(s - k) = d(s + k - 1) = k, so phase k - 1 is done there and phase k + 1 not.
   Every phase relaxes every row once, each from the values the sweeps one after another give it:
   the same bits for any block size, thread count and T. Races: in pass 1 a block writes rows
   [a, e) and reads [a - 1, e]; it writes only the first colour of row e - 1 and the block above
   reads only the second colour of it (and likewise at a - 1), halves that lie apart in the
   colour layout. A seam writes rows [s - P + 1, s + P - 1) and reads one row more on each side,
   so two seams share no row when interior blocks have 2P - 1 rows or more (P = 4: 7, blocks are
   8 or more); a walk of more sweeps than that allows takes fewer. An odd sweep left over (and
   every sweep of grids under 4 rows) goes through the single-sweep schedule above. */
/* The most sweeps (<= t) one walk can take on be->grid: blocks between two seams (every block but
   the first and the last when there are 3 or more) need 4 t - 1 rows. */
static int hd__cpu_rb_walk_fit(const hd__backend *be, int t)
{
    int nb = hd__cpu_rb_blocks(be), rows = hd__cpu_rb_rows_per_block(be);
    if (nb == 0) return 1;
    while (t > 1 && nb >= 3 && rows < 4 * t - 1) --t;
    return t;
}

/* One walk of be->rb_phases half-sweeps through z of channel c: phase k (colour be->parity ^ k)
   in rows [lo[k], hi[k]) of plane z - k at step z. */
static void hd__cpu_rb_phases(hd__backend *be, int c, const int *lo, const int *hi)
{
    int P = be->rb_phases, z, k;
    for (z = 0; z < be->grid->k->p->gdims.z + P - 1; ++z)
        for (k = 0; k < P; ++k) hd__cpu_rb_rows(be, be->parity ^ (k & 1), lo[k], hi[k], z - k, c);
}

/* Pass 1 of a walk of several sweeps, item r = c * blocks + b: block b of channel c. */
static void hd__cpu_rb_tblock(hd__backend *be, int r)
{
    int gy = be->grid->k->p->gdims.y, nb = hd__cpu_rb_blocks(be), rows = hd__cpu_rb_rows_per_block(be);
    int b = r % nb, a = b * rows, e = b == nb - 1 ? gy : a + rows, k;
    int lo[2 * HD__CPU_RB_WALK_SWEEPS_MAX], hi[2 * HD__CPU_RB_WALK_SWEEPS_MAX];
    for (k = 0; k < be->rb_phases; ++k) {
        lo[k] = a > 0 ? a + k : a;
        hi[k] = e < gy ? e - k : e;
    }
    hd__cpu_rb_phases(be, r / nb, lo, hi);
}

/* Pass 2, item r = c * (blocks - 1) + b - 1: the seam at block b's start (b >= 1). */
static void hd__cpu_rb_tseam(hd__backend *be, int r)
{
    int nb = hd__cpu_rb_blocks(be), s = (r % (nb - 1) + 1) * hd__cpu_rb_rows_per_block(be), k;
    int lo[2 * HD__CPU_RB_WALK_SWEEPS_MAX], hi[2 * HD__CPU_RB_WALK_SWEEPS_MAX];
    for (k = 0; k < be->rb_phases; ++k) {
        lo[k] = s - k;
        hi[k] = s + k;
    }
    hd__cpu_rb_phases(be, r / (nb - 1), lo, hi);
}

/* One sweep of a grid under 4 rows, colour by colour on one thread (item 0; no blocks). */
static void hd__cpu_rb_small(hd__backend *be, int r)
{
    int h, c, z;
    (void)r;
    for (h = 0; h < 2; ++h)
        for (c = 0; c < be->grid->k->p->gdims.w; ++c)
            for (z = 0; z < be->grid->k->p->gdims.z; ++z) hd__cpu_rb_rows(be, be->parity ^ h, 0, 4, z, c);
}

/* Red-black sweeps on be->grid, the colour `first` first (multigrid's post-smoothing runs the
   adjoint order, black first): walks of up to be->rb_walk_sweeps sweeps, the rest one by one. */
static void hd__cpu_red_black(hd__backend *be, int sweeps, int first)
{
    int nb = hd__cpu_rb_blocks(be), ch = be->grid->k->p->gdims.w, s = 0;
    be->jacobi = 0;
    be->parity = first;
    while (s < sweeps) {
        int t = sweeps - s < be->rb_walk_sweeps ? sweeps - s : be->rb_walk_sweeps;
        t = hd__cpu_rb_walk_fit(be, t > HD__CPU_RB_WALK_SWEEPS_MAX ? HD__CPU_RB_WALK_SWEEPS_MAX : t < 1 ? 1 : t);
        if (t > 1) {
            be->rb_phases = 2 * t;
            hd__cpu_parallel(be, hd__cpu_rb_tblock, nb * ch);
            if (nb > 1) hd__cpu_parallel(be, hd__cpu_rb_tseam, (nb - 1) * ch);
        } else if (nb > 0) {
            hd__cpu_parallel(be, hd__cpu_rb_block, nb * ch);
            hd__cpu_parallel(be, hd__cpu_rb_seam, (nb + 1) * ch);
        } else {
            hd__cpu_parallel(be, hd__cpu_rb_small, 1);
        }
        s += t;
    }
}

/* The residual f - A phi of row (y, z) of channel c of be->grid into its res, in the colour layout
   (float32 grids: multigrid's): each colour's half-row through the sweep's loop
   (hd__cpu_colour_loop with residual), written to a local half-row first (stores through res
   might alias the loads, which would keep the compiler from vectorising the loop); the in-grid
   flags as hd__cpu_relax_colour's. */
HD__CPU_INLINE void hd__cpu_residual_halves(hd__backend *be, int y, int z, int c, int iym, int iyp, int izm, int izp)
{
    hd__kctx k = *be->grid->k; /* f16 a literal 0: no per-load precision test in the loop */
    const hd__kctx *K = &k;
    int gx = K->p->gdims.x, x0;
    k.f16 = 0;
    for (x0 = 0; x0 < 2; ++x0) {
        float out[HD__CPU_ROW_MAX / 2 + 1];
        hd__cpu_rows o;
        hd__cpu_rows_at(K, y, z, c, x0, iym, iyp, izm, izp, &o);
        HD__CPU_COLOUR_SWITCH(1, iym, iyp, izm, izp)
        memcpy(be->grid->res + o.p[0], out, (size_t)hd__cpu_half_len(gx, x0) * sizeof(float));
    }
}

/* An edge row's residual (a face of the grid in y or z), out of line as hd__cpu_diffuse_edge_row. */
static HD__CPU_NOINLINE HD__CPU_FLATTEN void hd__cpu_residual_edge_row(hd__backend *be, int y, int z, int c)
{
    int gy = be->grid->k->p->gdims.y, gz = be->grid->k->p->gdims.z;
    hd__cpu_residual_halves(be, y, z, c, y > 0, y < gy - 1, z > 0, z < gz - 1);
}

/* The per-voxel residual of row (y, z) of channel c, out of line as hd__cpu_diffuse_row_short. */
static HD__CPU_NOINLINE void hd__cpu_residual_voxels(hd__backend *be, int y, int z, int c)
{
    const hd__kctx *K = be->grid->k;
    int gx = K->p->gdims.x, gy = K->p->gdims.y, gz = K->p->gdims.z, x;
    float rhs;
    for (x = 0; x < gx; ++x)
        be->grid->res[hd__split_slot(gx, gy, x, y, z + c * gz)] = hdk_diffuse_residual(K, x, y, z, c, &rhs);
}

/* Row r = (c * gz + z) * gy + y. The per-voxel path (hdk_diffuse_residual) where the loop does not
   apply (or without HD__CPU_ROW_LOOPS): rows under 3 voxels, and edge rows under the surface boundary without rhs, whose empty
   voxels hdk_diffuse_residual gives residual 0 (the V-cycle's grids all solve with rhs). */
static HD__CPU_FLATTEN void hd__cpu_residual_row(hd__backend *be, int r)
{
    const hd__kctx *K = be->grid->k;
    int gx = K->p->gdims.x, gy = K->p->gdims.y, gz = K->p->gdims.z;
    int y = r % gy, z = (r / gy) % gz, c = r / (gy * gz);
    int edge = hd__cpu_edge_row(K->p, y, z);
    int f = K->p->counts.z & (HD_FLAG_SURFACE_BOUNDARY | HD_FLAG_DIFFUSE_RHS);
    if (!HD__CPU_ROW_LOOPS || gx < 3 || (edge && f == HD_FLAG_SURFACE_BOUNDARY)) {
        hd__cpu_residual_voxels(be, y, z, c);
    } else if (edge) {
        hd__cpu_residual_edge_row(be, y, z, c);
    } else {
        hd__cpu_residual_halves(be, y, z, c, 1, 1, 1, 1);
    }
}

/* An image row on a copy of the kernel context whose storage precision (f16) is a literal, every
   call inlined: the sample's 16 loads of E and phi lose their precision test. */
static HD__CPU_FLATTEN void hd__cpu_project_row(hd__backend *be, int py)
{
    int px, w = be->vw->kp.image.x;
    hd__kctx k = be->k;
    k.lsum = be->lsum_ok ? be->lsum : NULL;
    k.ptab = be->ptab;
    k.ptab_n = be->ptab_n;
    if (k.f16) {
        k.f16 = 1;
        for (px = 0; px < w; ++px) hdk_project_pixel(&k, px, py);
    } else {
        k.f16 = 0;
        for (px = 0; px < w; ++px) hdk_project_pixel(&k, px, py);
    }
}

/* A row of a reduced frame's upsample pass. */
/* A row of the upsample pass: hdk_upsample_pixel's operations in its order (the same bits), the
   row's source rows and weight computed once (a frame at 1280x720 upsamples 0.9 M pixels, the
   largest part of a reduced frame's time). */
static void hd__cpu_upsample_row(hd__backend *be, int py)
{
    const hd__view *vw = be->vw;
    int w = vw->kp.image.x, h = vw->kp.image.y, s = vw->kp.region.y, px, k;
    int lw = (w + s - 1) / s, lh = (h + s - 1) / s, x0, x1, y1;
    float wx, wy;
    int y0 = hdk_upsample_axis(py, h, lh, &y1, &wy);
    const float *r0 = be->img + ((size_t)w * h + (size_t)y0 * lw) * 4, *r1 = be->img + ((size_t)w * h + (size_t)y1 * lw) * 4;
    float *o = be->img + (size_t)py * w * 4;
    if (be->up_x && be->up_w == w && be->up_lw == lw) {
        /* the columns from the table; on x86 the row is written past the cache (nothing reads
           it before hd_read_image), 4 floats at a time where aligned */
#ifdef HD__CPU_FTZ
        int stream = ((uintptr_t)o & 15u) == 0;
#endif
        for (px = 0; px < w; ++px) {
            float q[4];
            x0 = be->up_x[2 * px];
            x1 = be->up_x[2 * px + 1];
            wx = be->up_wx[px];
            for (k = 0; k < 4; ++k) {
                float top = r0[x0 * 4 + k] + wx * (r0[x1 * 4 + k] - r0[x0 * 4 + k]);
                float bot = r1[x0 * 4 + k] + wx * (r1[x1 * 4 + k] - r1[x0 * 4 + k]);
                q[k] = top + wy * (bot - top);
            }
#ifdef HD__CPU_FTZ
            if (stream) {
                _mm_stream_ps(o + px * 4, _mm_loadu_ps(q));
                continue;
            }
#endif
            for (k = 0; k < 4; ++k) o[px * 4 + k] = q[k];
        }
#ifdef HD__CPU_FTZ
        if (stream) _mm_sfence(); /* the streamed stores are visible before the pass ends */
#endif
        return;
    }
    for (px = 0; px < w; ++px) {
        x0 = hdk_upsample_axis(px, w, lw, &x1, &wx);
        for (k = 0; k < 4; ++k) {
            float top = r0[x0 * 4 + k] + wx * (r0[x1 * 4 + k] - r0[x0 * 4 + k]);
            float bot = r1[x0 * 4 + k] + wx * (r1[x1 * 4 + k] - r1[x0 * 4 + k]);
            o[px * 4 + k] = top + wy * (bot - top);
        }
    }
}

static hd_result hd__be_classify(const hd__view *vw)
{
    hd__cpu_parallel(vw->be, hd__cpu_classify_row, vw->gdims[1] * vw->gdims[2]);
    return HD_SUCCESS;
}
static hd_result hd__be_direct(const hd__view *vw, size_t first, size_t n)
{
    vw->be->lsum_ok = 0;
    vw->be->dl_first = first;
    vw->be->dl_end = first + n;
    hd__cpu_parallel(vw->be, hd__cpu_direct_chunk, (int)((n + HD__CPU_DIRECT_CHUNK - 1) / HD__CPU_DIRECT_CHUNK));
    return HD_SUCCESS;
}
/* Every pass has run when its hd__cpu_parallel returns. */
static hd_result hd__be_wait(const hd__view *vw)
{
    (void)vw;
    return HD_SUCCESS;
}
/* The voxels to track are the context's (vw->dl_bits, vw->dl_brick): nothing to upload. */
static hd_result hd__be_direct_list(const hd__view *vw)
{
    (void)vw;
    return HD_SUCCESS;
}

/* `sweeps` full sweeps on the illumination grid: red-black through hd__cpu_red_black (walks of
   several sweeps, hd_schedule.h's hd__diffuse_sweeps hands it all of an iteration's), Jacobi one
   pass and a swap each. */
static hd_result hd__be_diffuse_sweeps(const hd__view *vw, int jacobi, int sweeps)
{
    hd__backend *be = vw->be;
    hd__cpu_grid fine;
    int s;
    be->lsum_ok = 0;
    fine.k = &be->k;
    fine.res = NULL;
    be->grid = &fine;
    if (!jacobi) hd__cpu_red_black(be, sweeps, 0);
    for (s = 0; jacobi && s < sweeps; ++s) {
        float *t;
        uint16_t *th;
        be->jacobi = 1;
        be->parity = 0;
        hd__cpu_parallel(be, hd__cpu_diffuse_block, hd__cpu_blocks(be) * vw->channels);
        t = be->phi; be->phi = be->phi2; be->phi2 = t;
        th = be->phih; be->phih = be->phi2h; be->phi2h = th;
        hd__cpu_bind_illum(be);
    }
    be->grid = NULL;
    return HD_SUCCESS;
}
/* One full sweep: two half-sweeps (red, black) or one Jacobi pass and a swap. */
static hd_result hd__be_diffuse(const hd__view *vw, int jacobi) { return hd__be_diffuse_sweeps(vw, jacobi, 1); }
/* One row (channel c, z, y: r = (c * gz + z) * gy + y) of lsum = E + phi, x-fastest. */
static void hd__cpu_lsum_row(hd__backend *be, int r)
{
    int gx = be->vw->gdims[0], gy = be->vw->gdims[1], x;
    hd__kctx k = be->k;
    k.lsum = be->lsum;
    for (x = 0; x < gx; ++x) hdk_light_sum_voxel(&k, x, r % gy, r / gy);
}

/* The projection's inputs: lsum (after any pass that changed E or phi) and the TF table for the
   current TF, step and medium (hd__project_table, rebuilt when its key changes). Without room for
   either the projection reads E, phi and the TF directly. */
static void hd__cpu_project_prepare(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int n = hd__project_table_n(vw);
    size_t rows = (size_t)vw->gdims[1] * vw->gdims[2] * vw->channels;
    if (!be->lsum && (be->E || be->Eh))
        be->lsum = (float *)hd__alloc(vw, rows * (size_t)vw->gdims[0] * sizeof(float));
    if (be->lsum && !be->lsum_ok) {
        hd__cpu_parallel(be, hd__cpu_lsum_row, (int)rows);
        be->lsum_ok = 1;
    }
    if (n > be->ptab_cap) {
        hd__free(vw, be->ptab);
        be->ptab = (float *)hd__alloc(vw, (size_t)n * 4 * sizeof(float));
        be->ptab_cap = be->ptab ? n : 0;
        be->ptab_key.valid = 0;
    }
    if (be->ptab && !hd__project_table_key_same(vw, &be->ptab_key)) {
        hd__project_table(vw, be->ptab, n);
        be->ptab_key = hd__project_table_key(vw);
    }
    be->ptab_n = n;
}

static hd_result hd__be_project(const hd__view *vw)
{
    hd__cpu_project_prepare(vw);
    hd__cpu_parallel(vw->be, hd__cpu_project_row, vw->kp.image.y);
    return HD_SUCCESS;
}

/* The upsample pass's column table for the current sizes (the same expressions as the rows'
   own, which they fall back to without room for it). */
static void hd__cpu_upsample_table(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int w = vw->kp.image.x, s = vw->kp.region.y, lw = (w + s - 1) / s, px;
    if (be->up_x && be->up_w == w && be->up_lw == lw) return;
    if (be->up_w != w) {
        hd__free(vw, be->up_x);
        hd__free(vw, be->up_wx);
        be->up_x = (int *)hd__alloc(vw, (size_t)w * 2 * sizeof(int));
        be->up_wx = (float *)hd__alloc(vw, (size_t)w * sizeof(float));
        if (!be->up_x || !be->up_wx) {
            hd__free(vw, be->up_x);
            hd__free(vw, be->up_wx);
            be->up_x = NULL;
            be->up_wx = NULL;
            be->up_w = 0;
            return;
        }
        be->up_w = w;
    }
    for (px = 0; px < w; ++px) {
        be->up_x[2 * px] = hdk_upsample_axis(px, w, lw, &be->up_x[2 * px + 1], &be->up_wx[px]);
    }
    be->up_lw = lw;
}

/* A row of HD_REST_BLEND's blend pass (hdk_blend_pixel). */
static void hd__cpu_blend_row(hd__backend *be, int py)
{
    int px, w = be->vw->kp.image.x;
    for (px = 0; px < w; ++px) hdk_blend_pixel(&be->k, px, py);
}

static hd_result hd__be_upsample(const hd__view *vw)
{
    if (vw->kp.counts.z & HD_FLAG_BLEND) {
        hd__cpu_parallel(vw->be, hd__cpu_blend_row, vw->kp.image.y);
        return HD_SUCCESS;
    }
    hd__cpu_upsample_table(vw);
    hd__cpu_parallel(vw->be, hd__cpu_upsample_row, vw->kp.image.y);
    return HD_SUCCESS;
}

/* No recording and no GL texture: the core never calls these (hd__be_features). The direct
   light reads the core's mask, which it has in memory, instead of a list beside it. */
static unsigned hd__be_features(void) { return HD__BE_LIST_FROM_BITS; }
HD__BE_NO_RECORDING("cpu")
HD__BE_NO_TEXTURE("cpu")
HD__BE_NO_CL_BUFFER("cpu")

static hd_result hd__be_read_image(const hd__view *vw, float *dst)
{
    memcpy(dst, vw->be->img, (size_t)vw->kp.image.x * vw->kp.image.y * 4 * sizeof(float));
    return HD_SUCCESS;
}
static hd_result hd__be_read_depth(const hd__view *vw, float *dst)
{
    memcpy(dst, vw->be->img + vw->kp.region.z, (size_t)vw->kp.image.x * vw->kp.image.y * sizeof(float));
    return HD_SUCCESS;
}
/* Copies E or phi between the colour layout and the API's x-fastest channel-planar order, one
   direction per call: into dst (src NULL; binary16 widened exactly) or from src (dst NULL; rounded
   to nearest even), as the OpenCL backend's hd__cl_copy_illumination. Padding slots are not
   touched (they stay 0). With a slice list (list, count), only those stacked slices, in its order. */
static void hd__cpu_copy_illumination(const hd__view *vw, hd_illumination which, const float *src, float *dst, const int *list,
                                      int count)
{
    hd__backend *be = vw->be;
    int gx = vw->gdims[0], gy = vw->gdims[1], nz = list ? count : vw->gdims[2] * vw->channels, x, y, k, zz;
    float *f = which == HD_ILLUMINATION_DIRECT ? be->E : be->phi;
    uint16_t *h = which == HD_ILLUMINATION_DIRECT ? be->Eh : be->phih;
    for (k = 0; k < nz; ++k)
        for (zz = list ? list[k] : k, y = 0; y < gy; ++y)
            for (x = 0; x < gx; ++x) {
                size_t s = hd__split_slot(gx, gy, x, y, zz);
                if (h) {
                    if (src) h[s] = hdk_f2h(*src++);
                    else *dst++ = hdk_h2f(h[s]);
                } else {
                    if (src) f[s] = *src++;
                    else *dst++ = f[s];
                }
            }
}

static hd_result hd__be_read_illumination(const hd__view *vw, hd_illumination which, const int *zz, int count, float *dst)
{
    hd__cpu_copy_illumination(vw, which, NULL, dst, zz, count);
    return HD_SUCCESS;
}

#ifdef HYBRIDDIFF_TESTING
/* The inverse, for the test hooks (src/hd_test_hooks.h). */
HD__MAYBE_UNUSED static hd_result hd__cpu_write_illumination(const hd__view *vw, hd_illumination which, const float *src)
{
    vw->be->lsum_ok = 0;
    hd__cpu_copy_illumination(vw, which, src, NULL, NULL, 0);
    return HD_SUCCESS;
}
#endif

/* Relative residual |r| / |sigma_s E| of the diffusion equation for the current E and phi: the
   solver's convergence measure, for tests and benchmarks. Summed row by row in a fixed order. */
HD__MAYBE_UNUSED static double hd__cpu_residual(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int gx = vw->gdims[0], gy = vw->gdims[1], gz = vw->gdims[2], x, y, z, c;
    double r2 = 0.0, b2 = 0.0;
    for (c = 0; c < vw->channels; ++c)
        for (z = 0; z < gz; ++z)
            for (y = 0; y < gy; ++y)
                for (x = 0; x < gx; ++x) {
                    float rhs;
                    float r = hdk_diffuse_residual(&be->k, x, y, z, c, &rhs);
                    r2 += (double)r * r;
                    b2 += (double)rhs * rhs;
                }
    return b2 > 0.0 ? sqrt(r2 / b2) : sqrt(r2);
}

/* ---- the other methods: CD's convection, PT_SS / PT_MS paths ---------------------------------- */

/* CD's light volumes: frees the old ones and allocates count + 1 zeroed volumes of the
   illumination grid (count lights and one spare that rotates through them as the ping-pong
   buffer of hd__be_convect); count 0 frees them (every method but CD). Zeroed = dark: CD starts
   with no light in the volume. Bytes held: 4 * (count + 1) per voxel. */
static hd_result hd__be_alloc_lights(const hd__view *vw, int count)
{
    hd__backend *be = vw->be;
    size_t gvox = (size_t)vw->gdims[0] * vw->gdims[1] * vw->gdims[2];
    int l;
    hd__cpu_free_lights(vw);
    if (count <= 0) return HD_SUCCESS;
    be->lv = (float **)hd__calloc(vw, (size_t)count + 1, sizeof(float *));
    if (!be->lv) return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate %d light volumes", count);
    be->nlv = count;
    for (l = 0; l <= count; ++l) {
        be->lv[l] = (float *)hd__calloc(vw, gvox, sizeof(float));
        if (!be->lv[l]) {
            hd__cpu_free_lights(vw);
            return HD__ERR(&vw->log, HD_ERROR_OUT_OF_MEMORY, "cpu: cannot allocate %d light volumes of %zu voxels", count, gvox);
        }
    }
    return HD_SUCCESS;
}

static void hd__cpu_convect_row(hd__backend *be, int r)
{
    int gx = be->vw->gdims[0], gy = be->vw->gdims[1], x;
    for (x = 0; x < gx; ++x) hdk_convect_voxel(&be->k, x, r % gy, r / gy, be->light);
}
static void hd__cpu_sum_light_row(hd__backend *be, int r)
{
    int gx = be->vw->gdims[0], gy = be->vw->gdims[1], x;
    for (x = 0; x < gx; ++x) hdk_sum_light_voxel(&be->k, x, r % gy, r / gy, be->light, be->light == 0);
}
static void hd__cpu_path_row(hd__backend *be, int py)
{
    int px, w = be->vw->kp.image.x;
    hd__kctx k = be->k;
    k.lsum = be->lsum_ok ? be->lsum : NULL; /* HD's light, for a resting view's refinement */
    for (px = 0; px < w; ++px) hdk_path_pixel(&k, px, py);
}

/* One convection step of light `light` (hdk_convect_voxel on every voxel of the illumination
   grid): reads its volume, writes the spare, and the two swap roles. Needs sigma_t (classify). */
static hd_result hd__be_convect(const hd__view *vw, int light)
{
    hd__backend *be = vw->be;
    float *t;
    be->light = light;
    be->k.lv = be->lv[light];
    be->k.lv2 = be->lv[be->nlv];
    hd__cpu_parallel(be, hd__cpu_convect_row, vw->gdims[1] * vw->gdims[2]);
    t = be->lv[light]; be->lv[light] = be->lv[be->nlv]; be->lv[be->nlv] = t;
    return HD_SUCCESS;
}

/* E = sum over the lights of colour * falloff * light volume (hdk_sum_light_voxel, one pass per
   light, the first overwriting E), so the diffusion and projection of HD run on it unchanged. */
static hd_result hd__be_sum_lights(const hd__view *vw)
{
    hd__backend *be = vw->be;
    int l;
    be->lsum_ok = 0;
    for (l = 0; l < be->nlv; ++l) {
        be->light = l;
        be->k.lv = be->lv[l];
        hd__cpu_parallel(be, hd__cpu_sum_light_row, vw->gdims[1] * vw->gdims[2]);
    }
    return HD_SUCCESS;
}

/* One path per pixel (hdk_path_pixel), folded into the image with weight march.y. */
static hd_result hd__be_path(const hd__view *vw)
{
    hd__cpu_parallel(vw->be, hd__cpu_path_row, vw->kp.image.y);
    return HD_SUCCESS;
}
