/* Embree hits on known geometry (accel/). */
#include "accel/accel.h"

#include <math.h>
#include <string.h>

#include "rayes/shader.h"
#include "test.h"
#include "util/thread.h"

static GridSet scene(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    DiceCamera cam = {.eye = v3(0, 0, -100), .pixel_angle = 0.01f, .min_distance = 1e-3f};
    /* Object 0: a 10 x 10 square at z = 0 (one 11 x 11 grid). */
    Prim quad = {.type = PRIM_BILINEAR, .object = 0, .shading_rate = 1.0f};
    quad.cp[0] = v3(-5, -5, 0), quad.cp[1] = v3(5, -5, 0), quad.cp[2] = v3(-5, 5, 0),
    quad.cp[3] = v3(5, 5, 0);
    geom_dice_prim(&gs, &quad, 0, NULL, &cam);
    /* Object 1: a triangle at z = 10 behind it, off to the side. */
    Prim tri = {.type = PRIM_TRIANGLE, .object = 1, .shading_rate = 1.0f};
    tri.cp[0] = v3(20, 0, 10), tri.cp[1] = v3(28, 0, 10), tri.cp[2] = v3(20, 8, 10);
    geom_dice_prim(&gs, &tri, 1, NULL, &cam);
    return gs;
}

static void test_quad_grid_hit(void)
{
    GridSet gs = scene();
    uint32_t masks[2] = {RAYES_RAY_CAMERA | RAYES_RAY_SHADOW, RAYES_RAY_CAMERA};
    char err[256];
    Accel *a = accel_new(&gs, masks, 2, NULL, err, sizeof err);
    CHECK(a != NULL);
    if (!a)
        return;
    Ray r = {v3(2.5f, -1.25f, -10), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_CAMERA};
    Hit h;
    CHECK(accel_intersect(a, &r, &h));
    CHECK(h.grid == 0);
    CHECK_NEAR(h.t, 10.0, 1e-4);
    CHECK_NEAR(h.gu, 0.75, 1e-5);    /* (2.5 + 5) / 10 */
    CHECK_NEAR(h.gv, 0.375, 1e-5);   /* (-1.25 + 5) / 10 */
    CHECK(h.n_vertex == 4);
    /* The weights reproduce the hit point. */
    Vec3 P = v3(0, 0, 0);
    float wsum = 0.0f;
    for (int k = 0; k < 4; k++) {
        P = v3_madd(P, gs.P[h.vertex[k]], h.weight[k]);
        wsum += h.weight[k];
    }
    CHECK_NEAR(wsum, 1.0, 1e-6);
    CHECK_NEAR(P.x, 2.5, 1e-4);
    CHECK_NEAR(P.y, -1.25, 1e-4);
    CHECK_NEAR(fabsf(h.Ng.z), 1.0, 1e-5);
    CHECK(h.Ng.z > 0.0f); /* dPdu x dPdv = +z */
    /* Misses, segments and masks. */
    Ray miss = {v3(6, 0, -10), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_CAMERA};
    CHECK(!accel_intersect(a, &miss, &h));
    Ray shorty = {v3(0, 0, -10), v3(0, 0, 1), 0.0f, 9.0f, RAYES_RAY_CAMERA};
    CHECK(!accel_occluded(a, &shorty));
    Ray through = {v3(0, 0, -10), v3(0, 0, 1), 0.0f, 11.0f, RAYES_RAY_SHADOW};
    CHECK(accel_occluded(a, &through));
    Ray diffuse = {v3(0, 0, -10), v3(0, 0, 1), 0.0f, 11.0f, RAYES_RAY_DIFFUSE};
    CHECK(!accel_occluded(a, &diffuse)); /* object 0 is invisible to diffuse rays */
    accel_free(a);
    geom_gridset_fini(&gs);
}

static void test_triangle_grid_hit(void)
{
    GridSet gs = scene();
    uint32_t masks[2] = {RAYES_RAY_CAMERA, RAYES_RAY_CAMERA};
    char err[256];
    Accel *a = accel_new(&gs, masks, 2, NULL, err, sizeof err);
    CHECK(a != NULL);
    if (!a)
        return;
    Ray r = {v3(22, 2, 0), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_CAMERA};
    Hit h;
    CHECK(accel_intersect(a, &r, &h));
    CHECK(h.grid == 1);
    CHECK(h.n_vertex == 3);
    CHECK_NEAR(h.t, 10.0, 1e-4);
    CHECK_NEAR(h.gu, 0.25, 1e-4); /* barycentrics of the patch: (22-20)/8, (2-0)/8 */
    CHECK_NEAR(h.gv, 0.25, 1e-4);
    Vec3 P = v3(0, 0, 0);
    for (int k = 0; k < 3; k++)
        P = v3_madd(P, gs.P[h.vertex[k]], h.weight[k]);
    CHECK_NEAR(P.x, 22.0, 1e-4);
    CHECK_NEAR(P.y, 2.0, 1e-4);
    CHECK(h.Ng.z > 0.99f);
    /* The flat triangle is traced as one (its micro-triangles found from
     * the barycentrics): lower and upper ones, and along the hypotenuse,
     * each hit's weights reproduce it. */
    for (int k = 0; k < 64; k++) {
        float x = 20.0f + 7.99f * (float)(k % 8) / 7.0f, y = 0.01f + 7.9f * (float)(k / 8) / 8.0f;
        if (x - 20.0f + y > 7.99f)
            y = 7.99f - (x - 20.0f);
        Ray rk = {v3(x, y, 0), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_CAMERA};
        if (!accel_intersect(a, &rk, &h)) {
            CHECK(!"a hit inside the triangle");
            continue;
        }
        Vec3 Pk = v3(0, 0, 0);
        float wsum = 0.0f;
        for (int c = 0; c < 3; c++) {
            Pk = v3_madd(Pk, gs.P[h.vertex[c]], h.weight[c]);
            wsum += h.weight[c];
            CHECK(h.weight[c] >= -1e-5f);
        }
        CHECK_NEAR(wsum, 1.0, 1e-5);
        CHECK_NEAR(Pk.x, x, 1e-4);
        CHECK_NEAR(Pk.y, y, 1e-4);
        CHECK_NEAR(h.gu, (x - 20.0f) / 8.0f, 1e-4);
        CHECK_NEAR(h.gv, y / 8.0f, 1e-4);
    }
    accel_free(a);
    geom_gridset_fini(&gs);
}

/* Hits from several threads agree with hits from one (queries are
 * concurrent-safe once built). */
typedef struct Par {
    const Accel *a;
    int mismatches;
} Par;

static void par_task(void *ctx, size_t task, int worker)
{
    (void)worker;
    Par *p = ctx;
    float x = -4.9f + 9.8f * (float)(task % 100) / 99.0f, y = -4.9f + 9.8f * (float)(task / 100) / 99.0f;
    Ray r = {v3(x, y, -10), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_CAMERA};
    Hit h;
    if (!accel_intersect(p->a, &r, &h) || fabsf(h.t - 10.0f) > 1e-3f)
        __atomic_add_fetch(&p->mismatches, 1, __ATOMIC_RELAXED);
}

static void test_concurrent_queries(void)
{
    GridSet gs = scene();
    uint32_t masks[2] = {RAYES_RAY_CAMERA, RAYES_RAY_CAMERA};
    char err[256];
    Accel *a = accel_new(&gs, masks, 2, NULL, err, sizeof err);
    Par p = {a, 0};
    thread_parallel_for(4, 10000, par_task, &p);
    CHECK(p.mismatches == 0);
    accel_free(a);
    geom_gridset_fini(&gs);
}

/* A transmission query's crossings: each hit as accel_intersect finds it,
 * but for Ng, which accel_crossing_normal adds; each opacity multiplies. */
typedef struct Crossings {
    int n, no_normal;
    Hit hit[2];
} Crossings;

static Vec3 half_clear(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing)
{
    Crossings *c = user;
    if (hit->Ng.x == 0.0f && hit->Ng.y == 0.0f && hit->Ng.z == 0.0f)
        c->no_normal++; /* left out: nothing but the opacity lookup's fields */
    accel_crossing_normal(crossing, hit);
    if (c->n < 2)
        c->hit[c->n] = *hit;
    c->n++;
    (void)ray;
    return v3(0.5f, 0.25f, 0.0f);
}

/* The scene's two objects under masks m0 and m1. */
static Accel *with_masks(const GridSet *gs, uint32_t m0, uint32_t m1)
{
    uint32_t masks[2] = {m0, m1};
    char err[256];
    Accel *a = accel_new(gs, masks, 2, NULL, err, sizeof err);
    CHECK(a != NULL);
    return a;
}

/* The scene's two objects under one mask. */
static Accel *both_with_mask(const GridSet *gs, uint32_t mask)
{
    return with_masks(gs, mask, mask);
}

static void test_transmission_crossings(void)
{
    GridSet gs = scene();
    Accel *a = both_with_mask(&gs, RAYES_RAY_SHADOW | RAYES_RAY_CAMERA | ACCEL_MASK_TRANSPARENT);
    if (!a)
        return;
    /* the square (grid 0) at t = 10, then a miss of the triangle; and
     * the triangle (grid 1) alone */
    const Ray rays[2] = {{v3(2.5f, -1.25f, -10), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_SHADOW},
                         {v3(22, 2, 0), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_SHADOW}};
    for (int k = 0; k < 2; k++) {
        Crossings c = {0};
        Vec3 T = accel_transmission(a, &rays[k], half_clear, &c, 0.0f);
        CHECK(c.n == 1);
        CHECK(c.no_normal == 1);
        CHECK_NEAR(T.x, 0.5, 1e-6);
        CHECK_NEAR(T.y, 0.75, 1e-6);
        CHECK_NEAR(T.z, 1.0, 1e-6);
        Ray camera = rays[k];
        camera.mask = RAYES_RAY_CAMERA;
        Hit h;
        CHECK(accel_intersect(a, &camera, &h));
        CHECK(c.hit[0].grid == h.grid && c.hit[0].n_vertex == h.n_vertex);
        CHECK(c.hit[0].t == h.t && c.hit[0].gu == h.gu && c.hit[0].gv == h.gv);
        CHECK(c.hit[0].Ng.x == h.Ng.x && c.hit[0].Ng.y == h.Ng.y && c.hit[0].Ng.z == h.Ng.z);
        CHECK(memcmp(c.hit[0].vertex, h.vertex, sizeof h.vertex) == 0);
        CHECK(memcmp(c.hit[0].weight, h.weight, sizeof h.weight) == 0);
    }
    accel_free(a);
    geom_gridset_fini(&gs);
}

/* A hit in an object's own scene is the world's, its Ng Embree's. */
static void test_own_scene_hits(void)
{
    GridSet gs = scene();
    Accel *a = both_with_mask(&gs, RAYES_RAY_CAMERA | RAYES_RAY_SUBSURFACE | ACCEL_MASK_OWN_SCENE);
    if (!a)
        return;
    const Ray rays[4] = {{v3(2.5f, -1.25f, -10), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_SUBSURFACE},
                         {v3(2.5f, -1.25f, 10), v3(0.1f, 0, -1), 0.0f, 1e9f, RAYES_RAY_SUBSURFACE},
                         {v3(22, 2, 0), v3(0, 0, 1), 0.0f, 1e9f, RAYES_RAY_SUBSURFACE},
                         {v3(22, 2, 20), v3(0, 0.1f, -1), 0.0f, 1e9f, RAYES_RAY_SUBSURFACE}};
    for (int k = 0; k < 4; k++) {
        Hit own, world;
        uint32_t object = k < 2 ? 0 : 1;
        CHECK(accel_intersect_object(a, object, &rays[k], &own));
        CHECK(!accel_intersect_object(a, 1 - object, &rays[k], &world)); /* the other's */
        CHECK(accel_intersect(a, &rays[k], &world));
        CHECK(own.grid == world.grid && own.n_vertex == world.n_vertex && own.t == world.t);
        CHECK(own.gu == world.gu && own.gv == world.gv);
        CHECK(v3_dot(own.Ng, world.Ng) > 0.9999f);
    }
    accel_free(a);
    geom_gridset_fini(&gs);
}

/* A stop asked cancels the build: NULL, "render: cancelled"; a stop
 * flag at 0 builds. */
static void test_stop_cancels_build(void)
{
    GridSet gs = scene();
    uint32_t masks[2] = {RAYES_RAY_CAMERA, RAYES_RAY_CAMERA};
    char err[256] = "";
    volatile int stop = 1, go = 0;
    CHECK(accel_new(&gs, masks, 2, &stop, err, sizeof err) == NULL);
    CHECK(strcmp(err, "render: cancelled") == 0);
    Accel *a = accel_new(&gs, masks, 2, &go, err, sizeof err);
    CHECK(a != NULL);
    accel_free(a);
    geom_gridset_fini(&gs);
}

/* Four transparent 10 x 10 squares (object 0) stacked at z = 1, 2, 3, 4,
 * and an opaque one (object 1) at z = 5. */
static GridSet stack(void)
{
    GridSet gs;
    geom_gridset_init(&gs);
    DiceCamera cam = {.eye = v3(0, 0, -100), .pixel_angle = 0.01f, .min_distance = 1e-3f};
    for (int k = 1; k <= 5; k++) {
        float z = (float)k;
        Prim quad = {.type = PRIM_BILINEAR, .object = k == 5, .shading_rate = 1.0f};
        quad.cp[0] = v3(-5, -5, z), quad.cp[1] = v3(5, -5, z), quad.cp[2] = v3(-5, 5, z),
        quad.cp[3] = v3(5, 5, z);
        geom_dice_prim(&gs, &quad, (uint32_t)k - 1, NULL, &cam);
    }
    return gs;
}

static float keep_p(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing)
{
    (void)ray, (void)hit, (void)crossing;
    return *(const float *)user;
}

static Vec3 opacity_p(void *user, const Ray *ray, Hit *hit, const AccelCrossing *crossing)
{
    (void)ray, (void)hit, (void)crossing;
    float p = *(const float *)user;
    return v3(p, 0.5f * p, 0.25f * p); /* coloured: red the most opaque */
}

static Ray stack_ray(int i, uint32_t mask)
{
    float x = -4.9f + 9.8f * (float)(i % 97) / 97.0f, y = -4.9f + 9.8f * (float)(i / 97) / 97.0f;
    return (Ray){v3(x, y, 0), v3(0.01f, 0, 1), 0.0f, 1e9f, mask};
}

/* Kept with probability p, the layer a ray stops at is k with probability
 * p (1 - p)^k (the weight compositing gives it), the opaque square behind
 * when all pass; the same ray and key stop at the same layer; p 1 is
 * accel_intersect and p 0 passes every layer. */
static void test_intersect_stochastic(void)
{
    GridSet gs = stack();
    Accel *a = with_masks(&gs, RAYES_RAY_DIFFUSE | ACCEL_MASK_TRANSPARENT, RAYES_RAY_DIFFUSE);
    if (!a)
        return;
    enum { N = 97 * 97 };
    float p = 0.4f;
    int at[5] = {0};
    for (int i = 0; i < N; i++) {
        Ray r = stack_ray(i, RAYES_RAY_DIFFUSE);
        Hit h, again, plain;
        CHECK(accel_intersect_stochastic(a, &r, keep_p, &p, (uint64_t)i, &h));
        CHECK(accel_intersect_stochastic(a, &r, keep_p, &p, (uint64_t)i, &again));
        CHECK(h.grid == again.grid && h.t == again.t);
        int layer = (int)lrintf(r.o.z + h.t * r.d.z) - 1;
        CHECK(layer >= 0 && layer < 5);
        at[layer < 0 ? 0 : layer > 4 ? 4 : layer]++;
        float one = 1.0f, zero = 0.0f;
        CHECK(accel_intersect_stochastic(a, &r, keep_p, &one, (uint64_t)i, &h));
        CHECK(accel_intersect(a, &r, &plain));
        CHECK(h.grid == plain.grid && h.t == plain.t && h.gu == plain.gu && h.gv == plain.gv);
        CHECK(accel_intersect_stochastic(a, &r, keep_p, &zero, (uint64_t)i, &h));
        CHECK_NEAR(r.o.z + h.t * r.d.z, 5.0, 1e-3);
    }
    for (int k = 0; k < 5; k++) {
        double expect = (k < 4 ? p : 1.0) * pow(1.0 - p, k);
        /* binomial: within 4 standard deviations */
        CHECK_NEAR(at[k] / (double)N, expect, 4.0 * sqrt(expect * (1.0 - expect) / N));
    }
    accel_free(a);
    geom_gridset_fini(&gs);
}

/* Past the roulette threshold a transmission query's crossings end it or
 * are rescaled: the mean over rays is the product through the four
 * layers (the opaque square is seen by no shadow ray), each ray's answer
 * is the same asked again, and threshold 0 multiplies every crossing. */
static void test_transmission_roulette(void)
{
    GridSet gs = stack();
    Accel *a = with_masks(&gs, RAYES_RAY_SHADOW | ACCEL_MASK_TRANSPARENT, 0);
    if (!a)
        return;
    enum { N = 97 * 97 };
    float p = 0.4f;
    double mean[3] = {0, 0, 0};
    int stopped = 0;
    for (int i = 0; i < N; i++) {
        Ray r = stack_ray(i, RAYES_RAY_SHADOW);
        Vec3 T = accel_transmission(a, &r, opacity_p, &p, 0.85f);
        Vec3 again = accel_transmission(a, &r, opacity_p, &p, 0.85f);
        CHECK(T.x == again.x && T.y == again.y && T.z == again.z);
        Vec3 exact = accel_transmission(a, &r, opacity_p, &p, 0.0f);
        CHECK_NEAR(exact.x, pow(0.6, 4), 1e-6);
        CHECK_NEAR(exact.y, pow(0.8, 4), 1e-6);
        CHECK_NEAR(exact.z, pow(0.9, 4), 1e-6);
        stopped += T.y == 0.0f;
        mean[0] += T.x / N, mean[1] += T.y / N, mean[2] += T.z / N;
    }
    /* the largest component, blue's, falls below 0.85 after two crossings
     * (0.81): the last two each end a ray with probability 0.1 */
    fprintf(stderr, "roulette: means %g %g %g, exact %g %g %g; %d of %d stopped\n", mean[0],
            mean[1], mean[2], pow(0.6, 4), pow(0.8, 4), pow(0.9, 4), stopped, N);
    CHECK_NEAR(stopped / (double)N, 1.0 - 0.81, 0.02);
    CHECK_NEAR(mean[0] / pow(0.6, 4), 1.0, 0.02);
    CHECK_NEAR(mean[1] / pow(0.8, 4), 1.0, 0.02);
    CHECK_NEAR(mean[2] / pow(0.9, 4), 1.0, 0.02);
    accel_free(a);
    geom_gridset_fini(&gs);
}

TEST_MAIN(TEST(test_stop_cancels_build), TEST(test_quad_grid_hit), TEST(test_triangle_grid_hit),
          TEST(test_concurrent_queries), TEST(test_transmission_crossings),
          TEST(test_own_scene_hits), TEST(test_intersect_stochastic),
          TEST(test_transmission_roulette))
