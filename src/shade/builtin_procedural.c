/*
 * shade/builtin_procedural.c — procedural surfaces of realistic cost for
 * production-like scenes (the production-room scene, issue 21):
 *
 *   wood       wood grain (rings about an axis, perturbed by fbm, with fine
 *              fibres) under a varnish: plastic-like, the highlight weighted
 *              by Schlick's Fresnel; optional planks (a floor), each plank
 *              its own piece of wood with dark gaps between them
 *   brickwall  bricks in running bond, a colour per brick, grit and soot
 *              from fbm, mortar joints; its displacement method recesses the
 *              mortar and roughens the faces, so the same class serves as
 *              the wall's displacement (rayes_scene_set_displacement)
 *
 * Both lay their pattern out in world space, not (s, t), so walls and
 * floors made of several patches show one seamless pattern: wood's axis
 * is a parameter, brickwall runs along x + z with rows up y (walls facing
 * along x or z). The pattern colour is computed once per point in
 * prelighting into scratch and read by lighting and by the
 * view-independent diffuselighting (which drops the highlight), as the
 * memo's shaders do. Noise comes through the services (sv->noise, sv->fbm),
 * as a plugin's would; methods run SHADE_CHUNK points at a time.
 */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "shade/builtin.h"
#include "shade/shade.h"

typedef struct WoodParams {
    float Ka, Kd, Ks, roughness;
    float Clight[3], Cdark[3]; /* early and late wood */
    float ringscale;           /* rings per world unit of radius */
    float grainscale;          /* frequency of the ring's wobble, per world unit */
    float grainamp;            /* the wobble, in rings */
    float axis;                /* 0, 1, 2: the trunk runs along x, y or z */
    float plankwidth;          /* world units across the trunk's axis; 0: no planks */
    float planklength;         /* world units along it (staggered ends) */
    float gapwidth;            /* world units of dark gap between planks */
} WoodParams;

typedef struct BrickParams {
    float Ka, Kd, Ks, roughness;
    float Cbrick[3], Cmortar[3];
    float brickwidth, brickheight, mortarthickness; /* world units */
    float variation;                                /* spread of the brick colours, 0..1 */
    float mortardepth;  /* displacement: how far the mortar is recessed */
    float roughnessamp; /* displacement: fbm roughness of the faces */
} BrickParams;

typedef struct ColourScratch {
    float C[3]; /* the pattern's colour at the point */
} ColourScratch;

static float clampf(float x, float a, float b)
{
    return x < a ? a : x > b ? b : x;
}

static float smooth(float a, float b, float x)
{
    float t = clampf((x - a) / (b - a), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

/* A number in [0, 1) from two integers (a brick's or plank's identity). */
static float cell_hash(int a, int b)
{
    uint32_t h = (uint32_t)a * 0x8da6b343u ^ (uint32_t)b * 0xd8163841u;
    h ^= h >> 15;
    h *= 0x2c1b3c6du;
    h ^= h >> 12;
    h *= 0x297a2d39u;
    h ^= h >> 15;
    return (float)(h >> 8) / 16777216.0f;
}

/* ---- the lighting both share: C (Ka ambient + Kd diffuse) + Ks F spec */

static void coat_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float Ka, float Kd,
                       float Ks, float roughness, int highlight, RayesShadeOutputs *out)
{
    const ColourScratch *sc = ctx->scratch;
    float dd[SHADE_CHUNK][3], id[SHADE_CHUNK][3], ds[SHADE_CHUNK][3], am[SHADE_CHUNK][3];
    float rough[SHADE_CHUNK];
    for (size_t i = 0; i < ctx->n_points; i++)
        rough[i] = roughness;
    highlight = highlight && ctx->I && Ks > 0.0f;
    sv->direct_lighting(sv, ctx, 0, NULL, rough, dd, highlight ? ds : NULL);
    sv->indirect_diffuse(sv, ctx, 0, id);
    if (sv->ambient)
        sv->ambient(sv, ctx, am);
    else
        memset(am, 0, sizeof am);
    for (size_t i = 0; i < ctx->n_points; i++) {
        float F = 0.0f;
        if (highlight) { /* Schlick, for a varnish of index 1.5 (F0 = 0.04): the
                            highlight is Ks at normal incidence, 4 Ks grazing */
            const float *I = ctx->I[i], *N = ctx->N[i];
            float c = clampf(-(I[0] * N[0] + I[1] * N[1] + I[2] * N[2]), 0.0f, 1.0f);
            float m = 1.0f - c;
            F = 0.04f + 0.96f * m * m * m * m * m;
        }
        for (int c = 0; c < 3; c++) {
            float base = (ctx->Cs ? ctx->Cs[i][c] : 1.0f) * sc[i].C[c] *
                         (Ka * am[i][c] + Kd * (dd[i][c] + id[i][c]));
            out->Ci[i][c] =
                base + (highlight ? Ks * (1.0f + 3.0f * (F - 0.04f) / 0.96f) * ds[i][c] : 0.0f);
        }
    }
    if (out->Irradiance)
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++)
                out->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
}

typedef void (*ChunkFn)(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                        RayesShadeOutputs *out);

/* Calls fn on SHADE_CHUNK-point slices of ctx, the scratch sliced along;
 * then Oi = Os and Ci premultiplied by it. */
static void by_chunks(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                      RayesShadeOutputs *out, ChunkFn fn)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        if (ctx->scratch)
            sub.scratch = (ColourScratch *)ctx->scratch + start;
        RayesShadeOutputs o = {out->Ci + start, out->Oi + start,
                               out->Irradiance ? out->Irradiance + start : NULL, NULL};
        fn(sv, &sub, params, &o);
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Oi[i][c] = ctx->Os ? ctx->Os[i][c] : 1.0f;
            out->Ci[i][c] *= out->Oi[i][c];
        }
}

/* ---- wood */

/* The wood colour at world point P. */
static void wood_colour(const RayesShaderServices *sv, const WoodParams *p, const float P[3],
                        float C[3])
{
    int ax = (int)clampf(p->axis, 0.0f, 2.0f);
    float along = P[ax], a = P[(ax + 1) % 3], b = P[(ax + 2) % 3];
    float gap = 0.0f, tone = 1.0f;
    float cx = 0.0f, cy = 0.0f; /* the trunk's centre, in (a, b) */
    if (p->plankwidth > 0.0f) {
        /* planks across a (the width), their ends staggered along the axis */
        float fa = a / p->plankwidth;
        int row = (int)floorf(fa);
        float len = p->planklength > 0.0f ? p->planklength : 1e9f;
        float fl = along / len + cell_hash(row, 7);
        int col = (int)floorf(fl);
        float ea = (fa - (float)row) * p->plankwidth, el = (fl - (float)col) * len;
        float gw = p->gapwidth;
        gap = gw > 0.0f ? 1.0f - smooth(0.0f, gw, ea) * smooth(0.0f, gw, p->plankwidth - ea) *
                                     smooth(0.0f, gw, el) * smooth(0.0f, gw, len - el)
                        : 0.0f;
        /* each plank cut from its own log: a centre below the board */
        cx = ((float)row + 0.5f) * p->plankwidth + (cell_hash(row, col) - 0.5f) * 0.6f;
        cy = -0.3f - 0.5f * cell_hash(col, row + 31);
        along += 17.0f * cell_hash(row, col + 5);
        tone = 0.8f + 0.4f * cell_hash(col + 11, row); /* each board its own shade */
    }
    float q[3] = {along * p->grainscale * 0.25f, a * p->grainscale, b * p->grainscale};
    float wobble = p->grainamp * sv->fbm(sv, q, 4, 1.99f, 0.5f);
    float da = a - cx, db = b - cy;
    float r = sqrtf(da * da + db * db) * p->ringscale + wobble;
    r -= floorf(r);
    float ring = smooth(0.0f, 0.8f, r) - smooth(0.83f, 1.0f, r);
    float f[3] = {along * 5.0f * p->grainscale, a * 40.0f * p->grainscale,
                  b * 40.0f * p->grainscale};
    float fibre = 0.85f + 0.15f * sv->noise(sv, f);
    for (int c = 0; c < 3; c++) {
        float w = p->Clight[c] + (p->Cdark[c] - p->Clight[c]) * ring;
        C[c] = w * tone * fibre * (1.0f - 0.85f * gap);
    }
}

static void wood_prelighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                             const void *params, RayesShadeOutputs *out)
{
    (void)out;
    ColourScratch *sc = ctx->scratch;
    for (size_t i = 0; i < ctx->n_points; i++)
        wood_colour(sv, params, ctx->P[i], sc[i].C);
}

static void wood_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                       RayesShadeOutputs *out)
{
    const WoodParams *p = params;
    coat_chunk(sv, ctx, p->Ka, p->Kd, p->Ks, p->roughness, 1, out);
}

static void wood_diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    const WoodParams *p = params;
    coat_chunk(sv, ctx, p->Ka, p->Kd, p->Ks, p->roughness, 0, out);
}

static void wood_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, wood_chunk);
}

static void wood_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, wood_diffuse_chunk);
}

static const RayesShaderParamDesc wood_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(WoodParams, Ka), {1, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(WoodParams, Kd), {1, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(WoodParams, Ks), {0.3f, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(WoodParams, roughness), {0.05f, 0, 0}},
    {"Clight", RAYES_PARAM_COLOR, offsetof(WoodParams, Clight), {0.62f, 0.42f, 0.24f}},
    {"Cdark", RAYES_PARAM_COLOR, offsetof(WoodParams, Cdark), {0.36f, 0.2f, 0.09f}},
    {"ringscale", RAYES_PARAM_FLOAT, offsetof(WoodParams, ringscale), {40, 0, 0}},
    {"grainscale", RAYES_PARAM_FLOAT, offsetof(WoodParams, grainscale), {4, 0, 0}},
    {"grainamp", RAYES_PARAM_FLOAT, offsetof(WoodParams, grainamp), {1.5f, 0, 0}},
    {"axis", RAYES_PARAM_FLOAT, offsetof(WoodParams, axis), {0, 0, 0}},
    {"plankwidth", RAYES_PARAM_FLOAT, offsetof(WoodParams, plankwidth), {0, 0, 0}},
    {"planklength", RAYES_PARAM_FLOAT, offsetof(WoodParams, planklength), {2, 0, 0}},
    {"gapwidth", RAYES_PARAM_FLOAT, offsetof(WoodParams, gapwidth), {0.003f, 0, 0}},
};

const RayesShaderClass shade_class_wood = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "wood",
    .params_size = sizeof(WoodParams),
    .params = wood_params,
    .n_params = sizeof wood_params / sizeof wood_params[0],
    .prelighting = wood_prelighting,
    .lighting = wood_lighting,
    .diffuselighting = wood_diffuselighting,
    .scratch_size = sizeof(ColourScratch),
};

/* ---- brickwall */

/* Where P falls in the bond: *mortar in [0, 1] (1 in a joint), the brick's
 * row and column. */
static void brick_cell(const BrickParams *p, const float P[3], float *mortar, int *row, int *col)
{
    float s = (P[0] + P[2]) / p->brickwidth, t = P[1] / p->brickheight;
    *row = (int)floorf(t);
    if (*row & 1)
        s += 0.5f;
    *col = (int)floorf(s);
    float es = (s - (float)*col) * p->brickwidth, et = (t - (float)*row) * p->brickheight;
    float h = 0.5f * p->mortarthickness, e = 0.3f * p->mortarthickness;
    float in_s = smooth(h - e, h + e, es) * smooth(h - e, h + e, p->brickwidth - es);
    float in_t = smooth(h - e, h + e, et) * smooth(h - e, h + e, p->brickheight - et);
    *mortar = 1.0f - in_s * in_t;
}

static void brick_colour(const RayesShaderServices *sv, const BrickParams *p, const float P[3],
                         float C[3])
{
    float mortar;
    int row, col;
    brick_cell(p, P, &mortar, &row, &col);
    float v = (cell_hash(row, col) - 0.5f) * 2.0f * p->variation;
    float q[3] = {P[0] * 40.0f, P[1] * 40.0f, P[2] * 40.0f};
    float grit = sv->fbm(sv, q, 5, 1.99f, 0.5f);
    float r[3] = {P[0] * 2.0f, P[1] * 3.0f, P[2] * 2.0f};
    float soot = clampf(0.5f + 0.8f * sv->fbm(sv, r, 3, 1.99f, 0.5f), 0.0f, 1.0f);
    for (int c = 0; c < 3; c++) {
        float b = p->Cbrick[c] * (1.0f + v) * (0.85f + 0.25f * grit) * (0.7f + 0.3f * soot);
        float m = p->Cmortar[c] * (0.9f + 0.2f * grit);
        C[c] = clampf(b + (m - b) * mortar, 0.0f, 1.0f);
    }
}

static void brick_prelighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                              const void *params, RayesShadeOutputs *out)
{
    (void)out;
    ColourScratch *sc = ctx->scratch;
    for (size_t i = 0; i < ctx->n_points; i++)
        brick_colour(sv, params, ctx->P[i], sc[i].C);
}

static void brick_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                        RayesShadeOutputs *out)
{
    const BrickParams *p = params;
    coat_chunk(sv, ctx, p->Ka, p->Kd, p->Ks, p->roughness, 1, out);
}

static void brick_diffuse_chunk(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                const void *params, RayesShadeOutputs *out)
{
    const BrickParams *p = params;
    coat_chunk(sv, ctx, p->Ka, p->Kd, p->Ks, p->roughness, 0, out);
}

static void brick_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                           const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, brick_chunk);
}

static void brick_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out)
{
    by_chunks(sv, ctx, params, out, brick_diffuse_chunk);
}

/* The mortar sinks by mortardepth, the faces are roughened by fbm. */
static void brick_displacement(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    const BrickParams *p = params;
    for (size_t i = 0; i < ctx->n_points; i++) {
        const float *P = ctx->P[i];
        float mortar;
        int row, col;
        brick_cell(p, P, &mortar, &row, &col);
        float q[3] = {P[0] * 25.0f, P[1] * 25.0f, P[2] * 25.0f};
        float h = -p->mortardepth * mortar + p->roughnessamp * sv->fbm(sv, q, 4, 1.99f, 0.5f);
        for (int c = 0; c < 3; c++)
            out->P[i][c] = P[c] + h * ctx->N[i][c];
    }
}

static const RayesShaderParamDesc brick_params[] = {
    {"Ka", RAYES_PARAM_FLOAT, offsetof(BrickParams, Ka), {1, 0, 0}},
    {"Kd", RAYES_PARAM_FLOAT, offsetof(BrickParams, Kd), {1, 0, 0}},
    {"Ks", RAYES_PARAM_FLOAT, offsetof(BrickParams, Ks), {0, 0, 0}},
    {"roughness", RAYES_PARAM_FLOAT, offsetof(BrickParams, roughness), {0.2f, 0, 0}},
    {"Cbrick", RAYES_PARAM_COLOR, offsetof(BrickParams, Cbrick), {0.55f, 0.2f, 0.12f}},
    {"Cmortar", RAYES_PARAM_COLOR, offsetof(BrickParams, Cmortar), {0.62f, 0.6f, 0.55f}},
    {"brickwidth", RAYES_PARAM_FLOAT, offsetof(BrickParams, brickwidth), {0.215f, 0, 0}},
    {"brickheight", RAYES_PARAM_FLOAT, offsetof(BrickParams, brickheight), {0.075f, 0, 0}},
    {"mortarthickness", RAYES_PARAM_FLOAT, offsetof(BrickParams, mortarthickness), {0.01f, 0, 0}},
    {"variation", RAYES_PARAM_FLOAT, offsetof(BrickParams, variation), {0.15f, 0, 0}},
    {"mortardepth", RAYES_PARAM_FLOAT, offsetof(BrickParams, mortardepth), {0.006f, 0, 0}},
    {"roughnessamp", RAYES_PARAM_FLOAT, offsetof(BrickParams, roughnessamp), {0.0015f, 0, 0}},
};

const RayesShaderClass shade_class_brickwall = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "brickwall",
    .params_size = sizeof(BrickParams),
    .params = brick_params,
    .n_params = sizeof brick_params / sizeof brick_params[0],
    .displacement = brick_displacement,
    .prelighting = brick_prelighting,
    .lighting = brick_lighting,
    .diffuselighting = brick_diffuselighting,
    .scratch_size = sizeof(ColourScratch),
};
