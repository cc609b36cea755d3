/*
 * paintedplastic against stub services (shade/): prelighting looks the
 * texture up once for all points into the scratch the runners provide, and
 * lighting and diffuselighting read it back per point across chunks;
 * lighting is Cs T (Ka ambient + Kd diffuse) + Ks specularcolor specular,
 * diffuselighting the same without the highlight; without a texture name,
 * or when the lookup fails, T is 1.
 */
#include <string.h>

#include "rayes/shader.h"
#include "shade/registry.h"
#include "shade/shade.h"
#include "test.h"

enum { N = 150 }; /* more than two SHADE_CHUNKs */

static int texture_calls, texture_fails;
static size_t texture_points;
static char texture_name[64];

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
        for (int c = 0; c < 3; c++)
            out[i][c] = 0.25f;
}

static void stub_ambient(const RayesShaderServices *sv, const RayesShadeCtx *ctx, float (*out)[3])
{
    (void)sv;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = 0.125f;
}

/* T = (s, t, 0.5): each point's own colour, so mixing points shows. */
static int stub_texture(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                        const float *s, const float *t, const float *ds, const float *dt,
                        float (*rgb)[3], float *alpha)
{
    (void)sv, (void)alpha;
    texture_calls++;
    texture_points += ctx->n_points;
    snprintf(texture_name, sizeof texture_name, "%s", name);
    CHECK(ds == NULL && dt == NULL); /* the context's footprint */
    for (size_t i = 0; i < ctx->n_points; i++) {
        rgb[i][0] = texture_fails ? 0.0f : s[i];
        rgb[i][1] = texture_fails ? 0.0f : t[i];
        rgb[i][2] = texture_fails ? 0.0f : 0.5f;
    }
    return texture_fails ? -1 : 0;
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
    .texture = stub_texture,
    .supports = stub_supports,
};

static float P[N][3], Nn[N][3], I[N][3], Cs[N][3], Os[N][3], Ci[N][3], Oi[N][3];
static float u[N], v[N], du[N], dv[N];

static RayesShadeCtx context(void)
{
    for (int i = 0; i < N; i++) {
        Nn[i][2] = 1.0f;
        I[i][0] = 0.6f;
        I[i][2] = -0.8f;
        u[i] = (float)i / N;
        v[i] = 1.0f - (float)i / N;
        du[i] = dv[i] = 0.01f;
        for (int c = 0; c < 3; c++) {
            P[i][c] = (float)i;
            Cs[i][c] = 0.8f;
            Os[i][c] = 1.0f;
        }
    }
    return (RayesShadeCtx){
        .n_points = N, .ray_type = RAYES_RAY_CAMERA, .P = (const float(*)[3])P,
        .N = (const float(*)[3])Nn, .Ng = (const float(*)[3])Nn, .u = u, .v = v, .s = u, .t = v,
        .du = du, .dv = dv, .I = (const float(*)[3])I, .Cs = (const float(*)[3])Cs,
        .Os = (const float(*)[3])Os,
    };
}

static ShaderInstance instance(const char *texturename)
{
    const RayesShaderClass *cls = shade_find_class("paintedplastic");
    CHECK(cls != NULL);
    CHECK(cls->prelighting && cls->diffuselighting && cls->scratch_size == 3 * sizeof(float));
    RayesParam p[3] = {
        {"texturename", RAYES_PARAM_STRING, {0, 0, 0}, texturename},
        {"Ka", RAYES_PARAM_FLOAT, {2, 0, 0}, NULL},
        {"Ks", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL},
    };
    ShaderInstance inst;
    char err[100];
    CHECK(shade_instance_init(&inst, cls, p, 3, err, sizeof err) == 0);
    return inst;
}

/* Expected Ci of point i for texture colour T. */
static float expected(int i, int c, const float T[3], int highlight)
{
    (void)i;
    float Ka = 2.0f, Kd = 0.5f, Ks = 0.5f;
    float diffuse = Ka * 0.125f + Kd * (0.5f + 0.25f);
    return 0.8f * T[c] * diffuse + (highlight ? Ks * 1.0f * 2.0f : 0.0f);
}

static void check_run(int diffuse_only, const char *name, int fails)
{
    ShaderInstance inst = instance(name);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    texture_calls = 0;
    texture_points = 0;
    texture_fails = fails;
    if (diffuse_only)
        shade_run_diffuselighting(&stub, &ctx, &inst, &out);
    else
        shade_run_lighting(&stub, &ctx, &inst, &out);
    int textured = name[0] != '\0';
    CHECK(texture_calls == textured); /* once, in prelighting, for all points */
    CHECK(texture_points == (textured ? (size_t)N : 0));
    if (textured)
        CHECK(strcmp(texture_name, name) == 0);
    for (int i = 0; i < N; i++) {
        float T[3] = {1.0f, 1.0f, 1.0f};
        if (textured && !fails) {
            T[0] = u[i];
            T[1] = v[i];
            T[2] = 0.5f;
        }
        for (int c = 0; c < 3; c++) {
            CHECK_NEAR(Ci[i][c], expected(i, c, T, !diffuse_only), 1e-5);
            CHECK_NEAR(Oi[i][c], 1.0, 0);
        }
    }
    shade_instance_fini(&inst);
}

static void test_lighting_reads_the_prelighting_texture(void)
{
    check_run(0, "wood.exr", 0);
}

static void test_diffuselighting_has_no_highlight(void)
{
    check_run(1, "wood.exr", 0);
}

static void test_no_texture_is_white(void)
{
    check_run(0, "", 0);
    check_run(1, "missing.exr", 1);
}

TEST_MAIN(TEST(test_lighting_reads_the_prelighting_texture),
          TEST(test_diffuselighting_has_no_highlight), TEST(test_no_texture_is_white))
