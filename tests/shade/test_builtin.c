/*
 * Built-in shaders against stub services (shade/): each shader's lighting
 * is its diffuse terms plus its view-dependent terms, its diffuselighting
 * exactly the diffuse terms, and diffuselighting never sees I nor gets a
 * specular answer from the services. The stubs' view-dependent answers
 * (specular highlights, traced reflections and refractions, environment
 * lookups) can be switched off, which subtracts them from lighting, or
 * set to 1 everywhere for a white furnace.
 */
#include <string.h>

#include "rayes/shader.h"
#include "shade/bsdf.h"
#include "shade/registry.h"
#include "shade/shade.h"
#include "test.h"
#include "util/rng.h"

enum { N = 70 }; /* more than one SHADE_CHUNK */

static int saw_I_in_specular_call;

/* STUB_NORMAL: the answers below; STUB_NO_VIEW: every view-dependent
 * answer 0; STUB_FURNACE: radiance 1 from everywhere (direct diffuse 1,
 * traced 1, highlights, indirect diffuse and ambient 0). */
enum { STUB_NORMAL, STUB_NO_VIEW, STUB_FURNACE };
static int stub_mode = STUB_NORMAL;
static int refraction_calls;

static void stub_direct(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                        const char *category, const float *roughness, float (*diffuse)[3],
                        float (*specular)[3])
{
    (void)sv, (void)n, (void)category, (void)roughness;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            if (diffuse)
                diffuse[i][c] = stub_mode == STUB_FURNACE ? 1.0f : 0.25f * (float)(c + 1);
            if (specular) {
                /* renderer rule: no I, no specular */
                specular[i][c] = ctx->I && stub_mode == STUB_NORMAL ? 2.0f : 0.0f;
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
            out[i][c] = stub_mode == STUB_FURNACE ? 0.0f : 0.1f;
}

static void stub_ambient(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                         float (*out)[3])
{
    (void)sv;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = stub_mode == STUB_FURNACE ? 0.0f : 0.05f * (float)(3 - c);
}

static void stub_refraction(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                            const float (*dir)[3], float (*out)[3])
{
    (void)sv;
    refraction_calls++;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = stub_mode == STUB_NO_VIEW   ? 0.0f
                        : stub_mode == STUB_FURNACE ? 1.0f
                                                    : 3.0f + dir[i][c]; /* the direction, + 3 */
}

/* A lat-long "environment": rgb = (s, t, 0.5). */
static int stub_texture(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const char *name,
                        const float *s, const float *t, const float *ds, const float *dt,
                        float (*rgb)[3], float *alpha)
{
    (void)sv, (void)ds, (void)dt, (void)alpha;
    int ok = strcmp(name, "env.exr") == 0;
    for (size_t i = 0; i < ctx->n_points; i++) {
        float v = stub_mode == STUB_NORMAL && ok;
        rgb[i][0] = v * s[i];
        rgb[i][1] = v * t[i];
        rgb[i][2] = v * 0.5f;
    }
    return ok ? 0 : -1;
}

static void stub_specular(const RayesShaderServices *sv, const RayesShadeCtx *ctx,
                          const float (*dir)[3], const float *roughness, int n, float (*out)[3])
{
    (void)sv, (void)roughness, (void)n;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++)
            out[i][c] = stub_mode == STUB_NO_VIEW   ? 0.0f
                        : stub_mode == STUB_FURNACE ? 1.0f
                                                    : dir[i][c]; /* the direction, to check */
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

/* The full set: ambient, refraction and textures too. */
static const RayesShaderServices stub_full = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderServices),
    .direct_lighting = stub_direct,
    .ambient = stub_ambient,
    .indirect_diffuse = stub_indirect,
    .indirect_specular = stub_specular,
    .indirect_refraction = stub_refraction,
    .texture = stub_texture,
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
    CHECK(shade_find_class("shinymetal") != NULL);
    CHECK(shade_find_class("shinymetal") != shade_find_class("mirror"));
    /* Unknown names warn and are ignored; a float may set a colour. */
    RayesParam p[2] = {{"bogus", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL},
                       {"specularcolor", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL}};
    ShaderInstance m = instance("plastic", p, 2);
    const float *sc = (const float *)((const char *)m.params + 4 * sizeof(float));
    CHECK(sc[0] == 0.5f && sc[1] == 0.5f && sc[2] == 0.5f);
    shade_instance_fini(&m);
}

/* ---- every built-in, random views */

typedef struct Spec {
    const char *name;
    RayesParam p[3];
    size_t n;
    int view_dependent; /* has a term that depends on I */
} Spec;

static const Spec specs[] = {
    {"matte", {{"Ka", RAYES_PARAM_FLOAT, {0.7f, 0, 0}, NULL}}, 1, 0},
    {"plastic", {{"Ka", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL}}, 1, 1},
    {"mirror", {{"Kr", RAYES_PARAM_FLOAT, {0.9f, 0, 0}, NULL}}, 1, 1},
    {"constant", {{"Ka", RAYES_PARAM_FLOAT, {0.9f, 0, 0}, NULL}}, 0, 0},
    {"metal", {{"Ka", RAYES_PARAM_FLOAT, {0.3f, 0, 0}, NULL}}, 1, 1},
    {"shinymetal", {{"Kr", RAYES_PARAM_FLOAT, {0.8f, 0, 0}, NULL}}, 1, 1},
    {"shinymetal", {{"texturename", RAYES_PARAM_STRING, {0, 0, 0}, "env.exr"}}, 1, 1},
    {"glass", {{"roughness", RAYES_PARAM_FLOAT, {0.05f, 0, 0}, NULL}}, 1, 1},
    {"glass", {{"Ks", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL}}, 1, 1},
    {"diffuse", {{"reflectance", RAYES_PARAM_COLOR, {0.2f, 0.4f, 0.8f}, NULL}}, 1, 0},
    {"conductor",
     {{"preset", RAYES_PARAM_STRING, {0, 0, 0}, "gold"},
      {"roughness", RAYES_PARAM_FLOAT, {0.04f, 0, 0}, NULL}},
     2, 1},
    {"conductor", {{"reflectance", RAYES_PARAM_COLOR, {0.9f, 0.5f, 0.2f}, NULL}}, 1, 1},
    {"dielectric", {{"eta", RAYES_PARAM_FLOAT, {1.33f, 0, 0}, NULL}}, 1, 1},
    {"dielectric", {{"roughness", RAYES_PARAM_FLOAT, {0.1f, 0, 0}, NULL}}, 1, 1},
    {"coateddiffuse",
     {{"reflectance", RAYES_PARAM_COLOR, {0.6f, 0.3f, 0.1f}, NULL},
      {"roughness", RAYES_PARAM_FLOAT, {0.05f, 0, 0}, NULL}},
     2, 1},
};

static int backfacing[N];

static Vec3 random_unit(uint64_t key)
{
    float z = 2.0f * rng_float(hash_combine(key, 1)) - 1.0f;
    float phi = 6.2831853f * rng_float(hash_combine(key, 2));
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return v3(r * cosf(phi), r * sinf(phi), z);
}

/* Random N per point, I toward it from a random direction on N's side,
 * some points on back faces. */
static RayesShadeCtx random_context(uint64_t seed, float cs_value)
{
    RayesShadeCtx ctx = context();
    for (int i = 0; i < N; i++) {
        uint64_t key = hash_combine(seed, (uint64_t)i);
        Vec3 n = random_unit(hash_combine(key, 10)), d = random_unit(hash_combine(key, 11));
        if (v3_dot(d, n) > -0.05f)
            d = v3_normalize(v3_sub(d, v3_scale(n, v3_dot(d, n) + 0.3f)));
        Nn[i][0] = n.x, Nn[i][1] = n.y, Nn[i][2] = n.z;
        I[i][0] = d.x, I[i][1] = d.y, I[i][2] = d.z;
        for (int c = 0; c < 3; c++)
            Cs[i][c] = cs_value;
        backfacing[i] = i % 3 == 1;
    }
    ctx.backfacing = backfacing;
    return ctx;
}

static float cos_view(int i)
{
    return fmaxf(-(I[i][0] * Nn[i][0] + I[i][1] * Nn[i][1] + I[i][2] * Nn[i][2]), 1e-4f);
}

/* lighting with the view-dependent answers switched off (its
 * view-dependent terms subtracted) equals diffuselighting; diffuselighting
 * does not change when they are switched back on (it never asks). */
static void test_diffuselighting_is_view_independent_part(void)
{
    for (size_t k = 0; k < sizeof specs / sizeof specs[0]; k++)
        for (uint64_t seed = 0; seed < 4; seed++) {
            ShaderInstance m = instance(specs[k].name, specs[k].p, specs[k].n);
            RayesShadeCtx ctx = random_context(seed + 100 * k, 0.6f);
            RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
            float lit0[N][3], lit[N][3], dif[N][3];
            stub_mode = STUB_NO_VIEW;
            shade_run_lighting(&stub_full, &ctx, &m, &out);
            memcpy(lit0, Ci, sizeof lit0);
            stub_mode = STUB_NORMAL;
            shade_run_lighting(&stub_full, &ctx, &m, &out);
            memcpy(lit, Ci, sizeof lit);
            saw_I_in_specular_call = 0;
            refraction_calls = 0;
            shade_run_diffuselighting(&stub_full, &ctx, &m, &out);
            memcpy(dif, Ci, sizeof dif);
            CHECK(!saw_I_in_specular_call && refraction_calls == 0);
            stub_mode = STUB_NO_VIEW;
            shade_run_diffuselighting(&stub_full, &ctx, &m, &out);
            CHECK(memcmp(dif, Ci, sizeof dif) == 0);
            stub_mode = STUB_NORMAL;
            float favg = fresnel_dielectric_average(1.5f);
            int differs = 0, bad = 0;
            for (int i = 0; i < N; i++)
                for (int c = 0; c < 3; c++) {
                    double want = dif[i][c];
                    /* coateddiffuse: diffuselighting is the view average of
                     * lighting's base term (1 - F(cos_v)) (1 - Favg). */
                    if (strcmp(specs[k].name, "coateddiffuse") == 0)
                        want *= (1.0 - fresnel_dielectric(cos_view(i), 1.5f)) / (1.0 - favg);
                    bad += fabs(lit0[i][c] - want) > 1e-5 * fmax(1.0, fabs(want));
                    differs += fabsf(lit[i][c] - lit0[i][c]) > 1e-4f;
                }
            if (bad || (differs > 0) != specs[k].view_dependent)
                fprintf(stderr, "%s #%zu: %d mismatches, %d view-dependent values\n",
                        specs[k].name, k, bad, differs);
            CHECK(bad == 0);
            CHECK((differs > 0) == specs[k].view_dependent);
            CHECK(dif[0][0] >= 0.0f && lit[0][0] == lit[0][0]);
            shade_instance_fini(&m);
        }
}

/* Radiance 1 from everywhere and albedo 1: glass and the smooth
 * dielectric return exactly 1 (R + T = 1, TIR included), the Lambertian
 * shaders 1, the coated white base 1 (what its coat sends back inside
 * reaches the viewer after bounces: pbrt-v4's layered model; it lost 8%
 * before), conductors at most 1. */
static void test_shader_furnace(void)
{
    static const Spec white[] = {
        {"diffuse", {{"reflectance", RAYES_PARAM_COLOR, {1, 1, 1}, NULL}}, 1, 0},
        {"matte", {{"Kd", RAYES_PARAM_FLOAT, {1, 0, 0}, NULL}}, 1, 0},
        {"glass", {{"eta", RAYES_PARAM_FLOAT, {1.5f, 0, 0}, NULL}}, 1, 1},
        {"dielectric", {{"eta", RAYES_PARAM_FLOAT, {2.4f, 0, 0}, NULL}}, 1, 1},
        {"conductor", {{"preset", RAYES_PARAM_STRING, {0, 0, 0}, "silver"}}, 1, 1},
        {"conductor", {{"reflectance", RAYES_PARAM_COLOR, {1, 1, 1}, NULL}}, 1, 1},
        {"coateddiffuse",
         {{"reflectance", RAYES_PARAM_COLOR, {1, 1, 1}, NULL},
          {"thickness", RAYES_PARAM_FLOAT, {0, 0, 0}, NULL}},
         2, 1},
    };
    stub_mode = STUB_FURNACE;
    for (size_t k = 0; k < sizeof white / sizeof white[0]; k++) {
        ShaderInstance m = instance(white[k].name, white[k].p, white[k].n);
        RayesShadeCtx ctx = random_context(7 + k, 1.0f);
        RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
        shade_run_lighting(&stub_full, &ctx, &m, &out);
        int exact = k < 4 || k == 6;
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                if (exact)
                    CHECK_NEAR(Ci[i][c], 1.0, 1e-5);
                CHECK(Ci[i][c] <= 1.0f + 1e-5f);
                CHECK(Ci[i][c] >= (k == 4 ? 0.8f : 0.85f)); /* silver, coat: most of it */
            }
        shade_instance_fini(&m);
    }
    stub_mode = STUB_NORMAL;
}

static void test_glass_fresnel_and_sides(void)
{
    ShaderInstance m = instance("glass", NULL, 0);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    memset(backfacing, 0, sizeof backfacing);
    ctx.backfacing = backfacing;
    backfacing[1] = backfacing[2] = 1;
    I[2][0] = 0.5f, I[2][2] = -sqrtf(0.75f); /* leaving, 30 degrees: refracts */
    I[1][0] = 0.8f, I[1][2] = -0.6f;         /* leaving, 53 degrees: TIR */
    shade_run_lighting(&stub_full, &ctx, &m, &out);
    /* Entering at cos 0.8: refracted by Snell, sin_t = 0.6 / 1.5. */
    double F = fresnel_dielectric(0.8f, 1.5f), st = 0.4, ct = -sqrt(1 - st * st);
    CHECK(F > 0.04 && F < 0.06);
    CHECK_NEAR(Ci[0][0], F * 0.6 + 0.5 * (1 - F) * (3 + st), 1e-5);
    CHECK_NEAR(Ci[0][2], F * 0.8 + 0.5 * (1 - F) * (3 + ct), 1e-5);
    /* Leaving at 30 degrees: sin_t = 1.5 sin_i, F from the inside. */
    F = fresnel_dielectric(-sqrtf(0.75f), 1.5f);
    st = 0.75, ct = -sqrt(1 - st * st);
    CHECK_NEAR(Ci[2][0], F * 0.5 + 0.5 * (1 - F) * (3 + st), 1e-5);
    CHECK_NEAR(Ci[2][2], F * sqrt(0.75) + 0.5 * (1 - F) * (3 + ct), 1e-5);
    /* Total internal reflection: the mirror ray only. */
    CHECK_NEAR(Ci[1][0], 0.8, 1e-5);
    CHECK_NEAR(Ci[1][2], 0.6, 1e-5);
    shade_instance_fini(&m);
}

static void test_metals(void)
{
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    RayesShadeCtx ctx = context();
    /* metal: Cs (Ka ambient + Ks specular). */
    RayesParam ks = {"Ks", RAYES_PARAM_FLOAT, {0.7f, 0, 0}, NULL};
    ShaderInstance m = instance("metal", &ks, 1);
    shade_run_lighting(&stub_full, &ctx, &m, &out);
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(Ci[5][c], 0.5 * (0.05 * (3 - c) + 0.7 * 2.0), 1e-6);
    shade_instance_fini(&m);
    /* shinymetal: + Kr times the traced mirror ray, or the lat-long map. */
    m = instance("shinymetal", NULL, 0);
    shade_run_lighting(&stub_full, &ctx, &m, &out);
    CHECK_NEAR(Ci[5][0], 0.5 * (0.15 + 2.0 + 0.6), 1e-6);
    CHECK_NEAR(Ci[5][2], 0.5 * (0.05 + 2.0 + 0.8), 1e-6);
    shade_instance_fini(&m);
    RayesParam tex = {"texturename", RAYES_PARAM_STRING, {0, 0, 0}, "env.exr"};
    m = instance("shinymetal", &tex, 1);
    shade_run_lighting(&stub_full, &ctx, &m, &out);
    double s = 0.5 + atan2(0.6, -0.8) / (2 * 3.14159265358979), t = 0.5;
    CHECK_NEAR(Ci[5][0], 0.5 * (0.15 + 2.0 + s), 1e-5);
    CHECK_NEAR(Ci[5][1], 0.5 * (0.10 + 2.0 + t), 1e-5);
    shade_instance_fini(&m);
    /* A missing map falls back to the traced ray. */
    tex.string = "missing.exr";
    m = instance("shinymetal", &tex, 1);
    shade_run_lighting(&stub_full, &ctx, &m, &out);
    CHECK_NEAR(Ci[5][2], 0.5 * (0.05 + 2.0 + 0.8), 1e-6);
    shade_instance_fini(&m);
    /* conductor of reflectance 0.7 seen head on reflects 0.7 of the mirror ray. */
    for (int i = 0; i < N; i++)
        I[i][0] = 0.0f, I[i][2] = -1.0f;
    RayesParam r = {"reflectance", RAYES_PARAM_COLOR, {0.7f, 0.7f, 0.7f}, NULL};
    m = instance("conductor", &r, 1);
    shade_run_lighting(&stub_full, &ctx, &m, &out);
    CHECK_NEAR(Ci[5][2], 0.5 * 0.7, 1e-5);
    CHECK_NEAR(Ci[5][0], 0.0, 1e-6);
    shade_instance_fini(&m);
    /* The default conductor is copper, a preset gold; an unknown preset
     * warns and is copper. Head on, the mirror ray is (0, 0, 1). */
    const char *names[3] = {NULL, "gold", "unobtainium"};
    float z[3];
    for (int k = 0; k < 3; k++) {
        RayesParam pr = {"preset", RAYES_PARAM_STRING, {0, 0, 0}, names[k]};
        m = instance("conductor", &pr, names[k] ? 1 : 0);
        shade_run_lighting(&stub_full, &ctx, &m, &out);
        z[k] = Ci[5][2];
        shade_instance_fini(&m);
    }
    Vec3 eta, kk;
    conductor_preset("copper", &eta, &kk);
    CHECK_NEAR(z[0], 0.5 * fresnel_conductor(1.0f, eta.z, kk.z), 1e-5);
    conductor_preset("gold", &eta, &kk);
    CHECK_NEAR(z[1], 0.5 * fresnel_conductor(1.0f, eta.z, kk.z), 1e-5);
    CHECK(z[2] == z[0]);
}

/* A slice of a context starts every per-point array at its first point,
 * the texture coordinates' derivatives (dst) and backfacing included. */
static void test_ctx_slice(void)
{
    float P[8][3] = {{0}}, st[8], dst[8][4];
    int back[8];
    for (int i = 0; i < 8; i++)
        P[i][0] = st[i] = dst[i][0] = (float)i, back[i] = i;
    RayesShadeCtx ctx = {.n_points = 8,
                         .P = (const float(*)[3])P,
                         .s = st,
                         .t = st,
                         .backfacing = back,
                         .dst = (const float(*)[4])dst};
    RayesShadeCtx sub;
    shade_ctx_slice(&ctx, 5, 3, &sub);
    CHECK(sub.n_points == 3 && sub.first_point == 5);
    CHECK(sub.P[0][0] == 5.0f && sub.s[0] == 5.0f && sub.t[1] == 6.0f);
    CHECK(sub.backfacing[2] == 7 && sub.dst[0][0] == 5.0f);
    CHECK(sub.u == NULL && sub.Cs == NULL);
}

/* A class whose methods return NaN and infinity at every other point (a
 * plugin dividing by zero): the renderer takes Ci 0 and Oi opaque there,
 * and keeps the finite points as they are. The opacity method's output is
 * Oi alone; a Ci it leaves as it found it (a cache fill's scratch, whatever
 * that held) is not the shader's fault and draws no warning. */
static void nan_method(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                       RayesShadeOutputs *out)
{
    (void)sv, (void)params;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            float bad = c == 1 ? INFINITY : NAN;
            out->Ci[i][c] = i % 2 ? bad : 0.25f;
            out->Oi[i][c] = i % 2 ? bad : 0.5f;
        }
}

static void test_nonfinite_outputs(void)
{
    static const RayesShaderClass cls = {.abi_version = RAYES_SHADER_ABI_VERSION,
                                         .struct_size = sizeof(RayesShaderClass),
                                         .name = "nanny",
                                         .lighting = nan_method,
                                         .diffuselighting = nan_method,
                                         .opacity = nan_method};
    ShaderInstance inst;
    char err[128];
    CHECK(shade_instance_init(&inst, &cls, NULL, 0, err, sizeof err) == 0);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    for (int method = 0; method < 3; method++) {
        if (method == 0)
            shade_run_lighting(&stub, &ctx, &inst, &out);
        else if (method == 1)
            shade_run_diffuselighting(&stub, &ctx, &inst, &out);
        else
            shade_run_opacity(&stub, &ctx, &inst, &out);
        for (int i = 0; i < N; i++)
            for (int c = 0; c < 3; c++) {
                if (method < 2)
                    CHECK(Ci[i][c] == (i % 2 ? 0.0f : 0.25f));
                else /* opacity's output is Oi alone: Ci is the caller's scratch */
                    CHECK(i % 2 ? !isfinite(Ci[i][c]) : Ci[i][c] == 0.25f);
                CHECK(Oi[i][c] == (i % 2 ? 1.0f : 0.5f));
            }
    }
    shade_instance_fini(&inst);
}

/* glow (the RenderMan Companion's halo): face on Cs and opaque, at 60
 * degrees cos^(2 attenuation) = 1/16 for the default 2 (premultiplied),
 * its back clear; clear and black to shadow and diffuse rays. */
static void test_glow(void)
{
    ShaderInstance g = instance("glow", NULL, 0);
    RayesShadeCtx ctx = context();
    int back[N] = {0};
    back[N - 1] = 1;
    ctx.backfacing = back;
    for (int i = 0; i < N; i++) { /* I at 0 and 60 degrees from -N, in turn */
        float th = i % 2 ? (float)(M_PI / 3) : 0.0f;
        I[i][0] = sinf(th), I[i][1] = 0.0f, I[i][2] = -cosf(th);
    }
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    shade_run_lighting(&stub, &ctx, &g, &out);
    for (int i = 0; i < N; i++) {
        float f = i == N - 1 ? 0.0f : i % 2 ? 1.0f / 16.0f : 1.0f;
        CHECK_NEAR(Oi[i][1], f, 1e-5);
        CHECK_NEAR(Ci[i][1], 0.5 * f, 1e-5); /* Cs 0.5 */
    }
    shade_run_opacity(&stub, &ctx, &g, &out);
    CHECK(Oi[0][0] == 0.0f && Oi[2][1] == 0.0f);
    shade_run_diffuselighting(&stub, &ctx, &g, &out);
    CHECK(Ci[0][0] == 0.0f && Oi[0][0] == 0.0f);
    shade_instance_fini(&g);
}

TEST_MAIN(TEST(test_matte), TEST(test_plastic_splits_highlight), TEST(test_mirror_reflects),
          TEST(test_params_and_lookup), TEST(test_diffuselighting_is_view_independent_part),
          TEST(test_shader_furnace), TEST(test_glass_fresnel_and_sides), TEST(test_metals),
          TEST(test_ctx_slice), TEST(test_nonfinite_outputs), TEST(test_glow))
