/*
 * io/pbrt_params.c — the parameter lists of the pbrt reader
 * (pbrt_internal.h): the `"type name" value|[values]` pairs after a
 * directive's fixed arguments, their lookup by name, and colour values
 * (rgb, named and sampled spectra, blackbody, grey, textures) as linear
 * sRGB.
 *
 * Values are checked against their type as they are read (integers whole,
 * counts a multiple of the type's arity); the getters then check only
 * counts. Every lookup marks the parameter used, so pbrt_warn_unused can
 * name the rest; of two parameters of the same name the later wins.
 * Named spectra are RGB fits at 650, 550 and 450 nm.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "io/text.h"
#include "util/colour.h"

/* ------------------------------------------------------------ parameters */

void pbrt_params_free(ParamList *pl)
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
        if (pbrt_string_value(P, t, s, sizeof s) != 0)
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
    if (p->type == PT_BOOL && (pbrt_word_is(t, "true") || pbrt_word_is(t, "false")))
        return push_num(p, t->s[0] == 't') != 0 ? FAIL_TOK(P, t, "out of memory") : 0;
    if (pbrt_parse_number(t, &v) != 0)
        return FAIL_TOK(P, t, "expected a value for \"%s %s\", found %s", p->type_name, p->name,
                        pbrt_shown(t, b));
    if (p->type == PT_STRING || p->type == PT_TEXTURE || p->type == PT_BOOL)
        return FAIL_TOK(P, t, "expected a %s value for \"%s\", found a number", p->type_name,
                        p->name);
    if (p->n_str > 0)
        return FAIL_TOK(P, t, "expected strings only in \"%s\"", p->name);
    if (p->type == PT_INTEGER && (v != floor(v) || fabs(v) > 2147483647.0))
        return FAIL_TOK(P, t, "expected an integer for \"%s\", found %s", p->name,
                        pbrt_shown(t, b));
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

int pbrt_parse_params(Parser *P, ParamList *pl)
{
    for (;;) {
        Token t;
        char b[48];
        if (pbrt_peek(P, &t) != 0)
            return -1;
        if (t.kind != TOK_STRING)
            return 0;
        pbrt_next(P, &t);
        char decl[160], tname[32], pname[96], extra[8];
        if (pbrt_string_value(P, &t, decl, sizeof decl) != 0)
            return -1;
        int k = sscanf(decl, "%31s %95s %7s", tname, pname, extra);
        if (k != 2)
            return FAIL_TOK(P, &t, "expected a parameter declaration \"type name\", found %s",
                            pbrt_shown(&t, b));
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
        if (pbrt_next(P, &t) != 0)
            return -1;
        if (t.kind == TOK_LBRACKET) {
            for (;;) {
                if (pbrt_next(P, &t) != 0)
                    return -1;
                if (t.kind == TOK_RBRACKET)
                    break;
                if (t.kind == TOK_END || t.kind == TOK_LBRACKET)
                    return FAIL_TOK(P, &t, "expected a value or \"]\" in \"%s\", found %s",
                                    p->name, pbrt_shown(&t, b));
                if (param_value(P, p, &t) != 0)
                    return -1;
            }
        } else if (param_value(P, p, &t) != 0) {
            return -1;
        }
        size_t n = p->n_num + p->n_str;
        if (n == 0)
            return pbrt_fail_at(P, p->line, p->col, "expected at least one value for \"%s\"",
                                p->name);
        if (p->n_num % arity(p->type) != 0)
            return pbrt_fail_at(P, p->line, p->col,
                                "expected a multiple of %zu values for \"%s %s\", found %zu",
                                arity(p->type), p->type_name, p->name, p->n_num);
    }
}

Param *pbrt_find(ParamList *pl, const char *name)
{
    for (size_t i = pl->n; i-- > 0;)
        if (strcmp(pl->p[i].name, name) == 0) {
            pl->p[i].used = 1;
            return &pl->p[i];
        }
    return NULL;
}

double pbrt_get_float(ParamList *pl, const char *name, double def)
{
    Param *p = pbrt_find(pl, name);
    return p && p->n_num > 0 && p->type != PT_STRING ? p->num[0] : def;
}

const char *pbrt_get_string(ParamList *pl, const char *name, const char *def)
{
    Param *p = pbrt_find(pl, name);
    return p && p->n_str > 0 ? p->str[0] : def;
}

const double *pbrt_get_point(ParamList *pl, const char *name)
{
    Param *p = pbrt_find(pl, name);
    return p && p->n_num >= 3 ? p->num : NULL;
}

void pbrt_warn_unused(Parser *P, ParamList *pl, const char *directive, const char *kind)
{
    for (size_t i = 0; i < pl->n; i++)
        if (!pl->p[i].used) {
            char key[96];
            snprintf(key, sizeof key, "param %.20s %.20s %.40s", directive, kind, pl->p[i].name);
            pbrt_warn_at(P, pl->p[i].line, pl->p[i].col, key,
                         "%s \"%s\": parameter \"%s %s\" is not supported; ignored", directive,
                         kind, pl->p[i].type_name, pl->p[i].name);
        }
}

/* ------------------------------------------------------------ colours */

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

#define PBRT_MAX_SPD_PAIRS 65536

/* A spectrum file (pbrt's .spd: wavelength, value pairs; '#' starts a
 * comment) as RGB at 650, 550, 450 nm; 0, or -1 with the error set. */
static int spd_rgb(Parser *P, const Param *p, const char *file, float out[3])
{
    Token at = {.line = p->line, .col = p->col};
    char path[PBRT_PATH], err[600];
    if (pbrt_resolve(P, &at, file, path, sizeof path) != 0)
        return -1;
    size_t size;
    char *text = text_read_file(path, &size, err, sizeof err);
    if (!text)
        return pbrt_fail_at(P, p->line, p->col, "spectrum: %s", err);
    double *v = malloc(2 * PBRT_MAX_SPD_PAIRS * sizeof *v);
    size_t n = 0;
    int bad = !v;
    for (char *s = text; !bad && *s;) {
        if (*s == '#') {
            while (*s && *s != '\n')
                s++;
            continue;
        }
        if (strchr(" \t\r\n,", *s)) {
            s++;
            continue;
        }
        char *end;
        double x = strtod(s, &end);
        if (end == s || !isfinite(x) || n >= 2 * PBRT_MAX_SPD_PAIRS)
            bad = 1;
        else
            v[n++] = x, s = end;
    }
    if (!bad && (n < 2 || n % 2 != 0))
        bad = 1;
    for (size_t i = 2; !bad && i < n; i += 2)
        bad = !(v[i] > v[i - 2]); /* wavelengths increase */
    if (!bad)
        sampled_rgb(v, n / 2, out);
    free(v);
    free(text);
    if (bad)
        return pbrt_fail_at(P, p->line, p->col,
                            "%s: expected (wavelength, value) pairs with increasing wavelengths "
                            "(at most %d)", path, PBRT_MAX_SPD_PAIRS);
    return 0;
}

const Texture *pbrt_find_texture(const Parser *P, const char *name)
{
    for (size_t i = P->n_textures; i-- > 0;)
        if (strcmp(P->textures[i].name, name) == 0)
            return &P->textures[i];
    return NULL;
}

/* A colour parameter: rgb, spectrum (named, sampled or constant), blackbody,
 * float (grey) or texture. Returns 0 (not given: out = def), 1 (a colour
 * in out; a constant texture's, or any texture's stand-in when tex is
 * NULL), 2 (a pattern texture in *tex, out = its stand-in) or -1 (error). */
int pbrt_get_color(Parser *P, ParamList *pl, const char *name, const float def[3], float out[3],
                   const Texture **tex)
{
    memcpy(out, def, 3 * sizeof(float));
    Param *p = pbrt_find(pl, name);
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
        colour_blackbody(p->num[0], out);
        return 1;
    case PT_SPECTRUM:
        if (p->n_str > 0) {
            for (size_t i = 0; i < sizeof named_spectra / sizeof named_spectra[0]; i++)
                if (strcmp(named_spectra[i].name, p->str[0]) == 0) {
                    memcpy(out, named_spectra[i].rgb, sizeof named_spectra[i].rgb);
                    return 1;
                }
            const char *dot = strrchr(p->str[0], '.');
            if (dot && strcmp(dot, ".spd") == 0)
                return spd_rgb(P, p, p->str[0], out) == 0 ? 1 : -1;
            char key[96];
            snprintf(key, sizeof key, "spectrum %.60s", p->str[0]);
            pbrt_warn_at(P, p->line, p->col, key,
                         "spectrum \"%s\" (an unknown named spectrum) is not supported; using "
                         "the default of \"%s\"", p->str[0], name);
            return 0;
        }
        if (p->n_num == 1) {
            out[0] = out[1] = out[2] = (float)p->num[0];
            return 1;
        }
        if (p->n_num % 2 != 0)
            return pbrt_fail_at(P, p->line, p->col, "expected (wavelength, value) pairs for "
                                "\"spectrum %s\", found %zu numbers", name, p->n_num);
        sampled_rgb(p->num, p->n_num / 2, out);
        return 1;
    case PT_TEXTURE: {
        const Texture *t = p->n_str > 0 ? pbrt_find_texture(P, p->str[0]) : NULL;
        if (!t)
            P->missing_texture = 1; /* perhaps defined further down (pbrt_defer.c) */
        if (!t)
            return pbrt_fail_at(P, p->line, p->col,
                                "expected the name of a texture defined before, found \"%.60s\"",
                                p->n_str > 0 ? p->str[0] : "");
        memcpy(out, t->rgb, sizeof t->rgb);
        if (t->pattern[0] && tex) {
            *tex = t;
            return 2;
        }
        return 1;
    }
    default:
        return pbrt_fail_at(P, p->line, p->col,
                            "expected a colour (rgb, spectrum, blackbody, float or texture) for "
                            "\"%s\", found type %s",
                            name, p->type_name);
    }
}

int pbrt_get_emission(Parser *P, ParamList *pl, const char *name, float out[3])
{
    static const float white[3] = {1, 1, 1};
    Param *p = pbrt_find(pl, name);
    int k = pbrt_get_color(P, pl, name, white, out, NULL);
    if (k == 1 && (p->type == PT_BLACKBODY || p->type == PT_SPECTRUM)) {
        /* pbrt-v4 divides a light's spectrum by its luminance (lights.cpp,
         * SpectrumToPhotometric): rgb is kept, a spectrum is 1 nit */
        float Y = 0.2126f * out[0] + 0.7152f * out[1] + 0.0722f * out[2];
        for (int c = 0; c < 3 && Y > 0.0f; c++)
            out[c] /= Y;
    }
    return k;
}

/* A float parameter that may be a texture (its stand-in's mean grey then). */
int pbrt_get_float_tex(Parser *P, ParamList *pl, const char *name, double def, double *out)
{
    Param *p = pbrt_find(pl, name);
    *out = def;
    if (!p)
        return 0;
    if (p->type == PT_FLOAT || p->type == PT_INTEGER) {
        *out = p->num[0];
        return 0;
    }
    float c[3], d[3] = {(float)def, (float)def, (float)def};
    p->used = 0;
    if (pbrt_get_color(P, pl, name, d, c, NULL) < 0)
        return -1;
    *out = (c[0] + c[1] + c[2]) / 3.0;
    return 0;
}

/* Reads the "name" argument and the parameter list of a directive. */
int pbrt_name_and_params(Parser *P, char *name, size_t size, const char *what, ParamList *pl,
                         Token *where)
{
    if (pbrt_expect_string(P, name, size, what, where) != 0)
        return -1;
    return pbrt_parse_params(P, pl);
}
