/* hd_k_classify.h - sigma_t at the illumination grid's voxel centres, for the diffusion stencil
   (shared source). Rerun when the transfer function or the extinction changes. */
HD_FN void hd_classify_voxel(HD_KARGS int x, int y, int z)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x;
    float v;
    if (gx == HD_PRM(dims).x && gy == HD_PRM(dims).y && gz == HD_PRM(dims).z) {
        v = HD_GET(vol, i, x, y, z); /* same grid: the voxel itself, no interpolation round-off */
    } else {
        v = hd_sample_value(HD_KPASS HD_V3((HD_F(x) + 0.5f) / HD_F(gx), (HD_F(y) + 0.5f) / HD_F(gy),
                                           (HD_F(z) + 0.5f) / HD_F(gz)));
    }
    HD_SET(sig, i, x, y, z, hd_tf(HD_KPASS v).w * HD_PRM(medium).x);
}
