/*
 * image/image_png.c — PNG writing and reading through libpng.
 *
 * Writing: 8-bit RGBA. Colour is the sRGB transfer curve applied to linear
 * values clamped to [0, 1] (NaN becomes 0); alpha is stored linearly, as
 * PNG requires. The renderer's colour is premultiplied by alpha (as EXR
 * keeps it); PNG's is not, so RGBA files store colour / alpha (a pixel
 * of alpha 0 black): stored premultiplied, every viewer multiplied it by
 * alpha again, and silhouettes and glows over the background came out
 * dark (a half-covered white edge pixel showed 0.25 over black, not 0.5). The file carries an sRGB
 * chunk, with the gAMA and cHRM chunks that the PNG specification asks for beside it for older
 * readers. image_write_png_curve can instead quantize the values as they are, with no colour chunk
 * (RenderMan's 8-bit files: its Exposure is the curve).
 *
 * Reading: any PNG (palette, grey, 1 to 16 bits, interlaced, with or
 * without alpha or tRNS) is converted by libpng to 8-bit RGBA, then colour
 * is decoded from sRGB to linear through a 256-entry table; alpha stays
 * linear. gAMA, cHRM and ICC chunks are ignored: the file is taken to be
 * sRGB, which is what nearly every PNG means.
 *
 * libpng reports errors by longjmp to a setjmp in our code; each setjmp
 * sits in a small function whose only state lives behind a pointer, so no
 * local variable is modified between setjmp and longjmp. Our error and
 * warning callbacks never print: the first error message goes to err.
 *
 * Thread-safety: reentrant; each call has its own libpng structures.
 */
#include "image/image.h"
#include "image/image_internal.h"
#include "util/colour.h"

#include <errno.h>
#include <math.h>
#include <setjmp.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <png.h>

/* Limits on images we read (see image_exr.c): 2^28 pixels is 4 GiB of
 * floats, far beyond any render, and stops a forged header early. */
#define MAX_PIXELS ((uint64_t)1 << 28)

/* One PNG call's state, shared with libpng's callbacks (error and I/O
 * pointer). */
typedef struct PngIo {
    FILE *file;         /* read or written; owned by the caller */
    int sys_errno;      /* errno of the first failed read or write, or 0 */
    bool truncated;     /* a read met the end of the file */
    char message[256];  /* libpng's first error message, "" if none */
    uint8_t *pixels;    /* reading: 8-bit RGBA, width * height * 4; owned */
    png_bytep *rows;    /* reading: height pointers into pixels; owned */
    png_uint_32 width;  /* reading: pixels */
    png_uint_32 height; /* reading: pixels */
} PngIo;

typedef struct PngImage {
    int width, height; /* pixels */
    const float *rgba; /* width * height * 4, top row first */
    int linear;        /* 1: values quantized as they are, no colour chunk */
    int channels;      /* 4: RGBA, 3: RGB */
} PngImage;

/* ------------------------------------------------------------ callbacks */

static void on_png_error(png_structp png, png_const_charp msg)
{
    PngIo *io = png_get_error_ptr(png);
    if (io->message[0] == '\0')
        snprintf(io->message, sizeof io->message, "%s", msg);
    png_longjmp(png, 1);
}

/* Warnings (a bad ancillary chunk, say) do not stop reading, and library
 * code does not print. */
static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;
}

static void write_png_bytes(png_structp png, png_bytep data, size_t n_bytes)
{
    PngIo *io = png_get_io_ptr(png);
    if (fwrite(data, 1, n_bytes, io->file) != n_bytes) {
        if (io->sys_errno == 0)
            io->sys_errno = errno ? errno : EIO;
        png_error(png, "write failed");
    }
}

/* image_write_via_temp flushes once at the end, which reports the error. */
static void flush_png(png_structp png)
{
    (void)png;
}

static void read_png_bytes(png_structp png, png_bytep data, size_t n_bytes)
{
    PngIo *io = png_get_io_ptr(png);
    if (fread(data, 1, n_bytes, io->file) != n_bytes) {
        if (ferror(io->file) && io->sys_errno == 0)
            io->sys_errno = errno ? errno : EIO;
        else
            io->truncated = true;
        png_error(png, "read failed");
    }
}

/* Fills err with "PATH: doing: why" after a libpng error. */
static RayesError report(const PngIo *io, const char *path, const char *doing, char *err,
                         size_t err_size)
{
    if (io->sys_errno != 0) {
        image_set_errno_error(err, err_size, io->sys_errno, "%s: %s", path, doing);
        return RAYES_ERROR_IO;
    }
    if (io->truncated) {
        image_set_error(err, err_size, "%s: %s: the file is truncated", path, doing);
        return RAYES_ERROR_PARSE;
    }
    image_set_error(err, err_size, "%s: %s: %s", path, doing,
                 io->message[0] ? io->message : "unknown libpng error");
    /* libpng says "Out of Memory", ours "out of memory". */
    return strcasestr(io->message, "out of memory") ? RAYES_ERROR_OUT_OF_MEMORY : RAYES_ERROR_PARSE;
}

/* -------------------------------------------------------------- writing */

static uint8_t encode_srgb8(float linear)
{
    if (!(linear > 0.0f)) /* also NaN */
        return 0;
    if (linear >= 1.0f)
        return 255;
    return (uint8_t)(colour_linear_to_srgb(linear) * 255.0f + 0.5f);
}

static uint8_t encode_linear8(float value)
{
    if (!(value > 0.0f))
        return 0;
    return value >= 1.0f ? 255 : (uint8_t)(value * 255.0f + 0.5f);
}

/* Runs libpng over the whole image; returns 0, or -1 after a libpng error
 * (the message in io). row holds width * image->channels bytes. */
static int write_png_all(png_structp png, png_infop info, const PngImage *image, uint8_t *row)
{
    if (setjmp(png_jmpbuf(png)))
        return -1;
    png_set_IHDR(png, info, (png_uint_32)image->width, (png_uint_32)image->height, 8,
                 image->channels == 4 ? PNG_COLOR_TYPE_RGB_ALPHA : PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    if (!image->linear)
        png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    for (int y = 0; y < image->height; y++) {
        const float *src = image->rgba + (size_t)y * (size_t)image->width * 4;
        for (int x = 0, k = image->channels; x < image->width; x++) {
            float a = src[4 * x + 3];
            /* RGBA: straight colour; RGB keeps what lies over black */
            float unmul = k == 4 ? (a > 0.0f && a < 1.0f ? 1.0f / a : a > 0.0f) : 1.0f;
            for (int c = 0; c < 3; c++) {
                float v = src[4 * x + c] * unmul;
                row[k * x + c] = image->linear ? encode_linear8(v) : encode_srgb8(v);
            }
            if (k == 4)
                row[4 * x + 3] = encode_linear8(a);
        }
        png_write_row(png, row);
    }
    png_write_end(png, info);
    return 0;
}

/* ImageBodyWriter for image_write_via_temp; data is a PngImage. */
static RayesError write_png_body(FILE *file, const char *path, const void *data, char *err,
                                 size_t err_size)
{
    const PngImage *image = data;
    PngIo io = {.file = file};
    uint8_t *row = malloc((size_t)image->width * 4);
    png_structp png =
        row ? png_create_write_struct(PNG_LIBPNG_VER_STRING, &io, on_png_error, on_png_warning)
            : NULL;
    png_infop info = png ? png_create_info_struct(png) : NULL;
    RayesError rv = RAYES_OK;
    if (!info) {
        image_set_error(err, err_size, "%s: out of memory", path);
        rv = RAYES_ERROR_OUT_OF_MEMORY;
    } else {
        png_set_write_fn(png, &io, write_png_bytes, flush_png);
        if (write_png_all(png, info, image, row) != 0)
            rv = report(&io, path, "cannot write PNG", err, err_size);
        if (rv == RAYES_ERROR_PARSE) /* libpng refused our image, e.g. too wide */
            rv = RAYES_ERROR_INVALID_ARGUMENT;
    }
    png_destroy_write_struct(&png, info ? &info : NULL);
    free(row);
    return rv;
}

RayesError image_write_png(const char *path, int width, int height, const float *rgba, char *err,
                        size_t err_size)
{
    return image_write_png_curve(path, width, height, rgba, 0, err, err_size);
}

RayesError image_write_png_curve(const char *path, int width, int height, const float *rgba,
                                 int flags, char *err, size_t err_size)
{
    if (!path || !rgba || width <= 0 || height <= 0) {
        image_set_error(err, err_size, "%s: cannot write PNG: invalid arguments (%d x %d pixels%s)",
                     path ? path : "(null)", width, height, rgba ? "" : ", no pixels");
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    PngImage image = {width, height, rgba, (flags & IMAGE_LINEAR) != 0,
                      flags & IMAGE_NO_ALPHA ? 3 : 4};
    return image_write_via_temp(path, write_png_body, &image, err, err_size);
}

/* -------------------------------------------------------------- reading */

/* Asks libpng for 8-bit RGBA whatever the file holds. */
static void request_rgba8(png_structp png, png_infop info)
{
    int color_type = png_get_color_type(png, info);
    png_set_expand(png);   /* palette to RGB, 1-4 bit grey to 8, tRNS to alpha */
    png_set_scale_16(png); /* 16 bits to 8, rounded (strip_16 would truncate) */
    png_set_gray_to_rgb(png);
    if (!(color_type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(png, info, PNG_INFO_tRNS))
        png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
}

/* Runs libpng over the whole file into io->pixels; returns 0, or -1 after
 * a libpng error (the message in io; io->pixels and io->rows, if set, are
 * the caller's to free). */
static int read_png_all(png_structp png, png_infop info, PngIo *io)
{
    if (setjmp(png_jmpbuf(png)))
        return -1;
    png_set_sig_bytes(png, 8);
    png_read_info(png, info);
    io->width = png_get_image_width(png, info);
    io->height = png_get_image_height(png, info);
    if ((uint64_t)io->width * io->height > MAX_PIXELS)
        png_error(png, "image too large");
    request_rgba8(png, info);
    if (png_get_rowbytes(png, info) != (size_t)io->width * 4)
        png_error(png, "cannot convert to 8-bit RGBA");
    io->pixels = malloc((size_t)io->width * io->height * 4);
    io->rows = malloc(io->height * sizeof *io->rows);
    if (!io->pixels || !io->rows)
        png_error(png, "out of memory");
    for (png_uint_32 y = 0; y < io->height; y++)
        io->rows[y] = io->pixels + (size_t)y * io->width * 4;
    png_read_image(png, io->rows);
    /* Reading the end finds truncation after the last row and bad CRCs. */
    png_read_end(png, NULL);
    return 0;
}

/* Converts io's 8-bit sRGB pixels to new linear floats, or NULL. */
static float *decode_pixels(const PngIo *io)
{
    size_t n = (size_t)io->width * io->height * 4;
    float *rgba = malloc(n * sizeof *rgba);
    if (!rgba)
        return NULL;
    float linear[256];
    for (int i = 0; i < 256; i++) {
        float v = (float)i / 255.0f;
        linear[i] = colour_srgb_to_linear(v);
    }
    for (size_t i = 0; i < n; i += 4) {
        rgba[i + 0] = linear[io->pixels[i + 0]];
        rgba[i + 1] = linear[io->pixels[i + 1]];
        rgba[i + 2] = linear[io->pixels[i + 2]];
        rgba[i + 3] = (float)io->pixels[i + 3] / 255.0f;
    }
    return rgba;
}

/* Reads the rest of an open file whose 8 signature bytes were checked. */
static RayesError read_png_file(PngIo *io, const char *path, char *err, size_t err_size)
{
    png_structp png =
        png_create_read_struct(PNG_LIBPNG_VER_STRING, io, on_png_error, on_png_warning);
    png_infop info = png ? png_create_info_struct(png) : NULL;
    if (!info) {
        png_destroy_read_struct(&png, NULL, NULL);
        image_set_error(err, err_size, "%s: out of memory", path);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    png_set_read_fn(png, io, read_png_bytes);
    int failed = read_png_all(png, info, io);
    png_destroy_read_struct(&png, &info, NULL);
    if (failed)
        return report(io, path, "cannot read PNG", err, err_size);
    return RAYES_OK;
}

RayesError image_read_png(const char *path, int *width, int *height, float **rgba, char *err,
                       size_t err_size)
{
    if (!path || !width || !height || !rgba) {
        image_set_error(err, err_size, "%s: cannot read PNG: invalid arguments",
                     path ? path : "(null)");
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    *rgba = NULL;
    *width = *height = 0;
    PngIo io = {.file = fopen(path, "rbe")};
    if (!io.file) {
        image_set_errno_error(err, err_size, errno, "%s: cannot open", path);
        return RAYES_ERROR_IO;
    }
    uint8_t signature[8];
    RayesError rv = RAYES_OK;
    if (fread(signature, 1, sizeof signature, io.file) != sizeof signature ||
        png_sig_cmp(signature, 0, sizeof signature) != 0) {
        image_set_error(err, err_size, "%s: not a PNG file", path);
        rv = RAYES_ERROR_PARSE;
    } else {
        rv = read_png_file(&io, path, err, err_size);
    }
    fclose(io.file);
    if (rv == RAYES_OK) {
        *rgba = decode_pixels(&io);
        if (!*rgba) {
            image_set_error(err, err_size, "%s: out of memory", path);
            rv = RAYES_ERROR_OUT_OF_MEMORY;
        } else {
            *width = (int)io.width;
            *height = (int)io.height;
        }
    }
    free(io.pixels);
    free(io.rows);
    return rv;
}
