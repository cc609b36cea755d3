/*
 * rayes view: the headless script mode writes the images of the edited
 * scene (an edit after some passes gives the bytes of the same edit before
 * any pass: nothing cached before a light or shader edit is used after it,
 * and radiosity cached before a camera move is reused to the same bytes);
 * script errors name the file and line; the window (SDL's dummy driver, and
 * Xvfb when xvfb-run is installed) shows the image, not a blank window.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "image/image.h"
#include "test.h"

#define DIR RAYES_TEST_TMP "/app_view"

static void write_text(const char *name, const char *text)
{
    char path[600];
    snprintf(path, sizeof path, DIR "/%s", name);
    test_write_text(path, text);
}

/* Runs "rayes view ARGS" in DIR with env before it; returns the exit
 * status; stderr goes to DIR/err.txt. */
static int view(const char *env, const char *args)
{
    char cmd[2000];
    snprintf(cmd, sizeof cmd,
             "cd " DIR " && %s '" RAYES_BIN "' view %s --data '" RAYES_TEST_DATA
             "' > out.txt 2> err.txt",
             env, args);
    int st = system(cmd);
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

static void read_err(char *buf, size_t n)
{
    FILE *f = fopen(DIR "/err.txt", "r");
    size_t got = f ? fread(buf, 1, n - 1, f) : 0;
    buf[got] = '\0';
    if (f)
        fclose(f);
}

static float *read_exr(const char *name, int *w, int *h)
{
    char path[600], err[600];
    float *rgba = NULL;
    snprintf(path, sizeof path, DIR "/%s", name);
    if (image_read_exr(path, w, h, &rgba, err, sizeof err) != RAYES_OK)
        fprintf(stderr, "%s\n", err);
    CHECK(rgba != NULL);
    return rgba;
}

static int same_exr(const char *a, const char *b)
{
    int wa, ha, wb, hb;
    float *x = read_exr(a, &wa, &ha), *y = read_exr(b, &wb, &hb);
    int same = x && y && wa == wb && ha == hb &&
               memcmp(x, y, sizeof(float) * 4 * (size_t)wa * ha) == 0;
    free(x);
    free(y);
    return same;
}

#define OPTS "cornell-teapots --headless --quiet --res 40x32 --spp 4 --bounces 2 --threads 2 "

static void test_edits_after_passes_equal_edits_before(void)
{
    write_text("late.txt", "# edits after two passes\n"
                           "2 light 0 scale 0.5\n"
                           "2 shader @26,24 Cs 0.2 0.3 0.9\n"
                           "6 write late.exr\n");
    write_text("early.txt", "0 light 0 scale 0.5\n"
                            "0 shader @26,24 Cs 0.2 0.3 0.9\n"
                            "4 write early.exr\n");
    write_text("none.txt", "4 write none.exr\n");
    CHECK(view("", OPTS "--script late.txt") == 0);
    CHECK(view("", OPTS "--script early.txt") == 0);
    CHECK(view("", OPTS "--script none.txt") == 0);
    CHECK(same_exr("late.exr", "early.exr"));
    CHECK(!same_exr("late.exr", "none.exr"));
}

/* The scene's exposure applies in the viewer as in rayes render: a pbrt
 * film at iso 400 shows (and writes) 4 times the light of one at 100. */
static void test_scene_exposure(void)
{
    for (int k = 0; k < 2; k++) {
        char text[600], name[32];
        snprintf(text, sizeof text,
                 "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 20\n"
                 "Film \"rgb\" \"float iso\" %d\nWorldBegin\n"
                 "LightSource \"distant\" \"point3 from\" [0 0 1] \"point3 to\" [0 0 0] "
                 "\"rgb L\" [0.2 0.2 0.2]\nShape \"sphere\" \"float radius\" 1\n",
                 k ? 400 : 100);
        snprintf(name, sizeof name, "iso%d.pbrt", k ? 400 : 100);
        write_text(name, text);
        snprintf(text, sizeof text, "1 write iso%d.exr\n", k ? 400 : 100);
        write_text(k ? "iso400.txt" : "iso100.txt", text);
        snprintf(text, sizeof text, "%s --headless --quiet --res 16x16 --spp 1 --threads 1 --script %s",
                 name, k ? "iso400.txt" : "iso100.txt");
        CHECK(view("", text) == 0);
    }
    int w, h, w2, h2;
    float *a = read_exr("iso100.exr", &w, &h), *b = read_exr("iso400.exr", &w2, &h2);
    if (a && b) {
        size_t c = 4 * (size_t)(h / 2 * w + w / 2);
        CHECK(a[c] > 0.01f && fabsf(b[c] / a[c] - 4.0f) < 0.01f);
    }
    free(a);
    free(b);
}

static void test_camera_move_reuses_cache_to_the_same_bytes(void)
{
    write_text("cam_late.txt", "3 camera orbit 12 4\n3 camera dolly 0.2\n7 write cam_late.exr\n");
    write_text("cam_early.txt", "0 camera orbit 12 4\n0 camera dolly 0.2\n4 write cam_early.exr\n");
    CHECK(view("", OPTS "--script cam_late.txt") == 0);
    CHECK(view("", OPTS "--script cam_early.txt") == 0);
    CHECK(same_exr("cam_late.exr", "cam_early.exr"));
    CHECK(!same_exr("cam_late.exr", "none.exr"));
}

static void test_script_errors(void)
{
    static const struct {
        const char *script, *want;
    } cases[] = {
        {"light 0 scale 2\n", "bad.txt:1:1: expected a pass number"},
        {"# c\n1 write a.png\n0 quit\n", "bad.txt:3:1: passes must not decrease"},
        {"0 light 7 intensity 2\n", "bad.txt:1: edit light: no light 7"},
        {"0 frobnicate\n", "bad.txt:1: unknown command \"frobnicate\""},
        {"0 shader 0 nosuchparam 1\n", "bad.txt:1: edit shader: shader \"matte\" has no "
                                       "parameter \"nosuchparam\""},
        {"0 camera orbit 1\n", "bad.txt:1: camera: expected orbit"},
        {"0 write picture.tiff\n", "bad.txt:1: write: expected a file name"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        write_text("bad.txt", cases[i].script);
        CHECK(view("", OPTS "--script bad.txt") == 1);
        char err[2000];
        read_err(err, sizeof err);
        CHECK(strstr(err, cases[i].want) != NULL);
        if (!strstr(err, cases[i].want))
            fprintf(stderr, "expected \"%s\" in: %s", cases[i].want, err);
    }
    CHECK(view("", "cornell --headless --script missing.txt") == 1);
    CHECK(access(DIR "/a.png", F_OK) != 0);
}

/* The window's pixels after some passes: an image of the box, not blank. */
static void check_screenshot(const char *env, const char *name)
{
    char args[300], path[600], err[600];
    snprintf(args, sizeof args, "cornell --res 64x48 --passes 2 --threads 2 --screenshot %s",
             name);
    snprintf(path, sizeof path, DIR "/%s", name);
    unlink(path);
    CHECK(view(env, args) == 0);
    int w = 0, h = 0;
    float *rgba = NULL;
    CHECK(image_read_png(path, &w, &h, &rgba, err, sizeof err) == RAYES_OK);
    CHECK(w == 64 && h == 48);
    double red = 0, green = 0, mean = 0;
    for (int y = 0; rgba && y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *p = &rgba[4 * (y * w + x)];
            mean += (p[0] + p[1] + p[2]) / (3.0 * w * h);
            if (x < w / 5) /* the red wall, left */
                red += p[0] - p[1];
            if (x > 4 * w / 5) /* the green wall, right */
                green += p[1] - p[0];
        }
    CHECK(mean > 0.01);
    CHECK(red > 0 && green > 0);
    free(rgba);
}

/* LeakSanitizer is off for the window runs only: D-Bus and X libraries
 * that SDL loads keep allocations to the end (the headless runs check the
 * viewer's own memory). The options replace make test-asan's, whose
 * new_delete_type_mismatch=0 (OpenImageIO's) they keep. */
#define NO_LEAKS "ASAN_OPTIONS=detect_leaks=0:new_delete_type_mismatch=0 "

static void test_window_shows_the_image(void)
{
    check_screenshot(NO_LEAKS "SDL_VIDEODRIVER=dummy", "dummy.png");
    if (system("command -v xvfb-run > /dev/null 2>&1") == 0)
        check_screenshot(NO_LEAKS "xvfb-run -a", "xvfb.png");
    else
        fprintf(stderr, "note: xvfb-run is not installed; the Xvfb screenshot is skipped\n");
}

int main(void)
{
    mkdir(DIR, 0755);
    static const TestCase tests[] = {
        TEST(test_edits_after_passes_equal_edits_before), TEST(test_scene_exposure),
        TEST(test_camera_move_reuses_cache_to_the_same_bytes), TEST(test_script_errors),
        TEST(test_window_shows_the_image)};
    return test_run(tests, sizeof tests / sizeof tests[0]);
}
