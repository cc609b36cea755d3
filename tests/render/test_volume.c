/*
 * Volumes (memo 6.1): a homogeneous slab's transmittance is exp(-sigma d)
 * (cached and not); an optically thick slab lit from behind the viewer
 * scatters the single-scattering closed form toward the camera; the
 * memo's turbulence medium's shadow with cached extinction agrees with
 * the uncached one within noise; images do not depend on threads or the
 * cache budget; a bad box is refused. A slab whose density is a NanoVDB
 * grid of one value (written by nvdb_write.h) or a densitygrid transmits
 * exp(-sigma d) as the constant does.
 *
 * The camera looks down -z from z = 6 at [-1, 1]^2 of the plane z = 0.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cache_stats.h"
#include "nvdb_write.h"
#include "rayes/rayes.h"
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

/* A densitygrid pattern of 2 x 2 x 2 voxels of the one value sigma over
 * x, y in [-30, 30] and z in [z0, z1]: a marched medium, unlike the
 * constant's one step. */
static void constant_grid(RayesScene *s, const char *name, float sigma, float z0, float z1)
{
    const float d[8] = {sigma, sigma, sigma, sigma, sigma, sigma, sigma, sigma};
    RayesParam q[6] = {pf("nx", 2), pf("ny", 2), pf("nz", 2), pc("p0", -30, -30, z0),
                       pc("p1", 30, 30, z1)};
    q[5] = (RayesParam){"density", RAYES_PARAM_FLOATS, {0}, NULL, d, 8};
    CHECK(rayes_scene_pattern(s, name, "densitygrid", q, 6) == RAYES_OK);
}

static RayesScene *new_scene(void)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 6}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, (float)(2.0 * atan(1.0 / 6.0) * 180.0 / M_PI)) ==
          RAYES_OK);
    return s;
}

static void floor_matte(RayesScene *s)
{
    RayesParam m[1] = {pf("Ka", 0.0f)};
    CHECK(rayes_scene_set_shader(s, "matte", m, 1) == RAYES_OK);
    const float P[4][3] = {{-2, -2, 0}, {2, -2, 0}, {-2, 2, 0}, {2, 2, 0}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
}

static RayesImage *render(RayesScene *s, int threads, double opacity_mb, int cached,
                          RayesStats **stats)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 1;
    o.threads = threads;
    o.bounces = 0;
    o.opacity_cache = cached;
    o.opacity_cache_mb = opacity_mb;
    if (opacity_mb < 1.0) /* a budget meant to evict: no other type's to borrow */
        o.cache_mb = o.irradiance_cache_mb = 0.0, o.env_guide = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

static double mean(const RayesImage *img, int c)
{
    double m = 0.0;
    for (int i = 0; i < img->width * img->height; i++)
        m += img->rgba[4 * i + c];
    return m / (img->width * img->height);
}

/* The floor under a point light 20 above it, and a slab of the medium
 * between z = 8 and 9 (above the camera: only shadow rays cross it). */
static RayesImage *floor_under_slab(int slab, float sigma, int cached)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam lp[2] = {pc("from", 0, 0, 20), pf("intensity", 400.0f)};
    CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
    if (slab) {
        RayesParam v[2] = {pf("density", sigma), pc("albedo", 0, 0, 0)};
        CHECK(rayes_scene_set_shader(s, "homogeneous", v, 2) == RAYES_OK);
        const float box[6] = {-10, 10, -10, 10, 8, 9};
        CHECK(rayes_scene_volume(s, box) == RAYES_OK);
    }
    RayesImage *img = render(s, 2, 20.0, cached, NULL);
    rayes_scene_release(s);
    return img;
}

/* The slab's density from a grid pattern of the single value sigma
 * covering the slab: kind 0 a NanoVDB file (8^3 voxels of 3 units from
 * (-10.5, -10.5, 7.5)), kind 1 a densitygrid of 2 x 2 x 2 over a box
 * whose outer voxel centres enclose the slab. */
static RayesImage *floor_under_grid_slab(int kind, float sigma, int cached)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam lp[2] = {pc("from", 0, 0, 20), pf("intensity", 400.0f)};
    CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
    if (kind == 0) {
        static float v[8][8][8];
        for (int i = 0; i < 512; i++)
            v[i >> 6][i >> 3 & 7][i & 7] = sigma;
        const double o[3] = {-10.5, -10.5, 7.5};
        const char *path = RAYES_TEST_TMP "/slab.nvdb";
        CHECK(nvdb_write(path, "density", (const float(*)[8][8])v, 3.0, o) == 0);
        RayesParam q[1] = {{"filename", RAYES_PARAM_STRING, {0}, path}};
        CHECK(rayes_scene_pattern(s, "cloud", "nanovdb", q, 1) == RAYES_OK);
    } else {
        constant_grid(s, "cloud", sigma, 7, 10);
    }
    RayesParam v[2] = {{"density", RAYES_PARAM_PATTERN, {0}, "cloud"}, pc("albedo", 0, 0, 0)};
    CHECK(rayes_scene_set_shader(s, "homogeneous", v, 2) == RAYES_OK);
    const float box[6] = {-10, 10, -10, 10, 8, 9};
    CHECK(rayes_scene_volume(s, box) == RAYES_OK);
    RayesImage *img = render(s, 2, 20.0, cached, NULL);
    rayes_scene_release(s);
    return img;
}

static void test_homogeneous_slab_transmittance(void)
{
    const float sigma = 0.5f; /* exact in half floats */
    RayesImage *open = floor_under_slab(0, 0.0f, 1);
    for (int run = 0; run < 6; run++) {
        int cached = run & 1, kind = run >> 1; /* the constant, a NanoVDB grid, a densitygrid */
        RayesImage *img = kind == 0 ? floor_under_slab(1, sigma, cached)
                                    : floor_under_grid_slab(kind - 1, sigma, cached);
        if (!open || !img) {
            rayes_image_free(img);
            continue;
        }
        /* pixel centres on the floor: a shadow ray crosses the slab over
         * 1 / cos(theta), theta from the light straight above */
        double worst = 0.0;
        for (int y = 0; y < RES; y++)
            for (int x = 0; x < RES; x++) {
                double fx = -1.0 + (x + 0.5) * 2.0 / RES, fy = -1.0 + (y + 0.5) * 2.0 / RES;
                double path = sqrt(fx * fx + fy * fy + 400.0) / 20.0;
                double want = exp(-sigma * path);
                size_t i = 4 * ((size_t)y * RES + x);
                worst = fmax(worst, fabs(img->rgba[i] / open->rgba[i] - want) / want);
            }
        fprintf(stderr, "slab of %s (%s): worst relative error %g\n",
                kind == 0   ? "a constant"
                : kind == 1 ? "a NanoVDB grid"
                            : "a densitygrid",
                cached ? "cached" : "uncached", worst);
        CHECK(worst < 2e-3); /* the pixel's sample lies within it, not at its centre */
        rayes_image_free(img);
    }
    rayes_image_free(open);
}

/* A medium of one extinction everywhere is not marched: a shadow ray
 * takes one step through it (the slab test above shows the result
 * exact), while the same slab from a grid takes a step per voxel. */
static void test_uniform_volume_one_step(void)
{
    for (int grid = 0; grid < 2; grid++) {
        RayesScene *s = new_scene();
        floor_matte(s);
        RayesParam lp[2] = {pc("from", 0, 0, 20), pf("intensity", 400.0f)};
        CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
        constant_grid(s, "cloud", 0.5f, 7, 10);
        RayesParam v[2] = {grid ? (RayesParam){"density", RAYES_PARAM_PATTERN, {0}, "cloud"}
                                : pf("density", 0.5f),
                           pc("albedo", 0, 0, 0)};
        CHECK(rayes_scene_set_shader(s, "homogeneous", v, 2) == RAYES_OK);
        const float box[6] = {-10, 10, -10, 10, 8, 9};
        CHECK(rayes_scene_volume(s, box) == RAYES_OK);
        RayesStats *st = NULL;
        RayesImage *img = render(s, 2, 20.0, 1, &st);
        const RayesStat *tr = rayes_stats_find(st, "rays/transmission");
        const RayesStat *steps = rayes_stats_find(st, "volume/steps");
        CHECK(tr && steps && tr->count > 0);
        if (tr && steps) {
            fprintf(stderr, "%s slab: %g steps a transmission ray\n", grid ? "grid" : "uniform",
                    (double)steps->count / (double)tr->count);
            CHECK(grid ? steps->count > 4 * tr->count : steps->count == tr->count);
        }
        rayes_stats_free(st);
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

/* A slab z in [1, 2] of an isotropic medium, albedo 1, lit by a distant
 * light shining down the view: a point s deep sees the light through s
 * and the camera through s, so L = sigma E / (4 pi) (1 - e^(-2 sigma d)) /
 * (2 sigma) = E (1 - e^(-2 sigma d)) / (8 pi). */
static void test_single_scattering_closed_form(void)
{
    RayesScene *s = new_scene();
    RayesParam lp[3] = {pc("from", 0, 0, 1), pc("to", 0, 0, 0), pf("intensity", 10.0f)};
    CHECK(rayes_scene_light(s, "distantlight", lp, 3) == RAYES_OK);
    const float sigma = 1.0f;
    RayesParam v[2] = {pf("density", sigma), pc("albedo", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "homogeneous", v, 2) == RAYES_OK);
    const float box[6] = {-10, 10, -10, 10, 1, 2};
    CHECK(rayes_scene_volume(s, box) == RAYES_OK);
    RayesImage *img = render(s, 2, 20.0, 1, NULL);
    if (img) {
        double want = 10.0 * (1.0 - exp(-2.0 * sigma)) / (8.0 * M_PI), got = 0.0;
        for (int y = RES / 2 - 2; y < RES / 2 + 2; y++)
            for (int x = RES / 2 - 2; x < RES / 2 + 2; x++)
                got += img->rgba[4 * ((size_t)y * RES + x)] / 16.0;
        fprintf(stderr, "single scattering: %g, closed form %g\n", got, want);
        CHECK_NEAR(got / want, 1.0, 0.02);
        /* alpha: what shows through is e^(-sigma d) */
        CHECK_NEAR(img->rgba[4 * ((size_t)(RES / 2) * RES + RES / 2) + 3], 1.0 - exp(-sigma), 0.01);
    }
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* The same slab, dense (sigma 20: the light is gone 0.46 in) and marched
 * (a densitygrid of that one value): its lighting points gather where the
 * camera sees the medium, so the single scattering still meets the closed
 * form (placed at equal steps, most of them lit depths the camera does not
 * see and the front was interpolated: 6.7% too bright), and the march ends
 * where the slab is
 * opaque (transmittance 1e-4) and its lighting points' shadow rays are
 * short, so it takes fewer steps than the same slab at sigma 1. */
static RayesScene *marched_slab(float sigma)
{
    RayesScene *s = new_scene();
    RayesParam lp[3] = {pc("from", 0, 0, 1), pc("to", 0, 0, 0), pf("intensity", 10.0f)};
    CHECK(rayes_scene_light(s, "distantlight", lp, 3) == RAYES_OK);
    constant_grid(s, "slab", sigma, 0, 3);
    RayesParam v[2] = {{"density", RAYES_PARAM_PATTERN, {0}, "slab"}, pc("albedo", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "homogeneous", v, 2) == RAYES_OK);
    const float box[6] = {-10, 10, -10, 10, 1, 2};
    CHECK(rayes_scene_volume(s, box) == RAYES_OK);
    return s;
}

static void test_dense_single_scattering(void)
{
    const float sigma = 20.0f;
    RayesScene *thin = marched_slab(1.0f);
    RayesStats *st_thin = NULL;
    RayesImage *img_thin = render(thin, 2, 20.0, 1, &st_thin);
    const RayesStat *thin_steps = rayes_stats_find(st_thin, "volume/steps");
    CHECK(img_thin && thin_steps);
    RayesScene *s = marched_slab(sigma);
    for (int cached = 0; cached < 2; cached++) {
        RayesStats *st = NULL;
        RayesImage *img = render(s, 2, 20.0, cached, &st);
        const RayesStat *steps = rayes_stats_find(st, "volume/steps");
        if (img && steps && thin_steps) {
            double want = 10.0 * (1.0 - exp(-2.0 * sigma)) / (8.0 * M_PI), got = 0.0;
            for (int y = RES / 2 - 2; y < RES / 2 + 2; y++)
                for (int x = RES / 2 - 2; x < RES / 2 + 2; x++)
                    got += img->rgba[4 * ((size_t)y * RES + x)] / 16.0;
            fprintf(stderr,
                    "dense single scattering (%s): %g, closed form %g; steps %g of sigma 1's\n",
                    cached ? "cached" : "uncached", got, want,
                    (double)steps->count / (double)thin_steps->count);
            CHECK_NEAR(got / want, 1.0, 0.03);
            CHECK(steps->count < thin_steps->count / 2);
        }
        CHECK(img && steps);
        rayes_stats_free(st);
        rayes_image_free(img);
    }
    rayes_stats_free(st_thin);
    rayes_image_free(img_thin);
    rayes_scene_release(thin);
    rayes_scene_release(s);
}

/* The memo's Figure 9 medium over a floor under a spot light. */
static RayesScene *cloud_scene(void)
{
    RayesScene *s = new_scene();
    floor_matte(s);
    RayesParam lp[4] = {pc("from", 1, 1, 8), pc("to", 0, 0, 0), pf("intensity", 64.0f),
                        pf("coneangle", 30.0f)};
    CHECK(rayes_scene_light(s, "spotlight", lp, 4) == RAYES_OK);
    RayesParam v[2] = {pf("density", 3.0f), pf("frequency", 2.0f)};
    CHECK(rayes_scene_set_shader(s, "turbulence", v, 2) == RAYES_OK);
    const float box[6] = {-0.8f, 0.8f, -0.8f, 0.8f, 1.0f, 2.6f};
    CHECK(rayes_scene_volume(s, box) == RAYES_OK);
    return s;
}

static void test_cached_extinction_within_noise_and_deterministic(void)
{
    RayesScene *s = cloud_scene();
    RayesStats *st = NULL;
    RayesImage *cached = render(s, 2, 20.0, 1, &st);
    RayesImage *uncached = render(s, 2, 20.0, 0, NULL);
    RayesImage *one = render(s, 1, 20.0, 1, NULL);
    RayesStats *tiny_st = NULL;
    RayesImage *tiny = render(s, 3, 0.01, 1, &tiny_st);
    CHECK(test_cache_evictions(tiny_st, "opacity") > 0);
    rayes_stats_free(tiny_st);
    if (cached && uncached && one && tiny) {
        for (int c = 0; c < 3; c++) {
            fprintf(stderr, "cloud channel %d: cached %g, uncached %g\n", c, mean(cached, c),
                    mean(uncached, c));
            CHECK(mean(uncached, c) > 0.01);
            CHECK_NEAR(mean(cached, c) / mean(uncached, c), 1.0, 0.01);
        }
        size_t bytes = sizeof(float) * 4 * RES * RES;
        CHECK(memcmp(cached->rgba, one->rgba, bytes) == 0);
        CHECK(memcmp(cached->rgba, tiny->rgba, bytes) == 0);
        const RayesStat *tr = rayes_stats_find(st, "rays/transmission");
        const RayesStat *fine = rayes_stats_find(st, "cache/opacity/fine/lookups");
        const RayesStat *coarse = rayes_stats_find(st, "cache/opacity/coarse/lookups");
        CHECK(tr && tr->count > 0);
        CHECK(fine && coarse && fine->count + coarse->count > 0);
    }
    rayes_stats_free(st);
    rayes_image_free(cached);
    rayes_image_free(uncached);
    rayes_image_free(one);
    rayes_image_free(tiny);
    rayes_scene_release(s);
}

/* A furnace: a cube of a medium of albedo 1 under a uniform environment
 * of radiance 1. Whatever it scatters, the light leaving it is 1 in every
 * direction; single scattering alone (no bounces) falls short, since the
 * light it scatters again is lost. The mean of the central pixels. */
static double furnace(float sigma, int bounces, int threads)
{
    RayesScene *s = new_scene();
    RayesParam e = {"intensity", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL};
    CHECK(rayes_scene_light(s, "environmentlight", &e, 1) == RAYES_OK);
    RayesParam v[2] = {pf("density", sigma), pc("albedo", 1, 1, 1)};
    CHECK(rayes_scene_set_shader(s, "homogeneous", v, 2) == RAYES_OK);
    const float box[6] = {-1, 1, -1, 1, -1, 1};
    CHECK(rayes_scene_volume(s, box) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 16;
    o.spp = 16;
    o.threads = threads;
    o.bounces = bounces;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double m = 0.0;
    for (int y = 4; img && y < 12; y++)
        for (int x = 4; x < 12; x++)
            m += (img->rgba[4 * (y * 16 + x)] + img->rgba[4 * (y * 16 + x) + 1] +
                  img->rgba[4 * (y * 16 + x) + 2]) /
                 (3.0 * 64.0);
    rayes_image_free(img);
    rayes_scene_release(s);
    return m;
}

/* Multiple scattering (DESIGN.md "Volumes"): the furnace comes out 1
 * with bounces enough for its optical depth, and the same bytes on any
 * threads. */
static void test_multiple_scattering_furnace(void)
{
    double single = furnace(1.0f, 0, 2), one = furnace(1.0f, 1, 2), many = furnace(1.0f, 8, 2);
    fprintf(stderr, "furnace, albedo 1: %.4f single scattering, %.4f one bounce, %.4f eight\n",
            single, one, many);
    CHECK(single < 0.9 && one > single && many > one);
    CHECK(fabs(many - 1.0) < 0.03);
    CHECK(furnace(1.0f, 8, 1) == many);
}

static void test_bad_volume(void)
{
    RayesScene *s = rayes_scene_new();
    const float flat[6] = {0, 1, 0, 1, 2, 2}, nan[6] = {0, 1, 0, NAN, 0, 1};
    CHECK(rayes_scene_volume(s, flat) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_volume(s, nan) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_volume(s, NULL) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_homogeneous_slab_transmittance), TEST(test_multiple_scattering_furnace),
          TEST(test_uniform_volume_one_step), TEST(test_dense_single_scattering),
          TEST(test_single_scattering_closed_form),
          TEST(test_cached_extinction_within_noise_and_deterministic), TEST(test_bad_volume))
