/*
 * Bounded dicing through the scene (scene_prepare): a floor of 1 km
 * under the camera stays within a budget of grid vertices when one is
 * set, coarsened by one factor found by counting, the same on every
 * call; without a budget it needs more; the off-screen factor dices
 * what the camera does not see coarser; a dense mesh over the budget
 * stops coarsening once it cannot shrink, keeps its corners bit for bit,
 * and one too big for the memory left is refused with a message; a stop
 * flag stops it, and stitching.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

static RayesScene *floor_scene(void)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 1.7f, 0}, at[3] = {0, 1.0f, 4}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 45.0f) == RAYES_OK);
    const float P[4][3] = {{-500, 0, -500}, {500, 0, -500}, {-500, 0, 500}, {500, 0, 500}};
    CHECK(rayes_scene_bilinear_patch(s, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    return s;
}

static size_t prepare(RayesScene *s, const DiceOptions *o, float *coarsened)
{
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 256, 256, o, NULL, &gs, coarsened, NULL, 0) == 0);
    size_t n = gs.n_vertices;
    geom_gridset_fini(&gs);
    return n;
}

static void test_vertex_budget(void)
{
    RayesScene *s = floor_scene();
    float c = 0.0f;
    DiceOptions free = {0, 4.0f, 0};
    size_t unbounded = prepare(s, &free, &c);
    CHECK(c == 1.0f);
    CHECK(unbounded > 100000);
    DiceOptions tight = {0, 4.0f, 50000};
    size_t bounded = prepare(s, &tight, &c);
    CHECK(bounded <= 50000 && bounded > 10000);
    CHECK(c > 1.0f);
    float c2 = 0.0f;
    CHECK(prepare(s, &tight, &c2) == bounded && c2 == c); /* deterministic */
    rayes_scene_release(s);
}

static void test_offscreen_factor(void)
{
    RayesScene *s = floor_scene();
    DiceOptions one = {0, 1.0f, 0}, four = {0, 4.0f, 0}, sixteen = {0, 16.0f, 0};
    size_t n1 = prepare(s, &one, NULL), n4 = prepare(s, &four, NULL),
           n16 = prepare(s, &sixteen, NULL);
    CHECK(n4 < n1 / 4);
    CHECK(n16 < n4);
    rayes_scene_release(s);
}

/* Isotropic dicing (RenderMan's rasterorient 0) dices the floor seen at
 * a grazing angle as finely along the view as across it: more vertices
 * than raster-oriented dicing, with the off-screen part alike. */
static void test_isotropic(void)
{
    RayesScene *s = floor_scene();
    DiceOptions raster = {0, 4.0f, 0, 0}, iso = {0, 4.0f, 0, 1};
    size_t nr = prepare(s, &raster, NULL), ni = prepare(s, &iso, NULL);
    CHECK(ni > nr + nr / 4);
    rayes_scene_release(s);
}

/* A bumpy sheet of 2 n^2 triangles, each far below a pixel. */
static RayesScene *dense_mesh(int n, float **points)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, -50}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 30.0f) == RAYES_OK);
    int m = n + 1, *nv = malloc(2 * (size_t)n * n * sizeof *nv);
    int *idx = malloc(6 * (size_t)n * n * sizeof *idx);
    float *P = malloc(3 * (size_t)m * m * sizeof *P);
    CHECK(nv && idx && P);
    for (int j = 0; j < m; j++)
        for (int i = 0; i < m; i++) {
            float *p = &P[3 * (j * m + i)];
            p[0] = 0.37f * i / n - 0.2f, p[1] = 0.41f * j / n - 0.2f;
            p[2] = 0.01f * sinf(0.7f * i) * cosf(0.3f * j);
        }
    test_lattice_triangles(n, nv, idx);
    CHECK(rayes_scene_polygon_mesh(s, 2 * (size_t)n * n, nv, idx, (size_t)m * m, P) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    free(nv), free(idx);
    *points = P;
    return s;
}

/* Points by value (-0 is 0: a corner weighed by 1 and two 0s may
 * come out +0 where the point holds -0). */
static int cmp_points(const void *a, const void *b)
{
    const float *p = a, *q = b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

static void test_dense_mesh(void)
{
    const int n = 60; /* 7,200 triangles: 21,600 vertices at one micropolygon each */
    float *P;
    RayesScene *s = dense_mesh(n, &P);
    size_t m2 = (size_t)(n + 1) * (n + 1);
    qsort(P, m2, 3 * sizeof *P, cmp_points);
    DiceOptions tight = {0, 4.0f, 5000, 0, 0.0};
    GridSet gs;
    geom_gridset_init(&gs);
    float c = 0.0f;
    CHECK(scene_prepare(s, 256, 256, &tight, NULL, &gs, &c, NULL, 0) == 0);
    CHECK(gs.n_grids == 2 * (size_t)n * n && gs.n_vertices == 3 * gs.n_grids);
    /* three rounds: coarser rates did not shrink it, nor two steps of
     * sqrt(2) after (grid sizes come in steps), so no more were tried:
     * 1.05 sqrt(4.32) x 2 (eight rounds would have made edges
     * 1.05 sqrt(4.3) ^ 8 longer) */
    CHECK(c > 4.0f && c < 4.7f);
    size_t on_corner = 0; /* exact corners, and stitching moved none */
    for (size_t v = 0; v < gs.n_vertices; v++)
        on_corner += bsearch(&gs.P[v], P, m2, 3 * sizeof *P, cmp_points) != NULL;
    CHECK(on_corner == gs.n_vertices);
    geom_gridset_fini(&gs);
    /* refused: the grids would take more than the memory left */
    DiceOptions small = {0, 4.0f, 5000, 0, 1e6};
    char err[300] = "";
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 256, 256, &small, NULL, &gs, NULL, err, sizeof err) == -1);
    CHECK(strstr(err, "21600 grid vertices in 7200 grids") && strstr(err, "memory left"));
    geom_gridset_fini(&gs);
    free(P);
    rayes_scene_release(s);
}

/* A stop flag (a signal's, RayesRenderOptions.stop) stops dicing between
 * primitives: scene_prepare returns -2 with "render: cancelled" (and
 * rayes_render RAYES_ERROR_CANCELLED) where it prepared the whole scene
 * first (a farm's SIGTERM waited for it). */
static void test_stop_stops_dicing(void)
{
    RayesScene *s = floor_scene();
    volatile int stop = 1;
    DiceOptions o = {0, 4.0f, 0, .stop = &stop};
    GridSet gs;
    geom_gridset_init(&gs);
    char err[64] = "";
    CHECK(scene_prepare(s, 256, 256, &o, NULL, &gs, NULL, err, sizeof err) == -2);
    CHECK(gs.n_grids == 0);
    CHECK(strcmp(err, "render: cancelled") == 0);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
    /* stitching reads it between lines (the floor's 7,988 grids) */
    s = floor_scene();
    DiceOptions go = {0, 4.0f, 0, 0, 0.0};
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 512, 512, &go, NULL, &gs, NULL, NULL, 0) == 0);
    volatile int no = 0;
    CHECK(geom_stitch(&gs, s->prims, &no) == 0);
    CHECK(geom_stitch(&gs, s->prims, &stop) == -2);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_vertex_budget), TEST(test_offscreen_factor), TEST(test_isotropic),
          TEST(test_dense_mesh), TEST(test_stop_stops_dicing))
