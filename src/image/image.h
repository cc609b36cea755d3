/*
 * image/image.h — writing and reading images: OpenEXR (through OpenEXRCore's
 * C API) and PNG (libpng).
 *
 * Pixels are RGBA floats, linear, top row first, width * height * 4.
 * Writers are atomic: they write a temporary file beside the target and
 * rename it, so the target appears whole or not at all (an existing target
 * is left untouched on failure). Errors fill err (one line naming the
 * file and what went wrong; err may be NULL or err_size 0) and return
 * nonzero RayesError: INVALID_ARGUMENT for bad parameters, IO when the
 * system refuses (a missing directory, a full disk), PARSE for a file that
 * is not a readable image, OUT_OF_MEMORY. On failure a reader sets *rgba
 * to NULL and *width and *height to 0.
 * Thread-safety: all functions are reentrant.
 */
#ifndef RAYES_IMAGE_IMAGE_H
#define RAYES_IMAGE_IMAGE_H

#include <stddef.h>

#include "rayes/rayes.h"

typedef enum ImageFormat {
    IMAGE_FORMAT_UNKNOWN = 0,
    IMAGE_FORMAT_EXR = 1,
    IMAGE_FORMAT_PNG = 2
} ImageFormat;

/* The format named by a path's extension (.exr, .png, any case). */
ImageFormat image_format_from_path(const char *path);

/* What the writers below write beyond the pixels' colours:
 * IMAGE_LINEAR (PNG) the values quantized as they are (clamped to [0, 1])
 * with no colour chunk: what RenderMan writes to 8 bits, its Exposure
 * gamma the only curve (else the sRGB curve and chunk);
 * IMAGE_NO_ALPHA R, G, B only (RenderMan's display mode "rgb": what no
 * surface covers is black, not transparent). */
#define IMAGE_AOV_NAME 64 /* an AOV channel's name, its NUL included, at most */

enum { IMAGE_LINEAR = 1, IMAGE_NO_ALPHA = 2, IMAGE_NO_COLOUR = 4 /* EXR: the AOVs alone */ };

/* EXR: half-float R, G, B, A channels, ZIP compression, scanlines, with a
 * "renderer" string attribute. */
RayesError image_write_exr(const char *path, int width, int height, const float *rgba,
                        char *err, size_t err_size);
/* The same with the data window x, y, w, h of window[] (a crop: the
 * display window stays width x height, as OpenEXR intends) and flags
 * (IMAGE_NO_ALPHA). */
RayesError image_write_exr_window(const char *path, int width, int height, const float *rgba,
                                  const int window[4], int flags, char *err, size_t err_size);

/* The same with aov_channels 32-bit float channels more, named
 * aov_names[c], from aov (width * height * aov_channels floats): a
 * render's AOVs (RayesImage.aov) beside its colour. */
RayesError image_write_exr_aov(const char *path, int width, int height, const float *rgba,
                               const int window[4], int flags, const float *aov, int aov_channels,
                               const char *const *aov_names, char *err, size_t err_size);

/* PNG: 8-bit RGBA, sRGB-encoded (the sRGB transfer curve applied to the
 * clamped linear values, alpha linear), with an sRGB chunk. */
RayesError image_write_png(const char *path, int width, int height, const float *rgba,
                        char *err, size_t err_size);

/* The same with flags (IMAGE_LINEAR, IMAGE_NO_ALPHA). */
RayesError image_write_png_curve(const char *path, int width, int height, const float *rgba,
                                 int flags, char *err, size_t err_size);

/* Dispatch on the extension; an unknown extension is INVALID_ARGUMENT. */
RayesError image_write(const char *path, int width, int height, const float *rgba,
                          char *err, size_t err_size);

/* Reads part 0 of an EXR file with R, G, B (and optionally A; 1 if absent)
 * channels of any pixel type, scanline or tiled (a mipmap's full level);
 * the data window is the image. DWAA/DWAB files are not readable (the
 * OpenEXRCore of Debian 12 cannot decompress them). *rgba is new (free()). */
RayesError image_read_exr(const char *path, int *width, int *height, float **rgba,
                       char *err, size_t err_size);

/* The same, with the file's display window size (display[0] x
 * display[1]) and its data window within it (window: x, y, w, h; the
 * image is the data window's pixels): a crop rendered with --crop. */
RayesError image_read_exr_window(const char *path, int display[2], int window[4], float **rgba,
                                 char *err, size_t err_size);
/* The same, with up to max_aov of its float channels besides R, G, B, A
 * (AOVs, not subsampled, names under IMAGE_AOV_NAME bytes): *n_aov of
 * them into *aov (window's pixels, *n_aov floats each, in the file's
 * order; new, free(); NULL when none), their names in names[]; *others
 * (may be NULL) counts every channel besides R, G, B, A. aov, n_aov and
 * names may be NULL to read none. */
RayesError image_read_exr_aov(const char *path, int display[2], int window[4], float **rgba,
                              float **aov, int *n_aov, char (*names)[IMAGE_AOV_NAME], int max_aov,
                              int *others, char *err, size_t err_size);

/* Reads a PNG (any bit depth/colour type, converted to RGBA) and decodes
 * sRGB to linear. *rgba is new (free()). */
RayesError image_read_png(const char *path, int *width, int *height, float **rgba,
                       char *err, size_t err_size);

#endif /* RAYES_IMAGE_IMAGE_H */
