/* hd_dicom.h - DICOM series (a folder of slices) for the example tools, read with GDCM in
   examples/hd_dicom.cpp (link -lgdcmMSFF -lgdcmDSED -lgdcmCommon); the library itself does not
   depend on it. */
#ifndef HD_DICOM_H
#define HD_DICOM_H
#include <stddef.h>
#include "hybriddiff.h"
#ifdef __cplusplus
extern "C" {
#endif

/* 1 if path names a directory (then the tools read it as a DICOM series), else 0. */
int hdx_is_directory(const char *path);

/* Reads the single-frame DICOM images in dir (files that are not DICOM are ignored) as one
   volume: float32 voxels after the rescale slope and intercept, slices sorted by position along
   the slice normal (row cosine x column cosine), spacing from Pixel Spacing and the slice
   positions; x runs along a row, y down the columns, z along the normal. On failure returns 0
   and writes one line to err: no images, several series, differing sizes or orientations,
   missing or repeated slices, colour or multi-frame images, a transfer syntax GDCM cannot
   decode. out->data is malloc'd: hd_volume_free releases it. */
int hdx_dicom_load_series(const char *dir, hd_volume_file *out, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif
#endif
