/*
 * shade/builtin.c — RenderMan's classic surfaces: matte, plastic,
 * paintedplastic, a tinted mirror and constant, and hair, Kajiya-Kay
 * fibres for curves (the others are in builtin_bsdf.c).
 *
 * Each has a separate diffuselighting with exactly the view-independent
 * terms of its lighting: for matte and constant the two are the same; for
 * plastic it drops the highlight; for the mirror it is black (no diffuse
 * lobe). Scratch arrays live on the stack, SHADE_CHUNK points at a time.
 * Parameters follow RenderMan's names and defaults; matte's Ke
 * (incandescence, as in OBJ and pbrt) is an extension used by furnace
 * tests and emissive surfaces seen by diffuse rays.
 */
#include "shade/builtin.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "shade/shade.h"

typedef struct MatteParams {
    float Ka, Kd;
    float Ke[3];
    float normalmap[3]; /* bound to a pattern, or the flat (0.5, 0.5, 1) */
} MatteParams;

typedef struct PlasticParams {
    float Ka, Kd, Ks, roughness;
    float specularcolor[3];
    float normalmap[3];
} PlasticParams;

typedef struct MirrorParams {
    float Kr;
    float specularcolor[3];
} MirrorParams;

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

/* Ci = Cs (Ka ambient + Kd (direct + indirect diffuse)) + emit, on one
 * chunk (ambient is 0 when the services lack it). */
static void diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float Ka,
                          float Kd, const float emit[3], RayesShadeOutputs *out)
{
    float dd[SHADE_CHUNK][3], id[SHADE_CHUNK][3], am[SHADE_CHUNK][3];
    sv->direct_lighting(sv, ctx, 0, NULL, NULL, dd, NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    if (sv->ambient)
        sv->ambient(sv, ctx, am);
    else
        memset(am, 0, sizeof am);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * (Ka * am[i][c] + Kd * (dd[i][c] + id[i][c])) + emit[c];
    if (out->Irradiance)
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++)
                out->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
}

/* Calls fn on SHADE_CHUNK-point slices of ctx and out. */
typedef void (*ChunkFn)(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const void *params, RayesShadeOutputs *out);

/* The same, offsetting ctx->scratch by scratch_size bytes per point. */
static void by_chunks_scratch(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const void *params, RayesShadeOutputs *out, ChunkFn fn,
                              size_t scratch_size)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        if (ctx->scratch)
            sub.scratch = (char *)ctx->scratch + start * scratch_size;
        RayesShadeOutputs o = {out->Ci + start, out->Oi + start,
                               out->Irradiance ? out->Irradiance + start : NULL, NULL};
        float mapped[SHADE_CHUNK][3];
        if (shade_param_bound(&sub, "normalmap")) { /* an OBJ's normal or bump map */
            shade_normal_map(sv, &sub, mapped);
            sub.N = (const float(*)[3])mapped;
        }
        fn(sv, &sub, params, &o);
    }
    set_opacity(ctx, out);
}

static void by_chunks(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                      RayesShadeOutputs *out, ChunkFn fn)
{
    by_chunks_scratch(sv, ctx, params, out, fn, 0);
}

/* ---- matte */

static void matte_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const void *params, RayesShadeOutputs *out)
{
    const MatteParams *p = params;
    diffuse_chunk(sv, ctx, p->Ka, p->Kd, p->Ke, out);
}

static void matte_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, matte_chunk);
}

static const RayesShaderParamDesc matte_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(MatteParams, Ka), {1, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(MatteParams, Kd), {1, 0, 0}},
    {"Ke", RAYES_PARAM_COLOR, offsetof(MatteParams, Ke), {0, 0, 0}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(MatteParams, normalmap), {0.5f, 0.5f, 1.0f}},
};

const RayesShaderClass shade_class_matte = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "matte",
    .params_size = sizeof(MatteParams),
    .params = matte_params,
    .n_params = sizeof matte_params / sizeof matte_params[0],
    .lighting = matte_lighting,
    .diffuselighting = matte_lighting, /* matte is view-independent throughout */
};

void shade_classic_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const float *roughness, float (*diffuse)[3], float (*specular)[3])
{
    if (SHADE_HAS_SERVICE(sv, classic_lighting))
        sv->classic_lighting(sv, ctx, 0, NULL, roughness, diffuse, specular);
    else
        sv->direct_lighting(sv, ctx, 0, NULL, roughness, diffuse, specular);
}

/* ---- plastic */

static void plastic_diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out)
{
    const PlasticParams *p = params;
    static const float black[3] = {0, 0, 0};
    diffuse_chunk(sv, ctx, p->Ka, p->Kd, black, out);
}

static void plastic_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    const PlasticParams *p = params;
    float dd[SHADE_CHUNK][3], id[SHADE_CHUNK][3], ds[SHADE_CHUNK][3], am[SHADE_CHUNK][3];
    float rough[SHADE_CHUNK];
    for (size_t i = 0; i < ctx->n_points; i++)
        rough[i] = p->roughness;
    shade_classic_lighting(sv, ctx, rough, dd, ds); /* one set of shadow rays for both */
    sv->indirect_diffuse(sv, ctx, 0, id);
    if (sv->ambient)
        sv->ambient(sv, ctx, am);
    else
        memset(am, 0, sizeof am);
    float sc[SHADE_CHUNK][3]; /* specularcolor: a constant, or a map (an OBJ's map_Ks) */
    shade_param_color(sv, ctx, "specularcolor", p->specularcolor, sc);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * (p->Ka * am[i][c] + p->Kd * (dd[i][c] + id[i][c])) +
                            sc[i][c] * p->Ks * ds[i][c];
}

static void plastic_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, plastic_chunk);
}

static void plastic_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                    const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, plastic_diffuse_chunk);
}

static const RayesShaderParamDesc plastic_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(PlasticParams, Ka), {1, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(PlasticParams, Kd), {0.5f, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(PlasticParams, Ks), {0.5f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(PlasticParams, roughness), {0.1f, 0, 0}},
    {"specularcolor", RAYES_PARAM_COLOR, offsetof(PlasticParams, specularcolor), {1, 1, 1}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(PlasticParams, normalmap), {0.5f, 0.5f, 1.0f}},
};

const RayesShaderClass shade_class_plastic = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "plastic",
    .params_size = sizeof(PlasticParams),
    .params = plastic_params,
    .n_params = sizeof plastic_params / sizeof plastic_params[0],
    .lighting = plastic_lighting,
    .diffuselighting = plastic_diffuselighting,
};

/* ---- mirror */

static void mirror_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const void *params, RayesShadeOutputs *out)
{
    const MirrorParams *p = params;
    float dir[SHADE_CHUNK][3], L[SHADE_CHUNK][3];
    for (size_t i = 0; i < ctx->n_points; i++) {
        const float *I = ctx->I[i], *N = ctx->N[i];
        float d = 2.0f * (I[0] * N[0] + I[1] * N[1] + I[2] * N[2]);
        for (int c = 0; c < 3; c++)
            dir[i][c] = I[c] - d * N[c];
    }
    sv->indirect_specular(sv, ctx, (const float(*)[3])dir, NULL, 1, L);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = p->Kr * p->specularcolor[c] * L[i][c];
}

static void mirror_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, mirror_chunk);
}

static void black(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                  RayesShadeOutputs *out)
{
    (void)sv;
    (void)params;
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
    if (out->Irradiance)
        memset(out->Irradiance, 0, ctx->n_points * sizeof *out->Irradiance);
    set_opacity(ctx, out);
}

static const RayesShaderParamDesc mirror_params[] = {
    {"Kr", RAYES_PARAM_FLOAT, offsetof(MirrorParams, Kr), {1, 0, 0}},
    {"specularcolor", RAYES_PARAM_COLOR, offsetof(MirrorParams, specularcolor), {1, 1, 1}},
};

const RayesShaderClass shade_class_mirror = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "mirror",
    .params_size = sizeof(MirrorParams),
    .params = mirror_params,
    .n_params = sizeof mirror_params / sizeof mirror_params[0],
    .lighting = mirror_lighting,
    .diffuselighting = black, /* a perfect mirror has no view-independent lobe */
};

/* ---- constant */

static void constant_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const void *params, RayesShadeOutputs *out)
{
    (void)sv;
    (void)params;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c);
    if (out->Irradiance)
        memset(out->Irradiance, 0, ctx->n_points * sizeof *out->Irradiance);
    set_opacity(ctx, out);
}

const RayesShaderClass shade_class_constant = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "constant",
    .lighting = constant_lighting,
    .diffuselighting = constant_lighting,
};

/* ---- defaultsurface
 *
 * RenderMan's default surface, what files that set none are drawn with
 * when they have no lights: Ci = Cs (Ka + Kd (I.N)^2), a headlight-like
 * look by the facing ratio that needs no light. It reflects no light:
 * diffuse rays see it black. */

typedef struct DefaultParams {
    float Ka, Kd;
} DefaultParams;

static void default_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    (void)sv;
    const DefaultParams *p = params;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float d = 0;
        if (ctx->I) {
            const float *I = ctx->I[i], *N = ctx->N[i];
            float ii = I[0] * I[0] + I[1] * I[1] + I[2] * I[2];
            float nn = N[0] * N[0] + N[1] * N[1] + N[2] * N[2];
            if (ii > 0 && nn > 0)
                d = (I[0] * N[0] + I[1] * N[1] + I[2] * N[2]) / sqrtf(ii * nn);
        }
        for (int c = 0; c < 3; c++)
            out->Ci[i][c] = cs(ctx, i, c) * (p->Ka + p->Kd * d * d);
    }
    if (out->Irradiance)
        memset(out->Irradiance, 0, ctx->n_points * sizeof *out->Irradiance);
    set_opacity(ctx, out);
}

static const RayesShaderParamDesc default_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(DefaultParams, Ka), {0.2f, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(DefaultParams, Kd), {0.8f, 0, 0}},
};

const RayesShaderClass shade_class_defaultsurface = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "defaultsurface",
    .params_size = sizeof(DefaultParams),
    .params = default_params,
    .n_params = sizeof default_params / sizeof default_params[0],
    .lighting = default_lighting,
    .diffuselighting = black, /* it reflects no light */
};

/* ---- paintedplastic
 *
 * RenderMan's paintedplastic: Ci = Cs T (Ka ambient + Kd diffuse) +
 * Ks specularcolor specular, T the texture's colour at (s, t) (not
 * multiplied by Os, like plastic here: surfaces are opaque for now). prelighting
 * looks T up once into the scratch (1 without a texture name, or when the
 * texture cannot be read: the surface is then plain plastic), which both
 * lighting and diffuselighting read; diffuselighting drops the highlight. */

typedef struct PaintedPlasticParams {
    float Ka, Kd, Ks, roughness;
    float specularcolor[3];
    float normalmap[3];
    char texturename[RAYES_SHADER_PATH_BYTES];
} PaintedPlasticParams;

typedef struct PaintedScratch {
    float T[3];            /* the texture colour of the point */
} PaintedScratch;

static void painted_prelighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    (void)out;
    const PaintedPlasticParams *p = params;
    PaintedScratch *sc = ctx->scratch;
    int ok = -1;
    if (p->texturename[0] && sv->texture && sv->supports(sv, "texture"))
        ok = sv->texture(sv, ctx, p->texturename, ctx->s, ctx->t, NULL, NULL,
                         (float(*)[3])sc, NULL);
    if (ok != 0)
        for (size_t i = 0; i < ctx->n_points; i++)
            sc[i].T[0] = sc[i].T[1] = sc[i].T[2] = 1.0f;
}

/* Ci = Cs T (Ka ambient + Kd (direct + indirect diffuse)) [+ highlight]. */
static void painted_chunk_common(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const PaintedPlasticParams *p, int highlight,
                                 RayesShadeOutputs *out)
{
    const PaintedScratch *sc = ctx->scratch;
    float dd[SHADE_CHUNK][3], id[SHADE_CHUNK][3], ds[SHADE_CHUNK][3], am[SHADE_CHUNK][3];
    float rough[SHADE_CHUNK];
    for (size_t i = 0; i < ctx->n_points; i++)
        rough[i] = p->roughness;
    highlight = highlight && ctx->I;
    shade_classic_lighting(sv, ctx, rough, dd, highlight ? ds : NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    if (sv->ambient)
        sv->ambient(sv, ctx, am);
    else
        memset(am, 0, sizeof am);
    float spc[SHADE_CHUNK][3]; /* specularcolor: a constant, or a map (an OBJ's map_Ks) */
    if (highlight)
        shade_param_color(sv, ctx, "specularcolor", p->specularcolor, spc);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            float diffuse = p->Ka * am[i][c] + p->Kd * (dd[i][c] + id[i][c]);
            float spec = highlight ? spc[i][c] * p->Ks * ds[i][c] : 0.0f;
            out->Ci[i][c] = cs(ctx, i, c) * sc[i].T[c] * diffuse + spec;
        }
    if (out->Irradiance)
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++)
                out->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
}

static void painted_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    painted_chunk_common(sv, ctx, params, 1, out);
}

static void painted_diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out)
{
    painted_chunk_common(sv, ctx, params, 0, out);
}

static void painted_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    by_chunks_scratch(sv, ctx, params, out, painted_chunk, sizeof(PaintedScratch));
}

static void painted_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                    const void *params, RayesShadeOutputs *out)
{
    by_chunks_scratch(sv, ctx, params, out, painted_diffuse_chunk, sizeof(PaintedScratch));
}

static const RayesShaderParamDesc painted_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(PaintedPlasticParams, Ka), {1, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(PaintedPlasticParams, Kd), {0.5f, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(PaintedPlasticParams, Ks), {0.5f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(PaintedPlasticParams, roughness), {0.1f, 0, 0}},
    {"specularcolor", RAYES_PARAM_COLOR, offsetof(PaintedPlasticParams, specularcolor), {1, 1, 1}},
    {"texturename", RAYES_PARAM_STRING, offsetof(PaintedPlasticParams, texturename), {0, 0, 0}},
    {"normalmap", RAYES_PARAM_COLOR, offsetof(PaintedPlasticParams, normalmap), {0.5f, 0.5f, 1.0f}},
};

const RayesShaderClass shade_class_paintedplastic = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "paintedplastic",
    .params_size = sizeof(PaintedPlasticParams),
    .params = painted_params,
    .n_params = sizeof painted_params / sizeof painted_params[0],
    .prelighting = painted_prelighting,
    .lighting = painted_lighting,
    .diffuselighting = painted_diffuselighting,
    .scratch_size = sizeof(PaintedScratch),
    .flags = RAYES_SHADER_PATH_STRINGS,
};

/* ---- hair: Kajiya-Kay fibres (direct_fiber), for curves */

typedef PlasticParams HairParams; /* the same parameters, other defaults */

/* Ci = Cs (Ka ambient + Kd (fibre diffuse + indirect diffuse)), plus the
 * highlight when spec is wanted. The tangent is dPdu (along a curve);
 * indirect light is gathered over the hemisphere of N (on curves the
 * side that faces the camera), an approximation of a fibre's sphere.
 * Without direct_fiber (an older renderer) it is plastic. */
static void hair_terms(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const HairParams *p, int spec, RayesShadeOutputs *out)
{
    float dd[SHADE_CHUNK][3], id[SHADE_CHUNK][3], ds[SHADE_CHUNK][3], am[SHADE_CHUNK][3];
    float rough[SHADE_CHUNK], T[SHADE_CHUNK][3];
    for (size_t i = 0; i < ctx->n_points; i++) {
        rough[i] = p->roughness;
        for (int c = 0; c < 3; c++)
            T[i][c] = ctx->dPdu ? ctx->dPdu[i][c] : 0.0f;
    }
    if (sv->direct_fiber && ctx->dPdu)
        sv->direct_fiber(sv, ctx, 0, NULL, (const float(*)[3])T, rough, dd, spec ? ds : NULL);
    else
        sv->direct_lighting(sv, ctx, 0, NULL, rough, dd, spec ? ds : NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    if (sv->ambient)
        sv->ambient(sv, ctx, am);
    else
        memset(am, 0, sizeof am);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Ci[i][c] = cs(ctx, i, c) * (p->Ka * am[i][c] + p->Kd * (dd[i][c] + id[i][c]));
            if (spec)
                out->Ci[i][c] += p->specularcolor[c] * p->Ks * ds[i][c];
        }
    if (out->Irradiance)
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++)
                out->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
}

static void hair_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const void *params, RayesShadeOutputs *out)
{
    hair_terms(sv, ctx, params, 1, out);
}

static void hair_diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    hair_terms(sv, ctx, params, 0, out);
}

static void hair_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, hair_chunk);
}

static void hair_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, hair_diffuse_chunk);
}

static const RayesShaderParamDesc hair_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(HairParams, Ka), {1, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(HairParams, Kd), {0.6f, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(HairParams, Ks), {0.3f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(HairParams, roughness), {0.05f, 0, 0}},
    {"specularcolor", RAYES_PARAM_COLOR, offsetof(HairParams, specularcolor), {1, 1, 1}},
};

const RayesShaderClass shade_class_hair = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "hair",
    .params_size = sizeof(HairParams),
    .params = hair_params,
    .n_params = sizeof hair_params / sizeof hair_params[0],
    .lighting = hair_lighting,
    .diffuselighting = hair_diffuselighting,
};
