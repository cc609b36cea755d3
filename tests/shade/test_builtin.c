/*
 * Built-in shaders against stub services (shade/): each shader's lighting
 * is its diffuse terms plus its view-dependent terms, its diffuselighting
 * exactly the diffuse terms, and diffuselighting never sees I nor gets a
 * specular answer from the services.
 */
#include <string.h>

#include "rayes/shader.h"
#include "shade/shade.h"
#include "test.h"

enum { N = 70 }; /* more than one SHADE_CHUNK */

static int saw_I_in_specular_call;

static void stub_direct(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                        const char *category, const float *roughness, float (*diffuse)[3],
                        float (*specular)[3])
{
    (void)sv, (void)n, (void)category, (void)roughness;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            if (diffuse)
                diffuse[i][c] = 0.25f * (float)(c + 1);
            if (specular) {
                specular[i][c] = ctx->I ? 2.0f : 0.0f; /* renderer rule: no I, no specular */
                saw_I_in_specular_call |= ctx->I != NULL;
            }
        }
}

static void stub_indirect(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                          float (*out)[3])
{
    (void)sv, (void)n;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = 0.1f;
}

static void stub_specular(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const float (*dir)[3], const float *roughness, int n, float (*out)[3])
{
    (void)sv, (void)roughness, (void)n;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = dir[i][c]; /* returns the direction, so the test can check it */
}

static int stub_supports(const RayesShaderServices *sv, const char *s)
{
    (void)sv, (void)s;
    return 1;
}

static const RayesShaderServices stub = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderServices),
    .direct_lighting = stub_direct,
    .indirect_diffuse = stub_indirect,
    .indirect_specular = stub_specular,
    .supports = stub_supports,
};

static float P[N][3], Nn[N][3], I[N][3], Cs[N][3], Os[N][3], Ci[N][3], Oi[N][3];

static RayesShadeCtx context(void)
{
    for (int i = 0; i < N; i++) {
        Nn[i][0] = Nn[i][1] = 0.0f;
        Nn[i][2] = 1.0f;
        I[i][0] = 0.6f;
        I[i][1] = 0.0f;
        I[i][2] = -0.8f;
        for (int c = 0; c < 3; c++) {
            P[i][c] = (float)i;
            Cs[i][c] = 0.5f;
            Os[i][c] = 1.0f;
        }
    }
    RayesShadeCtx ctx = {.n_points = N, .ray_type = RAYES_RAY_CAMERA,
                         .P = (const float(*)[3])P, .N = (const float(*)[3])Nn,
                         .Ng = (const float(*)[3])Nn, .I = (const float(*)[3])I,
                         .Cs = (const float(*)[3])Cs, .Os = (const float(*)[3])Os};
    return ctx;
}

static ShaderInstance instance(const char *name, const RayesParam *p, size_t n)
{
    ShaderInstance inst;
    char err[128];
    const RayesShaderClass *cls = shade_find_class(name);
    CHECK(cls != NULL);
    CHECK(shade_instance_init(&inst, cls, p, n, err, sizeof err) == 0);
    return inst;
}

static void test_matte(void)
{
    RayesParam kd = {"Kd", RAYES_PARAM_FLOAT, {0.8f, 0, 0}, NULL};
    ShaderInstance m = instance("matte", &kd, 1);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    shade_run_lighting(&stub, &ctx, &m, &out);
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(Ci[i][c], 0.5 * 0.8 * (0.25 * (c + 1) + 0.1), 1e-6);
    float lit[N][3];
    memcpy(lit, Ci, sizeof lit);
    shade_run_diffuselighting(&stub, &ctx, &m, &out);
    CHECK(memcmp(lit, Ci, sizeof lit) == 0);
    CHECK(Oi[N - 1][2] == 1.0f);
    shade_instance_fini(&m);
}

static void test_plastic_splits_highlight(void)
{
    RayesParam p[2] = {{"Ks", RAYES_PARAM_FLOAT, {0.3f, 0, 0}, NULL},
                       {"specularcolor", RAYES_PARAM_COLOR, {1, 0.5f, 0.25f}, NULL}};
    ShaderInstance m = instance("plastic", p, 2);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    shade_run_lighting(&stub, &ctx, &m, &out);
    float lit[N][3];
    memcpy(lit, Ci, sizeof lit);
    saw_I_in_specular_call = 0;
    shade_run_diffuselighting(&stub, &ctx, &m, &out);
    CHECK(!saw_I_in_specular_call);
    const float sc[3] = {1, 0.5f, 0.25f};
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++) {
            double diffuse = 0.5 * 0.5 * (0.25 * (c + 1) + 0.1); /* Cs Kd (dd + id), Kd 0.5 */
            CHECK_NEAR(Ci[i][c], diffuse, 1e-6);
            CHECK_NEAR(lit[i][c], diffuse + 0.3 * sc[c] * 2.0, 1e-6);
        }
    shade_instance_fini(&m);
}

static void test_mirror_reflects(void)
{
    RayesParam kr = {"Kr", RAYES_PARAM_FLOAT, {0.9f, 0, 0}, NULL};
    ShaderInstance m = instance("mirror", &kr, 1);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    shade_run_lighting(&stub, &ctx, &m, &out);
    /* The reflection of (0.6, 0, -0.8) about +z is (0.6, 0, 0.8). */
    CHECK_NEAR(Ci[3][0], 0.9 * 0.6, 1e-6);
    CHECK_NEAR(Ci[3][2], 0.9 * 0.8, 1e-6);
    shade_run_diffuselighting(&stub, &ctx, &m, &out);
    CHECK(Ci[3][0] == 0.0f && Ci[3][1] == 0.0f && Ci[3][2] == 0.0f);
    shade_instance_fini(&m);
}

static void test_params_and_lookup(void)
{
    CHECK(shade_find_class("nosuch") == NULL);
    CHECK(shade_find_class("shinymetal") == shade_find_class("mirror"));
    /* Unknown names warn and are ignored; a float may set a colour. */
    RayesParam p[2] = {{"bogus", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL},
                       {"specularcolor", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL}};
    ShaderInstance m = instance("plastic", p, 2);
    const float *sc = (const float *)((const char *)m.params + 4 * sizeof(float));
    CHECK(sc[0] == 0.5f && sc[1] == 0.5f && sc[2] == 0.5f);
    shade_instance_fini(&m);
}

TEST_MAIN(TEST(test_matte), TEST(test_plastic_splits_highlight), TEST(test_mirror_reflects),
          TEST(test_params_and_lookup))
