/*
 * Where geometry may lie: a projective transform (which sends points
 * through infinity) and geometry beyond 1e18 from the origin (where
 * squared distances overflow a float: Embree asserted on the rays of a
 * quad 1e20 wide and dicing one 1e24 wide ran out of memory) are refused
 * with a message, for every kind of primitive; an affine matrix with a
 * homogeneous scale, and geometry just inside the limit, are kept.
 */
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

/* Nonzero if the scene's error message contains what; clears it. */
static int said(RayesScene *s, const char *what)
{
    int found = strstr(rayes_scene_get_error(s), what) != NULL;
    rayes_scene_clear_error(s);
    return found;
}

static void test_projective_transforms_are_refused(void)
{
    RayesScene *s = rayes_scene_new();
    /* a RIB matrix's translation written in the last column: row-major,
     * it lands in the perspective row */
    const float projective[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 3, 2, 1, 1};
    CHECK(rayes_scene_set_transform(s, projective) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "transform: expected an affine matrix"));
    const float motion[2][16] = {{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1},
                                 {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0.5f, 1}};
    const float times[2] = {0, 1};
    CHECK(rayes_scene_set_transform_motion(s, 2, times, motion) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "transform motion: expected an affine matrix"));

    /* an exporter's noise in the perspective row (Maya's MTOR wrote
     * -4.8e-9 -6.8e-18 -5.0e-9 1 in a camera transform) is affine, the
     * noise dropped */
    const float noisy[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -4.8e-9f, -6.8e-18f, -5.0e-9f, 1};
    CHECK(rayes_scene_set_transform(s, noisy) == RAYES_OK);
    CHECK(s->world_from_object.m[3][0] == 0.0f && s->world_from_object.m[3][2] == 0.0f);
    /* w = 2 everywhere: a uniform scale by 1/2, as RenderMan reads it */
    const float halve[16] = {1, 0, 0, 4, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 2};
    CHECK(rayes_scene_set_transform(s, halve) == RAYES_OK);
    const float P[4][3] = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {2, 2, 0}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(s->n_prims == 1);
    CHECK_NEAR(s->prims[0].cp[3].x, 3.0, 1e-6); /* (2 + 4) / 2 */
    CHECK_NEAR(s->prims[0].cp[3].y, 1.0, 1e-6);
    rayes_scene_release(s);
}

static void test_far_geometry_is_refused(void)
{
    RayesScene *s = rayes_scene_new();
    const float near_limit = 9e17f, far = 1e20f;
    const float ok[4][3] = {{-near_limit, -1, 1}, {near_limit, -1, 1}, {-1, 1, 1}, {1, 1, 1}};
    CHECK(rayes_scene_bilinear_patch(s, ok) == RAYES_OK);
    const float wide[4][3] = {{-far, -1, 1}, {far, -1, 1}, {-1, 1, 1}, {1, 1, 1}};
    CHECK(rayes_scene_bilinear_patch(s, wide) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "beyond 1e18"));

    const int nv[1] = {3}, ix[3] = {0, 1, 2};
    const float tri[9] = {0, 0, 1, far, 0, 1, 0, 1, 1};
    CHECK(rayes_scene_polygon_mesh(s, 1, nv, ix, 3, tri) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "beyond 1e18"));

    const int quad_n[1] = {4}, quad_ix[4] = {0, 1, 2, 3};
    const float quad[12] = {-1, -1, 1, far, -1, 1, 1, 1, 1, -1, 1, 1};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 1, quad_n, quad_ix, 4, quad,
                                       NULL, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "subdivision mesh: geometry reaches beyond 1e18"));

    const float sphere[4] = {far, -far, far, 360};
    CHECK(rayes_scene_quadric(s, RAYES_QUADRIC_SPHERE, sphere, 4, 0) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "beyond 1e18"));
    const float cylinder[4] = {far, 0, 1, 360};
    CHECK(rayes_scene_quadric(s, RAYES_QUADRIC_CYLINDER, cylinder, 4, 0) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "beyond 1e18"));

    /* a transform that carries small geometry far */
    const float away[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1e19f, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, away) == RAYES_OK);
    const float small[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    CHECK(rayes_scene_bilinear_patch(s, small) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "beyond 1e18"));
    const float white[3] = {1, 1, 1};
    CHECK(rayes_scene_area_light(s, small, white) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(said(s, "area light: geometry reaches beyond 1e18"));
    CHECK(s->n_prims == 1 && s->n_lights == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_projective_transforms_are_refused), TEST(test_far_geometry_is_refused))
