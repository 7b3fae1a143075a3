/* hd_multigrid_cg.h - HD_SOLVER_MULTIGRID's rules that the core's step (src/hd_multigrid.h) and
   the backends' primitives share: the row-order sum of the dot products' row sums, the
   levels' count, grids and parameter blocks, the solver's bytes (OpenCL pads its rows: its own
   count) and whether a backend's buffers still fit the grid. Below the backends: it calls none
   of them. docs/DESIGN-MULTIGRID.md has the design. */
#ifndef HD_MULTIGRID_CG_H
#define HD_MULTIGRID_CG_H


/* The sum of the first `rows` row sums in row order: the same bits for any thread count and on
   any backend. */
HD__MAYBE_UNUSED static double hd__mg_row_sum(const double *d, size_t rows)
{
    double s = 0.0;
    size_t r;
    for (r = 0; r < rows; ++r) s += d[r];
    return s;
}

/* Level l's grid: the fine grid halved l times, rounded down (hd__mg_levels' rule; halving
   a grid already halved and rounded down is the same as dividing by 2^l once). */
HD__MAYBE_UNUSED static void hd__mg_level_dims(const int *fine, int l, int *d)
{
    int i;
    for (i = 0; i < 3; ++i) d[i] = fine[i] / (1 << l);
}

/* How many levels a fine grid has: halved (rounded down) until at most 4 voxels per axis, or
   fewer than 4 on one axis; at most HD__MG_MAX_LEVELS. */
#define HD__MG_MAX_LEVELS 12
HD__MAYBE_UNUSED static int hd__mg_levels(const int *fine)
{
    int l, d[3];
    for (l = 0; l < HD__MG_MAX_LEVELS - 1; ++l) {
        hd__mg_level_dims(fine, l, d);
        if ((d[0] <= 4 && d[1] <= 4 && d[2] <= 4) || d[0] < 4 || d[1] < 4 || d[2] < 4) break;
    }
    return l + 1;
}

/* Level l's parameter block: the fine one with the level's grid d, 1 / h^2 and h of its spacing
   (2^l fine voxels), and the right-hand-side flag (each level smooths A e = its rhs). */
HD__MAYBE_UNUSED static hd__kparams hd__mg_level_kp(const hd__kparams *fine, int l, const int *d)
{
    hd__kparams kp = *fine;
    float s = (float)(1 << l);
    kp.gdims.x = d[0]; kp.gdims.y = d[1]; kp.gdims.z = d[2];
    kp.grid.x = fine->grid.x / (s * s); kp.grid.y = fine->grid.y / (s * s); kp.grid.z = fine->grid.z / (s * s);
    kp.gridh.x = fine->gridh.x * s; kp.gridh.y = fine->gridh.y * s; kp.gridh.z = fine->gridh.z * s;
    kp.counts.z |= HD_FLAG_DIFFUSE_RHS;
    return kp;
}

/* Values of `channels` channels on grid d. */
HD__MAYBE_UNUSED static size_t hd__mg_voxels(const int *d, int channels) { return (size_t)channels * d[0] * (size_t)d[1] * d[2]; }

/* Bytes of the solver's state on a backend whose grids are unpadded, one float per value (CPU, GL
   and Vulkan; counted in method_bytes): the two row-sum buffers (a double per fine row and channel),
   p and lo on the fine grid, each of `levels` levels' rhs, phi and residual, and the coarse
   levels' sigma_t of sig_channels channels. */
HD__MAYBE_UNUSED static size_t hd__mg_bytes(const int *fine, int levels, int channels, int sig_channels)
{
    size_t b = 2 * sizeof(double) * (size_t)fine[1] * fine[2] * channels + 2 * sizeof(float) * hd__mg_voxels(fine, channels);
    int l, d[3];
    for (l = 0; l < levels; ++l) {
        hd__mg_level_dims(fine, l, d);
        b += 3 * sizeof(float) * hd__mg_voxels(d, channels);
        if (l > 0) b += sizeof(float) * hd__mg_voxels(d, sig_channels);
    }
    return b;
}

/* Whether a backend's solver buffers, made for fine grid `fine` with channels and sig_channels
   channels, no longer fit the view's grid (hd__be_mg_begin then remakes them). */
HD__MAYBE_UNUSED static int hd__mg_stale(const hd__view *vw, const int *fine, int channels, int sig_channels)
{
    return channels != vw->channels || sig_channels != vw->sig_channels || memcmp(fine, vw->gdims, 3 * sizeof(int)) != 0;
}

#endif
