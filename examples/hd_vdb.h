/* hd_vdb.h - OpenVDB grids for the example tools, in examples/hd_vdb.cpp (link -lopenvdb); the
   library itself does not depend on it. docs/INTEGRATION.md ("Sparse volumes from OpenVDB") says
   what is read and how the grid's transform becomes the volume's. */
#ifndef HD_VDB_H
#define HD_VDB_H
#include <stddef.h>
#include "hybriddiff.h"
#ifdef __cplusplus
extern "C" {
#endif

/* 1 if path names an OpenVDB file: it ends in ".vdb", or in ".vdb:GRID" (a grid by name). */
int hdx_is_vdb(const char *path);

/* Reads one float grid of an OpenVDB file, "FILE.vdb" (the grid named "density", else the file's
   first float grid) or "FILE.vdb:GRID", as a dense volume: the bounding box of its active voxels
   and tiles, x fastest, inactive voxels at the grid's background value.
   out->desc: HD_VOXEL_F32, dims the box's, spacing the voxel size per axis, value_range the range
   of the values (hd_volume_file's rule: a constant grid gets a little more than nothing), and
   transform the volume-to-world matrix that puts the library's box where the grid's
   index-to-world map puts those voxels (voxel centres at integer index coordinates, as OpenVDB's
   are). Only linear maps (scale, rotation, translation; a shear is kept, and hd_create refuses
   it) are read; a frustum map is an error.
   The file is read in a child process limited in address space and CPU time, so a damaged file
   that makes OpenVDB abort or allocate what it claims costs an error line, not the tool. On
   failure returns 0 and writes one line to err. Calls fork(): call it before starting threads.
   out->data is malloc'd: hd_volume_free releases it. */
int hdx_vdb_load(const char *path, hd_volume_file *out, char *err, size_t err_size);

#ifdef __cplusplus
}
#endif
#endif
