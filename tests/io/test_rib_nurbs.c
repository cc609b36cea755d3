/*
 * RIB's NuPatch (io/rib_nurbs.c): polynomial spans become the very
 * bicubic Bezier patches the same surface has as a Patch or a b-spline
 * PatchMesh; rational spans (a NURBS sphere) lie on the surface within
 * the fit's tolerance and render as the quadric sphere does; knots,
 * ranges and orders as RenderMan reads them; texture coordinates; errors.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "rayes/rayes.h"
#include "record_sink.h"
#include "rib_round_trip.h"
#include "test.h"

static Record rec;
static char err[1024];

static RayesError rib(const char *text)
{
    return record_rib(&rec, text, NULL, err, sizeof err);
}

#define WORLD(body) "Projection \"perspective\" \"fov\" 40\nWorldBegin\n" body "\nWorldEnd\n"

/* A 5 x 5 grid of control points, bumpy in z. */
static void grid_points(char *out, size_t size)
{
    size_t k = 0;
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 5; i++)
            k += (size_t)snprintf(out + k, size - k, "%d %d %g ", i, j,
                                  0.3 * sin(1.3 * i + 0.7 * j) + 0.1 * i * j);
}

static float max_diff(const float (*a)[3], const float (*b)[3], int n)
{
    float d = 0;
    for (int k = 0; k < n; k++)
        for (int c = 0; c < 3; c++)
            d = fmaxf(d, fabsf(a[k][c] - b[k][c]));
    return d;
}

static void test_polynomial_spans_exact(void)
{
    char P[2048], text[8192];
    grid_points(P, sizeof P);
    /* a uniform cubic B-spline of 5 x 5 points: 2 x 2 spans, the patches
     * of the same points as a b-spline PatchMesh */
    snprintf(text, sizeof text,
             WORLD("NuPatch 5 4 [0 1 2 3 4 5 6 7 8] 3 5 5 4 [0 1 2 3 4 5 6 7 8] 3 5 \"P\" [%s]"),
             P);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_patch == 4);
    float nurbs[4][16][3];
    for (int k = 0; k < rec.n_patch && k < 4; k++)
        memcpy(nurbs[k], rec.patch[k].P, sizeof nurbs[k]);
    snprintf(text, sizeof text,
             WORLD("Basis \"b-spline\" 1 \"b-spline\" 1\n"
                   "PatchMesh \"bicubic\" 5 \"nonperiodic\" 5 \"nonperiodic\" \"P\" [%s]"),
             P);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_patch == 4);
    for (int k = 0; k < rec.n_patch && k < 4; k++)
        CHECK(max_diff((const float(*)[3])nurbs[k], (const float(*)[3])rec.patch[k].P, 16) <
              2e-5f);
    /* a quadratic in u (order 3, degree elevated exactly) and a clamped
     * cubic in v: still one patch per span, on the surface */
    snprintf(text, sizeof text,
             WORLD("NuPatch 5 3 [0 0 0 1 2 3 3 3] 0 3 5 4 [0 0 0 0 1 2 2 2 2] 0 2 \"P\" [%s]"), P);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_patch == 3 * 2);
    /* texture coordinates default to (u, v): the last span's far corner */
    const RecPatch *last = &rec.patch[rec.n_patch - 1];
    const RayesPrimvar *st = rec_primvar(&last->pv, "st");
    CHECK(st && st->cls == RAYES_PRIMVAR_VARYING && st->count == 4);
    if (st)
        CHECK(st->data[6] == 3.0f && st->data[7] == 2.0f);
    /* varying st: one value per knot span corner, an empty span's too
     * (RenderMan's count, (nu - uorder + 2) (nv - vorder + 2)): the span
     * after the empty one reads corners 2 and 3 */
    CHECK(rib(WORLD("NuPatch 5 3 [0 0 0 1 1 2 2 2] 0 2 2 2 [0 0 1 1] 0 1 \"P\" [0 0 0 1 0 0 2 0 0 "
                    "3 0 0 4 0 0 0 1 0 1 1 0 2 1 0 3 1 0 4 1 0] \"st\" [0 0 1 0 2 0 3 0 0 1 1 1 "
                    "2 1 3 1]")) == RAYES_OK);
    CHECK(rec.n_patch == 2);
    st = rec.n_patch == 2 ? rec_primvar(&rec.patch[1].pv, "st") : NULL;
    CHECK(st && st->data[0] == 2.0f && st->data[2] == 3.0f && st->data[7] == 1.0f);
    /* a range inside the knots: only the spans it covers, cut at it */
    snprintf(text, sizeof text,
             WORLD("NuPatch 5 4 [0 1 2 3 4 5 6 7 8] 3.5 5 5 4 [0 1 2 3 4 5 6 7 8] 3 4 \"P\" [%s]"),
             P);
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_patch == 2);
    st = rec_primvar(&rec.patch[0].pv, "st");
    CHECK(st && st->data[0] == 3.5f);
}

/* The point of a bicubic Bezier patch at (u, v). */
static void bezier(const float P[16][3], float u, float v, float out[3])
{
    float bu[4] = {(1 - u) * (1 - u) * (1 - u), 3 * u * (1 - u) * (1 - u), 3 * u * u * (1 - u),
                   u * u * u};
    float bv[4] = {(1 - v) * (1 - v) * (1 - v), 3 * v * (1 - v) * (1 - v), 3 * v * v * (1 - v),
                   v * v * v};
    out[0] = out[1] = out[2] = 0;
    for (int j = 0; j < 4; j++)
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++)
                out[c] += bu[i] * bv[j] * P[4 * j + i][c];
}

/* A unit NURBS sphere: a rational quadratic circle (9 points) swept along
 * a half circle (5 points), as modellers write it. */
static void sphere_rib(char *out, size_t size, const char *before, const char *after)
{
    static const float cu[9][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 1}, {-1, 0},
                                   {-1, -1}, {0, -1}, {1, -1}, {1, 0}};
    static const float cv[5][2] = {{0, -1}, {1, -1}, {1, 0}, {1, 1}, {0, 1}};
    float h = sqrtf(0.5f);
    size_t k = (size_t)snprintf(out, size,
                                "%sNuPatch 9 3 [0 0 0 0.25 0.25 0.5 0.5 0.75 0.75 1 1 1] 0 1 "
                                "5 3 [0 0 0 0.5 0.5 1 1 1] 0 1 \"Pw\" [",
                                before);
    for (int j = 0; j < 5; j++)
        for (int i = 0; i < 9; i++) {
            float w = (i % 2 ? h : 1) * (j % 2 ? h : 1);
            k += (size_t)snprintf(out + k, size - k, "%.9g %.9g %.9g %.9g ",
                                  cu[i][0] * cv[j][0] * w, cu[i][1] * cv[j][0] * w, cv[j][1] * w,
                                  w);
        }
    snprintf(out + k, size - k, "]\n%s", after);
}

static void test_rational_sphere(void)
{
    char text[16384];
    sphere_rib(text, sizeof text, "Projection \"perspective\" \"fov\" 40\nWorldBegin\n",
               "WorldEnd\n");
    CHECK(rib(text) == RAYES_OK);
    CHECK(rec.n_patch >= 32); /* split until the fit holds */
    float worst = 0;
    for (int k = 0; k < rec.n_patch; k++)
        for (int b = 0; b <= 4; b++)
            for (int a = 0; a <= 4; a++) {
                float p[3];
                bezier((const float(*)[3])rec.patch[k].P, (float)a / 4, (float)b / 4, p);
                worst = fmaxf(worst, fabsf(sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]) - 1));
            }
    CHECK(worst < 2e-4f);
    /* rendered: the quadric sphere's image */
    const char *head = "Format 48 48 1\nProjection \"perspective\" \"fov\" 30\nTranslate 0 0 5\n"
                       "WorldBegin\nLightSource \"distantlight\" 1 \"from\" [1 1 -1] \"to\" "
                       "[0 0 0]\n";
    char quadric[1024];
    snprintf(quadric, sizeof quadric, "%sSphere 1 -1 1 360\nWorldEnd\n", head);
    sphere_rib(text, sizeof text, head, "WorldEnd\n");
    RayesImage *img[2] = {NULL, NULL};
    for (int k = 0; k < 2; k++) {
        RayesError e;
        RayesScene *s = rib_read_scene(k ? quadric : text, &e, err, sizeof err);
        CHECK(e == RAYES_OK);
        if (e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK) {
            RayesRenderOptions o;
            rayes_render_options_init(&o, RAYES_QUALITY_PREVIEW);
            o.width = o.height = 48;
            o.spp = 16;
            o.threads = 2;
            o.bounces = 0;
            CHECK(rayes_render(s, &o, &img[k], NULL) == RAYES_OK);
        }
        rayes_scene_release(s);
    }
    if (img[0] && img[1]) {
        double m[2] = {0, 0}, alpha[2] = {0, 0};
        for (int k = 0; k < 2; k++)
            for (int i = 0; i < 48 * 48; i++)
                m[k] += img[k]->rgba[4 * i], alpha[k] += img[k]->rgba[4 * i + 3];
        CHECK_NEAR(m[0], m[1], 0.005 * m[1]);
        CHECK_NEAR(alpha[0], alpha[1], 0.005 * alpha[1]);
    }
    rayes_image_free(img[0]);
    rayes_image_free(img[1]);
}

static RayesError rec_motion_begin(void *t, size_t n, const float *times)
{
    (void)t, (void)n, (void)times;
    return RAYES_OK;
}

static RayesError rec_motion_end(void *t)
{
    (void)t;
    return RAYES_OK;
}

/* A rational patch whose centre weight changes between the samples of a
 * deformation: each sample the same patches (a fit that splits by its own
 * error would split them apart and pair them wrongly, or fail). */
static void test_deforming(void)
{
    char text[4096];
    const char *pts = "-1 -1 0 1  0 -1 0 1  1 -1 0 1  -1 0 0 1  0 0 %s %s  1 0 0 1  "
                      "-1 1 0 1  0 1 0 1  1 1 0 1";
    char a[512], b[512];
    snprintf(a, sizeof a, pts, "0.9", "0.9");
    snprintf(b, sizeof b, pts, "20", "20");
    snprintf(text, sizeof text,
             "Projection \"perspective\" \"fov\" 40\nShutter 0 1\nWorldBegin\nTranslate 0 0 5\n"
             "MotionBegin [0 1]\nNuPatch 3 3 [0 0 0 1 1 1] 0 1 3 3 [0 0 0 1 1 1] 0 1 \"Pw\" [%s]\n"
             "NuPatch 3 3 [0 0 0 1 1 1] 0 1 3 3 [0 0 0 1 1 1] 0 1 \"Pw\" [%s]\nMotionEnd\n"
             "WorldEnd\n",
             a, b);
    RayesError e;
    RayesScene *s = rib_read_scene(text, &e, err, sizeof err);
    CHECK(e == RAYES_OK);
    CHECK(e == RAYES_OK && rayes_scene_commit(s) == RAYES_OK);
    rayes_scene_release(s);
    /* the samples' patches, recorded one after the other: as many, over
     * the same (u, v) pieces */
    record_free(&rec);
    IoSink sink = record_sink(&rec);
    sink.motion_begin = rec_motion_begin;
    sink.motion_end = rec_motion_end;
    IoSettings settings;
    io_settings_init(&settings);
    IoReadOptions opt = {NULL, -1};
    CHECK(io_rib_parse("t.rib", (const unsigned char *)text, strlen(text), &sink, &opt, &settings,
                       err, sizeof err) == RAYES_OK);
    int half = rec.n_patch / 2;
    CHECK(rec.n_patch > 2 && rec.n_patch % 2 == 0);
    for (int k = 0; k < half && k < REC_MAX / 2; k++) {
        const RayesPrimvar *a = rec_primvar(&rec.patch[k].pv, "st");
        const RayesPrimvar *b = rec_primvar(&rec.patch[half + k].pv, "st");
        CHECK(a && b && memcmp(a->data, b->data, 8 * sizeof(float)) == 0);
    }
}

static void test_reading(void)
{
    (void)rec_param, (void)rib_round_trip; /* the headers' helpers this file does not need */
    char P[2048], text[8192];
    grid_points(P, sizeof P);
    /* RenderMan's rule: an order above the points is their count */
    snprintf(text, sizeof text,
             WORLD("NuPatch 2 4 [0 0 1 1 1 1] 0 1 2 4 [0 0 1 1 1 1] 0 1 \"P\" [0 0 0 1 0 0 "
                   "0 1 0 1 1 0]"));
    CHECK(rib(text) == RAYES_OK && rec.n_patch == 1);
    /* errors name what was expected */
    snprintf(text, sizeof text,
             WORLD("NuPatch 5 4 [0 1 2 3 5 4 6 7 8] 3 5 5 4 [0 1 2 3 4 5 6 7 8] 3 5 \"P\" [%s]"),
             P);
    CHECK(rib(text) != RAYES_OK && strstr(err, "non-decreasing") && strstr(err, "t.rib:3"));
    CHECK(rib(WORLD("NuPatch 5 4 [0 1 2 3 4 5 6 7 8] 3 5 5 4 [0 1 2 3 4 5 6 7 8] 3 5 "
                    "\"P\" [0 0 0]")) != RAYES_OK &&
          strstr(err, "\"P\" needs 5 x 5"));
    CHECK(rib(WORLD("NuPatch 5 1 [0 1 2 3 4 5] 0 5 5 4 [0 1 2 3 4 5 6 7 8] 3 5 \"P\" [0 0 0]")) !=
          RAYES_OK);
    CHECK(rib(WORLD("NuPatch 5 4 [0 1 2 3 4 5 6 7 8] 6 7 5 4 [0 1 2 3 4 5 6 7 8] 3 5 \"P\" "
                    "[0 0 0]")) != RAYES_OK &&
          strstr(err, "range is empty"));
    CHECK(rib(WORLD("NuPatch 1e9 4 [0] 0 1 1 2 [0 1] 0 1 \"P\" [0 0 0]")) != RAYES_OK);
    /* a small file asking for hours of work is refused: an order-32
     * rational patch of many spans */
    {
        static char big[1 << 17];
        size_t k = (size_t)snprintf(big, sizeof big, "WorldBegin\nNuPatch 64 32 [");
        for (int j = 0; j < 96; j++)
            k += (size_t)snprintf(big + k, sizeof big - k, "%d ", j);
        k += (size_t)snprintf(big + k, sizeof big - k, "] 31 64 64 32 [");
        for (int j = 0; j < 96; j++)
            k += (size_t)snprintf(big + k, sizeof big - k, "%d ", j);
        k += (size_t)snprintf(big + k, sizeof big - k, "] 31 64 \"Pw\" [");
        for (int j = 0; j < 64 * 64; j++)
            k += (size_t)snprintf(big + k, sizeof big - k, "%d %d %d %d ", j % 64, j / 64, j % 7,
                                  1 + j % 3);
        snprintf(big + k, sizeof big - k, "]\nWorldEnd\n");
        CHECK(rib(big) != RAYES_OK && strstr(err, "refused"));
    }
    /* w must be positive */
    CHECK(rib(WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 0 1 1 0 0 0 "
                    "0 1 0 1 1 1 0 1]")) != RAYES_OK &&
          strstr(err, "w is not positive"));
    /* a TrimCurve that does not read (too few knots): warned, ignored */
    snprintf(text, sizeof text,
             WORLD("TrimCurve [1] [2] [0 0 1] [0] [1] [2] [0.2 0.8] [0.2 0.8] [1 1]\n"
                   "NuPatch 5 4 [0 1 2 3 4 5 6 7 8] 3 5 5 4 [0 1 2 3 4 5 6 7 8] 3 5 \"P\" [%s]"),
             P);
    CHECK(rib(text) == RAYES_OK && rec.n_patch == 4);
}

/* The centres of the patches sent: how many lie inside |x|, |y| < h and
 * how many outside |x|, |y| < h2. */
static void centres(float h, float h2, int *in, int *out)
{
    *in = *out = 0;
    for (int k = 0; k < rec.n_patch; k++) {
        float c[3];
        bezier((const float(*)[3])rec.patch[k].P, 0.5f, 0.5f, c);
        *in += fabsf(c[0]) < h && fabsf(c[1]) < h;
        *out += fabsf(c[0]) > h2 || fabsf(c[1]) > h2;
    }
}

/* A flat 2 x 2 square, (u, v) over [0, 1]^2, after trim. */
#define SQUARE_NUPATCH(trim)                                                                       \
    WORLD(trim "NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [-1 -1 0 1 -1 0 -1 1 0 1 1 0]")
#define SQUARE_LOOP                                                                                \
    "TrimCurve [1] [2] [0 0 1 2 3 4 4] [0] [4] [5] [0.2 0.8 0.8 0.2 0.2] [0.2 0.2 0.8 0.8 0.2] "   \
    "[1 1 1 1 1]\n"

static void test_trim(void)
{
    int in, out;
    CHECK(rib(SQUARE_NUPATCH("")) == RAYES_OK && rec.n_patch == 1);
    /* RenderMan's default: the loop's inside, (u, v) in [0.2, 0.8]^2, is
     * cut away, to 1/128 of the patch */
    CHECK(rib(SQUARE_NUPATCH(SQUARE_LOOP)) == RAYES_OK);
    centres(0.59f, 0.61f, &in, &out);
    CHECK(rec.n_patch > 1 && in == 0 && out > 0);
    /* "sense" "outside": only the inside stays */
    CHECK(rib(SQUARE_NUPATCH("Attribute \"trimcurve\" \"sense\" \"outside\"\n" SQUARE_LOOP)) ==
          RAYES_OK);
    centres(0.61f, 0.61f, &in, &out);
    CHECK(rec.n_patch > 1 && in == rec.n_patch && out == 0);
    CHECK(rib(SQUARE_NUPATCH("Attribute \"trimcurve\" \"sense\" \"sideways\"\n")) != RAYES_OK);
    /* an attribute: AttributeEnd and an empty TrimCurve end it */
    CHECK(rib(SQUARE_NUPATCH("AttributeBegin\n" SQUARE_LOOP "AttributeEnd\n")) == RAYES_OK &&
          rec.n_patch == 1);
    CHECK(rib(SQUARE_NUPATCH(SQUARE_LOOP "TrimCurve [] [] [] [] [] [] [] [] []\n")) == RAYES_OK &&
          rec.n_patch == 1);
    /* a rational circle of radius 0.3 about the centre: a round hole,
     * its edge within 1/128 of the patch (1/64 of its width 2) */
    /* (u and v given times w: homogeneous, as RenderMan's spec and
     * modellers write them) */
    CHECK(rib(SQUARE_NUPATCH("TrimCurve [1] [3] [0 0 0 1 1 2 2 3 3 4 4 4] [0] [4] [9] "
                             "[0.8 0.56568542 0.5 0.14142136 0.2 0.14142136 0.5 0.56568542 0.8] "
                             "[0.5 0.56568542 0.8 0.56568542 0.5 0.14142136 0.2 0.14142136 0.5] "
                             "[1 0.70710678 1 0.70710678 1 0.70710678 1 0.70710678 1]\n")) ==
          RAYES_OK);
    float nearest = INFINITY; /* the kept piece nearest the centre */
    for (int k = 0; k < rec.n_patch; k++) {
        float c[3];
        bezier((const float(*)[3])rec.patch[k].P, 0.5f, 0.5f, c);
        nearest = fminf(nearest, sqrtf(c[0] * c[0] + c[1] * c[1]));
    }
    CHECK(rec.n_patch > 1 && nearest > 0.6f - 2.0f / 128 && nearest < 0.6f + 4.0f / 128);
}

/* Cs: vertex colours through the surface's own basis, weighted as its
 * points are (a rational patch pulls the colour toward heavy points),
 * varying ones a span corner each, a constant one; reached the patches'
 * corners (Houdini's NuPatches were left uncoloured). */
static void test_colours(void)
{
    /* bilinear: red at u = 0, blue at u = 1 */
    CHECK(rib(WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 1 1 0 1 0 1 1 1 1 1] "
                    "\"vertex color Cs\" [1 0 0 0 0 1 1 0 0 0 0 1]")) == RAYES_OK);
    const RayesPrimvar *cs = rec.n_patch == 1 ? rec_primvar(&rec.patch[0].pv, "Cs") : NULL;
    CHECK(cs && cs->count == 4);
    if (cs)
        CHECK(cs->data[0] == 1 && cs->data[2] == 0 && cs->data[3] == 0 && cs->data[5] == 1);
    /* rational, quadratic in u, red, green, blue along u, the middle point
     * weighing 3: at u = 0.5 (a corner, the span being split) green is
     * 0.5 3 / (0.25 + 1.5 + 0.25) = 0.75, where unweighted it would be 0.5 */
    CHECK(rib(WORLD("NuPatch 3 3 [0 0 0 1 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"Pw\" [0 0 1 1  1.5 0 3 3  "
                    "1 0 1 1  0 1 1 1  1.5 3 3 3  1 1 1 1] \"vertex color Cs\" [1 0 0 0 1 0 0 0 1 "
                    "1 0 0 0 1 0 0 0 1]")) == RAYES_OK);
    int found = 0, middle = 0;
    for (int k = 0; k < rec.n_patch; k++) {
        const RayesPrimvar *c = rec_primvar(&rec.patch[k].pv, "Cs");
        found += c != NULL;
        for (int j = 0; c && j < 4; j++) {
            CHECK_NEAR(c->data[3 * j] + c->data[3 * j + 1] + c->data[3 * j + 2], 1, 1e-5);
            middle += fabsf(c->data[3 * j + 1] - 0.75f) < 1e-4f;
        }
    }
    CHECK(found == rec.n_patch && found > 0 && middle > 0);
    /* varying: a span corner each; constant: one */
    CHECK(rib(WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 1 1 0 1 0 1 1 1 1 1] "
                    "\"varying color Cs\" [0 1 0 0 1 0 0 0 1 0 0 1]")) == RAYES_OK);
    cs = rec.n_patch == 1 ? rec_primvar(&rec.patch[0].pv, "Cs") : NULL;
    CHECK(cs && cs->data[1] == 1 && cs->data[11] == 1);
    CHECK(rib(WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 1 1 0 1 0 1 1 1 1 1] "
                    "\"constant color Cs\" [0.2 0.4 0.6]")) == RAYES_OK);
    cs = rec.n_patch == 1 ? rec_primvar(&rec.patch[0].pv, "Cs") : NULL;
    CHECK(cs && cs->data[9] == 0.2f && cs->data[11] == 0.6f);
    /* a count that fits no class: the patch uncoloured (one warning) */
    CHECK(rib(WORLD("NuPatch 2 2 [0 0 1 1] 0 1 2 2 [0 0 1 1] 0 1 \"P\" [0 0 1 1 0 1 0 1 1 1 1 1] "
                    "\"vertex color Cs\" [1 0 0 0 0 1]")) == RAYES_OK);
    CHECK(rec.n_patch == 1 && rec_primvar(&rec.patch[0].pv, "Cs") == NULL);
}

TEST_MAIN(TEST(test_polynomial_spans_exact), TEST(test_rational_sphere), TEST(test_reading),
          TEST(test_trim), TEST(test_deforming), TEST(test_colours))
