/*
 * io/rib_record.c — the sink that records an object definition
 * (ObjectBegin ... ObjectEnd) for replay at each ObjectInstance
 * (rib_internal.h). Calls are kept as a list of RibCall with deep copies of
 * their arrays and strings; replay premultiplies transforms by the
 * instance's world_from_instance.
 */
#include <stdlib.h>
#include <string.h>

#include "io/rib_internal.h"

typedef enum CallKind {
    CALL_TRANSFORM,
    CALL_SHADER,
    CALL_DISPLACEMENT,
    CALL_DISPLACEMENT_BOUND,
    CALL_SHADING_RATE,
    CALL_VISIBILITY,   /* f[0]: the ray-type bits */
    CALL_OPACITY_MODE, /* f[0]: the hit mode, f[1]: cache */
    CALL_BILINEAR,
    CALL_BICUBIC,
    CALL_MESH,
    CALL_SPHERE,
    CALL_QUADRIC,
    CALL_AREA_LIGHT,
    CALL_SUBDIV,
    CALL_CURVES,
    CALL_POINTS,
    CALL_VOLUME
} CallKind;

typedef struct RibCall {
    CallKind kind;
    char *name;          /* shader name */
    RayesParam *params;  /* names and strings owned */
    size_t n_params;
    float *f;            /* floats: matrix, points, quadric params */
    size_t n_f;
    int *ints;           /* mesh: n_verts then indices */
    size_t n_faces, n_idx;
    unsigned flags;      /* quadric type << 8 | flags */
    RayesPrimvar *pv;    /* patches and meshes: primitive variables, names and data owned */
    size_t n_pv;
    /* Subdivision meshes: f holds P, then the crease and corner
     * sharpnesses; ints the faces' sizes, indices, crease edges, corner
     * points and holes; tags the counts (its pointers unset). */
    int scheme;
    size_t n_points;
    RayesSubdivTags tags;
    int has_tags;
    /* Curves: f holds the basis then P, ints the control point counts
     * (n_faces of them), curves the rest (its pointers unset). Points: f
     * holds P, flags the shape. */
    RayesCurves curves;
} RibCall;

struct RibRecording {
    RibCall *calls;
    size_t n, cap;
};

RibRecording *rib_recording_new(void)
{
    return calloc(1, sizeof(RibRecording));
}

static void call_fini(RibCall *c)
{
    free(c->name);
    for (size_t i = 0; i < c->n_params; i++) {
        free((char *)c->params[i].name);
        free((char *)c->params[i].string);
        free((float *)c->params[i].floats);
    }
    free(c->params);
    free(c->f);
    free(c->ints);
    for (size_t i = 0; i < c->n_pv; i++) {
        free((char *)c->pv[i].name);
        free((float *)c->pv[i].data);
    }
    free(c->pv);
}

void rib_recording_free(RibRecording *rec)
{
    if (!rec)
        return;
    for (size_t i = 0; i < rec->n; i++)
        call_fini(&rec->calls[i]);
    free(rec->calls);
    free(rec);
}

static RibCall *push(RibRecording *rec, CallKind kind)
{
    if (rec->n == rec->cap) {
        size_t cap = rec->cap ? 2 * rec->cap : 16;
        RibCall *c = realloc(rec->calls, cap * sizeof *c);
        if (!c)
            return NULL;
        rec->calls = c;
        rec->cap = cap;
    }
    RibCall *c = &rec->calls[rec->n++];
    memset(c, 0, sizeof *c);
    c->kind = kind;
    return c;
}

static char *dup_str(const char *s)
{
    if (!s)
        return NULL;
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

static RayesError floats(RibRecording *rec, CallKind kind, const float *f, size_t n)
{
    RibCall *c = push(rec, kind);
    if (!c)
        return RAYES_ERROR_OUT_OF_MEMORY;
    c->f = malloc((n ? n : 1) * sizeof *f);
    if (!c->f) {
        rec->n--;
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    if (n)
        memcpy(c->f, f, n * sizeof *f);
    c->n_f = n;
    return RAYES_OK;
}

static RayesError named(RibRecording *rec, CallKind kind, const char *name, const RayesParam *p,
                        size_t n)
{
    RibCall *c = push(rec, kind);
    if (!c)
        return RAYES_ERROR_OUT_OF_MEMORY;
    c->name = dup_str(name ? name : "");
    c->params = calloc(n ? n : 1, sizeof *c->params);
    if (!c->name || !c->params)
        return RAYES_ERROR_OUT_OF_MEMORY; /* the call stays, freed with the recording */
    for (size_t i = 0; i < n; i++) {
        c->params[i] = p[i];
        c->params[i].name = dup_str(p[i].name);
        c->params[i].string = dup_str(p[i].string);
        c->params[i].floats = NULL;
        if (p[i].type == RAYES_PARAM_FLOATS && p[i].n_floats) { /* a pattern's data */
            float *v = malloc(p[i].n_floats * sizeof *v);
            if (!v)
                return RAYES_ERROR_OUT_OF_MEMORY;
            memcpy(v, p[i].floats, p[i].n_floats * sizeof *v);
            c->params[i].floats = v;
        }
        c->n_params++;
    }
    return RAYES_OK;
}

static RayesError rec_camera(void *t, const float *e, const float *a, const float *u, float f)
{
    (void)t, (void)e, (void)a, (void)u, (void)f;
    return RAYES_OK;
}
static RayesError rec_camera_matrix(void *t, const float m[16], RayesProjection p, float f,
                                    const float s[4])
{
    (void)t, (void)m, (void)p, (void)f, (void)s;
    return RAYES_OK;
}
static RayesError rec_transform(void *t, const float m[16])
{
    return floats(t, CALL_TRANSFORM, m, 16);
}
static RayesError rec_shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    return named(t, CALL_SHADER, name, p, n);
}
static RayesError rec_displacement(void *t, const char *name, const RayesParam *p, size_t n)
{
    return named(t, CALL_DISPLACEMENT, name, p, n);
}
static RayesError rec_bound(void *t, float b)
{
    return floats(t, CALL_DISPLACEMENT_BOUND, &b, 1);
}
static RayesError rec_search_path(void *t, const char *kind, const char *path)
{
    (void)t, (void)kind, (void)path;
    return RAYES_OK;
}
static RayesError rec_rate(void *t, float r)
{
    return floats(t, CALL_SHADING_RATE, &r, 1);
}
static RayesError rec_visibility(void *t, uint32_t ray_types)
{
    float f = (float)ray_types; /* a few low bits: exact */
    return floats(t, CALL_VISIBILITY, &f, 1);
}
static RayesError rec_opacity_mode(void *t, RayesTransmissionHitMode mode, int cache)
{
    float f[2] = {(float)mode, (float)cache};
    return floats(t, CALL_OPACITY_MODE, f, 2);
}
/* Copies primitive variables into the last call (names and data). */
static RayesError keep_primvars(RibRecording *rec, RayesError e, const RayesPrimvar *pv,
                                size_t n_pv)
{
    if (e != RAYES_OK || n_pv == 0)
        return e;
    RibCall *c = &rec->calls[rec->n - 1];
    c->pv = calloc(n_pv, sizeof *c->pv);
    if (!c->pv)
        return RAYES_ERROR_OUT_OF_MEMORY;
    for (size_t i = 0; i < n_pv; i++) {
        size_t n = pv[i].count * (strcmp(pv[i].name, "st") == 0      ? 2u
                                  : strcmp(pv[i].name, "width") == 0 ? 1u
                                                                     : 3u);
        float *d = malloc((n ? n : 1) * sizeof *d);
        c->pv[i] = pv[i];
        c->pv[i].name = dup_str(pv[i].name);
        c->pv[i].data = d;
        c->n_pv++;
        if (!d || !c->pv[i].name)
            return RAYES_ERROR_OUT_OF_MEMORY; /* the call stays, freed with the recording */
        memcpy(d, pv[i].data, n * sizeof *d);
    }
    return RAYES_OK;
}
static RayesError rec_bilinear(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n_pv)
{
    return keep_primvars(t, floats(t, CALL_BILINEAR, &P[0][0], 12), pv, n_pv);
}
static RayesError rec_bicubic(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n_pv)
{
    return keep_primvars(t, floats(t, CALL_BICUBIC, &P[0][0], 48), pv, n_pv);
}
static RayesError rec_mesh(void *t, size_t n_faces, const int *nv, const int *idx, size_t n_points,
                           const float *P, const RayesPrimvar *pv, size_t n_pv)
{
    RibRecording *rec = t;
    size_t n_idx = 0;
    for (size_t i = 0; i < n_faces; i++)
        n_idx += (size_t)nv[i];
    RayesError e = keep_primvars(rec, floats(rec, CALL_MESH, P, 3 * n_points), pv, n_pv);
    if (e != RAYES_OK)
        return e;
    RibCall *c = &rec->calls[rec->n - 1];
    c->ints = malloc((n_faces + n_idx + 1) * sizeof *c->ints);
    if (!c->ints)
        return RAYES_ERROR_OUT_OF_MEMORY;
    memcpy(c->ints, nv, n_faces * sizeof *nv);
    memcpy(c->ints + n_faces, idx, n_idx * sizeof *idx);
    c->n_faces = n_faces;
    c->n_idx = n_idx;
    return RAYES_OK;
}
static RayesError rec_subdivision_mesh(void *t, RayesSubdivScheme scheme, size_t n_faces,
                                       const int *nv, const int *idx, size_t n_points,
                                       const float *P, const RayesSubdivTags *tags,
                                       const RayesPrimvar *pv, size_t n_pv)
{
    RibRecording *rec = t;
    RayesSubdivTags none = {0};
    const RayesSubdivTags *g = tags ? tags : &none;
    size_t n_idx = 0;
    for (size_t i = 0; i < n_faces; i++)
        n_idx += (size_t)nv[i];
    size_t n_f = 3 * n_points + g->n_creases + g->n_corners;
    float *f = malloc((n_f + 1) * sizeof *f);
    if (!f)
        return RAYES_ERROR_OUT_OF_MEMORY;
    memcpy(f, P, 3 * n_points * sizeof *f);
    if (g->n_creases)
        memcpy(f + 3 * n_points, g->crease_sharpness, g->n_creases * sizeof *f);
    if (g->n_corners)
        memcpy(f + 3 * n_points + g->n_creases, g->corner_sharpness, g->n_corners * sizeof *f);
    RayesError e = keep_primvars(rec, floats(rec, CALL_SUBDIV, f, n_f), pv, n_pv);
    free(f);
    if (e != RAYES_OK)
        return e;
    RibCall *c = &rec->calls[rec->n - 1];
    size_t n_ints = n_faces + n_idx + 2 * g->n_creases + g->n_corners + g->n_holes;
    c->ints = malloc((n_ints + 1) * sizeof *c->ints);
    if (!c->ints)
        return RAYES_ERROR_OUT_OF_MEMORY;
    int *at = c->ints;
    memcpy(at, nv, n_faces * sizeof *nv), at += n_faces;
    memcpy(at, idx, n_idx * sizeof *idx), at += n_idx;
    if (g->n_creases)
        memcpy(at, g->crease_edges, 2 * g->n_creases * sizeof *at), at += 2 * g->n_creases;
    if (g->n_corners)
        memcpy(at, g->corner_points, g->n_corners * sizeof *at), at += g->n_corners;
    if (g->n_holes)
        memcpy(at, g->hole_faces, g->n_holes * sizeof *at);
    c->n_faces = n_faces, c->n_idx = n_idx, c->n_points = n_points, c->scheme = (int)scheme;
    c->tags = *g, c->has_tags = tags != NULL;
    return RAYES_OK;
}
static RayesError rec_curves(void *t, const RayesCurves *curves, const RayesPrimvar *pv,
                             size_t n_pv)
{
    RibRecording *rec = t;
    size_t n_points, n_varying;
    if (rayes_curves_counts(curves, &n_points, &n_varying) != 0)
        return RAYES_ERROR_INVALID_ARGUMENT;
    float *f = malloc((16 + 3 * n_points) * sizeof *f);
    if (!f)
        return RAYES_ERROR_OUT_OF_MEMORY;
    memcpy(f, curves->basis, 16 * sizeof *f);
    if (n_points)
        memcpy(f + 16, curves->P, 3 * n_points * sizeof *f);
    RayesError e = keep_primvars(rec, floats(rec, CALL_CURVES, f, 16 + 3 * n_points), pv, n_pv);
    free(f);
    if (e != RAYES_OK)
        return e;
    RibCall *c = &rec->calls[rec->n - 1];
    c->ints = malloc((curves->n_curves + 1) * sizeof *c->ints);
    if (!c->ints)
        return RAYES_ERROR_OUT_OF_MEMORY;
    if (curves->n_curves)
        memcpy(c->ints, curves->n_verts, curves->n_curves * sizeof *c->ints);
    c->n_faces = curves->n_curves;
    c->curves = *curves;
    return RAYES_OK;
}
static RayesError rec_points(void *t, RayesPointShape shape, size_t n, const float *P,
                             const RayesPrimvar *pv, size_t n_pv)
{
    RibRecording *rec = t;
    RayesError e = keep_primvars(rec, floats(rec, CALL_POINTS, P, 3 * n), pv, n_pv);
    if (e == RAYES_OK)
        rec->calls[rec->n - 1].flags = (unsigned)shape;
    return e;
}
static RayesError rec_sphere(void *t, float r)
{
    return floats(t, CALL_SPHERE, &r, 1);
}
static RayesError rec_quadric(void *t, RayesQuadric type, const float *p, size_t n, unsigned flags)
{
    RibRecording *rec = t;
    RayesError e = floats(rec, CALL_QUADRIC, p, n);
    if (e == RAYES_OK)
        rec->calls[rec->n - 1].flags = (unsigned)type << 8 | (flags & 0xff);
    return e;
}
static RayesError rec_volume(void *t, const float bound[6])
{
    return floats(t, CALL_VOLUME, bound, 6);
}
static RayesError rec_area_light(void *t, const float P[4][3], const float L[3])
{
    float f[15];
    memcpy(f, &P[0][0], 12 * sizeof *f);
    memcpy(f + 12, L, 3 * sizeof *f);
    return floats(t, CALL_AREA_LIGHT, f, 15);
}
static RayesError rec_light(void *t, const char *type, const RayesParam *p, size_t n)
{
    (void)t, (void)type, (void)p, (void)n;
    return RAYES_OK;
}
/* The reader sends light links and lights to the real sink only, before
 * an instance is replayed (its objects take the links in force there). */
static RayesError rec_light_links(void *t, RayesLightLinks mode, const size_t *l, size_t n)
{
    (void)t, (void)mode, (void)l, (void)n;
    return RAYES_OK;
}
static size_t rec_light_count(void *t)
{
    (void)t;
    return 0;
}
static const char *rec_error(void *t)
{
    (void)t;
    return "out of memory while recording an object";
}

IoSink rib_recording_sink(RibRecording *rec)
{
    IoSink s = {rec,           rec_camera,   rec_camera_matrix, rec_transform,  rec_shader,
                rec_displacement, rec_bound, rec_search_path,  rec_rate,       rec_bilinear,
                rec_bicubic,   rec_mesh,     rec_sphere,        rec_quadric,    rec_area_light,
                rec_light,     rec_light_links, rec_light_count, rec_error};
    s.subdivision_mesh = rec_subdivision_mesh;
    s.curves = rec_curves;
    s.points = rec_points;
    s.volume = rec_volume;
    s.set_visibility = rec_visibility;
    s.set_opacity_mode = rec_opacity_mode;
    return s;
}

RayesError rib_recording_replay(const RibRecording *rec, const IoSink *out,
                                const float world_from_instance[16])
{
    void *t = out->target;
    RayesError e = RAYES_OK;
    int placed = 0;
    for (size_t i = 0; i < rec->n && e == RAYES_OK; i++) {
        const RibCall *c = &rec->calls[i];
        if (!placed && c->kind != CALL_TRANSFORM && c->kind >= CALL_BILINEAR) {
            /* geometry before any transform: the instance's own */
            e = out->set_transform(t, world_from_instance);
            placed = 1;
            if (e != RAYES_OK)
                break;
        }
        switch (c->kind) {
        case CALL_TRANSFORM: {
            float m[16];
            rib_mat_mul(world_from_instance, c->f, m);
            e = out->set_transform(t, m);
            placed = 1;
            break;
        }
        case CALL_SHADER: e = out->set_shader(t, c->name, c->params, c->n_params); break;
        case CALL_DISPLACEMENT: e = out->set_displacement(t, c->name, c->params, c->n_params); break;
        case CALL_DISPLACEMENT_BOUND: e = out->set_displacement_bound(t, c->f[0]); break;
        case CALL_SHADING_RATE: e = out->set_shading_rate(t, c->f[0]); break;
        case CALL_VISIBILITY:
            e = out->set_visibility ? out->set_visibility(t, (uint32_t)c->f[0]) : RAYES_OK;
            break;
        case CALL_OPACITY_MODE:
            e = out->set_opacity_mode
                    ? out->set_opacity_mode(t, (RayesTransmissionHitMode)c->f[0], (int)c->f[1])
                    : RAYES_OK;
            break;
        case CALL_BILINEAR:
            e = out->bilinear_patch(t, (const float(*)[3])c->f, c->pv, c->n_pv);
            break;
        case CALL_BICUBIC:
            e = out->bicubic_patch(t, (const float(*)[3])c->f, c->pv, c->n_pv);
            break;
        case CALL_MESH:
            e = out->polygon_mesh(t, c->n_faces, c->ints, c->ints + c->n_faces, c->n_f / 3, c->f,
                                  c->pv, c->n_pv);
            break;
        case CALL_SPHERE: e = out->sphere(t, c->f[0]); break;
        case CALL_QUADRIC:
            e = out->quadric(t, (RayesQuadric)(c->flags >> 8), c->f, c->n_f, c->flags & 0xff);
            break;
        case CALL_AREA_LIGHT: e = out->area_light(t, (const float(*)[3])c->f, c->f + 12); break;
        case CALL_VOLUME:
            e = out->volume ? out->volume(t, c->f) : RAYES_OK; /* the reader warned */
            break;
        case CALL_SUBDIV: {
            RayesSubdivTags g = c->tags;
            const int *at = c->ints + c->n_faces + c->n_idx;
            g.crease_edges = at, at += 2 * g.n_creases;
            g.corner_points = at, at += g.n_corners;
            g.hole_faces = at;
            g.crease_sharpness = c->f + 3 * c->n_points;
            g.corner_sharpness = c->f + 3 * c->n_points + g.n_creases;
            e = out->subdivision_mesh
                    ? out->subdivision_mesh(t, (RayesSubdivScheme)c->scheme, c->n_faces, c->ints,
                                            c->ints + c->n_faces, c->n_points, c->f,
                                            c->has_tags ? &g : NULL, c->pv, c->n_pv)
                    : RAYES_ERROR_INVALID_ARGUMENT;
            break;
        }
        case CALL_CURVES: {
            RayesCurves cv = c->curves;
            memcpy(cv.basis, c->f, sizeof cv.basis);
            cv.P = c->f + 16;
            cv.n_verts = c->ints;
            e = out->curves ? out->curves(t, &cv, c->pv, c->n_pv) : RAYES_ERROR_INVALID_ARGUMENT;
            break;
        }
        case CALL_POINTS:
            e = out->points ? out->points(t, (RayesPointShape)c->flags, c->n_f / 3, c->f, c->pv,
                                          c->n_pv)
                            : RAYES_ERROR_INVALID_ARGUMENT;
            break;
        }
    }
    return e;
}
