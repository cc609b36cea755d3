/*
 * shade/builtin_opacity.c — built-in shaders about opacity (memo 6.1):
 * stainedglass, whose opacity method colours shadows, thindielectric
 * (pbrt-v4's thin glass: a sheet light passes straight through),
 * occlusion, RenderMan's classic ambient occlusion shader, and glow, the
 * RenderMan Companion's halo.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "shade/bsdf.h"
#include "shade/builtin.h"
#include "shade/shade.h"

typedef float Rgb[3];

/* Oi = Os times the shader's own opacity (NULL: 1), and Ci premultiplied
 * by it (RenderMan's Ci *= Oi). */
static void premultiply(const RayesShadeCtx *ctx, const Rgb *own, RayesShadeOutputs *out)
{
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            float os = ctx->Os ? ctx->Os[i][c] : 1.0f;
            out->Oi[i][c] = os * (own ? own[i][c] : 1.0f);
            out->Ci[i][c] *= out->Oi[i][c];
        }
}

/* ---- stainedglass
 *
 * Panes of coloured glass held by lead came, over (s, t): frequency cells
 * per unit, their borders bent by noise; each pane has a hue of its own
 * and a clarity that varies with five octaves of noise (bubbles and
 * streaks in the glass). The lead's edges are box filtered over the
 * point's footprint (du, dv), as a production shader antialiases them, so
 * that the opacity cache's vertices, a level's spacing apart, average the
 * lead instead of point-sampling it. The opacity method returns 1 - the
 * pane's transmission colour (lead: 1), so shadow rays through it are
 * coloured; lighting reflects Kd times the pane's colour, premultiplied. */

typedef struct StainedGlassParams {
    float Kd, frequency, leadwidth, clarity;
} StainedGlassParams;

/* A hue of cell (i, j): a saturated colour. */
static void cell_colour(int i, int j, float rgb[3])
{
    uint32_t h = (uint32_t)i * 73856093u ^ (uint32_t)j * 19349663u;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    float hue = (float)(h & 0xffffu) / 65536.0f * 6.0f;
    int k = (int)hue;
    float f = hue - (float)k;
    float v[6][3] = {{1, f, 0}, {1 - f, 1, 0}, {0, 1, f}, {0, 1 - f, 1}, {f, 0, 1}, {1, 0, 1 - f}};
    for (int c = 0; c < 3; c++)
        rgb[c] = 0.15f + 0.85f * v[k % 6][c];
}

/* The mean over [x - fw / 2, x + fw / 2] of a pulse train of period 1
 * that is 1 on [k, k + w) (Apodaca and Gritz's filteredpulsetrain): box
 * filtered, so that a grid of points spaced fw apart sees the lead's true
 * share whatever its width. */
static float filtered_pulse_train(float w, float x, float fw)
{
    if (!(fw > 1e-6f)) {
        float f = x - floorf(x);
        return f < w ? 1.0f : 0.0f;
    }
    float x0 = x - 0.5f * fw, x1 = x + 0.5f * fw;
    float i0 = floorf(x0) * w + fminf(x0 - floorf(x0), w);
    float i1 = floorf(x1) * w + fminf(x1 - floorf(x1), w);
    return fminf(fmaxf((i1 - i0) / fw, 0.0f), 1.0f);
}

/* The panes' hues box-filtered over a footprint fw cells wide about (x,
 * y): each cell's colour weighted by its overlap (at most 8 x 8 cells;
 * wider footprints take the hues' mean, 0.575, for the rest). */
static void filtered_hue(float x, float y, float fw, float out[3])
{
    if (!(fw > 1e-3f)) {
        cell_colour((int)floorf(x), (int)floorf(y), out);
        return;
    }
    float span = fminf(fw, 8.0f), x0 = x - 0.5f * span, y0 = y - 0.5f * span;
    float sum[3] = {0, 0, 0}, rgb[3];
    for (float cy = floorf(y0); cy < y0 + span; cy += 1.0f) {
        float wy = fminf(cy + 1.0f, y0 + span) - fmaxf(cy, y0);
        for (float cx = floorf(x0); cx < x0 + span; cx += 1.0f) {
            float wx = fminf(cx + 1.0f, x0 + span) - fmaxf(cx, x0);
            cell_colour((int)cx, (int)cy, rgb);
            for (int c = 0; c < 3; c++)
                sum[c] += wx * wy * rgb[c];
        }
    }
    float mix = fw > 8.0f ? 1.0f - 64.0f / (fw * fw) : 0.0f;
    for (int c = 0; c < 3; c++)
        out[c] = sum[c] / (span * span) * (1.0f - mix) + 0.575f * mix;
}

/* The transmission colour at (s, t), over a footprint of fw in (s, t): 0
 * on the lead, else the pane's hue scaled by its clarity, the lead's
 * edges box filtered over the footprint. */
static void glass_transmission(const RayesShaderServices *sv, const StainedGlassParams *p, float s,
                               float t, float fw, float out[3])
{
    float q[3] = {s * p->frequency, t * p->frequency, 0.0f};
    float warp[3] = {q[0] * 0.7f, q[1] * 0.7f, 3.1f};
    float x = q[0] + 0.35f * sv->noise(sv, warp);
    warp[2] = 7.3f;
    float y = q[1] + 0.35f * sv->noise(sv, warp);
    /* lead of width lw (in cells) centred on the cells' borders */
    float lw = p->leadwidth * p->frequency, fwc = fw * p->frequency;
    float clear = (1.0f - filtered_pulse_train(lw, x + 0.5f * lw, fwc)) *
                  (1.0f - filtered_pulse_train(lw, y + 0.5f * lw, fwc));
    if (!(clear > 0.0f)) {
        out[0] = out[1] = out[2] = 0.0f;
        return;
    }
    /* Streaks finer than the footprint average out. */
    float hue[3], fade = fmaxf(0.0f, 1.0f - 8.0f * fwc);
    filtered_hue(x, y, fwc, hue);
    float bubbles[3] = {q[0] * 8.0f, q[1] * 8.0f, 0.5f};
    float streak = sv->fbm ? fade * sv->fbm(sv, bubbles, 5, 2.0f, 0.5f) : 0.0f;
    float clarity = clear * fminf(fmaxf(p->clarity * (1.0f + 0.3f * streak), 0.0f), 1.0f);
    for (int c = 0; c < 3; c++)
        out[c] = hue[c] * clarity;
}

/* The footprint of point i, the larger of du and dv (0 without them): in
 * (s, t) as in (u, v), as patches without their own s and t have them. */
static float footprint(const RayesShadeCtx *ctx, size_t i)
{
    if (ctx->du && ctx->dv)
        return fmaxf(ctx->du[i], ctx->dv[i]);
    return 0.0f;
}

static void stainedglass_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                 const void *params, RayesShadeOutputs *out)
{
    const StainedGlassParams *p = params;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float T[3];
        glass_transmission(sv, p, ctx->s ? ctx->s[i] : ctx->u[i], ctx->t ? ctx->t[i] : ctx->v[i],
                           footprint(ctx, i), T);
        for (int c = 0; c < 3; c++)
            out->Oi[i][c] = (ctx->Os ? ctx->Os[i][c] : 1.0f) * (1.0f - T[c]);
    }
}

/* One chunk of stainedglass's lighting (points of ctx, at most
 * SHADE_CHUNK). */
static void stainedglass_chunk(const RayesShaderServices *sv, const RayesShadeCtx *sub,
                               const void *params, RayesShadeOutputs *o)
{
    const StainedGlassParams *p = params;
    Rgb dd[SHADE_CHUNK], id[SHADE_CHUNK], own[SHADE_CHUNK];
    sv->direct_lighting(sv, sub, 0, NULL, NULL, dd, NULL);
    sv->indirect_diffuse(sv, sub, 0, id);
    for (size_t i = 0; i < sub->n_points; i++) {
        float T[3];
        glass_transmission(sv, p, sub->s ? sub->s[i] : sub->u[i], sub->t ? sub->t[i] : sub->v[i],
                           footprint(sub, i), T);
        for (int c = 0; c < 3; c++) {
            /* the lead is dark grey; glass reflects a little of its hue */
            float colour = T[c] > 0.0f ? T[c] : 0.05f;
            own[i][c] = 1.0f - T[c];
            o->Ci[i][c] = p->Kd * colour * (dd[i][c] + id[i][c]);
            if (o->Irradiance)
                o->Irradiance[i][c] = 3.14159265f * (dd[i][c] + id[i][c]);
        }
    }
    premultiply(sub, (const Rgb *)own, o);
}

static void stainedglass_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                  const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, stainedglass_chunk);
}

static const RayesShaderParamDesc stainedglass_params[] = {
    {"Kd", RAYES_PARAM_FLOAT, offsetof(StainedGlassParams, Kd), {0.5f, 0, 0}},
    {"frequency", RAYES_PARAM_FLOAT, offsetof(StainedGlassParams, frequency), {4, 0, 0}},
    {"leadwidth", RAYES_PARAM_FLOAT, offsetof(StainedGlassParams, leadwidth), {0.03f, 0, 0}},
    {"clarity", RAYES_PARAM_FLOAT, offsetof(StainedGlassParams, clarity), {0.8f, 0, 0}},
};

const RayesShaderClass shade_class_stainedglass = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "stainedglass",
    .params_size = sizeof(StainedGlassParams),
    .params = stainedglass_params,
    .n_params = sizeof stainedglass_params / sizeof stainedglass_params[0],
    .opacity = stainedglass_opacity,
    .lighting = stainedglass_lighting,
    .diffuselighting = stainedglass_lighting, /* view-independent throughout */
};

/* ---- thindielectric
 *
 * pbrt-v4's thin dielectric: a sheet of glass of index eta (a window) that
 * light crosses unbent. Its two faces reflect R' = R + T^2 R / (1 - R^2)
 * = 2 R / (1 + R) in all (R Fresnel's reflectance at the view angle, T =
 * 1 - R), and the rest passes straight on. So it is a partly transparent
 * surface: Oi = R', Ci = R' times the mirrored radiance, and the renderer
 * composites what lies behind by 1 - R'. Shadow rays and cached diffuse
 * rays take the opacity method's R' at normal incidence (view-independent:
 * 0.077 for eta 1.5): sunlight and skylight come in through windows. */

typedef struct ThinDielectricParams {
    float eta;
} ThinDielectricParams;

static float thin_reflectance(float cos_i, float eta)
{
    float R = fresnel_dielectric(fminf(fmaxf(cos_i, 1e-4f), 1.0f), eta);
    return 2.0f * R / (1.0f + R);
}

static void thindielectric_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                   const void *params, RayesShadeOutputs *out)
{
    (void)sv;
    const ThinDielectricParams *p = params;
    float R = thin_reflectance(1.0f, p->eta);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out->Oi[i][c] = (ctx->Os ? ctx->Os[i][c] : 1.0f) * R;
}

/* One chunk of thindielectric's lighting. */
static void thindielectric_chunk(const RayesShaderServices *sv, const RayesShadeCtx *sub,
                                 const void *params, RayesShadeOutputs *o)
{
    const ThinDielectricParams *p = params;
    size_t n = sub->n_points;
    Rgb own[SHADE_CHUNK], dir[SHADE_CHUNK], L[SHADE_CHUNK];
    float R0 = thin_reflectance(1.0f, p->eta);
    for (size_t i = 0; i < n; i++) {
        float R = R0;
        if (sub->I) { /* the mirror direction and Fresnel at the view angle */
            Vec3 V = v3(-sub->I[i][0], -sub->I[i][1], -sub->I[i][2]);
            Vec3 N = v3(sub->N[i][0], sub->N[i][1], sub->N[i][2]);
            float c = v3_dot(V, N);
            Vec3 r = v3_sub(v3_scale(N, 2.0f * c), V);
            dir[i][0] = r.x, dir[i][1] = r.y, dir[i][2] = r.z;
            R = thin_reflectance(c, p->eta);
        }
        own[i][0] = own[i][1] = own[i][2] = R;
    }
    if (sub->I && sv->indirect_specular)
        sv->indirect_specular(sv, sub, (const float(*)[3])dir, NULL, 1, L);
    else
        memset(L, 0, n * sizeof *L);
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            o->Ci[i][c] = L[i][c];
            if (o->Irradiance)
                o->Irradiance[i][c] = 0.0f;
        }
    premultiply(sub, (const Rgb *)own, o);
}

static void thindielectric_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                                    const void *params, RayesShadeOutputs *out)
{
    shade_chunks(sv, ctx, params, out, thindielectric_chunk);
}

static const RayesShaderParamDesc thindielectric_params[] = {
    {"eta", RAYES_PARAM_FLOAT, offsetof(ThinDielectricParams, eta), {1.5f, 0, 0}},
};

const RayesShaderClass shade_class_thindielectric = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "thindielectric",
    .params_size = sizeof(ThinDielectricParams),
    .params = thindielectric_params,
    .n_params = sizeof thindielectric_params / sizeof thindielectric_params[0],
    .opacity = thindielectric_opacity,
    .lighting = thindielectric_lighting,
    .diffuselighting = thindielectric_lighting, /* no I: no reflection, R' at normal incidence */
};

/* ---- occlusion
 *
 * RenderMan's classic ambient occlusion shader: Ci = Cs (1 - occlusion),
 * occlusion from the occlusion service with `samples` rays (0: the
 * renderer's diffuse ray count) within `maxdist` (0: any distance).
 * Transparent surfaces occlude by their opacity. */

typedef struct OcclusionParams {
    float samples, maxdist;
} OcclusionParams;

static void occlusion_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const void *params, RayesShadeOutputs *out)
{
    const OcclusionParams *p = params;
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        Rgb occ[SHADE_CHUNK];
        if (sv->occlusion)
            sv->occlusion(sv, &sub, (int)p->samples, p->maxdist, occ);
        else
            memset(occ, 0, n * sizeof *occ);
        for (size_t i = 0; i < n; i++)
            for (int c = 0; c < 3; c++) {
                out->Ci[start + i][c] = (sub.Cs ? sub.Cs[i][c] : 1.0f) * (1.0f - occ[i][c]);
                if (out->Irradiance)
                    out->Irradiance[start + i][c] = 0.0f;
            }
    }
    premultiply(ctx, NULL, out);
}

static const RayesShaderParamDesc occlusion_params[] = {
    {"samples", RAYES_PARAM_FLOAT, offsetof(OcclusionParams, samples), {0, 0, 0}},
    {"maxdist", RAYES_PARAM_FLOAT, offsetof(OcclusionParams, maxdist), {0, 0, 0}},
};

const RayesShaderClass shade_class_occlusion = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "occlusion",
    .params_size = sizeof(OcclusionParams),
    .params = occlusion_params,
    .n_params = sizeof occlusion_params / sizeof occlusion_params[0],
    .lighting = occlusion_lighting,
    .diffuselighting = occlusion_lighting,
};

/* ---- glow
 *
 * The RenderMan Companion's glow (Listing 16.26), a halo on a sphere about
 * a light bulb: seen face on it is Cs and opaque, toward its rim it fades
 * as cos^(2 attenuation) of the view to the normal, and its far side is
 * clear. It is a picture of light, not matter: its opacity method and its
 * diffuselighting are clear, so it casts no shadow and diffuse rays pass
 * it (it lights nothing either; a light inside it does). */

typedef struct GlowParams {
    float attenuation;
} GlowParams;

static void glow_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out)
{
    (void)sv;
    const GlowParams *p = params;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float f = 0.0f; /* RSL: (I.N)^2 / (I.I N.N), to the attenuation, where I.N < 0 */
        if (ctx->I && !(ctx->backfacing && ctx->backfacing[i])) {
            const float *I = ctx->I[i], *N = ctx->N[i];
            float in = I[0] * N[0] + I[1] * N[1] + I[2] * N[2];
            float ii = I[0] * I[0] + I[1] * I[1] + I[2] * I[2];
            float nn = N[0] * N[0] + N[1] * N[1] + N[2] * N[2];
            if (in < 0.0f && ii > 0.0f && nn > 0.0f)
                f = powf(in * in / (ii * nn), p->attenuation);
        }
        for (int c = 0; c < 3; c++) {
            out->Oi[i][c] = (ctx->Os ? ctx->Os[i][c] : 1.0f) * f;
            out->Ci[i][c] = (ctx->Cs ? ctx->Cs[i][c] : 1.0f) * out->Oi[i][c];
        }
    }
}

/* Clear and black: what shadow rays and diffuse rays see of a glow. */
static void glow_clear(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                       RayesShadeOutputs *out)
{
    (void)sv, (void)params;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Ci[i][c] = 0.0f;
            out->Oi[i][c] = 0.0f;
            if (out->Irradiance)
                out->Irradiance[i][c] = 0.0f;
        }
}

static const RayesShaderParamDesc glow_params[] = {
    {"attenuation", RAYES_PARAM_FLOAT, offsetof(GlowParams, attenuation), {2, 0, 0}},
};

const RayesShaderClass shade_class_glow = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderClass),
    .name = "glow",
    .params_size = sizeof(GlowParams),
    .params = glow_params,
    .n_params = sizeof glow_params / sizeof glow_params[0],
    .opacity = glow_clear,
    .lighting = glow_lighting,
    .diffuselighting = glow_clear,
};
