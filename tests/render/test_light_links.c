/*
 * Light linking (rayes_scene_set_light_links): each object is lit only by
 * its linked lights, in direct lighting and the ambient service, at camera
 * hits (ray-traced and grid hider), in radiosity cache fills and under
 * irradiance interpolation; links may name lights made later, and a link
 * to a light that never comes fails the commit.
 */
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}
static RayesParam pv(const char *name, float x, float y, float z)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {x, y, z}, NULL};
}

enum { SIZE = 24 };

static RayesImage *render(RayesScene *s, int hider, int bounces)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = SIZE;
    o.spp = 1;
    o.threads = 2;
    o.bounces = bounces;
    o.hider = hider ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE;
    o.irradiance = hider;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

static int same_columns(const RayesImage *a, const RayesImage *b, int x0, int x1)
{
    for (int y = 0; y < SIZE; y++)
        if (memcmp(&a->rgba[4 * (y * SIZE + x0)], &b->rgba[4 * (y * SIZE + x0)],
                   sizeof(float) * 4 * (size_t)(x1 - x0)) != 0) {
            return 0;
        }
    return 1;
}

static float sum(const RayesImage *a, int x0, int x1)
{
    float t = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = x0; x < x1; x++)
            t += a->rgba[4 * (y * SIZE + x)];
    return t;
}

/* Two side-by-side quads facing the camera, a point light in front of
 * each and an ambient light: lights 0 (left), 1 (right), 2 (ambient).
 * which: 0 every light, linked (left: ONLY 0, 2; right: EXCEPT 0, 2);
 * 1 lights 0 and 2 alone, unlinked; 2 light 1 alone, unlinked. */
static RayesScene *two_quads(int which)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0, -4}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 40.0f) == RAYES_OK);
    const size_t left[2] = {0, 2};
    const float L[4][3] = {{-2, -1, 0}, {0, -1, 0}, {-2, 1, 0}, {0, 1, 0}};
    const float R[4][3] = {{0, -1, 0}, {2, -1, 0}, {0, 1, 0}, {2, 1, 0}};
    RayesParam kd = pf("Kd", 0.8f);
    /* links set before the lights exist: checked at commit */
    if (which == 0)
        CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ONLY, left, 2) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, L) == RAYES_OK);
    if (which == 0)
        CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_EXCEPT, left, 2) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, R) == RAYES_OK);
    RayesParam a[2] = {pv("from", -1, 0, -1), pf("intensity", 2)};
    RayesParam b[2] = {pv("from", 1, 0, -1), pf("intensity", 3)};
    RayesParam amb = pf("intensity", 0.25f);
    if (which != 2)
        CHECK(rayes_scene_light(s, "pointlight", a, 2) == RAYES_OK);
    if (which != 1)
        CHECK(rayes_scene_light(s, "pointlight", b, 2) == RAYES_OK);
    if (which != 2)
        CHECK(rayes_scene_light(s, "ambientlight", &amb, 1) == RAYES_OK);
    return s;
}

static void test_each_object_its_lights(void)
{
    for (int hider = 0; hider < 2; hider++) {
        RayesScene *s[3];
        RayesImage *img[3];
        for (int k = 0; k < 3; k++) {
            s[k] = two_quads(k);
            img[k] = render(s[k], hider, 0);
        }
        CHECK(img[0] && img[1] && img[2]);
        if (img[0] && img[1] && img[2]) {
            /* looking down +z with +y up, world +x is on the image's left
             * (rayes_scene_set_camera): the quad at x < 0 fills the right half */
            CHECK(same_columns(img[0], img[1], SIZE / 2, SIZE));
            CHECK(same_columns(img[0], img[2], 0, SIZE / 2));
            CHECK(sum(img[0], 0, SIZE / 2) > 0 && sum(img[0], SIZE / 2, SIZE) > 0);
            CHECK(!same_columns(img[1], img[2], 0, SIZE / 2) &&
                  !same_columns(img[1], img[2], SIZE / 2, SIZE));
        }
        for (int k = 0; k < 3; k++) {
            rayes_image_free(img[k]);
            rayes_scene_release(s[k]);
        }
    }
}

/* A wall lit by light 0 alone over a floor not lit by it (which: 0), or
 * the same wall over a black floor (1): the wall's indirect light, from
 * radiosity cache fills of the floor, is zero either way. */
static RayesScene *wall_floor(int which)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 0.5f, -4}, target[3] = {0, 0, 1}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 50.0f) == RAYES_OK);
    const size_t zero = 0;
    const float W[4][3] = {{-2, -1, 1}, {2, -1, 1}, {-2, 2, 1}, {2, 2, 1}};
    const float F[4][3] = {{-2, -1, -3}, {2, -1, -3}, {-2, -1, 1}, {2, -1, 1}};
    RayesParam kd = pf("Kd", 0.8f), black = pf("Kd", 0.0f);
    if (which == 0)
        CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ONLY, &zero, 1) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, W) == RAYES_OK);
    if (which == 0)
        CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_EXCEPT, &zero, 1) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", which == 0 ? &kd : &black, 1) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, F) == RAYES_OK);
    RayesParam a[2] = {pv("from", 0, 0.5f, -1), pf("intensity", 2)};
    CHECK(rayes_scene_light(s, "pointlight", a, 2) == RAYES_OK);
    return s;
}

static void test_radiosity_fills_follow_links(void)
{
    for (int hider = 0; hider < 2; hider++) {
        RayesScene *a = wall_floor(0), *b = wall_floor(1);
        RayesImage *ia = render(a, hider, 1), *ib = render(b, hider, 1);
        CHECK(ia && ib && sum(ia, 0, SIZE) > 0);
        /* rows of the wall: the top of the image */
        if (ia && ib)
            CHECK(memcmp(ia->rgba, ib->rgba, sizeof(float) * 4 * SIZE * (SIZE / 3)) == 0);
        rayes_image_free(ia);
        rayes_image_free(ib);
        rayes_scene_release(a);
        rayes_scene_release(b);
    }
}

static void test_bad_links(void)
{
    RayesScene *s = rayes_scene_new();
    const size_t five = 5;
    CHECK(rayes_scene_set_light_links(s, (RayesLightLinks)7, NULL, 0) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ONLY, NULL, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ONLY, &five, 1) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_commit(s) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "no light 5") != NULL);
    /* links in force but no object made under them: nothing to check */
    RayesScene *t = rayes_scene_new();
    CHECK(rayes_scene_set_light_links(t, RAYES_LIGHT_LINKS_EXCEPT, &five, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(t) == RAYES_OK);
    rayes_scene_release(s);
    rayes_scene_release(t);
}

TEST_MAIN(TEST(test_each_object_its_lights), TEST(test_radiosity_fills_follow_links),
          TEST(test_bad_links))
