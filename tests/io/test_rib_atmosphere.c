/*
 * RIB's Atmosphere (io/rib_shade.c, rayes_scene_atmosphere): RenderMan's
 * fog, and Gritz's smoke as BMRT's noisysmoke computes it, become a
 * homogeneous medium between the eye and the surfaces camera rays meet.
 *
 * The scene: the camera at the origin looking down +z at a matte square
 * at z = 6 lit by a distant light along +z; the square fills the middle
 * of the image, its corners see nothing. Fogged, the middle is Ci
 * exp(-6 / distance) + background (1 - exp(-6 / distance)), the corners
 * stay black (a ray that meets nothing crosses no atmosphere) and the
 * light on the square is the same (shadow rays cross none); the writer's
 * RIB renders the same image.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "test.h"

#include "io/rib_round_trip.h"

enum { SIZE = 16 };

static const char *const square_rib =
    "LightSource \"distantlight\" 1 \"intensity\" 1\n"
    "Surface \"matte\"\nPolygon \"P\" [-1 -1 6  1 -1 6  1 1 6  -1 1 6]\nWorldEnd\n";

static RayesImage *render_text(const char *text)
{
    return rib_render_text(text, SIZE, 4);
}

/* The square under the atmosphere text (or ""). */
static RayesImage *render_atmosphere(const char *atmosphere)
{
    char text[2048];
    snprintf(text, sizeof text, "Projection \"perspective\" \"fov\" [40]\nWorldBegin\n%s\n%s",
             atmosphere, square_rib);
    return render_text(text);
}

static double middle(const RayesImage *img, int c)
{
    return rib_image_middle(img, SIZE, 2, c);
}

/* Fog of distance 4 and a coloured background: the middle as the formula
 * says (its rays cross about 6.05 units: the view is 40 degrees wide),
 * the corner black; the writer's RIB the same image. */
static void test_fog(void)
{
    RayesImage *clear = render_atmosphere("");
    const char *fog = "Atmosphere \"fog\" \"distance\" [4] \"background\" [0.2 0.4 0.8]";
    RayesImage *fogged = render_atmosphere(fog);
    CHECK(clear && fogged);
    if (clear && fogged) {
        double d = 6.0 / cos(atan(2.0 / SIZE * tan(20.0 * M_PI / 180.0))), T = exp(-d / 4.0);
        static const double bg[3] = {0.2, 0.4, 0.8};
        for (int c = 0; c < 3; c++) {
            double want = middle(clear, c) * T + bg[c] * (1.0 - T);
            CHECK_NEAR(middle(fogged, c), want, 0.01 * want);
        }
        CHECK(middle(clear, 0) > 0.1);
        CHECK(fogged->rgba[0] == 0.0f && fogged->rgba[1] == 0.0f); /* a corner: nothing met */
    }
    char text[2048], err[512];
    snprintf(text, sizeof text, "Projection \"perspective\" \"fov\" [40]\nWorldBegin\n%s\n%s", fog,
             square_rib);
    char *written = rib_round_trip(text, err, sizeof err);
    CHECK(written && strstr(written, "Atmosphere \"homogeneous\""));
    RayesImage *again = written ? render_text(written) : NULL;
    CHECK(again != NULL);
    if (again && fogged)
        for (int i = 0; i < 4 * SIZE * SIZE; i++)
            CHECK(fabsf(again->rgba[i] - fogged->rgba[i]) < 1e-5f);
    free(written);
    rayes_image_free(clear);
    rayes_image_free(fogged);
    rayes_image_free(again);
}

/* noisysmoke without lighting or noise glows lightscale density (1 -
 * exp(-density stepsize)) per unit length through extinction density:
 * the middle is Ci T + that / density (1 - T). With lighting, the lit
 * smoke adds light in front of the square; an atmosphere rayes does not
 * have (depthcue) warns and changes nothing. */
static void test_smoke(void)
{
    RayesImage *clear = render_atmosphere("");
    RayesImage *glow = render_atmosphere(
        "Atmosphere \"noisysmoke\" \"density\" [0.1] \"stepsize\" [0.2] \"lightscale\" [5] "
        "\"use_noise\" [0] \"use_lighting\" [0]");
    RayesImage *lit = render_atmosphere("Atmosphere \"smoke\" \"density\" [0.1] \"stepsize\" "
                                        "[0.2] \"lightscale\" [5] \"use_noise\" [0]");
    RayesImage *dark = render_atmosphere("Atmosphere \"smoke\" \"density\" [0.1] \"stepsize\" "
                                         "[0.2] \"lightscale\" [0] \"use_noise\" [0]");
    RayesImage *cue = render_atmosphere("Atmosphere \"depthcue\" \"maxdistance\" [3]");
    CHECK(clear && glow && lit && dark && cue);
    if (clear && glow && lit && dark && cue) {
        double d = 6.0 / cos(atan(2.0 / SIZE * tan(20.0 * M_PI / 180.0))), T = exp(-0.1 * d);
        double e = 5.0 * 0.1 * (1.0 - exp(-0.1 * 0.2));
        double want = middle(clear, 0) * T + e / 0.1 * (1.0 - T);
        CHECK_NEAR(middle(glow, 0), want, 0.01 * want);
        CHECK_NEAR(middle(dark, 0), middle(clear, 0) * T, 0.01 * middle(clear, 0) * T);
        CHECK(middle(lit, 0) > 1.02 * middle(dark, 0));
        CHECK_NEAR(middle(cue, 0), middle(clear, 0), 1e-6);
    }
    RayesImage *all[] = {clear, glow, lit, dark, cue};
    for (size_t k = 0; k < sizeof all / sizeof all[0]; k++)
        rayes_image_free(all[k]);
}

TEST_MAIN(TEST(test_fog), TEST(test_smoke))
