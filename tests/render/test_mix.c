/*
 * The "mix" shader (shade/mix.c, make_instance in scene.c): two materials
 * of any classes blended by an amount. Against renders of each material
 * alone (the same sample keys, so the same numbers): a constant amount is
 * their blend, pixel by pixel, at camera hits and through the radiosity
 * cache (diffuselighting); an amount bound to a checkerboard pattern shows
 * one material or the other cell by cell; a mix within a mix; a child's
 * opacity makes the object transparent, children without none leave it
 * opaque; a subsurface child asks for the object's own scene; errors name
 * what is missing.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "shade/shade.h"
#include "test.h"

enum { RES = 24 };

static RayesParam pf(const char *name, float v)
{
    return (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}
static RayesParam pc(const char *name, float r, float g, float b)
{
    return (RayesParam){name, RAYES_PARAM_COLOR, {r, g, b}, NULL};
}
static RayesParam ps(const char *name, const char *v)
{
    return (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}
static RayesParam pp(const char *name, const char *pattern)
{
    return (RayesParam){name, RAYES_PARAM_PATTERN, {0, 0, 0}, pattern};
}

/* A lit floor facing the camera, shaded by class with params, and a
 * white wall beside it whose light comes from the floor (bounces 1). */
static RayesImage *render_with(const char *cls, const RayesParam *params, size_t n, int bounces)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40) == RAYES_OK);
    RayesParam light[3] = {pc("from", 1, 2, 4), pc("to", 0, 0, 0), pf("intensity", 3)};
    CHECK(rayes_scene_light(s, "distantlight", light, 3) == RAYES_OK);
    RayesParam cells[2] = {pf("uscale", 4), pf("vscale", 4)};
    CHECK(rayes_scene_pattern(s, "cells", "checkerboard", cells, 2) == RAYES_OK);
    RayesError e = rayes_scene_set_shader(s, cls, params, n);
    CHECK(e == RAYES_OK);
    const float floor[4][3] = {{-2, -2, 0}, {2, -2, 0}, {-2, 2, 0}, {2, 2, 0}};
    CHECK(rayes_scene_bilinear_patch(s, floor) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    const float wall[4][3] = {{2, -2, 0}, {2, -2, 3}, {2, 2, 0}, {2, 2, 3}};
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    RayesImage *img = NULL;
    if (e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK) {
        RayesRenderOptions o;
        rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
        o.width = o.height = RES;
        o.spp = 4;
        o.threads = 2;
        o.bounces = bounces;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    }
    rayes_scene_release(s);
    return img;
}

/* The largest difference between img and (1 - w) a + w b over every pixel
 * (w < 0: per pixel, a or b whichever is nearer), and the mean of img. */
static double worst_blend(const RayesImage *img, const RayesImage *a, const RayesImage *b, float w,
                          double *mean)
{
    double worst = 0.0, sum = 0.0;
    for (int i = 0; i < 4 * RES * RES; i++) {
        if (i % 4 == 3)
            continue;
        double x = img->rgba[i], want = (1.0 - w) * a->rgba[i] + w * b->rgba[i];
        if (w < 0.0f)
            want = fabs(x - a->rgba[i]) < fabs(x - b->rgba[i]) ? a->rgba[i] : b->rgba[i];
        worst = fmax(worst, fabs(x - want));
        sum += x;
    }
    *mean = sum / (3.0 * RES * RES);
    return worst;
}

static void test_mix_blends(void)
{
    /* Light transport is linear in the light, not in the material: a path
     * that meets the floor twice (floor, wall, floor) weighs the mix twice.
     * With no bounce, and with one bounce from a floor whose materials
     * trace no specular rays (so no path meets it twice), the image is
     * the blend exactly. */
    RayesParam plastic[2] = {pf("Ks", 0.8f), pf("roughness", 0.05f)};
    RayesParam conductor[1] = {pf("roughness", 0.2f)};
    RayesParam matte[1] = {pf("Kd", 0.3f)};
    for (int bounces = 0; bounces < 2; bounces++) {
        const char *second = bounces ? "matte" : "conductor";
        RayesImage *a = render_with("plastic", plastic, 2, bounces);
        RayesImage *b = bounces ? render_with("matte", matte, 1, bounces)
                                : render_with("conductor", conductor, 1, bounces);
        RayesParam mix[6] = {ps("a", "plastic"), ps("b", second), pf("a:Ks", 0.8f),
                             pf("a:roughness", 0.05f),
                             bounces ? pf("b:Kd", 0.3f) : pf("b:roughness", 0.2f),
                             pf("amount", 0.3f)};
        RayesImage *m = render_with("mix", mix, 6, bounces);
        mix[5] = pp("amount", "cells");
        RayesImage *cells = render_with("mix", mix, 6, bounces);
        CHECK(a && b && m && cells);
        if (a && b && m && cells) {
            double mean, ma, mb;
            double wb = worst_blend(m, a, b, 0.3f, &mean);
            if (!(wb < 2e-4))
                fprintf(stderr, "  bounces %d: worst %g of mean %g\n", bounces, wb, mean);
            CHECK(wb < 2e-4);
            worst_blend(a, a, b, 0.0f, &ma);
            worst_blend(b, a, b, 1.0f, &mb);
            CHECK(fabs(ma - mb) > 0.01); /* the two materials differ */
            /* by cells: each pixel one material's (pixels on a cell's
             * edge blend their samples) */
            int whole = 0;
            for (int i = 0; i < RES * RES; i++) {
                int near_a = 1, near_b = 1;
                for (int c = 0; c < 3; c++) {
                    near_a &= fabsf(cells->rgba[4 * i + c] - a->rgba[4 * i + c]) < 2e-4f;
                    near_b &= fabsf(cells->rgba[4 * i + c] - b->rgba[4 * i + c]) < 2e-4f;
                }
                whole += near_a || near_b;
            }
            CHECK(whole > RES * RES / 2);
        }
        rayes_image_free(a);
        rayes_image_free(b);
        rayes_image_free(m);
        rayes_image_free(cells);
    }
    /* a mix within a mix: amount 1 is its second material alone */
    RayesImage *b = render_with("conductor", conductor, 1, 0);
    RayesParam nested[7] = {ps("a", "plastic"),    ps("b", "mix"),
                            ps("b:a", "matte"),    ps("b:b", "conductor"),
                            pf("b:amount", 1),     pf("b:b:roughness", 0.2f),
                            pf("amount", 1)};
    RayesImage *n = render_with("mix", nested, 7, 0);
    CHECK(b && n);
    if (b && n) {
        double mean;
        CHECK(worst_blend(n, b, b, 0.0f, &mean) < 1e-5);
    }
    rayes_image_free(b);
    rayes_image_free(n);
}

/* The object's flags and opacity come from its materials. */
static void test_mix_flags(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam glassy[3] = {ps("a", "matte"), ps("b", "stainedglass"), pf("amount", 0.5f)};
    RayesParam plain[2] = {ps("a", "matte"), ps("b", "plastic")};
    RayesParam sss[2] = {ps("a", "plastic"), ps("b", "subsurface")};
    CHECK(rayes_scene_set_shader(s, "mix", glassy, 3) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "mix", plain, 2) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "mix", sss, 2) == RAYES_OK);
    if (s->n_objects == 3) {
        CHECK(shade_instance_has_opacity(&s->objects[0].shader));
        CHECK(!shade_instance_has_opacity(&s->objects[1].shader));
        CHECK(shade_instance_flags(&s->objects[2].shader) & RAYES_SHADER_SUBSURFACE);
        CHECK(!(shade_instance_flags(&s->objects[1].shader) & RAYES_SHADER_SUBSURFACE));
        /* an edit of the mix's own parameter keeps its materials */
        RayesParam amount = pf("amount", 0.75f);
        CHECK(rayes_scene_edit_shader(s, 1, &amount, 1) == RAYES_OK);
        CHECK(s->objects[1].shader.n_children == 2);
        RayesParam child = pf("a:Kd", 0.5f), cls = ps("a", "conductor");
        CHECK(rayes_scene_edit_shader(s, 1, &child, 1) == RAYES_ERROR_INVALID_ARGUMENT);
        rayes_scene_clear_error(s);
        CHECK(rayes_scene_edit_shader(s, 1, &cls, 1) == RAYES_ERROR_INVALID_ARGUMENT);
        CHECK(strstr(rayes_scene_get_error(s), "materials") != NULL);
    }
    rayes_scene_release(s);
}

static void test_mix_errors(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam none[1] = {ps("a", "matte")};
    CHECK(rayes_scene_set_shader(s, "mix", none, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "string b") != NULL);
    rayes_scene_clear_error(s);
    RayesParam unknown[2] = {ps("a", "matte"), ps("b", "velvet")};
    CHECK(rayes_scene_set_shader(s, "mix", unknown, 2) != RAYES_OK);
    CHECK(strstr(rayes_scene_get_error(s), "velvet") != NULL);
    rayes_scene_clear_error(s);
    /* nine mixes deep: at each level "a" is matte and "b" the next mix */
    RayesParam deep[20];
    char names[20][32];
    size_t n = 0;
    for (int d = 0; d < 9; d++)
        for (int k = 0; k < 2; k++) {
            snprintf(names[n], sizeof names[n], "%.*s%c", 2 * d, "b:b:b:b:b:b:b:b:b:b:", 'a' + k);
            deep[n] = ps(names[n], k ? "mix" : "matte");
            n++;
        }
    CHECK(rayes_scene_set_shader(s, "mix", deep, n) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "deep") != NULL);
    CHECK(s->n_objects == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_mix_blends), TEST(test_mix_flags), TEST(test_mix_errors))
