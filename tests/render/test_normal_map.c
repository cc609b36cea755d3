/*
 * Normal maps (pbrt-v4's "normalmap", the "normalmap" parameter of the
 * physically based shaders bound to a linear image): under a distant
 * light 60 degrees off the vertical toward +x, a map that tilts every
 * normal 60 degrees toward +s turns a diffuse floor whose s runs along x
 * to face the light (twice the light), and one whose s runs along y a
 * quarter away from it (cos^2 60 = 1/4: half the light); the frame
 * follows dP/ds, not dP/du. A flat map changes nothing, and a map normal
 * below the surface is not used.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "rayes/rayes.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/normal_map"
enum { RES = 16 };

/* An EXR (linear) of one tangent-space normal everywhere. */
static void write_map(const char *path, float nx, float ny, float nz)
{
    enum { S = 8 };
    static float rgba[S * S * 4];
    for (int k = 0; k < S * S; k++) {
        rgba[4 * k + 0] = 0.5f * (nx + 1.0f);
        rgba[4 * k + 1] = 0.5f * (ny + 1.0f);
        rgba[4 * k + 2] = 0.5f * (nz + 1.0f);
        rgba[4 * k + 3] = 1.0f;
    }
    char err[300];
    mkdir(TMP, 0755);
    CHECK(image_write_exr(path, S, S, rgba, err, sizeof err) == RAYES_OK);
}

/* The mean of a diffuse floor (z = 0, seen from above) under a distant
 * light 60 degrees off +z toward +x, with the normal map at path (NULL:
 * none). swap: the floor's s runs along its v (y), so dP/du is not dP/ds. */
static double floor_light(const char *path, int swap)
{
    RayesScene *s = rayes_scene_new();
    static const float eye[3] = {0, 0, 6}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 15.0f) == RAYES_OK);
    RayesParam p[2] = {{"reflectance", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
                       {"normalmap", RAYES_PARAM_PATTERN, {0, 0, 0}, "nm"}};
    if (path) {
        RayesParam q[2] = {{"filename", RAYES_PARAM_STRING, {0, 0, 0}, path},
                           {"encoding", RAYES_PARAM_STRING, {0, 0, 0}, "linear"}};
        CHECK(rayes_scene_pattern(s, "nm", "imagemap", q, 2) == RAYES_OK);
    }
    CHECK(rayes_scene_set_shader(s, "diffuse", p, path ? 2 : 1) == RAYES_OK);
    /* P00 P10 P01 P11; st at the corners (swapped: s along v) */
    const float P[4][3] = {{-2, -2, 0}, {2, -2, 0}, {-2, 2, 0}, {2, 2, 0}};
    const float st[4][2] = {{0, 0}, {1, 0}, {0, 1}, {1, 1}}, ts[4][2] = {{0, 0}, {0, 1}, {1, 0},
                                                                       {1, 1}};
    RayesPrimvar pv = {"st", RAYES_PRIMVAR_VERTEX, &(swap ? ts : st)[0][0], 4};
    CHECK(rayes_scene_bilinear_patch_pv(s, P, &pv, 1) == RAYES_OK);
    RayesParam l[2] = {{"from", RAYES_PARAM_COLOR, {0.8660254f, 0, 0.5f}, NULL},
                       {"to", RAYES_PARAM_COLOR, {0, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", l, 2) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = RES;
    o.spp = 1;
    o.bounces = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double m = 0.0;
    for (size_t i = 0; img && i < (size_t)RES * RES; i++)
        m += img->rgba[4 * i + 1] / (double)(RES * RES);
    rayes_image_free(img);
    rayes_scene_release(s);
    return m;
}

static void test_tilt_follows_s(void)
{
    const float a = (float)(M_PI / 3.0);
    write_map(TMP "/tilt.exr", sinf(a), 0.0f, cosf(a));
    write_map(TMP "/flat.exr", 0.0f, 0.0f, 1.0f);
    write_map(TMP "/away.exr", 0.0f, 0.0f, -1.0f);
    double plain = floor_light(NULL, 0);
    CHECK(plain > 0.05);
    CHECK_NEAR(floor_light(TMP "/flat.exr", 0), plain, 1e-4 * plain);
    CHECK_NEAR(floor_light(TMP "/tilt.exr", 0), 2.0 * plain, 2e-3 * plain);
    CHECK_NEAR(floor_light(TMP "/tilt.exr", 1), 0.5 * plain, 2e-3 * plain);
    /* A map normal below the surface is not used. */
    CHECK_NEAR(floor_light(TMP "/away.exr", 0), plain, 1e-4 * plain);
}

TEST_MAIN(TEST(test_tilt_follows_s))
