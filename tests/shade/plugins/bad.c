/*
 * tests/shade/plugins/bad.c — shader plugins that the loader must refuse,
 * one per BAD_* definition (tests/CMakeLists.txt builds each as
 * RAYES_TEST_BAD_SHADERS/NAME.so), plus "good", a minimal plugin that
 * must load:
 *   abi1        abi_version 1
 *   noentry     no rayes_shader_entry function
 *   wrongname   file wrongname.so, class named "other"
 *   badparams   a parameter beyond params_size
 *   nolighting  no lighting method
 *   nullclass   the entry returns NULL
 *   attributes  (loads) Ci = (object:id, patch:id, checker at (u, v) x 4)
 *               from the renderer's services, to test them
 */
#include <stddef.h>
#include <string.h>

#include "rayes/shader.h"

#ifndef PLUGIN_NAME
#error "PLUGIN_NAME must be the plugin's name"
#endif

typedef struct Params {
    float Kd;
} Params;

static void lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                     RayesShadeOutputs *out)
{
    (void)sv;
    const Params *p = params;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Ci[i][c] = p->Kd;
            out->Oi[i][c] = 1.0f;
        }
#ifdef ATTRIBUTES
    float object = -1.0f, patch = -1.0f;
    int n_object = sv->attribute(sv, ctx, "object:id", &object, 1);
    int n_patch = sv->attribute(sv, ctx, "patch:id", &patch, 1);
    int unknown = sv->attribute(sv, ctx, "no:such", &patch, 1);
    for (size_t i = 0; i < ctx->n_points; i++) {
        out->Ci[i][0] = n_object == 1 && unknown == 0 ? object : -1.0f;
        out->Ci[i][1] = n_patch == 1 ? patch : -1.0f;
        out->Ci[i][2] = sv->checker(sv, 4.0f * ctx->u[i], 4.0f * ctx->v[i], 0.0f, 0.0f);
    }
#endif
}

static const RayesShaderParamDesc params[] = {
#ifdef BAD_PARAMS
    {"Kd", RAYES_PARAM_FLOAT, sizeof(Params), {1, 0, 0}},
#else
    {"Kd", RAYES_PARAM_FLOAT, offsetof(Params, Kd), {0.25f, 0, 0}},
#endif
};

static const RayesShaderClass cls = {
#ifdef BAD_ABI
    .abi_version = 1,
#else
    .abi_version = RAYES_SHADER_ABI_VERSION,
#endif
    .struct_size = sizeof(RayesShaderClass),
#ifdef BAD_NAME
    .name = "other",
#else
    .name = PLUGIN_NAME,
#endif
    .params_size = sizeof(Params),
    .params = params,
    .n_params = 1,
#ifdef BAD_NOLIGHTING
    .postlighting = lighting, /* but no lighting */
#else
    .lighting = lighting,
#endif
};

#ifdef BAD_NOENTRY
RAYES_API const RayesShaderClass *not_the_entry(void)
#else
RAYES_API const RayesShaderClass *rayes_shader_entry(void)
#endif
{
#ifdef BAD_NULLCLASS
    return cls.name ? NULL : &cls;
#else
    return &cls;
#endif
}
