/*
 * The third-party scene files of ../shared/data/scenes through the command
 * line: every file converts (reads) without error, every file that makes
 * an image renders one that is neither black nor broken, the two Cornell
 * boxes have their coloured walls on the sides their files put them (the
 * Aqsis RIB, left-handed as RenderMan is, shows its red wall on the right;
 * Bitterli's pbrt scene is the classic box, red on the left), and the pbrt
 * box converted to RIB renders the same image within noise.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "test.h"

#define SCENES RAYES_TEST_DATA "/scenes/"

static const char *const all_files[] = {
    "rib-aqsis/cornellbox/all_passes.rib", "rib-aqsis/cornellbox/bake_pass.rib",
    "rib-aqsis/cornellbox/beauty_pass.rib", "rib-aqsis/cornellbox/beautycam.rib",
    "rib-aqsis/cornellbox/geometry.rib",    "rib-aqsis/cornellbox/lights.rib",
    "rib-aqsis/cornellbox/shadow_pass.rib", "rib-aqsis/vase/vase.rib",
    "rib-aqsis/archives/bike.rib",          "rib-aqsis/archives/bikeData.rib.gz",
    "rib-aqsis/xpm/teapotgeom.rib",         "rib-aqsis/objectinstance/singlepolygon.rib",
    "pbrt-bitterli/cornell-box/scene-v4.pbrt",
};

/* The files that make a picture (the others are archives or map passes). */
static const char *const image_files[] = {
    "rib-aqsis/cornellbox/all_passes.rib", "rib-aqsis/cornellbox/beauty_pass.rib",
    "rib-aqsis/vase/vase.rib",             "rib-aqsis/archives/bike.rib",
    "rib-aqsis/xpm/teapotgeom.rib",        "rib-aqsis/objectinstance/singlepolygon.rib",
    "pbrt-bitterli/cornell-box/scene-v4.pbrt",
};

static int run(const char *args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "%s %s --data %s >/dev/null 2>%s/scene_files.err", RAYES_BIN, args,
             RAYES_TEST_DATA, RAYES_TEST_TMP);
    int status = system(cmd);
    if (status != 0) {
        char path[512], line[512];
        snprintf(path, sizeof path, "%s/scene_files.err", RAYES_TEST_TMP);
        FILE *f = fopen(path, "r");
        fprintf(stderr, "  `%s` failed:\n", args);
        while (f && fgets(line, sizeof line, f))
            fprintf(stderr, "    %s", line);
        if (f)
            fclose(f);
    }
    return status;
}

static float *render(const char *file, int size, int spp, const char *out, int *w, int *h)
{
    char args[1024], path[512], err[512];
    snprintf(path, sizeof path, "%s/%s", RAYES_TEST_TMP, out);
    snprintf(args, sizeof args, "render %s --res %d --spp %d --quiet -o %s", file, size, spp, path);
    if (run(args) != 0)
        return NULL;
    float *rgba = NULL;
    if (image_read_exr(path, w, h, &rgba, err, sizeof err) != RAYES_OK)
        fprintf(stderr, "  %s\n", err);
    return rgba;
}

/* Mean of channel c over the columns [x0, x1) of the middle half of the rows. */
static double band(const float *rgba, int w, int h, int x0, int x1, int c)
{
    double sum = 0;
    int n = 0;
    for (int y = h / 4; y < 3 * h / 4; y++)
        for (int x = x0; x < x1; x++, n++)
            sum += rgba[4 * (y * w + x) + c];
    return n ? sum / n : 0;
}

static void test_every_file_reads(void)
{
    for (size_t i = 0; i < sizeof all_files / sizeof all_files[0]; i++) {
        char args[1024];
        snprintf(args, sizeof args, "convert " SCENES "%s %s/converted.rib", all_files[i],
                 RAYES_TEST_TMP);
        CHECK(run(args) == 0);
    }
}

static void test_every_image_file_renders(void)
{
    for (size_t i = 0; i < sizeof image_files / sizeof image_files[0]; i++) {
        char file[512];
        snprintf(file, sizeof file, SCENES "%s", image_files[i]);
        int w = 0, h = 0;
        float *rgba = render(file, 48, 1, "scene_file.exr", &w, &h);
        CHECK(rgba != NULL);
        if (!rgba)
            continue;
        double sum = 0;
        int finite = 1;
        for (int k = 0; k < 4 * w * h; k++)
            finite &= isfinite(rgba[k]) != 0, sum += (k % 4 != 3) ? rgba[k] : 0;
        CHECK(finite);
        if (!(sum / (3.0 * w * h) > 1e-3))
            fprintf(stderr, "  %s renders black\n", image_files[i]);
        CHECK(sum / (3.0 * w * h) > 1e-3);
        free(rgba);
    }
}

static void check_walls(const char *file, int red_on_left)
{
    int w = 0, h = 0;
    float *rgba = render(file, 64, 4, "walls.exr", &w, &h);
    CHECK(rgba != NULL);
    if (!rgba)
        return;
    double lr = band(rgba, w, h, 0, w / 8, 0), lg = band(rgba, w, h, 0, w / 8, 1);
    double rr = band(rgba, w, h, w - w / 8, w, 0), rg = band(rgba, w, h, w - w / 8, w, 1);
    if (red_on_left) {
        CHECK(lr > lg && rg > rr);
    } else {
        CHECK(lg > lr && rr > rg);
    }
    free(rgba);
}

static void test_cornell_walls(void)
{
    check_walls(SCENES "rib-aqsis/cornellbox/beauty_pass.rib", 0);
    check_walls(SCENES "pbrt-bitterli/cornell-box/scene-v4.pbrt", 1);
}

static void test_pbrt_and_its_rib_agree(void)
{
    char args[1024], rib[512];
    snprintf(rib, sizeof rib, "%s/bitterli.rib", RAYES_TEST_TMP);
    snprintf(args, sizeof args, "convert " SCENES "pbrt-bitterli/cornell-box/scene-v4.pbrt %s",
             rib);
    CHECK(run(args) == 0);
    int w1 = 0, h1 = 0, w2 = 0, h2 = 0;
    float *a = render(SCENES "pbrt-bitterli/cornell-box/scene-v4.pbrt", 64, 16, "a.exr", &w1, &h1);
    float *b = render(rib, 64, 16, "b.exr", &w2, &h2);
    CHECK(a && b && w1 == w2 && h1 == h2);
    if (a && b && w1 == w2 && h1 == h2) {
        for (int c = 0; c < 3; c++) {
            double ma = band(a, w1, h1, 0, w1, c), mb = band(b, w2, h2, 0, w2, c);
            CHECK(fabs(ma - mb) <= 0.02 * ma + 1e-4);
        }
    }
    free(a);
    free(b);
}

TEST_MAIN(TEST(test_every_file_reads), TEST(test_every_image_file_renders),
          TEST(test_cornell_walls), TEST(test_pbrt_and_its_rib_agree))
