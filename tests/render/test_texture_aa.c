/*
 * Texture anti-aliasing through the public API (render/, shade/texture): a
 * checkerboard on a plane receding to the horizon, shaded by paintedplastic,
 * rendered with one pixel sample. Filtered by the ray footprint, its error
 * against a 64-sample point-sampled reference must be far below the error
 * of the same one-sample render point-sampled (texture_width 0), which
 * aliases into moire toward the horizon. Also: a missing texture warns and
 * the image still renders; the statistics carry the textures/ block; the
 * image does not depend on the texture cache budget nor on threads.
 */
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "rayes/rayes.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/texture_aa"
enum { W = 64, H = 48 };

static void write_checker(void)
{
    enum { S = 512, CHECK_PX = 2 };
    static float rgba[S * S * 4];
    for (int y = 0; y < S; y++)
        for (int x = 0; x < S; x++) {
            float v = ((x / CHECK_PX) + (y / CHECK_PX)) % 2 ? 1.0f : 0.0f;
            float *p = &rgba[4 * (y * S + x)];
            p[0] = v;
            p[1] = v;
            p[2] = v;
            p[3] = 1.0f;
        }
    char err[300];
    mkdir(TMP, 0755);
    CHECK(image_write_png(TMP "/checker.png", S, S, rgba, err, sizeof err) == RAYES_OK);
}

/* The plane y = 0 from z = 20 to 220 under an area light, 256 x 256
 * checks, the eye 10 above it looking toward the horizon: every pixel it
 * covers minifies the texture, so its one-sample error is texture aliasing
 * (not where the sample fell in a magnified texel's ramp). */
static RayesScene *plane_scene(const char *texture)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 10, 0}, target[3] = {0, 7.4f, 10}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 50.0f) == RAYES_OK);
    CHECK(rayes_scene_set_search_path(s, "texture", "/nonexistent:" TMP) == RAYES_OK);
    RayesParam p[4] = {
        {"texturename", RAYES_PARAM_STRING, {0, 0, 0}, texture},
        {"Ka", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
        {"Kd", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL},
        {"Ks", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "paintedplastic", p, 4) == RAYES_OK);
    float plane[4][3] = {{-150, 0, 20}, {-150, 0, 220}, {150, 0, 20}, {150, 0, 220}};
    CHECK(rayes_scene_bilinear_patch(s, plane) == RAYES_OK);
    /* Small against its distance, so 4 shadow rays see nearly the same
     * light everywhere: the images differ by their texture only. */
    float light[4][3] = {{-10, 300, 110}, {10, 300, 110}, {10, 300, 130}, {-10, 300, 130}};
    float L[3] = {600, 600, 600};
    CHECK(rayes_scene_area_light(s, light, L) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static RayesImage *render(RayesScene *s, int spp, float texture_width, double texture_mb,
                          int threads, RayesStats **stats)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = W;
    o.height = H;
    o.spp = spp;
    o.threads = threads;
    o.bounces = 0;
    o.shadow_rays = o.shadow_rays_deep = 4;
    o.tile_size = 16;
    o.texture_width = texture_width;
    o.texture_mb = texture_mb;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

/* Root mean square difference over the pixels the plane covers wholly in
 * the reference (alpha 1): pixels on its far edge differ by where their one
 * sample fell, with or without texture filtering. */
static double rms(const RayesImage *a, const RayesImage *ref)
{
    double sum = 0.0;
    size_t n = 0;
    for (size_t i = 0; i < (size_t)W * H; i++) {
        if (ref->rgba[4 * i + 3] < 1.0f)
            continue;
        for (int c = 0; c < 3; c++) {
            double d = a->rgba[4 * i + c] - ref->rgba[4 * i + c];
            sum += d * d;
        }
        n++;
    }
    CHECK(n > (size_t)W * H / 3);
    return n ? sqrt(sum / (3.0 * (double)n)) : 0.0;
}

static void save(const RayesImage *img, const char *name)
{
    char path[512], err[300];
    snprintf(path, sizeof path, "%s/%s", TMP, name);
    CHECK(image_write_png(path, img->width, img->height, img->rgba, err, sizeof err) == RAYES_OK);
}

static void test_filtered_one_sample_is_close_to_the_reference(void)
{
    write_checker();
    RayesScene *s = plane_scene("checker.png");
    RayesStats *stats = NULL;
    RayesImage *ref = render(s, 64, 0.0f, 64.0, 0, NULL);
    RayesImage *point = render(s, 1, 0.0f, 64.0, 0, NULL);
    RayesImage *filtered = render(s, 1, 1.0f, 64.0, 0, &stats);
    double e_point = rms(point, ref), e_filtered = rms(filtered, ref);
    printf("rms error against 64 spp: point-sampled %.4f, filtered %.4f\n", e_point, e_filtered);
    CHECK(e_point > 0.1);               /* the moire is there to remove */
    CHECK(e_filtered < 0.35 * e_point); /* and filtering removes most of it */
    save(ref, "reference.png");
    save(point, "point.png");
    save(filtered, "filtered.png");

    const RayesStat *st = rayes_stats_find(stats, "textures/lookups");
    CHECK(st && st->count > 0);
    st = rayes_stats_find(stats, "textures/textures");
    CHECK(st && st->count == 1);
    st = rayes_stats_find(stats, "textures/missing");
    CHECK(st && st->count == 0);
    st = rayes_stats_find(stats, "textures/budget_bytes");
    CHECK(st && st->count == 64000000u);
    CHECK(rayes_stats_find(stats, "textures/evictions") != NULL);
    CHECK(rayes_stats_find(stats, "textures/bytes") != NULL);
    CHECK(rayes_stats_find(stats, "textures/loads") != NULL);

    /* The same bytes with a budget below the texture's pyramid (5.6 MB;
     * OpenImageIO keeps at least 10 MiB, and an untiled file's levels
     * whole: tests/shade/test_texture.c evicts a .tx file's tiles), and on
     * one thread. */
    RayesStats *tiny_stats = NULL;
    RayesImage *tiny = render(s, 1, 1.0f, 4.5, 0, &tiny_stats);
    st = rayes_stats_find(tiny_stats, "textures/budget_bytes");
    CHECK(st && st->count == 4500000u);
    rayes_stats_free(tiny_stats);
    RayesImage *one = render(s, 1, 1.0f, 64.0, 1, NULL);
    size_t bytes = sizeof(float) * 4 * W * H;
    CHECK(memcmp(tiny->rgba, filtered->rgba, bytes) == 0);
    CHECK(memcmp(one->rgba, filtered->rgba, bytes) == 0);
    rayes_image_free(tiny);
    rayes_image_free(one);
    rayes_image_free(ref);
    rayes_image_free(point);
    rayes_image_free(filtered);
    rayes_stats_free(stats);
    rayes_scene_release(s);
}

static void test_missing_texture_still_renders(void)
{
    RayesScene *s = plane_scene("no_such_checker.png");
    RayesStats *stats = NULL;
    RayesImage *img = render(s, 1, 1.0f, 64.0, 0, &stats);
    CHECK(img != NULL);
    const RayesStat *st = rayes_stats_find(stats, "textures/missing");
    CHECK(st && st->count == 1);
    /* Plain plastic instead: the plane is lit, not black. */
    CHECK(img && img->rgba[4 * ((H / 2) * W + W / 2)] > 0.1f);
    rayes_image_free(img);
    rayes_stats_free(stats);
    rayes_scene_release(s);
}

static void test_search_path_kinds(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_search_path(s, "texture", "a:b") == RAYES_OK);
    CHECK(rayes_scene_set_search_path(s, "texture", "c:&") == RAYES_OK);
    CHECK(rayes_scene_set_search_path(s, "nonsense", "a") == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "nonsense") != NULL);
    CHECK(rayes_scene_set_search_path(s, NULL, "a") == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_filtered_one_sample_is_close_to_the_reference),
          TEST(test_missing_texture_still_renders), TEST(test_search_path_kinds))
