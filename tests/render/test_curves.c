/*
 * Curves and points (rayes_scene_curves, rayes_scene_points; geom, accel):
 * rays hit a tube where its analytic centre line and width say, and miss
 * it just outside; flat curves face the ray; a B-spline and a Catmull-Rom
 * curve's diced centre line lies on the curve their basis defines; widths
 * vary along segments; spheres and disks are hit at their analytic
 * distance; bad counts are refused with a message; a field of 100,000
 * hairs renders with its diffuse rays reading the radiosity cache; the
 * hair shader's fibre lighting follows Kajiya-Kay's sin(T, L).
 */
#include <math.h>
#include <string.h>

#include "accel/accel.h"
#include "rayes/rayes.h"
#include "scene/scene.h"
#include "test.h"

/* The camera looks down -z from z = 5 at the origin. */
static RayesScene *new_scene(void)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 0, 5}, at[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40.0f) == RAYES_OK);
    return s;
}

/* Preview options: size x size pixels, 4 samples, 2 threads. */
static RayesRenderOptions preview(int size)
{
    RayesRenderOptions o;
    rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
    o.width = o.height = size;
    o.spp = 4;
    o.threads = 2;
    return o;
}

typedef struct Traced {
    GridSet gs;
    Accel *accel;
} Traced;

static void trace_init(Traced *t, RayesScene *s)
{
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    geom_gridset_init(&t->gs);
    CHECK(scene_prepare(s, 256, 256, NULL, NULL, &t->gs, NULL, NULL, 0) == 0);
    uint32_t mask[4] = {~0u, ~0u, ~0u, ~0u};
    char err[256];
    t->accel = accel_new(&t->gs, mask, 4, NULL, err, sizeof err);
    CHECK(t->accel != NULL);
}

static void trace_fini(Traced *t)
{
    accel_free(t->accel);
    geom_gridset_fini(&t->gs);
}

static int hit_along(const Traced *t, Vec3 o, Vec3 d, Hit *h)
{
    Ray r = {o, d, 0.0f, INFINITY, ~0u};
    return t->accel && accel_intersect(t->accel, &r, h);
}

/* A round tube along x (a linear curve from -1 to 1, width 0.2): rays
 * down -z at (x, y) hit at z = sqrt(r^2 - y^2), miss beyond r. */
static void test_round_tube_hits(void)
{
    RayesScene *s = new_scene();
    const float P[6] = {-1, 0, 0, 1, 0, 0};
    const int nv = 2;
    RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1, .n_verts = &nv, .P = P};
    const float w = 0.2f;
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &w, 1};
    CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
    Traced t;
    trace_init(&t, s);
    CHECK(t.gs.n_grids >= 1 && t.gs.grids[0].shape == GEOM_SHAPE_ROUND_CURVE &&
          t.gs.grids[0].nv == 2);
    float worst = 0.0f;
    for (int i = 0; i <= 20; i++) {
        float x = -0.9f + 1.8f * (float)i / 20.0f;
        for (int j = -4; j <= 4; j++) {
            float y = 0.0225f * (float)j; /* within 0.9 r */
            Hit h;
            int got = hit_along(&t, v3(x, y, 5), v3(0, 0, -1), &h);
            CHECK(got);
            if (got)
                worst = fmaxf(worst, fabsf((5.0f - h.t) - sqrtf(0.01f - y * y)));
            if (got && j == 0)
                CHECK(h.Ng.z > 0.99f && h.shape == GEOM_SHAPE_ROUND_CURVE);
            /* across the width: the hair BSDF's h = y / r as v = (h + 1) / 2 */
            if (got)
                CHECK(fabsf(h.gv - 0.5f * (y / 0.1f + 1.0f)) < 0.01f);
        }
        Hit h;
        CHECK(!hit_along(&t, v3(x, 0.105f, 5), v3(0, 0, -1), &h));
        CHECK(!hit_along(&t, v3(x, -0.105f, 5), v3(0, 0, -1), &h));
    }
    CHECK(worst < 1e-4f);
    /* Along the grid: the hit's position runs with x. */
    Hit a, b;
    CHECK(hit_along(&t, v3(-0.5f, 0, 5), v3(0, 0, -1), &a));
    CHECK(hit_along(&t, v3(0.5f, 0, 5), v3(0, 0, -1), &b));
    CHECK(a.grid != b.grid || a.gu < b.gu);
    trace_fini(&t);
    rayes_scene_release(s);
}

/* A flat curve faces the ray: seen from the side it is as wide. */
static void test_flat_faces_ray(void)
{
    RayesScene *s = new_scene();
    const float P[6] = {0, -1, 0, 0, 1, 0};
    const int nv = 2;
    RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_FLAT, .n_curves = 1, .n_verts = &nv, .P = P};
    const float w[2] = {0.2f, 0.4f}; /* varying: wider at the top */
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_VARYING, w, 2};
    CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
    Traced t;
    trace_init(&t, s);
    Hit h;
    /* From +x at y = 0 (width 0.3): hit within 0.15 of the axis, not beyond. */
    CHECK(hit_along(&t, v3(5, 0, 0.14f), v3(-1, 0, 0), &h));
    CHECK(fabsf(h.gv - 0.5f * (0.14f / 0.15f + 1.0f)) < 0.01f || /* across, either way */
          fabsf(h.gv - 0.5f * (1.0f - 0.14f / 0.15f)) < 0.01f);
    CHECK(!hit_along(&t, v3(5, 0, 0.16f), v3(-1, 0, 0), &h));
    CHECK(hit_along(&t, v3(5, 0.9f, 0.185f), v3(-1, 0, 0), &h)); /* width 0.39 there */
    CHECK(!hit_along(&t, v3(5, -0.9f, 0.185f), v3(-1, 0, 0), &h));
    trace_fini(&t);
    rayes_scene_release(s);
}

static void eval_basis(const float B[16], const float g[4], float t, float *out)
{
    float T[4] = {t * t * t, t * t, t, 1.0f};
    *out = 0.0f;
    for (int r = 0; r < 4; r++)
        for (int j = 0; j < 4; j++)
            *out += T[r] * B[4 * r + j] * g[j];
}

/* B-spline and Catmull-Rom curves: the prims' centre lines are the
 * curves of their bases. */
static void test_bases(void)
{
    const float *bases[2] = {rayes_basis_bspline, rayes_basis_catmull_rom};
    for (int b = 0; b < 2; b++) {
        RayesScene *s = new_scene();
        float P[18];
        for (int i = 0; i < 6; i++)
            P[3 * i] = (float)i * 0.3f, P[3 * i + 1] = 0.4f * sinf((float)i), P[3 * i + 2] = 0.1f * i;
        const int nv = 6;
        RayesCurves c = {.degree = 3, .step = 1, .n_curves = 1, .n_verts = &nv, .P = P};
        memcpy(c.basis, bases[b], sizeof c.basis);
        CHECK(rayes_scene_curves(s, &c, NULL, 0) == RAYES_OK);
        CHECK(s->n_prims == 1 && s->prims[0].curve.n_seg == 3); /* one run */
        float worst = 0.0f;
        for (int k = 0; k < 3 && s->n_prims == 1; k++)
            for (int q = 0; q <= 8; q++) {
                float t = (float)q / 8.0f, w, dw;
                Vec3 C, T, B;
                geom_curve_frame(&s->prims[0], ((float)k + t) / 3.0f, &C, &T, &w, &dw, &B);
                CHECK_NEAR(w, 1.0f, 1e-6); /* RenderMan's default width */
                float want[3];
                for (int axis = 0; axis < 3; axis++) {
                    float g[4] = {P[3 * k + axis], P[3 * (k + 1) + axis], P[3 * (k + 2) + axis],
                                  P[3 * (k + 3) + axis]};
                    eval_basis(bases[b], g, t, &want[axis]);
                }
                worst = fmaxf(worst, v3_length(v3_sub(C, v3_load(want))));
            }
        CHECK(worst < 1e-5f);
        rayes_scene_release(s);
    }
}

/* A Hermite curve (RenderMan's basis: points and tangents, step 2) under
 * a translation: the tangents are not moved, only the curve. */
static void test_hermite_translated(void)
{
    static const float hermite[16] = {2, 1, -2, 1, -3, -2, 3, -1, 0, 1, 0, 0, 1, 0, 0, 0};
    RayesScene *s = new_scene();
    const float m[16] = {1, 0, 0, 10, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; /* row-major */
    CHECK(rayes_scene_set_transform(s, m) == RAYES_OK);
    const float P[12] = {0, 0, 0, 3, 0, 0, 1, 0, 0, 3, 0, 0}; /* P0 T0 P1 T1 */
    const int nv = 4;
    RayesCurves c = {.degree = 3, .step = 2, .n_curves = 1, .n_verts = &nv, .P = P};
    memcpy(c.basis, hermite, sizeof c.basis);
    CHECK(rayes_scene_curves(s, &c, NULL, 0) == RAYES_OK);
    CHECK(s->n_prims == 1);
    if (s->n_prims == 1) { /* Bezier: P0, P0 + T0 / 3, P1 - T1 / 3, P1 */
        CHECK_NEAR(s->prims[0].big->curve.cp[0].x, 10.0, 1e-5);
        CHECK_NEAR(s->prims[0].big->curve.cp[1].x, 11.0, 1e-5);
        CHECK_NEAR(s->prims[0].big->curve.cp[2].x, 10.0, 1e-5);
        CHECK_NEAR(s->prims[0].big->curve.cp[3].x, 11.0, 1e-5);
    }
    rayes_scene_release(s);
}

/* Spheres and disks at their analytic distance; N makes oriented disks. */
static void test_points(void)
{
    RayesScene *s = new_scene();
    const float P[6] = {-1, 0, 0, 1, 0, 0}, w[2] = {0.5f, 0.3f};
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_VARYING, w, 2};
    CHECK(rayes_scene_points(s, RAYES_POINT_SPHERE, 2, P, &pv, 1) == RAYES_OK);
    const float Q[3] = {0, 1, 0};
    const float qw = 0.4f, qn[3] = {0, 0, 1};
    RayesPrimvar qv[2] = {{"constantwidth", RAYES_PRIMVAR_CONSTANT, &qw, 1},
                          {"width", RAYES_PRIMVAR_CONSTANT, &qw, 1}};
    CHECK(rayes_scene_points(s, RAYES_POINT_DISK, 1, Q, qv, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "constantwidth") != NULL);
    rayes_scene_clear_error(s);
    RayesPrimvar dv[2] = {qv[1], {"N", RAYES_PRIMVAR_CONSTANT, qn, 1}};
    CHECK(rayes_scene_points(s, RAYES_POINT_DISK, 1, Q, dv, 2) == RAYES_OK);
    Traced t;
    trace_init(&t, s);
    Hit h;
    CHECK(hit_along(&t, v3(-1, 0.1f, 5), v3(0, 0, -1), &h));
    CHECK_NEAR(5.0f - h.t, sqrtf(0.0625f - 0.01f), 1e-4);
    CHECK(h.shape == GEOM_SHAPE_SPHERE && h.Ng.z > 0.9f);
    CHECK(hit_along(&t, v3(1, 0, 5), v3(0, 0, -1), &h));
    CHECK_NEAR(5.0f - h.t, 0.15f, 1e-4);
    CHECK(!hit_along(&t, v3(1, 0.16f, 5), v3(0, 0, -1), &h));
    /* The oriented disk lies in z = 0: hit at t = 5, radius 0.2. */
    CHECK(hit_along(&t, v3(0.1f, 1.1f, 5), v3(0, 0, -1), &h));
    CHECK_NEAR(h.t, 5.0f, 1e-4);
    CHECK(!hit_along(&t, v3(0.2f, 1.2f, 5), v3(0, 0, -1), &h));
    trace_fini(&t);
    rayes_scene_release(s);
}

static void test_bad_input(void)
{
    RayesScene *s = new_scene();
    float P[15] = {0};
    int nv = 5;
    RayesCurves c = {.degree = 3, .step = 3, .n_curves = 1, .n_verts = &nv, .P = P};
    memcpy(c.basis, rayes_basis_bezier, sizeof c.basis);
    CHECK(rayes_scene_curves(s, &c, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "no whole segments") != NULL);
    rayes_scene_clear_error(s);
    nv = 4;
    float w[3] = {1, 1, 1};
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_VARYING, w, 3}; /* 2 segment ends */
    CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(strstr(rayes_scene_get_error(s), "expected 2") != NULL);
    rayes_scene_clear_error(s);
    pv.count = 2, w[1] = -1.0f;
    CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_ERROR_INVALID_ARGUMENT);
    rayes_scene_clear_error(s);
    c.degree = 2;
    CHECK(rayes_scene_curves(s, &c, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    P[4] = NAN;
    CHECK(rayes_scene_points(s, RAYES_POINT_SPHERE, 5, P, NULL, 0) == RAYES_ERROR_INVALID_ARGUMENT);
    CHECK(s->n_prims == 0);
    rayes_scene_release(s);
}

static uint32_t lcg(uint32_t *x)
{
    *x = *x * 1664525u + 1013904223u;
    return *x >> 8;
}

/* 100,000 hairs on a floor under a light, 1 bounce: the diffuse rays
 * that hit hairs read the cache. */
static void test_hair_field_caches(void)
{
    RayesScene *s = rayes_scene_new();
    const float eye[3] = {0, 1.2f, 3}, at[3] = {0, 0.1f, 0}, up[3] = {0, 1, 0};
    CHECK(rayes_scene_set_camera(s, eye, at, up, 40.0f) == RAYES_OK);
    const float from[3] = {1, 3, 1}, to[3] = {0, 0, 0}, white[3] = {1, 1, 1};
    RayesParam lp[3] = {{"from", RAYES_PARAM_COLOR, {from[0], from[1], from[2]}, NULL},
                        {"to", RAYES_PARAM_COLOR, {to[0], to[1], to[2]}, NULL},
                        {"intensity", RAYES_PARAM_FLOAT, {3, 0, 0}, NULL}};
    (void)white;
    CHECK(rayes_scene_light(s, "distantlight", lp, 3) == RAYES_OK);
    const float F[4][3] = {{-2, 0, -2}, {2, 0, -2}, {-2, 0, 2}, {2, 0, 2}};
    CHECK(rayes_scene_set_shader(s, "matte", NULL, 0) == RAYES_OK);
    CHECK(rayes_scene_bilinear_patch(s, F) == RAYES_OK);
    CHECK(rayes_scene_set_shader(s, "hair", NULL, 0) == RAYES_OK);
    enum { N = 100000 };
    static float P[N * 4 * 3];
    static int nv[N];
    uint32_t x = 1;
    for (int i = 0; i < N; i++) {
        float px = (float)(lcg(&x) % 10000) / 2500.0f - 2.0f, pz = (float)(lcg(&x) % 10000) / 2500.0f - 2.0f;
        float h = 0.2f + (float)(lcg(&x) % 1000) / 5000.0f;
        nv[i] = 4;
        for (int k = 0; k < 4; k++) {
            float *p = &P[12 * i + 3 * k];
            float t = (float)k / 3.0f;
            p[0] = px + 0.05f * t * t, p[1] = h * t, p[2] = pz;
        }
    }
    RayesCurves c = {.degree = 3, .step = 3, .n_curves = N, .n_verts = nv, .P = P};
    memcpy(c.basis, rayes_basis_bezier, sizeof c.basis);
    const float w = 0.004f;
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &w, 1};
    CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview(64);
    o.bounces = 1;
    RayesImage *img = NULL;
    RayesStats *st = NULL;
    CHECK(rayes_render(s, &o, &img, &st) == RAYES_OK);
    /* Lookups and hits over the three resolutions. */
    static const char *const levels[3] = {"coarse", "medium", "fine"};
    double look = 0.0, hits = 0.0;
    for (int l = 0; l < 3 && st; l++) {
        char name[64];
        snprintf(name, sizeof name, "cache/%s/lookups", levels[l]);
        const RayesStat *a = rayes_stats_find(st, name);
        snprintf(name, sizeof name, "cache/%s/hits", levels[l]);
        const RayesStat *b = rayes_stats_find(st, name);
        look += a ? (double)a->count : 0.0;
        hits += b ? (double)b->count : 0.0;
    }
    const RayesStat *grids = st ? rayes_stats_find(st, "grids") : NULL;
    CHECK(grids && grids->count > (uint64_t)N);
    /* Measured: 35,616 lookups, 15,485 hits (each hair is met by few of
     * this small image's diffuse rays, and its first lookup fills). */
    CHECK(look > 10000.0 && hits > 0.3 * look);
    double mean = 0.0;
    for (size_t k = 0; img && k < (size_t)img->width * img->height; k++)
        mean += img->rgba[4 * k + 1];
    CHECK(mean > 0.0);
    rayes_stats_free(st);
    rayes_image_free(img);
    rayes_scene_release(s);
}

/* A lone hair (Kd 1, Ks 0, white) under a constant environment of
 * radiance L: Kajiya-Kay's diffuse gathers (1/pi) L integral of sin over
 * the sphere = pi L, from both sides of the fibre. With a highlight
 * (Ks 1) the pixels rise above it and stay finite. */
static void test_fiber_environment(void)
{
    for (int with_spec = 0; with_spec < 2; with_spec++) {
        RayesScene *s = new_scene();
        RayesParam hp[4] = {{"Kd", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL},
                            {"Ks", RAYES_PARAM_FLOAT, {(float)with_spec, 0, 0}, NULL},
                            {"Ka", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
                            {"roughness", RAYES_PARAM_FLOAT, {0.02f, 0, 0}, NULL}};
        CHECK(rayes_scene_set_shader(s, "hair", hp, 4) == RAYES_OK);
        const float P[6] = {0, -2, 0, 0, 2, 0};
        const int nv = 2;
        RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1, .n_verts = &nv,
                         .P = P};
        const float w = 0.2f;
        RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &w, 1};
        CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
        RayesParam e = {"intensity", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL};
        CHECK(rayes_scene_light(s, "environmentlight", &e, 1) == RAYES_OK);
        CHECK(rayes_scene_commit(s) == RAYES_OK);
        RayesRenderOptions o = preview(32);
        o.shadow_rays = 64;
        RayesImage *img = NULL;
        CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
        double sum = 0.0;
        int n = 0;
        for (int y = 4; img && y < 28; y++) { /* the hair's middle column, lit all round */
            const float *px = &img->rgba[4 * ((size_t)y * 32 + 16)];
            if (px[3] == 1.0f)
                sum += px[0], n++;
        }
        CHECK(n > 10);
        double mean = n ? sum / n : 0.0;
        if (!with_spec)
            CHECK_NEAR(mean, 3.14159265 * 0.5, 0.03 * 3.14159265 * 0.5);
        else
            CHECK(mean > 3.14159265 * 0.5 && mean < 20.0); /* plus a finite highlight */
        rayes_image_free(img);
        rayes_scene_release(s);
    }
}

/* physicalhair (pbrt-v4's hair BSDF) in a white furnace: a fibre that
 * absorbs nothing under an environment of radiance L shows L at every
 * pixel across its width (the BSDF integrates to 1 for every view and
 * offset), by direct light alone; a clump of such fibres, their light
 * passed on by the cached Lambertian stand-in of albedo 1, too; an
 * absorbing clump is darker and redder for pbrt's eumelanin. */
static double hair_furnace_hider(int clump, const float *sigma, int bounces, double *red_over_blue,
                                 RayesHider hider, double *total)
{
    RayesScene *s = new_scene();
    RayesParam hp[1] = {{"sigma_a", RAYES_PARAM_COLOR, {0, 0, 0}, NULL}};
    int n_hp = sigma ? 1 : 0;
    if (sigma)
        memcpy(hp[0].value, sigma, 3 * sizeof(float));
    CHECK(rayes_scene_set_shader(s, "physicalhair", hp, n_hp) == RAYES_OK);
    enum { M = 5 };
    float P[M * M * 6];
    int nv[M * M], n = clump ? M * M : 1;
    for (int i = 0; i < n; i++) { /* vertical fibres 0.15 wide, 0.45 apart, in a square clump */
        float x = clump ? 0.45f * (float)(i % M - M / 2) : 0.0f;
        float z = clump ? 0.45f * (float)(i / M - M / 2) : 0.0f;
        const float q[6] = {x, -2, z, x, 2, z};
        memcpy(&P[6 * i], q, sizeof q);
        nv[i] = 2;
    }
    RayesCurves c = {.degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = n, .n_verts = nv, .P = P};
    const float w = 0.15f;
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &w, 1};
    CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
    RayesParam e = {"intensity", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL};
    CHECK(rayes_scene_light(s, "environmentlight", &e, 1) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview(64);
    o.shadow_rays = 16;
    o.diffuse_rays = 64;
    o.bounces = bounces;
    o.hider = hider;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double sum[3] = {0, 0, 0};
    int count = 0;
    if (total)
        *total = 0.0;
    for (int y = 16; img && y < 48; y++) /* the middle rows: fibres' sides, not their ends */
        for (int x = 0; x < 64; x++) {
            const float *px = &img->rgba[4 * ((size_t)y * 64 + x)];
            if (total) /* every pixel, edges too: the light of the fibres' whole width */
                *total += px[0] + px[1] + px[2];
            if (px[3] == 1.0f)
                sum[0] += px[0], sum[1] += px[1], sum[2] += px[2], count++;
        }
    CHECK(count > (clump ? 300 : 30));
    if (red_over_blue)
        *red_over_blue = sum[2] > 0.0 ? sum[0] / sum[2] : 0.0;
    rayes_image_free(img);
    rayes_scene_release(s);
    return count ? (sum[0] + sum[1] + sum[2]) / (3.0 * count) : 0.0;
}

static double hair_furnace(int clump, const float *sigma, int bounces, double *red_over_blue)
{
    return hair_furnace_hider(clump, sigma, bounces, red_over_blue, RAYES_HIDER_RAYTRACE, NULL);
}

static void test_physicalhair_furnace(void)
{
    double rb = 0.0;
    CHECK(hair_furnace(0, NULL, 0, &rb) < 0.3 && rb > 1.2); /* pbrt's 1.3 of eumelanin: brown */
    const float clear[3] = {0, 0, 0};
    CHECK_NEAR(hair_furnace(0, clear, 0, NULL), 0.5, 0.01);
    /* the grid hider's vertices lie on the fibre's edges (where an
     * absorbing fibre's BSDF is another) and stand for its whole width: the
     * light of the fibre's width is the ray-traced hider's */
    const float brown[3] = {0.54f, 0.91f, 1.78f};
    double traced = 0.0, grid = 0.0;
    hair_furnace_hider(0, brown, 0, NULL, RAYES_HIDER_RAYTRACE, &traced);
    hair_furnace_hider(0, brown, 0, NULL, RAYES_HIDER_GRID, &grid);
    CHECK(traced > 0.0);
    CHECK_NEAR(grid, traced, 0.01 * traced);
    double lone = hair_furnace(1, clear, 0, NULL), many = hair_furnace(1, clear, 8, NULL);
    CHECK(lone < 0.45);          /* without bounces, the fibres shadow each other */
    CHECK_NEAR(many, 0.5, 0.01); /* with them, the light they pass on makes it up */
    double ratio = 0.0, dark = hair_furnace(1, brown, 8, &ratio);
    CHECK(dark < 0.3 && ratio > 1.2);
}

/* The light of a brown fibre lit from the side by a distant light, the
 * fibre placed by an instance of a master (rotated and moved) or given
 * in world space: the same, since an instance's hits know where they met
 * the width too (in the master's space); the BSDF at the axis alone
 * would be far darker. */
static double side_lit_fibre(int instanced)
{
    RayesScene *s = new_scene();
    RayesParam hp[1] = {{"sigma_a", RAYES_PARAM_COLOR, {0.54f, 0.91f, 1.78f}, NULL}};
    CHECK(rayes_scene_set_shader(s, "physicalhair", hp, 1) == RAYES_OK);
    const float P[6] = {0, -2, 0, 0, 2, 0}, W[6] = {-2, 0, 0, 2, 0, 0};
    const int nv = 2;
    const float w = 0.3f;
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &w, 1};
    if (instanced) { /* a horizontal master turned upright, moved along x and back */
        RayesCurves c = {
            .degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1, .n_verts = &nv, .P = W};
        CHECK(rayes_scene_object_begin(s, "fibre") == RAYES_OK);
        CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
        const float turn[16] = {0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, turn) == RAYES_OK);
        CHECK(rayes_scene_object_instance(s, "fibre") == RAYES_OK);
        const float away[16] = {1, 0, 0, 50, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        CHECK(rayes_scene_set_transform(s, away) == RAYES_OK); /* a second, out of view */
        CHECK(rayes_scene_object_instance(s, "fibre") == RAYES_OK);
    } else {
        RayesCurves c = {
            .degree = 1, .shape = RAYES_CURVE_ROUND, .n_curves = 1, .n_verts = &nv, .P = P};
        CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
    }
    RayesParam lp[3] = {{"from", RAYES_PARAM_COLOR, {1, 0, -1}, NULL},
                        {"to", RAYES_PARAM_COLOR, {0, 0, 0}, NULL},
                        {"intensity", RAYES_PARAM_FLOAT, {3, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "distantlight", lp, 3) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview(64);
    o.bounces = 0;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    double total = 0.0;
    for (size_t k = 0; img && k < (size_t)64 * 64; k++)
        total += img->rgba[4 * k] + img->rgba[4 * k + 1] + img->rgba[4 * k + 2];
    rayes_image_free(img);
    rayes_scene_release(s);
    return total;
}

static void test_physicalhair_instances(void)
{
    double world = side_lit_fibre(0), inst = side_lit_fibre(1);
    CHECK(world > 0.0);
    CHECK_NEAR(inst, world, 0.01 * world);
}

/* Flat (ray-facing) matte fibres seen left and right of the view, a wall
 * behind them lit by a point light in front, one bounce: a tuft placed
 * by two instances of a master (turned and moved) draws as its copies do
 * with either hider. The master's grids face the eye they were diced for,
 * the left instance's; the right one's normals face its own view (they
 * faced the left one's: 4-5% dark). Writes the sum of red in each half. */
static void flat_fibres(int instanced, RayesHider hider, double half[2])
{
    RayesScene *s = new_scene();
    RayesParam mp[1] = {{"Kd", RAYES_PARAM_FLOAT, {0.8f, 0, 0}, NULL}};
    CHECK(rayes_scene_set_shader(s, "matte", mp, 1) == RAYES_OK);
    const float wall[4][3] = {{-4, -4, -1}, {4, -4, -1}, {-4, 4, -1}, {4, 4, -1}};
    CHECK(rayes_scene_bilinear_patch(s, wall) == RAYES_OK);
    const float P[3][12] = {{0, -1, 0, 0.1f, -0.3f, 0, -0.1f, 0.3f, 0, 0, 1, 0},
                            {0.3f, -1, 0, 0.4f, -0.3f, 0.1f, 0.2f, 0.3f, 0, 0.3f, 1, 0},
                            {-0.3f, -1, 0, -0.2f, -0.3f, -0.1f, -0.4f, 0.3f, 0, -0.3f, 1, 0}};
    const int nv = 4;
    const float w = 0.15f;
    RayesPrimvar pv = {"width", RAYES_PRIMVAR_CONSTANT, &w, 1};
    RayesCurves c = {
        .degree = 3, .step = 3, .shape = RAYES_CURVE_FLAT, .n_curves = 1, .n_verts = &nv};
    memcpy(c.basis, rayes_basis_bezier, sizeof c.basis);
    /* left: moved; right: moved and turned 50 degrees about y */
    const float cs = cosf(0.8727f), sn = sinf(0.8727f);
    const float place[2][16] = {{1, 0, 0, -1.2f, 0, 1, 0, 0, 0, 0, 1, 0.3f, 0, 0, 0, 1},
                                {cs, 0, sn, 1.2f, 0, 1, 0, 0, -sn, 0, cs, 0, 0, 0, 0, 1}};
    if (instanced) {
        CHECK(rayes_scene_object_begin(s, "tuft") == RAYES_OK);
        for (int k = 0; k < 3; k++) {
            c.P = P[k];
            CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
        }
        CHECK(rayes_scene_object_end(s) == RAYES_OK);
    }
    for (int i = 0; i < 2; i++) {
        CHECK(rayes_scene_set_transform(s, place[i]) == RAYES_OK);
        if (instanced)
            CHECK(rayes_scene_object_instance(s, "tuft") == RAYES_OK);
        for (int k = 0; !instanced && k < 3; k++) {
            c.P = P[k];
            CHECK(rayes_scene_curves(s, &c, &pv, 1) == RAYES_OK);
        }
    }
    const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    CHECK(rayes_scene_set_transform(s, identity) == RAYES_OK);
    RayesParam lp[2] = {{"from", RAYES_PARAM_COLOR, {0.5f, 1, 4}, NULL},
                        {"intensity", RAYES_PARAM_FLOAT, {20, 0, 0}, NULL}};
    CHECK(rayes_scene_light(s, "pointlight", lp, 2) == RAYES_OK);
    CHECK(rayes_scene_commit(s) == RAYES_OK);
    RayesRenderOptions o = preview(64);
    o.bounces = 1;
    o.hider = hider;
    RayesImage *img = NULL;
    CHECK(rayes_render(s, &o, &img, NULL) == RAYES_OK);
    half[0] = half[1] = 0.0;
    for (int y = 0; img && y < 64; y++)
        for (int x = 0; x < 64; x++)
            half[x >= 32] += img->rgba[4 * (64 * y + x)];
    rayes_image_free(img);
    rayes_scene_release(s);
}

static void test_flat_curve_instances(void)
{
    for (int h = 0; h < 2; h++) {
        RayesHider hider = h ? RAYES_HIDER_GRID : RAYES_HIDER_RAYTRACE;
        double copies[2], inst[2];
        flat_fibres(0, hider, copies);
        flat_fibres(1, hider, inst);
        for (int i = 0; i < 2; i++) {
            CHECK(copies[i] > 0.0);
            CHECK_NEAR(inst[i], copies[i], 0.005 * copies[i]);
        }
    }
}

TEST_MAIN(TEST(test_physicalhair_furnace), TEST(test_physicalhair_instances),
          TEST(test_flat_curve_instances), TEST(test_fiber_environment),
          TEST(test_hermite_translated), TEST(test_round_tube_hits), TEST(test_flat_faces_ray),
          TEST(test_bases), TEST(test_points), TEST(test_bad_input), TEST(test_hair_field_caches))
