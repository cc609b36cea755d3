/*
 * io/rib.c — the RIB reader of rib.h (docs/rib.md says what is supported,
 * mapped, warned about and skipped).
 *
 * A file is read twice. The first pass drives a sink that does nothing:
 * it checks the whole stream (so bad input reaches no scene) and lists the
 * frames, which of them render an image (not a shadow-map pass), so that
 * frame -1 can mean "the last frame that renders an image". The second
 * pass reads that frame (and everything outside frames) into the caller's
 * sink. Every file and archive is read whole through zlib (gzopen/gzread
 * pass plain files through), so .rib and .rib.gz share one path.
 *
 * State: the attribute state (transform, colour, shaders, orientation,
 * basis) is a value copied onto a stack by AttributeBegin/TransformBegin.
 * Shaders are immutable records (ShaderRec) owned by the reader, so the
 * copies share them. What was last sent to each sink (transform, shader,
 * ...) is remembered in a SinkState, and resent only when it changes.
 * Lights: which are on is an attribute (a bit per light in Attr, saved by
 * AttributeBegin, not by TransformBegin; LightSource turns the new light
 * on, Illuminate on or off). A light is sent at the first geometry after
 * its LightSource, on or off, or at WorldEnd if it is on then (one that
 * no geometry followed and that is off at the end lights nothing, and is
 * not sent); each geometry's objects get the light links EXCEPT the lights
 * that are off for it. A light still lights the geometry before its
 * LightSource (as every light did before light linking), and area lights
 * light everything. Object definitions go to a recording
 * sink (rib_record.c) replayed per instance.
 *
 * Limits (bad input fails cleanly): archive depth 32, attribute stack
 * 1024, files up to 1 GB uncompressed, arguments per request 1,000,000.
 */
#include "io/rib.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <zlib.h>

#include "io/bpt.h"
#include "io/rib_internal.h"
#include "io/rib_lex.h"
#include "util/log.h"

#define RIB_MAX_ARCHIVE_DEPTH 32
#define RIB_MAX_STACK 1024
#define RIB_MAX_ARGS 1000000
#define RIB_MAX_FILE_BYTES ((size_t)1 << 30)
#define RIB_MAX_WARNED 512
#define RIB_MAX_LIGHTS 4096

/* ----------------------------------------------------------- arguments */

typedef enum ArgKind { ARG_NUM, ARG_STR, ARG_NUMS, ARG_STRS } ArgKind;

typedef struct Arg {
    ArgKind kind;
    double *d;   /* NUM, NUMS */
    char **s;    /* STR, STRS */
    size_t n;    /* values */
    long line, col;
} Arg;

typedef struct Args {
    Arg *v;
    size_t n, cap;
} Args;

/* ------------------------------------------------------- declarations */

typedef enum Cls { CLS_CONSTANT, CLS_UNIFORM, CLS_VARYING, CLS_VERTEX, CLS_FACEVARYING } Cls;
typedef enum Ty { TY_FLOAT, TY_INT, TY_STRING, TY_COLOR, TY_POINT, TY_HPOINT, TY_MATRIX } Ty;

typedef struct Decl {
    char name[64];
    Cls cls;
    Ty ty;
    int array; /* elements per value, >= 1 */
} Decl;

typedef struct Param {
    Decl d;
    int declared; /* 0: unknown name, type guessed from the values */
    const Arg *v;
} Param;

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
    {"endofframe", "integer"}, {"shadows", "string"}, {"origin", "integer[2]"},
    {"maxdistance", "float"}, {"distance", "float"}, {"background", "color"},
    {"eta", "float"}, {"Kr", "float"}, {"__category", "string"},
};

/* ------------------------------------------------------------- state */

typedef struct ShaderRec {
    char name[64];
    RayesParam *params; /* names and strings owned */
    size_t n;
    struct ShaderRec *next;
} ShaderRec;

enum { ORIENT_OUTSIDE, ORIENT_INSIDE, ORIENT_LH, ORIENT_RH };

typedef struct Attr {
    float M[16];               /* camera_from_object before WorldBegin, world_from_object after */
    int orient;
    float Cs[3], Os[3];
    long color_gen;            /* changes with Cs/Os */
    const ShaderRec *surface;  /* NULL: matte */
    const ShaderRec *displacement;
    float shading_rate;
    float bound;
    int area;                  /* AreaLightSource in force */
    unsigned char on[RIB_MAX_LIGHTS / 8]; /* bit k: Rib.lights[k] is on */
    float area_L[3];
    float ubasis[16], vbasis[16];
    int ustep, vstep;
} Attr;

typedef struct SinkState {
    float M[16];
    int have_M;
    const ShaderRec *surface;
    long color_gen;
    int have_shader;
    const ShaderRec *displacement;
    int have_displacement;
    float rate, bound;
    int have_rate, have_bound;
} SinkState;

#define RIB_LIGHT_PARAMS 12

typedef struct Light {
    char handle[64];
    char type[32];
    RayesParam params[RIB_LIGHT_PARAMS];
    char names[RIB_LIGHT_PARAMS][64];
    char category[128];
    size_t n;
    float M[16];   /* world_from_light (camera_from_light before WorldBegin) */
    int pre_world;
    long index;    /* the sink's index of the light once sent, else -1 */
} Light;

typedef struct Object {
    char key[64];
    RibRecording *rec;
} Object;

typedef struct Frame {
    long number;
    int renders; /* a world block whose display is not a shadow map */
} Frame;

typedef struct StackEntry {
    Attr a;
    int attribute; /* 1: AttributeBegin, 0: TransformBegin */
} StackEntry;

typedef struct Rib {
    int pass;                  /* 1: check and list frames, 2: read into the sink */
    const IoSink *sink;
    const IoReadOptions *opt;
    IoSettings *settings;
    char *err;
    size_t err_size;
    RibLexer *lx;              /* the file being read (NULL after the top file ends) */
    const char *top_name;      /* the top file, for messages after it ends */
    const char *file;          /* its path */
    char req[64];              /* the current request */
    long req_line, req_col;
    int archive_depth;

    Attr a;
    StackEntry *stack;
    size_t depth;
    long next_gen;
    ShaderRec *shaders;

    int in_world;
    int worlds;
    float camera_from_world[16];
    int projection;            /* RayesProjection */
    float fov;
    float screen[4];
    int have_screen;
    float frame_aspect;
    int width, height;

    Decl *decls;
    size_t n_decls;
    Light *lights;
    size_t n_lights;
    size_t *links;             /* the light links last sent (EXCEPT these; none: ALL) */
    size_t n_links;
    Object *objects;
    size_t n_objects;
    RibRecording *rec;         /* the object being defined */
    IoSink rec_sink;
    char rec_key[64];
    float rec_saved_M[16];
    SinkState real, recorded;

    char archive_path[4096];
    char *coordsys_names;      /* CoordinateSystem: n x 64 names */
    float *coordsys_M;
    int *coordsys_world;
    size_t n_coordsys;

    Frame *frames;
    size_t n_frames;
    long frame_ordinal;
    long selected;             /* ordinal of the frame to read, -1: no frames */
    int in_frame, skipping, done;
    int shadow_display;
    IoSettings frame_saved;
    int frame_saved_shadow;
    int motion, motion_seen;
    int archive_block;

    char *warned[RIB_MAX_WARNED];
    size_t n_warned;
} Rib;

/* ------------------------------------------------------------ messages */

static int rib_error(Rib *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static int rib_error(Rib *r, const char *fmt, ...)
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

static int arg_error(Rib *r, const Arg *a, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static int arg_error(Rib *r, const Arg *a, const char *fmt, ...)
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
static void warn_once(Rib *r, const char *key, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void warn_once(Rib *r, const char *key, const char *fmt, ...)
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

static int sink_failed(Rib *r, const IoSink *s)
{
    const char *m = s->get_error(s->target);
    return rib_error(r, "%s", m && m[0] ? m : "the scene refused it");
}

/* -------------------------------------------------------------- files */

/* The whole file through zlib (plain or gzip); new buffer or NULL. */
static unsigned char *read_gz(const char *path, size_t *size, char *err, size_t err_size)
{
    gzFile f = gzopen(path, "rb");
    if (!f) {
        snprintf(err, err_size, "%s: cannot open the file", path);
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    for (;;) {
        if (!buf) {
            snprintf(err, err_size, "%s: out of memory", path);
            break;
        }
        if (n == cap) {
            if (cap >= RIB_MAX_FILE_BYTES) {
                snprintf(err, err_size, "%s: larger than 1 GB uncompressed", path);
                free(buf);
                buf = NULL;
                break;
            }
            unsigned char *b = realloc(buf, cap * 2);
            if (!b) {
                free(buf);
                buf = NULL;
                continue;
            }
            buf = b;
            cap *= 2;
        }
        int got = gzread(f, buf + n, (unsigned)(cap - n > (1u << 30) ? (1u << 30) : cap - n));
        if (got < 0) {
            int code;
            snprintf(err, err_size, "%s: cannot read the file (%s)", path, gzerror(f, &code));
            free(buf);
            buf = NULL;
            break;
        }
        if (got == 0)
            break;
        n += (size_t)got;
    }
    gzclose(f);
    *size = n;
    return buf;
}

/* A gzip buffer inflated (io_rib_parse of compressed data); NULL on error. */
static unsigned char *inflate_buffer(const unsigned char *data, size_t size, size_t *out_size)
{
    z_stream z;
    memset(&z, 0, sizeof z);
    if (inflateInit2(&z, 15 + 32) != Z_OK)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    unsigned char *buf = malloc(cap);
    z.next_in = (unsigned char *)data;
    z.avail_in = (uInt)(size > UINT32_MAX ? UINT32_MAX : size);
    int ret = Z_OK;
    while (buf && ret == Z_OK) {
        if (n == cap) {
            unsigned char *b = cap < RIB_MAX_FILE_BYTES / 4 ? realloc(buf, cap * 2) : NULL;
            if (!b) {
                free(buf);
                buf = NULL;
                break;
            }
            buf = b;
            cap *= 2;
        }
        z.next_out = buf + n;
        z.avail_out = (uInt)(cap - n);
        ret = inflate(&z, Z_NO_FLUSH);
        n = cap - z.avail_out;
        if (ret == Z_BUF_ERROR && z.avail_in == 0)
            break;
    }
    inflateEnd(&z);
    if (buf && ret != Z_STREAM_END) {
        free(buf);
        buf = NULL;
    }
    *out_size = n;
    return buf;
}

/* ------------------------------------------------------------ parsing */

static void args_clear(Args *a)
{
    for (size_t i = 0; i < a->n; i++) {
        free(a->v[i].d);
        if (a->v[i].s)
            for (size_t k = 0; k < a->v[i].n; k++)
                free(a->v[i].s[k]);
        free(a->v[i].s);
    }
    a->n = 0;
}

static Arg *args_push(Rib *r, Args *a, const RibToken *t)
{
    if (a->n >= RIB_MAX_ARGS) {
        rib_lex_error_at(r->lx, t->line, t->col, "more than %d arguments", RIB_MAX_ARGS);
        return NULL;
    }
    if (a->n == a->cap) {
        size_t cap = a->cap ? 2 * a->cap : 16;
        Arg *v = realloc(a->v, cap * sizeof *v);
        if (!v) {
            rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
            return NULL;
        }
        a->v = v;
        a->cap = cap;
    }
    Arg *g = &a->v[a->n++];
    memset(g, 0, sizeof *g);
    g->line = t->line;
    g->col = t->col;
    return g;
}

static int add_num(Rib *r, Arg *g, double v, size_t *cap, const RibToken *t)
{
    if (!isfinite(v) || fabs(v) > FLT_MAX)
        return rib_lex_error_at(r->lx, t->line, t->col, "a number out of range");
    if (g->n == *cap) {
        size_t c = *cap ? 2 * *cap : 4;
        double *d = realloc(g->d, c * sizeof *d);
        if (!d)
            return rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
        g->d = d;
        *cap = c;
    }
    g->d[g->n++] = v;
    return 0;
}

static int add_str(Rib *r, Arg *g, const RibToken *t, size_t *cap)
{
    if (g->n == *cap) {
        size_t c = *cap ? 2 * *cap : 4;
        char **s = realloc(g->s, c * sizeof *s);
        if (!s)
            return rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
        g->s = s;
        *cap = c;
    }
    char *copy = malloc(t->len + 1);
    if (!copy)
        return rib_lex_error_at(r->lx, t->line, t->col, "out of memory");
    memcpy(copy, t->str, t->len + 1);
    g->s[g->n++] = copy;
    return 0;
}

/* Reads the arguments of a request up to the next request (left in *t). */
static int read_args(Rib *r, Args *a, RibToken *t)
{
    for (;;) {
        if (rib_lex_next(r->lx, t) != 0)
            return -1;
        if (t->type == RIB_TOK_REQUEST || t->type == RIB_TOK_EOF)
            return 0;
        if (t->type == RIB_TOK_RBRACKET)
            return rib_lex_error_at(r->lx, t->line, t->col, "']' without '['");
        Arg *g = args_push(r, a, t);
        if (!g)
            return -1;
        size_t cap = 0;
        if (t->type == RIB_TOK_NUMBER) {
            g->kind = ARG_NUM;
            if (add_num(r, g, t->num, &cap, t) != 0)
                return -1;
        } else if (t->type == RIB_TOK_STRING) {
            g->kind = ARG_STR;
            if (add_str(r, g, t, &cap) != 0)
                return -1;
        } else if (t->type == RIB_TOK_FLOATS) {
            g->kind = ARG_NUMS;
            for (size_t k = 0; k < t->n_floats; k++)
                if (add_num(r, g, t->floats[k], &cap, t) != 0)
                    return -1;
        } else { /* '[' */
            g->kind = ARG_NUMS;
            int strings = -1;
            long l0 = t->line, c0 = t->col;
            for (;;) {
                if (rib_lex_next(r->lx, t) != 0)
                    return -1;
                if (t->type == RIB_TOK_RBRACKET)
                    break;
                int is_str = t->type == RIB_TOK_STRING;
                if (t->type != RIB_TOK_NUMBER && t->type != RIB_TOK_STRING &&
                    t->type != RIB_TOK_FLOATS)
                    return rib_lex_error_at(r->lx, l0, c0, "the array has no closing ']'");
                if (strings >= 0 && strings != is_str)
                    return rib_lex_error_at(r->lx, t->line, t->col,
                                            "an array mixes numbers and strings");
                strings = is_str;
                g->kind = is_str ? ARG_STRS : ARG_NUMS;
                int e = 0;
                if (is_str)
                    e = add_str(r, g, t, &cap);
                else if (t->type == RIB_TOK_NUMBER)
                    e = add_num(r, g, t->num, &cap, t);
                else
                    for (size_t k = 0; e == 0 && k < t->n_floats; k++)
                        e = add_num(r, g, t->floats[k], &cap, t);
                if (e != 0)
                    return -1;
            }
        }
    }
}

/* ---------------------------------------------------- argument helpers */

static int is_num(const Arg *g)
{
    return g->kind == ARG_NUM || g->kind == ARG_NUMS;
}

/* n numbers from args *i on (scalars or arrays, an array taken whole). */
static int get_floats(Rib *r, const Args *a, size_t *i, float *out, size_t n, const char *what)
{
    size_t got = 0;
    while (got < n) {
        if (*i >= a->n || !is_num(&a->v[*i]) || a->v[*i].n > n - got)
            return rib_error(r, "expected %s (%zu numbers)", what, n);
        const Arg *g = &a->v[(*i)++];
        for (size_t k = 0; k < g->n; k++)
            out[got++] = (float)g->d[k];
        if (g->n == 0 && g->kind == ARG_NUMS && got < n)
            return rib_error(r, "expected %s (%zu numbers)", what, n);
    }
    return 0;
}

static const char *get_string(Rib *r, const Args *a, size_t *i, const char *what)
{
    if (*i < a->n && a->v[*i].kind == ARG_STR)
        return a->v[(*i)++].s[0];
    if (*i < a->n && a->v[*i].kind == ARG_STRS && a->v[*i].n == 1)
        return a->v[(*i)++].s[0];
    rib_error(r, "expected %s (a string)", what);
    return NULL;
}

/* A handle: an integer or a string, as a key. */
static int get_handle(Rib *r, const Args *a, size_t *i, char key[64])
{
    if (*i < a->n && a->v[*i].kind == ARG_NUM) {
        snprintf(key, 64, "#%.17g", a->v[(*i)++].d[0]);
        return 0;
    }
    const char *s = get_string(r, a, i, "a handle");
    if (!s)
        return -1;
    snprintf(key, 64, "%s", s);
    return 0;
}

/* An integer array (or one integer) with every value in [lo, hi]. */
static int get_ints(Rib *r, const Args *a, size_t *i, int **out, size_t *n, long lo, long hi,
                    const char *what)
{
    if (*i >= a->n || !is_num(&a->v[*i]))
        return rib_error(r, "expected %s (integers)", what);
    const Arg *g = &a->v[(*i)++];
    int *v = malloc((g->n ? g->n : 1) * sizeof *v);
    if (!v)
        return rib_error(r, "out of memory");
    for (size_t k = 0; k < g->n; k++) {
        double d = g->d[k];
        if (d != floor(d) || d < lo || d > hi) {
            free(v);
            return arg_error(r, g, "%s: value %zu (%g) is not an integer in [%ld, %ld]", what,
                             k + 1, d, lo, hi);
        }
        v[k] = (int)d;
    }
    *out = v;
    *n = g->n;
    return 0;
}

/* ------------------------------------------------------- declarations */

static int type_size(Ty t)
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
    static const char *const types[] = {"float", "integer", "string", "color", "point", "hpoint",
                                        "matrix", "int", "vector", "normal", "bool"};
    static const Ty type_of[] = {TY_FLOAT, TY_INT, TY_STRING, TY_COLOR, TY_POINT, TY_HPOINT,
                                 TY_MATRIX, TY_INT, TY_POINT, TY_POINT, TY_INT};
    int k = 0, have_type = 0;
    d->cls = CLS_UNIFORM;
    d->array = 1;
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
        for (int t = 0; t < 11; t++)
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
static int get_params(Rib *r, const Args *a, size_t start, Param **out, size_t *n_out)
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
            return arg_error(r, name, "expected a parameter name (a string)");
        }
        if (i + 1 >= a->n) {
            free(p);
            return arg_error(r, name, "the parameter \"%s\" has no value", name->s[0]);
        }
        Param *q = &p[k++];
        q->v = &a->v[i + 1];
        const char *s = name->s[0];
        if (strchr(s, ' ') || strchr(s, '\t')) {
            if (parse_decl(s, &q->d, 1) != 0) {
                free(p);
                return arg_error(r, name, "expected an inline declaration \"[class] type name\", "
                                          "found \"%s\"", s);
            }
            q->declared = 1;
        } else if (lookup_decl(r, s, &q->d)) {
            q->declared = 1;
        } else {
            snprintf(q->d.name, sizeof q->d.name, "%s", s);
            q->d.cls = CLS_UNIFORM;
            q->d.ty = is_num(q->v) ? TY_FLOAT : TY_STRING;
            q->d.array = 1;
        }
        int str = q->v->kind == ARG_STR || q->v->kind == ARG_STRS;
        if (q->declared && (q->d.ty == TY_STRING) != str && q->v->n > 0) {
            arg_error(r, q->v, "the parameter \"%s\" is declared %s but has %s values", q->d.name,
                      q->d.ty == TY_STRING ? "string" : "numeric", str ? "string" : "numeric");
            free(p);
            return -1;
        }
    }
    *out = p;
    *n_out = k;
    return 0;
}

static const Param *find_param(const Param *p, size_t n, const char *name)
{
    for (size_t i = n; i-- > 0;)
        if (strcmp(p[i].d.name, name) == 0)
            return &p[i];
    return NULL;
}

/* Counts of a primitive's classes, for value-count checks. */
typedef struct Counts {
    size_t uniform, varying, vertex, facevarying;
} Counts;

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

static int check_counts(Rib *r, const Param *p, size_t n, const Counts *c)
{
    static const char *const cls_names[] = {"constant", "uniform", "varying", "vertex",
                                            "facevarying"};
    for (size_t i = 0; i < n; i++) {
        if (!p[i].declared) {
            char key[128];
            snprintf(key, sizeof key, "undeclared %s", p[i].d.name);
            warn_once(r, key, "%s: undeclared parameter \"%s\" ignored", r->req, p[i].d.name);
            continue;
        }
        size_t want = class_count(c, p[i].d.cls) * (size_t)type_size(p[i].d.ty) * (size_t)p[i].d.array;
        if (p[i].v->n != want)
            return arg_error(r, p[i].v, "the %s parameter \"%s\" needs %zu values (%zu %s), found %zu",
                             cls_names[p[i].d.cls], p[i].d.name, want, class_count(c, p[i].d.cls),
                             p[i].d.cls == CLS_UNIFORM ? "faces" : "values", p[i].v->n);
    }
    return 0;
}

/* Warns once per parameter name a primitive does not use. */
static void warn_unused(Rib *r, const Param *p, size_t n)
{
    static const char *const used[] = {"P", "Pw", "Cs", "Os", "N", "Np", "st", "s", "t", NULL};
    for (size_t i = 0; i < n; i++) {
        int u = !p[i].declared;
        for (int k = 0; used[k]; k++)
            u |= strcmp(p[i].d.name, used[k]) == 0;
        if (!u) {
            char key[128];
            snprintf(key, sizeof key, "unused %s", p[i].d.name);
            warn_once(r, key, "parameter \"%s\" is not used (rayes takes P, N, st and Cs)",
                      p[i].d.name);
        }
    }
}

/* The primitive's "Cs" when it is one colour per value; NULL otherwise. */
static const Param *color_param(Rib *r, const Param *p, size_t n)
{
    const Param *cs = find_param(p, n, "Cs");
    if (!cs || !cs->declared)
        return NULL;
    if (type_size(cs->d.ty) != 3 || cs->d.array != 1 || cs->d.ty == TY_STRING) {
        warn_once(r, "Cs type", "\"Cs\" that is not one colour per value is ignored");
        return NULL;
    }
    return cs;
}

/* ---------------------------------------------------------- emission */

static const IoSink *out_sink(Rib *r, SinkState **st)
{
    *st = r->rec ? &r->recorded : &r->real;
    return r->rec ? &r->rec_sink : r->sink;
}

static const float white[3] = {1, 1, 1};

static int send_shader(Rib *r, const IoSink *s, const float Cs[3])
{
    const ShaderRec *sh = r->a.surface;
    size_t n = sh ? sh->n : 0;
    RayesParam *p = malloc((n + 2) * sizeof *p);
    if (!p)
        return rib_error(r, "out of memory");
    if (n)
        memcpy(p, sh->params, n * sizeof *p);
    p[n++] = (RayesParam){"Cs", RAYES_PARAM_COLOR, {Cs[0], Cs[1], Cs[2]}, NULL};
    if (memcmp(r->a.Os, white, sizeof white) != 0)
        p[n++] = (RayesParam){"Os", RAYES_PARAM_COLOR, {r->a.Os[0], r->a.Os[1], r->a.Os[2]}, NULL};
    RayesError e = s->set_shader(s->target, sh ? sh->name : "matte", p, n);
    free(p);
    return e == RAYES_OK ? 0 : sink_failed(r, s);
}

static int light_on(const Attr *a, size_t k)
{
    return (a->on[k / 8] >> (k % 8)) & 1;
}

static void set_light_on(Attr *a, size_t k, int on)
{
    unsigned bit = 1u << (k % 8);
    a->on[k / 8] = (unsigned char)(on ? a->on[k / 8] | bit : a->on[k / 8] & ~bit);
}

static int send_light(Rib *r, Light *L)
{
    const IoSink *s = r->sink;
    size_t index = s->light_count(s->target);
    for (size_t i = 0; i < L->n; i++) { /* the array may have moved since */
        L->params[i].name = L->names[i];
        if (L->params[i].type == RAYES_PARAM_STRING)
            L->params[i].string = L->category;
    }
    if (s->set_transform(s->target, L->M) != RAYES_OK ||
        s->light(s->target, L->type, L->params, L->n) != RAYES_OK)
        return sink_failed(r, s);
    L->index = (long)index;
    r->real.have_M = 0;
    return 0;
}

/* Before geometry (not in an object definition) or an instance: sends the
 * lights never sent, on or off (so that the links of this geometry can
 * exclude them), then the light links (EXCEPT the sent
 * lights that are off) if they changed; new links need a new object, so
 * the shader is sent again. */
static int send_lights(Rib *r)
{
    const IoSink *s = r->sink;
    size_t n = 0;
    int changed = 0;
    for (size_t k = 0; k < r->n_lights; k++) {
        Light *L = &r->lights[k];
        if (L->index < 0 && send_light(r, L) != 0)
            return -1;
        if (light_on(&r->a, k))
            continue;
        if (n >= r->n_links || r->links[n] != (size_t)L->index) {
            size_t *nl = realloc(r->links, (n + 1) * sizeof *nl);
            if (!nl)
                return rib_error(r, "out of memory");
            r->links = nl;
            r->links[n] = (size_t)L->index;
            changed = 1;
        }
        n++;
    }
    if (!changed && n == r->n_links)
        return 0;
    r->n_links = n;
    if (s->set_light_links(s->target, n ? RAYES_LIGHT_LINKS_EXCEPT : RAYES_LIGHT_LINKS_ALL,
                           r->links, n) != RAYES_OK)
        return sink_failed(r, s);
    r->real.have_shader = 0;
    return 0;
}

/* Brings the sink up to date before a primitive; Cs overrides the
 * colour (a per-face colour) when not NULL. 1: skip (outside the world). */
static int emit_begin(Rib *r, const float *Cs)
{
    if (!r->in_world && !r->rec) {
        warn_once(r, "outside world", "geometry outside WorldBegin/WorldEnd is ignored");
        return 1;
    }
    if (!r->rec && send_lights(r) != 0)
        return -1;
    SinkState *st;
    const IoSink *s = out_sink(r, &st);
    if (!st->have_M || memcmp(st->M, r->a.M, sizeof st->M) != 0) {
        if (s->set_transform(s->target, r->a.M) != RAYES_OK)
            return sink_failed(r, s);
        memcpy(st->M, r->a.M, sizeof st->M);
        st->have_M = 1;
    }
    if (Cs) {
        if (send_shader(r, s, Cs) != 0)
            return -1;
        st->have_shader = 0;
    } else if (!st->have_shader || st->surface != r->a.surface || st->color_gen != r->a.color_gen) {
        if (send_shader(r, s, r->a.Cs) != 0)
            return -1;
        st->surface = r->a.surface;
        st->color_gen = r->a.color_gen;
        st->have_shader = 1;
    }
    if (!st->have_displacement || st->displacement != r->a.displacement) {
        const ShaderRec *d = r->a.displacement;
        if (s->set_displacement(s->target, d ? d->name : NULL, d ? d->params : NULL,
                                d ? d->n : 0) != RAYES_OK)
            return sink_failed(r, s);
        st->displacement = d;
        st->have_displacement = 1;
    }
    if (!st->have_rate || st->rate != r->a.shading_rate) {
        if (s->set_shading_rate(s->target, r->a.shading_rate) != RAYES_OK)
            return sink_failed(r, s);
        st->rate = r->a.shading_rate;
        st->have_rate = 1;
    }
    if (!st->have_bound || st->bound != r->a.bound) {
        if (s->set_displacement_bound(s->target, r->a.bound) != RAYES_OK)
            return sink_failed(r, s);
        st->bound = r->a.bound;
        st->have_bound = 1;
    }
    return 0;
}

/* Whether the front of a surface is opposite to the right-hand rule in
 * world space: RenderMan's orientation against the handedness of object
 * space (camera space is left-handed), and a mirror in world_from_object. */
static int flip_of(Rib *r)
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

/* One of the primitive variables rayes.h takes (N, st, Cs), as a
 * primitive gives it: values of size floats, or separate s and t. */
typedef struct RibVar {
    const double *d;  /* the values; s when d2 is set; NULL: not given */
    const double *d2; /* t, when s and t are separate */
    Cls cls;
    int size;         /* floats per value: 3 (N, Cs), 2 (st) */
} RibVar;

static const char *const rib_var_names[3] = {"N", "st", "Cs"};

/* A parameter that is a numeric declared value of size floats, or NULL
 * (with one warning when it has the name but another type). */
static const Param *var_param(Rib *r, const Param *p, size_t n, const char *name, int size)
{
    const Param *q = find_param(p, n, name);
    if (!q || !q->declared)
        return NULL;
    if (q->d.ty == TY_STRING || type_size(q->d.ty) * q->d.array != size) {
        char key[96];
        snprintf(key, sizeof key, "type %s", name);
        warn_once(r, key, "\"%s\" of %d numbers per value is ignored (expected %d)", name,
                  type_size(q->d.ty) * q->d.array, size);
        return NULL;
    }
    return q;
}

/* The primitive's N (or Np), st (or s and t) and Cs, in that order. */
static void rib_vars(Rib *r, const Param *p, size_t n, RibVar vars[3])
{
    memset(vars, 0, 3 * sizeof *vars);
    const Param *N = var_param(r, p, n, "N", 3);
    if (!N)
        N = var_param(r, p, n, "Np", 3);
    if (N)
        vars[0] = (RibVar){N->v->d, NULL, N->d.cls, 3};
    const Param *st = var_param(r, p, n, "st", 2);
    if (st)
        vars[1] = (RibVar){st->v->d, NULL, st->d.cls, 2};
    else {
        const Param *ps = var_param(r, p, n, "s", 1), *pt = var_param(r, p, n, "t", 1);
        if (ps && pt && ps->d.cls == pt->d.cls)
            vars[1] = (RibVar){ps->v->d, pt->v->d, ps->d.cls, 2};
        else if (ps || pt)
            warn_once(r, "s t", "\"s\" and \"t\" are used only together and of one class");
    }
    const Param *cs = var_param(r, p, n, "Cs", 3);
    if (cs)
        vars[2] = (RibVar){cs->v->d, NULL, cs->d.cls, 3};
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

/* Primitive variables for one sink call; the data are owned. */
typedef struct PvOut {
    RayesPrimvar pv[3];
    float *data[3];
    size_t n;
} PvOut;

static void pv_out_free(PvOut *o)
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
    for (int b = 0; b < 3; b++) {
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
            pv_out_free(o);
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
    for (int b = 0; b < 3 && e == 0; b++) {
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
        pv_out_free(o);
    return e;
}

/* The points of a primitive from "P" or "Pw" (divided by w); new array. */
static float *get_points(Rib *r, const Param *p, size_t n_par, size_t *n_points)
{
    const Param *P = find_param(p, n_par, "P");
    const Param *Pw = find_param(p, n_par, "Pw");
    if (!P && !Pw) {
        if (find_param(p, n_par, "Pz"))
            rib_error(r, "\"Pz\" (height fields) is not supported; give \"P\"");
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
        arg_error(r, v, "\"%s\" needs %zu numbers per point, found %zu numbers", w ? "Pw" : "P",
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

static int emit_polys(Rib *r, const Polys *g, const float *P, size_t n_points, const Param *par,
                      size_t n_par)
{
    RibVar vars[3];
    rib_vars(r, par, n_par, vars);
    int flip = flip_of(r);
    RibFaces faces = {0};
    size_t *face_poly = NULL, *poly_at = NULL, *poly_nv = NULL, cap_f = 0, cap_a = 0, cap_n = 0;
    size_t loop = 0, at = 0;
    int e = 0;
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
            float Q[4][3];
            for (int k = 0; k < 4; k++)
                memcpy(Q[flip ? 3 - k : k], &P[3 * v[k]], sizeof Q[0]);
            SinkState *st;
            const IoSink *s = out_sink(r, &st);
            e = emit_begin(r, NULL);
            if (e == 0 && s->area_light(s->target, (const float(*)[3])Q, r->a.area_L) != RAYES_OK)
                e = sink_failed(r, s);
        } else {
            if (r->a.area)
                warn_once(r, "area shape", "only quads become area lights; other shapes under "
                                           "AreaLightSource are ordinary surfaces");
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
        (e = emit_begin(r, NULL)) == 0) {
        SinkState *st;
        const IoSink *s = out_sink(r, &st);
        if (s->polygon_mesh(s->target, faces.n_faces, faces.n_verts, faces.idx, n_points, P,
                            pv.pv, pv.n) != RAYES_OK)
            e = sink_failed(r, s);
    }
    pv_out_free(&pv);
    free(face_poly);
    free(poly_at);
    free(poly_nv);
    rib_faces_fini(&faces);
    return e > 0 ? 0 : e;
}

/* ----------------------------------------------------------- handlers */

typedef int (*Handler)(Rib *r, const Args *a);

static void concat(Rib *r, const float m[16])
{
    rib_mat_mul(r->a.M, m, r->a.M);
}

static int h_translate(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3], m[16];
    if (get_floats(r, a, &i, v, 3, "dx dy dz") != 0)
        return -1;
    rib_mat_identity(m);
    m[3] = v[0], m[7] = v[1], m[11] = v[2];
    concat(r, m);
    return 0;
}

static int h_scale(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3], m[16];
    if (get_floats(r, a, &i, v, 3, "sx sy sz") != 0)
        return -1;
    rib_mat_identity(m);
    m[0] = v[0], m[5] = v[1], m[10] = v[2];
    concat(r, m);
    return 0;
}

static int h_rotate(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4], m[16];
    if (get_floats(r, a, &i, v, 4, "angle dx dy dz") != 0)
        return -1;
    double len = sqrt((double)v[1] * v[1] + (double)v[2] * v[2] + (double)v[3] * v[3]);
    if (!(len > 0))
        return rib_error(r, "the rotation axis is zero");
    double x = v[1] / len, y = v[2] / len, z = v[3] / len;
    double th = v[0] * M_PI / 180, c = cos(th), s = sin(th), t = 1 - c;
    float rm[16] = {(float)(t * x * x + c), (float)(t * x * y - s * z), (float)(t * x * z + s * y), 0,
                    (float)(t * x * y + s * z), (float)(t * y * y + c), (float)(t * y * z - s * x), 0,
                    (float)(t * x * z - s * y), (float)(t * y * z + s * x), (float)(t * z * z + c), 0,
                    0, 0, 0, 1};
    memcpy(m, rm, sizeof m);
    concat(r, m);
    return 0;
}

static int get_matrix(Rib *r, const Args *a, float m[16])
{
    size_t i = 0;
    float v[16];
    if (get_floats(r, a, &i, v, 16, "a 4 x 4 matrix") != 0)
        return -1;
    for (int row = 0; row < 4; row++) /* RIB matrices map row vectors: transpose */
        for (int col = 0; col < 4; col++)
            m[4 * row + col] = v[4 * col + row];
    return 0;
}

static int h_transform(Rib *r, const Args *a)
{
    return get_matrix(r, a, r->a.M);
}

static int h_concat(Rib *r, const Args *a)
{
    float m[16];
    if (get_matrix(r, a, m) != 0)
        return -1;
    concat(r, m);
    return 0;
}

static int h_identity(Rib *r, const Args *a)
{
    (void)a;
    rib_mat_identity(r->a.M);
    return 0;
}

static int h_perspective(Rib *r, const Args *a)
{
    size_t i = 0;
    float fov;
    if (get_floats(r, a, &i, &fov, 1, "fov") != 0)
        return -1;
    if (!(fov > 0 && fov < 180))
        return rib_error(r, "fov must be in (0, 180)");
    float t = (float)tan(fov * M_PI / 360), m[16] = {1 / t, 0, 0, 0, 0, 1 / t, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0};
    warn_once(r, "Perspective", "Perspective concatenates a projective matrix; use Projection");
    concat(r, m);
    return 0;
}

static int push(Rib *r, int attribute)
{
    if (r->depth >= RIB_MAX_STACK)
        return rib_error(r, "more than %d nested blocks", RIB_MAX_STACK);
    if (!r->stack) {
        r->stack = malloc(RIB_MAX_STACK * sizeof *r->stack);
        if (!r->stack)
            return rib_error(r, "out of memory");
    }
    r->stack[r->depth].a = r->a;
    r->stack[r->depth++].attribute = attribute;
    return 0;
}

static int pop(Rib *r, int attribute)
{
    if (r->depth == 0) {
        warn_once(r, attribute ? "AttributeEnd" : "TransformEnd", "%s without a matching begin",
                  r->req);
        return 0;
    }
    StackEntry *s = &r->stack[--r->depth];
    if (s->attribute != attribute)
        warn_once(r, "unbalanced", "%s closes a %s block", r->req,
                  s->attribute ? "AttributeBegin" : "TransformBegin");
    if (attribute)
        r->a = s->a;
    else
        memcpy(r->a.M, s->a.M, sizeof r->a.M);
    return 0;
}

static int h_attribute_begin(Rib *r, const Args *a) { (void)a; return push(r, 1); }
static int h_attribute_end(Rib *r, const Args *a) { (void)a; return pop(r, 1); }
static int h_transform_begin(Rib *r, const Args *a) { (void)a; return push(r, 0); }
static int h_transform_end(Rib *r, const Args *a) { (void)a; return pop(r, 0); }

static int h_coordinate_system(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a coordinate system name");
    if (!name)
        return -1;
    size_t k = 0;
    while (k < r->n_coordsys && strncmp(&r->coordsys_names[64 * k], name, 63) != 0)
        k++;
    if (k == r->n_coordsys) {
        if (k >= 4096)
            return rib_error(r, "more than 4096 coordinate systems");
        char *nn = realloc(r->coordsys_names, 64 * (k + 1));
        if (nn)
            r->coordsys_names = nn;
        float *nm = realloc(r->coordsys_M, 16 * (k + 1) * sizeof *nm);
        if (nm)
            r->coordsys_M = nm;
        int *nw = realloc(r->coordsys_world, (k + 1) * sizeof *nw);
        if (nw)
            r->coordsys_world = nw;
        if (!nn || !nm || !nw)
            return rib_error(r, "out of memory");
        snprintf(&r->coordsys_names[64 * k], 64, "%s", name);
        r->n_coordsys++;
    }
    memcpy(&r->coordsys_M[16 * k], r->a.M, 16 * sizeof(float));
    r->coordsys_world[k] = r->in_world;
    return 0;
}

/* world_from_camera, or the identity (with a warning) when singular. */
static void world_from_camera(Rib *r, float m[16])
{
    if (rib_mat_inverse(r->camera_from_world, m) != 0) {
        warn_once(r, "singular camera", "the camera transform is singular");
        rib_mat_identity(m);
    }
}

static int h_coordsys_transform(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a coordinate system name");
    if (!name)
        return -1;
    if (strcmp(name, "world") == 0) {
        if (r->in_world)
            rib_mat_identity(r->a.M);
        else
            warn_once(r, "coordsys world", "CoordSysTransform \"world\" before WorldBegin ignored");
        return 0;
    }
    if (strcmp(name, "camera") == 0) {
        if (r->in_world)
            world_from_camera(r, r->a.M);
        else
            rib_mat_identity(r->a.M);
        return 0;
    }
    for (size_t k = r->n_coordsys; k-- > 0;)
        if (strcmp(&r->coordsys_names[64 * k], name) == 0) {
            const float *m = &r->coordsys_M[16 * k];
            if (r->in_world && !r->coordsys_world[k]) {
                float wc[16];
                world_from_camera(r, wc);
                rib_mat_mul(wc, m, r->a.M);
            } else {
                memcpy(r->a.M, m, 16 * sizeof *m);
            }
            return 0;
        }
    return rib_error(r, "unknown coordinate system \"%s\"", name);
}

/* ------------------------------------------------------------ options */

static int h_format(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3];
    if (get_floats(r, a, &i, v, 2, "width height") != 0)
        return -1;
    if (i < a->n && get_floats(r, a, &i, v + 2, 1, "the pixel aspect ratio") != 0)
        return -1;
    if (!(v[0] >= 1 && v[0] <= 65536 && v[1] >= 1 && v[1] <= 65536))
        return rib_error(r, "the image size must be 1 to 65536 pixels");
    r->width = r->settings->width = (int)v[0];
    r->height = r->settings->height = (int)v[1];
    if (i == 3 && v[2] != 1 && v[2] != -1)
        warn_once(r, "pixel aspect", "pixel aspect ratio %g treated as 1", (double)v[2]);
    return 0;
}

static int h_frame_aspect(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (get_floats(r, a, &i, &v, 1, "the frame aspect ratio") != 0)
        return -1;
    if (!(v > 0))
        return rib_error(r, "the frame aspect ratio must be positive");
    r->frame_aspect = v;
    return 0;
}

static int h_screen_window(Rib *r, const Args *a)
{
    size_t i = 0;
    if (get_floats(r, a, &i, r->screen, 4, "left right bottom top") != 0)
        return -1;
    r->have_screen = 1;
    return 0;
}

static int h_crop_window(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4];
    if (get_floats(r, a, &i, v, 4, "xmin xmax ymin ymax") != 0)
        return -1;
    for (int k = 0; k < 4; k++)
        r->settings->crop[k] = v[k] < 0 ? 0 : v[k] > 1 ? 1 : v[k];
    return 0;
}

static int h_projection(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a projection name");
    if (!name)
        return -1;
    Param *p;
    size_t n;
    if (get_params(r, a, i, &p, &n) != 0)
        return -1;
    const Param *fov = find_param(p, n, "fov");
    int e = 0;
    if (strcmp(name, "orthographic") == 0) {
        r->projection = RAYES_PROJECTION_ORTHOGRAPHIC;
    } else {
        if (strcmp(name, "perspective") != 0)
            warn_once(r, name, "projection \"%s\" is not supported; perspective used", name);
        r->projection = RAYES_PROJECTION_PERSPECTIVE;
        r->fov = 90;
        if (fov) {
            if (!is_num(fov->v) || fov->v->n != 1 || !(fov->v->d[0] > 0 && fov->v->d[0] < 180))
                e = arg_error(r, fov->v, "\"fov\" needs one angle in (0, 180) degrees");
            else
                r->fov = (float)fov->v->d[0];
        }
    }
    free(p);
    return e;
}

static int h_clipping(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    /* Rays start at the eye and go to infinity: the clipping planes only
     * matter to a z-buffer, and are read and ignored. */
    return get_floats(r, a, &i, v, 2, "near far");
}

static int h_pixel_samples(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    if (get_floats(r, a, &i, v, 2, "xsamples ysamples") != 0)
        return -1;
    if (!(v[0] >= 1 && v[0] <= 1024 && v[1] >= 1 && v[1] <= 1024))
        return rib_error(r, "pixel samples must be 1 to 1024 per axis");
    r->settings->spp = (int)roundf(v[0]) * (int)roundf(v[1]);
    return 0;
}

static int h_pixel_filter(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a filter name");
    float w[2];
    if (!name || get_floats(r, a, &i, w, 2, "xwidth ywidth") != 0)
        return -1;
    if (!(w[0] > 0 && w[0] <= 64))
        return rib_error(r, "the filter width must be in (0, 64] pixels");
    if (strcmp(name, "box") == 0) {
        r->settings->filter = RAYES_FILTER_BOX;
    } else {
        if (strcmp(name, "gaussian") != 0)
            warn_once(r, name, "pixel filter \"%s\" is not built in; the gaussian (nearest "
                               "smooth filter) is used with the same width", name);
        r->settings->filter = RAYES_FILTER_GAUSSIAN;
    }
    r->settings->filter_width = w[0];
    return 0;
}

static int h_one_float(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    return get_floats(r, a, &i, &v, 1, "a number");
}

static int h_exposure(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[2];
    if (get_floats(r, a, &i, v, 2, "gain gamma") != 0)
        return -1;
    if (!(v[0] > 0 && v[1] > 0))
        return rib_error(r, "gain and gamma must be positive");
    r->settings->exposure_gain = v[0];
    r->settings->exposure_gamma = v[1];
    return 0;
}

static int h_quantize(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[4];
    /* Quantisation follows the output file's type (8-bit PNG, float EXR). */
    if (!get_string(r, a, &i, "the kind (\"rgba\" or \"z\")"))
        return -1;
    return get_floats(r, a, &i, v, 4, "one min max dither");
}

static int is_shadow_display(const char *type, const char *mode)
{
    return strcmp(type, "zfile") == 0 || strcmp(type, "shadow") == 0 || strcmp(mode, "z") == 0;
}

static int h_display(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "an image name");
    const char *type = name ? get_string(r, a, &i, "a display type") : NULL;
    const char *mode = type ? get_string(r, a, &i, "a display mode") : NULL;
    if (!mode)
        return -1;
    IoSettings *s = r->settings;
    int extra = name[0] == '+';
    if (!extra) {
        s->n_displays = 0;
        r->shadow_display = is_shadow_display(type, mode);
    }
    if (s->n_displays >= IO_MAX_DISPLAYS) {
        warn_once(r, "displays", "more than %d displays: the others are ignored", IO_MAX_DISPLAYS);
        return 0;
    }
    IoDisplay *d = &s->displays[s->n_displays++];
    snprintf(d->name, sizeof d->name, "%s", name + extra);
    snprintf(d->type, sizeof d->type, "%s", type);
    snprintf(d->mode, sizeof d->mode, "%s", mode);
    return 0;
}

static int h_hider(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a hider name");
    if (!name)
        return -1;
    if (strcmp(name, "hidden") != 0 && strcmp(name, "raytrace") != 0)
        warn_once(r, name, "hider \"%s\" is not supported; rays are traced", name);
    return 0;
}

static int h_shading_rate(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (get_floats(r, a, &i, &v, 1, "a shading rate") != 0)
        return -1;
    if (!(v > 0))
        return rib_error(r, "the shading rate must be positive");
    r->a.shading_rate = v;
    return 0;
}

static int h_sides(Rib *r, const Args *a)
{
    size_t i = 0;
    float v;
    if (get_floats(r, a, &i, &v, 1, "1 or 2") != 0)
        return -1;
    if (v != 1 && v != 2)
        return rib_error(r, "expected 1 or 2, found %g", (double)v);
    return 0;
}

static int h_orientation(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *o = get_string(r, a, &i, "an orientation");
    if (!o)
        return -1;
    static const char *const names[] = {"outside", "inside", "lh", "rh"};
    for (int k = 0; k < 4; k++)
        if (strcmp(o, names[k]) == 0) {
            r->a.orient = k;
            return 0;
        }
    return rib_error(r, "expected \"outside\", \"inside\", \"lh\" or \"rh\", found \"%s\"", o);
}

static int h_reverse_orientation(Rib *r, const Args *a)
{
    (void)a;
    r->a.orient ^= 1; /* outside <-> inside, lh <-> rh */
    return 0;
}

static int h_color(Rib *r, const Args *a)
{
    size_t i = 0;
    float v[3];
    if (get_floats(r, a, &i, v, 3, "a colour") != 0)
        return -1;
    memcpy(strcmp(r->req, "Color") == 0 ? r->a.Cs : r->a.Os, v, sizeof v);
    r->a.color_gen = ++r->next_gen;
    return 0;
}

/* ------------------------------------------------------------ shaders */

static const char *const builtin_surfaces[] = {"matte", "plastic", "metal", "shinymetal",
                                               "constant", "glass", "mirror", "paintedplastic",
                                               "diffuse", "conductor", "dielectric",
                                               "coateddiffuse", NULL};
static const char *const builtin_displacements[] = {"bumpy", "fractal", NULL};

static int in_list(const char *const *list, const char *s)
{
    for (int k = 0; list[k]; k++)
        if (strcmp(list[k], s) == 0)
            return 1;
    return 0;
}

static char *dup_string(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = malloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}

/* A new shader record of name with the parameters the API can take. */
static ShaderRec *make_shader(Rib *r, const char *name, const Param *p, size_t n, int only_k)
{
    ShaderRec *sh = calloc(1, sizeof *sh);
    if (sh)
        sh->params = calloc(n + 1, sizeof *sh->params);
    if (!sh || !sh->params) {
        free(sh);
        rib_error(r, "out of memory");
        return NULL;
    }
    sh->next = r->shaders;
    r->shaders = sh;
    snprintf(sh->name, sizeof sh->name, "%s", name);
    for (size_t i = 0; i < n; i++) {
        const Param *q = &p[i];
        if (only_k && strcmp(q->d.name, "Kd") != 0 && strcmp(q->d.name, "Ka") != 0)
            continue;
        if (!q->declared)
            continue;
        RayesParam o = {NULL, RAYES_PARAM_NONE, {0, 0, 0}, NULL};
        if (q->d.ty == TY_STRING && q->v->n == 1) {
            o.type = RAYES_PARAM_STRING;
            o.string = dup_string(q->v->s[0]);
            if (!o.string)
                return NULL;
        } else if ((q->d.ty == TY_FLOAT || q->d.ty == TY_INT) && q->v->n == 1) {
            o.type = RAYES_PARAM_FLOAT;
            o.value[0] = (float)q->v->d[0];
        } else if (q->d.ty == TY_COLOR || q->d.ty == TY_POINT) {
            if (q->v->n != 3)
                continue;
            o.type = RAYES_PARAM_COLOR;
            for (int c = 0; c < 3; c++)
                o.value[c] = (float)q->v->d[c];
        } else {
            continue;
        }
        o.name = dup_string(q->d.name);
        if (!o.name) {
            free((char *)o.string);
            return NULL;
        }
        sh->params[sh->n++] = o;
    }
    return sh;
}

/* A built-in shader name, or one the sink knows (a plugin on its search
 * path). */
static int shader_known(Rib *r, const char *const *builtins, const char *name)
{
    return in_list(builtins, name) ||
           (r->sink->has_shader && r->sink->has_shader(r->sink->target, name));
}

static int h_surface(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a shader name");
    Param *p;
    size_t n;
    if (!name || get_params(r, a, i, &p, &n) != 0)
        return -1;
    static const Counts one = {1, 1, 1, 1};
    if (check_counts(r, p, n, &one) != 0) {
        free(p);
        return -1;
    }
    int known = shader_known(r, builtin_surfaces, name);
    if (!known) {
        char key[128];
        snprintf(key, sizeof key, "surface %s", name);
        warn_once(r, key,
                  "surface shader \"%s\" is neither built in nor a plugin on the shader path: "
                  "matte instead (with its Ka, Kd)",
                  name);
    }
    ShaderRec *sh = make_shader(r, known ? name : "matte", p, n, !known);
    free(p);
    if (!sh)
        return -1;
    r->a.surface = sh;
    return 0;
}

static int h_displacement(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a shader name");
    Param *p;
    size_t n;
    if (!name || get_params(r, a, i, &p, &n) != 0)
        return -1;
    static const Counts one = {1, 1, 1, 1};
    if (check_counts(r, p, n, &one) != 0) {
        free(p);
        return -1;
    }
    if (!shader_known(r, builtin_displacements, name)) {
        char key[128];
        snprintf(key, sizeof key, "displacement %s", name);
        warn_once(r, key,
                  "displacement shader \"%s\" is neither built in nor a plugin on the shader path: "
                  "no displacement",
                  name);
        r->a.displacement = NULL;
        free(p);
        return 0;
    }
    ShaderRec *sh = make_shader(r, name, p, n, 0);
    free(p);
    if (!sh)
        return -1;
    r->a.displacement = sh;
    return 0;
}

static Light *find_light(Rib *r, const char *handle)
{
    for (size_t k = 0; k < r->n_lights; k++)
        if (strcmp(r->lights[k].handle, handle) == 0)
            return &r->lights[k];
    return NULL;
}

static int h_light_source(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a light shader name");
    char handle[64];
    if (!name)
        return -1;
    if (i < a->n && (a->n - i) % 2 == 1) { /* parameters come in pairs: the odd one out */
        if (get_handle(r, a, &i, handle) != 0)
            return -1;
    } else {
        snprintf(handle, sizeof handle, "@%zu", r->n_lights);
    }
    Param *p;
    size_t n;
    if (get_params(r, a, i, &p, &n) != 0)
        return -1;
    static const Counts one = {1, 1, 1, 1};
    if (check_counts(r, p, n, &one) != 0) {
        free(p);
        return -1;
    }
    const char *type = NULL;
    int spot = 0;
    if (strcmp(name, "pointlight") == 0)
        type = "pointlight";
    else if (strcmp(name, "distantlight") == 0)
        type = "distantlight";
    else if (strcmp(name, "spotlight") == 0 || strcmp(name, "shadowspot") == 0)
        type = "spotlight", spot = 1;
    else if (strcmp(name, "ambientlight") == 0)
        type = "ambientlight";
    if (r->rec) {
        warn_once(r, "light in object", "lights inside ObjectBegin are ignored");
        type = NULL;
    } else if (!type) {
        char key[128];
        snprintf(key, sizeof key, "light %s", name);
        warn_once(r, key, "light shader \"%s\" is not built in; the light is skipped", name);
    }
    if (!type) {
        free(p);
        return 0;
    }
    if (r->n_lights >= RIB_MAX_LIGHTS) {
        free(p);
        return rib_error(r, "more than %d lights", RIB_MAX_LIGHTS);
    }
    Light *L = find_light(r, handle);
    if (L && L->index < 0) {
        /* redefined before any geometry saw it: replace */
    } else {
        if (L)
            L->handle[0] = '\0'; /* the old one keeps lighting; the handle moves on */
        Light *nl = realloc(r->lights, (r->n_lights + 1) * sizeof *nl);
        if (!nl) {
            free(p);
            return rib_error(r, "out of memory");
        }
        r->lights = nl;
        L = &r->lights[r->n_lights++];
    }
    memset(L, 0, sizeof *L);
    snprintf(L->handle, sizeof L->handle, "%s", handle);
    snprintf(L->type, sizeof L->type, "%s", type);
    memcpy(L->M, r->a.M, sizeof L->M);
    L->pre_world = !r->in_world;
    L->index = -1;
    set_light_on(&r->a, (size_t)(L - r->lights), 1);
    static const char *const names[] = {"intensity", "lightcolor", "from", "to", "coneangle",
                                        "conedeltaangle", "beamdistribution", "__category", NULL};
    for (size_t k = 0; k < n && L->n < RIB_LIGHT_PARAMS; k++) {
        const Param *q = &p[k];
        if (!in_list(names, q->d.name) || !q->declared)
            continue;
        RayesParam *o = &L->params[L->n];
        snprintf(L->names[L->n], sizeof L->names[0], "%s", q->d.name);
        o->name = L->names[L->n];
        if (q->d.ty == TY_STRING) {
            if (q->v->n != 1)
                continue;
            snprintf(L->category, sizeof L->category, "%s", q->v->s[0]);
            o->type = RAYES_PARAM_STRING;
            o->string = L->category;
        } else if (q->v->n == 3) {
            o->type = RAYES_PARAM_COLOR;
            for (int c = 0; c < 3; c++)
                o->value[c] = (float)q->v->d[c];
        } else if (q->v->n == 1) {
            o->type = RAYES_PARAM_FLOAT;
            o->value[0] = (float)q->v->d[0];
            if (spot && (strcmp(q->d.name, "coneangle") == 0 ||
                         strcmp(q->d.name, "conedeltaangle") == 0))
                o->value[0] = (float)(o->value[0] * 180 / M_PI); /* RenderMan gives radians */
        } else {
            continue;
        }
        L->n++;
    }
    free(p);
    return 0;
}

static int h_area_light(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a light shader name");
    char handle[64];
    if (!name)
        return -1;
    if (i < a->n && (a->n - i) % 2 == 1)
        if (get_handle(r, a, &i, handle) != 0)
            return -1;
    Param *p;
    size_t n;
    if (get_params(r, a, i, &p, &n) != 0)
        return -1;
    const Param *in = find_param(p, n, "intensity"), *lc = find_param(p, n, "lightcolor");
    float I = in && is_num(in->v) && in->v->n == 1 ? (float)in->v->d[0] : 1;
    for (int c = 0; c < 3; c++)
        r->a.area_L[c] = I * (lc && is_num(lc->v) && lc->v->n == 3 ? (float)lc->v->d[c] : 1);
    r->a.area = 1;
    free(p);
    return 0;
}

static int h_illuminate(Rib *r, const Args *a)
{
    size_t i = 0;
    char handle[64];
    float on;
    if (get_handle(r, a, &i, handle) != 0 || get_floats(r, a, &i, &on, 1, "0 or 1") != 0)
        return -1;
    Light *L = find_light(r, handle);
    if (!L)
        return rib_error(r, "no light has the handle %s", handle[0] == '#' ? handle + 1 : handle);
    set_light_on(&r->a, (size_t)(L - r->lights), on != 0);
    return 0;
}

/* At WorldEnd: sends the lights on then that were never sent, and ends
 * the world's lights (the next world starts with none, and all links). */
static int flush_lights(Rib *r)
{
    for (size_t k = 0; k < r->n_lights; k++) {
        Light *L = &r->lights[k];
        if (L->index < 0 && light_on(&r->a, k) && send_light(r, L) != 0)
            return -1;
    }
    r->n_lights = 0;
    memset(r->a.on, 0, sizeof r->a.on);
    r->real.have_M = 0;
    return 0;
}

/* -------------------------------------------------- attributes, options */

static int search_path(Rib *r, const char *kind, const char *path)
{
    if (strcmp(kind, "archive") == 0 || strcmp(kind, "resource") == 0) {
        char out[4096] = "";
        char buf[4096];
        snprintf(buf, sizeof buf, "%s", path);
        for (char *save = NULL, *e = strtok_r(buf, ":", &save); e; e = strtok_r(NULL, ":", &save)) {
            const char *add = strcmp(e, "&") == 0 ? r->archive_path : strcmp(e, "@") == 0 ? "" : e;
            if (!add[0])
                continue;
            size_t len = strlen(out), k = strlen(add);
            if (len + k + 2 > sizeof out)
                break;
            if (len)
                out[len++] = ':';
            memcpy(out + len, add, k + 1);
        }
        snprintf(r->archive_path, sizeof r->archive_path, "%s", out);
    }
    if (strcmp(kind, "shader") == 0 || strcmp(kind, "texture") == 0 ||
        strcmp(kind, "resource") == 0) {
        const IoSink *s = r->sink;
        if (strcmp(kind, "resource") == 0)
            return (s->set_search_path(s->target, "shader", path) != RAYES_OK ||
                    s->set_search_path(s->target, "texture", path) != RAYES_OK)
                       ? sink_failed(r, s)
                       : 0;
        if (s->set_search_path(s->target, kind, path) != RAYES_OK)
            return sink_failed(r, s);
    }
    return 0;
}

/* Option "limits" "gridsize": RenderMan's micropolygons per grid. rayes'
 * grids have at most 64 x 64 micropolygons, so a larger value is clamped. */
static int set_grid_size(Rib *r, double g)
{
    if (!(g >= 1 && g <= 1e9) || g != floor(g))
        return rib_error(r, "Option \"limits\" \"gridsize\": expected a positive integer, "
                            "found %g", g);
    if (g > 4096)
        warn_once(r, "gridsize", "Option \"limits\" \"gridsize\" %.0f: clamped to 4096 "
                                 "(64 x 64 micropolygons)", g);
    r->settings->grid_size = g > 4096 ? 4096 : (int)g;
    return 0;
}

static int h_option_attribute(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *group = get_string(r, a, &i, "a name");
    Param *p;
    size_t n;
    if (!group || get_params(r, a, i, &p, &n) != 0)
        return -1;
    int option = strcmp(r->req, "Option") == 0, e = 0;
    for (size_t k = 0; k < n && e == 0; k++) {
        const Param *q = &p[k];
        if (option && strcmp(group, "searchpath") == 0 && q->v->kind != ARG_NUM &&
            q->v->kind != ARG_NUMS && q->v->n == 1) {
            e = search_path(r, q->d.name, q->v->s[0]);
        } else if (!option && strcmp(group, "displacementbound") == 0 &&
                   strcmp(q->d.name, "sphere") == 0 && is_num(q->v) && q->v->n == 1) {
            r->a.bound = (float)fabs(q->v->d[0]);
        } else if (!option && strcmp(group, "trace") == 0 && is_num(q->v) && q->v->n == 1 &&
                   (strcmp(q->d.name, "maxdiffusedepth") == 0 ||
                    strcmp(q->d.name, "maxspeculardepth") == 0)) {
            /* PRMan's ray depths; rayes has one per render, so the last wins */
            double d = q->v->d[0]; /* NaN (a binary float) counts as 0 */
            int depth = !(d > 0) ? 0 : d > 1e6 ? 1000000 : (int)d;
            if (q->d.name[3] == 'd')
                r->settings->bounces = depth;
            else
                r->settings->specular_depth = depth;
        } else if (option && strcmp(group, "limits") == 0 &&
                   strcmp(q->d.name, "gridsize") == 0 && is_num(q->v) && q->v->n == 1) {
            e = set_grid_size(r, q->v->d[0]);
        } else if (!option && strcmp(group, "identifier") == 0) {
            /* names are for messages only */
        } else if (!(!option && strcmp(group, "displacementbound") == 0)) {
            char key[160];
            snprintf(key, sizeof key, "%s %s:%s", r->req, group, q->d.name);
            warn_once(r, key, "%s \"%s\" \"%s\" is not supported and ignored", r->req, group,
                      q->d.name);
        }
    }
    free(p);
    return e;
}

static int h_declare(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "a parameter name");
    const char *decl = name ? get_string(r, a, &i, "a declaration") : NULL;
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

/* ----------------------------------------------------------- geometry */

static int h_polygon(Rib *r, const Args *a)
{
    Param *p;
    size_t n, np = 0;
    if (get_params(r, a, 0, &p, &n) != 0)
        return -1;
    float *P = get_points(r, p, n, &np);
    int e = P ? 0 : -1;
    Counts c = {1, np, np, np};
    if (e == 0 && np < 3)
        e = rib_error(r, "a polygon needs at least 3 points, found %zu", np);
    if (e == 0)
        e = check_counts(r, p, n, &c);
    int *idx = e == 0 ? malloc(np * sizeof *idx) : NULL;
    if (e == 0 && !idx)
        e = rib_error(r, "out of memory");
    if (e == 0) {
        for (size_t k = 0; k < np; k++)
            idx[k] = (int)k;
        int nv = (int)np;
        Polys g = {1, NULL, &nv, idx};
        warn_unused(r, p, n);
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
    if (get_ints(r, a, &i, &loops, &nl, 3, 1 << 24, "vertices per loop") != 0)
        return -1;
    int e = get_params(r, a, i, &p, &n);
    float *P = e == 0 ? get_points(r, p, n, &np) : NULL;
    if (e == 0 && !P)
        e = -1;
    size_t total = 0;
    for (size_t k = 0; k < nl; k++)
        total += (size_t)loops[k];
    Counts c = {1, np, np, np};
    if (e == 0 && (nl == 0 || total != np))
        e = rib_error(r, "the loops have %zu vertices but \"P\" gives %zu points", total, np);
    if (e == 0)
        e = check_counts(r, p, n, &c);
    int *idx = e == 0 ? malloc(np * sizeof *idx) : NULL;
    if (e == 0 && !idx)
        e = rib_error(r, "out of memory");
    if (e == 0) {
        for (size_t k = 0; k < np; k++)
            idx[k] = (int)k;
        int nlo = (int)nl;
        Polys g = {1, &nlo, loops, idx};
        warn_unused(r, p, n);
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
        e = get_ints(r, a, &i, &nloops, &n_polys, 1, 1 << 24, "loops per polygon");
    if (e == 0)
        e = get_ints(r, a, &i, &nverts, &n_loops, 3, 1 << 24, "vertices per polygon");
    if (e == 0)
        e = get_ints(r, a, &i, &verts, &n_idx, 0, 1 << 30, "vertex indices");
    if (e == 0 && r->req[0] == 'S' && i < a->n && a->v[i].kind != ARG_STR)
        i += 4; /* SubdivisionMesh: tags nargs intargs floatargs */
    if (e == 0)
        e = get_params(r, a, i, &p, &n);
    if (e == 0 && !(P = get_points(r, p, n, &np)))
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
        e = check_counts(r, p, n, &c);
    if (e == 0) {
        Polys g = {n_polys, general ? nloops : NULL, nverts, verts};
        warn_unused(r, p, n);
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

static int h_subdivision_mesh(Rib *r, const Args *a)
{
    size_t i = 0;
    if (!get_string(r, a, &i, "a subdivision scheme"))
        return -1;
    warn_once(r, "SubdivisionMesh", "SubdivisionMesh is rendered as its control polygons");
    return points_polygons(r, a, i, 0);
}

static int emit_bicubic(Rib *r, float B[16][3], const PvOut *pv)
{
    if (flip_of(r))
        for (int j = 0; j < 4; j++)
            for (int k = 0; k < 2; k++)
                for (int c = 0; c < 3; c++) {
                    float t = B[4 * j + k][c];
                    B[4 * j + k][c] = B[4 * j + 3 - k][c];
                    B[4 * j + 3 - k][c] = t;
                }
    int e = emit_begin(r, NULL);
    if (e != 0)
        return e > 0 ? 0 : -1;
    SinkState *st;
    const IoSink *s = out_sink(r, &st);
    return s->bicubic_patch(s->target, (const float(*)[3])B, pv->pv, pv->n) == RAYES_OK
               ? 0
               : sink_failed(r, s);
}

static int emit_bilinear(Rib *r, const float P[4][3], const PvOut *pv)
{
    float Q[4][3];
    int flip = flip_of(r);
    for (int k = 0; k < 4; k++)
        memcpy(Q[flip ? k ^ 1 : k], P[k], sizeof Q[0]);
    int e = emit_begin(r, NULL);
    if (e != 0)
        return e > 0 ? 0 : -1;
    SinkState *st;
    const IoSink *s = out_sink(r, &st);
    if (r->a.area) {
        float A[4][3];
        memcpy(A[0], Q[0], sizeof A[0]);
        memcpy(A[1], Q[1], sizeof A[0]);
        memcpy(A[2], Q[3], sizeof A[0]);
        memcpy(A[3], Q[2], sizeof A[0]);
        return s->area_light(s->target, (const float(*)[3])A, r->a.area_L) == RAYES_OK
                   ? 0
                   : sink_failed(r, s);
    }
    return s->bilinear_patch(s->target, (const float(*)[3])Q, pv->pv, pv->n) == RAYES_OK
               ? 0
               : sink_failed(r, s);
}

/* The colour of a quadric: Cs constant/uniform (index u_index), or the
 * average of the given varying/vertex indices (quadrics take no primitive
 * variables). */
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
    warn_once(r, "vertex Cs", "per-vertex colours (Cs) of quadrics are averaged: quadrics take "
                              "one colour");
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
    const char *type = get_string(r, a, &i, "\"bilinear\" or \"bicubic\"");
    Param *p;
    if (!type || get_params(r, a, i, &p, &n) != 0)
        return -1;
    int cubic = strcmp(type, "bicubic") == 0;
    int e = 0;
    if (!cubic && strcmp(type, "bilinear") != 0)
        e = rib_error(r, "expected \"bilinear\" or \"bicubic\", found \"%s\"", type);
    float *P = e == 0 ? get_points(r, p, n, &np) : NULL;
    if (e == 0 && !P)
        e = -1;
    size_t want = cubic ? 16 : 4;
    if (e == 0 && np != want)
        e = rib_error(r, "a %s patch needs %zu points, found %zu", type, want, np);
    Counts c = {1, 4, want, 4};
    if (e == 0)
        e = check_counts(r, p, n, &c);
    RibVar vars[3];
    PvOut pv = {0};
    if (e == 0) {
        warn_unused(r, p, n);
        rib_vars(r, p, n, vars);
        static const size_t corners[4] = {0, 1, 2, 3};
        static const size_t all[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
        e = patch_vars(r, vars, 0, corners, corners, all, (int)want, flip_of(r), &pv);
    }
    if (e == 0) {
        if (cubic) {
            float B[16][3];
            rib_basis_to_bezier(r->a.ubasis, r->a.vbasis, (const float(*)[3])P, B);
            e = emit_bicubic(r, B, &pv);
        } else {
            e = emit_bilinear(r, (const float(*)[3])P, &pv);
        }
    }
    pv_out_free(&pv);
    free(P);
    free(p);
    return e;
}

static int wrap_of(Rib *r, const char *s, int *periodic)
{
    if (strcmp(s, "periodic") == 0)
        *periodic = 1;
    else if (strcmp(s, "nonperiodic") == 0)
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
    const char *type = get_string(r, a, &i, "\"bilinear\" or \"bicubic\"");
    float nuv[2];
    const char *uw, *vw;
    int up = 0, vp = 0;
    if (!type || get_floats(r, a, &i, nuv, 1, "nu") != 0 ||
        !(uw = get_string(r, a, &i, "\"periodic\" or \"nonperiodic\"")) ||
        get_floats(r, a, &i, nuv + 1, 1, "nv") != 0 ||
        !(vw = get_string(r, a, &i, "\"periodic\" or \"nonperiodic\"")) ||
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
    if (get_params(r, a, i, &p, &n) != 0)
        return -1;
    float *P = get_points(r, p, n, &np);
    int e = P ? 0 : -1;
    if (e == 0 && np != (size_t)(nu * nv))
        e = rib_error(r, "\"P\" needs %ld x %ld = %ld points, found %zu", nu, nv, nu * nv, np);
    long nuvar = cubic ? nup + !up : nu, nvvar = cubic ? nvp + !vp : nv;
    Counts c = {(size_t)(nup * nvp), (size_t)(nuvar * nvvar), np, (size_t)(nup * nvp * 4)};
    if (e == 0)
        e = check_counts(r, p, n, &c);
    RibVar vars[3];
    if (e == 0) {
        warn_unused(r, p, n);
        rib_vars(r, p, n, vars);
    }
    int flip = flip_of(r);
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
                e = emit_bicubic(r, B, &out);
            } else if (e == 0) {
                e = emit_bilinear(r, (const float(*)[3])G, &out);
            }
            if (e == 0)
                pv_out_free(&out);
        }
    free(P);
    free(p);
    return e;
}

static int get_basis(Rib *r, const Args *a, size_t *i, float m[16])
{
    if (*i < a->n && a->v[*i].kind == ARG_STR) {
        int step;
        const char *name = a->v[(*i)++].s[0];
        if (rib_basis_named(name, m, &step) != 0)
            return rib_error(r, "unknown basis \"%s\" (bezier, b-spline, catmull-rom, hermite, "
                                "power or 16 numbers)", name);
        return 0;
    }
    return get_floats(r, a, i, m, 16, "a basis name or matrix");
}

static int h_basis(Rib *r, const Args *a)
{
    size_t i = 0;
    float ub[16], vb[16], us, vs;
    if (get_basis(r, a, &i, ub) != 0 || get_floats(r, a, &i, &us, 1, "the u step") != 0 ||
        get_basis(r, a, &i, vb) != 0 || get_floats(r, a, &i, &vs, 1, "the v step") != 0)
        return -1;
    if (!(us >= 1 && us <= 4 && vs >= 1 && vs <= 4) || us != floorf(us) || vs != floorf(vs))
        return rib_error(r, "steps must be integers from 1 to 4");
    memcpy(r->a.ubasis, ub, sizeof ub);
    memcpy(r->a.vbasis, vb, sizeof vb);
    r->a.ustep = (int)us;
    r->a.vstep = (int)vs;
    return 0;
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
    if (get_floats(r, a, &i, v, (size_t)q[k].n, q[k].what) != 0 || get_params(r, a, i, &p, &n) != 0)
        return -1;
    Counts c = {1, 4, 4, 4};
    int e = check_counts(r, p, n, &c);
    if (e == 0) {
        warn_unused(r, p, n);
        static const size_t corners[4] = {0, 1, 2, 3};
        float col[3];
        const float *Cs = patch_color(r, color_param(r, p, n), 0, corners, 4, corners, 4, col);
        e = emit_begin(r, Cs);
        if (e == 0) {
            SinkState *st;
            const IoSink *s = out_sink(r, &st);
            if (s->quadric(s->target, q[k].type, v, (size_t)q[k].n,
                           flip_of(r) ? RAYES_QUADRIC_REVERSE : 0) != RAYES_OK)
                e = sink_failed(r, s);
        }
        e = e > 0 ? 0 : e;
    }
    free(p);
    return e;
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
    if (emit_bicubic(tt->r, B, &none) != 0) {
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
    const char *name = get_string(r, a, &i, "a geometry name");
    if (!name)
        return -1;
    if (strcmp(name, "teapot") != 0) {
        char key[128];
        snprintf(key, sizeof key, "geometry %s", name);
        warn_once(r, key, "Geometry \"%s\" is not supported and skipped", name);
        return 0;
    }
    if (!r->opt || !r->opt->data_dir) {
        warn_once(r, "teapot", "Geometry \"teapot\" needs the data directory (teapot.bpt); skipped");
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

/* ------------------------------------------------------------ objects */

static Object *find_object(Rib *r, const char *key)
{
    for (size_t k = 0; k < r->n_objects; k++)
        if (strcmp(r->objects[k].key, key) == 0)
            return &r->objects[k];
    return NULL;
}

static int h_object_begin(Rib *r, const Args *a)
{
    size_t i = 0;
    if (r->rec)
        return rib_error(r, "ObjectBegin inside an object definition");
    if (get_handle(r, a, &i, r->rec_key) != 0)
        return -1;
    r->rec = rib_recording_new();
    if (!r->rec)
        return rib_error(r, "out of memory");
    r->rec_sink = rib_recording_sink(r->rec);
    memset(&r->recorded, 0, sizeof r->recorded);
    memcpy(r->rec_saved_M, r->a.M, sizeof r->rec_saved_M);
    rib_mat_identity(r->a.M);
    return push(r, 1);
}

static int h_object_end(Rib *r, const Args *a)
{
    (void)a;
    if (!r->rec)
        return rib_error(r, "ObjectEnd without ObjectBegin");
    pop(r, 1);
    memcpy(r->a.M, r->rec_saved_M, sizeof r->a.M);
    Object *o = find_object(r, r->rec_key);
    if (!o) {
        if (r->n_objects >= 65536)
            return rib_error(r, "more than 65536 objects");
        Object *no = realloc(r->objects, (r->n_objects + 1) * sizeof *no);
        if (!no)
            return rib_error(r, "out of memory");
        r->objects = no;
        o = &r->objects[r->n_objects++];
        snprintf(o->key, sizeof o->key, "%s", r->rec_key);
    } else {
        rib_recording_free(o->rec);
    }
    o->rec = r->rec;
    r->rec = NULL;
    return 0;
}

static int h_object_instance(Rib *r, const Args *a)
{
    size_t i = 0;
    char key[64];
    if (get_handle(r, a, &i, key) != 0)
        return -1;
    Object *o = find_object(r, key);
    if (!o)
        return rib_error(r, "no object has the handle %s", key[0] == '#' ? key + 1 : key);
    if (r->rec)
        return rib_error(r, "ObjectInstance inside an object definition");
    if (!r->in_world) {
        warn_once(r, "outside world", "geometry outside WorldBegin/WorldEnd is ignored");
        return 0;
    }
    if (send_lights(r) != 0)
        return -1;
    RayesError e = rib_recording_replay(o->rec, r->sink, r->a.M);
    memset(&r->real, 0, sizeof r->real); /* the replay changed the sink's state */
    return e == RAYES_OK ? 0 : sink_failed(r, r->sink);
}

/* ---------------------------------------------------- structure, files */

static int run(Rib *r, const char *name, const unsigned char *data, size_t size);

/* Archives must be regular files (not devices or pipes, which could
 * stream forever). */
static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static int read_archive(Rib *r, const char *name)
{
    if (r->archive_depth >= RIB_MAX_ARCHIVE_DEPTH)
        return rib_error(r, "archives nested more than %d deep (a loop?)", RIB_MAX_ARCHIVE_DEPTH);
    char path[4096] = "";
    if (name[0] == '/') {
        snprintf(path, sizeof path, "%s", name);
    } else {
        const char *slash = strrchr(r->file, '/');
        int dir = slash ? (int)(slash - r->file) : 0;
        snprintf(path, sizeof path, "%.*s%s%s", dir, r->file, slash ? "/" : "", name);
        if (!file_exists(path)) {
            char buf[4096];
            snprintf(buf, sizeof buf, "%s", r->archive_path);
            for (char *save = NULL, *d = strtok_r(buf, ":", &save); d;
                 d = strtok_r(NULL, ":", &save)) {
                char cand[4096];
                snprintf(cand, sizeof cand, "%s/%s", d, name);
                if (file_exists(cand)) {
                    snprintf(path, sizeof path, "%s", cand);
                    break;
                }
            }
        }
    }
    char err[600];
    size_t size;
    if (!file_exists(path))
        return rib_error(r, "archive \"%s\": not found (as %s, nor on the archive search path)",
                         name, path);
    unsigned char *data = read_gz(path, &size, err, sizeof err);
    if (!data)
        return rib_error(r, "archive \"%s\": %s", name, err);
    RibLexer *outer = r->lx;
    const char *outer_file = r->file;
    char req[64];
    long line = r->req_line, col = r->req_col;
    memcpy(req, r->req, sizeof req);
    r->archive_depth++;
    char *path_copy = dup_string(path);
    int e = path_copy ? run(r, path_copy, data, size) : rib_error(r, "out of memory");
    r->archive_depth--;
    r->lx = outer;
    r->file = outer_file;
    memcpy(r->req, req, sizeof req);
    r->req_line = line, r->req_col = col;
    free(path_copy);
    free(data);
    return e;
}

static int h_read_archive(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *name = get_string(r, a, &i, "an archive name");
    return name ? read_archive(r, name) : -1;
}

static int h_procedural(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *kind = get_string(r, a, &i, "a procedural name");
    if (!kind)
        return -1;
    if (strcmp(kind, "DelayedReadArchive") == 0 && i < a->n && a->v[i].kind == ARG_STRS &&
        a->v[i].n >= 1)
        return read_archive(r, a->v[i].s[0]);
    char key[128];
    snprintf(key, sizeof key, "procedural %s", kind);
    warn_once(r, key, "Procedural \"%s\" is not supported and skipped", kind);
    return 0;
}

static int h_world_begin(Rib *r, const Args *a)
{
    (void)a;
    if (r->in_world)
        return rib_error(r, "WorldBegin inside a world block");
    if (r->pass == 1 && r->in_frame && r->n_frames > 0)
        r->frames[r->n_frames - 1].renders |= !r->shadow_display;
    if (r->worlds++ > 0 && !r->in_frame)
        warn_once(r, "worlds", "several world blocks outside frames are read into one scene");
    memcpy(r->camera_from_world, r->a.M, sizeof r->a.M);
    rib_mat_identity(r->a.M);
    r->in_world = 1;
    float sw[4];
    const float *screen = NULL;
    if (r->have_screen) {
        screen = r->screen;
    } else if (r->frame_aspect > 0) {
        float fa = r->frame_aspect;
        float s[4] = {-fa, fa, -1, 1}, t[4] = {-1, 1, -1 / fa, 1 / fa};
        memcpy(sw, fa >= 1 ? s : t, sizeof sw);
        screen = sw;
    }
    const IoSink *s = r->sink;
    if (s->set_camera_matrix(s->target, r->camera_from_world, (RayesProjection)r->projection,
                             r->fov, screen) != RAYES_OK)
        return sink_failed(r, s);
    float wc[16];
    world_from_camera(r, wc);
    for (size_t k = 0; k < r->n_lights; k++)
        if (r->lights[k].pre_world) {
            rib_mat_mul(wc, r->lights[k].M, r->lights[k].M);
            r->lights[k].pre_world = 0;
        }
    memset(&r->real, 0, sizeof r->real);
    return 0;
}

static int h_world_end(Rib *r, const Args *a)
{
    (void)a;
    if (!r->in_world)
        return rib_error(r, "WorldEnd without WorldBegin");
    r->in_world = 0;
    memcpy(r->a.M, r->camera_from_world, sizeof r->a.M);
    return flush_lights(r);
}

static int h_frame_begin(Rib *r, const Args *a)
{
    size_t i = 0;
    float n = 0;
    if (i < a->n && get_floats(r, a, &i, &n, 1, "a frame number") != 0)
        return -1;
    if (!(fabsf(n) <= 1e9f) || n != floorf(n))
        return rib_error(r, "the frame number must be an integer, found %g", n);
    if (r->in_frame)
        return rib_error(r, "FrameBegin inside a frame");
    long ordinal = r->frame_ordinal++;
    r->in_frame = 1;
    if (r->pass == 1) {
        Frame *f = realloc(r->frames, (r->n_frames + 1) * sizeof *f);
        if (!f)
            return rib_error(r, "out of memory");
        r->frames = f;
        r->frames[r->n_frames++] = (Frame){(long)n, 0};
        r->frame_saved = *r->settings;
        r->frame_saved_shadow = r->shadow_display;
    } else if (ordinal != r->selected) {
        r->skipping = 1;
    }
    return 0;
}

static int h_frame_end(Rib *r, const Args *a)
{
    (void)a;
    if (!r->in_frame)
        return rib_error(r, "FrameEnd without FrameBegin");
    r->in_frame = 0;
    if (r->pass == 1) { /* frames keep their options to themselves */
        *r->settings = r->frame_saved;
        r->shadow_display = r->frame_saved_shadow;
    } else if (!r->skipping) {
        r->done = 1; /* the selected frame is read */
    }
    r->skipping = 0;
    return 0;
}

static int h_motion_begin(Rib *r, const Args *a)
{
    (void)a;
    warn_once(r, "MotionBegin", "motion blur is not supported: the first sample of each motion "
                                "block is used");
    r->motion = 1;
    r->motion_seen = 0;
    return 0;
}

static int h_nothing(Rib *r, const Args *a)
{
    (void)r, (void)a;
    return 0;
}

static int h_skip(Rib *r, const Args *a)
{
    (void)a;
    char key[96];
    snprintf(key, sizeof key, "request %s", r->req);
    warn_once(r, key, "%s is not supported; read and skipped", r->req);
    return 0;
}

static int h_archive_begin(Rib *r, const Args *a)
{
    h_skip(r, a);
    r->archive_block = 1;
    return 0;
}

typedef struct Request {
    const char *name;
    Handler fn;
} Request;

static const Request requests[] = {
    {"version", h_nothing}, {"ErrorHandler", h_nothing}, {"FrameBegin", h_frame_begin},
    {"FrameEnd", h_frame_end}, {"WorldBegin", h_world_begin}, {"WorldEnd", h_world_end},
    {"AttributeBegin", h_attribute_begin}, {"AttributeEnd", h_attribute_end},
    {"TransformBegin", h_transform_begin}, {"TransformEnd", h_transform_end},
    {"Identity", h_identity}, {"Transform", h_transform}, {"ConcatTransform", h_concat},
    {"Translate", h_translate}, {"Rotate", h_rotate}, {"Scale", h_scale},
    {"Perspective", h_perspective}, {"CoordinateSystem", h_coordinate_system},
    {"ScopedCoordinateSystem", h_coordinate_system}, {"CoordSysTransform", h_coordsys_transform},
    {"Format", h_format}, {"FrameAspectRatio", h_frame_aspect}, {"ScreenWindow", h_screen_window},
    {"CropWindow", h_crop_window}, {"Projection", h_projection}, {"Clipping", h_clipping},
    {"PixelSamples", h_pixel_samples}, {"PixelFilter", h_pixel_filter},
    {"PixelVariance", h_one_float}, {"Exposure", h_exposure}, {"Quantize", h_quantize},
    {"Display", h_display}, {"Hider", h_hider}, {"ShadingRate", h_shading_rate},
    {"Sides", h_sides}, {"Orientation", h_orientation},
    {"ReverseOrientation", h_reverse_orientation}, {"Color", h_color}, {"Opacity", h_color},
    {"Surface", h_surface}, {"Displacement", h_displacement}, {"LightSource", h_light_source},
    {"AreaLightSource", h_area_light}, {"Illuminate", h_illuminate},
    {"Attribute", h_option_attribute}, {"Option", h_option_attribute}, {"Declare", h_declare},
    {"ReadArchive", h_read_archive}, {"ObjectBegin", h_object_begin},
    {"ObjectEnd", h_object_end}, {"ObjectInstance", h_object_instance}, {"Polygon", h_polygon},
    {"GeneralPolygon", h_general_polygon}, {"PointsPolygons", h_points_polygons},
    {"PointsGeneralPolygons", h_points_general_polygons}, {"Patch", h_patch},
    {"PatchMesh", h_patch_mesh}, {"Basis", h_basis}, {"Sphere", h_quadric},
    {"Cylinder", h_quadric}, {"Cone", h_quadric}, {"Disk", h_quadric}, {"Torus", h_quadric},
    {"Hyperboloid", h_quadric}, {"Paraboloid", h_quadric}, {"Geometry", h_geometry},
    {"SubdivisionMesh", h_subdivision_mesh}, {"Procedural", h_procedural},
    {"MotionBegin", h_motion_begin}, {"ArchiveBegin", h_archive_begin},
    /* tier 1 and 2: read and skipped with one warning per request name */
    {"NuPatch", h_skip}, {"TrimCurve", h_skip}, {"Points", h_skip}, {"Curves", h_skip},
    {"Blobby", h_skip}, {"HierarchicalSubdivisionMesh", h_skip}, {"Procedural2", h_skip},
    {"Bxdf", h_skip}, {"Light", h_skip}, {"Pattern", h_skip}, {"Integrator", h_skip},
    {"DisplayChannel", h_skip}, {"DisplayFilter", h_skip}, {"SampleFilter", h_skip},
    {"Camera", h_skip}, {"Shutter", h_skip}, {"DepthOfField", h_skip}, {"MakeShadow", h_skip},
    {"MakeTexture", h_skip}, {"MakeBump", h_skip}, {"MakeCubeFaceEnvironment", h_skip},
    {"MakeLatLongEnvironment", h_skip}, {"MakeBrickMap", h_skip}, {"Imager", h_skip},
    {"Atmosphere", h_skip}, {"Interior", h_skip}, {"Exterior", h_skip}, {"Deformation", h_skip},
    {"Detail", h_skip}, {"DetailRange", h_skip}, {"RelativeDetail", h_skip},
    {"GeometricApproximation", h_skip}, {"ShadingInterpolation", h_skip},
    {"SolidBegin", h_skip}, {"SolidEnd", h_skip}, {"ShaderLayer", h_skip},
    {"ConnectShaderLayers", h_skip}, {"Shader", h_skip}, {"IfBegin", h_skip},
    {"ElseIf", h_skip}, {"Else", h_skip}, {"IfEnd", h_skip}, {"Matte", h_skip},
    {"TextureCoordinates", h_skip}, {"Bound", h_skip}, {"ColorSamples", h_skip},
    {"ClippingPlane", h_skip}, {"Skew", h_skip}, {"Resource", h_skip},
    {"ResourceBegin", h_skip}, {"ResourceEnd", h_skip}, {"System", h_skip},
    {"PixelSampleImager", h_skip}, {"ArchiveRecord", h_nothing}, {"EditBegin", h_skip},
    {"EditEnd", h_skip}, {"CameraBegin", h_skip}, {"CameraEnd", h_skip},
};

static int dispatch(Rib *r, const Args *a)
{
    const char *q = r->req;
    if (r->done)
        return 0;
    if (r->archive_block) {
        if (strcmp(q, "ArchiveEnd") == 0)
            r->archive_block = 0;
        return 0;
    }
    if (r->skipping && strcmp(q, "FrameEnd") != 0)
        return 0;
    if (r->motion) {
        if (strcmp(q, "MotionEnd") == 0) {
            r->motion = 0;
            return 0;
        }
        if (r->motion_seen++ > 0)
            return 0;
    } else if (strcmp(q, "MotionEnd") == 0) {
        return rib_error(r, "MotionEnd without MotionBegin");
    }
    for (size_t k = 0; k < sizeof requests / sizeof requests[0]; k++)
        if (strcmp(requests[k].name, q) == 0)
            return requests[k].fn(r, a);
    return rib_error(r, "unknown request (expected a RIB request such as WorldBegin or Polygon)");
}

static int run(Rib *r, const char *name, const unsigned char *data, size_t size)
{
    RibLexer lx;
    rib_lex_init(&lx, name, data, size, r->err, r->err_size);
    r->lx = &lx;
    r->file = name;
    Args args = {0};
    RibToken t;
    int e = rib_lex_next(&lx, &t);
    while (e == 0 && t.type != RIB_TOK_EOF) {
        if (t.type != RIB_TOK_REQUEST) {
            e = rib_lex_error_at(&lx, t.line, t.col, "expected a request name, found %s",
                                 t.type == RIB_TOK_STRING ? "a string" :
                                 t.type == RIB_TOK_LBRACKET ? "'['" : "a number");
            break;
        }
        snprintf(r->req, sizeof r->req, "%s", t.str);
        r->req_line = t.line;
        r->req_col = t.col;
        args_clear(&args);
        e = read_args(r, &args, &t);
        if (e == 0)
            e = dispatch(r, &args);
    }
    args_clear(&args);
    free(args.v);
    rib_lex_fini(&lx);
    r->lx = NULL;
    return e;
}

/* --------------------------------------------------------------- entry */

static RayesError null_camera(void *t, const float *e, const float *a, const float *u, float f)
{
    (void)t, (void)e, (void)a, (void)u, (void)f;
    return RAYES_OK;
}
static RayesError null_camera_matrix(void *t, const float m[16], RayesProjection p, float f,
                                     const float s[4])
{
    (void)t, (void)m, (void)p, (void)f, (void)s;
    return RAYES_OK;
}
static RayesError null_matrix(void *t, const float m[16]) { (void)t, (void)m; return RAYES_OK; }
static RayesError null_named(void *t, const char *n, const RayesParam *p, size_t k)
{
    (void)t, (void)n, (void)p, (void)k;
    return RAYES_OK;
}
static RayesError null_float(void *t, float f) { (void)t, (void)f; return RAYES_OK; }
static RayesError null_path(void *t, const char *k, const char *p)
{
    (void)t, (void)k, (void)p;
    return RAYES_OK;
}
static RayesError null_p4(void *t, const float P[4][3], const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_p16(void *t, const float P[16][3], const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_mesh(void *t, size_t nf, const int *nv, const int *ix, size_t np,
                            const float *P, const RayesPrimvar *pv, size_t n)
{
    (void)t, (void)nf, (void)nv, (void)ix, (void)np, (void)P, (void)pv, (void)n;
    return RAYES_OK;
}
static RayesError null_quadric(void *t, RayesQuadric q, const float *p, size_t n, unsigned f)
{
    (void)t, (void)q, (void)p, (void)n, (void)f;
    return RAYES_OK;
}
static RayesError null_area(void *t, const float P[4][3], const float L[3])
{
    (void)t, (void)P, (void)L;
    return RAYES_OK;
}
static RayesError null_links(void *t, RayesLightLinks m, const size_t *l, size_t n)
{
    (void)t, (void)m, (void)l, (void)n;
    return RAYES_OK;
}
static size_t null_count(void *t) { (void)t; return 0; }
static const char *null_error(void *t) { (void)t; return ""; }

static const IoSink null_sink = {NULL,        null_camera, null_camera_matrix, null_matrix,
                                 null_named,  null_named,  null_float,         null_path,
                                 null_float,  null_p4,     null_p16,           null_mesh,
                                 null_float,  null_quadric, null_area,         null_named,
                                 null_links,  null_count,  null_error};

static void rib_init(Rib *r, int pass, const IoSink *sink, const IoReadOptions *opt,
                     IoSettings *settings, char *err, size_t err_size)
{
    memset(r, 0, sizeof *r);
    r->pass = pass;
    r->sink = sink;
    r->opt = opt;
    r->settings = settings;
    r->err = err;
    r->err_size = err_size;
    rib_mat_identity(r->a.M);
    rib_mat_identity(r->camera_from_world);
    memcpy(r->a.Cs, white, sizeof white);
    memcpy(r->a.Os, white, sizeof white);
    r->a.shading_rate = 1;
    int step;
    rib_basis_named("bezier", r->a.ubasis, &step);
    rib_basis_named("bezier", r->a.vbasis, &step);
    r->a.ustep = r->a.vstep = step;
    r->projection = RAYES_PROJECTION_ORTHOGRAPHIC; /* RenderMan's default */
    r->fov = 90;
    r->selected = -1;
    r->top_name = "";
}

static void rib_fini(Rib *r)
{
    free(r->stack);
    while (r->shaders) {
        ShaderRec *s = r->shaders;
        r->shaders = s->next;
        for (size_t i = 0; i < s->n; i++) {
            free((char *)s->params[i].name);
            free((char *)s->params[i].string);
        }
        free(s->params);
        free(s);
    }
    free(r->decls);
    free(r->lights);
    free(r->links);
    for (size_t k = 0; k < r->n_objects; k++)
        rib_recording_free(r->objects[k].rec);
    free(r->objects);
    rib_recording_free(r->rec);
    free(r->coordsys_names);
    free(r->coordsys_M);
    free(r->coordsys_world);
    free(r->frames);
    for (size_t k = 0; k < r->n_warned; k++)
        free(r->warned[k]);
}

RayesError io_rib_parse(const char *name, const unsigned char *data, size_t size,
                        const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                        char *err, size_t err_size)
{
    if (err_size)
        err[0] = '\0';
    unsigned char *inflated = NULL;
    if (size >= 2 && data[0] == 0x1f && data[1] == 0x8b) {
        size_t n;
        inflated = inflate_buffer(data, size, &n);
        if (!inflated) {
            snprintf(err, err_size, "%s: not a valid gzip stream", name);
            return RAYES_ERROR_PARSE;
        }
        data = inflated;
        size = n;
    }
    static const unsigned char empty[1] = {0};
    if (!data)
        data = empty, size = 0;
    /* pass 1: check everything, list the frames */
    IoSettings scratch;
    io_settings_init(&scratch);
    Rib r;
    rib_init(&r, 1, &null_sink, options, &scratch, err, err_size);
    r.top_name = name;
    int e = run(&r, name, data, size);
    if (e == 0 && r.rec)
        e = rib_error(&r, "the file ends inside an object definition (ObjectBegin)");
    long selected = -1;
    int frame = options ? options->frame : -1;
    if (e == 0 && r.n_frames > 0) {
        for (size_t k = 0; k < r.n_frames; k++)
            if (frame >= 0 ? r.frames[k].number == frame && selected < 0 : r.frames[k].renders)
                selected = (long)k;
        if (selected < 0 && frame < 0)
            selected = (long)r.n_frames - 1;
        if (selected < 0) {
            snprintf(err, err_size, "%s: the file has no frame %d (FrameBegin %d)", name, frame,
                     frame);
            e = -1;
        }
    } else if (e == 0 && frame >= 0) {
        snprintf(err, err_size, "%s: the file has no frames (FrameBegin), so no frame %d", name,
                 frame);
        e = -1;
    }
    rib_fini(&r);
    if (e == 0) { /* pass 2: the selected frame into the sink */
        rib_init(&r, 2, sink, options, settings, err, err_size);
        r.top_name = name;
        r.selected = selected;
        e = run(&r, name, data, size);
        if (e == 0 && r.n_lights > 0)
            e = flush_lights(&r); /* a file without WorldEnd */
        rib_fini(&r);
    }
    free(inflated);
    for (char *c = err; e != 0 && *c; c++) /* names from the file may hold newlines */
        if ((unsigned char)*c < 0x20 || *c == 0x7f)
            *c = '?';
    return e == 0 ? RAYES_OK : RAYES_ERROR_PARSE;
}

RayesError io_rib_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                       IoSettings *settings, char *err, size_t err_size)
{
    size_t size;
    unsigned char *data = read_gz(path, &size, err, err_size);
    if (!data)
        return RAYES_ERROR_IO;
    RayesError e = io_rib_parse(path, data, size, sink, options, settings, err, err_size);
    free(data);
    return e;
}
