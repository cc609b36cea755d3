/*
 * Determinism (DESIGN.md): the same scene gives the same bytes whatever the
 * number of threads and the tile size, for every filter; a different seed
 * gives a different image; and every filter, negative lobes included,
 * keeps a constant image constant.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

/* A built-in scene, committed. */
static RayesScene *builtin(const char *scene_name)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    RayesError e = io_builtin_scene(scene_name, RAYES_TEST_DATA, &sink, err, sizeof err);
    if (e == RAYES_OK)
        e = rayes_scene_commit(s);
    CHECK(e == RAYES_OK);
    if (e != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    return s;
}

static RayesImage *render(const char *scene_name, int threads, int tile, RayesFilter filter,
                          uint64_t seed, int bounces)
{
    RayesScene *s = builtin(scene_name);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = 48;
    o.height = 40;
    o.spp = 2;
    o.threads = threads;
    o.tile_size = tile;
    o.filter = filter;
    io_filter_named(io_filter_name(filter), &o.filter_width); /* its default width */
    o.seed = seed;
    o.bounces = bounces;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static int same(const RayesImage *a, const RayesImage *b)
{
    return a && b && a->width == b->width && a->height == b->height &&
           memcmp(a->rgba, b->rgba, sizeof(float) * 4 * (size_t)a->width * a->height) == 0;
}

static void check_threads(const char *scene, RayesFilter filter, int bounces)
{
    RayesImage *one = render(scene, 1, 16, filter, 0, bounces);
    RayesImage *two = render(scene, 2, 16, filter, 0, bounces);
    RayesImage *four = render(scene, 4, 7, filter, 0, bounces);
    CHECK(same(one, two));
    CHECK(same(one, four));
    rayes_image_free(one);
    rayes_image_free(two);
    rayes_image_free(four);
}

static void test_box_filter_any_thread_count(void)
{
    check_threads("cornell", RAYES_FILTER_BOX, 2);
}

static void test_gaussian_filter_any_thread_count(void)
{
    check_threads("cornell", RAYES_FILTER_GAUSSIAN, 1);
}

static void test_every_filter_any_thread_count(void)
{
    for (int f = RAYES_FILTER_TRIANGLE; f <= RAYES_FILTER_LANCZOS; f++)
        check_threads("cornell", (RayesFilter)f, 0);
}

/* Inside a closed sphere emitting 1 (matte, Kd 0, Ke 1) every sample is 1:
 * the filtered image must be 1 everywhere, whatever the filter's lobes. */
static void test_filters_keep_a_constant_image(void)
{
    for (int f = RAYES_FILTER_BOX; f <= RAYES_FILTER_LANCZOS; f++) {
        RayesScene *s = rayes_scene_new();
        float eye[3] = {0, 0, 0}, target[3] = {0, 0, 1}, up[3] = {0, 1, 0};
        rayes_scene_set_camera(s, eye, target, up, 60.0f);
        RayesParam p[2] = {{"Kd", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
                           {"Ke", RAYES_PARAM_COLOR, {1, 1, 1}, NULL}};
        CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
        CHECK(rayes_scene_sphere(s, 10.0f) == RAYES_OK);
        CHECK(rayes_scene_commit(s) == RAYES_OK);
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = 24;
        o.height = 20;
        o.spp = 3;
        o.threads = 2;
        o.bounces = 0;
        o.filter = (RayesFilter)f;
        io_filter_named(io_filter_name(f), &o.filter_width);
        RayesImage *img = NULL;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
        float worst = 0.0f;
        for (int i = 0; img && i < img->width * img->height; i++) {
            worst = fmaxf(worst, fabsf(img->rgba[4 * i] - 1.0f));
            worst = fmaxf(worst, fabsf(img->rgba[4 * i + 3] - 1.0f));
        }
        CHECK(img && worst < 1e-5f);
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

static void test_teapots_any_thread_count(void)
{
    check_threads("cornell-teapots", RAYES_FILTER_BOX, 1);
}

/* Displacement runs at dicing, on every thread count the same; and it does
 * change the picture (the matte teapot, right of centre). */
static void test_displaced_teapots(void)
{
    check_threads("cornell-teapots-displaced", RAYES_FILTER_BOX, 1);
    RayesImage *plain = render("cornell-teapots", 2, 16, RAYES_FILTER_BOX, 0, 1);
    RayesImage *bumpy = render("cornell-teapots-displaced", 2, 16, RAYES_FILTER_BOX, 0, 1);
    CHECK(plain && bumpy && !same(plain, bumpy));
    rayes_image_free(plain);
    rayes_image_free(bumpy);
}

static void test_seed_changes_image(void)
{
    RayesImage *a = render("cornell", 2, 16, RAYES_FILTER_BOX, 0, 1);
    RayesImage *b = render("cornell", 2, 16, RAYES_FILTER_BOX, 1, 1);
    CHECK(a && b && !same(a, b));
    rayes_image_free(a);
    rayes_image_free(b);
}

/* Every built-in shader: glossy lobes, refraction, Fresnel. */
static void test_spheres_any_thread_count(void)
{
    check_threads("cornell-spheres", RAYES_FILTER_BOX, 1);
}

/* A bright edge (an emitting square filling the left half of the view,
 * nothing on the right): the negative lobes of Catmull-Rom overshoot on
 * the bright side (values above 1, as a film with such a filter shows),
 * where the triangle filter, all positive, stays within [0, 1]. */
static float edge_max(RayesFilter f)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -3}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 40.0f);
    RayesParam p[2] = {{"Kd", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
                       {"Ke", RAYES_PARAM_COLOR, {1, 1, 1}, NULL}};
    CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
    float quad[4][3] = {{-5, -5, 0}, {0.013f, -5, 0}, {-5, 5, 0}, {0.013f, 5, 0}};
    CHECK(rayes_scene_bilinear_patch(s, quad) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 16;
    o.threads = 2;
    o.bounces = 0;
    o.filter = f;
    io_filter_named(io_filter_name(f), &o.filter_width);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    float top = 0.0f;
    for (int i = 0; img && i < img->width * img->height; i++)
        top = fmaxf(top, img->rgba[4 * i]);
    rayes_image_free(img);
    rayes_scene_release(s);
    return top;
}

static void test_negative_lobes_ring(void)
{
    CHECK(edge_max(RAYES_FILTER_TRIANGLE) <= 1.0f);
    CHECK(edge_max(RAYES_FILTER_CATMULL_ROM) > 1.01f);
}

/* Adaptive pixel sampling: a pixel's count follows the samples of fixed
 * pixels (its own, its 3 x 3 neighbourhood's first block) and the frame's
 * mean, so the image is the same bytes on 1, 2 and 4 threads, with tiles
 * of other sizes and through a wide filter's margins; flat pixels stop at spp,
 * noisy ones go on (camera rays between the two bounds, some at the
 * most, not all). */
static RayesImage *render_adaptive(int threads, int tile, RayesFilter filter, RayesStats **st)
{
    RayesScene *s = builtin("cornell-teapots");
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = 40;
    o.height = 32;
    o.spp = 2;
    o.max_spp = 32;
    o.adaptive_error = 0.05f;
    o.threads = threads;
    o.tile_size = tile;
    o.filter = filter;
    io_filter_named(io_filter_name(filter), &o.filter_width);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, st) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static void test_adaptive_any_thread_count(void)
{
    for (int f = 0; f < 2; f++) {
        RayesFilter filter = f ? RAYES_FILTER_GAUSSIAN : RAYES_FILTER_BOX;
        RayesStats *st = NULL;
        RayesImage *one = render_adaptive(1, 16, filter, &st);
        RayesImage *two = render_adaptive(2, 16, filter, NULL);
        RayesImage *four = render_adaptive(4, 7, filter, NULL);
        CHECK(same(one, two));
        CHECK(same(one, four));
        const RayesStat *cam = rayes_stats_find(st, "rays/camera");
        const RayesStat *at_max = rayes_stats_find(st, "adaptive/pixels_at_max");
        CHECK(cam && at_max);
        if (cam && at_max && f == 0) { /* the box filter has no margins: counts are exact */
            fprintf(stderr, "adaptive: %llu camera rays for 1280 pixels, %llu at the most\n",
                    (unsigned long long)cam->count, (unsigned long long)at_max->count);
            CHECK(cam->count > 2 * 40 * 32 && cam->count < 32 * 40 * 32);
            CHECK(at_max->count > 0 && at_max->count < 40 * 32);
        }
        rayes_stats_free(st);
        rayes_image_free(one);
        rayes_image_free(two);
        rayes_image_free(four);
    }
}

/* The reference preset converges in pixels too (64 samples a pixel) and
 * caches nothing: no cache at all is made. */
static void test_reference_preset(void)
{
    RayesScene *s = builtin("cornell");
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_REFERENCE);
    CHECK(o.spp == 64 && o.max_spp == 1024 && o.adaptive_error > 0.0f && !o.cache &&
          !o.opacity_cache && !o.irradiance_cache);
    o.width = o.height = 8;
    o.threads = 2;
    o.diffuse_rays = 16; /* the pixel samples are what is tested */
    RayesImage *img = NULL, *uniform = NULL;
    RayesStats *st = NULL, *st_uniform = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    /* adaptive: at least the 64 first samples a pixel, more where needed */
    const RayesStat *cam = rayes_stats_find(st, "rays/camera");
    CHECK(cam && cam->count > 8 * 8 * 64 && cam->count < 8 * 8 * 1024);
    CHECK(rayes_stats_find(st, "cache/budget_bytes") == NULL);
    o.max_spp = 0;
    CHECK(rayes_render(s, &o, &uniform, &st_uniform) == RAYES_OK);
    cam = rayes_stats_find(st_uniform, "rays/camera");
    CHECK(cam && cam->count == 8 * 8 * 64);
    rayes_stats_free(st);
    rayes_stats_free(st_uniform);
    rayes_image_free(img);
    rayes_image_free(uniform);
    rayes_scene_release(s);
}

/* Replaying the rays (RayesRenderOptions.replay_rays) leaves the image as
 * it was, keeps every ray the statistics count (cornell-teapots has no
 * subsurface or volume rays beside them) and traces them again. */
static void test_replay_rays(void)
{
    RayesScene *s = builtin("cornell-teapots");
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = 48;
    o.height = 40;
    o.spp = 2;
    o.threads = 2;
    RayesImage *plain = NULL, *replayed = NULL;
    RayesStats *st = NULL, *st_plain = NULL;
    CHECK(rayes_render(s, &o, &plain, &st_plain) == RAYES_OK);
    o.replay_rays = 1;
    CHECK(rayes_render(s, &o, &replayed, &st) == RAYES_OK);
    CHECK(same(plain, replayed));
    const RayesStat *rays = rayes_stats_find(st, "rays/total");
    const RayesStat *kept = rayes_stats_find(st, "replay/rays");
    const RayesStat *dropped = rayes_stats_find(st, "replay/dropped");
    const RayesStat *cpu = rayes_stats_find(st, "replay/cpu_s");
    CHECK(rays && kept && dropped && cpu);
    if (rays && kept && dropped && cpu) {
        CHECK(rays->count > 1000);
        CHECK(kept->count == rays->count);
        CHECK(dropped->count == 0);
        CHECK(cpu->real > 0.0);
    }
    CHECK(rayes_stats_find(st_plain, "replay/rays") == NULL);
    rayes_stats_free(st);
    rayes_stats_free(st_plain);
    rayes_image_free(plain);
    rayes_image_free(replayed);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_box_filter_any_thread_count), TEST(test_gaussian_filter_any_thread_count),
          TEST(test_every_filter_any_thread_count), TEST(test_filters_keep_a_constant_image),
          TEST(test_negative_lobes_ring), TEST(test_teapots_any_thread_count),
          TEST(test_displaced_teapots), TEST(test_seed_changes_image),
          TEST(test_spheres_any_thread_count), TEST(test_adaptive_any_thread_count),
          TEST(test_reference_preset), TEST(test_replay_rays))
