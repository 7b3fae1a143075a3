/* hd_input.h - the tools' volume input: a folder is a DICOM series (hd_dicom.h, GDCM), FILE.vdb or
   FILE.vdb:GRID an OpenVDB grid (hd_vdb.h), anything else a file for hd_volume_load (NRRD,
   MetaImage, NIfTI). The tools frame the volume's box themselves, so a grid's placement in its
   world (out->desc.transform) is dropped here; a host that places the volume keeps it. */
#ifndef HD_INPUT_H
#define HD_INPUT_H
#include <stdio.h>
#include <string.h>
#include "hd_dicom.h"
#include "hd_vdb.h"

/* HD_SUCCESS, or the loader's result with its message in err (DICOM and OpenVDB write one there;
   hd_volume_load logs its own through log and leaves err empty). */
static hd_result hdx_load_input(const char *input, hd_volume_file *out, const hd_logger *log, char *err,
                                size_t err_size)
{
    if (err_size) err[0] = 0;
    if (hdx_is_directory(input)) {
        char e[480];
        if (hdx_dicom_load_series(input, out, e, sizeof e)) return HD_SUCCESS;
        snprintf(err, err_size, "DICOM: %s", e);
        return HD_ERROR_FILE_FORMAT;
    }
    if (hdx_is_vdb(input)) {
        char e[480];
        if (!hdx_vdb_load(input, out, e, sizeof e)) {
            snprintf(err, err_size, "OpenVDB: %s", e);
            return HD_ERROR_FILE_FORMAT;
        }
        memset(out->desc.transform, 0, sizeof out->desc.transform);
        return HD_SUCCESS;
    }
    return hd_volume_load(input, out, log);
}
#endif
