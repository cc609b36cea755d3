/*
 * io/pbrt_material.c — pbrt materials and textures (pbrt_internal.h):
 * Material, MakeNamedMaterial, NamedMaterial and Texture. Each pbrt
 * material becomes one call of a built-in shader (diffuse, coateddiffuse,
 * conductor, dielectric; matte for what has no counterpart) with at most
 * MAT_MAX_PARAMS parameters, and its "displacement" the built-in
 * displacement shader "displace"; what is approximated or dropped is
 * warned about once. Each Texture becomes a pattern of the sink
 * (rayes_scene_pattern: pbrt-v4's texture classes, evaluated per shading
 * point), named "N:name" with N its index, so a redefined name is a new
 * pattern; a parameter pbrt lets be textured takes the pattern
 * (RAYES_PARAM_PATTERN), every other parameter a constant. Named materials
 * and textures are found latest first, so a redefinition wins.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"
#include "util/media.h"

#define TEX_MAX_PARAMS 16

/* ------------------------------------------------------------ textures */

/* Appends tex to the parser's textures; its index, or -1 (no memory). */
static long add_texture(Parser *P, const Token *t, const Texture *tex)
{
    if ((P->n_textures & (P->n_textures - 1)) == 0) {
        Texture *n = realloc(P->textures, (P->n_textures ? 2 * P->n_textures : 1) * sizeof *n);
        if (!n)
            return FAIL_TOK(P, t, "out of memory");
        P->textures = n;
    }
    P->textures[P->n_textures] = *tex;
    return (long)P->n_textures++;
}

/* A texture of pattern class cls: sent to the sink as "N:name" under the
 * current transform (the 3-D classes' texture space), or, for a sink that
 * takes no patterns, the constant standin with one warning. Returns its
 * index, or -1. */
static long define_pattern(Parser *P, const Token *t, const char *name, int is_float,
                           const char *cls, const RayesParam *params, size_t n,
                           const float standin[3])
{
    Texture tex;
    memset(&tex, 0, sizeof tex);
    snprintf(tex.name, sizeof tex.name, "%s", name);
    memcpy(tex.rgb, standin, sizeof tex.rgb);
    tex.is_float = is_float;
    if (!P->sink->pattern) {
        pbrt_warn_at(P, t->line, t->col, "no patterns",
                     "this output takes no textures; textured parameters become constants (the "
                     "texture's mean)");
        return add_texture(P, t, &tex);
    }
    snprintf(tex.pattern, sizeof tex.pattern, "%zu:%.120s", P->n_textures,
             name[0] == ' ' ? name + 1 : name);
    if (pbrt_emit_pattern(P, t, tex.pattern, cls, params, n) != 0)
        return -1;
    return add_texture(P, t, &tex);
}

/* One input of a texture (tex1, amount, ...): a pattern or a constant into
 * *out (named name), its stand-in into standin. Returns 0, or -1. */
static int tex_input(Parser *P, ParamList *pl, const char *name, const float def[3],
                     RayesParam *out, float standin[3])
{
    const Texture *tex = NULL;
    int k = pbrt_get_color(P, pl, name, def, standin, &tex);
    if (k < 0)
        return -1;
    *out = (RayesParam){.name = name, .type = RAYES_PARAM_COLOR};
    memcpy(out->value, standin, sizeof out->value);
    if (k == 2)
        *out = (RayesParam){.name = name, .type = RAYES_PARAM_PATTERN, .string = tex->pattern};
    return 0;
}

/* A number parameter passed on when given (an integer or a float). */
static void tex_number(ParamList *pl, const char *name, RayesParam *out, size_t *n)
{
    Param *p = pbrt_find(pl, name);
    if (p && (p->type == PT_FLOAT || p->type == PT_INTEGER) && p->n_num > 0)
        out[(*n)++] = (RayesParam){
            .name = name, .type = RAYES_PARAM_FLOAT, .value = {(float)p->num[0], 0, 0}};
    else if (p)
        p->used = 0; /* the wrong type: warned about as unused */
}

/* pbrt's (u, v) mapping and its parameters: "uv" (uscale ... vdelta),
 * "spherical", "cylindrical" (in the texture's space) or "planar" (v1,
 * v2, udelta, vdelta); another name warns and maps by "uv". */
static void tex_mapping(Parser *P, const Token *t, ParamList *pl, RayesParam *out, size_t *n)
{
    static const char *const names[] = {"uscale", "vscale", "udelta", "vdelta"};
    for (int k = 0; k < 4; k++)
        tex_number(pl, names[k], out, n);
    const char *mapping = pbrt_get_string(pl, "mapping", "uv");
    if (strcmp(mapping, "spherical") == 0 || strcmp(mapping, "cylindrical") == 0 ||
        strcmp(mapping, "planar") == 0) {
        out[(*n)++] =
            (RayesParam){.name = "mapping", .type = RAYES_PARAM_STRING, .string = mapping};
        static const char *const axes[2] = {"v1", "v2"};
        for (int k = 0; k < 2 && strcmp(mapping, "planar") == 0; k++) {
            const double *v = pbrt_get_point(pl, axes[k]);
            if (v)
                out[(*n)++] = (RayesParam){.name = axes[k],
                                           .type = RAYES_PARAM_COLOR,
                                           .value = {(float)v[0], (float)v[1], (float)v[2]}};
        }
    } else if (strcmp(mapping, "uv") != 0) {
        pbrt_warn_at(P, t->line, t->col, "texture mapping",
                     "Texture: mapping \"%.40s\" is not supported; using \"uv\"", mapping);
    }
}

static void mean2(const float a[3], const float b[3], float out[3])
{
    for (int c = 0; c < 3; c++)
        out[c] = 0.5f * (a[c] + b[c]);
}

/* The parameters of an imagemap: the file (resolved), its scale, invert,
 * encoding and mapping; a float texture reads the first channel, as pbrt
 * does. */
static int imagemap_params(Parser *P, const Token *t, ParamList *pl, int is_float, char *path,
                           RayesParam *q, size_t *n, float standin[3])
{
    const char *file = pbrt_get_string(pl, "filename", NULL);
    if (!file)
        return FAIL_TOK(P, t, "imagemap: expected \"string filename\"");
    if (pbrt_resolve(P, t, file, path, PBRT_PATH) != 0)
        return -1;
    q[(*n)++] = (RayesParam){.name = "filename", .type = RAYES_PARAM_STRING, .string = path};
    tex_number(pl, "scale", q, n);
    Param *inv = pbrt_find(pl, "invert");
    if (inv && inv->type == PT_BOOL && inv->n_num > 0)
        q[(*n)++] = (RayesParam){
            .name = "invert", .type = RAYES_PARAM_FLOAT, .value = {(float)inv->num[0], 0, 0}};
    const char *enc = pbrt_get_string(pl, "encoding", NULL);
    float g;
    char tail;
    const Param *ep = pbrt_find(pl, "encoding");
    if (enc && strcmp(enc, "sRGB") != 0 && strcmp(enc, "linear") != 0 &&
        !(sscanf(enc, "gamma %f%c", &g, &tail) == 1 && g > 0.0f && g < 100.0f))
        return pbrt_fail_at(
            P, ep->line, ep->col,
            "imagemap: expected encoding \"sRGB\", \"linear\" or \"gamma G\", found \"%.40s\"",
            enc);
    Param *gamma = enc ? NULL : pbrt_find(pl, "gamma"); /* pbrt-v3's: sRGB or linear */
    if (gamma && gamma->type == PT_BOOL && gamma->n_num > 0)
        enc = gamma->num[0] != 0 ? "sRGB" : "linear";
    if (enc)
        q[(*n)++] = (RayesParam){.name = "encoding", .type = RAYES_PARAM_STRING, .string = enc};
    if (is_float)
        q[(*n)++] = (RayesParam){.name = "channel", .type = RAYES_PARAM_FLOAT};
    const char *wrap = pbrt_get_string(pl, "wrap", "repeat");
    if (strcmp(wrap, "black") == 0 || strcmp(wrap, "clamp") == 0)
        q[(*n)++] = (RayesParam){.name = "wrap", .type = RAYES_PARAM_STRING, .string = wrap};
    else if (strcmp(wrap, "repeat") != 0) /* octahedralsphere: an environment map's */
        pbrt_warn_at(P, t->line, t->col, "imagemap wrap",
                     "imagemap: wrap \"%.40s\" is not supported; the image repeats", wrap);
    (void)pbrt_find(pl, "filter"); /* rayes always filters (OpenImageIO's anisotropic MIP) */
    (void)pbrt_find(pl, "maxanisotropy");
    (void)pbrt_find(pl, "trilinear"); /* pbrt-v3's filter choice */
    float sc = (float)pbrt_get_float(pl, "scale", 1.0);
    standin[0] = standin[1] = standin[2] = sc;
    tex_mapping(P, t, pl, q, n);
    return 0;
}

/* The pattern parameters of a pbrt texture class, and its stand-in. Returns
 * 1 for a class rayes has, 0 for one it has not, or -1. */
static int texture_params(Parser *P, const Token *t, const char *cls, ParamList *pl, int is_float,
                          char *path, RayesParam *q, size_t *n, float standin[3])
{
    static const float one[3] = {1, 1, 1}, zero[3] = {0, 0, 0}, half[3] = {.5f, .5f, .5f};
    float a[3], b[3], c[3], d[3];
    if (strcmp(cls, "constant") == 0)
        return tex_input(P, pl, "value", one, &q[(*n)++], standin) ? -1 : 1;
    if (strcmp(cls, "scale") == 0) { /* pbrt-v3's names its factors tex1 and tex2 */
        int v3 = !pbrt_find(pl, "tex") && !pbrt_find(pl, "scale");
        if (tex_input(P, pl, v3 ? "tex1" : "tex", one, &q[0], a) ||
            tex_input(P, pl, v3 ? "tex2" : "scale", one, &q[1], b))
            return -1;
        q[0].name = "tex", q[1].name = "scale";
        *n = 2;
        for (int k = 0; k < 3; k++)
            standin[k] = a[k] * b[k];
        return 1;
    }
    if (strcmp(cls, "mix") == 0 || strcmp(cls, "directionmix") == 0) {
        if (tex_input(P, pl, "tex1", zero, &q[0], a) || tex_input(P, pl, "tex2", one, &q[1], b))
            return -1;
        *n = 2;
        float w = 0.5f;
        if (cls[0] == 'm') {
            if (tex_input(P, pl, "amount", half, &q[(*n)++], c))
                return -1;
            w = c[0];
        } else if (pbrt_get_point(pl, "dir")) {
            const double *dir = pbrt_get_point(pl, "dir");
            q[(*n)++] = (RayesParam){.name = "dir",
                                     .type = RAYES_PARAM_COLOR,
                                     .value = {(float)dir[0], (float)dir[1], (float)dir[2]}};
        }
        for (int k = 0; k < 3; k++)
            standin[k] = (1 - w) * a[k] + w * b[k];
        return 1;
    }
    if (strcmp(cls, "checkerboard") == 0 || strcmp(cls, "dots") == 0) {
        int dots = cls[0] == 'd';
        if (tex_input(P, pl, dots ? "inside" : "tex1", one, &q[0], a) ||
            tex_input(P, pl, dots ? "outside" : "tex2", zero, &q[1], b))
            return -1;
        *n = 2;
        Param *dim = dots ? NULL : pbrt_find(pl, "dimension");
        if (dim && dim->n_num > 0 && dim->num[0] != 2 && dim->num[0] != 3)
            return pbrt_fail_at(P, dim->line, dim->col,
                                "checkerboard: expected dimension 2 or 3, found %g", dim->num[0]);
        if (!dots)
            tex_number(pl, "dimension", q, n);
        tex_mapping(P, t, pl, q, n);
        mean2(a, b, standin);
        return 1;
    }
    if (strcmp(cls, "imagemap") == 0)
        return imagemap_params(P, t, pl, is_float, path, q, n, standin) ? -1 : 1;
    if (strcmp(cls, "bilerp") == 0) {
        static const char *const v[4] = {"v00", "v01", "v10", "v11"};
        float *vals[4] = {a, b, c, d};
        for (int k = 0; k < 4; k++)
            if (tex_input(P, pl, v[k], k & 1 ? one : zero, &q[k], vals[k]))
                return -1;
        *n = 4;
        tex_mapping(P, t, pl, q, n);
        for (int k = 0; k < 3; k++)
            standin[k] = 0.25f * (a[k] + b[k] + c[k] + d[k]);
        return 1;
    }
    if (strcmp(cls, "fbm") == 0 || strcmp(cls, "wrinkled") == 0 || strcmp(cls, "windy") == 0 ||
        strcmp(cls, "marble") == 0) {
        static const char *const nums[] = {"octaves", "roughness", "scale", "variation"};
        int k_max = cls[0] == 'w' && cls[1] == 'i' ? 0 : cls[0] == 'm' ? 4 : 2;
        for (int k = 0; k < k_max; k++)
            tex_number(pl, nums[k], q, n);
        memcpy(standin, half, sizeof half);
        return 1;
    }
    return 0;
}

int pbrt_d_texture(Parser *P, const Token *t)
{
    char name[128], kind[32], cls[64];
    ParamList pl = {0};
    int r = pbrt_need_world(P, t, 1);
    if (!r)
        r = pbrt_expect_string(P, name, sizeof name, "a texture name", NULL);
    if (!r)
        r = pbrt_expect_string(P, kind, sizeof kind, "a texture type (\"spectrum\" or \"float\")",
                               NULL);
    if (!r && strcmp(kind, "float") != 0 && strcmp(kind, "spectrum") != 0 &&
        strcmp(kind, "color") != 0)
        r = FAIL_TOK(
            P, t, "Texture \"%.60s\": expected the type \"spectrum\" or \"float\", found \"%.40s\"",
            name, kind);
    if (!r)
        r = pbrt_name_and_params(P, cls, sizeof cls, "a texture class", &pl, NULL);
    if (r) {
        pbrt_params_free(&pl);
        return -1;
    }
    int is_float = strcmp(kind, "float") == 0;
    RayesParam q[TEX_MAX_PARAMS];
    char *path = malloc(PBRT_PATH);
    size_t n = 0;
    float standin[3] = {.5f, .5f, .5f};
    int k = path ? texture_params(P, t, cls, &pl, is_float, path, q, &n, standin)
                 : FAIL_TOK(P, t, "out of memory");
    if (k == 0) {
        char key[96];
        snprintf(key, sizeof key, "texture %.60s", cls);
        pbrt_warn_at(P, t->line, t->col, key,
                     "Texture \"%.40s\" is not supported; using a constant 0.5", cls);
        for (size_t i = 0; i < pl.n; i++)
            pl.p[i].used = 1;
        Texture tex;
        memset(&tex, 0, sizeof tex);
        snprintf(tex.name, sizeof tex.name, "%s", name);
        memcpy(tex.rgb, standin, sizeof tex.rgb);
        tex.is_float = is_float;
        k = add_texture(P, t, &tex) < 0 ? -1 : 1;
    } else if (k > 0 && strcmp(cls, "constant") == 0 && q[0].type != RAYES_PARAM_PATTERN) {
        Texture tex; /* a constant needs no pattern */
        memset(&tex, 0, sizeof tex);
        snprintf(tex.name, sizeof tex.name, "%s", name);
        memcpy(tex.rgb, standin, sizeof tex.rgb);
        tex.is_float = is_float;
        k = add_texture(P, t, &tex) < 0 ? -1 : 1;
    } else if (k > 0) {
        k = define_pattern(P, t, name, is_float, cls, q, n, standin) < 0 ? -1 : 1;
    }
    free(path);
    if (k > 0)
        pbrt_warn_unused(P, &pl, "Texture", cls);
    pbrt_params_free(&pl);
    return k > 0 ? 0 : -1;
}

/* ------------------------------------------------------------ materials */

void pbrt_mat_init(Material *m, const char *shader)
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

void pbrt_mat_color(Material *m, const char *name, const float c[3])
{
    if (m->n >= MAT_MAX_PARAMS)
        return;
    snprintf(m->p[m->n].name, sizeof m->p[m->n].name, "%s", name);
    m->p[m->n].type = RAYES_PARAM_COLOR;
    memcpy(m->p[m->n].v, c, 3 * sizeof(float));
    m->n++;
}

/* The parameter name bound to texture index tex's pattern. */
static void mat_pattern(Material *m, const char *name, size_t tex)
{
    if (m->n >= MAT_MAX_PARAMS)
        return;
    snprintf(m->p[m->n].name, sizeof m->p[m->n].name, "%s", name);
    m->p[m->n].type = RAYES_PARAM_PATTERN;
    m->p[m->n].tex = tex;
    m->n++;
}

/* A parameter pbrt lets be textured: pbrt's pname (default def) as rayes'
 * name, a constant of that type or the texture's pattern. Returns 0, or
 * -1. */
static int mat_textured(Parser *P, ParamList *pl, Material *m, const char *pname, const char *name,
                        RayesParamType type, const float def[3])
{
    float c[3];
    const Texture *tex = NULL;
    int k = pbrt_get_color(P, pl, pname, def, c, &tex);
    if (k < 0)
        return -1;
    if (k == 2)
        mat_pattern(m, name, (size_t)(tex - P->textures));
    else if (type == RAYES_PARAM_FLOAT)
        mat_float(m, name, (c[0] + c[1] + c[2]) / 3.0f);
    else
        pbrt_mat_color(m, name, c);
    return 0;
}

/* The colour of a material's parameter, if it has one of that name. */
static const float *mat_get(const Material *m, const char *name)
{
    for (int i = 0; i < m->n; i++)
        if (strcmp(m->p[i].name, name) == 0)
            return m->p[i].v;
    return NULL;
}

/* pbrt's names of a lobe's roughness: roughness, uroughness, vroughness,
 * after a prefix (coatedconductor's "conductor."). */
typedef struct RoughNames {
    char r[32], u[32], v[32];
} RoughNames;

static RoughNames rough_names(const char *prefix)
{
    RoughNames n;
    snprintf(n.r, sizeof n.r, "%sroughness", prefix);
    snprintf(n.u, sizeof n.u, "%suroughness", prefix);
    snprintf(n.v, sizeof n.v, "%svroughness", prefix);
    return n;
}

/* rayes' roughness r is pbrt's with remapping on (alpha = sqrt(r)). pbrt's
 * "remaproughness" false gives alpha itself, so r = alpha^2. Anisotropic
 * roughness (uroughness, vroughness) becomes the isotropic lobe of the
 * two alphas' geometric mean, which keeps the lobe's solid angle; when
 * they differ that is said once, at the material's directive t.
 * Constants only (constant textures read as their value). */
static int get_roughness(Parser *P, const Token *t, ParamList *pl, const RoughNames *n, double def,
                         double *out)
{
    double r, ru, rv;
    if (pbrt_get_float_tex(P, pl, n->r, def, &r) != 0 ||
        pbrt_get_float_tex(P, pl, n->u, r, &ru) != 0 ||
        pbrt_get_float_tex(P, pl, n->v, r, &rv) != 0)
        return -1;
    Param *remap = pbrt_find(pl, "remaproughness");
    int alpha_given = remap && remap->n_num && remap->num[0] == 0.0;
    double au = alpha_given ? ru : sqrt(fmax(ru, 0.0)), av = alpha_given ? rv : sqrt(fmax(rv, 0.0));
    double alpha = sqrt(fmax(au, 0.0) * fmax(av, 0.0));
    if (ru != rv)
        pbrt_warn_at(P, t->line, t->col, "anisotropic roughness",
                     "%s %g and %s %g differ: rayes' glossy lobes are isotropic, so the lobe "
                     "has their alphas' geometric mean (alpha %g); highlights are not stretched",
                     n->u, ru, n->v, rv, alpha);
    *out = alpha * alpha;
    return 0;
}

/* One roughness as a pattern parameter: texture index tex, or constant v
 * when tex is (size_t)-1. */
static RayesParam rough_param(const Parser *P, const char *name, size_t tex, float v)
{
    if (tex != (size_t)-1)
        return (RayesParam){
            .name = name, .type = RAYES_PARAM_PATTERN, .string = P->textures[tex].pattern};
    return (RayesParam){.name = name, .type = RAYES_PARAM_FLOAT, .value = {v, 0, 0}};
}

/* The roughness of a material with a textured roughness, uroughness or
 * vroughness: the same texture in u and v is rayes' roughness as it is
 * (remapped) or squared (alpha given: "scale" of it by itself); two
 * different ones are multiplied (alpha given: the alphas' geometric mean
 * squared) or averaged (remapped: rayes' patterns take no square root, so
 * the arithmetic mean stands in for the geometric, with a warning). */
static int textured_roughness(Parser *P, const Token *t, ParamList *pl, const RoughNames *n,
                              Material *m)
{
    static const float zero[3] = {0, 0, 0};
    const char *names[2] = {pbrt_find(pl, n->u) ? n->u : n->r, pbrt_find(pl, n->v) ? n->v : n->r};
    size_t tex[2];
    float c[2][3];
    for (int k = 0; k < 2; k++) {
        const Texture *tx = NULL;
        int got = pbrt_get_color(P, pl, names[k], zero, c[k], &tx);
        if (got < 0)
            return -1;
        tex[k] = got == 2 ? (size_t)(tx - P->textures) : (size_t)-1;
    }
    Param *remap = pbrt_find(pl, "remaproughness");
    int alpha_given = remap && remap->n_num && remap->num[0] == 0.0;
    int same = tex[0] == tex[1] && (tex[0] != (size_t)-1 || c[0][0] == c[1][0]);
    if (same && !alpha_given) {
        mat_pattern(m, "roughness", tex[0]);
        return 0;
    }
    if (!same && !alpha_given)
        pbrt_warn_at(
            P, t->line, t->col, "anisotropic roughness texture",
            "textured uroughness and vroughness become one isotropic roughness, their mean");
    RayesParam q[3] = {rough_param(P, alpha_given ? "tex" : "tex1", tex[0], c[0][0]),
                       rough_param(P, alpha_given ? "scale" : "tex2", tex[1], c[1][0]),
                       {.name = "amount", .type = RAYES_PARAM_FLOAT, .value = {0.5f, 0, 0}}};
    float standin[3];
    for (int k = 0; k < 3; k++)
        standin[k] = alpha_given ? c[0][0] * c[1][0] : 0.5f * (c[0][0] + c[1][0]);
    long i = define_pattern(P, t, " roughness", 1, alpha_given ? "scale" : "mix", q,
                            alpha_given ? 2 : 3, standin);
    if (i < 0)
        return -1;
    mat_pattern(m, "roughness", (size_t)i);
    return 0;
}

/* rayes' "roughness" of a material: a constant, or a pattern when pbrt's
 * roughness, uroughness or vroughness (after prefix) is a texture that
 * varies. */
static int mat_roughness(Parser *P, const Token *t, ParamList *pl, Material *m, double def,
                         const char *prefix)
{
    RoughNames n = rough_names(prefix);
    const char *names[3] = {n.r, n.u, n.v};
    for (int k = 0; k < 3; k++) {
        Param *p = pbrt_find(pl, names[k]);
        const Texture *tx =
            p && p->type == PT_TEXTURE && p->n_str > 0 ? pbrt_find_texture(P, p->str[0]) : NULL;
        if (tx && tx->pattern[0])
            return textured_roughness(P, t, pl, &n, m);
    }
    double r;
    if (get_roughness(P, t, pl, &n, def, &r) != 0)
        return -1;
    mat_float(m, "roughness", (float)r);
    return 0;
}

/* pbrt's "displacement" (a float or a float texture): the displacement
 * shader of the material's shapes. */
static int mat_displacement(Parser *P, ParamList *pl, Material *m)
{
    static const float zero[3] = {0, 0, 0};
    float c[3];
    const Texture *tex = NULL;
    /* pbrt-v3 called it "bumpmap" */
    const char *name =
        pbrt_find(pl, "displacement") || !pbrt_find(pl, "bumpmap") ? "displacement" : "bumpmap";
    int k = pbrt_get_color(P, pl, name, zero, c, &tex);
    if (k < 0)
        return -1;
    if (k == 2) {
        m->displaced = 2;
        m->displacement_tex = (size_t)(tex - P->textures);
    } else if (k == 1 && c[0] != 0.0f) {
        m->displaced = 1;
        m->displacement_v = c[0];
    }
    return 0;
}

int pbrt_shape_displacement(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    Param *d = pbrt_find(pl, "displacement");
    if (!d)
        return 0;
    static const float zero[3] = {0, 0, 0};
    float c[3];
    const Texture *tex = NULL;
    int k = pbrt_get_color(P, pl, "displacement", zero, c, &tex);
    if (k < 0)
        return -1;
    /* object-space lengths: the transform's uniform scale, cube root of
     * its linear part's determinant */
    float scale = (float)cbrt(fabs(pbrt_mat_det3(P->gs.ctm)));
    if (!(isfinite(scale) && scale > 0.0f))
        scale = 1.0f;
    if (k != 2 && c[0] == 0.0f)
        return 0; /* nothing moves: the material's own bump, if any, stays */
    if (m->displaced)
        pbrt_warn_at(P, d->line, d->col, "ply displacement and bump",
                     "plymesh: its displacement replaces its material's \"displacement\" (a "
                     "bump map) on this shape");
    if (k != 2) { /* a texture that is a constant (or a float given) */
        m->displaced = 4;
        m->displacement_v = c[0] * scale;
        return 0;
    }
    size_t i = (size_t)(tex - P->textures);
    if (fabsf(scale - 1.0f) > 1e-6f) {
        RayesParam q[2] = {
            {.name = "tex", .type = RAYES_PARAM_PATTERN, .string = P->textures[i].pattern},
            {.name = "scale", .type = RAYES_PARAM_FLOAT, .value = {scale, 0, 0}}};
        float standin[3] = {c[0] * scale, c[1] * scale, c[2] * scale};
        long s = define_pattern(P, t, " displacement", 1, "scale", q, 2, standin);
        if (s < 0)
            return -1;
        i = (size_t)s;
    }
    m->displaced = 3;
    m->displacement_tex = i;
    return 0;
}

static int diffuse_material(Parser *P, ParamList *pl, Material *m, const char *param)
{
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    pbrt_mat_init(m, "diffuse");
    return mat_textured(P, pl, m, param, "reflectance", RAYES_PARAM_COLOR, half);
}

/* The reflectance of a diffuse material as a pattern input named name. */
static RayesParam reflectance_input(const Parser *P, const Material *m, const char *name)
{
    for (int i = 0; i < m->n; i++)
        if (strcmp(m->p[i].name, "reflectance") == 0 && m->p[i].type == RAYES_PARAM_PATTERN)
            return (RayesParam){.name = name,
                                .type = RAYES_PARAM_PATTERN,
                                .string = P->textures[m->p[i].tex].pattern};
    const float *c = mat_get(m, "reflectance");
    return (RayesParam){.name = name, .type = RAYES_PARAM_COLOR, .value = {c[0], c[1], c[2]}};
}

/* A "mix" shader of materials a and b by amount (q: its pattern, or
 * the constant c): their classes as "a" and "b", each parameter as
 * "a:NAME" or "b:NAME" (a mix's own too, so mixes nest). Returns 0, or -1
 * when that cannot be said (the parameters or their names do not fit), m
 * untouched. */
static int mix_of(Parser *P, const Material *a, const Material *b, const RayesParam *q, float c,
                  Material *m)
{
    const Material *ab[2] = {a, b};
    /* one slot left for a shape's alpha or normal map; an interface (no
     * surface) cannot be a mix's */
    if (a->n + b->n + 4 > MAT_MAX_PARAMS || strcmp(a->shader, PBRT_INVISIBLE) == 0 ||
        strcmp(b->shader, PBRT_INVISIBLE) == 0)
        return -1;
    Material out;
    pbrt_mat_init(&out, "mix");
    for (int k = 0; k < 2; k++) {
        snprintf(out.p[out.n].name, sizeof out.p[out.n].name, "%c", 'a' + k);
        out.p[out.n].type = RAYES_PARAM_STRING;
        snprintf(out.p[out.n].s, sizeof out.p[out.n].s, "%s", ab[k]->shader);
        out.n++;
        for (int i = 0; i < ab[k]->n; i++) {
            out.p[out.n] = ab[k]->p[i];
            if ((size_t)snprintf(out.p[out.n].name, sizeof out.p[out.n].name, "%c:%s", 'a' + k,
                                 ab[k]->p[i].name) >= sizeof out.p[out.n].name)
                return -1; /* nested too deep for the name */
            out.n++;
        }
    }
    /* pbrt's displacement belongs to a material, not to their mix: the
     * first one's (a mix cannot displace two ways) */
    for (int k = 1; k >= 0; k--)
        if (ab[k]->displaced) {
            out.displaced = ab[k]->displaced;
            out.displacement_v = ab[k]->displacement_v;
            out.displacement_tex = ab[k]->displacement_tex;
        }
    if (q->type == RAYES_PARAM_PATTERN) {
        size_t i = 0;
        while (i < P->n_textures && P->textures[i].pattern != q->string)
            i++;
        if (i == P->n_textures)
            return -1;
        mat_pattern(&out, "amount", i);
    } else {
        mat_float(&out, "amount", c);
    }
    *m = out;
    return 0;
}

/* pbrt's mix of two materials: two diffuse ones are one diffuse material
 * whose reflectance is their mix (a "mix" pattern when either reflectance
 * or the amount is a texture); others a "mix" shader of the two (mix_of),
 * or where that cannot be said the heavier one. */
static int mix_material(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    Param *names = pbrt_find(pl, "materials");
    /* pbrt-v3's: namedmaterial1 and namedmaterial2 */
    const char *n1 = pbrt_get_string(pl, "namedmaterial1", NULL);
    const char *n2 = pbrt_get_string(pl, "namedmaterial2", NULL);
    const char *mats[2] = {names && names->n_str == 2 ? names->str[0] : n1,
                           names && names->n_str == 2 ? names->str[1] : n2};
    if (!mats[0] || !mats[1])
        return FAIL_TOK(P, t, "mix: expected \"string materials\" with two material names");
    int ra, rb;
    const Material *a = pbrt_named_material(P, mats[0], &ra);
    const Material *b = pbrt_named_material(P, mats[1], &rb);
    if (ra || rb)
        return -1;
    a = pbrt_named_material(P, mats[0], &ra); /* b's definition may have moved it */
    if (!a || !b) {
        P->missing_texture = 1; /* perhaps defined further down */
        return FAIL_TOK(P, t, "mix: expected materials defined before, found \"%.60s\"",
                        !a ? mats[0] : mats[1]);
    }
    RayesParam q[3];
    float amount[3];
    if (tex_input(P, pl, "amount", half, &q[2], amount) != 0)
        return -1;
    if (strcmp(a->shader, "diffuse") == 0 && strcmp(b->shader, "diffuse") == 0 &&
        mat_get(a, "reflectance") && mat_get(b, "reflectance")) {
        q[0] = reflectance_input(P, a, "tex1");
        q[1] = reflectance_input(P, b, "tex2");
        pbrt_warn_at(
            P, t->line, t->col, "mix diffuse",
            "mix: two diffuse materials become one diffuse material of the blended reflectance");
        float c[3];
        for (int k = 0; k < 3; k++) /* the constant, or the pattern's stand-in */
            c[k] = (1 - amount[0]) * mat_get(a, "reflectance")[k] +
                   amount[0] * mat_get(b, "reflectance")[k];
        pbrt_mat_init(m, "diffuse");
        if (q[0].type != RAYES_PARAM_PATTERN && q[1].type != RAYES_PARAM_PATTERN &&
            q[2].type != RAYES_PARAM_PATTERN) {
            pbrt_mat_color(m, "reflectance", c);
            return 0;
        }
        long i = define_pattern(P, t, " mix", 0, "mix", q, 3, c);
        if (i < 0)
            return -1;
        mat_pattern(m, "reflectance", (size_t)i);
        return 0;
    }
    if (mix_of(P, a, b, &q[2], amount[0], m) == 0)
        return 0;
    *m = amount[0] > 0.5f ? *b : *a;
    pbrt_warn_at(P, t->line, t->col, "mix",
                 "mix: rayes cannot blend these materials (an interface, more than %d "
                 "parameters between them, or mixes nested too deep); using the heavier one "
                 "(\"%.60s\")",
                 MAT_MAX_PARAMS - 4, amount[0] > 0.5f ? mats[1] : mats[0]);
    return 0;
}

/* coateddiffuse: reflectance, roughness and thickness may be textures. */
static int coated_material(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    static const float half[3] = {0.5f, 0.5f, 0.5f}, thin[3] = {0.01f, 0.01f, 0.01f};
    pbrt_mat_init(m, "coateddiffuse");
    if (mat_textured(P, pl, m, "reflectance", "reflectance", RAYES_PARAM_COLOR, half) != 0 ||
        mat_roughness(P, t, pl, m, 0.0, "") != 0 ||
        mat_textured(P, pl, m, "thickness", "thickness", RAYES_PARAM_FLOAT, thin) != 0)
        return -1;
    mat_float(m, "eta", (float)pbrt_get_float(pl, "eta", 1.5));
    return 0;
}

/* conductor (and coatedconductor's conductor): reflectance if given, else
 * eta and k (copper by default, as pbrt); each and the roughness may be
 * textures. */
static int conductor_material(Parser *P, const Token *t, const char *type, ParamList *pl,
                              Material *m)
{
    static const float cu_eta[3] = {0.200f, 0.924f, 1.102f}, cu_k[3] = {3.912f, 2.452f, 2.142f};
    int coated = strcmp(type, "coatedconductor") == 0;
    pbrt_mat_init(m, "conductor");
    if (coated) { /* the coat in closed form (conductor's "coat"; docs/pbrt.md) */
        RoughNames n = rough_names("interface.");
        double r;
        if (get_roughness(P, t, pl, &n, 0.0, &r) != 0)
            return -1;
        mat_float(m, "coat", 1.0f);
        mat_float(m, "coat_roughness", (float)r);
        mat_float(m, "coat_eta", (float)pbrt_get_float(pl, "interface.eta", 1.5));
        (void)pbrt_find(pl, "thickness"); /* a clear layer's (albedo 0): a per cent or so */
    }
    const char *eta_name = coated ? "conductor.eta" : "eta", *k_name = coated ? "conductor.k" : "k";
    int r = pbrt_find(pl, "reflectance")
                ? mat_textured(P, pl, m, "reflectance", "reflectance", RAYES_PARAM_COLOR, cu_eta)
                : mat_textured(P, pl, m, eta_name, "eta", RAYES_PARAM_COLOR, cu_eta) ||
                      mat_textured(P, pl, m, k_name, "k", RAYES_PARAM_COLOR, cu_k);
    if (r != 0 || mat_roughness(P, t, pl, m, 0.0, coated ? "conductor." : "") != 0)
        return -1;
    return 0;
}

/* pbrt-v4's hair as rayes's `physicalhair` (docs/pbrt.md), the same
 * BSDF (Chiang et al. 2016): sigma_a, reflectance or the melanin
 * concentrations, which the shader takes in pbrt's order (sigma_a, then
 * reflectance, then melanin: 1.3 of eumelanin when none is given), each
 * a constant or a texture; eta, beta_m, beta_n and alpha. */
static int hair_material(Parser *P, ParamList *pl, Material *m)
{
    static const float none[3] = {-1, -1, -1}, zero[3] = {0, 0, 0};
    pbrt_mat_init(m, "physicalhair");
    /* pbrt-v3 called the reflectance "color" */
    const char *refl =
        pbrt_find(pl, "reflectance") || !pbrt_find(pl, "color") ? "reflectance" : "color";
    int given = pbrt_find(pl, "sigma_a") || pbrt_find(pl, refl) || pbrt_find(pl, "eumelanin") ||
                pbrt_find(pl, "pheomelanin");
    if (mat_textured(P, pl, m, "sigma_a", "sigma_a", RAYES_PARAM_COLOR, none) != 0 ||
        mat_textured(P, pl, m, refl, "reflectance", RAYES_PARAM_COLOR, none) != 0)
        return -1;
    if (given) { /* pbrt's 1.3 of eumelanin only when nothing names the colour */
        if (mat_textured(P, pl, m, "eumelanin", "eumelanin", RAYES_PARAM_FLOAT, zero) != 0 ||
            mat_textured(P, pl, m, "pheomelanin", "pheomelanin", RAYES_PARAM_FLOAT, zero) != 0)
            return -1;
    }
    mat_float(m, "eta", (float)pbrt_get_float(pl, "eta", 1.55));
    mat_float(m, "beta_m", (float)pbrt_get_float(pl, "beta_m", 0.3));
    mat_float(m, "beta_n", (float)pbrt_get_float(pl, "beta_n", 0.3));
    mat_float(m, "alpha", (float)pbrt_get_float(pl, "alpha", 2.0));
    return 0;
}

/* The medium of pbrt-v4's subsurface: a named one (Jensen 2001's), or
 * reflectance and mfp, or sigma_a and sigma_s (pbrt's default: whole
 * milk); g reduces sigma_s to sigma_s' = (1 - g) sigma_s. */
static int subsurface_medium(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    static const float milk_a[3] = {0.0011f, 0.0024f, 0.014f}, milk_s[3] = {2.55f, 3.21f, 3.77f},
                       one[3] = {1, 1, 1};
    const char *name = pbrt_get_string(pl, "name", NULL);
    float a[3], b[3];
    if (name) {
        const MeasuredMedium *med = media_find(name);
        if (!med)
            return FAIL_TOK(P, t,
                            "subsurface: unknown medium \"%.60s\" (rayes knows Jensen 2001's: "
                            "Apple, Chicken1, Chicken2, Cream, Ketchup, Marble, Potato, "
                            "Skimmilk, Skin1, Skin2, Spectralon, Wholemilk)",
                            name);
        pbrt_mat_color(m, "sigma_s", med->sigma_s);
        pbrt_mat_color(m, "sigma_a", med->sigma_a);
        return 0;
    }
    if (pbrt_find(pl, "reflectance")) {
        const Texture *tex = NULL;
        int k = pbrt_get_color(P, pl, "reflectance", one, a, &tex);
        if (k < 0 || pbrt_get_color(P, pl, "mfp", one, b, NULL) < 0)
            return -1;
        if (k == 2) { /* a texture: the medium of a mid reflectance, tinted by it per point */
            static const float mid[3] = {0.5f, 0.5f, 0.5f};
            memcpy(a, mid, sizeof a);
            mat_pattern(m, "reflectance", (size_t)(tex - P->textures));
        }
        pbrt_mat_color(m, "reflectance", a);
        pbrt_mat_color(m, "mfp", b);
        return 0;
    }
    if (pbrt_get_color(P, pl, "sigma_a", milk_a, a, NULL) < 0 ||
        pbrt_get_color(P, pl, "sigma_s", milk_s, b, NULL) < 0)
        return -1;
    float g = (float)pbrt_get_float(pl, "g", 0.0);
    for (int k = 0; k < 3; k++)
        b[k] *= 1.0f - g;
    pbrt_mat_color(m, "sigma_s", b);
    pbrt_mat_color(m, "sigma_a", a);
    return 0;
}

/* pbrt-v4's subsurface as rayes's `subsurface` (memo 6.2, docs/pbrt.md):
 * pbrt's "scale" multiplies the per-mm coefficients into per-scene-unit
 * ones, so rayes's unitlength (scene units per mm) is 1 / scale; eta
 * (pbrt's default 1.33) and the roughness of the boundary become the
 * coat's. */
static int subsurface_material(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    pbrt_mat_init(m, "subsurface");
    if (subsurface_medium(P, t, pl, m) != 0)
        return -1;
    double scale = pbrt_get_float(pl, "scale", 1.0);
    if (!(scale > 0.0))
        return FAIL_TOK(P, t, "subsurface: \"scale\" must be positive, got %g", scale);
    mat_float(m, "unitlength", (float)(1.0 / scale));
    mat_float(m, "eta", (float)pbrt_get_float(pl, "eta", 1.33));
    if (mat_roughness(P, t, pl, m, 0.0, "") != 0)
        return -1;
    return 0;
}

/* ------------------------------------------------- pbrt-v3's materials */

/* pbrt-v3's roughness as rayes' (alpha squared): remapped (its default)
 * through v3's polynomial in log(roughness) (TrowbridgeReitz's
 * RoughnessToAlpha, not v4's square root), or alpha itself with
 * "remaproughness" false; uroughness and vroughness as their alphas'
 * geometric mean. Materials that are specular at roughness 0 (v3's glass
 * and kdsubsurface test it before remapping: zero_is_smooth) stay 0.
 * Constants (a texture's constant value). */
static int v3_roughness(Parser *P, ParamList *pl, double def, int zero_is_smooth, Material *m)
{
    double r, ru, rv;
    if (pbrt_get_float_tex(P, pl, "roughness", def, &r) != 0 ||
        pbrt_get_float_tex(P, pl, "uroughness", r, &ru) != 0 ||
        pbrt_get_float_tex(P, pl, "vroughness", r, &rv) != 0)
        return -1;
    if (zero_is_smooth && ru == 0.0 && rv == 0.0) { /* v3's glass: specular, no remap */
        mat_float(m, "roughness", 0.0f);
        return 0;
    }
    Param *remap = pbrt_find(pl, "remaproughness");
    int alpha_given = remap && remap->n_num && remap->num[0] == 0.0;
    double a[2], in[2] = {ru, rv};
    for (int k = 0; k < 2; k++) {
        double x = log(fmax(in[k], 1e-3));
        a[k] = alpha_given
                   ? fmax(in[k], 0.0)
                   : 1.62142 + x * (0.819955 + x * (0.1734 + x * (0.0171201 + x * 0.000640711)));
        a[k] = fmax(a[k], 0.0);
    }
    mat_float(m, "roughness", (float)(a[0] * a[1]));
    return 0;
}

/* The index of refraction of a pbrt-v3 material: "eta", or its older
 * "index", else def. */
static float v3_eta(Parser *P, ParamList *pl, double def)
{
    static const float none[3] = {-1, -1, -1};
    float c[3];
    if (pbrt_get_color(P, pl, "eta", none, c, NULL) > 0)
        return (c[0] + c[1] + c[2]) / 3.0f;
    return (float)pbrt_get_float(pl, "index", def);
}

/* A parameter of pbrt-v3's that rayes does not draw, warned once when it
 * is not its harmless default (dflt). */
static void v3_unused(Parser *P, const Token *t, ParamList *pl, const char *type, const char *name,
                      float dflt)
{
    static const float none[3] = {-1, -1, -1};
    float c[3];
    int k = pbrt_get_color(P, pl, name, none, c, NULL);
    if (k != 0 && !(k == 1 && c[0] == dflt && c[1] == dflt && c[2] == dflt)) {
        char key[96];
        snprintf(key, sizeof key, "v3 %s %s", type, name);
        pbrt_warn_at(P, t->line, t->col, key, "%s: \"%s\" is not drawn (rayes' %s)", type, name,
                     type[0] == 'u' ? "uber is a plastic" : "approximation leaves it out");
    }
}

/* pbrt-v3's materials (matte, plastic, uber, substrate, metal, mirror,
 * glass, translucent, disney, kdsubsurface) as rayes' shaders
 * (docs/pbrt.md); 1 if type is one, 0 if not, -1 on error. */
static int v3_material(Parser *P, const Token *t, const char *type, ParamList *pl, Material *m)
{
    static const float half[3] = {.5f, .5f, .5f}, quarter[3] = {.25f, .25f, .25f},
                       one[3] = {1, 1, 1}, r09[3] = {.9f, .9f, .9f};
    if (strcmp(type, "matte") == 0) {
        v3_unused(P, t, pl, type, "sigma", 0);
        return diffuse_material(P, pl, m, "Kd") ? -1 : 1;
    }
    if (strcmp(type, "plastic") == 0 || strcmp(type, "uber") == 0 ||
        strcmp(type, "substrate") == 0) {
        /* a Lambertian base plus a dielectric glossy lobe scaled by Ks */
        int sub = type[0] == 's';
        pbrt_mat_init(m, "coateddiffuse");
        if (mat_textured(P, pl, m, "Kd", "reflectance", RAYES_PARAM_COLOR, sub ? half : quarter) ||
            mat_textured(P, pl, m, "Ks", "specular", RAYES_PARAM_COLOR, sub ? half : quarter) ||
            v3_roughness(P, pl, 0.1, 0, m))
            return -1;
        mat_float(m, "eta", type[0] == 'u' ? v3_eta(P, pl, 1.5) : 1.5f);
        mat_float(m, "thickness", 0.0f);
        if (type[0] == 'u') {
            v3_unused(P, t, pl, type, "Kr", 0);
            v3_unused(P, t, pl, type, "Kt", 0);
            float op[3];
            if (pbrt_get_color(P, pl, "opacity", one, op, NULL) < 0)
                return -1;
            if (op[0] < 1.0f || op[1] < 1.0f || op[2] < 1.0f)
                pbrt_mat_color(m, "Os", op);
        }
        return 1;
    }
    if (strcmp(type, "metal") == 0) {
        static const float cu_eta[3] = {0.200f, 0.924f, 1.102f}, cu_k[3] = {3.912f, 2.452f, 2.142f};
        pbrt_mat_init(m, "conductor");
        if (mat_textured(P, pl, m, "eta", "eta", RAYES_PARAM_COLOR, cu_eta) ||
            mat_textured(P, pl, m, "k", "k", RAYES_PARAM_COLOR, cu_k) ||
            v3_roughness(P, pl, 0.01, 0, m))
            return -1;
        return 1;
    }
    if (strcmp(type, "mirror") == 0) {
        pbrt_mat_init(m, "conductor");
        if (mat_textured(P, pl, m, "Kr", "reflectance", RAYES_PARAM_COLOR, r09))
            return -1;
        mat_float(m, "roughness", 0.0f);
        return 1;
    }
    if (strcmp(type, "glass") == 0) {
        float kt[3];
        pbrt_mat_init(m, "dielectric");
        mat_float(m, "eta", v3_eta(P, pl, 1.5));
        if (v3_roughness(P, pl, 0.0, 1, m) || pbrt_get_color(P, pl, "Kt", one, kt, NULL) < 0)
            return -1;
        if (kt[0] != 1.0f || kt[1] != 1.0f || kt[2] != 1.0f)
            pbrt_mat_color(m, "transmitcolor", kt);
        v3_unused(P, t, pl, type, "Kr", 1);
        return 1;
    }
    if (strcmp(type, "translucent") == 0) {
        float kd[3], re[3], tr[3], refl[3], tran[3];
        if (pbrt_get_color(P, pl, "Kd", quarter, kd, NULL) < 0 ||
            pbrt_get_color(P, pl, "reflect", half, re, NULL) < 0 ||
            pbrt_get_color(P, pl, "transmit", half, tr, NULL) < 0)
            return -1;
        for (int c = 0; c < 3; c++)
            refl[c] = kd[c] * re[c], tran[c] = kd[c] * tr[c];
        pbrt_mat_init(m, "diffusetransmission");
        pbrt_mat_color(m, "reflectance", refl);
        pbrt_mat_color(m, "transmittance", tran);
        v3_unused(P, t, pl, type, "Ks", 0.25f);
        (void)pbrt_find(pl, "roughness");
        return 1;
    }
    if (strcmp(type, "disney") == 0) {
        /* mostly metal: a conductor of its colour; mostly transmissive: a
         * dielectric; else its colour under a coat of its specular (0.5
         * is the F0 of index 1.5); roughness r is alpha r^2 */
        double rough = pbrt_get_float(pl, "roughness", 0.5), r4 = rough * rough * rough * rough;
        if (pbrt_get_float(pl, "spectrans", 0.0) > 0.5) {
            pbrt_mat_init(m, "dielectric");
            mat_float(m, "eta", v3_eta(P, pl, 1.5));
            mat_float(m, "roughness", (float)r4);
            return 1;
        }
        int metal = pbrt_get_float(pl, "metallic", 0.0) >= 0.5;
        pbrt_mat_init(m, metal ? "conductor" : "coateddiffuse");
        if (mat_textured(P, pl, m, "color", "reflectance", RAYES_PARAM_COLOR, half))
            return -1;
        mat_float(m, "roughness", (float)r4);
        if (!metal) {
            float s = (float)pbrt_get_float(pl, "specular", 0.5) / 0.5f, sc[3] = {s, s, s};
            pbrt_mat_color(m, "specular", sc);
            mat_float(m, "thickness", 0.0f);
        }
        return 1;
    }
    if (strcmp(type, "kdsubsurface") == 0) {
        /* the medium of total diffuse reflectance Kd and mean free path
         * scale mfp in scene units (v3's mfree): rayes' mfp of the
         * subsurface shader, in mm, times unitlength */
        float kd[3], mfp[3];
        if (pbrt_get_color(P, pl, "Kd", half, kd, NULL) < 0 ||
            pbrt_get_color(P, pl, "mfp", half, mfp, NULL) < 0)
            return -1;
        double scale = pbrt_get_float(pl, "scale", 1.0);
        pbrt_mat_init(m, "subsurface");
        pbrt_mat_color(m, "reflectance", kd);
        pbrt_mat_color(m, "mfp", mfp);
        mat_float(m, "unitlength", (float)(scale > 0.0 ? scale : 1.0));
        mat_float(m, "eta", (float)pbrt_get_float(pl, "eta", 1.33));
        return v3_roughness(P, pl, 0.0, 1, m) ? -1 : 1;
    }
    return 0;
}

static int material_of_type(Parser *P, const Token *t, const char *type, ParamList *pl, Material *m)
{
    int v3 = v3_material(P, t, type, pl, m);
    if (v3 != 0)
        return v3 < 0 ? -1 : 0;
    if (strcmp(type, "diffuse") == 0)
        return diffuse_material(P, pl, m, "reflectance");
    if (strcmp(type, "coateddiffuse") == 0)
        return coated_material(P, t, pl, m);
    if (strcmp(type, "conductor") == 0 || strcmp(type, "coatedconductor") == 0)
        return conductor_material(P, t, type, pl, m);
    if (strcmp(type, "thindielectric") == 0) { /* a sheet: light through it unbent */
        static const float d15[3] = {1.5f, 1.5f, 1.5f};
        float c[3];
        if (pbrt_get_color(P, pl, "eta", d15, c, NULL) < 0)
            return -1;
        pbrt_mat_init(m, "thindielectric");
        mat_float(m, "eta", (c[0] + c[1] + c[2]) / 3.0f);
        return 0;
    }
    if (strcmp(type, "dielectric") == 0) {
        static const float d15[3] = {1.5f, 1.5f, 1.5f};
        float c[3];
        if (pbrt_get_color(P, pl, "eta", d15, c, NULL) < 0)
            return -1;
        pbrt_mat_init(m, "dielectric");
        mat_float(m, "eta", (c[0] + c[1] + c[2]) / 3.0f);
        return mat_roughness(P, t, pl, m, 0.0, "");
    }
    if (strcmp(type, "mix") == 0)
        return mix_material(P, t, pl, m);
    if (strcmp(type, "hair") == 0)
        return hair_material(P, pl, m);
    if (strcmp(type, "subsurface") == 0)
        return subsurface_material(P, t, pl, m);
    if (strcmp(type, "interface") == 0 || strcmp(type, "") == 0 || strcmp(type, "none") == 0) {
        /* pbrt's "interface" (and "" or "none") marks a shape that only
         * bounds a participating medium: it is not a surface at all (its
         * medium, if any, is pbrt_medium.c's). */
        pbrt_mat_init(m, PBRT_INVISIBLE);
        return 0;
    }
    if (strcmp(type, "diffusetransmission") == 0) { /* reflects and transmits diffusely */
        static const float quarter[3] = {0.25f, 0.25f, 0.25f};
        pbrt_mat_init(m, "diffusetransmission");
        if (mat_textured(P, pl, m, "reflectance", "reflectance", RAYES_PARAM_COLOR, quarter) != 0 ||
            mat_textured(P, pl, m, "transmittance", "transmittance", RAYES_PARAM_COLOR, quarter) !=
                0)
            return -1;
        mat_float(m, "scale", (float)pbrt_get_float(pl, "scale", 1.0));
        return 0;
    }
    char key[96];
    snprintf(key, sizeof key, "material %.60s", type);
    pbrt_warn_at(P, t->line, t->col, key, "material \"%.40s\" is not supported; using matte", type);
    pbrt_mat_init(m, "matte");
    for (size_t i = 0; i < pl->n; i++)
        if (strcmp(pl->p[i].name, "displacement") != 0)
            pl->p[i].used = 1; /* one warning for the material, not one per parameter */
    return 0;
}

/* pbrt-v4's "normalmap": a linear image of tangent-space normals, as a
 * pattern the shader's "normalmap" parameter is bound to (the shaders
 * rayes maps pbrt's materials to read it; others warn). */
static int mat_normal_map(Parser *P, const Token *t, ParamList *pl, Material *m)
{
    const char *file = pbrt_get_string(pl, "normalmap", NULL);
    if (!file || !file[0])
        return 0;
    static const char *const takes[] = {
        "diffuse", "dielectric", "conductor", "coateddiffuse", "diffusetransmission",
        "matte",   "plastic",    NULL};
    int k = 0;
    while (takes[k] && strcmp(m->shader, takes[k]) != 0)
        k++;
    if (!takes[k]) {
        pbrt_warn_at(P, t->line, t->col, "normalmap",
                     "\"normalmap\" on a material rayes draws as \"%s\" is not used", m->shader);
        return 0;
    }
    char path[PBRT_PATH];
    if (pbrt_resolve(P, t, file, path, sizeof path) != 0)
        return -1;
    const RayesParam q[2] = {{.name = "filename", .type = RAYES_PARAM_STRING, .string = path},
                             {.name = "encoding", .type = RAYES_PARAM_STRING, .string = "linear"}};
    static const float flat[3] = {0.5f, 0.5f, 1.0f};
    long idx = define_pattern(P, t, " normalmap", 0, "imagemap", q, 2, flat);
    if (idx < 0)
        return -1;
    if (P->textures[idx].pattern[0])
        mat_pattern(m, "normalmap", (size_t)idx);
    return 0;
}

static int make_material(Parser *P, const Token *t, const char *type, ParamList *pl, Material *m)
{
    if (material_of_type(P, t, type, pl, m) != 0 || mat_normal_map(P, t, pl, m) != 0)
        return -1;
    return strcmp(m->shader, PBRT_INVISIBLE) != 0 ? mat_displacement(P, pl, m) : 0;
}

/* ------------------------------------------------------------ forward references */

/* In a MakeNamedMaterial that failed (r, the handler's result) for a
 * texture or material not defined yet: 0 when it was deferred (the error
 * dropped: it is read again when first asked for), else r. */
static int defer_material(Parser *P, const Lexer *at, const Token *t, const char *name, int r)
{
    if (!r || !P->missing_texture || P->rereading || P->recording)
        return r;
    Deferred *d = pbrt_defer(P, &P->defs, at, t);
    if (!d)
        return -1;
    snprintf(d->name, sizeof d->name, "%s", name);
    if (P->err_size)
        P->err[0] = '\0'; /* not an error yet */
    return 0;
}

static const Material *find_material(const Parser *P, const char *name)
{
    for (size_t i = P->n_materials; i-- > 0;)
        if (strcmp(P->materials[i].name, name) == 0)
            return &P->materials[i].m;
    return NULL;
}

const Material *pbrt_named_material(Parser *P, const char *name, int *r)
{
    *r = 0;
    const Material *m = find_material(P, name);
    for (size_t i = P->defs.n; !m && i-- > 0;) {
        Deferred *d = &P->defs.d[i];
        if (d->done || strcmp(d->name, name) != 0)
            continue;
        if (P->rereading >= PBRT_MAX_REREAD) {
            *r = FAIL_TOK(P, &d->t,
                          "MakeNamedMaterial \"%.60s\": mixes of materials defined "
                          "further down nest more than %d deep",
                          name, PBRT_MAX_REREAD);
            return NULL;
        }
        d->done = 1;        /* no loop through a mix of itself */
        Deferred copy = *d; /* reading it again may grow P->defs */
        if (pbrt_reread(P, &copy, &copy.gs, pbrt_d_makenamedmaterial) != 0) {
            P->defs.d[i].done = 0; /* a mix being read may be deferred in turn, and ask again */
            *r = -1;
            return NULL;
        }
        m = find_material(P, name);
    }
    return m;
}

/* ------------------------------------------------------------ directives */

int pbrt_d_material(Parser *P, const Token *t)
{
    char type[64];
    ParamList pl = {0};
    int r = pbrt_need_world(P, t, 1);
    if (!r)
        r = pbrt_name_and_params(P, type, sizeof type, "a material type", &pl, NULL);
    if (!r)
        r = make_material(P, t, type, &pl, &P->gs.material);
    if (!r) {
        pbrt_warn_unused(P, &pl, "Material", type);
        P->gs.pending[0] = '\0';
    }
    pbrt_params_free(&pl);
    return r;
}

int pbrt_d_makenamedmaterial(Parser *P, const Token *t)
{
    char name[128] = "";
    ParamList pl = {0};
    Material m;
    Lexer at = *P->lx; /* for reading it again (pbrt_defer_material) */
    P->missing_texture = 0;
    int r = pbrt_need_world(P, t, 1);
    if (!r)
        r = pbrt_name_and_params(P, name, sizeof name, "a material name", &pl, NULL);
    const char *type = r ? NULL : pbrt_get_string(&pl, "type", NULL);
    if (!r && !type)
        r = FAIL_TOK(P, t, "MakeNamedMaterial \"%.60s\": expected \"string type\"", name);
    if (!r)
        r = make_material(P, t, type, &pl, &m);
    if (!r) {
        pbrt_warn_unused(P, &pl, "MakeNamedMaterial", type);
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
    pbrt_params_free(&pl);
    return defer_material(P, &at, t, name, r);
}

int pbrt_d_namedmaterial(Parser *P, const Token *t)
{
    char name[128];
    Token w;
    if (pbrt_need_world(P, t, 1) ||
        pbrt_expect_string(P, name, sizeof name, "a material name", &w) != 0)
        return -1;
    int r;
    const Material *m = pbrt_named_material(P, name, &r);
    if (r)
        return -1;
    if (m) {
        P->gs.material = *m;
        P->gs.pending[0] = '\0';
        return 0;
    }
    /* defined further down, perhaps: its shapes wait (pbrt_defer_shape) */
    snprintf(P->gs.pending, sizeof P->gs.pending, "%s", name);
    P->gs.pending_file = P->lx->name;
    P->gs.pending_line = w.line;
    P->gs.pending_col = w.col;
    return 0;
}
