/*
 * Constructive solid geometry (rayes_scene_solid_begin, DESIGN.md
 * "Solids"): two spheres, a big one (radius 1 at the origin) and a small
 * one (radius 0.5 at x = 1), combined by union, intersection and
 * difference; rays along the x axis meet the surface of the result where
 * geometry says, from either side, and a chord wholly inside the
 * subtracted sphere is neither hit nor occluded. Also: the tree of a RIB
 * file's SolidBegin blocks, errors, and the RIB writer's blocks read back.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "accel/accel.h"
#include "geom/geom.h"
#include "io/rib.h"
#include "io/rib_round_trip.h"
#include "io/sink.h"
#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

static void sphere_at(RayesScene *s, float x, float r)
{
    const float m[16] = {1, 0, 0, x, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    CHECK(rayes_scene_sphere(s, r) == RAYES_OK);
}

/* The two spheres under op, or as plain geometry when op < 0. */
static RayesScene *two_spheres(int op)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, -6}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, at, up, 40.0f);
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    if (op >= 0)
        CHECK(rayes_scene_solid_begin(s, (RayesSolidOp)op) == RAYES_OK);
    for (int k = 0; k < 2; k++) {
        if (op >= 0)
            CHECK(rayes_scene_solid_begin(s, RAYES_SOLID_PRIMITIVE) == RAYES_OK);
        sphere_at(s, k ? 1.0f : 0.0f, k ? 0.5f : 1.0f);
        if (op >= 0)
            CHECK(rayes_scene_solid_end(s) == RAYES_OK);
    }
    if (op >= 0)
        CHECK(rayes_scene_solid_end(s) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

typedef struct Traced {
    GridSet gs;
    Accel *a;
} Traced;

static void trace_init(Traced *t, const RayesScene *s)
{
    geom_gridset_init(&t->gs);
    CHECK(scene_prepare(s, 256, 256, NULL, NULL, &t->gs, NULL, NULL, 0) == 0);
    uint32_t mask = RAYES_RAY_CAMERA | RAYES_RAY_SHADOW;
    char err[256];
    t->a = accel_new(&t->gs, &mask, 1, NULL, err, sizeof err);
    CHECK(t->a != NULL);
}

static void trace_fini(Traced *t)
{
    accel_free(t->a);
    geom_gridset_fini(&t->gs);
}

/* The distance to the first hit along the ray from o in direction d, or
 * -1; *entering: the hit faces the ray. */
static float first_hit(const Traced *t, Vec3 o, Vec3 d, int *entering)
{
    Ray r = {o, d, 0.0f, 1e30f, RAYES_RAY_CAMERA, 0.0f};
    Hit h;
    if (!t->a || !accel_intersect(t->a, &r, &h))
        return -1.0f;
    if (entering)
        *entering = v3_dot(h.Ng, d) < 0.0f;
    return h.t;
}

static int occluded(const Traced *t, Vec3 o, Vec3 d, float tfar)
{
    Ray r = {o, d, 0.0f, tfar, RAYES_RAY_SHADOW, 0.0f};
    return t->a && accel_occluded(t->a, &r);
}

static const Vec3 from_left = {-5, 0, 0}, from_right = {5, 0, 0};
static const Vec3 plus_x = {1, 0, 0}, minus_x = {-1, 0, 0};
/* Spheres are diced: surfaces within a few thousandths of their radius. */
#define TOL 0.01

static void test_union(void)
{
    RayesScene *s = two_spheres(RAYES_SOLID_UNION);
    Traced t;
    trace_init(&t, s);
    int in = 0;
    CHECK_NEAR(first_hit(&t, from_left, plus_x, &in), 4.0, TOL); /* x = -1 */
    CHECK(in);
    CHECK_NEAR(first_hit(&t, from_right, minus_x, &in), 3.5, TOL); /* the small one, x = 1.5 */
    /* From inside the union the next surface is its outside: the big
     * sphere's inside face at x = 0.5..1 is not a surface of the union. */
    CHECK_NEAR(first_hit(&t, v3(0.2f, 0, 0), plus_x, &in), 1.3, TOL); /* x = 1.5 */
    CHECK(!in);
    trace_fini(&t);
    rayes_scene_release(s);
}

static void test_intersection(void)
{
    RayesScene *s = two_spheres(RAYES_SOLID_INTERSECTION);
    Traced t;
    trace_init(&t, s);
    int in = 0;
    /* The lens between x = 0.5 and 1. */
    CHECK_NEAR(first_hit(&t, from_left, plus_x, &in), 5.5, TOL);
    CHECK(in);
    CHECK_NEAR(first_hit(&t, from_right, minus_x, &in), 4.0, TOL);
    CHECK(in);
    /* Off the lens (y = 0.6 passes the big sphere, not the small one). */
    CHECK(first_hit(&t, v3(-5, 0.6f, 0), plus_x, NULL) < 0.0f);
    trace_fini(&t);
    rayes_scene_release(s);
}

static void test_difference(void)
{
    RayesScene *s = two_spheres(RAYES_SOLID_DIFFERENCE);
    Traced t;
    trace_init(&t, s);
    int in = 1;
    CHECK_NEAR(first_hit(&t, from_left, plus_x, &in), 4.0, TOL); /* the big sphere */
    CHECK(in);
    /* From the right: the small sphere's surface at x = 0.5, met from its
     * inside (the hole's wall). */
    CHECK_NEAR(first_hit(&t, from_right, minus_x, &in), 4.5, TOL);
    CHECK(!in);
    /* The chord x = 0.9 lies inside the small sphere wherever it is inside
     * the big one: nothing there, and nothing to stop a shadow ray. */
    Vec3 o = v3(0.9f, -5, 0), up = v3(0, 1, 0);
    CHECK(first_hit(&t, o, up, NULL) < 0.0f);
    CHECK(!occluded(&t, o, up, 10.0f));
    /* x = 0.3: through the big sphere, outside the small one. */
    CHECK(occluded(&t, v3(0.3f, -5, 0), up, 10.0f));
    trace_fini(&t);
    /* Without solids the same chord hits the big sphere. */
    RayesScene *plain = two_spheres(-1);
    trace_init(&t, plain);
    CHECK(first_hit(&t, o, up, NULL) > 0.0f && occluded(&t, o, up, 10.0f));
    trace_fini(&t);
    rayes_scene_release(plain);
    rayes_scene_release(s);
}

static void test_api_errors(void)
{
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_solid_end(s) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_solid_begin(s, (RayesSolidOp)7) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(rayes_scene_solid_begin(s, RAYES_SOLID_PRIMITIVE) == RAYES_OK);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_solid_begin(s, RAYES_SOLID_UNION) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "inside a primitive") != NULL);
    rayes_scene_release(s);
}

static char err[1024];

static RayesScene *read_rib(const char *text, RayesError *e)
{
    return rib_read_scene(text, e, err, sizeof err);
}

static const char *const rib_text =
    "WorldBegin\n"
    "SolidBegin \"difference\"\n"
    "  SolidBegin \"primitive\" Sphere 1 -1 1 360 SolidEnd\n"
    "  Translate 1 0 0\n"
    "  SolidBegin \"union\"\n"
    "    SolidBegin \"primitive\" Sphere 0.5 -0.5 0.5 360 SolidEnd\n"
    "    SolidBegin \"primitive\" Translate 0 1 0 Sphere 0.25 -0.25 0.25 360 SolidEnd\n"
    "  SolidEnd\n"
    "SolidEnd\n"
    "Sphere 0.1 -0.1 0.1 360\n" /* after the blocks: the transform they saved */
    "WorldEnd\n";

static void test_rib(void)
{
    RayesError e;
    RayesScene *s = read_rib(rib_text, &e);
    CHECK(e == RAYES_OK);
    CHECK(s->n_solids == 5 && s->open_solid == -1 && s->n_prims == 4);
    if (s->n_solids == 5 && s->n_prims == 4) {
        const GeomSolid *g = s->solids;
        CHECK(g[0].op == GEOM_SOLID_DIFFERENCE && g[0].parent == 0 && g[0].end == 5);
        CHECK(g[1].op == GEOM_SOLID_PRIMITIVE && g[1].parent == 1 && g[1].end == 2);
        CHECK(g[2].op == GEOM_SOLID_UNION && g[2].parent == 1 && g[2].end == 5);
        CHECK(g[4].op == GEOM_SOLID_PRIMITIVE && g[4].parent == 3);
        CHECK(s->prims[0].solid == 2 && s->prims[1].solid == 4 && s->prims[2].solid == 5);
        CHECK(s->prims[3].solid == 0);
        /* SolidBegin saves the transform: the last sphere is at the origin. */
        CHECK(fabsf(s->prims[3].big->quadric.world_from_object.m[0][3]) < 1e-6f);
        CHECK(fabsf(s->prims[2].big->quadric.world_from_object.m[1][3] - 1.0f) < 1e-6f);
    }
    rayes_scene_release(s);
    s = read_rib("WorldBegin\nSolidBegin \"xor\"\nSolidEnd\nWorldEnd\n", &e);
    CHECK(e != RAYES_OK && strstr(err, "t.rib:2") && strstr(err, "xor"));
    rayes_scene_release(s);
    /* A solid in a primitive solid: left out of the tree (a warning). */
    s = read_rib("WorldBegin\nSolidBegin \"primitive\"\nSolidBegin \"union\"\n"
                 "Sphere 1 -1 1 360\nSolidEnd\nSolidEnd\nWorldEnd\n",
                 &e);
    CHECK(e == RAYES_OK && s->n_solids == 1 && s->n_prims == 1 && s->prims[0].solid == 1);
    rayes_scene_release(s);
}

static void test_write_back(void)
{
    char *buf = rib_round_trip(rib_text, err, sizeof err);
    CHECK(buf && strstr(buf, "SolidBegin \"difference\"") && strstr(buf, "SolidEnd"));
    RayesError e;
    RayesScene *a = read_rib(rib_text, &e), *b = read_rib(buf ? buf : "", &e);
    CHECK(e == RAYES_OK && a->n_solids == b->n_solids && a->n_prims == b->n_prims);
    for (size_t k = 0; k < a->n_solids && k < b->n_solids; k++)
        CHECK(memcmp(&a->solids[k], &b->solids[k], sizeof a->solids[k]) == 0);
    for (size_t k = 0; k < a->n_prims && k < b->n_prims; k++)
        CHECK(a->prims[k].solid == b->prims[k].solid);
    rayes_scene_release(a);
    rayes_scene_release(b);
    free(buf);
}

TEST_MAIN(TEST(test_union), TEST(test_intersection), TEST(test_difference), TEST(test_api_errors),
          TEST(test_rib), TEST(test_write_back))
