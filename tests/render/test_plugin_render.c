/*
 * Shader plugins through the public API (scene/, render/): the scene's
 * "shader" search path and $RAYES_SHADER_PATH find the example plugin
 * brick; "&" keeps the previous path; an unknown name is
 * RAYES_ERROR_INVALID_ARGUMENT naming the directories; and a Cornell box
 * whose back wall is brick renders, red where the matte wall is not, with
 * the same bytes on 1 and 2 threads (scratch, cache fills of brick grids).
 *
 * With RAYES_PLUGIN_PICTURE=FILE.png set, also writes a 256 x 256 picture
 * of the scene there (to look at; not checked).
 */
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

#ifndef RAYES_TEST_SHADERS
#error "RAYES_TEST_SHADERS must name the directory of the example plugins"
#endif

static const RayesParam brick[] = {
    {"brickwidth", RAYES_PARAM_FLOAT, {0.1f, 0, 0}, NULL},
    {"brickheight", RAYES_PARAM_FLOAT, {0.045f, 0, 0}, NULL},
    {"mortarthickness", RAYES_PARAM_FLOAT, {0.008f, 0, 0}, NULL},
    {"Cbrick", RAYES_PARAM_COLOR, {0.6f, 0.16f, 0.1f}, NULL},
    {"Cmortar", RAYES_PARAM_COLOR, {0.7f, 0.7f, 0.65f}, NULL},
};

/* The Cornell box with a wall 1.2 mm in front of the back wall, shaded by
 * the named shader (from the scene's search path). */
static RayesScene *cornell_with_wall(const char *shader, const RayesParam *p, size_t n)
{
    char err[512];
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_search_path(s, "shader", RAYES_TEST_SHADERS) == RAYES_OK);
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    static const float wall[4][3] = {
        {549.6f, 0, 558}, {0, 0, 558}, {0, 548.8f, 558}, {556, 548.8f, 558}};
    static const int nv[1] = {4}, idx[4] = {0, 1, 2, 3};
    CHECK(rayes_scene_set_shader(s, shader, p, n) == RAYES_OK);
    CHECK(rayes_scene_polygon_mesh(s, 1, nv, idx, 4, &wall[0][0]) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static RayesImage *render(RayesScene *s, int res, int spp, int threads)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = res;
    o.spp = spp;
    o.threads = threads;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

/* Mean red over mean green in the middle of the back wall (the central
 * fifth of the width, between the ceiling and the tall block). */
static double wall_red_over_green(const RayesImage *img)
{
    double r = 0.0, g = 0.0;
    for (int y = img->height * 22 / 100; y < img->height * 40 / 100; y++)
        for (int x = 2 * img->width / 5; x < 3 * img->width / 5; x++) {
            r += img->rgba[4 * (y * img->width + x)];
            g += img->rgba[4 * (y * img->width + x) + 1];
        }
    return g > 0.0 ? r / g : 0.0;
}

static void test_search_path(void)
{
    unsetenv("RAYES_SHADER_PATH");
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_shader(s, "brick", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "unknown shader \"brick\"") != NULL);
    CHECK(strstr(rayes_scene_get_error(s), "empty") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_set_search_path(s, "shader", "/nonexistent/a:/nonexistent/b") == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "brick", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "/nonexistent/a, /nonexistent/b") != NULL);
    rayes_scene_clear_error(s);
    /* $RAYES_SHADER_PATH is searched after the scene's path. */
    setenv("RAYES_SHADER_PATH", "/nonexistent/c:" RAYES_TEST_SHADERS, 1);
    CHECK(rayes_scene_set_shader(s, "brick", brick, 5) == RAYES_OK);
    unsetenv("RAYES_SHADER_PATH");
    /* "&" and "@" stand for the previous value. */
    CHECK(rayes_scene_set_search_path(s, "shader", RAYES_TEST_SHADERS) == RAYES_OK);
    CHECK(rayes_scene_set_search_path(s, "shader", "/nonexistent/d:&") == RAYES_OK);
    CHECK(rayes_scene_set_search_path(s, "shader", "@:/nonexistent/e") == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "brick", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "nosuch", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "/nonexistent/d, " RAYES_TEST_SHADERS
                                           ", /nonexistent/e") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_set_search_path(s, "shader", "/nonexistent/f") == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "brick", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_clear_error(s);
    /* Bad arguments. */
    CHECK(rayes_scene_set_search_path(s, "bogus", "/tmp") == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "unknown kind \"bogus\"") != NULL);
    CHECK(rayes_scene_set_search_path(s, "shader", NULL) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_search_path(NULL, "shader", "/tmp") == RAYES_ERROR_INVALID_ARGUMENT);
    /* Doubling with "&" cannot grow without bound. */
    RayesError e = RAYES_OK;
    for (int i = 0; i < 40 && e == RAYES_OK; i++)
        e = rayes_scene_set_search_path(s, "shader", "&:&:/x");
    CHECK(e == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_release(s);
}

static void test_brick_wall_renders(void)
{
    RayesScene *b = cornell_with_wall("brick", brick, 5);
    static const RayesParam white = {"Cs", RAYES_PARAM_COLOR, {0.725f, 0.71f, 0.68f}, NULL};
    RayesScene *m = cornell_with_wall("matte", &white, 1);
    RayesImage *ib = render(b, 40, 2, 1), *ib2 = render(b, 40, 2, 2), *im = render(m, 40, 2, 2);
    if (ib && ib2 && im) {
        double rb = wall_red_over_green(ib), rm = wall_red_over_green(im);
        CHECK(rm > 0.5);
        CHECK(rb > 1.8 * rm); /* brick red (with a little grey mortar) against white */
        printf("  wall red/green: brick %.3f, matte %.3f\n", rb, rm);
        CHECK(memcmp(ib->rgba, ib2->rgba, sizeof(float) * 4 * 40 * 40) == 0);
    }
    rayes_image_free(ib);
    rayes_image_free(ib2);
    rayes_image_free(im);
    const char *picture = getenv("RAYES_PLUGIN_PICTURE");
    if (picture) {
        char err[512];
        RayesImage *big = render(b, 256, 16, 0);
        CHECK(big && image_write(picture, big->width, big->height, big->rgba, err, sizeof err) ==
                         RAYES_OK);
        rayes_image_free(big);
    }
    rayes_scene_release(b);
    rayes_scene_release(m);
}

/* The example plugin noisydisplace as a displacement shader: found on the
 * search path, run at dicing, it changes the picture (the displaced back
 * wall), and the same bytes come out for 1 and 2 threads. */
static void test_plugin_displacement(void)
{
    char err[512];
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_search_path(s, "shader", RAYES_TEST_SHADERS) == RAYES_OK);
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    const RayesParam p[] = {{"Km", RAYES_PARAM_FLOAT, {15.0f, 0, 0}, NULL},
                            {"frequency", RAYES_PARAM_FLOAT, {0.02f, 0, 0}, NULL}};
    CHECK(rayes_scene_set_displacement(s, "noisydisplace", p, 2) == RAYES_OK);
    static const float wall[4][3] = {
        {549.6f, 0, 558}, {0, 0, 558}, {0, 548.8f, 558}, {556, 548.8f, 558}};
    static const int nv[1] = {4}, idx[4] = {0, 1, 2, 3};
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_polygon_mesh(s, 1, nv, idx, 4, &wall[0][0]) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesScene *flat = cornell_with_wall("matte", NULL, 0);
    RayesImage *a = render(s, 40, 2, 1), *b = render(s, 40, 2, 2), *c = render(flat, 40, 2, 2);
    CHECK(a && b && c);
    if (a && b && c) {
        size_t bytes = sizeof(float) * 4 * 40 * 40;
        CHECK(memcmp(a->rgba, b->rgba, bytes) == 0);
        CHECK(memcmp(a->rgba, c->rgba, bytes) != 0);
    }
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
    rayes_scene_release(s);
    rayes_scene_release(flat);
}

/* The attribute and checker services, seen by a test plugin that writes
 * (object:id, patch:id, checker) as its colour: two quads, two objects. */
static void test_attribute_service(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_search_path(s, "shader", RAYES_TEST_BAD_SHADERS) == RAYES_OK);
    const float left[4][3] = {{-1, -1, 0}, {0, -1, 0}, {-1, 1, 0}, {0, 1, 0}};
    const float right[4][3] = {{0, -1, 0}, {1, -1, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_set_shader(s, "attributes", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, left) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "attributes", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, right) == RAYES_OK);
    const float eye[3] = {0, 0, -3}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 30.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 1;
    o.threads = 1;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    if (img) {
        /* Pixel (3, 8) sees the left quad (object 0), (12, 8) the right (1),
         * the camera looking along +z with +x to the left of the image. */
        const float *a = &img->rgba[4 * (8 * 16 + 3)], *b = &img->rgba[4 * (8 * 16 + 12)];
        CHECK(a[0] != b[0]);
        CHECK((a[0] == 0.0f && b[0] == 1.0f) || (a[0] == 1.0f && b[0] == 0.0f));
        CHECK(a[1] >= 0.0f && b[1] >= 0.0f && a[1] != b[1]);
        int zeros = 0, ones = 0;
        for (int i = 0; i < 16 * 16; i++) {
            zeros += img->rgba[4 * i + 2] == 0.0f;
            ones += img->rgba[4 * i + 2] == 1.0f;
        }
        CHECK(zeros > 20 && ones > 20); /* the checker shows both squares */
    }
    rayes_image_free(img);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_search_path), TEST(test_brick_wall_renders), TEST(test_plugin_displacement),
          TEST(test_attribute_service))
