/*
 * io/ply.c — the PLY reader of ply.h. The header is read line by line into
 * a table of elements and properties; the body is then read element by
 * element with one value reader for the three encodings. Counts are capped
 * by the bytes left before anything is allocated, every read is bounded by
 * the buffer's end (no NUL is assumed), and faces are checked against the
 * vertex count once the whole file is read (a face element may come first).
 */
#include "io/ply.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#define PLY_MAX_ELEMENTS 16
#define PLY_MAX_PROPS 32
#define PLY_MAX_FACE_VERTS 256
#define PLY_MAX_COUNT 100000000L /* elements of one kind */

typedef enum PlyType { PLY_NONE, PLY_I8, PLY_U8, PLY_I16, PLY_U16, PLY_I32, PLY_U32, PLY_F32, PLY_F64 } PlyType;

typedef enum PlyRole { ROLE_NONE, ROLE_X, ROLE_Y, ROLE_Z, ROLE_NX, ROLE_NY, ROLE_NZ, ROLE_U, ROLE_V,
                       ROLE_INDICES } PlyRole;

typedef enum PlyFormat { FORMAT_ASCII, FORMAT_LE, FORMAT_BE } PlyFormat;

typedef struct PlyProp {
    PlyType type;       /* the value type (of the items for a list) */
    PlyType count_type; /* PLY_NONE for a scalar */
    PlyRole role;
} PlyProp;

typedef struct PlyElement {
    char name[64];
    long count;
    PlyProp props[PLY_MAX_PROPS];
    int n_props;
} PlyElement;

typedef struct Ply {
    const char *name;
    const unsigned char *p, *end;
    long line;                 /* 1-based line of p while the text is read; 0 in binary */
    const unsigned char *line_start;
    PlyFormat format;
    PlyElement elements[PLY_MAX_ELEMENTS];
    int n_elements;
    char *err;
    size_t err_size;
    /* faces as the file gives them */
    int *raw_counts;
    int *raw_indices;
    size_t n_raw, n_raw_indices, cap_raw_indices;
} Ply;

static int fail(Ply *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static int fail(Ply *r, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (r->line > 0)
        snprintf(r->err, r->err_size, "%s:%ld:%ld: %s", r->name, r->line,
                 (long)(r->p - r->line_start) + 1, msg);
    else
        snprintf(r->err, r->err_size, "%s: %s", r->name, msg);
    return -1;
}

static size_t type_size(PlyType t)
{
    static const size_t sizes[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return sizes[t];
}

static PlyType type_of(const char *s)
{
    static const struct {
        const char *name;
        PlyType type;
    } names[] = {{"char", PLY_I8},    {"int8", PLY_I8},     {"uchar", PLY_U8},    {"uint8", PLY_U8},
                 {"short", PLY_I16},  {"int16", PLY_I16},   {"ushort", PLY_U16},  {"uint16", PLY_U16},
                 {"int", PLY_I32},    {"int32", PLY_I32},   {"uint", PLY_U32},    {"uint32", PLY_U32},
                 {"float", PLY_F32},  {"float32", PLY_F32}, {"double", PLY_F64},  {"float64", PLY_F64}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(names[i].name, s) == 0)
            return names[i].type;
    return PLY_NONE;
}

/* ------------------------------------------------------------- header */

/* The words of the next header line (at most 8, each at most 63 chars);
 * returns their number, -1 at the end of the data. p moves past the line. */
static int header_line(Ply *r, char words[8][64])
{
    if (r->p >= r->end)
        return -1;
    int n = 0;
    while (r->p < r->end && *r->p != '\n') {
        while (r->p < r->end && (*r->p == ' ' || *r->p == '\t' || *r->p == '\r'))
            r->p++;
        if (r->p >= r->end || *r->p == '\n')
            break;
        size_t k = 0;
        while (r->p < r->end && *r->p != ' ' && *r->p != '\t' && *r->p != '\r' && *r->p != '\n') {
            if (n < 8 && k < 63)
                words[n][k++] = (char)*r->p;
            r->p++;
        }
        if (n < 8)
            words[n][k] = '\0';
        n++;
    }
    return n > 8 ? 8 : n;
}

static void next_line(Ply *r)
{
    if (r->p < r->end && *r->p == '\n')
        r->p++;
    r->line++;
    r->line_start = r->p;
}

static PlyRole role_of(const char *element, const char *prop, int is_list)
{
    if (strcmp(element, "vertex") == 0 && !is_list) {
        static const struct {
            const char *name;
            PlyRole role;
        } roles[] = {{"x", ROLE_X},         {"y", ROLE_Y},         {"z", ROLE_Z},
                     {"nx", ROLE_NX},       {"ny", ROLE_NY},       {"nz", ROLE_NZ},
                     {"u", ROLE_U},         {"v", ROLE_V},         {"s", ROLE_U},
                     {"t", ROLE_V},         {"texture_u", ROLE_U}, {"texture_v", ROLE_V},
                     {"texture_s", ROLE_U}, {"texture_t", ROLE_V}};
        for (size_t i = 0; i < sizeof roles / sizeof roles[0]; i++)
            if (strcmp(roles[i].name, prop) == 0)
                return roles[i].role;
    }
    if (strcmp(element, "face") == 0 && is_list &&
        (strcmp(prop, "vertex_indices") == 0 || strcmp(prop, "vertex_index") == 0))
        return ROLE_INDICES;
    return ROLE_NONE;
}

static int parse_property(Ply *r, char w[8][64], int n)
{
    if (r->n_elements == 0)
        return fail(r, "expected an element line before a property");
    PlyElement *e = &r->elements[r->n_elements - 1];
    if (e->n_props >= PLY_MAX_PROPS)
        return fail(r, "too many properties in element \"%s\" (at most %d)", e->name, PLY_MAX_PROPS);
    PlyProp *pr = &e->props[e->n_props];
    int is_list = n >= 2 && strcmp(w[1], "list") == 0;
    if (is_list) {
        if (n != 5)
            return fail(r, "expected \"property list COUNT_TYPE ITEM_TYPE NAME\"");
        pr->count_type = type_of(w[2]);
        pr->type = type_of(w[3]);
        if (pr->count_type == PLY_NONE || pr->count_type == PLY_F32 || pr->count_type == PLY_F64)
            return fail(r, "expected an integer list count type, found \"%.20s\"", w[2]);
        if (pr->type == PLY_NONE)
            return fail(r, "expected a property type, found \"%.20s\"", w[3]);
    } else {
        if (n != 3)
            return fail(r, "expected \"property TYPE NAME\"");
        pr->count_type = PLY_NONE;
        pr->type = type_of(w[1]);
        if (pr->type == PLY_NONE)
            return fail(r, "expected a property type, found \"%.20s\"", w[1]);
    }
    pr->role = role_of(e->name, w[n - 1], is_list);
    if (pr->role == ROLE_INDICES && (pr->type == PLY_F32 || pr->type == PLY_F64))
        return fail(r, "expected integer vertex indices");
    e->n_props++;
    return 0;
}

static int parse_header(Ply *r)
{
    char w[8][64];
    int n = header_line(r, w);
    if (n != 1 || strcmp(w[0], "ply") != 0) {
        r->p = r->line_start;
        return fail(r, "expected \"ply\" (not a PLY file)");
    }
    next_line(r);
    int have_format = 0;
    for (;;) {
        const unsigned char *start = r->p;
        n = header_line(r, w);
        if (n < 0)
            return fail(r, "expected \"end_header\", found the end of the file");
        r->p = start; /* errors point at the line's start */
        int e = 0;
        if (n == 0 || strcmp(w[0], "comment") == 0 || strcmp(w[0], "obj_info") == 0) {
        } else if (strcmp(w[0], "format") == 0) {
            if (n != 3 || strcmp(w[2], "1.0") != 0)
                e = fail(r, "expected \"format ascii|binary_little_endian|binary_big_endian 1.0\"");
            else if (strcmp(w[1], "ascii") == 0)
                r->format = FORMAT_ASCII;
            else if (strcmp(w[1], "binary_little_endian") == 0)
                r->format = FORMAT_LE;
            else if (strcmp(w[1], "binary_big_endian") == 0)
                r->format = FORMAT_BE;
            else
                e = fail(r, "expected ascii, binary_little_endian or binary_big_endian, found "
                            "\"%.20s\"", w[1]);
            have_format = 1;
        } else if (strcmp(w[0], "element") == 0) {
            char *endp;
            errno = 0;
            long count = n == 3 ? strtol(w[2], &endp, 10) : -1;
            if (n != 3 || *endp != '\0' || errno != 0 || count < 0 || count > PLY_MAX_COUNT)
                e = fail(r, "expected \"element NAME COUNT\" with a count from 0 to %ld",
                         PLY_MAX_COUNT);
            else if (r->n_elements >= PLY_MAX_ELEMENTS)
                e = fail(r, "too many elements (at most %d)", PLY_MAX_ELEMENTS);
            else {
                PlyElement *el = &r->elements[r->n_elements++];
                memset(el, 0, sizeof *el);
                snprintf(el->name, sizeof el->name, "%s", w[1]);
                el->count = count;
            }
        } else if (strcmp(w[0], "property") == 0) {
            e = parse_property(r, w, n);
        } else if (strcmp(w[0], "end_header") == 0 && n == 1) {
            if (!have_format)
                return fail(r, "expected a format line before end_header");
            header_line(r, w);
            next_line(r);
            return 0;
        } else {
            e = fail(r, "expected comment, format, element, property or end_header, found "
                        "\"%.20s\"", w[0]);
        }
        if (e)
            return -1;
        header_line(r, w);
        next_line(r);
    }
}

/* ------------------------------------------------------------- values */

/* The next value of type t; element names the place for binary errors. */
static int read_value(Ply *r, PlyType t, double *out, const char *element, long index)
{
    if (r->format == FORMAT_ASCII) {
        while (r->p < r->end && (*r->p == ' ' || *r->p == '\t' || *r->p == '\r' || *r->p == '\n')) {
            if (*r->p == '\n') {
                r->line++;
                r->line_start = r->p + 1;
            }
            r->p++;
        }
        char tok[64];
        size_t n = 0;
        const unsigned char *q = r->p;
        while (q < r->end && *q != ' ' && *q != '\t' && *q != '\r' && *q != '\n') {
            if (n < sizeof tok - 1)
                tok[n] = (char)*q;
            n++;
            q++;
        }
        if (n == 0)
            return fail(r, "expected a value of %s %ld, found the end of the file", element, index);
        if (n >= sizeof tok)
            return fail(r, "expected a number in %s %ld, found a %zu-character word", element,
                        index, n);
        tok[n] = '\0';
        char *endp;
        errno = 0;
        double v = t == PLY_F32 || t == PLY_F64 ? strtod(tok, &endp) : (double)strtoll(tok, &endp, 10);
        if (*endp != '\0' || errno != 0) { /* "nan" and "inf" are the caller's to judge */
            for (size_t k = 0; k < n && k < 20; k++)
                if (tok[k] < 0x20 || tok[k] >= 0x7f || tok[k] == '"')
                    tok[k] = '?';
            tok[n < 20 ? n : 20] = '\0';
            return fail(r, "expected a%s number in %s %ld, found \"%s\"",
                        t == PLY_F32 || t == PLY_F64 ? "" : "n integer", element, index, tok);
        }
        r->p = q;
        *out = v;
        return 0;
    }
    size_t size = type_size(t);
    if ((size_t)(r->end - r->p) < size)
        return fail(r, "%s %ld: the file ends inside it", element, index);
    unsigned char b[8];
    memcpy(b, r->p, size);
    r->p += size;
    int host_le = 1;
    unsigned char probe[2];
    uint16_t one = 1;
    memcpy(probe, &one, 2);
    host_le = probe[0] == 1;
    if ((r->format == FORMAT_LE) != host_le)
        for (size_t k = 0; k < size / 2; k++) {
            unsigned char c = b[k];
            b[k] = b[size - 1 - k];
            b[size - 1 - k] = c;
        }
    switch (t) {
    case PLY_I8: { int8_t v; memcpy(&v, b, 1); *out = v; break; }
    case PLY_U8: { uint8_t v; memcpy(&v, b, 1); *out = v; break; }
    case PLY_I16: { int16_t v; memcpy(&v, b, 2); *out = v; break; }
    case PLY_U16: { uint16_t v; memcpy(&v, b, 2); *out = v; break; }
    case PLY_I32: { int32_t v; memcpy(&v, b, 4); *out = v; break; }
    case PLY_U32: { uint32_t v; memcpy(&v, b, 4); *out = v; break; }
    case PLY_F32: { float v; memcpy(&v, b, 4); *out = v; break; }
    case PLY_F64: { double v; memcpy(&v, b, 8); *out = v; break; }
    default: *out = 0; break;
    }
    return 0; /* not finite: the caller's to judge (a count or index fails its range) */
}

/* ------------------------------------------------------------- body */

static int add_raw_index(Ply *r, int v)
{
    if (r->n_raw_indices == r->cap_raw_indices) {
        size_t cap = r->cap_raw_indices ? 2 * r->cap_raw_indices : 1024;
        int *p = realloc(r->raw_indices, cap * sizeof *p);
        if (!p)
            return fail(r, "out of memory for face indices");
        r->raw_indices = p;
        r->cap_raw_indices = cap;
    }
    r->raw_indices[r->n_raw_indices++] = v;
    return 0;
}

static int read_element(Ply *r, const PlyElement *e, PlyMesh *m, int is_vertex, int is_face)
{
    for (long i = 0; i < e->count; i++) {
        double vals[ROLE_INDICES] = {0};
        int have_indices = 0;
        for (int k = 0; k < e->n_props; k++) {
            const PlyProp *pr = &e->props[k];
            double v;
            if (pr->count_type == PLY_NONE) {
                if (read_value(r, pr->type, &v, e->name, i) != 0)
                    return -1;
                if (pr->role != ROLE_NONE && pr->role < ROLE_INDICES)
                    vals[pr->role] = v;
                continue;
            }
            double count;
            if (read_value(r, pr->count_type, &count, e->name, i) != 0)
                return -1;
            if (count < 0 || count > PLY_MAX_FACE_VERTS || count != floor(count))
                return fail(r, "%s %ld: a list of %.0f values (expected 0 to %d)", e->name, i,
                            count, PLY_MAX_FACE_VERTS);
            int take = is_face && pr->role == ROLE_INDICES && !have_indices;
            if (take)
                r->raw_counts[r->n_raw] = (int)count;
            for (int j = 0; j < (int)count; j++) {
                if (read_value(r, pr->type, &v, e->name, i) != 0)
                    return -1;
                if (take) {
                    if (!(v >= 0 && v <= (double)INT32_MAX) || v != floor(v))
                        return fail(r, "face %ld: vertex index %g is not an integer from 0 to "
                                       "2147483647", i, v);
                    if (add_raw_index(r, (int)v) != 0)
                        return -1;
                }
            }
            have_indices |= take;
        }
        if (is_face) {
            if (!have_indices)
                r->raw_counts[r->n_raw] = 0;
            r->n_raw++;
        }
        if (is_vertex) {
            for (int c = 0; c < 3; c++) {
                m->P[3 * i + c] = (float)vals[ROLE_X + c];
                if (m->N)
                    m->N[3 * i + c] = (float)vals[ROLE_NX + c];
            }
            if (m->uv) {
                m->uv[2 * i] = (float)vals[ROLE_U];
                m->uv[2 * i + 1] = (float)vals[ROLE_V];
            }
            for (int c = 0; c < 3; c++)
                if (!isfinite(m->P[3 * i + c]))
                    return fail(r, "vertex %ld: a coordinate is not a finite float", i);
            if (m->uv && !(isfinite(m->uv[2 * i]) && isfinite(m->uv[2 * i + 1])))
                return fail(r, "vertex %ld: a texture coordinate is not a finite float", i);
        }
    }
    return 0;
}

static int has_role(const PlyElement *e, PlyRole role)
{
    for (int k = 0; k < e->n_props; k++)
        if (e->props[k].role == role)
            return 1;
    return 0;
}

/* The least number of bytes one element takes in the body. */
static size_t min_element_size(const Ply *r, const PlyElement *e)
{
    size_t s = 0;
    for (int k = 0; k < e->n_props; k++)
        s += r->format == FORMAT_ASCII ? 2
             : type_size(e->props[k].count_type != PLY_NONE ? e->props[k].count_type
                                                             : e->props[k].type);
    return s;
}

static int read_body(Ply *r, PlyMesh *m)
{
    int seen_vertex = 0, seen_face = 0;
    for (int k = 0; k < r->n_elements; k++) {
        const PlyElement *e = &r->elements[k];
        int is_vertex = strcmp(e->name, "vertex") == 0 && !seen_vertex;
        int is_face = strcmp(e->name, "face") == 0 && !seen_face;
        size_t room = (size_t)(r->end - r->p) + 1;
        size_t least = min_element_size(r, e);
        if (e->count > 0 && (least == 0 || (size_t)e->count > room / least + 1))
            return fail(r, "element \"%s\": %ld of them cannot fit in the %zu bytes left", e->name,
                        e->count, room - 1);
        if (is_vertex) {
            seen_vertex = 1;
            if (!has_role(e, ROLE_X) || !has_role(e, ROLE_Y) || !has_role(e, ROLE_Z))
                return fail(r, "element \"vertex\" lacks one of the properties x, y, z");
            m->n_vertices = (size_t)e->count;
            size_t n = m->n_vertices ? m->n_vertices : 1;
            m->P = malloc(n * 3 * sizeof(float));
            if (has_role(e, ROLE_NX) && has_role(e, ROLE_NY) && has_role(e, ROLE_NZ))
                m->N = malloc(n * 3 * sizeof(float));
            if (has_role(e, ROLE_U) && has_role(e, ROLE_V))
                m->uv = malloc(n * 2 * sizeof(float));
            if (!m->P || (has_role(e, ROLE_NX) && !m->N) || (has_role(e, ROLE_U) && !m->uv))
                return fail(r, "out of memory for %ld vertices", e->count);
        }
        if (is_face) {
            seen_face = 1;
            if (!has_role(e, ROLE_INDICES))
                return fail(r, "element \"face\" lacks the list property vertex_indices");
            r->raw_counts = malloc((e->count ? (size_t)e->count : 1) * sizeof(int));
            if (!r->raw_counts)
                return fail(r, "out of memory for %ld faces", e->count);
        }
        if (read_element(r, e, m, is_vertex, is_face) != 0)
            return -1;
    }
    if (!seen_vertex)
        return fail(r, "the file has no element \"vertex\"");
    if (!seen_face)
        return fail(r, "the file has no element \"face\"");
    return 0;
}

/* ------------------------------------------------------------- faces */

static void sub3(const float *a, const float *b, double out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = (double)a[c] - (double)b[c];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Nonzero if the quad q (indices into P) is planar and strictly convex. */
static int quad_is_flat_convex(const float *P, const int q[4])
{
    double n[4][3], len[4];
    for (int k = 0; k < 4; k++) {
        double a[3], b[3];
        sub3(&P[3 * q[(k + 1) % 4]], &P[3 * q[k]], a);
        sub3(&P[3 * q[(k + 3) % 4]], &P[3 * q[k]], b);
        cross3(a, b, n[k]);
        len[k] = sqrt(n[k][0] * n[k][0] + n[k][1] * n[k][1] + n[k][2] * n[k][2]);
        if (!(len[k] > 0))
            return 0;
    }
    for (int k = 1; k < 4; k++) {
        double d = (n[0][0] * n[k][0] + n[0][1] * n[k][1] + n[0][2] * n[k][2]) / (len[0] * len[k]);
        if (d < 0.9999)
            return 0;
    }
    return 1;
}

static int finish_faces(Ply *r, PlyMesh *m)
{
    size_t cap = r->n_raw_indices * 3 + 4; /* a fan of n vertices needs 3 (n - 2) indices */
    m->indices = malloc(cap * sizeof(int));
    m->n_verts = malloc((r->n_raw_indices + 1) * sizeof(int));
    if (!m->indices || !m->n_verts)
        return fail(r, "out of memory for %zu faces", r->n_raw);
    size_t at = 0;
    for (size_t f = 0; f < r->n_raw; at += (size_t)r->raw_counts[f], f++) {
        int n = r->raw_counts[f];
        if (n == 0) { /* raw_indices may be NULL then */
            m->n_skipped++;
            continue;
        }
        const int *idx = r->raw_indices + at;
        for (int k = 0; k < n; k++)
            if ((size_t)idx[k] >= m->n_vertices) {
                r->line = 0; /* found after reading: the face's index names the place */
                return fail(r, "face %zu uses vertex %d but the file has %zu vertices", f, idx[k],
                            m->n_vertices);
            }
        if (n < 3) {
            m->n_skipped++;
            continue;
        }
        if (n == 4 && quad_is_flat_convex(m->P, idx)) {
            m->n_verts[m->n_faces++] = 4;
            memcpy(&m->indices[m->n_indices], idx, 4 * sizeof(int));
            m->n_indices += 4;
            continue;
        }
        m->n_split += n > 3;
        for (int k = 1; k + 1 < n; k++) {
            m->n_verts[m->n_faces++] = 3;
            m->indices[m->n_indices++] = idx[0];
            m->indices[m->n_indices++] = idx[k];
            m->indices[m->n_indices++] = idx[k + 1];
        }
    }
    return 0;
}

static int normal_ok(const float *n)
{
    float len2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
    return isfinite(len2) && len2 > 0.0f;
}

/* Vertex normals that are NaN, infinite or zero (exporters write them at
 * degenerate vertices: Bitterli's lamp has 285) become the sum of their
 * faces' normals, each turned toward its face's good vertex normals;
 * pbrt-v4 shades such a triangle with its geometric normal. A vertex no
 * good face touches gets its faces' sum anyway, or +z. */
static void repair_normals(PlyMesh *m)
{
    unsigned char *bad = NULL;
    for (size_t i = 0; i < m->n_vertices; i++)
        if (!normal_ok(&m->N[3 * i])) {
            if (!m->n_bad_normals++)
                bad = calloc(m->n_vertices, 1); /* out of memory: +z below */
            if (bad)
                bad[i] = 1;
            m->N[3 * i] = m->N[3 * i + 1] = m->N[3 * i + 2] = 0.0f;
        }
    if (!m->n_bad_normals)
        return;
    size_t at = 0;
    for (size_t f = 0; bad && f < m->n_faces; at += (size_t)m->n_verts[f++]) {
        const int *v = m->indices + at;
        int n = m->n_verts[f];
        double a[3], b[3], fn[3], good[3] = {0, 0, 0};
        sub3(&m->P[3 * v[n == 4 ? 2 : 1]], &m->P[3 * v[0]], a);
        sub3(&m->P[3 * v[n == 4 ? 3 : 2]], &m->P[3 * v[n == 4 ? 1 : 0]], b);
        cross3(a, b, fn);
        int any_bad = 0;
        for (int k = 0; k < n; k++) {
            any_bad |= bad[v[k]];
            for (int c = 0; c < 3 && !bad[v[k]]; c++)
                good[c] += m->N[3 * v[k] + c];
        }
        if (!any_bad)
            continue;
        double s = fn[0] * good[0] + fn[1] * good[1] + fn[2] * good[2] < 0 ? -1.0 : 1.0;
        for (int k = 0; k < n; k++)
            for (int c = 0; c < 3 && bad[v[k]]; c++)
                m->N[3 * v[k] + c] += (float)(s * fn[c]);
    }
    for (size_t i = 0; i < m->n_vertices; i++) {
        float *nv = &m->N[3 * i];
        if (!normal_ok(nv))
            nv[0] = nv[1] = 0.0f, nv[2] = 1.0f;
        float len = sqrtf(nv[0] * nv[0] + nv[1] * nv[1] + nv[2] * nv[2]);
        if (bad && bad[i])
            for (int c = 0; c < 3; c++)
                nv[c] /= len;
    }
    free(bad);
}

RayesError io_ply_parse(const char *name, const unsigned char *data, size_t size, PlyMesh *mesh,
                        char *err, size_t err_size)
{
    memset(mesh, 0, sizeof *mesh);
    static const unsigned char empty[1] = {0};
    Ply r = {.name = name, .p = data ? data : empty, .line = 1, .err = err, .err_size = err_size};
    r.end = r.p + (data ? size : 0);
    r.line_start = r.p;
    int bad = parse_header(&r);
    if (!bad) {
        if (r.format != FORMAT_ASCII)
            r.line = 0; /* binary errors name the element instead */
        bad = read_body(&r, mesh) || finish_faces(&r, mesh);
        if (!bad && mesh->N)
            repair_normals(mesh);
    }
    free(r.raw_counts);
    free(r.raw_indices);
    if (bad) {
        io_ply_mesh_fini(mesh);
        return RAYES_ERROR_PARSE;
    }
    return RAYES_OK;
}

/* Files are read through zlib, which passes plain files through, so
 * pbrt-v4's .ply.gz meshes read as .ply ones do. */
#define PLY_MAX_FILE_BYTES ((size_t)1 << 30)

RayesError io_ply_read(const char *path, PlyMesh *mesh, char *err, size_t err_size)
{
    memset(mesh, 0, sizeof *mesh);
    errno = 0;
    gzFile f = gzopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open: %s", path,
                 errno ? strerror(errno) : "out of memory");
        return RAYES_ERROR_IO;
    }
    unsigned char *buf = NULL;
    size_t n = 0, cap = 0;
    const char *why = NULL;
    for (;;) {
        if (n == cap) {
            if (cap >= PLY_MAX_FILE_BYTES) {
                why = "larger than 1 GB uncompressed";
                break;
            }
            cap = cap ? 2 * cap : 1 << 16;
            unsigned char *b = realloc(buf, cap);
            if (!b) {
                why = "out of memory";
                break;
            }
            buf = b;
        }
        size_t want = cap - n > (1u << 30) ? (1u << 30) : cap - n;
        int got = gzread(f, buf + n, (unsigned)want);
        if (got < 0) {
            int code;
            why = gzerror(f, &code);
            break;
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    if (why) {
        snprintf(err, err_size, "%s: %s", path, why);
        gzclose(f);
        free(buf);
        return RAYES_ERROR_IO;
    }
    gzclose(f);
    RayesError e = io_ply_parse(path, buf, n, mesh, err, err_size);
    free(buf);
    return e;
}

void io_ply_mesh_fini(PlyMesh *mesh)
{
    free(mesh->P);
    free(mesh->N);
    free(mesh->uv);
    free(mesh->n_verts);
    free(mesh->indices);
    memset(mesh, 0, sizeof *mesh);
}
