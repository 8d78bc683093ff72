/* PNG writer for the visual truth image, by libpng's simplified API (no setjmp). */
#include "io/png_image.h"

#include <errno.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"

static unsigned char png_image_byte(float v)
{
    if (!(v > 0.0f))
        return 0;
    if (v >= 1.0f)
        return 255;
    return (unsigned char)(v * 255.0f + 0.5f);
}

thz_status png_image_write_srgb8(const char *path, const float *rgb, uint32_t columns,
                                 uint32_t rows, thz_error *err)
{
    if (columns == 0 || rows == 0)
        return thz_error_set(err, THZ_ERR_INTERNAL, "%s: empty image", path);
    /* libpng's writer refuses a side above its user limits with "Invalid IHDR data";
     * said here with the sizes (a classification of more than 10^6 pooled pixels, one
     * row of them, reaches it) */
    if (columns > PNG_USER_WIDTH_MAX || rows > PNG_USER_HEIGHT_MAX)
        return thz_error_set(
            err, THZ_ERR_LIMIT, "%s: %u x %u pixels: a PNG is written up to %lu x %lu pixels", path,
            columns, rows, (unsigned long)PNG_USER_WIDTH_MAX, (unsigned long)PNG_USER_HEIGHT_MAX);
    size_t n = (size_t)columns * rows;
    unsigned char *bytes = thz_malloc_array(n, 3);
    if (!bytes)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    for (size_t i = 0; i < 3 * n; i++)
        bytes[i] = png_image_byte(rgb[i]);

    png_image image;
    memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    image.width = columns;
    image.height = rows;
    image.format = PNG_FORMAT_RGB; /* 8-bit, sRGB-encoded (not linear) */
    thz_status status = THZ_OK;
    errno = 0; /* libpng reports an allocation failure, or fopen's ENOMEM, as a message */
    if (!png_image_write_to_file(&image, path, 0, bytes, (png_int_32)(3 * (size_t)columns), NULL))
        status = thz_error_set(
            err,
            errno == ENOMEM || (strstr(image.message, "memory") || strstr(image.message, "Memory"))
                ? THZ_ERR_NOMEM
                : THZ_ERR_IO,
            "%s: cannot write PNG: %s", path, image.message);
    png_image_free(&image);
    free(bytes);
    return status;
}
