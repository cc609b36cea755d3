/*
 * Displacement at dicing (scene/displace.c) and the noise it uses
 * (shade/noise.c): a sinusoidal displacement of a plane gives the analytic
 * surface and normals; neighbouring grids diced at different rates agree
 * where their vertices coincide; the bound clamps; the API refuses classes
 * without a displacement method; noise is zero on the lattice, bounded and
 * continuous.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "image/image.h"
#include "rayes/rayes.h"
#include "rayes/shader.h"
#include "scene/scene.h"
#include "shade/noise.h"
#include "test.h"

static const float amp = 0.05f, wave = 3.0f; /* h = amp sin(wave x) */

static void sine_displacement(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const void *params, RayesShadeOutputs *out)
{
    (void)sv, (void)params;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float h = amp * sinf(wave * ctx->P[i][0]);
        for (int c = 0; c < 3; c++)
            out->P[i][c] = ctx->P[i][c] + h * ctx->N[i][c];
    }
}

static void black(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                  RayesShadeOutputs *out)
{
    (void)sv, (void)params;
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
}

static const RayesShaderClass sine_class = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "sine",
    .displacement = sine_displacement,
    .lighting = black,
};

/* A scene of one unit-square bilinear patch in z = 0 (normal +z) per x
 * offset given, displaced by a built-in shader, then swapped for the test
 * class when sine is set. */
static RayesScene *plane_scene(int n_patches, const float *shading_rates, int sine)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_displacement(s, "fractal", NULL, 0) == RAYES_OK);
    for (int k = 0; k < n_patches; k++) {
        float x0 = (float)k;
        const float P[4][3] = {{x0, 0, 0}, {x0 + 1, 0, 0}, {x0, 1, 0}, {x0 + 1, 1, 0}};
        CHECK(rayes_scene_set_shading_rate(s, shading_rates[k]) == RAYES_OK);
        CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    }
    if (sine)
        s->displacements[0].cls = &sine_class;
    const float eye[3] = {1, 0.5f, 3}, target[3] = {1, 0.5f, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 40.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static void test_sine_plane_is_analytic(void)
{
    const float rates[1] = {1.0f};
    RayesScene *s = plane_scene(1, rates, 1);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 200, 200, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    CHECK(gs.n_vertices > 100);
    double worst_p = 0.0, worst_n = 0.0;
    for (size_t i = 0; i < gs.n_vertices; i++) {
        float x = gs.P[i].x;
        float h = amp * sinf(wave * x);
        worst_p = fmax(worst_p, fabs(gs.P[i].z - h));
        /* The surface z = h(x) has normal (-h'(x), 0, 1) / |...|. */
        Vec3 n = v3_normalize(v3(-amp * wave * cosf(wave * x), 0, 1));
        worst_n = fmax(worst_n, v3_length(v3_sub(gs.N[i], n)));
    }
    CHECK(worst_p < 1e-5);
    CHECK(worst_n < 2e-3); /* central differences over half a micropolygon */
    CHECK(worst_n > 0.0 || amp == 0.0f);
    /* Edge and curvature are re-measured on the displaced grid. */
    float curv = 0.0f;
    for (size_t g = 0; g < gs.n_grids; g++)
        curv = fmaxf(curv, gs.grids[g].curvature);
    CHECK(curv > 0.5f * amp * wave * wave);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

/* Two patches sharing the edge x = 1, diced at different rates: where their
 * vertices coincide (the shared corners) the displaced points and normals
 * are the same. */
static void test_neighbours_agree(void)
{
    const float rates[2] = {1.0f, 7.0f};
    RayesScene *s = plane_scene(2, rates, 0);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 20, 20, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    CHECK(gs.n_grids == 2);
    CHECK(gs.grids[0].nu != gs.grids[1].nu);
    int matches = 0;
    for (size_t a = 0; a < gs.n_vertices; a++)
        for (size_t b = a + 1; b < gs.n_vertices; b++) {
            int other_grid = (a < gs.grids[1].first_vertex) != (b < gs.grids[1].first_vertex);
            if (!other_grid || fabsf(gs.uv[a][1] - gs.uv[b][1]) > 1e-6f ||
                fabsf(gs.uv[a][0] - 1.0f) > 1e-6f || fabsf(gs.uv[b][0]) > 1e-6f)
                continue;
            matches++;
            CHECK(v3_length(v3_sub(gs.P[a], gs.P[b])) < 1e-4f);
            CHECK(v3_length(v3_sub(gs.N[a], gs.N[b])) < 1e-3f);
        }
    CHECK(matches >= 2);
    /* The fractal displacement did move the points off the plane. */
    float most = 0.0f;
    for (size_t i = 0; i < gs.n_vertices; i++)
        most = fmaxf(most, fabsf(gs.P[i].z));
    CHECK(most > 0.05f);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

static void test_bound_clamps(void)
{
    const float rates[1] = {1.0f};
    RayesScene *s = rayes_scene_new();
    const RayesParam p[] = {{"amplitude", RAYES_PARAM_FLOAT, {1.0f, 0, 0}, NULL}};
    CHECK(rayes_scene_set_displacement(s, "fractal", p, 1) == RAYES_OK);
    CHECK(rayes_scene_set_displacement_bound(s, 0.01f) == RAYES_OK);
    const float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_set_shading_rate(s, rates[0]) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 100, 100, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    float most = 0.0f;
    for (size_t i = 0; i < gs.n_vertices; i++)
        most = fmaxf(most, fabsf(gs.P[i].z));
    CHECK(most <= 0.01f * 1.0001f);
    CHECK(most > 0.005f);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

static void test_api_errors(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_set_displacement(s, "no-such-shader", NULL, 0) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "no-such-shader") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_set_displacement(s, "matte", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "no displacement method") != NULL);
    CHECK(rayes_scene_set_displacement_bound(s, -1.0f) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_displacement_bound(s, NAN) == RAYES_ERROR_INVALID_ARGUMENT);
    const RayesParam bad[] = {{"Km", RAYES_PARAM_FLOAT, {INFINITY, 0, 0}, NULL}};
    CHECK(rayes_scene_set_displacement(s, "bumpy", bad, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_set_displacement(s, "bumpy", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_displacement(s, NULL, NULL, 0) == RAYES_OK);
    CHECK(s->current_displacement == 0);
    rayes_scene_release(s);
}

static void test_noise(void)
{
    for (int x = -3; x <= 3; x++)
        for (int y = -3; y <= 3; y++)
            CHECK(noise3((float)x, (float)y, 7.0f) == 0.0f);
    float lo = 1.0f, hi = -1.0f, worst_step = 0.0f;
    double sum = 0.0;
    int n = 0;
    for (int i = 0; i < 20000; i++) {
        float x = 0.0137f * (float)i, y = 0.31f * (float)(i % 97), z = 0.07f * (float)(i % 13);
        float a = noise3(x, y, z), b = noise3(x + 1e-3f, y, z);
        lo = fminf(lo, a);
        hi = fmaxf(hi, a);
        worst_step = fmaxf(worst_step, fabsf(a - b));
        sum += a;
        n++;
    }
    CHECK(lo >= -1.0f && hi <= 1.0f);
    CHECK(hi - lo > 1.0f);           /* it does vary */
    CHECK(fabs(sum / n) < 0.05);     /* about zero mean */
    CHECK(worst_step < 0.01f);       /* continuous: gradient below ~10 */
    const float p[3] = {1.3f, -2.7f, 0.4f};
    float f1 = noise_fbm(p, 1, NOISE_LACUNARITY, 0.5f);
    CHECK(f1 == noise3(p[0], p[1], p[2]));
    float f4 = noise_fbm(p, 4, NOISE_LACUNARITY, 0.5f);
    CHECK(fabsf(f4) <= 1.875f);
    CHECK(noise_turbulence(p, 4, NOISE_LACUNARITY, 0.5f) >= fabsf(f4) - 1e-6f);
}

/* bumpy with a texture: displacement by Km times the texture, looked up at
 * dicing through the texture system given to prepare. */
static void test_bumpy_texture(void)
{
    const char *path = RAYES_TEST_TMP "/bumpy_half.exr";
    float px[4 * 4 * 4];
    for (int i = 0; i < 16; i++)
        px[4 * i] = px[4 * i + 1] = px[4 * i + 2] = 0.5f, px[4 * i + 3] = 1.0f;
    char err[256];
    CHECK(image_write_exr(path, 4, 4, px, err, sizeof err) == RAYES_OK);
    TextureSystem *ts = texture_system_new("", 1000000, 1.0f);
    CHECK(ts != NULL);
    RayesScene *s = rayes_scene_new();
    const RayesParam p[] = {{"Km", RAYES_PARAM_FLOAT, {0.1f, 0, 0}, NULL},
                            {"texturename", RAYES_PARAM_STRING, {0, 0, 0}, path}};
    CHECK(rayes_scene_set_displacement(s, "bumpy", p, 2) == RAYES_OK);
    const float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    for (int with = 0; with < 2; with++) {
        GridSet gs;
        geom_gridset_init(&gs);
        CHECK(scene_prepare(s, 50, 50, NULL, with ? ts : NULL, &gs, NULL, NULL, 0) == 0);
        float lo = INFINITY, hi = -INFINITY;
        for (size_t i = 0; i < gs.n_vertices; i++)
            lo = fminf(lo, gs.P[i].z), hi = fmaxf(hi, gs.P[i].z);
        if (with) {
            CHECK_NEAR(lo, 0.05f, 1e-6);
            CHECK_NEAR(hi, 0.05f, 1e-6);
        } else {
            CHECK(hi - lo > 0.01f); /* no texture system: noise, as without a texture */
        }
        geom_gridset_fini(&gs);
    }
    rayes_scene_release(s);
    texture_system_free(ts);
    remove(path);
}

static void test_checker(void)
{
    CHECK(pattern_checker(0.5f, 0.5f, 0, 0) == 1.0f);
    CHECK(pattern_checker(1.5f, 0.5f, 0, 0) == 0.0f);
    CHECK(pattern_checker(-0.5f, 0.5f, 0, 0) == 0.0f);
    CHECK(pattern_checker(-0.5f, -0.5f, 0, 0) == 1.0f);
    /* A footprint of whole periods averages to one half anywhere. */
    CHECK_NEAR(pattern_checker(0.3f, 0.7f, 2.0f, 2.0f), 0.5f, 1e-5);
    CHECK_NEAR(pattern_checker(0.3f, 0.7f, 4.0f, 0.0f), 0.5f, 1e-5);
    /* The filter is the mean of point samples over the box. */
    float s = 0.8f, t = 0.35f, ds = 0.7f, dt = 0.45f;
    double mean = 0.0;
    for (int i = 0; i < 400; i++)
        for (int j = 0; j < 400; j++)
            mean += pattern_checker(s + ds * ((i + 0.5f) / 400 - 0.5f),
                                    t + dt * ((j + 0.5f) / 400 - 0.5f), 0, 0);
    CHECK_NEAR(pattern_checker(s, t, ds, dt), mean / (400.0 * 400.0), 2e-3);
}

/* pbrt's "displacement": the displace shader's amount bound to a
 * checkerboard pattern raises the plane by 0.1 on its even checks of pbrt's
 * (u, v) = (2 s, 2 (1 - t)) and leaves the others; the pattern and binding
 * calls refuse what they cannot do, with a message. */
static void test_pattern_displacement(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam q[] = {{"tex1", RAYES_PARAM_FLOAT, {0.1f, 0, 0}, NULL},
                      {"tex2", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
                      {"uscale", RAYES_PARAM_FLOAT, {2, 0, 0}, NULL},
                      {"vscale", RAYES_PARAM_FLOAT, {2, 0, 0}, NULL}};
    CHECK(rayes_scene_pattern(s, "checks", "checkerboard", q, 4) == RAYES_OK);
    RayesParam amount = {"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, "checks"};
    CHECK(rayes_scene_set_displacement(s, "displace", &amount, 1) == RAYES_OK);
    const float P[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    const float eye[3] = {0.5f, 0.5f, 3}, target[3] = {0.5f, 0.5f, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 40.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 100, 100, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    size_t checked = 0, bad = 0;
    for (size_t i = 0; i < gs.n_vertices; i++) {
        float x = gs.P[i].x, y = gs.P[i].y, z = gs.P[i].z;
        if (z < -1e-6f || z > 0.1f + 1e-6f)
            bad++;
        if (fabsf(x - 0.5f) < 0.1f || fabsf(y - 0.5f) < 0.1f || x < 0.1f || x > 0.9f || y < 0.1f ||
            y > 0.9f)
            continue; /* near an edge the filtered checker blends */
        int even = ((int)floorf(2 * x) + (int)floorf(2 * (1 - y))) % 2 == 0;
        bad += fabsf(z - (even ? 0.1f : 0.0f)) > 1e-4f;
        checked++;
    }
    CHECK(checked > 50 && bad == 0);
    geom_gridset_fini(&gs);
    /* what is refused */
    RayesParam none = {"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, "nope"};
    CHECK(rayes_scene_set_displacement(s, "displace", &none, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "names no pattern (\"nope\")") != NULL);
    rayes_scene_clear_error(s);
    RayesParam wrong = {"preset", RAYES_PARAM_PATTERN, {0, 0, 0}, "checks"};
    CHECK(rayes_scene_set_shader(s, "conductor", &wrong, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "cannot take a pattern") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_pattern(s, "x", "ptex", NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "pattern \"x\": unknown pattern class \"ptex\"") !=
          NULL);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_sine_plane_is_analytic), TEST(test_neighbours_agree), TEST(test_bound_clamps),
          TEST(test_api_errors), TEST(test_noise), TEST(test_checker), TEST(test_bumpy_texture),
          TEST(test_pattern_displacement))
