/*
 * Voxel grids (shade/grid) and the patterns that hold them: a NanoVDB
 * float grid written by the test (nvdb_write.h; nanovdb_validate and
 * nanovdb_print accept it when installed) read back at its voxel centres,
 * trilinear between them and the background outside; the file's errors
 * (missing, truncated, wrong magic, no such grid, not scalar, compressed)
 * each one line naming the file; the quantized grids nanovdb_convert
 * makes of it (Fp4, Fp8, Fp16, FpN) within their quanta; pbrt-v4's uniform grid at its centres,
 * between them, fading past the outer centres and 0 outside its box.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "nvdb_write.h"
#include "shade/grid.h"
#include "shade/pattern.h"
#include "test.h"

#define DIR RAYES_TEST_TMP

static const double origin[3] = {1.0, 2.0, 3.0};
static const double voxel = 0.5;

static float value_at(int x, int y, int z)
{
    return 0.01f * (float)(x + 10 * y + 100 * z) + 0.25f;
}

static void fill(float v[8][8][8])
{
    for (int x = 0; x < 8; x++)
        for (int y = 0; y < 8; y++)
            for (int z = 0; z < 8; z++)
                v[x][y][z] = value_at(x, y, z);
}

static const char *grid_file(void)
{
    static float v[8][8][8];
    fill(v);
    CHECK(nvdb_write(DIR "/grid.nvdb", "density", (const float(*)[8][8])v, voxel, origin) == 0);
    return DIR "/grid.nvdb";
}

static float sample(const VoxelGrid *g, float x, float y, float z)
{
    float p[1][3] = {{x, y, z}}, out;
    grid_sample(g, 1, (const float(*)[3])p, &out);
    return out;
}

static void test_nanovdb_voxels(void)
{
    char err[512] = "";
    VoxelGrid *g = grid_read_nanovdb(grid_file(), "density", err, sizeof err);
    CHECK(g != NULL);
    if (!g) {
        fprintf(stderr, "  %s\n", err);
        return;
    }
    for (int x = 0; x < 8; x++)
        for (int y = 0; y < 8; y++)
            for (int z = 0; z < 8; z++)
                CHECK_NEAR(sample(g, (float)(origin[0] + voxel * x), (float)(origin[1] + voxel * y),
                                  (float)(origin[2] + voxel * z)),
                           value_at(x, y, z), 1e-5);
    /* halfway between (2,3,4) and (3,4,5): the mean of the cube's eight */
    float mid = 0.0f;
    for (int c = 0; c < 8; c++)
        mid += value_at(2 + (c & 1), 3 + (c >> 1 & 1), 4 + (c >> 2)) / 8.0f;
    CHECK_NEAR(sample(g, 1.0f + 1.25f, 2.0f + 1.75f, 3.0f + 2.25f), mid, 1e-5);
    CHECK_NEAR(sample(g, -50.0f, 0.0f, 0.0f), 0.0f, 0); /* the background */
    CHECK_NEAR(sample(g, 1e30f, 0.0f, 0.0f), 0.0f, 0);  /* far beyond the tree */
    CHECK_NEAR(sample(g, 1.0f - 0.25f, 2.0f, 3.0f), 0.5f * value_at(0, 0, 0), 1e-5); /* fading */
    grid_free(g);
}

/* nanovdb_validate and nanovdb_print take the test's file for a valid
 * grid (libnanovdb-tools; skipped when absent). */
static void test_nanovdb_tools_agree(void)
{
    const char *path = grid_file();
    if (system("command -v nanovdb_validate >/dev/null 2>&1") != 0) {
        fprintf(stderr, "  nanovdb_validate not installed: skipped\n");
        return;
    }
    char cmd[1024], out[4096] = "";
    snprintf(cmd, sizeof cmd, "nanovdb_validate -v %s 2>&1", path);
    FILE *f = popen(cmd, "r");
    size_t n = f ? fread(out, 1, sizeof out - 1, f) : 0;
    out[n] = '\0';
    int rc = f ? pclose(f) : -1;
    CHECK(rc == 0);
    CHECK(strstr(out, "density") && !strstr(out, "FAIL") && !strstr(out, "rror"));
    if (rc != 0 || strstr(out, "FAIL"))
        fprintf(stderr, "%s\n", out);
    snprintf(cmd, sizeof cmd, "nanovdb_print -l %s 2>&1", path);
    f = popen(cmd, "r");
    n = f ? fread(out, 1, sizeof out - 1, f) : 0;
    out[n] = '\0';
    CHECK((f ? pclose(f) : -1) == 0);
    CHECK(strstr(out, "density") && strstr(out, "float") && strstr(out, "512"));
}

/* Runs cmd; 0 if it exits 0. */
static int run(const char *cmd)
{
    int rc = system(cmd);
    if (rc != 0)
        fprintf(stderr, "  failed: %s\n", cmd);
    return rc;
}

/* The test's grid through OpenVDB and back, quantized by nanovdb_convert
 * (--fp4, --fp8, --fp16, --fpN), reads at every voxel centre within the
 * quantum of its bits: (max - min) / (2^bits - 1) / 2 over the leaf's
 * range, rounding to nearest (no dithering). */
static void test_nanovdb_quantized(void)
{
    const char *path = grid_file();
    if (system("command -v nanovdb_convert >/dev/null 2>&1") != 0) {
        fprintf(stderr, "  nanovdb_convert not installed: skipped\n");
        return;
    }
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "nanovdb_convert -f %s %s/grid.vdb >/dev/null", path, DIR);
    CHECK(run(cmd) == 0);
    float range = value_at(7, 7, 7) - value_at(0, 0, 0);
    struct {
        const char *flag;
        float tol;
    } kinds[] = {{"--fp4", range / 15.0f}, {"--fp8", range / 255.0f},
                 {"--fp16", range / 65535.0f}, {"--fpN -a 0.002", 0.002f}};
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        snprintf(cmd, sizeof cmd, "nanovdb_convert -f %s %s/grid.vdb %s/grid-q.nvdb >/dev/null",
                 kinds[k].flag, DIR, DIR);
        CHECK(run(cmd) == 0);
        char err[512] = "";
        VoxelGrid *g = grid_read_nanovdb(DIR "/grid-q.nvdb", "density", err, sizeof err);
        CHECK(g != NULL);
        if (!g) {
            fprintf(stderr, "  %s: %s\n", kinds[k].flag, err);
            continue;
        }
        float worst = 0.0f;
        for (int x = 0; x < 8; x++)
            for (int y = 0; y < 8; y++)
                for (int z = 0; z < 8; z++) {
                    float got = sample(g, (float)(origin[0] + voxel * x),
                                       (float)(origin[1] + voxel * y),
                                       (float)(origin[2] + voxel * z));
                    worst = fmaxf(worst, fabsf(got - value_at(x, y, z)));
                }
        CHECK(worst <= 0.5f * kinds[k].tol + 1e-5f);
        CHECK(worst > 0.0f || k == 2); /* quantized, so not exact (Fp16 may be) */
        if (worst > 0.5f * kinds[k].tol + 1e-5f)
            fprintf(stderr, "  %s: worst error %g, quantum %g\n", kinds[k].flag, worst,
                    kinds[k].tol);
        grid_free(g);
    }
}

static unsigned char *slurp(const char *path, size_t *size)
{
    FILE *f = fopen(path, "rb");
    unsigned char *b = malloc(400000);
    *size = f && b ? fread(b, 1, 400000, f) : 0;
    if (f)
        fclose(f);
    return b;
}

/* The error for the file's bytes after edit, which must name the file
 * and say what: one line. */
static void check_error(const unsigned char *data, size_t size, const char *grid,
                        const char *expect)
{
    char err[512] = "";
    VoxelGrid *g = grid_parse_nanovdb(data, size, grid, "cloud.nvdb", err, sizeof err);
    CHECK(g == NULL);
    grid_free(g);
    CHECK(strncmp(err, "cloud.nvdb: ", 12) == 0 && strstr(err, expect) && !strchr(err, '\n'));
    if (!strstr(err, expect))
        fprintf(stderr, "  got \"%s\", expected \"%s\"\n", err, expect);
}

static void test_nanovdb_errors(void)
{
    size_t size;
    unsigned char *b = slurp(grid_file(), &size);
    char err[512] = "";
    CHECK(grid_read_nanovdb(DIR "/no such.nvdb", "density", err, sizeof err) == NULL);
    CHECK(strstr(err, "no such.nvdb") != NULL);
    check_error(b, 10, "density", "truncated");
    check_error(b, 100, "density", "truncated");
    check_error(b, size - 100, "density", "truncated");
    check_error(b, size, "temperature", "no grid \"temperature\" (the file has \"density\")");
    unsigned char *c = malloc(size);
    memcpy(c, b, size);
    c[0] ^= 1;
    check_error(c, size, "density", "wrong magic number");
    memcpy(c, b, size);
    c[14] = 2; /* the segment's codec: blosc */
    check_error(c, size, "density", "compressed (blosc)");
    memcpy(c, b, size);
    c[16 + 32] = PNANOVDB_GRID_TYPE_VEC3F; /* metadata's grid type */
    check_error(c, size, "density", "not a scalar grid (NanoVDB type 6");
    memcpy(c, b, size);
    c[16 + 32] = PNANOVDB_GRID_TYPE_DOUBLE; /* a scalar type, but not the grid's */
    check_error(c, size, "density", "damaged");
    memcpy(c, b, size);
    c[16 + 176 + 8 + PNANOVDB_GRID_OFF_GRID_TYPE] = PNANOVDB_GRID_TYPE_DOUBLE; /* the grid's own */
    check_error(c, size, "density", "damaged");
    /* any single damaged byte of the grid reads without error or crash */
    for (size_t k = 16 + 176 + 8; k < size; k += 97) {
        memcpy(c, b, size);
        c[k] ^= 0xa5;
        VoxelGrid *g = grid_parse_nanovdb(c, size, "density", "x.nvdb", err, sizeof err);
        if (g)
            sample(g, 2.0f, 3.0f, 4.0f);
        grid_free(g);
    }
    free(c);
    free(b);
}

static void test_nanovdb_pattern(void)
{
    const char *path = grid_file();
    RayesParam q[2] = {{"filename", RAYES_PARAM_STRING, {0}, path},
                       {"grid", RAYES_PARAM_STRING, {0}, "density"}};
    char err[512];
    /* texture space 2x world: world (2 + 2x) reads the file at x */
    float xf[16] = {2, 0, 0, 2, 0, 2, 0, 4, 0, 0, 2, 6, 0, 0, 0, 1};
    Pattern *p = pattern_new("nanovdb", q, 2, xf, NULL, NULL, err, sizeof err);
    CHECK(p != NULL);
    if (!p)
        return;
    float P[1][3] = {{2 + 2 * 1.5f, 4 + 2 * 2.5f, 6 + 2 * 3.5f}}, out[1][3];
    RayesShadeCtx ctx = {.n_points = 1, .P = (const float(*)[3])P};
    CHECK(pattern_eval(p, NULL, &ctx, NULL, NULL, out) == 0);
    CHECK_NEAR(out[0][0], value_at(1, 1, 1), 1e-5);
    CHECK_NEAR(out[0][2], value_at(1, 1, 1), 1e-5);
    pattern_free(p);
    q[1].string = "velocity";
    CHECK(pattern_new("nanovdb", q, 2, NULL, NULL, NULL, err, sizeof err) == NULL);
    CHECK(strstr(err, "grid.nvdb: no grid \"velocity\"") != NULL);
    RayesParam bad = {"filename", RAYES_PARAM_FLOAT, {1}, NULL};
    CHECK(pattern_new("nanovdb", &bad, 1, NULL, NULL, NULL, err, sizeof err) == NULL);
    CHECK(strstr(err, "wrong type") != NULL);
}

static void test_densitygrid(void)
{
    /* 2 x 1 x 3 values over the box (0,0,0)-(2,1,3): centres at x 0.5, 1.5; z 0.5 1.5 2.5 */
    const float d[6] = {1, 2, 3, 4, 5, 6};
    RayesParam q[] = {{"nx", RAYES_PARAM_FLOAT, {2}, NULL},
                      {"ny", RAYES_PARAM_FLOAT, {1}, NULL},
                      {"nz", RAYES_PARAM_FLOAT, {3}, NULL},
                      {"p1", RAYES_PARAM_COLOR, {2, 1, 3}, NULL},
                      {"density", RAYES_PARAM_FLOATS, {0}, NULL, d, 6}};
    char err[512];
    Pattern *p = pattern_new("densitygrid", q, 5, NULL, NULL, NULL, err, sizeof err);
    CHECK(p != NULL);
    if (!p)
        return;
    float P[6][3] = {{0.5f, 0.5f, 0.5f},  {1.5f, 0.5f, 2.5f}, {1.0f, 0.5f, 1.0f},
                     {1.5f, 0.5f, 2.75f}, {2.5f, 0.5f, 1.0f}, {0.5f, 0.5f, -0.1f}};
    float out[6][3];
    RayesShadeCtx ctx = {.n_points = 6, .P = (const float(*)[3])P};
    CHECK(pattern_eval(p, NULL, &ctx, NULL, NULL, out) == 0);
    CHECK_NEAR(out[0][0], 1.0f, 1e-6);                   /* (0, 0, 0) */
    CHECK_NEAR(out[1][0], 6.0f, 1e-6);                   /* (1, 0, 2) */
    CHECK_NEAR(out[2][0], (1 + 2 + 3 + 4) / 4.0f, 1e-6); /* between four */
    CHECK_NEAR(out[3][0], 0.75f * 6.0f, 1e-6);           /* past the last centre: toward 0 */
    CHECK_NEAR(out[4][0], 0.0f, 0);                      /* outside the box */
    CHECK_NEAR(out[5][0], 0.0f, 0);
    pattern_free(p);
    q[4].n_floats = 5;
    CHECK(pattern_new("densitygrid", q, 5, NULL, NULL, NULL, err, sizeof err) == NULL);
    CHECK(strstr(err, "5 values, not nx ny nz = 6") != NULL);
    q[4].n_floats = 6;
    q[0].value[0] = 0;
    CHECK(pattern_new("densitygrid", q, 5, NULL, NULL, NULL, err, sizeof err) == NULL);
    CHECK(strstr(err, "nx must be a count") != NULL);
    RayesParam one[] = {{"density", RAYES_PARAM_FLOAT, {0.5f}, NULL}};
    p = pattern_new("densitygrid", one, 1, NULL, NULL, NULL, err, sizeof err);
    CHECK(p != NULL);
    pattern_free(p);
    RayesParam unknown[] = {{"sigma_a", RAYES_PARAM_FLOAT, {0.5f}, NULL}};
    CHECK(pattern_new("densitygrid", unknown, 1, NULL, NULL, NULL, err, sizeof err) == NULL);
    CHECK(strstr(err, "no parameter \"sigma_a\"") != NULL);
}

TEST_MAIN(TEST(test_nanovdb_voxels), TEST(test_nanovdb_tools_agree), TEST(test_nanovdb_quantized), TEST(test_nanovdb_errors),
          TEST(test_nanovdb_pattern), TEST(test_densitygrid))
