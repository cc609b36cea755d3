/*
 * Object instances (rayes_scene_object_begin/_end/_instance; memo 3.1):
 * one diced master serves every instance (grids counted once), each
 * instance has its own radiosity cache entries and takes the shader and
 * colour current when it was made, an instance renders as the same
 * geometry placed directly does, images do not depend on threads, and
 * misuse of the calls is an error.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

enum { SIZE = 64 };

static RayesParam color(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}

static void translate(RayesScene *s, float x, float y, float z)
{
    const float m[16] = {1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
}

static void identity(RayesScene *s)
{
    translate(s, 0, 0, 0);
}

static void quad(RayesScene *s, float x0, float y0, float z0, float ux, float uy, float uz,
                 float vx, float vy, float vz)
{
    const float P[4][3] = {{x0, y0, z0},
                           {x0 + ux, y0 + uy, z0 + uz},
                           {x0 + vx, y0 + vy, z0 + vz},
                           {x0 + ux + vx, y0 + uy + vy, z0 + uz + vz}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
}

/* A floor (y = 0) lit by a point light (light 0; with unlit_floor, the
 * floor is lit only by what it sees), the camera above and in front. */
static RayesScene *stage_lit(int unlit_floor)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 2.5f, -6}, at[3] = {0, 0.4f, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 45.0f) == RAYES_OK);
    RayesParam I = {"intensity", RAYES_PARAM_FLOAT, {30, 0, 0}, NULL};
    RayesParam from = unlit_floor ? color("from", 0, 0.6f, -1.5f) : color("from", 0, 5, -2);
    RayesParam lp[2] = {I, from};
    CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
    RayesParam white = color("Cs", 1, 1, 1);
    const size_t light0 = 0;
    if (unlit_floor)
        CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_EXCEPT, &light0, 1) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &white, 1) == RAYES_OK);
    quad(s, -4, 0, -4, 0, 0, 8, 8, 0, 0); /* normal up */
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ALL, NULL, 0) == RAYES_OK);
    return s;
}

static RayesScene *stage(void)
{
    return stage_lit(0);
}

/* The master "ball": a sphere of radius 0.5 in a block with no shader,
 * so each instance's shader applies. */
static void define_ball(RayesScene *s)
{
    CHECK(rayes_scene_object_begin(s, "ball") == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 0.5f) == RAYES_OK);
    CHECK(rayes_scene_object_end(s) == RAYES_OK);
}

static RayesImage *render_hider(RayesScene *s, int threads, int bounces, int hider,
                                RayesStats **stats)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = SIZE;
    o.spp = 4;
    o.threads = threads;
    o.bounces = bounces;
    o.hider = hider ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE;
    o.irradiance = hider;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

/* With RAYES_TEST_DUMP set, writes img as a PPM (sRGB-ish gamma 2.2) of
 * that name under the build tree, to look at. */
static void dump(const RayesImage *img, const char *name)
{
    if (!getenv("RAYES_TEST_DUMP"))
        return;
    char path[512];
    snprintf(path, sizeof path, "%s/%s.ppm", RAYES_TEST_TMP, name);
    FILE *f = fopen(path, "wb");
    if (!f)
        return;
    fprintf(f, "P6 %d %d 255\n", img->width, img->height);
    for (int i = 0; i < img->width * img->height; i++)
        for (int c = 0; c < 3; c++) {
            float v = powf(fminf(fmaxf(img->rgba[4 * i + c], 0.0f), 1.0f), 1.0f / 2.2f);
            fputc((int)(v * 255.0f + 0.5f), f);
        }
    fclose(f);
}

static RayesImage *render(RayesScene *s, int threads, int bounces, RayesStats **stats)
{
    return render_hider(s, threads, bounces, 0, stats);
}

static uint64_t stat_count(const RayesStats *st, const char *name)
{
    const RayesStat *x = rayes_stats_find(st, name);
    return x ? x->count : 0;
}

/* The mean of channel c over the pixels [x0, x1) x [y0, y1). */
static double mean(const RayesImage *img, int c, int x0, int x1, int y0, int y1)
{
    double t = 0;
    for (int y = y0; y < y1; y++)
        for (int x = x0; x < x1; x++)
            t += img->rgba[4 * (y * img->width + x) + c];
    return t / ((double)(x1 - x0) * (y1 - y0));
}

/* 1 ball in front, or that ball and n - 1 more behind it, each with its
 * own shader: the master is diced once (for the nearest), so the grids do
 * not grow with n (bench/instances at test size). */
static uint64_t grids_of(int n, uint64_t *instances)
{
    RayesScene *s = stage();
    define_ball(s);
    for (int i = 0; i < n; i++) {
        RayesParam c = color("Cs", (float)(i % 7) / 7.0f, (float)(i % 5) / 5.0f, 0.5f);
        CHECK(rayes_scene_set_shader(s, "matte", &c, 1) == RAYES_OK); /* an object each */
        translate(s, i ? (float)(i % 50) - 24.5f : 0.0f, 0.5f,
                  1.5f * (float)(i / 50) + (i ? 2.0f : -1.0f));
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    }
    identity(s);
    RayesStats *st = NULL;
    RayesImage *img = render(s, 2, 1, &st);
    uint64_t grids = stat_count(st, "grids");
    *instances = stat_count(st, "instances/count");
    CHECK(stat_count(st, "instances/master_grids") > 0);
    CHECK(stat_count(st, "instances/flattened_vertices") ==
          (uint64_t)n * stat_count(st, "instances/master_vertices"));
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
    return grids;
}

static void test_master_counted_once(void)
{
    uint64_t n1, n_many;
    uint64_t one = grids_of(1, &n1), many = grids_of(2500, &n_many);
    CHECK(n1 == 1 && n_many == 2500);
    CHECK(one == many);
    CHECK(one > 10); /* the ball is diced into grids at all */
}

/* Two white balls, one by a red wall and one by a green wall: each
 * ball's own shading differs in colour (its indirect light). */
static void test_walls_colour_instances(void)
{
    RayesScene *s = stage();
    RayesParam red = color("Cs", 1, 0.05f, 0.05f), green = color("Cs", 0.05f, 1, 0.05f);
    CHECK(rayes_scene_set_shader(s, "matte", &red, 1) == RAYES_OK);
    quad(s, 1.8f, 0, -4, 0, 0, 8, 0, 3, 0); /* x = 1.8 (the image's left), facing -x */
    CHECK(rayes_scene_set_shader(s, "matte", &green, 1) == RAYES_OK);
    quad(s, -1.8f, 0, -4, 0, 3, 0, 0, 0, 8); /* x = -1.8 (the right), facing +x */
    define_ball(s);
    RayesParam white = color("Cs", 1, 1, 1);
    CHECK(rayes_scene_set_shader(s, "matte", &white, 1) == RAYES_OK);
    translate(s, 1.1f, 0.5f, 0);
    CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    translate(s, -1.1f, 0.5f, 0);
    CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    RayesImage *img = render(s, 2, 1, NULL);
    dump(img, "instances_walls");
    /* the balls' middles, left and right of the image's centre */
    int y0 = SIZE / 2 - 2, y1 = SIZE / 2 + 6;
    double lr = mean(img, 0, 14, 22, y0, y1), lg = mean(img, 1, 14, 22, y0, y1);
    double rr = mean(img, 0, 42, 50, y0, y1), rg = mean(img, 1, 42, 50, y0, y1);
    CHECK(lr > 0.01 && rg > 0.01);
    CHECK(lr / lg > 1.1 * (rr / rg)); /* the left ball is redder */
    CHECK(rg / rr > 1.1 * (lg / lr)); /* the right one greener */
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A red and a green instance of a ball with no shader of its own: each
 * takes the shader made before it, and the floor about each, unlit but by
 * what it sees through diffuse rays (the radiosity cache), takes its
 * colour: the cache holds an entry per instance. With one entry shared
 * (a key without the instance), both would bleed the same colour. */
static void test_instances_bleed_their_own_colour(void)
{
    RayesScene *s = stage_lit(1);
    define_ball(s);
    RayesParam red = color("Cs", 1, 0, 0), green = color("Cs", 0, 1, 0);
    CHECK(rayes_scene_set_shader(s, "matte", &red, 1) == RAYES_OK);
    translate(s, 1, 0.5f, 0); /* +x is the image's left (RenderMan's left-handed camera) */
    CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &green, 1) == RAYES_OK);
    translate(s, -1, 0.5f, 0);
    CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    RayesStats *st = NULL;
    RayesImage *img = render(s, 2, 1, &st);
    dump(img, "instances_bleed");
    /* the balls: red left, green right */
    int y0 = SIZE / 2 - 2, y1 = SIZE / 2 + 6;
    CHECK(mean(img, 0, 16, 24, y0, y1) > 4 * mean(img, 1, 16, 24, y0, y1));
    CHECK(mean(img, 1, 40, 48, y0, y1) > 4 * mean(img, 0, 40, 48, y0, y1));
    /* the floor about each ball, lit only by what the balls reflect */
    int f0 = SIZE / 2 + 6, f1 = SIZE / 2 + 16;
    double lr = mean(img, 0, 8, 30, f0, f1), lg = mean(img, 1, 8, 30, f0, f1);
    double rr = mean(img, 0, 34, 56, f0, f1), rg = mean(img, 1, 34, 56, f0, f1);
    CHECK(lr > 1e-3 && rg > 1e-3);
    CHECK(lr > 3 * lg);
    CHECK(rg > 3 * rr);
    CHECK(stat_count(st, "instances/radiosity_fills") >= 2);
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* The ball as an instance, and as a sphere placed directly: the same
 * picture within noise (the master is diced by distance, the copy by its
 * projection). */
static void test_instance_renders_as_copy(void)
{
    RayesImage *img[2];
    for (int k = 0; k < 2; k++) {
        RayesScene *s = stage();
        if (k == 0)
            define_ball(s);
        RayesParam c = color("Cs", 0.9f, 0.6f, 0.3f);
        CHECK(rayes_scene_set_shader(s, "matte", &c, 1) == RAYES_OK);
        const float m[16] = {0, 0, 1.2f, 0.3f, 0, 1.2f, 0, 0.6f, -1.2f, 0, 0, 0, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
        if (k == 0)
            CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        else
            CHECK(rayes_scene_sphere(s, 0.5f) == RAYES_OK);
        identity(s);
        img[k] = render(s, 2, 1, NULL);
        dump(img[k], k ? "instances_copy" : "instances_instance");
        rayes_scene_release(s);
    }
    for (int c = 0; c < 3; c++) {
        double a = mean(img[0], c, 0, SIZE, 0, SIZE), b = mean(img[1], c, 0, SIZE, 0, SIZE);
        CHECK_NEAR(a / b, 1.0, 0.01);
        for (int ty = 0; ty < SIZE; ty += 16) /* 16 x 16 tiles */
            for (int tx = 0; tx < SIZE; tx += 16) {
                double ta = mean(img[0], c, tx, tx + 16, ty, ty + 16);
                double tb = mean(img[1], c, tx, tx + 16, ty, ty + 16);
                CHECK(fabs(ta - tb) <= 0.03 * tb + 2e-3);
            }
    }
    rayes_image_free(img[0]);
    rayes_image_free(img[1]);
}

/* Nested instances: a "pair" of balls instanced twice is four balls; the
 * same bytes with 1 and 3 threads. */
static void test_nested_and_deterministic(void)
{
    RayesImage *img[2];
    for (int k = 0; k < 2; k++) {
        RayesScene *s = stage();
        define_ball(s);
        CHECK(rayes_scene_object_begin(s, "pair") == RAYES_OK);
        translate(s, -0.6f, 0, 0);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        translate(s, 0.6f, 0, 0);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
        RayesParam c = color("Cs", 0.3f, 0.5f, 0.9f);
        CHECK(rayes_scene_set_shader(s, "matte", &c, 1) == RAYES_OK);
        translate(s, -1.3f, 0.5f, 0);
        CHECK(rayes_scene_object_instance(s, "pair") == RAYES_OK);
        translate(s, 1.3f, 0.5f, 1);
        CHECK(rayes_scene_object_instance(s, "pair") == RAYES_OK);
        CHECK(rayes_scene_instance_count(s) == 4);
        RayesStats *st = NULL;
        img[k] = render(s, k ? 3 : 1, 2, &st);
        CHECK(stat_count(st, "instances/count") == 4); /* flattened: four balls */
        rayes_stats_free(st);
        rayes_scene_release(s);
    }
    CHECK(memcmp(img[0]->rgba, img[1]->rgba, sizeof(float) * 4 * SIZE * SIZE) == 0);
    dump(img[0], "instances_nested");
    /* four balls: blue-ish pixels in four places along the middle row band */
    int blue = 0;
    for (int x = 0; x < SIZE; x++) {
        const float *p = &img[0]->rgba[4 * ((SIZE / 2 + 2) * SIZE + x)];
        blue += p[2] > 1.3f * p[0] && p[2] > 0.02f;
    }
    CHECK(blue > 8);
    rayes_image_free(img[0]);
    rayes_image_free(img[1]);
}

/* The mean absolute difference of two images' RGB. */
static double mean_diff(const RayesImage *a, const RayesImage *b)
{
    double t = 0;
    for (int i = 0; i < SIZE * SIZE; i++)
        for (int c = 0; c < 3; c++)
            t += fabs(a->rgba[4 * i + c] - b->rgba[4 * i + c]);
    return t / (3.0 * SIZE * SIZE);
}

/* Light links per instance: a ball linked to no light is dark where the
 * other is lit. And an enclosing instance invisible to every ray hides
 * the instances nested in it even when their block gave them a visible
 * object of their own: the picture is the one without it (but for ray
 * offsets, which follow the scene's bounds), unlike a visible one. */
static void test_instance_links_and_visibility(void)
{
    RayesScene *s = stage();
    define_ball(s);
    const size_t light0 = 0;
    RayesParam white = color("Cs", 1, 1, 1);
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_EXCEPT, &light0, 1) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &white, 1) == RAYES_OK);
    translate(s, 1, 0.5f, 0); /* the image's left */
    CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    CHECK(rayes_scene_set_light_links(s, RAYES_LIGHT_LINKS_ALL, NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", &white, 1) == RAYES_OK);
    translate(s, -1, 0.5f, 0);
    CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
    RayesImage *img = render(s, 2, 1, NULL);
    int y0 = SIZE / 2 - 6, y1 = SIZE / 2 + 2;
    double unlit = mean(img, 1, 16, 24, y0, y1), lit = mean(img, 1, 40, 48, y0, y1);
    CHECK(lit > 0.05);
    CHECK(unlit < 0.25 * lit);
    rayes_image_free(img);
    rayes_scene_release(s);

    RayesImage *img3[3];
    for (int k = 0; k < 3; k++) {
        s = stage();
        define_ball(s);
        CHECK(rayes_scene_object_begin(s, "pair") == RAYES_OK);
        RayesParam blue = color("Cs", 0.2f, 0.3f, 1);
        CHECK(rayes_scene_set_shader(s, "matte", &blue, 1) == RAYES_OK); /* visible */
        translate(s, -0.6f, 0, 0);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        translate(s, 0.6f, 0, 0);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
        if (k < 2) {
            if (k == 0)
                CHECK(rayes_scene_set_visibility(s, 0) == RAYES_OK);
            CHECK(rayes_scene_set_shader(s, "matte", &white, 1) == RAYES_OK);
            translate(s, 0, 0.5f, 0);
            CHECK(rayes_scene_object_instance(s, "pair") == RAYES_OK);
        }
        img3[k] = render(s, 2, 1, NULL);
        rayes_scene_release(s);
    }
    double hidden = mean_diff(img3[0], img3[2]), shown = mean_diff(img3[1], img3[2]);
    CHECK(hidden < 2e-3);
    CHECK(shown > 10 * hidden && shown > 5e-3);
    for (int k = 0; k < 3; k++)
        rayes_image_free(img3[k]);
}

/* The grid hider (with irradiance interpolation) shades a master's grids
 * once per instance: the balls of differently coloured instances keep
 * their colours, the picture agrees with the ray-tracing hider's, and it
 * does not depend on threads. */
static void test_grid_hider(void)
{
    RayesImage *img[3];
    for (int k = 0; k < 3; k++) {
        RayesScene *s = stage();
        define_ball(s);
        RayesParam red = color("Cs", 1, 0.1f, 0.1f), green = color("Cs", 0.1f, 1, 0.1f);
        CHECK(rayes_scene_set_shader(s, "matte", &red, 1) == RAYES_OK);
        translate(s, 1, 0.5f, 0);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        CHECK(rayes_scene_set_shader(s, "matte", &green, 1) == RAYES_OK);
        translate(s, -1, 0.5f, 0);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        img[k] = render_hider(s, k == 2 ? 1 : 2, 1, k != 0, NULL);
        dump(img[k], k ? "instances_hider" : "instances_raytrace");
        rayes_scene_release(s);
    }
    int y0 = SIZE / 2 - 6, y1 = SIZE / 2 + 2;
    CHECK(mean(img[1], 0, 16, 24, y0, y1) > 4 * mean(img[1], 1, 16, 24, y0, y1)); /* red */
    CHECK(mean(img[1], 1, 40, 48, y0, y1) > 4 * mean(img[1], 0, 40, 48, y0, y1)); /* green */
    for (int c = 0; c < 3; c++) {
        double a = mean(img[0], c, 8, 56, 16, 48), b = mean(img[1], c, 8, 56, 16, 48);
        CHECK_NEAR(b / a, 1.0, 0.03);
    }
    CHECK(memcmp(img[1]->rgba, img[2]->rgba, sizeof(float) * 4 * SIZE * SIZE) == 0);
    for (int k = 0; k < 3; k++)
        rayes_image_free(img[k]);
}

static void test_errors(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_object_instance(s, "nothing") == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "nothing") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_object_end(s) == RAYES_ERROR_INVALID_OPERATION);
    CHECK(rayes_scene_object_begin(s, "a") == RAYES_OK);
    CHECK(rayes_scene_object_begin(s, "b") == RAYES_ERROR_INVALID_OPERATION);
    CHECK(rayes_scene_object_instance(s, "a") == RAYES_ERROR_INVALID_ARGUMENT); /* itself */
    RayesParam I = {"intensity", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL};
    CHECK(rayes_scene_light(s, "pointlight", &I, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    const float bound[6] = {0, 1, 0, 1, 0, 1};
    CHECK(rayes_scene_volume(s, bound) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_commit(s) == RAYES_ERROR_INVALID_OPERATION);
    CHECK(rayes_scene_object_end(s) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    /* blocks of two instances of the one before: 2^k placements; past
     * 2^24 flattened instances, an error instead of an explosion */
    CHECK(rayes_scene_object_begin(s, "n0") == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1) == RAYES_OK);
    CHECK(rayes_scene_object_end(s) == RAYES_OK);
    RayesError last = RAYES_OK;
    int level = 1;
    for (; level <= 30 && last == RAYES_OK; level++) {
        char name[16], prev[16];
        snprintf(name, sizeof name, "n%d", level);
        snprintf(prev, sizeof prev, "n%d", level - 1);
        CHECK(rayes_scene_object_begin(s, name) == RAYES_OK);
        last = rayes_scene_object_instance(s, prev);
        if (last == RAYES_OK)
            last = rayes_scene_object_instance(s, prev);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
    }
    CHECK(last == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(level - 1 == 25); /* n24 holds 2^24 placements; n25 would hold 2^25 */
    rayes_scene_clear_error(s);
    /* a projective transform is refused where it is set
     * (tests/scene/test_extent.c); a homogeneous scale is divided out, so
     * an instance's transform is affine with w = 1, as Embree takes it */
    const float proj[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 1, 1};
    CHECK(rayes_scene_set_transform(s, proj) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_clear_error(s);
    const float halve[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2};
    CHECK(rayes_scene_set_transform(s, halve) == RAYES_OK);
    CHECK(rayes_scene_object_instance(s, "a") == RAYES_OK);
    rayes_scene_release(s);
}

/* Attributes set inside a block do not leak out of it. */
static void test_block_restores_state(void)
{
    RayesScene *s = stage();
    translate(s, 0, 1, 0);
    CHECK(rayes_scene_object_begin(s, "x") == RAYES_OK);
    RayesParam red = color("Cs", 1, 0, 0);
    CHECK(rayes_scene_set_shader(s, "matte", &red, 1) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 0.5f) == RAYES_OK);
    CHECK(rayes_scene_object_end(s) == RAYES_OK);
    size_t objects = rayes_scene_object_count(s);
    CHECK(rayes_scene_sphere(s, 0.25f) == RAYES_OK); /* the floor's white matte again */
    CHECK(rayes_scene_object_count(s) == objects);
    CHECK(rayes_scene_instance_count(s) == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_master_counted_once), TEST(test_walls_colour_instances),
          TEST(test_instances_bleed_their_own_colour), TEST(test_instance_renders_as_copy),
          TEST(test_nested_and_deterministic), TEST(test_instance_links_and_visibility),
          TEST(test_grid_hider),
          TEST(test_errors), TEST(test_block_restores_state))
