/*
 * Adaptive pixel sampling's stopping rule (render.c, pixel_converged;
 * DESIGN.md "Adaptive pixel sampling"): a thin, bright strip over a dim
 * background, a fraction of a pixel wide, is what a light's edge or a
 * mirror's small reflection of a light is to cornell-teapots. A pixel
 * whose first block of samples misses the strip sees no variance; one
 * that finds it converges to a few percent of its own bright value. The
 * rule held each pixel to its own relative error only and left such an
 * image at 215% relative RMSE, however small the error asked; now it
 * stays under the error asked. A crop window's pixels stay the
 * same bytes as the whole frame's (the neighbourhood and the frame's mean
 * do not depend on the window), on 1 and 2 threads.
 */
#include <math.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"
#include "util/rng.h"

#define W 32
#define BACK 0.1f   /* the background's radiance */
#define BRIGHT 40.f /* the strip's */
#define X0 -0.23f   /* the strip's left edge (screen -1 to 1: pixels of 1/16) */
#define WIDTH (0.2f / 16) /* a fifth of a pixel */

static RayesParam pc(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}

static RayesScene *strip_scene(void)
{
    RayesScene *s = rayes_scene_new();
    const float cam[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_camera_matrix(s, cam, RAYES_PROJECTION_ORTHOGRAPHIC, 0, NULL) ==
          RAYES_OK);
    RayesParam back[1] = {pc("Cs", BACK, BACK, BACK)};
    CHECK(rayes_scene_set_shader(s, "constant", back, 1) == RAYES_OK);
    float P[4][3] = {{-2, -2, 4}, {2, -2, 4}, {-2, 2, 4}, {2, 2, 4}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    RayesParam bright[1] = {pc("Cs", BRIGHT, BRIGHT, BRIGHT)};
    CHECK(rayes_scene_set_shader(s, "constant", bright, 1) == RAYES_OK);
    float Q[4][3] = {{X0, -2, 3}, {X0 + WIDTH, -2, 3}, {X0, 2, 3}, {X0 + WIDTH, 2, 3}};
    CHECK(rayes_scene_bilinear_patch(s, Q) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static RayesImage *render(RayesScene *s, float error, int threads, const float *crop,
                          uint64_t *camera_rays)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = W;
    o.spp = 4;
    o.max_spp = 1024;
    o.adaptive_error = error;
    o.bounces = 0;
    o.threads = threads;
    o.tile_size = 8;
    if (crop)
        memcpy(o.crop, crop, sizeof o.crop);
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *cam = rayes_stats_find(st, "rays/camera");
    if (camera_rays)
        *camera_rays = cam ? cam->count : 0;
    rayes_stats_free(st);
    return img;
}

/* The image's relative RMSE (over the mean) against the exact one: the
 * strip covers a fifth of each pixel of its column. */
static double rel_rmse(const RayesImage *img)
{
    int column = (int)floorf((X0 + 1.0f) * W / 2.0f);
    double truth = BACK * 0.8 + BRIGHT * 0.2, sum = 0.0, mean = 0.0;
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
            double t = x == column ? truth : BACK;
            for (int c = 0; c < 3; c++) {
                double d = img->rgba[4 * (y * W + x) + c] - t;
                sum += d * d;
            }
            mean += t;
        }
    return sqrt(sum / (3.0 * W * W)) / (mean / (W * W));
}

static void test_converges_with_error_asked(void)
{
    RayesScene *s = strip_scene();
    const float errors[3] = {0.1f, 0.05f, 0.02f};
    for (int k = 0; k < 3; k++) {
        uint64_t rays = 0;
        RayesImage *img = render(s, errors[k], 2, NULL, &rays);
        if (!img)
            continue;
        double e = rel_rmse(img);
        printf("  error %.2f: relative RMSE %.4f, %llu camera rays\n", (double)errors[k], e,
               (unsigned long long)rays);
        CHECK(e < 1.5 * errors[k]);
        rayes_image_free(img);
    }
    rayes_scene_release(s);
}

static void test_crop_and_threads(void)
{
    RayesScene *s = strip_scene();
    const float crop[4] = {0.25f, 0.6f, 0.3f, 0.8f};
    RayesImage *full = render(s, 0.05f, 2, NULL, NULL);
    RayesImage *part = render(s, 0.05f, 1, crop, NULL);
    if (full && part) {
        int x0 = (int)ceilf(W * crop[0]), x1 = (int)ceilf(W * crop[1]);
        int y0 = (int)ceilf(W * crop[2]), y1 = (int)ceilf(W * crop[3]);
        int same = 1;
        for (int y = y0; y < y1; y++)
            for (int x = x0; x < x1; x++)
                same &= memcmp(&full->rgba[4 * (y * W + x)], &part->rgba[4 * (y * W + x)],
                               4 * sizeof(float)) == 0;
        CHECK(same);
    }
    rayes_image_free(full);
    rayes_image_free(part);
    rayes_scene_release(s);
}

/* The pixel positions of adaptive sampling: every prefix of 2^k points of
 * sobol_owen_2d has one point in each of the 2^k elementary intervals of
 * every shape (2^a x 2^b cells, a + b = k), for any seed. */
static void test_sobol_prefixes_stratified(void)
{
    for (uint32_t seed = 0; seed < 3; seed++)
        for (int k = 0; k <= 10; k += 2)
            for (int a = 0; a <= k; a++) {
                uint32_t n = 1u << k, cols = 1u << a, rows = n / cols;
                unsigned char hit[1024] = {0};
                int ok = 1;
                for (uint32_t s = 0; s < n; s++) {
                    float x, y;
                    sobol_owen_2d(s, seed * 2654435761u, &x, &y);
                    ok &= x >= 0.0f && x < 1.0f && y >= 0.0f && y < 1.0f;
                    uint32_t cell = (uint32_t)(y * rows) * cols + (uint32_t)(x * cols);
                    ok &= cell < n && !hit[cell];
                    if (cell < n)
                        hit[cell] = 1;
                }
                CHECK(ok);
            }
}

TEST_MAIN(TEST(test_converges_with_error_asked), TEST(test_crop_and_threads),
          TEST(test_sobol_prefixes_stratified))
