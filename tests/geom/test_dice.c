#include <math.h>
#include <stdio.h>
/* Patch evaluation and dicing (geom/). */
#include <string.h>

#include "geom/geom.h"
#include "test.h"

static Prim bilinear(Vec3 a, Vec3 b, Vec3 c, Vec3 d)
{
    Prim p = {.type = PRIM_BILINEAR, .shading_rate = 1.0f};
    p.cp[0] = a, p.cp[1] = b, p.cp[2] = c, p.cp[3] = d;
    return p;
}

static void test_bezier_basis(void)
{
    for (float t = 0.0f; t <= 1.0f; t += 0.125f) {
        float b[4], db[4];
        geom_bezier_basis(t, b, db);
        CHECK_NEAR(b[0] + b[1] + b[2] + b[3], 1.0, 1e-6);
        CHECK_NEAR(db[0] + db[1] + db[2] + db[3], 0.0, 1e-5);
    }
    float b[4], db[4];
    geom_bezier_basis(0.5f, b, db);
    CHECK_NEAR(b[1], 0.375, 1e-7);
    CHECK_NEAR(db[0], -0.75, 1e-7);
}

/* A bicubic patch whose control points are the bilinear interpolation of
 * four corners on a 1/3 lattice is that bilinear patch exactly. */
static void test_bicubic_reproduces_bilinear(void)
{
    Vec3 c[4] = {v3(0, 0, 0), v3(3, 0, 1), v3(0, 2, 0), v3(3, 3, 2)};
    Prim bl = bilinear(c[0], c[1], c[2], c[3]);
    PrimBig big;
    Prim bc = {.type = PRIM_BICUBIC, .shading_rate = 1.0f, .big = &big};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            Vec3 a = v3_lerp(c[0], c[1], i / 3.0f), b = v3_lerp(c[2], c[3], i / 3.0f);
            big.cp[4 * j + i] = v3_lerp(a, b, j / 3.0f);
        }
    for (float v = 0.0f; v <= 1.0f; v += 0.25f)
        for (float u = 0.0f; u <= 1.0f; u += 0.25f) {
            Vec3 P1, du1, dv1, P2, du2, dv2;
            geom_prim_eval(&bl, u, v, &P1, &du1, &dv1);
            geom_prim_eval(&bc, u, v, &P2, &du2, &dv2);
            CHECK_NEAR(v3_length(v3_sub(P1, P2)), 0.0, 1e-5);
            CHECK_NEAR(v3_length(v3_sub(du1, du2)), 0.0, 1e-4);
            CHECK_NEAR(v3_length(v3_sub(dv1, dv2)), 0.0, 1e-4);
        }
}

static void test_bilinear_known_values(void)
{
    Prim p = bilinear(v3(0, 0, 0), v3(2, 0, 0), v3(0, 4, 0), v3(2, 4, 2));
    Vec3 P, du, dv;
    geom_prim_eval(&p, 0.5f, 0.5f, &P, &du, &dv);
    CHECK_NEAR(P.x, 1.0, 1e-6);
    CHECK_NEAR(P.y, 2.0, 1e-6);
    CHECK_NEAR(P.z, 0.5, 1e-6);
    CHECK_NEAR(du.x, 2.0, 1e-6);
    CHECK_NEAR(du.z, 1.0, 1e-6);
    CHECK_NEAR(dv.y, 4.0, 1e-6);
    Vec3 n = geom_prim_normal(&p, 0.0f, 0.0f);
    CHECK_NEAR(n.z, 1.0, 1e-6); /* dPdu x dPdv = x cross y */
}

/* A dense mesh keeps a primitive and a grid per face: what only some
 * need is out of line (PrimBig, GridSub), so both stay small. */
static void test_prim_is_small(void)
{
    CHECK(sizeof(Prim) <= 112);
    CHECK(sizeof(PrimBig) >= 16 * sizeof(Vec3));
    CHECK(sizeof(Grid) <= 76);
}

static void test_sphere_eval_and_normal(void)
{
    PrimBig big;
    Prim s = {.type = PRIM_SPHERE, .shading_rate = 1.0f, .big = &big};
    s.big->sphere.world_from_object = mat4_translate(1, 2, 3);
    s.big->sphere.normal_from_object = mat4_identity();
    s.big->sphere.radius = 2.0f;
    Vec3 P, du, dv;
    geom_prim_eval(&s, 0.0f, 0.5f, &P, &du, &dv);
    CHECK_NEAR(P.x, 3.0, 1e-5);
    CHECK_NEAR(P.y, 2.0, 1e-5);
    CHECK_NEAR(P.z, 3.0, 1e-5);
    Vec3 n = geom_prim_normal(&s, 0.0f, 0.5f);
    CHECK_NEAR(n.x, 1.0, 1e-5);
    Vec3 pole = geom_prim_normal(&s, 0.3f, 0.0f); /* degenerate dPdu: still defined */
    CHECK_NEAR(pole.z, -1.0, 1e-5);
}

/* A degenerate row (the teapot lid's apex) still gets the limit normal. */
static void test_degenerate_bicubic_normal(void)
{
    PrimBig big;
    Prim bc = {.type = PRIM_BICUBIC, .shading_rate = 1.0f, .big = &big};
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++) {
            /* The first two rows at one height: a smooth dome, not a cone. */
            static const float z[4] = {1.0f, 1.0f, 0.8f, 0.5f};
            float r = j / 3.0f, a = 1.5707963f * i / 3.0f;
            big.cp[4 * j + i] = v3(r * cosf(a), r * sinf(a), z[j]);
        }
    Vec3 n = geom_prim_normal(&bc, 0.5f, 0.0f);
    CHECK(fabsf(n.z) > 0.99f);
}

static DiceCamera camera(void)
{
    DiceCamera c = {.eye = v3(0, 0, -100), .pixel_angle = 0.01f, .min_distance = 1e-3f};
    return c;
}

/* A 10 x 10 square 100 units away needs 10 micropolygons per side at 1 pixel
 * = 1 unit: one 11 x 11 grid. */
static void test_dicing_rate_from_camera(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    Prim p = bilinear(v3(-5, -5, 0), v3(5, -5, 0), v3(-5, 5, 0), v3(5, 5, 0));
    DiceCamera cam = camera();
    CHECK(geom_dice_prim(&gs, &p, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 1);
    CHECK(gs.grids[0].nu == 11 && gs.grids[0].nv == 11);
    CHECK(gs.n_vertices == 121);
    CHECK_NEAR(gs.grids[0].edge, 1.0, 1e-4);
    CHECK_NEAR(gs.grids[0].curvature, 0.0, 1e-6);
    /* Shading rate 4 (area) halves the rate per side. */
    geom_gridset_fini(&gs);
    p.shading_rate = 4.0f;
    CHECK(geom_dice_prim(&gs, &p, 0, NULL, &cam) == 0);
    CHECK(gs.grids[0].nu == 6 && gs.grids[0].nv == 6);
    geom_gridset_fini(&gs);
}

/* A large patch splits into grids of at most GEOM_GRID_SIZE micropolygons,
 * covering it exactly. */
static void test_split_limits_grid_size(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    Prim p = bilinear(v3(-50, -20, 0), v3(50, -20, 0), v3(-50, 20, 0), v3(50, 20, 0));
    DiceCamera cam = camera();
    CHECK(geom_dice_prim(&gs, &p, 7, NULL, &cam) == 0);
    CHECK(gs.n_grids > 1);
    double area = 0.0;
    for (size_t g = 0; g < gs.n_grids; g++) {
        const Grid *gr = &gs.grids[g];
        CHECK(gr->nu >= 2 && gr->nu <= GEOM_MAX_GRID && gr->nv >= 2 && gr->nv <= GEOM_MAX_GRID);
        CHECK((gr->nu - 1) * (gr->nv - 1) <= GEOM_GRID_SIZE);
        CHECK(gr->prim == 7);
        area += (gr->uv[1][0] - gr->uv[0][0]) * (gr->uv[1][1] - gr->uv[0][1]);
        const Vec3 *P = &gs.P[gr->first_vertex];
        CHECK(P[0].z == 0.0f);
    }
    CHECK_NEAR(area, 1.0, 1e-6);
    geom_gridset_fini(&gs);
}

/* RenderMan's gridsize rule: a 20 x 20 square (400 micropolygons) splits
 * once, across u, into two 10 x 20 grids, where a rule of 16 per side
 * would have made four 10 x 10 grids; a 40 x 2 strip (80 micropolygons)
 * stays whole; a 100 x 1 strip splits only for the side limit. */
static void test_split_by_area(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    DiceCamera cam = camera();
    Prim sq = bilinear(v3(-10, -10, 0), v3(10, -10, 0), v3(-10, 10, 0), v3(10, 10, 0));
    CHECK(geom_dice_prim(&gs, &sq, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 2);
    for (size_t g = 0; g < gs.n_grids; g++)
        CHECK(gs.grids[g].nu == 11 && gs.grids[g].nv == 21);
    CHECK_NEAR(gs.grids[0].uv[1][0], 0.5, 1e-6);
    geom_gridset_fini(&gs);
    Prim strip = bilinear(v3(-20, -1, 0), v3(20, -1, 0), v3(-20, 1, 0), v3(20, 1, 0));
    CHECK(geom_dice_prim(&gs, &strip, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 1 && gs.grids[0].nu == 41 && gs.grids[0].nv == 3);
    geom_gridset_fini(&gs);
    Prim line = bilinear(v3(-50, -0.5f, 0), v3(50, -0.5f, 0), v3(-50, 0.5f, 0), v3(50, 0.5f, 0));
    CHECK(geom_dice_prim(&gs, &line, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 2);
    for (size_t g = 0; g < gs.n_grids; g++)
        CHECK(gs.grids[g].nu <= GEOM_MAX_GRID && gs.grids[g].nv == 2);
    geom_gridset_fini(&gs);
}

/* The gridsize option: the 20 x 20 square of test_split_by_area in grids of
 * at most 64 micropolygons (10 x 20, then 10 x 10, then eight 5 x 10
 * pieces of 50), in one 20 x 20 grid at 400, and at 4096 a 64 x 64 square
 * stays whole. A triangle then has at most sqrt(gridsize) subdivisions
 * per edge, and an out-of-range value is clamped to 4096. */
static void test_grid_size_option(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    DiceCamera cam = camera();
    Prim sq = bilinear(v3(-10, -10, 0), v3(10, -10, 0), v3(-10, 10, 0), v3(10, 10, 0));
    cam.grid_size = 64;
    CHECK(geom_dice_prim(&gs, &sq, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 8);
    for (size_t g = 0; g < gs.n_grids; g++)
        CHECK(gs.grids[g].nu == 6 && gs.grids[g].nv == 11);
    geom_gridset_fini(&gs);
    cam.grid_size = 400;
    CHECK(geom_dice_prim(&gs, &sq, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 1 && gs.grids[0].nu == 21 && gs.grids[0].nv == 21);
    geom_gridset_fini(&gs);
    Prim big = bilinear(v3(-32, -32, 0), v3(32, -32, 0), v3(-32, 32, 0), v3(32, 32, 0));
    cam.grid_size = 1 << 20;
    CHECK(geom_dice_prim(&gs, &big, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 1 && gs.grids[0].nu == 65 && gs.grids[0].nv == 65);
    geom_gridset_fini(&gs);
    /* Triangles: one triangular grid of at most sqrt(size) subdivisions,
     * or, too large for that, quad grids of at most size micropolygons. */
    Prim t = {.type = PRIM_TRIANGLE, .shading_rate = 1.0f};
    t.cp[0] = v3(0, 0, 0), t.cp[1] = v3(100, 0, 0), t.cp[2] = v3(0, 100, 0);
    for (int size = 16; size <= 4096; size *= 4) {
        cam.grid_size = size;
        CHECK(geom_dice_prim(&gs, &t, 0, NULL, &cam) == 0);
        int biggest = 0;
        for (size_t g = 0; g < gs.n_grids; g++) {
            const Grid *q = &gs.grids[g];
            int m = q->triangular ? q->nu * q->nu : (q->nu - 1) * (q->nv - 1);
            CHECK(!q->triangular && m <= size);
            biggest = m > biggest ? m : biggest;
        }
        CHECK(4 * biggest > size);
        geom_gridset_fini(&gs);
    }
}

/* Nearer parts dice finer: a floor receding from the camera. */
static void test_distance_based_rates(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    Prim p = bilinear(v3(-20, -5, -90), v3(20, -5, -90), v3(-20, -5, 400), v3(20, -5, 400));
    DiceCamera cam = camera();
    CHECK(geom_dice_prim(&gs, &p, 0, NULL, &cam) == 0);
    float near_edge = 1e9f, far_edge = 0.0f;
    for (size_t g = 0; g < gs.n_grids; g++) {
        float z = gs.P[gs.grids[g].first_vertex].z;
        if (z < -80.0f)
            near_edge = fminf(near_edge, gs.grids[g].edge);
        if (z > 300.0f)
            far_edge = fmaxf(far_edge, gs.grids[g].edge);
    }
    CHECK(far_edge > 3.0f * near_edge);
    geom_gridset_fini(&gs);
}

/* Twice the area of triangle a b c projected on z. */
static double tri_area2(Vec3 a, Vec3 b, Vec3 c)
{
    return v3_cross(v3_sub(b, a), v3_sub(c, a)).z;
}

/* The summed area of every grid's micropolygons (quad cells as two
 * triangles), counted positive when it faces +z times sign. */
static double cell_area(const GridSet *gs, float sign)
{
    double area = 0.0;
    for (size_t g = 0; g < gs->n_grids; g++) {
        const Grid *q = &gs->grids[g];
        const Vec3 *T = gs->P + q->first_vertex;
        uint32_t n = q->nu;
        for (uint32_t j = 0; q->triangular && j < n; j++)
            for (uint32_t i = 0; i + j < n; i++) {
                area += 0.5 * sign *
                        tri_area2(T[geom_tri_vertex(n, i, j)], T[geom_tri_vertex(n, i + 1, j)],
                                  T[geom_tri_vertex(n, i, j + 1)]);
                if (i + j + 1 < n)
                    area += 0.5 * sign *
                            tri_area2(T[geom_tri_vertex(n, i + 1, j)],
                                      T[geom_tri_vertex(n, i + 1, j + 1)],
                                      T[geom_tri_vertex(n, i, j + 1)]);
            }
        for (int j = 0; !q->triangular && j + 1 < q->nv; j++)
            for (int i = 0; i + 1 < q->nu; i++) {
                const Vec3 *P = gs->P + q->first_vertex + (size_t)j * q->nu + i;
                Vec3 a = P[0], b = P[1], c = P[q->nu], d = P[q->nu + 1];
                area += 0.5 * sign * (tri_area2(a, b, c) + tri_area2(b, d, c));
            }
    }
    return area;
}

static void test_triangle_grid_counts(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    Prim t = {.type = PRIM_TRIANGLE, .shading_rate = 1.0f};
    t.cp[0] = v3(0, 0, 0), t.cp[1] = v3(8, 0, 0), t.cp[2] = v3(0, 8, 0);
    DiceCamera cam = camera();
    CHECK(geom_dice_prim(&gs, &t, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids == 1 && gs.grids[0].triangular);
    uint32_t n = gs.grids[0].nu;
    CHECK(n >= 8 && n <= 12); /* the hypotenuse is 11.3 units */
    CHECK(gs.n_vertices == (n + 1) * (n + 2) / 2);
    CHECK(geom_tri_vertex(n, 0, n) == gs.n_vertices - 1);
    Vec3 apex = gs.P[geom_tri_vertex(n, 0, n)];
    CHECK_NEAR(apex.y, 8.0, 1e-5);
    geom_gridset_fini(&gs);
    /* A big triangle: three quads meeting at its centroid, split as quads
     * are; their micropolygons cover it exactly, facing its way. */
    t.cp[1] = v3(100, 0, 0), t.cp[2] = v3(0, 100, 0);
    CHECK(geom_dice_prim(&gs, &t, 0, NULL, &cam) == 0);
    CHECK(gs.n_grids >= 3);
    CHECK_NEAR(cell_area(&gs, 1.0f), 5000.0, 0.05);
    for (size_t g = 0; g < gs.n_grids; g++)
        CHECK(!gs.grids[g].triangular &&
              (gs.grids[g].nu - 1) * (gs.grids[g].nv - 1) <= GEOM_GRID_SIZE);
    geom_gridset_fini(&gs);
}

/* A camera at (0, 0, -100) looking down +z, 100 pixels over a screen of
 * [-1, 1]^2 with tan(fov / 2) = 0.5: one pixel is 0.01 radians, as in
 * camera(). */
static DiceCamera view_camera(float offscreen)
{
    DiceCamera c = camera();
    c.has_view = 1;
    c.camera_from_world = mat4_translate(0, 0, 100);
    c.tan_half_fov = 0.5f;
    c.screen[0] = -1, c.screen[1] = 1, c.screen[2] = -1, c.screen[3] = 1;
    c.pixel = 0.02f;
    c.offscreen = offscreen;
    return c;
}

static size_t dice_vertices(const Prim *p, const DiceCamera *cam, GridSet *gs)
{
    geom_gridset_init(gs);
    CHECK(geom_dice_prim(gs, p, 0, NULL, cam) == 0);
    size_t grids = 0; /* counting agrees with dicing */
    CHECK(geom_count_prim(p, cam, &grids) == gs->n_vertices);
    CHECK(grids == gs->n_grids);
    return gs->n_vertices;
}

/* On screen, dicing follows the raster: a square facing the camera gets
 * the rate it had by distance, while a strip seen at a grazing angle is
 * diced across at the pixel rate and along the view as coarsely as its
 * few pixels of height (by distance it needed 10 micropolygons). */
static void test_raster_oriented_dicing(void)
{
    GridSet gs;
    DiceCamera cam = view_camera(4.0f);
    Prim face = bilinear(v3(-5, -5, 0), v3(5, -5, 0), v3(-5, 5, 0), v3(5, 5, 0));
    dice_vertices(&face, &cam, &gs);
    CHECK(gs.n_grids == 1 && gs.grids[0].nu == 11 && gs.grids[0].nv == 11);
    geom_gridset_fini(&gs);
    Prim strip = bilinear(v3(-5, -5, 0), v3(5, -5, 0), v3(-5, -5, 10), v3(5, -5, 10));
    dice_vertices(&strip, &cam, &gs);
    CHECK(gs.n_grids == 1);
    CHECK(gs.grids[0].nu == 11 && gs.grids[0].nv == 2);
    geom_gridset_fini(&gs);
    cam.has_view = 0; /* by distance: 10 units at 100 units away */
    dice_vertices(&strip, &cam, &gs);
    CHECK(gs.grids[0].nu == 11 && gs.grids[0].nv == 11);
    geom_gridset_fini(&gs);
}

/* Off screen and behind the eye, dicing is by distance with micropolygons
 * up to the off-screen factor longer; far beyond the frame the whole
 * factor applies. */
static void test_offscreen_dicing(void)
{
    GridSet gs;
    DiceCamera one = view_camera(1.0f), four = view_camera(4.0f);
    /* Beside the view: 300 units right of the axis, 100 ahead (the frame
     * ends at 50); nearest point at 255 units from the eye. */
    Prim side = bilinear(v3(245, -5, 0), v3(255, -5, 0), v3(245, 5, 0), v3(255, 5, 0));
    dice_vertices(&side, &one, &gs);
    CHECK(gs.grids[0].nu == 5 && gs.grids[0].nv == 5); /* 10 / 2.6 */
    geom_gridset_fini(&gs);
    dice_vertices(&side, &four, &gs);
    CHECK(gs.grids[0].nu == 2 && gs.grids[0].nv == 2); /* 10 / 10.4 */
    geom_gridset_fini(&gs);
    /* Behind the eye, 100 units back. */
    Prim back = bilinear(v3(-5, -5, -200), v3(5, -5, -200), v3(-5, 5, -200), v3(5, 5, -200));
    dice_vertices(&back, &one, &gs);
    CHECK(gs.grids[0].nu == 11);
    geom_gridset_fini(&gs);
    dice_vertices(&back, &four, &gs);
    CHECK(gs.grids[0].nu == 4 && gs.grids[0].nv == 4);
    geom_gridset_fini(&gs);
    /* Just outside the frame's edge the factor has barely grown. */
    Prim edge = bilinear(v3(52, -5, 0), v3(62, -5, 0), v3(52, 5, 0), v3(62, 5, 0));
    dice_vertices(&edge, &four, &gs);
    CHECK(gs.grids[0].nu >= 8);
    geom_gridset_fini(&gs);
}

/* A floor 1 km wide passing 1 unit below the eye, through the eye plane
 * and far behind: its vertices stay bounded (by distance near the eye
 * plane, the off-screen factor beside and behind), where a projection
 * would explode. */
static void test_floor_through_eye_plane(void)
{
    GridSet gs;
    DiceCamera cam = view_camera(4.0f);
    Prim floor =
        bilinear(v3(-500, -1, -600), v3(500, -1, -600), v3(-500, -1, 400), v3(500, -1, 400));
    size_t n = dice_vertices(&floor, &cam, &gs);
    CHECK(n > 1000 && n < 400000);
    for (size_t g = 0; g < gs.n_grids; g++)
        CHECK((int)(gs.grids[g].nu - 1) * (gs.grids[g].nv - 1) <= GEOM_GRID_SIZE);
    geom_gridset_fini(&gs);
}

/* The grids of a sliver: quads (fans, GridSub corner GEOM_FAN + apex) or
 * triangles; the number of fans. */
static size_t fans(const GridSet *gs)
{
    size_t n = 0;
    for (size_t g = 0; g < gs->n_grids; g++) {
        const Grid *gr = &gs->grids[g];
        n += !gr->triangular && gr->sub && gs->subs[gr->sub - 1].corner >= GEOM_FAN;
    }
    return n;
}

/* A long thin triangle (1000 x 1 units, one unit per micropolygon at its
 * nearest) is a needle: a fan from its short edge, diced along it at the
 * rate its length needs and once or twice across, in quads split along
 * it: 3,003 vertices where bisecting it across its long edge gave 39,687
 * and splitting in fours (which keeps it as thin) 198,336. */
static void test_thin_triangle(void)
{
    GridSet gs;
    Prim t = {.type = PRIM_TRIANGLE, .shading_rate = 1.0f};
    t.cp[0] = v3(-500, 0, 0), t.cp[1] = v3(500, 0, 0), t.cp[2] = v3(-500, 1, 0);
    DiceCamera cam = camera();
    size_t n = dice_vertices(&t, &cam, &gs);
    printf("  needle: %zu vertices, %zu grids, %zu fans\n", n, gs.n_grids, fans(&gs));
    CHECK(n > 1000 && n < 4000);
    CHECK(fans(&gs) == gs.n_grids);
    CHECK_NEAR(cell_area(&gs, 1.0f), 500.0, 0.01); /* the parts tile the triangle */
    geom_gridset_fini(&gs);
}

/* A cap (its apex a unit above the middle of a 1000-unit edge) is halved
 * across its long edge until its halves are needles, then fanned; a
 * sliver seen edge on but fat in space is not a sliver (its grid serves
 * rays that meet it face on). */
static void test_sliver_cap(void)
{
    GridSet gs;
    Prim t = {.type = PRIM_TRIANGLE, .shading_rate = 1.0f};
    t.cp[0] = v3(-500, 0, 0), t.cp[1] = v3(500, 0, 0), t.cp[2] = v3(30, 1, 0);
    DiceCamera cam = camera();
    size_t n = dice_vertices(&t, &cam, &gs);
    printf("  cap: %zu vertices, %zu grids, %zu fans\n", n, gs.n_grids, fans(&gs));
    CHECK(n > 1000 && n < 8000);
    CHECK(fans(&gs) >= 2 && fans(&gs) == gs.n_grids);
    CHECK_NEAR(cell_area(&gs, 1.0f), 500.0, 0.01);
    geom_gridset_fini(&gs);
    /* Seen edge on from (0, 0, -100): a line on the screen, a right
     * triangle of 10 x 10 units in space. */
    DiceCamera view = view_camera(4.0f);
    t.cp[0] = v3(-5, 0, -5), t.cp[1] = v3(5, 0, -5), t.cp[2] = v3(-5, 0, 5);
    dice_vertices(&t, &view, &gs);
    CHECK(fans(&gs) == 0);
    geom_gridset_fini(&gs);
}

/* Slivers that split deep (collinear corners, a cap a million units long
 * and a thousandth high, one far off its middle): dicing ends, with
 * bounded vertices, where a cap's split point came to need more bits
 * than the domain's floats hold (Bitterli's staircase hung there). */
static void test_degenerate_slivers(void)
{
    static const float c[][3][3] = {
        {{-1e6f, 0, 0}, {1e6f, 0, 0}, {3, 1e-3f, 0}},
        {{-1e6f, 0, 0}, {1e6f, 0, 0}, {999000, 1e-3f, 0}},
        {{-1e3f, 0, 0}, {1e3f, 0, 0}, {0.1f, 0, 0}},
        {{1, 1, 1}, {1, 1, 1 + 1e-6f}, {1, 1 + 1e-7f, 1 + 3e-7f}},
        {{-5e5f, 0, 0}, {5e5f, 0, 0}, {-4.99e5f, 2e-3f, 1e-3f}},
    };
    DiceCamera cam = camera();
    for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
        GridSet gs;
        Prim t = {.type = PRIM_TRIANGLE, .shading_rate = 1.0f};
        for (int i = 0; i < 3; i++)
            t.cp[i] = v3(c[k][i][0], c[k][i][1], c[k][i][2]);
        size_t n = dice_vertices(&t, &cam, &gs);
        printf("  degenerate sliver %zu: %zu vertices, %zu grids\n", k, n, gs.n_grids);
        CHECK(n < 20000000);
        geom_gridset_fini(&gs);
    }
    /* Random slivers: two corners up to 10^4 apart, the third near the
     * line between them (up to 10^-6 off it) or near one of them, at
     * every scale. */
    uint32_t r = 12345;
    size_t most = 0;
    for (int k = 0; k < 3000; k++) {
        float f[9];
        for (int i = 0; i < 9; i++) {
            r = r * 1664525u + 1013904223u;
            f[i] = (float)(r >> 8) / 16777216.0f;
        }
        float len = powf(10.0f, 4.0f * f[0]), off = powf(10.0f, -6.0f + 6.0f * f[1]);
        Prim t = {.type = PRIM_TRIANGLE, .shading_rate = 1.0f};
        t.cp[0] = v3(-len * f[2], 5 * f[3], 10 * f[4]);
        t.cp[1] = v3(t.cp[0].x + len, t.cp[0].y + off * f[5], t.cp[0].z);
        float at = k % 3 == 0 ? f[6] : k % 3 == 1 ? 1e-4f * f[6] : 1.0f - 1e-4f * f[6];
        t.cp[2] = v3(t.cp[0].x + len * at, t.cp[0].y + off * f[7], t.cp[0].z + off * f[8]);
        GridSet gs;
        size_t n = dice_vertices(&t, &cam, &gs);
        most = n > most ? n : most;
        geom_gridset_fini(&gs);
    }
    printf("  3000 random slivers: at most %zu vertices\n", most);
    CHECK(most < 1000000);
}

TEST_MAIN(TEST(test_bezier_basis), TEST(test_prim_is_small), TEST(test_bicubic_reproduces_bilinear),
          TEST(test_bilinear_known_values), TEST(test_sphere_eval_and_normal),
          TEST(test_degenerate_bicubic_normal), TEST(test_dicing_rate_from_camera),
          TEST(test_split_limits_grid_size), TEST(test_split_by_area), TEST(test_grid_size_option),
          TEST(test_distance_based_rates), TEST(test_triangle_grid_counts),
          TEST(test_raster_oriented_dicing), TEST(test_offscreen_dicing),
          TEST(test_floor_through_eye_plane), TEST(test_thin_triangle), TEST(test_sliver_cap),
          TEST(test_degenerate_slivers))
