/*
 * shade/builtin_bsdf.c — RenderMan's metal, shinymetal and glass, and the
 * physically based family the pbrt reader maps to: diffuse, conductor,
 * dielectric and coateddiffuse (DESIGN.md "Built-in BSDFs and shaders").
 *
 * Mirror reflection comes from the indirect_specular service and
 * refraction from indirect_refraction, whose rays see area lights; glossy
 * reflection of the physically based shaders (conductor, dielectric,
 * coateddiffuse) from the microfacet service (GGX, as pbrt's and Cycles's
 * rough surfaces), which adds the lights by multiple importance sampling
 * against the same lobe, so small bright lights reflect without speckle
 * and nothing is counted twice.
 * RenderMan's metal, shinymetal and glass keep indirect_specular's lobe
 * and their classic specular() highlight, as their definitions say. Past the
 * renderer's branch depth, glass and dielectric follow one of reflection
 * and refraction (fresnel_split), so a path through nested glass is a
 * path, not a tree.
 *
 * diffuselighting is each shader's view-independent part: ambient and
 * diffuse terms only (black for glass, dielectric and conductor). Scratch
 * arrays live on the stack, SHADE_CHUNK points at a time.
 */
#include "shade/builtin.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "shade/bsdf.h"
#include "shade/shade.h"
#include "util/log.h"

typedef float Rgb[3];

static float cs(const RayesShadeCtx *ctx, size_t i, int c)
{
    return ctx->Cs ? ctx->Cs[i][c] : 1.0f;
}

/* Oi = Os, and Ci premultiplied by it (RenderMan's Ci *= Oi: the renderer
 * composites Ci + (1 - Oi) behind). */
static void set_opacity(const RayesShadeCtx *ctx, RayesShadeOutputs *out)
{
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Oi[i][c] = ctx->Os ? ctx->Os[i][c] : 1.0f;
            out->Ci[i][c] *= out->Oi[i][c];
        }
}

/* A shader's chunk function and parameters, for shade_chunks. */
typedef struct MappedChunk {
    ShadeChunkFn fn;
    const void *params;
} MappedChunk;

/* One slice: its normals bent by the normal map, if one is bound, then
 * the shader's function. */
static void mapped_chunk(const RayesShaderServices *sv, const RayesShadeCtx *sub,
                         const void *params, RayesShadeOutputs *out)
{
    const MappedChunk *m = params;
    RayesShadeCtx ctx = *sub;
    Rgb mapped[SHADE_CHUNK];
    if (shade_param_bound(&ctx, "normalmap")) {
        shade_normal_map(sv, &ctx, mapped);
        ctx.N = (const float(*)[3])mapped;
    }
    m->fn(sv, &ctx, m->params, out);
}

/* Runs fn on SHADE_CHUNK-point slices; Irradiance, if asked for, is left
 * to fn (zeroed first). */
static void by_chunks(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                      RayesShadeOutputs *out, ShadeChunkFn fn)
{
    if (out->Irradiance)
        memset(out->Irradiance, 0, ctx->n_points * sizeof *out->Irradiance);
    const MappedChunk m = {fn, params};
    shade_chunks(sv, ctx, &m, out, mapped_chunk);
    set_opacity(ctx, out);
}

static void ambient(const RayesShaderServices *sv, const RayesShadeCtx *ctx, Rgb *out)
{
    if (sv->ambient)
        sv->ambient(sv, ctx, out);
    else
        memset(out, 0, ctx->n_points * sizeof *out);
}

/* dd + id + ambient: what a Lambertian surface of albedo 1 reflects. */
static void diffuse_light(const RayesShaderServices *sv, const RayesShadeCtx *ctx, Rgb *E,
                          RayesShadeOutputs *out)
{
    Rgb dd[SHADE_CHUNK], id[SHADE_CHUNK], am[SHADE_CHUNK];
    sv->direct_lighting(sv, ctx, 0, NULL, NULL, dd, NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    ambient(sv, ctx, am);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            E[i][c] = dd[i][c] + id[i][c] + am[i][c];
    if (out->Irradiance)
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++)
                out->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
}

static Vec3 ld(const float p[3])
{
    return v3(p[0], p[1], p[2]);
}

/* cos of the angle between N and the direction to the viewer, kept away
 * from 0 (interpolated normals may turn slightly away). */
static float cos_view(const RayesShadeCtx *ctx, size_t i)
{
    return fmaxf(-v3_dot(ld(ctx->I[i]), ld(ctx->N[i])), 1e-4f);
}

static void mirror_dirs(const RayesShadeCtx *ctx, Rgb *dir)
{
    for (size_t i = 0; i < ctx->n_points; i++) {
        Vec3 r = bsdf_reflect(v3_neg(ld(ctx->I[i])), ld(ctx->N[i]));
        dir[i][0] = r.x, dir[i][1] = r.y, dir[i][2] = r.z;
    }
}

/* How many of the points' lobe widths (exponents or alphas) are 0
 * (mirrors). */
static size_t count_mirrors(const RayesShadeCtx *ctx, const float *width)
{
    size_t n = 0;
    for (size_t i = 0; i < ctx->n_points; i++)
        n += !(width[i] > 0.0f);
    return n;
}

/* Radiance reflected about the mirror directions: a perfect mirror where
 * exponent[i] is 0, else the mean over the Blinn-Phong lobe of that
 * exponent. */
static void reflection(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const float *exponent, Rgb *L)
{
    Rgb dir[SHADE_CHUNK];
    float rough[SHADE_CHUNK];
    mirror_dirs(ctx, dir);
    for (size_t i = 0; i < ctx->n_points; i++)
        rough[i] = exponent[i] > 0.0f ? 1.0f / exponent[i] : 0.0f;
    int mirrors = count_mirrors(ctx, exponent) == ctx->n_points;
    sv->indirect_specular(sv, ctx, (const float(*)[3])dir, mirrors ? NULL : rough, mirrors ? 1 : 0,
                          L);
}

/* Reflection of the physically based shaders: a mirror where alpha[i] is
 * 0; elsewhere the microfacet service's GGX lobe of width alpha[i], whose
 * lights come by multiple importance sampling. A renderer without it: the
 * glossy service's Blinn-Phong lobe of the same width (Walter et al.'s
 * exponent), or without that reflection's lobe, which sees lights only
 * through its rays. A chunk mixing mirrors and lobes (a textured
 * roughness reaching 0) goes point by point. */
static void glossy_reflection(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const float *alpha, Rgb *L)
{
    size_t mirrors = count_mirrors(ctx, alpha);
    float w[SHADE_CHUNK];
    if (mirrors != ctx->n_points && mirrors != 0) {
        for (size_t i = 0; i < ctx->n_points; i++) {
            RayesShadeCtx one;
            shade_ctx_slice(ctx, i, 1, &one);
            glossy_reflection(sv, &one, &alpha[i], &L[i]);
        }
    } else if (mirrors == 0 && SHADE_HAS_SERVICE(sv, microfacet)) {
        sv->microfacet(sv, ctx, alpha, 0, L);
    } else {
        for (size_t i = 0; i < ctx->n_points; i++)
            w[i] = alpha[i] > 0.0f ? bsdf_blinn_exponent_from_alpha(alpha[i]) : 0.0f;
        if (mirrors == ctx->n_points || !SHADE_HAS_SERVICE(sv, glossy)) {
            reflection(sv, ctx, w, L);
            return;
        }
        for (size_t i = 0; i < ctx->n_points; i++)
            w[i] = 1.0f / w[i]; /* the glossy service's roughness */
        sv->glossy(sv, ctx, w, 0, L);
    }
}

/* pbrt-v4's roughness (remapped: alpha = sqrt(roughness)) as the GGX
 * width; 0 for a smooth surface. */
static float alpha_of(float roughness)
{
    return roughness > 0.0f ? bsdf_alpha_from_roughness(roughness) : 0.0f;
}

/* The lobe widths of the points: the parameter "roughness" (its constant,
 * or the pattern bound to it) through alpha_of. */
static void alphas(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float roughness,
                   float *alpha)
{
    shade_param_float(sv, ctx, "roughness", roughness, alpha);
    for (size_t i = 0; i < ctx->n_points; i++)
        alpha[i] = alpha_of(alpha[i]);
}

/* ------------------------------------------------------------ metal */

typedef struct MetalParams {
    float Ka, Ks, roughness;
} MetalParams;

/* Cs (Ka ambient + Ks specular); the view-independent part is Cs Ka ambient. */
static void metal_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const void *params, RayesShadeOutputs *out)
{
    const MetalParams *p = params;
    Rgb am[SHADE_CHUNK], ds[SHADE_CHUNK];
    float rough[SHADE_CHUNK];
    ambient(sv, ctx, am);
    memset(ds, 0, sizeof ds);
    if (ctx->I) {
        for (size_t i = 0; i < ctx->n_points; i++)
            rough[i] = p->roughness;
        shade_classic_lighting(sv, ctx, rough, NULL, ds);
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * (p->Ka * am[i][c] + p->Ks * ds[i][c]);
}

static void metal_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, metal_chunk);
}

static const RayesShaderParamDesc metal_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(MetalParams, Ka), {1, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(MetalParams, Ks), {1, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(MetalParams, roughness), {0.1f, 0, 0}},
};

const RayesShaderClass shade_class_metal = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "metal",
    .params_size = sizeof(MetalParams),
    .params = metal_params,
    .n_params = sizeof metal_params / sizeof metal_params[0],
    .lighting = metal_lighting,
    .diffuselighting = metal_lighting, /* without I: the specular term is left at 0 */
};

/* ------------------------------------------------------------ shinymetal */

typedef struct ShinymetalParams {
    float Ka, Ks, Kr, roughness;
    char texturename[RAYES_SHADER_PATH_BYTES];
} ShinymetalParams;

/* The environment around the mirror directions: the lat-long map
 * texturename if it reads (s = 0.5 + atan2(x, -z) / 2 pi, t = acos(y) / pi:
 * y up, -z at the centre), else traced. */
static void environment(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const char *texturename, Rgb *env)
{
    Rgb dir[SHADE_CHUNK];
    mirror_dirs(ctx, dir);
    if (texturename[0] && sv->texture) {
        float s[SHADE_CHUNK], t[SHADE_CHUNK], zero[SHADE_CHUNK];
        for (size_t i = 0; i < ctx->n_points; i++) {
            Vec3 d = v3_normalize(ld(dir[i]));
            s[i] = 0.5f + atan2f(d.x, -d.z) * (0.5f / 3.14159265f);
            t[i] = acosf(fminf(fmaxf(d.y, -1.0f), 1.0f)) * (1.0f / 3.14159265f);
            zero[i] = 0.0f;
        }
        if (sv->texture(sv, ctx, texturename, s, t, zero, zero, env, NULL) == 0)
            return;
    }
    sv->indirect_specular(sv, ctx, (const float(*)[3])dir, NULL, 1, env);
}

static void shinymetal_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    const ShinymetalParams *p = params;
    Rgb am[SHADE_CHUNK], ds[SHADE_CHUNK], env[SHADE_CHUNK];
    float rough[SHADE_CHUNK];
    ambient(sv, ctx, am);
    memset(ds, 0, sizeof ds);
    memset(env, 0, sizeof env);
    if (ctx->I) {
        for (size_t i = 0; i < ctx->n_points; i++)
            rough[i] = p->roughness;
        shade_classic_lighting(sv, ctx, rough, NULL, ds);
        environment(sv, ctx, p->texturename, env);
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] =
                cs(ctx, i, c) * (p->Ka * am[i][c] + p->Ks * ds[i][c] + p->Kr * env[i][c]);
}

static void shinymetal_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, shinymetal_chunk);
}

static const RayesShaderParamDesc shinymetal_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(ShinymetalParams, Ka), {1, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(ShinymetalParams, Ks), {1, 0, 0}},
    {"Kr", RAYES_PARAM_FLOAT, offsetof(ShinymetalParams, Kr), {1, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(ShinymetalParams, roughness), {0.1f, 0, 0}},
    {"texturename", RAYES_PARAM_STRING, offsetof(ShinymetalParams, texturename), {0, 0, 0}},
};

const RayesShaderClass shade_class_shinymetal = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "shinymetal",
    .params_size = sizeof(ShinymetalParams),
    .params = shinymetal_params,
    .n_params = sizeof shinymetal_params / sizeof shinymetal_params[0],
    .lighting = shinymetal_lighting,
    .diffuselighting = shinymetal_lighting, /* without I: Cs Ka ambient only */
    .flags = RAYES_SHADER_PATH_STRINGS,
};

/* ------------------------------------------------------------ glass, dielectric */

typedef struct GlassParams {
    float Kr, Kt, eta, roughness, Ks;
    float specularcolor[3], transmitcolor[3];
} GlassParams;

int shade_branches(const RayesShaderServices *sv, const RayesShadeCtx *ctx)
{
    float depth = 0.0f;
    if (!SHADE_HAS_SERVICE(sv, random) || !SHADE_HAS_SERVICE(sv, option) ||
        sv->option(sv, ctx, "branchdepth", &depth, 1) != 1)
        return 1;
    return (float)(ctx->diffuse_depth + ctx->specular_depth) < depth;
}

/* Whether point i's ray hit the back side (it is leaving the medium). */
static int leaving(const RayesShadeCtx *ctx, size_t i)
{
    return ctx->backfacing && ctx->backfacing[i];
}

static float max3(const float v[3])
{
    return fmaxf(v[0], fmaxf(v[1], v[2]));
}

/* How many rays a glossy lobe of the context's points traces: the
 * renderer's diffuse ray count for their depth, one past the branch depth
 * (the glossy service's rule). */
static int lobe_rays(const RayesShaderServices *sv, const RayesShadeCtx *ctx)
{
    float n[2] = {1.0f, 1.0f};
    if (!shade_branches(sv, ctx) || !SHADE_HAS_SERVICE(sv, option) ||
        sv->option(sv, ctx, "diffuserays", n, 2) < 1)
        return 1;
    int k = (int)n[ctx->diffuse_depth > 0];
    return k > 1 ? k : 1;
}

/* Radiance refracted through a rough boundary (relative index rel) at
 * the one point of ctx: the mean over n rays, each refracted through a
 * microfacet normal drawn from GGX of width alpha and weighted as
 * bsdf_ggx_refract_sample says, or reflected about it where it reflects
 * totally (pbrt-v4's rough dielectric, Fresnel left to the caller, taken
 * at N); the normals' random numbers from the random service
 * (dimensions 1 and up), the first stratified over the n rays. */
static void rough_refraction(const RayesShaderServices *sv, const RayesShadeCtx *one, float alpha,
                             float rel, int n, float L[3])
{
    Vec3 V = v3_neg(ld(one->I[0])), N = ld(one->N[0]), t, b;
    v3_basis(N, &t, &b);
    Vec3 wo = v3(v3_dot(V, t), v3_dot(V, b), fmaxf(v3_dot(V, N), 1e-4f));
    L[0] = L[1] = L[2] = 0.0f;
    int rnd = SHADE_HAS_SERVICE(sv, random); /* else the strata's middles, a golden-ratio walk */
    for (int s = 0; s < n; s++) {
        float u1 =
            ((float)s + (rnd ? sv->random(sv, one, 0, 1u + 2u * (uint32_t)s) : 0.5f)) / (float)n;
        float u2 = rnd ? sv->random(sv, one, 0, 2u + 2u * (uint32_t)s)
                       : fmodf(0.5f + 0.618034f * (float)s, 1.0f);
        Vec3 w;
        float weight = bsdf_ggx_refract_sample(wo, fminf(u1, 0.99999994f), u2, alpha, rel, &w);
        if (!(weight > 0.0f))
            continue;
        Vec3 d = v3_add(v3_add(v3_scale(t, w.x), v3_scale(b, w.y)), v3_scale(N, w.z));
        Rgb dir = {d.x, d.y, d.z}, Ls;
        if (w.z < 0.0f)
            sv->indirect_refraction(sv, one, (const float(*)[3])&dir, &Ls);
        else if (sv->indirect_specular) /* the microfacet reflects totally: a mirror ray about it */
            sv->indirect_specular(sv, one, (const float(*)[3])&dir, NULL, 1, &Ls);
        else
            continue;
        for (int c = 0; c < 3; c++)
            L[c] += weight * Ls[c] / (float)n;
    }
}

/* Fresnel-weighted reflection and refraction at a smooth boundary of
 * relative index eta (inside over outside). A ray that hit the back side
 * is leaving: the index is then inverted, and beyond the critical angle
 * all light reflects. width[i] is the reflection lobe's (0: a mirror):
 * with glossy, the GGX alpha of glossy_reflection, lights included; else
 * the Blinn-Phong exponent of reflection's lobe; with glossy, refraction
 * is rough through the same width (rough_refraction; sharp at 0). Writes
 * R[i] = F * reflected and T[i] = (1 - F) * refracted,
 * which the caller weights by wR[i] and wT[i]. Past the branch depth each
 * point traces one of the two, chosen with probability in proportion to
 * F max(wR) and (1 - F) max(wT), and none with probability 1 - q, q that
 * sum at most 1 (Russian roulette on the weight the path carries on);
 * the chosen one is divided by its probability, so the expectation is
 * unchanged. */
static void fresnel_split(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float eta,
                          const float *width, int glossy, const Rgb *wR, const Rgb *wT, Rgb *R,
                          Rgb *T)
{
    Rgb dir[SHADE_CHUNK], refr[SHADE_CHUNK];
    float F[SHADE_CHUNK];
    size_t n_refr = 0;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float rel = leaving(ctx, i) ? 1.0f / eta : eta;
        Vec3 V = v3_neg(ld(ctx->I[i])), N = ld(ctx->N[i]), t;
        F[i] = fresnel_dielectric(cos_view(ctx, i), rel);
        if (!bsdf_refract(V, N, rel, &t)) {
            F[i] = 1.0f; /* total internal reflection */
            t = v3_neg(N);
        }
        dir[i][0] = t.x, dir[i][1] = t.y, dir[i][2] = t.z;
        n_refr += F[i] < 1.0f;
    }
    if (!shade_branches(sv, ctx)) {
        memset(R, 0, ctx->n_points * sizeof *R);
        memset(T, 0, ctx->n_points * sizeof *T);
        for (size_t i = 0; i < ctx->n_points; i++) {
            float a = F[i] * max3(wR[i]), b = (1.0f - F[i]) * max3(wT[i]), q = fminf(a + b, 1.0f);
            float u = sv->random(sv, ctx, i, 0);
            if (!(a + b > 0.0f) || u >= q)
                continue; /* ended by roulette */
            RayesShadeCtx one;
            shade_ctx_slice(ctx, i, 1, &one);
            int reflect = u < q * a / (a + b);
            float p = q * (reflect ? a : b) / (a + b);
            Rgb L;
            if (reflect && glossy)
                glossy_reflection(sv, &one, &width[i], &L);
            else if (reflect)
                reflection(sv, &one, &width[i], &L);
            else if (sv->indirect_refraction && glossy && width[i] > 0.0f)
                rough_refraction(sv, &one, width[i], leaving(ctx, i) ? 1.0f / eta : eta, 1, L);
            else if (sv->indirect_refraction)
                sv->indirect_refraction(sv, &one, (const float(*)[3])&dir[i], &L);
            else
                memset(L, 0, sizeof L);
            float w = (reflect ? F[i] : 1.0f - F[i]) / p;
            for (int c = 0; c < 3; c++)
                (reflect ? R : T)[i][c] = w * L[c];
        }
        return;
    }
    if (glossy)
        glossy_reflection(sv, ctx, width, R);
    else
        reflection(sv, ctx, width, R);
    memset(refr, 0, sizeof refr);
    size_t n_rough = 0;
    for (size_t i = 0; glossy && i < ctx->n_points; i++)
        n_rough += width[i] > 0.0f && F[i] < 1.0f;
    if (n_refr > 0 && sv->indirect_refraction && n_rough == 0) {
        sv->indirect_refraction(sv, ctx, (const float(*)[3])dir, refr);
    } else if (n_refr > 0 && sv->indirect_refraction) { /* point by point */
        int rays = lobe_rays(sv, ctx);
        for (size_t i = 0; i < ctx->n_points; i++) {
            RayesShadeCtx one;
            shade_ctx_slice(ctx, i, 1, &one);
            if (F[i] >= 1.0f)
                continue;
            if (glossy && width[i] > 0.0f)
                rough_refraction(sv, &one, width[i], leaving(ctx, i) ? 1.0f / eta : eta, rays,
                                 refr[i]);
            else
                sv->indirect_refraction(sv, &one, (const float(*)[3])&dir[i], &refr[i]);
        }
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            R[i][c] *= F[i];
            T[i][c] = F[i] < 1.0f ? (1.0f - F[i]) * refr[i][c] : 0.0f;
        }
}

/* Thin shadows of glass: the opacity a shadow ray, or a diffuse ray (it
 * has no view: ctx->I is NULL), meets at a dielectric's surface, as if
 * light crossed it unbent: Os (1 - (1 - R0) tint) a crossing, R0 Fresnel's
 * reflectance at normal incidence, so a solid's two crossings pass
 * (1 - R0)^2 tint^2 (0.92 at eta 1.5). Opaque, glass cast black shadows
 * and was black to diffuse rays: a table under a glass jug, a room behind
 * a glass door lost the light that pbrt-v4 carries there as caustics
 * (DESIGN.md "Built-in BSDFs and shaders"). */
static void thin_shadow(const RayesShadeCtx *ctx, float eta, const Rgb *tint,
                        RayesShadeOutputs *out)
{
    float T0 = 1.0f - fresnel_dielectric(1.0f, eta);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            float T = fminf(fmaxf(T0 * tint[i][c], 0.0f), 1.0f);
            out->Oi[i][c] = (ctx->Os ? ctx->Os[i][c] : 1.0f) * (1.0f - T);
        }
}

/* glass's tint of what it transmits: Cs transmitcolor Kt. */
static void glass_tint(const RayesShadeCtx *ctx, const GlassParams *p, Rgb *tint)
{
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            tint[i][c] = cs(ctx, i, c) * p->transmitcolor[c] * p->Kt;
}

static void glass_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const void *params, RayesShadeOutputs *out)
{
    const GlassParams *p = params;
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
    if (!ctx->I)
        return; /* no view-independent lobe */
    Rgb R[SHADE_CHUNK], T[SHADE_CHUNK], ds[SHADE_CHUNK], wR[SHADE_CHUNK], wT[SHADE_CHUNK];
    float e[SHADE_CHUNK];
    glass_tint(ctx, p, wT);
    for (size_t i = 0; i < ctx->n_points; i++) {
        for (int c = 0; c < 3; c++)
            wR[i][c] = p->specularcolor[c] * p->Kr;
        e[i] = p->roughness > 0.0f ? 1.0f / p->roughness : 0.0f;
    }
    fresnel_split(sv, ctx, p->eta, e, 0, (const Rgb *)wR, (const Rgb *)wT, R, T);
    memset(ds, 0, sizeof ds);
    if (p->Ks != 0.0f) {
        float rough[SHADE_CHUNK];
        for (size_t i = 0; i < ctx->n_points; i++)
            rough[i] = p->roughness > 0.0f ? p->roughness : 0.1f;
        shade_classic_lighting(sv, ctx, rough, NULL, ds);
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = p->specularcolor[c] * (p->Kr * R[i][c] + p->Ks * ds[i][c]) +
                            cs(ctx, i, c) * p->transmitcolor[c] * p->Kt * T[i][c];
}

static void glass_opacity_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    (void)sv;
    Rgb tint[SHADE_CHUNK];
    glass_tint(ctx, params, tint);
    thin_shadow(ctx, ((const GlassParams *)params)->eta, (const Rgb *)tint, out);
}

static void glass_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, glass_opacity_chunk);
}

static void glass_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, glass_chunk);
    if (!ctx->I) /* a diffuse ray sees through, as a shadow ray does */
        glass_opacity(sv, ctx, params, out);
}

static const RayesShaderParamDesc glass_params[] = {
    {"Kr", RAYES_PARAM_FLOAT, offsetof(GlassParams, Kr), {1, 0, 0}},
    {"Kt", RAYES_PARAM_FLOAT, offsetof(GlassParams, Kt), {1, 0, 0}},
    {"eta", RAYES_PARAM_FLOAT, offsetof(GlassParams, eta), {1.5f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(GlassParams, roughness), {0, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(GlassParams, Ks), {0, 0, 0}},
    {"specularcolor", RAYES_PARAM_COLOR, offsetof(GlassParams, specularcolor), {1, 1, 1}},
    {"transmitcolor", RAYES_PARAM_COLOR, offsetof(GlassParams, transmitcolor), {1, 1, 1}},
};

const RayesShaderClass shade_class_glass = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "glass",
    .params_size = sizeof(GlassParams),
    .params = glass_params,
    .n_params = sizeof glass_params / sizeof glass_params[0],
    .opacity = glass_opacity,
    .lighting = glass_lighting,
    .diffuselighting = glass_lighting, /* without I: black, and thin-shadow Oi */
    .flags = RAYES_SHADER_THIN_SHADOW,
};

typedef struct DielectricParams {
    float eta, roughness, normalmap[3], transmitcolor[3];
} DielectricParams;

static void dielectric_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    const DielectricParams *p = params;
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
    if (!ctx->I)
        return;
    Rgb R[SHADE_CHUNK], T[SHADE_CHUNK], one[SHADE_CHUNK], tint[SHADE_CHUNK];
    float alpha[SHADE_CHUNK];
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            one[i][c] = 1.0f, tint[i][c] = p->transmitcolor[c];
    alphas(sv, ctx, p->roughness, alpha);
    fresnel_split(sv, ctx, p->eta, alpha, 1, (const Rgb *)one, (const Rgb *)tint, R, T);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = R[i][c] + tint[i][c] * T[i][c]; /* at each crossing */
}

static void dielectric_opacity_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                     const void *params, RayesShadeOutputs *out)
{
    (void)sv;
    const DielectricParams *p = params;
    Rgb tint[SHADE_CHUNK];
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            tint[i][c] = p->transmitcolor[c];
    thin_shadow(ctx, p->eta, (const Rgb *)tint, out);
}

static void dielectric_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, dielectric_opacity_chunk);
}

static void dielectric_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, dielectric_chunk);
    if (!ctx->I) /* a diffuse ray sees through, as a shadow ray does */
        dielectric_opacity(sv, ctx, params, out);
}

static const RayesShaderParamDesc dielectric_params[] = {
    {"eta", RAYES_PARAM_FLOAT, offsetof(DielectricParams, eta), {1.5f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(DielectricParams, roughness), {0, 0, 0}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(DielectricParams, normalmap), {0.5f, 0.5f, 1.0f}},
    {"transmitcolor", RAYES_PARAM_COLOR, offsetof(DielectricParams, transmitcolor), {1, 1, 1}},
};

const RayesShaderClass shade_class_dielectric = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "dielectric",
    .params_size = sizeof(DielectricParams),
    .params = dielectric_params,
    .n_params = sizeof dielectric_params / sizeof dielectric_params[0],
    .opacity = dielectric_opacity,
    .lighting = dielectric_lighting,
    .diffuselighting = dielectric_lighting, /* without I: black, and thin-shadow Oi */
    .flags = RAYES_SHADER_THIN_SHADOW,
};

/* ------------------------------------------------------------ diffuse */

typedef struct DiffuseParams {
    float reflectance[3], normalmap[3];
} DiffuseParams;

static void diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    const DiffuseParams *p = params;
    Rgb E[SHADE_CHUNK], refl[SHADE_CHUNK];
    shade_param_color(sv, ctx, "reflectance", p->reflectance, refl);
    diffuse_light(sv, ctx, E, out);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * refl[i][c] * E[i][c];
}

static void diffuse_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, diffuse_chunk);
}

static const RayesShaderParamDesc diffuse_params[] = {
    {"reflectance", RAYES_PARAM_COLOR, offsetof(DiffuseParams, reflectance), {0.5f, 0.5f, 0.5f}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(DiffuseParams, normalmap), {0.5f, 0.5f, 1.0f}},
};

const RayesShaderClass shade_class_diffuse = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "diffuse",
    .params_size = sizeof(DiffuseParams),
    .params = diffuse_params,
    .n_params = sizeof diffuse_params / sizeof diffuse_params[0],
    .lighting = diffuse_lighting,
    .diffuselighting = diffuse_lighting, /* Lambertian: view-independent throughout */
};

/* ------------------------------------------------- diffusetransmission */

/* pbrt-v4's diffusetransmission (leaves, paper, lamp shades): Lambertian
 * reflection of the light on the shaded side and Lambertian transmission
 * of the light on the other, each scaled by `scale`. The other side's
 * light is the same services' with the normals turned over (its rays leave
 * from that side). View-independent, so cached as diffuse light. */
typedef struct DiffuseTransmissionParams {
    float reflectance[3], transmittance[3], scale, normalmap[3];
} DiffuseTransmissionParams;

static void diffusetransmission_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                      const void *params, RayesShadeOutputs *out)
{
    const DiffuseTransmissionParams *p = params;
    Rgb E[SHADE_CHUNK], Eb[SHADE_CHUNK], refl[SHADE_CHUNK], tran[SHADE_CHUNK];
    Rgb Nb[SHADE_CHUNK], Ngb[SHADE_CHUNK];
    shade_param_color(sv, ctx, "reflectance", p->reflectance, refl);
    shade_param_color(sv, ctx, "transmittance", p->transmittance, tran);
    diffuse_light(sv, ctx, E, out);
    RayesShadeCtx back; /* the other side */
    shade_ctx_turned(ctx, Nb, Ngb, &back);
    RayesShadeOutputs ob = {NULL, NULL, NULL, NULL};
    diffuse_light(sv, &back, Eb, &ob);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] =
                cs(ctx, i, c) * p->scale * (refl[i][c] * E[i][c] + tran[i][c] * Eb[i][c]);
}

static void diffusetransmission_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                         const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, diffusetransmission_chunk);
}

static const RayesShaderParamDesc diffusetransmission_params[] = {
    {"reflectance",
     RAYES_PARAM_COLOR,
     offsetof(DiffuseTransmissionParams, reflectance),
     {0.25f, 0.25f, 0.25f}},
    {"transmittance",
     RAYES_PARAM_COLOR,
     offsetof(DiffuseTransmissionParams, transmittance),
     {0.25f, 0.25f, 0.25f}},
    {"scale", RAYES_PARAM_FLOAT, offsetof(DiffuseTransmissionParams, scale), {1, 0, 0}},
    {"normalmap",
     RAYES_PARAM_COLOR,
     offsetof(DiffuseTransmissionParams, normalmap),
     {0.5f, 0.5f, 1.0f}},
};

const RayesShaderClass shade_class_diffusetransmission = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "diffusetransmission",
    .params_size = sizeof(DiffuseTransmissionParams),
    .params = diffusetransmission_params,
    .n_params = sizeof diffusetransmission_params / sizeof diffusetransmission_params[0],
    .lighting = diffusetransmission_lighting,
    .diffuselighting = diffusetransmission_lighting, /* view-independent throughout */
};

/* ------------------------------------------------------------ conductor */

typedef struct ConductorParams {
    float eta[3], k[3], reflectance[3], roughness;
    char preset[64];
    float coat, coat_roughness, coat_eta; /* a dielectric coat (pbrt's coatedconductor) */
    float normalmap[3];
} ConductorParams;

/* The complex index of the points: the preset if named (an unknown name:
 * copper), else reflectance if given (bound to a pattern, or all of it >=
 * 0), else eta and k (each a constant or a pattern). */
static void conductor_index(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const ConductorParams *p, Rgb *eta, Rgb *k)
{
    Vec3 e, kk;
    if (p->preset[0]) {
        if (conductor_preset(p->preset, &e, &kk) != 0) {
            log_warning_once("conductor:preset",
                             "conductor: unknown preset \"%s\" (expected gold, copper, "
                             "aluminium or silver); using copper",
                             p->preset);
            conductor_preset("copper", &e, &kk);
        }
        for (size_t i = 0; i < ctx->n_points; i++)
            v3_store(eta[i], e), v3_store(k[i], kk);
        return;
    }
    if (shade_param_bound(ctx, "reflectance") ||
        (p->reflectance[0] >= 0.0f && p->reflectance[1] >= 0.0f && p->reflectance[2] >= 0.0f)) {
        shade_param_color(sv, ctx, "reflectance", p->reflectance, k);
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++) {
                eta[i][c] = 1.0f;
                k[i][c] = conductor_k_from_reflectance(fminf(fmaxf(k[i][c], 0.0f), 0.9999f));
            }
        return;
    }
    shade_param_color(sv, ctx, "eta", p->eta, eta);
    shade_param_color(sv, ctx, "k", p->k, k);
}

static void conductor_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const void *params, RayesShadeOutputs *out)
{
    const ConductorParams *p = params;
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
    if (!ctx->I)
        return; /* no view-independent lobe */
    Rgb eta[SHADE_CHUNK], k[SHADE_CHUNK], L[SHADE_CHUNK];
    float alpha[SHADE_CHUNK];
    conductor_index(sv, ctx, p, eta, k);
    alphas(sv, ctx, p->roughness, alpha);
    glossy_reflection(sv, ctx, alpha, L);
    /* Under a coat (pbrt's coatedconductor, whose layers pbrt walks
     * stochastically; here in closed form): the coat reflects its
     * dielectric Fresnel F_c through its own lobe, and the metal what
     * crosses the coat twice and bounces between metal and coat,
     * (1 - F_c)^2 F / (1 - F_c F) (the layer's absorption and the lobe's
     * narrowing by refraction left out). A white metal under a clear coat
     * reflects F_c + (1 - F_c) = 1: no energy lost or made. */
    Rgb Lc[SHADE_CHUNK];
    float ac[SHADE_CHUNK];
    if (p->coat > 0.0f) {
        for (size_t i = 0; i < ctx->n_points; i++)
            ac[i] = alpha_of(p->coat_roughness);
        glossy_reflection(sv, ctx, ac, Lc);
    }
    for (size_t i = 0; i < ctx->n_points; i++) {
        float cv = cos_view(ctx, i);
        Vec3 F = fresnel_conductor_rgb(cv, v3_load(eta[i]), v3_load(k[i]));
        float Fc = p->coat > 0.0f ? fminf(p->coat, 1.0f) * fresnel_dielectric(cv, p->coat_eta) : 0.0f;
        for (int c = 0; c < 3; c++) {
            float Fm = v3_index(F, c);
            out->Ci[i][c] = cs(ctx, i, c) * (1.0f - Fc) * (1.0f - Fc) * Fm / (1.0f - Fc * Fm) * L[i][c];
            if (Fc > 0.0f)
                out->Ci[i][c] += Fc * Lc[i][c];
        }
    }
}

static void conductor_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, conductor_chunk);
}

static const RayesShaderParamDesc conductor_params[] = {
    /* copper, pbrt-v4's default conductor */
    {"eta", RAYES_PARAM_COLOR, offsetof(ConductorParams, eta), {0.200f, 0.924f, 1.102f}},
    {"k", RAYES_PARAM_COLOR, offsetof(ConductorParams, k), {3.912f, 2.452f, 2.142f}},
    {"reflectance", RAYES_PARAM_COLOR, offsetof(ConductorParams, reflectance), {-1, -1, -1}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(ConductorParams, roughness), {0, 0, 0}},
    {"preset", RAYES_PARAM_STRING, offsetof(ConductorParams, preset), {0, 0, 0}},
    {"coat", RAYES_PARAM_FLOAT, offsetof(ConductorParams, coat), {0, 0, 0}},
    {"coat_roughness", RAYES_PARAM_FLOAT, offsetof(ConductorParams, coat_roughness), {0, 0, 0}},
    {"coat_eta", RAYES_PARAM_FLOAT, offsetof(ConductorParams, coat_eta), {1.5f, 0, 0}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(ConductorParams, normalmap), {0.5f, 0.5f, 1.0f}},
};

const RayesShaderClass shade_class_conductor = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "conductor",
    .params_size = sizeof(ConductorParams),
    .params = conductor_params,
    .n_params = sizeof conductor_params / sizeof conductor_params[0],
    .lighting = conductor_lighting,
    .diffuselighting = conductor_lighting, /* without I: black */
};

/* ------------------------------------------------------------ coateddiffuse */

typedef struct CoatedParams {
    float reflectance[3], roughness, eta, thickness, normalmap[3];
    float specular[3]; /* unset (negative): layered; else pbrt-v3's plastic (below) */
} CoatedParams;

/* A Lambertian base of albedo R under a smooth or glossy dielectric coat
 * of index eta. Light reaches the base through the coat with the
 * hemispherical average 1 - Favg, and what the base reflects leaves toward
 * the viewer with 1 - F(cos_v), compressed into the coat's solid angle by
 * 1 / eta^2, after bouncing between base and coat: 1 / (1 - R Fint), Fint
 * the coat's reflectance seen from inside (total internal reflection
 * included), 1 - (1 - Favg) / eta^2 (0.596 at eta 1.5). So R = 1 keeps all
 * the light (the coat's Favg plus (1 - Favg) from the base), as pbrt-v4's
 * layered coateddiffuse does, whose closed form this is with Favg for the
 * incident F (dark bases were 2 times too bright, white ones 16% too dark).
 * The coat reflects F(cos_v) * the reflected radiance. diffuselighting
 * averages the base term over cosine-weighted views (1 - Favg in place of
 * 1 - F(cos_v)). The coat absorbs exp(-2 thickness) (normal incidence,
 * down and up). With "specular" S given, the two are not layered: pbrt-v3's
 * plastic and uber, a Lambertian base R plus S times the coat's reflection
 * F(cos_v) L, neither dimming the other. */
static void coated_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const void *params, RayesShadeOutputs *out)
{
    const CoatedParams *p = params;
    Rgb E[SHADE_CHUNK], L[SHADE_CHUNK], refl[SHADE_CHUNK], spec[SHADE_CHUNK];
    float alpha[SHADE_CHUNK], thick[SHADE_CHUNK];
    shade_param_color(sv, ctx, "reflectance", p->reflectance, refl);
    shade_param_float(sv, ctx, "thickness", p->thickness, thick);
    int plastic = shade_param_bound(ctx, "specular") ||
                  (p->specular[0] >= 0.0f && p->specular[1] >= 0.0f && p->specular[2] >= 0.0f);
    if (plastic)
        shade_param_color(sv, ctx, "specular", p->specular, spec);
    diffuse_light(sv, ctx, E, out);
    float favg = fresnel_dielectric_average(p->eta);
    if (ctx->I) {
        alphas(sv, ctx, p->roughness, alpha);
        glossy_reflection(sv, ctx, alpha, L);
    }
    float eta2 = p->eta > 0.0f ? p->eta * p->eta : 1.0f, fint = 1.0f - (1.0f - favg) / eta2;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float base = (1.0f - favg) * (1.0f - favg) * expf(-2.0f * fmaxf(thick[i], 0.0f)) / eta2;
        float F = ctx->I ? fresnel_dielectric(cos_view(ctx, i), p->eta) : 0.0f;
        float view = ctx->I ? (1.0f - F) / (1.0f - favg) : 1.0f;
        for (int c = 0; c < 3; c++) {
            float R = cs(ctx, i, c) * refl[i][c];
            out->Ci[i][c] =
                plastic ? R * E[i][c] : R * base * view * E[i][c] / fmaxf(1.0f - R * fint, 1e-3f);
            if (ctx->I)
                out->Ci[i][c] += (plastic ? fmaxf(spec[i][c], 0.0f) : 1.0f) * F * L[i][c];
        }
    }
}

static void coated_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, coated_chunk);
}

static const RayesShaderParamDesc coated_params[] = {
    {"reflectance", RAYES_PARAM_COLOR, offsetof(CoatedParams, reflectance), {0.5f, 0.5f, 0.5f}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(CoatedParams, roughness), {0, 0, 0}},
    {"eta", RAYES_PARAM_FLOAT, offsetof(CoatedParams, eta), {1.5f, 0, 0}},
    {"thickness", RAYES_PARAM_FLOAT, offsetof(CoatedParams, thickness), {0.01f, 0, 0}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(CoatedParams, normalmap), {0.5f, 0.5f, 1.0f}},
    {"specular", RAYES_PARAM_COLOR, offsetof(CoatedParams, specular), {-1, -1, -1}},
};

const RayesShaderClass shade_class_coateddiffuse = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "coateddiffuse",
    .params_size = sizeof(CoatedParams),
    .params = coated_params,
    .n_params = sizeof coated_params / sizeof coated_params[0],
    .lighting = coated_lighting,
    .diffuselighting = coated_lighting, /* without I: the base's view average only */
};
