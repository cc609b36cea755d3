/*
 * Time in the readers: RIB's MotionBegin (around transforms, with samples
 * composed with later transforms; around primitives), Shutter, Option
 * "shutter" "offset", DepthOfField and Attribute "dice" "motionfactor";
 * pbrt-v4's ActiveTransform/TransformTimes, shutteropen/shutterclose and
 * lensradius/focaldistance. Each file renders the same coverage as the
 * same scene made through rayes.h; bad input names file:line; the RIB
 * writer writes motion, shutter and lens back and the result reads the
 * same (rayes convert round-trips).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "io/pbrt.h"
#include "io/rib.h"
#include "io/rib_write.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "record_sink.h"
#include "test.h"

#define W 48

static char err[1024];

static RayesScene *read(const char *text, int pbrt, RayesError *e)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    err[0] = '\0';
    size_t n = strlen(text);
    *e = pbrt ? io_pbrt_parse("t.pbrt", (const unsigned char *)text, n, &sink, &opt, &settings, err,
                              sizeof err)
              : io_rib_parse("t.rib", (const unsigned char *)text, n, &sink, &opt, &settings, err,
                             sizeof err);
    if (*e != RAYES_OK)
        printf("  (%s)\n", err);
    return s;
}

static RayesImage *render(RayesScene *s)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = W, o.spp = 16, o.bounces = 0, o.threads = 2;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

/* The largest alpha difference between two renders. */
static double alpha_diff(const RayesImage *a, const RayesImage *b)
{
    double worst = a && b ? 0 : 1;
    for (size_t i = 3; a && b && i < 4 * (size_t)W * W; i += 4)
        worst = fmax(worst, fabs(a->rgba[i] - b->rgba[i]));
    return worst;
}

/* The largest RGB difference between two renders. */
static double rgb_diff(const RayesImage *a, const RayesImage *b)
{
    double worst = a && b ? 0 : 1;
    for (size_t i = 0; a && b && i < 4 * (size_t)W * W; i++)
        if (i % 4 != 3)
            worst = fmax(worst, fabs(a->rgba[i] - b->rgba[i]));
    return worst;
}

static double alpha_sum(const RayesImage *a)
{
    double sum = 0;
    for (size_t i = 3; a && i < 4 * (size_t)W * W; i += 4)
        sum += a->rgba[i];
    return sum;
}

static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/* The reference: a unit sphere moving from x0 to x1 (over times t0, t1 of a
 * shutter [0, 1]) before an orthographic camera 5 units away, or a sphere
 * at x = 0 through a lens. */
static RayesImage *reference(float x0, float x1, float t0, float t1, float lens, float focus)
{
    RayesScene *s = rayes_scene_new();
    float cam[16];
    memcpy(cam, identity, sizeof cam);
    cam[11] = 5;
    const float screen[4] = {-3, 3, -3, 3};
    CHECK(rayes_scene_set_camera_matrix(
              s, cam, lens > 0 ? RAYES_PROJECTION_PERSPECTIVE : RAYES_PROJECTION_ORTHOGRAPHIC, 60,
              lens > 0 ? NULL : screen) == RAYES_OK);
    CHECK(rayes_scene_set_shutter(s, 0, 1) == RAYES_OK);
    if (lens > 0)
        CHECK(rayes_scene_set_depth_of_field(s, lens, focus) == RAYES_OK);
    if (x0 != x1) {
        float m[2][16], times[2] = {t0, t1};
        memcpy(m[0], identity, sizeof identity);
        memcpy(m[1], identity, sizeof identity);
        m[0][3] = x0, m[1][3] = x1;
        CHECK(rayes_scene_set_transform_motion(s, 2, times, (const float(*)[16])m) == RAYES_OK);
    }
    CHECK(rayes_scene_sphere(s, 1.0f) == RAYES_OK);
    RayesImage *img = render(s);
    rayes_scene_release(s);
    return img;
}

static RayesImage *from_file(const char *text, int pbrt)
{
    RayesError e;
    RayesScene *s = read(text, pbrt, &e);
    CHECK(e == RAYES_OK);
    RayesImage *img = e == RAYES_OK ? render(s) : NULL;
    rayes_scene_release(s);
    return img;
}

static const char *const rib_ortho = "Format 48 48 1\n"
                                     "Projection \"orthographic\"\n"
                                     "ScreenWindow -3 3 -3 3\n";

static void test_rib_transform_motion(void)
{
    char text[2048];
    /* Two samples composed with a later Scale (of 1: the motion survives
     * it), the shutter shifted by its offset onto the motion's times. */
    snprintf(text, sizeof text,
             "%sShutter 0 1\nOption \"shutter\" \"offset\" [10]\nTranslate 0 0 5\nWorldBegin\n"
             "AttributeBegin\nMotionBegin [10 11]\nTranslate -1 0 0\nTranslate 1 0 0\nMotionEnd\n"
             "Scale 1 1 1\nSphere 1 -1 1 360\nAttributeEnd\nWorldEnd\n",
             rib_ortho);
    RayesImage *a = from_file(text, 0), *b = reference(-1, 1, 0, 1, 0, 0);
    double d = alpha_diff(a, b);
    CHECK(d < 1e-5);
    CHECK(alpha_sum(b) > 0);
    /* A still sphere covers less: the blur is really there. */
    RayesImage *still = reference(0, 0, 0, 1, 0, 0);
    CHECK(alpha_diff(b, still) > 0.3);
    printf("  RIB transform motion vs rayes.h: %.2g\n", d);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(still);
}

static void test_rib_deformation_and_camera(void)
{
    char text[4096];
    /* The sphere as a deforming patch mesh would need the same topology;
     * a camera moving the other way gives the object motion's image. */
    snprintf(text, sizeof text,
             "%sShutter 0 1\nMotionBegin [0 1]\nTranslate -1 0 5\nTranslate 1 0 5\nMotionEnd\n"
             "WorldBegin\nSphere 1 -1 1 360\nWorldEnd\n",
             rib_ortho);
    RayesImage *a = from_file(text, 0), *b = reference(-1, 1, 0, 1, 0, 0);
    CHECK(alpha_diff(a, b) < 1e-5);
    rayes_image_free(a);
    rayes_image_free(b);
    /* Deformation: two bilinear patches, against the same motion as a
     * transform. */
    const char *deform = "Shutter 0 1\nTranslate 0 0 5\nWorldBegin\n"
                         "MotionBegin [0 1]\n"
                         "Patch \"bilinear\" \"P\" [-2 -1 0 0 -1 0 -2 1 0 0 1 0]\n"
                         "Patch \"bilinear\" \"P\" [0 -1 0 2 -1 0 0 1 0 2 1 0]\n"
                         "MotionEnd\nWorldEnd\n";
    const char *xform = "Shutter 0 1\nTranslate 0 0 5\nWorldBegin\n"
                        "MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 2 0 0\nMotionEnd\n"
                        "Patch \"bilinear\" \"P\" [-2 -1 0 0 -1 0 -2 1 0 0 1 0]\n"
                        "WorldEnd\n";
    snprintf(text, sizeof text, "%s%s", rib_ortho, deform);
    RayesImage *c = from_file(text, 0);
    snprintf(text, sizeof text, "%s%s", rib_ortho, xform);
    RayesImage *d = from_file(text, 0);
    CHECK(alpha_diff(c, d) < 1e-5);
    CHECK(fabs(alpha_sum(c) * 0.125 * 0.125 - 4.0) < 0.05); /* coverage over time keeps the
                                                                area, 2 x 2 */
    rayes_image_free(c);
    rayes_image_free(d);
}

static void test_rib_depth_of_field(void)
{
    /* fstop 2.8, focal length 2.8: a lens of radius 0.5, focused at 3. */
    const char *text = "Format 48 48 1\nProjection \"perspective\" \"fov\" [60]\n"
                       "DepthOfField 2.8 2.8 3\nTranslate 0 0 5\nWorldBegin\nSphere 1 -1 1 360\n"
                       "WorldEnd\n";
    RayesImage *a = from_file(text, 0), *b = reference(0, 0, 0, 1, 0.5f, 3);
    CHECK(alpha_diff(a, b) < 1e-5);
    rayes_image_free(a);
    rayes_image_free(b);
}

static void test_rib_errors(void)
{
    RayesError e;
    const char *bad[] = {
        "WorldBegin\nMotionBegin [0 1]\nTranslate 1 0 0\nMotionEnd\nWorldEnd\n",
        "WorldBegin\nMotionBegin [1 0]\nTranslate 1 0 0\nTranslate 0 0 0\nMotionEnd\nWorldEnd\n",
        "WorldBegin\nMotionBegin [0 1]\nTranslate 1 0 0\nSphere 1 -1 1 360\nMotionEnd\nWorldEnd\n",
        "Shutter 1 0\nWorldBegin\nWorldEnd\n",
        "DepthOfField 0 1 1\nWorldBegin\nWorldEnd\n",
        "WorldBegin\nAttribute \"dice\" \"motionfactor\" [-1]\nWorldEnd\n",
    };
    const char *want[] = {"t.rib:4", "t.rib:2", "t.rib:4", "t.rib:1", "t.rib:1", "t.rib:2"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        RayesScene *s = read(bad[k], 0, &e);
        CHECK(e != RAYES_OK);
        CHECK(strstr(err, want[k]) != NULL);
        if (e == RAYES_OK || !strstr(err, want[k]))
            printf("  case %zu: %s\n", k, err);
        rayes_scene_release(s);
    }
}

static const char *const pbrt_ortho =
    "Film \"rgb\" \"integer xresolution\" [48] \"integer yresolution\" [48]\n";

static void test_pbrt_motion_and_lens(void)
{
    char text[2048];
    snprintf(text, sizeof text,
             "%sTranslate 0 0 5\n"
             "Camera \"orthographic\" \"float screenwindow\" [-3 3 -3 3]\n"
             "WorldBegin\nAttributeBegin\nActiveTransform StartTime\nTranslate -1 0 0\n"
             "ActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n"
             "Shape \"sphere\" \"float radius\" [1]\nAttributeEnd\n",
             pbrt_ortho);
    RayesImage *a = from_file(text, 1), *b = reference(-1, 1, 0, 1, 0, 0);
    double d = alpha_diff(a, b);
    CHECK(d < 1e-5);
    printf("  pbrt ActiveTransform motion vs rayes.h: %.2g\n", d);
    rayes_image_free(a);
    /* TransformTimes and a shutter: the motion over [0, 2], the shutter
     * the first half of it: the sphere from -1 to 0. */
    snprintf(text, sizeof text,
             "%sTransformTimes 0 2\nTranslate 0 0 5\n"
             "Camera \"orthographic\" \"float screenwindow\" [-3 3 -3 3] "
             "\"float shutteropen\" [0] \"float shutterclose\" [1]\n"
             "WorldBegin\nActiveTransform StartTime\nTranslate -1 0 0\n"
             "ActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n"
             "Shape \"sphere\" \"float radius\" [1]\n",
             pbrt_ortho);
    RayesImage *c = from_file(text, 1), *half = reference(-1, 0, 0, 1, 0, 0);
    CHECK(alpha_diff(c, half) < 1e-5);
    rayes_image_free(c);
    rayes_image_free(half);
    rayes_image_free(b);
    snprintf(text, sizeof text,
             "%sTranslate 0 0 5\nCamera \"perspective\" \"float fov\" [60] "
             "\"float lensradius\" [0.5] \"float focaldistance\" [3]\n"
             "WorldBegin\nShape \"sphere\" \"float radius\" [1]\n",
             pbrt_ortho);
    RayesImage *l = from_file(text, 1), *lr = reference(0, 0, 0, 1, 0.5f, 3);
    CHECK(alpha_diff(l, lr) < 1e-5);
    rayes_image_free(l);
    rayes_image_free(lr);
    RayesError e;
    RayesScene *s = read("TransformTimes 1 0\n", 1, &e);
    CHECK(e != RAYES_OK && strstr(err, "t.pbrt:1") != NULL);
    rayes_scene_release(s);
    s = read("Camera \"perspective\" \"float lensradius\" [-1]\n", 1, &e);
    CHECK(e != RAYES_OK && strstr(err, "t.pbrt:1") != NULL);
    rayes_scene_release(s);
}

/* The RIB writer: what it writes of a file reads back to the same image. */
static void round_trip(const char *text, int pbrt)
{
    RibWriter *wr = io_rib_writer_new();
    IoSink sink = io_rib_writer_sink(wr);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    size_t n = strlen(text);
    RayesError e = pbrt ? io_pbrt_parse("t.pbrt", (const unsigned char *)text, n, &sink, &opt,
                                        &settings, err, sizeof err)
                        : io_rib_parse("t.rib", (const unsigned char *)text, n, &sink, &opt,
                                       &settings, err, sizeof err);
    CHECK(e == RAYES_OK);
    char *out = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&out, &size);
    CHECK(io_rib_writer_finish(wr, &settings, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    RayesImage *a = from_file(text, pbrt), *b = from_file(out, 0);
    double d = fmax(alpha_diff(a, b), rgb_diff(a, b));
    CHECK(d < 1e-5);
    CHECK(strstr(out, "MotionBegin") != NULL);
    if (d >= 1e-5)
        printf("  round trip differs by %g:\n%s\n", d, out);
    rayes_image_free(a);
    rayes_image_free(b);
    free(out);
    io_rib_writer_free(wr);
}

static void test_writer_round_trip(void)
{
    char text[4096];
    snprintf(text, sizeof text,
             "%sShutter 0 1\nDepthOfField 4 2 4\nMotionBegin [0 1]\nTranslate -0.5 0 5\n"
             "Translate 0.5 0 5\nMotionEnd\nWorldBegin\n"
             "AttributeBegin\nMotionBegin [0 0.5 1]\nTranslate -1 0 0\nTranslate 0 1 0\n"
             "Translate 1 0 0\nMotionEnd\nSphere 1 -1 1 360\nAttributeEnd\n"
             "MotionBegin [0 1]\nPatch \"bilinear\" \"P\" [-2 -2 1 0 -2 1 -2 -1 1 0 -1 1]\n"
             "Patch \"bilinear\" \"P\" [-1 -2 1 1 -2 1 -1 -1 1 1 -1 1]\nMotionEnd\nWorldEnd\n",
             "Format 48 48 1\nProjection \"perspective\" \"fov\" [60]\n");
    round_trip(text, 0);
    snprintf(text, sizeof text,
             "%sTranslate 0 0 5\nCamera \"perspective\" \"float fov\" [60] "
             "\"float lensradius\" [0.2] \"float focaldistance\" [4]\n"
             "WorldBegin\nActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n"
             "Shape \"sphere\" \"float radius\" [1]\n",
             pbrt_ortho);
    round_trip(text, 1);
    /* Primitives whose samples the writer writes unevenly: a bicubic
     * patch (its Basis written before the first sample only) and curves
     * (each sample in its own AttributeBegin block, with its Basis), and
     * deforming points. */
    snprintf(text, sizeof text,
             "%sShutter 0 1\nTranslate 0 0 5\nWorldBegin\nMotionBegin [0 1]\n"
             "Patch \"bicubic\" \"P\" [-2 -2 0 -1 -2 0 0 -2 0 1 -2 0 -2 -1 0 -1 -1 0 0 -1 0 1 -1 0 "
             "-2 0 0 -1 0 0 0 0 0 1 0 0 -2 1 0 -1 1 0 0 1 0 1 1 0]\n"
             "Patch \"bicubic\" \"P\" [-1 -2 0 0 -2 0 1 -2 0 2 -2 0 -1 -1 0 0 -1 0 1 -1 0 2 -1 0 "
             "-1 0 0 0 0 0 1 0 0 2 0 0 -1 1 0 0 1 0 1 1 0 2 1 0]\n"
             "MotionEnd\nMotionBegin [0 1]\n"
             "Curves \"cubic\" [4] \"nonperiodic\" \"P\" [-2 1.5 0 -1 2 0 1 2 0 2 1.5 0] "
             "\"constantwidth\" [0.3]\n"
             "Curves \"cubic\" [4] \"nonperiodic\" \"P\" [-2 2.5 0 -1 2 0 1 2 0 2 2.5 0] "
             "\"constantwidth\" [0.6]\nMotionEnd\nMotionBegin [0 1]\n"
             "Points \"P\" [-2 -2.5 0 2 -2.5 0] \"constantwidth\" [0.4]\n"
             "Points \"P\" [-1 -2.5 0 1 -2.5 0] \"constantwidth\" [0.4]\nMotionEnd\nWorldEnd\n",
             rib_ortho);
    round_trip(text, 0);
}

/* A RIB light under a moving transform (MotionBegin around its
 * Translate) moves within the frame: it lights a plane otherwise than
 * the light held at either end, the light at the far end lights it as the
 * reversed motion's does, and the writer writes the motion back. */
static void test_rib_moving_light(void)
{
    const char *fmt = "%sShutter 0 1\nTranslate 0 0 5\nWorldBegin\nTransformBegin\n"
                      "MotionBegin [0 1]\nTranslate %s 0 -1\nTranslate %s 0 -1\nMotionEnd\n"
                      "LightSource \"pointlight\" 1 \"intensity\" [1]\nTransformEnd\n"
                      "Surface \"matte\"\n"
                      "Patch \"bilinear\" \"P\" [-4 -4 0 4 -4 0 -4 4 0 4 4 0]\nWorldEnd\n";
    char text[4][2048];
    snprintf(text[0], sizeof text[0], fmt, rib_ortho, "-1", "1");
    snprintf(text[1], sizeof text[1], fmt, rib_ortho, "-1", "-1");
    snprintf(text[2], sizeof text[2], fmt, rib_ortho, "1", "1");
    snprintf(text[3], sizeof text[3], fmt, rib_ortho, "1", "-1");
    RayesImage *img[4];
    for (int k = 0; k < 4; k++)
        img[k] = from_file(text[k], 0);
    /* the plane is lit symmetrically about x = 0 by the moving light */
    double mirror = 0;
    for (int y = 0; img[0] && y < W; y++)
        for (int x = 0; x < W; x++)
            mirror = fmax(mirror, fabs(img[0]->rgba[4 * (y * W + x)] -
                                       img[0]->rgba[4 * (y * W + (W - 1 - x))]));
    /* (16 times a pixel: their strata sample the motion differently) */
    CHECK(mirror < 0.06);
    CHECK(rgb_diff(img[0], img[1]) > 0.2 && rgb_diff(img[0], img[2]) > 0.2);
    CHECK(rgb_diff(img[0], img[3]) < 0.06);
    printf("  RIB moving light: mirror %.3g, against still %.3g, reversed %.3g\n", mirror,
           rgb_diff(img[0], img[1]), rgb_diff(img[0], img[3]));
    for (int k = 0; k < 4; k++)
        rayes_image_free(img[k]);
    round_trip(text[0], 0);
}

/* RIB deformation of Points and Curves: a motion block around their
 * samples renders as the same motion by a moving transform. */
static void test_rib_deforming_points_and_curves(void)
{
    char a_text[2048], b_text[2048];
    snprintf(a_text, sizeof a_text,
             "%sShutter 0 1\nTranslate 0 0 5\nWorldBegin\nMotionBegin [0 1]\n"
             "Points \"P\" [-1 1 0 -1 -1 0] \"constantwidth\" [1]\n"
             "Points \"P\" [1 1 0 1 -1 0] \"constantwidth\" [1]\nMotionEnd\n"
             "MotionBegin [0 1]\n"
             "Curves \"linear\" [2] \"nonperiodic\" \"P\" [-1 -2 0 -1 2 0] \"constantwidth\" [0.2]\n"
             "Curves \"linear\" [2] \"nonperiodic\" \"P\" [1 -2 0 1 2 0] \"constantwidth\" [0.2]\n"
             "MotionEnd\nWorldEnd\n",
             rib_ortho);
    snprintf(b_text, sizeof b_text,
             "%sShutter 0 1\nTranslate 0 0 5\nWorldBegin\nMotionBegin [0 1]\n"
             "Translate 0 0 0\nTranslate 2 0 0\nMotionEnd\n"
             "Points \"P\" [-1 1 0 -1 -1 0] \"constantwidth\" [1]\n"
             "Curves \"linear\" [2] \"nonperiodic\" \"P\" [-1 -2 0 -1 2 0] \"constantwidth\" [0.2]\n"
             "WorldEnd\n",
             rib_ortho);
    RayesImage *a = from_file(a_text, 0), *b = from_file(b_text, 0);
    double d = alpha_diff(a, b);
    CHECK(d < 0.02);
    /* the blur is there: the first samples alone cover otherwise */
    char still[2048];
    snprintf(still, sizeof still,
             "%sTranslate 0 0 5\nWorldBegin\n"
             "Points \"P\" [-1 1 0 -1 -1 0] \"constantwidth\" [1]\n"
             "Curves \"linear\" [2] \"nonperiodic\" \"P\" [-1 -2 0 -1 2 0] \"constantwidth\" [0.2]\n"
             "WorldEnd\n",
             rib_ortho);
    RayesImage *c = from_file(still, 0);
    CHECK(alpha_diff(a, c) > 0.3);
    rayes_image_free(c);
    printf("  RIB deforming points and curves vs transform: %.2g\n", d);
    rayes_image_free(a);
    rayes_image_free(b);
}

/* Instance motion: MotionBegin around an instance's transform (RIB) or
 * ActiveTransform around it (pbrt-v4) blurs the instance as the sphere
 * moving by its own transform is blurred (measured: the same alpha; the
 * bound, 0.02 per pixel, allows for the master's dicing in master space);
 * the writer writes the
 * motion block before ObjectInstance and the result reads the same. */
static void test_moving_instance(void)
{
    char text[2048];
    snprintf(text, sizeof text,
             "%sShutter 0 1\nTranslate 0 0 5\nWorldBegin\nObjectBegin \"ball\"\n"
             "Sphere 1 -1 1 360\nObjectEnd\nAttributeBegin\nMotionBegin [0 1]\n"
             "Translate -1 0 0\nTranslate 1 0 0\nMotionEnd\nObjectInstance \"ball\"\n"
             "AttributeEnd\nWorldEnd\n",
             rib_ortho);
    RayesImage *a = from_file(text, 0), *b = reference(-1, 1, 0, 1, 0, 0);
    RayesImage *still = reference(0, 0, 0, 1, 0, 0);
    double d = alpha_diff(a, b);
    CHECK(d < 0.02);
    CHECK(fabs(alpha_sum(a) - alpha_sum(b)) < 0.002 * alpha_sum(b));
    CHECK(alpha_diff(a, still) > 0.3); /* blurred, not the first sample */
    printf("  RIB moving instance vs the moving sphere: %.2g\n", d);
    round_trip(text, 0);
    /* The writer's text: the motion block, then the instance. */
    RibWriter *wr = io_rib_writer_new();
    IoSink sink = io_rib_writer_sink(wr);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    CHECK(io_rib_parse("t.rib", (const unsigned char *)text, strlen(text), &sink, &opt, &settings,
                       err, sizeof err) == RAYES_OK);
    char *out = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&out, &size);
    CHECK(io_rib_writer_finish(wr, &settings, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    const char *mb = out ? strstr(out, "MotionBegin") : NULL;
    const char *oi = mb ? strstr(mb, "ObjectInstance") : NULL;
    CHECK(mb && oi && strstr(mb, "MotionEnd") < oi);
    free(out);
    io_rib_writer_free(wr);
    snprintf(text, sizeof text,
             "%sTranslate 0 0 5\n"
             "Camera \"orthographic\" \"float screenwindow\" [-3 3 -3 3]\n"
             "WorldBegin\nObjectBegin \"ball\"\nShape \"sphere\" \"float radius\" [1]\n"
             "ObjectEnd\nAttributeBegin\nActiveTransform StartTime\nTranslate -1 0 0\n"
             "ActiveTransform EndTime\nTranslate 1 0 0\nActiveTransform All\n"
             "ObjectInstance \"ball\"\nAttributeEnd\n",
             pbrt_ortho);
    RayesImage *p = from_file(text, 1);
    double dp = alpha_diff(p, b);
    CHECK(dp < 0.02);
    CHECK(alpha_diff(p, still) > 0.3);
    printf("  pbrt moving instance vs the moving sphere: %.2g\n", dp);
    round_trip(text, 1);
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_image_free(p);
    rayes_image_free(still);
}

/* The transform samples a recording sink last received. */
static struct {
    size_t n;
    float times[RAYES_MAX_TIMES], M[RAYES_MAX_TIMES][16];
} turns;

static RayesError rec_turns(void *t, size_t n, const float *times, const float (*M)[16])
{
    (void)t;
    turns.n = n;
    memcpy(turns.times, times, n * sizeof *times);
    memcpy(turns.M, M, n * sizeof M[0]);
    return RAYES_OK;
}

/* Reads RIB text into a recording sink whose transform motions land in
 * turns; 1 if it read. */
static int parse_turns(const char *text)
{
    static Record rec;
    IoSink s = record_sink(&rec);
    s.set_transform_motion = rec_turns;
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    turns.n = 0;
    int ok = io_rib_parse("t.rib", (const unsigned char *)text, strlen(text), &s, &opt, &settings,
                          err, sizeof err) == RAYES_OK;
    record_free(&rec);
    return ok;
}

/* A transform that turns within a motion block is sent with samples at
 * most 10 degrees apart, blended about the turning request's own origin
 * (as PRMan moves Rotate's angle): a sphere 1.5 from the axis stays 1.5
 * from it all the way (two samples blended as matrices cut across: 1.06
 * half way). */
static void test_rib_turning_motion(void)
{
    (void)rec_param;
    const char *text = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                       "Translate 0 3 0\n"
                       "MotionBegin [0 1]\nRotate 0 0 0 1\nRotate 90 0 0 1\nMotionEnd\n"
                       "Translate 1.5 0 0\nSphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    CHECK(parse_turns(text));
    CHECK(turns.n == 10); /* 90 degrees in steps of 10 */
    for (size_t k = 0; k < turns.n; k++) {
        const float *m = turns.M[k]; /* the sphere's centre: the translation column */
        float angle = atan2f(m[7] - 3, m[3]) * (float)(180 / M_PI);
        CHECK_NEAR(hypotf(m[3], m[7] - 3), 1.5, 1e-4);
        CHECK_NEAR(angle, 90 * turns.times[k], 1e-3);
        CHECK_NEAR(turns.times[k], k / 9.0, 1e-6);
    }
    /* a Rotate moves its angle: a whole turn spins once (16 samples, the
     * most), three quarters go the long way */
    const char *spin = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                       "MotionBegin [0 1]\nRotate 0 0 0 1\nRotate %s 0 0 1\nMotionEnd\n"
                       "Translate 1 0 0\nSphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    char t2[512];
    snprintf(t2, sizeof t2, spin, "360");
    CHECK(parse_turns(t2));
    CHECK(turns.n == RAYES_MAX_TIMES);
    CHECK(turns.n > 8 && turns.M[turns.n / 2][3] < -0.9f); /* half way: the far side */
    snprintf(t2, sizeof t2, spin, "270");
    CHECK(parse_turns(t2));
    CHECK(turns.n == 16);
    for (size_t k = 0; k < turns.n; k++)
        CHECK_NEAR(atan2f(turns.M[k][7], turns.M[k][3]),
                   remainderf(270 * turns.times[k] * (float)(M_PI / 180), 2 * (float)M_PI), 1e-3);
    /* Transform sets the whole matrix: blended in the world's frame, not
     * the Scale's before it (which would stretch it half way) */
    const char *whole = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                        "Scale 3 1 1\nMotionBegin [0 1]\n"
                        "Transform [1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1]\n"
                        "Transform [0 1 0 0 -1 0 0 0 0 0 1 0 0 0 0 1]\nMotionEnd\n"
                        "Sphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    CHECK(parse_turns(whole));
    CHECK(turns.n == 10);
    for (size_t k = 0; k < turns.n; k++)
        CHECK_NEAR(hypotf(turns.M[k][0], turns.M[k][4]), 1, 1e-4); /* x's image: unit */
    /* a motion that does not turn keeps its samples */
    const char *slide = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                        "MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 1 0 0\nMotionEnd\n"
                        "Sphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    CHECK(parse_turns(slide));
    CHECK(turns.n == 2);
}

/* Motion blocks one after another compose: a child's block moves within
 * its parent's moving frame, at the times of both (the second block used
 * to start from the first one's opening transform, still). */
static void test_rib_consecutive_motion(void)
{
    const char *spin = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                       "MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 2 0 0\nMotionEnd\n"
                       "MotionBegin [0 1]\nRotate 0 0 0 1\nRotate 90 0 0 1\nMotionEnd\n"
                       "Translate 1 0 0\nSphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    CHECK(parse_turns(spin));
    CHECK(turns.n == 10);
    for (size_t k = 0; k < turns.n; k++) { /* the centre: (2t + cos 90t, sin 90t) */
        float t = turns.times[k], a = 90 * t * (float)(M_PI / 180);
        CHECK_NEAR(turns.M[k][3], 2 * t + cosf(a), 1e-4);
        CHECK_NEAR(turns.M[k][7], sinf(a), 1e-4);
    }
    /* blocks at different times: every time of both, each block blended at
     * the other's */
    const char *times = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                        "MotionBegin [0 0.5 1]\nTranslate 0 0 0\nTranslate 1 0 0\n"
                        "Translate 3 0 0\nMotionEnd\n"
                        "MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 0 1 0\nMotionEnd\n"
                        "Sphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    CHECK(parse_turns(times));
    CHECK(turns.n == 3);
    static const float want[3][3] = {{0, 0, 0}, {0.5f, 1, 0.5f}, {1, 3, 1}};
    for (size_t k = 0; k < 3 && k < turns.n; k++) {
        CHECK_NEAR(turns.times[k], want[k][0], 1e-6);
        CHECK_NEAR(turns.M[k][3], want[k][1], 1e-5);
        CHECK_NEAR(turns.M[k][7], want[k][2], 1e-5);
    }
    /* a still transform after a block moves every sample */
    const char *after = "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\n"
                        "MotionBegin [0 1]\nTranslate 0 0 0\nTranslate 0 1 0\nMotionEnd\n"
                        "Translate 5 0 0\nSphere 0.3 -0.3 0.3 360\nWorldEnd\n";
    CHECK(parse_turns(after));
    CHECK(turns.n == 2 && turns.M[0][3] == 5 && turns.M[1][3] == 5 && turns.M[1][7] == 1);
}

TEST_MAIN(TEST(test_rib_transform_motion), TEST(test_rib_turning_motion),
          TEST(test_rib_consecutive_motion), TEST(test_rib_deformation_and_camera),
          TEST(test_rib_depth_of_field), TEST(test_rib_errors), TEST(test_pbrt_motion_and_lens),
          TEST(test_writer_round_trip), TEST(test_rib_deforming_points_and_curves),
          TEST(test_rib_moving_light), TEST(test_moving_instance))
