/*
 * Analytic renders (render/): a white furnace. The camera sits inside a
 * closed sphere whose inside is matte with albedo a and emits Ke = 1
 * (incandescence). Every point sees the same radiance, so with b bounces
 * the image is exactly sum_{k=0..b} a^k everywhere, and the infinite sum
 * 1 / (1 - a) is the limit. Light lost or gained anywhere (ray offsets,
 * normals, sampling weights, the depth bookkeeping) shows up here.
 */
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

/* cache: -2 off; -1 on, resolution by differentials; 0..2 forced level. */
/* offscreen: the off-screen dicing factor. At 24 x 24 pixels the default
 * (4) makes off-screen micropolygons of 19 degrees on this sphere, whose
 * flat facets turn away a share of the cosine-distributed diffuse rays
 * (they carry no light below the geometric surface): 0.5% of the energy
 * at six bounces. The tests of energy bookkeeping use 1; one test bounds
 * the default's loss. */
static double furnace_mean_at(float albedo, int bounces, int diffuse_rays, int threads, int cache,
                              float offscreen)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, 0}, target[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, target, up, 90.0f);
    RayesParam p[3] = {
        {"Kd", RAYES_PARAM_FLOAT, {albedo, 0, 0}, NULL},
        {"Ke", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
        {"Cs", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
    };
    CHECK(rayes_scene_set_shader(s, "matte", p, 3) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 10.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 24;
    o.spp = 2;
    o.bounces = bounces;
    o.diffuse_rays = o.diffuse_rays_deep = diffuse_rays;
    o.threads = threads;
    o.cache = cache != -2;
    o.cache_resolution = cache >= 0 ? cache : -1;
    o.dice_offscreen = offscreen;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double sum = 0.0;
    for (int i = 0; img && i < img->width * img->height; i++) {
        sum += img->rgba[4 * i];
        CHECK(img->rgba[4 * i + 3] == 1.0f); /* every camera ray hits */
    }
    double mean = img ? sum / (img->width * img->height) : 0.0;
    rayes_image_free(img);
    rayes_scene_release(s);
    return mean;
}

static double furnace_mean(float albedo, int bounces, int diffuse_rays, int threads, int cache)
{
    return furnace_mean_at(albedo, bounces, diffuse_rays, threads, cache, 1.0f);
}

static void test_furnace_each_bounce_count(void)
{
    const float a = 0.5f;
    double expected = 1.0;
    for (int b = 0; b <= 3; b++) {
        double m = furnace_mean(a, b, 4, 2, -1);
        CHECK_NEAR(m / expected, 1.0, 0.01);
        expected = expected * a + 1.0;
    }
}

/* Every cache resolution, and no cache, conserve energy: a fill point on a
 * patch boundary of the curved sphere must not see a neighbour from behind. */
static void test_furnace_each_resolution(void)
{
    const float a = 0.8f;
    double finite = 0.0, ak = 1.0;
    for (int k = 0; k <= 6; k++, ak *= a)
        finite += ak;
    for (int cache = -2; cache <= 2; cache++) {
        double m = furnace_mean(a, 6, 2, 2, cache);
        CHECK_NEAR(m / finite, 1.0, 0.005);
    }
}

/* The default off-screen dicing loses at most 1% at six bounces, the
 * coarse facets behind the camera of a 24-pixel image included. */
static void test_furnace_offscreen_dicing(void)
{
    const float a = 0.8f;
    double finite = 0.0, ak = 1.0;
    for (int k = 0; k <= 6; k++, ak *= a)
        finite += ak;
    for (int cache = -2; cache <= -1; cache++) {
        double m = furnace_mean_at(a, 6, 2, 2, cache, 4.0f);
        CHECK_NEAR(m / finite, 1.0, 0.01);
    }
}

static void test_furnace_converges_to_infinite_sum(void)
{
    /* 0.8^12 = 0.07: twelve bounces (one ray each: every path carries the same value) leave 6.9% of 1/(1-a) out,
     * which the finite sum accounts for. */
    const float a = 0.8f;
    double finite = 0.0, ak = 1.0;
    for (int k = 0; k <= 12; k++, ak *= a)
        finite += ak;
    double m = furnace_mean(a, 12, 1, 2, -1);
    CHECK_NEAR(m / finite, 1.0, 0.01);
    CHECK(m < 1.0 / (1.0 - a));
}

TEST_MAIN(TEST(test_furnace_each_bounce_count), TEST(test_furnace_each_resolution),
          TEST(test_furnace_offscreen_dicing), TEST(test_furnace_converges_to_infinite_sum))
