/*
 * tests/io/test_bpt.c — the Bezier patch reader of io/bpt.h, through the
 * public API it drives: the shared teapot (32 patches), small hand-written
 * files (comments, no final newline, a buffer without a NUL), and bad input,
 * whose one-line errors must name "name:line:col" and what was expected and
 * must leave the scene as it was.
 *
 * Patches are counted with a tiny render: at 4 x 4 pixels every patch dices
 * into a single grid, so the "grids" statistic is the patch count.
 * Buffers are copied to heap blocks of exactly their size so that
 * AddressSanitizer catches any read past the end.
 */
#include <string.h>

#include "io/bpt.h"
#include "rayes/rayes.h"
#include "test.h"

#ifndef RAYES_TEST_DATA
#error "RAYES_TEST_DATA must name the shared data directory"
#endif

/* ------------------------------------------------------------- helpers */

/* One patch, a flat 4 x 4 grid of points in the z = 0 plane (16 points). */
#define ONE_PATCH_INDICES "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n"
#define SIXTEEN_POINTS                                                                   \
    "16\n"                                                                               \
    "-1.5 -1.5 0\n-0.5 -1.5 0\n0.5 -1.5 0\n1.5 -1.5 0\n"                                 \
    "-1.5 -0.5 0\n-0.5 -0.5 0\n0.5 -0.5 0\n1.5 -0.5 0\n"                                 \
    "-1.5 0.5 0\n-0.5 0.5 0\n0.5 0.5 0\n1.5 0.5 0\n"                                     \
    "-1.5 1.5 0\n-0.5 1.5 0\n0.5 1.5 0\n1.5 1.5 0\n"
#define ONE_PATCH "1\n" ONE_PATCH_INDICES SIXTEEN_POINTS

/* Parses text[0..size) from a heap copy of exactly size bytes (no NUL). */
static RayesError parse_exact(const char *name, const char *text, size_t size, RayesScene *s,
                              char *err, size_t err_size)
{
    char *copy = malloc(size ? size : 1);
    if (!copy)
        return RAYES_ERROR_OUT_OF_MEMORY;
    memcpy(copy, text, size);
    err[0] = '\0';
    IoSink sink = io_sink_scene(s);
    RayesError e = io_parse_bpt(name, copy, size, &sink, err, err_size);
    free(copy);
    return e;
}

static RayesError parse_str(const char *text, RayesScene *s, char *err, size_t err_size)
{
    return parse_exact("t.bpt", text, strlen(text), s, err, err_size);
}

/* Commits the scene and renders it at 4 x 4, 1 spp, one thread; returns
 * the number of grids (one per patch at this size), or -1 on failure. */
static long count_grids(RayesScene *s)
{
    static const float eye[3] = {0, 0, -20}, target[3] = {0, 0, 0}, up[3] = {0, 1, 0};
    if (rayes_scene_set_camera(s, eye, target, up, 30.0f) != RAYES_OK ||
        rayes_scene_commit(s) != RAYES_OK)
        return -1;
    RayesRenderOptions opt;
    rayes_render_options_init(&opt, RAYES_QUALITY_PREVIEW);
    opt.width = opt.height = 4;
    opt.spp = 1;
    opt.threads = 1;
    opt.shadow_rays = opt.shadow_rays_deep = 1;
    opt.diffuse_rays = opt.diffuse_rays_deep = 1;
    RayesImage *img = NULL;
    RayesStats *stats = NULL;
    long n = -1;
    if (rayes_render(s, &opt, &img, &stats) == RAYES_OK) {
        const RayesStat *g = rayes_stats_find(stats, "grids");
        n = g ? (long)g->count : -1;
    } else {
        fprintf(stderr, "render failed: %s\n", rayes_scene_get_error(s));
    }
    rayes_stats_free(stats);
    rayes_image_free(img);
    return n;
}

static int starts_with(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

/* Parses bad input into a fresh scene and checks the error: PARSE, one
 * line, starting with `where` ("t.bpt:L:C: "), containing `what`; then
 * that the scene gained nothing. */
static void check_bad_size(const char *text, size_t size, const char *where, const char *what)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    RayesError e = parse_exact("t.bpt", text, size, s, err, sizeof err);
    CHECK(e == RAYES_ERROR_PARSE);
    CHECK(starts_with(err, where));
    CHECK(strstr(err, what) != NULL);
    CHECK(strchr(err, '\n') == NULL);
    if (!starts_with(err, where) || !strstr(err, what))
        fprintf(stderr, "  message: \"%s\"\n  expected \"%s...%s...\"\n", err, where, what);
    CHECK(count_grids(s) == 0);
    rayes_scene_release(s);
}

static void check_bad(const char *text, const char *where, const char *what)
{
    check_bad_size(text, strlen(text), where, what);
}

/* --------------------------------------------------------------- tests */

static void test_teapot_file(void)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    char err[512] = "";
    CHECK(io_read_bpt(RAYES_TEST_DATA "/teapot.bpt", &sink, err, sizeof err) == RAYES_OK);
    CHECK(err[0] == '\0');
    if (err[0] != '\0')
        fprintf(stderr, "  %s\n", err);
    CHECK(count_grids(s) == 32);
    rayes_scene_release(s);
}

static void test_missing_file(void)
{
    RayesScene *s = rayes_scene_new();
    IoSink sink = io_sink_scene(s);
    char err[512] = "";
    CHECK(io_read_bpt(RAYES_TEST_DATA "/no-such-file.bpt", &sink, err, sizeof err) == RAYES_ERROR_IO);
    CHECK(strstr(err, "no-such-file.bpt") != NULL);
    CHECK(strchr(err, '\n') == NULL);
    CHECK(count_grids(s) == 0);
    rayes_scene_release(s);
}

static void test_small_valid(void)
{
    static const char text[] = "# two patches sharing their points\n"
                               "2   # patch count\n" ONE_PATCH_INDICES
                               "\t16 15 14 13 12 11 10 9 8 7 6 5 4 3 2 1  # reversed\n"
                               "\n" SIXTEEN_POINTS "# trailing comment\n";
    RayesScene *s = rayes_scene_new();
    char err[512];
    CHECK(parse_str(text, s, err, sizeof err) == RAYES_OK);
    CHECK(err[0] == '\0');
    CHECK(count_grids(s) == 2);
    rayes_scene_release(s);
}

static void test_crlf_and_exponents(void)
{
    static const char text[] = "1\r\n" "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\r\n" "16\r\n"
                               "-1.5e0 -1.5 0\r\n-0.5 -1.5 0\r\n+0.5 -1.5 0\r\n1.5 -1.5 -0\r\n"
                               "-1.5 -0.5 0\r\n-0.5 -0.5 0\r\n0.5 -0.5 0\r\n1.5 -0.5 0\r\n"
                               "-1.5 0.5 0\r\n-0.5 0.5 0\r\n0.5 0.5 0\r\n1.5 0.5 0\r\n"
                               "-1.5 1.5 0\r\n-.5 1.5 0\r\n0.5 1.5 0\r\n15E-1 1.5 0\r\n";
    RayesScene *s = rayes_scene_new();
    char err[512];
    CHECK(parse_str(text, s, err, sizeof err) == RAYES_OK);
    CHECK(count_grids(s) == 1);
    rayes_scene_release(s);
}

static void test_no_final_newline(void)
{
    char text[1024];
    snprintf(text, sizeof text, "%s", ONE_PATCH);
    text[strlen(text) - 1] = '\0'; /* drop the last '\n' */
    RayesScene *s = rayes_scene_new();
    char err[512];
    CHECK(parse_str(text, s, err, sizeof err) == RAYES_OK);
    CHECK(count_grids(s) == 1);
    rayes_scene_release(s);
}

/* The size, not a NUL, ends the input: trailing bytes beyond it are never
 * seen, and a number cut by the size is read only up to the cut. */
static void test_not_nul_terminated(void)
{
    static const char valid[] = ONE_PATCH;
    char text[1024];
    snprintf(text, sizeof text, "%sgarbage that must not be read 1 2 3", valid);
    RayesScene *s = rayes_scene_new();
    char err[512];
    CHECK(parse_exact("t.bpt", text, strlen(valid), s, err, sizeof err) == RAYES_OK);
    CHECK(count_grids(s) == 1);
    rayes_scene_release(s);

    /* "1.5 1.5 0\n" cut after "1.5 1." leaves a valid "1." and no z. */
    size_t cut = strlen(valid) - strlen("5 0\n");
    check_bad_size(valid, cut, "t.bpt:19:7: ", "expected a coordinate");
    /* Cut after "1.5 1.5 0" (no newline, no NUL): valid. */
    s = rayes_scene_new();
    CHECK(parse_exact("t.bpt", valid, strlen(valid) - 1, s, err, sizeof err) == RAYES_OK);
    CHECK(count_grids(s) == 1);
    rayes_scene_release(s);
}

static void test_truncated(void)
{
    check_bad("1\n1 2 3 4 5\n", "t.bpt:3:1: ",
              "expected a control point index (16 per patch), found the end of the file");
    check_bad("1\n" ONE_PATCH_INDICES "16\n0 0 0\n", "t.bpt:5:1: ",
              "expected a coordinate (x y z per point), found the end of the file");
    check_bad("1\n" ONE_PATCH_INDICES, "t.bpt:3:1: ", "expected a point count");
    /* 15 indices on the line, the 16th missing: the next number is taken
     * as the 16th index and the error comes at the point list. */
    check_bad("1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15\n16\n", "t.bpt:4:1: ",
              "expected a point count");
}

static void test_not_a_number(void)
{
    check_bad("1\n1 2 x 4 5 6 7 8 9 10 11 12 13 14 15 16\n", "t.bpt:2:5: ",
              "expected a control point index (16 per patch), found \"x\"");
    check_bad("one\n", "t.bpt:1:1: ", "expected a patch count, found \"one\"");
    check_bad("1\n1 2 3.5 4\n", "t.bpt:2:5: ", "found \"3.5\"");
    check_bad("1\n" ONE_PATCH_INDICES "16\n0 0 zero\n", "t.bpt:4:5: ",
              "expected a coordinate (x y z per point), found \"zero\"");
    check_bad("1\n" ONE_PATCH_INDICES "16\n0 0,0 0\n", "t.bpt:4:3: ", "found \"0,0\"");
    /* A token longer than the reader's buffer is cut in the message. */
    check_bad("1\n11111111111111111111111111111111111111111111111111111111111111111111\n",
              "t.bpt:2:1: ", "found \"11111111111111111111...\"");
}

static void test_index_out_of_range(void)
{
    check_bad("1\n0 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16\n" SIXTEEN_POINTS, "t.bpt:2:1: ",
              "expected a control point index (16 per patch) from 1 to");
    check_bad("1\n1 2 3 -4 5 6 7 8 9 10 11 12 13 14 15 16\n" SIXTEEN_POINTS, "t.bpt:2:7: ",
              "expected a control point index (16 per patch) from 1 to");
    /* Beyond the point count: known only once the points are read, so the
     * message names the line of the index (no column), the patch and the
     * point. */
    check_bad("1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 17\n" SIXTEEN_POINTS, "t.bpt:2: ",
              "patch 1 uses point 17 but the file has 16 points");
    check_bad("1\n1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 99999999999999999999\n", "t.bpt:2:37: ",
              "expected a control point index (16 per patch)");
}

static void test_bad_counts(void)
{
    check_bad("0\n", "t.bpt:1:1: ", "expected a patch count from 1 to");
    check_bad("-3\n", "t.bpt:1:1: ", "expected a patch count from 1 to");
    check_bad("# comment\n  20000000\n", "t.bpt:2:3: ", "expected a patch count from 1 to");
    check_bad("1\n" ONE_PATCH_INDICES "0\n", "t.bpt:3:1: ", "expected a point count from 1 to");
    check_bad("1\n" ONE_PATCH_INDICES "-16\n", "t.bpt:3:1: ", "expected a point count from 1 to");
}

static void test_garbage_after_points(void)
{
    check_bad(ONE_PATCH "0 0 0\n", "t.bpt:20:1: ", "expected the end of the file after 16 points");
    check_bad(ONE_PATCH "\n# fine\nextra", "t.bpt:22:1: ",
              "expected the end of the file after 16 points");
}

static void test_non_finite(void)
{
    static const char *const bad[] = {"nan", "NaN", "inf", "-inf", "infinity", "1e999",
                                      "-1e40", "0x1p200"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char text[1024], what[128];
        snprintf(text, sizeof text, "1\n" ONE_PATCH_INDICES "16\n0 %s 0\n", bad[i]);
        snprintf(what, sizeof what, "expected a coordinate (x y z per point), found \"%s\"",
                 bad[i]);
        check_bad(text, "t.bpt:4:3: ", what);
    }
}

static void test_binary_garbage(void)
{
    static const char bin[] = {'\x7f', 'E', 'L', 'F', '\x02', '\x01', '\x01', '\0',
                               '\0',   '\xff', '\xfe', '\n', '\x80', '\0'};
    check_bad_size(bin, sizeof bin, "t.bpt:1:1: ", "expected a patch count, found \"");
    static const char nul_then_text[] = {'\0', '1', '\n'};
    check_bad_size(nul_then_text, sizeof nul_then_text, "t.bpt:1:1: ",
                   "expected a patch count");
    static const char mid[] = "1\n1 2 3 \x01\x02\x03 5\n";
    check_bad(mid, "t.bpt:2:7: ", "expected a control point index (16 per patch), found \"");
}

static void test_empty(void)
{
    check_bad_size("", 0, "t.bpt:1:1: ", "expected a patch count, found the end of the file");
    check_bad("\n\n   \n", "t.bpt:4:1: ", "expected a patch count, found the end of the file");
    check_bad("# only a comment", "t.bpt:1:17: ",
              "expected a patch count, found the end of the file");
}

/* A failed parse adds nothing: a good parse afterwards gives exactly its
 * own patches, even when the bad input was wrong only at its very end. */
static void test_failure_leaves_scene_unchanged(void)
{
    RayesScene *s = rayes_scene_new();
    char err[512];
    CHECK(parse_str(ONE_PATCH, s, err, sizeof err) == RAYES_OK);
    CHECK(parse_str("2\n" ONE_PATCH_INDICES ONE_PATCH_INDICES SIXTEEN_POINTS "oops\n", s, err,
                    sizeof err) == RAYES_ERROR_PARSE);
    CHECK(starts_with(err, "t.bpt:21:1: "));
    CHECK(parse_str("2\n" ONE_PATCH_INDICES "1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 17\n"
                    SIXTEEN_POINTS, s, err, sizeof err) == RAYES_ERROR_PARSE);
    CHECK(strstr(err, "patch 2 uses point 17") != NULL);
    char nan_last[1024];
    snprintf(nan_last, sizeof nan_last, "3\n" ONE_PATCH_INDICES ONE_PATCH_INDICES
             ONE_PATCH_INDICES SIXTEEN_POINTS);
    memcpy(strrchr(nan_last, ' ') + 1, "n\n", 3); /* the last z: "0" -> "n" */
    CHECK(parse_str(nan_last, s, err, sizeof err) == RAYES_ERROR_PARSE);
    CHECK(starts_with(err, "t.bpt:21:9: "));
    CHECK(parse_str(ONE_PATCH, s, err, sizeof err) == RAYES_OK);
    CHECK(count_grids(s) == 2);
    rayes_scene_release(s);
}

/* A small err buffer truncates the message and stays NUL-terminated. */
static void test_small_error_buffer(void)
{
    RayesScene *s = rayes_scene_new();
    char err[8];
    memset(err, 'x', sizeof err);
    CHECK(parse_str("oops", s, err, sizeof err) == RAYES_ERROR_PARSE);
    CHECK(memchr(err, '\0', sizeof err) != NULL);
    CHECK(strcmp(err, "t.bpt:1") == 0);
    rayes_scene_release(s);
}

TEST_MAIN(TEST(test_teapot_file), TEST(test_missing_file), TEST(test_small_valid),
          TEST(test_crlf_and_exponents), TEST(test_no_final_newline),
          TEST(test_not_nul_terminated), TEST(test_truncated), TEST(test_not_a_number),
          TEST(test_index_out_of_range), TEST(test_bad_counts), TEST(test_garbage_after_points),
          TEST(test_non_finite), TEST(test_binary_garbage), TEST(test_empty),
          TEST(test_failure_leaves_scene_unchanged), TEST(test_small_error_buffer))
