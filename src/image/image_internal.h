/*
 * image/image_internal.h — private to src/image/: error
 * formatting and the atomic write (temporary file, then rename) that
 * image_file.c implements for image_exr.c and image_png.c.
 */
#ifndef RAYES_IMAGE_IMAGE_INTERNAL_H
#define RAYES_IMAGE_IMAGE_INTERNAL_H

#include <stddef.h>
#include <stdio.h>

#include "rayes/rayes.h"

/* Writes the body of a file to an open stream; returns RAYES_OK or fills err. */
typedef RayesError (*ImageBodyWriter)(FILE *file, const char *path, const void *data, char *err,
                                   size_t err_size);

/* Formats one line into err (newlines in library messages are flattened). */
void image_set_error(char *err, size_t err_size, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* As image_set_error, followed by ": " and the text of errnum. */
void image_set_errno_error(char *err, size_t err_size, int errnum, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Runs write_body on a temporary file beside path and renames it over path
 * on success; on failure removes the temporary and leaves path untouched. */
RayesError image_write_via_temp(const char *path, ImageBodyWriter write_body, const void *data, char *err,
                             size_t err_size);

#endif /* RAYES_IMAGE_IMAGE_INTERNAL_H */
