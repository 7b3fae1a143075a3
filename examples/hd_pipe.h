// hd_pipe.h - what the tools' C++ readers (hd_dicom.cpp, hd_vdb.cpp) share to talk to the child
// process that parses a file for them: whole writes to a pipe and a monotonic clock.
#ifndef HD_PIPE_H
#define HD_PIPE_H
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>

namespace hdx {

// Writes all n bytes (retrying after signals); false on an error or a closed pipe.
inline bool write_all(int fd, const void *p, size_t n)
{
    const char *c = static_cast<const char *>(p);
    while (n) {
        const ssize_t w = write(fd, c, n);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) return false;
        c += w, n -= (size_t)w;
    }
    return true;
}

// Seconds on the monotonic clock.
inline double now_s()
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

} // namespace hdx
#endif
