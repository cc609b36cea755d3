/*
 * pbrt-v4's mix of two materials of other classes, read into the "mix"
 * shader (io/pbrt_material.c) and rendered: where a checkerboard amount
 * is 0 the first material shows, where 1 the second, each pixel as the
 * material's own render (no bounce: no path meets the surface twice);
 * the RIB writer writes the mix as `Surface "mix"` with "a:" and "b:"
 * parameters and reads back to the same image.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

#include "io/rib_round_trip.h"

enum { RES = 32 };

static const char *const head =
    "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" [30]\n"
    "WorldBegin\n"
    "LightSource \"distant\" \"point3 from\" [1 2 5] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3]\n"
    "Texture \"checks\" \"float\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2]\n"
    "MakeNamedMaterial \"red\" \"string type\" \"coateddiffuse\" \"rgb reflectance\" [0.8 0.1 "
    "0.1] \"float roughness\" [0.1]\n"
    "MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\" "
    "\"spectrum k\" \"metal-Au-k\" \"float roughness\" [0.3]\n"
    "MakeNamedMaterial \"both\" \"string type\" \"mix\" \"string materials\" [\"red\" \"gold\"] "
    "\"texture amount\" \"checks\"\n";

static const char *const square =
    "Shape \"bilinearmesh\" \"point3 P\" [-1 -1 0 1 -1 0 -1 1 0 1 1 0] \"point2 uv\" [0 0 1 0 0 1 "
    "1 1]\n";

static RayesImage *render_scene(RayesScene *s)
{
    RayesImage *img = NULL;
    if (rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = RES;
        o.spp = 4;
        o.threads = 2;
        o.bounces = 0;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    }
    return img;
}

/* The square under NamedMaterial material, rendered from pbrt text. */
static RayesImage *render_named(const char *material)
{
    char text[4096], err[512];
    snprintf(text, sizeof text, "%sNamedMaterial \"%s\"\n%s", head, material, square);
    RayesError e;
    RayesScene *s = pbrt_read_scene(text, &e, err, sizeof err);
    if (e != RAYES_OK)
        fprintf(stderr, "  %s\n", err);
    CHECK(e == RAYES_OK);
    RayesImage *img = e == RAYES_OK ? render_scene(s) : NULL;
    rayes_scene_release(s);
    return img;
}

static int same_pixel(const RayesImage *a, const RayesImage *b, int i)
{
    for (int c = 0; c < 3; c++)
        if (fabsf(a->rgba[4 * i + c] - b->rgba[4 * i + c]) > 1e-4f)
            return 0;
    return 1;
}

static void test_pbrt_mix_checks(void)
{
    RayesImage *red = render_named("red"), *gold = render_named("gold");
    RayesImage *both = render_named("both");
    CHECK(red && gold && both);
    if (red && gold && both) {
        int as_red = 0, as_gold = 0, other = 0;
        for (int i = 0; i < RES * RES; i++) {
            int r = same_pixel(both, red, i), g = same_pixel(both, gold, i);
            as_red += r && !g;
            as_gold += g && !r;
            other += !r && !g;
        }
        /* the square covers half the frame, half its cells each; only
         * pixels across an edge (a cell's, the square's) blend their
         * samples */
        CHECK(as_red > RES * RES / 8 && as_gold > RES * RES / 8);
        CHECK(other < RES * RES / 5);
    }
    rayes_image_free(red);
    rayes_image_free(gold);
    rayes_image_free(both);
}

/* The writer's RIB of a mix reads back to the same image. */
static void test_mix_round_trip(void)
{
    const char *text =
        "Projection \"perspective\" \"fov\" [40]\nWorldBegin\n"
        "LightSource \"pointlight\" 1 \"from\" [1 1 0] \"intensity\" [40]\n"
        "Pattern \"checkerboard\" \"cells\" \"float uscale\" [4] \"float vscale\" [4]\n"
        "Surface \"mix\" \"string a\" [\"plastic\"] \"string b\" [\"mix\"] \"float a:Ks\" [0.9] "
        "\"string b:a\" [\"matte\"] \"string b:b\" [\"conductor\"] \"float b:b:roughness\" [0.2] "
        "\"float b:amount\" [0.4] \"reference pattern amount\" [\"cells\"]\n"
        "Polygon \"P\" [-3 -3 6  3 -3 6  3 3 6  -3 3 6]\nWorldEnd\n";
    char err[512];
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written != NULL);
    if (!written) {
        fprintf(stderr, "  %s\n", err);
        return;
    }
    CHECK(strstr(written, "Surface \"mix\"") && strstr(written, "b:b:roughness"));
    RayesError e1, e2;
    RayesScene *s1 = rib_read_scene(text, &e1, err, sizeof err);
    RayesScene *s2 = rib_read_scene(written, &e2, err, sizeof err);
    CHECK(e1 == RAYES_OK && e2 == RAYES_OK);
    RayesImage *a = e1 == RAYES_OK ? render_scene(s1) : NULL;
    RayesImage *b = e2 == RAYES_OK ? render_scene(s2) : NULL;
    CHECK(a && b);
    if (a && b) {
        int differ = 0;
        for (int i = 0; i < RES * RES; i++)
            differ += !same_pixel(a, b, i);
        CHECK(differ == 0);
    }
    rayes_image_free(a);
    rayes_image_free(b);
    rayes_scene_release(s1);
    rayes_scene_release(s2);
    free(written);
}

TEST_MAIN(TEST(test_pbrt_mix_checks), TEST(test_mix_round_trip))
