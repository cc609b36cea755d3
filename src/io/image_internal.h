/*
 * io/image_internal.h — private to the image writers of src/io/: error
 * formatting and the atomic write (temporary file, then rename) that
 * image.c implements for image_exr.c and image_png.c.
 */
#ifndef RAYES_IO_IMAGE_INTERNAL_H
#define RAYES_IO_IMAGE_INTERNAL_H

#include <stddef.h>
#include <stdio.h>

#include "rayes/rayes.h"

/* Writes the body of a file to an open stream; returns RAYES_OK or fills err. */
typedef RayesError (*IoBodyWriter)(FILE *file, const char *path, const void *data, char *err,
                                   size_t err_size);

/* Formats one line into err (newlines in library messages are flattened). */
void io_set_error(char *err, size_t err_size, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
/* As io_set_error, followed by ": " and the text of errnum. */
void io_set_errno_error(char *err, size_t err_size, int errnum, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* Runs write_body on a temporary file beside path and renames it over path
 * on success; on failure removes the temporary and leaves path untouched. */
RayesError io_write_via_temp(const char *path, IoBodyWriter write_body, const void *data, char *err,
                             size_t err_size);

#endif /* RAYES_IO_IMAGE_INTERNAL_H */
