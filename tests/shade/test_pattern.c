/*
 * Patterns (shade/pattern): each of pbrt-v4's texture classes at known
 * points — constant, scale, mix, directionmix, checkerboard in 2-D (exact
 * box filter: half a check each side of an edge is the mean) and 3-D (in
 * texture space), imagemap with uscale, vscale, udelta, vdelta, invert,
 * scale, encoding (untiled and maketx's tiled files) and a float's first
 * channel (images written by the test, by oiiotool and maketx), bilerp at its corners, dots (only
 * its two values), the noise patterns (deterministic; a footprint wider than the first octave
 * leaves fbm's mean 0); more points than one chunk give what one point at
 * a time gives; and bad definitions are refused with a message.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "image/image.h"
#include "shade/pattern.h"
#include "test.h"

#define TMP RAYES_TEST_TMP "/pattern_test"
#define MAXN 200

static const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/* Points for evaluation: texture coordinates (s, t) with footprint ds, dt,
 * positions P with dPdu = x, dPdv = y and du = dv = w, normals N. */
typedef struct Points {
    float s[MAXN], t[MAXN], ds[MAXN], dt[MAXN], du[MAXN], dv[MAXN];
    float P[MAXN][3], N[MAXN][3], dPdu[MAXN][3], dPdv[MAXN][3];
    size_t n;
} Points;

static void add_point(Points *pt, float s, float t, float ds, const float P[3], float w)
{
    size_t i = pt->n++;
    pt->s[i] = s, pt->t[i] = t, pt->ds[i] = pt->dt[i] = ds;
    pt->du[i] = pt->dv[i] = w;
    memcpy(pt->P[i], P, sizeof pt->P[i]);
    float N[3] = {0, 0, 1}, x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
    memcpy(pt->N[i], N, sizeof N);
    memcpy(pt->dPdu[i], x, sizeof x);
    memcpy(pt->dPdv[i], y, sizeof y);
}

static RayesShadeCtx ctx_of(const Points *pt)
{
    return (RayesShadeCtx){.n_points = pt->n,
                           .P = (const float(*)[3])pt->P,
                           .N = (const float(*)[3])pt->N,
                           .Ng = (const float(*)[3])pt->N,
                           .dPdu = (const float(*)[3])pt->dPdu,
                           .dPdv = (const float(*)[3])pt->dPdv,
                           .s = pt->s,
                           .t = pt->t,
                           .du = pt->du,
                           .dv = pt->dv};
}

static const Pattern *find_in(void *data, const char *name);

/* Patterns made by the test, by name, for references between them. */
typedef struct Made {
    const char *name[32];
    Pattern *p[32];
    int n;
} Made;

static const Pattern *find_in(void *data, const char *name)
{
    Made *m = data;
    for (int i = m->n; i-- > 0;)
        if (strcmp(m->name[i], name) == 0)
            return m->p[i];
    return NULL;
}

static Pattern *make(Made *m, const char *name, const char *type, const RayesParam *q, size_t n,
                     const float xf[16])
{
    char err[256] = "";
    Pattern *p = pattern_new(type, q, n, xf ? xf : identity, find_in, m, err, sizeof err);
    CHECK(p != NULL);
    if (!p) {
        fprintf(stderr, "  pattern_new(%s): %s\n", type, err);
        return NULL;
    }
    m->name[m->n] = name;
    m->p[m->n++] = p;
    return p;
}

static void free_made(Made *m)
{
    for (int i = 0; i < m->n; i++)
        pattern_free(m->p[i]);
    m->n = 0;
}

/* The pattern at one point (s, t), footprint ds, position P. */
static void eval1(const Pattern *p, TextureSystem *ts, float s, float t, float ds, const float P[3],
                  float w, float out[3])
{
    static Points pt;
    pt.n = 0;
    static const float origin[3] = {0, 0, 0};
    add_point(&pt, s, t, ds, P ? P : origin, w);
    RayesShadeCtx c = ctx_of(&pt);
    float rgb[1][3];
    pattern_eval(p, ts, &c, pt.ds, pt.dt, rgb);
    memcpy(out, rgb[0], sizeof rgb[0]);
}

#define COLOR(n, r, g, b)                                                                          \
    {                                                                                              \
        n, RAYES_PARAM_COLOR, {r, g, b}, NULL                                                      \
    }
#define FLOAT(n, v)                                                                                \
    {                                                                                              \
        n, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL                                                      \
    }
#define STRING(n, v)                                                                               \
    {                                                                                              \
        n, RAYES_PARAM_STRING, {0, 0, 0}, v                                                        \
    }
#define REF(n, v)                                                                                  \
    {                                                                                              \
        n, RAYES_PARAM_PATTERN, {0, 0, 0}, v                                                       \
    }

static void check_rgb(const float got[3], float r, float g, float b, double tol)
{
    CHECK_NEAR(got[0], r, tol);
    CHECK_NEAR(got[1], g, tol);
    CHECK_NEAR(got[2], b, tol);
}

static void test_constant_scale_mix(void)
{
    Made m = {0};
    float v[3];
    RayesParam a[] = {COLOR("value", 0.2f, 0.4f, 0.6f)};
    make(&m, "a", "constant", a, 1, NULL);
    RayesParam b[] = {REF("tex", "a"), FLOAT("scale", 0.5f)};
    make(&m, "b", "scale", b, 2, NULL);
    RayesParam c[] = {REF("tex1", "a"), REF("tex2", "b"), FLOAT("amount", 0.25f)};
    Pattern *mix = make(&m, "c", "mix", c, 3, NULL);
    eval1(m.p[1], NULL, 0, 0, 0, NULL, 0, v);
    check_rgb(v, 0.1f, 0.2f, 0.3f, 1e-6);
    eval1(mix, NULL, 0, 0, 0, NULL, 0, v); /* 0.75 a + 0.25 a/2 */
    check_rgb(v, 0.175f, 0.35f, 0.525f, 1e-6);
    /* the amount as a pattern, tex2 defaulting to 1 */
    RayesParam d[] = {REF("tex1", "a"), REF("amount", "b")};
    Pattern *mixed = make(&m, "d", "mix", d, 2, NULL);
    eval1(mixed, NULL, 0, 0, 0, NULL, 0, v); /* amount = 0.1 (b's first channel) */
    check_rgb(v, 0.9f * 0.2f + 0.1f, 0.9f * 0.4f + 0.1f, 0.9f * 0.6f + 0.1f, 1e-6);
    /* directionmix: tex1 where N is along dir, tex2 across it */
    RayesParam e[] = {COLOR("tex1", 1, 0, 0), COLOR("tex2", 0, 0, 1), COLOR("dir", 0, 0, 2)};
    Pattern *dm = make(&m, "e", "directionmix", e, 3, NULL);
    eval1(dm, NULL, 0, 0, 0, NULL, 0, v);
    check_rgb(v, 1, 0, 0, 1e-6);
    RayesParam f[] = {COLOR("tex1", 1, 0, 0), COLOR("tex2", 0, 0, 1), COLOR("dir", 1, 0, 0)};
    dm = make(&m, "f", "directionmix", f, 3, NULL);
    eval1(dm, NULL, 0, 0, 0, NULL, 0, v);
    check_rgb(v, 0, 0, 1, 1e-6);
    free_made(&m);
}

/* pbrt's (u, v) is (s, 1 - t): with uscale 2 the checks of u are half as
 * wide, and a footprint across an edge averages. */
static void test_checkerboard_2d(void)
{
    Made m = {0};
    float v[3];
    RayesParam q[] = {COLOR("tex1", 1, 1, 1), COLOR("tex2", 0, 0, 0), FLOAT("uscale", 2)};
    Pattern *p = make(&m, "c", "checkerboard", q, 3, NULL);
    eval1(p, NULL, 0.2f, 0.3f, 0, NULL, 0, v); /* u 0.4, v 0.7: even */
    check_rgb(v, 1, 1, 1, 0);
    eval1(p, NULL, 0.7f, 0.3f, 0, NULL, 0, v); /* u 1.4: odd */
    check_rgb(v, 0, 0, 0, 0);
    eval1(p, NULL, 0.2f, 1.3f, 0, NULL, 0, v); /* v -0.3: odd */
    check_rgb(v, 0, 0, 0, 0);
    /* a footprint centred on the edge u = 1: half each side, the mean */
    eval1(p, NULL, 0.5f, 0.5f, 0.1f, NULL, 0, v);
    CHECK_NEAR(v[0], 0.5, 1e-5);
    /* inside a check with room to spare: the check's own value */
    eval1(p, NULL, 0.25f, 0.5f, 0.05f, NULL, 0, v);
    CHECK_NEAR(v[0], 1.0, 1e-5);
    /* a footprint of many checks: the mean */
    eval1(p, NULL, 0.3f, 0.6f, 40.0f, NULL, 0, v);
    CHECK_NEAR(v[0], 0.5, 0.02);
    /* inputs may be patterns */
    RayesParam in[] = {COLOR("value", 0.3f, 0.3f, 0.3f)};
    make(&m, "k", "constant", in, 1, NULL);
    RayesParam q2[] = {REF("tex1", "k")};
    Pattern *p2 = make(&m, "c2", "checkerboard", q2, 1, NULL);
    eval1(p2, NULL, 0.2f, 0.3f, 0, NULL, 0, v);
    CHECK_NEAR(v[0], 0.3, 1e-6);
    free_made(&m);
}

/* 3-D: cubes of texture space, whose transform scales world by 1/2. */
static void test_checkerboard_3d(void)
{
    Made m = {0};
    float v[3];
    const float world_from_texture[16] = {0.5f, 0, 0, 0, 0, 0.5f, 0, 0, 0, 0, 0.5f, 0, 0, 0, 0, 1};
    RayesParam q[] = {COLOR("tex1", 1, 1, 1), COLOR("tex2", 0, 0, 0), FLOAT("dimension", 3)};
    Pattern *p = make(&m, "c", "checkerboard", q, 3, world_from_texture);
    float a[3] = {0.25f, 0.1f, 0.1f}, b[3] = {0.6f, 0.1f, 0.1f}, c[3] = {-0.1f, -0.1f, 0.1f};
    eval1(p, NULL, 0, 0, 0, a, 0, v); /* texture (0.5, 0.2, 0.2): even */
    check_rgb(v, 1, 1, 1, 0);
    eval1(p, NULL, 0, 0, 0, b, 0, v); /* (1.2, ...): odd */
    check_rgb(v, 0, 0, 0, 0);
    eval1(p, NULL, 0, 0, 0, c, 0, v); /* (-0.2, -0.2, 0.2): -1 - 1 + 0, even */
    check_rgb(v, 1, 1, 1, 0);
    free_made(&m);
}

/* A 2 x 2 EXR: red, green over blue, white (top row first). */
static void write_quad(void)
{
    float rgba[16] = {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1};
    char err[300];
    mkdir(TMP, 0755);
    CHECK(image_write_exr(TMP "/quad.exr", 2, 2, rgba, err, sizeof err) == RAYES_OK);
}

static void test_imagemap_mapping(void)
{
    write_quad();
    TextureSystem *ts = texture_system_new(NULL, 1u << 20, 1.0f);
    Made m = {0};
    float v[3];
    RayesParam q[] = {STRING("filename", TMP "/quad.exr")};
    Pattern *p = make(&m, "i", "imagemap", q, 1, NULL);
    eval1(p, ts, 0.25f, 0.25f, 0, NULL, 0, v); /* the image's top left */
    check_rgb(v, 1, 0, 0, 1e-6);
    eval1(p, ts, 0.75f, 0.75f, 0, NULL, 0, v);
    check_rgb(v, 1, 1, 1, 1e-6);
    /* u = 2 s + 0.5, v = (1 - t) + 0.5: (0.125, 0.25) lands on the bottom right */
    RayesParam q2[] = {STRING("filename", TMP "/quad.exr"), FLOAT("uscale", 2),
                       FLOAT("udelta", 0.5f), FLOAT("vdelta", 0.5f)};
    p = make(&m, "j", "imagemap", q2, 4, NULL);
    eval1(p, ts, 0.125f, 0.25f, 0, NULL, 0, v);
    check_rgb(v, 1, 1, 1, 1e-6);
    /* vscale 2: v = 2 (1 - t); t 0.875 gives v 0.25, the bottom row, left */
    RayesParam q3[] = {STRING("filename", TMP "/quad.exr"), FLOAT("vscale", 2)};
    p = make(&m, "k", "imagemap", q3, 2, NULL);
    eval1(p, ts, 0.25f, 0.875f, 0, NULL, 0, v);
    check_rgb(v, 0, 0, 1, 1e-6);
    /* scale, then invert, clamped at 0 */
    RayesParam q4[] = {STRING("filename", TMP "/quad.exr"), FLOAT("scale", 0.5f),
                       FLOAT("invert", 1)};
    p = make(&m, "l", "imagemap", q4, 3, NULL);
    eval1(p, ts, 0.25f, 0.25f, 0, NULL, 0, v);
    check_rgb(v, 0.5f, 1, 1, 1e-6);
    RayesParam q5[] = {STRING("filename", TMP "/quad.exr"), FLOAT("scale", 3), FLOAT("invert", 1)};
    p = make(&m, "m", "imagemap", q5, 3, NULL);
    eval1(p, ts, 0.25f, 0.25f, 0, NULL, 0, v);
    check_rgb(v, 0, 1, 1, 1e-6);
    /* a float texture: the first channel, grey */
    RayesParam q6[] = {STRING("filename", TMP "/quad.exr"), FLOAT("channel", 0)};
    p = make(&m, "n", "imagemap", q6, 2, NULL);
    eval1(p, ts, 0.25f, 0.25f, 0, NULL, 0, v);
    check_rgb(v, 1, 1, 1, 1e-6);
    /* filtered over the whole image: its mean */
    p = m.p[0];
    eval1(p, ts, 0.5f, 0.5f, 1.0f, NULL, 0, v);
    check_rgb(v, 0.5f, 0.5f, 0.5f, 0.02);
    /* a missing file: -1, black */
    RayesParam q7[] = {STRING("filename", TMP "/none.exr")};
    p = make(&m, "o", "imagemap", q7, 1, NULL);
    Points pt = {0};
    add_point(&pt, 0.5f, 0.5f, 0, (float[3]){0, 0, 0}, 0);
    RayesShadeCtx c = ctx_of(&pt);
    float rgb[1][3];
    CHECK(pattern_eval(p, ts, &c, NULL, NULL, rgb) == -1);
    check_rgb(rgb[0], 0, 0, 0, 0);
    free_made(&m);
    texture_system_free(ts);
}

/* An 8-bit PNG of texels 128: sRGB by default, as it is with "linear",
 * raised to 2.2 with "gamma 2.2". */
static void test_imagemap_encoding(void)
{
    mkdir(TMP, 0755);
    int status = system("oiiotool --pattern constant:color=0.50196,0.50196,0.50196 4x4 3 "
                        "-d uint8 -o " TMP "/grey128.png > /dev/null 2>&1");
    CHECK(status == 0);
    if (status != 0)
        return;
    TextureSystem *ts = texture_system_new(NULL, 1u << 20, 1.0f);
    Made m = {0};
    static const char *const enc[3] = {"sRGB", "linear", "gamma 2.2"};
    double c = 128.0 / 255.0;
    double want[3] = {pow((c + 0.055) / 1.055, 2.4), c, pow(c, 2.2)};
    float v[3];
    for (int k = 0; k < 3; k++) {
        RayesParam q[] = {STRING("filename", TMP "/grey128.png"), STRING("encoding", enc[k])};
        Pattern *p = make(&m, enc[k], "imagemap", q, 2, NULL);
        eval1(p, ts, 0.5f, 0.5f, 0.1f, NULL, 0, v);
        CHECK_NEAR(v[0], want[k], 1e-3);
    }
    RayesParam d[] = {STRING("filename", TMP "/grey128.png")};
    eval1(make(&m, "default", "imagemap", d, 1, NULL), ts, 0.5f, 0.5f, 0.1f, NULL, 0, v);
    CHECK_NEAR(v[0], want[0], 1e-3); /* an 8-bit PNG is sRGB */
    /* maketx's tiled 8-bit .tx: decoded after filtering, the same here */
    status = system("maketx " TMP "/grey128.png -o " TMP "/grey128.tx > /dev/null 2>&1");
    CHECK(status == 0);
    for (int k = 0; k < 3 && status == 0; k++) {
        RayesParam q[] = {STRING("filename", TMP "/grey128.tx"), STRING("encoding", enc[k])};
        eval1(make(&m, enc[k], "imagemap", q, 2, NULL), ts, 0.5f, 0.5f, 0.1f, NULL, 0, v);
        CHECK_NEAR(v[0], want[k], 1e-3);
    }
    free_made(&m);
    texture_system_free(ts);
}

static void test_bilerp_and_dots(void)
{
    Made m = {0};
    float v[3];
    RayesParam q[] = {COLOR("v00", 1, 0, 0), COLOR("v10", 0, 1, 0), COLOR("v01", 0, 0, 1),
                      COLOR("v11", 1, 1, 1)};
    Pattern *p = make(&m, "b", "bilerp", q, 4, NULL);
    eval1(p, NULL, 0, 1, 0, NULL, 0, v); /* (u, v) = (0, 0) */
    check_rgb(v, 1, 0, 0, 1e-6);
    eval1(p, NULL, 1, 1, 0, NULL, 0, v); /* (1, 0) */
    check_rgb(v, 0, 1, 0, 1e-6);
    eval1(p, NULL, 0, 0, 0, NULL, 0, v); /* (0, 1) */
    check_rgb(v, 0, 0, 1, 1e-6);
    eval1(p, NULL, 0.5f, 0.5f, 0, NULL, 0, v);
    check_rgb(v, 0.5f, 0.5f, 0.5f, 1e-6);
    RayesParam d[] = {COLOR("inside", 1, 1, 0), COLOR("outside", 0, 0, 1), FLOAT("uscale", 4),
                      FLOAT("vscale", 4)};
    p = make(&m, "d", "dots", d, 4, NULL);
    int inside = 0, outside = 0;
    for (int i = 0; i < 64; i++)
        for (int j = 0; j < 64; j++) {
            eval1(p, NULL, (float)i / 64.0f, (float)j / 64.0f, 0, NULL, 0, v);
            inside += v[0] == 1 && v[1] == 1 && v[2] == 0;
            outside += v[0] == 0 && v[1] == 0 && v[2] == 1;
        }
    CHECK(inside + outside == 64 * 64 && inside > 64 && outside > 64);
    free_made(&m);
}

static void test_noise_patterns(void)
{
    Made m = {0};
    static const char *const types[4] = {"fbm", "wrinkled", "windy", "marble"};
    for (int k = 0; k < 4; k++)
        make(&m, types[k], types[k], NULL, 0, NULL);
    float sum[4] = {0}, v[3], w[3];
    for (int i = 0; i < 200; i++) {
        float P[3] = {0.37f * (float)i, 0.11f * (float)i, 0.05f * (float)i};
        for (int k = 0; k < 4; k++) {
            eval1(m.p[k], NULL, 0, 0, 0, P, 0.001f, v);
            eval1(m.p[k], NULL, 0, 0, 0, P, 0.001f, w);
            CHECK(memcmp(v, w, sizeof v) == 0); /* a function of the point */
            CHECK(isfinite(v[0]) && fabsf(v[0]) < 3.0f);
            if (k == 1)
                CHECK(v[0] >= 0.0f); /* turbulence */
            if (k == 3)
                CHECK(v[0] >= 0.0f && v[0] <= 1.0f);
            sum[k] += fabsf(v[0]);
        }
    }
    CHECK(sum[0] > 1.0f && sum[1] > 1.0f && sum[2] > 0.1f && sum[3] > 1.0f); /* not flat */
    /* filtered: a footprint wider than the first octave leaves the mean */
    float P[3] = {0.3f, 0.7f, 0.2f};
    eval1(m.p[0], NULL, 0, 0, 0, P, 10.0f, v);
    CHECK(v[0] == 0.0f);
    free_made(&m);
}

/* More points than a chunk: each as it is alone. */
static void test_chunks_match_single_points(void)
{
    write_quad();
    TextureSystem *ts = texture_system_new(NULL, 1u << 20, 1.0f);
    Made m = {0};
    RayesParam q[] = {STRING("filename", TMP "/quad.exr"), FLOAT("uscale", 3)};
    make(&m, "i", "imagemap", q, 2, NULL);
    RayesParam c[] = {REF("tex1", "i"), FLOAT("uscale", 5), FLOAT("vscale", 5)};
    Pattern *p = make(&m, "c", "checkerboard", c, 3, NULL);
    static Points pt;
    pt.n = 0;
    for (int i = 0; i < 150; i++)
        add_point(&pt, (float)i * 0.013f, (float)i * 0.007f, 0.01f * (float)(i % 3),
                  (float[3]){(float)i, 0, 0}, 0);
    RayesShadeCtx ctx = ctx_of(&pt);
    static float all[MAXN][3];
    CHECK(pattern_eval(p, ts, &ctx, pt.ds, pt.dt, all) == 0);
    for (size_t i = 0; i < pt.n; i++) {
        float one[3];
        eval1(p, ts, pt.s[i], pt.t[i], pt.ds[i], pt.P[i], 0, one);
        CHECK(memcmp(one, all[i], sizeof one) == 0);
    }
    free_made(&m);
    texture_system_free(ts);
}

static void expect_refused(const char *type, const RayesParam *q, size_t n, const char *want)
{
    Made m = {0};
    RayesParam base[] = {COLOR("value", 1, 1, 1)};
    make(&m, "known", "constant", base, 1, NULL);
    char err[256] = "";
    Pattern *p = pattern_new(type, q, n, identity, find_in, &m, err, sizeof err);
    CHECK(p == NULL && strstr(err, want) != NULL);
    if (p || !strstr(err, want))
        fprintf(stderr, "  %s: got \"%s\", wanted \"%s\"\n", type, err, want);
    pattern_free(p);
    free_made(&m);
}

static void test_bad_definitions(void)
{
    expect_refused("ptex", NULL, 0, "unknown pattern class \"ptex\"");
    RayesParam a[] = {FLOAT("nonsense", 1)};
    expect_refused("constant", a, 1, "has no parameter \"nonsense\"");
    RayesParam b[] = {STRING("tex1", "x")};
    expect_refused("mix", b, 1, "\"tex1\" has the wrong type");
    RayesParam c[] = {REF("tex1", "unknown")};
    expect_refused("mix", c, 1, "\"tex1\" names no pattern (\"unknown\")");
    RayesParam d[] = {FLOAT("dimension", 4)};
    expect_refused("checkerboard", d, 1, "dimension must be 2 or 3");
    RayesParam e[] = {STRING("filename", "a.png"), STRING("encoding", "gamma")};
    expect_refused("imagemap", e, 2, "encoding \"gamma\"");
    expect_refused("imagemap", NULL, 0, "no filename");
    /* nesting: 16 levels are fine, 17 are not */
    Made m = {0};
    static char names[20][16]; /* "p" and any int */
    RayesParam first[] = {COLOR("value", 1, 1, 1)};
    snprintf(names[0], sizeof names[0], "p0");
    make(&m, names[0], "constant", first, 1, NULL);
    for (int k = 1; k < 16; k++) {
        snprintf(names[k], sizeof names[k], "p%d", k);
        RayesParam q[] = {REF("tex", names[k - 1])};
        make(&m, names[k], "scale", q, 1, NULL);
    }
    char err[256] = "";
    RayesParam q[] = {REF("tex", names[15])};
    Pattern *p = pattern_new("scale", q, 1, identity, find_in, &m, err, sizeof err);
    CHECK(p == NULL && strstr(err, "deeper than 16") != NULL);
    float v[3];
    eval1(m.p[15], NULL, 0, 0, 0, NULL, 0, v); /* the deepest allowed evaluates */
    check_rgb(v, 1, 1, 1, 0);
    free_made(&m);
}

TEST_MAIN(TEST(test_constant_scale_mix), TEST(test_checkerboard_2d), TEST(test_checkerboard_3d),
          TEST(test_imagemap_mapping), TEST(test_imagemap_encoding), TEST(test_bilerp_and_dots),
          TEST(test_noise_patterns), TEST(test_chunks_match_single_points),
          TEST(test_bad_definitions))
