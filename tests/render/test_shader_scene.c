/*
 * The cornell-spheres scene renders what its shaders promise, measured on
 * the picture: the gold conductor is yellower than the grey shinymetal,
 * glass shows the red wall (on its left in the room) inverted, on its
 * right half, and the dielectric spheres and conductors are not black.
 */
#include <math.h>
#include <string.h>

#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

enum { RES = 128 };

typedef struct Disc {
    double rgb[3];
    double half[2][3]; /* image-left half, image-right half */
} Disc;

/* Mean colour over the inner 80% of the disc of a sphere of radius 55 at
 * world (x, y, z), seen by the Cornell camera (eye (278, 273, -800) looking
 * down +z, field of view 39.3077 degrees; world +x is image left). */
static Disc disc(const RayesImage *img, float x, float y, float z)
{
    Disc d;
    memset(&d, 0, sizeof d);
    double t = tan(39.3077 * 3.14159265358979 / 360.0), depth = z + 800.0;
    double cx = 0.5 * RES * (1.0 - (x - 278.0) / (depth * t));
    double cy = 0.5 * RES * (1.0 - (y - 273.0) / (depth * t));
    double r = 0.8 * 0.5 * RES * 55.0 / (depth * t);
    int n = 0, nh[2] = {0, 0};
    for (int py = 0; py < RES; py++)
        for (int px = 0; px < RES; px++) {
            double dx = px + 0.5 - cx, dy = py + 0.5 - cy;
            if (dx * dx + dy * dy > r * r)
                continue;
            const float *p = img->rgba + 4 * ((size_t)py * RES + px);
            int h = dx > 0.0;
            for (int c = 0; c < 3; c++) {
                d.rgb[c] += p[c];
                d.half[h][c] += p[c];
            }
            n++;
            nh[h]++;
        }
    for (int c = 0; c < 3; c++) {
        d.rgb[c] /= n > 0 ? n : 1;
        d.half[0][c] /= nh[0] > 0 ? nh[0] : 1;
        d.half[1][c] /= nh[1] > 0 ? nh[1] : 1;
    }
    CHECK(n > 100);
    return d;
}

static void test_spheres_picture(void)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell-spheres", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 4;
    o.specular_depth = 8;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    rayes_scene_release(s);
    if (!img)
        return;
    /* Positions as io/builtin.c places them. */
    Disc shiny = disc(img, 92, 260, 400), glass = disc(img, 464, 55, 170);
    Disc gold = disc(img, 340, 55, 170), water = disc(img, 216, 55, 170);
    Disc coated = disc(img, 92, 55, 170);
    double gold_yb = gold.rgb[0] / gold.rgb[2], shiny_yb = shiny.rgb[0] / shiny.rgb[2];
    fprintf(stderr, "R/B gold %.2f shinymetal %.2f; glass R/G left %.2f right %.2f\n", gold_yb,
            shiny_yb, glass.half[0][0] / glass.half[0][1], glass.half[1][0] / glass.half[1][1]);
    CHECK(gold_yb > 1.5 * shiny_yb);
    /* The red wall is at world +x, left in the image: through the glass
     * ball it appears on the ball's right half (measured: right R/G 1.32
     * times the left's; 0.89 for a glass of eta 1, which does not bend). */
    CHECK(glass.half[1][0] / glass.half[1][1] > 1.15 * (glass.half[0][0] / glass.half[0][1]));
    CHECK(water.rgb[0] + water.rgb[1] + water.rgb[2] > 0.05);
    CHECK(coated.rgb[1] > coated.rgb[0] && coated.rgb[1] > coated.rgb[2]); /* green base */
    rayes_image_free(img);
}

TEST_MAIN(TEST(test_spheres_picture))
