/* hdbench_triad.h - the STREAM-style triad a = b + 3 c over nthreads threads, the memory
   bandwidth every benchmark's "share of the triad" divides by. One copy for hdbench and
   hdbench_opencl. Needs <pthread.h>, <stdlib.h> and hd__now() (the library's clock).

   Bytes counted: 12 per element, three float arrays (b, c read, a written): STREAM's
   convention, write-allocate traffic not counted. (Until 2026-11-23 this counted 24, STREAM's
   figure for doubles, which doubled the triad and halved every share printed against it.) */
#ifndef HDBENCH_TRIAD_H
#define HDBENCH_TRIAD_H

#define HDBENCH_TRIAD_N ((size_t)32 << 20) /* 3 arrays of 128 MiB: beyond most L3s (not the
   480 MB one, shared with other tenants, that the CI VM reports) */

typedef struct hdbench_triad_job { float *a, *b, *c; size_t lo, hi; } hdbench_triad_job;

static void *hdbench_triad_worker(void *arg)
{
    hdbench_triad_job *j = (hdbench_triad_job *)arg;
    size_t i;
    for (i = j->lo; i < j->hi; ++i) j->a[i] = j->b[i] + 3.0f * j->c[i];
    return NULL;
}

/* Best of 5 passes, in bytes/s; 0 if the arrays cannot be allocated. */
static double hdbench_triad_bandwidth(int nthreads)
{
    size_t n = HDBENCH_TRIAD_N, i;
    float *a = (float *)malloc(n * sizeof(float)), *b = (float *)malloc(n * sizeof(float));
    float *c = (float *)malloc(n * sizeof(float));
    pthread_t th[64];
    hdbench_triad_job jobs[64];
    double best = 0.0;
    int rep, t;
    if (a == NULL || b == NULL || c == NULL) { free(a); free(b); free(c); return 0.0; }
    if (nthreads > 64) nthreads = 64;
    if (nthreads < 1) nthreads = 1;
    for (i = 0; i < n; ++i) { a[i] = 0.0f; b[i] = 1.0f; c[i] = 2.0f; }
    for (rep = 0; rep < 5; ++rep) {
        double t0 = hd__now(), dt;
        for (t = 0; t < nthreads; ++t) {
            jobs[t].a = a; jobs[t].b = b; jobs[t].c = c;
            jobs[t].lo = n / (size_t)nthreads * (size_t)t;
            jobs[t].hi = t == nthreads - 1 ? n : n / (size_t)nthreads * (size_t)(t + 1);
            pthread_create(&th[t], NULL, hdbench_triad_worker, &jobs[t]);
        }
        for (t = 0; t < nthreads; ++t) pthread_join(th[t], NULL);
        dt = hd__now() - t0;
        if (12.0 * (double)n / dt > best) best = 12.0 * (double)n / dt;
    }
    free(a); free(b); free(c);
    return best;
}

#endif
