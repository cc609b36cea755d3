/*
 * io/rib_prim.c — the geometric primitives of the RIB reader: Polygon,
 * GeneralPolygon, PointsPolygons, PointsGeneralPolygons (tessellated into
 * triangles and convex planar quads by rib_geom.c), SubdivisionMesh and
 * HierarchicalSubdivisionMesh (schemes and tags to rayes.h's subdivision
 * meshes), Patch and PatchMesh in the current basis (made
 * Bezier), the quadrics and Geometry "teapot"; and their primitive
 * variables (N, st or s and t, Cs, Os) in the API's classes. Each primitive
 * checks its parameters' counts, then brings the sink up to date
 * (rib_emit_begin) and sends itself, wound as RenderMan's orientation and
 * the transform's handedness say (flip_of).
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/bpt.h"
#include "io/rib_reader.h"

/* Whether the front of a surface is opposite to the right-hand rule in
 * world space: RenderMan's orientation against the handedness of object
 * space (camera space is left-handed), and a mirror in world_from_object. */
int rib_flip(Rib *r)
{
    double det_wo = rib_mat_det3(r->a.M);
    double det_co = rib_mat_det3(r->camera_from_world) * det_wo;
    int cur_lh = det_co > 0;
    int orient_lh = r->a.orient == ORIENT_LH      ? 1
                    : r->a.orient == ORIENT_RH    ? 0
                    : r->a.orient == ORIENT_INSIDE ? !cur_lh
                                                   : cur_lh;
    return (orient_lh != cur_lh) ^ (det_wo < 0);
}

/* ------------------------------------------------ primitive variables */

/* One of the primitive variables rayes.h takes (N, st, Cs, Os), as a
 * primitive gives it: values of size floats, or separate s and t. */
typedef struct RibVar {
    const double *d;  /* the values; s when d2 is set; NULL: not given */
    const double *d2; /* t, when s and t are separate */
    Cls cls;
    int size; /* floats per value: 3 (N, Cs, Os), 2 (st) */
} RibVar;

#define RIB_N_VARS 4
static const char *const rib_var_names[RIB_N_VARS] = {"N", "st", "Cs", "Os"};

/* A parameter that is a numeric declared value of size floats, or NULL
 * (with one warning when it has the name but another type). */
const Param *rib_var_param(Rib *r, const Param *p, size_t n, const char *name, int size)
{
    const Param *q = rib_find_param(p, n, name);
    if (!q || !q->declared)
        return NULL;
    if (q->d.ty == TY_STRING || rib_type_size(q->d.ty) * q->d.array != size) {
        char key[96];
        snprintf(key, sizeof key, "type %s", name);
        rib_warn_once(r, key, "\"%s\" of %d numbers per value is ignored (expected %d)", name,
                  rib_type_size(q->d.ty) * q->d.array, size);
        return NULL;
    }
    return q;
}

/* The primitive's N (or Np), st (or s and t), Cs and Os, in that order. */
static void rib_vars(Rib *r, const Param *p, size_t n, RibVar vars[RIB_N_VARS])
{
    memset(vars, 0, RIB_N_VARS * sizeof *vars);
    const Param *N = rib_var_param(r, p, n, "N", 3);
    if (!N)
        N = rib_var_param(r, p, n, "Np", 3);
    if (N)
        vars[0] = (RibVar){N->v->d, NULL, N->d.cls, 3};
    const Param *st = rib_var_param(r, p, n, "st", 2);
    if (st)
        vars[1] = (RibVar){st->v->d, NULL, st->d.cls, 2};
    else {
        const Param *ps = rib_var_param(r, p, n, "s", 1), *pt = rib_var_param(r, p, n, "t", 1);
        if (ps && pt && ps->d.cls == pt->d.cls)
            vars[1] = (RibVar){ps->v->d, pt->v->d, ps->d.cls, 2};
        else if (ps || pt)
            rib_warn_once(r, "s t", "\"s\" and \"t\" are used only together and of one class");
    }
    const Param *cs = rib_var_param(r, p, n, "Cs", 3);
    if (cs)
        vars[2] = (RibVar){cs->v->d, NULL, cs->d.cls, 3};
    else if (rib_block_color_only(r) && r->a.cs_gen != r->object_cs_gen) {
        /* the block's Color, on the instance's shader */
        for (int c = 0; c < 3; c++)
            r->block_Cs[c] = r->a.Cs[c];
        vars[2] = (RibVar){r->block_Cs, NULL, CLS_CONSTANT, 3};
        r->pv_block_color = 1;
    }
    const Param *os = rib_var_param(r, p, n, "Os", 3);
    if (os)
        vars[3] = (RibVar){os->v->d, NULL, os->d.cls, 3};
    else if (rib_block_color_only(r) && r->a.os_gen != r->object_os_gen) {
        /* the block's Opacity, likewise */
        for (int c = 0; c < 3; c++)
            r->block_Os[c] = r->a.Os[c];
        vars[3] = (RibVar){r->block_Os, NULL, CLS_CONSTANT, 3};
        r->pv_block_color = 1;
    }
}

static void var_value(const RibVar *v, size_t j, float out[3])
{
    if (v->d2) {
        out[0] = (float)v->d[j], out[1] = (float)v->d2[j];
        return;
    }
    for (int c = 0; c < v->size; c++) {
        double x = v->d[(size_t)v->size * j + c];
        out[c] = fabs(x) < FLT_MAX ? (float)x : 0.0f;
    }
}

void rib_pv_out_free(PvOut *o)
{
    for (size_t i = 0; i < o->n; i++)
        free(o->data[i]);
    o->n = 0;
}

/* Adds variable b of vars as class cls with count values, the k-th from
 * source value src[k] (src NULL: k). Returns 0, or -1 out of memory. */
static int pv_add(Rib *r, PvOut *o, const RibVar *vars, int b, RayesPrimvarClass cls,
                  const size_t *src, size_t count)
{
    int size = vars[b].size;
    float *d = malloc((count ? count : 1) * (size_t)size * sizeof *d);
    if (!d)
        return rib_error(r, "out of memory");
    for (size_t k = 0; k < count; k++) {
        float v[3];
        var_value(&vars[b], src ? src[k] : k, v);
        memcpy(d + k * (size_t)size, v, (size_t)size * sizeof *d);
    }
    o->data[o->n] = d;
    o->pv[o->n++] = (RayesPrimvar){rib_var_names[b], cls, d, count};
    return 0;
}

/* The primitive variables of a patch: uniform value ui, varying corners
 * vi[4], facevarying corners fi[4], vertex values vv[n_vv] (4, or 16
 * control points in the current basis, made Bezier), each corner (control
 * point) order reversed along u when flip, as the patch's points are. */
static int patch_vars(Rib *r, const RibVar *vars, size_t ui, const size_t vi[4],
                      const size_t fi[4], const size_t *vv, int n_vv, int flip, PvOut *o)
{
    memset(o, 0, sizeof *o);
    for (int b = 0; b < RIB_N_VARS; b++) {
        if (!vars[b].d)
            continue;
        size_t src[16];
        int e = 0;
        switch (vars[b].cls) {
        case CLS_CONSTANT: e = pv_add(r, o, vars, b, RAYES_PRIMVAR_CONSTANT, NULL, 1); break;
        case CLS_UNIFORM: e = pv_add(r, o, vars, b, RAYES_PRIMVAR_UNIFORM, &ui, 1); break;
        case CLS_VARYING:
        case CLS_FACEVARYING:
            for (int k = 0; k < 4; k++)
                src[k] = (vars[b].cls == CLS_VARYING ? vi : fi)[flip ? k ^ 1 : k];
            e = pv_add(r, o, vars, b,
                       vars[b].cls == CLS_VARYING ? RAYES_PRIMVAR_VARYING
                                                  : RAYES_PRIMVAR_FACEVARYING,
                       src, 4);
            break;
        case CLS_VERTEX:
            if (n_vv == 4) {
                for (int k = 0; k < 4; k++)
                    src[k] = vv[flip ? k ^ 1 : k];
                e = pv_add(r, o, vars, b, RAYES_PRIMVAR_VERTEX, src, 4);
                break;
            }
            for (int k = 0; k < 16; k++)
                src[k] = vv[k];
            if ((e = pv_add(r, o, vars, b, RAYES_PRIMVAR_VERTEX, src, 16)) != 0)
                break;
            float G[16][3] = {{0}}, B[16][3];
            float *d = o->data[o->n - 1];
            int size = vars[b].size;
            for (int k = 0; k < 16; k++)
                memcpy(G[k], d + k * size, (size_t)size * sizeof *d);
            rib_basis_to_bezier(r->a.ubasis, r->a.vbasis, (const float(*)[3])G, B);
            for (int j = 0; j < 4; j++)
                for (int k = 0; k < 4; k++)
                    memcpy(d + (4 * j + k) * size, B[4 * j + (flip ? 3 - k : k)],
                           (size_t)size * sizeof *d);
            break;
        }
        if (e != 0) {
            rib_pv_out_free(o);
            return -1;
        }
    }
    return 0;
}

/* The primitive variables of polygons tessellated into faces: face f came
 * from polygon face_poly[f], whose corners start at poly_at[p] in the
 * polygon list g (for facevarying values: a face corner takes the value of
 * the polygon's first corner at the same point). */
static int poly_vars(Rib *r, const RibVar *vars, const RibFaces *faces, const size_t *face_poly,
                     const size_t *poly_at, const int *idx, const size_t *poly_nv,
                     size_t n_points, PvOut *o)
{
    memset(o, 0, sizeof *o);
    size_t *src = malloc((faces->n_idx + faces->n_faces + 1) * sizeof *src);
    if (!src)
        return rib_error(r, "out of memory");
    int e = 0;
    for (int b = 0; b < RIB_N_VARS && e == 0; b++) {
        if (!vars[b].d)
            continue;
        switch (vars[b].cls) {
        case CLS_CONSTANT: e = pv_add(r, o, vars, b, RAYES_PRIMVAR_CONSTANT, NULL, 1); break;
        case CLS_UNIFORM:
            e = pv_add(r, o, vars, b, RAYES_PRIMVAR_UNIFORM, face_poly, faces->n_faces);
            break;
        case CLS_VARYING:
        case CLS_VERTEX: e = pv_add(r, o, vars, b, RAYES_PRIMVAR_VERTEX, NULL, n_points); break;
        case CLS_FACEVARYING: {
            size_t k = 0;
            for (size_t f = 0; f < faces->n_faces; f++) {
                size_t p = face_poly[f], at = poly_at[p];
                for (int c = 0; c < faces->n_verts[f]; c++, k++) {
                    size_t j = 0;
                    while (j + 1 < poly_nv[p] && idx[at + j] != faces->idx[k])
                        j++;
                    src[k] = at + j;
                }
            }
            e = pv_add(r, o, vars, b, RAYES_PRIMVAR_FACEVARYING, src, k);
            break;
        }
        }
    }
    free(src);
    if (e != 0)
        rib_pv_out_free(o);
    return e;
}

/* The points of a primitive from "P" or "Pw" (divided by w); new array. */
float *rib_get_points(Rib *r, const Param *p, size_t n_par, size_t *n_points)
{
    const Param *P = rib_find_param(p, n_par, "P");
    const Param *Pw = rib_find_param(p, n_par, "Pw");
    if (!P && !Pw) {
        if (rib_find_param(p, n_par, "Pz"))
            rib_error(r, "\"Pz\" (a height field) is for Patch and PatchMesh; give \"P\"");
        else
            rib_error(r, "expected the positions \"P\"");
        return NULL;
    }
    int w = P == NULL;
    const Arg *v = w ? Pw->v : P->v;
    size_t dim = w ? 4 : 3;
    if (v->kind != ARG_NUMS && v->kind != ARG_NUM) {
        rib_error(r, "\"P\" needs numbers");
        return NULL;
    }
    if (v->n % dim != 0 || v->n == 0) {
        rib_arg_error(r, v, "\"%s\" needs %zu numbers per point, found %zu numbers", w ? "Pw" : "P",
                  dim, v->n);
        return NULL;
    }
    *n_points = v->n / dim;
    float *out = malloc(*n_points * 3 * sizeof *out);
    if (!out) {
        rib_error(r, "out of memory");
        return NULL;
    }
    for (size_t i = 0; i < *n_points; i++) {
        double ww = w ? v->d[4 * i + 3] : 1.0;
        if (ww == 0)
            ww = 1;
        for (int c = 0; c < 3; c++) {
            double x = v->d[dim * i + c] / ww;
            out[3 * i + c] = fabs(x) < FLT_MAX ? (float)x : 0.0f;
        }
    }
    return out;
}

/* The points of an nu x nv patch mesh (u fastest): rib_get_points', or
 * from a height field "Pz" (RenderMan's: each point's x and y are the
 * mesh's surface parameters at it, i / (nu - 1) and j / (nv - 1), over nu
 * and nv where the mesh wraps); new array. */
static float *grid_points(Rib *r, const Param *p, size_t n_par, long nu, long nv, int uwrap,
                          int vwrap, size_t *n_points)
{
    const Param *Pz = rib_find_param(p, n_par, "Pz");
    if (!Pz || rib_find_param(p, n_par, "P") || rib_find_param(p, n_par, "Pw"))
        return rib_get_points(r, p, n_par, n_points);
    const Arg *v = Pz->v;
    if (v->kind != ARG_NUMS && v->kind != ARG_NUM) {
        rib_error(r, "\"Pz\" needs numbers");
        return NULL;
    }
    if (v->n != (size_t)(nu * nv)) {
        rib_arg_error(r, v, "\"Pz\" needs %ld x %ld = %ld heights, found %zu", nu, nv, nu * nv,
                      v->n);
        return NULL;
    }
    *n_points = v->n;
    float *out = malloc(*n_points * 3 * sizeof *out);
    if (!out) {
        rib_error(r, "out of memory");
        return NULL;
    }
    long su = uwrap ? nu : nu - 1, sv = vwrap ? nv : nv - 1;
    for (long j = 0; j < nv; j++)
        for (long i = 0; i < nu; i++) {
            float *o = &out[3 * (size_t)(j * nu + i)];
            double z = v->d[j * nu + i];
            o[0] = su > 0 ? (float)((double)i / (double)su) : 0.0f;
            o[1] = sv > 0 ? (float)((double)j / (double)sv) : 0.0f;
            o[2] = fabs(z) < FLT_MAX ? (float)z : 0.0f;
        }
    return out;
}

/* Polygons as loops: polys of n_loops[p] loops, loops of loop_n[l] indices. */
typedef struct Polys {
    size_t n_polys;
    const int *n_loops; /* NULL: one loop each */
    const int *loop_n;
    const int *idx;
} Polys;

/* Grows an array of size_t to hold n + 1. */
static int grow_sizes(size_t **a, size_t *cap, size_t n)
{
    if (n < *cap)
        return 0;
    size_t c = *cap ? 2 * *cap : 64;
    size_t *p = realloc(*a, c * sizeof *p);
    if (!p)
        return -1;
    *a = p;
    *cap = c;
    return 0;
}

/* The radiance of the area light in force on shapes of area A (as
 * placed): BMRT's and Pixie's arealight give a point light's intensity,
 * with which each of its samples lights a point (I cos / d^2, averaged
 * over the shape), so a radiance of pi I / A in rayes' units (RSL's pi,
 * as for point lights); RenderMan's areaNormalize (PxrMeshLight's, RenderMan
 * 19-20's area lights') divides the radiance by A; other area lights give
 * the radiance (A is not needed: callers measure it only when
 * area_measured says). */
static int area_measured(const Rib *r)
{
    return r->a.area_point_units || r->a.area_normalize;
}

static void area_radiance(const Rib *r, double A, float L[3])
{
    double k = r->a.area_point_units ? (A > 0.0 ? M_PI / A : 0.0)
               : r->a.area_normalize ? (A > 0.0 ? 1.0 / A : 0.0)
                                     : 1.0;
    for (int c = 0; c < 3; c++)
        L[c] = (float)fmin((double)r->a.area_L[c] * k, FLT_MAX);
}

/* The area of the polygons of g (points P), as placed. */
static double polys_area(const Rib *r, const Polys *g, const float *P)
{
    double A = 0.0;
    for (size_t p = 0, loop = 0, at = 0; p < g->n_polys; p++) {
        size_t nl = g->n_loops ? (size_t)g->n_loops[p] : 1;
        A += rib_polygon_area(r->a.M, P, &g->idx[at], g->loop_n[loop]); /* its outline */
        for (size_t k = 0; k < nl; k++)
            at += (size_t)g->loop_n[loop + k];
        loop += nl;
    }
    return A;
}

/* Nonzero when the polygons of g are at most AREA_QUADS quads of one loop
 * each: under an area light, quad lights (sampled exactly as quads). */
#define AREA_QUADS 4
static int few_quads(const Polys *g)
{
    if (g->n_polys > AREA_QUADS)
        return 0;
    for (size_t p = 0, loop = 0; p < g->n_polys; p++) {
        size_t nl = g->n_loops ? (size_t)g->n_loops[p] : 1;
        if (nl != 1 || g->loop_n[loop] != 4)
            return 0;
        loop += nl;
    }
    return 1;
}

/* The polygons of g as one mesh light (tessellated as surfaces are),
 * textured by the area light's texture over tex_st (2 a point) when
 * given. */
static int emit_area_mesh(Rib *r, const Polys *g, const float *P, size_t n_points,
                          const float *tex_st)
{
    int flip = rib_flip(r), e = 0;
    RibFaces faces = {0};
    for (size_t p = 0, loop = 0, at = 0; p < g->n_polys && e == 0; p++) {
        size_t nl = g->n_loops ? (size_t)g->n_loops[p] : 1, nv = 0;
        for (size_t k = 0; k < nl; k++)
            nv += (size_t)g->loop_n[loop + k];
        if (rib_tessellate(P, &g->loop_n[loop], nl, &g->idx[at], flip, &faces) != 0)
            e = rib_error(r, "out of memory");
        loop += nl;
        at += nv;
    }
    if (e == 0 && faces.n_faces > 0 && (e = rib_emit_begin(r, NULL)) == 0) {
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        float L[3];
        area_radiance(r, area_measured(r) ? polys_area(r, g, P) : 0.0, L);
        RayesError res = tex_st
                             ? s->area_light_mesh_textured(s->target, faces.n_faces, faces.n_verts,
                                                           faces.idx, n_points, P, tex_st, L,
                                                           r->a.area_twosided, r->a.area_texture)
                             : s->area_light_mesh(s->target, faces.n_faces, faces.n_verts,
                                                  faces.idx, n_points, P, L, r->a.area_twosided);
        if (res != RAYES_OK)
            e = rib_sink_failed(r, s);
    }
    rib_faces_fini(&faces);
    return e > 0 ? 0 : e;
}

static int emit_polys(Rib *r, const Polys *g, const float *P, size_t n_points, const Param *par,
                      size_t n_par)
{
    if (r->a.area && r->a.area_texture[0]) { /* a textured emitter: one mesh light */
        SinkState *st;
        const Param *stp = rib_find_param(par, n_par, "st");
        if (!rib_out_sink(r, &st)->area_light_mesh_textured ||
            !rib_out_sink(r, &st)->area_light_mesh)
            rib_warn_once(r, "area texture sink",
                          "this scene takes no textured area lights; "
                          "the light's texture is not used");
        else if (!stp || !rib_is_num(stp->v) || stp->v->n != 2 * n_points)
            rib_warn_once(r, "area texture st",
                          "a textured area light's shape has no vertex "
                          "\"st\" (2 values a point); its texture is not used");
        else {
            float *stf = malloc(2 * n_points * sizeof *stf);
            if (!stf)
                return rib_error(r, "out of memory");
            for (size_t k = 0; k < 2 * n_points; k++)
                stf[k] = (float)stp->v->d[k];
            int e = emit_area_mesh(r, g, P, n_points, stf);
            free(stf);
            return e;
        }
    }
    if (r->a.area && !few_quads(g)) {
        SinkState *st;
        if (rib_out_sink(r, &st)->area_light_mesh)
            return emit_area_mesh(r, g, P, n_points, NULL);
    }
    RibVar vars[RIB_N_VARS];
    rib_vars(r, par, n_par, vars);
    int flip = rib_flip(r);
    RibFaces faces = {0};
    size_t *face_poly = NULL, *poly_at = NULL, *poly_nv = NULL, cap_f = 0, cap_a = 0, cap_n = 0;
    size_t loop = 0, at = 0;
    int e = 0;
    float L[3];
    if (r->a.area)
        area_radiance(r, area_measured(r) ? polys_area(r, g, P) : 0.0, L);
    for (size_t p = 0; p < g->n_polys && e == 0; p++) {
        size_t nl = g->n_loops ? (size_t)g->n_loops[p] : 1;
        size_t nv = 0;
        for (size_t k = 0; k < nl; k++)
            nv += (size_t)g->loop_n[loop + k];
        const int *v = &g->idx[at];
        if (grow_sizes(&poly_at, &cap_a, p) != 0 || grow_sizes(&poly_nv, &cap_n, p) != 0) {
            e = rib_error(r, "out of memory");
            break;
        }
        poly_at[p] = at, poly_nv[p] = nv;
        if (r->a.area && nl == 1 && g->loop_n[loop] == 4) {
            SinkState *st;
            const IoSink *s = rib_out_sink(r, &st);
            e = rib_emit_begin(r, NULL);
            for (int side = 0; e == 0 && side < 1 + r->a.area_twosided; side++) {
                float Q[4][3]; /* "twosided": the reversed quad too */
                for (int k = 0; k < 4; k++)
                    memcpy(Q[flip ^ side ? 3 - k : k], &P[3 * v[k]], sizeof Q[0]);
                if (s->area_light(s->target, (const float(*)[3])Q, L) != RAYES_OK)
                    e = rib_sink_failed(r, s);
            }
        } else {
            if (r->a.area)
                rib_warn_once(r, "area shape",
                              "this scene takes no mesh lights: only quads "
                              "become area lights, other polygons are surfaces");
            size_t first_face = faces.n_faces;
            if (rib_tessellate(P, &g->loop_n[loop], nl, v, flip, &faces) != 0)
                e = rib_error(r, "out of memory");
            for (size_t f = first_face; e == 0 && f < faces.n_faces; f++) {
                if (grow_sizes(&face_poly, &cap_f, f) != 0)
                    e = rib_error(r, "out of memory");
                else
                    face_poly[f] = p;
            }
        }
        loop += nl;
        at += nv;
    }
    PvOut pv = {0};
    if (e == 0 && faces.n_faces > 0 &&
        (e = poly_vars(r, vars, &faces, face_poly, poly_at, g->idx, poly_nv, n_points, &pv)) == 0 &&
        (e = rib_emit_begin(r, NULL)) == 0) {
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        if (s->polygon_mesh(s->target, faces.n_faces, faces.n_verts, faces.idx, n_points, P,
                            pv.pv, pv.n) != RAYES_OK)
            e = rib_sink_failed(r, s);
    }
    rib_pv_out_free(&pv);
    free(face_poly);
    free(poly_at);
    free(poly_nv);
    rib_faces_fini(&faces);
    return e > 0 ? 0 : e;
}

/* --------------------------------------------------------- primitives */

static int h_polygon(Rib *r, const Args *a)
{
    Param *p;
    size_t n, np = 0;
    if (rib_get_params(r, a, 0, &p, &n) != 0)
        return -1;
    float *P = rib_get_points(r, p, n, &np);
    int e = P ? 0 : -1;
    Counts c = {1, np, np, np};
    if (e == 0 && np < 3)
        e = rib_error(r, "a polygon needs at least 3 points, found %zu", np);
    if (e == 0)
        e = rib_check_counts(r, p, n, &c);
    int *idx = e == 0 ? malloc(np * sizeof *idx) : NULL;
    if (e == 0 && !idx)
        e = rib_error(r, "out of memory");
    if (e == 0) {
        for (size_t k = 0; k < np; k++)
            idx[k] = (int)k;
        int nv = (int)np;
        Polys g = {1, NULL, &nv, idx};
        rib_warn_unused(r, p, n);
        e = emit_polys(r, &g, P, np, p, n);
    }
    free(idx);
    free(P);
    free(p);
    return e;
}

static int h_general_polygon(Rib *r, const Args *a)
{
    size_t i = 0, nl = 0, n, np = 0;
    int *loops = NULL;
    Param *p = NULL;
    if (rib_get_ints(r, a, &i, &loops, &nl, 3, 1 << 24, "vertices per loop") != 0)
        return -1;
    int e = rib_get_params(r, a, i, &p, &n);
    float *P = e == 0 ? rib_get_points(r, p, n, &np) : NULL;
    if (e == 0 && !P)
        e = -1;
    size_t total = 0;
    for (size_t k = 0; k < nl; k++)
        total += (size_t)loops[k];
    Counts c = {1, np, np, np};
    if (e == 0 && (nl == 0 || total != np))
        e = rib_error(r, "the loops have %zu vertices but \"P\" gives %zu points", total, np);
    if (e == 0)
        e = rib_check_counts(r, p, n, &c);
    int *idx = e == 0 ? malloc(np * sizeof *idx) : NULL;
    if (e == 0 && !idx)
        e = rib_error(r, "out of memory");
    if (e == 0) {
        for (size_t k = 0; k < np; k++)
            idx[k] = (int)k;
        int nlo = (int)nl;
        Polys g = {1, &nlo, loops, idx};
        rib_warn_unused(r, p, n);
        e = emit_polys(r, &g, P, np, p, n);
    }
    free(idx);
    free(P);
    free(p);
    free(loops);
    return e;
}

/* PointsPolygons (general 0) and PointsGeneralPolygons (general 1). */
static int points_polygons(Rib *r, const Args *a, size_t i, int general)
{
    int *nloops = NULL, *nverts = NULL, *verts = NULL;
    size_t n_polys = 0, n_loops = 0, n_idx = 0, n = 0, np = 0;
    Param *p = NULL;
    float *P = NULL;
    int e = 0;
    if (general)
        e = rib_get_ints(r, a, &i, &nloops, &n_polys, 1, 1 << 24, "loops per polygon");
    if (e == 0)
        e = rib_get_ints(r, a, &i, &nverts, &n_loops, 3, 1 << 24, "vertices per polygon");
    if (e == 0)
        e = rib_get_ints(r, a, &i, &verts, &n_idx, 0, 1 << 30, "vertex indices");
    if (e == 0)
        e = rib_get_params(r, a, i, &p, &n);
    if (e == 0 && !(P = rib_get_points(r, p, n, &np)))
        e = -1;
    if (e == 0 && !general)
        n_polys = n_loops;
    size_t sum_loops = 0, sum_verts = 0;
    for (size_t k = 0; general && k < n_polys; k++)
        sum_loops += (size_t)nloops[k];
    for (size_t k = 0; k < n_loops; k++)
        sum_verts += (size_t)nverts[k];
    if (e == 0 && general && sum_loops != n_loops)
        e = rib_error(r, "the polygons have %zu loops but %zu loop sizes are given", sum_loops,
                      n_loops);
    if (e == 0 && sum_verts != n_idx)
        e = rib_error(r, "the loops have %zu vertices but %zu indices are given", sum_verts, n_idx);
    for (size_t k = 0; e == 0 && k < n_idx; k++)
        if ((size_t)verts[k] >= np)
            e = rib_error(r, "vertex index %d is past the %zu points of \"P\"", verts[k], np);
    Counts c = {n_polys, np, np, n_idx};
    if (e == 0)
        e = rib_check_counts(r, p, n, &c);
    if (e == 0) {
        Polys g = {n_polys, general ? nloops : NULL, nverts, verts};
        rib_warn_unused(r, p, n);
        e = emit_polys(r, &g, P, np, p, n);
    }
    free(P);
    free(p);
    free(nloops);
    free(nverts);
    free(verts);
    return e;
}

static int h_points_polygons(Rib *r, const Args *a) { return points_polygons(r, a, 0, 0); }
static int h_points_general_polygons(Rib *r, const Args *a) { return points_polygons(r, a, 0, 1); }

/* ------------------------------------------------- subdivision meshes */

/* A numeric argument's values (a scalar or an array), or NULL with the
 * error set. */
static const double *num_array(Rib *r, const Args *a, size_t *i, size_t *n, const char *what)
{
    if (*i >= a->n || (a->v[*i].kind != ARG_NUMS && a->v[*i].kind != ARG_NUM)) {
        rib_error(r, "expected %s", what);
        return NULL;
    }
    const Arg *g = &a->v[(*i)++];
    *n = g->n;
    return g->d ? g->d : (const double *)"";
}

/* A string argument's strings (a string or an array), or NULL with the
 * error set. */
static char *const *str_array(Rib *r, const Args *a, size_t *i, size_t *n, const char *what)
{
    static char *const none[1] = {NULL};
    const Arg *g = *i < a->n ? &a->v[*i] : NULL;
    if (g && g->kind == ARG_NUMS && g->n == 0) { /* [] */
        (*i)++;
        *n = 0;
        return none;
    }
    if (!g || (g->kind != ARG_STRS && g->kind != ARG_STR)) {
        rib_error(r, "expected %s", what);
        return NULL;
    }
    (*i)++;
    *n = g->n;
    return g->s;
}

/* The tags of a SubdivisionMesh, as rayes.h takes them; arrays owned. */
typedef struct SubdivTags {
    RayesSubdivTags t;
    int *edges, *corners, *holes;
    float *edge_sharp, *corner_sharp;
} SubdivTags;

static void subdiv_tags_free(SubdivTags *s)
{
    free(s->edges), free(s->corners), free(s->holes);
    free(s->edge_sharp), free(s->corner_sharp);
}

/* Appends n ints and their sharpness (one for all, or one each) to a tag
 * list; chain: the ints are a chain of points, each step an edge. */
static int add_sharp(Rib *r, int **ints, float **sharp, size_t *count, const double *iv, size_t ni,
                     const double *fv, size_t nf, int chain, const char *tag)
{
    size_t items = chain ? (ni >= 2 ? ni - 1 : 0) : ni;
    if ((chain && ni < 2) || nf == 0 || (nf != 1 && nf != items))
        return rib_error(r, "tag \"%s\": %zu points and %zu sharpnesses (expected %s)", tag, ni, nf,
                         chain ? "at least 2 points, and 1 sharpness or one per edge"
                               : "1 sharpness or one per point");
    size_t per = chain ? 2 : 1;
    int *ni_ = realloc(*ints, (*count + items) * per * sizeof **ints + sizeof **ints);
    if (ni_)
        *ints = ni_;
    float *ns = realloc(*sharp, (*count + items) * sizeof **sharp + sizeof **sharp);
    if (ns)
        *sharp = ns;
    if (!ni_ || !ns)
        return rib_error(r, "out of memory");
    for (size_t k = 0; k < items; k++) {
        for (size_t c = 0; c < per; c++) {
            double x = iv[k + c];
            (*ints)[(*count + k) * per + c] = x >= 0 && x < 2147483647.0 ? (int)x : -1;
        }
        double s = fv[nf == 1 ? 0 : k];
        (*sharp)[*count + k] = s >= 0 && s < 1e30 ? (float)s : -1.0f;
    }
    *count += items;
    return 0;
}

/* Reads tags nargs intargs floatargs (and stringargs for the
 * hierarchical form, per = 3) from *i on. */
/* Whether a bare string after a mesh's indices names a tag (some writers
 * leave out the brackets of a one-tag array) rather than a parameter. */
static int is_tag_name(const char *s)
{
    static const char *const tags[] = {"interpolateboundary",
                                       "facevaryinginterpolateboundary",
                                       "crease",
                                       "corner",
                                       "hole",
                                       "creasemethod",
                                       "facevaryingpropagatecorners",
                                       "smoothtriangles",
                                       "vertexedit",
                                       "edgeedit",
                                       "faceedit",
                                       NULL};
    for (int k = 0; tags[k]; k++)
        if (strcmp(s, tags[k]) == 0)
            return 1;
    return 0;
}

static int subdiv_tags(Rib *r, const Args *a, size_t *i, int per, SubdivTags *out)
{
    size_t n_tags, n_nargs, n_int, n_float, n_str = 0;
    /* The tag arrays may be left out altogether (no tags): the parameters
     * follow the indices. */
    if (*i >= a->n || (a->v[*i].kind == ARG_STR && !is_tag_name(a->v[*i].s[0]))) {
        out->t.interpolate_boundary = 0; /* RenderMan's default */
        out->t.facevarying_boundary = 1;
        return 0;
    }
    char *const *tags = str_array(r, a, i, &n_tags, "the tags (strings)");
    const double *nargs = tags ? num_array(r, a, i, &n_nargs, "the tags' argument counts") : NULL;
    const double *iv = nargs ? num_array(r, a, i, &n_int, "the tags' integer arguments") : NULL;
    const double *fv = iv ? num_array(r, a, i, &n_float, "the tags' float arguments") : NULL;
    if (fv && per == 3 && !str_array(r, a, i, &n_str, "the tags' string arguments"))
        return -1;
    if (!fv)
        return -1;
    if (n_nargs != (size_t)per * n_tags)
        return rib_error(r, "%zu tags need %zu argument counts; %zu given", n_tags,
                         (size_t)per * n_tags, n_nargs);
    RayesSubdivTags *t = &out->t;
    t->interpolate_boundary = 0; /* RenderMan's default: boundary faces are left out */
    t->facevarying_boundary = 1;
    size_t at_i = 0, at_f = 0, n_edges = 0, n_corners = 0;
    for (size_t k = 0; k < n_tags; k++) {
        double di = nargs[per * k], df = nargs[per * k + 1];
        if (!(di >= 0 && df >= 0 && di <= (double)(n_int - at_i) && df <= (double)(n_float - at_f)))
            return rib_error(r, "tag \"%s\" asks for more arguments than are given", tags[k]);
        size_t ni = (size_t)di, nf = (size_t)df;
        const double *ti = iv + at_i, *tf = fv + at_f;
        at_i += ni, at_f += nf;
        const char *tag = tags[k];
        int e = 0;
        if (strcmp(tag, "interpolateboundary") == 0) {
            t->interpolate_boundary = ni ? (int)fmin(fmax(ti[0], -1.0), 3.0) : 1;
            if (t->interpolate_boundary < 0 || t->interpolate_boundary > 2)
                e = rib_error(r, "tag \"interpolateboundary\": expected 0, 1 or 2");
        } else if (strcmp(tag, "facevaryinginterpolateboundary") == 0) {
            t->facevarying_boundary = ni ? (int)fmin(fmax(ti[0], -1.0), 4.0) : 1;
            if (t->facevarying_boundary < 0 || t->facevarying_boundary > 3)
                e = rib_error(r, "tag \"facevaryinginterpolateboundary\": expected 0 to 3");
        } else if (strcmp(tag, "crease") == 0)
            e = add_sharp(r, &out->edges, &out->edge_sharp, &n_edges, ti, ni, tf, nf, 1, tag);
        else if (strcmp(tag, "corner") == 0)
            e = add_sharp(r, &out->corners, &out->corner_sharp, &n_corners, ti, ni, tf, nf, 0, tag);
        else if (strcmp(tag, "hole") == 0) {
            int *h = realloc(out->holes, (t->n_holes + ni + 1) * sizeof *h);
            if (!h)
                return rib_error(r, "out of memory");
            out->holes = h;
            for (size_t c = 0; c < ni; c++)
                h[t->n_holes++] = ti[c] >= 0 && ti[c] < 2147483647.0 ? (int)ti[c] : -1;
        } else {
            char key[96];
            snprintf(key, sizeof key, "subdiv tag %.60s", tag);
            rib_warn_once(r, key, "tag \"%s\" is ignored", tag);
        }
        if (e != 0)
            return -1;
    }
    t->n_creases = n_edges, t->crease_edges = out->edges, t->crease_sharpness = out->edge_sharp;
    t->n_corners = n_corners, t->corner_points = out->corners;
    t->corner_sharpness = out->corner_sharp;
    t->hole_faces = out->holes;
    return 0;
}

static int subdiv_scheme(Rib *r, const char *name, RayesSubdivScheme *scheme)
{
    static const char *const names[3] = {"catmull-clark", "loop", "bilinear"};
    for (int k = 0; k < 3; k++)
        if (strcmp(name, names[k]) == 0) {
            *scheme = (RayesSubdivScheme)k;
            return 0;
        }
    return rib_error(r, "unknown scheme \"%s\"; expected catmull-clark, loop or bilinear", name);
}

/* The primitive variables of a subdivision mesh; facevarying values
 * follow the corners as order[] permutes them. */
static int subdiv_vars(Rib *r, const RibVar *vars, size_t n_faces, size_t n_points,
                       const size_t *order, size_t n_idx, PvOut *o)
{
    memset(o, 0, sizeof *o);
    static const RayesPrimvarClass cls_of[] = {[CLS_CONSTANT] = RAYES_PRIMVAR_CONSTANT,
                                               [CLS_UNIFORM] = RAYES_PRIMVAR_UNIFORM,
                                               [CLS_VARYING] = RAYES_PRIMVAR_VARYING,
                                               [CLS_VERTEX] = RAYES_PRIMVAR_VERTEX,
                                               [CLS_FACEVARYING] = RAYES_PRIMVAR_FACEVARYING};
    int e = 0;
    for (int b = 0; b < RIB_N_VARS && e == 0; b++) {
        if (!vars[b].d)
            continue;
        RayesPrimvarClass c = cls_of[vars[b].cls];
        size_t count = c == RAYES_PRIMVAR_CONSTANT      ? 1
                       : c == RAYES_PRIMVAR_UNIFORM     ? n_faces
                       : c == RAYES_PRIMVAR_FACEVARYING ? n_idx
                                                        : n_points;
        e = pv_add(r, o, vars, b, c, c == RAYES_PRIMVAR_FACEVARYING ? order : NULL, count);
    }
    if (e != 0)
        rib_pv_out_free(o);
    return e;
}

/* SubdivisionMesh (per = 2) and HierarchicalSubdivisionMesh (per = 3, its
 * string arguments unused). */
static int subdivision_mesh(Rib *r, const Args *a, int per)
{
    size_t i = 0, n_faces = 0, n_idx = 0, n = 0, np = 0;
    const char *name = rib_get_string(r, a, &i, "a subdivision scheme");
    RayesSubdivScheme scheme = RAYES_SUBDIV_CATMULL_CLARK;
    if (!name || subdiv_scheme(r, name, &scheme) != 0)
        return -1;
    int *nverts = NULL, *verts = NULL;
    size_t *order = NULL;
    Param *p = NULL;
    float *P = NULL;
    SubdivTags tags = {0};
    PvOut pv = {0};
    int e = rib_get_ints(r, a, &i, &nverts, &n_faces, 3, 1 << 16, "vertices per face");
    if (e == 0)
        e = rib_get_ints(r, a, &i, &verts, &n_idx, 0, 1 << 30, "vertex indices");
    if (e == 0)
        e = subdiv_tags(r, a, &i, per, &tags);
    if (e == 0)
        e = rib_get_params(r, a, i, &p, &n);
    if (e == 0 && !(P = rib_get_points(r, p, n, &np)))
        e = -1;
    size_t sum = 0;
    for (size_t k = 0; e == 0 && k < n_faces; k++)
        sum += (size_t)nverts[k];
    if (e == 0 && sum != n_idx)
        e = rib_error(r, "the faces have %zu vertices but %zu indices are given", sum, n_idx);
    for (size_t k = 0; e == 0 && k < n_idx; k++)
        if ((size_t)verts[k] >= np)
            e = rib_error(r, "vertex index %d is past the %zu points of \"P\"", verts[k], np);
    Counts c = {n_faces, np, np, n_idx};
    if (e == 0)
        e = rib_check_counts(r, p, n, &c);
    /* Wound as the orientation says: each face reversed after its first
     * corner, facevarying values with it. */
    if (e == 0 && !(order = malloc((n_idx + 1) * sizeof *order)))
        e = rib_error(r, "out of memory");
    int flip = e == 0 && rib_flip(r);
    for (size_t f = 0, at = 0; e == 0 && f < n_faces; at += (size_t)nverts[f++])
        for (int k = 0; k < nverts[f]; k++)
            order[at + (size_t)k] = at + (size_t)(flip && k ? nverts[f] - k : k);
    int *wound = e == 0 ? malloc((n_idx + 1) * sizeof *wound) : NULL;
    if (e == 0 && !wound)
        e = rib_error(r, "out of memory");
    for (size_t k = 0; e == 0 && k < n_idx; k++)
        wound[k] = verts[order[k]];
    RibVar vars[RIB_N_VARS];
    if (e == 0) {
        rib_vars(r, p, n, vars);
        e = subdiv_vars(r, vars, n_faces, np, order, n_idx, &pv);
    }
    if (e == 0 && r->a.area)
        rib_warn_once(r, "area shape",
                      "only quads become area lights; other shapes under "
                      "AreaLightSource are ordinary surfaces");
    if (e == 0 && (e = rib_emit_begin(r, NULL)) == 0) {
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        rib_warn_unused(r, p, n);
        if (!s->subdivision_mesh)
            e = rib_error(r, "this sink takes no subdivision meshes");
        else if (s->subdivision_mesh(s->target, scheme, n_faces, nverts, wound, np, P, &tags.t,
                                     pv.pv, pv.n) != RAYES_OK)
            e = rib_sink_failed(r, s);
    }
    if (e == 1) /* outside the world: nothing to draw */
        e = 0;
    rib_pv_out_free(&pv);
    subdiv_tags_free(&tags);
    free(wound);
    free(order);
    free(P);
    free(p);
    free(nverts);
    free(verts);
    return e;
}

static int h_subdivision_mesh(Rib *r, const Args *a)
{
    return subdivision_mesh(r, a, 2);
}
static int h_hierarchical_subdivision_mesh(Rib *r, const Args *a)
{
    return subdivision_mesh(r, a, 3);
}

int rib_emit_bicubic(Rib *r, float B[16][3], const PvOut *pv)
{
    if (rib_flip(r))
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 2; k++)
                for (int c = 0; c < 3; c++) {
                    float t = B[4 * j + k][c];
                    B[4 * j + k][c] = B[4 * j + 3 - k][c];
                    B[4 * j + 3 - k][c] = t;
                }
    int e = rib_emit_begin(r, NULL);
    if (e != 0)
        return e > 0 ? 0 : -1;
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    return s->bicubic_patch(s->target, (const float(*)[3])B, pv->pv, pv->n) == RAYES_OK
               ? 0
               : rib_sink_failed(r, s);
}

static int emit_bilinear(Rib *r, const float P[4][3], const PvOut *pv)
{
    float Q[4][3];
    int flip = rib_flip(r);
    for (int k = 0; k < 4; k++)
        memcpy(Q[flip ? k ^ 1 : k], P[k], sizeof Q[0]);
    int e = rib_emit_begin(r, NULL);
    if (e != 0)
        return e > 0 ? 0 : -1;
    SinkState *st;
    const IoSink *s = rib_out_sink(r, &st);
    if (r->a.area) {
        float A[4][3];
        memcpy(A[0], Q[0], sizeof A[0]);
        memcpy(A[1], Q[1], sizeof A[0]);
        memcpy(A[2], Q[3], sizeof A[0]);
        memcpy(A[3], Q[2], sizeof A[0]);
        static const int around[4] = {0, 1, 2, 3};
        float L[3];
        area_radiance(r, area_measured(r) ? rib_polygon_area(r->a.M, &A[0][0], around, 4) : 0.0, L);
        return s->area_light(s->target, (const float(*)[3])A, L) == RAYES_OK
                   ? 0
                   : rib_sink_failed(r, s);
    }
    return s->bilinear_patch(s->target, (const float(*)[3])Q, pv->pv, pv->n) == RAYES_OK
               ? 0
               : rib_sink_failed(r, s);
}

/* The colour (or opacity) of a quadric: Cs (Os) constant/uniform (index
 * u_index), or the average of the given varying/vertex indices (quadrics
 * take no primitive variables). */
static const float *patch_color(Rib *r, const Param *cs, size_t uniform_index,
                                const size_t *vi, size_t nvi, const size_t *vv, size_t nvv,
                                float out[3])
{
    if (!cs || !cs->declared)
        return NULL;
    if (cs->d.cls == CLS_CONSTANT || cs->d.cls == CLS_UNIFORM) {
        size_t j = cs->d.cls == CLS_CONSTANT ? 0 : uniform_index;
        for (int c = 0; c < 3; c++)
            out[c] = (float)cs->v->d[3 * j + c];
        return out;
    }
    if (strcmp(cs->d.name, "Cs") == 0)
        rib_warn_once(r, "vertex Cs",
                      "per-vertex colours (Cs) of quadrics are averaged: "
                      "quadrics take one colour");
    else
        rib_warn_once(r, "vertex Os",
                      "per-vertex opacities (Os) of quadrics are averaged: "
                      "quadrics take one opacity");
    const size_t *ix = cs->d.cls == CLS_VERTEX ? vv : vi;
    size_t nx = cs->d.cls == CLS_VERTEX ? nvv : nvi;
    double s[3] = {0, 0, 0};
    for (size_t k = 0; k < nx; k++)
        for (int c = 0; c < 3; c++)
            s[c] += cs->v->d[3 * ix[k] + c];
    for (int c = 0; c < 3; c++)
        out[c] = (float)(s[c] / (double)nx);
    return out;
}

static int h_patch(Rib *r, const Args *a)
{
    size_t i = 0, n, np = 0;
    const char *type = rib_get_string(r, a, &i, "\"bilinear\" or \"bicubic\"");
    Param *p;
    if (!type || rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    int cubic = strcmp(type, "bicubic") == 0;
    int e = 0;
    if (!cubic && strcmp(type, "bilinear") != 0)
        e = rib_error(r, "expected \"bilinear\" or \"bicubic\", found \"%s\"", type);
    float *P = e == 0 ? grid_points(r, p, n, cubic ? 4 : 2, cubic ? 4 : 2, 0, 0, &np) : NULL;
    if (e == 0 && !P)
        e = -1;
    size_t want = cubic ? 16 : 4;
    if (e == 0 && np != want)
        e = rib_error(r, "a %s patch needs %zu points, found %zu", type, want, np);
    Counts c = {1, 4, want, 4};
    if (e == 0)
        e = rib_check_counts(r, p, n, &c);
    RibVar vars[RIB_N_VARS];
    PvOut pv = {0};
    if (e == 0) {
        rib_warn_unused(r, p, n);
        rib_vars(r, p, n, vars);
        if (!vars[1].d && r->a.have_texcoords) /* TextureCoordinates: st at the corners */
            vars[1] = (RibVar){r->a.texcoords, NULL, CLS_VARYING, 2};
        static const size_t corners[4] = {0, 1, 2, 3};
        static const size_t all[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
        e = patch_vars(r, vars, 0, corners, corners, all, (int)want, rib_flip(r), &pv);
    }
    if (e == 0) {
        if (cubic) {
            float B[16][3];
            rib_basis_to_bezier(r->a.ubasis, r->a.vbasis, (const float(*)[3])P, B);
            e = rib_emit_bicubic(r, B, &pv);
        } else {
            e = emit_bilinear(r, (const float(*)[3])P, &pv);
        }
    }
    rib_pv_out_free(&pv);
    free(P);
    free(p);
    return e;
}

static int wrap_of(Rib *r, const char *s, int *periodic)
{
    if (strcmp(s, "periodic") == 0 || strcmp(s, "wrap") == 0) /* ri.h's RI_WRAP too */
        *periodic = 1;
    else if (strcmp(s, "nonperiodic") == 0 || strcmp(s, "nowrap") == 0)
        *periodic = 0;
    else
        return rib_error(r, "expected \"periodic\" or \"nonperiodic\", found \"%s\"", s);
    return 0;
}

/* Patches along one direction of a patch mesh; -1 when n does not fit. */
static long mesh_patches(long n, int periodic, int cubic, int step)
{
    if (!cubic)
        return periodic ? n : n - 1;
    if (periodic)
        return n % step == 0 ? n / step : -1;
    return n >= 4 && (n - 4) % step == 0 ? (n - 4) / step + 1 : -1;
}

static int h_patch_mesh(Rib *r, const Args *a)
{
    size_t i = 0, n, np = 0;
    const char *type = rib_get_string(r, a, &i, "\"bilinear\" or \"bicubic\"");
    float nuv[2];
    const char *uw, *vw;
    int up = 0, vp = 0;
    if (!type || rib_get_floats(r, a, &i, nuv, 1, "nu") != 0 ||
        !(uw = rib_get_string(r, a, &i, "\"periodic\" or \"nonperiodic\"")) ||
        rib_get_floats(r, a, &i, nuv + 1, 1, "nv") != 0 ||
        !(vw = rib_get_string(r, a, &i, "\"periodic\" or \"nonperiodic\"")) ||
        wrap_of(r, uw, &up) != 0 || wrap_of(r, vw, &vp) != 0)
        return -1;
    int cubic = strcmp(type, "bicubic") == 0;
    if (!cubic && strcmp(type, "bilinear") != 0)
        return rib_error(r, "expected \"bilinear\" or \"bicubic\", found \"%s\"", type);
    if (!(nuv[0] >= 1 && nuv[0] <= 1 << 24 && nuv[1] >= 1 && nuv[1] <= 1 << 24) ||
        nuv[0] != floorf(nuv[0]) || nuv[1] != floorf(nuv[1]))
        return rib_error(r, "nu and nv must be positive integers");
    long nu = (long)nuv[0], nv = (long)nuv[1];
    int us = cubic ? r->a.ustep : 1, vs = cubic ? r->a.vstep : 1;
    long nup = mesh_patches(nu, up, cubic, us), nvp = mesh_patches(nv, vp, cubic, vs);
    if (nup < 1 || nvp < 1)
        return rib_error(r, "%ld x %ld points do not make whole patches (steps %d, %d)", nu, nv,
                         us, vs);
    Param *p;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    float *P = grid_points(r, p, n, nu, nv, up, vp, &np);
    int e = P ? 0 : -1;
    if (e == 0 && np != (size_t)(nu * nv))
        e = rib_error(r, "\"P\" needs %ld x %ld = %ld points, found %zu", nu, nv, nu * nv, np);
    long nuvar = cubic ? nup + !up : nu, nvvar = cubic ? nvp + !vp : nv;
    Counts c = {(size_t)(nup * nvp), (size_t)(nuvar * nvvar), np, (size_t)(nup * nvp * 4)};
    if (e == 0)
        e = rib_check_counts(r, p, n, &c);
    RibVar vars[RIB_N_VARS];
    if (e == 0) {
        rib_warn_unused(r, p, n);
        rib_vars(r, p, n, vars);
    }
    int flip = rib_flip(r);
    for (long pv = 0; e == 0 && pv < nvp; pv++)
        for (long pu = 0; e == 0 && pu < nup; pu++) {
            size_t vi[4] = {(size_t)(pv * nuvar + pu), (size_t)(pv * nuvar + (pu + 1) % nuvar),
                            (size_t)(((pv + 1) % nvvar) * nuvar + pu),
                            (size_t)(((pv + 1) % nvvar) * nuvar + (pu + 1) % nuvar)};
            int k = cubic ? 4 : 2;
            size_t vv[16];
            float G[16][3];
            for (int j = 0; j < k; j++)
                for (int q = 0; q < k; q++) {
                    size_t idx = (size_t)(((pv * vs + j) % nv) * nu + (pu * us + q) % nu);
                    vv[j * k + q] = idx;
                    memcpy(G[j * k + q], &P[3 * idx], sizeof G[0]);
                }
            size_t ui = (size_t)(pv * nup + pu), fi[4] = {4 * ui, 4 * ui + 1, 4 * ui + 2, 4 * ui + 3};
            PvOut out;
            e = patch_vars(r, vars, ui, vi, fi, vv, k * k, flip, &out);
            if (e == 0 && cubic) {
                float B[16][3];
                rib_basis_to_bezier(r->a.ubasis, r->a.vbasis, (const float(*)[3])G, B);
                e = rib_emit_bicubic(r, B, &out);
            } else if (e == 0) {
                e = emit_bilinear(r, (const float(*)[3])G, &out);
            }
            if (e == 0)
                rib_pv_out_free(&out);
        }
    free(P);
    free(p);
    return e;
}

static int h_quadric(Rib *r, const Args *a)
{
    static const struct {
        const char *name;
        RayesQuadric type;
        int n;
        const char *what;
    } q[] = {{"Sphere", RAYES_QUADRIC_SPHERE, 4, "radius zmin zmax thetamax"},
             {"Cylinder", RAYES_QUADRIC_CYLINDER, 4, "radius zmin zmax thetamax"},
             {"Cone", RAYES_QUADRIC_CONE, 3, "height radius thetamax"},
             {"Disk", RAYES_QUADRIC_DISK, 3, "height radius thetamax"},
             {"Paraboloid", RAYES_QUADRIC_PARABOLOID, 4, "rmax zmin zmax thetamax"},
             {"Hyperboloid", RAYES_QUADRIC_HYPERBOLOID, 7, "point1 point2 thetamax"},
             {"Torus", RAYES_QUADRIC_TORUS, 5, "rmajor rminor phimin phimax thetamax"}};
    int k = 0;
    while (strcmp(q[k].name, r->req) != 0)
        k++;
    size_t i = 0, n;
    float v[7];
    Param *p;
    if (rib_get_floats(r, a, &i, v, (size_t)q[k].n, q[k].what) != 0 || rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    Counts c = {1, 4, 4, 4};
    int e = rib_check_counts(r, p, n, &c);
    if (e == 0) {
        rib_warn_unused(r, p, n);
        static const size_t corners[4] = {0, 1, 2, 3};
        float col[3], op[3], saved[3];
        const float *Cs = patch_color(r, rib_color_param(r, p, n), 0, corners, 4, corners, 4, col);
        const float *Os =
            patch_color(r, rib_var_param(r, p, n, "Os", 3), 0, corners, 4, corners, 4, op);
        memcpy(saved, r->a.Os, sizeof saved);
        if (Os) /* the shader is sent with this opacity, as with a per-face colour */
            memcpy(r->a.Os, Os, sizeof r->a.Os);
        e = rib_emit_begin(r, Os && !Cs ? r->a.Cs : Cs);
        memcpy(r->a.Os, saved, sizeof saved);
        if (e == 0) {
            SinkState *st;
            const IoSink *s = rib_out_sink(r, &st);
            unsigned flags = rib_flip(r) ? RAYES_QUADRIC_REVERSE : 0;
            /* a negative radius of a disk, cone or cylinder: the same
             * surface, its parameters (and so its normals) turned over */
            int ri = q[k].type == RAYES_QUADRIC_CYLINDER                                  ? 0
                     : q[k].type == RAYES_QUADRIC_DISK || q[k].type == RAYES_QUADRIC_CONE ? 1
                                                                                          : -1;
            if (ri >= 0 && v[ri] < 0.0f) {
                v[ri] = -v[ri];
                flags ^= RAYES_QUADRIC_REVERSE;
            }
            if (r->a.area && !s->area_light_quadric)
                rib_warn_once(r, "area quadric",
                              "this scene takes no emitting quadrics: they "
                              "are surfaces");
            if (r->a.area && s->area_light_quadric) { /* an emitter */
                float L[3];
                area_radiance(
                    r, area_measured(r) ? rib_quadric_area(r->a.M, (int)q[k].type, v) : 0.0, L);
                if (s->area_light_quadric(s->target, q[k].type, v, (size_t)q[k].n, flags, L,
                                          r->a.area_twosided) != RAYES_OK)
                    e = rib_sink_failed(r, s);
            } else if (s->quadric(s->target, q[k].type, v, (size_t)q[k].n, flags) != RAYES_OK) {
                e = rib_sink_failed(r, s);
            }
        }
        e = e > 0 ? 0 : e;
    }
    free(p);
    return e;
}

/* Volume "box" [xmin xmax ymin ymax zmin zmax] [nx ny nz]: a volume filled
 * by the current surface shader (a volume shader: its opacity is the
 * extinction); the voxel counts are read and unused (rayes chooses the
 * resolution from the camera). Other types warn once and are skipped. */
static int h_volume(Rib *r, const Args *a)
{
    size_t i = 0, n;
    const char *type = rib_get_string(r, a, &i, "a volume type");
    float b[6], dims[3];
    Param *p;
    if (!type || rib_get_floats(r, a, &i, b, 6, "the bound xmin xmax ymin ymax zmin zmax") != 0 ||
        rib_get_floats(r, a, &i, dims, 3, "the voxel counts nx ny nz") != 0 ||
        rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    /* rayes' own "inside" 1: only inside the geometry just before it */
    const Param *in = rib_find_param(p, n, "inside");
    int inside = in && rib_is_num(in->v) && in->v->n == 1 && in->v->d[0] != 0;
    free(p);
    if (strcmp(type, "box") != 0) {
        char key[128];
        snprintf(key, sizeof key, "volume %s", type);
        rib_warn_once(r, key, "Volume \"%s\" is not supported (only \"box\"); skipped", type);
        return 0;
    }
    if (!(b[0] < b[1] && b[2] < b[3] && b[4] < b[5]))
        return rib_error(r, "Volume: expected a bound with xmin < xmax, ymin < ymax, zmin < zmax");
    int e = rib_emit_begin(r, NULL);
    if (e == 0) {
        SinkState *st;
        const IoSink *s = rib_out_sink(r, &st);
        if (!s->volume)
            rib_warn_once(r, "volume sink", "Volume is not supported here; skipped");
        else if ((inside && s->volume_inside ? s->volume_inside(s->target, b)
                                             : s->volume(s->target, b)) != RAYES_OK)
            e = rib_sink_failed(r, s);
    }
    return e > 0 ? 0 : e;
}

/* Geometry "teapot": io_read_bpt drives this sink, whose patches go
 * through the reader's own emission (transform, shader, orientation,
 * object recording). */
typedef struct TeapotTarget {
    Rib *r;
    int failed;
} TeapotTarget;

static RayesError teapot_patch(void *t, const float P[16][3], const RayesPrimvar *pv,
                               size_t n_pv)
{
    TeapotTarget *tt = t;
    float B[16][3];
    memcpy(B, P, sizeof B);
    const PvOut none = {0};
    (void)pv, (void)n_pv; /* the patch file has none */
    if (rib_emit_bicubic(tt->r, B, &none) != 0) {
        tt->failed = 1;
        return RAYES_ERROR_INVALID_ARGUMENT;
    }
    return RAYES_OK;
}

static const char *teapot_error(void *t)
{
    return ((TeapotTarget *)t)->r->err;
}

static int h_geometry(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a geometry name");
    if (!name)
        return -1;
    int light = rib_ris_geometry_light(r, name);
    if (light != 0)
        return light < 0 ? -1 : 0;
    if (strcmp(name, "teapot") != 0) {
        char key[128];
        snprintf(key, sizeof key, "geometry %s", name);
        rib_warn_once(r, key, "Geometry \"%s\" is not supported and skipped", name);
        return 0;
    }
    if (!r->opt || !r->opt->data_dir) {
        rib_warn_once(r, "teapot", "Geometry \"teapot\" needs the data directory (teapot.bpt); skipped");
        return 0;
    }
    char path[4096], err[512];
    snprintf(path, sizeof path, "%s/teapot.bpt", r->opt->data_dir);
    TeapotTarget tt = {r, 0};
    IoSink s = *r->sink;
    s.target = &tt;
    s.bicubic_patch = teapot_patch;
    s.get_error = teapot_error;
    RayesError e = io_read_bpt(path, &s, err, sizeof err);
    if (e != RAYES_OK && !tt.failed)
        return rib_error(r, "%s", err);
    return e == RAYES_OK ? 0 : -1;
}


/* ------------------------------------------------------------ requests */

const RibRequest rib_prim_requests[] = {
    {"Polygon", h_polygon},
    {"GeneralPolygon", h_general_polygon},
    {"PointsPolygons", h_points_polygons},
    {"PointsGeneralPolygons", h_points_general_polygons},
    {"Patch", h_patch},
    {"PatchMesh", h_patch_mesh},
    {"Sphere", h_quadric},
    {"Cylinder", h_quadric},
    {"Cone", h_quadric},
    {"Disk", h_quadric},
    {"Torus", h_quadric},
    {"Hyperboloid", h_quadric},
    {"Paraboloid", h_quadric},
    {"Geometry", h_geometry},
    {"Volume", h_volume},
    {"SubdivisionMesh", h_subdivision_mesh},
    {"HierarchicalSubdivisionMesh", h_hierarchical_subdivision_mesh},
    {NULL, NULL},
};
