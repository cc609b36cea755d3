/*
 * io/pbrt_material.c — pbrt materials and textures (pbrt_internal.h):
 * Material, MakeNamedMaterial, NamedMaterial and Texture. Each pbrt
 * material becomes one call of a built-in shader (diffuse, coateddiffuse,
 * conductor, dielectric; paintedplastic for an image-textured diffuse;
 * matte for what has no counterpart) with at most MAT_MAX_PARAMS
 * parameters; what is approximated or dropped is warned about once.
 * Textures are a constant colour or an image file with a scale. Named
 * materials and textures are found latest first, so a redefinition wins.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/pbrt_internal.h"

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

/* rayes' roughness r is pbrt's with remapping on (alpha = sqrt(r)). pbrt's
 * "remaproughness" false gives alpha itself, so r = alpha^2. Anisotropic
 * roughness (uroughness, vroughness) becomes the isotropic lobe of the
 * two alphas' geometric mean, which keeps the lobe's solid angle. */
static double get_roughness(ParamList *pl, double def)
{
    double r = pbrt_get_float(pl, "roughness", def);
    Param *u = pbrt_find(pl, "uroughness"), *v = pbrt_find(pl, "vroughness");
    Param *remap = pbrt_find(pl, "remaproughness");
    int alpha_given = remap && remap->n_num && remap->num[0] == 0.0;
    double ru = u && u->n_num ? u->num[0] : r, rv = v && v->n_num ? v->num[0] : r;
    double au = alpha_given ? ru : sqrt(fmax(ru, 0.0)), av = alpha_given ? rv : sqrt(fmax(rv, 0.0));
    double alpha = sqrt(fmax(au, 0.0) * fmax(av, 0.0));
    return alpha * alpha;
}

static int diffuse_material(Parser *P, ParamList *pl, Material *m, const char *param)
{
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    float c[3];
    const Texture *tex = NULL;
    int k = pbrt_get_color(P, pl, param, half, c, &tex);
    if (k < 0)
        return -1;
    if (k == 2) { /* Cs T Kd (diffuse light), T the image */
        pbrt_mat_init(m, "paintedplastic");
        mat_float(m, "Kd", 1.0f);
        mat_float(m, "Ks", 0.0f);
        pbrt_mat_color(m, "Cs", c);
        mat_texture(m, tex->path);
        return 0;
    }
    pbrt_mat_init(m, "diffuse");
    pbrt_mat_color(m, "reflectance", c);
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
    Param *names = pbrt_find(pl, "materials");
    if (!names || names->n_str != 2)
        return FAIL_TOK(P, t, "mix: expected \"string materials\" with two material names");
    double amount;
    if (pbrt_get_float_tex(P, pl, "amount", 0.5, &amount) != 0)
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
        pbrt_mat_init(m, "diffuse");
        pbrt_mat_color(m, "reflectance", c);
        pbrt_warn_at(P, t->line, t->col, "mix diffuse", "mix: two diffuse materials become one "
                     "diffuse material of the blended reflectance");
        return 0;
    }
    *m = amount > 0.5 ? *b : *a;
    pbrt_warn_at(P, t->line, t->col, "mix", "mix: rayes cannot blend these materials; using the "
                 "heavier one (\"%.60s\")", amount > 0.5 ? names->str[1] : names->str[0]);
    return 0;
}

static int make_material(Parser *P, const Token *t, const char *type, ParamList *pl, Material *m)
{
    static const float cu_eta[3] = {0.200f, 0.924f, 1.102f}, cu_k[3] = {3.912f, 2.452f, 2.142f};
    static const float half[3] = {0.5f, 0.5f, 0.5f};
    float c[3];
    int k;
    if (pbrt_find(pl, "displacement"))
        pbrt_warn_at(P, t->line, t->col, "displacement", "material \"%s\": \"displacement\" is not "
                     "supported (no displacement)", type);
    if (pbrt_find(pl, "normalmap"))
        pbrt_warn_at(P, t->line, t->col, "normalmap",
                     "material \"%s\": \"normalmap\" is not supported", type);
    if (strcmp(type, "diffuse") == 0)
        return diffuse_material(P, pl, m, "reflectance");
    if (strcmp(type, "coateddiffuse") == 0) {
        const Texture *tex = NULL;
        if ((k = pbrt_get_color(P, pl, "reflectance", half, c, &tex)) < 0)
            return -1;
        if (k == 2)
            pbrt_warn_at(P, t->line, t->col, "coateddiffuse texture", "coateddiffuse: an image "
                         "texture as reflectance is not supported; using its scale as a colour");
        double eta = pbrt_get_float(pl, "eta", 1.5);
        pbrt_mat_init(m, "coateddiffuse");
        pbrt_mat_color(m, "reflectance", c);
        mat_float(m, "roughness", (float)get_roughness(pl, 0.0));
        mat_float(m, "eta", (float)eta);
        mat_float(m, "thickness", (float)pbrt_get_float(pl, "thickness", 0.01));
        return 0;
    }
    if (strcmp(type, "conductor") == 0 || strcmp(type, "coatedconductor") == 0) {
        if (strcmp(type, "coatedconductor") == 0)
            pbrt_warn_at(P, t->line, t->col, "coatedconductor",
                         "coatedconductor: mapped to conductor (the coating is left out)");
        pbrt_mat_init(m, "conductor");
        int coated = strcmp(type, "coatedconductor") == 0;
        const char *eta_name = coated ? "conductor.eta" : "eta",
                   *k_name = coated ? "conductor.k" : "k";
        if ((k = pbrt_get_color(P, pl, "reflectance", half, c, NULL)) < 0)
            return -1;
        if (k > 0) {
            pbrt_mat_color(m, "reflectance", c);
        } else {
            float eta[3], kk[3];
            if (pbrt_get_color(P, pl, eta_name, cu_eta, eta, NULL) < 0 ||
                pbrt_get_color(P, pl, k_name, cu_k, kk, NULL) < 0)
                return -1;
            pbrt_mat_color(m, "eta", eta);
            pbrt_mat_color(m, "k", kk);
        }
        mat_float(m, "roughness", (float)get_roughness(pl, 0.0));
        return 0;
    }
    if (strcmp(type, "dielectric") == 0 || strcmp(type, "thindielectric") == 0) {
        if (type[0] == 't')
            pbrt_warn_at(P, t->line, t->col, "thindielectric",
                         "thindielectric: mapped to dielectric");
        static const float d15[3] = {1.5f, 1.5f, 1.5f};
        if (pbrt_get_color(P, pl, "eta", d15, c, NULL) < 0)
            return -1;
        pbrt_mat_init(m, "dielectric");
        mat_float(m, "eta", (c[0] + c[1] + c[2]) / 3.0f);
        mat_float(m, "roughness", (float)get_roughness(pl, 0.0));
        return 0;
    }
    if (strcmp(type, "mix") == 0)
        return mix_material(P, t, pl, m);
    if (strcmp(type, "interface") == 0 || strcmp(type, "") == 0 || strcmp(type, "none") == 0) {
        /* pbrt's "interface" (and "" or "none") marks a shape that only
         * bounds a participating medium: it is not a surface at all. */
        pbrt_warn_at(P, t->line, t->col, "interface",
                     "material \"interface\": its shapes only bound media, which rayes does "
                     "not render; they are left out");
        pbrt_mat_init(m, PBRT_INVISIBLE);
        return 0;
    }
    if (strcmp(type, "diffusetransmission") == 0) {
        pbrt_warn_at(P, t->line, t->col, "diffusetransmission", "diffusetransmission: mapped to "
                     "diffuse (no transmission)");
        return diffuse_material(P, pl, m, "reflectance");
    }
    char key[96];
    snprintf(key, sizeof key, "material %.60s", type);
    pbrt_warn_at(P, t->line, t->col, key, "material \"%.40s\" is not supported; using matte", type);
    pbrt_mat_init(m, "matte");
    for (size_t i = 0; i < pl->n; i++)
        pl->p[i].used = 1; /* one warning for the material, not one per parameter */
    return 0;
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
    if (!r)
        pbrt_warn_unused(P, &pl, "Material", type);
    pbrt_params_free(&pl);
    return r;
}

int pbrt_d_makenamedmaterial(Parser *P, const Token *t)
{
    char name[128];
    ParamList pl = {0};
    Material m;
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
    return r;
}

int pbrt_d_namedmaterial(Parser *P, const Token *t)
{
    char name[128];
    Token w;
    if (pbrt_need_world(P, t, 1) ||
        pbrt_expect_string(P, name, sizeof name, "a material name", &w) != 0)
        return -1;
    const Material *m = named_material(P, name);
    if (!m)
        return FAIL_TOK(P, &w, "NamedMaterial: expected a material defined with "
                        "MakeNamedMaterial, found \"%.60s\"", name);
    P->gs.material = *m;
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
    if (!r)
        r = pbrt_name_and_params(P, cls, sizeof cls, "a texture class", &pl, NULL);
    if (r) {
        pbrt_params_free(&pl);
        return -1;
    }
    Texture tex;
    memset(&tex, 0, sizeof tex);
    snprintf(tex.name, sizeof tex.name, "%s", name);
    static const float one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    if (strcmp(cls, "imagemap") == 0) {
        const char *file = pbrt_get_string(&pl, "filename", NULL);
        if (!file)
            r = FAIL_TOK(P, t, "imagemap: expected \"string filename\"");
        if (!r)
            r = pbrt_resolve(P, t, file, tex.path, sizeof tex.path);
        double scale = pbrt_get_float(&pl, "scale", 1.0);
        tex.rgb[0] = tex.rgb[1] = tex.rgb[2] = (float)scale;
        tex.image = 1;
        static const char *quiet[] = {"filter", "maxanisotropy", "wrap", "encoding", "invert",
                                      "uscale", "vscale", "udelta", "vdelta", "mapping"};
        for (size_t i = 0; i < sizeof quiet / sizeof quiet[0]; i++)
            if (pbrt_find(&pl, quiet[i]) && i >= 4)
                pbrt_warn_at(P, t->line, t->col, "imagemap mapping", "imagemap: mapping and "
                             "encoding parameters are not supported; the image is used as it is");
    } else if (strcmp(cls, "checkerboard") == 0) {
        float a[3], b[3];
        if (pbrt_get_color(P, &pl, "tex1", one, a, NULL) < 0 ||
            pbrt_get_color(P, &pl, "tex2", zero, b, NULL) < 0)
            r = -1;
        for (int c = 0; c < 3; c++)
            tex.rgb[c] = 0.5f * (a[c] + b[c]);
        pbrt_warn_at(P, t->line, t->col, "checkerboard",
                     "checkerboard: rayes has no built-in pattern shader for it; using the average "
                     "of tex1 and tex2");
        for (size_t i = 0; i < pl.n; i++)
            pl.p[i].used = 1;
    } else if (strcmp(cls, "constant") == 0) {
        r = pbrt_get_color(P, &pl, "value", one, tex.rgb, NULL) < 0;
    } else if (strcmp(cls, "scale") == 0) {
        float a[3], b[3];
        const Texture *img = NULL;
        int k = pbrt_get_color(P, &pl, "tex", one, a, &img);
        if (k < 0 || pbrt_get_color(P, &pl, "scale", one, b, NULL) < 0)
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
        pbrt_warn_at(P, t->line, t->col, key,
                     "Texture \"%.40s\" is not supported; using a constant 0.5", cls);
        tex.rgb[0] = tex.rgb[1] = tex.rgb[2] = 0.5f;
        for (size_t i = 0; i < pl.n; i++)
            pl.p[i].used = 1;
    }
    if (!r) {
        pbrt_warn_unused(P, &pl, "Texture", cls);
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
    pbrt_params_free(&pl);
    return r ? -1 : 0;
}
