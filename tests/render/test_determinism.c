/*
 * Determinism (DESIGN.md): the same scene gives the same bytes whatever the
 * number of threads and the tile size, for both filters; a different seed
 * gives a different image.
 */
#include <stdlib.h>
#include <string.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

static RayesImage *render(const char *scene_name, int threads, int tile, RayesFilter filter,
                          uint64_t seed, int bounces)
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
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = 48;
    o.height = 40;
    o.spp = 2;
    o.threads = threads;
    o.tile_size = tile;
    o.filter = filter;
    o.filter_width = filter == RAYES_FILTER_GAUSSIAN ? 2.0f : 1.0f;
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

TEST_MAIN(TEST(test_box_filter_any_thread_count), TEST(test_gaussian_filter_any_thread_count),
          TEST(test_teapots_any_thread_count), TEST(test_displaced_teapots),
          TEST(test_seed_changes_image), TEST(test_spheres_any_thread_count))
