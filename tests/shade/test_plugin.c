/*
 * Shader plugins (shade/plugin.c): the example plugins load by name from a
 * search path and run against stub services (brick's prelighting writes
 * its colours to scratch and lighting uses them; noisydisplace displaces
 * along N by the renderer's fbm); unknown names list the directories
 * searched; every plugin the loader must refuse (tests/shade/plugins/bad.c)
 * gives one line naming the file and the problem; many threads loading at
 * once get one class.
 */
#include <pthread.h>
#include <string.h>
#include <sys/stat.h>

#include "rayes/shader.h"
#include "shade/noise.h"
#include "shade/plugin.h"
#include "shade/registry.h"
#include "shade/shade.h"
#include "test.h"

#ifndef RAYES_TEST_SHADERS
#error "RAYES_TEST_SHADERS must name the directory of the example plugins"
#endif
#ifndef RAYES_TEST_BAD_SHADERS
#error "RAYES_TEST_BAD_SHADERS must name the directory of the test plugins"
#endif

enum { N = 70 }; /* more than one chunk of the plugins (64) */

/* ---------------------------------------------------------- stub services */

static void stub_direct(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                        const char *category, const float *roughness, float (*diffuse)[3],
                        float (*specular)[3])
{
    (void)sv, (void)n, (void)category, (void)roughness;
    for (size_t i = 0; i < ctx->n_points; i++)
        for (int c = 0; c < 3; c++) {
            if (diffuse)
                diffuse[i][c] = 0.25f * (float)(c + 1);
            if (specular)
                specular[i][c] = ctx->I ? 2.0f : 0.0f;
        }
}

static void stub_indirect(const RayesShaderServices *sv, const RayesShadeCtx *ctx, int n,
                          float (*out)[3])
{
    (void)sv, (void)n;
    for (size_t i = 0; i < ctx->n_points; i++)
        out[i][0] = out[i][1] = out[i][2] = 0.1f;
}

static float stub_fbm(const RayesShaderServices *sv, const float p[3], int octaves,
                      float lacunarity, float gain)
{
    (void)sv;
    return noise_fbm(p, octaves, lacunarity, gain);
}

static const RayesShaderServices stub = {
    .abi_version = RAYES_SHADER_ABI_VERSION,
    .struct_size = sizeof(RayesShaderServices),
    .direct_lighting = stub_direct,
    .indirect_diffuse = stub_indirect,
    .fbm = stub_fbm,
};

static float P[N][3], Nn[N][3], I[N][3], Cs[N][3], Os[N][3], S[N], T[N], D[N];
static float Ci[N][3], Oi[N][3], Irr[N][3], Pout[N][3];

static RayesShadeCtx context(void)
{
    for (int i = 0; i < N; i++) {
        Nn[i][0] = 0.6f;
        Nn[i][1] = 0.0f;
        Nn[i][2] = 0.8f;
        I[i][0] = 0.0f;
        I[i][1] = 0.0f;
        I[i][2] = -1.0f;
        for (int c = 0; c < 3; c++) {
            P[i][c] = 0.37f * (float)i + 0.11f * (float)c;
            Cs[i][c] = 0.5f + 0.25f * (float)c;
            Os[i][c] = 1.0f;
        }
    }
    RayesShadeCtx ctx = {.n_points = N, .ray_type = RAYES_RAY_CAMERA,
                         .P = (const float(*)[3])P, .N = (const float(*)[3])Nn,
                         .Ng = (const float(*)[3])Nn, .s = S, .t = T,
                         .I = (const float(*)[3])I, .Cs = (const float(*)[3])Cs,
                         .Os = (const float(*)[3])Os};
    return ctx;
}

static const RayesShaderClass *load(const char *name, const char *path, char *err, size_t n)
{
    err[0] = '\0';
    return shade_find_class_on_path(name, path, err, n);
}

/* ------------------------------------------------------------------ brick */

/* brickwidth 0.2, brickheight 0.1, mortar 0.02: periods 0.22 x 0.12; odd
 * rows shifted by half a brick (0.11). */
static const RayesParam brick_params[] = {
    {"brickwidth", RAYES_PARAM_FLOAT, {0.2f, 0, 0}, NULL},
    {"brickheight", RAYES_PARAM_FLOAT, {0.1f, 0, 0}, NULL},
    {"mortarthickness", RAYES_PARAM_FLOAT, {0.02f, 0, 0}, NULL},
    {"Cbrick", RAYES_PARAM_COLOR, {0.8f, 0.2f, 0.1f}, NULL},
    {"Cmortar", RAYES_PARAM_COLOR, {0.4f, 0.4f, 0.4f}, NULL},
    {"Kd", RAYES_PARAM_FLOAT, {0.9f, 0, 0}, NULL},
    {"Ks", RAYES_PARAM_FLOAT, {0.3f, 0, 0}, NULL},
};
static const float brick_colour[3] = {0.8f, 0.2f, 0.1f}, mortar_colour[3] = {0.4f, 0.4f, 0.4f};

/* Known points: (s, t) and whether it is brick. */
static const struct {
    float s, t;
    int brick;
} known[] = {
    {0.11f, 0.06f, 1},  /* middle of the first brick */
    {0.11f, 0.001f, 0}, /* the bed joint below it */
    {0.2195f, 0.06f, 0}, /* the head joint after it */
    {0.33f, 0.06f, 1},  /* middle of the second brick */
    {0.11f, 0.18f, 0},  /* row 1 is shifted: a head joint above the first brick's middle */
    {0.22f, 0.18f, 1},  /* ... and a brick above the first head joint */
    {0.11f, 0.119f, 0}, /* the bed joint between rows 0 and 1 */
};
enum { N_KNOWN = sizeof known / sizeof known[0] };

static void set_known_points(void)
{
    for (int i = 0; i < N; i++) {
        S[i] = known[i % N_KNOWN].s;
        T[i] = known[i % N_KNOWN].t;
    }
}

static void test_brick_loads_by_name(void)
{
    char err[512];
    const char *path = "/nonexistent/dir::" RAYES_TEST_SHADERS;
    const RayesShaderClass *cls = load("brick", path, err, sizeof err);
    CHECK(cls != NULL);
    if (!cls) {
        fprintf(stderr, "%s\n", err);
        return;
    }
    CHECK(strcmp(cls->name, "brick") == 0);
    CHECK(cls->scratch_size >= 3 * sizeof(float));
    CHECK(cls->prelighting && cls->lighting && cls->diffuselighting);
    CHECK(load("brick", path, err, sizeof err) == cls); /* loaded once */
    CHECK(load("matte", path, err, sizeof err) == shade_find_class("matte")); /* built-ins first */
}

static void test_brick_prelighting_writes_scratch(void)
{
    char err[512];
    const RayesShaderClass *cls = load("brick", RAYES_TEST_SHADERS, err, sizeof err);
    CHECK(cls != NULL);
    if (!cls)
        return;
    ShaderInstance inst;
    CHECK(shade_instance_init(&inst, cls, brick_params, 7, err, sizeof err) == 0);
    RayesShadeCtx ctx = context();
    set_known_points();
    static unsigned char scratch[N * 256];
    CHECK(cls->scratch_size <= 256);
    memset(scratch, 0, sizeof scratch);
    ctx.scratch = scratch;
    RayesShadeOutputs out = {Ci, Oi, NULL, NULL};
    cls->prelighting(&stub, &ctx, inst.params, &out);
    for (int i = 0; i < N; i++) {
        const float *colour = (const float *)(scratch + (size_t)i * cls->scratch_size);
        const float *want = known[i % N_KNOWN].brick ? brick_colour : mortar_colour;
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(colour[c], Cs[i][c] * want[c], 1e-6);
    }
    shade_instance_fini(&inst);
}

static void test_brick_lighting_and_diffuselighting(void)
{
    char err[512];
    const RayesShaderClass *cls = load("brick", RAYES_TEST_SHADERS, err, sizeof err);
    CHECK(cls != NULL);
    if (!cls)
        return;
    ShaderInstance inst;
    CHECK(shade_instance_init(&inst, cls, brick_params, 7, err, sizeof err) == 0);
    RayesShadeCtx ctx = context();
    set_known_points();
    RayesShadeOutputs out = {Ci, Oi, Irr, NULL};
    shade_run_lighting(&stub, &ctx, &inst, &out); /* scratch from shade.c */
    for (int i = 0; i < N; i++) {
        const float *want = known[i % N_KNOWN].brick ? brick_colour : mortar_colour;
        for (int c = 0; c < 3; c++) {
            double diffuse = 0.25 * (c + 1) + 0.1;
            CHECK_NEAR(Ci[i][c], 0.9 * Cs[i][c] * want[c] * diffuse + 0.3 * 2.0, 1e-5);
            CHECK(Oi[i][c] == 1.0f);
        }
    }
    shade_run_diffuselighting(&stub, &ctx, &inst, &out);
    for (int i = 0; i < N; i++) {
        const float *want = known[i % N_KNOWN].brick ? brick_colour : mortar_colour;
        for (int c = 0; c < 3; c++) {
            double diffuse = 0.25 * (c + 1) + 0.1;
            CHECK_NEAR(Ci[i][c], 0.9 * Cs[i][c] * want[c] * diffuse, 1e-5);
            CHECK_NEAR(Irr[i][c], 3.14159265 * diffuse, 1e-5);
        }
    }
    /* A footprint of many bricks averages the pattern: brick covers
     * (1 - 0.02/0.22) x (1 - 0.02/0.12) of the wall. */
    for (int i = 0; i < N; i++) {
        S[i] = 0.013f * (float)i;
        T[i] = 0.029f * (float)i;
        D[i] = 2.2f;
    }
    ctx.du = ctx.dv = D;
    shade_run_diffuselighting(&stub, &ctx, &inst, &out);
    double f = (1.0 - 0.02 / 0.22) * (1.0 - 0.02 / 0.12);
    for (int i = 0; i < N; i++)
        for (int c = 0; c < 3; c++) {
            double mix = mortar_colour[c] + f * (brick_colour[c] - mortar_colour[c]);
            CHECK_NEAR(Ci[i][c], 0.9 * Cs[i][c] * mix * (0.25 * (c + 1) + 0.1), 0.01);
        }
    shade_instance_fini(&inst);
}

/* ---------------------------------------------------------- noisydisplace */

static void test_noisydisplace(void)
{
    char err[512];
    const RayesShaderClass *cls = load("noisydisplace", RAYES_TEST_SHADERS, err, sizeof err);
    CHECK(cls != NULL && cls->displacement != NULL);
    if (!cls || !cls->displacement)
        return;
    RayesParam p[3] = {{"Km", RAYES_PARAM_FLOAT, {0.5f, 0, 0}, NULL},
                       {"frequency", RAYES_PARAM_FLOAT, {2.0f, 0, 0}, NULL},
                       {"octaves", RAYES_PARAM_FLOAT, {3, 0, 0}, NULL}};
    ShaderInstance inst;
    CHECK(shade_instance_init(&inst, cls, p, 3, err, sizeof err) == 0);
    RayesShadeCtx ctx = context();
    RayesShadeOutputs out = {NULL, NULL, NULL, Pout};
    memcpy(Pout, P, sizeof Pout);
    cls->displacement(&stub, &ctx, inst.params, &out);
    double largest = 0.0;
    for (int i = 0; i < N; i++) {
        float q[3] = {2.0f * P[i][0], 2.0f * P[i][1], 2.0f * P[i][2]};
        double h = 0.5 * noise_fbm(q, 3, NOISE_LACUNARITY, 0.5f);
        for (int c = 0; c < 3; c++)
            CHECK_NEAR(Pout[i][c], P[i][c] + h * Nn[i][c], 1e-5);
        largest = fmax(largest, fabs(h));
    }
    CHECK(largest > 0.05); /* the noise did move points */
    /* Its surface is matte. */
    RayesShadeOutputs lit = {Ci, Oi, NULL, NULL};
    shade_run_lighting(&stub, &ctx, &inst, &lit);
    for (int c = 0; c < 3; c++)
        CHECK_NEAR(Ci[N - 1][c], Cs[N - 1][c] * (0.25 * (c + 1) + 0.1), 1e-6);
    shade_instance_fini(&inst);
}

/* ------------------------------------------------------------ refusals */

static void test_unknown_name_lists_directories(void)
{
    char err[512];
    CHECK(load("nosuchshader", "/a/b::" RAYES_TEST_SHADERS ":/c", err, sizeof err) == NULL);
    CHECK(strstr(err, "unknown shader \"nosuchshader\"") != NULL);
    CHECK(strstr(err, "/a/b, " RAYES_TEST_SHADERS ", /c") != NULL);
    CHECK(strchr(err, '\n') == NULL);
    CHECK(load("nosuchshader", "", err, sizeof err) == NULL);
    CHECK(strstr(err, "search path (it is empty)") != NULL);
    CHECK(load("nosuchshader", NULL, err, sizeof err) == NULL);
    CHECK(load("../shaders/brick", RAYES_TEST_SHADERS, err, sizeof err) == NULL);
    CHECK(strstr(err, "without '/'") != NULL);
    /* A tiny buffer truncates, never overflows. */
    char small[24];
    CHECK(load("nosuchshader", "/a/very/long/directory/name", small, sizeof small) == NULL);
    CHECK(strlen(small) < sizeof small);
}

/* err must be exactly "DIR/NAME.so: " followed by a text containing what. */
static void check_refused(const char *name, const char *what)
{
    char err[512], prefix[512];
    const RayesShaderClass *cls = load(name, RAYES_TEST_BAD_SHADERS, err, sizeof err);
    CHECK(cls == NULL);
    snprintf(prefix, sizeof prefix, "%s/%s.so: ", RAYES_TEST_BAD_SHADERS, name);
    CHECK(strncmp(err, prefix, strlen(prefix)) == 0);
    CHECK(strstr(err, what) != NULL);
    CHECK(strchr(err, '\n') == NULL);
    if (cls || !strstr(err, what))
        fprintf(stderr, "  %s: got \"%s\"\n", name, err);
}

static void test_refusals(void)
{
    char err[512];
    CHECK(load("abi1", RAYES_TEST_BAD_SHADERS, err, sizeof err) == NULL);
    CHECK(strcmp(err, RAYES_TEST_BAD_SHADERS "/abi1.so: shader ABI version 1, this renderer "
                      "needs 2") == 0);
    check_refused("noentry", "no rayes_shader_entry function");
    check_refused("wrongname", "the class is named \"other\", expected \"wrongname\"");
    check_refused("badparams", "parameter \"Kd\" lies outside the parameter block");
    check_refused("nolighting", "no lighting method");
    check_refused("nullclass", "returned no class");
    /* A file that is no shared object at all. */
    char dir[512], file[600];
    snprintf(dir, sizeof dir, "%s/shade_plugin", RAYES_TEST_TMP);
    mkdir(dir, 0777);
    snprintf(file, sizeof file, "%s/junk.so", dir);
    FILE *f = fopen(file, "w");
    CHECK(f != NULL);
    if (f) {
        fputs("not an ELF file\n", f);
        fclose(f);
    }
    CHECK(load("junk", dir, err, sizeof err) == NULL);
    CHECK(strstr(err, "junk.so: cannot load: ") != NULL);
    /* Refused once, refused again (failures are not remembered as loaded). */
    CHECK(load("abi1", RAYES_TEST_BAD_SHADERS, err, sizeof err) == NULL);
    /* The first directory holding the name wins; good loads and runs. */
    const RayesShaderClass *good =
        load("good", RAYES_TEST_BAD_SHADERS ":" RAYES_TEST_SHADERS, err, sizeof err);
    CHECK(good != NULL && strcmp(good->name, "good") == 0);
}

static void nothing(const RayesShaderServices *sv, const RayesShadeCtx *ctx, const void *params,
                    RayesShadeOutputs *out)
{
    (void)sv, (void)ctx, (void)params, (void)out;
}

static void test_check_class_tables(void)
{
    char err[256];
    static const RayesShaderParamDesc twice[] = {
        {"Kd", RAYES_PARAM_FLOAT, 0, {1, 0, 0}},
        {"Kd", RAYES_PARAM_FLOAT, 4, {1, 0, 0}},
    };
    static const RayesShaderParamDesc odd[] = {{"Kd", RAYES_PARAM_FLOAT, 2, {1, 0, 0}}};
    static const RayesShaderParamDesc nan_default[] = {{"Kd", RAYES_PARAM_FLOAT, 0, {NAN, 0, 0}}};
    static const RayesShaderParamDesc bad_type[] = {{"Kd", (RayesParamType)7, 0, {1, 0, 0}}};
    static const RayesShaderParamDesc kd[] = {{"Kd", RAYES_PARAM_FLOAT, 4, {1, 0, 0}}};
    const RayesShaderClass c = {.abi_version = RAYES_SHADER_ABI_VERSION,
                                .struct_size = sizeof(RayesShaderClass), .name = "x",
                                .params_size = 8, .params = kd, .n_params = 1,
                                .lighting = nothing};
    CHECK(shade_plugin_check_class(&c, "x", err, sizeof err) == 0);
    RayesShaderClass b = c;
    b.struct_size = 8;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "struct_size"));
    b = c;
    b.params = twice, b.n_params = 2;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "twice"));
    b = c;
    b.params = odd, b.n_params = 1;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "aligned"));
    b = c;
    b.params = nan_default, b.n_params = 1;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "non-finite"));
    b = c;
    b.params = bad_type, b.n_params = 1;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "unknown type"));
    b = c;
    b.params = NULL, b.n_params = 1;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "no parameter"));
    b = c;
    b.scratch_size = (size_t)1 << 40;
    CHECK(shade_plugin_check_class(&b, "x", err, sizeof err) != 0 && strstr(err, "scratch_size"));
    CHECK(shade_plugin_check_class(NULL, "x", err, sizeof err) != 0);
}

/* --------------------------------------------------------------- threads */

static void *load_in_thread(void *arg)
{
    char err[512];
    const RayesShaderClass **out = arg;
    out[0] = load("good", RAYES_TEST_BAD_SHADERS, err, sizeof err);
    out[1] = load("noisydisplace", RAYES_TEST_SHADERS, err, sizeof err);
    return NULL;
}

static void test_concurrent_loads(void)
{
    enum { THREADS = 8 };
    pthread_t th[THREADS];
    const RayesShaderClass *got[THREADS][2];
    for (int i = 0; i < THREADS; i++)
        CHECK(pthread_create(&th[i], NULL, load_in_thread, got[i]) == 0);
    for (int i = 0; i < THREADS; i++)
        pthread_join(th[i], NULL);
    for (int i = 0; i < THREADS; i++) {
        CHECK(got[i][0] != NULL && got[i][0] == got[0][0]);
        CHECK(got[i][1] != NULL && got[i][1] == got[0][1]);
    }
}

TEST_MAIN(TEST(test_concurrent_loads), TEST(test_brick_loads_by_name), TEST(test_brick_prelighting_writes_scratch),
          TEST(test_brick_lighting_and_diffuselighting), TEST(test_noisydisplace),
          TEST(test_unknown_name_lists_directories), TEST(test_refusals),
          TEST(test_check_class_tables))
