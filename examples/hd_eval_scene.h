/* hd_eval_scene.h - the scene file of examples/hdeval (examples/eval/head.scene is the one the
   evaluation uses). Example helper, not library API: every function is static, hde_.

   Format: one `key = value` per line, '#' starts a comment, blank lines are ignored. Vectors are
   space-separated numbers. `paper.KEY = value` replaces KEY when the file is read with paper = 1
   (hdeval --paper) and is ignored otherwise; the order of lines does not matter for that.
   `light = DX DY DZ INTENSITY` repeats (a white directional light; DX DY DZ is the direction the
   light travels). Every other key may appear once (a later line replaces an earlier one).
   Unknown keys and malformed values are errors naming the line. */
#ifndef HD_EVAL_SCENE_H
#define HD_EVAL_SCENE_H

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define HDE_MAX_LIGHTS 16
#define HDE_MAX_LEVELS 16

/* Method slots: HD, CD, PT_SS, PT_MS. */
enum { HDE_HD = 0, HDE_CD, HDE_SS, HDE_MS, HDE_METHODS };

typedef struct hde_scene {
    char volume[512];
    char tf[512];
    float extinction, albedo, anisotropy, step, exposure, fov, lit_opacity;
    int max_bounces, diffusion_sweeps, frame_window;
    int solver; /* HD and CD's diffusion solver: 0 (unset) or 1 = red-black, the paper's,
                   2 = multigrid CG (HD_SOLVER_RED_BLACK / _MULTIGRID; the CPU backend only);
                   diffusion_sweeps counts CG steps with multigrid */
    float eye[3], target[3], up[3];
    int light_count;
    float light_dir[HDE_MAX_LIGHTS][3], light_intensity[HDE_MAX_LIGHTS];
    int size, table_size;
    int iterations[HDE_METHODS]; /* quality curves */
    int ref_paths[HDE_METHODS];  /* PT_SS and PT_MS only */
    double table_seconds;
    int table_min_iterations, table_rounds;
    int level_count;
    float levels[HDE_MAX_LEVELS];
    uint32_t seed, ref_seed;
    int threads;
} hde_scene;

static const char *const hde_method_keys[HDE_METHODS] = {"hd", "cd", "pt_ss", "pt_ms"};

static void hde_scene_defaults(hde_scene *s)
{
    memset(s, 0, sizeof *s);
    snprintf(s->volume, sizeof s->volume, "data/head.nrrd");
    snprintf(s->tf, sizeof s->tf, "ct-skin");
    s->extinction = 100.0f; s->albedo = 0.9f; s->step = 0.5f; s->exposure = 8.0f;
    s->fov = 40.0f; s->lit_opacity = 0.5f; s->max_bounces = 64; s->diffusion_sweeps = 4;
    s->frame_window = 8; s->eye[2] = 2.5f; s->up[1] = 1.0f;
    s->size = 256; s->table_size = 1024;
    s->iterations[HDE_HD] = 64; s->iterations[HDE_CD] = 256;
    s->iterations[HDE_SS] = 512; s->iterations[HDE_MS] = 512;
    s->ref_paths[HDE_SS] = 2048; s->ref_paths[HDE_MS] = 2048;
    s->table_seconds = 3.0; s->table_min_iterations = 2; s->table_rounds = 2;
    s->level_count = 3; s->levels[0] = 20.0f; s->levels[1] = 25.0f; s->levels[2] = 30.0f;
    s->ref_seed = 1000;
}

/* Up to max numbers from s; returns how many, -1 on a malformed number. */
static int hde__numbers(const char *s, double *v, int max)
{
    int n = 0;
    for (;;) {
        char *end;
        while (*s == ' ' || *s == '\t') ++s;
        if (!*s) return n;
        if (n == max) return -1;
        errno = 0;
        v[n] = strtod(s, &end);
        if (end == s || errno == ERANGE || (*end && *end != ' ' && *end != '\t')) return -1;
        ++n;
        s = end;
    }
}

/* Applies one key; 0 with err filled on failure. */
static int hde__apply(hde_scene *s, const char *key, const char *val, char *err, size_t errn)
{
    double v[HDE_MAX_LEVELS];
    int n = hde__numbers(val, v, HDE_MAX_LEVELS), m;
#define HDE_NUM(k, lo, hi) (strcmp(key, k) == 0 && (n == 1 && v[0] >= (lo) && v[0] <= (hi) ? 1 : \
    (snprintf(err, errn, "%s wants one number in [%g, %g]", k, (double)(lo), (double)(hi)), 0)))
#define HDE_VEC3(k, dst) if (strcmp(key, k) == 0) { \
        if (n != 3) { snprintf(err, errn, "%s wants 3 numbers", k); return 0; } \
        dst[0] = (float)v[0]; dst[1] = (float)v[1]; dst[2] = (float)v[2]; return 1; }
    if (strcmp(key, "volume") == 0 || strcmp(key, "tf") == 0) {
        char *dst = key[0] == 'v' ? s->volume : s->tf;
        if (!*val || strlen(val) >= 512) { snprintf(err, errn, "%s: empty or too long", key); return 0; }
        snprintf(dst, 512, "%s", val);
        return 1;
    }
    HDE_VEC3("eye", s->eye)
    HDE_VEC3("target", s->target)
    HDE_VEC3("up", s->up)
    if (strcmp(key, "light") == 0) {
        if (n != 4 || !(v[3] > 0.0) || (v[0] == 0 && v[1] == 0 && v[2] == 0)) {
            snprintf(err, errn, "light wants DX DY DZ INTENSITY (non-zero direction, intensity > 0)");
            return 0;
        }
        if (s->light_count == HDE_MAX_LIGHTS) { snprintf(err, errn, "more than %d lights", HDE_MAX_LIGHTS); return 0; }
        for (m = 0; m < 3; ++m) s->light_dir[s->light_count][m] = (float)v[m];
        s->light_intensity[s->light_count++] = (float)v[3];
        return 1;
    }
    if (strcmp(key, "solver") == 0) {
        if (strcmp(val, "red-black") == 0) s->solver = 1;
        else if (strcmp(val, "multigrid") == 0) s->solver = 2;
        else { snprintf(err, errn, "solver wants red-black or multigrid"); return 0; }
        return 1;
    }
    if (strcmp(key, "psnr_levels") == 0) {
        if (n < 1) { snprintf(err, errn, "psnr_levels wants 1..%d numbers", HDE_MAX_LEVELS); return 0; }
        for (m = 0; m < n; ++m) s->levels[m] = (float)v[m];
        s->level_count = n;
        return 1;
    }
    for (m = 0; m < HDE_METHODS; ++m) {
        char k[64];
        snprintf(k, sizeof k, "iterations.%s", hde_method_keys[m]);
        if (strcmp(key, k) == 0) {
            if (!HDE_NUM(k, 1, 1e8)) return 0;
            s->iterations[m] = (int)v[0];
            return 1;
        }
        snprintf(k, sizeof k, "ref_paths.%s", hde_method_keys[m]);
        if (m >= HDE_SS && strcmp(key, k) == 0) {
            if (!HDE_NUM(k, 2, 1e9)) return 0;
            s->ref_paths[m] = (int)v[0];
            return 1;
        }
    }
    if (strcmp(key, "extinction") == 0) { if (!HDE_NUM("extinction", 1e-6, 1e6)) return 0; s->extinction = (float)v[0]; return 1; }
    if (strcmp(key, "albedo") == 0) { if (!HDE_NUM("albedo", 1e-6, 1)) return 0; s->albedo = (float)v[0]; return 1; }
    if (strcmp(key, "anisotropy") == 0) { if (!HDE_NUM("anisotropy", -0.999, 0.999)) return 0; s->anisotropy = (float)v[0]; return 1; }
    if (strcmp(key, "step") == 0) { if (!HDE_NUM("step", 0.01, 16)) return 0; s->step = (float)v[0]; return 1; }
    if (strcmp(key, "exposure") == 0) { if (!HDE_NUM("exposure", 1e-6, 1e9)) return 0; s->exposure = (float)v[0]; return 1; }
    if (strcmp(key, "fov") == 0) { if (!HDE_NUM("fov", 1, 179)) return 0; s->fov = (float)v[0]; return 1; }
    if (strcmp(key, "lit_opacity") == 0) { if (!HDE_NUM("lit_opacity", 0, 1)) return 0; s->lit_opacity = (float)v[0]; return 1; }
    if (strcmp(key, "max_bounces") == 0) { if (!HDE_NUM("max_bounces", 1, 100000)) return 0; s->max_bounces = (int)v[0]; return 1; }
    if (strcmp(key, "diffusion_sweeps") == 0) { if (!HDE_NUM("diffusion_sweeps", 1, 100000)) return 0; s->diffusion_sweeps = (int)v[0]; return 1; }
    if (strcmp(key, "frame_window") == 0) { if (!HDE_NUM("frame_window", 1, 1e6)) return 0; s->frame_window = (int)v[0]; return 1; }
    if (strcmp(key, "size") == 0) { if (!HDE_NUM("size", 8, 16384)) return 0; s->size = (int)v[0]; return 1; }
    if (strcmp(key, "table_size") == 0) { if (!HDE_NUM("table_size", 8, 16384)) return 0; s->table_size = (int)v[0]; return 1; }
    if (strcmp(key, "table_seconds") == 0) { if (!HDE_NUM("table_seconds", 0, 1e5)) return 0; s->table_seconds = v[0]; return 1; }
    if (strcmp(key, "table_min_iterations") == 0) { if (!HDE_NUM("table_min_iterations", 1, 1e6)) return 0; s->table_min_iterations = (int)v[0]; return 1; }
    if (strcmp(key, "table_rounds") == 0) { if (!HDE_NUM("table_rounds", 1, 100)) return 0; s->table_rounds = (int)v[0]; return 1; }
    if (strcmp(key, "seed") == 0) { if (!HDE_NUM("seed", 0, 2147483647.0)) return 0; s->seed = (uint32_t)v[0]; return 1; }
    if (strcmp(key, "ref_seed") == 0) { if (!HDE_NUM("ref_seed", 0, 2147483646.0)) return 0; s->ref_seed = (uint32_t)v[0]; return 1; }
    if (strcmp(key, "threads") == 0) { if (!HDE_NUM("threads", 0, 4096)) return 0; s->threads = (int)v[0]; return 1; }
#undef HDE_NUM
#undef HDE_VEC3
    snprintf(err, errn, "unknown key '%s'", key);
    return 0;
}

static char *hde__trim(char *s)
{
    char *e;
    while (*s == ' ' || *s == '\t') ++s;
    e = s + strlen(s);
    while (e > s && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r' || e[-1] == '\n')) *--e = 0;
    return s;
}

/* Reads path into s (defaults first). Returns 1, or 0 with err ("FILE:LINE: what"). */
static int hde_scene_load(const char *path, int paper, hde_scene *s, char *err, size_t errn)
{
    int pass;
    hde_scene_defaults(s);
    for (pass = 0; pass < 2; ++pass) { /* pass 0: plain keys, pass 1: paper.* keys */
        char line[1024], what[256];
        int lineno = 0, lights_seen = 0;
        FILE *f = fopen(path, "r");
        if (!f) { snprintf(err, errn, "%s: cannot open: %s", path, strerror(errno)); return 0; }
        while (fgets(line, sizeof line, f)) {
            char *hash = strchr(line, '#'), *eq, *key, *val;
            ++lineno;
            if (hash) *hash = 0;
            key = hde__trim(line);
            if (!*key) continue;
            eq = strchr(key, '=');
            if (!eq) { snprintf(err, errn, "%s:%d: expected key = value", path, lineno); fclose(f); return 0; }
            *eq = 0;
            val = hde__trim(eq + 1);
            key = hde__trim(key);
            if (strncmp(key, "paper.", 6) == 0) {
                if (pass == 0) continue;
                if (!paper) continue;
                key += 6;
                if (strcmp(key, "light") == 0) {
                    snprintf(err, errn, "%s:%d: paper.light is not supported", path, lineno);
                    fclose(f);
                    return 0;
                }
            } else if (pass == 1) {
                continue;
            }
            if (pass == 0 && strcmp(key, "light") == 0 && lights_seen++ == 0) s->light_count = 0;
            if (!hde__apply(s, key, val, what, sizeof what)) {
                snprintf(err, errn, "%s:%d: %s", path, lineno, what);
                fclose(f);
                return 0;
            }
        }
        fclose(f);
    }
    if (s->light_count < 3) { snprintf(err, errn, "%s: needs 3 `light =` lines (1- and 3-light scenes)", path); return 0; }
    return 1;
}

#endif /* HD_EVAL_SCENE_H */
