/*
 * Bounded dicing through the scene (scene_prepare): a floor of 1 km
 * under the camera stays within a budget of grid vertices when one is
 * set, coarsened by one factor found by counting, the same on every
 * call; without a budget it needs more; the off-screen factor dices
 * what the camera does not see coarser.
 */
#include <math.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

static RayesScene *floor_scene(void)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 1.7f, 0}, at[3] = {0, 1.0f, 4}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 45.0f) == RAYES_OK);
    const float P[4][3] = {{-500, 0, -500}, {500, 0, -500}, {-500, 0, 500}, {500, 0, 500}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static size_t prepare(RayesScene *s, const DiceOptions *o, float *coarsened)
{
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 256, 256, o, NULL, &gs, coarsened) == 0);
    size_t n = gs.n_vertices;
    geom_gridset_fini(&gs);
    return n;
}

static void test_vertex_budget(void)
{
    RayesScene *s = floor_scene();
    float c = 0.0f;
    DiceOptions free = {0, 4.0f, 0};
    size_t unbounded = prepare(s, &free, &c);
    CHECK(c == 1.0f);
    CHECK(unbounded > 100000);
    DiceOptions tight = {0, 4.0f, 50000};
    size_t bounded = prepare(s, &tight, &c);
    CHECK(bounded <= 50000 && bounded > 10000);
    CHECK(c > 1.0f);
    float c2 = 0.0f;
    CHECK(prepare(s, &tight, &c2) == bounded && c2 == c); /* deterministic */
    rayes_scene_release(s);
}

static void test_offscreen_factor(void)
{
    RayesScene *s = floor_scene();
    DiceOptions one = {0, 1.0f, 0}, four = {0, 4.0f, 0}, sixteen = {0, 16.0f, 0};
    size_t n1 = prepare(s, &one, NULL), n4 = prepare(s, &four, NULL),
           n16 = prepare(s, &sixteen, NULL);
    CHECK(n4 < n1 / 4);
    CHECK(n16 < n4);
    rayes_scene_release(s);
}

/* Isotropic dicing (RenderMan's rasterorient 0) dices the floor seen at
 * a grazing angle as finely along the view as across it: more vertices
 * than raster-oriented dicing, with the off-screen part alike. */
static void test_isotropic(void)
{
    RayesScene *s = floor_scene();
    DiceOptions raster = {0, 4.0f, 0, 0}, iso = {0, 4.0f, 0, 1};
    size_t nr = prepare(s, &raster, NULL), ni = prepare(s, &iso, NULL);
    CHECK(ni > nr + nr / 4);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_vertex_budget), TEST(test_offscreen_factor), TEST(test_isotropic))
