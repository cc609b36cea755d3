/*
 * tests/image/test_image.c — the EXR and PNG writers and readers of
 * image/image.h: round trips within the formats' precision, files of other
 * layouts (float, uint, tiled, no alpha, grey PNG) written here with the
 * libraries directly, dispatch by extension, and failures: a missing
 * directory, garbage and truncated files, a write that runs out of room
 * (RLIMIT_FSIZE), each with a one-line message naming the file, no
 * temporary file left behind and an existing target untouched; and
 * threads writing one target at once.
 *
 * Scratch files go under RAYES_TEST_TMP/io_image, a directory of our own
 * because other tests share RAYES_TEST_TMP and may run at the same time.
 */
#include <dirent.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <OpenEXR/openexr.h>
#include <png.h>

#include "image/image.h"
#include "test.h"

#ifndef RAYES_TEST_TMP
#error "RAYES_TEST_TMP must name a scratch directory"
#endif

#define SCRATCH_DIR RAYES_TEST_TMP "/io_image"

/* ------------------------------------------------------------- helpers */

static const char *scratch(char *buf, size_t n, const char *name)
{
    mkdir(SCRATCH_DIR, 0777); /* EEXIST is fine */
    snprintf(buf, n, "%s/%s", SCRATCH_DIR, name);
    return buf;
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

/* Temporary files of target left in its directory ("NAME.tmp-..."). */
static int count_leftovers(const char *dir, const char *name)
{
    char prefix[256];
    snprintf(prefix, sizeof prefix, "%s.tmp-", name);
    DIR *d = opendir(dir);
    if (!d)
        return 0;
    int n = 0;
    for (struct dirent *e; (e = readdir(d)) != NULL;)
        n += strncmp(e->d_name, prefix, strlen(prefix)) == 0;
    closedir(d);
    return n;
}

static unsigned char *slurp(const char *path, size_t *n_bytes)
{
    *n_bytes = 0;
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    unsigned char *bytes = NULL;
    size_t cap = 0, n;
    do {
        if (*n_bytes == cap) {
            cap = cap ? 2 * cap : 4096;
            bytes = realloc(bytes, cap);
        }
        n = fread(bytes + *n_bytes, 1, cap - *n_bytes, f);
        *n_bytes += n;
    } while (n > 0);
    fclose(f);
    return bytes;
}

static void spit(const char *path, const void *bytes, size_t n_bytes)
{
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (f) {
        CHECK(fwrite(bytes, 1, n_bytes, f) == n_bytes);
        fclose(f);
    }
}

/* A message that names the file and fits on one line. */
static int good_message(const char *err, const char *path)
{
    return strstr(err, path) != NULL && strchr(err, '\n') == NULL;
}

/* Deterministic noise in [-0.25, 1.75), which no codec compresses well. */
static float *noise_image(int width, int height, uint32_t seed)
{
    float *rgba = malloc((size_t)width * height * 4 * sizeof *rgba);
    for (size_t i = 0; i < (size_t)width * height * 4; i++) {
        seed = seed * 1664525u + 1013904223u;
        rgba[i] = (float)(seed >> 8) / (float)(1u << 24) * 2.0f - 0.25f;
    }
    return rgba;
}

/* Half keeps 11 significant bits; subnormals (below 2^-14) have a fixed
 * spacing of 2^-24, so rounding is off by at most half of either. */
static double half_tolerance(float v)
{
    double rel = fabs((double)v) * ldexp(1.0, -11);
    double abs_min = ldexp(1.0, -25);
    return rel > abs_min ? rel : abs_min;
}

static int srgb8(float linear)
{
    if (!(linear > 0.0f))
        return 0;
    if (linear >= 1.0f)
        return 255;
    double v = linear <= 0.0031308 ? 12.92 * linear : 1.055 * pow(linear, 1.0 / 2.4) - 0.055;
    return (int)(v * 255.0 + 0.5);
}

static float srgb_decode(int v8)
{
    double v = v8 / 255.0;
    return (float)(v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4));
}

/* ----------------------------------------------- EXR files of other kinds */

typedef struct TestExr {
    exr_pixel_type_t type; /* of every channel */
    int has_alpha;         /* A besides R, G, B */
    int has_extra;         /* an extra float channel "Z" to skip */
    int tile;              /* tile size, or 0 for scanlines */
    exr_compression_t compression;
    int width, height, x0, y0; /* data window */
} TestExr;

static void bind_test_channels(exr_encode_pipeline_t *enc, const float *first, int width)
{
    for (int c = 0; c < enc->channel_count; c++) {
        exr_coding_channel_info_t *ch = &enc->channels[c];
        const char *name = ch->channel_name;
        int slot = !strcmp(name, "G") ? 1 : !strcmp(name, "B") ? 2 : !strcmp(name, "A") ? 3 : 0;
        ch->encode_from_ptr = (const uint8_t *)(first + slot);
        ch->user_data_type = EXR_PIXEL_FLOAT;
        ch->user_bytes_per_element = 4;
        ch->user_pixel_stride = 16;
        ch->user_line_stride = 16 * width;
    }
}

/* Encodes one chunk with top-left pixel (x, y) relative to the window. */
static exr_result_t encode_test_chunk(exr_context_t ctx, exr_encode_pipeline_t *enc, int *init,
                                      const exr_chunk_info_t *cinfo, const float *rgba, int width,
                                      int x, int y)
{
    exr_result_t rv = *init ? exr_encoding_update(ctx, 0, cinfo, enc)
                            : exr_encoding_initialize(ctx, 0, cinfo, enc);
    if (rv != EXR_ERR_SUCCESS)
        return rv;
    bind_test_channels(enc, rgba + ((size_t)y * width + x) * 4, width);
    if (!*init) {
        *init = 1;
        rv = exr_encoding_choose_default_routines(ctx, 0, enc);
    }
    return rv == EXR_ERR_SUCCESS ? exr_encoding_run(ctx, 0, enc) : rv;
}

static exr_result_t write_test_pixels(exr_context_t ctx, const TestExr *t, const float *rgba)
{
    exr_encode_pipeline_t enc = EXR_ENCODE_PIPELINE_INITIALIZER;
    exr_result_t rv = EXR_ERR_SUCCESS;
    int init = 0;
    exr_chunk_info_t cinfo;
    if (t->tile) {
        for (int ty = 0; ty * t->tile < t->height && !rv; ty++)
            for (int tx = 0; tx * t->tile < t->width && !rv; tx++) {
                rv = exr_write_tile_chunk_info(ctx, 0, tx, ty, 0, 0, &cinfo);
                if (!rv)
                    rv = encode_test_chunk(ctx, &enc, &init, &cinfo, rgba, t->width, tx * t->tile,
                                           ty * t->tile);
            }
    } else {
        int32_t lines = 1;
        exr_get_scanlines_per_chunk(ctx, 0, &lines);
        for (int y = 0; y < t->height && !rv; y += lines) {
            rv = exr_write_scanline_chunk_info(ctx, 0, t->y0 + y, &cinfo);
            if (!rv)
                rv = encode_test_chunk(ctx, &enc, &init, &cinfo, rgba, t->width, 0, y);
        }
    }
    if (init)
        exr_encoding_destroy(ctx, &enc);
    return rv;
}

/* Writes rgba (the window's pixels, interleaved RGBA floats) with
 * OpenEXRCore directly, in the layout t describes. */
static int write_test_exr(const char *path, const TestExr *t, const float *rgba)
{
    exr_context_t ctx = NULL;
    int part = 0;
    exr_result_t rv = exr_start_write(&ctx, path, EXR_WRITE_FILE_DIRECTLY, NULL);
    if (!rv)
        rv = exr_add_part(ctx, "test", t->tile ? EXR_STORAGE_TILED : EXR_STORAGE_SCANLINE, &part);
    exr_attr_box2i_t dw;
    dw.min.x = t->x0;
    dw.min.y = t->y0;
    dw.max.x = t->x0 + t->width - 1;
    dw.max.y = t->y0 + t->height - 1;
    exr_attr_v2f_t center;
    center.x = center.y = 0.0f;
    if (!rv)
        rv = exr_initialize_required_attr(ctx, part, &dw, &dw, 1.0f, &center, 1.0f,
                                          EXR_LINEORDER_INCREASING_Y, t->compression);
    if (!rv && t->tile)
        rv = exr_set_tile_descriptor(ctx, part, (uint32_t)t->tile, (uint32_t)t->tile,
                                     EXR_TILE_ONE_LEVEL, EXR_TILE_ROUND_DOWN);
    const char *names[] = {"R", "G", "B", "A"};
    for (int i = 0; i < 3 + t->has_alpha && !rv; i++)
        rv = exr_add_channel(ctx, part, names[i], t->type, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (!rv && t->has_extra)
        rv = exr_add_channel(ctx, part, "Z", EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LINEAR, 1, 1);
    if (!rv)
        rv = exr_write_header(ctx);
    if (!rv)
        rv = write_test_pixels(ctx, t, rgba);
    if (ctx) {
        exr_result_t finished = exr_finish(&ctx);
        rv = rv ? rv : finished;
    }
    if (rv)
        fprintf(stderr, "write_test_exr(%s): %s\n", path, exr_get_error_code_as_string(rv));
    return rv == EXR_ERR_SUCCESS;
}

/* ---------------------------------------------------------------- tests */

static void test_exr_round_trip(void)
{
    enum { W = 7, H = 5 };
    static const float specials[] = {0.0f,  1.0f,  65504.0f, 0.5f,  1e-3f, 6.1035156e-5f,
                                     1e-5f, 3e-7f, 3.14159f, -2.5f, 0.18f, 1000.25f};
    float rgba[W * H * 4];
    for (int i = 0; i < W * H * 4; i++)
        rgba[i] = specials[i % (sizeof specials / sizeof specials[0])] * (i % 5 == 4 ? -1 : 1);
    char path[512], err[512] = "";
    scratch(path, sizeof path, "round_trip.exr");

    /* Writing over an existing file replaces it. */
    float zeros[W * H * 4] = {0};
    CHECK(image_write_exr(path, W, H, zeros, err, sizeof err) == RAYES_OK);
    CHECK(image_write_exr(path, W, H, rgba, err, sizeof err) == RAYES_OK);
    CHECK(count_leftovers(SCRATCH_DIR, "round_trip.exr") == 0);

    int w = 0, h = 0;
    float *back = NULL;
    CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(w == W && h == H && back != NULL);
    if (back && w == W && h == H)
        for (int i = 0; i < W * H * 4; i++)
            CHECK_NEAR(back[i], rgba[i], half_tolerance(rgba[i]));
    if (back) {
        CHECK(back[0] == 0.0f); /* 0 and 1 and max half are exact */
        CHECK(back[1] == 1.0f);
        CHECK(back[2] == 65504.0f);
    }
    free(back);
}

/* The header says what image_write_exr promises: half RGBA, ZIP, scanlines,
 * renderer = "rayes". */
static void test_exr_header(void)
{
    char path[512], err[512] = "";
    scratch(path, sizeof path, "header.exr");
    /* Noise does not compress, so chunks are stored raw: read them back too. */
    float *rgba = noise_image(19, 37, 7);
    CHECK(image_write_exr(path, 19, 37, rgba, err, sizeof err) == RAYES_OK);
    int w = 0, h = 0;
    float *back = NULL;
    CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    int mismatches = 0;
    for (int i = 0; back && w == 19 && h == 37 && i < 19 * 37 * 4; i++)
        mismatches += !(fabs(back[i] - rgba[i]) <= half_tolerance(rgba[i]));
    CHECK(back != NULL && mismatches == 0);
    free(back);
    free(rgba);

    exr_context_t ctx = NULL;
    CHECK(exr_start_read(&ctx, path, NULL) == EXR_ERR_SUCCESS);
    if (!ctx)
        return;
    exr_storage_t storage;
    exr_compression_t compression;
    const exr_attr_chlist_t *channels = NULL;
    const char *renderer = NULL;
    int32_t n_renderer = 0;
    exr_attr_box2i_t dw;
    CHECK(exr_get_storage(ctx, 0, &storage) == EXR_ERR_SUCCESS && storage == EXR_STORAGE_SCANLINE);
    CHECK(exr_get_compression(ctx, 0, &compression) == EXR_ERR_SUCCESS);
    CHECK(compression == EXR_COMPRESSION_ZIP);
    CHECK(exr_get_data_window(ctx, 0, &dw) == EXR_ERR_SUCCESS);
    CHECK(dw.min.x == 0 && dw.min.y == 0 && dw.max.x == 18 && dw.max.y == 36);
    CHECK(exr_get_channels(ctx, 0, &channels) == EXR_ERR_SUCCESS && channels);
    if (channels) {
        CHECK(channels->num_channels == 4);
        for (int i = 0; i < channels->num_channels; i++)
            CHECK(channels->entries[i].pixel_type == EXR_PIXEL_HALF);
    }
    CHECK(exr_attr_get_string(ctx, 0, "renderer", &n_renderer, &renderer) == EXR_ERR_SUCCESS);
    CHECK(renderer && n_renderer == 5 && strncmp(renderer, "rayes", 5) == 0);
    exr_finish(&ctx);
}

/* Float, uint and half files, scanline and tiled, with and without alpha,
 * with an offset data window and a channel to skip. */
static void test_exr_reads_other_layouts(void)
{
    static const TestExr layouts[] = {
        {EXR_PIXEL_FLOAT, 0, 0, 0, EXR_COMPRESSION_NONE, 13, 9, 3, -2},
        {EXR_PIXEL_UINT, 1, 0, 4, EXR_COMPRESSION_ZIP, 10, 7, 0, 0},
        {EXR_PIXEL_HALF, 0, 1, 5, EXR_COMPRESSION_PIZ, 9, 11, -4, 6},
        {EXR_PIXEL_HALF, 1, 1, 0, EXR_COMPRESSION_RLE, 40, 3, 0, 0},
        {EXR_PIXEL_FLOAT, 1, 0, 16, EXR_COMPRESSION_ZIPS, 33, 17, 1, 1},
    };
    for (size_t k = 0; k < sizeof layouts / sizeof layouts[0]; k++) {
        const TestExr *t = &layouts[k];
        size_t n = (size_t)t->width * t->height * 4;
        float *rgba = malloc(n * sizeof *rgba);
        /* Small integers and eighths: exact in uint (integers), half, float. */
        for (size_t i = 0; i < n; i++)
            rgba[i] = t->type == EXR_PIXEL_UINT ? (float)(i % 251) : (float)(i % 97) / 8.0f;
        char name[64], path[512], err[512] = "";
        snprintf(name, sizeof name, "layout%zu.exr", k);
        scratch(path, sizeof path, name);
        CHECK(write_test_exr(path, t, rgba));
        int w = 0, h = 0;
        float *back = NULL;
        CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
        if (err[0])
            fprintf(stderr, "layout %zu: %s\n", k, err);
        CHECK(w == t->width && h == t->height);
        int mismatches = 0;
        for (size_t i = 0; back && w == t->width && h == t->height && i < n; i++) {
            float want = (i % 4 == 3 && !t->has_alpha) ? 1.0f : rgba[i];
            mismatches += back[i] != want;
        }
        CHECK(back != NULL && mismatches == 0);
        free(back);
        free(rgba);
    }
}

static void test_png_round_trip(void)
{
    enum { W = 37, H = 11 };
    float *rgba = noise_image(W, H, 42);
    /* Edge values: 0, 1, above 1, below 0, NaN, the linear toe. */
    static const float edges[] = {0.0f, 1.0f, 7.0f, -1.0f, NAN, 0.0031308f, 0.002f, 0.5f};
    for (int i = 0; i < 8; i++)
        rgba[i] = edges[i];
    char path[512], err[512] = "";
    scratch(path, sizeof path, "round_trip.png");
    CHECK(image_write_png(path, W, H, rgba, err, sizeof err) == RAYES_OK);
    CHECK(count_leftovers(SCRATCH_DIR, "round_trip.png") == 0);
    int w = 0, h = 0;
    float *back = NULL;
    CHECK(image_read_png(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(w == W && h == H && back != NULL);
    int worst = 0;
    for (int i = 0; back && w == W && h == H && i < W * H * 4; i++) {
        /* Compare in the file's space: re-encoding must give the same code.
         * The file's colour is straight: the premultiplied colour over
         * alpha (alpha 0 or less: black). */
        float a = rgba[i - i % 4 + 3];
        float straight = !(a > 0.0f) ? 0.0f : a < 1.0f ? rgba[i] / a : rgba[i];
        int want =
            i % 4 == 3 ? (int)(fminf(fmaxf(rgba[i], 0.0f), 1.0f) * 255.0f + 0.5f) : srgb8(straight);
        int got = i % 4 == 3 ? (int)(back[i] * 255.0f + 0.5f) : srgb8(back[i]);
        int diff = abs(want - got);
        worst = diff > worst ? diff : worst;
    }
    CHECK(worst <= 1);
    if (back) {
        CHECK(back[0] == 0.0f && back[1] == 0.0f && back[2] == 0.0f && back[3] == 0.0f);
        CHECK(back[4] == 0.0f); /* NaN is stored as 0 */
    }
    /* A white surface covering half a pixel over nothing (premultiplied
     * 0.5, alpha 0.5) is white at alpha 0.5 in the file: stored as 0.5 it
     * showed 0.25 over black in every viewer. */
    const float half[4] = {0.5f, 0.5f, 0.5f, 0.5f};
    float *one = NULL;
    CHECK(image_write_png(path, 1, 1, half, err, sizeof err) == RAYES_OK);
    CHECK(image_read_png(path, &w, &h, &one, err, sizeof err) == RAYES_OK);
    CHECK(one && one[0] == 1.0f && one[2] == 1.0f && fabsf(one[3] - 0.5f) < 0.003f);
    free(one);
    free(back);
    free(rgba);

    /* The file says it is sRGB. */
    FILE *f = fopen(path, "rb");
    png_image image = {.version = PNG_IMAGE_VERSION};
    CHECK(f && png_image_begin_read_from_stdio(&image, f));
    CHECK((image.flags & PNG_IMAGE_FLAG_COLORSPACE_NOT_sRGB) == 0);
    png_image_free(&image);
    if (f)
        fclose(f);
}

/* A grey and a grey-alpha PNG come back as RGBA, grey decoded from sRGB. */
static void test_png_reads_grey(void)
{
    static const png_byte grey[6] = {0, 64, 128, 255, 1, 200};
    static const png_byte grey_alpha[6 * 2] = {0, 255, 64, 0, 128, 128, 255, 7, 1, 9, 200, 255};
    for (int with_alpha = 0; with_alpha < 2; with_alpha++) {
        char path[512], err[512] = "";
        scratch(path, sizeof path, with_alpha ? "grey_alpha.png" : "grey.png");
        png_image image = {.version = PNG_IMAGE_VERSION, .width = 3, .height = 2};
        image.format = with_alpha ? PNG_FORMAT_GA : PNG_FORMAT_GRAY;
        CHECK(png_image_write_to_file(&image, path, 0, with_alpha ? grey_alpha : grey, 0, NULL));
        int w = 0, h = 0;
        float *back = NULL;
        CHECK(image_read_png(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
        CHECK(w == 3 && h == 2 && back != NULL);
        for (int i = 0; back && w == 3 && h == 2 && i < 6; i++) {
            int g = with_alpha ? grey_alpha[2 * i] : grey[i];
            float a = with_alpha ? grey_alpha[2 * i + 1] / 255.0f : 1.0f;
            for (int c = 0; c < 3; c++)
                CHECK_NEAR(back[4 * i + c], srgb_decode(g), 1e-6);
            CHECK_NEAR(back[4 * i + 3], a, 1e-6);
        }
        free(back);
    }
}

static void test_format_dispatch(void)
{
    CHECK(image_format_from_path("a.exr") == IMAGE_FORMAT_EXR);
    CHECK(image_format_from_path("dir/B.EXR") == IMAGE_FORMAT_EXR);
    CHECK(image_format_from_path("x.PnG") == IMAGE_FORMAT_PNG);
    CHECK(image_format_from_path("/a.b/c.png") == IMAGE_FORMAT_PNG);
    CHECK(image_format_from_path("c.png.bak") == IMAGE_FORMAT_UNKNOWN);
    CHECK(image_format_from_path("dir.exr/file") == IMAGE_FORMAT_UNKNOWN);
    CHECK(image_format_from_path("noext") == IMAGE_FORMAT_UNKNOWN);
    CHECK(image_format_from_path(".png") == IMAGE_FORMAT_UNKNOWN);
    CHECK(image_format_from_path("") == IMAGE_FORMAT_UNKNOWN);
    CHECK(image_format_from_path(NULL) == IMAGE_FORMAT_UNKNOWN);

    float rgba[2 * 2 * 4] = {0.25f, 0.5f, 1.0f, 1.0f, 0.0f, 0.0f, 0.0f, 0.5f};
    char path[512], err[512] = "";
    int w, h;
    float *back = NULL;
    CHECK(image_write(scratch(path, sizeof path, "dispatch.EXR"), 2, 2, rgba, err, sizeof err) ==
          RAYES_OK);
    CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(back && back[1] == 0.5f);
    free(back);
    CHECK(image_write(scratch(path, sizeof path, "dispatch.png"), 2, 2, rgba, err, sizeof err) ==
          RAYES_OK);
    CHECK(image_read_png(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(back && w == 2 && h == 2);
    free(back);

    CHECK(image_write(scratch(path, sizeof path, "dispatch.tiff"), 2, 2, rgba, err,
                         sizeof err) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(good_message(err, path));
    CHECK(!file_exists(path));
}

static void test_bad_arguments(void)
{
    float rgba[4] = {0};
    char path[512], err[512] = "";
    scratch(path, sizeof path, "bad_arguments.exr");
    CHECK(image_write_exr(path, 0, 1, rgba, err, sizeof err) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(good_message(err, path));
    CHECK(image_write_exr(path, 1, -3, rgba, err, sizeof err) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(image_write_png(path, 1, 1, NULL, err, sizeof err) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(image_write_exr(NULL, 1, 1, rgba, err, sizeof err) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(!file_exists(path));
    CHECK(count_leftovers(SCRATCH_DIR, "bad_arguments.exr") == 0);
    /* No room for a message is allowed. */
    CHECK(image_write_png(path, 0, 0, rgba, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
}

static void test_missing_directory(void)
{
    float rgba[4] = {1, 1, 1, 1};
    char dir[400], path[512], err[1024];
    scratch(dir, sizeof dir, "no-such-dir");
    snprintf(path, sizeof path, "%s/sub/out", dir);
    const char *exts[] = {".exr", ".png"};
    for (int i = 0; i < 2; i++) {
        char file[600];
        snprintf(file, sizeof file, "%s%s", path, exts[i]);
        err[0] = '\0';
        RayesError rv = image_write(file, 1, 1, rgba, err, sizeof err);
        CHECK(rv == RAYES_ERROR_IO);
        CHECK(good_message(err, file));
        CHECK(strstr(err, "does not exist") != NULL);
        CHECK(!file_exists(dir));
    }
    CHECK(count_leftovers(SCRATCH_DIR, "no-such-dir") == 0);
}

/* Garbage, truncated and missing files fail with a message, no crash. */
static void check_read_fails(const char *path, int exr)
{
    char err[512] = "";
    int w = -1, h = -1;
    float sentinel = 0.0f, *rgba = &sentinel; /* must be replaced by NULL */
    RayesError rv = exr ? image_read_exr(path, &w, &h, &rgba, err, sizeof err)
                        : image_read_png(path, &w, &h, &rgba, err, sizeof err);
    CHECK(rv != RAYES_OK);
    CHECK(rgba == NULL && w == 0 && h == 0);
    CHECK(good_message(err, path));
    if (!good_message(err, path))
        fprintf(stderr, "  message: \"%s\"\n", err);
}

static void test_read_bad_files(void)
{
    char path[512];
    static const char garbage[] = "this is not an image, just some text\n\x76\x2f\x31\x01 trailing";
    for (int exr = 0; exr < 2; exr++) {
        const char *ext = exr ? "exr" : "png";
        char name[64];
        snprintf(name, sizeof name, "garbage.%s", ext);
        spit(scratch(path, sizeof path, name), garbage, sizeof garbage);
        check_read_fails(path, exr);
        snprintf(name, sizeof name, "empty.%s", ext);
        spit(scratch(path, sizeof path, name), "", 0);
        check_read_fails(path, exr);
        snprintf(name, sizeof name, "missing.%s", ext);
        check_read_fails(scratch(path, sizeof path, name), exr);

        /* A good file cut short: in the header, and in the pixels. */
        char good[512], err[512] = "";
        snprintf(name, sizeof name, "good.%s", ext);
        scratch(good, sizeof good, name);
        float *rgba = noise_image(64, 48, 3);
        CHECK(image_write(good, 64, 48, rgba, err, sizeof err) == RAYES_OK);
        free(rgba);
        size_t n = 0;
        unsigned char *bytes = slurp(good, &n);
        CHECK(bytes && n > 1000);
        size_t cuts[] = {8, 40, n / 2, n - 5};
        for (size_t i = 0; bytes && i < sizeof cuts / sizeof cuts[0]; i++) {
            snprintf(name, sizeof name, "truncated%zu.%s", i, ext);
            spit(scratch(path, sizeof path, name), bytes, cuts[i]);
            check_read_fails(path, exr);
        }
        /* The wrong reader for the format. */
        check_read_fails(good, !exr);
        free(bytes);
    }
    /* No room for a message is allowed. */
    int w, h;
    float *rgba;
    CHECK(image_read_exr(path, &w, &h, &rgba, NULL, 0) != RAYES_OK);
}

/* A write that fails half-way (the file size limit stands in for a full
 * disk) leaves the old target as it was and no temporary file. */
static void test_failed_write_keeps_target(void)
{
    const char *names[] = {"keep.exr", "keep.png"};
    for (int i = 0; i < 2; i++) {
        char path[512], err[512] = "";
        scratch(path, sizeof path, names[i]);
        float small[4 * 4 * 4] = {0.5f};
        CHECK(image_write(path, 4, 4, small, err, sizeof err) == RAYES_OK);
        size_t n_before = 0, n_after = 0;
        unsigned char *before = slurp(path, &n_before);

        float *big = noise_image(128, 128, 9);
        struct rlimit old_limit, limit;
        getrlimit(RLIMIT_FSIZE, &old_limit);
        limit = old_limit;
        limit.rlim_cur = 2048;
        void (*old_handler)(int) = signal(SIGXFSZ, SIG_IGN);
        CHECK(setrlimit(RLIMIT_FSIZE, &limit) == 0);
        RayesError rv = image_write(path, 128, 128, big, err, sizeof err);
        setrlimit(RLIMIT_FSIZE, &old_limit);
        signal(SIGXFSZ, old_handler);
        free(big);

        CHECK(rv == RAYES_ERROR_IO);
        CHECK(good_message(err, path));
        unsigned char *after = slurp(path, &n_after);
        CHECK(before && after && n_before == n_after && memcmp(before, after, n_before) == 0);
        CHECK(count_leftovers(SCRATCH_DIR, names[i]) == 0);
        free(before);
        free(after);
    }
}

/* Threads writing the same target at once: every write succeeds, and the
 * file read afterwards is one whole image, not a mix. */
typedef struct Writer {
    const char *path; /* shared target */
    float value;      /* this thread's constant colour */
    int n_failures;   /* writes that did not return RAYES_OK */
} Writer;

static void *write_repeatedly(void *arg)
{
    Writer *writer = arg;
    float rgba[16 * 16 * 4];
    for (int i = 0; i < 16 * 16 * 4; i++)
        rgba[i] = i % 4 == 3 ? 1.0f : writer->value;
    for (int k = 0; k < 8; k++) {
        char err[512];
        writer->n_failures += image_write(writer->path, 16, 16, rgba, err, sizeof err) != 0;
    }
    return NULL;
}

static void test_concurrent_writes(void)
{
    const char *names[] = {"shared.exr", "shared.png"};
    for (int f = 0; f < 2; f++) {
        char path[512], err[512] = "";
        scratch(path, sizeof path, names[f]);
        enum { N_THREADS = 4 };
        pthread_t threads[N_THREADS];
        Writer writers[N_THREADS];
        for (int t = 0; t < N_THREADS; t++) {
            writers[t] = (Writer){path, 0.25f * (float)(t + 1), 0};
            CHECK(pthread_create(&threads[t], NULL, write_repeatedly, &writers[t]) == 0);
        }
        for (int t = 0; t < N_THREADS; t++) {
            pthread_join(threads[t], NULL);
            CHECK(writers[t].n_failures == 0);
        }
        int w = 0, h = 0;
        float *back = NULL;
        RayesError rv = f == 0 ? image_read_exr(path, &w, &h, &back, err, sizeof err)
                               : image_read_png(path, &w, &h, &back, err, sizeof err);
        CHECK(rv == RAYES_OK && w == 16 && h == 16);
        int uniform = back != NULL;
        for (int i = 0; back && i < 16 * 16 * 4; i++)
            uniform &= back[i] == back[i % 4];
        CHECK(uniform);
        CHECK(count_leftovers(SCRATCH_DIR, names[f]) == 0);
        free(back);
    }
}

/* RenderMan's 8-bit files: values quantized as they are, no sRGB chunk
 * (read back, the bytes pass through the sRGB decoding every PNG gets). */
static void test_png_linear_curve(void)
{
    static const float rgba[2 * 4] = {0.5f, 0.25f, 1.5f, 1.0f, -1.0f, 0.0031308f, 1.0f, 0.5f};
    char path[512], err[512] = "";
    scratch(path, sizeof path, "linear.png");
    CHECK(image_write_png_curve(path, 2, 1, rgba, 1, err, sizeof err) == RAYES_OK);
    FILE *f = fopen(path, "rb");
    unsigned char bytes[4096];
    size_t n = f ? fread(bytes, 1, sizeof bytes, f) : 0;
    if (f)
        fclose(f);
    int srgb_chunk = 0;
    for (size_t i = 0; i + 4 <= n; i++)
        srgb_chunk |= memcmp(bytes + i, "sRGB", 4) == 0 || memcmp(bytes + i, "gAMA", 4) == 0;
    CHECK(n > 0 && !srgb_chunk);
    int w = 0, h = 0;
    float *back = NULL;
    CHECK(image_read_png(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    /* 0.5 was stored as 128, which the reader takes for sRGB: 0.2158 */
    CHECK(back && fabsf(back[0] - 0.21586f) < 1e-3f && back[2] == 1.0f && back[4] == 0.0f);
    CHECK(back && fabsf(back[7] - 128.0f / 255.0f) < 1e-6f); /* alpha linear as always */
    free(back);
    CHECK(image_write_png_curve(path, 2, 1, rgba, 0, err, sizeof err) == RAYES_OK);
    CHECK(image_read_png(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(back && fabsf(back[0] - 0.5f) < 3e-3f); /* the sRGB curve both ways */
    free(back);
}

/* RenderMan's display mode "rgb": R, G, B only, in PNG (colour type 2 in
 * the header) and EXR; read back, alpha is 1 and the colours are kept. */
static void test_no_alpha(void)
{
    static const float rgba[2 * 4] = {0.5f, 0.25f, 1.0f, 0.25f, 0.0f, 0.0f, 0.0f, 0.0f};
    char path[512], err[512] = "";
    scratch(path, sizeof path, "rgb.png");
    CHECK(image_write_png_curve(path, 2, 1, rgba, IMAGE_LINEAR | IMAGE_NO_ALPHA, err, sizeof err) ==
          RAYES_OK);
    FILE *f = fopen(path, "rb");
    unsigned char head[26] = {0};
    CHECK(f && fread(head, 1, sizeof head, f) == sizeof head);
    if (f)
        fclose(f);
    CHECK(memcmp(head + 12, "IHDR", 4) == 0 && head[25] == 2); /* RGB, 8 bits */
    int w = 0, h = 0;
    float *back = NULL;
    CHECK(image_read_png(path, &w, &h, &back, err, sizeof err) == RAYES_OK && w == 2 && h == 1);
    CHECK(back && back[3] == 1.0f && back[7] == 1.0f && back[2] == 1.0f && back[4] == 0.0f);
    free(back);
    scratch(path, sizeof path, "rgb.exr");
    const int all[4] = {0, 0, 2, 1};
    CHECK(image_write_exr_window(path, 2, 1, rgba, all, IMAGE_NO_ALPHA, err, sizeof err) ==
          RAYES_OK);
    back = NULL;
    CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(back && back[0] == 0.5f && back[1] == 0.25f && back[3] == 1.0f && back[7] == 1.0f);
    free(back);
}

TEST_MAIN(TEST(test_exr_round_trip), TEST(test_exr_header), TEST(test_exr_reads_other_layouts),
          TEST(test_png_round_trip), TEST(test_png_linear_curve), TEST(test_no_alpha),
          TEST(test_png_reads_grey), TEST(test_format_dispatch), TEST(test_bad_arguments),
          TEST(test_missing_directory), TEST(test_read_bad_files),
          TEST(test_failed_write_keeps_target), TEST(test_concurrent_writes))
