/* hd_thread_times.h - where each thread of this process spent a stretch of wall time (Linux):
   on a CPU, waiting in the run queue for one, or neither (asleep: idle), from
   /proc/self/task/TID/schedstat. On a shared machine the run-queue wait is the other processes'
   share; the sleep of a backend's worker threads is time the backend itself left a core unused
   (work split unevenly, a serial host step), which the wall clock alone cannot tell apart from
   load. Header-only; elsewhere than Linux hdt_take finds no threads and hdt_print prints none. */
#ifndef HD_THREAD_TIMES_H
#define HD_THREAD_TIMES_H
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define HDT_MAX 64
typedef struct hdt_snap {
    int n;
    int tid[HDT_MAX];
    double run[HDT_MAX], wait[HDT_MAX]; /* seconds on a CPU, seconds runnable in the run queue */
    double wall;
} hdt_snap;

static void hdt_take(hdt_snap *t)
{
    DIR *d = opendir("/proc/self/task");
    struct dirent *e;
    struct timespec w;
    t->n = 0;
    while (d && (e = readdir(d)) != NULL && t->n < HDT_MAX) {
        int tid = atoi(e->d_name);
        char path[64];
        unsigned long long run = 0, wait = 0;
        FILE *f;
        if (tid <= 0) continue;
        snprintf(path, sizeof path, "/proc/self/task/%d/schedstat", tid);
        if (!(f = fopen(path, "r"))) continue;
        if (fscanf(f, "%llu %llu", &run, &wait) == 2) {
            t->tid[t->n] = tid;
            t->run[t->n] = (double)run * 1e-9;
            t->wait[t->n++] = (double)wait * 1e-9;
        }
        fclose(f);
    }
    if (d) closedir(d);
    clock_gettime(CLOCK_MONOTONIC, &w);
    t->wall = (double)w.tv_sec + (double)w.tv_nsec * 1e-9;
}

/* For each thread that was on a CPU for at least a tenth of the wall time between a and b (the
   workers; not a host thread that only waits for them): [CPU run-queue asleep] in ms per frame,
   and the sum of the asleep column over those threads. */
static void hdt_print(const hdt_snap *a, const hdt_snap *b, int frames)
{
    double wall = (b->wall - a->wall) * 1e3 / frames, idle = 0.0;
    int i, j;
    printf("  threads [cpu runq asleep] ms/frame:");
    for (i = 0; i < b->n; ++i) {
        double r0 = 0.0, w0 = 0.0, r, q;
        for (j = 0; j < a->n; ++j)
            if (a->tid[j] == b->tid[i]) { r0 = a->run[j]; w0 = a->wait[j]; }
        r = (b->run[i] - r0) * 1e3 / frames;
        q = (b->wait[i] - w0) * 1e3 / frames;
        if (r < 0.1 * wall) continue;
        printf(" [%.1f %.1f %.1f]", r, q, wall - r - q);
        idle += wall - r - q;
    }
    printf(" asleep %.1f", idle);
}
#endif
