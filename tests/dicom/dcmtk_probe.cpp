// dcmtk_probe - how DCMTK fares on the files gdcm_probe measures GDCM on (the alternative reader
// for the tools' DICOM input): each file is loaded by DcmFileFormat::loadFile and its image made
// by DicomImage (the JPEG, JPEG-LS and RLE decoders registered), in a child of its own with the
// same caps (1 GiB of address space, 60 s of CPU time), and the outcome is counted: read,
// refused cleanly, aborted or crashed, over 5 s, over 256 MiB. A measurement only: the tools do
// not link DCMTK. `make dicom-dcmtk-probe` (needs Debian's libdcmtk-dev) runs it on the long
// corpus of `make dicom-hostile-long`.
//
//   dcmtk_probe FILE...    one line per file that misbehaves, then the counts
#include <dcmtk/config/osconfig.h>
#include <dcmtk/dcmdata/dcfilefo.h>
#include <dcmtk/dcmdata/dcrledrg.h>
#include <dcmtk/dcmimgle/dcmimage.h>
#include <dcmtk/dcmjpeg/djdecode.h>
#include <dcmtk/dcmjpls/djdecode.h>
#include <dcmtk/oflog/oflog.h>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <string>

int main(int argc, char **argv)
{
    OFLog::configure(OFLogger::FATAL_LOG_LEVEL);
    DJDecoderRegistration::registerCodecs();
    DJLSDecoderRegistration::registerCodecs();
    DcmRLEDecoderRegistration::registerCodecs();
    int files = 0, read = 0, refused = 0, died = 0, slow = 0, big = 0;
    for (int i = 1; i < argc; ++i) {
        std::fflush(NULL);
        struct timespec t0, t1;
        clock_gettime(CLOCK_MONOTONIC, &t0);
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
            DcmFileFormat file;
            if (file.loadFile(argv[i]).bad()) _exit(1);
            DicomImage image(&file, file.getDataset()->getOriginalXfer());
            if (image.getStatus() != EIS_Normal || !image.getOutputData(16)) _exit(1);
            _exit(0);
        }
        int st = 0;
        struct rusage ru;
        while (wait4(pid, &st, 0, &ru) < 0 && errno == EINTR) {}
        clock_gettime(CLOCK_MONOTONIC, &t1);
        const double s = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
        ++files;
        if (WIFSIGNALED(st)) ++died;
        else if (WEXITSTATUS(st) == 0) ++read;
        else ++refused;
        slow += s > 5.0;
        big += ru.ru_maxrss > 256 * 1024;
        if (WIFSIGNALED(st) || s > 5.0 || ru.ru_maxrss > 256 * 1024)
            std::printf("%s: %s %d, %.2f s, %ld KiB peak\n", argv[i], WIFSIGNALED(st) ? "signal" : "exit",
                        WIFSIGNALED(st) ? WTERMSIG(st) : WEXITSTATUS(st), s, ru.ru_maxrss);
    }
    std::printf("dcmtk_probe: %d files: DCMTK read %d, refused %d cleanly, aborted or crashed on %d; %d over 5 s, "
                "%d over 256 MiB\n", files, read, refused, died, slow, big);
    return 0;
}
