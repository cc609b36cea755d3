/*
 * shade/displace.c — the built-in displacement shaders and the services
 * table displacement runs with at dicing time.
 *
 *   bumpy    P += N * Km * noise(P * frequency), or Km * the texture's first
 *            channel at (s, t) when texturename is given (RenderMan's bumpy
 *            displaces by a texture map; without one, by noise)
 *   fractal  the memo's procedural displacement: P += N * amplitude *
 *            fbm(P * frequency, octaves, lacunarity, gain), octaves at the
 *            digest's frequency ratio 1.99 by default
 *
 * Both are surfaces too (matte-like lighting from the Kd parameter is not
 * theirs to give): they are meant for rayes_scene_set_displacement, whose
 * instance only ever runs the displacement method, so lighting is the
 * constant black of a class that is never shaded.
 */
#include <stddef.h>
#include <string.h>

#include "shade/builtin.h"
#include "shade/noise.h"
#include "shade/pattern.h"
#include "shade/shade.h"
#include "shade/texture.h"

typedef struct BumpyParams {
    float Km, frequency;
    char texturename[RAYES_SHADER_PATH_BYTES];
} BumpyParams;

typedef struct FractalParams {
    float amplitude, frequency, octaves, lacunarity, gain;
} FractalParams;

/* Moves out->P[i] along N[i] by h[i]. */
static void displace_along_normal(const RayesShadeCtx *ctx, const float *h, RayesShadeOutputs *out)
{
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->P[i][c] = ctx->P[i][c] + h[i] * ctx->N[i][c];
}

/* The heights of a chunk of at most SHADE_CHUNK points. */
typedef void (*HeightFn)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const void *params, float *h);

/* Displaces ctx's points along their normals by height, SHADE_CHUNK
 * points at a time. */
static void displace_by_chunks(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out, HeightFn height)
{
    float h[SHADE_CHUNK];
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        height(sv, &sub, params, h);
        RayesShadeOutputs o = *out;
        o.P = out->P + start;
        displace_along_normal(&sub, h, &o);
    }
}

/* bumpy: Km times the texture's first channel, else times noise. */
static void bumpy_height(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const void *params, float *h)
{
    const BumpyParams *p = params;
    float tex[SHADE_CHUNK][3];
    if (p->texturename[0] && sv->texture &&
        sv->texture(sv, ctx, p->texturename, ctx->s, ctx->t, NULL, NULL, tex, NULL) == 0) {
        for (size_t i = 0; i < ctx->n_points; i++)
            h[i] = p->Km * tex[i][0];
        return;
    }
    for (size_t i = 0; i < ctx->n_points; i++) {
        const float *P = ctx->P[i];
        float q[3] = {P[0] * p->frequency, P[1] * p->frequency, P[2] * p->frequency};
        h[i] = p->Km * sv->noise(sv, q);
    }
}

static void bumpy_displacement(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    displace_by_chunks(sv, ctx, params, out, bumpy_height);
}

static void fractal_displacement(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    const FractalParams *p = params;
    int octaves = p->octaves < 1.0f ? 1 : p->octaves > 16.0f ? 16 : (int)p->octaves;
    for (size_t i = 0; i < ctx->n_points; i++) {
        const float *P = ctx->P[i];
        float q[3] = {P[0] * p->frequency, P[1] * p->frequency, P[2] * p->frequency};
        float h = p->amplitude * sv->fbm(sv, q, octaves, p->lacunarity, p->gain);
        for (int c = 0; c < 3; c++)
            out->P[i][c] = P[c] + h * ctx->N[i][c];
    }
}

typedef struct DisplaceParams {
    float amount;
} DisplaceParams;

/* displace: amount, a constant or a pattern (pbrt's "displacement"). */
static void displace_height(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const void *params, float *h)
{
    shade_param_float(sv, ctx, "amount", ((const DisplaceParams *)params)->amount, h);
}

static void displace_displacement(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out)
{
    displace_by_chunks(sv, ctx, params, out, displace_height);
}

/* A displacement-only class is never shaded; its lighting is black. */
static void unshaded(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                     RayesShadeOutputs *out)
{
    (void)sv, (void)params;
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
    for (size_t i = 0; i < ctx->n_points; i++)
        out->Oi[i][0] = out->Oi[i][1] = out->Oi[i][2] = 1.0f;
    if (out->Irradiance)
        memset(out->Irradiance, 0, ctx->n_points * sizeof *out->Irradiance);
}

static const RayesShaderParamDesc bumpy_params[] = {
    {"Km", RAYES_PARAM_FLOAT, offsetof(BumpyParams, Km), {1, 0, 0}},
    {"frequency", RAYES_PARAM_FLOAT, offsetof(BumpyParams, frequency), {1, 0, 0}},
    {"texturename", RAYES_PARAM_STRING, offsetof(BumpyParams, texturename), {0, 0, 0}},
};

const RayesShaderClass shade_class_bumpy = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "bumpy",
    .params_size = sizeof(BumpyParams),
    .params = bumpy_params,
    .n_params = sizeof bumpy_params / sizeof bumpy_params[0],
    .displacement = bumpy_displacement,
    .lighting = unshaded,
    .diffuselighting = unshaded,
    .flags = RAYES_SHADER_PATH_STRINGS,
};

static const RayesShaderParamDesc fractal_params[] = {
    {"amplitude", RAYES_PARAM_FLOAT, offsetof(FractalParams, amplitude), {1, 0, 0}},
    {"frequency", RAYES_PARAM_FLOAT, offsetof(FractalParams, frequency), {1, 0, 0}},
    {"octaves", RAYES_PARAM_FLOAT, offsetof(FractalParams, octaves), {4, 0, 0}},
    {"lacunarity", RAYES_PARAM_FLOAT, offsetof(FractalParams, lacunarity), {NOISE_LACUNARITY, 0, 0}},
    {"gain", RAYES_PARAM_FLOAT, offsetof(FractalParams, gain), {0.5f, 0, 0}},
};

const RayesShaderClass shade_class_fractal = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "fractal",
    .params_size = sizeof(FractalParams),
    .params = fractal_params,
    .n_params = sizeof fractal_params / sizeof fractal_params[0],
    .displacement = fractal_displacement,
    .lighting = unshaded,
    .diffuselighting = unshaded,
};

static const RayesShaderParamDesc displace_params[] = {
    {"amount", RAYES_PARAM_FLOAT, offsetof(DisplaceParams, amount), {0, 0, 0}},
};

const RayesShaderClass shade_class_displace = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "displace",
    .params_size = sizeof(DisplaceParams),
    .params = displace_params,
    .n_params = sizeof displace_params / sizeof displace_params[0],
    .displacement = displace_displacement,
    .lighting = unshaded,
    .diffuselighting = unshaded,
};

/* ------------------------------------------ services at dicing time */

float shade_service_noise(const RayesShaderServices *sv, const float p[3])
{
    (void)sv;
    return noise3(p[0], p[1], p[2]);
}

float shade_service_fbm(const RayesShaderServices *sv, const float p[3], int octaves,
                      float lacunarity, float gain)
{
    (void)sv;
    return noise_fbm(p, octaves, lacunarity, gain);
}

float shade_service_turbulence(const RayesShaderServices *sv, const float p[3], int octaves,
                             float lacunarity, float gain)
{
    (void)sv;
    return noise_turbulence(p, octaves, lacunarity, gain);
}

float shade_service_checker(const RayesShaderServices *sv, float s, float t, float ds, float dt)
{
    (void)sv;
    return pattern_checker(s, t, ds, dt);
}

static int dice_supports(const RayesShaderServices *sv, const char *service)
{
    if (strcmp(service, "texture") == 0 || strcmp(service, "pattern") == 0)
        return sv->texture != NULL;
    return strcmp(service, "noise") == 0 || strcmp(service, "fbm") == 0 ||
           strcmp(service, "turbulence") == 0 || strcmp(service, "checker") == 0;
}

/* Texture lookups at dicing, filtered over the grid's spacing. */
static int dice_texture(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                        const float *s, const float *t, const float *ds, const float *dt,
                        float (*rgb)[3], float *alpha)
{
    TextureSystem *ts = ((const DicingServices *)(const void *)sv)->textures;
    return shade_texture_service(ts, ctx, name, s, t, ds, dt, rgb, alpha);
}

/* Patterns at dicing, their images filtered over the grid's spacing. */
static int dice_pattern(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const RayesPattern *pattern, float (*out)[3])
{
    TextureSystem *ts = ((const DicingServices *)(const void *)sv)->textures;
    return pattern_eval(pattern, ts, ctx, NULL, NULL, out);
}

int shade_texture_service(TextureSystem *ts, const RayesShadeCtx *ctx, const char *name,
                          const float *s, const float *t, const float *ds, const float *dt,
                          float (*rgb)[3], float *alpha)
{
    if (!ts || !name || !s || !t) {
        memset(rgb, 0, ctx->n_points * sizeof *rgb);
        for (size_t i = 0; alpha && i < ctx->n_points; i++)
            alpha[i] = 1.0f;
        return -1;
    }
    return texture_lookup(ts, name, ctx->n_points, s, t, ds ? ds : ctx->du, dt ? dt : ctx->dv,
                          rgb, alpha);
}

void shade_dicing_services_init(DicingServices *ds, TextureSystem *textures)
{
    ds->sv = shade_dicing_services;
    ds->sv.texture = dice_texture;
    ds->sv.pattern = dice_pattern;
    ds->textures = textures;
}

/* Lighting does not exist yet when displacement runs: those members are NULL. */
const RayesShaderServices shade_dicing_services = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderServices),
    .noise = shade_service_noise,
    .fbm = shade_service_fbm,
    .turbulence = shade_service_turbulence,
    .supports = dice_supports,
    .checker = shade_service_checker,
};
