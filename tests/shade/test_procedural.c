/*
 * The procedural surfaces of shade/builtin_procedural.c against stub
 * lighting services (the real noise): brickwall's displacement recesses
 * the mortar by mortardepth along N and leaves brick faces alone; its
 * colour is the brick's in a brick and the mortar's in a joint; wood's
 * planks have dark gaps between them, and its colour stays within the
 * range its parameters allow; both are Cs C (Ka ambient + Kd diffuse) in
 * diffuselighting, and lighting adds exactly the varnish highlight
 * Ks (1 + 3 (F - 0.04) / 0.96) specular, F Schlick's for index 1.5.
 */
#include <math.h>
#include <string.h>

#include "rayes/shader.h"
#include "shade/builtin.h"
#include "shade/registry.h"
#include "shade/shade.h"
#include "test.h"

enum { N = 4 };

static void stub_direct(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                        const char *category, const float *roughness, float (*diffuse)[3],
                        float (*specular)[3])
{
    (void)sv, (void)n, (void)category, (void)roughness;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            if (diffuse)
                diffuse[i][c] = 0.5f;
            if (specular)
                specular[i][c] = ctx->I ? 2.0f : 0.0f;
        }
}

static void stub_indirect(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                          float (*out)[3])
{
    (void)sv, (void)n;
    for (size_t i = 0; i < ctx->n_points; i++)
        out[i][0] = out[i][1] = out[i][2] = 0.25f;
}

static void stub_ambient(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3])
{
    (void)sv;
    for (size_t i = 0; i < ctx->n_points; i++)
        out[i][0] = out[i][1] = out[i][2] = 0.125f;
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
    .ambient = stub_ambient,
    .indirect_diffuse = stub_indirect,
    .noise = shade_service_noise,
    .fbm = shade_service_fbm,
    .supports = stub_supports,
};

static float P[N][3], Nn[N][3], I[N][3], Ci[N][3], Oi[N][3], Cd[N][3], Od[N][3], Pd[N][3];

/* Points at P (set by the caller), facing +z, seen along I. */
static RayesShadeCtx context(void)
{
    for (int i = 0; i < N; i++) {
        Nn[i][0] = Nn[i][1] = 0.0f;
        Nn[i][2] = 1.0f;
        I[i][0] = 0.6f;
        I[i][1] = 0.0f;
        I[i][2] = -0.8f;
    }
    return (RayesShadeCtx){.n_points = N,
                           .ray_type = RAYES_RAY_CAMERA,
                           .P = (const float(*)[3])P,
                           .N = (const float(*)[3])Nn,
                           .Ng = (const float(*)[3])Nn,
                           .I = (const float(*)[3])I};
}

static ShaderInstance instance(const char *name, const RayesParam *p, size_t n)
{
    const RayesShaderClass *cls = shade_find_class(name);
    CHECK(cls != NULL);
    ShaderInstance inst;
    char err[100];
    CHECK(shade_instance_init(&inst, cls, p, n, err, sizeof err) == 0);
    return inst;
}

/* Runs lighting and diffuselighting; checks their difference is the
 * varnish highlight (Ks at normal incidence) and returns through Cd the
 * pattern colour C = Cd / (Ka 0.125 + Kd 0.75). */
static void shade_both(ShaderInstance *inst, float Ks)
{
    RayesShadeCtx ctx = context();
    RayesShadeOutputs lit = {Ci, Oi, NULL, NULL}, dif = {Cd, Od, NULL, NULL};
    shade_run_lighting(&stub, &ctx, inst, &lit);
    ctx.I = NULL;
    shade_run_diffuselighting(&stub, &ctx, inst, &dif);
    double cosv = 0.8, m = 1.0 - cosv, F = 0.04 + 0.96 * m * m * m * m * m;
    double spec = Ks * (1.0 + 3.0 * (F - 0.04) / 0.96) * 2.0;
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(Ci[i][c] - Cd[i][c], spec, 1e-5);
            CHECK_NEAR(Oi[i][c], 1.0, 0);
            Cd[i][c] /= 1.0f * 0.125f + 1.0f * 0.75f;
        }
}

static void test_brick_displacement_recesses_the_mortar(void)
{
    const RayesParam p[] = {{"roughnessamp", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
                            {"mortardepth", RAYES_PARAM_FLOAT, {0.006f, 0, 0}, NULL}};
    ShaderInstance inst = instance("brickwall", p, 2);
    CHECK(inst.cls->displacement != NULL);
    /* bricks 0.215 x 0.075 (the defaults), a joint at y = 0 and x = 0 */
    const float at[N][3] = {
        {0.1075f, 0.0375f, 0}, {0.0f, 0.0375f, 0}, {0.05f, 0.0f, 0}, {0.2f, 0.1125f, 0}};
    memcpy(P, at, sizeof P);
    RayesShadeCtx ctx = context();
    ctx.I = NULL;
    memcpy(Pd, P, sizeof Pd);
    RayesShadeOutputs out = {NULL, NULL, NULL, Pd};
    inst.cls->displacement(&stub, &ctx, inst.params, &out);
    CHECK_NEAR(Pd[0][2], 0.0, 1e-7);    /* a brick's middle */
    CHECK_NEAR(Pd[1][2], -0.006, 1e-7); /* a head joint */
    CHECK_NEAR(Pd[2][2], -0.006, 1e-7); /* a bed joint */
    CHECK_NEAR(Pd[3][2], 0.0, 1e-7);    /* the next row, offset half a brick */
    for (int i = 0; i < N; i++)
        CHECK(Pd[i][0] == P[i][0] && Pd[i][1] == P[i][1]);
    shade_instance_fini(&inst);
}

static void test_brick_colours(void)
{
    const RayesParam p[] = {{"Ks", RAYES_PARAM_FLOAT, {0.4f, 0, 0}, NULL},
                            {"Cbrick", RAYES_PARAM_COLOR, {0.6f, 0.2f, 0.1f}, NULL},
                            {"Cmortar", RAYES_PARAM_COLOR, {0.6f, 0.6f, 0.6f}, NULL}};
    ShaderInstance inst = instance("brickwall", p, 3);
    const float at[N][3] = {
        {0.1075f, 0.0375f, 0}, {0.0f, 0.0375f, 0}, {0.05f, 0.0f, 0}, {0.2f, 0.1125f, 0}};
    memcpy(P, at, sizeof P);
    shade_both(&inst, 0.4f);
    for (int i = 0; i < N; i++) {
        int mortar = i == 1 || i == 2;
        if (mortar) { /* grey, the grit within 0.7 to 1.1 */
            CHECK(fabsf(Cd[i][0] - Cd[i][2]) < 1e-5f);
            CHECK(Cd[i][1] > 0.6f * 0.7f - 1e-5f && Cd[i][1] < 0.6f * 1.1f + 1e-5f);
        } else { /* red: the brick's hue, darker by soot at most by 0.7 x 0.85 x (1 - .15) */
            CHECK(Cd[i][0] > 2.5f * Cd[i][1] && Cd[i][1] > 1.5f * Cd[i][2]);
            CHECK(Cd[i][0] < 0.6f * 1.15f * 1.1f && Cd[i][0] > 0.6f * 0.85f * 0.6f * 0.7f);
        }
    }
    shade_instance_fini(&inst);
}

static void test_wood_planks_and_grain(void)
{
    const RayesParam p[] = {{"plankwidth", RAYES_PARAM_FLOAT, {0.16f, 0, 0}, NULL},
                            {"gapwidth", RAYES_PARAM_FLOAT, {0.004f, 0, 0}, NULL},
                            {"axis", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL},
                            {"Ks", RAYES_PARAM_FLOAT, {0.25f, 0, 0}, NULL}};
    ShaderInstance inst = instance("wood", p, 4);
    /* planks run along x, side by side along y (axis 0: a = y) */
    const float at[N][3] = {
        {0.3f, 0.08f, 0}, {0.3f, 0.16f, 0}, {0.31f, 0.24f, 0}, {0.3f, 0.08f, 0}};
    memcpy(P, at, sizeof P);
    shade_both(&inst, 0.25f);
    const float light[3] = {0.62f, 0.42f, 0.24f}, dark[3] = {0.36f, 0.2f, 0.09f};
    for (int c = 0; c < 3; c++) {
        /* the gap between two planks is dark: 0.15 of the wood at most */
        CHECK(Cd[1][c] < 0.15f * light[c] * 1.2f + 1e-5f);
        for (int i = 0; i < N; i += 2) { /* mid-plank: between the tones, each board's
                                             shade 0.8-1.2, the fibres 0.7-1.0 */
            CHECK(Cd[i][c] >= 0.8f * 0.7f * dark[c] - 1e-5f);
            CHECK(Cd[i][c] <= 1.2f * light[c] + 1e-5f);
        }
        CHECK(Cd[3][c] == Cd[0][c]); /* the same point, the same colour */
    }
    shade_instance_fini(&inst);
}

TEST_MAIN(TEST(test_brick_displacement_recesses_the_mortar), TEST(test_brick_colours),
          TEST(test_wood_planks_and_grain))
