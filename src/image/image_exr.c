/*
 * image/image_exr.c — OpenEXR writing and reading through OpenEXRCore, the C
 * API of OpenEXR 3.
 *
 * Writing: one scanline part, half R, G, B, A, ZIP compression (16 lines a
 * chunk), and a "renderer" string attribute. The library converts our
 * floats to half while packing; values too large for half (65520 and up)
 * become infinity, as in any half file. The bytes go to the temporary file
 * of image_write_via_temp through our own write function, so the library
 * never opens a file.
 *
 * Reading: part 0 of any flat (not deep) file, scanline or tiled (level 0
 * of a mipmap), half, float or uint channels (uint values become floats as
 * numbers), whose data window becomes the image. R, G and B are required,
 * A is 1 when absent, other channels are skipped. Every compression but
 * DWAA/DWAB, which OpenEXRCore 3.1 cannot decompress (its message says so).
 *
 * OpenEXRCore 3.1.5 quirks this file works around:
 *  - The coding pipelines list channels sorted by name (A, B, G, R), not in
 *    the order they were added, so pointers are bound by channel_name.
 *  - The decoder's specialised unpack routines cannot be trusted: for our
 *    interleaved RGBA floats it picked its reversed-interleave routine,
 *    which stored A in R, B in G and so on; with a skipped channel it wrote
 *    through that channel's NULL pointer; and its 3-channel planar routine
 *    reads the third channel one element after the second. So after
 *    exr_decoding_choose_default_routines (kept for reading and
 *    decompressing) we install our own unpack step, unpack_rgba, which
 *    converts the decompressed chunk (line by line, channel by channel,
 *    little-endian) into our RGBA floats. The encoder has a single generic
 *    pack routine, which is correct and converts float to half itself.
 *  - A chunk stored raw (as large as its pixels) still goes through the
 *    B44 decoder; decode_chunk skips decompression for such chunks.
 *  - Without an error handler the library prints to stderr; ours keeps the
 *    first message for err instead. Global defaults (exr_set_default_*)
 *    are not touched, so other threads' contexts are unaffected.
 *
 * Thread-safety: reentrant; each call has its own context and file.
 */
#include "image/image.h"
#include "image/image_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openexr.h>

/* Limits on images we read: a side keeps a line of RGBA floats within the
 * library's int32 line stride, and the pixel count keeps a forged header
 * from asking for an absurd allocation (2^28 pixels is 4 GiB of floats). */
#define MAX_SIDE (1 << 24)
#define MAX_PIXELS ((int64_t)1 << 28)

/* What one EXR call shares with the library's callbacks (user_data). */
typedef struct ExrIo {
    int fd;                /* the file read or written; owned by the caller */
    int sys_errno;         /* the first failed read or write's errno, or 0 */
    bool short_read;       /* a read met the end of the file */
    char first_error[256]; /* the library's first message, "" if none */
} ExrIo;

typedef struct ExrImage {
    int width, height; /* pixels: the display window */
    const float *rgba; /* width * height * 4, top row first */
    int x0, y0, w, h;  /* the data window written: its corner and size */
    int channels;      /* 4: R, G, B, A; 3: R, G, B */
    const float *aov;  /* width * height * aov_channels floats, or NULL */
    int aov_channels;
    const char *const *aov_names; /* their channels' names (32-bit float channels) */
} ExrImage;

/* ------------------------------------------------------------ callbacks */

static void keep_first_error(exr_const_context_t ctx, exr_result_t code, const char *msg)
{
    void *user = NULL;
    /* The context may be NULL when allocating it failed; nothing to keep. */
    if (!ctx || exr_get_user_data(ctx, &user) != EXR_ERR_SUCCESS || !user)
        return;
    ExrIo *io = user;
    if (io->first_error[0] == '\0')
        snprintf(io->first_error, sizeof io->first_error, "%s",
                 msg ? msg : exr_get_default_error_message(code));
}

static int64_t write_bytes(exr_const_context_t ctx, void *user, const void *buffer,
                           uint64_t n_bytes, uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    (void)ctx;
    (void)error_cb; /* our errno, kept in io, makes the better message */
    ExrIo *io = user;
    const uint8_t *bytes = buffer;
    uint64_t done = 0;
    while (done < n_bytes) {
        ssize_t n = pwrite(io->fd, bytes + done, n_bytes - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            if (io->sys_errno == 0)
                io->sys_errno = n < 0 ? errno : EIO;
            return -1;
        }
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

/* Like pread, but loops; a short count means the end of the file. */
static int64_t read_bytes(exr_const_context_t ctx, void *user, void *buffer, uint64_t n_bytes,
                          uint64_t offset, exr_stream_error_func_ptr_t error_cb)
{
    (void)ctx;
    (void)error_cb;
    ExrIo *io = user;
    uint8_t *bytes = buffer;
    uint64_t done = 0;
    while (done < n_bytes) {
        ssize_t n = pread(io->fd, bytes + done, n_bytes - done, (off_t)(offset + done));
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            if (io->sys_errno == 0)
                io->sys_errno = errno;
            return -1;
        }
        if (n == 0) {
            io->short_read = true;
            break;
        }
        done += (uint64_t)n;
    }
    return (int64_t)done;
}

/* The file size lets the library check chunk offsets against it. */
static int64_t query_size(exr_const_context_t ctx, void *user)
{
    (void)ctx;
    const ExrIo *io = user;
    struct stat st;
    return fstat(io->fd, &st) == 0 ? (int64_t)st.st_size : -1;
}

static exr_context_initializer_t make_initializer(ExrIo *io)
{
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = keep_first_error;
    init.user_data = io;
    init.read_fn = read_bytes;
    init.size_fn = query_size;
    init.write_fn = write_bytes;
    /* A damaged file is an error to report, not something to patch up. */
    init.flags = EXR_CONTEXT_FLAG_DISABLE_CHUNK_RECONSTRUCTION;
    return init;
}

/* Fills err with "PATH: doing: why" from what io saw, and returns the
 * RayesError for rv. Our errno and end-of-file notes explain I/O failures
 * better than the library can; for anything else its message is the one
 * (a short read may be the library probing, not the cause). */
static RayesError report(const ExrIo *io, exr_result_t rv, const char *path, const char *doing,
                         RayesError otherwise, char *err, size_t err_size)
{
    bool io_failure = rv == EXR_ERR_READ_IO || rv == EXR_ERR_WRITE_IO ||
                      rv == EXR_ERR_FILE_ACCESS || io->first_error[0] == '\0';
    if (io_failure && io->sys_errno != 0) {
        image_set_errno_error(err, err_size, io->sys_errno, "%s: %s", path, doing);
        return RAYES_ERROR_IO;
    }
    if (io_failure && io->short_read) {
        image_set_error(err, err_size, "%s: %s: the file is truncated", path, doing);
        return RAYES_ERROR_PARSE;
    }
    const char *why = io->first_error[0] ? io->first_error : exr_get_default_error_message(rv);
    image_set_error(err, err_size, "%s: %s: %s", path, doing, why);
    if (rv == EXR_ERR_OUT_OF_MEMORY)
        return RAYES_ERROR_OUT_OF_MEMORY;
    if (rv == EXR_ERR_FILE_ACCESS || rv == EXR_ERR_READ_IO || rv == EXR_ERR_WRITE_IO)
        return RAYES_ERROR_IO;
    return otherwise;
}

/* Our slot in an RGBA pixel for a channel name, or -1 to skip it. */
static int rgba_slot(const char *name)
{
    static const char *const names[4] = {"R", "G", "B", "A"};
    for (int i = 0; i < 4; i++)
        if (strcmp(name, names[i]) == 0)
            return i;
    return -1;
}

/* -------------------------------------------------------------- writing */

static exr_result_t define_part(exr_context_t ctx, const ExrImage *image)
{
    int part = 0;
    exr_result_t rv = exr_add_part(ctx, NULL, EXR_STORAGE_SCANLINE, &part);
    exr_attr_box2i_t display, data;
    display.min.x = 0, display.min.y = 0;
    display.max.x = image->width - 1, display.max.y = image->height - 1;
    data.min.x = image->x0, data.min.y = image->y0;
    data.max.x = image->x0 + image->w - 1, data.max.y = image->y0 + image->h - 1;
    exr_attr_v2f_t centre;
    centre.x = 0.0f, centre.y = 0.0f;
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_initialize_required_attr(ctx, part, &display, &data, 1.0f, &centre, 1.0f,
                                          EXR_LINEORDER_INCREASING_Y, EXR_COMPRESSION_ZIP);
    /* Perceptual treatment only matters to lossy codecs; say it right. */
    static const char *const names[4] = {"R", "G", "B", "A"};
    for (int i = 0; i < image->channels && rv == EXR_ERR_SUCCESS; i++)
        rv = exr_add_channel(ctx, part, names[i], EXR_PIXEL_HALF,
                             i == 3 ? EXR_PERCEPTUALLY_LINEAR : EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    for (int i = 0; i < image->aov_channels && rv == EXR_ERR_SUCCESS; i++)
        rv = exr_add_channel(ctx, part, image->aov_names[i], EXR_PIXEL_FLOAT,
                             EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_attr_set_string(ctx, part, "renderer", "rayes");
    return rv;
}

/* Points the encoder's channels (sorted by name) at the interleaved floats
 * of the chunk's first line y: RGBA's, or the AOVs'. */
static void bind_encode_channels(exr_encode_pipeline_t *encoder, const ExrImage *image, int y)
{
    size_t first = (size_t)y * (size_t)image->width + (size_t)image->x0;
    for (int c = 0; c < encoder->channel_count; c++) {
        exr_coding_channel_info_t *chan = &encoder->channels[c];
        int slot = rgba_slot(chan->channel_name), n = 4;
        const float *from = image->rgba + first * 4;
        for (int k = 0; slot < 0 && k < image->aov_channels; k++)
            if (strcmp(chan->channel_name, image->aov_names[k]) == 0) {
                slot = k, n = image->aov_channels;
                from = image->aov + first * (size_t)n;
            }
        chan->encode_from_ptr = (const uint8_t *)(from + (slot < 0 ? 0 : slot));
        chan->user_data_type = EXR_PIXEL_FLOAT;
        chan->user_bytes_per_element = (int16_t)sizeof(float);
        chan->user_pixel_stride = (int32_t)(n * sizeof(float));
        chan->user_line_stride = (int32_t)(n * sizeof(float)) * image->width;
    }
}

static exr_result_t write_chunks(exr_context_t ctx, const ExrImage *image)
{
    int32_t lines_per_chunk = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, 0, &lines_per_chunk);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    exr_encode_pipeline_t encoder = EXR_ENCODE_PIPELINE_INITIALIZER;
    bool initialized = false;
    for (int y = image->y0; y < image->y0 + image->h && rv == EXR_ERR_SUCCESS;
         y += lines_per_chunk) {
        exr_chunk_info_t cinfo;
        rv = exr_write_scanline_chunk_info(ctx, 0, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS)
            break;
        rv = initialized ? exr_encoding_update(ctx, 0, &cinfo, &encoder)
                         : exr_encoding_initialize(ctx, 0, &cinfo, &encoder);
        if (rv != EXR_ERR_SUCCESS)
            break;
        bind_encode_channels(&encoder, image, y);
        if (!initialized) {
            initialized = true;
            rv = exr_encoding_choose_default_routines(ctx, 0, &encoder);
        }
        if (rv == EXR_ERR_SUCCESS)
            rv = exr_encoding_run(ctx, 0, &encoder);
    }
    if (initialized)
        exr_encoding_destroy(ctx, &encoder);
    return rv;
}

/* ImageBodyWriter for image_write_via_temp; data is an ExrImage. */
static RayesError write_exr_body(FILE *file, const char *path, const void *data, char *err,
                                 size_t err_size)
{
    ExrIo io = {.fd = fileno(file)};
    exr_context_initializer_t init = make_initializer(&io);
    exr_context_t ctx = NULL;
    /* With our write_fn the library opens nothing: path is only a name. */
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv == EXR_ERR_SUCCESS)
        rv = define_part(ctx, data);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_write_header(ctx);
    if (rv == EXR_ERR_SUCCESS)
        rv = write_chunks(ctx, data);
    if (ctx) {
        /* exr_finish writes the chunk offset table, so it can fail too. */
        exr_result_t finished = exr_finish(&ctx);
        if (rv == EXR_ERR_SUCCESS)
            rv = finished;
    }
    if (rv != EXR_ERR_SUCCESS)
        return report(&io, rv, path, "cannot write EXR", RAYES_ERROR_IO, err, err_size);
    return RAYES_OK;
}

RayesError image_write_exr(const char *path, int width, int height, const float *rgba, char *err,
                        size_t err_size)
{
    const int all[4] = {0, 0, width, height};
    return image_write_exr_window(path, width, height, rgba, all, 0, err, err_size);
}

RayesError image_write_exr_window(const char *path, int width, int height, const float *rgba,
                                  const int window[4], int flags, char *err, size_t err_size)
{
    return image_write_exr_aov(path, width, height, rgba, window, flags, NULL, 0, NULL, err,
                               err_size);
}

RayesError image_write_exr_aov(const char *path, int width, int height, const float *rgba,
                               const int window[4], int flags, const float *aov, int aov_channels,
                               const char *const *aov_names, char *err, size_t err_size)
{
    for (int i = 0; i < aov_channels; i++) /* names EXR can hold, none of R, G, B, A twice */
        if (!aov || !aov_names || !aov_names[i] || !aov_names[i][0] ||
            rgba_slot(aov_names[i]) >= 0) {
            image_set_error(err, err_size, "%s: cannot write EXR: invalid AOV channel %d",
                            path ? path : "(null)", i);
            return RAYES_ERROR_INVALID_ARGUMENT;
        }
    if (!path || !rgba || width <= 0 || height <= 0 || width > MAX_SIDE || window[0] < 0 ||
        window[1] < 0 || window[2] <= 0 || window[3] <= 0 || window[0] + window[2] > width ||
        window[1] + window[3] > height) {
        image_set_error(err, err_size, "%s: cannot write EXR: invalid arguments (%d x %d pixels%s)",
                     path ? path : "(null)", width, height, rgba ? "" : ", no pixels");
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    ExrImage image = {width,     height,       rgba,      window[0],
                      window[1], window[2],    window[3], flags & IMAGE_NO_ALPHA ? 3 : 4,
                      aov,       aov_channels, aov_names};
    if ((flags & IMAGE_NO_COLOUR) && aov_channels > 0)
        image.channels = 0;
    return image_write_via_temp(path, write_exr_body, &image, err, err_size);
}

/* -------------------------------------------------------------- reading */

/* Where decoding writes: the image and the data window's origin. */
typedef struct ExrTarget {
    float *rgba;       /* width * height * 4 */
    int width, height; /* the data window's size */
    int x0, y0;        /* the data window's minimum corner */
    bool tiled;        /* tiles, else scanlines */
    int display[4];    /* the display window: minimum corner, width, height */
    int others;        /* channels other than R, G, B, A (AOVs) */
    /* Asked for: up to max_aov of those, not subsampled, read as floats into
     * aov (n_aov a pixel, in the file's order), their names in aov_names. */
    int max_aov, n_aov;
    char (*aov_names)[IMAGE_AOV_NAME];
    float *aov;
} ExrTarget;

/* Points the decoder's channels at the chunk's first pixel (offset first
 * in target's images): R, G, B, A into rgba, the AOVs asked for into aov;
 * other channels get NULL, which means skip. The strides are what
 * unpack_rgba follows; the type and size tell the library's routine
 * chooser that we convert, so it never reads straight into them. */
static void bind_decode_channels(exr_decode_pipeline_t *decoder, const ExrTarget *target,
                                 size_t first)
{
    for (int c = 0; c < decoder->channel_count; c++) {
        exr_coding_channel_info_t *chan = &decoder->channels[c];
        int slot = rgba_slot(chan->channel_name), n = 4;
        float *to = slot < 0 ? NULL : target->rgba + first * 4 + slot;
        for (int k = 0; slot < 0 && k < target->n_aov; k++)
            if (strcmp(chan->channel_name, target->aov_names[k]) == 0)
                n = target->n_aov, to = target->aov + first * (size_t)n + k;
        chan->decode_to_ptr = (uint8_t *)to;
        chan->user_data_type = EXR_PIXEL_FLOAT;
        chan->user_bytes_per_element = (int16_t)sizeof(float);
        chan->user_pixel_stride = (int32_t)(n * sizeof(float));
        chan->user_line_stride = (int32_t)(n * sizeof(float)) * target->width;
    }
}

static float half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, exponent = (h >> 10) & 0x1fu;
    uint32_t mantissa = h & 0x3ffu, bits;
    if (exponent == 0) { /* zero or subnormal: mantissa * 2^-24, exact in float */
        float f = ldexpf((float)mantissa, -24);
        return sign ? -f : f;
    }
    if (exponent == 31) /* infinity or NaN */
        bits = sign | 0x7f800000u | (mantissa << 13);
    else
        bits = sign | ((exponent + 112) << 23) | (mantissa << 13);
    float f;
    memcpy(&f, &bits, sizeof f);
    return f;
}

/* Converts n little-endian values of one channel's line to floats stride
 * apart. */
static void convert_line(float *dst, int stride, const uint8_t *src, int n, uint16_t data_type)
{
    for (int x = 0; x < n; x++, dst += stride) {
        if (data_type == EXR_PIXEL_HALF) {
            *dst = half_to_float((uint16_t)(src[2 * x] | src[2 * x + 1] << 8));
            continue;
        }
        const uint8_t *b = src + 4 * x;
        uint32_t bits =
            (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
        if (data_type == EXR_PIXEL_UINT) {
            *dst = (float)bits;
        } else {
            memcpy(dst, &bits, sizeof *dst);
        }
    }
}

/* The decoder's unpack_and_convert_fn: the decompressed chunk holds, for
 * each line, each channel's samples on that line (sorted by name), as
 * the file stores them. See the quirks above for why this is ours. */
static exr_result_t unpack_rgba(exr_decode_pipeline_t *decoder)
{
    const uint8_t *src = decoder->unpacked_buffer;
    const uint8_t *end = src ? src + decoder->chunk.unpacked_size : NULL;
    if (!src)
        return EXR_ERR_CORRUPT_CHUNK;
    for (int y = 0; y < decoder->chunk.height; y++) {
        int file_y = decoder->chunk.start_y + y;
        for (int c = 0; c < decoder->channel_count; c++) {
            const exr_coding_channel_info_t *chan = &decoder->channels[c];
            if (chan->height == 0 || (chan->y_samples > 1 && file_y % chan->y_samples != 0))
                continue;
            size_t n_bytes = (size_t)chan->width * (size_t)chan->bytes_per_element;
            if ((size_t)(end - src) < n_bytes)
                return EXR_ERR_CORRUPT_CHUNK;
            if (chan->decode_to_ptr) /* R, G, B, A and AOVs: never subsampled (checked) */
                convert_line((float *)(chan->decode_to_ptr + (size_t)y * chan->user_line_stride),
                             chan->user_pixel_stride / (int)sizeof(float), src, chan->width,
                             chan->data_type);
            src += n_bytes;
        }
    }
    return EXR_ERR_SUCCESS;
}

/* A decoding pipeline reused across the chunks of one image. */
typedef exr_result_t (*ExrStage)(exr_decode_pipeline_t *pipe);
typedef struct ExrDecoder {
    exr_decode_pipeline_t pipe; /* set up by the first chunk */
    bool initialized;           /* pipe holds buffers to destroy */
    ExrStage decompress;        /* the library's choice for compressed chunks */
} ExrDecoder;

/* Decodes one chunk whose top-left pixel is (x, y) in file coordinates. */
static exr_result_t decode_chunk(exr_const_context_t ctx, ExrDecoder *decoder,
                                 const exr_chunk_info_t *cinfo, int x, int y,
                                 const ExrTarget *target)
{
    int64_t col = (int64_t)x - target->x0, row = (int64_t)y - target->y0;
    /* Our unpacker trusts these sizes; check them against our buffer so a
     * damaged file cannot make it write outside. */
    if (col < 0 || row < 0 || cinfo->width <= 0 || cinfo->height <= 0 ||
        col + cinfo->width > target->width || row + cinfo->height > target->height)
        return EXR_ERR_CORRUPT_CHUNK;
    exr_decode_pipeline_t *pipe = &decoder->pipe;
    exr_result_t rv = decoder->initialized ? exr_decoding_update(ctx, 0, cinfo, pipe)
                                           : exr_decoding_initialize(ctx, 0, cinfo, pipe);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    bind_decode_channels(pipe, target, (size_t)row * target->width + (size_t)col);
    if (!decoder->initialized) {
        decoder->initialized = true;
        rv = exr_decoding_choose_default_routines(ctx, 0, pipe);
        if (rv != EXR_ERR_SUCCESS)
            return rv;
        decoder->decompress = pipe->decompress_fn;
    }
    /* A chunk as large as its pixels was stored raw, because compressing
     * did not pay; that is how the C++ library reads it. OpenEXRCore 3.1.5
     * runs its B44 decoder over such a chunk anyway, in place, which
     * scrambles B44 files whose channels are all float. */
    pipe->decompress_fn = cinfo->packed_size == cinfo->unpacked_size ? NULL : decoder->decompress;
    pipe->unpack_and_convert_fn = unpack_rgba;
    return exr_decoding_run(ctx, 0, pipe);
}

static exr_result_t read_scanlines(exr_const_context_t ctx, const ExrTarget *target)
{
    int32_t lines_per_chunk = 0;
    exr_result_t rv = exr_get_scanlines_per_chunk(ctx, 0, &lines_per_chunk);
    if (rv == EXR_ERR_SUCCESS && lines_per_chunk <= 0)
        rv = EXR_ERR_INVALID_ATTR;
    ExrDecoder decoder = {.pipe = EXR_DECODE_PIPELINE_INITIALIZER};
    int64_t end = (int64_t)target->y0 + target->height;
    for (int64_t y = target->y0; y < end && rv == EXR_ERR_SUCCESS; y += lines_per_chunk) {
        exr_chunk_info_t cinfo;
        rv = exr_read_scanline_chunk_info(ctx, 0, (int)y, &cinfo);
        if (rv == EXR_ERR_SUCCESS)
            rv = decode_chunk(ctx, &decoder, &cinfo, target->x0, cinfo.start_y, target);
    }
    if (decoder.initialized)
        exr_decoding_destroy(ctx, &decoder.pipe);
    return rv;
}

static exr_result_t read_tiles(exr_const_context_t ctx, const ExrTarget *target)
{
    int32_t tile_w = 0, tile_h = 0, level_w = 0, level_h = 0;
    exr_result_t rv = exr_get_tile_sizes(ctx, 0, 0, 0, &tile_w, &tile_h);
    if (rv == EXR_ERR_SUCCESS)
        rv = exr_get_level_sizes(ctx, 0, 0, 0, &level_w, &level_h);
    if (rv == EXR_ERR_SUCCESS &&
        (tile_w <= 0 || tile_h <= 0 || level_w != target->width || level_h != target->height))
        rv = EXR_ERR_INVALID_ATTR;
    ExrDecoder decoder = {.pipe = EXR_DECODE_PIPELINE_INITIALIZER};
    int n_x = rv == EXR_ERR_SUCCESS ? (int)(((int64_t)level_w + tile_w - 1) / tile_w) : 0;
    int n_y = rv == EXR_ERR_SUCCESS ? (int)(((int64_t)level_h + tile_h - 1) / tile_h) : 0;
    for (int ty = 0; ty < n_y && rv == EXR_ERR_SUCCESS; ty++) {
        for (int tx = 0; tx < n_x && rv == EXR_ERR_SUCCESS; tx++) {
            exr_chunk_info_t cinfo;
            /* Level 0 only: the full-resolution image of a mipmap. */
            rv = exr_read_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &cinfo);
            if (rv == EXR_ERR_SUCCESS)
                rv = decode_chunk(ctx, &decoder, &cinfo, target->x0 + tx * tile_w,
                                  target->y0 + ty * tile_h, target);
        }
    }
    if (decoder.initialized)
        exr_decoding_destroy(ctx, &decoder.pipe);
    return rv;
}

/* Checks what the header promises before any pixel is read: a flat part,
 * R, G and B present and not subsampled, a sane data window. Fills err and
 * returns nonzero when the file is not something we read. */
static RayesError check_header(exr_const_context_t ctx, const char *path, ExrTarget *target,
                               char *err, size_t err_size)
{
    exr_storage_t storage = EXR_STORAGE_LAST_TYPE;
    exr_attr_box2i_t dw;
    const exr_attr_chlist_t *channels = NULL;
    if (exr_get_storage(ctx, 0, &storage) != EXR_ERR_SUCCESS ||
        exr_get_data_window(ctx, 0, &dw) != EXR_ERR_SUCCESS ||
        exr_get_channels(ctx, 0, &channels) != EXR_ERR_SUCCESS || !channels) {
        image_set_error(err, err_size, "%s: cannot read EXR: incomplete header", path);
        return RAYES_ERROR_PARSE;
    }
    if (storage != EXR_STORAGE_SCANLINE && storage != EXR_STORAGE_TILED) {
        image_set_error(err, err_size, "%s: cannot read EXR: deep images are not supported", path);
        return RAYES_ERROR_PARSE;
    }
    int found = 0, others = 0, n_aov = 0;
    for (int i = 0; i < channels->num_channels; i++) {
        const exr_attr_chlist_entry_t *entry = &channels->entries[i];
        int slot = rgba_slot(entry->name.str);
        others += slot < 0;
        if (slot < 0 && n_aov < target->max_aov && entry->x_sampling == 1 &&
            entry->y_sampling == 1 && strlen(entry->name.str) < IMAGE_AOV_NAME)
            snprintf(target->aov_names[n_aov++], IMAGE_AOV_NAME, "%s", entry->name.str);
        if (slot < 0)
            continue;
        if (entry->x_sampling != 1 || entry->y_sampling != 1) {
            image_set_error(err, err_size, "%s: cannot read EXR: channel %s is subsampled", path,
                         entry->name.str);
            return RAYES_ERROR_PARSE;
        }
        found |= 1 << slot;
    }
    if ((found & 7) != 7) {
        image_set_error(err, err_size, "%s: cannot read EXR: no R, G and B channels", path);
        return RAYES_ERROR_PARSE;
    }
    int64_t w = (int64_t)dw.max.x - dw.min.x + 1, h = (int64_t)dw.max.y - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > MAX_SIDE || h > MAX_SIDE || w * h > MAX_PIXELS) {
        image_set_error(err, err_size, "%s: cannot read EXR: unsupported data window %lld x %lld",
                     path, (long long)w, (long long)h);
        return RAYES_ERROR_PARSE;
    }
    *target = (ExrTarget){NULL,
                          (int)w,
                          (int)h,
                          dw.min.x,
                          dw.min.y,
                          storage == EXR_STORAGE_TILED,
                          {dw.min.x, dw.min.y, (int)w, (int)h},
                          others,
                          target->max_aov,
                          n_aov,
                          target->aov_names,
                          NULL};
    exr_attr_box2i_t disp;
    if (exr_get_display_window(ctx, 0, &disp) == EXR_ERR_SUCCESS) {
        int64_t dw_ = (int64_t)disp.max.x - disp.min.x + 1, dh = (int64_t)disp.max.y - disp.min.y + 1;
        if (dw_ > 0 && dh > 0 && dw_ <= MAX_SIDE && dh <= MAX_SIDE && dw_ * dh <= MAX_PIXELS)
            memcpy(target->display, (int[4]){disp.min.x, disp.min.y, (int)dw_, (int)dh},
                   sizeof target->display);
    }
    return RAYES_OK;
}

/* Reads part 0 of an open context into a new image in *target. */
static RayesError read_part(exr_const_context_t ctx, const ExrIo *io, const char *path,
                            ExrTarget *target, char *err, size_t err_size)
{
    RayesError status = check_header(ctx, path, target, err, err_size);
    if (status != RAYES_OK)
        return status;
    size_t n_pixels = (size_t)target->width * (size_t)target->height;
    target->rgba = malloc(n_pixels * 4 * sizeof(float));
    target->aov = target->n_aov ? calloc(n_pixels * (size_t)target->n_aov, sizeof(float)) : NULL;
    if (!target->rgba || (target->n_aov && !target->aov)) {
        free(target->rgba), free(target->aov);
        target->rgba = NULL, target->aov = NULL;
        image_set_error(err, err_size, "%s: out of memory", path);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    /* Alpha defaults to 1; R, G, B are always overwritten. */
    for (size_t i = 0; i < n_pixels; i++) {
        float *p = target->rgba + 4 * i;
        p[0] = p[1] = p[2] = 0.0f;
        p[3] = 1.0f;
    }
    exr_result_t rv = target->tiled ? read_tiles(ctx, target) : read_scanlines(ctx, target);
    if (rv != EXR_ERR_SUCCESS) {
        free(target->rgba), free(target->aov);
        target->rgba = NULL, target->aov = NULL;
        return report(io, rv, path, "cannot read EXR pixels", RAYES_ERROR_PARSE, err, err_size);
    }
    return RAYES_OK;
}

static RayesError read_exr(const char *path, ExrTarget *out, char *err, size_t err_size);

RayesError image_read_exr(const char *path, int *width, int *height, float **rgba, char *err,
                          size_t err_size)
{
    if (!path || !width || !height || !rgba) {
        image_set_error(err, err_size, "%s: cannot read EXR: invalid arguments",
                        path ? path : "(null)");
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    ExrTarget t = {0};
    RayesError e = read_exr(path, &t, err, err_size);
    *rgba = t.rgba;
    *width = t.width;
    *height = t.height;
    return e;
}

RayesError image_read_exr_window(const char *path, int display[2], int window[4], float **rgba,
                                 char *err, size_t err_size)
{
    return image_read_exr_aov(path, display, window, rgba, NULL, NULL, NULL, 0, NULL, err,
                              err_size);
}

RayesError image_read_exr_aov(const char *path, int display[2], int window[4], float **rgba,
                              float **aov, int *n_aov, char (*names)[IMAGE_AOV_NAME], int max_aov,
                              int *others, char *err, size_t err_size)
{
    ExrTarget t = {.max_aov = aov && n_aov && names ? max_aov : 0, .aov_names = names};
    RayesError e = read_exr(path, &t, err, err_size);
    *rgba = t.rgba;
    if (aov)
        *aov = t.aov;
    if (n_aov)
        *n_aov = e == RAYES_OK ? t.n_aov : 0;
    if (others)
        *others = e == RAYES_OK ? t.others : 0;
    if (e == RAYES_OK) {
        display[0] = t.display[2], display[1] = t.display[3];
        window[0] = t.x0 - t.display[0], window[1] = t.y0 - t.display[1];
        window[2] = t.width, window[3] = t.height;
    }
    return e;
}

/* Part 0 of the file at path into a new image in *out (out->rgba NULL on
 * failure). */
static RayesError read_exr(const char *path, ExrTarget *out, char *err, size_t err_size)
{
    ExrIo io = {.fd = open(path, O_RDONLY | O_CLOEXEC)};
    if (io.fd < 0) {
        image_set_errno_error(err, err_size, errno, "%s: cannot open", path);
        return RAYES_ERROR_IO;
    }
    exr_context_initializer_t init = make_initializer(&io);
    exr_context_t ctx = NULL;
    exr_result_t rv = exr_start_read(&ctx, path, &init);
    RayesError status = RAYES_OK;
    ExrTarget target = {.max_aov = out->max_aov, .aov_names = out->aov_names};
    if (rv != EXR_ERR_SUCCESS)
        status = report(&io, rv, path, "not a readable EXR file", RAYES_ERROR_PARSE, err, err_size);
    else
        status = read_part(ctx, &io, path, &target, err, err_size);
    if (ctx)
        exr_finish(&ctx);
    close(io.fd);
    if (status == RAYES_OK)
        *out = target;
    return status;
}
