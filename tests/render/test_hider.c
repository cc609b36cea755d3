/*
 * The grid hider (render/hider.c): it agrees with the ray-tracing hider on
 * a diffuse scene (image and 16 x 16 tile means, within noise), gives the
 * same bytes for any thread count, shades each visible grid vertex once
 * (depth-0 shading points do not grow with pixel samples), and shades
 * sharp mirrors where the camera rays hit them.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

static RayesImage *render_irr(RayesHider hider, int irradiance, int threads, int spp, int rays,
                              uint64_t *depth0, uint64_t *records)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 64;
    o.spp = spp;
    o.threads = threads;
    o.shadow_rays = o.shadow_rays_deep = rays;
    o.diffuse_rays = rays;
    o.hider = hider;
    o.irradiance = irradiance;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *sp = rayes_stats_find(st, "shading_points/by_depth");
    CHECK(sp && sp->n_counts > 0);
    if (depth0)
        *depth0 = sp && sp->n_counts ? sp->counts[0] : 0;
    const RayesStat *rec = rayes_stats_find(st, "irradiance/records");
    CHECK((rec != NULL) == (irradiance != 0));
    if (records)
        *records = rec ? rec->count : 0;
    rayes_stats_free(st);
    rayes_scene_release(s);
    return img;
}

static RayesImage *render(RayesHider hider, int threads, int spp, int rays, uint64_t *depth0)
{
    return render_irr(hider, 0, threads, spp, rays, depth0, NULL);
}

static double tile_mean(const RayesImage *img, int x0, int y0, int size)
{
    double sum = 0.0;
    for (int y = y0; y < y0 + size; y++)
        for (int x = x0; x < x0 + size; x++)
            for (int c = 0; c < 3; c++)
                sum += img->rgba[4 * ((size_t)y * img->width + x) + c];
    return sum / (3.0 * size * size);
}

/* Image means within 1%, 16 x 16 tile means within tile_tol. */
static void check_agree(const RayesImage *a, const RayesImage *b, double tile_tol)
{
    CHECK(a && b);
    if (!a || !b)
        return;
    double ma = tile_mean(a, 0, 0, 64), mb = tile_mean(b, 0, 0, 64);
    CHECK(fabs(mb - ma) < 0.01 * ma);
    double worst = 0.0;
    for (int y = 0; y < 64; y += 16)
        for (int x = 0; x < 64; x += 16) {
            double ta = tile_mean(a, x, y, 16), tb = tile_mean(b, x, y, 16);
            if (ta > 0.02 * ma)
                worst = fmax(worst, fabs(tb - ta) / ta);
        }
    CHECK(worst < tile_tol);
    if (worst >= tile_tol || fabs(mb - ma) >= 0.01 * ma)
        fprintf(stderr, "  means %g %g, worst tile %.3f\n", ma, mb, worst);
}

static void test_agrees_with_raytrace(void)
{
    RayesImage *a = render(RAYES_HIDER_RAYTRACE, 2, 16, 16, NULL);
    RayesImage *b = render(RAYES_HIDER_GRID, 2, 16, 16, NULL);
    check_agree(a, b, 0.05);
    rayes_image_free(a);
    rayes_image_free(b);
}

/* Irradiance interpolation with gradients: records at a fraction of the
 * vertices, the same picture within noise, the same bytes for any thread
 * count. */
static void test_irradiance_interpolation(void)
{
    uint64_t d_off, d_on, records;
    RayesImage *a = render_irr(RAYES_HIDER_GRID, 0, 2, 1, 256, &d_off, NULL);
    RayesImage *b = render_irr(RAYES_HIDER_GRID, 1, 2, 1, 256, &d_on, &records);
    RayesImage *c = render_irr(RAYES_HIDER_GRID, 1, 1, 1, 256, NULL, NULL);
    check_agree(a, b, 0.03);
    /* Nearly the same shading points: the grid's vertices, plus samples on
     * micropolygons too contrasted to interpolate, which depend on values. */
    CHECK(d_on > d_off * 19 / 20 && d_on < d_off * 21 / 20);
    CHECK(records > 0 && records < d_on * 3 / 4);
    CHECK(b && c && memcmp(b->rgba, c->rgba, sizeof(float) * 4 * 64 * 64) == 0);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
}

static void test_any_thread_count(void)
{
    RayesImage *a = render(RAYES_HIDER_GRID, 1, 2, 4, NULL);
    RayesImage *b = render(RAYES_HIDER_GRID, 3, 2, 4, NULL);
    CHECK(a && b && memcmp(a->rgba, b->rgba, sizeof(float) * 4 * 64 * 64) == 0);
    rayes_image_free(a);
    rayes_image_free(b);
}

static void test_shading_follows_vertices(void)
{
    uint64_t grid1, grid16, ray1, ray16;
    rayes_image_free(render(RAYES_HIDER_GRID, 2, 1, 1, &grid1));
    rayes_image_free(render(RAYES_HIDER_GRID, 2, 16, 1, &grid16));
    rayes_image_free(render(RAYES_HIDER_RAYTRACE, 2, 1, 1, &ray1));
    rayes_image_free(render(RAYES_HIDER_RAYTRACE, 2, 16, 1, &ray16));
    CHECK(ray16 > 15 * ray1 && ray16 < 17 * ray1); /* one shading point per camera hit */
    CHECK(grid16 < grid1 + grid1 / 10);   /* a few more grids hit, no more per grid */
    CHECK(grid16 < ray16 / 4);
}

/* The chrome teapot reflects the light (radiance 17) in highlights smaller
 * than a micropolygon: the grid hider shades such micropolygons per sample
 * (with the ray-tracing hider's keys) instead of smearing a vertex's
 * highlight over them, so no pixel is far from the ray-traced image. */
static void test_highlights_not_smeared(void)
{
    RayesImage *img[2];
    for (int h = 0; h < 2; h++) {
        RayesScene *s = rayes_scene_new();
        char err[512];
        IoSink sink = io_sink_scene(s);
        CHECK(io_builtin_scene("cornell-teapots", RAYES_TEST_DATA, &sink, err, sizeof err) == RAYES_OK);
        CHECK(rayes_scene_commit(s) == RAYES_OK);
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = 96;
        o.spp = 2;
        o.shadow_rays = o.shadow_rays_deep = 64;
        o.diffuse_rays = 64;
        o.hider = h ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE;
        img[h] = NULL;
        CHECK(rayes_render(s, &o, &img[h], NULL) == RAYES_OK);
        rayes_scene_release(s);
    }
    if (img[0] && img[1]) {
        float worst = 0.0f;
        for (int i = 0; i < 96 * 96 * 4; i++)
            worst = fmaxf(worst, fabsf(img[0]->rgba[i] - img[1]->rgba[i]));
        CHECK(worst < 1.0f);
        if (worst >= 1.0f)
            fprintf(stderr, "  largest pixel difference %g\n", worst);
    }
    rayes_image_free(img[0]);
    rayes_image_free(img[1]);
}

/* A chrome ball (the only thing the camera sees) reflects a small light
 * and a diffuse wall behind the camera: the light's image in it is far
 * smaller than a micropolygon. A grid whose shading traces perfect mirror
 * or refraction rays is shaded where each camera ray hits it, as the
 * ray-tracing hider shades it, so both hiders give the same bytes (shaded
 * at its vertices and interpolated, every pixel of the ball would differ
 * and the light's image would be lost or smeared). */
static RayesImage *render_chrome_ball(RayesHider hider)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, 6}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    static const float at_light[16] = {1, 0, 0, 3, 0, 1, 0, 4, 0, 0, 1, 5, 0, 0, 0, 1};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 25.0f) == RAYES_OK);
    RayesParam chrome = {"specularcolor", RAYES_PARAM_COLOR, {0.9f, 0.9f, 0.9f}, NULL};
    CHECK(rayes_scene_set_shader(s, "mirror", &chrome, 1) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesParam kd = {"Kd", RAYES_PARAM_FLOAT, {0.8f, 0, 0}, NULL};
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    const float wall[4][3] = {{-20, -20, 12}, {20, -20, 12}, {-20, 20, 12}, {20, 20, 12}};
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    RayesParam light[3] = {{"shape", RAYES_PARAM_STRING, {0, 0, 0}, "sphere"},
                           {"radius", RAYES_PARAM_FLOAT, {0.3f, 0, 0}, NULL},
                           {"intensity", RAYES_PARAM_FLOAT, {400.0f, 0, 0}, NULL}};
    CHECK(rayes_scene_set_transform(s, at_light) == RAYES_OK);
    CHECK(rayes_scene_light(s, "arealight", light, 3) == RAYES_OK);
    CHECK(rayes_scene_set_transform(s, identity) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 48;
    o.spp = 4;
    o.threads = 2;
    o.bounces = 0;
    o.hider = hider;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static void test_sharp_reflections_per_sample(void)
{
    RayesImage *a = render_chrome_ball(RAYES_HIDER_RAYTRACE), *b = render_chrome_ball(RAYES_HIDER_GRID);
    CHECK(a && b);
    if (a && b) {
        size_t n = (size_t)48 * 48, differ = 0;
        float brightest = 0.0f;
        for (size_t i = 0; i < n; i++) {
            differ += memcmp(a->rgba + 4 * i, b->rgba + 4 * i, 3 * sizeof(float)) != 0;
            brightest = fmaxf(brightest, a->rgba[4 * i]);
        }
        CHECK(differ == 0);
        CHECK(brightest > 1.0f); /* the light's image is in the picture */
        if (differ)
            fprintf(stderr, "  %zu of %zu pixels differ between the hiders\n", differ, n);
    }
    rayes_image_free(a);
    rayes_image_free(b);
}

TEST_MAIN(TEST(test_agrees_with_raytrace), TEST(test_highlights_not_smeared),
          TEST_THREADS(test_irradiance_interpolation), TEST_THREADS(test_any_thread_count),
          TEST(test_sharp_reflections_per_sample), TEST(test_shading_follows_vertices))
