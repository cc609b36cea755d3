/*
 * RenderMan's quadrics (rayes_scene_quadric): every diced vertex lies on
 * the analytic surface, within the swept angle and the profile's range;
 * normals point away from the axis (up for the disk) and turn with
 * RAYES_QUADRIC_REVERSE; the current transform places them; bad
 * parameters are refused with a message naming the shape.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

typedef struct Case {
    RayesQuadric type;
    float p[7];
    size_t n;
} Case;

static const Case cases[] = {
    {RAYES_QUADRIC_SPHERE, {2.0f, -1.0f, 1.5f, 270.0f}, 4},
    {RAYES_QUADRIC_CYLINDER, {1.5f, -1.0f, 2.0f, 360.0f}, 4},
    {RAYES_QUADRIC_CONE, {2.0f, 1.0f, 300.0f}, 3},
    {RAYES_QUADRIC_DISK, {0.5f, 1.5f, 360.0f}, 3},
    {RAYES_QUADRIC_PARABOLOID, {1.0f, 0.25f, 2.0f, 360.0f}, 4},
    {RAYES_QUADRIC_HYPERBOLOID, {1.0f, 0.0f, -1.0f, 0.0f, 1.0f, 1.0f, 360.0f}, 7},
    {RAYES_QUADRIC_TORUS, {2.0f, 0.5f, 0.0f, 360.0f, 180.0f}, 5},
};

/* How far object-space P is from the surface of c (0 on it). */
static double off_surface(const Case *c, Vec3 P)
{
    double x = P.x, y = P.y, z = P.z, rho = sqrt(x * x + y * y);
    const float *q = c->p;
    switch (c->type) {
    case RAYES_QUADRIC_SPHERE:
        return fabs(sqrt(x * x + y * y + z * z) - q[0]) + fmax(0.0, q[1] - z - 1e-4) +
               fmax(0.0, z - q[2] - 1e-4);
    case RAYES_QUADRIC_CYLINDER:
        return fabs(rho - q[0]) + fmax(0.0, q[1] - z - 1e-4) + fmax(0.0, z - q[2] - 1e-4);
    case RAYES_QUADRIC_CONE: /* rho = radius (1 - z / height) */
        return fabs(rho - q[1] * (1.0 - z / q[0]));
    case RAYES_QUADRIC_DISK:
        return fabs(z - q[0]) + fmax(0.0, rho - q[1] - 1e-4);
    case RAYES_QUADRIC_PARABOLOID:
        return fabs(rho * rho - q[0] * q[0] * z / q[2]);
    case RAYES_QUADRIC_HYPERBOLOID: /* the line (1 - t, t, -1 + 2t) swept */
    {
        double t = (z + 1.0) / 2.0;
        return fabs(rho * rho - ((1.0 - t) * (1.0 - t) + t * t));
    }
    case RAYES_QUADRIC_TORUS:
        return fabs(sqrt((rho - q[0]) * (rho - q[0]) + z * z) - q[1]);
    }
    return 1e9;
}

/* The outward direction at object-space P (away from the axis; up for the
 * disk; away from the tube's centre line for the torus). */
static Vec3 outward(const Case *c, Vec3 P)
{
    if (c->type == RAYES_QUADRIC_DISK)
        return v3(0, 0, 1);
    if (c->type == RAYES_QUADRIC_SPHERE)
        return P;
    double rho = sqrt(P.x * P.x + P.y * P.y);
    if (c->type == RAYES_QUADRIC_TORUS && rho > 0)
        return v3((float)(P.x - c->p[0] * P.x / rho), (float)(P.y - c->p[0] * P.y / rho), P.z);
    return v3(P.x, P.y, 0);
}

static void check_case(const Case *c, unsigned flags, float tx)
{
    RayesScene *s = rayes_scene_new();
    const float m[16] = {1, 0, 0, tx, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    CHECK(rayes_scene_quadric(s, c->type, c->p, c->n, flags) == RAYES_OK);
    const float eye[3] = {tx, -12, 3}, target[3] = {tx, 0, 0}, up[3] = {0, 0, 1};
    CHECK(rayes_scene_set_camera(s, eye, target, up, 40.0f) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    GridSet gs;
    geom_gridset_init(&gs);
    CHECK(scene_prepare(s, 64, 64, NULL, NULL, &gs, NULL, NULL, 0) == 0);
    CHECK(gs.n_vertices > 16);
    double worst = 0.0, theta_max = 0.0;
    size_t inward = 0, judged = 0;
    for (size_t i = 0; i < gs.n_vertices; i++) {
        Vec3 P = v3(gs.P[i].x - tx, gs.P[i].y, gs.P[i].z);
        worst = fmax(worst, off_surface(c, P));
        double th = atan2(P.y, P.x);
        if (th < -1e-4)
            th += 2.0 * M_PI;
        if (P.x * P.x + P.y * P.y > 1e-6)
            theta_max = fmax(theta_max, th);
        Vec3 o = outward(c, P);
        if (v3_length(o) > 1e-3f && fabs(P.x * P.x + P.y * P.y) > 1e-3) {
            judged++;
            float d = v3_dot(gs.N[i], v3_normalize(o));
            if ((flags & RAYES_QUADRIC_REVERSE) ? d > 0.0f : d < 0.0f)
                inward++;
        }
    }
    const char *names[] = {"sphere", "cylinder", "cone", "disk", "paraboloid", "hyperboloid", "torus"};
    if (worst > 2e-3 || inward > 0)
        fprintf(stderr, "  %s flags %u: %.2g off the surface, %zu of %zu normals the wrong way\n",
                names[c->type], flags, worst, inward, judged);
    CHECK(worst < 2e-3);
    CHECK(judged > 8);
    CHECK(inward == 0);
    float sweep = c->p[c->n - 1] * (float)(M_PI / 180.0);
    CHECK(theta_max <= sweep + 1e-3);
    CHECK(theta_max > sweep - 0.3);
    geom_gridset_fini(&gs);
    rayes_scene_release(s);
}

static void test_quadrics_on_their_surfaces(void)
{
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        check_case(&cases[k], 0, 0.0f);
        check_case(&cases[k], RAYES_QUADRIC_REVERSE, 5.0f);
    }
}

static void test_bad_quadrics(void)
{
    RayesScene *s = rayes_scene_new();
    const float p3[3] = {1, 1, 360}, zero_radius[4] = {0, -1, 1, 360},
                no_sweep[4] = {1, -1, 1, 0}, flat_cyl[4] = {1, 2, 2, 360};
    CHECK(rayes_scene_quadric(s, RAYES_QUADRIC_SPHERE, p3, 3, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "sphere: expected 4") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_quadric(s, RAYES_QUADRIC_SPHERE, zero_radius, 4, 0) != RAYES_OK);
    CHECK(strstr(rayes_scene_get_error(s), "positive radius") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_quadric(s, RAYES_QUADRIC_CYLINDER, no_sweep, 4, 0) != RAYES_OK);
    CHECK(strstr(rayes_scene_get_error(s), "thetamax") != NULL);
    rayes_scene_clear_error(s);
    CHECK(rayes_scene_quadric(s, RAYES_QUADRIC_CYLINDER, flat_cyl, 4, 0) != RAYES_OK);
    CHECK(rayes_scene_quadric(s, (RayesQuadric)42, p3, 3, 0) != RAYES_OK);
    CHECK(s->n_prims == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_quadrics_on_their_surfaces), TEST(test_bad_quadrics))
