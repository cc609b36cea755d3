/*
 * examples/shaders/brick.c — a procedural brick wall, the RenderMan
 * Companion's classic (Upstill 1990), as a rayes shader plugin.
 *
 * In texture space (s, t), bricks of brickwidth x brickheight are laid in
 * rows with mortarthickness of mortar between them, every other row
 * shifted by half a brick. The pattern is box-filtered over the point's
 * footprint (du, dv; 0 when the renderer gives none), so distant walls
 * turn to the average colour instead of aliasing.
 *
 *   prelighting      the colour Cs * mix(Cmortar, Cbrick, brick fraction),
 *                    into the point's scratch (illumination-independent);
 *   lighting         Kd * colour * (direct + indirect diffuse)
 *                    + Ks * (Blinn-Phong highlight of roughness);
 *   diffuselighting  the same without the highlight (view-independent).
 *
 * Written against rayes/shader.h only; everything else comes through the
 * services table.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "chunk.h"
#include "rayes/shader.h"

typedef struct BrickParams {
    float Kd, Ks, roughness;
    float brickwidth, brickheight, mortarthickness; /* texture-space units */
    float Cbrick[3], Cmortar[3];
} BrickParams;

typedef struct BrickScratch {
    float colour[3]; /* Cs times the filtered brick/mortar colour */
} BrickScratch;

/* The integral from 0 to x of a pulse train of period 1 that is 1 on
 * [m, 1 - m] of every period. */
static float pulse_integral(float x, float m)
{
    float f = floorf(x);
    float in = x - f - m;
    in = in < 0.0f ? 0.0f : in > 1.0f - 2.0f * m ? 1.0f - 2.0f * m : in;
    return f * (1.0f - 2.0f * m) + in;
}

/* The pulse train box-filtered over [x - w/2, x + w/2]. */
static float filtered_pulse(float x, float w, float m)
{
    if (!(w > 1e-6f)) {
        float f = x - floorf(x);
        return f >= m && f < 1.0f - m ? 1.0f : 0.0f;
    }
    return (pulse_integral(x + 0.5f * w, m) - pulse_integral(x - 0.5f * w, m)) / w;
}

/* The fraction of the footprint at (s, t) that is brick. */
static float brick_fraction(const BrickParams *p, float s, float t, float ds, float dt)
{
    float bw = p->brickwidth + p->mortarthickness, bh = p->brickheight + p->mortarthickness;
    if (!(bw > 0.0f) || !(bh > 0.0f))
        return 1.0f;
    float mw = 0.5f * p->mortarthickness / bw, mh = 0.5f * p->mortarthickness / bh;
    float ss = s / bw, tt = t / bh;
    float row = 0.5f * tt;
    if (row - floorf(row) >= 0.5f)
        ss += 0.5f; /* odd rows are shifted by half a brick */
    return filtered_pulse(ss, fabsf(ds) / bw, mw) * filtered_pulse(tt, fabsf(dt) / bh, mh);
}

/* Writes the brick colour of every point to out (n_points colours). */
static void brick_colours(const RayesShadeCtx *ctx, const BrickParams *p, float (*out)[3])
{
    for (size_t i = 0; i < ctx->n_points; i++) {
        float s = ctx->s ? ctx->s[i] : ctx->u ? ctx->u[i] : 0.0f;
        float t = ctx->t ? ctx->t[i] : ctx->v ? ctx->v[i] : 0.0f;
        float ds = ctx->du ? ctx->du[i] : 0.0f, dt = ctx->dv ? ctx->dv[i] : 0.0f;
        float f = brick_fraction(p, s, t, ds, dt);
        for (int c = 0; c < 3; c++) {
            float cs = ctx->Cs ? ctx->Cs[i][c] : 1.0f;
            out[i][c] = cs * (p->Cmortar[c] + f * (p->Cbrick[c] - p->Cmortar[c]));
        }
    }
}

static void brick_prelighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const void *params, RayesShadeOutputs *out)
{
    (void)sv, (void)out;
    if (!ctx->scratch)
        return; /* lighting then computes the colour itself */
    for (size_t start = 0; start < ctx->n_points; start += CHUNK) {
        RayesShadeCtx sub;
        chunk_ctx(ctx, sizeof(BrickScratch), start, chunk_size(ctx, start), &sub);
        float colour[CHUNK][3];
        brick_colours(&sub, params, colour);
        BrickScratch *scratch = sub.scratch;
        for (size_t i = 0; i < sub.n_points; i++)
            memcpy(scratch[i].colour, colour[i], sizeof colour[i]);
    }
}

/* One chunk of lighting (highlight != 0) or diffuselighting. */
static void brick_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const BrickParams *p, int highlight, RayesShadeOutputs *out)
{
    size_t n = ctx->n_points;
    float colour[CHUNK][3], dd[CHUNK][3], id[CHUNK][3], spec[CHUNK][3], rough[CHUNK];
    if (ctx->scratch) {
        const BrickScratch *scratch = ctx->scratch;
        for (size_t i = 0; i < n; i++)
            memcpy(colour[i], scratch[i].colour, sizeof colour[i]);
    } else {
        brick_colours(ctx, p, colour);
    }
    highlight = highlight && p->Ks != 0.0f && ctx->I;
    for (size_t i = 0; i < CHUNK; i++)
        rough[i] = p->roughness > 1e-4f ? p->roughness : 1e-4f;
    sv->direct_lighting(sv, ctx, 0, NULL, rough, dd, highlight ? spec : NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            float diffuse = dd[i][c] + id[i][c];
            out->Oi[i][c] = ctx->Os ? ctx->Os[i][c] : 1.0f;
            out->Ci[i][c] = out->Oi[i][c] * (p->Kd * colour[i][c] * diffuse +
                                             (highlight ? p->Ks * spec[i][c] : 0.0f));
            if (out->Irradiance)
                out->Irradiance[i][c] = 3.14159265f * diffuse;
        }
}

static void brick_run(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                      RayesShadeOutputs *out, int highlight)
{
    for (size_t start = 0; start < ctx->n_points; start += CHUNK) {
        RayesShadeCtx sub;
        chunk_ctx(ctx, sizeof(BrickScratch), start, chunk_size(ctx, start), &sub);
        RayesShadeOutputs o = chunk_out(out, start);
        brick_chunk(sv, &sub, params, highlight, &o);
    }
}

static void brick_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    brick_run(sv, ctx, params, out, 1);
}

static void brick_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out)
{
    brick_run(sv, ctx, params, out, 0);
}

static const RayesShaderParamDesc brick_params[] = {
    {"Kd", RAYES_PARAM_FLOAT, offsetof(BrickParams, Kd), {1, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(BrickParams, Ks), {0, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(BrickParams, roughness), {0.1f, 0, 0}},
    {"brickwidth", RAYES_PARAM_FLOAT, offsetof(BrickParams, brickwidth), {0.25f, 0, 0}},
    {"brickheight", RAYES_PARAM_FLOAT, offsetof(BrickParams, brickheight), {0.08f, 0, 0}},
    {"mortarthickness", RAYES_PARAM_FLOAT, offsetof(BrickParams, mortarthickness), {0.01f, 0, 0}},
    {"Cbrick", RAYES_PARAM_COLOR, offsetof(BrickParams, Cbrick), {0.5f, 0.15f, 0.14f}},
    {"Cmortar", RAYES_PARAM_COLOR, offsetof(BrickParams, Cmortar), {0.5f, 0.5f, 0.5f}},
};

static const RayesShaderClass brick_class = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "brick",
    .params_size = sizeof(BrickParams),
    .params = brick_params,
    .n_params = sizeof brick_params / sizeof brick_params[0],
    .prelighting = brick_prelighting,
    .lighting = brick_lighting,
    .diffuselighting = brick_diffuselighting,
    .scratch_size = sizeof(BrickScratch),
};

RAYES_API const RayesShaderClass *rayes_shader_entry(void)
{
    return &brick_class;
}
