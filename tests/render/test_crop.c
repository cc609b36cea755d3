/*
 * Crop windows (RayesRenderOptions.crop, RenderMan's CropWindow): the
 * pixels of a crop are the same, bit for bit, as the same pixels of the
 * whole frame, with either hider, both quality presets, a wide filter,
 * other thread counts and a small cache; pixels outside are 0; the image
 * says which pixels it holds (RenderMan's ceil rule); an empty or reversed
 * window is refused; an EXR written with the crop as its data window reads
 * back as the crop.
 */
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

static RayesScene *cornell(void)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static RayesImage *render(RayesScene *s, RayesQuality q, RayesHider hider, int wide, int threads,
                          double cache_mb, const float crop[4])
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, q);
    o.width = 40, o.height = 36;
    o.spp = 2;
    o.tile_size = 8;
    o.threads = threads;
    o.cache_mb = cache_mb;
    if (cache_mb < 1.0) /* a budget meant to evict: no other type's to borrow */
        o.opacity_cache_mb = o.irradiance_cache_mb = 0.0, o.env_guide = 0;
    o.hider = hider;
    o.diffuse_rays = o.diffuse_rays < 16 ? o.diffuse_rays : 16;
    o.diffuse_rays_deep = o.diffuse_rays_deep < 8 ? o.diffuse_rays_deep : 8;
    o.shadow_rays = o.shadow_rays_deep = 4;
    if (wide) {
        o.filter = RAYES_FILTER_GAUSSIAN;
        o.filter_width = 3.0f;
    }
    if (crop)
        memcpy(o.crop, crop, sizeof o.crop);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

static void test_crop_matches_frame(void)
{
    RayesScene *s = cornell();
    const float crop[4] = {0.3f, 0.71f, 0.25f, 0.9f};
    /* ceil(40 * .3) = 12 to ceil(40 * .71) = 29; ceil(36 * .25) = 9 to ceil(36 * .9) = 33 */
    const int x0 = 12, x1 = 29, y0 = 9, y1 = 33;
    const RayesQuality quality[2] = {RAYES_QUALITY_PREVIEW, RAYES_QUALITY_FINAL};
    const RayesHider hiders[2] = {RAYES_HIDER_RAYTRACE, RAYES_HIDER_GRID};
    for (int q = 0; q < 2; q++)
        for (int h = 0; h < 2; h++) {
            int wide = q == h; /* a wide filter on two of the four */
            RayesImage *full = render(s, quality[q], hiders[h], wide, 2, 100.0, NULL);
            RayesImage *part = render(s, quality[q], hiders[h], wide, 1, 0.5, crop);
            if (!full || !part) {
                rayes_image_free(full);
                rayes_image_free(part);
                continue;
            }
            CHECK(full->crop[2] == 0);
            CHECK(part->crop[0] == x0 && part->crop[1] == y0);
            CHECK(part->crop[2] == x1 - x0 && part->crop[3] == y1 - y0);
            int same = 1, zero = 1;
            double mean = 0.0;
            for (int y = 0; y < 36; y++)
                for (int x = 0; x < 40; x++) {
                    const float *a = &full->rgba[4 * (y * 40 + x)], *b = &part->rgba[4 * (y * 40 + x)];
                    if (x >= x0 && x < x1 && y >= y0 && y < y1) {
                        same &= memcmp(a, b, 4 * sizeof *a) == 0;
                        mean += a[0];
                    } else
                        zero &= b[0] == 0.0f && b[1] == 0.0f && b[2] == 0.0f && b[3] == 0.0f;
                }
            CHECK(same && zero && mean > 0.0);
            rayes_image_free(full);
            rayes_image_free(part);
        }
    rayes_scene_release(s);
}

static void test_bad_windows(void)
{
    RayesScene *s = cornell();
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    CHECK(o.crop[0] == 0.0f && o.crop[1] == 1.0f && o.crop[2] == 0.0f && o.crop[3] == 1.0f);
    o.width = o.height = 8;
    const float bad[3][4] = {{0.5f, 0.5f, 0, 1}, {0, 1, 0.9f, 0.2f}, {0.51f, 0.55f, 0, 1}};
    for (int k = 0; k < 3; k++) {
        memcpy(o.crop, bad[k], sizeof o.crop);
        RayesImage *img = NULL;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT && !img);
        CHECK(strstr(rayes_scene_get_error(s), "crop window") != NULL);
        rayes_scene_clear_error(s);
    }
    rayes_scene_release(s);
}

/* The EXR of a crop: the data window holds the crop's pixels. */
static void test_exr_data_window(void)
{
    enum { W = 9, H = 7 };
    float rgba[W * H * 4];
    for (int i = 0; i < W * H * 4; i++)
        rgba[i] = (float)(i % 17) / 16.0f;
    const int win[4] = {2, 3, 5, 4};
    char path[512], err[256];
    snprintf(path, sizeof path, "%s/test_crop.exr", RAYES_TEST_TMP);
    CHECK(image_write_exr_window(path, W, H, rgba, win, 0, err, sizeof err) == RAYES_OK);
    int w = 0, h = 0;
    float *back = NULL;
    CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK);
    CHECK(w == 5 && h == 4);
    int same = back != NULL;
    for (int y = 0; back && y < 4; y++)
        for (int x = 0; x < 5; x++)
            for (int c = 0; c < 4; c++) /* half floats: these values are exact */
                same &= back[4 * (y * 5 + x) + c] == rgba[4 * ((y + 3) * W + x + 2) + c];
    CHECK(same);
    free(back);
    const int outside[4] = {6, 0, 4, 7};
    CHECK(image_write_exr_window(path, W, H, rgba, outside, 0, err, sizeof err) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    remove(path);
}

TEST_MAIN(TEST(test_crop_matches_frame), TEST(test_bad_windows), TEST(test_exr_data_window))
