/* hd_crop.h - the tools' default crop box per known volume (hdrender, hdview), so both show the
   same scene; header-only. */
#ifndef HD_CROP_H
#define HD_CROP_H
#include <string.h>
#include "hybriddiff.h"

/* The head CT that scripts/fetch-data fetches (face +y, top +z) lies on the scanner's head rest,
   a U-shaped sheet that hugs the back of the head (low y) and rises beside it (low and high x).
   No box separates the two entirely: this one clears the rest from the default view (the face,
   three-quarter) and keeps the ears, at the price of the back of the scalp and skull (y below
   0.165, about 3 cm; seen only from behind); thin strips of the rest's sides stay behind the
   head, seen from the side or behind. Fills p's crop box and returns 1 for a known volume (file
   name and dims), else returns 0 and leaves p alone. */
static int hdx_known_crop(const char *path, const int dims[3], hd_params *p)
{
    static const float head_min[3] = {0.11f, 0.165f, 0.0f}, head_max[3] = {0.89f, 1.0f, 1.0f};
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (strcmp(base, "head.nrrd") == 0 && dims[0] == 256 && dims[1] == 256 && dims[2] == 108) {
        memcpy(p->crop_min, head_min, sizeof head_min);
        memcpy(p->crop_max, head_max, sizeof head_max);
        return 1;
    }
    return 0;
}
#endif
