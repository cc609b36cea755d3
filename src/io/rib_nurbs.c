/*
 * io/rib_nurbs.c — RenderMan's NuPatch: a non-uniform rational B-spline
 * surface of any order, made bicubic Bezier patches (docs/rib.md).
 *
 * Each span of the knot vectors within [umin, umax] x [vmin, vmax] is
 * evaluated exactly (de Boor's algorithm on the homogeneous points Pw,
 * then divided by w) at a 4 x 4 lattice of parameters, and the bicubic
 * Bezier patch through those 16 points is sent: the same surface, exactly,
 * when the span is a polynomial of degree 3 or less in each direction
 * (order 2 to 4, every w equal). A rational span (a circle's arc) or one
 * of higher order is approximated so: it is checked against the exact
 * surface between the lattice points and split in four until the two
 * agree within NURBS_TOLERANCE of its size (a quarter circle in one
 * piece is off by 3e-4 of its radius; each split divides that by 16).
 * Texture coordinates default to (u, v), RenderMan's for NURBS; "st"
 * (or "s" and "t") of class varying, one value per span corner, are
 * interpolated bilinearly across each span.
 *
 * Trim curves (TrimCurve, an attribute) are made polygons in (u, v), each
 * curve 16 segments a knot span; a piece of the surface the loops cross
 * is split in four, down to 1/128 of its span, and each piece is kept or
 * cut by whether its centre lies inside the loops (odd crossings):
 * RenderMan's default cuts the insides away, Attribute "trimcurve"
 * "sense" "outside" the outsides. Trimmed edges are so exact to 1/128 of a
 * span, in steps.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_reader.h"

#define NURBS_MAX_ORDER 32
#define NURBS_MAX_POINTS (1L << 24)
/* A NuPatch makes at most this many Bezier patches (a hostile file's
 * knot vector of a million spans is an error, not a long wait). */
#define NURBS_MAX_PATCHES (1L << 22)
#define NURBS_TOLERANCE 1e-4f
#define NURBS_MAX_SPLITS 5
/* In a deformation motion block every sample must make the same patches:
 * a span that is not exact is split so many times, whatever its fit. */
#define NURBS_MOTION_SPLITS 2
/* The work a file's NURBS may take, in multiply-adds of de Boor and trim
 * tests: a few seconds; a small hostile file could ask for hours. */
#define NURBS_MAX_WORK 2e9

#define TRIM_SEGMENTS 16 /* polygon edges per knot span of a trim curve */
#define TRIM_MAX_POINTS (1L << 20)
#define TRIM_SPLITS 7 /* a crossed piece is split down to 1/128 of its span */

/* The loops of a TrimCurve as polygons in (u, v). */
typedef struct TrimSet {
    size_t n_loops;
    size_t *first; /* loop k: points first[k] .. first[k + 1] - 1 (closed) */
    float (*pt)[2];
    float lo[2], hi[2];
    struct TrimSet *next;
} TrimSet;

typedef struct Nurbs {
    int n[2], order[2];  /* control points and order in u (0) and v (1) */
    const float *knot[2];
    const float *Pw;     /* n[0] x n[1] homogeneous points, u fastest */
    double *work;        /* the file's NURBS work so far (Rib.nurbs_work) */
} Nurbs;

/* de Boor on dim-float points d[0..p] of span k (knots t), at x: the
 * points are overwritten, the result is d[p]. */
static void de_boor(float (*d)[4], const float *t, int k, int p, float x)
{
    for (int r = 1; r <= p; r++)
        for (int j = p; j >= r; j--) {
            int i = k - p + j;
            float den = t[i + p + 1 - r] - t[i];
            float a = den > 0 ? (x - t[i]) / den : 0;
            for (int c = 0; c < 4; c++)
                d[j][c] = (1 - a) * d[j - 1][c] + a * d[j][c];
        }
}

/* The surface at (u, v) in span (ku, kv): a point. */
static void eval(const Nurbs *s, int ku, int kv, float u, float v, float out[3])
{
    int pu = s->order[0] - 1, pv = s->order[1] - 1;
    float row[NURBS_MAX_ORDER][4], col[NURBS_MAX_ORDER][4];
    *s->work += (double)(pu + 1) * (pv + 1) * (pu + pv + 2);
    for (int j = 0; j <= pv; j++) {
        int l = kv - pv + j;
        for (int q = 0; q <= pu; q++)
            memcpy(row[q], &s->Pw[4 * ((size_t)l * (size_t)s->n[0] + (size_t)(ku - pu + q))],
                   sizeof row[0]);
        de_boor(row, s->knot[0], ku, pu, u);
        memcpy(col[j], row[pu], sizeof col[0]);
    }
    de_boor(col, s->knot[1], kv, pv, v);
    float w = col[pv][3];
    if (!(fabsf(w) > 1e-30f))
        w = 1e-30f;
    for (int c = 0; c < 3; c++)
        out[c] = col[pv][c] / w;
}

/* The inverse of the cubic Bernstein basis sampled at 0, 1/3, 2/3, 1:
 * the Bezier control values of the cubic through four such samples. */
static const float bezier_from_samples[4][4] = {{1, 0, 0, 0},
                                                {-5.0f / 6, 3, -1.5f, 1.0f / 3},
                                                {1.0f / 3, -1.5f, 3, -5.0f / 6},
                                                {0, 0, 0, 1}};

static float bernstein(int i, float t)
{
    float s = 1 - t;
    return i == 0 ? s * s * s : i == 1 ? 3 * t * s * s : i == 2 ? 3 * t * t * s : t * t * t;
}

/* The bicubic Bezier patch through the surface at a 4 x 4 lattice of
 * [u0, u1] x [v0, v1] in span (ku, kv); B[4 j + i], i along u. */
static void fit(const Nurbs *s, int ku, int kv, const float u[2], const float v[2],
                float B[16][3])
{
    float S[4][4][3], T[4][4][3];
    for (int l = 0; l < 4; l++)
        for (int k = 0; k < 4; k++)
            eval(s, ku, kv, u[0] + (u[1] - u[0]) * (float)k / 3, v[0] + (v[1] - v[0]) * (float)l / 3,
                 S[l][k]);
    for (int l = 0; l < 4; l++) /* along u */
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++) {
                float x = 0;
                for (int k = 0; k < 4; k++)
                    x += bezier_from_samples[i][k] * S[l][k][c];
                T[l][i][c] = x;
            }
    for (int j = 0; j < 4; j++) /* along v */
        for (int i = 0; i < 4; i++)
            for (int c = 0; c < 3; c++) {
                float x = 0;
                for (int l = 0; l < 4; l++)
                    x += bezier_from_samples[j][l] * T[l][i][c];
                B[4 * j + i][c] = x;
            }
}

/* How far the patch B strays from the surface between its lattice
 * points, over the patch's size. */
static float fit_error(const Nurbs *s, int ku, int kv, const float u[2], const float v[2],
                       const float B[16][3])
{
    float lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (int k = 0; k < 16; k++)
        for (int c = 0; c < 3; c++)
            lo[c] = fminf(lo[c], B[k][c]), hi[c] = fmaxf(hi[c], B[k][c]);
    float size = sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                       (hi[2] - lo[2]) * (hi[2] - lo[2]));
    float worst = 0;
    for (int b = 0; b < 3; b++)
        for (int a = 0; a < 3; a++) {
            float x = (1 + 2 * (float)a) / 6, y = (1 + 2 * (float)b) / 6, P[3], Q[3] = {0, 0, 0};
            eval(s, ku, kv, u[0] + (u[1] - u[0]) * x, v[0] + (v[1] - v[0]) * y, P);
            for (int j = 0; j < 4; j++)
                for (int i = 0; i < 4; i++) {
                    float w = bernstein(i, x) * bernstein(j, y);
                    for (int c = 0; c < 3; c++)
                        Q[c] += w * B[4 * j + i][c];
                }
            float d = sqrtf((P[0] - Q[0]) * (P[0] - Q[0]) + (P[1] - Q[1]) * (P[1] - Q[1]) +
                            (P[2] - Q[2]) * (P[2] - Q[2]));
            worst = fmaxf(worst, d);
        }
    return size > 0 ? worst / size : 0;
}

/* What a NuPatch call sends its patches with. */
typedef struct Emit {
    Rib *r;
    const Nurbs *s;
    int exact;        /* polynomial of order <= 4: one patch a span */
    int fixed;        /* in a deformation motion block: NURBS_MOTION_SPLITS */
    const float *st;  /* varying st, one per knot span corner (u fastest), or NULL */
    size_t st_w;      /* corners along u: n[0] - order[0] + 2 */
    const Nurbs *cs_vertex;   /* vertex Cs: the surface's weights times the colours, or NULL */
    const float *cs_varying;  /* varying Cs, one per knot span corner, or NULL */
    const float *cs_constant; /* constant Cs, or NULL */
    long made;
    int unconverged;
    const TrimSet *trim; /* or NULL */
    int trim_outside;
} Emit;

/* Whether segment a-b passes through the open rectangle (Liang-Barsky). */
static int segment_crosses(const float a[2], const float b[2], const float u[2], const float v[2])
{
    float t0 = 0, t1 = 1, d[2] = {b[0] - a[0], b[1] - a[1]};
    const float lo[2] = {u[0], v[0]}, hi[2] = {u[1], v[1]};
    for (int k = 0; k < 2; k++) {
        if (d[k] == 0) {
            if (!(a[k] > lo[k] && a[k] < hi[k]))
                return 0;
            continue;
        }
        float ta = (lo[k] - a[k]) / d[k], tb = (hi[k] - a[k]) / d[k];
        if (ta > tb) {
            float x = ta;
            ta = tb, tb = x;
        }
        t0 = fmaxf(t0, ta);
        t1 = fminf(t1, tb);
        if (t0 >= t1)
            return 0;
    }
    return 1;
}

/* Whether (x, y) lies inside the loops: an odd number of crossings. */
static int inside_loops(const TrimSet *t, float x, float y)
{
    int in = 0;
    for (size_t k = 0; k < t->n_loops; k++)
        for (size_t i = t->first[k], j = t->first[k + 1] - 1; i < t->first[k + 1]; j = i++) {
            const float *a = t->pt[i], *b = t->pt[j];
            if ((a[1] > y) != (b[1] > y) && x < a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1]))
                in = !in;
        }
    return in;
}

/* A piece of the surface against the trim loops: 1 kept whole, 0 cut
 * away whole, -1 crossed by them. */
static int trim_state(const Emit *e, const float u[2], const float v[2])
{
    const TrimSet *t = e->trim;
    if (!t)
        return 1;
    e->r->nurbs_work += 8.0 * (double)t->first[t->n_loops];
    if (u[1] > t->lo[0] && u[0] < t->hi[0] && v[1] > t->lo[1] && v[0] < t->hi[1])
        for (size_t k = 0; k < t->n_loops; k++)
            for (size_t i = t->first[k], j = t->first[k + 1] - 1; i < t->first[k + 1]; j = i++)
                if (segment_crosses(t->pt[j], t->pt[i], u, v))
                    return -1;
    int in = inside_loops(t, 0.5f * (u[0] + u[1]), 0.5f * (v[0] + v[1]));
    return in == e->trim_outside;
}

/* st at (u, v) in knot span (ku, kv): varying values are RenderMan's, one
 * per knot span corner (empty spans too), bilinear over the span. */
static void st_at(const Emit *e, int ku, int kv, float u, float v, float out[2])
{
    if (!e->st) {
        out[0] = u, out[1] = v;
        return;
    }
    const float *tu = e->s->knot[0], *tv = e->s->knot[1];
    float x = (u - tu[ku]) / (tu[ku + 1] - tu[ku]), y = (v - tv[kv]) / (tv[kv + 1] - tv[kv]);
    size_t w = e->st_w;
    size_t a = (size_t)(kv - (e->s->order[1] - 1)) * w + (size_t)(ku - (e->s->order[0] - 1));
    const float *c[4] = {&e->st[2 * a], &e->st[2 * (a + 1)], &e->st[2 * (a + w)],
                         &e->st[2 * (a + w + 1)]};
    for (int k = 0; k < 2; k++)
        out[k] = (1 - y) * ((1 - x) * c[0][k] + x * c[1][k]) + y * ((1 - x) * c[2][k] + x * c[3][k]);
}

/* Cs at (u, v) in knot span (ku, kv), as the file gives it: vertex colours
 * through the surface's own (rational) basis, varying ones bilinear over
 * the span as st, a constant one. 0 if the file gives none. */
static int cs_at(const Emit *e, int ku, int kv, float u, float v, float out[3])
{
    if (e->cs_vertex) {
        eval(e->cs_vertex, ku, kv, u, v, out);
        return 1;
    }
    if (e->cs_constant) {
        memcpy(out, e->cs_constant, 3 * sizeof *out);
        return 1;
    }
    if (!e->cs_varying)
        return 0;
    const float *tu = e->s->knot[0], *tv = e->s->knot[1];
    float x = (u - tu[ku]) / (tu[ku + 1] - tu[ku]), y = (v - tv[kv]) / (tv[kv + 1] - tv[kv]);
    size_t w = e->st_w;
    size_t a = (size_t)(kv - (e->s->order[1] - 1)) * w + (size_t)(ku - (e->s->order[0] - 1));
    const float *c[4] = {&e->cs_varying[3 * a], &e->cs_varying[3 * (a + 1)],
                         &e->cs_varying[3 * (a + w)], &e->cs_varying[3 * (a + w + 1)]};
    for (int k = 0; k < 3; k++)
        out[k] =
            (1 - y) * ((1 - x) * c[0][k] + x * c[1][k]) + y * ((1 - x) * c[2][k] + x * c[3][k]);
    return 1;
}

/* Sends the patches of [u0, u1] x [v0, v1] in span (ku, kv), split while
 * the fit strays (depth splits so far) or trim loops cross it (tdepth). */
static int emit_part(Emit *e, int ku, int kv, const float u[2], const float v[2], int depth,
                     int tdepth)
{
    if (e->r->nurbs_work > NURBS_MAX_WORK)
        return rib_error(e->r,
                         "NuPatch: the file's NURBS need more than %.0e evaluations; "
                         "refused",
                         NURBS_MAX_WORK);
    int trim = trim_state(e, u, v);
    if (trim < 0 && tdepth < TRIM_SPLITS) {
        float um = 0.5f * (u[0] + u[1]), vm = 0.5f * (v[0] + v[1]);
        const float us[2][2] = {{u[0], um}, {um, u[1]}}, vs[2][2] = {{v[0], vm}, {vm, v[1]}};
        for (int b = 0; b < 2; b++)
            for (int a = 0; a < 2; a++)
                if (emit_part(e, ku, kv, us[a], vs[b], depth + 1, tdepth + 1) != 0)
                    return -1;
        return 0;
    }
    if (trim < 0) /* as fine as trims go: by its centre */
        trim = inside_loops(e->trim, 0.5f * (u[0] + u[1]), 0.5f * (v[0] + v[1])) == e->trim_outside;
    if (trim == 0)
        return 0;
    float B[16][3];
    fit(e->s, ku, kv, u, v, B);
    int split = 0;
    if (!e->exact && e->fixed)
        split = depth < NURBS_MOTION_SPLITS;
    else if (!e->exact && fit_error(e->s, ku, kv, u, v, B) > NURBS_TOLERANCE) {
        split = depth < NURBS_MAX_SPLITS;
        e->unconverged |= !split;
    }
    {
        if (split) {
            float um = 0.5f * (u[0] + u[1]), vm = 0.5f * (v[0] + v[1]);
            const float us[2][2] = {{u[0], um}, {um, u[1]}}, vs[2][2] = {{v[0], vm}, {vm, v[1]}};
            for (int b = 0; b < 2; b++)
                for (int a = 0; a < 2; a++)
                    if (emit_part(e, ku, kv, us[a], vs[b], depth + 1, TRIM_SPLITS) !=
                        0) /* a piece the loops cross no more */
                        return -1;
            return 0;
        }
    }
    if (++e->made > NURBS_MAX_PATCHES)
        return rib_error(e->r, "NuPatch: more than %ld patches", NURBS_MAX_PATCHES);
    float st[4][2], cs[4][3];
    const float cu[4] = {u[0], u[1], u[0], u[1]}, cv[4] = {v[0], v[0], v[1], v[1]};
    int flip = rib_flip(e->r), coloured = 0; /* the patch's u reverses: so do its corners' */
    for (int k = 0; k < 4; k++) {
        st_at(e, ku, kv, cu[k], cv[k], st[flip ? k ^ 1 : k]);
        coloured = cs_at(e, ku, kv, cu[k], cv[k], cs[flip ? k ^ 1 : k]);
    }
    PvOut pv = {.n = 1};
    pv.pv[0] = (RayesPrimvar){"st", RAYES_PRIMVAR_VARYING, &st[0][0], 4};
    if (coloured)
        pv.pv[pv.n++] = (RayesPrimvar){"Cs", RAYES_PRIMVAR_VARYING, &cs[0][0], 4};
    return rib_emit_bicubic(e->r, B, &pv);
}

/* A knot vector of n + order values, non-decreasing and finite. */
static int read_knots(Rib *r, const Args *a, size_t *i, int n, int order, float **out,
                      const char *what)
{
    size_t count = (size_t)n + (size_t)order;
    float *k = malloc(count * sizeof *k);
    if (!k)
        return rib_error(r, "out of memory");
    if (rib_get_floats(r, a, i, k, count, what) != 0) {
        free(k);
        return -1;
    }
    for (size_t j = 0; j < count; j++)
        if (!isfinite(k[j]) || (j > 0 && k[j] < k[j - 1])) {
            free(k);
            return rib_error(r, "NuPatch: %s must be finite and non-decreasing", what);
        }
    *out = k;
    return 0;
}

/* n, order, knots, min and max of one direction. */
static int read_direction(Rib *r, const Args *a, size_t *i, int dir, int *n, int *order,
                          float **knot, float range[2])
{
    const char *names[2] = {"u", "v"};
    float no[2];
    char what[32];
    snprintf(what, sizeof what, "n%s and %sorder", names[dir], names[dir]);
    if (rib_get_floats(r, a, i, no, 1, what) != 0 || rib_get_floats(r, a, i, no + 1, 1, what) != 0)
        return -1;
    if (!(no[0] >= 1 && no[0] <= NURBS_MAX_POINTS && no[0] == floorf(no[0])) ||
        !(no[1] >= 2 && no[1] <= NURBS_MAX_ORDER && no[1] == floorf(no[1])))
        return rib_error(r,
                         "NuPatch: expected n%s >= 1 and %sorder from 2 to %d (whole numbers), "
                         "found %g and %g",
                         names[dir], names[dir], NURBS_MAX_ORDER, no[0], no[1]);
    *n = (int)no[0];
    *order = (int)no[1];
    snprintf(what, sizeof what, "the %s knots", names[dir]);
    if (read_knots(r, a, i, *n, *order, knot, what) != 0)
        return -1;
    snprintf(what, sizeof what, "%smin and %smax", names[dir], names[dir]);
    if (rib_get_floats(r, a, i, range, 2, what) != 0)
        return -1;
    if (*order > *n) /* RenderMan: a spline of order n, on the knots it has */
        *order = *n;
    if (*order < 2)
        return rib_error(r, "NuPatch: one control point in %s makes no surface", names[dir]);
    /* the parameters the knots define a surface over */
    float lo = (*knot)[*order - 1], hi = (*knot)[*n];
    range[0] = fmaxf(range[0], lo);
    range[1] = fminf(range[1], hi);
    if (!(range[0] < range[1]))
        return rib_error(r, "NuPatch: the %s range is empty within the knots [%g, %g]",
                         names[dir], lo, hi);
    return 0;
}

/* The spans of one direction within range: their knot index k (knot[k] <
 * knot[k + 1]) and their clipped parameter intervals. */
static int spans(const float *knot, int n, int order, const float range[2], int *k, float (*iv)[2])
{
    int m = 0;
    for (int j = order - 1; j < n; j++) {
        float a = fmaxf(knot[j], range[0]), b = fminf(knot[j + 1], range[1]);
        if (knot[j] < knot[j + 1] && a < b) {
            k[m] = j;
            iv[m][0] = a;
            iv[m][1] = b;
            m++;
        }
    }
    return m;
}

static int h_nupatch(Rib *r, const Args *a)
{
    size_t i = 0;
    Nurbs s = {.Pw = NULL};
    float *knot[2] = {NULL, NULL}, range[2][2], *Pw = NULL;
    int *k[2] = {NULL, NULL};
    float(*iv[2])[2] = {NULL, NULL};
    Param *p = NULL;
    size_t n_p = 0;
    int e = read_direction(r, a, &i, 0, &s.n[0], &s.order[0], &knot[0], range[0]);
    if (e == 0)
        e = read_direction(r, a, &i, 1, &s.n[1], &s.order[1], &knot[1], range[1]);
    if (e == 0 && (long)s.n[0] * s.n[1] > NURBS_MAX_POINTS)
        e = rib_error(r, "NuPatch: more than %ld control points", NURBS_MAX_POINTS);
    if (e == 0)
        e = rib_get_params(r, a, i, &p, &n_p);
    size_t np = e == 0 ? (size_t)s.n[0] * (size_t)s.n[1] : 0;
    int rational = 0;
    if (e == 0) { /* Pw as given (homogeneous), or P with w = 1 */
        const Param *pw = rib_find_param(p, n_p, "Pw"), *pp = rib_find_param(p, n_p, "P");
        const Param *q = pw ? pw : pp;
        size_t size = pw ? 4 : 3;
        if (!q || !rib_is_num(q->v))
            e = rib_error(r, "NuPatch: expected \"P\" or \"Pw\"");
        else if (q->v->n != np * size)
            e = rib_error(r, "NuPatch: \"%s\" needs %d x %d = %zu points, found %zu values",
                          pw ? "Pw" : "P", s.n[0], s.n[1], np, q->v->n);
        else if (!(Pw = malloc(np * 4 * sizeof *Pw)))
            e = rib_error(r, "out of memory");
        for (size_t j = 0; e == 0 && j < np; j++) {
            for (size_t c = 0; c < 4; c++)
                Pw[4 * j + c] = c < size ? (float)q->v->d[size * j + c] : 1.0f;
            if (!isfinite(Pw[4 * j]) || !isfinite(Pw[4 * j + 1]) || !isfinite(Pw[4 * j + 2]) ||
                !(Pw[4 * j + 3] > 0 && isfinite(Pw[4 * j + 3])))
                e = rib_error(r, "NuPatch: point %zu is not finite or its w is not positive", j);
            rational |= Pw[4 * j + 3] != Pw[3];
        }
    }
    int m[2] = {0, 0};
    for (int d = 0; e == 0 && d < 2; d++) {
        k[d] = malloc((size_t)s.n[d] * sizeof *k[d]);
        iv[d] = malloc((size_t)s.n[d] * sizeof *iv[d]);
        if (!k[d] || !iv[d])
            e = rib_error(r, "out of memory");
        else
            m[d] = spans(knot[d], s.n[d], s.order[d], range[d], k[d], iv[d]);
    }
    if (e == 0 && (long)m[0] * m[1] > NURBS_MAX_PATCHES)
        e = rib_error(r, "NuPatch: more than %ld spans", NURBS_MAX_PATCHES);
    /* st (or s and t) of class varying: one value a span corner */
    float *st = NULL, *cw = NULL, *cs_var = NULL, cs_const[3];
    int have_const = 0;
    if (e == 0) {
        const Param *qst = rib_find_param(p, n_p, "st"), *qs = rib_find_param(p, n_p, "s"),
                    *qt = rib_find_param(p, n_p, "t");
        /* RenderMan's count: one per knot span corner, empty spans too */
        size_t corners = (size_t)(s.n[0] - s.order[0] + 2) * (size_t)(s.n[1] - s.order[1] + 2);
        int pair = qst && rib_is_num(qst->v) && qst->v->n == 2 * corners;
        int apart = qs && qt && rib_is_num(qs->v) && rib_is_num(qt->v) &&
                    qs->v->n == corners && qt->v->n == corners;
        if ((qst || qs || qt) && !pair && !apart)
            rib_warn_once(r, "nupatch st",
                          "NuPatch: st (or s and t) needs one value per span corner (varying); "
                          "the patch's (u, v) are used");
        else if (pair || apart) {
            st = malloc(2 * corners * sizeof *st);
            if (!st)
                e = rib_error(r, "out of memory");
            for (size_t j = 0; e == 0 && j < corners; j++) {
                st[2 * j] = (float)(pair ? qst->v->d[2 * j] : qs->v->d[j]);
                st[2 * j + 1] = (float)(pair ? qst->v->d[2 * j + 1] : qt->v->d[j]);
            }
        }
        /* Cs: vertex (through the surface's basis, weighted as P is),
         * varying (a span corner each) or constant */
        const Param *qc = rib_find_param(p, n_p, "Cs");
        size_t points = (size_t)s.n[0] * (size_t)s.n[1];
        if (qc && rib_is_num(qc->v) && qc->v->n == 3 * points && qc->d.cls == CLS_VERTEX) {
            cw = malloc(4 * points * sizeof *cw);
            if (!cw)
                e = rib_error(r, "out of memory");
            for (size_t j = 0; e == 0 && j < points; j++) {
                for (int c = 0; c < 3; c++)
                    cw[4 * j + c] = (float)qc->v->d[3 * j + c] * Pw[4 * j + 3];
                cw[4 * j + 3] = Pw[4 * j + 3];
            }
        } else if (qc && rib_is_num(qc->v) && qc->v->n == 3 * corners && qc->d.cls != CLS_VERTEX) {
            cs_var = malloc(3 * corners * sizeof *cs_var);
            if (!cs_var)
                e = rib_error(r, "out of memory");
            for (size_t j = 0; e == 0 && j < 3 * corners; j++)
                cs_var[j] = (float)qc->v->d[j];
        } else if (qc && rib_is_num(qc->v) && qc->v->n == 3) {
            for (int c = 0; c < 3; c++)
                cs_const[c] = (float)qc->v->d[c];
            have_const = 1;
        } else if (qc) {
            rib_warn_once(r, "nupatch Cs",
                          "NuPatch: Cs needs one colour per control point (vertex), per span "
                          "corner (varying) or one (constant); not used");
        }
        for (size_t j = 0; j < n_p; j++) {
            const char *name = p[j].d.name;
            if (strcmp(name, "P") != 0 && strcmp(name, "Pw") != 0 && strcmp(name, "st") != 0 &&
                strcmp(name, "s") != 0 && strcmp(name, "t") != 0 && strcmp(name, "Cs") != 0) {
                char key[128];
                snprintf(key, sizeof key, "nupatch %.100s", name);
                rib_warn_once(r, key, "NuPatch: \"%s\" is not used (P, Pw, st and Cs are)", name);
            }
        }
    }
    s.knot[0] = knot[0];
    s.knot[1] = knot[1];
    s.Pw = Pw;
    s.work = &r->nurbs_work;
    Emit em = {.r = r,
               .s = &s,
               .exact = !rational && s.order[0] <= 4 && s.order[1] <= 4,
               .fixed = r->motion, /* transforms are consumed there: a deformation */
               .st = st,
               .st_w = (size_t)(s.n[0] - s.order[0] + 2),
               .trim = r->a.trim,
               .trim_outside = r->a.trim_outside};
    Nurbs colours = s;
    colours.Pw = cw;
    em.cs_vertex = cw ? &colours : NULL;
    em.cs_varying = cs_var;
    em.cs_constant = have_const ? cs_const : NULL;
    /* the first pass checks the file: patches are made in the second */
    for (int sv = 0; e == 0 && r->pass == 2 && sv < m[1]; sv++)
        for (int su = 0; e == 0 && su < m[0]; su++)
            e = emit_part(&em, k[0][su], k[1][sv], iv[0][su], iv[1][sv], 0, 0);
    if (e == 0 && em.unconverged)
        rib_warn_once(r, "nupatch fit",
                      "NuPatch: a span of high order or strong weights is approximated "
                      "coarser than 1e-4 of its size");
    free(st);
    free(cw);
    free(cs_var);
    free(p);
    free(Pw);
    for (int d = 0; d < 2; d++) {
        free(knot[d]);
        free(k[d]);
        free(iv[d]);
    }
    return e;
}

/* A TrimCurve that does not read (as PRMan, which says so and renders
 * on): one warning, and the NuPatches after it are not trimmed. */
static int trim_bad(Rib *r, const char *what)
{
    rib_warn_once(r, "trimcurve bad", "TrimCurve: %s; the trim is ignored", what);
    r->a.trim = NULL;
    return 0;
}

/* A numeric array argument of count values (count 0: any), or NULL. */
static const Arg *array_arg(const Args *a, size_t i, size_t count)
{
    if (i >= a->n || !rib_is_num(&a->v[i]) || (count && a->v[i].n != count))
        return NULL;
    return &a->v[i];
}

/* TrimCurve [ncurves] [order] [knot] [min] [max] [n] [u] [v] [w] (the
 * loops' count is ncurves'): the trim loops of the NuPatches after it,
 * an attribute; an empty one ends trimming. */
static int h_trim_curve(Rib *r, const Args *a)
{
    const Arg *nc = array_arg(a, 0, 0);
    if (!nc)
        return trim_bad(r, "expected the curves of each loop (numbers)");
    if (nc->n == 0) {
        r->a.trim = NULL;
        return 0;
    }
    size_t curves = 0;
    for (size_t k = 0; k < nc->n; k++) {
        if (!(nc->d[k] >= 1 && nc->d[k] <= 1e6 && nc->d[k] == floor(nc->d[k])))
            return trim_bad(r, "a loop needs a whole number of curves (1 or more)");
        curves += (size_t)nc->d[k];
    }
    const Arg *order = array_arg(a, 1, curves), *n = array_arg(a, 5, curves);
    if (!order || !n)
        return trim_bad(r, "expected an order and a point count per curve");
    size_t knots = 0, points = 0;
    for (size_t c = 0; c < curves; c++) {
        if (!(order->d[c] >= 2 && order->d[c] <= NURBS_MAX_ORDER &&
              order->d[c] == floor(order->d[c])) ||
            !(n->d[c] >= order->d[c] && n->d[c] <= TRIM_MAX_POINTS && n->d[c] == floor(n->d[c])))
            return trim_bad(r, "a curve needs an order from 2 to 32 and as many points or more");
        knots += (size_t)(order->d[c] + n->d[c]);
        points += (size_t)n->d[c];
    }
    if (points > TRIM_MAX_POINTS)
        return trim_bad(r, "more than 2^20 points");
    const Arg *knot = array_arg(a, 2, knots), *lo = array_arg(a, 3, curves);
    const Arg *hi = array_arg(a, 4, curves), *u = array_arg(a, 6, points);
    const Arg *v = array_arg(a, 7, points), *w = array_arg(a, 8, points);
    if (!knot)
        return trim_bad(r, "expected order + n knots per curve");
    if (!lo || !hi || !u || !v || !w)
        return trim_bad(r, "expected a min and a max per curve, and n u, v and w per curve");
    for (size_t q = 0; q < points; q++)
        if (!(w->d[q] > 0))
            return trim_bad(r, "a point's w is not positive");
    TrimSet *t = calloc(1, sizeof *t);
    size_t cap = points * TRIM_SEGMENTS + curves + 1;
    if (t) {
        t->first = calloc(nc->n + 1, sizeof *t->first);
        t->pt = malloc(cap * sizeof *t->pt);
    }
    if (!t || !t->first || !t->pt) {
        if (t)
            free(t->first), free(t->pt);
        free(t);
        return rib_error(r, "out of memory");
    }
    t->next = r->trims;
    r->trims = t;
    t->n_loops = nc->n;
    size_t np = 0, c = 0, ko = 0, po = 0;
    float cp[NURBS_MAX_ORDER][4];
    for (size_t l = 0; l < nc->n; l++) {
        t->first[l] = np;
        for (size_t j = 0; j < (size_t)nc->d[l]; j++, c++) {
            int ord = (int)order->d[c], cn = (int)n->d[c], p = ord - 1;
            const double *kn = knot->d + ko;
            float kf[2 * NURBS_MAX_ORDER];
            for (int sp = p; sp < cn; sp++) { /* each knot span within [min, max] */
                float a0 = fmaxf((float)kn[sp], (float)lo->d[c]);
                float a1 = fminf((float)kn[sp + 1], (float)hi->d[c]);
                if (!(kn[sp] < kn[sp + 1]) || !(a0 < a1))
                    continue;
                for (int q = 0; q < 2 * ord; q++) /* the knots de Boor reads, as floats */
                    kf[q] = (float)kn[sp - p + q];
                int segs = ord == 2 ? 1 : TRIM_SEGMENTS; /* a line is one segment */
                for (int seg = 0; seg < segs && np < cap; seg++) {
                    float x = a0 + (a1 - a0) * (float)seg / (float)segs;
                    for (int q = 0; q <= p; q++) { /* homogeneous (u, v, w), as Pw */
                        size_t pi = po + (size_t)(sp - p + q);
                        cp[q][0] = (float)u->d[pi], cp[q][1] = (float)v->d[pi];
                        cp[q][2] = (float)w->d[pi], cp[q][3] = 0;
                    }
                    de_boor(cp, kf, p, p, x); /* kf holds knots sp - p .. sp + p + 1 */
                    t->pt[np][0] = cp[p][0] / cp[p][2];
                    t->pt[np][1] = cp[p][1] / cp[p][2];
                    if (!isfinite(t->pt[np][0]) || !isfinite(t->pt[np][1]))
                        t->pt[np][0] = t->pt[np][1] = 0; /* w underflowed: a point at 0 */
                    np++;
                }
            }
            ko += (size_t)(ord + cn);
            po += (size_t)cn;
        }
        if (np - t->first[l] < 3) /* a loop of less than a triangle cuts nothing */
            np = t->first[l];
    }
    t->first[nc->n] = np;
    t->lo[0] = t->lo[1] = INFINITY;
    t->hi[0] = t->hi[1] = -INFINITY;
    for (size_t q = 0; q < np; q++)
        for (int k = 0; k < 2; k++)
            t->lo[k] = fminf(t->lo[k], t->pt[q][k]), t->hi[k] = fmaxf(t->hi[k], t->pt[q][k]);
    r->a.trim = np ? t : NULL;
    return 0;
}

void rib_trims_free(Rib *r)
{
    while (r->trims) {
        TrimSet *t = r->trims;
        r->trims = t->next;
        free(t->first);
        free(t->pt);
        free(t);
    }
}

const RibRequest rib_nurbs_requests[] = {
    {"NuPatch", h_nupatch},
    {"TrimCurve", h_trim_curve},
    {NULL, NULL},
};
