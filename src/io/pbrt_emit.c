/*
 * io/pbrt_emit.c — how the pbrt reader's geometry and lights reach the
 * sink (pbrt_internal.h). Outside ObjectBegin ... ObjectEnd a primitive is
 * sent at once: the current transform, the material when it differs from
 * the last one sent, then the primitive. Inside, it is recorded instead as
 * an Op owning copies of its arrays, its transform and its material, and
 * ObjectInstance replays the Ops under the instance's transform (at most
 * PBRT_MAX_REPLAYED primitives in all, so a small file cannot make a huge
 * scene). Lights are never recorded. pbrt's uv become rayes' st with
 * t = 1 - v.
 */
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "rayes/shader.h"

#define PBRT_MAX_REPLAYED 10000000L /* primitives emitted by ObjectInstance, in all */

int pbrt_sink_failed(Parser *P, const Token *t, RayesError e)
{
    const char *msg = P->sink->get_error ? P->sink->get_error(P->sink->target) : "";
    FAIL_TOK(P, t, "%s", msg && msg[0] ? msg : rayes_error_string(e));
    return -1;
}

static void material_params(const Parser *P, const Material *m, RayesParam out[MAT_MAX_PARAMS])
{
    for (int i = 0; i < m->n; i++) {
        out[i] = (RayesParam){.name = m->p[i].name, .type = m->p[i].type};
        memcpy(out[i].value, m->p[i].v, sizeof out[i].value);
        if (m->p[i].type == RAYES_PARAM_PATTERN)
            out[i].string = P->textures[m->p[i].tex].pattern;
        if (m->p[i].type == RAYES_PARAM_STRING) /* a mix's classes */
            out[i].string = m->p[i].s;
    }
}

/* The displacement of mat (the built-in "displace" of its amount), or
 * none when the last material sent had one and this has not. */
static RayesError send_displacement(Parser *P, const Material *mat)
{
    if (!mat->displaced)
        return P->have_sent && P->sent.displaced
                   ? P->sink->set_displacement(P->sink->target, "", NULL, 0)
                   : RAYES_OK;
    /* pbrt-v4's material displacement is a bump map: the shading normal
     * of the surface displaced along N, the surface where it is; a
     * plymesh's (3) moves the surface */
    RayesParam p[2] = {
        {.name = "amount", .type = RAYES_PARAM_FLOAT, .value = {mat->displacement_v, 0, 0}},
        {.name = "__bump", .type = RAYES_PARAM_FLOAT, .value = {1, 0, 0}}};
    if (mat->displaced == 2 || mat->displaced == 3)
        p[0] = (RayesParam){.name = "amount",
                            .type = RAYES_PARAM_PATTERN,
                            .string = P->textures[mat->displacement_tex].pattern};
    return P->sink->set_displacement(P->sink->target, "displace", p, mat->displaced <= 2 ? 2 : 1);
}

/* Sends m as the sink's transform; 0, or -1 when it is not finite or the
 * sink fails. */
static int send_transform(Parser *P, const Token *t, const double m[16])
{
    float f[2][16];
    if (!pbrt_mat_finite(m))
        return FAIL_TOK(P, t, "the current transform is not finite");
    pbrt_mat_to_float(m, f[0]);
    /* The current transform moves when its end-time matrix differs
     * (ActiveTransform EndTime), over TransformTimes. */
    int moving = m == P->gs.ctm && memcmp(P->gs.ctm, P->gs.ctm_end, sizeof P->gs.ctm) != 0;
    RayesError e;
    if (moving && P->sink->set_transform_motion) {
        if (!pbrt_mat_finite(P->gs.ctm_end))
            return FAIL_TOK(P, t, "the current end-time transform is not finite");
        pbrt_mat_to_float(P->gs.ctm_end, f[1]);
        float times[2] = {(float)P->transform_times[0], (float)P->transform_times[1]};
        e = P->sink->set_transform_motion(P->sink->target, 2, times, (const float(*)[16])f);
    } else {
        if (moving)
            pbrt_warn_at(P, t->line, t->col, "motion",
                         "this sink has no motion blur: the start-time transform is used");
        e = P->sink->set_transform(P->sink->target, f[0]);
    }
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

int pbrt_emit_pattern(Parser *P, const Token *t, const char *name, const char *type,
                      const RayesParam *params, size_t n)
{
    return pbrt_emit_pattern_in(P, t, P->gs.ctm, name, type, params, n);
}

int pbrt_emit_pattern_in(Parser *P, const Token *t, const double m[16], const char *name,
                         const char *type, const RayesParam *params, size_t n)
{
    if (send_transform(P, t, m) != 0)
        return -1;
    RayesError e = P->sink->pattern(P->sink->target, name, type, params, n);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

int pbrt_emit_volume(Parser *P, const Token *t, const double m[16], const RayesParam *params,
                     size_t n, const float bound[6], int inside)
{
    if (send_transform(P, t, m) != 0)
        return -1;
    P->have_sent = 0; /* the shader changes under the material last sent */
    RayesError e = P->sink->set_shader(P->sink->target, "homogeneous", params, n);
    if (e == RAYES_OK)
        e = inside && P->sink->volume_inside ? P->sink->volume_inside(P->sink->target, bound)
                                             : P->sink->volume(P->sink->target, bound);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

/* Grows the Shape's bounds by n points (object space). */
void pbrt_grow_bound(Parser *P, const float *pts, size_t n)
{
    float *b = P->shape_bound;
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++) {
            float v = pts[3 * i + k];
            if (!P->have_shape_bound || v < b[2 * k])
                b[2 * k] = v;
            if (!P->have_shape_bound || v > b[2 * k + 1])
                b[2 * k + 1] = v;
            if (k == 2)
                P->have_shape_bound = 1;
        }
}

/* The corners of a quadric's bounds (pbrt's sphere, cylinder, disk, and
 * the annulus: a flat hyperboloid from the rim). */
void pbrt_grow_quadric(Parser *P, RayesQuadric q, const float *qp)
{
    int flat = q == RAYES_QUADRIC_DISK || q == RAYES_QUADRIC_HYPERBOLOID;
    float r = q == RAYES_QUADRIC_DISK ? qp[1] : qp[0];
    float h = q == RAYES_QUADRIC_DISK ? qp[0] : qp[2];
    float z0 = flat ? h : qp[1], z1 = flat ? h : qp[2];
    const float c[6] = {-r, -r, z0, r, r, z1};
    pbrt_grow_bound(P, c, 2);
}

/* Every object's visibility but a hidden bound's: rayes's default, since
 * pbrt has none of its own. */
#define PBRT_SEEN (RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE | RAYES_RAY_SPECULAR | RAYES_RAY_SHADOW)

/* An "interface" shape (no surface) is sent only when it bounds a medium of
 * its own (P->shape_bounds), and then as an object no ray sees (a plain matte, which never
 * shades): 1 to skip it. */
static int skip_interface(Parser *P)
{
    return strcmp(P->gs.material.shader, PBRT_INVISIBLE) == 0 && !P->shape_bounds;
}

int pbrt_shown_again(Parser *P, const Token *t)
{
    if (!P->shape_hidden)
        return 0;
    RayesError e = P->sink->set_visibility(P->sink->target, PBRT_SEEN);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

static int send_material(Parser *P, const Token *t, const Material *mat)
{
    if (P->have_sent && memcmp(&P->sent, mat, sizeof *mat) == 0)
        return 0;
    RayesParam params[MAT_MAX_PARAMS];
    material_params(P, mat, params);
    RayesError e = P->sink->set_shader(P->sink->target, mat->shader, params, (size_t)mat->n);
    if (e == RAYES_OK)
        e = send_displacement(P, mat);
    if (e != RAYES_OK)
        return pbrt_sink_failed(P, t, e);
    P->sent = *mat;
    P->have_sent = 1;
    return 0;
}

/* The transform and material of a shape about to be sent; an interface
 * one's object is seen by no ray (pbrt_shown_again turns visibility back). */
static int send_state(Parser *P, const Token *t, const double m[16], const Material *mat)
{
    if (send_transform(P, t, m) != 0)
        return -1;
    if (strcmp(mat->shader, PBRT_INVISIBLE) != 0)
        return send_material(P, t, mat);
    if (P->shape_hidden)
        return 0; /* the shape's next piece (a bilinear mesh's patch): the same object */
    RayesError e = P->sink->set_visibility(P->sink->target, 0);
    if (e == RAYES_OK)
        e = P->sink->set_shader(P->sink->target, "matte", NULL, 0);
    if (e != RAYES_OK)
        return pbrt_sink_failed(P, t, e);
    P->have_sent = 0;
    P->shape_hidden = 1;
    return 0;
}

static Op *new_op(Parser *P, const Token *t, OpKind kind)
{
    Object *o = P->recording;
    if (o->n_ops == o->cap_ops) {
        size_t cap = o->cap_ops ? 2 * o->cap_ops : 8;
        Op *n = realloc(o->ops, cap * sizeof *n);
        if (!n) {
            FAIL_TOK(P, t, "out of memory");
            return NULL;
        }
        o->ops = n;
        o->cap_ops = cap;
    }
    Op *op = &o->ops[o->n_ops];
    memset(op, 0, sizeof *op);
    op->mat = malloc(sizeof *op->mat);
    if (!op->mat) {
        FAIL_TOK(P, t, "out of memory");
        return NULL;
    }
    o->n_ops++;
    op->kind = kind;
    memcpy(op->m, P->gs.ctm, sizeof op->m);
    *op->mat = P->gs.material;
    return op;
}

/* Vertex-class primitive variables N and st from pbrt's per-point N and
 * uv (either may be NULL): st = (u, 1 - v), since pbrt's image textures
 * put v = 0 at the bottom and rayes' t = 0 is the top row. st_store
 * (2 * n floats) holds the converted values. Returns the count. */
static size_t mesh_primvars(size_t n, const float *N, const float *uv, float *st_store,
                            RayesPrimvar pv[2])
{
    size_t k = 0;
    if (N)
        pv[k++] = (RayesPrimvar){"N", RAYES_PRIMVAR_VERTEX, N, n};
    if (uv && st_store) {
        for (size_t i = 0; i < n; i++)
            st_store[2 * i] = uv[2 * i], st_store[2 * i + 1] = 1.0f - uv[2 * i + 1];
        pv[k++] = (RayesPrimvar){"st", RAYES_PRIMVAR_VERTEX, st_store, n};
    }
    return k;
}

static float *copy_floats(const float *f, size_t n)
{
    float *c = f ? malloc((n ? n : 1) * sizeof *c) : NULL;
    if (c)
        memcpy(c, f, n * sizeof *c);
    return c;
}

/* Sends a mesh (or a Loop subdivision surface, subdiv) with N and uv per
 * point (NULL: none). */
static RayesError send_mesh(Parser *P, size_t n_faces, const int *n_verts, const int *idx,
                            size_t n_points, const float *pts, const float *N, const float *uv,
                            int subdiv)
{
    RayesPrimvar pv[2];
    float *st = uv ? malloc((2 * n_points + 1) * sizeof *st) : NULL;
    if (uv && !st)
        return RAYES_ERROR_OUT_OF_MEMORY;
    size_t n_pv = mesh_primvars(n_points, N, uv, st, pv);
    /* pbrt's Loop surfaces interpolate their boundaries. */
    static const RayesSubdivTags tags = {.interpolate_boundary = 1, .facevarying_boundary = 1};
    RayesError e = !subdiv ? P->sink->polygon_mesh(P->sink->target, n_faces, n_verts, idx, n_points,
                                                   pts, pv, n_pv)
                   : P->sink->subdivision_mesh
                       ? P->sink->subdivision_mesh(P->sink->target, RAYES_SUBDIV_LOOP, n_faces,
                                                   n_verts, idx, n_points, pts, &tags, pv, n_pv)
                       : RAYES_ERROR_INVALID_ARGUMENT;
    free(st);
    return e;
}

static int emit_mesh(Parser *P, const Token *t, size_t n_faces, const int *n_verts, const int *idx,
                     size_t n_points, const float *pts, const float *N, const float *uv, int subdiv)
{
    pbrt_grow_bound(P, pts, n_points);
    if (n_faces == 0 || skip_interface(P))
        return 0;
    if (P->recording) {
        Op *op = new_op(P, t, OP_MESH);
        if (!op)
            return -1;
        size_t n_idx = 0;
        for (size_t f = 0; f < n_faces; f++)
            n_idx += (size_t)n_verts[f];
        op->n_faces = n_faces;
        op->n_points = n_points;
        op->n_verts = malloc(n_faces * sizeof(int));
        op->idx = malloc(n_idx * sizeof(int));
        op->pts = malloc(n_points * 3 * sizeof(float));
        op->N = copy_floats(N, 3 * n_points);
        op->uv = copy_floats(uv, 2 * n_points);
        if (!op->n_verts || !op->idx || !op->pts || (N && !op->N) || (uv && !op->uv))
            return FAIL_TOK(P, t, "out of memory");
        memcpy(op->n_verts, n_verts, n_faces * sizeof(int));
        memcpy(op->idx, idx, n_idx * sizeof(int));
        memcpy(op->pts, pts, n_points * 3 * sizeof(float));
        op->subdiv = subdiv;
        return 0;
    }
    if (send_state(P, t, P->gs.ctm, &P->gs.material) != 0)
        return -1;
    RayesError e = send_mesh(P, n_faces, n_verts, idx, n_points, pts, N, uv, subdiv);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

int pbrt_emit_mesh(Parser *P, const Token *t, size_t n_faces, const int *n_verts, const int *idx,
                   size_t n_points, const float *pts, const float *N, const float *uv)
{
    return emit_mesh(P, t, n_faces, n_verts, idx, n_points, pts, N, uv, 0);
}

int pbrt_emit_subdiv(Parser *P, const Token *t, size_t n_faces, const int *n_verts, const int *idx,
                     size_t n_points, const float *pts, const float *uv)
{
    return emit_mesh(P, t, n_faces, n_verts, idx, n_points, pts, NULL, uv, 1);
}

/* Records curves c with their primitive variables (at most 2: "width",
 * one float a value, and "N", three) as an Op of the object being defined. */
static int record_curves(Parser *P, const Token *t, const RayesCurves *c, const RayesPrimvar *pv,
                         size_t n_pv)
{
    size_t n_points = 0, n_varying = 0;
    if (rayes_curves_counts(c, &n_points, &n_varying) != 0 || n_pv > 2)
        return FAIL_TOK(P, t, "curve: not a whole number of segments");
    Op *op = new_op(P, t, OP_CURVES);
    if (!op)
        return -1;
    op->curves = *c;
    op->n_points = n_points;
    op->n_verts = malloc((c->n_curves ? c->n_curves : 1) * sizeof(int));
    op->pts = copy_floats(c->P, 3 * n_points);
    if (!op->n_verts || !op->pts)
        return FAIL_TOK(P, t, "out of memory");
    memcpy(op->n_verts, c->n_verts, c->n_curves * sizeof(int));
    op->curves.n_verts = op->n_verts;
    op->curves.P = op->pts;
    for (size_t i = 0; i < n_pv; i++) {
        size_t size = strcmp(pv[i].name, "width") == 0 ? 1 : 3;
        float *data = copy_floats(pv[i].data, size * pv[i].count);
        if (!data)
            return FAIL_TOK(P, t, "out of memory");
        op->curve_pv[i] = pv[i];
        op->curve_pv[i].data = data;
        op->n_curve_pv = i + 1;
    }
    return 0;
}

int pbrt_emit_curves(Parser *P, const Token *t, const RayesCurves *c, const RayesPrimvar *pv,
                     size_t n_pv)
{
    if (strcmp(P->gs.material.shader, PBRT_INVISIBLE) == 0)
        return 0;
    if (!P->sink->curves)
        return FAIL_TOK(P, t, "curve: this sink takes no curves");
    if (P->recording)
        return record_curves(P, t, c, pv, n_pv);
    if (send_state(P, t, P->gs.ctm, &P->gs.material) != 0)
        return -1;
    RayesError e = P->sink->curves(P->sink->target, c, pv, n_pv);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

int pbrt_emit_quadric(Parser *P, const Token *t, RayesQuadric q, const float *qp, size_t n,
                      unsigned flags)
{
    if (q == RAYES_QUADRIC_SPHERE || q == RAYES_QUADRIC_CYLINDER || q == RAYES_QUADRIC_DISK ||
        q == RAYES_QUADRIC_HYPERBOLOID)
        pbrt_grow_quadric(P, q, qp);
    if (skip_interface(P))
        return 0;
    if (P->recording) {
        Op *op = new_op(P, t, OP_QUADRIC);
        if (!op)
            return -1;
        op->q = q;
        memcpy(op->qp, qp, n * sizeof *qp);
        op->n_qp = n;
        op->flags = flags;
        return 0;
    }
    if (send_state(P, t, P->gs.ctm, &P->gs.material) != 0)
        return -1;
    RayesError e = P->sink->quadric(P->sink->target, q, qp, n, flags);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

/* Sends a bilinear patch with N and uv at its corners (by op's patch_pv). */
static RayesError send_patch(Parser *P, const Op *op)
{
    RayesPrimvar pv[2];
    float st[4][2];
    size_t n_pv = mesh_primvars(4, (op->patch_pv & 1) ? &op->patch_N[0][0] : NULL,
                                (op->patch_pv & 2) ? &op->patch_uv[0][0] : NULL, &st[0][0], pv);
    return P->sink->bilinear_patch(P->sink->target, op->patch, pv, n_pv);
}

int pbrt_emit_patch(Parser *P, const Token *t, const Op *patch)
{
    pbrt_grow_bound(P, &patch->patch[0][0], 4);
    if (skip_interface(P))
        return 0;
    if (P->recording) {
        Op *op = new_op(P, t, OP_PATCH);
        if (!op)
            return -1;
        memcpy(op->patch, patch->patch, sizeof op->patch);
        op->patch_pv = patch->patch_pv;
        memcpy(op->patch_N, patch->patch_N, sizeof op->patch_N);
        memcpy(op->patch_uv, patch->patch_uv, sizeof op->patch_uv);
        return 0;
    }
    if (send_state(P, t, P->gs.ctm, &P->gs.material) != 0)
        return -1;
    RayesError e = send_patch(P, patch);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

int pbrt_emit_light(Parser *P, const Token *t, const double m[16], const char *type,
                    const RayesParam *params, size_t n)
{
    if (send_transform(P, t, m) != 0)
        return -1;
    RayesError e = P->sink->light(P->sink->target, type, params, n);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

/* Sends o's Ops, each under ctm times its own transform. */
static int send_ops(Parser *P, const Token *t, const Object *o, const double ctm[16])
{
    for (size_t i = 0; i < o->n_ops; i++) {
        const Op *op = &o->ops[i];
        double m[16];
        pbrt_mat_mul(ctm, op->m, m);
        if (send_state(P, t, m, op->mat) != 0)
            return -1;
        RayesError e = RAYES_OK;
        if (op->kind == OP_MESH)
            e = send_mesh(P, op->n_faces, op->n_verts, op->idx, op->n_points, op->pts, op->N,
                          op->uv, op->subdiv);
        else if (op->kind == OP_QUADRIC)
            e = P->sink->quadric(P->sink->target, op->q, op->qp, op->n_qp, op->flags);
        else if (op->kind == OP_CURVES)
            e = P->sink->curves(P->sink->target, &op->curves, op->curve_pv, op->n_curve_pv);
        else
            e = send_patch(P, op);
        if (e != RAYES_OK)
            return pbrt_sink_failed(P, t, e);
    }
    return 0;
}

/* A sink with instances: o is sent once as a master (its Ops under their
 * own transforms, which include the one current at their definition, as
 * in pbrt-v4), then placed with the current transform. */
static int send_instance(Parser *P, const Token *t, Object *o)
{
    const IoSink *s = P->sink;
    if (!o->sent) {
        static const double identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        if (s->object_begin(s->target, o->name) != RAYES_OK)
            return pbrt_sink_failed(P, t, RAYES_ERROR_INVALID_ARGUMENT);
        P->have_sent = 0; /* the block starts with no material: each Op sends its own */
        if (send_ops(P, t, o, identity) != 0)
            return -1;
        if (s->object_end(s->target) != RAYES_OK)
            return pbrt_sink_failed(P, t, RAYES_ERROR_INVALID_ARGUMENT);
        P->have_sent = 0; /* object_end restored the material before the block */
        o->sent = 1;
    }
    if (send_transform(P, t, P->gs.ctm) != 0)
        return -1;
    RayesError e = s->object_instance(s->target, o->name);
    return e != RAYES_OK ? pbrt_sink_failed(P, t, e) : 0;
}

void pbrt_object_free(Object *o)
{
    for (size_t k = 0; k < o->n_ops; k++) {
        Op *op = &o->ops[k];
        free(op->mat);
        free(op->n_verts);
        free(op->idx);
        free(op->pts);
        free(op->N);
        free(op->uv);
        for (size_t i = 0; i < op->n_curve_pv; i++)
            free((float *)op->curve_pv[i].data);
    }
    free(o->ops);
    o->ops = NULL;
    o->n_ops = o->cap_ops = 0;
}

int pbrt_emit_bound(Parser *P, const Token *t, const Object *o)
{
    double identity[16];
    pbrt_mat_identity(identity);
    P->shape_hidden = 0; /* the first shape makes the hidden object, the rest join it */
    return send_ops(P, t, o, identity);
}

int pbrt_replay(Parser *P, const Token *t, Object *o)
{
    if (P->sink->object_begin && P->sink->object_end && P->sink->object_instance)
        return send_instance(P, t, o);
    P->replayed += (long)o->n_ops;
    if (P->replayed > PBRT_MAX_REPLAYED)
        return FAIL_TOK(P, t, "more than %ld instanced primitives", PBRT_MAX_REPLAYED);
    return send_ops(P, t, o, P->gs.ctm);
}
