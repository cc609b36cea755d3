/*
 * Illuminate rendered (io/rib_shade.c's light links through io_sink_scene): a
 * light turned off around one object leaves that object lit by the other
 * lights alone, and the rest of the scene as if Illuminate were not there.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "rayes/rayes.h"
#include "test.h"

enum { SIZE = 24 };

/* Two quads side by side (x < 0 on the image's left), a point light in
 * front of them (handle 1) and, if two_lights, another (handle 2);
 * left_off wraps the left quad in Illuminate 1 0. */
static RayesImage *render_rib(int light1, int two_lights, int left_off)
{
    char text[2048];
    snprintf(text, sizeof text,
             "Projection \"perspective\" \"fov\" [40]\nWorldBegin\n%s%s"
             "%sPolygon \"P\" [-2 -1 4  0 -1 4  0 1 4  -2 1 4]\n%s"
             "Polygon \"P\" [0 -1 4  2 -1 4  2 1 4  0 1 4]\nWorldEnd\n",
             light1 ? "LightSource \"pointlight\" 1 \"from\" [0 0 2] \"intensity\" [4]\n" : "",
             two_lights ? "LightSource \"pointlight\" 2 \"from\" [1 1 1] \"intensity\" [2]\n" : "",
             left_off ? "AttributeBegin\nIlluminate 1 0\n" : "", left_off ? "AttributeEnd\n" : "");
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    char err[512];
    RayesImage *img = NULL;
    RayesError e = io_rib_parse("illuminate.rib", (const unsigned char *)text, strlen(text), &sink,
                                &opt, &settings, err, sizeof err);
    CHECK(e == RAYES_OK);
    if (e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = SIZE;
        o.spp = 1;
        o.threads = 2;
        o.bounces = 0;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    }
    rayes_scene_release(s);
    return img;
}

static int same_columns(const RayesImage *a, const RayesImage *b, int x0, int x1)
{
    for (int y = 0; y < SIZE; y++)
        if (memcmp(&a->rgba[4 * (y * SIZE + x0)], &b->rgba[4 * (y * SIZE + x0)],
                   sizeof(float) * 4 * (size_t)(x1 - x0)) != 0)
            return 0;
    return 1;
}

static float red(const RayesImage *a, int x0, int x1)
{
    float t = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = x0; x < x1; x++)
            t += a->rgba[4 * (y * SIZE + x)];
    return t;
}

static void test_illuminate_off_around_one_object(void)
{
    RayesImage *all = render_rib(1, 0, 0), *off = render_rib(1, 0, 1);
    CHECK(all && off);
    if (all && off) {
        CHECK(red(all, 0, SIZE / 2) > 0 && red(off, 0, SIZE / 2) == 0); /* the left: unlit */
        CHECK(same_columns(all, off, SIZE / 2, SIZE));                 /* the right: as before */
    }
    rayes_image_free(all);
    rayes_image_free(off);
    /* with a second light, the left quad is lit by it alone */
    RayesImage *both = render_rib(1, 1, 1), *second = render_rib(0, 1, 0),
               *plain = render_rib(1, 1, 0);
    CHECK(both && second && plain);
    if (both && second && plain) {
        CHECK(red(both, 0, SIZE / 2) > 0);
        CHECK(same_columns(both, second, 0, SIZE / 2));
        CHECK(same_columns(both, plain, SIZE / 2, SIZE));
    }
    rayes_image_free(both);
    rayes_image_free(second);
    rayes_image_free(plain);
}

TEST_MAIN(TEST(test_illuminate_off_around_one_object))
