/* hd_k_classify.h - sigma_t at the illumination grid's voxel centres, for the diffusion stencil
   (shared source), and with RGB scattering the TF colour there in channels 1..3 (channel k at
   index i + k * voxels, image z + k * dz, like E and phi). Rerun when the transfer function,
   the extinction or the crop box changes. */
HD_FN void hdk_classify_voxel(HD_KARGS int x, int y, int z)
{
    int gx = HD_PRM(gdims).x, gy = HD_PRM(gdims).y, gz = HD_PRM(gdims).z;
    int i = (z * gy + y) * gx + x;
    hd_v3 u = HD_V3((HD_F(x) + 0.5f) / HD_F(gx), (HD_F(y) + 0.5f) / HD_F(gy), (HD_F(z) + 0.5f) / HD_F(gz));
    float v;
    if (gx == HD_PRM(dims).x && gy == HD_PRM(dims).y && gz == HD_PRM(dims).z) {
        v = hdk_voxel(HD_KPASS i, x, y, z); /* same grid: the voxel itself, no interpolation round-off */
    } else {
        v = hdk_sample_value(HD_KPASS u);
    }
    {
        hd_v4 c = hdk_tf(HD_KPASS v);
        /* outside the crop box the voxel holds no medium */
        HD_SET(sig, i, x, y, z, hdk_in_crop(HD_KPASS u) != 0 ? c.w * HD_PRM(medium).x : 0.0f);
        if ((HD_PRM(counts).z & HD_FLAG_RGB_SCATTERING) != 0) {
            int nvox = gx * gy * gz;
            HD_SET(sig, i + nvox, x, y, z + gz, c.x);
            HD_SET(sig, i + 2 * nvox, x, y, z + 2 * gz, c.y);
            HD_SET(sig, i + 3 * nvox, x, y, z + 3 * gz, c.z);
        }
    }
}
