/*
 * Watertight dicing (geom/stitch.c, DESIGN.md "Stitching"): neighbouring
 * patches diced at different rates must not crack. Closed surfaces (a
 * perturbed Catmull-Clark mesh of 96 faces, the same mesh as bilinear
 * quads, a Catmull-Clark mesh of triangles and quads, a perturbed
 * icosahedron as a Loop mesh and as a polygon mesh of triangles, and the
 * triangles-and-quads mesh as a displaced polygon mesh) hold a marker
 * sphere; camera rays through
 * every pixel of a 512 x 512 image (four per pixel) must all enter the
 * surface from outside: a ray that reaches the marker or first meets the
 * surface from inside leaked through a crack. Also: rays through a
 * subdivision mesh's hole miss, and rays beside it hit.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "accel/accel.h"
#include "geom/geom.h"
#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

#define SIDE 4                      /* quads per side of each cube face */
#define N_FACES (6 * SIDE * SIDE)   /* 96 */
#define IMAGE 512

/* A cube of side 2 cut into SIDE x SIDE quads per face, its points moved
 * by a fixed pseudo-random amount, faces counter-clockwise from outside. */
typedef struct Mesh {
    float P[(SIDE + 1) * (SIDE + 1) * (SIDE + 1)][3];
    int n_points, n_verts[N_FACES], idx[4 * N_FACES];
} Mesh;

static float jitter(int i, int j, int k, int axis)
{
    unsigned h = (unsigned)(i * 73856093) ^ (unsigned)(j * 19349663) ^ (unsigned)(k * 83492791) ^
                 (unsigned)(axis * 2654435761u);
    h ^= h >> 13, h *= 0x5bd1e995u, h ^= h >> 15;
    return 0.12f * ((float)(h & 0xffff) / 65535.0f - 0.5f);
}

static void cube_mesh(Mesh *m)
{
    static int at[SIDE + 1][SIDE + 1][SIDE + 1];
    memset(m, 0, sizeof *m);
    for (int i = 0; i <= SIDE; i++)
        for (int j = 0; j <= SIDE; j++)
            for (int k = 0; k <= SIDE; k++) {
                at[i][j][k] = -1;
                if (i % SIDE && j % SIDE && k % SIDE)
                    continue; /* inside */
                int c[3] = {i, j, k};
                float *p = m->P[at[i][j][k] = m->n_points++];
                for (int a = 0; a < 3; a++)
                    p[a] = 2.0f * (float)c[a] / SIDE - 1.0f + jitter(i, j, k, a);
            }
    int f = 0;
    for (int a = 0; a < 3; a++)
        for (int side = 0; side <= SIDE; side += SIDE)
            for (int s = 0; s < SIDE; s++)
                for (int t = 0; t < SIDE; t++) {
                    int b = (a + 1) % 3, c = (a + 2) % 3, q[4][3];
                    for (int v = 0; v < 4; v++) {
                        q[v][a] = side;
                        q[v][b] = s + (v == 1 || v == 2);
                        q[v][c] = t + (v >= 2);
                    }
                    m->n_verts[f] = 4;
                    for (int v = 0; v < 4; v++) {
                        int w = side ? v : 3 - v; /* e_b x e_c = e_a: outward on the far side */
                        m->idx[4 * f + v] = at[q[w][0]][q[w][1]][q[w][2]];
                    }
                    f++;
                }
}

static const float eye[3] = {2.6f, 3.1f, -5.3f};

static RayesScene *scene_with_marker(void)
{
    RayesScene *s = rayes_scene_new();
    const float at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, eye, at, up, 34.0f);
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK); /* object 0 */
    /* Micropolygons of 4 x 4 pixels: chords far enough inside the limit
     * surface that unstitched neighbours leak (14 rays here without). */
    CHECK(rayes_scene_set_shading_rate(s, 16.0f) == RAYES_OK);
    return s;
}

static void add_marker(RayesScene *s)
{
    RayesParam red = {"Cs", RAYES_PARAM_COLOR, {1, 0, 0}, NULL};
    CHECK(rayes_scene_set_shader(s, "constant", &red, 1) == RAYES_OK); /* object 1 */
    CHECK(rayes_scene_sphere(s, 0.4f) == RAYES_OK);
}

/* Camera rays (n per pixel side) through an IMAGE x IMAGE view of the
 * scene's camera that leak: reach object 1, or first meet a surface from
 * behind (a closed surface seen from outside is entered first; a ray
 * grazing the silhouette may meet the edge of a micropolygon turned a
 * hair away, which is no leak). */
static size_t last_fans; /* the last leaks() scene's needle fans (dice.c dice_fan) */

static long leaks(const RayesScene *s, int n)
{
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, IMAGE, IMAGE, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    uint32_t masks[2] = {RAYES_RAY_CAMERA, RAYES_RAY_CAMERA};
    char err[256];
    Accel *a = accel_new(&gs, masks, 2, NULL, err, sizeof err);
    CHECK(a != NULL);
    const SceneCamera *c = &s->camera;
    long leaked = 0;
    last_fans = 0;
    for (size_t g = 0; g < gs.n_grids; g++)
        last_fans += gs.grids[g].sub && gs.subs[gs.grids[g].sub - 1].corner >= GEOM_FAN;
    for (int y = 0; a && y < IMAGE * n; y++)
        for (int x = 0; x < IMAGE * n; x++) {
            float sx = 2.0f * ((float)x + 0.5f) / (float)(IMAGE * n) - 1.0f;
            float sy = 1.0f - 2.0f * ((float)y + 0.5f) / (float)(IMAGE * n);
            Vec3 d = v3_add(c->z, v3_add(v3_scale(c->x, sx * c->tan_half_fov),
                                          v3_scale(c->y, sy * c->tan_half_fov)));
            Ray r = {c->eye, d, 0.0f, 1e30f, RAYES_RAY_CAMERA};
            Hit h;
            if (accel_intersect(a, &r, &h) &&
                (gs.grids[h.grid].object == 1 || v3_dot(h.Ng, v3_normalize(d)) > 0.02f))
                leaked++;
        }
    accel_free(a);
    geom_gridset_fini(&gs);
    return leaked;
}

static void test_subdivision_mesh_is_watertight(void)
{
    Mesh m;
    cube_mesh(&m);
    RayesScene *s = scene_with_marker();
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, N_FACES, m.n_verts, m.idx,
                                       (size_t)m.n_points, &m.P[0][0], NULL, NULL, 0) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("subdivision mesh: %ld leaked rays of %d\n", n, 4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

static void test_polygon_mesh_is_watertight(void)
{
    Mesh m;
    cube_mesh(&m);
    RayesScene *s = scene_with_marker();
    CHECK(rayes_scene_polygon_mesh(s, N_FACES, m.n_verts, m.idx, (size_t)m.n_points,
                                   &m.P[0][0]) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("polygon mesh: %ld leaked rays of %d\n", n, 4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

enum { BARREL = 5 }; /* quads around the middle */

/* The barrel: a ring of BARREL quads closed by two fans of triangles;
 * returns the faces. */
static int barrel(float P[2 * BARREL + 2][3], int nv[3 * BARREL], int idx[10 * BARREL])
{
    enum { N = BARREL };
    int f = 0, k = 0;
    for (int i = 0; i < N; i++)
        for (int top = 0; top < 2; top++) {
            float a = 6.2831853f * (float)i / N;
            P[2 * i + top][0] = 1.1f * cosf(a) + jitter(i, top, 0, 0);
            P[2 * i + top][1] = top ? 0.9f : -0.9f;
            P[2 * i + top][2] = 1.1f * sinf(a) + jitter(i, top, 0, 2);
        }
    float apex[2][3] = {{0, -1.6f, 0}, {0, 1.6f, 0}};
    memcpy(P[2 * N], apex, sizeof apex);
    for (int i = 0; i < N; i++) {
        int j = (i + 1) % N;
        int side[4] = {2 * i, 2 * i + 1, 2 * j + 1, 2 * j}; /* a quad around the middle */
        nv[f++] = 4;
        memcpy(&idx[k], side, sizeof side), k += 4;
        int bottom[3] = {2 * N, 2 * i, 2 * j}, top[3] = {2 * N + 1, 2 * j + 1, 2 * i + 1};
        nv[f++] = 3;
        memcpy(&idx[k], bottom, sizeof bottom), k += 3;
        nv[f++] = 3;
        memcpy(&idx[k], top, sizeof top), k += 3;
    }
    return f;
}

/* A closed Catmull-Clark mesh of triangles (two fans of five) and quads
 * (a ring): each triangle is three sub-face patches, whose sides meet
 * inside the face and along half edges of the mesh (10 leaked rays
 * without stitching). */
static void test_ngon_mesh_is_watertight(void)
{
    float P[2 * BARREL + 2][3];
    int nv[3 * BARREL], idx[10 * BARREL], f = barrel(P, nv, idx);
    RayesScene *s = scene_with_marker();
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, (size_t)f, nv, idx,
                                       2 * BARREL + 2, &P[0][0], NULL, NULL, 0) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("n-gon mesh: %ld leaked rays of %d\n", n, 4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

/* A perturbed icosahedron, its 20 faces (3 corners each, in nv)
 * counter-clockwise from outside,
 * scaled to hold the marker: a closed mesh of triangles only. */
static void icosahedron(float P[12][3], int idx[60], int nv[20])
{
    for (int f = 0; f < 20; f++)
        nv[f] = 3;
    static const int faces[20][3] = {
        {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},  {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    const float g = 1.6180340f;
    const float v[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                            {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                            {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    for (int i = 0; i < 12; i++)
        for (int a = 0; a < 3; a++)
            P[i][a] = 0.8f * v[i][a] + 2.0f * jitter(i, 7, 3, a);
    memcpy(idx, faces, sizeof faces);
}

/* A closed Loop mesh: one triangular patch per face, sharing the mesh's
 * edges. */
static void test_loop_mesh_is_watertight(void)
{
    float P[12][3];
    int idx[60], nv[20];
    icosahedron(P, idx, nv);
    RayesScene *s = scene_with_marker();
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_LOOP, 20, nv, idx, 12, &P[0][0], NULL,
                                       NULL, 0) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("Loop mesh: %ld leaked rays of %d\n", n, 4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

/* The same icosahedron as a polygon mesh of triangles: flat faces, each
 * diced into quads (split_quads) or one triangular grid by its size. */
static void test_triangle_mesh_is_watertight(void)
{
    float P[12][3];
    int idx[60], nv[20];
    icosahedron(P, idx, nv);
    RayesScene *s = scene_with_marker();
    CHECK(rayes_scene_polygon_mesh(s, 20, nv, idx, 12, &P[0][0]) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("triangle mesh: %ld leaked rays of %d\n", n, 4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

/* The barrel as a polygon mesh, displaced: flat faces meet along straight
 * edges, but displacement moves each face's side vertices along its own
 * normal, so triangle-triangle and triangle-quad edges open unless
 * stitched (1,447 leaked rays without). An amplitude of 0.03: at 0.08 the
 * fractal folds over itself near the silhouette, and rays meet those
 * folds from behind without passing any crack (none reach the marker). */
static void test_displaced_mixed_mesh_is_watertight(void)
{
    float P[2 * BARREL + 2][3];
    int nv[3 * BARREL], idx[10 * BARREL], f = barrel(P, nv, idx);
    RayesScene *s = scene_with_marker();
    const RayesParam amp = {"amplitude", RAYES_PARAM_FLOAT, {0.03f, 0, 0}, NULL};
    CHECK(rayes_scene_set_displacement(s, "fractal", &amp, 1) == RAYES_OK);
    CHECK(rayes_scene_set_displacement_bound(s, 0.2f) == RAYES_OK);
    CHECK(rayes_scene_polygon_mesh(s, (size_t)f, nv, idx, 2 * BARREL + 2, &P[0][0]) == RAYES_OK);
    CHECK(rayes_scene_set_displacement(s, NULL, NULL, 0) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("displaced mixed mesh: %ld leaked rays of %d\n", n, 4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

/* The icosahedron as two meshes sharing edges: ten faces displaced, ten
 * undisplaced and each one micropolygon (shading rate 1e6), whose grids
 * need no stitching among themselves (geom/stitch.c whole_flat_triangle)
 * but must hold the displaced faces' sides on their edges (1,935 leaked
 * rays when they were left out). */
static void test_displaced_beside_one_micropolygon_faces(void)
{
    float P[12][3];
    int idx[60], nv[20];
    icosahedron(P, idx, nv);
    RayesScene *s = scene_with_marker();
    const RayesParam amp = {"amplitude", RAYES_PARAM_FLOAT, {0.03f, 0, 0}, NULL};
    CHECK(rayes_scene_set_displacement(s, "fractal", &amp, 1) == RAYES_OK);
    CHECK(rayes_scene_set_displacement_bound(s, 0.2f) == RAYES_OK);
    CHECK(rayes_scene_polygon_mesh(s, 10, nv, idx, 12, &P[0][0]) == RAYES_OK);
    CHECK(rayes_scene_set_displacement(s, NULL, NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_set_shading_rate(s, 1e6f) == RAYES_OK);
    CHECK(rayes_scene_polygon_mesh(s, 10, nv + 10, idx + 30, 12, &P[0][0]) == RAYES_OK);
    CHECK(rayes_scene_set_shading_rate(s, 16.0f) == RAYES_OK);
    add_marker(s);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    long n = leaks(s, 2);
    printf("displaced beside one-micropolygon faces: %ld leaked rays of %d\n", n,
           4 * IMAGE * IMAGE);
    CHECK(n == 0);
    rayes_scene_release(s);
}

enum { SLIVERS = 128 }; /* strips around the sliver cylinder */

/* A closed cylinder (radius 1, height 2) of slivers: each of SLIVERS
 * strips around it is four triangles about a point on a ring at y = 0.3,
 * two needles (their short edges on the rims) and two caps (their long
 * edges the strip's sides, split near their apexes' feet, not at their
 * midpoints), and the ends are fans of needles; faces wound outward.
 * Returns the faces. */
static int sliver_cylinder(float P[3 * SLIVERS + 2][3], int idx[18 * SLIVERS])
{
    const float pi = 3.14159265f;
    for (int i = 0; i < SLIVERS; i++) {
        float a = 2.0f * pi * (float)i / SLIVERS, m = a + pi / SLIVERS;
        float ring[3][3] = {
            {cosf(a), -1, sinf(a)}, {cosf(a), 1, sinf(a)}, {cosf(m), 0.3f, sinf(m)}};
        memcpy(P[3 * i], ring, sizeof ring);
    }
    float ends[2][3] = {{0, -1, 0}, {0, 1, 0}};
    memcpy(P[3 * SLIVERS], ends, sizeof ends);
    int f = 0;
    for (int i = 0; i < SLIVERS; i++) {
        int j = (i + 1) % SLIVERS, b0 = 3 * i, t0 = b0 + 1, m = b0 + 2, b1 = 3 * j, t1 = b1 + 1;
        int tri[6][3] = {{b0, b1, m}, {t0, t1, m},           {b0, t0, m},
                         {b1, t1, m}, {3 * SLIVERS, b0, b1}, {3 * SLIVERS + 1, t0, t1}};
        for (int k = 0; k < 6; k++, f++) {
            const float *p0 = P[tri[k][0]], *p1 = P[tri[k][1]], *p2 = P[tri[k][2]];
            Vec3 n = v3_cross(v3(p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]),
                              v3(p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]));
            Vec3 c = v3(p0[0] + p1[0] + p2[0], p0[1] + p1[1] + p2[1], p0[2] + p1[2] + p2[2]);
            int out = v3_dot(n, c) > 0.0f; /* the cylinder is star-shaped about 0 */
            idx[3 * f] = tri[k][0];
            idx[3 * f + 1] = tri[k][out ? 1 : 2];
            idx[3 * f + 2] = tri[k][out ? 2 : 1];
        }
    }
    return f;
}

/* Slivers dice as fans (needles) and caps split near their feet
 * (geom/dice.c sliver_shape), along lines a triangular grid's neighbours
 * do not share whole: plain, and displaced. */
static void test_sliver_mesh_is_watertight(void)
{
    static float P[3 * SLIVERS + 2][3];
    static int idx[18 * SLIVERS], nv[6 * SLIVERS];
    int f = sliver_cylinder(P, idx);
    for (int k = 0; k < f; k++)
        nv[k] = 3;
    for (int displaced = 0; displaced < 2; displaced++) {
        RayesScene *s = scene_with_marker();
        const RayesParam amp = {"amplitude", RAYES_PARAM_FLOAT, {0.01f, 0, 0}, NULL};
        if (displaced) {
            CHECK(rayes_scene_set_displacement(s, "fractal", &amp, 1) == RAYES_OK);
            CHECK(rayes_scene_set_displacement_bound(s, 0.05f) == RAYES_OK);
        }
        CHECK(rayes_scene_polygon_mesh(s, (size_t)f, nv, idx, 3 * SLIVERS + 2, &P[0][0]) ==
              RAYES_OK);
        CHECK(rayes_scene_set_displacement(s, NULL, NULL, 0) == RAYES_OK);
        add_marker(s);
        CHECK(rayes_scene_commit(s) == RAYES_OK);
        long n = leaks(s, 2);
        printf("sliver mesh%s: %ld leaked rays of %d, %zu fans\n", displaced ? ", displaced" : "",
               n, 4 * IMAGE * IMAGE, last_fans);
        CHECK(n == 0);
        CHECK(last_fans > (size_t)SLIVERS);
        rayes_scene_release(s);
    }
}

/* Holes are holes: a flat 3 x 3 Catmull-Clark grid whose middle face is a
 * hole; rays through the middle of the hole (a square of half its size)
 * miss, rays through the other faces' middles hit. */
static void test_hole_lets_rays_through(void)
{
    float P[16][3];
    int nv[9], idx[36];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            P[4 * j + i][0] = (float)i, P[4 * j + i][1] = (float)j, P[4 * j + i][2] = 0.0f;
    for (int f = 0; f < 9; f++) {
        int a = f % 3 + 4 * (f / 3), q[4] = {a, a + 1, a + 5, a + 4};
        nv[f] = 4;
        memcpy(&idx[4 * f], q, sizeof q);
    }
    RayesScene *s = rayes_scene_new();
    const float from[3] = {1.5f, 1.5f, -8.0f}, at[3] = {1.5f, 1.5f, 0.0f}, up[3] = {0, 1, 0};
    rayes_scene_set_camera(s, from, at, up, 30.0f);
    const int hole[1] = {4};
    RayesSubdivTags t = {.interpolate_boundary = 1, .n_holes = 1, .hole_faces = hole};
    CHECK(rayes_scene_subdivision_mesh(s, RAYES_SUBDIV_CATMULL_CLARK, 9, nv, idx, 16, &P[0][0], &t,
                                       NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 64, 64, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    uint32_t mask = RAYES_RAY_CAMERA;
    char err[256];
    Accel *a = accel_new(&gs, &mask, 1, NULL, err, sizeof err);
    CHECK(a != NULL);
    int hits_in_hole = 0, misses_elsewhere = 0;
    for (int k = 0; a && k < 21 * 21; k++) {
        float x = 1.25f + 0.5f * (float)(k % 21) / 20.0f, y = 1.25f + 0.5f * (float)(k / 21) / 20.0f;
        Ray r = {v3(x, y, -8.0f), v3(0, 0, 1), 0.0f, 1e30f, RAYES_RAY_CAMERA};
        Hit h;
        hits_in_hole += accel_intersect(a, &r, &h);
    }
    for (int f = 0; a && f < 9; f++) {
        Ray r = {v3(0.5f + (float)(f % 3), 0.5f + (float)(f / 3), -8.0f), v3(0, 0, 1), 0.0f, 1e30f,
                 RAYES_RAY_CAMERA};
        Hit h;
        misses_elsewhere += f != 4 && !accel_intersect(a, &r, &h);
    }
    CHECK(hits_in_hole == 0);
    CHECK(misses_elsewhere == 0);
    accel_free(a);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_hole_lets_rays_through), TEST(test_subdivision_mesh_is_watertight),
          TEST(test_polygon_mesh_is_watertight), TEST(test_ngon_mesh_is_watertight),
          TEST(test_loop_mesh_is_watertight), TEST(test_triangle_mesh_is_watertight),
          TEST(test_displaced_mixed_mesh_is_watertight),
          TEST(test_displaced_beside_one_micropolygon_faces), TEST(test_sliver_mesh_is_watertight))
