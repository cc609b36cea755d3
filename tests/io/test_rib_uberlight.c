/*
 * The RIB reader's uberlight (Barzel's light, as Gritz's shader names its
 * parameters; io/rib_shade.c) and its shadows, rendered through
 * io_sink_scene: undeclared parameters are read, intensity is RenderMan's
 * (pi times rayes'), shadows are cast only with a shadow map or BMRT's
 * raytraceshadow, shadowcolor colours them, Attribute "light" "shadows"
 * "off" turns them off for any light, a blocker is found by its
 * CoordinateSystem; the RIB writer writes it all back.
 *
 * The scenes: the camera and the light at the origin looking down +z at a
 * matte floor at z = 6; a square at z = 3 that the camera does not see but
 * shadow rays do, its shadow the middle of the image.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

#include "io/rib_round_trip.h"

enum { SIZE = 24 };

static const char *const floor_rib =
    "Projection \"perspective\" \"fov\" [40]\nWorldBegin\n"
    "Surface \"matte\"\nPolygon \"P\" [-4 -4 6  4 -4 6  4 4 6  -4 4 6]\n";

#define SQUARE                                                                                     \
    "AttributeBegin\nAttribute \"visibility\" \"int camera\" [0]\n"                                \
    "Polygon \"P\" [-0.5 -0.5 3  0.5 -0.5 3  0.5 0.5 3  -0.5 0.5 3]\nAttributeEnd\n"

/* The floor lit by the RIB text light, then more (geometry or ""). */
static RayesImage *render_text(const char *text)
{
    return rib_render_text(text, SIZE, 1);
}

static RayesImage *render_light(const char *light, const char *more)
{
    char text[4096];
    snprintf(text, sizeof text, "%s%s%sWorldEnd\n", light, floor_rib, more);
    return render_text(text);
}

/* The mean of channel c over the middle 4 x 4 pixels. */
static double middle(const RayesImage *img, int c)
{
    return rib_image_middle(img, SIZE, 2, c);
}

static double pixel(const RayesImage *img, int x, int y)
{
    return img->rgba[4 * (y * SIZE + x)];
}

static void test_uberlight_reads(void)
{
    /* Undeclared, as the RenderMan Repository's scenes give them: a sharp
     * square cross-section of half-width 0.2 at unit depth. The middle of
     * the floor faces the light: Kd Cs cos I = 2 (RenderMan's intensity,
     * no falloff by default); the corner pixels lie outside. */
    RayesImage *img = render_light(
        "LightSource \"uberlight\" 1 \"intensity\" 2 \"width\" [.2] \"height\" .2 \"wedge\" 0 "
        "\"hedge\" 0 \"roundness\" 0\n",
        "");
    CHECK(img != NULL);
    if (img) {
        CHECK_NEAR(middle(img, 0), 2.0, 0.01);
        CHECK(pixel(img, 0, 0) == 0.0 && pixel(img, SIZE - 1, SIZE - 1) == 0.0);
        rayes_image_free(img);
    }
    /* a falloff whose falloffdist lies beyond the floor: RenderMan's
     * default maxintensity (1, as the intensity) keeps it at the intensity
     * there (it grew without bound when the default missed the factor pi) */
    img = render_light("LightSource \"uberlight\" 1 \"falloff\" 2 \"falloffdist\" 8\n", "");
    CHECK(img && fabs(middle(img, 0) - 1.0) < 0.01);
    rayes_image_free(img);
    /* BMRT's area lighttype is omni (with a warning), lighting the corners */
    img = render_light("LightSource \"uberlight\" 1 \"string lighttype\" \"arealight\"\n", "");
    CHECK(img && pixel(img, 0, 0) > 0.5);
    rayes_image_free(img);
    /* an unknown blocker coordinate system is an error naming it */
    RayesError e;
    char err[512];
    RayesScene *s = rib_read_scene("WorldBegin\nLightSource \"uberlight\" 1 \"string "
                                   "blockercoords\" \"nowhere\"\nWorldEnd\n",
                                   &e, err, sizeof err);
    CHECK(e != RAYES_OK && strstr(err, "nowhere") && strstr(err, "t.rib:2"));
    rayes_scene_release(s);
}

/* Shadows: none without a shadow map or raytraceshadow (RenderMan's
 * uberlight traces no rays), ray traced with either; shadowcolor lights
 * the shadow; Attribute "light" "shadows" "off" turns off any light's. */
static void test_uberlight_shadows(void)
{
    RayesImage *open = render_light("LightSource \"uberlight\" 1\n", "");
    RayesImage *none = render_light("LightSource \"uberlight\" 1\n", SQUARE);
    RayesImage *traced = render_light("LightSource \"uberlight\" 1 \"raytraceshadow\" 1\n", SQUARE);
    RayesImage *mapped =
        render_light("LightSource \"uberlight\" 1 \"string shadowmap\" \"l.shd\"\n", SQUARE);
    RayesImage *coloured = render_light(
        "LightSource \"uberlight\" 1 \"shadowmap\" \"l.shd\" \"shadowcolor\" [0.25 0.5 1]\n",
        SQUARE);
    RayesImage *off = render_light("Attribute \"light\" \"shadows\" \"off\"\n"
                                   "LightSource \"uberlight\" 1 \"raytraceshadow\" 1\n",
                                   SQUARE);
    RayesImage *on = render_light("Attribute \"light\" \"shadows\" \"on\"\n"
                                  "LightSource \"uberlight\" 1\n",
                                  SQUARE);
    CHECK(open && none && traced && mapped && coloured && off && on);
    if (open && none && traced && mapped && coloured && off && on) {
        double m = middle(open, 0);
        CHECK(m > 0.9);
        CHECK_NEAR(middle(none, 0), m, 1e-4);
        CHECK(middle(traced, 0) == 0.0 && middle(mapped, 0) == 0.0 && middle(on, 0) == 0.0);
        CHECK_NEAR(middle(coloured, 0), 0.25 * m, 1e-4);
        CHECK_NEAR(middle(coloured, 1), 0.5 * m, 1e-4);
        CHECK_NEAR(middle(coloured, 2), m, 1e-4);
        CHECK_NEAR(middle(off, 0), m, 1e-4);
    }
    RayesImage *all[] = {open, none, traced, mapped, coloured, off, on};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; k++)
        rayes_image_free(all[k]);
}

/* RenderMan's classic lights: pointlight, spotlight and distantlight
 * trace no shadows; shadowpoint, shadowspot and shadowdistant cast those
 * of a map (shadowname, shadowpoint's sf* faces), none without one;
 * BMRT's Attribute "light" "shadows" "on" and rayes' own "shadows" 1 cast
 * them for any, "off" and "shadows" 0 for none; the writer keeps each. */
static void test_classic_light_shadows(void)
{
    static const struct {
        const char *light;
        int shadowed;
    } cases[] = {
        {"LightSource \"pointlight\" 1 \"intensity\" 36\n", 0},
        {"LightSource \"spotlight\" 1 \"intensity\" 36 \"coneangle\" 0.6\n", 0},
        {"LightSource \"distantlight\" 1\n", 0},
        {"LightSource \"shadowpoint\" 1 \"intensity\" 36\n", 0},
        {"LightSource \"shadowpoint\" 1 \"intensity\" 36 \"string sfpz\" \"pz.shd\"\n", 1},
        {"LightSource \"shadowspot\" 1 \"intensity\" 36 \"coneangle\" 0.6 \"string shadowname\" "
         "\"raytrace\"\n",
         1},
        {"LightSource \"shadowspot\" 1 \"intensity\" 36 \"string shadowname\" \"\"\n", 0},
        {"LightSource \"shadowdistant\" 1 \"string shadowname\" \"d.shd\"\n", 1},
        {"Attribute \"light\" \"string shadows\" [\"on\"]\n"
         "LightSource \"pointlight\" 1 \"intensity\" 36\n",
         1},
        {"Attribute \"light\" \"string shadows\" [\"off\"]\n"
         "LightSource \"shadowdistant\" 1 \"string shadowname\" \"d.shd\"\n",
         0},
        {"LightSource \"pointlight\" 1 \"intensity\" 36 \"float shadows\" [1]\n", 1},
        {"Attribute \"light\" \"string shadows\" [\"on\"]\n"
         "LightSource \"pointlight\" 1 \"intensity\" 36 \"float shadows\" [0]\n",
         0},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char text[4096], err[512];
        snprintf(text, sizeof text, "%s%s%sWorldEnd\n", cases[k].light, floor_rib, SQUARE);
        RayesImage *img = render_text(text);
        char *written = rib_round_trip(text, err, sizeof err);
        RayesImage *again = written ? render_text(written) : NULL;
        CHECK(img && again);
        if (img && again) {
            if (cases[k].shadowed)
                CHECK(middle(img, 0) == 0.0 && pixel(img, 0, 0) > 0.0);
            else
                CHECK(middle(img, 0) > 0.0);
            CHECK_NEAR(middle(again, 0), middle(img, 0), 1e-5);
        }
        if (!img || !again || (cases[k].shadowed != (middle(img, 0) == 0.0)))
            fprintf(stderr, "  case %zu: %s", k, cases[k].light);
        rayes_image_free(img);
        rayes_image_free(again);
        free(written);
    }
}

/* Light shaders rayes does not have stand in by what they say they are:
 * one with a cone is the spotlight of its parameters (the same image),
 * one named a distant, directional or sun light the distant light, one
 * named a point light the point light, each without shadows unless a map
 * is named; any other is skipped (a black floor). */
static void test_stand_in_lights(void)
{
    static const char *const pairs[][2] = {
        {"LightSource \"spotlight\" 1 \"intensity\" 36 \"coneangle\" 0.6\n",
         "LightSource \"myblockerspot\" 1 \"intensity\" 36 \"coneangle\" 0.6 \"blockername\" "
         "\"star.tx\"\n"},
        {"LightSource \"distantlight\" 1 \"intensity\" 0.5\n",
         "LightSource \"MKshadowdistant_rim\" 1 \"intensity\" 0.5 \"shadowname\" \"\"\n"},
        {"LightSource \"pointlight\" 1 \"intensity\" 36\n",
         "LightSource \"mtorPointLight\" 1 \"intensity\" 36\n"},
        {"LightSource \"shadowspot\" 1 \"intensity\" 36 \"coneangle\" 0.6 \"shadowname\" \"s\"\n",
         "LightSource \"TLblockerspot\" 1 \"intensity\" 36 \"coneangle\" 0.6 \"shadowname\" "
         "\"s\"\n"},
    };
    for (size_t k = 0; k < sizeof pairs / sizeof pairs[0]; k++) {
        RayesImage *a = render_light(pairs[k][0], SQUARE), *b = render_light(pairs[k][1], SQUARE);
        CHECK(a && b);
        if (a && b) {
            CHECK(pixel(a, 0, 0) > 0.05);
            for (int i = 0; i < 4 * SIZE * SIZE; i++)
                CHECK(fabsf(a->rgba[i] - b->rgba[i]) < 1e-6f);
        }
        rayes_image_free(a);
        rayes_image_free(b);
    }
    RayesImage *none = render_light("LightSource \"pointnofalloff\" 1 \"intensity\" 36\n", "");
    CHECK(none && pixel(none, 0, 0) == 0.0 && middle(none, 0) == 0.0);
    rayes_image_free(none);
}

/* Lancaster's l_uber (Maya's lights through MTOR): its numeric lighttype
 * (0 spot, 3 directional), Maya's coneAngle (full width, degrees) a round
 * cone, sharp edges by default, and falloffdist 0 read (it was an error):
 * unused without falloff, with it l_uber's (1 / (d - falloffdist))^falloff
 * (MTOR writes 0: 1 / d^falloff). A 20 degree cone lights the middle of
 * the floor 6 away (radius 1.06) but not the corners (2.2 away); a 60
 * degree one both. Its six shadow maps (spx ... snz) turn shadows on. */
static void test_l_uber(void)
{
    RayesImage *narrow =
        render_light("LightSource \"l_uber\" 1 \"float lighttype\" [0] \"float coneAngle\" [20] "
                     "\"float penumbraAngle\" [0] \"float falloff\" [0] \"float falloffdist\" [0] "
                     "\"float intensity\" [36]\n",
                     "");
    RayesImage *wide = render_light("LightSource \"l_uber\" 1 \"float lighttype\" [0] \"float "
                                    "coneAngle\" [60] \"float intensity\" [36]\n",
                                    "");
    RayesImage *sun = render_light(
        "LightSource \"l_uber\" 1 \"float lighttype\" [3] \"float intensity\" [1]\n", "");
    CHECK(narrow && wide && sun);
    if (narrow && wide && sun) {
        CHECK(middle(narrow, 0) > 0.5 && pixel(narrow, 0, 0) == 0.0);
        CHECK(middle(wide, 0) > 0.5 && pixel(wide, 0, 0) > 0.3);
        /* parallel rays straight down: no falloff with distance or angle
         * beyond the floor's cosine, so the corner nearly the middle */
        CHECK(pixel(sun, 0, 0) > 0.9 * middle(sun, 0) && middle(sun, 0) > 0.1);
    }
    rayes_image_free(narrow);
    rayes_image_free(wide);
    rayes_image_free(sun);
    /* omni, linear falloff from the light: 36 / 6 under it */
    RayesImage *fall = render_light("LightSource \"l_uber\" 1 \"float lighttype\" [1] \"float "
                                    "falloff\" [1] \"float falloffdist\" [0] \"float intensity\" "
                                    "[36]\n",
                                    "");
    CHECK(fall && fabs(middle(fall, 0) - 6.0) < 0.05);
    rayes_image_free(fall);
    const char *maps[] = {"", "\"string spx\" [\"\"] ", "\"string snz\" [\"p.shd6.tex\"] "};
    for (int k = 0; k < 3; k++) {
        char light[256];
        snprintf(light, sizeof light,
                 "LightSource \"l_uber\" 1 \"float lighttype\" [1] %s\"float intensity\" [6]\n",
                 maps[k]);
        RayesImage *img = render_light(light, SQUARE);
        CHECK(img && (k == 2 ? middle(img, 0) == 0.0 : middle(img, 0) > 5.0));
        rayes_image_free(img);
    }
}

/* A blocker in the coordinate system "blk" (z = 3): the middle is dark,
 * the corners lit; after AttributeEnd the system is still known. */
static void test_uberlight_blocker(void)
{
    RayesImage *img = render_light(
        "TransformBegin\nTranslate 0 0 3\nCoordinateSystem \"blk\"\nTransformEnd\n"
        "LightSource \"uberlight\" 1 \"string lighttype\" \"omni\" \"string blockercoords\" "
        "\"blk\" \"blockerwidth\" 0.3 \"blockerheight\" 0.3 \"blockerwedge\" 0 \"blockerhedge\" 0 "
        "\"blockerround\" 0\n",
        "");
    CHECK(img != NULL);
    if (img) {
        CHECK(middle(img, 0) == 0.0);
        CHECK(pixel(img, 0, 0) > 0.5);
        rayes_image_free(img);
    }
}

/* rayes convert: the writer's RIB renders the same image (shaping, shadows
 * on, shadowcolor, blocker, falloff with maxintensity, a shadowless light,
 * nonspecular). */
static void test_uberlight_round_trip(void)
{
    char text[4096], err[512];
    snprintf(text, sizeof text, "%s%s%sWorldEnd\n",
             "TransformBegin\nTranslate 0.5 0 3\nCoordinateSystem \"blk\"\nTransformEnd\n"
             "LightSource \"uberlight\" 1 \"intensity\" 3 \"raytraceshadow\" 1 \"shadowcolor\" "
             "[0.1 0.2 0.3] \"falloff\" 2 \"falloffdist\" 4 \"maxintensity\" 5 \"shearx\" 0.1 "
             "\"width\" 0.4 \"roundness\" 0.5 \"beamdistribution\" 1 \"blockercoords\" \"blk\" "
             "\"blockerwidth\" 0.2 \"nonspecular\" 1 \"noiseamp\" 0.5\n"
             "Translate 1 0 0\nLightSource \"uberlight\" 2 \"lighttype\" \"omni\" \"cuton\" 5 "
             "\"nearedge\" 1\n",
             floor_rib, SQUARE);
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written != NULL);
    if (!written) {
        fprintf(stderr, "  %s\n", err);
        return;
    }
    CHECK(strstr(written, "uberlight") && strstr(written, "blockermatrix"));
    RayesImage *a = render_text(text), *b = render_text(written);
    CHECK(a && b);
    if (a && b) {
        double worst = 0.0, sum = 0.0;
        for (int i = 0; i < 4 * SIZE * SIZE; i++) {
            worst = fmax(worst, fabs(a->rgba[i] - b->rgba[i]));
            sum += a->rgba[i];
        }
        CHECK(worst < 1e-5 && sum > 10.0);
    }
    rayes_image_free(a);
    rayes_image_free(b);
    free(written);
}

TEST_MAIN(TEST(test_uberlight_reads), TEST(test_uberlight_shadows),
          TEST(test_classic_light_shadows), TEST(test_stand_in_lights), TEST(test_l_uber),
          TEST(test_uberlight_blocker), TEST(test_uberlight_round_trip))
