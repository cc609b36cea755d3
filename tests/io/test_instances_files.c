/*
 * tests/io/test_instances_files.c — RIB and pbrt-v4 ObjectBegin, ObjectEnd
 * and ObjectInstance read into a scene (io_sink_scene) as masters and
 * instances, not copies: counts, the shader an instance inherits, nesting
 * (RIB), errors naming file:line, and the RIB writer's round trip.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt.h"
#include "io/rib.h"
#include "io/rib_write.h"
#include "rayes/rayes.h"
#include "test.h"

static char err[1024];

static RayesError read_into(RayesScene *s, const char *name, const char *text)
{
    IoSettings settings;
    io_settings_init(&settings);
    IoSink sink = io_sink_scene(s);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    size_t n = strlen(text);
    unsigned char *copy = malloc(n ? n : 1); /* exactly its size, for AddressSanitizer */
    memcpy(copy, text, n);
    err[0] = '\0';
    RayesError e = strstr(name, ".pbrt")
                       ? io_pbrt_parse(name, copy, n, &sink, &opt, &settings, err, sizeof err)
                       : io_rib_parse(name, copy, n, &sink, &opt, &settings, err, sizeof err);
    free(copy);
    return e;
}

/* Renders s at 48 x 48 and returns the statistic (a count). */
static uint64_t render_stat(RayesScene *s, const char *stat, RayesImage **keep)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 48;
    o.spp = 1;
    o.threads = 2;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    const RayesStat *x = st ? rayes_stats_find(st, stat) : NULL;
    uint64_t v = x ? x->count : 0;
    rayes_stats_free(st);
    if (keep)
        *keep = img;
    else
        rayes_image_free(img);
    return v;
}

#define RIB_HEAD                                                                                   \
    "Projection \"perspective\" \"fov\" 40\nTranslate 0 0 6\nWorldBegin\n"                         \
    "LightSource \"pointlight\" 1 \"from\" [0 0 -4] \"intensity\" [20]\n"

/* A quad in a block with no Surface or Color, instanced red at x = 1 and
 * green at x = -1 (the image's right and left). */
static const char *rib_two = RIB_HEAD
    "ObjectBegin \"card\"\n"
    "  Polygon \"P\" [-0.8 -0.8 0  0.8 -0.8 0  0.8 0.8 0  -0.8 0.8 0]\n"
    "ObjectEnd\n"
    "AttributeBegin\nColor [1 0 0]\nTranslate 1 0 0\nObjectInstance \"card\"\nAttributeEnd\n"
    "AttributeBegin\nColor [0 1 0]\nTranslate -1 0 0\nObjectInstance \"card\"\n"
    "AttributeEnd\nWorldEnd\n";

static void test_rib_instances_inherit_colour(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, "t.rib", rib_two) == RAYES_OK);
    CHECK(rayes_scene_instance_count(s) == 2);
    RayesImage *img = NULL;
    CHECK(render_stat(s, "instances/count", &img) == 2);
    const float *left = &img->rgba[4 * (24 * 48 + 12)], *right = &img->rgba[4 * (24 * 48 + 36)];
    CHECK(right[0] > 0.05f && right[1] < 0.2f * right[0]); /* red */
    CHECK(left[1] > 0.05f && left[0] < 0.2f * left[1]);    /* green */
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A block with its own Color keeps it in every instance; numeric handles. */
static void test_rib_block_colour_kept(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, "t.rib",
                    RIB_HEAD "ObjectBegin 7\nColor [0 0 1]\n"
                             "  Polygon \"P\" [-0.8 -0.8 0  0.8 -0.8 0  0.8 0.8 0  -0.8 0.8 0]\n"
                             "ObjectEnd\nColor [1 0 0]\nObjectInstance 7\nWorldEnd\n") == RAYES_OK);
    RayesImage *img = NULL;
    CHECK(render_stat(s, "instances/masters", &img) == 1);
    const float *mid = &img->rgba[4 * (24 * 48 + 24)];
    CHECK(mid[2] > 0.05f && mid[0] < 0.2f * mid[2]); /* blue, not red */
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A block that sets Color but no Surface: its geometry keeps each
 * instance's Surface with the block's colour (a constant shader shows the
 * colour itself, a matte one shades it), not the Surface current at
 * ObjectBegin. */
static void test_rib_block_colour_instance_surface(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, "t.rib",
                    RIB_HEAD "ObjectBegin \"card\"\nColor [0 0 1]\n"
                             "  Polygon \"P\" [-0.8 -0.8 0  0.8 -0.8 0  0.8 0.8 0  -0.8 0.8 0]\n"
                             "ObjectEnd\n"
                             "AttributeBegin\nSurface \"constant\"\nColor [1 0 0]\n"
                             "Translate 1 0 0\nObjectInstance \"card\"\nAttributeEnd\n"
                             "AttributeBegin\nSurface \"matte\"\nColor [0 1 0]\n"
                             "Translate -1 0 0\nObjectInstance \"card\"\nAttributeEnd\n"
                             "WorldEnd\n") == RAYES_OK);
    RayesImage *img = NULL;
    CHECK(render_stat(s, "instances/count", &img) == 2);
    const float *left = &img->rgba[4 * (24 * 48 + 12)], *right = &img->rgba[4 * (24 * 48 + 36)];
    /* constant: the block's blue itself */
    CHECK(right[0] < 0.01f && right[1] < 0.01f && right[2] > 0.99f && right[2] < 1.01f);
    /* matte: blue, lit by the point light (not 1) */
    CHECK(left[2] > 0.05f && left[0] < 0.2f * left[2] && left[1] < 0.2f * left[2]);
    CHECK(left[2] < 0.9f || left[2] > 1.1f);
    printf("  Color-only block: constant instance %.3f %.3f %.3f, matte instance %.3f %.3f %.3f\n",
           right[0], right[1], right[2], left[0], left[1], left[2]);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A block that sets Opacity but no Surface or Color: its geometry keeps
 * each instance's Surface and Color and the block's opacity (PRMan's
 * attributes in a block override the instance's), drawn see-through even
 * though the instance's object is opaque; nested blocks pass it on. */
static void test_rib_block_opacity(void)
{
    static const char *const blocks[2] = {
        "ObjectBegin \"card\"\nOpacity [0.5 0.5 0.5]\n"
        "  Polygon \"P\" [-0.8 -0.8 0  0.8 -0.8 0  0.8 0.8 0  -0.8 0.8 0]\n"
        "ObjectEnd\n",
        "ObjectBegin \"inner\"\nOpacity [0.5 0.5 0.5]\n"
        "  Polygon \"P\" [-0.8 -0.8 0  0.8 -0.8 0  0.8 0.8 0  -0.8 0.8 0]\n"
        "ObjectEnd\nObjectBegin \"card\"\nObjectInstance \"inner\"\nObjectEnd\n"};
    for (int nested = 0; nested < 2; nested++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "%s%sAttributeBegin\nSurface \"constant\"\nColor [1 0 0]\n"
                 "Translate 1 0 0\nObjectInstance \"card\"\nAttributeEnd\n"
                 "AttributeBegin\nSurface \"constant\"\nColor [0 1 0]\nOpacity [0.25 0.25 0.25]\n"
                 "Translate -1 0 0\nObjectInstance \"card\"\nAttributeEnd\nWorldEnd\n",
                 RIB_HEAD, blocks[nested]);
        RayesScene *s = rayes_scene_new();
        CHECK(read_into(s, "t.rib", text) == RAYES_OK);
        RayesImage *img = NULL;
        CHECK(render_stat(s, "instances/count", &img) == 2);
        const float *left = &img->rgba[4 * (24 * 48 + 12)], *right = &img->rgba[4 * (24 * 48 + 36)];
        /* the instance's red and green at the block's half opacity (premultiplied) */
        CHECK(fabsf(right[0] - 0.5f) < 0.01f && right[1] < 0.01f && fabsf(right[3] - 0.5f) < 0.01f);
        CHECK(fabsf(left[1] - 0.5f) < 0.01f && left[0] < 0.01f && fabsf(left[3] - 0.5f) < 0.01f);
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

/* ObjectInstance inside ObjectBegin (RenderMan allows it): 2 x 3 balls. */
static void test_rib_nested(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, "t.rib",
                    RIB_HEAD
                    "ObjectBegin \"ball\"\nSphere 0.2 -0.2 0.2 360\nObjectEnd\n"
                    "ObjectBegin \"row\"\n"
                    "  TransformBegin\nTranslate -0.5 0 0\nObjectInstance \"ball\"\n"
                    "  TransformEnd\n"
                    "  ObjectInstance \"ball\"\n"
                    "  Translate 0.5 0 0\nObjectInstance \"ball\"\n"
                    "ObjectEnd\n"
                    "TransformBegin\nTranslate 0 0.5 0\nObjectInstance \"row\"\nTransformEnd\n"
                    "Translate 0 -0.5 0\nObjectInstance \"row\"\nWorldEnd\n") == RAYES_OK);
    CHECK(rayes_scene_instance_count(s) == 5);           /* made: 3 in "row", 2 of it */
    CHECK(render_stat(s, "instances/count", NULL) == 6); /* flattened */
    rayes_scene_release(s);
}

static void expect_error(const char *name, const char *text, const char *where, const char *what)
{
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, name, text) != RAYES_OK);
    if (!strstr(err, where) || !strstr(err, what))
        fprintf(stderr, "error was: %s\n", err);
    CHECK(strstr(err, where) != NULL);
    CHECK(strstr(err, what) != NULL);
    CHECK(strchr(err, '\n') == NULL); /* one line */
    rayes_scene_release(s);
}

static void test_errors(void)
{
    expect_error("t.rib", RIB_HEAD "Sphere 1 -1 1 360\nObjectInstance \"nope\"\nWorldEnd\n",
                 "t.rib:6", "nope");
    expect_error("t.rib", RIB_HEAD "ObjectEnd\nWorldEnd\n", "t.rib:5", "ObjectEnd without");
    expect_error("t.rib", RIB_HEAD "ObjectBegin 1\nObjectBegin 2\nObjectEnd\nObjectEnd\n",
                 "t.rib:6", "inside an object definition");
    expect_error("t.pbrt", "WorldBegin\nShape \"sphere\"\nObjectInstance \"nope\"\n", "t.pbrt:3",
                 "nope");
    expect_error("t.pbrt",
                 "WorldBegin\nObjectBegin \"a\"\nShape \"sphere\"\nObjectEnd\nObjectBegin \"b\"\n"
                 "ObjectInstance \"a\"\nObjectEnd\n",
                 "t.pbrt:6", "ObjectInstance inside ObjectBegin");
}

/* pbrt-v4: the object is sent once as a master, placed three times. */
static void test_pbrt_instances(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(
        read_into(s, "t.pbrt",
                  "LookAt 0 0 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
                  "WorldBegin\n"
                  "LightSource \"point\" \"point3 from\" [0 0 -4] \"float scale\" 20\n"
                  "ObjectBegin \"pebble\"\n"
                  "  Material \"diffuse\" \"rgb reflectance\" [0.8 0.4 0.2]\n"
                  "  Shape \"sphere\" \"float radius\" 0.3\n"
                  "ObjectEnd\n"
                  "ObjectInstance \"pebble\"\n"
                  "AttributeBegin\nTranslate 1 0 0\nObjectInstance \"pebble\"\nAttributeEnd\n"
                  "AttributeBegin\nTranslate -1 0 0\nObjectInstance \"pebble\"\nAttributeEnd\n") ==
        RAYES_OK);
    CHECK(rayes_scene_instance_count(s) == 3);
    CHECK(render_stat(s, "instances/masters", NULL) == 1);
    rayes_scene_release(s);
}

/* The mean of channel c over the columns [x0, x1) of img. */
static double column_mean(const RayesImage *img, int c, int x0, int x1)
{
    double sum = 0.0;
    for (int y = 0; y < img->height; y++)
        for (int x = x0; x < x1; x++)
            sum += img->rgba[4 * ((size_t)y * (size_t)img->width + (size_t)x) + (size_t)c];
    return sum / ((double)img->height * (double)(x1 - x0));
}

#define PBRT_CURVE_HEAD                                                                            \
    "LookAt 0 0 -6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n"           \
    "LightSource \"point\" \"point3 from\" [0 0 -4] \"float scale\" 20\n"                          \
    "Material \"diffuse\" \"rgb reflectance\" [0.8 0.4 0.2]\n"
#define PBRT_TUFT                                                                                  \
    "  Shape \"curve\" \"point3 P\" [0 -1 0  0.1 -0.3 0  -0.1 0.3 0  0 1 0] \"float width\" 0.2\n" \
    "  Shape \"curve\" \"point3 P\" [0.3 -1 0  0.4 -0.3 0  0.2 0.3 0  0.3 1 0] \"float width\" "   \
    "0.2\n"

/* pbrt-v4 curves inside ObjectBegin are instanced (they were skipped):
 * a tuft of two curves placed left and right draws as its copies do. */
static void test_pbrt_curve_instances(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, "t.pbrt",
                    PBRT_CURVE_HEAD "ObjectBegin \"tuft\"\n" PBRT_TUFT "ObjectEnd\n"
                                    "AttributeBegin\nTranslate 1 0 0\nObjectInstance \"tuft\"\n"
                                    "AttributeEnd\nAttributeBegin\nTranslate -1 0 0\n"
                                    "ObjectInstance \"tuft\"\nAttributeEnd\n") == RAYES_OK);
    CHECK(rayes_scene_instance_count(s) == 2);
    RayesImage *inst = NULL, *copies = NULL;
    CHECK(render_stat(s, "instances/masters", &inst) == 1);
    rayes_scene_release(s);
    s = rayes_scene_new();
    CHECK(read_into(s, "t.pbrt",
                    PBRT_CURVE_HEAD "AttributeBegin\nTranslate 1 0 0\n" PBRT_TUFT
                                    "AttributeEnd\nAttributeBegin\nTranslate -1 0 0\n" PBRT_TUFT
                                    "AttributeEnd\n") == RAYES_OK);
    CHECK(render_stat(s, "instances/masters", &copies) == 0);
    rayes_scene_release(s);
    int w = inst->width;
    for (int half = 0; half < 2; half++) {
        double a = column_mean(inst, 0, half * w / 2, (half + 1) * w / 2);
        double b = column_mean(copies, 0, half * w / 2, (half + 1) * w / 2);
        CHECK(b > 0.01);                /* each half shows a tuft */
        CHECK(fabs(a - b) <= 0.01 * b); /* drawn as the copies are */
    }
    rayes_image_free(inst);
    rayes_image_free(copies);
}

/* RIB -> RIB writer -> RIB: the blocks and instances survive, and the
 * second file reads into the same instances. */
static void test_rib_writer_round_trip(void)
{
    RibWriter *w = io_rib_writer_new();
    IoSink sink = io_rib_writer_sink(w);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    size_t n = strlen(rib_two);
    CHECK(io_rib_parse("t.rib", (const unsigned char *)rib_two, n, &sink, &opt, &settings, err,
                       sizeof err) == RAYES_OK);
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    CHECK(io_rib_writer_finish(w, &settings, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    io_rib_writer_free(w);
    CHECK(strstr(text, "ObjectBegin \"card\"") != NULL);
    CHECK(strstr(text, "ObjectEnd") != NULL);
    const char *first = strstr(text, "ObjectInstance \"card\"");
    CHECK(first && strstr(first + 1, "ObjectInstance \"card\"") != NULL);
    RayesScene *s = rayes_scene_new();
    CHECK(read_into(s, "w.rib", text) == RAYES_OK);
    CHECK(rayes_scene_instance_count(s) == 2);
    RayesImage *img = NULL;
    CHECK(render_stat(s, "instances/count", &img) == 2);
    const float *left = &img->rgba[4 * (24 * 48 + 12)], *right = &img->rgba[4 * (24 * 48 + 36)];
    CHECK(right[0] > 0.05f && right[1] < 0.2f * right[0]);
    CHECK(left[1] > 0.05f && left[0] < 0.2f * left[1]);
    rayes_image_free(img);
    rayes_scene_release(s);
    free(text);
}

/* Aqsis's objectinstance scene: one master of one quad, twelve instances. */
static void test_aqsis_objectinstance(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scenes/rib-aqsis/objectinstance/singlepolygon.rib",
             RAYES_TEST_DATA);
    RayesScene *s = rayes_scene_new();
    IoSettings settings;
    io_settings_init(&settings);
    IoSink sink = io_sink_scene(s);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    CHECK(io_rib_read(path, &sink, &opt, &settings, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_instance_count(s) == 12);
    CHECK(render_stat(s, "instances/masters", NULL) == 1);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_aqsis_objectinstance), TEST(test_rib_instances_inherit_colour),
          TEST(test_rib_block_colour_kept), TEST(test_rib_block_colour_instance_surface),
          TEST(test_rib_block_opacity), TEST(test_rib_nested), TEST(test_errors),
          TEST(test_pbrt_instances), TEST(test_pbrt_curve_instances),
          TEST(test_rib_writer_round_trip))
