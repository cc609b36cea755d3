/*
 * io/rib_curves.c — RenderMan's Curves, Points and Blobby (docs/rib.md).
 *
 * Curves take the current v basis and step (RenderMan's rule for curves),
 * "width" (any class) or "constantwidth", "N" (ribbons), "Cs", "Os" and "st";
 * without N they are flat ribbons facing each ray, or tubes under
 * Attribute "dice" "roundcurve" 1. Points take "width" or
 * "constantwidth", "N" (oriented disks), "Cs", "st", and 3Delight's
 * "uniform string type" "sphere" (the default) or "disk". Blobby passes
 * its program's arrays as read, with "Cs", "Os" and "st" (one value, or
 * one per primitive field).
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_internal.h"
#include "io/rib_reader.h"

/* The primitive variables of a curves or points call, converted for the
 * sink: width, N, Cs, st in that order (those given). */
typedef PvOut Vars;

static const RayesPrimvarClass class_of[] = {
    [CLS_CONSTANT] = RAYES_PRIMVAR_CONSTANT, [CLS_UNIFORM] = RAYES_PRIMVAR_UNIFORM,
    [CLS_VARYING] = RAYES_PRIMVAR_VARYING,   [CLS_VERTEX] = RAYES_PRIMVAR_VERTEX,
    [CLS_FACEVARYING] = RAYES_PRIMVAR_FACEVARYING};

/* Adds parameter q (of size floats per value) as the sink's variable name. */
static int add_var(Rib *r, Vars *v, const Param *q, const char *name, int size)
{
    size_t n = q->v->n;
    float *d = malloc((n ? n : 1) * sizeof *d);
    if (!d)
        return rib_error(r, "out of memory");
    for (size_t k = 0; k < n; k++)
        d[k] = fabs(q->v->d[k]) < FLT_MAX ? (float)q->v->d[k] : 0.0f;
    v->data[v->n] = d;
    v->pv[v->n++] = (RayesPrimvar){name, class_of[q->d.cls], d, n / (size_t)size};
    return 0;
}

/* Reads the variables; warns once about parameters nothing reads. */
static int read_vars(Rib *r, const Param *p, size_t n, Vars *v)
{
    memset(v, 0, sizeof *v);
    const Param *w = rib_var_param(r, p, n, "width", 1);
    if (!w)
        w = rib_var_param(r, p, n, "constantwidth", 1);
    static const struct {
        const char *name;
        int size;
    } names[4] = {{"N", 3}, {"Cs", 3}, {"st", 2}, {"Os", 3}};
    int e = w ? add_var(r, v, w, "width", 1) : 0;
    for (int k = 0; k < 4 && e == 0; k++) {
        const Param *q = rib_var_param(r, p, n, names[k].name, names[k].size);
        if (q)
            e = add_var(r, v, q, names[k].name, names[k].size);
        else if ((k == 1 || k == 3) && rib_block_color_only(r) &&
                 (k == 1 ? r->a.cs_gen != r->object_cs_gen : r->a.os_gen != r->object_os_gen)) {
            /* the block's Color or Opacity as a constant Cs or Os */
            float *d = malloc(3 * sizeof *d);
            if (!d) {
                e = rib_error(r, "out of memory");
                break;
            }
            for (int c = 0; c < 3; c++)
                d[c] = k == 1 ? r->a.Cs[c] : r->a.Os[c];
            v->data[v->n] = d;
            v->pv[v->n++] = (RayesPrimvar){names[k].name, RAYES_PRIMVAR_CONSTANT, d, 1};
            r->pv_block_color = 1;
        }
    }
    static const char *const used[] = {"P",    "Pw", "N", "Cs", "st", "width", "constantwidth",
                                       "type", "Os", NULL};
    for (size_t i = 0; i < n; i++) {
        int u = !p[i].declared;
        for (int k = 0; used[k]; k++)
            u |= strcmp(p[i].d.name, used[k]) == 0;
        if (!u) {
            char key[128];
            snprintf(key, sizeof key, "unused %s", p[i].d.name);
            rib_warn_once(r, key,
                          "parameter \"%s\" is not used (rayes's curves and points take P, "
                          "width, N, st, Cs and Os)",
                          p[i].d.name);
        }
    }
    if (e != 0)
        rib_pv_out_free(v);
    return e;
}

/* Sends the primitive to the sink (after the state it needs). */
static int emit(Rib *r, const RayesCurves *c, RayesPointShape shape, size_t n_points,
                const float *P, const Vars *v)
{
    int e = rib_emit_begin(r, NULL);
    if (e == 1) /* outside the world: nothing to draw */
        return 0;
    if (e != 0)
        return e;
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (c ? !s->curves : !s->points)
        return rib_error(r, "this sink takes no %s", c ? "curves" : "points");
    RayesError err = c ? s->curves(s->target, c, v->pv, v->n)
                       : s->points(s->target, shape, n_points, P, v->pv, v->n);
    return err == RAYES_OK ? 0 : rib_sink_failed(r, s);
}

static int h_curves(Rib *r, const Args *a)
{
    size_t i = 0, n_curves = 0, n = 0, np = 0;
    const char *type = rib_get_string(r, a, &i, "\"linear\" or \"cubic\"");
    if (!type)
        return -1;
    int cubic = strcmp(type, "cubic") == 0;
    if (!cubic && strcmp(type, "linear") != 0)
        return rib_error(r, "expected \"linear\" or \"cubic\", found \"%s\"", type);
    int *nverts = NULL;
    Param *p = NULL;
    float *P = NULL;
    Vars vars = {0};
    int e = rib_get_ints(r, a, &i, &nverts, &n_curves, 1, 1 << 24, "vertices per curve");
    const char *wrap = e == 0 ? rib_get_string(r, a, &i, "\"periodic\" or \"nonperiodic\"") : NULL;
    if (e == 0 && !wrap)
        e = -1;
    int periodic = wrap && (strcmp(wrap, "periodic") == 0 || strcmp(wrap, "wrap") == 0);
    if (e == 0 && !periodic && strcmp(wrap, "nonperiodic") != 0 && strcmp(wrap, "nowrap") != 0)
        e = rib_error(r, "expected \"periodic\" or \"nonperiodic\", found \"%s\"", wrap);
    if (e == 0)
        e = rib_get_params(r, a, i, &p, &n);
    if (e == 0 && !(P = rib_get_points(r, p, n, &np)))
        e = -1;
    RayesCurves c = {.degree = cubic ? 3 : 1,
                     .step = r->a.vstep,
                     .periodic = periodic,
                     .shape = r->a.roundcurve ? RAYES_CURVE_ROUND : RAYES_CURVE_FLAT,
                     .n_curves = n_curves,
                     .n_verts = nverts,
                     .P = P};
    memcpy(c.basis, r->a.vbasis, sizeof c.basis);
    size_t n_points = 0, n_varying = 0;
    long bad = e == 0 ? rayes_curves_counts(&c, &n_points, &n_varying) : 0;
    if (e == 0 && bad == LONG_MIN)
        e = rib_error(r, "the basis step %d is out of range (1 to 4)", c.step);
    if (e == 0 && bad != 0)
        e = rib_error(r, "curve %ld has %d vertices, which make no whole %s segments (step %d)",
                      -1 - bad, nverts[-1 - bad], type, cubic ? c.step : 1);
    if (e == 0 && n_points != np)
        e = rib_error(r, "the curves have %zu vertices but \"P\" has %zu points", n_points, np);
    Counts counts = {n_curves, n_varying, n_points, n_varying};
    if (e == 0)
        e = rib_check_counts(r, p, n, &counts);
    if (e == 0)
        e = read_vars(r, p, n, &vars);
    if (e == 0)
        e = emit(r, &c, RAYES_POINT_SPHERE, 0, NULL, &vars);
    rib_pv_out_free(&vars);
    free(P);
    free(p);
    free(nverts);
    return e;
}

static int h_points(Rib *r, const Args *a)
{
    size_t n = 0, np = 0;
    Param *p = NULL;
    float *P = NULL;
    Vars vars = {0};
    int e = rib_get_params(r, a, 0, &p, &n);
    if (e == 0 && !(P = rib_get_points(r, p, n, &np)))
        e = -1;
    Counts counts = {1, np, np, np};
    if (e == 0)
        e = rib_check_counts(r, p, n, &counts);
    RayesPointShape shape = RAYES_POINT_SPHERE;
    const Param *type = e == 0 ? rib_find_param(p, n, "type") : NULL;
    if (type && (type->v->kind == ARG_STR || type->v->kind == ARG_STRS) && type->v->n == 1) {
        if (strcmp(type->v->s[0], "disk") == 0)
            shape = RAYES_POINT_DISK;
        else if (strcmp(type->v->s[0], "sphere") != 0)
            rib_warn_once(r, "points type",
                          "Points type \"%s\" is not supported; drawn as spheres (rayes draws "
                          "\"sphere\" and \"disk\")",
                          type->v->s[0]);
    }
    if (e == 0)
        e = read_vars(r, p, n, &vars);
    if (e == 0)
        e = emit(r, NULL, shape, np, P, &vars);
    rib_pv_out_free(&vars);
    free(P);
    free(p);
    return e;
}

/* Blobby nleaf [code] [floats] [strings] parameters. */
static int h_blobby(Rib *r, const Args *a)
{
    size_t i = 0, n_nleaf = 0, n_code = 0, n = 0;
    int *nleaf = NULL, *code = NULL;
    float *floats = NULL;
    Param *p = NULL;
    Vars vars = {0};
    int e = rib_get_ints(r, a, &i, &nleaf, &n_nleaf, 0, 1 << 24, "the number of blobs");
    if (e == 0 && n_nleaf != 1)
        e = rib_error(r, "expected one number of blobs, found %zu numbers", n_nleaf);
    if (e == 0)
        e = rib_get_ints(r, a, &i, &code, &n_code, INT32_MIN, INT32_MAX, "the code array");
    const Arg *fa = e == 0 && i < a->n ? &a->v[i] : NULL;
    if (e == 0 && (!fa || !rib_is_num(fa)))
        e = rib_error(r, "expected the float array");
    size_t n_floats = fa && e == 0 ? fa->n : 0;
    if (e == 0 && !(floats = malloc((n_floats ? n_floats : 1) * sizeof *floats)))
        e = rib_error(r, "out of memory");
    for (size_t k = 0; e == 0 && k < n_floats; k++) {
        if (!(fabs(fa->d[k]) <= FLT_MAX))
            e = rib_arg_error(r, fa, "float %zu (%g) is not a finite float", k + 1, fa->d[k]);
        floats[k] = (float)fa->d[k];
    }
    i += e == 0;
    const Arg *sa = e == 0 && i < a->n ? &a->v[i] : NULL;
    size_t n_strings = 0;
    if (e == 0 && sa && (sa->kind == ARG_STR || sa->kind == ARG_STRS))
        n_strings = sa->n;
    else if (e == 0 && !(sa && sa->kind == ARG_NUMS && sa->n == 0)) /* [] */
        e = rib_error(r, "expected the string array");
    i += e == 0;
    if (e == 0)
        e = rib_get_params(r, a, i, &p, &n);
    size_t leaves = nleaf ? (size_t)nleaf[0] : 0;
    Counts counts = {1, leaves, leaves, leaves};
    if (e == 0)
        e = rib_check_counts(r, p, n, &counts);
    static const struct {
        const char *name;
        int size;
    } names[3] = {{"Cs", 3}, {"Os", 3}, {"st", 2}};
    for (int k = 0; k < 3 && e == 0; k++) {
        const Param *q = rib_var_param(r, p, n, names[k].name, names[k].size);
        if (q && q->d.cls == CLS_FACEVARYING)
            e = rib_error(r, "\"%s\" cannot be facevarying on a blobby", names[k].name);
        else if (q)
            e = add_var(r, &vars, q, names[k].name, names[k].size);
    }
    for (size_t k = 0; e == 0 && k < n; k++)
        if (p[k].declared && strcmp(p[k].d.name, "Cs") != 0 && strcmp(p[k].d.name, "Os") != 0 &&
            strcmp(p[k].d.name, "st") != 0) {
            char key[128];
            snprintf(key, sizeof key, "unused %s", p[k].d.name);
            rib_warn_once(r, key, "parameter \"%s\" is not used (a blobby takes Cs, Os and st)",
                          p[k].d.name);
        }
    if (e == 0 && r->a.area)
        rib_warn_once(r, "area shape",
                      "only quads become area lights; other shapes under "
                      "AreaLightSource are ordinary surfaces");
    int begun = e == 0 ? rib_emit_begin(r, NULL) : e;
    if (begun == 0) {
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        RayesBlobby b = {leaves,   code,     n_code,
                         floats,   n_floats, (const char *const *)(n_strings ? sa->s : NULL),
                         n_strings};
        if (!s->blobby)
            rib_warn_once(r, "blobby sink", "this sink takes no blobbies; skipped");
        else if (s->blobby(s->target, &b, vars.pv, vars.n) != RAYES_OK)
            e = rib_sink_failed(r, s);
    } else if (begun != 1) /* 1: outside the world, nothing to draw */
        e = begun;
    rib_pv_out_free(&vars);
    free(p);
    free(floats);
    free(code);
    free(nleaf);
    return e;
}

const RibRequest rib_curves_requests[] = {
    {"Curves", h_curves},
    {"Points", h_points},
    {"Blobby", h_blobby},
    {NULL, NULL},
};
