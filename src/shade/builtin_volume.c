/*
 * shade/builtin_volume.c — built-in volume shaders (memo 6.1: "the
 * opacity returned by a shader is interpreted as the volume extinction
 * coefficients"): homogeneous, and turbulence, the memo's Figure 9 medium
 * whose extinction is a turbulence function of five octaves of noise.
 *
 * Both: opacity() = sigma_t = density * extinction (RGB, per unit
 * length), times turbulence's pattern; density may be bound to a pattern
 * (a densitygrid or nanovdb grid, shade_param_float), negative values
 * read as 0; lighting() = sigma_s * (the direct
 * light the phase function scatters toward the viewer, the direct_volume
 * service) + density * emission, sigma_s = albedo * sigma_t. Volume points
 * carry their position in the box in u, v and s (0 to 1).
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "shade/builtin.h"
#include "shade/shade.h"

typedef float Rgb[3];

typedef struct VolumeParams {
    float density;
    float extinction[3]; /* sigma_t per unit density (pbrt's sigma_a + sigma_s) */
    float albedo[3];     /* sigma_s / sigma_t */
    float g;             /* Henyey-Greenstein asymmetry */
    float emission[3];   /* emitted radiance per unit length and density */
    float frequency;     /* turbulence only: the noise's frequency in world units */
    float octaves;
    float falloff;       /* turbulence only: 1 fades the density to 0 at the box's inscribed
                            sphere (a puff), 0 fills the box */
} VolumeParams;

/* The density pattern at point i: 1 for homogeneous media. */
typedef float (*DensityFn)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                           const VolumeParams *p);

static float uniform_density(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                             const VolumeParams *p)
{
    (void)sv, (void)ctx, (void)i, (void)p;
    return 1.0f;
}

/* The memo's medium: turbulence (|noise| summed over octaves) at the
 * point's world position, optionally faded toward the box's edges. */
static float turbulence_density(const RayesShaderServices *sv, const RayesShadeCtx *ctx, size_t i,
                                const VolumeParams *p)
{
    float q[3] = {ctx->P[i][0] * p->frequency, ctx->P[i][1] * p->frequency,
                  ctx->P[i][2] * p->frequency};
    float turb = sv->turbulence ? sv->turbulence(sv, q, (int)p->octaves, 2.0f, 0.5f) : 0.5f;
    float fade = 1.0f;
    if (p->falloff > 0.0f && ctx->u && ctx->v && ctx->s) {
        float dx = ctx->u[i] - 0.5f, dy = ctx->v[i] - 0.5f, dz = ctx->s[i] - 0.5f;
        float r = 2.0f * sqrtf(dx * dx + dy * dy + dz * dz); /* 1 at the inscribed sphere */
        float edge = fminf(fmaxf((1.0f - r) / 0.5f, 0.0f), 1.0f);
        fade = 1.0f - p->falloff + p->falloff * edge * edge * (3.0f - 2.0f * edge);
    }
    return fmaxf(0.0f, 2.0f * turb - 0.3f) * fade;
}

/* sigma_t at ctx's points into out: density (a constant, or the pattern
 * bound to "density") times fn's pattern times extinction. */
static void extinction(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const VolumeParams *p, DensityFn fn, Rgb *out)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        float density[SHADE_CHUNK];
        shade_ctx_slice(ctx, start, n, &sub);
        shade_param_float(sv, &sub, "density", p->density, density);
        for (size_t i = 0; i < n; i++) {
            float d = fmaxf(density[i], 0.0f) * fn(sv, &sub, i, p);
            for (int c = 0; c < 3; c++)
                out[start + i][c] = d * p->extinction[c];
        }
    }
}

static void volume_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const VolumeParams *p, DensityFn fn, RayesShadeOutputs *out)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        Rgb sigma[SHADE_CHUNK], light[SHADE_CHUNK];
        extinction(sv, &sub, p, fn, sigma);
        int lit = sv->direct_volume && (p->albedo[0] > 0 || p->albedo[1] > 0 || p->albedo[2] > 0);
        if (lit)
            sv->direct_volume(sv, &sub, 0, NULL, p->g, light);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                float d = p->extinction[c] > 0.0f ? sigma[i][c] / p->extinction[c] : 0.0f;
                out->Ci[start + i][c] =
                    (lit ? p->albedo[c] * sigma[i][c] * light[i][c] : 0.0f) + d * p->emission[c];
                out->Oi[start + i][c] = sigma[i][c];
                if (out->Irradiance)
                    out->Irradiance[start + i][c] = 0.0f;
            }
    }
}

static void homogeneous_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    extinction(sv, ctx, params, uniform_density, out->Oi);
}

static void homogeneous_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    volume_lighting(sv, ctx, params, uniform_density, out);
}

static void turbulence_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    extinction(sv, ctx, params, turbulence_density, out->Oi);
}

static void turbulence_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    volume_lighting(sv, ctx, params, turbulence_density, out);
}

#define VOLUME_COMMON_PARAMS                                                                  \
    {"density", RAYES_PARAM_FLOAT, offsetof(VolumeParams, density), {1, 0, 0}},               \
        {"extinction", RAYES_PARAM_COLOR, offsetof(VolumeParams, extinction), {1, 1, 1}},     \
        {"albedo", RAYES_PARAM_COLOR, offsetof(VolumeParams, albedo), {0.8f, 0.8f, 0.8f}},    \
        {"g", RAYES_PARAM_FLOAT, offsetof(VolumeParams, g), {0, 0, 0}},                       \
        {"emission", RAYES_PARAM_COLOR, offsetof(VolumeParams, emission), {0, 0, 0}}

static const RayesShaderParamDesc homogeneous_params[] = {VOLUME_COMMON_PARAMS};

const RayesShaderClass shade_class_homogeneous = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "homogeneous",
    .params_size = sizeof(VolumeParams),
    .params = homogeneous_params,
    .n_params = sizeof homogeneous_params / sizeof homogeneous_params[0],
    .opacity = homogeneous_opacity,
    .lighting = homogeneous_lighting,
    .diffuselighting = homogeneous_lighting,
};

static const RayesShaderParamDesc turbulence_params[] = {
    VOLUME_COMMON_PARAMS,
    {"frequency", RAYES_PARAM_FLOAT, offsetof(VolumeParams, frequency), {1, 0, 0}},
    {"octaves", RAYES_PARAM_FLOAT, offsetof(VolumeParams, octaves), {5, 0, 0}},
    {"falloff", RAYES_PARAM_FLOAT, offsetof(VolumeParams, falloff), {1, 0, 0}},
};

const RayesShaderClass shade_class_turbulence = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "turbulence",
    .params_size = sizeof(VolumeParams),
    .params = turbulence_params,
    .n_params = sizeof turbulence_params / sizeof turbulence_params[0],
    .opacity = turbulence_opacity,
    .lighting = turbulence_lighting,
    .diffuselighting = turbulence_lighting,
};
