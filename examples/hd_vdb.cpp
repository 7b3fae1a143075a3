// hd_vdb.cpp - OpenVDB grids for the example tools (see hd_vdb.h). A child process opens the file
// with OpenVDB under limits on address space and CPU time, densifies the chosen float grid over
// its active bounding box and sends it through a pipe: OpenVDB trusts the lengths a file claims,
// and a damaged file must cost the tool an error line, not its life.
#include "hd_vdb.h"
#include "hd_pipe.h"

#include <openvdb/openvdb.h>

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

namespace {

using hdx::now_s;
using hdx::write_all;

const unsigned long long kMaxVoxels = 1ull << 31; // the dense box: 8 GiB of float32

// What the child sends before the voxels. msg is empty on success.
struct header {
    char msg[480];
    int dims[3];
    double spacing[3];
    double world[16]; // index to world, column-major, column vectors
    int origin[3];    // index of the box's first voxel
    float lo, hi;     // value range
    unsigned long long non_finite;
};

void set_msg(header &h, const std::string &m)
{
    std::snprintf(h.msg, sizeof h.msg, "%s", m.c_str());
    for (char *p = h.msg; *p; ++p)
        if ((unsigned char)*p < 32 || *p == 127) *p = '?';
}

// Reads n bytes before the deadline; false on timeout, error or end of file.
bool read_until(int fd, void *p, size_t n, double deadline)
{
    char *c = static_cast<char *>(p);
    while (n) {
        double left = deadline - now_s();
        if (left <= 0) return false;
        struct pollfd q = {fd, POLLIN, 0};
        int pr = poll(&q, 1, (int)(left * 1000.0) + 1);
        if (pr < 0 && errno == EINTR) continue;
        if (pr <= 0) return false;
        ssize_t r = read(fd, c, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return false;
        c += r;
        n -= (size_t)r;
    }
    return true;
}

// The grid to read: by name, else "density", else the first float grid.
openvdb::FloatGrid::Ptr pick_grid(openvdb::io::File &file, const std::string &name, header &h)
{
    openvdb::GridPtrVecPtr meta = file.readAllGridMetadata();
    std::string chosen, kinds;
    bool found = false;
    for (const openvdb::GridBase::Ptr &g : *meta) {
        const std::string n = g->getName(), t = g->valueType();
        if (kinds.size() < 200) kinds += (kinds.empty() ? "" : ", ") + (n.empty() ? std::string("(unnamed)") : n) + " (" + t + ")";
        if (!name.empty() && n == name) {
            if (t != "float") return set_msg(h, "grid '" + name + "' holds " + t + " values, not float"), nullptr;
            chosen = n, found = true;
        } else if (name.empty() && t == "float" && (!found || n == "density") && chosen != "density") {
            chosen = n, found = true;
        }
    }
    if (!found) {
        set_msg(h, meta->empty() ? std::string("the file holds no grid")
                   : name.empty() ? "no float grid (the file has " + kinds + ")"
                                  : "no grid named '" + name + "' (the file has " + kinds + ")");
        return nullptr;
    }
    return openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid(chosen));
}

// The child: reads the grid and writes the header, then the voxels, to fd.
void child(const std::string &path, const std::string &name, int fd)
{
    header h;
    std::memset(&h, 0, sizeof h);
    std::vector<float> dense;
    try {
        openvdb::initialize();
        openvdb::io::File file(path);
        file.open(false);
        openvdb::FloatGrid::Ptr grid = pick_grid(file, name, h);
        file.close();
        if (grid) {
            const openvdb::math::Transform &xf = grid->transform();
            const openvdb::CoordBBox bb = grid->evalActiveVoxelBoundingBox();
            if (!xf.isLinear()) {
                set_msg(h, "the grid's transform is not linear (a frustum map): only scale, rotation and translation are read");
            } else if (bb.empty()) {
                set_msg(h, "grid '" + grid->getName() + "' has no active voxel");
            } else {
                const openvdb::Coord d = bb.dim();
                const unsigned long long n = (unsigned long long)d.x() * (unsigned long long)d.y() * (unsigned long long)d.z();
                if (d.x() > HD_MAX_DIM || d.y() > HD_MAX_DIM || d.z() > HD_MAX_DIM || n > kMaxVoxels) {
                    char m[160];
                    std::snprintf(m, sizeof m, "the active voxels span %d x %d x %d: more than %d per axis or 2^31 in all",
                                  d.x(), d.y(), d.z(), HD_MAX_DIM);
                    set_msg(h, m);
                } else {
                    const float bg = grid->background();
                    dense.assign((size_t)n, bg);
                    const size_t sx = (size_t)d.x(), sxy = sx * (size_t)d.y();
                    const openvdb::Coord o = bb.min();
                    for (openvdb::FloatGrid::ValueOnCIter it = grid->cbeginValueOn(); it; ++it) {
                        openvdb::CoordBBox b;
                        it.getBoundingBox(b);
                        b.intersect(bb);
                        const float v = *it;
                        for (int z = b.min().z(); z <= b.max().z(); ++z)
                            for (int y = b.min().y(); y <= b.max().y(); ++y)
                                for (int x = b.min().x(); x <= b.max().x(); ++x)
                                    dense[(size_t)(z - o.z()) * sxy + (size_t)(y - o.y()) * sx + (size_t)(x - o.x())] = v;
                    }
                    bool any = false;
                    for (float &v : dense) {
                        if (!std::isfinite(v)) {
                            v = 0.0f;
                            ++h.non_finite;
                        }
                        if (!any) h.lo = h.hi = v, any = true;
                        h.lo = std::min(h.lo, v);
                        h.hi = std::max(h.hi, v);
                    }
                    const openvdb::math::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
                    // OpenVDB multiplies row vectors: world = index * m; ours are columns
                    for (int r = 0; r < 4; ++r)
                        for (int c = 0; c < 4; ++c) h.world[c * 4 + r] = m(c, r);
                    const openvdb::Vec3d vs = xf.voxelSize();
                    for (int a = 0; a < 3; ++a) {
                        h.dims[a] = d[a];
                        h.origin[a] = o[a];
                        h.spacing[a] = vs[a];
                    }
                }
            }
        }
    } catch (const std::bad_alloc &) {
        set_msg(h, "out of memory reading the file (damaged, or larger than the reader's limit)");
        dense.clear();
    } catch (const std::exception &e) {
        set_msg(h, std::string("OpenVDB: ") + e.what());
        dense.clear();
    }
    if (!h.msg[0] && dense.empty()) set_msg(h, "nothing read");
    if (!write_all(fd, &h, sizeof h)) _exit(1);
    if (!h.msg[0] && !write_all(fd, dense.data(), dense.size() * sizeof(float))) _exit(1);
    _exit(0);
}

bool fail(char *err, size_t size, const std::string &msg)
{
    if (size) std::snprintf(err, size, "%s", msg.c_str());
    return false;
}

unsigned long long physical_memory()
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    return pages > 0 && page > 0 ? (unsigned long long)pages * (unsigned long long)page : 8ull << 30;
}

} // namespace

extern "C" int hdx_is_vdb(const char *path)
{
    if (!path) return 0;
    const char *dot = std::strrchr(path, '.');
    if (!dot) return 0;
    std::string ext(dot + 1);
    const size_t colon = ext.find(':');
    if (colon != std::string::npos) ext.resize(colon);
    for (char &c : ext) c = (char)std::tolower((unsigned char)c);
    return ext == "vdb";
}

extern "C" int hdx_vdb_load(const char *path_c, hd_volume_file *out, char *err, size_t err_size)
{
    if (!path_c || !out) return fail(err, err_size, "no file or no output");
    std::memset(out, 0, sizeof *out);
    std::string path(path_c), name;
    const size_t dot = path.rfind('.');
    const size_t colon = dot == std::string::npos ? std::string::npos : path.find(':', dot);
    if (colon != std::string::npos) {
        name = path.substr(colon + 1);
        path.resize(colon);
        if (name.empty()) return fail(err, err_size, path + ": an empty grid name after ':'");
    }
    struct stat st;
    if (stat(path.c_str(), &st) != 0) return fail(err, err_size, path + ": " + std::strerror(errno));
    if (!S_ISREG(st.st_mode)) return fail(err, err_size, path + ": not a regular file");
    if (st.st_size == 0) return fail(err, err_size, path + ": empty file");

    int fds[2];
    if (pipe(fds) != 0) return fail(err, err_size, std::string("cannot make a pipe: ") + std::strerror(errno));
    // CPU: a minute plus a second per 8 MiB; memory: half the machine's
    const unsigned cpu_s = 60u + (unsigned)((unsigned long long)st.st_size >> 23);
    const unsigned long long as_bytes = std::max(physical_memory() / 2, 2ull << 30);
    const pid_t pid = fork();
    if (pid < 0) {
        close(fds[0]);
        close(fds[1]);
        return fail(err, err_size, std::string("cannot fork: ") + std::strerror(errno));
    }
    if (pid == 0) {
        close(fds[0]);
        signal(SIGPIPE, SIG_IGN);
        struct rlimit none = {0, 0}, cpu = {cpu_s, cpu_s + 1}, as = {as_bytes, as_bytes};
        setrlimit(RLIMIT_CORE, &none); // an abort leaves no core file behind
        setrlimit(RLIMIT_FSIZE, &none);
        setrlimit(RLIMIT_CPU, &cpu);
        setrlimit(RLIMIT_AS, &as);
        child(path, name, fds[1]);
    }
    close(fds[1]);
    const double deadline = now_s() + 4.0 * cpu_s;
    header h;
    std::string why;
    float *data = nullptr;
    if (!read_until(fds[0], &h, sizeof h, deadline)) {
        why = "the reader stopped";
    } else if (h.msg[0]) {
        h.msg[sizeof h.msg - 1] = 0;
        why = h.msg;
    } else {
        const size_t n = (size_t)h.dims[0] * (size_t)h.dims[1] * (size_t)h.dims[2];
        data = static_cast<float *>(std::malloc(n * sizeof(float)));
        if (!data) why = "out of memory for the dense volume";
        else if (!read_until(fds[0], data, n * sizeof(float), deadline)) why = "the reader stopped";
    }
    close(fds[0]);
    if (!why.empty() && why == "the reader stopped") kill(pid, SIGKILL);
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {}
    if (why == "the reader stopped") {
        if (WIFSIGNALED(status))
            why = WTERMSIG(status) == SIGXCPU || WTERMSIG(status) == SIGKILL
                      ? "OpenVDB took too long (damaged file?)"
                      : std::string("OpenVDB crashed on the file (") + strsignal(WTERMSIG(status)) + ")";
        else why = "OpenVDB stopped before the grid was read";
    }
    if (!why.empty()) {
        std::free(data);
        return fail(err, err_size, path + ": " + why);
    }
    if (h.non_finite)
        std::fprintf(stderr, "warning: %s: %llu non-finite values read as 0\n", path.c_str(), h.non_finite);

    // The library's box, centred at 0 with its largest side 1, to the grid's world: box point b
    // is at index origin - 0.5 + dims / 2 + b * L / spacing (L the box's largest side in world
    // units), then the grid's map takes the index to world.
    hd_volume_desc &d = out->desc;
    double L = 0.0;
    for (int a = 0; a < 3; ++a) {
        d.dims[a] = h.dims[a];
        d.spacing[a] = (float)h.spacing[a];
        L = std::max(L, h.dims[a] * h.spacing[a]);
    }
    double idx[3];
    for (int a = 0; a < 3; ++a) idx[a] = h.origin[a] - 0.5 + 0.5 * h.dims[a];
    for (int r = 0; r < 3; ++r) {
        double t = h.world[12 + r];
        for (int c = 0; c < 3; ++c) {
            d.transform[c * 4 + r] = (float)(h.world[c * 4 + r] * L / h.spacing[c]);
            t += h.world[c * 4 + r] * idx[c];
        }
        d.transform[12 + r] = (float)t;
    }
    d.transform[15] = 1.0f;
    d.type = HD_VOXEL_F32;
    d.data = data;
    out->data = data;
    out->value_min = h.lo;
    out->value_max = h.hi;
    d.value_range[0] = h.lo;
    d.value_range[1] = h.hi;
    if (!(d.value_range[1] > d.value_range[0])) d.value_range[1] = d.value_range[0] + std::max(1e-6f, std::fabs(d.value_range[0]) * 1e-6f);
    return 1;
}
