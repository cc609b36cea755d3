/*
 * Irradiance records with gradients (render/irradiance.c) against finite
 * differences on an analytic scene: an infinite emitting ceiling z = H over
 * the point, radiance varying smoothly with position (a different function
 * per channel), nothing below the horizon. The rotational gradient must
 * predict E at a tilted normal, the translational one E at a moved point.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "render/irradiance.h"
#include "test.h"

static const float H = 2.0f;

/* Bright patches on the ceiling, fading to black far away so that grazing
 * directions carry no light: the cell-centre rule for tan(theta), which the
 * rotational gradient uses, is then accurate, and the test checks the
 * formulas and their signs rather than quadrature near the horizon. */
static float blob(float x, float y, float cx, float cy, float s)
{
    return expf(-((x - cx) * (x - cx) + (y - cy) * (y - cy)) / (s * s));
}

static Vec3 ceiling(float x, float y)
{
    return v3(2.0f * blob(x, y, 1.0f, 0.5f, 1.5f), blob(x, y, 0.0f, 0.0f, 3.0f),
              4.0f * blob(x, y, -0.8f, 0.3f, 0.8f));
}

/* Radiance and distance along d from p. */
static Vec3 trace(Vec3 p, Vec3 d, float *r)
{
    if (d.z <= 1e-6f) {
        *r = INFINITY;
        return v3(0, 0, 0);
    }
    float t = (H - p.z) / d.z;
    *r = t;
    return ceiling(p.x + t * d.x, p.y + t * d.y);
}

/* A record at (p, n) from M x N cells with jitter pattern `pattern` (0:
 * cell centres). */
static void record_jittered(int M, int N, Vec3 p, Vec3 n, unsigned pattern, IrrRecord *rec)
{
    Vec3 *L = malloc(sizeof *L * (size_t)(M * N));
    float *r = malloc(sizeof *r * (size_t)(M * N));
    unsigned h = pattern * 2654435761u + 12345u;
    for (int j = 0; j < M; j++)
        for (int k = 0; k < N; k++) {
            float xi[2] = {0.5f, 0.5f};
            for (int q = 0; q < 2 && pattern; q++) {
                h = h * 1664525u + 1013904223u;
                xi[q] = (float)(h >> 8) / 16777216.0f;
            }
            L[j * N + k] = trace(p, irr_direction(M, N, j, k, xi[0], xi[1], n), &r[j * N + k]);
        }
    irr_record(M, N, L, r, p, n, rec);
    free(L);
    free(r);
}

static void record(int M, int N, Vec3 p, Vec3 n, IrrRecord *rec)
{
    record_jittered(M, N, p, n, 0, rec);
}

/* The mean of 32 jittered records: every part of a record is linear in the
 * radiance, and jittered samples are unbiased where cell centres are not
 * (tan(theta) at grazing angles). */
static void record_mean(int M, int N, Vec3 p, Vec3 n, IrrRecord *rec)
{
    enum { PATTERNS = 32 };
    IrrRecord sum = {0}, one;
    for (unsigned q = 1; q <= PATTERNS; q++) {
        record_jittered(M, N, p, n, q, &one);
        sum.E = v3_add(sum.E, one.E);
        for (int c = 0; c < 3; c++) {
            sum.grad_r[c] = v3_add(sum.grad_r[c], one.grad_r[c]);
            sum.grad_t[c] = v3_add(sum.grad_t[c], one.grad_t[c]);
        }
    }
    *rec = one;
    rec->E = v3_scale(sum.E, 1.0f / PATTERNS);
    for (int c = 0; c < 3; c++) {
        rec->grad_r[c] = v3_scale(sum.grad_r[c], 1.0f / PATTERNS);
        rec->grad_t[c] = v3_scale(sum.grad_t[c], 1.0f / PATTERNS);
    }
}

/* Irradiance by a fine midpoint rule. */
static Vec3 irradiance(Vec3 p, Vec3 n)
{
    IrrRecord rec;
    record(400, 1257, p, n, &rec);
    return rec.E;
}

static float comp(Vec3 v, int c)
{
    return c == 0 ? v.x : c == 1 ? v.y : v.z;
}

static void test_frame_is_right_handed(void)
{
    Vec3 ns[3] = {v3(0, 0, 1), v3_normalize(v3(0.3f, -0.5f, 0.8f)), v3(0, 0, -1)};
    for (int i = 0; i < 3; i++) {
        Vec3 t, b;
        irr_frame(ns[i], &t, &b);
        CHECK(v3_length(v3_sub(v3_cross(t, b), ns[i])) < 1e-5f);
    }
}

static void test_uniform_sky(void)
{
    /* Constant radiance 1 over the hemisphere: E = pi, no gradients. */
    enum { M = 8, N = 25 };
    Vec3 L[M * N];
    float r[M * N];
    for (int i = 0; i < M * N; i++) {
        L[i] = v3(1, 1, 1);
        r[i] = 3.0f;
    }
    IrrRecord rec;
    irr_record(M, N, L, r, v3(0, 0, 0), v3(0, 0, 1), &rec);
    CHECK_NEAR(rec.E.x, (float)M_PI, 1e-5);
    CHECK_NEAR(rec.R, 3.0f, 1e-6);
    for (int c = 0; c < 3; c++) {
        CHECK(v3_length(rec.grad_t[c]) < 1e-5f);
        CHECK(v3_length(rec.grad_r[c]) < 1e-4f);
    }
}

static void test_rotational_gradient(void)
{
    Vec3 p = v3(0.4f, -0.3f, 0.0f), n = v3_normalize(v3(0.2f, 0.1f, 1.0f));
    IrrRecord rec;
    record_mean(32, 100, p, n, &rec);
    Vec3 t, b;
    irr_frame(n, &t, &b);
    const float eps = 0.01f;
    for (int a = 0; a < 2; a++) {
        Vec3 axis = a ? b : t;
        /* rotate n about axis by +-eps */
        Vec3 w = v3_cross(axis, n);
        Vec3 n1 = v3_normalize(v3_madd(n, w, eps)), n0 = v3_normalize(v3_madd(n, w, -eps));
        Vec3 e1 = irradiance(p, n1), e0 = irradiance(p, n0);
        for (int c = 0; c < 3; c++) {
            float fd = (comp(e1, c) - comp(e0, c)) / (2.0f * eps);
            /* The record's prediction for the rotated normals. */
            float pr = (comp(irr_extrapolate(&rec, p, n1), c) -
                        comp(irr_extrapolate(&rec, p, n0), c)) /
                       (2.0f * eps);
            CHECK_NEAR(pr, fd, 0.03 * fabs(fd) + 0.01);
        }
    }
}

static void test_translational_gradient(void)
{
    Vec3 p = v3(0.4f, -0.3f, 0.0f), n = v3_normalize(v3(0.2f, 0.1f, 1.0f));
    IrrRecord rec;
    record(32, 100, p, n, &rec);
    Vec3 t, b;
    irr_frame(n, &t, &b);
    const float d = 0.01f;
    float largest = 0.0f;
    for (int a = 0; a < 3; a++) {
        Vec3 e = a == 0 ? t : a == 1 ? b : v3_normalize(v3_add(t, b));
        Vec3 e1 = irradiance(v3_madd(p, e, d), n), e0 = irradiance(v3_madd(p, e, -d), n);
        for (int c = 0; c < 3; c++) {
            float fd = (comp(e1, c) - comp(e0, c)) / (2.0f * d);
            float pr = v3_dot(e, rec.grad_t[c]);
            largest = fmaxf(largest, fabsf(fd));
            CHECK_NEAR(pr, fd, 0.05 * fabs(fd) + 0.01);
        }
    }
    CHECK(largest > 0.1f); /* the scene does have translational gradients */
}

/* Extrapolation with gradients beats the record's constant value nearby. */
static void test_gradients_improve_interpolation(void)
{
    Vec3 p = v3(0, 0, 0), n = v3(0, 0, 1);
    IrrRecord rec;
    record_mean(32, 100, p, n, &rec);
    Vec3 q = v3(0.1f, 0.05f, 0), m = v3_normalize(v3(0.03f, 0, 1));
    Vec3 truth = irradiance(q, m), with = irr_extrapolate(&rec, q, m);
    for (int c = 0; c < 3; c++) {
        float err_with = fabsf(comp(with, c) - comp(truth, c));
        float err_without = fabsf(comp(rec.E, c) - comp(truth, c));
        CHECK(err_with < 0.01f * comp(truth, c) + 1e-3f);
        CHECK(c == 1 || err_with < 0.5f * err_without);
    }
}

/* An open box: floor z = 0, black walls up to z = 1 around x, y in [-1, 1],
 * open to a uniform sky of radiance 1 above. The irradiance at a floor
 * point is the sky seen through the opening, given exactly by Lambert's
 * formula for a polygon. */
static Vec3 open_box(Vec3 p, Vec3 d, float *r)
{
    *r = INFINITY;
    if (d.z <= 0.0f)
        return v3(0, 0, 0);
    float t = (1.0f - p.z) / d.z;
    Vec3 q = v3_madd(p, d, t);
    if (fabsf(q.x) <= 1.0f && fabsf(q.y) <= 1.0f)
        return v3(1, 1, 1); /* out through the opening */
    /* the first wall it meets */
    float tw = INFINITY;
    if (d.x > 0.0f)
        tw = fminf(tw, (1.0f - p.x) / d.x);
    if (d.x < 0.0f)
        tw = fminf(tw, (-1.0f - p.x) / d.x);
    if (d.y > 0.0f)
        tw = fminf(tw, (1.0f - p.y) / d.y);
    if (d.y < 0.0f)
        tw = fminf(tw, (-1.0f - p.y) / d.y);
    *r = tw;
    return v3(0, 0, 0);
}

/* Lambert: E = L/2 sum over edges of angle * (n . unit normal of the edge's
 * plane through p), for the opening seen from p with normal +z. */
static double open_box_exact(Vec3 p)
{
    const double c[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    double sum = 0.0;
    for (int i = 0; i < 4; i++) {
        double a[3] = {c[i][0] - p.x, c[i][1] - p.y, 1.0 - p.z};
        double b[3] = {c[(i + 1) % 4][0] - p.x, c[(i + 1) % 4][1] - p.y, 1.0 - p.z};
        double la = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        double lb = sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        double cosg = (a[0] * b[0] + a[1] * b[1] + a[2] * b[2]) / (la * lb);
        double g = acos(fmin(1.0, fmax(-1.0, cosg)));
        double cz = a[0] * b[1] - a[1] * b[0];
        double cl = sqrt(pow(a[1] * b[2] - a[2] * b[1], 2) + pow(a[2] * b[0] - a[0] * b[2], 2) +
                         cz * cz);
        sum += g * cz / cl;
    }
    return 0.5 * fabs(sum);
}

static void test_open_box(void)
{
    enum { M = 48, N = 151 };
    static Vec3 L[M * N];
    static float r[M * N];
    Vec3 n = v3(0, 0, 1), p0 = v3(0.3f, -0.2f, 0.0f), p1 = v3(0.42f, -0.12f, 0.0f);
    for (int j = 0; j < M; j++)
        for (int k = 0; k < N; k++)
            L[j * N + k] = open_box(p0, irr_direction(M, N, j, k, 0.5f, 0.5f, n), &r[j * N + k]);
    IrrRecord rec;
    irr_record(M, N, L, r, p0, n, &rec);
    double e0 = open_box_exact(p0), e1 = open_box_exact(p1);
    CHECK(fabs(rec.E.x - e0) < 0.005 * e0); /* the record itself */
    double with = irr_extrapolate(&rec, p1, n).x, without = rec.E.x;
    CHECK(fabs(with - e1) < 0.01 * e1);
    CHECK(fabs(without - e1) > 0.02 * e1);
    CHECK(fabs(without - e1) > 3.0 * fabs(with - e1));
    printf("  open box: exact %.5f, with gradients %.5f, without %.5f\n", e1, with, without);
}

static void test_weight(void)
{
    IrrRecord rec = {.p = v3(0, 0, 0), .n = v3(0, 0, 1), .R = 1.0f};
    CHECK_NEAR(irr_weight(&rec, v3(0, 0, 0), v3(0, 0, 1), 1.0f), 1.0f, 1e-6);
    CHECK_NEAR(irr_weight(&rec, v3(0.5f, 0, 0), v3(0, 0, 1), 1.0f), 0.5f, 1e-6);
    CHECK(irr_weight(&rec, v3(1.5f, 0, 0), v3(0, 0, 1), 1.0f) == 0.0f);
    /* normals 10 degrees apart: weight 0 */
    float a = 10.0f * (float)M_PI / 180.0f;
    CHECK(irr_weight(&rec, v3(0, 0, 0), v3(sinf(a), 0, cosf(a)), 1.0f) < 1e-3f);
    /* a record in front of the point (above it) is not used */
    CHECK(irr_weight(&rec, v3(0.1f, 0, -0.2f), v3(0, 0, 1), 1.0f) == 0.0f);
}

TEST_MAIN(TEST(test_frame_is_right_handed), TEST(test_uniform_sky), TEST(test_rotational_gradient),
          TEST(test_translational_gradient), TEST(test_gradients_improve_interpolation),
          TEST(test_weight), TEST(test_open_box))
