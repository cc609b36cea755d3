/*
 * tests/api/test_headers_c11.c — the public headers rayes/rayes.h and
 * rayes/shader.h compile as strict C11 (-std=c11 -pedantic -Werror, set in
 * tests/api/CMakeLists.txt) and their declarations are usable: options,
 * a scene's life cycle, errors, versions and a shader class table.
 * test_headers_cxx.cpp is the C++ twin.
 */
#include <stdio.h>
#include <string.h>

#include "rayes/rayes.h"
#include "rayes/shader.h"

#if !defined(__STDC_VERSION__) || __STDC_VERSION__ != 201112L
#error "this test must be compiled as C11"
#endif

static int failures;

#define EXPECT(cond)                                                                   \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond);  \
            failures++;                                                                \
        }                                                                              \
    } while (0)

typedef struct Params {
    float Kd;     /* diffuse weight */
    float Cs[3];  /* surface colour */
} Params;

static void lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                     const void *params, RayesShadeOutputs *out)
{
    const Params *p = (const Params *)params;
    (void)sv;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Ci[i][c] = p->Kd * p->Cs[c];
            out->Oi[i][c] = 1.0f;
        }
}

static const RayesShaderParamDesc param_table[] = {
    {"Kd", RAYES_PARAM_FLOAT, offsetof(Params, Kd), {1.0f, 0.0f, 0.0f}},
    {"Cs", RAYES_PARAM_COLOR, offsetof(Params, Cs), {1.0f, 1.0f, 1.0f}},
};

static const RayesShaderClass flat_class = {
    RAYES_SHADER_ABI_VERSION, (uint32_t)sizeof(RayesShaderClass), "flat", sizeof(Params),
    param_table, sizeof param_table / sizeof param_table[0],
    NULL, NULL, NULL, lighting, NULL, NULL};

int main(void)
{
    RayesRenderOptions opt;
    rayes_render_options_init(&opt, RAYES_QUALITY_PREVIEW);
    EXPECT(opt.struct_size == sizeof(RayesRenderOptions));
    EXPECT(opt.width > 0 && opt.height > 0 && opt.spp > 0);
    EXPECT(opt.filter == RAYES_FILTER_BOX);

    EXPECT(strcmp(rayes_version_string(), RAYES_VERSION_STRING) == 0);
    EXPECT(rayes_error_string(RAYES_ERROR_PARSE) != NULL);

    RayesScene *scene = rayes_scene_new();
    EXPECT(scene != NULL);
    RayesParam kd = {"Kd", RAYES_PARAM_FLOAT, {0.5f, 0.0f, 0.0f}, NULL};
    EXPECT(rayes_scene_set_shader(scene, "matte", &kd, 1) == RAYES_OK);
    EXPECT(rayes_scene_set_search_path(scene, "shader", "/nonexistent:&") == RAYES_OK);
    EXPECT(rayes_scene_sphere(scene, 1.0f) == RAYES_OK);
    EXPECT(rayes_scene_commit(scene) == RAYES_OK);
    EXPECT(rayes_scene_get_timestamp(scene) == 1u);
    EXPECT(strcmp(rayes_scene_get_error(scene), "") == 0);
    rayes_scene_retain(scene);
    rayes_scene_release(scene);
    rayes_scene_release(scene);

    /* The shader table: call the method the way the renderer would. */
    EXPECT(flat_class.abi_version == RAYES_SHADER_ABI_VERSION);
    Params p = {0.5f, {1.0f, 0.5f, 0.25f}};
    float P[1][3] = {{0.0f, 0.0f, 0.0f}}, Ci[1][3], Oi[1][3];
    RayesShadeCtx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.n_points = 1;
    ctx.ray_type = RAYES_RAY_CAMERA | RAYES_RAY_SPECULAR;
    ctx.P = (const float(*)[3])P;
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    flat_class.lighting(NULL, &ctx, &p, &out);
    EXPECT(Ci[0][1] == 0.25f && Oi[0][2] == 1.0f);

    printf("%s (%d failed)\n", failures ? "FAIL" : "ok", failures);
    return failures ? 1 : 0;
}
