/*
 * shade/builtin_hair.c — the built-in `physicalhair` surface shader for
 * curves: pbrt-v4's hair material, the hair service's BSDF (Chiang et al.
 * 2016; shade/hair.h).
 *
 * The fibre's absorption, in order of precedence: "sigma_a" (per unit of
 * the fibre's radius, as pbrt's), "reflectance" (the colour a mass of
 * such hair shows, inverted by Chiang et al.'s fit for beta_n), or the
 * melanin concentrations "eumelanin" and "pheomelanin" (pbrt's default:
 * 1.3 of eumelanin, brown). "eta", "beta_m", "beta_n" and "alpha" shape
 * the lobes (1.55, 0.3, 0.3, 2 degrees). The fibre's direction is dPdu,
 * where the ray met its width 2 v - 1 (a curve's v runs across it); at v
 * 0 or 1, a grid's vertex on the fibre's edge (the grid hider shades
 * those), the service integrates over the width instead.
 *
 *   lighting         Ci = the hair service's scattered light toward -I.
 *   diffuselighting  view-independent, for the radiosity diffuse rays
 *                    read: a two-sided Lambertian stand-in of the fibre's
 *                    albedo averaged over views and offsets, so light that
 *                    crosses a mass of hair from fibre to fibre keeps the
 *                    energy and colour each fibre's BSDF gives it (not
 *                    its forward lobes' direction).
 */
#include <stddef.h>
#include <string.h>

#include "shade/builtin.h"
#include "shade/hair.h"
#include "shade/shade.h"

typedef float Rgb[3];

typedef struct PhysicalHairParams {
    float sigma_a[3];     /* < 0: unset */
    float reflectance[3]; /* < 0: unset */
    float eumelanin, pheomelanin;
    float eta, beta_m, beta_n, alpha;
} PhysicalHairParams;

/* The points' sigma_a, by the parameters' precedence. */
static void absorption(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const PhysicalHairParams *p, Rgb *sigma)
{
    if (shade_param_bound(ctx, "sigma_a") || p->sigma_a[0] >= 0.0f) {
        shade_param_color(sv, ctx, "sigma_a", p->sigma_a, sigma);
        return;
    }
    if (shade_param_bound(ctx, "reflectance") || p->reflectance[0] >= 0.0f) {
        shade_param_color(sv, ctx, "reflectance", p->reflectance, sigma);
        for (size_t i = 0; i < ctx->n_points; i++)
            v3_store(sigma[i], hair_sigma_a_from_reflectance(v3_load(sigma[i]), p->beta_n));
        return;
    }
    float eu[SHADE_CHUNK], pheo[SHADE_CHUNK];
    shade_param_float(sv, ctx, "eumelanin", p->eumelanin, eu);
    shade_param_float(sv, ctx, "pheomelanin", p->pheomelanin, pheo);
    for (size_t i = 0; i < ctx->n_points; i++)
        v3_store(sigma[i], hair_sigma_a_from_melanin(eu[i], pheo[i]));
}

static void hair_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                       RayesShadeOutputs *out)
{
    const PhysicalHairParams *p = params;
    Rgb sigma[SHADE_CHUNK], T[SHADE_CHUNK];
    float h[SHADE_CHUNK];
    absorption(sv, ctx, p, sigma);
    for (size_t i = 0; i < ctx->n_points; i++) {
        for (int c = 0; c < 3; c++)
            T[i][c] = ctx->dPdu ? ctx->dPdu[i][c] : 0.0f;
        /* a grid's vertex (the grid hider's) lies on the fibre's edge,
         * v 0 or 1, and stands for the fibre's whole width */
        float v = ctx->v ? ctx->v[i] : 0.5f;
        h[i] = v > 0.0f && v < 1.0f ? 2.0f * v - 1.0f : 2.0f;
    }
    RayesHairParams hp = {
        (const float(*)[3])T, h, (const float(*)[3])sigma, p->eta, p->beta_m, p->beta_n, p->alpha};
    if (sv->hair)
        sv->hair(sv, ctx, &hp, 0, 0, out->Ci);
    else
        memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
}

/* The fibre's mean albedo for sigma_a and p's lobes (hair_bsdf_mean_albedo),
 * remembered per thread for the last parameters asked: a material's
 * points share them. */
static Vec3 mean_albedo(const PhysicalHairParams *p, Vec3 sigma)
{
    static _Thread_local struct {
        int set;
        float key[7];
        Vec3 albedo;
    } memo;
    float key[7] = {sigma.x, sigma.y, sigma.z, p->eta, p->beta_m, p->beta_n, p->alpha};
    if (!memo.set || memcmp(key, memo.key, sizeof key) != 0) {
        memo.albedo = hair_bsdf_mean_albedo(p->eta, sigma, p->beta_m, p->beta_n, p->alpha);
        memcpy(memo.key, key, sizeof key);
        memo.set = 1;
    }
    return memo.albedo;
}

/* A Lambertian stand-in of the fibre's mean albedo A, lit from both
 * sides (a fibre has no back): A (E_front + E_back) / 2, each E the
 * direct and indirect diffuse light on one side of the grid's normal (the
 * second with the normals turned over, its rays leaving there). Lights and
 * everything else are weighed alike on each side, so under uniform light L
 * it is A L whatever shadows the fibre (a white furnace keeps its energy). */
static void hair_diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    const PhysicalHairParams *p = params;
    Rgb sigma[SHADE_CHUNK], Nb[SHADE_CHUNK], Ngb[SHADE_CHUNK], dd[2][SHADE_CHUNK],
        id[2][SHADE_CHUNK];
    absorption(sv, ctx, p, sigma);
    RayesShadeCtx back;
    shade_ctx_turned(ctx, Nb, Ngb, &back);
    const RayesShadeCtx *side[2] = {ctx, &back};
    for (int k = 0; k < 2; k++) {
        sv->direct_lighting(sv, side[k], 0, NULL, NULL, dd[k], NULL);
        sv->indirect_diffuse(sv, side[k], 0, id[k]);
    }
    for (size_t i = 0; i < ctx->n_points; i++) {
        Vec3 E = v3_add(v3_add(v3_load(dd[0][i]), v3_load(id[0][i])),
                        v3_add(v3_load(dd[1][i]), v3_load(id[1][i])));
        E = v3_scale(E, 0.5f);
        v3_store(out->Ci[i], v3_mul(mean_albedo(p, v3_load(sigma[i])), E));
        if (out->Irradiance)
            v3_store(out->Irradiance[i], v3_scale(E, 3.14159265f));
    }
}

static void hair_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    shade_chunks_opacity(sv, ctx, params, out, hair_chunk);
}

static void hair_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    shade_chunks_opacity(sv, ctx, params, out, hair_diffuse_chunk);
}

static const RayesShaderParamDesc physicalhair_params[] = {
    {"sigma_a", RAYES_PARAM_COLOR, offsetof(PhysicalHairParams, sigma_a), {-1, -1, -1}},
    {"reflectance", RAYES_PARAM_COLOR, offsetof(PhysicalHairParams, reflectance), {-1, -1, -1}},
    {"eumelanin", RAYES_PARAM_FLOAT, offsetof(PhysicalHairParams, eumelanin), {1.3f, 0, 0}},
    {"pheomelanin", RAYES_PARAM_FLOAT, offsetof(PhysicalHairParams, pheomelanin), {0, 0, 0}},
    {"eta", RAYES_PARAM_FLOAT, offsetof(PhysicalHairParams, eta), {1.55f, 0, 0}},
    {"beta_m", RAYES_PARAM_FLOAT, offsetof(PhysicalHairParams, beta_m), {0.3f, 0, 0}},
    {"beta_n", RAYES_PARAM_FLOAT, offsetof(PhysicalHairParams, beta_n), {0.3f, 0, 0}},
    {"alpha", RAYES_PARAM_FLOAT, offsetof(PhysicalHairParams, alpha), {2, 0, 0}},
};

const RayesShaderClass shade_class_physicalhair = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "physicalhair",
    .params_size = sizeof(PhysicalHairParams),
    .params = physicalhair_params,
    .n_params = sizeof physicalhair_params / sizeof physicalhair_params[0],
    .lighting = hair_lighting,
    .diffuselighting = hair_diffuselighting,
};
