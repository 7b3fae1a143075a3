# brainsmall.tf - VolPack's MRI head (data/brainsmall.nrrd, uint8) for hdeval's second scene:
# background noise (values below about 10) transparent, skin and tissue (20-90) a thick, skin-
# coloured scatterer, the few brighter voxels opaque.
domain 0 255
0    0.95 0.75 0.62 0
12   0.95 0.75 0.62 0
30   0.95 0.75 0.62 0.5
90   0.92 0.65 0.55 0.7
255  1.00 0.97 0.90 0.95
