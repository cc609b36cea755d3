/*
 * io/rib_params.c — the RIB reader's messages (errors naming the file,
 * line, column and request; warnings said once per key and read), and the
 * arguments of requests: numbers, strings, handles and integer arrays
 * taken in order, and parameter lists (name, values pairs) typed by
 * Declare, by an inline declaration ("uniform color Kd") or by
 * RenderMan's predeclared names. A primitive checks the number of values
 * of each parameter against its classes' counts before it uses them;
 * undeclared parameters are warned about and ignored. It calls no other
 * file of the reader.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/rib_reader.h"
#include "util/log.h"

/* ------------------------------------------------------------ messages */

int rib_error(Rib *r, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(r->err, r->err_size, "%s:%ld:%ld: %s: %s", r->lx ? r->lx->name : r->top_name, r->req_line, r->req_col,
             r->req, msg);
    return -1;
}

int rib_arg_error(Rib *r, const Arg *a, const char *fmt, ...)
{
    char msg[400];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(r->err, r->err_size, "%s:%ld:%ld: %s: %s", r->lx ? r->lx->name : r->top_name, a->line, a->col, r->req, msg);
    return -1;
}

/* One warning per key and read (the second pass only, so each is said once). */
void rib_warn_once(Rib *r, const char *key, const char *fmt, ...)
{
    if (r->pass != 2)
        return;
    for (size_t i = 0; i < r->n_warned; i++)
        if (strcmp(r->warned[i], key) == 0)
            return;
    if (r->n_warned < RIB_MAX_WARNED) {
        size_t n = strlen(key) + 1;
        r->warned[r->n_warned] = malloc(n);
        if (r->warned[r->n_warned])
            memcpy(r->warned[r->n_warned++], key, n);
    }
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    log_warning("%s:%ld: %s", r->lx ? r->lx->name : r->top_name, r->req_line, msg);
}

int rib_sink_failed(Rib *r, const IoSink *s)
{
    const char *m = s->get_error(s->target);
    return rib_error(r, "%s", m && m[0] ? m : "the scene refused it");
}

/* A copy of s, or NULL. */
char *rib_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* ---------------------------------------------------- argument helpers */

int rib_is_num(const Arg *g)
{
    return g->kind == ARG_NUM || g->kind == ARG_NUMS;
}

/* n numbers from args *i on (scalars or arrays, an array taken whole). */
int rib_get_floats(Rib *r, const Args *a, size_t *i, float *out, size_t n, const char *what)
{
    size_t got = 0;
    while (got < n) {
        if (*i >= a->n || !rib_is_num(&a->v[*i]) || a->v[*i].n > n - got)
            return rib_error(r, "expected %s (%zu numbers)", what, n);
        const Arg *g = &a->v[(*i)++];
        for (size_t k = 0; k < g->n; k++)
            out[got++] = (float)g->d[k];
        if (g->n == 0 && g->kind == ARG_NUMS && got < n)
            return rib_error(r, "expected %s (%zu numbers)", what, n);
    }
    return 0;
}

const char *rib_get_string(Rib *r, const Args *a, size_t *i, const char *what)
{
    if (*i < a->n && a->v[*i].kind == ARG_STR)
        return a->v[(*i)++].s[0];
    if (*i < a->n && a->v[*i].kind == ARG_STRS && a->v[*i].n == 1)
        return a->v[(*i)++].s[0];
    rib_error(r, "expected %s (a string)", what);
    return NULL;
}

/* A handle: an integer or a string, as a key. */
int rib_get_handle(Rib *r, const Args *a, size_t *i, char key[RIB_MAX_HANDLE])
{
    if (*i < a->n && a->v[*i].kind == ARG_NUM) {
        snprintf(key, RIB_MAX_HANDLE, "#%.17g", a->v[(*i)++].d[0]);
        return 0;
    }
    const char *s = rib_get_string(r, a, i, "a handle");
    if (!s)
        return -1;
    if (strlen(s) > RIB_MAX_HANDLE - 3)
        return rib_error(r, "a handle longer than %d characters", RIB_MAX_HANDLE - 3);
    snprintf(key, RIB_MAX_HANDLE, "\"%s\"", s);
    return 0;
}

const char *rib_handle_name(const char *key)
{
    return key[0] == '#' ? key + 1 : key;
}

/* An integer array (or one integer) with every value in [lo, hi]. */
int rib_get_ints(Rib *r, const Args *a, size_t *i, int **out, size_t *n, long lo, long hi,
                    const char *what)
{
    if (*i >= a->n || !rib_is_num(&a->v[*i]))
        return rib_error(r, "expected %s (integers)", what);
    const Arg *g = &a->v[(*i)++];
    int *v = malloc((g->n ? g->n : 1) * sizeof *v);
    if (!v)
        return rib_error(r, "out of memory");
    for (size_t k = 0; k < g->n; k++) {
        double d = g->d[k];
        if (d != floor(d) || d < lo || d > hi) {
            free(v);
            return rib_arg_error(r, g, "%s: value %zu (%g) is not an integer in [%ld, %ld]", what,
                             k + 1, d, lo, hi);
        }
        v[k] = (int)d;
    }
    *out = v;
    *n = g->n;
    return 0;
}

/* ------------------------------------------------------- declarations */

static const char *const predeclared[][2] = {
    {"P", "vertex point"}, {"Pw", "vertex hpoint"}, {"Pz", "vertex float"},
    {"N", "varying normal"}, {"Np", "uniform normal"}, {"Ng", "varying normal"},
    {"Cs", "varying color"}, {"Os", "varying color"}, {"s", "varying float"},
    {"t", "varying float"}, {"st", "varying float[2]"}, {"u", "varying float"},
    {"v", "varying float"}, {"width", "varying float"}, {"constantwidth", "constant float"},
    {"Ka", "uniform float"}, {"Kd", "uniform float"}, {"Ks", "uniform float"},
    {"Kr", "uniform float"}, {"Km", "uniform float"}, {"Kt", "uniform float"},
    {"Ke", "uniform color"}, {"roughness", "uniform float"}, {"specularcolor", "uniform color"},
    {"texturename", "uniform string"}, {"intensity", "uniform float"},
    {"lightcolor", "uniform color"}, {"from", "uniform point"}, {"to", "uniform point"},
    {"coneangle", "uniform float"}, {"conedeltaangle", "uniform float"},
    {"beamdistribution", "uniform float"}, {"amplitude", "uniform float"},
    {"shadowname", "uniform string"}, {"mapname", "uniform string"}, {"fov", "float"},
    {"sphere", "float"}, {"coordinatesystem", "string"}, {"name", "string"},
    {"shader", "string"}, {"texture", "string"}, {"archive", "string"},
    {"resource", "string"}, {"procedural", "string"}, {"display", "string"},
    {"bucketsize", "integer[2]"}, {"gridsize", "integer"}, {"texturememory", "integer"},
    {"opacitycachememory", "integer"}, {"transmissionhitmode", "string"},
    {"opacitycache", "integer"},
    {"endofframe", "integer"}, {"shadows", "string"}, {"origin", "integer[2]"},
    {"maxdistance", "float"}, {"distance", "float"}, {"background", "color"},
    {"eta", "float"}, {"Kr", "float"}, {"__category", "string"},
};


int rib_type_size(Ty t)
{
    static const int size[] = {1, 1, 1, 3, 3, 4, 16};
    return size[t];
}

/* Parses "[class] [type][n] [name]"; returns 0 and fills d (name "" when
 * the string has none), -1 when it is no declaration. */
static int parse_decl(const char *s, Decl *d, int want_name)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", s);
    char *words[4];
    int n = 0;
    char *save = NULL;
    for (char *w = strtok_r(buf, " \t\n", &save); w && n < 4; w = strtok_r(NULL, " \t\n", &save))
        words[n++] = w;
    if (n == 0)
        return -1;
    static const char *const classes[] = {"constant", "uniform", "varying", "vertex", "facevarying",
                                          "facevertex"};
    /* mpoint: RenderMan's blob reference frame, a matrix per blob */
    static const char *const types[] = {"float",  "integer", "string", "color",
                                        "point",  "hpoint",  "matrix", "int",
                                        "vector", "normal",  "bool",   "mpoint"};
    static const Ty type_of[] = {TY_FLOAT, TY_INT,   TY_STRING, TY_COLOR, TY_POINT, TY_HPOINT,
                                 TY_MATRIX, TY_INT,  TY_POINT,  TY_POINT, TY_INT,   TY_MATRIX};
    int k = 0, have_type = 0;
    d->cls = CLS_UNIFORM;
    d->array = 1;
    d->reference = 0;
    if (strcmp(words[0], "reference") == 0 && n > 1) {
        /* RenderMan's connection to a Pattern: rayes' "reference pattern
         * NAME" (or any type there), whose value is the pattern's name */
        d->reference = 1;
        d->ty = TY_STRING;
        return want_name && n == 3 ? (snprintf(d->name, sizeof d->name, "%s", words[2]), 0) : -1;
    }
    for (int c = 0; c < 6; c++)
        if (strcmp(words[k], classes[c]) == 0) {
            d->cls = c == 5 ? CLS_FACEVARYING : (Cls)c;
            k++;
            break;
        }
    if (k < n) {
        char *br = strchr(words[k], '[');
        if (br)
            *br = '\0';
        for (int t = 0; t < (int)(sizeof types / sizeof *types); t++)
            if (strcmp(words[k], types[t]) == 0) {
                d->ty = type_of[t];
                have_type = 1;
                break;
            }
        if (have_type) {
            k++;
            if (br) {
                long len = strtol(br + 1, NULL, 10);
                if (len < 1 || len > 1 << 16)
                    return -1;
                d->array = (int)len;
            } else if (k < n && words[k][0] == '[') {
                long len = strtol(words[k] + 1, NULL, 10);
                if (len < 1 || len > 1 << 16)
                    return -1;
                d->array = (int)len;
                k++;
            }
        } else if (br) {
            *br = '[';
        }
    }
    if (!have_type)
        return -1;
    d->name[0] = '\0';
    if (k < n) {
        if (!want_name || k != n - 1)
            return -1;
        snprintf(d->name, sizeof d->name, "%s", words[k]);
    } else if (want_name) {
        return -1;
    }
    return 0;
}

static int lookup_decl(Rib *r, const char *name, Decl *d)
{
    for (size_t i = r->n_decls; i-- > 0;)
        if (strcmp(r->decls[i].name, name) == 0) {
            *d = r->decls[i];
            return 1;
        }
    for (size_t i = 0; i < sizeof predeclared / sizeof predeclared[0]; i++)
        if (strcmp(predeclared[i][0], name) == 0) {
            parse_decl(predeclared[i][1], d, 0);
            snprintf(d->name, sizeof d->name, "%s", name);
            return 1;
        }
    return 0;
}

/* The parameter list of args[start..]: pairs of a name and values. */
int rib_get_params(Rib *r, const Args *a, size_t start, Param **out, size_t *n_out)
{
    *out = NULL;
    *n_out = 0;
    if (start > a->n)
        start = a->n;
    size_t n = (a->n - start) / 2 + 1;
    Param *p = calloc(n, sizeof *p);
    if (!p)
        return rib_error(r, "out of memory");
    size_t k = 0;
    for (size_t i = start; i < a->n; i += 2) {
        const Arg *name = &a->v[i];
        if (name->kind != ARG_STR) {
            free(p);
            return rib_arg_error(r, name, "expected a parameter name (a string)");
        }
        if (i + 1 >= a->n) {
            free(p);
            return rib_arg_error(r, name, "the parameter \"%s\" has no value", name->s[0]);
        }
        Param *q = &p[k++];
        q->v = &a->v[i + 1];
        const char *s = name->s[0];
        if (strchr(s, ' ') || strchr(s, '\t')) {
            if (parse_decl(s, &q->d, 1) != 0) {
                free(p);
                return rib_arg_error(r, name, "expected an inline declaration \"[class] type name\", "
                                          "found \"%s\"", s);
            }
            q->declared = 1;
        } else if (lookup_decl(r, s, &q->d)) {
            q->declared = 1;
        } else {
            snprintf(q->d.name, sizeof q->d.name, "%s", s);
            q->d.cls = CLS_UNIFORM;
            q->d.ty = rib_is_num(q->v) ? TY_FLOAT : TY_STRING;
            q->d.array = 1;
        }
        int str = q->v->kind == ARG_STR || q->v->kind == ARG_STRS;
        if (q->declared && (q->d.ty == TY_STRING) != str && q->v->n > 0) {
            rib_arg_error(r, q->v, "the parameter \"%s\" is declared %s but has %s values", q->d.name,
                      q->d.ty == TY_STRING ? "string" : "numeric", str ? "string" : "numeric");
            free(p);
            return -1;
        }
    }
    *out = p;
    *n_out = k;
    return 0;
}

const Param *rib_find_param(const Param *p, size_t n, const char *name)
{
    for (size_t i = n; i-- > 0;)
        if (strcmp(p[i].d.name, name) == 0)
            return &p[i];
    return NULL;
}

static size_t class_count(const Counts *c, Cls cls)
{
    switch (cls) {
    case CLS_CONSTANT: return 1;
    case CLS_UNIFORM: return c->uniform;
    case CLS_VARYING: return c->varying;
    case CLS_VERTEX: return c->vertex;
    case CLS_FACEVARYING: return c->facevarying;
    }
    return 1;
}

int rib_check_counts(Rib *r, const Param *p, size_t n, const Counts *c)
{
    static const char *const cls_names[] = {"constant", "uniform", "varying", "vertex",
                                            "facevarying"};
    for (size_t i = 0; i < n; i++) {
        if (!p[i].declared) {
            char key[128];
            snprintf(key, sizeof key, "undeclared %s", p[i].d.name);
            rib_warn_once(r, key, "%s: undeclared parameter \"%s\" ignored", r->req, p[i].d.name);
            continue;
        }
        size_t want = class_count(c, p[i].d.cls) * (size_t)rib_type_size(p[i].d.ty) * (size_t)p[i].d.array;
        if (p[i].v->n != want)
            return rib_arg_error(r, p[i].v, "the %s parameter \"%s\" needs %zu values (%zu %s), found %zu",
                             cls_names[p[i].d.cls], p[i].d.name, want, class_count(c, p[i].d.cls),
                             p[i].d.cls == CLS_UNIFORM ? "faces" : "values", p[i].v->n);
    }
    return 0;
}

/* Warns once per parameter name a primitive does not use. */
void rib_warn_unused(Rib *r, const Param *p, size_t n)
{
    static const char *const used[] = {"P",  "Pw", "Pz", "Cs", "Os", "N",
                                       "Np", "st", "s",  "t",  NULL};
    for (size_t i = 0; i < n; i++) {
        int u = !p[i].declared;
        for (int k = 0; used[k]; k++)
            u |= strcmp(p[i].d.name, used[k]) == 0;
        if (!u) {
            char key[128];
            snprintf(key, sizeof key, "unused %s", p[i].d.name);
            rib_warn_once(r, key, "parameter \"%s\" is not used (rayes takes P, N, st, Cs and Os)",
                          p[i].d.name);
        }
    }
}

/* The primitive's "Cs" when it is one colour per value; NULL otherwise. */
const Param *rib_color_param(Rib *r, const Param *p, size_t n)
{
    const Param *cs = rib_find_param(p, n, "Cs");
    if (!cs || !cs->declared)
        return NULL;
    if (rib_type_size(cs->d.ty) != 3 || cs->d.array != 1 || cs->d.ty == TY_STRING) {
        rib_warn_once(r, "Cs type", "\"Cs\" that is not one colour per value is ignored");
        return NULL;
    }
    return cs;
}

static int h_declare(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = rib_get_string(r, a, &i, "a parameter name");
    const char *decl = name ? rib_get_string(r, a, &i, "a declaration") : NULL;
    if (!decl)
        return -1;
    Decl d;
    if (parse_decl(decl, &d, 0) != 0)
        return rib_error(r, "expected a declaration \"[class] type[n]\", found \"%s\"", decl);
    if (r->n_decls >= 65536)
        return rib_error(r, "more than 65536 declarations");
    Decl *nd = realloc(r->decls, (r->n_decls + 1) * sizeof *nd);
    if (!nd)
        return rib_error(r, "out of memory");
    r->decls = nd;
    snprintf(d.name, sizeof d.name, "%s", name);
    r->decls[r->n_decls++] = d;
    return 0;
}


/* ------------------------------------------------------------ requests */

const RibRequest rib_params_requests[] = {
    {"Declare", h_declare},
    {NULL, NULL},
};
