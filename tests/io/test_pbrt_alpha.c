/*
 * pbrt-v4's "alpha" on shapes rendered through io_sink_scene
 * (io/pbrt_shape.c): a constant alpha is opacity Os (0 casts no shadow,
 * 0.5 half of one), and a float texture's alpha cuts out where it is 0 (a
 * checkerboard's shadow is a checkerboard). pbrt cuts out stochastically
 * where alpha is fractional; rayes' opacity is the same in expectation.
 *
 * The scene: the camera at z = 6 looks down at the floor (z = 0, seeing
 * [-1, 1]^2 of it); a point light low at x = 4 is hidden from the whole
 * visible floor by a wall at x = 2.5, out of view, which carries the
 * alpha.
 *
 * Also pbrt-v4's material "displacement", a bump map: the shading normal
 * bends, the surface stays (it used to move, and swelled a scene's
 * cushions over its table); and a medium inside a glass shape, which
 * fills the shape, not its bounding box.
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

enum { SIZE = 32 };

/* The scene's text with the wall's shape parameters (NULL: no wall). */
static void scene_text(const char *wall, char *text, size_t size)
{
    snprintf(text, size,
             "LookAt 0 0 6  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 18.92\n"
             "WorldBegin\nLightSource \"point\" \"point3 from\" [4 0 1] \"rgb I\" [10 10 10]\n"
             "Texture \"checks\" \"float\" \"checkerboard\" \"float uscale\" 4 "
             "\"float vscale\" 4 \"float tex1\" 0 \"float tex2\" 1\n"
             "Material \"diffuse\"\n"
             "Shape \"bilinearmesh\" \"point3 P\" [-4 -4 0 4 -4 0 -4 4 0 4 4 0] "
             "\"integer indices\" [0 1 2 3]\n"
             "%s%s\n",
             wall ? "Shape \"bilinearmesh\" \"point3 P\" [2.5 -3 0.01 2.5 3 0.01 2.5 -3 2 2.5 3 2] "
                    "\"integer indices\" [0 1 2 3] \"point2 uv\" [0 0 1 0 0 1 1 1] "
                  : "",
             wall ? wall : "");
}

/* The image of a scene read (by read, into io_sink_scene), its opacity
 * cached or not. */
static RayesImage *render_read(RayesError (*read)(const char *, const unsigned char *, size_t,
                                                  const IoSink *, const IoReadOptions *,
                                                  IoSettings *, char *, size_t),
                               const char *text, int opacity_cache)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    char err[512] = "";
    RayesImage *img = NULL;
    RayesError e = read("alpha.pbrt", (const unsigned char *)text, strlen(text), &sink, &opt,
                        &settings, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "  %s\n", err);
    CHECK(e == RAYES_OK);
    if (e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = SIZE;
        o.spp = 1;
        o.threads = 2;
        o.bounces = 0;
        o.opacity_cache = opacity_cache;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    }
    rayes_scene_release(s);
    return img;
}

/* The scene with the wall's shape parameters (NULL: no wall), its
 * opacity cached or not. */
static RayesImage *render_pbrt(const char *wall, int opacity_cache)
{
    char text[4096];
    scene_text(wall, text, sizeof text);
    return render_read(io_pbrt_parse, text, opacity_cache);
}

static double mean_red(const RayesImage *img)
{
    double t = 0;
    for (int i = 0; i < SIZE * SIZE; i++)
        t += img->rgba[4 * i];
    return t / (SIZE * SIZE);
}

static void test_constant_alpha(void)
{
    RayesImage *open = render_pbrt(NULL, 1), *wall = render_pbrt("", 1),
               *half = render_pbrt("\"float alpha\" 0.5", 1),
               *gone = render_pbrt("\"float alpha\" 0", 1);
    CHECK(open && wall && half && gone);
    if (open && wall && half && gone) {
        CHECK(mean_red(open) > 0.01);
        CHECK(mean_red(wall) == 0.0);
        CHECK_NEAR(mean_red(half) / mean_red(open), 0.5, 1e-4);
        CHECK_NEAR(mean_red(gone) / mean_red(open), 1.0, 1e-4);
    }
    rayes_image_free(open);
    rayes_image_free(wall);
    rayes_image_free(half);
    rayes_image_free(gone);
}

/* A checkerboard alpha (0 and 1), uncached: about half the floor lit as
 * if the wall were not there, half dark, in cells, and half the light in
 * all. Cached, the wall (out of view, diced coarsely) shadows with its
 * cells' mean at a cache level's resolution: half the light too. */
static void test_texture_alpha(void)
{
    RayesImage *open = render_pbrt(NULL, 0),
               *checks = render_pbrt("\"texture alpha\" \"checks\"", 0),
               *cached = render_pbrt("\"texture alpha\" \"checks\"", 1);
    CHECK(open && checks && cached);
    if (open && checks && cached) {
        int lit = 0, dark = 0;
        for (int i = 0; i < SIZE * SIZE; i++) {
            float a = checks->rgba[4 * i], b = open->rgba[4 * i];
            lit += fabsf(a - b) < 0.02f * b;
            dark += a < 0.02f * b;
        }
        double ratio = mean_red(checks) / mean_red(open);
        fprintf(stderr, "checkerboard alpha: %d lit, %d dark of %d; %g of the light (%g cached)\n",
                lit, dark, SIZE * SIZE, ratio, mean_red(cached) / mean_red(open));
        CHECK(lit > SIZE * SIZE / 4 && dark > SIZE * SIZE / 4);
        CHECK(ratio > 0.4 && ratio < 0.6);
        CHECK_NEAR(mean_red(cached) / mean_red(checks), 1.0, 0.02);
    }
    rayes_image_free(open);
    rayes_image_free(checks);
    rayes_image_free(cached);
}

/* Converted to RIB (the writer keeps Os bound to the pattern), the scene
 * renders the same. */
/* The pbrt text written as RIB by the RIB writer (new string, or NULL). */
static char *pbrt_as_rib(const char *text)
{
    char err[512], *rib = NULL;
    size_t size = 0;
    RibWriter *w = io_rib_writer_new();
    IoSink sink = io_rib_writer_sink(w);
    IoSettings settings;
    io_settings_init(&settings);
    CHECK(io_pbrt_parse("t.pbrt", (const unsigned char *)text, strlen(text), &sink, NULL, &settings,
                        err, sizeof err) == RAYES_OK);
    FILE *f = open_memstream(&rib, &size);
    CHECK(io_rib_writer_finish(w, &settings, f, err, sizeof err) == RAYES_OK);
    fclose(f);
    io_rib_writer_free(w);
    return rib;
}

/* The largest difference of two images' values (1 if either is missing). */
static float max_diff(const RayesImage *a, const RayesImage *b)
{
    float d = a && b ? 0.0f : 1.0f;
    for (int i = 0; a && b && i < 4 * SIZE * SIZE; i++)
        d = fmaxf(d, fabsf(a->rgba[i] - b->rgba[i]));
    return d;
}

static void test_rib_round_trip(void)
{
    char text[4096];
    scene_text("\"texture alpha\" \"checks\"", text, sizeof text);
    char *rib = pbrt_as_rib(text);
    CHECK(rib && strstr(rib, "\"reference pattern Os\"") != NULL);
    RayesImage *a = render_pbrt("\"texture alpha\" \"checks\"", 0),
               *b = rib ? render_read(io_rib_parse, rib, 0) : NULL;
    CHECK(max_diff(a, b) < 1e-4f);
    rayes_image_free(a);
    rayes_image_free(b);
    free(rib);
}

static void test_bad_alpha(void)
{
    const char *text = "WorldBegin\nShape \"sphere\" \"string alpha\" \"x\"\n";
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    IoSettings settings;
    io_settings_init(&settings);
    char err[512] = "";
    CHECK(io_pbrt_parse("alpha.pbrt", (const unsigned char *)text, strlen(text), &sink, NULL,
                        &settings, err, sizeof err) != RAYES_OK);
    CHECK(strstr(err, "alpha.pbrt:2:") && strstr(err, "alpha") && !strchr(err, '\n'));
    text = "WorldBegin\nShape \"sphere\" \"texture alpha\" \"nothing\"\n";
    CHECK(io_pbrt_parse("alpha.pbrt", (const unsigned char *)text, strlen(text), &sink, NULL,
                        &settings, err, sizeof err) != RAYES_OK);
    CHECK(strstr(err, "alpha.pbrt:2:") != NULL);
    rayes_scene_release(s);
}

/* A sphere before the camera, its material's displacement amount as
 * given ("" none). */
static RayesImage *bumped_sphere(const char *amount)
{
    char text[2048];
    snprintf(text, sizeof text,
             "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\n"
             "WorldBegin\nLightSource \"distant\" \"point3 from\" [0 1 -1] \"point3 to\" "
             "[0 0 0] \"rgb L\" [3 3 3]\n"
             "Texture \"ridges\" \"float\" \"checkerboard\" \"float uscale\" 16 "
             "\"float vscale\" 8 \"float tex1\" 0 \"float tex2\" 0.05\n"
             "Material \"diffuse\" \"rgb reflectance\" [0.6 0.6 0.6] %s\n"
             "Shape \"sphere\" \"float radius\" 0.8\n",
             amount);
    return render_read(io_pbrt_parse, text, 1);
}

static void test_displacement_is_bump(void)
{
    RayesImage *plain = bumped_sphere(""), *shifted = bumped_sphere("\"float displacement\" 0.3"),
               *ridged = bumped_sphere("\"texture displacement\" \"ridges\"");
    CHECK(plain && shifted && ridged);
    if (plain && shifted && ridged) {
        double cover_moved = 0, shade_moved = 0, shade_bent = 0;
        for (int i = 0; i < SIZE * SIZE; i++) {
            cover_moved =
                fmax(cover_moved, fabs(shifted->rgba[4 * i + 3] - plain->rgba[4 * i + 3]));
            cover_moved = fmax(cover_moved, fabs(ridged->rgba[4 * i + 3] - plain->rgba[4 * i + 3]));
            shade_moved = fmax(shade_moved, fabs(shifted->rgba[4 * i] - plain->rgba[4 * i]));
            shade_bent = fmax(shade_bent, fabs(ridged->rgba[4 * i] - plain->rgba[4 * i]));
        }
        printf("  pbrt displacement: coverage moved %.3g, a constant's shading %.3g, a "
               "checkerboard's %.3g\n",
               cover_moved, shade_moved, shade_bent);
        CHECK(cover_moved == 0.0); /* the surface is where it was (0.3 used to grow it) */
        CHECK(shade_moved < 1e-3); /* a constant offset bends nothing */
        CHECK(shade_bent > 0.05);  /* the checkerboard's steps tilt the normal */
    }
    rayes_image_free(plain);
    rayes_image_free(shifted);
    rayes_image_free(ridged);
}

/* A glass sphere holding an absorbing medium before a white sky: the
 * sky beside the sphere, inside its bounding box, is untinted (the box
 * was filled: a green square); through the sphere, red and blue are
 * absorbed. */
static void test_medium_inside_glass(void)
{
    const char *text =
        "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 22\n"
        "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n"
        "MakeNamedMedium \"green\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [4 0.2 4] "
        "\"rgb sigma_s\" [0 0 0]\n"
        "AttributeBegin\nMediumInterface \"green\" \"\"\nMaterial \"dielectric\" "
        "\"float eta\" 1.01\nShape \"sphere\" \"float radius\" 0.9\nAttributeEnd\n";
    RayesImage *img = render_read(io_pbrt_parse, text, 1);
    CHECK(img != NULL);
    if (img) {
        /* a corner of the sphere's box on screen (the sphere covers most
         * of the frame: its box's corners lie outside the disc) */
        const float *corner = &img->rgba[4 * (1 * SIZE + 1)];
        const float *mid = &img->rgba[4 * (SIZE / 2 * SIZE + SIZE / 2)];
        printf("  medium in glass: beside %.3f %.3f %.3f, through %.3f %.3f %.3f\n", corner[0],
               corner[1], corner[2], mid[0], mid[1], mid[2]);
        CHECK(corner[0] > 0.95f && corner[1] > 0.95f && corner[2] > 0.95f);
        CHECK(mid[1] > 0.5f && mid[0] < 0.1f && mid[2] < 0.1f); /* exp(-4 * 1.8) red */
    }
    /* written as RIB (rayes' "inside" on the Volume) and read back: the
     * same image */
    char *rib = pbrt_as_rib(text);
    CHECK(rib && strstr(rib, "\"constant int inside\" [1]") != NULL);
    RayesImage *back = rib ? render_read(io_rib_parse, rib, 1) : NULL;
    CHECK(img && max_diff(img, back) < 1e-4f);
    rayes_image_free(back);
    free(rib);
    rayes_image_free(img);
}

/* Renders a pbrt scene as render_read does and copies n of its pixels
 * (x, y) into out; 0 if it did not render. */
static int render_pixels(const char *text, const int (*xy)[2], int n, float (*out)[3])
{
    RayesImage *img = render_read(io_pbrt_parse, text, 1);
    CHECK(img != NULL);
    if (!img)
        return 0;
    for (int k = 0; k < n; k++)
        memcpy(out[k], &img->rgba[4 * (xy[k][1] * SIZE + xy[k][0])], sizeof out[k]);
    rayes_image_free(img);
    return 1;
}

/* The pixel in the middle of the image. */
static const int MIDDLE[1][2] = {{SIZE / 2, SIZE / 2}};

/* An absorbing medium (sigma_a 0.5), and an orthographic view along +z
 * over [-1, 1]^2 under a white sky. */
#define ABSORB                                                                                     \
    "MakeNamedMedium \"absorb\" \"string type\" \"homogeneous\" \"rgb sigma_a\" "                  \
    "[0.5 0.5 0.5] \"rgb sigma_s\" [0 0 0]\n"
#define AXIS_VIEW                                                                                  \
    "LookAt 0 0 -5  0 0 0  0 1 0\n"                                                                \
    "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n"                                 \
    "WorldBegin\nLightSource \"infinite\" \"rgb L\" [1 1 1]\n" ABSORB

/* pbrt's "interface" shapes (no surface) bound their media: rays meet
 * the medium between their crossings of the shape, not in its bounding box.
 * An absorbing sphere of radius 1 (sigma_a 0.5) seen along its axis, over
 * a floor lit through it: its centre passes exp(-1) twice (the camera's
 * ray and the floor's light), a corner of its box (inside the box, outside
 * the sphere) all; two closed cubes in one mesh, 0.5 and 0.8 deep, pass
 * exp(-0.5 * 1.3) where the box gave exp(-1). Written as RIB (the shape
 * hidden from every ray) and read back: the same image. */
static void test_medium_inside_interface(void)
{
    const char *sphere =
        "LookAt 0 5 0  0 0 0  0 0 1\n"
        "Camera \"orthographic\" \"float screenwindow\" [-1.5 1.5 -1.5 1.5]\n"
        "WorldBegin\nLightSource \"distant\" \"point3 from\" [0 10 0] \"point3 to\" [0 0 0] "
        "\"rgb L\" [3.14159265 3.14159265 3.14159265]\n" ABSORB
        "AttributeBegin\nTranslate 0 2 0\nMaterial \"interface\"\n"
        "MediumInterface \"absorb\" \"\"\nShape \"sphere\" \"float radius\" [1]\nAttributeEnd\n"
        "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [1 1 1]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [-3 0 -3  3 0 -3  -3 0 3  3 0 3] "
        "\"integer indices\" [0 1 2 3]\nAttributeEnd\n";
    RayesImage *img = render_read(io_pbrt_parse, sphere, 1);
    CHECK(img != NULL);
    if (img) {
        /* pixel centres at +-0.047 and at 1.17 (x and z) from the axis */
        const float *mid = &img->rgba[4 * (SIZE / 2 * SIZE + SIZE / 2)];
        const float *corner = &img->rgba[4 * ((SIZE / 2 + 13) * SIZE + SIZE / 2 + 13)];
        printf("  medium in an interface sphere: through %.4f (exp(-2) %.4f), beside %.4f\n",
               mid[0], expf(-2.0f), corner[0]);
        CHECK(fabsf(mid[0] - expf(-2.0f)) < 0.01f);
        CHECK(fabsf(corner[0] - 1.0f) < 1e-3f);
    }
    char *rib = pbrt_as_rib(sphere);
    CHECK(rib && strstr(rib, "\"int camera\" [0] \"int diffuse\" [0] \"int specular\" [0] "
                             "\"int transmission\" [0]") != NULL);
    RayesImage *back = rib ? render_read(io_rib_parse, rib, 1) : NULL;
    CHECK(img && max_diff(img, back) < 1e-4f);
    rayes_image_free(back);
    free(rib);
    rayes_image_free(img);

    const char *cubes =
        AXIS_VIEW "AttributeBegin\nMaterial \"interface\"\nMediumInterface \"absorb\" \"\"\n"
                  "Shape \"trianglemesh\" \"point3 P\" ["
                  "-.5 -.5 -1 .5 -.5 -1 -.5 .5 -1 .5 .5 -1 -.5 -.5 -.5 .5 -.5 -.5 -.5 .5 -.5 .5 .5 "
                  "-.5 -.5 -.5 .2 .5 -.5 .2 -.5 .5 .2 .5 .5 .2 -.5 -.5 1 .5 -.5 1 -.5 .5 1 .5 .5 "
                  "1] \"integer indices\" [0 2 1 1 2 3 4 5 6 5 7 6 0 4 2 2 4 6 1 3 5 3 7 5 0 1 4 "
                  "1 5 4 2 6 3 3 6 7 8 10 9 9 10 11 12 13 14 13 15 14 8 12 10 10 12 14 9 11 13 "
                  "11 15 13 8 9 12 9 13 12 10 14 11 11 14 15]\nAttributeEnd\n";
    const int at[2][2] = {{SIZE / 2, SIZE / 2}, {1, 1}};
    float px[2][3];
    if (render_pixels(cubes, at, 2, px)) {
        printf("  medium in two interface cubes: through %.4f (exp(-0.65) %.4f), beside %.4f\n",
               px[0][0], expf(-0.65f), px[1][0]);
        CHECK(fabsf(px[0][0] - expf(-0.65f)) < 2e-3f);
        CHECK(fabsf(px[1][0] - 1.0f) < 1e-3f);
    }

    /* a unit cube of six bilinear patches in one Shape (each patch sent on
     * its own: they must make one bound), turned 30 degrees about y and 20
     * about x: the axis ray's chord is 1 / max |d| in the cube's frame,
     * 1.2288 */
    const char *patches =
        AXIS_VIEW "AttributeBegin\nRotate 30 0 1 0\nRotate 20 1 0 0\nMaterial \"interface\"\n"
                  "MediumInterface \"absorb\" \"\"\n"
                  "Shape \"bilinearmesh\" \"point3 P\" [-.5 -.5 -.5 .5 -.5 -.5 -.5 .5 -.5 .5 .5 "
                  "-.5 -.5 -.5 .5 .5 -.5 .5 -.5 .5 .5 .5 .5 .5] \"integer indices\" [0 2 1 3 4 5 "
                  "6 7 0 4 2 6 1 3 5 7 0 1 4 5 2 6 3 7]\nAttributeEnd\n";
    if (render_pixels(patches, MIDDLE, 1, px)) {
        printf("  medium in an interface cube of patches: through %.4f (exp(-0.6144) %.4f)\n",
               px[0][0], expf(-0.6144f));
        CHECK(fabsf(px[0][0] - expf(-0.6144f)) < 2e-3f);
    }
}

/* Glass lets shadow rays through (its thin shadow, (1 - R0)^2 for a
 * solid), and so through the medium it holds: a glass ball of wine casts
 * a red shadow. The distant light at 45 degrees puts the ball's shadow
 * beside it; the floor's centre pixel's shadow ray crosses the ball's
 * diameter, 2: 0.9216 exp(-0.1 * 2) red, 0.9216 exp(-2 * 2) green and
 * blue (it was 0.9216 in all three: the medium was skipped). */
static void test_medium_in_glass_shadow(void)
{
    const char *text =
        "LookAt -2 5 0  -2 0 0  0 0 1\n"
        "Camera \"orthographic\" \"float screenwindow\" [-0.5 0.5 -0.5 0.5]\n"
        "WorldBegin\nLightSource \"distant\" \"point3 from\" [1 1 0] \"point3 to\" [0 0 0] "
        "\"rgb L\" [4.44288294 4.44288294 4.44288294]\n"
        "MakeNamedMedium \"wine\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 2 2] "
        "\"rgb sigma_s\" [0 0 0]\n"
        "AttributeBegin\nTranslate 0 2 0\nMaterial \"dielectric\" \"float eta\" 1.5\n"
        "MediumInterface \"wine\" \"\"\nShape \"sphere\" \"float radius\" [1]\nAttributeEnd\n"
        "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [1 1 1]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [-4 0 -2  0 0 -2  -4 0 2  0 0 2] "
        "\"integer indices\" [0 1 2 3]\nAttributeEnd\n";
    float mid[1][3];
    if (render_pixels(text, MIDDLE, 1, mid)) {
        float red = 0.9216f * expf(-0.2f), green = 0.9216f * expf(-4.0f);
        printf("  shadow of wine in glass: %.4f %.4f %.4f (expected %.4f %.4f %.4f)\n", mid[0][0],
               mid[0][1], mid[0][2], red, green, green);
        CHECK(fabsf(mid[0][0] - red) < 0.01f);
        CHECK(fabsf(mid[0][1] - green) < 0.003f && fabsf(mid[0][2] - green) < 0.003f);
    }
}

/* A fog the camera is in, seen through a half-transparent black pane
 * (alpha 0.5) 2 units away, before a white emitter 11 units away: the
 * fog behind the pane counts too, 0.5 exp(-0.1 * 11), beside the pane
 * exp(-1.1) (only the fog before the pane counted: 0.5 exp(-0.2)). */
static void test_fog_behind_transparent(void)
{
    const char *text =
        "LookAt 0 0 -1  0 0 1  0 1 0\n"
        "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.1 0.1 0.1] "
        "\"rgb sigma_s\" [0 0 0]\nMediumInterface \"\" \"fog\"\n"
        "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\nWorldBegin\n"
        "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
        "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [-5 -5 10  -5 5 10  5 -5 10  5 5 10] "
        "\"integer indices\" [0 1 2 3]\nAttributeEnd\n"
        "AttributeBegin\nMaterial \"diffuse\" \"rgb reflectance\" [0 0 0]\n"
        "Shape \"bilinearmesh\" \"point3 P\" [0 -1 1  1 -1 1  0 1 1  1 1 1] "
        "\"integer indices\" [0 1 2 3] \"float alpha\" 0.5\nAttributeEnd\n";
    const int at[2][2] = {{SIZE / 4, SIZE / 2}, {3 * SIZE / 4, SIZE / 2}};
    float px[2][3];
    if (render_pixels(text, at, 2, px)) {
        printf("  fog beside a half-transparent pane %.4f (exp(-1.1) %.4f), through it %.4f "
               "(%.4f)\n",
               px[0][0], expf(-1.1f), px[1][0], 0.5f * expf(-1.1f));
        CHECK(fabsf(px[0][0] - expf(-1.1f)) < 2e-3f);
        CHECK(fabsf(px[1][0] - 0.5f * expf(-1.1f)) < 2e-3f);
    }
}

/* The mean image row (0 at the top) of the alpha-weighted pixels. */
static double mean_row(const RayesImage *img)
{
    double sum = 0.0, w = 0.0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            double a = img->rgba[4 * (y * SIZE + x) + 3];
            sum += a * y;
            w += a;
        }
    return w > 0.0 ? sum / w : -1.0;
}

/* A plymesh's "texture displacement" (pbrt-v4's: each vertex moved along
 * its normal by the texture, in object space) moves the surface: a flat
 * square under Scale 2 displaced by a constant 0.5 rises to z = 1, seen
 * from the side a little above; by a checkerboard of 0 and 0.5, half of
 * it does; without the displacement it stays. */
static void test_plymesh_displacement_moves(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/test_pbrt_alpha_quad.ply", RAYES_TEST_TMP);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    if (!f)
        return;
    fputs("ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
          "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
          "property float u\nproperty float v\nelement face 1\n"
          "property list uchar int vertex_indices\nend_header\n"
          "-1 -1 0 0 0 1 0 0\n1 -1 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n-1 1 0 0 0 1 0 1\n"
          "4 0 1 2 3\n",
          f);
    fclose(f);
    double row[3];
    static const char *const shift[3] = {
        "", " \"texture displacement\" \"lift\" \"float edgelength\" 0.1",
        " \"texture displacement\" \"cells\""};
    for (int k = 0; k < 3; k++) {
        char text[2048];
        snprintf(text, sizeof text,
                 "LookAt 0 -12 2  0 0 0.5  0 0 1\nCamera \"perspective\" \"float fov\" 30\n"
                 "WorldBegin\nLightSource \"distant\" \"point3 from\" [0 0 5] \"point3 to\" "
                 "[0 0 0]\n"
                 "Texture \"lift\" \"float\" \"constant\" \"float value\" 0.5\n"
                 "Texture \"cells\" \"float\" \"checkerboard\" \"float uscale\" 2 "
                 "\"float vscale\" 2 \"float tex1\" 0 \"float tex2\" 0.5\n"
                 "Scale 2 2 2\nShape \"plymesh\" \"string filename\" \"%s\"%s\n",
                 path, shift[k]);
        RayesImage *img = render_read(io_pbrt_parse, text, 1);
        CHECK(img != NULL);
        row[k] = img ? mean_row(img) : -1.0;
        rayes_image_free(img);
    }
    /* up in world z by 1 at 12 units: about 1 / (12 tan 15) of the half
     * height, 5 of the 32 rows */
    printf("  plymesh displacement: mean row %.2f without, %.2f lifted, %.2f by cells\n", row[0],
           row[1], row[2]);
    CHECK(row[0] > 0.0 && row[1] > 0.0 && row[2] > 0.0);
    CHECK(row[0] - row[1] > 3.0 && row[0] - row[1] < 7.0);
    /* half its cells lifted as far (a pattern, scaled too): between */
    CHECK(row[2] < row[0] - 1.0 && row[2] > row[1] + 0.5);
}

TEST_MAIN(TEST(test_constant_alpha), TEST(test_plymesh_displacement_moves),
          TEST(test_texture_alpha), TEST(test_rib_round_trip), TEST(test_bad_alpha),
          TEST(test_displacement_is_bump), TEST(test_medium_inside_glass),
          TEST(test_medium_inside_interface), TEST(test_medium_in_glass_shadow),
          TEST(test_fog_behind_transparent))
