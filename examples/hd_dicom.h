/* hd_dicom.h - DICOM series (a folder of slices) for the example tools, in examples/hd_dicom.cpp
   (link -lgdcmMSFF -lgdcmDICT -lgdcmDSED -lgdcmCommon); the library itself does not depend on
   it. docs/DICOM.md describes what is read, what is checked and the limits. */
#ifndef HD_DICOM_H
#define HD_DICOM_H
#include <stddef.h>
#include "hybriddiff.h"
#ifdef __cplusplus
extern "C" {
#endif

/* 1 if path names a directory (then the tools read it as a DICOM series), else 0. */
int hdx_is_directory(const char *path);

/* Reads the single-frame greyscale DICOM images in dir (not its subfolders) as one volume:
   float32 voxels after the rescale slope and intercept, slices sorted by position along the
   slice normal (row cosine x column cosine), spacing from Pixel Spacing and the slice positions;
   x runs along a row, y down the columns, z along the normal.
   The folder is listed by the reader (regular files; links only to regular files inside it);
   each file is checked before GDCM parses it, and GDCM runs in a child process limited in
   address space and CPU time per file. Every entry that is not read (not DICOM, damaged, colour
   or multi-frame, a FIFO or link, a file GDCM aborts on) is named in one line on stderr,
   "PROGRAM: DICOM: PATH: skipped: WHY", and the series is made of the rest.
   On failure returns 0 and writes one line to err: no image left, several series, differing
   sizes or orientations, missing (a gap) or repeated slices. Calls fork(): call it before
   starting threads. out->data is malloc'd: hd_volume_free releases it. */
int hdx_dicom_load_series(const char *dir, hd_volume_file *out, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif
#endif
