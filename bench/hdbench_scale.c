/* hdbench_scale.c - how the light and the memory scale with the volume (make bench-scale, CPU
   backend, the library's defaults but the solver): the head CT resampled to a given size
   (trilinear, kept as I16) and a procedural sparse cloud (U8, about 10 % of its voxels
   occupied) at the same sizes. Per case, in a child process of its own (so getrusage's peak is
   that case's): device bytes per voxel (hd_stats volume_bytes + method_bytes), the host's peak
   during hd_create beyond what was resident before it, the light iteration's time
   (seconds_direct + seconds_diffusion per iteration), the iterations and the wall time until
   hd_stats.light_converged (as hd_render decides), and one 512^2 frame over the converged
   light. Prints a table and, with --dat FILE, gnuplot's data.
   Usage: hdbench_scale [--ct data/head.nrrd] [--sizes native,2x,256,512] [--cloud 256,512]
                        [--solvers rb,mg,auto] [--max-iters N] [--dat FILE] [--as-f32] [--f16]
   --as-f32: the CT's Hounsfield units given as F32 (the float path, for comparison); --f16:
   illumination_precision FLOAT16. auto: HD_SOLVER_AUTO, printed with its pick. The CPU seconds
   to converge (the process's, both threads) are the measure to compare on a shared machine. */
#if !defined(HYBRIDDIFF_BACKEND_OPENCL) && !defined(HYBRIDDIFF_BACKEND_VULKAN) && !defined(HYBRIDDIFF_BACKEND_GL)
#define HYBRIDDIFF_BACKEND_CPU
#endif
#define HYBRIDDIFF_IMPLEMENTATION
#include "hybriddiff.h"
#include "../examples/hd_tf.h"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include <time.h>
#include <unistd.h>
#include <sys/resource.h>
#include <sys/wait.h>

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* The process's CPU seconds (every thread): the steadier measure on a shared machine. */
static double cpu_s(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_utime.tv_sec + 1e-6 * (double)u.ru_utime.tv_usec + (double)u.ru_stime.tv_sec + 1e-6 * (double)u.ru_stime.tv_usec;
}

static size_t peak_kb(void)
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (size_t)u.ru_maxrss;
}

static size_t resident_kb(void)
{
    long pages = 0, res = 0;
    FILE *f = fopen("/proc/self/statm", "r");
    if (f) {
        if (fscanf(f, "%ld %ld", &pages, &res) != 2) res = 0;
        fclose(f);
    }
    return (size_t)res * (size_t)sysconf(_SC_PAGESIZE) / 1024;
}

static void quiet(void *u, hd_log_level l, hd_result c, const char *m, const char *f, int line)
{
    (void)u; (void)c; (void)f; (void)line;
    if (l == HD_LOG_ERROR) fprintf(stderr, "hdbench_scale: %s\n", m);
}

/* The CT resampled to n[0..2] voxels (trilinear, the same physical box), as I16. */
static int16_t *ct_resample(const hd_volume_file *ct, const int *n, float *spacing)
{
    const int *s = ct->desc.dims;
    int16_t *out = (int16_t *)malloc((size_t)n[0] * n[1] * n[2] * sizeof(int16_t));
    int x, y, z, d;
    if (!out) return NULL;
    for (d = 0; d < 3; ++d) spacing[d] = ct->desc.spacing[d] * (float)s[d] / (float)n[d];
    for (z = 0; z < n[2]; ++z) {
        float fz = ((float)z + 0.5f) * (float)s[2] / (float)n[2] - 0.5f;
        int z0 = fz < 0 ? 0 : (int)fz, z1 = z0 + 1 < s[2] ? z0 + 1 : s[2] - 1;
        float wz = fz < 0 ? 0.0f : fz - (float)z0;
        for (y = 0; y < n[1]; ++y) {
            float fy = ((float)y + 0.5f) * (float)s[1] / (float)n[1] - 0.5f;
            int y0 = fy < 0 ? 0 : (int)fy, y1 = y0 + 1 < s[1] ? y0 + 1 : s[1] - 1;
            float wy = fy < 0 ? 0.0f : fy - (float)y0;
            for (x = 0; x < n[0]; ++x) {
                float fx = ((float)x + 0.5f) * (float)s[0] / (float)n[0] - 0.5f;
                int x0 = fx < 0 ? 0 : (int)fx, x1 = x0 + 1 < s[0] ? x0 + 1 : s[0] - 1;
                float wx = fx < 0 ? 0.0f : fx - (float)x0, v = 0.0f;
                int c;
                for (c = 0; c < 8; ++c) {
                    int xi = c & 1 ? x1 : x0, yi = c & 2 ? y1 : y0, zi = c & 4 ? z1 : z0;
                    float w = (c & 1 ? wx : 1.0f - wx) * (c & 2 ? wy : 1.0f - wy) * (c & 4 ? wz : 1.0f - wz);
                    v += w * (float)((const int16_t *)ct->data)[((size_t)zi * s[1] + yi) * s[0] + xi];
                }
                out[((size_t)z * n[1] + y) * n[0] + x] = (int16_t)lrintf(v);
            }
        }
    }
    return out;
}

/* A cumulus-like cloud of 24 soft puffs in an n^3 box, U8; *occupied = the fraction of voxels
   above 0. */
static uint8_t *cloud_make(int n, double *occupied)
{
    enum { PUFFS = 24 };
    float c[PUFFS][4];
    uint8_t *v = (uint8_t *)malloc((size_t)n * n * n);
    size_t filled = 0;
    uint32_t h = 12345u;
    int i, x, y, z;
    if (!v) return NULL;
    for (i = 0; i < PUFFS; ++i) {
        int k;
        for (k = 0; k < 4; ++k) {
            h = h * 1664525u + 1013904223u;
            c[i][k] = (float)(h >> 8) / 16777216.0f;
        }
        c[i][0] = 0.25f + 0.5f * c[i][0];
        c[i][1] = 0.35f + 0.2f * c[i][1];
        c[i][2] = 0.25f + 0.5f * c[i][2];
        c[i][3] = 0.06f + 0.07f * c[i][3];
    }
    for (z = 0; z < n; ++z)
        for (y = 0; y < n; ++y)
            for (x = 0; x < n; ++x) {
                float p[3] = {((float)x + 0.5f) / (float)n, ((float)y + 0.5f) / (float)n, ((float)z + 0.5f) / (float)n}, d = 0.0f;
                uint32_t q = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u;
                for (i = 0; i < PUFFS; ++i) {
                    float dx = p[0] - c[i][0], dy = p[1] - c[i][1], dz = p[2] - c[i][2];
                    float t = 1.0f - (dx * dx + dy * dy + dz * dz) / (c[i][3] * c[i][3]);
                    if (t > 0.0f) d += t;
                }
                d = d > 0.0f ? d * (0.85f + 0.3f * (float)((q * 2654435761u) >> 8) / 16777216.0f) : 0.0f;
                v[((size_t)z * n + y) * n + x] = (uint8_t)(d >= 1.0f ? 255 : (int)(d * 255.0f));
                filled += d > 0.0f;
            }
    *occupied = (double)filled / ((double)n * n * n);
    return v;
}

typedef struct result {
    int ok, iters, converged, solver; /* solver: the one hd_create chose (AUTO's pick) */
    double bpv, host_extra_mb, vol_mb, iter_s, conv_s, conv_cpu_s, frame_s, occupied;
} result;

/* One case in this process: the desc's volume, the solver, up to max_iters light iterations. */
static result run_case(hd_desc *d, hd_solver solver, int max_iters, double vol_bytes, int f16)
{
    result r;
    hd_context c;
    hd_stats st;
    size_t before = resident_kb(), nvox = (size_t)d->volume.dims[0] * d->volume.dims[1] * d->volume.dims[2];
    double t0, c0;
    memset(&r, 0, sizeof r);
    d->params.solver = solver;
    if (f16) d->params.illumination_precision = HD_PRECISION_FLOAT16;
    d->camera.width = d->camera.height = 64; /* the light's iterations: a small image */
    if (hd_create(d, &c) != HD_SUCCESS) return r;
    {
        hd_desc q;
        memset(&q, 0, sizeof q);
        if (hd_query_desc(c, &q) == HD_SUCCESS) r.solver = (int)q.params.solver;
    }
    r.host_extra_mb = (double)((peak_kb() > before ? peak_kb() - before : 0)) / 1024.0;
    r.vol_mb = vol_bytes / 1048576.0;
    t0 = now_s();
    c0 = cpu_s();
    for (r.iters = 0; r.iters < max_iters; ++r.iters) {
        if (hd_render(c) != HD_SUCCESS || hd_get_stats(c, &st) != HD_SUCCESS) { hd_destroy(c); return r; }
        if (st.light_converged) break;
    }
    r.conv_s = now_s() - t0;
    r.conv_cpu_s = cpu_s() - c0;
    r.converged = st.light_converged;
    r.iters = (int)st.iterations;
    r.iter_s = st.iterations ? (st.seconds_direct + st.seconds_diffusion) / (double)st.iterations : 0.0;
    r.bpv = (double)(st.volume_bytes + st.method_bytes) / (double)nvox;
    {
        hd_camera cam = d->camera;
        cam.width = cam.height = 512;
        if (hd_set_camera(c, &cam) == HD_SUCCESS) {
            t0 = now_s();
            if (hd_render(c) == HD_SUCCESS) r.frame_s = now_s() - t0;
        }
    }
    hd_destroy(c);
    r.ok = 1;
    return r;
}

/* Runs fn's case in a child; its result comes back through a pipe. */
static result in_child(hd_desc *d, hd_solver solver, int max_iters, double vol_bytes, int f16)
{
    result r;
    int fd[2];
    pid_t pid;
    memset(&r, 0, sizeof r);
    if (pipe(fd) != 0) return r;
    fflush(stdout);
    pid = fork();
    if (pid == 0) {
        result x = run_case(d, solver, max_iters, vol_bytes, f16);
        ssize_t w = write(fd[1], &x, sizeof x);
        _exit(w == (ssize_t)sizeof x ? 0 : 1);
    }
    close(fd[1]);
    if (pid < 0 || read(fd[0], &r, sizeof r) != (ssize_t)sizeof r) memset(&r, 0, sizeof r);
    close(fd[0]);
    if (pid > 0) waitpid(pid, NULL, 0);
    return r;
}

static void print_row(FILE *dat, const char *name, const int *n, const char *asked, const result *r)
{
    double nvox = (double)n[0] * n[1] * n[2];
    char solver[16];
    snprintf(solver, sizeof solver, "%s%s", asked,
             strcmp(asked, "auto") ? "" : r->solver == HD_SOLVER_MULTIGRID ? ":mg" : ":rb");
    if (!r->ok) {
        printf("| %-6s | %4dx%4dx%4d | %-7s | failed |\n", name, n[0], n[1], n[2], solver);
        return;
    }
    printf("| %-6s | %4dx%4dx%4d | %6.1f M | %-7s | %5.2f | %7.0f MB (%.2f x %.0f MB) | %7.3f s | %4d%s | %7.1f s | %7.1f s | %6.2f s |\n", name, n[0], n[1], n[2],
           nvox / 1e6, solver, r->bpv, r->host_extra_mb, r->vol_mb > 0 ? r->host_extra_mb / r->vol_mb : 0.0, r->vol_mb, r->iter_s,
           r->iters, r->converged ? "" : "+", r->conv_s, r->conv_cpu_s, r->frame_s);
    fflush(stdout);
    if (dat)
        fprintf(dat, "%s %s %.0f %.4f %.3f %.5f %d %.3f %.4f %.3f\n", name, solver, nvox, r->bpv, r->host_extra_mb, r->iter_s, r->iters,
                r->conv_s, r->frame_s, r->conv_cpu_s);
}

int main(int argc, char **argv)
{
    const char *ct_path = "data/head.nrrd", *sizes = "native,2x,256,512", *clouds = "256,512", *solvers = "rb,mg", *datp = NULL;
    int max_iters = 200, i, as_f32 = 0, f16 = 0;
    hd_volume_file ct;
    hd_logger log;
    hdx_tf tf;
    hd_light light;
    FILE *dat = NULL;
    char buf[256], *tok;
    static const float cloud_tf[] = {0, 0, 0, 0, 1, 1, 1, 0.6f, 1, 1, 1, 1};
    for (i = 1; i < argc; ++i) {
        if (!strcmp(argv[i], "--ct") && i + 1 < argc) ct_path = argv[++i];
        else if (!strcmp(argv[i], "--sizes") && i + 1 < argc) sizes = argv[++i];
        else if (!strcmp(argv[i], "--cloud") && i + 1 < argc) clouds = argv[++i];
        else if (!strcmp(argv[i], "--solvers") && i + 1 < argc) solvers = argv[++i];
        else if (!strcmp(argv[i], "--max-iters") && i + 1 < argc) max_iters = atoi(argv[++i]);
        else if (!strcmp(argv[i], "--dat") && i + 1 < argc) datp = argv[++i];
        else if (!strcmp(argv[i], "--as-f32")) as_f32 = 1;
        else if (!strcmp(argv[i], "--f16")) f16 = 1;
        else { fprintf(stderr, "usage: see the top of bench/hdbench_scale.c\n"); return 2; }
    }
    memset(&log, 0, sizeof log);
    log.func = quiet;
    if (hd_volume_load(ct_path, &ct, &log) != HD_SUCCESS || ct.desc.type != HD_VOXEL_I16) {
        fprintf(stderr, "hdbench_scale: %s: not an int16 volume (make data)\n", ct_path);
        return 1;
    }
    if (datp && !(dat = fopen(datp, "w"))) { perror(datp); return 1; }
    if (!hdx_tf_preset("ct-skin", &tf)) return 1;
    memset(&light, 0, sizeof light);
    light.type = HD_LIGHT_DIRECTIONAL;
    light.direction[0] = -0.4f; light.direction[1] = -1.0f; light.direction[2] = -0.6f;
    light.intensity = 1.0f;
    printf("hdbench_scale: %s backend, %ld cores; light iterations capped at %d (+: not converged)\n", hd_backend_name(),
           sysconf(_SC_NPROCESSORS_ONLN), max_iters);
    printf("| volume | dims | voxels | solver | device B/voxel | host peak in hd_create (x volume) | light iteration | iterations | to converge | CPU s to converge | frame 512^2 |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (int pass = 0; pass < 2; ++pass) {
        snprintf(buf, sizeof buf, "%s", pass == 0 ? sizes : clouds);
        for (tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) { /* the only strtok walk */
            int n[3];
            void *data;
            float spacing[3] = {1, 1, 1};
            double occ = 0.0;
            hd_desc d;
            if (pass == 0 && !strcmp(tok, "native")) { memcpy(n, ct.desc.dims, sizeof n); }
            else if (pass == 0 && !strcmp(tok, "2x")) { for (i = 0; i < 3; ++i) n[i] = 2 * ct.desc.dims[i]; }
            else n[0] = n[1] = n[2] = atoi(tok);
            if (n[0] < 2) continue;
            data = pass == 0 ? (void *)ct_resample(&ct, n, spacing) : (void *)cloud_make(n[0], &occ);
            if (!data) { printf("| %s | %d^3 | no memory |\n", tok, n[0]); continue; }
            memset(&d, 0, sizeof d);
            d.volume = ct.desc;
            d.volume.dims[0] = n[0]; d.volume.dims[1] = n[1]; d.volume.dims[2] = n[2];
            memcpy(d.volume.spacing, spacing, sizeof spacing);
            d.volume.data = data;
            if (pass == 0 && as_f32) { /* the same Hounsfield units as floats: the F32 path's figures */
                size_t k, nv = (size_t)n[0] * n[1] * n[2];
                float *f = (float *)malloc(nv * sizeof(float));
                if (!f) { free(data); continue; }
                for (k = 0; k < nv; ++k) f[k] = (float)((const int16_t *)data)[k];
                free(data);
                data = f;
                d.volume.type = HD_VOXEL_F32;
                d.volume.data = data;
            }
            if (pass == 0) {
                hdx_tf_use(&d, &d.volume, &tf);
            } else {
                d.volume.type = HD_VOXEL_U8;
                d.volume.value_range[0] = 0.0f; d.volume.value_range[1] = 255.0f;
                d.transfer_function.rgba = cloud_tf;
                d.transfer_function.count = 3;
                printf("| cloud %d^3: %.1f %% of the voxels occupied |\n", n[0], 100.0 * occ);
            }
            d.lights = &light;
            d.light_count = 1;
            d.camera.eye[1] = 2.3f; d.camera.up[2] = 1.0f;
            d.logger = log;
            {
                const char *p = solvers; /* comma-separated */
                while (*p) {
                    char name[8] = {0};
                    size_t k = 0;
                    result r;
                    while (*p && *p != ',' && k < sizeof name - 1) name[k++] = *p++;
                    while (*p && *p != ',') ++p;
                    if (*p == ',') ++p;
                    r = in_child(&d, !strcmp(name, "mg") ? HD_SOLVER_MULTIGRID : !strcmp(name, "auto") ? HD_SOLVER_AUTO : HD_SOLVER_RED_BLACK, max_iters,
                                 (double)n[0] * n[1] * n[2] * (pass == 0 ? (as_f32 ? 4.0 : 2.0) : 1.0), f16);
                    print_row(dat, pass == 0 ? (as_f32 ? "ct-f32" : "ct") : "cloud", n, name, &r);
                }
            }
            free(data);
        }
    }
    if (dat) fclose(dat);
    hd_volume_free(&ct);
    return 0;
}
