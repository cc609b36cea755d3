/*
 * examples/shaders/noisydisplace.c — a fractal noise displacement with a
 * matte surface, as a rayes shader plugin (the memo's procedural
 * displacement: technical digest, section 5).
 *
 *   displacement     P += N * Km * fbm(P * frequency, octaves, 1.99, 0.5),
 *                    the noise from the renderer's fbm service (the same
 *                    value on every thread and machine);
 *   lighting         matte: Kd * Cs * (direct + indirect diffuse), which is
 *                    view-independent, so it is diffuselighting too.
 *
 * Km is in the scene's units (world space), frequency in cycles per unit.
 * Written against rayes/shader.h only.
 */
#include <stddef.h>

#include "chunk.h"
#include "rayes/shader.h"

#define LACUNARITY 1.99f /* the digest's octave frequency ratio */
#define GAIN 0.5f

typedef struct NoisyParams {
    float Km;        /* amplitude, scene units */
    float frequency; /* of the first octave, per scene unit */
    float octaves;   /* rounded to an integer in [1, 16] */
    float Kd;
} NoisyParams;

static int octave_count(float octaves)
{
    int n = (int)(octaves + 0.5f);
    return n < 1 ? 1 : n > 16 ? 16 : n;
}

static void noisy_displacement(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    const NoisyParams *p = params;
    int octaves = octave_count(p->octaves);
    for (size_t i = 0; i < ctx->n_points; i++) {
        float q[3] = {ctx->P[i][0] * p->frequency, ctx->P[i][1] * p->frequency,
                      ctx->P[i][2] * p->frequency};
        float h = sv->fbm ? p->Km * sv->fbm(sv, q, octaves, LACUNARITY, GAIN) : 0.0f;
        for (int c = 0; c < 3; c++)
            out->P[i][c] = ctx->P[i][c] + h * ctx->N[i][c];
    }
}

static void matte_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const NoisyParams *p, RayesShadeOutputs *out)
{
    float dd[CHUNK][3], id[CHUNK][3];
    sv->direct_lighting(sv, ctx, 0, NULL, NULL, dd, NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            float cs = ctx->Cs ? ctx->Cs[i][c] : 1.0f;
            out->Oi[i][c] = ctx->Os ? ctx->Os[i][c] : 1.0f;
            out->Ci[i][c] = out->Oi[i][c] * p->Kd * cs * (dd[i][c] + id[i][c]);
            if (out->Irradiance)
                out->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
        }
}

static void noisy_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    for (size_t start = 0; start < ctx->n_points; start += CHUNK) {
        RayesShadeCtx sub;
        chunk_ctx(ctx, 0, start, chunk_size(ctx, start), &sub);
        RayesShadeOutputs o = chunk_out(out, start);
        matte_chunk(sv, &sub, params, &o);
    }
}

static const RayesShaderParamDesc noisy_params[] = {
    {"Km", RAYES_PARAM_FLOAT, offsetof(NoisyParams, Km), {0.1f, 0, 0}},
    {"frequency", RAYES_PARAM_FLOAT, offsetof(NoisyParams, frequency), {1, 0, 0}},
    {"octaves", RAYES_PARAM_FLOAT, offsetof(NoisyParams, octaves), {4, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(NoisyParams, Kd), {1, 0, 0}},
};

static const RayesShaderClass noisydisplace_class = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "noisydisplace",
    .params_size = sizeof(NoisyParams),
    .params = noisy_params,
    .n_params = sizeof noisy_params / sizeof noisy_params[0],
    .displacement = noisy_displacement,
    .lighting = noisy_lighting,
    .diffuselighting = noisy_lighting, /* matte is view-independent throughout */
};

RAYES_API const RayesShaderClass *rayes_shader_entry(void)
{
    return &noisydisplace_class;
}
