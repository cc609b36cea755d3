/*
 * io/rib_ris.c — RenderMan 19 and later (RIS): Bxdf, Light, Integrator,
 * Displace (PxrDisplace), the geometric area lights of RenderMan 19 and
 * 20 (Geometry "rectlight" and its kin under AreaLightSource) and the
 * patterns PxrTexture, PxrNormalMap, PxrBump, PxrFractal, PxrChecker,
 * PxrMix, PxrExposure, PxrDispTransform and PxrManifold2D, translated to
 * rayes' own shaders, patterns and lights (docs/rib.md "RenderMan 19 and
 * later"); bumps and displacements become the built-in "displace". RIS describes materials by physically based lobes and
 * lights by shapes of unit size; rayes keeps the base colour, the
 * specular and refraction lobes and the lights' radiance, and says once
 * what it leaves out.
 *
 * Lights: radiance intensity * 2^exposure * lightColor, divided by the
 * emitting area when areaNormalize is set; shapes of RenderMan's unit
 * size (a 1 x 1 rectangle and a disk of diameter 1 in z = 0 emitting
 * toward +z, a sphere of diameter 1) scaled by the transform, as rayes'
 * "arealight"; a distant light is a disk of angleExtent degrees
 * (0.53, the sun) seen along +z, whose irradiance is its radiance times
 * its solid angle (areaNormalize: the intensity is the irradiance).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "io/rib_internal.h"
#include "io/rib_reader.h"
#include "util/colour.h"
#include "util/grow.h"
#include "util/sky.h"

/* ------------------------------------------------------------ values */

static const Param *value(const Param *p, size_t n, const char *name, size_t count)
{
    const Param *q = rib_find_param(p, n, name);
    return q && !q->d.reference && rib_is_num(q->v) && q->v->n == count ? q : NULL;
}

static float num(const Param *p, size_t n, const char *name, float dflt)
{
    const Param *q = value(p, n, name, 1);
    return q ? (float)q->v->d[0] : dflt;
}

/* A colour (three numbers, or one grey). */
static void color(const Param *p, size_t n, const char *name, const float dflt[3], float out[3])
{
    const Param *q = value(p, n, name, 3), *g = value(p, n, name, 1);
    for (int c = 0; c < 3; c++)
        out[c] = q ? (float)q->v->d[c] : g ? (float)g->v->d[0] : dflt[c];
}

static float max3(const float c[3])
{
    return fmaxf(c[0], fmaxf(c[1], c[2]));
}

static const char *string(const Param *p, size_t n, const char *name)
{
    const Param *q = rib_find_param(p, n, name);
    return q && q->d.ty == TY_STRING && !q->d.reference && q->v->n == 1 ? q->v->s[0] : NULL;
}

/* ------------------------------------------------------------ Bxdf */

/* The parameters of one translated shader. */
#define OUT_MAX 12
typedef struct Out {
    RayesParam p[OUT_MAX];
    char pattern[OUT_MAX][160];
    size_t n;
} Out;

static void out_string(Out *o, const char *name, const char *v)
{
    o->p[o->n++] = (RayesParam){name, RAYES_PARAM_STRING, {0, 0, 0}, v};
}

static void out_float(Out *o, const char *name, float v)
{
    o->p[o->n++] = (RayesParam){name, RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
}

static void out_color(Out *o, const char *name, const float c[3])
{
    o->p[o->n++] = (RayesParam){name, RAYES_PARAM_COLOR, {c[0], c[1], c[2]}, NULL};
}

/* A colour parameter that may reference a pattern ("tex:resultRGB", the
 * pattern's output after the colon): the pattern, if rayes has it;
 * otherwise the value (times gain), or dflt. */
static void out_colour_of(Rib *r, Out *o, const char *bxdf, const Param *p, size_t n,
                          const char *from, const char *to, const float dflt[3], float gain)
{
    const Param *q = rib_find_param(p, n, from);
    if (q && q->d.reference && q->v->n == 1 && q->d.ty == TY_STRING) {
        char buf[160];
        const char *name = rib_pattern_ref(r, q->v->s[0], buf, sizeof buf);
        if (name) {
            snprintf(o->pattern[o->n], sizeof o->pattern[0], "%s", name);
            name = o->pattern[o->n];
            if (gain != 1.0f)
                rib_warn_once(r, "ris gain pattern",
                              "Bxdf \"%s\": a gain other than 1 on a pattern is not applied",
                              bxdf);
            o->p[o->n++] = (RayesParam){to, RAYES_PARAM_PATTERN, {0, 0, 0}, name};
            return;
        }
        float c[3];
        if (rib_pattern_stand_in(r, q->v->s[0], c)) { /* an unbuilt pattern's input */
            for (int k = 0; k < 3; k++)
                c[k] *= gain;
            out_color(o, to, c);
            return;
        }
        char key[200];
        snprintf(key, sizeof key, "ris reference %.150s", q->v->s[0]);
        rib_warn_once(r, key,
                      "\"%s\": \"%s\" names the pattern \"%.100s\", which is not "
                      "defined or of a class rayes has not; its value is used",
                      bxdf, from, q->v->s[0]);
    }
    float c[3];
    color(p, n, from, dflt, c);
    for (int k = 0; k < 3; k++)
        c[k] *= gain;
    out_color(o, to, c);
}

static int referenced(const Param *p, size_t n, const char *name)
{
    const Param *q = rib_find_param(p, n, name);
    return q && q->d.reference;
}

/* PxrSurface's subsurface lobe (subsurfaceGain > 0) as rayes' subsurface
 * (memo 6.2): RenderMan's albedo (subsurfaceColor) and diffuse mean free
 * path (subsurfaceDmfp times subsurfaceDmfpColor, in mm; unitLength scene
 * units a mm, 0.1 for centimetres), the dipole for Jensen's and d'Eon's
 * models and Burley's normalized diffusion for the others, weighed by the
 * gain, under the specular lobe when there is one (roughness >= 0). A
 * textured subsurfaceColor tints each point, the medium keeping a
 * constant albedo; the diffuse lobe gives way to it. */
static const char *pxr_subsurface(Rib *r, const char *cls, const Param *p, size_t n, Out *o,
                                  float roughness)
{
    static const float albedo[3] = {0.83f, 0.791f, 0.753f},
                       dmfp_colour[3] = {0.851f, 0.557f, 0.395f};
    const Param *q = rib_find_param(p, n, "subsurfaceColor");
    char buf[160];
    const char *tex = q && q->d.reference && q->d.ty == TY_STRING && q->v->n == 1
                          ? rib_pattern_ref(r, q->v->s[0], buf, sizeof buf)
                          : NULL;
    float a[3], dc[3], d = num(p, n, "subsurfaceDmfp", 10);
    color(p, n, "subsurfaceColor", albedo, a);
    color(p, n, "subsurfaceDmfpColor", dmfp_colour, dc);
    if (tex) { /* the pattern over the albedo the medium keeps: its tint */
        out_color(o, "albedo", albedo);
        out_color(o, "reflectance", albedo);
        snprintf(o->pattern[o->n], sizeof o->pattern[0], "%s", tex);
        o->p[o->n] = (RayesParam){"reflectance", RAYES_PARAM_PATTERN, {0, 0, 0}, o->pattern[o->n]};
        o->n++;
    } else {
        out_color(o, "albedo", a);
    }
    float dmfp[3] = {d * dc[0], d * dc[1], d * dc[2]};
    out_color(o, "diffusemeanfreepath", dmfp);
    out_float(o, "unitlength", num(p, n, "unitLength", 0.1f));
    out_float(o, "ior", num(p, n, "subsurfaceIor", 1.4f));
    float type = num(p, n, "subsurfaceType", 0);
    out_string(o, "profile", type == 0 || type == 1 ? "dipole" : "burley");
    if (type > 2)
        rib_warn_once(r, "ris subsurface type",
                      "Bxdf \"%s\": subsurfaceType %g (multiple mean free paths, path traced) is "
                      "rendered with Burley's normalized diffusion",
                      cls, (double)type);
    out_float(o, "Kd", fminf(num(p, n, "subsurfaceGain", 0), 1.0f));
    out_float(o, "Ks", roughness >= 0.0f ? 1.0f : 0.0f);
    if (roughness >= 0.0f)
        out_float(o, "roughness", roughness);
    if (num(p, n, "diffuseGain", 1) > 0 && num(p, n, "subsurfaceGain", 0) < 1)
        rib_warn_once(r, "ris subsurface diffuse",
                      "Bxdf \"%s\": with a subsurface lobe its diffuse lobe is not added", cls);
    return "subsurface";
}

/* PxrSurface (and PxrLayerSurface): its glass lobe when it refracts; else
 * its diffuse lobe under a coat of its specular (or clearcoat) lobe, or
 * that lobe alone as a conductor (artistic face colour, or the physical
 * mode's index and extinction). */
static const char *pxr_surface(Rib *r, const char *cls, const Param *p, size_t n, Out *o)
{
    static const float d18[3] = {0.18f, 0.18f, 0.18f}, zero[3] = {0, 0, 0};
    static const float ior[3] = {1.5f, 1.5f, 1.5f};
    if (num(p, n, "refractionGain", 0) > 0) {
        static const float white[3] = {1, 1, 1};
        float tint[3];
        color(p, n, "refractionColor", white, tint); /* each crossing: in and out */
        for (int c = 0; c < 3; c++)
            tint[c] *= fminf(num(p, n, "refractionGain", 1), 1.0f);
        out_float(o, "eta", num(p, n, "glassIor", 1.5f));
        out_float(o, "roughness", num(p, n, "glassRoughness", 0.1f));
        out_color(o, "transmitcolor", tint);
        return "dielectric";
    }
    float gain = num(p, n, "diffuseGain", 1), dc[3], face[3], edge[3], rough[3], coat[3];
    color(p, n, "diffuseColor", d18, dc);
    color(p, n, "specularFaceColor", zero, face);
    color(p, n, "specularEdgeColor", zero, edge);
    color(p, n, "roughSpecularFaceColor", zero, rough);
    color(p, n, "clearcoatFaceColor", zero, coat);
    int physical = num(p, n, "specularFresnelMode", 0) != 0;
    float eta[3], k[3];
    color(p, n, "specularIor", ior, eta);
    color(p, n, "specularExtinctionCoeff", zero, k);
    int spec = max3(face) > 0 || max3(edge) > 0 || max3(rough) > 0 ||
               (physical && (max3(eta) != 1.0f || max3(k) > 0));
    int diffuse = gain > 0 && (max3(dc) > 0 || referenced(p, n, "diffuseColor"));
    if (num(p, n, "glowGain", 0) > 0 || num(p, n, "fuzzGain", 0) > 0 ||
        num(p, n, "singlescatterGain", 0) > 0)
        rib_warn_once(r, "ris lobes",
                      "Bxdf \"%s\": its glow, fuzz and single-scatter lobes are not translated "
                      "(diffuse, subsurface, specular, clearcoat and glass are)",
                      cls);
    /* the lobe that shines: the primary specular, else the rough
     * specular, else the clearcoat; its colour and roughness */
    int primary = max3(face) > 0 || max3(edge) > 0 || (physical && spec);
    float roughness = primary           ? num(p, n, "specularRoughness", 0.2f)
                      : max3(rough) > 0 ? num(p, n, "roughSpecularRoughness", 0.6f)
                                        : num(p, n, "clearcoatRoughness", 0);
    float shine[3];
    for (int c = 0; c < 3; c++)
        shine[c] = primary ? fmaxf(face[c], edge[c]) : max3(rough) > 0 ? rough[c] : coat[c];
    if (num(p, n, "subsurfaceGain", 0) > 0)
        return pxr_subsurface(r, cls, p, n, o, spec || max3(coat) > 0 ? roughness : -1.0f);
    if (diffuse) {
        out_colour_of(r, o, cls, p, n, "diffuseColor", "reflectance", d18, gain);
        if (!spec && max3(coat) <= 0)
            return "diffuse";
        out_float(o, "roughness", roughness);
        return "coateddiffuse";
    }
    if (!spec && max3(coat) <= 0) {
        out_color(o, "reflectance", zero);
        return "diffuse";
    }
    if (physical) {
        out_color(o, "eta", eta);
        out_color(o, "k", k);
    } else if (primary && max3(face) > 0) {
        out_colour_of(r, o, cls, p, n, "specularFaceColor", "reflectance", shine, 1);
    } else {
        out_color(o, "reflectance", shine);
    }
    out_float(o, "roughness", roughness);
    return "conductor";
}

/* PxrDisney: a conductor of its base colour when mostly metallic, else
 * the base colour under a coat (its specular lobe) or bare. */
static const char *pxr_disney(Rib *r, const char *cls, const Param *p, size_t n, Out *o)
{
    static const float base[3] = {0.2f, 0.5f, 0.8f};
    out_colour_of(r, o, cls, p, n, "baseColor", "reflectance", base, 1);
    float rough = num(p, n, "roughness", 0.25f);
    if (num(p, n, "metallic", 0) >= 0.5f) {
        out_float(o, "roughness", rough);
        return "conductor";
    }
    if (num(p, n, "specular", 0.5f) <= 0 && num(p, n, "clearcoat", 0) <= 0)
        return "diffuse";
    out_float(o, "roughness", rough);
    return "coateddiffuse";
}

/* RIS's "class" "name" params (the name optional; parameters come in
 * pairs): the class and the parameters, or NULL with the error set. */
static const char *class_and_params(Rib *r, const Args *a, const char *what, Param **p, size_t *n)
{
    size_t i = 0;
    const char *cls = rib_get_string(r, a, &i, what);
    if (!cls)
        return NULL;
    if (i < a->n && (a->n - i) % 2 == 1 && !rib_get_string(r, a, &i, "a name"))
        return NULL;
    return rib_get_params(r, a, i, p, n) == 0 ? cls : NULL;
}

/* RenderMan's bumpNormal (the Bxdf's, or its lobes'), connected to a
 * PxrNormalMap: rayes' "normalmap" bound to that pattern. */
static void out_normal_map(Rib *r, Out *o, const Param *p, size_t n)
{
    static const char *const names[] = {"bumpNormal", "diffuseBumpNormal", "specularBumpNormal"};
    for (int k = 0; k < 3 && o->n < OUT_MAX; k++) {
        const Param *q = rib_find_param(p, n, names[k]);
        char buf[160];
        const char *name = q && q->d.reference && q->d.ty == TY_STRING && q->v->n == 1
                               ? rib_pattern_ref(r, q->v->s[0], buf, sizeof buf)
                               : NULL;
        if (name) {
            snprintf(o->pattern[o->n], sizeof o->pattern[0], "%s", name);
            o->p[o->n] =
                (RayesParam){"normalmap", RAYES_PARAM_PATTERN, {0, 0, 0}, o->pattern[o->n]};
            o->n++;
            return;
        }
    }
}

/* Whether a reference ("node:output", or "node") names node. */
static int names_node(const char *ref, const char *node)
{
    const char *colon = strrchr(ref, ':');
    size_t len = colon ? (size_t)(colon - ref) : strlen(ref);
    return strlen(node) == len && strncmp(node, ref, len) == 0;
}

/* The PxrBump a Bxdf's bumpNormal references ("bump:resultN"), or NULL. */
static const struct RisBump *bump_of(const Rib *r, const Param *p, size_t n)
{
    static const char *const names[] = {"bumpNormal", "diffuseBumpNormal", "specularBumpNormal"};
    for (int k = 0; k < 3; k++) {
        const Param *q = rib_find_param(p, n, names[k]);
        if (!q || !q->d.reference || q->d.ty != TY_STRING || q->v->n != 1)
            continue;
        for (size_t b = r->n_bumps; b-- > 0;)
            if (names_node(q->v->s[0], r->bumps[b].name))
                return &r->bumps[b];
    }
    return NULL;
}

/* A Bxdf's bump (its bumpNormal referencing a PxrBump): the built-in
 * "displace" of the bump's height as a bump map (the shading normal
 * bends, the surface stays), the displacement of the geometry that
 * follows; a Bxdf without one ends the bump of the one before. A
 * displacement of the file's own (Displace, Displacement) is kept: an
 * object has one. */
static int bxdf_bump(Rib *r, const char *cls, const Param *p, size_t n)
{
    const struct RisBump *b = bump_of(r, p, n);
    if (!b) {
        if (r->a.displacement && r->a.displacement->bump)
            r->a.displacement = NULL;
        return 0;
    }
    if (r->a.displacement && !r->a.displacement->bump) {
        rib_warn_once(r, "ris bump and displacement",
                      "Bxdf \"%s\": its PxrBump is not applied to a displaced surface (the "
                      "displacement is kept)",
                      cls);
        return 0;
    }
    RayesParam q[2] = {{"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, b->height},
                       {"__bump", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL}};
    ShaderRec *sh = rib_shader_rec(r, "displace", q, 2);
    if (!sh)
        return -1;
    sh->bump = 1;
    r->a.displacement = sh;
    return 0;
}

static int h_bxdf(Rib *r, const Args *a)
{
    r->ris = 1;
    Param *p;
    size_t n;
    const char *cls = class_and_params(r, a, "a Bxdf class", &p, &n);
    if (!cls)
        return -1;
    static const float half[3] = {0.5f, 0.5f, 0.5f}, one[3] = {1, 1, 1}, zero[3] = {0, 0, 0};
    Out o = {.n = 0};
    const char *shader = "diffuse";
    if (strcasecmp(cls, "PxrDiffuse") == 0) {
        out_colour_of(r, &o, cls, p, n, "diffuseColor", "reflectance", half, 1);
    } else if (strcasecmp(cls, "PxrLMDiffuse") == 0) {
        out_colour_of(r, &o, cls, p, n, "frontColor", "reflectance", half, 1);
    } else if (strcasecmp(cls, "PxrSurface") == 0 || strcasecmp(cls, "PxrLayerSurface") == 0) {
        shader = pxr_surface(r, cls, p, n, &o);
    } else if (strcasecmp(cls, "PxrDisney") == 0 || strcasecmp(cls, "PxrDisneyBsdf") == 0) {
        shader = pxr_disney(r, cls, p, n, &o);
    } else if (strcasecmp(cls, "PxrConstant") == 0) {
        float e[3]; /* emitColor: the surface's own light, nothing reflected */
        color(p, n, "emitColor", one, e);
        shader = "matte";
        out_float(&o, "Ka", 0);
        out_float(&o, "Kd", 0);
        out_color(&o, "Ke", e);
    } else if (strcasecmp(cls, "PxrGlass") == 0 || strcasecmp(cls, "PxrLMGlass") == 0) {
        shader = "dielectric";
        out_float(&o, "eta", num(p, n, "ior", num(p, n, "eta", 1.5f)));
        out_float(&o, "roughness", num(p, n, "roughness", 0));
    } else if (strcasecmp(cls, "PxrLMPlastic") == 0) {
        shader = "coateddiffuse";
        out_colour_of(r, &o, cls, p, n, "diffuseColor", "reflectance", half, 1);
        out_float(&o, "roughness", num(p, n, "specularRoughness", num(p, n, "roughness", 0.1f)));
    } else if (strcasecmp(cls, "PxrLMMetal") == 0) {
        shader = "conductor";
        float c[3];
        color(p, n, "specularColor", one, c);
        out_color(&o, "reflectance", c);
        out_float(&o, "roughness", num(p, n, "roughness", 0.1f));
    } else if (strcasecmp(cls, "PxrLightEmission") == 0 || strcasecmp(cls, "PxrBlack") == 0) {
        out_color(&o, "reflectance", zero); /* an emitter's own surface: its light is the
                                               AreaLightSource's */
    } else {
        char key[128];
        snprintf(key, sizeof key, "bxdf %.100s", cls);
        rib_warn_once(r, key, "Bxdf \"%s\" is not one rayes translates: a grey diffuse instead",
                      cls);
    }
    if (strcmp(shader, "matte") != 0)
        out_normal_map(r, &o, p, n);
    int e = bxdf_bump(r, cls, p, n);
    free(p);
    if (e != 0)
        return -1;
    ShaderRec *sh = rib_shader_rec(r, shader, o.p, o.n);
    if (!sh)
        return -1;
    r->a.surface = sh;
    return 0;
}

/* ------------------------------------------------------------ patterns */

/* The size a transform gives object-space lengths: the cube root of its
 * determinant's magnitude (a uniform scale's factor). RenderMan's bumps
 * and displacements are in object space, rayes' in world space. */
static float object_scale(const float M[16])
{
    double det = (double)M[0] * ((double)M[5] * M[10] - (double)M[6] * M[9]) -
                 (double)M[1] * ((double)M[4] * M[10] - (double)M[6] * M[8]) +
                 (double)M[2] * ((double)M[4] * M[9] - (double)M[5] * M[8]);
    double k = cbrt(fabs(det));
    return k > 0.0 && k < 1e30 ? (float)k : 1.0f;
}

/* Sends a pattern the translation makes itself, of class type under
 * transform M, named in *name (a name starting with a space, which no
 * file's reference can name; "" when the sink takes no patterns). 0, or
 * -1 with the error set. */
static int send_internal(Rib *r, const char *type, const RayesParam *q, size_t n, const float M[16],
                         char name[160])
{
    const IoSink *s = r->sink;
    name[0] = '\0';
    if (!s->pattern) { /* a sink without patterns (name stays "") */
        rib_warn_once(r, "ris internal pattern",
                      "this output takes no patterns: RenderMan's bumps, displacements and "
                      "fractals are left out");
        return 0;
    }
    snprintf(name, 160, " ris %u %s", ++r->n_internal, type);
    ShaderRec *sh = rib_shader_rec(r, type, q, n);
    if (!sh)
        return -1;
    if (s->set_transform(s->target, M) != RAYES_OK ||
        s->pattern(s->target, name, sh->name, sh->params, sh->n) != RAYES_OK)
        return rib_sink_failed(r, s);
    r->real.have_M = 0;
    snprintf(sh->pattern, sizeof sh->pattern, "%s", name);
    return 0;
}

/* The parameters of a + b x, x the pattern src: a mix from a to a + b by
 * x (mix takes its amount as it is, so x may lie outside [0, 1]). */
static size_t affine_params(float a, float b, const char *src, RayesParam q[3])
{
    q[0] = (RayesParam){"tex1", RAYES_PARAM_COLOR, {a, a, a}, NULL};
    q[1] = (RayesParam){"tex2", RAYES_PARAM_COLOR, {a + b, a + b, a + b}, NULL};
    q[2] = (RayesParam){"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, src};
    return 3;
}

/* The pattern a float parameter references ("tex:resultF"), sent, in buf;
 * NULL when it references none rayes has (or is not a reference). */
static const char *float_ref(Rib *r, const Param *p, size_t n, const char *name, char buf[160])
{
    const Param *q = rib_find_param(p, n, name);
    if (!q || !q->d.reference || q->d.ty != TY_STRING || q->v->n != 1)
        return NULL;
    return rib_pattern_ref(r, q->v->s[0], buf, 160);
}

/* The manifold a pattern's "manifold" references ("name:result"), or NULL. */
static const struct RisManifold *manifold_of(const Rib *r, const Param *p, size_t n)
{
    const Param *q = rib_find_param(p, n, "manifold");
    if (!q || !q->d.reference || q->d.ty != TY_STRING || q->v->n != 1)
        return NULL;
    for (size_t k = r->n_manifolds; k-- > 0;)
        if (names_node(q->v->s[0], r->manifolds[k].name))
            return &r->manifolds[k];
    return NULL;
}

/* PxrManifold2D: kept by name (a later one of the same name replaces it
 * for the patterns after it). */
static int keep_manifold(Rib *r, const char *name, const Param *p, size_t n)
{
    if (num(p, n, "angle", 0) != 0)
        rib_warn_once(r, "ris manifold angle",
                      "PxrManifold2D: a rotation (\"angle\") is not applied");
    const char *ps = string(p, n, "primvarS");
    if (ps && ps[0])
        rib_warn_once(r, "ris manifold primvar",
                      "PxrManifold2D: \"primvarS\" is not used; the surface's st is");
    if (strlen(name) >= sizeof r->manifolds[0].name)
        return 0;
    if (util_grow((void **)&r->manifolds, &r->cap_manifolds, r->n_manifolds,
                  sizeof *r->manifolds) != 0)
        return rib_error(r, "out of memory");
    struct RisManifold *m = &r->manifolds[r->n_manifolds++];
    snprintf(m->name, sizeof m->name, "%s", name);
    m->scale[0] = num(p, n, "scaleS", 1), m->scale[1] = num(p, n, "scaleT", 1);
    m->offset[0] = num(p, n, "offsetS", 0), m->offset[1] = num(p, n, "offsetT", 0);
    m->invert_t = value(p, n, "invertT", 1) ? num(p, n, "invertT", 1) != 0 : -1;
    return 0;
}

/* RenderMan's placement of a 2-D pattern as rayes' uscale, vscale,
 * udelta and vdelta: RenderMan reads the image at (scaleS s + offsetS,
 * scaleT t + offsetT), that t inverted (1 - t') when invertT is on (its
 * default: Maya's t runs up, RenderMan's images down); rayes' imagemap
 * reads it at (uscale s + udelta, 1 - (vscale (1 - t) + vdelta)). The
 * pattern's own invertT counts, else the manifold's. */
static void placement(const Rib *r, const Param *p, size_t n, Out *o)
{
    const struct RisManifold *m = manifold_of(r, p, n);
    float sc[2] = {1, 1}, off[2] = {0, 0};
    int invert = 1;
    if (m) {
        memcpy(sc, m->scale, sizeof sc), memcpy(off, m->offset, sizeof off);
        invert = m->invert_t != 0;
    }
    if (value(p, n, "invertT", 1))
        invert = num(p, n, "invertT", 1) != 0;
    out_float(o, "uscale", sc[0]);
    out_float(o, "udelta", off[0]);
    out_float(o, "vscale", invert ? -sc[1] : sc[1]);
    out_float(o, "vdelta", invert ? off[1] + sc[1] : 1.0f - sc[1] - off[1]);
}

/* PxrBump: kept by name with the pattern of its height, the object-space
 * scale applied (rayes' displacements are in world units): its texture's
 * channel, or the pattern its inputBump references. A bump of neither is
 * flat and kept as none. */
static int keep_bump(Rib *r, const char *name, const Param *p, size_t n)
{
    float scale = num(p, n, "scale", 1) * object_scale(r->a.M);
    char height[160], src_buf[160];
    const char *file = string(p, n, "filename");
    if (file && file[0]) {
        Out o = {.n = 0};
        out_string(&o, "filename", rib_texture_source(r, file));
        out_string(&o, "encoding", "linear");
        float ch = num(p, n, "firstChannel", 0);
        if (!(ch >= 0 && ch <= 3)) {
            rib_warn_once(r, "ris bump channel",
                          "PxrBump: firstChannel %g is not 0 to 3; channel 0 is used", (double)ch);
            ch = 0;
        }
        out_float(&o, "channel", floorf(ch));
        out_float(&o, "scale", scale);
        placement(r, p, n, &o);
        if (send_internal(r, "imagemap", o.p, o.n, r->a.M, height) != 0)
            return -1;
        if (!height[0])
            return 0;
    } else {
        const char *src = float_ref(r, p, n, "inputBump", src_buf);
        if (!src || strlen(name) >= sizeof r->bumps[0].name)
            return 0;
        RayesParam q[3];
        size_t nq = affine_params(0, scale, src, q);
        if (send_internal(r, "mix", q, nq, r->a.M, height) != 0)
            return -1;
        if (!height[0])
            return 0;
    }
    if (strlen(name) >= sizeof r->bumps[0].name)
        return 0;
    if (util_grow((void **)&r->bumps, &r->cap_bumps, r->n_bumps, sizeof *r->bumps) != 0)
        return rib_error(r, "out of memory");
    struct RisBump *b = &r->bumps[r->n_bumps++];
    snprintf(b->name, sizeof b->name, "%s", name);
    snprintf(b->height, sizeof b->height, "%s", height);
    b->scale = scale;
    return 0;
}

/* PxrFractal's noise: rayes' fbm (turbulent: the sum of |noise|, pbrt's
 * wrinkled) of layers octaves, each weighed lacunarity^-(3 - 2 dimension)
 * times the one before, over the object's space (its default manifold)
 * times frequency, shifted by variation; sent, its name in fbm. rayes'
 * octaves double the frequency (lacunarity 2) and have no erosion. */
static int fractal_noise(Rib *r, const Param *p, size_t n, char fbm[160])
{
    float f = num(p, n, "frequency", 1), lac = num(p, n, "lacunarity", 2);
    float dim = num(p, n, "dimension", 1), var = num(p, n, "variation", 0);
    float omega = powf(lac > 1.0f ? lac : 2.0f, -(3.0f - 2.0f * dim));
    if (!(omega >= 0.0f && omega <= 1.0f))
        omega = omega > 1.0f ? 1.0f : 0.5f;
    if (fabsf(lac - 2.0f) > 0.01f || num(p, n, "erosion", 0) != 0)
        rib_warn_once(r, "ris fractal",
                      "PxrFractal: lacunarity other than 2 and erosion are not applied");
    if (referenced(p, n, "manifold"))
        rib_warn_once(r, "ris fractal manifold",
                      "PxrFractal: its manifold is not used; the noise is over object space");
    float layers = num(p, n, "layers", 6);
    if (!(layers >= 0 && layers <= 32)) {
        rib_warn_once(r, "ris fractal layers", "PxrFractal: layers %g taken as %d", (double)layers,
                      layers > 32 ? 32 : 0);
        layers = layers > 32 ? 32 : 0;
    }
    RayesParam q[2] = {{"octaves", RAYES_PARAM_FLOAT, {layers, 0, 0}, NULL},
                       {"roughness", RAYES_PARAM_FLOAT, {omega, 0, 0}, NULL}};
    /* texture space = frequency (object space + shift): M S(1/f) T(-shift) */
    float M[16], inv = f != 0.0f && isfinite(f) ? 1.0f / f : 1.0f;
    const float shift[3] = {12.9898f * var, 78.233f * var, 37.719f * var};
    memcpy(M, r->a.M, sizeof M);
    for (int row = 0; row < 3; row++) {
        for (int c = 0; c < 3; c++)
            M[4 * row + c] *= inv;
        for (int c = 0; c < 3; c++)
            M[4 * row + 3] -= M[4 * row + c] * shift[c];
    }
    return send_internal(r, num(p, n, "turbulent", 0) != 0 ? "wrinkled" : "fbm", q, 2, M, fbm);
}

/* A Pattern of RenderMan's classes that rayes translates: 1 with a new
 * record of the rayes pattern in *sh (its class in (*sh)->name); 2 for a
 * PxrManifold2D, kept for the patterns that reference it (nothing to
 * send); 0 for a class it does not translate (or a texture without a
 * file); -1 on error. */
static int ris_pattern(Rib *r, const char *cls, const char *name, const Param *p, size_t n,
                       ShaderRec **sh)
{
    static const float black[3] = {0, 0, 0}, white[3] = {1, 1, 1}, half[3] = {.5f, .5f, .5f};
    Out o = {.n = 0};
    const char *type;
    *sh = NULL;
    if (strcasecmp(cls, "PxrManifold2D") == 0)
        return keep_manifold(r, name, p, n) == 0 ? 2 : -1;
    if (strcasecmp(cls, "PxrBump") == 0)
        return keep_bump(r, name, p, n) == 0 ? 2 : -1;
    if (strcasecmp(cls, "PxrFractal") == 0) {
        char fbm[160];
        if (fractal_noise(r, p, n, fbm) != 0)
            return -1;
        if (!fbm[0])
            return 0;
        type = "mix"; /* RenderMan's fractal lies in [0, 1]: 0.5 + amplitude fbm / 2 */
        o.n = affine_params(0.5f, 0.5f * num(p, n, "amplitude", 1), fbm, o.p);
        snprintf(o.pattern[2], sizeof o.pattern[2], "%s", fbm);
        o.p[2].string = o.pattern[2];
    } else if (strcasecmp(cls, "PxrDispTransform") == 0) {
        char buf[160];
        const char *src = float_ref(r, p, n, "dispScalar", buf);
        if (!src || num(p, n, "dispType", 1) != 1)
            return 0; /* a constant, or a vector: not built */
        snprintf(o.pattern[2], sizeof o.pattern[2], "%s", src);
        type = "mix";
        float h = num(p, n, "dispHeight", 1), d = num(p, n, "dispDepth", 1);
        float c = num(p, n, "dispCenter", 0.5f), mode = num(p, n, "dispRemapMode", 0);
        /* none: v h; centred: (v - c) h; depth and height: from -d at 0 to h
         * at 1 (RenderMan's spline through them, here a line) */
        o.n = mode == 1   ? affine_params(-h * c, h, o.pattern[2], o.p)
              : mode == 2 ? affine_params(-d, h + d, o.pattern[2], o.p)
                          : affine_params(0, h, o.pattern[2], o.p);
        if (mode == 1 && d != h)
            rib_warn_once(r, "ris disp depth",
                          "PxrDispTransform: dispDepth is taken as dispHeight (one scale "
                          "for both sides)");
        const char *space = string(p, n, "dispScaleSpace");
        if (space && strcmp(space, "object") != 0)
            rib_warn_once(r, "ris disp space",
                          "PxrDispTransform: dispScaleSpace \"%s\" is read as object space", space);
    } else if (strcasecmp(cls, "PxrTexture") == 0) {
        const char *file = string(p, n, "filename");
        if (!file || !file[0])
            return 0;
        type = "imagemap";
        out_string(&o, "filename", rib_texture_source(r, file));
        /* texels as they are, unless linearize asks for sRGB's inverse */
        out_string(&o, "encoding", num(p, n, "linearize", 0) != 0 ? "sRGB" : "linear");
        placement(r, p, n, &o);
    } else if (strcasecmp(cls, "PxrNormalMap") == 0) {
        /* a tangent-space normal map (rgb 2 n - 1, green along t), for
         * the Bxdf's bumpNormal: rayes' "normalmap" */
        const char *file = string(p, n, "filename");
        if (!file || !file[0])
            return 0;
        type = "imagemap";
        out_string(&o, "filename", rib_texture_source(r, file));
        out_string(&o, "encoding", "linear");
        placement(r, p, n, &o);
        if (num(p, n, "bumpScale", 1) != 1 || num(p, n, "flipX", 0) != 0 ||
            num(p, n, "flipY", 0) != 0 || num(p, n, "invertBump", 0) != 0)
            rib_warn_once(r, "ris normal map",
                          "PxrNormalMap: bumpScale, flipX, flipY and invertBump are not applied");
    } else if (strcasecmp(cls, "PxrChecker") == 0) {
        /* one check per unit of the manifold's s and t, colorA's where
         * both floors' sum is even */
        type = "checkerboard";
        out_colour_of(r, &o, cls, p, n, "colorA", "tex1", white, 1);
        out_colour_of(r, &o, cls, p, n, "colorB", "tex2", black, 1);
        if (num(p, n, "mode", 0) != 0 || num(p, n, "dimensions", 2) == 3)
            out_float(&o, "dimension", 3);
        placement(r, p, n, &o);
    } else if (strcasecmp(cls, "PxrExposure") == 0) {
        type = "scale"; /* inputRGB 2^stops */
        float gain = exp2f(num(p, n, "stops", 0));
        float g[3] = {gain, gain, gain};
        out_colour_of(r, &o, cls, p, n, "inputRGB", "tex", white, 1);
        out_color(&o, "scale", g);
    } else if (strcasecmp(cls, "PxrMix") == 0) {
        type = "mix"; /* (1 - mix) color1 + mix color2 */
        out_colour_of(r, &o, cls, p, n, "color1", "tex1", black, 1);
        out_colour_of(r, &o, cls, p, n, "color2", "tex2", white, 1);
        out_colour_of(r, &o, cls, p, n, "mix", "amount", half, 1);
    } else {
        return 0;
    }
    *sh = rib_shader_rec(r, type, o.p, o.n);
    if (!*sh)
        return -1;
    (*sh)->channels = strcmp(type, "imagemap") == 0;
    return 1;
}

/* ------------------------------------------------------------ lights */

/* The area the transform M gives a unit square of z = 0 (a disk's and a
 * sphere's scale their unit ones' alike, in the plane's two directions). */
static float plane_scale(const float M[16])
{
    float x[3] = {M[0], M[4], M[8]}, y[3] = {M[1], M[5], M[9]}; /* columns: the axes */
    float cx = x[1] * y[2] - x[2] * y[1], cy = x[2] * y[0] - x[0] * y[2],
          cz = x[0] * y[1] - x[1] * y[0];
    return sqrtf(cx * cx + cy * cy + cz * cz);
}

/* The solid angle of a disk of angular diameter deg degrees: 2 pi (1 -
 * cos h) for the half angle h, as 4 pi sin^2(h / 2) (the sun's 1 - cos
 * is too near 0 for a float's cosine). */
static float disk_solid_angle(float deg)
{
    float s = sinf(0.25f * fminf(fmaxf(deg, 0.0f), 360.0f) * (float)(M_PI / 180.0));
    return 4.0f * (float)M_PI * s * s;
}

/* A RenderMan 19-21 light is a thing of the scene, not of the attribute
 * block it is placed in (area lights light everything, docs/rib.md): on for the geometry after the block ends too
 * (Illuminate still turns it off). */
static void on_everywhere(Rib *r, const Light *l)
{
    size_t k = (size_t)(l - r->lights);
    for (size_t d = r->world_depth; d < r->depth; d++) /* the world's blocks only */
        r->stack[d].a.on[k / 8] |= (unsigned char)(1u << (k % 8));
}

/* Light l's mapname, map (found as textures are), or one warning saying
 * what the light is without it. */
static void map_param(Rib *r, Light *l, const char *cls, const char *map, const char *without)
{
    map = rib_texture_source(r, map);
    if (rib_texture_found(r, map))
        rib_light_param(l, "mapname", RAYES_PARAM_STRING, NULL, map);
    else
        rib_warn_once(r, "light map",
                      "light \"%s\": map \"%.200s\" is not found as given nor on the texture "
                      "search path; %s",
                      cls, map, without);
}

/* Adds light cls (a RenderMan 21 Light, or the shape of a RenderMan 19-20
 * area light: "PxrRectLight", "PxrDiskLight", "PxrSphereLight",
 * "PxrDistantLight", "PxrDomeLight") of radiance L; 1 if made, 0 if rayes
 * has no such light (warned), -1 on error. */
static int make_light(Rib *r, const char *handle, const char *cls, const float L[3],
                      int normalize, float angle, const char *map)
{
    if (r->rec || r->in_object) {
        rib_warn_once(r, "light in object", "lights inside ObjectBegin are ignored");
        return 0;
    }
    int rect = strcasecmp(cls, "PxrRectLight") == 0, disk = strcasecmp(cls, "PxrDiskLight") == 0;
    int sphere = strcasecmp(cls, "PxrSphereLight") == 0,
        dist = strcasecmp(cls, "PxrDistantLight") == 0;
    int dome = strcasecmp(cls, "PxrDomeLight") == 0;
    int tube = strcasecmp(cls, "PxrCylinderLight") == 0; /* along x, 1 long, 1 across */
    if (!rect && !disk && !sphere && !dist && !dome && !tube) {
        char key[128];
        snprintf(key, sizeof key, "light %.100s", cls);
        rib_warn_once(
            r, key,
            "light \"%s\" is not one rayes translates (PxrRectLight, PxrDiskLight, "
            "PxrSphereLight, PxrCylinderLight, PxrDistantLight, PxrDomeLight, PxrEnvDayLight, "
            "PxrMeshLight); "
            "the light is skipped",
            cls);
        return 0;
    }
    float scale = 1; /* normalize: radiance over the area of the shape as placed */
    if (normalize && (rect || disk || sphere || tube)) {
        float area = plane_scale(r->a.M) * (rect ? 1.0f : (float)M_PI * 0.25f);
        if (sphere || tube) /* a uniform scale s: 4 pi (s / 2)^2, or pi s s (its side) */
            area = plane_scale(r->a.M) * (float)M_PI;
        scale = area > 0 ? 1.0f / area : 1.0f;
    } else if (dist && !normalize) {
        scale = disk_solid_angle(angle); /* irradiance of a disk of that radiance */
    }
    float I = fmaxf(fmaxf(L[0], L[1]), L[2]) * scale, c[3];
    for (int k = 0; k < 3; k++)
        c[k] = I > 0 ? L[k] * scale / I : 0;
    const char *type = dist ? "distantlight" : dome ? "environmentlight" : "arealight";
    Light *l = rib_new_light(r, handle, type);
    if (!l)
        return -1;
    if ((rect || disk) && rib_mat_det3(r->a.M) < 0) {
        /* a mirroring transform (exporters write them: RenderMan for
         * Blender's and hdPrman's lights all have one) turns the shape's
         * winding, not the side RenderMan emits from: mirror it back in
         * y, which leaves a unit square or disk where it was */
        for (int c = 1; c < 16; c += 4) { /* column 1: the image of y */
            l->M[c] = -l->M[c];
            for (int t = 0; t < l->n_motion; t++)
                l->motion_M[t][c] = -l->motion_M[t][c];
        }
    }
    float v[3] = {I, 0, 0};
    rib_light_param(l, "intensity", RAYES_PARAM_FLOAT, v, NULL);
    rib_light_param(l, "lightcolor", RAYES_PARAM_COLOR, c, NULL);
    if (rect || disk || sphere || tube) {
        rib_light_param(l, "shape", RAYES_PARAM_STRING, NULL,
                        rect     ? "quad"
                        : disk   ? "disk"
                        : sphere ? "sphere"
                                 : "cylinder");
        float half[3] = {0.5f, 0, 0};
        if (!rect)
            rib_light_param(l, "radius", RAYES_PARAM_FLOAT, half, NULL);
        if (rect && map && map[0]) /* lightColorMap: the image over the square */
            map_param(r, l, cls, map, "the light is even");
    } else if (dist) {
        float from[3] = {0, 0, 0}, to[3] = {0, 0, 1};
        rib_light_param(l, "from", RAYES_PARAM_COLOR, from, NULL);
        rib_light_param(l, "to", RAYES_PARAM_COLOR, to, NULL);
    } else if (map && map[0]) {
        map_param(r, l, cls, map, "a constant environment");
    }
    on_everywhere(r, l);
    return 1;
}

/* A RenderMan 21 light's controls rayes has: enableShadows 0 casts no
 * shadows, a diffuse or specular multiplier of 0 none of that light; what
 * it has not (a cone, near-distance falloff, focus, shadow colour, other
 * multipliers) is said once. */
/* Multiplies light l's colour by gain (a LightFilter's): its lightcolor,
 * or a lightcolor of the gain when it has none. */
static void scale_light(Light *l, const float gain[3])
{
    for (size_t k = 0; k < l->n; k++)
        if (l->params[k].name && strcmp(l->params[k].name, "lightcolor") == 0) {
            for (int c = 0; c < 3; c++)
                l->params[k].value[c] *= gain[c];
            return;
        }
    rib_light_param(l, "lightcolor", RAYES_PARAM_COLOR, gain, NULL);
}

static void light_controls(Rib *r, const char *cls, Light *l, const Param *p, size_t n)
{
    static const float zero[3] = {0, 0, 0}, one[3] = {1, 1, 1};
    if (num(p, n, "enableShadows", 1) == 0)
        rib_light_param(l, "shadows", RAYES_PARAM_FLOAT, zero, NULL);
    float diffuse = num(p, n, "diffuse", 1), specular = num(p, n, "specular", 1);
    if (diffuse == 0)
        rib_light_param(l, "__nondiffuse", RAYES_PARAM_FLOAT, one, NULL);
    if (specular == 0)
        rib_light_param(l, "__nonspecular", RAYES_PARAM_FLOAT, one, NULL);
    float shadow[3];
    color(p, n, "shadowColor", zero, shadow);
    /* a rect or disk light's cone: its emission within coneAngle of its
     * normal, softened over coneSoftness of it (rayes' arealight cone) */
    float cone = num(p, n, "coneAngle", 90);
    int shaped =
        cone < 90 && (strcasecmp(cls, "PxrRectLight") == 0 || strcasecmp(cls, "PxrDiskLight") == 0);
    if (shaped && cone > 0) {
        float c[3] = {cone, 0, 0},
              soft[3] = {fminf(fmaxf(num(p, n, "coneSoftness", 0), 0), 1), 0, 0};
        rib_light_param(l, "cone", RAYES_PARAM_FLOAT, c, NULL);
        rib_light_param(l, "conesoftness", RAYES_PARAM_FLOAT, soft, NULL);
    }
    const char *unbuilt = (diffuse != 0 && diffuse != 1) || (specular != 0 && specular != 1)
                              ? "diffuse and specular multipliers other than 0 and 1"
                          : cone < 90 && !(shaped && cone > 0)    ? "coneAngle (a cone)"
                          : num(p, n, "intensityNearDist", 0) > 0 ? "intensityNearDist"
                          : num(p, n, "emissionFocus", 0) != 0    ? "emissionFocus"
                          : shadow[0] != 0 || shadow[1] != 0 || shadow[2] != 0 ? "shadowColor"
                                                                               : NULL;
    if (unbuilt) {
        char key[160];
        snprintf(key, sizeof key, "ris light %.60s %.60s", cls, unbuilt);
        rib_warn_once(r, key, "light \"%s\": %s not built; the light shines as without it", cls,
                      unbuilt);
    }
}

/* Turns a light's frame by Rx(90) (its y column becomes its z, its z
 * minus its y): light-space +y then lies where +z did. */
static void zenith_to_y(Light *l)
{
    for (int t = -1; t < l->n_motion; t++) {
        float *M = t < 0 ? l->M : l->motion_M[t];
        for (int row = 0; row < 16; row += 4) {
            float y = M[row + 1];
            M[row + 1] = M[row + 2], M[row + 2] = -y;
        }
    }
}

/* PxrEnvDayLight (RenderMan 21's; PxrStdEnvDayLight is RenderMan 20's):
 * a clear sky, an environmentlight of rayes' "sky" (util/sky.h:
 * Preetham et al.'s, haziness its turbidity, skyTint its colour, the
 * ground below the horizon of groundColor), and its sun, a distant light
 * of Hottel's radiance (sunTint) over a disk of sunSize x 0.53 degrees,
 * both in cd/m^2 times intensity 2^exposure 1e-5, as PRMan scales them.
 * The sun's direction is sunDirection (+y the zenith), or, when a month is
 * given, its place at that hour, day and month seen from latitude and
 * longitude (+z north, +x east). Returns 1, 0 (skipped) or -1. */
static int day_light(Rib *r, const char *handle, const char *cls, const Param *p, size_t n)
{
    if (r->rec || r->in_object) {
        rib_warn_once(r, "light in object", "lights inside ObjectBegin are ignored");
        return 0;
    }
    static const float up[3] = {0, 1, 0}, one[3] = {1, 1, 1}, grey[3] = {.18f, .18f, .18f};
    float gain = num(p, n, "intensity", strcasecmp(cls, "PxrStdEnvDayLight") == 0 ? 1e-5f : 1) *
                 exp2f(fminf(fmaxf(num(p, n, "exposure", 0), -126), 126));
    if (strcasecmp(cls, "PxrEnvDayLight") == 0)
        gain *= 1e-5f; /* RenderMan 21: the model's cd/m^2, 100 000 times too bright, scaled */
    float dir[3], sky_tint[3], sun_tint[3], ground[3];
    color(p, n, value(p, n, "sunDirection", 3) ? "sunDirection" : "direction", up, dir);
    /* RenderMan 21's sky has its zenith at +z, RenderMan 20's and 22's at
     * +y: the zenith is the one of them the transform turns nearer the
     * world's +y (RenderMan for Maya 21 writes a Rotate -90 1 0 0 before
     * it), and a +z zenith is turned to rayes' +y (the directions by Rx(-90),
     * the frame's columns by Rx(90)) */
    const float *M = r->a.M;
    float ly = hypotf(hypotf(M[1], M[5]), M[9]), lz = hypotf(hypotf(M[2], M[6]), M[10]);
    int zup = lz > 0 && ly > 0 && M[6] / lz > M[5] / ly;
    if (zup) {
        float y = dir[1];
        dir[1] = dir[2], dir[2] = -y;
    }
    int month = (int)num(p, n, "month", 0); /* the heliodon's: +y already the zenith */
    if (month >= 1 && month <= 12)
        sky_sun_direction(month, (int)num(p, n, "day", 1), num(p, n, "hour", 14.633333f),
                          num(p, n, "zone", -8), num(p, n, "latitude", 37.7749f),
                          num(p, n, "longitude", -122.4194f), dir);
    color(p, n, "skyTint", one, sky_tint);
    color(p, n, "sunTint", one, sun_tint);
    color(p, n, "groundColor", grey, ground);
    float haziness = fminf(fmaxf(num(p, n, "haziness", 2), 1.7f), 10.0f);
    Light *l = rib_new_light(r, handle, "environmentlight");
    if (!l)
        return -1;
    if (zup)
        zenith_to_y(l);
    float I = gain * max3(sky_tint), c[3], v[3] = {I, 0, 0};
    for (int k = 0; k < 3; k++)
        c[k] = I > 0 ? gain * sky_tint[k] / I : 0;
    rib_light_param(l, "intensity", RAYES_PARAM_FLOAT, v, NULL);
    rib_light_param(l, "lightcolor", RAYES_PARAM_COLOR, c, NULL);
    rib_light_param(l, "mapping", RAYES_PARAM_STRING, NULL, "sky");
    rib_light_param(l, "sundirection", RAYES_PARAM_COLOR, dir, NULL);
    float hz[3] = {haziness, 0, 0};
    rib_light_param(l, "haziness", RAYES_PARAM_FLOAT, hz, NULL);
    rib_light_param(l, "groundcolor", RAYES_PARAM_COLOR, ground, NULL);
    on_everywhere(r, l);
    l->own_visibility = 1; /* the sky: the background, unless hidden */
    l->visibility = r->a.visibility;
    Sky sky;
    sky_init(&sky, dir, haziness);
    float sun[3];
    sky_sun_radiance(&sky, sun);
    if (dir[1] <= 0 || max3(sun) <= 0)
        return 1; /* set: the sky of dusk alone */
    float L[3];
    for (int k = 0; k < 3; k++)
        L[k] = sun[k] * sun_tint[k] * gain;
    int e = make_light(r, handle, "PxrDistantLight", L, 0,
                       0.53f * fmaxf(num(p, n, "sunSize", 1), 0.0f), NULL);
    if (e > 0) { /* it shines from the sun, along -dir in the light's space */
        float to[3] = {-sky.sun[0], -sky.sun[1], -sky.sun[2]};
        rib_light_param(&r->lights[r->n_lights - 1], "to", RAYES_PARAM_COLOR, to, NULL);
        if (zup)
            zenith_to_y(&r->lights[r->n_lights - 1]);
    }
    return e;
}

/* Light "class" "handle" params (RenderMan 21 and later). */
/* PxrMeshLight: the geometry that follows in its attribute block emits
 * radiance L from its front, as under a classic AreaLightSource (a few
 * quads as quad lights, other meshes as one mesh light, quadrics as
 * theirs); areaNormalize divides by each shape's area. Its handle is an
 * area light's (Illuminate knows it; area lights light everything). */
static int mesh_light(Rib *r, const char *handle, const float L[3], int normalize)
{
    if (r->in_object || r->rec) {
        rib_warn_once(r, "light in object", "lights inside ObjectBegin are ignored");
        return 0;
    }
    if (rib_add_area_handle(r, handle) != 0)
        return -1;
    memcpy(r->a.area_L, L, sizeof r->a.area_L);
    r->a.area_normalize = normalize;
    r->a.area_point_units = 0;
    r->a.area_map[0] = '\0';
    r->a.area_texture[0] = '\0';
    r->a.area_unseen = 0;
    r->a.area_twosided = 0;
    r->a.area = 1;
    r->lit = 1;
    return 0;
}

/* LightFilter "class" "handle" params (RenderMan 21 and later): bound
 * to the lights declared after it in its attribute block, as a Bxdf is to
 * geometry (the last one wins). PxrIntMultLightFilter scales them by
 * intensity times 2^exposure (invert: by its inverse), tinted by
 * colorTint; the filters that shape or block light (barn doors, blockers,
 * rods, gobos, cookies, ramps) are not built: the lights shine unfiltered,
 * one warning naming the class. */
static int h_light_filter(Rib *r, const Args *a)
{
    r->ris = 1;
    Param *p;
    size_t n;
    const char *cls = class_and_params(r, a, "a light filter class", &p, &n);
    if (!cls)
        return -1;
    if (strcasecmp(cls, "PxrIntMultLightFilter") == 0) {
        static const float one[3] = {1, 1, 1};
        float g =
            num(p, n, "intensity", 1) * exp2f(fminf(fmaxf(num(p, n, "exposure", 0), -126), 126));
        if (num(p, n, "invert", 0) != 0)
            g = g != 0.0f ? 1.0f / g : 0.0f;
        float tint[3];
        color(p, n, "colorTint", one, tint);
        for (int k = 0; k < 3; k++)
            r->a.light_filter_gain[k] = g * tint[k];
        r->a.light_filter = 1;
        if (num(p, n, "saturation", 1) != 1)
            rib_warn_once(r, "light filter saturation",
                          "LightFilter \"%s\": saturation is not applied", cls);
    } else {
        r->a.light_filter = 0; /* the last one bound wins */
        char key[128];
        snprintf(key, sizeof key, "light filter %.100s", cls);
        rib_warn_once(r, key,
                      "LightFilter \"%s\" is not built (of RenderMan's filters only "
                      "PxrIntMultLightFilter is): the lights shine unfiltered",
                      cls);
    }
    free(p);
    return 0;
}

/* EnableLightFilter "light" "filter" on: filters are on by default; one
 * turned off for the primitives after it is not (one warning). */
static int h_enable_light_filter(Rib *r, const Args *a)
{
    size_t i = 0;
    char light[RIB_MAX_HANDLE], filter[RIB_MAX_HANDLE];
    float on;
    if (rib_get_handle(r, a, &i, light) != 0 || rib_get_handle(r, a, &i, filter) != 0 ||
        rib_get_floats(r, a, &i, &on, 1, "0 or 1") != 0)
        return -1;
    if (on == 0)
        rib_warn_once(r, "EnableLightFilter",
                      "EnableLightFilter: turning a filter off for some primitives is not "
                      "built; ignored");
    return 0;
}

static int h_light(Rib *r, const Args *a)
{
    r->ris = 1;
    size_t i = 0;
    const char *cls = rib_get_string(r, a, &i, "a light class");
    char handle[RIB_MAX_HANDLE];
    if (!cls || rib_get_handle(r, a, &i, handle) != 0)
        return -1;
    Param *p;
    size_t n;
    if (rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    static const float one[3] = {1, 1, 1};
    float L[3], I = num(p, n, "intensity", strcasecmp(cls, "PxrDistantLight") == 0 ? 50000 : 1);
    I *= exp2f(fminf(fmaxf(num(p, n, "exposure", 0), -126), 126));
    color(p, n, "lightColor", one, L);
    for (int k = 0; k < 3; k++)
        L[k] *= I;
    if (num(p, n, "enableTemperature", 0) != 0) { /* a tint; 6500 K white */
        float tint[3];
        colour_temperature(num(p, n, "temperature", 6500), tint);
        for (int k = 0; k < 3; k++)
            L[k] *= tint[k];
    }
    if (r->a.light_filter) /* RenderMan binds a filter to the lights after it */
        for (int k = 0; k < 3; k++)
            L[k] *= r->a.light_filter_gain[k];
    if (strcasecmp(cls, "PxrMeshLight") == 0) {
        int e = mesh_light(r, handle, L, num(p, n, "areaNormalize", 0) != 0);
        free(p);
        return e;
    }
    const char *map = string(p, n, "lightColorMap");
    int day = strcasecmp(cls, "PxrEnvDayLight") == 0 || strcasecmp(cls, "PxrStdEnvDayLight") == 0;
    size_t before = r->n_lights;
    int e = day ? day_light(r, handle, cls, p, n)
                : make_light(r, handle, cls, L, num(p, n, "areaNormalize", 0) != 0,
                             num(p, n, "angleExtent", 0.53f), map);
    if (day) { /* the sky and its sun take the light's controls (and filter) */
        for (size_t k = before; e > 0 && k < r->n_lights; k++) {
            light_controls(r, cls, &r->lights[k], p, n);
            if (r->a.light_filter)
                scale_light(&r->lights[k], r->a.light_filter_gain);
        }
        free(p);
        return e < 0 ? -1 : 0;
    }
    if (e > 0)
        light_controls(r, cls, &r->lights[r->n_lights - 1], p, n);
    free(p);
    if (e > 0 &&
        (strcasecmp(cls, "PxrRectLight") == 0 || strcasecmp(cls, "PxrDiskLight") == 0 ||
         strcasecmp(cls, "PxrSphereLight") == 0 || strcasecmp(cls, "PxrCylinderLight") == 0)) {
        /* RenderMan 21's lights are not seen by the camera unless said */
        Light *l = &r->lights[r->n_lights - 1];
        l->own_visibility = 1;
        l->visibility = r->a.camera_said ? r->a.visibility : r->a.visibility & ~RAYES_RAY_CAMERA;
    } else if (e > 0 && strcasecmp(cls, "PxrDomeLight") == 0) {
        /* the dome: the background the camera sees unless the attributes
         * hide it ("visibility" "camera" 0) */
        Light *l = &r->lights[r->n_lights - 1];
        l->own_visibility = 1;
        l->visibility = r->a.visibility;
    }
    return e < 0 ? -1 : 0;
}

int rib_ris_geometry_light(Rib *r, const char *name)
{
    static const char *const shapes[][2] = {
        {"rectlight", "PxrRectLight"},       {"disklight", "PxrDiskLight"},
        {"spherelight", "PxrSphereLight"},   {"cylinderlight", "PxrCylinderLight"},
        {"distantlight", "PxrDistantLight"}, {"envsphere", "PxrDomeLight"}};
    const char *cls = NULL;
    for (size_t k = 0; k < sizeof shapes / sizeof shapes[0]; k++)
        if (strcmp(name, shapes[k][0]) == 0)
            cls = shapes[k][1];
    if (!cls)
        return 0;
    if (!r->a.area) {
        char key[128];
        snprintf(key, sizeof key, "geometry %s", name);
        rib_warn_once(r, key, "Geometry \"%s\" outside AreaLightSource: skipped", name);
        return 1;
    }
    if (!r->in_world)
        return 1;
    char handle[RIB_MAX_HANDLE];
    snprintf(handle, sizeof handle, "@area%zu", r->n_lights);
    int e = make_light(r, handle, cls, r->a.area_L, r->a.area_normalize, 0.53f, r->a.area_map);
    if (e > 0) { /* seen as the attributes say, and the envsphere's primary visibility */
        Light *l = &r->lights[r->n_lights - 1];
        l->own_visibility = 1;
        l->visibility = r->a.visibility & (r->a.area_unseen ? ~(uint32_t)RAYES_RAY_CAMERA : ~0u);
    }
    return e < 0 ? -1 : 1;
}

/* ------------------------------------------------------------ Displace */

/* RenderMan 21's Displace (PxrDisplace and its pattern network): not
 * built; the surfaces are not displaced, with one warning. */
/* RIS's Displace: PxrDisplace's scalar displacement (dispAmount times
 * dispScalar along N, object space) as the built-in "displace" of the
 * surfaces that follow; vector displacement and other classes are not
 * built (no displacement, one warning). */
static int ris_displace(Rib *r, const char *cls, const Param *p, size_t n)
{
    r->a.displacement = NULL;
    if (strcasecmp(cls, "PxrDisplace") != 0) {
        rib_warn_once(r, "ris displace",
                      "Displace \"%s\": only PxrDisplace's scalar displacement is built; the "
                      "surfaces that follow are not displaced",
                      cls);
        return 0;
    }
    if (referenced(p, n, "dispVector") || referenced(p, n, "modelDispVector"))
        rib_warn_once(r, "ris displace vector",
                      "PxrDisplace: vector displacement (dispVector, modelDispVector) is not "
                      "built; only dispScalar displaces");
    if (num(p, n, "enabled", 1) == 0)
        return 0;
    float amount = num(p, n, "dispAmount", 1) * object_scale(r->a.M);
    char buf[160], height[160];
    const char *src = float_ref(r, p, n, "dispScalar", buf);
    RayesParam q[3];
    if (src) {
        size_t nq = affine_params(0, amount, src, q);
        if (send_internal(r, "mix", q, nq, r->a.M, height) != 0)
            return -1;
        if (!height[0])
            return 0;
        q[0] = (RayesParam){"amount", RAYES_PARAM_PATTERN, {0, 0, 0}, height};
    } else {
        float v = num(p, n, "dispScalar", 0) * amount;
        if (v == 0.0f)
            return 0;
        q[0] = (RayesParam){"amount", RAYES_PARAM_FLOAT, {v, 0, 0}, NULL};
    }
    ShaderRec *sh = rib_shader_rec(r, "displace", q, 1);
    if (!sh)
        return -1;
    r->a.displacement = sh;
    return 0;
}

static int h_displace(Rib *r, const Args *a)
{
    r->ris = 1;
    Param *p;
    size_t n;
    const char *cls = class_and_params(r, a, "a displacement class", &p, &n);
    if (!cls)
        return -1;
    int e = ris_displace(r, cls, p, n);
    free(p);
    return e;
}

/* ------------------------------------------------------------ Integrator */

/* The most diffuse bounces a maxPathLength gives (as pbrt's maxdepth). */
enum { RIS_DIFFUSE_BOUNCES = 8 };

static int h_integrator(Rib *r, const Args *a)
{
    r->ris = 1;
    r->integrator = 1;
    Param *p;
    size_t n;
    const char *cls = class_and_params(r, a, "an integrator class", &p, &n);
    if (!cls)
        return -1;
    /* maxPathLength counts the camera ray's segment: N - 1 diffuse
     * bounces (each cached apart, so capped as pbrt's maxdepth is) */
    float len = num(p, n, "maxPathLength", 10);
    free(p);
    if (strcasecmp(cls, "PxrDirectLighting") == 0) {
        r->settings->bounces = 0;
        return 0;
    }
    if (!(len >= 0 && len <= 1e6))
        return rib_error(r, "\"%s\": expected maxPathLength >= 0", cls);
    int bounces = len >= 1 ? (int)len - 1 : 0;
    r->settings->bounces = bounces < RIS_DIFFUSE_BOUNCES ? bounces : RIS_DIFFUSE_BOUNCES;
    r->settings->specular_depth = (int)len;
    if (bounces > RIS_DIFFUSE_BOUNCES && !(r->opt && r->opt->bounces_given))
        rib_warn_once(r, "ris bounces",
                      "Integrator \"%s\" maxPathLength %g: %d diffuse bounces, not %d (each "
                      "costs about as much as the first; --bounces N for more)",
                      cls, len, RIS_DIFFUSE_BOUNCES, bounces);
    return 0;
}

/* Pattern "class" "name" params: RenderMan's classes rayes translates,
 * else rib_pattern_define's (rayes' own classes, or a stand-in). */
static int h_pattern(Rib *r, const Args *a)
{
    size_t i = 0;
    const char *type = rib_get_string(r, a, &i, "a pattern class");
    const char *name = type ? rib_get_string(r, a, &i, "a pattern name") : NULL;
    Param *p;
    size_t n;
    if (!name || rib_get_params(r, a, i, &p, &n) != 0)
        return -1;
    ShaderRec *sh = NULL;
    int ris = ris_pattern(r, type, name, p, n, &sh);
    if (ris < 0 || ris == 2) {
        free(p);
        return ris < 0 ? -1 : 0;
    }
    return rib_pattern_define(r, type, name, p, n, sh);
}

const RibRequest rib_ris_requests[] = {
    {"Pattern", h_pattern},
    {"Bxdf", h_bxdf},
    {"Light", h_light},
    {"Integrator", h_integrator},
    {"Displace", h_displace},
    {"LightFilter", h_light_filter},
    {"EnableLightFilter", h_enable_light_filter},
    {NULL, NULL},
};
