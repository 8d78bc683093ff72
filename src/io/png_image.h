/* 8-bit RGB PNG files through libpng: the visual truth image S.visual.png. */
#ifndef THZ_IO_PNG_IMAGE_H
#define THZ_IO_PNG_IMAGE_H

#include <stdint.h>

#include "core/error.h"

/* Writes rgb (rows x columns x 3 values, row 0 at the top) to path as an 8-bit sRGB
 * PNG. The values are taken as sRGB-encoded intensities in 0..1 (a material's `color`
 * is written unchanged where fully lit); values outside are clamped, NaN gives 0.
 * THZ_ERR_LIMIT for a side above libpng's limit (10^6 pixels). */
thz_status png_image_write_srgb8(const char *path, const float *rgb, uint32_t columns,
                                 uint32_t rows, thz_error *err);

#endif
