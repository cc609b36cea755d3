/*
 * Primitive variables in renders: a quad with per-vertex Cs under the
 * constant shader renders the bilinear gradient (ray-tracing and grid
 * hiders); a constant-class Cs primitive variable on a wall bleeds as the
 * shader's Cs does, to rounding (the radiosity cache's fills read the
 * vertex colours); a coarse sphere mesh with N = the unit position shades like
 * the true sphere, far closer than without N (no facets).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

enum { RES = 48 };

static RayesImage *render(RayesScene *s, RayesHider hider, int cache)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 4;
    o.threads = 2;
    o.hider = hider;
    o.cache = cache;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

/* The quad spans x and y in [-1, 1] at z = 0, seen head on from z = -4
 * with a field of view of 2 atan(1/4): it fills the image, x = -1 on the
 * image's right (camera +x is world -x when looking down +z with +y up). */
static void test_vertex_color_gradient(void)
{
    for (int hider = 0; hider < 2; hider++) {
        RayesScene *s = rayes_scene_new();
        static const float eye[3] = {0, 0, -4}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
        CHECK(rayes_scene_set_camera(s, eye, at, up, (float)(2.0 * atan(0.25) * 180.0 / M_PI)) ==
              RAYES_OK);
        CHECK(rayes_scene_set_shader(s, "constant", NULL, 0) == RAYES_OK);
        const float P[4][3] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
        const float Cs[4][3] = {{1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {1, 0, 0}}; /* red at x = -1 */
        const int nv[1] = {4}, idx[4] = {0, 1, 2, 3};
        RayesPrimvar pv = {"Cs", RAYES_PRIMVAR_VERTEX, &Cs[0][0], 4};
        CHECK(rayes_scene_polygon_mesh_pv(s, 1, nv, idx, 4, &P[0][0], &pv, 1) == RAYES_OK);
        RayesImage *img = render(s, hider ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE, 1);
        rayes_scene_release(s);
        if (!img)
            continue;
        double worst = 0.0;
        for (int y = 2; y < RES - 2; y++)
            for (int x = 2; x < RES - 2; x++) {
                const float *p = img->rgba + 4 * ((size_t)y * RES + x);
                double red = (x + 0.5) / RES; /* image x from left: world x from +1 to -1 */
                worst = fmax(worst, fabs(p[0] - red) + fabs(p[1] - (1 - red)) + fabs(p[2]));
            }
        fprintf(stderr, "hider %d: largest difference from the gradient %g\n", hider, worst);
        CHECK(worst < 0.03); /* box filter over a pixel of a linear ramp: exact but for AA */
        rayes_image_free(img);
    }
}

/* A white floor and a wall whose colour is red, given once as the
 * shader's Cs and once as a constant primitive variable: the same image,
 * colour bleeding through the cache included. */
static RayesImage *bleed(int as_primvar, int cache)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 2, -4}, at[3] = {0, 0.5f, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 50.0f) == RAYES_OK);
    RayesParam white = {"Cs", RAYES_PARAM_COLOR, {1, 1, 1}, NULL};
    CHECK(rayes_scene_set_shader(s, "matte", &white, 1) == RAYES_OK);
    const float floor[4][3] = {{-2, 0, -2}, {-2, 0, 2}, {2, 0, -2}, {2, 0, 2}};
    CHECK(rayes_scene_bilinear_patch(s, floor) == RAYES_OK);
    RayesParam red = {"Cs", RAYES_PARAM_COLOR, {1, 0.1f, 0.1f}, NULL};
    CHECK(rayes_scene_set_shader(s, "matte", as_primvar ? &white : &red, 1) == RAYES_OK);
    const float wall[4][3] = {{-2, 0, 1}, {2, 0, 1}, {-2, 2, 1}, {2, 2, 1}};
    RayesPrimvar pv = {"Cs", RAYES_PRIMVAR_CONSTANT, red.value, 1};
    CHECK(rayes_scene_bilinear_patch_pv(s, wall, &pv, as_primvar ? 1 : 0) == RAYES_OK);
    RayesParam light[2] = {{"from", RAYES_PARAM_COLOR, {0, 4, -3}, NULL},
                           {"intensity", RAYES_PARAM_FLOAT, {20, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "pointlight", light, 2) == RAYES_OK);
    RayesImage *img = render(s, RAYES_HIDER_RAYTRACE, cache);
    rayes_scene_release(s);
    return img;
}

static void test_color_bleeding(void)
{
    for (int cache = 0; cache < 2; cache++) {
        RayesImage *a = bleed(0, cache), *b = bleed(1, cache);
        CHECK(a && b);
        if (a && b) {
            double worst = 0.0;
            for (size_t i = 0; i < (size_t)RES * RES * 4; i++)
                worst = fmax(worst, fabs(a->rgba[i] - b->rgba[i]) / fmax(a->rgba[i], 1e-3));
            fprintf(stderr, "cache %d: largest relative difference %g\n", cache, worst);
            CHECK(worst < 1e-5); /* interpolated at hits: weights sum to 1 but for rounding */
            /* and the floor near the wall is reddened: more red than green */
            const float *p = a->rgba + 4 * ((size_t)(RES * 5 / 8) * RES + RES / 2);
            CHECK(p[0] > 1.1f * p[1]);
        }
        rayes_image_free(a);
        rayes_image_free(b);
    }
}

/* A lat-long sphere mesh of 8 x 16 faces, with or without N; else the
 * analytic sphere. */
static RayesScene *sphere_scene(int kind)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, -5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 30.0f) == RAYES_OK);
    RayesParam light[2] = {{"from", RAYES_PARAM_COLOR, {-1, 1, -1}, NULL},
                           {"to", RAYES_PARAM_COLOR, {0, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", light, 2) == RAYES_OK);
    if (kind == 2) {
        CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
        return s;
    }
    enum { ROWS = 8, COLS = 16 };
    float P[(ROWS + 1) * COLS][3];
    int nv[ROWS * COLS], idx[4 * ROWS * COLS];
    for (int j = 0; j <= ROWS; j++)
        for (int i = 0; i < COLS; i++) {
            double th = M_PI * j / ROWS, ph = 2 * M_PI * i / COLS;
            P[j * COLS + i][0] = (float)(sin(th) * cos(ph));
            P[j * COLS + i][1] = (float)cos(th);
            P[j * COLS + i][2] = (float)(sin(th) * sin(ph));
        }
    size_t nf = 0, k = 0;
    for (int j = 0; j < ROWS; j++)
        for (int i = 0; i < COLS; i++) {
            int a = j * COLS + i, b = j * COLS + (i + 1) % COLS, c = a + COLS, d = b + COLS;
            nv[nf++] = 4;
            idx[k++] = a, idx[k++] = b, idx[k++] = d, idx[k++] = c;
        }
    RayesPrimvar pv = {"N", RAYES_PRIMVAR_VERTEX, &P[0][0], (ROWS + 1) * COLS};
    CHECK(rayes_scene_polygon_mesh_pv(s, nf, nv, idx, (ROWS + 1) * COLS, &P[0][0], &pv,
                                      kind == 1) == RAYES_OK);
    return s;
}

static void test_smooth_sphere(void)
{
    RayesImage *img[3];
    for (int kind = 0; kind < 3; kind++) {
        RayesScene *s = sphere_scene(kind);
        img[kind] = render(s, RAYES_HIDER_RAYTRACE, 1);
        rayes_scene_release(s);
    }
    CHECK(img[0] && img[1] && img[2]);
    if (img[0] && img[1] && img[2]) {
        /* over pixels all three cover, away from the silhouette */
        double err[2] = {0, 0};
        int n = 0;
        for (size_t i = 0; i < (size_t)RES * RES; i++) {
            if (img[0]->rgba[4 * i + 3] < 1 || img[1]->rgba[4 * i + 3] < 1 ||
                img[2]->rgba[4 * i + 3] < 1)
                continue;
            for (int k = 0; k < 2; k++) {
                double d = img[k]->rgba[4 * i] - img[2]->rgba[4 * i];
                err[k] += d * d;
            }
            n++;
        }
        CHECK(n > 200);
        for (int k = 0; k < 2; k++)
            err[k] = sqrt(err[k] / (n ? n : 1));
        fprintf(stderr, "RMS against the true sphere: flat %.4f, smooth %.4f\n", err[0], err[1]);
        CHECK(err[1] < 0.4 * err[0]);
    }
    for (int kind = 0; kind < 3; kind++)
        rayes_image_free(img[kind]);
}

TEST_MAIN(TEST(test_vertex_color_gradient), TEST(test_color_bleeding), TEST(test_smooth_sphere))
