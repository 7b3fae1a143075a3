// gdcm_probe - how GDCM itself fares on files, with and without the DICOM reader's checks
// (examples/hd_dicom.cpp, included here for its checks): each file is read by gdcm::ImageReader
// and decoded in a child of its own, without the reader's limits (only caps of 1 GiB of address
// space and 60 s of CPU time, so that the machine survives), and the outcome is counted: read,
// refused cleanly, aborted or crashed, over 5 s, over 256 MiB. `make dicom-hostile-long` runs
// it on the long corpus; the figures say whether GDCM still needs the worker once a file passes
// the checks.
//
//   gdcm_probe [--passing] FILE...   one line per file that misbehaves, then the counts;
//                                    --passing: only the files that pass the checks
#include "../../examples/hd_dicom.cpp"

#include <sys/resource.h>
#include <sys/time.h>

namespace {

struct outcome {
    int status;      // wait status
    double seconds;  // wall
    long max_rss_kb; // the child's peak
};

outcome probe(const std::vector<unsigned char> &bytes)
{
    std::fflush(NULL);
    const double t0 = now_s();
    const pid_t pid = fork();
    if (pid == 0) {
        const int devnull = open("/dev/null", O_WRONLY);
        dup2(devnull, 1), dup2(devnull, 2);
        struct rlimit l;
        l.rlim_cur = l.rlim_max = 1ull << 30;
        setrlimit(RLIMIT_AS, &l);
        l.rlim_cur = l.rlim_max = 60;
        setrlimit(RLIMIT_CPU, &l);
        l.rlim_cur = l.rlim_max = 0;
        setrlimit(RLIMIT_CORE, &l);
        memory_buf buf(bytes.data(), bytes.size());
        std::istream is(&buf);
        gdcm::ImageReader reader;
        reader.SetStream(is);
        int read = reader.Read();
        if (read) {
            const gdcm::Image &image = reader.GetImage();
            std::vector<char> raw(image.GetBufferLength());
            read = image.GetBuffer(raw.data());
        }
        _exit(read ? 0 : 1);
    }
    outcome o = {0, 0, 0};
    struct rusage ru;
    while (wait4(pid, &o.status, 0, &ru) < 0 && errno == EINTR) {}
    o.seconds = now_s() - t0;
    o.max_rss_kb = ru.ru_maxrss;
    return o;
}

} // namespace

int main(int argc, char **argv)
{
    gdcm::Trace::WarningOff();
    gdcm::Trace::ErrorOff();
    struct counts {
        int files = 0, read = 0, refused = 0, died = 0, slow = 0, big = 0;
    } all, passing;
    const bool only_passing = argc > 1 && std::strcmp(argv[1], "--passing") == 0;
    for (int i = 1 + only_passing; i < argc; ++i) {
        std::vector<unsigned char> bytes;
        if (!read_file(argv[i], bytes).empty()) continue;
        file_check c;
        const bool passes = check_file(bytes, c).empty();
        if (only_passing && !passes) continue;
        const outcome o = probe(bytes);
        for (counts *k : {&all, passes ? &passing : (counts *)NULL}) {
            if (!k) continue;
            ++k->files;
            if (WIFSIGNALED(o.status)) ++k->died;
            else if (WEXITSTATUS(o.status) == 0) ++k->read;
            else ++k->refused;
            k->slow += o.seconds > 5.0;
            k->big += o.max_rss_kb > 256 * 1024;
        }
        if (WIFSIGNALED(o.status) || o.seconds > 5.0 || o.max_rss_kb > 256 * 1024)
            std::printf("%s: %s%s, %.2f s, %ld KiB peak%s\n", argv[i], WIFSIGNALED(o.status) ? "signal " : "exit ",
                        std::to_string(WIFSIGNALED(o.status) ? WTERMSIG(o.status) : WEXITSTATUS(o.status)).c_str(), o.seconds,
                        o.max_rss_kb, passes ? " (passes the reader's checks)" : "");
    }
    for (const counts *k : {&all, &passing})
        std::printf("gdcm_probe: %s: %d files: GDCM read %d, refused %d cleanly, aborted or crashed on %d; %d over 5 s, "
                    "%d over 256 MiB\n",
                    k == &all ? "every file" : "files passing the checks", k->files, k->read, k->refused, k->died, k->slow,
                    k->big);
    return 0;
}
