// integrate_units_cxx.cpp - the C++17 half of integrate_units.c: the declarations only.
#include <cstdio>
#include <vector>
#include "hybriddiff.h"

extern "C" int render_in_cxx(const unsigned char *voxels, int n, int size)
{
    hd_desc desc = HD_DESC_INIT; // {} in C++
    desc.volume.type = HD_VOXEL_U8;
    desc.volume.dims[0] = desc.volume.dims[1] = desc.volume.dims[2] = n;
    desc.volume.data = voxels;
    desc.camera.width = desc.camera.height = size;
    desc.threads = 1;
    desc.logger.func = hd_log_stderr;
    hd_context ctx;
    if (hd_create(&desc, &ctx) != HD_SUCCESS) return -1;
    std::vector<uint8_t> px(size_t(size) * size * 4);
    for (int i = 0; i < 3; ++i) hd_render(ctx);
    hd_result r = hd_read_image_rgba8(ctx, px.data(), px.size());
    hd_destroy(ctx);
    if (r != HD_SUCCESS) { std::fprintf(stderr, "%s\n", hd_result_string(r)); return -1; }
    int lit = 0;
    for (size_t i = 0; i < px.size(); i += 4) lit += px[i] > 8;
    return lit;
}
