/*
 * shade/builtin_subsurface.c — the built-in `subsurface` surface shader
 * (memo section 6.2): multiple subsurface scattering by diffusion under a
 * specular coat, for wax, marble, skin, milk.
 *
 * The medium, in order of precedence: a named preset (Jensen 2001's
 * measured media, shade/diffusion.h); RenderMan's classic "albedo" (total
 * diffuse reflectance) and "diffusemeanfreepath"; pbrt-v4's "reflectance"
 * and "mfp" (volume mean free path); or the coefficients "sigma_s"
 * (reduced scattering) and "sigma_a" themselves. Lengths and coefficients
 * are in mm; "unitlength" gives the scene units per mm. "profile" chooses
 * the dipole (the memo's) or Burley's normalized diffusion.
 *
 *   lighting         Ci = Cs Kd (1 - F) subsurface + Ks F specular: the
 *                    subsurface service's diffusion (samples rays; 0: the
 *                    renderer's setting) and a Blinn-Phong coat from
 *                    direct_lighting, F Schlick's Fresnel at the viewer.
 *   diffuselighting  view-independent, for diffuse rays and the irradiance
 *                    the subsurface service reads: Irradiance (filled by
 *                    direct_lighting) and Ci = Cs Kd Rd (direct + indirect
 *                    diffuse), a Lambertian of the medium's total diffuse
 *                    reflectance Rd; subsurface rays (ray type SUBSURFACE)
 *                    need only Irradiance, so they skip the indirect part.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "shade/builtin.h"
#include "shade/diffusion.h"
#include "shade/shade.h"
#include "util/log.h"

typedef struct SubsurfaceParams {
    char preset[64];              /* a measured medium's name, or "" */
    char profile[64];             /* "dipole" or "burley" */
    float sigma_s[3];             /* reduced scattering coefficient, per mm */
    float sigma_a[3];             /* absorption coefficient, per mm */
    float albedo[3];              /* RenderMan: total diffuse reflectance ... */
    float diffusemeanfreepath[3]; /* ... and 1 / sigma_tr, mm (0: unused) */
    float reflectance[3];         /* pbrt: total diffuse reflectance ... */
    float mfp[3];                 /* ... and 1 / sigma_t', mm (0: unused) */
    float eta;                    /* index of refraction of the medium */
    float ior;                    /* RenderMan's name for it; 0: unset, eta counts */
    float unitlength;             /* scene units per mm */
    float Kd, Ks, roughness;      /* subsurface weight, coat weight, coat roughness */
    float samples;                /* subsurface rays (0: the renderer's setting) */
} SubsurfaceParams;

/* The service's medium of the parameters. */
static void medium(const SubsurfaceParams *p, RayesSubsurfaceParams *m)
{
    m->eta = p->ior > 0.0f ? p->ior : p->eta > 0.0f ? p->eta : 1.3f;
    m->scale = p->unitlength > 0.0f ? p->unitlength : 1.0f;
    m->profile =
        strcasecmp(p->profile, "burley") == 0 ? RAYES_SUBSURFACE_BURLEY : RAYES_SUBSURFACE_DIPOLE;
    if (p->preset[0] && diffusion_preset(p->preset, m->sigma_s, m->sigma_a) == 0)
        return;
    if (p->preset[0]) {
        char key[96];
        snprintf(key, sizeof key, "subsurface preset:%s", p->preset);
        log_warning_once(key, "subsurface: unknown preset \"%s\"; using sigma_s and sigma_a",
                         p->preset);
    }
    for (int c = 0; c < 3; c++) {
        m->sigma_s[c] = p->sigma_s[c];
        m->sigma_a[c] = p->sigma_a[c];
        if (p->diffusemeanfreepath[c] > 0.0f)
            diffusion_from_dmfp(p->albedo[c], p->diffusemeanfreepath[c], m->eta, &m->sigma_s[c],
                                &m->sigma_a[c]);
        else if (p->mfp[c] > 0.0f)
            diffusion_from_mfp(p->reflectance[c], p->mfp[c], m->eta, &m->sigma_s[c],
                               &m->sigma_a[c]);
    }
}

static float cs(const RayesShadeCtx *ctx, size_t i, int c)
{
    return ctx->Cs ? ctx->Cs[i][c] : 1.0f;
}

/* Schlick's Fresnel reflectance at cos_o for index eta. */
static float schlick(float cos_o, float eta)
{
    float f0 = (eta - 1.0f) / (eta + 1.0f), m = 1.0f - fminf(fmaxf(cos_o, 0.0f), 1.0f);
    f0 *= f0;
    return f0 + (1.0f - f0) * m * m * m * m * m;
}

/* A pattern bound to "reflectance" (pbrt-v4's textured reflectance, a
 * skin's albedo map): the medium stays the constant's (how far light
 * diffuses), each point's colour is the pattern's: the diffusion times
 * pattern / constant. Without a pattern, 1. */
static void reflectance_tint(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const SubsurfaceParams *p, float (*tint)[3])
{
    if (!shade_param_bound(ctx, "reflectance")) {
        for (size_t i = 0; i < ctx->n_points; i++)
            tint[i][0] = tint[i][1] = tint[i][2] = 1.0f;
        return;
    }
    shade_param_color(sv, ctx, "reflectance", p->reflectance, tint);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            tint[i][c] =
                p->reflectance[c] > 0.0f ? fmaxf(tint[i][c], 0.0f) / p->reflectance[c] : 0.0f;
}

static void lighting_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    const SubsurfaceParams *p = params;
    RayesSubsurfaceParams m;
    medium(p, &m);
    float sss[SHADE_CHUNK][3], spec[SHADE_CHUNK][3], rough[SHADE_CHUNK], tint[SHADE_CHUNK][3];
    memset(sss, 0, sizeof sss);
    memset(spec, 0, sizeof spec);
    reflectance_tint(sv, ctx, p, tint);
    if (p->Kd > 0.0f && SHADE_HAS_SERVICE(sv, subsurface))
        sv->subsurface(sv, ctx, &m, (int)p->samples, sss);
    /* roughness 0 (pbrt's smooth boundary) is a sharp coat, not the
     * service's default 0.1 */
    for (size_t i = 0; i < ctx->n_points; i++)
        rough[i] = fmaxf(p->roughness, 0.005f);
    if (p->Ks > 0.0f && ctx->I)
        sv->direct_lighting(sv, ctx, 0, NULL, rough, NULL, spec);
    for (size_t i = 0; i < ctx->n_points; i++) {
        float cos_o = 1.0f;
        if (ctx->I)
            cos_o = -(ctx->I[i][0] * ctx->N[i][0] + ctx->I[i][1] * ctx->N[i][1] +
                      ctx->I[i][2] * ctx->N[i][2]);
        float F = schlick(cos_o, m.eta);
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * tint[i][c] * p->Kd * (1.0f - F) * sss[i][c] +
                            p->Ks * F * spec[i][c];
    }
}

static void diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    const SubsurfaceParams *p = params;
    RayesSubsurfaceParams m;
    medium(p, &m);
    float dd[SHADE_CHUNK][3], id[SHADE_CHUNK][3], Rd[3], tint[SHADE_CHUNK][3];
    memset(id, 0, sizeof id);
    reflectance_tint(sv, ctx, p, tint);
    for (int c = 0; c < 3; c++) {
        DiffusionChannel ch;
        diffusion_channel(&m, c, &ch);
        Rd[c] = ch.Rd;
    }
    sv->direct_lighting(sv, ctx, 0, NULL, NULL, dd, NULL); /* fills Irradiance, memo 6.2 */
    if (!(ctx->ray_type & RAYES_RAY_SUBSURFACE))
        sv->indirect_diffuse(sv, ctx, 0, id);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * tint[i][c] * p->Kd * Rd[c] * (dd[i][c] + id[i][c]);
}

static void subsurface_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    shade_chunks_opacity(sv, ctx, params, out, lighting_chunk);
}

static void subsurface_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                       const void *params, RayesShadeOutputs *out)
{
    shade_chunks_opacity(sv, ctx, params, out, diffuse_chunk);
}

#define P_(f) offsetof(SubsurfaceParams, f)
static const RayesShaderParamDesc subsurface_params[] = {
    {"preset", RAYES_PARAM_STRING, P_(preset), {0, 0, 0}},
    {"profile", RAYES_PARAM_STRING, P_(profile), {0, 0, 0}},
    /* Jensen 2001's marble */
    {"sigma_s", RAYES_PARAM_COLOR, P_(sigma_s), {2.19f, 2.62f, 3.00f}},
    {"sigma_a", RAYES_PARAM_COLOR, P_(sigma_a), {0.0021f, 0.0041f, 0.0071f}},
    {"albedo", RAYES_PARAM_COLOR, P_(albedo), {0.8f, 0.8f, 0.8f}},
    {"diffusemeanfreepath", RAYES_PARAM_COLOR, P_(diffusemeanfreepath), {0, 0, 0}},
    {"reflectance", RAYES_PARAM_COLOR, P_(reflectance), {0.8f, 0.8f, 0.8f}},
    {"mfp", RAYES_PARAM_COLOR, P_(mfp), {0, 0, 0}},
    {"eta", RAYES_PARAM_FLOAT, P_(eta), {1.3f, 0, 0}},
    {"ior", RAYES_PARAM_FLOAT, P_(ior), {0, 0, 0}},
    {"unitlength", RAYES_PARAM_FLOAT, P_(unitlength), {1.0f, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, P_(Kd), {1.0f, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, P_(Ks), {1.0f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, P_(roughness), {0.05f, 0, 0}},
    {"samples", RAYES_PARAM_FLOAT, P_(samples), {0, 0, 0}},
};
#undef P_

const RayesShaderClass shade_class_subsurface = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "subsurface",
    .params_size = sizeof(SubsurfaceParams),
    .params = subsurface_params,
    .n_params = sizeof subsurface_params / sizeof subsurface_params[0],
    .lighting = subsurface_lighting,
    .diffuselighting = subsurface_diffuselighting,
    .flags = RAYES_SHADER_SUBSURFACE,
};
