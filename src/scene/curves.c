/*
 * scene/curves.c — rayes_scene_curves and rayes_scene_points (rayes.h):
 * RenderMan's Curves and Points as primitives of the scene.
 *
 * A curve becomes one PRIM_CURVE per run of up to GEOM_CURVE_RUN
 * segments: each segment's four control points turned into Bezier ones
 * (B^-1 basis G, B the Bezier basis), its width and primitive variables
 * at the segments' ends (geom interpolates them linearly along each, as
 * RenderMan does varying ones; vertex ones are evaluated with the curve's
 * basis at the ends). Ribbons are one segment per primitive (their
 * normals take the room). A point becomes one PRIM_POINT. Widths are object-space diameters, scaled to world space by
 * the cube root of the transform's determinant.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rayes/rayes.h"
#include "scene/scene.h"

const float rayes_basis_bezier[16] = {-1, 3, -3, 1, 3, -6, 3, 0, -3, 3, 0, 0, 1, 0, 0, 0};
const float rayes_basis_bspline[16] = {-1.0f / 6, 3.0f / 6,  -3.0f / 6, 1.0f / 6,
                                       3.0f / 6,  -6.0f / 6, 3.0f / 6,  0,
                                       -3.0f / 6, 0,         3.0f / 6,  0,
                                       1.0f / 6,  4.0f / 6,  1.0f / 6,  0};
const float rayes_basis_catmull_rom[16] = {-0.5f, 1.5f, -1.5f, 0.5f, 1.0f, -2.5f, 2.0f, -0.5f,
                                           -0.5f, 0,    0.5f,  0,    0,    1.0f,  0,    0};

/* The inverse of the Bezier basis: Bezier control points = this * basis * G. */
static const float bezier_inverse[16] = {0, 0, 0, 1, 0, 0, 1.0f / 3, 1, 0, 1.0f / 3, 2.0f / 3, 1,
                                         1, 1, 1, 1};

/* The primitive variables curves and points read. */
enum { VAR_WIDTH, VAR_N, VAR_CS, VAR_ST, VAR_OS, N_VARS };
static const char *const var_names[N_VARS] = {"width", "N", "Cs", "st", "Os"};
static const int var_sizes[N_VARS] = {1, 3, 3, 2, 3};

/* Value counts of each class, and the variables found. */
typedef struct Vars {
    const RayesPrimvar *by[N_VARS];
    size_t count[5]; /* per RayesPrimvarClass */
} Vars;

static RayesError read_vars(RayesScene *s, const char *what, const RayesPrimvar *pv, size_t n_pv,
                            Vars *vars)
{
    if (n_pv && !pv)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "%s: primitive variables are NULL",
                          what);
    for (size_t i = 0; i < n_pv; i++) {
        int b = 0;
        while (b < N_VARS && !(pv[i].name && strcmp(pv[i].name, var_names[b]) == 0))
            b++;
        if (b == N_VARS)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: unknown primitive variable \"%.64s\"; expected width, N, Cs, "
                              "st or Os",
                              what, pv[i].name ? pv[i].name : "(null)");
        if (vars->by[b])
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s given twice", what, var_names[b]);
        if ((unsigned)pv[i].cls > RAYES_PRIMVAR_FACEVARYING)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s has class %d", what, var_names[b],
                              (int)pv[i].cls);
        size_t want = vars->count[pv[i].cls];
        if (pv[i].count != want)
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: %s has %zu values; expected %zu for its class", what,
                              var_names[b], pv[i].count, want);
        if (!pv[i].data || !scene_finite(pv[i].data, want * (size_t)var_sizes[b]))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "%s: primitive variable %s has no data or a non-finite value", what,
                              var_names[b]);
        if (b == VAR_WIDTH)
            for (size_t k = 0; k < want; k++)
                if (pv[i].data[k] < 0.0f)
                    return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                                      "%s: width %g is negative", what, (double)pv[i].data[k]);
        vars->by[b] = &pv[i];
    }
    const RayesPrimvar *Os = vars->by[VAR_OS];
    scene_note_Os(s, Os ? Os->data : NULL, Os ? Os->count : 0);
    return RAYES_OK;
}

/* How long the transform makes a unit of object space, for widths. */
static float width_scale(const Mat4 *m)
{
    float det = m->m[0][0] * (m->m[1][1] * m->m[2][2] - m->m[1][2] * m->m[2][1]) -
                m->m[0][1] * (m->m[1][0] * m->m[2][2] - m->m[1][2] * m->m[2][0]) +
                m->m[0][2] * (m->m[1][0] * m->m[2][1] - m->m[1][1] * m->m[2][0]);
    return cbrtf(fabsf(det));
}

/* ----------------------------------------------------------------- curves */

/* Where one segment's values come from: per class, the index of the value
 * at each end (constant, uniform, varying), or the 4 control points with
 * the weights of each end (vertex). */
typedef struct SegSource {
    size_t uniform;
    size_t varying[2];
    size_t vertex[4];
    float end_weight[2][4]; /* vertex: the basis at t = 0 and 1 */
} SegSource;

/* Variable b's value (var_sizes[b] floats) at end e of a segment. */
static void seg_value(const RayesPrimvar *v, int b, const SegSource *src, int e, float *out)
{
    int size = var_sizes[b];
    memset(out, 0, (size_t)size * sizeof *out);
    switch (v->cls) {
    case RAYES_PRIMVAR_CONSTANT: memcpy(out, v->data, (size_t)size * sizeof *out); break;
    case RAYES_PRIMVAR_UNIFORM:
        memcpy(out, v->data + src->uniform * (size_t)size, (size_t)size * sizeof *out);
        break;
    case RAYES_PRIMVAR_VERTEX:
        for (int k = 0; k < 4; k++)
            for (int c = 0; c < size; c++)
                out[c] += src->end_weight[e][k] * v->data[src->vertex[k] * (size_t)size + c];
        break;
    default: /* varying, facevarying */
        memcpy(out, v->data + src->varying[e] * (size_t)size, (size_t)size * sizeof *out);
        break;
    }
}

/* Segments of a curve of n control points, or 0 if n does not fit. */
static size_t curve_segments(const RayesCurves *c, int n)
{
    if (c->degree == 1)
        return n < 2 ? 0 : c->periodic ? (size_t)n : (size_t)n - 1;
    if (c->periodic)
        return n >= 4 && n % c->step == 0 ? (size_t)(n / c->step) : 0;
    return n >= 4 && (n - 4) % c->step == 0 ? (size_t)((n - 4) / c->step + 1) : 0;
}

long rayes_curves_counts(const RayesCurves *c, size_t *n_points, size_t *n_varying)
{
    *n_points = *n_varying = 0;
    if (!c || (c->degree != 1 && c->degree != 3) ||
        (c->degree == 3 && (c->step < 1 || c->step > 4)) ||
        (c->n_curves && (!c->n_verts || !c->P)))
        return LONG_MIN;
    for (size_t k = 0; k < c->n_curves; k++) {
        size_t segs = curve_segments(c, c->n_verts[k]);
        if (segs == 0 || c->n_verts[k] > (1 << 24))
            return -1 - (long)k;
        *n_points += (size_t)c->n_verts[k];
        *n_varying += c->periodic ? segs : segs + 1;
    }
    return 0;
}

static RayesError check_curves(RayesScene *s, const RayesCurves *c, size_t *n_points,
                               size_t *n_varying)
{
    if (c->degree != 1 && c->degree != 3)
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "curves: degree %d; expected 1 or 3",
                          c->degree);
    if (c->degree == 3 && (c->step < 1 || c->step > 4 || !scene_finite(c->basis, 16)))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                          "curves: basis step %d; expected 1 to 4 and a finite basis", c->step);
    if (c->n_curves && (!c->n_verts || !c->P))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "curves: no vertex counts or points");
    *n_points = *n_varying = 0;
    for (size_t k = 0; k < c->n_curves; k++) {
        size_t segs = curve_segments(c, c->n_verts[k]);
        if (segs == 0 || c->n_verts[k] > (1 << 24))
            return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT,
                              "curves: curve %zu has %d control points, which make no whole "
                              "segments (%s, step %d)",
                              k, c->n_verts[k], c->degree == 1 ? "linear" : "cubic",
                              c->degree == 1 ? 1 : c->step);
        *n_points += (size_t)c->n_verts[k];
        *n_varying += c->periodic ? segs : segs + 1;
    }
    if (!scene_finite(c->P, 3 * *n_points))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "curves: non-finite point");
    return RAYES_OK;
}

/* The control points (indices) and end weights of segment k of a curve
 * of n points starting at point `first`. */
static void segment_source(const RayesCurves *c, size_t first, int n, size_t k, SegSource *src)
{
    memset(src, 0, sizeof *src);
    if (c->degree == 1) {
        src->vertex[0] = first + k;
        src->vertex[1] = first + (k + 1) % (size_t)n;
        src->end_weight[0][0] = 1.0f;
        src->end_weight[1][1] = 1.0f;
        return;
    }
    for (int j = 0; j < 4; j++) {
        src->vertex[j] = first + (k * (size_t)c->step + (size_t)j) % (size_t)n;
        /* [t^3 t^2 t 1] basis at t = 0 (the last row) and t = 1 (the rows' sum). */
        src->end_weight[0][j] = c->basis[12 + j];
        for (int r = 0; r < 4; r++)
            src->end_weight[1][j] += c->basis[4 * r + j];
    }
}

/* Segment's Bezier control points, world space. The basis works on the
 * object-space points (a Hermite or power basis has tangents and
 * coefficients among them, which a translation must not move); the
 * Bezier points it gives are points, and are then transformed. */
static void segment_bezier(const RayesScene *s, const RayesCurves *c, const SegSource *src,
                           Vec3 cp[4])
{
    Vec3 g[4];
    int n = c->degree == 1 ? 2 : 4;
    for (int j = 0; j < n; j++)
        g[j] = v3_load(c->P + 3 * src->vertex[j]);
    if (c->degree == 1) {
        cp[0] = g[0], cp[3] = g[1];
        cp[1] = v3_lerp(g[0], g[1], 1.0f / 3.0f);
        cp[2] = v3_lerp(g[0], g[1], 2.0f / 3.0f);
        for (int r = 0; r < 4; r++)
            cp[r] = mat4_point(&s->world_from_object, cp[r]);
        return;
    }
    float m[16]; /* bezier_inverse * basis */
    for (int r = 0; r < 4; r++)
        for (int j = 0; j < 4; j++) {
            m[4 * r + j] = 0.0f;
            for (int k = 0; k < 4; k++)
                m[4 * r + j] += bezier_inverse[4 * r + k] * c->basis[4 * k + j];
        }
    for (int r = 0; r < 4; r++) {
        cp[r] = v3(0, 0, 0);
        for (int j = 0; j < 4; j++)
            cp[r] = v3_madd(cp[r], g[j], m[4 * r + j]);
        cp[r] = mat4_point(&s->world_from_object, cp[r]);
    }
}

/* Appends st, Cs and Os (when given) of a prim with n ends whose values
 * are end[e][var] (pool order: GEOM_PV_* bits, st before Cs before Os; per
 * end). */
static RayesError push_ends(RayesScene *s, Prim *p, const Vars *vars, float (*end)[N_VARS][3],
                            int n)
{
    static const unsigned bits[N_VARS] = {0, 0, GEOM_PV_CS, GEOM_PV_ST, GEOM_PV_OS};
    const int order[3] = {VAR_ST, VAR_CS, VAR_OS};
    float values[(GEOM_CURVE_RUN + 4) * 8];
    size_t k = 0;
    unsigned mask = 0;
    for (int o = 0; o < 3; o++) {
        int b = order[o];
        if (!vars->by[b])
            continue;
        mask |= bits[b];
        for (int e = 0; e < n; e++)
            for (int c = 0; c < var_sizes[b]; c++)
                values[k++] = end[e][b][c];
    }
    if (!mask) {
        p->pv = 0;
        return RAYES_OK;
    }
    return scene_push_values(s, p, mask, values, k);
}

/* The values of every variable at end e (0 or 1) of a segment. */
static void seg_ends(const Vars *vars, const SegSource *src, int e, float out[N_VARS][3])
{
    memset(out, 0, N_VARS * sizeof out[0]);
    out[VAR_WIDTH][0] = 1.0f; /* RenderMan's default width */
    for (int b = 0; b < N_VARS; b++)
        if (vars->by[b])
            seg_value(vars->by[b], b, src, e, out[b]);
}

RayesError rayes_scene_curves(RayesScene *s, const RayesCurves *c, const RayesPrimvar *pv,
                              size_t n_pv)
{
    if (!s || !c)
        return RAYES_ERROR_INVALID_ARGUMENT;
    size_t n_points = 0, n_varying = 0;
    RayesError e = check_curves(s, c, &n_points, &n_varying);
    if (e != RAYES_OK)
        return e;
    Vars vars = {.count = {1, c->n_curves, n_varying, n_points, n_varying}};
    if ((e = read_vars(s, "curves", pv, n_pv, &vars)) != RAYES_OK)
        return e;
    Mat4 inv;
    mat4_invert(s->world_from_object, &inv);
    Mat4 normal_from_object = mat4_transpose(inv);
    float scale = width_scale(&s->world_from_object);
    uint8_t shape = vars.by[VAR_N]                   ? GEOM_SHAPE_SURFACE
                    : c->shape == RAYES_CURVE_FLAT ? GEOM_SHAPE_FLAT_CURVE
                                                   : GEOM_SHAPE_ROUND_CURVE;
    int run = shape == GEOM_SHAPE_SURFACE ? 1 : GEOM_CURVE_RUN;
    size_t first = 0, vary = 0;
    for (size_t k = 0; k < c->n_curves; k++) {
        int n = c->n_verts[k];
        size_t segs = curve_segments(c, n), n_vary = c->periodic ? segs : segs + 1;
        /* Runs of up to `run` segments, each one primitive; a run ends
         * early where the curve is not continuous (a basis and step that
         * leave gaps). */
        for (size_t seg = 0; seg < segs;) {
            PrimBig big = {0};
            Prim p = {.type = PRIM_CURVE, .big = &big};
            p.curve.shape = shape;
            float end[GEOM_CURVE_RUN + 1][N_VARS][3] = {{{0}}};
            int m = 0;
            while (m < run && seg < segs) {
                SegSource src;
                segment_source(c, first, n, seg, &src);
                src.uniform = k;
                src.varying[0] = vary + seg;
                src.varying[1] = vary + (seg + 1) % n_vary;
                Vec3 cp[4];
                segment_bezier(s, c, &src, cp);
                if (m > 0 && v3_length(v3_sub(cp[0], p.big->curve.cp[3 * m])) >
                                 1e-5f * (1.0f + v3_length(cp[0])))
                    break;
                memcpy(&p.big->curve.cp[3 * m], cp, sizeof cp);
                if (m == 0)
                    seg_ends(&vars, &src, 0, end[0]);
                seg_ends(&vars, &src, 1, end[m + 1]);
                m++, seg++;
            }
            p.curve.n_seg = (uint8_t)m;
            for (int j = 0; j <= m; j++)
                p.big->curve.width[j] = fmaxf(end[j][VAR_WIDTH][0], 0.0f) * scale;
            for (int side = 0; side < 2 && vars.by[VAR_N]; side++)
                p.big->curve.n[side] = v3_normalize(
                    mat4_vector(&normal_from_object, v3_load(end[side ? m : 0][VAR_N])));
            if ((e = push_ends(s, &p, &vars, end, m + 1)) != RAYES_OK ||
                (e = scene_add_prim(s, &p)) != RAYES_OK)
                return e;
        }
        first += (size_t)n;
        vary += n_vary;
    }
    return RAYES_OK;
}

/* ----------------------------------------------------------------- points */

RayesError rayes_scene_points(RayesScene *s, RayesPointShape shape, size_t n_points,
                              const float *P, const RayesPrimvar *pv, size_t n_pv)
{
    if (!s || (n_points && !P) || (shape != RAYES_POINT_SPHERE && shape != RAYES_POINT_DISK))
        return RAYES_ERROR_INVALID_ARGUMENT;
    if (!scene_finite(P, 3 * n_points))
        return scene_fail(s, RAYES_ERROR_INVALID_ARGUMENT, "points: non-finite point");
    Vars vars = {.count = {1, 1, n_points, n_points, n_points}};
    RayesError e = read_vars(s, "points", pv, n_pv, &vars);
    if (e != RAYES_OK)
        return e;
    Mat4 inv;
    mat4_invert(s->world_from_object, &inv);
    Mat4 normal_from_object = mat4_transpose(inv);
    float scale = width_scale(&s->world_from_object);
    for (size_t i = 0; i < n_points; i++) {
        /* A point's values: a segment's first end, at all 4 corners. */
        SegSource src = {.uniform = 0, .varying = {i, i}, .vertex = {i, i, i, i},
                         .end_weight = {{1, 0, 0, 0}, {1, 0, 0, 0}}};
        float end[4][N_VARS][3];
        seg_ends(&vars, &src, 0, end[0]);
        for (int k = 1; k < 4; k++)
            memcpy(end[k], end[0], sizeof end[0]);
        Prim p = {.type = PRIM_POINT};
        p.point.centre = mat4_point(&s->world_from_object, v3_load(P + 3 * i));
        p.point.radius = 0.5f * fmaxf(end[0][VAR_WIDTH][0], 0.0f) * scale;
        if (vars.by[VAR_N])
            p.point.n = v3_normalize(mat4_vector(&normal_from_object, v3_load(end[0][VAR_N])));
        p.point.shape = vars.by[VAR_N]                ? GEOM_SHAPE_ORIENTED_DISK
                        : shape == RAYES_POINT_DISK ? GEOM_SHAPE_DISK
                                                    : GEOM_SHAPE_SPHERE;
        if (!(p.point.radius > 0.0f))
            continue; /* nothing to see */
        if ((e = push_ends(s, &p, &vars, end, 4)) != RAYES_OK ||
            (e = scene_add_prim(s, &p)) != RAYES_OK)
            return e;
    }
    return RAYES_OK;
}
