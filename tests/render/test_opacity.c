/*
 * Opacity (memo 6.1) in renders: stacked coloured sheets transmit the
 * product of (1 - Os) whatever their order; a half-transparent sheet
 * halves a light's irradiance; ambient occlusion under a plane (with a
 * maximum distance) and against a wall matches its closed forms; a
 * cut-out (an Os pattern) shadows like the same cut-out made of geometry;
 * the opacity cache gives the uncached image within noise, and images do
 * not depend on threads or the cache budget. Also thin glass and
 * diffuse transmission (pbrt-v4's thindielectric, diffusetransmission).
 *
 * The scenes look down at a floor (z = 0, x and y in [-2, 2]) from above;
 * sheets are invisible to the camera (visibility) unless a test says so,
 * so that pixels show the floor's light.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cache_stats.h"
#include "rayes/rayes.h"
#include "rayes/shader.h"
#include "test.h"

enum { RES = 32 };

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static RayesParam pc(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}

static RayesParam ps(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

/* The camera 6 above the floor's centre, seeing [-1, 1]^2 of it. */
static RayesScene *new_scene(void)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 6}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, (float)(2.0 * atan(1.0 / 6.0) * 180.0 / M_PI)) ==
          RAYES_OK);
    return s;
}

static void quad_at(RayesScene *s, float half, float z)
{
    /* P00, P10, P01, P11 */
    const float P[4][3] = {{-half, -half, z}, {half, -half, z}, {-half, half, z}, {half, half, z}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
}

/* A constant (unlit) floor is no use: a matte floor, Kd 1, no bounces. */
static void floor_matte(RayesScene *s)
{
    RayesParam m[1] = {pf("Ka", 0.0f)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 1) == RAYES_OK);
    quad_at(s, 2.0f, 0.0f);
}

static void point_light(RayesScene *s, float z)
{
    RayesParam p[2] = {(RayesParam){"from", RAYES_PARAM_COLOR, {0, 0, z}, NULL},
                       pf("intensity", z * z)};
    CHECK(rayes_scene_light(s, "pointlight", p, 2) == RAYES_OK);
}

static RayesImage *render(RayesScene *s, int threads, double cache_mb, int opacity_cache,
                          int quality, RayesStats **stats)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, (RayesQuality)quality);
    o.width = o.height = RES;
    o.spp = 1;
    o.threads = threads;
    o.bounces = 0;
    o.opacity_cache = opacity_cache;
    o.opacity_cache_mb = cache_mb;
    if (cache_mb < 1.0) /* a budget meant to evict: no other type's to borrow */
        o.cache_mb = o.irradiance_cache_mb = 0.0, o.env_guide = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

static void mean_rgb(const RayesImage *img, double out[3])
{
    out[0] = out[1] = out[2] = 0.0;
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++)
            out[c] += img->rgba[4 * i + c] / (double)n;
}

/* The floor's mean colour under sheets of opacities os[k] (in that order
 * from the floor up), seen by shadow rays only. */
static void floor_under_sheets(const float (*os)[3], int n, double out[3])
{
    RayesScene *s = new_scene();
    floor_matte(s);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_SHADOW) == RAYES_OK);
    for (int k = 0; k < n; k++) {
        RayesParam p[1] = {pc("Os", os[k][0], os[k][1], os[k][2])};
        CHECK(rayes_scene_set_shader(s, "matte", p, 1) == RAYES_OK);
        quad_at(s, 3.0f, 1.0f + 0.5f * (float)k);
    }
    point_light(s, 5.0f);
    RayesImage *img = render(s, 2, 20.0, 1, RAYES_QUALITY_PREVIEW, NULL);
    if (img)
        mean_rgb(img, out);
    rayes_image_free(img);
    rayes_scene_release(s);
}

static void test_stacked_sheets_multiply_in_any_order(void)
{
    static const float os[3][3] = {{0.5f, 0.2f, 0.1f}, {0.25f, 0.75f, 0.0f}, {0.1f, 0.1f, 0.9f}};
    static const float rev[3][3] = {{0.1f, 0.1f, 0.9f}, {0.25f, 0.75f, 0.0f}, {0.5f, 0.2f, 0.1f}};
    double open[3], a[3], b[3];
    floor_under_sheets(NULL, 0, open);
    floor_under_sheets(os, 3, a);
    floor_under_sheets(rev, 3, b);
    for (int c = 0; c < 3; c++) {
        double want = open[c] * (1 - os[0][c]) * (1 - os[1][c]) * (1 - os[2][c]);
        CHECK(open[c] > 0.1);
        CHECK_NEAR(a[c], want, 1e-5 * open[c]);
        CHECK_NEAR(b[c], want, 1e-5 * open[c]);
    }
}

static void test_half_transparent_sheet_halves_irradiance(void)
{
    static const float half[1][3] = {{0.5f, 0.5f, 0.5f}}, opaque[1][3] = {{1, 1, 1}};
    double open[3], got[3], none[3];
    floor_under_sheets(NULL, 0, open);
    floor_under_sheets(half, 1, got);
    floor_under_sheets(opaque, 1, none);
    for (int c = 0; c < 3; c++) {
        CHECK_NEAR(got[c] / open[c], 0.5, 1e-5);
        CHECK(none[c] == 0.0);
    }
}

/* The occlusion shader on the floor, AO rays up to maxdist (0: any). */
static double floor_occlusion(float maxdist, int wall)
{
    RayesScene *s = new_scene();
    RayesParam p[2] = {pf("samples", 1024), pf("maxdist", maxdist)};
    CHECK(rayes_scene_set_shader(s, "occlusion", p, 2) == RAYES_OK);
    quad_at(s, 1.0f, 0.0f);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_SHADOW) == RAYES_OK);
    RayesParam m[1] = {pf("Kd", 1.0f)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 1) == RAYES_OK);
    /* Large, not huge: rays leave points a millionth of the scene's size
     * times ten above them (path.h), 0.0007 here. */
    if (wall) { /* the plane x = 0, its floor side: half the hemisphere */
        const float P[4][3] = {{0, -50, -50}, {0, 50, -50}, {0, -50, 50}, {0, 50, 50}};
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    } else {
        quad_at(s, 50.0f, 1.0f); /* a plane at height 1 */
    }
    RayesImage *img = render(s, 2, 20.0, 1, RAYES_QUALITY_PREVIEW, NULL);
    double m3[3] = {0, 0, 0};
    if (img)
        mean_rgb(img, m3);
    rayes_image_free(img);
    rayes_scene_release(s);
    return 1.0 - m3[0]; /* the occlusion */
}

static void test_ambient_occlusion_closed_forms(void)
{
    /* Under a plane at height h, directions within maxdist have cos >= h /
     * maxdist: a cosine-weighted fraction 1 - (h / maxdist)^2. */
    CHECK_NEAR(floor_occlusion(0.0f, 0), 1.0, 1e-3); /* but grazing rays past the plane's end */
    CHECK_NEAR(floor_occlusion(2.0f, 0), 0.75, 0.01);
    CHECK_NEAR(floor_occlusion(1.25f, 0), 1.0 - 0.64, 0.01);
    /* Beside an infinite wall, half the hemisphere (its pixels on both
     * sides of it, the wall's half each). */
    CHECK_NEAR(floor_occlusion(0.0f, 1), 0.5, 0.01);
}

/* The floor's image under a square at height 1 that is a checkerboard:
 * cut out of an opaque square by an Os pattern, or made of its opaque
 * cells as geometry. */
static RayesImage *checker_shadow(int as_pattern, int opacity_cache)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_SHADOW) == RAYES_OK);
    RayesParam m[1] = {pf("Kd", 1.0f)};
    if (as_pattern) {
        RayesParam cb[2] = {pf("uscale", 4.0f), pf("vscale", 4.0f)};
        CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cb, 2) == RAYES_OK);
        RayesParam p[2] = {m[0], (RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "cells"}};
        CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
        quad_at(s, 1.0f, 1.0f);
    } else {
        CHECK(rayes_scene_set_shader(s, "matte", m, 1) == RAYES_OK);
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++) {
                if ((i + j) % 2 == 0) /* tex1 (1, opaque) where floor(u) + floor(v) is even,
                                         v = 1 - t running down y */
                    continue;
                float x0 = -1.0f + 0.5f * (float)i, y0 = -1.0f + 0.5f * (float)j;
                const float P[4][3] = {
                    {x0, y0, 1}, {x0 + 0.5f, y0, 1}, {x0, y0 + 0.5f, 1}, {x0 + 0.5f, y0 + 0.5f, 1}};
                CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
            }
    }
    point_light(s, 5.0f);
    RayesImage *img = render(s, 2, 20.0, opacity_cache, RAYES_QUALITY_PREVIEW, NULL);
    rayes_scene_release(s);
    return img;
}

static void test_cutout_shadow_matches_geometry(void)
{
    for (int cached = 0; cached < 2; cached++) {
        RayesImage *a = checker_shadow(1, cached), *b = checker_shadow(0, cached);
        if (!a || !b) {
            rayes_image_free(a);
            rayes_image_free(b);
            continue;
        }
        /* Pixels differ only along the cells' edges, where the pattern is
         * filtered over a cache level's spacing (or a shadow ray's
         * footprint): count the pixels that disagree by more than a tenth. */
        int differ = 0;
        double ma[3], mb[3];
        for (int i = 0; i < RES * RES; i++)
            differ += fabsf(a->rgba[4 * i] - b->rgba[4 * i]) > 0.1f * fmaxf(b->rgba[4 * i], 0.05f);
        mean_rgb(a, ma);
        mean_rgb(b, mb);
        fprintf(stderr, "cut-out (%s): %d of %d pixels differ, means %g and %g\n",
                cached ? "cached" : "uncached", differ, RES * RES, ma[0], mb[0]);
        CHECK(differ < RES * RES * 4 / 10); /* the edges of 16 cells on 32 x 32 pixels */
        CHECK_NEAR(ma[0] / mb[0], 1.0, 0.01);
        rayes_image_free(a);
        rayes_image_free(b);
    }
}

/* Pixels of a floor image strictly between shadowed and lit (a tenth to
 * nine tenths of the brightest): the blurred ones. */
static int blurred_pixels(const RayesImage *img)
{
    float top = 0.0f;
    for (int i = 0; i < RES * RES; i++)
        top = fmaxf(top, img->rgba[4 * i]);
    int n = 0;
    for (int i = 0; i < RES * RES; i++)
        n += img->rgba[4 * i] > 0.1f * top && img->rgba[4 * i] < 0.9f * top;
    return n;
}

/* A distant light straight down casts a cut-out's shadow as sharp as the
 * cut-out however high it hangs: the shadow ray of a delta light carries
 * the floor point's footprint, not the camera's spread (at 20 units that
 * spread is 0.2, two fifths of a cell), at normal incidence the footprint
 * is not lost to rounding (it was, in patches: the pattern then
 * point-sampled there and filtered beside), and with the opacity cache the
 * cut-out, diced coarsely behind the eye, is asked at the hit since its
 * cached points lie too far apart for such a fine ray. */
static void test_cutout_shadow_from_afar_is_sharp(void)
{
    for (int cached = 0; cached < 2; cached++) {
        RayesScene *s = new_scene();
        floor_matte(s);
        CHECK(rayes_scene_set_visibility(s, RAYES_RAY_SHADOW) == RAYES_OK);
        RayesParam cb[2] = {pf("uscale", 4.0f), pf("vscale", 4.0f)};
        CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cb, 2) == RAYES_OK);
        RayesParam p[2] = {pf("Kd", 1.0f),
                           (RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "cells"}};
        CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
        quad_at(s, 1.0f, 20.0f);
        RayesParam l[3] = {(RayesParam){"from", RAYES_PARAM_COLOR, {0, 0, 1}, NULL},
                           (RayesParam){"to", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                           pf("intensity", 1)};
        CHECK(rayes_scene_light(s, "distantlight", l, 3) == RAYES_OK);
        RayesImage *img = render(s, 2, 20.0, cached, RAYES_QUALITY_PREVIEW, NULL);
        rayes_scene_release(s);
        if (!img)
            continue;
        /* the cells' 6 inner edges run 32 pixels each, between pixels: at
         * most the pixels either side of them blurred (705 uncached with
         * the camera's spread; cached from the coarse grid, 1002) */
        int blurred = blurred_pixels(img);
        fprintf(stderr, "cut-out at 20 units (%s): %d of %d pixels blurred\n",
                cached ? "cached" : "uncached", blurred, RES * RES);
        CHECK(blurred <= 6 * 32 * 2);
        rayes_image_free(img);
    }
}

/* A curved stained-glass sheet (the stainedglass shader's opacity method,
 * coloured) over the floor under an area light, camera-visible. */
static RayesScene *stained_glass_scene(void)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam g[1] = {pf("frequency", 2.0f)};
    CHECK(rayes_scene_set_shader(s, "stainedglass", g, 1) == RAYES_OK);
    const float P[16][3] = {
        {-1, -1, 1},    {-0.3f, -1, 1.6f},    {0.3f, -1, 1.6f},    {1, -1, 1},
        {-1, -0.3f, 1}, {-0.3f, -0.3f, 1.6f}, {0.3f, -0.3f, 1.6f}, {1, -0.3f, 1},
        {-1, 0.3f, 1},  {-0.3f, 0.3f, 1.6f},  {0.3f, 0.3f, 1.6f},  {1, 0.3f, 1},
        {-1, 1, 1},     {-0.3f, 1, 1.6f},     {0.3f, 1, 1.6f},     {1, 1, 1}};
    CHECK(rayes_scene_bicubic_patch(s, P) == RAYES_OK);
    /* beside the view (which it would fill, seen from behind, above it) */
    const float L[4][3] = {{1.5f, -0.5f, 4}, {1.5f, 0.5f, 4}, {2.5f, 0.5f, 4}, {2.5f, -0.5f, 4}};
    const float Le[3] = {10, 10, 10};
    CHECK(rayes_scene_area_light(s, L, Le) == RAYES_OK);
    return s;
}

static void test_opacity_cache_within_noise_and_deterministic(void)
{
    RayesScene *s = stained_glass_scene();
    RayesStats *st = NULL;
    RayesImage *cached = render(s, 2, 20.0, 1, RAYES_QUALITY_FINAL, &st);
    RayesImage *uncached = render(s, 2, 20.0, 0, RAYES_QUALITY_FINAL, NULL);
    RayesImage *one = render(s, 1, 20.0, 1, RAYES_QUALITY_FINAL, NULL);
    RayesStats *tiny_st = NULL;
    RayesImage *tiny = render(s, 3, 0.002, 1, RAYES_QUALITY_FINAL, &tiny_st);
    /* refilled: the budget holds too little (here, not one entry) */
    CHECK(test_cache_count(tiny_st, "opacity", "fills") > test_cache_count(st, "opacity", "fills"));
    rayes_stats_free(tiny_st);
    if (cached && uncached && one && tiny) {
        double a[3], b[3];
        mean_rgb(cached, a);
        mean_rgb(uncached, b);
        fprintf(stderr, "stained glass: cached %g %g %g, uncached %g %g %g\n", a[0], a[1], a[2],
                b[0], b[1], b[2]);
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(a[c] / b[c], 1.0, 0.01);
        size_t bytes = sizeof(float) * 4 * RES * RES;
        CHECK(memcmp(cached->rgba, one->rgba, bytes) == 0);
        CHECK(memcmp(cached->rgba, tiny->rgba, bytes) == 0);
        const RayesStat *hits = rayes_stats_find(st, "cache/opacity/fine/hits");
        const RayesStat *coarse = rayes_stats_find(st, "cache/opacity/coarse/lookups");
        CHECK(hits && coarse && hits->count + coarse->count > 0);
    }
    rayes_stats_free(st);
    rayes_image_free(cached);
    rayes_image_free(uncached);
    rayes_image_free(one);
    rayes_image_free(tiny);
    rayes_scene_release(s);
}

/* Camera rays composite a half-transparent red sheet over a white floor. */
static void test_camera_sees_through(void)
{
    RayesScene *s = new_scene();
    RayesParam c[1] = {pc("Cs", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "constant", c, 1) == RAYES_OK);
    quad_at(s, 2.0f, 0.0f);
    RayesParam r[2] = {pc("Cs", 1, 0, 0), pc("Os", 0.5f, 0.5f, 0.5f)};
    CHECK(rayes_scene_set_shader(s, "constant", r, 2) == RAYES_OK);
    quad_at(s, 3.0f, 1.0f);
    for (int quality = 0; quality < 2; quality++) {
        RayesImage *img = render(s, 2, 20.0, 1, quality, NULL);
        double m[3];
        if (!img)
            continue;
        mean_rgb(img, m);
        CHECK_NEAR(m[0], 1.0, 1e-5); /* 0.5 red + 0.5 white */
        CHECK_NEAR(m[1], 0.5, 1e-5);
        CHECK_NEAR(m[2], 0.5, 1e-5);
        CHECK(img->rgba[3] == 1.0f);
        rayes_image_free(img);
    }
    rayes_scene_release(s);
}

/* The grid hider shades a transparent object's grids once, Oi with Ci, and
 * composites them as the ray-tracing hider does: a red sheet cut into a
 * checkerboard (an Os pattern) over a white floor agrees pixel for pixel,
 * the cells' edges shaded where the rays hit (so as sharp),
 * while the sheet's depth-0 shading points no longer follow the pixel
 * samples. */
static RayesImage *checker_seen(RayesHider hider, int threads, uint64_t *depth0)
{
    RayesScene *s = new_scene();
    RayesParam white[1] = {pc("Cs", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "constant", white, 1) == RAYES_OK);
    quad_at(s, 2.0f, 0.0f);
    RayesParam cb[2] = {pf("uscale", 4.0f), pf("vscale", 4.0f)};
    CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cb, 2) == RAYES_OK);
    RayesParam p[2] = {pc("Cs", 1, 0, 0),
                       (RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "cells"}};
    CHECK(rayes_scene_set_shader(s, "constant", p, 2) == RAYES_OK);
    quad_at(s, 1.0f, 1.0f);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 64;
    o.spp = 16;
    o.threads = threads;
    o.bounces = 0;
    o.hider = hider;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *sp = rayes_stats_find(st, "shading_points/by_depth");
    *depth0 = sp && sp->n_counts ? sp->counts[0] : 0;
    rayes_stats_free(st);
    rayes_scene_release(s);
    return img;
}

static void test_grid_hider_transparent_grids(void)
{
    uint64_t n_ray, n_grid, n_one;
    RayesImage *ray = checker_seen(RAYES_HIDER_RAYTRACE, 2, &n_ray);
    RayesImage *grid = checker_seen(RAYES_HIDER_GRID, 2, &n_grid);
    RayesImage *one = checker_seen(RAYES_HIDER_GRID, 1, &n_one);
    if (ray && grid && one) {
        int differ = 0;
        double worst = 0.0;
        for (int i = 0; i < 64 * 64; i++)
            for (int c = 0; c < 4; c++) {
                double d = fabs((double)ray->rgba[4 * i + c] - grid->rgba[4 * i + c]);
                worst = fmax(worst, d);
                differ += d > 0.01;
            }
        fprintf(stderr,
                "grid hider, transparent: %d values differ by > 0.01 (worst %g); depth-0 "
                "points %llu (ray tracing %llu)\n",
                differ, worst, (unsigned long long)n_grid, (unsigned long long)n_ray);
        CHECK(differ < 64 * 64 * 4 / 100);
        CHECK(n_grid < n_ray / 2);
        CHECK(memcmp(grid->rgba, one->rgba, sizeof(float) * 4 * 64 * 64) == 0);
    }
    rayes_image_free(ray);
    rayes_image_free(grid);
    rayes_image_free(one);
}

/* A camera ray through a cut-out's hole (Os 0, no opacity method) is not
 * shaded there: a sheet whose Os pattern is 0 everywhere, in front of the
 * white floor, is one hole; every ray passes it unshaded (it was shaded
 * first, and its premultiplied colour was 0) and is shaded once, at the
 * floor, which it sees whole. */
static void test_holes_pass_unshaded(void)
{
    RayesScene *s = new_scene();
    RayesParam white[1] = {pc("Cs", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "constant", white, 1) == RAYES_OK);
    quad_at(s, 2.0f, 0.0f);
    RayesParam zero[1] = {pf("value", 0.0f)};
    CHECK(rayes_scene_pattern(s, "none", "constant", zero, 1) == RAYES_OK);
    RayesParam p[2] = {pc("Cs", 1, 0, 0),
                       (RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "none"}};
    CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
    quad_at(s, 1.0f, 1.0f);
    point_light(s, 5.0f);
    RayesStats *st = NULL;
    RayesImage *img = render(s, 2, 20.0, 1, RAYES_QUALITY_PREVIEW, &st);
    const RayesStat *sp = rayes_stats_find(st, "shading_points/by_depth");
    const RayesStat *h = rayes_stats_find(st, "opacity/holes");
    uint64_t rays = RES * RES, depth0 = sp && sp->n_counts ? sp->counts[0] : 0;
    fprintf(stderr, "holes: %llu of %llu camera rays, %llu depth-0 points\n",
            h ? (unsigned long long)h->count : 0ull, (unsigned long long)rays,
            (unsigned long long)depth0);
    CHECK(h && h->count == rays);
    CHECK(depth0 == rays);
    for (int i = 0; img && i < RES * RES; i++)
        CHECK_NEAR(img->rgba[4 * i], 1.0, 1e-6);
    rayes_image_free(img);
    rayes_stats_free(st);
    rayes_scene_release(s);
}

static void test_bad_attributes(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_visibility(s, 1u << 20) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_opacity_mode(s, (RayesTransmissionHitMode)7, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    RayesParam p[1] = {(RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "nothing"}};
    CHECK(rayes_scene_set_shader(s, "matte", p, 1) != RAYES_OK);
    (void)ps;
    rayes_scene_release(s);
}

/* A thin dielectric window (pbrt-v4's thindielectric): shadow rays pass
 * with 1 - R', R' = 2R / (1 + R) of Fresnel's R at normal incidence; the
 * camera sees the floor through it unbent, dimmed by its R' at the view
 * angle (here head on), the floor's pattern not shifted. */
static void test_thin_glass(void)
{
    const double R0 = 0.04, Rt = 2 * R0 / (1 + R0); /* eta 1.5 */
    double open[3], through[3];
    floor_under_sheets(NULL, 0, open);
    RayesScene *s = new_scene();
    floor_matte(s);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_SHADOW) == RAYES_OK);
    RayesParam eta[1] = {pf("eta", 1.5f)};
    CHECK(rayes_scene_set_shader(s, "thindielectric", eta, 1) == RAYES_OK);
    quad_at(s, 3.0f, 1.0f);
    point_light(s, 5.0f);
    RayesImage *img = render(s, 2, 20.0, 1, RAYES_QUALITY_PREVIEW, NULL);
    if (img)
        mean_rgb(img, through);
    rayes_image_free(img);
    rayes_scene_release(s);
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(through[c] / open[c], 1.0 - Rt, 1e-4);
    /* Seen by the camera too: a checkered floor through the window, the
     * same picture as without it times about 1 - R' (the camera's rays
     * are within 10 degrees of the normal; nothing to reflect but black). */
    RayesImage *pair[2];
    for (int k = 0; k < 2; k++) {
        s = new_scene();
        RayesParam cb[2] = {pf("uscale", 4.0f), pf("vscale", 4.0f)};
        CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cb, 2) == RAYES_OK);
        RayesParam p[1] = {(RayesParam){"Cs", RAYES_PARAM_PATTERN, {0, 0, 0}, "cells"}};
        CHECK(rayes_scene_set_shader(s, "constant", p, 1) == RAYES_OK);
        quad_at(s, 2.0f, 0.0f);
        if (k) {
            CHECK(rayes_scene_set_shader(s, "thindielectric", eta, 1) == RAYES_OK);
            quad_at(s, 3.0f, 1.0f);
        }
        pair[k] = render(s, 2, 20.0, 1, RAYES_QUALITY_PREVIEW, NULL);
        rayes_scene_release(s);
    }
    double worst = 0.0;
    for (size_t i = 0; pair[0] && pair[1] && i < (size_t)RES * RES; i++) {
        double a = pair[0]->rgba[4 * i], b = pair[1]->rgba[4 * i];
        worst = fmax(worst, fabs(b - (1.0 - Rt) * a));
    }
    CHECK(pair[0] && pair[1] && worst < 0.01);
    rayes_image_free(pair[0]);
    rayes_image_free(pair[1]);
}

/* pbrt-v4's diffusetransmission: a sheet lit from behind shows its
 * transmittance times that light, as a diffuse sheet of that reflectance
 * lit from the front would; lit from the front, its reflectance. */
static double sheet(const char *shader, float refl, float tran, float light_z)
{
    RayesScene *s = new_scene();
    RayesParam p[2] = {pc("reflectance", refl, refl, refl), pc("transmittance", tran, tran, tran)};
    CHECK(rayes_scene_set_shader(s, shader, p, strcmp(shader, "diffuse") ? 2 : 1) == RAYES_OK);
    quad_at(s, 2.0f, 0.0f);
    point_light(s, light_z);
    RayesImage *img = render(s, 2, 20.0, 1, RAYES_QUALITY_PREVIEW, NULL);
    double m[3] = {0, 0, 0};
    if (img)
        mean_rgb(img, m);
    rayes_image_free(img);
    rayes_scene_release(s);
    return m[1];
}

static void test_diffuse_transmission(void)
{
    double lit = sheet("diffuse", 1.0f, 0.0f, 5.0f);
    CHECK(lit > 0.05);
    CHECK_NEAR(sheet("diffusetransmission", 0.0f, 1.0f, -5.0f), lit, 1e-4 * lit);
    CHECK_NEAR(sheet("diffusetransmission", 0.0f, 1.0f, 5.0f), 0.0, 1e-6);
    CHECK_NEAR(sheet("diffusetransmission", 0.25f, 0.5f, 5.0f), 0.25 * lit, 1e-4 * lit);
    CHECK_NEAR(sheet("diffusetransmission", 0.25f, 0.5f, -5.0f), 0.5 * lit, 1e-4 * lit);
}

/* Cut-out squares (a checkerboard Os) over a lit floor, one placed once
 * and three as instances of a master, with a bounce and the coarse cache
 * level forced: shadow and diffuse rays read the squares' coarse opacity
 * from the opacity table (optable.h). Rendered with the instances'
 * tables and without (a budget too small for one: the cache serves them),
 * on one thread and two, the bytes are the same. */
static RayesImage *cutout_instances(int threads, double opacity_mb, RayesStats **st)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam cb[2] = {pf("uscale", 4.0f), pf("vscale", 4.0f)};
    CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cb, 2) == RAYES_OK);
    RayesParam p[2] = {pf("Kd", 1.0f), (RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "cells"}};
    CHECK(rayes_scene_object_begin(s, "leaf") == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
    quad_at(s, 0.1f, 0.0f);
    CHECK(rayes_scene_object_end(s) == RAYES_OK);
    const float at[3][3] = {{-0.5f, -0.5f, 2.0f}, {0.5f, -0.4f, 2.4f}, {0.0f, 0.5f, 2.8f}};
    for (int k = 0; k < 4; k++) { /* then back to the identity */
        const float m[16] = {1, 0, 0, k < 3 ? at[k][0] : 0, 0, 1, 0, k < 3 ? at[k][1] : 0,
                             0, 0, 1, k < 3 ? at[k][2] : 0, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
        if (k < 3)
            CHECK(rayes_scene_object_instance(s, "leaf") == RAYES_OK);
    }
    CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
    quad_at(s, 0.1f, 1.6f);
    point_light(s, 5.0f);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 1;
    o.threads = threads;
    o.bounces = 1;
    o.opacity_cache_mb = opacity_mb;
    o.cache_resolution = 0; /* coarse: as rays far wider than a leaf see it */
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, st) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static unsigned long long stat_count(const RayesStats *st, const char *name)
{
    const RayesStat *x = st ? rayes_stats_find(st, name) : NULL;
    return x ? x->count : 0;
}

static void test_opacity_table_same_bytes_as_cache(void)
{
    RayesStats *st = NULL, *small_st = NULL;
    RayesImage *a = cutout_instances(2, 20.0, &st), *b = cutout_instances(1, 20.0, NULL);
    RayesImage *c = cutout_instances(2, 1e-6, &small_st); /* 1 byte: no entry fits */
    unsigned long long lookups = stat_count(st, "opacity/table_lookups");
    unsigned long long fills = stat_count(st, "opacity/table_fills");
    unsigned long long small = stat_count(small_st, "opacity/table_lookups");
    fprintf(stderr,
            "opacity table: %llu lookups, %llu fills, %llu bytes; %llu lookups in 0 bytes; "
            "cache %llu %llu %llu\n",
            lookups, fills, stat_count(st, "memory/opacity_table_bytes"), small,
            stat_count(st, "cache/opacity/coarse/lookups"),
            stat_count(st, "cache/opacity/medium/lookups"),
            stat_count(st, "cache/opacity/fine/lookups"));
    /* four grids' slots (one square's, three instances'), each filled once,
     * or twice when two threads met at it */
    CHECK(lookups > 100 && fills >= 4 && fills <= 8);
    CHECK(small > 0 && small < lookups); /* the world's square alone */
    CHECK(test_cache_count(small_st, "opacity", "lookups") > 0);
    if (a && b && c) {
        size_t bytes = sizeof(float) * 4 * RES * RES;
        CHECK(memcmp(a->rgba, b->rgba, bytes) == 0);
        CHECK(memcmp(a->rgba, c->rgba, bytes) == 0);
    }
    rayes_stats_free(st);
    rayes_stats_free(small_st);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
}

/* A wall seen by the floor through three grey sheets (Os 0.4, seen by
 * diffuse rays alone) at one bounce, the light between floor and sheets:
 * cached diffuse rays stop at a sheet with the probability of its
 * opacity (accel_intersect_stochastic) and take its radiosity over it,
 * uncached ones composite every layer; the floor's light is the same
 * within noise. */
static double floor_through_sheets(int cache)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam w[1] = {pf("Kd", 1.0f)};
    CHECK(rayes_scene_set_shader(s, "matte", w, 1) == RAYES_OK);
    const float wall[4][3] = {{1.6f, -2, 0}, {1.6f, 2, 0}, {1.6f, -2, 3}, {1.6f, 2, 3}};
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    RayesParam g[2] = {pf("Kd", 0.5f), pc("Os", 0.4f, 0.4f, 0.4f)};
    CHECK(rayes_scene_set_shader(s, "matte", g, 2) == RAYES_OK);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_DIFFUSE) == RAYES_OK);
    for (int k = 0; k < 3; k++) {
        float x = 1.0f + 0.15f * (float)k;
        const float P[4][3] = {{x, -2, 0}, {x, 2, 0}, {x, -2, 2}, {x, 2, 2}};
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    }
    RayesParam l[2] = {(RayesParam){"from", RAYES_PARAM_COLOR, {0.5f, 0, 2.5f}, NULL},
                       pf("intensity", 4.0f)};
    CHECK(rayes_scene_light(s, "pointlight", l, 2) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_FINAL);
    o.width = o.height = 16;
    o.spp = 4;
    o.bounces = 1;
    o.cache = cache;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    rayes_scene_release(s);
    double m[3] = {0, 0, 0};
    if (img)
        mean_rgb(img, m);
    rayes_image_free(img);
    return m[0];
}

static void test_diffuse_rays_through_sheets(void)
{
    double cached = floor_through_sheets(1), uncached = floor_through_sheets(0);
    fprintf(stderr, "floor through sheets: cached %g, uncached %g\n", cached, uncached);
    CHECK(uncached > 0.01);
    CHECK_NEAR(cached / uncached, 1.0, 0.015); /* without the 1 / a: 3.5% dark */
}

/* Holes cast no rays: a checkerboard cut-out (half its cells Os 0) seen by
 * diffuse and shadow rays alone, over a lit floor at one bounce: of its
 * fills' points, those in the holes are counted (opacity/hole_points) and
 * cast none of their rays (PathState.holes); the same square at a constant
 * Os 0.5 has none. Returns the share of fill points in holes. */
static double fill_holes(int checker)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam cb[2] = {pf("uscale", 4.0f), pf("vscale", 4.0f)};
    CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cb, 2) == RAYES_OK);
    RayesParam p[2] = {pf("Kd", 1.0f),
                       checker ? (RayesParam){"Os", RAYES_PARAM_PATTERN, {0, 0, 0}, "cells"}
                               : pc("Os", 0.5f, 0.5f, 0.5f)};
    CHECK(rayes_scene_set_shader(s, "matte", p, 2) == RAYES_OK);
    CHECK(rayes_scene_set_visibility(s, RAYES_RAY_DIFFUSE | RAYES_RAY_SHADOW) == RAYES_OK);
    quad_at(s, 1.0f, 1.0f);
    point_light(s, 0.5f); /* under the square: its underside, which the floor sees, is lit */
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 1;
    o.bounces = 1;
    RayesStats *st = NULL;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *depth = rayes_stats_find(st, "shading_points/by_depth");
    double fill = depth && depth->n_counts > 1 ? (double)depth->counts[1] : 0.0;
    double holes = (double)stat_count(st, "opacity/hole_points");
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
    CHECK(fill > 0.0);
    return fill > 0.0 ? holes / fill : 0.0;
}

static void test_holes_cast_no_rays(void)
{
    double cut = fill_holes(1), half = fill_holes(0);
    fprintf(stderr, "fill points in holes: cut-out %g, Os 0.5 %g\n", cut, half);
    CHECK(half == 0.0);
    CHECK(cut > 0.0 && cut < 0.6); /* at most half the cells, less their filtered edges */
}

TEST_MAIN(TEST(test_stacked_sheets_multiply_in_any_order),
          TEST(test_half_transparent_sheet_halves_irradiance),
          TEST(test_ambient_occlusion_closed_forms), TEST(test_cutout_shadow_matches_geometry),
          TEST(test_cutout_shadow_from_afar_is_sharp),
          TEST(test_opacity_cache_within_noise_and_deterministic), TEST(test_camera_sees_through),
          TEST(test_grid_hider_transparent_grids), TEST(test_holes_pass_unshaded),
          TEST(test_bad_attributes), TEST(test_thin_glass), TEST(test_diffuse_transmission),
          TEST(test_opacity_table_same_bytes_as_cache), TEST(test_diffuse_rays_through_sheets),
          TEST(test_holes_cast_no_rays))
