/*
 * shade/mix.c — the "mix" shader: two materials of any classes blended by
 * an amount that may vary over the surface (pbrt-v4's MixMaterial; a
 * layered look such as gold inlay in a painted surface, masked by a
 * texture).
 *
 * Its two materials are instances of their own (the children the scene
 * gives it with shade_instance_adopt: the parameters "a" and "b" name their
 * classes, and a parameter "a:NAME" or "b:NAME" is NAME of that material,
 * bound to a pattern as any other). Every method runs both materials'
 * methods on the same points, each with its own pattern bindings and
 * scratch, and blends what they give point by point: Ci, Oi and
 * (opacity) Oi as (1 - amount) a + amount b. Where amount is 0 (or 1) on
 * every point of a chunk, only a (or b) runs. pbrt picks one of the two
 * per shading point at random with probability amount; the blend is that
 * choice's expectation, without its noise. The irradiance a subsurface
 * child's diffuselighting gives is the last child's (not blended).
 */
#include <stddef.h>
#include <string.h>

#include "shade/builtin.h"
#include "shade/shade.h"

typedef struct MixParams {
    const ShaderInstance *children; /* first (SHADE_CLASS_CHILDREN): a, b */
    float amount;                   /* 0: a alone, 1: b alone */
    char a[64], b[64];              /* their classes, as the scene was given them */
} MixParams;

static const RayesShaderParamDesc mix_params[] = {
    {"amount", RAYES_PARAM_FLOAT, offsetof(MixParams, amount), {0.5f, 0, 0}},
    {"a", RAYES_PARAM_STRING, offsetof(MixParams, a), {0, 0, 0}},
    {"b", RAYES_PARAM_STRING, offsetof(MixParams, b), {0, 0, 0}},
};

/* The random dimension a mix draws its child with (past the branch depth). */
#define MIX_DIMENSION 0x6d697800u

typedef void (*RunFn)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                      const ShaderInstance *inst, RayesShadeOutputs *out);

/* One chunk: run each child that some point weighs (its own outputs),
 * then blend into out; Oi only for opacity (opacity_only). */
static void mix_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                      const MixParams *p, RayesShadeOutputs *out, RunFn run, int opacity_only)
{
    size_t n = ctx->n_points;
    float amount[SHADE_CHUNK];
    shade_param_float(sv, ctx, "amount", p->amount, amount);
    int any[2] = {0, 0};
    for (size_t i = 0; i < n; i++) {
        amount[i] = amount[i] < 0.0f ? 0.0f : amount[i] > 1.0f ? 1.0f : amount[i];
        any[0] |= amount[i] < 1.0f;
        any[1] |= amount[i] > 0.0f;
    }
    /* each child starts from what the renderer put in out (Oi = Os: a
     * method that leaves Oi alone is as opaque as the surface) */
    float Ci[2][SHADE_CHUNK][3], Oi[2][SHADE_CHUNK][3];
    for (int k = 0; k < 2; k++) {
        memcpy(Ci[k], out->Ci, n * sizeof *out->Ci);
        memcpy(Oi[k], out->Oi, n * sizeof *out->Oi);
    }
    RayesShadeCtx sub = *ctx;
    sub.scratch = NULL; /* each child's own (the run functions make it) */
    /* Past the branch depth a path follows one lobe: a mix lit whose points
     * all draw the same child (one point, as a path's hit is) runs that child
     * alone, weight 1 (chosen with probability amount, the estimate is the
     * blend's). Running both made each specular bounce of a mix two paths:
     * 2^depth of them in a mix of coated materials at maxdepth 15. */
    if (run == shade_run_lighting && any[0] && any[1] && p->children && !shade_branches(sv, ctx)) {
        int pick = -1;
        for (size_t i = 0; i < n && pick != 2; i++) {
            int k = sv->random(sv, ctx, i, MIX_DIMENSION) < amount[i];
            pick = pick < 0 || pick == k ? k : 2;
        }
        if (pick == 0 || pick == 1) {
            for (size_t i = 0; i < n; i++)
                amount[i] = (float)pick;
            any[1 - pick] = 0;
        }
    }
    for (int k = 0; k < 2; k++) {
        if (!any[k] || !p->children)
            continue;
        RayesShadeOutputs o = {Ci[k], Oi[k], out->Irradiance, NULL};
        run(sv, &sub, &p->children[k], &o);
    }
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float w = amount[i];
            if (!opacity_only)
                out->Ci[i][c] = (1.0f - w) * Ci[0][i][c] + w * Ci[1][i][c];
            out->Oi[i][c] = (1.0f - w) * Oi[0][i][c] + w * Oi[1][i][c];
        }
}

static void lighting_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    mix_chunk(sv, ctx, params, out, shade_run_lighting, 0);
}

static void diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    mix_chunk(sv, ctx, params, out, shade_run_diffuselighting, 0);
}

static void opacity_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    mix_chunk(sv, ctx, params, out, shade_run_opacity, 1);
}

static void mix_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, lighting_chunk);
}

static void mix_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, diffuse_chunk);
}

static void mix_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, opacity_chunk);
}

const RayesShaderClass shade_class_mix = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "mix",
    .params_size = sizeof(MixParams),
    .params = mix_params,
    .n_params = sizeof mix_params / sizeof mix_params[0],
    .opacity = mix_opacity,
    .lighting = mix_lighting,
    .diffuselighting = mix_diffuselighting,
    .flags = SHADE_CLASS_CHILDREN,
};
