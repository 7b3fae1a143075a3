// hd_dicom.cpp - DICOM series for the example tools through GDCM (see hd_dicom.h).
#include "hd_dicom.h"

#include <gdcmDirectory.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmReader.h>
#include <gdcmStringFilter.h>
#include <gdcmTag.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

namespace {

struct slice {
    std::string path;
    double position; // along the slice normal, mm
};

// The value of a tag as text, trimmed ("" when absent).
std::string tag_text(const gdcm::File &file, const gdcm::Tag &tag)
{
    gdcm::StringFilter sf;
    sf.SetFile(file);
    if (!file.GetDataSet().FindDataElement(tag)) return std::string();
    std::string s = sf.ToString(tag);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\0')) s.pop_back();
    return s;
}

bool fail(char *err, size_t size, const std::string &msg)
{
    if (size) std::snprintf(err, size, "%s", msg.c_str());
    return false;
}

std::string fmt(const char *f, double a, double b = 0.0, double c = 0.0)
{
    char buf[256];
    std::snprintf(buf, sizeof buf, f, a, b, c);
    return buf;
}

// Reads one slice's voxels into dst (rows * cols floats) after the rescale.
bool read_pixels(const std::string &path, const gdcm::Image &image, float *dst, size_t count, char *err,
                 size_t err_size)
{
    std::vector<char> buf(image.GetBufferLength());
    if (!image.GetBuffer(buf.data()))
        return fail(err, err_size, path + ": cannot decode its pixel data (transfer syntax " +
                                       gdcm::TransferSyntax::GetTSString(image.GetTransferSyntax()) + ")");
    const gdcm::PixelFormat &pf = image.GetPixelFormat();
    const double slope = image.GetSlope(), intercept = image.GetIntercept();
    for (size_t i = 0; i < count; ++i) {
        double v;
        switch (pf.GetScalarType()) {
        case gdcm::PixelFormat::UINT8: v = (double)((const uint8_t *)buf.data())[i]; break;
        case gdcm::PixelFormat::INT8: v = (double)((const int8_t *)buf.data())[i]; break;
        case gdcm::PixelFormat::UINT16: v = (double)((const uint16_t *)buf.data())[i]; break;
        case gdcm::PixelFormat::INT16: v = (double)((const int16_t *)buf.data())[i]; break;
        case gdcm::PixelFormat::UINT32: v = (double)((const uint32_t *)buf.data())[i]; break;
        case gdcm::PixelFormat::INT32: v = (double)((const int32_t *)buf.data())[i]; break;
        case gdcm::PixelFormat::FLOAT32: v = (double)((const float *)buf.data())[i]; break;
        case gdcm::PixelFormat::FLOAT64: v = ((const double *)buf.data())[i]; break;
        default:
            return fail(err, err_size, path + ": pixel type " + pf.GetScalarTypeAsString() + " is not supported");
        }
        dst[i] = (float)(v * slope + intercept);
    }
    return true;
}

} // namespace

extern "C" int hdx_is_directory(const char *path)
{
    struct stat st;
    return path && stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

extern "C" int hdx_dicom_load_series(const char *dir, hd_volume_file *out, char *err, size_t err_size)
{
    std::memset(out, 0, sizeof *out);
    // GDCM's own warnings go to stderr; a failure here is reported as one line in err instead
    gdcm::Trace::WarningOff();
    gdcm::Directory d;
    if (access(dir, R_OK | X_OK) != 0)
        return fail(err, err_size, std::string(dir) + ": cannot read the directory: " + std::strerror(errno));
    d.Load(dir, false); // 0 files is "no DICOM images" below
    std::vector<std::string> files = d.GetFilenames();
    std::sort(files.begin(), files.end());

    std::vector<slice> slices;
    std::string series, first;
    unsigned rows = 0, cols = 0;
    double cosines[6] = {0, 0, 0, 0, 0, 0}, normal[3] = {0, 0, 0}, pixel_spacing[2] = {1, 1};
    for (const std::string &path : files) {
        gdcm::Reader header;
        header.SetFileName(path.c_str());
        if (!header.Read()) {
            // not DICOM (a README, a thumbnail) unless it has the DICOM preamble: then it is damaged
            char magic[4] = {0, 0, 0, 0};
            std::FILE *f = std::fopen(path.c_str(), "rb");
            bool dicm = f && std::fseek(f, 128, SEEK_SET) == 0 && std::fread(magic, 1, 4, f) == 4 &&
                        std::memcmp(magic, "DICM", 4) == 0;
            if (f) std::fclose(f);
            if (dicm) return fail(err, err_size, path + ": a DICOM file GDCM cannot parse (truncated or damaged)");
            continue;
        }
        const gdcm::File &file = header.GetFile();
        if (!file.GetDataSet().FindDataElement(gdcm::Tag(0x7fe0, 0x0010))) {
            if (file.GetDataSet().FindDataElement(gdcm::Tag(0x0028, 0x0010))) // Rows: an image's header
                return fail(err, err_size, path + ": an image without its pixel data (truncated?)");
            continue; // no image (a DICOMDIR, a report)
        }
        const gdcm::TransferSyntax ts = file.GetHeader().GetDataSetTransferSyntax();
        if (!ts.IsEncapsulated()) {
            // GDCM reads a file cut short in its pixel data with a warning only: the value, which
            // starts where a read that skips it stops, must end inside the file
            gdcm::Reader upto;
            upto.SetFileName(path.c_str());
            struct stat st;
            const size_t vl = file.GetDataSet().GetDataElement(gdcm::Tag(0x7fe0, 0x0010)).GetVL();
            const std::set<gdcm::Tag> skip = {gdcm::Tag(0x7fe0, 0x0010)};
            if (upto.ReadUpToTag(gdcm::Tag(0x7fe0, 0x0010), skip) && stat(path.c_str(), &st) == 0 &&
                (size_t)st.st_size < upto.GetStreamCurrentPosition() + vl)
                return fail(err, err_size, path + ": its pixel data is cut short (a truncated file)");
        }
        gdcm::ImageReader reader;
        reader.SetFileName(path.c_str());
        if (!reader.Read())
            return fail(err, err_size, path + ": GDCM cannot read the image (transfer syntax " +
                                           (ts.IsValid() ? ts.GetString() : tag_text(file, gdcm::Tag(0x0002, 0x0010))) + ")");
        const gdcm::Image &image = reader.GetImage();
        const std::string uid = tag_text(file, gdcm::Tag(0x0020, 0x000e));
        if (image.GetNumberOfDimensions() != 2 && image.GetDimension(2) > 1)
            return fail(err, err_size, path + ": a multi-frame image; only single-frame series are read");
        if (image.GetPixelFormat().GetSamplesPerPixel() != 1)
            return fail(err, err_size, path + ": a colour image; only greyscale series are read");
        if (slices.empty()) {
            first = path;
            series = uid;
            cols = image.GetDimension(0);
            rows = image.GetDimension(1);
            const double *dc = image.GetDirectionCosines();
            for (int k = 0; k < 6; ++k) cosines[k] = dc[k];
            normal[0] = dc[1] * dc[5] - dc[2] * dc[4];
            normal[1] = dc[2] * dc[3] - dc[0] * dc[5];
            normal[2] = dc[0] * dc[4] - dc[1] * dc[3];
            pixel_spacing[0] = image.GetSpacing(0);
            pixel_spacing[1] = image.GetSpacing(1);
        } else {
            if (uid != series)
                return fail(err, err_size, std::string(dir) + ": more than one series (" + first + " is in " +
                                               series + ", " + path + " in " + uid + "); give a folder of one series");
            if (image.GetDimension(0) != cols || image.GetDimension(1) != rows)
                return fail(err, err_size, std::string(dir) + ": slices of different sizes (" + first + " " +
                                               std::to_string(cols) + "x" + std::to_string(rows) + ", " + path + " " +
                                               std::to_string(image.GetDimension(0)) + "x" +
                                               std::to_string(image.GetDimension(1)) + ")");
            const double *dc = image.GetDirectionCosines();
            for (int k = 0; k < 6; ++k)
                if (std::fabs(dc[k] - cosines[k]) > 1e-3)
                    return fail(err, err_size, std::string(dir) + ": slices of different orientations (" + first +
                                                   ", " + path + ")");
        }
        const double *o = image.GetOrigin();
        slices.push_back({path, o[0] * normal[0] + o[1] * normal[1] + o[2] * normal[2]});
    }
    if (slices.empty()) return fail(err, err_size, std::string(dir) + ": no DICOM images in the directory");
    std::sort(slices.begin(), slices.end(), [](const slice &a, const slice &b) { return a.position < b.position; });

    // slice spacing: the smallest step; a larger one means slices are missing
    double step = 1.0;
    if (slices.size() > 1) {
        step = slices[1].position - slices[0].position;
        for (size_t i = 1; i < slices.size(); ++i) {
            double s = slices[i].position - slices[i - 1].position;
            if (s < 1e-4)
                return fail(err, err_size, std::string(dir) + ": two slices at one position (" + slices[i - 1].path +
                                               ", " + slices[i].path + ")");
            step = std::min(step, s);
        }
        for (size_t i = 1; i < slices.size(); ++i) {
            double s = slices[i].position - slices[i - 1].position;
            if (s > 1.5 * step)
                return fail(err, err_size, std::string(dir) + ": missing slices between " + slices[i - 1].path +
                                               " and " + slices[i].path +
                                               fmt(" (a gap of %.4g mm, %.4g mm elsewhere)", s, step));
        }
    }
    if (slices.size() > (size_t)HD_MAX_DIM || rows > (unsigned)HD_MAX_DIM || cols > (unsigned)HD_MAX_DIM)
        return fail(err, err_size, std::string(dir) + fmt(": %gx%gx%g voxels, over the library's limit per axis",
                                                          cols, rows, (double)slices.size()));

    const size_t plane = (size_t)rows * cols;
    float *data = (float *)std::malloc(plane * slices.size() * sizeof(float));
    if (!data) return fail(err, err_size, std::string(dir) + ": out of memory for the volume");
    for (size_t z = 0; z < slices.size(); ++z) {
        gdcm::ImageReader reader;
        reader.SetFileName(slices[z].path.c_str());
        if (!reader.Read() || !read_pixels(slices[z].path, reader.GetImage(), data + z * plane, plane, err, err_size)) {
            if (err_size && !err[0]) std::snprintf(err, err_size, "%s: GDCM cannot read it", slices[z].path.c_str());
            std::free(data);
            return 0;
        }
    }
    float lo = data[0], hi = data[0];
    for (size_t i = 1; i < plane * slices.size(); ++i) {
        lo = std::min(lo, data[i]);
        hi = std::max(hi, data[i]);
    }
    out->desc.type = HD_VOXEL_F32;
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
