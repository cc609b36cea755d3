/*
 * image/image.c — writing an image: the format chosen by the file name,
 * then its writer (image_exr.c, image_png.c), which writes through
 * image_file.c's atomic write. The dispatcher depends on the writers,
 * never the reverse.
 */
#include "image/image.h"
#include "image/image_internal.h"

#include <stdio.h>
#include <string.h>
#include <strings.h>

ImageFormat image_format_from_path(const char *path)
{
    if (!path)
        return IMAGE_FORMAT_UNKNOWN;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    /* A leading dot names a hidden file (".png"), not an extension. */
    if (!dot || dot == base)
        return IMAGE_FORMAT_UNKNOWN;
    if (strcasecmp(dot, ".exr") == 0)
        return IMAGE_FORMAT_EXR;
    if (strcasecmp(dot, ".png") == 0)
        return IMAGE_FORMAT_PNG;
    return IMAGE_FORMAT_UNKNOWN;
}

RayesError image_write(const char *path, int width, int height, const float *rgba, char *err,
                          size_t err_size)
{
    switch (image_format_from_path(path)) {
    case IMAGE_FORMAT_EXR:
        return image_write_exr(path, width, height, rgba, err, err_size);
    case IMAGE_FORMAT_PNG:
        return image_write_png(path, width, height, rgba, err, err_size);
    case IMAGE_FORMAT_UNKNOWN:
        break;
    }
    image_set_error(err, err_size, "%s: unknown image format (the name should end in .exr or .png)",
                 path ? path : "(null)");
    return RAYES_ERROR_INVALID_ARGUMENT;
}
