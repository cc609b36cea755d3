/*
 * Arbitrary output variables (RayesAov): a plane facing the camera gives
 * its distance as Z, its normal as N and its points as P; objects get
 * their own ids and no surface gives Z +inf and id 0; a cut-out's hole
 * passes to what lies behind; the colour is the same bytes with AOVs or
 * without, and the AOVs the same bytes on 1 and 2 threads and in a crop
 * window; the cache's resolution is read where diffuse rays were traced;
 * the EXR writer names every channel.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "io/builtin.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "test.h"

#define SIZE 32

static RayesParam pc(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}

/* Camera at z = 5 looking down -z (40 degrees); squares at z = 0: one
 * across [-1, 1]^2 or, with two, left and right halves, the second made
 * with its own shader (another object); with hole, a sheet of Os 0 at
 * z = 2 over all of it. */
static RayesScene *planes(int two, int hole)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40.0f) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    const float whole[4][3] = {{-1, -1, 0}, {1, -1, 0}, {-1, 1, 0}, {1, 1, 0}};
    const float left[4][3] = {{-1, -1, 0}, {0, -1, 0}, {-1, 1, 0}, {0, 1, 0}};
    const float right[4][3] = {{0, -1, 0}, {1, -1, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_bilinear_patch(s, two ? left : whole) == RAYES_OK);
    if (two) {
        RayesParam red[1] = {pc("Cs", 1, 0, 0)};
        CHECK(rayes_scene_set_shader(s, "matte", red, 1) == RAYES_OK);
        CHECK(rayes_scene_bilinear_patch(s, right) == RAYES_OK);
    }
    if (hole) {
        RayesParam clear[1] = {pc("Os", 0, 0, 0)};
        CHECK(rayes_scene_set_shader(s, "matte", clear, 1) == RAYES_OK);
        const float sheet[4][3] = {{-3, -3, 2}, {3, -3, 2}, {-3, 3, 2}, {3, 3, 2}};
        CHECK(rayes_scene_bilinear_patch(s, sheet) == RAYES_OK);
    }
    const float from[3] = {0, 0, 5}, to[3] = {0, 0, 0};
    RayesParam l[3] = {(RayesParam){"from", RAYES_PARAM_COLOR, {from[0], from[1], from[2]}, NULL},
                       (RayesParam){"to", RAYES_PARAM_COLOR, {to[0], to[1], to[2]}, NULL},
                       (RayesParam){"intensity", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", l, 3) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static RayesImage *render(RayesScene *s, unsigned aovs, int threads, int size, const float *crop)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = size;
    o.spp = 4;
    o.threads = threads;
    o.aovs = aovs;
    if (crop)
        memcpy(o.crop, crop, sizeof o.crop);
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

/* The cache AOV alone, at 48 x 48 with the given hider. */
static RayesImage *render_hider(RayesScene *s, RayesHider hider, int threads)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = 48;
    o.spp = 4;
    o.threads = threads;
    o.hider = hider;
    o.aovs = RAYES_AOV_CACHE;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    return img;
}

static const float *aov_at(const RayesImage *img, int x, int y)
{
    return &img->aov[(size_t)img->aov_channels * ((size_t)y * img->width + x)];
}

static void test_channels(void)
{
    CHECK(rayes_aov_channels(0) == 0);
    CHECK(rayes_aov_channels(RAYES_AOV_ALL) == RAYES_AOV_CHANNELS_MAX);
    CHECK(rayes_aov_channels(RAYES_AOV_N | RAYES_AOV_ID) == 4);
    CHECK(strcmp(rayes_aov_channel_name(RAYES_AOV_N | RAYES_AOV_ID, 0), "N.X") == 0);
    CHECK(strcmp(rayes_aov_channel_name(RAYES_AOV_N | RAYES_AOV_ID, 3), "id") == 0);
    CHECK(rayes_aov_channel_name(RAYES_AOV_N | RAYES_AOV_ID, 4) == NULL);
    CHECK(strcmp(rayes_aov_channel_name(RAYES_AOV_ALL, 8), "patch") == 0);
    CHECK(strcmp(rayes_aov_channel_name(RAYES_AOV_ALL, 9), "cache") == 0);
    CHECK(strcmp(rayes_aov_channel_name(RAYES_AOV_ALL, 12), "albedo.B") == 0);
    RayesScene *s = planes(0, 0);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.aovs = 1u << 7;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_ERROR_INVALID_ARGUMENT && img == NULL);
    o.aovs = RAYES_AOV_Z; /* sessions accumulate colour alone */
    RayesSession *session = NULL;
    CHECK(rayes_session_new(s, &o, &session) == RAYES_ERROR_INVALID_ARGUMENT && !session);
    rayes_scene_release(s);
}

/* The plane's pixels: Z 5 (its distance along the view), N (0, 0, 1), P
 * on it at the pixel; the corners see nothing: Z +inf, id 0, N 0. */
static void test_plane(void)
{
    RayesScene *s = planes(0, 0);
    RayesImage *img = render(s, RAYES_AOV_ALL, 2, SIZE, NULL);
    CHECK(img->aov != NULL && img->aov_channels == RAYES_AOV_CHANNELS_MAX);
    CHECK(img->aovs == RAYES_AOV_ALL);
    float pixel = 2.0f * 5.0f * tanf(20.0f * (float)M_PI / 180.0f) / SIZE; /* world, at z = 0 */
    int inside = 0;
    for (int y = 0; y < SIZE; y++)
        for (int x = 0; x < SIZE; x++) {
            const float *a = aov_at(img, x, y);
            float wx = ((float)x + 0.5f - SIZE / 2.0f) * pixel, wy = (SIZE / 2.0f - (float)y - 0.5f) * pixel;
            if (fabsf(wx) < 1.0f - pixel && fabsf(wy) < 1.0f - pixel) { /* wholly on it */
                inside++;
                CHECK(fabsf(a[0] - 5.0f) < 1e-4f);
                CHECK(fabsf(a[1]) < 1e-5f && fabsf(a[2]) < 1e-5f && fabsf(a[3] - 1.0f) < 1e-5f);
                CHECK(fabsf(a[4] - wx) < 0.5f * pixel && fabsf(a[5] - wy) < 0.5f * pixel);
                CHECK(fabsf(a[6]) < 1e-5f);
                CHECK(a[7] == 1.0f && a[8] >= 1.0f);
                CHECK(fabsf(a[10] - 1.0f) < 1e-4f && fabsf(a[12] - 1.0f) < 1e-4f); /* Kd 1 */
            } else if (fabsf(wx) > 1.0f + pixel && fabsf(wy) > 1.0f + pixel) { /* beside it */
                CHECK(isinf(a[0]) && a[0] > 0.0f && a[7] == 0.0f && a[8] == 0.0f);
                CHECK(a[1] == 0.0f && a[2] == 0.0f && a[3] == 0.0f && a[10] == 0.0f);
            }
        }
    CHECK(inside > SIZE * SIZE / 5); /* the plane is 0.55 of the view across */
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* The albedo of a plane across the view shaded by shader with params,
 * at the centre pixel (the albedo AOV alone: 3 channels). */
static void plane_albedo(const char *shader, const RayesParam *params, int n, float out[3])
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 20.0f) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, shader, params, n) == RAYES_OK);
    const float whole[4][3] = {{-3, -3, 0}, {3, -3, 0}, {-3, 3, 0}, {3, 3, 0}};
    CHECK(rayes_scene_bilinear_patch(s, whole) == RAYES_OK);
    RayesParam l[3] = {(RayesParam){"from", RAYES_PARAM_COLOR, {1, 2, 5}, NULL},
                       (RayesParam){"to", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                       (RayesParam){"intensity", RAYES_PARAM_FLOAT, {3, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", l, 3) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesImage *img = render(s, RAYES_AOV_ALBEDO, 2, 8, NULL);
    CHECK(img->aov_channels == 3 &&
          strcmp(rayes_aov_channel_name(RAYES_AOV_ALBEDO, 1), "albedo.G") == 0);
    memcpy(out, aov_at(img, 4, 4), 3 * sizeof(float));
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* The albedo is what each shader reflects of white light from everywhere,
 * whatever the scene's lights: Kd Cs for matte (its ambient term is the
 * ambient lights', 0), a pbrt diffuse's reflectance, a mirror's Kr
 * specularcolor, a dielectric's reflection and refraction together (1). */
static void test_albedo(void)
{
    float a[3];
    RayesParam matte[2] = {{"Kd", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL},
                           pc("Cs", 1.0f, 0.5f, 0.25f)};
    plane_albedo("matte", matte, 2, a);
    CHECK(fabsf(a[0] - 0.5f) < 1e-4f && fabsf(a[1] - 0.25f) < 1e-4f &&
          fabsf(a[2] - 0.125f) < 1e-4f);
    RayesParam diffuse[1] = {pc("reflectance", 0.2f, 0.4f, 0.6f)};
    plane_albedo("diffuse", diffuse, 1, a);
    CHECK(fabsf(a[0] - 0.2f) < 1e-4f && fabsf(a[1] - 0.4f) < 1e-4f && fabsf(a[2] - 0.6f) < 1e-4f);
    RayesParam mirror[2] = {{"Kr", RAYES_PARAM_FLOAT, {0.8f, 0, 0}, NULL},
                            pc("specularcolor", 1.0f, 0.5f, 1.0f)};
    plane_albedo("mirror", mirror, 2, a);
    CHECK(fabsf(a[0] - 0.8f) < 1e-4f && fabsf(a[1] - 0.4f) < 1e-4f && fabsf(a[2] - 0.8f) < 1e-4f);
    plane_albedo("dielectric", NULL, 0, a);
    fprintf(stderr, "dielectric albedo %g %g %g\n", a[0], a[1], a[2]);
    CHECK(fabsf(a[0] - 1.0f) < 0.02f && fabsf(a[1] - 1.0f) < 0.02f && fabsf(a[2] - 1.0f) < 0.02f);
}

/* Two objects: their own ids; a hole in front passes to them. */
static void test_ids_and_holes(void)
{
    for (int hole = 0; hole < 2; hole++) {
        RayesScene *s = planes(1, hole);
        RayesImage *img = render(s, RAYES_AOV_Z | RAYES_AOV_ID, 2, SIZE, NULL);
        const float *l = aov_at(img, SIZE / 2 - 4, SIZE / 2), *r = aov_at(img, SIZE / 2 + 3, SIZE / 2);
        CHECK(l[1] >= 1.0f && r[1] >= 1.0f && l[1] != r[1]);
        CHECK(fabsf(l[0] - 5.0f) < 1e-4f && fabsf(r[0] - 5.0f) < 1e-4f); /* not the sheet's 3 */
        const float *corner = aov_at(img, 0, 0);
        if (hole) /* the sheet covers the corner, a hole all over: nothing */
            CHECK(isinf(corner[0]) && corner[1] == 0.0f);
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

/* The colour does not change with AOVs; the AOVs do not change with the
 * threads or a crop window (the Cornell box: walls, boxes, a light). */
static void test_deterministic(void)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    IoSink sink = io_sink_scene(s);
    CHECK(io_builtin_scene("cornell", NULL, &sink, err, sizeof err) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesImage *plain = render(s, 0, 2, 48, NULL), *two = render(s, RAYES_AOV_ALL, 2, 48, NULL);
    RayesImage *one = render(s, RAYES_AOV_ALL, 1, 48, NULL);
    const float crop[4] = {0.25f, 0.75f, 0.4f, 0.9f};
    RayesImage *part = render(s, RAYES_AOV_ALL, 2, 48, crop);
    size_t n = (size_t)48 * 48;
    CHECK(plain->aov == NULL && plain->aov_channels == 0);
    CHECK(memcmp(plain->rgba, two->rgba, n * 4 * sizeof(float)) == 0);
    CHECK(memcmp(one->aov, two->aov, n * RAYES_AOV_CHANNELS_MAX * sizeof(float)) == 0);
    int differ = 0, ids = 0;
    for (int y = part->crop[1]; y < part->crop[1] + part->crop[3]; y++)
        for (int x = part->crop[0]; x < part->crop[0] + part->crop[2]; x++)
            differ += memcmp(aov_at(part, x, y), aov_at(two, x, y),
                             RAYES_AOV_CHANNELS_MAX * sizeof(float)) != 0;
    for (size_t i = 1; i < n; i++)
        ids += two->aov[RAYES_AOV_CHANNELS_MAX * i + 7] != two->aov[RAYES_AOV_CHANNELS_MAX * (i - 1) + 7];
    CHECK(part->crop[2] > 0 && differ == 0);
    CHECK(ids > 10); /* walls, boxes and the light are objects of their own */
    /* the cache's resolutions: 0 to 2 where diffuse rays were traced, -1
     * on the light (which traces none); all three levels read somewhere */
    int traced = 0, none = 0, levels[3] = {0, 0, 0};
    for (size_t i = 0; i < n; i++) {
        float c = two->aov[RAYES_AOV_CHANNELS_MAX * i + 9];
        CHECK(c == -1.0f || (c >= 0.0f && c <= 2.0f));
        traced += c >= 0.0f;
        none += c == -1.0f;
        if (c >= 0.0f)
            levels[(int)lroundf(c)]++;
    }
    CHECK(traced > (int)n / 2 && none > 0);
    CHECK(levels[0] > 0 && levels[1] > 0 && levels[2] > 0);
    /* the grid hider: a grid's mean level, the same on any threads */
    RayesImage *g1 = render_hider(s, RAYES_HIDER_GRID, 1),
               *g2 = render_hider(s, RAYES_HIDER_GRID, 2);
    CHECK(memcmp(g1->aov, g2->aov, n * sizeof(float)) == 0);
    CHECK(memcmp(g1->rgba, g2->rgba, n * 4 * sizeof(float)) == 0);
    traced = 0;
    for (size_t i = 0; i < n; i++)
        traced += g2->aov[i] >= 0.0f && g2->aov[i] <= 2.0f;
    CHECK(traced > (int)n / 2);
    rayes_image_free(g1);
    rayes_image_free(g2);
    rayes_image_free(plain);
    rayes_image_free(two);
    rayes_image_free(one);
    rayes_image_free(part);
    rayes_scene_release(s);
}

/* The EXR holds the AOVs as float channels of their names, beside R, G,
 * B, A (read back by OpenImageIO's oiiotool when it is installed). */
static void test_exr(void)
{
    RayesScene *s = planes(0, 0);
    RayesImage *img = render(s, RAYES_AOV_Z | RAYES_AOV_N, 1, 16, NULL);
    const char *names[4] = {rayes_aov_channel_name(img->aovs, 0), rayes_aov_channel_name(img->aovs, 1),
                            rayes_aov_channel_name(img->aovs, 2), rayes_aov_channel_name(img->aovs, 3)};
    char path[1024], err[512], cmd[1200], line[4096] = "";
    snprintf(path, sizeof path, "%s/test_aov.exr", RAYES_TEST_TMP);
    const int all[4] = {0, 0, 16, 16};
    CHECK(image_write_exr_aov(path, 16, 16, img->rgba, all, 0, img->aov, 4, names, err, sizeof err) ==
          RAYES_OK);
    const char *bad[1] = {"G"};
    CHECK(image_write_exr_aov(path, 16, 16, img->rgba, all, 0, img->aov, 1, bad, err, sizeof err) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    float *back = NULL;
    int w = 0, h = 0;
    CHECK(image_read_exr(path, &w, &h, &back, err, sizeof err) == RAYES_OK && w == 16);
    free(back);
    snprintf(cmd, sizeof cmd, "oiiotool --info -v %s 2>/dev/null", path);
    FILE *p = popen(cmd, "r");
    size_t got = p ? fread(line, 1, sizeof line - 1, p) : 0;
    int status = p ? pclose(p) : -1;
    line[got] = '\0';
    if (status == 0 && got > 0) {
        CHECK(strstr(line, "Z (float)") != NULL);
        CHECK(strstr(line, "N.X (float)") != NULL && strstr(line, "N.Z (float)") != NULL);
        CHECK(strstr(line, "R (half)") != NULL);
    } else {
        printf("  oiiotool not found: channel names not read back\n");
    }
    rayes_image_free(img);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_channels), TEST(test_plane), TEST(test_albedo), TEST(test_ids_and_holes),
          TEST(test_deterministic), TEST(test_exr))
