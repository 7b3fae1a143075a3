/* test_io_limits.c - what the loaders refuse to read and how much they allocate.
   MetaImage detached data: inside the header's folder only (relative names, '..', absolute
   names, symbolic links), unless hd_load_options.allow_outside_folder. Non-regular files (a
   directory, /dev/zero, a FIFO) as a header or as detached data: HD_ERROR_FILE_NOT_REGULAR,
   run in a child process with an alarm so that a hang or a read of /dev/zero fails the test
   instead of stalling it. Allocation: a counting hd_load_options.allocator measures the peak
   bytes live while loading; a short gzip stream claiming a huge volume, a file much longer
   than its header needs, and every format and encoding at about 1 M voxels. */
#include "hybriddiff.h"
#include "hd_test.h"
#include "tests/fuzz/hd_fuzz_gen.h"
#include <stdlib.h>
#include <stdint.h>
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <unistd.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>

typedef hd_test_log lim_log;
#define lim_logger hd_test_logger

#define LIM_EXPECT(call, want, log) \
    do { \
        hd_result r_ = (call); \
        CHECK_MSG(r_ == (want), "got %s, want %s (%s)", hd_result_string(r_), \
                  hd_result_string(want), (log).last); \
        CHECK_MSG((log).errors == 1 && (log).last[0], "%d errors logged", (log).errors); \
        CHECK((log).last_code == (want)); \
    } while (0)

/* ---- files ------------------------------------------------------------------------------------ */
static char lim_dir[256];

static void lim_cleanup(void)
{
    if (lim_dir[0] && strcmp(lim_dir, "/tmp") != 0) rmdir(lim_dir);
}

static const char *lim_path(const char *name)
{
    static char p[8][512];
    static int k;
    if (!lim_dir[0]) {
        const char *t = getenv("TMPDIR");
        snprintf(lim_dir, sizeof lim_dir, "%s/hd_test_lim_XXXXXX", t && *t ? t : "/tmp");
        if (!mkdtemp(lim_dir)) {
            fprintf(stderr, "  mkdtemp(%s) failed\n", lim_dir);
            snprintf(lim_dir, sizeof lim_dir, "/tmp");
        } else {
            atexit(lim_cleanup);
        }
    }
    k = (k + 1) % 8;
    snprintf(p[k], sizeof p[k], "%s/%s", lim_dir, name);
    return p[k];
}

static int lim_write(const char *path, const void *a, size_t na, const void *b, size_t nb)
{
    FILE *f = fopen(path, "wb");
    int ok;
    if (!f) return 0;
    if (!na) na = strlen((const char *)a);
    ok = fwrite(a, 1, na, f) == na;
    if (nb) ok = ok && fwrite(b, 1, nb, f) == nb;
    return fclose(f) == 0 && ok;
}

/* The constant of the peak-allocation bound: the longest header a loader reads (1 MiB) and its
   chunk buffers and zlib state (256 KiB). */
#define LIM_SLACK ((size_t)5 << 18)

/* ---- a counting allocator ---------------------------------------------------------------------- */
typedef struct lim_alloc {
    size_t live, peak, calls, blocks;
} lim_alloc;

#define LIM_HEAD 16 /* keeps the size; 16 keeps the alignment of malloc */

static void *lim_alloc_fn(size_t n, void *user)
{
    lim_alloc *a = (lim_alloc *)user;
    unsigned char *p = (unsigned char *)malloc(n + LIM_HEAD);
    if (!p) return NULL;
    memcpy(p, &n, sizeof n);
    a->live += n;
    if (a->live > a->peak) a->peak = a->live;
    ++a->calls;
    ++a->blocks;
    return p + LIM_HEAD;
}

static void lim_free_fn(void *ptr, void *user)
{
    lim_alloc *a = (lim_alloc *)user;
    unsigned char *p;
    size_t n;
    if (!ptr) return;
    p = (unsigned char *)ptr - LIM_HEAD;
    memcpy(&n, p, sizeof n);
    a->live -= n;
    --a->blocks;
    free(p);
}

static hd_load_options lim_options(lim_alloc *a)
{
    hd_load_options o;
    memset(&o, 0, sizeof o);
    memset(a, 0, sizeof *a);
    o.allocator.alloc = lim_alloc_fn;
    o.allocator.free = lim_free_fn;
    o.allocator.user_data = a;
    return o;
}

/* ---- a call that must neither hang nor read without end --------------------------------------- */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define LIM_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define LIM_SANITIZED 1
#endif
#endif

typedef hd_result (*lim_load_fn)(const char *path, hd_volume_file *out, const hd_logger *log);

/* Runs load(path) in a child process under a 10 s alarm (and, outside the sanitizers, an address
   space limit, so that a loader reading /dev/zero stops early). Returns the result code,
   or -1 if the child hung or crashed. The child exits 250 if the call logged other than one
   error with its code, 251 if an error left data in the output. */
static int lim_in_child(lim_load_fn load, const char *path)
{
    pid_t pid;
    int status;
    fflush(NULL);
    pid = fork();
    if (pid < 0) return -2;
    if (pid == 0) {
        lim_log l;
        hd_logger lg = lim_logger(&l);
        hd_volume_file v;
        hd_result r;
#ifndef LIM_SANITIZED
        { /* 1 GiB more address space than the process has now (Linux: /proc/self/statm) */
            FILE *f = fopen("/proc/self/statm", "r");
            unsigned long pages = 0;
            if (f && fscanf(f, "%lu", &pages) == 1 && pages) {
                struct rlimit rl;
                rl.rlim_cur = rl.rlim_max =
                    (rlim_t)pages * (rlim_t)sysconf(_SC_PAGESIZE) + ((rlim_t)1 << 30);
                setrlimit(RLIMIT_AS, &rl);
            }
            if (f) fclose(f);
        }
#endif
        alarm(10);
        r = load(path, &v, &lg);
        if (r != HD_SUCCESS && (l.errors != 1 || l.last_code != r)) _exit(250);
        if (r != HD_SUCCESS && v.data) _exit(251);
        hd_volume_free(&v);
        _exit((int)r);
    }
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return -2;
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return -1;
}

static hd_result lim_load_raw_u8(const char *path, hd_volume_file *out, const hd_logger *log)
{
    static const int dims[3] = {4, 4, 4};
    return hd_volume_load_raw(path, dims, HD_RAW_U8, HD_ENDIAN_LITTLE, 0, out, log);
}

#define LIM_CHILD(load, path, want) \
    do { \
        int got_ = lim_in_child(load, path); \
        CHECK_MSG(got_ == (int)(want), "%s(%s): %s%s (want %s)", #load, path, \
                  got_ == -1 ? "hung or crashed" \
                  : got_ == 250 ? "not one logged error" \
                  : got_ == 251 ? "data left after an error" \
                  : got_ >= 0 && got_ < HD_RESULT_COUNT ? hd_result_string((hd_result)got_) \
                  : "fork failed", "", hd_result_string(want)); \
    } while (0)

/* ---- detached data: where they may be ------------------------------------------------------- */
static const unsigned char lim_vox[64] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10};

static hd_result lim_mhd(const char *header_name, const char *data_file, hd_volume_file *v,
                         lim_log *l, const hd_load_options *opt)
{
    char text[1024];
    hd_logger lg = lim_logger(l);
    hd_result r;
    snprintf(text, sizeof text, "NDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
             "ElementDataFile = %s\n", data_file);
    CHECK(lim_write(lim_path(header_name), text, 0, NULL, 0));
    r = opt ? hd_volume_load_ex(lim_path(header_name), opt, v, &lg)
            : hd_volume_load_mhd(lim_path(header_name), v, &lg);
    if (r != HD_SUCCESS) CHECK(v->data == NULL);
    if (r == HD_SUCCESS) CHECK(v->data && memcmp(v->data, lim_vox, 64) == 0);
    hd_volume_free(v);
    return r;
}

static void lim_mhd_detached_policy(void)
{
    hd_volume_file v;
    lim_log l;
    hd_load_options allow;
    char abs_name[600], link_target[600];
    memset(&allow, 0, sizeof allow);
    allow.allow_outside_folder = 1;
    mkdir(lim_path("in"), 0755);
    mkdir(lim_path("in/sub"), 0755);
    CHECK(lim_write(lim_path("out.raw"), lim_vox, 64, NULL, 0));
    CHECK(lim_write(lim_path("in/a.raw"), lim_vox, 64, NULL, 0));
    CHECK(lim_write(lim_path("in/sub/b.raw"), lim_vox, 64, NULL, 0));
    /* inside: relative names, a sub-folder, '..' that stays inside, a link that stays inside */
    CHECK(lim_mhd("in/h.mhd", "a.raw", &v, &l, NULL) == HD_SUCCESS);
    CHECK(lim_mhd("in/h.mhd", "sub/b.raw", &v, &l, NULL) == HD_SUCCESS);
    CHECK(lim_mhd("in/h.mhd", "sub/../a.raw", &v, &l, NULL) == HD_SUCCESS);
    CHECK(symlink("sub/b.raw", lim_path("in/inner.raw")) == 0);
    CHECK(lim_mhd("in/h.mhd", "inner.raw", &v, &l, NULL) == HD_SUCCESS);
    /* outside: '..', an absolute name (even one naming a file inside), a link leading out */
    LIM_EXPECT(lim_mhd("in/h.mhd", "../out.raw", &v, &l, NULL), HD_ERROR_FILE_OUTSIDE_FOLDER, l);
    LIM_EXPECT(lim_mhd("in/h.mhd", "sub/../../out.raw", &v, &l, NULL),
               HD_ERROR_FILE_OUTSIDE_FOLDER, l);
    snprintf(abs_name, sizeof abs_name, "%s", lim_path("in/a.raw"));
    CHECK(abs_name[0] == '/');
    LIM_EXPECT(lim_mhd("in/h.mhd", abs_name, &v, &l, NULL), HD_ERROR_FILE_OUTSIDE_FOLDER, l);
    snprintf(link_target, sizeof link_target, "%s", lim_path("out.raw"));
    CHECK(symlink(link_target, lim_path("in/outer.raw")) == 0);
    LIM_EXPECT(lim_mhd("in/h.mhd", "outer.raw", &v, &l, NULL), HD_ERROR_FILE_OUTSIDE_FOLDER, l);
    CHECK(symlink("../../out.raw", lim_path("in/sub/up.raw")) == 0);
    LIM_EXPECT(lim_mhd("in/h.mhd", "sub/up.raw", &v, &l, NULL), HD_ERROR_FILE_OUTSIDE_FOLDER, l);
    CHECK(strstr(l.last, "outside the header's folder") != NULL);
    /* the same through hd_volume_load, which picks the loader by the extension */
    {
        hd_logger lg = lim_logger(&l);
        LIM_EXPECT(hd_volume_load(lim_path("in/h.mhd"), &v, &lg), HD_ERROR_FILE_OUTSIDE_FOLDER,
                   l);
    }
    /* allowed by the option */
    CHECK(lim_mhd("in/h.mhd", "../out.raw", &v, &l, &allow) == HD_SUCCESS);
    CHECK(lim_mhd("in/h.mhd", abs_name, &v, &l, &allow) == HD_SUCCESS);
    CHECK(lim_mhd("in/h.mhd", "outer.raw", &v, &l, &allow) == HD_SUCCESS);
    /* a missing data file is still a file error naming it */
    LIM_EXPECT(lim_mhd("in/h.mhd", "nope.raw", &v, &l, NULL), HD_ERROR_FILE_IO, l);
    CHECK(strstr(l.last, "nope.raw") != NULL);
    LIM_EXPECT(lim_mhd("in/h.mhd", "nope.raw", &v, &l, &allow), HD_ERROR_FILE_IO, l);
    CHECK(strstr(l.last, "nope.raw") != NULL);
    remove(lim_path("in/sub/up.raw"));
    remove(lim_path("in/outer.raw"));
    remove(lim_path("in/inner.raw"));
    remove(lim_path("in/sub/b.raw"));
    remove(lim_path("in/a.raw"));
    remove(lim_path("in/h.mhd"));
    remove(lim_path("out.raw"));
    rmdir(lim_path("in/sub"));
    rmdir(lim_path("in"));
}

/* ---- non-regular files ----------------------------------------------------------------------- */
static hd_result lim_load_mhd_in_child(const char *path, hd_volume_file *out, const hd_logger *lg)
{
    hd_load_options o;
    memset(&o, 0, sizeof o);
    o.allow_outside_folder = 1; /* so that only the file's kind can refuse it */
    return hd_volume_load_ex(path, &o, out, lg);
}

static void lim_not_regular(void)
{
    const char *fifo = lim_path("fifo.raw");
    const char *fifo_nii = lim_path("fifo.nii");
    lim_log l;
    hd_logger lg;
    hd_volume_file v;
    CHECK(mkfifo(fifo, 0600) == 0);
    CHECK(mkfifo(fifo_nii, 0600) == 0);
    /* as the main file of every loader */
    LIM_CHILD(hd_volume_load_nrrd, fifo, HD_ERROR_FILE_NOT_REGULAR);
    LIM_CHILD(hd_volume_load_nifti, fifo_nii, HD_ERROR_FILE_NOT_REGULAR);
    LIM_CHILD(hd_volume_load_mhd, fifo, HD_ERROR_FILE_NOT_REGULAR);
    LIM_CHILD(hd_volume_load, fifo_nii, HD_ERROR_FILE_NOT_REGULAR);
    LIM_CHILD(lim_load_raw_u8, fifo, HD_ERROR_FILE_NOT_REGULAR);
    if (access("/dev/zero", R_OK) == 0) {
        LIM_CHILD(hd_volume_load_nrrd, "/dev/zero", HD_ERROR_FILE_NOT_REGULAR);
        LIM_CHILD(hd_volume_load_nifti, "/dev/zero", HD_ERROR_FILE_NOT_REGULAR);
        LIM_CHILD(hd_volume_load_mhd, "/dev/zero", HD_ERROR_FILE_NOT_REGULAR);
        LIM_CHILD(hd_volume_load, "/dev/zero", HD_ERROR_FILE_NOT_REGULAR);
        LIM_CHILD(lim_load_raw_u8, "/dev/zero", HD_ERROR_FILE_NOT_REGULAR);
    }
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load(lim_dir, &v, &lg), HD_ERROR_FILE_NOT_REGULAR, l);
    CHECK(strstr(l.last, "directory") != NULL);
    /* as MetaImage detached data: a FIFO inside the folder, /dev/zero (allowed outside), a link
       to /dev/zero (outside by default), HeaderSize -1 (which would seek from the end) */
    CHECK(lim_write(lim_path("f.mhd"), "NDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
                    "ElementDataFile = fifo.raw\n", 0, NULL, 0));
    LIM_CHILD(hd_volume_load_mhd, lim_path("f.mhd"), HD_ERROR_FILE_NOT_REGULAR);
    CHECK(lim_write(lim_path("z.mhd"), "NDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
                    "HeaderSize = -1\nElementDataFile = /dev/zero\n", 0, NULL, 0));
    LIM_CHILD(hd_volume_load_mhd, lim_path("z.mhd"), HD_ERROR_FILE_OUTSIDE_FOLDER);
    if (access("/dev/zero", R_OK) == 0) {
        LIM_CHILD(lim_load_mhd_in_child, lim_path("z.mhd"), HD_ERROR_FILE_NOT_REGULAR);
        CHECK(symlink("/dev/zero", lim_path("zero.raw")) == 0);
        CHECK(lim_write(lim_path("l.mhd"), "NDims = 3\nDimSize = 4 4 4\n"
                        "ElementType = MET_UCHAR\nElementDataFile = zero.raw\n", 0, NULL, 0));
        LIM_CHILD(hd_volume_load_mhd, lim_path("l.mhd"), HD_ERROR_FILE_OUTSIDE_FOLDER);
        LIM_CHILD(lim_load_mhd_in_child, lim_path("l.mhd"), HD_ERROR_FILE_NOT_REGULAR);
        remove(lim_path("zero.raw"));
        remove(lim_path("l.mhd"));
    }
    remove(lim_path("f.mhd"));
    remove(lim_path("z.mhd"));
    remove(fifo);
    remove(fifo_nii);
}

/* ---- data shorter and longer than declared ------------------------------------------------------ */
static void lim_data_length(void)
{
    hd_volume_file v;
    lim_log l;
    lim_alloc a;
    hd_load_options o = lim_options(&a);
    hd_logger lg;
    int fd;
    const uint64_t huge = (uint64_t)1 << 30; /* sparse: takes no disk */
    CHECK(lim_write(lim_path("d.mhd"), "NDims = 3\nDimSize = 4 4 4\nElementType = MET_UCHAR\n"
                    "ElementDataFile = d.raw\n", 0, NULL, 0));
    /* shorter */
    CHECK(lim_write(lim_path("d.raw"), lim_vox, 63, NULL, 0));
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_mhd(lim_path("d.mhd"), &v, &lg), HD_ERROR_FILE_TRUNCATED, l);
    /* longer: 1 GiB, of which the 64 bytes the header needs are read */
    CHECK(lim_write(lim_path("d.raw"), lim_vox, 64, NULL, 0));
    fd = open(lim_path("d.raw"), O_WRONLY);
    CHECK(fd >= 0 && ftruncate(fd, (off_t)huge) == 0);
    if (fd >= 0) close(fd);
    lg = lim_logger(&l);
    CHECK(hd_volume_load_ex(lim_path("d.mhd"), &o, &v, &lg) == HD_SUCCESS);
    CHECK(v.data && memcmp(v.data, lim_vox, 64) == 0 && l.errors == 0);
    CHECK_MSG(a.peak <= 128 + LIM_SLACK, "peak %zu bytes for 64 bytes of data", a.peak);
    hd_volume_free(&v);
    CHECK(a.live == 0 && a.blocks == 0);
    /* the same for a NRRD and a NIfTI file followed by 1 GiB */
    {
        static const char *names[2] = {"long.nrrd", "long.nii"};
        size_t n[2];
        unsigned char *b[2];
        int dim[3] = {4, 4, 4}, i;
        float pix[3] = {1, 1, 1};
        b[0] = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n",
                       lim_vox, 64, &n[0]);
        b[1] = gen_nifti(0, 2, 8, 3, dim, pix, 352, 0, 0, lim_vox, 64, &n[1]);
        for (i = 0; i < 2; ++i) {
            CHECK(lim_write(lim_path(names[i]), b[i], n[i], NULL, 0));
            fd = open(lim_path(names[i]), O_WRONLY);
            CHECK(fd >= 0 && ftruncate(fd, (off_t)huge) == 0);
            if (fd >= 0) close(fd);
            o = lim_options(&a);
            lg = lim_logger(&l);
            CHECK(hd_volume_load_ex(lim_path(names[i]), &o, &v, &lg) == HD_SUCCESS);
            CHECK(v.data && memcmp(v.data, lim_vox, 64) == 0);
            CHECK_MSG(a.peak <= 128 + LIM_SLACK, "%s: peak %zu bytes for 64 bytes of data",
                      names[i], a.peak);
            hd_volume_free(&v);
            CHECK(a.live == 0);
            remove(lim_path(names[i]));
            free(b[i]);
        }
    }
    remove(lim_path("d.raw"));
    remove(lim_path("d.mhd"));
}

/* ---- allocation --------------------------------------------------------------------------------- */
static uint32_t lim_rng = 12345u;
static unsigned char lim_byte(void)
{
    lim_rng = lim_rng * 1664525u + 1013904223u;
    return (unsigned char)(lim_rng >> 24);
}

/* A gzip stream of `real` random bytes (incompressible: the stream is as long) under headers
   claiming 1024^3 voxels of u8: the old guard (1032:1) let that allocate 1 GiB. */
static void lim_gzip_claim(void)
{
    const size_t real = (size_t)1100 << 10;
    unsigned char *d = (unsigned char *)malloc(real), *z, *b;
    size_t zn, n, i;
    int k;
    for (i = 0; i < real; ++i) d[i] = lim_byte();
    z = gen_deflate(d, real, 1, &zn);
    for (k = 0; k < 3; ++k) {
        static const char *names[3] = {"claim.nrrd", "claim.mha", "claim.nii.gz"};
        lim_alloc a;
        hd_load_options o = lim_options(&a);
        lim_log l;
        hd_logger lg = lim_logger(&l);
        hd_volume_file v;
        if (k == 0) {
            b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1024 1024 1024\n"
                        "encoding: gzip\n\n", z, zn, &n);
        } else if (k == 1) {
            b = gen_cat("NDims = 3\nDimSize = 1024 1024 1024\nElementType = MET_UCHAR\n"
                        "CompressedData = True\nElementDataFile = LOCAL\n", z, zn, &n);
        } else { /* a .nii of 1024^3 claimed, 1.1 MiB there, gzipped */
            int dim[3] = {1024, 1024, 1024};
            float pix[3] = {1, 1, 1};
            unsigned char *nii = gen_nifti(0, 2, 8, 3, dim, pix, 352, 0, 0, d, real, &n);
            b = gen_deflate(nii, n, 1, &n);
            free(nii);
        }
        CHECK(lim_write(lim_path(names[k]), b, n, NULL, 0));
        LIM_EXPECT(hd_volume_load_ex(lim_path(names[k]), &o, &v, &lg), HD_ERROR_FILE_TRUNCATED,
                   l);
        CHECK_MSG(a.peak <= 2 * real + LIM_SLACK,
                  "%s: peak allocation %zu bytes for %zu bytes really there", names[k], a.peak,
                  real);
        CHECK(a.live == 0 && a.calls > 0);
        printf("  %s: claims 1 GiB, holds %zu KiB: peak allocation %zu KiB\n", names[k],
               real >> 10, a.peak >> 10);
        remove(lim_path(names[k]));
        free(b);
    }
    free(z);
    free(d);
}

/* Every format and encoding: peak <= 2 x the volume + 1.25 MiB (the longest header a loader
   reads, 1 MiB, and its chunk buffers). Sizes that are not powers of two, so that a growing
   buffer's last step copies most of the volume; u8 at 4 M voxels, where reading the whole file
   (its buffer, then the volume) or inflating all of it before converting would exceed the bound;
   short and double at 1 M voxels (loaded as f32). */
static void lim_peak_allocation(void)
{
    static const int dims[2][3] = {{160, 160, 161}, {100, 101, 99}};
    const size_t most = (size_t)160 * 160 * 161 * 8;
    unsigned char *raw = (unsigned char *)malloc(most);
    float pix[3] = {1, 1, 1};
    size_t i;
    int c;
    for (i = 0; i < most; ++i) raw[i] = lim_byte();
    for (i = 7; i < most; i += 8) raw[i] &= 0x3f; /* finite doubles: a tame exponent */
    for (c = 0; c < 18; ++c) {
        /* type: 0 u8, 1 short, 2 double; container: 0 nrrd raw, 1 nrrd gzip, 2 mha LOCAL zlib,
           3 mhd + detached raw, 4 .nii, 5 .nii.gz */
        static const char *nrrd_t[3] = {"uchar", "short", "double"};
        static const char *met_t[3] = {"MET_UCHAR", "MET_SHORT", "MET_DOUBLE"};
        static const int nii_t[3] = {2, 4, 64}, bits[3] = {8, 16, 64};
        static const size_t es[3] = {1, 2, 8}, os[3] = {1, 4, 4};
        int type = c % 3, container = c / 3;
        const int *dim = dims[type != 0];
        int NX = dim[0], NY = dim[1], NZ = dim[2];
        size_t count = (size_t)NX * NY * NZ;
        size_t data = count * es[type], vol = count * (es[type] > os[type] ? es[type] : os[type]);
        const char *name = container == 0 || container == 1 ? "p.nrrd"
                           : container == 2 ? "p.mha" : container == 3 ? "p.mhd"
                           : container == 4 ? "p.nii" : "p.nii.gz";
        char text[256];
        unsigned char *b = NULL, *z = NULL;
        size_t n = 0, zn;
        lim_alloc a;
        hd_load_options o = lim_options(&a);
        lim_log l;
        hd_logger lg = lim_logger(&l);
        hd_volume_file v;
        hd_result r;
        if (container <= 1) {
            snprintf(text, sizeof text, "NRRD0004\ntype: %s\ndimension: 3\nsizes: %d %d %d\n"
                     "endian: little\nencoding: %s\n\n", nrrd_t[type], NX, NY, NZ,
                     container ? "gzip" : "raw");
            if (container) z = gen_deflate(raw, data, 1, &zn);
            b = gen_cat(text, container ? z : raw, container ? zn : data, &n);
        } else if (container <= 3) {
            snprintf(text, sizeof text, "NDims = 3\nDimSize = %d %d %d\nElementType = %s\n%s"
                     "ElementDataFile = %s\n", NX, NY, NZ, met_t[type],
                     container == 2 ? "CompressedData = True\n" : "",
                     container == 2 ? "LOCAL" : "p.raw");
            if (container == 2) z = gen_deflate(raw, data, 0, &zn);
            b = gen_cat(text, container == 2 ? z : NULL, container == 2 ? zn : 0, &n);
            if (container == 3) CHECK(lim_write(lim_path("p.raw"), raw, data, NULL, 0));
        } else {
            b = gen_nifti(0, nii_t[type], bits[type], 3, dim, pix, 352, 0, 0, raw, data, &n);
            if (container == 5) {
                z = b;
                b = gen_deflate(z, n, 1, &n);
            }
        }
        CHECK(lim_write(lim_path(name), b, n, NULL, 0));
        r = hd_volume_load_ex(lim_path(name), &o, &v, &lg);
        CHECK_MSG(r == HD_SUCCESS, "%s (%s): %s %s", name, nrrd_t[type], hd_result_string(r),
                  l.last);
        if (r == HD_SUCCESS) {
            CHECK(v.desc.dims[0] == NX && v.desc.dims[1] == NY && v.desc.dims[2] == NZ);
            if (type == 0) CHECK(v.data && memcmp(v.data, raw, count) == 0);
        }
        CHECK_MSG(a.peak <= 2 * vol + LIM_SLACK,
                  "%s (%s): peak %zu bytes, volume %zu", name, nrrd_t[type], a.peak, vol);
        printf("  %-9s %-6s volume %6zu KiB, peak allocation %6zu KiB (%.2f x)\n", name,
               nrrd_t[type], vol >> 10, a.peak >> 10, (double)a.peak / (double)vol);
        hd_volume_free(&v);
        CHECK_MSG(a.live == 0 && a.blocks == 0, "%s: %zu bytes in %zu blocks not freed", name,
                  a.live, a.blocks);
        remove(lim_path(name));
        if (container == 3) remove(lim_path("p.raw"));
        free(b);
        free(z);
    }
    free(raw);
}

/* max_bytes, counted in the file's type and the loaded type: a 4x4x4 volume of u8 takes 64
   bytes, of short 256 once loaded as f32. */
static void lim_max_bytes(void)
{
    unsigned char d[128];
    size_t n, zn;
    unsigned char *b, *z;
    hd_load_options o;
    hd_volume_file v;
    lim_log l;
    hd_logger lg;
    int dim[3] = {4, 4, 4};
    float pix[3] = {1, 1, 1};
    memset(d, 7, sizeof d);
    memset(&o, 0, sizeof o);
    b = gen_cat("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n", d, 64,
                &n);
    CHECK(lim_write(lim_path("m.nrrd"), b, n, NULL, 0));
    free(b);
    o.max_bytes = 64;
    lg = lim_logger(&l);
    CHECK(hd_volume_load_ex(lim_path("m.nrrd"), &o, &v, &lg) == HD_SUCCESS);
    hd_volume_free(&v);
    o.max_bytes = 63;
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_ex(lim_path("m.nrrd"), &o, &v, &lg), HD_ERROR_FILE_TOO_LARGE, l);
    /* char: 64 bytes in the file, 128 loaded (widened to I16) */
    z = gen_deflate(d, 64, 0, &zn);
    b = gen_cat("NDims = 3\nDimSize = 4 4 4\nElementType = MET_CHAR\nCompressedData = True\n"
                "ElementDataFile = LOCAL\n", z, zn, &n);
    CHECK(lim_write(lim_path("m.mha"), b, n, NULL, 0));
    free(b);
    free(z);
    o.max_bytes = 127;
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_ex(lim_path("m.mha"), &o, &v, &lg), HD_ERROR_FILE_TOO_LARGE, l);
    o.max_bytes = 128;
    lg = lim_logger(&l);
    CHECK(hd_volume_load_ex(lim_path("m.mha"), &o, &v, &lg) == HD_SUCCESS);
    hd_volume_free(&v);
    b = gen_nifti(0, 2, 8, 3, dim, pix, 352, 0, 0, d, 64, &n);
    z = gen_deflate(b, n, 1, &zn);
    CHECK(lim_write(lim_path("m.nii.gz"), z, zn, NULL, 0));
    free(b);
    free(z);
    o.max_bytes = 63;
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_ex(lim_path("m.nii.gz"), &o, &v, &lg), HD_ERROR_FILE_TOO_LARGE, l);
    /* the options themselves */
    o.max_bytes = 0;
    o.format = HD_FILE_NRRD;
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_ex(lim_path("m.nii.gz"), &o, &v, &lg), HD_ERROR_FILE_FORMAT, l);
    o.format = HD_FILE_NIFTI;
    lg = lim_logger(&l);
    CHECK(hd_volume_load_ex(lim_path("m.nii.gz"), &o, &v, &lg) == HD_SUCCESS);
    hd_volume_free(&v);
    o.format = HD_FILE_FORMAT_COUNT;
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_ex(lim_path("m.nii.gz"), &o, &v, &lg), HD_ERROR_INVALID_ENUM, l);
    o.format = HD_FILE_AUTO;
    o.allocator.alloc = lim_alloc_fn;
    lg = lim_logger(&l);
    LIM_EXPECT(hd_volume_load_ex(lim_path("m.nii.gz"), &o, &v, &lg), HD_ERROR_NULL_POINTER, l);
    remove(lim_path("m.nrrd"));
    remove(lim_path("m.mha"));
    remove(lim_path("m.nii.gz"));
}

/* Every allocation of a load failed once (the allocator returns NULL for the k-th call):
   HD_ERROR_OUT_OF_MEMORY with one logged line, nothing left allocated. */
typedef struct lim_fail {
    lim_alloc a;
    size_t fail_at;
} lim_fail;

static void *lim_fail_alloc(size_t n, void *user)
{
    lim_fail *f = (lim_fail *)user;
    if (f->a.calls + 1 == f->fail_at) {
        ++f->a.calls;
        return NULL;
    }
    return lim_alloc_fn(n, &f->a);
}

static void lim_fail_free(void *p, void *user) { lim_free_fn(p, &((lim_fail *)user)->a); }

static void lim_alloc_fail(void)
{
    enum { N = 48 }; /* N^3 > 64 Ki voxels: gzip output grows twice, so a failure can strand one */
    const size_t bytes = (size_t)N * N * N;
    unsigned char *d = (unsigned char *)malloc(bytes), *b, *z;
    size_t n, zn, i;
    int k, dim[3] = {N, N, N};
    float pix[3] = {1, 1, 1};
    static const char *names[3] = {"f.nii.gz", "f.nrrd", "f.mhd"};
    for (i = 0; i < bytes; ++i) d[i] = lim_byte();
    b = gen_nifti(0, 2, 8, 3, dim, pix, 352, 2.0f, 1.0f, d, bytes, &n); /* rescaled too */
    z = gen_deflate(b, n, 1, &zn);
    CHECK(lim_write(lim_path(names[0]), z, zn, NULL, 0));
    free(b);
    free(z);
    b = gen_cat("NRRD0004\ntype: short\ndimension: 3\nsizes: 48 48 24\nencoding: raw\n\n", d,
                bytes, &n);
    CHECK(lim_write(lim_path(names[1]), b, n, NULL, 0));
    free(b);
    CHECK(lim_write(lim_path(names[2]), "NDims = 3\nDimSize = 48 48 48\nElementType = MET_UCHAR\n"
                    "CompressedData = True\nElementDataFile = f.zraw\n", 0, NULL, 0));
    z = gen_deflate(d, bytes, 0, &zn);
    CHECK(lim_write(lim_path("f.zraw"), z, zn, NULL, 0));
    free(z);
    free(d);
    for (k = 0; k < 3; ++k) {
        lim_fail f;
        hd_load_options o;
        size_t total, at;
        hd_volume_file v;
        lim_log l;
        hd_logger lg = lim_logger(&l);
        memset(&f, 0, sizeof f);
        memset(&o, 0, sizeof o);
        o.allocator.alloc = lim_fail_alloc;
        o.allocator.free = lim_fail_free;
        o.allocator.user_data = &f;
        CHECK(hd_volume_load_ex(lim_path(names[k]), &o, &v, &lg) == HD_SUCCESS);
        hd_volume_free(&v);
        total = f.a.calls;
        CHECK(total >= 3 && f.a.live == 0);
        for (at = 1; at <= total; ++at) {
            hd_result r;
            memset(&f, 0, sizeof f);
            f.fail_at = at;
            lg = lim_logger(&l);
            r = hd_volume_load_ex(lim_path(names[k]), &o, &v, &lg);
            CHECK_MSG(r == HD_ERROR_OUT_OF_MEMORY && l.errors == 1 &&
                      l.last_code == HD_ERROR_OUT_OF_MEMORY && v.data == NULL,
                      "%s, allocation %zu failed: %s (%d errors)", names[k], at,
                      hd_result_string(r), l.errors);
            hd_volume_free(&v);
            CHECK_MSG(f.a.live == 0, "%s, allocation %zu failed: %zu bytes leaked", names[k], at,
                      f.a.live);
        }
        remove(lim_path(names[k]));
    }
    remove(lim_path("f.zraw"));
}

const hd_test_case hd_tests_io_limits[] = {
    {"io_mhd_detached_policy", lim_mhd_detached_policy},
    {"io_not_regular", lim_not_regular},
    {"io_data_length", lim_data_length},
    {"io_gzip_claim", lim_gzip_claim},
    {"io_peak_allocation", lim_peak_allocation},
    {"io_max_bytes", lim_max_bytes},
    {"io_alloc_fail_every_k", lim_alloc_fail},
};
const int hd_tests_io_limits_count = sizeof hd_tests_io_limits / sizeof hd_tests_io_limits[0];
