/* hd_orbit_scene.h - the scene of the orbit benchmarks (bench/hdbench_orbit.c, bench/peer/):
   the head CT with hdrender's defaults (ct-skin TF, the three-quarter camera in front of the face,
   one key light placed from that camera, exposure 8), a camera orbit around the vertical axis
   through the target, and a wall clock; the tone map and PSNR are hdeval's (examples/hd_tonemap.h).
   Bench helpers, every function static, hdo_. */
#ifndef HD_ORBIT_SCENE_H
#define HD_ORBIT_SCENE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "hybriddiff.h"
#include "hd_tf.h"
#include "hd_tonemap.h"

#if defined(__GNUC__) || defined(__clang__)
#define HDO_FN static __attribute__((unused))
#else
#define HDO_FN static
#endif

#define HDO_EXPOSURE 8.0f

typedef struct hdo_scene {
    hd_volume_file vol;
    hdx_tf tf;
    hd_light light;
    hd_desc desc; /* ready for hd_create; points into this struct */
} hdo_scene;

HDO_FN double hdo_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* The process's CPU seconds divided by the online cores: a budget's clock that the machine's
   other load does not stretch (on a quiet machine about wall time for work on all cores). */
HDO_FN double hdo_cpu_clock(void)
{
    static double cores = 0.0;
    struct timespec ts;
    if (cores <= 0.0) {
        long n = sysconf(_SC_NPROCESSORS_ONLN);
        cores = n > 0 ? (double)n : 1.0;
    }
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ((double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec) / cores;
}

/* hdrender's default camera at azimuth deg around the +z axis through its target. */
HDO_FN hd_camera hdo_orbit_camera(double deg, int size)
{
    static const float eye0[3] = {0.6f, 1.65f, 0.3f}, target[3] = {0.0f, 0.0f, -0.04f};
    hd_camera c;
    double a = deg * 3.14159265358979323846 / 180.0, ca = cos(a), sa = sin(a);
    double dx = eye0[0] - target[0], dy = eye0[1] - target[1];
    memset(&c, 0, sizeof c);
    c.eye[0] = (float)(target[0] + ca * dx - sa * dy);
    c.eye[1] = (float)(target[1] + sa * dx + ca * dy);
    c.eye[2] = eye0[2];
    memcpy(c.target, target, sizeof target);
    c.up[2] = 1.0f;
    c.fov_y = 37.0f;
    c.width = c.height = size;
    return c;
}

/* hdrender's key light for camera c: from the upper left of the view, toward the target. */
HDO_FN hd_light hdo_key_light(const hd_camera *c)
{
    static const float from_cam[3] = {-0.55f, 0.65f, 0.75f}; /* right, up, toward the camera */
    float w[3], u[3], v[3], from[3], n;
    hd_light l;
    int k;
    for (k = 0; k < 3; ++k) w[k] = c->target[k] - c->eye[k];
    n = sqrtf(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    for (k = 0; k < 3; ++k) w[k] /= n;
    u[0] = w[1] * c->up[2] - w[2] * c->up[1];
    u[1] = w[2] * c->up[0] - w[0] * c->up[2];
    u[2] = w[0] * c->up[1] - w[1] * c->up[0];
    n = sqrtf(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (k = 0; k < 3; ++k) u[k] /= n;
    v[0] = u[1] * w[2] - u[2] * w[1];
    v[1] = u[2] * w[0] - u[0] * w[2];
    v[2] = u[0] * w[1] - u[1] * w[0];
    for (k = 0; k < 3; ++k) from[k] = from_cam[0] * u[k] + from_cam[1] * v[k] - from_cam[2] * w[k];
    n = sqrtf(from[0] * from[0] + from[1] * from[1] + from[2] * from[2]);
    memset(&l, 0, sizeof l);
    l.type = HD_LIGHT_DIRECTIONAL;
    for (k = 0; k < 3; ++k) l.direction[k] = -from[k] / n;
    l.color[0] = l.color[1] = l.color[2] = 1.0f;
    l.intensity = 1.0f;
    return l;
}

/* Loads path and fills s->desc with the scene at azimuth 0, size x size. 0 on failure (said). */
HDO_FN int hdo_scene_load(hdo_scene *s, const char *path, int size, const hd_logger *log)
{
    hd_result r;
    memset(s, 0, sizeof *s);
    r = hd_volume_load(path, &s->vol, log);
    if (r != HD_SUCCESS) {
        fprintf(stderr, "cannot load %s: %s (make data fetches the head CT)\n", path,
                hd_result_string(r));
        return 0;
    }
    hdx_tf_preset("ct-skin", &s->tf);
    hdx_tf_use(&s->desc, &s->vol.desc, &s->tf);
    s->desc.camera = hdo_orbit_camera(0.0, size);
    s->light = hdo_key_light(&s->desc.camera);
    s->desc.lights = &s->light;
    s->desc.light_count = 1;
    s->desc.params.exposure = HDO_EXPOSURE;
    if (log) s->desc.logger = *log;
    return 1;
}

/* Refines ctx's light until hd_stats.light_converged, at most max_iters iterations (progress on
   stderr every 10). If it has not converged by then, light_tolerance is raised above the current
   error estimate, so that hd_render does projections only from here on (benchmarks of frame
   time), and the raise is reported. Returns 1 if it converged by itself, 0 if raised, -1 on error
   (said). *seconds: the time spent. */
HDO_FN int hdo_converge(hd_context ctx, int max_iters, const char *tag, double *seconds)
{
    hd_stats st;
    hd_desc d;
    hd_result r;
    double t0 = hdo_now();
    int it = 0, extra = 0;
    do {
        if ((r = hd_refine(ctx, 1)) != HD_SUCCESS || (r = hd_get_stats(ctx, &st)) != HD_SUCCESS) {
            fprintf(stderr, "%s: hd_refine: %s\n", tag, hd_result_string(r));
            return -1;
        }
        if (++it % 10 == 0)
            fprintf(stderr, "%s: light iteration %d, light_error %.4g\n", tag, it, st.light_error);
    } while (!st.light_converged && it < max_iters);
    *seconds = hdo_now() - t0;
    fprintf(stderr, "%s: light %s after %d iterations in %.1f s, light_error %.4g\n", tag,
            st.light_converged ? "converged" : "not converged", it, *seconds, st.light_error);
    if (st.light_converged) return 1;
    if ((r = hd_query_desc(ctx, &d)) != HD_SUCCESS) {
        fprintf(stderr, "%s: hd_query_desc: %s\n", tag, hd_result_string(r));
        return -1;
    }
    d.params.light_tolerance = (float)(1.5 * st.light_error);
    if ((r = hd_set_params(ctx, &d.params)) != HD_SUCCESS) {
        fprintf(stderr, "%s: hd_set_params: %s\n", tag, hd_result_string(r));
        return -1;
    }
    do {
        if ((r = hd_refine(ctx, 1)) != HD_SUCCESS || (r = hd_get_stats(ctx, &st)) != HD_SUCCESS) {
            fprintf(stderr, "%s: hd_refine: %s\n", tag, hd_result_string(r));
            return -1;
        }
    } while (!st.light_converged && ++extra < 20);
    *seconds = hdo_now() - t0;
    fprintf(stderr, "%s: light_tolerance raised to %.4g (the iteration cap): converged %d after %d "
            "more iterations, light_error %.4g\n", tag, (double)d.params.light_tolerance,
            st.light_converged, extra + 1, st.light_error);
    return st.light_converged ? 0 : -1;
}

#endif
