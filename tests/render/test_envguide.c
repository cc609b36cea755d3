/*
 * Guided sampling of environment lights (shade/light.c's LightGuide,
 * render/envguide.c): a guided draw's pdf is the light's own times its
 * bin's factor, bins are drawn by mass x weight (chi-square), bins of
 * weight 0 never, and the guided estimate of the light's integral equals
 * the unguided one, for a map with black rows and columns and for a
 * constant environment. Then a room lit through a window: guided and
 * unguided renders agree in the mean with a many-sample reference, the
 * guided one is closer, guides were filled, and the guided image is the
 * same bytes on 1 and 2 threads and in a crop window, and with a marble
 * ball's irradiance fills on 1 and 8 threads. And direct lighting's
 * multiple importance sampling at fills of one shadow ray.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "rayes/rayes.h"
#include "scene/scene.h"
#include "shade/light.h"
#include "test.h"
#include "util/rng.h"

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}
static RayesParam ps(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

/* A 100 x 37 map (bins of unequal sizes) with empty rows and columns, a
 * bright patch and a gradient. */
static void write_map(const char *path)
{
    int w = 100, h = 37;
    float *p = malloc(sizeof(float) * 4 * w * h);
    for (int i = 0; i < w * h; i++) {
        int x = i % w, y = i / w;
        float v = y >= 30 || (x >= 10 && x < 25) ? 0.0f
                  : x >= 60 && x < 64 && y >= 9 && y < 12 ? 300.0f
                                                           : 0.05f + 0.01f * (float)(x + y);
        p[4 * i + 0] = v, p[4 * i + 1] = 0.5f * v, p[4 * i + 2] = 0.25f * v;
        p[4 * i + 3] = 1.0f;
    }
    CHECK(image_write_exr(path, w, h, p, NULL, 0) == RAYES_OK);
    free(p);
}

/* A light's guide against its own sampling (weights of 0 to 1). */
static void check_guide(const Light *l)
{
    double total = 0.0;
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++) {
        CHECK(light_guide_mass(l, b) >= 0.0f);
        total += light_guide_mass(l, b);
    }
    CHECK_NEAR(total, 1.0, 1e-4);
    float wt[LIGHT_GUIDE_BINS];
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++)
        wt[b] = (float)((b * 7) % 5) * 0.25f; /* 0 to 1, a fifth of the bins 0 */
    LightGuide g;
    CHECK(light_guide_init(l, wt, &g));
    int n = 200000, pdf_far = 0, zero_drawn = 0, failed = 0;
    int *count = calloc(LIGHT_GUIDE_BINS, sizeof *count);
    double guided = 0.0, plain = 0.0;
    for (int i = 0; i < n; i++) {
        float a = rng_float(hash_combine(21, (uint64_t)i));
        float b = rng_float(hash_combine(22, (uint64_t)i));
        LightSample ls, back;
        if (!light_guide_sample(l, &g, a, b, &ls)) {
            failed++;
            continue;
        }
        CHECK(light_intersect(l, v3(0, 0, 0), ls.wi, &back));
        float factor = light_guide_factor(l, &g, ls.wi);
        /* a direction on a pixel's or bin's edge may look up its neighbour */
        pdf_far += fabsf(back.pdf * factor - ls.pdf) > 1e-3f * ls.pdf;
        /* the bin drawn: the first whose cdf's end lies above a */
        int bin = 0;
        while (bin < LIGHT_GUIDE_BINS - 1 && !(a < g.cdf[bin + 1]))
            bin++;
        count[bin]++;
        pdf_far += factor != g.scale[bin];
        zero_drawn += !(factor > 0.0f);
        guided += ls.Li.x / ls.pdf;
        /* the unguided estimate over the same bins: the light's own draw */
        LightSample u;
        if (light_sample(l, v3(0, 0, 0), a, b, &u) && light_guide_factor(l, &g, u.wi) > 0.0f)
            plain += u.Li.x / u.pdf;
    }
    CHECK(failed < n / 1000);
    CHECK(zero_drawn == 0);
    CHECK(pdf_far < n / 100);
    CHECK_NEAR(guided / plain, 1.0, 0.02);
    double chi2 = 0.0;
    int dof = -1;
    for (int k = 0; k < LIGHT_GUIDE_BINS; k++) {
        double expect = (double)(g.cdf[k + 1] - g.cdf[k]) * n;
        if (expect >= 5.0) {
            chi2 += (count[k] - expect) * (count[k] - expect) / expect;
            dof++;
        } else {
            CHECK(expect > 0.0 || count[k] == 0);
        }
    }
    CHECK(dof > 10);
    CHECK(chi2 < dof + 5.0 * sqrt(2.0 * dof));
    /* weights of 0 everywhere: no guide */
    for (int b = 0; b < LIGHT_GUIDE_BINS; b++)
        wt[b] = 0.0f;
    CHECK(!light_guide_init(l, wt, &g));
    free(count);
}

static void test_guide_sampling(void)
{
    const char *path = RAYES_TEST_TMP "/test_envguide_map.exr";
    write_map(path);
    RayesScene *s = rayes_scene_new();
    RayesParam e[2] = {ps("mapname", path), pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 2) == RAYES_OK);
    CHECK(s->n_lights == 1 && s->lights[0].env != NULL);
    if (s->n_lights == 1)
        check_guide(&s->lights[0]);
    rayes_scene_release(s);
    s = rayes_scene_new(); /* a constant environment */
    RayesParam c[1] = {pf("intensity", 2)};
    CHECK(rayes_scene_light(s, "environmentlight", c, 1) == RAYES_OK);
    if (s->n_lights == 1)
        check_guide(&s->lights[0]);
    rayes_scene_release(s);
}

/* A closed room 4 wide, 3 high, 6 deep (x -2..2, y 0..3, z 0..6), matte,
 * its walls facing in, with a window 1.2 x 1 in its left wall (x = -2),
 * under a constant environment; the camera at the front looks at the back
 * wall, which only the window's sky lights. */
static RayesScene *window_room(int marble)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {1.2f, 1.5f, 0.3f}, target[3] = {-0.5f, 1.2f, 6}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 60.0f) == RAYES_OK);
    RayesParam kd = pf("Kd", 0.8f);
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    /* each quad counter-clockwise seen from inside */
    const float quads[][4][3] = {
        {{-2, 0, 0}, {2, 0, 0}, {2, 0, 6}, {-2, 0, 6}},  /* floor, up */
        {{-2, 3, 0}, {-2, 3, 6}, {2, 3, 6}, {2, 3, 0}},  /* ceiling, down */
        {{-2, 0, 6}, {2, 0, 6}, {2, 3, 6}, {-2, 3, 6}},  /* back, -z */
        {{-2, 0, 0}, {-2, 3, 0}, {2, 3, 0}, {2, 0, 0}},  /* front, +z */
        {{2, 0, 0}, {2, 3, 0}, {2, 3, 6}, {2, 0, 6}},    /* right, -x */
        /* the left wall, +x, around the window y 1..2, z 2.4..3.6 */
        {{-2, 0, 0}, {-2, 0, 6}, {-2, 1, 6}, {-2, 1, 0}},
        {{-2, 2, 0}, {-2, 2, 6}, {-2, 3, 6}, {-2, 3, 0}},
        {{-2, 1, 0}, {-2, 1, 2.4f}, {-2, 2, 2.4f}, {-2, 2, 0}},
        {{-2, 1, 3.6f}, {-2, 1, 6}, {-2, 2, 6}, {-2, 2, 3.6f}},
    };
    for (size_t q = 0; q < sizeof quads / sizeof quads[0]; q++) {
        /* a bilinear patch's corners: (0,0) (1,0) (0,1) (1,1) */
        const float P[4][3] = {{quads[q][0][0], quads[q][0][1], quads[q][0][2]},
                               {quads[q][1][0], quads[q][1][1], quads[q][1][2]},
                               {quads[q][3][0], quads[q][3][1], quads[q][3][2]},
                               {quads[q][2][0], quads[q][2][1], quads[q][2][2]}};
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    }
    if (marble) { /* a marble ball under the window: irradiance fills at depth 0 */
        RayesParam m[3] = {ps("preset", "marble"), pf("unitlength", 0.2f), pf("Ks", 0.5f)};
        CHECK(rayes_scene_set_shader(s, "subsurface", m, 3) == RAYES_OK);
        float T[16] = {1, 0, 0, -1.0f, 0, 1, 0, 0.9f, 0, 0, 1, 3.0f, 0, 0, 0, 1}; /* row-major */
        CHECK(rayes_scene_set_transform(s, T) == RAYES_OK);
        CHECK(rayes_scene_sphere(s, 0.9f) == RAYES_OK);
    }
    RayesParam e[1] = {pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static RayesImage *render_room(RayesScene *s, int guide, int shadow_rays, int threads,
                               double cache_mb, const float crop[4], RayesStats **stats)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 96;
    o.spp = 4;
    o.threads = threads;
    o.bounces = 0;
    o.tile_size = 16;
    o.env_guide = guide;
    o.cache_mb = cache_mb;
    o.shadow_rays = o.shadow_rays_deep = shadow_rays;
    if (crop)
        memcpy(o.crop, crop, sizeof o.crop);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

static double mean_of(const RayesImage *img)
{
    double m = 0.0;
    for (int i = 0; i < img->width * img->height; i++)
        m += img->rgba[4 * i];
    return m / (img->width * img->height);
}

static double rms_from(const RayesImage *a, const RayesImage *ref)
{
    double e = 0.0;
    for (int i = 0; i < a->width * a->height; i++) {
        double d = a->rgba[4 * i] - ref->rgba[4 * i];
        e += d * d;
    }
    return sqrt(e / (a->width * a->height)) / mean_of(ref);
}

static void test_guide_window_room(void)
{
    RayesScene *s = window_room(0);
    RayesStats *stats = NULL;
    RayesImage *ref = render_room(s, 0, 256, 2, 100.0, NULL, NULL);
    RayesImage *off = render_room(s, 0, 4, 2, 100.0, NULL, NULL);
    RayesImage *on = render_room(s, 1, 4, 2, 100.0, NULL, &stats);
    if (ref && off && on) {
        double m = mean_of(ref);
        CHECK(m > 0.01);
        /* unbiased: both means within noise of the reference's (the
         * pixels' samples are the same, the light's differ) */
        CHECK_NEAR(mean_of(off) / m, 1.0, 0.03);
        CHECK_NEAR(mean_of(on) / m, 1.0, 0.03);
        double e_off = rms_from(off, ref), e_on = rms_from(on, ref);
        CHECK(e_on < 0.75 * e_off); /* measured: 0.58 against 0.93 */
        const RayesStat *fills = rayes_stats_find(stats, "cache/guide/coarse/fills");
        CHECK(fills && fills->count > 0);
    }
    /* the same bytes on 1 thread and in a crop */
    RayesImage *one = render_room(s, 1, 4, 1, 100.0, NULL, NULL);
    const float crop[4] = {0.2f, 0.7f, 0.3f, 0.9f};
    RayesImage *part = render_room(s, 1, 4, 2, 100.0, crop, NULL);
    if (on && one)
        CHECK(memcmp(on->rgba, one->rgba, sizeof(float) * 4 * 96 * 96) == 0);
    if (on && part) {
        int same = 1;
        for (int y = part->crop[1]; y < part->crop[1] + part->crop[3]; y++)
            for (int x = part->crop[0]; x < part->crop[0] + part->crop[2]; x++)
                same &= memcmp(&on->rgba[4 * (y * 96 + x)], &part->rgba[4 * (y * 96 + x)],
                               4 * sizeof(float)) == 0;
        CHECK(same);
    }
    rayes_stats_free(stats);
    rayes_image_free(ref);
    rayes_image_free(off);
    rayes_image_free(on);
    rayes_image_free(one);
    rayes_image_free(part);
    rayes_scene_release(s);
}

/* Camera hits are guided and the marble's irradiance fills (depth 0 too,
 * with a shadow-ray count of their own, filled by whichever thread's
 * lookup comes first) are not: the same bytes on 1 and 8 threads (a
 * worker's remembered guide decision once leaked into the fills, whose
 * values then depended on the order of lookups). */
static void test_guide_threads_with_irradiance(void)
{
    RayesScene *s = window_room(1);
    RayesStats *st = NULL;
    RayesImage *one = render_room(s, 1, 1, 1, 100.0, NULL, &st);
    const RayesStat *irr = rayes_stats_find(st, "subsurface/irradiance_points");
    CHECK(irr && irr->count > 1000); /* the ball is in view, its fills ran */
    rayes_stats_free(st);
    RayesImage *four = render_room(s, 1, 1, 8, 100.0, NULL, NULL);
    if (one && four)
        CHECK(memcmp(one->rgba, four->rgba, sizeof(float) * 4 * 96 * 96) == 0);
    rayes_image_free(one);
    rayes_image_free(four);
    rayes_scene_release(s);
}

/* A floor and a wall under a constant environment, one bounce: the fills'
 * points take 1 shadow ray or 8, the same light in the mean. With 1 ray
 * and a fill's zero spread the light's strategy once took weight 1 while
 * the cosine strategy's samples were added too (0.836 against 0.654). */
static void test_one_shadow_ray_fills(void)
{
    RayesScene *s = rayes_scene_new();
    float eye[3] = {0, 1.5f, -4}, target[3] = {0, 0.5f, 2}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 50.0f) == RAYES_OK);
    RayesParam kd = pf("Kd", 0.8f);
    CHECK(rayes_scene_set_shader(s, "matte", &kd, 1) == RAYES_OK);
    const float floor_[4][3] = {{-4, 0, -4}, {4, 0, -4}, {-4, 0, 4}, {4, 0, 4}};
    const float wall[4][3] = {{-4, 0, 4}, {4, 0, 4}, {-4, 4, 4}, {4, 4, 4}};
    CHECK(rayes_scene_bilinear_patch(s, floor_) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    RayesParam e[1] = {pf("intensity", 1)};
    CHECK(rayes_scene_light(s, "environmentlight", e, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    double mean[2] = {0, 0};
    for (int k = 0; k < 2; k++) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = 32;
        o.spp = 4;
        o.bounces = 1;
        o.env_guide = 0;
        o.shadow_rays_deep = k ? 8 : 1;
        RayesImage *img = NULL;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
        if (img)
            mean[k] = mean_of(img);
        rayes_image_free(img);
    }
    CHECK(mean[1] > 0.1);
    CHECK_NEAR(mean[0] / mean[1], 1.0, 0.03);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_guide_sampling), TEST(test_guide_window_room), TEST(test_one_shadow_ray_fills),
          TEST_THREADS(test_guide_threads_with_irradiance))
