/*
 * Image textures (shade/texture, through OpenImageIO): the MIP levels of a
 * power-of-two texture keep its mean; a constant texture is that constant
 * at any footprint; lookups wrap periodically and interpolate across the
 * seam; texels come back exactly at their centres; TGA and Radiance HDR
 * files are read (8-bit ones decoded from sRGB), and maketx's .tx files
 * give what their source gives; names resolve on the search path; a
 * missing file returns -1 with one warning; results are the same bytes
 * whatever the cache budget; the statistics count what happened. Test
 * images are written at test time.
 */
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "image/image.h"
#include "shade/texture.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/texture_test"

/* A deterministic pseudo-random image of values k / 64 (exact in half). */
static float *random_image(int w, int h, uint32_t seed)
{
    float *rgba = malloc((size_t)w * h * 4 * sizeof *rgba);
    uint32_t x = seed * 2654435761u + 1u;
    for (size_t i = 0; i < (size_t)w * h * 4; i++) {
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        rgba[i] = (float)(x % 65u) / 64.0f;
    }
    return rgba;
}

static void write_exr(const char *name, int w, int h, const float *rgba)
{
    char path[512], err[300];
    mkdir(TMP, 0755);
    snprintf(path, sizeof path, "%s/%s", TMP, name);
    CHECK(image_write_exr(path, w, h, rgba, err, sizeof err) == RAYES_OK);
}

static void image_mean(const float *rgba, int w, int h, double mean[4])
{
    for (int c = 0; c < 4; c++) {
        mean[c] = 0.0;
        for (size_t i = 0; i < (size_t)w * h; i++)
            mean[c] += rgba[4 * i + c];
        mean[c] /= (double)w * h;
    }
}

/* Averages lookups at the centres of level l's texels, filtered exactly at
 * that level (footprint 2^l texels of level 0). */
static void level_mean(TextureSystem *ts, const char *name, int w, int h, int l, double mean[4])
{
    int lw = w >> l > 0 ? w >> l : 1, lh = h >> l > 0 ? h >> l : 1;
    float ds = (float)(1 << l) / (float)w, dt = (float)(1 << l) / (float)h;
    for (int c = 0; c < 4; c++)
        mean[c] = 0.0;
    for (int y = 0; y < lh; y++)
        for (int x = 0; x < lw; x++) {
            float s = ((float)x + 0.5f) / (float)lw, t = ((float)y + 0.5f) / (float)lh;
            float rgb[1][3], a;
            CHECK(texture_lookup(ts, name, 1, &s, &t, &ds, &dt, rgb, &a) == 0);
            for (int c = 0; c < 3; c++)
                mean[c] += rgb[0][c];
            mean[3] += a;
        }
    for (int c = 0; c < 4; c++)
        mean[c] /= (double)lw * lh;
}

static void check_pyramid_means(int w, int h)
{
    char name[64];
    snprintf(name, sizeof name, "random_%dx%d.exr", w, h);
    float *img = random_image(w, h, (uint32_t)(w * 131 + h));
    write_exr(name, w, h, img);
    double want[4], got[4];
    image_mean(img, w, h, want);
    TextureSystem *ts = texture_system_new(TMP, 64u << 20, 1.0f);
    int levels = 1;
    while ((w >> levels) > 0 || (h >> levels) > 0)
        levels++;
    for (int l = 0; l < levels; l++) {
        level_mean(ts, name, w, h, l, got);
        for (int c = 0; c < 4; c++) /* OpenImageIO keeps a half file's levels in half */
            CHECK_NEAR(got[c], want[c], 5e-4);
    }
    /* A footprint as large as a square texture reads the 1 x 1 level: the
     * mean. */
    float s = 0.3f, t = 0.7f, ds = 1.0f, dt = 1.0f, rgb[1][3];
    CHECK(texture_lookup(ts, name, 1, &s, &t, &ds, &dt, rgb, NULL) == 0);
    for (int c = 0; w == h && c < 3; c++)
        CHECK_NEAR(rgb[0][c], want[c], 5e-4);
    texture_system_free(ts);
    free(img);
}

/* OpenImageIO's automatic MIP levels of other sizes are resampled, not
 * box averages: maketx makes .tx files for those. */
static void test_pyramid_keeps_the_mean(void)
{
    check_pyramid_means(64, 64);
    check_pyramid_means(16, 16);
    check_pyramid_means(1, 1);
}

static void test_constant_at_any_footprint(void)
{
    int w = 24, h = 10;
    float *img = malloc((size_t)w * h * 4 * sizeof *img);
    for (int i = 0; i < w * h; i++) {
        img[4 * i + 0] = 0.25f;
        img[4 * i + 1] = 0.5f;
        img[4 * i + 2] = 0.75f;
        img[4 * i + 3] = 1.0f;
    }
    write_exr("constant.exr", w, h, img);
    TextureSystem *ts = texture_system_new(TMP, 64u << 20, 1.0f);
    enum { N = 200 };
    float s[N], t[N], ds[N], dt[N], rgb[N][3], a[N];
    for (int i = 0; i < N; i++) {
        s[i] = -3.0f + 0.0713f * (float)i;
        t[i] = 5.0f - 0.0391f * (float)i;
        ds[i] = powf(2.0f, (float)(i % 20) - 14.0f);  /* 2^-14 .. 2^5 */
        dt[i] = powf(2.0f, (float)((i * 7) % 20) - 14.0f); /* anisotropic too */
    }
    CHECK(texture_lookup(ts, "constant.exr", N, s, t, ds, dt, rgb, a) == 0);
    for (int i = 0; i < N; i++) {
        CHECK_NEAR(rgb[i][0], 0.25, 1e-6);
        CHECK_NEAR(rgb[i][1], 0.5, 1e-6);
        CHECK_NEAR(rgb[i][2], 0.75, 1e-6);
        CHECK_NEAR(a[i], 1.0, 1e-6);
    }
    texture_system_free(ts);
    free(img);
}

static void test_texel_centres_and_wrap(void)
{
    int w = 6, h = 3;
    float *img = random_image(w, h, 7);
    write_exr("wrap.exr", w, h, img);
    TextureSystem *ts = texture_system_new(TMP, 64u << 20, 1.0f);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int k = -2; k <= 2; k++) { /* periods in s and t */
                float s = ((float)x + 0.5f) / (float)w + (float)k;
                float t = ((float)y + 0.5f) / (float)h - (float)k;
                float rgb[1][3], a;
                CHECK(texture_lookup(ts, "wrap.exr", 1, &s, &t, NULL, NULL, rgb, &a) == 0);
                for (int c = 0; c < 3; c++)
                    CHECK_NEAR(rgb[0][c], img[4 * (y * w + x) + c], 1e-6);
                CHECK_NEAR(a, img[4 * (y * w + x) + 3], 1e-6);
            }
    /* On the seam s = 0 the first and last columns blend half and half. */
    float s = 0.0f, t = 0.5f / (float)h, rgb[1][3];
    CHECK(texture_lookup(ts, "wrap.exr", 1, &s, &t, NULL, NULL, rgb, NULL) == 0);
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(rgb[0][c], 0.5f * (img[c] + img[4 * (w - 1) + c]), 1e-6);
    /* pbrt's other wraps: outside [0, 1] black (alpha 0) or the edge's
     * texels; inside, the same texels as periodic */
    for (int k = 0; k < 3; k++) {
        float ss[3] = {-0.4f, 1.7f, (0.5f + 2.0f) / (float)w}, tt = (0.5f + 1.0f) / (float)h;
        float black[1][3], clamp[1][3], ab, ac;
        CHECK(texture_lookup_encoded(ts, "wrap.exr", NULL, TEXTURE_WRAP_BLACK, 1, &ss[k], &tt, NULL,
                                     NULL, black, &ab) == 0);
        CHECK(texture_lookup_encoded(ts, "wrap.exr", NULL, TEXTURE_WRAP_CLAMP, 1, &ss[k], &tt, NULL,
                                     NULL, clamp, &ac) == 0);
        int x = k == 0 ? 0 : k == 1 ? w - 1 : 2; /* the column clamp reads */
        const float *texel = &img[4 * (1 * w + x)];
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(clamp[0][c], texel[c], 1e-6);
            CHECK_NEAR(black[0][c], k == 2 ? texel[c] : 0.0f, 1e-6);
        }
        CHECK_NEAR(ac, texel[3], 1e-6);
        CHECK_NEAR(ab, k == 2 ? texel[3] : 0.0f, 1e-6);
    }
    texture_system_free(ts);
    free(img);
}

static void write_bytes(const char *name, const unsigned char *b, size_t n)
{
    char path[512];
    mkdir(TMP, 0755);
    snprintf(path, sizeof path, "%s/%s", TMP, name);
    FILE *f = fopen(path, "wb");
    CHECK(f && fwrite(b, 1, n, f) == n);
    if (f)
        fclose(f);
}

/* Formats beyond EXR and PNG, written by hand: an uncompressed 2 x 1 TGA
 * (8-bit, sRGB: 255 is 1, 188 about 0.5) and a 2 x 1 Radiance HDR (RGBE,
 * linear, exact for these values). */
static void test_formats(void)
{
    unsigned char tga[18 + 6] = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 24, 0x20};
    const unsigned char bgr[6] = {0, 0, 255, 188, 188, 188}; /* red; grey */
    memcpy(tga + 18, bgr, sizeof bgr);
    write_bytes("two.tga", tga, sizeof tga);
    const char hdr_head[] = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 1 +X 2\n";
    unsigned char hdr[sizeof hdr_head - 1 + 8];
    memcpy(hdr, hdr_head, sizeof hdr_head - 1);
    const unsigned char rgbe[8] = {128, 64,  32,  129,
                                   128, 128, 128, 128}; /* (1 .5 .25) (.5 .5 .5) */
    memcpy(hdr + sizeof hdr_head - 1, rgbe, sizeof rgbe);
    write_bytes("two.hdr", hdr, sizeof hdr);
    TextureSystem *ts = texture_system_new(TMP, 64u << 20, 1.0f);
    float s0 = 0.25f, s1 = 0.75f, t = 0.5f, rgb[1][3], a;
    CHECK(texture_lookup(ts, "two.tga", 1, &s0, &t, NULL, NULL, rgb, &a) == 0);
    CHECK_NEAR(rgb[0][0], 1.0, 1e-5);
    CHECK_NEAR(rgb[0][1], 0.0, 1e-5);
    CHECK_NEAR(a, 1.0, 1e-6);
    CHECK(texture_lookup(ts, "two.tga", 1, &s1, &t, NULL, NULL, rgb, NULL) == 0);
    CHECK_NEAR(rgb[0][0], 0.5029, 1e-3); /* sRGB 188 */
    CHECK(texture_lookup(ts, "two.hdr", 1, &s0, &t, NULL, NULL, rgb, NULL) == 0);
    CHECK_NEAR(rgb[0][0], 1.0, 1e-6);
    CHECK_NEAR(rgb[0][1], 0.5, 1e-6);
    CHECK_NEAR(rgb[0][2], 0.25, 1e-6);
    texture_system_free(ts);
    /* The whole-image reader of environment maps reads them too. */
    int w = 0, h = 0;
    float *px = NULL;
    char path[512], err[300];
    snprintf(path, sizeof path, "%s/two.hdr", TMP);
    CHECK(texture_read_image(path, &w, &h, &px, err, sizeof err) == 0 && w == 2 && h == 1);
    CHECK(px && px[0] == 1.0f && px[4] == 0.5f && px[3] == 1.0f);
    free(px);
    snprintf(path, sizeof path, "%s/no_such.hdr", TMP);
    CHECK(texture_read_image(path, &w, &h, &px, err, sizeof err) == -1 && err[0] && !px);
}

/* maketx's tiled, MIP-mapped .tx file gives its source's texels. */
static void test_maketx(void)
{
    float *img = random_image(64, 32, 11);
    write_exr("src.exr", 64, 32, img);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "maketx %s/src.exr -o %s/src.tx > /dev/null 2>&1", TMP, TMP);
    int status = system(cmd);
    CHECK(status == 0); /* openimageio-tools (tools/install-deps --test) */
    TextureSystem *ts = texture_system_new(TMP, 64u << 20, 1.0f);
    for (int y = 0; status == 0 && y < 32; y += 5)
        for (int x = 0; x < 64; x += 7) {
            float s = ((float)x + 0.5f) / 64.0f, t = ((float)y + 0.5f) / 32.0f, a[2], rgb[2][3];
            CHECK(texture_lookup(ts, "src.tx", 1, &s, &t, NULL, NULL, &rgb[0], &a[0]) == 0);
            CHECK(texture_lookup(ts, "src.exr", 1, &s, &t, NULL, NULL, &rgb[1], &a[1]) == 0);
            for (int c = 0; c < 3; c++)
                CHECK_NEAR(rgb[0][c], rgb[1][c], 1e-6);
        }
    texture_system_free(ts);
    free(img);
}

/* Runs fn with stderr sent to a file; returns what was written (static). */
static const char *capture_stderr(void (*fn)(void *), void *arg)
{
    static char text[4096];
    char path[512];
    snprintf(path, sizeof path, "%s/stderr.txt", TMP);
    mkdir(TMP, 0755);
    fflush(stderr);
    int saved = dup(2), fd = open(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 2);
    close(fd);
    fn(arg);
    fflush(stderr);
    dup2(saved, 2);
    close(saved);
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    text[n] = '\0';
    if (f)
        fclose(f);
    return text;
}

static int missing_status[2];

static void look_up_missing(void *arg)
{
    TextureSystem *ts = arg;
    float s[2] = {0.5f, 0.1f}, t[2] = {0.5f, 0.2f}, rgb[2][3] = {{9, 9, 9}, {9, 9, 9}}, a[2];
    missing_status[0] = texture_lookup(ts, "no_such_texture.exr", 2, s, t, NULL, NULL, rgb, a);
    missing_status[1] = texture_lookup(ts, "no_such_texture.exr", 1, s, t, NULL, NULL, rgb, a);
    for (int i = 0; i < 2; i++) {
        CHECK(rgb[i][0] == 0.0f && rgb[i][1] == 0.0f && rgb[i][2] == 0.0f);
        CHECK(a[i] == 1.0f);
    }
}

static void test_missing_file_warns_once(void)
{
    TextureSystem *ts = texture_system_new(TMP, 64u << 20, 1.0f);
    const char *err = capture_stderr(look_up_missing, ts);
    CHECK(missing_status[0] == -1 && missing_status[1] == -1);
    const char *first = strstr(err, "no_such_texture.exr");
    CHECK(first != NULL);
    CHECK(first && strstr(first + 1, "no_such_texture.exr") == NULL); /* one warning */
    TextureStats st;
    texture_get_stats(ts, &st);
    CHECK(st.missing == 1 && st.textures == 1 && st.lookups == 3);
    texture_system_free(ts);
}

static void test_search_path(void)
{
    float img[4] = {0.5f, 0.25f, 0.125f, 1.0f};
    write_exr("found.exr", 1, 1, img);
    /* Found through the second directory; an absolute name as given. */
    TextureSystem *ts = texture_system_new("/nonexistent-dir:" TMP, 1u << 20, 1.0f);
    float s = 0.5f, t = 0.5f, rgb[1][3];
    CHECK(texture_lookup(ts, "found.exr", 1, &s, &t, NULL, NULL, rgb, NULL) == 0);
    CHECK_NEAR(rgb[0][1], 0.25, 1e-6);
    CHECK(texture_lookup(ts, TMP "/found.exr", 1, &s, &t, NULL, NULL, rgb, NULL) == 0);
    texture_system_free(ts);
    ts = texture_system_new(NULL, 1u << 20, 1.0f);
    CHECK(texture_lookup(ts, "found.exr", 1, &s, &t, NULL, NULL, rgb, NULL) == -1);
    texture_system_free(ts);
    /* PNG is decoded from sRGB: white is 1, black 0. */
    float bw[8] = {1, 1, 1, 1, 0, 0, 0, 1};
    char path[512], err[300];
    snprintf(path, sizeof path, "%s/bw.png", TMP);
    CHECK(image_write_png(path, 2, 1, bw, err, sizeof err) == RAYES_OK);
    ts = texture_system_new(TMP, 1u << 20, 1.0f);
    float s0 = 0.25f, s1 = 0.75f;
    CHECK(texture_lookup(ts, "bw.png", 1, &s0, &t, NULL, NULL, rgb, NULL) == 0);
    CHECK_NEAR(rgb[0][0], 1.0, 1e-6);
    CHECK(texture_lookup(ts, "bw.png", 1, &s1, &t, NULL, NULL, rgb, NULL) == 0);
    CHECK_NEAR(rgb[0][0], 0.0, 1e-6);
    texture_system_free(ts);
}

/* Random lookups over two textures with random footprints: a .tx file
 * (tiled and MIP-mapped, so it streams through the budgeted tile cache)
 * and a small untiled EXR (which OpenImageIO holds whole with its MIP
 * levels). */
static void random_lookups(TextureSystem *ts, int n, float (*rgb)[3], float *alpha)
{
    uint32_t x = 12345u;
    for (int i = 0; i < n; i++) {
        float v[4];
        for (int k = 0; k < 4; k++) {
            x = x * 1664525u + 1013904223u;
            v[k] = (float)(x >> 8) / (float)(1u << 24);
        }
        float s = 4.0f * v[0] - 2.0f, t = 4.0f * v[1] - 2.0f;
        float ds = powf(2.0f, -11.0f * v[2]), dt = powf(2.0f, -11.0f * v[3]);
        const char *name = i % 3 ? "budget_a.tx" : "budget_b.exr";
        CHECK(texture_lookup(ts, name, 1, &s, &t, &ds, &dt, &rgb[i], &alpha[i]) == 0);
    }
}

static void test_budget_does_not_change_results(void)
{
    float *a = random_image(2048, 1024, 3), *b = random_image(77, 51, 4);
    write_exr("budget_a.exr", 2048, 1024, a);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "maketx %s/budget_a.exr -o %s/budget_a.tx > /dev/null 2>&1", TMP,
             TMP);
    CHECK(system(cmd) == 0);
    write_exr("budget_b.exr", 77, 51, b);
    enum { N = 2000 };
    static float rgb[3][N][3], alpha[3][N];
    uint64_t budgets[3] = {1000u << 20, 10u << 20, 0}; /* OpenImageIO keeps 10 MiB at least */
    TextureStats st[3];
    int counts[3] = {N, N, N};
    for (int k = 0; k < 3; k++) {
        TextureSystem *ts = texture_system_new(TMP, budgets[k], 1.0f);
        random_lookups(ts, counts[k], rgb[k], alpha[k]);
        texture_get_stats(ts, &st[k]);
        CHECK(st[k].budget_bytes == budgets[k] && st[k].loads > 0 && st[k].file_reads == 2);
        texture_system_free(ts);
    }
    CHECK(memcmp(rgb[0], rgb[1], sizeof rgb[0]) == 0);
    CHECK(memcmp(rgb[0], rgb[2], (size_t)counts[2] * sizeof rgb[0][0]) == 0);
    CHECK(memcmp(alpha[0], alpha[1], sizeof alpha[0]) == 0);
    CHECK(memcmp(alpha[0], alpha[2], (size_t)counts[2] * sizeof alpha[0][0]) == 0);
    CHECK(st[0].lookups == N && st[0].textures == 2 && st[0].missing == 0);
    /* The .tx's tiles (34 MB of them) are evicted to keep 10 MiB. */
    CHECK(st[0].evictions == 0 && st[1].evictions > 0 && st[2].evictions > 0);
    CHECK(st[0].bytes > (20u << 20) && st[1].bytes <= (12u << 20));
    free(a);
    free(b);
}

TEST_MAIN(TEST(test_pyramid_keeps_the_mean), TEST(test_constant_at_any_footprint),
          TEST(test_texel_centres_and_wrap), TEST(test_formats), TEST(test_maketx),
          TEST(test_missing_file_warns_once), TEST(test_search_path),
          TEST(test_budget_does_not_change_results))
