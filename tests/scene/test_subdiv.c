/*
 * Subdivision surfaces (rayes_scene_subdivision_mesh, geom/subdiv.cpp):
 * the limit surface against closed forms. A regular interior face is the
 * uniform bicubic B-spline patch of its 16 control points; an infinitely
 * sharp crease is the cubic B-spline curve of its points; the limit of a
 * cube's corner is (1/2, 1/2, 1/2) of the cube of side 2 (one
 * Catmull-Clark step by hand, then the limit mask); neighbouring patches
 * agree along shared edges; an n-gon is n quad patches; holes make no
 * patch; vertex, facevarying, uniform and constant variables interpolate
 * as they should; bad input is refused with a message.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "geom/subdiv.h"
#include "scene/scene.h"
#include "test.h"

static void bspline(float t, float b[4])
{
    float s = 1.0f - t;
    b[0] = s * s * s / 6.0f;
    b[1] = (3.0f * t * t * t - 6.0f * t * t + 4.0f) / 6.0f;
    b[2] = (-3.0f * t * t * t + 3.0f * t * t + 3.0f * t + 1.0f) / 6.0f;
    b[3] = t * t * t / 6.0f;
}

/* A grid of nx x ny points (x = i, y = j, z = height(i, j)) and its
 * (nx - 1) x (ny - 1) quads, counter-clockwise, face (i, j) at
 * i + (nx - 1) j. */
typedef struct Grid2 {
    float P[64][3];
    int n_verts[49], idx[196];
    int nx, ny, n_faces;
} Grid2;

static float height(int i, int j)
{
    return 0.3f * sinf(1.7f * (float)i + 0.4f) + 0.2f * cosf(2.3f * (float)j - 0.2f * (float)i);
}

static void grid2(Grid2 *g, int nx, int ny)
{
    memset(g, 0, sizeof *g);
    g->nx = nx, g->ny = ny;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            float *p = g->P[j * nx + i];
            p[0] = (float)i, p[1] = (float)j, p[2] = height(i, j);
        }
    for (int j = 0; j + 1 < ny; j++)
        for (int i = 0; i + 1 < nx; i++) {
            int f = g->n_faces++, a = j * nx + i;
            g->n_verts[f] = 4;
            int q[4] = {a, a + 1, a + 1 + nx, a + nx};
            memcpy(&g->idx[4 * f], q, sizeof q);
        }
}

static RayesScene *scene(void)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, -10}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, at, up, 40.0f);
    return s;
}

/* The prim of s that is patch k of face f (the first, for quads). */
static const Prim *patch_of_face(const RayesScene *s, size_t face)
{
    for (size_t i = 0; i < s->n_prims; i++)
        if (s->prims[i].type == PRIM_SUBDIV &&
            geom_subdiv_patch_face(s->prims[i].subdiv.mesh, s->prims[i].subdiv.patch) == face)
            return &s->prims[i];
    return NULL;
}

static void test_regular_face_is_bspline(void)
{
    Grid2 g;
    grid2(&g, 4, 4); /* 3 x 3 faces: the middle one (4) is regular */
    RayesScene *s = scene();
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, (size_t)g.n_faces,
                                       g.n_verts, g.idx, 16, &g.P[0][0], NULL, NULL,
                                       0) == RAYES_OK);
    const Prim *p = patch_of_face(s, 4);
    CHECK(p != NULL);
    double worst = 0.0;
    for (int b = 0; p && b <= 8; b++)
        for (int a = 0; a <= 8; a++) {
            float u = (float)a / 8.0f, v = (float)b / 8.0f, bu[4], bv[4];
            bspline(u, bu);
            bspline(v, bv);
            float want[3] = {0, 0, 0};
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++)
                    for (int c = 0; c < 3; c++)
                        want[c] += bu[i] * bv[j] * g.P[j * 4 + i][c];
            Vec3 P, du, dv;
            geom_prim_eval(p, u, v, &P, &du, &dv);
            worst = fmax(worst, v3_length(v3_sub(P, v3(want[0], want[1], want[2]))));
        }
    CHECK(worst < 1e-5); /* measured: 4.8e-7 */
    rayes_scene_release(s);
}

static void test_sharp_crease_is_bspline_curve(void)
{
    Grid2 g;
    grid2(&g, 7, 3); /* 6 x 2 faces; the crease runs along row j = 1 */
    RayesScene *s = scene();
    int edges[12];
    float sharp[6];
    for (int i = 0; i < 6; i++) {
        edges[2 * i] = 7 + i, edges[2 * i + 1] = 8 + i;
        sharp[i] = RAYES_SUBDIV_INFINITELY_SHARP;
    }
    RayesSubdivTags t = {.interpolate_boundary = 1, .facevarying_boundary = 1,
                         .n_creases = 6, .crease_edges = edges, .crease_sharpness = sharp};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, (size_t)g.n_faces,
                                       g.n_verts, g.idx, 21, &g.P[0][0], &t, NULL, 0) == RAYES_OK);
    /* Face 2 (i = 2, j = 0): its edge v = 1 runs from point (2, 1) to (3, 1). */
    const Prim *p = patch_of_face(s, 2);
    CHECK(p != NULL);
    double worst = 0.0;
    for (int a = 0; p && a <= 8; a++) {
        float u = (float)a / 8.0f, b[4], want[3] = {0, 0, 0};
        bspline(u, b);
        for (int k = 0; k < 4; k++)
            for (int c = 0; c < 3; c++)
                want[c] += b[k] * g.P[7 + 1 + k][c];
        Vec3 P, du, dv;
        geom_prim_eval(p, u, 1.0f, &P, &du, &dv);
        worst = fmax(worst, v3_length(v3_sub(P, v3(want[0], want[1], want[2]))));
    }
    CHECK(worst < 1e-5);
    rayes_scene_release(s);
}

static const float cube_P[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                   {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
static const int cube_idx[24] = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4,
                                 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
static const int cube_nv[6] = {4, 4, 4, 4, 4, 4};

static void test_cube(void)
{
    RayesScene *s = scene();
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 6, cube_nv, cube_idx, 8,
                                       &cube_P[0][0], NULL, NULL, 0) == RAYES_OK);
    CHECK(s->n_prims == 6);
    /* Face 1 starts at point 4, (-1, -1, 1): its limit is -1/2 of it. */
    const Prim *p = patch_of_face(s, 1);
    Vec3 P, du, dv;
    geom_prim_eval(p, 0.0f, 0.0f, &P, &du, &dv);
    CHECK_NEAR(P.x, -0.5, 1e-5);
    CHECK_NEAR(P.y, -0.5, 1e-5);
    CHECK_NEAR(P.z, 0.5, 1e-5);
    /* The middle of a face: by symmetry on the axis, inside the cube. */
    geom_prim_eval(p, 0.5f, 0.5f, &P, &du, &dv);
    CHECK(fabsf(P.x) < 1e-5f && fabsf(P.y) < 1e-5f && P.z > 0.5f && P.z < 1.0f);
    /* Shared edges: face 1's edge u = 1 (points 5 -> 6) is face 3's
     * (1, 2, 6, 5) edge v = 1, from 5 at u = 0 to 6 at u = 1. */
    const Prim *q = patch_of_face(s, 3);
    double worst = 0.0;
    for (int a = 0; a <= 16; a++) {
        float t = (float)a / 16.0f;
        Vec3 A, B;
        geom_prim_eval(p, 1.0f, t, &A, &du, &dv);
        geom_prim_eval(q, t, 1.0f, &B, &du, &dv);
        worst = fmax(worst, v3_length(v3_sub(A, B)));
    }
    CHECK(worst < 1e-5);
    /* Normals face out (counter-clockwise seen from outside). */
    Vec3 n = geom_prim_normal(p, 0.5f, 0.5f);
    CHECK(n.z > 0.99f);
    rayes_scene_release(s);
}

/* How far q lies from patch p: Gauss-Newton on (u, v) from the nearest
 * of a 5 x 5 lattice, clamped to the patch. */
static double distance_to_patch(const Prim *p, Vec3 q)
{
    enum { L = 5 };
    double u = 0.0, v = 0.0, best = INFINITY;
    Vec3 P, du, dv;
    for (int a = 0; a < L * L; a++) {
        float su = (float)(a % L) / (L - 1), sv = (float)(a / L) / (L - 1);
        geom_prim_eval(p, su, sv, &P, &du, &dv);
        double d = v3_length(v3_sub(P, q));
        if (d < best)
            best = d, u = su, v = sv;
    }
    for (int it = 0; it < 30; it++) {
        geom_prim_eval(p, (float)u, (float)v, &P, &du, &dv);
        Vec3 r = v3_sub(q, P);
        double a = v3_dot(du, du), b = v3_dot(du, dv), c = v3_dot(dv, dv);
        double ru = v3_dot(du, r), rv = v3_dot(dv, r), det = a * c - b * b;
        if (det <= 0.0)
            break;
        u = fmin(fmax(u + (c * ru - b * rv) / det, 0.0), 1.0);
        v = fmin(fmax(v + (a * rv - b * ru) / det, 0.0), 1.0);
    }
    geom_prim_eval(p, (float)u, (float)v, &P, &du, &dv);
    return v3_length(v3_sub(P, q));
}

/* How far q lies from the limit surface of s's patches. */
static double distance_to_limit(const RayesScene *s, Vec3 q)
{
    double d = INFINITY;
    for (size_t i = 0; i < s->n_prims; i++)
        d = fmin(d, distance_to_patch(&s->prims[i], q));
    return d;
}

/* The cube's limit surface (Bfr, as rayes dices it) against OpenSubdiv's
 * uniform refinement (Far): the limit positions of the 24,578 vertices
 * of level 6 lie on it within 1e-6 on a cube of side 2 (measured:
 * 3.8e-7, float rounding; 5.1e-4 near the corners with Bfr's default
 * approximation level of 2, subdiv.cpp), and the refined vertices
 * themselves of level 8 lie within 1.1e-5 of it (the refinement's own
 * distance from its limit; every 61st vertex). */
static void test_cube_against_uniform_refinement(void)
{
    RayesScene *s = scene();
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 6, cube_nv, cube_idx, 8,
                                       &cube_P[0][0], NULL, NULL, 0) == RAYES_OK);
    SubdivDesc d = {.scheme = SUBDIV_CATMULL_CLARK, .n_faces = 6, .n_verts = cube_nv,
                    .indices = cube_idx, .n_points = 8, .P = &cube_P[0][0],
                    .interpolate_boundary = 1};
    for (int pass = 0; pass < 2; pass++) {
        int level = pass ? 8 : 6, limit = !pass;
        size_t n = 0;
        float *P = geom_subdiv_refine_uniform(&d, level, limit, &n);
        CHECK(P && n == (size_t)6 * (1u << (2 * level)) + 2);
        double worst = 0.0;
        size_t step = pass ? 61 : 1; /* level 8: every 61st of 393,218 */
        for (size_t i = 0; P && i < n; i += step)
            worst = fmax(worst, distance_to_limit(s, v3(P[3 * i], P[3 * i + 1], P[3 * i + 2])));
        printf("level %d %s: largest distance to the limit surface %.3g\n", level,
               limit ? "limit points" : "vertices", worst);
        CHECK(worst < (limit ? 1e-6 : 1e-4));
        free(P);
    }
    rayes_scene_release(s);
}

/* A pentagon and a triangle (Catmull-Clark): one quad patch per corner;
 * each sub-patch's corner (0, 0) lies near its face's corner, and (1, 1)
 * at the face's centre, where all the sub-patches meet. */
static void test_ngon_patches(void)
{
    RayesScene *s = scene();
    const float P[6][3] = {{0, 0, 0}, {2, 0, 0}, {3, 1.5f, 0}, {1, 3, 0}, {-1, 1.5f, 0},
                           {1, -2, 0}};
    const int nv[2] = {5, 3}, idx[8] = {0, 1, 2, 3, 4, 0, 5, 1};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 2, nv, idx, 6, &P[0][0],
                                       NULL, NULL, 0) == RAYES_OK);
    CHECK(s->n_prims == 8);
    Vec3 centre, X, du, dv;
    geom_prim_eval(&s->prims[0], 1.0f, 1.0f, &centre, &du, &dv);
    for (int k = 1; k < 5; k++) {
        geom_prim_eval(&s->prims[k], 1.0f, 1.0f, &X, &du, &dv);
        CHECK(v3_length(v3_sub(X, centre)) < 1e-5f);
    }
    CHECK(fabsf(centre.z) < 1e-6f); /* a planar mesh stays in its plane */
    rayes_scene_release(s);
}

static void test_holes_and_boundaries(void)
{
    Grid2 g;
    grid2(&g, 4, 4);
    RayesScene *s = scene();
    const int hole[1] = {4};
    RayesSubdivTags t = {.interpolate_boundary = 1, .n_holes = 1, .hole_faces = hole};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 9, g.n_verts, g.idx, 16,
                                       &g.P[0][0], &t, NULL, 0) == RAYES_OK);
    CHECK(s->n_prims == 8 && patch_of_face(s, 4) == NULL);
    rayes_scene_release(s);
    /* interpolateboundary 0: boundary faces have no limit surface; the
     * one interior face is left. */
    s = scene();
    RayesSubdivTags none = {.interpolate_boundary = 0, .facevarying_boundary = 1};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 9, g.n_verts, g.idx, 16,
                                       &g.P[0][0], &none, NULL, 0) == RAYES_OK);
    CHECK(s->n_prims == 1 && patch_of_face(s, 4) != NULL);
    rayes_scene_release(s);
}

/* Vertex Cs = an affine function of P stays that function on the limit
 * surface (subdivision is affine invariant); facevarying st = (x, y) of
 * a flat grid is (x, y) of the limit point; uniform Cs is the face's. */
static void test_primvars(void)
{
    Grid2 g;
    grid2(&g, 4, 4);
    RayesScene *s = scene();
    float Cs[16][3], st[36][2], U[9][3];
    for (int k = 0; k < 16; k++)
        for (int c = 0; c < 3; c++)
            Cs[k][c] = 0.1f * g.P[k][0] - 0.2f * g.P[k][1] + 0.3f * g.P[k][2] + (float)c;
    RayesPrimvar pv[2] = {{"Cs", RAYES_PRIMVAR_VERTEX, &Cs[0][0], 16},
                          {"st", RAYES_PRIMVAR_FACEVARYING, &st[0][0], 36}};
    for (int k = 0; k < 36; k++) {
        st[k][0] = g.P[g.idx[k]][0];
        st[k][1] = g.P[g.idx[k]][1];
    }
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 9, g.n_verts, g.idx, 16,
                                       &g.P[0][0], NULL, pv, 2) == RAYES_OK);
    const Prim *p = patch_of_face(s, 4);
    CHECK(p && p->pv == (GEOM_PV_CS | GEOM_PV_ST));
    for (int a = 0; p && a <= 4; a++) {
        float u = (float)a / 4.0f, v = 1.0f - u;
        Vec3 P, du, dv;
        geom_prim_eval(p, u, v, &P, &du, &dv);
        PrimvarSample ps;
        geom_prim_primvars(p, s->pv, u, v, &ps);
        CHECK_NEAR(ps.Cs.y, 0.1f * P.x - 0.2f * P.y + 0.3f * P.z + 1.0f, 1e-4);
        CHECK_NEAR(ps.st[0], P.x, 1e-4);
        CHECK_NEAR(ps.st[1], P.y, 1e-4);
        CHECK_NEAR(ps.dst[0], du.x, 1e-3); /* ds/du = dx/du */
    }
    rayes_scene_release(s);
    s = scene();
    for (int f = 0; f < 9; f++)
        U[f][0] = (float)f, U[f][1] = U[f][2] = 0.5f;
    RayesPrimvar upv = {"Cs", RAYES_PRIMVAR_UNIFORM, &U[0][0], 9};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 9, g.n_verts, g.idx, 16,
                                       &g.P[0][0], NULL, &upv, 1) == RAYES_OK);
    PrimvarSample ps;
    geom_prim_primvars(patch_of_face(s, 7), s->pv, 0.3f, 0.6f, &ps);
    CHECK_NEAR(ps.Cs.x, 7.0, 1e-6);
    rayes_scene_release(s);
}

static void test_loop_and_bad_input(void)
{
    RayesScene *s = scene();
    /* An octahedron under Loop: 8 triangular patches, the limit inside. */
    const float P[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const int nv[8] = {3, 3, 3, 3, 3, 3, 3, 3};
    const int idx[24] = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_LOOP, 8, nv, idx, 6, &P[0][0], NULL, NULL,
                                       0) == RAYES_OK);
    CHECK(s->n_prims == 8 && s->prims[0].subdiv.triangular);
    Vec3 X, du, dv;
    geom_prim_eval(&s->prims[0], 1.0f / 3.0f, 1.0f / 3.0f, &X, &du, &dv);
    CHECK(v3_length(X) > 0.3f && v3_length(X) < 1.0f);
    CHECK(v3_dot(geom_prim_normal(&s->prims[0], 0.3f, 0.3f), X) > 0.0f); /* outward */
    /* A quad under Loop, a bad index, a negative sharpness. */
    const int quad_nv[1] = {4}, quad[4] = {0, 1, 2, 3};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_LOOP, 1, quad_nv, quad, 6, &P[0][0], NULL,
                                       NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "Loop takes triangles") != NULL);
    rayes_scene_clear_error(s);
    const int bad[4] = {0, 1, 2, 9};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 1, quad_nv, bad, 6,
                                       &P[0][0], NULL, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "uses vertex 9") != NULL);
    rayes_scene_clear_error(s);
    const int e[2] = {0, 1};
    const float neg[1] = {-1};
    RayesSubdivTags t = {.interpolate_boundary = 1, .n_creases = 1, .crease_edges = e,
                         .crease_sharpness = neg};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 1, quad_nv, quad, 6,
                                       &P[0][0], &t, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "negative") != NULL);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_regular_face_is_bspline), TEST(test_sharp_crease_is_bspline_curve),
          TEST(test_cube), TEST(test_cube_against_uniform_refinement), TEST(test_ngon_patches), TEST(test_holes_and_boundaries),
          TEST(test_primvars), TEST(test_loop_and_bad_input))
