// hd_dicom.cpp - DICOM series for the example tools (see hd_dicom.h). The folder is listed here,
// each file is read once and its structure checked here (every length against its bounds), and
// only a file that passes is handed to GDCM, from memory, in a child process whose address space
// and CPU time are limited: GDCM asserts, aborts or allocates what a length claims on some damaged
// files, which would take the tool down with them.
#include "hd_dicom.h"
#include "hd_pipe.h"

#include <gdcmDict.h>
#include <gdcmDicts.h>
#include <gdcmGlobal.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>

#include <dirent.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <istream>
#include <map>
#include <new>
#include <set>
#include <streambuf>
#include <string>
#include <utility>
#include <vector>

namespace {

using hdx::now_s;
using hdx::write_all;

// ---- limits --------------------------------------------------------------------------------------
const size_t kMaxEntries = 100000;            // directory entries listed
const size_t kMaxFileBytes = size_t(256) << 20; // one slice's file
const int kMaxNesting = 16;                   // sequences within sequences
const double kMaxCoordinate = 1e9;            // |position|, |rescale| and spacing, mm or units

std::string fmt(const char *f, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
std::string fmt(const char *f, ...)
{
    char buf[512];
    va_list ap;
    va_start(ap, f);
    std::vsnprintf(buf, sizeof buf, f, ap);
    va_end(ap);
    return buf;
}

// A message on one line: control characters (a newline in a file name) become '?'.
std::string one_line(std::string s)
{
    for (char &ch : s)
        if ((unsigned char)ch < 32 || ch == 127) ch = '?';
    return s;
}

bool fail(char *err, size_t size, const std::string &msg)
{
    if (size) std::snprintf(err, size, "%s", one_line(msg).c_str());
    return false;
}

// One line on stderr for each file that is not read: "PROGRAM: DICOM: PATH: skipped: WHY".
void skipped(const std::string &path, const std::string &why)
{
    std::fprintf(stderr, "%s: DICOM: %s\n", program_invocation_short_name, one_line(path + ": skipped: " + why).c_str());
}

// Text from a file as a message shows it: at most max characters, '?' for what is not printable.
std::string printable(const std::string &s, size_t max = 64)
{
    std::string o;
    for (char ch : s.substr(0, max)) o += ch >= 32 && ch < 127 ? ch : '?';
    return o;
}

std::string tag_name(uint16_t g, uint16_t e) { return fmt("(%04X,%04X)", g, e); }

// ---- the folder ------------------------------------------------------------------------------------
struct candidate {
    std::string path; // as listed (the messages)
    std::string open; // what is opened: path, or the target of a link inside the folder
    size_t size;      // bytes when listed (the time it may take)
};

const char *kind_of(mode_t m)
{
    return S_ISDIR(m) ? "a folder" : S_ISFIFO(m) ? "a FIFO" : S_ISSOCK(m) ? "a socket"
           : S_ISCHR(m) || S_ISBLK(m) ? "a device" : "not a regular file";
}

// The regular files of dir, by name; links are followed only to regular files inside the folder,
// each file once. Everything else gets a line. False (err set) if dir cannot be listed.
bool list_folder(const std::string &dir, std::vector<candidate> &out, size_t &skips, char *err, size_t err_size)
{
    DIR *d = opendir(dir.c_str());
    if (!d) return fail(err, err_size, dir + ": cannot read the directory: " + std::strerror(errno));
    std::vector<std::string> names;
    errno = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL; errno = 0) {
        if (!std::strcmp(e->d_name, ".") || !std::strcmp(e->d_name, "..")) continue;
        if (names.size() == kMaxEntries) {
            closedir(d);
            return fail(err, err_size, dir + fmt(": more than %zu entries; a series folder has a few thousand", kMaxEntries));
        }
        names.push_back(e->d_name);
    }
    const int read_errno = errno;
    const int dfd = dirfd(d);
    if (read_errno) {
        closedir(d);
        return fail(err, err_size, dir + ": cannot read the directory: " + std::strerror(read_errno));
    }
    std::sort(names.begin(), names.end());
    char *root_c = realpath(dir.c_str(), NULL);
    const std::string root = root_c ? root_c : dir;
    std::free(root_c);
    const std::string prefix = dir.empty() || dir.back() == '/' ? dir : dir + "/";

    std::map<std::pair<dev_t, ino_t>, std::string> seen; // each file once
    std::vector<std::string> links;
    for (const std::string &n : names) { // the regular files first: a link to one of them is a duplicate
        struct stat st;
        const std::string path = prefix + n;
        if (fstatat(dfd, n.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) {
            skipped(path, std::string("cannot stat it: ") + std::strerror(errno)), ++skips;
        } else if (S_ISLNK(st.st_mode)) {
            links.push_back(n);
        } else if (!S_ISREG(st.st_mode)) {
            skipped(path, S_ISDIR(st.st_mode) ? "a folder (the files of subfolders are not read)"
                                              : std::string("not a regular file (") + kind_of(st.st_mode) + ")"),
                ++skips;
        } else {
            auto it = seen.emplace(std::make_pair(st.st_dev, st.st_ino), path);
            if (!it.second) skipped(path, "the same file as " + it.first->second), ++skips;
            else out.push_back({path, path, (size_t)std::min<unsigned long long>((unsigned long long)st.st_size, kMaxFileBytes)});
        }
    }
    for (const std::string &n : links) {
        const std::string path = prefix + n;
        char *target_c = realpath(path.c_str(), NULL);
        if (!target_c) {
            skipped(path, errno == ELOOP ? "a symbolic link loop"
                          : errno == ENOENT ? "a dangling symbolic link"
                                            : std::string("a symbolic link that cannot be resolved: ") + std::strerror(errno)),
                ++skips;
            continue;
        }
        const std::string target = target_c;
        std::free(target_c);
        struct stat st;
        if (stat(target.c_str(), &st) != 0) {
            skipped(path, "a symbolic link to " + target + ": " + std::strerror(errno)), ++skips;
        } else if (!S_ISREG(st.st_mode)) {
            skipped(path, std::string("a symbolic link to ") + kind_of(st.st_mode)), ++skips;
        } else if (target.compare(0, root.size() + 1, root + "/") != 0) {
            skipped(path, "a symbolic link out of the folder (not followed)"), ++skips;
        } else {
            auto it = seen.emplace(std::make_pair(st.st_dev, st.st_ino), path);
            if (!it.second) skipped(path, "the same file as " + it.first->second), ++skips;
            else out.push_back({path, target, (size_t)std::min<unsigned long long>((unsigned long long)st.st_size, kMaxFileBytes)});
        }
    }
    closedir(d);
    std::sort(out.begin(), out.end(), [](const candidate &a, const candidate &b) { return a.path < b.path; });
    return true;
}

// Reads a regular file whole (never blocks on a FIFO swapped in after the listing). "" or why not.
std::string read_file(const std::string &path, std::vector<unsigned char> &bytes)
{
    const int fd = open(path.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return std::string("cannot open it: ") + std::strerror(errno);
    struct stat st;
    if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        close(fd);
        return "not a regular file when opened";
    }
    if ((unsigned long long)st.st_size > kMaxFileBytes) {
        close(fd);
        return fmt("%lld bytes, over the %zu MiB a slice's file may have", (long long)st.st_size, kMaxFileBytes >> 20);
    }
    bytes.resize((size_t)st.st_size);
    size_t got = 0;
    while (got < bytes.size()) {
        const ssize_t n = read(fd, bytes.data() + got, bytes.size() - got);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const int e = errno;
            close(fd);
            return std::string("read error: ") + std::strerror(e);
        }
        if (n == 0) break; // cut short while read: what was read is checked
        got += (size_t)n;
    }
    close(fd);
    bytes.resize(got);
    return "";
}

// ---- the structure of one file -------------------------------------------------------------------------
// The value of an element that the reader checks or GDCM interprets.
struct value_ref {
    size_t offset = 0, length = 0;
    char vr[3] = {0, 0, 0}; // "" in implicit VR
    bool present = false;
};

struct file_check {
    std::string ts_uid;
    bool implicit = false, encapsulated = false;
    std::map<uint32_t, value_ref> values; // top level, by (group << 16 | element)
    // from the checked values
    unsigned rows = 0, cols = 0, bits = 0;
    std::string series;
};

const char *const kLongVRs[] = {"OB", "OD", "OF", "OL", "OV", "OW", "SQ", "UC", "UN", "UR", "UT", "SV", "UV"};
const char *const kShortVRs[] = {"AE", "AS", "AT", "CS", "DA", "DS", "DT", "FL", "FD", "IS", "LO",
                                 "LT", "PN", "SH", "SL", "SS", "ST", "TM", "UI", "UL", "US"};

bool vr_in(const char *vr, const char *const *list, size_t n)
{
    for (size_t i = 0; i < n; ++i)
        if (vr[0] == list[i][0] && vr[1] == list[i][1]) return true;
    return false;
}

// The tags kept at the top level: what the reader checks and what GDCM turns into the image.
bool wanted(uint32_t tag)
{
    static const std::set<uint32_t> tags = {
        0x00020010, 0x0020000e, 0x00200032, 0x00200037, 0x00280002, 0x00280004, 0x00280008, 0x00280010,
        0x00280011, 0x00280030, 0x00280034, 0x00280100, 0x00280101, 0x00280102, 0x00280103, 0x00281052,
        0x00281053, 0x00180050, 0x00180088, 0x00181164, 0x00182010, 0x7fe00008, 0x7fe00009, 0x7fe00010};
    return tags.count(tag) != 0;
}

// Bytes per value of a binary VR (0: text or bytes).
unsigned value_size(gdcm::VR::VRType t)
{
    switch (t) {
    case gdcm::VR::US: case gdcm::VR::SS: case gdcm::VR::OW: return 2;
    case gdcm::VR::UL: case gdcm::VR::SL: case gdcm::VR::FL: case gdcm::VR::AT: case gdcm::VR::OF: case gdcm::VR::OL: return 4;
    case gdcm::VR::FD: case gdcm::VR::OD: case gdcm::VR::SV: case gdcm::VR::UV: case gdcm::VR::OV: return 8;
    default: return 0;
    }
}

// "" if an element of a public tag has a VR that GDCM's dictionary allows for it and a length
// that is whole values of it; GDCM asserts on either when it turns the element into an attribute.
std::string check_vr(uint16_t g, uint16_t e, const char *file_vr, uint32_t length)
{
    if (g & 1 || g == 0xfffe) return ""; // private tags, items
    const gdcm::Dict &dict = gdcm::Global::GetInstance().GetDicts().GetPublicDict();
    const gdcm::VR known = dict.GetDictEntry(gdcm::Tag(g, e)).GetVR();
    const bool in_dict = known != gdcm::VR::INVALID && known != gdcm::VR::UN;
    gdcm::VR::VRType t = known;
    if (file_vr[0]) {
        t = gdcm::VR::GetVRTypeFromFile(file_vr);
        if (in_dict && t != gdcm::VR::UN && !known.Compatible(gdcm::VR(t)))
            return fmt("element %s has VR %s; the DICOM dictionary gives it %s", tag_name(g, e).c_str(), file_vr,
                       gdcm::VR::GetVRString(known));
        if (t == gdcm::VR::UN && in_dict && !known.IsDual()) t = known; // GDCM reads UN as the dictionary's VR
    } else if (!in_dict || known.IsDual()) {
        return "";
    }
    const unsigned size = value_size(t);
    if (size && length != 0xffffffffu && length % size)
        return fmt("element %s of VR %s has %u bytes, not whole %u-byte values", tag_name(g, e).c_str(),
                   gdcm::VR::GetVRString(t), length, size);
    return "";
}

// Walks the elements of a file, each length checked against the end of what holds it: the file,
// a sequence item or a sequence. Nothing is allocated from a length.
class walker {
public:
    walker(const std::vector<unsigned char> &b, file_check &c) : p_(b.data()), n_(b.size()), c_(c) {}
    std::string err;

    uint16_t u16(size_t o) const { return (uint16_t)(p_[o] | p_[o + 1] << 8); }
    uint32_t u32(size_t o) const { return (uint32_t)p_[o] | (uint32_t)p_[o + 1] << 8 | (uint32_t)p_[o + 2] << 16 | (uint32_t)p_[o + 3] << 24; }

    // The file meta information (group 0002, explicit VR) from byte 132; pos: where the data set starts.
    bool meta(size_t &pos)
    {
        pos = 132;
        size_t group_end = 0;
        uint32_t prev = 0;
        bool have_prev = false;
        while (pos + 4 <= n_ && u16(pos) == 0x0002) {
            element e;
            if (!header(pos, n_, true, e)) return false;
            if (e.undefined || (e.vr[0] == 'S' && e.vr[1] == 'Q'))
                return bad(fmt("meta element %s at byte %zu: a sequence or undefined length", tag_name(e.g, e.e).c_str(), pos));
            if (have_prev && e.tag() <= prev) return order(e, pos, prev);
#ifndef HDX_DICOM_TEST_NO_VR_CHECK
            const std::string vr_err = check_vr(e.g, e.e, e.vr, e.length);
            if (!vr_err.empty()) return bad(vr_err + fmt(" (at byte %zu)", pos));
#endif
            if (e.e == 0x0000) {
                if (e.length != 4) return bad(fmt("meta group length at byte %zu has %u bytes, not 4", pos, e.length));
                group_end = e.value + 4 + u32(e.value);
            }
            keep(e);
            prev = e.tag(), have_prev = true;
            pos = e.value + e.length;
        }
        if (group_end && group_end != pos)
            return bad(fmt("the meta group length says the group ends at byte %zu; its elements end at byte %zu", group_end, pos));
        const value_ref &ts = c_.values[0x00020010];
        if (!ts.present) return bad("no Transfer Syntax UID (0002,0010) in the meta information");
        c_.ts_uid = text(ts);
        const std::string &u = c_.ts_uid;
        if (u == "1.2.840.10008.1.2") c_.implicit = true;
        else if (u == "1.2.840.10008.1.2.1") {}
        else if (u == "1.2.840.10008.1.2.2") return bad("transfer syntax " + u + " (explicit VR big endian) is not read");
        else if (u == "1.2.840.10008.1.2.1.99") return bad("transfer syntax " + u + " (deflated) is not read");
        else if (u.compare(0, 20, "1.2.840.10008.1.2.4.") == 0 || u == "1.2.840.10008.1.2.5") c_.encapsulated = true;
        else return bad("transfer syntax '" + printable(u) + "' is not one the reader knows");
        return true;
    }

    // The elements of a data set from pos to end (or to its item delimiter, item_delimited).
    bool dataset(size_t &pos, size_t end, bool implicit, int depth, bool item_delimited)
    {
        uint32_t prev = 0;
        bool have_prev = false;
        while (pos < end) {
            element e;
            if (!header(pos, end, !implicit, e)) return false;
            const size_t at = pos;
            if (e.g == 0xfffe) {
                if (item_delimited && e.e == 0xe00d) {
                    if (e.length != 0) return bad(fmt("item delimiter at byte %zu claims %u bytes", at, e.length));
                    pos = e.value;
                    return true;
                }
                return bad(fmt("%s at byte %zu: an item or delimiter outside a sequence", tag_name(e.g, e.e).c_str(), at));
            }
            if (have_prev && e.tag() <= prev) return order(e, at, prev);
            prev = e.tag(), have_prev = true;
#ifdef HDX_DICOM_TEST_NO_VR_CHECK // tests/dicom: without it GDCM's asserts reach the worker
            (void)&check_vr;
#else
            const std::string vr_err = check_vr(e.g, e.e, e.vr, e.length);
            if (!vr_err.empty()) return bad(vr_err + fmt(" (at byte %zu)", at));
#endif
            const bool sq = !implicit && e.vr[0] == 'S' && e.vr[1] == 'Q';
            if (e.undefined) {
                if (e.tag() == 0x7fe00010 && c_.encapsulated && !implicit &&
                    (e.vr[1] == 'B' || e.vr[1] == 'W') && e.vr[0] == 'O') {
                    pos = e.value;
                    if (!fragments(pos, end)) return false;
                    if (depth == 0) keep(e, pos - e.value);
                    continue;
                }
                if (e.tag() == 0x7fe00010)
                    return bad(fmt("Pixel Data at byte %zu has an undefined length in transfer syntax %s", at, c_.ts_uid.c_str()));
                const bool un = !implicit && e.vr[0] == 'U' && e.vr[1] == 'N';
                if (!implicit && !sq && !un)
                    return bad(fmt("element %s at byte %zu: an undefined length on VR %s", tag_name(e.g, e.e).c_str(), at,
                                   printable(std::string(e.vr, 2)).c_str()));
                pos = e.value;
                if (!sequence(pos, end, true, implicit || un, depth + 1)) return false; // UN: implicit VR inside
                continue;
            }
            pos = e.value + e.length;
            const bool items = e.length >= 8 && u16(e.value) == 0xfffe && u16(e.value + 2) == 0xe000;
            if (sq || (implicit && items)) {
                size_t q = e.value;
                if (!sequence(q, e.value + e.length, false, implicit, depth + 1)) return false;
            }
            if (depth == 0 && c_.encapsulated && e.tag() == 0x7fe00010)
                return bad(fmt("Pixel Data at byte %zu has a defined length; transfer syntax %s needs it encapsulated", at,
                               c_.ts_uid.c_str()));
            if (depth == 0) keep(e);
        }
        if (item_delimited) return bad(fmt("a sequence item without its delimiter before byte %zu", end));
        return true;
    }

    std::string text(const value_ref &v) const
    {
        std::string s(reinterpret_cast<const char *>(p_) + v.offset, v.length);
        while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
        size_t i = 0;
        while (i < s.size() && s[i] == ' ') ++i;
        return s.substr(i);
    }

private:
    struct element {
        uint16_t g = 0, e = 0;
        char vr[3] = {0, 0, 0};
        uint32_t length = 0;
        size_t value = 0;
        bool undefined = false;
        uint32_t tag() const { return (uint32_t)g << 16 | e; }
    };

    const unsigned char *p_;
    size_t n_;
    file_check &c_;

    bool bad(const std::string &m)
    {
        err = m;
        return false;
    }
    bool order(const element &e, size_t at, uint32_t prev)
    {
        return bad(fmt("element %s at byte %zu comes after %s (out of order or repeated)", tag_name(e.g, e.e).c_str(), at,
                       tag_name((uint16_t)(prev >> 16), (uint16_t)prev).c_str()));
    }

    // One element's tag, VR and length at pos; its value must end by end.
    bool header(size_t pos, size_t end, bool explicit_vr, element &e)
    {
        if (end - pos < 8) return cut(pos, end);
        e.g = u16(pos), e.e = u16(pos + 2);
        size_t len_at = pos + 4;
        e.value = pos + 8;
        if (e.g != 0xfffe && explicit_vr) {
            e.vr[0] = (char)p_[pos + 4], e.vr[1] = (char)p_[pos + 5];
            if (vr_in(e.vr, kLongVRs, sizeof kLongVRs / sizeof *kLongVRs)) {
                if (end - pos < 12) return cut(pos, end);
                len_at = pos + 8, e.value = pos + 12;
                e.length = u32(len_at);
            } else if (vr_in(e.vr, kShortVRs, sizeof kShortVRs / sizeof *kShortVRs)) {
                e.length = u16(pos + 6);
            } else {
                return bad(fmt("element %s at byte %zu has VR '%s', none DICOM defines", tag_name(e.g, e.e).c_str(), pos,
                               printable(std::string(e.vr, 2)).c_str()));
            }
        } else {
            e.length = u32(len_at);
        }
        e.undefined = e.length == 0xffffffffu;
        if (!e.undefined && e.length > end - e.value && e.g == 0x7fe0 && e.e == 0x0010 && end == n_)
            return bad(fmt("its pixel data is cut short: Pixel Data (7FE0,0010) at byte %zu claims %u bytes, the file "
                           "has %zu after it (a truncated file?)", pos, e.length, end - e.value));
        if (!e.undefined && e.length > end - e.value)
            return bad(fmt("element %s at byte %zu claims %u bytes, past the end of %s (%zu bytes)", tag_name(e.g, e.e).c_str(),
                           pos, e.length, end == n_ ? "the file" : "what holds it", end == n_ ? n_ : end - e.value));
        return true;
    }
    bool cut(size_t pos, size_t end)
    {
        return bad(fmt("an element at byte %zu is cut short by the end of %s", pos, end == n_ ? "the file" : "what holds it"));
    }

    // A sequence's items from pos: to end (a defined length) or to its delimiter (undefined).
    bool sequence(size_t &pos, size_t end, bool undefined, bool implicit, int depth)
    {
        if (depth > kMaxNesting) return bad(fmt("sequences nested deeper than %d at byte %zu", kMaxNesting, pos));
        while (undefined || pos < end) {
            if (end - pos < 8) return cut(pos, end);
            const uint16_t g = u16(pos), el = u16(pos + 2);
            const uint32_t len = u32(pos + 4);
            if (undefined && g == 0xfffe && el == 0xe0dd) {
                if (len != 0) return bad(fmt("sequence delimiter at byte %zu claims %u bytes", pos, len));
                pos += 8;
                return true;
            }
            if (g != 0xfffe || el != 0xe000)
                return bad(fmt("%s at byte %zu where a sequence item should start", tag_name(g, el).c_str(), pos));
            size_t q = pos + 8;
            if (len == 0xffffffffu) {
                if (!dataset(q, end, implicit, depth, true)) return false;
            } else {
                if (len > end - q) return bad(fmt("sequence item at byte %zu claims %u bytes, past the end of what holds it", pos, len));
                if (!dataset(q, q + len, implicit, depth, false)) return false;
            }
            pos = q;
        }
        return true;
    }

    // Encapsulated Pixel Data: the offset table and the fragments, each an item of a defined length.
    bool fragments(size_t &pos, size_t end)
    {
        int items = 0;
        for (;;) {
            if (end - pos < 8) return cut(pos, end);
            const uint16_t g = u16(pos), el = u16(pos + 2);
            const uint32_t len = u32(pos + 4);
            if (g == 0xfffe && el == 0xe0dd) {
                if (len != 0) return bad(fmt("sequence delimiter at byte %zu claims %u bytes", pos, len));
                pos += 8;
                if (items < 2) return bad("encapsulated Pixel Data without a fragment");
                return true;
            }
            if (g != 0xfffe || el != 0xe000 || len == 0xffffffffu || len > end - pos - 8)
                return bad(fmt("encapsulated Pixel Data: %s of %u bytes at byte %zu is no fragment within the file",
                               tag_name(g, el).c_str(), len, pos));
            pos += 8 + len;
            ++items;
        }
    }

    void keep(const element &e, size_t length = (size_t)-1)
    {
        if (!wanted(e.tag())) return;
        value_ref &v = c_.values[e.tag()];
        v.offset = e.value;
        v.length = length == (size_t)-1 ? e.length : length;
        v.vr[0] = e.vr[0], v.vr[1] = e.vr[1];
        v.present = true;
    }
};

// A decimal string's numbers (DS, IS: "a\b\c"); false if one is not a finite number.
bool numbers(const std::string &s, std::vector<double> &out)
{
    out.clear();
    size_t i = 0;
    for (;;) {
        size_t j = s.find('\\', i);
        std::string v = s.substr(i, j == std::string::npos ? std::string::npos : j - i);
        while (!v.empty() && v.back() == ' ') v.pop_back();
        size_t k = 0;
        while (k < v.size() && v[k] == ' ') ++k;
        if (k < v.size() && v[k] == '+') ++k;
        double d = 0;
        const char *b = v.data() + k, *e = v.data() + v.size();
        if (b == e || (*b != '-' && *b != '.' && (*b < '0' || *b > '9'))) return false; // no "nan", "inf"
        auto r = std::from_chars(b, e, d);
        if (r.ec != std::errc() || r.ptr != e || !std::isfinite(d)) return false;
        out.push_back(d);
        if (j == std::string::npos) return true;
        i = j + 1;
    }
}

// The image attributes: present, of the right size, and sane. "" or why the file is not read.
std::string check_image(const walker &w, file_check &c)
{
    auto get = [&](uint32_t tag) -> const value_ref & { return c.values[tag]; };
    auto us = [&](uint32_t tag, const char *name, unsigned &v, bool required) -> std::string {
        const value_ref &r = get(tag);
        if (!r.present) return required ? std::string("no ") + name : std::string();
        if (r.length != 2 || (r.vr[0] && (r.vr[0] != 'U' || r.vr[1] != 'S')))
            return fmt("%s has %zu bytes of VR %s, not one US value", name, r.length,
                       r.vr[0] ? printable(std::string(r.vr, 2)).c_str() : "(implicit)");
        v = w.u16(r.offset);
        return "";
    };
    if (get(0x7fe00008).present || get(0x7fe00009).present) return "Float Pixel Data is not read";
    if (!get(0x7fe00010).present) return "not an image (no Pixel Data)";
    unsigned samples = 1, stored = 0, high = 0, rep = 0;
    bool have_stored = get(0x00280101).present, have_high = get(0x00280102).present;
    std::string m;
    if (!(m = us(0x00280010, "Rows", c.rows, true)).empty() || !(m = us(0x00280011, "Columns", c.cols, true)).empty() ||
        !(m = us(0x00280100, "Bits Allocated", c.bits, true)).empty() ||
        !(m = us(0x00280002, "Samples per Pixel", samples, false)).empty() ||
        !(m = us(0x00280101, "Bits Stored", stored, false)).empty() ||
        !(m = us(0x00280102, "High Bit", high, false)).empty() ||
        !(m = us(0x00280103, "Pixel Representation", rep, false)).empty())
        return m;
    if (samples != 1) return fmt("a colour image (Samples per Pixel %u); only greyscale series are read", samples);
    const std::string photometric = get(0x00280004).present ? w.text(get(0x00280004)) : "MONOCHROME2";
    if (photometric != "MONOCHROME1" && photometric != "MONOCHROME2")
        return "a colour image (Photometric Interpretation '" + printable(photometric) + "'); only greyscale series are read";
    if (get(0x00280008).present) {
        std::vector<double> f;
        const std::string s = w.text(get(0x00280008));
        if (!numbers(s, f) || f.size() != 1 || f[0] != std::floor(f[0]) || f[0] < 1)
            return "Number of Frames '" + printable(s) + "' is not a count";
        if (f[0] != 1) return fmt("a multi-frame image (%g frames); only single-frame series are read", f[0]);
    }
    if (c.rows < 1 || c.cols < 1 || c.rows > (unsigned)HD_MAX_DIM || c.cols > (unsigned)HD_MAX_DIM)
        return fmt("%ux%u pixels; each side must be 1..%d", c.cols, c.rows, HD_MAX_DIM);
    if (c.bits != 8 && c.bits != 16 && c.bits != 32) return fmt("Bits Allocated %u is not 8, 16 or 32", c.bits);
    if (have_stored && (stored < 1 || stored > c.bits)) return fmt("Bits Stored %u with Bits Allocated %u", stored, c.bits);
    if (have_high && high != (have_stored ? stored : c.bits) - 1)
        return fmt("High Bit %u with Bits Stored %u", high, have_stored ? stored : c.bits);
    if (rep > 1) return fmt("Pixel Representation %u is not 0 or 1", rep);
    const value_ref &pixels = get(0x7fe00010);
    if (!c.encapsulated) {
        const size_t need = (size_t)c.rows * c.cols * (c.bits / 8);
        if (pixels.length != need + (need & 1))
            return fmt("Pixel Data has %zu bytes; %ux%u pixels of %u bits need %zu", pixels.length, c.cols, c.rows, c.bits, need);
    }
    // the numbers GDCM turns into the geometry and the values: finite, in range
    static const struct {
        uint32_t tag;
        const char *name;
        size_t count;
        bool positive;
    } nums[] = {
        {0x00280030, "Pixel Spacing", 2, true},           {0x00200032, "Image Position (Patient)", 3, false},
        {0x00200037, "Image Orientation (Patient)", 6, false}, {0x00281052, "Rescale Intercept", 1, false},
        {0x00281053, "Rescale Slope", 1, false},          {0x00180050, "Slice Thickness", 1, false},
        {0x00180088, "Spacing Between Slices", 1, false}, {0x00181164, "Imager Pixel Spacing", 2, true},
        {0x00182010, "Nominal Scanned Pixel Spacing", 2, true}, {0x00280034, "Pixel Aspect Ratio", 2, true},
    };
    for (const auto &n : nums) {
        const value_ref &r = get(n.tag);
        if (!r.present || r.length == 0) continue;
        const std::string s = w.text(r);
        std::vector<double> v;
        bool ok = numbers(s, v) && v.size() == n.count;
        for (double d : v) ok = ok && std::fabs(d) <= kMaxCoordinate && (!n.positive || d > 0);
        if (!ok)
            return fmt("%s '%s' is not %s finite number%s %s", n.name, printable(s).c_str(),
                       n.count == 1 ? "a" : n.count == 2 ? "two" : n.count == 3 ? "three" : "six", n.count == 1 ? "" : "s",
                       n.positive ? "> 0" : "within +-1e9");
    }
    if (get(0x0020000e).present) c.series = w.text(get(0x0020000e));
    if (c.series.size() > 64) return "Series Instance UID '" + printable(c.series) + "...' is longer than 64 characters";
    return "";
}

// "" if the bytes are a file the reader can hand to GDCM, else why not.
std::string check_file(const std::vector<unsigned char> &b, file_check &c)
{
    if (b.size() < 132 || std::memcmp(b.data() + 128, "DICM", 4) != 0)
        return fmt("not DICOM (%zu bytes, no 'DICM' after a 128-byte preamble)", b.size());
    walker w(b, c);
    size_t pos;
    if (!w.meta(pos)) return w.err;
    if (!w.dataset(pos, b.size(), c.implicit, 0, false)) return w.err;
    return check_image(w, c);
}

// ---- the worker: checks and GDCM in a child process ----------------------------------------------
// One child reads, checks and parses the files one by one (a fork per file costs milliseconds in
// page tables and copy-on-write faults); before GDCM sees a file its address space and CPU time
// are limited to that file's budget. A worker that dies takes only its file with it: the next
// file goes to a new one.

// A read-only stream over bytes in memory (GDCM parses exactly what was checked, not the file again).
class memory_buf : public std::streambuf {
public:
    memory_buf(const unsigned char *p, size_t n)
    {
        char *b = const_cast<char *>(reinterpret_cast<const char *>(p));
        setg(b, b, b + n);
    }

protected:
    pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override
    {
        if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
        const off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? gptr() - eback() : egptr() - eback();
        const off_type to = base + off;
        if (to < 0 || to > egptr() - eback()) return pos_type(off_type(-1));
        setg(eback(), eback() + to, egptr());
        return pos_type(to);
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override
    {
        return seekoff(off_type(pos), std::ios_base::beg, which);
    }
};

// What the worker sends for each file, before the voxels of an image.
struct reply {
    uint32_t magic, index;
    int32_t ok; // 1: an image; cols * rows floats follow
    uint32_t cols, rows;
    double origin[3], cosines[6], spacing[2];
    char series[72];
    char message[400];
};
const uint32_t kMagic = 0x4d434448;

bool read_all(int fd, void *p, size_t n)
{
    char *c = (char *)p;
    while (n) {
        const ssize_t r = read(fd, c, n);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) return false;
        c += r, n -= (size_t)r;
    }
    return true;
}

// One file's budget: CPU seconds, wall seconds (the machine may be busy), address space beyond
// what the worker holds (GDCM keeps the file, the decoded pixels and the floats, plus its own).
unsigned cpu_budget_s(size_t file_bytes) { return 1 + (unsigned)(file_bytes >> 24); }
double wall_budget_s(size_t file_bytes) { return 4.0 * cpu_budget_s(file_bytes) + 2.0; }
unsigned long long memory_budget(size_t file_bytes, const file_check &c)
{
    return (64ull << 20) + 3ull * file_bytes + (unsigned long long)c.rows * c.cols * (c.bits / 8 + 8);
}

void set_soft_limit(int resource, rlim_t soft)
{
    struct rlimit l;
    if (getrlimit(resource, &l) != 0) return;
    l.rlim_cur = l.rlim_max == RLIM_INFINITY || soft < l.rlim_max ? soft : l.rlim_max;
    setrlimit(resource, &l);
}

void relax_soft_limit(int resource)
{
    struct rlimit l;
    if (getrlimit(resource, &l) != 0) return;
    l.rlim_cur = l.rlim_max;
    setrlimit(resource, &l);
}

unsigned long long address_space_bytes()
{
    unsigned long long pages = 0;
    if (std::FILE *f = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(f, "%llu", &pages) != 1) pages = 0;
        std::fclose(f);
    }
    return pages * (unsigned long long)sysconf(_SC_PAGESIZE);
}

double cpu_seconds()
{
    struct rusage u;
    getrusage(RUSAGE_SELF, &u);
    return (double)u.ru_utime.tv_sec + (double)u.ru_stime.tv_sec + 1e-6 * (double)(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// In the worker: GDCM reads the checked bytes into r's geometry and voxels (after the rescale).
// "" or why not.
std::string gdcm_parse(const std::vector<unsigned char> &bytes, const file_check &c, reply &r, std::vector<float> &voxels)
{
    try {
        memory_buf buf(bytes.data(), bytes.size());
        std::istream is(&buf);
        gdcm::ImageReader reader;
        reader.SetStream(is);
        if (!reader.Read()) return "GDCM cannot read it";
        const gdcm::Image &image = reader.GetImage();
        const gdcm::PixelFormat &pf = image.GetPixelFormat();
        const size_t count = (size_t)c.rows * c.cols;
        if ((image.GetNumberOfDimensions() != 2 && image.GetDimension(2) > 1) || image.GetDimension(0) != c.cols ||
            image.GetDimension(1) != c.rows || pf.GetSamplesPerPixel() != 1)
            return fmt("GDCM reads it as %ux%ux%u pixels of %u samples; the header says %ux%u of 1", image.GetDimension(0),
                       image.GetDimension(1), image.GetNumberOfDimensions() > 2 ? image.GetDimension(2) : 1,
                       pf.GetSamplesPerPixel(), c.cols, c.rows);
        if (image.GetBufferLength() != count * (c.bits / 8) || pf.GetBitsAllocated() != c.bits)
            return fmt("GDCM decodes it to %lu bytes of %u bits; %zu pixels of %u bits expected", image.GetBufferLength(),
                       pf.GetBitsAllocated(), count, c.bits);
        std::vector<char> raw(image.GetBufferLength());
        if (!image.GetBuffer(raw.data())) return "cannot decode its pixel data (transfer syntax " + c.ts_uid + ")";
        voxels.resize(count);
        const double slope = image.GetSlope(), intercept = image.GetIntercept();
        for (size_t i = 0; i < count; ++i) {
            double v;
            switch (pf.GetScalarType()) {
            case gdcm::PixelFormat::UINT8: v = (double)((const uint8_t *)raw.data())[i]; break;
            case gdcm::PixelFormat::INT8: v = (double)((const int8_t *)raw.data())[i]; break;
            case gdcm::PixelFormat::UINT16: v = (double)((const uint16_t *)raw.data())[i]; break;
            case gdcm::PixelFormat::INT16: v = (double)((const int16_t *)raw.data())[i]; break;
            case gdcm::PixelFormat::UINT32: v = (double)((const uint32_t *)raw.data())[i]; break;
            case gdcm::PixelFormat::INT32: v = (double)((const int32_t *)raw.data())[i]; break;
            default: return std::string("pixel type ") + pf.GetScalarTypeAsString() + " is not supported";
            }
            voxels[i] = (float)(v * slope + intercept);
        }
        for (int k = 0; k < 3; ++k) r.origin[k] = image.GetOrigin()[k];
        for (int k = 0; k < 6; ++k) r.cosines[k] = image.GetDirectionCosines()[k];
        r.spacing[0] = image.GetSpacing(0), r.spacing[1] = image.GetSpacing(1);
        return "";
    } catch (const std::bad_alloc &) {
        return "GDCM ran out of the memory a file of its size may take";
    } catch (const std::exception &e) {
        return fmt("GDCM failed on it (%.200s)", e.what());
    }
}

// In the worker: one file read, checked and, if it passes, parsed under its budget.
void work_one(const candidate &f, std::vector<unsigned char> &bytes, reply &r, std::vector<float> &voxels)
{
    std::string why = read_file(f.open, bytes);
    file_check c;
    if (why.empty()) why = check_file(bytes, c);
    if (why.empty()) {
        const unsigned long long now = address_space_bytes();
        if (now) set_soft_limit(RLIMIT_AS, (rlim_t)(now + memory_budget(bytes.size(), c)));
        set_soft_limit(RLIMIT_CPU, (rlim_t)std::ceil(cpu_seconds()) + cpu_budget_s(bytes.size()));
        why = gdcm_parse(bytes, c, r, voxels);
        relax_soft_limit(RLIMIT_AS);
        relax_soft_limit(RLIMIT_CPU);
    }
    if (!why.empty()) {
        std::snprintf(r.message, sizeof r.message, "%s", why.c_str());
        return;
    }
    r.ok = 1;
    r.cols = c.cols, r.rows = c.rows;
    std::snprintf(r.series, sizeof r.series, "%s", c.series.c_str());
}

[[noreturn]] void worker_main(const std::vector<candidate> &files, int requests, int replies)
{
    signal(SIGPIPE, SIG_DFL);
    struct rlimit none = {0, 0};
    setrlimit(RLIMIT_CORE, &none);  // an abort leaves no core file in the user's folder
    setrlimit(RLIMIT_FSIZE, &none); // nor writes one
    std::vector<unsigned char> bytes;
    std::vector<float> voxels;
    reply r;
    for (uint32_t i; read_all(requests, &i, sizeof i);) {
        if (i >= files.size()) _exit(3);
        std::memset(&r, 0, sizeof r);
        r.magic = kMagic, r.index = i;
        work_one(files[i], bytes, r, voxels);
        if (!write_all(replies, &r, sizeof r) || (r.ok && !write_all(replies, voxels.data(), voxels.size() * sizeof(float))))
            _exit(4);
    }
    _exit(0); // no destructors, no atexit handlers, no flush of the parent's stdio buffers
}

// The last line the worker wrote to stderr (GDCM's assertion or error) for a message: an
// assertion as FILE:LINE and its condition.
std::string last_line(const std::string &s)
{
    const size_t end = s.find_last_not_of("\r\n ");
    if (end == std::string::npos) return "";
    const size_t nl = s.find_last_of('\n', end), begin = nl == std::string::npos ? 0 : nl + 1;
    std::string line = s.substr(begin, end + 1 - begin);
    const size_t a = line.find("Assertion `");
    if (a != std::string::npos) {
        const size_t p = line.find(": ");                  // "PROGRAM: SOURCE:LINE: FUNCTION: Assertion ..."
        const size_t q = p == std::string::npos ? p : line.find(": ", p + 2);
        std::string where = q == std::string::npos ? "" : line.substr(p + 2, q - p - 2);
        if (where.find('/') != std::string::npos) where = where.substr(where.rfind('/') + 1);
        line = (where.empty() ? "" : where + ": ") + line.substr(a);
    }
    return printable(line, 200);
}

// The parent's end of the worker.
class worker {
public:
    explicit worker(const std::vector<candidate> &files) : files_(files) {}
    ~worker() { stop(); }

    // File i read by the worker: "" with r and, for an image, its voxels in plane; or why it was not.
    std::string ask(uint32_t i, reply &r, std::vector<float> &plane)
    {
        std::string why;
        if (pid_ < 0 && !start(why)) return why;
        errtext_.clear();
        const double wall_s = wall_budget_s(files_[i].size);
        if (!write_all(requests_, &i, sizeof i)) return died(false, i);
        size_t got = 0, want = sizeof r;
        const double deadline = now_s() + wall_s;
        while (got < want) {
            const double left = deadline - now_s();
            if (left <= 0) return died(true, i);
            struct pollfd fds[2] = {{replies_, POLLIN, 0}, {errors_, POLLIN, 0}};
            const int n = poll(fds, errors_ >= 0 ? 2 : 1, (int)(left * 1000) + 1);
            if (n < 0 && errno == EINTR) continue;
            if (n < 0) return died(false, i);
            if (errors_ >= 0 && (fds[1].revents & (POLLIN | POLLHUP | POLLERR))) drain_errors();
            if (!(fds[0].revents & (POLLIN | POLLHUP | POLLERR))) continue;
            char *to = got < sizeof r ? (char *)&r + got : (char *)plane.data() + (got - sizeof r);
            const ssize_t m = read(replies_, to, (got < sizeof r ? sizeof r : want) - got);
            if (m < 0 && errno == EINTR) continue;
            if (m <= 0) return died(false, i);
            got += (size_t)m;
            if (got == sizeof r && want == sizeof r) { // the header: is there an image?
                if (r.magic != kMagic || r.index != i) {
                    stop();
                    return "the reader's worker answered out of turn";
                }
                r.message[sizeof r.message - 1] = r.series[sizeof r.series - 1] = 0;
                if (!r.ok) break;
                if (r.cols < 1 || r.rows < 1 || r.cols > (unsigned)HD_MAX_DIM || r.rows > (unsigned)HD_MAX_DIM) {
                    stop();
                    return fmt("the reader's worker sent a %ux%u image", r.cols, r.rows);
                }
                try {
                    plane.resize((size_t)r.cols * r.rows);
                } catch (const std::bad_alloc &) {
                    stop();
                    return "out of memory for a slice";
                }
                want = sizeof r + plane.size() * sizeof(float);
            }
        }
        if (r.ok) return "";
        drain_errors();
        const std::string said = last_line(errtext_);
        return std::strncmp(r.message, "GDCM cannot", 11) == 0 && !said.empty() ? std::string(r.message) + " (" + said + ")"
                                                                               : std::string(r.message);
    }

private:
    const std::vector<candidate> &files_;
    pid_t pid_ = -1;
    int requests_ = -1, replies_ = -1, errors_ = -1;
    std::string errtext_;

    bool start(std::string &why)
    {
        int req[2], rep[2], err[2];
        if (pipe(req) != 0) return why = std::string("cannot make a pipe: ") + std::strerror(errno), false;
        if (pipe(rep) != 0) {
            close(req[0]), close(req[1]);
            return why = std::string("cannot make a pipe: ") + std::strerror(errno), false;
        }
        if (pipe(err) != 0) {
            close(req[0]), close(req[1]), close(rep[0]), close(rep[1]);
            return why = std::string("cannot make a pipe: ") + std::strerror(errno), false;
        }
        std::fflush(NULL);
        const pid_t pid = fork();
        if (pid < 0) {
            for (int fd : {req[0], req[1], rep[0], rep[1], err[0], err[1]}) close(fd);
            return why = std::string("cannot start the reader's worker: ") + std::strerror(errno), false;
        }
        if (pid == 0) {
            close(req[1]), close(rep[0]), close(err[0]);
            dup2(err[1], 1), dup2(err[1], 2);
            close(err[1]);
            worker_main(files_, req[0], rep[1]);
        }
        close(req[0]), close(rep[1]), close(err[1]);
        pid_ = pid, requests_ = req[1], replies_ = rep[0], errors_ = err[0];
        return true;
    }

    void drain_errors()
    {
        char buf[4096];
        struct pollfd p = {errors_, POLLIN, 0};
        while (errors_ >= 0 && poll(&p, 1, 0) > 0) {
            const ssize_t m = read(errors_, buf, sizeof buf);
            if (m < 0 && errno == EINTR) continue;
            if (m <= 0) {
                close(errors_);
                errors_ = -1;
                break;
            }
            errtext_.append(buf, (size_t)m);
            if (errtext_.size() > 8192) errtext_.erase(0, errtext_.size() - 4096);
        }
    }

    // Ends the worker; returns its exit status (-1 if there was none).
    int stop(bool kill_it = true)
    {
        if (pid_ < 0) return -1;
        if (kill_it) kill(pid_, SIGKILL);
        if (requests_ >= 0) close(requests_);
        if (replies_ >= 0) close(replies_);
        int st = 0;
        while (waitpid(pid_, &st, 0) < 0 && errno == EINTR) {}
        drain_errors();
        if (errors_ >= 0) close(errors_);
        pid_ = -1, requests_ = replies_ = errors_ = -1;
        return st;
    }

    // Why file i was not read when the worker stopped answering: killed at the deadline, over its
    // CPU time, aborted, crashed.
    std::string died(bool timed_out, uint32_t i)
    {
        if (timed_out) kill(pid_, SIGKILL);
        const int st = stop(false);
        const std::string said = last_line(errtext_);
        const std::string tail = said.empty() ? "" : ": " + said;
        if (timed_out) return fmt("reading it took over %.0f s (stopped)", wall_budget_s(files_[i].size));
        if (WIFSIGNALED(st)) {
            const int sig = WTERMSIG(st);
            if (sig == SIGXCPU || sig == SIGKILL)
                return fmt("reading it took over %u s of CPU time (stopped)", cpu_budget_s(files_[i].size));
            return fmt("GDCM %s on it (signal %d%s)", sig == SIGABRT ? "aborted" : "crashed", sig, tail.c_str());
        }
        return fmt("the reader's worker stopped on it (exit status %d%s)", WIFEXITED(st) ? WEXITSTATUS(st) : -1, tail.c_str());
    }
};

// GDCM's geometry of a slice: finite, unit direction cosines at right angles, spacing > 0.
std::string check_geometry(const reply &r)
{
    for (double v : r.origin)
        if (!std::isfinite(v) || std::fabs(v) > kMaxCoordinate) return "its origin is not finite";
    for (double v : r.cosines)
        if (!std::isfinite(v)) return "its direction cosines are not finite";
    const double *a = r.cosines, *b = r.cosines + 3;
    const double na = a[0] * a[0] + a[1] * a[1] + a[2] * a[2], nb = b[0] * b[0] + b[1] * b[1] + b[2] * b[2];
    const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    if (std::fabs(na - 1) > 1e-3 || std::fabs(nb - 1) > 1e-3 || std::fabs(dot) > 1e-3)
        return fmt("Image Orientation %g,%g,%g,%g,%g,%g is not two perpendicular unit vectors", a[0], a[1], a[2], b[0], b[1], b[2]);
    for (double v : r.spacing)
        if (!(v > 0) || v > kMaxCoordinate) return fmt("its pixel spacing %g,%g is not > 0", r.spacing[0], r.spacing[1]);
    return "";
}

// SIGPIPE ignored while it lives: a request to a worker that has just died is an error to
// handle, not the end of the program.
struct sigpipe_ignored {
    struct sigaction old;
    sigpipe_ignored()
    {
        struct sigaction ign;
        std::memset(&ign, 0, sizeof ign);
        ign.sa_handler = SIG_IGN;
        sigemptyset(&ign.sa_mask);
        sigaction(SIGPIPE, &ign, &old);
    }
    ~sigpipe_ignored() { sigaction(SIGPIPE, &old, NULL); }
};

struct slice {
    std::string path;
    double position; // along the slice normal, mm
    size_t plane;    // its plane in the volume as read
};

} // namespace

extern "C" int hdx_is_directory(const char *path)
{
    struct stat st;
    return path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

extern "C" int hdx_dicom_load_series(const char *dir_c, hd_volume_file *out, char *err, size_t err_size)
{
    std::memset(out, 0, sizeof *out);
    if (err_size) err[0] = 0;
    // GDCM's messages go to the worker's captured stderr; its warnings are not wanted at all
    gdcm::Trace::WarningOff();
    const std::string dir = dir_c;
    std::vector<candidate> files;
    size_t skips = 0;
    if (!list_folder(dir, files, skips, err, err_size)) return 0;

    std::vector<slice> slices;
    std::string series, first;
    unsigned rows = 0, cols = 0;
    double cosines[6] = {0, 0, 0, 0, 0, 0}, normal[3] = {0, 0, 0}, pixel_spacing[2] = {1, 1};
    float *data = NULL;
    size_t plane = 0;
    auto fail_free = [&](const std::string &m) {
        std::free(data);
        return fail(err, err_size, m);
    };
    sigpipe_ignored no_sigpipe;
    worker w(files);
    std::vector<float> voxels;
    for (uint32_t i = 0; i < (uint32_t)files.size(); ++i) {
        const candidate &f = files[i];
        reply r;
        std::string why = w.ask(i, r, voxels);
        if (why.empty() && !slices.empty() && (r.cols != cols || r.rows != rows))
            return fail_free(dir + ": slices of different sizes (" + first + " " + std::to_string(cols) + "x" +
                             std::to_string(rows) + ", " + f.path + " " + std::to_string(r.cols) + "x" + std::to_string(r.rows) + ")");
        if (why.empty()) why = check_geometry(r);
        for (size_t k = 0; why.empty() && k < voxels.size(); ++k)
            if (!std::isfinite(voxels[k])) why = "a voxel is not finite after the rescale";
        if (!why.empty()) {
            skipped(f.path, why), ++skips;
            continue;
        }
        if (slices.size() == (size_t)HD_MAX_DIM)
            return fail_free(dir + fmt(": more than %d slices, the library's limit per axis", HD_MAX_DIM));
        const double *dc = r.cosines;
        if (slices.empty()) {
            first = f.path;
            series = r.series;
            cols = r.cols;
            rows = r.rows;
            plane = (size_t)rows * cols;
            for (int k = 0; k < 6; ++k) cosines[k] = dc[k];
            normal[0] = dc[1] * dc[5] - dc[2] * dc[4];
            normal[1] = dc[2] * dc[3] - dc[0] * dc[5];
            normal[2] = dc[0] * dc[4] - dc[1] * dc[3];
            pixel_spacing[0] = r.spacing[0];
            pixel_spacing[1] = r.spacing[1];
        } else {
            if (r.series != series)
                return fail_free(dir + ": more than one series (" + first + " is in " + printable(series) + ", " + f.path +
                                 " in " + printable(r.series) + "); give a folder of one series");
            for (int k = 0; k < 6; ++k)
                if (std::fabs(dc[k] - cosines[k]) > 1e-3)
                    return fail_free(dir + ": slices of different orientations (" + first + ", " + f.path + ")");
        }
        float *grown = (float *)std::realloc(data, (slices.size() + 1) * plane * sizeof(float));
        if (!grown) return fail_free(dir + ": out of memory for the volume");
        data = grown;
        std::memcpy(data + slices.size() * plane, voxels.data(), plane * sizeof(float));
        const double *o = r.origin;
        slices.push_back({f.path, o[0] * normal[0] + o[1] * normal[1] + o[2] * normal[2], slices.size()});
    }
    voxels = std::vector<float>();
    if (slices.empty())
        return fail_free(dir + (skips ? fmt(": no DICOM images it can read (%zu entr%s skipped, each named above)", skips,
                                            skips == 1 ? "y" : "ies")
                                      : std::string(": no DICOM images it can read (the folder is empty)")));
    std::stable_sort(slices.begin(), slices.end(), [](const slice &a, const slice &b) { return a.position < b.position; });

    // slice spacing: the smallest step; a larger one means slices are missing
    double step = 1.0;
    if (slices.size() > 1) {
        step = slices[1].position - slices[0].position;
        for (size_t i = 1; i < slices.size(); ++i) {
            double s = slices[i].position - slices[i - 1].position;
            if (s < 1e-4)
                return fail_free(dir + ": two slices at one position (" + slices[i - 1].path + ", " + slices[i].path + ")");
            step = std::min(step, s);
        }
        for (size_t i = 1; i < slices.size(); ++i) {
            double s = slices[i].position - slices[i - 1].position;
            if (s > 1.5 * step)
                return fail_free(dir + ": missing slices between " + slices[i - 1].path + " and " + slices[i].path +
                                 fmt(" (a gap of %.4g mm, %.4g mm elsewhere)", s, step));
        }
    }
    // the planes into position order, in place: each cycle of the permutation through one spare plane
    std::vector<float> spare(plane);
    std::vector<char> done(slices.size(), 0);
    for (size_t z = 0; z < slices.size(); ++z) {
        if (done[z] || slices[z].plane == z) continue;
        std::memcpy(spare.data(), data + z * plane, plane * sizeof(float));
        size_t to = z;
        while (slices[to].plane != z) {
            const size_t from = slices[to].plane;
            std::memcpy(data + to * plane, data + from * plane, plane * sizeof(float));
            done[to] = 1;
            to = from;
        }
        std::memcpy(data + to * plane, spare.data(), plane * sizeof(float));
        done[to] = 1;
    }
    const size_t total = plane * slices.size();
    float lo = data[0], hi = data[0];
    for (size_t i = 0; i < total; ++i) {
        lo = std::min(lo, data[i]);
        hi = std::max(hi, data[i]);
    }
    out->desc.type = HD_VOXEL_F32;
    // Hounsfield units (integers within int16 after the rescale, as CTs are) are kept as I16:
    // half the bytes, and the library keeps them so on the device
    bool integral = lo >= -32768.0f && hi <= 32767.0f;
    for (size_t i = 0; integral && i < total; ++i) integral = data[i] == std::floor(data[i]);
    if (integral) {
        unsigned char *b = (unsigned char *)data; // in place: voxel i's 2 bytes go where floats <= i were read
        for (size_t i = 0; i < total; ++i) {
            float f;
            std::memcpy(&f, b + 4 * i, sizeof f);
            const int16_t v = (int16_t)f;
            std::memcpy(b + 2 * i, &v, sizeof v);
        }
        if (int16_t *shrunk = (int16_t *)std::realloc(data, total * sizeof(int16_t))) data = (float *)shrunk;
        out->desc.type = HD_VOXEL_I16;
    }
    out->desc.dims[0] = (int)cols;
    out->desc.dims[1] = (int)rows;
    out->desc.dims[2] = (int)slices.size();
    out->desc.spacing[0] = (float)pixel_spacing[0];
    out->desc.spacing[1] = (float)pixel_spacing[1];
    out->desc.spacing[2] = (float)step;
    out->desc.data = data;
    out->data = data;
    out->value_min = lo;
    out->value_max = hi;
    return 1;
}
