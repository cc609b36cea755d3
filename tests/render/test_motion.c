/*
 * Motion blur (DESIGN.md "Motion blur and depth of field"): a sphere moving
 * across an orthographic view covers each pixel for the fraction of the
 * shutter it spends there (the analytic time average); deformation blur of
 * a moving patch renders the same bytes as transform blur of the same
 * motion; cached radiosity with motion segments matches uncached (1% mean,
 * 3% per 32 x 32 tile), is deterministic across thread counts, and fills
 * one set of entries per segment; a camera moving past a still sphere
 * blurs it as the sphere moving the other way would. Deforming points and
 * curves; a light moving within the frame (its shadow against the analytic
 * time average, cached against uncached); the grid hider's shading per
 * motion segment against the ray-tracing hider.
 */
#include <math.h>
#include <string.h>

#include "accel/accel.h"
#include "cache_stats.h"
#include "geom/geom.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "scene/scene.h"
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
                                               HALF - (y + (j + 0.5) / 4) * px) /
                            16;
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

/* Points and curves move by their transform too: a sphere point of
 * diameter 2 moving as the sphere above covers what it covers, and a
 * vertical tube of width 0.5 moving 2 units across covers a band 2.5
 * wide, its time-averaged area its own (length times width, and its
 * round end caps), and the middle a quarter of the time. */
static void test_moving_points_and_curves(void)
{
    for (int kind = 0; kind < 2; kind++) {
        RayesScene *s = rayes_scene_new();
        ortho_camera(s);
        CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
        float m[2][16];
        translate(m[0], -1, 0, 0);
        translate(m[1], 1, 0, 0);
        const float times[2] = {0, 1};
        CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
        if (kind == 0) {
            const float P[3] = {0, 0, 0}, width = 2.0f;
            RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &width, 1};
            CHECK(rayes_scene_points(s, RAYES_POINT_SPHERE, 1, P, &pv, 1) == RAYES_OK);
        } else {
            const float P[6] = {0, -1.5f, 0, 0, 1.5f, 0}, width = 0.5f;
            const int nv = 2;
            RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1,
                             .n_verts = &nv, .P = P};
            RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &width, 1};
            CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
        }
        RayesStats *st = NULL;
        RayesImage *img = render(s, 64, 2, 1, &st);
        const RayesStat *moving = rayes_stats_find(st, "motion/moving_grids");
        CHECK(moving && moving->count > 0);
        rayes_stats_free(st);
        double err = 0, sum = 0, outside = 0;
        float px = 2 * HALF / W;
        for (int y = 0; img && y < W; y++)
            for (int x = 0; x < W; x++) {
                double cx = -HALF + (x + 0.5) * px, cy = HALF - (y + 0.5) * px;
                double got = img->rgba[4 * (y * W + x) + 3];
                sum += got;
                if (kind == 0)
                    err += fabs(got - disk_time_coverage(cx, cy));
                else if (fabs(cx) > 1.25 + px || fabs(cy) > 1.5 + 0.25 + px)
                    outside += got;
            }
        double area = kind == 0 ? M_PI : 3.0 * 0.5 + M_PI * 0.25 * 0.25; /* + the end caps */
        printf("  moving %s: coverage %.4f (%.4f)\n", kind ? "tube" : "sphere point",
               sum * px * px, area);
        CHECK_NEAR(sum * px * px, area, 0.03 * area);
        if (kind == 0)
            CHECK(err / (W * W) < 0.02);
        else
            CHECK(outside == 0.0);
        if (kind == 1) { /* blurred: the middle sees the tube a quarter of the shutter */
            double mid = img ? img->rgba[4 * ((W / 2) * W + W / 2) + 3] : 0;
            CHECK_NEAR(mid, 0.25, 0.05);
        }
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

/* A sphere point (diameter 2) from x = -1 to x = 1: by its transform
 * (deform 0) or by its two positions in a motion block (deform 1). */
static RayesScene *point_scene(int deform)
{
    RayesScene *s = rayes_scene_new();
    ortho_camera(s);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    RayesParam lp[2] = {{"from", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                        {"to", RAYES_PARAM_COLOR, {0.3f, 0.2f, 1}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", lp, 2) == RAYES_OK);
    const float times[2] = {0, 1}, width = 2.0f;
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &width, 1};
    if (!deform) {
        float m[2][16];
        translate(m[0], -1, 0, 0);
        translate(m[1], 1, 0, 0);
        CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
        const float P[3] = {0, 0, 0};
        CHECK(rayes_scene_points(s, RAYES_POINT_SPHERE, 1, P, &pv, 1) == RAYES_OK);
        return s;
    }
    CHECK(rayes_scene_motion_begin(s, 2, times) == RAYES_OK);
    for (int k = 0; k < 2; k++) {
        const float P[3] = {k ? 1.0f : -1.0f, 0, 0};
        CHECK(rayes_scene_points(s, RAYES_POINT_SPHERE, 1, P, &pv, 1) == RAYES_OK);
    }
    CHECK(rayes_scene_motion_end(s) == RAYES_OK);
    return s;
}

/* The fraction of the shutter [0, 1] a tube whose axis runs from x = -1
 * to x = 1 while its width grows from 0.5 to 1.5 covers abscissa x (its
 * straight part): a midpoint sum over 4,000 times. */
static double tube_time_coverage(double x)
{
    int n = 4000, in = 0;
    for (int i = 0; i < n; i++) {
        double t = (i + 0.5) / n;
        in += fabs(x - (-1.0 + 2.0 * t)) < 0.5 * (0.5 + t);
    }
    return (double)in / n;
}

/* Deforming points and curves (a motion block around Points or Curves of
 * the same topology): a point moved by its positions renders as the same
 * motion by transform, and a vertical tube whose axis moves and whose
 * width grows covers each pixel for its analytic fraction of the
 * shutter. */
static void test_deforming_points_and_curves(void)
{
    RayesScene *a = point_scene(0), *b = point_scene(1);
    RayesImage *ia = render(a, 16, 2, 1, NULL), *ib = render(b, 16, 2, 1, NULL);
    double worst = 0, mean = 0, cover = 0;
    for (size_t i = 0; ia && ib && i < 4 * (size_t)W * W; i++) {
        worst = fmax(worst, fabs(ia->rgba[i] - ib->rgba[i]));
        mean += fabs(ia->rgba[i] - ib->rgba[i]) / (4.0 * W * W);
        if (i % 4 == 3)
            cover += ib->rgba[i];
    }
    float px = 2 * HALF / W;
    CHECK_NEAR(cover * px * px, M_PI, 0.03 * M_PI);
    CHECK(mean < 1e-4);
    CHECK(worst < 0.02);
    printf("  deforming point vs transform: mean difference %.2g, largest %.2g, coverage %.4f\n",
           mean, worst, cover * px * px);
    rayes_image_free(ia);
    rayes_image_free(ib);
    rayes_scene_release(a);
    rayes_scene_release(b);

    RayesScene *s = rayes_scene_new();
    ortho_camera(s);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    const float times[2] = {0, 1};
    CHECK(rayes_scene_motion_begin(s, 2, times) == RAYES_OK);
    for (int k = 0; k < 2; k++) {
        float x = k ? 1.0f : -1.0f, width = k ? 1.5f : 0.5f;
        const float P[6] = {x, -1.5f, 0, x, 1.5f, 0};
        const int nv = 2;
        RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1,
                         .n_verts = &nv, .P = P};
        RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &width, 1};
        CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
    }
    CHECK(rayes_scene_motion_end(s) == RAYES_OK);
    RayesStats *st = NULL;
    RayesImage *img = render(s, 64, 2, 1, &st);
    const RayesStat *moving = rayes_stats_find(st, "motion/moving_grids");
    CHECK(moving && moving->count > 0);
    rayes_stats_free(st);
    double err = 0, worst_px = 0;
    int n = 0;
    for (int y = 0; img && y < W; y++)
        for (int x = 0; x < W; x++) {
            double cy = HALF - (y + 0.5) * px;
            if (fabs(cy) > 1.2) /* the straight part, away from the end caps */
                continue;
            double want = 0;
            for (int i = 0; i < 4; i++) /* the pixel's mean over 4 abscissae */
                want += tube_time_coverage(-HALF + (x + (i + 0.5) / 4) * px) / 4;
            double got = img->rgba[4 * (y * W + x) + 3];
            err += fabs(got - want);
            worst_px = fmax(worst_px, fabs(got - want));
            n++;
        }
    CHECK(n > 0 && err / n < 0.01);
    CHECK(worst_px < 0.15);
    printf("  deforming tube: mean |coverage error| %.4f, worst %.3f\n", err / n, worst_px);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A lit bilinear patch (4 x 2 units, facing the camera) moving from x = -1
 * to x = 1: by its transform, or by its two shapes. */
static RayesScene *patch_scene(int deform, float motionfactor)
{
    RayesScene *s = rayes_scene_new();
    ortho_camera(s);
    CHECK(rayes_scene_set_dice_blur(s, motionfactor, 0) == RAYES_OK);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    RayesParam lp[2] = {{"from", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                        {"to", RAYES_PARAM_COLOR, {0.3f, 0.2f, 1}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", lp, 2) == RAYES_OK);
    const float times[2] = {0, 1};
    float P[4][3] = {{-2, -1, 0}, {2, -1, 0}, {-2, 1, 0.5f}, {2, 1, 0.5f}};
    if (!deform) {
        float m[2][16];
        translate(m[0], -1, 0, 0);
        translate(m[1], 1, 0, 0);
        CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
        return s;
    }
    CHECK(rayes_scene_motion_begin(s, 2, times) == RAYES_OK);
    for (int k = 0; k < 2; k++) {
        float Q[4][3];
        memcpy(Q, P, sizeof Q);
        for (int i = 0; i < 4; i++)
            Q[i][0] += k ? 1.0f : -1.0f;
        CHECK(rayes_scene_bilinear_patch(s, Q) == RAYES_OK);
    }
    CHECK(rayes_scene_motion_end(s) == RAYES_OK);
    return s;
}

static void deformation_equals_transform(float motionfactor)
{
    RayesScene *a = patch_scene(0, motionfactor), *b = patch_scene(1, motionfactor);
    RayesImage *ia = render(a, 16, 2, 1, NULL), *ib = render(b, 16, 2, 1, NULL);
    double worst = 0, mean = 0, cover = 0;
    for (size_t i = 0; ia && ib && i < 4 * (size_t)W * W; i++) {
        worst = fmax(worst, fabs(ia->rgba[i] - ib->rgba[i]));
        mean += ia->rgba[i];
        if (i % 4 == 3)
            cover += ia->rgba[i];
    }
    CHECK(mean > 0);
    /* The patch sweeps 4 + 2 = 6 units wide, 2 tall: area 8 times 1. */
    float px = 2 * HALF / W;
    CHECK_NEAR(cover * px * px, 8.0, 0.08);
    CHECK(worst < 1e-5);
    printf("  deformation vs transform (motionfactor %g): largest difference %.2g\n", motionfactor,
           worst);
    rayes_image_free(ia);
    rayes_image_free(ib);
    rayes_scene_release(a);
    rayes_scene_release(b);
}

/* Also with motionfactor: both blurs measure the same motion, so dice
 * alike. */
static void test_deformation_equals_transform(void)
{
    deformation_equals_transform(0.0f);
    deformation_equals_transform(1.0f);
}

/* Bad motion calls are refused with a message. */
static void test_bad_motion(void)
{
    RayesScene *s = rayes_scene_new();
    const float times[3] = {0, 1, 0.5f};
    float m[3][16];
    for (int k = 0; k < 3; k++)
        translate(m[k], 0, 0, 0);
    CHECK(rayes_scene_set_transform_motion(s, 3, times, (const float(*)[16])m) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "increasing") != NULL);
    CHECK(rayes_scene_set_transform_motion(s, 1, times, (const float(*)[16])m) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_shutter(s, 1, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_motion_end(s) == RAYES_ERROR_INVALID_OPERATION);
    /* different topology: a patch, then a sphere */
    CHECK(rayes_scene_motion_begin(s, 2, times) == RAYES_OK);
    float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1) == RAYES_OK);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_motion_end(s) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "same topology") != NULL);
    CHECK(rayes_scene_set_depth_of_field(s, 1, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_dice_blur(s, -1, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_release(s);
}

/* A moving camera: the still sphere blurs as the moving sphere did. */
static void test_camera_motion(void)
{
    RayesScene *a = rayes_scene_new(), *b = rayes_scene_new();
    ortho_camera(a);
    ortho_camera(b);
    CHECK(rayes_scene_set_shutter(a, 0.0f, 1.0f) == RAYES_OK);
    CHECK(rayes_scene_set_shutter(b, 0.0f, 1.0f) == RAYES_OK);
    const float times[2] = {0, 1};
    float m[2][16];
    translate(m[0], -1, 0, 0);
    translate(m[1], 1, 0, 0);
    CHECK(rayes_scene_set_transform_motion(a, 2, times, (const float(*)[16])m) == RAYES_OK);
    CHECK(rayes_scene_sphere(a, 1.0f) == RAYES_OK);
    float cam[2][16]; /* camera_from_world: the world moves by -1 .. +1 in the camera */
    translate(cam[0], -1, 0, 5);
    translate(cam[1], 1, 0, 5);
    CHECK(rayes_scene_set_camera_motion(b, 2, times, (const float(*)[16])cam) == RAYES_OK);
    CHECK(rayes_scene_sphere(b, 1.0f) == RAYES_OK);
    RayesImage *ia = render(a, 16, 2, 1, NULL), *ib = render(b, 16, 2, 1, NULL);
    double worst = 0;
    for (size_t i = 3; ia && ib && i < 4 * (size_t)W * W; i += 4)
        worst = fmax(worst, fabs(ia->rgba[i] - ib->rgba[i]));
    CHECK(worst < 1e-4);
    printf("  camera motion vs object motion: largest coverage difference %.2g\n", worst);
    rayes_image_free(ia);
    rayes_image_free(ib);
    rayes_scene_release(a);
    rayes_scene_release(b);
}

enum { BOX_LIGHT_MOVES = 1, BOX_INSTANCED = 2 };

/* The Cornell box with a white sphere rising and swinging toward the red
 * wall over the shutter (3 samples, 2 motion segments); flags
 * BOX_LIGHT_MOVES: and a point light moving 156 units (of the box's 555)
 * above it; BOX_INSTANCED: the sphere an instance of a master moved by
 * the instance's transform; hider: RayesHider. */
static RayesImage *box_render_with(int cache, double cache_mb, int threads, const float crop[4],
                                   RayesStats **stats, int flags, int hider)
{
    int light_moves = flags & BOX_LIGHT_MOVES;
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    const float times[3] = {0, 0.5f, 1};
    float m[3][16];
    translate(m[0], 300, 100, 150);
    translate(m[1], 380, 180, 150);
    translate(m[2], 420, 200, 150);
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    if (flags & BOX_INSTANCED) {
        CHECK(rayes_scene_object_begin(s, "ball") == RAYES_OK);
        CHECK(rayes_scene_sphere(s, 80.0f) == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
    }
    CHECK(rayes_scene_set_transform_motion(s, 3, times, (const float(*)[16])m) == RAYES_OK);
    CHECK((flags & BOX_INSTANCED ? rayes_scene_object_instance(s, "ball")
                                 : rayes_scene_sphere(s, 80.0f)) == RAYES_OK);
    if (light_moves) {
        float lm[2][16];
        translate(lm[0], 210, 420, 200);
        translate(lm[1], 330, 420, 300);
        const float lt[2] = {0, 1};
        CHECK(rayes_scene_set_transform_motion(s, 2, lt, (const float(*)[16])lm) == RAYES_OK);
        RayesParam lp = {"intensity", RAYES_PARAM_FLOAT, {40000, 0, 0}, NULL};
        CHECK(rayes_scene_light(s, "pointlight", &lp, 1) == RAYES_OK);
    }
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 128;
    o.spp = 16;
    o.threads = threads;
    o.hider = (RayesHider)hider;
    o.bounces = 1;
    o.diffuse_rays = 16;
    o.cache = cache;
    o.cache_mb = cache_mb;
    if (cache_mb < 1.0) /* a budget meant to evict: no other type's to borrow */
        o.opacity_cache_mb = o.irradiance_cache_mb = 0.0, o.env_guide = 0;
    if (crop)
        memcpy(o.crop, crop, sizeof o.crop);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

static RayesImage *box_render(int cache, double cache_mb, int threads, const float crop[4],
                              RayesStats **stats)
{
    return box_render_with(cache, cache_mb, threads, crop, stats, 0, RAYES_HIDER_RAYTRACE);
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

static void test_cached_segments_match_uncached(void)
{
    RayesStats *st = NULL;
    RayesImage *a = box_render(1, 100, 2, NULL, &st), *b = box_render(0, 100, 2, NULL, NULL);
    CHECK(a && b);
    const RayesStat *seg = rayes_stats_find(st, "motion/fills_by_segment");
    const RayesStat *nt = rayes_stats_find(st, "motion/time_samples");
    CHECK(nt && nt->count == 3);
    CHECK(seg && seg->n_counts == 2);
    if (seg && seg->n_counts == 2) {
        CHECK(seg->counts[0] > 0 && seg->counts[1] > 0);
        printf("  radiosity fills by segment: %llu %llu\n", (unsigned long long)seg->counts[0],
               (unsigned long long)seg->counts[1]);
    }
    if (a && b) {
        double ma = tile_mean(a, 0, 0, 128), mb = tile_mean(b, 0, 0, 128), worst = 0;
        for (int y = 0; y < 128; y += 32)
            for (int x = 0; x < 128; x += 32) {
                double ta = tile_mean(a, x, y, 32), tb = tile_mean(b, x, y, 32);
                worst = fmax(worst, fabs(ta - tb) / tb);
            }
        CHECK(fabs(ma - mb) < 0.01 * mb);
        CHECK(worst < 0.03);
        printf("  cached vs uncached: means %.5f %.5f (%.2f%%), worst 32 x 32 tile %.2f%%\n", ma,
               mb, 100 * fabs(ma - mb) / mb, 100 * worst);
    }
    rayes_stats_free(st);
    rayes_image_free(a);
    rayes_image_free(b);
}

/* The same bytes for 1 and 2 threads, a 200 kB cache (evicting), and in a crop
 * window. */
static void test_motion_determinism(void)
{
    RayesImage *a = box_render(1, 100, 2, NULL, NULL), *b = box_render(1, 100, 1, NULL, NULL);
    RayesStats *st = NULL;
    RayesImage *c = box_render(1, 0.2, 2, NULL, &st);
    CHECK(test_cache_evictions(st, "radiosity") > 0);
    rayes_stats_free(st);
    const float crop[4] = {0.3f, 0.7f, 0.4f, 0.9f};
    RayesImage *d = box_render(1, 100, 2, crop, NULL);
    CHECK(a && b && c && d);
    size_t n = 4 * (size_t)128 * 128;
    if (a && b && c)
        CHECK(memcmp(a->rgba, b->rgba, n * sizeof *a->rgba) == 0 &&
              memcmp(a->rgba, c->rgba, n * sizeof *a->rgba) == 0);
    int same = 1, inside = 0;
    for (int y = 0; a && d && y < 128; y++)
        for (int x = 0; x < 128; x++) {
            size_t i = 4 * ((size_t)y * 128 + x);
            if (d->rgba[i + 3] == 0 && d->rgba[i] == 0)
                continue; /* outside the window */
            inside++;
            same &= memcmp(&a->rgba[i], &d->rgba[i], 4 * sizeof *a->rgba) == 0;
        }
    CHECK(same && inside > 1000);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
    rayes_image_free(d);
}

/* Attribute "dice" "motionfactor": a sphere blurred across 32 pixels is
 * diced coarser (edges 1 + 32/16 = 3 times longer), covering the same. */
static void test_motionfactor(void)
{
    uint64_t verts[2];
    double cover[2];
    for (int k = 0; k < 2; k++) {
        RayesScene *s = rayes_scene_new();
        ortho_camera(s);
        CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
        CHECK(rayes_scene_set_dice_blur(s, k ? 1.0f : 0.0f, 0.0f) == RAYES_OK);
        float m[2][16];
        translate(m[0], -1, 0, 0);
        translate(m[1], 1, 0, 0);
        const float times[2] = {0, 1};
        CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
        CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
        RayesStats *st = NULL;
        RayesImage *img = render(s, 16, 2, 1, &st);
        const RayesStat *v = rayes_stats_find(st, "grid_vertices");
        verts[k] = v ? v->count : 0;
        cover[k] = 0;
        for (size_t i = 3; img && i < 4 * (size_t)W * W; i += 4)
            cover[k] += img->rgba[i];
        rayes_stats_free(st);
        rayes_image_free(img);
        rayes_scene_release(s);
    }
    CHECK(verts[1] * 4 < verts[0]);
    CHECK(fabs(cover[1] / cover[0] - 1) < 0.01);
    printf("  motionfactor 1: %llu grid vertices instead of %llu, coverage %+.2f%%\n",
           (unsigned long long)verts[1], (unsigned long long)verts[0],
           100 * (cover[1] / cover[0] - 1));
}

/* The ray tracing structure of a patch turning half round about y (0, 90
 * and 180 degrees at times 0, 0.5, 1) beside a still one: a ray at time t
 * meets the moving patch where it is then, with the normal it has then
 * (the side the cache keys), and the motion segment of its time; the
 * still patch keeps segment 0 and its own vertices only. */
static void test_moving_hits(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    const float times[3] = {0, 0.5f, 1};
    float m[3][16];
    for (int k = 0; k < 3; k++) {
        float a = (float)M_PI * (float)k / 2, c = cosf(a), sn = sinf(a);
        const float r[16] = {c, 0, sn, 0, 0, 1, 0, 0, -sn, 0, c, 0, 0, 0, 0, 1};
        memcpy(m[k], r, sizeof r);
    }
    CHECK(rayes_scene_set_transform_motion(s, 3, times, (const float(*)[16])m) == RAYES_OK);
    float P[4][3] = {{-1, -1, 0}, {1, -1, 0}, {-1, 1, 0}, {1, 1, 0}}; /* normal +z at t = 0 */
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_set_transform(s, identity) == RAYES_OK);
    float Q[4][3] = {{5, -1, 0}, {7, -1, 0}, {5, 1, 0}, {7, 1, 0}};
    CHECK(rayes_scene_bilinear_patch(s, Q) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 64, 64, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    CHECK(gs.n_times == 3);
    size_t moving = 0, still_vertices = 0;
    for (size_t g = 0; g < gs.n_grids; g++) {
        moving += gs.grids[g].moving;
        if (!gs.grids[g].moving)
            still_vertices += geom_grid_n_vertices(&gs.grids[g]);
    }
    CHECK(moving > 0 && still_vertices > 0);
    CHECK(gs.n_motion_vertices + still_vertices == gs.n_vertices); /* only movers sampled */
    uint32_t masks[1] = {RAYES_RAY_CAMERA};
    char err[256];
    Accel *a = accel_new(&gs, masks, 1, NULL, err, sizeof err);
    CHECK(a != NULL);
    /* Along -z through (0.3, 0.2): the patch at t = 0 faces the ray's
     * origin with +z; at t = 1 it is turned round and faces it with -z;
     * at t = 0.5 it is edge on (missed). */
    const float ts[3] = {0.0f, 0.5f, 1.0f};
    const int want_hit[3] = {1, 0, 1};
    const float want_nz[3] = {1, 0, -1};
    for (int k = 0; a && k < 3; k++) {
        Ray r = {v3(0.3f, 0.2f, 5), v3(0, 0, -1), 0.0f, 1e30f, RAYES_RAY_CAMERA, ts[k]};
        Hit h;
        int hit = accel_intersect(a, &r, &h);
        CHECK(hit == want_hit[k]);
        if (hit && want_hit[k]) {
            CHECK_NEAR(h.t, 5.0, 1e-3);
            CHECK_NEAR(h.Ng.z, want_nz[k], 1e-3);
            float f;
            CHECK(geom_motion_segment(&gs, ts[k], &f) == (k == 2 ? 1 : 0));
        }
    }
    /* The still patch: the same at every time. */
    for (int k = 0; a && k < 3; k++) {
        Ray r = {v3(6, 0, 5), v3(0, 0, -1), 0.0f, 1e30f, RAYES_RAY_CAMERA, ts[k]};
        Hit h;
        CHECK(accel_intersect(a, &r, &h) && !gs.grids[h.grid].moving);
    }
    accel_free(a);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

/* Means within 1%, 32 x 32 tiles (those not near black) within 3%. */
static void check_close(const char *what, const RayesImage *a, const RayesImage *b)
{
    CHECK(a && b);
    if (!a || !b)
        return;
    double ma = tile_mean(a, 0, 0, 128), mb = tile_mean(b, 0, 0, 128), worst = 0;
    for (int y = 0; y < 128; y += 32)
        for (int x = 0; x < 128; x += 32) {
            double ta = tile_mean(a, x, y, 32), tb = tile_mean(b, x, y, 32);
            if (tb > 0.02 * mb)
                worst = fmax(worst, fabs(ta - tb) / tb);
        }
    CHECK(fabs(ma - mb) < 0.01 * mb);
    CHECK(worst < 0.03);
    printf("  %s: means %.5f %.5f (%.2f%%), worst 32 x 32 tile %.2f%%\n", what, ma, mb,
           100 * fabs(ma - mb) / mb, 100 * worst);
}

/* The time average of a point light of intensity pi moving from (-1, 0,
 * -1) to (1, 0, -1) over a matte plane z = 0 seen from -z, a sphere of
 * radius 0.25 at (0, 0, -0.5) (seen by shadow rays only) between them:
 * radiance h / d^3 where the light is seen, at (x, y), over 512 times. */
static double moving_light_radiance(double x, double y)
{
    double sum = 0;
    for (int i = 0; i < 512; i++) {
        double lx = -1.0 + 2.0 * (i + 0.5) / 512, dx = lx - x, dy = -y, dz = -1.0;
        double d = sqrt(dx * dx + dy * dy + dz * dz);
        /* the segment from (x, y, 0) to the light against the sphere */
        double cx = -x, cy = -y, cz = -0.5; /* the centre from the point */
        double s = (cx * dx + cy * dy + cz * dz) / (d * d);
        s = s < 0 ? 0 : s > 1 ? 1 : s;
        double ex = cx - s * dx, ey = cy - s * dy, ez = cz - s * dz;
        if (ex * ex + ey * ey + ez * ez >= 0.25 * 0.25)
            sum += 1.0 / (d * d * d);
    }
    return sum / 512;
}

/* A light moving within the frame (rayes_scene_light under a moving
 * transform): each ray sees it where it is at the ray's time, so a matte
 * plane's light and the shadow of a sphere blur as the analytic time
 * average; the light still at its middle position differs. */
static void test_moving_light_shadow(void)
{
    RayesImage *img[2];
    for (int still = 0; still < 2; still++) {
        RayesScene *s = rayes_scene_new();
        ortho_camera(s);
        CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
        float m[2][16];
        translate(m[0], 0, 0, -0.5f);
        CHECK(rayes_scene_set_transform(s, m[0]) == RAYES_OK);
        CHECK(rayes_scene_set_visibility(s, RAYES_RAY_SHADOW) == RAYES_OK);
        CHECK(rayes_scene_sphere(s, 0.25f) == RAYES_OK);
        CHECK(rayes_scene_set_visibility(s, 0x1fu /* every ray */) == RAYES_OK);
        translate(m[0], still ? 0.0f : -1.0f, 0, -1);
        translate(m[1], still ? 0.0f : 1.0f, 0, -1);
        const float times[2] = {0, 1};
        CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
        RayesParam lp = {"intensity", RAYES_PARAM_FLOAT, {(float)M_PI, 0, 0}, NULL};
        CHECK(rayes_scene_light(s, "pointlight", &lp, 1) == RAYES_OK);
        CHECK(rayes_scene_set_transform(s, identity) == RAYES_OK);
        CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
        float P[4][3] = {{-4, -4, 0}, {4, -4, 0}, {-4, 4, 0}, {4, 4, 0}};
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
        img[still] = render(s, 64, 2, 0, NULL);
        rayes_scene_release(s);
    }
    double err = 0, worst = 0, off = 0;
    float px = 2 * HALF / W;
    for (int y = 0; img[0] && img[1] && y < W; y++)
        for (int x = 0; x < W; x++) {
            double want = 0;
            for (int j = 0; j < 2; j++)
                for (int i = 0; i < 2; i++)
                    want += moving_light_radiance(-HALF + (x + (i + 0.5) / 2) * px,
                                                  HALF - (y + (j + 0.5) / 2) * px) / 4;
            double got = img[0]->rgba[4 * (y * W + x)];
            err += fabs(got - want);
            worst = fmax(worst, fabs(got - want));
            off = fmax(off, fabs(img[1]->rgba[4 * (y * W + x)] - want));
        }
    err /= W * W;
    CHECK(err < 0.01);
    CHECK(worst < 0.1);
    CHECK(off > 0.2); /* the light held still at its middle is another picture */
    printf("  moving light: mean |error| %.4f, worst %.3f (still light: worst %.3f)\n", err, worst,
           off);
    rayes_image_free(img[0]);
    rayes_image_free(img[1]);
}

/* A light moving through the box: cached radiosity (fills at the shutter's
 * middle for still grids, the segment's for moving ones) against uncached
 * (every ray at its own time), and the grid hider (which shades grids lit
 * by a moving light per hit) against the ray-tracing hider. */
static void test_moving_light_cached(void)
{
    RayesImage *a = box_render_with(1, 100, 2, NULL, NULL, 1, RAYES_HIDER_RAYTRACE);
    RayesImage *b = box_render_with(0, 100, 2, NULL, NULL, 1, RAYES_HIDER_RAYTRACE);
    RayesImage *c = box_render_with(1, 100, 2, NULL, NULL, 1, RAYES_HIDER_GRID);
    check_close("moving light, cached vs uncached", a, b);
    check_close("moving light, grid hider vs ray tracing", c, a);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(c);
}

/* A matte sphere moving from x = -1 through (0, 0.3) to x = 1 (3 samples,
 * 2 motion segments, or with fine 5: the same path in 4 segments) under a
 * point light, rendered with a hider. */
static RayesImage *hider_sphere(int hider, int threads, int fine, RayesStats **stats)
{
    RayesScene *s = rayes_scene_new();
    ortho_camera(s);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    RayesParam lp[2] = {{"from", RAYES_PARAM_COLOR, {0, 3, -6}, NULL},
                        {"intensity", RAYES_PARAM_FLOAT, {150, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
    int n = fine ? 5 : 3;
    float times[5], m[5][16];
    for (int k = 0; k < n; k++) {
        times[k] = (float)k / (float)(n - 1);
        float x = 2.0f * times[k] - 1.0f;
        translate(m[k], x, 0.3f * (1.0f - fabsf(x)), 0);
    }
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_transform_motion(s, (size_t)n, times, (const float(*)[16])m) ==
          RAYES_OK);
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = W;
    o.spp = 16;
    o.threads = threads;
    o.bounces = 0;
    o.hider = (RayesHider)hider;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, stats) == RAYES_OK);
    rayes_scene_release(s);
    return img;
}

/* Mean relative difference of a and b (RGB), and the worst over 16 x 16
 * tiles the sphere mostly covers, into *worst. */
static double hider_diff(const RayesImage *a, const RayesImage *b, double *worst)
{
    double ma = 0, mb = 0;
    *worst = 0;
    for (int ty = 0; a && b && ty < W; ty += 16)
        for (int tx = 0; tx < W; tx += 16) {
            double ta = 0, tb = 0;
            for (int y = ty; y < ty + 16; y++)
                for (int x = tx; x < tx + 16; x++)
                    for (int c = 0; c < 3; c++) {
                        ta += a->rgba[4 * (y * W + x) + c];
                        tb += b->rgba[4 * (y * W + x) + c];
                    }
            ma += ta, mb += tb;
            if (tb > 0.2 * 16 * 16)
                *worst = fmax(*worst, fabs(ta - tb) / tb);
        }
    return mb > 0 ? fabs(ma - mb) / mb : 1.0;
}

/* The grid hider on moving grids: each is shaded once per motion segment
 * (where it is at the segment's middle time), and hits interpolate their
 * segment's shading. Against the ray-tracing hider (every hit shaded at
 * its own time) the means agree within 1%; the tiles differ by the
 * lighting's change within a segment, so less with more segments along
 * the same path; far fewer camera shading points; the same bytes for 1
 * and 2 threads. */
static void test_grid_hider_motion(void)
{
    RayesStats *sa = NULL, *sb = NULL;
    RayesImage *a = hider_sphere(RAYES_HIDER_GRID, 2, 0, &sa);
    RayesImage *b = hider_sphere(RAYES_HIDER_RAYTRACE, 2, 0, &sb);
    RayesImage *af = hider_sphere(RAYES_HIDER_GRID, 2, 1, NULL);
    RayesImage *bf = hider_sphere(RAYES_HIDER_RAYTRACE, 2, 1, NULL);
    CHECK(a && b && af && bf);
    double worst, worst_f, mean = hider_diff(a, b, &worst), mean_f = hider_diff(af, bf, &worst_f);
    CHECK(mean < 0.01 && mean_f < 0.01);
    CHECK(worst > 0 && worst < 0.08 && worst_f < 0.75 * worst);
    printf("  moving sphere, grid hider vs ray tracing: 2 segments: means %.2f%%, worst 16 x 16 "
           "tile %.2f%%; 4 segments: %.2f%%, %.2f%%\n",
           100 * mean, 100 * worst, 100 * mean_f, 100 * worst_f);
    const RayesStat *pa = rayes_stats_find(sa, "shading_points/by_depth");
    const RayesStat *pb = rayes_stats_find(sb, "shading_points/by_depth");
    CHECK(pa && pb && pa->n_counts > 0 && pb->n_counts > 0);
    if (pa && pb && pa->n_counts > 0 && pb->n_counts > 0) {
        CHECK(pa->counts[0] * 2 < pb->counts[0]);
        printf("  depth-0 shading points: grid hider %llu, ray tracing %llu\n",
               (unsigned long long)pa->counts[0], (unsigned long long)pb->counts[0]);
    }
    rayes_stats_free(sa);
    rayes_stats_free(sb);
    RayesImage *c = hider_sphere(RAYES_HIDER_GRID, 1, 0, NULL);
    CHECK(a && c && memcmp(a->rgba, c->rgba, 4 * sizeof *a->rgba * W * W) == 0);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(af);
    rayes_image_free(bf);
    rayes_image_free(c);
}

/* The unit sphere of test_moving_sphere_coverage, moving from x = -1 to
 * 1 over the shutter: placed directly (instanced 0), as an instance of a
 * master under the moving transform (1), or nested (2): a still instance
 * inside a block, the block's instance moving (composed per sample). */
static RayesImage *moving_ball(int instanced, int spp, int threads)
{
    RayesScene *s = rayes_scene_new();
    ortho_camera(s);
    CHECK(rayes_scene_set_shutter(s, 0.0f, 1.0f) == RAYES_OK);
    float m[2][16], half[16];
    translate(m[0], -1, 0, 0);
    translate(m[1], 1, 0, 0);
    translate(half, 0.5f, 0, 0);
    const float times[2] = {0, 1};
    if (instanced) {
        CHECK(rayes_scene_object_begin(s, "ball") == RAYES_OK);
        CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
    }
    if (instanced == 2) { /* the ball half a unit right inside "outer" */
        CHECK(rayes_scene_object_begin(s, "outer") == RAYES_OK);
        CHECK(rayes_scene_set_transform(s, half) == RAYES_OK);
        CHECK(rayes_scene_object_instance(s, "ball") == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
        translate(m[0], -1.5f, 0, 0);
        translate(m[1], 0.5f, 0, 0);
    }
    CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
    CHECK((instanced == 2   ? rayes_scene_object_instance(s, "outer")
           : instanced == 1 ? rayes_scene_object_instance(s, "ball")
                            : rayes_scene_sphere(s, 1.0f)) == RAYES_OK);
    RayesImage *img = render(s, spp, threads, 1, NULL);
    rayes_scene_release(s);
    return img;
}

/* Instance motion: an instance under a moving transform blurs as the same
 * sphere moving by its own transform does (within the tessellations'
 * difference: the master is diced in master space), and covers each
 * pixel for its analytic share of the shutter; nested, the same; the same
 * bytes on 1 and 2 threads. */
static void test_moving_instance(void)
{
    RayesImage *direct = moving_ball(0, 64, 2), *inst = moving_ball(1, 64, 2);
    RayesImage *nested = moving_ball(2, 64, 2), *one = moving_ball(1, 64, 1);
    CHECK(direct && inst && nested && one);
    float px = 2 * HALF / W;
    double err = 0, worst = 0, sum = 0, diff = 0, worst_diff = 0, nested_diff = 0;
    for (int y = 0; direct && inst && nested && y < W; y++)
        for (int x = 0; x < W; x++) {
            double want = 0;
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++)
                    want += disk_time_coverage(-HALF + (x + (i + 0.5) / 4) * px,
                                               HALF - (y + (j + 0.5) / 4) * px) /
                            16;
            size_t k = 4 * ((size_t)y * W + x) + 3;
            double got = inst->rgba[k];
            err += fabs(got - want);
            worst = fmax(worst, fabs(got - want));
            sum += got;
            diff += fabs(got - direct->rgba[k]);
            worst_diff = fmax(worst_diff, fabs(got - direct->rgba[k]));
            nested_diff = fmax(nested_diff, fabs(nested->rgba[k] - got));
        }
    CHECK_NEAR(sum * px * px, M_PI, 0.01 * M_PI);
    CHECK(err / (W * W) < 0.01);
    CHECK(worst < 0.15);
    CHECK(diff / (W * W) < 0.002);
    CHECK(worst_diff < 0.05);
    CHECK(nested_diff < 0.05);
    if (inst && one)
        CHECK(memcmp(inst->rgba, one->rgba, 4 * (size_t)W * W * sizeof *inst->rgba) == 0);
    printf("  moving instance: coverage %.4f (pi %.4f), mean |error| %.4f, worst %.3f; against "
           "the sphere moved directly: mean |alpha diff| %.5f, worst %.4f; nested: worst %.4f\n",
           sum * px * px, M_PI, err / (W * W), worst, diff / (W * W), worst_diff, nested_diff);
    rayes_image_free(direct);
    rayes_image_free(inst);
    rayes_image_free(nested);
    rayes_image_free(one);
}

/* The Cornell box's moving sphere as a moving instance: cached radiosity
 * (entries per instance and motion segment) against uncached within 1%
 * mean, 3% per tile; fills in both segments. */
static void test_moving_instance_cached(void)
{
    RayesStats *st = NULL;
    RayesImage *a = box_render_with(1, 100, 2, NULL, &st, BOX_INSTANCED, RAYES_HIDER_RAYTRACE);
    RayesImage *b = box_render_with(0, 100, 2, NULL, NULL, BOX_INSTANCED, RAYES_HIDER_RAYTRACE);
    const RayesStat *seg = rayes_stats_find(st, "motion/fills_by_segment");
    CHECK(seg && seg->n_counts == 2);
    if (seg && seg->n_counts == 2) {
        CHECK(seg->counts[0] > 0 && seg->counts[1] > 0);
        printf("  moving instance: radiosity fills by segment %llu %llu\n",
               (unsigned long long)seg->counts[0], (unsigned long long)seg->counts[1]);
    }
    check_close("moving instance, cached vs uncached", a, b);
    rayes_stats_free(st);
    rayes_image_free(a);
    rayes_image_free(b);
}

/* Against the sphere moved directly within 1% mean, 3% per tile, with
 * either hider; the same bytes on 1 and 2 threads; the grid hider
 * (which shades a grid seen through a moving instance per hit) against
 * itself on the sphere moved directly: it shades still grids once (the
 * walls see the sphere's shadow at one time), so it is not compared with
 * ray tracing here. */
static void test_moving_instance_threads_and_hider(void)
{
    RayesImage *a = box_render_with(1, 100, 2, NULL, NULL, BOX_INSTANCED, RAYES_HIDER_RAYTRACE);
    RayesImage *c = box_render_with(1, 100, 1, NULL, NULL, BOX_INSTANCED, RAYES_HIDER_RAYTRACE);
    RayesImage *e = box_render_with(1, 100, 2, NULL, NULL, BOX_INSTANCED, RAYES_HIDER_GRID);
    RayesImage *d = box_render(1, 100, 2, NULL, NULL);
    RayesImage *f = box_render_with(1, 100, 2, NULL, NULL, 0, RAYES_HIDER_GRID);
    size_t n = 4 * (size_t)128 * 128 * sizeof *a->rgba;
    CHECK(a && c && e && d && f);
    if (a && c)
        CHECK(memcmp(a->rgba, c->rgba, n) == 0);
    check_close("moving instance vs the sphere moved directly", a, d);
    check_close("moving instance vs the sphere moved directly, grid hider", e, f);
    rayes_image_free(a);
    rayes_image_free(c);
    rayes_image_free(e);
    rayes_image_free(d);
    rayes_image_free(f);
}

TEST_MAIN(TEST(test_moving_instance_cached), TEST_THREADS(test_moving_instance_threads_and_hider),
          TEST_THREADS(test_moving_instance), TEST(test_moving_hits),
          TEST(test_moving_sphere_coverage), TEST(test_moving_points_and_curves),
          TEST(test_deforming_points_and_curves), TEST(test_moving_light_shadow),
          TEST(test_moving_light_cached), TEST_THREADS(test_grid_hider_motion),
          TEST(test_motionfactor), TEST(test_cached_segments_match_uncached),
          TEST_THREADS(test_motion_determinism), TEST(test_deformation_equals_transform),
          TEST(test_bad_motion), TEST(test_camera_motion))
