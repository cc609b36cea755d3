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
