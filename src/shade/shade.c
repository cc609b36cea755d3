/*
 * shade/shade.c — parameter blocks and method dispatch with the fallbacks
 * of DESIGN.md (the classes are found by registry.c). Thread-safe:
 * instances are read-only after shade_instance_init. Scratch for classes that ask for it
 * is allocated per method run (simple; a per-thread arena would avoid the
 * allocation, and must then nest, since lighting traces rays that shade).
 */
#include "shade/shade.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "util/log.h"
#include "util/vec.h"

static const RayesShaderParamDesc *find_param(const RayesShaderClass *cls, const char *name)
{
    for (size_t i = 0; i < cls->n_params; i++)
        if (strcmp(cls->params[i].name, name) == 0)
            return &cls->params[i];
    return NULL;
}

static void set_param(const RayesShaderClass *cls, void *block, const RayesShaderParamDesc *d,
                      RayesParamType type, const float value[3], const char *string)
{
    char *at = (char *)block + d->offset;
    size_t bytes = shade_string_bytes(cls);
    if (d->type == RAYES_PARAM_FLOAT)
        memcpy(at, value, sizeof(float));
    else if (d->type == RAYES_PARAM_COLOR) {
        float c[3] = {value[0], type == RAYES_PARAM_FLOAT ? value[0] : value[1],
                      type == RAYES_PARAM_FLOAT ? value[0] : value[2]};
        memcpy(at, c, sizeof c);
    } else if (d->type == RAYES_PARAM_STRING &&
               (size_t)snprintf(at, bytes, "%s", string ? string : "") >= bytes) {
        char key[96];
        snprintf(key, sizeof key, "long:%s:%s", cls->name, d->name);
        log_warning_once(key,
                         "shader \"%s\" parameter \"%s\": \"%.40s...\" is longer than %zu "
                         "characters; cut",
                         cls->name, d->name, string, bytes - 1);
    }
}

int shade_instance_apply(ShaderInstance *inst, const RayesParam *params, size_t n_params,
                         int strict, char *err, size_t err_size)
{
    const RayesShaderClass *cls = inst->cls;
    for (size_t i = 0; i < n_params; i++) {
        if (params[i].type == RAYES_PARAM_PATTERN)
            continue; /* bound by shade_instance_bind */
        const RayesShaderParamDesc *d = find_param(cls, params[i].name);
        int ok = d && (d->type == params[i].type ||
                       (d->type == RAYES_PARAM_COLOR && params[i].type == RAYES_PARAM_FLOAT));
        if (!ok && strict) {
            snprintf(err, err_size, d ? "shader \"%s\" parameter \"%s\" has another type"
                                      : "shader \"%s\" has no parameter \"%s\"",
                     cls->name, params[i].name);
            return -1;
        }
        if (!ok) {
            char key[96];
            snprintf(key, sizeof key, "param:%s:%s", cls->name, params[i].name);
            log_warning_once(key, d ? "shader \"%s\" parameter \"%s\" has the wrong type; ignored"
                                    : "shader \"%s\" has no parameter \"%s\"; ignored",
                             cls->name, params[i].name);
            continue;
        }
        set_param(cls, inst->params, d, params[i].type, params[i].value, params[i].string);
    }
    return 0;
}

int shade_instance_init(ShaderInstance *inst, const RayesShaderClass *cls,
                        const RayesParam *params, size_t n_params, char *err, size_t err_size)
{
    inst->cls = cls;
    inst->patterns = NULL;
    inst->n_patterns = 0;
    inst->children = NULL;
    inst->n_children = 0;
    inst->params = calloc(1, cls->params_size ? cls->params_size : 1);
    if (!inst->params) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    for (size_t i = 0; i < cls->n_params; i++)
        set_param(cls, inst->params, &cls->params[i], cls->params[i].type,
                  cls->params[i].default_value, "");
    return shade_instance_apply(inst, params, n_params, 0, err, err_size);
}

void shade_instance_fini(ShaderInstance *inst)
{
    free(inst->params);
    inst->params = NULL;
    free(inst->patterns);
    inst->patterns = NULL;
    inst->n_patterns = 0;
    for (size_t i = 0; i < inst->n_children; i++)
        shade_instance_fini(&inst->children[i]);
    free(inst->children);
    inst->children = NULL;
    inst->n_children = 0;
}

void shade_instance_adopt(ShaderInstance *inst, ShaderInstance *children, size_t n)
{
    inst->children = children;
    inst->n_children = n;
    if (shade_class_flags(inst->cls) & SHADE_CLASS_CHILDREN)
        memcpy(inst->params, &inst->children, sizeof inst->children);
}

int shade_instance_has_opacity(const ShaderInstance *inst)
{
    if (!inst || !inst->cls)
        return 0;
    if (!(shade_class_flags(inst->cls) & SHADE_CLASS_CHILDREN))
        return inst->cls->opacity != NULL;
    for (size_t i = 0; i < inst->n_children; i++)
        if (shade_instance_has_opacity(&inst->children[i]))
            return 1;
    return 0;
}

uint32_t shade_instance_flags(const ShaderInstance *inst)
{
    uint32_t f = inst ? shade_class_flags(inst->cls) & ~SHADE_CLASS_CHILDREN : 0u;
    for (size_t i = 0; inst && i < inst->n_children; i++)
        f |= shade_instance_flags(&inst->children[i]);
    return f;
}

int shade_instance_bind(ShaderInstance *inst, const char *name, const RayesPattern *pattern,
                        char *err, size_t err_size)
{
    const RayesShaderParamDesc *d = find_param(inst->cls, name);
    if (!d || (d->type != RAYES_PARAM_FLOAT && d->type != RAYES_PARAM_COLOR)) {
        snprintf(err, err_size,
                 d ? "shader \"%s\" parameter \"%s\" is not a float or colour; it cannot take "
                     "a pattern"
                   : "shader \"%s\" has no parameter \"%s\"",
                 inst->cls->name, name);
        return -1;
    }
    for (size_t i = 0; i < inst->n_patterns; i++)
        if (strcmp(inst->patterns[i].param, d->name) == 0) {
            inst->patterns[i].pattern = pattern;
            return 0;
        }
    RayesPatternBinding *b = realloc(inst->patterns, (inst->n_patterns + 1) * sizeof *b);
    if (!b) {
        snprintf(err, err_size, "out of memory");
        return -1;
    }
    inst->patterns = b;
    b[inst->n_patterns++] = (RayesPatternBinding){d->name, pattern};
    return 0;
}

static const RayesPattern *bound(const RayesShadeCtx *ctx, const char *name)
{
    for (size_t i = 0; ctx->patterns && i < ctx->n_patterns; i++)
        if (strcmp(ctx->patterns[i].param, name) == 0)
            return ctx->patterns[i].pattern;
    return NULL;
}

int shade_param_bound(const RayesShadeCtx *ctx, const char *name)
{
    return bound(ctx, name) != NULL;
}

/* The shading normals of a normal map (pbrt-v4's "normalmap": a linear
 * image whose texel n = 2 rgb - 1 is in the frame of x = dP/ds, z = N,
 * y = z cross x; the pattern "normalmap" holds it): dP/ds from dPdu, dPdv
 * and the texture coordinates' derivatives (ctx->dst; without them s is u),
 * made perpendicular to N. A mapped normal that turns away from the
 * geometric normal keeps N. */
void shade_normal_map(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3])
{
    static const float flat[3] = {0.5f, 0.5f, 1.0f};
    float tex[SHADE_CHUNK][3];
    shade_param_color(sv, ctx, "normalmap", flat, tex);
    for (size_t i = 0; i < ctx->n_points; i++) {
        Vec3 N = v3_load(ctx->N[i]), du = v3_load(ctx->dPdu[i]), dv = v3_load(ctx->dPdv[i]),
             dPds = du;
        if (ctx->dst) { /* [ds dt] = J [du dv]: dP/ds = (dt/dv dPdu - dt/du dPdv) / det J */
            const float *j = ctx->dst[i];
            float det = j[0] * j[3] - j[1] * j[2];
            if (fabsf(det) > 1e-20f)
                dPds = v3_scale(v3_sub(v3_scale(du, j[3]), v3_scale(dv, j[2])), 1.0f / det);
        }
        Vec3 T = v3_sub(dPds, v3_scale(N, v3_dot(N, dPds)));
        float len = v3_length(T);
        Vec3 m = N;
        if (len > 0.0f && isfinite(len)) {
            T = v3_scale(T, 1.0f / len);
            Vec3 B = v3_cross(N, T);
            Vec3 n = v3(2.0f * tex[i][0] - 1.0f, 2.0f * tex[i][1] - 1.0f, 2.0f * tex[i][2] - 1.0f);
            m = v3_normalize(v3_add(v3_add(v3_scale(T, n.x), v3_scale(B, n.y)), v3_scale(N, n.z)));
            Vec3 Ng = ctx->Ng ? v3_load(ctx->Ng[i]) : N;
            if (!(v3_dot(m, Ng) > 0.0f) || !isfinite(m.x + m.y + m.z))
                m = N;
        }
        out[i][0] = m.x, out[i][1] = m.y, out[i][2] = m.z;
    }
}

void shade_param_color(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                       const float value[3], float (*out)[3])
{
    const RayesPattern *p = bound(ctx, name);
    if (p && SHADE_HAS_SERVICE(sv, pattern)) {
        sv->pattern(sv, ctx, p, out);
        return;
    }
    for (size_t i = 0; i < ctx->n_points; i++)
        memcpy(out[i], value, sizeof out[i]);
}

void shade_param_float(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                       float value, float *out)
{
    const RayesPattern *p = bound(ctx, name);
    if (!p || !SHADE_HAS_SERVICE(sv, pattern)) {
        for (size_t i = 0; i < ctx->n_points; i++)
            out[i] = value;
        return;
    }
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        float rgb[SHADE_CHUNK][3];
        shade_ctx_slice(ctx, start, n, &sub);
        sv->pattern(sv, &sub, p, rgb);
        for (size_t i = 0; i < n; i++)
            out[start + i] = rgb[i][0];
    }
}

void shade_ctx_slice(const RayesShadeCtx *ctx, size_t start, size_t count, RayesShadeCtx *sub)
{
    *sub = *ctx;
    sub->n_points = count;
    sub->first_point = ctx->first_point + start;
#define SLICE(f)                                  \
    if (ctx->f)                                   \
        sub->f = ctx->f + start;
    SLICE(P)
    SLICE(N) SLICE(Ng) SLICE(dPdu) SLICE(dPdv) SLICE(u) SLICE(v) SLICE(s) SLICE(t) SLICE(du)
        SLICE(dv) SLICE(I) SLICE(Cs) SLICE(Os) SLICE(backfacing) SLICE(dst)
#undef SLICE
}

void shade_chunks(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                  RayesShadeOutputs *out, ShadeChunkFn fn)
{
    for (size_t start = 0; start < ctx->n_points; start += SHADE_CHUNK) {
        size_t n = ctx->n_points - start < SHADE_CHUNK ? ctx->n_points - start : SHADE_CHUNK;
        RayesShadeCtx sub;
        shade_ctx_slice(ctx, start, n, &sub);
        RayesShadeOutputs o = {out->Ci + start, out->Oi + start,
                               out->Irradiance ? out->Irradiance + start : NULL, NULL};
        fn(sv, &sub, params, &o);
    }
}

void shade_chunks_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const void *params, RayesShadeOutputs *out, ShadeChunkFn fn)
{
    shade_chunks(sv, ctx, params, out, fn);
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Oi[i][c] = ctx->Os ? ctx->Os[i][c] : 1.0f;
            out->Ci[i][c] *= out->Oi[i][c];
        }
}

void shade_ctx_turned(const RayesShadeCtx *ctx, float (*N)[3], float (*Ng)[3], RayesShadeCtx *back)
{
    *back = *ctx;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            N[i][c] = -ctx->N[i][c];
            Ng[i][c] = -(ctx->Ng ? ctx->Ng : ctx->N)[i][c];
        }
    back->N = (const float(*)[3])N;
    back->Ng = (const float(*)[3])Ng;
}

/* Scratch for a call on ctx's points, if the class needs it and the caller
 * gave none: n_points * scratch_size zeroed bytes, set in *c. Returns the
 * block to free (NULL if none was made), or sets *failed when out of
 * memory. */
static void *scratch_begin(const RayesShaderClass *cls, RayesShadeCtx *c, int *failed)
{
    *failed = 0;
    if (cls->scratch_size == 0 || c->scratch || c->n_points == 0)
        return NULL;
    void *block = calloc(c->n_points, cls->scratch_size);
    if (!block) {
        *failed = 1;
        return NULL;
    }
    c->scratch = block;
    return block;
}

/* Out of memory for scratch: the points come out black and opaque. */
static void scratch_failed(const RayesShaderClass *cls, const RayesShadeCtx *ctx,
                           RayesShadeOutputs *out)
{
    char key[96];
    snprintf(key, sizeof key, "noscratch:%s", cls->name);
    log_warning_once(key, "shader \"%s\": out of memory for its scratch; shading black",
                     cls->name);
    memset(out->Ci, 0, ctx->n_points * sizeof *out->Ci);
    for (size_t i = 0; i < ctx->n_points; i++)
        out->Oi[i][0] = out->Oi[i][1] = out->Oi[i][2] = 1.0f;
    if (out->Irradiance)
        memset(out->Irradiance, 0, ctx->n_points * sizeof *out->Irradiance);
}

/* What a method call on inst begins with: c, ctx with the instance's
 * pattern bindings and scratch if the class needs some (the block to free
 * is returned); out of memory for it, *failed is set and the points come
 * out black and opaque. */
static void *call_begin(const ShaderInstance *inst, const RayesShadeCtx *ctx, RayesShadeCtx *c,
                        RayesShadeOutputs *out, int *failed)
{
    *c = *ctx;
    c->patterns = inst->patterns, c->n_patterns = inst->n_patterns;
    void *scratch = scratch_begin(inst->cls, c, failed);
    if (*failed)
        scratch_failed(inst->cls, ctx, out);
    return scratch;
}

/* A method's outputs that are not finite (a plugin's division by zero)
 * become what cannot harm the rest of the frame: Ci and Irradiance 0, Oi
 * opaque; said once per class and method. Left alone, one NaN in a cache
 * fill would spread through the interpolation to every lookup near it, and
 * a NaN pixel poisons filters, adaptive sampling and the files. */
/* Whether the n colours at v (NULL: none) are all finite: an exponent of
 * all ones is infinity or NaN; a branch-free pass the compiler vectorises. */
static int all_finite(const float (*v)[3], size_t n)
{
    uint32_t hit = 0;
    for (size_t k = 0; v && k < 3 * n; k++) {
        uint32_t u;
        memcpy(&u, &v[0][0] + k, sizeof u);
        hit |= (u & 0x7f800000u) == 0x7f800000u;
    }
    return !hit;
}

static void finite_outputs(const RayesShaderClass *cls, const char *method, size_t n,
                           RayesShadeOutputs *out)
{
    if (all_finite((const float(*)[3])out->Ci, n) && all_finite((const float(*)[3])out->Oi, n) &&
        all_finite((const float(*)[3])out->Irradiance, n))
        return;
    size_t bad = 0;
    for (size_t i = 0; i < n; i++)
        for (int c = 0; c < 3; c++) {
            if (out->Ci && !isfinite(out->Ci[i][c]))
                out->Ci[i][c] = 0.0f, bad++;
            if (out->Oi && !isfinite(out->Oi[i][c]))
                out->Oi[i][c] = 1.0f, bad++;
            if (out->Irradiance && !isfinite(out->Irradiance[i][c]))
                out->Irradiance[i][c] = 0.0f, bad++;
        }
    if (bad) {
        char key[96];
        snprintf(key, sizeof key, "nonfinite:%s:%s", cls->name, method);
        log_warning_once(key,
                         "shader \"%s\": its %s method returned values that are not finite; "
                         "they are taken as 0 (Oi: opaque)",
                         cls->name, method);
    }
}

void shade_run_lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                        const ShaderInstance *inst, RayesShadeOutputs *out)
{
    const RayesShaderClass *cls = inst->cls;
    RayesShadeCtx c;
    int failed;
    void *scratch = call_begin(inst, ctx, &c, out, &failed);
    if (failed)
        return;
    if (cls->prelighting)
        cls->prelighting(sv, &c, inst->params, out);
    cls->lighting(sv, &c, inst->params, out);
    if (cls->postlighting)
        cls->postlighting(sv, &c, inst->params, out);
    finite_outputs(cls, "lighting", ctx->n_points, out);
    free(scratch);
}

void shade_run_diffuselighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                               const ShaderInstance *inst, RayesShadeOutputs *out)
{
    const RayesShaderClass *cls = inst->cls;
    RayesShadeCtx c;
    int failed;
    void *scratch = call_begin(inst, ctx, &c, out, &failed);
    if (failed)
        return;
    c.I = NULL; /* view independence: diffuselighting never sees I */
    if (cls->prelighting)
        cls->prelighting(sv, &c, inst->params, out);
    if (cls->diffuselighting) {
        cls->diffuselighting(sv, &c, inst->params, out);
    } else {
        char key[96];
        snprintf(key, sizeof key, "nodiffuselighting:%s", cls->name);
        log_warning_once(key,
                         "shader \"%s\" has no diffuselighting method; using the diffuse part "
                         "of its lighting method",
                         cls->name);
        cls->lighting(sv, &c, inst->params, out);
    }
    finite_outputs(cls, "diffuselighting", ctx->n_points, out);
    free(scratch);
}

void shade_run_opacity(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                       const ShaderInstance *inst, RayesShadeOutputs *out)
{
    const RayesShaderClass *cls = inst ? inst->cls : NULL;
    if (!cls || !cls->opacity) {
        for (size_t i = 0; i < ctx->n_points; i++)
            for (int c = 0; c < 3; c++)
                out->Oi[i][c] = ctx->Os ? ctx->Os[i][c] : 1.0f;
        return;
    }
    RayesShadeCtx c;
    int failed;
    void *scratch = call_begin(inst, ctx, &c, out, &failed);
    if (failed)
        return;
    cls->opacity(sv, &c, inst->params, out);
    RayesShadeOutputs Oi = {NULL, out->Oi, NULL, NULL}; /* the method's one output */
    finite_outputs(cls, "opacity", ctx->n_points, &Oi);
    free(scratch);
}
