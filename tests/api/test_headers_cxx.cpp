/*
 * tests/api/test_headers_cxx.cpp — the public headers rayes/rayes.h and
 * rayes/shader.h compile as C++11 (-std=c++11 -pedantic -Werror, set in
 * tests/api/CMakeLists.txt), link with C linkage, and their declarations
 * are usable from C++: options, a scene's life cycle, errors, versions and
 * a shader class table. test_headers_c11.c is the C twin.
 */
#include <cstddef>
#include <cstdio>
#include <cstring>

#include "rayes/rayes.h"
#include "rayes/shader.h"

#if __cplusplus < 201103L
#error "this test must be compiled as C++11 or later"
#endif

namespace {

int failures;

#define EXPECT(cond)                                                                   \
    do {                                                                               \
        if (!(cond)) {                                                                 \
            std::fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
            failures++;                                                                \
        }                                                                              \
    } while (0)

struct Params {
    float Kd;     // diffuse weight
    float Cs[3];  // surface colour
};

extern "C" void lighting(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         const void *params, RayesShadeOutputs *out)
{
    const Params *p = static_cast<const Params *>(params);
    (void)sv;
    for (std::size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            out->Ci[i][c] = p->Kd * p->Cs[c];
            out->Oi[i][c] = 1.0f;
        }
}

const RayesShaderParamDesc param_table[] = {
    {"Kd", RAYES_PARAM_FLOAT, offsetof(Params, Kd), {1.0f, 0.0f, 0.0f}},
    {"Cs", RAYES_PARAM_COLOR, offsetof(Params, Cs), {1.0f, 1.0f, 1.0f}},
};

const RayesShaderClass flat_class = {
    RAYES_SHADER_ABI_VERSION, static_cast<uint32_t>(sizeof(RayesShaderClass)), "flat",
    sizeof(Params), param_table, sizeof param_table / sizeof param_table[0],
    nullptr, nullptr, nullptr, lighting, nullptr, nullptr};

}  // namespace

int main()
{
    RayesRenderOptions opt;
    rayes_render_options_init(&opt, RAYES_QUALITY_FINAL);
    EXPECT(opt.struct_size == sizeof(RayesRenderOptions));
    EXPECT(opt.width > 0 && opt.height > 0 && opt.spp > 0);
    EXPECT(opt.progress == nullptr);

    EXPECT(std::strcmp(rayes_version_string(), RAYES_VERSION_STRING) == 0);
    EXPECT(rayes_error_string(RAYES_ERROR_IO) != nullptr);

    RayesScene *scene = rayes_scene_new();
    EXPECT(scene != nullptr);
    RayesParam kd = {"Kd", RAYES_PARAM_FLOAT, {0.5f, 0.0f, 0.0f}, nullptr};
    EXPECT(rayes_scene_set_shader(scene, "matte", &kd, 1) == RAYES_OK);
    EXPECT(rayes_scene_set_search_path(scene, "shader", "/nonexistent:&") == RAYES_OK);
    const float P4[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}};
    EXPECT(rayes_scene_bilinear_patch(scene, P4) == RAYES_OK);
    EXPECT(rayes_scene_commit(scene) == RAYES_OK);
    EXPECT(rayes_scene_get_timestamp(scene) == 1u);
    rayes_scene_retain(scene);
    rayes_scene_release(scene);
    rayes_scene_release(scene);

    EXPECT(flat_class.abi_version == RAYES_SHADER_ABI_VERSION);
    Params p = {0.5f, {1.0f, 0.5f, 0.25f}};
    float P[1][3] = {{0.0f, 0.0f, 0.0f}}, Ci[1][3], Oi[1][3];
    RayesShadeCtx ctx;
    std::memset(&ctx, 0, sizeof ctx);
    ctx.n_points = 1;
    ctx.ray_type = RAYES_RAY_CAMERA | RAYES_RAY_DIFFUSE;
    ctx.P = P;
    RayesShadeOutputs out = {Ci, Oi, nullptr, nullptr};
    flat_class.lighting(nullptr, &ctx, &p, &out);
    EXPECT(Ci[0][1] == 0.25f && Oi[0][2] == 1.0f);

    std::printf("%s (%d failed)\n", failures ? "FAIL" : "ok", failures);
    return failures ? 1 : 0;
}
