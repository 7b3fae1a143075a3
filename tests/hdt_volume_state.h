/* hdt_volume_state.h - the core's view of the volume, read by a test hook of tests/hd_impl_cpu.c
   for tests/test_living.c: what hd_update_volume must keep equal to a fresh context's (voxels,
   cell ranges, majorants, the largest extinction, the direct light's mask and list, E's sample
   count), after hd__prepare (run by hd_read_illumination's bracket). The pointers are the
   context's own, valid until its next call. One declaration for both files. */
#ifndef HDT_VOLUME_STATE_H
#define HDT_VOLUME_STATE_H
#include <stddef.h>
#include <stdint.h>
#include "hybriddiff.h"

typedef struct hdt_volume_state {
    size_t nvox, ncell, gvox, dl_count;
    void *vol;        /* the voxels as the core keeps them (normalised floats for F32) */
    size_t vol_bytes; /* their bytes */
    float *cell_range, *majorant, max_sigma;
    unsigned char *bits;
    uint32_t *dl_idx;   /* the list, or NULL where the backend reads the bits (dl_brick) */
    uint32_t *dl_brick; /* the entries before each brick, dl_bricks + 1 of them, or NULL */
    size_t dl_bricks;
    uint64_t dl_n;
} hdt_volume_state;
/* 1 with *s filled, 0 for a stale handle. */
int hdt_volume_state_get(hd_context h, hdt_volume_state *s);
#endif
