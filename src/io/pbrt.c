/*
 * io/pbrt.c — the pbrt-v4 scene reader of pbrt.h (docs/pbrt.md says what
 * is supported, mapped, warned about and skipped).
 *
 * A lexer per file (Include and Import open nested ones) gives tokens —
 * bare words, quoted strings, brackets — with their line and column. Each
 * directive reads its fixed arguments, then a parameter list of
 * `"type name" value|[values]` pairs; after a directive is handled every
 * parameter nobody asked for gets one warning (pbrt's own rule).
 *
 * The graphics state (transform, orientation, material, area light) lives
 * in a stack for AttributeBegin/End and TransformBegin/End. Geometry goes
 * to the sink through emit_*; between ObjectBegin and ObjectEnd the same
 * calls are recorded instead, with their transform and material, and
 * ObjectInstance replays them under the instance's transform.
 *
 * Limits keep bad input cheap: include depth and file count, stack depth,
 * replayed primitives; every index is checked before it is used. Warnings
 * go to standard error once per kind and per read.
 */
#include "io/pbrt.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/ply.h"
#include "io/text.h"
#include "util/log.h"

#define PBRT_MAX_INCLUDE_DEPTH 16
#define PBRT_MAX_FILES 256
#define PBRT_MAX_STACK 1024
#define PBRT_MAX_WARNED 512
#define PBRT_MAX_REPLAYED 10000000L /* primitives emitted by ObjectInstance, in all */
#define PBRT_PATH 1024
#define MAT_MAX_PARAMS 8

static const double PI = 3.14159265358979323846;

/* ------------------------------------------------------------ types */

typedef enum TokKind { TOK_END, TOK_WORD, TOK_STRING, TOK_LBRACKET, TOK_RBRACKET } TokKind;

typedef struct Token {
    TokKind kind;
    const char *s; /* the word, or the inside of the quotes (escapes not yet resolved) */
    size_t n;
    long line, col;
} Token;

typedef struct Lexer {
    const char *name; /* for messages */
    const char *p, *end;
    long line;
    const char *line_start;
    char dir[PBRT_PATH]; /* relative paths resolve here ("" = the working directory) */
} Lexer;

typedef enum ParamType {
    PT_INTEGER, PT_FLOAT, PT_POINT2, PT_VECTOR2, PT_POINT3, PT_VECTOR3, PT_NORMAL, PT_RGB,
    PT_SPECTRUM, PT_BLACKBODY, PT_BOOL, PT_STRING, PT_TEXTURE
} ParamType;

typedef struct Param {
    ParamType type;
    char type_name[32];
    char name[96];
    double *num;  /* numeric values (bools as 0/1) */
    size_t n_num;
    char **str;   /* string values */
    size_t n_str;
    long line, col;
    int used;
} Param;

typedef struct ParamList {
    Param *p;
    size_t n, cap;
} ParamList;

/* A shader call: the built-in class and its parameters. Zeroed before it
 * is filled, so two materials compare with memcmp. */
typedef struct Material {
    char shader[24];
    int n;
    struct {
        char name[16];
        RayesParamType type;
        float v[3];
    } p[MAT_MAX_PARAMS];
    char texture[PBRT_PATH]; /* the value of a STRING parameter "texturename" */
} Material;

typedef struct AreaLight {
    int on;
    float L[3]; /* radiance, scale included */
    int twosided;
} AreaLight;

typedef struct GState {
    double ctm[16]; /* world_from_object, row-major */
    int reverse;    /* ReverseOrientation */
    int active;     /* ActiveTransform: 1 All/StartTime, 0 EndTime (transforms dropped) */
    Material material;
    AreaLight area;
    int kind; /* on the stack: 'A' AttributeBegin, 'T' TransformBegin, 'O' ObjectBegin */
} GState;

typedef struct Named {
    char name[128];
    double m[16];
} Named;

typedef struct NamedMaterial {
    char name[128];
    Material m;
} NamedMaterial;

typedef struct Texture {
    char name[128];
    int image;               /* 1: an image file (path), 0: a constant colour */
    float rgb[3];            /* the constant, or the image's scale */
    char path[PBRT_PATH];
} Texture;

typedef enum OpKind { OP_MESH, OP_QUADRIC, OP_PATCH } OpKind;

typedef struct Op {
    OpKind kind;
    double m[16];
    Material *mat;        /* owned */
    size_t n_faces, n_points;
    int *n_verts, *idx;   /* owned */
    float *pts;           /* owned */
    float *N, *uv;        /* per point, owned; NULL when not given */
    RayesQuadric q;
    float qp[8];
    size_t n_qp;
    unsigned flags;
    float patch[4][3];
    int patch_pv;         /* GEOM-like bits: 1 patch_N, 2 patch_uv given */
    float patch_N[4][3], patch_uv[4][2];
} Op;

typedef struct Object {
    char name[128];
    Op *ops;
    size_t n_ops, cap_ops;
} Object;

typedef struct Parser {
    const IoSink *sink;
    const IoReadOptions *options;
    IoSettings *settings;
    char *err;
    size_t err_size;
    Lexer *lx;
    Token peeked;
    int has_peek;
    int depth, n_files;
    GState gs;
    GState *stack;
    size_t n_stack, cap_stack;
    Named *coordsys;
    size_t n_coordsys;
    NamedMaterial *materials;
    size_t n_materials;
    Texture *textures;
    size_t n_textures;
    Object *objects;
    size_t n_objects;
    Object *recording; /* between ObjectBegin and ObjectEnd */
    long replayed;
    /* camera and options */
    int world; /* after WorldBegin */
    double camera_from_world[16];
    RayesProjection projection;
    float fov;
    float screen[4];
    int have_screen;
    /* what the sink was last told */
    Material sent;
    int have_sent;
    char (*warned)[96];
    size_t n_warned;
} Parser;

/* ------------------------------------------------------------ messages */

/* Messages are one line: names from the file may hold escaped newlines. */
static void one_line(char *msg)
{
    for (; *msg; msg++)
        if ((unsigned char)*msg < 0x20 || *msg == 0x7f)
            *msg = '?';
}

static int fail_at(Parser *P, long line, long col, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static int fail_at(Parser *P, long line, long col, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    one_line(msg);
    snprintf(P->err, P->err_size, "%s:%ld:%ld: %s", P->lx->name, line, col, msg);
    return -1;
}

#define FAIL_TOK(P, t, ...) fail_at((P), (t)->line, (t)->col, __VA_ARGS__)

/* One warning per key and read. */
static void warn_at(Parser *P, long line, long col, const char *key, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

static void warn_at(Parser *P, long line, long col, const char *key, const char *fmt, ...)
{
    for (size_t i = 0; i < P->n_warned; i++)
        if (strncmp(P->warned[i], key, sizeof P->warned[i] - 1) == 0)
            return;
    if (P->n_warned >= PBRT_MAX_WARNED)
        return;
    snprintf(P->warned[P->n_warned++], sizeof P->warned[0], "%s", key);
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    one_line(msg);
    log_warning("%s:%ld:%ld: %s", P->lx->name, line, col, msg);
}

/* A printable copy of a token for messages (at most 40 characters). */
static const char *shown(const Token *t, char buf[48])
{
    if (t->kind == TOK_END)
        return "the end of the file";
    size_t k = 0;
    buf[k++] = '"';
    for (size_t i = 0; i < t->n && k < 42; i++)
        buf[k++] = t->s[i] >= 0x20 && t->s[i] < 0x7f && t->s[i] != '"' ? t->s[i] : '?';
    if (t->n > 40) {
        buf[k - 1] = '.';
    }
    buf[k++] = '"';
    buf[k] = '\0';
    return buf;
}

/* ------------------------------------------------------------ lexer */

static void skip_space(Lexer *l)
{
    while (l->p < l->end) {
        char c = *l->p;
        if (c == '\n') {
            l->p++;
            l->line++;
            l->line_start = l->p;
        } else if (c == '#') {
            while (l->p < l->end && *l->p != '\n')
                l->p++;
        } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
            l->p++;
        } else {
            break;
        }
    }
}

static int lex(Parser *P, Token *t)
{
    Lexer *l = P->lx;
    skip_space(l);
    t->line = l->line;
    t->col = (long)(l->p - l->line_start) + 1;
    t->s = l->p;
    t->n = 0;
    if (l->p >= l->end) {
        t->kind = TOK_END;
        return 0;
    }
    char c = *l->p;
    if (c == '[' || c == ']') {
        t->kind = c == '[' ? TOK_LBRACKET : TOK_RBRACKET;
        t->n = 1;
        l->p++;
        return 0;
    }
    if (c == '"') {
        const char *q = ++l->p;
        while (q < l->end && *q != '"' && *q != '\n') {
            if (*q == '\\' && q + 1 < l->end && q[1] != '\n')
                q++;
            q++;
        }
        if (q >= l->end || *q != '"')
            return FAIL_TOK(P, t, "expected a closing quote before the end of the line");
        t->kind = TOK_STRING;
        t->s = l->p;
        t->n = (size_t)(q - l->p);
        l->p = q + 1;
        return 0;
    }
    const char *q = l->p;
    while (q < l->end && *q != ' ' && *q != '\t' && *q != '\r' && *q != '\n' && *q != '\f' &&
           *q != '\v' && *q != '"' && *q != '[' && *q != ']' && *q != '#')
        q++;
    t->kind = TOK_WORD;
    t->n = (size_t)(q - l->p);
    l->p = q;
    return 0;
}

static int next(Parser *P, Token *t)
{
    if (P->has_peek) {
        *t = P->peeked;
        P->has_peek = 0;
        return 0;
    }
    return lex(P, t);
}

static int peek(Parser *P, Token *t)
{
    if (!P->has_peek) {
        if (lex(P, &P->peeked) != 0)
            return -1;
        P->has_peek = 1;
    }
    *t = P->peeked;
    return 0;
}

static int word_is(const Token *t, const char *w)
{
    return t->kind == TOK_WORD && t->n == strlen(w) && memcmp(t->s, w, t->n) == 0;
}

/* The string's contents with escapes resolved, into buf (error if long). */
static int string_value(Parser *P, const Token *t, char *buf, size_t size)
{
    size_t k = 0;
    for (size_t i = 0; i < t->n; i++) {
        char c = t->s[i];
        if (c == '\\' && i + 1 < t->n) {
            c = t->s[++i];
            c = c == 'n' ? '\n' : c == 't' ? '\t' : c == 'r' ? '\r' : c;
        }
        if (c == '\0')
            return FAIL_TOK(P, t, "expected a string without NUL characters");
        if (k + 1 >= size)
            return FAIL_TOK(P, t, "expected a string of at most %zu characters", size - 1);
        buf[k++] = c;
    }
    buf[k] = '\0';
    return 0;
}

static int parse_number(const Token *t, double *out)
{
    char buf[64];
    if (t->kind != TOK_WORD || t->n == 0 || t->n >= sizeof buf)
        return -1;
    memcpy(buf, t->s, t->n);
    buf[t->n] = '\0';
    char *endp;
    errno = 0;
    double v = strtod(buf, &endp);
    if (*endp != '\0' || errno != 0 || !isfinite(v) || fabs(v) > 1e30)
        return -1;
    *out = v;
    return 0;
}

static int expect_number(Parser *P, double *out, const char *what)
{
    Token t;
    char b[48];
    if (next(P, &t) != 0)
        return -1;
    if (parse_number(&t, out) != 0)
        return FAIL_TOK(P, &t, "expected %s, found %s", what, shown(&t, b));
    return 0;
}

static int expect_string(Parser *P, char *buf, size_t size, const char *what, Token *where)
{
    Token t;
    char b[48];
    if (next(P, &t) != 0)
        return -1;
    if (where)
        *where = t;
    if (t.kind != TOK_STRING)
        return FAIL_TOK(P, &t, "expected %s (a quoted string), found %s", what, shown(&t, b));
    return string_value(P, &t, buf, size);
}

/* n numbers, optionally between brackets. */
static int expect_numbers(Parser *P, double *out, int n, const char *what)
{
    Token t;
    if (peek(P, &t) != 0)
        return -1;
    int bracket = t.kind == TOK_LBRACKET;
    if (bracket)
        next(P, &t);
    for (int i = 0; i < n; i++)
        if (expect_number(P, &out[i], what) != 0)
            return -1;
    if (bracket) {
        char b[48];
        if (next(P, &t) != 0)
            return -1;
        if (t.kind != TOK_RBRACKET)
            return FAIL_TOK(P, &t, "expected \"]\" after %d numbers, found %s", n, shown(&t, b));
    }
    return 0;
}

/* ------------------------------------------------------------ parameters */

static void params_free(ParamList *pl)
{
    for (size_t i = 0; i < pl->n; i++) {
        free(pl->p[i].num);
        for (size_t k = 0; k < pl->p[i].n_str; k++)
            free(pl->p[i].str[k]);
        free(pl->p[i].str);
    }
    free(pl->p);
    memset(pl, 0, sizeof *pl);
}

static int type_of(const char *s, ParamType *t)
{
    static const struct {
        const char *name;
        ParamType type;
    } types[] = {{"integer", PT_INTEGER}, {"float", PT_FLOAT},     {"point2", PT_POINT2},
                 {"vector2", PT_VECTOR2}, {"point3", PT_POINT3},   {"point", PT_POINT3},
                 {"vector3", PT_VECTOR3}, {"vector", PT_VECTOR3},  {"normal3", PT_NORMAL},
                 {"normal", PT_NORMAL},   {"rgb", PT_RGB},         {"color", PT_RGB},
                 {"spectrum", PT_SPECTRUM}, {"blackbody", PT_BLACKBODY}, {"bool", PT_BOOL},
                 {"string", PT_STRING},   {"texture", PT_TEXTURE}};
    for (size_t i = 0; i < sizeof types / sizeof types[0]; i++)
        if (strcmp(types[i].name, s) == 0) {
            *t = types[i].type;
            return 0;
        }
    return -1;
}

static int push_num(Param *p, double v)
{
    if ((p->n_num & (p->n_num - 1)) == 0) { /* grow at powers of two */
        double *n = realloc(p->num, (p->n_num ? 2 * p->n_num : 1) * sizeof *n);
        if (!n)
            return -1;
        p->num = n;
    }
    p->num[p->n_num++] = v;
    return 0;
}

static int push_str(Param *p, const char *s)
{
    if ((p->n_str & (p->n_str - 1)) == 0) {
        char **n = realloc(p->str, (p->n_str ? 2 * p->n_str : 1) * sizeof *n);
        if (!n)
            return -1;
        p->str = n;
    }
    char *c = strdup(s);
    if (!c)
        return -1;
    p->str[p->n_str++] = c;
    return 0;
}

/* One value of a parameter's list. */
static int param_value(Parser *P, Param *p, const Token *t)
{
    char b[48];
    double v;
    if (t->kind == TOK_STRING) {
        char s[PBRT_PATH];
        if (string_value(P, t, s, sizeof s) != 0)
            return -1;
        if (p->type == PT_BOOL && (strcmp(s, "true") == 0 || strcmp(s, "false") == 0))
            return push_num(p, s[0] == 't') != 0 ? FAIL_TOK(P, t, "out of memory") : 0;
        if (p->type != PT_STRING && p->type != PT_TEXTURE && p->type != PT_SPECTRUM)
            return FAIL_TOK(P, t, "expected a %s value for \"%s\", found a string",
                            p->type_name, p->name);
        if (p->n_num > 0)
            return FAIL_TOK(P, t, "expected numbers only in \"%s\"", p->name);
        return push_str(p, s) != 0 ? FAIL_TOK(P, t, "out of memory") : 0;
    }
    if (p->type == PT_BOOL && (word_is(t, "true") || word_is(t, "false")))
        return push_num(p, t->s[0] == 't') != 0 ? FAIL_TOK(P, t, "out of memory") : 0;
    if (parse_number(t, &v) != 0)
        return FAIL_TOK(P, t, "expected a value for \"%s %s\", found %s", p->type_name, p->name,
                        shown(t, b));
    if (p->type == PT_STRING || p->type == PT_TEXTURE || p->type == PT_BOOL)
        return FAIL_TOK(P, t, "expected a %s value for \"%s\", found a number", p->type_name,
                        p->name);
    if (p->n_str > 0)
        return FAIL_TOK(P, t, "expected strings only in \"%s\"", p->name);
    if (p->type == PT_INTEGER && (v != floor(v) || fabs(v) > 2147483647.0))
        return FAIL_TOK(P, t, "expected an integer for \"%s\", found %s", p->name, shown(t, b));
    return push_num(p, v) != 0 ? FAIL_TOK(P, t, "out of memory") : 0;
}

/* The number of values a type takes per item. */
static size_t arity(ParamType t)
{
    switch (t) {
    case PT_POINT2: case PT_VECTOR2: return 2;
    case PT_POINT3: case PT_VECTOR3: case PT_NORMAL: case PT_RGB: return 3;
    default: return 1;
    }
}

static int parse_params(Parser *P, ParamList *pl)
{
    for (;;) {
        Token t;
        char b[48];
        if (peek(P, &t) != 0)
            return -1;
        if (t.kind != TOK_STRING)
            return 0;
        next(P, &t);
        char decl[160], tname[32], pname[96], extra[8];
        if (string_value(P, &t, decl, sizeof decl) != 0)
            return -1;
        int k = sscanf(decl, "%31s %95s %7s", tname, pname, extra);
        if (k != 2)
            return FAIL_TOK(P, &t, "expected a parameter declaration \"type name\", found %s",
                            shown(&t, b));
        if (pl->n == pl->cap) {
            size_t cap = pl->cap ? 2 * pl->cap : 8;
            Param *np = realloc(pl->p, cap * sizeof *np);
            if (!np)
                return FAIL_TOK(P, &t, "out of memory");
            pl->p = np;
            pl->cap = cap;
        }
        Param *p = &pl->p[pl->n++];
        memset(p, 0, sizeof *p);
        p->line = t.line;
        p->col = t.col;
        snprintf(p->type_name, sizeof p->type_name, "%s", tname);
        snprintf(p->name, sizeof p->name, "%s", pname);
        if (type_of(tname, &p->type) != 0)
            return FAIL_TOK(P, &t, "expected a parameter type (integer, float, point2, point3, "
                                   "vector3, normal, rgb, spectrum, blackbody, bool, string, "
                                   "texture), found \"%.20s\"", tname);
        if (next(P, &t) != 0)
            return -1;
        if (t.kind == TOK_LBRACKET) {
            for (;;) {
                if (next(P, &t) != 0)
                    return -1;
                if (t.kind == TOK_RBRACKET)
                    break;
                if (t.kind == TOK_END || t.kind == TOK_LBRACKET)
                    return FAIL_TOK(P, &t, "expected a value or \"]\" in \"%s\", found %s",
                                    p->name, shown(&t, b));
                if (param_value(P, p, &t) != 0)
                    return -1;
            }
        } else if (param_value(P, p, &t) != 0) {
            return -1;
        }
        size_t n = p->n_num + p->n_str;
        if (n == 0)
            return fail_at(P, p->line, p->col, "expected at least one value for \"%s\"", p->name);
        if (p->n_num % arity(p->type) != 0)
            return fail_at(P, p->line, p->col, "expected a multiple of %zu values for \"%s %s\", "
                           "found %zu", arity(p->type), p->type_name, p->name, p->n_num);
    }
}

static Param *find(ParamList *pl, const char *name)
{
    for (size_t i = pl->n; i-- > 0;)
        if (strcmp(pl->p[i].name, name) == 0) {
            pl->p[i].used = 1;
            return &pl->p[i];
        }
    return NULL;
}

static double get_float(ParamList *pl, const char *name, double def)
{
    Param *p = find(pl, name);
    return p && p->n_num > 0 && p->type != PT_STRING ? p->num[0] : def;
}

static const char *get_string(ParamList *pl, const char *name, const char *def)
{
    Param *p = find(pl, name);
    return p && p->n_str > 0 ? p->str[0] : def;
}

static const double *get_point(ParamList *pl, const char *name)
{
    Param *p = find(pl, name);
    return p && p->n_num >= 3 ? p->num : NULL;
}

static void warn_unused(Parser *P, ParamList *pl, const char *directive, const char *kind)
{
    for (size_t i = 0; i < pl->n; i++)
        if (!pl->p[i].used) {
            char key[96];
            snprintf(key, sizeof key, "param %.20s %.20s %.40s", directive, kind, pl->p[i].name);
            warn_at(P, pl->p[i].line, pl->p[i].col, key,
                    "%s \"%s\": parameter \"%s %s\" is not supported; ignored", directive, kind,
                    pl->p[i].type_name, pl->p[i].name);
        }
}

/* ------------------------------------------------------------ colours */

static float luminance(const float c[3])
{
    return 0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2];
}

/* A normalised blackbody colour (max component 1) in linear sRGB, through
 * the Planckian locus approximation of Kim et al. (2002). */
static void blackbody_rgb(double T, float out[3])
{
    if (T < 1667)
        T = 1667;
    if (T > 25000)
        T = 25000;
    double t = 1e3 / T, t2 = t * t, t3 = t2 * t, x, y;
    x = T <= 4000 ? -0.2661239 * t3 - 0.2343589 * t2 + 0.8776956 * t + 0.179910
                  : -3.0258469 * t3 + 2.1070379 * t2 + 0.2226347 * t + 0.240390;
    double x2 = x * x, x3 = x2 * x;
    if (T <= 2222)
        y = -1.1063814 * x3 - 1.34811020 * x2 + 2.18555832 * x - 0.20219683;
    else if (T <= 4000)
        y = -0.9549476 * x3 - 1.37418593 * x2 + 2.09137015 * x - 0.16748867;
    else
        y = 3.0817580 * x3 - 5.87338670 * x2 + 3.75112997 * x - 0.37001483;
    double X = x / y, Y = 1.0, Z = (1 - x - y) / y;
    double rgb[3] = {3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z,
                     -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z,
                     0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z};
    double m = 0;
    for (int c = 0; c < 3; c++) {
        rgb[c] = rgb[c] > 0 ? rgb[c] : 0;
        m = rgb[c] > m ? rgb[c] : m;
    }
    for (int c = 0; c < 3; c++)
        out[c] = (float)(m > 0 ? rgb[c] / m : 1.0);
}

/* Named spectra as RGB: conductors' eta and k (fits at 650, 550, 450 nm),
 * glasses' eta, and the standard illuminants (white). */
static const struct {
    const char *name;
    float rgb[3];
} named_spectra[] = {
    {"metal-Cu-eta", {0.200f, 0.924f, 1.102f}},   {"metal-Cu-k", {3.912f, 2.452f, 2.142f}},
    {"metal-Au-eta", {0.143f, 0.374f, 1.442f}},   {"metal-Au-k", {3.983f, 2.385f, 1.603f}},
    {"metal-Ag-eta", {0.155f, 0.117f, 0.138f}},   {"metal-Ag-k", {4.828f, 3.122f, 2.147f}},
    {"metal-Al-eta", {1.657f, 0.880f, 0.521f}},   {"metal-Al-k", {9.224f, 6.270f, 4.837f}},
    {"metal-CuZn-eta", {0.444f, 0.527f, 1.094f}}, {"metal-CuZn-k", {3.695f, 2.765f, 1.829f}},
    {"glass-BK7", {1.5168f, 1.5168f, 1.5168f}},   {"glass-BAF10", {1.670f, 1.670f, 1.670f}},
    {"glass-FK51A", {1.4866f, 1.4866f, 1.4866f}}, {"glass-LASF9", {1.850f, 1.850f, 1.850f}},
    {"glass-F5", {1.6034f, 1.6034f, 1.6034f}},    {"glass-F10", {1.6200f, 1.6200f, 1.6200f}},
    {"glass-F11", {1.6200f, 1.6200f, 1.6200f}},   {"stdillum-D65", {1, 1, 1}},
    {"stdillum-D50", {1, 1, 1}},                  {"illum-acesD60", {1, 1, 1}},
};

/* Values at 650, 550, 450 nm of a piecewise linear spectrum given as
 * (wavelength, value) pairs. */
static void sampled_rgb(const double *pairs, size_t n_pairs, float out[3])
{
    static const double lambda[3] = {650, 550, 450};
    for (int c = 0; c < 3; c++) {
        double v = pairs[1];
        for (size_t i = 0; i < n_pairs; i++) {
            if (pairs[2 * i] <= lambda[c])
                v = pairs[2 * i + 1];
            if (i + 1 < n_pairs && pairs[2 * i] <= lambda[c] && lambda[c] < pairs[2 * i + 2]) {
                double t = (lambda[c] - pairs[2 * i]) / (pairs[2 * i + 2] - pairs[2 * i]);
                v = pairs[2 * i + 1] + t * (pairs[2 * i + 3] - pairs[2 * i + 1]);
                break;
            }
        }
        out[c] = (float)v;
    }
}

static const Texture *find_texture(Parser *P, const char *name)
{
    for (size_t i = P->n_textures; i-- > 0;)
        if (strcmp(P->textures[i].name, name) == 0)
            return &P->textures[i];
    return NULL;
}

/* A colour parameter: rgb, spectrum (named, sampled or constant), blackbody,
 * float (grey) or texture. Returns 0 (not given: out = def), 1 (a colour
 * in out), 2 (an image texture in *tex, out = its scale) or -1 (error). */
static int get_color(Parser *P, ParamList *pl, const char *name, const float def[3], float out[3],
                     const Texture **tex)
{
    memcpy(out, def, 3 * sizeof(float));
    Param *p = find(pl, name);
    if (!p)
        return 0;
    switch (p->type) {
    case PT_RGB:
        for (int c = 0; c < 3; c++)
            out[c] = (float)p->num[c];
        return 1;
    case PT_FLOAT:
    case PT_INTEGER:
        out[0] = out[1] = out[2] = (float)p->num[0];
        return 1;
    case PT_BLACKBODY:
        blackbody_rgb(p->num[0], out);
        return 1;
    case PT_SPECTRUM:
        if (p->n_str > 0) {
            for (size_t i = 0; i < sizeof named_spectra / sizeof named_spectra[0]; i++)
                if (strcmp(named_spectra[i].name, p->str[0]) == 0) {
                    memcpy(out, named_spectra[i].rgb, sizeof named_spectra[i].rgb);
                    return 1;
                }
            char key[96];
            snprintf(key, sizeof key, "spectrum %.60s", p->str[0]);
            warn_at(P, p->line, p->col, key,
                    "spectrum \"%s\" (a spectrum file or an unknown named spectrum) is not "
                    "supported; using the default of \"%s\"", p->str[0], name);
            return 0;
        }
        if (p->n_num == 1) {
            out[0] = out[1] = out[2] = (float)p->num[0];
            return 1;
        }
        if (p->n_num % 2 != 0)
            return fail_at(P, p->line, p->col, "expected (wavelength, value) pairs for "
                           "\"spectrum %s\", found %zu numbers", name, p->n_num);
        sampled_rgb(p->num, p->n_num / 2, out);
        return 1;
    case PT_TEXTURE: {
        const Texture *t = p->n_str > 0 ? find_texture(P, p->str[0]) : NULL;
        if (!t)
            return fail_at(P, p->line, p->col, "expected the name of a texture defined before, "
                           "found \"%.60s\"", p->n_str > 0 ? p->str[0] : "");
        memcpy(out, t->rgb, sizeof t->rgb);
        if (t->image && tex) {
            *tex = t;
            return 2;
        }
        return 1;
    }
    default:
        return fail_at(P, p->line, p->col, "expected a colour (rgb, spectrum, blackbody, float "
                       "or texture) for \"%s\", found type %s", name, p->type_name);
    }
}

/* A float parameter that may be a texture (the texture's grey value then). */
static int get_float_tex(Parser *P, ParamList *pl, const char *name, double def, double *out)
{
    Param *p = find(pl, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type == PT_FLOAT || p->type == PT_INTEGER) {
        *out = p->num[0];
        return 0;
    }
    float c[3], d[3] = {(float)def, (float)def, (float)def};
    p->used = 0;
    if (get_color(P, pl, name, d, c, NULL) < 0)
        return -1;
    if (p->type == PT_TEXTURE) {
        char key[96];
        snprintf(key, sizeof key, "float texture %.60s", name);
        warn_at(P, p->line, p->col, key, "\"%s\": float textures are not supported; using a "
                "constant", name);
    }
    *out = (c[0] + c[1] + c[2]) / 3.0;
    return 0;
}

/* ------------------------------------------------------------ matrices */

static void mat_identity(double m[16])
{
    memset(m, 0, 16 * sizeof *m);
    m[0] = m[5] = m[10] = m[15] = 1;
}

static void mat_mul(const double a[16], const double b[16], double out[16])
{
    double r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double s = 0;
            for (int k = 0; k < 4; k++)
                s += a[4 * i + k] * b[4 * k + j];
            r[4 * i + j] = s;
        }
    memcpy(out, r, sizeof r);
}

static double mat_det3(const double m[16])
{
    return m[0] * (m[5] * m[10] - m[6] * m[9]) - m[1] * (m[4] * m[10] - m[6] * m[8]) +
           m[2] * (m[4] * m[9] - m[5] * m[8]);
}

/* Gauss-Jordan with partial pivoting; -1 if singular. */
static int mat_inverse(const double m[16], double out[16])
{
    double a[4][8];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 8; j++)
            a[i][j] = j < 4 ? m[4 * i + j] : (j - 4 == i);
    for (int c = 0; c < 4; c++) {
        int piv = c;
        for (int r = c + 1; r < 4; r++)
            if (fabs(a[r][c]) > fabs(a[piv][c]))
                piv = r;
        if (!(fabs(a[piv][c]) > 1e-300))
            return -1;
        for (int j = 0; j < 8; j++) {
            double t = a[c][j];
            a[c][j] = a[piv][j];
            a[piv][j] = t;
        }
        double d = a[c][c];
        for (int j = 0; j < 8; j++)
            a[c][j] /= d;
        for (int r = 0; r < 4; r++)
            if (r != c) {
                double f = a[r][c];
                for (int j = 0; j < 8; j++)
                    a[r][j] -= f * a[c][j];
            }
    }
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            out[4 * i + j] = a[i][j + 4];
    return 0;
}

static int mat_finite(const double m[16])
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(m[i]) || fabs(m[i]) > 1e30)
            return 0;
    return 1;
}

static void mat_to_float(const double m[16], float out[16])
{
    for (int i = 0; i < 16; i++)
        out[i] = (float)m[i];
}

/* ------------------------------------------------------------ emitting */

static int sink_failed(Parser *P, const Token *t, RayesError e)
{
    const char *msg = P->sink->get_error ? P->sink->get_error(P->sink->target) : "";
    FAIL_TOK(P, t, "%s", msg && msg[0] ? msg : rayes_error_string(e));
    return -1;
}

static void material_params(const Material *m, RayesParam out[MAT_MAX_PARAMS + 1])
{
    for (int i = 0; i < m->n; i++) {
        out[i] = (RayesParam){.name = m->p[i].name, .type = m->p[i].type};
        memcpy(out[i].value, m->p[i].v, sizeof out[i].value);
        if (m->p[i].type == RAYES_PARAM_STRING)
            out[i].string = m->texture;
    }
}

static int send_state(Parser *P, const Token *t, const double m[16], const Material *mat)
{
    float f[16];
    if (!mat_finite(m))
        return FAIL_TOK(P, t, "the current transform is not finite");
    mat_to_float(m, f);
    RayesError e = P->sink->set_transform(P->sink->target, f);
    if (e != RAYES_OK)
        return sink_failed(P, t, e);
    if (!P->have_sent || memcmp(&P->sent, mat, sizeof *mat) != 0) {
        RayesParam params[MAT_MAX_PARAMS + 1];
        material_params(mat, params);
        e = P->sink->set_shader(P->sink->target, mat->shader, params, (size_t)mat->n);
        if (e != RAYES_OK)
            return sink_failed(P, t, e);
        P->sent = *mat;
        P->have_sent = 1;
    }
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

/* Sends (or records) a mesh with N and uv per point (NULL: none). */
static RayesError send_mesh(Parser *P, size_t n_faces, const int *n_verts, const int *idx,
                            size_t n_points, const float *pts, const float *N, const float *uv)
{
    RayesPrimvar pv[2];
    float *st = uv ? malloc((2 * n_points + 1) * sizeof *st) : NULL;
    if (uv && !st)
        return RAYES_ERROR_OUT_OF_MEMORY;
    size_t n_pv = mesh_primvars(n_points, N, uv, st, pv);
    RayesError e = P->sink->polygon_mesh(P->sink->target, n_faces, n_verts, idx, n_points, pts,
                                         pv, n_pv);
    free(st);
    return e;
}

static int emit_mesh(Parser *P, const Token *t, size_t n_faces, const int *n_verts,
                     const int *idx, size_t n_points, const float *pts, const float *N,
                     const float *uv)
{
    if (n_faces == 0)
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
        return 0;
    }
    if (send_state(P, t, P->gs.ctm, &P->gs.material) != 0)
        return -1;
    RayesError e = send_mesh(P, n_faces, n_verts, idx, n_points, pts, N, uv);
    return e != RAYES_OK ? sink_failed(P, t, e) : 0;
}

static int emit_quadric(Parser *P, const Token *t, RayesQuadric q, const float *qp, size_t n,
                        unsigned flags)
{
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
    return e != RAYES_OK ? sink_failed(P, t, e) : 0;
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

static int emit_patch(Parser *P, const Token *t, const Op *patch)
{
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
    return e != RAYES_OK ? sink_failed(P, t, e) : 0;
}

static int emit_light(Parser *P, const Token *t, const double m[16], const char *type,
                      const RayesParam *params, size_t n)
{
    float f[16];
    if (!mat_finite(m))
        return FAIL_TOK(P, t, "the current transform is not finite");
    mat_to_float(m, f);
    RayesError e = P->sink->set_transform(P->sink->target, f);
    if (e == RAYES_OK)
        e = P->sink->light(P->sink->target, type, params, n);
    return e != RAYES_OK ? sink_failed(P, t, e) : 0;
}

static int replay(Parser *P, const Token *t, const Object *o)
{
    for (size_t i = 0; i < o->n_ops; i++) {
        const Op *op = &o->ops[i];
        if (++P->replayed > PBRT_MAX_REPLAYED)
            return FAIL_TOK(P, t, "more than %ld instanced primitives", PBRT_MAX_REPLAYED);
        double m[16];
        mat_mul(P->gs.ctm, op->m, m);
        if (send_state(P, t, m, op->mat) != 0)
            return -1;
        RayesError e = RAYES_OK;
        if (op->kind == OP_MESH)
            e = send_mesh(P, op->n_faces, op->n_verts, op->idx, op->n_points, op->pts, op->N,
                          op->uv);
        else if (op->kind == OP_QUADRIC)
            e = P->sink->quadric(P->sink->target, op->q, op->qp, op->n_qp, op->flags);
        else
            e = send_patch(P, op);
        if (e != RAYES_OK)
            return sink_failed(P, t, e);
    }
    return 0;
}

/* ------------------------------------------------------------ materials */

static void mat_init(Material *m, const char *shader)
{
    memset(m, 0, sizeof *m);
    snprintf(m->shader, sizeof m->shader, "%s", shader);
}

static void mat_float(Material *m, const char *name, float v)
{
    if (m->n >= MAT_MAX_PARAMS)
        return;
    snprintf(m->p[m->n].name, sizeof m->p[m->n].name, "%s", name);
    m->p[m->n].type = RAYES_PARAM_FLOAT;
    m->p[m->n].v[0] = v;
    m->n++;
}

static void mat_color(Material *m, const char *name, const float c[3])
{
    if (m->n >= MAT_MAX_PARAMS)
        return;
    snprintf(m->p[m->n].name, sizeof m->p[m->n].name, "%s", name);
    m->p[m->n].type = RAYES_PARAM_COLOR;
    memcpy(m->p[m->n].v, c, 3 * sizeof(float));
    m->n++;
}

static void mat_texture(Material *m, const char *path)
{
    if (m->n >= MAT_MAX_PARAMS)
        return;
    snprintf(m->p[m->n].name, sizeof m->p[m->n].name, "texturename");
    m->p[m->n].type = RAYES_PARAM_STRING;
    snprintf(m->texture, sizeof m->texture, "%s", path);
    m->n++;
}

/* The colour of a material's parameter, if it has one of that name. */
static const float *mat_get(const Material *m, const char *name)
{
    for (int i = 0; i < m->n; i++)
        if (strcmp(m->p[i].name, name) == 0)
            return m->p[i].v;
    return NULL;
}

static double get_roughness(ParamList *pl, double def)
{
    double r = get_float(pl, "roughness", def);
    Param *u = find(pl, "uroughness"), *v = find(pl, "vroughness");
    if (u || v)
        r = 0.5 * (u && u->n_num ? u->num[0] : r) + 0.5 * (v && v->n_num ? v->num[0] : r);
    find(pl, "remaproughness"); /* rayes' roughness is pbrt's with remapping on */
    return r;
}

static int diffuse_material(Parser *P, ParamList *pl, Material *m, const char *param)
{
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    float c[3];
    const Texture *tex = NULL;
    int k = get_color(P, pl, param, half, c, &tex);
    if (k < 0)
        return -1;
    if (k == 2) { /* Cs T Kd (diffuse light), T the image */
        mat_init(m, "paintedplastic");
        mat_float(m, "Kd", 1.0f);
        mat_float(m, "Ks", 0.0f);
        mat_color(m, "Cs", c);
        mat_texture(m, tex->path);
        return 0;
    }
    mat_init(m, "diffuse");
    mat_color(m, "reflectance", c);
    return 0;
}

static int make_material(Parser *P, const Token *t, const char *type, ParamList *pl, Material *m);

static const Material *named_material(Parser *P, const char *name)
{
    for (size_t i = P->n_materials; i-- > 0;)
        if (strcmp(P->materials[i].name, name) == 0)
            return &P->materials[i].m;
    return NULL;
}

static int mix_material(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    Param *names = find(pl, "materials");
    if (!names || names->n_str != 2)
        return FAIL_TOK(P, t, "mix: expected \"string materials\" with two material names");
    double amount;
    if (get_float_tex(P, pl, "amount", 0.5, &amount) != 0)
        return -1;
    const Material *a = named_material(P, names->str[0]), *b = named_material(P, names->str[1]);
    if (!a || !b)
        return FAIL_TOK(P, t, "mix: expected materials defined before, found \"%.60s\"",
                        !a ? names->str[0] : names->str[1]);
    const float *ca = mat_get(a, "reflectance"), *cb = mat_get(b, "reflectance");
    if (strcmp(a->shader, "diffuse") == 0 && strcmp(b->shader, "diffuse") == 0 && ca && cb) {
        float c[3];
        for (int k = 0; k < 3; k++)
            c[k] = (float)((1 - amount) * ca[k] + amount * cb[k]);
        mat_init(m, "diffuse");
        mat_color(m, "reflectance", c);
        warn_at(P, t->line, t->col, "mix diffuse", "mix: two diffuse materials become one "
                "diffuse material of the blended reflectance");
        return 0;
    }
    *m = amount > 0.5 ? *b : *a;
    warn_at(P, t->line, t->col, "mix", "mix: rayes cannot blend these materials; using the "
            "heavier one (\"%.60s\")", amount > 0.5 ? names->str[1] : names->str[0]);
    return 0;
}

static int make_material(Parser *P, const Token *t, const char *type, ParamList *pl, Material *m)
{
    static const float cu_eta[3] = {0.200f, 0.924f, 1.102f}, cu_k[3] = {3.912f, 2.452f, 2.142f};
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    float c[3];
    int k;
    if (find(pl, "displacement"))
        warn_at(P, t->line, t->col, "displacement", "material \"%s\": \"displacement\" is not "
                "supported (no displacement)", type);
    if (find(pl, "normalmap"))
        warn_at(P, t->line, t->col, "normalmap", "material \"%s\": \"normalmap\" is not supported",
                type);
    if (strcmp(type, "diffuse") == 0)
        return diffuse_material(P, pl, m, "reflectance");
    if (strcmp(type, "coateddiffuse") == 0) {
        const Texture *tex = NULL;
        if ((k = get_color(P, pl, "reflectance", half, c, &tex)) < 0)
            return -1;
        if (k == 2)
            warn_at(P, t->line, t->col, "coateddiffuse texture", "coateddiffuse: an image "
                    "texture as reflectance is not supported; using its scale as a colour");
        double eta = get_float(pl, "eta", 1.5);
        mat_init(m, "coateddiffuse");
        mat_color(m, "reflectance", c);
        mat_float(m, "roughness", (float)get_roughness(pl, 0.0));
        mat_float(m, "eta", (float)eta);
        mat_float(m, "thickness", (float)get_float(pl, "thickness", 0.01));
        return 0;
    }
    if (strcmp(type, "conductor") == 0 || strcmp(type, "coatedconductor") == 0) {
        if (strcmp(type, "coatedconductor") == 0)
            warn_at(P, t->line, t->col, "coatedconductor", "coatedconductor: mapped to conductor "
                    "(the coating is left out)");
        mat_init(m, "conductor");
        int coated = strcmp(type, "coatedconductor") == 0;
        const char *eta_name = coated ? "conductor.eta" : "eta", *k_name = coated ? "conductor.k" : "k";
        if ((k = get_color(P, pl, "reflectance", half, c, NULL)) < 0)
            return -1;
        if (k > 0) {
            mat_color(m, "reflectance", c);
        } else {
            float eta[3], kk[3];
            if (get_color(P, pl, eta_name, cu_eta, eta, NULL) < 0 ||
                get_color(P, pl, k_name, cu_k, kk, NULL) < 0)
                return -1;
            mat_color(m, "eta", eta);
            mat_color(m, "k", kk);
        }
        mat_float(m, "roughness", (float)get_roughness(pl, 0.0));
        return 0;
    }
    if (strcmp(type, "dielectric") == 0 || strcmp(type, "thindielectric") == 0) {
        if (type[0] == 't')
            warn_at(P, t->line, t->col, "thindielectric", "thindielectric: mapped to dielectric");
        static const float d15[3] = {1.5f, 1.5f, 1.5f};
        if (get_color(P, pl, "eta", d15, c, NULL) < 0)
            return -1;
        mat_init(m, "dielectric");
        mat_float(m, "eta", (c[0] + c[1] + c[2]) / 3.0f);
        mat_float(m, "roughness", (float)get_roughness(pl, 0.0));
        return 0;
    }
    if (strcmp(type, "mix") == 0)
        return mix_material(P, t, pl, m);
    if (strcmp(type, "diffusetransmission") == 0) {
        warn_at(P, t->line, t->col, "diffusetransmission", "diffusetransmission: mapped to "
                "diffuse (no transmission)");
        return diffuse_material(P, pl, m, "reflectance");
    }
    char key[96];
    snprintf(key, sizeof key, "material %.60s", type);
    warn_at(P, t->line, t->col, key, "material \"%.40s\" is not supported; using matte", type);
    mat_init(m, "matte");
    for (size_t i = 0; i < pl->n; i++)
        pl->p[i].used = 1; /* one warning for the material, not one per parameter */
    return 0;
}

/* ------------------------------------------------------------ paths */

static int resolve(Parser *P, const Token *t, const char *file, char *out, size_t size)
{
    int n = file[0] == '/' || !P->lx->dir[0] ? snprintf(out, size, "%s", file)
                                             : snprintf(out, size, "%s/%s", P->lx->dir, file);
    if (n < 0 || (size_t)n >= size)
        return FAIL_TOK(P, t, "the path \"%.40s...\" is too long", file);
    return 0;
}

static void dir_of(const char *path, char *dir, size_t size)
{
    const char *slash = strrchr(path, '/');
    size_t n = slash ? (size_t)(slash - path) : 0;
    if (n >= size)
        n = size - 1;
    if (slash && n == 0)
        n = 1; /* "/x" */
    memcpy(dir, path, n);
    dir[n] = '\0';
}

/* ------------------------------------------------------------ shapes */

static int swaps_handedness(const double m[16])
{
    return mat_det3(m) < 0;
}

static void sub3d(const float *a, const float *b, double o[3])
{
    for (int c = 0; c < 3; c++)
        o[c] = (double)a[c] - b[c];
}

static void cross3d(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3d(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* A quad's normal (unnormalised): the cross product of its diagonals. */
static void quad_normal(const float *pts, const int *f, double out[3])
{
    double c[3], d[3];
    sub3d(&pts[3 * f[2]], &pts[3 * f[0]], c);
    sub3d(&pts[3 * f[3]], &pts[3 * f[1]], d);
    cross3d(c, d, out);
}

/* Emits one emitting quad q (indices into pts; N per vertex or NULL). */
static int emit_area_quad(Parser *P, const Token *t, const float *pts, const float *N,
                          const int q[4])
{
    double g[3], d[3];
    quad_normal(pts, q, g);
    memcpy(d, g, sizeof d);
    if (N) {
        for (int c = 0; c < 3; c++)
            d[c] = (double)N[3 * q[0] + c] + N[3 * q[1] + c] + N[3 * q[2] + c] + N[3 * q[3] + c];
        if (dot3d(d, d) == 0)
            memcpy(d, g, sizeof d);
    }
    if (P->gs.reverse)
        for (int c = 0; c < 3; c++)
            d[c] = -d[c];
    int flip = (dot3d(g, d) < 0) != swaps_handedness(P->gs.ctm);
    for (int side = 0; side < 1 + P->gs.area.twosided; side++) {
        float Q[4][3];
        int rev = flip ^ side;
        for (int k = 0; k < 4; k++)
            memcpy(Q[k], &pts[3 * q[rev ? (4 - k) % 4 : k]], sizeof Q[k]);
        float f[16];
        if (!mat_finite(P->gs.ctm))
            return FAIL_TOK(P, t, "the current transform is not finite");
        mat_to_float(P->gs.ctm, f);
        RayesError e = P->sink->set_transform(P->sink->target, f);
        if (e == RAYES_OK)
            e = P->sink->area_light(P->sink->target, (const float(*)[3])Q, P->gs.area.L);
        if (e != RAYES_OK)
            return sink_failed(P, t, e);
    }
    return 0;
}

/* Nonzero if the triangles a and b share an edge and make a planar convex
 * quad; q gets it in order around. */
static int pair_quad(const float *pts, const int *a, const int *b, int q[4])
{
    for (int i = 0; i < 3; i++) {
        int x = a[i], s1 = a[(i + 1) % 3], s2 = a[(i + 2) % 3];
        for (int j = 0; j < 3; j++)
            if (b[j] == s2 && b[(j + 1) % 3] == s1) {
                int y = b[(j + 2) % 3];
                if (y == x || y == s1 || y == s2)
                    return 0;
                q[0] = x, q[1] = s1, q[2] = y, q[3] = s2;
                double n[4][3], len[4];
                for (int k = 0; k < 4; k++) {
                    double u[3], v[3];
                    sub3d(&pts[3 * q[(k + 1) % 4]], &pts[3 * q[k]], u);
                    sub3d(&pts[3 * q[(k + 3) % 4]], &pts[3 * q[k]], v);
                    cross3d(u, v, n[k]);
                    len[k] = sqrt(dot3d(n[k], n[k]));
                    if (!(len[k] > 0))
                        return 0;
                }
                for (int k = 1; k < 4; k++)
                    if (dot3d(n[0], n[k]) < 0.999 * len[0] * len[k])
                        return 0;
                return 1;
            }
    }
    return 0;
}

/* A mesh of triangles and quads (indices checked): an emitter's quads go to
 * area_light, the rest to polygon_mesh with pbrt's orientation. */
static int shape_mesh(Parser *P, const Token *t, const char *what, size_t n_faces, int *n_verts,
                      int *idx, size_t n_points, const float *pts, const float *N,
                      const float *uv)
{
    if (P->gs.area.on && P->recording) {
        warn_at(P, t->line, t->col, "instanced area light", "%s: area lights inside ObjectBegin "
                "are not supported (as in pbrt); the shape is not emitting", what);
    } else if (P->gs.area.on) {
        size_t lone = 0;
        const int *f = idx;
        for (size_t i = 0; i < n_faces; f += n_verts[i], i++) {
            int q[4];
            if (n_verts[i] == 4) {
                memcpy(q, f, sizeof q);
            } else if (i + 1 < n_faces && n_verts[i + 1] == 3 && pair_quad(pts, f, f + 3, q)) {
                f += 3;
                i++;
            } else {
                lone++;
                continue;
            }
            if (emit_area_quad(P, t, pts, N, q) != 0)
                return -1;
        }
        if (lone)
            warn_at(P, t->line, t->col, "lone emitting triangle", "%s: %zu emitting triangle(s) "
                    "do not pair into quads; rayes' area lights are quads, so they do not emit",
                    what, lone);
        return 0;
    }
    if (P->gs.reverse != swaps_handedness(P->gs.ctm)) {
        int *f = idx;
        for (size_t i = 0; i < n_faces; f += n_verts[i], i++) {
            int tmp = f[1];
            f[1] = f[n_verts[i] - 1];
            f[n_verts[i] - 1] = tmp;
        }
    }
    return emit_mesh(P, t, n_faces, n_verts, idx, n_points, pts, N, uv);
}

/* Points of a "point3 P" parameter as floats (new, free()). */
static float *points_of(Parser *P, const Token *t, const Param *p)
{
    float *pts = malloc((p->n_num ? p->n_num : 1) * sizeof(float));
    if (!pts) {
        FAIL_TOK(P, t, "out of memory");
        return NULL;
    }
    for (size_t i = 0; i < p->n_num; i++)
        pts[i] = (float)p->num[i];
    return pts;
}

static void warn_vertex_data(Parser *P, const Token *t, ParamList *pl, const char *what)
{
    static const char *names[] = {"S", "faceIndices", "alpha", "emissionfilename"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        Param *p = find(pl, names[i]);
        if (p) {
            char key[96];
            snprintf(key, sizeof key, "vertex data %.60s", names[i]);
            warn_at(P, p->line, p->col, key, "%s: \"%s\" is not passed on (rayes meshes carry "
                    "positions, N and uv)", what, names[i]);
        }
    }
    (void)t;
}

/* The "point2 uv" (or "st") of a mesh of n_points points, or NULL (with
 * a warning when its count is wrong). */
static Param *uv_param(Parser *P, ParamList *pl, const char *what, size_t n_points)
{
    Param *uv = find(pl, "uv");
    if (!uv)
        uv = find(pl, "st");
    if (uv && uv->n_num != 2 * n_points) {
        warn_at(P, uv->line, uv->col, "uv count", "%s: \"uv\" has %zu values for %zu points; "
                "ignored", what, uv->n_num, n_points);
        return NULL;
    }
    return uv;
}

static int shape_trianglemesh(Parser *P, const Token *t, ParamList *pl)
{
    Param *pp = find(pl, "P"), *ip = find(pl, "indices"), *np = find(pl, "N");
    warn_vertex_data(P, t, pl, "trianglemesh");
    if (!pp || pp->n_num < 9)
        return FAIL_TOK(P, t, "trianglemesh: expected \"point3 P\" with at least 3 points");
    size_t n_points = pp->n_num / 3;
    if (!ip && n_points != 3)
        return FAIL_TOK(P, t, "trianglemesh: expected \"integer indices\" (P has %zu points)",
                        n_points);
    size_t n_idx = ip ? ip->n_num : 3;
    if (n_idx % 3 != 0 || n_idx == 0)
        return fail_at(P, ip->line, ip->col, "trianglemesh: expected a multiple of 3 indices, "
                       "found %zu", n_idx);
    for (size_t i = 0; ip && i < n_idx; i++)
        if (ip->num[i] < 0 || ip->num[i] >= (double)n_points)
            return fail_at(P, ip->line, ip->col, "trianglemesh: index %zu is %.0f but P has %zu "
                           "points", i, ip->num[i], n_points);
    if (np && np->n_num != pp->n_num) {
        warn_at(P, np->line, np->col, "N count", "trianglemesh: \"N\" has %zu values, P %zu; N "
                "ignored", np->n_num, pp->n_num);
        np = NULL;
    }
    Param *uvp = uv_param(P, pl, "trianglemesh", n_points);
    size_t n_faces = n_idx / 3;
    float *pts = points_of(P, t, pp);
    float *N = np ? points_of(P, t, np) : NULL;
    float *uv = uvp ? points_of(P, t, uvp) : NULL;
    int *nv = malloc(n_faces * sizeof(int)), *idx = malloc(n_idx * sizeof(int));
    int r = -1;
    if (!pts || (np && !N) || (uvp && !uv) || !nv || !idx) {
        FAIL_TOK(P, t, "out of memory");
    } else {
        for (size_t f = 0; f < n_faces; f++)
            nv[f] = 3;
        for (size_t i = 0; i < n_idx; i++)
            idx[i] = ip ? (int)ip->num[i] : (int)i;
        r = shape_mesh(P, t, "trianglemesh", n_faces, nv, idx, n_points, pts, N, uv);
    }
    free(pts);
    free(N);
    free(uv);
    free(nv);
    free(idx);
    return r;
}

static int shape_bilinearmesh(Parser *P, const Token *t, ParamList *pl)
{
    Param *pp = find(pl, "P"), *ip = find(pl, "indices"), *np = find(pl, "N");
    warn_vertex_data(P, t, pl, "bilinearmesh");
    if (!pp || pp->n_num < 12)
        return FAIL_TOK(P, t, "bilinearmesh: expected \"point3 P\" with at least 4 points");
    size_t n_points = pp->n_num / 3;
    if (!ip && n_points != 4)
        return FAIL_TOK(P, t, "bilinearmesh: expected \"integer indices\" (P has %zu points)",
                        n_points);
    size_t n_idx = ip ? ip->n_num : 4;
    if (n_idx % 4 != 0)
        return fail_at(P, ip->line, ip->col, "bilinearmesh: expected a multiple of 4 indices, "
                       "found %zu", n_idx);
    for (size_t i = 0; ip && i < n_idx; i++)
        if (ip->num[i] < 0 || ip->num[i] >= (double)n_points)
            return fail_at(P, ip->line, ip->col, "bilinearmesh: index %zu is %.0f but P has %zu "
                           "points", i, ip->num[i], n_points);
    if (np && np->n_num != pp->n_num) {
        warn_at(P, np->line, np->col, "N count", "bilinearmesh: \"N\" has %zu values, P %zu; N "
                "ignored", np->n_num, pp->n_num);
        np = NULL;
    }
    Param *uvp = uv_param(P, pl, "bilinearmesh", n_points);
    float *pts = points_of(P, t, pp);
    if (!pts)
        return -1;
    int flip = P->gs.reverse != swaps_handedness(P->gs.ctm);
    for (size_t f = 0; f < n_idx / 4; f++) {
        int v[4];
        for (int k = 0; k < 4; k++)
            v[k] = ip ? (int)ip->num[4 * f + k] : k;
        int r;
        if (P->gs.area.on && !P->recording) {
            int q[4] = {v[0], v[1], v[3], v[2]}; /* around the patch */
            r = emit_area_quad(P, t, pts, NULL, q);
        } else {
            Op patch = {.patch_pv = (np ? 1 : 0) | (uvp ? 2 : 0)};
            static const int order[2][4] = {{0, 1, 2, 3}, {1, 0, 3, 2}};
            for (int k = 0; k < 4; k++) {
                size_t j = (size_t)v[order[flip][k]];
                memcpy(patch.patch[k], &pts[3 * j], sizeof patch.patch[k]);
                for (int c = 0; c < 3 && np; c++)
                    patch.patch_N[k][c] = (float)np->num[3 * j + (size_t)c];
                for (int c = 0; c < 2 && uvp; c++)
                    patch.patch_uv[k][c] = (float)uvp->num[2 * j + (size_t)c];
            }
            r = emit_patch(P, t, &patch);
        }
        if (r != 0) {
            free(pts);
            return -1;
        }
    }
    free(pts);
    return 0;
}

static int shape_plymesh(Parser *P, const Token *t, ParamList *pl)
{
    const char *file = get_string(pl, "filename", NULL);
    if (!file)
        return FAIL_TOK(P, t, "plymesh: expected \"string filename\"");
    Param *d = find(pl, "displacement");
    if (d)
        warn_at(P, d->line, d->col, "ply displacement", "plymesh: \"displacement\" is not "
                "supported (no displacement)");
    find(pl, "edgelength");
    char path[PBRT_PATH], err[600];
    if (resolve(P, t, file, path, sizeof path) != 0)
        return -1;
    PlyMesh m;
    if (io_ply_read(path, &m, err, sizeof err) != RAYES_OK)
        return FAIL_TOK(P, t, "plymesh: %s", err);
    int r = shape_mesh(P, t, "plymesh", m.n_faces, m.n_verts, m.indices, m.n_vertices, m.P, m.N,
                       m.uv);
    io_ply_mesh_fini(&m);
    return r;
}

/* An emitting sphere or disk: rayes' "arealight" of that shape. */
static int quadric_light(Parser *P, const Token *t, const char *shape, float radius,
                         const double m[16])
{
    RayesParam lp[4] = {
        {.name = "shape", .type = RAYES_PARAM_STRING, .string = shape},
        {.name = "radius", .type = RAYES_PARAM_FLOAT, .value = {radius}},
        {.name = "lightcolor", .type = RAYES_PARAM_COLOR},
        {.name = "intensity", .type = RAYES_PARAM_FLOAT, .value = {1}},
    };
    memcpy(lp[2].value, P->gs.area.L, sizeof lp[2].value);
    return emit_light(P, t, m, "arealight", lp, 4);
}

static int shape_quadric(Parser *P, const Token *t, const char *type, ParamList *pl)
{
    double radius = get_float(pl, "radius", 1.0);
    double phimax = get_float(pl, "phimax", 360.0);
    if (!(radius > 0))
        return FAIL_TOK(P, t, "%s: expected a positive radius, found %g", type, radius);
    if (!(phimax > 0 && phimax <= 360))
        return FAIL_TOK(P, t, "%s: expected phimax in (0, 360], found %g", type, phimax);
    unsigned flags = P->gs.reverse ? RAYES_QUADRIC_REVERSE : 0;
    float qp[4];
    size_t n;
    RayesQuadric q;
    double height = 0;
    if (strcmp(type, "sphere") == 0) {
        double zmin = get_float(pl, "zmin", -radius), zmax = get_float(pl, "zmax", radius);
        zmin = zmin < -radius ? -radius : zmin > radius ? radius : zmin;
        zmax = zmax < -radius ? -radius : zmax > radius ? radius : zmax;
        if (!(zmin < zmax))
            return FAIL_TOK(P, t, "sphere: expected zmin < zmax");
        q = RAYES_QUADRIC_SPHERE;
        qp[0] = (float)radius, qp[1] = (float)zmin, qp[2] = (float)zmax, qp[3] = (float)phimax;
        n = 4;
        if (P->gs.area.on && (zmin > -radius || zmax < radius || phimax < 360))
            warn_at(P, t->line, t->col, "partial sphere light", "sphere: a partial emitting "
                    "sphere emits as a whole sphere");
    } else if (strcmp(type, "cylinder") == 0) {
        double zmin = get_float(pl, "zmin", -1), zmax = get_float(pl, "zmax", 1);
        if (!(zmin != zmax))
            return FAIL_TOK(P, t, "cylinder: expected zmin != zmax");
        q = RAYES_QUADRIC_CYLINDER;
        qp[0] = (float)radius, qp[1] = (float)zmin, qp[2] = (float)zmax, qp[3] = (float)phimax;
        n = 4;
    } else {
        height = get_float(pl, "height", 0.0);
        double inner = get_float(pl, "innerradius", 0.0);
        if (inner > 0)
            warn_at(P, t->line, t->col, "disk innerradius", "disk: \"innerradius\" is not "
                    "supported; the disk is whole");
        q = RAYES_QUADRIC_DISK;
        qp[0] = (float)height, qp[1] = (float)radius, qp[2] = (float)phimax;
        n = 3;
    }
    if (!P->gs.area.on || P->recording || q == RAYES_QUADRIC_CYLINDER) {
        if (P->gs.area.on)
            warn_at(P, t->line, t->col, P->recording ? "instanced area light" : "cylinder light",
                    "%s: this emitter is not supported (%s); the shape does not emit", type,
                    P->recording ? "inside ObjectBegin" : "rayes' area lights are quads, disks "
                    "and spheres");
        return emit_quadric(P, t, q, qp, n, flags);
    }
    if (q == RAYES_QUADRIC_SPHERE) {
        if (P->gs.reverse)
            warn_at(P, t->line, t->col, "inward sphere light", "sphere: an inward-emitting "
                    "sphere (ReverseOrientation) emits outward in rayes");
        return quadric_light(P, t, "sphere", (float)radius, P->gs.ctm);
    }
    double m[16], tr[16], flip[16];
    mat_identity(tr);
    tr[11] = height;
    mat_mul(P->gs.ctm, tr, m);
    mat_identity(flip);
    flip[5] = flip[10] = -1; /* 180 degrees about x: emits toward -z */
    for (int side = 0; side < 1 + P->gs.area.twosided; side++) {
        double ms[16];
        if (P->gs.reverse ^ side)
            mat_mul(m, flip, ms);
        else
            memcpy(ms, m, sizeof ms);
        if (quadric_light(P, t, "disk", (float)radius, ms) != 0)
            return -1;
    }
    return 0;
}

/* ------------------------------------------------------------ directives */

typedef struct Directive Directive;
typedef int (*Handler)(Parser *P, const Token *t);

static int need_world(Parser *P, const Token *t, int inside)
{
    if (P->world != inside)
        return FAIL_TOK(P, t, inside ? "expected WorldBegin before this directive"
                                     : "expected this directive before WorldBegin");
    return 0;
}

/* Reads the "name" argument and the parameter list of a directive. */
static int name_and_params(Parser *P, char *name, size_t size, const char *what, ParamList *pl,
                           Token *where)
{
    if (expect_string(P, name, size, what, where) != 0)
        return -1;
    return parse_params(P, pl);
}

static void apply(Parser *P, const double m[16])
{
    if (!P->gs.active)
        return;
    mat_mul(P->gs.ctm, m, P->gs.ctm);
}

static int d_translate(Parser *P, const Token *t)
{
    (void)t;
    double v[3], m[16];
    if (expect_numbers(P, v, 3, "a number (Translate x y z)") != 0)
        return -1;
    mat_identity(m);
    m[3] = v[0], m[7] = v[1], m[11] = v[2];
    apply(P, m);
    return 0;
}

static int d_scale(Parser *P, const Token *t)
{
    (void)t;
    double v[3], m[16];
    if (expect_numbers(P, v, 3, "a number (Scale x y z)") != 0)
        return -1;
    mat_identity(m);
    m[0] = v[0], m[5] = v[1], m[10] = v[2];
    apply(P, m);
    return 0;
}

static int d_rotate(Parser *P, const Token *t)
{
    double v[4], m[16];
    if (expect_numbers(P, v, 4, "a number (Rotate angle x y z)") != 0)
        return -1;
    double len = sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(len > 0))
        return FAIL_TOK(P, t, "Rotate: expected a nonzero axis");
    double x = v[1] / len, y = v[2] / len, z = v[3] / len;
    double s = sin(v[0] * PI / 180), c = cos(v[0] * PI / 180);
    mat_identity(m);
    m[0] = x * x + (1 - x * x) * c;
    m[1] = x * y * (1 - c) - z * s;
    m[2] = x * z * (1 - c) + y * s;
    m[4] = x * y * (1 - c) + z * s;
    m[5] = y * y + (1 - y * y) * c;
    m[6] = y * z * (1 - c) - x * s;
    m[8] = x * z * (1 - c) - y * s;
    m[9] = y * z * (1 - c) + x * s;
    m[10] = z * z + (1 - z * z) * c;
    apply(P, m);
    return 0;
}

static int d_lookat(Parser *P, const Token *t)
{
    double v[9];
    if (expect_numbers(P, v, 9, "a number (LookAt eye target up)") != 0)
        return -1;
    double dir[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]}, up[3] = {v[6], v[7], v[8]};
    double dl = sqrt(dot3d(dir, dir)), ul = sqrt(dot3d(up, up));
    if (!(dl > 0) || !(ul > 0))
        return FAIL_TOK(P, t, "LookAt: expected distinct eye and target and a nonzero up");
    for (int c = 0; c < 3; c++)
        dir[c] /= dl, up[c] /= ul;
    double right[3], nu[3];
    cross3d(up, dir, right);
    double rl = sqrt(dot3d(right, right));
    if (!(rl > 1e-12))
        return FAIL_TOK(P, t, "LookAt: the up vector is parallel to the viewing direction");
    for (int c = 0; c < 3; c++)
        right[c] /= rl;
    cross3d(dir, right, nu);
    double m[16]; /* camera_from_world: rows right, up, dir; translation -R eye */
    const double *rows[3] = {right, nu, dir};
    mat_identity(m);
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[4 * r + c] = rows[r][c];
        m[4 * r + 3] = -dot3d(rows[r], v);
    }
    apply(P, m);
    return 0;
}

static int read_matrix(Parser *P, double m[16])
{
    double v[16];
    if (expect_numbers(P, v, 16, "a number (16 per matrix)") != 0)
        return -1;
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++)
            m[4 * i + j] = v[4 * j + i]; /* pbrt lists the matrix column by column */
    return 0;
}

static int d_transform(Parser *P, const Token *t)
{
    (void)t;
    double m[16];
    if (read_matrix(P, m) != 0)
        return -1;
    if (P->gs.active)
        memcpy(P->gs.ctm, m, sizeof m);
    return 0;
}

static int d_concat(Parser *P, const Token *t)
{
    (void)t;
    double m[16];
    if (read_matrix(P, m) != 0)
        return -1;
    apply(P, m);
    return 0;
}

static int d_identity(Parser *P, const Token *t)
{
    (void)t;
    if (P->gs.active)
        mat_identity(P->gs.ctm);
    return 0;
}

static int set_coordsys(Parser *P, const Token *t, const char *name, const double m[16])
{
    for (size_t i = 0; i < P->n_coordsys; i++)
        if (strcmp(P->coordsys[i].name, name) == 0) {
            memcpy(P->coordsys[i].m, m, sizeof P->coordsys[i].m);
            return 0;
        }
    if ((P->n_coordsys & (P->n_coordsys - 1)) == 0) {
        Named *n = realloc(P->coordsys, (P->n_coordsys ? 2 * P->n_coordsys : 1) * sizeof *n);
        if (!n)
            return FAIL_TOK(P, t, "out of memory");
        P->coordsys = n;
    }
    Named *c = &P->coordsys[P->n_coordsys++];
    snprintf(c->name, sizeof c->name, "%s", name);
    memcpy(c->m, m, sizeof c->m);
    return 0;
}

static int d_coordsys(Parser *P, const Token *t)
{
    char name[128];
    if (expect_string(P, name, sizeof name, "a coordinate system name", NULL) != 0)
        return -1;
    return set_coordsys(P, t, name, P->gs.ctm);
}

static int d_coordsystransform(Parser *P, const Token *t)
{
    char name[128];
    Token w;
    (void)t;
    if (expect_string(P, name, sizeof name, "a coordinate system name", &w) != 0)
        return -1;
    for (size_t i = 0; i < P->n_coordsys; i++)
        if (strcmp(P->coordsys[i].name, name) == 0) {
            memcpy(P->gs.ctm, P->coordsys[i].m, sizeof P->gs.ctm);
            return 0;
        }
    char key[96];
    snprintf(key, sizeof key, "coordsys %.60s", name);
    warn_at(P, w.line, w.col, key, "CoordSysTransform: no coordinate system \"%.60s\"; ignored",
            name);
    return 0;
}

static int d_active(Parser *P, const Token *t)
{
    Token w;
    char b[48];
    if (next(P, &w) != 0)
        return -1;
    if (word_is(&w, "All") || word_is(&w, "StartTime")) {
        P->gs.active = 1;
    } else if (word_is(&w, "EndTime")) {
        P->gs.active = 0;
        warn_at(P, t->line, t->col, "motion", "ActiveTransform EndTime: motion blur is not "
                "supported; end-time transforms are ignored");
    } else {
        return FAIL_TOK(P, &w, "expected All, StartTime or EndTime, found %s", shown(&w, b));
    }
    return 0;
}

static int d_transformtimes(Parser *P, const Token *t)
{
    double v[2];
    if (expect_number(P, &v[0], "a start time") != 0 || expect_number(P, &v[1], "an end time") != 0)
        return -1;
    warn_at(P, t->line, t->col, "TransformTimes", "TransformTimes: motion blur is not supported; "
            "ignored");
    return 0;
}

static int push(Parser *P, const Token *t, int kind)
{
    if (P->n_stack >= PBRT_MAX_STACK)
        return FAIL_TOK(P, t, "more than %d nested AttributeBegin/TransformBegin/ObjectBegin",
                        PBRT_MAX_STACK);
    if (P->n_stack == P->cap_stack) {
        size_t cap = P->cap_stack ? 2 * P->cap_stack : 16;
        GState *s = realloc(P->stack, cap * sizeof *s);
        if (!s)
            return FAIL_TOK(P, t, "out of memory");
        P->stack = s;
        P->cap_stack = cap;
    }
    P->stack[P->n_stack] = P->gs;
    P->stack[P->n_stack++].kind = kind;
    return 0;
}

static int pop(Parser *P, const Token *t, int kind, const char *name)
{
    if (P->n_stack == 0 || (kind == 'O') != (P->stack[P->n_stack - 1].kind == 'O'))
        return FAIL_TOK(P, t, "%s without a matching %sBegin", name,
                        kind == 'O' ? "Object" : kind == 'T' ? "Transform" : "Attribute");
    GState *s = &P->stack[--P->n_stack];
    if (s->kind != kind)
        warn_at(P, t->line, t->col, "mismatched end", "%s closes a %sBegin", name,
                s->kind == 'T' ? "Transform" : "Attribute");
    if (kind == 'T') {
        memcpy(P->gs.ctm, s->ctm, sizeof P->gs.ctm);
        P->gs.active = s->active;
    } else {
        P->gs = *s;
    }
    return 0;
}

static int d_attrbegin(Parser *P, const Token *t) { return push(P, t, 'A'); }
static int d_attrend(Parser *P, const Token *t) { return pop(P, t, 'A', "AttributeEnd"); }
static int d_xformbegin(Parser *P, const Token *t) { return push(P, t, 'T'); }
static int d_xformend(Parser *P, const Token *t) { return pop(P, t, 'T', "TransformEnd"); }

static int d_reverse(Parser *P, const Token *t)
{
    (void)t;
    P->gs.reverse = !P->gs.reverse;
    return 0;
}

/* Directives read and ignored with one warning (their parameters too):
 * leading name strings (those without a space, unlike "type name"), then
 * a parameter list. */
static int d_ignored(Parser *P, const Token *t)
{
    char name[64];
    snprintf(name, sizeof name, "%.*s", (int)t->n, t->s);
    ParamList pl = {0};
    Token a;
    int r = 0;
    for (int k = 0; k < 2 && r == 0; k++) {
        if ((r = peek(P, &a)) != 0 || a.kind != TOK_STRING || memchr(a.s, ' ', a.n))
            break;
        next(P, &a);
    }
    if (!r)
        r = parse_params(P, &pl);
    params_free(&pl);
    if (!r)
        warn_at(P, t->line, t->col, name, "%s is not supported; ignored", name);
    return r;
}

static int d_colorspace(Parser *P, const Token *t)
{
    char name[64];
    Token w;
    if (expect_string(P, name, sizeof name, "a colour space name", &w) != 0)
        return -1;
    if (strcmp(name, "srgb") != 0)
        warn_at(P, w.line, w.col, "colorspace", "ColorSpace \"%.40s\": rayes works in linear sRGB; "
                "colours are taken as they are", name);
    (void)t;
    return 0;
}

static int d_camera(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = need_world(P, t, 0);
    if (!r)
        r = name_and_params(P, type, sizeof type, "a camera type", &pl, NULL);
    if (r) {
        params_free(&pl);
        return -1;
    }
    memcpy(P->camera_from_world, P->gs.ctm, sizeof P->camera_from_world);
    double inv[16];
    if (mat_inverse(P->gs.ctm, inv) != 0) {
        params_free(&pl);
        return FAIL_TOK(P, t, "Camera: the camera transform is singular");
    }
    r = set_coordsys(P, t, "camera", inv);
    P->projection = strcmp(type, "orthographic") == 0 ? RAYES_PROJECTION_ORTHOGRAPHIC
                                                      : RAYES_PROJECTION_PERSPECTIVE;
    if (strcmp(type, "perspective") != 0 && strcmp(type, "orthographic") != 0)
        warn_at(P, t->line, t->col, "camera type", "Camera \"%.40s\" is not supported; using a "
                "perspective camera", type);
    P->fov = (float)get_float(&pl, "fov", 90.0);
    if (!(P->fov > 0 && P->fov < 180)) {
        params_free(&pl);
        return FAIL_TOK(P, t, "Camera: expected fov between 0 and 180 degrees");
    }
    Param *sw = find(&pl, "screenwindow");
    P->have_screen = sw && sw->n_num == 4;
    for (int i = 0; P->have_screen && i < 4; i++)
        P->screen[i] = (float)sw->num[i];
    if (get_float(&pl, "lensradius", 0.0) > 0)
        warn_at(P, t->line, t->col, "lensradius", "Camera: depth of field (lensradius) is not "
                "supported; the camera is a pinhole");
    find(&pl, "focaldistance");
    warn_unused(P, &pl, "Camera", type);
    params_free(&pl);
    return r;
}

static int d_film(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (need_world(P, t, 0) || name_and_params(P, type, sizeof type, "a film type", &pl, NULL)) {
        params_free(&pl);
        return -1;
    }
    IoSettings *s = P->settings;
    double w = get_float(&pl, "xresolution", 1280), h = get_float(&pl, "yresolution", 720);
    if (!(w >= 1 && w <= 65536 && h >= 1 && h <= 65536)) {
        params_free(&pl);
        return FAIL_TOK(P, t, "Film: expected resolutions from 1 to 65536");
    }
    s->width = (int)w, s->height = (int)h;
    const char *file = get_string(&pl, "filename", NULL);
    if (file) {
        IoDisplay *d = &s->displays[0];
        memset(d, 0, sizeof *d);
        snprintf(d->name, sizeof d->name, "%s", file);
        const char *dot = strrchr(file, '.');
        snprintf(d->type, sizeof d->type, "%s", dot && strcmp(dot, ".exr") == 0   ? "openexr"
                                                : dot && strcmp(dot, ".png") == 0 ? "png"
                                                                                  : "file");
        snprintf(d->mode, sizeof d->mode, "rgba");
        s->n_displays = 1;
    }
    Param *crop = find(&pl, "cropwindow");
    if (crop && crop->n_num == 4)
        for (int i = 0; i < 4; i++)
            s->crop[i] = (float)fmin(1.0, fmax(0.0, crop->num[i]));
    if (strcmp(type, "rgb") != 0)
        warn_at(P, t->line, t->col, "film type", "Film \"%.40s\": written as an rgb film", type);
    warn_unused(P, &pl, "Film", type);
    params_free(&pl);
    return 0;
}

static int d_sampler(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (need_world(P, t, 0) || name_and_params(P, type, sizeof type, "a sampler type", &pl, NULL)) {
        params_free(&pl);
        return -1;
    }
    double spp = get_float(&pl, "pixelsamples", 16);
    if (!(spp >= 1 && spp <= 1e6)) {
        params_free(&pl);
        return FAIL_TOK(P, t, "Sampler: expected pixelsamples from 1 to 1000000");
    }
    P->settings->spp = (int)spp;
    find(&pl, "seed");
    find(&pl, "randomization");
    warn_unused(P, &pl, "Sampler", type);
    params_free(&pl);
    return 0;
}

static int d_integrator(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (need_world(P, t, 0) ||
        name_and_params(P, type, sizeof type, "an integrator type", &pl, NULL)) {
        params_free(&pl);
        return -1;
    }
    double depth = get_float(&pl, "maxdepth", 5);
    if (!(depth >= 0 && depth <= 1e6)) {
        params_free(&pl);
        return FAIL_TOK(P, t, "Integrator: expected maxdepth >= 0");
    }
    /* pbrt's maxdepth 1 is direct light only: rayes' 0 diffuse bounces */
    P->settings->bounces = depth >= 1 ? (int)depth - 1 : 0;
    P->settings->specular_depth = (int)depth;
    if (strcmp(type, "ambientocclusion") == 0 || strcmp(type, "sppm") == 0 ||
        strcmp(type, "mlt") == 0)
        warn_at(P, t->line, t->col, "integrator", "Integrator \"%.40s\": rayes renders with its "
                "own integrator (radiosity cache)", type);
    find(&pl, "regularize");
    find(&pl, "lightsampler");
    warn_unused(P, &pl, "Integrator", type);
    params_free(&pl);
    return 0;
}

static int d_filter(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    if (need_world(P, t, 0) || name_and_params(P, type, sizeof type, "a filter type", &pl, NULL)) {
        params_free(&pl);
        return -1;
    }
    if (strcmp(type, "box") == 0 || strcmp(type, "gaussian") == 0) {
        int box = type[0] == 'b';
        double rx = get_float(&pl, "xradius", box ? 0.5 : 1.5);
        double ry = get_float(&pl, "yradius", rx);
        find(&pl, "sigma");
        P->settings->filter = box ? RAYES_FILTER_BOX : RAYES_FILTER_GAUSSIAN;
        P->settings->filter_width = (float)fmax(0.01, rx + ry);
        warn_unused(P, &pl, "PixelFilter", type);
    } else {
        warn_at(P, t->line, t->col, "filter", "PixelFilter \"%.40s\" is not supported; using the "
                "renderer's default filter", type);
    }
    params_free(&pl);
    return 0;
}

static int emit_camera(Parser *P, const Token *t)
{
    float m[16];
    if (!mat_finite(P->camera_from_world))
        return FAIL_TOK(P, t, "the camera transform is not finite");
    mat_to_float(P->camera_from_world, m);
    RayesError e = P->sink->set_camera_matrix(P->sink->target, m, P->projection, P->fov,
                                              P->have_screen ? P->screen : NULL);
    return e != RAYES_OK ? sink_failed(P, t, e) : 0;
}

static int d_worldbegin(Parser *P, const Token *t)
{
    if (need_world(P, t, 0) != 0)
        return -1;
    P->world = 1;
    mat_identity(P->gs.ctm);
    if (set_coordsys(P, t, "world", P->gs.ctm) != 0)
        return -1;
    if (P->settings->width == 0) {
        P->settings->width = 1280; /* pbrt's default film */
        P->settings->height = 720;
    }
    return emit_camera(P, t);
}

static int d_worldend(Parser *P, const Token *t)
{
    (void)P, (void)t; /* pbrt-v3's; the file ends the world in v4 */
    return 0;
}

static int d_material(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = need_world(P, t, 1);
    if (!r)
        r = name_and_params(P, type, sizeof type, "a material type", &pl, NULL);
    if (!r)
        r = make_material(P, t, type, &pl, &P->gs.material);
    if (!r)
        warn_unused(P, &pl, "Material", type);
    params_free(&pl);
    return r;
}

static int d_makenamedmaterial(Parser *P, const Token *t)
{
    char name[128];
    ParamList pl = {0};
    Material m;
    int r = need_world(P, t, 1);
    if (!r)
        r = name_and_params(P, name, sizeof name, "a material name", &pl, NULL);
    const char *type = r ? NULL : get_string(&pl, "type", NULL);
    if (!r && !type)
        r = FAIL_TOK(P, t, "MakeNamedMaterial \"%.60s\": expected \"string type\"", name);
    if (!r)
        r = make_material(P, t, type, &pl, &m);
    if (!r) {
        warn_unused(P, &pl, "MakeNamedMaterial", type);
        if ((P->n_materials & (P->n_materials - 1)) == 0) {
            NamedMaterial *n =
                realloc(P->materials, (P->n_materials ? 2 * P->n_materials : 1) * sizeof *n);
            if (!n)
                r = FAIL_TOK(P, t, "out of memory");
            else
                P->materials = n;
        }
        if (!r) {
            NamedMaterial *nm = &P->materials[P->n_materials++];
            snprintf(nm->name, sizeof nm->name, "%s", name);
            nm->m = m;
        }
    }
    params_free(&pl);
    return r;
}

static int d_namedmaterial(Parser *P, const Token *t)
{
    char name[128];
    Token w;
    if (need_world(P, t, 1) || expect_string(P, name, sizeof name, "a material name", &w) != 0)
        return -1;
    const Material *m = named_material(P, name);
    if (!m)
        return FAIL_TOK(P, &w, "NamedMaterial: expected a material defined with "
                        "MakeNamedMaterial, found \"%.60s\"", name);
    P->gs.material = *m;
    return 0;
}

static int d_texture(Parser *P, const Token *t)
{
    char name[128], kind[32], cls[64];
    ParamList pl = {0};
    int r = need_world(P, t, 1);
    if (!r)
        r = expect_string(P, name, sizeof name, "a texture name", NULL);
    if (!r)
        r = expect_string(P, kind, sizeof kind, "a texture type (\"spectrum\" or \"float\")", NULL);
    if (!r)
        r = name_and_params(P, cls, sizeof cls, "a texture class", &pl, NULL);
    if (r) {
        params_free(&pl);
        return -1;
    }
    Texture tex;
    memset(&tex, 0, sizeof tex);
    snprintf(tex.name, sizeof tex.name, "%s", name);
    static const float one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    if (strcmp(cls, "imagemap") == 0) {
        const char *file = get_string(&pl, "filename", NULL);
        if (!file)
            r = FAIL_TOK(P, t, "imagemap: expected \"string filename\"");
        if (!r)
            r = resolve(P, t, file, tex.path, sizeof tex.path);
        double scale = get_float(&pl, "scale", 1.0);
        tex.rgb[0] = tex.rgb[1] = tex.rgb[2] = (float)scale;
        tex.image = 1;
        static const char *quiet[] = {"filter", "maxanisotropy", "wrap", "encoding", "invert",
                                      "uscale", "vscale", "udelta", "vdelta", "mapping"};
        for (size_t i = 0; i < sizeof quiet / sizeof quiet[0]; i++)
            if (find(&pl, quiet[i]) && i >= 4)
                warn_at(P, t->line, t->col, "imagemap mapping", "imagemap: mapping and "
                        "encoding parameters are not supported; the image is used as it is");
    } else if (strcmp(cls, "checkerboard") == 0) {
        float a[3], b[3];
        if (get_color(P, &pl, "tex1", one, a, NULL) < 0 || get_color(P, &pl, "tex2", zero, b, NULL) < 0)
            r = -1;
        for (int c = 0; c < 3; c++)
            tex.rgb[c] = 0.5f * (a[c] + b[c]);
        warn_at(P, t->line, t->col, "checkerboard", "checkerboard: rayes has no built-in pattern "
                "shader for it; using the average of tex1 and tex2");
        for (size_t i = 0; i < pl.n; i++)
            pl.p[i].used = 1;
    } else if (strcmp(cls, "constant") == 0) {
        r = get_color(P, &pl, "value", one, tex.rgb, NULL) < 0;
    } else if (strcmp(cls, "scale") == 0) {
        float a[3], b[3];
        const Texture *img = NULL;
        int k = get_color(P, &pl, "tex", one, a, &img);
        if (k < 0 || get_color(P, &pl, "scale", one, b, NULL) < 0)
            r = -1;
        if (!r && k == 2) {
            tex = *img;
            snprintf(tex.name, sizeof tex.name, "%s", name);
        }
        for (int c = 0; c < 3; c++)
            tex.rgb[c] = a[c] * b[c];
    } else {
        char key[96];
        snprintf(key, sizeof key, "texture %.60s", cls);
        warn_at(P, t->line, t->col, key, "Texture \"%.40s\" is not supported; using a constant "
                "0.5", cls);
        tex.rgb[0] = tex.rgb[1] = tex.rgb[2] = 0.5f;
        for (size_t i = 0; i < pl.n; i++)
            pl.p[i].used = 1;
    }
    if (!r) {
        warn_unused(P, &pl, "Texture", cls);
        if ((P->n_textures & (P->n_textures - 1)) == 0) {
            Texture *n = realloc(P->textures, (P->n_textures ? 2 * P->n_textures : 1) * sizeof *n);
            if (!n)
                r = FAIL_TOK(P, t, "out of memory");
            else
                P->textures = n;
        }
        if (!r)
            P->textures[P->n_textures++] = tex;
    }
    params_free(&pl);
    return r ? -1 : 0;
}

static int d_arealight(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = need_world(P, t, 1);
    if (!r)
        r = name_and_params(P, type, sizeof type, "an area light type", &pl, NULL);
    if (r) {
        params_free(&pl);
        return -1;
    }
    static const float one[3] = {1, 1, 1};
    memset(&P->gs.area, 0, sizeof P->gs.area);
    if (strcmp(type, "diffuse") != 0) {
        warn_at(P, t->line, t->col, "area light type", "AreaLightSource \"%.40s\" is not "
                "supported; the shapes that follow do not emit", type);
        params_free(&pl);
        return 0;
    }
    float L[3];
    if (get_color(P, &pl, "L", one, L, NULL) < 0) {
        params_free(&pl);
        return -1;
    }
    double scale = get_float(&pl, "scale", 1.0);
    Param *tw = find(&pl, "twosided");
    P->gs.area.twosided = tw && tw->n_num > 0 && tw->num[0] != 0;
    if (find(&pl, "filename"))
        warn_at(P, t->line, t->col, "area filename", "AreaLightSource: image emission "
                "(\"filename\") is not supported; using L");
    if (find(&pl, "power"))
        warn_at(P, t->line, t->col, "area power", "AreaLightSource: \"power\" is not supported "
                "(it needs the shape's area); using L and scale");
    for (int c = 0; c < 3; c++)
        P->gs.area.L[c] = (float)(L[c] * scale);
    P->gs.area.on = 1;
    warn_unused(P, &pl, "AreaLightSource", type);
    params_free(&pl);
    return 0;
}

static int d_light(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = need_world(P, t, 1);
    if (!r)
        r = name_and_params(P, type, sizeof type, "a light type", &pl, NULL);
    if (r) {
        params_free(&pl);
        return -1;
    }
    static const float one[3] = {1, 1, 1};
    double scale = get_float(&pl, "scale", 1.0), power = get_float(&pl, "power", 0.0);
    float col[3];
    RayesParam lp[8];
    size_t n = 0;
    const char *rtype = NULL;
    double zero3[3] = {0, 0, 0}, z1[3] = {0, 0, 1};
    if (P->recording)
        warn_at(P, t->line, t->col, "instanced light", "LightSource inside ObjectBegin: the "
                "light is added once, not per instance");
    if (strcmp(type, "point") == 0 || strcmp(type, "spot") == 0) {
        if (get_color(P, &pl, "I", one, col, NULL) < 0)
            r = -1;
        const double *from = get_point(&pl, "from");
        from = from ? from : zero3;
        lp[n++] = (RayesParam){.name = "from", .type = RAYES_PARAM_COLOR,
                               .value = {(float)from[0], (float)from[1], (float)from[2]}};
        double k_e = 4 * PI;
        if (type[0] == 's') {
            const double *to = get_point(&pl, "to");
            to = to ? to : z1;
            double cone = get_float(&pl, "coneangle", 30), delta = get_float(&pl, "conedeltaangle", 5);
            lp[n++] = (RayesParam){.name = "to", .type = RAYES_PARAM_COLOR,
                                   .value = {(float)to[0], (float)to[1], (float)to[2]}};
            lp[n++] = (RayesParam){.name = "coneangle", .type = RAYES_PARAM_FLOAT, .value = {(float)cone}};
            lp[n++] = (RayesParam){.name = "conedeltaangle", .type = RAYES_PARAM_FLOAT,
                                   .value = {(float)delta}};
            lp[n++] = (RayesParam){.name = "beamdistribution", .type = RAYES_PARAM_FLOAT};
            double c0 = cos(cone * PI / 180), c1 = cos((cone - delta) * PI / 180);
            k_e = 2 * PI * ((1 - c1) + (c1 - c0) / 2);
        }
        if (power > 0 && luminance(col) > 0)
            scale *= power / (k_e * luminance(col));
        rtype = type[0] == 's' ? "spotlight" : "pointlight";
    } else if (strcmp(type, "distant") == 0) {
        if (get_color(P, &pl, "L", one, col, NULL) < 0)
            r = -1;
        const double *from = get_point(&pl, "from"), *to = get_point(&pl, "to");
        from = from ? from : zero3;
        to = to ? to : z1;
        lp[n++] = (RayesParam){.name = "from", .type = RAYES_PARAM_COLOR,
                               .value = {(float)from[0], (float)from[1], (float)from[2]}};
        lp[n++] = (RayesParam){.name = "to", .type = RAYES_PARAM_COLOR,
                               .value = {(float)to[0], (float)to[1], (float)to[2]}};
        double E = get_float(&pl, "illuminance", 0.0);
        if (E > 0 && luminance(col) > 0)
            scale *= E / luminance(col);
        rtype = "distantlight";
    } else if (strcmp(type, "infinite") == 0) {
        if (get_color(P, &pl, "L", one, col, NULL) < 0)
            r = -1;
        const char *file = get_string(&pl, "filename", NULL);
        if (file)
            warn_at(P, t->line, t->col, "infinite map", "LightSource \"infinite\": \"%.60s\" is an "
                    "equal-area octahedral map, which rayes cannot read (it takes latitude-"
                    "longitude maps); using a constant environment of radiance scale", file);
        if (get_float(&pl, "illuminance", 0.0) > 0)
            warn_at(P, t->line, t->col, "infinite illuminance", "LightSource \"infinite\": "
                    "\"illuminance\" is not supported; using scale");
        find(&pl, "portal");
        rtype = "environmentlight";
    } else {
        char key[96];
        snprintf(key, sizeof key, "light %.60s", type);
        warn_at(P, t->line, t->col, key, "LightSource \"%.40s\" is not supported; skipped", type);
        params_free(&pl);
        return 0;
    }
    if (!r) {
        lp[n++] = (RayesParam){.name = "intensity", .type = RAYES_PARAM_FLOAT, .value = {(float)scale}};
        lp[n++] = (RayesParam){.name = "lightcolor", .type = RAYES_PARAM_COLOR,
                               .value = {col[0], col[1], col[2]}};
        warn_unused(P, &pl, "LightSource", type);
        r = emit_light(P, t, P->gs.ctm, rtype, lp, n);
    }
    params_free(&pl);
    return r;
}

static int d_shape(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = need_world(P, t, 1);
    if (!r)
        r = name_and_params(P, type, sizeof type, "a shape type", &pl, NULL);
    if (r) {
        params_free(&pl);
        return -1;
    }
    if (find(&pl, "alpha"))
        warn_at(P, t->line, t->col, "alpha", "Shape: \"alpha\" cut-outs are not supported");
    if (strcmp(type, "trianglemesh") == 0)
        r = shape_trianglemesh(P, t, &pl);
    else if (strcmp(type, "bilinearmesh") == 0)
        r = shape_bilinearmesh(P, t, &pl);
    else if (strcmp(type, "plymesh") == 0)
        r = shape_plymesh(P, t, &pl);
    else if (strcmp(type, "sphere") == 0 || strcmp(type, "disk") == 0 ||
             strcmp(type, "cylinder") == 0)
        r = shape_quadric(P, t, type, &pl);
    else {
        char key[96];
        snprintf(key, sizeof key, "shape %.60s", type);
        warn_at(P, t->line, t->col, key, "Shape \"%.40s\" is not supported; skipped", type);
        params_free(&pl);
        return 0;
    }
    if (!r)
        warn_unused(P, &pl, "Shape", type);
    params_free(&pl);
    return r;
}

static int d_objectbegin(Parser *P, const Token *t)
{
    char name[128];
    if (need_world(P, t, 1) || expect_string(P, name, sizeof name, "an object name", NULL) != 0)
        return -1;
    if (P->recording)
        return FAIL_TOK(P, t, "ObjectBegin inside ObjectBegin \"%.60s\"", P->recording->name);
    if (push(P, t, 'O') != 0)
        return -1;
    if ((P->n_objects & (P->n_objects - 1)) == 0) {
        Object *n = realloc(P->objects, (P->n_objects ? 2 * P->n_objects : 1) * sizeof *n);
        if (!n)
            return FAIL_TOK(P, t, "out of memory");
        P->objects = n;
    }
    Object *o = &P->objects[P->n_objects++];
    memset(o, 0, sizeof *o);
    snprintf(o->name, sizeof o->name, "%s", name);
    P->recording = o;
    return 0;
}

static int d_objectend(Parser *P, const Token *t)
{
    if (!P->recording)
        return FAIL_TOK(P, t, "ObjectEnd without a matching ObjectBegin");
    P->recording = NULL;
    return pop(P, t, 'O', "ObjectEnd");
}

static int d_objectinstance(Parser *P, const Token *t)
{
    char name[128];
    Token w;
    if (need_world(P, t, 1) || expect_string(P, name, sizeof name, "an object name", &w) != 0)
        return -1;
    if (P->recording)
        return FAIL_TOK(P, t, "ObjectInstance inside ObjectBegin \"%.60s\"", P->recording->name);
    for (size_t i = P->n_objects; i-- > 0;)
        if (strcmp(P->objects[i].name, name) == 0)
            return replay(P, t, &P->objects[i]);
    return FAIL_TOK(P, &w, "ObjectInstance: expected an object defined with ObjectBegin, found "
                    "\"%.60s\"", name);
}

static int parse_buffer(Parser *P, const char *name, const char *dir, const char *data,
                        size_t size);

static int d_include(Parser *P, const Token *t)
{
    char file[PBRT_PATH], path[PBRT_PATH];
    Token w;
    if (expect_string(P, file, sizeof file, "a file name", &w) != 0 ||
        resolve(P, &w, file, path, sizeof path) != 0)
        return -1;
    if (P->depth >= PBRT_MAX_INCLUDE_DEPTH)
        return FAIL_TOK(P, &w, "more than %d nested Include/Import", PBRT_MAX_INCLUDE_DEPTH);
    if (++P->n_files > PBRT_MAX_FILES)
        return FAIL_TOK(P, &w, "more than %d included files", PBRT_MAX_FILES);
    size_t n;
    char err[600];
    char *text = text_read_file(path, &n, err, sizeof err);
    if (!text)
        return FAIL_TOK(P, &w, "%s: %s", t->s[1] == 'm' ? "Import" : "Include", err);
    char dir[PBRT_PATH];
    dir_of(path, dir, sizeof dir);
    int r = parse_buffer(P, path, dir, text, n);
    free(text);
    return r;
}

static const struct {
    const char *name;
    Handler fn;
} directives[] = {
    {"Accelerator", d_ignored},
    {"ActiveTransform", d_active},
    {"AreaLightSource", d_arealight},
    {"Attribute", d_ignored},
    {"AttributeBegin", d_attrbegin},
    {"AttributeEnd", d_attrend},
    {"Camera", d_camera},
    {"ColorSpace", d_colorspace},
    {"ConcatTransform", d_concat},
    {"CoordinateSystem", d_coordsys},
    {"CoordSysTransform", d_coordsystransform},
    {"Film", d_film},
    {"Identity", d_identity},
    {"Import", d_include},
    {"Include", d_include},
    {"Integrator", d_integrator},
    {"LightSource", d_light},
    {"LookAt", d_lookat},
    {"MakeNamedMaterial", d_makenamedmaterial},
    {"MakeNamedMedium", d_ignored},
    {"Material", d_material},
    {"MediumInterface", d_ignored},
    {"NamedMaterial", d_namedmaterial},
    {"ObjectBegin", d_objectbegin},
    {"ObjectEnd", d_objectend},
    {"ObjectInstance", d_objectinstance},
    {"Option", d_ignored},
    {"PixelFilter", d_filter},
    {"ReverseOrientation", d_reverse},
    {"Rotate", d_rotate},
    {"Sampler", d_sampler},
    {"Scale", d_scale},
    {"Shape", d_shape},
    {"Texture", d_texture},
    {"Transform", d_transform},
    {"TransformBegin", d_xformbegin},
    {"TransformEnd", d_xformend},
    {"TransformTimes", d_transformtimes},
    {"Translate", d_translate},
    {"WorldBegin", d_worldbegin},
    {"WorldEnd", d_worldend},
};

static int parse_buffer(Parser *P, const char *name, const char *dir, const char *data,
                        size_t size)
{
    Lexer lx = {.name = name, .p = data, .end = data + size, .line = 1, .line_start = data};
    snprintf(lx.dir, sizeof lx.dir, "%s", dir);
    Lexer *saved = P->lx;
    int saved_peek = P->has_peek;
    Token saved_tok = P->peeked;
    P->lx = &lx;
    P->has_peek = 0;
    P->depth++;
    int r = 0;
    for (;;) {
        Token t;
        char b[48];
        if ((r = next(P, &t)) != 0)
            break;
        if (t.kind == TOK_END)
            break;
        Handler fn = NULL;
        for (size_t i = 0; t.kind == TOK_WORD && i < sizeof directives / sizeof directives[0]; i++)
            if (word_is(&t, directives[i].name))
                fn = directives[i].fn;
        if (!fn) {
            r = FAIL_TOK(P, &t, "expected a directive (Shape, Material, Translate, ...), found %s",
                         shown(&t, b));
            break;
        }
        if ((r = fn(P, &t)) != 0)
            break;
    }
    P->depth--;
    P->lx = saved; /* an error's message, written already, names the innermost file */
    P->has_peek = saved_peek;
    P->peeked = saved_tok;
    return r;
}

/* ------------------------------------------------------------ entry points */

static void parser_free(Parser *P)
{
    for (size_t i = 0; i < P->n_objects; i++) {
        for (size_t k = 0; k < P->objects[i].n_ops; k++) {
            Op *op = &P->objects[i].ops[k];
            free(op->mat);
            free(op->n_verts);
            free(op->idx);
            free(op->pts);
            free(op->N);
            free(op->uv);
        }
        free(P->objects[i].ops);
    }
    free(P->objects);
    free(P->stack);
    free(P->coordsys);
    free(P->materials);
    free(P->textures);
    free(P->warned);
}

RayesError io_pbrt_parse(const char *name, const unsigned char *data, size_t size,
                         const IoSink *sink, const IoReadOptions *options, IoSettings *settings,
                         char *err, size_t err_size)
{
    Parser *P = calloc(1, sizeof *P);
    if (!P) {
        snprintf(err, err_size, "%s: out of memory", name);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    P->warned = calloc(PBRT_MAX_WARNED, sizeof *P->warned);
    if (!P->warned) {
        free(P);
        snprintf(err, err_size, "%s: out of memory", name);
        return RAYES_ERROR_OUT_OF_MEMORY;
    }
    P->sink = sink;
    P->options = options;
    P->settings = settings;
    P->err = err;
    P->err_size = err_size;
    if (err_size)
        err[0] = '\0';
    mat_identity(P->gs.ctm);
    mat_identity(P->camera_from_world);
    P->gs.active = 1;
    P->fov = 90;
    mat_init(&P->gs.material, "diffuse"); /* pbrt's default material: diffuse 0.5 */
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    mat_color(&P->gs.material, "reflectance", half);
    char dir[PBRT_PATH];
    dir_of(name, dir, sizeof dir);
    static const char empty[1] = "";
    int r = parse_buffer(P, name, dir, data ? (const char *)data : empty, data ? size : 0);
    if (!r && P->recording) {
        snprintf(err, err_size, "%s: ObjectBegin \"%.60s\" has no ObjectEnd", name,
                 P->recording->name);
        r = -1;
    }
    if (!r && !P->world) {
        snprintf(err, err_size, "%s: expected WorldBegin, found the end of the file", name);
        r = -1;
    }
    parser_free(P);
    free(P);
    return r ? RAYES_ERROR_PARSE : RAYES_OK;
}

RayesError io_pbrt_read(const char *path, const IoSink *sink, const IoReadOptions *options,
                        IoSettings *settings, char *err, size_t err_size)
{
    size_t n;
    char *text = text_read_file(path, &n, err, err_size);
    if (!text)
        return RAYES_ERROR_IO;
    RayesError e = io_pbrt_parse(path, (const unsigned char *)text, n, sink, options, settings,
                                 err, err_size);
    free(text);
    return e;
}
