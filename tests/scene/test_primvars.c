/*
 * Primitive variables (rayes.h's RayesPrimvar) through the scene and the
 * dicer: a linear function of position given in each class comes back
 * exactly at every diced grid vertex (bilinear on quads, barycentric on
 * triangles, Bezier for a bicubic patch's vertex class, bilinear over its
 * corners for varying); N is turned by the current transform's inverse
 * transpose and to the front; a smooth-normal sphere mesh has one shading
 * normal per point wherever grids meet, though its faces are flat; a
 * displacement replaces N; wrong counts, names and classes are refused.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

/* The linear functions: st = (x + 2y, 3 - z), Cs = (x, y, x + y). */
static void st_of(const float p[3], float st[2])
{
    st[0] = p[0] + 2.0f * p[1];
    st[1] = 3.0f - p[2];
}

static void cs_of(const float p[3], float c[3])
{
    c[0] = p[0], c[1] = p[1], c[2] = p[0] + p[1];
}

static int prepare(RayesScene *s, GridSet *gs)
{
    static const float eye[3] = {0.5f, 0.5f, -4.0f}, at[3] = {0.5f, 0.5f, 0.0f},
                       up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    geom_gridset_init(gs);
    return scene_prepare(s, 64, 64, NULL, NULL, gs, NULL, NULL, 0);
}

/* Every vertex of every grid: st and Cs are the functions of its P. */
static void check_linear(const GridSet *gs, double tol)
{
    double worst = 0.0;
    int seen = 0;
    for (size_t g = 0; g < gs->n_grids; g++) {
        const Grid *grid = &gs->grids[g];
        CHECK((grid->primvars & (GEOM_PV_ST | GEOM_PV_CS)) == (GEOM_PV_ST | GEOM_PV_CS));
        for (size_t k = 0; k < geom_grid_n_vertices(grid); k++) {
            size_t i = grid->first_vertex + k;
            float p[3] = {gs->P[i].x, gs->P[i].y, gs->P[i].z}, st[2], c[3];
            st_of(p, st);
            cs_of(p, c);
            worst = fmax(worst, fabs(gs->st[i][0] - st[0]) + fabs(gs->st[i][1] - st[1]));
            worst = fmax(worst, fabs(gs->Cs[i].x - c[0]) + fabs(gs->Cs[i].y - c[1]) +
                                    fabs(gs->Cs[i].z - c[2]));
            seen++;
        }
    }
    CHECK(seen > 0);
    if (worst > tol)
        fprintf(stderr, "largest difference %g\n", worst);
    CHECK(worst <= tol);
}

/* A quad and a triangle (a mesh of 4 + 3 corners over 5 points), the
 * quad not a parallelogram, so the interpolation must be bilinear. */
static const float mesh_P[5][3] = {{0, 0, 0}, {1, 0, 0.2f}, {1.2f, 1, 0}, {0, 1, 0.4f},
                                   {2, 0.5f, 0.1f}};
static const int mesh_nv[2] = {4, 3}, mesh_idx[7] = {0, 1, 2, 3, 1, 4, 2};

static void test_mesh_classes(void)
{
    /* vertex (per point), facevarying (per corner), varying (per point) */
    for (int cls = RAYES_PRIMVAR_VARYING; cls <= RAYES_PRIMVAR_FACEVARYING; cls++) {
        int corners = cls == RAYES_PRIMVAR_FACEVARYING;
        size_t n = corners ? 7 : 5;
        float st[7][2], cs[7][3];
        for (size_t k = 0; k < n; k++) {
            const float *p = mesh_P[corners ? mesh_idx[k] : (int)k];
            st_of(p, st[k]);
            cs_of(p, cs[k]);
        }
        RayesPrimvar pv[2] = {{"st", (RayesPrimvarClass)cls, &st[0][0], n},
                              {"Cs", (RayesPrimvarClass)cls, &cs[0][0], n}};
        RayesScene *s = rayes_scene_new();
        CHECK(rayes_scene_set_shading_rate(s, 0.5f) == RAYES_OK);
        CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], pv, 2) ==
              RAYES_OK);
        GridSet gs;
        CHECK(prepare(s, &gs) == 0);
        CHECK(gs.n_grids >= 2);
        check_linear(&gs, 2e-6);
        geom_gridset_fini(&gs);
        rayes_scene_release(s);
    }
}

/* Constant and uniform values hold over the whole face. */
static void test_constant_uniform(void)
{
    const float c1[3] = {0.25f, 0.5f, 0.75f}, cu[2][3] = {{1, 0, 0}, {0, 1, 0}};
    const float st1[2] = {7, 8};
    RayesPrimvar pv[2] = {{"Cs", RAYES_PRIMVAR_UNIFORM, &cu[0][0], 2},
                          {"st", RAYES_PRIMVAR_CONSTANT, st1, 1}};
    RayesScene *s = rayes_scene_new();
    CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], pv, 2) ==
          RAYES_OK);
    RayesPrimvar one = {"Cs", RAYES_PRIMVAR_CONSTANT, c1, 1};
    const float quad[4][3] = {{0, 0, 1}, {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
    CHECK(rayes_scene_bilinear_patch_pv(s, quad, &one, 1) == RAYES_OK);
    GridSet gs;
    CHECK(prepare(s, &gs) == 0);
    int ok = 1;
    for (size_t g = 0; g < gs.n_grids; g++) {
        const Grid *grid = &gs.grids[g];
        const float *want = grid->prim == 2 ? c1 : cu[grid->prim];
        for (size_t k = 0; k < geom_grid_n_vertices(grid); k++) {
            size_t i = grid->first_vertex + k;
            ok &= fabsf(gs.Cs[i].x - want[0]) + fabsf(gs.Cs[i].y - want[1]) +
                      fabsf(gs.Cs[i].z - want[2]) < 1e-6f;
            if (grid->prim < 2)
                ok &= fabsf(gs.st[i][0] - 7) < 1e-5f && fabsf(gs.st[i][1] - 8) < 1e-5f;

            else
                ok &= !(grid->primvars & GEOM_PV_ST); /* the patch: (u, v) */
        }
    }
    CHECK(ok);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

/* A bicubic patch whose control points are an affine lattice: its vertex
 * class (16 values, Bezier) and its varying class (4 corners, bilinear)
 * both reproduce a linear function exactly. */
static void test_bicubic(void)
{
    float P[16][3];
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            P[4 * j + i][0] = (float)i / 3.0f + 0.1f * (float)j / 3.0f;
            P[4 * j + i][1] = (float)j / 3.0f;
            P[4 * j + i][2] = 0.2f * (float)i / 3.0f;
        }
    float st16[16][2], cs16[16][3], st4[4][2], cs4[4][3];
    static const int corner[4] = {0, 3, 12, 15};
    for (int k = 0; k < 16; k++) {
        st_of(P[k], st16[k]);
        cs_of(P[k], cs16[k]);
    }
    for (int k = 0; k < 4; k++) {
        memcpy(st4[k], st16[corner[k]], sizeof st4[k]);
        memcpy(cs4[k], cs16[corner[k]], sizeof cs4[k]);
    }
    RayesPrimvar vertex[2] = {{"st", RAYES_PRIMVAR_VERTEX, &st16[0][0], 16},
                              {"Cs", RAYES_PRIMVAR_VERTEX, &cs16[0][0], 16}};
    RayesPrimvar varying[2] = {{"st", RAYES_PRIMVAR_VARYING, &st4[0][0], 4},
                               {"Cs", RAYES_PRIMVAR_VARYING, &cs4[0][0], 4}};
    for (int pass = 0; pass < 2; pass++) {
        RayesScene *s = rayes_scene_new();
        CHECK(rayes_scene_bicubic_patch_pv(s, (const float(*)[3])P, pass ? varying : vertex, 2) ==
              RAYES_OK);
        GridSet gs;
        CHECK(prepare(s, &gs) == 0);
        check_linear(&gs, 4e-6);
        geom_gridset_fini(&gs);
        rayes_scene_release(s);
    }
    /* a vertex class of 4 values on a bicubic patch is refused */
    RayesScene *s = rayes_scene_new();
    RayesPrimvar bad = {"st", RAYES_PRIMVAR_VERTEX, &st4[0][0], 4};
    CHECK(rayes_scene_bicubic_patch_pv(s, (const float(*)[3])P, &bad, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "vertex st has 4 values; expected 16") != NULL);
    rayes_scene_release(s);
}

/* A sphere of n x n lat-long quads (poles as triangles) with N = the unit
 * position: at every point where grids meet, the shading normal is the
 * same in all of them (no facets) and equals the given normal, while the
 * geometric normals of neighbouring faces differ. Returns the scene. */
static RayesScene *smooth_sphere(int n, int with_n)
{
    int rows = n, cols = 2 * n;
    size_t np = (size_t)(rows + 1) * cols;
    float(*P)[3] = malloc(np * sizeof *P);
    int *nv = malloc((size_t)rows * cols * sizeof *nv), *idx = malloc(4 * (size_t)rows * cols * sizeof *idx);
    for (int j = 0; j <= rows; j++)
        for (int i = 0; i < cols; i++) {
            double th = M_PI * j / rows, ph = 2 * M_PI * i / cols;
            float *p = P[(size_t)j * cols + i];
            p[0] = (float)(sin(th) * cos(ph)), p[1] = (float)cos(th), p[2] = (float)(sin(th) * sin(ph));
        }
    size_t nf = 0, k = 0;
    for (int j = 0; j < rows; j++)
        for (int i = 0; i < cols; i++) {
            int a = j * cols + i, b = j * cols + (i + 1) % cols, c = a + cols, d = b + cols;
            if (j == 0) { /* the pole: a triangle */
                nv[nf++] = 3, idx[k++] = a, idx[k++] = d, idx[k++] = c;
            } else if (j == rows - 1) {
                nv[nf++] = 3, idx[k++] = a, idx[k++] = b, idx[k++] = c;
            } else {
                nv[nf++] = 4, idx[k++] = a, idx[k++] = b, idx[k++] = d, idx[k++] = c;
            }
        }
    RayesScene *s = rayes_scene_new();
    RayesPrimvar pv = {"N", RAYES_PRIMVAR_VERTEX, &P[0][0], np};
    CHECK(rayes_scene_polygon_mesh_pv(s, nf, nv, idx, np, &P[0][0], &pv, with_n ? 1 : 0) ==
          RAYES_OK);
    free(P);
    free(nv);
    free(idx);
    return s;
}

static void test_smooth_normals(void)
{
    RayesScene *s = smooth_sphere(8, 1);
    GridSet gs;
    static const float eye[3] = {0, 0, -6}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 64, 64, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    double worst_given = 0.0, worst_shared = 0.0, facet = 0.0;
    for (size_t g = 0; g < gs.n_grids; g++) {
        const Grid *a = &gs.grids[g];
        CHECK(a->primvars & GEOM_PV_N);
        /* corners of each grid: the given normal is the unit position, on the front */
        size_t i0 = a->first_vertex;
        Vec3 p = gs.P[i0], want = v3_normalize(p);
        if (v3_dot(want, gs.N[i0]) < 0.0f)
            want = v3_neg(want);
        worst_given = fmax(worst_given, v3_length(v3_sub(gs.Ns[i0], want)));
    }
    /* every pair of vertices of different grids at one position */
    for (size_t g = 0; g < gs.n_grids; g++)
        for (size_t h = g + 1; h < gs.n_grids; h++) {
            const Grid *a = &gs.grids[g], *b = &gs.grids[h];
            for (size_t x = 0; x < geom_grid_n_vertices(a); x++)
                for (size_t y = 0; y < geom_grid_n_vertices(b); y++) {
                    size_t i = a->first_vertex + x, j = b->first_vertex + y;
                    if (v3_length(v3_sub(gs.P[i], gs.P[j])) > 1e-6f)
                        continue;
                    worst_shared = fmax(worst_shared, v3_length(v3_sub(gs.Ns[i], gs.Ns[j])));
                    facet = fmax(facet, v3_length(v3_sub(gs.N[i], gs.N[j])));
                }
        }
    fprintf(stderr, "shading normals: %g from given, %g apart at shared points; geometric "
                    "normals up to %g apart\n", worst_given, worst_shared, facet);
    CHECK(worst_given < 1e-5);
    CHECK(worst_shared < 1e-5);
    CHECK(facet > 0.2); /* the faces are flat: without N the picture would be faceted */
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

/* N transforms as a normal: under a non-uniform scale it stays
 * perpendicular to the surface (here a plane z = x, scaled in x). */
static void test_normal_transform(void)
{
    RayesScene *s = rayes_scene_new();
    const float m[16] = {2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    const float quad[4][3] = {{0, 0, 0}, {1, 0, 1}, {0, 1, 0}, {1, 1, 1}};
    const float N[3] = {-1, 0, 1}; /* object space: perpendicular to the plane z = x */
    RayesPrimvar pv = {"N", RAYES_PRIMVAR_CONSTANT, N, 1};
    CHECK(rayes_scene_bilinear_patch_pv(s, quad, &pv, 1) == RAYES_OK);
    GridSet gs;
    CHECK(prepare(s, &gs) == 0);
    size_t i = gs.grids[0].first_vertex;
    CHECK(fabsf(v3_dot(gs.Ns[i], gs.dPdu[i])) < 1e-5f);
    CHECK(fabsf(v3_dot(gs.Ns[i], gs.N[i]) - 1.0f) < 1e-5f); /* turned to the front */
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

/* A displacement shader's normals replace a supplied N. */
static void test_displacement_replaces_n(void)
{
    RayesScene *s = rayes_scene_new();
    RayesParam amp = {"Km", RAYES_PARAM_FLOAT, {0.05f, 0, 0}, NULL};
    CHECK(rayes_scene_set_displacement(s, "bumpy", &amp, 1) == RAYES_OK);
    const float quad[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    const float N[3] = {0, 0, 1};
    RayesPrimvar pv = {"N", RAYES_PRIMVAR_CONSTANT, N, 1};
    CHECK(rayes_scene_bilinear_patch_pv(s, quad, &pv, 1) == RAYES_OK);
    GridSet gs;
    CHECK(prepare(s, &gs) == 0);
    CHECK(gs.n_grids > 0 && !(gs.grids[0].primvars & GEOM_PV_N));
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

static void test_refused(void)
{
    RayesScene *s = rayes_scene_new();
    const float st[8] = {0};
    RayesPrimvar pv = {"st", RAYES_PRIMVAR_VERTEX, st, 4};
    CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], &pv, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "polygon mesh: vertex st has 4 values; expected 5"));
    rayes_scene_clear_error(s);
    pv = (RayesPrimvar){"Oi", RAYES_PRIMVAR_CONSTANT, st, 1};
    CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], &pv, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "unknown primitive variable \"Oi\""));
    rayes_scene_clear_error(s);
    pv = (RayesPrimvar){"st", (RayesPrimvarClass)7, st, 1};
    CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], &pv, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    RayesPrimvar two[2] = {{"st", RAYES_PRIMVAR_CONSTANT, st, 1},
                           {"st", RAYES_PRIMVAR_CONSTANT, st, 1}};
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], two, 2) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "given twice"));
    const float nan[3] = {0, NAN, 0};
    pv = (RayesPrimvar){"Cs", RAYES_PRIMVAR_CONSTANT, nan, 1};
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_polygon_mesh_pv(s, 2, mesh_nv, mesh_idx, 5, &mesh_P[0][0], &pv, 1) ==
          RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "non-finite"));
    CHECK(s->n_prims == 0); /* nothing was added */
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_mesh_classes), TEST(test_constant_uniform), TEST(test_bicubic),
          TEST(test_smooth_normals), TEST(test_normal_transform),
          TEST(test_displacement_replaces_n), TEST(test_refused))
