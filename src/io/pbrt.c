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
 * to the sink through pbrt_emit_* (pbrt_emit.c); between ObjectBegin and
 * ObjectEnd the same calls are recorded instead, with their transform and
 * material, and ObjectInstance replays them under the instance's
 * transform.
 *
 * Limits keep bad input cheap: include depth and file count, stack depth,
 * replayed primitives; every index is checked before it is used. Warnings
 * go to standard error once per kind and per read.
 *
 * This file holds the directives of the graphics state (transforms,
 * blocks, coordinate systems, objects, Include), the directive table and
 * the entry points; the other directives live in the file of their
 * concern, which pbrt_internal.h lists, over pbrt_lex.c (messages, tokens,
 * matrices, paths) that every file uses.
 */
#include "io/pbrt.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "io/text.h"
#include "util/log.h"

#define PBRT_MAX_INCLUDE_DEPTH 16
#define PBRT_MAX_FILES 256
#define PBRT_MAX_STACK 1024

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

/* ------------------------------------------------------------ directives */

typedef struct Directive Directive;
typedef int (*Handler)(Parser *P, const Token *t);

/* Concatenates m onto the active transforms (start, end, or both). */
static void apply(Parser *P, const double m[16])
{
    if (P->gs.active & 1)
        pbrt_mat_mul(P->gs.ctm, m, P->gs.ctm);
    if (P->gs.active & 2)
        pbrt_mat_mul(P->gs.ctm_end, m, P->gs.ctm_end);
}

static int d_translate(Parser *P, const Token *t)
{
    (void)t;
    double v[3], m[16];
    if (pbrt_expect_numbers(P, v, 3, "a number (Translate x y z)") != 0)
        return -1;
    pbrt_mat_identity(m);
    m[3] = v[0], m[7] = v[1], m[11] = v[2];
    apply(P, m);
    return 0;
}

static int d_scale(Parser *P, const Token *t)
{
    (void)t;
    double v[3], m[16];
    if (pbrt_expect_numbers(P, v, 3, "a number (Scale x y z)") != 0)
        return -1;
    pbrt_mat_identity(m);
    m[0] = v[0], m[5] = v[1], m[10] = v[2];
    apply(P, m);
    return 0;
}

static int d_rotate(Parser *P, const Token *t)
{
    double v[4], m[16];
    if (pbrt_expect_numbers(P, v, 4, "a number (Rotate angle x y z)") != 0)
        return -1;
    double len = sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(len > 0))
        return FAIL_TOK(P, t, "Rotate: expected a nonzero axis");
    double x = v[1] / len, y = v[2] / len, z = v[3] / len;
    double s = sin(v[0] * PI / 180), c = cos(v[0] * PI / 180);
    pbrt_mat_identity(m);
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
    if (pbrt_expect_numbers(P, v, 9, "a number (LookAt eye target up)") != 0)
        return -1;
    double dir[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]}, up[3] = {v[6], v[7], v[8]};
    double dl = sqrt(pbrt_dot3d(dir, dir)), ul = sqrt(pbrt_dot3d(up, up));
    if (!(dl > 0) || !(ul > 0))
        return FAIL_TOK(P, t, "LookAt: expected distinct eye and target and a nonzero up");
    for (int c = 0; c < 3; c++)
        dir[c] /= dl, up[c] /= ul;
    double right[3], nu[3];
    pbrt_cross3d(up, dir, right);
    double rl = sqrt(pbrt_dot3d(right, right));
    if (!(rl > 1e-12))
        return FAIL_TOK(P, t, "LookAt: the up vector is parallel to the viewing direction");
    for (int c = 0; c < 3; c++)
        right[c] /= rl;
    pbrt_cross3d(dir, right, nu);
    double m[16]; /* camera_from_world: rows right, up, dir; translation -R eye */
    const double *rows[3] = {right, nu, dir};
    pbrt_mat_identity(m);
    for (int r = 0; r < 3; r++) {
        for (int c = 0; c < 3; c++)
            m[4 * r + c] = rows[r][c];
        m[4 * r + 3] = -pbrt_dot3d(rows[r], v);
    }
    apply(P, m);
    return 0;
}

static int read_matrix(Parser *P, double m[16])
{
    double v[16];
    if (pbrt_expect_numbers(P, v, 16, "a number (16 per matrix)") != 0)
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
    if (P->gs.active & 1)
        memcpy(P->gs.ctm, m, sizeof m);
    if (P->gs.active & 2)
        memcpy(P->gs.ctm_end, m, sizeof m);
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
    if (P->gs.active & 1)
        pbrt_mat_identity(P->gs.ctm);
    if (P->gs.active & 2)
        pbrt_mat_identity(P->gs.ctm_end);
    return 0;
}

static int d_coordsys(Parser *P, const Token *t)
{
    char name[128];
    if (pbrt_expect_string(P, name, sizeof name, "a coordinate system name", NULL) != 0)
        return -1;
    return pbrt_set_coordsys(P, t, name, P->gs.ctm);
}

static int d_coordsystransform(Parser *P, const Token *t)
{
    char name[128];
    Token w;
    (void)t;
    if (pbrt_expect_string(P, name, sizeof name, "a coordinate system name", &w) != 0)
        return -1;
    for (size_t i = 0; i < P->n_coordsys; i++)
        if (strcmp(P->coordsys[i].name, name) == 0) {
            memcpy(P->gs.ctm, P->coordsys[i].m, sizeof P->gs.ctm);
            memcpy(P->gs.ctm_end, P->coordsys[i].m, sizeof P->gs.ctm_end);
            return 0;
        }
    char key[96];
    snprintf(key, sizeof key, "coordsys %.60s", name);
    pbrt_warn_at(P, w.line, w.col, key,
                 "CoordSysTransform: no coordinate system \"%.60s\"; ignored", name);
    return 0;
}

static int d_active(Parser *P, const Token *t)
{
    Token w;
    char b[48];
    (void)t;
    if (pbrt_next(P, &w) != 0)
        return -1;
    if (pbrt_word_is(&w, "All"))
        P->gs.active = 3;
    else if (pbrt_word_is(&w, "StartTime"))
        P->gs.active = 1;
    else if (pbrt_word_is(&w, "EndTime"))
        P->gs.active = 2;
    else
        return FAIL_TOK(P, &w, "expected All, StartTime or EndTime, found %s", pbrt_shown(&w, b));
    return 0;
}

static int d_transformtimes(Parser *P, const Token *t)
{
    double v[2];
    if (pbrt_expect_number(P, &v[0], "a start time") != 0 || pbrt_expect_number(P, &v[1], "an end time") != 0)
        return -1;
    if (!isfinite(v[0]) || !isfinite(v[1]) || !(v[1] > v[0]))
        return FAIL_TOK(P, t, "TransformTimes: expected finite start < end, found %g %g", v[0],
                        v[1]);
    P->transform_times[0] = v[0], P->transform_times[1] = v[1];
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
        pbrt_warn_at(P, t->line, t->col, "mismatched end", "%s closes a %sBegin", name,
                     s->kind == 'T' ? "Transform" : "Attribute");
    if (kind == 'T') {
        memcpy(P->gs.ctm, s->ctm, sizeof P->gs.ctm);
        memcpy(P->gs.ctm_end, s->ctm_end, sizeof P->gs.ctm_end);
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
        if ((r = pbrt_peek(P, &a)) != 0 || a.kind != TOK_STRING || memchr(a.s, ' ', a.n))
            break;
        pbrt_next(P, &a);
    }
    if (!r)
        r = pbrt_parse_params(P, &pl);
    pbrt_params_free(&pl);
    /* Accelerator chooses pbrt's own ray structure: nothing to say */
    if (!r && strcmp(name, "Accelerator") != 0)
        pbrt_warn_at(P, t->line, t->col, name, "%s is not supported; ignored", name);
    return r;
}

static int d_objectbegin(Parser *P, const Token *t)
{
    char name[128];
    if (pbrt_need_world(P, t, 1) ||
        pbrt_expect_string(P, name, sizeof name, "an object name", NULL) != 0)
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
    if (pbrt_need_world(P, t, 1) ||
        pbrt_expect_string(P, name, sizeof name, "an object name", &w) != 0)
        return -1;
    if (P->recording)
        return FAIL_TOK(P, t, "ObjectInstance inside ObjectBegin \"%.60s\"", P->recording->name);
    for (size_t i = P->n_objects; i-- > 0;)
        if (strcmp(P->objects[i].name, name) == 0)
            return pbrt_replay(P, t, &P->objects[i]);
    return FAIL_TOK(P, &w, "ObjectInstance: expected an object defined with ObjectBegin, found "
                    "\"%.60s\"", name);
}

/* Include and Import: the file's tokens come next, then the rest of this
 * file's (pbrt-v4 reads one stream of tokens, so a directive that ends an
 * included file may take parameters that follow the Include: pbrt-v4's
 * smoke-plume scene names a medium's type in one and its coefficients
 * after). The lexer returns to this file at the included one's end. */
static int d_include(Parser *P, const Token *t)
{
    char file[PBRT_PATH], path[PBRT_PATH];
    Token w;
    if (pbrt_expect_string(P, file, sizeof file, "a file name", &w) != 0 ||
        pbrt_resolve(P, &w, file, path, sizeof path) != 0)
        return -1;
    if (P->depth >= PBRT_MAX_INCLUDE_DEPTH)
        return FAIL_TOK(P, &w, "more than %d nested Include/Import", PBRT_MAX_INCLUDE_DEPTH);
    if (++P->n_files > PBRT_MAX_FILES)
        return FAIL_TOK(P, &w, "more than %d included files", PBRT_MAX_FILES);
    size_t n;
    char err[600];
    Lexer *lx = calloc(1, sizeof *lx);
    if (!lx)
        return FAIL_TOK(P, &w, "out of memory");
    lx->text = text_read_file(path, &n, err, sizeof err);
    if (!lx->text) {
        free(lx);
        return FAIL_TOK(P, &w, "%s: %s", t->s[1] == 'm' ? "Import" : "Include", err);
    }
    lx->next = P->included;
    P->included = lx;
    size_t len = strlen(path) + 1;
    char *name = malloc(len);
    if (!name)
        return FAIL_TOK(P, &w, "out of memory");
    memcpy(name, path, len);
    lx->name = name;
    lx->p = lx->line_start = lx->text;
    lx->end = lx->text + n;
    lx->line = 1;
    /* pbrt-v4 resolves every relative path, in included files too, against
     * the directory of the file it was given (its search directory). */
    snprintf(lx->dir, sizeof lx->dir, "%s", P->lx->dir);
    lx->parent = P->lx;
    P->lx = lx;
    P->depth++;
    return 0;
}

static const struct {
    const char *name;
    Handler fn;
} directives[] = {
    {"Accelerator", d_ignored},
    {"ActiveTransform", d_active},
    {"AreaLightSource", pbrt_d_arealight},
    {"Attribute", d_ignored},
    {"AttributeBegin", d_attrbegin},
    {"AttributeEnd", d_attrend},
    {"Camera", pbrt_d_camera},
    {"ColorSpace", pbrt_d_colorspace},
    {"ConcatTransform", d_concat},
    {"CoordinateSystem", d_coordsys},
    {"CoordSysTransform", d_coordsystransform},
    {"Film", pbrt_d_film},
    {"Identity", d_identity},
    {"Import", d_include},
    {"Include", d_include},
    {"Integrator", pbrt_d_integrator},
    {"LightSource", pbrt_d_light},
    {"LookAt", d_lookat},
    {"MakeNamedMaterial", pbrt_d_makenamedmaterial},
    {"MakeNamedMedium", pbrt_d_makenamedmedium},
    {"Material", pbrt_d_material},
    {"MediumInterface", pbrt_d_mediuminterface},
    {"NamedMaterial", pbrt_d_namedmaterial},
    {"ObjectBegin", d_objectbegin},
    {"ObjectEnd", d_objectend},
    {"ObjectInstance", d_objectinstance},
    {"Option", d_ignored},
    {"PixelFilter", pbrt_d_filter},
    {"ReverseOrientation", d_reverse},
    {"Rotate", d_rotate},
    {"Sampler", pbrt_d_sampler},
    {"Scale", d_scale},
    {"Shape", pbrt_d_shape},
    {"Texture", pbrt_d_texture},
    {"Transform", d_transform},
    {"TransformBegin", d_xformbegin},
    {"TransformEnd", d_xformend},
    {"TransformTimes", d_transformtimes},
    {"Translate", d_translate},
    {"WorldBegin", pbrt_d_worldbegin},
    {"WorldEnd", pbrt_d_worldend},
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
        if ((r = pbrt_next(P, &t)) != 0)
            break;
        if (t.kind == TOK_END)
            break;
        Handler fn = NULL;
        for (size_t i = 0; t.kind == TOK_WORD && i < sizeof directives / sizeof directives[0]; i++)
            if (pbrt_word_is(&t, directives[i].name))
                fn = directives[i].fn;
        if (!fn) {
            r = FAIL_TOK(P, &t, "expected a directive (Shape, Material, Translate, ...), found %s",
                         pbrt_shown(&t, b));
            break;
        }
        if ((r = fn(P, &t)) != 0)
            break;
    }
    if (r == 0 && P->depth == 1 && P->world) /* the top file's end: its lexer names it */
        r = pbrt_deferred_shapes(P);
    if (r == 0 && P->depth == 1 && P->world)
        r = pbrt_media_send(P);
    if (r == 0 && P->depth == 1 && P->world)
        r = pbrt_medium_camera(P);
    P->depth--;
    P->lx = saved; /* an error's message, written already, names the innermost file */
    P->has_peek = saved_peek;
    P->peeked = saved_tok;
    return r;
}

/* ------------------------------------------------------------ entry points */

static void parser_free(Parser *P)
{
    while (P->included) {
        Lexer *lx = P->included;
        P->included = lx->next;
        free((char *)lx->name);
        free(lx->text);
        free(lx);
    }
    for (size_t i = 0; i < P->n_objects; i++)
        pbrt_object_free(&P->objects[i]);
    free(P->objects);
    free(P->stack);
    free(P->coordsys);
    free(P->materials);
    free(P->textures);
    pbrt_media_free(P);
    pbrt_defer_free(P);
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
    pbrt_mat_identity(P->gs.ctm);
    pbrt_mat_identity(P->gs.ctm_end);
    pbrt_mat_identity(P->camera_from_world);
    pbrt_mat_identity(P->camera_from_world_end);
    P->transform_times[0] = 0, P->transform_times[1] = 1;
    P->shutter[0] = 0, P->shutter[1] = 1;
    P->iso = 100;
    P->gs.active = 3;
    P->fov = 90;
    P->film_diagonal = 35;
    if (settings) { /* pbrt-v4's integrator when the file names none: volpath, maxdepth 5 */
        settings->bounces = 4;
        settings->specular_depth = 5;
    }
    pbrt_mat_init(&P->gs.material, "diffuse"); /* pbrt's default material: diffuse 0.5 */
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    pbrt_mat_color(&P->gs.material, "reflectance", half);
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
    /* pbrt-v4's imaging ratio: the exposure time times iso / 100 (1 by
     * default: shutter 0 to 1, iso 100) scales every pixel */
    if (!r && settings) {
        settings->exposure_gain *= (P->shutter[1] - P->shutter[0]) * P->iso / 100.0f;
        settings->opaque = 1; /* pbrt's films write no alpha */
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
