/* hd_png.h - stb_image_write (Debian: libstb-dev) for the examples: its implementation, once per
   program, with the warnings it trips under -Wall -Wextra -Wpedantic -Werror silenced here only.
   Include it in the one .c file of an example that writes PNGs. */
#ifndef HD_PNG_H
#define HD_PNG_H
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#if defined(__GNUC__) || defined(__clang__)
#pragma GCC diagnostic pop
#endif
#endif
