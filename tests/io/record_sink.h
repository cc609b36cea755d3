/*
 * tests/io/record_sink.h — a recording IoSink for the reader and writer
 * tests: every call is kept (meshes, shaders with their parameters, lights,
 * the camera), so a test can check what a reader said. Header-only; one
 * Record per test, reset with record_free.
 */
#ifndef RAYES_TESTS_IO_RECORD_SINK_H
#define RAYES_TESTS_IO_RECORD_SINK_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib.h"
#include "io/sink.h"

#define REC_MAX 64

/* Primitive variables of one call, copied. */
typedef struct RecPrimvars {
    RayesPrimvar pv[3];       /* data owned */
    char name[3][8];
    size_t n;
} RecPrimvars;

typedef struct RecMesh {
    size_t n_faces, n_points;
    int *nv, *idx;
    float *P;
    int shader;               /* index of the shader in force, -1 none */
    RecPrimvars pv;
    int subdiv; /* 1: a subdivision mesh, of scheme and tags: */
    RayesSubdivScheme scheme;
    RayesSubdivTags tags; /* counts, and pointers into the arrays below */
    int has_tags;
    int tag_ints[64];     /* crease edges, corners, holes */
    float tag_floats[32]; /* crease, then corner sharpnesses */
} RecMesh;

typedef struct RecPatch {
    int cubic;
    float P[16][3];           /* 4 or 16 points */
    RecPrimvars pv;
} RecPatch;

typedef struct RecShader {
    char name[64];
    RayesParam p[8];
    char pname[8][32], pstring[8][1100];
    size_t n;
} RecShader;

typedef struct Record {
    int calls;                /* every call */
    int n_camera;
    float eye[3], at[3], up[3], fov;
    int n_transform;
    RecMesh mesh[REC_MAX];
    int n_mesh;
    RecPatch patch[REC_MAX];
    int n_patch;
    RecShader shader[REC_MAX];
    int n_shader;
    float area_P[REC_MAX][4][3], area_L[REC_MAX][3];
    int n_area;
    size_t mesh_light_faces[REC_MAX]; /* area_light_mesh: faces, radiance, sides */
    float mesh_light_L[REC_MAX][3];
    int mesh_light_two_sided[REC_MAX], n_mesh_light;
    char mesh_light_texture[REC_MAX][256]; /* "" untextured */
    float mesh_light_st0[REC_MAX][2];      /* the first point's (s, t) */
    RecShader light[REC_MAX]; /* type in name */
    int n_light;
    int links_mode;           /* the last set_light_links: RayesLightLinks */
    size_t links[REC_MAX], n_links;
} Record;

static RayesError rec_camera(void *t, const float eye[3], const float at[3], const float up[3],
                             float fov)
{
    Record *r = t;
    r->calls++;
    r->n_camera++;
    memcpy(r->eye, eye, sizeof r->eye);
    memcpy(r->at, at, sizeof r->at);
    memcpy(r->up, up, sizeof r->up);
    r->fov = fov;
    return RAYES_OK;
}

static RayesError rec_camera_matrix(void *t, const float m[16], RayesProjection p, float fov,
                                    const float s[4])
{
    (void)m, (void)p, (void)fov, (void)s;
    ((Record *)t)->calls++;
    ((Record *)t)->n_camera++;
    return RAYES_OK;
}

static RayesError rec_transform(void *t, const float m[16])
{
    (void)m;
    ((Record *)t)->calls++;
    ((Record *)t)->n_transform++;
    return RAYES_OK;
}

static void rec_copy_shader(RecShader *s, const char *name, const RayesParam *p, size_t n)
{
    snprintf(s->name, sizeof s->name, "%s", name ? name : "");
    s->n = n < 8 ? n : 8;
    for (size_t i = 0; i < s->n; i++) {
        s->p[i] = p[i];
        snprintf(s->pname[i], sizeof s->pname[i], "%s", p[i].name);
        s->p[i].name = s->pname[i];
        snprintf(s->pstring[i], sizeof s->pstring[i], "%s", p[i].string ? p[i].string : "");
        s->p[i].string = p[i].string ? s->pstring[i] : NULL;
    }
}

static RayesError rec_shader(void *t, const char *name, const RayesParam *p, size_t n)
{
    Record *r = t;
    r->calls++;
    if (r->n_shader == REC_MAX)
        return RAYES_ERROR_OUT_OF_MEMORY;
    rec_copy_shader(&r->shader[r->n_shader++], name, p, n);
    return RAYES_OK;
}

static RayesError rec_displacement(void *t, const char *name, const RayesParam *p, size_t n)
{
    (void)name, (void)p, (void)n;
    ((Record *)t)->calls++;
    return RAYES_OK;
}

static RayesError rec_float(void *t, float f)
{
    (void)f;
    ((Record *)t)->calls++;
    return RAYES_OK;
}

static RayesError rec_search_path(void *t, const char *k, const char *p)
{
    (void)k, (void)p;
    ((Record *)t)->calls++;
    return RAYES_OK;
}

static void rec_copy_primvars(RecPrimvars *out, const RayesPrimvar *pv, size_t n)
{
    out->n = n < 3 ? n : 3;
    for (size_t i = 0; i < out->n; i++) {
        size_t floats = pv[i].count * (strcmp(pv[i].name, "st") == 0 ? 2u : 3u);
        float *d = malloc(floats * sizeof *d + 1);
        memcpy(d, pv[i].data, floats * sizeof *d);
        snprintf(out->name[i], sizeof out->name[i], "%s", pv[i].name);
        out->pv[i] = pv[i];
        out->pv[i].name = out->name[i];
        out->pv[i].data = d;
    }
}

static void rec_free_primvars(RecPrimvars *p)
{
    for (size_t i = 0; i < p->n; i++)
        free((float *)p->pv[i].data);
    p->n = 0;
}

/* The primitive variable of that name, or NULL. */
static inline const RayesPrimvar *rec_primvar(const RecPrimvars *p, const char *name)
{
    for (size_t i = 0; i < p->n; i++)
        if (strcmp(p->pv[i].name, name) == 0)
            return &p->pv[i];
    return NULL;
}

static RayesError rec_patch(Record *r, int cubic, const float *P, const RayesPrimvar *pv,
                            size_t n_pv)
{
    r->calls++;
    if (r->n_patch == REC_MAX)
        return RAYES_OK; /* counted only */
    RecPatch *p = &r->patch[r->n_patch++];
    p->cubic = cubic;
    memcpy(p->P, P, (cubic ? 48 : 12) * sizeof *P);
    rec_copy_primvars(&p->pv, pv, n_pv);
    return RAYES_OK;
}

static RayesError rec_bilinear(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n_pv)
{
    return rec_patch(t, 0, &P[0][0], pv, n_pv);
}

static RayesError rec_bicubic(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n_pv)
{
    return rec_patch(t, 1, &P[0][0], pv, n_pv);
}

static RayesError rec_mesh(void *t, size_t n_faces, const int *nv, const int *idx,
                           size_t n_points, const float *P, const RayesPrimvar *pv, size_t n_pv)
{
    Record *r = t;
    r->calls++;
    if (r->n_mesh == REC_MAX)
        return RAYES_ERROR_OUT_OF_MEMORY;
    RecMesh *m = &r->mesh[r->n_mesh++];
    size_t k = 0;
    for (size_t f = 0; f < n_faces; f++)
        k += (size_t)nv[f];
    m->n_faces = n_faces;
    m->n_points = n_points;
    m->nv = malloc(n_faces * sizeof *m->nv + 1);
    m->idx = malloc(k * sizeof *m->idx + 1);
    m->P = malloc(3 * n_points * sizeof *m->P + 1);
    memcpy(m->nv, nv, n_faces * sizeof *nv);
    memcpy(m->idx, idx, k * sizeof *idx);
    memcpy(m->P, P, 3 * n_points * sizeof *P);
    m->shader = r->n_shader - 1;
    rec_copy_primvars(&m->pv, pv, n_pv);
    return RAYES_OK;
}

static RayesError rec_subdiv(void *t, RayesSubdivScheme scheme, size_t n_faces, const int *nv,
                             const int *idx, size_t n_points, const float *P,
                             const RayesSubdivTags *tags, const RayesPrimvar *pv, size_t n_pv)
{
    Record *r = t;
    RayesError e = rec_mesh(t, n_faces, nv, idx, n_points, P, pv, n_pv);
    if (e != RAYES_OK)
        return e;
    RecMesh *m = &r->mesh[r->n_mesh - 1];
    m->subdiv = 1, m->scheme = scheme, m->has_tags = tags != NULL;
    if (!tags)
        return RAYES_OK;
    m->tags = *tags;
    size_t ni = 2 * tags->n_creases + tags->n_corners + tags->n_holes;
    size_t nf = tags->n_creases + tags->n_corners;
    if (ni > 64 || nf > 32)
        return RAYES_ERROR_OUT_OF_MEMORY;
    int *at = m->tag_ints;
    if (tags->n_creases)
        memcpy(at, tags->crease_edges, 2 * tags->n_creases * sizeof *at);
    m->tags.crease_edges = at, at += 2 * tags->n_creases;
    if (tags->n_corners)
        memcpy(at, tags->corner_points, tags->n_corners * sizeof *at);
    m->tags.corner_points = at, at += tags->n_corners;
    if (tags->n_holes)
        memcpy(at, tags->hole_faces, tags->n_holes * sizeof *at);
    m->tags.hole_faces = at;
    if (tags->n_creases)
        memcpy(m->tag_floats, tags->crease_sharpness, tags->n_creases * sizeof(float));
    if (tags->n_corners)
        memcpy(m->tag_floats + tags->n_creases, tags->corner_sharpness,
               tags->n_corners * sizeof(float));
    m->tags.crease_sharpness = m->tag_floats;
    m->tags.corner_sharpness = m->tag_floats + tags->n_creases;
    return RAYES_OK;
}

static RayesError rec_sphere(void *t, float radius)
{
    (void)radius;
    ((Record *)t)->calls++;
    return RAYES_OK;
}

static RayesError rec_quadric(void *t, RayesQuadric q, const float *p, size_t n, unsigned f)
{
    (void)q, (void)p, (void)n, (void)f;
    ((Record *)t)->calls++;
    return RAYES_OK;
}

static RayesError rec_area_light(void *t, const float P[4][3], const float L[3])
{
    Record *r = t;
    r->calls++;
    if (r->n_area == REC_MAX)
        return RAYES_ERROR_OUT_OF_MEMORY;
    memcpy(r->area_P[r->n_area], P, sizeof r->area_P[0]);
    memcpy(r->area_L[r->n_area++], L, sizeof r->area_L[0]);
    return RAYES_OK;
}

static RayesError rec_area_light_mesh_textured(void *t, size_t n_faces, const int *nv,
                                               const int *idx, size_t n_points, const float *P,
                                               const float *st, const float L[3], int two_sided,
                                               const char *texture)
{
    Record *r = t;
    (void)nv, (void)idx, (void)n_points, (void)P;
    r->calls++;
    if (r->n_mesh_light == REC_MAX)
        return RAYES_ERROR_OUT_OF_MEMORY;
    r->mesh_light_faces[r->n_mesh_light] = n_faces;
    memcpy(r->mesh_light_L[r->n_mesh_light], L, sizeof r->mesh_light_L[0]);
    snprintf(r->mesh_light_texture[r->n_mesh_light], sizeof r->mesh_light_texture[0], "%s",
             texture);
    memcpy(r->mesh_light_st0[r->n_mesh_light], st, sizeof r->mesh_light_st0[0]);
    r->mesh_light_two_sided[r->n_mesh_light++] = two_sided;
    return RAYES_OK;
}

static RayesError rec_area_light_mesh(void *t, size_t n_faces, const int *nv, const int *idx,
                                      size_t n_points, const float *P, const float L[3],
                                      int two_sided)
{
    const float st0[2] = {0, 0};
    return rec_area_light_mesh_textured(t, n_faces, nv, idx, n_points, P, st0, L, two_sided, "");
}

static RayesError rec_light(void *t, const char *type, const RayesParam *p, size_t n)
{
    Record *r = t;
    r->calls++;
    if (r->n_light == REC_MAX)
        return RAYES_ERROR_OUT_OF_MEMORY;
    rec_copy_shader(&r->light[r->n_light++], type, p, n);
    return RAYES_OK;
}

static RayesError rec_light_links(void *t, RayesLightLinks mode, const size_t *l, size_t n)
{
    Record *r = t;
    r->calls++;
    r->links_mode = (int)mode;
    r->n_links = n < REC_MAX ? n : REC_MAX;
    memcpy(r->links, l, r->n_links * sizeof *l);
    return RAYES_OK;
}
static size_t rec_light_count(void *t)
{
    Record *r = t;
    return (size_t)(r->n_light + r->n_area);
}
static const char *rec_error(void *t)
{
    (void)t;
    return "";
}

static IoSink record_sink(Record *r)
{
    memset(r, 0, sizeof *r);
    return (IoSink){.target = r,
                    .set_camera = rec_camera,
                    .set_camera_matrix = rec_camera_matrix,
                    .set_transform = rec_transform,
                    .set_shader = rec_shader,
                    .set_displacement = rec_displacement,
                    .set_displacement_bound = rec_float,
                    .set_search_path = rec_search_path,
                    .set_shading_rate = rec_float,
                    .bilinear_patch = rec_bilinear,
                    .bicubic_patch = rec_bicubic,
                    .polygon_mesh = rec_mesh,
                    .sphere = rec_sphere,
                    .quadric = rec_quadric,
                    .area_light = rec_area_light,
                    .light = rec_light,
                    .set_light_links = rec_light_links,
                    .light_count = rec_light_count,
                    .get_error = rec_error,
                    .subdivision_mesh = rec_subdiv,
                    .area_light_mesh = rec_area_light_mesh,
                    .area_light_mesh_textured = rec_area_light_mesh_textured};
}

static void record_free(Record *r)
{
    for (int i = 0; i < r->n_mesh; i++) {
        free(r->mesh[i].nv);
        free(r->mesh[i].idx);
        free(r->mesh[i].P);
        rec_free_primvars(&r->mesh[i].pv);
    }
    r->n_mesh = 0;
    for (int i = 0; i < r->n_patch; i++)
        rec_free_primvars(&r->patch[i].pv);
    r->n_patch = 0;
}

/* A RIB text read as file t.rib into a fresh recording (from a copy of
 * exactly its length, so that reading past its end is caught); settings
 * receive what the file says of the render (NULL: not kept), err the
 * message of an error. */
static inline RayesError record_rib(Record *rec, const char *text, IoSettings *settings, char *err,
                                    size_t err_size)
{
    record_free(rec);
    IoSink s = record_sink(rec);
    IoSettings own;
    if (!settings)
        settings = &own;
    io_settings_init(settings);
    IoReadOptions opt = {RAYES_TEST_DATA, -1};
    size_t n = strlen(text);
    unsigned char *copy = malloc(n + 1);
    memcpy(copy, text, n);
    err[0] = '\0';
    RayesError e = io_rib_parse("t.rib", copy, n, &s, &opt, settings, err, err_size);
    free(copy);
    return e;
}

/* record_rib, printing the error when the text is refused. */
static inline RayesError record_rib_said(Record *rec, const char *text, IoSettings *settings,
                                         char *err, size_t err_size)
{
    RayesError e = record_rib(rec, text, settings, err, err_size);
    if (e != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    return e;
}

/* The parameter of that name, or NULL. */
static const RayesParam *rec_param(const RecShader *s, const char *name)
{
    for (size_t i = 0; i < s->n; i++)
        if (strcmp(s->p[i].name, name) == 0)
            return &s->p[i];
    return NULL;
}

#endif
